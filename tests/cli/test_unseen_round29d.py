#!/usr/bin/env python3
"""Round 29D: the trainer window as a learner with a mouse meets it. From the docs alone (docs/trainer.md,
docs/cli.md `train`, "Conventions", "Exit statuses" and `report`, docs/devices.md "The pointer as a device",
docs/experiments.md "Trial records", "Trace files", the log's events and the tidy tables, `calligraphy train
--help`, Python's `help(calligraphy.Scene)` for the medians).

Without a display: `train`'s options at and past their ranges (`--window`, `--exit-after`, the miss counts,
`--watchdog-ms`, `--subject`), an unknown device, `--quiz` with guidance options (refused before any file is
read), outputs refused before the window opens, a character the library lacks, and the display that cannot be
opened (exit 1, no session folder). A value at its bound must pass the parser and reach the display (exit 1,
not 2).

With a window (four in all, 800x480, under an Xvfb of the file's own, the pointer moved with xdotool along the
data's medians mapped to the window by the printed box, `CALLIGRAPHY_PRINT_BOXES`):
1. 一 written along its median on `--device mouse`: exit 0, nothing on standard output, every standard error
   line the command's own, the learner's panel (`CALLIGRAPHY_PANEL_TEXT`) saying what to do with a mouse and
   naming no state, tick, element or force, the feedback "good" in mm, the screenshot a valid PNG of the
   window's size, the session folder read back by `calligraphy report --csv`;
2. 十 with `--hint-after-misses 1 --assist-after-misses 2`: stroke 1 lifted twice at 40 % (too short), then
   stroke 2 written: stroke 1 credited as assisted in the record, the panel and the tables;
3. 十 `--engineer --no-demo`, SIGTERM with the pen down mid-stroke: exit 143, the attempt kept with every
   servo tick, the log's `trial_interrupted` and `session_stopped`, the engineer's panel, no demonstration;
4. 一 `--quiz`, written backwards (the miss printed as it happens), then the X server killed: exit 4, the
   display named, the attempt kept as a quiz with `stopped by display_lost`.

CALLIGRAPHY_CLI names the program; PYTHONPATH the built Python package (for the medians).
CALLIGRAPHY_SANITIZED=1 takes five refusal cases (no window).
"""
import csv
import json
import os
import re
import shutil
import signal
import struct
import subprocess
import tempfile
import time
import unittest
import zlib
from pathlib import Path

from outsider import CLI, ENV, OneErrorLine, error_lines, run, sanitized_subset, start_own_x_server

try:
    import numpy as np
    import calligraphy as cg
except ImportError:  # the window cases need the medians; the refusals do not
    np = cg = None

try:
    import h5py
except ImportError:
    h5py = None

try:
    from PIL import Image
except ImportError:
    Image = None

load_tests = sanitized_subset({"test_window_size_outside_800x480_to_8192x8192_is_one_usage_error",
                               "test_exit_after_outside_0_to_86400_is_one_usage_error",
                               "test_quiz_with_a_guidance_option_is_refused_before_any_file_is_read",
                               "test_screenshot_in_a_missing_folder_is_refused_naming_the_option",
                               "test_no_display_exits_1_and_leaves_no_session_folder"})

HAVE_X = shutil.which("Xvfb") is not None and shutil.which("xdotool") is not None
WINDOW = (800, 480)
MOUSE_LINE = ("Hold the left mouse button and draw each stroke; a mouse cannot push back, so nothing is felt.")
ENGINEER_WORDS = re.compile(r"\b(SS|AS|CS|WS|tick|ticks|element|force|guidance on)\b")
STEP_S = 0.02          # one pointer move each 20 ms: 30 steps over a ~48 mm stroke, about 80 mm/s


def display_free(result):
    """True when the run got past the parser and failed only at opening the display (exit 1, no option named)."""
    return result.returncode == 1 and not any("--" in line for line in error_lines(result))


