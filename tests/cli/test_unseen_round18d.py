#!/usr/bin/env python3
"""Round 18D: a device that misbehaves, from the docs alone (docs/devices.md, docs/servo-loop.md,
docs/force-rendering.md, docs/cli.md's `trial --device`, docs/python.md's devices and Renderer, and the stand-in
libHD's own README, tests/hd_stand_in/README.md, for the faults it can inject). Run by CTest as
`cli_unseen_round18d_tests`.

What the hardware reports is forged three ways. `calligraphy trial --device openhaptics` on the stand-in libHD
whose hand plays back a path given in its environment (HD_STAND_IN_PATH): a NaN, an infinite and a 20 m reading
mid-trial, NaN from the first tick and flickering every other tick, a leap of 5 m in one tick, a pen frozen 4 mm
into the paper (and its record re-run with a short continuous-force time constant). Python's `run_trial` on the
stand-in driven through its control API (one interpreter runs every scenario once, the cases read its findings):
the link lost once and restored ten ticks later, dead from the first tick, frames late under the watchdog, a
square wave of 20 m and of 5 m on the pen, the driver's clock set back and leaping, the buttons stuck and the
stylus docked mid-trial, the scheduler full at open; the stand-in's frame log says what force reached the motors
each tick. A Python `Renderer` ticked by hand with time stamps that repeat, go backwards, leap and are not finite,
a velocity that is NaN; the simulated device given a NaN force and told to advance back in time.

Each case holds what the docs promise: a device state that is not finite or past 10 m gives zero force
(`input_rejected`) and the trial goes on; a fault code ends the trial `device_fault` with every tick before it
kept, zero force commanded from then on (a link that comes back brings no force back) and the device released;
a late tick under the watchdog is counted and the trial goes on; the Touch's peak (3.3 N), the per-tick change
(0.25 N) and the continuous force hold in the recorded forces and in those the motors got; exit 1 for a trial
that ended early; every tick in the trace; no crash, no hang. CALLIGRAPHY_CLI names the program,
CALLIGRAPHY_HD_STAND_IN the stand-in (the cases that need it are skipped, saying so, without it),
CALLIGRAPHY_PYTHON_HD_STAND_IN the stand-in as the Python module was built. CALLIGRAPHY_SANITIZED=1 takes five
cases.
"""
import csv
import json
import math
import os
import subprocess
import sys
import tempfile
import textwrap
import unittest
from pathlib import Path

import numpy as np

import calligraphy as cg
from outsider import ENV, TIMEOUT_S, run, sanitized_subset

STAND_IN = os.environ.get("CALLIGRAPHY_HD_STAND_IN", "")
PYTHON_STAND_IN = os.environ.get("CALLIGRAPHY_PYTHON_HD_STAND_IN", "") or STAND_IN
YI = "一"
PEAK_N = 3.3  # the Touch's nominal peak force (docs/devices.md), which the stand-in reports
CONTINUOUS_N = 0.88
STEP_N = 0.25  # docs/force-rendering.md: max_force_change_n_per_tick
EPS = 1e-6

load_tests = sanitized_subset({"test_renderer_time_stamp_that_is_not_finite_gives_zero_force",
                               "test_renderer_time_stamps_that_repeat_or_go_backwards_keep_the_limits",
                               "test_simulated_device_time_sent_back_or_not_finite_is_refused_naming_dt",
                               "test_simulated_device_given_a_nan_force_keeps_a_finite_pen",
                               "test_safety_limits_of_a_trial_hold_in_its_recorded_forces"})


def need_stand_in(test):
    return unittest.skipUnless(STAND_IN and Path(STAND_IN).exists(),
                               "no stand-in libHD (CALLIGRAPHY_HD_STAND_IN)")(test)


def hd_mm(x, y, z):
    """HDAPI's frame (x right, y up, z towards the user; mm) from the library's (x right, y away, z up; m)."""
    return 1000.0 * x, 1000.0 * z, -1000.0 * y


def read_trace(path):
    with open(path, newline="") as handle:
        rows = list(csv.DictReader(handle))
    return rows


def strict_json(text):
    def refuse(name):
        raise ValueError(f"{name} in a JSON document")
    return json.loads(text, parse_constant=refuse)


def largest_step_but_to_zero(f):
    """The largest per-tick change of the forces `f` (N x 3), a change to exactly zero left out: the non-finite
    check and a trial's end step the force to zero, the one step docs/force-rendering.md allows."""
    f = np.asarray(f, dtype=float).reshape(-1, 3)
    steps = np.linalg.norm(np.diff(f, axis=0), axis=1)
    to_zero = ~f[1:].any(axis=1)
    return float(steps[~to_zero].max(initial=0.0))


