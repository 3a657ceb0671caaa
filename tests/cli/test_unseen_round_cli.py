#!/usr/bin/env python3
"""Hostile cases on the program's surfaces besides the study, written from the documentation alone
(docs/cli.md, docs/python.md) as an outsider would: odd Unicode and oversized texts for `characters`, outputs
on folders, inputs, devices and links for `model`, damaged and mislabelled traces for `score` and `trace`,
numbers in every spelling for `trial`, closed and broken standard output, file size limits, and the Python
API with wrong types, NaN, wrong shapes and numpy arrays of every layout. Run by CTest as
`cli_unseen_round_tests`.

Each case asserts what the documentation promises: the exit status (0 ok, 1 data or I/O error, 2 usage, one
line naming the option, file or row), that no file is left behind and that an input is never replaced.

CALLIGRAPHY_CLI names the program and CALLIGRAPHY_SOURCE_DIR the source tree; the built Python package is found
on PYTHONPATH (its cases are skipped without it). Standard library, numpy and h5py where present.
"""
import gzip
import json
import math
import os
import resource
import shutil
import subprocess
import tempfile
import unittest
from pathlib import Path

CLI = os.environ.get("CALLIGRAPHY_CLI", "")
SOURCE = Path(os.environ.get("CALLIGRAPHY_SOURCE_DIR", Path(__file__).resolve().parents[2]))
DATA = SOURCE / "data" / "hanzi-writer-data"
YONG = "永"
TIMEOUT_S = 60
# Under the sanitizers (ten times slower) the lists of spellings are tried one in three.
SANITIZED = os.environ.get("CALLIGRAPHY_SANITIZED") == "1"


def sample(cases):
    return cases[::3] if SANITIZED else cases

try:
    import numpy as np
except ImportError:  # pragma: no cover - the Python cases are skipped
    np = None

try:
    import h5py
except ImportError:  # pragma: no cover
    h5py = None

cg = None
if np is not None:
    try:  # the built package, on PYTHONPATH under CTest
        import calligraphy as cg
    except ImportError:  # pragma: no cover - a build without the Python bindings
        cg = None


def run(args, cwd, stdout=subprocess.PIPE, limit_file_bytes=None, close_stdout=False):
    def prepare():
        if limit_file_bytes is not None:
            resource.setrlimit(resource.RLIMIT_FSIZE, (limit_file_bytes, limit_file_bytes))
        if close_stdout:
            os.close(1)

    return subprocess.run([CLI, *map(str, args)], cwd=cwd, stdout=stdout, stderr=subprocess.PIPE,
                          timeout=TIMEOUT_S, preexec_fn=prepare)


class Shared:
    """One trial's trace, made once: 永 by the skilled simulated writer."""
    folder = None
    trace = None

    @classmethod
    def get(cls):
        if cls.trace is None:
            cls.folder = tempfile.TemporaryDirectory(prefix="calligraphy-unseen-shared-")
            trace = Path(cls.folder.name) / "yong.csv"
            result = run(["trial", YONG, "--writer-profile", "skilled", "--seed", "3", "--csv", trace],
                         cls.folder.name)
            assert result.returncode == 0, result.stderr.decode(errors="replace")
            cls.trace = trace
        return cls.trace


class UnseenCase(unittest.TestCase):
    def setUp(self):
        if not CLI or not Path(CLI).exists():
            self.fail(f"CALLIGRAPHY_CLI={CLI!r} is not the calligraphy program: run these tests through ctest")
        self.folder = tempfile.TemporaryDirectory(prefix="calligraphy-unseen-")
        self.cwd = Path(self.folder.name)

    def tearDown(self):
        self.folder.cleanup()

    def cli(self, *args, **kwargs):
        return run(args, self.cwd, **kwargs)

    def assert_error(self, result, status, *names):
        """Exit `status` and one error line on stderr naming each of `names`."""
        message = result.stderr.decode(errors="replace")
        self.assertEqual(result.returncode, status, message)
        errors = [line for line in message.splitlines() if ": error: " in line]
        self.assertEqual(len(errors), 1, message)
        for name in names:
            self.assertIn(str(name), errors[0], message)

    def assert_ok(self, result):
        self.assertEqual(result.returncode, 0, result.stderr.decode(errors="replace"))

    def leftovers(self, folder=None):
        folder = Path(folder or self.cwd)
        return sorted(p.name for p in folder.iterdir())

    def score_json(self, trace, character=YONG, *extra):
        result = self.cli("score", trace, "--character", character, "--json", "-", *extra)
        return result, (json.loads(result.stdout) if result.returncode == 0 else None)


