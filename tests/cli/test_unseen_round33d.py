#!/usr/bin/env python3
"""Round 33D: a lab's study from Python. Protocols written by Python's json module and run by the command line,
sessions of simulated subjects, cohorts in memory (threads, an Executor, a Dask cluster), the tidy tables of
`calligraphy.study.load` against `calligraphy report --csv` and `session cohort --csv`, their dtypes, a trial's
samples against h5py and `calligraphy trace`, and a study damaged in the ways a lab damages one (a record
missing, cut, retyped or copied in, a trace swapped or cut, a session of another study or subject, a study
without its identity file), plus every wrong kind of argument to the public functions of that side.

From the docs alone: docs/python.md ("Simulated cohorts", "Statistics", "A study's traces", "Errors"),
docs/experiments.md ("Protocol files", "Phases", "Sessions", "Trace files", "Trial records", "Tidy tables",
"A cohort in memory"), docs/cli.md (`session run`, `session plan`, `session cohort`, `report`, `trace`,
`curriculum`) and the docstrings of calligraphy.study and calligraphy.cohort.

CALLIGRAPHY_CLI names the program; PYTHONPATH the built Python package. CALLIGRAPHY_SANITIZED=1 takes five cases.
"""
import concurrent.futures
import hashlib
import io
import json
import os
import pickle
import re
import shutil
import tempfile
import unittest
from pathlib import Path

from outsider import OneErrorLine, run, run_ok, sanitized_subset

import numpy as np
import pandas as pd
import calligraphy as cg
import calligraphy.cohort
import calligraphy.statistics
import calligraphy.study

try:
    import distributed  # Dask's scheduler, which imports Dask
except ImportError:
    distributed = None
try:
    import h5py
except ImportError:
    h5py = None

load_tests = sanitized_subset({"test_load_refuses_every_wrong_kind_of_paths",
                               "test_samples_refuses_every_wrong_kind_of_trial",
                               "test_simulate_refuses_every_wrong_kind_of_argument",
                               "test_null_key_refused_alike_by_session_plan_and_simulate",
                               "test_record_copied_in_outside_the_plan_is_refused_naming_it_and_plan"})

# The design: conditions listed haptic first, so that the control (the one in vision mode) coming first in
# `condition`'s categories is the reader's doing, not the file's order.
PROTOCOL = {"name": "r33d",
            "conditions": [{"name": "haptic", "mode": "haptic"}, {"name": "vision", "mode": "vision"}],
            "test": {"characters": ["十", "二"], "conditions": ["haptic", "vision"], "repetitions": 1},
            "trial": {"max_duration_s": 30}}
PHASED = {"name": "r33dphases",
          "conditions": [{"name": "fixture", "mode": "haptic"}, {"name": "unguided", "mode": "vision"}],
          "phases": [{"phase": "pre-test", "condition": "unguided", "characters": ["十"]},
                     {"phase": "training", "condition": "fixture", "characters": ["十"], "repetitions": 2},
                     {"phase": "post-test", "condition": "unguided", "characters": ["十"]}],
          "trial": {"max_duration_s": 30}}
LABELS = ["subject", "protocol", "group", "condition", "characters", "item_set", "trained_condition",
          "trace_sha256"]
STROKE_LABELS = ["subject", "condition", "character_text"]
# docs/experiments.md "Tidy tables": every column of trials.csv it names.
TRIAL_COLUMNS = ["subject", "session", "protocol", "session_number", "group", "phase", "block", "condition",
                 "mode", "characters", "trial", "item", "repetition", "item_set", "sequence", "period",
                 "trained_condition", "writer", "end_reason", "start_utc", "writer_profile", "writer_learning",
                 "completed_in_order", "strokes_total", "strokes_written", "strokes_accepted", "order_errors",
                 "backwards_strokes", "unmatched_segments", "strokes_assisted", "mean_deviation_m",
                 "max_deviation_m", "rms_deviation_m", "frechet_m", "dtw_m", "total_time_s", "pen_down_time_s",
                 "velocity_peaks", "normalised_jerk", "shape_skill", "order_skill", "timing_skill",
                 "subject_writing_speed_factor", "subject_spatial_error_factor", "subject_error_rate_factor",
                 "subject_motor_noise_factor", "subject_fast_learning_per_trial",
                 "subject_slow_learning_per_trial", "subject_fast_retention_per_trial",
                 "subject_slow_retention_per_trial", "strokes_given_up", "legibility_top1", "legibility_top5",
                 "trace_file", "trace_sha256"]
STROKE_COLUMNS = ["subject", "session", "trial", "phase", "condition", "character", "character_text", "stroke",
                  "typical_id", "written", "backwards", "segments", "refused_segments", "refusal",
                  "mean_deviation_m", "time_s", "path_length_m", "assisted"]
COUNTS = ["session_number", "block", "trial", "item", "repetition", "strokes_total", "strokes_written",
          "strokes_accepted", "order_errors", "backwards_strokes", "unmatched_segments", "strokes_assisted"]