# ------------------------------------------------------------------------------------------------ no window
class Refusals(unittest.TestCase, OneErrorLine):
    """`train`'s options checked before any window opens (docs/cli.md `train`: "2 for a usage error (checked
    before any window opens)"), run without a display."""

    def setUp(self):
        self.tmp = Path(tempfile.mkdtemp(prefix="round29d-"))
        self.addCleanup(shutil.rmtree, self.tmp, True)

    def train(self, *args):
        return run(["train", "十", "--device", "mouse", *args], self.tmp)

    def assert_nothing_made(self):
        self.assertEqual(sorted(p.name for p in self.tmp.iterdir()), [])

    def test_window_size_outside_800x480_to_8192x8192_is_one_usage_error(self):
        # docs/cli.md: `--window` WxH "(at least 800x480, at most 8192x8192)".
        for value in ("0x0", "99999x99999", "799x480", "800x479", "8193x480", "800x8193", "-800x480",
                      "800x480x2", "800x", "x480", "1e3x480", "800.0x480", "800X480 ", "nanxnan"):
            with self.subTest(value=value):
                self.assert_one_error(self.train("--window", value), 2, "--window")
                self.assert_nothing_made()

    def test_window_sizes_at_their_bounds_pass_the_parser_and_reach_the_display(self):
        for value in ("800x480", "8192x8192", "8192x480", "800x8192"):
            with self.subTest(value=value):
                result = self.train("--window", value)
                self.assertTrue(display_free(result), (result.returncode, error_lines(result)))

    def test_exit_after_outside_0_to_86400_is_one_usage_error(self):
        # docs/cli.md: `--exit-after` "s, (0, 86400]"; "a real number must be finite (nan, inf are errors)".
        for value in ("0", "-1", "-0", "0.0", "nan", "inf", "-inf", "86400.001", "1e999", "", "5s", "1,5"):
            with self.subTest(value=value):
                self.assert_one_error(self.train("--exit-after", value), 2, "--exit-after")

    def test_exit_after_at_86400_and_a_millisecond_pass_the_parser(self):
        for value in ("86400", "0.001", "1e-3"):
            with self.subTest(value=value):
                result = self.train("--exit-after", value)
                self.assertTrue(display_free(result), (result.returncode, error_lines(result)))

    def test_miss_counts_outside_0_to_1000_are_one_usage_error_naming_the_option(self):
        # docs/cli.md: `--hint-after-misses`, `--assist-after-misses` "N in 0..1000"; integers "decimal
        # digits only (2x, 1.5, 0x10, 1e3 are errors)".
        for option in ("--hint-after-misses", "--assist-after-misses"):
            for value in ("-1", "1001", "1.5", "1e3", "0x10", "2x", "99999999999999999999"):
                with self.subTest(option=option, value=value):
                    self.assert_one_error(self.train(option, value), 2, option)

    def test_miss_counts_at_0_and_1000_pass_the_parser(self):
        for option in ("--hint-after-misses", "--assist-after-misses"):
            for value in ("0", "1000"):
                with self.subTest(option=option, value=value):
                    result = self.train(option, value)
                    self.assertTrue(display_free(result), (result.returncode, error_lines(result)))

    def test_watchdog_past_60000_ms_is_one_usage_error(self):
        for value in ("60001", "-1", "50.5"):
            with self.subTest(value=value):
                self.assert_one_error(self.train("--watchdog-ms", value), 2, "--watchdog-ms")

    def test_subject_outside_its_alphabet_or_past_64_is_one_usage_error(self):
        # docs/cli.md: `--subject` "A-Z a-z 0-9 _ -, at most 64".
        for value in ("a b", "../x", "s\u00e9", "a" * 65):
            with self.subTest(value=value):
                self.assert_one_error(self.train("--subject", value, "--session", "S"), 2, "--subject")
                self.assert_nothing_made()

    def test_unknown_device_is_a_usage_error_naming_it(self):
        # docs/cli.md "Exit statuses": 2 for "an unknown device".
        self.assert_one_error(run(["train", "十", "--device", "nosuch"], self.tmp), 2, "nosuch")

    def test_quiz_with_a_guidance_option_is_refused_before_any_file_is_read(self):
        # docs/cli.md `--quiz`: "--guidance-mode other than fixed, --teacher or --guidance-gain with it is a
        # usage error"; "combinations of options before any file is read": the teacher need not exist.
        for extra in (["--guidance-mode", "fading"], ["--guidance-mode", "replay", "--teacher", "none.json"],
                      ["--teacher", "none.json"], ["--guidance-gain", "0.5"]):
            with self.subTest(extra=extra):
                line = self.assert_one_error(self.train("--quiz", *extra), 2, "--quiz")
                self.assertTrue(any(o in line for o in extra if o.startswith("--")), line)
                self.assertNotIn("none.json: ", line)   # not read

    def test_no_display_exits_1_and_leaves_no_session_folder(self):
        # docs/cli.md `train`: "The --session folder is made once the window is open: a display that cannot
        # be opened (exit 1) leaves none."
        self.assert_one_error(self.train("--session", "S", "--screenshot", "S/shot.png"), 1)
        self.assert_nothing_made()

    def test_quiz_screenshots_folder_missing_is_refused_before_the_window_naming_it(self):
        # docs/cli.md `--quiz-screenshots`: "DIR must exist and be writable: checked before the window opens,
        # exit 1 naming it".
        self.assert_one_error(self.train("--quiz", "--quiz-screenshots", "shots"), 1, "--quiz-screenshots",
                              "shots")

    def test_screenshot_in_a_missing_folder_is_refused_naming_the_option(self):
        # docs/cli.md "Checked before anything runs", "Output folders": exit 1 naming the option and path.
        self.assert_one_error(self.train("--screenshot", "nowhere/s.png"), 1, "--screenshot", "nowhere")

    def test_screenshot_and_record_the_same_file_is_refused_naming_both(self):
        # docs/cli.md "Output identity": "refused with exit status 2 naming both options and paths".
        self.assert_one_error(self.train("--screenshot", "x.out", "--record", "./x.out"), 2, "--screenshot",
                              "--record")
        self.assert_nothing_made()

    def test_a_character_the_library_lacks_is_a_usage_error_with_its_code_point(self):
        self.assert_one_error(run(["train", "\u3042", "--device", "mouse"], self.tmp), 2, "U+3042")


