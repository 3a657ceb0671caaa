#!/usr/bin/env python3
"""Speed of simulated trials from Python: one trial, and sweeps on 1 and N local workers and on a Dask cluster.

1. One trial (永, novice, guided, 1 kHz, seed 0, after one untimed trial), metrics only and with the
   trace kept: simulated seconds per wall-clock second.
2. One sweep (every embedded character x guidance off/on x --seeds seeds) as a plain loop in this
   process (no pool: the baseline for the sweep's overhead), on a local process pool of 1 and of
   --workers processes, then on a distributed.LocalCluster of --workers processes with one
   thread each: trials per wall-clock second. The local pool is started by each sweep, so its start-up
   (spawning and importing, about a second) is in its time; the Dask cluster is started before, its
   start-up printed apart. Each table is checked to equal the first (same rows whatever the executor).

From a build tree (one run each; on a shared machine, say so next to the numbers):
    PYTHONPATH=build/python python3 examples/python/sweep_throughput.py [--seeds 2] [--workers 2]
"""

import argparse
import sys
import time

import calligraphy
from calligraphy.experiments import dask_worker_config, sweep


def one_trial(keep_trace):
    calligraphy.simulate_trial("永", seed=1, keep_trace=keep_trace)  # warm-up: first loads, allocations
    start = time.perf_counter()
    result = calligraphy.simulate_trial("永", seed=0, keep_trace=keep_trace)
    wall_s = time.perf_counter() - start
    simulated_s = result.metrics["total_time_s"]
    print(f"one trial, 永, trace {'kept' if keep_trace else 'not kept'}: {simulated_s:.2f} s simulated in "
          f"{wall_s * 1e3:.0f} ms wall = {simulated_s / wall_s:.0f} simulated s per wall s")


def timed_sweep(label, characters, seeds, reference, **executor):
    start = time.perf_counter()
    table = sweep(characters, {"guidance": [False, True]}, seeds, progress=False, **executor)
    wall_s = time.perf_counter() - start
    errors = int(table.error.notna().sum())
    print(f"{label:28s} {len(table)} trials in {wall_s:6.2f} s = {len(table) / wall_s:6.2f} trials/s"
          f"{f', {errors} failed' if errors else ''}")
    if reference is not None and not table.equals(reference):
        raise SystemExit(f"{label}: the table differs from the first run")
    return table, len(table) / wall_s


def main(argv):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seeds", type=int, default=2, help="seeds per character and guidance (default 2)")
    parser.add_argument("--workers", type=int, default=2, help="processes of the parallel runs (default 2)")
    args = parser.parse_args(argv)
    if args.seeds < 1 or args.workers < 1:
        parser.error("--seeds and --workers must be at least 1")

    one_trial(keep_trace=False)
    one_trial(keep_trace=True)

    characters = calligraphy.CharacterLibrary.embedded().characters()
    print(f"sweep: {len(characters)} embedded characters x guidance off/on x {args.seeds} seeds")
    start = time.perf_counter()
    for guidance in (False, True):
        for character in characters:
            for seed in range(args.seeds):
                calligraphy.simulate_trial(character, guidance=guidance, seed=seed, keep_trace=False)
    wall_s = time.perf_counter() - start
    trials = 2 * len(characters) * args.seeds
    print(f"{'a loop in this process':28s} {trials} trials in {wall_s:6.2f} s = {trials / wall_s:6.2f} trials/s")
    reference, single = timed_sweep("local, 1 worker", characters, args.seeds, None, workers=1)
    _, local = timed_sweep(f"local, {args.workers} workers", characters, args.seeds, reference,
                           workers=args.workers)
    try:
        import dask.config
        import distributed
    except ImportError:
        print("distributed is not installed: no Dask run")
        on_dask = None
    else:
        start = time.perf_counter()
        # glibc's own malloc thresholds in the workers, not the nanny's (calligraphy.experiments).
        with dask.config.set(dask_worker_config()), \
                distributed.LocalCluster(n_workers=args.workers, processes=True, threads_per_worker=1,
                                         dashboard_address=None) as cluster, distributed.Client(cluster) as client:
            print(f"(Dask LocalCluster of {args.workers} workers started in {time.perf_counter() - start:.1f} s)")
            _, on_dask = timed_sweep(f"Dask LocalCluster, {args.workers} workers", characters, args.seeds,
                                     reference, client=client)
    print(f"scaling 1 -> {args.workers} local workers: x{local / single:.2f}"
          + (f"; Dask: x{on_dask / single:.2f}" if on_dask else ""))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
