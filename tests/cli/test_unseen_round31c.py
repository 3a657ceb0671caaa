#!/usr/bin/env python3
"""Round 31C: many trials at once in Python, interrupted and shared. From the docs alone (docs/python.md
"Sweeps: many trials on every core or a Dask cluster", "Simulated cohorts", "Simulated trials", "Running a
trial again", "Logging", "Errors", the pickling paragraph under "Nearest point and force law"; the docstrings
of calligraphy.experiments (sweep, parameter_names), calligraphy.cohort (simulate), simulate_trial, run_trial,
set_log_level and flush_log).

Attacked: a sweep's rows against the same trials run one by one (same seeds, same parameters, in the
documented nesting order), on the local process pool, a thread pool, an executor of our own and batches of any
size; grid names qualified and dotted, numpy values, the last seed, an empty grid; a failing trial as a row;
every refusal "before any trial runs" (an executor that counts what it is given), a sweep past
MAX_SWEEP_TRIALS refused at once; tables, metrics, parameters and a cohort's Study pickled with every protocol
and a re-run from an unpickled record; the classes that must refuse pickling; two threads running trials at
once; Ctrl-C (SIGINT) during a long simulate_trial, a real-time run_trial and a cohort on two threads (no
thread left), a SIGINT handler that does not raise; SIGTERM and Ctrl-C to a process sweeping on the local
pool (no worker, no forkserver outlives it); the library's log reaching logging.getLogger("calligraphy") from
a trial and from a sweep's threads, its level on both sides, a handler that raises.

PYTHONPATH names the built Python package. CALLIGRAPHY_SANITIZED=1 takes five cases.
"""
import concurrent.futures
import copy
import json
import logging
import os
import pickle
import signal
import subprocess
import sys
import tempfile
import threading
import time
import unittest
import warnings
from pathlib import Path

from outsider import descendants, running, sanitized_subset

try:
    import calligraphy as cg
    import calligraphy.cohort as cohort
    from calligraphy.experiments import MAX_SWEEP_TRIALS, parameter_names, sweep
except ImportError:  # reported by setUpClass of each class
    cg = None

load_tests = sanitized_subset({"test_sweep_refuses_bad_grids_seeds_and_clients_before_any_trial",
                               "test_cohort_refuses_bad_arguments_naming_them",
                               "test_parameter_names_are_the_trial_arguments_and_every_field",
                               "test_trial_result_and_scene_refuse_copy_and_pickle_naming_their_class",
                               "test_set_log_level_sets_both_sides_and_refuses_unknown_levels"})

CHAR = "十"          # two strokes, about 7 s simulated: the cheapest trial
SEEDS = [0, 7]


def reference_grid():
    """Guidance on and off, with a writer's profile, a nested field and a miss count that the process pool's
    batches must carry: one combination each."""
    return {"guidance": [True, False], "writer": [cg.WriterProfile.novice().replace(bias_offset_m=0.0005)],
            "nearest.method": ["newton"], "acceptance.hint_after_misses": [1]}


def reference_trial(guidance, seed):
    law = cg.ForceLawParameters()
    law.nearest.method = "newton"
    return cg.simulate_trial(CHAR, guidance=guidance, seed=seed, keep_trace=False, force_law=law,
                             writer=cg.WriterProfile.novice().replace(bias_offset_m=0.0005), hint_after_misses=1)
SCALARS = (bool, int, float, str)
# Trials long enough to be interrupted: 十 at 100 kHz is 0.6 M ticks (several tenths of a second of CPU).
LONG = {"rate_hz": 100000.0, "max_duration_s": 60.0, "keep_trace": False}
PROTOCOL = {"name": "tiny", "conditions": [{"name": "v", "mode": "vision"}, {"name": "h", "mode": "haptic"}],
            "test": {"characters": [CHAR], "conditions": ["v", "h"], "repetitions": 1}}
STIFF = {"guidance_stiffness_n_per_m": 1500.0, "paper_stiffness_n_per_m": 5000.0}   # above 1000 N/m at 1 kHz


def needs_package():
    if cg is None:
        raise unittest.SkipTest("the calligraphy Python package (PYTHONPATH), numpy and pandas are needed")


class CountingExecutor(concurrent.futures.Executor):
    """An executor of our own: runs each task at once in this thread and counts the tasks given."""

    def __init__(self):
        self.submitted = 0

    def submit(self, fn, /, *args, **kwargs):
        self.submitted += 1
        future = concurrent.futures.Future()
        try:
            future.set_result(fn(*args, **kwargs))
        except BaseException as e:  # noqa: BLE001 - a future holds what the task raised
            future.set_exception(e)
        return future


