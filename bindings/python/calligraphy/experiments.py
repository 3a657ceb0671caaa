"""Parameter sweeps of simulated trials, on every local core or on a Dask cluster.

``sweep(characters, grid, seeds)`` runs one simulated trial (``simulate_trial``, metrics only) per
combination of the grid's values x character x seed and returns a pandas DataFrame with one row per
trial: the trial's parameters and the flat metrics of ``calligraphy trial --json``.

Trials run in batches on a process pool (the 'forkserver' or 'spawn' start method) or on the workers
of a ``distributed.Client``; both go through one path (``concurrent.futures`` submit and
as_completed, the client through ``Client.get_executor``). A batch carries only names and numbers:
each worker opens the character source (the default set of every character, a corpus store or a
hanzi-writer-data folder) once by its path and loads characters by name. A trial is deterministic for its parameters,
and the rows are sorted by the trial's position in the sweep, so the table does not depend on the
executor, the number of workers or the batch size.

pandas is needed for the table; tqdm (optional) draws the progress bar; distributed only when a
client is given. Scripts that sweep locally need ``if __name__ == "__main__":``, as every program
using a 'spawn' or 'forkserver' process pool does: the workers import the main module.
"""

from __future__ import annotations

import collections.abc
import concurrent.futures
import functools
import itertools
import math
import multiprocessing
import numbers
import os
import typing

from ._calligraphy import CharacterLibrary, ForceLawParameters, WriterProfile, simulate_trial
from .metrics import metric_frame

if typing.TYPE_CHECKING:  # pragma: no cover
    import pandas

__all__ = ["DASK_WORKER_ENVIRONMENT", "MAX_SWEEP_TRIALS", "MAX_WORKERS", "dask_worker_config", "parameter_names", "sweep"]

# glibc's malloc settings for Dask workers that run trials. distributed's nanny starts every worker with
# MALLOC_TRIM_THRESHOLD_=65536 (its config key distributed.nanny.pre-spawn-environ), and setting any of these
# variables turns glibc's adaptive thresholds off (mallopt(3), M_MMAP_THRESHOLD): every vector of a trial
# above 128 KiB (its trace, the matcher's copies) is then a fresh mapping that page-faults in again, and a
# worker runs trials about 1.7 times slower than a local pool. These are the values glibc's adaptation
# reaches on 64-bit Linux (an mmap threshold of at most 32 MiB, trim at twice that): give them before the
# cluster starts: ``with dask.config.set(dask_worker_config()):``, or in the cluster's own Dask configuration.
DASK_WORKER_ENVIRONMENT = {"MALLOC_MMAP_THRESHOLD_": 32 << 20, "MALLOC_TRIM_THRESHOLD_": 64 << 20}


def dask_worker_config() -> dict[str, int]:
    """``DASK_WORKER_ENVIRONMENT`` as Dask configuration keys (``distributed.nanny.pre-spawn-environ.<name>``:
    bytes), for ``dask.config.set`` before a cluster's workers start. Needs no Dask import; raises nothing."""
    return {f"distributed.nanny.pre-spawn-environ.{name}": value for name, value in DASK_WORKER_ENVIRONMENT.items()}

# Arguments of simulate_trial that a grid may set directly. `writer` is a profile name ('novice',
# 'skilled') or a WriterProfile; WriterProfile fields swept at the same time change that profile.
TRIAL_ARGUMENTS = ("guidance", "rate_hz", "max_duration_s", "writer")

# How a trial's position in the sweep, its character, seed and parameter values travel to a worker.
_TrialSpec = typing.Tuple[int, str, int, typing.Tuple[typing.Tuple[str, typing.Any], ...]]
# Where characters come from: ("embedded", ""), ("store", path) or ("hanzi_writer", folder).
_Source = typing.Tuple[str, str]

