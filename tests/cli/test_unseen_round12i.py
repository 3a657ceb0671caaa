#!/usr/bin/env python3
"""Hostile cases written from the documentation alone (docs/python.md, docs/metrics.md, docs/experiments.md and
the module's docstrings), as an experimenter with numpy, pandas, matplotlib and Dask uses `calligraphy`. Run by
CTest as `cli_unseen_round12i_tests`.

- numpy arrays of the dtypes and layouts a lab's own code makes: big-endian, integer data units from a tablet,
  bool pens, structured and record arrays, complex, Fortran order, strided and transposed views, read-only,
  no row and one row, a million rows; given to `score`, `nearest_point`, `match_stroke`, `Placement`,
  `clamp_force` and `StrokeElement.point`: the same numbers as plain float64 arrays, or a refusal naming the
  argument, never a silent misreading, and the caller's arrays left as they were.
- pandas frames with their columns in another order, extra text and categorical columns, an index that is not
  0..n-1, a column named twice or under both of its names: scored as the CLI scores the same table as CSV.
- numpy scalars where ints and floats are taken, keywords misspelt, positional where keyword-only, None where a
  value is needed, attributes misspelt: the documented TypeError/ValueError/IndexError naming the argument.
- results pickled, copied and evaluated back; four threads at once against one after another; sweeps on a
  `concurrent.futures` executor and a Dask cluster with bad trials and a lost batch among good ones, and a grid
  of numpy values.
- one vocabulary: the same trial through `calligraphy trial`/`score` and through Python gives the same numbers,
  names, units and stroke numbering.
- the plot helpers' figures of a one-tick trial and into given axes (Agg backend, no display).

CALLIGRAPHY_CLI names the program; CALLIGRAPHY_SOURCE_DIR the source tree; the built Python package is found on
PYTHONPATH. CALLIGRAPHY_SANITIZED=1 takes a small subset.
"""
import concurrent.futures
import copy
import io
import json
import math
import os
import pickle
import re
import shutil
import subprocess
import sys
import tempfile
import threading
import unittest
import warnings
from pathlib import Path

from outsider import TIMEOUT_S, error_lines, run, sanitized_subset
from outsider_python import (SharedTrial, cg, needs_cli, needs_pandas, needs_python, np, pd,
                             remove_shared_trial)

SOURCE = Path(os.environ.get("CALLIGRAPHY_SOURCE_DIR", Path(__file__).resolve().parents[2]))
SHI = "十"
YI = "一"



Shared = SharedTrial  # one trial of 十 (seed 1), made once


def tearDownModule():
    remove_shared_trial()


def without(record, *keys):
    return {k: v for k, v in record.items() if k not in keys}


class Case(unittest.TestCase):
    def setUp(self):
        self.shared = Shared.get()
        self.tmp = Path(tempfile.mkdtemp(prefix="case-", dir=self.shared.folder))

    def assert_named(self, kind, text, call, *args, **kwargs):
        with self.assertRaises(kind) as caught:
            call(*args, **kwargs)
        self.assertIn(text, str(caught.exception))
        return caught.exception

    def assert_same_record(self, a, b, where="", exact=False):
        """Two metrics records alike: keys, counts, flags and texts exactly; numbers to the precision a trace
        file is written with (docs/metrics.md: times to 1 us, lengths to 0.1 um, within a millionth)."""
        if isinstance(a, dict):
            self.assertIsInstance(b, dict, where)
            self.assertEqual(sorted(a), sorted(b), where)
            for key in a:
                self.assert_same_record(a[key], b[key], f"{where}/{key}", exact)
        elif isinstance(a, list):
            self.assertIsInstance(b, list, where)
            self.assertEqual(len(a), len(b), where)
            for i, (x, y) in enumerate(zip(a, b)):
                self.assert_same_record(x, y, f"{where}/{i}", exact)
        elif isinstance(a, float) and not isinstance(b, bool) and isinstance(b, (int, float)) and not exact:
            tolerance = 2e-6 if where.endswith("_s") and not where.endswith("_m_s") else 2e-7
            self.assertTrue(math.isclose(a, b, rel_tol=1e-6, abs_tol=tolerance), (where, a, b))
        else:
            self.assertEqual(a, b, where)
            self.assertEqual(type(a), type(b), where)

    def cli_score(self, csv_path, *extra):
        """`calligraphy score CSV --character 十 --json -`: (exit status, record or None, error lines)."""
        r = run(["score", csv_path, "--character", SHI, "--json", "-", *extra], self.tmp)
        record = json.loads(r.stdout.decode("utf-8")) if r.returncode == 0 else None
        return r.returncode, record, error_lines(r)


def pen_columns(shared):
    """The trial's trace with a `pen` column instead of the height (down within 0.5 mm of the paper)."""
    c = shared.columns
    return {"t": c["t"], "x": c["x"], "y": c["y"], "pen": (c["z"] <= 0.0005).astype(np.int64)}


