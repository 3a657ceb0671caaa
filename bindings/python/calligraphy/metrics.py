"""Metrics dicts named by the one metric table (include/calligraphy/analysis/metric_table.hpp).

Every metric has one name with its SI unit in it (``mean_deviation_m``, ``frechet_m``, ``total_time_s``):
the key of ``TrialResult.metrics``, of ``score(...)``'s dict and of the DataFrame columns.
``calligraphy.metric_table()`` lists them. A metric that had another name before (``mean_deviation_mm``,
``frechet_mm``, ... in millimetres) can still be read under it for one version: the value is converted
(metres x 1000) and a DeprecationWarning names the new key.
"""

from __future__ import annotations

import json
import warnings
from typing import Any

from ._calligraphy import metric_table

__all__ = ["Metrics", "legacy_names", "loads", "metric_frame"]


def _legacy() -> dict[str, tuple[str, float]]:
    return {row["legacy_name"]: (row["name"], row["legacy_factor"]) for row in metric_table() if row["legacy_name"]}


_LEGACY = _legacy()


def legacy_names() -> dict[str, str]:
    """{old name: its one name}, e.g. {"mean_deviation_mm": "mean_deviation_m"}."""
    return {old: new for old, (new, _) in _LEGACY.items()}


def _deprecated(old: str) -> tuple[str, float]:
    new, factor = _LEGACY[old]
    warnings.warn(
        f"metrics['{old}'] is deprecated: use metrics['{new}'] (metres; {old} = {new} x {factor:g})",
        DeprecationWarning,
        stacklevel=3,
    )
    return new, factor


class Metrics(dict):
    """A dict of metrics (one object of a metrics record) that still reads an old millimetre name, with a
    DeprecationWarning naming the new key; iteration, ``keys()`` and equality see only the one names."""

    def __getitem__(self, key: Any) -> Any:
        if not dict.__contains__(self, key) and key in _LEGACY and dict.__contains__(self, _LEGACY[key][0]):
            new, factor = _deprecated(key)
            value = dict.__getitem__(self, new)
            return None if value is None else value * factor
        return dict.__getitem__(self, key)

    def get(self, key: Any, default: Any = None) -> Any:
        if not dict.__contains__(self, key) and key in _LEGACY and dict.__contains__(self, _LEGACY[key][0]):
            return self[key]
        return dict.get(self, key, default)

    def __reduce__(self):  # pickles as a Metrics (process pools, Dask)
        return (Metrics, (dict(self),))


def loads(text: str) -> Metrics:
    """A metrics record's JSON text with every object a ``Metrics``."""
    return json.loads(text, object_hook=Metrics)


_FRAME_CLASS = None


def _frame_class():
    """The DataFrame class of ``metric_frame``, made on first use (pandas is imported only then)."""
    global _FRAME_CLASS
    if _FRAME_CLASS is None:
        import pandas

        class MetricFrame(pandas.DataFrame):
            @property
            def _constructor(self):
                return MetricFrame

            def _legacy_column(self, key: Any) -> bool:
                return (isinstance(key, str) and key in _LEGACY and key not in self.columns
                        and _LEGACY[key][0] in self.columns)

            def __getitem__(self, key: Any) -> Any:
                if self._legacy_column(key):
                    new, factor = _deprecated(key)
                    return pandas.DataFrame.__getitem__(self, new) * factor
                return pandas.DataFrame.__getitem__(self, key)

            def __getattr__(self, name: str) -> Any:
                if not name.startswith("_") and self._legacy_column(name):
                    return self[name]
                return pandas.DataFrame.__getattr__(self, name)

        # Pickled by name as calligraphy.metrics.MetricFrame (DataFrame.to_pickle, process pools, Dask): the
        # module's __getattr__ below gives the class to pickle, making it when it is not made yet.
        MetricFrame.__module__ = __name__
        MetricFrame.__qualname__ = "MetricFrame"
        _FRAME_CLASS = MetricFrame
    return _FRAME_CLASS


def metric_frame(frame):
    """``frame`` (a pandas.DataFrame with metric columns) as a DataFrame that still reads an old millimetre
    column (``frame["mean_deviation_mm"]``, ``frame.mean_deviation_mm``) with a DeprecationWarning naming the
    new column; its columns are the one names. It pickles (``to_pickle``) and unpickles as such."""
    return _frame_class()(frame)


def __getattr__(name: str) -> Any:
    if name == "MetricFrame":
        return _frame_class()
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
