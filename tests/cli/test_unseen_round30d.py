#!/usr/bin/env python3
"""Round 30D: devices, the emulated Phantom and the safety chain, from the command line and Python. From the docs
alone: docs/devices.md (the Phantom's safety and device information, "Emulated Phantom", "Trials on any device",
"Discovery", "The pointer as a device", "OpenHaptics"), docs/servo-loop.md, docs/force-rendering.md "Safety
chain", docs/cli.md (`devices`, `trial`: `--device`, `--pacing`, `--realtime`, `--watchdog-ms`, "Stopping a
trial", exit statuses) and docs/python.md (`run_trial`, `list_devices`).

Attacked: `devices` listing every kind the docs name with its writer and commands, each kind taken or refused by
`trial` as listed; every surveyed device running a trial that names it; trials on `emulated-phantom` with ticks
one period apart at rates from 100 Hz to 100 kHz (lock-step) and in real time, forces never above the Omni's
3.3 N, the per-tick change limit or the start ramp even under a guidance stiffness of 100,000 N/m; the default
stiffness capped at the Omni's 700 N/m; the inkwell start; `--watchdog-ms` at and past its range, with
lock-step; SIGINT, SIGTERM and SIGSTOP during a real-time trial on the emulated Phantom, every tick kept;
devices that need hardware (OpenHaptics with no libHD or a refused CALLIGRAPHY_LIBHD, Phantoms over HID or USB)
failing in one line with no file left behind, and who writes checked against the kind first; device names in
other spellings; Python's registry without the emulator, its real-time trial and its watchdog argument.

CALLIGRAPHY_CLI names the program; PYTHONPATH the built Python package. CALLIGRAPHY_SANITIZED=1 takes five cases.
"""
import csv
import io
import json
import math
import os
import shutil
import signal
import subprocess
import tempfile
import time
import unittest
from pathlib import Path

from outsider import CLI, ENV, OneErrorLine, error_lines, run, run_ok, sanitized_subset

try:
    import calligraphy as cg
except ImportError:  # the Python cases skip; the command-line ones run
    cg = None

needs_python = unittest.skipIf(cg is None, "the calligraphy Python package (PYTHONPATH) is missing")

load_tests = sanitized_subset({"test_devices_lists_every_documented_kind_with_its_writer_and_commands",
                               "test_kinds_for_trial_pass_trial_check_and_the_pointer_kinds_are_refused",
                               "test_device_name_in_other_spellings_is_a_usage_error_listing_the_devices",
                               "test_libhd_that_is_a_folder_is_refused_naming_it_and_no_file_is_left",
                               "test_person_devices_refuse_simulated_writing_before_they_are_looked_for"})

# docs/cli.md "devices": the kinds, who writes on each and the commands that take each with --device.
KINDS = {
    "simulated": ("simulated", ["trial", "train", "session run"]),
    "emulated-phantom": ("simulated", ["trial", "train", "session run"]),
    "mouse": ("person", ["train", "session run"]),
    "mouse-hand": ("person", ["train", "session run"]),
    "openhaptics": ("person", ["trial", "train", "session run"]),
    "phantom-hid:PATH": ("person", ["trial", "train", "session run"]),
    "phantom-usb:BUS-ADDRESS": ("person", ["trial", "train", "session run"]),
}
# A name of each kind as a user gives it (the placeholders filled in).
KIND_NAMES = {"phantom-hid:PATH": "phantom-hid:/dev/hidraw0", "phantom-usb:BUS-ADDRESS": "phantom-usb:1-2"}
# docs/devices.md "Device information" and the simulated Phantom Desktop (docs/force-rendering.md).
OMNI = {"max_force_n": 3.3, "max_continuous_force_n": 0.88, "max_stiffness_n_per_m": 700.0,
        "max_damping_n_s_per_m": 5.0, "workspace_radius_m": 0.10, "workspace_size_m": [0.16, 0.12, 0.07]}
DESKTOP = {"max_force_n": 7.9, "max_continuous_force_n": 1.75, "max_stiffness_n_per_m": 1000.0,
           "max_damping_n_s_per_m": 5.0, "workspace_radius_m": 0.10, "workspace_size_m": [0.16, 0.12, 0.12]}
