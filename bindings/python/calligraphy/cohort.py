"""Simulated cohorts: many simulated subjects through every session of a study protocol, in memory, on every
local core or on a Dask cluster.

``simulate(protocol, subjects)`` runs subjects 1..N (ids S01, S02, ...) through the protocol's phases and
sessions as ``calligraphy session run --subjects N`` would, with the same plan, seeds, guidance schedules and
learning memory, but without session folders, traces or per-trial files (``simulate_cohort``,
include/calligraphy/study/cohort.hpp), and returns a ``calligraphy.study.Study``: the tidy tables that
``calligraphy.study.load`` reads from folders, row for row, except for the ``session`` name ("PROTOCOL-SUBJECT-sN"),
an empty ``start_utc`` and no trace file. The tables feed ``calligraphy.statistics`` (``learning``,
``group_comparison``) as they are.

Locally the subjects run on C++ threads in this process. With a ``distributed.Client`` (or any
``concurrent.futures.Executor``) they run in batches on its workers, each batch one task that carries only
the protocol's path, the subjects' ids and numbers and the names of the profile and learning; every subject
is deterministic, so the tables do not depend on where or in which batches it ran.
"""

from __future__ import annotations

import os
import typing

from .stats import study as _study
from ._calligraphy import _MAX_COHORT_SUBJECTS, _simulate_cohort_csv
from .experiments import MAX_WORKERS as _MAX_WORKERS
from .experiments import _library, _local_workers, _progress_bar, _source

__all__ = ["simulate"]

PathLike = typing.Union[str, "os.PathLike[str]"]

# Subjects per task on an executor: a subject is 50 trials or so (a second or two), long enough that a
# task's overhead (milliseconds on Dask) does not count, and one a task balances the workers best.
_DEFAULT_BATCH = 1


def _subject_list(subjects: typing.Any, prefix: str) -> list[tuple[str, int]]:
    if isinstance(subjects, bool) or not isinstance(subjects, int):
        raise TypeError(f"subjects: expected an int (the number of simulated subjects), got {subjects!r}")
    if subjects < 1 or subjects > _MAX_COHORT_SUBJECTS:
        raise ValueError(f"subjects: expected 1 to {_MAX_COHORT_SUBJECTS} subjects, got {subjects}")
    return [(f"{prefix}{number:02d}", number) for number in range(1, subjects + 1)]


def _run_batch(protocol: str, batch: list[tuple[str, int]], profile: str, learning: str,
               source: tuple[str, str], individual_differences: bool = True) -> tuple[str, str]:
    """One task on a worker: the batch's subjects one after another; the CSV texts of their tables."""
    return _simulate_cohort_csv(protocol, batch, profile, learning, _library(source), 1, individual_differences)


def _body(text: str) -> str:
    """A CSV text without its header line."""
    return text.split("\n", 1)[1] if "\n" in text else ""


