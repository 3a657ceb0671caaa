#!/usr/bin/env python3
"""Round 19C: two writers at once, from the docs alone (docs/cli.md "Outputs", "session run | resume", "report",
"corpus build"; docs/experiments.md "Sessions", "How nothing is lost", "The per-trial pages"; docs/python.md).
Run by CTest as `cli_unseen_round19c_tests`.

Earlier rounds killed one run at each rename and started two runs of one protocol together; this one races every
other pair of processes that write, or write and read, one file or folder: two trials to the same outputs, a
trial replacing what `score`, `trace` or a replay reads, two reports into one folder (of one study and of two),
a report while a run or a resume adds trials, a run and a resume of one study, two resumes (one through a link),
two runs of two protocols making one study's identity, two corpus builds of one store and a trial, a plan and a
build reading it, Python's `study.load` and `record_teacher` beside the command line; and races in which one of
the two is SIGKILLed, then the other finishes and a resume or a report follows. The processes are released
together from one barrier (a pipe both read; the parent closes it). Each race checks what the docs promise:
each process succeeds whole or fails with one line naming the thing, exit status as documented, nothing lost,
never a file mixing both writers (a file equal to one writer's own, a set of tables from one run), no temporary
left, later readers accept the result.

CALLIGRAPHY_CLI names the program, PYTHONPATH its Python module. CALLIGRAPHY_SANITIZED=1 takes five cases.
"""
import csv
import json
import os
import re
import shutil
import signal
import subprocess
import sys
import tempfile
import time
import unittest
import urllib.parse
from pathlib import Path

from outsider import CLI, ENV, error_lines, run, sanitized_subset

load_tests = sanitized_subset({"test_two_trials_to_the_same_outputs_leave_each_file_one_writers",
                               "test_two_reports_into_one_folder_leave_the_tables_of_the_study",
                               "test_two_resumes_together_save_the_missing_trial_once",
                               "test_two_corpus_builds_of_one_store_leave_one_builds_store",
                               "test_reports_of_two_studies_into_one_tables_folder_never_mix_the_pair"})

YI = "一"
CORPUS = Path(os.environ.get("CALLIGRAPHY_CORPUS_DIR", Path.home() / ".cache/calligraphy/hanzi-writer-data-2.0.1"))
SIM = ["--writer", "simulated", "--writer-learning", "none", "--individual-differences", "off"]
REPEAT = 2
# Hidden files a study folder keeps by the docs: its identity and its run lock (docs/cli.md, "session run").
STUDY_FILES = {".calligraphy-study.json", ".calligraphy-run.lock"}


def protocol(name):
    return {"name": name, "conditions": [{"name": "V", "mode": "vision"}],
            "test": {"characters": [YI], "conditions": ["V"], "repetitions": 2}, "trial": {"max_duration_s": 4}}


def race(commands, cwd, kill=None, timeout=60):
    """Start every command (an argv) at once: each waits in a shell reading one pipe (its standard input, then
    /dev/null for the command) that the parent closes when all are started. `kill` = (index, seconds): SIGKILL
    that one so long after the release. A CompletedProcess each, with its `pid`."""
    r, w = os.pipe()
    procs = []
    try:
        for argv in commands:
            procs.append(subprocess.Popen(["/bin/sh", "-c", 'read _; exec "$@" </dev/null', "sh", *map(str, argv)],
                                          cwd=cwd, env=ENV, stdin=r, stdout=subprocess.PIPE,
                                          stderr=subprocess.PIPE))
    finally:
        os.close(r)
        os.close(w)
    if kill is not None:
        time.sleep(kill[1])
        procs[kill[0]].send_signal(signal.SIGKILL)
    results = []
    for p, argv in zip(procs, commands):
        out, err = p.communicate(timeout=timeout)
        results.append(subprocess.CompletedProcess(argv, p.returncode, out, err))
        results[-1].pid = p.pid
    return results


def cli(*args):
    return [CLI, *args]


def leftovers(folder):
    """Temporaries, journals, half-made folders and records' `.part` anywhere under `folder`."""
    found = []
    for path in Path(folder).rglob("*"):
        name = path.name
        if name in STUDY_FILES:
            continue
        if name.startswith(".") or name.endswith(".part") or ".tmp-" in name:
            found.append(str(path.relative_to(folder)))
    return found


def sessions(study):
    return sorted(p.parent for p in Path(study).glob("*/*/session.json"))


def log_kinds(session):
    return [json.loads(line) for line in (Path(session) / "log.jsonl").read_text().splitlines() if line.strip()]


def event(line):
    return line.get("event", line.get("kind"))


