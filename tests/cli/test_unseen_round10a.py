#!/usr/bin/env python3
"""Round 10A: hostile cases written from the documentation alone (docs/cli.md, docs/python.md, the commands'
`--help` and `calligraphy schema`) on the single-trial surfaces: `trial` (its options, `--spec` records,
teachers, devices named, outputs), `trace`, `score`, `model`, `strokes`, `characters`, `corpus`, `devices`,
`curriculum`, `schema`, `bench` and `train` options, and the Python functions of the same surfaces. Inputs
are forged, cut, linked, made FIFOs and devices; numbers are given at and past their documented ranges;
outputs are put on inputs, into missing and immutable folders, into FIFOs, closed pipes and under a file
size limit. Run by CTest as `cli_unseen_round10a_tests`.

Each case asserts what the documentation promises: one error line naming the option, file, JSON pointer or
row, exit 2 for wrong usage or refused content and 1 for a runtime failure, never a hang, a crash, a
traceback or a silent wrong result, nothing written outside its folder, no input replaced, no temporary
left behind. CALLIGRAPHY_CLI names the program, CALLIGRAPHY_SOURCE_DIR the source tree; the built Python
package is found on PYTHONPATH (its cases are skipped without it). CALLIGRAPHY_SANITIZED=1 takes a small
subset.
"""
import json
import math
import os
import resource
import shutil
import signal
import subprocess
import sys
import tempfile
import threading
import time
import unittest
from pathlib import Path

from outsider import CLI, ENV, TIMEOUT_S, OneErrorLine, error_lines, run

SOURCE = Path(os.environ.get("CALLIGRAPHY_SOURCE_DIR", Path(__file__).resolve().parents[2]))
DATA = SOURCE / "data" / "hanzi-writer-data"
HANG_S = 25  # a read that waits for a writer that never comes must end well before this
SANITIZED = os.environ.get("CALLIGRAPHY_SANITIZED") == "1"
SHI = "十"

heavy = unittest.skipIf(SANITIZED, "several runs of the program: left to the Release run")

try:
    import calligraphy as cg
except ImportError:  # pragma: no cover - a build without the Python bindings
    cg = None

needs_python = unittest.skipIf(cg is None, "the Python package is not on PYTHONPATH")


def strict_json(text):
    def refuse(token):
        raise ValueError(f"not JSON: {token}")
    return json.loads(text, parse_constant=refuse)


def file_size_limit(limit_bytes):
    def apply():
        resource.setrlimit(resource.RLIMIT_FSIZE, (limit_bytes, limit_bytes))
    return apply


def address_space_limit():
    # A reader that slurps /dev/zero must not take the machine with it.
    resource.setrlimit(resource.RLIMIT_AS, (3 << 30, 3 << 30))


SHARED = {}

# The cases the sanitizer stage runs (a run of the program is ten times slower there).
SANITIZED_CASES = {"test_spec_that_is_a_fifo_with_no_writer_does_not_hang", "test_record_over_the_file_size_limit",
                   "test_coordinates_and_times_at_the_ends_of_a_double", "test_build_out_onto_a_data_file",
                   "test_a_regular_file_as_a_hidraw_device_is_not_written"}


def setUpModule():
    """One trial (its record, trace and teacher's recording) and one saved session, shared by every case."""
    if not CLI or not Path(CLI).exists():
        raise unittest.SkipTest("CALLIGRAPHY_CLI is not set to the built program")
    shared = Path(tempfile.mkdtemp(prefix="r10a-shared-"))
    SHARED["dir"] = shared
    made = run(["trial", SHI, "--json", "r.json", "--csv", "t.csv", "--record", "teacher.json"], shared)
    assert made.returncode == 0, made.stderr
    protocol = {"name": "p10a", "conditions": [{"name": "h", "mode": "haptic"}],
                "test": {"characters": [SHI], "conditions": ["h"], "repetitions": 1},
                "trial": {"max_duration_s": 20}}
    (shared / "p.json").write_text(json.dumps(protocol))
    made = run(["session", "run", "p.json", "--subject", "S01", "--out", "study"], shared)
    assert made.returncode == 0, made.stderr
    SHARED["h5"] = next((shared / "study").rglob("*.trace.h5"))
    SHARED["saved_record"] = next((shared / "study").rglob("trials/*.json"))


def tearDownModule():
    if "dir" in SHARED:
        shutil.rmtree(SHARED["dir"], ignore_errors=True)


class Base(OneErrorLine, unittest.TestCase):
    def setUp(self):
        if SANITIZED and self._testMethodName not in SANITIZED_CASES:
            self.skipTest("a small subset under the sanitizers")
        self.shared = SHARED["dir"]
        self.h5 = SHARED["h5"]
        self.saved_record = SHARED["saved_record"]
        self.dir = Path(tempfile.mkdtemp(prefix="r10a-"))
        self.addCleanup(shutil.rmtree, self.dir, True)

    def copy(self, name, as_name=None):
        target = self.dir / (as_name or name)
        shutil.copyfile(self.shared / name, target)
        return target

    def record(self):
        return json.loads((self.shared / "r.json").read_text())

    def assert_listing(self, folder, names):
        self.assertEqual(sorted(p.name for p in Path(folder).iterdir()), sorted(names))