# ------------------------------------------------------------------------------------- score: numpy columns
@needs_python
class ScoreColumns(Case):
    """docs/python.md, "Scoring any pen trace": `trace` is a CSV path or a mapping of 1-D columns."""

    def test_big_endian_columns_score_as_native_ones(self):
        # '>f8' is what a file written on another machine or read with numpy.fromfile gives; a reader that
        # takes the bytes as native floats scores garbage.
        swapped = {k: v.astype(">f8") for k, v in self.shared.columns.items()}
        self.assertFalse(swapped["x"].dtype.isnative)
        self.assertEqual(cg.score(swapped, SHI), self.shared.reference)
        swapped_int = dict(pen_columns(self.shared))
        swapped_int["pen"] = swapped_int["pen"].astype(">i4")
        self.assertEqual(cg.score(swapped_int, SHI), cg.score(pen_columns(self.shared), SHI))

    def test_integer_data_units_from_a_tablet_score_as_floats(self):
        # A tablet gives whole numbers; `units="data"` takes x and y in the 1024 box. int64, uint16 and
        # big-endian int32 columns of those numbers score exactly as float64 columns of the same numbers.
        scene = cg.Scene(SHI)
        c = self.shared.columns
        data = scene.characters[0].placement.to_data(np.stack([c["x"], c["y"]], axis=1))
        whole = np.clip(np.rint(data), 0, 1023)
        as_float = {"t": c["t"], "x": whole[:, 0].astype(np.float64), "y": whole[:, 1].astype(np.float64),
                    "z": c["z"]}
        expected = cg.score(as_float, SHI, units="data")
        self.assertGreater(expected["strokes_written"], 0)
        for dtype in (np.int64, np.uint16, ">i4"):
            with self.subTest(dtype=str(dtype)):
                columns = dict(as_float, x=whole[:, 0].astype(dtype), y=whole[:, 1].astype(dtype))
                self.assertEqual(cg.score(columns, SHI, units="data"), expected)

    def test_bool_pen_column_is_the_0_1_column(self):
        columns = pen_columns(self.shared)
        expected = cg.score(columns, SHI)
        self.assertEqual(expected["strokes_written"], 2)
        self.assertEqual(cg.score(dict(columns, pen=columns["pen"].astype(bool)), SHI), expected)
        self.assertEqual(cg.score(dict(columns, pen=columns["pen"].astype(np.float32)), SHI), expected)

    def test_read_only_and_strided_columns_are_scored_and_left_unchanged(self):
        columns = {}
        for name, values in self.shared.columns.items():
            doubled = np.repeat(values, 2)[::2]          # a strided view of the same numbers
            doubled.flags.writeable = False
            columns[name] = doubled
        before = {k: v.copy() for k, v in columns.items()}
        self.assertEqual(cg.score(columns, SHI), self.shared.reference)
        for name in columns:
            np.testing.assert_array_equal(columns[name], before[name])

    def test_structured_arrays_are_refused_or_read_by_field(self):
        c = self.shared.columns
        n = len(c["t"])
        record = np.zeros(n, dtype=[("t", "f8"), ("x", "f8"), ("y", "f8"), ("z", "f8")])
        for name in "txyz":
            record[name] = c[name]
        # A structured array as one column holds no numbers: refused naming the column.
        with self.assertRaises((TypeError, ValueError)) as caught:
            cg.score(dict(c, x=record), SHI)
        self.assertIn("'x'", str(caught.exception))
        # The whole table as a record array (numpy's own table): read by its fields or refused naming `trace`.
        try:
            result = cg.score(record, SHI)
        except TypeError as error:
            self.assertIn("trace", str(error))
        else:
            self.assertEqual(result, self.shared.reference)
        # Its fields are strided views, and they score as the columns they are.
        self.assertEqual(cg.score({name: record[name] for name in "txyz"}, SHI), self.shared.reference)

    def outcome_of(self, call):
        try:
            return "scored", without(call(), "trace")
        except cg.Error as error:
            return "refused", str(error)

    def agree_with_the_cli(self, columns, csv_text):
        path = self.tmp / "t.csv"
        path.write_text(csv_text)
        status, record, lines = self.cli_score(path)
        self.assertIn(status, (0, 1), lines)
        from_file = self.outcome_of(lambda: cg.score(str(path), SHI))
        from_columns = self.outcome_of(lambda: cg.score(columns, SHI))
        if status == 0:
            self.assertEqual(from_file[0], "scored", from_file)
            self.assertEqual(from_columns[0], "scored", from_columns)
            self.assertEqual(from_file[1], without(record, "trace"))
            self.assert_same_record(without(from_columns[1], "samples"), without(record, "trace", "samples"))
        else:
            self.assertEqual(len(lines), 1, lines)
            self.assertEqual(from_file[0], "refused", from_file)
            self.assertEqual(from_columns[0], "refused", from_columns)
        return status, record

    def test_a_trace_of_no_sample_agrees_with_the_cli(self):
        empty = np.zeros(0)
        self.agree_with_the_cli({"t": empty, "x": empty, "y": empty, "pen": empty.astype(np.int64)},
                                "t,x,y,pen\n")

    def test_a_trace_of_one_sample_agrees_with_the_cli(self):
        status, record = self.agree_with_the_cli(
            {"t": np.array([0.0]), "x": np.array([0.0]), "y": np.array([0.0]), "pen": np.array([1])},
            "t,x,y,pen\n0,0,0,1\n")
        if status == 0:
            self.assertEqual(record["strokes_written"], 0)
            self.assertIsNone(record["mean_deviation_m"])

    def test_exactly_a_million_samples_are_taken(self):
        # docs/cli.md: 1,000,000 samples a trace; the limit itself is a trace (the pen lifted throughout).
        n = 1_000_000
        result = cg.score({"t": np.arange(n) * 1e-3, "x": np.zeros(n), "y": np.zeros(n), "z": np.ones(n)}, SHI)
        self.assertEqual(result["samples"], n)
        self.assertEqual(result["strokes_written"], 0)