class CharactersCases(UnseenCase):
    def characters(self, text):
        result = self.cli("characters", "--text", text, "--json")
        self.assert_ok(result)
        return json.loads(result.stdout)

    def test_text_with_lone_surrogate_bytes_is_a_usage_error(self):
        # The UTF-8 encoding of U+D800 (a surrogate, never valid UTF-8); argv carries bytes.
        result = subprocess.run([CLI, "characters", "--text", b"\xe6\xb0\xb8\xed\xa0\x80"], cwd=self.cwd,
                                stdout=subprocess.PIPE, stderr=subprocess.PIPE, timeout=TIMEOUT_S)
        self.assert_error(result, 2, "--text")

    def test_text_with_invalid_utf8_is_a_usage_error(self):
        result = subprocess.run([CLI, "characters", "--text", b"\xff\xfe"], cwd=self.cwd,
                                stdout=subprocess.PIPE, stderr=subprocess.PIPE, timeout=TIMEOUT_S)
        self.assert_error(result, 2, "--text")

    def test_combining_mark_is_named_not_found(self):
        listed = self.characters(YONG + "\u0301")
        self.assertEqual([c["character"] for c in listed["characters"]], [YONG])
        self.assertIn("\u0301", listed["not_found"])

    def test_variation_selector_keeps_the_character(self):
        listed = self.characters(YONG + "\U000E0100")
        self.assertEqual([c["character"] for c in listed["characters"]], [YONG])
        self.assertEqual(listed["count"], 1)

    def test_private_use_is_not_found(self):
        listed = self.characters("\ue000")
        self.assertEqual(listed["count"], 0)
        self.assertEqual(listed["not_found"], ["\ue000"])

    def test_control_character_in_text_is_not_found_and_table_stays_printable(self):
        listed = self.characters("\x1b[31m" + YONG)
        self.assertEqual([c["character"] for c in listed["characters"]], [YONG])
        self.assertIn("\x1b", listed["not_found"])
        table = self.cli("characters", "--text", "\x1b[31m" + YONG)
        self.assert_ok(table)
        self.assertNotIn(b"\x1b", table.stdout + table.stderr)

    def test_white_space_of_every_kind_is_skipped(self):
        listed = self.characters("永\u00a0我\u3000二\t\u2003八\u202f\u2028")
        self.assertEqual([c["character"] for c in listed["characters"]], ["永", "我", "二", "八"])
        self.assertEqual(listed["not_found"], [])

    def test_long_text_each_character_once(self):
        # Linux limits one argument to 128 KiB (MAX_ARG_STRLEN): a 10 MB argument never reaches the program.
        text = YONG * 40000  # 120,000 bytes
        listed = self.characters(text)
        self.assertEqual(listed["count"], 1)

    def test_stroke_counts_out_of_range_or_misspelt(self):
        for value in sample(["0", "256", "0x5", " 5", "5 ", "-0", "1e1", "+5", "٥"]):
            with self.subTest(value=value):
                self.assert_error(self.cli("characters", "--strokes", value), 2, "--strokes")

    def test_repeated_strokes_is_a_usage_error(self):
        self.assert_error(self.cli("characters", "--strokes", "5", "--strokes", "6"), 2, "--strokes")

    def test_unknown_typical_stroke_is_a_usage_error(self):
        for value in ("XYZ", "40", "0", "", "HZG\u0000"[:3] + "\u200b"):
            with self.subTest(value=value):
                self.assert_error(self.cli("characters", "--typical", value), 2, "--typical")

    def test_typical_stroke_by_its_cjk_character(self):
        by_char = self.cli("characters", "--typical", "㇆", "--strokes", "4", "--json")
        by_acronym = self.cli("characters", "--typical", "hzg", "--strokes", "4", "--json")
        self.assert_ok(by_char)
        self.assertEqual(json.loads(by_char.stdout), json.loads(by_acronym.stdout))

    def test_flag_given_a_value_is_a_usage_error(self):
        self.assert_error(self.cli("characters", "--json=yes"), 2, "--json")

    def test_json_into_closed_stdout_is_exit_1(self):
        result = self.cli("characters", "--text", YONG, "--json", close_stdout=True)
        self.assert_error(result, 1)


