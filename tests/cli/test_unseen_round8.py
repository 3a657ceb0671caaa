#!/usr/bin/env python3
"""Hostile cases written from the documentation alone (docs/cli.md, docs/experiments.md, docs/python.md and
the program's own `--help`) on the surfaces the seventh round left: HDF5 traces forged, cut and mislabelled
for `trace` and `score`, CSV traces with columns renamed, reordered, doubled and bytes no text holds, the
number spellings of `characters`, `model` and `report`, a link planted in a report's table folder, a report
killed while it writes, the study report's R process replaced by one that answers garbage or by none, a
Python study stopped by SIGTERM while R runs, a Python sweep on a process pool stopped by SIGTERM, Python's
`score` given values out of range, and `train` without a display. Run by CTest as `cli_unseen_round8_tests`.

Each case asserts what the documentation promises: one error line naming the file (and the column, row or
option) at fault, exit 1 for damaged data and 2 for wrong usage, never a silent wrong result, nothing written
outside the folders a command was given, no child process left behind.

CALLIGRAPHY_CLI names the program, CALLIGRAPHY_SOURCE_DIR the source tree; the built Python package is found
on PYTHONPATH (its cases are skipped without it), h5py forges the HDF5 traces (those cases are skipped
without it). CALLIGRAPHY_SANITIZED=1 takes a small subset.
"""
import hashlib
import json
import os
import signal
import subprocess
import sys
import tempfile
import time
import unittest
import zlib
from pathlib import Path

from outsider import descendants, running

CLI = os.environ.get("CALLIGRAPHY_CLI", "")
TIMEOUT_S = 60
SANITIZED = os.environ.get("CALLIGRAPHY_SANITIZED") == "1"
SHI = "十"

# Under the sanitizers (ten times slower) only the cases of one run of the program each are kept.
heavy = unittest.skipIf(SANITIZED, "several runs or megabytes: left to the Release run")

try:
    import numpy
    import h5py
except ImportError:  # pragma: no cover - Debian's python3-h5py missing
    numpy = None
    h5py = None

try:
    import calligraphy as cg
except ImportError:  # pragma: no cover - a build without the Python bindings
    cg = None


def run(args, cwd, env=None, timeout=TIMEOUT_S):
    arguments = [a if isinstance(a, bytes) else str(a) for a in args]  # bytes as they are: invalid UTF-8
    return subprocess.run([CLI, *arguments], cwd=cwd, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                          timeout=timeout, env=env)


def sha(path):
    return hashlib.sha256(Path(path).read_bytes()).hexdigest()


PROTOCOL = {"name": "p8", "conditions": [{"name": "h", "mode": "haptic"}, {"name": "v", "mode": "vision"}],
            "test": {"characters": [SHI, "人"], "conditions": ["h", "v"], "repetitions": 1},
            "trial": {"max_duration_s": 20}}


class Shared:
    """A study of three simulated subjects (haptic and vision, 十 and 人), one of its traces, a trial's CSV; and
    the study of 十 alone (study_of_shi) for the study report."""
    folder = None

    @classmethod
    def get(cls):
        if cls.folder is None:
            cls.folder = tempfile.TemporaryDirectory(prefix="calligraphy-unseen8-shared-")
            root = Path(cls.folder.name)
            (root / "p.json").write_text(json.dumps(PROTOCOL, ensure_ascii=False), encoding="utf-8")
            result = run(["session", "run", "p.json", "--subjects", "3", "--out", "study"], root)
            assert result.returncode == 0, result.stderr.decode(errors="replace")
            result = run(["trial", SHI, "--seed", "1", "--csv", "r.csv"], root)
            assert result.returncode == 0, result.stderr.decode(errors="replace")
        return Path(cls.folder.name)

    @classmethod
    def trace(cls):
        return sorted(cls.get().glob("study/*/*/trials/*U5341.trace.h5"))[0]

    @classmethod
    def study_of_shi(cls):
        """The study of the protocol with 十 alone (three subjects, haptic and vision: 6 trials), beside the other:
        what the study report's cases read. Three subjects are the fewest it fits a mixed model for; each
        report loads and draws half the trials."""
        root = cls.get()
        if not (root / "study-shi").exists():
            protocol = dict(PROTOCOL, test=dict(PROTOCOL["test"], characters=[SHI]))
            (root / "p-shi.json").write_text(json.dumps(protocol, ensure_ascii=False), encoding="utf-8")
            result = run(["session", "run", "p-shi.json", "--subjects", "3", "--out", "study-shi"], root)
            assert result.returncode == 0, result.stderr.decode(errors="replace")
        return root / "study-shi"


class Case(unittest.TestCase):
    def setUp(self):
        if not CLI or not Path(CLI).exists():
            self.fail(f"CALLIGRAPHY_CLI={CLI!r} is not the calligraphy program: run these tests through ctest")
        self.folder = tempfile.TemporaryDirectory(prefix="calligraphy-unseen8-")
        self.cwd = Path(self.folder.name)

    def tearDown(self):
        self.folder.cleanup()

    def cli(self, *args, **kwargs):
        return run(args, self.cwd, **kwargs)

    def error_line(self, result, status, *names):
        """Exit `status`, exactly one line on standard error, an error line naming each of `names`."""
        message = result.stderr.decode(errors="replace")
        self.assertEqual(result.returncode, status, message)
        lines = message.splitlines()
        self.assertEqual(len(lines), 1, message)
        self.assertIn(": error: ", lines[0])
        for name in names:
            self.assertIn(name, lines[0])
        return lines[0]