# The largest default batch: large enough that a task's overhead (about a millisecond on a process
# pool, several on Dask) is small against its trials (0.05-1 s each), small enough to balance load.
_MAX_DEFAULT_BATCH = 32
# Bounds of a sweep, checked before any list is built: trials (a million is hours of simulation and the
# largest table kept in memory) and local workers (as `session cohort --jobs`).
MAX_SWEEP_TRIALS = 1_000_000
_MAX_SEED = 2 ** 64 - 1  # a seed is a 64-bit unsigned integer (simulate_trial, `trial --seed`)
MAX_WORKERS = 1024
# Default batches per worker, so that a slow batch at the end does not leave the other workers idle.
_BATCHES_PER_WORKER = 4


@functools.lru_cache(maxsize=1)
def _catalogue() -> dict[str, tuple[str, ...]]:
    """Every name a grid accepts -> where it goes: ("trial", arg), ("force_law", field[, subfield]),
    ("writer", field). Force-law and writer fields are also accepted as "force_law.<field>" and
    "writer.<field>"; unqualified only where the name is unique."""
    qualified: dict[str, tuple[str, ...]] = {}
    for field, default in ForceLawParameters().to_dict().items():
        qualified[f"force_law.{field}"] = ("force_law", field)
        if isinstance(default, dict):  # a nested parameter struct (nearest): its fields by dotted name
            for sub in default:
                qualified[f"force_law.{field}.{sub}"] = ("force_law", field, sub)
    for field in WriterProfile().to_dict():
        if field != "name":  # the profile's name is the `writer` argument
            qualified[f"writer.{field}"] = ("writer", field)

    names: dict[str, tuple[str, ...]] = {name: ("trial", name) for name in TRIAL_ARGUMENTS}
    short_names: dict[str, list[str]] = {}
    for name in qualified:
        short_names.setdefault(name.split(".", 1)[1], []).append(name)
    for short, full in short_names.items():
        if len(full) == 1 and short not in names:
            names[short] = qualified[full[0]]
    names.update(qualified)
    return names


def parameter_names() -> list[str]:
    """The names a sweep's grid accepts, unqualified: the trial arguments (guidance, rate_hz,
    max_duration_s, writer), every field of ForceLawParameters (a nested one by dotted name, e.g.
    'nearest.method') and every field of WriterProfile but its name. Each field is also accepted as
    'force_law.<field>' or 'writer.<field>'."""
    return [name for name in _catalogue() if not name.startswith(("force_law.", "writer."))]


def _plain(value: typing.Any) -> typing.Any:
    """A numpy scalar (numpy.int64 from numpy.arange, numpy.float64 from numpy.linspace, numpy.bool_ from a
    boolean array) as the Python number or bool it holds, as simulate_trial and the parameter classes take
    it; any other value as it is."""
    if type(value).__module__ == "numpy" and getattr(value, "ndim", None) == 0 and hasattr(value, "item"):
        return value.item()
    return value


def _resolve(grid: typing.Mapping[str, typing.Iterable[typing.Any]]) -> list[tuple[str, list[typing.Any]]]:
    if not isinstance(grid, typing.Mapping):
        raise TypeError(f"grid: expected a dict of parameter name -> list of values, got {type(grid).__name__}")
    catalogue = _catalogue()
    resolved = []
    targets: dict[tuple[str, ...], str] = {}
    for name, values in grid.items():
        if name not in catalogue:
            raise ValueError(f"grid: unknown parameter '{name}'; valid names: {', '.join(parameter_names())} "
                             "(fields also as force_law.<field> and writer.<field>)")
        if catalogue[name] in targets:
            raise ValueError(f"grid: '{name}' and '{targets[catalogue[name]]}' name the same parameter")
        targets[catalogue[name]] = name
        if isinstance(values, (str, bytes)) or not isinstance(values, typing.Iterable):
            raise TypeError(f"grid['{name}']: expected a list of values, got {type(values).__name__}")
        values = [_plain(value) for value in values]
        if not values:
            raise ValueError(f"grid['{name}']: no values")
        resolved.append((name, values))
    return resolved


def _writer_profile(writer: typing.Any) -> WriterProfile:
    if isinstance(writer, WriterProfile):
        return writer
    if writer == "novice":
        return WriterProfile.novice()
    if writer == "skilled":
        return WriterProfile.skilled()
    raise ValueError(f"writer: expected 'novice', 'skilled' or a WriterProfile, got {writer!r}")


