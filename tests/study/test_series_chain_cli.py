#!/usr/bin/env python3
"""A subject's series of sessions as a checked chain, through the program, run by CTest as
`study_series_chain_cli`: a predecessor moved away, replaced, copied from another subject or left with a
trial unsaved is an error naming it and what mends it; a predecessor whose clock was ahead is recorded as
measured and stays readable; concurrent runs of one subject leave one series; a copied session is not counted
twice by the report.

CALLIGRAPHY_CLI names the program. Standard library only.
"""
import hashlib
import json
import os
import shutil
import subprocess
import tempfile
import unittest
from pathlib import Path

from study_protocols import two_session_protocol

CLI = os.environ.get("CALLIGRAPHY_CLI", "")

PROTOCOL = two_session_protocol("chain")


class SeriesChainTest(unittest.TestCase):
    def setUp(self):
        if not CLI or not Path(CLI).exists():
            self.fail(f"CALLIGRAPHY_CLI={CLI!r} is not the calligraphy program: run these tests through ctest")
        self.folder = tempfile.TemporaryDirectory(prefix="calligraphy-chain-")
        self.cwd = Path(self.folder.name)
        (self.cwd / "p.json").write_text(json.dumps(PROTOCOL, ensure_ascii=False), encoding="utf-8")

    def tearDown(self):
        self.folder.cleanup()

    def run_cli(self, *args):
        return subprocess.run([CLI, *map(str, args)], cwd=self.cwd, capture_output=True, timeout=600)

    def run_subject(self, subject="S01"):
        return self.run_cli("session", "run", "p.json", "--writer", "simulated", "--subject", subject, "--out", "S")

    def sessions(self, subject="S01"):
        """{session number: folder} of the subject's session folders."""
        found = {}
        for folder in (self.cwd / "S" / subject).iterdir():
            if (folder / "session.json").is_file():
                manifest = json.loads((folder / "session.json").read_text(encoding="utf-8"))
                self.assertNotIn(manifest["session_number"], found, "a session started twice")
                found[manifest["session_number"]] = folder
        return found

    def first_session_only(self, subject="S01"):
        """Runs the subject's series, then removes session 2: where a run finds session 1 done."""
        done = self.run_subject(subject)
        self.assertEqual(done.returncode, 0, done.stderr.decode())
        sessions = self.sessions(subject)
        shutil.rmtree(sessions[2])
        return sessions[1]

    def assert_refused(self, result, *named):
        stderr = result.stderr.decode()
        self.assertEqual(result.returncode, 1, stderr)
        self.assertNotIn("internal error", stderr)
        for text in named:
            self.assertIn(text, stderr)

    def test_the_next_session_names_its_predecessor_by_folder_and_content(self):
        first = self.first_session_only()
        result = self.run_subject()
        self.assertEqual(result.returncode, 0, result.stderr.decode())
        second = json.loads((self.sessions()[2] / "session.json").read_text(encoding="utf-8"))
        link = second["previous_session"]
        self.assertEqual(link["session_id"], first.name)
        self.assertEqual(link["session_sha256"], hashlib.sha256((first / "session.json").read_bytes()).hexdigest())

    def test_a_moved_predecessor_is_named_and_no_session_is_started_again(self):
        done = self.run_subject()
        self.assertEqual(done.returncode, 0, done.stderr.decode())
        sessions = self.sessions()
        shutil.move(sessions[1], self.cwd / "elsewhere")
        result = self.run_subject()
        self.assert_refused(result, "session 1 of chain is missing", sessions[2].name, sessions[1].name)
        self.assertEqual(list(self.sessions()), [2])

    def test_a_replaced_predecessor_is_named(self):
        done = self.run_subject()
        self.assertEqual(done.returncode, 0, done.stderr.decode())
        sessions = self.sessions()
        manifest = sessions[1] / "session.json"
        # Another file of the same content (a key's spacing changed): a group edited in would be refused as such.
        text = manifest.read_text(encoding="utf-8")
        self.assertIn('"group": ""', text)
        manifest.write_text(text.replace('"group": ""', '"group":""'), encoding="utf-8")
        result = self.run_subject()
        self.assert_refused(result, "/previous_session/session_sha256", str(manifest.relative_to(self.cwd)))

    def test_a_resumed_learning_session_refuses_a_replaced_predecessor(self):
        done = self.run_cli("session", "run", "p.json", "--writer", "simulated", "--writer-learning", "two-state",
                            "--subject", "S01", "--out", "S")
        self.assertEqual(done.returncode, 0, done.stderr.decode())
        sessions = self.sessions()
        for record in (sessions[2] / "trials").glob("*.json"):
            record.unlink()  # unsaved again: the resume writes it with the memory of session 1
        manifest = sessions[1] / "session.json"
        # Another file of the same content (a key's spacing changed): a group edited in would be refused as such.
        text = manifest.read_text(encoding="utf-8")
        self.assertIn('"group": ""', text)
        manifest.write_text(text.replace('"group": ""', '"group":""'), encoding="utf-8")
        resumed = self.run_cli("session", "resume", sessions[2])
        self.assert_refused(resumed, "/previous_session/session_sha256", str(manifest.relative_to(self.cwd)))

    def test_a_predecessor_with_a_trial_unsaved_names_session_resume(self):
        first = self.first_session_only()
        sorted((first / "trials").glob("002-*.json"))[0].unlink()
        result = self.run_subject()
        stderr = result.stderr.decode()
        self.assertEqual(result.returncode, 1, stderr)
        self.assertIn(f"calligraphy session resume S/S01/{first.name}", stderr)
        self.assertEqual(list(self.sessions()), [1])
        resumed = self.run_cli("session", "resume", first)
        self.assertEqual(resumed.returncode, 0, resumed.stderr.decode())
        self.assertEqual(self.run_subject().returncode, 0)
        self.assertEqual(sorted(self.sessions()), [1, 2])

    def test_another_subjects_session_is_named_where_it_belongs_and_counted_once(self):
        self.assertEqual(self.run_subject("S01").returncode, 0)
        foreign = self.sessions("S01")[1]
        (self.cwd / "S" / "S02").mkdir()
        shutil.copytree(foreign, self.cwd / "S" / "S02" / foreign.name)
        result = self.run_subject("S02")
        self.assert_refused(result, "subject 'S01'", "move it back to S/S01")
        report = self.run_cli("report", "S", "--csv", ".")
        self.assert_refused(report, "the same session as", foreign.name)

    def test_a_predecessor_from_a_clock_ahead_is_recorded_as_measured_and_stays_readable(self):
        first = self.first_session_only()
        last = sorted((first / "trials").glob("*.json"))[-1]
        record = json.loads(last.read_text(encoding="utf-8"))
        record["end_time_utc"] = "2066-01-01T00:00:00.000Z"
        last.write_text(json.dumps(record), encoding="utf-8")
        result = self.run_subject()
        self.assertEqual(result.returncode, 0, result.stderr.decode())
        link = json.loads((self.sessions()[2] / "session.json").read_text(encoding="utf-8"))["previous_session"]
        self.assertEqual(link["ended_utc"], "2066-01-01T00:00:00.000Z")
        self.assertLess(link["elapsed_s"], -1e9)
        for command in (["report", "S", "--csv", "."], ["report", "S", "--out", "r.html"]):
            read = self.run_cli(*command)
            self.assertEqual(read.returncode, 0, read.stderr.decode())
        again = self.run_subject()
        self.assertEqual(again.returncode, 0, again.stderr.decode())
        self.assertIn("every session of chain is done", again.stdout.decode())

    def test_concurrent_runs_of_one_subject_leave_one_series(self):
        runs = [subprocess.Popen([CLI, "session", "run", "p.json", "--writer", "simulated", "--subject", "S01",
                                  "--out", "S"], cwd=self.cwd, stdout=subprocess.PIPE, stderr=subprocess.PIPE)
                for _ in range(5)]
        # One run writes the study folder at a time: the others, started while it runs, are refused naming it
        # (one may start after it ended, and find every session done: it saves no trial).
        ran = 0
        for run in runs:
            stdout, stderr = run.communicate(timeout=600)
            if run.returncode == 0:
                ran += "trials saved" in stdout.decode()
            else:
                self.assertEqual(run.returncode, 1, stderr.decode())
                self.assertIn("another run is writing this study folder", stderr.decode())
        self.assertEqual(ran, 1)
        sessions = self.sessions()  # fails on a session number found twice
        self.assertEqual(sorted(sessions), [1, 2])
        link = json.loads((sessions[2] / "session.json").read_text(encoding="utf-8"))["previous_session"]
        self.assertEqual(link["session_id"], sessions[1].name)


if __name__ == "__main__":
    unittest.main()
