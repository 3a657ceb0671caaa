#!/usr/bin/env python3
"""`calligraphy session run|resume` and `calligraphy report` end to end (docs/experiments.md), run by CTest as
`study_session_cli`: a session stopped by SIGINT, SIGTERM or SIGKILL resumes without losing or changing a
saved trial; protocol errors name the file and the JSON pointer; the report of the sessions has a trajectory
and a force figure per trial.

CALLIGRAPHY_CLI names the program, CALLIGRAPHY_SOURCE_DIR the source tree. Standard library only.
"""
import hashlib
import json
import os
import re
import signal
import subprocess
import tempfile
import time
import unittest
from pathlib import Path

CLI = os.environ.get("CALLIGRAPHY_CLI", "")
SOURCE = Path(os.environ.get("CALLIGRAPHY_SOURCE_DIR", Path(__file__).resolve().parents[2]))

# Under the sanitizers a trial takes ten times as long: the cases run fewer trials and subjects there (the
# Release run has them all); what they check holds trial by trial and subject by subject.
SANITIZED = bool(os.environ.get("CALLIGRAPHY_SANITIZED"))

# Many short trials, so that a signal sent after the first saved trials arrives while the session runs: 48,
# or 16 under the sanitizers (where the fourteen after the second saved one still run for seconds; ABBA
# takes an even number of repetitions).
LONG_PROTOCOL = {
    "name": "long",
    "conditions": [{"name": "vision", "mode": "vision"}, {"name": "haptic", "mode": "haptic"}],
    "test": {"characters": ["十", "人"], "conditions": ["vision", "haptic"], "repetitions": 4 if SANITIZED else 12},
    "order": {"conditions": "abba"},
    "trial": {"max_duration_s": 30},
}


def digest(path):
    return hashlib.sha256(path.read_bytes()).hexdigest()


