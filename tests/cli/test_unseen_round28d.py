#!/usr/bin/env python3
"""Round 28D: every file one command writes, read by every other, and forged on the way. From the docs alone
(docs/cli.md: "Outputs", "Checked before anything runs", "Standard output", `trial` and its `--json`/`--csv`,
"Re-running a trial", `score` and "Pen traces: format and limits", `trace`; docs/experiments.md "Sessions",
"Trace files", "Trial records"; docs/python.md "Scoring any pen trace", "Running a trial again", "A study's
traces"; include/calligraphy/report/pen_trace_csv.hpp and trace_hdf5.hpp's comments).

Written: `trial 十 --json --csv`, a replay's record bound to its teacher's SHA-256, a session of two trials
(十, 二) with their `.trace.h5` and records naming each trace's SHA-256, `trace`'s CSV of them. Read back by
every reader that takes each (`score` of the CSV, its gzip, the HDF5 trace, a trace renamed; `trial --spec`
of a `trial --json` record and of a session's record; `trace`; `report --out`; Python's `score`,
`check_trial_record`, `rerun_trial`, `study.load(...).samples`; h5py), the numbers compared with what the test
computes itself. Then forged as an outsider would: cut at half, junk appended, a byte flipped, a sample edited
with h5py (and its user block's length and CRC-32 made to match again), another program's HDF5 layout, an
attribute, filter, byte order or external link forged; two records' traces swapped, or each record edited to
name the other's trace with its SHA-256; a teacher replaced or removed (a `trial --json` replay and a
session's); a CSV with its columns reordered, duplicated, named with units, quoted, with CR LF and a BOM,
comments and padding, `pen` spelt as numpy writes it, a NUL, a time going back, a position of 1e308 or nan; a
record with numbers spelt as JSON allows; outputs that are inputs (the same path, `./` spellings, symbolic and
hard links, a teacher the record names, a session's record or trace under `report --out`), an output in a
folder that does not exist, a folder as output, links as outputs, a 254-byte name, `/dev/full`, the file size
limit, `/dev/stdout` on a file, a closed standard output, `| head -1`, standard input as an input. Each refusal is one line naming the file (and the line or
the JSON pointer), with the documented status; inputs are compared byte for byte and no temporary is left.

CALLIGRAPHY_CLI names the program; PYTHONPATH the built Python package. CALLIGRAPHY_SANITIZED=1 takes five cases.
"""
import gzip
import hashlib
import json
import os
import shutil
import subprocess
import tempfile
import unittest
from pathlib import Path

from outsider import CLI, ENV, OneErrorLine, error_lines, run, run_ok, sanitized_subset

try:
    import calligraphy as cg
    import calligraphy.study as cg_study
except ImportError:  # reported by setUpClass
    cg = cg_study = None
try:
    import h5py
except ImportError:
    h5py = None

load_tests = sanitized_subset({"test_trace_csv_of_a_session_trace_is_its_record_re_run_byte_for_byte",
                               "test_trace_cut_at_half_is_refused_naming_it_and_writes_nothing",
                               "test_spec_record_cut_at_half_is_refused_naming_the_file_and_byte",
                               "test_output_that_is_an_input_is_refused_in_every_spelling",
                               "test_score_csv_with_columns_reordered_scores_the_same"})

PROTOCOL = {"name": "p", "conditions": [{"name": "h", "mode": "haptic"}],
            "test": {"characters": ["十", "二"], "conditions": ["h"], "repetitions": 1},
            "trial": {"max_duration_s": 20}}
# Keys of score --json that name the file read rather than what it holds.
FILE_KEYS = ("trace",)
COUNT_KEYS = ("strokes_total", "strokes_written", "strokes_accepted", "strokes_assisted", "order_errors",
              "backwards_strokes", "unmatched_segments", "velocity_peaks")
LENGTH_KEYS = ("mean_deviation_m", "max_deviation_m", "rms_deviation_m", "frechet_m", "dtw_m")
TIME_KEYS = ("total_time_s", "pen_down_time_s")


def sha(path):
    return hashlib.sha256(Path(path).read_bytes()).hexdigest()


def snapshot(folder):
    """Every file under `folder` (links as their targets' names): {relative path: bytes}."""
    out = {}
    for p in sorted(Path(folder).rglob("*")):
        if p.is_symlink():
            out[str(p.relative_to(folder))] = ("link", os.readlink(p))
        elif p.is_file():
            out[str(p.relative_to(folder))] = p.read_bytes()
    return out


def temporaries(folder):
    return [p.name for p in Path(folder).rglob(".*") if ".tmp-" in p.name]


def text(value):
    """An HDF5 string attribute as h5py gives it (str or bytes) as str."""
    return value.decode("utf-8") if isinstance(value, bytes) else str(value)


def without_file_keys(scored):
    return {k: v for k, v in scored.items() if k not in FILE_KEYS}


