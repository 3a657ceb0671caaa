#!/usr/bin/env python3
"""Hostile cases written from the documentation alone (docs/python.md, docs/experiments.md, `help()` of the
module's public names and the stubs `_calligraphy.pyi`): the Python module `calligraphy` in a notebook or a script
that is stopped, threaded or forked. Run by CTest as `cli_unseen_round20c_tests`. Round 16D pickled, pooled and
stopped a single `simulate_trial`; this one takes the other long calls and Python's own concurrency:

- Ctrl-C (SIGINT) during a cohort on the module's C++ threads and on an executor, a real-time `run_trial`, a
  renderer loop, `study.load` at any moment, a study report and an R fit; SIGTERM to a process inside an R fit:
  raised promptly, no thread or R child left, nothing half-written, the objects usable after.
- threads: trials, cohorts, scores, a shared teacher, teachers saved to one path, errors and log messages from
  several threads at once, the GIL released where the docs say it is (a cohort on threads, `match_stroke`).
- `os.fork()` after the module has run threads (a cohort, a real-time trial, an R process) and while another
  thread is inside a trial; `ProcessPoolExecutor` with the fork and spawn start methods as a cohort's client.
- objects after `close()`, at `atexit` and in `__del__` as the interpreter ends, after a refused call, and Python
  code the API calls (a mapping, a sequence, a path-like object, a logging filter) raising.

CALLIGRAPHY_CLI names the program; the built Python package is found on PYTHONPATH. CALLIGRAPHY_SANITIZED=1 takes a
small subset.
"""
import concurrent.futures
import json
import logging
import multiprocessing
import os
import shutil
import signal
import subprocess
import sys
import tempfile
import textwrap
import threading
import time
import unittest
from pathlib import Path

from outsider import CLI, ENV, sanitized_subset
from outsider_python import cg, needs_python, np, pd

YI = "一"
SHI = "十"
PROMPT_S = 2.0  # the brief's "promptly": a KeyboardInterrupt within this long of the signal

load_tests = sanitized_subset({"test_ctrl_c_in_a_renderer_loop_loses_no_tick",
                               "test_a_closed_simulated_device_has_its_forces_off_and_opens_again",
                               "test_four_threads_of_simulate_trial_give_the_serial_results",
                               "test_python_code_the_api_calls_raises_through_it",
                               "test_errors_in_four_threads_name_their_own_character"})


def protocol(name, repetitions=2):
    return {"name": name, "conditions": [{"name": "V", "mode": "vision"}],
            "test": {"characters": [YI], "conditions": ["V"], "repetitions": repetitions},
            "trial": {"max_duration_s": 4}}


def tasks():
    """The threads of this process (the C++ ones too)."""
    return len(os.listdir("/proc/self/task"))


def children(pid=None):
    """The process ids of the children of `pid` (default this process)."""
    pid = os.getpid() if pid is None else pid
    found = []
    for task in Path(f"/proc/{pid}/task").iterdir():
        try:
            found += [int(c) for c in (task / "children").read_text().split()]
        except OSError:
            pass
    return found


def alive(pid):
    try:
        state = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0]
    except OSError:
        return False
    return state != "Z"


def wait_for(predicate, timeout_s=3.0):
    end = time.monotonic() + timeout_s
    while time.monotonic() < end:
        if predicate():
            return True
        time.sleep(0.02)
    return predicate()


class Interrupter:
    """Sends SIGINT to this process `after_s` seconds after start(); `sent` is the monotonic time it did."""

    def __init__(self, after_s):
        self.after_s = after_s
        self.sent = None
        self.timer = threading.Timer(after_s, self._fire)

    def _fire(self):
        self.sent = time.monotonic()
        os.kill(os.getpid(), signal.SIGINT)

    def __enter__(self):
        self.timer.start()
        return self

    def __exit__(self, *exc):
        self.timer.cancel()
        self.timer.join()
        return False


def interrupted(test, call, after_s=0.3):
    """Runs `call` and SIGINTs it after `after_s`: asserts KeyboardInterrupt within PROMPT_S of the signal and
    returns the delay."""
    with Interrupter(after_s) as stop:
        try:
            call()
        except KeyboardInterrupt:
            raised = time.monotonic()
        else:
            test.fail(f"{call} ran to its end ({time.monotonic() - stop.sent if stop.sent else 0:.2f} s after the "
                      "signal): no KeyboardInterrupt")
    test.assertIsNotNone(stop.sent)
    delay = raised - stop.sent
    test.assertLess(delay, PROMPT_S, f"KeyboardInterrupt came {delay:.2f} s after SIGINT")
    return delay


def python_env():
    env = dict(ENV)
    env["PYTHONPATH"] = os.pathsep.join(p for p in sys.path if p and Path(p).is_dir() and
                                        (Path(p) / "calligraphy").is_dir()) or env.get("PYTHONPATH", "")
    return env


