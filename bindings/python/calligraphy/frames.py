"""pandas tables of a trial: one row per servo tick, or one row per stroke.

pandas is optional: it is imported when a table is asked for, not with ``calligraphy``. These functions
are what ``TrialResult.to_dataframe()`` and ``TrialResult.per_stroke_dataframe()`` call.
"""

from __future__ import annotations

import typing

import numpy as np

from ._calligraphy import metric_table, trace_columns
from .metrics import metric_frame

if typing.TYPE_CHECKING:  # pragma: no cover
    import pandas

    from ._calligraphy import TrialResult


def _state_names():
    """The state column's categories, 'SS', 'AS', 'CS', 'WS', in the order of InteractionState's values."""
    from ._calligraphy import InteractionState

    states = sorted(InteractionState.__members__.values(), key=int)
    assert [int(s) for s in states] == list(range(len(states)))
    return [s.short_name for s in states]


def _pandas():
    try:
        import pandas
    except ImportError as error:  # pragma: no cover - depends on the installation
        raise ImportError(
            "calligraphy's tables need pandas (Debian: apt-get install python3-pandas; or pip install pandas)"
        ) from error
    return pandas


def trial_dataframe(result: TrialResult) -> pandas.DataFrame:
    """One row per servo tick of ``result`` (empty when the trial ran with ``keep_trace=False``).

    Columns, SI units in their names, as ``calligraphy.trace_columns()`` names them and ``Study.samples()``
    does (``calligraphy.score`` takes this frame as it is): ``t_s`` [s]; ``x_m``, ``y_m``, ``z_m``, the pen tip as read
    from the device [m]; ``fx_n``, ``fy_n``, ``fz_n``, the commanded force [N]; ``state``, the
    interaction state as a categorical of 'SS', 'AS', 'CS', 'WS' (paper Table 1); ``stroke``, the active
    stroke over the scene (0-based, as ``result.scene.strokes``); ``element``, the active element
    within it (0-based); ``attempt``, the attempt at the stroke (1-based, 0 outside any); ``rewritten``, 1 for
    a tick of an attempt written again later. Raises ImportError when pandas is missing.
    """
    pandas = _pandas()
    position = np.asarray(result.position_m)
    force = np.asarray(result.force_n)
    state = pandas.Categorical.from_codes(np.asarray(result.state, dtype=np.int8), categories=_state_names())
    columns = {
        "t_s": np.asarray(result.time_s),
        "x_m": position[:, 0],
        "y_m": position[:, 1],
        "z_m": position[:, 2],
        "fx_n": force[:, 0],
        "fy_n": force[:, 1],
        "fz_n": force[:, 2],
        "state": state,
        "stroke": np.asarray(result.stroke),
        "element": np.asarray(result.element),
        "attempt": np.asarray(result.attempt),
        "rewritten": np.asarray(result.rewritten, dtype=np.int64),
    }
    # In the table's order, each column by its name there (a column the table lacks is an error here).
    return pandas.DataFrame({column["name"]: columns[column["name"]] for column in trace_columns()})


# Every stroke-level metric of the metric table, in its order: the per-stroke table's metric columns.
_STROKE_METRICS = [row["name"] for row in metric_table() if "stroke" in row["levels"].split(", ")]


def per_stroke_dataframe(result: TrialResult) -> pandas.DataFrame:
    """One row per stroke of the scene, indexed by the stroke over the scene (0-based, named
    ``stroke`` as in ``trial_dataframe``): what was written, from the one metrics record
    (``result.metrics['per_character'][c]['per_stroke']``, docs/metrics.md), and the renderer's attempts
    (``result.metrics['renderer_strokes']``).

    Columns: ``character`` (str), ``acronym`` of its typical stroke, ``typical_id`` (1..39),
    then every stroke-level metric of the metric table (``calligraphy.metric_table()``, docs/metrics.md) under
    its name, in SI units: ``written``, ``assisted`` (credited after ``assist_after_misses`` refusals, as the
    renderer credits it) and ``backwards`` (bool), ``mean_deviation_m``, ``max_deviation_m``,
    ``rms_deviation_m``, ``outside_tube_share``, ``frechet_m``, ``dtw_m``, ``path_length_m`` [m], ``time_s``
    [s] (its pen-down writing time), ``mean_speed_m_s``, ``velocity_peaks``, ``normalised_jerk`` (None for a
    stroke not written; the old ``*_mm`` columns still read, in mm, with a DeprecationWarning), then
    ``completed`` (bool, the renderer completed it in turn) and ``attempts`` (int). Raises ImportError when
    pandas is missing.
    """
    pandas = _pandas()
    acronyms = [stroke.acronym for stroke in result.scene.strokes]
    renderer = result.metrics["renderer_strokes"]
    rows = []
    stroke = 0
    for character in result.metrics["per_character"]:
        for entry in character["per_stroke"]:
            live = renderer[stroke] if stroke < len(renderer) else {"completed": False, "attempts": 0}
            rows.append(
                {
                    "stroke": stroke,
                    "character": character["character"],
                    "acronym": acronyms[stroke],
                    "typical_id": entry["typical_id"],
                    "written": entry["written"],
                    "backwards": entry["backwards"],
                    **{name: entry[name] for name in _STROKE_METRICS},
                    "completed": live["completed"],
                    "attempts": live["attempts"],
                }
            )
            stroke += 1
    columns = ["stroke", "character", "acronym", "typical_id", *_STROKE_METRICS, "completed", "attempts"]
    return metric_frame(pandas.DataFrame(rows, columns=columns).set_index("stroke"))
