#!/usr/bin/env python3
"""Round 28G: an experimenter in Python, with numpy, pandas, matplotlib and Dask. From the docs alone
(docs/python.md: "Simulated trials", "Scoring any pen trace", "Writers, guidance modes", "Tables and figures",
"Sweeps", "Simulated cohorts", "A study's traces", "Errors", the pickling paragraph; docs/metrics.md "Trace CSV";
docs/cli.md "Pen traces: format and limits"; docs/experiments.md "A cohort in memory"; the docstrings of
`simulate_trial`, `score`, `TrialResult`, `calligraphy.frames`, `calligraphy.plot`, `calligraphy.experiments`,
`calligraphy.cohort.simulate` and `calligraphy.study.Study`).

What is attacked: a trial's arrays (shapes, dtypes, read-only, one servo period apart, emptied by
keep_trace=False with the same metrics), its DataFrames (columns and units named, the state categorical),
`score` fed the trial's own frame and columns of every dtype (float32, big-endian, strided, Fortran order,
nullable, masked, complex, text, timedelta, 0-d and 2-d, NaN and inf in one cell, a decreasing time, columns of
different lengths, duplicated or renamed, an index that is not 0..n-1), keyword arguments at and past their
ranges and of the wrong type, `sweep`'s checks before any trial runs (an Executor that counts its tasks), its
rows against `simulate_trial`, its table on a thread pool, the local process pool and a Dask client, failed
trials as rows with nullable columns, a worker killed (batch failed), the sweeping process ended by SIGTERM (no
worker left, by /proc), Ctrl-C in a long trial, pickles of results, metrics, parameters, tables and a study,
the figures read through their artists' gids, a cohort simulated in memory and its study's refusals.

CALLIGRAPHY_CLI names the program (unused here: every case is the Python module); PYTHONPATH the built package.
CALLIGRAPHY_SANITIZED=1 takes five cases.
"""
import concurrent.futures
import copy
import json
import os
import pickle
import signal
import subprocess
import sys
import tempfile
import threading
import time
import unittest
import warnings
from pathlib import Path

from outsider import descendants, run, running, sanitized_subset

try:
    import numpy as np
    import pandas as pd
    import calligraphy as cg
except ImportError:  # reported by each class's setUpClass
    np = pd = cg = None

load_tests = sanitized_subset({"test_error_classes_follow_the_documented_table",
                               "test_seed_range_and_type_are_checked_with_the_documented_message",
                               "test_nan_or_inf_in_one_cell_is_refused_naming_its_column",
                               "test_sweep_refuses_bad_arguments_before_any_task_is_submitted",
                               "test_match_stroke_takes_any_real_array_and_names_path_and_indices"})

TRACE_COLUMNS = ["t_s", "x_m", "y_m", "z_m", "fx_n", "fy_n", "fz_n", "state", "stroke", "element", "attempt",
                 "rewritten"]
PER_STROKE_COLUMNS = ["character", "acronym", "typical_id", "written", "assisted", "backwards",
                      "mean_deviation_m", "max_deviation_m", "rms_deviation_m", "outside_tube_share", "frechet_m",
                      "dtw_m", "path_length_m", "time_s", "mean_speed_m_s", "velocity_peaks", "normalised_jerk",
                      "completed", "attempts"]
_TRIALS = {}


def need_module():
    if cg is None:
        raise unittest.SkipTest("numpy, pandas and the calligraphy Python package (PYTHONPATH) are needed")


def trial(*args, **kw):
    """simulate_trial, once per set of arguments (every case reads the same few trials)."""
    key = repr((args, sorted(kw.items())))
    if key not in _TRIALS:
        _TRIALS[key] = cg.simulate_trial(*args, **kw)
    return _TRIALS[key]


def ten():
    """The one trial most cases read: 十, novice, guided, 1 kHz, seed 3."""
    return trial("十", seed=3)


def columns(r, **change):
    """The trial's trace as a dict of columns t, x, y, z (float64, contiguous), some replaced."""
    p = r.position_m
    cols = {"t": np.ascontiguousarray(r.time_s), "x": np.ascontiguousarray(p[:, 0]),
            "y": np.ascontiguousarray(p[:, 1]), "z": np.ascontiguousarray(p[:, 2])}
    cols.update(change)
    return cols


def values_of(tree, key):
    """Every value under `key` anywhere in a JSON-like tree of dicts and lists."""
    if isinstance(tree, dict):
        return [v for k, v in tree.items() if k == key] + [x for v in tree.values() for x in values_of(v, key)]
    if isinstance(tree, list):
        return [x for v in tree for x in values_of(v, key)]
    return []


def core(result):
    """What a score says, to compare two scores: the figures and every segment's verdict."""
    keys = ("mean_deviation_m", "max_deviation_m", "frechet_m", "dtw_m", "strokes_accepted", "strokes_written",
            "order_errors", "backwards_strokes", "completed_in_order")
    segments = [(s["begin"], s["end"], s["matched_stroke"],
                 None if s["verdict"] is None else (s["verdict"]["accepted"], s["verdict"]["refusal"]))
                for s in result["per_character"][0]["segments"]]
    return {k: result[k] for k in keys}, segments


