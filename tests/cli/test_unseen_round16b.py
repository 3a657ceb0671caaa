#!/usr/bin/env python3
"""Round 16B: metamorphic cases written from the documentation alone (docs/metrics.md, docs/stroke-acceptance.md,
docs/cli.md "trial", "score", "report" and "Pen traces", docs/experiments.md "Tidy tables", docs/python.md
`score`, `Scene`, `match_stroke`, `simulate_trial` and `rerun_trial`, each command's `--help`): what must not
change when nothing that matters changes, and what changes in the known way when something does. Run by CTest
as `cli_unseen_round16b_tests`.

One trace of 十 is made with numpy from the data's medians (each stroke a minimum-jerk movement along its
median, 0.8 s a stroke, 0.3 s of pen-up movement between), then transformed: written in data units, its clock
moved by -1e3, 1e3 and 1e9 s or slowed twice, resampled at 60, 120, 1000 and 4000 Hz, every sample or some written
twice, its pen-up samples thinned or removed; the character laid out in a box of half and twice the size and
elsewhere on raised paper (Python's `Scene`), as the second of a row; a stroke reversed, written twice, another
stroke's path given for it, the character mirrored; `model` against Python in every layout, the character's
data file against the embedded character. Simulated trials of 一: the same seed twice, other seeds, other servo
rates, a record replayed at 250 Hz with the largest seed, Python against the command line, a trial without its
trace kept. A tiny study's `report --csv` twice, on 1 and 3 threads, of a copy, of the
folder renamed, of its sessions listed in another order and of a session folder named with a trailing slash,
`.` or a link; its trials run again from their records against `trace` of their saved traces, a saved trace
scored as HDF5 and as its CSV; `session cohort` on 1 and 2 threads.

Each case asserts the documented relation: the same verdicts, the same numbers to the last bit or within the
bound the definition gives (the discrete Frechet distance is a pseudo-metric: resampling a path moves it by at
most half the largest step), or the known change (times scaled, lengths scaled by size / 60 mm).
CALLIGRAPHY_CLI names the program, CALLIGRAPHY_SOURCE_DIR the source tree (its hanzi-writer-data sample).
CALLIGRAPHY_SANITIZED=1 takes five cases.
"""
import csv
import io
import json
import os
import shutil
import tempfile
import unittest
from pathlib import Path

import numpy as np

from outsider import run, sanitized_subset

SOURCE = Path(os.environ.get("CALLIGRAPHY_SOURCE_DIR", Path(__file__).resolve().parents[2]))
SAMPLE = SOURCE / "data" / "hanzi-writer-data"
SHI, YI = "十", "一"

load_tests = sanitized_subset({"test_data_units_score_as_metres",
                               "test_reversed_stroke_is_refused_backwards_with_the_same_shape_distances",
                               "test_same_seed_twice_is_the_same_trial_bit_for_bit",
                               "test_report_of_sessions_listed_in_another_order_is_the_same",
                               "test_report_of_a_session_folder_named_with_a_trailing_slash"})

try:
    import calligraphy
except ImportError:  # pragma: no cover - the Python cases are skipped, saying why
    calligraphy = None
needs_python = unittest.skipUnless(calligraphy, "the calligraphy Python module is not on PYTHONPATH")

# The standard layout (README.md, docs/python.md: 1024 data units, y up, in a 60 mm box; the character's frame,
# x 0..1024 and y -124..900, centred on the paper's origin: Placement origin (-0.03, -0.0227...) m).
UNIT_M = 0.06 / 1024.0
STROKE_S, GAP_S, LEAD_S = 0.8, 0.3, 0.1


def medians(char):
    return [np.asarray(m, dtype=float) for m in
            json.loads((SAMPLE / f"{char}.json").read_text(encoding="utf-8"))["medians"]]


def to_metres(points):
    points = np.asarray(points, dtype=float)
    return np.column_stack(((points[:, 0] - 512.0) * UNIT_M, (points[:, 1] - 388.0) * UNIT_M))


def to_data(points_m):
    points_m = np.asarray(points_m, dtype=float)
    return np.column_stack((points_m[:, 0] / UNIT_M + 512.0, points_m[:, 1] / UNIT_M + 388.0))


def along(poly, s):
    """Points at arc lengths `s` along the polyline `poly`."""
    cum = np.concatenate(([0.0], np.cumsum(np.hypot(*np.diff(poly, axis=0).T))))
    return np.column_stack((np.interp(s, cum, poly[:, 0]), np.interp(s, cum, poly[:, 1])))


def poly_length(poly):
    return float(np.hypot(*np.diff(poly, axis=0).T).sum())


def write_paths(paths, rate_hz=1000.0):
    """Columns t [s], xy (N, 2), pen of `paths` (each a polyline, in any unit) written one after the other:
    LEAD_S of pen-up approach, each path a minimum-jerk movement of STROKE_S along it, GAP_S of pen-up
    movement to the next, LEAD_S of pen-up lift. Sample times are whole ticks of `rate_hz`, so every rate
    that divides 0.1 s samples the pen's first and last contact at the same times."""
    ticks, points, pens = [], [], []
    lead, stroke, gap = (round(v * rate_hz) for v in (LEAD_S, STROKE_S, GAP_S))
    first, lift = paths[0][0], paths[-1][-1]
    start = first - 0.05 * (paths[0][-1] - first)  # the approach, along the first stroke's line
    away = lift + 0.05 * (paths[-1][-1] - paths[-1][0])  # the lift, on along the last
    for k in range(lead):
        ticks.append(k)
        points.append(start + (first - start) * k / lead)
        pens.append(0)
    tick = lead
    for i, poly in enumerate(paths):
        u = np.arange(stroke + 1) / stroke
        s = poly_length(poly) * (10 * u ** 3 - 15 * u ** 4 + 6 * u ** 5)
        for k, p in enumerate(along(poly, s)):
            ticks.append(tick + k)
            points.append(p)
            pens.append(1)
        tick += stroke
        if i + 1 < len(paths):
            for k in range(1, gap):
                ticks.append(tick + k)
                points.append(poly[-1] + (paths[i + 1][0] - poly[-1]) * k / gap)
                pens.append(0)
            tick += gap
    for k in range(1, lead + 1):
        ticks.append(tick + k)
        points.append(lift + (away - lift) * k / lead)
        pens.append(0)
    return np.asarray(ticks, dtype=float) / rate_hz, np.asarray(points), np.asarray(pens, dtype=int)


