#!/usr/bin/env python3
"""Round 30B: the haptic API in Python, one tick at a time, fed hostile arrays. From the docs alone
(docs/python.md "Characters", "Scenes: data units and metres", "Nearest point and force law", "Renderer, one tick
at a time", "Stroke matching and labelled pen paths", "Errors"; docs/nearest-point.md; docs/force-rendering.md;
docs/devices.md "Readings that are no pen"; the stub _calligraphy.pyi; the docstrings; the comments of
include/calligraphy/render/renderer.hpp, render/force_law.hpp, core/device_types.hpp, devices/simulated_device.hpp).

Points, control points, paths and device states are given as numpy arrays of every hostile kind: integer,
float16/float32 (values they hold exactly), big-endian, Fortran order, transposed, strided and reversed views,
read-only, object, lists, DataFrames; each gives the bits the same numbers as contiguous float64 give. Complex,
text, times, masked values and wrong shapes are refused as `InvalidArgument` naming the argument. The nearest
point is held to what nearest-point.md promises: no farther than any sampled point, independent of where the
element is (an exact offset) and of its size (a power of two), finite up to 1e150. A `Renderer` is ticked by hand
along 十: the in-plane force at rest is K_et a (X_S - X_p) with X_S what `nearest_point` finds on the placed element
(metres in, newtons out), halves with K_et, is zero off the constraint space and without guidance, continuous as
the pen crosses R_res; readings that are no pen give zero force and it climbs back at the per-tick limit; time
stamps shifted, repeated, going back or jumping keep the force within the chain's limits. The simulated device
is fed hostile forces, steps and a close.

PYTHONPATH names the built Python package. CALLIGRAPHY_SANITIZED=1 takes five cases.
"""
import copy
import gc
import os
import pickle
import subprocess
import sys
import threading
import unittest

from outsider import sanitized_subset

try:
    import numpy as np
    import pandas as pd
    import calligraphy as cg
except ImportError:  # reported by setUpClass
    np = pd = cg = None

load_tests = sanitized_subset({"test_nearest_point_takes_any_real_point_array_bit_for_bit",
                               "test_device_state_refuses_bad_shapes_and_non_real_arrays_naming_the_field",
                               "test_reading_that_is_no_pen_gives_zero_force_then_climbs_at_the_tick_limit",
                               "test_simulated_device_force_and_steps_hostile",
                               "test_renderer_scene_and_outputs_refuse_pickle_and_copy"})

RATE_HZ = 1000.0
HOVER_M = 0.002        # pen lifted, 2 mm above the paper (z0 = 0, the default layout)
DOWN_M = -0.0003       # pen on the paper, 0.3 mm in: paper force K_en * 0.3 mm
OFF_M = 0.001          # the held pen 1 mm beside the stroke
FAR_M = 0.008          # beyond R_res = 6 mm
K_ET = 400.0           # the documented default guidance stiffness
K_EN = 800.0           # the documented default paper stiffness
MAX_STEP_N = 0.25      # the safety chain's default per-tick change limit
CUBIC = [[100, 100], [300, 700], [700, -100], [900, 500]]   # exact in every dtype used below


def same_numbers(a):
    """Arrays and containers holding exactly the numbers of the 2-D float64 array `a` (small integers): the
    hostile forms a caller may hand over."""
    a = np.asarray(a, dtype=np.float64)
    ro = a.copy()
    ro.flags.writeable = False
    forms = {
        "int64": a.astype(np.int64), "int32": a.astype(np.int32), "uint16": (a + 0).astype(np.uint16)
        if (a >= 0).all() else a.astype(np.int16),
        "float16": a.astype(np.float16), "float32": a.astype(np.float32),
        "big-endian": a.astype(">f8"), "big-endian-f4": a.astype(">f4"),
        "fortran": np.asfortranarray(a), "transposed-view": np.ascontiguousarray(a.T).T,
        "row-strided": np.repeat(a, 3, axis=0)[::3], "column-strided": np.repeat(a, 2, axis=1)[:, ::2],
        "reversed-view": np.ascontiguousarray(a[::-1])[::-1], "read-only": ro,
        "list": a.tolist(), "tuple": tuple(tuple(r) for r in a.tolist()), "object": a.astype(object),
        "masked-none": np.ma.masked_array(a, mask=np.zeros_like(a, dtype=bool)),
        "dataframe": pd.DataFrame(a, columns=["xyz"[i] for i in range(a.shape[1])], index=np.arange(len(a)) * 7 + 3),
    }
    for name, form in forms.items():
        if name not in ("list", "tuple", "dataframe", "object"):
            assert np.array_equal(np.asarray(form, dtype=np.float64), a), name
    return forms


def not_real(a):
    """Forms of `a` that numpy would misread as float64 (documented as refused naming the argument)."""
    a = np.asarray(a, dtype=np.float64)
    masked = np.ma.masked_array(a.copy(), mask=np.zeros_like(a, dtype=bool))
    masked.mask.flat[0] = True
    return {"complex": a.astype(np.complex128), "text": a.astype(str),
            "timedelta": a.astype(np.int64).astype("timedelta64[ms]"),
            "datetime": a.astype(np.int64).astype("datetime64[s]"), "masked-one": masked}


def bits(x):
    return np.asarray(x, dtype=np.float64).tobytes()


def walk(points, step):
    """Points along the polyline `points` [m], `step` apart along it, both ends included."""
    points = np.asarray(points, dtype=np.float64)
    keep = np.concatenate([[True], np.hypot(*np.diff(points, axis=0).T) > 0])
    points = points[keep]
    s = np.concatenate([[0.0], np.cumsum(np.hypot(*np.diff(points, axis=0).T))])
    q = np.append(np.arange(0.0, s[-1], step), s[-1])
    return np.column_stack([np.interp(q, s, points[:, 0]), np.interp(q, s, points[:, 1])])


def states(xyz, rate_hz=RATE_HZ, times=None, velocity=None):
    """DeviceStates of the positions `xyz` (N, 3) [m], one per tick, velocity the difference [m/s]."""
    xyz = np.asarray(xyz, dtype=np.float64)
    if velocity is None:
        velocity = np.vstack([np.zeros(3), np.diff(xyz, axis=0) * rate_hz])
    if times is None:
        times = np.arange(len(xyz)) / rate_hz
    return [cg.DeviceState(position_m=tuple(p), velocity_m_s=tuple(v), time_s=float(t))
            for p, v, t in zip(xyz, velocity, times)]


