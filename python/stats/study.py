"""A study as tidy pandas tables: ``load(path)`` reads session folders into one row per trial and one row per
reference stroke, and gives each trial's samples on demand.

The tables are the ones ``calligraphy report DIR --csv TABLES`` writes (``read_study_tables``,
include/calligraphy/study/study_tables.hpp): the same code, so R, spreadsheet and Python users see the same
numbers. Metrics are each trial record's one metrics record (docs/metrics.md) in SI units, the unit in every
column name; indices (trial, block, item, repetition, character, stroke) count from 1, as the trial files'
numbers (001-..., r1) do. Traces are never read by ``load``: ``Study.samples(trial)`` reads one trial's
trace (its HDF5 file, ``.trace.h5``, read by the library's C++ reader; the gzip CSV ``.csv.gz`` or plain
``.csv`` of older folders) when asked, and
``Study.iter_samples()`` streams them one at a time. Columns: docs/experiments.md ("Tidy
tables"). Tidy data: Wickham 2014, J Stat Softw 59(10).
"""

from __future__ import annotations

import collections.abc
import dataclasses
import io
import os
import typing

from . import _native

if typing.TYPE_CHECKING:  # pandas is optional for the package as a whole
    import pandas

PathLike = typing.Union[str, "os.PathLike[str]"]

__all__ = ["PathLike", "Study", "load", "propose_characters"]


def _metric_columns(table: str, kinds: tuple[str, ...]) -> tuple[str, ...]:
    """The metric columns of study table `table` ("trials" or "strokes") of the given kinds, from the one
    metric table (metric_table(), include/calligraphy/analysis/metric_table.hpp), in their columns' order."""
    key = table + "_column"
    rows = [row for row in _native.metric_table() if row[key] > 0 and row["kind"] in kinds]
    return tuple(row["name"] for row in sorted(rows, key=lambda row: row[key]))


# Columns whose empty fields are absent values (NaN); every other empty field is an empty string. The metric
# columns (numbers and counts; flags are booleans) come from the metric table, the others are the design's.
_NUMERIC_TRIAL_COLUMNS = (
    ("session_number", "block", "trial", "item", "repetition", "period")
    + _metric_columns("trials", ("number", "count"))
    + ("shape_skill", "order_skill", "timing_skill", "subject_writing_speed_factor",
       "subject_spatial_error_factor", "subject_error_rate_factor", "subject_motor_noise_factor",
       "subject_fast_learning_per_trial", "subject_slow_learning_per_trial", "subject_fast_retention_per_trial",
       "subject_slow_retention_per_trial", "strokes_given_up", "legibility_top1", "legibility_top5"))
_BOOLEAN_TRIAL_COLUMNS = _metric_columns("trials", ("flag",))
# Numeric columns kept float64 even without a gap, in a study of no trial too: a crossover period is NaN where
# the item's set is not trained, every metric number (the metric table's kind), the skills, traits and
# legibility shares are real numbers; one dtype in every study spares an analysis a column whose type follows
# the data.
_FLOAT_COLUMNS = (
    ("period", "shape_skill", "order_skill", "timing_skill", "subject_writing_speed_factor",
     "subject_spatial_error_factor", "subject_error_rate_factor", "subject_motor_noise_factor",
     "subject_fast_learning_per_trial", "subject_slow_learning_per_trial", "subject_fast_retention_per_trial",
     "subject_slow_retention_per_trial", "legibility_top1", "legibility_top5")
    + _metric_columns("trials", ("number",)) + _metric_columns("strokes", ("number",)))
_NUMERIC_STROKE_COLUMNS = (
    ("trial", "character", "stroke", "typical_id", "segments", "refused_segments")
    + _metric_columns("strokes", ("number", "count")))
_BOOLEAN_STROKE_COLUMNS = ("written", "backwards") + _metric_columns("strokes", ("flag",))
_CATEGORIES = ("subject", "session", "protocol", "group", "phase", "condition", "mode", "item_set", "sequence",
               "trained_condition", "writer", "writer_profile", "writer_learning", "end_reason")
# The trace CSV's columns (calligraphy trial --csv) with their SI units named.
_trace_columns = _native.trace_columns
# From the one table of a trace's columns (trace_columns(), include/calligraphy/report/trace_columns.hpp).
_SAMPLE_COLUMNS = {c["file_name"]: c["name"] for c in _trace_columns() if c["file_name"] != c["name"]}


# Traces saved since attempts were marked add the attempt at the stroke (1-based, 0 outside any) and whether
# it was written again later (1: not the final writing); older traces lack both.
_MARKED_TRACE_HEADER = [c["file_name"] for c in _trace_columns()]
_TRACE_HEADER = _MARKED_TRACE_HEADER[:-2]
_WHOLE_NUMBER_COLUMNS = ("stroke", "element", "attempt", "rewritten")


