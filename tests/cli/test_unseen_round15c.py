#!/usr/bin/env python3
"""Round 15C: hostile cases written from the documentation alone (README.md, docs/cli.md, docs/python.md and
each command's `--help`) on the limits and events of a lab machine rather than the arguments: few file
descriptors (RLIMIT_NOFILE 4 to 8) for a trial with all its outputs, `session run`, `report --csv --out`,
`corpus build`, `score` of a gzip and Python's study report; little address space (RLIMIT_AS) for each; no
thread or process to be had (RLIMIT_NPROC 0, as nobody) for the commands that use threads and for the study
report, whose R cannot then start; an Rscript on PATH that cannot be executed; SIGHUP, SIGQUIT, SIGUSR1,
SIGXCPU and SIGSTOP/SIGCONT during a real-time trial and during `session run`; SIGPIPE on standard error;
standard output and error on /dev/full; a standard output pipe whose reader is slow or stops reading; a
study folder on a file system that fills mid-session; processes racing: four `trial --record` onto one file,
two `report --csv` into one folder, `score` reading a trace another process rewrites. Round 14B's angles
(locale, umask, a removed working directory, environment variables, a blocked signal mask, RLIMIT_NOFILE 16,
a 300 MB address space, RLIMIT_CPU on a session) are not repeated. Run by CTest as
`cli_unseen_round15c_tests`.

Each case asserts what the documentation promises: the exit status (0; 1 for a failed write, a library error
or a trial that ended early; 128 + N for a stop signal N), one error line naming the file, option or resource,
outputs whole or absent, nothing partial left (no temporary, no half-made folder), no crash, no hang beyond the
reader. CALLIGRAPHY_CLI names the program, CALLIGRAPHY_SOURCE_DIR the source tree (its hanzi-writer-data
sample), PYTHONPATH the Python module. CALLIGRAPHY_SANITIZED=1 takes five cases.
"""
import json
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

from outsider import CLI, ENV, SANITIZED, TIMEOUT_S, OneErrorLine, error_lines, run, sanitized_subset

SOURCE = Path(os.environ.get("CALLIGRAPHY_SOURCE_DIR", Path(__file__).resolve().parents[2]))
SAMPLE = SOURCE / "data" / "hanzi-writer-data"
YI = "一"
PYTHON = "/usr/bin/python3" if os.path.exists("/usr/bin/python3") else sys.executable
NOBODY = 65534

load_tests = sanitized_subset({"test_sighup_during_a_real_time_trial_keeps_every_tick",
                               "test_sigpipe_on_standard_error_loses_no_output",
                               "test_a_reader_that_stops_reading_then_closes_ends_the_writer",
                               "test_four_trial_records_racing_onto_one_file",
                               "test_sigstop_longer_than_the_watchdog_ends_the_trial_safely"})

# Two conditions of one tiny character: two trials a subject.
PROTOCOL = {"name": "r15", "conditions": [{"name": "u", "mode": "vision"}, {"name": "f", "mode": "haptic"}],
            "test": {"characters": [YI], "conditions": ["u", "f"], "repetitions": 1},
            "trial": {"max_duration_s": 20}}
TRIAL = [YI, "--seed", "1", "--max-duration", "20"]
REAL_TIME = [YI, "--pacing", "real-time", "--max-duration", "8"]


def no_core():
    resource.setrlimit(resource.RLIMIT_CORE, (0, 0))


def limited(nofile=None, address_space=None):
    """A preexec_fn setting the limits given (and no core file)."""
    def apply():
        no_core()
        if nofile is not None:
            resource.setrlimit(resource.RLIMIT_NOFILE, (nofile, nofile))
        if address_space is not None:
            resource.setrlimit(resource.RLIMIT_AS, (address_space << 20, address_space << 20))
    return apply


def nobody_without_processes():
    """A preexec_fn: the user nobody with RLIMIT_NPROC 0 (root is not held to it), so no thread or process
    can be started."""
    no_core()
    os.setgroups([])
    os.setgid(NOBODY)
    os.setuid(NOBODY)
    resource.setrlimit(resource.RLIMIT_NPROC, (0, 0))


def leftovers(folder):
    """What a failed or killed writer must not leave: temporaries of an atomic write (`.NAME.tmp-PID-N`), a
    session folder being made (`.partial.`), a set's journal."""
    return [p for p in Path(folder).rglob("*")
            if ".tmp-" in p.name or ".partial." in p.name or p.name.endswith(".journal")]


def strict_json(data):
    def refuse(token):
        raise ValueError(f"not JSON: {token}")
    return json.loads(data, parse_constant=refuse)


def score_of(output):
    """A `score --json -` document without its `trace` (the path it was given), to compare two runs."""
    document = strict_json(output)
    document.pop("trace")
    return document


def csv_rows(path):
    return Path(path).read_text(encoding="utf-8").strip().splitlines()[1:]


