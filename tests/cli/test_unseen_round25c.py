#!/usr/bin/env python3
"""Round 25C: the Python module as an experimenter uses it, as a matrix. From the docs alone (docs/python.md,
docs/experiments.md "Sessions", "Trace files", "Tidy tables"; docs/cli.md "Pen traces: format and limits",
"Re-running a trial"; docs/metrics.md; `help(calligraphy)` and the stub `_calligraphy.pyi`).

For each file or array a public function reads and each file it writes, one case per verb:
forge (passes a glance, one value changed), cut (truncated, empty, one sample, mismatched lengths), link (Path,
bytes, os.PathLike, symbolic links dangling or looping, a FIFO, output = input), fill (NaN, inf, limits,
byte order, layout, dtypes, pandas nullable, Dask), kill (SIGINT/SIGTERM during a long call), race (threads,
fork and spawn, pickling, use after garbage collection) and mislabel (a file of another kind, a list where one
value is, a keyword misspelt). Each expects the documented outcome, or the documented exception type naming the
thing; never a crash, a hang, a silently wrong result or a file replaced. Cases that could crash or hang the
interpreter run in a child interpreter with a timeout.

Left out: `write_report` and the statistics functions past their argument checks (a report fits mixed models
in R: seconds of CPU each, beyond the round's budget); `sweep` and `cohort.simulate` past their up-front
checks (a process pool or a cohort's threads: their own tests cover them); `run_trial` on hardware (no device
here); the kill verb on a study load (a load of this round's study takes milliseconds: there is no window to
signal into; the long call signalled is a real-time trial instead); Dask arrays only where a function takes
arrays (no function takes a Dask collection as a table). A corpus store cut by another process after it was
opened loads as it was (a store is read whole when opened, docs/corpus.md).
"""
import concurrent.futures
import copy
import gc
import json
import multiprocessing
import os
import pickle
import shutil
import signal
import subprocess
import sys
import tempfile
import textwrap
import unittest
import warnings
from pathlib import Path

import numpy as np

import calligraphy as cg
import calligraphy.study as study_module
from outsider import ENV, run_ok, sanitized_subset

load_tests = sanitized_subset({"test_score_csv_path_forms_score_the_same",
                               "test_rerun_record_with_seed_changed_warns",
                               "test_study_trace_swapped_with_another_trials_is_refused",
                               "test_score_nul_in_path_is_invalid_argument",
                               "test_sigint_during_real_time_trial_leaves_interpreter_and_fds_whole"})

PROTOCOL = {"name": "s", "conditions": [{"name": "V", "mode": "vision"}],
            "test": {"characters": ["一", "十"], "conditions": ["V"], "repetitions": 1},
            "trial": {"max_duration_s": 0.4}}
SEED = 3
CORPUS = Path(os.environ.get("CALLIGRAPHY_CORPUS_DIR", Path.home() / ".cache/calligraphy/hanzi-writer-data-2.0.1"))


class PathLikeBox:
    """An os.PathLike that is neither str nor pathlib.Path."""

    def __init__(self, path):
        self.path = str(path)

    def __fspath__(self):
        return self.path


def child(code, timeout=30):
    """`code` run by a fresh interpreter with this one's environment; its CompletedProcess (text)."""
    return subprocess.run([sys.executable, "-c", textwrap.dedent(code)], env=ENV, timeout=timeout,
                          stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)


def open_fds():
    return sorted(os.listdir("/proc/self/fd"))


def columns_of(result):
    p = result.position_m
    return {"t": np.array(result.time_s), "x": np.array(p[:, 0]), "y": np.array(p[:, 1]), "z": np.array(p[:, 2])}


def scored(trace, character="一", **kw):
    """The scalar figures of a score, for comparing two scores (the trace's own name left out)."""
    s = cg.score(trace, character, **kw)
    return {k: v for k, v in s.items()
            if k != "trace" and (isinstance(v, (int, float, bool, str)) or v is None)}


def trial_fn(seed):
    """A module-level function for worker processes."""
    r = cg.simulate_trial("一", max_duration_s=0.5, seed=seed)
    return r.metrics["mean_deviation_m"], float(r.position_m.sum())