_STATES = ("SS", "AS", "CS", "WS")  # InteractionState's numbers in an HDF5 trace (render/interaction_state.hpp)
# A trace file over this is refused unread (read_trace_hdf5's default, PenTraceCsvOptions::max_file_bytes).
_MAX_TRACE_FILE_BYTES = 256 << 20


def _check_trace_sha256(path: str, expected: str) -> None:
    """DataError when the trace file at `path` is not the one its record names by SHA-256 (FIPS 180-4): a
    trace copied or renamed from another trial. A missing file is left to the reader to name."""
    import hashlib

    digest = hashlib.sha256()
    try:
        with open(path, "rb") as stream:
            for block in iter(lambda: stream.read(1 << 20), b""):
                digest.update(block)
    except FileNotFoundError:
        return
    if digest.hexdigest() != expected:
        raise _native.DataError(f"{path}: SHA-256 {digest.hexdigest()}, but its record names a trace of "
                                     f"SHA-256 {expected} (files.trace_sha256): it is not this trial's trace")


def _read_trace(path: str, sha256: str = "") -> "pandas.DataFrame":
    """A trial's trace as samples, the same columns from either format: its HDF5 file (``.trace.h5``, read
    whole by the C++ reader, trace_hdf5.hpp) or, in older session folders, its CSV, gzip-compressed
    (``.csv.gz``) or plain (``.csv``); DataError naming the file (and line) for damage, and, given `sha256`
    (its record's files.trace_sha256), for a trace of another SHA-256. An HDF5 trace is read once: the C++
    reader hashes the bytes it parses."""
    if str(path).endswith(".h5"):
        import numpy as np

        if not os.path.exists(path):
            raise FileNotFoundError(f"{path}: no such trace file")
        columns = _native._read_trace_columns(os.fspath(path), _MAX_TRACE_FILE_BYTES, sha256)
        columns["state"] = np.array(_STATES, dtype=object)[columns["state"]]
        for column in _WHOLE_NUMBER_COLUMNS:
            columns[column] = columns[column].astype(np.int64)
        return _pandas().DataFrame(columns)
    samples = _read_csv_trace(path)  # a damaged trace is named as damaged
    if sha256:
        _check_trace_sha256(path, sha256)
    return samples


def _read_csv_trace(path: str) -> "pandas.DataFrame":
    """An older trial's trace as samples: its CSV, gzip-compressed (``.csv.gz``, decompressed as it is read)
    or plain (``.csv``); DataError naming the file and line for damage."""
    import gzip
    import zlib

    import numpy as np

    from ._native import DataError

    pd = _pandas()
    try:
        frame = pd.read_csv(path, dtype=str, keep_default_na=False, compression="infer")
    except (gzip.BadGzipFile, EOFError, zlib.error) as error:
        raise DataError(f"{path}: not a gzip-compressed trial trace: {error}") from error
    except (ValueError, pd.errors.ParserError, UnicodeDecodeError) as error:
        raise DataError(f"{path}: not a trial trace (CSV): {error}") from error
    if list(frame.columns) not in (_TRACE_HEADER, _MARKED_TRACE_HEADER):
        raise DataError(f"{path}:1: expected the header '{','.join(_MARKED_TRACE_HEADER)}' "
                        f"(or '{','.join(_TRACE_HEADER)}')")
    for column in frame.columns:
        if column == "state":
            continue
        values = pd.to_numeric(frame[column], errors="coerce").to_numpy(dtype=float)
        whole = column in _WHOLE_NUMBER_COLUMNS
        bad = ~np.isfinite(values) if not whole else ~np.isfinite(values) | (values != np.round(values))
        if column == "rewritten":
            bad |= (values != 0) & (values != 1)
        if bad.any():
            first = int(np.argmax(bad))
            raise DataError(f"{path}:{first + 2}: column {column}: not a finite number: {frame[column].iloc[first]!r}")
        frame[column] = values.astype(int) if whole else values
    return frame.rename(columns=_SAMPLE_COLUMNS)


def _pandas() -> typing.Any:
    try:
        import pandas
    except ImportError as error:  # pragma: no cover - pandas is a Debian package here
        raise ImportError("calligraphy.study needs pandas (Debian: python3-pandas)") from error
    return pandas