# --------------------------------------------------------------------------------------------- the windows
def png_size(path):
    """The (width, height) of a PNG whose every chunk's CRC holds and whose image data decompresses to the
    rows its header announces (8-bit RGB or RGBA, no interlace); AssertionError otherwise."""
    data = Path(path).read_bytes()
    assert data[:8] == b"\x89PNG\r\n\x1a\n", "not a PNG signature"
    pos, idat, header = 8, b"", None
    while pos < len(data):
        length, kind = struct.unpack(">I4s", data[pos:pos + 8])
        body = data[pos + 8:pos + 8 + length]
        crc, = struct.unpack(">I", data[pos + 8 + length:pos + 12 + length])
        assert zlib.crc32(kind + body) & 0xFFFFFFFF == crc, f"bad CRC in {kind!r}"
        if kind == b"IHDR":
            header = struct.unpack(">IIBBBBB", body)
        elif kind == b"IDAT":
            idat += body
        pos += 12 + length
        if kind == b"IEND":
            break
    assert header is not None, "no IHDR"
    width, height, depth, colour, _, _, interlace = header
    assert depth == 8 and colour in (2, 6) and interlace == 0, header
    channels = 3 if colour == 2 else 4
    assert len(zlib.decompress(idat)) == height * (1 + width * channels), "image data of another size"
    return width, height


class WindowRun:
    """One `calligraphy train` in a window on `display`, standard output and error kept in files of `folder`,
    read while it runs."""

    def __init__(self, folder, display, args):
        self.folder, self.display = Path(folder), display
        self.out, self.err = self.folder / "stdout.txt", self.folder / "stderr.txt"
        self.panel = self.folder / "panel.txt"
        env = dict(ENV, DISPLAY=display, CALLIGRAPHY_PRINT_BOXES="1", CALLIGRAPHY_PANEL_TEXT=str(self.panel))
        with open(self.out, "wb") as out, open(self.err, "wb") as err:
            self.process = subprocess.Popen([CLI, "train", *args], cwd=self.folder, env=env,
                                            stdin=subprocess.DEVNULL, stdout=out, stderr=err)
        self.boxes = {}
        self.window = None

    def stderr(self):
        return self.err.read_text(encoding="utf-8", errors="replace")

    def wait_for(self, pattern, timeout=20.0):
        """The first match of `pattern` in standard error once it appears; AssertionError after `timeout`."""
        end = time.monotonic() + timeout
        while True:
            found = re.search(pattern, self.stderr())
            if found:
                return found
            if self.process.poll() is not None or time.monotonic() > end:
                raise AssertionError(f"no {pattern!r} on standard error (exit {self.process.poll()}):\n"
                                     + self.stderr())
            time.sleep(0.05)

    def open(self):
        """Waits for the character boxes and the window; returns self."""
        self.wait_for(r"box 0 ")
        for m in re.finditer(r"box (\d+) (\S+) x=(\d+) y=(\d+) size=(\d+)", self.stderr()):
            self.boxes[int(m.group(1))] = tuple(int(m.group(k)) for k in (3, 4, 5))
        found = subprocess.run(["xdotool", "search", "--sync", "--onlyvisible", "--name", "calligraphy"],
                               env=dict(ENV, DISPLAY=self.display), capture_output=True, timeout=20, text=True)
        self.window = found.stdout.split()[0]
        time.sleep(0.3)   # the trial's first frames
        return self

    def pixels(self, character, stroke, box=0, fraction=1.0, backwards=False, n=30):
        """`n` window pixels along the data's median of `stroke` (0-based) of `character`, its first
        `fraction` (from its end when `backwards`): data (y up, 900 at the top) to pixels as docs/trainer.md
        gives, (box.x + x / 1024 size, box.y + (900 - y) / 1024 size)."""
        placed = cg.Scene(character).characters[0]
        data = placed.placement.to_data(np.asarray(placed.strokes[stroke].median_m))
        if backwards:
            data = data[::-1]
        bx, by, size = self.boxes[box]
        p = np.column_stack([bx + data[:, 0] / 1024 * size, by + (900 - data[:, 1]) / 1024 * size])
        s = np.r_[0, np.cumsum(np.hypot(*np.diff(p, axis=0).T))]
        t = np.linspace(0, s[-1] * fraction, n)
        return list(zip(np.interp(t, s, p[:, 0]).round().astype(int), np.interp(t, s, p[:, 1]).round().astype(int)))

    def xdo(self, *commands):
        subprocess.run(["xdotool", *map(str, commands)], env=dict(ENV, DISPLAY=self.display), timeout=30,
                       check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)

    def draw(self, points, lift=True, pressed=False):
        """The button pressed at the first point (already held with `pressed`), the pointer carried through
        the rest one each STEP_S, then (with `lift`) released; a pause after."""
        commands = ["mousemove", "--window", self.window, *points[0], "sleep", 0.1]
        if not pressed:
            commands += ["mousedown", 1]
        for x, y in points[1:]:
            commands += ["sleep", STEP_S, "mousemove", "--window", self.window, x, y]
        if lift:
            commands += ["sleep", 0.05, "mouseup", 1, "sleep", 0.3]
        self.xdo(*commands)

    def finish(self, timeout=30):
        try:
            return self.process.wait(timeout)
        except subprocess.TimeoutExpired:
            self.process.kill()
            self.process.wait()
            raise

    def kill(self):
        if self.process.poll() is None:
            self.process.kill()
            self.process.wait()