class Race(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.tmp = tempfile.TemporaryDirectory(prefix="r19c-")
        root = cls.root = Path(cls.tmp.name)
        (root / "p.json").write_text(json.dumps(protocol("r19c")))
        (root / "q.json").write_text(json.dumps(protocol("r19d")))
        data = root / "data"
        data.mkdir()
        shutil.copy(CORPUS / f"{YI}.json", data)
        shutil.copy(CORPUS / "十.json", data)
        cls.data = data
        # Two stores of the same data that differ (the tolerance), each built alone.
        cls.stores = []
        for tolerance in ("10", "4"):
            out = root / f"store-{tolerance}.clg"
            cls.check(run(["corpus", "build", "--out", out, "--data", data, "--tolerance", tolerance,
                           "--threads", "1"], root))
            cls.stores.append(out.read_bytes())
        # Two trials of 一 (seeds 1 and 2) written alone: their CSV traces and SVGs.
        cls.solo = {}
        for seed in ("1", "2"):
            cls.check(run(["trial", YI, "--seed", seed, "--max-duration", "10", "--json", f"solo{seed}.json",
                           "--csv", f"solo{seed}.csv", "--svg", f"solo{seed}.svg"], root))
            cls.solo[seed] = {ext: (root / f"solo{seed}.{ext}").read_bytes() for ext in ("csv", "svg")}
        # Two finished studies of one subject each (protocols r19c and r19d), their tables made alone.
        for name, proto in (("st", "p.json"), ("st2", "q.json")):
            cls.check(run(["session", "run", proto, "--subjects", "1", "--out", name, *SIM], root))
            (root / f"{name}-t").mkdir()
            cls.check(run(["report", root / name, "--csv", f"{name}-t"], root))
        cls.tables = {name: {f: (root / f"{name}-t" / f).read_bytes() for f in ("trials.csv", "strokes.csv")}
                      for name in ("st", "st2")}
        # A study whose one session was stopped by SIGTERM after its first trial was saved (real-time pacing).
        stopped = root / "stopped"
        p = subprocess.Popen([CLI, "session", "run", "p.json", "--subjects", "1", "--out", stopped, *SIM,
                              "--pacing", "real-time"], cwd=root, env=ENV, stdin=subprocess.DEVNULL,
                             stdout=subprocess.PIPE, stderr=subprocess.PIPE)
        deadline = time.monotonic() + 30
        while not list(stopped.glob("S01/*/trials/001-*.json")) and time.monotonic() < deadline:
            time.sleep(0.01)
        p.send_signal(signal.SIGTERM)
        out, err = p.communicate(timeout=30)
        assert p.returncode == 143, (p.returncode, err)
        assert len(list(stopped.glob("S01/*/trials/0*.json"))) == 1, err

    @classmethod
    def tearDownClass(cls):
        cls.tmp.cleanup()

    @staticmethod
    def check(result):
        assert result.returncode == 0, (result.args, result.returncode, result.stderr.decode())
        return result

    def setUp(self):
        self.dir = Path(tempfile.mkdtemp(dir=self.root))

    def copy(self, name):
        target = self.dir / name
        shutil.copytree(self.root / name, target, symlinks=True)
        return target

    def assert_ok_or_refused(self, result, *needles, statuses=(1,)):
        """Succeeded (0), or refused with one of `statuses` and one error line holding each needle."""
        text = result.stderr.decode("utf-8", "replace")
        self.assertNotIn("terminate called", text)
        self.assertNotIn("Traceback", text)
        if result.returncode == 0:
            return True
        self.assertIn(result.returncode, statuses, text)
        lines = error_lines(result)
        self.assertEqual(len(lines), 1, lines)
        for needle in needles:
            self.assertIn(str(needle), lines[0])
        return False

    def assert_clean(self, folder):
        """Nothing half made or temporary left, and a study's run lock empty: it names its run only while it
        runs (docs/cli.md, "session run")."""
        self.assertEqual(leftovers(folder), [])
        for lock in Path(folder).rglob(".calligraphy-run.lock"):
            self.assertEqual(lock.read_bytes(), b"", lock)

    def assert_turns(self, results, folder):
        """Each run or resume succeeded, or was refused (exit 1) in one line naming the study folder and the
        other racer by its process id as the run that holds the folder. True for each that succeeded."""
        done = []
        for r in results:
            others = [o.pid for o in results if o is not r]
            ok = self.assert_ok_or_refused(r, folder)
            if not ok:
                self.assertTrue(any(f"pid {pid}" in error_lines(r)[0] for pid in others), error_lines(r))
            done.append(ok)
        return done

    def assert_session_whole(self, session, planned=2):
        """Every planned trial saved once: a record and a trace each, one `trial_saved` each, the log completed."""
        records = sorted((session / "trials").glob("0*.json"))
        self.assertEqual(len(records), planned, records)
        for rec in records:
            json.loads(rec.read_text())
            self.assertTrue(Path(str(rec)[:-5] + ".trace.h5").exists(), rec)
        events = log_kinds(session)
        saved = [e for e in events if event(e) == "trial_saved"]
        self.assertEqual(len(saved), planned, saved)
        self.assertEqual(event(events[-1]), "session_completed", events[-1])

    def stopped_session(self, study):
        (session,) = sessions(study)
        return session

    def report_rows(self, study, extra=()):
        tables = self.dir / f"t-{study.name}-{time.monotonic_ns()}"
        tables.mkdir()
        self.check(run(["report", study, "--csv", tables, *extra], self.dir))
        with open(tables / "trials.csv", newline="") as f:
            return list(csv.DictReader(f))

    # ---- trial, score, trace -------------------------------------------------------------------------------

    def test_two_trials_to_the_same_outputs_leave_each_file_one_writers(self):
        for _ in range(REPEAT):
            results = race([cli("trial", YI, "--seed", seed, "--max-duration", "10", "--json", "a.json", "--csv",
                                "a.csv", "--svg", "a.svg") for seed in ("1", "2")], self.dir)
            for r in results:
                self.check(r)
            self.assertIn(json.loads((self.dir / "a.json").read_text())["seed"], (1, 2))
            self.assertIn((self.dir / "a.csv").read_bytes(), [self.solo[s]["csv"] for s in ("1", "2")])
            self.assertIn((self.dir / "a.svg").read_bytes(), [self.solo[s]["svg"] for s in ("1", "2")])
            self.assert_clean(self.dir)

    def test_score_reading_a_trace_a_trial_replaces_reads_one_whole_trace(self):
        shutil.copy(self.root / "solo1.csv", self.dir / "a.csv")
        for seed in ("2", "1", "2"):
            results = race([cli("trial", YI, "--seed", seed, "--max-duration", "10", "--csv", "a.csv"),
                            cli("score", "a.csv", "--character", YI, "--json", "-")], self.dir)
            self.check(results[0])
            self.check(results[1])
            score = json.loads(results[1].stdout)
            self.assertTrue(score, score)
            self.assert_clean(self.dir)

    def test_trace_and_trial_writing_one_csv_leave_one_writers_csv(self):
        study = self.root / "st"
        traces = sorted(study.glob("S01/*/trials/*.trace.h5"))
        solo = self.check(run(["trace", traces[0]], self.dir)).stdout
        for _ in range(REPEAT):
            results = race([cli("trace", traces[0], "--csv", "a.csv"),
                            cli("trial", YI, "--seed", "1", "--max-duration", "10", "--csv", "a.csv")], self.dir)
            for r in results:
                self.check(r)
            self.assertIn((self.dir / "a.csv").read_bytes(), (solo, self.solo["1"]["csv"]))
            self.assert_clean(self.dir)

    def test_a_rerun_of_a_record_a_trial_replaces_runs_one_whole_record(self):
        shutil.copy(self.root / "solo1.json", self.dir / "a.json")
        for seed in ("2", "1"):
            results = race([cli("trial", YI, "--seed", seed, "--max-duration", "10", "--json", "a.json"),
                            cli("trial", "--spec", "a.json", "--json", "b.json")], self.dir)
            for r in results:
                self.check(r)
            self.assertIn(json.loads((self.dir / "b.json").read_text())["seed"], (1, 2))
            self.assert_clean(self.dir)

    def test_two_traces_to_one_csv_leave_one_of_them(self):
        traces = sorted((self.root / "st").glob("S01/*/trials/*.trace.h5"))
        solos = [self.check(run(["trace", t], self.dir)).stdout for t in traces]
        self.assertNotEqual(solos[0], solos[1])
        for _ in range(REPEAT):
            for r in race([cli("trace", t, "--csv", "o.csv") for t in traces], self.dir):
                self.check(r)
            self.assertIn((self.dir / "o.csv").read_bytes(), solos)
            self.assert_clean(self.dir)

    def test_two_scores_to_one_json_leave_one_of_them(self):
        solos = [self.check(run(["score", self.root / f"solo{s}.csv", "--character", YI, "--json", "-"],
                                self.dir)).stdout for s in ("1", "2")]
        for _ in range(REPEAT):
            for r in race([cli("score", self.root / f"solo{s}.csv", "--character", YI, "--json", "s.json")
                           for s in ("1", "2")], self.dir):
                self.check(r)
            self.assertIn((self.dir / "s.json").read_bytes(), solos)
            self.assert_clean(self.dir)

    def test_two_teacher_recordings_to_one_file_leave_a_teacher_a_replay_takes(self):
        for _ in range(2):
            for r in race([cli("trial", YI, "--writer-profile", "skilled", "--seed", s, "--max-duration", "10",
                               "--record", "t.json") for s in ("1", "2")], self.dir):
                self.check(r)
            self.check(run(["trial", YI, "--guidance-mode", "replay", "--teacher", "t.json", "--max-duration",
                            "10"], self.dir))
            self.assert_clean(self.dir)

    def test_a_refused_recording_beside_a_kept_one_leaves_the_kept_teacher(self):
        # A trial that ends at its time limit has its --record refused (exit 1, nothing written); the one beside it
        # completes and writes the same file, which the refused one must not remove or replace.
        for _ in range(REPEAT):
            (self.dir / "t.json").unlink(missing_ok=True)
            results = race([cli("trial", YI, "--max-duration", "0.2", "--record", "t.json"),
                            cli("trial", YI, "--writer-profile", "skilled", "--max-duration", "10", "--record",
                                "t.json")], self.dir)
            self.assertEqual(results[0].returncode, 1, results[0].stderr)
            self.check(results[1])
            self.assertTrue((self.dir / "t.json").is_file())
            self.check(run(["trial", YI, "--guidance-mode", "replay", "--teacher", "t.json", "--max-duration",
                            "10"], self.dir))
            self.assert_clean(self.dir)

    def test_a_replay_reading_a_teacher_a_trial_replaces_reads_one_whole_teacher(self):
        self.check(run(["trial", YI, "--writer-profile", "skilled", "--max-duration", "10", "--record", "t.json"],
                       self.dir))
        for seed in ("3", "4"):
            results = race([cli("trial", YI, "--writer-profile", "skilled", "--seed", seed, "--max-duration", "10",
                                "--record", "t.json"),
                            cli("trial", YI, "--guidance-mode", "replay", "--teacher", "t.json", "--max-duration",
                                "10")], self.dir)
            for r in results:
                self.check(r)
            self.assert_clean(self.dir)

    # ---- report ------------------------------------------------------------------------------------------------

    def test_two_reports_into_one_folder_leave_the_tables_of_the_study(self):
        (self.dir / "t").mkdir()
        for _ in range(REPEAT):
            results = race([cli("report", self.root / "st", "--out", "r.html", "--csv", "t")] * 2, self.dir)
            for r in results:
                self.check(r)
            for f in ("trials.csv", "strokes.csv"):
                self.assertEqual((self.dir / "t" / f).read_bytes(), self.tables["st"][f], f)
            self.assertIn("r19c", (self.dir / "r.html").read_text())
            self.assertTrue(list((self.dir / "r_files").glob("S01/*.html")))
            self.assert_clean(self.dir)

    def test_reports_of_two_studies_into_one_tables_folder_never_mix_the_pair(self):
        (self.dir / "t").mkdir()
        for _ in range(REPEAT + 1):
            results = race([cli("report", self.root / name, "--csv", "t") for name in ("st", "st2")], self.dir)
            for r in results:
                self.check(r)
            pair = {f: (self.dir / "t" / f).read_bytes() for f in ("trials.csv", "strokes.csv")}
            self.assertIn(pair, [self.tables["st"], self.tables["st2"]])
            self.assert_clean(self.dir)

    def test_reports_of_two_studies_to_one_page_leave_one_studys_index(self):
        for _ in range(REPEAT):
            results = race([cli("report", self.root / name, "--out", "r.html") for name in ("st", "st2")],
                           self.dir)
            for r in results:
                self.check(r)
            index = (self.dir / "r.html").read_text()
            self.assertNotEqual("r19c-S01" in index, "r19d-S01" in index, "the index names both studies' sessions")
            links = re.findall(r'href="([^"#]+)', index)
            self.assertTrue(links)
            for link in links:
                self.assertTrue((self.dir / urllib.parse.unquote(link)).is_file(), link)
            self.assert_clean(self.dir)

    def test_a_failing_report_beside_a_report_into_one_new_folder_takes_none_of_its_pages(self):
        # A study whose second trace is cut: its report fails (exit 1, naming the trace) and removes the folders it
        # made, which must not take the pages the other report, of a whole study, wrote into the same folder.
        bad = self.copy("st2")
        (trace,) = bad.glob("S01/*/trials/002-*.trace.h5")
        trace.write_bytes(trace.read_bytes()[:3000])
        for i in range(REPEAT + 2):
            out = self.dir / f"o{i}"
            out.mkdir()
            results = race([cli("report", bad, "--out", "r.html"), cli("report", self.root / "st", "--out", "r.html")],
                           out)
            self.assertEqual(results[0].returncode, 1)
            self.assertIn(trace.name, error_lines(results[0])[-1])
            self.check(results[1])
            index = (out / "r.html").read_text()
            self.assertIn("r19c-S01", index)
            links = re.findall(r'href="([^"#]+)', index)
            self.assertTrue(links)
            for link in links:
                self.assertTrue((out / urllib.parse.unquote(link)).is_file(), link)
            self.assert_clean(out)

    def test_a_failing_report_beside_a_report_into_one_tables_folder_leaves_the_whole_studys_tables(self):
        bad = self.copy("st2")
        (record,) = bad.glob("S01/*/trials/002-*.json")
        record.write_bytes(record.read_bytes()[:100])
        (self.dir / "t").mkdir()
        for _ in range(REPEAT):
            results = race([cli("report", bad, "--csv", "t"), cli("report", self.root / "st", "--csv", "t")],
                           self.dir)
            self.assertEqual(results[0].returncode, 1)
            self.assertIn(record.name, error_lines(results[0])[-1])
            self.check(results[1])
            pair = {f: (self.dir / "t" / f).read_bytes() for f in ("trials.csv", "strokes.csv")}
            self.assertEqual(pair, self.tables["st"])
            self.assert_clean(self.dir / "t")

    def test_a_report_while_a_run_adds_a_subject_reads_whole_trials(self):
        study = self.copy("st")
        (self.dir / "t").mkdir()
        results = race([cli("session", "run", self.root / "p.json", "--subjects", "1", "--new-subjects", "--out",
                            study, *SIM),
                        cli("report", study, "--csv", "t")], self.dir)
        self.check(results[0])
        self.check(results[1])
        with open(self.dir / "t" / "trials.csv", newline="") as f:
            rows = list(csv.DictReader(f))
        self.assertIn(len(rows), (2, 3, 4))
        for row in rows:
            self.assertTrue((self.dir / row["trace_file"]).exists(), row["trace_file"])
        self.assertEqual(len(self.report_rows(study)), 4)
        self.assert_clean(study)

    def test_a_report_while_a_resume_saves_reads_whole_trials(self):
        study = self.copy("stopped")
        session = self.stopped_session(study)
        (self.dir / "t").mkdir()
        results = race([cli("session", "resume", session, "--pacing", "lock-step"),
                        cli("report", study, "--csv", "t", "--out", "r.html")], self.dir)
        self.check(results[0])
        self.check(results[1])
        with open(self.dir / "t" / "trials.csv", newline="") as f:
            self.assertIn(len(list(csv.DictReader(f))), (1, 2))
        self.assert_session_whole(session)
        self.assertEqual(len(self.report_rows(study)), 2)
        self.assert_clean(study)

    def test_a_cohort_and_a_report_into_one_tables_folder_never_mix_the_pair(self):
        options = ["--subjects", "1", "--jobs", "1", *SIM[2:]]
        cohort = cli("session", "cohort", self.root / "p.json", "--csv", "t", *options)
        (self.dir / "c").mkdir()
        self.check(run(["session", "cohort", self.root / "p.json", "--csv", "c", *options], self.dir))
        alone = {f: (self.dir / "c" / f).read_bytes() for f in ("trials.csv", "strokes.csv")}
        self.assertNotEqual(alone, self.tables["st"])
        (self.dir / "t").mkdir()
        for _ in range(REPEAT):
            for r in race([cohort, cli("report", self.root / "st", "--csv", "t")], self.dir):
                self.check(r)
            pair = {f: (self.dir / "t" / f).read_bytes() for f in ("trials.csv", "strokes.csv")}
            self.assertIn(pair, [alone, self.tables["st"]])
            self.assert_clean(self.dir)

    def test_reports_racing_after_a_killed_report_leave_its_tables_whole(self):
        # A report killed at a few moments (at times between two renames, leaving its journal), then two reports
        # of another study racing into the same folder, which complete or replace what it left.
        (self.dir / "t").mkdir()
        for delay in (0.03, 0.07):
            p = subprocess.Popen([CLI, "report", self.root / "st2", "--csv", "t"], cwd=self.dir, env=ENV,
                                 stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
            time.sleep(delay)
            p.kill()
            p.wait()
            for r in race([cli("report", self.root / "st", "--csv", "t")] * 2, self.dir):
                self.check(r)
            pair = {f: (self.dir / "t" / f).read_bytes() for f in ("trials.csv", "strokes.csv")}
            self.assertEqual(pair, self.tables["st"])
            self.assert_clean(self.dir / "t")

    # ---- session run | resume ------------------------------------------------------------------------------

    def test_a_run_and_a_resume_of_one_study_together_lose_nothing(self):
        for _ in range(2):
            study = self.copy("stopped") if not (self.dir / "stopped").exists() else None
            if study is None:
                shutil.rmtree(self.dir / "stopped")
                study = self.copy("stopped")
            session = self.stopped_session(study)
            run_cmd = cli("session", "run", self.root / "p.json", "--subjects", "1", "--new-subjects", "--out",
                          study, *SIM)
            resume_cmd = cli("session", "resume", session, "--pacing", "lock-step")
            results = race([run_cmd, resume_cmd], self.dir)
            ran, resumed = self.assert_turns(results, study)
            if not ran:
                self.check(run(run_cmd[1:], self.dir))
            if not resumed:
                self.check(run(resume_cmd[1:], self.dir))
            self.assertEqual(len(sessions(study)), 2)
            for s in sessions(study):
                self.assert_session_whole(s)
            self.assertEqual(len(self.report_rows(study)), 4)
            self.assert_clean(study)

    def test_two_resumes_together_save_the_missing_trial_once(self):
        for _ in range(2):
            if (self.dir / "stopped").exists():
                shutil.rmtree(self.dir / "stopped")
            study = self.copy("stopped")
            session = self.stopped_session(study)
            results = race([cli("session", "resume", session, "--pacing", "lock-step")] * 2, self.dir)
            done = self.assert_turns(results, session.name)
            self.assertTrue(any(done), [r.stderr for r in results])
            self.assert_session_whole(session)
            self.assertEqual(len(self.report_rows(study)), 2)
            self.assert_clean(study)

    def test_two_resumes_by_two_names_one_a_link_save_the_missing_trial_once(self):
        study = self.copy("stopped")
        session = self.stopped_session(study)
        elsewhere = self.dir / "a" / "b"
        elsewhere.mkdir(parents=True)
        (elsewhere / session.name).symlink_to(session)
        results = race([cli("session", "resume", session, "--pacing", "lock-step"),
                        cli("session", "resume", elsewhere / session.name, "--pacing", "lock-step")], self.dir)
        done = [self.assert_ok_or_refused(r, session.name) for r in results]
        self.assertTrue(any(done), [r.stderr for r in results])
        self.assert_session_whole(session)
        self.assertEqual(len(self.report_rows(study)), 2)
        self.assert_clean(study)
        self.assert_clean(self.dir / "a")

    def test_two_runs_of_two_protocols_into_a_new_folder_make_one_study(self):
        for i in range(REPEAT - 1):
            study = self.dir / f"new{i}"
            cmds = [cli("session", "run", self.root / proto, "--subject", subject, "--out", study, *SIM)
                    for proto, subject in (("p.json", "A01"), ("q.json", "B01"))]
            results = race(cmds, self.dir)
            for ok, cmd in zip(self.assert_turns(results, study), cmds):
                if not ok:
                    self.check(run(cmd[1:], self.dir))
            identity = json.loads((study / ".calligraphy-study.json").read_text())["study_id"]
            found = sessions(study)
            self.assertEqual(len(found), 2)
            for s in found:
                self.assertEqual(json.loads((s / "session.json").read_text())["study_id"], identity, s)
                self.assert_session_whole(s)
            self.assertEqual(len(self.report_rows(study)), 4)
            self.assert_clean(study)

    def test_a_plan_beside_a_run_extending_the_study_prints_the_plan_alone(self):
        study = self.copy("st")
        solo = self.check(run(["session", "plan", self.root / "p.json", "--subjects", "2", "--json"], self.dir))
        results = race([cli("session", "run", self.root / "p.json", "--subjects", "1", "--new-subjects", "--out",
                            study, *SIM),
                        cli("session", "plan", self.root / "p.json", "--subjects", "2", "--json")], self.dir)
        self.check(results[0])
        self.assertEqual(self.check(results[1]).stdout, solo.stdout)
        self.assertEqual(len(sessions(study)), 2)
        self.assert_clean(study)

    def test_a_trace_of_a_saved_trial_while_a_resume_saves_the_next_reads_it_whole(self):
        study = self.copy("stopped")
        session = self.stopped_session(study)
        (saved,) = sorted((session / "trials").glob("001-*.trace.h5"))
        solo = self.check(run(["trace", saved], self.dir)).stdout
        results = race([cli("session", "resume", session, "--pacing", "lock-step"), cli("trace", saved)], self.dir)
        self.check(results[0])
        self.assertEqual(self.check(results[1]).stdout, solo)
        self.assert_session_whole(session)

    def test_a_run_killed_beside_a_report_leaves_a_study_its_subjects_next_run_finishes(self):
        study = self.dir / "k"
        for delay in (0.02, 0.07):
            (self.dir / "t").mkdir(exist_ok=True)
            results = race([cli("session", "run", self.root / "p.json", "--subject", "A01", "--out", study, *SIM),
                            cli("report", study, "--csv", "t")], self.dir, kill=(0, delay))
            self.assertIn(results[0].returncode, (0, -signal.SIGKILL))
            # The report reads what is there: nothing yet (refused, one line naming the folder) or whole trials.
            self.assert_ok_or_refused(results[1], study)
            # Killed before its first trial, the run leaves a folder named ".partial.": no session yet, which
            # the subject's next run removes (docs/experiments.md, "Sessions").
            found = [s for s in sessions(study) if not s.name.startswith(".partial.")]
            if found and (len(list((found[0] / "trials").glob("0*.json"))) < 2
                          or event(log_kinds(found[0])[-1]) != "session_completed"):
                self.check(run(["session", "resume", found[0], "--pacing", "lock-step"], self.dir))
            elif not found:
                self.check(run(["session", "run", self.root / "p.json", "--subject", "A01", "--out", study, *SIM],
                               self.dir))
            (session,) = sessions(study)
            self.assert_session_whole(session)
            self.assertEqual(len(self.report_rows(study)), 2)
            self.assert_clean(study)
            shutil.rmtree(study)

    # ---- corpus build ------------------------------------------------------------------------------------------

    def test_two_corpus_builds_of_one_store_leave_one_builds_store(self):
        for _ in range(REPEAT):
            for r in race([cli("corpus", "build", "--out", "s.clg", "--data", self.data, "--tolerance", t,
                               "--threads", "1") for t in ("10", "4")], self.dir):
                self.check(r)
            self.assertIn((self.dir / "s.clg").read_bytes(), self.stores)
            self.assert_clean(self.dir)

    def test_a_failing_corpus_build_beside_a_build_of_one_store_leaves_the_built_store(self):
        # A folder with no character file is an error naming it, no store written (docs/cli.md, "corpus build").
        (self.dir / "empty").mkdir()
        for t in ("4", "10"):
            results = race([cli("corpus", "build", "--out", "s.clg", "--data", "empty", "--threads", "1"),
                            cli("corpus", "build", "--out", "s.clg", "--data", self.data, "--tolerance", t,
                                "--threads", "1")], self.dir)
            self.assertEqual(results[0].returncode, 1)
            self.assertIn("empty", error_lines(results[0])[-1])
            self.check(results[1])
            self.assertEqual((self.dir / "s.clg").read_bytes(), self.stores[0 if t == "10" else 1])
            self.assert_clean(self.dir)

    def test_a_trial_reading_a_store_being_rebuilt_reads_one_whole_store(self):
        (self.dir / "s.clg").write_bytes(self.stores[1])
        for t in ("10", "4", "10"):
            results = race([cli("corpus", "build", "--out", "s.clg", "--data", self.data, "--tolerance", t,
                                "--threads", "1"),
                            cli("trial", YI, "--store", "s.clg", "--max-duration", "10", "--json", "-")], self.dir)
            self.check(results[0])
            self.check(results[1])
            self.assertTrue(json.loads(results[1].stdout))
            self.assert_clean(self.dir)

    def test_a_run_reading_a_store_being_rebuilt_saves_whole_trials(self):
        (self.dir / "s.clg").write_bytes(self.stores[1])
        study = self.dir / "o"
        for i, t in enumerate(("10", "4")):
            results = race([cli("corpus", "build", "--out", "s.clg", "--data", self.data, "--tolerance", t,
                                "--threads", "1"),
                            cli("session", "run", self.root / "p.json", "--subject", f"A0{i + 1}", "--store",
                                "s.clg", "--out", study, *SIM)], self.dir)
            self.check(results[0])
            self.check(results[1])
        for session in sessions(study):
            self.assert_session_whole(session)
        self.assertEqual(len(self.report_rows(study)), 4)
        self.assert_clean(self.dir)

    def test_a_trials_json_and_another_trials_csv_to_one_file_leave_one_writers_file(self):
        for _ in range(REPEAT):
            for r in race([cli("trial", YI, "--seed", "1", "--max-duration", "10", "--json", "x.out"),
                           cli("trial", YI, "--seed", "2", "--max-duration", "10", "--csv", "x.out")], self.dir):
                self.check(r)
            text = (self.dir / "x.out").read_bytes()
            if text != self.solo["2"]["csv"]:
                self.assertEqual(json.loads(text)["seed"], 1)
            self.assert_clean(self.dir)

    def test_a_plan_reading_a_store_being_rebuilt_plans_alone(self):
        (self.dir / "s.clg").write_bytes(self.stores[0])
        solo = self.check(run(["session", "plan", self.root / "p.json", "--subjects", "1", "--store", "s.clg"],
                              self.dir)).stdout
        for t in ("4", "10"):
            results = race([cli("corpus", "build", "--out", "s.clg", "--data", self.data, "--tolerance", t,
                                "--threads", "1"),
                            cli("session", "plan", self.root / "p.json", "--subjects", "1", "--store", "s.clg")],
                           self.dir)
            self.check(results[0])
            self.assertEqual(self.check(results[1]).stdout, solo)
            self.assert_clean(self.dir)

    # ---- Python beside the command line --------------------------------------------------------------------

    def test_study_load_while_a_run_adds_a_subject_loads_whole_trials(self):
        study = self.copy("st")
        code = ("import sys, calligraphy.study as s\n"
                "st = s.load(sys.argv[1])\n"
                "print(len(st.trials))\n")
        results = race([cli("session", "run", self.root / "p.json", "--subjects", "1", "--new-subjects", "--out",
                            study, *SIM),
                        [sys.executable, "-c", code, study]], self.dir)
        self.check(results[0])
        self.check(results[1])
        self.assertIn(int(results[1].stdout), (2, 3, 4))
        self.assertEqual(len(self.report_rows(study)), 4)
        self.assert_clean(study)

    def test_python_record_teacher_and_trial_record_to_one_file_leave_a_whole_teacher(self):
        code = ("import calligraphy as cg\n"
                "cg.record_teacher(cg.simulate_trial('一', writer='skilled', seed=5), 't.json')\n")
        results = race([[sys.executable, "-c", code],
                        cli("trial", YI, "--writer-profile", "skilled", "--seed", "6", "--max-duration", "10",
                            "--record", "t.json")], self.dir)
        for r in results:
            self.check(r)
        self.assertTrue(json.loads((self.dir / "t.json").read_text()))
        # The command line's replay reads what either wrote (the Python loader reads the same format).
        self.check(run(["trial", YI, "--guidance-mode", "replay", "--teacher", "t.json", "--max-duration", "10"],
                       self.dir))
        self.assert_clean(self.dir)

    # ---- a race and a kill ---------------------------------------------------------------------------------

    def test_two_resumes_one_killed_then_a_resume_completes_the_session(self):
        study = self.copy("stopped")
        session = self.stopped_session(study)
        results = race([cli("session", "resume", session, "--pacing", "lock-step")] * 2, self.dir,
                        kill=(0, 0.03))
        if results[0].returncode != -signal.SIGKILL:
            self.assert_ok_or_refused(results[0], session.name)
        self.assert_ok_or_refused(results[1], session.name)
        again = self.check(run(["session", "resume", session, "--pacing", "lock-step"], self.dir))
        self.assertTrue(again.stdout or again.stderr)
        self.assert_session_whole(session)
        self.assertEqual(len(self.report_rows(study)), 2)
        self.assert_clean(study)

    def test_two_reports_one_killed_then_a_report_leaves_the_tables_whole(self):
        (self.dir / "t").mkdir()
        for delay in (0.02, 0.05):
            results = race([cli("report", self.root / name, "--csv", "t", "--out", "r.html")
                            for name in ("st2", "st")], self.dir, kill=(0, delay))
            self.assertIn(results[0].returncode, (0, -signal.SIGKILL))
            self.check(results[1])
            pair = {f: (self.dir / "t" / f).read_bytes() for f in ("trials.csv", "strokes.csv")}
            self.assertIn(pair, [self.tables["st"], self.tables["st2"]])
            self.check(run(["report", self.root / "st", "--csv", "t", "--out", "r.html"], self.dir))
            pair = {f: (self.dir / "t" / f).read_bytes() for f in ("trials.csv", "strokes.csv")}
            self.assertEqual(pair, self.tables["st"])
            self.assert_clean(self.dir / "t")

    def test_two_corpus_builds_one_killed_leave_a_whole_store(self):
        (self.dir / "s.clg").write_bytes(self.stores[0])
        for delay in (0.005, 0.02):
            results = race([cli("corpus", "build", "--out", "s.clg", "--data", self.data, "--tolerance", t,
                                "--threads", "1") for t in ("4", "10")], self.dir, kill=(0, delay))
            self.assertIn(results[0].returncode, (0, -signal.SIGKILL))
            self.check(results[1])
            self.assertIn((self.dir / "s.clg").read_bytes(), self.stores)
            self.check(run(["corpus", "stats", "s.clg"], self.dir))
            self.check(run(["trial", YI, "--store", "s.clg", "--max-duration", "10"], self.dir))

    def test_two_runs_one_killed_then_a_resume_and_a_report_read_the_study(self):
        study = self.copy("st")
        results = race([cli("session", "run", self.root / "p.json", "--subjects", "1", "--new-subjects", "--out",
                            study, *SIM)] * 2, self.dir, kill=(0, 0.06))
        self.assertIn(results[0].returncode, (0, 1, -signal.SIGKILL))
        self.assert_ok_or_refused(results[1], study)
        for s in sessions(study):
            if len(list((s / "trials").glob("0*.json"))) < 2 or event(log_kinds(s)[-1]) != "session_completed":
                self.check(run(["session", "resume", s, "--pacing", "lock-step"], self.dir))
            self.assert_session_whole(s)
        rows = self.report_rows(study)
        self.assertEqual(len(rows), 2 * len(sessions(study)))
        self.assertIn(len(sessions(study)), (1, 2, 3))
        # A half-made folder of the killed run is skipped by the readers and removed by the subject's next run.
        self.check(run(["session", "run", self.root / "p.json", "--subjects", "1", "--new-subjects", "--out",
                        study, *SIM], self.dir))
        self.assert_clean(study)


if __name__ == "__main__":
    unittest.main()
