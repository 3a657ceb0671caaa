#!/usr/bin/env python3
"""Fails when a source file includes a module its own module does not depend on.

The modules and what each depends on directly (docs/architecture.md) are MODULE_DEPENDS below, the same graph
as the `calligraphy_module(NAME DEPENDS ...)` lines of CMakeLists.txt (checked when that file is there, so
the two cannot drift apart). A module may include itself and every module it reaches through the graph. The
testing part (the emulator) is a side branch only eval and programs use. The front-ends (PROGRAMS: the command
line, the trainer, the Python module, the examples) stand on public headers: any module's `calligraphy/...`,
their own folder's headers, and the private parts PROGRAMS names for each (the command line runs eval's jobs
and opens the trainer's window); a module's private header is refused. Tests, benchmarks and fuzzers may
include anything (they test the internals). A file's module is the folder after src/ or
include/calligraphy/; an include's module is the folder after calligraphy/ (a public header) or the first
folder of a private header under src/. Usage: check-layering.py [ROOT] -> exit 1 listing each bad include
as file:line: message.
"""
import pathlib
import re
import sys

MODULE_DEPENDS = {
    "core": [],
    "model": ["core"],
    "collision": ["model"],
    "render": ["collision"],
    "analysis": ["model"],
    "devices": ["core"],
    "phantom_usb": ["devices"],
    "testing": ["devices"],
    "trial": ["render", "devices", "analysis"],
    "sim": ["devices", "render", "trial"],
    "report": ["trial", "analysis"],
    "legibility": ["trial"],
    "study": ["report", "sim", "legibility"],
    "eval": ["study", "testing"],
}


def reachable(module):
    seen, todo = set(), [module]
    while todo:
        for dependency in MODULE_DEPENDS[todo.pop()]:
            if dependency not in seen:
                seen.add(dependency)
                todo.append(dependency)
    return seen


# Each front-end's folder, and the private parts (folders under src/) it may include besides its own.
PROGRAMS = {
    "src/cli": {"cli", "eval", "trainer"},
    "src/trainer": {"trainer"},
    "bindings/python": set(),
    "examples": set(),
}

REACHES = {name: reachable(name) for name in MODULE_DEPENDS}
RANK = REACHES  # the modules the checker knows
CMAKE_MODULE = re.compile(r"^calligraphy_module\((\w+)([^)]*)\)", re.MULTILINE)


def cmake_graph_problems(root: pathlib.Path):
    """The DEPENDS of CMakeLists.txt's calligraphy_module lines, against MODULE_DEPENDS."""
    cmake = root / "CMakeLists.txt"
    if not cmake.is_file():
        return []
    problems = []
    for name, rest in CMAKE_MODULE.findall(cmake.read_text(encoding="utf-8")):
        words = rest.split()
        depends = []
        if "DEPENDS" in words:
            for word in words[words.index("DEPENDS") + 1:]:
                if word.isupper():
                    break
                depends.append(word)
        if name not in MODULE_DEPENDS:
            problems.append(f"CMakeLists.txt: module '{name}' is not in check-layering's MODULE_DEPENDS")
        elif sorted(depends) != sorted(MODULE_DEPENDS[name]):
            problems.append(f"CMakeLists.txt: module '{name}' DEPENDS {depends}, check-layering says "
                            f"{MODULE_DEPENDS[name]}")
    return problems


INCLUDE = re.compile(r'^\s*#\s*include\s*"([^"]+)"')


def module_of_file(relative: pathlib.PurePosixPath):
    parts = relative.parts
    if parts[:2] == ("include", "calligraphy") and len(parts) > 3:
        return parts[2]
    if parts[0] == "src" and len(parts) > 2:
        return parts[1]
    return None


def module_of_include(path: str):
    parts = pathlib.PurePosixPath(path).parts
    if parts[0] == "calligraphy" and len(parts) > 2:
        return parts[1]
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
                if target in RANK and target != own and target not in REACHES[own] and target != "testing":
                    problems.append(f"{relative}:{number}: module '{own}' includes '{match.group(1)}' "
                                    f"of module '{target}', which it does not depend on")
                elif target == "testing" and own not in ("testing", "eval"):
                    # The testing part (emulator, in-memory link) is a side branch for tests, not a layer
                    # the library builds on.
                    problems.append(f"{relative}:{number}: module '{own}' includes '{match.group(1)}' "
                                    f"of the testing part, which only tests, eval and programs may use")
    return problems


def check_programs(root: pathlib.Path):
    """Front-ends include public headers, their own, and the private parts PROGRAMS allows them."""
    problems = []
    for folder, allowed in PROGRAMS.items():
        for file in sorted((root / folder).rglob("*")):
            if file.suffix not in (".hpp", ".cpp", ".h"):
                continue
            relative = pathlib.PurePosixPath(file.relative_to(root).as_posix())
            for number, line in enumerate(file.read_text(encoding="utf-8").splitlines(), 1):
                match = INCLUDE.match(line)
                if not match:
                    continue
                parts = pathlib.PurePosixPath(match.group(1)).parts
                if parts[0] == "calligraphy" or len(parts) == 1 or parts[0] in allowed:
                    continue  # public, the folder's own (by name), or allowed
                if (root / "src" / parts[0]).is_dir():
                    problems.append(f"{relative}:{number}: the front-end {folder} includes '{match.group(1)}', "
                                    f"a private header of src/{parts[0]}: it stands on public headers")
    return problems


def main():
    root = pathlib.Path(sys.argv[1] if len(sys.argv) > 1 else ".").resolve()
    if not (root / "src").is_dir():
        print(f"check-layering: {root} has no src/ folder", file=sys.stderr)
        return 2
    problems = cmake_graph_problems(root) + check(root) + check_programs(root)
    for problem in problems:
        print(problem)
    if problems:
        print(f"check-layering: {len(problems)} problem(s)", file=sys.stderr)
        return 1
    print("check-layering: every include points to the same module or one it depends on, and the front-ends "
          "to public headers")
    return 0


if __name__ == "__main__":
    sys.exit(main())