def one_session(root):
    """The one session folder under `root` (docs/trainer.md: DIR/SUBJECT/train-SUBJECT-...)."""
    found = sorted(Path(root).glob("anonymous/train-*"))
    assert len(found) == 1, found
    return found[0]


def log_events(session):
    return [json.loads(line) for line in (session / "log.jsonl").read_text(encoding="utf-8").splitlines()
            if line.strip()]


def report_tables(folder, session_root):
    """`calligraphy report ROOT --csv TABLES`: (trials rows, strokes rows)."""
    tables = Path(folder) / "tables"
    tables.mkdir()
    result = run(["report", session_root, "--csv", tables], folder)
    assert result.returncode == 0, result.stderr.decode("utf-8", "replace")
    def read(name):
        with open(tables / name, encoding="utf-8", newline="") as f:
            return list(csv.DictReader(f))
    return read("trials.csv"), read("strokes.csv")


class WindowCase(unittest.TestCase):
    """A class that runs one window in its setUpClass on a shared X server of this file's own."""
    server = None

    @classmethod
    def x_server(cls):
        if WindowCase.server is None:
            started = start_own_x_server("1024x768x24")
            if started is None:
                raise unittest.SkipTest("no X server starts")
            WindowCase.server = started
        return WindowCase.server[1]

    @classmethod
    def make_folder(cls):
        if cg is None:
            raise unittest.SkipTest("numpy and the calligraphy Python package (PYTHONPATH) are needed")
        cls.tmp = Path(tempfile.mkdtemp(prefix="round29d-"))
        cls.addClassCleanup(shutil.rmtree, cls.tmp, True)
        return cls.tmp


def tearDownModule():
    if WindowCase.server is not None:
        WindowCase.server[0].kill()
        WindowCase.server[0].wait()


