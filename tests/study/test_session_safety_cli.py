#!/usr/bin/env python3
"""What `calligraphy session run|resume` refuses at the entry, before any trial runs and before any folder is
made, and what a run leaves when it fails or is killed (docs/cli.md, "session run | resume"; docs/experiments.md,
"How nothing is lost"), run by CTest as `study_session_safety_cli`:

- a folder no trial could be saved in (read-only, too little free space) is refused naming it; a disk that fills
  mid-session stops the run naming the trial and `session resume`, which then completes it;
- an edited protocol beside sessions of its earlier text is refused naming that session and both SHA-256;
  two protocols under one name are not pooled by `report`;
- session.json: the cap its readers take is the writer's, a larger plan is refused before any folder;
- a trial longer than the tick bound is refused by the protocol's field, before any folder;
- a previous session whose end is not recorded is not timed from its creation;
- a run waiting for another run's lock ends on SIGINT and SIGTERM;
- a run killed at any moment leaves whole session folders, or temporaries that readers skip and the next run
  removes.

CALLIGRAPHY_CLI names the program. Standard library only.
"""
import errno
import fcntl
import hashlib
import json
import os
import select
import shutil
import signal
import socket
import subprocess
import tempfile
import time
import unittest
from pathlib import Path

from study_protocols import two_session_protocol

CLI = os.environ.get("CALLIGRAPHY_CLI", "")

SMALL = {
    "name": "small",
    "conditions": [{"name": "vision", "mode": "vision"}, {"name": "haptic", "mode": "haptic"}],
    "test": {"characters": ["十", "人"], "conditions": ["vision", "haptic"], "repetitions": 2},
    "trial": {"max_duration_s": 20},
}


def digest(path):
    return hashlib.sha256(path.read_bytes()).hexdigest()


def sha256_of(protocol):
    return hashlib.sha256(json.dumps(protocol, ensure_ascii=False).encode("utf-8")).hexdigest()


def many_trials(name, strings, conditions, repetitions, duration_s=0.001):
    """A protocol of strings x conditions x repetitions trials of the vision condition's kind."""
    return {
        "name": name,
        "conditions": [{"name": f"c{i}", "mode": "vision"} for i in range(conditions)],
        "test": {"characters": strings, "conditions": [f"c{i}" for i in range(conditions)],
                 "repetitions": repetitions},
        "trial": {"max_duration_s": duration_s},
    }


