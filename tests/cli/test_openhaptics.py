#!/usr/bin/env python3
"""The `calligraphy` program with the OpenHaptics backend (docs/devices.md), run by CTest as
`cli_openhaptics_tests` against the stand-in libHD the test suite builds (tests/hd_stand_in), which is
set up through its environment variables:

- a trial on the stand-in: the stand-in's hand plays back a pen path (from the simulated writer's trace of
  the same character, turned into HDAPI's frame and millimetres); the trial completes and its times start
  at 0 although the stand-in's clock reads its own;
- a device that cannot initialise: exit 1 with the HD error and what to try, not "unknown device";
- a CALLIGRAPHY_LIBHD that is not a loadable library (a folder, an empty, short, truncated or text file, a
  FIFO, /dev/zero, a missing file): commands that do not use OpenHaptics run as if it were not set and
  never load it, `devices` notes the path and why, `--device openhaptics` exits 1 naming them; nothing
  crashes or hangs;
- a hostile driver (the stand-in's HD_STAND_IN_INIT, HD_STAND_IN_EXIT_ON_LOAD, HD_STAND_IN_SCHEDULER_STALLED):
  one that crashes, hangs or exits in hdInitDevice or while loading is named by `devices`, `trial --device
  openhaptics` and Python's list_devices() with what it did, the command itself survives; one whose
  scheduler never runs leaves a trial that SIGTERM still ends (143, outputs written);
- a CALLIGRAPHY_LIBHD refused for missing symbols is never replaced by a libHD.so on the search path.

CALLIGRAPHY_CLI names the program, CALLIGRAPHY_HD_STAND_IN the stand-in, CALLIGRAPHY_HD_PARTIAL a libHD with
hdInitDevice only, CALLIGRAPHY_PYTHONPATH the Python package (its test is skipped when it does not import) and
CALLIGRAPHY_PYTHON_HD_STAND_IN the stand-in built as that package was (default: CALLIGRAPHY_HD_STAND_IN).
Standard library only (unittest).
"""
import csv
import json
import os
import shutil
import signal
import subprocess
import sys
import tempfile
import time
import unittest
from pathlib import Path

CLI = os.environ.get("CALLIGRAPHY_CLI", "")
STAND_IN = os.environ.get("CALLIGRAPHY_HD_STAND_IN", "")
PARTIAL = os.environ.get("CALLIGRAPHY_HD_PARTIAL", "")
PYTHONPATH = os.environ.get("CALLIGRAPHY_PYTHONPATH", "")
# The stand-in built as that package was: a sanitizer build's cannot be loaded into a plain interpreter.
PYTHON_STAND_IN = os.environ.get("CALLIGRAPHY_PYTHON_HD_STAND_IN", "") or STAND_IN
# Two strokes: the properties are the same as a longer character's, at a fifth of its writing time.
CHARACTER = "十"
TIMEOUT_S = 120  # a hang fails the case instead of blocking CTest


def hd_mm(x, y, z):
    """HDAPI's frame (x right, y up, z towards the user; mm) from the library's (x right, y away, z up; m)."""
    return 1000.0 * x, 1000.0 * z, -1000.0 * y