def _check_trial_argument_type(name: str, argument: str, value: typing.Any) -> None:
    """The type simulate_trial takes for a trial argument, checked before any trial runs (its range is the
    trial's to check: a value out of range becomes that trial's error row)."""
    if argument == "guidance":
        if not isinstance(value, bool):
            raise TypeError(f"grid['{name}']: expected bool, got {type(value).__name__} {value!r}")
    elif argument in ("rate_hz", "max_duration_s"):
        if isinstance(value, bool) or not isinstance(value, numbers.Real):
            raise TypeError(f"grid['{name}']: expected a number, got {type(value).__name__} {value!r}")


def _trial_arguments(parameters: typing.Iterable[tuple[str, typing.Any]]) -> dict[str, typing.Any]:
    """simulate_trial's keyword arguments for one combination of grid values. Raises what the parameter
    classes raise for a value out of range (ValueError) or of the wrong type (TypeError), naming it."""
    catalogue = _catalogue()
    arguments: dict[str, typing.Any] = {}
    law_fields: dict[str, typing.Any] = {}
    law_nested: dict[str, dict[str, typing.Any]] = {}
    writer_fields: dict[str, typing.Any] = {}
    for name, value in parameters:
        target = catalogue[name]
        if target[0] == "trial":
            _check_trial_argument_type(name, target[1], value)
            arguments[target[1]] = value
        elif target[0] == "writer":
            writer_fields[target[1]] = value
        elif len(target) == 2:
            law_fields[target[1]] = value
        else:
            law_nested.setdefault(target[1], {})[target[2]] = value
    if "writer" in arguments or writer_fields:
        profile = _writer_profile(arguments.get("writer", "novice"))
        arguments["writer"] = profile.replace(**writer_fields) if writer_fields else profile
    if law_fields or law_nested:
        law = ForceLawParameters().replace(**law_fields)
        for field, sub_fields in law_nested.items():
            law = law.replace(**{field: getattr(law, field).replace(**sub_fields)})
        arguments["force_law"] = law
    return arguments


@functools.lru_cache(maxsize=4)
def _library(source: _Source) -> CharacterLibrary:
    """The character source, opened once per process (a store is read whole, a folder lazily)."""
    kind, path = source
    if kind == "store":
        return CharacterLibrary.from_store(path)
    if kind == "hanzi_writer":
        return CharacterLibrary.from_hanzi_writer(path)
    return CharacterLibrary.default()


def _flat_metrics(metrics: dict[str, typing.Any]) -> dict[str, typing.Any]:
    """The scalar metrics of `calligraphy trial --json` (the one metrics record and the renderer's figures);
    the lists summarised: the renderer's attempts as their total over the strokes, the refusals one column
    per reason, the characters left out."""
    flat = {key: value for key, value in metrics.items()
            if key not in ("renderer_strokes", "per_character", "refusals")}
    flat["attempts_total"] = sum(stroke["attempts"] for stroke in metrics["renderer_strokes"])
    for reason, count in metrics["refusals"].items():
        flat[f"refused_{reason}"] = count
    return flat


def _error_text(error: BaseException) -> str:
    return f"{type(error).__name__}: {error}"


def _run_batch(batch: list[_TrialSpec], source: _Source) -> list[tuple[int, dict[str, typing.Any]]]:
    """Runs the trials of one batch in this process: [(position in the sweep, row)]. A trial that
    raises becomes a row with the error's text in 'error'; nothing but an interrupt escapes."""
    rows = []
    for index, character, seed, parameters in batch:
        row: dict[str, typing.Any] = {}
        try:
            result = simulate_trial(character, seed=seed, library=_library(source), keep_trace=False,
                                    **_trial_arguments(parameters))
            row.update(_flat_metrics(result.metrics))
            row["error"] = None
        except Exception as error:  # noqa: BLE001 - the error is the row's content
            row["error"] = _error_text(error)
        rows.append((index, row))
    return rows


