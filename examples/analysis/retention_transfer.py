#!/usr/bin/env python3
"""Guidance compared on what it leaves behind: a simulated retention and transfer experiment.

Runs examples/protocols/retention-transfer.json, or another protocol of that design such as
guidance-schedules.json (day 1: unguided pre-test, training in one group per training condition, unguided
post-test; day 2: unguided retention and transfer tests) with learning simulated
subjects (`--writer-learning two-state`: the two-state memory of Smith, Ghazizadeh & Shadmehr 2006, which
learns from the error the guidance leaves it; docs/writer.md), then prints the design's questions
(calligraphy.design_analysis: during training a mixed model with subjects and characters crossed and
Satterthwaite df from R's lmerTest; after training each group against the unguided control adjusted for the
pre-test (ANCOVA); Holm within each outcome; Hedges' g) and the guarded share of the gain kept. Optionally writes the study report. The subjects are a model, not people: what it
prints is what the model predicts (docs/experiments.md, "Retention and transfer in simulation").

    python3 examples/analysis/retention_transfer.py --cli build/bin/calligraphy --per-group 10 [--protocol FILE] [--out DIR] [--report DIR]
"""

import argparse
import json
import pathlib
import subprocess
import sys
import tempfile
import time

import calligraphy.study
from calligraphy import design_analysis

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
    design = design_analysis.study_design(study.trials)
    print(f"\n{design.sentence()}")
    for value in ("mean_deviation_m", "pen_down_time_s"):
        millimetres = value.endswith("_m")
        questions = design_analysis.design_questions(study.trials, value, design, scale=1e3 if millimetres else 1.0,
                                                     display_unit="mm" if millimetres else "s")
        print(f"\n{value}: each group against {design.control} (training: crossed mixed model; after: ANCOVA on "
              "the pre-test; p Holm-adjusted)")
        for row in questions.itertuples():
            result = row.apa or row.note
            print(f"  {row.phase:9} {row.comparison:22} {result}" + (f", p(Holm) = {row.p_holm:.3g}"
                                                                     if row.apa else ""))
        ratios = design_analysis.retention_ratios(study.trials, value, design)
        for ratio in ratios.itertuples():
            print(f"  share of the gain kept at retention, {ratio.group}: "
                  f"{ratio.retention_ratio:.2f}" if ratio.retention_ratio == ratio.retention_ratio else
                  f"  share of the gain kept at retention, {ratio.group}: {ratio.note}")
    print(f"\n{design_analysis.transfer_baseline(study.trials, design)}")
    if arguments.report:
        from calligraphy import study_report
        print(study_report.write_report(study, arguments.report))
    return 0


if __name__ == "__main__":
    sys.exit(main())
