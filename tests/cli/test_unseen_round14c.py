#!/usr/bin/env python3
"""Round 14C: every number the program reports about a trial or a study, recomputed independently from the
definitions of docs/metrics.md, docs/experiments.md, docs/cli.md and the statistics' docstrings, with numpy,
from the raw trace and never from the library. Run by CTest as `cli_unseen_round14c_tests`.

Traces made by hand with a known geometry on 一 and 十 (whose models are straight elements: `model --json`):
the stroke's parallel curve 2 mm to its side at a constant 50 mm/s, the same with a pause with the pen down,
with a lift mid-stroke, written twice, backwards, with irregular time stamps, minimum-jerk movements, an
ignored blip, a pen height at the contact threshold, clocks far from 0, a row of two characters; each `score`d
(JSON and table, metres and data units, Python's `score` of a mapping) and every reported number held to its
closed form or to a brute-force deviation, discrete Frechet distance, DTW and low-pass kinematics written here.
Two simulated trials' `--json` held to their own `--csv` (segments from the pen's height, times, path, forces,
state changes, attempts, deviations, fluency); a Python trial on a raised paper held to `score(trace, scene)`.
One tiny study (`session run` of 4 subjects, `report --csv` and `--out`, `trace` of its saved trials, `session
cohort`): the tables' rows against the records, the times against the traces, the per-trial pages, the
statistics' means, SDs, intervals and paired t against numpy; a between-subjects cohort's groups and learning
statistics; a crossover cohort's labels against the documented rule; a quiz condition's events against the
record's verdicts and its trace.

Each case asserts the documented value; tolerances are those a trace file's precision gives (times 1 us,
lengths 0.1 um) or the documented discretisation. CALLIGRAPHY_CLI names the program, PYTHONPATH its Python
module. CALLIGRAPHY_SANITIZED=1 takes five cases.
"""
import csv
import hashlib
import io
import json
import math
import os
import re
import tempfile
import unittest
from decimal import Decimal
from pathlib import Path

import numpy as np

from outsider import run, sanitized_subset

load_tests = sanitized_subset({"test_offset_line_deviations_are_two_millimetres",
                               "test_offset_line_path_time_and_speed",
                               "test_frechet_matches_a_brute_force",
                               "test_trial_times_and_path_from_its_own_csv",
                               "test_trials_table_rows_are_the_records"})

YI, SHI = "一", "十"
SCALE = 0.06 / 1024  # the default layout: 60 mm per 1024-unit box, centred on the paper's origin
CONTACT_M = 0.0005
YI_MEDIAN = [[121, 393], [193, 372], [417, 402], [827, 434], [920, 401]]  # hanzi-writer-data 2.0.1's 一
STEP_M = 0.00025  # the reference's arc-length spacing for Frechet and DTW (docs/metrics.md, "Resampling")
SHARED = {}


# ---- geometry, independent of the library ------------------------------------------------------------

def to_metres(data_points):
    """hanzi-writer-data units (y up) to paper metres: (x - 512, y - 388) x 60 mm / 1024 (docs/trainer.md)."""
    p = np.asarray(data_points, float)
    return np.c_[(p[:, 0] - 512.0) * SCALE, (p[:, 1] - 388.0) * SCALE]


def to_data(metres):
    p = np.asarray(metres, float)
    return np.c_[p[:, 0] / SCALE + 512.0, p[:, 1] / SCALE + 388.0]


def model_polylines(char, cwd):
    """Each stroke's elements from `model --json` (all straight for 一 and 十) as a polyline in metres."""
    result = run(["model", char, "--json"], cwd)
    assert result.returncode == 0, result.stderr
    lines = []
    for stroke in json.loads(result.stdout)["strokes"]:
        points = []
        for element in stroke["elements"]:
            assert element["degree"] == 1, "the closed forms here need straight elements"
            a, b = element["control_points"]
            if not points:
                points.append(a)
            points.append(b)
        lines.append(to_metres(points))
    return lines


def model_elements(char, cwd):
    """Each stroke's elements from `model --json` as (N, 2) control points in metres (lines and Beziers)."""
    result = run(["model", char, "--json"], cwd)
    assert result.returncode == 0, result.stderr
    return [[to_metres(e["control_points"]) for e in stroke["elements"]]
            for stroke in json.loads(result.stdout)["strokes"]]


def bezier(control, parameters):
    """The Bezier (or line) of `control` points at `parameters`, by Bernstein polynomials."""
    degree = len(control) - 1
    u = np.asarray(parameters, float)[:, None]
    return sum(math.comb(degree, k) * u ** k * (1 - u) ** (degree - k) * control[k] for k in range(degree + 1))


def element_polyline(elements, chords):
    """The elements one after another, each split into `chords` chords of equal parameter step."""
    points = [bezier(elements[0], [0.0])]
    for control in elements:
        points.append(bezier(control, np.linspace(0.0, 1.0, chords + 1)[1:]))
    return np.concatenate(points)


def point_segment_distances(points, a, b):
    d = b - a
    s = np.clip(((points - a) @ d) / (d @ d), 0.0, 1.0)
    return np.linalg.norm(points - (a + s[:, None] * d), axis=1)


def deviations(points, polyline):
    """d_i = min over elements of the distance to the element (exact for straight elements), all at once."""
    points = np.asarray(points, float)
    a, d = polyline[:-1], np.diff(polyline, axis=0)
    best = np.full(len(points), np.inf)
    for start in range(0, len(points), 256):  # blocks of samples x every segment
        p = points[start:start + 256, None, :]
        s = np.clip(np.sum((p - a) * d, axis=2) / np.sum(d * d, axis=1), 0.0, 1.0)
        best[start:start + 256] = np.min(np.linalg.norm(p - (a + s[..., None] * d), axis=2), axis=1)
    return best


def chord_length(points):
    return float(np.sum(np.linalg.norm(np.diff(points, axis=0), axis=1)))


def resample_by_arc_length(polyline, step=STEP_M, max_points=2000):
    """Equal arc-length spacing of at most `step` and at most `max_points` points, both ends kept."""
    lengths = np.linalg.norm(np.diff(polyline, axis=0), axis=1)
    cumulative = np.r_[0.0, np.cumsum(lengths)]
    total = cumulative[-1]
    count = min(max_points, int(math.ceil(total / step - 1e-12)) + 1)
    s = np.linspace(0.0, total, count)
    return np.c_[np.interp(s, cumulative, polyline[:, 0]), np.interp(s, cumulative, polyline[:, 1])]


def drop_repeats(points):
    keep = np.r_[True, np.any(np.diff(points, axis=0) != 0.0, axis=1)]
    return points[keep]


def _diagonals(p, q):
    """The cells (i, j) of the n x m table by anti-diagonals k = i + j: each diagonal's i and distances."""
    n, m = len(p), len(q)
    for k in range(n + m - 1):
        i = np.arange(max(0, k - m + 1), min(k, n - 1) + 1)
        yield k, i, np.linalg.norm(p[i] - q[k - i], axis=1)


def brute_frechet(p, q):
    """Eiter & Mannila's recurrence over the whole table (by anti-diagonals, so numpy does each one)."""
    n = len(p)
    prev2 = np.full(n, np.inf)
    prev1 = np.full(n, np.inf)
    for k, i, dist in _diagonals(p, q):
        up = np.r_[np.inf, prev1[:-1]]  # c(i-1, j)
        diag = np.r_[np.inf, prev2[:-1]]  # c(i-1, j-1)
        best = np.minimum(np.minimum(up, diag), prev1)[i]  # prev1[i] is c(i, j-1)
        if k == 0:
            best = np.array([-np.inf])
        row = np.full(n, np.inf)
        row[i] = np.maximum(best, dist)
        prev2, prev1 = prev1, row
    return float(prev1[n - 1])


def brute_dtw(p, q):
    """Sakoe & Chiba with steps (1,0), (0,1), (1,1): D(n-1, m-1) / K, K the pairs on the optimal path."""
    n = len(p)
    cost2, cost1 = np.full(n, np.inf), np.full(n, np.inf)
    pairs2, pairs1 = np.zeros(n), np.zeros(n)
    for k, i, dist in _diagonals(p, q):
        options = np.array([np.r_[np.inf, cost2[:-1]][i], np.r_[np.inf, cost1[:-1]][i], cost1[i]])
        counts = np.array([np.r_[0, pairs2[:-1]][i], np.r_[0, pairs1[:-1]][i], pairs1[i]])
        choice = np.argmin(options, axis=0)
        best = options[choice, np.arange(len(i))]
        count = counts[choice, np.arange(len(i))]
        if k == 0:
            best, count = np.zeros(1), np.zeros(1)
        cost, pairs = np.full(n, np.inf), np.zeros(n)
        cost[i] = best + dist
        pairs[i] = count + 1
        cost2, cost1, pairs2, pairs1 = cost1, cost, pairs1, pairs
    return float(cost1[n - 1] / pairs1[n - 1]), int(pairs1[n - 1])


def written_for_curves(points, max_points=2000):
    """The written samples as Frechet and DTW take them: repeats dropped, above `max_points` replaced by
    `max_points` points equally spaced by arc length."""
    points = drop_repeats(np.asarray(points, float))
    if len(points) <= max_points:
        return points
    lengths = np.r_[0.0, np.cumsum(np.linalg.norm(np.diff(points, axis=0), axis=1))]
    s = np.linspace(0.0, lengths[-1], max_points)
    return np.c_[np.interp(s, lengths, points[:, 0]), np.interp(s, lengths, points[:, 1])]


def parallel_curve(polyline, offset, spacing):
    """Points at arc-length `spacing` on the curve `offset` metres to the left of the polyline: every point
    is exactly |offset| from it (offset lines cut at their crossing on the inner side of a corner, an arc
    round the corner on the outer side)."""
    pieces = []
    for a, b in zip(polyline[:-1], polyline[1:]):
        d = (b - a) / np.linalg.norm(b - a)
        normal = np.array([-d[1], d[0]])
        pieces.append((a + offset * normal, b + offset * normal))
    dense = [pieces[0][0]]
    for k in range(len(pieces) - 1):
        (a1, b1), (a2, b2) = pieces[k], pieces[k + 1]
        corner = polyline[k + 1]
        matrix = np.array([b1 - a1, a2 - b2]).T
        inner = False
        if abs(np.linalg.det(matrix)) > 1e-18:
            s, u = np.linalg.solve(matrix, a2 - a1)
            inner = 0.0 < s < 1.0 and 0.0 < u < 1.0
        if inner:  # the two offset lines cross
            dense.append(a1 + s * (b1 - a1))
        else:  # an arc of radius |offset| round the corner
            angle1 = math.atan2(b1[1] - corner[1], b1[0] - corner[0])
            angle2 = math.atan2(a2[1] - corner[1], a2[0] - corner[0])
            sweep = (angle2 - angle1 + math.pi) % (2 * math.pi) - math.pi
            dense.extend(corner + abs(offset) * np.array([math.cos(angle1 + sweep * f), math.sin(angle1 + sweep * f)])
                         for f in np.linspace(0.0, 1.0, 513))
    dense.append(pieces[-1][1])
    return resample_by_arc_length(drop_repeats(np.array(dense)), spacing, max_points=10 ** 6)


def kinematics(t, xy, cutoff_hz=10.0):
    """Velocity peaks and normalised jerk as docs/metrics.md defines them: a Gaussian low-pass of
    sigma = sqrt(ln 2) / (2 pi f_c) truncated at 4 sigma, on a uniform grid of step the mean sampling interval
    clamped to [sigma/16, sigma/4] but at most 16 grid points per sampling interval, from the first sample on
    (past the last, the pen rests there), extended
    before and after by the pen resting as far as the kernel reaches plus 3 points; speed and jerk by the
    documented differences; peaks by 10 % hysteresis."""
    t = np.asarray(t, float)
    xy = np.asarray(xy, float)
    sigma = math.sqrt(math.log(2.0)) / (2.0 * math.pi * cutoff_hz)
    mean_interval = (t[-1] - t[0]) / (len(t) - 1)
    h = max(min(max(mean_interval, sigma / 16.0), sigma / 4.0), mean_interval / 16.0)
    grid = t[0] + np.arange(int(math.ceil((t[-1] - t[0]) / h)) + 1) * h
    y = np.c_[np.interp(grid, t, xy[:, 0]), np.interp(grid, t, xy[:, 1])]
    reach = int(math.ceil(4.0 * sigma / h))
    y = np.r_[np.repeat(y[:1], reach + 3, 0), y, np.repeat(y[-1:], reach + 3, 0)]
    weights = np.exp(-0.5 * (np.arange(-reach, reach + 1) * h / sigma) ** 2)
    weights /= weights.sum()
    padded = np.r_[np.repeat(y[:1], reach, 0), y, np.repeat(y[-1:], reach, 0)]
    f = np.c_[np.convolve(padded[:, 0], weights, "valid"), np.convolve(padded[:, 1], weights, "valid")]
    speed = np.linalg.norm(f[2:] - f[:-2], axis=1) / (2.0 * h)
    jerk = (f[4:] - 2.0 * f[3:-1] + 2.0 * f[1:-3] - f[:-4]) / (2.0 * h ** 3)
    integral = float(np.sum(jerk ** 2) * h)
    duration = t[-1] - t[0]
    length = chord_length(xy)
    threshold = 0.1 * float(np.max(speed))
    peaks, high, trough, top = 0, False, speed[0], 0.0
    for v in speed:
        if not high:
            trough = min(trough, v)
            if v - trough >= threshold:
                high, top = True, v
        else:
            top = max(top, v)
            if top - v >= threshold:
                peaks, high, trough = peaks + 1, False, v
    return peaks + (1 if high else 0), math.sqrt(0.5 * integral * duration ** 5 / length ** 2)


