"""Figures of a trial with matplotlib, after the paper's (Wang, Zhang & Yao 2006, section 7):

* ``trial(result)``: the pen trace over the reference character, Fig. 31: the reference in blue
  (the source medians broad and light, the fitted stroke elements thin, feature points as dots), the
  pen's trace of each stroke (its last attempt) in green;
* ``forces(result)``: the force in the paper plane over time with the stroke boundaries,
  Figs. 32-36 (zoom with ``ax.set_xlim`` for a detailed view such as Fig. 36).

matplotlib is optional: it is imported when a figure is made, not with ``calligraphy``. Characters
in titles and labels use a CJK font found through matplotlib's font manager (Debian's
fonts-arphic-ukai or fonts-noto-cjk); without one they may show as boxes. Lengths are drawn in mm.
"""

from __future__ import annotations

import typing

import numpy as np

from .stats.fonts import cjk_font

if typing.TYPE_CHECKING:  # pragma: no cover
    import matplotlib.axes

    from ._calligraphy import Scene, TrialResult

REFERENCE_COLOUR = "blue"
TRACE_COLOUR = "limegreen"
HINT_COLOUR = "red"

_MM_PER_M = 1e3


def _pyplot():
    try:
        import matplotlib.pyplot as plt
    except ImportError as error:  # pragma: no cover - depends on the installation
        raise ImportError(
            "calligraphy.plot needs matplotlib (Debian: apt-get install python3-matplotlib; or pip install "
            "matplotlib)"
        ) from error
    return plt


def _text_font(text: str) -> dict:
    """For a text with CJK characters, the default family with the CJK font as fallback (matplotlib
    >= 3.6 falls back per glyph); else nothing."""
    if any(ord(c) >= 0x2E80 for c in text):
        font = cjk_font()
        if font is not None:
            return {"fontfamily": ["sans-serif", font.get_name()]}
    return {}


def _axes(ax, figsize):
    if ax is not None:
        import matplotlib.axes
        if not isinstance(ax, matplotlib.axes.Axes):
            raise TypeError(f"ax: expected matplotlib Axes, got {type(ax).__name__} {ax!r}")
        return ax
    _, ax = _pyplot().subplots(figsize=figsize)
    return ax


def _runs(mask: np.ndarray):
    """[start, end) index ranges where mask is True."""
    padded = np.zeros(mask.size + 2, dtype=np.int8)
    padded[1:-1] = mask
    edges = np.flatnonzero(np.diff(padded))
    return list(zip(edges[::2], edges[1::2]))


def _require_trace(result: TrialResult, what: str):
    from ._calligraphy import TrialResult as _TrialResult
    if not isinstance(result, _TrialResult):
        raise TypeError(f"calligraphy.plot.{what}: result: expected a TrialResult (simulate_trial, run_trial), "
                        f"got {type(result).__name__}")
    if np.asarray(result.time_s).size == 0:
        raise ValueError(f"calligraphy.plot.{what}: the result has no trace; run simulate_trial with "
                         "keep_trace=True")


