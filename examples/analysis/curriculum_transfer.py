#!/usr/bin/env python3
"""Does a curriculum beat a fixed list on transfer? A simulated comparison.

Two cohorts of learning simulated subjects (`--writer-learning two-state`, docs/writer.md) write the same
unguided pre-test (十, 人, 口), then train on four characters each, four times, and take a transfer test on
eight characters neither cohort trained. The fixed cohort trains on the first four candidates in the order
given (as a textbook list would); the curriculum cohort on the four that `calligraphy.study.
propose_characters` proposes from the pre-test's record (new typical strokes first, then weak ones). The
transfer test compares the shape skill the model carries into the test (free of trial noise) and the mean
deviation, with calligraphy.statistics.group_comparison. In this model transfer flows only through shared
typical strokes, so the result follows from which strokes each list covers: it is a prediction of the
model, not a finding about people (docs/experiments.md).

    python3 examples/analysis/curriculum_transfer.py --cli build/bin/calligraphy --subjects 10 [--out DIR]
"""

import argparse
import json
import pathlib
import subprocess
import sys
import tempfile

import pandas

import calligraphy.statistics as statistics
import calligraphy.study

PRE_TEST = ["十", "人", "口"]
# Candidates in a textbook-like order (the embedded set's, by code point), and a transfer set held out of both.
CANDIDATES = "七不专东个为乃之乙九也书以写几凸凹出力北千去又及四大女子家小弓心我月母水永没火"
TRANSFER = ["中", "日", "天", "木", "山", "马", "长", "风"]
TRAINED = 4


def protocol(name: str, training: list[str]) -> dict:
    return {"name": name, "conditions": [{"name": "free", "mode": "vision"}],
            "phases": [{"phase": "pre-test", "condition": "free", "characters": PRE_TEST},
                       {"phase": "training", "condition": "free", "characters": training, "repetitions": 4},
                       {"phase": "transfer", "condition": "free", "characters": TRANSFER}],
            "trial": {"max_duration_s": 60}}


def run(cli: str, folder: pathlib.Path, name: str, training: list[str], subjects: int, prefix: str) -> None:
    path = folder / f"{name}.json"
    path.write_text(json.dumps(protocol(name, training), ensure_ascii=False), encoding="utf-8")
    subprocess.run([cli, "session", "run", str(path), "--subjects", str(subjects), "--subject", prefix,
                    "--writer-profile", "foreign", "--writer-learning", "two-state", "--out", str(folder / "study")],
                   check=True, stdout=subprocess.DEVNULL)


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--cli", default="calligraphy", help="the calligraphy program")
    parser.add_argument("--subjects", type=int, default=10, help="simulated subjects in each cohort (>= 2)")
    parser.add_argument("--out", help="a new folder (default: a temporary one)")
    arguments = parser.parse_args()
    if arguments.subjects < 2:
        parser.error("--subjects: at least 2")
    folder = pathlib.Path(arguments.out or tempfile.mkdtemp(prefix="curriculum-"))
    folder.mkdir(parents=True, exist_ok=True)

    # The curriculum reads a learner's pre-test: a placement subject writes it first.
    placement = {"name": "placement", "conditions": [{"name": "free", "mode": "vision"}],
                 "phases": [{"phase": "pre-test", "condition": "free", "characters": PRE_TEST}]}
    (folder / "placement.json").write_text(json.dumps(placement, ensure_ascii=False), encoding="utf-8")
    subprocess.run([arguments.cli, "session", "run", str(folder / "placement.json"), "--subject", "P01",
                    "--writer-profile", "foreign", "--out", str(folder / "placement")], check=True,
                   stdout=subprocess.DEVNULL)
    proposed = calligraphy.study.propose_characters(folder / "placement", "P01", CANDIDATES, count=TRAINED)
    curriculum = [p["character"] for p in proposed]
    fixed = list(CANDIDATES[:TRAINED])
    reasons = ", ".join(f"{p['character']} new {p['new_strokes']}" for p in proposed)
    print(f"fixed list: {''.join(fixed)}; curriculum: {''.join(curriculum)} ({reasons})")
    run(arguments.cli, folder, "fixed-list", fixed, arguments.subjects, "F")
    run(arguments.cli, folder, "curriculum", curriculum, arguments.subjects, "C")

    trials = calligraphy.study.load(folder / "study").trials
    transfer = trials[trials.phase == "transfer"]
    per_subject = transfer.groupby("subject", observed=True).agg(
        cohort=("protocol", "first"), shape_skill=("shape_skill", "mean"),
        mean_deviation_m=("mean_deviation_m", "mean")).reset_index()
    per_subject["cohort"] = per_subject["cohort"].astype(str)
    print(per_subject.groupby("cohort")[["shape_skill", "mean_deviation_m"]].agg(["mean", "std"]).to_string())
    for value in ("shape_skill", "mean_deviation_m"):
        try:
            c = statistics.group_comparison(per_subject, value, "curriculum", "fixed-list", by="cohort")
        except ValueError as error:  # a constant value (the model's skill is the same for every subject)
            means = per_subject.groupby("cohort")[value].mean()
            print(f"{value}: curriculum - fixed list = {means['curriculum'] - means['fixed-list']:+.4g} "
                  f"(no test: {error})")
            continue
        print(f"{value}: curriculum - fixed list = {c.mean_difference:+.4g} [{c.ci95_low:+.4g}, {c.ci95_high:+.4g}], "
              f"Welch t({c.df:.1f}) = {c.t:.2f}, p = {c.p:.3g}, g = {c.g:+.2f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