METRICS = ["mean_deviation_m", "max_deviation_m", "rms_deviation_m", "frechet_m", "dtw_m", "total_time_s",
           "pen_down_time_s", "normalised_jerk", "period"]
SAMPLE_FLOATS = ["t_s", "x_m", "y_m", "z_m", "fx_n", "fy_n", "fz_n"]
SAMPLE_INTS = ["stroke", "element", "attempt", "rewritten"]
# The trace's columns in h5py and `calligraphy trace`'s CSV, by the samples' names.
TRACE_NAMES = {"t_s": "t", "x_m": "x", "y_m": "y", "z_m": "z", "fx_n": "fx", "fy_n": "fy", "fz_n": "fz"}

ROOT = None          # the module's temporary folder
P_JSON = None        # PROTOCOL as Python wrote it (UTF-8, no escapes)
STUDY = None         # `session run P_JSON --subjects 2`
OTHER = None         # another study of the same protocol, subject S09
TABLES = None        # `report STUDY --csv`
LOADED = None        # calligraphy.study.load(STUDY)
COHORT = None        # calligraphy.cohort.simulate(P_JSON, 2, workers=1)


def write_json(path, document, **kw):
    with open(path, "w", encoding="utf-8") as f:
        json.dump(document, f, ensure_ascii=kw.pop("ensure_ascii", False), **kw)
    return Path(path)


def setUpModule():
    global ROOT, P_JSON, STUDY, OTHER, TABLES, LOADED, COHORT
    ROOT = Path(tempfile.mkdtemp(prefix="r33d-"))
    P_JSON = write_json(ROOT / "p.json", PROTOCOL, indent=2)
    STUDY, OTHER, TABLES = ROOT / "study", ROOT / "other", ROOT / "tables"
    TABLES.mkdir()
    run_ok(["session", "run", P_JSON, "--subjects", "2", "--out", STUDY], ROOT)
    run_ok(["session", "run", P_JSON, "--subject", "S09", "--out", OTHER], ROOT)
    run_ok(["report", STUDY, "--csv", TABLES], ROOT)
    LOADED = calligraphy.study.load(str(STUDY))
    COHORT = calligraphy.cohort.simulate(str(P_JSON), 2, workers=1, progress=False)


def tearDownModule():
    if ROOT is not None:
        shutil.rmtree(ROOT, ignore_errors=True)


def read_tables_csv(path, labels):
    """A table of `report --csv` read as docs/experiments.md says to read it with pandas."""
    return pd.read_csv(path, keep_default_na=False, na_values=[""], float_precision="round_trip",
                       dtype=dict.fromkeys(labels, str))


def session_of(root, subject):
    """The one session folder of `subject` under the study folder `root`."""
    found = [p for p in (Path(root) / subject).iterdir() if (p / "session.json").is_file()]
    assert len(found) == 1, found
    return found[0]


def record_path(session, number):
    found = sorted((Path(session) / "trials").glob(f"{number:03d}-*.json"))
    assert len(found) == 1, found
    return found[0]


def tree(root):
    """Every file under `root` (but the run lock, whose content the docs let change) with its bytes' hash."""
    return {str(p.relative_to(root)): hashlib.sha256(p.read_bytes()).hexdigest()
            for p in sorted(Path(root).rglob("*")) if p.is_file() and p.name != ".calligraphy-run.lock"}


class StudyCase(unittest.TestCase, OneErrorLine):
    def setUp(self):
        self._tmp = tempfile.TemporaryDirectory(prefix="r33d-case-")
        self.tmp = Path(self._tmp.name)

    def tearDown(self):
        self._tmp.cleanup()

    def copy_study(self, source=None, name="study"):
        target = self.tmp / name
        shutil.copytree(source or STUDY, target, symlinks=True)
        return target

    def assert_same_column(self, name, got, expected):
        """`got` (a DataFrame's column) holds the values of `expected` (a column read from CSV), each as its kind."""
        got, expected = got.reset_index(drop=True), expected.reset_index(drop=True)
        if pd.api.types.is_bool_dtype(got.dtype):
            self.assertTrue(pd.api.types.is_bool_dtype(expected.dtype), f"{name}: {expected.dtype}")
            self.assertEqual(got.tolist(), expected.tolist(), name)
        elif pd.api.types.is_integer_dtype(got.dtype):
            self.assertTrue(pd.api.types.is_integer_dtype(expected.dtype), f"{name}: {expected.dtype}")
            self.assertEqual(got.tolist(), expected.tolist(), name)
        elif pd.api.types.is_float_dtype(got.dtype):
            a, b = got.to_numpy(float), expected.to_numpy(float)
            self.assertTrue(np.array_equal(a, b, equal_nan=True), f"{name}: {a} != {b}")
        else:
            self.assertEqual([("" if pd.isna(v) else str(v)) for v in got],
                             [("" if pd.isna(v) else str(v)) for v in expected], name)