def min_jerk(a, b, duration, rate):
    """Flash & Hogan's minimum-jerk movement from a to b in `duration` seconds sampled at `rate` Hz."""
    count = int(round(duration * rate)) + 1
    tau = np.linspace(0.0, 1.0, count)
    s = 10 * tau ** 3 - 15 * tau ** 4 + 6 * tau ** 5
    return tau * duration, a + s[:, None] * (b - a)


# ---- traces and the program -------------------------------------------------------------------------

def write_trace(path, t, xy, pen=None, z=None, decimals=9):
    """A CSV trace: `t` in s to 1 us, x and y to `decimals`, `pen` (1/0) or `z` [m]."""
    with open(path, "w", encoding="utf-8") as out:
        out.write("t,x,y," + ("z" if z is not None else "pen") + "\n")
        last = z if z is not None else (pen if pen is not None else np.ones(len(t), int))
        for ti, (x, y), v in zip(t, xy, last):
            third = repr(float(v)) if z is not None else str(int(v))
            out.write(f"{ti if isinstance(ti, str) else format(ti, '.6f')},{x:.{decimals}f},{y:.{decimals}f},{third}\n")
    return path


def read_trace(path):
    """The written trace back as the program reads it (the printed precision is the data)."""
    with open(path, encoding="utf-8") as f:
        rows = list(csv.DictReader(f))
    return rows


def score(trace, char, cwd, *extra):
    result = run(["score", str(trace), "--character", char, "--json", "-", *extra], cwd)
    assert result.returncode == 0, result.stderr.decode()
    return json.loads(result.stdout)


def score_table(trace, char, cwd):
    result = run(["score", str(trace), "--character", char], cwd)
    assert result.returncode == 0, result.stderr.decode()
    return result.stdout.decode()


def constant_speed_trace(polyline, offset, speed=0.05, rate=100.0):
    """The parallel curve `offset` from the stroke, at `speed` m/s sampled at `rate` Hz."""
    xy = parallel_curve(polyline, offset, speed / rate)
    t = np.arange(len(xy)) / rate
    return t, xy


def times_of(t):
    return [format(v, ".6f") for v in t]


def pen_segments(down):
    """Maximal runs of pen-down samples as (first index, last index)."""
    runs = []
    start = None
    for i, d in enumerate(down):
        if d and start is None:
            start = i
        if not d and start is not None:
            runs.append((start, i - 1))
            start = None
    if start is not None:
        runs.append((start, len(down) - 1))
    return runs


def ns(value):
    """A time rounded to whole nanoseconds, as the docs round every reported time."""
    return round(float(value) * 1e9) / 1e9


def setUpModule():
    SHARED["tmp"] = tempfile.TemporaryDirectory(prefix="round14c-")
    root = Path(SHARED["tmp"].name)
    SHARED["root"] = root
    SHARED["yi"] = model_polylines(YI, root)[0]
    SHARED["shi"] = model_polylines(SHI, root)
    t, xy = constant_speed_trace(SHARED["yi"], 0.002)
    SHARED["offset"] = (t, xy)
    write_trace(root / "offset.csv", times_of(t), xy)
    SHARED["offset_score"] = score(root / "offset.csv", YI, root)


def tearDownModule():
    SHARED["tmp"].cleanup()


class Base(unittest.TestCase):
    maxDiff = None

    def setUp(self):
        self.root = SHARED["root"]
        self.yi = SHARED["yi"]

    def only_stroke(self, record, char_index=0, stroke=0):
        return record["per_character"][char_index]["per_stroke"][stroke]

    def close(self, got, expected, tol, what):
        self.assertIsNotNone(got, f"{what}: null, expected {expected!r}")
        self.assertLessEqual(abs(got - expected), tol, f"{what}: got {got!r}, expected {expected!r}")


# ---- traces made by hand, scored --------------------------------------------------------------------

