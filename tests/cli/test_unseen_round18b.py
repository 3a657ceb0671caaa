#!/usr/bin/env python3
"""Round 18B: the audit trail, from the docs alone (docs/experiments.md "Sessions", "How nothing is lost", "Log
events", "Trial records", "Tidy tables", "Phases"; docs/cli.md "session run | resume"). Run by CTest as
`cli_unseen_round18b_tests`.

Earlier rounds forged or damaged a session's files; this one asks whether a GENUINE run's trail tells what
happened, all of it and only it, as an auditor or a journal's reviewer reads it: the session's log.jsonl (every
event one JSON line of a documented kind with its documented fields, in time order, within the session's
dates; one `trial_saved` per saved trial and none for a trial not saved; one `trial_interrupted` per kept
attempt; a resume logged once as one; `session_completed` last and once), session.json's dates and its
`previous_session`, the trial records' times and end reasons against the log's, and `report --csv` and
`calligraphy.study.load` against the log. The runs: a two-session study (rests, a within-session delay, a
retention session a day later) written straight through lock-step, and sessions in real time stopped by SIGINT,
SIGTERM (at the first trial), SIGHUP, SIGUSR1 and SIGKILL at a chosen trial and resumed lock-step, one of them
stopped again during its resume; logs as a run killed between two appends leaves them; a replay condition whose
teacher is recorded, and one whose teacher cannot be.

CALLIGRAPHY_CLI names the program, PYTHONPATH its Python module. CALLIGRAPHY_SANITIZED=1 takes five cases.
"""
import csv
import datetime
import hashlib
import json
import math
import re
import shutil
import signal
import subprocess
import tempfile
import threading
import time
import unittest
from pathlib import Path

from outsider import CLI, ENV, OneErrorLine, error_lines, run, sanitized_subset

load_tests = sanitized_subset({"test_every_line_is_one_object_of_a_documented_kind",
                               "test_each_saved_trial_has_exactly_one_trial_saved",
                               "test_sigint_mid_trial_keeps_the_attempt_and_logs_it_once",
                               "test_session_completed_counts_equal_the_files",
                               "test_report_tables_agree_with_the_log"})

YI, SHI = "一", "十"
RUN = ["--writer", "simulated", "--writer-learning", "none", "--individual-differences", "off"]
# docs/experiments.md, "Log events".
KINDS = {"session_created", "session_started", "session_resumed", "teacher_saved", "break", "trial_started",
         "trial_saved", "trial_interrupted", "trial_failed", "session_stopped", "session_completed"}
TRIAL_KINDS = {"trial_started", "trial_saved", "trial_interrupted", "trial_failed"}
UTC = re.compile(r"^\d{4}-\d\d-\d\dT\d\d:\d\d:\d\d(\.\d+)?Z$")
# Times in the log and the records are written to the millisecond (`2026-11-28T01:45:43.152Z`).
SLACK_S = 0.002

# Two sessions: a pre-test, two training blocks after a rest, a post-test after a within-session delay, and a
# retention test a day later (its delay simulated).
DAYS = {"name": "d18b",
        "conditions": [{"name": "U", "mode": "vision"}, {"name": "F", "mode": "haptic"}],
        "phases": [{"phase": "pre-test", "condition": "U", "characters": [YI]},
                   {"phase": "training", "conditions": ["U", "F"], "characters": [YI, SHI]},
                   {"phase": "post-test", "condition": "U", "characters": [YI], "delay_s": 30},
                   {"phase": "retention", "condition": "U", "characters": [YI], "session": 2, "delay_s": 86400}],
        "breaks": {"between_blocks_s": 7},
        "trial": {"max_duration_s": 0.4}}
# Four trials of 十 in real time at 100 Hz, each long enough (up to 1.5 s) to be stopped while it runs.
STOP = {"name": "s18b", "conditions": [{"name": "U", "mode": "vision"}],
        "test": {"characters": [SHI], "conditions": ["U"], "repetitions": 4},
        "trial": {"max_duration_s": 1.5, "rate_hz": 100}}

SHARED = {}
STOPPED = ("int", "term", "hup", "kill", "usr")


def parse_utc(text):
    return datetime.datetime.strptime(text.replace("Z", "+0000"), "%Y-%m-%dT%H:%M:%S.%f%z" if "." in text
                                      else "%Y-%m-%dT%H:%M:%S%z").timestamp()


def read_log(session):
    return [json.loads(line) for line in (session / "log.jsonl").read_text(encoding="utf-8").splitlines()]


def kind(event):
    return event["event"]


def trial_number(event):
    return event["trial"]


def sessions_under(out):
    return sorted((p.parent for p in Path(out).glob("*/*/session.json")), key=lambda p: p.name)


def manifest(session):
    return json.loads((session / "session.json").read_text(encoding="utf-8"))


def records(session):
    return {p.name[:-len(".json")]: json.loads(p.read_text(encoding="utf-8"))
            for p in sorted((session / "trials").glob("*.json"))}


def attempts(session):
    return {p.name[:-len(".json")]: json.loads(p.read_text(encoding="utf-8"))
            for p in sorted((session / "trials" / "attempts").glob("*.json"))}