class TablesAgree(StudyCase):
    """One study, three readers: `report --csv`, `study.load` and a cohort in memory."""

    def test_load_equals_report_csv_column_for_column_value_for_value(self):
        for table, loaded, labels in (("trials.csv", LOADED.trials, LABELS),
                                      ("strokes.csv", LOADED.strokes, STROKE_LABELS)):
            csv = read_tables_csv(TABLES / table, labels)
            self.assertEqual(list(loaded.columns), list(csv.columns), table)
            self.assertEqual(len(loaded), len(csv), table)
            for name in csv.columns:
                with self.subTest(table=table, column=name):
                    self.assert_same_column(name, loaded[name], csv[name])

    def test_every_documented_column_is_in_both_tables(self):
        header = (TABLES / "trials.csv").read_text(encoding="utf-8").splitlines()[0].split(",")
        for name in TRIAL_COLUMNS:
            self.assertIn(name, header)
            self.assertIn(name, LOADED.trials.columns)
        header = (TABLES / "strokes.csv").read_text(encoding="utf-8").splitlines()[0].split(",")
        for name in STROKE_COLUMNS:
            self.assertIn(name, header)
            self.assertIn(name, LOADED.strokes.columns)

    def test_cohort_in_memory_equals_the_folders_but_session_start_and_trace(self):
        self.assertEqual(COHORT.trials.session.astype(str).tolist(), ["r33d-S01-s1"] * 4 + ["r33d-S02-s1"] * 4)
        self.assertEqual(set(COHORT.trials.start_utc), {""})
        self.assertEqual(set(COHORT.trials.trace_file.astype(str)), {""})
        self.assertEqual(set(COHORT.trials.trace_sha256.astype(str)), {""})
        drop = ["session", "start_utc", "trace_file", "trace_sha256"]
        pd.testing.assert_frame_equal(COHORT.trials.drop(columns=drop), LOADED.trials.drop(columns=drop))
        pd.testing.assert_frame_equal(COHORT.strokes.drop(columns=["session"]),
                                      LOADED.strokes.drop(columns=["session"]))

    def test_cli_cohort_csv_equals_python_cohort(self):
        out = self.tmp / "t"
        out.mkdir()
        run_ok(["session", "cohort", P_JSON, "--subjects", "2", "--jobs", "1", "--csv", out], self.tmp)
        for table, frame, labels in (("trials.csv", COHORT.trials, LABELS),
                                     ("strokes.csv", COHORT.strokes, STROKE_LABELS)):
            csv = read_tables_csv(out / table, labels)
            self.assertEqual(list(frame.columns), list(csv.columns), table)
            for name in csv.columns:
                with self.subTest(table=table, column=name):
                    self.assert_same_column(name, frame[name], csv[name])

    def test_protocol_written_with_ascii_escapes_gives_the_same_cohort(self):
        escaped = write_json(self.tmp / "escaped.json", PROTOCOL, ensure_ascii=True)
        self.assertIn(b"\\u5341", escaped.read_bytes())
        study = calligraphy.cohort.simulate(escaped, 2, workers=1, progress=False)
        pd.testing.assert_frame_equal(study.trials, COHORT.trials)
        pd.testing.assert_frame_equal(study.strokes, COHORT.strokes)

    def test_same_name_other_bytes_is_refused_by_session_run_leaving_the_study(self):
        study = self.copy_study()
        before = tree(study)
        escaped = write_json(self.tmp / "escaped.json", PROTOCOL, ensure_ascii=True)
        result = run(["session", "run", escaped, "--subject", "S05", "--out", study], self.tmp)
        text = result.stderr.decode("utf-8", "replace")
        self.assertEqual(result.returncode, 1, text)
        self.assertNotIn("Traceback", text)
        self.assertIn("escaped.json", text)
        self.assertTrue(any(session_of(study, s).name in text for s in ("S01", "S02")), text)
        for path in (escaped, P_JSON):
            self.assertIn(hashlib.sha256(path.read_bytes()).hexdigest()[:12], text)
        self.assertEqual(tree(study), before)
        self.assertFalse((study / "S05").exists())

    def test_load_of_sessions_listed_in_any_order_gives_the_same_rows(self):
        s1, s2 = session_of(STUDY, "S01"), session_of(STUDY, "S02")
        a = calligraphy.study.load([str(s2), str(s1)])
        b = calligraphy.study.load((s1, s2))
        c = calligraphy.study.load(p for p in (s2, s1))
        for other in (b, c):
            pd.testing.assert_frame_equal(a.trials, other.trials)
            pd.testing.assert_frame_equal(a.strokes, other.strokes)
        drop = ["trace_file"]
        pd.testing.assert_frame_equal(a.trials.drop(columns=drop), LOADED.trials.drop(columns=drop))

    def test_relative_study_gives_relative_trace_files_as_report_does(self):
        tables = self.tmp / "rel"
        tables.mkdir()
        run_ok(["report", "study", "--csv", tables], ROOT)
        csv = read_tables_csv(tables / "trials.csv", LABELS)
        here = os.getcwd()
        os.chdir(ROOT)
        try:
            study = calligraphy.study.load("study")
            files = study.trials.trace_file.astype(str).tolist()
            self.assertEqual(files, csv.trace_file.tolist())
            self.assertTrue(all(f.startswith("study" + os.sep) for f in files), files)
            samples = study.samples(0)
        finally:
            os.chdir(here)
        pd.testing.assert_frame_equal(samples, LOADED.samples(0))


    def test_report_pages_hold_one_article_per_saved_trial(self):
        index = self.tmp / "pages.html"
        run_ok(["report", STUDY, "--out", index], self.tmp)
        self.assertTrue(index.is_file())
        for subject in ("S01", "S02"):
            session = session_of(STUDY, subject).name
            page = (self.tmp / "pages_files" / subject / f"{session}.html").read_text(encoding="utf-8")
            ids = re.findall(r'<article\b[^>]*\bid="([^"]*)"', page)
            self.assertEqual(ids, [f"trial-{session}-{n}" for n in range(1, 5)], subject)