class HandMadeTraces(Base):

    def test_offset_line_deviations_are_two_millimetres(self):
        t, xy = SHARED["offset"]
        mine = deviations(xy, self.yi)
        self.assertLess(float(np.max(np.abs(mine - 0.002))), 1e-8, "the test's own curve is 2 mm off")
        record = SHARED["offset_score"]
        stroke = self.only_stroke(record)
        for level, values in (("scene", record), ("stroke", stroke), ("character", record["per_character"][0])):
            self.close(values["mean_deviation_m"], float(np.mean(mine)), 2e-9, f"{level} mean_deviation_m")
            self.close(values["max_deviation_m"], float(np.max(mine)), 2e-9, f"{level} max_deviation_m")
            self.close(values["rms_deviation_m"], float(np.sqrt(np.mean(mine ** 2))), 2e-9,
                       f"{level} rms_deviation_m")
        self.assertEqual(record["strokes_written"], 1)
        self.assertEqual(record["strokes_total"], 1)
        self.assertTrue(record["completed_in_order"])

    def test_offset_line_path_time_and_speed(self):
        t, xy = SHARED["offset"]
        record = SHARED["offset_score"]
        stroke = self.only_stroke(record)
        character = record["per_character"][0]
        written = np.array([[float(r["x"]), float(r["y"])] for r in read_trace(self.root / "offset.csv")])
        length = chord_length(written)
        duration = ns(Decimal(times_of(t)[-1]) - Decimal(times_of(t)[0]))
        self.close(stroke["path_length_m"], length, 1e-9, "per_stroke path_length_m")
        self.close(character["path_length_m"], length, 1e-9, "per_character path_length_m")
        self.assertEqual(stroke["time_s"], duration)
        self.assertEqual(record["pen_down_time_s"], duration)
        self.assertEqual(record["total_time_s"], duration)
        self.assertEqual(character["in_air_time_s"], 0.0)
        self.assertEqual(character["pen_lifts"], 0)
        self.close(stroke["mean_speed_m_s"], length / duration, 1e-9, "per_stroke mean_speed_m_s")
        self.close(character["mean_speed_m_s"], length / duration, 1e-9, "per_character mean_speed_m_s")
        self.close(stroke["mean_speed_m_s"], 0.05, 0.05 * 0.01, "the constant 50 mm/s")

    def test_constant_speed_has_one_velocity_peak(self):
        record = SHARED["offset_score"]
        self.assertEqual(self.only_stroke(record)["velocity_peaks"], 1)
        self.assertEqual(record["velocity_peaks"], 1)

    def test_frechet_matches_a_brute_force(self):
        t, xy = SHARED["offset"]
        written = drop_repeats(np.array([[float(r["x"]), float(r["y"])] for r in read_trace(self.root / "offset.csv")]))
        expected = brute_frechet(written, resample_by_arc_length(self.yi))
        record = SHARED["offset_score"]
        self.close(self.only_stroke(record)["frechet_m"], expected, 1e-8, "frechet_m against the brute force")
        self.assertEqual(record["frechet_m"], self.only_stroke(record)["frechet_m"])
        # docs/metrics.md: delta_dF <= d_max + step/2 with d_max the largest deviation (2 mm here)
        self.assertLessEqual(record["frechet_m"], 0.002 + STEP_M / 2 + 1e-9)
        self.assertGreaterEqual(record["frechet_m"], 0.002 - 1e-9)

    def test_dtw_matches_a_brute_force(self):
        written = drop_repeats(np.array([[float(r["x"]), float(r["y"])] for r in read_trace(self.root / "offset.csv")]))
        reference = resample_by_arc_length(self.yi)
        expected, pairs = brute_dtw(written, reference)
        self.assertTrue(max(len(written), len(reference)) <= pairs <= len(written) + len(reference) - 1)
        record = SHARED["offset_score"]
        self.close(self.only_stroke(record)["dtw_m"], expected, 1e-8, "dtw_m against the brute force")
        self.assertEqual(record["dtw_m"], self.only_stroke(record)["dtw_m"])

    def test_tube_share_counts_samples_beyond_two_millimetres(self):
        t, near = constant_speed_trace(self.yi, 0.0015)
        _, far = constant_speed_trace(self.yi, 0.0025)
        half = len(near) // 2
        xy = np.r_[near[:half], far[half:]]
        path = write_trace(self.root / "tube.csv", times_of(t[:len(xy)]), xy)
        record = score(path, YI, self.root)
        mine = deviations(np.array([[float(r["x"]), float(r["y"])] for r in read_trace(path)]), self.yi)
        stroke = self.only_stroke(record)
        self.assertEqual(stroke["outside_tube_share"], float(np.sum(mine > 0.002)) / len(mine))
        self.close(stroke["mean_deviation_m"], float(np.mean(mine)), 2e-9, "mean over the two halves")
        self.close(stroke["max_deviation_m"], float(np.max(mine)), 2e-9, "max over the two halves")

    def test_data_units_give_the_same_numbers(self):
        t, xy = SHARED["offset"]
        path = write_trace(self.root / "offset-data.csv", times_of(t), to_data(xy), decimals=6)
        record = score(path, YI, self.root, "--units", "data")
        metres = SHARED["offset_score"]
        for key in ("mean_deviation_m", "max_deviation_m", "rms_deviation_m", "frechet_m", "dtw_m"):
            self.close(record[key], metres[key], 1e-8, key)
        self.close(self.only_stroke(record)["path_length_m"], self.only_stroke(metres)["path_length_m"], 1e-7,
                   "path_length_m")
        self.assertEqual(record["total_time_s"], metres["total_time_s"])
        self.assertEqual(record["units"], "data")

    def test_pause_with_the_pen_down_counts_in_the_writing_time(self):
        t, xy = SHARED["offset"]
        middle = len(xy) // 2
        pause = 40  # 0.4 s at 100 Hz, the pen resting on the paper
        xy2 = np.r_[xy[:middle], np.repeat(xy[middle:middle + 1], pause, axis=0), xy[middle:]]
        t2 = np.arange(len(xy2)) / 100.0
        path = write_trace(self.root / "pause.csv", times_of(t2), xy2)
        record = score(path, YI, self.root)
        stroke = self.only_stroke(record)
        written = np.array([[float(r["x"]), float(r["y"])] for r in read_trace(path)])
        duration = ns(Decimal(times_of(t2)[-1]))
        self.assertEqual(stroke["time_s"], duration)
        self.assertEqual(record["pen_down_time_s"], duration)
        self.close(stroke["path_length_m"], chord_length(written), 1e-9, "path_length_m")
        self.close(stroke["mean_speed_m_s"], chord_length(written) / duration, 1e-9, "mean speed over the pause")
        self.assertEqual(stroke["velocity_peaks"], 2, "the speed falls to 0 and rises again: two peaks")
        # the repeated samples count in the deviation (N samples) and are dropped for Frechet and DTW
        self.close(stroke["mean_deviation_m"], float(np.mean(deviations(written, self.yi))), 2e-9, "mean")
        offset = self.only_stroke(SHARED["offset_score"])
        self.close(stroke["frechet_m"], offset["frechet_m"], 1e-12, "Frechet without the repeats")
        self.close(stroke["dtw_m"], offset["dtw_m"], 1e-12, "DTW without the repeats")

    def test_lift_mid_stroke_times_and_segments(self):
        t, xy = SHARED["offset"]
        cut = int(len(xy) * 0.6)
        pen = np.ones(len(xy), int)
        pen[cut:cut + 20] = 0  # 0.2 s in the air
        path = write_trace(self.root / "lift.csv", times_of(t), xy, pen=pen)
        record = score(path, YI, self.root)
        character = record["per_character"][0]
        runs = pen_segments(pen == 1)
        self.assertEqual(len(runs), 2)
        tt = [Decimal(v) for v in times_of(t)]
        writing = sum(ns(tt[b] - tt[a]) for a, b in runs)
        in_air = ns(tt[runs[1][0]] - tt[runs[0][1]])
        self.assertEqual(character["pen_lifts"], 1)
        self.close(character["in_air_time_s"], in_air, 1e-12, "in_air_time_s")
        self.close(record["pen_down_time_s"], writing, 1e-12, "pen_down_time_s")
        self.close(record["total_time_s"], ns(tt[runs[1][1]] - tt[runs[0][0]]), 1e-12, "total_time_s")
        self.close(record["total_time_s"], writing + in_air, 1e-12, "total = writing + in the air")
        written = np.array([[float(r["x"]), float(r["y"])] for r in read_trace(path)])
        path_down = sum(chord_length(written[a:b + 1]) for a, b in runs)
        self.close(character["path_length_m"], path_down, 1e-9, "pen-down path over both segments")
        self.close(character["mean_speed_m_s"], path_down / writing, 1e-9, "path / writing time")
        self.assertEqual([(s["begin"], s["end"]) for s in character["segments"]], [(a, b + 1) for a, b in runs],
                         "begin the first sample, end one past the last (0-based)")
        for stroke in character["per_stroke"]:
            if stroke["written"]:
                seg = [s for s in character["segments"] if s["matched_stroke"] == stroke["index"]][0]
                a, b = [r for r in runs if r[0] == seg["begin"]][0]
                self.assertEqual(stroke["time_s"], ns(tt[b] - tt[a]))
                self.close(stroke["path_length_m"], chord_length(written[a:b + 1]), 1e-9, "the matched run's path")
            else:
                self.assertIsNone(stroke["mean_deviation_m"])
                self.assertIsNone(stroke["time_s"])

    def test_stroke_written_twice_matches_the_closer_copy(self):
        t, far = constant_speed_trace(self.yi, 0.002)
        _, near = constant_speed_trace(self.yi, -0.001)
        count = min(len(far), len(near))
        xy = np.r_[far[:count], near[:count]]
        pen = np.r_[np.ones(count, int), np.ones(count, int)]
        tt = np.r_[t[:count], t[:count] + t[count - 1] + 0.3]
        pen[count - 1] = 0  # the lift between the two copies
        path = write_trace(self.root / "twice.csv", times_of(tt), xy, pen=pen)
        record = score(path, YI, self.root)
        character = record["per_character"][0]
        stroke = self.only_stroke(record)
        self.assertEqual(record["strokes_written"], 1)
        self.assertEqual(record["unmatched_segments"], 1)
        self.assertEqual(record["strokes_accepted"], 1)
        self.assertEqual(sum(record["refusals"].values()), 0)
        self.assertEqual([s["matched_stroke"] for s in character["segments"]], [None, 0])
        self.assertEqual(character_verdicts(record)[0], "accepted", "the first copy is accepted in turn")
        self.assertIsNone(character["segments"][1]["verdict"], "no verdict once every stroke is accepted")
        written = np.array([[float(r["x"]), float(r["y"])] for r in read_trace(path)])
        second = written[count:]
        self.close(stroke["mean_deviation_m"], float(np.mean(deviations(second, self.yi))), 2e-9, "the near copy")
        self.assertEqual(stroke["time_s"], ns(Decimal(times_of(tt)[-1]) - Decimal(times_of(tt)[count])))
        self.close(character["path_length_m"], chord_length(written[:count - 1]) + chord_length(second), 1e-9,
                   "both copies' pen-down path")
        # velocity peaks: a sum over scored segments; jerk: a mean over them (two copies of one movement)
        self.assertEqual(record["velocity_peaks"], 2)
        self.close(record["normalised_jerk"], stroke["normalised_jerk"], stroke["normalised_jerk"] * 0.05,
                   "mean jerk of two copies of one movement")

    def test_irregular_time_stamps_read_in_whole_nanoseconds(self):
        t, xy = SHARED["offset"]
        rng = np.random.default_rng(14)
        steps = rng.choice([0.0007, 0.001, 0.0013, 0.0171], size=len(xy) - 1)
        stamps = np.r_[13.075, 13.075 + np.cumsum(steps)]
        text = [format(v, ".4f") for v in stamps]
        path = write_trace(self.root / "irregular.csv", text, xy)
        record = score(path, YI, self.root)
        exact = Decimal(text[-1]) - Decimal(text[0])
        self.assertEqual(record["total_time_s"], float(exact), "the exact decimal difference")
        self.assertEqual(record["pen_down_time_s"], float(exact))
        self.assertEqual(self.only_stroke(record)["time_s"], float(exact))
        written = np.array([[float(r["x"]), float(r["y"])] for r in read_trace(path)])
        self.close(self.only_stroke(record)["mean_speed_m_s"], chord_length(written) / float(exact), 1e-9,
                   "L / T with irregular steps")

    def test_large_clock_times_within_the_documented_resolution(self):
        # docs/metrics.md: exact to the nanosecond below about 10^6 s, within about 0.25 us at the Unix time
        t, xy = SHARED["offset"]
        ticks = len(xy) - 1
        for start, tolerance in (("1000000", 0.0), ("1764201600", 2.5e-7)):
            with self.subTest(start=start):
                text = [f"{start}.{i * 10:03d}" if i < 100 else f"{int(start) + i // 100}.{(i % 100) * 10:03d}"
                        for i in range(len(xy))]
                path = write_trace(self.root / f"clock-{start}.csv", text, xy)
                record = score(path, YI, self.root)
                exact = float(Decimal(text[-1]) - Decimal(text[0]))
                self.assertEqual(exact, round(ticks * 0.01, 9))
                for value in (record["total_time_s"], record["pen_down_time_s"], self.only_stroke(record)["time_s"]):
                    self.assertLessEqual(abs(value - exact), tolerance, (start, value, exact))

    def test_minimum_jerk_gives_the_documented_normalised_jerk(self):
        # docs/metrics.md's table (L = 30 mm, 10 Hz filter): 0.6 s at 1 kHz 17.76, at 100 Hz 17.69;
        # 1.5 s at 1 kHz 18.49; one velocity peak each
        a = self.yi[1] + np.array([0.002, 0.0])
        direction = (self.yi[2] - self.yi[1]) / np.linalg.norm(self.yi[2] - self.yi[1])
        b = a + 0.030 * direction
        for duration, rate, documented in ((0.6, 1000, 17.76), (0.6, 100, 17.69), (1.5, 1000, 18.49)):
            with self.subTest(duration=duration, rate=rate):
                t, xy = min_jerk(a, b, duration, rate)
                path = write_trace(self.root / f"minjerk-{duration}-{rate}.csv", times_of(t), xy)
                record = score(path, YI, self.root)
                self.close(record["normalised_jerk"], documented, 0.006, "normalised_jerk")
                self.assertEqual(record["velocity_peaks"], 1)
                self.close(record["per_character"][0]["path_length_m"], 0.030, 1e-8, "L = 30 mm")

    def test_an_ignored_blip_counts_in_the_times_but_not_the_fluency(self):
        t, xy = SHARED["offset"]
        blip = np.array([xy[0] + [0.0, 0.010], xy[0] + [0.0002, 0.010]])
        xy2 = np.r_[blip, xy[:1] + [0, 0.01], xy]
        pen = np.r_[1, 1, 0, np.ones(len(xy), int)]
        t2 = np.arange(len(xy2)) / 100.0
        path = write_trace(self.root / "blip.csv", times_of(t2), xy2, pen=pen)
        record = score(path, YI, self.root)
        character = record["per_character"][0]
        self.assertEqual(character["ignored_segments"], 1)
        self.assertEqual(character["pen_lifts"], 1)
        self.assertTrue(character["segments"][0]["ignored"])
        self.assertIsNone(character["segments"][0]["verdict"])
        tt = [Decimal(v) for v in times_of(t2)]
        self.assertEqual(record["total_time_s"], ns(tt[-1] - tt[0]))
        self.close(record["pen_down_time_s"], ns(tt[1] - tt[0]) + ns(tt[-1] - tt[3]), 1e-12, "both segments")
        self.close(character["in_air_time_s"], ns(tt[3] - tt[1]), 1e-12, "the gap after the blip")
        self.assertEqual(record["velocity_peaks"], 1, "the ignored blip has no fluency")
        self.assertEqual(record["normalised_jerk"], self.only_stroke(record)["normalised_jerk"])
        offset = self.only_stroke(SHARED["offset_score"])
        for key in ("mean_deviation_m", "frechet_m", "dtw_m", "time_s", "path_length_m"):
            self.assertEqual(self.only_stroke(record)[key], offset[key], key)

    def test_pen_height_at_the_contact_threshold(self):
        t, xy = SHARED["offset"]
        z = np.zeros(len(xy))
        cut = len(xy) // 2
        z[cut - 5:cut] = CONTACT_M  # still down at exactly 0.5 mm
        z[cut:cut + 5] = 0.00050001  # up just above it
        path = write_trace(self.root / "z.csv", times_of(t), xy, z=z)
        record = score(path, YI, self.root)
        runs = pen_segments(z <= CONTACT_M)
        character = record["per_character"][0]
        self.assertEqual(character["pen_lifts"], len(runs) - 1)
        self.assertEqual([s["begin"] for s in character["segments"]], [a for a, _ in runs])
        tt = [Decimal(v) for v in times_of(t)]
        self.close(record["pen_down_time_s"], sum(ns(tt[b] - tt[a]) for a, b in runs), 1e-12, "pen_down_time_s")

    def test_reference_itself_and_one_millimetre_beside(self):
        # docs/metrics.md: the reference sampled densely scores Frechet <= 0.125 mm, 1 mm beside it 1-1.125 mm
        for offset, low, high in ((0.0, 0.0, STEP_M / 2), (0.001, 0.001, 0.001 + STEP_M / 2)):
            with self.subTest(offset=offset):
                if offset:
                    t, xy = constant_speed_trace(self.yi, offset, 0.05, 1000.0)
                else:
                    xy = resample_by_arc_length(self.yi, 0.00005, 10 ** 6)
                    t = np.arange(len(xy)) / 1000.0
                path = write_trace(self.root / f"beside-{offset}.csv", times_of(t), xy)
                frechet = score(path, YI, self.root)["frechet_m"]
                self.assertGreaterEqual(frechet, low - 1e-9)
                self.assertLessEqual(frechet, high + 1e-9)

    def test_backwards_stroke_measured_against_the_reversed_reference(self):
        t, xy = SHARED["offset"]
        path = write_trace(self.root / "backwards.csv", times_of(t), xy[::-1])
        record = score(path, YI, self.root)
        stroke = self.only_stroke(record)
        self.assertTrue(stroke["backwards"])
        self.assertEqual(record["backwards_strokes"], 1)
        written = drop_repeats(np.array([[float(r["x"]), float(r["y"])] for r in read_trace(path)]))
        reference = resample_by_arc_length(self.yi)[::-1]
        self.close(stroke["frechet_m"], brute_frechet(written, reference), 1e-8, "Frechet against the reversed")
        self.close(stroke["dtw_m"], brute_dtw(written, reference)[0], 1e-8, "DTW against the reversed")
        self.close(stroke["mean_deviation_m"], 0.002, 1e-8, "mean deviation")
        self.assertEqual(character_verdicts(record), ["backwards"])

    def test_shi_strokes_swapped_give_one_order_error(self):
        first, second = SHARED["shi"]
        t1, xy1 = constant_speed_trace(second, 0.0)
        t2, xy2 = constant_speed_trace(first, 0.0)
        gap = 0.25
        t = np.r_[t1, t2 + t1[-1] + gap]
        xy = np.r_[xy1, xy2]
        pen = np.ones(len(xy), int)
        pen[len(xy1) - 1] = 0
        path = write_trace(self.root / "swapped.csv", times_of(t), xy, pen=pen)
        record = score(path, SHI, self.root)
        self.assertEqual(record["strokes_written"], 2)
        self.assertEqual(record["order_errors"], 1)
        self.assertFalse(record["completed_in_order"])
        self.assertFalse(record["per_character"][0]["strokes_in_order"])
        self.assertEqual(character_verdicts(record)[0], "wrong_order")
        self.assertEqual(record["per_character"][0]["segments"][0]["matched_stroke"], 1)

    def test_pooled_totals_over_two_strokes(self):
        first, second = SHARED["shi"]
        t1, xy1 = constant_speed_trace(first, 0.0005, 0.05)
        t2, xy2 = constant_speed_trace(second, -0.0015, 0.03)  # slower: more samples
        t = np.r_[t1, t2 + t1[-1] + 0.3]
        xy = np.r_[xy1, xy2]
        pen = np.ones(len(xy), int)
        pen[len(xy1) - 1] = 0
        path = write_trace(self.root / "pooled.csv", times_of(t), xy, pen=pen)
        SHARED["pooled_path"] = path
        record = score(path, SHI, self.root)
        SHARED["pooled"] = record
        written = np.array([[float(r["x"]), float(r["y"])] for r in read_trace(path)])
        d1 = deviations(written[:len(xy1) - 1], first)
        d2 = deviations(written[len(xy1):], second)
        pooled = np.r_[d1, d2]
        strokes = record["per_character"][0]["per_stroke"]
        self.close(strokes[0]["mean_deviation_m"], float(np.mean(d1)), 2e-9, "stroke 0 mean")
        self.close(strokes[1]["mean_deviation_m"], float(np.mean(d2)), 2e-9, "stroke 1 mean")
        self.close(record["mean_deviation_m"], float(np.mean(pooled)), 2e-9, "pooled mean, weighted by samples")
        self.close(record["rms_deviation_m"], float(np.sqrt(np.mean(pooled ** 2))), 2e-9, "pooled RMS")
        self.close(record["max_deviation_m"], float(np.max(pooled)), 2e-9, "max of maxima")
        self.assertEqual(record["frechet_m"], max(s["frechet_m"] for s in strokes))
        weights = np.array([len(d1), len(d2)], float)
        self.close(record["dtw_m"], float(np.dot(weights, [s["dtw_m"] for s in strokes]) / weights.sum()), 1e-12,
                   "DTW weighted by sample counts")
        self.assertEqual(record["velocity_peaks"], sum(s["velocity_peaks"] for s in strokes))
        self.close(record["normalised_jerk"], float(np.mean([s["normalised_jerk"] for s in strokes])), 1e-9,
                   "mean jerk over scored segments")
        self.assertEqual([s["index"] for s in strokes], [0, 1])

    def test_score_table_numbers_strokes_from_one_in_millimetres(self):
        if "pooled" not in SHARED:
            self.test_pooled_totals_over_two_strokes()
        record = SHARED["pooled"]
        table = score_table(SHARED["pooled_path"], SHI, self.root)
        strokes = record["per_character"][0]["per_stroke"]
        rows = [line.split() for line in table.splitlines() if re.match(r"^\s+[12]\s+[A-Z]+\s", line)]
        self.assertEqual([r[0] for r in rows], ["1", "2"], table)
        for row, stroke in zip(rows, strokes):
            mean, top, frechet, dtw, seconds = (float(v) for v in row[3:8])
            self.assertEqual(mean, round(stroke["mean_deviation_m"] * 1000, 2), row)
            self.assertEqual(top, round(stroke["max_deviation_m"] * 1000, 2), row)
            self.assertEqual(frechet, round(stroke["frechet_m"] * 1000, 2), row)
            self.assertEqual(dtw, round(stroke["dtw_m"] * 1000, 2), row)
            self.assertEqual(seconds, round(stroke["time_s"], 2), row)
        total = re.search(r"mean deviation\s+([0-9.]+) mm", table)
        self.assertEqual(float(total.group(1)), round(record["mean_deviation_m"] * 1000, 3), table)
        lifts = re.search(r"pen lifts\s+(\d+)", table)
        self.assertEqual(int(lifts.group(1)), record["per_character"][0]["pen_lifts"])
        peaks = re.search(r"velocity peaks\s+(\d+)", table)
        self.assertEqual(int(peaks.group(1)), record["velocity_peaks"])

    def test_stroke_ended_short_frechet_reaches_the_reference_end(self):
        # a stroke left 9 mm short (the shortfall allowed on 一 is 13 mm): Frechet couples the reference's end
        # with a written point, so it is at least the distance from that end to the nearest written point
        t, xy = SHARED["offset"]
        lengths = np.r_[0.0, np.cumsum(np.linalg.norm(np.diff(xy, axis=0), axis=1))]
        keep = lengths <= lengths[-1] - 0.009
        path = write_trace(self.root / "short.csv", times_of(t[keep]), xy[keep])
        record = score(path, YI, self.root)
        stroke = self.only_stroke(record)
        self.assertTrue(stroke["written"], "9 mm short is within the shortfall allowed")
        written = drop_repeats(np.array([[float(r["x"]), float(r["y"])] for r in read_trace(path)]))
        reference = resample_by_arc_length(self.yi)
        self.close(stroke["frechet_m"], brute_frechet(written, reference), 1e-8, "Frechet of the short stroke")
        self.close(stroke["dtw_m"], brute_dtw(written, reference)[0], 1e-8, "DTW of the short stroke")
        gap = float(np.min(np.linalg.norm(written - self.yi[-1], axis=1)))
        self.assertGreaterEqual(stroke["frechet_m"], gap - 1e-9)
        self.assertGreater(stroke["frechet_m"], 0.008, "the unwritten end shows in the worst case")
        self.close(stroke["max_deviation_m"], 0.002, 1e-8, "the deviation does not see the unwritten end")

    def test_two_characters_pool_over_the_scene(self):
        # a row of two: centres 66 mm apart about the origin (SceneLayout: spacing_m, centre_m)
        yi = self.yi + np.array([-0.033, 0.0])
        shi = [line + np.array([0.033, 0.0]) for line in SHARED["shi"]]
        pieces = [constant_speed_trace(yi, 0.001), constant_speed_trace(shi[0], -0.0005),
                  constant_speed_trace(shi[1], 0.0015, 0.03)]
        t_all, xy_all, pen_all, begin = [], [], [], 0.0
        for t, xy in pieces:
            t_all.append(t + begin)
            xy_all.append(xy)
            pen = np.ones(len(xy), int)
            pen[-1] = 0
            pen_all.append(pen)
            begin += t[-1] + 0.25
        t, xy, pen = np.concatenate(t_all), np.concatenate(xy_all), np.concatenate(pen_all)
        path = write_trace(self.root / "row.csv", times_of(t), xy, pen=pen)
        record = score(path, YI + SHI, self.root)
        self.assertEqual(record["strokes_total"], 3)
        self.assertEqual(record["strokes_written"], 3)
        self.assertTrue(record["completed_in_order"])
        written = np.array([[float(r["x"]), float(r["y"])] for r in read_trace(path)])
        runs = pen_segments(pen == 1)
        d = [deviations(written[a:b + 1], line) for (a, b), line in zip(runs, [yi, *shi])]
        pooled = np.concatenate(d)
        self.close(record["mean_deviation_m"], float(np.mean(pooled)), 2e-9, "scene mean over every sample")
        self.close(record["rms_deviation_m"], float(np.sqrt(np.mean(pooled ** 2))), 2e-9, "scene RMS")
        self.close(record["max_deviation_m"], float(np.max(pooled)), 2e-9, "scene max")
        self.close(record["per_character"][0]["mean_deviation_m"], float(np.mean(d[0])), 2e-9, "一's mean")
        self.close(record["per_character"][1]["mean_deviation_m"], float(np.mean(np.r_[d[1], d[2]])), 2e-9,
                   "十's mean")
        tt = [Decimal(v) for v in times_of(t)]
        self.assertEqual(record["total_time_s"], ns(tt[runs[-1][1]] - tt[runs[0][0]]))
        self.close(record["pen_down_time_s"], sum(ns(tt[b] - tt[a]) for a, b in runs), 1e-12, "pen down")
        self.assertEqual(record["per_character"][1]["total_time_s"], ns(tt[runs[2][1]] - tt[runs[1][0]]))
        self.assertEqual(record["velocity_peaks"],
                         sum(kinematics(t[a:b + 1], written[a:b + 1])[0] for a, b in runs))

    def test_score_table_verdicts_add_up_to_the_strokes(self):
        if not (self.root / "swapped.csv").exists():
            self.test_shi_strokes_swapped_give_one_order_error()
        table = score_table(self.root / "swapped.csv", SHI, self.root)
        record = score(self.root / "swapped.csv", SHI, self.root)

        def count(label):
            found = re.search(rf"^\s*{label}\s+(\d+)", table, re.M)
            self.assertIsNotNone(found, f"{label!r} in {table}")
            return int(found.group(1))
        accepted, refused, missing = count("strokes accepted"), count("strokes refused"), count("strokes not written")
        self.assertEqual(accepted + refused + missing, record["strokes_total"], table)
        self.assertEqual(accepted, record["strokes_accepted"], table)
        self.assertEqual(count("pen-downs refused"), sum(record["refusals"].values()), table)
        self.assertEqual(count("strokes matched"), record["strokes_written"], table)
        verdicts = [line.split(None, 3)[-1] for line in table.splitlines() if re.match(r"^\s+[12]\s+[A-Z]+\s", line)]
        self.assertEqual(len(verdicts), 2, table)
        self.assertIn("refused: wrong order", " ".join(verdicts), table)

    def test_long_written_stroke_is_resampled_to_two_thousand_points(self):
        # 3,000-odd samples at 1 kHz and 15 mm/s: above 2000 the written points are replaced by 2000 equally
        # spaced by arc length (docs/metrics.md, "Resampling")
        t, xy = constant_speed_trace(self.yi, 0.0012, 0.015, 1000.0)
        self.assertGreater(len(xy), 2000)
        path = write_trace(self.root / "long.csv", times_of(t), xy)
        record = score(path, YI, self.root)
        stroke = self.only_stroke(record)
        written = written_for_curves([[float(r["x"]), float(r["y"])] for r in read_trace(path)])
        self.assertEqual(len(written), 2000)
        reference = resample_by_arc_length(self.yi)
        self.close(stroke["frechet_m"], brute_frechet(written, reference), 1e-8, "Frechet of 2000 points")
        self.close(stroke["dtw_m"], brute_dtw(written, reference)[0], 1e-8, "DTW of 2000 points")
        self.close(stroke["mean_deviation_m"], 0.0012, 1e-8, "every raw sample in the deviation")

    def test_curved_strokes_of_ren_against_brute_force(self):
        # 人's strokes are cubic and quadratic Beziers: each written 1 mm and 0.8 mm to its side at 40 mm/s
        strokes = model_elements("人", self.root)
        dense = [element_polyline(elements, 4096) for elements in strokes]  # chords far below 1 um off the curve
        pieces = []
        for polyline, offset in ((dense[0], 0.001), (dense[1], -0.0008)):
            tangent = np.gradient(polyline, axis=0)
            tangent /= np.linalg.norm(tangent, axis=1)[:, None]
            beside = polyline + offset * np.c_[-tangent[:, 1], tangent[:, 0]]  # along the smooth curve's normal
            xy = resample_by_arc_length(beside, 0.04 / 100.0, 10 ** 6)
            pieces.append((np.arange(len(xy)) / 100.0, xy))
        t = np.r_[pieces[0][0], pieces[1][0] + pieces[0][0][-1] + 0.3]
        xy = np.r_[pieces[0][1], pieces[1][1]]
        pen = np.ones(len(xy), int)
        pen[len(pieces[0][1]) - 1] = 0
        path = write_trace(self.root / "ren.csv", times_of(t), xy, pen=pen)
        record = score(path, "人", self.root)
        self.assertEqual(record["strokes_written"], 2)
        written = np.array([[float(r["x"]), float(r["y"])] for r in read_trace(path)])
        runs = pen_segments(pen == 1)
        for index, ((a, b), polyline) in enumerate(zip(runs, dense)):
            stroke = record["per_character"][0]["per_stroke"][index]
            mine = deviations(written[a:b + 1], polyline)
            self.close(stroke["mean_deviation_m"], float(np.mean(mine)), 5e-9, f"stroke {index} mean")
            self.close(stroke["max_deviation_m"], float(np.max(mine)), 5e-9, f"stroke {index} max")
            reference = resample_by_arc_length(element_polyline(strokes[index], 128))
            points = written_for_curves(written[a:b + 1])
            self.close(stroke["frechet_m"], brute_frechet(points, reference), 1e-8, f"stroke {index} Frechet")
            self.close(stroke["dtw_m"], brute_dtw(points, reference)[0], 1e-8, f"stroke {index} DTW")

    def test_python_score_of_a_mapping_gives_the_closed_forms(self):
        try:
            import calligraphy
        except ImportError as error:  # pragma: no cover - the module is built with the tests
            self.skipTest(f"no calligraphy module: {error}")
        rows = read_trace(self.root / "offset.csv")
        columns = {"t": np.array([float(r["t"]) for r in rows]), "x": np.array([float(r["x"]) for r in rows]),
                   "y": np.array([float(r["y"]) for r in rows]), "pen": np.array([int(r["pen"]) for r in rows])}
        record = calligraphy.score(columns, YI)
        written = np.c_[columns["x"], columns["y"]]
        mine = deviations(written, self.yi)
        self.close(record["mean_deviation_m"], float(np.mean(mine)), 2e-9, "Python mean_deviation_m")
        self.close(record["per_character"][0]["path_length_m"], chord_length(written), 1e-9, "Python path")
        self.assertEqual(record["total_time_s"], ns(Decimal(rows[-1]["t"]) - Decimal(rows[0]["t"])))
        self.assertEqual(record["per_character"][0]["per_stroke"][0]["index"], 0)


    def test_velocity_peaks_and_jerk_of_hand_made_traces_recomputed(self):
        makers = {"pause": self.test_pause_with_the_pen_down_counts_in_the_writing_time,
                  "irregular": self.test_irregular_time_stamps_read_in_whole_nanoseconds,
                  "minjerk-0.6-100": self.test_minimum_jerk_gives_the_documented_normalised_jerk,
                  "pooled": self.test_pooled_totals_over_two_strokes,
                  "twice": self.test_stroke_written_twice_matches_the_closer_copy}
        for rate in (10.0, 15.0):  # a tablet's sparse samples: at most 16 grid points per sampling interval
            t, xy = constant_speed_trace(self.yi, 0.001, 0.02, rate)
            write_trace(self.root / f"sparse-{rate:g}.csv", times_of(t), xy)
        for name, char in (("offset", YI), ("pause", YI), ("irregular", YI), ("minjerk-0.6-100", YI),
                           ("pooled", SHI), ("twice", YI), ("sparse-10", YI), ("sparse-15", YI)):
            with self.subTest(trace=name):
                path = self.root / f"{name}.csv"
                if not path.exists():
                    makers[name]()  # the case that makes the trace, when this one runs alone
                rows = read_trace(path)
                t = np.array([float(r["t"]) for r in rows])
                xy = np.array([[float(r["x"]), float(r["y"])] for r in rows])
                down = np.array([r["pen"] == "1" for r in rows])
                record = score(path, char, self.root)
                results = [kinematics(t[a:b + 1], xy[a:b + 1]) for a, b in pen_segments(down)]
                self.assertEqual(record["velocity_peaks"], sum(p for p, _ in results))
                self.close(record["normalised_jerk"], float(np.mean([j for _, j in results])),
                           1e-9 * record["normalised_jerk"], "normalised_jerk")

    def test_python_trial_on_a_raised_paper_scores_as_the_trial_did(self):
        # a row centred 10 mm right and 5 mm down on paper 20 mm above the device's origin: the trace's z is the
        # device's, the pen down within 0.5 mm of the paper (docs/metrics.md); score(trace, scene) places and
        # measures it as the trial did
        try:
            import calligraphy
        except ImportError as error:  # pragma: no cover - the module is built with the tests
            self.skipTest(f"no calligraphy module: {error}")
        scene = calligraphy.Scene(YI, layout=calligraphy.SceneLayout(paper_z_m=0.02, centre_m=[0.01, -0.005]))
        result = calligraphy.simulate_trial(scene, max_duration_s=4, seed=0)
        t = np.asarray(result.time_s, float)
        position = np.asarray(result.position_m, float)
        runs = pen_segments(position[:, 2] - 0.02 <= CONTACT_M)
        self.assertGreater(len(runs), 0)
        total = ns(t[runs[-1][1]] - t[runs[0][0]])
        down = sum(ns(t[b] - t[a]) for a, b in runs)
        for name, record in (("the trial's metrics", result.metrics),
                             ("score of its trace", calligraphy.score(result.to_dataframe(), result.scene))):
            with self.subTest(name):
                self.close(record["total_time_s"], total, 1e-9, "total_time_s")
                self.close(record["pen_down_time_s"], down, 1e-9, "pen_down_time_s")
                self.assertEqual(record["strokes_written"], 1)
                segment = [s for s in record["per_character"][0]["segments"] if s["matched_stroke"] == 0][0]
                mine = deviations(position[segment["begin"]:segment["end"], :2], self.yi + np.array([0.01, -0.005]))
                self.close(record["mean_deviation_m"], float(np.mean(mine)), 2e-9, "mean deviation")

    def test_verdict_distance_is_the_path_mean_from_the_median(self):
        # docs/stroke-acceptance.md: the verdict's mean distance is from the centre line, the data's median
        # (一's median has a fifth point the model's elements leave out), over the pen's path
        median = to_metres(YI_MEDIAN)
        written = np.array([[float(r["x"]), float(r["y"])] for r in read_trace(self.root / "offset.csv")])
        d = deviations(written, median)
        steps = np.linalg.norm(np.diff(written, axis=0), axis=1)
        along_path = float(np.sum(steps * (d[1:] + d[:-1]) / 2) / np.sum(steps))
        verdict = SHARED["offset_score"]["per_character"][0]["segments"][0]["verdict"]
        self.assertTrue(verdict["accepted"])
        self.assertEqual(verdict["expected_stroke"], 0)
        self.close(verdict["mean_deviation_m"], along_path, 1e-6, "the verdict's mean distance")
        self.assertGreater(abs(verdict["mean_deviation_m"] - SHARED["offset_score"]["mean_deviation_m"]), 1e-5,
                           "the median is not the elements: the two distances differ")