class Round25C(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.tmp = Path(tempfile.mkdtemp(prefix="round25c-"))
        d = cls.tmp
        cls.trial = cg.simulate_trial("一", max_duration_s=2.0, seed=SEED)
        cls.record = cls.trial.metrics
        (d / "r.json").write_text(json.dumps(cls.record, ensure_ascii=False), encoding="utf-8")
        run_ok(["trial", "一", "--max-duration", "2", "--seed", SEED, "--csv", "r.csv"], d, ok=False)
        cls.csv_score = scored(str(d / "r.csv"))
        cls.columns = columns_of(cls.trial)
        cls.column_score = scored(cls.columns)
        cls.teacher = cg.record_teacher(cg.simulate_trial("一", writer="skilled", seed=1), d / "t.json")
        (d / "p.json").write_text(json.dumps(PROTOCOL, ensure_ascii=False), encoding="utf-8")
        run_ok(["session", "run", "p.json", "--subject", "S01", "--out", "study", "--writer-learning", "none"], d)
        cls.session = next((d / "study" / "S01").iterdir())
        cls.study = study_module.load(str(d / "study"))
        # A store and a hanzi-writer-data folder of two characters, when the data is there.
        (d / "hw").mkdir()
        cls.have_corpus = all((CORPUS / f"{ch}.json").is_file() for ch in "一十")
        if cls.have_corpus:
            for ch in "一十":
                shutil.copy(CORPUS / f"{ch}.json", d / "hw" / f"{ch}.json")
            run_ok(["corpus", "build", "--data", "hw", "--out", "s.clg", "--threads", "1"], d)

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.tmp, ignore_errors=True)

    def need_corpus(self):
        if not self.have_corpus:
            self.skipTest(f"no hanzi-writer-data at {CORPUS} (CALLIGRAPHY_CORPUS_DIR)")

    def case_dir(self):
        d = Path(tempfile.mkdtemp(dir=self.tmp))
        return d

    def assert_names(self, error, *needles):
        text = str(error.exception if hasattr(error, "exception") else error)
        for needle in needles:
            self.assertIn(needle, text)
        return text

    # ---------------------------------------------------------------- score: a trace file
    def test_score_csv_path_forms_score_the_same(self):
        p = self.tmp / "r.csv"
        for form in (p, bytes(p), PathLikeBox(p)):
            self.assertEqual(scored(form), self.csv_score, type(form))

    def test_score_csv_through_symlink_scores_the_same(self):
        d = self.case_dir()
        (d / "link.csv").symlink_to(self.tmp / "r.csv")
        self.assertEqual(scored(d / "link.csv"), self.csv_score)

    def test_score_dangling_symlink_names_the_file(self):
        d = self.case_dir()
        (d / "gone.csv").symlink_to(d / "nowhere.csv")
        with self.assertRaises((cg.DataError, OSError)) as e:
            cg.score(d / "gone.csv", "一")
        self.assert_names(e, "gone.csv")

    def test_score_symlink_loop_names_the_file_without_hanging(self):
        d = self.case_dir()
        (d / "a.csv").symlink_to(d / "b.csv")
        (d / "b.csv").symlink_to(d / "a.csv")
        with self.assertRaises((cg.DataError, OSError)) as e:
            cg.score(d / "a.csv", "一")
        self.assert_names(e, "a.csv")

    def test_score_fifo_is_refused_without_waiting(self):
        d = self.case_dir()
        os.mkfifo(d / "t.csv")
        got = child(f"""
            import calligraphy as cg
            try:
                cg.score({str(d / 't.csv')!r}, "一")
            except cg.DataError as e:
                print("refused:", e)
            """, timeout=20)
        self.assertIn("refused:", got.stdout, got.stderr)
        self.assertIn("t.csv", got.stdout)

    def test_score_folder_names_it(self):
        d = self.case_dir()
        with self.assertRaises((cg.DataError, OSError)) as e:
            cg.score(d, "一")
        self.assert_names(e, d.name)

    def test_score_truncated_csv_names_file_and_line(self):
        d = self.case_dir()
        text = (self.tmp / "r.csv").read_text(encoding="utf-8")
        lines = text.splitlines()
        cut = "\n".join(lines[:50]) + "\n" + lines[50].split(",")[0] + ","
        (d / "cut.csv").write_text(cut, encoding="utf-8")
        with self.assertRaises(cg.DataError) as e:
            cg.score(d / "cut.csv", "一")
        self.assert_names(e, "cut.csv", "51")

    def test_score_header_only_csv_is_scored_as_nothing_or_named(self):
        d = self.case_dir()
        header = (self.tmp / "r.csv").read_text(encoding="utf-8").splitlines()[0]
        (d / "h.csv").write_text(header + "\n", encoding="utf-8")
        try:
            s = cg.score(d / "h.csv", "一")
        except cg.DataError as e:
            self.assertIn("h.csv", str(e))
        else:
            self.assertEqual(s["strokes_written"], 0)

    def test_score_record_json_given_as_trace_is_named_for_what_it_is(self):
        with self.assertRaises(cg.DataError) as e:
            cg.score(self.tmp / "r.json", "一")
        self.assert_names(e, "r.json")

    def test_score_trace_h5_of_another_character_reads_its_columns(self):
        # docs/cli.md "score": a session's .trace.h5 is read by its columns t, x, y, z; scored against another
        # character than it wrote, it is scored as that, its samples all read.
        h5 = next(self.session.glob("trials/*U4E00.trace.h5"))
        samples = self.study.samples(self.study.trials.iloc[0])
        got = cg.score(h5, "十")
        self.assertEqual(got["samples"], len(samples))
        self.assertEqual(got["strokes_total"], 2)

    def test_score_list_of_paths_is_a_type_error(self):
        with self.assertRaises(TypeError) as e:
            cg.score([str(self.tmp / "r.csv")], "一")
        self.assert_names(e, "trace")

    def test_score_misspelt_keyword_is_a_type_error_naming_it(self):
        with self.assertRaises(TypeError) as e:
            cg.score(self.columns, "一", unit="m")
        self.assert_names(e, "unit")

    def test_score_units_mm_is_refused_naming_units(self):
        with self.assertRaises(cg.InvalidArgument) as e:
            cg.score(self.columns, "一", units="mm")
        self.assert_names(e, "units")

    def test_score_nul_in_path_is_invalid_argument(self):
        with self.assertRaises(cg.InvalidArgument):
            cg.score(str(self.tmp / "r\0.csv"), "一")

    # ---------------------------------------------------------------- score: columns
    def test_score_dataframe_of_to_dataframe_scores_as_columns(self):
        frame = self.trial.to_dataframe()
        self.assertEqual(scored(frame), self.column_score)

    def test_score_columns_in_mm_under_another_name_is_refused_naming_x(self):
        import pandas as pd
        frame = pd.DataFrame({"t_s": self.columns["t"], "x_mm": self.columns["x"] * 1e3,
                              "y_mm": self.columns["y"] * 1e3, "z_m": self.columns["z"]})
        with self.assertRaises(cg.InvalidArgument) as e:
            cg.score(frame, "一")
        self.assert_names(e, "x")

    def test_score_time_as_timedelta_is_refused_naming_t(self):
        import pandas as pd
        frame = pd.DataFrame(self.columns)
        frame["t"] = pd.to_timedelta(frame["t"], unit="s")
        with self.assertRaises(cg.InvalidArgument) as e:
            cg.score(frame, "一")
        self.assert_names(e, "t")

    def test_score_empty_columns_are_nothing_written_or_named(self):
        empty = {k: np.zeros(0) for k in "txyz"}
        try:
            s = cg.score(empty, "一")
        except cg.InvalidArgument as e:
            self.assertTrue(any(k in str(e) for k in ("t", "samples", "trace")), str(e))
        else:
            self.assertEqual(s["strokes_written"], 0)

    def test_score_one_sample_is_scored(self):
        one = {k: v[:1] for k, v in self.columns.items()}
        try:
            s = cg.score(one, "一")
        except cg.InvalidArgument as e:
            self.assertIn("sample", str(e))
        else:
            self.assertEqual(s["strokes_accepted"], 0)

    def test_score_mismatched_lengths_names_each_column_and_length(self):
        cols = dict(self.columns)
        cols["y"] = cols["y"][:-1]
        n = len(cols["x"])
        with self.assertRaises(cg.InvalidArgument) as e:
            cg.score(cols, "一")
        self.assert_names(e, "y", str(n - 1), str(n))

    def test_score_layouts_and_byte_orders_score_the_same(self):
        base = self.columns
        forms = {
            "big-endian": {k: v.astype(">f8") for k, v in base.items()},
            "non-contiguous": {k: np.repeat(v, 2)[::2] for k, v in base.items()},
            "read-only": {k: v.copy() for k, v in base.items()},
            "fortran": {k: np.asfortranarray(np.stack([v, v], axis=1))[:, 0] for k, v in base.items()},
        }
        for v in forms["read-only"].values():
            v.setflags(write=False)
        for name, cols in forms.items():
            self.assertEqual(scored(cols), self.column_score, name)

    def test_score_nan_position_is_refused_naming_the_column(self):
        cols = {k: v.copy() for k, v in self.columns.items()}
        cols["x"][10] = np.nan
        with self.assertRaises(cg.InvalidArgument) as e:
            cg.score(cols, "一")
        self.assert_names(e, "x")

    def test_score_inf_time_is_refused_naming_the_column(self):
        cols = {k: v.copy() for k, v in self.columns.items()}
        cols["t"][-1] = np.inf
        with self.assertRaises(cg.InvalidArgument) as e:
            cg.score(cols, "一")
        self.assert_names(e, "t")

    def test_score_negative_zero_and_denormal_read_as_numbers(self):
        cols = {k: v.copy() for k, v in self.columns.items()}
        cols["t"][0] = -0.0
        cols["x"][0] += 5e-324
        self.assertEqual(scored(cols), self.column_score)

    def test_score_complex_column_is_refused_naming_it(self):
        cols = dict(self.columns)
        cols["y"] = cols["y"].astype(complex)
        with self.assertRaises(cg.InvalidArgument) as e:
            cg.score(cols, "一")
        self.assert_names(e, "y")

    def test_score_pandas_nullable_with_na_is_refused_naming_it(self):
        import pandas as pd
        frame = pd.DataFrame(self.columns)
        frame["x"] = frame["x"].astype("Float64")
        frame.loc[5, "x"] = pd.NA
        with self.assertRaises(cg.InvalidArgument) as e:
            cg.score(frame, "一")
        self.assert_names(e, "x")

    def test_score_pandas_nullable_without_na_scores_the_same(self):
        import pandas as pd
        frame = pd.DataFrame(self.columns).astype("Float64")
        self.assertEqual(scored(frame), self.column_score)

    def test_score_pen_as_bool_equals_pen_as_int(self):
        pen = self.columns["z"] - self.trial.scene.layout.paper_z_m <= 0.0005
        base = {"t": self.columns["t"], "x": self.columns["x"], "y": self.columns["y"]}
        self.assertEqual(scored({**base, "pen": pen}), scored({**base, "pen": pen.astype(np.int64)}))

    def test_score_dask_columns_score_the_same(self):
        import dask.array as da
        cols = {k: da.from_array(v, chunks=256) for k, v in self.columns.items()}
        try:
            s = scored(cols)
        except (TypeError, cg.InvalidArgument) as e:
            self.assertTrue(any(k in str(e) for k in "txyz"), str(e))
        else:
            self.assertEqual(s, self.column_score)

    def test_score_two_dimensional_column_is_refused_naming_it(self):
        cols = dict(self.columns)
        cols["x"] = np.stack([cols["x"], cols["x"]], axis=1)
        with self.assertRaises(cg.InvalidArgument) as e:
            cg.score(cols, "一")
        self.assert_names(e, "x")

    def test_score_zero_d_column_is_refused_naming_it(self):
        cols = dict(self.columns)
        cols["z"] = np.float64(0.0).reshape(())
        with self.assertRaises(cg.InvalidArgument) as e:
            cg.score(cols, "一")
        self.assert_names(e, "z")

    def test_score_past_the_sample_limit_is_refused_and_at_it_is_read(self):
        n = 1_000_000
        t = np.arange(n + 1) * 1e-3
        lifted = {"t": t, "x": np.zeros(n + 1), "y": np.zeros(n + 1), "pen": np.zeros(n + 1, dtype=np.int8)}
        with self.assertRaises(cg.InvalidArgument) as e:
            cg.score(lifted, "一")
        self.assert_names(e, "1000000")
        at = {k: v[:n] for k, v in lifted.items()}
        self.assertEqual(cg.score(at, "一")["strokes_written"], 0)

    def test_score_character_as_list_of_str_is_a_row_or_named(self):
        try:
            s = scored(self.columns, ["一"])
        except (TypeError, cg.InvalidArgument) as e:
            self.assertIn("character", str(e))
        else:
            self.assertEqual(s, self.column_score)

    # ---------------------------------------------------------------- arrays of match_stroke, nearest_point
    def test_match_stroke_path_forms_give_the_same_verdict(self):
        scene = cg.Scene("永")
        path = np.array(scene.characters[0].strokes[1].median_m)
        want = cg.match_stroke(scene, 0, 1, path)
        for name, form in {"big-endian": path.astype(">f8"), "fortran": np.asfortranarray(path),
                           "non-contiguous": np.repeat(path, 2, axis=0)[::2],
                           "list": path.tolist()}.items():
            got = cg.match_stroke(scene, 0, 1, form)
            self.assertEqual((got.accepted, got.refusal, got.mean_deviation_m),
                             (want.accepted, want.refusal, want.mean_deviation_m), name)

    def test_match_stroke_empty_path_is_refused_naming_path_m(self):
        scene = cg.Scene("永")
        with self.assertRaises(cg.InvalidArgument) as e:
            cg.match_stroke(scene, 0, 1, np.zeros((0, 2)))
        self.assert_names(e, "path_m")

    def test_match_stroke_one_point_is_a_verdict(self):
        scene = cg.Scene("永")
        start = np.array(scene.characters[0].strokes[1].median_m)[:1]
        m = cg.match_stroke(scene, 0, 1, start)
        self.assertFalse(m.accepted)

    def test_match_stroke_three_d_and_nan_paths_are_refused_naming_path_m(self):
        scene = cg.Scene("永")
        path = np.array(scene.characters[0].strokes[1].median_m)
        bad_nan = path.copy()
        bad_nan[3, 1] = np.nan
        for name, bad in {"3-d": path[None, :, :], "(N, 3)": np.zeros((4, 3)), "nan": bad_nan,
                          "complex": path.astype(complex), "object": path.astype(str).astype(object)}.items():
            with self.assertRaises(cg.InvalidArgument, msg=name) as e:
                cg.match_stroke(scene, 0, 1, bad)
            self.assert_names(e, "path_m")

    def test_match_stroke_from_threads_agrees(self):
        scene = cg.Scene("永")
        paths = [cg.person_trace(scene, 0, 1, "human", seed=s) for s in range(8)]
        want = [cg.match_stroke(scene, 0, 1, p).covered_fraction for p in paths]
        with concurrent.futures.ThreadPoolExecutor(4) as pool:
            got = list(pool.map(lambda p: cg.match_stroke(scene, 0, 1, p).covered_fraction, paths))
        self.assertEqual(got, want)

    def test_nearest_point_dtypes(self):
        e = cg.Scene("一").strokes[0].elements[0]
        point = np.array([[0.001, 0.002]])
        want = cg.nearest_point(e, point)
        for name, form in {"int8": np.array([[0, 0]], dtype=np.int8), "bool": np.array([[False, True]])}.items():
            try:
                got = cg.nearest_point(e, form)
            except cg.InvalidArgument as err:
                self.assertIn("point", str(err), name)
            else:
                again = cg.nearest_point(e, form.astype(np.float64))
                np.testing.assert_array_equal(got[1], again[1], err_msg=name)
        with self.assertRaises(cg.InvalidArgument) as err:
            cg.nearest_point(e, point.astype(np.complex128))
        self.assert_names(err, "point")
        np.testing.assert_array_equal(cg.nearest_point(e, point.astype(np.float16).astype(np.float64))[0],
                                      cg.nearest_point(e, point.astype(np.float16))[0])
        self.assertEqual(len(want[0]), 1)

    def test_nearest_point_masked_array_is_refused_naming_point(self):
        e = cg.Scene("一").strokes[0].elements[0]
        masked = np.ma.masked_array([[0.001, 0.002]], mask=[[False, True]])
        with self.assertRaises(cg.InvalidArgument) as err:
            cg.nearest_point(e, masked)
        self.assert_names(err, "point")

    def test_placement_to_paper_of_read_only_and_dask_equals_plain(self):
        import dask.array as da
        placement = cg.Scene("一").characters[0].placement
        pts = np.array([[100.0, 200.0], [512.0, 512.0]])
        want = placement.to_paper(pts)
        ro = pts.copy()
        ro.setflags(write=False)
        np.testing.assert_array_equal(placement.to_paper(ro), want)
        np.testing.assert_array_equal(placement.to_paper(da.from_array(pts)), want)

    def test_clamp_force_non_finite_is_zero(self):
        forces = np.array([[np.nan, 0, 0], [np.inf, 1, 0], [3.0, 4.0, 0.0]])
        got = cg.clamp_force(forces, 2.5)
        np.testing.assert_array_equal(got[0], 0)
        np.testing.assert_array_equal(got[1], 0)
        np.testing.assert_allclose(got[2], [1.5, 2.0, 0.0])

    def test_paper_force_of_three_d_array_is_refused_naming_it(self):
        with self.assertRaises(cg.InvalidArgument) as e:
            cg.paper_force(np.zeros((2, 2, 2)), 0.0, 800.0)
        self.assert_names(e, "tip_z_m")

    # ---------------------------------------------------------------- rerun_trial, check_trial_record
    def test_rerun_record_path_forms_rerun_the_same(self):
        p = self.tmp / "r.json"
        for form in (str(p), p, bytes(p), PathLikeBox(p)):
            again = cg.rerun_trial(form)
            np.testing.assert_array_equal(again.position_m, self.trial.position_m, err_msg=repr(type(form)))

    def test_rerun_record_with_seed_changed_warns(self):
        record = copy.deepcopy(self.record)
        record["specification"]["trial"]["seed"] = SEED + 1
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            cg.rerun_trial(record)
        self.assertTrue(any(issubclass(w.category, RuntimeWarning) for w in caught),
                        [str(w.message) for w in caught])

    def test_rerun_record_of_other_characters_is_refused_naming_the_sha256(self):
        # docs/python.md "Running a trial again": characters other than the SHA-256 the record states.
        record = copy.deepcopy(self.record)
        record["specification"]["trial"]["characters"] = "十"
        with self.assertRaises((cg.DataError, cg.InvalidArgument)) as e:
            cg.rerun_trial(record)
        self.assert_names(e, "SHA-256")

    def test_rerun_truncated_record_names_file_and_byte(self):
        d = self.case_dir()
        text = (self.tmp / "r.json").read_bytes()
        (d / "cut.json").write_bytes(text[: len(text) // 2])
        with self.assertRaises(cg.DataError) as e:
            cg.rerun_trial(d / "cut.json")
        self.assert_names(e, "cut.json", "byte")

    def test_rerun_empty_dict_names_specification(self):
        with self.assertRaises(cg.DataError) as e:
            cg.rerun_trial({})
        self.assert_names(e, "specification")

    def test_rerun_dangling_symlink_names_it(self):
        d = self.case_dir()
        (d / "r.json").symlink_to(d / "gone.json")
        with self.assertRaises((cg.DataError, OSError)) as e:
            cg.rerun_trial(d / "r.json")
        self.assert_names(e, "r.json")

    def test_rerun_fifo_is_refused_without_waiting(self):
        d = self.case_dir()
        os.mkfifo(d / "r.json")
        got = child(f"""
            import calligraphy as cg
            try:
                cg.rerun_trial({str(d / 'r.json')!r})
            except cg.DataError as e:
                print("refused:", e)
            """, timeout=20)
        self.assertIn("refused:", got.stdout, got.stderr)
        self.assertIn("r.json", got.stdout)

    def test_rerun_csv_given_as_record_is_named_for_what_it_is(self):
        with self.assertRaises(cg.DataError) as e:
            cg.rerun_trial(self.tmp / "r.csv")
        self.assert_names(e, "r.csv", "CSV")

    def test_rerun_list_of_records_is_a_type_error(self):
        with self.assertRaises(TypeError):
            cg.rerun_trial([str(self.tmp / "r.json")])

    def test_rerun_misspelt_keyword_is_a_type_error_naming_it(self):
        with self.assertRaises(TypeError) as e:
            cg.rerun_trial(self.record, libary=None)
        self.assert_names(e, "libary")

    def test_check_record_seed_past_64_bits_names_the_pointer(self):
        record = copy.deepcopy(self.record)
        record["specification"]["trial"]["seed"] = 2 ** 64
        with self.assertRaises(cg.DataError) as e:
            cg.check_trial_record(record)
        self.assert_names(e, "/specification/trial/seed")

    def test_check_record_key_twice_names_the_pointer(self):
        d = self.case_dir()
        text = (self.tmp / "r.json").read_text(encoding="utf-8")
        text = text.replace('"seed": %d' % SEED, '"seed": %d, "seed": %d' % (SEED, SEED + 1), 1)
        self.assertIn('"seed": %d, "seed"' % SEED, text)
        (d / "twice.json").write_text(text, encoding="utf-8")
        with self.assertRaises(cg.DataError) as e:
            cg.check_trial_record(d / "twice.json")
        self.assert_names(e, "twice.json", "seed")

    def test_check_record_round_trips(self):
        spec = cg.check_trial_record(self.record)
        self.assertEqual(cg.check_trial_record({"specification": spec}), spec)

    def test_rerun_from_threads_gives_equal_traces(self):
        with concurrent.futures.ThreadPoolExecutor(3) as pool:
            runs = list(pool.map(lambda _: cg.rerun_trial(self.record).position_m, range(3)))
        for got in runs:
            np.testing.assert_array_equal(got, self.trial.position_m)

    # ---------------------------------------------------------------- teachers
    def test_teacher_path_forms_load_the_same(self):
        p = self.tmp / "t.json"
        for form in (str(p), p, bytes(p), PathLikeBox(p)):
            self.assertEqual(cg.TeacherRecording.load(form).to_json(), self.teacher.to_json())

    def test_teacher_truncated_names_the_file(self):
        d = self.case_dir()
        text = (self.tmp / "t.json").read_bytes()
        (d / "t.json").write_bytes(text[: len(text) // 3])
        with self.assertRaises(cg.DataError) as e:
            cg.TeacherRecording.load(d / "t.json")
        self.assert_names(e, "t.json")

    def test_teacher_csv_given_is_named_for_what_it_is(self):
        with self.assertRaises(cg.DataError) as e:
            cg.TeacherRecording.load(self.tmp / "r.csv")
        self.assert_names(e, "r.csv", "CSV")

    def test_teacher_from_json_key_twice_names_the_source(self):
        doc = json.loads(self.teacher.to_json())
        key = next(iter(doc))
        text = self.teacher.to_json().replace("{", "{%s: %s, " % (json.dumps(key), json.dumps(doc[key])), 1)
        with self.assertRaises(cg.DataError) as e:
            cg.TeacherRecording.from_json(text, "pasted.json")
        self.assert_names(e, "pasted.json", key)

    def test_teacher_save_over_its_own_file_keeps_it(self):
        d = self.case_dir()
        shutil.copy(self.tmp / "t.json", d / "t.json")
        before = (d / "t.json").read_bytes()
        cg.TeacherRecording.load(d / "t.json").save(d / "t.json")
        self.assertEqual((d / "t.json").read_bytes(), before)
        self.assertEqual(sorted(p.name for p in d.iterdir()), ["t.json"])

    def test_teacher_save_into_missing_folder_names_it_and_makes_nothing(self):
        d = self.case_dir()
        with self.assertRaises((cg.Error, OSError)) as e:
            self.teacher.save(d / "no" / "t.json")
        self.assert_names(e, "t.json")
        self.assertEqual(list(d.iterdir()), [])

    def test_teacher_save_over_a_folder_keeps_the_folder(self):
        d = self.case_dir()
        (d / "t.json").mkdir()
        (d / "t.json" / "keep").write_text("x")
        with self.assertRaises((cg.Error, OSError)) as e:
            self.teacher.save(d / "t.json")
        self.assert_names(e, "t.json")
        self.assertEqual((d / "t.json" / "keep").read_text(), "x")

    def test_teacher_save_over_a_symlink_replaces_its_target_and_keeps_the_link(self):
        # docs/cli.md "Conventions": a single output file follows a symbolic link; the link stays a link.
        d = self.case_dir()
        outside = self.case_dir() / "target.json"
        outside.write_text("old")
        (d / "t.json").symlink_to(outside)
        self.teacher.save(d / "t.json")
        self.assertTrue((d / "t.json").is_symlink())
        self.assertEqual(cg.TeacherRecording.load(outside).to_json(), self.teacher.to_json())
        self.assertEqual(sorted(p.name for p in outside.parent.iterdir()), ["target.json"])

    def test_record_teacher_path_forms_write_the_same(self):
        d = self.case_dir()
        for i, form in enumerate((d / "a.json", bytes(d / "b.json"), PathLikeBox(d / "c.json"))):
            cg.record_teacher(cg.simulate_trial("一", writer="skilled", seed=1), form)
        texts = {(d / n).read_text(encoding="utf-8") for n in ("a.json", "b.json", "c.json")}
        self.assertEqual(len(texts), 1)
        self.assertEqual(texts.pop(), (self.tmp / "t.json").read_text(encoding="utf-8"))

    def test_record_teacher_without_trace_names_it_and_writes_nothing(self):
        d = self.case_dir()
        r = cg.simulate_trial("一", writer="skilled", seed=1, keep_trace=False)
        with self.assertRaises(cg.Error) as e:
            cg.record_teacher(r, d / "t.json")
        self.assert_names(e, "trace")
        self.assertFalse((d / "t.json").exists())

    def test_teacher_of_another_character_is_refused_naming_teacher(self):
        with self.assertRaises(cg.InvalidArgument) as e:
            cg.simulate_trial("十", teacher=self.teacher, max_duration_s=0.2)
        self.assert_names(e, "teacher")

    def test_teacher_as_list_of_str_is_a_type_error_naming_teacher(self):
        with self.assertRaises(TypeError) as e:
            cg.simulate_trial("一", teacher=[str(self.tmp / "t.json")], max_duration_s=0.2)
        self.assert_names(e, "teacher")

    def test_teacher_does_not_pickle(self):
        with self.assertRaises(TypeError) as e:
            pickle.dumps(self.teacher)
        self.assert_names(e, "cannot pickle")

    # ---------------------------------------------------------------- character libraries
    def test_store_path_forms_load_the_same(self):
        self.need_corpus()
        p = self.tmp / "s.clg"
        want = cg.CharacterLibrary.from_store(str(p)).load("十").strokes[1].elements[0].control_points
        d = self.case_dir()
        (d / "link.clg").symlink_to(p)
        for form in (p, bytes(p), PathLikeBox(p), d / "link.clg"):
            got = cg.CharacterLibrary.from_store(form).load("十").strokes[1].elements[0].control_points
            np.testing.assert_array_equal(got, want, err_msg=repr(form))

    def test_store_truncated_names_the_file(self):
        self.need_corpus()
        d = self.case_dir()
        data = (self.tmp / "s.clg").read_bytes()
        (d / "cut.clg").write_bytes(data[: len(data) - 7])
        with self.assertRaises(cg.DataError) as e:
            cg.CharacterLibrary.from_store(d / "cut.clg").load("十")
        self.assert_names(e, "cut.clg")

    def test_store_one_byte_changed_is_refused_or_named(self):
        self.need_corpus()
        d = self.case_dir()
        data = bytearray((self.tmp / "s.clg").read_bytes())
        data[len(data) // 2] ^= 0x40
        (d / "forged.clg").write_bytes(bytes(data))
        with self.assertRaises(cg.DataError) as e:
            lib = cg.CharacterLibrary.from_store(d / "forged.clg")
            for ch in "一十":
                lib.load(ch)
        self.assert_names(e, "forged.clg")

    def test_store_json_given_is_named(self):
        with self.assertRaises(cg.DataError) as e:
            cg.CharacterLibrary.from_store(self.tmp / "r.json")
        self.assert_names(e, "r.json")

    def test_store_folder_given_is_named(self):
        self.need_corpus()
        with self.assertRaises((cg.DataError, OSError)) as e:
            cg.CharacterLibrary.from_store(self.tmp / "hw")
        self.assert_names(e, "hw")

    def test_store_truncated_while_mapped_does_not_crash(self):
        self.need_corpus()
        d = self.case_dir()
        shutil.copy(self.tmp / "s.clg", d / "s.clg")
        got = child(f"""
            import os, calligraphy as cg
            lib = cg.CharacterLibrary.from_store({str(d / 's.clg')!r})
            os.truncate({str(d / 's.clg')!r}, 0)
            try:
                c = lib.load("十")
                print("loaded", len(c.strokes))
            except cg.Error as e:
                print("refused:", e)
            """)
        self.assertEqual(got.returncode, 0, got.stderr)
        self.assertTrue(got.stdout.startswith("loaded 2"), got.stdout)

    def test_hanzi_writer_forged_character_file_names_it(self):
        self.need_corpus()
        d = self.case_dir()
        doc = json.loads((self.tmp / "hw" / "十.json").read_text(encoding="utf-8"))
        doc["medians"] = doc["medians"][:1]
        (d / "十.json").write_text(json.dumps(doc), encoding="utf-8")
        with self.assertRaises(cg.DataError) as e:
            cg.CharacterLibrary.from_hanzi_writer(d).load("十")
        self.assert_names(e, "十.json")

    def test_hanzi_writer_missing_folder_names_it(self):
        d = self.case_dir() / "nope"
        with self.assertRaises((cg.Error, OSError)) as e:
            cg.CharacterLibrary.from_hanzi_writer(d).load("十")
        self.assert_names(e, "nope")

    def test_character_outlives_its_library(self):
        self.need_corpus()
        lib = cg.CharacterLibrary.from_store(self.tmp / "s.clg")
        c = lib.load("十")
        want = np.array(c.strokes[1].median)
        del lib
        gc.collect()
        np.testing.assert_array_equal(c.strokes[1].median, want)
        r = cg.simulate_trial(c, max_duration_s=0.3, seed=1)
        self.assertEqual(r.metrics["character"], "十")

    def test_library_loads_from_threads_agree(self):
        self.need_corpus()
        lib = cg.CharacterLibrary.from_store(self.tmp / "s.clg")
        want = np.array(lib.load("十").strokes[0].elements[0].control_points)
        with concurrent.futures.ThreadPoolExecutor(4) as pool:
            got = list(pool.map(lambda _: np.array(lib.load("十").strokes[0].elements[0].control_points),
                                range(16)))
        for g in got:
            np.testing.assert_array_equal(g, want)

    def test_library_does_not_pickle(self):
        self.need_corpus()
        with self.assertRaises(TypeError):
            pickle.dumps(cg.CharacterLibrary.from_store(self.tmp / "s.clg"))

    # ---------------------------------------------------------------- trials: race, kill, gc
    def test_trials_from_threads_equal_the_plain_trial(self):
        want = trial_fn(5)
        with concurrent.futures.ThreadPoolExecutor(3) as pool:
            self.assertEqual(list(pool.map(trial_fn, [5, 5, 5])), [want] * 3)

    def test_trial_in_forked_child_equals_the_parent(self):
        want = trial_fn(6)
        with concurrent.futures.ProcessPoolExecutor(1, mp_context=multiprocessing.get_context("fork")) as pool:
            self.assertEqual(pool.submit(trial_fn, 6).result(timeout=60), want)

    def test_trial_in_spawned_child_equals_the_parent(self):
        got = child("""
            import calligraphy as cg
            r = cg.simulate_trial("一", max_duration_s=0.5, seed=6)
            print(repr((r.metrics["mean_deviation_m"], float(r.position_m.sum()))))
            """)
        self.assertEqual(got.returncode, 0, got.stderr)
        self.assertEqual(got.stdout.strip(), repr(trial_fn(6)))

    def test_trial_result_does_not_pickle_but_its_metrics_do(self):
        with self.assertRaises(TypeError):
            pickle.dumps(self.trial)
        self.assertEqual(pickle.loads(pickle.dumps(self.trial.metrics)), self.trial.metrics)

    def test_trial_result_outlives_its_scene(self):
        scene = cg.Scene("十")
        r = cg.simulate_trial(scene, max_duration_s=0.3, seed=2)
        del scene
        gc.collect()
        self.assertEqual(len(r.scene.strokes), 2)
        self.assertEqual(scored(columns_of(r), r.scene)["strokes_total"], 2)

    def test_trace_arrays_are_read_only(self):
        with self.assertRaises(ValueError):
            self.trial.position_m[0, 0] = 1.0

    def test_parameters_pickle_and_copy_equal(self):
        law = cg.ForceLawParameters(guidance_stiffness_n_per_m=321.0)
        for protocol in range(pickle.HIGHEST_PROTOCOL + 1):
            self.assertEqual(pickle.loads(pickle.dumps(law, protocol)).to_dict(), law.to_dict())

    def test_device_after_close_raises_communication_error(self):
        dev = cg.SimulatedDevice()
        dev.close()
        with self.assertRaises(cg.CommunicationError):
            dev.read_state()
        with self.assertRaises(cg.CommunicationError):
            dev.write_force([0.1, 0, 0])

    def test_sigint_during_real_time_trial_leaves_interpreter_and_fds_whole(self):
        got = child("""
            import os, signal, threading, time, calligraphy as cg
            before = sorted(os.listdir("/proc/self/fd"))
            threading.Timer(0.3, lambda: os.kill(os.getpid(), signal.SIGINT)).start()
            start = time.monotonic()
            try:
                cg.run_trial("永", device="simulated", pacing="real-time", max_duration_s=30)
                print("not interrupted")
            except KeyboardInterrupt:
                print("interrupted after %.1f s" % (time.monotonic() - start))
            r = cg.simulate_trial("一", max_duration_s=0.2, seed=1)
            print("still works", len(r.time_s))
            time.sleep(0.1)
            print("fds", sorted(os.listdir("/proc/self/fd")) == before)
            """, timeout=40)
        self.assertEqual(got.returncode, 0, got.stderr)
        lines = got.stdout.splitlines()
        self.assertTrue(lines[0].startswith("interrupted after"), got.stdout)
        self.assertLess(float(lines[0].split()[2]), 3.0)
        self.assertEqual(lines[1], "still works 200")
        self.assertEqual(lines[2], "fds True")

    def test_sigterm_handler_raising_during_real_time_trial_stops_it(self):
        got = child("""
            import os, signal, threading, time, calligraphy as cg
            class Stop(Exception):
                pass
            def on_term(signum, frame):
                raise Stop()
            signal.signal(signal.SIGTERM, on_term)
            threading.Timer(0.3, lambda: os.kill(os.getpid(), signal.SIGTERM)).start()
            start = time.monotonic()
            try:
                cg.run_trial("永", device="simulated", pacing="real-time", max_duration_s=30)
                print("ran to its end after %.1f s" % (time.monotonic() - start))
            except Stop:
                print("stopped after %.1f s" % (time.monotonic() - start))
            print("still works", len(cg.simulate_trial("一", max_duration_s=0.2, seed=1).time_s))
            """, timeout=40)
        self.assertEqual(got.returncode, 0, got.stderr)
        lines = got.stdout.splitlines()
        self.assertTrue(lines[0].startswith("stopped after"), got.stdout)
        self.assertLess(float(lines[0].split()[2]), 3.0)
        self.assertEqual(lines[1], "still works 200")

    def test_sigterm_default_during_record_teacher_leaves_no_half_file(self):
        d = self.case_dir()
        got = child(f"""
            import os, signal, threading, calligraphy as cg
            r = cg.simulate_trial("永", writer="skilled", seed=1)
            threading.Timer(0.05, lambda: os.kill(os.getpid(), signal.SIGTERM)).start()
            for i in range(100000):
                cg.record_teacher(r, {str(d / 't.json')!r})
            """, timeout=40)
        self.assertEqual(got.returncode, -signal.SIGTERM, got.stderr)
        # The process ends at once (no handler), so a temporary beside it may stay; the file itself is whole.
        names = [p.name for p in d.iterdir() if not p.name.startswith(".t.json.tmp-")]
        self.assertLessEqual(set(names), {"t.json"}, names)
        if names:
            self.assertEqual(cg.TeacherRecording.load(d / "t.json").characters, "永")

    # ---------------------------------------------------------------- study folders
    def copy_study(self):
        d = self.case_dir()
        shutil.copytree(self.tmp / "study", d / "study", symlinks=True)
        session = next((d / "study" / "S01").iterdir())
        return d / "study", session

    def test_study_path_forms_load_the_same(self):
        p = self.tmp / "study"
        for form in (p, PathLikeBox(p), [str(p)], (p,)):
            got = study_module.load(form).trials
            self.assertEqual(got.to_csv(), self.study.trials.to_csv(), repr(form))

    def test_study_bytes_path_is_a_type_error_naming_paths(self):
        # help(calligraphy.study.load): one path (str or path-like) or an iterable of them; bytes is refused.
        with self.assertRaises(TypeError) as e:
            study_module.load(bytes(self.tmp / "study"))
        self.assert_names(e, "paths")

    def test_study_given_twice_is_not_doubled(self):
        p = str(self.tmp / "study")
        try:
            got = study_module.load([p, p]).trials
        except (cg.DataError, ValueError) as e:
            self.assertIn("study", str(e))
        else:
            self.assertEqual(len(got), len(self.study.trials))

    def test_study_trace_swapped_with_another_trials_is_refused(self):
        root, session = self.copy_study()
        a, b = sorted(session.glob("trials/*.trace.h5"))
        a_bytes, b_bytes = a.read_bytes(), b.read_bytes()
        a.write_bytes(b_bytes)
        b.write_bytes(a_bytes)
        loaded = study_module.load(root)
        with self.assertRaises(cg.DataError) as e:
            loaded.samples(loaded.trials.iloc[0])
        self.assert_names(e, a.name)

    def test_study_truncated_trace_names_it(self):
        root, session = self.copy_study()
        trace = sorted(session.glob("trials/*.trace.h5"))[0]
        data = trace.read_bytes()
        trace.write_bytes(data[: len(data) // 2])
        loaded = study_module.load(root)
        with self.assertRaises(cg.DataError) as e:
            loaded.samples(loaded.trials.iloc[0])
        self.assert_names(e, trace.name)

    def test_study_truncated_session_json_names_it(self):
        root, session = self.copy_study()
        data = (session / "session.json").read_bytes()
        (session / "session.json").write_bytes(data[: len(data) // 2])
        with self.assertRaises(cg.DataError) as e:
            study_module.load(root)
        self.assert_names(e, "session.json")

    def test_study_record_duplicated_under_another_name_is_refused(self):
        root, session = self.copy_study()
        record = sorted(session.glob("trials/*.json"))[0]
        shutil.copy(record, record.with_name("003-test-V-r1-U4E00.json"))
        with self.assertRaises(cg.DataError) as e:
            study_module.load(root)
        self.assert_names(e, "003-test-V-r1-U4E00.json")

    def test_study_record_symlinked_is_refused_naming_it(self):
        root, session = self.copy_study()
        record = sorted(session.glob("trials/*.json"))[0]
        keep = self.case_dir() / record.name
        shutil.move(record, keep)
        record.symlink_to(keep)
        with self.assertRaises(cg.DataError) as e:
            study_module.load(root)
        self.assert_names(e, record.name, "symbolic link")

    def test_study_given_a_file_or_nothing_names_it(self):
        for bad in (self.tmp / "r.csv", self.tmp / "no-such-study"):
            with self.assertRaises((cg.DataError, ValueError, OSError)) as e:
                study_module.load(bad)
            self.assert_names(e, bad.name)

    def test_study_samples_of_none_and_unknown_label(self):
        with self.assertRaises(TypeError) as e:
            self.study.samples(None)
        self.assert_names(e, "trial")
        with self.assertRaises(KeyError):
            self.study.samples("no-such-trial")

    def test_study_loaded_from_threads_is_the_same(self):
        p = str(self.tmp / "study")
        with concurrent.futures.ThreadPoolExecutor(3) as pool:
            tables = list(pool.map(lambda _: study_module.load(p).trials.to_csv(), range(3)))
        self.assertEqual(tables, [self.study.trials.to_csv()] * 3)

    def test_study_pickles_and_reads_samples_after(self):
        again = pickle.loads(pickle.dumps(self.study))
        self.assertEqual(again.trials.to_csv(), self.study.trials.to_csv())
        a = again.samples(again.trials.iloc[1])
        b = self.study.samples(self.study.trials.iloc[1])
        self.assertTrue(a.equals(b))

    def test_study_iter_samples_leaves_no_open_file(self):
        before = open_fds()
        count = sum(1 for _ in self.study.iter_samples())
        self.assertEqual(count, len(self.study.trials))
        self.assertEqual(open_fds(), before)

    def test_study_samples_in_forked_child_equal(self):
        want = self.study.samples(self.study.trials.iloc[0])
        ctx = multiprocessing.get_context("fork")
        with concurrent.futures.ProcessPoolExecutor(1, mp_context=ctx) as pool:
            got = pool.submit(_samples_in_child, self.study).result(timeout=60)
        self.assertTrue(got.equals(want))

    # ---------------------------------------------------------------- figures, sweeps, cohorts: up-front checks
    def test_plot_refuses_a_path_and_a_non_axes(self):
        import matplotlib
        matplotlib.use("Agg")
        import calligraphy.plot
        with self.assertRaises(TypeError) as e:
            calligraphy.plot.trial(str(self.tmp / "r.json"))
        self.assert_names(e, "result")
        with self.assertRaises(TypeError) as e:
            calligraphy.plot.forces(self.trial, ax="axes")
        self.assert_names(e, "ax")

    def test_plot_of_a_trial_without_trace_is_a_value_error(self):
        import matplotlib
        matplotlib.use("Agg")
        import calligraphy.plot
        with self.assertRaises(ValueError):
            calligraphy.plot.trial(cg.simulate_trial("一", keep_trace=False, max_duration_s=0.2))

    def test_sweep_checks_before_any_trial(self):
        from calligraphy.experiments import sweep
        with self.assertRaises(ValueError) as e:
            sweep("一", {"guidance_stifness_n_per_m": [200]}, seeds=1, progress=False)
        self.assert_names(e, "guidance_stifness_n_per_m")
        with self.assertRaises(TypeError) as e:
            sweep("一", {"guidance": [True]}, seeds=1, client="tcp://nowhere:8786", progress=False)
        self.assert_names(e, "client")
        with self.assertRaises(ValueError) as e:
            sweep("一", {"guidance": [True]}, seeds=1, workers=0, progress=False)
        self.assert_names(e, "workers")

    def test_cohort_protocol_of_another_kind_names_it(self):
        import calligraphy.cohort
        with self.assertRaises(cg.DataError) as e:
            calligraphy.cohort.simulate(str(self.tmp / "r.csv"), 1, progress=False)
        self.assert_names(e, "r.csv")

    def test_cohort_dangling_protocol_link_names_it(self):
        import calligraphy.cohort
        d = self.case_dir()
        (d / "p.json").symlink_to(d / "gone.json")
        with self.assertRaises((cg.DataError, OSError)) as e:
            calligraphy.cohort.simulate(d / "p.json", 1, progress=False)
        self.assert_names(e, "p.json")

    def test_cohort_subjects_out_of_range_names_it(self):
        import calligraphy.cohort
        with self.assertRaises(ValueError) as e:
            calligraphy.cohort.simulate(str(self.tmp / "p.json"), 0, progress=False)
        self.assert_names(e, "subjects")


def _samples_in_child(study):
    return study.samples(study.trials.iloc[0])


if __name__ == "__main__":
    unittest.main()