class TrialSpecRecords(Base):
    """`trial --spec RECORD`: the record forged, made a FIFO or a device, or given beside options it excludes."""

    def test_spec_beside_other_options_and_as_an_output(self):
        self.copy("r.json")
        for extra in (["--record", "x.json"], ["--seed", "3"], ["--rate", "500"], ["--guidance", "off"]):
            with self.subTest(extra=extra):
                result = run(["trial", "--spec", "r.json", *extra], self.dir)
                self.assert_one_error(result, 2, extra[0])
        self.assert_listing(self.dir, ["r.json"])
        record = self.copy("r.json")
        before = record.read_bytes()
        os.link(record, self.dir / "again.json")
        result = run(["trial", "--spec", "r.json", "--json", "again.json"], self.dir)
        self.assert_one_error(result, 2, "--spec", "--json")
        self.assertEqual(record.read_bytes(), before)
        self.assert_listing(self.dir, ["r.json", "again.json"])

    def test_spec_that_is_a_fifo_with_no_writer_does_not_hang(self):
        os.mkfifo(self.dir / "r.json")
        started = time.monotonic()
        result = run(["trial", "--spec", "r.json", "--json", "out.json"], self.dir, timeout=HANG_S)
        self.assert_one_error(result, (1, 2), "r.json")
        self.assertLess(time.monotonic() - started, HANG_S)
        self.assertFalse((self.dir / "out.json").exists())

    @heavy
    def test_spec_that_is_an_endless_device(self):
        result = run(["trial", "--spec", "/dev/zero", "--check"], self.dir, timeout=HANG_S,
                     preexec_fn=address_space_limit)
        self.assert_one_error(result, (1, 2), "/dev/zero")

    def test_numbers_at_the_ends_of_their_kinds_in_a_record(self):
        record = self.record()
        record["specification"]["trial"]["seed"] = 18446744073709551615
        (self.dir / "top.json").write_text(json.dumps(record))
        result = run(["trial", "--spec", "top.json", "--check"], self.dir)
        self.assertEqual(result.returncode, 0, result.stderr)
        text = (self.dir / "top.json").read_text().replace("18446744073709551615", "18446744073709551616")
        (self.dir / "past.json").write_text(text)
        result = run(["trial", "--spec", "past.json", "--check"], self.dir)
        self.assert_one_error(result, 2, "past.json", "/specification/trial/seed")
        text = (self.shared / "r.json").read_text()
        self.assertEqual(text.count('"max_duration_s": 300.0'), 1)
        (self.dir / "big.json").write_text(text.replace('"max_duration_s": 300.0', '"max_duration_s": 1e400'))
        result = run(["trial", "--spec", "big.json", "--json", "out.json"], self.dir)
        self.assert_one_error(result, (1, 2), "big.json", "max_duration_s")
        self.assertFalse((self.dir / "out.json").exists())

    def test_ticks_beyond_ten_million_in_a_record_and_in_options(self):
        record = self.record()
        record["specification"]["trial"]["rate_hz"] = 100000.0
        record["specification"]["trial"]["max_duration_s"] = 86400.0
        (self.dir / "long.json").write_text(json.dumps(record))
        result = run(["trial", "--spec", "long.json", "--check"], self.dir)
        line = self.assert_one_error(result, 2, "long.json", "/specification/trial")
        self.assertTrue("max_duration_s" in line or "rate_hz" in line, line)
        result = run(["trial", SHI, "--rate", "100000", "--max-duration", "101", "--check"], self.dir)
        line = self.assert_one_error(result, 2)
        self.assertTrue("--max-duration" in line or "--rate" in line, line)

    def test_a_layout_the_scene_cannot_take(self):
        # In the schema's range, a layout must run: a zero start radius, spacing or size, and a paper 1e308 m
        # up, are refused by --check naming the pointer (exit 2), as the run would refuse them.
        for field, value in (("start_radius_m", 0.0), ("spacing_m", 0.0), ("character_size_m", 0.0),
                             ("paper_z_m", 1e308), ("centre_m", [1e308, 0.0])):
            with self.subTest(field=field):
                record = self.record()
                record["specification"]["scene"]["layout"][field] = value
                (self.dir / "layout.json").write_text(json.dumps(record))
                for extra in (["--check"], ["--json", "out.json"]):
                    result = run(["trial", "--spec", "layout.json", *extra], self.dir)
                    self.assert_one_error(result, 2, "layout.json", f"/specification/scene/layout/{field}")
        self.assert_listing(self.dir, ["layout.json"])

    def test_characters_empty_and_past_the_scene_limit(self):
        record = self.record()
        record["specification"]["trial"]["characters"] = ""
        (self.dir / "empty.json").write_text(json.dumps(record))
        result = run(["trial", "--spec", "empty.json"], self.dir)
        self.assert_one_error(result, 2, "empty.json", "/specification/trial", "characters")
        record["specification"]["trial"]["characters"] = SHI * 1001
        (self.dir / "many.json").write_text(json.dumps(record))
        started = time.monotonic()
        result = run(["trial", "--spec", "many.json", "--json", "out.json"], self.dir)
        line = self.assert_one_error(result, (1, 2), "many.json")
        self.assertTrue("1,000" in line or "1000" in line, line)
        self.assertLess(time.monotonic() - started, 10)
        self.assertFalse((self.dir / "out.json").exists())


class TrialOptions(Base):
    """`trial CHARS` with option values at and past their ranges, and options that cannot go together."""

    def test_writer_param_and_max_duration_spellings(self):
        for value in ("bias_offset_m=nan", "bias_offset_m=inf", "bias_offset_m=1e308", "bias_offset_m=",
                      "bias_offset_m", "=0.001", "bias_offset_m=0.001=2", "bias_offset_m= 0.001"):
            with self.subTest(value=value):
                result = run(["trial", SHI, "--writer-param", value, "--json", "out.json"], self.dir)
                line = self.assert_one_error(result, 2)
                self.assertTrue("--writer-param" in line or "bias_offset_m" in line, line)
        self.assert_listing(self.dir, [])
        for value in ("-0", "0", "1e308", "86400.001", "", "5s"):
            with self.subTest(value=value):
                result = run(["trial", SHI, "--max-duration", value, "--check"], self.dir)
                self.assert_one_error(result, 2, "--max-duration")
        result = run(["trial", SHI, "--max-duration", "86400", "--rate", "100", "--check"], self.dir)
        self.assertEqual(result.returncode, 0, result.stderr)

    def test_options_that_cannot_go_together(self):
        cases = [
            (["--watchdog-ms", "10"], "--watchdog-ms"),                     # lock-step on the simulated device
            (["--guidance", "off", "--guidance-stiffness", "300"], "--guidance-stiffness"),
            (["--guidance-gain", "0.5"], "--guidance-gain"),                # fixed mode
            (["--guidance", "off", "--guidance-mode", "fading"], "--guidance-mode"),
            (["--writer", "person"], "--writer"),                            # a person cannot hold 'simulated'
            (["--guidance-mode", "replay"], "--teacher"),                    # replay needs its teacher
        ]
        for extra, needle in cases:
            with self.subTest(extra=extra):
                result = run(["trial", SHI, *extra, "--json", "out.json"], self.dir)
                self.assert_one_error(result, 2, needle)
        self.assert_listing(self.dir, [])

