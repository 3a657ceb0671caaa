#!/usr/bin/env python3
"""Guidance compared on what it leaves behind: a simulated retention and transfer experiment.

Runs examples/protocols/retention-transfer.json, or another protocol of that design such as
guidance-schedules.json (day 1: unguided pre-test, training in one group per training condition, unguided
post-test; day 2: unguided retention and transfer tests) with learning simulated
subjects (`--writer-learning two-state`: the two-state memory of Smith, Ghazizadeh & Shadmehr 2006, which
learns from the error the guidance leaves it; docs/writer.md), then prints each group's learning,
retention and transfer (calligraphy.statistics.learning) and the groups compared (group_comparison: Welch
t-test, Hedges' g). Optionally writes the study report. The subjects are a model, not people: what it
prints is what the model predicts (docs/experiments.md, "Retention and transfer in simulation").

    python3 examples/analysis/retention_transfer.py --cli build/bin/calligraphy --per-group 10 [--protocol FILE] [--out DIR] [--report DIR]
"""

import argparse
import itertools
import json
import pathlib
import subprocess
import sys
import tempfile
import time

import calligraphy.statistics as statistics
import calligraphy.study

PROTOCOL = pathlib.Path(__file__).resolve().parents[1] / "protocols" / "retention-transfer.json"


def training_groups(protocol: pathlib.Path) -> int:
    """The protocol's between-subjects training conditions, assigned by subject number in turn."""
    phases = json.loads(protocol.read_text(encoding="utf-8"))["phases"]
    return max(len(phase.get("conditions", [])) for phase in phases if phase["phase"] == "training")


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--cli", default="calligraphy", help="the calligraphy program")
    parser.add_argument("--protocol", default=str(PROTOCOL),
                        help="the protocol (default: retention-transfer.json; guidance-schedules.json has all seven "
                             "schedules)")
    parser.add_argument("--per-group", type=int, default=10, help="simulated subjects in each group")
    parser.add_argument("--profile", default="foreign", help="the subjects' writer profile")
    parser.add_argument("--out", help="a new folder for the sessions (default: a temporary one)")
    parser.add_argument("--report", help="also write the study report (calligraphy.study_report) here")
    arguments = parser.parse_args()
    if arguments.per_group < 2:
        parser.error("--per-group: at least 2 (a group comparison needs 2 subjects a group)")
    out = arguments.out or str(pathlib.Path(tempfile.mkdtemp(prefix="retention-")) / "study")

    started = time.monotonic()
    groups = training_groups(pathlib.Path(arguments.protocol))
    subprocess.run([arguments.cli, "session", "run", arguments.protocol, "--subjects", str(groups * arguments.per_group),
                    "--writer-profile", arguments.profile, "--writer-learning", "two-state", "--out", out],
                   check=True, stdout=subprocess.DEVNULL)
    study = calligraphy.study.load(out)
    print(f"{out}: {len(study.trials)} trials of {study.trials.subject.nunique()} subjects in "
          f"{time.monotonic() - started:.1f} s")
    # The model's own state, free of the trials' noise: the skills each phase's trials started with.
    for skill in ("shape_skill", "timing_skill"):
        skills = study.trials.pivot_table(index="group", columns="phase", values=skill, aggfunc="mean",
                                          observed=True)
        print(f"\n{skill.replace('_', ' ')} (0 to 1) at the start of each phase's trials, mean over trials and subjects")
        print(skills[["pre-test", "training", "post-test", "retention", "transfer"]]
              .to_string(float_format=lambda x: f"{x:.3f}"))
    for value in ("mean_deviation_m", "pen_down_time_s"):
        table = statistics.learning(study.trials, value, "pre-test", "post-test", retention="retention",
                                    transfer="transfer")
        columns = ["pre", "post", "retention", "transfer", "gain", "retention_ratio", "transfer_gain"]
        print(f"\n{value}: means over each group's subjects")
        print(table.groupby("group")[columns].mean().to_string(float_format=lambda x: f"{x:.4g}"))
        for a, b in itertools.combinations(sorted(table.group.unique()), 2):
            for quantity in ("gain", "retention", "transfer"):
                c = statistics.group_comparison(table, quantity, a, b)
                print(f"  {quantity:9} {a} - {b}: {c.mean_difference:+.4g} [{c.ci95_low:+.4g}, {c.ci95_high:+.4g}], "
                      f"t({c.df:.1f}) = {c.t:.2f}, p = {c.p:.3g}, g = {c.g:+.2f} (n = {c.n_a}, {c.n_b})")
    if arguments.report:
        from calligraphy import study_report
        print(study_report.write_report(study, arguments.report))
    return 0


if __name__ == "__main__":
    sys.exit(main())