def _source(store: typing.Any, data: typing.Any) -> _Source:
    if store is not None and data is not None:
        raise ValueError("sweep: give store= or data=, not both")
    if store is not None:
        return ("store", os.path.abspath(os.fspath(store)))
    if data is not None:
        return ("hanzi_writer", os.path.abspath(os.fspath(data)))
    return ("embedded", "")


def _character_labels(characters: typing.Any, library: CharacterLibrary) -> list[str]:
    if characters is None:
        return list(library.characters())
    if isinstance(characters, str):
        return list(characters)
    if isinstance(characters, (bytes, bytearray)) or not isinstance(characters, collections.abc.Iterable):
        raise TypeError(f"characters: expected a str or a list of non-empty str, got "
                        f"{type(characters).__name__} {characters!r}")
    labels = list(characters)
    for label in labels:
        if not isinstance(label, str) or not label:
            raise TypeError(f"characters: expected a str or a list of non-empty str, got item {label!r}")
    return labels


def _seed_list(seeds: typing.Any) -> list[int]:
    seeds = _plain(seeds)
    if isinstance(seeds, int) and not isinstance(seeds, bool):
        if seeds < 1 or seeds > MAX_SWEEP_TRIALS:
            raise ValueError(f"seeds: expected a count in 1..{MAX_SWEEP_TRIALS} or a list of seeds, got {seeds}")
        return list(range(seeds))
    if isinstance(seeds, (str, bytes)) or not isinstance(seeds, collections.abc.Iterable):
        raise TypeError(f"seeds: expected a count (int) or a list of seeds, got {type(seeds).__name__} {seeds!r}")
    values = [_plain(seed) for seed in seeds]
    if not values:
        raise ValueError("seeds: no seeds")
    for seed in values:
        if not isinstance(seed, int) or isinstance(seed, bool):  # 1.5, "1", True: of the wrong type
            raise TypeError(f"seeds: expected ints in 0..{_MAX_SEED} (0..2**64-1), got {type(seed).__name__} "
                            f"{seed!r}")
        if seed < 0 or seed > _MAX_SEED:
            raise ValueError(f"seeds: expected ints in 0..{_MAX_SEED} (0..2**64-1), got {seed!r}")
    return values


def _local_workers() -> int:
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:  # pragma: no cover - not on Linux
        return os.cpu_count() or 1


def _end_with(sweeper_pid: int) -> None:  # pragma: no cover - runs in each worker as it starts
    """Ends this worker once the process that runs the sweep is gone (stopped by SIGTERM, killed), so that
    no worker outlives it: a worker's parent is the forkserver, which lives as long as any worker does, and a
    worker holds both ends of its own queues, so neither a parent-death signal nor an end of file tells it.
    A thread waits on the sweeping process's pidfd (Linux 5.3), else looks for it once a second."""
    import select
    import threading
    import time

    def watch() -> None:
        try:
            descriptor: typing.Optional[int] = os.pidfd_open(sweeper_pid)
        except (AttributeError, OSError):  # not Linux, an older kernel, or already gone
            descriptor = None
        if descriptor is not None:
            select.select([descriptor], [], [])
        else:
            while True:
                try:
                    os.kill(sweeper_pid, 0)
                except ProcessLookupError:
                    break
                except PermissionError:
                    pass
                time.sleep(1.0)
        os._exit(1)

    threading.Thread(target=watch, name="calligraphy-sweep-watch", daemon=True).start()


def _process_pool(workers: int) -> concurrent.futures.ProcessPoolExecutor:
    # Not 'fork': the parent may hold threads (Dask, a servo loop, BLAS) that a fork would copy mid-state.
    method = "forkserver" if "forkserver" in multiprocessing.get_all_start_methods() else "spawn"
    return concurrent.futures.ProcessPoolExecutor(max_workers=workers,
                                                  mp_context=multiprocessing.get_context(method),
                                                  initializer=_end_with, initargs=(os.getpid(),))