class TrialTeachers(Base):
    """A replay's `--teacher`: a trial record in its place, a forged recording, a FIFO."""

    def test_a_trial_record_and_a_fifo_as_teacher(self):
        self.copy("r.json")
        result = run(["trial", SHI, "--guidance-mode", "replay", "--teacher", "r.json", "--json", "out.json"],
                     self.dir)
        self.assert_one_error(result, (1, 2), "r.json")
        self.assertFalse((self.dir / "out.json").exists())
        os.mkfifo(self.dir / "teacher.json")
        result = run(["trial", SHI, "--guidance-mode", "replay", "--teacher", "teacher.json"], self.dir,
                     timeout=HANG_S)
        self.assert_one_error(result, (1, 2), "teacher.json")

    def test_forged_teacher_recordings(self):
        teacher = json.loads((self.shared / "teacher.json").read_text())
        short = json.loads(json.dumps(teacher))
        short["samples"]["x_m"] = short["samples"]["x_m"][:-5]
        backwards = json.loads(json.dumps(teacher))
        backwards["samples"]["t_s"] = list(reversed(backwards["samples"]["t_s"]))
        empty = json.loads(json.dumps(teacher))
        empty["samples"] = {key: [] for key in empty["samples"]}
        for name, forged in (("short.json", short), ("backwards.json", backwards), ("empty.json", empty)):
            with self.subTest(name=name):
                (self.dir / name).write_text(json.dumps(forged))
                result = run(["trial", SHI, "--guidance-mode", "replay", "--teacher", name,
                              "--json", "out.json"], self.dir)
                self.assert_one_error(result, (1, 2), name)
                self.assertFalse((self.dir / "out.json").exists())

    def replay_record(self):
        self.copy("teacher.json")
        made = run(["trial", SHI, "--guidance-mode", "replay", "--teacher", "teacher.json", "--json", "rep.json"],
                   self.dir)
        self.assertEqual(made.returncode, 0, made.stderr)
        record = json.loads((self.dir / "rep.json").read_text())
        self.assertEqual(len(record["specification"]["teacher_sha256"]), 64)
        return record

    def test_a_replay_record_that_drops_its_teacher_binding(self):
        # A record naming its teacher's file without the SHA-256 re-runs on any file of that name, which the
        # binding exists to prevent (docs/cli.md, "Re-running a trial").
        dropped = self.replay_record()
        dropped["specification"]["teacher_sha256"] = ""
        (self.dir / "dropped.json").write_text(json.dumps(dropped))
        for extra in (["--check"], ["--json", "out.json"]):
            result = run(["trial", "--spec", "dropped.json", *extra], self.dir)
            self.assert_one_error(result, 2, "dropped.json", "/specification/teacher_sha256")

    def test_a_replay_record_whose_teacher_moved(self):
        record = self.replay_record()
        # The teacher renamed to the record itself: another recording, named with both SHA-256.
        moved = json.loads(json.dumps(record))
        moved["specification"]["trial"]["teacher"] = "rep.json"
        (self.dir / "moved.json").write_text(json.dumps(moved))
        result = run(["trial", "--spec", "moved.json", "--json", "out.json"], self.dir)
        self.assert_one_error(result, 1, "rep.json", record["specification"]["teacher_sha256"])
        # A teacher given to a record that is no replay.
        result = run(["trial", "--spec", "rep.json", "--teacher", "teacher.json", "--json", "out.json"], self.dir)
        self.assertEqual(result.returncode, 0, result.stderr)
        self.copy("r.json")
        result = run(["trial", "--spec", "r.json", "--teacher", "teacher.json", "--json", "out2.json"], self.dir)
        self.assert_one_error(result, 2, "--teacher")
        self.assertFalse((self.dir / "out2.json").exists())

