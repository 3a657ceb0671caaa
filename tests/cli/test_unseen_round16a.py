#!/usr/bin/env python3
"""Round 16A: the force the library sends to the device, recomputed from the docs alone (docs/force-rendering.md,
docs/servo-loop.md, docs/devices.md, docs/stroke-acceptance.md and the paper's sections 4 and 5: eqs. 7-9, the
constraint space, the attraction factor, the states of Table 2). Run by CTest as `cli_unseen_round16a_tests`.

Two kinds of case. A Python `Renderer` ticked by hand along 一 and 口 (positions and velocities chosen here),
with the smoothing switched off where a case recomputes a law exactly, every force held to the documented
formula computed here with numpy from the model's control points: eq. (8) and (9), the fading gain, the
assist-as-needed band, error amplification's push and cap, timing's tangent-only pull, a replayed teacher's
saturated pull, the resistance of Fig. 4 in every mode (none under timing), the taper's smoothstep, paper
damping, friction with its stick band, the off-stroke spring in CS and damper in WS, the attraction factor
between feature points, the frame (a raised paper, a shifted row), the cross-fade and the paper fade, the end
neighbourhood, pen up, the character finished, non-finite states, the passivity observer and damper, and each
stage of the safety chain (peak clamp, vector rate limit, start ramp, low-pass, continuous-force limit); the
default device's passivity bound and the smoothing parameters' documented "0 is the paper". Then whole
simulated trials of 十 (`calligraphy trial --csv` in every guidance mode and unguided, Python's
`simulate_trial` of the same) whose traces are held to the caps, the rate limit, eq. (9) tick by tick, zero
force in SS and AS, the guidance's direction, the units of the CSV and of Python, an edited record's own rate
limit, a weaker device's peak, 10 kHz, and a re-run giving the same force bit for bit.

The trace has no velocity column (docs/cli.md): the laws on velocity are checked on the hand-ticked Renderer,
whose velocities are the test's own. CALLIGRAPHY_CLI names the program, PYTHONPATH its Python module,
CALLIGRAPHY_SOURCE_DIR the source tree (for the one docs sentence checked). CALLIGRAPHY_SANITIZED=1 takes five
cases.
"""
import csv
import json
import math
import os
import re
import shutil
import tempfile
import unittest
from pathlib import Path

import numpy as np

import calligraphy as cg
from outsider import run, sanitized_subset

load_tests = sanitized_subset({"test_fixed_guidance_is_eq8_and_the_paper_eq9",
                               "test_fading_gain_scales_the_guidance_exactly",
                               "test_peak_clamp_keeps_the_direction",
                               "test_rate_limit_is_a_vector_limit",
                               "test_every_mode_stays_within_the_caps_and_the_rate_limit"})

RATE = 1000.0
T = 1.0 / RATE
K_ET, K_EN, R_RES = 400.0, 800.0, 0.006  # docs/force-rendering.md's defaults
# Every smoothing parameter off ("setting it to 0 gives the paper's behaviour"); the foot-speed limit has no
# off value (it must be > 0), so a speed no pen reaches stands for it.
# In 一's box (its strokes' bounding box and margin, Table 1), far from its stroke's start: CS.
IN_BOX = (0.005, -0.0045)
PAPER_LAW = dict(friction_coefficient=0.0, constraint_taper_m=0.0, crossfade_s=0.0, paper_fade_s=0.0,
                 max_foot_speed_m_s=1000.0, off_stroke_force_n=0.0, off_stroke_damping_n_s_per_m=0.0)


def no_chain(**kw):
    """A safety chain with its start ramp and per-tick limit off (peak and continuous forces the device's)."""
    return cg.SafetyChainParameters(**{"start_ramp_n_per_s": 0.0, "max_force_change_n_per_tick": 0.0, **kw})


def smoothstep(x):
    x = np.clip(x, 0.0, 1.0)
    return x * x * (3.0 - 2.0 * x)


def foot_on_segment(p, a, b):
    """The foot point of p (2,) on the segment a-b and its parameter in [0, 1]."""
    ab = b - a
    u = float(np.clip(np.dot(p - a, ab) / np.dot(ab, ab), 0.0, 1.0))
    return a + u * ab, u


def bezier(control, u):
    """Points (N, 2) of the Bezier curve of `control` (n, 2) at parameters u (N,), by de Casteljau."""
    points = np.repeat(np.asarray(control, float)[None], len(u), axis=0)
    u = np.asarray(u, float)[:, None]
    while points.shape[1] > 1:
        points = (1.0 - u[:, :, None]) * points[:, :-1] + u[:, :, None] * points[:, 1:]
    return points[:, 0]


def foot_on_element(p, control):
    """The foot point of p on an element of any degree and its curve parameter, by a dense search refined by
    golden-section steps (independent of the library's nearest-point code)."""
    if len(control) == 2:
        return foot_on_segment(p, np.asarray(control[0], float), np.asarray(control[1], float))
    u = np.linspace(0.0, 1.0, 4001)
    i = int(np.argmin(np.linalg.norm(bezier(control, u) - p, axis=1)))
    lo, hi = u[max(i - 1, 0)], u[min(i + 1, len(u) - 1)]
    g = (math.sqrt(5.0) - 1.0) / 2.0
    for _ in range(80):
        m1, m2 = hi - g * (hi - lo), lo + g * (hi - lo)
        d1, d2 = (np.linalg.norm(bezier(control, [m]) - p) for m in (m1, m2))
        lo, hi = (lo, m2) if d1 < d2 else (m1, hi)
    u = 0.5 * (lo + hi)
    return bezier(control, [u])[0], u


def along(polyline, speed, offset=0.0, z=-0.001, start=0.0, stop=None, rate=RATE):
    """Positions (N, 3) and velocities (N, 3) of a pen moving at `speed` along `polyline` (M, 2) from arc length
    `start` to `stop`, `offset` metres to the left of each segment, at height z."""
    poly = np.asarray(polyline, float)
    seg = np.diff(poly, axis=0)
    length = np.hypot(seg[:, 0], seg[:, 1])
    s = np.r_[0.0, np.cumsum(length)]
    stop = s[-1] if stop is None else stop
    n = int(round((stop - start) / speed * rate)) + 1
    d = start + np.arange(n) * speed / rate
    i = np.clip(np.searchsorted(s, d, side="right") - 1, 0, len(seg) - 1)
    tangent = seg[i] / length[i][:, None]
    normal = np.c_[-tangent[:, 1], tangent[:, 0]]
    xy = poly[i] + tangent * (d - s[i])[:, None] + offset * normal
    positions = np.c_[xy, np.full(n, z)]
    velocities = np.c_[tangent * speed, np.zeros(n)]
    return positions, velocities


class Pen:
    """A Renderer ticked by hand: each tick's DeviceState is given here, each output kept."""

    def __init__(self, scene, law=None, safety=None, rate=RATE, passivity=None):
        options = cg.RendererOptions(rate_hz=rate, safety=safety or cg.SafetyChainParameters(),
                                     passivity=passivity or cg.PassivityParameters())
        self.renderer = cg.Renderer(scene, law or cg.ForceLawParameters(), options=options)
        self.period = 1.0 / rate
        self.t = 0.0
        self.out = []
        self.pos = []
        self.vel = []

    def tick(self, p, v=(0.0, 0.0, 0.0)):
        out = self.renderer.tick(cg.DeviceState(position_m=tuple(map(float, p)), velocity_m_s=tuple(map(float, v)),
                                                time_s=self.t))
        self.t += self.period
        self.out.append(out)
        self.pos.append(np.asarray(p, float))
        self.vel.append(np.asarray(v, float))
        return out

    def go(self, positions, velocities=None):
        first = len(self.out)
        for k, p in enumerate(positions):
            self.tick(p, (0.0, 0.0, 0.0) if velocities is None else velocities[k])
        return range(first, len(self.out))

    def hold(self, p, ticks, v=(0.0, 0.0, 0.0)):
        return self.go([p] * ticks, [v] * ticks)

    def touch_down(self, xy, z=-0.001, paper_z=0.0):
        """From 2 mm above the paper at xy straight down to z in 1 mm steps (a touch-down from SS)."""
        for h in (0.002, 0.001, 0.0):
            self.tick((xy[0], xy[1], paper_z + h), (0.0, 0.0, -0.05))
        return self.tick((xy[0], xy[1], z), (0.0, 0.0, -0.05))

    def force(self, ticks=None):
        f = np.array([o.force_n for o in self.out])
        return f if ticks is None else f[list(ticks)]


