#!/usr/bin/env python3
"""Round 28H: every guidance mode of `trial`, as a lab uses them. From the docs alone (docs/cli.md `trial`,
"Re-running a trial", "The trial specification"; docs/force-rendering.md "Guidance modes", "Teacher's
recording file", "Safety chain"; docs/python.md "Writers, guidance modes, learning and teachers", "Running a
trial again"; include/calligraphy/trial/trial_spec.hpp, trial/teacher_recording.hpp, render/guidance_law.hpp
and the Python docstrings of Renderer, simulate_trial, rerun_trial, next_guidance_gain, next_assist_band).

The surface: `calligraphy trial 十` under fixed, fading, replay, assist-as-needed, error amplification, timing
and guidance off, each mode's own options at and past their documented ends, another mode's option given (at
its default value too: `refuse_inapplicable_fields` refuses it "whatever their value"), a teacher recorded by
`--record` then edited, cut, of another character, swapped or moved after the replay's record was written;
each mode's record re-run byte for byte by `trial --spec` and by Python's `rerun_trial`; the force every trace
holds against the safety chain's documented limits (the device's peak force, 0.25 N per tick, the start ramp
of 20 N/s) and the record's own max |F| and max per-tick |dF|; what each mode does to the pen: guidance off
leaves in plane only the paper's friction (at most mu N, mu = 0.15), error amplification pushes away from
the stroke where the fixture pulls towards it, and a pen held still off the stroke feels exactly the
table's force of each mode (Python's `Renderer`, the foot point X_S it reports); fading's and the band's rules
per repetition computed from their documented formulas; a record whose `trial` states another mode's value
than its `force_law.guidance_law` ran with (a contradiction between fields), and Python's `rerun_trial` given a
teacher for a record that is no replay, as `trial --spec` refuses `--teacher` for one.

CALLIGRAPHY_CLI names the program; PYTHONPATH the built Python package. CALLIGRAPHY_SANITIZED=1 takes five cases.
"""
import hashlib
import json
import math
import os
import shutil
import tempfile
import unittest
import warnings
from pathlib import Path

from outsider import OneErrorLine, run, run_ok, sanitized_subset

try:
    import numpy as np
    import calligraphy as cg
except ImportError:  # reported by setUpClass
    np = cg = None

load_tests = sanitized_subset({"test_another_mode_s_option_at_its_default_is_a_usage_error_naming_it",
                               "test_mode_options_past_their_ranges_are_refused_naming_the_option",
                               "test_replay_without_a_teacher_is_a_usage_error_naming_teacher",
                               "test_record_mode_values_out_of_range_are_refused_at_their_pointers",
                               "test_fading_gain_and_assist_band_rules_follow_their_formulas"})

CHAR = "十"
# mode -> (its options, its own values as the record's force_law.guidance_law states them)
MODES = {
    "fixed": ([], {"mode": "fixed"}),
    "fading": (["--guidance-mode", "fading", "--guidance-gain", "0.4"], {"mode": "fading", "gain": 0.4}),
    "replay": (["--guidance-mode", "replay", "--teacher", "t.json"], {"mode": "replay", "max_lead_m": 0.003}),
    "assist": (["--guidance-mode", "assist-as-needed", "--assist-band", "0.002"],
               {"mode": "assist-as-needed", "band_m": 0.002}),
    "amplify": (["--guidance-mode", "error-amplification", "--amplification-gain", "0.5"],
                {"mode": "error-amplification", "gain": 0.5, "max_force_n": 0.3}),
    "timing": (["--guidance-mode", "timing", "--timing-speed", "0.08"],
               {"mode": "timing", "speed_m_s": 0.08, "max_lead_m": 0.003}),
    "off": (["--guidance", "off"], None),
}
MU = 0.15                  # friction_coefficient (docs/force-rendering.md)
STEP_LIMIT_N = 0.25        # max_force_change_n_per_tick
RAMP_N_PER_S = 20.0        # start_ramp_n_per_s
CSV_FORCE_ROUND_N = 0.5e-4  # forces to 0.1 mN
CSV_POS_ROUND_M = 0.5e-7    # positions to 0.1 um


def read_trace(path):
    """The CSV trace as numpy arrays: t, pos (N, 3), force (N, 3), state (array of str), stroke."""
    with open(path, encoding="utf-8") as f:
        header = f.readline().strip().split(",")
    assert header == ["t", "x", "y", "z", "fx", "fy", "fz", "state", "stroke", "element", "attempt", "rewritten"], header
    numbers = np.loadtxt(path, delimiter=",", skiprows=1, usecols=(0, 1, 2, 3, 4, 5, 6, 8), ndmin=2)
    state = np.loadtxt(path, delimiter=",", skiprows=1, usecols=7, dtype=str, ndmin=1)
    return numbers[:, 0], numbers[:, 1:4], numbers[:, 4:7], state, numbers[:, 7].astype(int)


def nearest_on_polyline(points, poly):
    """For each (x, y) of `points` the nearest point of the polyline `poly`."""
    best = np.full(len(points), np.inf)
    out = np.zeros((len(points), 2))
    for a, b in zip(poly[:-1], poly[1:]):
        ab = b - a
        u = np.clip(((points - a) @ ab) / max(ab @ ab, 1e-30), 0.0, 1.0)
        q = a + u[:, None] * ab
        d = np.linalg.norm(points - q, axis=1)
        closer = d < best
        best[closer] = d[closer]
        out[closer] = q[closer]
    return out