class TrialOutputs(Base):
    """Where `trial` writes: a refused `--record`, a closed standard output, a file size limit, folders that
    are missing, immutable or reached through a dangling link, names with control characters."""

    def test_a_refused_record_keeps_the_earlier_teacher_and_writes_the_rest(self):
        teacher = self.copy("teacher.json")
        before = teacher.read_bytes()
        result = run(["trial", SHI, "--max-duration", "0.3", "--record", "teacher.json", "--json", "out.json"],
                     self.dir)
        self.assertEqual(result.returncode, 1, result.stderr)
        self.assertIn("teacher.json", result.stderr.decode())
        self.assertEqual(teacher.read_bytes(), before)
        self.assertEqual(strict_json((self.dir / "out.json").read_text())["end_reason"], "time_limit")
        self.assert_listing(self.dir, ["teacher.json", "out.json"])

    def test_closed_standard_output_still_writes_the_files(self):
        process = subprocess.Popen([CLI, "trial", SHI, "--csv", "-", "--json", "out.json"], cwd=self.dir,
                                   stdout=subprocess.PIPE, stderr=subprocess.PIPE, env=ENV)
        process.stdout.read(10)
        process.stdout.close()
        _, err = process.communicate(timeout=TIMEOUT_S)
        self.assertEqual(process.returncode, 1, err)
        self.assertEqual(len([line for line in err.decode().splitlines() if line.strip()]), 1, err)
        self.assertEqual(strict_json((self.dir / "out.json").read_text())["end_reason"], "completed")
        self.assert_listing(self.dir, ["out.json"])

    def test_record_over_the_file_size_limit(self):
        teacher = self.copy("teacher.json")
        before = teacher.read_bytes()
        result = run(["trial", SHI, "--seed", "1", "--record", "teacher.json"], self.dir,
                     preexec_fn=file_size_limit(64 * 1024))
        self.assertEqual(result.returncode, 1, result.stderr)
        errors = [line for line in error_lines(result) if "error" in line]
        self.assertEqual(len(errors), 1, error_lines(result))
        self.assertIn("teacher.json", errors[0])
        self.assertEqual(teacher.read_bytes(), before)
        self.assert_listing(self.dir, ["teacher.json"])

    def test_an_output_in_an_immutable_folder(self):
        locked = self.dir / "locked"
        locked.mkdir()
        if subprocess.run(["chattr", "+i", str(locked)], stderr=subprocess.DEVNULL).returncode != 0:
            self.skipTest("chattr +i is not permitted here")
        try:
            result = run(["trial", SHI, "--csv", "ok.csv", "--json", "locked/x.json"], self.dir)
            self.assert_one_error(result, 1, "--json", "locked")
        finally:
            subprocess.run(["chattr", "-i", str(locked)])
        self.assert_listing(self.dir, ["locked"])
        self.assert_listing(locked, [])

    def test_links_as_outputs_relative_chains_and_loops(self):
        (self.dir / "out").mkdir()
        (self.dir / "real").mkdir()
        os.symlink("../real/x.svg", self.dir / "out" / "link.svg")  # relative to the link's own folder
        result = run(["model", SHI, "--svg", "out/link.svg"], self.dir)
        self.assertEqual(result.returncode, 0, result.stderr)
        self.assertTrue((self.dir / "out" / "link.svg").is_symlink())
        self.assertIn("</svg>", (self.dir / "real" / "x.svg").read_text())
        self.assert_listing(self.dir / "out", ["link.svg"])
        os.symlink("self.svg", self.dir / "self.svg")
        for index in range(1, 42):
            os.symlink(f"c{index + 1}", self.dir / f"c{index}")
        for name in ("self.svg", "c1"):
            with self.subTest(output=name):
                result = run(["model", SHI, "--svg", name], self.dir, timeout=HANG_S)
                self.assert_one_error(result, (1, 2), "--svg", name)
        self.assertFalse((self.dir / "c42").exists())

    def test_an_output_through_a_dangling_folder_link_and_a_bad_name(self):
        os.symlink("nowhere", self.dir / "gone")
        result = run(["trial", SHI, "--csv", "ok.csv", "--json", "gone/x.json"], self.dir)
        self.assert_one_error(result, 1, "--json")
        self.assertFalse((self.dir / "nowhere").exists())
        name = "no\x1b[2Jdir\n/x.json"
        result = run(["trial", SHI, "--svg", name], self.dir)
        line = self.assert_one_error(result, 1, "--svg")
        self.assertNotIn("\x1b", result.stderr.decode())
        self.assertIn("\\n", line)
        result = run(["trial", SHI, "--json", ""], self.dir)
        self.assert_one_error(result, 2, "--json")
        self.assert_listing(self.dir, ["gone"])


class TraceCommand(Base):
    """`trace`: its input as `-`, a loop of links; its output a FIFO with a reader, a file whose mode is kept;
    and the promise that its CSV is that of `trial --csv` of the same trial."""

    def test_dash_and_a_link_loop_as_input(self):
        reader, writer = os.pipe()
        try:
            result = run(["trace", "-"], self.dir, stdin=reader, timeout=HANG_S)
        finally:
            os.close(reader)
            os.close(writer)
        self.assert_one_error(result, (1, 2), "-")
        os.symlink("b.trace.h5", self.dir / "a.trace.h5")
        os.symlink("a.trace.h5", self.dir / "b.trace.h5")
        result = run(["trace", "a.trace.h5", "--csv", "out.csv"], self.dir)
        self.assert_one_error(result, 1, "a.trace.h5")
        self.assert_listing(self.dir, ["a.trace.h5", "b.trace.h5"])

    def test_output_into_a_fifo_with_a_reader(self):
        expected = run(["trace", self.h5], self.dir)
        self.assertEqual(expected.returncode, 0, expected.stderr)
        os.mkfifo(self.dir / "pipe")
        got = {}

        def read():
            with open(self.dir / "pipe", "rb") as handle:
                got["bytes"] = handle.read()
        thread = threading.Thread(target=read)
        thread.start()
        result = run(["trace", self.h5, "--csv", "pipe"], self.dir)
        thread.join(TIMEOUT_S)
        self.assertEqual(result.returncode, 0, result.stderr)
        self.assertEqual(got.get("bytes"), expected.stdout)
        self.assert_listing(self.dir, ["pipe"])

    def test_a_replaced_output_keeps_its_mode_and_the_csv_is_the_trials(self):
        out = self.dir / "out.csv"
        out.write_text("old\n")
        os.chmod(out, 0o600)
        result = run(["trace", self.h5, "--csv", "out.csv"], self.dir)
        self.assertEqual(result.returncode, 0, result.stderr)
        self.assertEqual(out.stat().st_mode & 0o7777, 0o600)
        again = run(["trial", "--spec", self.saved_record, "--csv", "again.csv"], self.dir)
        self.assertEqual(again.returncode, 0, again.stderr)
        self.assertEqual((self.dir / "again.csv").read_bytes(), out.read_bytes())
        self.assert_listing(self.dir, ["out.csv", "again.csv"])


