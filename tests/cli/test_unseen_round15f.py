#!/usr/bin/env python3
"""Round 15F: hostile cases written from the documentation alone (docs/devices.md, docs/servo-loop.md,
docs/force-rendering.md, docs/cli.md, each command's `--help` and Python's docstrings) on the devices and the
servo loop as the command line and Python drive them. Run by CTest as `cli_unseen_round15f_tests`.

Every kind of device `calligraphy devices --json` lists, given to `trial` and `session run` (taken, or refused
naming the device and the commands that take it); a writer or a pacing the device cannot have, whether or not
its driver loads; Phantom paths that are absent, a FIFO, /dev/null or a folder; CALLIGRAPHY_LIBHD naming a
library that lacks HDAPI, an executable, a link loop or a path with a line break; the servo rate at and past
its bounds in lock-step and real time, checked from the saved trace's tick spacing and the record's device
clock; `--watchdog-ms` at and past its range, on options and in records; a stall of the process (SIGSTOP)
past and under the watchdog; the stand-in libHD losing its link, tripping its force limit and stalling a frame
under Python's `run_trial`; SIGINT and SIGTERM before a trial, mid-trial on each device kind and while the
final outputs are written; records of each device kind re-run with `trial --spec`, and edited to a device, a
writer or a pacing that cannot go together.

Each case asserts what the documentation promises: the exit status (2 usage, 1 a device that cannot be used now
or an aborted trial, 128 + N after signal N), one error line naming the device, option, path or JSON pointer,
every tick kept in the trace, the end reason named as the docs name it.
CALLIGRAPHY_CLI names the program, CALLIGRAPHY_HD_STAND_IN the stand-in libHD (tests/hd_stand_in),
CALLIGRAPHY_HD_PARTIAL the one with hdInitDevice only, CALLIGRAPHY_PYTHON_HD_STAND_IN the stand-in as the
Python module was built; the cases that need one are skipped, saying so, without it.
CALLIGRAPHY_SANITIZED=1 takes five cases.
"""
import csv
import importlib.util
import json
import os
import shutil
import signal
import statistics
import subprocess
import sys
import tempfile
import textwrap
import time
import unittest
from pathlib import Path

from outsider import CLI, ENV, TIMEOUT_S, OneErrorLine, run, sanitized_subset

STAND_IN = os.environ.get("CALLIGRAPHY_HD_STAND_IN", "")
PARTIAL = os.environ.get("CALLIGRAPHY_HD_PARTIAL", "")
PYTHON_STAND_IN = os.environ.get("CALLIGRAPHY_PYTHON_HD_STAND_IN", "") or STAND_IN
YI = "一"
PROTOCOL = {"name": "tiny", "conditions": [{"name": "fixture", "mode": "haptic"}],
            "test": {"characters": [YI], "conditions": ["fixture"], "repetitions": 1},
            "trial": {"max_duration_s": 0.3}}

load_tests = sanitized_subset({"test_each_kind_is_taken_by_the_commands_listed_for_it_and_refused_by_the_others",
                               "test_phantom_paths_that_are_no_phantom_are_refused_in_one_line",
                               "test_libhd_lacking_hdapi_is_refused_naming_the_path_and_what_it_lacks",
                               "test_watchdog_ms_at_and_past_its_range",
                               "test_a_simulated_writer_on_a_person_s_device_is_a_usage_error_loaded_or_not"})


def with_stand_in(path=None, **extra):
    env = dict(ENV, CALLIGRAPHY_LIBHD=path or STAND_IN)
    env.update(extra)
    return env


def need_stand_in(test):
    return unittest.skipUnless(STAND_IN and Path(STAND_IN).exists(),
                               "no stand-in libHD (CALLIGRAPHY_HD_STAND_IN)")(test)


def read_trace(path):
    with open(path, newline="") as handle:
        rows = list(csv.reader(handle))
    return rows[0], rows[1:]


def spacing(rows):
    times = [float(row[0]) for row in rows]
    return [b - a for a, b in zip(times, times[1:])]


def without_warnings(result):
    """The run with its library's warning lines (the OpenHaptics stand-in's "using ..." line) left out."""
    kept = [line for line in result.stderr.splitlines(keepends=True) if b": warning: " not in line]
    return subprocess.CompletedProcess(result.args, result.returncode, result.stdout, b"".join(kept))


def start(args, cwd, env=None):
    return subprocess.Popen([CLI, *args], cwd=cwd, env=ENV if env is None else env, stdin=subprocess.DEVNULL,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE)


def in_trial(process, after):
    """Waits until the real-time trial of `process` runs (its servo loop is a thread of its own: the process has
    more than one, polled every 10 ms for at most 20 s), then `after` seconds of the trial."""
    deadline = time.monotonic() + 20
    while time.monotonic() < deadline and process.poll() is None:
        try:
            if len(os.listdir(f"/proc/{process.pid}/task")) >= 2:
                break
        except OSError:
            break
        time.sleep(0.01)
    time.sleep(after)