# ---------------------------------------------------------------------------------------------------------
# 1. HDF5 traces (docs/experiments.md "Trace files": datasets t, x, y, z, fx, fy, fz as int32 / 10^decimals
#    with `unit` and `decimals`; root `format` = "calligraphy-trace", `version` = 1, `samples`; a 512-byte
#    user block with the length and CRC-32 of the rest). A forged file carries a correct header, so that the
#    reader must judge the HDF5 content itself.

def reheader(path):
    data = bytearray(Path(path).read_bytes())
    body = bytes(data[512:])
    head = f"calligraphy-trace\nversion 1\nbytes {len(body)}\ncrc32 {zlib.crc32(body):08x}\n".encode()
    data[:512] = head + b"\0" * (512 - len(head))
    Path(path).write_bytes(bytes(data))


def forge(source, target, edit):
    """Copy the trace `source` to `target` through h5py, `edit(columns, root)` changing it in between."""
    with h5py.File(source, "r") as f:
        columns = {name: [f[name][()], dict(f[name].attrs)] for name in f}
        root = dict(f.attrs)
    edit(columns, root)
    with h5py.File(target, "w", userblock_size=512) as f:
        for key, value in root.items():
            f.attrs[key] = value
        for name, (data, attrs) in columns.items():
            dataset = f.create_dataset(name, data=data)
            for key, value in attrs.items():
                dataset.attrs[key] = value
    reheader(target)


# The C++ reader checks every attribute the writer writes (the root's format, version and samples, a
# column's unit and decimals) once the CRC-32 has matched, and refuses a file where one differs: h5py, which
# docs/python.md tells to divide by 10 ** decimals, and the C++ reader never read one file two ways.