class Round28D(unittest.TestCase, OneErrorLine):
    @classmethod
    def setUpClass(cls):
        if not CLI:
            raise unittest.SkipTest("CALLIGRAPHY_CLI is not set")
        cls.tmp = Path(tempfile.mkdtemp(prefix="round28d-"))
        d = cls.tmp
        run_ok(["trial", "十", "--seed", "3", "--json", "t.json", "--csv", "t.csv"], d)
        (d / "p.json").write_text(json.dumps(PROTOCOL), encoding="utf-8")
        run_ok(["session", "run", "p.json", "--writer", "simulated", "--subjects", "1", "--out", "S"], d)
        cls.session = next((d / "S" / "S01").iterdir())
        trials = cls.session / "trials"
        cls.records = sorted(trials.glob("*.json"))  # 001 (十), 002 (二)
        cls.h5 = [r.with_name(r.name[:-len(".json")] + ".trace.h5") for r in cls.records]
        run_ok(["trace", cls.h5[0], "--csv", "h.csv"], d)
        cls.scores = {}

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.tmp, ignore_errors=True)

    @classmethod
    def teachers(cls):
        """Two teacher's recordings of 十 (skilled, seeds 0 and 1), made once: (teacher.json, other.json)."""
        if not hasattr(cls, "_teachers"):
            d = cls.tmp / "teachers"
            d.mkdir()
            run_ok(["trial", "十", "--writer-profile", "skilled", "--record", "teacher.json"], d)
            run_ok(["trial", "十", "--writer-profile", "skilled", "--seed", "1", "--record", "other.json"], d)
            cls._teachers = d / "teacher.json", d / "other.json"
        return cls._teachers

    def cli(self, *args, **kw):
        return run(list(args), self.tmp, **kw)

    def score_json(self, trace, character="十"):
        key = (str(trace), character)
        if key not in self.scores:
            out = run_ok(["score", trace, "--character", character, "--json", "-"], self.tmp)
            self.scores[key] = json.loads(out.stdout)
        return self.scores[key]

    def copy_study(self, name):
        target = self.tmp / name
        shutil.copytree(self.tmp / "S", target, symlinks=True)
        session = next((target / "S01").iterdir())
        return target, session

    def assert_metrics_equal_to_trace_precision(self, got, want):
        for key in COUNT_KEYS:
            self.assertEqual(got[key], want[key], key)
        for key in LENGTH_KEYS:
            self.assertAlmostEqual(got[key], want[key], delta=2e-7, msg=key)
        for key in TIME_KEYS:
            self.assertAlmostEqual(got[key], want[key], delta=2e-6, msg=key)

    # ---- round trips ---------------------------------------------------------------------------------
    def test_trace_csv_of_a_session_trace_is_its_record_re_run_byte_for_byte(self):
        # cli.md `trace`: "the same text, byte for byte, as `trial --csv` of that trial would have written";
        # "Re-running a trial": every trial of a session re-runs to the same CSV byte for byte.
        for record, h5 in zip(self.records, self.h5):
            with self.subTest(record=record.name):
                out = self.tmp / f"rerun-{record.stem}.csv"
                result = self.cli("trial", "--spec", record, "--csv", out)
                self.assertEqual(result.returncode, 0, result.stderr)
                traced = run_ok(["trace", h5], self.tmp).stdout
                self.assertEqual(out.read_bytes(), traced)

    def test_trace_to_standard_output_dash_file_and_dev_stdout_are_the_same_bytes(self):
        want = (self.tmp / "h.csv").read_bytes()
        self.assertEqual(run_ok(["trace", self.h5[0]], self.tmp).stdout, want)
        self.assertEqual(run_ok(["trace", self.h5[0], "--csv", "-"], self.tmp).stdout, want)
        # cli.md "Outputs": `/dev/stdout` on a pipe: "the file goes into it".
        self.assertEqual(run_ok(["trace", self.h5[0], "--csv", "/dev/stdout"], self.tmp).stdout, want)

    def test_trace_file_attributes_and_sha256_are_what_the_record_and_tables_state(self):
        if h5py is None:
            self.skipTest("h5py is needed")
        study = cg_study.load(str(self.tmp / "S"))
        for i, (record_path, h5) in enumerate(zip(self.records, self.h5)):
            with self.subTest(trace=h5.name):
                record = json.loads(record_path.read_text(encoding="utf-8"))
                self.assertEqual(record["files"]["trace"], h5.name)
                self.assertEqual(record["files"]["trace_sha256"], sha(h5))
                row = study.trials[study.trials["trial"] == i + 1].iloc[0]
                self.assertEqual(row["trace_sha256"], sha(h5))
                self.assertIn(b"calligraphy-trace", h5.read_bytes()[:512])
                with h5py.File(h5, "r") as f:
                    attrs = dict(f.attrs)
                    self.assertEqual(text(attrs["format"]), "calligraphy-trace")
                    self.assertEqual(int(attrs["version"]), 1)
                    self.assertEqual(int(attrs["samples"]), record["samples"])
                    for column, decimals, unit in (("t", 6, "s"), ("x", 7, "m"), ("z", 7, "m"), ("fy", 4, "N")):
                        a = f[column].attrs
                        self.assertEqual(int(a["decimals"]), decimals, column)
                        self.assertEqual(text(a["unit"]), unit, column)
                        self.assertEqual(len(f[column]), record["samples"], column)

    def test_h5py_study_samples_and_the_csv_text_give_the_same_doubles(self):
        # experiments.md: "integer / 10^decimals is, bit for bit, the double its text reads to"; python.md:
        # `f["x"][()] / 10 ** f["x"].attrs["decimals"]` being `samples["x_m"]` bit for bit.
        if h5py is None:
            self.skipTest("h5py is needed")
        lines = (self.tmp / "h.csv").read_text(encoding="utf-8").splitlines()
        header = lines[0].split(",")
        table = list(zip(*(line.split(",") for line in lines[1:])))
        rows = {name: table[i] for i, name in enumerate(header)}
        samples = cg_study.load(str(self.tmp / "S")).samples(0)
        self.assertEqual(len(samples), len(lines) - 1)
        with h5py.File(self.h5[0], "r") as f:
            for column in ("t", "x", "z", "fy"):
                with self.subTest(column=column):
                    from_h5 = (f[column][()] / 10 ** f[column].attrs["decimals"]).tolist()
                    from_text = [float(v) for v in rows[column]]
                    name = {"t": "t_s", "fx": "fx_n", "fy": "fy_n", "fz": "fz_n"}.get(column, column + "_m")
                    from_study = samples[name].tolist()
                    self.assertEqual(from_h5, from_text)
                    self.assertEqual(from_study, from_text)
        self.assertEqual(samples["state"].astype(str).tolist(), list(rows["state"]))
        self.assertEqual(samples["stroke"].tolist(), [int(v) for v in rows["stroke"]])
        self.assertEqual(samples["attempt"].tolist(), [int(v) for v in rows["attempt"]])

    def test_score_of_the_h5_its_csv_and_their_gzip_agree_and_give_the_record(self):
        gz = self.tmp / "h.csv.gz"
        gz.write_bytes(gzip.compress((self.tmp / "h.csv").read_bytes(), compresslevel=1))
        from_h5 = without_file_keys(self.score_json(self.h5[0]))
        self.assertEqual(without_file_keys(self.score_json("h.csv")), from_h5)
        self.assertEqual(without_file_keys(self.score_json("h.csv.gz")), from_h5)
        record = json.loads(self.records[0].read_text(encoding="utf-8"))
        self.assertEqual(from_h5["samples"], record["samples"])
        self.assert_metrics_equal_to_trace_precision(from_h5, record)

    def test_trial_json_is_what_score_and_python_score_give_for_its_csv(self):
        record = json.loads((self.tmp / "t.json").read_text(encoding="utf-8"))
        cli = self.score_json("t.csv")
        self.assert_metrics_equal_to_trace_precision(cli, record)
        py = cg.score(str(self.tmp / "t.csv"), "十")
        for key in set(py) & set(cli) - set(FILE_KEYS):
            self.assertEqual(py[key], cli[key], key)
        for key in COUNT_KEYS + LENGTH_KEYS + TIME_KEYS + ("per_character",):
            self.assertIn(key, py)

    def test_trial_spec_of_its_json_and_of_the_json_rewritten_give_the_csv_byte_for_byte(self):
        # "Re-running a trial": in any layout, key order or escaping; cli.md "Pen traces": the JSON files a
        # person may edit skip a BOM and CR LF as a trace does.
        record = json.loads((self.tmp / "t.json").read_text(encoding="utf-8"))
        text = json.dumps(record, indent=1, sort_keys=True, ensure_ascii=True).replace("\n", "\r\n")
        (self.tmp / "t-crlf.json").write_bytes(b"\xef\xbb\xbf" + text.encode("utf-8"))
        for name in ("t.json", "t-crlf.json"):
            with self.subTest(record=name):
                out = self.tmp / f"again-{name}.csv"
                result = self.cli("trial", "--spec", name, "--csv", out)
                self.assertEqual(result.returncode, 0, result.stderr)
                self.assertEqual(out.read_bytes(), (self.tmp / "t.csv").read_bytes())

    # ---- forged HDF5 traces --------------------------------------------------------------------------
    def forged_h5(self, name, change):
        data = bytearray(self.h5[0].read_bytes())
        path = self.tmp / name
        path.write_bytes(bytes(change(data)))
        return path

    def test_trace_cut_at_half_is_refused_naming_it_and_writes_nothing(self):
        cut = self.forged_h5("cut.trace.h5", lambda b: b[:len(b) // 2])
        before = cut.read_bytes()
        (self.tmp / "kept.csv").write_text("kept\n", encoding="utf-8")
        self.assert_one_error(self.cli("trace", cut, "--csv", "new.csv"), 1, "cut.trace.h5")
        self.assertFalse((self.tmp / "new.csv").exists())
        self.assert_one_error(self.cli("trace", cut, "--csv", "kept.csv"), 1, "cut.trace.h5")
        self.assertEqual((self.tmp / "kept.csv").read_text(encoding="utf-8"), "kept\n")
        self.assert_one_error(self.cli("score", cut, "--character", "十"), 1, "cut.trace.h5")
        self.assertEqual(cut.read_bytes(), before)
        self.assertEqual(temporaries(self.tmp), [])

    def test_trace_with_junk_appended_or_a_byte_flipped_is_refused_naming_it(self):
        def flip(b):
            b[len(b) * 3 // 4] ^= 0xFF
            return b
        for name, change in (("junk.trace.h5", lambda b: b + b"junk junk junk\n"), ("flip.trace.h5", flip)):
            with self.subTest(name=name):
                path = self.forged_h5(name, change)
                self.assert_one_error(self.cli("trace", path), 1, name)
                self.assert_one_error(self.cli("score", path, "--character", "十", "--json", "-"), 1, name)

    def test_trace_sample_edited_with_h5py_is_refused_by_every_reader(self):
        if h5py is None:
            self.skipTest("h5py is needed")
        study, session = self.copy_study("SE")
        h5 = session / "trials" / self.h5[0].name
        before = h5.read_bytes()
        with h5py.File(h5, "r+") as f:
            x = f["x"][()]
            x[100] += 1000  # 0.1 mm
            f["x"][...] = x
        self.assertNotEqual(h5.read_bytes(), before)
        self.assert_one_error(self.cli("score", h5, "--character", "十"), 1, h5.name)
        self.assert_one_error(self.cli("trace", h5, "--csv", "edited.csv"), 1, h5.name)
        self.assertFalse((self.tmp / "edited.csv").exists())
        loaded = cg_study.load(str(study))
        with self.assertRaises(cg.DataError) as caught:
            loaded.samples(0)
        self.assertIn(h5.name, str(caught.exception))
        self.assert_one_error(self.cli("report", study, "--out", "SE.html"), 1, h5.name)
        self.assertEqual(temporaries(self.tmp), [])

    def test_two_records_traces_swapped_are_refused_naming_the_trace(self):
        # experiments.md "Trial records": `report`, `study_report` and `Study.samples` "refuse a trace that is
        # not the one its record names, naming both".
        study, session = self.copy_study("SW")
        a, b = (session / "trials" / h.name for h in self.h5)
        a_bytes, b_bytes = a.read_bytes(), b.read_bytes()
        a.write_bytes(b_bytes)
        b.write_bytes(a_bytes)
        before = snapshot(session / "trials")
        loaded = cg_study.load(str(study))
        for index, trace in ((0, a), (1, b)):
            with self.subTest(trace=trace.name):
                with self.assertRaises(cg.DataError) as caught:
                    loaded.samples(index)
                message = str(caught.exception)
                self.assertIn(trace.name, message)
                record = self.records[index]
                self.assertTrue(record.name in message or sha(self.h5[index]) in message, message)
        line = self.assert_one_error(self.cli("report", study, "--out", "SW.html"), 1)
        self.assertTrue(a.name in line or b.name in line, line)
        self.assertEqual(snapshot(session / "trials"), before)
        self.assertEqual(temporaries(self.tmp), [])

    def test_h5_renamed_csv_and_csv_renamed_h5_are_read_by_their_first_bytes(self):
        # pen_trace_csv.hpp: "an HDF5 trace, gzip or plain CSV, by their first bytes".
        as_csv = self.tmp / "renamed.csv"
        shutil.copyfile(self.h5[0], as_csv)
        self.assertEqual(without_file_keys(self.score_json(as_csv)), without_file_keys(self.score_json(self.h5[0])))
        self.assertEqual(run_ok(["trace", as_csv], self.tmp).stdout, (self.tmp / "h.csv").read_bytes())
        as_h5 = self.tmp / "renamed.trace.h5"
        shutil.copyfile(self.tmp / "h.csv", as_h5)
        self.assertEqual(without_file_keys(self.score_json(as_h5)), without_file_keys(self.score_json("h.csv")))
        # `trace`: "A damaged, cut or foreign file is refused naming it (exit 1)": CSV text in a .trace.h5 is
        # either refused so, or written back as the CSV it is.
        result = self.cli("trace", as_h5)
        if result.returncode == 0:
            self.assertEqual(result.stdout, (self.tmp / "h.csv").read_bytes())
        else:
            self.assert_one_error(result, 1, "renamed.trace.h5")

    def test_a_record_given_as_a_trace_and_a_trace_as_a_record_are_named_for_what_they_are(self):
        # cli.md: "A file of another kind given where JSON is read (a trace CSV, its gzip, a `.trace.h5` ...)
        # is named for what its first bytes show, with the same exit status as malformed JSON" (2 for --spec).
        gz = self.tmp / "t.csv.gz"
        gz.write_bytes(gzip.compress((self.tmp / "t.csv").read_bytes(), compresslevel=1))
        for given in (self.h5[0], self.tmp / "t.csv", gz):
            with self.subTest(spec=given.name):
                line = self.assert_one_error(self.cli("trial", "--spec", given, "--check"), 2, given.name)
                self.assertIn("not a JSON document", line)
                with self.assertRaises(cg.DataError) as caught:
                    cg.check_trial_record(str(given))
                self.assertIn(given.name, str(caught.exception))
        self.assertIn("CSV", error_lines(self.cli("trial", "--spec", "t.csv", "--check"))[0])
        self.assert_one_error(self.cli("trace", "t.json"), 1, "t.json")
        self.assert_one_error(self.cli("score", "t.json", "--character", "十"), 1, "t.json")

    # ---- forged CSV traces ---------------------------------------------------------------------------
    def csv_rows(self, name="t.csv"):
        text = (self.tmp / name).read_text(encoding="utf-8")
        return text.splitlines()

    def write(self, name, data):
        path = self.tmp / name
        path.write_bytes(data if isinstance(data, bytes) else data.encode("utf-8"))
        return path

    def test_score_csv_with_columns_reordered_scores_the_same(self):
        # pen_trace_csv.hpp: "Columns are found by header name (others are ignored, order is free)".
        table = [line.split(",") for line in self.csv_rows()]
        order = [3, 11, 1, 7, 0, 2, 4, 5, 6, 8, 9, 10]
        text = "\n".join(",".join(row[i] for i in order) for row in table) + "\n"
        self.write("reordered.csv", text)
        self.assertEqual(without_file_keys(self.score_json("reordered.csv")),
                         without_file_keys(self.score_json("t.csv")))

    def test_score_csv_named_by_units_columns_scores_the_same(self):
        # cli.md: each trace column "by its file name or by its name in the trace column table (t_s, x_m, ...)".
        lines = self.csv_rows()
        header = ",".join({"t": "t_s", "x": "x_m", "y": "y_m", "z": "z_m", "fx": "fx_n", "fy": "fy_n",
                           "fz": "fz_n"}.get(c, c) for c in lines[0].split(","))
        self.write("units.csv", "\n".join([header] + lines[1:]) + "\n")
        self.assertEqual(without_file_keys(self.score_json("units.csv")),
                         without_file_keys(self.score_json("t.csv")))

    def test_score_csv_with_a_column_twice_or_under_both_names_is_refused_naming_it(self):
        lines = self.csv_rows()
        x = [line.split(",")[1] for line in lines[1:]]
        for name, extra in (("dup-x.csv", "x"), ("dup-x-m.csv", "x_m")):
            with self.subTest(header=extra):
                text = "\n".join([lines[0] + "," + extra] + [f"{l},{v}" for l, v in zip(lines[1:], x)]) + "\n"
                self.write(name, text)
                line = self.assert_one_error(self.cli("score", name, "--character", "十"), 1, name)
                self.assertIn(extra, line.split(name, 1)[1])
                with self.assertRaises(cg.DataError):
                    cg.score(str(self.tmp / name), "十")

    def test_score_csv_in_other_units_by_header_is_refused_naming_the_missing_column(self):
        # Only `x` or `x_m` name the column; `x_mm` is another column, ignored: x is then missing.
        lines = self.csv_rows()
        header = lines[0].replace("t,x,y,z,", "t,x_mm,y_mm,z_mm,", 1)
        rows = []
        for line in lines[1:]:
            f = line.split(",")
            rows.append(",".join([f[0]] + [repr(float(v) * 1000) for v in f[1:4]] + f[4:]))
        self.write("mm.csv", "\n".join([header] + rows) + "\n")
        line = self.assert_one_error(self.cli("score", "mm.csv", "--character", "十"), 1, "mm.csv")
        self.assertRegex(line.split("mm.csv", 1)[1], r"\bx\b")

    def test_score_csv_with_crlf_bom_and_quoted_fields_scores_the_same(self):
        # cli.md "Pen traces": a BOM is skipped, "as are CR LF line ends, and a field in double quotes ... is
        # read as the text between them".
        lines = self.csv_rows()
        self.write("crlf-bom.csv", b"\xef\xbb\xbf" + ("\r\n".join(lines) + "\r\n").encode("utf-8"))
        quoted = "\r\n".join(",".join(f'"{v}"' for v in line.split(",")) for line in lines) + "\r\n"
        self.write("quoted.csv", b"\xef\xbb\xbf" + quoted.encode("utf-8"))
        want = without_file_keys(self.score_json("t.csv"))
        for name in ("crlf-bom.csv", "quoted.csv"):
            with self.subTest(trace=name):
                self.assertEqual(without_file_keys(self.score_json(name)), want)

    def test_score_csv_cut_mid_row_or_with_junk_appended_is_refused_at_its_line(self):
        data = (self.tmp / "t.csv").read_bytes()
        half = data.index(b"\n", len(data) // 2) + 1        # the start of a line past half the bytes
        line_no = data[:half].count(b"\n") + 1               # that line's number, the header being line 1
        cut = data[:half] + data[half:].split(b",")[0] + b","  # its t and one comma: a row cut short
        lines = data.count(b"\n")
        for name, content, where in (("half.csv", cut, line_no),
                                     ("junk.csv", data + b"junk,here\n", lines + 1),
                                     ("nul.csv", data[:half] + b"0.5\x00" + data[half + 3:], line_no)):
            with self.subTest(trace=name):
                self.write(name, content)
                result = self.cli("score", name, "--character", "十")
                self.assertNotIn(b"\x00", result.stderr)
                self.assert_one_error(result, 1, f"{name}:{where}")

    def test_score_csv_with_time_going_back_is_refused_at_its_line(self):
        lines = self.csv_rows()
        k = 500
        a, b = lines[k].split(","), lines[k + 1].split(",")
        a[0], b[0] = b[0], a[0]
        lines[k], lines[k + 1] = ",".join(a), ",".join(b)
        self.write("back.csv", "\n".join(lines) + "\n")
        self.assert_one_error(self.cli("score", "back.csv", "--character", "十"), 1, f"back.csv:{k + 2}")

    def test_score_gzip_cut_at_half_is_refused_naming_it(self):
        packed = gzip.compress((self.tmp / "t.csv").read_bytes(), compresslevel=1)
        self.write("cut.csv.gz", packed[:len(packed) // 2])
        self.assert_one_error(self.cli("score", "cut.csv.gz", "--character", "十"), 1, "cut.csv.gz")

    # ---- forged records --------------------------------------------------------------------------------
    def test_spec_record_cut_at_half_is_refused_naming_the_file_and_byte(self):
        data = (self.tmp / "t.json").read_bytes()
        cut = data[:data.index(b",", len(data) // 2) + 1]
        self.write("cut.json", cut)
        line = self.assert_one_error(self.cli("trial", "--spec", "cut.json", "--csv", "cut-out.csv"), 2, "cut.json")
        self.assertIn("not valid JSON at byte", line)
        self.assertFalse((self.tmp / "cut-out.csv").exists())
        with self.assertRaises(cg.DataError) as caught:
            cg.check_trial_record(str(self.tmp / "cut.json"))
        self.assertIn("cut.json", str(caught.exception))

    def test_spec_record_with_junk_appended_or_a_nul_is_refused_naming_the_file(self):
        data = (self.tmp / "t.json").read_bytes()
        middle = data.index(b'"seed"')
        for name, content in (("junk.json", data + b"\n{\"more\": 1}\n"),
                              ("nul.json", data[:middle] + b"\x00" + data[middle:])):
            with self.subTest(record=name):
                self.write(name, content)
                result = self.cli("trial", "--spec", name, "--json", "junk-out.json")
                self.assertNotIn(b"\x00", result.stderr)
                line = self.assert_one_error(result, 2, name)
                self.assertIn("byte", line)
                self.assertFalse((self.tmp / "junk-out.json").exists())

    def test_spec_record_with_a_key_twice_is_refused_naming_its_pointer(self):
        text = (self.tmp / "t.json").read_text(encoding="utf-8")
        record = json.loads(text)
        spec = json.dumps(record["specification"]["trial"])
        twice = spec[:-1] + ', "seed": 4}'
        forged = json.dumps(record).replace(spec, twice, 1)
        self.assertIn('"seed": 4}', forged)
        self.write("twice.json", forged)
        line = self.assert_one_error(self.cli("trial", "--spec", "twice.json", "--check"), 2, "twice.json")
        self.assertIn("/specification/trial/seed", line)

    def test_replay_record_refuses_a_teacher_replaced_or_named_by_another_sha256(self):
        d = self.tmp / "replay"
        d.mkdir()
        for made in self.teachers():
            shutil.copyfile(made, d / made.name)
        run_ok(["trial", "十", "--guidance-mode", "replay", "--teacher", "teacher.json", "--json", "rp.json",
                "--csv", "rp.csv"], d)
        record = json.loads((d / "rp.json").read_text(encoding="utf-8"))
        teacher_sha, other_sha = sha(d / "teacher.json"), sha(d / "other.json")
        self.assertEqual(record["specification"]["teacher_sha256"], teacher_sha)
        result = run(["trial", "--spec", "rp.json", "--csv", "again.csv"], d)
        self.assertEqual(result.returncode, 0, result.stderr)
        self.assertEqual((d / "again.csv").read_bytes(), (d / "rp.csv").read_bytes())
        # --teacher another recording: refused naming it and both SHA-256.
        line = self.assert_one_error(run(["trial", "--spec", "rp.json", "--teacher", "other.json", "--csv",
                                          "x.csv"], d), 1, "other.json")
        self.assertIn(teacher_sha, line)
        self.assertIn(other_sha, line)
        # The record's teacher file replaced by another recording.
        shutil.copyfile(d / "teacher.json", d / "teacher.orig")
        shutil.copyfile(d / "other.json", d / "teacher.json")
        line = self.assert_one_error(run(["trial", "--spec", "rp.json", "--csv", "y.csv"], d), 1, "teacher.json")
        self.assertIn(teacher_sha, line)
        self.assertIn(other_sha, line)
        self.assertFalse((d / "x.csv").exists() or (d / "y.csv").exists())
        here = os.getcwd()
        os.chdir(d)
        try:
            with self.assertRaises(cg.DataError) as caught:
                cg.rerun_trial(str(d / "rp.json"))
        finally:
            os.chdir(here)
        self.assertIn(teacher_sha, str(caught.exception))
        self.assertIn(other_sha, str(caught.exception))
        # The record's SHA-256 edited: the original teacher is no longer the one it names.
        shutil.copyfile(d / "teacher.orig", d / "teacher.json")
        record["specification"]["teacher_sha256"] = other_sha
        (d / "forged.json").write_text(json.dumps(record, ensure_ascii=False), encoding="utf-8")
        self.assert_one_error(run(["trial", "--spec", "forged.json", "--csv", "z.csv"], d), 1, "teacher.json")
        self.assertFalse((d / "z.csv").exists())
        self.assertEqual(temporaries(d), [])

    # ---- outputs ---------------------------------------------------------------------------------------
    def test_output_that_is_an_input_is_refused_in_every_spelling(self):
        d = self.tmp / "ident"
        d.mkdir()
        shutil.copyfile(self.h5[0], d / "a.trace.h5")
        shutil.copyfile(self.tmp / "t.csv", d / "t.csv")
        shutil.copyfile(self.tmp / "t.json", d / "t.json")
        (d / "sub").mkdir()
        os.symlink("t.csv", d / "link.csv")
        os.link(d / "t.csv", d / "hard.csv")
        os.symlink("a.trace.h5", d / "link.h5")
        os.link(d / "a.trace.h5", d / "hard.h5")
        os.symlink("t.json", d / "link.json")
        before = snapshot(d)
        cases = [(["trace", "a.trace.h5", "--csv", out], "--csv")
                 for out in ("a.trace.h5", "./a.trace.h5", "sub/../a.trace.h5", "link.h5", "hard.h5",
                             str(d / "a.trace.h5"))]
        cases += [(["score", "t.csv", "--character", "十", "--json", out], "--json")
                  for out in ("t.csv", "./t.csv", "link.csv", "hard.csv")]
        cases += [(["trial", "--spec", "t.json", opt, out], opt)
                  for opt, out in (("--json", "t.json"), ("--csv", "./t.json"), ("--svg", "link.json"))]
        cases += [(["trial", "--spec", "t.json", "--json", "o.json", "--csv", "./o.json"], "--json"),
                  (["trial", "十", "--json", "o.json", "--csv", "sub/../o.json"], "--csv")]
        for args, option in cases:
            with self.subTest(args=" ".join(args)):
                self.assert_one_error(run(args, d), 2, option)
        self.assertEqual(snapshot(d), before)
        self.assertEqual(temporaries(d), [])

    def test_output_in_a_missing_folder_or_naming_a_folder_fails_naming_the_option(self):
        for args, option in ((["trace", self.h5[0], "--csv", "nowhere/o.csv"], "--csv"),
                             (["score", "t.csv", "--character", "十", "--json", "nowhere/o.json"], "--json"),
                             (["trial", "--spec", "t.json", "--csv", "nowhere/o.csv"], "--csv")):
            with self.subTest(command=args[0]):
                line = self.assert_one_error(self.cli(*args), 1, option, "nowhere")
                self.assertIn("does not exist", line)
        self.assertFalse((self.tmp / "nowhere").exists())
        (self.tmp / "folder.csv").mkdir()
        self.assert_one_error(self.cli("trace", self.h5[0], "--csv", "folder.csv"), 1, "--csv", "folder.csv")
        self.assertEqual(list((self.tmp / "folder.csv").iterdir()), [])

    def test_dev_full_as_a_file_or_as_standard_output_is_a_failed_write(self):
        self.assert_one_error(self.cli("trace", self.h5[0], "--csv", "/dev/full"), 1, "/dev/full")
        self.assert_one_error(self.cli("score", "t.csv", "--character", "十", "--json", "/dev/full"), 1,
                              "/dev/full")
        with open("/dev/full", "wb") as full:
            self.assert_one_error(self.cli("trace", self.h5[0], stdout=full), 1)
            self.assert_one_error(self.cli("score", "t.csv", "--character", "十", "--json", "-", stdout=full), 1)

    def test_trial_spec_writes_its_other_outputs_when_one_fails(self):
        # cli.md: "Outputs are written before the table, each one even when another fails (each failure is one
        # line on standard error; exit 1)".
        result = self.cli("trial", "--spec", "t.json", "--json", "/dev/full", "--csv", "ok.csv")
        self.assert_one_error(result, 1, "/dev/full")
        self.assertEqual((self.tmp / "ok.csv").read_bytes(), (self.tmp / "t.csv").read_bytes())

    def test_closed_standard_output_is_an_error_not_exit_0(self):
        result = subprocess.run([CLI, "trace", str(self.h5[0])], cwd=self.tmp, env=ENV, stdin=subprocess.DEVNULL,
                                stderr=subprocess.PIPE, stdout=subprocess.DEVNULL, timeout=60,
                                preexec_fn=lambda: os.close(1))
        self.assert_one_error(result, 1)

    def test_trace_into_head_1_is_an_error_line_and_exit_1(self):
        trace = subprocess.Popen([CLI, "trace", str(self.h5[0])], cwd=self.tmp, env=ENV, stdin=subprocess.DEVNULL,
                                 stdout=subprocess.PIPE, stderr=subprocess.PIPE)
        head = subprocess.run(["head", "-1"], stdin=trace.stdout, stdout=subprocess.PIPE, timeout=60)
        trace.stdout.close()
        err = trace.stderr.read()
        trace.stderr.close()
        status = trace.wait(timeout=60)
        self.assertEqual(head.stdout, b"t,x,y,z,fx,fy,fz,state,stroke,element,attempt,rewritten\n")

        class Result:
            returncode, stderr = status, err
        self.assert_one_error(Result, 1)


    def test_outputs_through_links_keep_the_links_and_the_modes(self):
        # cli.md "Outputs": a link "keeps pointing where it did, and the file it names is replaced; a replaced
        # file keeps its permission bits, and a new one gets 0666 less the umask"; a dangling link's file is
        # created.
        d = self.tmp / "links"
        (d / "sub").mkdir(parents=True)
        (d / "sub" / "old.csv").write_text("old\n", encoding="utf-8")
        os.chmod(d / "sub" / "old.csv", 0o600)
        os.symlink("sub/old.csv", d / "to-old.csv")
        os.symlink("sub/new.csv", d / "dangling.csv")
        want = (self.tmp / "h.csv").read_bytes()
        for out in ("to-old.csv", "dangling.csv", "plain.csv"):
            with self.subTest(out=out):
                result = run(["trace", self.h5[0], "--csv", out], d, preexec_fn=lambda: os.umask(0o027))
                self.assertEqual(result.returncode, 0, result.stderr)
        self.assertEqual(os.readlink(d / "to-old.csv"), "sub/old.csv")
        self.assertEqual(os.readlink(d / "dangling.csv"), "sub/new.csv")
        self.assertEqual((d / "sub" / "old.csv").read_bytes(), want)
        self.assertEqual((d / "sub" / "new.csv").read_bytes(), want)
        self.assertEqual(os.stat(d / "sub" / "old.csv").st_mode & 0o777, 0o600)
        self.assertEqual(os.stat(d / "sub" / "new.csv").st_mode & 0o777, 0o640)
        self.assertEqual(os.stat(d / "plain.csv").st_mode & 0o777, 0o640)
        self.assertEqual(temporaries(d), [])

    def test_dev_stdout_on_a_regular_file_replaces_it_whole(self):
        # cli.md "Outputs": on a regular file `/dev/stdout` "is a symbolic link to that file like any other: the
        # file is replaced (`>> f.csv` does not append)".
        target = self.tmp / "stdout-file.csv"
        target.write_bytes(b"x" * 1_000_000)
        with open(target, "ab") as out:
            result = self.cli("trace", self.h5[0], "--csv", "/dev/stdout", stdout=out)
        self.assertEqual(result.returncode, 0, result.stderr)
        self.assertEqual(target.read_bytes(), (self.tmp / "h.csv").read_bytes())

    def test_file_size_limit_is_a_failed_write_that_keeps_the_earlier_file(self):
        # cli.md "Outputs": SIGXFSZ ignored, "a write over the file size limit (`ulimit -f`) ... is an error line
        # and exit 1"; "leaves any earlier file as it was", temporary removed.
        import resource
        d = self.tmp / "fsize"
        d.mkdir()
        (d / "big.csv").write_text("earlier\n", encoding="utf-8")

        def limit():
            resource.setrlimit(resource.RLIMIT_FSIZE, (100_000, 100_000))
        self.assert_one_error(run(["trace", self.h5[0], "--csv", "big.csv"], d, preexec_fn=limit), 1, "big.csv")
        self.assertEqual((d / "big.csv").read_text(encoding="utf-8"), "earlier\n")
        self.assertEqual(sorted(p.name for p in d.iterdir()), ["big.csv"])
        with open(d / "out.txt", "wb") as out:
            self.assert_one_error(run(["trace", self.h5[0]], d, preexec_fn=limit, stdout=out), 1)

    def test_standard_input_and_pipes_are_refused_as_inputs_never_waited_on(self):
        # cli.md "Pen traces": "an input given as `-` is a file named `-`, and where none exists the error says
        # that standard input is not read"; a pipe or `/dev/stdin` is refused at once, "not a regular file".
        data = (self.tmp / "t.csv").read_bytes()
        line = self.assert_one_error(self.cli("score", "-", "--character", "十"), 1)
        self.assertIn("standard input", line)
        for args in (["score", "/dev/stdin", "--character", "十"], ["trace", "/dev/stdin"],
                     ["trial", "--spec", "/dev/stdin", "--check"]):
            with self.subTest(command=args[0]):
                result = subprocess.run([CLI, *args], cwd=self.tmp, env=ENV, input=data, capture_output=True,
                                        timeout=30)
                self.assert_one_error(result, 1, "/dev/stdin", "not a regular file")

    def test_score_csv_with_pen_spelt_as_numpy_writes_it_scores_as_its_z(self):
        # cli.md `score`: `pen` "1 down, 0 up: the number, however spelt, so numpy's 1.000000000000000000e+00
        # and pandas' 1.0 too"; the pen touches at z <= 0.5 mm (the paper of 十's layout at z = 0).
        lines = self.csv_rows()
        spelt = {True: ("1.000000000000000000e+00", "1.0"), False: ("0.000000000000000000e+00", "0.0")}
        rows = ["t,x,y,pen"]
        for i, line in enumerate(lines[1:]):
            t, x, y, z = line.split(",")[:4]
            rows.append(f"{t},{x},{y},{spelt[float(z) <= 0.0005][i % 2]}")
        self.write("pen.csv", "\n".join(rows) + "\n")
        self.assertEqual(without_file_keys(self.score_json("pen.csv")), without_file_keys(self.score_json("t.csv")))
        both = "\n".join([lines[0] + ",pen"] + [f"{l},0" for l in lines[1:]]) + "\n"
        self.write("both.csv", both)
        self.assert_one_error(self.cli("score", "both.csv", "--character", "十"), 1, "both.csv")

    def test_score_csv_with_comments_blank_lines_and_padded_fields_scores_the_same(self):
        # pen_trace_csv.hpp: "Blank lines and lines starting with `#` are skipped; ... fields may be padded with
        # spaces".
        lines = self.csv_rows()
        out = ["# written by hand", lines[0].replace(",", " , ")]
        for i, line in enumerate(lines[1:]):
            out.append(" " + line.replace(",", " ,  ") + " ")
            if i % 1000 == 0:
                out += ["", "# a comment, with a comma"]
        self.write("padded.csv", "\n".join(out) + "\n")
        self.assertEqual(without_file_keys(self.score_json("padded.csv")),
                         without_file_keys(self.score_json("t.csv")))

    def test_python_rerun_of_a_session_record_gives_its_saved_trace(self):
        samples = cg_study.load(str(self.tmp / "S")).samples(1)
        again = cg.rerun_trial(str(self.records[1]))
        self.assertEqual(len(again.time_s), len(samples))
        p = again.position_m
        for i, column in enumerate(("x_m", "y_m", "z_m")):
            worst = max(abs(a - b) for a, b in zip(p[:, i].tolist(), samples[column].tolist()))
            self.assertLessEqual(worst, 0.5e-7 + 1e-15, column)
        self.assertEqual(again.stroke.tolist(), samples["stroke"].tolist())

    def test_an_input_the_record_names_is_not_an_output_either(self):
        # cli.md "Output identity": no output may be the same file as an input (`--teacher`, `--spec`, ...,
        # "every file of the session folders a command reads": under `report DIR...` the saved trial records).
        d = self.tmp / "named"
        d.mkdir()
        shutil.copyfile(self.teachers()[0], d / "teacher.json")
        run_ok(["trial", "十", "--guidance-mode", "replay", "--teacher", "teacher.json", "--json", "rp.json"], d)
        before = (d / "teacher.json").read_bytes()
        for args in (["trial", "--spec", "rp.json", "--json", "teacher.json"],
                     ["trial", "--spec", "rp.json", "--csv", "./teacher.json"],
                     ["trial", "十", "--guidance-mode", "replay", "--teacher", "teacher.json", "--record",
                      "teacher.json"]):
            with self.subTest(args=" ".join(args)):
                self.assert_one_error(run(args, d), 2, "teacher.json")
                self.assertEqual((d / "teacher.json").read_bytes(), before)
        study, session = self.copy_study("SO")
        before = snapshot(study)
        for target in (self.records[0].name, self.h5[0].name):
            with self.subTest(report_out=target):
                self.assert_one_error(self.cli("report", study, "--out", session / "trials" / target), 2, target)
                self.assertEqual(snapshot(study), before)

    def test_a_record_naming_another_trials_trace_is_refused(self):
        # Each record edited to name the other trial's trace, with that trace's own SHA-256: the trace of 二 is
        # not 十's. experiments.md "Trial records": `files` names "the trace and SVG beside it" ("an attempt's
        # record names its own `.attempt-K.trace.h5`"); "A record is its session's": a record that "names
        # another trial of the plan (`/trial/index`, `/trial/file`)" than the one "its file name gives" is
        # refused "rather than reported under its folder's labels"; `report` and `Study.samples` "refuse a trace
        # that is not the one its record names".
        study, session = self.copy_study("SN")
        records = [session / "trials" / r.name for r in self.records]
        for record, other in zip(records, reversed(self.h5)):
            r = json.loads(record.read_text(encoding="utf-8"))
            r["files"]["trace"] = other.name
            r["files"]["trace_sha256"] = sha(other)
            record.write_text(json.dumps(r, ensure_ascii=False), encoding="utf-8")
        before = snapshot(session)
        line = self.assert_one_error(self.cli("report", study, "--out", "SN.html"), 1, "/files/trace")
        self.assertTrue(any(r.name in line for r in records), line)
        self.assertFalse((self.tmp / "SN.html").exists())
        try:
            cg_study.load(str(study)).samples(0)
        except cg.DataError as e:
            self.assertIn("/files/trace", str(e))
        else:
            self.fail("the trace of 二 was read as the trial of 十's")
        self.assertEqual(snapshot(session), before)

    def test_session_replay_teacher_replaced_or_removed_is_refused_naming_it(self):
        # cli.md "Re-running a trial": a session's replay re-runs on the teacher kept in its folder, "bound by
        # that SHA-256 ...: one edited or replaced since is refused (exit 1) naming it and both SHA-256, and one
        # removed naming it".
        d = self.tmp / "replay-session"
        d.mkdir()
        for made in self.teachers():
            shutil.copyfile(made, d / made.name)
        protocol = {"name": "r",
                    "conditions": [{"name": "echo", "mode": "replay", "teachers": {"十": "teacher.json"}}],
                    "test": {"characters": ["十"], "conditions": ["echo"], "repetitions": 1},
                    "trial": {"max_duration_s": 20}}
        (d / "r.json").write_text(json.dumps(protocol, ensure_ascii=False), encoding="utf-8")
        run_ok(["session", "run", "r.json", "--writer", "simulated", "--subjects", "1", "--out", "R"], d)
        session = next((d / "R" / "S01").iterdir())
        record = next((session / "trials").glob("*.json"))
        h5 = record.with_name(record.name[:-len(".json")] + ".trace.h5")
        (d / "elsewhere").mkdir()
        result = run(["trial", "--spec", record, "--csv", "a.csv"], d / "elsewhere")
        self.assertEqual(result.returncode, 0, result.stderr)
        self.assertEqual((d / "elsewhere" / "a.csv").read_bytes(), run_ok(["trace", h5], d).stdout)
        copy = next((session / "teachers").iterdir())
        kept_sha, other_sha = sha(copy), sha(d / "other.json")
        shutil.copyfile(d / "other.json", copy)
        line = self.assert_one_error(run(["trial", "--spec", record, "--csv", "b.csv"], d / "elsewhere"), 1,
                                     copy.name)
        self.assertIn(kept_sha, line)
        self.assertIn(other_sha, line)
        with self.assertRaises(cg.DataError) as caught:
            cg.rerun_trial(str(record))
        self.assertIn(copy.name, str(caught.exception))
        copy.unlink()
        self.assert_one_error(run(["trial", "--spec", record, "--csv", "c.csv"], d / "elsewhere"), 1, copy.name)
        self.assertEqual(sorted(p.name for p in (d / "elsewhere").iterdir()), ["a.csv"])

    def test_trace_file_of_another_layout_reads_the_same_and_forged_columns_are_refused(self):
        # experiments.md "Trace files": another program's layout (contiguous storage, other chunks, fletcher32)
        # and a link inside the file read as the dataset; a column read from outside the file, through a
        # filter this HDF5 lacks (LZF, 32000), of another byte order, or with attributes other than this version
        # writes is refused naming the file and the column. The 512-byte user block's length and CRC-32 are
        # made to match, so that each forgery reaches the checks after it.
        if h5py is None:
            self.skipTest("h5py is needed")
        import zlib
        d = self.tmp / "layouts"
        d.mkdir()

        def seal(path):
            data = bytearray(path.read_bytes())
            body = bytes(data[512:])
            head = f"calligraphy-trace\nversion 1\nbytes {len(body)}\ncrc32 {zlib.crc32(body):08x}\n".encode()
            data[:512] = head + b"\0" * (512 - len(head))
            path.write_bytes(bytes(data))

        def rebuilt(name, options=lambda column: {}):
            path = d / name
            with h5py.File(self.h5[0], "r") as src, h5py.File(path, "w", userblock_size=512) as dst:
                for k, v in src.attrs.items():
                    dst.attrs[k] = v
                for column in src:
                    kw = {"dtype": src[column].dtype, **options(column)}
                    new = dst.create_dataset(column, data=src[column][()], **kw)
                    for k, v in src[column].attrs.items():
                        new.attrs[k] = v
            seal(path)
            return path

        def edited(name, change):
            path = d / name
            shutil.copyfile(self.h5[0], path)
            with h5py.File(path, "r+") as f:
                change(f)
            seal(path)
            return path

        def soft(f):
            f.move("x", "x_data")
            f["x"] = h5py.SoftLink("/x_data")

        def external(f):
            with h5py.File(d / "elsewhere.h5", "w") as other:
                other.create_dataset("x", data=f["x"][()])
            del f["x"]
            f["x"] = h5py.ExternalLink(str(d / "elsewhere.h5"), "/x")
        want = (self.tmp / "h.csv").read_bytes()
        for path in (rebuilt("contiguous.trace.h5"),
                     rebuilt("fletcher.trace.h5", lambda c: {"chunks": (333,), "fletcher32": True,
                                                             "compression": "gzip"}),
                     edited("soft.trace.h5", soft)):
            with self.subTest(read=path.name):
                self.assertEqual(run_ok(["trace", path], d).stdout, want)
        for path, needles in ((edited("decimals.trace.h5", lambda f: f["x"].attrs.modify("decimals", 3)),
                               ("'x'", "/x/decimals is 3, this version writes 7")),
                              (edited("external.trace.h5", external), ("'x'", "outside the trace file")),
                              (rebuilt("lzf.trace.h5", lambda c: {"compression": "lzf"} if c == "x" else {}),
                               ("'x'", "32000")),
                              (rebuilt("big-endian.trace.h5", lambda c: {"dtype": ">i4"} if c == "x" else {}),
                               ("'x'",))):
            with self.subTest(refused=path.name):
                self.assert_one_error(run(["trace", path, "--csv", "out.csv"], d), 1, path.name, *needles)
                self.assertFalse((d / "out.csv").exists())

    def test_trace_sample_edited_with_its_crc_made_to_match_is_refused_by_its_record(self):
        # The file is a sound trace again, but not the one the record's `files.trace_sha256` names: `report` and
        # `Study.samples` refuse it (experiments.md "Trial records").
        if h5py is None:
            self.skipTest("h5py is needed")
        import zlib
        study, session = self.copy_study("SC")
        h5 = session / "trials" / self.h5[0].name
        with h5py.File(h5, "r+") as f:
            x = f["x"][()]
            x[100] += 1000
            f["x"][...] = x
        data = bytearray(h5.read_bytes())
        body = bytes(data[512:])
        head = f"calligraphy-trace\nversion 1\nbytes {len(body)}\ncrc32 {zlib.crc32(body):08x}\n".encode()
        data[:512] = head + b"\0" * (512 - len(head))
        h5.write_bytes(bytes(data))
        traced = run_ok(["trace", h5], self.tmp).stdout  # a sound trace file again
        self.assertNotEqual(traced, (self.tmp / "h.csv").read_bytes())
        recorded = json.loads(self.records[0].read_text(encoding="utf-8"))["files"]["trace_sha256"]
        line = self.assert_one_error(self.cli("report", study, "--out", "SC.html"), 1, h5.name)
        self.assertIn(recorded, line)
        with self.assertRaises(cg.DataError) as caught:
            cg_study.load(str(study)).samples(0)
        self.assertIn(h5.name, str(caught.exception))

    def test_spec_record_with_numbers_spelt_as_json_allows_re_runs_the_same(self):
        # cli.md "Re-running a trial": "escaping (`"\u0073eed"`), and with numbers spelt as JSON allows (`1E3`,
        # `1000.0` for 1000, `-0` for 0)"; below 2^53 "`7.0` or `7e0` is the seed 7"; a seed with a fraction at
        # or above 2^53 "is refused at `/specification/trial/seed`".
        text = json.dumps(json.loads((self.tmp / "t.json").read_text(encoding="utf-8")), indent=1)
        spelt = text.replace('"rate_hz": 1000.0', '"rate_hz": 1E3').replace('"seed": 3,', '"\\u0073eed": 3.0,', 1)
        spelt = spelt.replace('"paper_z_m": 0.0', '"paper_z_m": -0')
        self.assertIn("1E3", spelt)
        self.assertIn('"\\u0073eed": 3.0', spelt)
        self.assertIn('"paper_z_m": -0', spelt)
        self.write("spelt.json", spelt)
        result = self.cli("trial", "--spec", "spelt.json", "--csv", "spelt.csv")
        self.assertEqual(result.returncode, 0, result.stderr)
        self.assertEqual((self.tmp / "spelt.csv").read_bytes(), (self.tmp / "t.csv").read_bytes())
        record = json.loads(text)
        record["specification"]["trial"]["seed"] = 9007199254740993
        self.write("past.json", json.dumps(record).replace("9007199254740993", "9007199254740993.0"))
        self.assert_one_error(self.cli("trial", "--spec", "past.json", "--check"), 2, "past.json",
                              "/specification/trial/seed")

    def test_score_csv_position_too_far_or_not_a_number_is_refused_at_its_line_naming_the_column(self):
        # cli.md "Pen traces": a position "so far from the character (`1e308` m) that it has no place in the
        # character's data units is refused at `TRACE:LINE`, naming its column"; pen_trace_csv.hpp: "a value
        # that is not a finite number".
        lines = self.csv_rows()[:200]
        for name, value in (("far.csv", "1e308"), ("nan.csv", "nan"), ("inf.csv", "-inf")):
            with self.subTest(value=value):
                row = lines[150].split(",")
                row[1] = value
                self.write(name, "\n".join(lines[:150] + [",".join(row)] + lines[151:]) + "\n")
                line = self.assert_one_error(self.cli("score", name, "--character", "十"), 1, f"{name}:151")
                self.assertRegex(line.split(f"{name}:151", 1)[1], r"\bx\b")

    def test_output_named_with_255_bytes_is_written(self):
        # cli.md "Outputs": the temporary's NAME is "cut to fit the 255-byte limit of a file name, so that any
        # name the file system takes can be written".
        d = self.tmp / "long"
        d.mkdir()
        name = "十" * 83 + "a.csv"  # 83 x 3 + 5 = 254 bytes
        self.assertLessEqual(len(name.encode()), 255)
        result = run(["trace", self.h5[0], "--csv", name], d)
        self.assertEqual(result.returncode, 0, result.stderr)
        self.assertEqual((d / name).read_bytes(), (self.tmp / "h.csv").read_bytes())
        self.assertEqual(temporaries(d), [])

if __name__ == "__main__":
    unittest.main()