class OpenHapticsTestCase(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        if not CLI or not Path(CLI).exists():
            raise unittest.SkipTest(f"CALLIGRAPHY_CLI={CLI!r} is not the calligraphy program")
        if not STAND_IN or not Path(STAND_IN).exists():
            raise AssertionError(f"CALLIGRAPHY_HD_STAND_IN={STAND_IN!r} is not the stand-in libHD")
        cls.folder = tempfile.TemporaryDirectory(prefix="calligraphy-openhaptics-")
        cls.dir = Path(cls.folder.name)
        # A pen path: the simulated writer's trace of the character, 1 kHz, resampled at 5 ms.
        trace = cls.dir / "writer.csv"
        result = subprocess.run([CLI, "trial", CHARACTER, "--csv", str(trace)], capture_output=True, timeout=TIMEOUT_S)
        assert result.returncode == 0, result.stderr.decode()
        with open(trace, newline="") as f:
            rows = list(csv.DictReader(f))
        cls.path = cls.dir / "path.txt"
        x = y = z = 0.0
        with open(cls.path, "w") as f:
            f.write(f"0 {' '.join(map(str, hd_mm(float(rows[0]['x']), float(rows[0]['y']), float(rows[0]['z']))))}\n")
            for row in rows[::5] + rows[-1:]:
                x, y, z = hd_mm(float(row["x"]), float(row["y"]), float(row["z"]))
                f.write(f"{0.3 + float(row['t'])} {x} {y} {z}\n")  # 0.3 s of rest while the trial starts
            # The trace ends where the last stroke was accepted, pen down: the hand then lifts the pen.
            f.write(f"{0.4 + float(rows[-1]['t'])} {x} {y + 10.0} {z}\n")
        cls.written_s = 0.4 + float(rows[-1]["t"])

    @classmethod
    def tearDownClass(cls):
        cls.folder.cleanup()

    def run_cli(self, *args, **environment):
        env = {k: v for k, v in os.environ.items() if not k.startswith(("CALLIGRAPHY_LIBHD", "HD_STAND_IN_"))}
        env.update(environment)
        return subprocess.run([CLI, *map(str, args)], cwd=self.dir, env=env, capture_output=True, timeout=TIMEOUT_S)

    def test_a_trial_on_the_stand_in_completes_with_times_from_zero(self):
        out = self.dir / "trial.json"
        trace = self.dir / "trial.csv"
        result = self.run_cli("trial", CHARACTER, "--device", "openhaptics", "--json", out, "--csv", trace,
                              CALLIGRAPHY_LIBHD=STAND_IN, HD_STAND_IN_PATH=str(self.path))
        self.assertEqual(result.returncode, 0, result.stderr.decode())
        record = json.loads(out.read_text())
        self.assertEqual(record["end_reason"], "completed")
        self.assertEqual(record["strokes_completed"], 2)
        # The trial's clock, not the stand-in's (which reads 1600 s and more): about the path's length in
        # time, longer on a loaded machine (the stand-in's hand keeps its own ticks' time).
        self.assertLess(record["trial_time_s"], 2.0 * self.written_s + 5.0)
        self.assertGreater(record["device_time_at_start_s"], 100.0)  # the stand-in's own clock
        self.assertTrue(record["loop"]["device_clock"])
        with open(trace, newline="") as f:
            first = next(csv.DictReader(f))
        self.assertEqual(float(first["t"]), 0.0)

    def test_a_device_that_cannot_initialise_is_named_with_its_reason(self):
        result = self.run_cli("trial", CHARACTER, "--device", "openhaptics", CALLIGRAPHY_LIBHD=STAND_IN,
                              HD_STAND_IN_FAIL_INIT="0x303")
        message = result.stderr.decode()
        self.assertEqual(result.returncode, 1, message)
        self.assertIn("HD_COMM_CONFIG_ERROR", message)
        self.assertIn("plugged in", message)
        self.assertNotIn("unknown device", message)
        listing = self.run_cli("devices", CALLIGRAPHY_LIBHD=STAND_IN, HD_STAND_IN_FAIL_INIT="0x303")
        self.assertEqual(listing.returncode, 0)
        self.assertIn("HD_COMM_CONFIG_ERROR", listing.stdout.decode())
        working = self.run_cli("devices", CALLIGRAPHY_LIBHD=STAND_IN)
        self.assertIn("openhaptics", working.stdout.decode())
        self.assertIn("read from the device when it is opened", working.stdout.decode())
        self.assertNotIn("max force:          0 N", working.stdout.decode())

    def damaged_paths(self):
        folder = self.dir / "damaged"
        folder.mkdir(exist_ok=True)
        library = Path(STAND_IN).read_bytes()
        cases = {"a folder": (folder, "a directory"), "/dev/zero": (Path("/dev/zero"), "a character device"),
                 "missing": (folder / "missing.so", "No such file")}
        for name, content, why in [("empty.so", b"", "empty"), ("short.so", b"libHD\n", "too short"),
                                   ("text.so", b"x" * 300, "not an ELF file"),
                                   ("truncated.so", library[: len(library) // 3], "truncated")]:
            (folder / name).write_bytes(content)
            cases[name] = (folder / name, why)
        fifo = folder / "fifo.so"
        if not fifo.exists():
            os.mkfifo(fifo)
        cases["fifo"] = (fifo, "a FIFO")
        return cases

    def test_a_damaged_libhd_path_never_crashes_or_hangs_a_command(self):
        for name, (path, why) in self.damaged_paths().items():
            with self.subTest(name):
                plain = self.run_cli("trial", CHARACTER, CALLIGRAPHY_LIBHD=str(path))
                self.assertEqual(plain.returncode, 0, plain.stderr.decode())
                listing = self.run_cli("devices", CALLIGRAPHY_LIBHD=str(path))
                self.assertEqual(listing.returncode, 0, listing.stderr.decode())
                self.assertIn(str(path), listing.stdout.decode())
                self.assertIn(why, listing.stdout.decode())
                asked = self.run_cli("trial", CHARACTER, "--device", "openhaptics", CALLIGRAPHY_LIBHD=str(path))
                message = asked.stderr.decode()
                self.assertEqual(asked.returncode, 1, message)
                self.assertIn(str(path), message)
                self.assertIn(why, message)

    def test_commands_on_the_simulated_device_never_load_libhd(self):
        marker = self.dir / "loaded"
        for args in (["trial", CHARACTER], ["trial", CHARACTER, "--pacing", "real-time", "--max-duration", "1"]):
            with self.subTest(" ".join(args)):
                marker.unlink(missing_ok=True)
                result = self.run_cli(*args, CALLIGRAPHY_LIBHD=STAND_IN, HD_STAND_IN_LOADED_MARKER=str(marker))
                self.assertIn(result.returncode, (0, 1), result.stderr.decode())
                self.assertFalse(marker.exists(), "the command loaded libHD")
        # The marker does work: `devices` probes every backend and so loads it.
        self.run_cli("devices", CALLIGRAPHY_LIBHD=STAND_IN, HD_STAND_IN_LOADED_MARKER=str(marker))
        self.assertTrue(marker.exists())

    # The stand-in misbehaving in the probe process, and what each command must say about it.
    HOSTILE = {
        "crash in hdInitDevice": ({"HD_STAND_IN_INIT": "crash"},
                                  "the driver crashed with SIGSEGV while initialising the device"),
        "hang in hdInitDevice": ({"HD_STAND_IN_INIT": "hang"}, "did not return from hdInitDevice within 5 s"),
        "exit(0) while loading": ({"HD_STAND_IN_EXIT_ON_LOAD": "0"},
                                  "the driver library exited the process (status 0) while loading"),
        "exit(0) in hdInitDevice": ({"HD_STAND_IN_INIT": "exit:0"},
                                    "the driver library exited the process (status 0) while initialising"),
    }

    def test_a_driver_that_crashes_hangs_or_exits_is_named_and_the_command_survives(self):
        for name, (misbehaviour, why) in self.HOSTILE.items():
            with self.subTest(name):
                listing = self.run_cli("devices", CALLIGRAPHY_LIBHD=STAND_IN, **misbehaviour)
                self.assertEqual(listing.returncode, 0, listing.stderr.decode())
                notes = [line for line in listing.stdout.decode().splitlines() if "openhaptics:" in line]
                self.assertEqual(len(notes), 1, listing.stdout.decode())
                self.assertIn(STAND_IN, notes[0])
                self.assertIn(why, notes[0])
                self.assertIn("simulated", listing.stdout.decode())  # the rest of the listing is there
                trial = self.dir / "hostile.json"
                trial.unlink(missing_ok=True)
                asked = self.run_cli("trial", CHARACTER, "--device", "openhaptics", "--json", trial,
                                     CALLIGRAPHY_LIBHD=STAND_IN, **misbehaviour)
                message = asked.stderr.decode()
                self.assertEqual(asked.returncode, 1, message)
                errors = [line for line in message.splitlines() if "error:" in line]
                self.assertEqual(len(errors), 1, message)
                self.assertIn(STAND_IN, errors[0])
                self.assertIn(why, errors[0])
                self.assertFalse(trial.exists())

    def test_python_list_devices_names_a_driver_that_crashes(self):
        env = {k: v for k, v in os.environ.items() if not k.startswith(("CALLIGRAPHY_LIBHD", "HD_STAND_IN_"))}
        env.update(PYTHONPATH=PYTHONPATH, CALLIGRAPHY_LIBHD=PYTHON_STAND_IN, HD_STAND_IN_INIT="crash")
        script = ("import calligraphy\n"
                  "survey = calligraphy.list_devices()\n"
                  "print([d.name for d in survey.devices])\n"
                  "print(survey.notes)\n")
        # The build's own package, never one installed elsewhere (an earlier `cmake --install` in /usr/local).
        from_build = ("import pathlib, sys, calligraphy\n"
                      "sys.exit(0 if pathlib.Path(calligraphy.__file__).resolve().is_relative_to("
                      "pathlib.Path(sys.argv[1]).resolve()) else 3)\n")
        if not PYTHONPATH or subprocess.run([sys.executable, "-c", from_build, PYTHONPATH], env=env,
                                            capture_output=True, timeout=TIMEOUT_S).returncode != 0:
            self.skipTest(f"the calligraphy Python package does not import from {PYTHONPATH!r}")
        result = subprocess.run([sys.executable, "-c", script], env=env, capture_output=True, timeout=TIMEOUT_S)
        self.assertEqual(result.returncode, 0, result.stderr.decode())
        output = result.stdout.decode()
        self.assertIn("simulated", output)
        self.assertIn(PYTHON_STAND_IN, output)
        self.assertIn("the driver crashed with SIGSEGV while initialising the device", output)

    def test_sigterm_ends_a_trial_whose_driver_scheduler_never_runs(self):
        out = self.dir / "stalled.json"
        trace = self.dir / "stalled.csv"
        for path in (out, trace):
            path.unlink(missing_ok=True)
        env = {k: v for k, v in os.environ.items() if not k.startswith(("CALLIGRAPHY_LIBHD", "HD_STAND_IN_"))}
        env.update(CALLIGRAPHY_LIBHD=STAND_IN, HD_STAND_IN_SCHEDULER_STALLED="1")
        process = subprocess.Popen([CLI, "trial", CHARACTER, "--device", "openhaptics", "--json", str(out), "--csv",
                                    str(trace)], cwd=self.dir, env=env, stdout=subprocess.PIPE,
                                   stderr=subprocess.PIPE)
        # The trial waits for the driver's first callback; the signal must end that wait, whenever it comes.
        time.sleep(1.0)
        process.send_signal(signal.SIGTERM)
        try:
            _, stderr = process.communicate(timeout=TIMEOUT_S)
        except subprocess.TimeoutExpired:
            process.kill()
            process.communicate()
            self.fail("SIGTERM did not end a trial whose driver scheduler never runs")
        message = stderr.decode()
        self.assertEqual(process.returncode, 143, message)
        self.assertIn("stopped by SIGTERM", message)
        record = json.loads(out.read_text())
        self.assertEqual(record["end_reason"], "interrupted")
        self.assertEqual(record["max_force_n"], 0.0)  # no force was ever commanded
        with open(trace, newline="") as f:
            rows = list(csv.DictReader(f))
        self.assertTrue(all(float(row[k]) == 0.0 for row in rows for k in ("fx", "fy", "fz")))

    def test_a_trial_whose_driver_scheduler_never_runs_ends_with_the_reason(self):
        asked = self.run_cli("trial", CHARACTER, "--device", "openhaptics", CALLIGRAPHY_LIBHD=STAND_IN,
                             HD_STAND_IN_SCHEDULER_STALLED="1")
        message = asked.stderr.decode()
        self.assertEqual(asked.returncode, 1, message)
        self.assertIn(STAND_IN, message)
        self.assertIn("ran no callback within 5 s", message)

    def test_a_driver_stuck_stopping_its_scheduler_still_gives_the_trial_its_outputs(self):
        out = self.dir / "stuck.json"
        trace = self.dir / "stuck.csv"
        started = time.monotonic()
        # The driver's thread is still stuck at exit, on purpose: LeakSanitizer cannot stop it to look for
        # leaks (its tracer faults), so leaks are not checked in this one run of a sanitized build.
        asan = ":".join(filter(None, [os.environ.get("ASAN_OPTIONS", ""), "detect_leaks=0"]))
        result = self.run_cli("trial", CHARACTER, "--device", "openhaptics", "--json", out, "--csv", trace,
                              CALLIGRAPHY_LIBHD=STAND_IN, HD_STAND_IN_PATH=str(self.path), HD_STAND_IN_STOP="hang",
                              ASAN_OPTIONS=asan)
        message = result.stderr.decode()
        self.assertEqual(result.returncode, 0, message)
        self.assertLess(time.monotonic() - started, TIMEOUT_S)
        self.assertIn("did not stop within 5 s", message)
        self.assertEqual(json.loads(out.read_text())["end_reason"], "completed")
        self.assertGreater(len(trace.read_text().splitlines()), 100)

    def test_a_named_library_refused_for_missing_symbols_is_not_replaced(self):
        if not PARTIAL or not Path(PARTIAL).exists():
            self.skipTest(f"CALLIGRAPHY_HD_PARTIAL={PARTIAL!r} is not the partial libHD")
        # The stand-in is on the search path as libHD.so: a fallback would find it and list the device.
        search = {"LD_LIBRARY_PATH": str(Path(STAND_IN).parent)}
        found = self.run_cli("devices", **search).stdout.decode()
        self.assertIn("via libHD.so", found)  # the fallback a refused named library must not reach
        listing = self.run_cli("devices", CALLIGRAPHY_LIBHD=PARTIAL, **search)
        self.assertEqual(listing.returncode, 0, listing.stderr.decode())
        output = listing.stdout.decode()
        self.assertNotIn("via ", output)
        notes = [line for line in output.splitlines() if "openhaptics:" in line]
        self.assertEqual(len(notes), 1, output)
        self.assertIn("CALLIGRAPHY_LIBHD=" + PARTIAL, notes[0])
        self.assertIn("lacks hdDisableDevice", notes[0])
        asked = self.run_cli("trial", CHARACTER, "--device", "openhaptics", CALLIGRAPHY_LIBHD=PARTIAL, **search)
        message = asked.stderr.decode()
        self.assertEqual(asked.returncode, 1, message)
        self.assertIn(PARTIAL, message)
        self.assertIn("lacks hdDisableDevice", message)
        self.assertNotIn(STAND_IN, message)


if __name__ == "__main__":
    unittest.main()