def _progress_bar(total: int, enabled: bool, unit: str = "trial", desc: str = "sweep") -> typing.Any:
    if not enabled:
        return None
    try:
        from tqdm.auto import tqdm  # type: ignore[import]
    except ImportError:  # tqdm is optional: no bar
        return None
    return tqdm(total=total, unit=unit, desc=desc)


def _execute(executor: concurrent.futures.Executor, batches: list[list[_TrialSpec]], source: _Source,
             progress: typing.Any) -> dict[int, dict[str, typing.Any]]:
    """Runs every batch on `executor` (a process pool or a Dask client's executor): {position: row}.
    A batch that fails as a whole (a worker killed) gives every trial of it an error row."""
    futures = {executor.submit(_run_batch, batch, source): batch for batch in batches}
    rows: dict[int, dict[str, typing.Any]] = {}
    try:
        for future in concurrent.futures.as_completed(futures):
            batch = futures[future]
            try:
                rows.update(future.result())
            except Exception as error:  # noqa: BLE001 - recorded in the rows, the sweep goes on
                text = "batch failed: " + _error_text(error)
                rows.update((spec[0], {"error": text}) for spec in batch)
            if progress is not None:
                progress.update(len(batch))
    finally:
        for future in futures:
            future.cancel()  # after an interrupt: drop what has not started
    return rows


