#!/usr/bin/env python3
"""Every reader of a study's files against every damage of every file kind, run by CTest as
`study_reader_conformance` (docs/testing.md).

A study of one subject is made once; for each file kind (a trial record, session.json, a trace) and each
damage (cut after a line and in the middle of one, at several places; a NUL byte; CRLF line ends; a byte-order
mark; a value of the wrong type; a newer version; a huge field; an empty file; for a trace, saved as HDF5 after a
header with its length and CRC-32: cuts, changed bytes, a newer version, another program's HDF5 file, and bytes
changed inside the HDF5 file's structure with the CRC-32 made to match, which HDF5 itself then parses; and
an older folder's gzip CSV trace with the CSV damages) a copy of the study holds the damaged file, and every
reader of that kind reads it: the command line's (`report --csv`, `report --out`,
`curriculum`, `session resume`, `trial --spec`, `score`) and Python's (`calligraphy.study.load`,
`Study.samples`, `rerun_trial`). Each must read the file or refuse it: a command exits 0, or 1 with one error
line naming the file (never a crash, a signal, a hang or an internal error); Python returns, or raises one of
the library's errors (DataError, ValueError) naming the file, never KeyError, IndexError, TypeError or a
parser's own exception.

CALLIGRAPHY_CLI names the program; the module is imported from PYTHONPATH.
"""
import gzip
import json
import os
import re
import shutil
import subprocess
import sys
import tempfile
import unittest
import zlib
from pathlib import Path

CLI = os.environ.get("CALLIGRAPHY_CLI", "")
SOURCE = Path(os.environ.get("CALLIGRAPHY_SOURCE_DIR", Path(__file__).resolve().parents[2]))
TIMEOUT_S = 60

PROTOCOL = {
    "format": "calligraphy-study-protocol",
    "version": 1,
    "name": "conformance",
    "conditions": [{"name": "vision", "mode": "vision"}, {"name": "fade", "mode": "fading"}],
    "phases": [
        {"phase": "pre-test", "condition": "vision", "characters": ["十"]},
        {"phase": "training", "condition": "fade", "characters": ["十"], "repetitions": 2},
    ],
    "trial": {"max_duration_s": 20},
}


