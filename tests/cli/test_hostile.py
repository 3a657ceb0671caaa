#!/usr/bin/env python3
"""The `calligraphy` program on hostile inputs and outputs, and stopped by signals (docs/cli.md), run by CTest
as `cli_hostile_tests`.

Each case runs the built program and asserts the exit status, the message (one line naming the file, folder
or character at fault) and that no earlier data was lost: an earlier output is byte for byte what it was, no
temporary file is left beside it, and a trial stopped by SIGINT or SIGTERM has every recorded tick in its
outputs. Inputs: the character files of tests/data/hostile/ and larger ones generated here (100,000-deep
nesting, 100,000-point and one-point medians, an oversized file), FIFOs and device files where files are read,
files where folders are expected, empty folders. Outputs: /dev/full, a file size limit (RLIMIT_FSIZE, which
applies to root as well).

CALLIGRAPHY_CLI names the program and CALLIGRAPHY_SOURCE_DIR the source tree. Standard library only
(unittest; pytest runs these cases as well), so that nothing has to be installed.
"""
import csv
import json
import os
import resource
import signal
import subprocess
import sys
import tempfile
import time
import unittest
from pathlib import Path

CLI = os.environ.get("CALLIGRAPHY_CLI", "")
SOURCE = Path(os.environ.get("CALLIGRAPHY_SOURCE_DIR", Path(__file__).resolve().parents[2]))
DATA = SOURCE / "data" / "hanzi-writer-data"
HOSTILE = SOURCE / "tests" / "data" / "hostile"
YONG = "永"  # U+6C38, in the embedded set
YONG_CODE = "U+6C38"
TIMEOUT_S = 120  # a hang (reading a FIFO, /dev/zero) fails the case instead of blocking CTest
SANITIZED = os.environ.get("CALLIGRAPHY_SANITIZED") == "1"  # the program runs about ten times slower there


def scratch_parent():
    """Where each case works: /dev/shm when it is a writable folder (tmpfs), else the default temporary folder.
    Nothing here depends on the file system; on a disk, removing a case's 3,000 folders took 9 s of waiting."""
    shm = Path("/dev/shm")
    return str(shm) if shm.is_dir() and os.access(shm, os.W_OK | os.X_OK) else None


class HostileTestCase(unittest.TestCase):
    def setUp(self):
        if not CLI or not Path(CLI).exists():
            self.fail(f"CALLIGRAPHY_CLI={CLI!r} is not the calligraphy program: run these tests through ctest")
        self.folder = tempfile.TemporaryDirectory(prefix="calligraphy-hostile-", dir=scratch_parent())
        self.cwd = Path(self.folder.name)

    def tearDown(self):
        self.folder.cleanup()

    def run_cli(self, *args, limit_file_bytes=None):
        def limit():
            if limit_file_bytes is not None:  # writes beyond this many bytes fail with EFBIG
                signal.signal(signal.SIGXFSZ, signal.SIG_IGN)
                resource.setrlimit(resource.RLIMIT_FSIZE, (limit_file_bytes, limit_file_bytes))

        return subprocess.run([CLI, *map(str, args)], cwd=self.cwd, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                              timeout=TIMEOUT_S, preexec_fn=limit)

    def assert_error(self, result, status, *names):
        """Exit `status`, and an error line on stderr naming each of `names`."""
        message = result.stderr.decode(errors="replace")
        self.assertEqual(result.returncode, status, message)
        errors = [line for line in message.splitlines() if ": error: " in line]
        self.assertEqual(len(errors), 1, f"not one error line: {message!r}")
        for name in names:
            self.assertIn(str(name), errors[0])
        return errors[0]

    def folder_with(self, name, files):
        """A folder `name` in the working folder holding `files` {file name: bytes}."""
        folder = self.cwd / name
        folder.mkdir()
        for file_name, content in files.items():
            (folder / file_name).write_bytes(content)
        return folder

    def earlier_files(self, *names):
        """Earlier outputs with known contents; returns {path: bytes}."""
        earlier = {}
        for name in names:
            path = self.cwd / name
            path.write_bytes(f"earlier {name}, kept unless replaced whole\n".encode())
            earlier[path] = path.read_bytes()
        return earlier

    def assert_kept(self, earlier):
        """Every earlier file is as it was, and nothing else was left beside them (no temporary)."""
        for path, content in earlier.items():
            self.assertEqual(path.read_bytes(), content, f"{path.name} was changed")
        for path in self.cwd.iterdir():
            self.assertFalse(path.name.startswith(".") or path.name.endswith(".tmp"), f"left behind: {path.name}")