def sweep(characters: typing.Union[str, typing.Sequence[str], None],
          grid: typing.Mapping[str, typing.Iterable[typing.Any]],
          seeds: typing.Union[int, typing.Iterable[int]],
          client: typing.Any = None,
          store: typing.Union[str, os.PathLike, None] = None,
          data: typing.Union[str, os.PathLike, None] = None,
          batch_size: typing.Optional[int] = None,
          progress: bool = True,
          *,
          workers: typing.Optional[int] = None) -> pandas.DataFrame:
    """Runs one simulated trial (``simulate_trial`` with ``keep_trace=False``) per combination of the
    grid's values x character x seed, in that nesting order, and returns a pandas.DataFrame with one
    row per trial in that order (index 0..n-1).

    characters: a str (each character one trial), a list of str (each item one trial; several
        characters in an item are a group written left to right), or None for every character of
        the source.
    grid: parameter name -> list of values, e.g. {"guidance": [True, False],
        "guidance_stiffness_n_per_m": [200, 400]}. Names: simulate_trial's guidance, rate_hz [Hz],
        max_duration_s [s] and writer ('novice', 'skilled' or a WriterProfile; default 'novice'),
        any field of ForceLawParameters (nested ones by dotted name, 'nearest.method') or of
        WriterProfile (applied to the writer's profile); see parameter_names(). {} is one
        combination with the defaults.
    seeds: the writer's seeds, a list of ints >= 0, or an int n for seeds 0..n-1.
    client: None runs on a local process pool; a distributed.Client runs on its cluster; any
        concurrent.futures.Executor is used as it is.
    store / data: load characters from a corpus store (CharacterLibrary.from_store) or a
        hanzi-writer-data folder (CharacterLibrary.from_hanzi_writer) instead of the default set (every
        hanzi-writer-data character); the path must be readable by every worker.
    batch_size: trials per task (default: at most 32, at least 4 tasks per worker).
    progress: a tqdm progress bar (when tqdm is installed). workers: local processes (default:
        every core this process may run on); ignored with a client.

    Columns: 'character', 'seed', one per grid name (its values as given), the scalar metrics of
    `calligraphy trial --json` not already among them (deviations in m, times in s, forces in N,
    'completed_in_order', 'end_reason', ...), 'attempts_total' (attempts summed over the strokes)
    and 'error': None, or the text of the exception a failed trial raised (its metrics are then
    missing), e.g. "CharacterNotFound: ...".

    Raises ValueError for an unknown grid name (listing the valid ones), an empty value list or a
    value out of range, more than MAX_SWEEP_TRIALS (1,000,000) trials or workers beyond 1..MAX_WORKERS (1024), TypeError for a value of the wrong type or a client that is
    neither a distributed.Client nor a concurrent.futures.Executor (all before any trial runs),
    DataError when the store or folder cannot be opened, ImportError without pandas.
    """
    from .frames import _pandas

    pandas = _pandas()  # first: an ImportError saying how to install it, before any trial runs
    if client is not None and not (isinstance(client, concurrent.futures.Executor) or hasattr(client, "get_executor")):
        raise TypeError(f"client: expected a distributed.Client or a concurrent.futures.Executor, got "
                        f"{type(client).__name__} {client!r}")
    axes = _resolve(grid)
    source = _source(store, data)
    labels = _character_labels(characters, _library(source))
    seed_values = _seed_list(seeds)
    trial_count = len(labels) * len(seed_values) * math.prod(len(values) for _, values in axes)
    if trial_count > MAX_SWEEP_TRIALS:
        raise ValueError(f"sweep: {trial_count} trials (characters x seeds x grid combinations) exceed the bound "
                         f"of {MAX_SWEEP_TRIALS}; split the sweep")
    combinations = [tuple(zip([name for name, _ in axes], values))
                    for values in itertools.product(*[values for _, values in axes])]
    for combination in combinations:
        _trial_arguments(combination)  # every value checked here, not as an error in every row

    specs: list[_TrialSpec] = [
        (index, character, seed, combination)
        for index, (combination, character, seed)
        in enumerate(itertools.product(combinations, labels, seed_values))]

    own_pool = None
    executor: concurrent.futures.Executor
    if client is None:
        worker_count = workers if workers is not None else _local_workers()
        if isinstance(worker_count, bool) or not isinstance(worker_count, int) or not 1 <= worker_count <= MAX_WORKERS:
            raise ValueError(f"workers: expected an int in 1..{MAX_WORKERS}, got {worker_count!r}")
        executor = own_pool = _process_pool(min(worker_count, max(1, len(specs))))
    elif isinstance(client, concurrent.futures.Executor):
        executor = client
        worker_count = getattr(client, "_max_workers", None) or _local_workers()
    else:  # a distributed.Client: its concurrent.futures face
        executor = client.get_executor(pure=False)
        worker_count = max(1, sum(client.nthreads().values()))

    if batch_size is None:
        batch_size = max(1, min(_MAX_DEFAULT_BATCH, math.ceil(len(specs) / (_BATCHES_PER_WORKER * worker_count))))
    elif not isinstance(batch_size, int) or isinstance(batch_size, bool) or batch_size < 1:
        raise ValueError(f"batch_size: expected an int >= 1, got {batch_size!r}")
    batches = [specs[start:start + batch_size] for start in range(0, len(specs), batch_size)]

    bar = _progress_bar(len(specs), progress)
    try:
        results = _execute(executor, batches, source, bar)
    finally:
        if bar is not None:
            bar.close()
        if own_pool is not None:
            own_pool.shutdown(wait=True, cancel_futures=True)

    parameter_columns = ["character", "seed"] + [name for name, _ in axes]
    # The metrics' names and types from the first trial that ran (all have the same keys).
    ran = [results[index] for index in range(len(specs)) if results[index].get("error") is None]
    sample: dict[str, typing.Any] = ran[0] if ran else {}
    metric_columns = [key for key in sample if key not in parameter_columns and key != "error"]
    records = []
    for index, character, seed, combination in specs:
        record = {"character": character, "seed": seed, **dict(combination)}
        row = results[index]
        record.update((key, row.get(key)) for key in metric_columns)
        record["error"] = row.get("error")
        records.append(record)
    table = pandas.DataFrame.from_records(records, columns=parameter_columns + metric_columns + ["error"])
    # old millimetre columns (mean_deviation_mm) still read, with a DeprecationWarning, for one version
    return metric_frame(table.astype(_nullable_types(sample, metric_columns)))


def _nullable_types(sample: dict[str, typing.Any], columns: list[str]) -> dict[str, str]:
    """pandas' nullable types for the bool and int metrics, so that they stay bool and int next to the
    missing values of failed trials (which would make them object and float)."""
    types = {}
    for column in columns:
        if isinstance(sample[column], bool):
            types[column] = "boolean"
        elif isinstance(sample[column], int):
            types[column] = "Int64"
    return types