class ModelCases(UnseenCase):
    def test_svg_to_a_folder(self):
        (self.cwd / "d").mkdir()
        self.assert_error(self.cli("model", YONG, "--svg", "d"), 1, "--svg")
        self.assertEqual(self.leftovers(self.cwd / "d"), [])

    def test_svg_in_a_missing_folder(self):
        self.assert_error(self.cli("model", YONG, "--svg", "no/such/x.svg"), 1, "--svg", "no/such")
        self.assertEqual(self.leftovers(), [])

    def test_svg_to_dev_full(self):
        self.assert_error(self.cli("model", YONG, "--svg", "/dev/full"), 1, "/dev/full")

    def test_svg_over_an_input_character_file(self):
        data = self.cwd / "data"
        data.mkdir()
        shutil.copy(DATA / f"{YONG}.json", data / f"{YONG}.json")
        before = (data / f"{YONG}.json").read_bytes()
        result = self.cli("model", YONG, "--data", "data", "--svg", f"data/{YONG}.json")
        self.assert_error(result, 2, "--svg")
        self.assertEqual((data / f"{YONG}.json").read_bytes(), before)
        self.assertEqual(self.leftovers(data), [f"{YONG}.json"])

    def test_svg_through_a_symbolic_link(self):
        (self.cwd / "target.svg").write_text("old")
        os.symlink("target.svg", self.cwd / "link.svg")
        self.assert_ok(self.cli("model", YONG, "--svg", "link.svg"))
        self.assertTrue((self.cwd / "link.svg").is_symlink())
        self.assertIn("<svg", (self.cwd / "target.svg").read_text())

    def test_svg_through_a_dangling_link(self):
        os.symlink("made.svg", self.cwd / "link.svg")
        self.assert_ok(self.cli("model", YONG, "--svg", "link.svg"))
        self.assertTrue((self.cwd / "link.svg").is_symlink())
        self.assertIn("<svg", (self.cwd / "made.svg").read_text())

    def test_svg_over_the_file_size_limit_keeps_the_earlier_file(self):
        (self.cwd / "m.svg").write_text("earlier")
        result = self.cli("model", YONG, "--svg", "m.svg", limit_file_bytes=512)
        self.assert_error(result, 1, "m.svg")
        self.assertEqual((self.cwd / "m.svg").read_text(), "earlier")
        self.assertEqual(self.leftovers(), ["m.svg"])

    def test_svg_to_closed_stdout(self):
        self.assert_error(self.cli("model", YONG, "--svg", "-", close_stdout=True), 1)

    def test_json_into_a_broken_pipe(self):
        read_end, write_end = os.pipe()
        os.close(read_end)
        try:
            result = self.cli("model", YONG, "--json", stdout=write_end)
        finally:
            os.close(write_end)
        self.assertEqual(result.returncode, 1, result.stderr.decode(errors="replace"))
        self.assertIn(": error: ", result.stderr.decode(errors="replace"))

    def test_svg_without_its_value(self):
        for args in (["--svg"], ["--svg="]):
            with self.subTest(args=args):
                result = self.cli("model", YONG, *args)
                self.assert_error(result, 2, "--svg", "value")
                self.assertNotIn("  ", result.stderr.decode())
        self.assertEqual(self.leftovers(), [])

    def test_repeated_svg(self):
        self.assert_error(self.cli("model", YONG, "--svg=a.svg", "--svg=b.svg"), 2, "--svg")
        self.assertEqual(self.leftovers(), [])

    def test_character_the_library_lacks(self):
        result = self.cli("model", "\ue000")
        self.assertIn(result.returncode, (1, 2), result.stderr.decode(errors="replace"))
        self.assert_error(result, result.returncode, "U+E000")

    def test_data_and_store_exclude_each_other(self):
        self.assert_error(self.cli("model", YONG, "--data", DATA, "--store", "x.clg"), 2, "--data", "--store")