class Trials(unittest.TestCase):
    """simulate_trial's arrays, DataFrames and metrics (docs/python.md "Simulated trials", "Tables and figures")."""

    @classmethod
    def setUpClass(cls):
        need_module()

    def test_trial_arrays_have_the_documented_shapes_dtypes_and_are_read_only(self):
        r = ten()
        n = len(r.time_s)
        self.assertGreater(n, 100)
        s = len(r.scene.strokes)
        self.assertEqual(s, 2)
        expected = {"time_s": ((n,), np.float64), "position_m": ((n, 3), np.float64),
                    "force_n": ((n, 3), np.float64), "state": ((n,), np.uint8), "stroke": ((n,), np.int64),
                    "element": ((n,), np.int64), "stroke_trace_range": ((s, 2), np.int64)}
        for name, (shape, dtype) in expected.items():
            a = getattr(r, name)
            self.assertEqual(a.shape, shape, name)
            self.assertEqual(a.dtype, dtype, name)
            self.assertFalse(a.flags.writeable, f"{name}: 'read-only, as every array the module returns'")
        with self.assertRaises(ValueError):
            r.position_m[0, 0] = 1.0
        copied = r.position_m.copy()
        copied[0, 0] = 1.0          # the documented way to change one
        self.assertNotEqual(r.position_m[0, 0], 1.0)
        # Every tick's state is one of the InteractionState values (uint8 of the enum's int).
        self.assertTrue(set(np.unique(r.state)) <= {int(v) for v in cg.InteractionState.__members__.values()})
        self.assertTrue((r.state == cg.InteractionState.writing).any())

    def test_ticks_are_one_servo_period_apart_and_the_time_limit_ends_the_trial(self):
        r = trial("十", rate_hz=500.0, max_duration_s=0.2)
        self.assertAlmostEqual(len(r.time_s), 100, delta=1)
        self.assertTrue(np.allclose(np.diff(r.time_s), 1 / 500.0, rtol=0, atol=1e-9), np.diff(r.time_s)[:5])
        self.assertEqual(r.metrics["end_reason"], "time_limit")
        self.assertEqual(r.metrics["rate_hz"], 500.0)

    def test_keep_trace_false_empties_the_arrays_and_keeps_the_same_metrics(self):
        full, bare = ten(), trial("十", seed=3, keep_trace=False)
        self.assertEqual(bare.time_s.shape, (0,))
        self.assertEqual(bare.position_m.shape, (0, 3))
        self.assertEqual(bare.force_n.shape, (0, 3))
        self.assertEqual(bare.state.shape, (0,))
        for key in ("mean_deviation_m", "max_deviation_m", "frechet_m", "dtw_m", "total_time_s", "trial_time_s",
                    "max_force_n", "strokes_accepted", "order_errors", "end_reason", "velocity_peaks"):
            self.assertEqual(bare.metrics[key], full.metrics[key], key)
        self.assertEqual(len(bare.to_dataframe()), 0, "'empty when the trial ran with keep_trace=False'")

    def test_the_same_seed_gives_the_same_arrays_and_another_seed_does_not(self):
        a = ten()
        b = cg.simulate_trial("十", seed=3)
        c = trial("十", seed=4)
        self.assertTrue(np.array_equal(a.position_m, b.position_m))
        self.assertTrue(np.array_equal(a.force_n, b.force_n))
        self.assertEqual(a.metrics, b.metrics)
        self.assertFalse(a.position_m.shape == c.position_m.shape and np.array_equal(a.position_m, c.position_m))

    def test_to_dataframe_names_every_column_with_its_unit_and_the_state_as_categories(self):
        r = ten()
        df = r.to_dataframe()
        self.assertEqual(list(df.columns), TRACE_COLUMNS)
        self.assertEqual(len(df), len(r.time_s))
        for name in TRACE_COLUMNS[:7]:
            self.assertEqual(df[name].dtype, np.float64, name)
        for name in ("stroke", "element", "attempt", "rewritten"):
            self.assertTrue(pd.api.types.is_integer_dtype(df[name]), name)
        self.assertIsInstance(df["state"].dtype, pd.CategoricalDtype)
        self.assertEqual(list(df["state"].cat.categories), ["SS", "AS", "CS", "WS"])
        names = [cg.InteractionState(int(v)).short_name for v in r.state]
        self.assertEqual(list(df["state"].astype(str)), names)
        self.assertTrue(np.array_equal(df["t_s"].to_numpy(), r.time_s))
        self.assertTrue(np.array_equal(df[["x_m", "y_m", "z_m"]].to_numpy(), r.position_m))
        self.assertTrue(np.array_equal(df[["fx_n", "fy_n", "fz_n"]].to_numpy(), r.force_n))
        self.assertTrue(np.array_equal(df["stroke"].to_numpy(), r.stroke))
        self.assertEqual([c["name"] for c in cg.trace_columns()][:len(TRACE_COLUMNS)], TRACE_COLUMNS)

    def test_per_stroke_dataframe_has_every_documented_column_for_each_stroke(self):
        r = ten()
        df = r.per_stroke_dataframe()
        self.assertEqual(list(df.index), [0, 1])
        self.assertEqual(df.index.name, "stroke")
        missing = [c for c in PER_STROKE_COLUMNS if c not in df.columns]
        self.assertEqual(missing, [], "docs/python.md lists these columns of per_stroke_dataframe()")
        per_stroke = r.metrics["per_character"][0]["per_stroke"]
        for k in range(2):
            self.assertEqual(df["mean_deviation_m"][k], per_stroke[k]["mean_deviation_m"])
            self.assertEqual(df["character"][k], "十")
            self.assertTrue(bool(df["written"][k]))
        self.assertEqual(list(df["typical_id"]), list(cg.CharacterLibrary.embedded().load("十").typical_stroke_ids))

    def test_metrics_are_in_metres_and_the_old_millimetre_key_reads_with_a_warning(self):
        m = ten().metrics
        self.assertGreater(m["mean_deviation_m"], 1e-5)
        self.assertLess(m["mean_deviation_m"], 5e-3, "a deviation in metres, not millimetres")
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            old = m["mean_deviation_mm"]
        self.assertAlmostEqual(old, 1000 * m["mean_deviation_m"], places=9)
        self.assertTrue(any(issubclass(w.category, DeprecationWarning) and "mean_deviation_m" in str(w.message)
                            for w in caught), [str(w.message) for w in caught])
        self.assertNotIn("mean_deviation_mm", list(m.keys()), "'a dict whose keys are the new names'")

    def test_score_of_the_trials_own_frame_and_columns_gives_the_trials_metrics(self):
        r = ten()
        by_frame = cg.score(r.to_dataframe(), r.scene)
        by_columns = cg.score(columns(r), "十")
        for key in ("mean_deviation_m", "max_deviation_m", "frechet_m", "dtw_m"):
            self.assertAlmostEqual(by_frame[key], r.metrics[key], delta=1e-12 + 1e-9 * abs(r.metrics[key]), msg=key)
            self.assertAlmostEqual(by_columns[key], r.metrics[key], delta=1e-12 + 1e-9 * abs(r.metrics[key]),
                                   msg=key)
        for key in ("strokes_accepted", "strokes_written", "order_errors", "backwards_strokes"):
            self.assertEqual(by_frame[key], r.metrics[key], key)
            self.assertEqual(by_columns[key], r.metrics[key], key)


    def test_metrics_have_exactly_the_keys_and_values_of_the_command_lines_json(self):
        r = ten()
        with tempfile.TemporaryDirectory(prefix="round28g-") as d:
            done = run(["trial", "十", "--seed", "3", "--json", "m.json"], d)
            self.assertEqual(done.returncode, 0, done.stderr.decode("utf-8", "replace"))
            cli = json.loads((Path(d) / "m.json").read_text(encoding="utf-8"))
        self.assertEqual(sorted(r.metrics.keys()), sorted(cli.keys()))
        for key in ("mean_deviation_m", "frechet_m", "total_time_s", "strokes_accepted", "end_reason", "seed"):
            if key in cli:
                self.assertEqual(r.metrics[key], cli[key], key)

    def test_a_rerun_of_the_metrics_their_pickle_json_or_checked_specification_gives_the_same_arrays(self):
        r = ten()
        for record in (r.metrics, pickle.loads(pickle.dumps(r.metrics)), json.loads(json.dumps(r.metrics)),
                       cg.check_trial_record(r.metrics)):
            again = cg.rerun_trial(record)
            self.assertTrue(np.array_equal(again.position_m, r.position_m))
            self.assertTrue(np.array_equal(again.force_n, r.force_n))
        with self.assertRaises(TypeError):
            cg.rerun_trial(42)
        with self.assertRaises(cg.DataError) as caught:
            cg.rerun_trial({})
        self.assertIn("specification", str(caught.exception))
        self.assertRegex(str(caught.exception), r"(^|\s)/\S*:", "naming the JSON pointer")

    def test_per_stroke_frame_old_millimetre_columns_read_from_copies_selections_and_pickles(self):
        df = ten().per_stroke_dataframe()
        for frame in (df, df.copy(), df.iloc[:1], pickle.loads(pickle.dumps(df))):
            with warnings.catch_warnings(record=True) as caught:
                warnings.simplefilter("always")
                old = frame["max_deviation_mm"]
            self.assertTrue(np.allclose(old.to_numpy(dtype=float), 1000 * frame["max_deviation_m"].to_numpy(float)))
            self.assertTrue(any(issubclass(w.category, DeprecationWarning) and "max_deviation_m" in str(w.message)
                                for w in caught))