def character_verdicts(record):
    out = []
    for segment in record["per_character"][0]["segments"]:
        verdict = segment["verdict"]
        if verdict is None:
            out.append(None)
        else:
            out.append("accepted" if verdict["accepted"] else verdict["refusal"])
    return out


# ---- one simulated trial: its JSON against its own CSV ----------------------------------------------

class TrialNumbers(Base):

    @classmethod
    def setUpClass(cls):
        root = SHARED["root"]
        result = run(["trial", SHI, "--max-duration", "6", "--seed", "3", "--json", "trial.json",
                      "--csv", "trial.csv"], root)
        assert result.returncode in (0, 1), result.stderr
        cls.record = json.loads((root / "trial.json").read_text(encoding="utf-8"))
        cls.rows = read_trace(root / "trial.csv")
        cls.table = result.stdout.decode()
        cls.t = [Decimal(r["t"]) for r in cls.rows]
        cls.xy = np.array([[float(r["x"]), float(r["y"])] for r in cls.rows])
        cls.z = np.array([float(r["z"]) for r in cls.rows])
        cls.runs = pen_segments(cls.z <= CONTACT_M)
        result = run(["trial", SHI, "--max-duration", "10", "--seed", "1", "--json", "done.json",
                      "--csv", "done.csv"], root)
        assert result.returncode == 0, result.stderr
        cls.done = json.loads((root / "done.json").read_text(encoding="utf-8"))
        cls.done_table = result.stdout.decode()
        cls.done_rows = read_trace(root / "done.csv")
        result = run(["trial", SHI, "--guidance", "off", "--max-duration", "30", "--assist-after-misses", "1",
                      "--writer-param", "backwards_probability=1", "--json", "assisted.json", "--csv",
                      "assisted.csv"], root)
        assert result.returncode == 0, result.stderr
        cls.assisted = json.loads((root / "assisted.json").read_text(encoding="utf-8"))

    def test_trial_times_and_path_from_its_own_csv(self):
        record, runs, t = self.record, self.runs, self.t
        self.assertGreater(len(runs), 0, "the simulated writer touched the paper")
        character = record["per_character"][0]
        self.assertEqual([s["begin"] for s in character["segments"]], [a for a, _ in runs])
        self.assertEqual(character["pen_lifts"], len(runs) - 1)
        self.close(record["total_time_s"], ns(t[runs[-1][1]] - t[runs[0][0]]), 1e-9, "total_time_s")
        self.close(record["pen_down_time_s"], sum(ns(t[b] - t[a]) for a, b in runs), 1e-9, "pen_down_time_s")
        self.close(character["in_air_time_s"], sum(ns(t[c] - t[b]) for (_, b), (c, _) in zip(runs, runs[1:])),
                   1e-9, "in_air_time_s")
        path = sum(chord_length(self.xy[a:b + 1]) for a, b in runs)
        self.close(character["path_length_m"], path, 1e-6 * max(path, 1e-3), "path_length_m")

    def test_trial_fluency_recomputed_from_its_csv(self):
        character = self.record["per_character"][0]
        t = np.array([float(v) for v in self.t])
        totals = []
        for segment in character["segments"]:
            if segment["ignored"]:
                continue
            a, b = segment["begin"], segment["end"]
            peaks, jerk = kinematics(t[a:b], self.xy[a:b])
            totals.append((peaks, jerk))
            if segment["matched_stroke"] is not None:
                stroke = character["per_stroke"][segment["matched_stroke"]]
                self.assertEqual(stroke["velocity_peaks"], peaks)
                self.close(stroke["normalised_jerk"], jerk, 1e-9 * jerk, "the stroke's normalised_jerk")
        self.assertEqual(self.record["velocity_peaks"], sum(p for p, _ in totals))
        self.close(self.record["normalised_jerk"], float(np.mean([j for _, j in totals])),
                   1e-9 * self.record["normalised_jerk"], "normalised_jerk, the mean over scored segments")
        self.close(character["mean_speed_m_s"], character["path_length_m"] / character["pen_down_time_s"], 1e-12,
                   "path / writing time")

    def test_completed_trial_time_and_attempts_from_its_csv(self):
        record, rows = self.done, self.done_rows
        self.assertEqual(record["end_reason"], "completed")
        self.assertEqual(record["trial_time_s"], ns(Decimal(rows[-1]["t"])), "the tick the last stroke completed")
        for stroke in record["renderer_strokes"]:
            attempts = {int(r["attempt"]) for r in rows if int(r["stroke"]) == stroke["index"]}
            self.assertEqual(stroke["attempts"], max(attempts), stroke)
        self.assertEqual(record["strokes_completed"], 2)
        self.assertTrue(record["completed_in_order"])

    def test_trial_frechet_and_dtw_of_each_written_stroke_from_the_csv(self):
        character = self.record["per_character"][0]
        for segment in character["segments"]:
            if segment["matched_stroke"] is None:
                continue
            stroke = character["per_stroke"][segment["matched_stroke"]]
            written = written_for_curves(self.xy[segment["begin"]:segment["end"]])
            reference = resample_by_arc_length(SHARED["shi"][segment["matched_stroke"]])
            if segment["backwards"]:
                reference = reference[::-1]
            self.close(stroke["frechet_m"], brute_frechet(written, reference), 1e-6, "Frechet from the CSV")
            self.close(stroke["dtw_m"], brute_dtw(written, reference)[0], 1e-6, "DTW from the CSV")

    def test_tables_totals_are_the_json_rounded(self):
        record = self.done
        score_record = score(self.root / "done.csv", SHI, self.root)
        score_text = score_table(self.root / "done.csv", SHI, self.root)
        character = score_record["per_character"][0]

        def value(text, label, pattern=r"([0-9.]+)"):
            found = re.search(rf"^\s*{re.escape(label)}\s+{pattern}", text, re.M)
            self.assertIsNotNone(found, f"{label!r} in {text}")
            return found.groups() if found.re.groups > 1 else found.group(1)
        for text in (self.done_table, score_text):
            self.assertEqual(value(text, "mean deviation"), f"{record['mean_deviation_m'] * 1000:.3f}")
            self.assertEqual(value(text, "max deviation"), f"{record['max_deviation_m'] * 1000:.3f}")
            self.assertEqual(value(text, "Frechet (worst stroke)"), f"{record['frechet_m'] * 1000:.3f}")
            self.assertEqual(value(text, "DTW (mean)"), f"{record['dtw_m'] * 1000:.3f}")
        self.assertEqual(value(self.done_table, "time", r"([0-9.]+) s \(pen down ([0-9.]+) s\)"),
                         (f"{record['total_time_s']:.2f}", f"{record['pen_down_time_s']:.2f}"))
        self.assertEqual(value(self.done_table, "trial time"), f"{record['trial_time_s']:.2f}")
        self.assertEqual(value(self.done_table, "state transitions"), str(record["state_transitions"]))
        self.assertEqual(value(self.done_table, "max |F|"), f"{record['max_force_n']:.3f}")
        self.assertEqual(value(self.done_table, "max per-tick |dF|"), f"{record['max_force_step_n']:.3f}")
        self.assertEqual(value(score_text, "RMS deviation"), f"{record['rms_deviation_m'] * 1000:.3f}")
        self.assertEqual(value(score_text, "time", r"([0-9.]+) s \(pen down ([0-9.]+) s, in the air ([0-9.]+) s\)"),
                         (f"{record['total_time_s']:.2f}", f"{record['pen_down_time_s']:.2f}",
                          f"{character['in_air_time_s']:.2f}"))
        self.assertEqual(float(value(score_text, "mean speed")), float(f"{character['mean_speed_m_s']:.4f}"))
        self.assertEqual(value(score_text, "pen lifts"), str(character["pen_lifts"]))
        self.assertEqual(value(score_text, "velocity peaks"), str(record["velocity_peaks"]))
        self.assertEqual(value(score_text, "normalised jerk"), f"{record['normalised_jerk']:.1f}")
        self.assertEqual(value(score_text, "pen-downs unmatched", r"(\d+), too short to score (\d+)"),
                         (str(character["unmatched_segments"]), str(character["ignored_segments"])))

    def test_strokes_written_backwards_then_assisted(self):
        # every stroke written from its end, refused, and credited as assisted after one miss: the renderer took
        # none (strokes_completed 0, strokes_assisted 2); the trace wrote both, backwards (docs/metrics.md)
        record = self.assisted
        self.assertEqual(record["end_reason"], "completed")
        renderer = record["renderer_strokes"]
        self.assertEqual(record["strokes_assisted"], sum(1 for s in renderer if s["assisted"]))
        self.assertEqual(record["strokes_completed"], sum(1 for s in renderer if s["completed"] and not s["assisted"]))
        self.assertEqual((record["strokes_assisted"], record["strokes_completed"], record["strokes_accepted"]),
                         (2, 0, 0))
        strokes = record["per_character"][0]["per_stroke"]
        self.assertEqual(record["strokes_written"], sum(1 for s in strokes if s["written"]))
        self.assertEqual(record["backwards_strokes"], sum(1 for s in strokes if s["backwards"]))
        self.assertEqual(record["completed_in_order"],
                         record["strokes_written"] == record["strokes_total"] and record["order_errors"] == 0)
        self.assertEqual((record["strokes_written"], record["backwards_strokes"], record["completed_in_order"]),
                         (2, 2, True), "both strokes were written, backwards (docs/stroke-acceptance.md)")
        self.assertEqual(sum(record["refusals"].values()),
                         sum(1 for s in record["per_character"][0]["segments"]
                             if s["verdict"] is not None and not s["verdict"]["accepted"]))
        rows = read_trace(self.root / "assisted.csv")
        xy = np.array([[float(r["x"]), float(r["y"])] for r in rows])
        for segment in record["per_character"][0]["segments"]:
            if segment["matched_stroke"] is not None:
                stroke = strokes[segment["matched_stroke"]]
                mine = deviations(xy[segment["begin"]:segment["end"]], SHARED["shi"][segment["matched_stroke"]])
                self.close(stroke["mean_deviation_m"], float(np.mean(mine)), 2e-7, "a backwards stroke's deviation")
        # Scored with the trial's assisted credit (after one miss), the verdicts in turn are the trial's.
        scored = score(self.root / "assisted.csv", SHI, self.root, "--assist-after-misses", "1")
        for key in ("strokes_written", "backwards_strokes", "completed_in_order", "strokes_accepted", "refusals"):
            self.assertEqual(scored[key], record[key], key)
        self.assertEqual(scored["strokes_assisted"], 2)

    def test_trial_forces_and_state_changes_from_its_csv(self):
        force = np.array([[float(r["fx"]), float(r["fy"]), float(r["fz"])] for r in self.rows])
        magnitude = np.linalg.norm(force, axis=1)
        self.close(self.record["max_force_n"], float(np.max(magnitude)), 2e-4, "max_force_n (0.1 mN in the CSV)")
        steps = np.linalg.norm(np.diff(force, axis=0), axis=1)  # max |F(k) - F(k-1)| over the ticks
        self.close(self.record["max_force_step_n"], float(np.max(steps)), 3e-4, "max_force_step_n")
        states = [r["state"] for r in self.rows]
        changes = sum(1 for a, b in zip(states, states[1:]) if a != b)
        self.assertEqual(self.record["state_transitions"], changes)

    def test_trial_renderer_counts_and_time(self):
        record = self.record
        renderer = record["renderer_strokes"]
        self.assertEqual([s["index"] for s in renderer], list(range(len(renderer))))
        self.assertEqual(record["strokes_completed"], sum(1 for s in renderer if s["completed"] and not s["assisted"]))
        self.assertEqual(record["strokes_assisted"], sum(1 for s in renderer if s["assisted"]))
        self.assertEqual(record["strokes_total"], len(renderer))
        ticks = len(self.rows)
        end = ticks / record["rate_hz"]
        if record["end_reason"] == "time_limit":
            self.close(record["trial_time_s"], end, 1e-9, "trial_time_s at the time limit")
        else:
            self.assertLessEqual(record["trial_time_s"], end + 1e-9)
        self.assertEqual(record["strokes_written"],
                         sum(1 for s in record["per_character"][0]["per_stroke"] if s["written"]))

    def test_trial_deviation_of_each_written_stroke_from_the_csv(self):
        character = self.record["per_character"][0]
        checked = 0
        for segment in character["segments"]:
            if segment["matched_stroke"] is None:
                continue
            a, b = [r for r in self.runs if r[0] == segment["begin"]][0]
            stroke = character["per_stroke"][segment["matched_stroke"]]
            polyline = SHARED["shi"][segment["matched_stroke"]]
            mine = deviations(self.xy[a:b + 1], polyline)
            self.close(stroke["mean_deviation_m"], float(np.mean(mine)), 2e-7, "mean from the CSV")
            self.close(stroke["max_deviation_m"], float(np.max(mine)), 2e-7, "max from the CSV")
            self.assertEqual(stroke["time_s"], ns(self.t[b] - self.t[a]))
            checked += 1
        self.assertEqual(checked, self.record["strokes_written"])

    def test_score_of_the_trial_csv_gives_the_trial_metrics(self):
        scored = score(self.root / "trial.csv", SHI, self.root)
        for key in ("strokes_total", "strokes_written", "strokes_accepted", "order_errors", "backwards_strokes",
                    "unmatched_segments", "completed_in_order", "velocity_peaks", "total_time_s",
                    "pen_down_time_s"):
            self.assertEqual(scored[key], self.record[key], key)
        for key in ("mean_deviation_m", "max_deviation_m", "rms_deviation_m", "frechet_m", "dtw_m",
                    "normalised_jerk"):
            if self.record[key] is None:
                self.assertIsNone(scored[key], key)
            else:
                self.close(scored[key], self.record[key], 1e-6 * max(abs(self.record[key]), 1e-3), key)

    def test_trial_table_numbers_strokes_from_one(self):
        rows = [line.split() for line in self.table.splitlines() if re.match(r"^\s+[12]\s+十\s", line)]
        self.assertEqual([r[0] for r in rows], ["1", "2"], self.table)
        for row, stroke in zip(rows, self.record["per_character"][0]["per_stroke"]):
            if stroke["mean_deviation_m"] is None:
                self.assertEqual(row[4], "-", row)
            else:
                self.assertEqual(float(row[4]), round(stroke["mean_deviation_m"] * 1000, 2), row)
                self.assertEqual(float(row[8]), round(stroke["time_s"], 2), row)