def cuts(text):
    """Cut after a line and in the middle of one, at the start, a quarter, the middle and the end."""
    lines = text.split(b"\n")
    damages = {}
    for share in (0.0, 0.25, 0.5, 0.75, 0.99):
        line = min(len(lines) - 2, int(share * len(lines)))
        before = len(b"\n".join(lines[: line + 1])) + 1
        damages[f"cut after line {line + 1}"] = text[:before]
        damages[f"cut inside line {line + 2}"] = text[: before + max(1, len(lines[line + 1]) // 2)]
    return damages


def json_damages(text):
    damages = cuts(text)
    middle = len(text) // 2
    damages["NUL byte"] = text[:middle] + b"\0" + text[middle:]
    damages["CRLF line ends"] = text.replace(b"\n", b"\r\n")
    damages["byte-order mark"] = b"\xef\xbb\xbf" + text
    damages["version as text"] = re.sub(rb'"version": (\d+)', rb'"version": "\1"', text, count=1)
    damages["newer version"] = re.sub(rb'"version": (\d+)', rb'"version": 99', text, count=1)
    damages["number as text"] = re.sub(rb'(": )(-?\d+\.\d+)', rb'\1"\2"', text, count=3)
    damages["object as array"] = re.sub(rb'(": )\{', rb'\1[', text, count=1)
    damages["huge field"] = re.sub(rb'"subject": "[^"]*"', b'"subject": "' + b"S" * 200_000 + b'"', text, count=1)
    damages["empty"] = b""
    return damages


def csv_damages(text):
    damages = cuts(text)
    middle = len(text) // 2
    damages["NUL byte"] = text[:middle] + b"\0" + text[middle:]
    damages["CRLF line ends"] = text.replace(b"\n", b"\r\n")
    damages["byte-order mark"] = b"\xef\xbb\xbf" + text
    lines = text.split(b"\n")
    fields = lines[5].split(b",")
    damages["number as text"] = b"\n".join(lines[:5] + [b",".join([b"abc"] + fields[1:])] + lines[6:])
    damages["huge field"] = b"\n".join(lines[:5] + [b",".join([fields[0] + b"1" * 200_000] + fields[1:])] + lines[6:])
    damages["another header"] = b"\n".join([b"t,x,y"] + lines[1:])
    damages["empty"] = b""
    return damages


def trace_file(hdf5):
    """A trace file of the HDF5 file `hdf5` (include/calligraphy/report/trace_hdf5.hpp): the 512-byte header
    with its length and CRC-32, then the file."""
    header = b"calligraphy-trace\nversion 1\nbytes %d\ncrc32 %08x\n" % (len(hdf5), zlib.crc32(hdf5))
    return header + b"\0" * (512 - len(header)) + hdf5


def trace_damages(data):
    """Damages of a saved HDF5 trace: damage the header checks find, and damage inside the HDF5 file (its
    superblock, object headers, chunk index and data) under a matching CRC-32, which reaches HDF5's parser."""
    hdf5 = data[512:]
    damages = {f"cut at {share:.0%}": data[: int(share * len(data))] for share in (0.01, 0.3, 0.5, 0.9)}
    damages["cut by a byte"] = data[:-1]
    damages["NUL byte"] = data[:700] + b"\0" + data[700:]
    damages["byte changed"] = data[:2000] + bytes([data[2000] ^ 0x10]) + data[2001:]
    damages["header changed"] = data.replace(b"version 1", b"versioN 1", 1)
    damages["newer version"] = data.replace(b"version 1", b"version 2", 1)
    damages["another program's HDF5 file"] = hdf5
    damages["huge field"] = data[:512] + b"x" * 200_000
    damages["empty"] = b""
    for offset in (0, 8, 13, 40, 60, 100, 200, 400, 800, len(hdf5) // 2, len(hdf5) - 600, len(hdf5) - 40):
        for value in (0x00, 0xFF):
            tampered = bytearray(hdf5)
            tampered[offset] = value if tampered[offset] != value else value ^ 0x55
            damages[f"HDF5 byte {offset} set to {value:#x}, CRC-32 matching"] = trace_file(bytes(tampered))
    return damages


class ReaderConformance(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        if not CLI:
            raise unittest.SkipTest("CALLIGRAPHY_CLI is not set: run through ctest")
        cls.scratch = tempfile.TemporaryDirectory(prefix="calligraphy-readers-")
        root = Path(cls.scratch.name)
        (root / "p.json").write_text(json.dumps(PROTOCOL, ensure_ascii=False), encoding="utf-8")
        made = subprocess.run([CLI, "session", "run", "p.json", "--writer", "simulated", "--subject", "S01",
                               "--out", "study"], cwd=root, capture_output=True, timeout=TIMEOUT_S)
        assert made.returncode == 0, made.stderr.decode()
        cls.study = root / "study"
        cls.session = next(p for p in (root / "study" / "S01").iterdir() if not p.name.startswith("."))
        cls.record = sorted((cls.session / "trials").glob("*.json"))[1]  # a fading trial
        cls.trace = cls.record.with_suffix(".trace.h5")
        import calligraphy  # noqa: F401  (imported once: pandas and the module take a second)
        import calligraphy.study  # noqa: F401

    @classmethod
    def tearDownClass(cls):
        cls.scratch.cleanup()

    def damaged_copy(self, original, content, compress=False):
        """A copy of the study with `original` (a file in it) replaced by `content`; the copy's path of it."""
        copy = Path(self.scratch.name) / "copy"
        shutil.rmtree(copy, ignore_errors=True)
        shutil.copytree(self.study, copy / "study")
        (copy / "tables").mkdir()
        target = copy / "study" / original.relative_to(self.study)
        target.write_bytes(gzip.compress(content) if compress else content)
        return copy, target

    def check_cli(self, arguments, cwd, damaged, what, refused=1):
        """`refused`: the status of a refusal (1, damaged data; 2, the content of the file the command was given
        as its input: `trial --spec`, the session.json of `session resume DIR`)."""
        try:
            result = subprocess.run([CLI, *map(str, arguments)], cwd=cwd, capture_output=True, timeout=TIMEOUT_S)
        except subprocess.TimeoutExpired:
            self.fail(f"{arguments[0]} hung on {what}")
        stderr = result.stderr.decode(errors="replace")
        self.assertIn(result.returncode, (0, refused), f"{arguments[0]} on {what}: {stderr[-2000:]}")
        self.assertNotIn("internal error", stderr)
        if result.returncode == refused:
            errors = [line for line in stderr.splitlines() if ": error: " in line]
            self.assertEqual(len(errors), 1, stderr[-2000:])
            self.assertIn(damaged.name, errors[0], f"{arguments[0]} on {what} does not name the file")

    def check_python(self, call, damaged, what):
        import calligraphy

        try:
            call()
        except (calligraphy.Error, ValueError) as error:
            if isinstance(error, (KeyError, IndexError, TypeError)):
                raise
            self.assertIn(damaged.name, str(error)[:100_000], f"{what}: {error!s:.300}")

    def test_trial_records(self):
        import calligraphy
        import calligraphy.study

        for what, content in json_damages(self.record.read_bytes()).items():
            with self.subTest(damage=what):
                copy, damaged = self.damaged_copy(self.record, content)
                self.check_cli(["report", "study", "--csv", "tables"], copy, damaged, what)
                self.check_cli(["report", "study", "--out", "report.html"], copy, damaged, what)
                self.check_cli(["curriculum", "study", "--subject", "S01", "--from", "十人大"], copy, damaged, what)
                self.check_cli(["trial", "--spec", damaged, "--json", "again.json"], copy, damaged, what, refused=2)
                self.check_python(lambda: calligraphy.study.load(copy / "study"), damaged, what)
                self.check_python(lambda: calligraphy.rerun_trial(damaged), damaged, what)

    def test_session_manifests(self):
        import calligraphy.study

        manifest = self.session / "session.json"
        for what, content in json_damages(manifest.read_bytes()).items():
            with self.subTest(damage=what):
                copy, damaged = self.damaged_copy(manifest, content)
                self.check_cli(["report", "study", "--csv", "tables"], copy, damaged, what)
                self.check_cli(["curriculum", "study", "--subject", "S01", "--from", "十人大"], copy, damaged, what)
                # the session.json of the folder `session resume` is given: its content is the command's input
                self.check_cli(["session", "resume", damaged.parent], copy, damaged, what, refused=2)
                self.check_python(lambda: calligraphy.study.load(copy / "study"), damaged, what)

    def check_trace_readers(self, copy, damaged, what):
        import calligraphy.study

        self.check_cli(["report", "study", "--out", "report.html"], copy, damaged, what)
        self.check_cli(["score", damaged, "--character", "十"], copy, damaged, what)

        def samples():
            study = calligraphy.study.load(copy / "study")
            row = study.trials[study.trials["trace_file"].str.endswith(damaged.name)].iloc[0]
            study.samples(row)

        self.check_python(samples, damaged, what)

    def test_traces(self):
        for what, content in trace_damages(self.trace.read_bytes()).items():
            with self.subTest(damage=what):
                copy, damaged = self.damaged_copy(self.trace, content)
                self.check_cli(["trace", damaged, "--csv", "trace.csv"], copy, damaged, what)
                self.check_trace_readers(copy, damaged, what)

    def test_older_csv_traces(self):
        """A folder written before traces were HDF5: its record names a gzip CSV trace (files.csv)."""
        text = subprocess.run([CLI, "trace", self.trace], capture_output=True, check=True).stdout
        older = self.trace.with_name(self.record.stem + ".csv.gz")
        damages = {what: (content, True) for what, content in csv_damages(text).items()}
        compressed = gzip.compress(text)
        damages["gzip cut"] = (compressed[: len(compressed) // 2], False)
        damages["not gzip"] = (text, False)
        for what, (content, compress) in damages.items():
            with self.subTest(damage=what):
                copy, damaged = self.damaged_copy(self.trace, content, compress)
                damaged = damaged.rename(damaged.with_name(older.name))
                record = damaged.with_name(self.record.name)
                document = json.loads(record.read_text(encoding="utf-8"))
                document["files"] = {"csv": older.name, "svg": document["files"]["svg"]}
                record.write_text(json.dumps(document, ensure_ascii=False), encoding="utf-8")
                self.check_trace_readers(copy, damaged, what)
                plain = damaged.with_suffix("")  # score reads a plain CSV too
                plain.write_bytes(gzip.decompress(damaged.read_bytes()) if compress else content)
                self.check_cli(["score", plain, "--character", "十"], copy, plain, what)


if __name__ == "__main__":
    unittest.main(verbosity=2)
