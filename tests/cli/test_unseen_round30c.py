#!/usr/bin/env python3
"""Round 30C: a study's sessions over days, stopped, resumed, raced. From the docs alone: docs/experiments.md
("Protocol files", "Phases", "Sessions", "Trace files", "How nothing is lost", "Log events", "Trial records",
"Tidy tables", "What to practise next", "A cohort in memory"), docs/writer.md ("Deterministic and resumable")
and docs/cli.md ("Conventions", "Exit statuses", "Stopping a trial", `curriculum`, `session run | resume`,
`session cohort`, `report`).

Tiny protocols written by hand (十 and 二, four trials; a real-time one whose trials end at 0.2 s of wall
time, so that a signal lands in a known trial by a poll of the session's log, never a fixed sleep, and a
lock-step one of a few milliseconds a trial): SIGINT, SIGTERM and SIGKILL in a trial, then `session resume`
(every saved file byte for byte as it was, each trial saved and logged once, the log's events in the
documented order, the tables counting what the records say, a killed and resumed session equal to one run
straight through and to `session cohort`); a log that lost its last lines or ends in a torn line; two
runs of one subject started at once, a run and two resumes racing one study folder; `report` while a
session runs; day 2 after day 1 edited, cut or short of a record; a resume after the protocol file changed;
a saved record emptied or cut; a record planted in `trials/`, `trials/` as a symbolic link, the run lock a link
out of the study, a resume through a link, a subject's folder linked into the
study or to another subject's, a study without its identity file, a dead run's temporaries and `.partial.`
folder; `curriculum` of a stopped session and beside a planted record.

CALLIGRAPHY_CLI names the program; CALLIGRAPHY_SANITIZED=1 takes five cases.
"""
import csv
import hashlib
import json
import os
import shutil
import signal
import socket
import subprocess
import tempfile
import time
import unittest
from pathlib import Path

from outsider import CLI, ENV, OneErrorLine, error_lines, run, run_ok, sanitized_subset

load_tests = sanitized_subset({"test_resume_completes_a_log_that_lacks_its_last_save_and_end_once",
                               "test_report_refuses_a_record_planted_beside_the_plan_naming_it",
                               "test_report_refuses_a_subject_folder_linked_into_the_study",
                               "test_resume_refuses_a_trials_folder_that_is_a_symbolic_link",
                               "test_rerun_of_a_finished_one_session_protocol_is_refused_and_changes_nothing"})

# Four trials, 十 二 twice; at real-time pacing each ends at its 0.2 s time limit, so a signal sent once the
# log says a trial started lands in that trial.
RT = {"name": "t30rt", "conditions": [{"name": "v", "mode": "vision"}],
      "test": {"characters": ["十", "二"], "conditions": ["v"], "repetitions": 2},
      "trial": {"max_duration_s": 0.2}}
# The same four trials lock-step at 200 Hz, written through (a few ms each), a 5 s rest (logged, not waited)
# after each.
LS = {"name": "t30ls", "conditions": [{"name": "v", "mode": "vision"}],
      "test": {"characters": ["十", "二"], "conditions": ["v"], "repetitions": 2},
      "breaks": {"every_trials": 1, "duration_s": 5}, "trial": {"max_duration_s": 20, "rate_hz": 200}}
# Two days: 十 trained on day 1, its retention on day 2.
DAYS = {"name": "t30days", "conditions": [{"name": "v", "mode": "vision"}],
        "phases": [{"phase": "training", "condition": "v", "characters": ["十"]},
                   {"phase": "retention", "condition": "v", "characters": ["十"], "session": 2,
                    "delay_s": 60}],
        "trial": {"max_duration_s": 0.2}}
RT_STEMS = ["001-test-v-r1-U5341", "002-test-v-r1-U4E8C", "003-test-v-r2-U5341", "004-test-v-r2-U4E8C"]
POLL_S = 0.02


def write_protocol(path, protocol):
    Path(path).write_text(json.dumps(protocol, ensure_ascii=False), encoding="utf-8")


def start(args, cwd):
    """The program started in the background, its output captured."""
    return subprocess.Popen([CLI, *map(str, args)], cwd=cwd, env=ENV, stdin=subprocess.DEVNULL,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE)


def log_events(log):
    """The log's lines parsed; a line that is not JSON as None."""
    out = []
    for line in Path(log).read_text(encoding="utf-8").splitlines():
        try:
            out.append(json.loads(line))
        except ValueError:
            out.append(None)
    return out


def sessions(study, subject="S01"):
    """The session folders of `subject` (not the hidden ones), by their session.json's session_number."""
    found = {}
    for folder in sorted((Path(study) / subject).iterdir()):
        if folder.name.startswith(".") or not (folder / "session.json").is_file():
            continue
        manifest = json.loads((folder / "session.json").read_text(encoding="utf-8"))
        found[manifest.get("session_number", 1)] = folder
    return found


def wait_for(predicate, what, timeout=30, poll_s=POLL_S):
    """Polls `predicate` every `poll_s` until it holds; fails naming `what` after `timeout` s."""
    end = time.monotonic() + timeout
    while time.monotonic() < end:
        try:
            if predicate():
                return
        except (OSError, ValueError):
            pass
        time.sleep(poll_s)
    raise AssertionError(f"timed out waiting for {what}")


def trial_started(study, trial, session_number=1, subject="S01"):
    """A predicate: the log of the subject's session `session_number` says trial `trial` started."""
    def holds():
        folder = sessions(study, subject).get(session_number)
        if folder is None:
            return False
        return any(e and e.get("event") == "trial_started" and e.get("trial") == trial
                   for e in log_events(folder / "log.jsonl"))
    return holds


def stop_in_trial(args, cwd, study, trial, sig, session_number=1):
    """Starts `session run`, waits until the log says `trial` started, sends `sig`; returns the result."""
    p = start(args, cwd)
    try:
        wait_for(trial_started(study, trial, session_number), f"trial {trial} of session {session_number}")
    finally:
        p.send_signal(sig)
        out, err = p.communicate(timeout=60)
    return subprocess.CompletedProcess(p.args, p.returncode, out, err)