@unittest.skipUnless(HAVE_X, "Xvfb and xdotool are needed")
class LearnerWritesYi(WindowCase):
    """一 written along its median with the mouse, `--exit-after` as the net: the run ends once the character
    had its trial."""

    @classmethod
    def setUpClass(cls):
        d = cls.make_folder()
        w = WindowRun(d, cls.x_server(), ["一", "--device", "mouse", "--window", "%dx%d" % WINDOW,
                                          "--exit-after", "12", "--session", "S", "--screenshot", "shot.png"])
        started = time.monotonic()
        try:
            w.open()
            w.draw(w.pixels("一", 0))
            cls.status = w.finish()
        finally:
            w.kill()
        cls.elapsed = time.monotonic() - started
        cls.w = w
        cls.stdout = w.out.read_bytes()
        cls.err = w.stderr()
        cls.trial_lines = [l for l in cls.err.splitlines() if re.search(r"trial 1 一:", l)]

    def test_the_stroke_along_its_median_completes_and_the_run_exits_0_before_its_limit(self):
        # docs/cli.md `--exit-after`: "quit after this long, or once every character had its trial".
        self.assertEqual(self.status, 0, self.err)
        self.assertLess(self.elapsed, 11.0)
        self.assertEqual(len(self.trial_lines), 1, self.err)
        self.assertIn("completed", self.trial_lines[0])
        self.assertIn("1 of 1 stroke", self.trial_lines[0])

    def test_standard_output_holds_nothing_and_standard_error_only_the_commands_lines(self):
        # docs/cli.md `train`: "Prints nothing on standard output"; "The library's log ... one line each in
        # the form of its error lines: calligraphy trial: warning: ...".
        self.assertEqual(self.stdout, b"")
        for line in self.err.splitlines():
            with self.subTest(line=line):
                self.assertTrue(line.startswith("calligraphy train: ") or line.startswith("box "), line)
                self.assertNotRegex(line, r"\[(info|warning|error|debug|trace)\]|^\[\d{4}-")
                self.assertNotIn(": info:", line)   # info lines only with --verbose

    def test_no_demonstration_in_an_unattended_run(self):
        # docs/trainer.md: the demonstration is shown "not in an unattended run (--exit-after)".
        self.assertNotIn("demonstrating", self.err)

    def test_the_learners_panel_says_what_to_do_with_a_mouse_and_names_no_engineers_term(self):
        text = self.w.panel.read_text(encoding="utf-8")
        self.assertIn(MOUSE_LINE, text)
        self.assertIn("一", text)
        self.assertNotRegex(text, ENGINEER_WORDS)

    def test_the_feedback_says_stroke_1_good_in_mm_and_the_summary_done(self):
        # docs/trainer.md: "Stroke 2: good, 1.2 mm off on average" at most 1.5 mm; "Done: 5 of 5 strokes in
        # order"; "Every stroke written" at the end.
        text = self.w.panel.read_text(encoding="utf-8")
        m = re.search(r"Stroke 1: good, (\d+\.\d) mm off on average", text)
        self.assertIsNotNone(m, text)
        self.assertLessEqual(float(m.group(1)), 1.5)
        self.assertIn("Done: 1 of 1 stroke", text)
        self.assertIn("Every stroke written", text)

    def test_the_screenshot_is_a_valid_png_of_the_windows_size(self):
        self.assertEqual(png_size(self.tmp / "shot.png"), WINDOW)

    def test_the_screenshot_has_the_red_start_circle_of_5_mm_at_the_strokes_start(self):
        # docs/trainer.md: the hint "a red ellipse (radius: the start neighbourhood, 5 mm) at the active
        # stroke's start; at every stroke's start once the trial ended"; 1024 data units are 60 mm.
        if Image is None:
            self.skipTest("PIL is needed to read the picture")
        with Image.open(self.tmp / "shot.png") as im:
            a = np.asarray(im.convert("RGB")).astype(int)
        bx, by, size = self.w.boxes[0]
        paper = a[:, :bx + size + 20]
        red = (paper[:, :, 0] > 180) & (paper[:, :, 1] < 90) & (paper[:, :, 2] < 90)
        ys, xs = np.nonzero(red)
        self.assertGreater(len(xs), 20, "no red on the paper")
        x0, y0 = self.w.pixels("一", 0, n=2)[0]
        radius = 0.005 / 0.06 * size
        d = np.hypot(xs - x0, ys - y0)
        self.assertLessEqual(d.max(), radius + 6, "red away from the stroke's start")
        self.assertGreaterEqual(d.max(), radius - 6, "the red mark is smaller than the 5 mm neighbourhood")

    def test_the_session_folder_holds_the_trial_as_docs_name_it(self):
        # docs/trainer.md: trials/NNN-test-CONDITION-rR-UXXXX.{json,trace.h5,svg}, condition vision on a
        # device without force output; session.json a protocol named train; the log's trial_saved.
        session = one_session(self.tmp / "S")
        names = sorted(p.name for p in (session / "trials").iterdir() if p.is_file())
        self.assertEqual(names, ["001-test-vision-r1-U4E00." + e for e in ("json", "svg", "trace.h5")])
        self.assertEqual(list((session / "trials" / "attempts").glob("*")) if (session / "trials" / "attempts")
                         .exists() else [], [])
        manifest = json.loads((session / "session.json").read_text(encoding="utf-8"))
        self.assertIn('"train"', json.dumps(manifest.get("protocol")))
        self.assertEqual([e["event"] for e in log_events(session) if e["event"].startswith("trial_")],
                         ["trial_saved"])
        record = json.loads((session / "trials" / names[0]).read_text(encoding="utf-8"))
        self.assertEqual((record["condition"], record["end_reason"]), ("vision", "completed"))

    def test_the_saved_trace_has_every_tick_and_the_mouse_pen_only_at_minus_1_or_plus_5_mm(self):
        # docs/devices.md `mouse`: "the left button held down puts the pen on the paper (z = -1 mm), released
        # lifts it (z = +5 mm)"; docs/trainer.md: every tick kept; the trace's z in m = integer / 10^7.
        if h5py is None:
            self.skipTest("h5py is needed")
        session = one_session(self.tmp / "S")
        record = json.loads((session / "trials" / "001-test-vision-r1-U4E00.json").read_text(encoding="utf-8"))
        ticks = re.search(r"servo loop: (\d+) ticks", self.err)
        self.assertIsNotNone(ticks, self.err)
        with h5py.File(session / "trials" / record["files"]["trace"], "r") as f:
            z = np.asarray(f["z"][()], dtype=float)
            z_m = z / 10 ** int(f["z"].attrs.get("decimals", 7)) if "decimals" in f["z"].attrs else z
        self.assertEqual(len(z_m), int(ticks.group(1)))
        self.assertEqual(sorted(set(np.round(z_m * 1000, 4))), [-1.0, 5.0])

    def test_report_reads_the_session_back_with_the_deviation_stderr_printed(self):
        trials, strokes = report_tables(self.tmp, self.tmp / "S")
        self.assertEqual(len(trials), 1)
        row = trials[0]
        self.assertEqual((row["condition"], row["end_reason"], row["characters"], row["strokes_accepted"],
                          row["completed_in_order"], row["writer"]), ("vision", "completed", "一", "1", "TRUE",
                                                                      "person"))
        m = re.search(r"mean deviation (\d+\.\d+) mm", self.trial_lines[0])
        self.assertIsNotNone(m, self.trial_lines[0])
        self.assertAlmostEqual(float(row["mean_deviation_m"]) * 1000, float(m.group(1)),
                               delta=0.5 * 10 ** -len(m.group(1).split(".")[1]) + 1e-9)
        self.assertEqual([(s["stroke"], s["written"], s["assisted"]) for s in strokes], [("1", "TRUE", "FALSE")])