def wait_for_trial(process, ticks_s=0.1):
    """Waits until `process` runs a trial, then `ticks_s` more: a trial's servo loop runs on threads of its
    own (with the log's drain), so the process has more than one thread from its first tick to its last.
    Without /proc, a second's wait as before. Polled every 10 ms, never past TIMEOUT_S."""
    if not os.path.isdir("/proc/self/task"):
        time.sleep(1.0)
        return
    deadline = time.monotonic() + TIMEOUT_S
    while process.poll() is None and time.monotonic() < deadline:
        try:
            if len(os.listdir(f"/proc/{process.pid}/task")) > 1:
                time.sleep(ticks_s)
                return
        except OSError:
            return
        time.sleep(0.01)


class Shared:
    """Made once: a trial's CSV trace and its gzip, their score; two tiny studies and their tables; a data
    folder of two characters."""
    dir = None

    @classmethod
    def make(cls):
        if cls.dir is not None:
            return
        cls.dir = Path(tempfile.mkdtemp(prefix="round15c-"))
        os.chmod(cls.dir, 0o755)
        base = cls.dir / "base"
        base.mkdir()
        result = run(["trial", *TRIAL, "--csv", "a.csv", "--json", "a.json"], base)
        assert result.returncode == 0, result.stderr
        subprocess.run(["gzip", "-k", str(base / "a.csv")], check=True, timeout=TIMEOUT_S)
        result = run(["score", "a.csv", "--character", YI, "--json", "-"], base)
        assert result.returncode == 0, result.stderr
        cls.score = score_of(result.stdout)
        (base / "p.json").write_text(json.dumps(PROTOCOL, ensure_ascii=False), encoding="utf-8")
        cls.tables = {}
        for study, subjects in (("st", "3"), ("sb", "2")):
            result = run(["session", "run", "p.json", "--writer", "simulated", "--subjects", subjects,
                          "--out", study], base)
            assert result.returncode == 0, result.stderr
            (base / f"t-{study}").mkdir()
            result = run(["report", base / study, "--csv", f"t-{study}", "--jobs", "1"], base)
            assert result.returncode == 0, result.stderr
            cls.tables[study] = tuple((base / f"t-{study}" / n).read_bytes() for n in ("trials.csv", "strokes.csv"))
        (base / "data").mkdir()
        for char in ("十", "乙"):
            shutil.copy(SAMPLE / f"{char}.json", base / "data" / f"{char}.json")
        for path in (base, *base.rglob("*")):
            os.chmod(path, 0o755 if path.is_dir() else 0o644)
        cls.base = base


def tearDownModule():  # noqa: N802 - unittest's name
    if Shared.dir is not None:
        shutil.rmtree(Shared.dir, ignore_errors=True)