def run_python(code, timeout=60, env=None, **kw):
    return subprocess.run([sys.executable, "-c", textwrap.dedent(code)], capture_output=True, text=True,
                          timeout=timeout, env=python_env() if env is None else env, **kw)


def frame_equal(test, a, b):
    pd.testing.assert_frame_equal(a.reset_index(drop=True), b.reset_index(drop=True))


class Base(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.tmp = tempfile.TemporaryDirectory(prefix="r20c-")
        cls.root = Path(cls.tmp.name)
        cls.protocol = cls.root / "p.json"
        cls.protocol.write_text(json.dumps(protocol("r20c")), encoding="utf-8")

    @classmethod
    def tearDownClass(cls):
        cls.tmp.cleanup()

    def cohort(self, subjects, **kw):
        import calligraphy.cohort
        kw.setdefault("individual_differences", True)
        kw.setdefault("progress", False)
        return calligraphy.cohort.simulate(str(self.protocol), subjects, **kw)


# ---------------------------------------------------------------------------------------------------------------
# Ctrl-C and SIGTERM


@needs_python
class Interrupt(Base):
    def test_ctrl_c_during_a_cohort_on_threads_raises_promptly_and_leaves_no_thread(self):
        before = self.cohort(3, workers=2).trials
        baseline = tasks()
        interrupted(self, lambda: self.cohort(1000, workers=2))
        self.assertTrue(wait_for(lambda: tasks() <= baseline), f"{tasks()} threads left, {baseline} before")
        # The module is usable after: the same subjects give the same rows.
        frame_equal(self, self.cohort(3, workers=2).trials, before)

    def test_ctrl_c_during_a_cohort_on_an_executor_raises_promptly_and_runs_no_more_batches(self):
        baseline = tasks()
        with concurrent.futures.ThreadPoolExecutor(2) as pool:
            interrupted(self, lambda: self.cohort(1000, client=pool))
            started = time.monotonic()
            pool.shutdown(wait=True)
            self.assertLess(time.monotonic() - started, PROMPT_S, "the executor ran the cohort's batches on")
        self.assertTrue(wait_for(lambda: tasks() <= baseline))

    def test_two_ctrl_c_in_a_row_during_a_cohort_raise_one_keyboard_interrupt(self):
        baseline = tasks()

        def twice():
            os.kill(os.getpid(), signal.SIGINT)
            time.sleep(0.03)
            os.kill(os.getpid(), signal.SIGINT)
        timer = threading.Timer(0.2, twice)
        started = time.monotonic()
        timer.start()
        try:
            with self.assertRaises(KeyboardInterrupt):
                try:
                    self.cohort(1000, workers=2)
                finally:
                    timer.join()  # the second signal is sent before this call returns or raises
        except KeyboardInterrupt:  # the second one, if the first was raised before it came
            pass
        self.assertLess(time.monotonic() - started, 0.2 + PROMPT_S)
        self.assertTrue(wait_for(lambda: tasks() <= baseline))
        self.assertEqual(len(self.cohort(2, workers=2).trials), 4)

    def test_a_sigint_handler_of_ones_own_is_what_a_cohort_and_a_trial_raise(self):
        def handler(signum, frame):
            raise Boom("stopped by the experimenter's handler")
        previous = signal.signal(signal.SIGINT, handler)
        try:
            for call in (lambda: self.cohort(1000, workers=2), lambda: cg.simulate_trial(SHI * 100, max_duration_s=3000.0,
                                                                                       keep_trace=False)):
                with Interrupter(0.2) as stop:
                    with self.assertRaises(Boom):
                        call()
                    self.assertLess(time.monotonic() - stop.sent, PROMPT_S)
        finally:
            signal.signal(signal.SIGINT, previous)

    def test_a_sigint_handler_that_does_not_raise_leaves_the_cohort_whole(self):
        expected = self.cohort(6, workers=2).trials
        caught = []
        previous = signal.signal(signal.SIGINT, lambda signum, frame: caught.append(signum))
        stop = threading.Event()

        def keep_signalling():
            while not stop.wait(0.02):
                os.kill(os.getpid(), signal.SIGINT)
        t = threading.Thread(target=keep_signalling)
        t.start()
        try:
            got = self.cohort(6, workers=2).trials
        finally:
            stop.set()
            t.join()
            signal.signal(signal.SIGINT, previous)
        self.assertGreater(len(caught), 0)
        frame_equal(self, got, expected)

    def test_ctrl_c_during_a_real_time_run_trial_leaves_no_servo_thread(self):
        baseline = tasks()
        interrupted(self, lambda: cg.run_trial(YI, pacing="real-time", max_duration_s=20.0))
        self.assertTrue(wait_for(lambda: tasks() <= baseline), f"{tasks()} threads left, {baseline} before")
        r = cg.run_trial(YI, max_duration_s=2.0, keep_trace=False)
        self.assertIn(r.metrics["end_reason"], ("completed", "time_limit"))

    def test_ctrl_c_in_a_renderer_loop_loses_no_tick(self):
        scene = cg.Scene(SHI)
        trial = cg.simulate_trial(SHI, seed=3, max_duration_s=3.0)
        states = [cg.DeviceState(position_m=p, velocity_m_s=(0.0, 0.0, 0.0), time_s=t)
                  for p, t in zip(trial.position_m, trial.time_s)]
        whole = cg.Renderer(scene)
        expected = [whole.tick(s).force_n for s in states]
        renderer = cg.Renderer(scene)
        got = []
        with Interrupter(0.05):
            try:
                for _ in range(10 ** 9):  # until Ctrl-C, then the rest
                    for s in states:
                        # One expression of C calls: the interpreter looks for the signal at the loop's jump,
                        # so a tick is never done without being kept.
                        got.append(renderer.tick(s).force_n)
                    renderer.reset()
                    got.clear()
            except KeyboardInterrupt:
                pass
        for s in states[len(got):]:
            got.append(renderer.tick(s).force_n)
        np.testing.assert_array_equal(np.array(got), np.array(expected))

    def test_ctrl_c_at_any_moment_of_study_load_leaves_the_next_load_whole(self):
        import calligraphy.study
        study = self.root / "study"
        if not study.exists():
            p = subprocess.run([CLI, "session", "run", str(self.protocol), "--subjects", "2", "--out", str(study),
                                "--writer", "simulated", "--writer-learning", "none"],
                               capture_output=True, timeout=60, env=ENV)
            self.assertEqual(p.returncode, 0, p.stderr)
        reference = calligraphy.study.load(str(study))
        for after in (0.001, 0.003, 0.006, 0.01, 0.02, 0.04):
            try:
                with Interrupter(after):
                    got = calligraphy.study.load(str(study))
                    frame_equal(self, got.trials, reference.trials)  # a load that ended is whole
                    time.sleep(0.2)  # the signal lands here when load was quicker
            except KeyboardInterrupt:
                pass
        again = calligraphy.study.load(str(study))
        frame_equal(self, again.trials, reference.trials)
        frame_equal(self, again.strokes, reference.strokes)
        self.assertEqual(sorted(p.name for p in study.rglob("*") if ".tmp" in p.name or p.name.endswith(".part")),
                         [])

    def test_ctrl_c_during_a_study_report_keeps_the_earlier_report_and_leaves_no_temporary(self):
        import calligraphy.study_report as study_report
        out = self.root / "paper"
        study = self.cohort(4, workers=1)  # one condition: no comparison for R to fit
        study_report.write_report(study, str(out), title="first")
        first = {str(f.relative_to(out)): f.read_bytes() for f in out.rglob("*") if f.is_file()}

        def reports():
            for i in range(50):
                study_report.write_report(study, str(out), title=f"second {i}")
        interrupted(self, reports)
        index = (out / "index.html").read_text(encoding="utf-8")
        self.assertTrue(index.rstrip().endswith("</html>"), index[-200:])
        self.assertTrue("first" in index or "second" in index)
        now = {str(f.relative_to(out)) for f in out.rglob("*") if f.is_file()}
        self.assertEqual(now, set(first), "files added or lost")
        left = [str(f.relative_to(out)) for f in out.rglob("*") if f.name.startswith(".") or ".tmp" in f.name
                or f.name.endswith((".part", ".journal"))]
        self.assertEqual(left, [])

    @unittest.skipUnless(shutil.which("Rscript"), "Rscript is not installed: the R cases are skipped")
    def test_ctrl_c_during_an_r_fit_then_the_next_fit_answers_its_own_frame(self):
        from calligraphy import mixed_models
        if not mixed_models.r_available():
            self.skipTest("R's lme4, lmerTest or pbkrtest is missing")
        rng = np.random.default_rng(20)
        subjects = np.repeat(np.arange(200), 20)

        def frame(effect, n):
            s = subjects[:n]
            g = np.where(np.arange(n) % 2 == 0, "a", "b")
            y = np.where(g == "b", effect, 0.0) + rng.normal(0, 1, 200)[s] + rng.normal(0, 0.1, n)
            return pd.DataFrame({"y": y, "g": g, "subject": [f"S{i}" for i in s]})

        small = frame(5.0, 200)
        mixed_models.lmer(small, "y ~ g + (1 | subject)", {"g": ["a", "b"]})  # R is up
        big = frame(-3.0, len(subjects))
        interrupted(self, lambda: [mixed_models.lmer(big, "y ~ g + (1 | subject) + (0 + g | subject)",
                                                     {"g": ["a", "b"]}) for _ in range(100)], after_s=0.5)
        fit = mixed_models.lmer(small, "y ~ g + (1 | subject)", {"g": ["a", "b"]})
        estimate = fit.fixed.set_index("term").loc["gb", "estimate"] if "gb" in set(fit.fixed["term"]) else \
            fit.fixed[fit.fixed["level"].astype(str) == "b"]["estimate"].iloc[0]
        self.assertAlmostEqual(float(estimate), 5.0, delta=0.3)

    @unittest.skipUnless(shutil.which("Rscript"), "Rscript is not installed: the R cases are skipped")
    def test_sigterm_to_python_during_an_r_fit_leaves_no_r_process(self):
        from calligraphy import mixed_models
        if not mixed_models.r_available():
            self.skipTest("R's lme4, lmerTest or pbkrtest is missing")
        rng = np.random.default_rng(1)
        s = np.repeat(np.arange(20), 10)
        f = pd.DataFrame({"y": rng.normal(size=200), "g": np.where(np.arange(200) % 2, "a", "b"),
                          "subject": [f"S{i}" for i in s]})
        pid = os.fork()  # a Python process of its own, without the time a new interpreter takes to start
        if pid == 0:  # pragma: no cover - the child: fits until SIGTERM ends it
            try:
                while True:
                    mixed_models.lmer(f, "y ~ g + (1 | subject)", {"g": ["a", "b"]})
            finally:
                os._exit(1)
        try:
            self.assertTrue(wait_for(lambda: children(pid), 10.0), "no R process started")
            time.sleep(0.3)  # R has started (it takes about 1.7 s to load lme4) and is loading or fitting
            r_processes = set(children(pid))
            self.assertTrue(r_processes)
            os.kill(pid, signal.SIGTERM)
            _, status = os.waitpid(pid, 0)
        except BaseException:
            os.kill(pid, signal.SIGKILL)
            os.waitpid(pid, 0)
            raise
        self.assertTrue(os.WIFSIGNALED(status) and os.WTERMSIG(status) == signal.SIGTERM, status)
        self.assertTrue(wait_for(lambda: not any(alive(r) for r in r_processes), 3.0),
                        f"R processes {sorted(r for r in r_processes if alive(r))} outlived Python")


# ---------------------------------------------------------------------------------------------------------------
# Threads


@needs_python
class Threads(Base):
    def run_threads(self, functions):
        results = [None] * len(functions)
        barrier = threading.Barrier(len(functions))

        def runner(i, f):
            barrier.wait()
            try:
                results[i] = ("ok", f())
            except BaseException as e:  # noqa: BLE001 - handed to the test
                results[i] = ("error", e)
        threads = [threading.Thread(target=runner, args=(i, f)) for i, f in enumerate(functions)]
        for t in threads:
            t.start()
        for t in threads:
            t.join(60)
            self.assertFalse(t.is_alive())
        return results

    def test_four_threads_of_simulate_trial_give_the_serial_results(self):
        args = [dict(characters=YI, seed=1), dict(characters=SHI, seed=2, writer="skilled"),
                dict(characters=YI, seed=3, guidance=False), dict(characters=SHI, seed=4, guidance_mode="fading",
                                                                 guidance_gain=0.5)]
        serial = [cg.simulate_trial(max_duration_s=6.0, **a) for a in args]
        got = self.run_threads([lambda a=a: cg.simulate_trial(max_duration_s=6.0, **a) for a in args])
        for (kind, r), s in zip(got, serial):
            self.assertEqual(kind, "ok", r)
            np.testing.assert_array_equal(r.position_m, s.position_m)
            self.assertEqual(json.dumps(r.metrics, sort_keys=True), json.dumps(s.metrics, sort_keys=True))

    def test_two_threads_of_cohorts_give_the_serial_tables(self):
        serial = [self.cohort(3, workers=1, prefix=p).trials for p in ("A", "B")]
        got = self.run_threads([lambda p=p: self.cohort(3, workers=1, prefix=p).trials for p in ("A", "B")])
        for (kind, frame), s in zip(got, serial):
            self.assertEqual(kind, "ok", frame)
            frame_equal(self, frame, s)

    def test_one_teacher_replayed_from_three_threads_gives_the_serial_trials(self):
        teacher = cg.record_teacher(cg.simulate_trial(YI, writer="skilled", seed=5, max_duration_s=6.0))
        serial = [cg.simulate_trial(YI, teacher=teacher, seed=s, max_duration_s=6.0) for s in range(3)]
        got = self.run_threads([lambda s=s: cg.simulate_trial(YI, teacher=teacher, seed=s, max_duration_s=6.0)
                                for s in range(3)])
        for (kind, r), s in zip(got, serial):
            self.assertEqual(kind, "ok", r)
            np.testing.assert_array_equal(r.force_n, s.force_n)

    def test_errors_in_four_threads_name_their_own_character(self):
        missing = ["\u0e01", "\u0e02", "\u0e03", "\u0e04"]  # Thai letters: no hanzi-writer-data character
        library = cg.CharacterLibrary.default()
        got = self.run_threads([lambda c=c: [library.load(c) for _ in range(50)] for c in missing] +
                               [lambda c=c: cg.simulate_trial(c) for c in missing])
        for (kind, error), c in zip(got, missing + missing):
            self.assertEqual(kind, "error")
            self.assertIsInstance(error, cg.CharacterNotFound)
            self.assertIn(c, str(error))
            self.assertIn(f"U+{ord(c):04X}", str(error))
            for other in set(missing) - {c}:
                self.assertNotIn(other, str(error))

    def test_log_messages_of_four_threads_arrive_once_each(self):
        law = cg.ForceLawParameters(guidance_stiffness_n_per_m=5000.0)
        records = []

        class Keep(logging.Handler):
            def emit(self, record):
                records.append(record.getMessage())
        handler = Keep(logging.WARNING)
        logger = logging.getLogger("calligraphy")
        logger.addHandler(handler)
        try:
            cg.flush_log()
            records.clear()
            cg.simulate_trial(YI, force_law=law, max_duration_s=0.5, keep_trace=False)
            cg.flush_log()
            one = list(records)
            self.assertGreater(len(one), 0, "a stiffness above the device's stable maximum logged no warning")
            records.clear()
            flushes = threading.Event()

            def flusher():
                while not flushes.is_set():
                    cg.flush_log()
            f = threading.Thread(target=flusher)
            f.start()
            try:
                got = self.run_threads([lambda: cg.simulate_trial(YI, force_law=law, max_duration_s=0.5,
                                                                  keep_trace=False)] * 4)
            finally:
                flushes.set()
                f.join()
            cg.flush_log()
            self.assertTrue(all(kind == "ok" for kind, _ in got), got)
            self.assertEqual(sorted(records), sorted(one * 4))
        finally:
            logger.removeHandler(handler)

    def test_score_from_four_threads_on_shared_columns_gives_the_serial_dict(self):
        trial = cg.simulate_trial(SHI, seed=2, max_duration_s=6.0)
        p = trial.position_m
        columns = {"t": trial.time_s, "x": p[:, 0], "y": p[:, 1], "z": p[:, 2]}
        serial = json.dumps(cg.score(columns, SHI), sort_keys=True)
        got = self.run_threads([lambda: cg.score(columns, SHI)] * 2 + [lambda: cg.score(columns, trial.scene)] * 2)
        for kind, result in got:
            self.assertEqual(kind, "ok", result)
            self.assertEqual(json.dumps(result, sort_keys=True), serial)

    def test_teachers_saved_from_three_threads_to_one_path_leave_one_whole_teacher(self):
        path = self.root / "shared-teacher.json"
        trials = [cg.simulate_trial(YI, seed=s, writer="skilled", max_duration_s=4.0) for s in range(3)]
        texts = {cg.record_teacher(t).to_json() for t in trials}
        self.assertEqual(len(texts), 3)
        for _ in range(2):
            got = self.run_threads([lambda t=t: cg.record_teacher(t, str(path)) for t in trials] +
                                   [lambda t=t: cg.record_teacher(t).save(str(path)) for t in trials])
            self.assertTrue(all(kind == "ok" for kind, _ in got), got)
            self.assertIn(cg.TeacherRecording.load(str(path)).to_json(), texts)
        self.assertEqual(sorted(f.name for f in self.root.iterdir() if f.name.startswith("shared-teacher")),
                         ["shared-teacher.json"])

    def gil_free_share(self, call):
        """How many times a pure-Python thread counts while `call` runs, against while it sleeps as long."""
        counts = []
        stop = threading.Event()

        def count():
            n = 0
            while not stop.is_set():
                n += 1
            counts.append(n)
        t = threading.Thread(target=count)
        t.start()
        started = time.monotonic()
        try:
            call()
        finally:
            elapsed = time.monotonic() - started
            stop.set()
            t.join()
        return counts[0], elapsed

    def test_a_cohort_on_threads_releases_the_gil(self):
        n, elapsed = self.gil_free_share(lambda: self.cohort(8, workers=1))
        self.assertGreater(elapsed, 0.05)
        # Holding the GIL, the counter would advance only at the interpreter's switch interval (5 ms) a few times.
        self.assertGreater(n / elapsed, 200_000, f"{n} counts in {elapsed:.2f} s")

    def test_match_stroke_releases_the_gil(self):
        scene = cg.Scene("永")
        median = scene.characters[0].strokes[1].median_m
        path = np.concatenate([np.linspace(median[i], median[i + 1], 20000) for i in range(len(median) - 1)])
        n, elapsed = self.gil_free_share(lambda: [cg.match_stroke(scene, 0, 1, path) for _ in range(3)])
        self.assertGreater(elapsed, 0.02)
        self.assertGreater(n / elapsed, 200_000, f"{n} counts in {elapsed:.2f} s")


# ---------------------------------------------------------------------------------------------------------------
# fork, multiprocessing


def in_child(test, work, timeout_s=20.0, meanwhile=None):
    """os.fork(): the child runs `work()` (its return value a JSON text) and exits; the parent returns what it
    wrote, failing when the child hangs past `timeout_s`, dies of a signal or raises. With `meanwhile`, the parent
    runs it while the child works and returns both results."""
    r, w = os.pipe()
    pid = os.fork()
    if pid == 0:  # pragma: no cover - the child
        status = 0
        try:
            os.close(r)
            text = json.dumps({"ok": work()})
        except BaseException as e:  # noqa: BLE001
            text = json.dumps({"error": f"{type(e).__name__}: {e}"})
            status = 1
        try:
            os.write(w, text.encode())
        finally:
            os._exit(status)
    os.close(w)
    mine = meanwhile() if meanwhile is not None else None
    end = time.monotonic() + timeout_s
    while True:
        done, status = os.waitpid(pid, os.WNOHANG)
        if done:
            break
        if time.monotonic() > end:
            os.kill(pid, signal.SIGKILL)
            os.waitpid(pid, 0)
            os.close(r)
            test.fail(f"the forked child hung for {timeout_s} s")
        time.sleep(0.02)
    with os.fdopen(r, "rb") as f:
        text = f.read().decode()
    test.assertTrue(os.WIFEXITED(status), f"the child died of signal {os.WTERMSIG(status)}")
    answer = json.loads(text) if text else {"error": "nothing written"}
    test.assertNotIn("error", answer, answer.get("error"))
    test.assertEqual(os.WEXITSTATUS(status), 0)
    return (answer["ok"], mine) if meanwhile is not None else answer["ok"]


def trial_digest(**kw):
    r = cg.simulate_trial(**kw)
    return [float(r.metrics["mean_deviation_m"]), float(r.metrics["total_time_s"]), float(r.position_m.sum())]


@needs_python
class Fork(Base):
    def test_fork_after_a_cohort_on_threads_the_child_runs_one(self):
        parent = self.cohort(3, workers=2).trials
        digest = trial_digest(characters=YI, seed=7, max_duration_s=6.0)
        got = in_child(self, lambda: [self.cohort(3, workers=2).trials.to_json(),
                                      trial_digest(characters=YI, seed=7, max_duration_s=6.0)])
        self.assertEqual(got[0], parent.to_json())
        self.assertEqual(got[1], digest)

    def test_fork_while_another_thread_is_inside_a_trial_the_child_runs_one(self):
        digest = trial_digest(characters=YI, seed=8, max_duration_s=6.0)
        stop = threading.Event()

        def busy():
            while not stop.is_set():
                cg.simulate_trial(YI, seed=1, max_duration_s=6.0)
                cg.flush_log()
        threads = [threading.Thread(target=busy) for _ in range(2)]
        for t in threads:
            t.start()
        try:
            time.sleep(0.05)
            for _ in range(3):
                got = in_child(self, lambda: (cg.flush_log(), trial_digest(characters=YI, seed=8,
                                                                           max_duration_s=6.0))[1])
                self.assertEqual(got, digest)
        finally:
            stop.set()
            for t in threads:
                t.join()

    def test_fork_after_a_real_time_trial_the_child_runs_one(self):
        cg.run_trial(YI, pacing="real-time", max_duration_s=0.1, keep_trace=False)
        got = in_child(self, lambda: cg.run_trial(YI, pacing="real-time", max_duration_s=0.1,
                                                  keep_trace=False).metrics["end_reason"])
        self.assertIn(got, ("completed", "time_limit"))

    @unittest.skipUnless(shutil.which("Rscript"), "Rscript is not installed: the R cases are skipped")
    def test_fork_after_r_started_parent_and_child_fit_their_own_frames_at_once(self):
        from calligraphy import mixed_models
        if not mixed_models.r_available():
            self.skipTest("R's lme4, lmerTest or pbkrtest is missing")
        rng = np.random.default_rng(7)

        def frame(effect):
            s = np.repeat(np.arange(20), 10)
            g = np.where(np.arange(200) % 2 == 0, "a", "b")
            y = np.where(g == "b", effect, 0.0) + rng.normal(0, 1, 20)[s] + rng.normal(0, 0.1, 200)
            return pd.DataFrame({"y": y, "g": g, "subject": [f"S{i}" for i in s]})

        def estimate(f):
            fit = mixed_models.lmer(f, "y ~ g + (1 | subject)", {"g": ["a", "b"]})
            return float(fit.fixed[fit.fixed["level"].astype(str) == "b"]["estimate"].iloc[0])
        mine, theirs = frame(2.0), frame(-4.0)
        self.assertAlmostEqual(estimate(mine), 2.0, delta=0.2)  # R is up
        # The child fits `theirs` while the parent fits `mine`, both after R was started by the parent.
        got = in_child(self, lambda: [estimate(theirs) for _ in range(3)], timeout_s=60,
                       meanwhile=lambda: [estimate(mine) for _ in range(3)])
        child, parent = got
        for v in child:
            self.assertAlmostEqual(v, -4.0, delta=0.2)
        for v in parent:
            self.assertAlmostEqual(v, 2.0, delta=0.2)

    def test_a_sweep_on_a_fork_pool_after_threads_gives_the_thread_pools_table(self):
        from calligraphy.experiments import sweep
        self.cohort(2, workers=2)  # the module has run C++ threads before the fork
        grid = {"guidance": [True, False]}
        with concurrent.futures.ThreadPoolExecutor(2) as pool:
            threads = sweep(YI, grid, seeds=2, client=pool, progress=False)
        with concurrent.futures.ProcessPoolExecutor(2, mp_context=multiprocessing.get_context("fork")) as pool:
            forked = sweep(YI, grid, seeds=2, client=pool, progress=False)
        self.assertEqual(list(forked["error"].isna()), [True] * 4, list(forked["error"]))
        frame_equal(self, forked, threads)

    def test_process_pools_as_a_cohort_client_give_the_threads_tables(self):
        threads = self.cohort(2, workers=1).trials
        for method in ("fork", "spawn"):
            with self.subTest(method=method):
                context = multiprocessing.get_context(method)
                with concurrent.futures.ProcessPoolExecutor(1, mp_context=context) as pool:
                    frame_equal(self, self.cohort(2, client=pool).trials, threads)


# ---------------------------------------------------------------------------------------------------------------
# Lifecycle: close, exceptions, finalisation, Python code the API calls


class Boom(Exception):
    pass


class RaisingMapping(dict):
    def keys(self):
        raise Boom("keys")

    def items(self):
        raise Boom("items")

    def __iter__(self):
        raise Boom("iter")

    def __getitem__(self, key):
        raise Boom("getitem")


class RaisingSequence(list):
    def __iter__(self):
        raise Boom("iter")

    def __getitem__(self, i):
        raise Boom("getitem")

    def __len__(self):
        raise Boom("len")


class RaisingPath:
    def __fspath__(self):
        raise Boom("fspath")


@needs_python
class Lifecycle(Base):
    def test_a_closed_simulated_device_has_its_forces_off_and_opens_again(self):
        device = cg.SimulatedDevice()
        device.write_force([0.5, 0.0, 0.0])
        device.advance(0.01)
        np.testing.assert_array_equal(device.applied_force_n, [0.5, 0.0, 0.0])
        device.close()  # "Forces off and closed."
        self.assertFalse(device.is_open)
        np.testing.assert_array_equal(device.applied_force_n, [0.0, 0.0, 0.0])
        device.close()  # twice: no crash, still closed, still no force
        self.assertFalse(device.is_open)
        np.testing.assert_array_equal(device.applied_force_n, [0.0, 0.0, 0.0])
        device.open()  # "Opens it again after close()."
        self.assertTrue(device.is_open)
        state = device.read_state()
        self.assertTrue(np.isfinite(state.position_m).all())
        device.write_force([0.2, 0.0, 0.0])
        device.advance(0.001)
        np.testing.assert_array_equal(device.applied_force_n, [0.2, 0.0, 0.0])

    def test_a_refused_call_leaves_the_device_as_it_was(self):
        a, b = cg.SimulatedDevice(), cg.SimulatedDevice()
        for d in (a, b):
            d.write_force([0.3, -0.2, 0.1])
            d.advance(0.002)
        for bad in ([1.0, 2.0], [[1.0, 0, 0]] * 2, [np.nan, 0, 0, 0], "fast"):
            with self.assertRaises((cg.InvalidArgument, TypeError)):
                a.write_force(bad)
        for bad in (-1.0, float("nan"), float("inf")):
            with self.assertRaises(cg.InvalidArgument):
                a.advance(bad)
        for d in (a, b):
            d.advance(0.003)
        np.testing.assert_array_equal(a.true_position_m, b.true_position_m)
        np.testing.assert_array_equal(a.applied_force_n, b.applied_force_n)
        self.assertEqual(a.time_s, b.time_s)

    def test_a_warning_raised_as_an_error_inside_a_with_block_leaves_the_objects_usable(self):
        # docs/python.md, "Errors": an old enum spelling is read with a DeprecationWarning; under
        # warnings.simplefilter("error") that warning is raised, in the middle of a call or an assignment.
        import warnings
        law = cg.ForceLawParameters()
        before = law.to_dict()
        expected = cg.simulate_trial(YI, guidance_mode="assist-as-needed", max_duration_s=2.0, keep_trace=False)
        with warnings.catch_warnings():
            warnings.simplefilter("error")
            with self.assertRaises(DeprecationWarning):
                cg.simulate_trial(YI, guidance_mode="assist_as_needed", max_duration_s=2.0)
            with self.assertRaises(DeprecationWarning):
                law.guidance_law = cg.default_guidance_law("error_amplification")
        self.assertEqual(law.to_dict(), before)
        again = cg.simulate_trial(YI, guidance_mode="assist-as-needed", max_duration_s=2.0, keep_trace=False)
        self.assertEqual(json.dumps(again.metrics, sort_keys=True), json.dumps(expected.metrics, sort_keys=True))

    def test_objects_at_atexit_and_in_del_as_the_interpreter_ends(self):
        out = self.root / "atexit-teacher.json"
        code = f"""
            import atexit, gc, calligraphy as cg, calligraphy.cohort
            class Holder:
                def __init__(self):
                    self.device = cg.SimulatedDevice()
                    self.renderer = cg.Renderer(cg.Scene("十"))
                    self.trial = cg.simulate_trial("一", max_duration_s=2.0)
                    self.me = self  # a cycle: collected at the end, if at all
                def __del__(self):
                    self.device.write_force([0.1, 0, 0]); self.device.advance(0.001); self.device.close()
                    self.renderer.tick(cg.DeviceState(position_m=(0, 0, 0.01), velocity_m_s=(0, 0, 0), time_s=0))
                    cg.flush_log()
            def at_exit():
                cg.record_teacher(cg.simulate_trial("一", max_duration_s=2.0), {str(out)!r})
                cg.flush_log()
            atexit.register(at_exit)
            holder = Holder()
            other = Holder(); del other
            device = cg.SimulatedDevice()   # open at the end
            study = calligraphy.cohort.simulate({str(self.protocol)!r}, 2, workers=2, progress=False)
            print("done", flush=True)
        """
        p = run_python(code)
        self.assertEqual(p.returncode, 0, p.stderr)
        self.assertEqual(p.stdout.strip(), "done")
        self.assertEqual(p.stderr.strip(), "")
        teacher = cg.TeacherRecording.load(str(out))
        self.assertGreater(len(teacher.samples) if hasattr(teacher, "samples") else 1, 0)

    def test_python_code_the_api_calls_raises_through_it(self):
        cases = {
            "writer_params": lambda: cg.simulate_trial(YI, writer_params=RaisingMapping(x=1.0), max_duration_s=1.0),
            "writer_profile": lambda: cg.writer_profile("novice", RaisingMapping(x=1.0)),
            "characters": lambda: cg.simulate_trial(RaisingSequence([cg.CharacterLibrary.default().load(YI)]),
                                                    max_duration_s=1.0),
            "teacher": lambda: cg.simulate_trial(YI, teacher=RaisingSequence([cg.TeacherSample(time_s=0.0, position_m=(0.0, 0.0, 0.0))]),
                                                 max_duration_s=1.0),
            "record_teacher path": lambda: cg.record_teacher(cg.simulate_trial(YI, max_duration_s=1.0),
                                                             RaisingPath()),
            "TeacherRecording.load": lambda: cg.TeacherRecording.load(RaisingPath()),
            "score": lambda: cg.score(RaisingPath(), YI),
        }
        for name, call in cases.items():
            with self.subTest(name):
                with self.assertRaises(Boom):
                    call()
        # and the module is usable after every one
        self.assertGreater(len(cg.simulate_trial(YI, max_duration_s=1.0).time_s), 0)

    def test_a_logging_filter_that_raises_is_reported_and_loses_no_other_message(self):
        # docs/python.md, "Logging": the C++ messages reach logging.getLogger("calligraphy") when a call that can
        # log returns; one a filter refuses by raising is reported through sys.unraisablehook, the call keeps
        # its result and the messages after it still arrive.
        logger = logging.getLogger("calligraphy")
        seen, reported = [], []

        class RefuseOnce(logging.Filter):
            armed = True

            def filter(self, record):
                if self.armed:
                    self.armed = False
                    raise Boom("filter")
                seen.append(record.getMessage())
                return True
        refuse = RefuseOnce()
        law = cg.ForceLawParameters(guidance_stiffness_n_per_m=5000.0)
        hook = sys.unraisablehook
        quiet = logging.NullHandler()  # not logging's last resort on standard error
        cg.flush_log()
        logger.addFilter(refuse)
        logger.addHandler(quiet)
        sys.unraisablehook = reported.append
        try:
            r = cg.simulate_trial(YI, force_law=law, max_duration_s=0.3)
            cg.flush_log()
        finally:
            sys.unraisablehook = hook
            logger.removeFilter(refuse)
            logger.removeHandler(quiet)
        self.assertEqual(len(r.time_s), 300)
        self.assertEqual([type(u.exc_value) for u in reported], [Boom])
        self.assertIn("calligraphy", str(reported[0].object))
        # Two warnings a trial (the stiffness above the device's stable maximum and the passivity bound): the
        # first raised, the second arrived.
        self.assertEqual(len(seen), 1, seen)
        self.assertIn("passivity", seen[0])

if __name__ == "__main__":
    unittest.main()
