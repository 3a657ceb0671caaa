#!/usr/bin/env python3
"""Benchmark: a study of many subjects loaded into tidy tables and reported, time and peak memory.

Runs one simulated subject through a protocol of TRIALS trials for real (`calligraphy session run`), then
copies that session folder for SUBJECTS - 1 more subjects (subject ids and per-subject metrics changed in the
copies; the traces hard-linked: neither the tables nor the Python page read them), and times, each in a fresh
process, `calligraphy.study.load` and `calligraphy.study_report.write_report` over the whole study. Prints the
wall time and the peak resident memory of each step (getrusage of the child).

    python3 bench/study_scale.py --cli build/bin/calligraphy --subjects 100 --trials 200 --work /tmp/scale

A benchmark, not a test: nothing is asserted; the figures go in docs/experiments.md.
"""

import argparse
import json
import os
import pathlib
import random
import shutil
import subprocess
import sys
import time

CHARACTERS = ["大", "山", "木", "中", "十", "人", "口", "九", "乙", "永"]


def protocol(trials: int) -> dict:
    repetitions = max(1, trials // (2 * len(CHARACTERS)))
    return {
        "format": "calligraphy-study-protocol", "version": 1, "name": "scale",
        "conditions": [{"name": "vision", "mode": "vision"}, {"name": "haptic", "mode": "haptic"}],
        "test": {"characters": CHARACTERS, "conditions": ["vision", "haptic"], "repetitions": repetitions},
        "order": {"conditions": "fixed", "characters": "fixed"},
        "trial": {"max_duration_s": 60, "rate_hz": 1000},
    }


def copy_subject(template: pathlib.Path, target: pathlib.Path, subject: str, factor: float) -> None:
    """The template subject's folder as another subject's: ids replaced (the subject's, and the session id,
    which names the subject), deviations and times scaled."""
    for source in template.rglob("*"):
        destination = target / str(source.relative_to(template)).replace("-S01-", f"-{subject}-")
        if source.is_dir():
            destination.mkdir(parents=True, exist_ok=True)
        elif source.suffix == ".json":
            text = source.read_text(encoding="utf-8").replace('"S01"', json.dumps(subject))
            text = text.replace("-S01-", f"-{subject}-")
            if source.parent.name == "trials":
                record = json.loads(text)
                for key in ("mean_deviation_m", "max_deviation_m", "rms_deviation_m", "total_time_s"):
                    if isinstance(record.get(key), (int, float)):
                        record[key] *= factor
                text = json.dumps(record)
            destination.write_text(text, encoding="utf-8")
        elif source.name != ".lock":
            os.link(source, destination)


def timed(code: str, env: dict) -> tuple[float, float, str]:
    """Runs `code` in a fresh Python; its wall time [s], its own peak resident memory [MB] and stdout."""
    start = time.perf_counter()
    peak = "import resource; print(resource.getrusage(resource.RUSAGE_SELF).ru_maxrss)"
    done = subprocess.run([sys.executable, "-c", code + "\n" + peak], env=env, capture_output=True, text=True)
    seconds = time.perf_counter() - start
    if done.returncode != 0:
        sys.exit(done.stderr)
    *output, peak_kb = done.stdout.strip().splitlines()
    return seconds, int(peak_kb) / 1024.0, "\n".join(output)


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--cli", required=True, help="the calligraphy program")
    parser.add_argument("--subjects", type=int, default=100)
    parser.add_argument("--trials", type=int, default=200, help="trials per subject (rounded to 20)")
    parser.add_argument("--work", required=True, help="a folder for the study (replaced)")
    parser.add_argument("--seed", type=int, default=1)
    arguments = parser.parse_args()
    work = pathlib.Path(arguments.work).resolve()
    cli = str(pathlib.Path(arguments.cli).resolve())
    shutil.rmtree(work, ignore_errors=True)
    work.mkdir(parents=True)
    (work / "scale.json").write_text(json.dumps(protocol(arguments.trials)), encoding="utf-8")
    start = time.perf_counter()
    subprocess.run([cli, "session", "run", "scale.json", "--writer", "simulated", "--subjects", "1",
                    "--out", "study"], cwd=work, check=True, stdout=subprocess.DEVNULL)
    print(f"one subject run for real: {time.perf_counter() - start:.1f} s")
    template = work / "study" / "S01"
    random_numbers = random.Random(arguments.seed)
    for number in range(2, arguments.subjects + 1):
        subject = f"S{number:03d}"
        copy_subject(template, work / "study" / subject, subject, random_numbers.uniform(0.8, 1.2))
    env = dict(os.environ)
    load_s, load_mb, rows = timed(
        "import calligraphy.study as s; t = s.load(%r); print(len(t.trials), len(t.strokes))" % str(work / "study"),
        env)
    print(f"load: {rows} rows (trials, strokes), {load_s:.1f} s, peak {load_mb:.0f} MB")
    report_s, report_mb, _ = timed(
        "import calligraphy.study as s, calligraphy.study_report as r; "
        "r.write_report(s.load(%r), %r)" % (str(work / "study"), str(work / "report")), env)
    print(f"load and report: {report_s:.1f} s, peak {report_mb:.0f} MB")
    return 0


if __name__ == "__main__":
    sys.exit(main())