def csv_text(t, xy, pen, header=("t", "x", "y", "pen")):
    out = io.StringIO()
    out.write(",".join(header) + "\n")
    for ti, (x, y), p in zip(t, xy, pen):
        out.write(f"{float(ti)!r},{float(x)!r},{float(y)!r},{int(p)}\n")
    return out.getvalue()


def spatial(score, index=0):
    """What does not depend on the clock: verdicts, assignment and distances [m], per stroke too."""
    pc = score["per_character"][index]
    out = {k: pc[k] for k in ("strokes_accepted", "strokes_written", "backwards_strokes", "order_errors",
                              "unmatched_segments", "mean_deviation_m", "max_deviation_m", "rms_deviation_m",
                              "frechet_m", "dtw_m", "path_length_m", "completed_in_order")}
    out["refusals"] = pc["refusals"]
    out["per_stroke"] = [(s["written"], s["backwards"], s["mean_deviation_m"], s["max_deviation_m"],
                          s["rms_deviation_m"], s["frechet_m"], s["dtw_m"], s["path_length_m"])
                         for s in pc["per_stroke"]]
    out["verdicts"] = [(s["ignored"], s["matched_stroke"], s["verdict"] and s["verdict"]["refusal"])
                       for s in pc["segments"]]
    return out


TIMES = ("total_time_s", "pen_down_time_s", "in_air_time_s")


def times(score, index=0):
    pc = score["per_character"][index]
    return [pc[k] for k in TIMES] + [s["time_s"] for s in pc["per_stroke"]]


def verdicts(score, index=0):
    return spatial(score, index)["verdicts"]