def simulate(protocol: PathLike, subjects: int, *, profile: str = "novice", learning: str = "two-state",
             individual_differences: bool = True, prefix: str = "S", client: typing.Any = None, workers: typing.Optional[int] = None,
             store: typing.Optional[PathLike] = None, data: typing.Optional[PathLike] = None,
             batch_size: typing.Optional[int] = None, progress: bool = True) -> "_study.Study":
    """Runs simulated subjects 1..`subjects` through every session of `protocol` (a study protocol file,
    docs/experiments.md) and returns their tidy tables as a ``calligraphy.study.Study`` (trials: one row per
    trial; strokes: one row per reference stroke; columns as ``calligraphy.study.load``'s).

    profile: the simulated writer's profile, 'novice', 'skilled' or 'foreign'. learning: 'two-state' (the
        learning memory of docs/writer.md, practised by every trial and consolidated between sessions) or
        'none'. individual_differences: True (each subject draws its own baseline skill, motor noise and
        learning rates from its id, as ``session run`` and ``session cohort`` do; docs/writer.md) or False
        (every subject is the profile itself). prefix: the subjects' ids are prefix + the number in two digits or more.
    client: None runs on `workers` C++ threads in this process (default: every core this process may use);
        a distributed.Client (or any concurrent.futures.Executor) runs batches of `batch_size` subjects
        (default 1) as its tasks, one thread each. The protocol file and the character source must be
        readable by every worker.
    store / data: characters from a corpus store or a hanzi-writer-data folder instead of the embedded set.
    progress: a tqdm bar over the batches on an executor (when tqdm is installed).

    Raises TypeError or ValueError for a bad argument (subjects beyond 1..100000 or workers beyond 1..1024, the
    CLI's bounds; a client that is neither a distributed.Client nor an Executor), InvalidArgument for a bad profile or learning, a
    protocol with a replay condition (its teacher lives in a session folder) or a transfer choice that
    cannot be made; DataError naming the protocol file when it cannot be read; CharacterNotFound for a
    character the source lacks; ImportError without pandas. A simulated subject is a model, not a person.
    """
    if not isinstance(individual_differences, bool):
        raise TypeError(f"individual_differences: expected a bool, got {individual_differences!r}")
    subject_list = _subject_list(subjects, prefix)
    if not isinstance(protocol, (str, os.PathLike)):
        raise TypeError(f"protocol: expected a protocol file's path (str or path-like), got "
                        f"{type(protocol).__name__} {protocol!r}")
    for name, value in (("profile", profile), ("learning", learning)):
        if not isinstance(value, str):
            raise TypeError(f"{name}: expected a str, got {type(value).__name__} {value!r}")
    if client is not None and not (hasattr(client, "get_executor") or callable(getattr(client, "submit", None))):
        raise TypeError(f"client: expected a distributed.Client or a concurrent.futures.Executor, got "
                        f"{type(client).__name__} {client!r}")
    # Checked whoever runs the subjects, so that a value is refused the same with and without a client.
    if batch_size is not None and (isinstance(batch_size, bool) or not isinstance(batch_size, int) or batch_size < 1):
        raise ValueError(f"batch_size: expected an int >= 1, got {batch_size!r}")
    path = os.path.abspath(os.fspath(protocol))
    source = _source(store, data)
    if client is None:
        threads = workers if workers is not None else _local_workers()
        if isinstance(threads, bool) or not isinstance(threads, int) or not 1 <= threads <= _MAX_WORKERS:
            raise ValueError(f"workers: expected an int in 1..{_MAX_WORKERS}, got {workers!r}")
        trials_text, strokes_text = _simulate_cohort_csv(path, subject_list, profile, learning, _library(source),
                                                         threads, individual_differences)
    else:
        size = batch_size if batch_size is not None else _DEFAULT_BATCH
        if isinstance(size, bool) or not isinstance(size, int) or size < 1:
            raise ValueError(f"batch_size: expected an int >= 1, got {batch_size!r}")
        executor = client.get_executor() if hasattr(client, "get_executor") else client
        batches = [subject_list[i:i + size] for i in range(0, len(subject_list), size)]
        futures = [executor.submit(_run_batch, path, batch, profile, learning, source,
                                   individual_differences) for batch in batches]
        bar = _progress_bar(len(subject_list), progress, unit="subject", desc="cohort")
        try:
            for future, batch in zip(futures, batches):
                future.add_done_callback(lambda _, n=len(batch): bar.update(n) if bar is not None else None)
            texts = [future.result() for future in futures]  # in subject order; the first error is raised
        finally:
            for future in futures:
                future.cancel()
            if bar is not None:
                bar.close()
        trials_text = texts[0][0] + "".join(_body(trials) for trials, _ in texts[1:])
        strokes_text = texts[0][1] + "".join(_body(strokes) for _, strokes in texts[1:])
    return _study._tidy_study(trials_text, strokes_text)