def yi():
    scene = cg.Scene("一")
    stroke = scene.characters[0].strokes[0]
    elements = [np.asarray(e.control_points, float) for e in stroke.elements]
    return scene, stroke, elements


def write_yi(pen, stroke, offset, speed=0.04, stop_before_end=0.0, z=-0.001):
    """Touch down at 一's start and write along its median with `offset` to the left; the ticks of the pass."""
    positions, velocities = along(stroke.median_m, speed, offset=offset, z=z, rate=1.0 / pen.period,
                                  stop=float(np.sum(np.hypot(*np.diff(stroke.median_m, axis=0).T))) - stop_before_end)
    pen.touch_down(positions[0][:2], z)
    return pen.go(positions, velocities)


def middle_ticks(pen, ticks, elements, margin=R_RES + 0.0005):
    """The ticks on 一's long middle element (element 1) farther than `margin` from both of its ends: no slack of
    a following element's corner there (docs/force-rendering.md, "a hand rounding a corner")."""
    a, b = elements[1]
    chosen = []
    for k in ticks:
        o = pen.out[k]
        if o.state != cg.InteractionState.writing or o.element != 1:
            continue
        foot, u = foot_on_segment(pen.pos[k][:2], a, b)
        if np.linalg.norm(foot - a) > margin and np.linalg.norm(b - foot) > margin:
            chosen.append(k)
    return chosen