@unittest.skipUnless(HAVE_X, "Xvfb and xdotool are needed")
class MissesOnShi(WindowCase):
    """十 with `--hint-after-misses 1 --assist-after-misses 2`: stroke 1 begun at its start and lifted at 40 %
    (a miss), begun again and carried at 40 % off the paper onto the panel with the button held (docs/trainer.md:
    "leaving it with the button held lifts the pen, which ends the attempt as a lift there does": the second
    miss, which credits stroke 1), then, the button still held, the pointer brought back onto the paper at
    stroke 2's start ("coming back with the button still held is a new pen-down where the pointer re-enters")
    and stroke 2 written along its median."""

    @classmethod
    def setUpClass(cls):
        d = cls.make_folder()
        w = WindowRun(d, cls.x_server(), ["十", "--device", "mouse", "--window", "%dx%d" % WINDOW,
                                          "--exit-after", "15", "--hint-after-misses", "1",
                                          "--assist-after-misses", "2", "--session", "S",
                                          "--screenshot", "shot.png"])
        try:
            w.open()
            w.draw(w.pixels("十", 0, fraction=0.4, n=12))
            w.draw(w.pixels("十", 0, fraction=0.4, n=12), lift=False)
            off_paper = (WINDOW[0] - 10, WINDOW[1] - 10)     # the panel's corner: the window's right part
            w.xdo("sleep", STEP_S, "mousemove", "--window", w.window, *off_paper, "sleep", 0.4)
            w.draw(w.pixels("十", 1), pressed=True)
            cls.status = w.finish()
        finally:
            w.kill()
        cls.w, cls.err = w, w.stderr()
        cls.session = one_session(d / "S")
        saved = sorted((cls.session / "trials").glob("*.json"))
        cls.record = json.loads(saved[0].read_text(encoding="utf-8")) if len(saved) == 1 else None

    def test_the_trial_completes_with_stroke_1_credited_as_assisted(self):
        # docs/trainer.md "Hints and assisted strokes": after N misses the stroke is credited; the record has
        # strokes_assisted 1 and stroke 1 assisted, not written.
        self.assertEqual(self.status, 0, self.err)
        self.assertIsNotNone(self.record, self.err)
        self.assertEqual(self.record["end_reason"], "completed")
        self.assertEqual(self.record["strokes_assisted"], 1)
        self.assertEqual([(s["assisted"], s["completed"]) for s in self.record["per_stroke"]],
                         [(True, False), (False, True)])
        self.assertEqual([s["attempts"] for s in self.record["per_stroke"]], [2, 1])

    def test_the_panel_says_the_stroke_was_shown_and_counted_as_assisted(self):
        # docs/trainer.md, the summary: "Done: ... (and "1 shown and counted as assisted" when the trial
        # credited a stroke so)".
        text = self.w.panel.read_text(encoding="utf-8")
        self.assertIn("Done:", text)
        self.assertIn("1 shown and counted as assisted", text)
        self.assertIn("Stroke 2:", text)
        self.assertNotRegex(text, ENGINEER_WORDS)

    def test_the_tables_mark_stroke_1_assisted_and_not_written(self):
        trials, strokes = report_tables(self.tmp, self.tmp / "S")
        self.assertEqual([(t["strokes_assisted"], t["end_reason"]) for t in trials], [("1", "completed")])
        self.assertEqual([(s["stroke"], s["written"], s["assisted"]) for s in strokes],
                         [("1", "FALSE", "TRUE"), ("2", "TRUE", "FALSE")])