def tick_all(renderer, device_states):
    return [renderer.tick(s) for s in device_states]


def forces(outs):
    return np.array([o.force_n for o in outs])


class Round30B(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        if cg is None:
            raise unittest.SkipTest("numpy, pandas and the calligraphy Python package (PYTHONPATH) are needed")
        cls.scene = cg.Scene("十")
        cls.stroke = cls.scene.characters[0].strokes[0]
        cls.device = cg.SimulatedDevice().info
        centre = np.asarray(cls.stroke.centre_line_m)
        along = walk(centre, 4e-5)                       # 0.04 mm a tick: 40 mm/s
        half = along[: len(along) // 2]
        chord = centre[-1] - centre[0]
        chord = chord / np.hypot(*chord)
        cls.normal = np.array([-chord[1], chord[0]])
        ramp = np.minimum(1.0, np.arange(len(half)) / 200.0)[:, None] * OFF_M
        path = half + ramp * cls.normal
        start = path[0]
        hover = [(*start, HOVER_M)] * 20
        descend = [(*start, HOVER_M + (DOWN_M - HOVER_M) * a) for a in np.linspace(0, 1, 30)[1:]]
        write = [(*p, DOWN_M) for p in path]
        hold = [write[-1]] * 400
        cls.hold_xyz = np.array(hover + descend + write + hold)
        n_moving = len(hover) + len(descend) + len(write)
        cls.hold_velocity = np.vstack([np.zeros(3), np.diff(cls.hold_xyz, axis=0) * RATE_HZ])
        cls.hold_velocity[n_moving:] = 0.0
        # Then straight away from the stroke, 1 mm -> 8 mm off at 4 mm/s (below the off-stroke damper's 5 mm/s),
        # and held there.
        away = [(*(path[-1] + cls.normal * (d - OFF_M)), DOWN_M) for d in np.arange(OFF_M, FAR_M, 4e-6)[1:]]
        cls.cross_xyz = np.vstack([cls.hold_xyz, away, [away[-1]] * 300])
        cls.cross_velocity = np.vstack([cls.hold_velocity, np.tile([*(cls.normal * 4e-3), 0.0], (len(away), 1)),
                                        np.zeros((300, 3))])
        cls.n_hold = len(cls.hold_xyz)
        cls.n_away = len(away)
        cls.cross_states = states(cls.cross_xyz, velocity=cls.cross_velocity)
        cls.guided = tick_all(cg.Renderer(cls.scene, cg.ForceLawParameters(), device=cls.device),
                              cls.cross_states)

    def assertNames(self, error, *names):
        text = str(error.exception)
        self.assertTrue(any(n in text for n in names), f"{names} not named in {text!r}")

    # ---- nearest point: hostile arrays ---------------------------------------------------------------------
    def test_nearest_point_takes_any_real_point_array_bit_for_bit(self):
        rng = np.random.default_rng(30)
        points = rng.integers(-200, 1200, size=(64, 2)).astype(np.float64)
        t0, foot0, d0 = cg.nearest_point(CUBIC, points)
        self.assertEqual((t0.shape, foot0.shape, d0.shape), ((64,), (64, 2), (64,)))
        for name, form in same_numbers(points).items():
            with self.subTest(point=name):
                t, foot, d = cg.nearest_point(CUBIC, form)
                self.assertEqual((bits(t), bits(foot), bits(d)), (bits(t0), bits(foot0), bits(d0)))
        # One row at a time gives the same bits as the batch; (1, 2) stays a batch of one.
        for i in range(0, 64, 9):
            t, foot, d = cg.nearest_point(CUBIC, points[i])
            self.assertEqual((bits(t), bits(foot), bits(d)), (bits(t0[i]), bits(foot0[i]), bits(d0[i])))
        t, foot, d = cg.nearest_point(CUBIC, points[:1])
        self.assertEqual((np.shape(t), np.shape(foot), np.shape(d)), ((1,), (1, 2), (1,)))

    def test_nearest_point_takes_any_real_control_point_array_bit_for_bit(self):
        point = [512.0, 333.0]
        base = cg.nearest_point(CUBIC, point)
        forms = same_numbers(CUBIC)
        forms.pop("dataframe")
        forms["StrokeElement"] = cg.StrokeElement(CUBIC)
        for name, form in forms.items():
            with self.subTest(element=name):
                got = cg.nearest_point(form, point)
                self.assertEqual([bits(x) for x in got], [bits(x) for x in base])

    def test_nearest_point_refuses_non_real_and_misshapen_points_naming_point(self):
        good = np.array([[500.0, 600.0], [10.0, 20.0]])
        bad = dict(not_real(good))
        bad.update({"shape (3,)": [1.0, 2.0, 3.0], "shape (2, 1)": [[500.0], [600.0]], "shape (2, 3)":
                    np.zeros((2, 3)), "shape (1, 2, 2)": good[None], "shape (0,)": [],
                    "NaN": [[500.0, np.nan], [1.0, 2.0]], "inf": [np.inf, 0.0], "-inf row 2": [[0, 0], [0, -np.inf]]})
        for name, form in bad.items():
            with self.subTest(point=name):
                with self.assertRaises(cg.InvalidArgument) as error:
                    cg.nearest_point(CUBIC, form)
                self.assertNames(error, "point")
        with self.assertRaises((cg.InvalidArgument, TypeError)) as error:   # a number where an array is taken
            cg.nearest_point(CUBIC, np.float64(3.0))
        self.assertNames(error, "point")

    def test_nearest_point_refuses_non_real_and_misshapen_elements_naming_element(self):
        bad = dict(not_real(CUBIC))
        bad.update({"one point": [[1.0, 2.0]], "six points": np.arange(12.0).reshape(6, 2),
                    "(4, 3)": np.zeros((4, 3)), "1-D": np.arange(8.0), "(1, 4, 2)": np.array(CUBIC, float)[None],
                    "NaN": [[0, 0], [1, np.nan]], "inf": [[0, 0], [np.inf, 1], [2, 2]]})
        for name, form in bad.items():
            with self.subTest(element=name):
                with self.assertRaises(cg.InvalidArgument) as error:
                    cg.nearest_point(form, [1.0, 1.0])
                self.assertNames(error, "element", "control_points", "control point")
            with self.subTest(constructor=name):
                with self.assertRaises(cg.InvalidArgument) as error:
                    cg.StrokeElement(form)
                self.assertNames(error, "control_points")

    # ---- nearest point: the documented guarantees ----------------------------------------------------------
    def test_nearest_point_is_no_farther_than_any_sampled_point_and_beats_newton(self):
        rng = np.random.default_rng(7)
        elements = [CUBIC, [[0, 0], [1000, 0], [0, 10]], [[0, 0], [30, 30], [0, 30], [30, 0]],
                    [[0, 0], [400, 900], [800, -900], [0, 900], [1000, 0]], [[5, 5], [5, 5]]]
        for cps in elements:
            e = cg.StrokeElement(cps)
            samples = e.point(np.linspace(0.0, 1.0, 4001))
            points = rng.uniform(-300, 1300, size=(200, 2))
            t, foot, d = cg.nearest_point(e, points)
            _, _, d_newton = cg.nearest_point(e, points, method="newton")
            for i, p in enumerate(points):
                with self.subTest(element=cps, point=p.tolist()):
                    sampled = np.hypot(*(samples - p).T).min()
                    self.assertLessEqual(d[i], sampled * (1 + 1e-12) + 1e-9)
                    self.assertLessEqual(d[i], d_newton[i] * (1 + 1e-12) + 1e-12)
                    self.assertTrue(0.0 <= t[i] <= 1.0)
                    self.assertAlmostEqual(float(np.hypot(*(foot[i] - p))), float(d[i]), delta=1e-9 * (1 + d[i]))
                    np.testing.assert_allclose(e.point(float(t[i])), foot[i], rtol=0, atol=1e-9)

    def test_nearest_point_does_not_depend_on_where_the_element_is_nor_its_size(self):
        # nearest-point.md: a local frame, "divided by a power of two (exact)", "does not depend on where the element
        # is (offsets of 1e2 m) or on its size (1e-6 m elements)". Inputs on a 2^-20 grid: an offset of 128 and a
        # scale of 2^k are exact, so the local problem is the same bits.
        rng = np.random.default_rng(11)
        cps = rng.integers(0, 2 ** 20, size=(4, 2)) / 2.0 ** 20
        points = rng.integers(-2 ** 19, 2 ** 21, size=(40, 2)) / 2.0 ** 20
        for method in ("exact", "newton", "subdivision"):
            t0, foot0, d0 = cg.nearest_point(cps, points, method=method)
            t, foot, d = cg.nearest_point(cps + 128.0, points + 128.0, method=method)
            with self.subTest(method=method, moved="offset 128"):
                self.assertEqual((bits(t), bits(d)), (bits(t0), bits(d0)))
                np.testing.assert_allclose(foot - 128.0, foot0, rtol=0, atol=1e-13)
            if method == "subdivision":   # its tolerance is a length: not scale-free
                continue
            for k in (-1000, -20, 20, 400):
                t, foot, d = cg.nearest_point(np.ldexp(cps, k), np.ldexp(points, k), method=method)
                with self.subTest(method=method, scaled=k):
                    self.assertEqual(bits(t), bits(t0))
                    self.assertEqual(bits(d), bits(np.ldexp(d0, k)))
                    self.assertEqual(bits(foot), bits(np.ldexp(foot0, k)))

    def test_nearest_point_finite_up_to_1e150_and_for_denormals(self):
        cases = [([[0, 0], [1e150, 1e150]], [1e150, 0.0]),
                 ([[-1e150, 0], [0, 1e150], [1e150, 0], [0, -1e150]], [1e150, 1e150]),
                 ([[0, 0], [1, 0], [1, 1]], [-1e150, 1e150]),
                 ([[0, 0], [1e-300, 0], [2e-300, 1e-300]], [5e-324, -5e-324]),
                 ([[5e-324, 0], [0, 5e-324], [1e-310, 1e-310]], [0.0, -0.0]),
                 ([[5e-324, 0], [0, 5e-324]], [0.0, 0.0])]
        for cps, p in cases:
            for method in ("exact", "newton", "subdivision"):
                with self.subTest(element=cps, point=p, method=method):
                    t, foot, d = cg.nearest_point(cps, p, method=method)
                    self.assertTrue(0.0 <= t <= 1.0, t)
                    self.assertTrue(np.isfinite(foot).all() and np.isfinite(d) and d >= 0, (foot, d))
        t, foot, d = cg.nearest_point([[0, 0], [1e150, 1e150]], [1e150, 0.0])
        self.assertAlmostEqual(t, 0.5, delta=1e-12)
        self.assertAlmostEqual(d / (1e150 / np.sqrt(2)), 1.0, delta=1e-12)

    def test_nearest_point_from_two_threads_on_one_shared_fortran_array(self):
        rng = np.random.default_rng(3)
        points = np.asfortranarray(rng.uniform(-100, 1100, size=(20000, 2)))
        points.flags.writeable = False
        serial = cg.nearest_point(CUBIC, points)
        results = [None, None]

        def work(i):
            results[i] = cg.nearest_point(CUBIC, points)

        threads = [threading.Thread(target=work, args=(i,)) for i in range(2)]
        for th in threads:
            th.start()
        for th in threads:
            th.join(30)
        for got in results:
            self.assertIsNotNone(got)
            self.assertEqual([bits(x) for x in got], [bits(x) for x in serial])

    # ---- scenes: data units and metres ---------------------------------------------------------------------
    def test_placement_maps_hostile_arrays_and_agrees_with_the_placed_elements(self):
        placement = self.scene.characters[0].placement
        data = np.array(CUBIC, dtype=np.float64)
        base = placement.to_paper(data)
        expected = np.asarray(placement.origin_m) + placement.metres_per_unit * data
        np.testing.assert_allclose(base, expected, rtol=1e-15, atol=1e-18)
        np.testing.assert_allclose(placement.to_data(base), data, rtol=0, atol=1e-9)
        for name, form in same_numbers(data).items():
            with self.subTest(to_paper=name):
                self.assertEqual(bits(placement.to_paper(form)), bits(base))
        for name, form in not_real(data).items():
            with self.subTest(refused=name):
                with self.assertRaises(cg.InvalidArgument) as error:
                    placement.to_paper(form)
                self.assertNames(error, "points")
        for name, form in {"(3,)": [1.0, 2.0, 3.0], "(4, 3)": np.zeros((4, 3)), "(2, 2, 2)": np.zeros((2, 2, 2))}.items():
            with self.subTest(shape=name):
                with self.assertRaises(cg.InvalidArgument) as error:
                    placement.to_paper(form)
                self.assertNames(error, "points")
                with self.assertRaises(cg.InvalidArgument) as error:
                    placement.to_data(form)
                self.assertNames(error, "points_m")
        # The Scene's elements are the library's, placed: metres = to_paper(data units), and the nearest point on
        # the placed element is the data one scaled by metres_per_unit.
        character = cg.CharacterLibrary.default().load("十")
        for k, (stroke, placed) in enumerate(zip(character.strokes, self.scene.characters[0].strokes)):
            for e_data, e_m in zip(stroke.elements, placed.elements):
                with self.subTest(stroke=k):
                    np.testing.assert_allclose(e_m.control_points, placement.to_paper(e_data.control_points),
                                               rtol=1e-12, atol=1e-15)
                    p_data = np.array([[400.0, 500.0], [20.0, 1000.0], [512.0, 512.0]])
                    t_d, foot_d, d_d = cg.nearest_point(e_data, p_data)
                    t_m, foot_m, d_m = cg.nearest_point(e_m, placement.to_paper(p_data))
                    np.testing.assert_allclose(t_m, t_d, rtol=0, atol=1e-9)
                    np.testing.assert_allclose(d_m, d_d * placement.metres_per_unit, rtol=1e-9, atol=1e-15)
                    np.testing.assert_allclose(foot_m, placement.to_paper(foot_d), rtol=0, atol=1e-12)

    # ---- stroke matching: hostile paths --------------------------------------------------------------------
    def test_match_stroke_reads_hostile_path_arrays_as_their_numbers(self):
        path = walk(np.asarray(self.stroke.centre_line_m), 2e-4)
        base = cg.match_stroke(self.scene, 0, 0, path)
        self.assertTrue(base.accepted, base.refusal)
        fields = ("accepted", "refusal", "matched_stroke", "entered", "covered_fraction", "mean_deviation_m")
        want = [getattr(base, f) for f in fields]
        forms = {"big-endian": path.astype(">f8"), "fortran": np.asfortranarray(path),
                 "transposed-view": np.ascontiguousarray(path.T).T, "row-strided": np.repeat(path, 2, axis=0)[::2],
                 "reversed-view": np.ascontiguousarray(path[::-1])[::-1], "list": path.tolist(),
                 "object": path.astype(object), "dataframe": pd.DataFrame(path, columns=["x", "y"])}
        ro = path.copy()
        ro.flags.writeable = False
        forms["read-only"] = ro
        for name, form in forms.items():
            with self.subTest(path=name):
                got = cg.match_stroke(self.scene, 0, 0, form)
                self.assertEqual([getattr(got, f) for f in fields], want)
        f32 = path.astype(np.float32)
        self.assertEqual([getattr(cg.match_stroke(self.scene, 0, 0, f32), f) for f in fields],
                         [getattr(cg.match_stroke(self.scene, 0, 0, f32.astype(np.float64)), f) for f in fields])

    def test_match_stroke_refuses_bad_paths_naming_path_m(self):
        path = walk(np.asarray(self.stroke.centre_line_m), 2e-4)
        bad = {"complex": path.astype(complex), "text": path.astype(str), "(N, 3)": np.zeros((len(path), 3)),
               "1-D": path.ravel(), "3-D": path[None], "no point": np.zeros((0, 2)),
               "NaN row": np.vstack([path, [np.nan, 0.0]]), "inf": np.vstack([[np.inf, 0.0], path])}
        masked = np.ma.masked_array(path, mask=np.zeros_like(path, dtype=bool))
        masked.mask[3, 1] = True
        bad["masked-one"] = masked
        for name, form in bad.items():
            with self.subTest(path=name):
                with self.assertRaises(cg.InvalidArgument) as error:
                    cg.match_stroke(self.scene, 0, 0, form)
                self.assertNames(error, "path_m")

    def test_match_stroke_on_a_path_that_leaps_1e300_metres_gives_a_verdict(self):
        # Finite is a path: only "a point that is not finite" is refused. Run apart, so that a matcher walking the
        # leap in 0.25 mm steps shows as a timeout instead of hanging the round.
        code = ("import numpy as np, calligraphy as cg\n"
                "s = cg.Scene('十'); c = np.asarray(s.characters[0].strokes[0].centre_line_m)\n"
                "for far in (1e300, -1e300, 1e150):\n"
                "    m = cg.match_stroke(s, 0, 0, np.vstack([c, [far, far]]))\n"
                "    print(m.accepted, m.covered_fraction, m.mean_deviation_m)\n")
        env = dict(os.environ)
        done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60, env=env)
        self.assertEqual(done.returncode, 0, done.stderr)
        lines = done.stdout.split("\n")[:3]
        for line in lines:
            accepted, covered, deviation = line.split()
            self.assertTrue(0.0 <= float(covered) <= 1.0, line)
            self.assertTrue(np.isfinite(float(deviation)), line)

    # ---- device states ------------------------------------------------------------------------------------
    def test_device_state_takes_hostile_arrays_as_copies(self):
        values = np.array([[1.0, -2.0, 3.0]])
        for name, form in same_numbers(np.vstack([values, values])).items():
            if name == "dataframe":
                continue
            row = form[0]
            with self.subTest(position=name):
                state = cg.DeviceState(position_m=row, velocity_m_s=row)
                self.assertEqual(bits(state.position_m), bits(values[0]))
                self.assertEqual(bits(state.velocity_m_s), bits(values[0]))
        source = values[0].copy()
        state = cg.DeviceState(position_m=source, time_s=np.float32(0.5))
        source[0] = 9.0
        self.assertEqual(bits(state.position_m), bits(values[0]), "a copy, not a view of the caller's array")
        self.assertFalse(state.position_m.flags.writeable)
        with self.assertRaises(ValueError):
            state.position_m[0] = 1.0
        self.assertEqual(state.time_s, 0.5)
        state.position_m = np.array([1.0, 2.0, 3.0], dtype=">f8")[::-1]
        self.assertEqual(state.position_m.tolist(), [3.0, 2.0, 1.0])

    def test_device_state_refuses_bad_shapes_and_non_real_arrays_naming_the_field(self):
        good = np.array([[1.0, -2.0, 3.0]])
        bad = {k: v[0] for k, v in not_real(good).items()}
        bad.update({"(2,)": [0.0, 0.0], "(4,)": [0.0] * 4, "(3, 3)": np.zeros((3, 3)), "(0,)": []})
        for field in ("position_m", "velocity_m_s"):
            for name, form in bad.items():
                with self.subTest(field=field, value=name):
                    with self.assertRaises(cg.InvalidArgument) as error:
                        cg.DeviceState(**{field: form})
                    self.assertNames(error, field)
            state = cg.DeviceState(position_m=(1.0, 2.0, 3.0), velocity_m_s=(4.0, 5.0, 6.0))
            with self.subTest(field=field, assigned="(2,)"):
                with self.assertRaises(cg.InvalidArgument) as error:
                    setattr(state, field, [0.0, 0.0])
                self.assertNames(error, field)
            self.assertEqual(state.position_m.tolist() + state.velocity_m_s.tolist(), [1, 2, 3, 4, 5, 6])
            with self.subTest(field=field, value="0-d"):
                with self.assertRaises((cg.InvalidArgument, TypeError)) as error:
                    cg.DeviceState(**{field: np.float64(1.0)})
                self.assertNames(error, field)
        with self.assertRaises(TypeError) as error:
            cg.DeviceState(time_s="0.1")
        self.assertNames(error, "time_s")
        for buttons in (-1, 2 ** 32, 2 ** 70, np.int64(-1)):
            with self.subTest(buttons=buttons):
                with self.assertRaises(cg.InvalidArgument) as error:
                    cg.DeviceState(buttons=buttons)
                self.assertNames(error, "buttons")

    def test_device_state_pickles_and_copies_hostile_values_at_every_protocol(self):
        state = cg.DeviceState(position_m=(-0.0, 5e-324, 1e300), velocity_m_s=(np.nan, -np.inf, 2.0 ** -1074),
                               buttons=2 ** 32 - 1, time_s=2.0 ** 62)
        copies = [pickle.loads(pickle.dumps(state, protocol=p)) for p in range(6)]
        copies += [copy.copy(state), copy.deepcopy(state)]
        for i, got in enumerate(copies):
            with self.subTest(copy=i):
                self.assertEqual(bits(got.position_m), bits(state.position_m))
                self.assertEqual(bits(got.velocity_m_s), bits(state.velocity_m_s))
                self.assertEqual((got.buttons, got.time_s), (2 ** 32 - 1, 2.0 ** 62))

    # ---- the renderer, one tick at a time -----------------------------------------------------------------
    def held_check(self, out, tip):
        """The in-plane force of a pen held still in WS is K_et a (X_S - X_p), X_S the foot on the placed element."""
        self.assertEqual(out.state, cg.InteractionState.writing)
        self.assertTrue(out.in_constraint_space)
        e = self.stroke.elements[out.element]
        _, foot, d = cg.nearest_point(e, tip)
        self.assertTrue(0.5e-3 < d < 1.5e-3, d)   # the path's own geometry: about 1 mm off
        factors = np.asarray(self.stroke.attraction_factors)[out.element:out.element + 2]
        f = np.asarray(out.force_n[:2])
        towards = (foot - tip) / d
        self.assertLessEqual(abs(f[0] * towards[1] - f[1] * towards[0]), 1e-9 + 1e-6 * np.hypot(*f))
        self.assertGreater(f @ towards, 0.0)
        a = np.hypot(*f) / (K_ET * d)
        self.assertTrue(factors.min() - 1e-9 <= a <= factors.max() + 1e-9, (a, factors))
        np.testing.assert_allclose(out.foot_m, foot, rtol=0, atol=1e-9)
        self.assertAlmostEqual(out.force_n[2], K_EN * (0.0 - DOWN_M), delta=1e-9)
        return f

    def test_held_pen_feels_eq8_in_newtons_towards_the_placed_foot_point(self):
        out = self.guided[self.n_hold - 1]
        self.held_check(out, self.hold_xyz[-1, :2])

    def test_guidance_force_scales_with_the_stiffness(self):
        half = cg.Renderer(self.scene, cg.ForceLawParameters(guidance_stiffness_n_per_m=K_ET / 2), device=self.device)
        out = tick_all(half, self.cross_states[: self.n_hold])[-1]
        full = np.asarray(self.guided[self.n_hold - 1].force_n[:2])
        np.testing.assert_allclose(np.asarray(out.force_n[:2]) * 2, full, rtol=1e-9, atol=0)
        self.assertAlmostEqual(out.force_n[2], self.guided[self.n_hold - 1].force_n[2], delta=1e-12)

    def test_force_is_continuous_across_the_constraint_edge_and_zero_beyond_it(self):
        outs = self.guided[self.n_hold - 1:]
        f = forces(outs)
        steps = np.hypot.reduce(np.diff(f, axis=0), axis=1)
        self.assertLess(steps.max(), 0.03, "a step at the edge of R_res: the taper and cross-fade should spread it")
        self.assertFalse(any("rate" in o.limit_names for o in outs), "the per-tick limit had to act")
        self.assertTrue(outs[0].in_constraint_space)
        self.assertFalse(outs[-1].in_constraint_space)
        self.assertEqual(outs[-1].state, cg.InteractionState.writing)
        np.testing.assert_allclose(f[-1, :2], [0.0, 0.0], rtol=0, atol=1e-12)
        self.assertAlmostEqual(f[-1, 2], K_EN * (0.0 - DOWN_M), delta=1e-9)
        # Control: the paper's step (no taper, no cross-fade) is what the per-tick limit catches.
        law = cg.ForceLawParameters(constraint_taper_m=0.0, crossfade_s=0.0)
        stepped = tick_all(cg.Renderer(self.scene, law, device=self.device), self.cross_states)[self.n_hold - 1:]
        self.assertTrue(any("rate" in o.limit_names for o in stepped), "the control did not step")

    def test_no_in_plane_force_at_all_without_guidance_and_friction(self):
        law = cg.ForceLawParameters(guidance=False, friction_coefficient=0.0)
        outs = tick_all(cg.Renderer(self.scene, law, device=self.device), self.cross_states)
        f = forces(outs)
        self.assertTrue((f[:, :2] == 0.0).all(), np.abs(f[:, :2]).max())
        self.assertAlmostEqual(f[self.n_hold - 1, 2], K_EN * (0.0 - DOWN_M), delta=1e-9)
        self.assertEqual(outs[self.n_hold - 1].state, cg.InteractionState.writing)

    def test_tick_reads_hostile_device_state_arrays_as_their_numbers(self):
        plain = cg.Renderer(self.scene, device=self.device)
        hostile = cg.Renderer(self.scene, device=self.device)
        xyz = self.hold_xyz[:400].astype(np.float32).astype(np.float64)
        vel = self.hold_velocity[:400].astype(np.float32).astype(np.float64)
        big = xyz.astype(">f8")
        fortran = np.asfortranarray(np.column_stack([xyz, vel]))
        for k in range(len(xyz)):
            a = plain.tick(cg.DeviceState(position_m=xyz[k], velocity_m_s=vel[k], time_s=k / RATE_HZ))
            form = k % 4
            if form == 0:
                s = cg.DeviceState(position_m=big[k], velocity_m_s=fortran[k, 3:], time_s=np.float64(k / RATE_HZ))
            elif form == 1:
                s = cg.DeviceState(position_m=xyz[k].astype(np.float32), velocity_m_s=vel[k].astype(np.float32),
                                   time_s=k / RATE_HZ)
            elif form == 2:
                s = cg.DeviceState(position_m=fortran[k, :3], velocity_m_s=list(vel[k]), time_s=k / RATE_HZ)
            else:
                s = cg.DeviceState(position_m=xyz[k].astype(object), velocity_m_s=tuple(vel[k]), time_s=k / RATE_HZ)
            b = hostile.tick(s)
            self.assertEqual(bits(b.force_n), bits(a.force_n), k)
            self.assertEqual((b.state, b.stroke, b.element), (a.state, a.stroke, a.element), k)

    def test_reading_that_is_no_pen_gives_zero_force_then_climbs_at_the_tick_limit(self):
        box = np.asarray(self.scene.characters[0].bounding_box_m)
        spot = box[0] + 0.25 * (box[1] - box[0])
        for s in self.scene.characters[0].strokes:
            self.assertGreater(np.hypot(*(spot - np.asarray(s.start_m))), 0.01)   # no stroke starts here
        depth = -0.005
        xyz = [(*spot, HOVER_M)] * 10 + [(*spot, HOVER_M + (depth - HOVER_M) * a) for a in np.linspace(0, 1, 40)[1:]]
        clock = iter(np.arange(len(xyz), 10 ** 5) / RATE_HZ)
        pressed = cg.DeviceState(position_m=(*spot, depth))

        def press(n):
            return [pressed.replace(time_s=float(next(clock))) for _ in range(n)]

        bad = {"NaN position": pressed.replace(position_m=(np.nan, spot[1], depth)),
               "inf velocity": pressed.replace(velocity_m_s=(0.0, np.inf, 0.0)),
               "NaN time": pressed.replace(time_s=np.nan),
               "10.5 m away": pressed.replace(position_m=(10.5, spot[1], depth)),
               "-1e300 z": pressed.replace(position_m=(spot[0], spot[1], -1e300))}
        renderer = cg.Renderer(self.scene, device=self.device)
        tick_all(renderer, states(xyz))
        settled = tick_all(renderer, press(400))[-1]
        np.testing.assert_allclose(settled.force_n, [0.0, 0.0, K_EN * -depth], rtol=0, atol=1e-9)
        for name, reading in bad.items():
            with self.subTest(reading=name):
                out = renderer.tick(reading.replace(time_s=reading.time_s if name == "NaN time" else next(clock)))
                self.assertTrue(out.input_rejected)
                self.assertEqual(out.force_n.tolist(), [0.0, 0.0, 0.0])
                self.assertIn("non_finite", out.limit_names)
                back = forces(tick_all(renderer, press(40)))
                climb = np.hypot.reduce(np.diff(np.vstack([[0, 0, 0], back]), axis=0), axis=1)
                self.assertLessEqual(climb.max(), MAX_STEP_N + 1e-12)
                np.testing.assert_allclose(back[20:], np.tile([0.0, 0.0, K_EN * -depth], (20, 1)), rtol=0,
                                           atol=1e-9, err_msg="the force did not climb back at the per-tick limit")
        out = renderer.tick(pressed.replace(position_m=(spot[0], spot[1], depth + 0.0), time_s=-5.0))
        self.assertFalse(out.input_rejected, "a finite time stamp that goes back is a reading")

    def test_time_stamps_only_differences_count_and_hostile_ones_keep_the_limits(self):
        # device_types.hpp: "Only differences are meaningful". At 1024 Hz the times k / 1024 and 2^20 + k / 1024 are
        # exact and so are their differences: the forces are the same bits.
        n = self.n_hold
        xyz, vel = self.hold_xyz, self.hold_velocity
        rate = 1024.0
        options = cg.RendererOptions(rate_hz=rate)
        runs = {}
        for name, t0 in (("origin 0", 0.0), ("origin 2^20 s", 2.0 ** 20)):
            r = cg.Renderer(self.scene, device=self.device, options=options)
            runs[name] = tick_all(r, states(xyz, rate, times=t0 + np.arange(n) / rate, velocity=vel))
        a, b = (forces(v) for v in runs.values())
        self.assertEqual(bits(a), bits(b))
        base_t = np.arange(n) / RATE_HZ
        hostile = {"back 1 s": np.where(np.arange(n) == 300, base_t - 1.0, base_t),
                   "each twice": np.floor(np.arange(n) / 2) / RATE_HZ * 2,
                   "all the same": np.zeros(n),
                   "jump 1e9 s": np.where(np.arange(n) >= 300, base_t + 1e9, base_t),
                   "1e300 s": np.where(np.arange(n) == 500, 1e300, base_t),
                   "backwards": -base_t}
        for name, times in hostile.items():
            with self.subTest(times=name):
                outs = tick_all(cg.Renderer(self.scene, device=self.device), states(xyz, times=times, velocity=vel))
                f = forces(outs)
                self.assertTrue(np.isfinite(f).all())
                self.assertFalse(any(o.input_rejected for o in outs))
                self.assertLessEqual(np.hypot.reduce(f, axis=1).max(), self.device.max_force_n + 1e-12)
                steps = np.hypot.reduce(np.diff(np.vstack([[0, 0, 0], f]), axis=0), axis=1)
                self.assertLessEqual(steps.max(), MAX_STEP_N + 1e-12)

    def test_device_limits_bound_the_force_above_what_the_options_ask(self):
        small = self.device.replace(max_force_n=1.0, max_continuous_force_n=1.0)
        options = cg.RendererOptions(safety=cg.SafetyChainParameters(
            max_force_n=50.0, max_continuous_force_n=50.0, start_ramp_n_per_s=0.0, max_force_change_n_per_tick=0.0))
        box = np.asarray(self.scene.characters[0].bounding_box_m)
        spot = box[0] + 0.25 * (box[1] - box[0])
        xyz = [(*spot, HOVER_M + (-0.02 - HOVER_M) * a) for a in np.linspace(0, 1, 60)] + [(*spot, -0.02)] * 300
        outs = tick_all(cg.Renderer(self.scene, device=small, options=options), states(xyz))
        f = forces(outs)
        self.assertLessEqual(np.hypot.reduce(f, axis=1).max(), 1.0 + 1e-12)
        np.testing.assert_allclose(f[-1], [0.0, 0.0, 1.0], rtol=0, atol=1e-9)

    def test_renderer_refuses_bad_arguments_by_name(self):
        with self.assertRaises(cg.InvalidArgument) as error:
            cg.Renderer(self.scene, device=cg.DeviceInfo())
        self.assertNames(error, "max_force_n")
        with self.assertRaises(TypeError) as error:
            cg.Renderer("十")
        self.assertNames(error, "scene")
        for rate in (99.0, 100001.0, np.nan, np.inf):
            with self.subTest(rate_hz=rate):
                with self.assertRaises(cg.InvalidArgument) as error:
                    cg.RendererOptions(rate_hz=rate)
                self.assertNames(error, "rate_hz")
        renderer = cg.Renderer(self.scene)
        for state in (None, {"position_m": (0, 0, 0)}, (0.0, 0.0, 0.0), np.zeros(3)):
            with self.subTest(state=repr(state)):
                with self.assertRaises(TypeError) as error:
                    renderer.tick(state)
                self.assertNames(error, "state")

    def test_render_output_arrays_are_read_only_and_outlive_later_ticks(self):
        renderer = cg.Renderer(cg.Scene("十"), device=self.device)   # the Scene kept alive by the renderer alone
        gc.collect()
        outs = []
        kept = []
        for s in self.cross_states[:self.n_hold]:
            out = renderer.tick(s)
            outs.append(out)
            kept.append((out.force_n, out.foot_m, out.force_n.tolist(), out.foot_m.tolist()))
        for force, foot, force_then, foot_then in kept:
            self.assertFalse(force.flags.writeable or foot.flags.writeable)
            self.assertEqual((force.tolist(), foot.tolist()), (force_then, foot_then))
        self.assertEqual(bits(forces(outs)), bits(forces(self.guided[:self.n_hold])))
        self.assertEqual(bits(renderer.scene.strokes[0].start_m), bits(self.stroke.start_m))

    def test_renderer_scene_and_outputs_refuse_pickle_and_copy(self):
        renderer = cg.Renderer(self.scene, device=self.device)
        out = renderer.tick(cg.DeviceState(position_m=(0.0, 0.0, 0.05)))
        for obj in (renderer, out, self.scene, cg.SimulatedDevice()):
            name = type(obj).__name__
            for how, call in [(f"protocol {p}", lambda o, p=p: pickle.dumps(o, protocol=p)) for p in range(6)] + \
                    [("copy", copy.copy), ("deepcopy", copy.deepcopy)]:
                with self.subTest(obj=name, how=how):
                    with self.assertRaises(TypeError) as error:
                        call(obj)
                    self.assertIn("cannot pickle", str(error.exception))
                    self.assertIn(name, str(error.exception))

    def test_reset_goes_back_to_the_first_stroke_in_separation(self):
        centre = walk(np.asarray(self.stroke.centre_line_m), 4e-5)
        start, end = centre[0], centre[-1]
        xyz = ([(*start, HOVER_M)] * 10 + [(*start, HOVER_M + (DOWN_M - HOVER_M) * a) for a in np.linspace(0, 1, 20)]
               + [(*p, DOWN_M) for p in centre] + [(*end, DOWN_M + (0.005 - DOWN_M) * a) for a in np.linspace(0, 1, 30)]
               + [(*end, 0.005)] * 10)
        renderer = cg.Renderer(self.scene, device=self.device)
        for attempt in range(2):
            with self.subTest(attempt=attempt):
                outs = tick_all(renderer, states(xyz))
                done = [i for i, o in enumerate(outs) if o.stroke_completed]
                self.assertEqual(len(done), 1, "stroke 0 written once")
                self.assertEqual((outs[-1].stroke, outs[-1].state), (1, cg.InteractionState.separation))
                renderer.reset()
                self.assertEqual(renderer.state, cg.InteractionState.separation)
                out = renderer.tick(cg.DeviceState(position_m=(*end, 0.005)))
                self.assertEqual((out.stroke, out.character, out.state), (0, 0, cg.InteractionState.separation))

    def test_match_stroke_refuses_indices_out_of_range_by_name(self):
        path = np.asarray(self.stroke.centre_line_m)
        for value in (2, -1, np.int64(-1), np.uint64(2), 2 ** 70):
            with self.subTest(stroke_index=repr(value)):
                with self.assertRaises(IndexError) as error:
                    cg.match_stroke(self.scene, 0, value, path)
                self.assertNames(error, "stroke_index")
            with self.subTest(character_index=repr(value)):
                with self.assertRaises(IndexError) as error:
                    cg.match_stroke(self.scene, value, 0, path)
                self.assertNames(error, "character_index")
        same = cg.match_stroke(self.scene, np.int16(0), np.uint8(0), path)
        self.assertTrue(same.accepted)

    def test_force_law_functions_scale_saturate_and_stay_continuous(self):
        rng = np.random.default_rng(5)
        tips = rng.integers(-4096, 4096, size=(50, 2)) / 2.0 ** 20
        foot = np.array([3.0, -5.0]) / 2.0 ** 10
        f1 = cg.attraction_force(tips.astype(">f8"), foot, K_ET, 1.5)
        np.testing.assert_allclose(f1, K_ET * 1.5 * (foot - tips), rtol=1e-15, atol=0)
        self.assertEqual(bits(cg.attraction_force(np.asfortranarray(tips), foot, 2 * K_ET, 1.5)), bits(2 * f1))
        # Friction: at most mu N, against the velocity, continuous through the stick band's edge.
        mu, band, normal_n = 0.15, 0.02, 2.0
        speeds = np.concatenate([np.geomspace(1e-9, 10, 200), band * (1 + np.array([-1e-12, 0.0, 1e-12]))])
        v = np.column_stack([speeds * 0.6, -speeds * 0.8])
        f = cg.friction_force(v[::-1][::-1], normal_n, mu, band)
        self.assertLessEqual(np.hypot.reduce(f, axis=1).max(), mu * normal_n * (1 + 1e-15))
        np.testing.assert_allclose(f, -mu * normal_n * v / np.maximum(speeds, band)[:, None], rtol=1e-12, atol=0)
        # Taper: 1 inside R - band, 0 from R, a C1 smoothstep between, 0.5 half-way; never outside [0, 1].
        radius, taper = 0.006, 0.002
        d = np.linspace(0.0, 0.008, 8001)
        w = cg.constraint_taper(d.astype(">f8"), radius, taper)
        self.assertTrue(((w >= 0) & (w <= 1)).all() and (np.diff(w) <= 0).all())
        self.assertTrue((w[d <= radius - taper] == 1).all() and (w[d >= radius] == 0).all())
        self.assertEqual(cg.constraint_taper(radius - taper / 2, radius, taper), 0.5)
        self.assertLess(np.abs(np.diff(w)).max(), 1.5 * 1e-6 / taper * 1.0001)
        # Clamp: direction kept for any finite size, non-finite rows zero, others untouched.
        rows = np.array([[1e308, 1e308, 0.0], [np.nan, 1.0, 1.0], [3.0, 4.0, 0.0], [np.inf, 0.0, 0.0],
                         [-1e308, 0.0, -1e308], [0.0, 0.0, 0.0]])
        got = cg.clamp_force(np.asfortranarray(rows), 7.9)
        s = 7.9 / np.sqrt(2)
        np.testing.assert_allclose(got, [[s, s, 0], [0, 0, 0], [3, 4, 0], [0, 0, 0], [-s, 0, -s], [0, 0, 0]],
                                   rtol=1e-15, atol=0)
        # The paper pushes out only below it: K (z0 - z), zero at and above z0.
        z = np.array([-0.002, -0.0, 0.0, 5e-324, -5e-324, 0.001, -1e-3])
        pf = cg.paper_force(z.astype(">f8")[::-1][::-1], 0.0, K_EN)
        np.testing.assert_allclose(pf[:, 2], np.where(z < 0, K_EN * -z, 0.0), rtol=1e-15, atol=0)
        self.assertTrue((pf[:, :2] == 0).all() and (pf[:, 2] >= 0).all())

    # ---- the simulated device ----------------------------------------------------------------------------
    def test_simulated_device_force_and_steps_hostile(self):
        dev = cg.SimulatedDevice()
        peak = dev.info.max_force_n
        wanted = np.array([[1.0, -2.0, 3.0]])
        for name, form in same_numbers(np.vstack([wanted, wanted])).items():
            if name == "dataframe":
                continue
            with self.subTest(force=name):
                dev.write_force([0.0, 0.0, 0.0])
                dev.write_force(form[0])
                self.assertEqual(bits(dev.applied_force_n), bits(wanted[0]))
        for name, form in {**{k: v[0] for k, v in not_real(wanted).items()}, "(2,)": [1.0, 0.0],
                           "(2, 3)": np.zeros((2, 3))}.items():
            with self.subTest(refused=name):
                with self.assertRaises(cg.InvalidArgument) as error:
                    dev.write_force(form)
                self.assertNames(error, "force_n")
        dev.write_force([1e308, 1e308, 0.0])
        np.testing.assert_allclose(dev.applied_force_n, [peak / np.sqrt(2), peak / np.sqrt(2), 0.0], rtol=1e-12)
        dev.write_force([1.0, 0.0, 0.0])
        dev.write_force([np.nan, 0.0, 0.0])
        self.assertEqual(dev.applied_force_n.tolist(), [0.0, 0.0, 0.0], "a non-finite force applies zero force")
        # The clock: whole nanoseconds; a bad step refused with the state unchanged.
        for _ in range(1000):
            dev.advance(1e-3)
        self.assertEqual(dev.time_s, 1.0)
        dev.advance(4e-10)
        self.assertEqual(dev.time_s, 1.0)
        dev.advance(6e-10)
        self.assertEqual(dev.time_s, 1.000000001)
        before = (dev.time_s, dev.true_position_m.tolist())
        for dt in (-1e-3, np.nan, np.inf, 5e9):
            with self.subTest(dt_s=dt):
                with self.assertRaises(cg.InvalidArgument) as error:
                    dev.advance(dt)
                self.assertNames(error, "dt_s")
            self.assertEqual((dev.time_s, dev.true_position_m.tolist()), before)
        # A huge step under 1 N: the terminal velocity F / b, the pen a million metres away, and the renderer takes
        # that reading for no pen.
        dev.write_force([1.0, 0.0, 0.0])
        x0 = dev.true_position_m[0]
        dev.advance(1e6)
        b = cg.SimulatedDeviceParameters().damping_n_s_per_m
        self.assertAlmostEqual(dev.true_velocity_m_s[0], 1.0 / b, delta=1e-9)
        self.assertAlmostEqual((dev.true_position_m[0] - x0) / (1e6 / b), 1.0, delta=1e-5)
        reading = dev.read_state()
        out = cg.Renderer(self.scene, device=dev.info).tick(reading)
        self.assertTrue(out.input_rejected)
        self.assertEqual(out.force_n.tolist(), [0.0, 0.0, 0.0])
        # Closed: reads and writes raise CommunicationError, no force acts; open again, the clock restarts.
        dev.close()
        with self.assertRaises(cg.CommunicationError):
            dev.read_state()
        with self.assertRaises(cg.CommunicationError):
            dev.write_force([1.0, 0.0, 0.0])
        self.assertEqual(dev.applied_force_n.tolist(), [0.0, 0.0, 0.0])
        dev.open()
        self.assertEqual(dev.time_s, 0.0)
        self.assertEqual(dev.read_state().time_s, 0.0)


if __name__ == "__main__":
    unittest.main()
