#!/usr/bin/env python3
"""Fails when a source file includes a module above its own.

The modules, lowest first (docs/architecture.md): core, model, collision, render, devices, sim (its testing
part, the emulator, only for eval and programs), trial, report, study, eval, then the programs (cli, bindings, tests, bench, examples, fuzz),
which may include any module. A file's module is the folder after src/ or include/calligraphy/; an
include's module is the folder after calligraphy/ (a public header) or the first folder of a private
header under src/. Usage: check-layering.py [ROOT] -> exit 1 listing each upward include as
file:line: message.
"""
import pathlib
import re
import sys

ORDER = ["core", "model", "collision", "render", "devices", "sim", "testing", "trial", "report", "study", "eval"]
RANK = {name: rank for rank, name in enumerate(ORDER)}
INCLUDE = re.compile(r'^\s*#\s*include\s*"([^"]+)"')


def module_of_file(relative: pathlib.PurePosixPath):
    parts = relative.parts
    if parts[:2] == ("include", "calligraphy") and len(parts) > 3:
        return parts[2]
    if parts[0] == "src" and len(parts) > 2:
        if parts[1] == "sim" and parts[2] == "testing":
            return "testing"
        return parts[1]
    return None


def module_of_include(path: str):
    parts = pathlib.PurePosixPath(path).parts
    if parts[0] == "calligraphy" and len(parts) > 2:
        return parts[1]
    if len(parts) > 1 and parts[0] == "sim" and parts[1] == "testing":
        return "testing"
    if len(parts) > 1 and parts[0] in RANK:
        return parts[0]
    return None


def check(root: pathlib.Path):
    problems = []
    for top in ("src", "include"):
        for file in sorted((root / top).rglob("*")):
            if file.suffix not in (".hpp", ".cpp", ".h"):
                continue
            relative = pathlib.PurePosixPath(file.relative_to(root).as_posix())
            own = module_of_file(relative)
            if own not in RANK:
                continue  # programs (cli) may include any module
            for number, line in enumerate(file.read_text(encoding="utf-8").splitlines(), 1):
                match = INCLUDE.match(line)
                if not match:
                    continue
                target = module_of_include(match.group(1))
                if target in RANK and RANK[target] > RANK[own]:
                    problems.append(f"{relative}:{number}: module '{own}' includes '{match.group(1)}' "
                                    f"of module '{target}', which is above it")
                elif target == "testing" and own not in ("testing", "eval"):
                    # The testing part (emulator, in-memory link) is a side branch for tests, not a layer
                    # the library builds on.
                    problems.append(f"{relative}:{number}: module '{own}' includes '{match.group(1)}' "
                                    f"of the testing part, which only tests, eval and programs may use")
    return problems


def main():
    root = pathlib.Path(sys.argv[1] if len(sys.argv) > 1 else ".").resolve()
    if not (root / "src").is_dir():
        print(f"check-layering: {root} has no src/ folder", file=sys.stderr)
        return 2
    problems = check(root)
    for problem in problems:
        print(problem)
    if problems:
        print(f"check-layering: {len(problems)} upward include(s)", file=sys.stderr)
        return 1
    print("check-layering: every include points to the same module or one below")
    return 0


if __name__ == "__main__":
    sys.exit(main())