@unittest.skipUnless(HAVE_X, "Xvfb and xdotool are needed")
class EngineerStoppedBySigterm(WindowCase):
    """十 `--engineer --no-demo` (no `--exit-after`: ended by SIGTERM), the pen put down at stroke 1's start as
    soon as the window is up and carried half of it, SIGTERM with the button held."""

    @classmethod
    def setUpClass(cls):
        d = cls.make_folder()
        w = WindowRun(d, cls.x_server(), ["十", "--device", "mouse", "--window", "%dx%d" % WINDOW, "--engineer",
                                          "--no-demo", "--session", "S", "--screenshot", "shot.png"])
        try:
            w.open()
            w.draw(w.pixels("十", 0, fraction=0.5, n=15), lift=False)
            time.sleep(0.2)
            w.process.send_signal(signal.SIGTERM)
            cls.status = w.finish(20)
        finally:
            w.kill()
            try:
                w.xdo("mouseup", 1)
            except subprocess.SubprocessError:
                pass
        cls.w, cls.err, cls.stdout = w, w.stderr(), w.out.read_bytes()
        cls.session = one_session(d / "S")
        cls.attempts = sorted((cls.session / "trials" / "attempts").glob("*.json"))

    def test_sigterm_exits_143_and_keeps_the_trial_as_an_interrupted_attempt(self):
        # docs/cli.md `train`, "Ending early": stop signal: abort_reason "stopped by SIGTERM", 128 + N.
        self.assertEqual(self.status, 143, self.err)
        self.assertEqual(self.stdout, b"")
        self.assertEqual([p.name for p in self.attempts], ["001-test-vision-r1-U5341.attempt-1.json"])
        record = json.loads(self.attempts[0].read_text(encoding="utf-8"))
        self.assertEqual((record["end_reason"], record["abort_reason"]), ("interrupted", "stopped by SIGTERM"))
        self.assertEqual(list((self.session / "trials").glob("*.json")), [])

    def test_the_trial_line_on_stderr_names_sigterm_and_the_attempt(self):
        # docs/cli.md `train`: "one line per trial, saying how it ended and what stopped it, ... and what was
        # kept of it".
        lines = [l for l in self.err.splitlines() if "trial 1 十:" in l]
        self.assertEqual(len(lines), 1, self.err)
        self.assertIn("SIGTERM", lines[0])
        self.assertIn("attempt-1.json", lines[0])

    def test_the_attempts_trace_holds_every_servo_tick(self):
        if h5py is None:
            self.skipTest("h5py is needed")
        record = json.loads(self.attempts[0].read_text(encoding="utf-8"))
        ticks = re.search(r"servo loop: (\d+) ticks", self.err)
        self.assertIsNotNone(ticks, self.err)
        trace = self.attempts[0].parent / record["files"]["trace"]
        with h5py.File(trace, "r") as f:
            rows = len(f["t"])
        self.assertEqual(rows, record["samples"])
        self.assertEqual(rows, int(ticks.group(1)))

    def test_the_log_says_trial_interrupted_then_session_stopped_by_sigterm(self):
        # docs/experiments.md, the trainer's free practice: trial_interrupted with ... end_reason and
        # abort_reason, session_stopped with reason; docs/cli.md "Ending early": reason the signal's name.
        events = [e for e in log_events(self.session) if e["event"] in ("trial_interrupted", "session_stopped")]
        self.assertEqual([(e["event"], e.get("abort_reason"), e.get("reason")) for e in events],
                         [("trial_interrupted", "stopped by SIGTERM", None), ("session_stopped", None, "SIGTERM")])
        self.assertEqual(events[0]["file"], "001-test-vision-r1-U5341")

    def test_no_demo_starts_the_trial_at_once_so_the_first_pen_down_is_in_it(self):
        # docs/cli.md `--no-demo`: "start writing at once: no stroke-order demonstration".
        self.assertNotIn("demonstrating", self.err)
        record = json.loads(self.attempts[0].read_text(encoding="utf-8"))
        self.assertGreater(record["pen_down_time_s"] or 0, 0.1)
        self.assertGreaterEqual(record["per_stroke"][0]["attempts"], 1)

    def test_the_engineers_panel_at_exit_shows_state_tick_and_no_force_output(self):
        # docs/trainer.md "The engineer's panel": "no force output: guidance not felt" on the mouse, the
        # interaction state, the tick; the screenshot "at exit" and its panel text.
        self.assertEqual(png_size(self.tmp / "shot.png"), WINDOW)
        text = self.w.panel.read_text(encoding="utf-8")
        self.assertIn("no force output: guidance not felt", text)
        self.assertRegex(text, r"\b(SS|AS|CS|WS)\b")
        self.assertRegex(text, r"(?i)\btick")
        self.assertNotIn("guidance on", text.replace("guidance on the", ""))