class Case(OneErrorLine, unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        Shared.make()
        cls.base = Shared.base

    def setUp(self):
        self.dir = Path(tempfile.mkdtemp(prefix="case-", dir=Shared.dir))
        os.chmod(self.dir, 0o777)

    def cli(self, *args, **kw):
        return run(list(args), self.dir, **kw)

    def assert_no_leftovers(self, folder=None):
        self.assertEqual(leftovers(folder or self.dir), [])

    def assert_clean_failure(self, result, *needles):
        """Exit 1 and one error line (after any plan lines a session prints first) holding each needle."""
        text = result.stderr.decode("utf-8", "replace")
        self.assertEqual(result.returncode, 1, text)
        self.assertNotIn("terminate called", text)
        self.assertNotIn("internal error", text)
        self.assertNotIn("Traceback", text)
        errors = [line for line in error_lines(result) if "error" in line]
        self.assertEqual(len(errors), 1, errors)
        for needle in needles:
            self.assertIn(needle, errors[0])
        return errors[0]


class FewDescriptors(Case):
    """RLIMIT_NOFILE 4 to 8: "a failed write prints one line naming the file and the reason, exits 1, removes
    the temporary" (docs/cli.md, "Outputs"); a refused or failed command leaves nothing partial."""

    def test_trial_with_every_output_under_few_descriptors(self):
        for n in (4, 5, 8):
            with self.subTest(nofile=n):
                out = self.dir / f"n{n}"
                out.mkdir()
                result = self.cli("trial", YI, "--writer-profile", "skilled", "--max-duration", "20", "--json",
                                  out / "a.json", "--csv", out / "a.csv", "--svg", out / "a.svg", "--record",
                                  out / "r.json", preexec_fn=limited(nofile=n))
                if result.returncode == 0:
                    self.assertEqual(sorted(p.name for p in out.iterdir()), ["a.csv", "a.json", "a.svg", "r.json"])
                    self.assertEqual(strict_json((out / "a.json").read_bytes())["end_reason"], "completed")
                else:
                    self.assert_clean_failure(result, "Too many open files")
                self.assert_no_leftovers(out)

    def test_session_run_under_few_descriptors_leaves_no_half_made_folder(self):
        shutil.copy(self.base / "p.json", self.dir / "p.json")
        for n in (5, 6, 7):
            with self.subTest(nofile=n):
                out = f"st{n}"
                result = self.cli("session", "run", "p.json", "--writer", "simulated", "--subjects", "2", "--out",
                                  out, preexec_fn=limited(nofile=n))
                if result.returncode == 0:
                    self.assertEqual(len(list((self.dir / out).glob("S0?/*/trials/*.json"))), 4)
                else:
                    self.assert_clean_failure(result, "Too many open files")
                    # Whatever was made is whole: a session folder holds its session.json.
                    for session in (self.dir / out).glob("S0?/*"):
                        self.assertTrue((session / "session.json").is_file(), session)
                self.assert_no_leftovers(self.dir / out)

    def test_report_under_few_descriptors_never_says_there_is_no_session(self):
        # The study is there; a report that cannot open it must say why, not that it found nothing.
        for n in (4, 5):
            with self.subTest(nofile=n):
                (self.dir / f"t{n}").mkdir()
                result = self.cli("report", self.base / "st", "--csv", f"t{n}", "--jobs", "1",
                                  preexec_fn=limited(nofile=n))
                if result.returncode == 0:
                    self.assertEqual((self.dir / f"t{n}" / "trials.csv").read_bytes(), Shared.tables["st"][0])
                else:
                    line = self.assert_clean_failure(result, "Too many open files")
                    self.assertNotIn("no session folder", line)
                    self.assertEqual(list((self.dir / f"t{n}").iterdir()), [])

    def test_report_pages_and_tables_under_few_descriptors_leave_nothing(self):
        for n in (5, 6, 7, 8):
            with self.subTest(nofile=n):
                case = self.dir / f"n{n}"
                (case / "t").mkdir(parents=True)
                result = run(["report", self.base / "st", "--csv", "t", "--out", "r.html", "--jobs", "2"], case,
                             preexec_fn=limited(nofile=n))
                if result.returncode == 0:
                    self.assertEqual((case / "t" / "trials.csv").read_bytes(), Shared.tables["st"][0])
                    self.assertTrue((case / "r.html").is_file())
                else:
                    self.assert_clean_failure(result, "Too many open files")
                    # A refused or failed command creates no folder and no file.
                    self.assertEqual(sorted(p.name for p in case.iterdir()), ["t"])
                    self.assertEqual(list((case / "t").iterdir()), [])
                self.assert_no_leftovers(case)

    def test_corpus_build_under_few_descriptors(self):
        good = self.dir / "good.clg"
        self.assertEqual(self.cli("corpus", "build", "--data", self.base / "data", "--out", good).returncode, 0)
        for n in (4, 6):
            with self.subTest(nofile=n):
                store = self.dir / f"c{n}.clg"
                shutil.copy(good, store)
                result = self.cli("corpus", "build", "--data", self.base / "data", "--out", store, "--threads", "2",
                                  preexec_fn=limited(nofile=n))
                if result.returncode != 0:
                    # docs/cli.md: exit 1, one line naming the file the machine would not open; the data is not
                    # at fault, so the earlier store is kept whole, never replaced by one without those characters.
                    self.assert_clean_failure(result, "Too many open files", ".json")
                    self.assertEqual(store.read_bytes(), good.read_bytes())
                self.assert_no_leftovers()

    def test_score_of_a_gzip_under_few_descriptors(self):
        for n in (4, 5):
            with self.subTest(nofile=n):
                result = self.cli("score", self.base / "a.csv.gz", "--character", YI, "--json", "-",
                                  preexec_fn=limited(nofile=n))
                if result.returncode == 0:
                    self.assertEqual(score_of(result.stdout), Shared.score)
                else:
                    self.assert_clean_failure(result, "Too many open files")

    def test_python_study_report_under_few_descriptors(self):
        # Python needs a few descriptors of its own to start; 6 leaves none for the report's files.
        env = dict(ENV, PATH=str(self.python_only_path()), MPLCONFIGDIR=str(self.dir / "mpl"))
        result = subprocess.run([PYTHON, "-m", "calligraphy.study_report", str(self.base / "st"), "--out", "rep"],
                                cwd=self.dir, env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                                stdin=subprocess.DEVNULL, timeout=TIMEOUT_S, preexec_fn=limited(nofile=6))
        if result.returncode == 0:
            self.assertTrue((self.dir / "rep" / "index.html").is_file())
        else:
            text = result.stderr.decode("utf-8", "replace")
            self.assertEqual(result.returncode, 1, text)
            self.assertNotIn("Traceback", text)
            self.assertEqual(len(error_lines(result)), 1, text)
            self.assertIn("Too many open files", text)
            # Nothing partial: no page, no table, no figure, no folder of them.
            self.assertEqual([p for p in (self.dir / "rep").rglob("*")] if (self.dir / "rep").exists() else [], [])
        self.assert_no_leftovers()

    def python_only_path(self):
        folder = self.dir / "bin"
        folder.mkdir(exist_ok=True)
        os.symlink(PYTHON, folder / "python3")
        return folder


class LittleMemory(Case):
    """RLIMIT_AS just above what the program needs to load: "bad input gets a clear error, never a crash";
    running out of memory is one line and exit 1 (or success), never an abort, a core or an internal error."""

    def skip_under_sanitizers(self):
        if SANITIZED:
            self.skipTest("the sanitizers' shadow memory needs terabytes of address space")

    def assert_memory_outcome(self, result, reason=()):
        text = result.stderr.decode("utf-8", "replace")
        self.assertGreaterEqual(result.returncode, 0, f"killed by a signal: {text}")
        if result.returncode == 127 and "error while loading shared libraries" in text:
            return False  # the limit is below what the dynamic loader needs: not the program's to report
        if result.returncode != 0:
            line = self.assert_clean_failure(result)
            self.assertTrue(any(word in line for word in ("memory", "thread", *reason)), line)
        return result.returncode == 0

    def test_trial_under_little_address_space(self):
        self.skip_under_sanitizers()
        for mb in (55, 60, 80):
            with self.subTest(megabytes=mb):
                out = self.dir / f"m{mb}"
                out.mkdir()
                result = self.cli("trial", *TRIAL, "--json", out / "a.json", "--csv", out / "a.csv",
                                  preexec_fn=limited(address_space=mb))
                if self.assert_memory_outcome(result):
                    self.assertEqual((out / "a.csv").read_bytes(), (self.base / "a.csv").read_bytes())
                else:
                    self.assertEqual(list(out.iterdir()), [])
                self.assert_no_leftovers(out)

    def test_report_under_little_address_space(self):
        self.skip_under_sanitizers()
        for mb in (55, 60, 70):
            with self.subTest(megabytes=mb):
                tables = self.dir / f"t{mb}"
                tables.mkdir()
                result = self.cli("report", self.base / "st", "--csv", tables, "--jobs", "2",
                                  preexec_fn=limited(address_space=mb))
                if self.assert_memory_outcome(result):
                    self.assertEqual((tables / "trials.csv").read_bytes(), Shared.tables["st"][0])
                else:
                    self.assertEqual(list(tables.iterdir()), [])
                self.assert_no_leftovers()

    def test_corpus_build_under_little_address_space(self):
        self.skip_under_sanitizers()
        for mb in (55, 60, 65, 80):
            with self.subTest(megabytes=mb):
                store = self.dir / f"c{mb}.clg"
                result = self.cli("corpus", "build", "--data", self.base / "data", "--out", store, "--threads", "2",
                                  preexec_fn=limited(address_space=mb))
                if not self.assert_memory_outcome(result):
                    self.assertFalse(store.exists())
                self.assert_no_leftovers()

    def test_session_run_and_score_under_little_address_space(self):
        self.skip_under_sanitizers()
        shutil.copy(self.base / "p.json", self.dir / "p.json")
        for mb in (55, 60):
            with self.subTest(megabytes=mb):
                result = self.cli("session", "run", "p.json", "--writer", "simulated", "--subjects", "1",
                                  "--out", f"st{mb}", preexec_fn=limited(address_space=mb))
                # A trial whose files cannot be made stops the session with one line naming the trial
                # (docs/cli.md, "session run"; HDF5 may not say that memory was the cause).
                if self.assert_memory_outcome(result, reason=("could not be saved",)):
                    self.assertEqual(len(list((self.dir / f"st{mb}").glob("S01/*/trials/*.json"))), 2)
                self.assert_no_leftovers()
                scored = self.cli("score", self.base / "a.csv.gz", "--character", YI, "--json", "-",
                                  preexec_fn=limited(address_space=mb))
                if self.assert_memory_outcome(scored):
                    self.assertEqual(score_of(scored.stdout), Shared.score)


class NoProcesses(Case):
    """RLIMIT_NPROC 0 as nobody: no thread and no process can be started. A command that reads on threads
    says so on one line (exit 1) or reads on its own; the study report's R cannot start, so its models are
    "not computed" and the page is still made (docs/python.md)."""

    def setUp(self):
        super().setUp()
        if os.geteuid() != 0:
            self.skipTest("becoming nobody needs root")

    def test_commands_with_threads_when_no_thread_can_start(self):
        for folder in ("t", "c"):
            (self.dir / folder).mkdir()
            os.chmod(self.dir / folder, 0o777)
        # Each command and the file its success writes.
        runs = {"corpus build": (["corpus", "build", "--data", self.base / "data", "--out", self.dir / "c.clg",
                                  "--threads", "2"], self.dir / "c.clg"),
                "report": (["report", self.base / "st", "--csv", self.dir / "t", "--jobs", "2"],
                           self.dir / "t" / "trials.csv"),
                "session cohort": (["session", "cohort", self.base / "p.json", "--subjects", "2", "--jobs", "2",
                                    "--csv", self.dir / "c"], self.dir / "c" / "trials.csv"),
                "real-time trial": (["trial", *REAL_TIME, "--json", self.dir / "a.json"], self.dir / "a.json")}
        for name, (args, output) in runs.items():
            with self.subTest(command=name):
                result = self.cli(*args, preexec_fn=nobody_without_processes)
                if result.returncode == 0:
                    self.assertTrue(output.is_file(), output)
                else:
                    self.assert_clean_failure(result, "thread")
                    self.assertFalse(output.exists())
                self.assert_no_leftovers()
        self.assertEqual((self.dir / "t" / "trials.csv").read_bytes(), Shared.tables["st"][0])

    def test_study_report_when_r_cannot_start(self):
        # matplotlib builds its font cache on a thread of its own the first time: the cache is made (or copied)
        # beforehand, as on a lab machine that made a figure before.
        mpl = self.dir / "mpl"
        mpl.mkdir(mode=0o777)
        cached = sorted((Path.home() / ".cache" / "matplotlib").glob("fontlist-*.json"))
        if cached:
            shutil.copy(cached[-1], mpl)
        else:
            subprocess.run([PYTHON, "-c", "import matplotlib.font_manager"], env=dict(ENV, MPLCONFIGDIR=str(mpl)),
                           stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, timeout=TIMEOUT_S, check=False)
        for path in (mpl, *mpl.iterdir()):
            os.chmod(path, 0o777)
        env = dict(ENV, HOME=str(self.dir), MPLCONFIGDIR=str(mpl))
        result = subprocess.run([PYTHON, "-m", "calligraphy.study_report", str(self.base / "st"), "--out", "rep"],
                                cwd=self.dir, env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                                stdin=subprocess.DEVNULL, timeout=TIMEOUT_S, preexec_fn=nobody_without_processes)
        text = result.stderr.decode("utf-8", "replace")
        self.assertEqual(result.returncode, 0, text)
        self.assertNotIn("Traceback", text)
        page = (self.dir / "rep" / "index.html").read_text(encoding="utf-8")
        self.assertIn("not computed: Rscript could not be run", page)
        self.assert_no_leftovers()


class UnexecutableR(Case):
    def test_study_report_with_an_rscript_that_cannot_be_executed(self):
        folder = self.dir / "bin"
        folder.mkdir()
        os.symlink(PYTHON, folder / "python3")
        (folder / "Rscript").write_text("#!/bin/sh\necho garbage\n", encoding="utf-8")
        os.chmod(folder / "Rscript", 0o644)
        env = dict(ENV, PATH=str(folder), MPLCONFIGDIR=str(self.dir / "mpl"))
        result = subprocess.run([PYTHON, "-m", "calligraphy.study_report", str(self.base / "st"), "--out", "rep"],
                                cwd=self.dir, env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                                stdin=subprocess.DEVNULL, timeout=TIMEOUT_S)
        self.assertEqual(result.returncode, 0, result.stderr)
        self.assertIn("not computed", (self.dir / "rep" / "index.html").read_text(encoding="utf-8"))


class Signals(Case):
    """docs/cli.md, "Stopping a trial": SIGINT, SIGTERM and SIGHUP stop a running trial at its next tick with
    zero force, every recorded tick written, exit 128 + N; SIGKILL and SIGQUIT still end the program."""

    def real_time(self, sig, extra=(), pause=None):
        process = subprocess.Popen([CLI, "trial", *REAL_TIME, *extra, "--json", "b.json", "--csv", "b.csv"],
                                   cwd=self.dir, env=ENV, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                                   stdin=subprocess.DEVNULL, preexec_fn=no_core)
        try:
            wait_for_trial(process)
            self.assertIsNone(process.poll(), "the trial ended before the signal")
            if pause is not None:
                process.send_signal(signal.SIGSTOP)
                time.sleep(pause)
                process.send_signal(signal.SIGCONT)
            else:
                process.send_signal(sig)
            stdout, stderr = process.communicate(timeout=TIMEOUT_S)
        finally:
            if process.poll() is None:
                process.kill()
                process.communicate()
        return process.returncode, stdout, stderr

    def assert_every_tick_kept(self, end_reason):
        record = strict_json((self.dir / "b.json").read_bytes())
        self.assertEqual(record["end_reason"], end_reason)
        rows = csv_rows(self.dir / "b.csv")
        self.assertEqual(len(rows), record["loop"]["ticks"])
        return record

    def stops_cleanly(self, sig):
        status, stdout, stderr = self.real_time(sig)
        self.assertEqual(status, 128 + sig, stderr)
        # The trial (about 3.8 s) runs when the signal comes a tenth of a second after its servo loop started;
        # had it not started, "a signal before the trial started opens no device and writes nothing" (docs/cli.md).
        if not (self.dir / "b.json").exists():
            self.assertEqual(sorted(p.name for p in self.dir.iterdir()), [])
            return
        record = self.assert_every_tick_kept("interrupted")
        self.assertIn(signal.Signals(sig).name, record["abort_reason"])
        said = [line for line in stderr.decode().splitlines() if "stopped by" in line]
        self.assertEqual(len(said), 1, stderr)
        self.assertIn(signal.Signals(sig).name, said[0])
        self.assert_no_leftovers()

    def test_sighup_during_a_real_time_trial_keeps_every_tick(self):
        self.stops_cleanly(signal.SIGHUP)

    def test_sigusr1_during_a_real_time_trial_keeps_every_tick(self):
        # The documentation (after this round) names SIGUSR1, which batch schedulers send before a job's end.
        self.stops_cleanly(signal.SIGUSR1)

    def test_sigxcpu_during_a_real_time_trial_keeps_every_tick(self):
        # A CPU time limit reached (RLIMIT_CPU's soft limit): the trial still ends with its ticks written.
        self.stops_cleanly(signal.SIGXCPU)

    def test_sigquit_during_a_real_time_trial_ends_the_program(self):
        status, _, _ = self.real_time(signal.SIGQUIT)
        self.assertEqual(status, -signal.SIGQUIT)
        # Ended by the signal before any output was written: nothing partial, no temporary.
        self.assertEqual(sorted(p.name for p in self.dir.iterdir()), [])

    def test_sigstop_longer_than_the_watchdog_ends_the_trial_safely(self):
        # A stopped process holds the device's last force: after 1 s stopped the 50 ms watchdog ends the trial
        # with zero force, exit 1 (ended early), every tick written.
        status, _, stderr = self.real_time(None, pause=1.0)
        self.assertEqual(status, 1, stderr)
        record = self.assert_every_tick_kept("watchdog")
        self.assertGreaterEqual(record["loop"]["longest_stall_ms"], 900)
        errors = [line for line in error_lines(type("R", (), {"stderr": stderr})()) if "error" in line]
        self.assertEqual(len(errors), 1, errors)
        self.assertIn("watchdog", errors[0])

    def test_sigstop_without_a_watchdog_resumes_the_trial(self):
        # Stopped 0.3 s, six times the default watchdog's 50 ms: with --watchdog-ms 0 the trial goes on to its
        # end, written by a quick writer (docs/writer.md: about 1.4 s of writing rather than 3.8 s).
        quick = ("--writer-profile", "skilled", "--writer-param", "writing_speed_m_s=0.1", "--writer-param",
                 "travel_speed_m_s=0.3")
        status, _, stderr = self.real_time(None, pause=0.3, extra=("--watchdog-ms", "0", *quick))
        self.assertEqual(status, 0, stderr)
        self.assert_every_tick_kept("completed")

    def session(self, *extra):
        shutil.copy(self.base / "p.json", self.dir / "p.json")
        return subprocess.Popen([CLI, "session", "run", "p.json", "--writer", "simulated", "--subject", "S01",
                                 "--pacing", "real-time", "--out", "st", *extra], cwd=self.dir, env=ENV,
                                stdout=subprocess.PIPE, stderr=subprocess.PIPE, stdin=subprocess.DEVNULL,
                                preexec_fn=no_core)

    def test_sighup_during_a_real_time_session_then_resume(self):
        process = self.session()
        try:
            wait_for_trial(process)  # its first trial running
            self.assertIsNone(process.poll(), "the session ended before the signal")
            process.send_signal(signal.SIGHUP)
            _, stderr = process.communicate(timeout=TIMEOUT_S)
        finally:
            if process.poll() is None:
                process.kill()
                process.communicate()
        self.assertEqual(process.returncode, 128 + signal.SIGHUP, stderr)
        said = [line for line in stderr.decode().splitlines() if "stopped by SIGHUP" in line]
        self.assertEqual(len(said), 1, stderr)
        self.assertIn("session resume", said[0])
        sessions = list((self.dir / "st" / "S01").glob("r15-*"))
        self.assertEqual(len(sessions), 1)
        attempts = list((sessions[0] / "trials" / "attempts").glob("*.json"))
        self.assertEqual(len(attempts), 1)
        self.assertIn("SIGHUP", strict_json(attempts[0].read_bytes())["abort_reason"])
        resumed = self.cli("session", "resume", sessions[0], "--pacing", "lock-step")
        self.assertEqual(resumed.returncode, 0, resumed.stderr)
        self.assertEqual(len(list((sessions[0] / "trials").glob("*.json"))), 2)
        self.assert_no_leftovers()

    def test_sigstop_and_sigcont_during_a_lock_step_session(self):
        shutil.copy(self.base / "p.json", self.dir / "p.json")
        process = subprocess.Popen([CLI, "session", "run", "p.json", "--writer", "simulated", "--subjects", "3",
                                    "--out", "st"], cwd=self.dir, env=ENV, stdout=subprocess.PIPE,
                                   stderr=subprocess.PIPE, stdin=subprocess.DEVNULL)
        try:
            time.sleep(0.05)
            process.send_signal(signal.SIGSTOP)
            time.sleep(0.2)
            process.send_signal(signal.SIGCONT)
            _, stderr = process.communicate(timeout=TIMEOUT_S)
        finally:
            if process.poll() is None:
                process.kill()
                process.communicate()
        self.assertEqual(process.returncode, 0, stderr)
        self.assertEqual(len(list((self.dir / "st").glob("S0?/*/trials/*.json"))), 6)
        self.assert_no_leftovers()

    def test_sigpipe_on_standard_error_loses_no_output(self):
        # Standard error a pipe whose reader is gone: the trial's error line cannot be written, yet the trial
        # (ended by its time limit) writes its outputs and exits 1, never killed by SIGPIPE.
        read, write = os.pipe()
        os.close(read)
        try:
            result = self.cli("trial", YI, "--max-duration", "0.5", "--json", "a.json", "--csv", "a.csv",
                              stderr=write)
        finally:
            os.close(write)
        self.assertEqual(result.returncode, 1)
        self.assertEqual(strict_json((self.dir / "a.json").read_bytes())["end_reason"], "time_limit")
        self.assertEqual(len(csv_rows(self.dir / "a.csv")), 500)
        self.assert_no_leftovers()


class StandardStreams(Case):
    def test_standard_output_on_dev_full(self):
        with open("/dev/full", "wb") as full:
            result = self.cli("trial", *TRIAL, "--json", "-", stdout=full)
        self.assert_one_error(result, 1, "standard output")
        with open("/dev/full", "wb") as full:
            result = self.cli("trial", *TRIAL, "--json", "a.json", stdout=full)
        self.assert_one_error(result, 1, "standard output")
        self.assertEqual(strict_json((self.dir / "a.json").read_bytes())["end_reason"], "completed")

    def test_standard_output_and_error_on_dev_full(self):
        with open("/dev/full", "wb") as full:
            result = self.cli("trial", *TRIAL, "--csv", "-", "--json", "a.json", stdout=full, stderr=full)
            report = self.cli("report", self.base / "st", "--csv", "-", stdout=full, stderr=full)
        self.assertEqual(result.returncode, 1)
        self.assertEqual(strict_json((self.dir / "a.json").read_bytes())["end_reason"], "completed")
        self.assertIn(report.returncode, (1, 2))  # `-` may be refused for --csv DIR; never a crash
        self.assert_no_leftovers()

    def big_output(self):
        return subprocess.Popen([CLI, "trial", YI, "--seed", "1", "--rate", "10000", "--csv", "-"], cwd=self.dir,
                                env=ENV, stdout=subprocess.PIPE, stderr=subprocess.PIPE, stdin=subprocess.DEVNULL)

    def test_a_slow_reader_gets_every_byte(self):
        whole = self.cli("trial", YI, "--seed", "1", "--rate", "10000", "--csv", "-").stdout
        self.assertGreater(len(whole), 1 << 20)
        process = self.big_output()
        got = bytearray()
        try:
            time.sleep(0.2)  # the pipe is full; the program waits for its reader
            while chunk := process.stdout.read1(256 << 10):
                got += chunk
                time.sleep(0.02)
            process.wait(timeout=TIMEOUT_S)
        finally:
            if process.poll() is None:
                process.kill()
            process.communicate()
        self.assertEqual(process.returncode, 0)
        self.assertEqual(bytes(got), whole)

    def test_a_reader_that_stops_reading_then_closes_ends_the_writer(self):
        process = self.big_output()
        try:
            process.stdout.read(4096)
            time.sleep(0.5)  # the whole output, unread, takes under 0.2 s to write
            self.assertIsNone(process.poll(), "the program did not wait for its reader")
            process.stdout.close()
            process.wait(timeout=10)
            stderr = process.stderr.read()
        finally:
            if process.poll() is None:
                process.kill()
                process.wait()
            process.stderr.close()
        self.assertEqual(process.returncode, 1)
        lines = stderr.decode().strip().splitlines()
        self.assertEqual(len(lines), 1, lines)
        self.assertIn("standard output", lines[0])


class FullDisk(Case):
    """docs/cli.md, "session run": a trial whose files cannot be saved (the disk filled after the run began)
    stops the session there, every trial saved before kept, exit 1 naming `session resume`, which runs that
    trial again."""

    def mount(self, folder, size):
        folder.mkdir()
        done = subprocess.run(["mount", "-t", "tmpfs", "-o", f"size={size},mode=0777", "tmpfs", str(folder)],
                              stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, check=False)
        if done.returncode != 0:
            self.skipTest("no tmpfs can be mounted here (not root, or no mount permission)")
        self.addCleanup(subprocess.run, ["umount", "-l", str(folder)], check=False)

    def test_a_session_on_a_disk_that_fills(self):
        disk = self.dir / "disk"
        self.mount(disk, "3m")
        protocol = dict(PROTOCOL, test={"characters": [YI], "conditions": ["u", "f"], "repetitions": 30})
        (self.dir / "p.json").write_text(json.dumps(protocol, ensure_ascii=False), encoding="utf-8")
        result = self.cli("session", "run", "p.json", "--writer", "simulated", "--subject", "S01", "--out",
                          disk / "st")
        sessions = list((disk / "st" / "S01").glob("r15-*"))
        self.assertEqual(len(sessions), 1, result.stderr)
        saved = sorted((sessions[0] / "trials").glob("*.json"))
        if result.returncode == 0:
            self.skipTest("the 60 trials fitted on the small disk: nothing filled it")
        line = self.assert_clean_failure(result, "No space left on device", "session resume")
        self.assertGreater(len(saved), 0, line)
        for record in saved:
            strict_json(record.read_bytes())
        self.assert_no_leftovers(disk)
        # Room again: resume runs the rest.
        for filler in sessions[0].glob("trials/*.svg"):
            filler.unlink()
        subprocess.run(["mount", "-o", "remount,size=16m", str(disk)], check=True)
        resumed = self.cli("session", "resume", sessions[0])
        self.assertEqual(resumed.returncode, 0, resumed.stderr)
        self.assertEqual(len(list((sessions[0] / "trials").glob("*.json"))), 60)


class Races(Case):
    def test_four_trial_records_racing_onto_one_file(self):
        seeds = ("1", "2", "3", "4")
        alone = {}
        for seed in seeds:
            result = self.cli("trial", YI, "--writer-profile", "skilled", "--seed", seed, "--record", f"r{seed}.json")
            self.assertEqual(result.returncode, 0, result.stderr)
            alone[seed] = (self.dir / f"r{seed}.json").read_bytes()
        self.assertEqual(len(set(alone.values())), 4)
        for _ in range(2):
            processes = [subprocess.Popen([CLI, "trial", YI, "--writer-profile", "skilled", "--seed", seed,
                                           "--record", "same.json"], cwd=self.dir, env=ENV,
                                          stdout=subprocess.DEVNULL, stderr=subprocess.PIPE,
                                          stdin=subprocess.DEVNULL) for seed in seeds]
            for process in processes:
                _, stderr = process.communicate(timeout=TIMEOUT_S)
                self.assertEqual(process.returncode, 0, stderr)
            self.assertIn((self.dir / "same.json").read_bytes(), alone.values())
        self.assert_no_leftovers()

    def test_two_reports_racing_into_one_tables_folder(self):
        (self.dir / "t").mkdir()
        for _ in range(3):
            processes = [subprocess.Popen([CLI, "report", str(self.base / study), "--csv", "t", "--jobs", "1"],
                                          cwd=self.dir, env=ENV, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE,
                                          stdin=subprocess.DEVNULL) for study in ("st", "sb")]
            for process in processes:
                _, stderr = process.communicate(timeout=TIMEOUT_S)
                self.assertEqual(process.returncode, 0, stderr)
            pair = tuple((self.dir / "t" / n).read_bytes() for n in ("trials.csv", "strokes.csv"))
            self.assertIn(pair, (Shared.tables["st"], Shared.tables["sb"]), "the tables of two reports mixed")
        self.assert_no_leftovers()

    def test_score_reads_a_trace_another_process_rewrites(self):
        seeds = ("1", "2", "3")
        scores = {}
        for seed in seeds:
            self.assertEqual(self.cli("trial", YI, "--seed", seed, "--csv", f"s{seed}.csv").returncode, 0)
            scores[seed] = score_of(self.cli("score", f"s{seed}.csv", "--character", YI, "--json", "-").stdout)
        stop = threading.Event()

        def rewrite():
            while not stop.is_set():
                for seed in seeds:
                    run(["trial", YI, "--seed", seed, "--csv", "live.csv"], self.dir)
        shutil.copy(self.dir / "s1.csv", self.dir / "live.csv")
        writer = threading.Thread(target=rewrite)
        writer.start()
        try:
            results = [self.cli("score", "live.csv", "--character", YI, "--json", "-") for _ in range(12)]
        finally:
            stop.set()
            writer.join()
        for result in results:
            self.assertEqual(result.returncode, 0, result.stderr)
            self.assertIn(score_of(result.stdout), list(scores.values()), "a score of a mix of two traces")
        self.assert_no_leftovers()


if __name__ == "__main__":
    unittest.main(verbosity=2)