class SessionCliTest(unittest.TestCase):
    def setUp(self):
        if not CLI or not Path(CLI).exists():
            self.fail(f"CALLIGRAPHY_CLI={CLI!r} is not the calligraphy program: run these tests through ctest")
        self.folder = tempfile.TemporaryDirectory(prefix="calligraphy-study-")
        self.cwd = Path(self.folder.name)

    def tearDown(self):
        self.folder.cleanup()

    def run_cli(self, *args, timeout=600):
        return subprocess.run([CLI, *map(str, args)], cwd=self.cwd, stdout=subprocess.PIPE,
                              stderr=subprocess.PIPE, timeout=timeout)

    def write_protocol(self, protocol, name="p.json"):
        path = self.cwd / name
        path.write_text(json.dumps(protocol, ensure_ascii=False), encoding="utf-8")
        return path

    def saved(self, session):
        return sorted((session / "trials").glob("*.json"))

    def interrupt_and_resume(self, signal_number, expected_status):
        protocol = self.write_protocol(LONG_PROTOCOL)
        process = subprocess.Popen([CLI, "session", "run", protocol, "--subject", "P1", "--out", "out"],
                                   cwd=self.cwd, stdout=subprocess.PIPE, stderr=subprocess.PIPE)
        deadline = time.monotonic() + 300
        session = None
        while time.monotonic() < deadline and process.poll() is None:
            found = list((self.cwd / "out" / "P1").glob("long-*"))
            if found and len(self.saved(found[0])) >= 2:
                session = found[0]
                break
            time.sleep(0.01)
        self.assertIsNotNone(session, "the session ended or saved nothing before the signal")
        process.send_signal(signal_number)
        _, stderr = process.communicate(timeout=300)
        self.assertEqual(process.returncode, expected_status, stderr.decode())
        planned = json.loads((session / "session.json").read_text(encoding="utf-8"))["plan"]
        before = {path.name: digest(path) for path in (session / "trials").glob("*.*") if
                  path.with_name(path.name.split(".")[0] + ".json").exists() and not path.name.endswith(".part")}
        self.assertLess(len(self.saved(session)), len(planned), "the signal came after the last trial")
        if signal_number != signal.SIGKILL:
            self.assertIn("resume with: calligraphy session resume", stderr.decode())

        resumed = self.run_cli("session", "resume", session)
        self.assertEqual(resumed.returncode, 0, resumed.stderr.decode())
        self.assertEqual(len(self.saved(session)), len(planned))
        for name, value in before.items():  # every trial saved before the signal is unchanged
            self.assertEqual(digest(session / "trials" / name), value, name)
        for trial in planned:  # every planned trial has its JSON, trace (HDF5) and SVG
            for extension in ("json", "trace.h5", "svg"):
                self.assertTrue((session / "trials" / f"{trial['file']}.{extension}").is_file(), trial["file"])
        events, torn = [], 0
        for line in (session / "log.jsonl").read_text(encoding="utf-8").splitlines():
            try:
                events.append(json.loads(line)["event"])
            except json.JSONDecodeError:  # a line SIGKILL tore; resume ends it so the next line stands alone
                torn += 1
        self.assertLessEqual(torn, 1 if signal_number == signal.SIGKILL else 0)
        self.assertEqual(events.count("session_resumed"), 1)
        self.assertEqual(events[-1], "session_completed")
        self.assertEqual(events.count("trial_saved"), len(planned))
        again = self.run_cli("session", "resume", session)
        self.assertEqual(again.returncode, 0)
        self.assertIn("saved already", again.stdout.decode())
        return session, events

    def test_sigint_stops_and_resume_completes(self):
        _, events = self.interrupt_and_resume(signal.SIGINT, 128 + signal.SIGINT)
        self.assertIn("session_stopped", events)

    def test_sigterm_stops_and_resume_completes(self):
        self.interrupt_and_resume(signal.SIGTERM, 128 + signal.SIGTERM)

    def test_sigkill_crash_resumes(self):
        self.interrupt_and_resume(signal.SIGKILL, -signal.SIGKILL)

    def test_a_protocol_over_two_days_links_each_subjects_sessions(self):
        protocol = {
            "name": "days",
            "conditions": [{"name": "free", "mode": "vision"}, {"name": "fixture", "mode": "haptic"},
                           {"name": "fading", "mode": "fading"}],
            "phases": [
                {"phase": "pre-test", "condition": "free", "characters": ["十"]},
                {"phase": "training", "conditions": ["fixture", "fading"], "assignment": "between-subjects",
                 "characters": ["十", "口"]},
                {"phase": "post-test", "condition": "free", "characters": ["十"]},
                {"phase": "retention", "condition": "free", "characters": ["十"], "session": 2, "delay_s": 86400},
                {"phase": "transfer", "condition": "free", "session": 2,
                 "characters": {"choose": 1, "from": ["大", "山", "日"]}}],
            "trial": {"max_duration_s": 30},
        }
        path = self.write_protocol(protocol)
        result = self.run_cli("session", "run", path, "--subjects", "2", "--out", "out")
        self.assertEqual(result.returncode, 0, result.stderr.decode())
        for number, group in ((1, "fixture"), (2, "fading")):
            folders = sorted((self.cwd / "out" / f"S0{number}").iterdir())
            self.assertEqual(len(folders), 2)
            first, second = (json.loads((f / "session.json").read_text(encoding="utf-8")) for f in folders)
            self.assertEqual((first["session_number"], second["session_number"]), (1, 2))
            self.assertEqual(first["group"], group)
            self.assertNotIn("previous_session", first)
            link = second["previous_session"]
            self.assertEqual(link["session_id"], folders[0].name)
            self.assertEqual((link["delay_s"], link["delay"]), (86400, "simulated"))
            self.assertEqual([t["phase"] for t in second["plan"]], ["retention", "transfer"])
            # 十 and 口 trained (typical strokes 1, 2, 7): of 大 (1, 32, 5), 山 (2, 21, 2) and 日 (2, 7, 1, 1)
            # only 日 is made of them.
            self.assertEqual(second["plan"][1]["characters"], "日")
            self.assertEqual(len(self.saved(folders[1])), 2)
        again = self.run_cli("session", "run", path, "--subjects", "2", "--out", "out")
        self.assertEqual(again.returncode, 0, again.stderr.decode())
        self.assertIn("S01: every session of days is done (2)", again.stdout.decode())
        self.assertEqual(len(list((self.cwd / "out" / "S01").iterdir())), 2)

        # A first session left unfinished is resumed before the second starts.
        unfinished = self.run_cli("session", "run", path, "--subject", "T1", "--out", "out2")
        self.assertEqual(unfinished.returncode, 0, unfinished.stderr.decode())
        folders = sorted((self.cwd / "out2" / "T1").iterdir())
        for folder in folders[1:]:
            for file in sorted(folder.rglob("*"), reverse=True):
                file.unlink() if file.is_file() else file.rmdir()
            folder.rmdir()
        last = self.saved(folders[0])[-1]
        last.unlink()
        refused = self.run_cli("session", "run", path, "--subject", "T1", "--out", "out2")
        self.assertEqual(refused.returncode, 1)
        self.assertIn("session 1 of days is not finished; resume it first: calligraphy session resume",
                      refused.stderr.decode())

    def test_protocol_errors_name_file_and_pointer(self):
        bad = dict(LONG_PROTOCOL, order={"conditions": "latin"})
        result = self.run_cli("session", "run", self.write_protocol(bad), "--subject", "P1", "--out", "out")
        self.assertEqual(result.returncode, 2)
        self.assertRegex(result.stderr.decode(), r'p\.json: /order/conditions: expected one of "fixed", "latin_square"')
        self.assertFalse((self.cwd / "out").exists())
        fading = dict(LONG_PROTOCOL, conditions=[{"name": "vision", "mode": "vision"},
                                                 {"name": "haptic", "mode": "fading",
                                                  "parameters": {"end_gain": 0}}])
        result = self.run_cli("session", "run", self.write_protocol(fading), "--subject", "P1", "--out", "out")
        self.assertEqual(result.returncode, 2)
        self.assertIn("p.json: /conditions/1/parameters/end_gain: unknown key", result.stderr.decode())
        self.assertFalse((self.cwd / "out").exists())

    def test_usage(self):
        protocol = self.write_protocol(LONG_PROTOCOL)
        for args, words in [
            (["--out", "o"], "--subject"),
            (["--subjects", "2", "--writer", "person", "--out", "o"], "--subjects"),
            (["--subjects", "2", "--subject-number", "3", "--out", "o"], "--subject-number"),
            (["--subject", "P1", "--writer-profile", "expert", "--out", "o"], "--writer-profile"),
            (["--subject", "P1", "--device", "nothing", "--out", "o"], "--device"),
        ]:
            result = self.run_cli("session", "run", protocol, *args)
            self.assertEqual(result.returncode, 2, f"{args}: {result.stderr.decode()}")
            self.assertIn(words, result.stderr.decode())
        result = self.run_cli("session", "resume", self.cwd)
        self.assertEqual(result.returncode, 1)
        self.assertIn("session.json", result.stderr.decode())
        result = self.run_cli("report", self.cwd, "--out", "r.html")
        self.assertEqual(result.returncode, 1)
        self.assertIn("no session folder", result.stderr.decode())

    def test_help_lists_each_option_with_default(self):
        for command in (["session", "run"], ["session", "resume"], ["report"]):
            result = self.run_cli(*command, "--help")
            self.assertEqual(result.returncode, 0)
            for entry in re.findall(r"^  (--[a-z-]+.*(?:\n {10,}.*)*)", result.stdout.decode(), flags=re.M):
                if re.match(r"--[a-z-]+ [A-Z]", entry):
                    self.assertRegex(entry, r"\((default: .+|required)\)", f"{command}: {entry}")

    def test_simulated_subjects_and_their_report(self):
        # Two repetitions of each item, one under the sanitizers: three subjects all the same (the square's
        # alternation and the profiles' are by subject).
        protocol = dict(LONG_PROTOCOL, test=dict(LONG_PROTOCOL["test"], repetitions=1 if SANITIZED else 2),
                        order={"conditions": "latin_square"})
        path = self.write_protocol(protocol)
        result = self.run_cli("session", "run", path, "--subjects", "3", "--writer-profile", "novice,skilled",
                              "--out", "study")
        self.assertEqual(result.returncode, 0, result.stderr.decode())
        sessions = sorted((self.cwd / "study").glob("S0*/long-*"))
        self.assertEqual([s.parent.name for s in sessions], ["S01", "S02", "S03"])
        manifests = [json.loads((s / "session.json").read_text()) for s in sessions]
        self.assertEqual([m["writer_profile"] for m in manifests], ["novice", "skilled", "novice"])
        self.assertEqual([m["subject"]["number"] for m in manifests], [1, 2, 3])
        # The Latin square alternates the first condition between subjects.
        self.assertEqual([m["plan"][0]["condition"] for m in manifests], ["vision", "haptic", "vision"])
        trials = sum(len(m["plan"]) for m in manifests)
        report = self.run_cli("report", "study", "--out", "study/report.html")
        self.assertEqual(report.returncode, 0, report.stderr.decode())
        index = (self.cwd / "study" / "report.html").read_text(encoding="utf-8")
        # One page per session, linked from the index; each trial anchored by its session id and number.
        pages = sorted((self.cwd / "study" / "report_files").glob("S0*/*.html"))
        self.assertEqual([p.stem for p in pages], [s.name for s in sessions])
        for page_file, session, manifest in zip(pages, sessions, manifests):
            self.assertIn(f'href="report_files/{page_file.parent.name}/{page_file.name}"', index)
            page = page_file.read_text(encoding="utf-8")
            self.assertEqual(page.count('<figure class="trajectory"'), len(manifest["plan"]))
            self.assertEqual(page.count('<figure class="force"'), len(manifest["plan"]))
            for number in range(1, len(manifest["plan"]) + 1):
                self.assertIn(f'id="trial-{session.name}-{number}"', page)
            self.assertNotIn("<table", page)  # no summary over trials: the study report's
        self.assertEqual(sum(len(m["plan"]) for m in manifests), trials)
        # The session ids name the subject: keys across subjects.
        self.assertEqual(len({s.name for s in sessions}), 3)
        for session in sessions:
            self.assertIn(f"-{session.parent.name}-", session.name)
        record = json.loads(self.saved(sessions[0])[0].read_text(encoding="utf-8"))
        for key in ("frechet_m", "dtw_m", "order_errors", "backwards_strokes"):
            self.assertIn(key, record)

    def test_guidance_retention_protocol_with_simulated_subjects(self):
        """The shipped training-then-retention protocol: every trial saved, replay teachers recorded and named,
        fading gains that fall after a repetition whose deviation the rule counts as small."""
        protocol_path = SOURCE / "examples" / "protocols" / "guidance-retention.json"
        protocol = json.loads(protocol_path.read_text(encoding="utf-8"))
        fading = next(c for c in protocol["conditions"] if c["mode"] == "fading")["parameters"]
        subjects = 1 if SANITIZED else 2  # 24 trials of up to a minute each
        result = self.run_cli("session", "run", protocol_path, "--subjects", str(subjects), "--out", "study")
        self.assertEqual(result.returncode, 0, result.stderr.decode())
        sessions = sorted((self.cwd / "study").glob("S0*/guidance-retention-*"))
        self.assertEqual(len(sessions), subjects)
        small_deviations = 0
        for session in sessions:
            planned = json.loads((session / "session.json").read_text(encoding="utf-8"))["plan"]
            records = [json.loads((session / "trials" / f"{t['file']}.json").read_text(encoding="utf-8"))
                       for t in planned]
            self.assertEqual(len(self.saved(session)), len(planned))
            self.assertEqual(records[-1]["mode"], "vision")  # retention last
            self.assertFalse(records[-1]["force_law"]["guidance"])
            for record in records:
                if record["mode"] == "replay":
                    teacher = record["guidance"]["teacher"]
                    self.assertEqual(teacher["sha256"], digest(session / teacher["file"]))
                    self.assertEqual(teacher["source"], "recorded")
            by_item = {}
            for record in (r for r in records if r["mode"] == "fading"):
                by_item.setdefault(record["characters"], []).append(record["guidance"])
            for gains in by_item.values():
                self.assertEqual(gains[0]["gain"], fading["start_gain"])
                for before, after in zip(gains, gains[1:]):
                    deviation_m = after["previous_mean_deviation_m"]
                    # g' = f g + k e falls below g exactly when e < (1 - f) g / k.
                    if deviation_m < (1 - fading["forgetting_factor"]) * before["gain"] / fading["error_gain_per_m"]:
                        small_deviations += 1
                        self.assertLess(after["gain"], before["gain"])
        self.assertGreater(small_deviations, 0, "no repetition was written closely enough for the gain to fall")


if __name__ == "__main__":
    unittest.main(verbosity=2)