class ScoreCommand(Base):
    """`score`: numbers at the ends of a double, pen values that are neither 0 nor 1, quoted commas, rows of
    characters with `--units data`, a FIFO."""

    HEADER = "t,x,y,pen\n"

    def test_coordinates_and_times_at_the_ends_of_a_double(self):
        rows = ["-1e308,0,0,0", "0,0,0,1", "0.001,1e308,0,1", "0.002,-1e308,1e308,1", "1e308,0,0,0"]
        (self.dir / "far.csv").write_text(self.HEADER + "\n".join(rows) + "\n")
        result = run(["score", "far.csv", "--character", SHI, "--json", "-"], self.dir)
        self.assertIn(result.returncode, (0, 1), result.stderr)
        if result.returncode == 0:
            strict_json(result.stdout.decode())
        else:
            self.assert_one_error(result, 1, "far.csv")

    def test_rows_refused_at_their_line(self):
        for value in ("2", "0.5", "-1", "", "yes"):
            with self.subTest(value=value):
                (self.dir / "pen.csv").write_text(self.HEADER + "0,0,0,0\n0.001,0,0," + value + "\n")
                result = run(["score", "pen.csv", "--character", SHI, "--json", "out.json"], self.dir)
                self.assert_one_error(result, 1, "pen.csv:3")
                self.assertFalse((self.dir / "out.json").exists())
        (self.dir / "q.csv").write_text('"t","x","y","z"\n"0","0","0","0.01"\n"0,001","0","0","0"\n')
        result = run(["score", "q.csv", "--character", SHI], self.dir)
        self.assert_one_error(result, 1, "q.csv:3")

    def test_units_data_with_a_row_of_characters_and_too_many_characters(self):
        self.copy("t.csv")
        result = run(["score", "t.csv", "--character", SHI + "人", "--units", "data"], self.dir)
        line = self.assert_one_error(result, 2)
        self.assertTrue("--units" in line or "--character" in line, line)
        started = time.monotonic()
        result = run(["score", "t.csv", "--character", SHI * 1001, "--json", "out.json"], self.dir)
        line = self.assert_one_error(result, (1, 2))
        self.assertTrue("1,000" in line or "1000" in line, line)
        self.assertLess(time.monotonic() - started, 10)
        self.assert_listing(self.dir, ["t.csv"])

    def test_a_trace_fifo_with_no_writer(self):
        os.mkfifo(self.dir / "t.csv")
        result = run(["score", "t.csv", "--character", SHI], self.dir, timeout=HANG_S)
        self.assert_one_error(result, 1, "t.csv")


class ModelStrokesCharacters(Base):
    """`model`, `strokes` and `characters`: `-` with a `--json` flag, one character, a broken pipe, stores
    that are no store."""

    def test_dash_beside_a_json_flag_and_one_character(self):
        result = run(["model", SHI, "--json", "--svg", "-"], self.dir)
        self.assert_one_error(result, 2, "--svg")
        result = run(["strokes", "--json", "--markdown", "-"], self.dir)
        self.assert_one_error(result, 2, "--markdown")
        for chars in (SHI + "人", "", " "):
            with self.subTest(chars=chars):
                result = run(["model", chars], self.dir)
                self.assert_one_error(result, 2)

    def test_standard_output_alone_and_closed(self):
        result = run(["model", SHI, "--svg", "-"], self.dir)
        self.assertEqual(result.returncode, 0, result.stderr)
        text = result.stdout.decode().strip()
        self.assertTrue(text.startswith("<?xml") or text.startswith("<svg"), text[:80])
        self.assertTrue(text.endswith("</svg>"), text[-80:])
        for args in (["characters", "--strokes", "2"], ["strokes", "--markdown", "-"]):
            with self.subTest(args=args):
                process = subprocess.Popen([CLI, *args], cwd=self.dir, stdout=subprocess.PIPE,
                                           stderr=subprocess.PIPE, env=ENV)
                process.stdout.close()  # before it writes: every write meets a closed pipe
                _, err = process.communicate(timeout=TIMEOUT_S)
                self.assertEqual(process.returncode, 1, err)
                self.assertEqual(len([line for line in err.decode().splitlines() if line.strip()]), 1, err)

    def test_strokes_markdown_keeps_a_files_mode_and_its_link(self):
        (self.dir / "table.md").write_text("old\n")
        os.chmod(self.dir / "table.md", 0o640)
        os.symlink("table.md", self.dir / "link.md")
        result = run(["strokes", "--markdown", "link.md"], self.dir)
        self.assertEqual(result.returncode, 0, result.stderr)
        self.assertTrue((self.dir / "link.md").is_symlink())
        self.assertIn("HZG", (self.dir / "table.md").read_text())
        self.assertEqual((self.dir / "table.md").stat().st_mode & 0o7777, 0o640)
        self.assert_listing(self.dir, ["table.md", "link.md"])

    @heavy
    def test_stores_that_are_no_store(self):
        os.mkfifo(self.dir / "fifo.clg")
        (self.dir / "text.clg").write_text("not a store\n")
        (self.dir / "empty.clg").write_bytes(b"")
        for name in ("fifo.clg", "text.clg", "empty.clg", "/dev/zero"):
            with self.subTest(store=name):
                result = run(["characters", "--store", name, "--strokes", "2"], self.dir, timeout=HANG_S,
                             preexec_fn=address_space_limit)
                self.assert_one_error(result, (1, 2), name)
                result = run(["model", SHI, "--store", name], self.dir, timeout=HANG_S,
                             preexec_fn=address_space_limit)
                self.assert_one_error(result, (1, 2), name)