# ---- one tiny study ---------------------------------------------------------------------------------

PROTOCOL = {"name": "r14c", "conditions": [{"name": "V", "mode": "vision"}, {"name": "H", "mode": "haptic"}],
            "test": {"characters": [YI, SHI], "conditions": ["V", "H"], "repetitions": 2},
            "trial": {"max_duration_s": 4}}
SUBJECTS = 4
T975 = {1: 12.706204736174698, 2: 4.302652729749464, 3: 3.182446305284263, 4: 2.7764451051977987}


def read_table(path):
    with open(path, encoding="utf-8", newline="") as f:
        return list(csv.DictReader(f))


def number(text):
    return float("nan") if text == "" else float(text)


class StudyNumbers(Base):

    @classmethod
    def setUpClass(cls):
        root = SHARED["root"] / "study"
        root.mkdir()
        (root / "p.json").write_text(json.dumps(PROTOCOL, ensure_ascii=False), encoding="utf-8")
        (root / "tables").mkdir()
        (root / "cohort").mkdir()
        cls.printed = []
        for args in (["session", "run", "p.json", "--subjects", str(SUBJECTS), "--out", "st"],
                     ["report", "st", "--csv", "tables"],
                     ["session", "cohort", "p.json", "--subjects", str(SUBJECTS), "--csv", "cohort", "--jobs", "1"]):
            result = run(args, root)
            assert result.returncode == 0, (args, result.stderr)
            cls.printed.append(result.stdout.decode())
        cls.study = root
        cls.trials = read_table(root / "tables" / "trials.csv")
        cls.strokes = read_table(root / "tables" / "strokes.csv")
        cls.records = {}
        for path in sorted(root.glob("st/*/*/trials/*.json")):
            cls.records[(path.parts[-4], int(path.name[:3]))] = (path, json.loads(path.read_text(encoding="utf-8")))

    def test_trials_table_rows_are_the_records(self):
        self.assertEqual(len(self.trials), SUBJECTS * 8)
        self.assertEqual(len(self.records), SUBJECTS * 8)
        metric_columns = ["completed_in_order", "strokes_total", "strokes_written", "strokes_accepted",
                          "strokes_assisted", "order_errors", "backwards_strokes", "unmatched_segments",
                          "mean_deviation_m", "max_deviation_m", "rms_deviation_m", "frechet_m", "dtw_m",
                          "total_time_s", "pen_down_time_s", "velocity_peaks", "normalised_jerk"]
        for row in self.trials:
            path, record = self.records[(row["subject"], int(row["trial"]))]
            found = self.find_metrics(record)
            for column in metric_columns:
                value = found[column]
                if value is None:
                    self.assertEqual(row[column], "", (path.name, column))
                elif isinstance(value, bool):
                    self.assertEqual(row[column], "TRUE" if value else "FALSE", (path.name, column))
                else:
                    self.assertEqual(float(row[column]), float(value), (path.name, column))
            self.assertEqual(row["end_reason"], record["end_reason"], path.name)
            self.assertEqual(number(row["legibility_top1"]), float(record["legibility"]["top1"]), path.name)
            self.assertEqual(number(row["legibility_top5"]), float(record["legibility"]["top5"]), path.name)
            self.assertEqual(int(row["strokes_given_up"]), record["writer"]["log"]["strokes_given_up"], path.name)
            trace = path.parent / record["files"]["trace"]
            self.assertEqual(row["trace_sha256"], hashlib.sha256(trace.read_bytes()).hexdigest(), path.name)
            self.assertEqual(Path(row["trace_file"]).name, trace.name)
            # the file name's NNN-phase-condition-rN
            number_, phase, condition, repetition = path.name.split("-")[:4]
            self.assertEqual(int(row["trial"]), int(number_))
            self.assertEqual((row["phase"], row["condition"]), (phase, condition))
            self.assertEqual(row["repetition"], repetition[1:])

    def find_metrics(self, record):
        """The one metrics record's keys wherever the record holds them (top level or under a key)."""
        if "mean_deviation_m" in record:
            return record
        for value in record.values():
            if isinstance(value, dict) and "mean_deviation_m" in value and "strokes_total" in value:
                return value
        raise AssertionError(f"no metrics in the record: {sorted(record)}")

    def test_numbering_blocks_items_and_labels(self):
        for subject in {r["subject"] for r in self.trials}:
            rows = sorted((r for r in self.trials if r["subject"] == subject), key=lambda r: int(r["trial"]))
            self.assertEqual([int(r["trial"]) for r in rows], list(range(1, 9)))
            self.assertEqual([r["condition"] for r in rows], ["V"] * 4 + ["H"] * 4)
            self.assertEqual([int(r["block"]) for r in rows], [1] * 4 + [2] * 4)
            self.assertEqual([r["mode"] for r in rows], ["vision"] * 4 + ["haptic"] * 4)
            self.assertEqual([r["characters"] for r in rows], [YI, SHI] * 4)
            self.assertEqual([int(r["item"]) for r in rows], [1, 2] * 4)
            self.assertEqual([int(r["repetition"]) for r in rows], [1, 1, 2, 2] * 2)
            self.assertTrue(all(r["group"] == "" and r["phase"] == "test" for r in rows))
            self.assertTrue(all(r["session_number"] == "1" for r in rows))

    def test_strokes_table_rows_are_the_per_stroke_records(self):
        expected = sum(int(r["strokes_total"]) for r in self.trials)
        self.assertEqual(len(self.strokes), expected)
        typical = {}
        for char in (YI, SHI):
            result = run(["model", char, "--json"], self.study)
            typical[char] = [stroke["typical_id"] for stroke in json.loads(result.stdout)["strokes"]]
        for row in self.strokes:
            _, record = self.records[(row["subject"], int(row["trial"]))]
            metrics = self.find_metrics(record)
            character = metrics["per_character"][int(row["character"]) - 1]
            stroke = character["per_stroke"][int(row["stroke"]) - 1]
            self.assertEqual(stroke["index"], int(row["stroke"]) - 1)
            self.assertEqual(row["character_text"], character["character"])
            self.assertEqual(row["written"], "TRUE" if stroke["written"] else "FALSE")
            self.assertEqual(row["backwards"], "TRUE" if stroke["backwards"] else "FALSE")
            self.assertEqual(int(row["typical_id"]), typical[row["character_text"]][int(row["stroke"]) - 1])
            for column in ("mean_deviation_m", "max_deviation_m", "rms_deviation_m", "frechet_m", "dtw_m",
                           "time_s", "path_length_m"):
                if stroke[column] is None:
                    self.assertEqual(row[column], "", column)
                else:
                    self.assertEqual(float(row[column]), float(stroke[column]), column)
            # the pen-downs whose verdict names this stroke (the one written as, or the one due), those refused
            # and the last refusal's reason
            judged = [s["verdict"] for s in character["segments"]
                      if s["verdict"] is not None and s["verdict"]["matched_stroke"] == stroke["index"]]
            refused = [v for v in judged if not v["accepted"]]
            self.assertEqual(int(row["segments"]), len(judged), row)
            self.assertEqual(int(row["refused_segments"]), len(refused), row)
            self.assertEqual(row["refusal"], refused[-1]["refusal"] if refused else "", row)

    def test_saved_traces_give_the_tables_times(self):
        checked = 0
        for row in self.trials[:4]:
            trace = self.study / row["trace_file"] if not os.path.isabs(row["trace_file"]) else Path(row["trace_file"])
            if not trace.exists():
                trace = Path(row["trace_file"])
            result = run(["trace", str(trace)], self.study)
            self.assertEqual(result.returncode, 0, result.stderr)
            rows = list(csv.DictReader(io.StringIO(result.stdout.decode())))
            t = [Decimal(r["t"]) for r in rows]
            z = np.array([float(r["z"]) for r in rows])
            xy = np.array([[float(r["x"]), float(r["y"])] for r in rows])
            runs = pen_segments(z <= CONTACT_M)
            _, record = self.records[(row["subject"], int(row["trial"]))]
            self.assertEqual(record["samples"], len(rows), "the record's samples are the trace's rows")
            if not runs:
                self.assertEqual(row["total_time_s"], "")
                continue
            scored = score(trace, row["characters"], self.study)
            for key in ("total_time_s", "pen_down_time_s", "strokes_written", "velocity_peaks"):
                self.assertEqual(scored[key], float(row[key]) if "." in row[key] else int(row[key]), key)
            for key in ("mean_deviation_m", "frechet_m", "dtw_m", "normalised_jerk"):
                if row[key] != "":
                    self.close(scored[key], float(row[key]), 1e-6 * abs(float(row[key])),
                               f"score of the .trace.h5: {key}")
            self.close(float(row["total_time_s"]), ns(t[runs[-1][1]] - t[runs[0][0]]), 1e-9, "total_time_s")
            self.close(float(row["pen_down_time_s"]), sum(ns(t[b] - t[a]) for a, b in runs), 1e-9, "pen_down_time_s")
            _, record = self.records[(row["subject"], int(row["trial"]))]
            metrics = self.find_metrics(record)
            character = metrics["per_character"][0]
            for segment in character["segments"]:
                if segment["matched_stroke"] is None:
                    continue
                a, b = [r for r in runs if r[0] == segment["begin"]][0]
                srow = [s for s in self.strokes if s["subject"] == row["subject"] and s["trial"] == row["trial"]
                        and int(s["stroke"]) == segment["matched_stroke"] + 1][0]
                self.close(float(srow["path_length_m"]), chord_length(xy[a:b + 1]), 1e-6, "strokes.csv path")
                self.close(float(srow["time_s"]), ns(t[b] - t[a]), 1e-9, "strokes.csv time_s")
            checked += 1
        self.assertGreater(checked, 0)

    def test_per_trial_pages_show_the_tables_values(self):
        import html as html_module
        result = run(["report", "st", "--out", "pages.html"], self.study)
        self.assertEqual(result.returncode, 0, result.stderr)
        shown = {}
        for page in sorted((self.study / "pages_files").glob("*/*.html")):
            text = page.read_text(encoding="utf-8")
            for article in re.finditer(r'<article[^>]* id="trial-([^"]+)-(\d+)".*?</article>', text, re.S):
                body = re.sub(r"<svg.*?</svg>|<figcaption.*?</figcaption>", "", article.group(0), flags=re.S)
                words = " ".join(html_module.unescape(re.sub(r"<[^>]+>", " ", body)).split())
                shown[(article.group(1), int(article.group(2)))] = words
        self.assertEqual(len(shown), len(self.trials))

        def mm(value):
            return "\u2013" if value == "" else f"{float(value) * 1000:.2f}"
        for row in self.trials:
            words = shown[(row["session"], int(row["trial"]))]
            expected = (f"{float(row['total_time_s']):.1f} s \u00b7 deviation {mm(row['mean_deviation_m'])} mm "
                        f"\u00b7 Fr\u00e9chet {mm(row['frechet_m'])} mm \u00b7 DTW {mm(row['dtw_m'])} mm "
                        f"\u00b7 order errors {row['order_errors']} \u00b7 backwards {row['backwards_strokes']}")
            self.assertIn(expected, words)
            self.assertIn(f"#{int(row['trial'])} {row['characters']} {row['phase']} {row['condition']} "
                          f"block {row['block']}, item {row['item']}, r{row['repetition']}", words)
            self.assertEqual(row["end_reason"] in words.split(" \u00b7 ")[-1], row["end_reason"] != "completed",
                             words)

    def test_printed_counts_are_the_tables(self):
        session_run, report, cohort = self.printed
        for subject in range(1, SUBJECTS + 1):
            line = [x for x in session_run.splitlines() if x.startswith(f"S{subject:02d}:")]
            self.assertEqual(len(line), 1, session_run)
            self.assertIn("8 of 8 trials saved", line[0])
        self.assertIn(f"trials.csv ({len(self.trials)} rows), strokes.csv ({len(self.strokes)} rows)", report)
        self.assertIn(f"{SUBJECTS} subjects, {len(self.trials)} trials on 1 threads",
                      cohort.replace("thread ", "threads "))
        self.assertIn(f"trials.csv ({len(self.trials)} rows), strokes.csv ({len(self.strokes)} rows)", cohort)

    def test_cohort_tables_are_the_session_tables(self):
        cohort = read_table(self.study / "cohort" / "trials.csv")
        self.assertEqual(len(cohort), len(self.trials))
        key = lambda r: (r["subject"], int(r["trial"]))  # noqa: E731
        left = {key(r): r for r in self.trials}
        skip = {"session", "start_utc", "trace_file", "trace_sha256"}
        for row in cohort:
            mine = left[key(row)]
            self.assertEqual(row["session"], f"r14c-{row['subject']}-s1")
            self.assertEqual(row["start_utc"], "")
            self.assertEqual(row["trace_file"], "")
            for column, value in row.items():
                if column not in skip:
                    self.assertEqual(value, mine[column], (key(row), column))
        cohort_strokes = read_table(self.study / "cohort" / "strokes.csv")
        self.assertEqual(len(cohort_strokes), len(self.strokes))
        stroke_key = lambda r: (r["subject"], int(r["trial"]), int(r["character"]), int(r["stroke"]))  # noqa: E731
        sessions = {stroke_key(r): r for r in self.strokes}
        for row in cohort_strokes:
            for column, value in row.items():
                if column != "session":
                    self.assertEqual(value, sessions[stroke_key(row)][column], (stroke_key(row), column))

    def frame(self):
        import pandas
        frame = pandas.DataFrame(self.trials)
        for column in ("mean_deviation_m", "total_time_s"):
            frame[column] = [number(v) for v in frame[column]]
        frame["mean_deviation_m"] = frame["mean_deviation_m"].astype(float)
        frame["repetition"] = frame["repetition"].astype(int)
        return frame

    def subject_means(self, value, condition):
        out = {}
        for subject in sorted({r["subject"] for r in self.trials}):
            values = [number(r[value]) for r in self.trials if r["subject"] == subject and r["condition"] == condition]
            values = [v for v in values if not math.isnan(v)]
            out[subject] = float(np.mean(values))
        return out

    def test_describe_by_subject_against_numpy(self):
        try:
            from calligraphy.statistics import describe
            import pandas  # noqa: F401
        except ImportError as error:  # pragma: no cover
            self.skipTest(f"no pandas: {error}")
        frame = self.frame()
        deviation = describe(frame, "mean_deviation_m", by="condition", unit="subject")
        for condition in ("H", "V"):
            rows = [r for r in self.trials if r["condition"] == condition]
            means = np.array(list(self.subject_means("mean_deviation_m", condition).values()))
            row = deviation[deviation.condition == condition].iloc[0]
            self.assertEqual(int(row["n_missing"]), sum(1 for r in rows if r["mean_deviation_m"] == ""))
            self.assertEqual(int(row["n"]), len(means))
            self.close(float(row["mean"]), float(np.mean(means)), 1e-15, "mean of subject means, NaN trials left out")
            by_trial = describe(frame, "mean_deviation_m", by="condition", unit="trial")
            values = np.array([float(r["mean_deviation_m"]) for r in rows if r["mean_deviation_m"] != ""])
            row = by_trial[by_trial.condition == condition].iloc[0]
            self.assertEqual(int(row["n"]), len(values))
            self.close(float(row["mean"]), float(np.mean(values)), 1e-15, "mean over trials")
            self.close(float(row["sd"]), float(np.std(values, ddof=1)), 1e-15, "SD over trials")
        table = describe(frame, "total_time_s", by="condition", unit="subject")
        for condition in ("H", "V"):
            means = np.array(list(self.subject_means("total_time_s", condition).values()))
            row = table[table.condition == condition].iloc[0]
            n = len(means)
            sd = float(np.std(means, ddof=1))
            self.assertEqual(int(row["n"]), n)
            self.close(float(row["mean"]), float(np.mean(means)), 1e-12, "mean of subject means")
            self.close(float(row["sd"]), sd, 1e-12, "SD over subjects")
            self.close(float(row["sem"]), sd / math.sqrt(n), 1e-12, "sem")
            self.close(float(row["ci95_low"]), float(np.mean(means)) - T975[n - 1] * sd / math.sqrt(n), 1e-9, "low")
            self.close(float(row["ci95_high"]), float(np.mean(means)) + T975[n - 1] * sd / math.sqrt(n), 1e-9, "high")

    def test_paired_comparison_against_numpy(self):
        try:
            from calligraphy.statistics import paired_comparison
            import pandas  # noqa: F401
        except ImportError as error:  # pragma: no cover
            self.skipTest(f"no pandas: {error}")
        a = self.subject_means("mean_deviation_m", "H")
        b = self.subject_means("mean_deviation_m", "V")
        diff = np.array([a[s] - b[s] for s in sorted(a)])
        n = len(diff)
        sd = float(np.std(diff, ddof=1))
        result = paired_comparison(self.frame(), "mean_deviation_m", "H", "V")
        self.assertEqual(result.n_subjects, n)
        self.assertEqual(result.df, n - 1)
        self.close(result.mean_difference, float(np.mean(diff)), 1e-15, "mean difference a - b")
        self.close(result.sd_difference, sd, 1e-15, "sd of the differences")
        self.close(result.t, float(np.mean(diff)) / (sd / math.sqrt(n)), 1e-9 * abs(result.t) + 1e-12, "t")
        self.close(result.ci95_low, float(np.mean(diff)) - T975[n - 1] * sd / math.sqrt(n), 1e-12, "low")
        self.close(result.ci95_high, float(np.mean(diff)) + T975[n - 1] * sd / math.sqrt(n), 1e-12, "high")
        self.close(result.d_z, float(np.mean(diff)) / sd, 1e-9, "d_z")
        sds = [float(np.std(list(m.values()), ddof=1)) for m in (a, b)]
        d_av = float(np.mean(diff)) / float(np.mean(sds))
        self.close(result.d_av, d_av, 1e-9, "d_av")
        self.close(result.g_av, d_av * (1 - 3 / (4 * (n - 1) - 1)), 1e-9, "g_av")
        self.close(result.mean_a, float(np.mean(list(a.values()))), 1e-15, "mean_a")