class Dtypes(StudyCase):
    """docs/experiments.md "Tidy tables": counts integers, flags logical, SI floats, labels categorical."""

    def test_counts_are_integers_flags_booleans_metrics_floats(self):
        for frame in (LOADED.trials, COHORT.trials):
            for name in COUNTS:
                self.assertTrue(pd.api.types.is_integer_dtype(frame[name].dtype), f"{name}: {frame[name].dtype}")
            self.assertTrue(pd.api.types.is_bool_dtype(frame.completed_in_order.dtype))
            for name in METRICS:
                self.assertEqual(frame[name].dtype, np.float64, name)
            numeric = COUNTS + METRICS + ["completed_in_order"]
            self.assertEqual([n for n in numeric if frame[n].dtype == object], [])
        for name in ("written", "backwards", "assisted"):
            self.assertTrue(pd.api.types.is_bool_dtype(LOADED.strokes[name].dtype), name)
        for name in ("trial", "character", "stroke", "typical_id", "segments", "refused_segments"):
            self.assertTrue(pd.api.types.is_integer_dtype(LOADED.strokes[name].dtype), name)

    def test_labels_are_categoricals_with_the_control_first(self):
        for reader, study in (("study.load", LOADED), ("cohort.simulate", COHORT)):
            with self.subTest(reader=reader):
                t = study.trials
                for name in ("phase", "condition", "group", "item_set", "sequence", "trained_condition"):
                    self.assertIsInstance(t[name].dtype, pd.CategoricalDtype, name)
                self.assertEqual(set(t.group.astype(str)), {""})
                self.assertTrue(t.period.isna().all())
                self.assertTrue(t.phase.cat.ordered)
                self.assertEqual(list(t.condition.cat.categories), ["vision", "haptic"])

    def test_phases_are_ordered_in_the_protocols_order(self):
        path = write_json(self.tmp / "phases.json", PHASED)
        run_ok(["session", "run", path, "--subjects", "1", "--out", self.tmp / "s"], self.tmp)
        for reader, study in (("study.load", calligraphy.study.load(self.tmp / "s")),
                              ("cohort.simulate", calligraphy.cohort.simulate(path, 1, workers=1, progress=False))):
            with self.subTest(reader=reader):
                phase = study.trials.phase
                self.assertEqual(phase.astype(str).tolist(), ["pre-test", "training", "training", "post-test"])
                self.assertTrue(phase.cat.ordered)
                self.assertEqual(list(phase.cat.categories), ["pre-test", "training", "post-test"])
                self.assertEqual(list(study.trials.condition.cat.categories), ["unguided", "fixture"])
                self.assertTrue(phase.min() == "pre-test" and phase.max() == "post-test")

    def test_strokes_table_has_one_row_per_reference_stroke(self):
        expected = []
        for _, row in LOADED.trials.iterrows():
            scene = cg.Scene(row.characters)
            for c, placed in enumerate(scene.characters):
                for k, _stroke in enumerate(placed.strokes):
                    expected.append((row.subject, row.trial, c + 1, k + 1))
        got = list(zip(LOADED.strokes.subject.astype(str), LOADED.strokes.trial, LOADED.strokes.character,
                       LOADED.strokes.stroke))
        self.assertEqual(got, expected)
        lib = cg.CharacterLibrary.default()
        for _, row in LOADED.strokes.iterrows():
            ids = lib.load(row.character_text).typical_stroke_ids
            self.assertEqual(row.typical_id, ids[row.stroke - 1])

    def test_samples_columns_and_dtypes(self):
        samples = LOADED.samples(0)
        self.assertEqual(list(samples.columns), SAMPLE_FLOATS + ["state"] + SAMPLE_INTS)
        for name in SAMPLE_FLOATS:
            self.assertEqual(samples[name].dtype, np.float64, name)
        for name in SAMPLE_INTS:
            self.assertEqual(samples[name].dtype, np.int64, name)
        self.assertLessEqual(set(samples.state.astype(str)), {"SS", "AS", "CS", "WS"})
        self.assertIn("WS", set(samples.state.astype(str)))

    @unittest.skipIf(h5py is None, "h5py is not installed")
    def test_samples_equal_h5py_bit_for_bit(self):
        samples = LOADED.samples(2)
        with h5py.File(LOADED.trials.trace_file[2], "r") as f:
            for name, column in TRACE_NAMES.items():
                values = f[column][()] / 10 ** f[column].attrs["decimals"]
                self.assertTrue(np.array_equal(values, samples[name].to_numpy()), name)
            for name in SAMPLE_INTS:
                self.assertEqual(f[name][()].astype(np.int64).tolist(), samples[name].tolist(), name)

    def test_trace_command_text_reads_to_the_samples(self):
        result = run_ok(["trace", LOADED.trials.trace_file[5]], ROOT)
        text = pd.read_csv(io.BytesIO(result.stdout), float_precision="round_trip")
        samples = LOADED.samples(5)
        self.assertEqual(len(text), len(samples))
        for name, column in TRACE_NAMES.items():
            self.assertTrue(np.array_equal(text[column].to_numpy(float), samples[name].to_numpy()), name)
        self.assertEqual(text.state.astype(str).tolist(), samples.state.astype(str).tolist())

    def test_iter_samples_gives_every_trial_once_as_samples_does(self):
        labels = []
        for label, samples in LOADED.iter_samples():
            labels.append(label)
            if label in (0, 7):
                pd.testing.assert_frame_equal(samples, LOADED.samples(label))
        self.assertEqual(labels, list(LOADED.trials.index))

    def test_study_pickles_with_its_dtypes(self):
        again = pickle.loads(pickle.dumps(LOADED, protocol=pickle.HIGHEST_PROTOCOL))
        pd.testing.assert_frame_equal(again.trials, LOADED.trials)
        pd.testing.assert_frame_equal(again.strokes, LOADED.strokes)

    def test_cohort_trial_has_no_trace_a_data_error_saying_so(self):
        with self.assertRaises(cg.DataError) as caught:
            COHORT.samples(0)
        self.assertIn("trace", str(caught.exception))