class ScoreCases(UnseenCase):
    def setUp(self):
        super().setUp()
        self.text = Shared.get().read_text()
        self.lines = self.text.splitlines()

    def write(self, name, text, mode="w", **kwargs):
        path = self.cwd / name
        with open(path, mode, **kwargs) as out:
            out.write(text)
        return path

    def reference(self):
        result, document = self.score_json(Shared.get())
        self.assert_ok(result)
        return document

    def data_line(self, index):
        """Line number (1-based, header is 1) of the index-th data row."""
        return index + 2

    def test_bom_and_crlf_score_as_the_plain_trace(self):
        plain = self.reference()
        trace = self.write("bom.csv", "\ufeff" + "\r\n".join(self.lines) + "\r\n", newline="")
        result, document = self.score_json(trace)
        self.assert_ok(result)
        for key in ("strokes_accepted", "mean_deviation_m", "frechet_m", "samples"):
            self.assertEqual(document[key], plain[key], key)

    def replace_value(self, row, column, value):
        header = self.lines[0].split(",")
        cells = self.lines[row + 1].split(",")
        cells[header.index(column)] = value
        lines = list(self.lines)
        lines[row + 1] = ",".join(cells)
        return "\n".join(lines) + "\n"

    def test_nan_and_inf_are_refused_naming_the_line(self):
        for column, value in (("x", "nan"), ("y", "inf"), ("t", "-inf"), ("z", "NaN")):
            with self.subTest(column=column, value=value):
                trace = self.write("bad.csv", self.replace_value(100, column, value))
                self.assert_error(self.score_json(trace)[0], 1, "bad.csv:102")

    def test_time_going_backwards_is_refused_naming_the_line(self):
        trace = self.write("back.csv", self.replace_value(200, "t", "0"))
        self.assert_error(self.score_json(trace)[0], 1, "back.csv:202")

    def test_duplicated_times_are_refused_or_scored_finite(self):
        header = self.lines[0].split(",")
        down = [i for i, line in enumerate(self.lines[1:]) if float(line.split(",")[header.index("z")]) <= 0.0004]
        row = down[len(down) // 2]  # while the pen writes: speeds and jerk divide by the time steps
        previous_t = self.lines[row].split(",")[header.index("t")]
        trace = self.write("dup.csv", self.replace_value(row, "t", previous_t))
        result, document = self.score_json(trace)
        if result.returncode == 0:
            self.assertEqual(document["samples"], len(self.lines) - 1)
            for stroke in document["per_character"][0]["per_stroke"]:
                for key in ("mean_speed_m_s", "normalised_jerk", "velocity_peaks", "mean_deviation_m"):
                    value = stroke.get(key)
                    self.assertTrue(value is None or math.isfinite(value), (key, value))
        else:
            self.assert_error(result, 1, f"dup.csv:{row + 2}")

    def test_trace_over_the_size_limit_is_refused_unread(self):
        trace = self.cwd / "huge.csv"
        with open(trace, "wb") as out:
            out.write(("\n".join(self.lines[:3]) + "\n").encode())
            out.truncate(257 * 1024 * 1024)  # sparse: no disk space used
        self.assert_error(self.score_json(trace)[0], 1, "huge.csv")

    def test_renamed_columns_are_named_missing(self):
        header = self.lines[0].replace("t,", "time,", 1)
        trace = self.write("renamed.csv", "\n".join([header, *self.lines[1:]]) + "\n")
        self.assert_error(self.score_json(trace)[0], 1, "renamed.csv", "t")

    def test_columns_in_millimetres_are_named_missing(self):
        header = "t,x_mm,y_mm,z_mm"
        rows = [",".join(line.split(",")[:4]) for line in self.lines[1:]]
        trace = self.write("mm.csv", "\n".join([header, *rows]) + "\n")
        self.assert_error(self.score_json(trace)[0], 1, "mm.csv")

    def test_trace_of_another_character_is_not_accepted_whole(self):
        own = self.reference()
        self.assertEqual(own["strokes_accepted"], 5)
        result, other = self.score_json(Shared.get(), "我")
        self.assert_ok(result)
        self.assertLess(other["strokes_accepted"], 7)

    def test_header_only_trace(self):
        trace = self.write("empty.csv", self.lines[0] + "\n")
        result, document = self.score_json(trace)
        if result.returncode == 0:
            self.assertEqual(document["samples"], 0)
            self.assertEqual(document["strokes_accepted"], 0)
        else:
            self.assert_error(result, 1, "empty.csv")

    def test_empty_file(self):
        trace = self.write("zero.csv", "")
        self.assert_error(self.score_json(trace)[0], 1, "zero.csv")

    def test_trace_is_a_folder(self):
        (self.cwd / "dir.csv").mkdir()
        self.assert_error(self.score_json("dir.csv")[0], 1, "dir.csv")

    def test_cut_gzip_trace(self):
        packed = gzip.compress(self.text.encode())
        trace = self.write("cut.csv.gz", packed[: len(packed) // 2], mode="wb")
        self.assert_error(self.score_json(trace)[0], 1, "cut.csv.gz")

    def test_json_over_the_trace_is_refused_and_the_trace_kept(self):
        trace = self.write("t.csv", self.text)
        result = self.cli("score", "t.csv", "--character", YONG, "--json", "t.csv")
        self.assert_error(result, 2, "--json")
        self.assertEqual(trace.read_text(), self.text)
        self.assertEqual(self.leftovers(), ["t.csv"])

    def test_unknown_units(self):
        self.assert_error(self.cli("score", Shared.get(), "--character", YONG, "--units", "mm"), 2, "--units")

    def test_json_to_closed_stdout(self):
        result = self.cli("score", Shared.get(), "--character", YONG, "--json", "-", close_stdout=True)
        self.assert_error(result, 1)


class TraceCases(UnseenCase):
    def test_foreign_file(self):
        (self.cwd / "a.trace.h5").write_bytes(b"\x89PNG\r\n\x1a\n" + bytes(200))
        self.assert_error(self.cli("trace", "a.trace.h5"), 1, "a.trace.h5")

    def test_device_or_folder_is_named_as_what_it_is(self):
        self.assert_error(self.cli("trace", "/dev/zero"), 1, "/dev/zero", "not a regular file")
        (self.cwd / "d.trace.h5").mkdir()
        self.assert_error(self.cli("trace", "d.trace.h5"), 1, "d.trace.h5", "not a regular file")
        self.assert_error(self.cli("score", "/dev/zero", "--character", YONG), 1, "/dev/zero", "not a regular file")

    def test_empty_file(self):
        (self.cwd / "a.trace.h5").write_bytes(b"")
        self.assert_error(self.cli("trace", "a.trace.h5"), 1, "a.trace.h5")

    @unittest.skipIf(h5py is None, "h5py is not installed")
    def test_hdf5_of_wrong_dtype_and_cut(self):
        path = self.cwd / "w.trace.h5"
        with h5py.File(path, "w") as f:
            for name in ("t", "x", "y", "z"):
                f.create_dataset(name, data=np.array([b"a", b"b", b"c"]))
        self.assert_error(self.cli("trace", path.name), 1, path.name)
        foreign = self.cwd / "f.trace.h5"
        with h5py.File(foreign, "w") as f:
            f.create_dataset("something", data=np.arange(10.0))
        self.assert_error(self.cli("trace", foreign.name), 1, foreign.name)
        data = foreign.read_bytes()
        (self.cwd / "cut.trace.h5").write_bytes(data[: len(data) // 2])
        self.assert_error(self.cli("trace", "cut.trace.h5"), 1, "cut.trace.h5")

    def test_csv_over_its_input(self):
        (self.cwd / "a.trace.h5").write_bytes(b"keep")
        result = self.cli("trace", "a.trace.h5", "--csv", "a.trace.h5")
        self.assert_error(result, 2, "--csv")
        self.assertEqual((self.cwd / "a.trace.h5").read_bytes(), b"keep")


class TrialOptionCases(UnseenCase):
    def check(self, *options):
        return self.cli("trial", YONG, "--check", *options)

    def test_numbers_in_other_spellings(self):
        cases = [("--seed", "0x10"), ("--seed", "1e3"), ("--seed", " 7"), ("--seed", "18446744073709551616"),
                 ("--max-duration", "1e999"), ("--max-duration", "-0"), ("--max-duration", "0"),
                 ("--max-duration", "nan"), ("--guidance-stiffness", "1,5"), ("--guidance-stiffness", " 400"),
                 ("--guidance-stiffness", "400 "), ("--guidance-stiffness", "0x1p8"), ("--rate", "99"),
                 ("--guidance-stiffness", "-1"), ("--rate", "１０００")]
        for option, value in sample(cases):
            with self.subTest(option=option, value=value):
                self.assert_error(self.check(f"{option}={value}"), 2, option)

    def test_refused_number_is_not_called_infinite(self):
        for value in ("+400", " 400", "0x190"):
            with self.subTest(value=value):
                result = self.check(f"--guidance-stiffness={value}")
                self.assert_error(result, 2, "--guidance-stiffness", "decimal")

    def test_repeated_option(self):
        self.assert_error(self.check("--seed", "3", "--seed", "4"), 2, "--seed")

    def test_option_of_another_command(self):
        self.assert_error(self.check("--units", "m"), 2, "--units")
        self.assert_error(self.check("--typical", "HZG"), 2, "--typical")

    def test_option_that_does_not_go_with_spec(self):
        record = self.cwd / "r.json"
        self.assert_ok(self.cli("trial", "乙", "--json", record))
        self.assert_error(self.cli("trial", "--spec", record, "--seed", "3", "--check"), 2, "--seed")

    def test_value_that_is_an_option(self):
        self.assert_error(self.cli("trial", YONG, "--json", "--seed", "3"), 2, "--json")
        self.assertEqual(self.leftovers(), [])

    def test_json_to_dev_full(self):
        self.assert_error(self.cli("trial", "乙", "--json", "/dev/full"), 1, "/dev/full")


class OtherCommandCases(UnseenCase):
    def test_schema_to_dev_full(self):
        with open("/dev/full", "wb") as full:
            result = self.cli("schema", "record", stdout=full)
        self.assert_error(result, 1)

    def test_schema_markdown_to_closed_stdout(self):
        self.assert_error(self.cli("schema", "metrics", "--markdown", close_stdout=True), 1)

    def test_unknown_schema(self):
        result = self.cli("schema", "recrod")
        self.assertEqual(result.returncode, 2, result.stderr.decode(errors="replace"))
        self.assertIn("recrod", result.stderr.decode(errors="replace"))

    def test_devices_json_to_closed_stdout(self):
        self.assert_error(self.cli("devices", "--json", close_stdout=True), 1)

    def test_devices_json_into_a_broken_pipe(self):
        read_end, write_end = os.pipe()
        os.close(read_end)
        try:
            result = self.cli("devices", "--json", stdout=write_end)
        finally:
            os.close(write_end)
        self.assertEqual(result.returncode, 1, result.stderr.decode(errors="replace"))

    def test_bench_markdown_to_dev_full(self):
        result = self.cli("bench", "jumps", "--seeds", "1", "--chars", "乙", "--markdown", "/dev/full")
        self.assert_error(result, 1, "/dev/full")

    def test_bench_markdown_under_a_file_size_limit(self):
        (self.cwd / "b.md").write_text("# earlier\n")
        result = self.cli("bench", "jumps", "--seeds", "1", "--chars", "乙", "--markdown", "b.md",
                          limit_file_bytes=64)
        self.assert_error(result, 1, "b.md")
        self.assertEqual((self.cwd / "b.md").read_text(), "# earlier\n")
        self.assertEqual(self.leftovers(), ["b.md"])

    def test_bench_queries_out_of_range(self):
        for value in ("0", "100000001", "1e3"):
            with self.subTest(value=value):
                self.assert_error(self.cli("bench", "nearest", "--queries", value), 2, "--queries")


@unittest.skipIf(cg is None, "the calligraphy Python package (PYTHONPATH) or numpy is missing")
class PythonCases(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.trial = cg.simulate_trial(YONG, writer="skilled", seed=3)
        p = cls.trial.position_m
        cls.columns = {"t": cls.trial.time_s, "x": p[:, 0], "y": p[:, 1], "z": p[:, 2]}
        cls.reference = cg.score(cls.columns, YONG)

    def test_simulate_trial_wrong_types(self):
        with self.assertRaises(TypeError) as caught:
            cg.simulate_trial(YONG, rate_hz="fast")
        self.assertIn("rate_hz", str(caught.exception))
        with self.assertRaises(TypeError):
            cg.simulate_trial(12345)

    def test_simulate_trial_characters_of_wrong_kinds(self):
        with self.assertRaises(TypeError) as caught:
            cg.simulate_trial([YONG, 3])
        self.assertIn("characters[0]", str(caught.exception))
        with self.assertRaises(ValueError) as caught:
            cg.simulate_trial("\ud800")
        self.assertIn("characters", str(caught.exception))

    def test_simulate_trial_nan_and_negative(self):
        for name, value in (("rate_hz", float("nan")), ("max_duration_s", float("nan")),
                            ("max_duration_s", -1.0), ("rate_hz", float("inf"))):
            with self.subTest(name=name, value=value):
                with self.assertRaises(ValueError) as caught:
                    cg.simulate_trial(YONG, **{name: value})
                self.assertIn(name, str(caught.exception))

    def test_simulate_trial_seed_out_of_range(self):
        for seed in (-1, 2**64):
            with self.subTest(seed=seed):
                with self.assertRaises(ValueError) as caught:
                    cg.simulate_trial(YONG, seed=seed)
                self.assertIn("seed", str(caught.exception))

    def same_score(self, columns):
        result = cg.score(columns, YONG)
        self.assertEqual(result["strokes_accepted"], self.reference["strokes_accepted"])
        self.assertAlmostEqual(result["mean_deviation_m"], self.reference["mean_deviation_m"], delta=1e-6)

    def test_score_float32_columns(self):
        self.same_score({k: v.astype(np.float32) for k, v in self.columns.items()})

    def test_score_non_contiguous_columns(self):
        p = np.asfortranarray(self.trial.position_m)  # columns of a Fortran array are contiguous; rows are not
        strided = {"t": np.repeat(self.trial.time_s, 2)[::2], "x": p[:, 0], "y": p[:, 1],
                   "z": self.trial.position_m[:, 2]}
        self.assertFalse(strided["t"].flags["C_CONTIGUOUS"])
        self.same_score(strided)

    def test_score_object_arrays(self):
        columns = {k: v.astype(object) for k, v in self.columns.items()}
        try:
            result = cg.score(columns, YONG)
        except (TypeError, ValueError) as error:
            self.assertRegex(str(error), "t|x|y|z")
        else:
            self.assertEqual(result["strokes_accepted"], self.reference["strokes_accepted"])

    def test_score_string_array_is_a_type_error(self):
        columns = dict(self.columns, x=np.array(["a"] * len(self.columns["x"])))
        with self.assertRaises((TypeError, ValueError)) as caught:
            cg.score(columns, YONG)
        self.assertIn("x", str(caught.exception))

    def test_score_nan_is_refused_naming_the_sample(self):
        x = self.columns["x"].copy()
        x[100] = np.nan
        with self.assertRaises(ValueError) as caught:
            cg.score(dict(self.columns, x=x), YONG)
        self.assertIn("100", str(caught.exception))

    def test_score_columns_of_different_lengths(self):
        with self.assertRaises(ValueError) as caught:
            cg.score(dict(self.columns, y=self.columns["y"][:-1]), YONG)
        self.assertIn("y", str(caught.exception))

    def test_score_two_dimensional_column(self):
        with self.assertRaises(ValueError) as caught:
            cg.score(dict(self.columns, x=self.trial.position_m), YONG)
        self.assertIn("x", str(caught.exception))

    def test_score_missing_column(self):
        columns = dict(self.columns)
        del columns["t"]
        with self.assertRaises(ValueError) as caught:
            cg.score(columns, YONG)
        self.assertIn("t", str(caught.exception))

    def test_score_too_many_samples(self):
        n = 1_000_001
        columns = {"t": np.arange(n) * 1e-3, "x": np.zeros(n), "y": np.zeros(n), "z": np.ones(n)}
        with self.assertRaises(ValueError) as caught:
            cg.score(columns, YONG)
        self.assertIn("1,000,000", str(caught.exception).replace("1000000", "1,000,000"))

    def test_score_dataframe_of_the_trial(self):
        frame = self.trial.to_dataframe()
        result = cg.score(frame, YONG)
        self.assertEqual(result["strokes_accepted"], self.reference["strokes_accepted"])

    def test_score_units_and_paths(self):
        with self.assertRaises(ValueError) as caught:
            cg.score(self.columns, YONG, units="mm")
        self.assertIn("units", str(caught.exception))
        self.assertIn("'m'", str(caught.exception))
        trace = str(Shared.get())
        by_bytes = cg.score(os.fsencode(trace), YONG)
        self.assertEqual(by_bytes["strokes_accepted"], cg.score(Path(trace), YONG)["strokes_accepted"])

    def test_load_wrong_types_and_text(self):
        library = cg.CharacterLibrary.default()
        with self.assertRaises(TypeError):
            library.load(0x6C38)
        for text in ("", "永永", "\ue000", "\ud800"):
            with self.subTest(text=text):
                with self.assertRaises((ValueError, KeyError)):
                    library.load(text)


if __name__ == "__main__":
    unittest.main()