BETWEEN = {"name": "r14cb",
           "conditions": [{"name": "unguided", "mode": "vision"}, {"name": "fixture", "mode": "haptic"}],
           "phases": [{"phase": "pre-test", "condition": "unguided", "characters": [YI, SHI]},
                      {"phase": "training", "conditions": ["unguided", "fixture"],
                       "assignment": "between-subjects", "characters": [YI, SHI], "repetitions": 2},
                      {"phase": "post-test", "condition": "unguided", "characters": [YI, SHI]},
                      {"phase": "retention", "condition": "unguided", "characters": [YI, SHI], "session": 2,
                       "delay_s": 86400}],
           "trial": {"max_duration_s": 4}}


class BetweenSubjectsNumbers(Base):
    """A cohort of six in a pre-test, training between subjects, post-test design: the labels and the learning
    statistics against numpy."""

    @classmethod
    def setUpClass(cls):
        root = SHARED["root"] / "between"
        root.mkdir()
        (root / "p.json").write_text(json.dumps(BETWEEN, ensure_ascii=False), encoding="utf-8")
        (root / "tables").mkdir()
        result = run(["session", "cohort", "p.json", "--subjects", "6", "--csv", "tables", "--jobs", "1"], root)
        assert result.returncode == 0, result.stderr
        cls.trials = read_table(root / "tables" / "trials.csv")

    def test_groups_phases_blocks_and_items(self):
        self.assertEqual(len(self.trials), 6 * 10)
        for n in range(1, 7):
            subject = f"S{n:02d}"
            later = [r for r in self.trials if r["subject"] == subject and r["session_number"] == "2"]
            self.assertEqual([(r["phase"], r["block"], r["trial"], r["group"], r["session"]) for r in later],
                             [("retention", "1", "1", ["unguided", "fixture"][(n - 1) % 2], f"r14cb-{subject}-s2"),
                              ("retention", "1", "2", ["unguided", "fixture"][(n - 1) % 2], f"r14cb-{subject}-s2")])
            rows = sorted((r for r in self.trials if r["subject"] == subject and r["session_number"] == "1"),
                          key=lambda r: int(r["trial"]))
            group = ["unguided", "fixture"][(n - 1) % 2]  # subject n writes the ((n - 1) mod k)-th condition
            self.assertEqual({r["group"] for r in rows}, {group}, subject)
            self.assertEqual([r["phase"] for r in rows], ["pre-test"] * 2 + ["training"] * 4 + ["post-test"] * 2)
            self.assertEqual([r["condition"] for r in rows], ["unguided"] * 2 + [group] * 4 + ["unguided"] * 2)
            self.assertEqual([int(r["block"]) for r in rows], [1, 1, 2, 2, 2, 2, 3, 3])
            self.assertEqual([int(r["trial"]) for r in rows], list(range(1, 9)))
            self.assertEqual([int(r["item"]) for r in rows], [1, 2] * 4)
            self.assertEqual([int(r["repetition"]) for r in rows], [1, 1, 1, 1, 2, 2, 1, 1])

    def means(self, value, phase):
        out = {}
        for r in self.trials:
            if r["phase"] == phase and r[value] != "":
                out.setdefault(r["subject"], []).append(float(r[value]))
        return {k: float(np.mean(v)) for k, v in out.items()}

    def test_learning_and_group_comparison_against_numpy(self):
        try:
            import pandas
            from calligraphy.statistics import group_comparison, learning
            from scipy import stats
        except ImportError as error:  # pragma: no cover
            self.skipTest(f"no pandas or scipy: {error}")
        frame = pandas.DataFrame(self.trials)
        frame["total_time_s"] = [number(v) for v in frame["total_time_s"]]
        frame["repetition"] = frame["repetition"].astype(int)
        table = learning(frame, "total_time_s", pre="pre-test", post="post-test", retention="retention")
        pre, post = self.means("total_time_s", "pre-test"), self.means("total_time_s", "post-test")
        kept = self.means("total_time_s", "retention")
        for _, row in table.iterrows():
            subject = row["subject"]
            self.close(row["pre"], pre[subject], 1e-12, f"{subject} pre")
            self.close(row["post"], post[subject], 1e-12, f"{subject} post")
            self.close(row["gain"], pre[subject] - post[subject], 1e-12, f"{subject} gain = pre - post")
            self.close(row["relative_gain"], (pre[subject] - post[subject]) / pre[subject], 1e-12, "gain / pre")
            self.close(row["retention"], kept[subject], 1e-12, f"{subject} retention")
            self.assertEqual(row["group"], ["unguided", "fixture"][(int(subject[1:]) - 1) % 2])
            gain = pre[subject] - post[subject]
            if gain >= 0.05 * pre[subject]:  # min_relative_gain: a ratio only over a gain of 5 % of the pre-test
                self.close(row["retention_ratio"], (pre[subject] - kept[subject]) / gain, 1e-9, "retention ratio")
            else:
                self.assertTrue(math.isnan(row["retention_ratio"]), (subject, gain, row["retention_ratio"]))
        ratios = 0
        for _, row in learning(frame, "total_time_s", pre="pre-test", post="post-test", retention="retention",
                               min_relative_gain=0.0).iterrows():
            gain = pre[row["subject"]] - post[row["subject"]]
            if gain > 0:
                ratios += 1
                self.close(row["retention_ratio"], (pre[row["subject"]] - kept[row["subject"]]) / gain, 1e-9,
                           "retention ratio = (pre - retention) / (pre - post)")
            else:
                self.assertTrue(math.isnan(row["retention_ratio"]), (row["subject"], gain))
        self.assertGreater(ratios, 0, "some subject gained")
        result = group_comparison(table, "gain", "fixture", "unguided")
        a = np.array([pre[s] - post[s] for s in pre if int(s[1:]) % 2 == 0])
        b = np.array([pre[s] - post[s] for s in pre if int(s[1:]) % 2 == 1])
        va, vb = np.var(a, ddof=1) / len(a), np.var(b, ddof=1) / len(b)
        df = (va + vb) ** 2 / (va ** 2 / (len(a) - 1) + vb ** 2 / (len(b) - 1))
        diff = float(np.mean(a) - np.mean(b))
        half = float(stats.t.ppf(0.975, df) * math.sqrt(va + vb))
        pooled = math.sqrt(((len(a) - 1) * np.var(a, ddof=1) + (len(b) - 1) * np.var(b, ddof=1)) /
                           (len(a) + len(b) - 2))
        self.assertEqual((result.n_a, result.n_b), (len(a), len(b)))
        self.close(result.mean_difference, diff, 1e-12, "mean difference a - b")
        self.close(result.df, df, 1e-9, "Welch-Satterthwaite df")
        self.close(result.t, diff / math.sqrt(va + vb), 1e-9, "Welch t")
        self.close(result.ci95_low, diff - half, 1e-9, "Welch interval, low")
        self.close(result.ci95_high, diff + half, 1e-9, "Welch interval, high")
        self.close(result.g, diff / pooled * (1 - 3 / (4 * (len(a) + len(b)) - 9)), 1e-9, "Hedges' g")
        self.close(result.sd_a, float(np.std(a, ddof=1)), 1e-12, "sd_a")