class ScoreColumns(unittest.TestCase):
    """`score` given columns of every dtype and shape (docs/python.md "Scoring any pen trace", "Errors")."""

    @classmethod
    def setUpClass(cls):
        need_module()
        cls.r = ten()
        cls.base = core(cg.score(columns(cls.r), cls.r.scene))

    def score(self, cols):
        return cg.score(cols, self.r.scene)

    def refused(self, cols, *needles, error=None):
        with self.assertRaises(error or cg.InvalidArgument) as caught:
            self.score(cols)
        message = str(caught.exception)
        for needle in needles:
            self.assertIn(needle, message)
        return message

    def test_segments_are_the_runs_of_samples_on_paper_end_exclusive(self):
        cols = columns(self.r)
        down = cols["z"] - self.r.scene.layout.paper_z_m <= 0.0005
        edges = np.flatnonzero(np.diff(np.concatenate([[0], down.astype(np.int8), [0]])))
        runs = list(zip(edges[::2].tolist(), edges[1::2].tolist()))
        got = [(b, e) for b, e, _, _ in self.base[1]]
        self.assertEqual(got, runs)

    def test_float32_columns_score_as_the_float64_numbers_they_hold(self):
        c32 = {k: v.astype(np.float32) for k, v in columns(self.r).items()}
        c64 = {k: v.astype(np.float64) for k, v in c32.items()}
        self.assertEqual(core(self.score(c32)), core(self.score(c64)))

    def test_big_endian_fortran_and_strided_columns_score_as_native_ones(self):
        p = self.r.position_m
        fortran = np.asfortranarray(np.array(p))
        cols = {"t": self.r.time_s.astype(">f8"), "x": p[:, 0], "y": fortran[:, 1], "z": p[:, 2].astype(">f8")}
        self.assertFalse(cols["x"].flags.c_contiguous)
        self.assertEqual(core(self.score(cols)), self.base)
        every_other = {k: v[::2] for k, v in columns(self.r).items()}
        self.assertEqual(core(self.score(every_other)),
                         core(self.score({k: v.copy() for k, v in every_other.items()})))

    def test_a_frame_with_extra_columns_and_an_index_not_from_zero_scores_as_its_columns(self):
        df = pd.DataFrame(columns(self.r))
        df.index = 1000 + 2 * np.arange(len(df))
        df["pressure"] = 0.3
        df["note"] = "x"
        self.assertEqual(core(self.score(df)), self.base)
        shuffled_index = df.copy()
        shuffled_index.index = np.random.default_rng(0).permutation(len(df))
        self.assertEqual(core(self.score(shuffled_index)), self.base, "the rows in their order, not the labels'")

    def test_nullable_float64_columns_without_missing_values_score_as_float64(self):
        df = pd.DataFrame(columns(self.r)).astype("Float64")
        self.assertEqual(core(self.score(df)), self.base)

    def test_pen_column_takes_one_and_zero_as_ints_and_refuses_a_half(self):
        paper = self.r.scene.layout.paper_z_m
        cols = columns(self.r)
        pen = (cols.pop("z") - paper <= 0.0005)
        as_ints = dict(cols, pen=pen.astype(np.int64))
        as_floats = dict(cols, pen=pen.astype(np.float64))
        self.assertEqual(core(self.score(as_ints)), self.base)
        self.assertEqual(core(self.score(as_floats)), self.base)
        half = as_floats["pen"].copy()
        half[10] = 0.5
        self.refused(dict(cols, pen=half), "pen")
        two = as_floats["pen"].copy()
        two[10] = 2.0
        self.refused(dict(cols, pen=two), "pen")

    def test_complex_text_and_timedelta_columns_are_refused_naming_the_column(self):
        cols = columns(self.r)
        self.refused(dict(cols, x=cols["x"].astype(np.complex128)), "x")
        df = pd.DataFrame(cols)
        df["y"] = df["y"].map(repr)
        self.assertEqual(df["y"].dtype, object)
        self.refused(df, "y")
        df = pd.DataFrame(cols)
        df["t"] = pd.to_timedelta(df["t"], unit="s")
        self.refused(df, "t")

    def test_masked_array_with_a_value_masked_is_refused_and_one_without_is_its_numbers(self):
        cols = columns(self.r)
        masked = np.ma.masked_array(cols["y"], mask=np.zeros(len(cols["y"]), bool))
        self.assertEqual(core(self.score(dict(cols, y=masked))), self.base)
        one = masked.copy()
        one[40] = np.ma.masked
        self.refused(dict(cols, y=one), "y")

    def test_nan_or_inf_in_one_cell_is_refused_naming_its_column(self):
        cols = columns(self.r)
        for name, value in (("x", np.nan), ("y", np.inf), ("z", -np.inf), ("t", np.nan)):
            broken = cols[name].copy()
            broken[len(broken) // 2] = value
            with self.subTest(column=name, value=value):
                message = self.refused(dict(cols, **{name: broken}))
                self.assertRegex(message, rf"(^|[^a-z_]){name}(_[a-z]+)?([^a-z_]|$)")

    def test_a_time_before_the_one_above_it_is_refused(self):
        cols = columns(self.r)
        t = cols["t"].copy()
        t[300] = t[299] - 0.01
        with self.assertRaises((cg.InvalidArgument, cg.DataError)) as caught:
            self.score(dict(cols, t=t))
        self.assertRegex(str(caught.exception), r"(^|[^a-z_])t(_s)?([^a-z_]|$)|time")
        equal = cols["t"].copy()
        equal[300] = equal[299]
        self.score(dict(cols, t=equal))      # 'equal stamps are taken'

    def test_columns_of_different_lengths_are_refused_naming_each_and_its_length(self):
        cols = columns(self.r)
        n = len(cols["t"])
        message = self.refused(dict(cols, x=cols["x"][:-1]), "x", str(n - 1), str(n))
        self.assertIn("y", message)

    def test_a_column_under_both_names_or_pen_beside_z_is_refused_naming_both(self):
        cols = columns(self.r)
        self.refused(dict(cols, x_m=cols["x"]), "x", "x_m")
        self.refused(dict(cols, pen=np.ones_like(cols["z"])), "pen", "z")

    def test_a_missing_or_renamed_column_is_refused_naming_the_one_lacking(self):
        cols = columns(self.r)
        lacking = dict(cols)
        del lacking["y"]
        self.refused(lacking, "y")
        df = pd.DataFrame(cols).rename(columns={"x": "X"})
        self.refused(df, "x")
        in_mm = pd.DataFrame(cols).rename(columns={"x": "x_mm"})
        self.refused(in_mm, "x")

    def test_a_frame_naming_a_column_twice_is_refused_naming_it(self):
        df = pd.DataFrame(columns(self.r))
        twice = pd.concat([df, df[["x"]]], axis=1)
        self.assertEqual(list(twice.columns).count("x"), 2)
        self.refused(twice, "x")

    def test_zero_d_and_two_d_columns_are_refused_naming_them(self):
        cols = columns(self.r)
        self.refused(dict(cols, x=np.float64(0.01)), "x")
        self.refused(dict(cols, y=cols["y"].reshape(-1, 1)), "y")

    def test_one_sample_scores_nothing_written_with_absent_values_as_none(self):
        cols = {k: v[len(v) // 2:len(v) // 2 + 1] for k, v in columns(self.r).items()}
        cols["z"] = np.array([self.r.scene.layout.paper_z_m])
        result = self.score(cols)
        self.assertEqual(result["strokes_accepted"], 0)
        self.assertIsNone(result["mean_deviation_m"], "'a value that does not exist is None'")

    def test_data_units_and_integer_columns_score_as_metres_do(self):
        r = self.r
        placement = r.scene.characters[0].placement
        data = np.asarray(placement.to_data(r.position_m[:, :2]))
        self.assertEqual(data.shape, (len(r.time_s), 2))
        cols = columns(r, x=data[:, 0].copy(), y=data[:, 1].copy())
        in_data = cg.score(cols, "十", units="data")
        in_m = cg.score(columns(r), "十")
        for key in ("mean_deviation_m", "frechet_m", "dtw_m"):
            self.assertAlmostEqual(in_data[key], in_m[key], delta=1e-9, msg=key)
        self.assertEqual(in_data["strokes_accepted"], in_m["strokes_accepted"])
        rounded = columns(r, x=np.round(data[:, 0]).astype(np.int64), y=np.round(data[:, 1]).astype(np.int64))
        as_float = columns(r, x=np.round(data[:, 0]), y=np.round(data[:, 1]))
        self.assertEqual(core(cg.score(rounded, "十", units="data")), core(cg.score(as_float, "十", units="data")))
        with self.assertRaises(cg.InvalidArgument):
            cg.score(cols, "十二", units="data")

    def test_a_csv_pandas_wrote_with_a_byte_order_mark_scores_as_its_frame(self):
        df = self.r.to_dataframe()
        with tempfile.TemporaryDirectory(prefix="round28g-") as d:
            path = Path(d) / "trace.csv"
            df.to_csv(path, index=False, encoding="utf-8-sig")
            self.assertTrue(path.read_bytes().startswith(b"\xef\xbb\xbft_s,"))
            by_path = core(cg.score(path, self.r.scene))
            by_bytes = core(cg.score(os.fsencode(path), self.r.scene))
        self.assertEqual(by_path, core(self.score(df)))
        self.assertEqual(by_bytes, by_path)

    def test_score_options_out_of_range_or_of_the_wrong_type_are_named(self):
        cols = columns(self.r)
        for kw, error, needle in (({"start_radius_m": 0.0}, cg.InvalidArgument, "start_radius_m"),
                                  ({"contact_threshold_m": "x"}, TypeError, "contact_threshold_m"),
                                  ({"acceptance": 3}, TypeError, "acceptance")):
            with self.subTest(kw=kw):
                with self.assertRaises(error) as caught:
                    cg.score(cols, "十", **kw)
                self.assertIn(needle, str(caught.exception))

    def test_paths_that_cannot_be_read_are_named_and_a_failing_fspath_is_its_own_error(self):
        with tempfile.TemporaryDirectory(prefix="round28g-") as d:
            missing = str(Path(d) / "missing.csv")
            with self.assertRaises(cg.DataError) as caught:
                cg.score(missing, "十")
            self.assertIn("missing.csv", str(caught.exception))

        class Broken:
            def __fspath__(self):
                raise ZeroDivisionError("from __fspath__")
        with self.assertRaises(ZeroDivisionError):
            cg.score(Broken(), "十")
        with self.assertRaises(cg.InvalidArgument):
            cg.score("t\ud800.csv", "十")
        with self.assertRaises(cg.InvalidArgument):
            cg.score("t\0.csv", "十")

    def test_units_other_than_m_or_data_are_refused_naming_units(self):
        with self.assertRaises(cg.InvalidArgument) as caught:
            cg.score(columns(self.r), "十", units="mm")
        self.assertIn("units", str(caught.exception))

    def test_match_stroke_takes_any_real_array_and_names_path_and_indices(self):
        scene = self.r.scene
        path = np.asarray(scene.characters[0].strokes[1].median_m)
        base = cg.match_stroke(scene, 0, 1, path)
        self.assertTrue(base.accepted)
        p32 = path.astype(np.float32)
        for variant in (p32, p32.astype(">f4"), np.asfortranarray(p32)):
            got = cg.match_stroke(scene, 0, 1, variant)
            want = cg.match_stroke(scene, 0, 1, p32.astype(np.float64))
            self.assertEqual((got.accepted, got.refusal, got.mean_deviation_m),
                             (want.accepted, want.refusal, want.mean_deviation_m))
        one = cg.match_stroke(scene, 0, 1, path[:1])
        self.assertFalse(one.accepted)
        for bad in (np.zeros((0, 2)), np.zeros((4, 3)), np.float64(0.0), path.astype(np.complex128)):
            with self.assertRaises(cg.InvalidArgument) as caught:
                cg.match_stroke(scene, 0, 1, bad)
            self.assertIn("path_m", str(caught.exception))
        with self.assertRaises(IndexError) as caught:
            cg.match_stroke(scene, 0, 5, path)
        self.assertIn("stroke_index: 5 is not in 0..1", str(caught.exception))
        with self.assertRaises(IndexError) as caught:
            cg.match_stroke(scene, np.int64(-1), 0, path)
        self.assertIn("character_index", str(caught.exception))


class Arguments(unittest.TestCase):
    """Keyword arguments at and past their ranges (docs/python.md "Errors", simulate_trial's docstring)."""

    @classmethod
    def setUpClass(cls):
        need_module()

    def names(self, error, needle, *args, **kw):
        with self.assertRaises(error) as caught:
            cg.simulate_trial(*args, **kw)
        self.assertIn(needle, str(caught.exception))
        return str(caught.exception)

    def test_error_classes_follow_the_documented_table(self):
        table = {"Error": (Exception,), "InvalidArgument": (ValueError, cg.Error),
                 "DataError": (RuntimeError, cg.Error), "CharacterNotFound": (KeyError, cg.DataError),
                 "DeviceError": (RuntimeError, cg.Error), "DeviceNotFound": (LookupError, cg.DeviceError),
                 "DeviceUnavailable": (cg.DeviceError,), "CommunicationError": (ConnectionError, cg.DeviceError),
                 "SafetyFault": (cg.DeviceError,), "CalibrationNeeded": (cg.DeviceError,),
                 "RealtimeError": (cg.DeviceError,), "StateError": (RuntimeError, cg.Error)}
        for name, bases in table.items():
            cls = getattr(cg, name)
            for base in bases:
                self.assertTrue(issubclass(cls, base), f"{name} is a {base.__name__}")

    def test_a_character_outside_the_data_is_not_found_and_points_to_the_python_sources(self):
        message = self.names(cg.CharacterNotFound, "U+00E9", "é", max_duration_s=0.01)
        self.assertIn("é", message)
        self.assertIn("from_hanzi_writer", message)
        self.assertNotIn("--data", message, "'speak Python where the CLI would name its flags'")

    def test_rate_hz_range_and_type(self):
        self.names(cg.InvalidArgument, "rate_hz", "十", rate_hz=99.9, max_duration_s=0.1)
        self.names(cg.InvalidArgument, "rate_hz", "十", rate_hz=100001.0, max_duration_s=0.01)
        message = self.names(TypeError, "rate_hz", "十", rate_hz="fast")
        self.assertIn("str", message)
        self.assertEqual(len(cg.simulate_trial("十", rate_hz=100, max_duration_s=0.05).time_s), 5)
        self.assertEqual(len(cg.simulate_trial("十", rate_hz=np.int64(200), max_duration_s=np.float32(0.25)).time_s),
                         50)

    def test_max_duration_is_positive_and_within_ten_million_ticks(self):
        for value in (0.0, -1.0, float("nan"), float("inf")):
            with self.subTest(max_duration_s=value):
                self.names(cg.InvalidArgument, "max_duration_s", "十", max_duration_s=value)
        self.names(cg.InvalidArgument, "max_duration_s", "十", rate_hz=100000.0, max_duration_s=100.01)
        self.names(TypeError, "max_duration_s", "十", max_duration_s="1")

    def test_max_duration_is_at_most_a_day_and_ten_million_ticks(self):
        # First run: a finding (python.md said only "at most 10^7 ticks", and 90000 s at 100 Hz, 9e6 ticks, was
        # refused naming a bound of 86400 s no Python doc gave). python.md and the docstring now say "at most
        # 86400 s and 10^7 ticks": a day at 100 Hz is taken, a day and an hour refused naming the day.
        r = cg.simulate_trial("十", rate_hz=100.0, max_duration_s=86400.0, keep_trace=False)
        self.assertEqual(r.metrics["end_reason"], "completed")
        with self.assertRaises(cg.InvalidArgument) as caught:
            cg.simulate_trial("十", rate_hz=100.0, max_duration_s=90000.0, keep_trace=False)
        self.assertIn("86400", str(caught.exception))
        self.assertIn("max_duration_s", str(caught.exception))

    def test_a_scene_of_more_than_a_thousand_characters_is_refused_before_loading(self):
        for make in (lambda: cg.Scene("十" * 1001), lambda: cg.simulate_trial("十" * 1001, max_duration_s=0.01)):
            start = time.monotonic()
            with self.assertRaises(cg.InvalidArgument) as caught:
                make()
            self.assertRegex(str(caught.exception), r"1,?000")
            self.assertLess(time.monotonic() - start, 1.0)

    def test_seed_range_and_type_are_checked_with_the_documented_message(self):
        message = self.names(cg.InvalidArgument, "seed", "十", seed=2 ** 64, max_duration_s=0.01)
        self.assertIn("seed: 18446744073709551616 is out of range: expected an int in 0..18446744073709551615 "
                      "(0..2**64-1)", message)
        self.names(cg.InvalidArgument, "seed", "十", seed=-1, max_duration_s=0.01)
        self.names(cg.InvalidArgument, "seed", "十", seed=np.int64(-1), max_duration_s=0.01)
        self.names(TypeError, "seed", "十", seed=1.5, max_duration_s=0.01)
        r = cg.simulate_trial("十", seed=np.uint64(2 ** 64 - 1), max_duration_s=0.01)
        self.assertIn(2 ** 64 - 1, [int(v) for v in values_of(r.metrics["specification"], "seed")],
                      "the record states the seed that ran")

    def test_miss_counts_range_type_and_record(self):
        for name in ("hint_after_misses", "assist_after_misses"):
            with self.subTest(name=name):
                self.names(cg.InvalidArgument, name, "十", max_duration_s=0.01, **{name: 1001})
                self.names(cg.InvalidArgument, name, "十", max_duration_s=0.01, **{name: -1})
                self.names(TypeError, name, "十", max_duration_s=0.01, **{name: 2.0})
        r = cg.simulate_trial("十", max_duration_s=0.01, hint_after_misses=1000, assist_after_misses=0)
        acceptance = r.metrics["specification"]["force_law"]["acceptance"]
        self.assertEqual((acceptance["hint_after_misses"], acceptance["assist_after_misses"]), (1000, 0))

    def test_guidance_mode_against_guidance_off_and_the_deprecated_member_name(self):
        self.names(cg.InvalidArgument, "guidance_mode", "十", guidance=False, guidance_mode="fading",
                   max_duration_s=0.01)
        self.names(cg.InvalidArgument, "guidance_mode", "十", guidance_mode="no-such-mode", max_duration_s=0.01)
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            r = cg.simulate_trial("十", guidance_mode="assist_as_needed", max_duration_s=0.01)
        self.assertTrue(any(issubclass(w.category, DeprecationWarning) and "assist-as-needed" in str(w.message)
                            for w in caught), [str(w.message) for w in caught])
        self.assertIn("assist-as-needed", json.dumps(r.metrics["specification"]))
        self.assertNotIn("assist_as_needed", json.dumps(r.metrics["specification"]))

    def test_unknown_writer_or_writer_parameter_is_named(self):
        self.names(cg.InvalidArgument, "writer_params['no_such_key']", "十", writer_params={"no_such_key": 1.0},
                   max_duration_s=0.01)
        self.names(cg.InvalidArgument, "expert", "十", writer="expert", max_duration_s=0.01)
        self.names(TypeError, "writer", "十", writer=3, max_duration_s=0.01)
        self.names(cg.InvalidArgument, "writer_params['learning_rate']", "十", writer_params={"learning_rate": -1.0},
                   max_duration_s=0.01)


class CountingExecutor(concurrent.futures.Executor):
    """A concurrent.futures.Executor that runs each task in this thread and counts them."""

    def __init__(self):
        self.submitted = 0

    def submit(self, fn, /, *args, **kwargs):
        self.submitted += 1
        future = concurrent.futures.Future()
        try:
            future.set_result(fn(*args, **kwargs))
        except BaseException as e:  # noqa: BLE001 - handed to the future as an executor does
            future.set_exception(e)
        return future


class Sweeps(unittest.TestCase):
    """calligraphy.experiments.sweep (docs/python.md "Sweeps: many trials on every core or a Dask cluster")."""

    @classmethod
    def setUpClass(cls):
        need_module()
        from calligraphy import experiments
        cls.sweep = staticmethod(experiments.sweep)
        cls.small = ("十", {"guidance": [True, False]}, [0, 1])
        cls._base = None

    def base(self):
        """The small sweep's table on an Executor of one thread."""
        if Sweeps._base is None:
            with concurrent.futures.ThreadPoolExecutor(1) as ex:
                Sweeps._base = self.sweep(*self.small, client=ex, progress=False)
        return Sweeps._base

    def test_sweep_refuses_bad_arguments_before_any_task_is_submitted(self):
        ex = CountingExecutor()
        cases = [
            (ValueError, ["no_such_name", "guidance_stiffness_n_per_m"], ("十", {"no_such_name": [1]}, 1), {}),
            (ValueError, ["guidance"], ("十", {"guidance": []}, 1), {}),
            (TypeError, ["guidance"], ("十", {"guidance": ["yes"]}, 1), {}),
            (TypeError, ["rate_hz"], ("十", {"rate_hz": ["fast"]}, 1), {}),
            (ValueError, ["guidance_stiffness_n_per_m"], ("十", {"guidance_stiffness_n_per_m": [-1.0]}, 1), {}),
            (ValueError, ["seed"], ("十", {}, [-1]), {}),
            (ValueError, ["seed"], ("十", {}, [2 ** 64]), {}),
            (ValueError, ["1,?000,?000"], ("十二", {"guidance": [True, False]}, 250001), {}),
            (ValueError, ["1,?000,?000"], ("十", {}, 10 ** 18), {}),
            (ValueError, ["batch_size"], ("十", {}, 1), {"batch_size": 0}),
            (TypeError, ["guidance"], ("十", {"guidance": [1]}, 1), {}),
            (TypeError, ["guidance"], ("十", {"guidance": True}, 1), {}),
            (TypeError, ["grid"], ("十", [("guidance", [True])], 1), {}),
            (TypeError, ["characters"], (["十", 5], {}, 1), {}),
            (TypeError, ["guidance"], ("十", {"guidance": [np.int64(0)]}, 1), {}),
            (TypeError, ["max_duration_s"], ("十", {"max_duration_s": ["1"]}, 1), {}),
            (ValueError, ["seed"], ("十", {}, 0), {}),
            (ValueError, ["seed"], ("十", {}, []), {}),
        ]
        for error, needles, args, kw in cases:
            with self.subTest(args=args, kw=kw):
                start = time.monotonic()
                with self.assertRaises(error) as caught:
                    self.sweep(*args, client=ex, progress=False, **kw)
                self.assertLess(time.monotonic() - start, 2.0, "refused before any list of trials is built")
                for needle in needles:
                    self.assertRegex(str(caught.exception), needle)
                self.assertEqual(ex.submitted, 0)
        for workers in (0, 1025, -1):
            with self.subTest(workers=workers):
                with self.assertRaises(ValueError) as caught:
                    self.sweep("十", {}, 1, workers=workers, progress=False)
                self.assertIn("workers", str(caught.exception))
        with self.assertRaises(TypeError) as caught:
            self.sweep("十", {}, 1, client=object(), progress=False)
        self.assertIn("client", str(caught.exception))

    def test_a_seed_that_is_no_int_is_a_type_error_naming_seeds(self):
        # The docstring: "TypeError for a value of the wrong type ... (all before any trial runs)"; seeds are
        # "a list of ints"; simulate_trial(seed=1.5) is a TypeError too.
        ex = CountingExecutor()
        for seeds in ([1.5], [0, "1"], 2.0):
            with self.subTest(seeds=seeds):
                with self.assertRaises(TypeError) as caught:
                    self.sweep("十", {}, seeds, client=ex, progress=False)
                self.assertIn("seed", str(caught.exception))
        self.assertEqual(ex.submitted, 0)

    def test_characters_of_another_type_is_a_type_error_naming_characters(self):
        # python.md "Errors": "An argument of the wrong type raises TypeError naming the argument".
        ex = CountingExecutor()
        for characters in (5, 2.5, b"\xe5\x8d\x81"):
            with self.subTest(characters=characters):
                with self.assertRaises(TypeError) as caught:
                    self.sweep(characters, {}, 1, client=ex, progress=False)
                self.assertIn("characters", str(caught.exception))
        self.assertEqual(ex.submitted, 0)

    def test_sweep_rows_are_in_nesting_order_with_the_metrics_of_simulate_trial(self):
        ex = CountingExecutor()
        table = self.sweep("十二", {"guidance": [True, False], "max_duration_s": [30.0]}, [5, 0], client=ex,
                           batch_size=1, progress=False)
        self.assertEqual(ex.submitted, 8)
        self.assertEqual(list(table.index), list(range(8)))
        self.assertEqual(list(table.columns[:4]), ["character", "seed", "guidance", "max_duration_s"])
        self.assertIn("attempts_total", table.columns)
        self.assertEqual(table.columns[-1], "error")
        order = [(g, c, s) for g in (True, False) for c in "十二" for s in (5, 0)]
        self.assertEqual(list(zip(table.guidance, table.character, table.seed)), order)
        for i, (g, c, s) in enumerate(order):
            r = trial(c, guidance=g, seed=s, max_duration_s=30.0, keep_trace=False)
            row = table.iloc[i]
            self.assertIsNone(row["error"])
            for key in ("mean_deviation_m", "frechet_m", "total_time_s", "max_force_n", "end_reason"):
                self.assertEqual(row[key], r.metrics[key], (i, key))
            self.assertEqual(row["strokes_accepted"], r.metrics["strokes_accepted"])
            self.assertEqual(row["attempts_total"], int(r.per_stroke_dataframe()["attempts"].sum()))

    def test_numpy_grid_values_and_seeds_are_the_python_numbers_they_hold(self):
        table = self.sweep("十", {"guidance_stiffness_n_per_m": np.linspace(200, 400, 2)}, np.arange(2),
                           client=CountingExecutor(), progress=False)
        self.assertEqual(list(table.guidance_stiffness_n_per_m), [200.0, 200.0, 400.0, 400.0])
        self.assertEqual(list(table.seed), [0, 1, 0, 1])
        r = trial("十", seed=1, force_law=cg.ForceLawParameters(guidance_stiffness_n_per_m=400.0), keep_trace=False)
        self.assertEqual(table.mean_deviation_m[3], r.metrics["mean_deviation_m"])
        bools = self.sweep("十", {"guidance": np.array([True, False])}, 1, client=CountingExecutor(), progress=False)
        self.assertEqual(list(bools.guidance), [True, False])
        self.assertTrue(bools.error.isna().all(), list(bools.error))

    def test_qualified_and_nested_grid_names_give_the_trial_of_those_parameters(self):
        grid = {"force_law.guidance_stiffness_n_per_m": [300.0], "writer.bias_offset_m": [0.0],
                "nearest.method": ["newton"]}
        table = self.sweep("十", grid, [1], client=CountingExecutor(), progress=False)
        self.assertEqual(list(table.columns[:5]), ["character", "seed", *grid])
        self.assertIsNone(table.error[0])
        law = cg.ForceLawParameters(guidance_stiffness_n_per_m=300.0)
        law.nearest.method = "newton"
        r = cg.simulate_trial("十", seed=1, force_law=law, writer=cg.WriterProfile.novice().replace(bias_offset_m=0.0),
                              keep_trace=False)
        for key in ("mean_deviation_m", "total_time_s", "max_force_n"):
            self.assertEqual(table[key][0], r.metrics[key], key)

    def test_a_group_item_is_one_trial_written_left_to_right(self):
        table = self.sweep(["十二"], {}, [0], client=CountingExecutor(), progress=False)
        self.assertEqual(list(table.character), ["十二"])
        r = trial("十二", seed=0, keep_trace=False)
        self.assertEqual(table.strokes_total[0], 4)
        self.assertEqual(table.mean_deviation_m[0], r.metrics["mean_deviation_m"])

    def test_a_source_that_cannot_be_opened_is_a_data_error_before_any_task(self):
        ex = CountingExecutor()
        with tempfile.TemporaryDirectory(prefix="round28g-") as d:
            not_a_store = Path(d) / "notes.txt"
            not_a_store.write_text("not a corpus store\n", encoding="utf-8")
            for kw, needle in (({"data": str(Path(d) / "no-such-folder")}, "no-such-folder"),
                               ({"store": not_a_store}, "notes.txt")):
                with self.subTest(kw=kw):
                    with self.assertRaises(cg.DataError) as caught:
                        self.sweep("十", {}, 1, client=ex, progress=False, **kw)
                    self.assertIn(needle, str(caught.exception))
        self.assertEqual(ex.submitted, 0)

    def test_a_grid_name_that_is_also_a_metric_is_one_column(self):
        table = self.sweep("十", {"rate_hz": [500.0], "guidance": [True]}, 1, client=CountingExecutor(),
                           progress=False)
        self.assertTrue(table.columns.is_unique, [c for c in table.columns if list(table.columns).count(c) > 1])
        self.assertEqual(table["rate_hz"][0], 500.0)

    def test_a_max_duration_out_of_the_trials_range_is_an_error_row(self):
        table = self.sweep("十", {"max_duration_s": [float("nan"), 0.0, 0.05]}, 1, client=CountingExecutor(),
                           progress=False)
        errors = list(table.error)
        self.assertIn("max_duration_s", str(errors[0]))
        self.assertIn("max_duration_s", str(errors[1]))
        self.assertIsNone(errors[2])
        self.assertEqual(table.end_reason[2], "time_limit")

    def test_failed_trials_are_rows_with_the_error_and_nullable_columns(self):
        table = self.sweep(["é", "十"], {"rate_hz": [50.0, 1000.0]}, 1, client=CountingExecutor(), progress=False)
        self.assertEqual(len(table), 4)
        errors = list(table.error)
        self.assertTrue(errors[0].startswith("CharacterNotFound: "), errors[0])
        self.assertIn("U+00E9", errors[0])
        self.assertIn("rate_hz", errors[1])
        self.assertTrue(errors[2].startswith("CharacterNotFound: "), errors[2])
        self.assertIsNone(errors[3])
        self.assertEqual(str(table["strokes_accepted"].dtype), "Int64")
        self.assertEqual(str(table["order_errors"].dtype), "Int64")
        self.assertEqual(str(table["completed_in_order"].dtype), "boolean")
        self.assertTrue(table.loc[:2, "strokes_accepted"].isna().all())
        self.assertTrue(table.loc[:2, "mean_deviation_m"].isna().all())
        self.assertEqual(table.loc[3, "strokes_accepted"], 2)
        self.assertTrue(bool(table.loc[3, "completed_in_order"]))

    def test_local_process_pool_gives_the_executor_table_row_for_row(self):
        pool = self.sweep(*self.small, workers=2, batch_size=1, progress=False)
        pd.testing.assert_frame_equal(pool, self.base())
        self.assertEqual([p for p in _pool_workers(os.getpid()) if running(p)], [],
                         "the pool's workers are gone once the sweep returned")

    def test_dask_client_gives_the_executor_table_row_for_row(self):
        try:
            import distributed
        except ImportError:
            self.skipTest("distributed is not installed")
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            with tempfile.TemporaryDirectory(prefix="round28g-") as d, \
                    distributed.Client(processes=False, n_workers=1, threads_per_worker=1, dashboard_address=None,
                                       silence_logs=50) as client:
                table = self.sweep(*self.small, client=client, progress=False)
                protocol = Path(d) / "tiny.json"
                protocol.write_text(json.dumps(PROTOCOL), encoding="utf-8")
                import calligraphy.cohort
                on_dask = calligraphy.cohort.simulate(protocol, 2, client=client, progress=False).trials
                on_threads = calligraphy.cohort.simulate(protocol, 2, workers=1, progress=False).trials
        pd.testing.assert_frame_equal(table, self.base())
        pd.testing.assert_frame_equal(on_dask, on_threads)

    def test_the_table_pickles_and_its_old_millimetre_columns_still_read(self):
        table = self.base()
        with tempfile.TemporaryDirectory(prefix="round28g-") as d:
            path = Path(d) / "t.pkl"
            table.to_pickle(path)
            back = pd.read_pickle(path)
        pd.testing.assert_frame_equal(back, table)
        for frame in (back, back[back.seed == 0], copy.deepcopy(back)):
            with warnings.catch_warnings(record=True) as caught:
                warnings.simplefilter("always")
                old = frame["mean_deviation_mm"]
            self.assertTrue(np.allclose(old.to_numpy(dtype=float), 1000 * frame["mean_deviation_m"].to_numpy()))
            self.assertTrue(any(issubclass(w.category, DeprecationWarning) for w in caught))


def _cmdline(pid):
    try:
        return Path(f"/proc/{pid}/cmdline").read_bytes()
    except OSError:
        return b""


def _parent(pid):
    try:
        return int(Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[1])
    except OSError:
        return 0


def _pool_workers(root):
    """The process pool's workers below `root`: a forkserver's children, or processes started by 'spawn' (the
    forkserver and the resource tracker themselves are not workers)."""
    below = descendants(root)
    servers = {p for p in below if b"multiprocessing.forkserver" in _cmdline(p)}
    return [p for p in below if _parent(p) in servers or b"spawn_main" in _cmdline(p)]


def _cpu_s(pid):
    try:
        fields = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()
        return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")
    except OSError:
        return 0.0


SWEEP_SCRIPT = """
import sys
from calligraphy.experiments import sweep
if __name__ == "__main__":
    table = sweep("我", {"rate_hz": [100000.0], "max_duration_s": [90.0]}, [0], workers=1, progress=False)
    print(repr(list(table["error"])))
"""


class SweepProcesses(unittest.TestCase):
    """A worker killed and the sweeping process ended (docs/python.md "Sweeps", its last paragraphs)."""

    @classmethod
    def setUpClass(cls):
        need_module()
        cls.tmp = tempfile.TemporaryDirectory(prefix="round28g-")
        cls.script = Path(cls.tmp.name) / "long_sweep.py"
        cls.script.write_text(SWEEP_SCRIPT, encoding="utf-8")

    @classmethod
    def tearDownClass(cls):
        cls.tmp.cleanup()

    def start(self):
        """The script's process, every process below it once its pool's worker runs, and that worker."""
        proc = subprocess.Popen([sys.executable, str(self.script)], stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                                cwd=self.tmp.name)
        self.addCleanup(lambda: proc.poll() is None and proc.kill())
        deadline = time.monotonic() + 30
        while time.monotonic() < deadline:
            workers = _pool_workers(proc.pid)
            if workers and _cpu_s(workers[0]) >= 0.05:
                return proc, descendants(proc.pid), workers[0]
            if proc.poll() is not None:
                self.fail(f"the sweep ended before its worker ran: {proc.communicate()}")
            time.sleep(0.02)
        self.fail("no worker ran within 30 s")

    def test_a_killed_worker_gives_its_trials_batch_failed_and_the_sweep_returns(self):
        proc, below, worker = self.start()
        os.kill(worker, signal.SIGKILL)
        out, err = proc.communicate(timeout=60)
        self.assertEqual(proc.returncode, 0, err.decode("utf-8", "replace"))
        errors = eval(out.decode().strip().splitlines()[-1])  # noqa: S307 - the script's own repr of a list of str
        self.assertEqual(len(errors), 1)
        self.assertTrue(str(errors[0]).startswith("batch failed: "), errors)
        time.sleep(0.2)
        self.assertEqual([p for p in below if running(p)], [])

    def test_sigterm_to_the_sweeping_process_leaves_no_worker_and_no_forkserver(self):
        proc, below, worker = self.start()
        self.assertIn(worker, below)
        proc.send_signal(signal.SIGTERM)
        proc.communicate(timeout=30)
        deadline = time.monotonic() + 3
        while time.monotonic() < deadline and any(running(p) for p in below):
            time.sleep(0.05)
        left = [p for p in below if running(p)]
        for p in left:  # do not leave them burning the machine; the case fails anyway
            os.kill(p, signal.SIGKILL)
        self.assertEqual(left, [], "'no worker, and so no forkserver, outlives it'")


class Interrupt(unittest.TestCase):
    """Ctrl-C in a long trial (docs/python.md "Simulated trials")."""

    @classmethod
    def setUpClass(cls):
        need_module()

    def test_ctrl_c_stops_a_long_trial_soon_with_keyboard_interrupt(self):
        sent = []

        def interrupt():
            sent.append(time.monotonic())
            os.kill(os.getpid(), signal.SIGINT)
        timer = threading.Timer(0.1, interrupt)
        timer.start()
        try:
            with self.assertRaises(KeyboardInterrupt):
                cg.simulate_trial("我", rate_hz=100000.0, max_duration_s=90.0, keep_trace=False)
            ended = time.monotonic()
        finally:
            timer.cancel()
        self.assertEqual(len(sent), 1)
        self.assertLess(ended - sent[0], 0.6, "'stops its ticks within about 50 ms' and puts together its metrics")


class Pickles(unittest.TestCase):
    """docs/python.md, the paragraph after "Nearest point and force law": what pickles and what does not."""

    @classmethod
    def setUpClass(cls):
        need_module()

    def test_results_and_scenes_refuse_pickle_and_copy_with_a_type_error(self):
        r = ten()
        for obj, name in ((r, "TrialResult"), (r.scene, "Scene")):
            for protocol in range(0, pickle.HIGHEST_PROTOCOL + 1):
                with self.subTest(name=name, protocol=protocol):
                    with self.assertRaises(TypeError) as caught:
                        pickle.dumps(obj, protocol=protocol)
                    self.assertRegex(str(caught.exception), rf"cannot pickle '([\w.]+\.)?{name}' object")
            for how in (copy.copy, copy.deepcopy):
                with self.assertRaises(TypeError):
                    how(obj)

    def test_metrics_pickle_with_every_protocol_and_keep_their_type_and_old_keys(self):
        m = ten().metrics
        for protocol in range(0, pickle.HIGHEST_PROTOCOL + 1):
            with self.subTest(protocol=protocol):
                back = pickle.loads(pickle.dumps(m, protocol=protocol))
                self.assertEqual(back, m)
                self.assertIs(type(back), type(m))
                with warnings.catch_warnings(record=True) as caught:
                    warnings.simplefilter("always")
                    self.assertAlmostEqual(back["frechet_mm"], 1000 * m["frechet_m"], places=9)
                self.assertTrue(any(issubclass(w.category, DeprecationWarning) for w in caught))

    def test_parameters_pickle_with_every_protocol_and_run_the_same_trial(self):
        law = cg.ForceLawParameters(guidance_stiffness_n_per_m=321.0, friction_coefficient=0.2)
        law.nearest.method = "newton"
        writer = cg.WriterProfile.novice().replace(bias_offset_m=0)
        layout = cg.SceneLayout(character_size_m=0.05, spacing_m=0.06)
        for obj in (law, writer, layout, cg.StrokeAcceptance(hint_after_misses=2), cg.InteractionState.writing):
            for protocol in range(0, pickle.HIGHEST_PROTOCOL + 1):
                with self.subTest(obj=type(obj).__name__, protocol=protocol):
                    back = pickle.loads(pickle.dumps(obj, protocol=protocol))
                    self.assertEqual(repr(back), repr(obj))
        namespace = {"calligraphy": cg, "cg": cg, **vars(cg)}
        self.assertEqual(eval(repr(law), namespace).to_dict(), law.to_dict())  # noqa: S307 - "repr evaluates back"
        back = pickle.loads(pickle.dumps(law))
        self.assertEqual(back.nearest.method, cg.NearestPointMethod.newton)
        a = trial("十", seed=2, force_law=law, writer=writer, keep_trace=False).metrics
        b = cg.simulate_trial("十", seed=2, force_law=back, writer=pickle.loads(pickle.dumps(writer)),
                              keep_trace=False).metrics
        self.assertEqual(a["mean_deviation_m"], b["mean_deviation_m"])
        self.assertEqual(a["specification"], b["specification"])


class Figures(unittest.TestCase):
    """calligraphy.plot (docs/python.md "Tables and figures", the module's docstrings), read through the artists."""

    @classmethod
    def setUpClass(cls):
        need_module()
        try:
            import matplotlib
            matplotlib.use("Agg")
            import matplotlib.pyplot as plt
            from matplotlib.colors import to_rgba
            import calligraphy.plot as plot
        except ImportError as e:
            raise unittest.SkipTest(f"matplotlib is needed: {e}")
        cls.plt, cls.plot, cls.to_rgba = plt, plot, staticmethod(to_rgba)

    def tearDown(self):
        self.plt.close("all")

    def gid(self, ax, name):
        """The artists of `ax` (at any depth) whose gid is `name`."""
        return ax.findobj(lambda a: a.get_gid() == name)

    def test_trial_figure_draws_one_green_trace_per_stroke_in_millimetres(self):
        r = ten()
        ax = self.plot.trial(r)
        traces = self.gid(ax, "calligraphy-trace")
        self.assertEqual(len(traces), 2, "'one green line per stroke'")
        wanted = []
        for begin, end in r.stroke_trace_range:
            self.assertLess(begin, end)
            wanted.append(1000 * r.position_m[begin:end, :2])
        for line in traces:
            xy = np.column_stack([np.asarray(line.get_xdata(), float), np.asarray(line.get_ydata(), float)])
            self.assertTrue(any(xy.shape == w.shape and np.allclose(xy, w, atol=1e-9) for w in wanted),
                            "a trace line is the pen tip over a stroke's last attempt, in mm")
            self.assertEqual(self.to_rgba(line.get_color()), self.to_rgba(self.plot.TRACE_COLOUR))
        self.assertIn(ax.get_aspect(), ("equal", 1.0))
        self.assertTrue(self.gid(ax, "calligraphy-element"))
        self.assertEqual(self.gid(ax, "calligraphy-hint"), [], "hints=False by default")
        with_hints = self.plot.trial(r, hints=True)
        self.assertTrue(self.gid(with_hints, "calligraphy-hint"))

    def test_forces_figure_draws_the_in_plane_force_over_time_and_each_stroke_change(self):
        r = ten()
        ax = self.plot.forces(r)
        (magnitude,) = self.gid(ax, "calligraphy-in-plane-force")
        self.assertTrue(np.allclose(np.asarray(magnitude.get_xdata(), float), r.time_s))
        self.assertTrue(np.allclose(np.asarray(magnitude.get_ydata(), float), np.hypot(r.force_n[:, 0],
                                                                                      r.force_n[:, 1])))
        (fx,) = self.gid(ax, "calligraphy-fx")
        self.assertTrue(np.allclose(np.asarray(fx.get_ydata(), float), r.force_n[:, 0]))
        changes = np.flatnonzero(np.diff(r.stroke)) + 1
        boundaries = self.gid(ax, "calligraphy-stroke-boundary")
        self.assertEqual(len(boundaries), len(changes))
        self.assertTrue(self.gid(ax, "calligraphy-writing"))
        bare = self.plot.forces(r, components=False)
        self.assertEqual(self.gid(bare, "calligraphy-fx") + self.gid(bare, "calligraphy-fy"), [])

    def test_figures_draw_into_given_axes_and_name_a_bad_argument(self):
        r = ten()
        fig, ax = self.plt.subplots()
        self.assertIs(self.plot.trial(r, ax=ax), ax)
        self.assertIs(self.plot.forces(r, ax=ax), ax)
        for draw in (self.plot.trial, self.plot.forces):
            with self.assertRaises(TypeError) as caught:
                draw(r.metrics)
            self.assertIn("result", str(caught.exception))
            with self.assertRaises(TypeError) as caught:
                draw(r, ax=fig)
            self.assertIn("ax", str(caught.exception))
            with self.assertRaises(ValueError):
                draw(trial("十", seed=3, keep_trace=False))

    def test_a_trial_ended_after_its_first_stroke_draws_that_stroke_alone(self):
        full = ten()
        first_end = int(full.stroke_trace_range[0][1])
        r = trial("十", seed=3, max_duration_s=round(full.time_s[first_end] + 0.3, 3))
        strokes = r.per_stroke_dataframe()
        self.assertEqual(list(strokes["written"].astype(bool)), [True, False])
        ax = self.plot.trial(r)
        drawn = [a for a in self.gid(ax, "calligraphy-trace") if len(a.get_xdata())]
        self.assertEqual(len(drawn), 1)
        begin, end = r.stroke_trace_range[0]
        self.assertTrue(np.allclose(np.asarray(drawn[0].get_xdata(), float), 1000 * r.position_m[begin:end, 0]))
        self.assertEqual(r.stroke_trace_range[1][0], r.stroke_trace_range[1][1], "'empty when not written'")

    def test_a_trial_that_wrote_nothing_draws_the_reference_and_no_trace(self):
        r = trial("十", max_duration_s=0.05)
        self.assertFalse((r.state == cg.InteractionState.writing).any())
        ax = self.plot.trial(r)
        drawn = [a for a in self.gid(ax, "calligraphy-trace") if len(a.get_xdata())]
        self.assertEqual(drawn, [])
        self.assertTrue(self.gid(ax, "calligraphy-element"))
        forces = self.plot.forces(r)
        (magnitude,) = self.gid(forces, "calligraphy-in-plane-force")
        self.assertEqual(len(magnitude.get_xdata()), len(r.time_s))
        self.assertEqual(self.gid(forces, "calligraphy-writing"), [], "no tick in WS")
        strokes = r.per_stroke_dataframe()
        self.assertFalse(strokes["written"].astype(bool).any())
        self.assertTrue(strokes["mean_deviation_m"].isna().all(), "'None for a stroke not written'")


PROTOCOL = {"name": "tiny", "conditions": [{"name": "v", "mode": "vision"}, {"name": "h", "mode": "haptic"}],
            "test": {"characters": ["十"], "conditions": ["v", "h"], "repetitions": 1},
            "trial": {"max_duration_s": 30}}


class Cohort(unittest.TestCase):
    """calligraphy.cohort.simulate and the Study it gives (docs/python.md "Simulated cohorts", "A study's traces")."""

    @classmethod
    def setUpClass(cls):
        need_module()
        import calligraphy.cohort
        cls.simulate = staticmethod(calligraphy.cohort.simulate)
        cls.tmp = tempfile.TemporaryDirectory(prefix="round28g-")
        cls.protocol = Path(cls.tmp.name) / "tiny.json"
        cls.protocol.write_text(json.dumps(PROTOCOL), encoding="utf-8")
        cls.nothing = Path(cls.tmp.name) / "nothing.json"
        cls.nothing.write_text(json.dumps(dict(PROTOCOL, name="nothing", trial={"max_duration_s": 0.05})),
                               encoding="utf-8")

    @classmethod
    def tearDownClass(cls):
        cls.tmp.cleanup()

    def test_a_cohort_in_memory_is_a_study_of_tidy_tables_in_si_units(self):
        study = self.simulate(self.protocol, 2, workers=1, progress=False)
        trials = study.trials
        self.assertEqual(len(trials), 4)
        self.assertEqual(sorted(set(trials.subject)), ["S01", "S02"])
        self.assertEqual(sorted(set(trials.condition)), ["h", "v"])
        self.assertEqual(trials["mean_deviation_m"].dtype, np.float64)
        self.assertTrue(((trials.mean_deviation_m > 1e-5) & (trials.mean_deviation_m < 5e-3)).all())
        self.assertTrue((trials.start_utc.fillna("") == "").all())
        with self.assertRaises(cg.DataError):
            study.samples(trials.index[0])
        for bad in (None, [0], True):
            with self.subTest(trial=bad):
                with self.assertRaises(TypeError) as caught:
                    study.samples(bad)
                self.assertIn("trial", str(caught.exception))
        with self.assertRaises(KeyError):
            study.samples(10 ** 6)
        back = pickle.loads(pickle.dumps(study))
        pd.testing.assert_frame_equal(back.trials, trials)
        again = self.simulate(str(self.protocol), 2, workers=2, progress=False)
        pd.testing.assert_frame_equal(again.trials, trials, "'The tables do not depend on the threads'")

    def test_a_cohort_on_an_executor_runs_batches_of_subjects_and_gives_the_same_tables(self):
        threads = self.simulate(self.protocol, 3, workers=1, progress=False)
        ex = CountingExecutor()
        batched = self.simulate(self.protocol, 3, client=ex, batch_size=2, progress=False)
        self.assertEqual(ex.submitted, 2, "3 subjects in batches of 2")
        pd.testing.assert_frame_equal(batched.trials, threads.trials)
        pd.testing.assert_frame_equal(batched.strokes, threads.strokes)
        named = self.simulate(self.protocol, 1, prefix="P", workers=1, progress=False)
        self.assertEqual(sorted(set(named.trials.subject)), ["P01"])

    def test_ctrl_c_stops_a_cohort_on_every_thread_and_leaves_no_thread(self):
        long = Path(self.tmp.name) / "long.json"
        long.write_text(json.dumps(dict(PROTOCOL, name="long", test={"characters": ["我"], "conditions": ["v", "h"],
                                                                    "repetitions": 1},
                                        trial={"max_duration_s": 300, "rate_hz": 10000})), encoding="utf-8")
        tasks_before = len(os.listdir("/proc/self/task"))
        sent = []

        def interrupt():
            sent.append(time.monotonic())
            os.kill(os.getpid(), signal.SIGINT)
        timer = threading.Timer(0.1, interrupt)
        timer.start()
        try:
            with self.assertRaises(KeyboardInterrupt):
                self.simulate(long, 40, workers=2, progress=False)
            ended = time.monotonic()
        finally:
            timer.cancel()
        self.assertEqual(len(sent), 1)
        self.assertLess(ended - sent[0], 0.6, "'stops every running trial at its next tick'")
        self.assertLessEqual(len(os.listdir("/proc/self/task")), tasks_before, "'with no thread left'")

    def test_a_cohort_whose_trials_wrote_nothing_has_nan_outcomes(self):
        trials = self.simulate(self.nothing, 1, workers=1, progress=False).trials
        self.assertEqual(list(trials.end_reason), ["time_limit", "time_limit"])
        self.assertTrue(trials.mean_deviation_m.isna().all(), "'NaN for a trial that wrote nothing'")

    def test_cohort_arguments_are_checked_before_anything_is_made(self):
        cases = [(ValueError, "subjects", (self.protocol, 0), {}),
                 (ValueError, "subjects", (self.protocol, 100001), {}),
                 (TypeError, "subjects", (self.protocol, 1.5), {}),
                 (ValueError, "workers", (self.protocol, 1), {"workers": 0}),
                 (ValueError, "workers", (self.protocol, 1), {"workers": 1025}),
                 (TypeError, "client", (self.protocol, 1), {"client": object()}),
                 (TypeError, "individual_differences", (self.protocol, 1), {"individual_differences": "yes"}),
                 (TypeError, "protocol", (12, 1), {}),
                 (TypeError, "profile", (self.protocol, 1), {"profile": 3}),
                 (ValueError, "CohortSetup.writer_profile", (self.protocol, 1), {"profile": "expert"}),
                 (ValueError, "CohortSetup.writer_learning", (self.protocol, 1), {"learning": "bogus"}),
                 (cg.DataError, "missing.json", (Path(self.tmp.name) / "missing.json", 1), {})]
        for error, needle, args, kw in cases:
            with self.subTest(needle=needle, args=args, kw=kw):
                start = time.monotonic()
                with self.assertRaises(error) as caught:
                    self.simulate(*args, progress=False, **kw)
                self.assertIn(needle, str(caught.exception))
                self.assertLess(time.monotonic() - start, 2.0)


if __name__ == "__main__":
    unittest.main()