@unittest.skipIf(h5py is None, "h5py (python3-h5py) is not installed: the HDF5 traces cannot be forged")
class TraceCases(Case):
    def forged(self, edit, name="f.trace.h5"):
        target = self.cwd / name
        forge(Shared.trace(), target, edit)
        return target

    def original_csv(self):
        result = self.cli("trace", Shared.trace())
        self.assertEqual(result.returncode, 0, result.stderr)
        return result.stdout.decode().splitlines()

    def test_an_untouched_copy_reads_as_the_original(self):
        # The forging itself changes nothing: the copy is the same CSV, byte for byte.
        target = self.forged(lambda columns, root: None)
        result = self.cli("trace", target)
        self.assertEqual(result.returncode, 0, result.stderr)
        self.assertEqual(result.stdout.decode().splitlines(), self.original_csv())

    def test_decimals_other_than_the_values_scale_are_honoured_or_refused(self):
        # x stored in millimetres' worth of integers (decimals 3): h5py reads x / 10**3 (docs/python.md, "bit for
        # bit"); `trace` must give the same metres or refuse the file, never read the integers at 10^7.
        def edit(columns, root):
            data, attrs = columns["x"]
            columns["x"] = [numpy.round(data / 1e4).astype(numpy.int32), dict(attrs, decimals=3)]
        target = self.forged(edit)
        result = self.cli("trace", target)
        if result.returncode != 0:
            self.error_line(result, 1, target.name, "x")
            return
        with h5py.File(target, "r") as f:
            expected = f["x"][()] / 10 ** int(f["x"].attrs["decimals"])
        rows = result.stdout.decode().splitlines()[1:]
        got = numpy.array([float(row.split(",")[1]) for row in rows])
        self.assertTrue(numpy.allclose(got, expected, rtol=0, atol=1e-9), "x read at another scale than its decimals")

    def test_a_unit_other_than_metres_is_refused(self):
        def edit(columns, root):
            columns["x"][1] = dict(columns["x"][1], unit=b"mm")
        target = self.forged(edit)
        for command in (["trace", target], ["score", target, "--character", SHI]):
            with self.subTest(command=command[0]):
                self.error_line(self.cli(*command), 1, target.name, "x")

    def test_a_foreign_format_or_a_newer_version_in_the_root_is_refused(self):
        for key, value in (("format", b"someone-elses-trace"), ("version", 2)):
            with self.subTest(key=key):
                target = self.forged(lambda columns, root: root.__setitem__(key, value), name=f"{key}.trace.h5")
                self.error_line(self.cli("trace", target), 1, target.name, key)

    def test_a_samples_count_that_disagrees_with_the_columns_is_refused(self):
        for declared in (5, 10 ** 12):
            with self.subTest(samples=declared):
                target = self.forged(lambda columns, root: root.__setitem__("samples", declared),
                                     name=f"s{declared}.trace.h5")
                self.error_line(self.cli("trace", target), 1, target.name, "samples")

    def test_an_attribute_missing_of_another_shape_or_on_doubles_is_refused_naming_it(self):
        def no_unit(columns, root):
            del columns["z"][1]["unit"]

        def two_versions(columns, root):
            root["version"] = numpy.array([1, 1], dtype=numpy.int32)

        def version_as_real(columns, root):
            root["version"] = 1.0

        def doubles_with_decimals(columns, root):  # h5py would divide these doubles by 10 ** 7
            data, attrs = columns["fy"]
            columns["fy"] = [data / 1e7, attrs]

        for edit, names in ((no_unit, ("'z'", "unit")), (two_versions, ("version",)),
                            (version_as_real, ("version",)), (doubles_with_decimals, ("'fy'", "decimals"))):
            with self.subTest(edit=edit.__name__):
                target = self.forged(edit, name=f"{edit.__name__}.trace.h5")
                self.error_line(self.cli("trace", target), 1, target.name, *names)

    def test_damaged_columns_are_refused_naming_the_file_and_the_column(self):
        def drop(columns, root):
            del columns["y"]

        def rename(columns, root):
            columns["Y"] = columns.pop("y")

        def short(columns, root):
            columns["y"][0] = columns["y"][0][:100]

        def two_d(columns, root):
            columns["y"][0] = numpy.stack([columns["y"][0]] * 2, axis=1)

        def complex_values(columns, root):
            columns["y"][0] = columns["y"][0].astype(complex)

        def strings(columns, root):
            columns["y"][0] = numpy.array([b"1"] * len(columns["y"][0]))

        def not_finite(columns, root):
            values = columns["y"][0] / 1e7
            values[7] = numpy.nan
            columns["y"] = [values, {"unit": numpy.bytes_(b"m")}]  # a fixed-length string, as written

        cases = [drop, rename, short, two_d, complex_values, strings, not_finite]
        for edit in cases[::3] if SANITIZED else cases:
            with self.subTest(edit=edit.__name__):
                target = self.forged(edit, name=f"{edit.__name__}.trace.h5")
                self.error_line(self.cli("trace", target), 1, target.name, "'y'")
                self.error_line(self.cli("score", target, "--character", SHI), 1, target.name, "'y'")

    def test_a_trace_cut_anywhere_is_refused_naming_it(self):
        whole = Shared.trace().read_bytes()
        points = [0, 17, 511, 512, 513, 4096, len(whole) // 2, len(whole) - 1]
        for cut in points[::3] if SANITIZED else points:
            with self.subTest(cut=cut):
                target = self.cwd / "cut.trace.h5"
                target.write_bytes(whole[:cut])
                self.error_line(self.cli("trace", target), 1, "cut.trace.h5")
                self.assertFalse(any(self.cwd.glob("*.tmp*")))

    def test_header_numbers_out_of_range_are_not_reported_as_other_numbers(self):
        # `bytes -5` or a number beyond 2^64 in the user block: the message may not claim the file says a number
        # it does not say (strtoull's wrap-around, 18446744073709551611).
        whole = bytearray(Shared.trace().read_bytes())
        crc = f"{zlib.crc32(bytes(whole[512:])):08x}"
        for spelled in ("-5", "99999999999999999999999", "0x10", ""):
            with self.subTest(bytes=spelled):
                head = f"calligraphy-trace\nversion 1\nbytes {spelled}\ncrc32 {crc}\n".encode()
                whole[:512] = head + b"\0" * (512 - len(head))
                target = self.cwd / "h.trace.h5"
                target.write_bytes(bytes(whole))
                line = self.error_line(self.cli("trace", target), 1, "h.trace.h5")
                self.assertNotIn("18446744073709551", line)

    def test_csv_aimed_at_its_own_trace_by_any_spelling_is_refused(self):
        trace = self.cwd / "a.trace.h5"
        trace.write_bytes(Shared.trace().read_bytes())
        (self.cwd / "sub").mkdir()
        os.symlink("a.trace.h5", self.cwd / "link.h5")
        os.link(trace, self.cwd / "hard.h5")
        before = sha(trace)
        spellings = ["a.trace.h5", "./a.trace.h5", "sub/../a.trace.h5", "link.h5", "hard.h5", str(trace)]
        for spelled in spellings[::3] if SANITIZED else spellings:
            with self.subTest(csv=spelled):
                self.error_line(self.cli("trace", "a.trace.h5", "--csv", spelled), 2, "--csv")
                self.assertEqual(sha(trace), before)

    def test_a_full_device_a_missing_folder_and_a_closed_pipe_are_errors(self):
        self.error_line(self.cli("trace", Shared.trace(), "--csv", "/dev/full"), 1, "/dev/full")
        self.error_line(self.cli("trace", Shared.trace(), "--csv", "missing/x.csv"), 1, "missing")
        self.assertFalse((self.cwd / "missing").exists())
        process = subprocess.Popen([CLI, "trace", str(Shared.trace())], stdout=subprocess.PIPE,
                                   stderr=subprocess.PIPE)
        process.stdout.readline()
        process.stdout.close()
        message = process.stderr.read().decode(errors="replace")
        process.stderr.close()
        self.assertEqual(process.wait(timeout=TIMEOUT_S), 1, message)
        self.assertEqual(len(message.splitlines()), 1, message)


# ---------------------------------------------------------------------------------------------------------
# 2. CSV traces for `score` (docs/cli.md "score", "Pen traces: format and limits").

class ScoreCsvCases(Case):
    def columns(self):
        lines = (Shared.get() / "r.csv").read_text().splitlines()
        header = lines[0].split(",")
        rows = [line.split(",") for line in lines[1:]]
        return {name: [row[i] for row in rows] for i, name in enumerate(header)}

    def write(self, name, header, columns, eol="\n", prefix=b""):
        rows = [",".join(values) for values in zip(*columns)]
        (self.cwd / name).write_bytes(prefix + (eol.join([",".join(header)] + rows) + eol).encode())
        return name

    def score(self, name, *extra):
        result = self.cli("score", name, "--character", SHI, "--json", "-", *extra)
        self.assertEqual(result.returncode, 0, result.stderr)
        return json.loads(result.stdout)

    def test_reordered_columns_bom_and_crlf_score_as_the_plain_file(self):
        c = self.columns()
        base = self.score(self.write("base.csv", ["t", "x", "y", "z"], [c["t"], c["x"], c["y"], c["z"]]))
        self.assertEqual(base["strokes_accepted"], 2)
        variants = [self.write("r.csv", ["z", "y", "x", "t"], [c["z"], c["y"], c["x"], c["t"]]),
                    self.write("b.csv", ["t", "x", "y", "z"], [c["t"], c["x"], c["y"], c["z"]], "\r\n",
                               b"\xef\xbb\xbf"),
                    self.write("u.csv", ["t_s", "x_m", "y_m", "z_m"], [c["t"], c["x"], c["y"], c["z"]])]
        for name in variants[:1] if SANITIZED else variants:
            with self.subTest(file=name):
                got = self.score(name)
                self.assertEqual(got["mean_deviation_m"], base["mean_deviation_m"])
                self.assertEqual(got["samples"], base["samples"])

    def test_quoted_header_names_and_values_score_as_the_plain_file(self):
        # RFC 4180 allows any field in double quotes; spreadsheet programs quote every one.
        c = self.columns()
        base = self.score(self.write("base.csv", ["t", "x", "y", "z"], [c["t"], c["x"], c["y"], c["z"]]))
        quote = lambda values: [f'"{v}"' for v in values]  # noqa: E731
        names = self.write("qh.csv", quote(["t", "x", "y", "z"]), [c["t"], c["x"], c["y"], c["z"]])
        every = self.write("qa.csv", quote(["t", "x", "y", "z"]), [quote(c[k]) for k in ("t", "x", "y", "z")])
        for name in (names, every):
            with self.subTest(file=name):
                got = self.score(name)
                self.assertEqual(got["mean_deviation_m"], base["mean_deviation_m"])
                self.assertEqual(got["samples"], base["samples"])
        # A quote that does not enclose its field is not taken away: the column is not found.
        self.write("bad.csv", ['"t', "x", "y", "z"], [c["t"], c["x"], c["y"], c["z"]])
        self.error_line(self.cli("score", "bad.csv", "--character", SHI), 1, "bad.csv:1", "'t'")

    def test_a_character_the_library_lacks_is_wrong_usage_naming_the_option(self):
        c = self.columns()
        name = self.write("base.csv", ["t", "x", "y", "z"], [c["t"], c["x"], c["y"], c["z"]])
        self.error_line(self.cli("score", name, "--character", "\u9f98"), 2, "--character", "U+9F98")

    @heavy
    def test_renamed_missing_or_doubled_columns_are_refused_naming_the_line(self):
        c = self.columns()
        t, x, y, z = c["t"], c["x"], c["y"], c["z"]
        cases = {"time.csv": (["time", "x", "y", "z"], [t, x, y, z], "'t'"),
                 "noy.csv": (["t", "x", "z"], [t, x, z], "'y'"),
                 "mm.csv": (["t", "x_mm", "y_mm", "z_mm"], [t, x, y, z], "'x'"),
                 "twice.csv": (["t", "x", "x_m", "y", "z"], [t, x, x, y, z], "x_m"),
                 "penz.csv": (["t", "x", "y", "z", "pen"], [t, x, y, z, ["1"] * len(t)], "pen")}
        for name, (header, columns, named) in cases.items():
            with self.subTest(file=name):
                self.write(name, header, columns)
                self.error_line(self.cli("score", name, "--character", SHI), 1, f"{name}:1", named)

    def test_a_nul_byte_in_a_value_is_printed_not_cutting_the_line(self):
        # docs/cli.md: whatever an error line quotes is printable text, control characters as \xHH or \uHHHH.
        c = self.columns()
        x = list(c["x"])
        x[5] = "0\x00"
        self.write("nul.csv", ["t", "x", "y", "z"], [c["t"], x, c["y"], c["z"]])
        line = self.error_line(self.cli("score", "nul.csv", "--character", SHI), 1, "nul.csv:7")
        self.assertTrue("\\x00" in line or "\\u0000" in line, line)
        self.assertNotIn("\0", line)

    @heavy
    def test_bad_numbers_and_time_going_back_are_refused_naming_the_line(self):
        c = self.columns()
        for field, value, line in (("t", "nan", 502), ("x", "inf", 502), ("x", "0x10", 7), ("t", "1e999", 502)):
            with self.subTest(field=field, value=value):
                columns = {k: list(v) for k, v in c.items() if k in "txyz"}
                columns[field][line - 2] = value
                self.write("bad.csv", ["t", "x", "y", "z"], [columns[k] for k in "txyz"])
                self.error_line(self.cli("score", "bad.csv", "--character", SHI), 1, f"bad.csv:{line}", value)
        columns = {k: list(v) for k, v in c.items() if k in "txyz"}
        columns["t"][500] = columns["t"][400]
        self.write("back.csv", ["t", "x", "y", "z"], [columns[k] for k in "txyz"])
        self.error_line(self.cli("score", "back.csv", "--character", SHI), 1, "back.csv", "backwards")

    def test_millimetres_labelled_metres_are_not_scored_as_written(self):
        # A user's mislabelling cannot be detected for certain, but it may not be scored as the character
        # written well: at 1000 times the size nothing lands on a stroke.
        c = self.columns()
        scaled = [[repr(float(v) * 1000) for v in c[k]] for k in "xyz"]
        self.write("mm.csv", ["t", "x", "y", "z"], [c["t"], *scaled])
        got = self.score("mm.csv")
        self.assertEqual(got["strokes_accepted"], 0)
        self.assertIsNone(got["mean_deviation_m"])

    def test_a_header_only_trace_scores_every_stroke_not_written(self):
        self.write("h.csv", ["t", "x", "y", "z"], [[], [], [], []])
        got = self.score("h.csv")
        self.assertEqual(got["samples"], 0)
        self.assertEqual(got["strokes_accepted"], 0)
        result = self.cli("score", "h.csv", "--character", SHI)
        self.assertEqual(result.returncode, 0, result.stderr)
        table = result.stdout.decode()
        self.assertEqual(sum(line.rstrip().endswith("not written") for line in table.splitlines()), 2, table)

    @heavy
    def test_one_sample_past_the_limit_is_refused_at_its_line(self):
        with open(self.cwd / "big.csv", "w") as f:
            f.write("t,x,y,pen\n")
            f.writelines(f"{i * 1e-3:.3f},0,0,0\n" for i in range(1_000_001))
        self.error_line(self.cli("score", "big.csv", "--character", SHI), 1, "big.csv:1000002")

    def test_characters_given_badly_are_usage_errors(self):
        (self.cwd / "one.csv").write_text("t,x,y,z\n0,0,0,0\n")
        for value, status in (("", 2), ("\udcff", 2), ("\ud800", 2), ("十十", 0)):
            with self.subTest(character=repr(value)):
                args = ["score", "one.csv", "--character", value.encode("utf-8", "surrogateescape")
                        if value != "\ud800" else b"\xed\xa0\x80"]
                if status == 0:
                    self.assertEqual(self.cli(*args).returncode, 0)
                else:
                    self.error_line(run(args, self.cwd), status, "--character")
        self.error_line(self.cli("score", "one.csv", "--character", "十十", "--units", "data"), 2, "--units")


# ---------------------------------------------------------------------------------------------------------
# 3. `model`, `characters`, `devices`, `report --jobs`: values at and past their documented ranges.

class OptionValueCases(Case):
    def test_integer_options_take_decimal_digits_in_range_only(self):
        spellings = ["0", "256", "-0", "1e999", "0x10", " 5", "5 ", "+5", "1.5", "５"]
        for value in spellings[::3] if SANITIZED else spellings:
            with self.subTest(strokes=value):
                self.error_line(self.cli("characters", "--strokes", value), 2, "--strokes")
        self.assertEqual(self.cli("characters", "--strokes", "255").returncode, 0)
        for value in ("0", "257", "-1"):
            with self.subTest(jobs=value):
                self.error_line(self.cli("report", ".", "--csv", ".", "--jobs", value), 2, "--jobs")

    def test_typical_strokes_out_of_range_are_named(self):
        for value in ("0", "40", "-0", "hzgx"):
            with self.subTest(typical=value):
                self.error_line(self.cli("characters", "--typical", value), 2, "--typical")

    def test_texts_invalid_empty_or_huge(self):
        for raw in (b"", b"\xed\xa0\x80", b"a\xffb", b"\xc0\x80"):
            with self.subTest(text=raw):
                self.error_line(run(["characters", "--text", raw], self.cwd), 2, "--text")
        for raw in (b"", b"\xed\xa0\x80", "十十".encode()):
            with self.subTest(model=raw):
                self.error_line(run(["model", raw], self.cwd), 2, "CHAR")
        text = "".join(chr(0x4E00 + i) for i in range(10_000)) + "\x1b[31m"
        result = self.cli("characters", "--text", text, "--json")
        self.assertEqual(result.returncode, 0, result.stderr)
        listing = json.loads(result.stdout)
        self.assertEqual(listing["count"] + len(listing["not_found"]), 10_000 + 5)  # ESC [ 3 1 m
        self.assertIn("\x1b", listing["not_found"])
        table = self.cli("characters", "--text", "十\x1b[31m")
        self.assertEqual(table.returncode, 0, table.stderr)
        self.assertNotIn(b"\x1b", table.stdout)
        self.assertIn(b"U+001B", table.stdout)

    def test_model_svg_on_a_data_file_by_a_link_is_refused(self):
        source = Path(os.environ.get("CALLIGRAPHY_SOURCE_DIR", "")) / "data" / "hanzi-writer-data" / f"{SHI}.json"
        if not source.exists():
            self.skipTest(f"{source} is not there")
        (self.cwd / "hw").mkdir()
        data = self.cwd / "hw" / f"{SHI}.json"
        data.write_bytes(source.read_bytes())
        os.symlink(data, self.cwd / "link.svg")
        before = sha(data)
        for out in ("link.svg", f"hw/./{SHI}.json"):
            with self.subTest(svg=out):
                self.error_line(self.cli("model", SHI, "--data", "hw", "--svg", out), 2, "--svg")
                self.assertEqual(sha(data), before)

    def test_flags_take_no_value_and_devices_takes_no_positional(self):
        self.error_line(self.cli("devices", "--json=yes"), 2, "--json")
        self.error_line(self.cli("devices", "extra"), 2, "extra")


# ---------------------------------------------------------------------------------------------------------
# 4. Reports and their journal: a link planted in the table folder, a report killed while it writes.

class ReportCases(Case):
    # Left failing: every output follows a symbolic link to its target (docs/cli.md "Outputs": "A symbolic
    # link keeps pointing where it did"), and report's tables do so too, while the same page says a set is
    # written in its folders only. Which promise gives way (refuse a link in a set's folder, or document that a
    # set's file follows it) is a decision about the file writer, not a small fix.
    def test_a_link_planted_in_the_table_folder_writes_nothing_outside_it(self):
        # docs/cli.md: a set of files (report) "needs no folder but those its files are in ... writes in /tmp/t
        # and beside ~/r.html only". A trials.csv that is a link to a file elsewhere must leave that file alone.
        outside = self.cwd / "outside"
        outside.mkdir()
        victim = outside / "precious.txt"
        victim.write_text("keep me\n")
        tables = self.cwd / "tables"
        tables.mkdir()
        os.symlink(victim, tables / "trials.csv")
        result = self.cli("report", Shared.get() / "study", "--csv", tables)
        self.assertEqual(victim.read_text(), "keep me\n", result.stderr)
        self.assertEqual(sorted(p.name for p in outside.iterdir()), ["precious.txt"])
        if result.returncode != 0:
            self.error_line(result, result.returncode, "trials.csv")

    @heavy
    def test_a_report_killed_at_any_moment_leaves_its_folders_whole_and_the_next_run_completes(self):
        study = Shared.get() / "study"
        tables = self.cwd / "tables"
        tables.mkdir()
        pages = self.cwd / "pages"
        pages.mkdir()
        bystander = self.cwd / "bystander.txt"
        bystander.write_text("untouched\n")
        first = self.cli("report", study, "--csv", tables, "--out", pages / "r.html")
        self.assertEqual(first.returncode, 0, first.stderr)
        whole = {p.name: sha(p) for p in tables.iterdir()}
        for delay_ms in (0, 2, 5, 10, 20, 40):
            process = subprocess.Popen([CLI, "report", str(study), "--csv", str(tables), "--out",
                                        str(pages / "r.html")], cwd=self.cwd, stdout=subprocess.DEVNULL,
                                       stderr=subprocess.DEVNULL)
            time.sleep(delay_ms / 1000)
            process.send_signal(signal.SIGKILL if delay_ms % 10 else signal.SIGTERM)
            process.wait(timeout=TIMEOUT_S)
            for name in ("trials.csv", "strokes.csv"):  # the earlier pair or the new one, never a half file
                self.assertTrue((tables / name).exists(), f"{name} missing after a kill at {delay_ms} ms")
        again = self.cli("report", study, "--csv", tables, "--out", pages / "r.html")
        self.assertEqual(again.returncode, 0, again.stderr)
        self.assertEqual({p.name: sha(p) for p in tables.iterdir()}, whole)
        self.assertEqual(bystander.read_text(), "untouched\n")
        self.assertEqual(sorted(p.name for p in self.cwd.iterdir()), ["bystander.txt", "pages", "tables"])

    def test_a_table_folder_that_is_not_writable(self):
        if os.geteuid() == 0:
            self.skipTest("root writes into a folder of mode 555: nothing to refuse")
        tables = self.cwd / "ro"
        tables.mkdir()
        tables.chmod(0o555)
        try:
            self.error_line(self.cli("report", Shared.get() / "study", "--csv", tables), 1, "ro")
        finally:
            tables.chmod(0o755)


# ---------------------------------------------------------------------------------------------------------
# 5. The study report's R process (docs/experiments.md "A report for a paper": "An R that ends, hangs past 10
#    minutes or answers otherwise spoils only that fit: its row says 'not computed' ... the page is still made").

# (An R that answers twice needs the framing of lmer_fit.R's replies, which the documentation does not give;
# an R that echoes its requests is a package's chatter there, waited out for 10 minutes: both are
# tests/python/test_r_process.py's.)
FAKE_R = {
    "garbage": "#!/bin/sh\necho 'garbage line'\necho '1 2 3'\nexit 0\n",
    "early": "#!/bin/sh\nexit 3\n",
}


@unittest.skipIf(cg is None, "the Python package is not on PYTHONPATH")
class RProcessCases(Case):
    def study_report(self, path, *extra, timeout=TIMEOUT_S):
        env = dict(os.environ, PATH=path)
        return subprocess.run([sys.executable, "-m", "calligraphy.study_report", str(Shared.study_of_shi()),
                               "--out", "paper", *extra], cwd=self.cwd, env=env, stdout=subprocess.PIPE,
                              stderr=subprocess.PIPE, timeout=timeout)

    def fake_r(self, script):
        folder = self.cwd / "fakebin"
        folder.mkdir(exist_ok=True)
        (folder / "Rscript").write_text(script)
        (folder / "Rscript").chmod(0o755)
        return f"{folder}:/usr/bin:/bin"

    @heavy
    def test_an_r_that_answers_garbage_ends_early_or_answers_twice_leaves_the_fit_not_computed(self):
        for name, script in FAKE_R.items():
            with self.subTest(r=name):
                result = self.study_report(self.fake_r(script))
                self.assertEqual(result.returncode, 0, result.stderr.decode(errors="replace"))
                page = (self.cwd / "paper" / "index.html").read_text(encoding="utf-8")
                self.assertIn("not computed", page)
                self.assertNotIn("Traceback", result.stderr.decode(errors="replace"))

    @heavy
    def test_no_r_on_the_path(self):
        empty = self.cwd / "empty"
        empty.mkdir()
        # the interpreter is named by its full path; nothing else is on PATH
        result = self.study_report(str(empty))
        self.assertEqual(result.returncode, 0, result.stderr.decode(errors="replace"))
        page = (self.cwd / "paper" / "index.html").read_text(encoding="utf-8")
        self.assertIn("Rscript is not installed", page)

    def test_a_reference_with_a_line_break_or_quotes_is_a_usage_error(self):
        references = ("h\nx", 'h"); quit("', "nosuch")
        for reference in references[:1] if SANITIZED else references:
            with self.subTest(reference=reference):
                result = self.study_report(os.environ.get("PATH", ""), "--reference", reference)
                message = result.stderr.decode(errors="replace")
                self.assertEqual(result.returncode, 2, message)
                self.assertNotIn("Traceback", message)
                self.assertFalse((self.cwd / "paper").exists())

    @heavy
    def test_sigterm_while_r_fits_leaves_no_r_behind(self):
        pidfile = self.cwd / "r.pid"
        path = self.fake_r(f"#!/bin/sh\necho $$ > {pidfile}\nexec sleep 60\n")
        process = subprocess.Popen([sys.executable, "-m", "calligraphy.study_report",
                                    str(Shared.study_of_shi()), "--out", "paper"], cwd=self.cwd,
                                   env=dict(os.environ, PATH=path), stdout=subprocess.DEVNULL,
                                   stderr=subprocess.PIPE)
        deadline = time.monotonic() + 30
        while not pidfile.exists() or not pidfile.read_text().strip():
            if time.monotonic() > deadline or process.poll() is not None:
                process.kill()
                self.fail("the study report never started R")
            time.sleep(0.05)
        r_pid = int(pidfile.read_text())
        process.send_signal(signal.SIGTERM)
        process.wait(timeout=TIMEOUT_S)
        message = process.stderr.read()
        process.stderr.close()
        self.assertNotIn(b"Traceback", message)
        deadline = time.monotonic() + 5
        while time.monotonic() < deadline:
            try:
                os.kill(r_pid, 0)
            except ProcessLookupError:
                break
            time.sleep(0.05)
        else:
            os.kill(r_pid, signal.SIGKILL)
            self.fail("R outlived the study report stopped by SIGTERM")


# ---------------------------------------------------------------------------------------------------------
# 6. Python: documented exception types naming the argument; the library's frames fed to `score`.

@unittest.skipIf(cg is None, "the Python package is not on PYTHONPATH")
class PythonCases(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.trial = cg.simulate_trial(SHI, seed=1)
        cls.frame = cls.trial.to_dataframe()

    def raises(self, kind, argument, call):
        with self.assertRaises(kind) as caught:
            call()
        self.assertIn(argument, str(caught.exception))

    def test_to_dataframe_and_study_samples_score_as_the_trial(self):
        got = cg.score(self.frame, SHI)
        self.assertEqual(got["strokes_accepted"], self.trial.metrics["strokes_accepted"])
        self.assertAlmostEqual(got["mean_deviation_m"], self.trial.metrics["mean_deviation_m"], places=9)
        import calligraphy.study as cg_study
        study = cg_study.load([str(Shared.get() / "study")])
        row = study.trials.iloc[0]
        samples = study.samples(row)
        scored = cg.score(samples, row["characters"])
        self.assertAlmostEqual(scored["mean_deviation_m"], row["mean_deviation_m"], places=9)

    def test_study_samples_of_none_or_a_list_is_a_type_error_naming_trial(self):
        import calligraphy.study as cg_study
        study = cg_study.load([str(Shared.get() / "study")])
        for value in (None, [0], True):
            with self.subTest(value=value):
                self.raises(TypeError, "trial", lambda: study.samples(value))
        with self.assertRaises(KeyError):
            study.samples(10 ** 9)

    def test_score_arguments_out_of_range_name_themselves(self):
        # (a negative contact threshold is left out: a height below the paper, the pen pressed in, is a
        # criterion that can make sense on a haptic device whose HIP enters the surface)
        for argument, value in (("contact_threshold_m", float("nan")),
                                ("contact_threshold_m", float("inf")), ("start_radius_m", 0.0),
                                ("start_radius_m", -1e-3), ("start_radius_m", float("inf"))):
            with self.subTest(argument=argument, value=value):
                self.raises(cg.InvalidArgument, argument, lambda: cg.score(self.frame, SHI, **{argument: value}))
        self.raises(cg.InvalidArgument, "units", lambda: cg.score(self.frame, SHI, units="mm"))
        self.raises(TypeError, "character", lambda: cg.score(self.frame, None))
        self.raises(TypeError, "trace", lambda: cg.score(None, SHI))

    def test_simulate_trial_values_out_of_range_name_themselves(self):
        for argument, value in (("rate_hz", float("nan")), ("rate_hz", -1.0), ("rate_hz", 1e999),
                                ("max_duration_s", 0.0), ("max_duration_s", float("nan")), ("seed", -1),
                                ("seed", 2 ** 64)):
            with self.subTest(argument=argument, value=value):
                self.raises(cg.InvalidArgument, argument,
                            lambda: cg.simulate_trial(SHI, **{argument: value}))
        self.raises(TypeError, "seed", lambda: cg.simulate_trial(SHI, seed=1.5))
        self.raises(TypeError, "guidance", lambda: cg.simulate_trial(SHI, guidance="yes"))
        self.raises(cg.InvalidArgument, "writer", lambda: cg.simulate_trial(SHI, writer="expert"))
        self.raises(cg.InvalidArgument, "characters", lambda: cg.simulate_trial("\ud800"))

    def test_study_cohort_and_sweep_arguments_of_the_wrong_type_name_themselves(self):
        # docs/python.md: "An argument of the wrong type raises TypeError naming the argument"; the cohort's
        # errors name subjects, workers or batch_size.
        import calligraphy.cohort as cg_cohort
        import calligraphy.study as cg_study
        from calligraphy.experiments import sweep
        protocol = Shared.get() / "p.json"
        for paths in (None, 5, b"study", [None]):
            with self.subTest(load=paths):
                self.raises(TypeError, "paths", lambda: cg_study.load(paths))
        self.raises(ValueError, "paths", lambda: cg_study.load([]))
        self.raises(TypeError, "protocol", lambda: cg_cohort.simulate(None, 1))
        self.raises(TypeError, "learning", lambda: cg_cohort.simulate(protocol, 1, learning=None))
        self.raises(TypeError, "profile", lambda: cg_cohort.simulate(protocol, 1, profile=3))
        self.raises(ValueError, "batch_size", lambda: cg_cohort.simulate(protocol, 1, batch_size=0))
        self.raises(ValueError, "subjects", lambda: cg_cohort.simulate(protocol, 0))
        for seeds in (float("nan"), None, "3"):
            with self.subTest(seeds=seeds):
                self.raises(TypeError, "seeds", lambda: sweep(SHI, {}, seeds, progress=False))
        self.raises(ValueError, "seeds", lambda: sweep(SHI, {}, [-1], progress=False))

    def test_a_frame_reversed_or_with_a_nan_time_is_refused(self):
        self.raises(cg.InvalidArgument, "backwards", lambda: cg.score(self.frame.iloc[::-1], SHI))
        broken = self.frame.copy()
        broken.loc[5, "t_s"] = float("nan")
        self.raises(cg.InvalidArgument, "sample 5", lambda: cg.score(broken, SHI))


SWEEP_SCRIPT = """
import os
if __name__ == "__main__":
    from calligraphy.experiments import sweep
    print(os.getpid(), flush=True)
    sweep("永我九心", {"guidance": [True, False]}, seeds=500, workers=2, progress=False)
"""


@unittest.skipIf(cg is None, "the Python package is not on PYTHONPATH")
class PythonSignalCases(Case):
    @heavy
    def test_sigterm_to_a_sweep_on_a_process_pool_leaves_no_worker(self):
        if not Path("/proc/self/stat").exists():
            self.skipTest("no /proc to find the workers by")
        (self.cwd / "sweep_run.py").write_text(SWEEP_SCRIPT, encoding="utf-8")
        process = subprocess.Popen([sys.executable, "sweep_run.py"], cwd=self.cwd, stdout=subprocess.PIPE,
                                   stderr=subprocess.DEVNULL)
        try:
            pid = int(process.stdout.readline())
            deadline = time.monotonic() + 30
            below = []
            while len(below) < 3 and time.monotonic() < deadline:  # the forkserver and its two workers
                time.sleep(0.1)
                below = descendants(pid)
            self.assertGreaterEqual(len(below), 3, "the sweep started no workers")
            process.send_signal(signal.SIGTERM)
            process.wait(timeout=TIMEOUT_S)
        finally:
            process.stdout.close()
            if process.poll() is None:
                process.kill()
                process.wait()
        deadline = time.monotonic() + 10
        while any(running(p) for p in below) and time.monotonic() < deadline:
            time.sleep(0.1)
        left = [p for p in below if running(p)]
        for p in left:
            os.kill(p, signal.SIGKILL)
        self.assertEqual(left, [], "processes of the sweep outlived it")


# ---------------------------------------------------------------------------------------------------------
# 7. `train` without a display: exit 1 and one line (docs/cli.md "Errors are one line"), nothing on stdout.

class TrainCases(Case):
    def test_train_without_a_display_is_one_error_line(self):
        env = {k: v for k, v in os.environ.items() if k not in ("DISPLAY", "WAYLAND_DISPLAY")}
        cases = [["train", SHI, "--exit-after", "1"], ["train", SHI, "--device", "mouse", "--exit-after", "1"],
                 ["train", SHI, "--writer", "simulated", "--exit-after", "1"]]
        for args in cases[:1] if SANITIZED else cases:
            with self.subTest(args=args):
                result = self.cli(*args, env=env)
                # A build without the window (the sanitizer stage's) says so, also in one line.
                built_without = b"built without the trainer window" in result.stderr
                self.error_line(result, 1, "built without the trainer window" if built_without else "DISPLAY")
                self.assertEqual(result.stdout, b"")


if __name__ == "__main__":
    unittest.main(verbosity=2)