def _read_table(text: str, numeric: tuple[str, ...], booleans: tuple[str, ...]) -> "pandas.DataFrame":
    pd = _pandas()
    # Every column that is not a number or a flag is text: a label of its alphabet that reads as a number
    # (a condition `007` or `1e5`, a subject `0012`) keeps its spelling, as the records write it.
    header = text.partition("\n")[0].rstrip("\r").split(",")
    labels = {c: str for c in header if c not in numeric and c not in booleans}
    # round_trip: every double as the C++ side wrote it (the default parser may differ in the last bit).
    frame = pd.read_csv(io.StringIO(text), keep_default_na=False, na_values={c: [""] for c in numeric},
                        float_precision="round_trip", dtype={**labels, **{c: "float64" for c in numeric}})
    for column in booleans:  # pandas reads "TRUE"/"FALSE" as booleans, but not a column of no row
        if frame[column].dtype != bool:
            frame[column] = frame[column].astype(str) == "TRUE"
    for column in numeric:  # counts and indices without a gap are integers
        if column in _FLOAT_COLUMNS:
            continue
        if frame[column].notna().all() and (frame[column] % 1 == 0).all():
            frame[column] = frame[column].astype("int64")
    for column in _CATEGORIES:
        if column in frame:
            frame[column] = frame[column].astype("category")
    return frame


@dataclasses.dataclass(frozen=True)
class Study:
    """The tidy tables of one or many session folders.

    trials: one row per saved trial (subject, session, protocol, session_number (1-based: which of the
        protocol's sessions), group (the subject's between-subjects group, '' when none), phase, block,
        condition, mode, characters, trial, item, repetition (1-based), item_set (the item's set, '' when the
        phase lists characters), sequence (the subject's crossover sequence, 'AB', 'BA', ...; '' without a
        crossover), period (the 1-based crossover period the item's set is trained in, NaN when none),
        trained_condition (the condition the item is or was trained under in the crossover, '' when none),
        writer, end_reason, start_utc,
        completed_in_order, stroke counts, order_errors, backwards_strokes, unmatched_segments, mean/max/rms_deviation_m, frechet_m, dtw_m [m],
        total_time_s, pen_down_time_s [s], velocity_peaks, normalised_jerk, shape_skill, order_skill and
        timing_skill (a learning simulated writer's skills before the trial, NaN otherwise), the simulated
        subject's traits subject_writing_speed_factor, subject_spatial_error_factor, subject_error_rate_factor,
        subject_motor_noise_factor (dimensionless factors on its profile) and subject_fast/slow_learning_per_trial,
        subject_fast/slow_retention_per_trial (its two-state rates; all NaN when subjects do not differ,
        docs/writer.md), strokes_given_up (strokes a simulated writer left after its last attempt, NaN for a
        person), trace_file).
    strokes: one row per reference stroke of each saved trial (subject, session, trial, phase, condition,
        character (1-based in the trial), character_text, stroke (1-based in its character), typical_id,
        written, backwards, segments, refused_segments, refusal, the per-stroke deviations [m], time_s [s],
        path_length_m [m], assisted).
    """

    trials: "pandas.DataFrame"
    strokes: "pandas.DataFrame"

    def samples(self, trial: typing.Union[int, "pandas.Series"]) -> "pandas.DataFrame":
        """One trial's trace, read now: a DataFrame of N ticks with t_s [s], x_m, y_m, z_m [m] (device frame),
        fx_n, fy_n, fz_n [N], state ("SS", "AS", "CS", "WS"), stroke, element (positions in the scene's arrays,
        0-based), attempt (1-based, 0 outside any) and rewritten (1: part of an attempt written again later;
        a trace of an older folder, saved before them, lacks both columns). `trial` is a row of `trials` or its index
        label. Raises TypeError naming `trial` for None or a value that cannot be a label (a list, a dict,
        a bool), KeyError for an unknown label, FileNotFoundError when the trace is gone, DataError for a
        trial without a trace file (a cohort simulated in memory) and naming
        the file of a damaged trace (and the line of an older CSV trace: another header, a field that is not a
        finite number)."""
        if not hasattr(trial, "trace_file"):
            if trial is None or isinstance(trial, bool) or not isinstance(trial, collections.abc.Hashable):
                raise TypeError(f"Study.samples: trial: expected a row of trials or its index label, got "
                                f"{type(trial).__name__} {trial!r}")
        row = self.trials.loc[trial] if not hasattr(trial, "trace_file") else trial
        path = row["trace_file"]
        if not isinstance(path, str) or not path:
            # A cohort simulated in memory (calligraphy.cohort.simulate) keeps no trace.
            raise _native.DataError(f"Study.samples: trial {row.get('trial', '?')} of session "
                                    f"{row.get('session', '?')} has no trace file (a cohort simulated in memory "
                                    "keeps no traces; run the protocol with calligraphy session run for them)")
        expected = row.get("trace_sha256", "")
        return _read_trace(path, expected if isinstance(expected, str) else "")

    def iter_samples(self) -> typing.Iterator[tuple[typing.Any, "pandas.DataFrame"]]:
        """(index label, samples) for every trial in turn, one trace in memory at a time."""
        for label, row in self.trials.iterrows():
            yield label, self.samples(row)