class Damage(StudyCase):
    """A study damaged as a lab damages one: what load, samples and report say."""

    def test_missing_record_leaves_its_row_out_of_load_and_report(self):
        study = self.copy_study()
        record_path(session_of(study, "S01"), 2).unlink()
        loaded = calligraphy.study.load(study)
        s01 = loaded.trials[loaded.trials.subject == "S01"]
        self.assertEqual(s01.trial.tolist(), [1, 3, 4])
        self.assertEqual(len(loaded.trials), 7)
        tables = self.tmp / "t"
        tables.mkdir()
        run_ok(["report", study, "--csv", tables], self.tmp)
        self.assertEqual(len(read_tables_csv(tables / "trials.csv", LABELS)), 7)

    def test_cut_record_is_a_data_error_naming_it(self):
        study = self.copy_study()
        record = record_path(session_of(study, "S02"), 3)
        record.write_bytes(record.read_bytes()[:200])
        with self.assertRaises(cg.DataError) as caught:
            calligraphy.study.load(study)
        self.assertIn(record.name, str(caught.exception))
        tables = self.tmp / "t"
        tables.mkdir()
        self.assert_one_error(run(["report", study, "--csv", tables], self.tmp), 1, record.name)
        self.assertEqual(list(tables.iterdir()), [])

    def test_metric_of_another_type_names_the_record_and_pointer(self):
        study = self.copy_study()
        record = record_path(session_of(study, "S01"), 1)
        document = json.loads(record.read_text(encoding="utf-8"))
        self.assertIsInstance(document.get("mean_deviation_m"), float)
        document["mean_deviation_m"] = str(document["mean_deviation_m"])
        write_json(record, document)
        with self.assertRaises(cg.DataError) as caught:
            calligraphy.study.load(study)
        self.assertIn(record.name, str(caught.exception))
        self.assertIn("/mean_deviation_m", str(caught.exception))

    def test_specification_of_another_version_names_the_pointer(self):
        study = self.copy_study()
        record = record_path(session_of(study, "S02"), 4)
        document = json.loads(record.read_text(encoding="utf-8"))
        self.assertIn("version", document["specification"])
        document["specification"]["version"] = 999
        write_json(record, document)
        with self.assertRaises(cg.DataError) as caught:
            calligraphy.study.load(study)
        self.assertIn(record.name, str(caught.exception))
        self.assertIn("/specification/version", str(caught.exception))

    def test_record_copied_in_outside_the_plan_is_refused_naming_it_and_plan(self):
        study = self.copy_study()
        session = session_of(study, "S01")
        record = record_path(session, 4)
        extra = record.with_name(record.name.replace("004-", "005-"))
        shutil.copyfile(record, extra)
        with self.assertRaises(cg.DataError) as caught:
            calligraphy.study.load(study)
        self.assertIn(extra.name, str(caught.exception))
        self.assertIn("/plan", str(caught.exception))
        tables = self.tmp / "t"
        tables.mkdir()
        self.assert_one_error(run(["report", study, "--csv", tables], self.tmp), 1, extra.name, "/plan")

    def test_stray_files_beside_the_sessions_change_nothing(self):
        study = self.copy_study()
        (study / "notes.txt").write_text("pilot, day 1\n", encoding="utf-8")
        (study / "S01" / "README.md").write_text("subject S01\n", encoding="utf-8")
        (study / "scratch").mkdir()
        (study / "scratch" / "plot.py").write_text("print(1)\n", encoding="utf-8")
        loaded = calligraphy.study.load(str(study))
        drop = ["trace_file"]
        pd.testing.assert_frame_equal(loaded.trials.drop(columns=drop), LOADED.trials.drop(columns=drop))
        pd.testing.assert_frame_equal(loaded.strokes, LOADED.strokes)

    def test_trace_of_another_trial_is_refused_by_samples_and_report_naming_it(self):
        study = self.copy_study()
        session = session_of(study, "S01")
        first = record_path(session, 1).with_suffix(".trace.h5")
        third = record_path(session, 3).with_suffix(".trace.h5")
        a, b = first.read_bytes(), third.read_bytes()
        self.assertNotEqual(a, b)
        first.write_bytes(b)
        third.write_bytes(a)
        loaded = calligraphy.study.load(study)      # the tables never read a trace
        self.assertEqual(len(loaded.trials), 8)
        with self.assertRaises(cg.DataError) as caught:
            loaded.samples(0)
        self.assertIn(first.name, str(caught.exception))
        tables = self.tmp / "t"
        tables.mkdir()
        run_ok(["report", study, "--csv", tables], self.tmp)
        self.assert_one_error(run(["report", study, "--out", self.tmp / "pages.html"], self.tmp), 1, first.name)

    def test_cut_trace_is_a_data_error_naming_it(self):
        study = self.copy_study()
        trace = record_path(session_of(study, "S02"), 2).with_suffix(".trace.h5")
        trace.write_bytes(trace.read_bytes()[:-100])
        loaded = calligraphy.study.load(study)
        with self.assertRaises(cg.DataError) as caught:
            loaded.samples(5)
        self.assertIn(trace.name, str(caught.exception))
        self.assert_one_error(run(["trace", trace], self.tmp), 1, trace.name)

    def test_missing_trace_is_file_not_found(self):
        study = self.copy_study()
        record_path(session_of(study, "S02"), 1).with_suffix(".trace.h5").unlink()
        loaded = calligraphy.study.load(study)
        with self.assertRaises(FileNotFoundError):
            loaded.samples(loaded.trials.iloc[4])
        pd.testing.assert_frame_equal(loaded.samples(loaded.trials.iloc[5]), LOADED.samples(5))

    def test_session_of_another_study_is_refused_naming_session_json_and_study_id(self):
        study = self.copy_study()
        foreign = session_of(OTHER, "S09")
        (study / "S09").mkdir()
        shutil.copytree(foreign, study / "S09" / foreign.name)
        with self.assertRaises(cg.DataError) as caught:
            calligraphy.study.load(study)
        message = str(caught.exception)
        self.assertIn("session.json", message)
        self.assertIn(foreign.name, message)
        self.assertIn("/study_id", message)
        tables = self.tmp / "t"
        tables.mkdir()
        self.assert_one_error(run(["report", study, "--csv", tables], self.tmp), 1, "/study_id")

    def test_study_without_its_identity_file_names_the_missing_file(self):
        study = self.copy_study()
        (study / ".calligraphy-study.json").unlink()
        with self.assertRaises(cg.DataError) as caught:
            calligraphy.study.load(study)
        message = str(caught.exception)
        self.assertIn("session.json", message)
        self.assertIn("/study_id", message)
        self.assertIn(".calligraphy-study.json", message)

    def test_session_moved_under_another_subject_names_subject_id(self):
        study = self.copy_study()
        moved = session_of(study, "S02")
        moved.rename(study / "S01" / moved.name)
        with self.assertRaises(cg.DataError) as caught:
            calligraphy.study.load(study)
        message = str(caught.exception)
        self.assertIn("session.json", message)
        self.assertIn("/subject/id", message)