@unittest.skipUnless(HAVE_X, "Xvfb and xdotool are needed")
class QuizLosesItsDisplay(WindowCase):
    """一 `--quiz` on an X server of its own: written backwards (a miss, printed as it happens), then the
    server killed."""

    @classmethod
    def setUpClass(cls):
        d = cls.make_folder()
        started = start_own_x_server("1024x768x24")
        if started is None:
            raise unittest.SkipTest("no X server starts")
        server, display = started
        cls.display = display
        w = WindowRun(d, display, ["一", "--device", "mouse", "--quiz", "--window", "%dx%d" % WINDOW,
                                   "--exit-after", "30", "--session", "S"])
        try:
            w.open()
            w.draw(w.pixels("一", 0, backwards=True))
            cls.miss = w.wait_for(r"quiz 一 stroke 1: stroke_missed \([^)]*\)", timeout=10).group(0)
            server.kill()
            server.wait()
            cls.status = w.finish(20)
        finally:
            w.kill()
            if server.poll() is None:
                server.kill()
                server.wait()
        cls.err, cls.stdout = w.stderr(), w.out.read_bytes()
        cls.session = one_session(d / "S")
        cls.attempts = sorted((cls.session / "trials" / "attempts").glob("*.json"))

    def test_the_backwards_stroke_is_printed_as_a_miss_as_it_happens(self):
        # docs/cli.md `train`: `quiz 一 stroke 1: stroke_missed (misses 1 on the stroke, 1 in all, backwards)`.
        self.assertEqual(self.miss, "quiz 一 stroke 1: stroke_missed (misses 1 on the stroke, 1 in all, backwards)")

    def test_the_lost_display_exits_4_naming_the_display(self):
        # docs/cli.md "Ending early": 4; "standard error names the display: the display was lost (X connection
        # to :99 broken)"; nothing on standard output; every line the command's own.
        self.assertEqual(self.status, 4, self.err)
        self.assertEqual(self.stdout, b"")
        for line in self.err.splitlines():
            self.assertTrue(line.startswith("calligraphy train: ") or line.startswith("box "), line)
        self.assertIn(f"the display was lost (X connection to {self.display} broken)", self.err)

    def test_the_quiz_trial_is_kept_as_an_attempt_stopped_by_display_lost(self):
        self.assertEqual([p.name for p in self.attempts], ["001-test-quiz-r1-U4E00.attempt-1.json"])
        record = json.loads(self.attempts[0].read_text(encoding="utf-8"))
        self.assertEqual((record["condition"], record["end_reason"], record["abort_reason"]),
                         ("quiz", "interrupted", "stopped by display_lost"))

    def test_the_saved_quiz_judges_the_same_backwards_miss(self):
        # docs/trainer.md: "The saved record (--session) judges the whole recorded trace after the trial ...
        # so its quiz events are those shown".
        record = json.loads(self.attempts[0].read_text(encoding="utf-8"))
        events = []

        def walk(node):
            if isinstance(node, dict):
                if "kind" in node and "refusal" in node:
                    events.append(node)
                for v in node.values():
                    walk(v)
            elif isinstance(node, list):
                for v in node:
                    walk(v)
        walk(record.get("quiz"))
        self.assertEqual([(e["stroke"], e["refusal"]) for e in events if e["refusal"] != "none"],
                         [(0, "backwards")], json.dumps(record.get("quiz"))[:2000])

    def test_the_log_says_session_stopped_with_display_lost(self):
        events = [e for e in log_events(self.session) if e["event"] in ("trial_interrupted", "session_stopped")]
        self.assertEqual([(e["event"], e.get("abort_reason"), e.get("reason")) for e in events],
                         [("trial_interrupted", "stopped by display_lost", None),
                          ("session_stopped", None, "display_lost")])


if __name__ == "__main__":
    unittest.main()
