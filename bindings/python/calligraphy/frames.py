"""pandas tables of a trial: one row per servo tick, or one row per stroke.

pandas is optional: it is imported when a table is asked for, not with ``calligraphy``. These functions
are what ``TrialResult.to_dataframe()`` and ``TrialResult.per_stroke_dataframe()`` call.
"""

from __future__ import annotations

import typing

import numpy as np

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

    Columns, SI units in their names: ``time_s`` [s]; ``x_m``, ``y_m``, ``z_m``, the pen tip as read
    from the device [m]; ``fx_n``, ``fy_n``, ``fz_n``, the commanded force [N]; ``state``, the
    interaction state as a categorical of 'SS', 'AS', 'CS', 'WS' (paper Table 1); ``stroke``, the active
    stroke over the scene (0-based, as ``result.scene.strokes``); ``element``, the active element
    within it (0-based). Raises ImportError when pandas is missing.
    """
    pandas = _pandas()
    position = np.asarray(result.position_m)
    force = np.asarray(result.force_n)
    state = pandas.Categorical.from_codes(np.asarray(result.state, dtype=np.int8), categories=_state_names())
    return pandas.DataFrame(
        {
            "time_s": np.asarray(result.time_s),
            "x_m": position[:, 0],
            "y_m": position[:, 1],
            "z_m": position[:, 2],
            "fx_n": force[:, 0],
            "fy_n": force[:, 1],
            "fz_n": force[:, 2],
            "state": state,
            "stroke": np.asarray(result.stroke),
            "element": np.asarray(result.element),
        }
    )


def per_stroke_dataframe(result: TrialResult) -> pandas.DataFrame:
    """One row per stroke of the scene, indexed by the stroke over the scene (0-based, named
    ``stroke`` as in ``trial_dataframe``), from ``result.metrics['per_stroke']``.

    Columns: ``character`` (str), ``acronym`` of its typical stroke, ``typical_id`` (1..39),
    ``completed`` (bool), ``attempts`` (int), ``mean_deviation_mm`` and ``max_deviation_mm`` [mm],
    ``time_s`` [s] (the last attempt's writing time). Raises ImportError when pandas is missing.
    """
    pandas = _pandas()
    characters = [placed.char for placed in result.scene.characters for _ in placed.strokes]
    acronyms = [stroke.acronym for stroke in result.scene.strokes]
    rows = []
    for entry in result.metrics["per_stroke"]:
        stroke = entry["index"] - 1  # the JSON counts from 1
        rows.append(
            {
                "stroke": stroke,
                "character": characters[stroke],
                "acronym": acronyms[stroke],
                "typical_id": entry["typical_id"],
                "completed": entry["completed"],
                "attempts": entry["attempts"],
                "mean_deviation_mm": entry["mean_deviation_mm"],
                "max_deviation_mm": entry["max_deviation_mm"],
                "time_s": entry["time_s"],
            }
        )
    columns = ["stroke", "character", "acronym", "typical_id", "completed", "attempts", "mean_deviation_mm",
               "max_deviation_mm", "time_s"]
    return pandas.DataFrame(rows, columns=columns).set_index("stroke")