class Arguments(StudyCase):
    """Every wrong kind of argument to study.load, Study.samples, propose_characters and cohort.simulate."""

    def test_load_refuses_every_wrong_kind_of_paths(self):
        for value in (None, 42, 4.2, True):
            with self.subTest(paths=value), self.assertRaises(TypeError) as caught:
                calligraphy.study.load(value)
            self.assertIn("paths", str(caught.exception))
        with self.assertRaises(TypeError) as caught:
            calligraphy.study.load([str(STUDY), None])
        self.assertIn("paths", str(caught.exception))
        for value in ([], "", ()):
            with self.subTest(paths=value), self.assertRaises(ValueError):
                calligraphy.study.load(value)
        for value in ("a\0b", "\ud800"):
            with self.subTest(paths=value), self.assertRaises(cg.InvalidArgument) as caught:
                calligraphy.study.load(value)
            self.assertIn("paths", str(caught.exception))
        empty = self.tmp / "empty"
        empty.mkdir()
        for value in (empty, self.tmp / "missing"):
            with self.subTest(paths=value), self.assertRaises(cg.DataError) as caught:
                calligraphy.study.load(value)
            self.assertIn(value.name, str(caught.exception))

    def test_samples_refuses_every_wrong_kind_of_trial(self):
        for value in (None, [0], True, {"trial": 0}):
            with self.subTest(trial=value), self.assertRaises(TypeError) as caught:
                LOADED.samples(value)
            self.assertIn("trial", str(caught.exception))
        for value in (8, -1, 10 ** 6):
            with self.subTest(trial=value), self.assertRaises(KeyError):
                LOADED.samples(value)
        expected = LOADED.samples(3)
        pd.testing.assert_frame_equal(LOADED.samples(np.int64(3)), expected)
        pd.testing.assert_frame_equal(LOADED.samples(LOADED.trials.iloc[3]), expected)

    def test_simulate_refuses_every_wrong_kind_of_argument(self):
        simulate = calligraphy.cohort.simulate
        EITHER = (TypeError, ValueError)
        cases = [
            # docs/python.md: "`TypeError`/`ValueError` naming `subjects`, `workers` or `batch_size`"
            ({"subjects": 0}, ValueError, "subjects"), ({"subjects": 100001}, ValueError, "subjects"),
            ({"subjects": 1.5}, EITHER, "subjects"), ({"subjects": "2"}, EITHER, "subjects"),
            ({"subjects": None}, EITHER, "subjects"),
            ({"workers": 0}, ValueError, "workers"), ({"workers": 1025}, ValueError, "workers"),
            ({"workers": "2"}, EITHER, "workers"), ({"workers": 1.0}, EITHER, "workers"),
            ({"batch_size": 0}, ValueError, "batch_size"), ({"batch_size": 1.5}, EITHER, "batch_size"),
            ({"profile": 3}, TypeError, "profile"), ({"profile": None}, TypeError, "profile"),
            ({"profile": "expert"}, ValueError, "CohortSetup.writer_profile"),
            ({"learning": 1}, TypeError, "learning"),
            ({"learning": "fast"}, ValueError, "CohortSetup.writer_learning"),
            ({"individual_differences": 1}, TypeError, "individual_differences"),
            ({"individual_differences": "yes"}, TypeError, "individual_differences"),
            ({"client": object()}, TypeError, "client"), ({"client": "tcp://localhost:8786"}, TypeError, "client"),
            ({"protocol": 42}, TypeError, "protocol"), ({"protocol": None}, TypeError, "protocol"),
        ]
        for change, error, needle in cases:
            arguments = {"protocol": str(P_JSON), "subjects": 1, "workers": 1, "progress": False}
            arguments.update(change)
            with self.subTest(**{k: repr(v) for k, v in change.items()}):
                with self.assertRaises(error) as caught:
                    simulate(**arguments)
                self.assertIn(needle, str(caught.exception))

    def test_simulate_of_a_protocol_it_cannot_read_names_the_file(self):
        missing = self.tmp / "nothing.json"
        with self.assertRaises(cg.DataError) as caught:
            calligraphy.cohort.simulate(missing, 1, workers=1, progress=False)
        self.assertIn("nothing.json", str(caught.exception))

    def test_null_key_refused_alike_by_session_plan_and_simulate(self):
        path = write_json(self.tmp / "nulls.json", {**PROTOCOL, "version": None})
        result = run(["session", "plan", path, "--subjects", "1"], self.tmp)
        self.assert_one_error(result, 2, "nulls.json", "/version")
        with self.assertRaises(cg.DataError) as caught:
            calligraphy.cohort.simulate(path, 1, workers=1, progress=False)
        self.assertIn("nulls.json", str(caught.exception))
        self.assertIn("/version", str(caught.exception))

    def test_python_json_quirks_are_refused_naming_the_file(self):
        cases = {"infinity.json": {**PROTOCOL, "trial": {"max_duration_s": float("inf")}},
                 "nan.json": {**PROTOCOL, "trial": {"max_duration_s": float("nan")}},
                 "spaced.json": {**PROTOCOL, "name": "r33d study"},
                 "typo.json": {**PROTOCOL, "trails": {"max_duration_s": 30}}}
        for name, document in cases.items():
            path = write_json(self.tmp / name, document)
            with self.subTest(protocol=name):
                with self.assertRaises(cg.DataError) as caught:
                    calligraphy.cohort.simulate(path, 1, workers=1, progress=False)
                self.assertIn(name, str(caught.exception))
                self.assert_one_error(run(["session", "plan", path, "--subjects", "1"], self.tmp), (1, 2), name)

    def test_replay_condition_is_refused_by_python_and_cli_cohort(self):
        document = json.loads(json.dumps(PROTOCOL))
        document["conditions"][0] = {"name": "haptic", "mode": "replay"}
        path = write_json(self.tmp / "replay.json", document)
        with self.assertRaises(ValueError) as caught:
            calligraphy.cohort.simulate(path, 1, workers=1, progress=False)
        self.assertIn("replay", str(caught.exception))
        out = self.tmp / "t"
        out.mkdir()
        result = run(["session", "cohort", path, "--subjects", "1", "--csv", out], self.tmp)
        self.assert_one_error(result, 2, "replay.json", "/conditions/0/mode")
        self.assertEqual(list(out.iterdir()), [])

    def test_propose_characters_as_curriculum_json_and_its_wrong_arguments(self):
        result = run_ok(["curriculum", STUDY, "--subject", "S01", "--from", "木山中", "--count", "2", "--json"],
                        ROOT)
        proposed = calligraphy.study.propose_characters(str(STUDY), "S01", "木山中", count=2)
        self.assertEqual(proposed, json.loads(result.stdout))
        cases = [({"count": 0}, cg.InvalidArgument), ({"count": 1001}, cg.InvalidArgument),
                 ({"count": 2.0}, TypeError), ({"count": "2"}, TypeError),
                 ({"subject": "S77"}, cg.InvalidArgument), ({"candidates": ""}, cg.InvalidArgument),
                 ({"candidates": "\ud800"}, cg.InvalidArgument), ({"candidates": "é"}, cg.CharacterNotFound)]
        for change, error in cases:
            arguments = {"paths": str(STUDY), "subject": "S01", "candidates": "木山中", "count": 2}
            arguments.update(change)
            with self.subTest(**{k: repr(v) for k, v in change.items()}), self.assertRaises(error):
                calligraphy.study.propose_characters(**arguments)


