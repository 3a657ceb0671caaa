#!/usr/bin/env python3
"""How a simulated cohort scales: the same subjects on 1 and N C++ threads and on Dask clusters of 1 and N
workers, with the tables checked equal, then the schedules compared on what the training left behind.

Runs examples/protocols/cohort-schedules.json (50 trials a subject over two days, seven training groups)
for --subjects learning subjects (calligraphy.cohort.simulate; docs/experiments.md, "A cohort in memory")
and prints each run's wall time and trials per second. The subjects are a model, not people.

    PYTHONPATH=build/python python3 examples/analysis/cohort_scale.py --subjects 28 [--workers 2] [--no-dask]
    PYTHONPATH=build/python python3 examples/analysis/cohort_scale.py --tables DIR   # trials.csv of session cohort
"""

import argparse
import pathlib
import sys
import time

import pandas

import calligraphy.cohort
import calligraphy.statistics as statistics
import calligraphy.study

PROTOCOL = pathlib.Path(__file__).resolve().parents[1] / "protocols" / "cohort-schedules.json"


def timed(label: str, run) -> "calligraphy.study.Study":
    start = time.perf_counter()
    study = run()
    seconds = time.perf_counter() - start
    print(f"{label:<34} {len(study.trials):6d} trials in {seconds:7.1f} s: {len(study.trials) / seconds:6.1f} trials/s",
          flush=True)
    return study


# What each group's training left behind: the error across the stroke, and the time the pen was down (the
# timing skill: speed and pauses), each with its scale and unit.
OUTCOMES = (("mean_deviation_m", 1e3, "mm"), ("pen_down_time_s", 1.0, "s"))


def compare_groups(trials: "pandas.DataFrame") -> None:
    """Each group's learning, retention and transfer, and each schedule against the unguided, per outcome."""
    print(f"\n{trials.subject.nunique()} subjects, {len(trials)} trials")
    for skill in ("shape_skill", "timing_skill"):
        skills = trials.pivot_table(index="group", columns="phase", values=skill, aggfunc="mean", observed=True)
        print(f"\n{skill.replace('_', ' ')} at the start of each phase's trials:")
        print(skills[[p for p in ("pre-test", "training", "post-test", "retention", "transfer") if p in skills]]
              .round(3).to_string())
    for value, scale, unit in OUTCOMES:
        learning = statistics.learning(trials, value, pre="pre-test", post="post-test", retention="retention",
                                       transfer="transfer")
        learning["retention_loss"] = learning["retention"] - learning["post"]
        columns = ["pre", "post", "retention", "transfer", "gain", "retention_loss"]
        print(f"\n{value} [{unit}] per group, means over subjects:")
        print((learning.groupby("group")[columns].mean() * scale).round(3).to_string())
        if "unguided" not in set(learning.group):
            continue
        if learning.groupby("group").size().min() < 2:
            print("(groups of fewer than 2 subjects: no comparisons)")
            continue
        print(f"each schedule - unguided (Welch t-test, Hedges' g; {unit}):")
        for group in sorted(set(learning.group) - {"unguided"}):
            for quantity in ("gain", "retention", "transfer"):
                c = statistics.group_comparison(learning, quantity, group, "unguided")
                print(f"  {group:17} {quantity:9} {c.mean_difference * scale:+.3f} [{c.ci95_low * scale:+.3f}, "
                      f"{c.ci95_high * scale:+.3f}], p = {c.p:.3g}, g = {c.g:+.2f} (n = {c.n_a}, {c.n_b})")


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--protocol", default=str(PROTOCOL))
    parser.add_argument("--subjects", type=int, default=28, help="simulated subjects (7 groups in turn)")
    parser.add_argument("--profile", default="foreign")
    parser.add_argument("--workers", type=int, default=2, help="threads and Dask workers of the larger runs")
    parser.add_argument("--no-dask", action="store_true", help="threads only")
    parser.add_argument("--tables", help="no timing: compare the groups of DIR/trials.csv (calligraphy session "
                                         "cohort --csv DIR)")
    arguments = parser.parse_args()
    if arguments.tables:
        text = (pathlib.Path(arguments.tables) / "trials.csv").read_text(encoding="utf-8")
        compare_groups(calligraphy.study._read_table(text, calligraphy.study._NUMERIC_TRIAL_COLUMNS,
                                                     ("completed_in_order",)))
        return 0

    def simulate(**options):
        return calligraphy.cohort.simulate(arguments.protocol, arguments.subjects, profile=arguments.profile,
                                           progress=False, **options)

    one = timed("threads: 1", lambda: simulate(workers=1))
    many = timed(f"threads: {arguments.workers}", lambda: simulate(workers=arguments.workers))
    pandas.testing.assert_frame_equal(one.trials, many.trials)
    if not arguments.no_dask:
        import dask.config
        import distributed

        from calligraphy.experiments import dask_worker_config

        # glibc's own malloc thresholds in the workers, not the nanny's (calligraphy.experiments).
        for workers in sorted({1, arguments.workers}):
            with dask.config.set(dask_worker_config()), \
                    distributed.LocalCluster(n_workers=workers, processes=True, threads_per_worker=1,
                                             dashboard_address=None, silence_logs=50) as cluster, \
                    distributed.Client(cluster) as client:
                on_dask = timed(f"Dask LocalCluster: {workers} worker(s)", lambda: simulate(client=client))
            pandas.testing.assert_frame_equal(on_dask.trials, one.trials)
    print("the tables of every run are the same, row for row")

    compare_groups(many.trials)
    return 0


if __name__ == "__main__":
    sys.exit(main())