MAX_STEP_N = 0.25        # docs/force-rendering.md: max_force_change_n_per_tick default
RAMP_N_PER_S = 20.0      # start_ramp_n_per_s default
CSV_FORCE_ROUND_N = 1e-4  # forces to 0.1 mN in the CSV
LOOP_KEYS = {"ticks", "late_ticks", "forces_withheld", "longest_stall_ms", "deadline_reanchors",
             "period_jitter_us_p99", "period_jitter_us_max", "fifo_scheduling"}


def read_csv(path):
    return list(csv.DictReader(io.StringIO(Path(path).read_text(encoding="utf-8"))))


def forces(rows):
    return [tuple(float(r[k]) for k in ("fx", "fy", "fz")) for r in rows]


def norm(v):
    return math.sqrt(sum(c * c for c in v))


class Round30D(unittest.TestCase, OneErrorLine):
    @classmethod
    def setUpClass(cls):
        if not CLI:
            raise unittest.SkipTest("CALLIGRAPHY_CLI not set")
        cls.tmp = Path(tempfile.mkdtemp(prefix="round30d-"))
        out = run_ok(["devices", "--json"], cls.tmp)
        cls.survey = json.loads(out.stdout)
        cls.survey_text = run_ok(["devices"], cls.tmp).stdout.decode()
        cls.trials = {}

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.tmp, ignore_errors=True)

    def cli(self, *args, env=None):
        return run(list(args), self.tmp, env=env)

    def fresh(self):
        """An empty folder of this case's own under the round's."""
        return Path(tempfile.mkdtemp(dir=self.tmp))

    def trial(self, device, *extra):
        """`trial 十 --device DEVICE EXTRA --json --csv`, once per argument list: (result, record, CSV rows)."""
        key = (device, *extra)
        if key not in self.trials:
            d = self.fresh()
            result = run(["trial", "十", "--device", device, *extra, "--json", "r.json", "--csv", "r.csv"], d)
            self.assertNotIn(b"Traceback", result.stderr)
            record = json.loads((d / "r.json").read_text(encoding="utf-8"))
            self.trials[key] = (result, record, read_csv(d / "r.csv"))
        return self.trials[key]

    def assertPeriods(self, rows, rate_hz, n):
        """`n` ticks from t = 0, each one period of `rate_hz` after the last (t is written to 1 us)."""
        t = [float(r["t"]) for r in rows]
        self.assertEqual(len(t), n)
        self.assertEqual(t[0], 0.0)
        for k, tk in enumerate(t):
            self.assertAlmostEqual(tk, k / rate_hz, delta=0.5e-6 + 1e-12, msg=f"tick {k} at {rate_hz} Hz")

    def assertSafeForces(self, rows, record, peak_n, rate_hz=1000.0):
        """The safety chain's limits hold in the CSV and the record states its maximum."""
        f = forces(rows)
        mags = [norm(v) for v in f]
        tol = CSV_FORCE_ROUND_N
        self.assertLessEqual(max(mags), peak_n + tol)
        self.assertLessEqual(record["max_force_n"], peak_n + 1e-9)
        self.assertAlmostEqual(record["max_force_n"], max(mags), delta=tol)
        steps = [norm(tuple(a - b for a, b in zip(f[k], f[k - 1]))) for k in range(1, len(f))]
        self.assertLessEqual(max(steps), MAX_STEP_N + 2 * tol)
        self.assertLessEqual(record["max_force_step_n"], MAX_STEP_N + 1e-9)
        for k, m in enumerate(mags):  # the start ramp: |F| <= 20 N/s x the time since the chain began
            self.assertLessEqual(m, RAMP_N_PER_S * (k + 2) / rate_hz + tol, f"tick {k}")

    # ---- devices -----------------------------------------------------------------------------------------
    def test_devices_lists_every_documented_kind_with_its_writer_and_commands(self):
        kinds = {k["name"]: (k["writer"], k["commands"]) for k in self.survey["kinds"]}
        expected = KINDS
        # docs/cli.md: "In a build without the trainer window no kind lists `train`, and the pointer kinds are
        # listed with no command" (the sanitizer builds have no window; such a kind says "not in this build").
        if any("not in this build" in k.get("what", "") for k in self.survey["kinds"]):
            expected = {name: (writer, [] if name in ("mouse", "mouse-hand") else [c for c in commands if c != "train"])
                        for name, (writer, commands) in KINDS.items()}
        self.assertEqual(kinds, expected)
        self.assertIn("No haptic hardware attached.", self.survey_text)
        self.assertFalse(self.survey["any_hardware"])
        for name in KINDS:
            self.assertIn(name, self.survey_text)
        # what was looked for and not found: a note per hardware backend
        for backend in ("openhaptics", "phantom-hid", "phantom-usb"):
            self.assertTrue(any(n.startswith(backend) for n in self.survey["notes"]), (backend, self.survey["notes"]))
        # the pointer devices are kinds, never in the survey: only the window has a pointer
        names = [d["name"] for d in self.survey["devices"]]
        self.assertNotIn("mouse", names)
        self.assertNotIn("mouse-hand", names)

    def test_survey_gives_the_documented_limits_and_capabilities(self):
        devices = {d["name"]: d for d in self.survey["devices"]}
        self.assertEqual(set(devices), {"simulated", "emulated-phantom"})
        for name, limits, calibrates in (("emulated-phantom", OMNI, True), ("simulated", DESKTOP, False)):
            with self.subTest(device=name):
                d = devices[name]
                self.assertEqual((d["hardware"], d["moved_by_simulated_hand"], d["needs_calibration"],
                                  d["limits_known"]), (False, True, calibrates, True))
                for key, value in limits.items():
                    self.assertEqual(d["info"][key], value, key)

    def test_kinds_for_trial_pass_trial_check_and_the_pointer_kinds_are_refused(self):
        for kind, (_, commands) in KINDS.items():
            name = KIND_NAMES.get(kind, kind)
            with self.subTest(device=name):
                result = self.cli("trial", "十", "--device", name, "--check")
                if "trial" in commands:
                    self.assertEqual(result.returncode, 0, result.stderr)
                    self.assertEqual(len(result.stdout.decode().strip().splitlines()), 1)
                else:
                    line = self.assert_one_error(result, 2, "--device", name)
                    self.assertIn("train", line)
                    self.assertIn("session run", line)

    def test_pointer_device_trial_is_refused_before_anything_is_written(self):
        for name in ("mouse", "mouse-hand"):
            with self.subTest(device=name):
                d = self.fresh()
                result = run(["trial", "十", "--device", name, "--json", "m.json", "--csv", "m.csv"], d)
                line = self.assert_one_error(result, 2, name)
                self.assertIn("train", line)
                self.assertEqual(list(d.iterdir()), [])

    def test_every_surveyed_device_runs_a_trial_that_names_it(self):
        for d in self.survey["devices"]:
            with self.subTest(device=d["name"]):
                result, record, rows = self.trial(d["name"])
                self.assertEqual(result.returncode, 0, result.stderr)
                self.assertEqual(record["device"], d["name"])
                self.assertEqual(record["specification"]["trial"]["device"], d["name"])
                self.assertEqual(record["specification"]["trial"]["pacing"], "lock-step")
                self.assertEqual(record["end_reason"], "completed")
                self.assertEqual(record["strokes_completed"], 2)
                self.assertIn(d["name"], result.stdout.decode().splitlines()[0])
                self.assertNotIn("loop", record, "a lock-step trial has no servo loop to report")

    # ---- the emulated Phantom ----------------------------------------------------------------------------
    def test_emulated_ticks_are_one_period_apart_at_every_rate(self):
        # docs/devices.md: "a trial's ticks on the emulated Phantom are one period of its rate apart from the
        # first, at any rate"; cli.md: the trial ends after --max-duration x --rate ticks (exit 1, time_limit).
        for rate in (100, 300, 3000, 10000, 100000):
            with self.subTest(rate=rate):
                result, record, rows = self.trial("emulated-phantom", "--rate", str(rate), "--max-duration", "0.05")
                self.assertEqual(result.returncode, 1, result.stderr)
                self.assertEqual(record["end_reason"], "time_limit")
                self.assertEqual(record["rate_hz"], rate)
                self.assertPeriods(rows, rate, round(0.05 * rate))

    def test_emulated_forces_stay_under_the_omni_saturation_and_the_chain_s_limits(self):
        # A guidance 140 times the Omni's stable stiffness and a writer 4 mm off: the chain clamps to 3.3 N.
        result, record, rows = self.trial("emulated-phantom", "--guidance-stiffness", "100000",
                                          "--writer-param", "bias_offset_m=0.004", "--max-duration", "4")
        self.assertIn(result.returncode, (0, 1), result.stderr)
        self.assertSafeForces(rows, record, OMNI["max_force_n"])
        self.assertGreater(record["max_force_n"], OMNI["max_continuous_force_n"], "the demand reached the clamp")
        _, plain, plain_rows = self.trial("emulated-phantom")
        self.assertSafeForces(plain_rows, plain, OMNI["max_force_n"])

    def test_simulated_desktop_forces_stay_under_its_saturation(self):
        result, record, rows = self.trial("simulated", "--guidance-stiffness", "100000",
                                          "--writer-param", "bias_offset_m=0.004", "--max-duration", "4")
        self.assertIn(result.returncode, (0, 1), result.stderr)
        self.assertSafeForces(rows, record, DESKTOP["max_force_n"])

    def test_default_stiffness_is_capped_at_each_device_s_stable_maximum(self):
        # cli.md "Defaults do not warn": paper 800 N/m capped at 700 N/m on the emulated Phantom.
        for device, paper in (("emulated-phantom", 700.0), ("simulated", 800.0)):
            with self.subTest(device=device):
                result, record, _ = self.trial(device)
                self.assertEqual(record["specification"]["force_law"]["paper_stiffness_n_per_m"], paper)
                self.assertNotIn(b"stiffness", result.stderr)

    def test_emulated_trial_starts_in_the_inkwell(self):
        # devices.md: "in the inkwell the tip is at (0, -43, -21) mm in device coordinates"
        _, record, rows = self.trial("emulated-phantom")
        first = [float(rows[0][k]) * 1000 for k in ("x", "y", "z")]
        for got, want in zip(first, (0.0, -43.0, -21.0)):
            self.assertAlmostEqual(got, want, delta=0.5)

    def test_emulated_lock_step_repeats_and_reruns_bit_for_bit(self):
        d = self.fresh()
        run_ok(["trial", "十", "--device", "emulated-phantom", "--seed", "3", "--json", "a.json", "--csv", "a.csv"], d)
        run_ok(["trial", "十", "--device", "emulated-phantom", "--seed", "3", "--csv", "b.csv"], d)
        again = run(["trial", "--spec", "a.json", "--csv", "c.csv"], d)
        self.assertEqual(again.returncode, 0, again.stderr)
        self.assertNotIn(b"differs", again.stderr)
        a = (d / "a.csv").read_bytes()
        self.assertEqual((d / "b.csv").read_bytes(), a)
        self.assertEqual((d / "c.csv").read_bytes(), a)

    # ---- real time ---------------------------------------------------------------------------------------
    def test_real_time_emulated_trial_keeps_every_tick_one_period_apart(self):
        result, record, rows = self.trial("emulated-phantom", "--pacing", "real-time", "--realtime", "ignore",
                                          "--rate", "500", "--max-duration", "0.2")
        self.assertEqual(result.returncode, 1, result.stderr)
        self.assertEqual(record["end_reason"], "time_limit")
        self.assertEqual(record["specification"]["trial"]["pacing"], "real-time")
        self.assertLessEqual(LOOP_KEYS, set(record["loop"]))
        self.assertEqual(record["loop"]["ticks"], 100)
        self.assertPeriods(rows, 500, 100)
        self.assertIn("servo loop", result.stdout.decode())

    def test_real_time_rate_above_ten_kilohertz_is_a_usage_error(self):
        for device in ("simulated", "emulated-phantom"):
            with self.subTest(device=device):
                self.assert_one_error(self.cli("trial", "十", "--device", device, "--pacing", "real-time",
                                               "--rate", "10001", "--check"), 2, "--rate")
        self.assertEqual(self.cli("trial", "十", "--pacing", "real-time", "--rate", "10000", "--check").returncode, 0)
        self.assertEqual(self.cli("trial", "十", "--rate", "100000", "--max-duration", "1", "--check").returncode, 0)

    def test_rate_in_the_tick_limit_error_reads_as_a_rate(self):
        # servo-loop.md: "Rates in messages read `500 Hz` or `678.3 Hz`"; 300 s at 100 kHz is past 10^7 ticks.
        line = self.assert_one_error(self.cli("trial", "十", "--rate", "100000", "--check"), 2, "--max-duration",
                                     "--rate", "100000 Hz")
        self.assertNotIn("e+", line)

    def test_watchdog_ms_past_its_range_or_not_whole_is_a_usage_error(self):
        for value in ("60001", "-1", "1.5", "nan", "50ms", "", "0x10"):
            with self.subTest(value=value):
                self.assert_one_error(self.cli("trial", "十", "--pacing", "real-time", "--watchdog-ms", value,
                                               "--check"), 2, "--watchdog-ms")
        for value in ("0", "60000"):
            with self.subTest(value=value):
                self.assertEqual(self.cli("trial", "十", "--pacing", "real-time", "--watchdog-ms", value,
                                          "--check").returncode, 0)

    def test_watchdog_ms_is_an_integer_option_refusing_exponents_and_fractions(self):
        # cli.md: "an integer option takes decimal digits only (`2x`, `1.5`, `0x10`, `1e3` are errors)";
        # --watchdog-ms is "ms, 0..60000", "in whole milliseconds".
        for value in ("1e3", "1000.0", "1E1"):
            with self.subTest(value=value):
                self.assert_one_error(self.cli("trial", "十", "--pacing", "real-time", "--watchdog-ms", value,
                                               "--check"), 2, "--watchdog-ms", value)

    def test_watchdog_ms_with_lock_step_is_a_usage_error(self):
        # cli.md: "real-time pacing only (an error with lock-step)"; auto is lock-step on both devices.
        for device, pacing in (("simulated", "lock-step"), ("emulated-phantom", "lock-step"),
                               ("simulated", "auto"), ("emulated-phantom", "auto")):
            with self.subTest(device=device, pacing=pacing):
                d = self.fresh()
                result = run(["trial", "十", "--device", device, "--pacing", pacing, "--watchdog-ms", "100",
                              "--json", "w.json"], d)
                self.assert_one_error(result, 2, "--watchdog-ms")
                self.assertEqual(list(d.iterdir()), [])

    def test_watchdog_at_the_ends_of_its_range_is_recorded_in_seconds(self):
        for ms, seconds in (("60000", 60.0), ("0", 0.0)):
            with self.subTest(ms=ms):
                result, record, rows = self.trial("emulated-phantom", "--pacing", "real-time", "--watchdog-ms", ms,
                                                  "--max-duration", "0.05")
                self.assertEqual(result.returncode, 1, result.stderr)
                self.assertEqual(record["end_reason"], "time_limit")
                self.assertEqual(record["specification"]["trial"]["watchdog_s"], seconds)
                self.assertEqual(len(rows), 50)

    def test_realtime_enforce_runs_with_fifo_or_fails_in_one_line_writing_nothing(self):
        d = self.fresh()
        result = run(["trial", "十", "--device", "emulated-phantom", "--pacing", "real-time", "--realtime", "enforce",
                      "--max-duration", "0.05", "--json", "e.json"], d)
        if (d / "e.json").exists():
            record = json.loads((d / "e.json").read_text(encoding="utf-8"))
            self.assertTrue(record["loop"]["fifo_scheduling"], "enforce ran without SCHED_FIFO")
            self.assertEqual(record["specification"]["trial"]["realtime"], "enforce")
        else:
            self.assert_one_error(result, 1, "SCHED_FIFO")
            self.assertEqual(list(d.iterdir()), [])

    def signalled(self, first, then=None, pause_s=0.8, gap_s=0.3):
        """A real-time trial of 十 on the emulated Phantom sent `first` after `pause_s` (and `then` `gap_s`
        later): (result, record, rows)."""
        d = self.fresh()
        process = subprocess.Popen([CLI, "trial", "十", "--device", "emulated-phantom", "--pacing", "real-time",
                                    "--max-duration", "30", "--json", "s.json", "--csv", "s.csv"], cwd=d, env=ENV,
                                   stdin=subprocess.DEVNULL, stdout=subprocess.PIPE, stderr=subprocess.PIPE)
        try:
            time.sleep(pause_s)
            process.send_signal(first)
            if then is not None:
                time.sleep(gap_s)
                process.send_signal(then)
            out, err = process.communicate(timeout=30)
        finally:
            if process.poll() is None:
                process.kill()
                process.wait()
        result = subprocess.CompletedProcess(process.args, process.returncode, out, err)
        self.assertTrue((d / "s.json").exists(), err)
        record = json.loads((d / "s.json").read_text(encoding="utf-8"))
        return result, record, read_csv(d / "s.csv")

    def test_sigint_and_sigterm_end_the_emulated_trial_keeping_every_tick(self):
        for sig, status in ((signal.SIGINT, 130), (signal.SIGTERM, 143)):
            with self.subTest(signal=sig.name):
                result, record, rows = self.signalled(sig)
                self.assertEqual(result.returncode, status, result.stderr)
                self.assertEqual(record["end_reason"], "interrupted")
                self.assertTrue(record["aborted"])
                self.assertEqual(record["abort_reason"], f"stopped by {sig.name}")
                self.assertEqual(len([l for l in error_lines(result) if sig.name in l]), 1, error_lines(result))
                self.assertEqual(record["loop"]["ticks"], len(rows))
                self.assertGreater(len(rows), 100)
                self.assertPeriods(rows, 1000, len(rows))

    def test_sigstop_past_the_watchdog_ends_the_real_time_trial_on_sigcont(self):
        result, record, rows = self.signalled(signal.SIGSTOP, signal.SIGCONT, gap_s=0.3)
        self.assertEqual(result.returncode, 1, result.stderr)
        self.assertEqual(record["end_reason"], "watchdog")
        self.assertTrue(record["aborted"])
        self.assertGreaterEqual(record["loop"]["longest_stall_ms"], 50)
        self.assertEqual(record["loop"]["ticks"], len(rows))
        self.assertPeriods(rows, 1000, len(rows))

    # ---- devices that need hardware ----------------------------------------------------------------------
    def test_openhaptics_without_a_driver_fails_in_one_line_and_leaves_no_file(self):
        d = self.fresh()
        result = run(["trial", "十", "--device", "openhaptics", "--json", "o.json", "--csv", "o.csv",
                      "--svg", "o.svg"], d)
        line = self.assert_one_error(result, (1, 2), "OpenHaptics not found")
        self.assertIn("libHD.so", line)
        self.assertEqual(list(d.iterdir()), [])
        self.assertEqual(result.stdout, b"")

    def libhd(self, path):
        env = dict(ENV)
        env["CALLIGRAPHY_LIBHD"] = str(path)
        d = self.fresh()
        result = run(["trial", "十", "--device", "openhaptics", "--json", "o.json", "--csv", "o.csv"], d, env=env)
        files = sorted(p.name for p in d.iterdir())
        return result, files, env

    def test_libhd_that_is_a_folder_is_refused_naming_it_and_no_file_is_left(self):
        folder = self.fresh()
        result, files, env = self.libhd(folder)
        line = self.assert_one_error(result, 1, f"CALLIGRAPHY_LIBHD={folder} cannot be used",
                                     "a directory, not a shared library")
        self.assertEqual(files, [])
        listing = run(["devices", "--json"], self.tmp, env=env)
        self.assertEqual(listing.returncode, 0, listing.stderr)
        survey = json.loads(listing.stdout)
        self.assertTrue(any("a directory, not a shared library" in n for n in survey["notes"]), survey["notes"])
        self.assertEqual([x["name"] for x in survey["devices"]], ["simulated", "emulated-phantom"])
        self.assertNotIn("\n", line)

    def test_libhd_damaged_files_are_refused_naming_path_and_reason(self):
        d = self.fresh()
        empty = d / "empty.so"
        empty.write_bytes(b"")
        text = d / "text.so"
        text.write_text("not a library\n")
        cases = [(empty, "empty"), (text, None)]
        real = next((p for p in (Path("/lib/x86_64-linux-gnu/libm.so.6"), Path("/usr/lib/x86_64-linux-gnu/libm.so.6"),
                                 Path("/lib64/libm.so.6")) if p.exists()), None)
        if real is not None:
            cut = d / "cut.so"
            cut.write_bytes(real.read_bytes()[:8192])
            cases.append((cut, "truncated"))
        for path, reason in cases:
            with self.subTest(file=path.name):
                result, files, _ = self.libhd(path)
                needles = [f"CALLIGRAPHY_LIBHD={path}"] + ([reason] if reason else [])
                self.assert_one_error(result, 1, *needles)
                self.assertEqual(files, [])

    def test_phantoms_not_attached_fail_in_one_line_and_leave_no_file(self):
        for name in ("phantom-usb:1-2", "phantom-hid:/dev/hidraw99"):
            with self.subTest(device=name):
                d = self.fresh()
                result = run(["trial", "十", "--device", name, "--json", "p.json", "--csv", "p.csv"], d)
                self.assert_one_error(result, (1, 2), name)
                self.assertEqual(list(d.iterdir()), [])

    def test_person_devices_refuse_simulated_writing_before_they_are_looked_for(self):
        # cli.md "devices": checked against the kind first, a usage error whether or not the device can be used.
        for device, extra, option in (("openhaptics", ["--writer", "simulated"], "--writer"),
                                      ("openhaptics", ["--pacing", "lock-step"], "--pacing"),
                                      ("phantom-usb:1-2", ["--writer-profile", "skilled"], "--writer-profile"),
                                      ("phantom-hid:/dev/hidraw0", ["--writer-param", "bias_offset_m=0.001"],
                                       "--writer-param")):
            with self.subTest(device=device, option=option):
                d = self.fresh()
                result = run(["trial", "十", "--device", device, *extra, "--json", "x.json"], d)
                self.assert_one_error(result, 2, option)
                self.assertEqual(list(d.iterdir()), [])
        for device in ("simulated", "emulated-phantom"):
            with self.subTest(device=device, writer="person"):
                self.assert_one_error(self.cli("trial", "十", "--device", device, "--writer", "person"), 2,
                                      f"a person cannot hold the device '{device}'")

    def test_device_name_in_other_spellings_is_a_usage_error_listing_the_devices(self):
        for name, shown in (("Emulated-Phantom", "Emulated-Phantom"), ("EMULATED-PHANTOM", "EMULATED-PHANTOM"),
                            ("emulated_phantom", "emulated_phantom"), ("emulatedphantom", "emulatedphantom"),
                            ("emulated-phantom ", "emulated-phantom "), (" simulated", " simulated"),
                            ("simulated\n", "simulated\\n"), ("simulated\x1b[2J", "simulated\\x1b[2J"),
                            ("Simulated", "Simulated")):
            with self.subTest(name=name):
                d = self.fresh()
                result = run(["trial", "十", "--device", name, "--json", "n.json"], d)
                line = self.assert_one_error(result, 2, shown, "simulated", "emulated-phantom")
                self.assertNotIn("\x1b", line)
                self.assertEqual(list(d.iterdir()), [])
        self.assert_one_error(self.cli("trial", "十", "--device", "", "--check"), 2, "--device")
        self.assert_one_error(self.cli("trial", "十", "--device", "simulated", "--device", "emulated-phantom",
                                       "--check"), 2, "--device")
        self.assertEqual(self.cli("trial", "十", "--device=emulated-phantom", "--check").returncode, 0)