class Executors(StudyCase):
    """docs/python.md: the tables do not depend on the threads, workers or batches."""

    def test_thread_pool_executor_gives_the_tables_of_threads(self):
        with concurrent.futures.ThreadPoolExecutor(2) as pool:
            study = calligraphy.cohort.simulate(str(P_JSON), 2, client=pool, progress=False)
        pd.testing.assert_frame_equal(study.trials, COHORT.trials)
        pd.testing.assert_frame_equal(study.strokes, COHORT.strokes)

    @unittest.skipIf(distributed is None, "dask.distributed is not installed")
    def test_dask_client_gives_the_tables_of_threads(self):
        cluster = distributed.LocalCluster(processes=False, n_workers=1, threads_per_worker=2,
                                           dashboard_address=None)
        client = distributed.Client(cluster)
        try:
            study = calligraphy.cohort.simulate(str(P_JSON), 2, client=client, batch_size=2, progress=False)
        finally:
            client.close()
            cluster.close()
        pd.testing.assert_frame_equal(study.trials, COHORT.trials)
        pd.testing.assert_frame_equal(study.strokes, COHORT.strokes)


class Statistics(StudyCase):
    """calligraphy.statistics on the tables: one subject, pd.NA, a missing label."""

    def test_learning_of_one_subject_is_its_own_phase_means(self):
        path = write_json(self.tmp / "phases.json", PHASED)
        trials = calligraphy.cohort.simulate(path, 1, workers=1, progress=False).trials
        table = calligraphy.statistics.learning(trials, "mean_deviation_m", "pre-test", "post-test")
        self.assertEqual(len(table), 1)
        pre = trials.mean_deviation_m[trials.phase == "pre-test"].mean()
        post = trials.mean_deviation_m[trials.phase == "post-test"].mean()
        self.assertAlmostEqual(float(table.gain.iloc[0]), pre - post, delta=1e-15)
        self.assertAlmostEqual(float(table.relative_gain.iloc[0]), (pre - post) / pre, delta=1e-12)

    def test_describe_counts_pd_na_in_a_nullable_outcome_as_missing(self):
        trials = LOADED.trials.copy()
        values = trials.mean_deviation_m.astype("Float64")
        values.iloc[0] = pd.NA
        trials["mean_deviation_m"] = values
        table = calligraphy.statistics.describe(trials, "mean_deviation_m", by=("condition",))
        nan = LOADED.trials.copy()
        nan.loc[0, "mean_deviation_m"] = np.nan
        expected = calligraphy.statistics.describe(nan, "mean_deviation_m", by=("condition",))
        pd.testing.assert_frame_equal(table, expected)
        row = table[table.condition.astype(str) == str(LOADED.trials.condition.iloc[0])].iloc[0]
        rest = LOADED.trials[LOADED.trials.condition == LOADED.trials.condition.iloc[0]].mean_deviation_m.iloc[1:]
        self.assertEqual(int(row.n_missing), 1)
        self.assertAlmostEqual(float(row["mean"]), float(rest.mean()), delta=1e-15)

    def test_describe_names_a_row_whose_condition_is_pd_na(self):
        trials = LOADED.trials.copy()
        trials["condition"] = trials.condition.astype(object)
        trials.loc[5, "condition"] = pd.NA
        with self.assertRaises(ValueError) as caught:
            calligraphy.statistics.describe(trials, "mean_deviation_m", by=("condition",))
        self.assertIn("condition", str(caught.exception))
        self.assertIn("5", str(caught.exception))

    def test_paired_comparison_of_one_subject_is_a_value_error(self):
        one = LOADED.trials[LOADED.trials.subject == "S01"]
        with self.assertRaises(ValueError):
            calligraphy.statistics.paired_comparison(one, "mean_deviation_m", "haptic", "vision")


if __name__ == "__main__":
    unittest.main()