def forces(rows):
    return np.array([[float(r["fx"]), float(r["fy"]), float(r["fz"])] for r in rows]).reshape(-1, 3)


# ---- the stand-in from Python: every scenario once, in one interpreter --------------------------------------
SCENARIOS = textwrap.dedent("""
    import ctypes, json, math, os, sys
    os.environ["CALLIGRAPHY_LIBHD"] = sys.argv[1]
    hd = ctypes.CDLL(sys.argv[1])  # the library the backend loads: one instance

    class Frame(ctypes.Structure):
        _fields_ = [("tick", ctypes.c_long), ("device_time_s", ctypes.c_double),
                    ("position_mm", ctypes.c_double * 3), ("velocity_mm_s", ctypes.c_double * 3),
                    ("buttons", ctypes.c_int), ("inkwell_switch", ctypes.c_int), ("frames", ctypes.c_int),
                    ("position_read", ctypes.c_int), ("force_set", ctypes.c_int),
                    ("force_set_n", ctypes.c_double * 3), ("force_output", ctypes.c_int),
                    ("force_output_n", ctypes.c_double * 3), ("first_error", ctypes.c_uint),
                    ("error_count", ctypes.c_int), ("late_us", ctypes.c_long)]

    hd.hd_stand_in_inject.argtypes = [ctypes.c_int, ctypes.c_long, ctypes.c_double]
    hd.hd_stand_in_set_path.argtypes = [ctypes.POINTER(ctypes.c_double), ctypes.POINTER(ctypes.c_double),
                                        ctypes.c_size_t]
    hd.hd_stand_in_set_square_wave.argtypes = [ctypes.c_int, ctypes.c_double, ctypes.c_int]
    hd.hd_stand_in_frame.argtypes = [ctypes.c_size_t, ctypes.POINTER(Frame)]
    hd.hd_stand_in_frame_count.restype = ctypes.c_size_t
    hd.hd_stand_in_frame_first.restype = ctypes.c_size_t
    import calligraphy as cg

    PEN = (-10.0, -4.0, 0.0)  # HDAPI mm: 4 mm below the paper, 10 mm left of the centre

    def hold(point):
        t = (ctypes.c_double * 1)(0.0)
        xyz = (ctypes.c_double * 3)(*point)
        assert hd.hd_stand_in_set_path(t, xyz, 1) == 0

    def frames():
        out, f = [], Frame()
        for i in range(hd.hd_stand_in_frame_first(), hd.hd_stand_in_frame_count()):
            if hd.hd_stand_in_frame(i, ctypes.byref(f)):
                out.append({"tick": f.tick, "t": f.device_time_s, "out": f.force_output,
                            "force_out": list(f.force_output_n), "set": f.force_set,
                            "force_set": list(f.force_set_n), "late_us": f.late_us,
                            "position_mm": list(f.position_mm)})
        return out

    def scenario(setup, duration=0.4, **kw):
        assert hd.hd_stand_in_reset() == 0
        hold(PEN)
        setup()
        got = {}
        try:
            # A stall bound far above the injected ones (docs/python.md, watchdog_s): a loaded machine that
            # holds the stand-in's scheduler back for 50 ms must not end a trial that tests something else.
            r = cg.run_trial("一", device="openhaptics", max_duration_s=duration, watchdog_s=5.0, **kw)
        except Exception as e:
            got["error"] = [type(e).__name__, [c.__name__ for c in type(e).__mro__], str(e)]
        else:
            m = r.metrics
            got.update(end_reason=m["end_reason"], aborted=m["aborted"], abort_reason=m["abort_reason"],
                       loop=m["loop"], ticks=len(r.time_s), start=m["device_time_at_start_s"],
                       time=[float(t) for t in r.time_s], force=[[float(v) for v in f] for f in r.force_n],
                       position_finite=bool(all(math.isfinite(float(v)) for p in r.position_m for v in p)))
        got["frames"] = frames()
        got["running"] = hd.hd_stand_in_scheduler_running()
        got["initialised"] = hd.hd_stand_in_device_initialized()
        return got

    results = {}
    results["link_blip"] = scenario(lambda: (hd.hd_stand_in_inject(1, 200, 0), hd.hd_stand_in_inject(7, 210, 0)))
    results["late"] = scenario(lambda: [hd.hd_stand_in_inject(4, t, 20) for t in (150, 250, 330)])
    results["far"] = scenario(lambda: hd.hd_stand_in_set_square_wave(0, 20000.0, 60))
    results["leap"] = scenario(lambda: hd.hd_stand_in_set_square_wave(1, 5000.0, 60))
    results["buttons"] = scenario(lambda: (hd.hd_stand_in_set_buttons(3), hd.hd_stand_in_set_docked(1)))
    results["full"] = scenario(lambda: hd.hd_stand_in_inject(3, 0, 1000))
    results["dead_from_start"] = scenario(lambda: hd.hd_stand_in_inject(1, 0, 0))
    results["force_limit_once"] = scenario(lambda: hd.hd_stand_in_inject(2, 200, 0))
    hd.hd_stand_in_set_clock_offset.argtypes = [ctypes.c_double]
    hd.hd_stand_in_wait_ticks.argtypes = [ctypes.c_long, ctypes.c_double]

    def clock_jumps(offsets):
        # the device's clock set back and forth while the trial runs (the GIL is released during it)
        import threading

        def jump():
            for k, offset in enumerate(offsets):
                hd.hd_stand_in_wait_ticks(150 + 50 * k, 5.0)
                hd.hd_stand_in_set_clock_offset(offset)
        threading.Thread(target=jump, daemon=True).start()
    results["clock"] = scenario(lambda: clock_jumps([1500.0, 1500.0, 1e7, 1600.0]))
    hd.hd_stand_in_reset()
    print(json.dumps(results))
    """)


