"""Figures of a trial: the trace over the reference (Fig. 31) and the in-plane force (Figs. 32-36)."""

import numpy as np
import pytest

import calligraphy

matplotlib = pytest.importorskip("matplotlib")
matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

import calligraphy.plot  # noqa: E402


@pytest.fixture(scope="module")
def result():
    return calligraphy.simulate_trial("永", seed=3)


def lines(ax, gid):
    return [line for line in ax.get_lines() if line.get_gid() == gid]


def test_trial_figure_draws_reference_in_blue_and_trace_in_green(result, tmp_path):
    ax = calligraphy.plot.trial(result, hints=True)
    scene = result.scene
    assert len(lines(ax, "calligraphy-median")) == scene.stroke_count
    assert len(lines(ax, "calligraphy-element")) == sum(len(s.elements) for s in scene.strokes)
    assert all(line.get_color() == "blue" for line in lines(ax, "calligraphy-element"))
    traces = lines(ax, "calligraphy-trace")
    assert len(traces) == scene.stroke_count
    for line, (begin, end) in zip(traces, result.stroke_trace_range):
        assert line.get_color() == "limegreen"
        np.testing.assert_allclose(line.get_xydata(), result.position_m[begin:end, :2] * 1e3)
    # Elements are drawn in mm through their own points.
    first = scene.strokes[0].elements[0]
    np.testing.assert_allclose(lines(ax, "calligraphy-element")[0].get_xydata()[0], first.control_points[0] * 1e3)
    assert len([p for p in ax.patches if p.get_gid() == "calligraphy-hint"]) == scene.stroke_count
    assert "永" in ax.get_title()
    ax.figure.savefig(tmp_path / "trial.png")
    plt.close(ax.figure)


def test_forces_figure_marks_stroke_boundaries(result):
    fig, ax = plt.subplots()
    assert calligraphy.plot.forces(result, ax=ax) is ax
    (magnitude,) = lines(ax, "calligraphy-in-plane-force")
    np.testing.assert_allclose(magnitude.get_ydata(), np.hypot(result.force_n[:, 0], result.force_n[:, 1]))
    np.testing.assert_array_equal(magnitude.get_xdata(), result.time_s)
    boundaries = lines(ax, "calligraphy-stroke-boundary")
    changes = np.flatnonzero(np.diff(result.stroke)) + 1
    assert len(boundaries) == len(changes) == result.metrics["strokes_total"] - 1
    assert [b.get_xdata()[0] for b in boundaries] == list(result.time_s[changes])
    labels = [t.get_text() for t in ax.texts]
    assert labels == [f"永 {s.acronym}" for s in result.scene.strokes]
    plt.close(fig)


def test_a_cjk_font_is_found():
    font = calligraphy.plot.cjk_font()
    assert font is not None
    from matplotlib import ft2font

    assert ord("永") in ft2font.FT2Font(font.get_file()).get_charmap()


def test_no_trace_no_figure():
    result = calligraphy.simulate_trial("九", keep_trace=False)
    with pytest.raises(ValueError, match="keep_trace"):
        calligraphy.plot.trial(result)
    with pytest.raises(ValueError, match="keep_trace"):
        calligraphy.plot.forces(result)