def _folder_paths(paths: typing.Any, caller: str) -> list[str]:
    """`paths` as a list of folder names: one path (str or path-like) or an iterable of them; a TypeError
    naming `paths` for anything else (None, a number, bytes), a ValueError for none or an empty one."""
    if isinstance(paths, (str, os.PathLike)):
        roots = [paths]
    elif not isinstance(paths, (bytes, bytearray)) and isinstance(paths, collections.abc.Iterable):
        roots = list(paths)
    else:
        raise TypeError(f"{caller}: paths: expected a folder's path or a list of them, got "
                        f"{type(paths).__name__} {paths!r}")
    for root in roots:
        if not isinstance(root, (str, os.PathLike)):
            raise TypeError(f"{caller}: paths: expected a folder's path (str or path-like), got "
                            f"{type(root).__name__} {root!r}")
    names = [os.fspath(root) for root in roots]
    if not names or any(not isinstance(name, str) or not name for name in names):
        raise ValueError(f"{caller}: paths must name session or study folders, got {paths!r}")
    return names


def load(paths: typing.Union[PathLike, typing.Sequence[PathLike]]) -> Study:
    """Reads the saved trials of the session folders under `paths` (a session folder, a study folder made by
    ``calligraphy session run --out``, or a list of either) into a `Study` of tidy DataFrames. Only the
    session manifests and trial records are read, never the traces. ``phase`` is an ordered categorical in
    the protocol's order and ``condition`` and ``group`` categoricals with the control (the condition without
    guidance, ``calligraphy.design_analysis.study_design``) first. Raises DataError naming the file (and
    JSON pointer) for a path without a session folder or a damaged record (its ``specification`` included, read as
    ``rerun_trial`` and ``calligraphy trial --spec`` read it), and naming the subject and both
    folders for a subject's session of one number found twice (a session run twice: its trials are not
    pooled), naming session.json and /study_id for a session of another study (copied in from another study
    folder: its study_id is not the folder's, docs/experiments.md "Phases"), ValueError for no path or an empty one,
    TypeError naming `paths` for anything but a path (str or path-like) or an iterable of them, ImportError without
    pandas."""
    roots = _folder_paths(paths, "load")
    return _tidy_study(*_native._study_tables_csv(roots))


def _tidy_study(trials_text: str, strokes_text: str) -> Study:
    """The `Study` of the trials and strokes tables' CSV texts (as ``calligraphy report --csv`` writes them):
    typed columns, and the design's order, not the alphabet's: phases as the protocol runs them, the control
    condition first. What `load` returns, and `calligraphy.cohort.simulate` for subjects run in memory."""
    trials = _read_table(trials_text, _NUMERIC_TRIAL_COLUMNS, _BOOLEAN_TRIAL_COLUMNS)
    strokes = _read_table(strokes_text, _NUMERIC_STROKE_COLUMNS, _BOOLEAN_STROKE_COLUMNS)
    if not trials.empty:
        from . import design_analysis

        trials = design_analysis.ordered(trials, design_analysis.study_design(trials))
    return Study(trials=trials, strokes=strokes)


def propose_characters(paths: typing.Union[PathLike, typing.Sequence[PathLike]], subject: str, candidates: str,
                       count: int = 3, library: typing.Any = None) -> list[dict]:
    """The characters `subject` should practise next, from its saved trials under `paths` (as `load`):
    greedily those of `candidates` (a str of characters) that bring the most typical strokes it never wrote
    (2 each) and that it writes worst (1 each: a mean deviation above the median of its typical strokes),
    ties to fewer strokes; characters it has written are not proposed (include/calligraphy/study/
    curriculum.hpp; the same as ``calligraphy curriculum``). Returns up to `count` dicts: character,
    new_strokes and weak_strokes (typical-stroke IDs). count: 1..1000, as the command's --count. library: a
    calligraphy.CharacterLibrary for the candidates (default: CharacterLibrary.default(), every
    hanzi-writer-data character, as the command). Raises InvalidArgument for a subject without saved
    trials, a count outside 1..1000, candidates empty or not Unicode text (a lone surrogate),
    CharacterNotFound for a candidate the library lacks, DataError for a damaged record."""
    if library is None:
        library = _native.CharacterLibrary.default()
    return _native._propose_characters(_folder_paths(paths, "propose_characters"), subject, candidates, count,
                                       library)