def snapshot(folder):
    """{relative path: bytes} of every file under `folder` (links as their target text)."""
    got = {}
    for root, dirs, files in os.walk(folder):
        for name in files + [d for d in dirs if os.path.islink(os.path.join(root, d))]:
            path = os.path.join(root, name)
            rel = os.path.relpath(path, folder)
            got[rel] = ("->" + os.readlink(path)) if os.path.islink(path) else Path(path).read_bytes()
    return got


def sha256(path):
    return hashlib.sha256(Path(path).read_bytes()).hexdigest()


def table(path):
    with open(path, encoding="utf-8", newline="") as f:
        return list(csv.DictReader(f))


def records(folder):
    """{stem: parsed record} of the saved trials of a session folder."""
    return {p.name[:-len(".json")]: json.loads(p.read_text(encoding="utf-8"))
            for p in sorted((Path(folder) / "trials").glob("*.json"))}


def finish(p):
    """The result of a started run, once it ended."""
    out, err = p.communicate(timeout=60)
    return subprocess.CompletedProcess(p.args, p.returncode, out, err)


def stop_line(result, signame):
    lines = [line for line in error_lines(result) if f"stopped by {signame}" in line]
    return lines


class Round30C(unittest.TestCase, OneErrorLine):
    def assert_run_error(self, result, status, *needles):
        """As assert_one_error, for `session run`, which prints its plan on standard error before it refuses
        (docs/cli.md): the one line that is an error, no traceback. Returns the line."""
        text = result.stderr.decode("utf-8", "replace")
        statuses = status if isinstance(status, tuple) else (status,)
        self.assertIn(result.returncode, statuses, text)
        self.assertNotIn("Traceback", text)
        self.assertNotIn("terminate called", text)
        errors = [line for line in error_lines(result) if ": error:" in line]
        self.assertEqual(len(errors), 1, f"expected one error line, got {error_lines(result)!r}")
        for needle in needles:
            self.assertIn(needle, errors[0])
        return errors[0]

    @classmethod
    def setUpClass(cls):
        cls.tmp = Path(tempfile.mkdtemp(prefix="round30c-"))
        for name, protocol in (("rt.json", RT), ("ls.json", LS), ("days.json", DAYS)):
            write_protocol(cls.tmp / name, protocol)
        cls.made = {}

    @classmethod
    def template(cls, name):
        """A template study, made at its first use: `stopped`, a session stopped by SIGINT in its second trial
        (trial 1 saved, trial 2 kept as an attempt); `complete`, a lock-step session written through; `days`,
        day 1 written and day 2 stopped by SIGINT in its first trial (nothing of day 2 saved). Returns the
        run's result."""
        if name not in cls.made:
            t = cls.tmp
            if name == "stopped":
                cls.made[name] = stop_in_trial(["session", "run", "rt.json", "--subject", "S01", "--out", name,
                                                "--pacing", "real-time"], t, t / name, 2, signal.SIGINT)
            elif name == "complete":
                cls.made[name] = run(["session", "run", "ls.json", "--subject", "S01", "--out", name], t)
            else:
                cls.made[name] = stop_in_trial(["session", "run", "days.json", "--subject", "S01", "--out", name,
                                                "--pacing", "real-time"], t, t / name, 1, signal.SIGINT,
                                               session_number=2)
        return cls.made[name]

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.tmp, ignore_errors=True)

    def setUp(self):
        self.d = Path(tempfile.mkdtemp(prefix="case-", dir=self.tmp))
        for name in ("rt.json", "ls.json", "days.json"):
            shutil.copy(self.tmp / name, self.d / name)

    def tearDown(self):
        shutil.rmtree(self.d, ignore_errors=True)

    def copy_of(self, template):
        """A copy of a template study (its hidden identity and lock files too) in the case's folder."""
        made = self.template(template)
        self.assertIn(made.returncode, (0, 130), made.stderr.decode("utf-8", "replace"))
        shutil.copytree(self.tmp / template, self.d / template, symlinks=True)
        return self.d / template

    # --- stopping -------------------------------------------------------------------------------------------

    def test_sigint_in_a_trial_exits_130_keeps_the_attempt_and_logs_the_stop(self):
        r = self.template("stopped")
        self.assertEqual(r.returncode, 130, r.stderr.decode("utf-8", "replace"))
        study = self.copy_of("stopped")
        folder = sessions(study)[1]
        # docs/cli.md: "calligraphy session run: stopped by SIGINT; resume with: calligraphy session resume DIR"
        lines = stop_line(r, "SIGINT")
        self.assertEqual(len(lines), 1, error_lines(r))
        self.assertTrue(lines[0].startswith("calligraphy session run: stopped by SIGINT"), lines[0])
        self.assertIn("resume with: calligraphy session resume", lines[0])
        self.assertIn(folder.name, lines[0])
        self.assertNotIn("Traceback", r.stderr.decode("utf-8", "replace"))
        # "S01: 1 of 4 trials saved (1 now, 1 attempt kept) in DIR, 3.4 s"
        self.assertIn("S01: 1 of 4 trials saved (1 now, 1 attempt kept)", r.stdout.decode("utf-8"))
        self.assertEqual(sorted(records(folder)), RT_STEMS[:1])
        attempt = folder / "trials" / "attempts" / f"{RT_STEMS[1]}.attempt-1.json"
        self.assertTrue(attempt.is_file(), sorted(os.listdir(folder / "trials" / "attempts")))
        a = json.loads(attempt.read_text(encoding="utf-8"))
        self.assertEqual(a["end_reason"], "interrupted")
        self.assertEqual(a["abort_reason"], "stopped by SIGINT")
        events = log_events(folder / "log.jsonl")
        self.assertNotIn(None, events)
        kinds = [e["event"] for e in events]
        self.assertEqual(kinds, ["session_created", "session_started", "trial_started", "trial_saved",
                                 "trial_started", "trial_interrupted", "session_stopped"])
        interrupted, stopped = events[-2], events[-1]
        self.assertEqual(interrupted["trial"], 2)
        self.assertEqual(interrupted["file"], RT_STEMS[1])
        self.assertEqual(interrupted["reason"], "SIGINT")
        self.assertEqual(interrupted["abort_reason"], "stopped by SIGINT")
        self.assertTrue(str(interrupted["attempt"]).startswith(f"{RT_STEMS[1]}.attempt-1"), interrupted)
        self.assertEqual((stopped["saved_trials"], stopped["planned"], stopped["reason"]), (1, 4, "SIGINT"))

    def test_resume_after_sigterm_saves_each_unsaved_trial_once_and_leaves_saved_bytes(self):
        r = stop_in_trial(["session", "run", "rt.json", "--subject", "S01", "--out", "st", "--pacing",
                           "real-time"], self.d, self.d / "st", 3, signal.SIGTERM)
        self.assertEqual(r.returncode, 143, r.stderr.decode("utf-8", "replace"))
        self.assertEqual(len(stop_line(r, "SIGTERM")), 1, error_lines(r))
        self.assertIn("S01: 2 of 4 trials saved (2 now, 1 attempt kept)", r.stdout.decode("utf-8"))
        folder = sessions(self.d / "st")[1]
        before = snapshot(folder / "trials")
        log_before = (folder / "log.jsonl").read_bytes()
        run_ok(["session", "resume", folder, "--pacing", "lock-step"], self.d)
        after = snapshot(folder / "trials")
        for rel, data in before.items():
            self.assertEqual(after.get(rel), data, f"{rel} changed by the resume")
        self.assertEqual(sorted(records(folder)), RT_STEMS)
        log = (folder / "log.jsonl").read_bytes()
        self.assertTrue(log.startswith(log_before), "the log is append-only")
        events = log_events(folder / "log.jsonl")
        self.assertNotIn(None, events)
        saved = [e["trial"] for e in events if e["event"] == "trial_saved"]
        self.assertEqual(saved, [1, 2, 3, 4])
        resumed = [e for e in events if e["event"] == "session_resumed"]
        self.assertEqual(len(resumed), 1)
        self.assertEqual((resumed[0]["saved_trials"], resumed[0]["next_trial"]), (2, 3))
        self.assertEqual(events[-1]["event"], "session_completed")
        self.assertEqual(events[-1]["trials"], 4)
        times = [e["time_utc"] for e in events]
        self.assertEqual(times, sorted(times))
        for t in times:  # "2026-11-28T05:03:17.441Z": UTC to the millisecond
            self.assertRegex(t, r"^\d{4}-\d\d-\d\dT\d\d:\d\d:\d\d\.\d{3}Z$")
        version = run_ok(["--version"], self.d).stdout.decode().split()[-1]
        self.assertEqual({e["library"] for e in events if e["event"] in ("session_started", "session_resumed")},
                         {version})
        # The tables count what the records say.
        (self.d / "T").mkdir()
        run_ok(["report", "st", "--csv", "T"], self.d)
        rows = table(self.d / "T" / "trials.csv")
        self.assertEqual(sorted(int(row["trial"]) for row in rows), [1, 2, 3, 4])
        recs = records(folder)
        for row in rows:
            rec = recs[RT_STEMS[int(row["trial"]) - 1]]
            self.assertEqual(row["end_reason"], rec["end_reason"])
            self.assertEqual(row["characters"], rec["characters"])
            self.assertEqual(row["start_utc"], rec["start_time_utc"])
        strokes = table(self.d / "T" / "strokes.csv")
        self.assertEqual(len(strokes), sum(len(rec["per_stroke"]) for rec in recs.values()))
        # Each trial event carries its planned trial's fields; session_created carries session.json's.
        manifest = json.loads((folder / "session.json").read_text(encoding="utf-8"))
        plan = {entry["index"]: entry for entry in manifest["plan"]}
        for e in events:
            if "trial" in e and e["event"] != "session_completed":
                entry = plan[e["trial"]]
                for key in ("phase", "condition", "characters", "repetition", "file"):
                    self.assertEqual(e[key], entry[key], (e, key))
        created = events[0]
        self.assertEqual(created["event"], "session_created")
        self.assertEqual((created["subject"], created["subject_number"], created["protocol"],
                          created["protocol_sha256"], created["trials_planned"]),
                         (manifest["subject"]["id"], manifest["subject"]["number"], manifest["protocol"]["name"],
                          manifest["protocol"]["sha256"], len(manifest["plan"])))
        # trial_started's skills are the record's and the table's; trial_saved's time_s the record's.
        by_trial = {int(row["trial"]): row for row in rows}
        last_start = {}
        for e in events:
            if e["event"] == "trial_started":
                last_start[e["trial"]] = e
            if e["event"] == "trial_saved":
                rec = recs[RT_STEMS[e["trial"] - 1]]
                self.assertEqual(e["time_s"], rec["total_time_s"])
                self.assertEqual(e["end_reason"], rec["end_reason"])
                self.assertEqual(float(by_trial[e["trial"]]["shape_skill"]), last_start[e["trial"]]["shape_skill"])
        # A resume with nothing left says so and leaves the log as it is.
        log = (folder / "log.jsonl").read_bytes()
        again = run_ok(["session", "resume", folder], self.d)
        self.assertIn("saved already", again.stdout.decode("utf-8") + again.stderr.decode("utf-8"))
        self.assertEqual((folder / "log.jsonl").read_bytes(), log)

    def test_sigkill_in_a_trial_then_resume_runs_the_lost_trial_again_and_logs_in_order(self):
        r = stop_in_trial(["session", "run", "rt.json", "--subject", "S01", "--out", "st", "--pacing",
                           "real-time"], self.d, self.d / "st", 2, signal.SIGKILL)
        self.assertEqual(r.returncode, -signal.SIGKILL)
        folder = sessions(self.d / "st")[1]
        events = log_events(folder / "log.jsonl")
        self.assertEqual(events[-1]["event"], "trial_started")
        self.assertEqual(events[-1]["trial"], 2)
        # What a kill as trial 2 was saved leaves at worst: temporaries of the dead run beside the records.
        dead = subprocess.Popen(["/bin/true"])
        dead.wait()
        for name in (f".{RT_STEMS[1]}.trace.h5.tmp-{dead.pid}-1", f".{RT_STEMS[1]}.svg.tmp-{dead.pid}-2",
                     f".{RT_STEMS[1]}.json.tmp-{dead.pid}-3"):
            (folder / "trials" / name).write_bytes(b"half a file")
        saved_before = snapshot(folder / "trials")
        run_ok(["session", "resume", folder, "--pacing", "lock-step"], self.d)
        after = snapshot(folder / "trials")
        for rel, data in saved_before.items():
            if rel.endswith(".json") and "/" not in rel:
                self.assertEqual(after.get(rel), data, f"{rel} changed by the resume")
        self.assertEqual(sorted(records(folder)), RT_STEMS)
        stray = [rel for rel in after if not rel.startswith("attempts/")
                 and not any(rel.startswith(stem + ".") for stem in RT_STEMS)]
        self.assertEqual(stray, [], "a dead run's temporaries are removed by the resume")
        events = log_events(folder / "log.jsonl")
        kinds = [e["event"] for e in events if e]
        i = kinds.index("session_resumed")
        self.assertEqual(events[i]["next_trial"], 2)
        self.assertEqual(events[i]["saved_trials"], 1)
        self.assertEqual([e["trial"] for e in events if e and e["event"] == "trial_saved"], [1, 2, 3, 4])
        self.assertEqual(kinds[-1], "session_completed")
        self.assertEqual(kinds.count("session_completed"), 1)

    def test_killed_lockstep_session_resumed_equals_one_run_straight_through_and_the_cohort(self):
        p = start(["session", "run", "ls.json", "--subject", "S01", "--out", "killed"], self.d)
        try:
            wait_for(lambda: any((self.d / "killed" / "S01").glob("*/trials/001-*.json")), "the first record",
                     poll_s=0.001)
        finally:
            p.kill()
            p.communicate()
        folder = sessions(self.d / "killed")[1]
        if len(records(folder)) == 4:
            self.skipTest("the run had saved every trial before the kill")
        n = len(log_events(folder / "log.jsonl"))
        run_ok(["session", "resume", folder], self.d)
        # A break is logged before each trial its plan rests before, but not before a run's first trial.
        plan = {e["index"]: e["break_before_s"]
                for e in json.loads((folder / "session.json").read_text(encoding="utf-8"))["plan"]}
        added = [e for e in log_events(folder / "log.jsonl")[n:] if e and e["event"] in ("break", "trial_started")]
        self.assertEqual(added[0]["event"], "trial_started", added[:2])
        for before, e in zip(added, added[1:]):
            if e["event"] == "trial_started":
                self.assertGreater(plan[e["trial"]], 0)
                self.assertEqual(before["event"], "break", e)
                self.assertEqual((before["before_trial"], before["duration_s"], before["waited"]),
                                 (e["trial"], plan[e["trial"]], False))
        for name in ("Tk", "Ts", "Tc"):
            (self.d / name).mkdir()
        run_ok(["report", "killed", "--csv", "Tk"], self.d)
        run_ok(["report", self.copy_of("complete"), "--csv", "Ts"], self.d)
        run_ok(["session", "cohort", "ls.json", "--subjects", "1", "--csv", "Tc", "--jobs", "1"], self.d)
        differ = {"session", "start_utc", "trace_file"}
        killed, straight, cohort = (table(self.d / n / "trials.csv") for n in ("Tk", "Ts", "Tc"))
        self.assertEqual(len(straight), 4)
        self.assertEqual([{k: v for k, v in a.items() if k not in differ} for a in killed],
                         [{k: v for k, v in b.items() if k not in differ} for b in straight])
        self.assertEqual(len(cohort), 4)
        for a, c in zip(straight, cohort):
            self.assertEqual({k: v for k, v in a.items() if k not in differ | {"trace_sha256"}},
                             {k: v for k, v in c.items() if k not in differ | {"trace_sha256"}})

    def test_ignored_sighup_goes_on_and_sigusr2_stops_with_140(self):
        p = subprocess.Popen([CLI, "session", "run", "rt.json", "--subject", "S01", "--out", "nohup", "--pacing",
                              "real-time"], cwd=self.d, env=ENV, stdin=subprocess.DEVNULL, stdout=subprocess.PIPE,
                             stderr=subprocess.PIPE, preexec_fn=lambda: signal.signal(signal.SIGHUP, signal.SIG_IGN))
        try:
            wait_for(trial_started(self.d / "nohup", 2), "the second trial")
            p.send_signal(signal.SIGHUP)  # nohup: ignored when the command started, so it stays ignored
            wait_for(trial_started(self.d / "nohup", 3), "the third trial")
        finally:
            p.send_signal(signal.SIGUSR2)
            r = finish(p)
        self.assertEqual(r.returncode, 140, r.stderr.decode("utf-8", "replace"))
        self.assertEqual(len(stop_line(r, "SIGUSR2")), 1, error_lines(r))
        folder = sessions(self.d / "nohup")[1]
        self.assertEqual(sorted(records(folder)), RT_STEMS[:2])
        events = log_events(folder / "log.jsonl")
        self.assertEqual([e["event"] for e in events if e["event"] in ("trial_interrupted", "session_stopped")],
                         ["trial_interrupted", "session_stopped"])
        self.assertEqual(events[-1]["reason"], "SIGUSR2")
        self.assertEqual(events[-1]["saved_trials"], 2)
        a = json.loads((folder / "trials" / "attempts" / f"{RT_STEMS[2]}.attempt-1.json").read_text("utf-8"))
        self.assertEqual(a["abort_reason"], "stopped by SIGUSR2")

    def test_resume_completes_a_log_that_lacks_its_last_save_and_end_once(self):
        study = self.copy_of("complete")
        folder = sessions(study)[1]
        log = folder / "log.jsonl"
        lines = log.read_bytes().splitlines(keepends=True)
        self.assertEqual([json.loads(x)["event"] for x in lines[-2:]], ["trial_saved", "session_completed"])
        # A run killed after its last record was linked, before it logged the save.
        cut = b"".join(lines[:-2])
        log.write_bytes(cut)
        trials_before = snapshot(folder / "trials")
        r = run_ok(["session", "resume", folder], self.d)
        self.assertIn("saved already", r.stdout.decode("utf-8") + r.stderr.decode("utf-8"))
        self.assertEqual(snapshot(folder / "trials"), trials_before)
        text = log.read_bytes()
        self.assertTrue(text.startswith(cut))
        added = [json.loads(x) for x in text[len(cut):].splitlines()]
        self.assertEqual([e["event"] for e in added], ["trial_saved", "session_resumed", "session_completed"])
        self.assertEqual((added[0]["trial"], added[0].get("recovered")), (4, True))
        self.assertIsNone(added[1]["next_trial"])
        run_ok(["session", "resume", folder], self.d)
        self.assertEqual(log.read_bytes(), text, "a log ending in session_completed is left as it is")

    def test_torn_last_log_line_stays_alone_and_the_resume_logs_on_its_own_lines(self):
        study = self.copy_of("complete")
        folder = sessions(study)[1]
        log = folder / "log.jsonl"
        lines = log.read_bytes().splitlines(keepends=True)
        torn = lines[-2][:40]  # the last trial_saved, torn by the kill as it was appended
        log.write_bytes(b"".join(lines[:-2]) + torn)
        run_ok(["session", "resume", folder], self.d)
        got = log.read_bytes().splitlines()
        self.assertIn(torn, got, "the torn line stands alone, as it was")
        after = got[got.index(torn) + 1:]
        self.assertTrue(after)
        events = [json.loads(x) for x in after]
        self.assertEqual([e["event"] for e in events], ["trial_saved", "session_resumed", "session_completed"])
        self.assertEqual(events[0]["trial"], 4)

    def test_a_second_signal_while_the_stop_is_written_is_ignored(self):
        p = start(["session", "run", "rt.json", "--subject", "S01", "--out", "twice", "--pacing", "real-time"],
                  self.d)
        try:
            wait_for(trial_started(self.d / "twice", 2), "the second trial")
        finally:
            p.send_signal(signal.SIGINT)
            time.sleep(0.005)  # past the trial's next tick (1 ms): the stop is being written
            while p.poll() is None:
                p.send_signal(signal.SIGTERM)
                time.sleep(0.001)
            r = finish(p)
        self.assertEqual(r.returncode, 130, r.stderr.decode("utf-8", "replace"))
        folder = sessions(self.d / "twice")[1]
        a = json.loads((folder / "trials" / "attempts" / f"{RT_STEMS[1]}.attempt-1.json").read_text("utf-8"))
        self.assertEqual(a["abort_reason"], "stopped by SIGINT")
        events = log_events(folder / "log.jsonl")
        self.assertNotIn(None, events)
        self.assertEqual([e["event"] for e in events[-2:]], ["trial_interrupted", "session_stopped"])
        self.assertEqual(events[-1]["reason"], "SIGINT")

    def test_sigint_during_a_resume_keeps_a_second_attempt_and_names_resume(self):
        study = self.copy_of("stopped")
        folder = sessions(study)[1]
        first = (folder / "trials" / "attempts" / f"{RT_STEMS[1]}.attempt-1.json").read_bytes()
        n = len(log_events(folder / "log.jsonl"))
        p = start(["session", "resume", folder], self.d)
        try:
            wait_for(lambda: any(e and e.get("event") == "trial_started"
                                 for e in log_events(folder / "log.jsonl")[n:]), "the resumed trial")
        finally:
            p.send_signal(signal.SIGINT)
            r = finish(p)
        self.assertEqual(r.returncode, 130, r.stderr.decode("utf-8", "replace"))
        lines = stop_line(r, "SIGINT")
        self.assertEqual(len(lines), 1, error_lines(r))
        self.assertTrue(lines[0].startswith("calligraphy session resume: stopped by SIGINT"), lines[0])
        attempts = folder / "trials" / "attempts"
        self.assertEqual((attempts / f"{RT_STEMS[1]}.attempt-1.json").read_bytes(), first)
        second = json.loads((attempts / f"{RT_STEMS[1]}.attempt-2.json").read_text("utf-8"))
        self.assertEqual(second["abort_reason"], "stopped by SIGINT")
        added = log_events(folder / "log.jsonl")[n:]
        self.assertEqual([e["event"] for e in added],
                         ["session_resumed", "trial_started", "trial_interrupted", "session_stopped"])
        self.assertEqual((added[0]["saved_trials"], added[0]["next_trial"]), (1, 2))
        self.assertTrue(str(added[2]["attempt"]).startswith(f"{RT_STEMS[1]}.attempt-2"), added[2])
        self.assertEqual(sorted(records(folder)), RT_STEMS[:1])

    # --- races ----------------------------------------------------------------------------------------------

    def test_two_runs_of_one_subject_started_together_leave_one_session(self):
        procs = [start(["session", "run", "ls.json", "--subject", "S01", "--out", "race"], self.d)
                 for _ in range(2)]
        results = [finish(p) for p in procs]
        codes = sorted(r.returncode for r in results)
        self.assertEqual(codes.count(0), 1, [(r.returncode, r.stderr) for r in results])
        for r in results:
            if r.returncode:
                self.assertIn(r.returncode, (1, 2))
                errors = [line for line in error_lines(r) if "error" in line]
                self.assertEqual(len(errors), 1, error_lines(r))
                self.assertNotIn("Traceback", r.stderr.decode("utf-8", "replace"))
        subject = self.d / "race" / "S01"
        self.assertEqual([n for n in os.listdir(subject) if n.startswith(".partial")], [])
        self.assertEqual(len(sessions(self.d / "race")), 1)
        self.assertEqual(len(records(sessions(self.d / "race")[1])), 4)
        (self.d / "T").mkdir()
        run_ok(["report", "race", "--csv", "T"], self.d)
        self.assertEqual(len(table(self.d / "T" / "trials.csv")), 4)

    def test_run_and_resumes_into_a_study_another_run_holds_are_refused_naming_the_holder(self):
        study = self.copy_of("stopped")
        folder = sessions(study)[1]
        os.symlink(folder, self.d / "alias")
        before = snapshot(folder)
        p = start(["session", "run", "rt.json", "--subject", "S02", "--out", study, "--pacing", "real-time"], self.d)
        try:
            wait_for(trial_started(study, 1, subject="S02"), "the first trial of S02")
            lock = study / ".calligraphy-run.lock"
            self.assertIn(str(p.pid), lock.read_text(encoding="utf-8", errors="replace"))
            other_run = run(["session", "run", "rt.json", "--subject", "S03", "--out", study], self.d)
            resume = run(["session", "resume", folder, "--pacing", "lock-step"], self.d)
            # DIR/../.. of the link is not the study: the lock is the session's own study folder's.
            resume_by_link = run(["session", "resume", self.d / "alias", "--pacing", "lock-step"], self.d)
            still = p.poll() is None
        finally:
            p.send_signal(signal.SIGINT)
            p.communicate(timeout=60)
        self.assertTrue(still, "the run ended before the others were refused")
        line = self.assert_run_error(other_run, 1, study.name)
        self.assertIn(str(p.pid), line)
        self.assertFalse((study / "S03").exists())
        self.assertIn(str(p.pid), self.assert_one_error(resume, 1))
        self.assertIn(str(p.pid), self.assert_one_error(resume_by_link, 1))
        self.assertEqual(snapshot(folder), before)
        self.assertEqual(p.returncode, 130)
        self.assertEqual(lock.read_bytes(), b"", "the lock file is empty after the run")

    def test_two_resumes_of_one_session_at_once_one_runs_and_the_other_is_refused(self):
        study = self.copy_of("stopped")
        folder = sessions(study)[1]
        procs = [start(["session", "resume", folder], self.d) for _ in range(2)]
        results = [finish(p) for p in procs]
        codes = sorted(r.returncode for r in results)
        self.assertEqual(codes, [0, 1], [(r.returncode, r.stderr) for r in results])
        refused = [r for r in results if r.returncode == 1][0]
        self.assert_one_error(refused, 1)
        self.assertEqual(sorted(records(folder)), RT_STEMS)
        events = log_events(folder / "log.jsonl")
        self.assertNotIn(None, events)
        self.assertEqual([e["trial"] for e in events if e["event"] == "trial_saved"], [1, 2, 3, 4])
        self.assertEqual([e["event"] for e in events].count("session_resumed"), 1)

    def test_report_while_a_session_runs_reads_only_saved_trials(self):
        p = start(["session", "run", "rt.json", "--subject", "S01", "--out", "live", "--pacing", "real-time"],
                  self.d)
        try:
            wait_for(trial_started(self.d / "live", 2), "the second trial")
            (self.d / "T").mkdir()
            r = run(["report", "live", "--csv", "T", "--jobs", "1"], self.d)
            still = p.poll() is None
        finally:
            p.send_signal(signal.SIGINT)
            stopped = finish(p)
        self.assertEqual(r.returncode, 0, r.stderr.decode("utf-8", "replace"))
        self.assertTrue(still, "the run ended before the report")
        self.assertEqual(stopped.returncode, 130, stopped.stderr.decode("utf-8", "replace"))
        rows = table(self.d / "T" / "trials.csv")
        trials = [int(row["trial"]) for row in rows]
        self.assertTrue(1 <= len(trials) <= 3, trials)
        self.assertEqual(trials, list(range(1, len(trials) + 1)))
        (self.d / "T2").mkdir()
        run_ok(["report", "live", "--csv", "T2"], self.d)
        saved = sorted(records(sessions(self.d / "live")[1]))
        self.assertEqual([RT_STEMS[int(row["trial"]) - 1] for row in table(self.d / "T2" / "trials.csv")], saved)

    # --- days -----------------------------------------------------------------------------------------------

    def test_day2_stopped_at_its_first_trial_resumes_linked_to_day1(self):
        made = self.template("days")
        self.assertEqual(made.returncode, 130, made.stderr.decode("utf-8", "replace"))
        study = self.copy_of("days")
        day = sessions(study)
        self.assertEqual(sorted(day), [1, 2])
        day1_before = snapshot(day[1])
        run_ok(["session", "resume", day[2], "--pacing", "lock-step"], self.d)
        self.assertEqual(snapshot(day[1]), day1_before)
        events = log_events(day[2] / "log.jsonl")
        kinds = [e["event"] for e in events]
        self.assertNotIn("session_resumed", kinds)
        self.assertEqual(kinds.count("session_started"), 2)
        second = [e for e in events if e["event"] == "session_started"][1]
        self.assertEqual((second["saved_trials"], second["next_trial"]), (0, 1))
        self.assertEqual(kinds[-1], "session_completed")
        manifest = json.loads((day[2] / "session.json").read_text(encoding="utf-8"))
        prev = manifest["previous_session"]
        last = list(records(day[1]).values())[-1]
        self.assertEqual(manifest["session_number"], 2)
        self.assertEqual(prev["session_id"], day[1].name)
        self.assertEqual(prev["ended_utc"], last["end_time_utc"])
        self.assertEqual(prev["session_sha256"], sha256(day[1] / "session.json"))
        self.assertEqual(prev["delay"], "simulated")
        self.assertEqual(prev["delay_s"], 60)
        # Both days saved: a run again reports the subject done and writes nothing.
        before = snapshot(study)
        r = run(["session", "run", "days.json", "--subject", "S01", "--out", study], self.d)
        self.assertEqual(r.returncode, 0, r.stderr.decode("utf-8", "replace"))
        after = snapshot(study)
        self.assertEqual({k: v for k, v in after.items() if k != ".calligraphy-run.lock"},
                         {k: v for k, v in before.items() if k != ".calligraphy-run.lock"})
        # Day 1, every trial saved and its log completed, is left as it is by a resume.
        run_ok(["session", "resume", day[1]], self.d)
        self.assertEqual(snapshot(day[1]), day1_before)

    def test_day2_resume_after_day1_manifest_edited_is_refused_naming_it(self):
        study = self.copy_of("days")
        day = sessions(study)
        manifest = day[1] / "session.json"
        manifest.write_bytes(manifest.read_bytes() + b"\n")  # still the same JSON, another SHA-256
        day2_before = snapshot(day[2])
        r = run(["session", "resume", day[2], "--pacing", "lock-step"], self.d)
        self.assert_one_error(r, 1, "session.json", day[1].name)
        self.assertEqual(snapshot(day[2]), day2_before)

    def test_day2_after_day1_last_record_without_end_is_refused_naming_it(self):
        study = self.copy_of("days")
        day = sessions(study)
        shutil.rmtree(day[2])
        stem, rec = list(records(day[1]).items())[-1]
        rec["end_time_utc"] = None
        (day[1] / "trials" / f"{stem}.json").write_text(json.dumps(rec, ensure_ascii=False), encoding="utf-8")
        listing = sorted(os.listdir(study / "S01"))
        r = run(["session", "run", "days.json", "--subject", "S01", "--out", study], self.d)
        self.assert_run_error(r, 1, f"{stem}.json", day[1].name, "did not end")
        self.assertEqual(sorted(os.listdir(study / "S01")), listing)

    def test_day2_after_day1_record_cut_short_is_refused_naming_it(self):
        study = self.copy_of("days")
        day = sessions(study)
        shutil.rmtree(day[2])
        stem = list(records(day[1]))[-1]
        path = day[1] / "trials" / f"{stem}.json"
        data = path.read_bytes()
        path.write_bytes(data[:len(data) // 2])
        listing = sorted(os.listdir(study / "S01"))
        r = run(["session", "run", "days.json", "--subject", "S01", "--out", study], self.d)
        self.assert_run_error(r, 1, f"{stem}.json")
        self.assertEqual(sorted(os.listdir(study / "S01")), listing)

    def test_day1_missing_a_record_that_day2_follows_is_not_resumed(self):
        study = self.copy_of("days")
        day = sessions(study)
        stem = list(records(day[1]))[-1]
        (day[1] / "trials" / f"{stem}.json").unlink()
        day1_before = snapshot(day[1])
        r = run(["session", "resume", day[1], "--pacing", "lock-step"], self.d)
        self.assert_one_error(r, 1, stem, day[2].name)
        self.assertEqual(snapshot(day[1]), day1_before)

    def test_day2_after_day1_with_an_unsaved_trial_names_session_resume(self):
        study = self.copy_of("days")
        day = sessions(study)
        shutil.rmtree(day[2])
        stem = list(records(day[1]))[-1]
        (day[1] / "trials" / f"{stem}.json").unlink()
        listing = sorted(os.listdir(study / "S01"))
        r = run(["session", "run", "days.json", "--subject", "S01", "--out", study], self.d)
        self.assert_run_error(r, (1, 2), "session resume", day[1].name)
        self.assertEqual(sorted(os.listdir(study / "S01")), listing)

    def test_run_for_a_subject_whose_folder_links_to_another_subjects_is_refused(self):
        study = self.copy_of("days")
        os.symlink(study / "S01", study / "S02")
        before = snapshot(study / "S01")
        r = run(["session", "run", "days.json", "--subject", "S02", "--out", study], self.d)
        self.assert_run_error(r, 1, "S02")
        self.assertEqual(snapshot(study / "S01"), before)

    # --- the protocol changed -------------------------------------------------------------------------------

    def test_resume_follows_its_plan_after_the_protocol_file_changed_and_a_new_run_is_refused(self):
        study = self.copy_of("stopped")
        folder = sessions(study)[1]
        original = sha256(self.d / "rt.json")
        edited = dict(RT, test={"characters": ["十", "二", "口"], "conditions": ["v"], "repetitions": 3})
        write_protocol(self.d / "rt.json", edited)
        manifest = (folder / "session.json").read_bytes()
        run_ok(["session", "resume", folder, "--pacing", "lock-step"], self.d)
        self.assertEqual(sorted(records(folder)), RT_STEMS)
        self.assertEqual((folder / "session.json").read_bytes(), manifest)
        listing = sorted(os.listdir(study))
        r = run(["session", "run", "rt.json", "--subject", "S02", "--out", study], self.d)
        self.assert_run_error(r, 1, "rt.json", folder.name, original, sha256(self.d / "rt.json"))
        self.assertEqual(sorted(os.listdir(study)), listing)

    def test_resume_needs_no_protocol_file_and_no_working_folder_of_the_run(self):
        study = self.copy_of("stopped")
        folder = sessions(study)[1]
        (self.d / "rt.json").unlink()
        r = run(["session", "resume", folder.resolve(), "--pacing", "lock-step"], "/")
        self.assertEqual(r.returncode, 0, r.stderr.decode("utf-8", "replace"))
        self.assertEqual(sorted(records(folder)), RT_STEMS)

    def test_rerun_of_a_finished_one_session_protocol_is_refused_and_changes_nothing(self):
        study = self.copy_of("complete")
        before = snapshot(study)
        r = run(["session", "run", "ls.json", "--subjects", "1", "--out", study], self.d)
        self.assert_run_error(r, 2, "S01", "--new-subjects")
        after = snapshot(study)
        self.assertEqual({k: v for k, v in after.items() if k != ".calligraphy-run.lock"},
                         {k: v for k, v in before.items() if k != ".calligraphy-run.lock"})

    # --- planted files, links -------------------------------------------------------------------------------

    def test_report_refuses_a_record_planted_beside_the_plan_naming_it(self):
        study = self.copy_of("complete")
        folder = sessions(study)[1]
        src = folder / "trials" / "001-test-v-r1-U5341.json"
        planted = folder / "trials" / "005-test-v-r3-U5341.json"
        shutil.copy(src, planted)
        (self.d / "T").mkdir()
        r = run(["report", study, "--csv", "T"], self.d)
        self.assert_one_error(r, 1, planted.name, "/plan")
        self.assertEqual(os.listdir(self.d / "T"), [])

    def test_resume_refuses_a_record_copied_over_the_next_unsaved_trial(self):
        study = self.copy_of("stopped")
        folder = sessions(study)[1]
        planted = folder / "trials" / f"{RT_STEMS[1]}.json"
        shutil.copy(folder / "trials" / f"{RT_STEMS[0]}.json", planted)
        before = snapshot(folder)
        r = run(["session", "resume", folder, "--pacing", "lock-step"], self.d)
        self.assert_one_error(r, (1, 2), planted.name)
        self.assertEqual(snapshot(folder), before)

    def test_resume_names_a_saved_record_emptied_or_cut_since_with_exit_2(self):
        # docs/cli.md, session resume: "a record cut or emptied since is named (exit 2), as when trials are left"
        for template, cut in (("complete", 0), ("stopped", 2)):
            with self.subTest(template=template, cut=cut):
                study = self.copy_of(template)
                try:
                    folder = sessions(study)[1]
                    record = folder / "trials" / "001-test-v-r1-U5341.json"
                    data = record.read_bytes()
                    record.write_bytes(data[:len(data) // cut] if cut else b"")
                    before = snapshot(folder)
                    r = run(["session", "resume", folder, "--pacing", "lock-step"], self.d)
                    self.assert_one_error(r, 2, record.name)
                    self.assertEqual(snapshot(folder), before)
                finally:
                    shutil.rmtree(study)

    def test_resume_refuses_a_trials_folder_that_is_a_symbolic_link(self):
        study = self.copy_of("stopped")
        folder = sessions(study)[1]
        elsewhere = self.d / "elsewhere"
        shutil.move(str(folder / "trials"), str(elsewhere))
        os.symlink(elsewhere, folder / "trials")
        there = snapshot(elsewhere)
        log = (folder / "log.jsonl").read_bytes()
        r = run(["session", "resume", folder, "--pacing", "lock-step"], self.d)
        self.assert_one_error(r, 2, "trials")
        self.assertEqual(snapshot(elsewhere), there)
        self.assertEqual((folder / "log.jsonl").read_bytes(), log)

    def test_resume_through_a_link_names_the_session_by_its_own_folder(self):
        study = self.copy_of("stopped")
        folder = sessions(study)[1]
        link = self.d / "alias"
        os.symlink(folder, link)
        run_ok(["session", "resume", link, "--pacing", "lock-step"], self.d)
        recs = records(folder)
        self.assertEqual(sorted(recs), RT_STEMS)
        self.assertEqual({rec["session"] for rec in recs.values()}, {folder.name})
        (self.d / "T").mkdir()
        run_ok(["report", study, "--csv", "T"], self.d)
        self.assertEqual({row["session"] for row in table(self.d / "T" / "trials.csv")}, {folder.name})

    def test_report_refuses_a_subject_folder_linked_into_the_study(self):
        study = self.copy_of("complete")
        os.symlink(study / "S01", study / "S07")
        (self.d / "T").mkdir()
        r = run(["report", study, "--csv", "T"], self.d)
        self.assert_one_error(r, 1, "S07")
        self.assertEqual(os.listdir(self.d / "T"), [])

    def test_partial_folder_of_a_dead_run_is_skipped_then_removed_by_the_next_run(self):
        study = self.copy_of("complete")
        dead = subprocess.Popen(["/bin/true"])
        dead.wait()
        (study / "S02").mkdir()
        partial = study / "S02" / f".partial.{dead.pid}.{socket.gethostname()}.t30ls-S02-20260101-000000"
        (partial / "trials").mkdir(parents=True)
        shutil.copy(sessions(study)[1] / "session.json", partial / "session.json")
        (self.d / "T").mkdir()
        run_ok(["report", study, "--csv", "T"], self.d)
        self.assertEqual({row["subject"] for row in table(self.d / "T" / "trials.csv")}, {"S01"})
        r = run(["session", "resume", partial], self.d)
        self.assertNotEqual(r.returncode, 0)
        self.assertEqual(len(error_lines(r)), 1, error_lines(r))
        self.assertIn(partial.name, error_lines(r)[0])
        live = subprocess.Popen(["/bin/sleep", "60"])
        try:
            alive = study / "S02" / f".partial.{live.pid}.{socket.gethostname()}.t30ls-S02-20260101-000001"
            other = study / "S02" / f".partial.{dead.pid}.not-{socket.gethostname()}.t30ls-S02-20260101-000002"
            (alive / "trials").mkdir(parents=True)
            (other / "trials").mkdir(parents=True)
            run_ok(["session", "run", "ls.json", "--subject", "S02", "--out", study], self.d)
        finally:
            live.kill()
            live.wait()
        self.assertFalse(partial.exists(), "the dead run's .partial. folder is removed")
        self.assertTrue(alive.is_dir(), "a running process's .partial. folder is left")
        self.assertTrue(other.is_dir(), "another host's .partial. folder is left")
        self.assertEqual(len(records(sessions(study, "S02")[1])), 4)

    def test_run_lock_planted_as_a_link_outside_the_study_leaves_its_target_alone(self):
        victim = self.d / "notes.txt"
        victim.write_bytes(b"a file outside the study\n")
        study = self.copy_of("stopped")
        (study / ".calligraphy-run.lock").unlink()
        os.symlink(victim, study / ".calligraphy-run.lock")
        run(["session", "run", "ls.json", "--subject", "S02", "--out", study], self.d)
        run(["session", "resume", sessions(study)[1], "--pacing", "lock-step"], self.d)
        self.assertEqual(victim.read_bytes(), b"a file outside the study\n")

    def test_study_without_its_identity_file_is_refused_by_report_and_resume(self):
        study = self.copy_of("stopped")
        (study / ".calligraphy-study.json").unlink()
        folder = sessions(study)[1]
        before = snapshot(folder)
        (self.d / "T").mkdir()
        r = run(["report", study, "--csv", "T"], self.d)
        self.assert_one_error(r, 1, "session.json", "/study_id", ".calligraphy-study.json")
        r = run(["session", "resume", folder, "--pacing", "lock-step"], self.d)
        self.assert_one_error(r, 1, "/study_id")
        r = run(["curriculum", study, "--subject", "S01", "--from", "口"], self.d)
        self.assert_one_error(r, 1, "/study_id")
        self.assertEqual(snapshot(folder), before)
        self.assertFalse((study / ".calligraphy-study.json").exists())

    # --- what to practise next ------------------------------------------------------------------------------

    def test_curriculum_of_a_stopped_session_leaves_out_what_was_written(self):
        study = self.copy_of("stopped")
        r = run_ok(["curriculum", study, "--subject", "S01", "--from", "十口", "--json"], self.d)
        proposed = [entry["character"] for entry in json.loads(r.stdout)]
        self.assertNotIn("十", proposed)
        self.assertEqual(proposed, ["口"])
        r = run(["curriculum", study, "--subject", "S09", "--from", "十口"], self.d)
        self.assert_one_error(r, 2, "S09")

    def test_curriculum_refuses_a_record_planted_beside_the_plan_as_report_does(self):
        study = self.copy_of("complete")
        folder = sessions(study)[1]
        planted = folder / "trials" / "005-test-v-r3-U53E3.json"
        shutil.copy(folder / "trials" / "001-test-v-r1-U5341.json", planted)
        r = run(["curriculum", study, "--subject", "S01", "--from", "口", "--json"], self.d)
        self.assert_one_error(r, 1, planted.name)


if __name__ == "__main__":
    unittest.main()