class ForceLawByHand(unittest.TestCase):
    """A Renderer ticked along 一 (and 口), every force held to the documented law computed here."""

    def paper_pen(self, law=None, safety=None, rate=RATE, **law_fields):
        scene, stroke, elements = yi()
        law = law or cg.ForceLawParameters(**{**PAPER_LAW, **law_fields})
        return Pen(scene, law, safety or no_chain(), rate=rate), stroke, elements

    def expected_eq8(self, pen, ticks, elements, gain=1.0):
        a, b = elements[1]
        feet = np.array([foot_on_segment(pen.pos[k][:2], a, b)[0] for k in ticks])
        return gain * K_ET * 1.0 * (feet - np.array([pen.pos[k][:2] for k in ticks]))

    def test_fixed_guidance_is_eq8_and_the_paper_eq9(self):
        for offset in (0.002, -0.003):
            pen, stroke, elements = self.paper_pen()
            ticks = middle_ticks(pen, write_yi(pen, stroke, offset), elements)
            self.assertGreater(len(ticks), 300, offset)
            f = pen.force(ticks)
            np.testing.assert_allclose(f[:, :2], self.expected_eq8(pen, ticks, elements), rtol=0, atol=1e-9)
            np.testing.assert_allclose(f[:, 2], K_EN * 0.001, rtol=0, atol=1e-12)  # eq. (9), +z out of the paper
            self.assertTrue(all(pen.out[k].in_constraint_space for k in ticks))

    def test_fading_gain_scales_the_guidance_exactly(self):
        fixed, stroke, elements = self.paper_pen()
        write_yi(fixed, stroke, 0.002)
        for gain in (0.3, 0.0):
            law = cg.ForceLawParameters(**PAPER_LAW, guidance_law=cg.FadingGuidance(gain=gain))
            pen, _, _ = self.paper_pen(law=law)
            ticks = middle_ticks(pen, write_yi(pen, stroke, 0.002), elements)
            self.assertEqual(ticks, middle_ticks(fixed, range(len(fixed.out)), elements))
            np.testing.assert_allclose(pen.force(ticks)[:, :2], gain * fixed.force(ticks)[:, :2], rtol=1e-12, atol=0)
            if gain == 0.0:
                self.assertTrue(np.all(pen.force(ticks)[:, :2] == 0.0), "g = 0 is no in-plane force at all")

    def test_assist_as_needed_acts_on_the_excess_beyond_the_band(self):
        band = 0.001
        law = cg.ForceLawParameters(**PAPER_LAW, guidance_law=cg.AssistAsNeededGuidance(band_m=band))
        for offset in (0.0005, -0.0009, 0.0025):
            pen, stroke, elements = self.paper_pen(law=law)
            ticks = middle_ticks(pen, write_yi(pen, stroke, offset), elements)
            a, b = elements[1]
            for k in ticks:
                p = pen.pos[k][:2]
                foot = foot_on_segment(p, a, b)[0]
                d = np.linalg.norm(foot - p)
                expected = K_ET * max(d - band, 0.0) * (foot - p) / d
                np.testing.assert_allclose(pen.out[k].force_n[:2], expected, rtol=0, atol=1e-9,
                                           err_msg=str((offset, k)))

    def test_error_amplification_pushes_away_and_stops_at_its_cap(self):
        gain, cap = 0.25, 0.3
        law = cg.ForceLawParameters(**PAPER_LAW, guidance_law=cg.ErrorAmplificationGuidance(gain=gain, max_force_n=cap))
        seen_capped = False
        for offset in (0.002, -0.001, 0.0045):
            pen, stroke, elements = self.paper_pen(law=law)
            ticks = middle_ticks(pen, write_yi(pen, stroke, offset), elements)
            a, b = elements[1]
            for k in ticks:
                p = pen.pos[k][:2]
                foot = foot_on_segment(p, a, b)[0]
                spring = gain * K_ET * (p - foot)
                n = np.linalg.norm(spring)
                expected = spring if n <= cap else spring * cap / n
                seen_capped |= n > cap
                np.testing.assert_allclose(pen.out[k].force_n[:2], expected, rtol=0, atol=1e-9,
                                           err_msg=str((offset, k)))
                self.assertLessEqual(np.linalg.norm(pen.out[k].force_n[:2]), cap + 1e-12)
        self.assertTrue(seen_capped, "4.5 mm off at 100 N/m asks 0.45 N: above the 0.3 N cap")

    def test_timing_pulls_along_the_stroke_only_and_saturates(self):
        lead = 0.003
        law = cg.ForceLawParameters(**PAPER_LAW, guidance_law=cg.TimingGuidance(speed_m_s=0.04, max_lead_m=lead))
        for speed in (0.01, 0.08):  # held back by a slow pen, holding back a fast one
            pen, stroke, elements = self.paper_pen(law=law)
            ticks = middle_ticks(pen, write_yi(pen, stroke, 0.002, speed=speed), elements)
            a, b = elements[1]
            t = (b - a) / np.linalg.norm(b - a)
            f = pen.force(ticks)[:, :2]
            across = f[:, 0] * t[1] - f[:, 1] * t[0]
            np.testing.assert_allclose(across, 0.0, rtol=0, atol=1e-12)
            self.assertTrue(np.all(np.linalg.norm(f, axis=1) <= K_ET * lead + 1e-9))
            sign = np.sign(f @ t)
            # the slow pen is pulled forward, the fast one held back, each at some tick
            self.assertIn(1.0 if speed < 0.04 else -1.0, set(sign.tolist()), speed)
            if speed < 0.04:
                self.assertAlmostEqual(float(np.max(np.linalg.norm(f, axis=1))), K_ET * lead, delta=1e-9)

    def test_replay_pulls_towards_the_teacher_and_saturates_at_max_lead(self):
        lead = 0.003
        scene, stroke, elements = yi()
        # a teacher writing 一 along its median at 80 mm/s, touching down and lifting
        positions, _ = along(stroke.median_m, 0.08)
        samples = [(0.0, (*positions[0][:2], 0.002)), (0.001, (*positions[0][:2], 0.001)),
                   (0.002, (*positions[0][:2], 0.0))]
        samples += [(0.003 + k * T, tuple(p)) for k, p in enumerate(positions)]
        end_t = samples[-1][0]
        samples += [(end_t + k * T, (*positions[-1][:2], 0.001 * k)) for k in range(1, 6)]
        teacher = [cg.TeacherSample(time_s=t, position_m=p) for t, p in samples]
        replay = cg.ReplayGuidance(max_lead_m=lead)
        replay.teacher_trajectory = teacher  # a field of the law, not a keyword (docs/python.md: "with")
        law = cg.ForceLawParameters(**PAPER_LAW, guidance_law=replay)
        pen = Pen(scene, law, no_chain())
        ticks = write_yi(pen, stroke, 0.0, speed=0.02, stop_before_end=0.028)  # a slow pen, stopped at 40 %
        held = pen.hold(pen.pos[ticks[-1]], 300)  # the teacher has long finished: its point is at the element's end
        self.assertEqual(pen.out[held[-1]].element, 1)
        inplane = np.linalg.norm(pen.force(range(ticks[0], held[-1] + 1))[:, :2], axis=1)
        self.assertLessEqual(float(np.max(inplane)), K_ET * lead + 1e-9, "at most K_et a max_lead_m")
        b = elements[1][1]
        p = pen.pos[held[-1]][:2]
        np.testing.assert_allclose(pen.out[held[-1]].force_n[:2], K_ET * lead * (b - p) / np.linalg.norm(b - p),
                                   rtol=0, atol=1e-9)

    def test_resistance_only_against_writing_backwards(self):
        pen, stroke, elements = self.paper_pen()
        write_yi(pen, stroke, 0.0, stop_before_end=0.02)
        a, b = elements[1]
        t = (b - a) / np.linalg.norm(b - a)
        on_line = a + 0.45 * (b - a)  # on the element itself: F_et = 0 exactly
        p = (on_line[0], on_line[1], -0.001)
        for v_along, expected in ((0.03, 0.0), (-0.05, 15.0 * 0.05), (-0.002, 15.0 * 0.002)):
            v = (t[0] * v_along, t[1] * v_along, 0.0)
            f = np.asarray(pen.tick(p, v).force_n)
            np.testing.assert_allclose(f[:2], expected * t, rtol=0, atol=1e-9, err_msg=str(v_along))
            np.testing.assert_allclose(f[2], 0.8, atol=1e-12)

    def test_resistance_stays_in_every_mode_but_timing(self):
        laws = {"fading": cg.FadingGuidance(gain=0.0), "assist-as-needed": cg.AssistAsNeededGuidance(band_m=0.004),
                "error-amplification": cg.ErrorAmplificationGuidance(), "timing": cg.TimingGuidance()}
        for mode, guidance_law in laws.items():
            pen, stroke, elements = self.paper_pen(law=cg.ForceLawParameters(**PAPER_LAW, guidance_law=guidance_law))
            write_yi(pen, stroke, 0.0, speed=0.02, stop_before_end=0.025)
            a, b = elements[1]
            t = (b - a) / np.linalg.norm(b - a)
            on_line = a + 0.4 * (b - a)
            p = (on_line[0], on_line[1], -0.001)
            pen.tick(p)
            at_rest = np.asarray(pen.out[-1].force_n)
            backwards = np.asarray(pen.tick(p, (-0.05 * t[0], -0.05 * t[1], 0.0)).force_n)
            if mode == "timing":  # its target's pull only, along the stroke: no resistance of Fig. 4
                np.testing.assert_allclose(backwards, at_rest, rtol=0, atol=1e-12, err_msg=mode)
                self.assertGreater(float(np.dot(at_rest[:2], t)), 0.0, "the target is ahead of a pen at 40 % of 一")
            else:  # on the element F_et is zero in these modes: what is left is -b (v . t) t
                np.testing.assert_allclose(at_rest[:2], 0.0, atol=1e-12, err_msg=mode)
                np.testing.assert_allclose(backwards[:2], 15.0 * 0.05 * t, rtol=0, atol=1e-9, err_msg=mode)

    def test_a_pen_exactly_on_the_element_gives_no_nan_in_any_mode(self):
        # d = 0: assist-as-needed's (X_S - X_p) / d with a band of 0 is 0 / 0 unless the law guards it
        laws = {"fixed": cg.FixedGuidance(), "assist-as-needed, band 0": cg.AssistAsNeededGuidance(band_m=0.0),
                "error-amplification": cg.ErrorAmplificationGuidance(), "timing": cg.TimingGuidance()}
        for name, guidance_law in laws.items():
            pen, stroke, elements = self.paper_pen(law=cg.ForceLawParameters(**PAPER_LAW, guidance_law=guidance_law))
            write_yi(pen, stroke, 0.0, stop_before_end=0.025)
            a, b = elements[1]
            for u in (0.4, 0.45, 0.5):
                on = a + u * (b - a)
                out = pen.tick((on[0], on[1], -0.001))
                self.assertFalse(out.force_error, name)
                self.assertTrue(np.all(np.isfinite(out.force_n)), name)
                self.assertAlmostEqual(out.force_n[2], 0.8, delta=1e-12, msg=name)  # the paper's force kept
                if name != "timing":
                    np.testing.assert_allclose(out.force_n[:2], 0.0, atol=1e-12, err_msg=name)

    def test_no_guidance_outside_the_constraint_space(self):
        pen, stroke, elements = self.paper_pen()
        ticks = write_yi(pen, stroke, 0.0, stop_before_end=0.025)
        a, b = elements[1]
        p0 = pen.pos[ticks[-1]]
        normal = np.array([-(b - a)[1], (b - a)[0]]) / np.linalg.norm(b - a)
        foot = foot_on_segment(p0[:2], a, b)[0]
        for d in (0.0055, 0.0059, 0.0061, 0.0075, 0.012):
            xy = foot + d * normal
            out = pen.tick((xy[0], xy[1], -0.001))
            if d < R_RES:
                self.assertTrue(out.in_constraint_space, d)
                np.testing.assert_allclose(out.force_n[:2], -K_ET * d * normal, atol=1e-9, err_msg=str(d))
            else:
                self.assertFalse(out.in_constraint_space, d)
                self.assertEqual(list(out.force_n[:2]), [0.0, 0.0], d)

    def test_taper_is_a_smoothstep_to_zero_at_the_edge(self):
        band = 0.002
        pen, stroke, elements = self.paper_pen(constraint_taper_m=band)
        ticks = write_yi(pen, stroke, 0.0, stop_before_end=0.025)
        a, b = elements[1]
        normal = np.array([-(b - a)[1], (b - a)[0]]) / np.linalg.norm(b - a)
        foot = foot_on_segment(pen.pos[ticks[-1]][:2], a, b)[0]
        for d in (0.001, 0.0039, 0.0041, 0.0045, 0.005, 0.0055, 0.0059, 0.00599):
            xy = foot + d * normal
            out = pen.tick((xy[0], xy[1], -0.001))
            expected = -K_ET * d * smoothstep((R_RES - d) / band) * normal
            np.testing.assert_allclose(out.force_n[:2], expected, rtol=1e-9, atol=1e-12, err_msg=str(d))

    def test_paper_force_pushes_out_below_the_paper_only(self):
        for paper_z in (0.0, 0.02):
            layout = cg.SceneLayout(paper_z_m=paper_z)
            scene = cg.Scene("一", layout=layout)
            pen = Pen(scene, cg.ForceLawParameters(**PAPER_LAW), no_chain())
            inside = IN_BOX  # in the box, far from the stroke's start: CS, the normal force only
            pen.touch_down(inside, paper_z - 0.0005, paper_z)
            for depth in (0.0005, 0.002, 0.004, 0.0):
                out = pen.hold((inside[0], inside[1], paper_z - depth), 3)
                f = pen.force(out)
                self.assertEqual(pen.out[out[-1]].state, cg.InteractionState.calibration, (paper_z, depth))
                np.testing.assert_allclose(f[:, 2], K_EN * depth, rtol=0, atol=1e-12, err_msg=str((paper_z, depth)))
                self.assertTrue(np.all(f[:, :2] == 0.0), "CS: no in-plane force (Table 2)")
            above = pen.hold((inside[0], inside[1], paper_z + 0.0002), 3)  # within the contact hysteresis
            self.assertTrue(np.all(pen.force(above)[:, 2] <= 0.0 + 0.0) and np.all(pen.force(above) == 0.0), paper_z)

    def test_paper_damping_acts_on_inward_motion_only(self):
        damping = 0.1  # 2 (b - B) / T = 800 N/m with the simulated device's b = 0.5 N s/m: no warning
        pen, _, _ = self.paper_pen(paper_damping_n_s_per_m=damping)
        inside = IN_BOX
        pen.touch_down(inside)
        for vz, expected in ((-0.05, K_EN * 0.001 + damping * 0.05), (0.05, K_EN * 0.001), (0.0, K_EN * 0.001)):
            out = pen.tick((inside[0], inside[1], -0.001), (0.0, 0.0, vz))
            self.assertAlmostEqual(out.force_n[2], expected, delta=1e-12, msg=vz)

    def test_friction_is_coulomb_with_a_viscous_stick_band(self):
        mu, band = 0.15, 0.02
        law = cg.ForceLawParameters(**{**PAPER_LAW, "friction_coefficient": mu, "friction_stick_speed_m_s": band,
                                       "guidance": False})
        pen, _, _ = self.paper_pen(law=law)
        inside = IN_BOX
        pen.touch_down(inside, -0.002)
        normal = K_EN * 0.002
        for v in ((0.05, 0.0), (-0.03, 0.04), (0.01, 0.0), (0.0, -0.004), (0.0, 0.0)):
            v = np.asarray(v)
            out = pen.tick((inside[0], inside[1], -0.002), (v[0], v[1], 0.0))
            speed = np.linalg.norm(v)
            expected = -mu * normal * v / (speed if speed > band else band)
            np.testing.assert_allclose(out.force_n[:2], expected, rtol=0, atol=1e-12, err_msg=str(v))
            self.assertAlmostEqual(out.force_n[2], normal, delta=1e-12)

    def test_attraction_factor_is_interpolated_between_feature_points(self):
        scene = cg.Scene("口")
        strokes = scene.characters[0].strokes
        factors = np.asarray(strokes[1].attraction_factors, float)
        self.assertFalse(np.all(factors == factors[0]), "口's 横折 has a corner factor of its own")
        pen = Pen(scene, cg.ForceLawParameters(**PAPER_LAW), no_chain())
        positions, velocities = along(strokes[0].median_m, 0.04)
        pen.touch_down(positions[0][:2])
        pen.go(positions, velocities)
        pen.hold((positions[-1][0], positions[-1][1], 0.003), 30)  # lift: stroke 0 written
        self.assertEqual(pen.out[-1].stroke, 1)
        elements = [np.asarray(e.control_points, float) for e in strokes[1].elements]
        ends = [bezier(e, [1.0])[0] for e in elements]
        positions, velocities = along(strokes[1].median_m, 0.04, offset=-0.0015)
        pen.touch_down(positions[0][:2])
        ticks = pen.go(positions, velocities)
        checked = set()
        for k in ticks:
            o = pen.out[k]
            if o.state != cg.InteractionState.writing or o.stroke != 1:
                continue
            foot, u = foot_on_element(pen.pos[k][:2], elements[o.element])
            if np.linalg.norm(ends[o.element] - foot) <= R_RES + 0.0005 or u < 0.02:
                continue  # the slack before a corner
            factor = factors[o.element] + u * (factors[o.element + 1] - factors[o.element])
            np.testing.assert_allclose(o.force_n[:2], K_ET * factor * (foot - pen.pos[k][:2]), rtol=0, atol=1e-7,
                                       err_msg=str((k, o.element, u)))
            if factors[o.element] != factors[o.element + 1]:
                checked.add(o.element)
        self.assertTrue(checked, "an element between two different factors was written")

    def test_the_force_moves_with_the_paper_and_the_row(self):
        layouts = (cg.SceneLayout(), cg.SceneLayout(centre_m=(0.013, -0.021), paper_z_m=-0.017))
        forces = []
        for layout in layouts:
            scene = cg.Scene("一", layout=layout)
            stroke = scene.characters[0].strokes[0]
            pen = Pen(scene, cg.ForceLawParameters(), cg.SafetyChainParameters())
            # from 0.5 mm along: a touch-down square on the start is a tie of Fig. 19's test (dot product 0)
            positions, velocities = along(stroke.median_m, 0.04, offset=0.002, z=layout.paper_z_m - 0.001, start=0.0005)
            pen.touch_down(positions[0][:2], layout.paper_z_m - 0.001, layout.paper_z_m)
            pen.go(positions, velocities)
            forces.append(pen.force())
        self.assertGreater(np.max(np.abs(forces[0][:, :2])), 0.5)
        np.testing.assert_allclose(forces[1], forces[0], rtol=0, atol=1e-9)

    def test_past_the_end_the_inplane_force_fades_to_zero_over_crossfade_s(self):
        crossfade = 0.05
        pen, stroke, elements = self.paper_pen(crossfade_s=crossfade)
        ticks = write_yi(pen, stroke, 0.0015)
        end = np.asarray(stroke.end_m)
        t_end = (elements[2][1] - elements[2][0]) / np.linalg.norm(elements[2][1] - elements[2][0])
        # carry on 4 mm past the end on the paper (within follow_through_m), then stay there
        beyond = [end + t_end * s for s in np.arange(1, 81) * 0.00005]
        past = pen.go([(p[0], p[1], -0.001) for p in beyond], [(t_end[0] * 0.05, t_end[1] * 0.05, 0.0)] * 80)
        rest = pen.hold((beyond[-1][0], beyond[-1][1], -0.001), 100)
        self.assertEqual(pen.out[rest[-1]].state, cg.InteractionState.writing)
        f = pen.force()
        settle = int(math.ceil(crossfade * RATE)) + 1
        tail = f[past[0] + settle:rest[-1] + 1]
        self.assertTrue(np.all(tail[:, :2] == 0.0), "past the end, after crossfade_s, no in-plane force")
        np.testing.assert_allclose(f[past[0]:, 2], 0.8, atol=1e-12)
        # in the fade itself: never pulling back harder than the force at the end, and reaching zero smoothly
        inplane = np.linalg.norm(f[ticks[0]:, :2], axis=1)
        steps = np.abs(np.diff(inplane))
        self.assertLess(float(np.max(steps)), 0.05, "the cross-fade spreads the step")

    def test_leaving_the_constraint_space_cross_fades_by_a_smoothstep(self):
        crossfade = 0.05
        for rate in (RATE, 4000.0):  # a time, not a count of ticks: 50 ticks at 1 kHz, 200 at 4 kHz
            pen, stroke, elements = self.paper_pen(crossfade_s=crossfade, rate=rate)
            ticks = write_yi(pen, stroke, 0.0, stop_before_end=0.025)
            a, b = elements[1]
            normal = np.array([-(b - a)[1], (b - a)[0]]) / np.linalg.norm(b - a)
            foot = foot_on_segment(pen.pos[ticks[-1]][:2], a, b)[0]
            inside, outside = foot + 0.003 * normal, foot + 0.0075 * normal
            steady = pen.hold((inside[0], inside[1], -0.001), 80)
            f0 = pen.force(steady)[-1]
            np.testing.assert_allclose(f0[:2], -K_ET * 0.003 * normal, atol=1e-9)
            n = int(round(crossfade * rate))
            fade = pen.hold((outside[0], outside[1], -0.001), 2 * n)
            f = pen.force(fade)[:, :2]
            best = min(np.max(np.abs(f - np.outer(1.0 - smoothstep((np.arange(2 * n) + shift) / n), f0[:2])))
                       for shift in (0, 1))
            self.assertLess(best, 1e-9, f"F = F0 (1 - smoothstep(t / crossfade_s)) from the switch, at {rate} Hz")
            self.assertTrue(np.all(f[n + 1:] == 0.0), rate)
            self.assertTrue(np.all(np.abs(f[: n - 2]) > 0.0), f"not cut short at {rate} Hz")

    def test_paper_force_fades_in_linearly_on_a_tip_already_below(self):
        fade = 0.2
        scene, stroke, _ = yi()
        pen = Pen(scene, cg.ForceLawParameters(**{**PAPER_LAW, "paper_fade_s": fade}), no_chain())
        first = pen.touch_down(IN_BOX, -0.002)  # from SS: no ramp (depth 0 at the touch-down)
        self.assertAlmostEqual(first.force_n[2], K_EN * 0.002, delta=1e-12)
        pen.hold((0.0, 0.0, 0.01), 400)  # up; its paper force has faded out
        self.assertEqual(list(pen.out[-1].force_n), [0.0, 0.0, 0.0])
        outside_box = (IN_BOX[0], IN_BOX[1] - 0.0075)
        pen.touch_down(outside_box, -0.003)  # AS: outside the box, no force (Table 2)
        self.assertEqual(pen.out[-1].state, cg.InteractionState.adjusting)
        self.assertEqual(list(pen.out[-1].force_n), [0.0, 0.0, 0.0])
        # slide in below the paper: AS -> CS with the tip 3 mm deep
        slide = [(IN_BOX[0], outside_box[1] + s * 0.00025, -0.003) for s in range(1, 31)]
        ticks = pen.go(slide)
        entered = next(k for k in ticks if pen.out[k].state == cg.InteractionState.calibration)
        ramp = pen.hold(slide[-1], 250)
        fz = pen.force(range(entered, ramp[-1] + 1))[:, 2]
        full = K_EN * 0.003
        n = int(round(fade * RATE))
        best = min(np.max(np.abs(fz - full * np.minimum(1.0, (np.arange(len(fz)) + shift) / n))) for shift in (0, 1))
        self.assertLess(best, 1e-9, "a linear weight from 0 to 1 over paper_fade_s")

    def test_pen_up_gives_exactly_zero_after_the_fades(self):
        scene, stroke, _ = yi()
        pen = Pen(scene)  # every default
        write_yi(pen, stroke, 0.002, stop_before_end=0.015)
        self.assertGreater(np.max(np.abs(pen.force()[:, :2])), 0.3)
        last = pen.pos[-1]
        up = pen.hold((last[0], last[1], 0.005), 400)
        f = pen.force(up)
        self.assertTrue(all(pen.out[k].state == cg.InteractionState.separation for k in up[5:]))
        settle = int(round((0.2 + 0.05) * RATE))  # paper_fade_s and crossfade_s
        self.assertTrue(np.all(f[settle:] == 0.0), "SS: zero force (Table 2)")
        self.assertTrue(np.all(np.isfinite(f)))

    def test_non_finite_or_absurd_state_gives_zero_force_at_once(self):
        scene, stroke, _ = yi()
        pen = Pen(scene)
        write_yi(pen, stroke, 0.002, stop_before_end=0.02)
        self.assertGreater(np.linalg.norm(pen.out[-1].force_n), 0.5)
        p = pen.pos[-1]
        bad = [((math.nan, p[1], p[2]), (0, 0, 0)), ((p[0], p[1], math.inf), (0, 0, 0)),
               ((p[0], p[1], p[2]), (0, -math.inf, 0)), ((10.5, p[1], p[2]), (0, 0, 0)),
               ((p[0], -1e300, p[2]), (0, 0, 0))]
        for position, velocity in bad:
            out = pen.tick(position, velocity)
            self.assertEqual(list(out.force_n), [0.0, 0.0, 0.0], position)
            self.assertTrue(out.input_rejected, position)
            self.assertIn("non_finite", out.limit_names)
        out = pen.tick((9.99, p[1], p[2]))  # within kMaxDeviceReadingM (10 m): a reading, not a garble
        self.assertFalse(out.input_rejected)
        self.assertTrue(np.all(np.isfinite(out.force_n)))

    def test_peak_clamp_keeps_the_direction(self):
        scene, stroke, _ = yi()
        law = cg.ForceLawParameters(**PAPER_LAW)
        free = Pen(scene, law, no_chain())
        capped = Pen(scene, law, no_chain(max_force_n=0.5, max_continuous_force_n=0.5))
        for pen in (free, capped):
            write_yi(pen, stroke, 0.004, z=-0.0008, stop_before_end=0.02)
        f, g = free.force(), capped.force()
        big = np.linalg.norm(f, axis=1) > 0.5
        self.assertGreater(int(np.sum(big)), 100)
        np.testing.assert_allclose(np.linalg.norm(g[big], axis=1), 0.5, rtol=1e-12)
        np.testing.assert_allclose(g[big] / 0.5, f[big] / np.linalg.norm(f[big], axis=1)[:, None], atol=1e-12)
        np.testing.assert_array_equal(g[~big], f[~big])
        self.assertTrue(all({"peak", "continuous"} & set(capped.out[k].limit_names) for k in np.flatnonzero(big)))

    def test_rate_limit_is_a_vector_limit(self):
        limit = 0.03
        scene, stroke, elements = yi()
        pen = Pen(scene, cg.ForceLawParameters(**PAPER_LAW), no_chain(max_force_change_n_per_tick=limit))
        ticks = write_yi(pen, stroke, 0.0, stop_before_end=0.025)
        a, b = elements[1]
        normal = np.array([-(b - a)[1], (b - a)[0]]) / np.linalg.norm(b - a)
        foot = foot_on_segment(pen.pos[ticks[-1]][:2], a, b)[0]
        f_before = np.asarray(pen.out[-1].force_n)
        target_xy = foot + 0.005 * normal  # a 2 N in-plane demand and 3 N normal at once
        p = (target_xy[0], target_xy[1], -0.00375)
        step = pen.hold(p, 200)
        target = np.array([*(-K_ET * 0.005 * normal), K_EN * 0.00375])
        f = np.vstack([f_before, pen.force(step)])
        direction = (target - f_before) / np.linalg.norm(target - f_before)
        n = int(np.linalg.norm(target - f_before) // limit)
        expected = f_before + np.outer(np.minimum(np.arange(len(f)) * limit, np.linalg.norm(target - f_before)),
                                       direction)
        np.testing.assert_allclose(f, expected, rtol=0, atol=1e-9)
        self.assertTrue(all("rate" in pen.out[k].limit_names for k in step[:n]))
        self.assertTrue(np.all(np.linalg.norm(np.diff(f, axis=0), axis=1) <= limit + 1e-12))

    def test_start_ramp_bounds_the_force_by_the_time_since_construction(self):
        ramp = 20.0
        scene, _, _ = yi()
        pen = Pen(scene, cg.ForceLawParameters(**PAPER_LAW), no_chain(start_ramp_n_per_s=ramp))
        inside = IN_BOX
        pen.tick((inside[0], inside[1], 0.001))
        ticks = pen.hold((inside[0], inside[1], -0.003), 300)  # 2.4 N asked at once
        fz = pen.force(ticks)[:, 2]
        elapsed = (np.asarray(ticks) + 1) * T
        self.assertTrue(np.all(fz <= ramp * elapsed + 1e-12), "abs(F) <= rate x time since construction")
        self.assertAlmostEqual(float(fz[-1]), 2.4, delta=1e-12)
        rising = fz[fz < 2.4 - 1e-9]
        self.assertGreater(len(rising), 100, "2.4 N at 20 N/s takes 120 ms")
        np.testing.assert_allclose(np.diff(rising[1:]), ramp * T, atol=1e-9)

    def test_reset_restarts_the_ramp_from_zero(self):
        ramp = 20.0
        scene, _, _ = yi()
        pen = Pen(scene, cg.ForceLawParameters(**PAPER_LAW), cg.SafetyChainParameters(start_ramp_n_per_s=ramp))
        pen.touch_down(IN_BOX, -0.003)
        held = pen.hold((*IN_BOX, -0.003), 300)
        self.assertAlmostEqual(pen.out[held[-1]].force_n[2], 2.4, delta=1e-12)
        pen.renderer.reset()  # with the pen pressed in: the documented drop to the ramp, never a push
        again = pen.hold((*IN_BOX, -0.003), 200)
        fz = pen.force(again)[:, 2]
        elapsed = (np.arange(len(fz)) + 1) * T
        self.assertTrue(np.all(fz <= ramp * elapsed + 1e-12), "abs(F) <= rate x time since reset()")
        self.assertTrue(np.all(np.abs(np.diff(fz)) <= 0.25 + 1e-12), "after the reset tick, the per-tick limit")
        self.assertAlmostEqual(float(fz[-1]), 2.4, delta=1e-12)
        self.assertEqual(pen.out[again[0]].state, cg.InteractionState.calibration)

    def test_low_pass_is_the_documented_first_order_filter(self):
        cutoff = 40.0
        scene, _, _ = yi()
        pen = Pen(scene, cg.ForceLawParameters(**PAPER_LAW), no_chain(low_pass_cutoff_hz=cutoff))
        pen.touch_down(IN_BOX, -0.0005)
        before = pen.hold((*IN_BOX, -0.0005), 300)
        self.assertAlmostEqual(pen.out[before[-1]].force_n[2], 0.4, delta=1e-6)
        y = pen.out[before[-1]].force_n[2]
        ticks = pen.hold((*IN_BOX, -0.003), 60)
        alpha = 1.0 - math.exp(-2.0 * math.pi * cutoff * T)
        expected = []
        for _ in ticks:
            y += alpha * (2.4 - y)
            expected.append(y)
        np.testing.assert_allclose(pen.force(ticks)[:, 2], expected, rtol=0, atol=1e-12)
        for bad in (RATE / 2, RATE):
            with self.assertRaises(ValueError) as caught:
                cg.Renderer(scene, options=cg.RendererOptions(rate_hz=RATE, safety=no_chain(low_pass_cutoff_hz=bad)))
            self.assertIn("low_pass_cutoff_hz", str(caught.exception))
        cg.Renderer(scene, options=cg.RendererOptions(rate_hz=RATE, safety=no_chain(low_pass_cutoff_hz=499.0)))

    def test_continuous_limit_allows_the_peak_then_settles_at_the_continuous_force(self):
        scene, _, _ = yi()
        pen = Pen(scene, cg.ForceLawParameters(**PAPER_LAW),
                  no_chain(max_continuous_force_n=1.0, continuous_time_constant_s=0.05))
        pen.tick((*IN_BOX, 0.001))
        ticks = pen.hold((*IN_BOX, -0.00375), 1500)  # 3 N asked, sustained
        fz = pen.force(ticks)[:, 2]
        self.assertAlmostEqual(float(fz[0]), 3.0, delta=1e-12, msg="the estimate starts below 80 %: the peak")
        self.assertTrue(np.all(fz <= 3.0 + 1e-12))
        self.assertTrue(np.all(fz >= 1.0 - 1e-9), "never below the continuous force while 3 N is asked")
        np.testing.assert_allclose(fz[-200:], 1.0, rtol=0, atol=0.01)
        self.assertIn("continuous", pen.out[ticks[-1]].limit_names)

    def test_after_the_last_stroke_no_force_at_all(self):
        pen, stroke, elements = self.paper_pen()
        write_yi(pen, stroke, 0.001)
        last = pen.pos[-1]
        pen.hold((last[0], last[1], 0.004), 20)  # the lift completes the stroke: the character is written
        self.assertTrue(pen.out[-1].finished)
        self.assertEqual(list(pen.out[-1].force_n), [0.0, 0.0, 0.0])
        positions, velocities = along(stroke.median_m, 0.05, offset=0.003, z=-0.0015, start=0.0005)
        pen.touch_down(positions[0][:2], -0.0015)
        ticks = pen.go(positions, velocities)
        f = pen.force(ticks)
        self.assertTrue(np.all(f == 0.0), "the character written: the renderer commands zero force")
        self.assertTrue(all(pen.out[k].finished for k in ticks))

    def test_off_stroke_friction_in_cs_is_a_dragged_spring(self):
        force, travel = 0.5, 0.001
        pen, _, _ = self.paper_pen(off_stroke_force_n=force, off_stroke_travel_m=travel)
        entered = np.array(IN_BOX)
        pen.touch_down(IN_BOX)
        self.assertEqual(pen.out[-1].state, cg.InteractionState.calibration)
        # straight 3 mm left at 10 mm/s: a spring to where CS was entered, the point dragged once 1 mm behind
        direction = np.array([-1.0, 0.0])
        ticks = pen.go([(*(entered + direction * 1e-5 * k), -0.001) for k in range(1, 301)],
                       [(-0.01, 0.0, 0.0)] * 300)
        anchor = entered.copy()
        for k in ticks:
            p = pen.pos[k][:2]
            if np.linalg.norm(p - anchor) > travel:
                anchor = p - travel * (p - anchor) / np.linalg.norm(p - anchor)
            expected = -force / travel * (p - anchor)
            np.testing.assert_allclose(pen.out[k].force_n[:2], expected, rtol=0, atol=1e-9, err_msg=str(k))
        self.assertAlmostEqual(float(np.linalg.norm(pen.out[ticks[-1]].force_n[:2])), force, delta=1e-9)
        # at rest the pen is held by the same spring, whatever the speed
        held = pen.hold(pen.pos[-1], 50)
        np.testing.assert_allclose(pen.force(held)[:, :2], [pen.out[ticks[-1]].force_n[:2]] * 50, atol=1e-12)

    def test_off_stroke_damper_resists_leaving_never_coming_back(self):
        damping, slow = 25.0, 0.005
        pen, stroke, elements = self.paper_pen(off_stroke_damping_n_s_per_m=damping, off_stroke_speed_m_s=slow)
        ticks = write_yi(pen, stroke, 0.0, stop_before_end=0.025)
        a, b = elements[1]
        normal = np.array([-(b - a)[1], (b - a)[0]]) / np.linalg.norm(b - a)
        foot = foot_on_segment(pen.pos[ticks[-1]][:2], a, b)[0]
        start = foot + 0.0065 * normal  # outside R_res: the damper, no attraction
        for speed in (0.003, 0.0075, 0.02, -0.02):
            v = speed * normal
            # long enough at one velocity for its 30 Hz low-pass to settle (200 ms is 38 time constants)
            held = pen.go([(*(start + v * T * k), -0.001) for k in range(200)], [(v[0], v[1], 0.0)] * 200)
            self.assertFalse(pen.out[held[-1]].in_constraint_space)
            w = float(smoothstep((abs(speed) - slow) / slow))
            expected = -damping * w * max(speed, 0.0) * normal
            np.testing.assert_allclose(pen.out[held[-1]].force_n[:2], expected, rtol=1e-6, atol=1e-9,
                                       err_msg=str(speed))
            start = pen.pos[held[-1]][:2]

    def test_passivity_observer_and_damper_recomputed(self):
        cap, floor = 20.0, 1e-4
        scene, _, _ = yi()
        pen = Pen(scene, cg.ForceLawParameters(**PAPER_LAW), no_chain(),
                  passivity=cg.PassivityParameters(enabled=True, max_damping_n_s_per_m=cap, min_speed_m_s=floor))
        # pressed 3 mm in, then rising at 50 mm/s: the paper pushes the pen out along its motion (E < 0)
        path = [((*IN_BOX, 0.002), (0, 0, 0)), ((*IN_BOX, -0.003), (0, 0, -0.05))]
        path += [((*IN_BOX, -0.003), (0, 0, 0))] * 5
        path += [((*IN_BOX, -0.003 + 5e-5 * k), (0, 0, 0.05)) for k in range(1, 40)]
        path += [((*IN_BOX, -0.001 + 2e-5 * k), (0, 0, 0.00005)) for k in range(1, 10)]  # below min speed: no damper
        energy, previous_force, previous_x = 0.0, np.zeros(3), None
        damped = 0
        for position, velocity in path:
            out = pen.tick(position, velocity)
            x, v = np.asarray(position, float), np.asarray(velocity, float)
            if previous_x is not None:
                energy -= float(np.dot(previous_force, x - previous_x))
            speed = np.linalg.norm(v)
            alpha = min(-energy / (T * speed * speed), cap) if energy < 0.0 and speed >= floor else 0.0
            self.assertAlmostEqual(out.passivity_damping_n_s_per_m, alpha, delta=1e-9 * max(1.0, alpha), msg=position)
            law = np.array([0.0, 0.0, K_EN * max(0.0, -x[2])]) if out.state != cg.InteractionState.separation else 0.0
            np.testing.assert_allclose(out.force_n, law - alpha * v, rtol=0, atol=1e-9, err_msg=str(position))
            damped += alpha > 0.0
            previous_force, previous_x = np.asarray(out.force_n), x
        self.assertGreater(damped, 10, "the rising pen is damped")

    def test_default_device_is_the_simulated_desktop_as_it_reports_itself(self):
        # docs/devices.md: the simulated device reports its own intrinsic damping (0.5 N s/m, `devices --json`);
        # a Renderer's default device is "the simulated Phantom Desktop's" DeviceInfo, so its passivity bound
        # 2 (b - B) / T warns where a simulated trial's does.
        listed = json.loads(run(["devices", "--json"], tempfile.gettempdir()).stdout)
        devices = listed if isinstance(listed, list) else listed["devices"]
        simulated = next(d for d in devices if d["name"] == "simulated")["info"]
        self.assertEqual(simulated["intrinsic_damping_n_s_per_m"], 0.5)
        law = cg.ForceLawParameters(paper_stiffness_n_per_m=900.0, paper_damping_n_s_per_m=0.1)  # above 800 N/m
        scene, _, _ = yi()
        with self.assertLogs("calligraphy", "WARNING") as logged:
            cg.Renderer(scene, law)
        self.assertTrue(any("passivity bound" in line and "b = 0.5 N s/m" in line for line in logged.output),
                        logged.output)

    def test_smoothing_table_parameters_at_zero_give_the_paper(self):
        # "setting it to 0 gives the paper's behaviour" for each smoothing parameter; the foot-speed limit has
        # no 0 (the docs say so): it is refused naming the field, and a speed no pen reaches is the paper's law.
        for field in ("constraint_taper_m", "crossfade_s", "paper_fade_s", "paper_damping_n_s_per_m",
                      "friction_coefficient"):
            self.assertEqual(getattr(cg.ForceLawParameters(**{field: 0.0}), field), 0.0)
        with self.assertRaises(ValueError) as caught:
            cg.ForceLawParameters(max_foot_speed_m_s=0.0)
        self.assertIn("ForceLawParameters.max_foot_speed_m_s", str(caught.exception))
        source = Path(os.environ.get("CALLIGRAPHY_SOURCE_DIR") or Path(__file__).resolve().parents[2])
        text = " ".join((source / "docs" / "force-rendering.md").read_text().split())
        said = re.search(r"setting it to 0 gives the paper's behaviour([^.]*)\.", text)
        self.assertIsNotNone(said)
        self.assertIn("foot-speed limit, which must be above 0", said.group(1), "the docs name the exception")


MODES = {  # calligraphy trial's options per guidance mode (docs/cli.md), non-default values where there are any
    "fixed": [],
    "fading": ["--guidance-mode", "fading", "--guidance-gain", "0.5"],
    "assist-as-needed": ["--guidance-mode", "assist-as-needed", "--assist-band", "0.002"],
    "error-amplification": ["--guidance-mode", "error-amplification", "--amplification-gain", "0.5"],
    "timing": ["--guidance-mode", "timing", "--timing-speed", "0.05"],
    "replay": ["--guidance-mode", "replay", "--teacher", "teacher.json"],
    "off": ["--guidance", "off"],
}
COLUMNS = "t,x,y,z,fx,fy,fz,state,stroke,element,attempt,rewritten".split(",")
STATES = {"SS": 0, "AS": 1, "CS": 2, "WS": 3}


def read_trace(path):
    """A trial's --csv as numpy arrays by column name (state as 0-3)."""
    with open(path, newline="") as handle:
        rows = list(csv.reader(handle))
    assert rows[0] == COLUMNS, rows[0]
    body = rows[1:]
    trace = {name: np.array([float(r[i]) for r in body]) for i, name in enumerate(COLUMNS) if name != "state"}
    trace["state"] = np.array([STATES[r[7]] for r in body])
    trace["force"] = np.c_[trace["fx"], trace["fy"], trace["fz"]]
    trace["position"] = np.c_[trace["x"], trace["y"], trace["z"]]
    return trace


class TrialTraces(unittest.TestCase):
    """Whole simulated trials of 十 from `calligraphy trial --csv` in every mode, and Python's `simulate_trial`."""

    @classmethod
    def setUpClass(cls):
        cls.dir = Path(tempfile.mkdtemp(prefix="round16a-"))
        made = run(["trial", "十", "--writer-profile", "skilled", "--record", "teacher.json", "--max-duration", "20"],
                   cls.dir)
        assert made.returncode == 0, made.stderr
        cls.traces, cls.records = {}, {}
        for mode, options in MODES.items():
            result = run(["trial", "十", *options, "--max-duration", "20", "--csv", f"{mode}.csv",
                          "--json", f"{mode}.json"], cls.dir)
            assert result.returncode == 0, (mode, result.stderr)
            cls.traces[mode] = read_trace(cls.dir / f"{mode}.csv")
            cls.records[mode] = json.loads((cls.dir / f"{mode}.json").read_text())

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.dir, ignore_errors=True)

    def test_every_mode_stays_within_the_caps_and_the_rate_limit(self):
        for mode, trace in self.traces.items():
            f = trace["force"]
            self.assertEqual(self.records[mode]["end_reason"], "completed", mode)
            self.assertTrue(np.all(np.isfinite(f)), mode)
            self.assertLessEqual(float(np.max(np.linalg.norm(f, axis=1))), 7.9, mode)  # the Phantom Desktop's peak
            steps = np.linalg.norm(np.diff(f, axis=0), axis=1)
            self.assertLessEqual(float(np.max(steps)), 0.25 + 2e-4, mode)  # 0.25 N per tick, forces to 0.1 mN
            np.testing.assert_allclose(np.diff(trace["t"]), T, atol=1e-6, err_msg=mode)
            self.assertTrue(np.all(f[:, 2] >= 0.0), f"{mode}: the paper never pulls the pen in")

    def test_separation_and_adjusting_are_exactly_zero_after_the_fades(self):
        for mode, trace in self.traces.items():
            contact = np.isin(trace["state"], (STATES["CS"], STATES["WS"]))
            last_contact = -np.inf
            checked = 0
            for k in range(len(trace["t"])):
                if contact[k]:
                    last_contact = trace["t"][k]
                elif trace["t"][k] - last_contact > 0.2 + 0.05 + 1e-9:  # paper_fade_s and crossfade_s
                    self.assertEqual(list(trace["force"][k]), [0.0, 0.0, 0.0], (mode, k, trace["state"][k]))
                    checked += 1
            self.assertGreater(checked, 100, mode)
            self.assertTrue(np.all(trace["force"][: int(np.argmax(contact))] == 0.0), mode)

    def test_paper_force_is_eq9_on_every_settled_contact_tick(self):
        for mode, trace in self.traces.items():
            state, t, z, fz = trace["state"], trace["t"], trace["z"], trace["fz"]
            adjusting = t[state == STATES["AS"]]
            settled = np.isin(state, (STATES["CS"], STATES["WS"])) & (t > 0.06)  # the start ramp over
            if len(adjusting):
                since = t - np.array([adjusting[adjusting <= x].max(initial=-np.inf) for x in t])
                settled &= since > 0.2 + 1e-9  # paper_fade_s after AS
            self.assertGreater(int(np.sum(settled)), 1000, mode)
            expected = K_EN * np.maximum(0.0, -z[settled])
            # z to 0.1 um (0.08 mN at 800 N/m), force to 0.1 mN
            np.testing.assert_allclose(fz[settled], expected, rtol=0, atol=1.5e-4, err_msg=mode)

    def test_guidance_points_towards_the_active_element_and_amplification_away(self):
        law_fields = dict(friction_coefficient=0.0, resistance_damping_n_s_per_m=0.0, off_stroke_force_n=0.0,
                          off_stroke_damping_n_s_per_m=0.0)
        for mode, sign in (("fixed", 1.0), ("error-amplification", -1.0)):
            law = cg.ForceLawParameters(**law_fields, guidance_law=cg.default_guidance_law(mode))
            r = cg.simulate_trial("十", seed=1, force_law=law, max_duration_s=20)
            self.assertEqual(r.metrics["end_reason"], "completed", mode)
            strokes = r.scene.characters[0].strokes
            towards = []
            for k in np.flatnonzero(r.state == cg.InteractionState.writing):
                stroke = strokes[int(r.stroke[k])]
                control = np.asarray(stroke.elements[int(r.element[k])].control_points, float)
                p = r.position_m[k, :2]
                foot, u = foot_on_element(p, control)
                off = foot - p
                f = r.force_n[k, :2]
                # beside the element (past either end its foot is the end, and past the stroke's end the force
                # fades from its value at the switch), off it by more than encoder noise, a force to speak of
                if not 0.001 < u < 0.999 or np.linalg.norm(off) < 0.0003 or np.linalg.norm(f) < 0.01:
                    continue
                towards.append(sign * float(np.dot(f, off)) / np.linalg.norm(off))
            self.assertGreater(len(towards), 300, mode)
            self.assertGreater(min(towards), 0.0, f"{mode}: the in-plane force never points the other way")

    def test_python_and_the_csv_give_the_same_newtons_in_every_mode(self):
        laws = {"fixed": cg.FixedGuidance(), "fading": cg.FadingGuidance(gain=0.5),
                "assist-as-needed": cg.AssistAsNeededGuidance(band_m=0.002),
                "error-amplification": cg.ErrorAmplificationGuidance(gain=0.5),
                "timing": cg.TimingGuidance(speed_m_s=0.05), "replay": None}  # replay: the teacher= argument
        docstring = " ".join(cg.simulate_trial.__doc__.split())
        teacher = cg.TeacherRecording.load(str(self.dir / "teacher.json"))
        for mode, trace in self.traces.items():
            if mode == "off":
                r = cg.simulate_trial("十", guidance=False, max_duration_s=20)
            else:
                self.assertTrue(f"'{mode}'" in docstring, f"simulate_trial's docstring names guidance_mode '{mode}'")
                law = None if laws[mode] is None else cg.ForceLawParameters(guidance_law=laws[mode])
                r = cg.simulate_trial("十", force_law=law, guidance_mode=mode,
                                      teacher=teacher if mode == "replay" else None, max_duration_s=20)
                self.assertEqual(r.metrics["guidance_mode"], mode)
            self.assertEqual(r.force_n.shape, (len(trace["t"]), 3), mode)
            np.testing.assert_allclose(trace["force"], r.force_n, rtol=0, atol=0.5e-4 + 1e-12, err_msg=mode)  # 0.1 mN
            np.testing.assert_allclose(trace["position"], r.position_m, rtol=0, atol=0.5e-7 + 1e-15, err_msg=mode)
            self.assertAlmostEqual(self.records[mode]["max_force_n"],
                                   float(np.max(np.linalg.norm(r.force_n, axis=1))), delta=1e-12, msg=mode)
        frame = r.to_dataframe()
        np.testing.assert_array_equal(frame[["fx_n", "fy_n", "fz_n"]].to_numpy(), r.force_n)
        units = {c["name"]: c["unit"] for c in cg.trace_columns()}
        self.assertEqual([units[c] for c in ("fx_n", "fy_n", "fz_n")], ["N"] * 3)

    def test_a_rerun_gives_the_same_force_bit_for_bit(self):
        for mode in ("timing", "assist-as-needed", "off"):
            again = run(["trial", "--spec", f"{mode}.json", "--csv", f"{mode}-again.csv"], self.dir)
            self.assertEqual(again.returncode, 0, again.stderr)
            self.assertEqual((self.dir / f"{mode}-again.csv").read_bytes(), (self.dir / f"{mode}.csv").read_bytes(),
                             mode)
        law = cg.ForceLawParameters(crossfade_s=0.01, constraint_taper_m=0.001, paper_damping_n_s_per_m=0.1,
                                    guidance_law=cg.TimingGuidance(speed_m_s=0.05, max_lead_m=0.002))
        safety = cg.SafetyChainParameters(low_pass_cutoff_hz=120.0, max_force_change_n_per_tick=0.1,
                                          max_continuous_force_n=1.0, continuous_time_constant_s=0.5)
        first = cg.simulate_trial("十", seed=3, force_law=law, safety=safety, max_duration_s=20)
        second = cg.rerun_trial(first.metrics)
        self.assertEqual(first.force_n.tobytes(), second.force_n.tobytes())
        self.assertLessEqual(float(np.max(np.linalg.norm(np.diff(first.force_n, axis=0), axis=1))), 0.1 + 1e-12)

    def test_an_edited_record_runs_its_own_rate_limit(self):
        record = json.loads((self.dir / "fixed.json").read_text())
        record["specification"]["safety"]["max_force_change_n_per_tick"] = 0.02
        record["specification"]["force_law"]["crossfade_s"] = 0.0
        record["specification"]["force_law"]["paper_fade_s"] = 0.0
        (self.dir / "edited.json").write_text(json.dumps(record))
        result = run(["trial", "--spec", "edited.json", "--csv", "edited.csv", "--json", "edited-out.json"], self.dir)
        self.assertIn(result.returncode, (0, 1), result.stderr)
        f = read_trace(self.dir / "edited.csv")["force"]
        self.assertLessEqual(float(np.max(np.linalg.norm(np.diff(f, axis=0), axis=1))), 0.02 + 2e-4)
        spec = json.loads((self.dir / "edited-out.json").read_text())["specification"]
        self.assertEqual((spec["safety"]["max_force_change_n_per_tick"], spec["force_law"]["crossfade_s"]), (0.02, 0.0))

    def test_a_weaker_device_caps_the_force(self):
        result = run(["trial", "十", "--device", "emulated-phantom", "--guidance-stiffness", "2000",
                      "--max-duration", "20", "--csv", "omni.csv", "--json", "omni.json"], self.dir)
        self.assertIn(result.returncode, (0, 1), result.stderr)
        f = read_trace(self.dir / "omni.csv")["force"]
        self.assertTrue(np.all(np.isfinite(f)))
        self.assertLessEqual(float(np.max(np.linalg.norm(f, axis=1))), 3.3 + 1e-4)  # the Omni's peak (devices --json)
        self.assertLessEqual(float(np.max(np.linalg.norm(np.diff(f, axis=0), axis=1))), 0.25 + 2e-4)

    def test_ten_kilohertz_keeps_the_per_tick_limit(self):
        result = run(["trial", "一", "--rate", "10000", "--max-duration", "1.5", "--csv", "fast.csv"], self.dir)
        self.assertIn(result.returncode, (0, 1), result.stderr)
        trace = read_trace(self.dir / "fast.csv")
        np.testing.assert_allclose(np.diff(trace["t"]), 1e-4, atol=1e-6)
        f = trace["force"]
        self.assertGreater(float(np.max(np.linalg.norm(f, axis=1))), 0.3)
        self.assertLessEqual(float(np.max(np.linalg.norm(np.diff(f, axis=0), axis=1))), 0.25 + 2e-4)


if __name__ == "__main__":
    unittest.main(verbosity=2)
