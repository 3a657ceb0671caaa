"""The one door from ``calligraphy.stats`` to the C++ extension: the study folders' reader, the metric table
(the study tables' metric columns), the trace reader, the writer of a report's files together, the character
proposal and the error they raise.

Every other module of the package is pure Python and imports nothing of ``calligraphy`` outside
``calligraphy.stats`` (tests/python/test_package_layering.py checks it): what the statistics need from the
library comes through the names below, so the analysis can be read, and tested, apart from the bindings.
"""

from __future__ import annotations

from .._calligraphy import (  # noqa: F401
    CharacterLibrary,
    DataError,
    _propose_characters,
    _read_trace_columns,
    _study_tables_csv,
    _write_files_together,
    metric_table,
    trace_columns,
)

__all__ = [
    "CharacterLibrary",
    "DataError",
    "_propose_characters",
    "_read_trace_columns",
    "_study_tables_csv",
    "_write_files_together",
    "metric_table",
    "trace_columns",
]