QUIZ = {"name": "r14cq", "conditions": [{"name": "Q", "mode": "quiz"}],
        "test": {"characters": [YI, SHI, "人"], "conditions": ["Q"], "repetitions": 2},
        "trial": {"max_duration_s": 6}}


class QuizNumbers(Base):
    """A quiz condition's record: the quiz fed the recorded trace judges each pen lift by the matcher that gives
    the metrics record's verdicts, so its events, misses and accepted strokes are those verdicts."""

    @classmethod
    def setUpClass(cls):
        root = SHARED["root"] / "quiz"
        root.mkdir()
        (root / "p.json").write_text(json.dumps(QUIZ, ensure_ascii=False), encoding="utf-8")
        result = run(["session", "run", "p.json", "--subjects", "2", "--out", "st", "--writer-profile", "foreign"],
                     root)
        assert result.returncode == 0, result.stderr
        cls.root_ = root
        cls.records = [(path, json.loads(path.read_text(encoding="utf-8")))
                       for path in sorted(root.glob("st/*/*/trials/*.json"))]

    def test_quiz_events_are_the_segments_verdicts(self):
        self.assertEqual(len(self.records), 12)
        misses_seen = 0
        for path, record in self.records:
            quiz = record["quiz"]
            rows = None
            self.assertEqual(quiz["misses"], sum(record["refusals"].values()), path.name)
            self.assertEqual(quiz["strokes_accepted"], record["strokes_accepted"], path.name)
            misses_seen += quiz["misses"]
            for character, judged in zip(record["per_character"], quiz["characters"]):
                self.assertEqual(judged["character"], character["character"])
                events = [e for e in judged["events"] if e["kind"] in ("stroke_accepted", "stroke_missed", "too_short")]
                if rows is None:
                    trace = path.parent / record["files"]["trace"]
                    result = run(["trace", str(trace)], self.root_)
                    rows = list(csv.DictReader(io.StringIO(result.stdout.decode())))
                expected, misses, total = [], {}, 0
                for segment in character["segments"]:
                    verdict = segment["verdict"]
                    if segment["ignored"]:
                        kind, refusal, stroke = "too_short", "none", None
                    elif verdict is None:
                        break  # every stroke accepted: the quiz is over
                    elif verdict["accepted"]:
                        kind, refusal, stroke = "stroke_accepted", "none", verdict["expected_stroke"]
                    else:
                        kind, refusal, stroke = "stroke_missed", verdict["refusal"], verdict["expected_stroke"]
                        # A run the trace ends in, never lifted, is missed but no miss on its stroke (quiz.hpp).
                        if segment["end"] < len(rows):
                            misses[stroke] = misses.get(stroke, 0) + 1
                        total += 1
                    expected.append((kind, refusal, segment["end"] - segment["begin"], total, segment["end"] - 1,
                                     misses.get(stroke, 0) if kind == "stroke_missed" else None))
                got = [(e["kind"], e["refusal"], e["samples"], e["total_misses"], e["time_s"],
                        e["misses_on_stroke"] if e["kind"] == "stroke_missed" else None) for e in events]
                self.assertEqual(len(got), len(expected), (path.name, got, expected))
                for g, x in zip(got, expected):
                    self.assertEqual(g[:4], x[:4], path.name)
                    self.assertEqual(g[4], ns(Decimal(rows[x[4]]["t"])), (path.name, "the lift's time"))
                    self.assertEqual(g[5], x[5], path.name)
                hints = [e for e in judged["events"] if e["kind"] == "hint"]
                self.assertEqual(len(hints), sum(max(0, m - quiz["hint_after_misses"] + 1) for m in misses.values()))
        self.assertGreater(misses_seen, 0, "the foreign writer misses some strokes")

    def test_pages_show_the_quiz_misses(self):
        import html as html_module
        result = run(["report", "st", "--out", "pages.html"], self.root_)
        self.assertEqual(result.returncode, 0, result.stderr)
        shown = {}
        for page in (self.root_ / "pages_files").glob("*/*.html"):
            for article in re.finditer(r'<article[^>]* id="trial-([^"]+)-(\d+)".*?</article>',
                                       page.read_text(encoding="utf-8"), re.S):
                body = re.sub(r"<svg.*?</svg>|<figcaption.*?</figcaption>", "", article.group(0), flags=re.S)
                shown[(article.group(1), int(article.group(2)))] = " ".join(
                    html_module.unescape(re.sub(r"<[^>]+>", " ", body)).split())
        for path, record in self.records:
            words = shown[(record["session"], int(path.name[:3]))]
            self.assertIn(f"quiz misses {record['quiz']['misses']}", words)