class Round15F(OneErrorLine, unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        if not CLI or not Path(CLI).exists():
            raise unittest.SkipTest(f"CALLIGRAPHY_CLI={CLI!r} is not the calligraphy program")
        cls.tmp = tempfile.TemporaryDirectory(prefix="calligraphy-round15f-")
        cls.root = Path(cls.tmp.name)
        listing = run(["devices", "--json"], cwd=cls.root)
        assert listing.returncode == 0, listing.stderr
        cls.listing = json.loads(listing.stdout)

    @classmethod
    def tearDownClass(cls):
        cls.tmp.cleanup()

    def folder(self):
        path = Path(tempfile.mkdtemp(dir=self.root))
        return path

    # ---- every kind with each command -------------------------------------------------------------------
    def test_each_kind_is_taken_by_the_commands_listed_for_it_and_refused_by_the_others(self):
        where = self.folder()
        kinds = {kind["name"]: kind for kind in self.listing["kinds"]}
        self.assertTrue({"simulated", "emulated-phantom", "mouse", "mouse-hand", "openhaptics"} <= set(kinds))
        for name, kind in kinds.items():
            device = name.replace("PATH", "/dev/hidraw99").replace("BUS-ADDRESS", "9-99")
            result = run(["trial", YI, "--device", device, "--max-duration", "0.05"], cwd=where)
            text = result.stderr.decode()
            if "trial" in kind["commands"]:
                # taken: it runs (the time limit ends it: 1), or is a device that cannot be used now (1)
                self.assertEqual(result.returncode, 1, (name, text))
                self.assertNotIn("unknown", text)
            else:
                line = self.assert_one_error(result, 2, f"--device {device}")
                for command in kind["commands"]:
                    self.assertIn(command, line)

    def test_a_simulated_writer_on_a_person_s_device_is_a_usage_error_loaded_or_not(self):
        # docs/cli.md, trial --writer: "any other pairing is a usage error"; the kind's writer is in the
        # listing, so whether the driver loads cannot change the answer.
        where = self.folder()
        (where / "p.json").write_text(json.dumps(PROTOCOL, ensure_ascii=False))
        envs = [ENV] + ([with_stand_in()] if STAND_IN else []) + ([with_stand_in(PARTIAL)] if PARTIAL else [])
        for env in envs:
            for device in ("openhaptics", "phantom-hid:/dev/hidraw0", "phantom-usb:1-2"):
                result = run(["trial", YI, "--writer", "simulated", "--device", device], cwd=where, env=env)
                self.assert_one_error(result, 2, "--writer", device)
                result = run(["session", "run", "p.json", "--subject", "S01", "--out", "study", "--device", device,
                              "--writer", "simulated"], cwd=where, env=env)
                self.assert_one_error(result, 2, "--writer", device)
                self.assertFalse((where / "study").exists())

    def test_a_person_on_a_device_the_simulated_writer_moves_is_a_usage_error(self):
        where = self.folder()
        (where / "p.json").write_text(json.dumps(PROTOCOL, ensure_ascii=False))
        for device in ("simulated", "emulated-phantom"):
            self.assert_one_error(run(["trial", YI, "--writer", "person", "--device", device], cwd=where), 2,
                                  "--writer", device)
            result = run(["session", "run", "p.json", "--subject", "S01", "--out", "study", "--device", device,
                          "--writer", "person"], cwd=where)
            self.assert_one_error(result, 2, "--writer", device)

    @need_stand_in
    def test_lock_step_on_a_device_a_person_moves_is_a_usage_error(self):
        # Lock-step pacing is for a device a simulated hand moves; on a person's device the two options cannot
        # go together (docs/cli.md, exit statuses: 2), as --watchdog-ms with lock-step is.
        where = self.folder()
        result = run(["trial", YI, "--device", "openhaptics", "--pacing", "lock-step", "--json", "t.json"],
                     cwd=where, env=with_stand_in())
        self.assert_one_error(result, 2, "--pacing", "openhaptics")
        self.assertFalse((where / "t.json").exists())

    def test_session_run_on_the_emulated_phantom_records_the_device_and_its_limits(self):
        where = self.folder()
        (where / "p.json").write_text(json.dumps(PROTOCOL, ensure_ascii=False))
        result = run(["session", "run", "p.json", "--subject", "S01", "--out", "study", "--device",
                      "emulated-phantom"], cwd=where)
        self.assertEqual(result.returncode, 0, result.stderr)
        records = list(where.glob("study/S01/*/trials/*.json"))
        self.assertEqual(len(records), 1)
        record = json.loads(records[0].read_text())
        listed = {d["name"]: d for d in self.listing["devices"]}["emulated-phantom"]
        self.assertEqual(record["device"]["name"], "emulated-phantom")
        self.assertEqual(record["device"]["info"], listed["info"])
        self.assertEqual(record["specification"]["trial"]["device"], "emulated-phantom")

    @need_stand_in
    def test_session_run_on_openhaptics_records_the_opened_device_s_limits(self):
        # The study record's device.info is the DeviceInfo (docs/cli.md, devices): once the trial opened the
        # device its limits are known, never the placeholder of a device not yet opened, never zeros; the
        # line a person reads for a trial that wrote nothing shows no `nan` (a value that does not exist is -).
        where = self.folder()
        (where / "p.json").write_text(json.dumps(PROTOCOL, ensure_ascii=False))
        result = run(["session", "run", "p.json", "--subject", "S01", "--out", "study", "--device", "openhaptics",
                      "--display", "terminal"], cwd=where, env=with_stand_in())
        self.assertEqual(result.returncode, 0, result.stderr)
        records = list(where.glob("study/S01/*/trials/*.json"))
        self.assertEqual(len(records), 1)
        record = json.loads(records[0].read_text())
        info = record["device"]["info"]
        self.assertTrue(record["device"]["hardware"])
        self.assertNotIn("not opened", info["model"])
        self.assertAlmostEqual(info["max_force_n"], 3.3)  # the stand-in's Touch (tests/hd_stand_in/README.md)
        self.assertAlmostEqual(info["max_continuous_force_n"], 0.88)
        self.assertGreater(info["max_stiffness_n_per_m"], 0)
        self.assertNotIn("nan", result.stderr.decode().lower())

    # ---- device paths that are no Phantom -----------------------------------------------------------------
    def test_phantom_paths_that_are_no_phantom_are_refused_in_one_line(self):
        where = self.folder()
        os.mkfifo(where / "fifo")
        (where / "p.json").write_text(json.dumps(PROTOCOL, ensure_ascii=False))
        for path in (where / "absent", where / "fifo", Path("/dev/null"), where, where / "p.json"):
            device = f"phantom-hid:{path}"
            self.assert_one_error(run(["trial", YI, "--device", device], cwd=where, timeout=20), 1, device)
            result = run(["session", "run", "p.json", "--subject", "S01", "--out", "study", "--device", device],
                         cwd=where, timeout=20)
            self.assert_one_error(result, 1, device)
        for device in ("phantom-usb:999-999", "phantom-usb:garbage", "phantom-usb:", "phantom-hid:"):
            self.assert_one_error(run(["trial", YI, "--device", device], cwd=where), 1, device)

    def test_the_simulated_kinds_with_an_id_are_known_backends_without_that_device(self):
        where = self.folder()
        for device in ("simulated:0", "emulated-phantom:1"):
            self.assert_one_error(run(["trial", YI, "--device", device], cwd=where), 1, device)
        self.assert_one_error(run(["trial", YI, "--device", "phantom"], cwd=where), 2, "phantom", "simulated")

    # ---- CALLIGRAPHY_LIBHD ----------------------------------------------------------------------------------
    def libhd_refusals(self, path, *needles):
        where = self.folder()
        env = dict(ENV, CALLIGRAPHY_LIBHD=str(path))
        self.assert_one_error(run(["trial", YI, "--device", "openhaptics"], cwd=where, env=env), 1,
                              "openhaptics", *needles)
        listing = run(["devices", "--json"], cwd=where, env=env)
        self.assertEqual(listing.returncode, 0, listing.stderr)
        notes = [n for n in json.loads(listing.stdout)["notes"] if n.startswith("openhaptics")]
        self.assertEqual(len(notes), 1, notes)
        for needle in needles:
            self.assertIn(needle, notes[0])
        # another device runs as if it were not set
        self.assertIn(run(["trial", YI, "--max-duration", "0.05"], cwd=where, env=env).returncode, (1,))

    @unittest.skipUnless(PARTIAL and Path(PARTIAL).exists(), "no partial libHD (CALLIGRAPHY_HD_PARTIAL)")
    def test_libhd_lacking_hdapi_is_refused_naming_the_path_and_what_it_lacks(self):
        self.libhd_refusals(PARTIAL, PARTIAL, "lacks", "hdBeginFrame")

    def test_libhd_that_is_another_library_or_no_library_is_refused_naming_it(self):
        where = self.folder()
        libm = next((p for p in ("/usr/lib/x86_64-linux-gnu/libm.so.6", "/lib/x86_64-linux-gnu/libm.so.6",
                                 "/usr/lib64/libm.so.6") if Path(p).exists()), None)
        if libm:
            self.libhd_refusals(libm, libm, "lacks", "hdInitDevice")
        true = shutil.which("true")
        self.libhd_refusals(true, true)
        script = where / "libHD.so"
        script.write_text("#!/bin/sh\nexit 0\n")
        script.chmod(0o755)
        self.libhd_refusals(script, str(script))
        (where / "a").symlink_to(where / "b")
        (where / "b").symlink_to(where / "a")
        self.libhd_refusals(where / "a", str(where / "a"))

    @unittest.skipUnless(PARTIAL and Path(PARTIAL).exists(), "no partial libHD (CALLIGRAPHY_HD_PARTIAL)")
    def test_a_libhd_path_with_a_line_break_is_named_on_one_line(self):
        where = self.folder()
        odd = where / "two\nlines"
        odd.mkdir()
        shutil.copy(PARTIAL, odd / "libHD.so")
        result = run(["trial", YI, "--device", "openhaptics"], cwd=where,
                     env=dict(ENV, CALLIGRAPHY_LIBHD=str(odd / "libHD.so")))
        self.assert_one_error(result, 1, "two\\nlines/libHD.so", "lacks")

    # ---- the servo rate and the clock ----------------------------------------------------------------------
    def test_lock_step_rates_at_their_bounds_space_the_trace_one_period_apart(self):
        where = self.folder()
        for device in ("simulated", "emulated-phantom"):
            for rate, seconds, ticks in ((100, 0.05, 5), (100000, 0.01, 1000)):
                csv_file = where / f"{device}-{rate}.csv"
                result = run(["trial", YI, "--device", device, "--rate", rate, "--max-duration", seconds,
                              "--csv", csv_file], cwd=where)
                self.assertEqual(result.returncode, 1, result.stderr)  # the time limit ended it
                _, rows = read_trace(csv_file)
                self.assertEqual(len(rows), ticks)
                self.assertEqual(float(rows[0][0]), 0.0)
                for step in spacing(rows):
                    self.assertAlmostEqual(step, 1 / rate, delta=1e-6)
            for rate in ("99.99", "100001", "nan", "-1000"):
                self.assert_one_error(run(["trial", YI, "--device", device, "--rate", rate], cwd=where), 2,
                                      "--rate")

    def test_real_time_rate_stops_at_10000_hz_on_options_and_in_records(self):
        where = self.folder()
        result = run(["trial", YI, "--pacing", "real-time", "--rate", "10000", "--max-duration", "0.05",
                      "--json", "t.json", "--csv", "t.csv"], cwd=where)
        self.assertEqual(result.returncode, 1, result.stderr)
        record = json.loads((where / "t.json").read_text())
        _, rows = read_trace(where / "t.csv")
        self.assertEqual(record["end_reason"], "time_limit")
        self.assertEqual(len(rows), 500)
        self.assertEqual(record["loop"]["ticks"], len(rows))
        for step in spacing(rows):
            self.assertAlmostEqual(step, 1e-4, delta=1e-6)
        self.assert_one_error(run(["trial", YI, "--pacing", "real-time", "--rate", "10001"], cwd=where), 2,
                              "--rate", "10000")
        record["specification"]["trial"]["rate_hz"] = 10001
        (where / "over.json").write_text(json.dumps(record))
        self.assert_one_error(run(["trial", "--spec", "over.json"], cwd=where), 2, "over.json: /specification/trial",
                              "rate_hz", "10001 Hz")

    @need_stand_in
    def test_openhaptics_ticks_on_the_driver_s_clock_and_counts_from_zero(self):
        where = self.folder()
        before_s = time.monotonic()
        result = run(["trial", YI, "--device", "openhaptics", "--max-duration", "0.3", "--json", "t.json",
                      "--csv", "t.csv"], cwd=where, env=with_stand_in())
        after_s = time.monotonic()
        self.assertEqual(result.returncode, 1, result.stderr)
        record = json.loads((where / "t.json").read_text())
        _, rows = read_trace(where / "t.csv")
        self.assertEqual(record["end_reason"], "time_limit")
        self.assertTrue(record["loop"]["device_clock"])
        self.assertEqual(record["loop"]["ticks"], len(rows))
        self.assertEqual(len(rows), 300)
        self.assertEqual(float(rows[0][0]), 0.0)
        self.assertAlmostEqual(statistics.median(spacing(rows)), 0.001, delta=2e-4)
        # HDAPI gives no clock of its own: the device's time of the first tick is the host's monotonic clock
        # when the scheduler called (CLOCK_MONOTONIC, as Python's time.monotonic). It is kept, and the trial's
        # times are not shifted by it. (The stand-in's own CLOCK_MONOTONIC + 1600 s is only in its log: an
        # assertion above 1600 s held only on a machine up for more than 27 minutes.)
        self.assertLessEqual(before_s, record["device_time_at_start_s"])
        self.assertLessEqual(record["device_time_at_start_s"], after_s)
        self.assertLess(float(rows[-1][0]), 5)

    @need_stand_in
    def test_a_rate_other_than_the_driver_s_is_refused_naming_both(self):
        # docs/devices.md: the scheduler rate is the device's (1000 Hz), and a loop at another rate is refused.
        where = self.folder()
        for rate in ("2000", "500"):
            result = run(["trial", YI, "--device", "openhaptics", "--rate", rate, "--json", "t.json"], cwd=where,
                         env=with_stand_in())
            self.assert_one_error(without_warnings(result), 1, f"{rate} Hz", "1000 Hz")
            self.assertFalse((where / "t.json").exists())

    def test_watchdog_ms_at_and_past_its_range(self):
        where = self.folder()
        for device in ("simulated", "emulated-phantom"):
            self.assert_one_error(run(["trial", YI, "--device", device, "--watchdog-ms", "20"], cwd=where), 2,
                                  "--watchdog-ms")
        real = ["trial", YI, "--pacing", "real-time", "--max-duration", "0.02"]
        for value in ("0", "60000"):
            result = run(real + ["--watchdog-ms", value, "--json", f"w{value}.json"], cwd=where)
            self.assertEqual(result.returncode, 1, result.stderr)
            record = json.loads((where / f"w{value}.json").read_text())
            self.assertEqual(record["end_reason"], "time_limit")
            self.assertEqual(record["specification"]["trial"]["watchdog_s"], int(value) / 1000)
        for value in ("60001", "-1", "1.5", "nan", "1e999"):
            self.assert_one_error(run(real + ["--watchdog-ms", value], cwd=where), 2, "--watchdog-ms")
        record = json.loads((where / "w0.json").read_text())
        for value in (0.0015, 60.001, -0.001):
            record["specification"]["trial"]["watchdog_s"] = value
            (where / "bad.json").write_text(json.dumps(record))
            # the pointer is the field's, or (a rule across fields: whole milliseconds) its object's with the
            # field named after it
            self.assert_one_error(run(["trial", "--spec", "bad.json"], cwd=where), 2, "bad.json: /specification/trial",
                                  "watchdog_s")

    # ---- stalls ---------------------------------------------------------------------------------------------
    def stalled(self, where, device, extra, stop_at=0.2, stop_for=0.2, seconds="1.5"):
        process = start(["trial", YI, "--device", device, "--pacing", "real-time", "--max-duration", seconds,
                         "--json", "t.json", "--csv", "t.csv", *extra], cwd=where)
        in_trial(process, stop_at)  # stopped `stop_at` s into the trial, for `stop_for` s
        process.send_signal(signal.SIGSTOP)
        time.sleep(stop_for)
        process.send_signal(signal.SIGCONT)
        _, err = process.communicate(timeout=TIMEOUT_S)
        record = json.loads((where / "t.json").read_text())
        _, rows = read_trace(where / "t.csv")
        return process.returncode, err.decode(), record, rows

    def test_a_stall_past_the_watchdog_ends_the_trial_with_every_tick_kept(self):
        for device in ("simulated", "emulated-phantom"):
            where = self.folder()
            status, err, record, rows = self.stalled(where, device, [])
            self.assertEqual(status, 1, err)
            self.assertEqual(record["end_reason"], "watchdog")
            self.assertTrue(record["aborted"])
            self.assertIn("stall", record["abort_reason"])
            loop = record["loop"]
            self.assertEqual(loop["ticks"], len(rows))  # the tick that tripped the bound included
            self.assertGreaterEqual(loop["late_ticks"], 1)
            self.assertGreaterEqual(loop["longest_stall_ms"], 50)
            self.assertLess(len(rows), 1500)
            self.assertIn("watchdog", err.strip().splitlines()[-1])
            for step in spacing(rows):  # the device's clock: one period a tick, the stall is not in it
                self.assertAlmostEqual(step, 0.001, delta=1e-6)

    def test_a_stall_under_the_watchdog_keeps_the_real_time_trial_the_lock_step_one(self):
        # docs/servo-loop.md: a real-time simulated trial records exactly the lock-step trial of the seed; with
        # the watchdog off a 200 ms stall is one late tick, re-anchored.
        where = self.folder()
        status, err, record, rows = self.stalled(where, "simulated", ["--watchdog-ms", "0"], seconds="1.0")
        self.assertEqual(status, 1, err)
        self.assertEqual(record["end_reason"], "time_limit")
        loop = record["loop"]
        self.assertEqual(loop["ticks"], 1000)
        self.assertGreaterEqual(loop["late_ticks"], 1)
        self.assertGreaterEqual(loop["deadline_reanchors"], 1)
        self.assertGreaterEqual(loop["longest_stall_ms"], 100)
        result = run(["trial", YI, "--pacing", "lock-step", "--max-duration", "1.0", "--csv", "ls.csv"], cwd=where)
        self.assertEqual(result.returncode, 1, result.stderr)
        self.assertEqual((where / "ls.csv").read_bytes(), (where / "t.csv").read_bytes())

    # ---- the stand-in's faults under Python -----------------------------------------------------------------
    def python(self, script, env=None):
        """`script` run by this interpreter with the calligraphy module, its last line parsed as JSON."""
        if importlib.util.find_spec("calligraphy") is None:
            self.skipTest("the calligraphy Python module is not on PYTHONPATH")
        result = subprocess.run([sys.executable, "-c", textwrap.dedent(script)], env=env or dict(ENV),
                                stdout=subprocess.PIPE, stderr=subprocess.PIPE, timeout=TIMEOUT_S)
        self.assertEqual(result.returncode, 0, result.stderr.decode())
        return json.loads(result.stdout.decode().strip().splitlines()[-1])

    def test_python_run_trial_names_what_it_refuses_by_the_errors_documented(self):
        # docs/python.md: DeviceNotFound (a LookupError) names the devices there are; a known device that
        # cannot be used now is DeviceUnavailable with the backend's reason; the rate in real time <= 10000 Hz.
        partial = PARTIAL if PARTIAL and Path(PARTIAL).exists() else "/nonexistent/libHD.so"
        out = self.python(f"""
            import json, os
            os.environ["CALLIGRAPHY_LIBHD"] = {partial!r}
            import calligraphy as cg
            got = {{}}
            for name, kwargs in (("mouse", {{"device": "mouse"}}), ("nosuch", {{"device": "nosuch"}}),
                                 ("openhaptics", {{"device": "openhaptics"}}),
                                 ("rate", {{"device": "emulated-phantom", "pacing": "real-time", "rate_hz": 10001}}),
                                 ("person", {{"device": "openhaptics", "pacing": "lock-step"}})):
                try:
                    cg.run_trial("一", max_duration_s=0.05, **kwargs)
                    got[name] = None
                except Exception as e:
                    got[name] = [type(e).__name__, isinstance(e, LookupError), str(e)]
            notes = [n for n in cg.list_devices().notes if n.startswith("openhaptics")]
            got["notes"] = notes
            print(json.dumps(got))
            """)
        for name in ("mouse", "nosuch"):
            kind, lookup, message = out[name]
            self.assertEqual((kind, lookup), ("DeviceNotFound", True), message)
            self.assertIn("simulated", message)
        kind, _, message = out["openhaptics"]
        self.assertEqual(kind, "DeviceUnavailable", message)
        self.assertIn(partial, message)
        kind, _, message = out["rate"]
        self.assertEqual(kind, "InvalidArgument", message)
        self.assertIn("10001", message)
        self.assertIsNotNone(out["person"])
        self.assertEqual(len(out["notes"]), 1)
        self.assertIn(partial, out["notes"][0])

    @need_stand_in
    def test_devices_lists_the_openhaptics_device_without_printing_zeros_for_its_limits(self):
        where = self.folder()
        marker = where / "loaded"
        env = with_stand_in(HD_STAND_IN_LOADED_MARKER=str(marker))
        listing = run(["devices", "--json"], cwd=where, env=env)
        self.assertEqual(listing.returncode, 0, listing.stderr)
        found = {d["name"]: d for d in json.loads(listing.stdout)["devices"]}
        self.assertIn("openhaptics", found)
        self.assertFalse(found["openhaptics"]["limits_known"])
        self.assertTrue(found["openhaptics"]["hardware"])
        self.assertFalse(found["openhaptics"]["moved_by_simulated_hand"])
        text = run(["devices"], cwd=where, env=env)
        self.assertEqual(text.returncode, 0, text.stderr)
        lines = text.stdout.decode().splitlines()
        at = lines.index("openhaptics")  # its block: the lines under its name, indented
        block = []
        for line in lines[at + 1:]:
            if not line.startswith("  "):
                break
            block.append(line)
        self.assertIn("  limits:             read from the device when it is opened", block)
        self.assertFalse([line for line in block if " N" in line or "N/m" in line], block)
        # a trial on another device never loads the driver
        marker.unlink()
        result = run(["trial", YI, "--device", "emulated-phantom", "--max-duration", "0.05"], cwd=where, env=env)
        self.assertEqual(result.returncode, 1, result.stderr)
        self.assertFalse(marker.exists())

    def python_fault(self, kind, tick, value):
        if not PYTHON_STAND_IN or not Path(PYTHON_STAND_IN).exists():
            self.skipTest("no stand-in libHD for the Python module (CALLIGRAPHY_PYTHON_HD_STAND_IN)")
        if importlib.util.find_spec("calligraphy") is None:
            self.skipTest("the calligraphy Python module is not on PYTHONPATH")
        script = textwrap.dedent(f"""
            import ctypes, json, os
            os.environ["CALLIGRAPHY_LIBHD"] = {PYTHON_STAND_IN!r}
            hd = ctypes.CDLL({PYTHON_STAND_IN!r})  # the library the backend loads: one instance
            hd.hd_stand_in_inject.argtypes = [ctypes.c_int, ctypes.c_long, ctypes.c_double]
            assert hd.hd_stand_in_inject({kind}, {tick}, {value}) == 0
            import calligraphy as cg
            r = cg.run_trial("一", device="openhaptics", max_duration_s=1.5)
            print(json.dumps({{"end_reason": r.metrics["end_reason"], "abort_reason": r.metrics["abort_reason"],
                              "aborted": r.metrics["aborted"], "loop": r.metrics["loop"],
                              "ticks": len(r.time_s), "last_force": [list(map(float, f)) for f in r.force_n[-3:]],
                              "scheduler_running": hd.hd_stand_in_scheduler_running(),
                              "initialised": hd.hd_stand_in_device_initialized()}}))
            """)
        result = subprocess.run([sys.executable, "-c", script], env={k: v for k, v in ENV.items()},
                                stdout=subprocess.PIPE, stderr=subprocess.PIPE, timeout=TIMEOUT_S)
        self.assertEqual(result.returncode, 0, result.stderr.decode())
        out = json.loads(result.stdout.decode().strip().splitlines()[-1])
        self.assertTrue(out["aborted"])
        self.assertEqual(out["loop"]["ticks"], out["ticks"])  # every tick before the fault kept
        self.assertLess(out["ticks"], 1500)
        self.assertEqual(out["scheduler_running"], 0)  # closed: scheduler stopped, device released
        self.assertEqual(out["initialised"], 0)
        return out

    def test_python_trial_on_a_driver_that_loses_its_link_ends_device_fault(self):
        out = self.python_fault(1, 300, 0)  # HD_STAND_IN_FAULT_LINK_LOST
        self.assertEqual(out["end_reason"], "device_fault")
        self.assertIn("Touch", out["abort_reason"])

    def test_python_trial_on_a_driver_past_its_force_limit_ends_device_fault(self):
        out = self.python_fault(2, 300, 0)  # HD_STAND_IN_FAULT_FORCE_LIMIT
        self.assertEqual(out["end_reason"], "device_fault")
        self.assertIn("safety limit", out["abort_reason"])

    def test_python_trial_on_a_driver_that_stalls_a_frame_ends_watchdog_with_the_stall_counted(self):
        # docs/servo-loop.md: a driver silent longer than stall_timeout_s is a watchdog fault; the statistics
        # count the stall (longest_stall: the longest time the device held one force beyond a period).
        out = self.python_fault(4, 300, 200)  # HD_STAND_IN_FAULT_SLOW_FRAME, 200 ms
        self.assertEqual(out["end_reason"], "watchdog")
        self.assertGreaterEqual(out["loop"]["longest_stall_ms"], 50)

    # ---- signals --------------------------------------------------------------------------------------------
    def interrupted(self, device, sig, env=None, after=0.3):
        where = self.folder()
        process = start(["trial", YI, "--device", device, "--pacing", "real-time", "--max-duration", "3",
                         "--json", "t.json", "--csv", "t.csv"], cwd=where, env=env)
        in_trial(process, after)  # `sig` `after` s into the trial
        process.send_signal(sig)
        _, err = process.communicate(timeout=TIMEOUT_S)
        self.assertEqual(process.returncode, 128 + sig, err)
        record = json.loads((where / "t.json").read_text())
        _, rows = read_trace(where / "t.csv")
        self.assertEqual(record["end_reason"], "interrupted")
        self.assertEqual(record["abort_reason"], f"stopped by {signal.Signals(sig).name}")
        self.assertEqual(record["loop"]["ticks"], len(rows))
        self.assertGreater(len(rows), 10)  # mid-trial: ticks were recorded before the signal
        self.assertIn(f"stopped by {signal.Signals(sig).name}", err.decode().strip().splitlines()[-1])
        return record, rows

    def test_sigint_and_sigterm_mid_trial_on_the_simulated_kinds_keep_every_tick(self):
        self.interrupted("simulated", signal.SIGINT)
        self.interrupted("emulated-phantom", signal.SIGTERM)

    @need_stand_in
    def test_sigint_mid_trial_on_openhaptics_keeps_every_tick_and_releases_the_device(self):
        record, rows = self.interrupted("openhaptics", signal.SIGINT, env=with_stand_in())
        self.assertTrue(record["loop"]["device_clock"])
        self.assertEqual(float(rows[0][0]), 0.0)

    @need_stand_in
    def test_a_signal_at_the_start_writes_nothing_or_ends_the_trial_interrupted(self):
        # A signal before the trial started opens no device and writes nothing; one a little later ends the
        # trial interrupted with its outputs written, exit 143.
        for attempt in range(4):
            where = self.folder()
            marker = where / "loaded"
            process = start(["trial", YI, "--device", "openhaptics", "--max-duration", "3", "--json", "t.json"],
                            cwd=where, env=with_stand_in(HD_STAND_IN_LOADED_MARKER=str(marker)))
            time.sleep(0.01 * attempt)
            process.send_signal(signal.SIGTERM)
            _, err = process.communicate(timeout=TIMEOUT_S)
            if process.returncode == -signal.SIGTERM:
                # the signal came before the program took it (its default action ended it, which a shell reports
                # as 143 too): then nothing may have been written
                self.assertEqual(sorted(p.name for p in where.iterdir() if p != marker), [], attempt)
                continue
            self.assertEqual(process.returncode, 143, (attempt, err))
            if (where / "t.json").exists():
                record = json.loads((where / "t.json").read_text())
                self.assertEqual(record["end_reason"], "interrupted")
                self.assertEqual(record["abort_reason"], "stopped by SIGTERM")

    def test_a_signal_while_the_outputs_are_written_is_ignored(self):
        # SIGINT stops the trial; a SIGTERM while its CSV waits for a reader of a FIFO is ignored: the files are
        # whole and the status is the first signal's.
        where = self.folder()
        os.mkfifo(where / "trace.csv")
        process = start(["trial", YI, "--device", "emulated-phantom", "--pacing", "real-time", "--max-duration",
                         "3", "--json", "t.json", "--csv", "trace.csv"], cwd=where)
        in_trial(process, 0.3)
        process.send_signal(signal.SIGINT)
        # The record is written first; then the CSV waits for a reader of the FIFO (polled, then 0.1 s into it).
        deadline = time.monotonic() + 5
        while time.monotonic() < deadline and not (where / "t.json").exists():
            time.sleep(0.01)
        time.sleep(0.1)
        process.send_signal(signal.SIGTERM)
        with open(where / "trace.csv", newline="") as fifo:
            rows = list(csv.reader(fifo))[1:]
        _, err = process.communicate(timeout=TIMEOUT_S)
        self.assertEqual(process.returncode, 130, err)
        record = json.loads((where / "t.json").read_text())
        self.assertEqual(record["abort_reason"], "stopped by SIGINT")
        self.assertEqual(record["loop"]["ticks"], len(rows))

    def test_sigterm_mid_trial_of_a_session_on_the_emulated_phantom_keeps_the_attempt(self):
        where = self.folder()
        protocol = dict(PROTOCOL, trial={"max_duration_s": 5})
        (where / "p.json").write_text(json.dumps(protocol, ensure_ascii=False))
        process = start(["session", "run", "p.json", "--subject", "S01", "--out", "study", "--device",
                         "emulated-phantom", "--pacing", "real-time"], cwd=where)
        deadline = time.monotonic() + 20
        while time.monotonic() < deadline and not any(
                b"trial_started" in log.read_bytes() for log in where.glob("study/S01/*/log.jsonl")):
            time.sleep(0.05)
        time.sleep(0.5)
        process.send_signal(signal.SIGTERM)
        _, err = process.communicate(timeout=TIMEOUT_S)
        self.assertEqual(process.returncode, 143, err)
        attempts = list(where.glob("study/S01/*/trials/attempts/*.json"))
        self.assertEqual(len(attempts), 1)
        record = json.loads(attempts[0].read_text())
        self.assertEqual(record["end_reason"], "interrupted")
        self.assertEqual(record["abort_reason"], "stopped by SIGTERM")
        trace = attempts[0].with_name(attempts[0].name.replace(".json", ".trace.h5"))
        result = run(["trace", trace, "--csv", "-"], cwd=where)
        self.assertEqual(result.returncode, 0, result.stderr)
        rows = result.stdout.decode().strip().splitlines()[1:]
        self.assertEqual(len(rows), record["loop"]["ticks"])
        self.assertIn("stopped by SIGTERM", err.decode().strip().splitlines()[-1])

    # ---- records of each kind re-run ------------------------------------------------------------------------
    def test_records_of_the_simulated_kinds_rerun_to_the_same_trace(self):
        where = self.folder()
        for device, pacing in (("emulated-phantom", "lock-step"), ("simulated", "real-time")):
            first = run(["trial", YI, "--device", device, "--pacing", pacing, "--max-duration", "0.3", "--json",
                         f"{device}.json", "--csv", f"{device}.csv"], cwd=where)
            self.assertEqual(first.returncode, 1, first.stderr)
            again = run(["trial", "--spec", f"{device}.json", "--csv", f"{device}-again.csv"], cwd=where)
            self.assertEqual(again.returncode, 1, again.stderr)
            self.assertEqual((where / f"{device}.csv").read_bytes(), (where / f"{device}-again.csv").read_bytes())

    @need_stand_in
    def test_a_record_of_openhaptics_reruns_there_or_names_why_not(self):
        where = self.folder()
        first = run(["trial", YI, "--device", "openhaptics", "--max-duration", "0.1", "--json", "oh.json"],
                    cwd=where, env=with_stand_in())
        self.assertEqual(first.returncode, 1, first.stderr)
        self.assert_one_error(run(["trial", "--spec", "oh.json"], cwd=where), 1, "openhaptics")
        again = run(["trial", "--spec", "oh.json", "--json", "again.json"], cwd=where, env=with_stand_in())
        self.assertEqual(again.returncode, 1, again.stderr)
        record = json.loads((where / "again.json").read_text())
        self.assertEqual((record["device"], record["writer"], record["end_reason"]),
                         ("openhaptics", "person", "time_limit"))
        # a person's record edited to lock-step pacing: refused at its pointer, the driver loaded or not
        record["specification"]["trial"]["pacing"] = "lock-step"
        (where / "ls.json").write_text(json.dumps(record))
        for env in (ENV, with_stand_in()):
            self.assert_one_error(run(["trial", "--spec", "ls.json", "--json", "out.json"], cwd=where, env=env), 2,
                                  "ls.json", "/specification/trial/pacing")
            self.assertFalse((where / "out.json").exists())

    def test_records_edited_to_a_device_they_cannot_run_on_are_refused_at_the_pointer(self):
        where = self.folder()
        run(["trial", YI, "--max-duration", "0.05", "--json", "t.json"], cwd=where)
        record = json.loads((where / "t.json").read_text())
        cases = [({"device": "mouse"}, 2, "/specification/trial/device"),
                 ({"device": "no-such-device"}, 2, "/specification/trial/device"),
                 ({"device": "emulated-phantom", "writer": "person"}, 2, "/specification/trial/writer"),
                 ({"device": "openhaptics", "writer": "simulated"}, 2, "/specification/trial/writer"),
                 ({"device": "phantom-hid:/dev/null", "writer": "simulated"}, 2, "/specification/trial/writer")]
        for edit, status, pointer in cases:
            changed = json.loads(json.dumps(record))
            changed["specification"]["trial"].update(edit)
            (where / "e.json").write_text(json.dumps(changed))
            self.assert_one_error(run(["trial", "--spec", "e.json", "--json", "out.json"], cwd=where), status,
                                  "e.json", pointer)
            self.assertFalse((where / "out.json").exists())


if __name__ == "__main__":
    unittest.main(verbosity=2)