class Round16B(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.dir = Path(tempfile.mkdtemp(prefix="calligraphy-r16b-"))
        cls.shi_data = medians(SHI)
        cls.shi_m = [to_metres(m) for m in cls.shi_data]
        cls.base = write_paths(cls.shi_m)
        cls.base_score = cls.score_columns("base", *cls.base)

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.dir, ignore_errors=True)

    @classmethod
    def score_file(cls, path, char=SHI, *options):
        result = run(["score", path, "--character", char, "--json", "-", *options], cls.dir)
        if result.returncode != 0:
            raise AssertionError(f"score {path} exited {result.returncode}: {result.stderr.decode()}")
        return json.loads(result.stdout)

    @classmethod
    def score_columns(cls, name, t, xy, pen, char=SHI, *options, header=("t", "x", "y", "pen")):
        path = cls.dir / f"{name}.csv"
        path.write_text(csv_text(t, xy, pen, header), encoding="utf-8")
        return cls.score_file(path, char, *options)

    def assertSpatialClose(self, got, want, atol, scale=1.0, msg=""):
        """Verdicts, counts and flags equal; every distance of `got` within `atol` [m] of `want` x `scale`."""
        for key, value in want.items():
            if key == "per_stroke":
                self.assertEqual(len(got[key]), len(value))
                for g, w in zip(got[key], value):
                    self.assertEqual(g[:2], w[:2], msg)
                    for a, b in zip(g[2:], w[2:]):
                        self.assertEqual(a is None, b is None, msg)
                        if a is not None:
                            self.assertLessEqual(abs(a - scale * b), atol, f"{msg} per stroke {g} vs {w}")
            elif isinstance(value, float):
                self.assertLessEqual(abs(got[key] - scale * value), atol, f"{msg} {key}: {got[key]} vs {value}")
            else:
                self.assertEqual(got[key], value, f"{msg} {key}")

    # -- the trace every other case transforms ------------------------------------------------------------

    def test_the_base_trace_writes_every_stroke_in_order(self):
        score = self.base_score
        self.assertEqual(score["strokes_accepted"], 2)
        self.assertTrue(score["completed_in_order"])
        self.assertEqual(score["per_character"][0]["pen_lifts"], 1)
        # on the data's median, within a millimetre of the fitted elements the deviation is measured from
        self.assertLess(score["max_deviation_m"], 1e-3)
        # minimum-jerk movements: one velocity peak a stroke (docs/metrics.md)
        self.assertEqual(score["velocity_peaks"], 2)
        self.assertAlmostEqual(score["total_time_s"], 2 * STROKE_S + GAP_S, places=9)
        self.assertAlmostEqual(score["pen_down_time_s"], 2 * STROKE_S, places=9)

    # -- units and clocks ---------------------------------------------------------------------------------

    def test_data_units_score_as_metres(self):
        t, _, pen = self.base
        xy_data = to_data(self.base[1])
        score = self.score_columns("data-units", t, xy_data, pen, SHI, "--units", "data")
        self.assertEqual(score["units"], "data")
        self.assertSpatialClose(spatial(score), spatial(self.base_score), atol=1e-12)
        self.assertEqual(times(score), times(self.base_score))

    @needs_python
    def test_python_and_the_cli_give_the_same_bits_in_metres_and_data_units(self):
        t, xy, pen = self.base
        path = self.dir / "base.csv"
        cli = self.score_file(path)
        for trace in (str(path), {"t": t, "x": xy[:, 0], "y": xy[:, 1], "pen": pen}):
            for character in (SHI, calligraphy.Scene(SHI)):  # by name: laid out as the default Scene
                py = calligraphy.score(trace, character)
                for key in cli:
                    if key != "trace":
                        self.assertEqual(py[key], cli[key], key)
        xy_data = to_data(xy)
        cli = self.score_columns("data-units-py", t, xy_data, pen, SHI, "--units", "data")
        py = calligraphy.score({"t": t, "x": xy_data[:, 0], "y": xy_data[:, 1], "pen": pen}, SHI, units="data")
        for key in cli:
            if key != "trace":
                self.assertEqual(py[key], cli[key], key)

    def test_clock_moved_by_1e3_s_changes_no_number(self):
        t, xy, pen = self.base
        score = self.score_columns("shift-1e3", t + 1e3, xy, pen)
        self.assertEqual(spatial(score), spatial(self.base_score))
        self.assertEqual(times(score), times(self.base_score))  # whole nanoseconds (docs/metrics.md)
        self.assertEqual(score["velocity_peaks"], self.base_score["velocity_peaks"])
        self.assertAlmostEqual(score["normalised_jerk"], self.base_score["normalised_jerk"], delta=1e-6)

    def test_clock_moved_by_1e9_s_keeps_space_and_times_within_the_doubles_resolution(self):
        t, xy, pen = self.base
        score = self.score_columns("shift-1e9", t + 1e9, xy, pen)
        self.assertEqual(spatial(score), spatial(self.base_score))
        # a double resolves 1.2e-7 s at 1e9 s: each difference of two stamps within 2.4e-7 s
        for got, want in zip(times(score), times(self.base_score)):
            self.assertLessEqual(abs(got - want), 2 * 2.4e-7 + 1e-9)
        self.assertEqual(score["velocity_peaks"], self.base_score["velocity_peaks"])

    def test_clock_before_its_origin_changes_no_number(self):
        # "a time is read as seconds whatever its origin" (docs/metrics.md): a logger's clock at -1000 s
        t, xy, pen = self.base
        score = self.score_columns("shift-minus-1e3", t - 1e3, xy, pen)
        self.assertEqual(spatial(score), spatial(self.base_score))
        self.assertEqual(times(score), times(self.base_score))
        self.assertEqual(score["velocity_peaks"], self.base_score["velocity_peaks"])

    def test_slower_clock_scales_the_times_and_nothing_spatial(self):
        t, xy, pen = self.base
        score = self.score_columns("slow", 2 * t, xy, pen)
        self.assertEqual(spatial(score), spatial(self.base_score))
        for got, want in zip(times(score), times(self.base_score)):
            self.assertAlmostEqual(got, 2 * want, delta=2e-9)
        got, want = score["per_character"][0], self.base_score["per_character"][0]
        self.assertAlmostEqual(got["mean_speed_m_s"], want["mean_speed_m_s"] / 2, delta=1e-12)
        for g, w in zip(got["per_stroke"], want["per_stroke"]):
            self.assertAlmostEqual(g["mean_speed_m_s"], w["mean_speed_m_s"] / 2, delta=1e-12)
        self.assertEqual(score["velocity_peaks"], self.base_score["velocity_peaks"])

    # -- resampling -----------------------------------------------------------------------------------------

    @classmethod
    def resampled(cls):
        if not hasattr(cls, "_resampled"):
            cls._resampled = {}
            for rate in (60.0, 120.0, 1000.0, 4000.0):
                columns = write_paths(cls.shi_m, rate)
                cls._resampled[rate] = (columns, cls.score_columns(f"rate-{rate:g}", *columns))
        return cls._resampled

    @staticmethod
    def largest_step(columns):
        t, xy, pen = columns
        down = pen == 1
        steps = np.hypot(*np.diff(xy, axis=0).T)
        return float(steps[down[1:] & down[:-1]].max())

    def test_resampled_at_60_to_4000_hz_gives_the_same_verdicts_and_times(self):
        runs = self.resampled()
        want = self.base_score
        for rate, (columns, score) in runs.items():
            self.assertEqual(verdicts(score), verdicts(want), rate)
            self.assertEqual(score["strokes_accepted"], 2, rate)
            # the pen's contacts begin and end on the same ticks at every rate: the same times to the ns
            self.assertEqual(times(score)[:3], times(want)[:3], rate)
            self.assertEqual(score["velocity_peaks"], 2, rate)

    def test_resampled_distances_stay_within_half_the_largest_step(self):
        runs = self.resampled()
        fine_columns, fine = runs[4000.0]
        # above 2,000 samples a stroke is resampled to 2,000 points by arc length (docs/metrics.md)
        fine_step = max(poly_length(m) / 1999 for m in self.shi_m)
        for rate, (columns, score) in runs.items():
            step = self.largest_step(columns)
            for g, w in zip(score["per_character"][0]["per_stroke"], fine["per_character"][0]["per_stroke"]):
                # the distance to the reference is 1-Lipschitz in the position: a sampled maximum misses the
                # path's by at most half a step; the discrete Frechet distance is a pseudo-metric, and a
                # polyline's vertices are within half a step of a denser sampling of it
                self.assertLessEqual(abs(g["max_deviation_m"] - w["max_deviation_m"]), step / 2 + 1e-12, rate)
                self.assertLessEqual(abs(g["frechet_m"] - w["frechet_m"]), (step + fine_step) / 2 + 1e-12, rate)
                # samples on the median's polyline cut its corners: never longer, a little shorter when sparse
                self.assertLessEqual(g["path_length_m"], w["path_length_m"] + 1e-9, rate)
                self.assertGreater(g["path_length_m"], 0.99 * w["path_length_m"], rate)
                self.assertLessEqual(abs(g["mean_deviation_m"] - w["mean_deviation_m"]),
                                     max(w["max_deviation_m"], 1e-4) * 0.25, rate)

    # -- samples written twice, pen-up samples removed -------------------------------------------------

    def test_every_sample_written_twice_changes_no_number(self):
        t, xy, pen = self.base
        score = self.score_columns("doubled", np.repeat(t, 2), np.repeat(xy, 2, axis=0), np.repeat(pen, 2))
        self.assertSpatialClose(spatial(score), spatial(self.base_score), atol=1e-15)
        self.assertEqual(times(score), times(self.base_score))
        self.assertEqual(score["velocity_peaks"], self.base_score["velocity_peaks"])
        self.assertEqual(score["samples"], 2 * self.base_score["samples"])

    def test_some_samples_written_twice_keep_the_verdicts_and_the_worst_cases(self):
        t, xy, pen = self.base
        rng = np.random.default_rng(16)
        repeat = np.where(rng.random(len(t)) < 0.2, 2, 1)
        score = self.score_columns("some-doubled", np.repeat(t, repeat), np.repeat(xy, repeat, axis=0),
                                   np.repeat(pen, repeat))
        got, want = spatial(score), spatial(self.base_score)
        self.assertEqual(got["verdicts"], want["verdicts"])
        self.assertEqual(times(score), times(self.base_score))
        # consecutive repeats are dropped for Frechet and DTW; the maximum and the path are the same points
        # (the scene's DTW is a mean weighted by sample counts, which the repeats do change)
        for key in ("max_deviation_m", "frechet_m", "path_length_m"):
            self.assertAlmostEqual(got[key], want[key], delta=1e-15, msg=key)
        for g, w in zip(got["per_stroke"], want["per_stroke"]):
            self.assertEqual(g[3], w[3])
            self.assertAlmostEqual(g[5], w[5], delta=1e-15)
            self.assertAlmostEqual(g[6], w[6], delta=1e-15)

    def test_pen_up_samples_thinned_to_one_a_gap_change_no_number(self):
        t, xy, pen = self.base
        keep = pen == 1
        keep |= np.concatenate(([False], (pen[1:] == 0) & (pen[:-1] == 1)))  # the first pen-up after a stroke
        score = self.score_columns("thinned", t[keep], xy[keep], pen[keep])
        self.assertEqual(spatial(score), spatial(self.base_score))
        self.assertEqual(times(score), times(self.base_score))
        self.assertEqual(score["per_character"][0]["pen_lifts"], 1)
        self.assertEqual(score["normalised_jerk"], self.base_score["normalised_jerk"])

    def test_pen_up_samples_all_removed_join_the_strokes_into_one_pen_down(self):
        # a segment is a maximal run of pen-down samples (docs/metrics.md): with no pen-up sample between them
        # the two strokes are one pen-down, one stroke at most is matched to it, and no lift is counted
        t, xy, pen = self.base
        keep = pen == 1
        score = self.score_columns("no-pen-up", t[keep], xy[keep], pen[keep])
        pc = score["per_character"][0]
        self.assertEqual(len(pc["segments"]), 1)
        self.assertEqual(pc["pen_lifts"], 0)
        self.assertLessEqual(score["strokes_written"], 1)
        self.assertFalse(score["completed_in_order"])
        self.assertAlmostEqual(score["total_time_s"], self.base_score["total_time_s"], delta=1e-9)

    # -- the box: its size, its place, a row ----------------------------------------------------------------

    @staticmethod
    def scene_paths(scene, char_index=0):
        return [np.asarray(s.median_m, dtype=float) for s in scene.characters[char_index].strokes]

    @needs_python
    def test_a_box_of_half_and_twice_the_size_scales_the_distances(self):
        want = spatial(calligraphy.score(dict(zip(("t", "x", "y", "pen"), self.columns_of(calligraphy.Scene(SHI)))),
                                         calligraphy.Scene(SHI)))
        for size in (0.03, 0.12):
            scene = calligraphy.Scene(SHI, layout=calligraphy.SceneLayout(character_size_m=size,
                                                                        spacing_m=1.1 * size))
            got = spatial(calligraphy.score(dict(zip(("t", "x", "y", "pen"), self.columns_of(scene))), scene))
            ratio = size / 0.06
            self.assertEqual(got["verdicts"], want["verdicts"], size)
            for key in ("mean_deviation_m", "max_deviation_m", "rms_deviation_m", "path_length_m"):
                self.assertAlmostEqual(got[key], ratio * want[key], delta=1e-9 * ratio, msg=(size, key))
            # the reference is resampled every 0.25 mm whatever the size: each Frechet within its half step
            self.assertLessEqual(abs(got["frechet_m"] - ratio * want["frechet_m"]), 0.125e-3 * (1 + ratio) + 1e-12)

    def columns_of(self, scene, char_index=0):
        t, xy, pen = write_paths(self.scene_paths(scene, char_index))
        return t, xy[:, 0], xy[:, 1], pen

    @needs_python
    def test_offsets_scaled_with_the_box_keep_their_verdicts(self):
        # every length of the acceptance scales by size / 60 mm (docs/stroke-acceptance.md): a stroke written
        # 2 mm beside itself in the 60 mm box is written 1 mm beside in a 30 mm box and 4 mm in a 120 mm box
        results, deviations = {}, {}
        for size in (0.03, 0.06, 0.12):
            scene = calligraphy.Scene(SHI, layout=calligraphy.SceneLayout(character_size_m=size,
                                                                        spacing_m=1.1 * size))
            for offset_mm in (2.0, 4.5):
                d = offset_mm * 1e-3 * size / 0.06
                path = self.scene_paths(scene)[0] + np.array([0.0, d])
                m = calligraphy.match_stroke(scene, 0, 0, path)
                results[(size, offset_mm)] = (m.accepted, str(m.refusal))
                deviations[(size, offset_mm)] = m.mean_deviation_m / (size / 0.06)
        for offset_mm in (2.0, 4.5):
            self.assertEqual({results[(s, offset_mm)] for s in (0.03, 0.06, 0.12)}, {results[(0.06, offset_mm)]},
                             offset_mm)
            for size in (0.03, 0.12) if results[(0.06, offset_mm)][0] else ():
                # the matcher reads a path in steps of 0.25 mm whatever the box (docs/python.md): the mean
                # distance per 60 mm within a micrometre, not to the bit
                self.assertAlmostEqual(deviations[(size, offset_mm)], deviations[(0.06, offset_mm)], delta=1e-6)
        self.assertTrue(results[(0.06, 2.0)][0])
        self.assertFalse(results[(0.06, 4.5)][0])

    @needs_python
    def test_another_place_on_raised_paper_changes_no_verdict_nor_distance(self):
        base_scene = calligraphy.Scene(SHI)
        t, x, y, pen = self.columns_of(base_scene)
        want = calligraphy.score({"t": t, "x": x, "y": y, "pen": pen}, base_scene)
        scene = calligraphy.Scene(SHI, layout=calligraphy.SceneLayout(centre_m=(0.12, -0.07), paper_z_m=0.03))
        t, x, y, pen = self.columns_of(scene)
        z = 0.03 + np.where(pen == 1, 0.0, 0.01)  # the height above the scene's paper
        got = calligraphy.score({"t": t, "x": x, "y": y, "z": z}, scene)
        self.assertSpatialClose(spatial(got), spatial(want), atol=1e-12)
        self.assertEqual(times(got), times(want))

    @needs_python
    def test_the_second_character_of_a_row_scores_as_it_does_alone(self):
        row = calligraphy.Scene(YI + SHI)
        paths = self.scene_paths(row, 0) + self.scene_paths(row, 1)
        t, xy, pen = write_paths(paths)
        cli_row = self.score_columns("row", t, xy, pen, YI + SHI)
        self.assertEqual(len(cli_row["per_character"]), 2)
        self.assertTrue(cli_row["completed_in_order"])
        alone_t, alone_xy, alone_pen = write_paths(self.scene_paths(calligraphy.Scene(SHI)))
        alone = self.score_columns("alone", alone_t, alone_xy, alone_pen)
        self.assertSpatialClose(spatial(cli_row, 1), spatial(alone), atol=1e-12)

    @needs_python
    def test_the_model_is_one_in_the_cli_python_and_every_layout(self):
        made = [run(["model", SHI, "--json", *extra], self.dir) for extra in ((), ("--data", SAMPLE))]
        for result in made:
            self.assertEqual(result.returncode, 0, result.stderr.decode())
        self.assertEqual(made[0].stdout, made[1].stdout)  # the embedded 十 is its data file's, fitted alike
        model = json.loads(made[0].stdout)
        character = calligraphy.CharacterLibrary.default().load(SHI)
        for stroke, py in zip(model["strokes"], character.strokes):
            for element, py_element in zip(stroke["elements"], py.elements):
                self.assertEqual(np.asarray(element["control_points"]).tolist(),
                                 py_element.control_points.tolist())
        # placed: the data units' elements through the placement, in the standard box and in another
        for layout in (calligraphy.SceneLayout(), calligraphy.SceneLayout(character_size_m=0.09, spacing_m=0.1,
                                                                         centre_m=(0.05, 0.02))):
            placed = calligraphy.Scene(SHI, layout=layout).characters[0]
            for stroke, py in zip(placed.strokes, character.strokes):
                for element, py_element in zip(stroke.elements, py.elements):
                    want = placed.placement.to_paper(py_element.control_points)
                    self.assertLessEqual(np.abs(element.control_points - want).max(), 1e-15)

    # -- direction, repetition, another stroke, a mirror ---------------------------------------------------

    def test_reversed_stroke_is_refused_backwards_with_the_same_shape_distances(self):
        forward = write_paths([self.shi_m[0]])
        backward = write_paths([self.shi_m[0][::-1]])
        f = self.score_columns("horizontal-forward", *forward)
        b = self.score_columns("horizontal-backward", *backward)
        fs, bs = f["per_character"][0]["per_stroke"][0], b["per_character"][0]["per_stroke"][0]
        self.assertEqual((fs["written"], fs["backwards"]), (True, False))
        self.assertEqual((bs["written"], bs["backwards"]), (True, True))
        self.assertEqual((b["backwards_strokes"], b["strokes_accepted"], b["refusals"]["backwards"]), (1, 0, 1))
        self.assertEqual(b["per_character"][0]["segments"][0]["verdict"]["refusal"], "backwards")
        # Frechet and DTW against the reference traversed from its end: the same shape, the same distances
        for key in ("mean_deviation_m", "max_deviation_m", "rms_deviation_m", "frechet_m", "dtw_m",
                    "path_length_m"):
            self.assertAlmostEqual(bs[key], fs[key], delta=1e-12, msg=key)

    @needs_python
    def test_match_stroke_gives_the_verdicts_score_gives_forward_and_reversed(self):
        scene = calligraphy.Scene(SHI)
        paths = self.scene_paths(scene)
        for index, path in enumerate(paths):
            # the strokes before `index` taken as written (docs/python.md)
            forward = calligraphy.match_stroke(scene, 0, index, path)
            backward = calligraphy.match_stroke(scene, 0, index, path[::-1])
            self.assertTrue(forward.accepted, index)
            self.assertFalse(backward.accepted, index)
            self.assertEqual(backward.refusal, calligraphy.StrokeRefusal.backwards, index)
        # score's verdict on each segment is match_stroke's on it with the stroke then due
        t, xy, pen = write_paths([paths[0], paths[1][::-1]])
        refusals = [s["verdict"]["refusal"] for s in calligraphy.score(
            {"t": t, "x": xy[:, 0], "y": xy[:, 1], "pen": pen}, scene)["per_character"][0]["segments"]]
        self.assertEqual(refusals, ["none", "backwards"])

    def test_a_stroke_written_twice_is_credited_once(self):
        first, second = self.shi_m
        score = self.score_columns("twice", *write_paths([first, first, second]))
        pc = score["per_character"][0]
        self.assertEqual(score["strokes_written"], 2)
        self.assertEqual(score["strokes_accepted"], 2)
        self.assertEqual(score["unmatched_segments"], 1)
        self.assertEqual(score["refusals"]["wrong_stroke"], 1)
        self.assertEqual([s["verdict"]["refusal"] for s in pc["segments"]], ["none", "wrong_stroke", "none"])
        self.assertTrue(score["completed_in_order"])
        # the stroke's distances are those of one of its two identical copies: the single writing's
        for g, w in zip(pc["per_stroke"], self.base_score["per_character"][0]["per_stroke"]):
            self.assertAlmostEqual(g["mean_deviation_m"], w["mean_deviation_m"], delta=1e-15)
        # after every stroke is accepted, another writing of it gets no verdict
        score = self.score_columns("all-then-again", *write_paths([first, second, second]))
        self.assertEqual(score["strokes_accepted"], 2)
        self.assertIsNone(score["per_character"][0]["segments"][2]["verdict"])

    @needs_python
    def test_another_strokes_path_is_never_credited(self):
        scene = calligraphy.Scene(SHI)
        first, second = self.scene_paths(scene)
        late = calligraphy.match_stroke(scene, 0, 0, second)  # the second stroke written first
        again = calligraphy.match_stroke(scene, 0, 1, first)  # the first written again when the second is due
        self.assertEqual((late.accepted, late.refusal, late.matched_stroke),
                         (False, calligraphy.StrokeRefusal.wrong_order, 1))
        self.assertEqual((again.accepted, again.refusal), (False, calligraphy.StrokeRefusal.wrong_stroke))
        score = self.score_columns("second-only", *write_paths([self.shi_m[1]]))
        self.assertEqual(score["strokes_accepted"], 0)
        self.assertEqual(score["per_character"][0]["segments"][0]["verdict"]["refusal"], "wrong_order")
        self.assertFalse(score["completed_in_order"])

    def test_mirrored_character_writes_its_horizontal_backwards(self):
        # 十 mirrored left to right: the vertical stays a vertical, the horizontal runs from right to left
        mirrored = [np.column_stack((-m[:, 0], m[:, 1])) for m in self.shi_m]  # the box is centred on x = 0
        score = self.score_columns("mirrored", *write_paths(mirrored))
        self.assertEqual(score["strokes_written"], 2)
        self.assertEqual(score["backwards_strokes"], 1)
        self.assertEqual(score["per_character"][0]["segments"][0]["verdict"]["refusal"], "backwards")
        self.assertEqual(score["strokes_accepted"], 0)
        # the horizontal written in its own direction again: the mirror image scores as the character
        score = self.score_columns("mirrored-turned", *write_paths([mirrored[0][::-1], mirrored[1]]))
        self.assertEqual(verdicts(score), verdicts(self.base_score))
        self.assertTrue(score["completed_in_order"])
        # the distances of the horizontal are those of the reference mirrored: within its asymmetry, which is
        # below the largest deviation of the original (its median points are the same numbers mirrored)
        self.assertLess(score["per_character"][0]["per_stroke"][0]["mean_deviation_m"], 3e-3)

    # -- simulated trials ----------------------------------------------------------------------------------

    def trial(self, name, *options, char=YI):
        json_path, csv_path = self.dir / f"{name}.json", self.dir / f"{name}.csv"
        result = run(["trial", char, "--writer-profile", "skilled", "--max-duration", "6", *options,
                      "--json", json_path, "--csv", csv_path], self.dir)
        self.assertIn(result.returncode, (0, 1), result.stderr.decode())
        return json_path, csv_path

    def test_same_seed_twice_is_the_same_trial_bit_for_bit(self):
        a = self.trial("seed5-a", "--seed", "5")
        b = self.trial("seed5-b", "--seed", "5")
        self.assertEqual(a[1].read_bytes(), b[1].read_bytes())
        self.assertEqual(a[0].read_bytes(), b[0].read_bytes())

    def test_other_seeds_of_one_writer_write_other_traces_with_the_same_verdict(self):
        traces, deviations = set(), set()
        for seed in range(1, 5):
            json_path, csv_path = self.trial(f"seed{seed}", "--seed", str(seed))
            record = json.loads(json_path.read_text(encoding="utf-8"))
            self.assertEqual(record["end_reason"], "completed", seed)
            self.assertTrue(record["completed_in_order"], seed)
            traces.add(csv_path.read_bytes())
            deviations.add(record["mean_deviation_m"])
        self.assertEqual(len(traces), 4)
        self.assertGreater(len(deviations), 1)

    def test_a_record_at_250_hz_with_the_largest_seed_replays_bit_for_bit(self):
        json_path, csv_path = self.trial("odd", "--seed", str(2 ** 64 - 1), "--rate", "250")
        again = self.dir / "odd-again.csv"
        result = run(["trial", "--spec", json_path, "--csv", again], self.dir)
        self.assertIn(result.returncode, (0, 1), result.stderr.decode())
        self.assertEqual(again.read_bytes(), csv_path.read_bytes())
        rows = list(csv.reader(io.StringIO(csv_path.read_text(encoding="utf-8"))))
        self.assertEqual([float(r[0]) for r in rows[1:4]], [0.0, 0.004, 0.008])
        record = json.loads(json_path.read_text(encoding="utf-8"))
        self.assertEqual(record["seed"], 2 ** 64 - 1)
        self.assertEqual(record["rate_hz"], 250)

    def test_other_servo_rates_complete_and_score_as_their_own_trace(self):
        for rate in ("250", "4000"):
            json_path, csv_path = self.trial(f"rate{rate}", "--seed", "3", "--rate", rate)
            record = json.loads(json_path.read_text(encoding="utf-8"))
            self.assertEqual(record["end_reason"], "completed", rate)
            scored = self.score_file(csv_path, YI)
            for key in ("strokes_accepted", "strokes_written", "completed_in_order", "order_errors"):
                self.assertEqual(scored[key], record[key], (rate, key))
            # the trace is written to 1 us and 0.1 um: the score of it within that of the record
            for key in ("mean_deviation_m", "max_deviation_m", "frechet_m", "dtw_m"):
                self.assertAlmostEqual(scored[key], record[key], delta=1e-6, msg=(rate, key))
            # and moved by 1e3 s on its clock, the same score again
            rows = csv_path.read_text(encoding="utf-8").splitlines()
            moved = [rows[0]] + [f"{float(r.split(',', 1)[0]) + 1e3!r},{r.split(',', 1)[1]}" for r in rows[1:]]
            moved_path = self.dir / f"rate{rate}-moved.csv"
            moved_path.write_text("\n".join(moved) + "\n", encoding="utf-8")
            self.assertEqual(spatial(self.score_file(moved_path, YI)), spatial(scored))

    @needs_python
    def test_python_simulate_trial_is_the_cli_trial(self):
        json_path, csv_path = self.trial("py-seed7", "--seed", "7")
        record = json.loads(json_path.read_text(encoding="utf-8"))
        result = calligraphy.simulate_trial(YI, writer="skilled", seed=7, max_duration_s=6.0,
                                            library=calligraphy.CharacterLibrary.default())
        for row in calligraphy.metric_table():
            name = row["name"] if isinstance(row, dict) else row.name
            if name in record:
                self.assertEqual(result.metrics[name], record[name], name)
        rows = np.loadtxt(csv_path, delimiter=",", skiprows=1, usecols=(0, 1, 2, 3))
        self.assertEqual(len(rows), len(result.time_s))
        self.assertLessEqual(np.abs(rows[:, 0] - result.time_s).max(), 0.5e-6 + 1e-12)
        self.assertLessEqual(np.abs(rows[:, 1:4] - result.position_m).max(), 0.05e-6 + 1e-12)
        again = calligraphy.rerun_trial(str(json_path), library=calligraphy.CharacterLibrary.default())
        self.assertTrue(np.array_equal(again.position_m, result.position_m))
        self.assertTrue(np.array_equal(again.time_s, result.time_s))

    @needs_python
    def test_a_trial_without_its_trace_kept_has_the_same_metrics(self):
        # keep_trace=False: "empty arrays; the metrics are still taken from the trace" (docs/python.md)
        kept = calligraphy.simulate_trial(YI, writer="skilled", seed=11, max_duration_s=6.0,
                                          library=calligraphy.CharacterLibrary.default())
        dropped = calligraphy.simulate_trial(YI, writer="skilled", seed=11, max_duration_s=6.0, keep_trace=False,
                                             library=calligraphy.CharacterLibrary.default())
        self.assertEqual(len(dropped.time_s), 0)
        self.assertEqual(dict(dropped.metrics), dict(kept.metrics))

    def test_the_character_from_its_data_file_scores_as_the_embedded_one(self):
        path = self.dir / "base.csv"
        got = self.score_file(path, SHI, "--data", SAMPLE)
        self.assertEqual({k: v for k, v in got.items() if k != "trace"},
                         {k: v for k, v in self.base_score.items() if k != "trace"})

    # -- a study's tables ----------------------------------------------------------------------------------

    @classmethod
    def study(cls):
        if not hasattr(cls, "_study"):
            protocol = {"format": "calligraphy-study-protocol", "version": 1, "name": "meta",
                        "conditions": [{"name": "h", "mode": "haptic"}, {"name": "v", "mode": "vision"}],
                        "test": {"characters": [YI], "conditions": ["h", "v"], "repetitions": 1},
                        "trial": {"max_duration_s": 4}}
            (cls.dir / "p.json").write_text(json.dumps(protocol), encoding="utf-8")
            made = run(["session", "run", "p.json", "--subjects", "2", "--writer-profile", "skilled", "--out",
                        "study"], cls.dir)
            if made.returncode != 0:
                raise AssertionError(made.stderr.decode())
            cls._study = cls.dir / "study"
        return cls._study

    def report(self, name, *arguments, cwd=None):
        tables = self.dir / name
        tables.mkdir()
        result = run(["report", *arguments, "--csv", tables], cwd or self.dir)
        self.assertEqual(result.returncode, 0, result.stderr.decode())
        return (tables / "trials.csv").read_bytes(), (tables / "strokes.csv").read_bytes()

    def test_report_twice_is_byte_for_byte(self):
        self.study()
        self.assertEqual(self.report("tables-1", "study"), self.report("tables-2", "study"))

    def test_report_and_cohort_tables_do_not_depend_on_their_threads(self):
        self.study()
        one = self.report("tables-jobs-1", "study", "--jobs", "1")
        self.assertEqual(one, self.report("tables-jobs-3", "study", "--jobs", "3"))
        tables = []
        for jobs in ("1", "2"):
            out = self.dir / f"cohort-jobs-{jobs}"
            out.mkdir()
            result = run(["session", "cohort", "p.json", "--subjects", "3", "--writer-profile", "skilled",
                          "--jobs", jobs, "--csv", out], self.dir)
            self.assertEqual(result.returncode, 0, result.stderr.decode())
            tables.append(((out / "trials.csv").read_bytes(), (out / "strokes.csv").read_bytes()))
        self.assertEqual(tables[0], tables[1])  # "the tables do not depend on it" (docs/cli.md)

    def test_a_saved_trial_run_again_writes_its_saved_trace(self):
        # `trace` writes a saved trace as `trial --csv` of that trial would have; `trial --spec` of its record
        # runs that trial again, bit for bit on the simulated device (docs/cli.md)
        study = self.study()
        for record in sorted(study.glob("S0*/*/trials/*.json")):
            again = self.dir / f"again-{record.parent.parent.name}-{record.stem}.csv"
            result = run(["trial", "--spec", record, "--csv", again], self.dir)
            self.assertIn(result.returncode, (0, 1), result.stderr.decode())
            saved = run(["trace", record.with_name(record.stem + ".trace.h5"), "--csv", "-"], self.dir)
            self.assertEqual(saved.returncode, 0, saved.stderr.decode())
            self.assertEqual(again.read_bytes(), saved.stdout, record)

    def test_a_saved_trace_scores_alike_as_hdf5_and_as_its_csv(self):
        # `score` reads a session's .trace.h5 by its columns; `trace` writes it as the CSV `trial --csv` writes
        study = self.study()
        trace = sorted(study.glob("S01/*/trials/*.trace.h5"))[0]
        exported = self.dir / "exported.csv"
        self.assertEqual(run(["trace", trace, "--csv", exported], self.dir).returncode, 0)
        from_h5 = self.score_file(trace, YI)
        from_csv = self.score_file(exported, YI)
        self.assertEqual({k: v for k, v in from_h5.items() if k != "trace"},
                         {k: v for k, v in from_csv.items() if k != "trace"})

    def test_report_of_a_copy_differs_only_in_the_trace_paths(self):
        self.study()
        want = self.report("tables-orig", "study")
        shutil.copytree(self.dir / "study", self.dir / "study-copy", symlinks=True)
        got = self.report("tables-copy", "study-copy")
        self.assertEqual(got[1], want[1])
        self.assertEqual(got[0].replace(b"study-copy/", b"study/"), want[0])
        shutil.rmtree(self.dir / "study-copy")

    def test_report_of_the_folder_renamed_and_named_absolutely(self):
        self.study()
        want = self.report("tables-before-rename", "study")
        (self.dir / "study").rename(self.dir / "renamed")
        try:
            got = self.report("tables-renamed", "renamed")
            absolute = self.report("tables-absolute", str(self.dir / "renamed"))
        finally:
            (self.dir / "renamed").rename(self.dir / "study")
        self.assertEqual(got[1], want[1])
        self.assertEqual(got[0].replace(b"renamed/", b"study/"), want[0])
        self.assertEqual(absolute[0].replace(str(self.dir / "renamed").encode() + b"/", b"study/"), want[0])

    def test_report_of_sessions_listed_in_another_order_is_the_same(self):
        study = self.study()
        subjects = sorted(p.name for p in study.iterdir() if p.is_dir())
        self.assertEqual(len(subjects), 2)
        one = self.report("tables-order-1", *(f"study/{s}" for s in subjects))
        other = self.report("tables-order-2", *(f"study/{s}" for s in reversed(subjects)))
        self.assertEqual(one, other)
        self.assertEqual(one, self.report("tables-order-whole", "study"))
        if calligraphy is not None:
            import calligraphy.study as study_module
            frames = [study_module.load([str(self.dir / "study" / s) for s in order]).trials
                      for order in (subjects, subjects[::-1])]
            self.assertEqual(list(frames[0]["session"]), list(frames[1]["session"]))

    def test_report_of_a_session_folder_named_with_a_trailing_slash(self):
        # a shell's completion ends a folder's name with "/": the session is still the folder's own, and so it
        # is named ".", "x/." or through a link given on the command line (docs/cli.md, "report")
        study = self.study()
        session = sorted((study / "S01").iterdir())[0]
        name = f"study/S01/{session.name}"
        want = self.report("tables-session", name)
        self.assertEqual(self.report("tables-session-slash", name + "/"), want)
        self.assertEqual(self.report("tables-session-slash-dot", name + "/.")[1], want[1])
        self.assertEqual(self.report("tables-session-here", ".", cwd=session)[1], want[1])
        link = self.dir / "a-link"
        link.symlink_to(session)
        try:
            self.assertEqual(self.report("tables-session-link", "a-link")[1], want[1])
            if calligraphy is not None:
                import calligraphy.study as study_module
                names = [name, name + "/", name + "/.", "a-link"]
                frames = [study_module.load(str(self.dir / n)).trials for n in names]
                for n, frame in zip(names[1:], frames[1:]):
                    self.assertEqual(list(frame["session"]), list(frames[0]["session"]), n)
        finally:
            link.unlink()


if __name__ == "__main__":
    unittest.main()
