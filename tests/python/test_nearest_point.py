"""nearest_point against an independent numpy computation: dense sampling, then refinement."""

from math import comb

import numpy as np
import pytest

import calligraphy


def bezier(cp, t):
    n = len(cp) - 1
    t = np.asarray(t, dtype=float)
    return sum(comb(n, i) * ((1 - t) ** (n - i) * t**i)[..., None] * cp[i] for i in range(n + 1))


def reference_nearest(cp, p, samples=4001):
    """Brute force: sample densely, then golden-section search on the bracket around the best sample."""
    cp = np.asarray(cp, dtype=float)
    t = np.linspace(0.0, 1.0, samples)
    d = np.linalg.norm(bezier(cp, t) - p, axis=1)
    k = int(np.argmin(d))
    lo, hi = t[max(k - 1, 0)], t[min(k + 1, samples - 1)]
    g = (np.sqrt(5.0) - 1.0) / 2.0
    f = lambda s: float(np.linalg.norm(bezier(cp, s) - p))  # noqa: E731
    for _ in range(80):
        a, b = hi - g * (hi - lo), lo + g * (hi - lo)
        if f(a) < f(b):
            hi = b
        else:
            lo = a
    best = 0.5 * (lo + hi)
    return best, bezier(cp, best), f(best)


def curve_elements(library):
    elements = [e for ch in ("永", "我", "九", "心") for s in library.load(ch).strokes for e in s.elements]
    curves = [e for e in elements if e.degree >= 2]
    assert len(curves) >= 3
    return curves


@pytest.mark.parametrize("method", ["exact", "newton", "subdivision"])
def test_single_point_matches_reference(library, method):
    rng = np.random.default_rng(7)
    tolerance = 1e-12 if method == "exact" else 1e-9
    for element in curve_elements(library)[:6]:
        cp = element.control_points
        lo, hi = cp.min(axis=0) - 80, cp.max(axis=0) + 80
        for p in rng.uniform(lo, hi, size=(15, 2)):
            t, foot, distance = calligraphy.nearest_point(element, p, method=method, tolerance=tolerance)
            t_ref, foot_ref, d_ref = reference_nearest(cp, p)
            assert 0.0 <= t <= 1.0
            np.testing.assert_allclose(foot, bezier(cp, t), atol=1e-9)
            assert distance == pytest.approx(np.linalg.norm(p - foot), abs=1e-9)
            if method == "exact":
                # Global: never worse than the dense reference, and equal to it within refinement error.
                assert distance <= d_ref + 1e-7
                assert distance == pytest.approx(d_ref, abs=1e-6)
            else:
                # Local methods may settle in a local minimum; they can never beat the global one.
                assert distance >= d_ref - 1e-6


def test_vectorised_form_equals_single_calls(library):
    element = curve_elements(library)[0]
    rng = np.random.default_rng(1)
    cp = element.control_points
    points = rng.uniform(cp.min(axis=0) - 50, cp.max(axis=0) + 50, size=(200, 2))
    t, foot, distance = calligraphy.nearest_point(element, points)
    assert t.shape == (200,) and foot.shape == (200, 2) and distance.shape == (200,)
    for i in range(0, 200, 17):
        ti, fi, di = calligraphy.nearest_point(element, points[i])
        assert t[i] == ti and di == distance[i]
        np.testing.assert_array_equal(fi, foot[i])
    d_ref = np.array([reference_nearest(cp, p)[2] for p in points[:40]])
    np.testing.assert_allclose(distance[:40], d_ref, atol=1e-6)


def test_control_point_array_and_line_element():
    cp = np.array([[0.0, 0.0], [0.02, 0.0]])  # a 20 mm LSE, in metres
    t, foot, distance = calligraphy.nearest_point(cp, [0.005, 0.003])
    assert t == pytest.approx(0.25)
    np.testing.assert_allclose(foot, [0.005, 0.0], atol=1e-15)
    assert distance == pytest.approx(0.003)
    # Beyond the end the foot clamps to the endpoint.
    t, foot, distance = calligraphy.nearest_point(cp, [0.03, -0.004])
    assert t == 1.0
    np.testing.assert_allclose(foot, [0.02, 0.0])
    assert distance == pytest.approx(np.hypot(0.01, 0.004))
    # The same element given as a StrokeElement.
    element = calligraphy.StrokeElement(cp)
    assert element.kind == "line" and element.degree == 1
    assert calligraphy.nearest_point(element, [0.005, 0.003])[2] == pytest.approx(0.003)


def test_a_point_that_is_not_finite_is_named_by_the_argument_and_its_row():
    line = [[0.0, 0.0], [1.0, 0.0]]
    with pytest.raises(ValueError, match=r"^point = \(nan, 0\) is not finite"):
        calligraphy.nearest_point(line, [float("nan"), 0.0])
    with pytest.raises(ValueError, match=r"^point\[1\] = \(2e\+150, 1\)"):
        calligraphy.nearest_point(line, [[0.0, 0.0], [2e150, 1.0]])
    t, foot, distance = calligraphy.nearest_point(line, [1e150, 0.0])  # the bound itself is taken
    assert t == 1.0 and distance == pytest.approx(1e150)