def trial(result: TrialResult, scene: Scene | None = None, ax: matplotlib.axes.Axes | None = None, *,
          medians: bool = True, elements: bool = True, hints: bool = False) -> matplotlib.axes.Axes:
    """The pen trace over the reference, as the paper's Fig. 31.

    result: a TrialResult with its trace (keep_trace=True). scene: the Scene it was written on
    (default ``result.scene``). ax: the matplotlib Axes to draw into (default a new figure).
    medians: draw the source medians (broad, light blue; a corpus store's characters have none).
    elements: draw the fitted stroke elements (thin blue) and their feature points (dots).
    hints: draw the start hint of every stroke, a red ellipse of the scene's start radius (Fig. 30).
    The trace is the pen tip over each stroke's last attempt (``result.stroke_trace_range``: the ticks
    its deviations are measured over), one green line per stroke.
    Axes in mm, equal aspect. Returns the Axes. Raises ValueError for a result without a trace,
    ImportError without matplotlib. Artists carry gids 'calligraphy-median', 'calligraphy-element',
    'calligraphy-feature-points', 'calligraphy-trace', 'calligraphy-hint'.
    """
    from matplotlib.patches import Ellipse

    _require_trace(result, "trial")
    scene = result.scene if scene is None else scene
    ax = _axes(ax, (3.2 * len(scene.characters) + 1.0, 4.2))
    parameter = np.linspace(0.0, 1.0, 33)
    for stroke in scene.strokes:
        if medians and stroke.median_m.size:
            median = stroke.median_m * _MM_PER_M
            ax.plot(median[:, 0], median[:, 1], color=REFERENCE_COLOUR, alpha=0.2, lw=7,
                    solid_capstyle="round", gid="calligraphy-median", zorder=1)
        if elements:
            for element in stroke.elements:
                points = element.point(parameter if element.degree > 1 else parameter[[0, -1]]) * _MM_PER_M
                ax.plot(points[:, 0], points[:, 1], color=REFERENCE_COLOUR, lw=1.2, gid="calligraphy-element",
                        zorder=2)
            joints = np.array([e.control_points[0] for e in stroke.elements]
                              + [stroke.elements[-1].control_points[-1]]) * _MM_PER_M
            ax.plot(joints[:, 0], joints[:, 1], "o", color=REFERENCE_COLOUR, ms=2.5,
                    gid="calligraphy-feature-points", zorder=3)
        if hints:
            r = scene.layout.start_radius_m * _MM_PER_M
            start = stroke.start_m * _MM_PER_M
            ax.add_patch(Ellipse(tuple(start), 2 * r, 1.4 * r, fill=False, edgecolor=HINT_COLOUR, lw=1.0,
                                 gid="calligraphy-hint", zorder=4))
    position = np.asarray(result.position_m) * _MM_PER_M
    for k, (begin, end) in enumerate(np.asarray(result.stroke_trace_range)):
        if end > begin:
            ax.plot(position[begin:end, 0], position[begin:end, 1], color=TRACE_COLOUR, lw=1.0,
                    gid="calligraphy-trace", zorder=5, label="pen trace" if k == 0 else None)
    ax.set_aspect("equal")
    ax.set_xlabel("x [mm]")
    ax.set_ylabel("y [mm]")
    m = result.metrics
    deviation = "-" if m["mean_deviation_m"] is None else f"{m['mean_deviation_m'] * 1e3:.2f} mm"
    time = "-" if m["total_time_s"] is None else f"{m['total_time_s']:.1f} s"  # None: the pen never touched
    title = (f"{m['character']}: {m['strokes_completed']}/{m['strokes_total']} strokes, mean deviation "
             f"{deviation}, {time}")
    ax.set_title(title, **_text_font(title))
    return ax


def forces(result: TrialResult, ax: matplotlib.axes.Axes | None = None, *, components: bool = True,
           stroke_labels: bool = True) -> matplotlib.axes.Axes:
    """The force in the paper plane over time, as the paper's Figs. 32-36.

    result: a TrialResult with its trace. ax: the Axes (default a new figure). Draws |F_xy| [N] (the
    in-plane magnitude, black) and with ``components`` F_x and F_y [N]; shades the ticks in WS (green);
    marks each change of the active stroke with a dashed vertical line and, with ``stroke_labels``,
    names each stroke (character and typical-stroke acronym) above the plot. Time in s. Returns the
    Axes. Raises ValueError for a result without a trace, ImportError without matplotlib. Artists carry
    gids 'calligraphy-in-plane-force', 'calligraphy-fx', 'calligraphy-fy', 'calligraphy-stroke-boundary',
    'calligraphy-writing'.
    """
    from ._calligraphy import InteractionState

    _require_trace(result, "forces")
    ax = _axes(ax, (9.0, 3.6))
    time = np.asarray(result.time_s)
    force = np.asarray(result.force_n)
    ax.plot(time, np.hypot(force[:, 0], force[:, 1]), color="black", lw=0.8, label="|F_xy|",
            gid="calligraphy-in-plane-force")
    if components:
        ax.plot(time, force[:, 0], color="tab:orange", lw=0.6, label="F_x", gid="calligraphy-fx")
        ax.plot(time, force[:, 1], color="tab:purple", lw=0.6, label="F_y", gid="calligraphy-fy")
    writing = np.asarray(result.state) == int(InteractionState.writing)
    for k, (start, end) in enumerate(_runs(writing)):
        ax.axvspan(time[start], time[end - 1], color=TRACE_COLOUR, alpha=0.12, lw=0, gid="calligraphy-writing",
                   label="writing (WS)" if k == 0 else None)
    stroke = np.asarray(result.stroke)
    changes = np.flatnonzero(np.diff(stroke)) + 1
    for i in changes:
        ax.axvline(time[i], color="grey", ls="--", lw=0.7, gid="calligraphy-stroke-boundary")
    if stroke_labels:
        names = [f"{placed.char} {s.acronym}" for placed in result.scene.characters for s in placed.strokes]
        starts = np.insert(changes, 0, 0)
        ends = np.append(changes, time.size)
        for a, b in zip(starts, ends):
            name = names[stroke[a]] if stroke[a] < len(names) else ""
            ax.text((time[a] + time[b - 1]) / 2, 1.01, name, transform=ax.get_xaxis_transform(), ha="center",
                    va="bottom", fontsize=8, **_text_font(name))
    ax.set_xlabel("time [s]")
    ax.set_ylabel("force in the paper plane [N]")
    if time[-1] > time[0]:  # a trial of one tick has no span to show
        ax.set_xlim(time[0], time[-1])
    ax.legend(loc="upper right", fontsize=8)
    return ax