class CorpusCommands(Base):
    """`corpus build|stats|fidelity|validate`: an output on an input, a cut store, a file size limit, a kill,
    numbers past their ranges."""

    def data(self, names=("十", "人", "大", "木", "口")):
        folder = self.dir / "data"
        folder.mkdir()
        for name in names:
            shutil.copyfile(DATA / f"{name}.json", folder / f"{name}.json")
        return folder

    def test_build_out_onto_a_data_file(self):
        folder = self.data()
        before = (folder / "十.json").read_bytes()
        os.link(folder / "十.json", self.dir / "alias.clg")
        for out in ("data/十.json", "alias.clg"):
            with self.subTest(out=out):
                result = run(["corpus", "build", "--data", "data", "--out", out], self.dir)
                self.assert_one_error(result, 2, "--out")
                self.assertEqual((folder / "十.json").read_bytes(), before)
        self.assert_listing(folder, ["十.json", "人.json", "大.json", "木.json", "口.json"])

    def test_cut_and_flipped_stores(self):
        self.data()
        result = run(["corpus", "build", "--data", "data", "--out", "s.clg"], self.dir)
        self.assertEqual(result.returncode, 0, result.stderr)
        whole = (self.dir / "s.clg").read_bytes()
        (self.dir / "cut.clg").write_bytes(whole[: len(whole) // 2])
        flipped = bytearray(whole)
        flipped[len(whole) * 3 // 4] ^= 0x5A
        (self.dir / "flipped.clg").write_bytes(bytes(flipped))
        for name in ("cut.clg", "flipped.clg"):
            with self.subTest(store=name):
                result = run(["corpus", "stats", name], self.dir)
                self.assertEqual(result.returncode, 1, result.stderr)
                self.assertIn(name + ":", (result.stdout + result.stderr).decode())
                self.assertNotIn("terminate called", result.stderr.decode())
                result = run(["characters", "--store", name], self.dir)
                self.assertIn(result.returncode, (0, 1), result.stderr)
                self.assertNotIn(b"terminate called", result.stderr)

    def test_build_under_a_file_size_limit_and_killed(self):
        self.data()
        (self.dir / "s.clg").write_bytes(b"earlier store\n")
        result = run(["corpus", "build", "--data", "data", "--out", "s.clg"], self.dir,
                     preexec_fn=file_size_limit(512))
        self.assertEqual(result.returncode, 1, result.stderr)
        errors = [line for line in error_lines(result) if "error" in line]
        self.assertEqual(len(errors), 1, error_lines(result))
        self.assertIn("s.clg", errors[0])
        self.assertEqual((self.dir / "s.clg").read_bytes(), b"earlier store\n")
        self.assert_listing(self.dir, ["data", "s.clg"])
        process = subprocess.Popen([CLI, "corpus", "build", "--data", "data", "--out", "s.clg"], cwd=self.dir,
                                   stdout=subprocess.PIPE, stderr=subprocess.PIPE, env=ENV)
        time.sleep(0.05)
        process.send_signal(signal.SIGTERM)
        process.communicate(timeout=TIMEOUT_S)
        self.assert_listing(self.dir, ["data", "s.clg"])
        if process.returncode != 0 and (self.dir / "s.clg").read_bytes() != b"earlier store\n":
            # The signal came after the store was renamed into place (the build is quick): the run ends by the
            # signal with the new store whole, never a part of it.
            self.assertEqual(run(["characters", "--store", "s.clg"], self.dir).returncode, 0)

    def test_numbers_past_their_ranges(self):
        self.data(("十",))
        cases = [["build", "--out", "s.clg", "--tolerance", v] for v in ("0", "-0", "nan", "1e999", "")]
        cases += [["build", "--out", "s.clg", "--steps", v] for v in ("3", "0", "2.0")]
        cases += [["build", "--out", "s.clg", "--threads", v] for v in ("0", "257", "0x2")]
        cases += [["fidelity", "--tolerances", v] for v in ("2,,5", "2,-1", "", "2;5", "inf")]
        for args in cases:
            with self.subTest(args=args):
                result = run(["corpus", args[0], "--data", "data", *args[1:]], self.dir)
                self.assert_one_error(result, 2, args[-2])
        self.assert_listing(self.dir, ["data"])

    def test_validate_with_an_empty_and_a_fifo_cnchar(self):
        self.data(("十",))
        (self.dir / "empty.js").write_bytes(b"")
        os.mkfifo(self.dir / "fifo.js")
        for name in ("empty.js", "fifo.js"):
            with self.subTest(cnchar=name):
                result = run(["corpus", "validate", "--data", "data", "--cnchar", name, "--markdown", "v.md"],
                             self.dir, timeout=HANG_S)
                self.assert_one_error(result, 1, name)
        self.assert_listing(self.dir, ["data", "empty.js", "fifo.js"])


class DevicesCommand(Base):
    """`devices` and devices named: a driver library that is garbage, a regular file as a hidraw device, a flag
    given a value."""

    def test_a_garbage_driver_library_and_a_flag_given_false(self):
        garbage = self.dir / "libHD.so"
        garbage.write_bytes(b"\x7fELF" + os.urandom(4000))
        env = dict(ENV, CALLIGRAPHY_LIBHD=str(garbage))
        result = run(["devices", "--json"], self.dir, env=env)
        self.assertEqual(result.returncode, 0, result.stderr)
        listing = strict_json(result.stdout.decode())
        self.assertTrue(any(str(garbage) in note for note in listing["notes"]), listing["notes"])
        result = run(["trial", SHI, "--device", "openhaptics", "--json", "out.json"], self.dir, env=env)
        self.assert_one_error(result, 1, str(garbage))
        self.assert_listing(self.dir, ["libHD.so"])
        result = run(["devices", "--json=false"], self.dir)
        self.assert_one_error(result, 2, "--json")
        result = run(["devices", "--json=true"], self.dir)
        self.assertEqual(result.returncode, 0, result.stderr)
        strict_json(result.stdout.decode())
        result = run(["devices", "simulated"], self.dir)
        self.assert_one_error(result, 2)

    def test_a_regular_file_as_a_hidraw_device_is_not_written(self):
        plain = self.dir / "plain.bin"
        plain.write_bytes(b"keep me\n")
        for device in (f"phantom-hid:{plain}", "phantom-usb:1-999", "phantom-usb:zz", "phantom-hid:"):
            with self.subTest(device=device):
                result = run(["trial", SHI, "--device", device, "--json", "out.json"], self.dir, timeout=HANG_S)
                self.assert_one_error(result, (1, 2))
        self.assertEqual(plain.read_bytes(), b"keep me\n")
        self.assert_listing(self.dir, ["plain.bin"])

class CurriculumSchemaBenchTrain(Base):
    """`curriculum`'s inputs, `schema`'s names, `bench`'s and `train`'s options."""

    def test_curriculum_inputs(self):
        study = self.shared / "study"
        for args in (["--from", ""], ["--from", b"\xff\xfe"], ["--from", "人", "--count", "0"],
                     ["--from", "人", "--count", "1001"], ["--from", "人", "--count", "1e2"]):
            with self.subTest(args=args):
                result = run(["curriculum", study, "--subject", "S01", *args], self.dir)
                self.assert_one_error(result, 2)
        result = run(["curriculum", study, "--subject", "S99", "--from", "人"], self.dir)
        self.assert_one_error(result, 2, "S99")
        (self.dir / "empty").mkdir()
        result = run(["curriculum", "empty", "--subject", "S01", "--from", "人"], self.dir)
        self.assert_one_error(result, (1, 2), "empty")
        (self.dir / "file").write_text("x")
        result = run(["curriculum", "file", "--subject", "S01", "--from", "人"], self.dir)
        self.assert_one_error(result, (1, 2), "file")
        result = run(["curriculum", study, "--subject", "S01", "--from", SHI + "人大", "--json"], self.dir)
        self.assertEqual(result.returncode, 0, result.stderr)
        proposed = [item["character"] for item in strict_json(result.stdout.decode())]
        self.assertNotIn(SHI, proposed)  # it has written it

    def test_schema_names_and_bench_options_past_their_ranges(self):
        for args in (["schema", "nope"], ["schema", "record", "--markdown=1"], ["schema", "record", "extra"],
                     ["schema", "Record"]):
            with self.subTest(args=args):
                result = run(args, self.dir)
                self.assert_one_error(result, 2)
        cases = [["loop", "--priority", "0", "--realtime", "enforce"], ["loop", "--rate", "10001"],
                 ["loop", "--cpu", "1024"], ["loop", "--cpu", "-2"], ["loop", "--seconds", "0"],
                 ["loop", "--seconds", "nan"], ["loop", "--priority", "100"],
                 ["loop", "--watchdog-periods", "1000001"], ["nearest", "--queries", "0"],
                 ["nearest", "--queries", "100000001"], ["jumps", "--seeds", "0"], ["tick", "--passes", "1001"],
                 ["tick", "--rate", "99"], ["acceptance", "--form-tolerance-mm", "60.001"],
                 ["acceptance", "--half", "nope"], ["acceptance", "--characters", "0"]]
        for args in cases:
            with self.subTest(args=args):
                started = time.monotonic()
                result = run(["bench", *args], self.dir, timeout=20)
                self.assert_one_error(result, 2)
                self.assertLess(time.monotonic() - started, 5)

    def test_bench_markdown_keeps_the_rest_of_a_document(self):
        # Another text, and a section begun but never ended (cut by hand): the rest of the document is kept.
        texts = {"notes.md": "# My notes\n\nKeep this paragraph.\n",
                 "cut.md": "# Notes\n<!-- BEGIN generated by `calligraphy bench jumps` -->\nold\n\nKeep this tail.\n"}
        for name, text in texts.items():
            with self.subTest(document=name):
                document = self.dir / name
                document.write_text(text)
                result = run(["bench", "jumps", "--seeds", "1", "--chars", SHI, "--markdown", name], self.dir)
                if result.returncode == 0:
                    self.assertIn(text.splitlines()[-1], document.read_text())
                    self.assertIn("| exact |", document.read_text())
                else:
                    self.assert_one_error(result, (1, 2), name)
                    self.assertEqual(document.read_text(), text)
        self.assert_listing(self.dir, list(texts))

    def test_train_bad_options_without_a_display(self):
        kinds = strict_json(run(["devices", "--json"], self.dir).stdout.decode())["kinds"]
        trainer = any("train" in kind["commands"] for kind in kinds)
        (self.dir / "file").write_text("x")
        cases = [["--window", "799x480"], ["--window", "1280x"], ["--window", "0x0"],
                 ["--window", "99999999999999999999x800"], ["--subject", "../x"], ["--subject", "a" * 65],
                 ["--exit-after", "0"], ["--exit-after", "nan"], ["--exit-after", "86401"],
                 ["--guidance-gain", "1.5"], ["--seed", "-1"]]
        for args in cases:
            with self.subTest(args=args):
                result = run(["train", SHI, *args], self.dir, timeout=20)
                # without the window: exit 1 saying so, or 2 for an option it checks first
                self.assert_one_error(result, 2 if trainer else (1, 2))
        result = run(["train", SHI, "--session", "file"], self.dir, timeout=20)
        self.assert_one_error(result, 1)
        self.assert_listing(self.dir, ["file"])


@needs_python
class PythonSurfaces(Base):
    """The Python functions of the same surfaces: readers given FIFOs, the record checker at every field's
    bounds, scoring pen values, trial bounds, teachers written and read."""

    def test_readers_given_a_fifo_or_values_of_another_type(self):
        os.mkfifo(self.dir / "fifo")
        script = (
            "import json, sys, calligraphy as cg\n"
            "path = sys.argv[1]\n"
            "out = {}\n"
            "for name, call in [('rerun_trial', lambda: cg.rerun_trial(path)),\n"
            "                   ('score', lambda: cg.score(path, '十')),\n"
            "                   ('from_store', lambda: cg.CharacterLibrary.from_store(path)),\n"
            "                   ('teacher', lambda: cg.TeacherRecording.load(path)),\n"
            "                   ('check', lambda: cg.check_trial_record(path))]:\n"
            "    try:\n"
            "        call(); out[name] = 'returned'\n"
            "    except Exception as error:\n"
            "        out[name] = [type(error).__name__, str(error)]\n"
            "print(json.dumps(out))\n")
        result = subprocess.run([sys.executable, "-c", script, str(self.dir / "fifo")], stdout=subprocess.PIPE,
                                stderr=subprocess.PIPE, timeout=HANG_S * 2, env=os.environ.copy())
        self.assertEqual(result.returncode, 0, result.stderr)
        out = json.loads(result.stdout)
        for name, what in out.items():
            with self.subTest(function=name):
                self.assertIsInstance(what, list, what)
                self.assertNotEqual(what[0], "TypeError", what)
        record = self.record()
        for value in ("7", 1.5, -1, None, 2 ** 64, [0]):
            with self.subTest(seed=value):
                forged = json.loads(json.dumps(record))
                forged["specification"]["trial"]["seed"] = value
                with self.assertRaises((cg.DataError, TypeError)) as caught:
                    cg.rerun_trial(forged)
                self.assertIn("/specification/trial/seed", str(caught.exception))
        for value in (42, 4.5, ["r.json"]):
            with self.subTest(record=value):
                with self.assertRaises(TypeError) as caught:
                    cg.rerun_trial(value)
                self.assertIn("record", str(caught.exception))

    def test_check_trial_record_at_every_numeric_bound_of_the_schema(self):
        schema = strict_json(run(["schema", "record"], self.dir).stdout.decode())
        record = self.record()
        defs = schema["$defs"]

        def properties(ref):
            return defs[ref.split("/")[-1]]["properties"]

        # Every part but the safety chain, whose upper bounds are being settled apart.
        groups = {"trial": properties(schema["properties"]["trial"]["$ref"]),
                  "passivity": properties(schema["properties"]["passivity"]["$ref"]),
                  "force_law": properties("#/$defs/ForceLawParameters"),
                  "force_law/acceptance": properties("#/$defs/StrokeAcceptance"),
                  "force_law/nearest": properties("#/$defs/NearestPointOptions"),
                  "scene/layout": properties("#/$defs/SceneLayout"),
                  "writer": properties("#/$defs/WriterProfile")}
        tried = 0
        for group, props in groups.items():
            for field, spec in props.items():
                if spec.get("type") not in ("number", "integer"):
                    continue
                integer = spec["type"] == "integer"
                bad = []
                if "exclusiveMinimum" in spec:
                    bad.append(spec["exclusiveMinimum"])
                if "minimum" in spec:
                    low = spec["minimum"]
                    bad.append(low - 1 if integer else (low - max(abs(low) * 1e-6, 1e-9)))
                if "maximum" in spec and spec["maximum"] < 1e308:
                    high = spec["maximum"]
                    bad.append(high + 1 if integer else 1e308)
                if "exclusiveMaximum" in spec:
                    bad.append(spec["exclusiveMaximum"])
                for value in bad:
                    if integer and value > 2 ** 64 - 1:
                        continue
                    with self.subTest(field=f"{group}/{field}", value=value):
                        forged = json.loads(json.dumps(record))
                        target = forged["specification"]
                        for part in group.split("/"):
                            target = target[part]
                        target[field] = value
                        with self.assertRaises(cg.DataError) as caught:
                            cg.check_trial_record(forged)
                        self.assertIn(f"/specification/{group}/{field}", str(caught.exception))
                        tried += 1
        self.assertGreater(tried, 60)
        # What the schema takes, the layout takes: the largest box margin it allows runs.
        forged = json.loads(json.dumps(record))
        largest = properties("#/$defs/SceneLayout")["box_margin_m"]["maximum"]
        self.assertLess(largest, 1e308)  # a finite bound, not the largest double
        forged["specification"]["scene"]["layout"]["box_margin_m"] = largest
        cg.check_trial_record(forged)

    def test_simulate_trial_and_score_past_their_bounds(self):
        cases = [({"rate_hz": 99.999}, "rate_hz"), ({"rate_hz": float("nan")}, "rate_hz"),
                 ({"max_duration_s": -0.0}, "max_duration_s"), ({"max_duration_s": 1e308}, "max_duration_s"),
                 ({"hint_after_misses": 1001}, "hint_after_misses"),
                 ({"assist_after_misses": 1.5}, "assist_after_misses")]
        for kwargs, name in cases:
            with self.subTest(kwargs=kwargs):
                with self.assertRaises((cg.InvalidArgument, TypeError)) as caught:
                    cg.simulate_trial(SHI, keep_trace=False, **kwargs)
                self.assertIn(name, str(caught.exception))
        t = [0.0, 0.001, 0.002]
        for pen in ([0, 2, 0], [0, 0.5, 0], [0, -1, 0]):
            with self.subTest(pen=pen):
                with self.assertRaises((cg.InvalidArgument, cg.DataError)) as caught:
                    cg.score({"t": t, "x": [0.0] * 3, "y": [0.0] * 3, "pen": pen}, SHI)
                self.assertIn("pen", str(caught.exception))
        with self.assertRaises((cg.InvalidArgument, cg.DataError)) as caught:  # no inf or NaN in the score
            cg.score({"t": t, "x": [0.0, 1e308, 0.0], "y": [0.0] * 3, "pen": [1, 1, 1]}, SHI)
        self.assertIn("sample 1", str(caught.exception))

    def test_record_teacher_outputs(self):
        trial = cg.simulate_trial(SHI, writer="skilled")
        (self.dir / "target.json").write_text("old")
        os.chmod(self.dir / "target.json", 0o600)
        os.symlink("target.json", self.dir / "link.json")
        cg.record_teacher(trial, str(self.dir / "link.json"))
        self.assertTrue((self.dir / "link.json").is_symlink())
        self.assertEqual((self.dir / "target.json").stat().st_mode & 0o7777, 0o600)
        self.assertEqual(cg.TeacherRecording.load(str(self.dir / "target.json")).characters, SHI)
        (self.dir / "folder").mkdir()
        for target in (self.dir / "missing" / "t.json", self.dir / "folder"):
            with self.subTest(target=target):
                with self.assertRaises(Exception) as caught:
                    cg.record_teacher(trial, str(target))
                self.assertNotIsInstance(caught.exception, TypeError)
                self.assertIn(str(target), str(caught.exception))
        self.assertFalse((self.dir / "missing").exists())
        self.assert_listing(self.dir, ["target.json", "link.json", "folder"])
        self.assert_listing(self.dir / "folder", [])

    def test_a_trial_record_read_as_a_teacher_and_a_cut_store(self):
        self.copy("r.json")
        with self.assertRaises(cg.DataError) as caught:
            cg.TeacherRecording.load(str(self.dir / "r.json"))
        self.assertIn("r.json", str(caught.exception))
        (self.dir / "cut.clg").write_bytes(b"CLG\x00" + b"\x00" * 10)
        with self.assertRaises(cg.DataError) as caught:
            cg.CharacterLibrary.from_store(str(self.dir / "cut.clg"))
        self.assertIn("cut.clg", str(caught.exception))
        with self.assertRaises(Exception) as caught:
            cg.CharacterLibrary.from_hanzi_writer(str(self.dir / "r.json"))
        self.assertNotIsInstance(caught.exception, TypeError)
        self.assertIn("r.json", str(caught.exception))


if __name__ == "__main__":
    unittest.main()
