#!/usr/bin/env python3
"""Where a build's time went: the compile and link time of each target and the slowest files, from Ninja's
own log (BUILD_DIR/.ninja_log, one line per output: start ms, end ms, mtime, output, command hash).

    python3 scripts/build-times.py BUILD_DIR [--top N]

Times are each step's wall time as Ninja measured it; with -j2 two steps overlap, so the sum is about twice
the stage's wall time. Only the last run of each output counts (an incremental build lists what it rebuilt).
"""
import argparse
import re
import sys
from collections import defaultdict
from pathlib import Path

TARGET = re.compile(r"CMakeFiles/([^/]+)\.dir/")


def read_log(path):
    """{output: seconds} of the newest entry of each output."""
    steps = {}
    with open(path, encoding="utf-8", errors="replace") as log:
        for line in log:
            if line.startswith("#"):
                continue
            fields = line.rstrip("\n").split("\t")
            if len(fields) < 4 or not fields[0].isdigit() or not fields[1].isdigit():
                continue
            steps[fields[3]] = (int(fields[1]) - int(fields[0])) / 1000.0
    return steps


def target_of(output):
    match = TARGET.search(output)
    if match:
        return match.group(1)
    return "links and other steps" if not output.endswith((".o", ".gch")) else "other objects"


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("build_dir", type=Path)
    parser.add_argument("--top", type=int, default=10)
    args = parser.parse_args()
    log = args.build_dir / ".ninja_log"
    if not log.is_file():
        sys.exit(f"build-times: {log} does not exist (not a Ninja build folder?)")
    steps = read_log(log)
    per_target = defaultdict(float)
    for output, seconds in steps.items():
        per_target[target_of(output)] += seconds
    total = sum(steps.values())
    print(f"-- build steps in {args.build_dir}: {len(steps)}, {total:.0f} s of step time in all")
    print(f"-- the {args.top} targets that took longest (s of step time):")
    for target, seconds in sorted(per_target.items(), key=lambda item: -item[1])[: args.top]:
        print(f"{seconds:8.1f}  {target}")
    print(f"-- the {args.top} slowest steps (s):")
    for output, seconds in sorted(steps.items(), key=lambda item: -item[1])[: args.top]:
        print(f"{seconds:8.1f}  {output}")


if __name__ == "__main__":
    main()