class Round28H(unittest.TestCase, OneErrorLine):
    @classmethod
    def setUpClass(cls):
        if cg is None:
            raise unittest.SkipTest("numpy and the calligraphy Python package (PYTHONPATH) are needed")
        cls.tmp = Path(tempfile.mkdtemp(prefix="round28h-"))
        d = cls.tmp
        # The teacher, recorded by the program as the docs show it (a skilled writer), with its trace.
        run_ok(["trial", CHAR, "--writer-profile", "skilled", "--record", "t.json", "--csv", "teacher.csv",
                "--json", "teacher-trial.json"], d)
        cls.records, cls.traces = {}, {}
        for name, (options, _) in MODES.items():
            result = run(["trial", CHAR, *options, "--json", f"{name}.json", "--csv", f"{name}.csv"], d)
            cls.records[name] = json.loads((d / f"{name}.json").read_text(encoding="utf-8"))
            cls.traces[name] = read_trace(d / f"{name}.csv")
            cls.records[name]["_status"] = result.returncode
        devices = json.loads(run_ok(["devices", "--json"], d).stdout)
        cls.peak = {dev["name"]: dev["info"]["max_force_n"] for dev in devices["devices"]}

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.tmp, ignore_errors=True)

    def cli(self, *args, cwd=None):
        return run(list(args), cwd or self.tmp)

    def record(self, name):
        r = json.loads(json.dumps(self.records[name]))
        r.pop("_status")
        return r

    def write_record(self, filename, record):
        (self.tmp / filename).write_text(json.dumps(record, ensure_ascii=False), encoding="utf-8")
        return filename

    # ---- options: each mode's own, another mode's, guidance off -----------------------------------------
    def test_each_mode_but_fixed_with_guidance_off_is_a_usage_error(self):
        # docs/cli.md: "a mode other than `fixed` with `--guidance off` is a usage error".
        for mode in ("fading", "assist-as-needed", "error-amplification", "timing"):
            for extra in (["--check"], ["--json", f"off-{mode}.json"])[:2 if mode == "timing" else 1]:
                with self.subTest(mode=mode, extra=extra):
                    result = self.cli("trial", CHAR, "--guidance", "off", "--guidance-mode", mode, *extra)
                    self.assert_one_error(result, 2, "--guidance-mode")
                    self.assertFalse((self.tmp / f"off-{mode}.json").exists())
        result = self.cli("trial", CHAR, "--guidance", "off", "--guidance-mode", "replay", "--teacher", "t.json",
                          "--check")
        self.assert_one_error(result, 2)

    def test_fixed_mode_stated_with_guidance_off_is_valid(self):
        result = self.cli("trial", CHAR, "--guidance", "off", "--guidance-mode", "fixed", "--check")
        self.assertEqual(result.returncode, 0, result.stderr)

    def test_another_mode_s_option_at_its_default_is_a_usage_error_naming_it(self):
        # docs/cli.md: `--guidance-gain` "`fading` only (a usage error with another mode)", each other mode's
        # option "... only"; `--teacher` "`replay` only"; `--guidance-stiffness` "a usage error with
        # `--guidance off`". trial_spec.hpp: refused when given "whatever their value".
        cases = [([], "--guidance-gain", "1"),
                 (["--guidance-mode", "timing"], "--guidance-gain", "1"),
                 (["--guidance-mode", "fading"], "--assist-band", "0.001"),
                 (["--guidance-mode", "assist-as-needed"], "--amplification-gain", "0.25"),
                 (["--guidance-mode", "error-amplification"], "--timing-speed", "0.04"),
                 (["--guidance-mode", "assist-as-needed"], "--teacher", "t.json"),
                 ([], "--teacher", "t.json"),
                 (["--guidance", "off"], "--guidance-stiffness", "400"),
                 (["--guidance", "off"], "--guidance-gain", "1")]
        for mode, option, value in cases:
            with self.subTest(mode=mode, option=option):
                self.assert_one_error(self.cli("trial", CHAR, *mode, option, value, "--check"), 2, option)
        for mode, option, value in (cases[2], cases[-2]):   # and as a trial: nothing run, nothing written
            with self.subTest(mode=mode, option=option, run=True):
                result = self.cli("trial", CHAR, *mode, option, value, "--json", "inapplicable.json")
                self.assert_one_error(result, 2, option)
                self.assertFalse((self.tmp / "inapplicable.json").exists())

    def test_mode_options_at_their_defaults_and_the_ends_of_their_ranges_are_taken(self):
        for mode, option, value in (("fading", "--guidance-gain", "0"), ("fading", "--guidance-gain", "1"),
                                    ("assist-as-needed", "--assist-band", "0"),
                                    ("assist-as-needed", "--assist-band", "0.001"),
                                    ("assist-as-needed", "--assist-band", "0.1"),
                                    ("error-amplification", "--amplification-gain", "0.25"),
                                    ("error-amplification", "--amplification-gain", "1"),
                                    ("timing", "--timing-speed", "0.04"), ("timing", "--timing-speed", "1"),
                                    ("timing", "--timing-speed", "1e-6")):
            with self.subTest(option=option, value=value):
                result = self.cli("trial", CHAR, "--guidance-mode", mode, option, value, "--check")
                self.assertEqual(result.returncode, 0, result.stderr)

    def test_mode_options_past_their_ranges_are_refused_naming_the_option(self):
        for mode, option, value in (("fading", "--guidance-gain", "1.0001"), ("fading", "--guidance-gain", "-0.01"),
                                    ("fading", "--guidance-gain", "nan"),
                                    ("assist-as-needed", "--assist-band", "0.1000001"),
                                    ("assist-as-needed", "--assist-band", "-1e-9"),
                                    ("error-amplification", "--amplification-gain", "1.01"),
                                    ("error-amplification", "--amplification-gain", "inf"),
                                    ("timing", "--timing-speed", "0"), ("timing", "--timing-speed", "1.0001")):
            with self.subTest(option=option, value=value):
                self.assert_one_error(self.cli("trial", CHAR, "--guidance-mode", mode, option, value, "--check"),
                                      2, option)

    def test_guidance_gain_past_its_range_gives_the_documented_line(self):
        line = self.assert_one_error(self.cli("trial", CHAR, "--guidance-mode", "fading", "--guidance-gain", "1.5",
                                              "--check"), 2)
        self.assertIn("--guidance-gain: guidance_gain = 1.5 must be in [0, 1]", line)

    def test_replay_without_a_teacher_is_a_usage_error_naming_teacher(self):
        result = self.cli("trial", CHAR, "--guidance-mode", "replay", "--json", "noteacher.json")
        self.assert_one_error(result, 2, "--teacher")
        self.assertFalse((self.tmp / "noteacher.json").exists())

    def test_check_of_a_replay_reads_no_teacher_but_its_run_refuses_a_missing_one(self):
        # docs/cli.md `--check`: "a record's characters and a replay's teacher are checked when it runs".
        result = self.cli("trial", CHAR, "--guidance-mode", "replay", "--teacher", "missing.json", "--check")
        self.assertEqual(result.returncode, 0, result.stderr)
        result = self.cli("trial", CHAR, "--guidance-mode", "replay", "--teacher", "missing.json",
                          "--json", "missing-out.json")
        self.assert_one_error(result, 1, "missing.json")
        self.assertFalse((self.tmp / "missing-out.json").exists())

    # ---- each mode's trial and its record ----------------------------------------------------------------
    def test_each_mode_completes_and_its_record_states_its_own_values_only(self):
        for name, (_, law) in MODES.items():
            with self.subTest(mode=name):
                r = self.records[name]
                self.assertEqual(r["_status"], 0)
                self.assertEqual(r["end_reason"], "completed")
                self.assertEqual(r["strokes_completed"], 2)
                spec = r["specification"]
                if law is None:
                    self.assertFalse(r["guidance"])
                    self.assertFalse(spec["trial"]["guidance"])
                    continue
                self.assertEqual(spec["force_law"]["guidance_law"], law)
                self.assertEqual(spec["trial"]["guidance_mode"], law["mode"])
                self.assertEqual(r["guidance_mode"], law["mode"])
                # docs/cli.md JSON keys: `guidance_gain` (fading only), `teacher` (replay only: file, characters)
                self.assertEqual("guidance_gain" in r, name == "fading")
                self.assertEqual("teacher" in r, name == "replay")
        self.assertEqual(self.records["fading"]["guidance_gain"], 0.4)
        self.assertEqual(self.records["replay"]["teacher"], {"file": "t.json", "characters": CHAR})
        sha = hashlib.sha256((self.tmp / "t.json").read_bytes()).hexdigest()
        self.assertEqual(self.records["replay"]["specification"]["teacher_sha256"], sha)
        self.assertEqual(self.records["fixed"]["specification"]["teacher_sha256"], "")

    def test_each_mode_re_runs_byte_for_byte_by_spec(self):
        for name in MODES:
            with self.subTest(mode=name):
                result = self.cli("trial", "--spec", f"{name}.json", "--csv", f"{name}-again.csv",
                                  "--json", f"{name}-again.json")
                self.assertEqual(result.returncode, 0, result.stderr)
                self.assertEqual(result.stderr, b"", "a record re-run as it was says nothing")
                self.assertEqual((self.tmp / f"{name}-again.csv").read_bytes(),
                                 (self.tmp / f"{name}.csv").read_bytes())
                again = json.loads((self.tmp / f"{name}-again.json").read_text(encoding="utf-8"))
                self.assertEqual(again["specification"], self.records[name]["specification"])

    def test_each_mode_re_runs_in_python_to_the_trace_the_command_wrote(self):
        teacher = cg.TeacherRecording.load(str(self.tmp / "t.json"))
        for name in MODES:
            with self.subTest(mode=name):
                extra = {"teacher": teacher} if name == "replay" else {}
                r = cg.rerun_trial(str(self.tmp / f"{name}.json"), **extra)
                _, pos, force, _, _ = self.traces[name]
                self.assertEqual(r.position_m.shape, pos.shape)
                self.assertLessEqual(float(np.abs(r.position_m - pos).max()), CSV_POS_ROUND_M + 1e-12)
                self.assertLessEqual(float(np.abs(r.force_n - force).max()), CSV_FORCE_ROUND_N + 1e-12)
                self.assertEqual(r.metrics["max_force_n"], self.records[name]["max_force_n"])

    def test_fading_at_gain_one_is_the_fixed_fixture(self):
        # force-rendering.md: fading's force is g K_et a (X_S - X_p), fixed's K_et a (X_S - X_p).
        run_ok(["trial", CHAR, "--guidance-mode", "fading", "--guidance-gain", "1", "--csv", "fade1.csv"], self.tmp)
        self.assertEqual((self.tmp / "fade1.csv").read_bytes(), (self.tmp / "fixed.csv").read_bytes())

    def test_forces_of_every_mode_stay_within_the_safety_chain_limits(self):
        peak = self.peak["simulated"]
        self.assertEqual(peak, 7.9)
        for name in MODES:
            with self.subTest(mode=name):
                t, _, force, _, _ = self.traces[name]
                magnitude = np.linalg.norm(force, axis=1)
                steps = np.linalg.norm(np.diff(force, axis=0), axis=1)
                self.assertLessEqual(magnitude.max(), peak)
                self.assertLessEqual(steps.max(), STEP_LIMIT_N + 4 * CSV_FORCE_ROUND_N)
                self.assertTrue(np.all(magnitude <= RAMP_N_PER_S * (t + 0.001) + 2 * CSV_FORCE_ROUND_N),
                                "the start ramp: |F| <= 20 N/s x time")
                r = self.records[name]
                self.assertAlmostEqual(r["max_force_n"], magnitude.max(), delta=2 * CSV_FORCE_ROUND_N)
                self.assertAlmostEqual(r["max_force_step_n"], steps.max(), delta=4 * CSV_FORCE_ROUND_N)
                self.assertLessEqual(r["max_force_step_n"], STEP_LIMIT_N)

    def test_a_timing_pull_stiffer_than_the_device_is_held_to_its_peak_force(self):
        # K_et a max_lead = 2000 x 3 mm = 6 N, 4000 x 3 mm = 12 N: above each device's peak force, which the
        # safety chain's peak clamp keeps ("the force commanded and recorded is never more than the device
        # can give"). A stiffness given is kept (docs/cli.md "Defaults do not warn").
        for device, stiffness in (("emulated-phantom", "2000"), ("simulated", "4000")):
            with self.subTest(device=device):
                result = self.cli("trial", CHAR, "--device", device, "--guidance-mode", "timing",
                                  "--guidance-stiffness", stiffness, "--timing-speed", "0.2", "--max-duration", "6",
                                  "--json", f"stiff-{device}.json", "--csv", f"stiff-{device}.csv")
                self.assertIn(result.returncode, (0, 1), result.stderr)
                self.assertNotIn(b"Traceback", result.stderr)
                r = json.loads((self.tmp / f"stiff-{device}.json").read_text(encoding="utf-8"))
                self.assertEqual(r["specification"]["trial"]["guidance_stiffness_n_per_m"], float(stiffness))
                _, _, force, _, _ = read_trace(self.tmp / f"stiff-{device}.csv")
                magnitude = np.linalg.norm(force, axis=1)
                self.assertLessEqual(magnitude.max(), self.peak[device] + 2 * CSV_FORCE_ROUND_N)
                self.assertLessEqual(r["max_force_n"], self.peak[device] * (1 + 1e-12))  # a rounding's ulp
                self.assertLessEqual(float(np.linalg.norm(np.diff(force, axis=0), axis=1).max()),
                                     STEP_LIMIT_N + 4 * CSV_FORCE_ROUND_N)

    def test_guidance_off_leaves_in_plane_only_the_paper_s_friction(self):
        # force-rendering.md: friction F_f = -mu N v / |v| (or / v_band), N the rendered normal force; guidance
        # off renders no F_et and no off-stroke resistance ("under guidance only"), and nothing refuses a stroke
        # (writer.md). Under the fixture the in-plane force goes beyond friction somewhere.
        for name, beyond in (("off", False), ("fixed", True)):
            with self.subTest(mode=name):
                _, _, force, state, _ = self.traces[name]
                on_paper = np.isin(state, ("CS", "WS"))
                in_plane = np.linalg.norm(force[:, :2], axis=1)
                excess = in_plane - MU * np.abs(force[:, 2]) - 3 * CSV_FORCE_ROUND_N
                if beyond:
                    self.assertGreater(excess[on_paper].max(), 0.05)
                else:
                    self.assertLessEqual(excess.max(), 0.0, f"in-plane force beyond mu N: {excess.max() + 3e-4:.4f} N")

    def test_force_is_zero_with_the_pen_lifted_once_the_fade_is_over(self):
        # force-rendering.md, "Tests": zero force in SS and AS "once the fade-out after leaving CS/WS (at most
        # 0.2 s) is over" (paper_fade_s 0.2 s, crossfade_s 0.05 s).
        for name in ("off", "fixed", "amplify"):
            with self.subTest(mode=name):
                t, _, force, state, _ = self.traces[name]
                last_contact = -math.inf
                worst = 0.0
                for k, s in enumerate(state):
                    if s in ("CS", "WS"):
                        last_contact = t[k]
                    elif t[k] - last_contact > 0.2 + 1e-9:
                        worst = max(worst, float(np.abs(force[k]).max()))
                self.assertEqual(worst, 0.0)

    def test_error_amplification_pushes_away_from_the_stroke_where_the_fixture_pulls_towards_it(self):
        scene = cg.Scene(CHAR)
        medians = [np.asarray(s.median_m) for s in scene.characters[0].strokes]
        means = {}
        for name in ("fixed", "amplify"):
            _, pos, force, state, stroke = self.traces[name]
            writing = state == "WS"
            pushes = []
            for k, median in enumerate(medians):
                sel = writing & (stroke == k)
                p = pos[sel, :2]
                away = p - nearest_on_polyline(p, median)
                distance = np.linalg.norm(away, axis=1)
                off = distance > 0.0003
                pushes.append((force[sel, :2][off] * (away[off] / distance[off, None])).sum(axis=1))
            pushes = np.concatenate(pushes)
            self.assertGreater(len(pushes), 100, name)
            means[name] = float(pushes.mean())
        self.assertLess(means["fixed"], 0.0, means)
        self.assertGreater(means["amplify"], 0.0, means)

    # ---- a pen held still off the stroke: each mode's force of the table ---------------------------------
    @staticmethod
    def held_pen(law, offset_m=0.001, hold_ticks=800):
        """A renderer of 一 under `law`: the pen set down at the stroke's start, moved along its median to the
        middle at 20 mm/s, then `offset_m` across it and held still. The last tick's force, foot point X_S, pen
        position and the stroke's tangent there."""
        scene = cg.Scene("一")
        median = np.asarray(scene.characters[0].strokes[0].median_m)
        s = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(median, axis=0), axis=1))])

        def at(u):
            return np.array([np.interp(u, s, median[:, 0]), np.interp(u, s, median[:, 1])])

        renderer = cg.Renderer(scene, law, device=cg.SimulatedDevice().info,
                               options=cg.RendererOptions(rate_hz=1000.0))
        k, previous, out = 0, at(0.0), None
        middle = s[-1] / 2
        n = int(middle / 0.02 * 1000)
        tangent = at(middle + 1e-4) - at(middle - 1e-4)
        tangent /= np.linalg.norm(tangent)
        normal = np.array([-tangent[1], tangent[0]])
        path = [at(middle * i / n) for i in range(n + 1)] + [at(middle) + normal * offset_m * i / 100
                                                              for i in range(1, 101)]
        path += [path[-1]] * hold_ticks
        for p in path:
            v = (p - previous) * 1000.0
            previous = p
            out = renderer.tick(cg.DeviceState(position_m=(p[0], p[1], -0.0003), velocity_m_s=(v[0], v[1], 0.0),
                                               time_s=k / 1000.0))
            k += 1
        return np.asarray(out.force_n), np.asarray(out.foot_m), path[-1], tangent, out.state

    def test_held_pen_feels_each_mode_s_force_of_the_table(self):
        # docs/force-rendering.md "Guidance modes": fixed K a (X_S - X_p); fading g times it; assist-as-needed
        # K a (d - b)+ (X_S - X_p) / d; error amplification g K a (X_p - X_S) bounded by max_force_n; timing
        # along the stroke only, saturating at K a max_lead_m. At rest friction, resistance and damper are 0.
        laws = {"fixed": cg.FixedGuidance(), "fading": cg.FadingGuidance(gain=0.3),
                "band": cg.AssistAsNeededGuidance(band_m=0.0004), "wide": cg.AssistAsNeededGuidance(band_m=0.003),
                "amplify": cg.ErrorAmplificationGuidance(gain=0.25), "bound": cg.ErrorAmplificationGuidance(gain=1.0),
                "bound2": cg.ErrorAmplificationGuidance(gain=1.0, max_force_n=0.2), "timing": cg.TimingGuidance()}
        got = {}
        for name, law in laws.items():
            force, foot, p, tangent, state = self.held_pen(cg.ForceLawParameters(guidance_law=law))
            self.assertEqual(state, cg.InteractionState.writing, name)
            got[name] = force
        fixed = got["fixed"][:2]
        d_vec = p - foot
        d = float(np.linalg.norm(d_vec))
        self.assertGreater(d, 0.0005)
        ka = float(np.linalg.norm(fixed)) / d                      # K_et a
        self.assertGreater(ka, 100.0)
        np.testing.assert_allclose(fixed, -ka * d_vec, atol=1e-9)  # towards X_S
        np.testing.assert_allclose(got["fading"][:2], 0.3 * fixed, atol=1e-9)
        np.testing.assert_allclose(got["band"][:2], (d - 0.0004) / d * fixed, atol=1e-9)
        np.testing.assert_allclose(got["wide"][:2], [0.0, 0.0], atol=1e-12)
        np.testing.assert_allclose(got["amplify"][:2], -0.25 * fixed, atol=1e-9)
        self.assertGreater(0.25 * ka * d, 0.0, "amplification under its bound here")
        self.assertLess(0.25 * ka * d, 0.3)
        for name, bound in (("bound", 0.3), ("bound2", 0.2)):
            self.assertGreater(ka * d, bound)
            np.testing.assert_allclose(got[name][:2], -bound * fixed / np.linalg.norm(fixed), atol=1e-9)
        timing = got["timing"][:2]
        self.assertAlmostEqual(float(timing @ d_vec), 0.0, delta=1e-9)        # never across the stroke
        self.assertLessEqual(float(np.linalg.norm(timing)), ka * 0.003 + 1e-9)  # at most K a max_lead_m
        self.assertGreater(float(np.linalg.norm(timing)), 0.95 * ka * 0.003)   # saturated: far behind
        self.assertGreater(float(timing @ tangent), 0.0)                       # onwards along the stroke
        for name, force in got.items():
            self.assertAlmostEqual(float(force[2]), got["fixed"][2], delta=1e-12, msg=name)  # the same paper

    def test_fading_gain_and_assist_band_rules_follow_their_formulas(self):
        # force-rendering.md: g(n+1) = clamp(f g(n) + k e(n), 0, 1), f = 0.8, k = 200 / m; b(n+1) = clamp(b(n)
        # + k (e* - e(n)), b_min, b_max), e* = 1.5 mm, k = 1, b in [0, 4 mm]; skill-adaptive fixed at or above 2 mm.
        e = self.records["fading"]["mean_deviation_m"]
        self.assertAlmostEqual(cg.next_guidance_gain(0.4, e), min(1.0, max(0.0, 0.8 * 0.4 + 200 * e)), delta=1e-12)
        self.assertAlmostEqual(cg.next_guidance_gain(1.0, 0.0), 0.8, delta=1e-12)
        gains = [1.0]
        for _ in range(5):
            gains.append(cg.next_guidance_gain(gains[-1], 0.0001))
        self.assertTrue(all(b < a for a, b in zip(gains, gains[1:])), gains)
        self.assertEqual(cg.next_guidance_gain(0.5, 0.01), 1.0)
        self.assertAlmostEqual(cg.next_guidance_gain(0.5, 0.001, cg.FadingRule(forgetting_factor=0.5,
                                                                                error_gain_per_m=100)),
                               0.35, delta=1e-12)
        self.assertAlmostEqual(cg.next_assist_band(0.001, 0.0005), 0.002, delta=1e-12)
        self.assertEqual(cg.next_assist_band(0.001, 0.01), 0.0)
        self.assertEqual(cg.next_assist_band(0.0035, 0.0), 0.004)
        self.assertEqual(cg.skill_adaptive_mode(0.002), cg.GuidanceMode.fixed)
        self.assertEqual(cg.skill_adaptive_mode(0.0019), cg.GuidanceMode.error_amplification)
        with self.assertRaises(cg.InvalidArgument):
            cg.next_guidance_gain(1.5, 0.0)

    # ---- the teacher: its file, edited, cut, of another character, swapped -------------------------------
    def teacher(self):
        return json.loads((self.tmp / "t.json").read_text(encoding="utf-8"))

    def test_teacher_recorded_by_the_program_holds_the_documented_format_and_the_trial_s_pen(self):
        t = self.teacher()
        self.assertEqual((t["format"], t["version"], t["characters"]), ("calligraphy-teacher-recording", 1, CHAR))
        self.assertEqual(t["rate_hz"], 1000)
        for key in ("writer", "device", "library_version"):
            self.assertIsInstance(t[key], str)
        samples = t["samples"]
        self.assertEqual(sorted(samples), ["t_s", "x_m", "y_m", "z_m"])
        self.assertEqual(len({len(v) for v in samples.values()}), 1)
        self.assertTrue(all(b >= a for a, b in zip(samples["t_s"], samples["t_s"][1:])))
        tt, pos, _, _, _ = read_trace(self.tmp / "teacher.csv")
        self.assertEqual(len(samples["t_s"]), len(tt))
        self.assertLessEqual(float(np.abs(np.array(samples["t_s"]) - tt).max()), 0.5e-6 + 1e-12)
        got = np.column_stack([samples["x_m"], samples["y_m"], samples["z_m"]])
        self.assertLessEqual(float(np.abs(got - pos).max()), CSV_POS_ROUND_M + 1e-12)

    def test_replay_of_a_teacher_of_another_character_is_refused(self):
        run_ok(["trial", "一", "--writer-profile", "skilled", "--record", "t-yi.json"], self.tmp)
        result = self.cli("trial", CHAR, "--guidance-mode", "replay", "--teacher", "t-yi.json",
                          "--json", "yi-out.json")
        self.assert_one_error(result, 1, "t-yi.json")
        self.assertFalse((self.tmp / "yi-out.json").exists())
        with self.assertRaises(cg.InvalidArgument) as caught:
            cg.simulate_trial(CHAR, teacher=cg.TeacherRecording.load(str(self.tmp / "t-yi.json")))
        self.assertIn("teacher", str(caught.exception))

    def test_teacher_cut_before_its_last_stroke_is_refused(self):
        # force-rendering.md: "A stroke the teacher never wrote in order throws InvalidArgument naming it".
        t = self.teacher()
        tt, _, _, state, stroke = read_trace(self.tmp / "teacher.csv")
        cut = int(np.argmax(stroke == 1))      # the first tick whose active stroke is the second
        self.assertGreater(cut, 10)
        for key in t["samples"]:
            t["samples"][key] = t["samples"][key][:cut]
        (self.tmp / "t-cut.json").write_text(json.dumps(t), encoding="utf-8")
        result = self.cli("trial", CHAR, "--guidance-mode", "replay", "--teacher", "t-cut.json",
                          "--json", "cut-out.json")
        line = self.assert_one_error(result, 1, "stroke")
        self.assertFalse((self.tmp / "cut-out.json").exists(), line)

    def test_teacher_edited_out_of_its_format_is_refused_naming_the_file(self):
        def back_in_time(t):
            t["samples"]["t_s"][10] = t["samples"]["t_s"][9] - 0.5

        def lengths_differ(t):
            t["samples"]["y_m"].pop()

        def one_sample(t):
            for key in t["samples"]:
                t["samples"][key] = t["samples"][key][:1]

        def text_for_a_number(t):
            t["samples"]["x_m"][3] = "0.01"

        for edit, needle in ((back_in_time, "t_s"), (lengths_differ, "t-edit"), (one_sample, "t-edit"),
                             (text_for_a_number, "x_m")):
            with self.subTest(edit=edit.__name__):
                t = self.teacher()
                edit(t)
                (self.tmp / "t-edit.json").write_text(json.dumps(t), encoding="utf-8")
                result = self.cli("trial", CHAR, "--guidance-mode", "replay", "--teacher", "t-edit.json",
                                  "--json", "edit-out.json")
                self.assert_one_error(result, 1, "t-edit.json", needle)
                self.assertFalse((self.tmp / "edit-out.json").exists())
                with self.assertRaises(cg.DataError) as caught:
                    cg.TeacherRecording.load(str(self.tmp / "t-edit.json"))
                self.assertIn("t-edit.json", str(caught.exception))
                self.assertIn(needle, str(caught.exception))

    def test_trial_record_given_as_a_teacher_is_refused(self):
        result = self.cli("trial", CHAR, "--guidance-mode", "replay", "--teacher", "fixed.json", "--json", "tr-out.json")
        self.assert_one_error(result, 1, "fixed.json", "/format")
        self.assertFalse((self.tmp / "tr-out.json").exists())

    def test_record_of_a_teacher_swapped_or_edited_since_is_refused_naming_both_sha256(self):
        d = self.tmp / "swap"
        d.mkdir(exist_ok=True)
        shutil.copy(self.tmp / "t.json", d / "t.json")
        shutil.copy(self.tmp / "replay.json", d / "replay.json")
        recorded = hashlib.sha256((d / "t.json").read_bytes()).hexdigest()
        other = self.tmp / "t-seed5.json"
        run_ok(["trial", CHAR, "--writer-profile", "skilled", "--seed", "5", "--record", str(other)], self.tmp)
        reformatted = json.dumps(json.loads((d / "t.json").read_text(encoding="utf-8")), indent=2)
        for how, content in (("another recording", other.read_bytes()), ("the same re-indented",
                                                                          reformatted.encode())):
            with self.subTest(how=how):
                (d / "t.json").write_bytes(content)
                now = hashlib.sha256(content).hexdigest()
                self.assertNotEqual(now, recorded)
                result = self.cli("trial", "--spec", "replay.json", "--csv", "swap.csv", cwd=d)
                self.assert_one_error(result, 1, "t.json", recorded, now)
                self.assertFalse((d / "swap.csv").exists())
                cwd = os.getcwd()
                os.chdir(d)
                try:
                    with self.assertRaises(cg.DataError) as caught:
                        cg.rerun_trial("replay.json")
                finally:
                    os.chdir(cwd)
                self.assertIn(recorded, str(caught.exception))
                self.assertIn(now, str(caught.exception))
        # `--teacher FILE` gives the recording instead, "which must be the one the replay ran on".
        result = self.cli("trial", "--spec", "replay.json", "--teacher", str(other), "--csv", "swap.csv", cwd=d)
        self.assert_one_error(result, 1, recorded)

    def test_replay_record_re_run_from_another_folder_needs_its_teacher_given(self):
        d = self.tmp / "elsewhere"
        d.mkdir(exist_ok=True)
        record = str(self.tmp / "replay.json")
        result = self.cli("trial", "--spec", record, "--csv", "x.csv", cwd=d)
        self.assert_one_error(result, 1, "t.json", "--teacher FILE")
        self.assertFalse((d / "x.csv").exists())
        # --check: "a replay's teacher [is] checked when it runs".
        self.assertEqual(self.cli("trial", "--spec", record, "--check", cwd=d).returncode, 0)
        cwd = os.getcwd()
        os.chdir(d)
        try:
            with self.assertRaises(cg.DataError) as caught:
                cg.rerun_trial(record)
        finally:
            os.chdir(cwd)
        self.assertIn("t.json", str(caught.exception))
        self.assertIn("teacher=", str(caught.exception))
        copy = d / "copy-of-teacher.json"
        shutil.copy(self.tmp / "t.json", copy)
        result = self.cli("trial", "--spec", record, "--teacher", str(copy), "--csv", "x.csv", cwd=d)
        self.assertEqual(result.returncode, 0, result.stderr)
        self.assertEqual((d / "x.csv").read_bytes(), (self.tmp / "replay.csv").read_bytes())

    def test_spec_of_a_record_that_is_no_replay_refuses_a_teacher(self):
        # `--spec`: "only `--json`, `--csv`, `--svg`, `--teacher` (a replay's) and `--data`/`--store` go with
        # it"; `--teacher` is "`replay` only": a fixed trial's record given one.
        result = self.cli("trial", "--spec", "fixed.json", "--teacher", "t.json", "--csv", "ft.csv")
        self.assert_one_error(result, (1, 2), "--teacher")
        self.assertFalse((self.tmp / "ft.csv").exists())

    def test_record_option_refuses_a_trial_that_did_not_write_every_stroke(self):
        # --record: "refused (exit 1, nothing written) unless the trial completed every stroke in order";
        # a trial that ended at its time limit exits 1 and still writes its outputs.
        result = self.cli("trial", CHAR, "--max-duration", "1", "--record", "short-teacher.json",
                          "--json", "short.json")
        self.assertEqual(result.returncode, 1, result.stderr)
        self.assertFalse((self.tmp / "short-teacher.json").exists())
        self.assertEqual(json.loads((self.tmp / "short.json").read_text(encoding="utf-8"))["end_reason"],
                         "time_limit")

    # ---- spellings, teachers that are no file to read, outputs onto the teacher ------------------------
    def test_mode_spelt_by_its_member_name_is_refused_by_the_command_and_in_records(self):
        # python.md: "the command line and the files take only the spelling"; skill-adaptive is a choice per
        # repetition, not a trial's mode (force-rendering.md).
        for value in ("error_amplification", "assist_as_needed", "skill-adaptive", "Fading"):
            with self.subTest(value=value):
                self.assert_one_error(self.cli("trial", CHAR, "--guidance-mode", value, "--check"), 2,
                                      "--guidance-mode")
        self.refused("amplify", lambda r: r["specification"]["trial"].__setitem__("guidance_mode",
                                                                                   "error_amplification"),
                     "/specification/trial/guidance_mode")
        self.refused("assist", lambda r: r["specification"]["force_law"]["guidance_law"].__setitem__(
            "mode", "assist_as_needed"), "/specification/force_law/guidance_law")

    def test_python_mode_by_its_member_name_warns_and_records_the_spelling(self):
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            r = cg.simulate_trial(CHAR, guidance_mode="error_amplification", max_duration_s=0.5, keep_trace=False)
        notes = [str(w.message) for w in caught if issubclass(w.category, DeprecationWarning)]
        self.assertTrue(any("error-amplification" in n for n in notes), notes)
        self.assertEqual(r.metrics["guidance_mode"], "error-amplification")
        self.assertEqual(r.metrics["specification"]["trial"]["guidance_mode"], "error-amplification")
        self.assertEqual(r.metrics["specification"]["force_law"]["guidance_law"]["mode"], "error-amplification")

    def test_python_guidance_mode_keeps_the_force_law_s_values_of_that_mode(self):
        # python.md: "`guidance_mode=` picks a mode (keeping the force law's parameters when it is already of
        # that mode) and `guidance_gain=` sets the fading gain (only with fading)".
        def law_of(**kwargs):
            r = cg.simulate_trial(CHAR, max_duration_s=0.2, keep_trace=False, **kwargs)
            return r.metrics["specification"]["force_law"]["guidance_law"], r.metrics["specification"]["trial"]
        fading = cg.ForceLawParameters(guidance_law=cg.FadingGuidance(gain=0.3))
        law, trial = law_of(force_law=fading, guidance_mode="fading")
        self.assertEqual((law, trial["guidance_gain"]), ({"mode": "fading", "gain": 0.3}, 0.3))
        law, trial = law_of(force_law=fading, guidance_mode="fading", guidance_gain=0.6)
        self.assertEqual((law, trial["guidance_gain"]), ({"mode": "fading", "gain": 0.6}, 0.6))
        timing = cg.ForceLawParameters(guidance_law=cg.TimingGuidance(speed_m_s=0.06))
        law, trial = law_of(force_law=timing, guidance_mode="timing")
        self.assertEqual((law["speed_m_s"], trial["timing_speed_m_s"]), (0.06, 0.06))
        law, trial = law_of(force_law=fading, guidance_mode="assist-as-needed")
        self.assertEqual(law, {"mode": "assist-as-needed", "band_m": 0.001})
        with self.assertRaises(cg.InvalidArgument) as caught:
            cg.simulate_trial(CHAR, guidance_mode="timing", guidance_gain=0.5, max_duration_s=0.2, keep_trace=False)
        self.assertIn("guidance_gain", str(caught.exception))

    def test_teacher_that_is_no_regular_file_is_refused_without_waiting(self):
        # teacher_recording.hpp: DataError naming the path when it "is not a regular file, is larger than
        # kMaxTeacherRecordingBytes" (256 MiB).
        (self.tmp / "t-folder").mkdir(exist_ok=True)
        fifo = self.tmp / "t-fifo"
        if not fifo.exists():
            os.mkfifo(fifo)
        with open(self.tmp / "t-huge.json", "wb") as f:
            f.truncate((256 << 20) + 1)
        for name in ("t-folder", "t-fifo", "t-huge.json"):
            with self.subTest(teacher=name):
                result = run(["trial", CHAR, "--guidance-mode", "replay", "--teacher", name, "--json", "nf.json"],
                             self.tmp, timeout=30)
                self.assert_one_error(result, 1, name)
                self.assertFalse((self.tmp / "nf.json").exists())

    def test_teacher_named_as_an_output_too_is_refused_and_kept(self):
        # cli.md "Output identity": no output may be the same file as an input, `--teacher` named; exit 2
        # naming both options.
        before = (self.tmp / "t.json").read_bytes()
        for option in ("--json", "--csv", "--record"):
            with self.subTest(option=option):
                result = self.cli("trial", CHAR, "--guidance-mode", "replay", "--teacher", "t.json", option, "./t.json")
                self.assert_one_error(result, 2, "--teacher", option)
                self.assertEqual((self.tmp / "t.json").read_bytes(), before)

    def test_teacher_recording_on_standard_output_is_refused(self):
        # trial_spec.hpp validate: "a teacher's recording on standard output"; --record takes FILE, not FILE|-.
        self.assert_one_error(self.cli("trial", CHAR, "--record", "-"), 2, "--record")

    def test_record_edited_to_another_amplification_bound_re_runs_and_says_it_differs(self):
        # cli.md: a re-run by the simulated writer, lock-step, "that gives another value says so in one line".
        record = self.record("amplify")
        record["specification"]["force_law"]["guidance_law"]["max_force_n"] = 0.02
        self.write_record("amp-edit.json", record)
        result = self.cli("trial", "--spec", "amp-edit.json", "--json", "amp-edit-out.json")
        self.assertEqual(result.returncode, 0, result.stderr)
        lines = result.stderr.decode().strip().splitlines()
        self.assertEqual(len(lines), 1, lines)
        self.assertIn("differs", lines[0])
        out = json.loads((self.tmp / "amp-edit-out.json").read_text(encoding="utf-8"))
        self.assertEqual(out["specification"]["force_law"]["guidance_law"]["max_force_n"], 0.02)
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            again = cg.rerun_trial(str(self.tmp / "amp-edit.json"))
        self.assertTrue(any(issubclass(w.category, RuntimeWarning) for w in caught))
        self.assertEqual(again.metrics["max_force_n"], out["max_force_n"])

    def test_teacher_of_a_shorter_row_of_characters_is_refused(self):
        result = self.cli("trial", CHAR + "一", "--guidance-mode", "replay", "--teacher", "t.json", "--json", "row.json")
        self.assert_one_error(result, 1, "t.json")
        self.assertFalse((self.tmp / "row.json").exists())

    # ---- more: modes with no guiding force, contradictions, teachers at a re-run -------------------------
    def test_every_mode_with_no_guiding_force_writes_one_trace(self):
        # force-rendering.md: fading g K a (..), assist-as-needed K a (d - b)+ (..), error amplification
        # g K a (..): with g = 0, a band wider than the constraint space, or K_et = 0 none pulls, and
        # "everything else (state machine, active stroke, resistance, friction, smoothing, passivity
        # controller, safety chain) is the same in every mode".
        runs = {"fading0": ["--guidance-mode", "fading", "--guidance-gain", "0"],
                "band": ["--guidance-mode", "assist-as-needed", "--assist-band", "0.1"],
                "amp0": ["--guidance-mode", "error-amplification", "--amplification-gain", "0"],
                "k0": ["--guidance-stiffness", "0"]}
        for name, options in runs.items():
            run_ok(["trial", CHAR, *options, "--csv", f"nopull-{name}.csv"], self.tmp)
        first = (self.tmp / "nopull-fading0.csv").read_bytes()
        for name in runs:
            with self.subTest(mode=name):
                self.assertEqual((self.tmp / f"nopull-{name}.csv").read_bytes(), first)
        self.assertNotEqual(first, (self.tmp / "fixed.csv").read_bytes())

    def test_record_contradicting_its_force_law_s_guidance_is_refused(self):
        # python.md check_trial_record: "a value ... out of its field's range ... raises DataError naming the
        # JSON pointer, and so does a contradiction between fields"; cli.md: the record's `trial` holds the
        # specification's fields, its `force_law` the guidance and the guidance law (`mode` and that mode's own
        # values) that ran. A record saying fading at 0.7 whose law ran 0.4 states two trials.
        cases = [("fading", ("trial", "guidance_mode"), "timing"),
                 ("fading", ("force_law", "guidance"), False),
                 ("fading", ("trial", "guidance_gain"), 0.7),
                 ("assist", ("trial", "assist_band_m"), 0.003),
                 ("amplify", ("trial", "amplification_gain"), 0.9),
                 ("timing", ("trial", "timing_speed_m_s"), 0.3)]
        for name, path, value in cases:
            with self.subTest(mode=name, field="/".join(path)):
                record = self.record(name)
                record["specification"][path[0]][path[1]] = value
                self.write_record("contradiction.json", record)
                (self.tmp / "contradiction.csv").unlink(missing_ok=True)
                result = self.cli("trial", "--spec", "contradiction.json", "--csv", "contradiction.csv")
                self.assert_one_error(result, 2, "contradiction.json", "/specification/")
                self.assertFalse((self.tmp / "contradiction.csv").exists())
                with self.assertRaises(cg.DataError):
                    cg.check_trial_record(str(self.tmp / "contradiction.json"))

    def test_python_rerun_of_a_replay_with_another_teacher_is_not_silent(self):
        # cli.md: `--teacher FILE` "must be the one the replay ran on"; a re-run that gives other figures
        # "is not run silently" (python.md: a RuntimeWarning).
        other = self.tmp / "t-other.json"
        if not other.exists():
            run_ok(["trial", CHAR, "--writer-profile", "skilled", "--seed", "9", "--record", str(other)], self.tmp)
        teacher = cg.TeacherRecording.load(str(other))
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            try:
                again = cg.rerun_trial(str(self.tmp / "replay.json"), teacher=teacher)
            except (cg.DataError, cg.InvalidArgument) as error:
                self.assertIn("teacher", str(error))
                return
        if again.metrics["trial_time_s"] != self.records["replay"]["trial_time_s"] or \
                again.metrics["max_force_n"] != self.records["replay"]["max_force_n"]:
            self.assertTrue(any(issubclass(w.category, RuntimeWarning) for w in caught),
                            "another teacher gave another trial, silently")

    def test_python_rerun_of_a_record_without_replay_refuses_a_teacher(self):
        # As `trial --spec fixed.json --teacher t.json` refuses it, and as simulate_trial raises for "a
        # teacher with another mode ... naming `teacher`".
        with self.assertRaises((cg.InvalidArgument, cg.DataError)) as caught:
            cg.rerun_trial(str(self.tmp / "fixed.json"), teacher=cg.TeacherRecording.load(str(self.tmp / "t.json")))
        self.assertIn("teacher", str(caught.exception))

    def test_spec_of_a_python_replay_that_names_no_teacher_file_needs_one(self):
        r = cg.simulate_trial(CHAR, teacher=cg.TeacherRecording.load(str(self.tmp / "t.json")), max_duration_s=2.0)
        spec = r.metrics["specification"]
        self.assertEqual((spec["trial"]["teacher"], spec["teacher_sha256"]), ("", ""))
        self.write_record("py-replay.json", dict(r.metrics))
        result = self.cli("trial", "--spec", "py-replay.json", "--csv", "py-replay.csv")
        self.assert_one_error(result, (1, 2), "teacher")
        self.assertFalse((self.tmp / "py-replay.csv").exists())

    def test_record_naming_a_copy_of_its_teacher_re_runs_the_same(self):
        # cli.md: "the re-run reads the file the record names", bound by its SHA-256.
        copy = self.tmp / "copies" / "teacher copy.json"
        copy.parent.mkdir(exist_ok=True)
        shutil.copy(self.tmp / "t.json", copy)
        record = self.record("replay")
        record["specification"]["trial"]["teacher"] = str(copy)
        self.write_record("renamed.json", record)
        result = self.cli("trial", "--spec", "renamed.json", "--csv", "renamed.csv")
        self.assertEqual(result.returncode, 0, result.stderr)
        self.assertEqual((self.tmp / "renamed.csv").read_bytes(), (self.tmp / "replay.csv").read_bytes())

    def test_replay_record_of_version_3_notes_the_teacher_sha256_it_lacks(self):
        # cli.md: version 3 was "written before ... a replay named its teacher's SHA-256"; "A field added in a
        # later version than the record's takes its default, and `trial --spec` says which on standard error".
        record = self.record("replay")
        record["specification"]["version"] = 3
        del record["specification"]["teacher_sha256"]
        self.write_record("v3-replay.json", record)
        result = self.cli("trial", "--spec", "v3-replay.json", "--json", "v3-replay-out.json")
        self.assertIn(result.returncode, (0, 1), result.stderr)
        self.assertNotIn(b"Traceback", result.stderr)
        self.assertIn("/specification/teacher_sha256", result.stderr.decode())
        out = json.loads((self.tmp / "v3-replay-out.json").read_text(encoding="utf-8"))
        self.assertEqual(out["specification"]["teacher_sha256"],
                         hashlib.sha256((self.tmp / "t.json").read_bytes()).hexdigest())

    # ---- records edited ----------------------------------------------------------------------------------
    def refused(self, name, change, *needles):
        record = self.record(name)
        change(record)
        filename = self.write_record("edited.json", record)
        line = self.assert_one_error(self.cli("trial", "--spec", filename, "--check"), 2, "edited.json", *needles)
        with self.assertRaises(cg.DataError) as caught:
            cg.check_trial_record(str(self.tmp / filename))
        for needle in needles:
            self.assertIn(needle, str(caught.exception))
        return line

    def test_record_mode_values_out_of_range_are_refused_at_their_pointers(self):
        line = self.refused("fading", lambda r: r["specification"]["trial"].__setitem__("guidance_gain", 1.5),
                            "/specification/trial/guidance_gain")
        self.assertIn("edited.json: /specification/trial/guidance_gain: expected a number in [0, 1] "
                      "(TrialSpec.guidance_gain), got 1.5", line)
        line = self.refused("fading", lambda r: r["specification"]["force_law"]["guidance_law"].__setitem__("gain", 1.5),
                            "/specification/force_law/guidance_law/gain")
        self.assertIn("FadingGuidance.gain", line)
        cases = [("timing", ("trial", "timing_speed_m_s"), 0),
                 ("timing", ("force_law", "guidance_law", "speed_m_s"), 1.5),
                 ("assist", ("trial", "assist_band_m"), 0.2),
                 ("assist", ("force_law", "guidance_law", "band_m"), -0.001),
                 ("amplify", ("trial", "amplification_gain"), 1.2),
                 ("amplify", ("force_law", "guidance_law", "max_force_n"), -1.0),
                 ("replay", ("force_law", "guidance_law", "max_lead_m"), 0.0)]
        for name, path, value in cases:
            with self.subTest(mode=name, path=path):
                def change(r, path=path, value=value):
                    node = r["specification"]
                    for part in path[:-1]:
                        node = node[part]
                    node[path[-1]] = value
                self.refused(name, change, "/specification/" + "/".join(path))

    def test_record_moving_target_lead_beyond_the_constraint_space_is_refused(self):
        # force-rendering.md: "a moving target's `max_lead_m` is at most R_res" (6 mm).
        for name in ("timing", "replay"):
            with self.subTest(mode=name):
                self.refused(name, lambda r: r["specification"]["force_law"]["guidance_law"].__setitem__(
                    "max_lead_m", 0.007), "max_lead_m")

    def test_record_guidance_law_with_another_mode_s_value_is_refused(self):
        # docs/cli.md: `guidance_law` holds "`mode` and that mode's own values only"; no key is unknown.
        self.refused("fading", lambda r: r["specification"]["force_law"]["guidance_law"].__setitem__("band_m", 0.001),
                     "/specification/force_law/guidance_law")
        self.refused("fixed", lambda r: r["specification"]["force_law"]["guidance_law"].__setitem__("gain", 1.0),
                     "/specification/force_law/guidance_law")

    def test_record_with_guidance_off_and_a_mode_gives_the_documented_contradiction(self):
        def change(r):
            r["specification"]["trial"]["guidance"] = False
            r["specification"]["force_law"]["guidance"] = False
        line = self.refused("fading", change, "/specification/trial/guidance_mode")
        self.assertIn("guidance_mode (--guidance-mode): 'fading' needs guidance on (guidance is off)", line)

    def test_record_naming_a_teacher_without_a_replay_is_refused(self):
        # trial_spec.hpp validate: "a replay without a teacher or a teacher without a replay".
        self.refused("fixed", lambda r: r["specification"]["trial"].__setitem__("teacher", "t.json"),
                     "/specification/trial/teacher")

    def test_replay_record_naming_its_teacher_without_its_sha256_is_refused(self):
        self.refused("replay", lambda r: r["specification"].__setitem__("teacher_sha256", ""),
                     "/specification/teacher_sha256")

    # ---- Python: the same modes ---------------------------------------------------------------------------
    def test_python_mode_asked_with_guidance_off_or_without_its_teacher_raises_naming_it(self):
        teacher = cg.TeacherRecording.load(str(self.tmp / "t.json"))
        for kwargs, needle in (({"guidance": False, "guidance_mode": "timing"}, "guidance_mode"),
                               ({"guidance": False, "guidance_mode": "fading", "guidance_gain": 0.5}, "guidance_mode"),
                               ({"guidance": False, "teacher": teacher}, "guidance_mode"),
                               ({"guidance_mode": "replay"}, "teacher"),
                               ({"guidance_mode": "fading", "teacher": teacher}, "teacher")):
            with self.subTest(kwargs=sorted(kwargs)):
                with self.assertRaises(cg.InvalidArgument) as caught:
                    cg.simulate_trial(CHAR, max_duration_s=1.0, keep_trace=False, **kwargs)
                self.assertIn(needle, str(caught.exception))

    def test_python_record_of_each_law_re_runs_on_the_command_line_to_its_arrays(self):
        laws = {"amplify": cg.ErrorAmplificationGuidance(gain=0.4, max_force_n=0.2),
                "timing": cg.TimingGuidance(speed_m_s=0.05, max_lead_m=0.002)}
        for name, law in laws.items():
            with self.subTest(law=name):
                r = cg.simulate_trial(CHAR, force_law=cg.ForceLawParameters(guidance_law=law), seed=3)
                self.assertEqual(r.metrics["end_reason"], "completed")
                stated = r.metrics["specification"]["force_law"]["guidance_law"]
                self.assertEqual(stated, dict(law.to_dict(), mode=r.metrics["guidance_mode"]))
                self.write_record(f"py-{name}.json", dict(r.metrics))
                result = self.cli("trial", "--spec", f"py-{name}.json", "--csv", f"py-{name}.csv")
                self.assertEqual(result.returncode, 0, result.stderr)
                self.assertEqual(result.stderr, b"")
                _, pos, force, _, _ = read_trace(self.tmp / f"py-{name}.csv")
                self.assertEqual(pos.shape, r.position_m.shape)
                self.assertLessEqual(float(np.abs(r.position_m - pos).max()), CSV_POS_ROUND_M + 1e-12)
                self.assertLessEqual(float(np.abs(r.force_n - force).max()), CSV_FORCE_ROUND_N + 1e-12)

    def test_python_replay_of_a_teacher_given_as_samples_re_runs_only_with_it(self):
        teacher = cg.TeacherRecording.load(str(self.tmp / "t.json"))
        r = cg.simulate_trial(CHAR, teacher=teacher)
        self.assertEqual(r.metrics["guidance_mode"], "replay")
        self.assertEqual(r.metrics["end_reason"], "completed")
        with self.assertRaises(cg.InvalidArgument) as caught:
            cg.rerun_trial(r.metrics)
        self.assertIn("teacher", str(caught.exception))
        again = cg.rerun_trial(r.metrics, teacher=teacher)
        self.assertTrue((again.position_m == r.position_m).all())
        self.assertTrue((again.force_n == r.force_n).all())


if __name__ == "__main__":
    unittest.main()