class SessionSafetyTest(unittest.TestCase):
    def setUp(self):
        if not CLI or not Path(CLI).exists():
            self.fail(f"CALLIGRAPHY_CLI={CLI!r} is not the calligraphy program: run these tests through ctest")
        self.folder = tempfile.TemporaryDirectory(prefix="calligraphy-safety-")
        self.cwd = Path(self.folder.name)
        self.mounted = []
        self.immutable = []

    def tearDown(self):
        for path in self.immutable:
            subprocess.run(["chattr", "-i", str(path)], capture_output=True)
            os.chmod(path, 0o755)
        for mount_point in reversed(self.mounted):
            subprocess.run(["umount", str(mount_point)], capture_output=True)
        self.folder.cleanup()

    def run_cli(self, *args, timeout=600):
        return subprocess.run([CLI, *map(str, args)], cwd=self.cwd, capture_output=True, timeout=timeout)

    def write_protocol(self, protocol, name="p.json"):
        path = self.cwd / name
        path.write_text(json.dumps(protocol, ensure_ascii=False), encoding="utf-8")
        return path

    def assert_refused(self, result, *named, status=1):
        stderr = result.stderr.decode()
        self.assertEqual(result.returncode, status, stderr)
        self.assertNotIn("internal error", stderr)
        self.assertEqual(len(stderr.strip().splitlines()), 1, stderr)
        for text in named:
            self.assertIn(text, stderr)
        return stderr

    def make_read_only(self, folder):
        """No one may write in `folder`: its mode bits, or (for root, whom they do not stop) the immutable flag."""
        self.immutable.append(folder)
        if os.geteuid() != 0:
            os.chmod(folder, 0o555)
            return
        made = subprocess.run(["chattr", "+i", str(folder)], capture_output=True)
        if made.returncode != 0:
            self.skipTest("root, and chattr +i does not work here: " + made.stderr.decode().strip())

    def mount_tmpfs(self, name, size):
        mount_point = self.cwd / name
        mount_point.mkdir()
        mounted = subprocess.run(["mount", "-t", "tmpfs", "-o", f"size={size}", "tmpfs", str(mount_point)],
                                 capture_output=True)
        if mounted.returncode != 0:
            self.skipTest("cannot mount a small tmpfs here (needs privileges): " + mounted.stderr.decode().strip())
        self.mounted.append(mount_point)
        return mount_point

    def session_folders(self, root):
        """The whole session folders under `root` (relative to the test's folder), as absolute paths."""
        root = self.cwd / root
        return sorted(p.parent for p in root.rglob("session.json") if not p.parent.name.startswith("."))

    def named(self, path):
        """`path` as the program names it when given paths relative to the test's folder."""
        return str(Path(path).relative_to(self.cwd))

    def saved(self, session):
        return sorted((session / "trials").glob("*.json"))

    def wait_for(self, condition, process, what):
        deadline = time.monotonic() + 300
        while time.monotonic() < deadline:
            if condition():
                return
            if process.poll() is not None:
                self.fail(f"the run ended before {what}: {process.stderr.read().decode()}")
            time.sleep(0.01)
        self.fail(f"no {what} in 300 s")

    # 1. Writing: checked before the first trial; a disk that fills later leaves the session resumable.

    def test_a_read_only_trials_folder_is_refused_before_any_trial(self):
        self.write_protocol(SMALL)
        done = self.run_cli("session", "run", "p.json", "--subject", "P1", "--out", "out")
        self.assertEqual(done.returncode, 0, done.stderr.decode())
        session = self.session_folders("out")[0]
        for path in (session / "trials").glob("00[3-8]-*"):
            path.unlink()
        before = {p.name: digest(p) for p in session.rglob("*") if p.is_file()}
        self.make_read_only(session / "trials")
        refused = self.run_cli("session", "resume", session)
        self.assert_refused(refused, str(session / "trials"), "checked before the first trial")
        self.assertEqual(before, {p.name: digest(p) for p in session.rglob("*") if p.is_file()},
                         "no trial ran and the log is as it was")
        # A session run into a subject folder no session folder can be made in is refused the same way (another
        # subject: a second run of P1's one session would be refused as doubling the study).
        (self.cwd / "out" / "P2").mkdir()
        self.make_read_only(self.cwd / "out" / "P2")
        run = self.run_cli("session", "run", "p.json", "--subject", "P2", "--out", "out")
        self.assert_refused(run, str(Path("out") / "P2"))
        self.assertEqual(self.session_folders("out"), [session])
        # Writable again: the resume completes the session.
        for path in self.immutable:
            subprocess.run(["chattr", "-i", str(path)], capture_output=True)
            os.chmod(path, 0o755)
        resumed = self.run_cli("session", "resume", session)
        self.assertEqual(resumed.returncode, 0, resumed.stderr.decode())
        self.assertEqual(len(self.saved(session)), 8)

    def test_too_little_free_space_is_refused_before_any_folder(self):
        tiny = self.mount_tmpfs("tiny", "512k")
        self.write_protocol(SMALL)
        refused = self.run_cli("session", "run", "p.json", "--subject", "P1", "--out", tiny / "out")
        self.assert_refused(refused, str(tiny), "free, less than the")
        self.assertEqual(list(tiny.iterdir()), [])

    def test_a_disk_filled_mid_session_keeps_the_saved_trials_and_resumes(self):
        disk = self.mount_tmpfs("disk", "48m")
        # Many short lock-step trials: the run is still writing when the disk fills (it is stopped after two
        # are saved; 200 trials of under 20 ms leave it over three seconds, against the poll's 10 ms). Under the
        # sanitizers a trial takes ten times as long, so fewer do: the resume runs them all.
        repetitions = 20 if os.environ.get("CALLIGRAPHY_SANITIZED") else 50
        self.write_protocol(dict(SMALL, name="fill", test=dict(SMALL["test"], repetitions=repetitions)))
        process = subprocess.Popen([CLI, "session", "run", "p.json", "--subject", "P1", "--out", disk / "out"],
                                   cwd=self.cwd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
        sessions = lambda: self.session_folders(disk / "out") if (disk / "out").exists() else []
        self.wait_for(lambda: sessions() and len(self.saved(sessions()[0])) >= 2, process, "two saved trials")
        # The disk fills while the run is stopped, so that its next write fails whatever it is.
        process.send_signal(signal.SIGSTOP)
        session = sessions()[0]
        before = {p.name: digest(p) for p in self.saved(session)}
        with open(disk / "filler", "wb") as filler:
            try:
                while True:
                    filler.write(b"\0" * (1 << 20))
                    filler.flush()
            except OSError as error:
                self.assertEqual(error.errno, errno.ENOSPC)
        process.send_signal(signal.SIGCONT)
        _, stderr = process.communicate(timeout=300)
        self.assertEqual(process.returncode, 1, stderr.decode())
        self.assertNotIn("internal error", stderr.decode())
        self.assertIn("every trial saved before is kept; resume with: calligraphy session resume " + str(session),
                      stderr.decode())
        for name, value in before.items():
            self.assertEqual(digest(session / "trials" / name), value, name)
        (disk / "filler").unlink()
        resumed = self.run_cli("session", "resume", session)
        self.assertEqual(resumed.returncode, 0, resumed.stderr.decode())
        planned = json.loads((session / "session.json").read_text(encoding="utf-8"))["plan"]
        self.assertEqual(len(self.saved(session)), len(planned))
        for name, value in before.items():
            self.assertEqual(digest(session / "trials" / name), value, name)

    # 2, 3. One protocol name, one content.

    def test_an_edited_protocol_is_refused_beside_its_earlier_sessions(self):
        protocol = two_session_protocol("days")
        self.write_protocol(protocol)
        done = self.run_cli("session", "run", "p.json", "--subject", "S01", "--out", "out")
        self.assertEqual(done.returncode, 0, done.stderr.decode())
        first = self.session_folders("out")
        self.assertEqual(len(first), 2)
        edited = dict(protocol, trial={"max_duration_s": 25})
        self.write_protocol(edited)
        for subject in ("S01", "S02"):  # the subject's own series, and another subject of the study
            refused = self.run_cli("session", "run", "p.json", "--subject", subject, "--out", "out")
            self.assert_refused(refused, "p.json", "differs from the one the session", self.named(first[0].parent),
                                sha256_of(edited), "restore that protocol", "new --out folder")
            self.assertEqual(self.session_folders("out"), first)
        self.assertFalse((self.cwd / "out" / "S02").exists() and any((self.cwd / "out" / "S02").iterdir()))
        # Under another name it is another design: its own series.
        self.write_protocol(dict(edited, name="days2"))
        renamed = self.run_cli("session", "run", "p.json", "--subject", "S01", "--out", "out")
        self.assertEqual(renamed.returncode, 0, renamed.stderr.decode())

    def test_two_protocols_under_one_name_are_not_pooled(self):
        protocol = dict(SMALL, test=dict(SMALL["test"], repetitions=1))
        self.write_protocol(protocol)
        self.assertEqual(self.run_cli("session", "run", "p.json", "--subject", "P1", "--out", "a").returncode, 0)
        edited = dict(protocol, trial={"max_duration_s": 25})
        self.write_protocol(edited)
        self.assertEqual(self.run_cli("session", "run", "p.json", "--subject", "P2", "--out", "b").returncode, 0)
        (self.cwd / "tables").mkdir()
        for args in (("--csv", "tables"), ("--out", "index.html")):
            refused = self.run_cli("report", "a", "b", *args)
            self.assert_refused(refused, self.named(self.session_folders("a")[0]),
                                self.named(self.session_folders("b")[0]),
                                sha256_of(protocol), sha256_of(edited), "pooled as one design")
        self.assertEqual(list((self.cwd / "tables").iterdir()), [])
        self.assertFalse((self.cwd / "index.html").exists())
        self.assertEqual(self.run_cli("report", "a", "--csv", "tables").returncode, 0)

    # 4. session.json: one cap for its writer and its readers.

    @unittest.skipIf(os.environ.get("CALLIGRAPHY_SANITIZED"),
                     "a 25 MB manifest built and read takes minutes under the sanitizers; the Release run reads it")
    def test_a_manifest_the_run_writes_is_read_by_resume(self):
        # 100,000 planned trials: a session.json of about 25 MB, over the 16 MiB resume once took.
        self.write_protocol(many_trials("big", ["十", "人", "口", "大", "山"], 20, 1000))
        process = subprocess.Popen([CLI, "session", "run", "p.json", "--subject", "P1", "--out", "out"],
                                   cwd=self.cwd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
        sessions = lambda: self.session_folders("out") if (self.cwd / "out").exists() else []
        self.wait_for(lambda: sessions() and self.saved(sessions()[0]), process, "a saved trial")
        process.send_signal(signal.SIGTERM)
        _, stderr = process.communicate(timeout=300)
        self.assertEqual(process.returncode, 128 + signal.SIGTERM, stderr.decode())
        session = sessions()[0]
        self.assertGreater((session / "session.json").stat().st_size, 16 << 20)
        resumed = subprocess.Popen([CLI, "session", "resume", session], cwd=self.cwd,
                                   stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
        log = session / "log.jsonl"
        self.wait_for(lambda: "session_resumed" in log.read_text(encoding="utf-8"), resumed, "session_resumed")
        resumed.send_signal(signal.SIGTERM)
        _, stderr = resumed.communicate(timeout=300)
        self.assertEqual(resumed.returncode, 128 + signal.SIGTERM, stderr.decode())

    @unittest.skipIf(os.environ.get("CALLIGRAPHY_SANITIZED"),
                     "a plan of 300,000 trials sized takes 14 s under the sanitizers; the Release run sizes it")
    def test_a_manifest_larger_than_its_readers_take_is_refused_before_any_folder(self):
        # 300,000 planned trials, within the 1,000,000 a session may plan: a session.json of some 75 MB.
        strings = ["十", "人", "口", "大", "山", "日", "木", "中", "天", "千", "十人", "人十", "口十", "十口", "大人"]
        self.write_protocol(many_trials("huge", strings, 20, 1000))
        refused = self.run_cli("session", "run", "p.json", "--subject", "P1", "--out", "out")
        self.assert_refused(refused, "p.json", "300000 trials", "more than the 64 MiB")
        self.assertFalse((self.cwd / "out").exists())

    # 5. The tick bound, by the protocol's field.

    def test_a_trial_over_the_tick_bound_is_refused_by_its_protocol_field_before_any_folder(self):
        self.write_protocol(dict(SMALL, trial={"max_duration_s": 3600, "rate_hz": 10000}))
        refused = self.run_cli("session", "run", "p.json", "--subject", "P1", "--out", "out")
        stderr = self.assert_refused(refused, "p.json: /trial/max_duration_s", "/trial/rate_hz", "10000000",
                                     status=2)  # the protocol's content: a usage error
        self.assertNotIn("--max-duration", stderr)
        self.assertFalse((self.cwd / "out").exists())

    # 6. A previous session without an end.

    def test_a_previous_session_without_an_end_is_not_timed_from_its_creation(self):
        self.write_protocol(two_session_protocol("days"))
        for end in (None, "missing"):
            shutil.rmtree(self.cwd / "out", ignore_errors=True)
            done = self.run_cli("session", "run", "p.json", "--subject", "S01", "--out", "out")
            self.assertEqual(done.returncode, 0, done.stderr.decode())
            first, second = self.session_folders("out")
            shutil.rmtree(second)
            last = self.saved(first)[-1]
            record = json.loads(last.read_text(encoding="utf-8"))
            if end is None:
                record["end_time_utc"] = None
            else:
                del record["end_time_utc"]
            last.write_text(json.dumps(record), encoding="utf-8")
            refused = self.run_cli("session", "run", "p.json", "--subject", "S01", "--out", "out")
            self.assert_refused(refused, self.named(last), "/end_time_utc", self.named(first), "did not end")
            self.assertEqual(self.session_folders("out"), [first])

    # 7. A lock wait ends on a stop signal.

    def test_a_run_waiting_for_the_subjects_lock_ends_on_sigint_and_sigterm(self):
        self.write_protocol(two_session_protocol("days"))
        subject = self.cwd / "out" / "S01"
        subject.mkdir(parents=True)
        holder = os.open(subject, os.O_RDONLY | os.O_DIRECTORY)
        try:
            fcntl.flock(holder, fcntl.LOCK_EX)  # another run of the subject, as the program takes it
            for signal_number in (signal.SIGINT, signal.SIGTERM):
                process = subprocess.Popen([CLI, "session", "run", "p.json", "--subject", "S01", "--out", "out"],
                                           cwd=self.cwd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
                ready, _, _ = select.select([process.stderr], [], [], 300)
                self.assertTrue(ready, "the run did not say it waits")
                # The run prints its plan first, then that it waits.
                lines = []
                while not lines or (b"waiting for another run" not in lines[-1] and lines[-1] and len(lines) < 200):
                    lines.append(process.stderr.readline())
                self.assertIn(b"waiting for another run of this subject", lines[-1], lines)
                process.send_signal(signal_number)
                try:
                    _, stderr = process.communicate(timeout=60)
                except subprocess.TimeoutExpired:
                    process.kill()
                    process.communicate()
                    self.fail(f"the lock wait ignored {signal_number.name}")
                self.assertEqual(process.returncode, 128 + signal_number, stderr.decode())
                self.assertEqual(len(stderr.decode().strip().splitlines()), 1, stderr.decode())
                self.assertIn(f"stopped by {signal_number.name} while waiting", stderr.decode())
                self.assertEqual(list(subject.iterdir()), [])
        finally:
            os.close(holder)

    # 8. A run killed at any moment.

    def test_a_run_killed_at_any_moment_leaves_whole_sessions_or_temporaries(self):
        self.write_protocol(SMALL)
        subject = self.cwd / "out" / "P1"
        for step in range(16):  # SIGKILL 0 to 150 ms after the start, in steps of 10 ms
            process = subprocess.Popen([CLI, "session", "run", "p.json", "--subject", "P1", "--out", "out"],
                                       cwd=self.cwd, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
            time.sleep(step * 0.01)
            process.kill()
            process.wait()
            for folder in subject.iterdir() if subject.exists() else []:
                whole = (folder / "session.json").is_file()
                inside = sorted(p.name for p in folder.iterdir()) if folder.is_dir() else "a file"
                self.assertTrue(whole or folder.name.startswith(".partial."),
                                f"{folder}: neither whole nor a temporary: {inside}")
        # Readers skip the temporaries: the report lists the whole sessions only.
        whole = self.session_folders("out")
        (self.cwd / "tables").mkdir()  # also for the last check, when no run got as far as a whole session
        if whole:
            report = self.run_cli("report", "out", "--csv", "tables")
            self.assertEqual(report.returncode, 0, report.stderr.decode())
            self.assertNotIn(".partial.", (self.cwd / "tables" / "trials.csv").read_text(encoding="utf-8"))
        # The next run removes those of dead runs on this host, keeps a live process's and another host's, and
        # makes its own whole.
        host = "".join(c if c.isascii() and c.isalnum() else "-" for c in socket.gethostname())[:64] or "host"
        dead = subprocess.Popen(["true"])
        dead.wait()
        # A whole session of P1 would make the next run a second session 1, which is refused: moved out.
        for folder in whole:
            shutil.rmtree(folder)
        subject.mkdir(parents=True, exist_ok=True)
        for owner in (f"{dead.pid}.{host}", f"{os.getpid()}.{host}", "1.elsewhere"):
            (subject / f".partial.{owner}.small-P1-20000101-000000" / "trials").mkdir(parents=True)
        done = self.run_cli("session", "run", "p.json", "--subject", "P1", "--out", "out")
        self.assertEqual(done.returncode, 0, done.stderr.decode())
        self.assertEqual(sorted(p.name for p in subject.iterdir() if p.name.startswith(".")),
                         sorted([f".partial.{os.getpid()}.{host}.small-P1-20000101-000000",
                                 ".partial.1.elsewhere.small-P1-20000101-000000"]))
        self.assertEqual(len(self.session_folders("out")), 1)
        # A temporary named as a session is refused by the commands that read one folder.
        temporary = subject / ".partial.1.elsewhere.small-P1-20000101-000001"
        shutil.copytree(self.session_folders("out")[-1], temporary)
        self.assert_refused(self.run_cli("session", "resume", temporary), "half made")
        self.assert_refused(self.run_cli("report", temporary, "--csv", "tables"), "half made")


if __name__ == "__main__":
    unittest.main()