def wait_for(predicate, timeout=30.0):
    end = time.monotonic() + timeout
    while time.monotonic() < end:
        if predicate():
            return True
        time.sleep(0.02)
    return False


def started(session_glob, number, times=1):
    """True once some session under `session_glob` logged trial_started for trial `number` `times` times."""
    def check():
        for log in Path(session_glob).glob("*/*/log.jsonl"):
            seen = 0
            for line in log.read_text(encoding="utf-8").splitlines():
                try:
                    event = json.loads(line)
                except ValueError:
                    continue
                seen += kind(event) == "trial_started" and trial_number(event) == number
            if seen >= times:
                return True
        return False
    return check


def stop_at(tmp, protocol, name, number, sig, resume_dir=None, times=1):
    """`session run` of subject NAME01 (or `session resume resume_dir`) in real time, to be sent `sig` 0.3 s
    after trial `number` started (by `finish`)."""
    out = tmp / name
    if resume_dir is None:
        args = ["session", "run", protocol, "--subjects", "1", "--subject", name.upper(), "--out", out,
                "--pacing", "real-time", *RUN]
    else:
        args = ["session", "resume", resume_dir, "--pacing", "real-time"]
    process = subprocess.Popen([CLI, *map(str, args)], cwd=tmp, env=ENV, stdin=subprocess.DEVNULL,
                               stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    return out, process, number, sig, times


def finish(out, process, number, sig, times):
    """Sends the signal of a `stop_at` run when its trial has run 0.3 s; the finished run and whether the
    trial was seen to start."""
    seen = wait_for(started(out, number, times))
    if seen:
        time.sleep(0.3)
        process.send_signal(sig)
    stdout, stderr = process.communicate(timeout=60)
    return subprocess.CompletedProcess(process.args, process.returncode, stdout, stderr), seen


def resume(tmp, session, *extra):
    return run(["session", "resume", session, "--pacing", "lock-step", *extra], cwd=tmp)


def tree(folder):
    return {p.relative_to(folder): p.read_bytes() for p in sorted(Path(folder).rglob("*")) if p.is_file()}


class Round18B(OneErrorLine, unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.tmp = Path(tempfile.mkdtemp(prefix="r18b-"))
        if SHARED:
            return
        days = cls.tmp / "days.json"
        days.write_text(json.dumps(DAYS, ensure_ascii=False), encoding="utf-8")
        stop = cls.tmp / "stop.json"
        stop.write_text(json.dumps(STOP, ensure_ascii=False), encoding="utf-8")
        # The stopped runs at once (real time costs wall time, not CPU).
        pending = {"int": stop_at(cls.tmp, stop, "int", 2, signal.SIGINT),
                   "term": stop_at(cls.tmp, stop, "term", 1, signal.SIGTERM),
                   "hup": stop_at(cls.tmp, stop, "hup", 3, signal.SIGHUP),
                   "kill": stop_at(cls.tmp, stop, "kill", 2, signal.SIGKILL),
                   "usr": stop_at(cls.tmp, stop, "usr", 2, signal.SIGUSR1)}
        threads = [threading.Thread(target=lambda n=name, a=args: SHARED.__setitem__(n + "_stop", finish(*a)))
                   for name, args in pending.items()]
        for thread in threads:
            thread.start()
        SHARED["days_run"] = run(["session", "run", days, "--subjects", "1", "--out", cls.tmp / "days", *RUN],
                                 cwd=cls.tmp)
        SHARED["days"] = sessions_under(cls.tmp / "days")
        for thread in threads:
            thread.join()
        for name in pending:
            (session,) = sessions_under(cls.tmp / name)
            SHARED[name] = session
            SHARED[name + "_stopped_tree"] = tree(session)
            SHARED[name + "_stopped_log"] = read_log(session)
        # The SIGHUP study as it was stopped, kept unresumed for the tables.
        shutil.copytree(cls.tmp / "hup", cls.tmp / "hup-stopped", symlinks=True)
        # The SIGINT session is stopped again during its resume, at the trial it lost, then resumed to the end.
        SHARED["int_resume_stop"] = finish(*stop_at(cls.tmp, stop, "int", 2, signal.SIGTERM,
                                                     resume_dir=SHARED["int"], times=2))
        for name in STOPPED:
            SHARED[name + "_resume"] = resume(cls.tmp, SHARED[name])

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.tmp, ignore_errors=True)

    # -- helpers ----------------------------------------------------------------------------------------------
    def all_sessions(self):
        return list(SHARED["days"]) + [SHARED[n] for n in STOPPED]

    def assert_stop_line(self, done, status, signame, command, session):
        """Exit 128 + N and, after the plan and warnings the docs allow on standard error, the one line that
        says the run stopped and names the resume command of this session's folder; no error, no traceback."""
        self.assertEqual(done.returncode, status, done.stderr)
        lines = error_lines(done)
        for line in lines:
            self.assertNotIn("error", line)
            self.assertNotIn("Traceback", line)
            self.assertNotIn("terminate called", line)
        said = re.fullmatch(rf"calligraphy session {command}: stopped by {signame}; resume with: "
                            r"calligraphy session resume (\S+)", lines[-1])
        self.assertIsNotNone(said, lines[-1])
        self.assertEqual(Path(said.group(1)).resolve(), session.resolve())

    # -- the log's form -----------------------------------------------------------------------------------------
    def test_every_line_is_one_object_of_a_documented_kind(self):
        for session in self.all_sessions():
            text = (session / "log.jsonl").read_text(encoding="utf-8")
            self.assertTrue(text.endswith("\n"), session)
            for number, line in enumerate(text.splitlines(), 1):
                event = json.loads(line)
                self.assertIsInstance(event, dict, f"{session.name}: line {number}")
                self.assertIn(kind(event), KINDS, f"{session.name}: line {number}: {line}")

    def test_times_are_utc_iso8601_and_never_go_back(self):
        for session in self.all_sessions():
            last = None
            for event in read_log(session):
                self.assertRegex(event["time_utc"], UTC, f"{session.name}: {event}")
                t = parse_utc(event["time_utc"])
                if last is not None:
                    self.assertGreaterEqual(t, last, f"{session.name}: {event}")
                last = t

    def test_trial_events_carry_the_documented_fields_of_the_plan(self):
        for session in self.all_sessions():
            plan = {p["index"]: p for p in manifest(session)["plan"]}
            for event in read_log(session):
                if kind(event) not in TRIAL_KINDS:
                    continue
                p = plan[trial_number(event)]
                self.assertIsInstance(trial_number(event), int)
                for key in ("phase", "condition", "characters", "repetition", "file"):
                    self.assertEqual(event[key], p[key], f"{session.name}: {key} of {event}")

    def test_first_created_then_started_and_completed_last_once(self):
        for session in self.all_sessions():
            kinds = [kind(e) for e in read_log(session)]
            self.assertEqual(kinds[0], "session_created", session.name)
            self.assertEqual(kinds[1], "session_started", session.name)
            self.assertEqual(kinds[-1], "session_completed", session.name)
            self.assertEqual(kinds.count("session_created"), 1, session.name)
            self.assertEqual(kinds.count("session_completed"), 1, session.name)

    def test_events_lie_within_the_sessions_dates(self):
        for session in self.all_sessions():
            created = parse_utc(manifest(session)["created_utc"])
            log = read_log(session)
            self.assertGreaterEqual(parse_utc(log[0]["time_utc"]) + SLACK_S, created, session.name)
            ends = [parse_utc(r["end_time_utc"]) for r in records(session).values()]
            completed = parse_utc(log[-1]["time_utc"])
            self.assertGreaterEqual(completed + SLACK_S, max(ends), session.name)
            for record in records(session).values():
                self.assertGreaterEqual(parse_utc(record["start_time_utc"]) + SLACK_S, created, session.name)

    # -- saved trials, one event each --------------------------------------------------------------------------
    def assert_one_save_each(self, session):
        saved = [e["file"] for e in read_log(session) if kind(e) == "trial_saved"]
        self.assertEqual(sorted(saved), sorted(records(session)), session.name)
        self.assertEqual(len(saved), len(set(saved)), session.name)
        self.assertEqual(sorted(saved), sorted(p["file"] for p in manifest(session)["plan"]), session.name)

    def test_each_saved_trial_has_exactly_one_trial_saved(self):
        for session in self.all_sessions():
            self.assert_one_save_each(session)

    def test_no_event_names_a_trial_that_is_not_planned(self):
        for session in self.all_sessions():
            plan = {(p["index"], p["file"]) for p in manifest(session)["plan"]}
            for event in read_log(session):
                if kind(event) in TRIAL_KINDS:
                    self.assertIn((trial_number(event), event["file"]), plan, f"{session.name}: {event}")

    def test_record_times_lie_between_its_started_and_saved_events(self):
        for session in self.all_sessions():
            log = read_log(session)
            for stem, record in records(session).items():
                saved = [e for e in log if kind(e) == "trial_saved" and e["file"] == stem]
                begun = [e for e in log if kind(e) == "trial_started" and e["file"] == stem]
                start, end = parse_utc(record["start_time_utc"]), parse_utc(record["end_time_utc"])
                self.assertLessEqual(start, end, stem)
                self.assertLessEqual(parse_utc(begun[-1]["time_utc"]), start + SLACK_S, f"{session.name}: {stem}")
                self.assertLessEqual(end, parse_utc(saved[0]["time_utc"]) + SLACK_S, f"{session.name}: {stem}")
                self.assertAlmostEqual(record["wall_time_s"], end - start, delta=2 * SLACK_S, msg=stem)

    def test_every_trial_started_has_one_outcome_or_was_killed(self):
        """After each trial_started: its trial_saved, trial_interrupted or trial_failed before anything else of
        a trial, or, for a run killed with SIGKILL, the next run's session_resumed (the trial lost)."""
        for session in self.all_sessions():
            log = read_log(session)
            for i, event in enumerate(log):
                if kind(event) != "trial_started":
                    continue
                rest = [e for e in log[i + 1:] if kind(e) in TRIAL_KINDS | {"session_resumed", "session_started"}]
                self.assertTrue(rest, f"{session.name}: {event} is the last event")
                nxt = rest[0]
                if kind(nxt) in ("session_resumed", "session_started"):
                    self.assertEqual(session, SHARED["kill"], f"{session.name}: {event} has no outcome")
                else:
                    self.assertIn(kind(nxt), ("trial_saved", "trial_interrupted", "trial_failed"))
                    self.assertEqual(nxt["file"], event["file"], f"{session.name}: {event}")

    def test_session_completed_counts_equal_the_files(self):
        for session in self.all_sessions():
            completed = read_log(session)[-1]
            self.assertEqual(set(completed), {"event", "time_utc", "trials"}, session.name)
            self.assertEqual(completed["trials"], len(records(session)), session.name)
            self.assertEqual(completed["trials"], len(manifest(session)["plan"]), session.name)

    def test_session_created_is_the_manifest(self):
        for session in self.all_sessions():
            m = manifest(session)
            created = read_log(session)[0]
            self.assertEqual(created["subject"], m["subject"]["id"])
            self.assertEqual(created["subject_number"], m["subject"]["number"])
            self.assertEqual(created["protocol"], m["protocol"]["name"])
            self.assertEqual(created["protocol_sha256"], m["protocol"]["sha256"])
            self.assertEqual(created["session_number"], m["session_number"])
            self.assertEqual(created["trials_planned"], len(m["plan"]))
            for key in ("device", "writer", "group", "writer_learning", "writer_profile", "individual_differences"):
                self.assertEqual(created[key], m[key], key)

    def test_run_events_count_what_was_saved_then(self):
        """session_started, session_resumed and session_stopped say how many trials were saved at that moment
        (and the next one to run, the first unsaved), as the trial_saved events before them count."""
        for session in self.all_sessions():
            plan = [p["index"] for p in manifest(session)["plan"]]
            saved = set()
            for event in read_log(session):
                if kind(event) == "trial_saved":
                    saved.add(trial_number(event))
                elif kind(event) in ("session_started", "session_resumed", "session_stopped"):
                    self.assertEqual(event["saved_trials"], len(saved), f"{session.name}: {event}")
                    if "next_trial" in event:
                        self.assertEqual(event["next_trial"], next(i for i in plan if i not in saved), event)
                    if "planned" in event:
                        self.assertEqual(event["planned"], len(plan), event)
                elif kind(event) == "session_completed":
                    self.assertEqual(event["trials"], len(saved), session.name)
                    self.assertEqual(saved, set(plan), session.name)

    def test_outcome_events_name_the_record_and_its_end(self):
        """trial_saved: the record's end_reason and its total_time_s as time_s (s, a float); trial_interrupted:
        the attempt file it kept, its end_reason and abort_reason, and the trial it was."""
        for session in self.all_sessions():
            saved, kept = records(session), attempts(session)
            for event in read_log(session):
                if kind(event) == "trial_saved":
                    self.assertEqual(event["end_reason"], saved[event["file"]]["end_reason"], event)
                    # A float, or null when the pen never touched (docs/experiments.md, the log's events).
                    self.assertIsInstance(event["time_s"], (float, type(None)))
                    self.assertEqual(event["time_s"], saved[event["file"]]["total_time_s"], event)
                elif kind(event) == "trial_interrupted":
                    stem = event["attempt"][:-len(".json")]
                    self.assertTrue(stem.startswith(event["file"] + ".attempt-"), event)
                    self.assertEqual(event["end_reason"], kept[stem]["end_reason"], event)
                    self.assertEqual(event["abort_reason"], kept[stem]["abort_reason"], event)
                    self.assertEqual(event["abort_reason"], "stopped by " + event["reason"], event)
                    self.assertEqual(kept[stem]["trial"]["index"], trial_number(event), event)

    def test_records_say_the_pacing_of_the_run_that_saved_them(self):
        """The SIGINT session ran trial 1 in real time; its resume ran the rest lock-step."""
        saved = records(SHARED["int"])
        paces = [saved[stem]["renderer"]["pacing"] for stem in sorted(saved)]
        self.assertEqual(paces, ["real-time", "lock-step", "lock-step", "lock-step"])
        for record in attempts(SHARED["int"]).values():
            self.assertEqual(record["renderer"]["pacing"], "real-time")

    # -- rests and delays -----------------------------------------------------------------------------------------
    def test_rests_are_logged_where_the_plan_puts_them_not_waited(self):
        """The 7 s rest between blocks and the post-test's 30 s delay are planned, and each logged as a break
        (not waited: a simulated writer) right before the trial it names; no other break."""
        plan = manifest(SHARED["days"][0])["plan"]
        self.assertEqual([p["phase"] for p in plan],
                         ["pre-test", "training", "training", "training", "training", "post-test"])
        self.assertEqual([p["break_before_s"] for p in plan], [0, 7, 0, 7, 0, 30])
        for session in SHARED["days"]:
            log = read_log(session)
            plan = manifest(session)["plan"]
            breaks = [(i, e) for i, e in enumerate(log) if kind(e) == "break"]
            self.assertEqual([(e["before_trial"], e["duration_s"]) for _, e in breaks],
                             [(p["index"], p["break_before_s"]) for p in plan if p["break_before_s"] > 0])
            for i, event in breaks:
                self.assertIs(event["waited"], False, event)
                self.assertIsInstance(event["duration_s"], float)
                self.assertEqual(kind(log[i + 1]), "trial_started")
                self.assertEqual(trial_number(log[i + 1]), event["before_trial"])

    def test_second_session_follows_the_first_ones_last_trial(self):
        first, second = SHARED["days"]
        previous = manifest(second)["previous_session"]
        last_end = max(r["end_time_utc"] for r in records(first).values())
        self.assertEqual(previous["ended_utc"], last_end)
        self.assertEqual(previous["delay"], "simulated")
        self.assertEqual(previous["delay_s"], 86400)
        self.assertEqual(previous["session_sha256"],
                         hashlib.sha256((first / "session.json").read_bytes()).hexdigest())
        created = parse_utc(manifest(second)["created_utc"])
        self.assertGreaterEqual(created + SLACK_S, parse_utc(last_end))
        self.assertAlmostEqual(previous["elapsed_s"], created - parse_utc(last_end), delta=2 * SLACK_S)
        self.assertGreaterEqual(parse_utc(read_log(second)[0]["time_utc"]) + SLACK_S,
                                parse_utc(read_log(first)[-1]["time_utc"]))

    # -- stopped and resumed ------------------------------------------------------------------------------------
    def check_stop(self, name, status, signame, number):
        done, seen = SHARED[name + "_stop"]
        self.assertTrue(seen, f"{name}: trial {number} never started")
        self.assert_stop_line(done, status, signame, "run", SHARED[name])
        log = SHARED[name + "_stopped_log"]
        self.assertEqual([kind(e) for e in log[-2:]], ["trial_interrupted", "session_stopped"], log[-3:])
        self.assertEqual(log[-2]["reason"], signame)
        self.assertEqual(log[-1]["reason"], signame)
        self.assertEqual(trial_number(log[-2]), number)
        stem = log[-2]["file"]
        saved = [e["file"] for e in log if kind(e) == "trial_saved"]
        self.assertNotIn(stem, saved)
        self.assertEqual(len(saved), number - 1)
        tree_ = SHARED[name + "_stopped_tree"]
        self.assertIn(Path("trials/attempts") / f"{stem}.attempt-1.json", tree_)
        self.assertNotIn(Path("trials") / f"{stem}.json", tree_)
        return log

    def test_sigint_mid_trial_keeps_the_attempt_and_logs_it_once(self):
        log = self.check_stop("int", 130, "SIGINT", 2)
        self.assertEqual(sum(kind(e) == "trial_interrupted" for e in log), 1)

    def test_sigterm_at_first_trial_then_resume_starts_the_session_again(self):
        self.check_stop("term", 143, "SIGTERM", 1)
        kinds = [kind(e) for e in read_log(SHARED["term"])]
        self.assertNotIn("session_resumed", kinds)
        self.assertEqual(kinds.count("session_started"), 2)

    def test_sighup_and_sigusr1_exit_129_and_138_and_are_logged(self):
        self.check_stop("hup", 129, "SIGHUP", 3)
        self.check_stop("usr", 138, "SIGUSR1", 2)

    def test_sigkill_leaves_a_parseable_log_and_no_temporary(self):
        done, seen = SHARED["kill_stop"]
        self.assertTrue(seen)
        self.assertEqual(done.returncode, -signal.SIGKILL)
        log = SHARED["kill_stopped_log"]
        self.assertEqual(kind(log[-1]), "trial_started")
        self.assertEqual(trial_number(log[-1]), 2)
        session = SHARED["kill"]
        leftovers = [p for p in session.rglob("*") if ".part" in p.name or ".tmp" in p.name]
        self.assertEqual(leftovers, [])
        self.assertEqual(SHARED["kill_resume"].returncode, 0, SHARED["kill_resume"].stderr)

    def test_each_resume_is_logged_once_as_one(self):
        expected = {"int": 2, "hup": 1, "kill": 1, "term": 0, "usr": 1}
        for name, count in expected.items():
            kinds = [kind(e) for e in read_log(SHARED[name])]
            self.assertEqual(kinds.count("session_resumed"), count, name)
            self.assertEqual(kinds.count("session_started"), 1 if count else 2, name)

    def test_resume_writes_no_saved_file_again_and_appends_to_the_log(self):
        for name in STOPPED:
            self.assertEqual(SHARED[name + "_resume"].returncode, 0, SHARED[name + "_resume"].stderr)
            now = tree(SHARED[name])
            for path, data in SHARED[name + "_stopped_tree"].items():
                if path.name == "log.jsonl":
                    self.assertTrue(now[path].startswith(data), name)
                else:
                    self.assertEqual(now.get(path), data, f"{name}: {path}")

    def test_every_attempt_file_has_its_trial_interrupted_event(self):
        for session in self.all_sessions():
            log = read_log(session)
            interrupted = sorted(e["file"] for e in log if kind(e) == "trial_interrupted")
            kept = sorted(stem.rsplit(".attempt-", 1)[0] for stem in attempts(session))
            self.assertEqual(interrupted, kept, session.name)

    def test_an_attempt_is_interrupted_with_its_own_trace(self):
        for session in self.all_sessions():
            for stem, record in attempts(session).items():
                self.assertEqual(record["end_reason"], "interrupted", stem)
                self.assertTrue(record["aborted"], stem)
                self.assertRegex(record["abort_reason"], r"^stopped by SIG(INT|TERM|HUP|USR1)$", stem)
                trace = session / "trials" / "attempts" / record["files"]["trace"]
                self.assertEqual(trace.name, stem + ".trace.h5")
                self.assertEqual(hashlib.sha256(trace.read_bytes()).hexdigest(), record["files"]["trace_sha256"])

    def test_a_resume_stopped_again_keeps_a_second_attempt(self):
        done, seen = SHARED["int_resume_stop"]
        self.assertTrue(seen)
        self.assert_stop_line(done, 143, "SIGTERM", "resume", SHARED["int"])
        stems = sorted(attempts(SHARED["int"]))
        self.assertEqual([s.rsplit(".", 1)[1] for s in stems], ["attempt-1", "attempt-2"], stems)
        self.assertEqual(attempts(SHARED["int"])[stems[1]]["abort_reason"], "stopped by SIGTERM")

    def test_attempt_times_lie_between_its_events(self):
        for session in self.all_sessions():
            log = read_log(session)
            for stem, record in attempts(session).items():
                base, k = stem.rsplit(".attempt-", 1)
                begun = [e for e in log if kind(e) == "trial_started" and e["file"] == base]
                ended = [e for e in log if kind(e) == "trial_interrupted" and e["file"] == base]
                k = int(k)
                start, end = parse_utc(record["start_time_utc"]), parse_utc(record["end_time_utc"])
                self.assertLessEqual(start, end, stem)
                self.assertLessEqual(end, parse_utc(ended[k - 1]["time_utc"]) + SLACK_S, stem)
                self.assertTrue(any(parse_utc(b["time_utc"]) <= start + SLACK_S for b in begun), stem)

    def test_resume_of_a_finished_session_logs_nothing_twice(self):
        session = SHARED["days"][0]
        before = (session / "log.jsonl").read_bytes()
        done = resume(self.tmp, session)
        self.assertEqual(done.returncode, 0, done.stderr)
        self.assertIn(b"saved already", done.stdout + done.stderr)
        kinds = [kind(e) for e in read_log(session)]
        self.assertEqual(kinds.count("session_completed"), 1)
        self.assertTrue((session / "log.jsonl").read_bytes().startswith(before))
        self.assertNotIn("session_resumed", kinds)

    def test_a_replay_teacher_is_logged_and_so_is_one_that_cannot_be_recorded(self):
        """A replay condition without teachers: the runner records 一's teacher (teacher_saved once, before its
        first trial, with the SHA-256 of the copy in teachers/ that the records name); 十's simulated teacher
        cannot write its two strokes in 4 s, which ends the run (exit 1, one error line) and is logged as a
        trial that could not be run: trial_failed with the error, then session_stopped with its reason."""
        protocol = self.tmp / "replay.json"
        protocol.write_text(json.dumps({"name": "r18b", "conditions": [{"name": "R", "mode": "replay"}],
                                        "test": {"characters": [YI, SHI], "conditions": ["R"], "repetitions": 2},
                                        "trial": {"max_duration_s": 4}}, ensure_ascii=False), encoding="utf-8")
        done = run(["session", "run", protocol, "--subjects", "1", "--out", self.tmp / "replay", *RUN], cwd=self.tmp)
        # The plan `session run` prints on standard error comes first; then one error line.
        self.assertEqual(done.returncode, 1, done.stderr)
        lines = error_lines(done)
        self.assertEqual([line for line in lines if "error" in line], lines[-1:])
        self.assertRegex(lines[-1], rf"^calligraphy session run: error: .*teacher.*{SHI}")
        (session,) = sessions_under(self.tmp / "replay")
        log = read_log(session)
        kinds = [kind(e) for e in log]
        self.assertEqual(kinds, ["session_created", "session_started", "teacher_saved", "trial_started",
                                 "trial_saved", "trial_failed", "session_stopped"])
        teacher = log[2]
        self.assertEqual((teacher["condition"], teacher["characters"], teacher["source"]), ("R", YI, "recorded"))
        self.assertEqual(teacher["sha256"], hashlib.sha256((session / teacher["file"]).read_bytes()).hexdigest())
        (record,) = records(session).values()
        self.assertEqual(record["guidance"]["teacher"]["sha256"], teacher["sha256"])
        self.assertEqual(record["guidance"]["teacher"]["file"], teacher["file"])
        failed, stopped = log[-2], log[-1]
        self.assertEqual((trial_number(failed), failed["characters"]), (2, SHI))
        self.assertIn("teacher", failed["error"])
        self.assertEqual((stopped["reason"], stopped["saved_trials"], stopped["planned"]),
                         ("teacher_not_loaded", 1, 4))

    def test_a_learning_subjects_skills_are_logged_as_recorded_and_rebuilt_on_resume(self):
        """A learning simulated subject (two-state): each trial_started carries the skills the record's
        writer memory and the tables give; a run killed after its first save and resumed logs the same skills
        for the trials it runs again as the run straight through did."""
        protocol = self.tmp / "learning.json"
        protocol.write_text(json.dumps({"name": "l18b", "conditions": [{"name": "U", "mode": "vision"}],
                                        "test": {"characters": [YI], "conditions": ["U"], "repetitions": 3},
                                        "trial": {"max_duration_s": 0.4}}, ensure_ascii=False), encoding="utf-8")
        out = self.tmp / "learning"
        done = run(["session", "run", protocol, "--subjects", "1", "--out", out, "--writer", "simulated",
                    "--writer-learning", "two-state"], cwd=self.tmp)
        self.assertEqual(done.returncode, 0, done.stderr)
        (session,) = sessions_under(out)
        skills = ("shape_skill", "order_skill", "timing_skill")

        def logged(log):
            return {trial_number(e): tuple(e[k] for k in skills) for e in log if kind(e) == "trial_started"}
        straight = logged(read_log(session))
        self.assertEqual(sorted(straight), [1, 2, 3])
        self.assertGreater(straight[3][0], straight[1][0])
        saved = records(session)
        for p in manifest(session)["plan"]:
            memory = saved[p["file"]]["writer"]["memory"]
            self.assertEqual(tuple(memory[k] for k in skills), straight[p["index"]], p["file"])
        from calligraphy import study
        for _, row in study.load(str(out)).trials.iterrows():
            self.assertEqual(tuple(row[k] for k in skills), straight[int(row.trial)])
        # Killed after trial 1's trial_saved (line 3): trials 2 and 3 unsaved; resumed.
        log = session / "log.jsonl"
        log.write_text("".join(log.read_text(encoding="utf-8").splitlines(keepends=True)[:4]), encoding="utf-8")
        for p in manifest(session)["plan"][1:]:
            for path in (session / "trials").glob(p["file"] + ".*"):
                path.unlink()
        self.assertEqual(resume(self.tmp, session).returncode, 0)
        after = read_log(session)
        resumed = next(i for i, e in enumerate(after) if kind(e) == "session_resumed")
        self.assertEqual(logged(after[resumed:]), {2: straight[2], 3: straight[3]})

    # -- a run killed between two appends of the log -------------------------------------------------------------
    def killed_between(self, name, last_line, trials_kept=4):
        """A lock-step session of the four trials of 十, then its files as a run killed right after writing
        line `last_line` of its log (0-based; the log ends there) would leave them, with trials
        1..`trials_kept` saved (a record is linked before its trial_saved line is appended); its folder."""
        stop = self.tmp / "stop.json"
        out = self.tmp / name
        done = run(["session", "run", stop, "--subjects", "1", "--subject", name.upper(), "--out", out,
                    "--pacing", "lock-step", *RUN], cwd=self.tmp)
        self.assertEqual(done.returncode, 0, done.stderr)
        (session,) = sessions_under(out)
        log = session / "log.jsonl"
        lines = log.read_text(encoding="utf-8").splitlines(keepends=True)
        log.write_text("".join(lines[:last_line + 1]), encoding="utf-8")
        for p in manifest(session)["plan"][trials_kept:]:
            for path in (session / "trials").glob(p["file"] + ".*"):
                path.unlink()
        return session

    def test_a_run_killed_before_session_completed_is_completed_by_resume(self):
        session = self.killed_between("late", 9)
        self.assertEqual(kind(read_log(session)[-1]), "trial_saved")
        done = resume(self.tmp, session)
        self.assertEqual(done.returncode, 0, done.stderr)
        log = read_log(session)
        self.assertEqual([kind(e) for e in log].count("session_completed"), 1)
        self.assertEqual(kind(log[-1]), "session_completed")
        self.assertEqual(log[-1]["trials"], 4)
        self.assertEqual(kind(log[-2]), "session_resumed")
        self.assertEqual(log[-2]["saved_trials"], 4)
        again = (session / "log.jsonl").read_bytes()
        self.assertEqual(resume(self.tmp, session).returncode, 0)
        self.assertEqual((session / "log.jsonl").read_bytes(), again)

    def assert_recovered(self, session, stems):
        """The saves the killed run did not log are logged once by the resume, marked recovered, with their
        records' end and time, before its session_resumed; every saved trial then has one trial_saved."""
        log = read_log(session)
        saved = records(session)
        resumed = next(i for i, e in enumerate(log) if kind(e) == "session_resumed")
        recovered = [(i, e) for i, e in enumerate(log) if e.get("recovered")]
        self.assertEqual([e["file"] for _, e in recovered], stems)
        for i, event in recovered:
            self.assertEqual(kind(event), "trial_saved")
            self.assertLess(i, resumed)
            self.assertEqual(event["time_s"], saved[event["file"]]["total_time_s"], event)
            self.assertEqual(event["end_reason"], saved[event["file"]]["end_reason"], event)
        self.assert_one_save_each(session)
        self.assertEqual(kind(log[-1]), "session_completed")
        self.assertEqual([kind(e) for e in log].count("session_completed"), 1)

    def test_a_run_killed_before_its_last_trial_saved_line_logs_it_on_resume(self):
        session = self.killed_between("last", 8)
        self.assertEqual(kind(read_log(session)[-1]), "trial_started")
        done = resume(self.tmp, session)
        self.assertEqual(done.returncode, 0, done.stderr)
        self.assert_recovered(session, [manifest(session)["plan"][3]["file"]])

    def test_a_save_the_log_missed_is_logged_with_its_time_and_end(self):
        session = self.killed_between("missed", 4, trials_kept=2)
        self.assertEqual([kind(e) for e in read_log(session)][-1], "trial_started")
        done = resume(self.tmp, session)
        self.assertEqual(done.returncode, 0, done.stderr)
        self.assert_recovered(session, [manifest(session)["plan"][1]["file"]])
        resumed = next(e for e in read_log(session) if kind(e) == "session_resumed")
        self.assertEqual((resumed["saved_trials"], resumed["next_trial"]), (2, 3))

    # -- what the program says and the tables ---------------------------------------------------------------------
    def test_run_prints_trials_saved_and_attempts_kept(self):
        """One line a session (trials saved of planned, saved now, attempts kept now, folder), then that the
        subject's sessions are all done."""
        done = SHARED["days_run"]
        self.assertEqual(done.returncode, 0, done.stderr)
        lines = done.stdout.decode().strip().splitlines()
        self.assertEqual(len(lines), 3, lines)
        for line, session in zip(lines, SHARED["days"]):
            n = len(records(session))
            self.assertRegex(line, rf"^S01: {n} of {n} trials saved \({n} now, 0 attempts kept\) in \S+{session.name},")
        self.assertIn("done", lines[2])

    def test_stopped_and_resumed_runs_print_their_own_counts(self):
        for name in STOPPED:
            session = SHARED[name]
            log = SHARED[name + "_stopped_log"]
            saved = sum(kind(e) == "trial_saved" for e in log)
            kept = sum(kind(e) == "trial_interrupted" for e in log)
            stopped = SHARED[name + "_stop"][0].stdout.decode()
            if name != "kill":
                self.assertRegex(stopped, rf"^{name.upper()}01: {saved} of 4 trials saved \({saved} now, {kept} "
                                          rf"attempts? kept\) in \S+{session.name},", name)
            resumed = SHARED[name + "_resume"].stdout.decode()
            before = 1 if name == "int" else saved
            self.assertRegex(resumed, rf"^{name.upper()}01: 4 of 4 trials saved \({4 - before} now, 0 attempts? kept\)",
                             name)

    def test_report_tables_agree_with_the_log(self):
        tables = self.tmp / "tables"
        tables.mkdir(exist_ok=True)
        done = run(["report", self.tmp / "days", self.tmp / "int", self.tmp / "kill", "--csv", tables],
                   cwd=self.tmp)
        self.assertEqual(done.returncode, 0, done.stderr)
        with open(tables / "trials.csv", encoding="utf-8", newline="") as f:
            rows = list(csv.DictReader(f))
        by_session = {}
        for row in rows:
            by_session.setdefault(row["session"], []).append(row)
        sessions = list(SHARED["days"]) + [SHARED["int"], SHARED["kill"]]
        self.assertEqual(set(by_session), {s.name for s in sessions})
        for session in sessions:
            saved = {trial_number(e): e for e in read_log(session) if kind(e) == "trial_saved"}
            got = by_session[session.name]
            self.assertEqual(sorted(int(r["trial"]) for r in got), sorted(saved), session.name)
            recs = records(session)
            for row in got:
                event = saved[int(row["trial"])]
                record = recs[event["file"]]
                self.assertEqual(row["end_reason"], record["end_reason"])
                self.assertEqual(row["start_utc"], record["start_time_utc"])
                self.assertEqual(row["phase"], event["phase"])
                if event["time_s"] is None:  # the pen never touched: an empty field
                    self.assertEqual(row["total_time_s"], "")
                else:
                    self.assertEqual(float(row["total_time_s"]), event["time_s"])

    def test_tables_of_a_stopped_session_leave_out_its_attempt(self):
        tables = self.tmp / "tables-stopped"
        tables.mkdir(exist_ok=True)
        done = run(["report", self.tmp / "hup-stopped", "--csv", tables], cwd=self.tmp)
        self.assertEqual(done.returncode, 0, done.stderr)
        with open(tables / "trials.csv", encoding="utf-8", newline="") as f:
            rows = list(csv.DictReader(f))
        log = SHARED["hup_stopped_log"]
        self.assertEqual(sorted(int(r["trial"]) for r in rows),
                         sorted(trial_number(e) for e in log if kind(e) == "trial_saved"))
        self.assertNotIn("interrupted", {r["end_reason"] for r in rows})

    def test_study_load_agrees_with_the_log(self):
        from calligraphy import study
        trials = study.load(str(self.tmp / "days")).trials
        for session in SHARED["days"]:
            rows = trials[trials.session == session.name]
            saved = {trial_number(e): e for e in read_log(session) if kind(e) == "trial_saved"}
            self.assertEqual(sorted(int(t) for t in rows.trial), sorted(saved))
            recs = records(session)
            for _, row in rows.iterrows():
                record = recs[saved[int(row.trial)]["file"]]
                self.assertEqual(row.end_reason, record["end_reason"])
                self.assertEqual(str(row.start_utc), record["start_time_utc"])
                if saved[int(row.trial)]["time_s"] is None:  # the pen never touched: NaN in the frame
                    self.assertTrue(math.isnan(row.total_time_s))
                else:
                    self.assertEqual(row.total_time_s, saved[int(row.trial)]["time_s"])


if __name__ == "__main__":
    unittest.main()
