#!/usr/bin/env python3
"""From `calligraphy session run` to the statistics table, in a few lines.

Runs the paper's design (examples/protocols/paper-table5.json: Wang, Zhang & Yao 2006, section 7) with
simulated subjects, loads the sessions as tidy tables (calligraphy.study), and prints the statistics of the
writing time and the mean deviation with and without haptic guidance (calligraphy.statistics: paired t-test,
Wilcoxon, Cohen's d_z, Hedges' g_av, power, and a mixed model with subject and character as random effects).
Simulated subjects are a model of a writer, not people: docs/experiments.md says what they can and cannot show.

    python3 examples/analysis/paper_table5.py --cli build/bin/calligraphy --subjects 6 [--out DIR]
"""

import argparse
import pathlib
import subprocess
import sys
import tempfile

import calligraphy.statistics as statistics
import calligraphy.study

PROTOCOL = pathlib.Path(__file__).resolve().parents[1] / "protocols" / "paper-table5.json"


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--cli", default="calligraphy", help="the calligraphy program")
    parser.add_argument("--subjects", type=int, default=6)
    parser.add_argument("--out", help="a new folder for the sessions (default: a temporary one)")
    arguments = parser.parse_args()
    out = arguments.out or str(pathlib.Path(tempfile.mkdtemp(prefix="table5-")) / "study")

    subprocess.run([arguments.cli, "session", "run", str(PROTOCOL), "--writer", "simulated",
                    "--subjects", str(arguments.subjects), "--out", out], check=True,
                   stdout=subprocess.DEVNULL)
    study = calligraphy.study.load(out)
    print(f"{out}: {len(study.trials)} trials of {study.trials.subject.nunique()} subjects")
    test = study.trials[study.trials.phase == "test"]
    print(test.groupby("condition", observed=True)[["total_time_s", "mean_deviation_m"]].agg(["mean", "std"]))
    for value in ("total_time_s", "mean_deviation_m"):
        table = statistics.statistics_table(test, value)
        print(f"\n{value}")
        print(table[["comparison", "test", "n", "statistic", "p", "effect_name", "effect"]].to_string(index=False))
    return 0


if __name__ == "__main__":
    sys.exit(main())