CROSSOVER = {"name": "r14cx",
             "conditions": [{"name": "unguided", "mode": "vision"}, {"name": "fixture", "mode": "haptic"}],
             "item_sets": [{"name": "set1", "characters": [YI]}, {"name": "set2", "characters": [SHI]}],
             "phases": [{"phase": "pre-test", "condition": "unguided", "sets": ["set1", "set2"]},
                        {"phase": "training", "conditions": ["unguided", "fixture"], "assignment": "crossover",
                         "sets": ["set1", "set2"]},
                        {"phase": "post-test", "condition": "unguided", "sets": ["set1", "set2"]}],
             "trial": {"max_duration_s": 3}}


class CrossoverLabels(Base):

    def test_crossover_labels_follow_the_documented_rule(self):
        root = SHARED["root"] / "crossover"
        root.mkdir()
        (root / "p.json").write_text(json.dumps(CROSSOVER, ensure_ascii=False), encoding="utf-8")
        (root / "tables").mkdir()
        result = run(["session", "cohort", "p.json", "--subjects", "4", "--csv", "tables", "--jobs", "1"], root)
        self.assertEqual(result.returncode, 0, result.stderr)
        trials = read_table(root / "tables" / "trials.csv")
        conditions, sets, items = ["unguided", "fixture"], ["set1", "set2"], {"set1": YI, "set2": SHI}
        square = [[0, 1], [1, 0]]  # the balanced Latin square of two conditions: rows = k = 2
        for n in range(1, 5):
            row = square[(n - 1) % 2]
            rotation = ((n - 1) // 2) % 2
            set_of = {i: sets[(i + rotation) % 2] for i in range(2)}  # listed condition i trains set (i + q) mod k
            period_of_set = {set_of[c]: p + 1 for p, c in enumerate(row)}
            condition_of_set = {set_of[i]: conditions[i] for i in range(2)}
            sequence = "".join("AB"[c] for c in row)
            rows = sorted((r for r in trials if r["subject"] == f"S{n:02d}"), key=lambda r: int(r["trial"]))
            self.assertEqual(len(rows), 6)
            for r in rows:
                item_set = [name for name, char in items.items() if char == r["characters"]][0]
                self.assertEqual((r["item_set"], r["sequence"], int(r["period"]), r["trained_condition"]),
                                 (item_set, sequence, period_of_set[item_set], condition_of_set[item_set]),
                                 (n, r["phase"], r["characters"]))
                self.assertEqual(int(r["item"]), sets.index(item_set) + 1)
            training = [r for r in rows if r["phase"] == "training"]
            self.assertEqual([(r["condition"], r["item_set"], r["block"]) for r in training],
                             [(conditions[c], set_of[c], str(2 + p)) for p, c in enumerate(row)])


if __name__ == "__main__":
    unittest.main(verbosity=2)