# --------------------------------------------------------------------------------------- score: pandas frames
@needs_python
@needs_pandas
class ScoreFrames(Case):
    """`trace` a pandas DataFrame: each column by the file's name or by its name with its unit."""

    def frame(self):
        return self.shared.trial.to_dataframe()

    def test_columns_reordered_with_extra_text_and_categorical_columns(self):
        frame = self.frame()
        expected = cg.score(frame, SHI)
        self.assert_same_record(without(expected, "trace"), without(self.shared.reference, "trace"))
        shuffled = frame[list(frame.columns)[::-1]].copy()
        shuffled["note"] = "subject S01"
        shuffled["hand"] = pd.Categorical(["left", "right"] * (len(frame) // 2) + ["left"] * (len(frame) % 2))
        shuffled["when"] = pd.Timestamp("2026-11-27")
        self.assertEqual(cg.score(shuffled, SHI), expected)

    def test_an_index_other_than_0_to_n_is_not_read(self):
        frame = self.frame()
        expected = cg.score(frame, SHI)
        n = len(frame)
        for name, index in (("offset", pd.RangeIndex(10 ** 9, 10 ** 9 + n)),
                            ("reversed labels", pd.Index(np.arange(n)[::-1])),
                            ("dates", pd.date_range("2026-01-01", periods=n, freq="ms")),
                            ("text", pd.Index([f"tick{i}" for i in range(n)])),
                            ("a slice", None)):
            with self.subTest(index=name):
                other = frame.iloc[5:].copy() if index is None else frame.set_axis(index, axis=0)
                got = cg.score(other, SHI)
                if index is None:
                    self.assertEqual(got, cg.score(frame.iloc[5:].reset_index(drop=True), SHI))
                else:
                    self.assertEqual(got, expected)

    @needs_cli
    def test_a_column_named_twice_is_refused_as_the_cli_refuses_it(self):
        frame = self.frame()[["t_s", "x_m", "y_m", "z_m"]]
        shifted = frame["x_m"] + 0.005
        doubled = pd.concat([frame, shifted.rename("x_m")], axis=1)
        self.assertEqual(list(doubled.columns).count("x_m"), 2)
        path = self.tmp / "doubled.csv"
        doubled.to_csv(path, index=False, float_format="%.17g")
        status, _, lines = self.cli_score(path)
        self.assertEqual(status, 1, lines)
        self.assertIn("x_m", lines[0])
        with self.assertRaises(ValueError) as caught:
            cg.score(doubled, SHI)
        self.assertIn("x_m", str(caught.exception))

    @needs_cli
    def test_a_column_under_both_its_names_agrees_with_the_cli(self):
        frame = self.frame()[["t_s", "x_m", "y_m", "z_m"]].copy()
        frame["x"] = frame["x_m"] + 0.005           # x named twice: once in the file's name, once with its unit
        path = self.tmp / "both.csv"
        frame.to_csv(path, index=False, float_format="%.17g")
        status, record, lines = self.cli_score(path)
        try:
            got = cg.score(frame, SHI)
        except ValueError as error:
            self.assertEqual(status, 1, "Python refused what the CLI scored: %s" % error)
            self.assertIn("x", str(error))
            self.assertIn("x", lines[0])
        else:
            self.assertEqual(status, 0, "the CLI refused what Python scored: %s" % lines)
            self.assert_same_record(without(got, "trace", "samples"), without(record, "trace", "samples"))

    def test_times_as_timedeltas_or_dates_are_refused_naming_the_column(self):
        # pandas' own time types (pd.to_timedelta(t, unit="s"), a time stamp per sample) cast to float64 as
        # nanoseconds: read so, the trace would last a billion times longer. Refused naming the column, as
        # `score` refuses any column that is no real numbers; in seconds as floats, the same trace.
        frame = self.frame()
        since_start = pd.to_timedelta(frame["t_s"], unit="s")
        for name, times in (("timedelta", since_start), ("datetime", pd.Timestamp("2026-11-27") + since_start)):
            with self.subTest(times=name):
                with self.assertRaises(ValueError) as caught:
                    cg.score(frame.assign(t_s=times), SHI)
                self.assertIn("'t_s'", str(caught.exception))
        seconds = frame.assign(t_s=since_start.dt.total_seconds())
        self.assert_same_record(without(cg.score(seconds, SHI), "trace"), without(cg.score(frame, SHI), "trace"))
        self.assert_named(cg.InvalidArgument, "distance_m", cg.constraint_taper,
                          np.array([1, 2], dtype="m8[ms]"), 0.002, 0.001)

    def test_categorical_and_text_pen_columns(self):
        columns = pen_columns(self.shared)
        expected = cg.score(columns, SHI)
        frame = pd.DataFrame(columns)
        frame["pen"] = pd.Categorical(frame["pen"])          # categories 0 and 1: the numbers themselves
        self.assertEqual(cg.score(frame, SHI), expected)
        frame["pen"] = frame["pen"].astype(str)               # "0"/"1" as text: not numbers
        with self.assertRaises((TypeError, ValueError)) as caught:
            cg.score(frame, SHI)
        self.assertIn("pen", str(caught.exception))
        frame["pen"] = pd.array(columns["pen"], dtype="Int64")  # pandas' nullable integers, no NA
        self.assertEqual(cg.score(frame, SHI), expected)
        frame.loc[3, "pen"] = pd.NA                            # a missing pen value is no pen value
        with self.assertRaises((TypeError, ValueError)) as caught:
            cg.score(frame, SHI)
        self.assertIn("pen", str(caught.exception))


# ---------------------------------------------------------------------------------------- geometry arrays
@needs_python
class GeometryArrays(Case):
    """docs/python.md, "Characters", "Nearest point and force law", "Stroke matching"."""

    @classmethod
    def setUpClass(cls):
        cls.character = cg.CharacterLibrary.default().load(SHI)
        cls.element = cls.character.strokes[0].elements[0]
        cls.scene = cg.Scene(SHI)
        cls.path = np.array(cls.scene.characters[0].strokes[1].median_m, dtype=np.float64)

    def layouts(self, points):
        """The same (N, 2) float64 numbers in the layouts numpy code makes."""
        big = np.zeros((len(points) * 2, 3))
        big[::2, :2] = points
        transposed = np.ascontiguousarray(points.T).T
        read_only = points.copy()
        read_only.flags.writeable = False
        return {"Fortran order": np.asfortranarray(points), "strided rows and columns": big[::2, :2],
                "a transposed (2, N)": transposed, "big-endian": points.astype(">f8"), "read-only": read_only,
                "a list of lists": points.tolist()}

    def test_nearest_point_of_odd_point_arrays(self):
        rng = np.random.default_rng(7)
        points = rng.integers(0, 1024, size=(50, 2)).astype(np.float64)  # whole numbers: exact in float32
        t0, foot0, d0 = cg.nearest_point(self.element, points)
        self.assertEqual((t0.shape, foot0.shape, d0.shape), ((50,), (50, 2), (50,)))
        variants = self.layouts(points)
        variants["float32"] = points.astype(np.float32)
        variants["int64"] = points.astype(np.int64)
        for name, value in variants.items():
            with self.subTest(layout=name):
                t, foot, d = cg.nearest_point(self.element, value)
                np.testing.assert_array_equal(t, t0)
                np.testing.assert_array_equal(foot, foot0)
                np.testing.assert_array_equal(d, d0)
        t, foot, d = cg.nearest_point(self.element, points[:0])
        self.assertEqual((t.shape, foot.shape, d.shape), ((0,), (0, 2), (0,)))
        t, foot, d = cg.nearest_point(self.element, points[:1])
        self.assertEqual((t.shape, foot.shape, d.shape), ((1,), (1, 2), (1,)))
        self.assertEqual(d[0], d0[0])
        t, foot, d = cg.nearest_point(self.element, points[0])  # (2,): one point, scalars back
        self.assertEqual(float(d), d0[0])
        for name, bad in (("(2, N)", points[:5].T.copy()), ("(N, 3)", np.zeros((5, 3))),
                          ("complex", points.astype(complex)), ("text", points.astype(str)),
                          ("objects holding text", points.astype(object).astype(str).astype(object))):
            with self.subTest(bad=name):
                with self.assertRaises((ValueError, TypeError)):
                    cg.nearest_point(self.element, bad)

    def test_match_stroke_paths_of_every_layout(self):
        reference = cg.match_stroke(self.scene, 0, 1, self.path)
        self.assertTrue(reference.accepted)

        def verdict(m):
            return (m.accepted, m.refusal, m.matched_stroke, m.covered_fraction, m.mean_deviation_m)
        for name, value in self.layouts(self.path).items():
            with self.subTest(layout=name):
                self.assertEqual(verdict(cg.match_stroke(self.scene, 0, 1, value)), verdict(reference))
        self.assertEqual(cg.match_stroke(self.scene, 0, 1, self.path[::-1].copy()).refusal,
                         cg.StrokeRefusal.backwards)
        self.assertEqual(verdict(cg.match_stroke(self.scene, 0, 1, self.path[::-1][::-1])), verdict(reference))

    def test_match_stroke_paths_of_wrong_shapes_and_types(self):
        for name, bad in (("(2, N)", self.path.T.copy()), ("(N, 3)", np.zeros((len(self.path), 3))),
                          ("(0, 2)", self.path[:0]), ("1-D", self.path[:, 0].copy()),
                          ("complex", self.path.astype(complex)), ("text", self.path.astype(str)),
                          ("NaN", np.where(self.path > 0, np.nan, 0.0))):
            with self.subTest(path=name):
                self.assert_named(cg.InvalidArgument, "path_m", cg.match_stroke, self.scene, 0, 1, bad)
        self.assert_named(IndexError, "stroke_index", cg.match_stroke, self.scene, 0, 2, self.path)
        self.assert_named(IndexError, "character_index", cg.match_stroke, self.scene, 1, 0, self.path)

    def test_placement_keeps_shapes_of_every_layout(self):
        placement = self.scene.characters[0].placement
        data = np.array([[0.0, 0.0], [512.0, 300.0], [1023.0, 1023.0], [100.0, 900.0]])
        paper = placement.to_paper(data)
        self.assertEqual(paper.shape, (4, 2))
        np.testing.assert_allclose(placement.to_data(paper), data, atol=1e-9)
        variants = self.layouts(data)
        variants["int64"] = data.astype(np.int64)
        for name, value in variants.items():
            with self.subTest(layout=name):
                np.testing.assert_array_equal(placement.to_paper(value), paper)
        self.assertEqual(placement.to_paper(data[0]).shape, (2,))
        np.testing.assert_array_equal(placement.to_paper(data[0]), paper[0])
        self.assertEqual(placement.to_paper(data[:0]).shape, (0, 2))
        self.assertEqual(placement.to_data(paper[:0]).shape, (0, 2))

    def test_clamp_force_rows_and_its_input(self):
        # docs/python.md: (3,) or (N, 3), direction kept, non-finite -> 0.
        forces = np.array([[3.0, 4.0, 0.0], [30.0, 40.0, 0.0], [np.nan, 1.0, 0.0], [np.inf, 0.0, 0.0],
                           [0.0, 0.0, -100.0], [-np.inf, np.inf, 1.0]])
        given = np.asfortranarray(forces)
        given.flags.writeable = False
        clamped = cg.clamp_force(given, 7.9)
        np.testing.assert_array_equal(given, forces)       # the input is the caller's, untouched
        self.assertEqual(clamped.shape, (6, 3))
        np.testing.assert_allclose(clamped[0], [3.0, 4.0, 0.0])
        np.testing.assert_allclose(clamped[1], [4.74, 6.32, 0.0])
        np.testing.assert_array_equal(clamped[2], [0.0, 0.0, 0.0])
        np.testing.assert_array_equal(clamped[3], [0.0, 0.0, 0.0])
        np.testing.assert_allclose(clamped[4], [0.0, 0.0, -7.9])
        np.testing.assert_array_equal(clamped[5], [0.0, 0.0, 0.0])
        self.assertTrue(np.isfinite(clamped).all())
        np.testing.assert_allclose(cg.clamp_force(forces[1], 7.9), clamped[1])
        np.testing.assert_array_equal(cg.clamp_force(forces.astype(np.float32)[:2], 7.9), clamped[:2])
        self.assertEqual(cg.clamp_force(forces[:0], 7.9).shape, (0, 3))

    def test_element_points_of_odd_parameter_arrays_and_read_only_control_points(self):
        e = self.element
        s = np.array([0.0, 0.25, 0.5, 1.0])
        expected = e.point(s)
        self.assertEqual(expected.shape, (4, 2))
        read_only = s.copy()
        read_only.flags.writeable = False
        for name, value in (("float32", s.astype(np.float32)), ("big-endian", s.astype(">f8")),
                            ("strided", np.repeat(s, 3)[::3]), ("read-only", read_only), ("list", s.tolist())):
            with self.subTest(parameters=name):
                np.testing.assert_array_equal(e.point(value), expected)
        np.testing.assert_array_equal(e.point(np.array([0, 1])), e.point(np.array([0.0, 1.0])))
        self.assertEqual(e.point(s[:0]).shape, (0, 2))
        # "control_points (degree+1, 2) float64, read-only": a write is refused and the character keeps them.
        points = e.control_points
        before = points.copy()
        with self.assertRaises(ValueError):
            points[0, 0] = 1e6
        np.testing.assert_array_equal(e.control_points, before)
        again = cg.CharacterLibrary.default().load(SHI).strokes[0].elements[0].control_points
        np.testing.assert_array_equal(again, before)

    def test_interaction_state_on_the_uint8_trace(self):
        # "InteractionState ... equal to its int value, so result.state == cg.InteractionState.writing works on
        # a trace's uint8 array"; the frame's categorical says WS for the same ticks.
        r = self.shared.trial
        self.assertEqual(r.state.dtype, np.uint8)
        writing = r.state == cg.InteractionState.writing
        self.assertEqual(writing.dtype, np.bool_)
        self.assertEqual(writing.shape, r.state.shape)
        np.testing.assert_array_equal(writing, r.state == int(cg.InteractionState.writing))
        self.assertGreater(int(writing.sum()), 0)
        self.assertEqual(cg.InteractionState.writing.short_name, "WS")
        if pd is not None:
            states = r.to_dataframe()["state"]
            np.testing.assert_array_equal((states == "WS").to_numpy(), writing)


# ---------------------------------------------------------------------------------------------- arguments
@needs_python
class Arguments(Case):
    """docs/python.md, "Errors": TypeError naming an argument of the wrong type, InvalidArgument (a ValueError)
    naming a value out of range, IndexError naming an index; integer arguments take any int."""

    def test_numpy_scalars_are_taken_as_the_ints_and_floats_they_are(self):
        plain = cg.simulate_trial(SHI, seed=3, rate_hz=1000, keep_trace=False).metrics
        self.assertEqual(cg.simulate_trial(SHI, seed=np.int64(3), rate_hz=np.float32(1000.0),
                                           keep_trace=False).metrics, plain)
        self.assertEqual(cg.simulate_trial(SHI, seed=np.uint8(3), rate_hz=np.int64(1000),
                                           keep_trace=False).metrics, plain)
        scene = cg.Scene(SHI)
        path = scene.characters[0].strokes[1].median_m
        self.assertTrue(cg.match_stroke(scene, np.int64(0), np.uint16(1), path).accepted)
        self.assertEqual(cg.typical_stroke(np.int64(10)).acronym, cg.typical_stroke(10).acronym)
        self.assert_named(cg.InvalidArgument, "key", cg.typical_stroke, np.int64(40))
        self.assert_named(cg.InvalidArgument, "seed", cg.simulate_trial, SHI, seed=np.int64(-1))
        self.assert_named(IndexError, "stroke_index", cg.match_stroke, scene, 0, np.uint64(2 ** 64 - 1), path)
        self.assert_named(TypeError, "seed", cg.simulate_trial, SHI, seed=np.float64(3.5))
        law = cg.ForceLawParameters(friction_coefficient=np.float64(0.2), guidance_stiffness_n_per_m=np.int64(300))
        self.assertEqual(law.friction_coefficient, 0.2)
        self.assertEqual(law.guidance_stiffness_n_per_m, 300.0)
        law.friction_coefficient = np.float32(0.25)
        self.assertEqual(law.friction_coefficient, float(np.float32(0.25)))
        self.assertEqual(cg.SceneLayout(character_size_m=np.float32(0.0625)).character_size_m, 0.0625)

    def test_misspelt_keywords_are_named(self):
        import calligraphy.experiments as experiments
        import calligraphy.cohort as cohort
        frame = Shared.get().columns
        protocol = SOURCE / "examples" / "protocols" / "cohort-schedules.json"
        for name, call in (("sead", lambda: cg.simulate_trial(SHI, sead=1)),
                           ("unit", lambda: cg.score(frame, SHI, unit="data")),
                           ("stiffness", lambda: cg.ForceLawParameters(stiffness=1.0)),
                           ("character_size", lambda: cg.SceneLayout(character_size=0.06)),
                           ("methd", lambda: cg.nearest_point(np.zeros((2, 2)), [0.0, 0.0], methd="newton")),
                           ("worker", lambda: experiments.sweep(SHI, {}, 1, worker=1, progress=False)),
                           ("profil", lambda: cohort.simulate(str(protocol), 1, profil="novice"))):
            with self.subTest(keyword=name):
                self.assert_named(TypeError, name, call)

    def test_positional_where_keyword_only(self):
        import calligraphy.experiments as experiments
        import calligraphy.cohort as cohort
        protocol = SOURCE / "examples" / "protocols" / "cohort-schedules.json"
        for name, call in (
                ("sweep's workers", lambda: experiments.sweep(SHI, {}, 1, None, None, None, None, False, 1)),
                ("simulate's profile", lambda: cohort.simulate(str(protocol), 1, "novice")),
                ("a parameter class", lambda: cg.ForceLawParameters(400.0)),
                ("a layout", lambda: cg.SceneLayout(0.06))):
            with self.subTest(call=name):
                with self.assertRaises(TypeError):
                    call()

    def test_misspelt_attributes_are_refused_not_kept(self):
        # "checks values on construction and on every assignment": a name that is no field is no setting.
        law = cg.ForceLawParameters()
        before = law.to_dict()
        with self.assertRaises(AttributeError) as caught:
            law.guidance_stifness_n_per_m = 100.0
        self.assertIn("guidance_stifness_n_per_m", str(caught.exception))
        self.assertEqual(law.to_dict(), before)
        layout = cg.SceneLayout()
        with self.assertRaises(AttributeError):
            layout.character_size = 0.1
        with self.assertRaises(AttributeError):
            law.nearest.methd = "newton"

    def test_none_where_a_value_is_needed(self):
        scene = cg.Scene(SHI)
        path = scene.characters[0].strokes[1].median_m
        law = cg.ForceLawParameters()
        element = cg.CharacterLibrary.default().load(SHI).strokes[0].elements[0]
        for name, call in (("characters", lambda: cg.simulate_trial(None)),
                           ("seed", lambda: cg.simulate_trial(SHI, seed=None)),
                           ("rate_hz", lambda: cg.simulate_trial(SHI, rate_hz=None)),
                           ("character_index", lambda: cg.match_stroke(scene, None, 1, path)),
                           ("path_m", lambda: cg.match_stroke(scene, 0, 1, None)),
                           ("friction_coefficient", lambda: setattr(law, "friction_coefficient", None)),
                           ("character_size_m", lambda: cg.SceneLayout(character_size_m=None)),
                           ("key", lambda: cg.typical_stroke(None))):
            with self.subTest(argument=name):
                self.assert_named(TypeError, name, call)
        with self.assertRaises(TypeError):
            cg.nearest_point(element, None)
        with self.assertRaises(TypeError):
            cg.clamp_force(None, 7.9)
        self.assertEqual(law.friction_coefficient, cg.ForceLawParameters().friction_coefficient)

    def test_a_missing_character_speaks_python_in_every_function(self):
        # "a character in no default set points to CharacterLibrary.from_hanzi_writer(folder) or
        # CharacterLibrary.from_store(path) (the CLI says --data DIR or --store FILE)".
        columns = Shared.get().columns
        for name, call in (("simulate_trial", lambda: cg.simulate_trial("é")),
                           ("score", lambda: cg.score(columns, "é")),
                           ("Scene", lambda: cg.Scene("é"))):
            with self.subTest(function=name):
                with self.assertRaises(cg.CharacterNotFound) as caught:
                    call()
                error = caught.exception
                self.assertIsInstance(error, KeyError)
                self.assertIsInstance(error, cg.DataError)
                self.assertIsInstance(error, RuntimeError)
                self.assertIn("é", str(error))
                self.assertIn("from_hanzi_writer", str(error))
                self.assertNotIn("--data", str(error))


# ------------------------------------------------------------------------------------------------- objects
@needs_python
class Objects(Case):
    def test_parameters_pickled_copied_and_evaluated_back(self):
        law = cg.ForceLawParameters(guidance_law=cg.AssistAsNeededGuidance(band_m=0.002), friction_coefficient=0.2)
        law.nearest.method = "newton"
        namespace = dict(vars(cg), calligraphy=cg, cg=cg)
        for name, again in (("pickle", pickle.loads(pickle.dumps(law, protocol=pickle.HIGHEST_PROTOCOL))),
                            ("copy", copy.copy(law)), ("deepcopy", copy.deepcopy(law)),
                            ("repr", eval(repr(law), namespace))):  # noqa: S307 - the documented round trip
            with self.subTest(how=name):
                self.assertEqual(again, law)
                self.assertEqual(again.to_dict(), law.to_dict())
                self.assertEqual(again.guidance_mode, law.guidance_mode)
                self.assertEqual(again.nearest.method, law.nearest.method)
                self.assertEqual(again.guidance_law.band_m, 0.002)
                again.nearest.method = "subdivision"            # the copy's nested fields are its own
                again.friction_coefficient = 0.3
                self.assertNotEqual(again, law)
                self.assertEqual(law.nearest.method, cg.NearestPointMethod.newton)
                self.assertEqual(law.friction_coefficient, 0.2)
        # A trial run with the copy is the trial run with the original.
        self.assertEqual(cg.simulate_trial(SHI, force_law=copy.deepcopy(law), keep_trace=False).metrics,
                         cg.simulate_trial(SHI, force_law=law, keep_trace=False).metrics)

    def test_metrics_copied_deep_and_pickled_keep_their_type_and_old_names(self):
        metrics = Shared.get().trial.metrics
        from calligraphy.metrics import Metrics
        for name, again in (("copy", copy.copy(metrics)), ("deepcopy", copy.deepcopy(metrics)),
                            ("pickle", pickle.loads(pickle.dumps(metrics)))):
            with self.subTest(how=name):
                self.assertIsInstance(again, Metrics)
                self.assertEqual(again, metrics)
                stroke = again["per_character"][0]["per_stroke"][0]
                with warnings.catch_warnings(record=True) as caught:
                    warnings.simplefilter("always")
                    old = again["mean_deviation_mm"]
                    old_stroke = stroke["frechet_mm"]
                self.assertEqual(old, metrics["mean_deviation_m"] * 1e3)
                self.assertEqual(old_stroke, stroke["frechet_m"] * 1e3)
                self.assertEqual(sum(issubclass(w.category, DeprecationWarning) for w in caught), 2)
        text = json.dumps(metrics)
        self.assertNotIn("_mm", text)
        self.assertEqual(json.loads(text), metrics)

    def test_a_trial_result_pickles_whole_or_refuses_to(self):
        r = Shared.get().trial
        for name, how in (("pickle", lambda: pickle.loads(pickle.dumps(r))), ("copy", lambda: copy.copy(r)),
                          ("deepcopy", lambda: copy.deepcopy(r))):
            with self.subTest(how=name):
                try:
                    again = how()
                except (TypeError, pickle.PicklingError) as error:
                    self.assertIn("TrialResult", str(error))
                    continue
                np.testing.assert_array_equal(again.position_m, r.position_m)
                np.testing.assert_array_equal(again.time_s, r.time_s)
                np.testing.assert_array_equal(again.state, r.state)
                self.assertEqual(again.metrics, r.metrics)

    @needs_pandas
    def test_tables_copied_filtered_and_pickled_keep_their_old_names(self):
        # docs/python.md: the old millimetre names "still read for this version ... from the DataFrames of
        # per_stroke_dataframe() and experiments.sweep".
        frame = Shared.get().trial.per_stroke_dataframe()
        for name, again in (("copy", frame.copy()), ("filtered", frame[frame["written"]]),
                            ("columns taken", frame[["character", "mean_deviation_m"]]),
                            ("pickled", pickle.loads(pickle.dumps(frame)))):
            with self.subTest(how=name):
                with warnings.catch_warnings(record=True) as caught:
                    warnings.simplefilter("always")
                    old = again["mean_deviation_mm"]
                self.assertTrue(any(issubclass(w.category, DeprecationWarning) for w in caught))
                self.assertEqual(list(old), [v * 1e3 for v in again["mean_deviation_m"]])
        # Saved with to_pickle and read in a later session, which has not made the frame class yet.
        path = self.tmp / "strokes.pkl"
        frame.to_pickle(path)
        code = ("import warnings, pandas\n"
                "frame = pandas.read_pickle(%r)\n"
                "with warnings.catch_warnings(record=True) as caught:\n"
                "    warnings.simplefilter('always')\n"
                "    old = list(frame['mean_deviation_mm'])\n"
                "assert [w.category for w in caught] == [DeprecationWarning], caught\n"
                "assert old == [v * 1e3 for v in frame['mean_deviation_m']]\n" % str(path))
        later = subprocess.run([sys.executable, "-c", code], stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                               timeout=TIMEOUT_S)
        self.assertEqual(later.returncode, 0, later.stderr.decode("utf-8", "replace"))


# --------------------------------------------------------------------------------------- threads and sweeps
class FlakyExecutor(concurrent.futures.ThreadPoolExecutor):
    """An executor whose second task is lost as a whole, as a killed worker's is."""

    def __init__(self):
        super().__init__(max_workers=2)
        self.submitted = 0
        self.lock = threading.Lock()

    def submit(self, fn, *args, **kwargs):
        with self.lock:
            self.submitted += 1
            lost = self.submitted == 2
        if lost:
            future = concurrent.futures.Future()
            future.set_exception(RuntimeError("worker 2 was killed"))
            return future
        return super().submit(fn, *args, **kwargs)


@needs_python
class Concurrency(Case):
    def work(self, i):
        scene = cg.Scene(SHI)
        element = cg.CharacterLibrary.default().load(SHI).strokes[0].elements[0]
        r = cg.simulate_trial(SHI, seed=i)
        p = r.position_m
        score = cg.score({"t": r.time_s, "x": p[:, 0], "y": p[:, 1], "z": p[:, 2]}, SHI)
        points = np.random.default_rng(i).random((20000, 2)) * 1024
        _, _, distances = cg.nearest_point(element, points)
        m = cg.match_stroke(scene, 0, 1, cg.person_trace(scene, 0, 1, cg.TraceKind.human, seed=i))
        return r.metrics, p.copy(), score, distances, (m.accepted, m.refusal, m.mean_deviation_m)

    def test_four_threads_at_once_give_the_results_of_one_after_another(self):
        one_by_one = [self.work(i) for i in range(4)]
        barrier = threading.Barrier(4)

        def together(i):
            barrier.wait()
            return self.work(i)
        with concurrent.futures.ThreadPoolExecutor(max_workers=4) as pool:
            at_once = list(pool.map(together, range(4)))
        for i, (a, b) in enumerate(zip(one_by_one, at_once)):
            with self.subTest(thread=i):
                self.assertEqual(a[0], b[0])
                np.testing.assert_array_equal(a[1], b[1])
                self.assertEqual(a[2], b[2])
                np.testing.assert_array_equal(a[3], b[3])
                self.assertEqual(a[4], b[4])

    @needs_pandas
    def test_sweep_on_an_executor_with_bad_trials_among_good_ones(self):
        from calligraphy.experiments import sweep
        with concurrent.futures.ThreadPoolExecutor(max_workers=2) as pool:
            table = sweep([SHI, "é"], {"rate_hz": [1000, 50]}, [0], client=pool, batch_size=1, progress=False)
        self.assertEqual(list(table["character"]), [SHI, "é", SHI, "é"])
        self.assertEqual(list(table["rate_hz"]), [1000, 1000, 50, 50])
        self.assertIsNone(table["error"][0])
        self.assertTrue(table["error"][1].startswith("CharacterNotFound: "), table["error"][1])
        self.assertIn("é", table["error"][1])
        self.assertNotIn("--data", table["error"][1])
        self.assertIn("rate_hz", table["error"][2])
        self.assertIn("InvalidArgument", table["error"][3] + table["error"][2])
        # The good row is the trial's metrics, in the metric table's units (metres, seconds).
        good = cg.simulate_trial(SHI, seed=0, rate_hz=1000, keep_trace=False).metrics
        for key in ("mean_deviation_m", "max_deviation_m", "frechet_m", "total_time_s", "strokes_accepted",
                    "order_errors", "completed_in_order", "end_reason"):
            with self.subTest(metric=key):
                self.assertEqual(table[key][0], good[key])
                self.assertTrue(pd.isna(table[key][1]))
        self.assertEqual(str(table["order_errors"].dtype), "Int64")
        self.assertEqual(str(table["completed_in_order"].dtype), "boolean")

    @needs_pandas
    def test_sweep_with_a_batch_lost_as_a_whole(self):
        from calligraphy.experiments import sweep
        executor = FlakyExecutor()
        try:
            table = sweep([SHI, YI], {}, 2, client=executor, batch_size=1, progress=False)
        finally:
            executor.shutdown()
        self.assertEqual(len(table), 4)
        errors = [e for e in table["error"] if e is not None and not pd.isna(e)]
        self.assertEqual(len(errors), 1, list(table["error"]))
        self.assertTrue(errors[0].startswith("batch failed: "), errors[0])
        self.assertIn("worker 2 was killed", errors[0])
        lost = table[table["error"].notna()].index[0]
        self.assertTrue(pd.isna(table["mean_deviation_m"][lost]))
        for i in table.index.drop(lost):
            expected = cg.simulate_trial(table["character"][i], seed=int(table["seed"][i]), keep_trace=False).metrics
            self.assertEqual(table["mean_deviation_m"][i], expected["mean_deviation_m"])

    @needs_pandas
    def test_sweep_on_a_dask_cluster_equals_the_executor_bad_rows_included(self):
        try:
            import distributed
        except ImportError:
            self.skipTest("distributed (Dask) is not installed")
        import logging
        from calligraphy.experiments import sweep
        grid = {"guidance": [True, False]}
        with concurrent.futures.ThreadPoolExecutor(max_workers=2) as pool:
            expected = sweep([SHI, "é"], grid, 1, client=pool, progress=False)
        with distributed.LocalCluster(n_workers=1, threads_per_worker=2, processes=False, dashboard_address=None,
                                      silence_logs=logging.ERROR, local_directory=str(self.tmp)) as cluster, \
                distributed.Client(cluster) as client:
            table = sweep([SHI, "é"], grid, 1, client=client, progress=False)
        pd.testing.assert_frame_equal(table, expected)
        self.assertEqual(table["error"].notna().sum(), 2)

    @needs_pandas
    def test_sweep_grid_and_seeds_of_numpy_values(self):
        # An experimenter's grid comes from numpy: np.linspace, np.array([True, False]), np.arange.
        from calligraphy.experiments import sweep
        plain_grid = {"guidance": [True, False], "guidance_stiffness_n_per_m": [200.0, 400.0], "rate_hz": [1000]}
        numpy_grid = {"guidance": np.array([True, False]), "guidance_stiffness_n_per_m": np.linspace(200, 400, 2),
                      "rate_hz": np.array([1000])}
        with concurrent.futures.ThreadPoolExecutor(max_workers=2) as pool:
            plain = sweep(SHI, plain_grid, [0, 1], client=pool, progress=False)
            from_numpy = sweep(SHI, numpy_grid, np.arange(2), client=pool, progress=False)
            counted = sweep(SHI, {}, np.int64(2), client=pool, progress=False)
        self.assertTrue(plain["error"].isna().all())
        self.assertTrue(from_numpy["error"].isna().all(), list(from_numpy["error"]))
        pd.testing.assert_frame_equal(from_numpy, plain, check_dtype=False)
        self.assertEqual(list(counted["seed"]), [0, 1])


# -------------------------------------------------------------------------------------------- one vocabulary
@needs_python
@needs_cli
class OneVocabulary(Case):
    """docs/metrics.md, "The one metrics record": one trace gives the same numbers everywhere; docs/python.md:
    `r.metrics` has exactly the keys of `calligraphy trial --json`."""

    @classmethod
    def setUpClass(cls):
        cls.folder = Path(tempfile.mkdtemp(prefix="unseen12i-cli-"))
        r = run(["trial", SHI, "--seed", "3", "--json", "t.json", "--csv", "t.csv"], cls.folder)
        assert r.returncode == 0, r.stderr
        cls.trial_stdout = r.stdout.decode("utf-8")
        cls.cli_trial = json.loads((cls.folder / "t.json").read_text(encoding="utf-8"))
        cls.python_trial = cg.simulate_trial(SHI, seed=3)

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.folder, ignore_errors=True)

    def test_trial_json_is_simulate_trials_metrics(self):
        metrics = self.python_trial.metrics
        self.assertEqual(sorted(metrics), sorted(self.cli_trial))
        self.assert_same_record(json.loads(json.dumps(metrics)), self.cli_trial, exact=True)

    def test_score_through_the_cli_and_python_with_one_stroke_numbering(self):
        csv = self.folder / "t.csv"
        r = run(["score", csv, "--character", SHI, "--json", "s.json"], self.folder)
        self.assertEqual(r.returncode, 0, r.stderr)
        cli = json.loads((self.folder / "s.json").read_text(encoding="utf-8"))
        self.assertEqual(cg.score(str(csv), SHI), cli)                      # the same file: the same dict
        frame = self.python_trial.to_dataframe()
        from_frame = cg.score(frame, SHI)
        self.assert_same_record(without(from_frame, "trace"), without(cli, "trace"))
        # The record's metrics are the trial's (docs/python.md: the values `calligraphy score` gives).
        for key in ("mean_deviation_m", "frechet_m", "dtw_m", "total_time_s", "pen_down_time_s", "order_errors",
                    "strokes_accepted", "strokes_written", "velocity_peaks"):
            with self.subTest(key=key):
                self.assert_same_record(cli[key], self.cli_trial[key], key)
        # Stroke numbers count from 0 in every record and table of Python and the JSON.
        strokes = self.python_trial.per_stroke_dataframe()
        self.assertEqual(list(strokes.index), [0, 1])
        self.assertEqual([s["index"] for s in self.cli_trial["renderer_strokes"]], [0, 1])
        segments = [s for s in cli["per_character"][0]["segments"] if s["verdict"]]
        self.assertEqual([s["matched_stroke"] for s in segments], [0, 1])
        for segment in segments:
            middle = (segment["begin"] + segment["end"]) // 2
            self.assertEqual(int(frame["stroke"].iloc[middle]), segment["matched_stroke"])
            self.assertEqual(int(self.python_trial.stroke[middle]), segment["matched_stroke"])
        # The tables for people number strokes from 1 (docs/cli.md): 1 and 2, never 0 or 3.
        for text in (self.trial_stdout, r.stdout.decode("utf-8")):
            numbers = [int(m.group(1)) for m in re.finditer(r"^\s*(\d+)\s+\S", text, re.MULTILINE)]
            self.assertIn(1, numbers, text)
            self.assertIn(2, numbers, text)
            self.assertNotIn(0, numbers, text)

    def test_metric_and_trace_column_names_are_the_clis(self):
        r = run(["schema", "metrics", "--markdown"], self.folder)
        self.assertEqual(r.returncode, 0, r.stderr)
        rows = {}
        for line in r.stdout.decode("utf-8").splitlines():
            cells = [c.strip() for c in line.strip().strip("|").split("|")]
            if len(cells) >= 4 and cells[0].startswith("`"):
                rows[cells[0].strip("`")] = (cells[2], cells[3])
        table = cg.metric_table()
        self.assertEqual([row["name"] for row in table], list(rows))
        for row in table:
            with self.subTest(metric=row["name"]):
                # The table for people writes a count's missing unit "-" and a ratio's "1" (docs/metrics.md).
                unit = row["unit"] or ("1" if row["kind"] == "number" else "-")
                self.assertEqual((unit, row["levels"]), rows[row["name"]])
        columns = cg.trace_columns()
        header = (self.folder / "t.csv").read_text(encoding="utf-8").splitlines()[0].split(",")
        self.assertEqual([c["file_name"] for c in columns], header)
        self.assertEqual([c["name"] for c in columns], list(self.python_trial.to_dataframe().columns))


# ------------------------------------------------------------------------------------------------- figures
@needs_python
class Figures(Case):
    """calligraphy.plot: `trial(result)` and `forces(result)` return the Axes they drew into."""

    def setUp(self):
        super().setUp()
        try:
            import matplotlib
            matplotlib.use("Agg")
            import matplotlib.pyplot as plt
            import calligraphy.plot as plot
        except ImportError as error:
            self.skipTest("matplotlib is not installed: %s" % error)
        self.plt, self.plot = plt, plot
        self.addCleanup(plt.close, "all")

    def gids(self, ax):
        return {a.get_gid() for a in ax.get_children() if a.get_gid()}

    def test_figures_of_a_trial_of_one_and_two_ticks(self):
        from matplotlib.axes import Axes
        for duration in (0.001, 0.002):
            r = cg.simulate_trial(SHI, max_duration_s=duration)
            self.assertGreaterEqual(len(r.time_s), 1)
            with self.subTest(ticks=len(r.time_s)), warnings.catch_warnings(record=True) as caught:
                warnings.simplefilter("always")
                ax = self.plot.trial(r)
                self.assertIsInstance(ax, Axes)
                self.assertIn("calligraphy-element", self.gids(ax))
                ax.figure.savefig(io.BytesIO(), format="png")
                ax = self.plot.forces(r)
                self.assertIsInstance(ax, Axes)
                self.assertIn("calligraphy-in-plane-force", self.gids(ax))
                ax.figure.savefig(io.BytesIO(), format="png")
                # A valid trial, however short, draws without a warning raised at the helpers' own lines.
                own = [str(w.message) for w in caught if os.path.dirname(w.filename) == os.path.dirname(
                    self.plot.__file__)]
                self.assertEqual(own, [])

    def test_figures_into_given_axes_are_saved_with_their_ids(self):
        r = Shared.get().trial
        figure, (left, right) = self.plt.subplots(1, 2)
        self.assertIs(self.plot.trial(r, ax=left, hints=True), left)
        self.assertIs(self.plot.forces(r, ax=right), right)
        svg = io.BytesIO()
        figure.savefig(svg, format="svg")
        text = svg.getvalue().decode("utf-8")
        has_medians = len(cg.CharacterLibrary.default().load(SHI).strokes[0].median) > 0
        for gid in ("calligraphy-median" if has_medians else "calligraphy-element", "calligraphy-element", "calligraphy-feature-points", "calligraphy-trace",
                    "calligraphy-hint", "calligraphy-in-plane-force", "calligraphy-fx", "calligraphy-fy",
                    "calligraphy-stroke-boundary", "calligraphy-writing"):
            with self.subTest(gid=gid):
                self.assertIn('id="%s' % gid, text)


# Under the sanitizers: a few cases without a run of the program.
SANITIZED_CASES = {"test_big_endian_columns_score_as_native_ones", "test_bool_pen_column_is_the_0_1_column",
                   "test_misspelt_keywords_are_named", "test_none_where_a_value_is_needed",
                   "test_clamp_force_rows_and_its_input"}

load_tests = sanitized_subset(SANITIZED_CASES)


if __name__ == "__main__":
    unittest.main(verbosity=2)
