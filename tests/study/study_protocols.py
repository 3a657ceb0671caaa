"""Protocols the study tests run (small enough to run in seconds, with the phases over two sessions), and the
scaffold of a test that runs `calligraphy` in a folder of its own (CALLIGRAPHY_CLI names the program)."""

import hashlib
import json
import os
import subprocess
import tempfile
import unittest
from pathlib import Path

CLI = os.environ.get("CALLIGRAPHY_CLI", "")


def williams_row(n, row):
    """Row `row` of the balanced Latin square of n conditions (Williams 1949) as condition indices, written out
    as docs/experiments.md states it: first row 0, 1, n-1, 2, n-2, ...; row r adds r mod n; for odd n, rows n
    to 2n-1 are rows 0 to n-1 reversed. The tests' own reading of the docs, not the library's code."""
    first, low, high = [0], 1, n - 1
    for k in range(1, n):
        first.append(low if k % 2 == 1 else high)
        low, high = (low + 1, high) if k % 2 == 1 else (low, high - 1)
    out = [(f + row) % n for f in first]
    if n % 2 == 1 and (row // n) % 2 == 1:
        out.reverse()
    return out


def digest_tree(folder):
    """SHA-256 of every file under `folder`, by its relative path: what a refused run must leave unchanged."""
    return {str(p.relative_to(folder)): hashlib.sha256(p.read_bytes()).hexdigest()
            for p in sorted(folder.rglob("*")) if p.is_file()}


class StudyCliTest(unittest.TestCase):
    """Runs the program in a temporary folder of its own (`self.cwd`), removed after each test."""

    folder_prefix = "calligraphy-study-"

    def setUp(self):
        if not CLI or not Path(CLI).exists():
            self.fail(f"CALLIGRAPHY_CLI={CLI!r} is not the calligraphy program: run these tests through ctest")
        self.folder = tempfile.TemporaryDirectory(prefix=self.folder_prefix)
        self.cwd = Path(self.folder.name)

    def tearDown(self):
        self.folder.cleanup()

    def run_cli(self, *args, timeout=600):
        return subprocess.run([CLI, *map(str, args)], cwd=self.cwd, stdout=subprocess.PIPE,
                              stderr=subprocess.PIPE, timeout=timeout)

    def write_protocol(self, protocol, name=None):
        """Writes `protocol` as `name` (default: its own name with .json) in the test's folder."""
        path = self.cwd / (name or f"{protocol['name']}.json")
        path.write_text(json.dumps(protocol, ensure_ascii=False), encoding="utf-8")
        return path


def two_session_protocol(name):
    """Pre-test, training and post-test on 十 in session 1, retention in session 2 after 60 s; 20 s trials."""
    return {
        "format": "calligraphy-study-protocol",
        "version": 1,
        "name": name,
        "conditions": [{"name": "vision", "mode": "vision"}, {"name": "haptic", "mode": "haptic"}],
        "phases": [
            {"phase": "pre-test", "condition": "vision", "characters": ["十"]},
            {"phase": "training", "condition": "haptic", "characters": ["十"]},
            {"phase": "post-test", "condition": "vision", "characters": ["十"]},
            {"phase": "retention", "condition": "vision", "characters": ["十"], "session": 2, "delay_s": 60},
        ],
        "trial": {"max_duration_s": 20},
    }