class Round18D(unittest.TestCase):
    stand_in = None

    @classmethod
    def setUpClass(cls):
        cls.tmp = tempfile.TemporaryDirectory(prefix="calligraphy-round18d-")
        cls.dir = Path(cls.tmp.name)
        cls.cli_runs = {}

    @classmethod
    def tearDownClass(cls):
        cls.tmp.cleanup()

    # ---- shared runs -----------------------------------------------------------------------------------------
    def stand_in_results(self):
        if not PYTHON_STAND_IN or not Path(PYTHON_STAND_IN).exists():
            self.skipTest("no stand-in libHD for the Python module (CALLIGRAPHY_PYTHON_HD_STAND_IN)")
        if Round18D.stand_in is None:
            result = subprocess.run([sys.executable, "-c", SCENARIOS, PYTHON_STAND_IN], env=dict(ENV),
                                    capture_output=True, timeout=TIMEOUT_S * 2)
            self.assertEqual(result.returncode, 0, result.stderr.decode())
            Round18D.stand_in = json.loads(result.stdout.decode().strip().splitlines()[-1])
        return Round18D.stand_in

    def cli_trial(self, name, points, duration=0.4):
        """`trial 一 --device openhaptics` on the stand-in whose hand plays back `points` ((t, x, y, z) in HDAPI
        mm, written as text so that nan and inf go through); the run, its record and its trace."""
        if name in self.cli_runs:
            return self.cli_runs[name]
        where = self.dir / name
        where.mkdir()
        path = where / "path.txt"
        path.write_text("".join(f"{t} {x} {y} {z}\n" for t, x, y, z in points))
        env = dict(ENV, CALLIGRAPHY_LIBHD=STAND_IN, HD_STAND_IN_PATH=str(path))
        result = run(["trial", YI, "--device", "openhaptics", "--max-duration", duration, "--watchdog-ms", "5000",
                      "--json", "t.json", "--csv", "t.csv"], cwd=where, env=env)
        record = strict_json((where / "t.json").read_text()) if (where / "t.json").exists() else None
        rows = read_trace(where / "t.csv") if (where / "t.csv").exists() else None
        self.cli_runs[name] = (result, record, rows, where)
        return self.cli_runs[name]

    def assert_trial_kept(self, result, record, rows):
        err = result.stderr.decode()
        self.assertNotIn("terminate called", err)
        self.assertIn(result.returncode, (0, 1), err)  # never a crash, never a usage error
        self.assertIsNotNone(record, err)
        self.assertIsNotNone(rows, err)
        self.assertEqual(record["loop"]["ticks"], len(rows))  # every tick in the trace
        self.assertGreater(len(rows), 100)
        f = forces(rows)
        self.assertTrue(np.isfinite(f).all())
        self.assertLessEqual(np.linalg.norm(f, axis=1).max(), PEAK_N + 1e-4)
        self.assertLessEqual(largest_step_but_to_zero(f), STEP_N + 2e-4)
        self.assertLessEqual(record["max_force_n"], PEAK_N + EPS)
        if record["end_reason"] == "completed":
            self.assertEqual(result.returncode, 0)
        else:
            self.assertEqual(result.returncode, 1, err)  # exit 1: the trial ended early
            # one error line says why (beside warnings: the stand-in the backend loaded, a loaded machine's rate)
            said = [line for line in err.strip().splitlines() if ": warning: " not in line]
            self.assertEqual(len(said), 1, said)
            self.assertIn(record["end_reason"], said[0])
        self.assertNotIn("nan", result.stdout.decode().lower())  # the table shows no NaN of a refused reading
        return f

    def assert_rejected_run(self, record, rows, f):
        """The pen, held 4 mm in the paper (about 3 N up), read garbled for 100 ticks: those ticks are kept with
        zero force and the last accepted position (include/calligraphy/trial/recorder.hpp), so the trace holds
        no reading the renderer refused; the force then climbs back at the per-tick limit."""
        zero = ~f.any(axis=1)
        runs, start = [], None
        for i, z in enumerate(list(zero) + [False]):
            if z and start is None:
                start = i
            elif not z and start is not None:
                runs.append((start, i))
                start = None
        longest = max(runs, key=lambda r: r[1] - r[0], default=(0, 0))
        self.assertGreaterEqual(longest[1] - longest[0], 90, "no run of zero force where the readings were garbled")
        self.assertGreater(longest[0], 0)
        self.assertGreater(np.linalg.norm(f[longest[0] - 1]), 1.0)  # a force there before: stepped to zero
        self.assertLess(longest[1], len(rows))  # and back after
        positions = {(r["x"], r["y"], r["z"]) for r in rows}
        self.assertEqual(positions, {("-0.01", "0", "-0.004")})  # the last accepted reading, never the garbled
        steps = np.linalg.norm(np.diff(f, axis=0), axis=1)
        self.assertAlmostEqual(record["max_force_step_n"], steps.max(), delta=2e-4)  # the step to zero counted
        # and the record counts those ticks: a run of zero force at a held position is no pen held still
        self.assertEqual(record["readings_rejected"], longest[1] - longest[0])

    # ---- the command line on the stand-in, its hand garbled -----------------------------------------------
    def garbled(self, value):
        pen = (-10.0, -4.0, 0.0)
        return [(0.0, *pen), (0.2, *pen), (0.2, value, -4.0, 0.0), (0.3, value, -4.0, 0.0), (0.3, *pen),
                (1.0, *pen)]

    @need_stand_in
    def test_nan_reading_mid_trial_gives_zero_force_and_every_tick_kept(self):
        result, record, rows, _ = self.cli_trial("nan", self.garbled("nan"))
        f = self.assert_trial_kept(result, record, rows)
        self.assert_rejected_run(record, rows, f)
        self.assertEqual(record["end_reason"], "time_limit")  # a garbled reading is not a fault: it goes on

    @need_stand_in
    def test_infinite_reading_mid_trial_gives_zero_force_and_every_tick_kept(self):
        result, record, rows, _ = self.cli_trial("inf", self.garbled("inf"))
        f = self.assert_trial_kept(result, record, rows)
        self.assert_rejected_run(record, rows, f)
        self.assertEqual(record["end_reason"], "time_limit")

    @need_stand_in
    def test_a_reading_past_ten_metres_gives_zero_force(self):
        result, record, rows, _ = self.cli_trial("far", self.garbled(20000.0))
        f = self.assert_trial_kept(result, record, rows)
        self.assert_rejected_run(record, rows, f)
        self.assertEqual(record["end_reason"], "time_limit")

    @need_stand_in
    def test_a_leap_of_metres_keeps_the_peak_and_the_rate_limit(self):
        result, record, rows, _ = self.cli_trial("leap", self.garbled(5000.0))
        self.assert_trial_kept(result, record, rows)
        self.assertGreater(max(abs(float(r["x"])) for r in rows), 4.0)  # the leap was read, 5 m away
        self.assertEqual(record["end_reason"], "time_limit")

    @need_stand_in
    def test_a_frozen_pen_in_the_paper_runs_to_its_time_limit_within_the_limits(self):
        pen = (-10.0, -4.0, 0.0)
        result, record, rows, _ = self.cli_trial("frozen", [(0.0, *pen), (5.0, *pen)])
        f = self.assert_trial_kept(result, record, rows)
        self.assertEqual(record["end_reason"], "time_limit")
        self.assertEqual(len({(r["x"], r["y"], r["z"]) for r in rows}), 1)  # the same sample throughout
        self.assertGreater(f[:, 2].max(), 0.5)  # the paper pushes the pen up

    @need_stand_in
    def test_garbage_from_the_first_tick_gives_no_force_and_the_origin_in_the_trace(self):
        result, record, rows, _ = self.cli_trial("all_nan", [(0.0, math.nan, math.nan, math.nan),
                                                             (1.0, math.nan, math.nan, math.nan)])
        f = self.assert_trial_kept(result, record, rows)
        self.assertEqual(record["end_reason"], "time_limit")
        self.assertFalse(f.any())  # nothing was ever pushed
        self.assertEqual({(r["x"], r["y"], r["z"]) for r in rows}, {("0", "0", "0")})  # the origin before any
        self.assertEqual(record["strokes_completed"], 0)

    @need_stand_in
    def test_a_reading_that_flickers_between_nan_and_the_pen_ramps_back_every_time(self):
        pen = (-10.0, -4.0, 0.0)
        points = [(0.0, *pen)] + [(0.15 + 0.002 * k + 0.001 * (k % 2 == 1), *((math.nan,) * 3 if k % 2 else pen))
                                  for k in range(100)] + [(0.5, *pen)]
        points.sort(key=lambda p: p[0])
        result, record, rows, _ = self.cli_trial("flicker", points)
        f = self.assert_trial_kept(result, record, rows)  # every step but those to zero within 0.25 N
        self.assertEqual(record["end_reason"], "time_limit")
        magnitudes = np.linalg.norm(f, axis=1)
        self.assertGreater((magnitudes == 0).sum(), 30)  # the garbled ticks
        # between garbled ticks the force restarts from zero: never more than one step above it
        after_zero = [magnitudes[i + 1] for i in range(100, len(f) - 1) if magnitudes[i] == 0]
        self.assertLessEqual(max(after_zero), STEP_N + 2e-4)
        self.assertEqual({(r["x"], r["y"], r["z"]) for r in rows}, {("-0.01", "0", "-0.004")})

    @need_stand_in
    def test_a_frozen_pen_re_run_with_a_short_time_constant_settles_at_the_continuous_force(self):
        # The frozen trial's record with the continuous-force limit's time constant cut to 50 ms, re-run on the
        # same stand-in: a sustained demand of 3.2 N (4 mm into the paper) settles at the Touch's 0.88 N.
        pen = (-10.0, -4.0, 0.0)
        _, record, _, where = self.cli_trial("frozen", [(0.0, *pen), (5.0, *pen)])
        self.assertIsNotNone(record)
        record["specification"]["safety"]["continuous_time_constant_s"] = 0.05
        record["specification"]["trial"]["max_duration_s"] = 0.6
        (where / "short.json").write_text(json.dumps(record))
        env = dict(ENV, CALLIGRAPHY_LIBHD=STAND_IN, HD_STAND_IN_PATH=str(where / "path.txt"))
        result = run(["trial", "--spec", "short.json", "--json", "r.json", "--csv", "r.csv"], cwd=where, env=env)
        self.assertEqual(result.returncode, 1, result.stderr.decode())  # the time limit
        again = strict_json((where / "r.json").read_text())
        self.assertEqual(again["end_reason"], "time_limit")
        self.assertEqual(again["specification"]["safety"]["continuous_time_constant_s"], 0.05)
        f = np.linalg.norm(forces(read_trace(where / "r.csv")), axis=1)
        self.assertGreater(f.max(), CONTINUOUS_N + 0.5)  # the peak allowed while the estimate was low
        self.assertLessEqual(f[-100:].max(), CONTINUOUS_N + 0.01)  # settled after 10 time constants
        self.assertGreater(f[-100:].min(), CONTINUOUS_N - 0.05)  # at it, not below

    @need_stand_in
    def test_the_trace_of_a_garbled_trial_scores_as_the_trial_did(self):
        # docs/cli.md: `score` reads a trial's CSV as it is and gives the trial's metrics to its precision; the
        # refused readings are no positions in it, so the pen-down time is the trial's and nothing is NaN
        result, record, rows, where = self.cli_trial("inf", self.garbled("inf"))
        self.assertIsNotNone(rows, result.stderr.decode())
        scored = run(["score", "t.csv", "--character", YI, "--json", "-"], cwd=where)
        self.assertEqual(scored.returncode, 0, scored.stderr.decode())
        metrics = strict_json(scored.stdout.decode())
        self.assertAlmostEqual(metrics["pen_down_time_s"], record["pen_down_time_s"], delta=2e-6)
        self.assertEqual(metrics["samples"], len(rows))  # every tick, the refused ones too
        self.assertEqual(metrics["strokes_accepted"], record["strokes_completed"])

    @need_stand_in
    def test_the_record_of_a_garbled_trial_is_valid_for_its_re_run(self):
        result, record, rows, where = self.cli_trial("nan", self.garbled("nan"))
        self.assertIsNotNone(record, result.stderr.decode())
        check = run(["trial", "--spec", "t.json", "--check"], cwd=where,
                    env=dict(ENV, CALLIGRAPHY_LIBHD=STAND_IN))
        self.assertEqual(check.returncode, 0, check.stderr.decode())
        self.assertEqual(len(check.stdout.decode().strip().splitlines()) + len(check.stderr.decode().strip()
                                                                                .splitlines()), 1)

    # ---- Python's run_trial on the stand-in ------------------------------------------------------------------
    def released(self, got):
        self.assertEqual(got["running"], 0)
        self.assertEqual(got["initialised"], 0)

    def test_a_link_lost_once_then_restored_ends_the_trial_and_brings_no_force_back(self):
        got = self.stand_in_results()["link_blip"]
        self.assertNotIn("error", got)
        self.assertEqual(got["end_reason"], "device_fault")
        self.assertTrue(got["aborted"])
        self.assertIn("Touch", got["abort_reason"])
        self.assertEqual(got["loop"]["ticks"], got["ticks"])
        self.assertLess(got["ticks"], 220)
        self.released(got)
        after = [f for f in got["frames"] if f["tick"] >= 200]
        self.assertTrue(after)
        self.assertFalse([f for f in after if f["out"] and any(f["force_out"])])  # no force once it failed
        self.assertFalse([f for f in after if f["set"] and any(f["force_set"])])

    def test_a_link_dead_from_the_start_is_one_error_or_a_trial_of_no_force_and_the_device_released(self):
        got = self.stand_in_results()["dead_from_start"]
        self.released(got)
        self.assertFalse([f for f in got["frames"] if f["out"] and any(f["force_out"])])
        if "error" in got:  # docs/devices.md: an error before the first tick is thrown, nothing recorded
            name, mro, message = got["error"]
            self.assertIn("DeviceError", mro, message)
            self.assertIn("HD_COMM_ERROR", message)
            self.assertEqual(len(message.splitlines()), 1)
        else:  # or the first tick's read is the fault: device_fault, every tick (none or few) kept
            self.assertEqual(got["end_reason"], "device_fault")
            self.assertEqual(got["loop"]["ticks"], got["ticks"])
            self.assertLess(got["ticks"], 5)

    def test_a_force_limit_tripped_once_ends_the_trial_and_no_force_follows(self):
        # docs/devices.md: HD_EXCEEDED_MAX_FORCE in the servo path is `safety_limit`, ending the trial
        # `device_fault`; the driver re-enables nothing by itself and the backend commands nothing after it
        got = self.stand_in_results()["force_limit_once"]
        self.assertNotIn("error", got)
        self.assertEqual(got["end_reason"], "device_fault")
        self.assertIn("safety limit", got["abort_reason"])
        self.assertEqual(got["loop"]["ticks"], got["ticks"])
        self.assertLess(got["ticks"], 210)
        after = [f for f in got["frames"] if f["tick"] > 200]
        self.assertTrue(after)
        self.assertFalse([f for f in after if any(f["force_out"])])
        self.assertFalse([f for f in after if f["set"] and any(f["force_set"])])
        self.released(got)

    def test_late_frames_under_the_watchdog_are_counted_and_the_trial_goes_on_for_its_ticks(self):
        got = self.stand_in_results()["late"]
        self.assertNotIn("error", got)
        self.assertEqual(got["end_reason"], "time_limit")
        self.assertEqual(got["loop"]["ticks"], got["ticks"])
        # on the driver's clock a late frame is a stall of the loop (docs/servo-loop.md: the device's clock
        # replaces the loop's own late-tick check), counted in longest_stall_ms and the period jitter
        self.assertGreaterEqual(got["loop"]["longest_stall_ms"], 15.0)
        self.assertGreaterEqual(got["loop"]["period_jitter_us_max"], 15000.0)
        self.assertLess(got["loop"]["longest_stall_ms"], 5000.0)  # under the stall bound given
        gaps = np.diff(got["time"])
        self.assertGreaterEqual((gaps > 0.015).sum(), 3)  # the trial's clock shows the leaps
        self.assertTrue((gaps > 0).all())  # and never goes back
        # the time limit is max_duration_s x rate_hz ticks (docs/servo-loop.md "Real-time trial"; docs/cli.md's
        # --max-duration said "after this much time"): 400 ticks, which the three late frames made 60 ms longer
        self.assertEqual(got["ticks"], 400)
        self.assertGreater(got["time"][-1], 0.4 + 0.05)
        self.released(got)

    def test_a_pen_twenty_metres_away_for_sixty_ticks_gets_zero_force_and_the_trial_goes_on(self):
        got = self.stand_in_results()["far"]
        self.assertNotIn("error", got)
        self.assertEqual(got["end_reason"], "time_limit")
        f = np.array(got["force"])
        self.assertTrue(np.isfinite(f).all())
        far = [fr for fr in got["frames"] if fr["set"] and abs(fr["position_mm"][0]) > 10000.0]
        self.assertGreater(len(far), 50)  # the pen was read 20 m away
        self.assertFalse([fr for fr in far if any(fr["force_set"]) or any(fr["force_out"])])  # zero force then
        self.assertLessEqual(largest_step_but_to_zero(f), STEP_N + 1e-9)
        self.released(got)

    def test_a_square_wave_of_five_metres_keeps_the_touch_s_limits_at_the_motors(self):
        got = self.stand_in_results()["leap"]
        self.assertNotIn("error", got)
        self.assertIn(got["end_reason"], ("time_limit",))
        f = np.array(got["force"])
        self.assertLessEqual(np.linalg.norm(f, axis=1).max(), PEAK_N + 1e-9)
        self.assertLessEqual(largest_step_but_to_zero(f), STEP_N + 1e-9)
        sent = np.array([fr["force_out"] for fr in got["frames"]])  # what reached the motors, every frame
        self.assertGreater(np.count_nonzero(sent.any(axis=1)), 100)
        self.assertLessEqual(np.linalg.norm(sent, axis=1).max(), PEAK_N + 1e-9)
        self.assertLessEqual(largest_step_but_to_zero(sent), STEP_N + 1e-9)
        self.released(got)

    def test_stuck_buttons_and_a_docked_stylus_mid_trial_do_not_fault(self):
        got = self.stand_in_results()["buttons"]
        self.assertNotIn("error", got)
        self.assertEqual(got["end_reason"], "time_limit")
        self.assertEqual(got["loop"]["ticks"], got["ticks"])
        self.released(got)

    def test_a_scheduler_that_is_full_at_open_is_a_device_error_and_releases_the_device(self):
        got = self.stand_in_results()["full"]
        self.assertIn("error", got)
        name, mro, message = got["error"]
        self.assertIn("DeviceError", mro, message)
        self.assertIn("HD_SCHEDULER_FULL", message)
        self.assertEqual(len(message.splitlines()), 1)
        self.released(got)

    def test_a_device_clock_that_goes_back_and_leaps_mid_trial_keeps_one_time_base(self):
        got = self.stand_in_results()["clock"]
        self.assertNotIn("error", got)
        self.assertEqual(got["loop"]["ticks"], got["ticks"])
        self.assertIn(got["end_reason"], ("time_limit",), got["abort_reason"])
        gaps = np.diff(got["time"])
        self.assertTrue((gaps > 0).all(), "the trial's times go back")
        self.assertLess(gaps.max(), 0.05)  # no leap of the driver's clock reaches the trial's times
        self.assertLess(got["time"][-1], 5.0)
        f = np.array(got["force"])
        self.assertLessEqual(largest_step_but_to_zero(f), STEP_N + 1e-9)
        self.released(got)

    # ---- the Renderer fed states a device should never give ------------------------------------------------
    @classmethod
    def renderer(cls):
        scene = cg.Scene(YI)
        start = scene.characters[0].strokes[0].median_m[0]
        renderer = cg.Renderer(scene, cg.ForceLawParameters(), device=cg.SimulatedDevice().info,
                               options=cg.RendererOptions(rate_hz=1000.0))
        return renderer, (float(start[0]), float(start[1]))

    def press(self, renderer, start, ticks, t0=0.0, depth=0.003):
        out = None
        for k in range(ticks):
            out = renderer.tick(cg.DeviceState(position_m=(start[0], start[1], -depth), velocity_m_s=(0, 0, 0),
                                               time_s=t0 + k * 1e-3))
        return out

    def test_renderer_time_stamp_that_is_not_finite_gives_zero_force(self):
        for bad in (math.nan, math.inf, -math.inf):
            renderer, start = self.renderer()
            before = self.press(renderer, start, 300)
            self.assertGreater(np.linalg.norm(before.force_n), 0.5)
            out = renderer.tick(cg.DeviceState(position_m=(start[0], start[1], -0.003), velocity_m_s=(0, 0, 0),
                                               time_s=bad))
            self.assertEqual(list(out.force_n), [0.0, 0.0, 0.0], bad)
            self.assertTrue(out.input_rejected)

    def test_renderer_velocity_that_is_nan_gives_zero_force(self):
        renderer, start = self.renderer()
        self.press(renderer, start, 300)
        out = renderer.tick(cg.DeviceState(position_m=(start[0], start[1], -0.003), velocity_m_s=(math.nan, 0, 0),
                                           time_s=0.3))
        self.assertEqual(list(out.force_n), [0.0, 0.0, 0.0])
        self.assertTrue(out.input_rejected)

    def assert_limits(self, outputs):
        f = np.array([o.force_n for o in outputs])
        self.assertTrue(np.isfinite(f).all())
        self.assertLessEqual(np.linalg.norm(f, axis=1).max(), 7.9 + 1e-9)  # the simulated Desktop's peak
        self.assertLessEqual(largest_step_but_to_zero(f), STEP_N + 1e-9)
        self.assertFalse([o for o in outputs if o.input_rejected])  # finite times are taken

    def test_renderer_time_stamps_that_repeat_or_go_backwards_keep_the_limits(self):
        for times in ([0.3] * 50, [0.3 - 0.01 * k for k in range(50)], [0.3, 0.1, 0.3, 0.1] * 12):
            renderer, start = self.renderer()
            outputs = [self.press(renderer, start, 300)]
            for k, t in enumerate(times):
                outputs.append(renderer.tick(cg.DeviceState(position_m=(start[0] + 1e-4 * k, start[1], -0.004),
                                                            velocity_m_s=(0.1, 0, -0.01), time_s=t)))
            self.assert_limits(outputs)

    def test_renderer_counts_ticks_not_time_stamps(self):
        # docs/servo-loop.md: a renderer's fades, filters and observer count ticks as periods of its rate, and
        # the start ramp (docs/force-rendering.md) bounds |F| by 20 N/s x the time since construction: the
        # same pen held in the paper gives the same forces whatever finite stamps the device puts on its states
        runs = []
        for times in ([k * 1e-3 for k in range(200)], [5.0 - 0.01 * k for k in range(200)], [0.0] * 200,
                      [1e300] * 200, [(-1) ** k * 1e6 for k in range(200)]):
            renderer, start = self.renderer()
            runs.append([list(renderer.tick(cg.DeviceState(position_m=(start[0], start[1], -0.004),
                                                           velocity_m_s=(0, 0, 0), time_s=t)).force_n)
                         for t in times])
        for other in runs[1:]:
            self.assertEqual(other, runs[0])
        magnitudes = np.linalg.norm(np.array(runs[0]), axis=1)
        self.assertLessEqual((magnitudes - 20.0 * 1e-3 * np.arange(1, 201)).max(), 1e-9)  # the start ramp
        self.assertGreater(magnitudes[-1], 3.0)  # and then the paper's 800 N/m x 4 mm

    def test_renderer_time_stamp_that_leaps_keeps_the_limits(self):
        renderer, start = self.renderer()
        outputs = [self.press(renderer, start, 300)]
        for k, t in enumerate((1e6, 1e6 + 1e-3, 1e12, 1e300)):
            outputs.append(renderer.tick(cg.DeviceState(position_m=(start[0], start[1], -0.006),
                                                        velocity_m_s=(0, 0, 0), time_s=t)))
        self.assert_limits(outputs)

    # ---- the simulated device used wrongly -----------------------------------------------------------------
    def test_simulated_device_given_a_nan_force_keeps_a_finite_pen(self):
        dev = cg.SimulatedDevice(cg.SimulatedDeviceParameters(initial_position_m=(0, 0, 0.02)))
        dev.open()
        try:
            dev.write_force([math.nan, 0.0, 0.0])
        except cg.SafetyFault:
            pass  # docs/devices.md: non_finite_force, a SafetyFault in Python
        dev.advance(1e-3)
        state = dev.read_state()
        self.assertTrue(np.isfinite(state.position_m).all(), state.position_m)
        self.assertTrue(np.isfinite(state.velocity_m_s).all(), state.velocity_m_s)

    def test_simulated_device_time_sent_back_or_not_finite_is_refused_naming_dt(self):
        dev = cg.SimulatedDevice(cg.SimulatedDeviceParameters(initial_position_m=(0, 0, 0.02)))
        dev.open()
        dev.read_state()
        dev.write_force([0.0, 0.0, 0.0])
        dev.advance(1e-3)
        before = dev.read_state()
        for dt in (-1e-3, math.nan, math.inf):
            with self.assertRaises(cg.InvalidArgument) as raised:
                dev.advance(dt)
            self.assertIn("dt_s", str(raised.exception))
        after = dev.read_state()  # nothing moved, the clock did not go back
        self.assertEqual(after.time_s, before.time_s)
        self.assertEqual(list(after.position_m), list(before.position_m))

    def test_safety_limits_of_a_trial_hold_in_its_recorded_forces(self):
        safety = cg.SafetyChainParameters(max_force_n=0.5, max_continuous_force_n=0.4,
                                          max_force_change_n_per_tick=0.05)
        r = cg.simulate_trial(YI, max_duration_s=1.0, safety=safety)
        f = np.array(r.force_n)
        self.assertLessEqual(np.linalg.norm(f, axis=1).max(), 0.5 + 1e-9)
        self.assertLessEqual(np.linalg.norm(np.diff(f, axis=0), axis=1).max(), 0.05 + 1e-9)
        self.assertLessEqual(r.metrics["max_force_n"], 0.5 + 1e-9)


if __name__ == "__main__":
    unittest.main()
