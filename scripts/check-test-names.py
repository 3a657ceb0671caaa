#!/usr/bin/env python3
"""Fails when a Catch2 test case's name would not come through CTest's discovery (catch_discover_tests) as one
test of its own: a name holding ';' (CMake's list separator: the name is split), a '[' or ']' without its
pair (the discovery's listing then runs into the following names: one test for 31 cases once), or a leading
or trailing space. Reads every TEST_CASE / SCENARIO / TEMPLATE_TEST_CASE under tests/, fuzz/ and bench/
whose name is a plain string literal. Usage: check-test-names.py [ROOT] -> exit 1 listing file:line: name.
"""
import pathlib
import re
import sys

CASE = re.compile(r'\b(?:TEST_CASE|SCENARIO|TEMPLATE_TEST_CASE|TEST_CASE_METHOD\s*\(\s*\w+\s*,)\s*\(?\s*((?:"(?:[^"\\]|\\.)*"\s*)+)',
                  re.S)
STRING = re.compile(r'"((?:[^"\\]|\\.)*)"')


def names(text):
    for match in CASE.finditer(text):
        name = "".join(STRING.findall(match.group(1)))
        yield text.count("\n", 0, match.start()) + 1, name


def problem(name):
    if ";" in name:
        return "holds ';' (CMake splits the discovered name there)"
    depth = 0
    for character in name:
        depth += {"[": 1, "]": -1}.get(character, 0)
        if depth < 0 or depth > 1:
            break
    if depth != 0:
        return "holds a '[' or ']' without its pair (CTest's discovery merges the cases after it)"
    if name != name.strip():
        return "begins or ends with a space"
    return None


def main(root):
    bad = []
    for folder in ("tests", "fuzz", "bench"):
        for path in sorted((root / folder).rglob("*.cpp")) if (root / folder).is_dir() else []:
            for line, name in names(path.read_text(encoding="utf-8", errors="replace")):
                why = problem(name)
                if why:
                    bad.append(f"{path.relative_to(root)}:{line}: {name!r} {why}")
    for entry in bad:
        print(entry)
    if bad:
        return 1
    print("check-test-names: every test case's name comes through CTest's discovery whole")
    return 0


if __name__ == "__main__":
    sys.exit(main(pathlib.Path(sys.argv[1] if len(sys.argv) > 1 else ".")))