@needs_python
class Round30DPython(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        if not CLI:
            raise unittest.SkipTest("CALLIGRAPHY_CLI not set")
        cls.tmp = Path(tempfile.mkdtemp(prefix="round30d-py-"))
        cls.cli_survey = json.loads(run_ok(["devices", "--json"], cls.tmp).stdout)

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.tmp, ignore_errors=True)

    def test_python_registry_holds_the_simulated_device_as_the_command_lists_it(self):
        survey = cg.list_devices()
        self.assertEqual([d.name for d in survey.devices], ["simulated"])
        self.assertFalse(survey.any_hardware)
        mine = survey.devices[0]
        theirs = next(d for d in self.cli_survey["devices"] if d["name"] == "simulated")
        self.assertEqual((mine.backend, mine.hardware, mine.moved_by_simulated_hand, mine.needs_calibration),
                         (theirs["backend"], theirs["hardware"], theirs["moved_by_simulated_hand"],
                          theirs["needs_calibration"]))
        got = mine.info.to_dict()
        got["workspace_size_m"] = list(got["workspace_size_m"])
        self.assertEqual(got, theirs["info"])

    def test_python_emulated_phantom_is_not_found_naming_the_devices(self):
        with self.assertRaises(cg.DeviceNotFound) as caught:
            cg.run_trial("十", device="emulated-phantom")
        self.assertIsInstance(caught.exception, LookupError)
        self.assertIn("simulated", str(caught.exception))

    def test_python_openhaptics_with_a_folder_for_libhd_is_unavailable_naming_it(self):
        before = os.environ.get("CALLIGRAPHY_LIBHD")
        os.environ["CALLIGRAPHY_LIBHD"] = str(self.tmp)
        try:
            with self.assertRaises(cg.DeviceUnavailable) as caught:
                cg.run_trial("十", device="openhaptics")
        finally:
            if before is None:
                del os.environ["CALLIGRAPHY_LIBHD"]
            else:
                os.environ["CALLIGRAPHY_LIBHD"] = before
        self.assertIn(str(self.tmp), str(caught.exception))
        self.assertIn("a directory, not a shared library", str(caught.exception))

    def test_python_real_time_trial_keeps_its_ticks_one_period_apart(self):
        r = cg.run_trial("十", pacing="real-time", rate_hz=500.0, max_duration_s=0.1)
        m = r.metrics
        self.assertEqual(m["end_reason"], "time_limit")
        self.assertEqual(m["device"], "simulated")
        self.assertEqual(m["specification"]["trial"]["pacing"], "real-time")
        self.assertEqual(m["specification"]["trial"]["watchdog_s"], 0.05)
        self.assertLessEqual(LOOP_KEYS, set(m["loop"]))
        self.assertEqual(m["loop"]["ticks"], 50)
        t = list(r.time_s)
        self.assertEqual(len(t), 50)
        for k, tk in enumerate(t):
            self.assertAlmostEqual(tk, k / 500.0, delta=1e-9)
        self.assertLessEqual(max(norm(f) for f in r.force_n), DESKTOP["max_force_n"])

    def test_python_watchdog_refused_in_lock_step_and_off_its_grid(self):
        for kwargs in ({"pacing": "lock-step", "watchdog_s": 0.1},
                       {"pacing": "real-time", "watchdog_s": 0.0105, "max_duration_s": 0.01},
                       {"pacing": "real-time", "watchdog_s": 60.001, "max_duration_s": 0.01},
                       {"pacing": "real-time", "watchdog_s": -0.001, "max_duration_s": 0.01},
                       {"pacing": "real-time", "watchdog_s": float("nan"), "max_duration_s": 0.01},
                       {"pacing": "lockstep"}, {"pacing": "real-time", "rate_hz": 10001.0, "max_duration_s": 0.01}):
            with self.subTest(**{k: str(v) for k, v in kwargs.items()}):
                with self.assertRaises(cg.InvalidArgument):
                    cg.run_trial("十", **kwargs)

    def test_python_auto_paced_simulated_trial_refuses_a_watchdog_as_the_command_does(self):
        # python.md: watchdog_s "refused in lock-step"; "the simulated device runs lock-step unless
        # pacing="real-time"". `trial 十 --watchdog-ms 100` (auto) is a usage error; a record with it is refused.
        try:
            r = cg.run_trial("十", watchdog_s=0.1)
        except cg.InvalidArgument:
            return
        try:
            cg.check_trial_record(r.metrics)
            verdict = "and its record is accepted"
        except cg.Error as e:
            verdict = f"and writes a record check_trial_record refuses: {e}"
        self.fail(f"run_trial ran {r.metrics['specification']['trial']['pacing']} with watchdog_s 0.1 {verdict}")

    def test_python_run_trial_gives_the_command_s_keys_and_figures(self):
        r = cg.run_trial("十", device="simulated", pacing="auto")
        out = run_ok(["trial", "十", "--json", "-"], self.tmp)
        record = json.loads(out.stdout)
        self.assertEqual(set(r.metrics), set(record))
        for key in ("device", "end_reason", "strokes_completed", "trial_time_s", "max_force_n", "seed"):
            self.assertEqual(r.metrics[key], record[key], key)


if __name__ == "__main__":
    unittest.main()