def interrupt_during(call, after_s):
    """`call()` with SIGINT sent to this process `after_s` seconds in, as Ctrl-C sends it. Returns (what
    happened, seconds from the signal to the KeyboardInterrupt): "interrupted" when the call raised it,
    "returned first" when the call had returned before, "no interrupt" when none came."""
    sent = []

    def send():
        sent.append(time.monotonic())
        os.kill(os.getpid(), signal.SIGINT)

    timer = threading.Timer(after_s, send)
    returned = False
    try:
        try:
            timer.start()
            call()
            returned = True
        finally:
            timer.join()
        time.sleep(0.05)   # a signal sent after the call returned is raised here
    except KeyboardInterrupt:
        return ("returned first" if returned else "interrupted"), time.monotonic() - sent[0]
    return "no interrupt", None


def tasks():
    """This process's threads (/proc/self/task)."""
    return set(os.listdir("/proc/self/task"))


def metric_scalars(metrics):
    return {k: v for k, v in metrics.items() if isinstance(v, SCALARS)}


class Sweeps(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        needs_package()
        import pandas
        cls.pd = pandas
        cls._table = None

    @property
    def table(self):
        """The reference, made when first needed: the local process pool, two workers, one trial a batch."""
        if Sweeps._table is None:
            Sweeps._table = sweep(CHAR, reference_grid(), seeds=SEEDS, workers=2, batch_size=1, progress=False)
        return Sweeps._table

    def trial(self, **kw):
        return cg.simulate_trial(CHAR, keep_trace=False, **kw)

    def assertRowIsTrial(self, row, metrics, skip=()):
        """Every scalar metric of the trial is the row's, exactly; attempts_total is the per-stroke sum."""
        compared = 0
        for key, value in metric_scalars(metrics).items():
            if key in row.index and key not in skip:
                self.assertEqual(row[key], value, key)
                compared += 1
        self.assertGreater(compared, 20)
        self.assertEqual(row["specification"], metrics["specification"])
        self.assertEqual(row["attempts_total"], sum(s["attempts"] for s in metrics["renderer_strokes"]))
        self.assertIsNone(row["error"])

    # ---- the table against the trials ------------------------------------------------------------------
    def test_local_pool_rows_are_the_trials_run_one_by_one_in_nesting_order(self):
        t = self.table
        self.assertEqual(list(t.index), [0, 1, 2, 3])
        # grid values x character x seed, in that nesting order
        self.assertEqual(list(zip(t.guidance, t.character, t.seed)),
                         [(True, CHAR, 0), (True, CHAR, 7), (False, CHAR, 0), (False, CHAR, 7)])
        for i, (g, s) in enumerate([(True, 0), (True, 7), (False, 0), (False, 7)]):
            with self.subTest(guidance=g, seed=s):
                self.assertRowIsTrial(t.iloc[i], reference_trial(g, s).metrics, skip=("writer",))
        self.assertEqual(t["writer"].tolist(), reference_grid()["writer"] * 4)
        self.assertEqual(t["nearest.method"].tolist(), ["newton"] * 4)

    def test_thread_pool_in_batches_of_three_gives_the_same_table(self):
        with concurrent.futures.ThreadPoolExecutor(2) as pool:
            table = sweep(CHAR, reference_grid(), seeds=SEEDS, client=pool, batch_size=3, progress=False)
        self.pd.testing.assert_frame_equal(table, self.table)

    def test_an_executor_of_ones_own_one_trial_a_batch_gives_the_same_table(self):
        executor = CountingExecutor()
        table = sweep(CHAR, reference_grid(), seeds=SEEDS, client=executor, batch_size=1, progress=False)
        self.assertEqual(executor.submitted, 4)   # one task a trial
        self.pd.testing.assert_frame_equal(table, self.table)

    def test_table_pickled_with_every_protocol_is_equal_and_reads_the_millimetre_name(self):
        for protocol in range(pickle.HIGHEST_PROTOCOL + 1):
            with self.subTest(protocol=protocol):
                self.pd.testing.assert_frame_equal(pickle.loads(pickle.dumps(self.table, protocol)), self.table)
        with tempfile.TemporaryDirectory(prefix="round31c-") as d:
            path = Path(d) / "t.pkl"
            self.table.to_pickle(path)
            loaded = self.pd.read_pickle(path)
        self.pd.testing.assert_frame_equal(loaded, self.table)
        for name, frame in (("to_pickle", loaded), ("selection", loaded[loaded.guidance]),
                            ("copy", pickle.loads(pickle.dumps(self.table, 2)).copy())):
            for metric in ("mean_deviation", "max_deviation", "rms_deviation", "frechet", "dtw"):
                with self.subTest(frame=name, metric=metric), warnings.catch_warnings(record=True) as caught:
                    warnings.simplefilter("always")
                    mm = frame[f"{metric}_mm"]
                    self.assertEqual(list(mm), [v * 1000 for v in frame[f"{metric}_m"]])
                    deprecations = [w for w in caught if issubclass(w.category, DeprecationWarning)]
                    self.assertTrue(deprecations, "no DeprecationWarning")
                    self.assertIn(f"{metric}_m", str(deprecations[0].message))

    def test_qualified_dotted_and_writer_field_names_are_the_trial_with_those_parameters(self):
        law = cg.ForceLawParameters(guidance_stiffness_n_per_m=300.0)
        law.nearest.method = "newton"
        writer = cg.WriterProfile.novice().replace(bias_offset_m=0.0)
        expected = self.trial(seed=1, force_law=law, writer=writer).metrics
        grids = ({"guidance_stiffness_n_per_m": [300.0], "nearest.method": ["newton"], "bias_offset_m": [0.0]},
                 {"force_law.guidance_stiffness_n_per_m": [300.0], "force_law.nearest.method": ["newton"],
                  "writer.bias_offset_m": [0.0]})
        for grid in grids:
            with self.subTest(grid=list(grid)), concurrent.futures.ThreadPoolExecutor(1) as pool:
                table = sweep(CHAR, grid, seeds=[1], client=pool, progress=False)
                self.assertEqual(len(table), 1)
                for name, values in grid.items():
                    self.assertEqual(table[name].tolist(), values, name)
                self.assertRowIsTrial(table.iloc[0], expected)

    def test_writer_values_are_the_trials_of_those_writers(self):
        profile = cg.WriterProfile.novice().replace(bias_offset_m=0.0)
        executor = CountingExecutor()
        table = sweep(CHAR, {"writer": ["skilled", profile]}, seeds=[2], client=executor, progress=False)
        self.assertEqual(len(table), 2)
        for i, writer in enumerate(["skilled", profile]):
            with self.subTest(writer=i):
                self.assertRowIsTrial(table.iloc[i], self.trial(seed=2, writer=writer).metrics, skip=("writer",))

    def test_numpy_grid_values_and_seeds_are_the_python_values_they_hold(self):
        import numpy as np
        plain = sweep(CHAR, {"guidance": [True], "guidance_stiffness_n_per_m": [200.0, 400.0]}, seeds=1,
                      client=CountingExecutor(), progress=False)
        numpy = sweep(CHAR, {"guidance": np.array([True]), "guidance_stiffness_n_per_m": np.linspace(200, 400, 2)},
                      seeds=np.arange(1), client=CountingExecutor(), progress=False)
        self.assertEqual(numpy["guidance_stiffness_n_per_m"].tolist(), [200.0, 400.0])
        self.assertEqual([type(v) for v in numpy["guidance_stiffness_n_per_m"].tolist()], [float, float])
        self.assertEqual(numpy["guidance"].tolist(), [True, True])
        self.pd.testing.assert_frame_equal(numpy, plain)
        law = cg.ForceLawParameters(guidance_stiffness_n_per_m=400.0)
        self.assertRowIsTrial(plain.iloc[1], self.trial(seed=0, force_law=law).metrics)

    def test_empty_grid_and_the_last_seed_make_one_trial_equal_to_simulate_trial(self):
        last = 2**64 - 1
        table = sweep(CHAR, {}, seeds=[last], client=CountingExecutor(), progress=False)
        self.assertEqual(len(table), 1)
        self.assertEqual(int(table["seed"].iloc[0]), last)
        self.assertRowIsTrial(table.iloc[0], self.trial(seed=last).metrics, skip=("seed",))

    def test_trial_that_raises_becomes_a_row_with_its_error_and_nullable_columns(self):
        table = sweep(["é", CHAR], {"rate_hz": [1000.0, 50.0]}, seeds=1, client=CountingExecutor(),
                      progress=False)
        self.assertEqual(list(zip(table.rate_hz, table.character)),
                         [(1000.0, "é"), (1000.0, CHAR), (50.0, "é"), (50.0, CHAR)])
        missing = table["error"].iloc[0]
        self.assertTrue(missing.startswith("CharacterNotFound: "), missing)
        self.assertIn("é (U+00E9)", missing)
        self.assertIsNone(table["error"].iloc[1])
        self.assertIn("rate_hz", table["error"].iloc[3])
        self.assertIsNotNone(table["error"].iloc[2])
        self.assertEqual(str(table["strokes_total"].dtype), "Int64")
        self.assertEqual(str(table["completed_in_order"].dtype), "boolean")
        for i in (0, 2, 3):
            self.assertTrue(self.pd.isna(table["mean_deviation_m"].iloc[i]))
            self.assertIs(table["strokes_total"].iloc[i], self.pd.NA)
        self.assertEqual(table["strokes_total"].iloc[1], 2)

    def test_an_item_of_several_characters_is_one_trial_of_the_group(self):
        table = sweep([CHAR + "二"], {}, seeds=[5], client=CountingExecutor(), progress=False)
        self.assertEqual(table["character"].tolist(), [CHAR + "二"])
        self.assertRowIsTrial(table.iloc[0], cg.simulate_trial(CHAR + "二", seed=5, keep_trace=False).metrics,
                              skip=("character",))
        self.assertEqual(table["strokes_total"].iloc[0], 4)

    def test_max_duration_in_the_grid_is_the_trials_time_limit_and_checked_in_the_trial(self):
        table = sweep(CHAR, {"max_duration_s": [0.5, 0.0]}, seeds=[0], client=CountingExecutor(), progress=False)
        self.assertEqual(table["max_duration_s"].tolist(), [0.5, 0.0])
        self.assertEqual(table["end_reason"].iloc[0], "time_limit")
        self.assertRowIsTrial(table.iloc[0], self.trial(seed=0, max_duration_s=0.5).metrics)
        self.assertIn("max_duration_s", table["error"].iloc[1])

    def test_a_source_that_cannot_be_opened_is_a_data_error(self):
        with tempfile.TemporaryDirectory(prefix="round31c-") as d:
            for kw in ({"store": Path(d) / "none.clg"}, {"data": Path(d) / "none"}):
                with self.subTest(**{k: str(v) for k, v in kw.items()}):
                    with self.assertRaises(cg.DataError) as caught:
                        sweep(CHAR, {}, seeds=[0], client=CountingExecutor(), progress=False, **kw)
                    self.assertIn("none", str(caught.exception))

    # ---- refusals before any trial ---------------------------------------------------------------------
    def test_sweep_refuses_bad_grids_seeds_and_clients_before_any_trial(self):
        cases = [({"guidance_stiffnes": [400.0]}, SEEDS, ValueError,
                  ("guidance_stiffnes", "guidance_stiffness_n_per_m")),
                 ({"guidance_stiffness_n_per_m": [400.0, -1.0]}, SEEDS, ValueError, ("guidance_stiffness_n_per_m",)),
                 ({"order_error_probability": [0.5, 1.5]}, SEEDS, ValueError, ("order_error_probability",)),
                 ({"nearest.method": ["exact", "bisection"]}, SEEDS, ValueError, ("bisection",)),
                 ({"guidance": []}, SEEDS, ValueError, ()),
                 ({"guidance": [True, "yes"]}, SEEDS, TypeError, ("guidance",)),
                 ({"rate_hz": ["fast"]}, SEEDS, TypeError, ("rate_hz",)),
                 ({"max_duration_s": [None]}, SEEDS, TypeError, ("max_duration_s",)),
                 ({"guidance": [True]}, [0, -1], ValueError, ()),
                 ({"guidance": [True]}, [0, 2**64], ValueError, ())]
        for grid, seeds, error, needles in cases:
            with self.subTest(grid=grid, seeds=seeds):
                executor = CountingExecutor()
                with self.assertRaises(error) as caught:
                    sweep(CHAR, grid, seeds=seeds, client=executor, progress=False)
                for needle in needles:
                    self.assertIn(needle, str(caught.exception))
                self.assertEqual(executor.submitted, 0, "a trial ran before the refusal")
        with self.assertRaises(TypeError) as caught:
            sweep(CHAR, {}, seeds=SEEDS, client="tcp://127.0.0.1:8786", progress=False)
        self.assertIn("client", str(caught.exception))
        for workers in (0, 1025):
            with self.subTest(workers=workers), self.assertRaises(ValueError) as caught:
                sweep(CHAR, {}, seeds=[0], workers=workers, progress=False)
            self.assertIn("workers", str(caught.exception))

    def test_sweep_past_a_million_trials_is_refused_at_once(self):
        self.assertEqual(MAX_SWEEP_TRIALS, 1_000_000)
        # In a process of its own, its memory and CPU bounded: a sweep that built its trials or ran them would
        # hit the bounds instead of answering.
        script = (
            "import json, resource, sys, time\n"
            "resource.setrlimit(resource.RLIMIT_AS, (3 << 30, 3 << 30))\n"
            "resource.setrlimit(resource.RLIMIT_CPU, (20, 20))\n"
            "from calligraphy.experiments import sweep\n"
            "if __name__ == '__main__':\n"
            "    out = []\n"
            "    for chars, grid, seeds in (('十', {'guidance_stiffness_n_per_m': [float(v) for v in range(1000)]},\n"
            "                                1001),\n"
            "                               (['十', '二'], {'guidance': [True, False]}, 250001),\n"
            "                               ('十', {}, 2**40)):\n"
            "        t = time.process_time()\n"
            "        try:\n"
            "            sweep(chars, grid, seeds, workers=1, progress=False)\n"
            "            out.append(['returned', '', 0])\n"
            "        except Exception as e:\n"
            "            out.append([type(e).__name__, str(e), time.process_time() - t])\n"
            "    print(json.dumps(out))\n")
        with tempfile.TemporaryDirectory(prefix="round31c-") as d:
            (Path(d) / "huge.py").write_text(script, encoding="utf-8")
            done = subprocess.run([sys.executable, "huge.py"], cwd=d, capture_output=True, timeout=60,
                                  start_new_session=True)
        self.assertEqual(done.returncode, 0, done.stderr.decode("utf-8", "replace")[-2000:])
        for kind, message, cpu_s in json.loads(done.stdout):
            with self.subTest(message=message):
                self.assertEqual(kind, "ValueError")
                self.assertLess(cpu_s, 0.5, "the refusal came after work")

    def test_parameter_names_are_the_trial_arguments_and_every_field(self):
        names = parameter_names()
        for name in ("guidance", "rate_hz", "max_duration_s", "writer", "nearest.method"):
            self.assertIn(name, names)
        for key, value in cg.ForceLawParameters().to_dict().items():
            if isinstance(value, dict) and key != "guidance_law":
                for inner in value:
                    self.assertIn(f"{key}.{inner}", names)
            else:
                self.assertIn(key, names)
        for field in cg.writer_parameter_names():
            self.assertIn(field, names)
        self.assertNotIn("name", names)
        self.assertEqual(len(names), len(set(names)))


class InterruptedSweeps(unittest.TestCase):
    """A process sweeping on the local pool, stopped by SIGTERM or by Ctrl-C (SIGINT to its process group)."""

    SCRIPT = (
        "import sys\n"
        "from calligraphy.experiments import sweep\n"
        "if __name__ == '__main__':\n"
        "    print('go', flush=True)\n"
        "    try:\n"
        "        sweep('十', {'rate_hz': [20000.0]}, seeds=40, workers=2, batch_size=1, progress=False)\n"
        "    except KeyboardInterrupt:\n"
        "        print('interrupted', flush=True)\n"
        "        sys.exit(3)\n"
        "    print('finished', flush=True)\n")

    @classmethod
    def setUpClass(cls):
        needs_package()

    def setUp(self):
        self.tmp = tempfile.TemporaryDirectory(prefix="round31c-")
        (Path(self.tmp.name) / "sweeping.py").write_text(self.SCRIPT, encoding="utf-8")
        self.process = subprocess.Popen([sys.executable, "sweeping.py"], cwd=self.tmp.name, start_new_session=True,
                                        stdout=subprocess.PIPE, stderr=subprocess.PIPE, stdin=subprocess.DEVNULL)
        self.assertEqual(self.process.stdout.readline().strip(), b"go")
        # The pool is there when the forkserver and both workers are (and the resource tracker): then let the
        # workers start their trials.
        deadline = time.monotonic() + 20
        while len(descendants(self.process.pid)) < 4 and time.monotonic() < deadline:
            time.sleep(0.05)
        time.sleep(0.15)
        self.tree = descendants(self.process.pid)
        self.assertGreaterEqual(len(self.tree), 3, "no pool started")

    def tearDown(self):
        for pid in [self.process.pid, *self.tree]:
            if running(pid):
                try:
                    os.kill(pid, signal.SIGKILL)
                except ProcessLookupError:
                    pass
        self.process.wait()
        self.process.stdout.close()
        self.process.stderr.close()
        self.tmp.cleanup()

    def left_over(self, wait_s=3.0):
        """The processes of the sweep's pool still running `wait_s` after the sweeping process ended."""
        deadline = time.monotonic() + wait_s
        while time.monotonic() < deadline:
            left = [pid for pid in self.tree if running(pid)]
            if not left:
                return []
            time.sleep(0.05)
        return [(pid, Path(f"/proc/{pid}/cmdline").read_bytes().replace(b"\0", b" ").decode(errors="replace"))
                for pid in self.tree if running(pid)]

    def test_sigterm_to_the_sweeping_process_leaves_no_worker_or_forkserver(self):
        os.kill(self.process.pid, signal.SIGTERM)
        self.assertEqual(self.process.wait(timeout=10), -signal.SIGTERM)
        self.assertEqual(self.left_over(), [])

    def test_ctrl_c_to_the_sweeping_process_group_raises_keyboard_interrupt_and_leaves_no_worker(self):
        sent = time.monotonic()
        os.killpg(self.process.pid, signal.SIGINT)
        status = self.process.wait(timeout=30)
        took = time.monotonic() - sent
        out = self.process.stdout.read().decode()
        self.assertEqual((status, out.strip()), (3, "interrupted"), self.process.stderr.read().decode()[-3000:])
        self.assertLess(took, 3.0, "every trial was told to stop within about 50 ms")
        self.assertEqual(self.left_over(), [])


class TrialsTogether(unittest.TestCase):
    """Trials on threads, pickled, re-run; Ctrl-C during a trial."""

    @classmethod
    def setUpClass(cls):
        needs_package()
        cls._result = None

    @property
    def result(self):
        if TrialsTogether._result is None:
            TrialsTogether._result = cg.simulate_trial(CHAR, seed=3)
        return TrialsTogether._result

    def test_two_threads_running_trials_at_once_each_get_their_seeds_trial(self):
        barrier = threading.Barrier(2)
        got = {}

        def one(seed):
            barrier.wait()
            got[seed] = cg.simulate_trial(CHAR, seed=seed, writer="foreign")

        threads = [threading.Thread(target=one, args=(s,)) for s in (4, 5)]
        for t in threads:
            t.start()
        for t in threads:
            t.join()
        for seed in (4, 5):
            with self.subTest(seed=seed):
                alone = cg.simulate_trial(CHAR, seed=seed, writer="foreign")
                self.assertTrue((got[seed].position_m == alone.position_m).all())
                self.assertEqual(metric_scalars(got[seed].metrics), metric_scalars(alone.metrics))
        self.assertFalse(got[4].position_m.shape == got[5].position_m.shape
                         and (got[4].position_m == got[5].position_m).all(), "two seeds, one trial")

    def test_metrics_and_parameters_pickle_with_every_protocol_and_the_unpickled_record_reruns_equal(self):
        law = cg.ForceLawParameters(guidance_stiffness_n_per_m=300.0)
        law.nearest.method = "newton"
        objects = {"metrics": self.result.metrics, "law": law,
                   "writer": cg.WriterProfile.novice().replace(bias_offset_m=0.001),
                   "device": cg.SimulatedDeviceParameters(initial_position_m=(0, 0, 0.02)),
                   "layout": cg.SceneLayout(character_size_m=0.05), "mode": cg.GuidanceMode.fading}
        for protocol in range(pickle.HIGHEST_PROTOCOL + 1):
            for name, value in objects.items():
                with self.subTest(protocol=protocol, object=name):
                    back = pickle.loads(pickle.dumps(value, protocol))
                    if name == "metrics":
                        self.assertEqual(back, value)
                    else:
                        self.assertEqual(repr(back), repr(value))
        record = pickle.loads(pickle.dumps(self.result.metrics, 0))
        again = cg.rerun_trial(record)
        self.assertEqual(again.position_m.shape, self.result.position_m.shape)
        self.assertTrue((again.position_m == self.result.position_m).all())
        self.assertTrue((again.force_n == self.result.force_n).all())

    def test_trial_result_and_scene_refuse_copy_and_pickle_naming_their_class(self):
        for name, value in (("TrialResult", self.result), ("Scene", self.result.scene)):
            for protocol in range(pickle.HIGHEST_PROTOCOL + 1):
                with self.subTest(cls=name, protocol=protocol), self.assertRaises(TypeError) as caught:
                    pickle.dumps(value, protocol)
                self.assertIn("cannot pickle", str(caught.exception))
                self.assertIn(name, str(caught.exception))
            for how in (copy.copy, copy.deepcopy):
                with self.subTest(cls=name, copy=how.__name__), self.assertRaises(TypeError):
                    how(value)

    def test_ctrl_c_stops_a_long_simulate_trial_and_raises_keyboard_interrupt(self):
        outcome, after_s = interrupt_during(lambda: cg.simulate_trial(CHAR, seed=0, **LONG), 0.2)
        self.assertEqual(outcome, "interrupted")
        # ticks stop within about 50 ms; 0.2 s of a trial is put together in far less than a second
        self.assertLess(after_s, 1.0)

    def test_ctrl_c_ends_a_real_time_run_trial_at_the_next_tick(self):
        outcome, after_s = interrupt_during(
            lambda: cg.run_trial(CHAR, device="simulated", pacing="real-time", keep_trace=False), 0.3)
        self.assertEqual(outcome, "interrupted")
        self.assertLess(after_s, 1.0)


class Cohorts(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        needs_package()
        import pandas
        cls.pd = pandas
        cls.tmp = tempfile.TemporaryDirectory(prefix="round31c-")
        cls.protocol = Path(cls.tmp.name) / "tiny.json"
        cls.protocol.write_text(json.dumps(PROTOCOL), encoding="utf-8")
        cls._study = None

    @classmethod
    def tearDownClass(cls):
        cls.tmp.cleanup()

    @property
    def study(self):
        """The reference cohort, made when first needed: 3 subjects on 2 threads."""
        if Cohorts._study is None:
            Cohorts._study = cohort.simulate(self.protocol, 3, workers=2, progress=False)
        return Cohorts._study

    def assertSameStudy(self, study):
        self.pd.testing.assert_frame_equal(study.trials, self.study.trials)
        self.pd.testing.assert_frame_equal(study.strokes, self.study.strokes)

    def test_cohort_has_every_subjects_trials(self):
        trials = self.study.trials
        self.assertEqual(len(trials), 6)   # 3 subjects x 2 conditions x 1 string x 1 repetition
        self.assertEqual(sorted(set(trials.subject)), ["S01", "S02", "S03"])
        self.assertEqual(set(trials.end_reason), {"completed"})

    def test_cohort_tables_are_the_same_on_one_thread_and_on_an_executor_in_batches(self):
        self.assertSameStudy(cohort.simulate(self.protocol, 3, workers=1, progress=False))
        with concurrent.futures.ThreadPoolExecutor(2) as pool:
            self.assertSameStudy(cohort.simulate(self.protocol, 3, client=pool, batch_size=2, progress=False))

    def test_cohort_study_pickles_with_every_protocol(self):
        for protocol in range(pickle.HIGHEST_PROTOCOL + 1):
            with self.subTest(protocol=protocol):
                self.assertSameStudy(pickle.loads(pickle.dumps(self.study, protocol)))

    def test_ctrl_c_stops_a_cohort_on_every_thread_and_leaves_no_thread(self):
        before = tasks()
        outcome, after_s = interrupt_during(
            lambda: cohort.simulate(self.protocol, 60, workers=2, progress=False), 0.15)
        self.assertEqual(outcome, "interrupted")
        self.assertLess(after_s, 1.0)
        self.assertEqual(tasks() - before, set(), "a thread of the cohort is left")

    def test_an_exception_a_sigint_handler_raises_stops_the_cohort_and_is_raised(self):
        class Stop(Exception):
            pass

        def handler(*_):
            raise Stop("stopped by our handler")

        before = tasks()
        old = signal.signal(signal.SIGINT, handler)
        sent = []
        timer = threading.Timer(0.15, lambda: (sent.append(time.monotonic()), os.kill(os.getpid(), signal.SIGINT)))
        try:
            timer.start()
            with self.assertRaises(Stop):
                cohort.simulate(self.protocol, 60, workers=2, progress=False)
            ended = time.monotonic()
        finally:
            timer.join()
            signal.signal(signal.SIGINT, old)
        self.assertLess(ended - sent[0], 1.0)
        self.assertEqual(tasks() - before, set(), "a thread of the cohort is left")

    def test_ctrl_c_on_an_executor_cancels_the_cohorts_batches_not_started(self):
        futures = []

        class Keeping(concurrent.futures.ThreadPoolExecutor):
            def submit(self, fn, /, *args, **kwargs):
                future = super().submit(fn, *args, **kwargs)
                futures.append(future)
                return future

        pool = Keeping(1)
        try:
            outcome, after_s = interrupt_during(
                lambda: cohort.simulate(self.protocol, 60, client=pool, batch_size=1, progress=False), 0.15)
        finally:
            began = time.monotonic()
            pool.shutdown(wait=True)
            shutdown_s = time.monotonic() - began
        self.assertEqual(outcome, "interrupted")
        self.assertLess(after_s, 1.0)
        ran = [f for f in futures if not f.cancelled()]
        self.assertLess(len(ran), 30, f"{len(ran)} of {len(futures)} batches ran after Ctrl-C")
        self.assertLess(shutdown_s, 1.0)

    def test_cohort_of_a_character_the_source_lacks_is_character_not_found(self):
        path = Path(self.tmp.name) / "lacking.json"
        path.write_text(json.dumps({**PROTOCOL, "name": "lacking",
                                    "test": {**PROTOCOL["test"], "characters": ["é"]}}), encoding="utf-8")
        with self.assertRaises(cg.CharacterNotFound) as caught:
            cohort.simulate(path, 1, progress=False)
        self.assertIn("é", str(caught.exception))

    def test_a_sigint_handler_that_does_not_raise_leaves_the_cohort_whole(self):
        calls = []
        state = {"returned": False}
        old = signal.signal(signal.SIGINT, lambda *_: calls.append(state["returned"]))
        try:
            outcome, _ = interrupt_during(
                lambda: (state.update(study=cohort.simulate(self.protocol, 3, workers=2, progress=False)),
                         state.update(returned=True)), 0.02)
        finally:
            signal.signal(signal.SIGINT, old)
        self.assertEqual(outcome, "no interrupt")
        self.assertEqual(len(calls), 1)
        if calls[0]:
            self.skipTest("the cohort ended before the signal: nothing shown")
        self.assertSameStudy(state["study"])

    def test_cohort_refuses_bad_arguments_naming_them(self):
        cases = [(dict(subjects=0), ValueError, "subjects"),
                 (dict(subjects=100_001), ValueError, "subjects"),
                 (dict(subjects=1.5), TypeError, "subjects"),
                 (dict(workers=1025), ValueError, "workers"),
                 (dict(workers=0), ValueError, "workers"),
                 (dict(batch_size=0), ValueError, "batch_size"),
                 (dict(batch_size=0, client=CountingExecutor()), ValueError, "batch_size"),
                 (dict(profile=3), TypeError, "profile"),
                 (dict(profile="expert"), ValueError, "CohortSetup.writer_profile"),
                 (dict(learning="lots"), ValueError, "CohortSetup.writer_learning"),
                 (dict(learning=2), TypeError, "learning"),
                 (dict(individual_differences=1), TypeError, "individual_differences"),
                 (dict(client="tcp://127.0.0.1:8786"), TypeError, "client")]
        for kw, error, needle in cases:
            args = {"subjects": 2, **kw}
            subjects = args.pop("subjects")
            with self.subTest(**{k: repr(v) for k, v in kw.items()}), self.assertRaises(error) as caught:
                cohort.simulate(self.protocol, subjects, progress=False, **args)
            self.assertIn(needle, str(caught.exception))
        missing = Path(self.tmp.name) / "missing.json"
        with self.assertRaises(cg.DataError) as caught:
            cohort.simulate(missing, 2, progress=False)
        self.assertIn("missing.json", str(caught.exception))
        with self.assertRaises(cg.DataError) as caught:
            cohort.simulate(self.protocol, 2, store=Path(self.tmp.name) / "none.clg", progress=False)
        self.assertIn("none.clg", str(caught.exception))


class Logging(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        needs_package()

    def setUp(self):
        self.logger = logging.getLogger("calligraphy")
        self.level = self.logger.level
        self.records = []
        outer = self

        class Keep(logging.Handler):
            def emit(self, record):
                outer.records.append(record)

        self.handler = Keep()
        self.logger.addHandler(self.handler)
        cg.set_log_level("warning")

    def tearDown(self):
        cg.flush_log()
        self.logger.removeHandler(self.handler)
        cg.set_log_level("warning")
        self.logger.setLevel(self.level)

    def stiff(self):
        return cg.ForceLawParameters(**STIFF)

    def warnings_about_stiffness(self):
        return [r for r in self.records if r.levelno == logging.WARNING and "stiffness" in r.getMessage()]

    def test_stiffness_warning_reaches_the_logger_when_the_trial_returns(self):
        r = cg.simulate_trial(CHAR, force_law=self.stiff(), keep_trace=False)
        self.assertEqual(r.metrics["end_reason"], "completed")
        got = self.warnings_about_stiffness()
        self.assertTrue(got, [x.getMessage() for x in self.records])
        self.assertTrue(all(x.name.startswith("calligraphy") for x in got))
        # never per tick: a warning or three, not thousands
        self.assertLess(len(self.records), 10)

    def test_warnings_of_a_sweep_on_threads_reach_the_logger(self):
        with concurrent.futures.ThreadPoolExecutor(2) as pool:
            table = sweep(CHAR, {"guidance_stiffness_n_per_m": [1500.0]}, seeds=[0, 1], client=pool,
                          progress=False)
        cg.flush_log()
        self.assertEqual(table["error"].tolist(), [None, None])
        got = self.warnings_about_stiffness()
        self.assertGreaterEqual(len(got), 2, [x.getMessage() for x in self.records])

    def test_set_log_level_sets_both_sides_and_refuses_unknown_levels(self):
        cg.set_log_level("error")
        self.assertEqual(self.logger.level, logging.ERROR)
        cg.simulate_trial(CHAR, force_law=self.stiff(), keep_trace=False)
        cg.flush_log()
        self.assertEqual(self.warnings_about_stiffness(), [])
        cg.set_log_level(logging.WARNING)
        self.assertEqual(self.logger.level, logging.WARNING)
        with self.assertRaises(ValueError) as caught:
            cg.set_log_level("loud")
        self.assertIsInstance(caught.exception, cg.InvalidArgument)
        with self.assertRaises(TypeError):
            cg.set_log_level(1.5)

    def test_a_raising_handler_is_reported_unraisable_and_the_call_keeps_its_result(self):
        seen = []
        refused = []

        class Refuse(logging.Handler):
            def emit(self, record):
                if not refused:
                    refused.append(record.getMessage())
                    raise RuntimeError("this handler refuses")

        refuse = Refuse()
        self.logger.removeHandler(self.handler)
        self.logger.addHandler(refuse)
        self.logger.addHandler(self.handler)
        old = sys.unraisablehook
        sys.unraisablehook = lambda info: seen.append((info.exc_type, f"{info.err_msg} {info.object!r}"))
        try:
            r = cg.simulate_trial(CHAR, force_law=self.stiff(), keep_trace=False)
            cg.flush_log()
        finally:
            sys.unraisablehook = old
            self.logger.removeHandler(refuse)
        self.assertEqual(r.metrics["end_reason"], "completed")
        self.assertEqual(len(refused), 1)
        self.assertTrue(seen, "nothing reported to sys.unraisablehook")
        self.assertIs(seen[0][0], RuntimeError)
        self.assertIn("calligraphy: forwarding the C++ log to Python's logging", seen[0][1])
        later = [x.getMessage() for x in self.records if x.getMessage() != refused[0]]
        self.assertTrue(later, "the messages after the refused one did not arrive")


if __name__ == "__main__":
    unittest.main()