class HostileCharacterFiles(HostileTestCase):
    def refuse_as_yong(self, content, *expected):
        """`content` as the character file of 永: model, trial and corpus build refuse it, naming the file and
        the character; the trial's earlier outputs and the earlier store are kept."""
        data = self.folder_with(f"data-{len(list(self.cwd.iterdir()))}", {f"{YONG}.json": content})
        names = (f"{YONG}.json", YONG_CODE, *expected)
        self.assert_error(self.run_cli("model", YONG, "--data", data), 1, *names)
        earlier = self.earlier_files("trial.json", "trace.csv", "corpus.clg")
        trial = self.run_cli("trial", YONG, "--data", data, "--json", "trial.json", "--csv", "trace.csv")
        self.assert_error(trial, 1, *names)
        build = self.run_cli("corpus", "build", "--data", data, "--out", "corpus.clg", "--threads", "1")
        self.assert_error(build, 1, data.name, "none of its 1 character files", "corpus.clg is not written",
                          *names)
        self.assert_kept(earlier)

    def test_every_file_of_the_hostile_set_is_refused(self):
        files = sorted(HOSTILE.glob("*.json"))
        self.assertGreaterEqual(len(files), 16)
        for path in files:
            with self.subTest(file=path.name):
                self.refuse_as_yong(path.read_bytes())

    def test_deep_nesting(self):
        depth = 100_000
        self.refuse_as_yong(b'{"medians": ' + b"[" * depth + b"]" * depth + b"}")
        # Under a key the loader skips: still bounded, never a stack overflow.
        self.refuse_as_yong(b'{"strokes": ' + b"[" * depth + b"]" * depth + b', "medians": [[[0, 0], [9, 9]]]}',
                            "nested deeper than")

    def test_one_point_and_100000_point_medians(self):
        self.refuse_as_yong(json.dumps({"medians": [[[500, 500]]]}).encode(), "/medians/0", "got 1")
        many = [[i % 1000, i // 1000] for i in range(100_000)]
        self.refuse_as_yong(json.dumps({"medians": [many]}).encode(), "/medians/0", "more than")

    def test_far_and_huge_coordinates(self):
        for value in ("1e17", "-1e17", "1e308", "18446744073709551616", "1e400"):
            with self.subTest(value=value):
                self.refuse_as_yong(f'{{"medians": [[[0, 0], [{value}, 5]]]}}'.encode(), "/medians/0/1/0")

    def test_oversized_file(self):
        self.refuse_as_yong(b" " * (17 << 20) + b'{"medians": []}', "bytes")


class NonRegularInputs(HostileTestCase):
    """FIFOs, devices and folders where files are read: refused unread (a FIFO would block, /dev/zero never
    ends), with one line naming the path."""

    def test_fifo_and_devices_as_character_files(self):
        data = self.cwd / "data"
        data.mkdir()
        os.mkfifo(data / f"{YONG}.json")
        for command in (["model", YONG], ["trial", YONG]):
            with self.subTest(command=command, kind="FIFO"):
                self.assert_error(self.run_cli(*command, "--data", data), 1, f"{YONG}.json", "FIFO")
        (data / f"{YONG}.json").unlink()
        for device in ("/dev/zero", "/dev/null"):
            os.symlink(device, data / f"{YONG}.json")
            with self.subTest(device=device):
                self.assert_error(self.run_cli("model", YONG, "--data", data), 1, f"{YONG}.json",
                                  "character device")
            (data / f"{YONG}.json").unlink()
        (data / f"{YONG}.json").mkdir()
        self.assert_error(self.run_cli("model", YONG, "--data", data), 1, f"{YONG}.json", "directory")

    def test_fifo_and_devices_as_input_files(self):
        os.mkfifo(self.cwd / "fifo")
        (self.cwd / "folder").mkdir()
        for path in ("fifo", "/dev/zero", "/dev/null", "folder"):
            for command in (["score", path, "--character", YONG], ["corpus", "stats", path],
                            ["model", YONG, "--store", path], ["corpus", "validate", "--cnchar", path]):
                with self.subTest(command=command):
                    self.assert_error(self.run_cli(*command), 1, path, "not a regular file")

    def test_files_and_devices_as_data_folders(self):
        (self.cwd / "file.json").write_text("{}")
        for path in ("/dev/null", "file.json"):
            for command in (["model", YONG], ["trial", YONG], ["corpus", "build", "--out", "s.clg"]):
                with self.subTest(command=command, data=path):
                    self.assert_error(self.run_cli(*command, "--data", path), 1, path, "not a folder")
        self.assertFalse((self.cwd / "s.clg").exists())


class EmptyAndUselessFolders(HostileTestCase):
    def test_empty_data_folder(self):
        empty = self.folder_with("empty", {})
        earlier = self.earlier_files("corpus.clg", "report.md")
        self.assert_error(self.run_cli("corpus", "build", "--data", empty, "--out", "corpus.clg"), 1, "empty",
                          "no character files")
        self.assert_error(self.run_cli("corpus", "fidelity", "--data", empty, "--tolerances", "10"), 1, "empty",
                          "no character files")
        cnchar = self.cwd / "cnchar.js"
        cnchar.write_text(json.dumps({YONG: "dhpn"}, ensure_ascii=False), encoding="utf-8")
        self.assert_error(self.run_cli("corpus", "validate", "--data", empty, "--cnchar", cnchar,
                                       "--markdown", "report.md"), 1, "empty", "no character files")
        # A character the user names that the folder lacks: wrong usage, as one a protocol names (docs/cli.md).
        self.assert_error(self.run_cli("model", YONG, "--data", empty), 2, YONG_CODE, "empty")
        self.assert_error(self.run_cli("trial", YONG, "--data", empty), 2, YONG_CODE, "empty")
        earlier[cnchar] = cnchar.read_bytes()
        self.assert_kept(earlier)

    def test_validation_that_compares_nothing_is_an_error(self):
        # 七 is labelled but not in a folder holding only 永: nothing to compare, no agreement of 0 %.
        data = self.folder_with("data", {f"{YONG}.json": (DATA / f"{YONG}.json").read_bytes()})
        cnchar = self.cwd / "cnchar.js"
        cnchar.write_text('{"七":"hs"}', encoding="utf-8")
        earlier = self.earlier_files("report.md")
        result = self.run_cli("corpus", "validate", "--data", data, "--cnchar", cnchar, "--markdown", "report.md")
        self.assert_error(result, 1, "nothing to compare", "cnchar.js")
        self.assertEqual(result.stdout, b"")
        earlier[cnchar] = cnchar.read_bytes()
        earlier[data / f"{YONG}.json"] = (DATA / f"{YONG}.json").read_bytes()
        self.assert_kept(earlier)


class FullAndFailingOutputs(HostileTestCase):
    def test_dev_full_as_every_kind_of_output(self):
        for command in (["trial", YONG, "--json", "/dev/full"], ["trial", YONG, "--csv", "/dev/full"],
                        ["trial", YONG, "--svg", "/dev/full"], ["model", YONG, "--svg", "/dev/full"],
                        ["strokes", "--markdown", "/dev/full"],
                        ["corpus", "build", "--data", DATA, "--out", "/dev/full", "--threads", "1"]):
            with self.subTest(command=command):
                self.assert_error(self.run_cli(*command), 1, "/dev/full", "No space left on device")

    def test_one_failing_output_does_not_keep_the_others_from_being_written(self):
        result = self.run_cli("trial", YONG, "--json", "trial.json", "--csv", "/dev/full", "--svg", "trial.svg")
        self.assert_error(result, 1, "/dev/full")
        self.assertEqual(json.loads((self.cwd / "trial.json").read_text())["end_reason"], "completed")
        self.assertTrue((self.cwd / "trial.svg").read_text().rstrip().endswith("</svg>"))

    def test_write_failure_keeps_earlier_outputs_whole(self):
        earlier = self.earlier_files("trial.json", "trace.csv")
        # The JSON of a trial is a few kilobytes, its trace far more: the trace fails part-way.
        result = self.run_cli("trial", YONG, "--json", "trial.json", "--csv", "trace.csv",
                              limit_file_bytes=64 << 10)
        self.assert_error(result, 1, "trace.csv", "too large")
        self.assertEqual(json.loads((self.cwd / "trial.json").read_text())["end_reason"], "completed")
        del earlier[self.cwd / "trial.json"]  # replaced whole by the new trial: that write succeeded
        self.assert_kept(earlier)

    def test_failed_store_write_keeps_the_earlier_store(self):
        store = self.cwd / "corpus.clg"
        self.assertEqual(self.run_cli("corpus", "build", "--data", DATA, "--out", store, "--steps", "1",
                                      "--threads", "1").returncode, 0)
        earlier = {store: store.read_bytes()}
        result = self.run_cli("corpus", "build", "--data", DATA, "--out", store, "--steps", "16", "--threads", "1",
                              limit_file_bytes=len(earlier[store]))
        self.assert_error(result, 1, "corpus.clg")
        self.assert_kept(earlier)


class HonestResults(HostileTestCase):
    def test_trial_that_writes_nothing_reports_no_deviation(self):
        # At 100 Hz the display takes none of the simulated writer's strokes: each is credited as assisted
        # after assist_after_misses refusals (docs/stroke-acceptance.md) and the trial goes on to its end;
        # nothing accepted, nothing measured.
        result = self.run_cli("trial", YONG, "--rate", "100", "--json", "trial.json")
        self.assertEqual(result.returncode, 0, result.stderr.decode())
        table = result.stdout.decode()
        self.assertRegex(table, r"strokes assisted +5\n")
        self.assertRegex(table, r"mean deviation +-\n")
        self.assertRegex(table, r"max deviation +-\n")
        for line in table.splitlines():
            if line.strip().startswith(("0 ", "1 ", "2 ", "3 ", "4 ")):
                self.assertEqual(line.split()[4:6], ["-", "-"], line)
        doc = json.loads((self.cwd / "trial.json").read_text())
        self.assertEqual(doc["strokes_completed"], 0)
        self.assertEqual(doc["strokes_assisted"], 5)
        self.assertFalse(doc["completed_in_order"])
        self.assertIsNone(doc["mean_deviation_m"])
        self.assertIsNone(doc["max_deviation_m"])
        for stroke in doc["per_character"][0]["per_stroke"]:
            self.assertIsNone(stroke["mean_deviation_m"])
            self.assertIsNone(stroke["time_s"])


def read_trace(path):
    """A trace CSV's header, its number of rows and its first and last rows. The program writes one row of
    numbers per line (nothing quoted), so rows are lines: counted, and only the first and last parsed."""
    lines = Path(path).read_text().splitlines()
    header, rows = next(csv.reader(lines[:1])), lines[1:]
    first, last = next(csv.reader(rows[:1]), None), next(csv.reader(rows[-1:]), None)
    return header, len(rows), first, last


def cpu_seconds(pid):
    """The user and system time process `pid` has used so far (/proc/PID/stat), or None once it is gone."""
    try:
        fields = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()
    except OSError:
        return None
    return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")


def threads(pid):
    """The number of threads of process `pid` (/proc/PID/status), or None once it is gone."""
    try:
        status = Path(f"/proc/{pid}/status").read_text()
    except OSError:
        return None
    return int(next(line.split()[1] for line in status.splitlines() if line.startswith("Threads:")))


class Signals(HostileTestCase):
    """A trial stopped by SIGINT or SIGTERM writes every recorded tick, then exits 128 + the signal.

    The signal comes once the trial runs (a signal before the program has set its handlers ends it by its
    default action, one while it reads the characters ends it with nothing written), found by polling every
    10 ms instead of a fixed wait: a real-time trial runs once its device's servo loop has a thread of its own
    (at most REAL_TIME_START_S, the fixed wait this replaces), then REAL_TIME_RUN_S more to record ticks; a
    lock-step trial, which ticks as fast as it can, once it has used LOCK_STEP_CPU_S of CPU (its characters are
    read in about a hundredth of a second: some 250,000 ticks at 10 kHz in Release), whatever the load."""

    REAL_TIME_START_S = 1.5
    REAL_TIME_RUN_S = 0.3
    LOCK_STEP_CPU_S = 1.5 if SANITIZED else 0.15

    def wait_until_running(self, process, lock_step=False):
        """Polls `process` until its trial runs (see the class); returns early when it has ended."""
        started = time.monotonic()
        if lock_step:
            while time.monotonic() - started < TIMEOUT_S:
                used = cpu_seconds(process.pid)
                if used is None or used >= self.LOCK_STEP_CPU_S or process.poll() is not None:
                    return
                time.sleep(0.01)
            return
        while time.monotonic() - started < self.REAL_TIME_START_S:
            count = threads(process.pid)
            if count is None or count > 1 or process.poll() is not None:
                break
            time.sleep(0.01)
        time.sleep(self.REAL_TIME_RUN_S)

    def stop_trial(self, args, sig, lock_step=False, twice=False, ignored=(), before=None):
        """`trial ARGS` stopped by `sig` once it runs; `ignored` signals are ignored in the program from its
        start (as `nohup` ignores SIGHUP), and `before` is sent first, half a second earlier."""
        def ignore():
            for each in ignored:
                signal.signal(each, signal.SIG_IGN)
        process = subprocess.Popen([CLI, "trial", *args], cwd=self.cwd, stdout=subprocess.PIPE,
                                   stderr=subprocess.PIPE, preexec_fn=ignore)
        try:
            self.wait_until_running(process, lock_step)
            if before is not None:
                process.send_signal(before)
                time.sleep(0.5)
            if process.poll() is not None:
                self.fail(f"the trial ended (status {process.returncode}) before the signal: "
                          f"{process.communicate()[1].decode(errors='replace')}")
            process.send_signal(sig)
            if twice:  # a second Ctrl-C while the files are written must not lose them
                time.sleep(0.05)
                if process.poll() is None:
                    process.send_signal(sig)
            stdout, stderr = process.communicate(timeout=TIMEOUT_S)
        finally:
            if process.poll() is None:
                process.kill()
                process.wait()
        message = stderr.decode(errors="replace")
        self.assertEqual(process.returncode, 128 + sig, message)
        name = signal.Signals(sig).name
        self.assertIn(f"stopped by {name}", message)
        self.assertIn("every recorded tick was written", message)
        table = stdout.decode()
        self.assertIn("ABORTED", table)
        self.assertIn("interrupted", table)
        doc = json.loads((self.cwd / "trial.json").read_text())
        self.assertEqual(doc["end_reason"], "interrupted")
        self.assertTrue(doc["aborted"])
        self.assertIn(name, doc["abort_reason"])
        self.assertLess(doc["strokes_completed"], doc["strokes_total"])
        header, rows, first, last = read_trace(self.cwd / "trace.csv")
        self.assertEqual(header[0], "t")
        self.assertGreater(rows, 0)
        # The last tick recorded is the last row (times written to 1 us).
        self.assertAlmostEqual(float(last[0]), doc["trial_time_s"], delta=1e-6)
        self.assertEqual(sorted(p.name for p in self.cwd.iterdir()), ["trace.csv", "trial.json"])  # no temporary
        return doc, rows, first

    def real_time(self, sig):
        doc, rows, _ = self.stop_trial([YONG, "--pacing", "real-time", "--json", "trial.json", "--csv",
                                        "trace.csv"], sig)
        self.assertEqual(rows, doc["loop"]["ticks"])  # one row per tick of the servo loop
        for key in ("late_ticks", "forces_withheld", "longest_stall_ms", "period_jitter_us_p99"):
            self.assertIn(key, doc["loop"])

    def lock_step(self, sig, twice=False):
        # Twenty 永 at 10 kHz: 3 million ticks to the time limit, seconds of work, still running when the signal
        # comes (a lock-step tick costs microseconds).
        rate_hz = 10000
        args = [YONG * 20, "--pacing", "lock-step", "--rate", str(rate_hz), "--json", "trial.json", "--csv",
                "trace.csv"]
        doc, rows, first = self.stop_trial(args, sig, lock_step=True, twice=twice)
        self.assertNotIn("loop", doc)
        # Ticks from t = 0 one period apart, up to the time the JSON gives: none missing.
        self.assertEqual(rows, round(doc["trial_time_s"] * rate_hz) + 1)
        self.assertEqual(float(first[0]), 0.0)

    def test_sigint_real_time(self):
        self.real_time(signal.SIGINT)

    def test_a_sighup_ignored_from_the_start_stays_ignored_and_sigterm_still_stops(self):
        # nohup: the trial goes on through the hangup (it is still running half a second after it), and
        # a SIGTERM ignored from the start (as no shell does) is still a stop asked for.
        doc, _, _ = self.stop_trial([YONG, "--pacing", "real-time", "--json", "trial.json", "--csv", "trace.csv"],
                                    signal.SIGTERM, ignored=(signal.SIGHUP, signal.SIGTERM), before=signal.SIGHUP)
        self.assertIn("SIGTERM", doc["abort_reason"])

    def test_sigterm_real_time(self):
        self.real_time(signal.SIGTERM)

    def test_sigint_lock_step_twice(self):
        self.lock_step(signal.SIGINT, twice=True)

    def test_sigterm_lock_step(self):
        self.lock_step(signal.SIGTERM)

    def test_bench_loop_trial(self):
        process = subprocess.Popen([CLI, "bench", "loop", "--trial", YONG, "--json"], cwd=self.cwd,
                                   stdout=subprocess.PIPE, stderr=subprocess.PIPE)
        self.wait_until_running(process)  # a real-time servo loop, as a real-time trial's
        self.assertIsNone(process.poll())
        process.send_signal(signal.SIGINT)
        stdout, stderr = process.communicate(timeout=TIMEOUT_S)
        self.assertEqual(process.returncode, 130, stderr.decode())
        self.assertIn("stopped by SIGINT", stderr.decode())
        report = json.loads(stdout)
        self.assertEqual(report["trial"]["end"], "interrupted")
        self.assertGreater(report["ticks"], 0)


class HostileSizes(HostileTestCase):
    """A byte-order mark before a trace's header, traces and scenes over their documented limits (docs/cli.md,
    "Pen traces: format and limits"), and the progress of a long score on a terminal."""

    MAX_SEGMENTS = 10000  # kMaxScoredSegments
    MAX_CHARACTERS = 1000  # kMaxSceneCharacters

    def trace(self, name, segments, samples_per_segment=5, bom=False):
        """A trace of `segments` pen-down segments, each a short line near the centre of 永's box."""
        lines = ["t,x,y,pen"]
        t = 0
        for k in range(segments):
            for i in range(samples_per_segment):
                lines.append(f"{t * 1e-3:.3f},{-0.02 + 0.0004 * i:.4f},{0.001 * (k % 20) - 0.01:.4f},1")
                t += 1
            lines.append(f"{t * 1e-3:.3f},0,0,0")
            t += 1
        path = self.cwd / name
        path.write_bytes((b"\xef\xbb\xbf" if bom else b"") + ("\r\n".join(lines) + "\r\n").encode())
        return path

    def test_byte_order_mark_before_the_header(self):
        self.trace("plain.csv", 3)
        self.trace("bom.csv", 3, bom=True)
        plain = self.run_cli("score", "plain.csv", "--character", YONG, "--json", "-")
        marked = self.run_cli("score", "bom.csv", "--character", YONG, "--json", "-")
        self.assertEqual(marked.returncode, 0, marked.stderr.decode())
        plain_score, marked_score = json.loads(plain.stdout), json.loads(marked.stdout)
        self.assertEqual(marked_score.pop("trace"), "bom.csv")
        self.assertEqual(plain_score.pop("trace"), "plain.csv")
        self.assertEqual(marked_score, plain_score)
        self.assertEqual(marked_score["samples"], 3 * 6)

    def test_too_many_pen_down_segments_are_refused_while_reading(self):
        self.trace("many.csv", self.MAX_SEGMENTS + 1, samples_per_segment=2)
        started = time.monotonic()
        error = self.assert_error(self.run_cli("score", "many.csv", "--character", YONG), 1, "many.csv",
                                  f"more than {self.MAX_SEGMENTS} pen-down segments")
        self.assertIn(f"many.csv:{3 * self.MAX_SEGMENTS + 2}:", error)  # the line starting one too many
        self.assertLess(time.monotonic() - started, 10)

    def test_too_many_samples_are_refused_while_reading(self):
        rows = "".join(f"{i * 1e-3:.3f},{0.0002 * (i % 100) - 0.01:.4f},0,1\n" for i in range(1_000_001))
        (self.cwd / "samples.csv").write_text("t,x,y,pen\n" + rows)
        self.assert_error(self.run_cli("score", "samples.csv", "--character", YONG), 1,
                          "samples.csv:1000002:", "more than 1000000 samples")

    def test_the_limit_itself_is_scored(self):
        self.trace("limit.csv", self.MAX_SEGMENTS, samples_per_segment=2)
        result = self.run_cli("score", "limit.csv", "--character", YONG, "--json", "-")
        self.assertEqual(result.returncode, 0, result.stderr.decode())
        self.assertEqual(len(json.loads(result.stdout)["per_character"][0]["segments"]), self.MAX_SEGMENTS)

    def test_a_scene_over_the_limit_is_refused_before_loading(self):
        started = time.monotonic()
        self.assert_error(self.run_cli("trial", YONG * (self.MAX_CHARACTERS + 1)), 1, "CHARS",
                          f"{self.MAX_CHARACTERS + 1} characters", f"limit of {self.MAX_CHARACTERS}")
        self.assertLess(time.monotonic() - started, 10)

    def test_score_refuses_a_scene_over_the_limit_before_loading(self):
        # Characters that are not in the embedded set: were any loaded first, that would be the error.
        trace = self.trace("few.csv", 1)
        self.assert_error(self.run_cli("score", trace, "--character", "一" * (self.MAX_CHARACTERS + 1)), 1,
                          "--character", f"{self.MAX_CHARACTERS + 1} characters", f"limit of {self.MAX_CHARACTERS}")

    def run_on_terminal(self, *args):
        """Runs the program with stderr on a pseudo-terminal (stdout a pipe); returns (status, stdout, what the
        terminal showed). Progress is shown from the start (CALLIGRAPHY_PROGRESS_AFTER_S=0), so that what the
        terminal shows does not depend on how fast this machine scores."""
        import pty
        controller, terminal = pty.openpty()
        environment = dict(os.environ, CALLIGRAPHY_PROGRESS_AFTER_S="0")
        process = subprocess.Popen([CLI, *map(str, args)], cwd=self.cwd, stdout=subprocess.PIPE, stderr=terminal,
                                   env=environment)
        os.close(terminal)
        shown = b""
        while True:
            try:
                chunk = os.read(controller, 65536)
            except OSError:  # EIO: the program closed the terminal
                break
            if not chunk:
                break
            shown += chunk
        stdout = process.stdout.read()
        process.wait(timeout=TIMEOUT_S)
        os.close(controller)
        return process.returncode, stdout, shown.decode(errors="replace")

    def test_progress_of_a_long_score_on_a_terminal_only(self):
        # One pen-down zig-zag of 200,000 samples (6 MB): the progress is shown from the start (run_on_terminal),
        # whatever the score's length (a trace past the limit of a million samples is read by
        # test_too_many_samples_are_refused_while_reading). Under the sanitizers a fifth of it (the program runs
        # ten times slower there).
        samples = 40_000 if SANITIZED else 200_000
        rows = "".join(f"{i * 1e-3:.3f},{0.0002 * (i % 100) - 0.01:.4f},{0.0001 * (i % 37):.4f},1\n"
                       for i in range(samples))
        (self.cwd / "long.csv").write_text("t,x,y,pen\n" + rows)
        status, stdout, shown = self.run_on_terminal("score", "long.csv", "--character", YONG)
        self.assertEqual(status, 0, shown)
        self.assertIn("Score of long.csv", stdout.decode())
        self.assertRegex(shown, r"\r\x1b\[K(reading long\.csv \d+%|scoring long\.csv \d+ / 1 segments)")
        self.assertTrue(shown.endswith("\r\x1b[K"), repr(shown[-40:]))  # the line is cleared at the end
        piped = self.run_cli("score", "long.csv", "--character", YONG)
        self.assertEqual(piped.returncode, 0)
        self.assertEqual(piped.stderr, b"")  # no progress into a pipe or a log


class HostileFolders(HostileTestCase):
    def test_thousands_of_empty_folders_are_named_in_a_short_line(self):
        folders = []
        for i in range(3000):
            (self.cwd / f"empty{i:04d}").mkdir()
            folders.append(f"empty{i:04d}")
        line = self.assert_error(self.run_cli("report", *folders, "--csv", "."), 1, "empty0000",
                                 "and 2997 more folders", "no session folder")
        self.assertLess(len(line), 300)


class HostileMessages(HostileTestCase):
    """Whatever an error quotes (a device name, a file name), it is one line of printable text of bounded
    length: no newline splits it, no escape sequence reaches the terminal (docs/cli.md, "Errors")."""

    def assert_one_printable_line(self, result, status):
        self.assertEqual(result.returncode, status, result.stderr)
        lines = result.stderr.split(b"\n")
        self.assertEqual(lines[-1], b"", "the message does not end its line")
        self.assertEqual(len(lines), 2, f"not one line: {result.stderr!r}")
        self.assertFalse(any(byte < 0x20 or byte == 0x7F for byte in lines[0]), f"control bytes: {lines[0]!r}")
        return lines[0].decode()

    def test_device_name_with_newline_and_escape(self):
        name = "evil\nname\x1b[31m\r"
        line = self.assert_one_printable_line(self.run_cli("trial", YONG, "--device", name), 2)
        self.assertIn("evil\\nname\\x1b[31m\\r", line)
        self.assertIn("simulated", line)  # what is available is still said

    def test_file_name_with_control_characters(self):
        line = self.assert_one_printable_line(self.run_cli("score", "no\x07such\nfile.csv", "--character", YONG), 1)
        self.assertIn("no\\x07such\\nfile.csv", line)

    def test_huge_name_gives_a_bounded_line(self):
        name = "d" * 100_000  # one argument may hold at most 128 KiB (MAX_ARG_STRLEN)
        line = self.assert_one_printable_line(self.run_cli("trial", YONG, "--device", name), 2)
        self.assertLess(len(line), 3000)
        self.assertRegex(line, r"\.\.\. \(\d+ more bytes\)$")


if __name__ == "__main__":
    unittest.main(verbosity=2)
