"""The trainer's window end to end on a virtual X server (run by run_under_xvfb.sh): the simulated writer
writes 永 live and the screenshot shows the reference, the trace, the active character and the hints
where the printed layout puts them; the real pointer, driven with xdotool, writes 一 on --device mouse;
closing the window, pressing Q or sending SIGTERM mid-trial ends it safely with every tick kept; a lost
display (the X server killed), SIGTERM and SIGHUP end `train` and a session in the window with the trial
kept whole as an interrupted attempt, the reason in its record and in the session's log, and the documented
exit status (4 after a lost display, 128 + the signal's number).

Environment: CALLIGRAPHY_CLI (the program), CALLIGRAPHY_SOURCE_DIR (the source tree)."""
import csv
import json
import math
import os
import pathlib
import shutil
import signal
import subprocess
import sys
import tempfile
import time
import unittest

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))
from hand import Hand  # noqa: E402
from png import read_png, read_xwd, write_png  # noqa: E402

CLI = os.environ.get("CALLIGRAPHY_CLI", "calligraphy")
SOURCE = pathlib.Path(os.environ.get("CALLIGRAPHY_SOURCE_DIR", pathlib.Path(__file__).resolve().parents[2]))
EMBEDDED = SOURCE / "data" / "hanzi-writer-data"
SAMPLE = SOURCE / "tests" / "data" / "hanzi-writer-sample"
SHI_STROKE_ONE_TOO_SHORT = "十 stroke 1 not written: too short: carry the stroke to its end (too_short; judged in WS)"
CHARACTER_SIZE_M = 0.06  # SceneLayout's default side of a character box on paper
# The window the tests open (train --window): Mesa's software renderer fills every pixel of it on each frame, so
# a smaller window than the default 1280x800 costs the tests 40 % less CPU time; the boxes scale with it.
TEST_WINDOW = "800x500"
START_RADIUS_M = 0.005   # SceneLayout's default start neighbourhood


def xdotool(*args):
    return subprocess.run(["xdotool", *map(str, args)], check=True, capture_output=True, text=True).stdout


def press_quit(window, trainer, key="q"):
    """Q (or Esc) to the window. xdotool sends the press, then the release: the program may close the window
    in between, and the release then fails (BadWindow). That is accepted only once the program has ended."""
    sent = subprocess.run(["xdotool", "key", "--window", str(window), key], capture_output=True, text=True)
    if sent.returncode != 0:
        try:
            trainer.process.wait(timeout=5)
        except subprocess.TimeoutExpired:
            raise AssertionError(f"key {key}: {sent.stderr.strip()}, and the program still runs") from None


class Box:
    """A `box <index> <char> x= y= size=` line: the data box in window pixels, y down."""

    def __init__(self, line):
        parts = line.split()
        self.index, self.char = int(parts[1]), parts[2]
        values = dict(p.split("=") for p in parts[3:])
        self.x, self.y, self.size = float(values["x"]), float(values["y"]), float(values["size"])

    def data_to_px(self, point):
        return (self.x + point[0] / 1024 * self.size, self.y + (900 - point[1]) / 1024 * self.size)

    def metres_to_px(self, x_m, y_m):
        # A trial lays its character out centred at the origin (Scene::lay_out): data (512, 388) is (0, 0).
        units = 1024 / CHARACTER_SIZE_M
        return self.data_to_px((x_m * units + 512, y_m * units + 388))


def boxes_environment(environment=None):
    """The environment (this process's, as it is now, by default) asking the window to print its character
    boxes on stderr (docs/trainer.md); standard output never has them."""
    return dict(environment or os.environ, CALLIGRAPHY_PRINT_BOXES="1")


def box_lines(folder, process, who, timeout=30):
    """The character boxes the window printed on stderr (folder/stderr.txt, asked for by boxes_environment)
    once it has drawn; fails when `process` ends first (naming `who` and its stderr) or after `timeout` s."""
    deadline = time.time() + timeout
    while time.time() < deadline:
        lines = [l for l in (folder / "stderr.txt").read_text().splitlines() if l.startswith("box ")]
        if lines:
            return [Box(l) for l in lines]
        if process.poll() is not None:
            raise AssertionError(who + " ended before its window showed: " + (folder / "stderr.txt").read_text())
        time.sleep(0.1)
    raise AssertionError("no box line within %s s" % timeout)


def program_window(pid, tool=None, timeout=60, process=None):
    """The window of the program with process id `pid`: searched by its pid as well as its title, so that the
    window of a program that has just ended (still listed for a moment by the X server) is never taken. A first
    window on a loaded machine took more than 30 s (llvmpipe beside a sanitizer build); with `process`, a
    program that ended before its window showed fails at once, with its status."""
    tool = tool or xdotool
    deadline = time.time() + timeout
    while True:
        try:
            found = tool("search", "--all", "--pid", pid, "--name", "calligraphy train").split()
        except subprocess.CalledProcessError:  # xdotool search exits 1 when nothing matches
            found = []
        if found:
            return found[-1]
        if process is not None and process.poll() is not None:
            raise AssertionError(f"process {pid} ended with status {process.returncode} and no window of it is shown")
        if time.time() > deadline:
            raise AssertionError(f"no window of process {pid} within {timeout} s")
        time.sleep(0.1)


class Trainer:
    """`calligraphy train` running in the background."""

    def __init__(self, *args, folder, environment=None):
        self.folder = pathlib.Path(folder)
        self.stdout = open(self.folder / "stdout.txt", "w+")
        self.stderr = open(self.folder / "stderr.txt", "w+")
        if "--window" not in args:  # a smaller window than the default: a software renderer fills it each frame
            args = (*args, "--window", TEST_WINDOW)
        self.process = subprocess.Popen([CLI, "train", *args], stdout=self.stdout, stderr=self.stderr,
                                        cwd=self.folder, env=environment or boxes_environment())

    def output(self):
        return (self.folder / "stdout.txt").read_text()

    def boxes(self, timeout=30):
        return box_lines(self.folder, self.process, "the trainer", timeout)

    def window(self):
        return program_window(self.process.pid, process=self.process)

    def wait(self, timeout=120):
        return self.process.wait(timeout=timeout)

    def errors(self):
        return (self.folder / "stderr.txt").read_text()

    def wait_for(self, text, timeout=20):
        """Waits until the trainer has printed `text` on stderr."""
        deadline = time.time() + timeout
        while text not in self.errors():
            if time.time() > deadline or self.process.poll() is not None:
                raise AssertionError(f"no '{text}' on stderr within {timeout} s:\n" + self.errors())
            time.sleep(0.05)

    def hand(self, box, **timing):
        """A hand moving the pointer in the trainer's window, at the scale of `box`."""
        return Hand(self.window(), box.size / (CHARACTER_SIZE_M * 1e3), **timing)

    def close(self):
        if self.process.poll() is None:
            self.process.kill()
            self.process.wait()
        self.stdout.close()
        self.stderr.close()


def saved_trace_rows(record_path):
    """The rows of the trace saved beside a record (STEM.trace.h5), as `calligraphy trace` writes its CSV."""
    text = subprocess.run([CLI, "trace", record_path.with_suffix(".trace.h5")], capture_output=True,
                          check=True, timeout=60).stdout.decode("utf-8")
    return list(csv.DictReader(text.splitlines()))


def saved_trials(folder, subject="anonymous"):
    """The saved trials of the one session folder `train --session FOLDER` made (FOLDER/SUBJECT/train-*)."""
    (session,) = sorted(pathlib.Path(folder).glob(f"{subject}/train-*"))
    return sorted((session / "trials").glob("*.json"))


def kept_attempts(folder, subject="anonymous"):
    (session,) = sorted(pathlib.Path(folder).glob(f"{subject}/train-*"))
    return sorted((session / "trials" / "attempts").glob("*.json"))


def medians(char, folder=EMBEDDED):
    return json.loads((folder / f"{char}.json").read_text(encoding="utf-8"))["medians"]


def along(polyline, fractions):
    """Points at the given fractions of the polyline's length."""
    lengths = [math.dist(a, b) for a, b in zip(polyline, polyline[1:])]
    total = sum(lengths)
    out = []
    for f in fractions:
        target, walked = f * total, 0.0
        for (a, b), length in zip(zip(polyline, polyline[1:]), lengths):
            if walked + length >= target and length > 0:
                t = (target - walked) / length
                out.append((a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1])))
                break
            walked += length
    return out


def near(image, point, radius, colour):
    """True when a pixel of `colour` (a predicate on r, g, b) lies within `radius` px of `point`."""
    cx, cy = round(point[0]), round(point[1])
    for y in range(max(0, cy - radius), min(image.height, cy + radius + 1)):
        for x in range(max(0, cx - radius), min(image.width, cx + radius + 1)):
            if (x - cx) ** 2 + (y - cy) ** 2 <= radius * radius and colour(*image.pixel(x, y)):
                return True
    return False


def is_blue(r, g, b):
    return b > 180 and r < 90 and g < 140


def is_yellow(r, g, b):
    return r > 230 and g > 180 and b < 80


def is_green(r, g, b):
    return g > 190 and 60 < r < 180 and 60 < b < 180 and g - r > 50


def is_red(r, g, b):
    return r > 190 and g < 70 and b < 70


def is_accepted(r, g, b):  # the quiz's accepted stroke (20, 150, 60)
    return g > 120 and r < 60 and b < 100


def is_demo_ink(r, g, b):  # the demonstration's ink, Hanzi Writer's stroke colour #555
    return all(abs(c - 85) <= 6 for c in (r, g, b))


def is_hint(r, g, b):  # the quiz's hint, Hanzi Writer's highlight colour #AAF
    return b > 230 and 140 < r < 200 and 140 < g < 200


def fraction(hits):
    return sum(hits) / len(hits)


def is_refused(r, g, b):  # a refused attempt, greyed (150, 150, 150); blue over yellow blends near it
    return all(abs(c - 150) <= 6 for c in (r, g, b))


def keep_artifact(path):
    """Copies a picture to CALLIGRAPHY_TEST_ARTIFACTS when that names a folder, to look at after the run."""
    folder = os.environ.get("CALLIGRAPHY_TEST_ARTIFACTS")
    if folder:
        pathlib.Path(folder).mkdir(parents=True, exist_ok=True)
        shutil.copy(path, pathlib.Path(folder) / pathlib.Path(path).name)


class TrainerTest(unittest.TestCase):
    def setUp(self):
        self.folder = tempfile.mkdtemp(prefix="calligraphy-train-")
        self.trainer = None

    def tearDown(self):
        if self.trainer is not None:
            self.trainer.close()
        shutil.rmtree(self.folder, ignore_errors=True)

    def start(self, *args):
        self.trainer = Trainer(*args, folder=self.folder)
        return self.trainer

    def test_simulated_writer_writes_yong_and_the_screenshot_shows_it(self):
        trainer = self.start("永", "--writer", "simulated", "--session", "out", "--screenshot", "out/yong.png",
                             "--exit-after", "60", "--watchdog-ms", "2000")
        (box,) = trainer.boxes()
        self.assertEqual(trainer.wait(), 0, trainer.errors())
        (record_path,) = saved_trials(pathlib.Path(self.folder) / "out")
        record = json.loads(record_path.read_text(encoding="utf-8"))
        self.assertEqual((record["strokes_completed"], record["strokes_total"]), (5, 5))
        self.assertTrue(record["completed_in_order"])
        self.assertEqual(record["end_reason"], "completed")
        self.assertEqual(record["characters"], "永")
        self.assertEqual(record["subject"], "anonymous")
        self.assertEqual(record["condition"], "haptic")
        self.assertEqual(record["device"]["name"], "simulated")
        self.assertEqual(record["renderer"]["loop"]["stall_timeout_s"], 2.0)  # --watchdog-ms, in s
        for key in ("start_time_utc", "library", "mean_deviation_m", "per_stroke", "loop", "per_character"):
            self.assertIn(key, record)
        trace = saved_trace_rows(record_path)
        self.assertEqual(len(trace), record["loop"]["ticks"])  # every tick kept
        self.assertTrue(record_path.with_suffix(".svg").read_text().startswith("<svg"))

        image = read_png(pathlib.Path(self.folder) / "out" / "yong.png")
        strokes = medians("永")
        inner = [i / 20 for i in range(2, 19)]
        blue = [near(image, box.data_to_px(p), 6, is_blue) for m in strokes for p in along(m, inner)]
        self.assertGreater(fraction(blue), 0.9, "the reference in blue along the medians")
        yellow = [near(image, box.data_to_px(p), 15, is_yellow) for m in strokes for p in along(m, inner)]
        self.assertGreater(fraction(yellow), 0.9, "the active character in yellow around the medians")
        writing = [row for row in trace if row["state"] == "WS"][::25]
        green = [near(image, box.metres_to_px(float(r["x"]), float(r["y"])), 5, is_green) for r in writing]
        self.assertGreater(len(writing), 50)
        self.assertGreater(fraction(green), 0.8, "the pen's trace in light green where the pen wrote")
        radius = START_RADIUS_M * box.size / CHARACTER_SIZE_M
        for m in strokes:  # a red ellipse (rx = r, ry = 0.7 r) at each stroke's start once the trial ended
            cx, cy = box.data_to_px(m[0])
            ring = [(cx + radius * math.cos(a), cy + 0.7 * radius * math.sin(a))
                    for a in (2 * math.pi * k / 24 for k in range(24))]
            self.assertGreater(fraction([near(image, p, 3, is_red) for p in ring]), 0.6, f"hint at {m[0]}")
        # Nothing of the scene outside the box: no reference or active character beyond it.
        outside = [(x, y) for x in range(0, int(box.x) - 2, 4) for y in range(0, image.height, 4)]
        self.assertFalse(any(is_blue(*image.pixel(x, y)) or is_yellow(*image.pixel(x, y)) for x, y in outside))

    def test_a_haptic_device_writes_yong_through_the_stand_in_libhd(self):
        """`train --device openhaptics` on the stand-in libHD the tests build (CALLIGRAPHY_HD_STAND_IN), whose
        hand plays back the simulated writer's pen path: the trial runs on the HD scheduler's clock."""
        stand_in = os.environ.get("CALLIGRAPHY_HD_STAND_IN", "")
        if not stand_in or not pathlib.Path(stand_in).exists():
            self.skipTest("no stand-in libHD (CALLIGRAPHY_HD_STAND_IN)")
        folder = pathlib.Path(self.folder)
        written = subprocess.run([CLI, "trial", "永", "--csv", str(folder / "writer.csv")], capture_output=True)
        self.assertEqual(written.returncode, 0, written.stderr.decode())
        with open(folder / "writer.csv", newline="") as f:
            rows = list(csv.DictReader(f))
        with open(folder / "path.txt", "w") as f:  # HDAPI's frame and mm; 1 s of rest while the window opens
            points = [(0.0, rows[0])] + [(1.0 + float(row["t"]), row) for row in rows[::5] + rows[-1:]]
            for t, row in points:
                x, y, z = (float(row[k]) for k in ("x", "y", "z"))
                f.write(f"{t} {1000 * x} {1000 * z} {-1000 * y}\n")
            f.write(f"{points[-1][0] + 0.1} {1000 * x} {1000 * z + 10} {-1000 * y}\n")  # then lifts the pen
        environment = {"CALLIGRAPHY_LIBHD": stand_in, "HD_STAND_IN_PATH": str(folder / "path.txt")}
        saved = {k: os.environ.get(k) for k in environment}
        os.environ.update(environment)
        try:
            trainer = self.start("永", "--device", "openhaptics", "--session", "out", "--screenshot",
                                 "out/openhaptics.png", "--exit-after", "60")
        finally:
            for k, v in saved.items():
                if v is None:
                    os.environ.pop(k, None)
                else:
                    os.environ[k] = v
        self.assertEqual(trainer.wait(), 0, trainer.errors())
        (record_path,) = saved_trials(folder / "out")
        record = json.loads(record_path.read_text(encoding="utf-8"))
        self.assertEqual(record["device"]["name"], "openhaptics")
        self.assertTrue(record["device"]["hardware"])
        self.assertEqual(record["end_reason"], "completed")
        self.assertEqual((record["strokes_completed"], record["strokes_total"]), (5, 5))
        self.assertTrue(record["loop"]["device_clock"])
        self.assertGreater(record["device"]["time_at_start_s"], 100.0)  # the stand-in's own clock
        trace = saved_trace_rows(record_path)
        self.assertEqual(float(trace[0]["t"]), 0.0)
        self.assertEqual(len(trace), record["loop"]["ticks"])
        keep_artifact(folder / "out" / "openhaptics.png")

    def test_the_real_pointer_writes_yi_on_the_mouse_device(self):
        trainer = self.start("一", "--device", "mouse", "--data", SAMPLE, "--session", "out", "--exit-after", "60")
        (box,) = trainer.boxes()
        window = trainer.window()
        median = medians("一", SAMPLE)[0]
        path = [box.data_to_px(p) for p in along(median, [i / 12 for i in range(13)])]
        end = box.data_to_px((median[-1][0] + 15, median[-1][1]))  # a little past the end
        time.sleep(0.5)
        self.write_with_the_mouse(window, path + [end], trainer=trainer)  # the pen down at the stroke's start
        self.assertEqual(trainer.wait(), 0, trainer.errors())
        (record_path,) = saved_trials(pathlib.Path(self.folder) / "out")
        record = json.loads(record_path.read_text(encoding="utf-8"))
        self.assertEqual(record["device"]["name"], "mouse")
        self.assertEqual(record["condition"], "vision")
        self.assertEqual((record["strokes_completed"], record["strokes_total"]), (1, 1))
        self.assertEqual(record["end_reason"], "completed")
        self.assertLess(record["per_character"][0]["per_stroke"][0]["mean_deviation_m"], 1.5e-3)

    def write_with_the_mouse(self, window, points, pause=0.12, trainer=None):
        """Presses at the first point, moves through the others, and lifts the pen. With `trainer`, a stroke
        that ends its session may close the window before the last points: the moves stop there."""
        xdotool("mousemove", "--window", window, round(points[0][0]), round(points[0][1]))
        time.sleep(0.3)
        xdotool("mousedown", 1)
        time.sleep(0.3)
        for x, y in points[1:]:
            try:
                xdotool("mousemove", "--window", window, round(x), round(y))
            except subprocess.CalledProcessError:
                if trainer is None:
                    raise
                trainer.wait(timeout=30)  # the window is gone: the program must be ending
                break
            time.sleep(pause)
        time.sleep(0.3)
        if trainer is None or trainer.process.poll() is None:
            xdotool("mouseup", 1)

    def test_the_quiz_misses_a_backwards_stroke_and_accepts_the_right_one_live(self):
        shots = pathlib.Path(self.folder) / "shots"
        shots.mkdir()
        trainer = self.start("一", "--device", "mouse", "--data", SAMPLE, "--quiz", "--hint-after-misses", "1",
                             "--session", "out", "--quiz-screenshots", "shots", "--exit-after", "60")
        (box,) = trainer.boxes()
        window = trainer.window()
        median = medians("一", SAMPLE)[0]
        forwards = [box.data_to_px(p) for p in along(median, [i / 12 for i in range(13)])]
        time.sleep(0.5)
        self.write_with_the_mouse(window, forwards[::-1])  # from its end to its start: missed, backwards
        deadline = time.time() + 20
        while "stroke_missed" not in trainer.errors() and time.time() < deadline:
            time.sleep(0.1)
        self.assertIn("quiz 一 stroke 1: stroke_missed (misses 1 on the stroke, 1 in all, backwards)",
                      trainer.errors())
        time.sleep(0.8)
        self.write_with_the_mouse(window, forwards + [box.data_to_px((median[-1][0] + 15, median[-1][1]))],
                                  trainer=trainer)
        self.assertEqual(trainer.wait(), 0, trainer.errors())
        errors = trainer.errors()
        self.assertIn("quiz 一 stroke 1: stroke_accepted (misses 0 on the stroke, 1 in all)", errors)
        self.assertIn("quiz 一 complete, 1 miss\n", errors)
        self.assertIn("quiz: 2 live verdicts, the same as in the saved record", errors)

        (record_path,) = saved_trials(pathlib.Path(self.folder) / "out")
        record = json.loads(record_path.read_text(encoding="utf-8"))
        self.assertEqual(record["condition"], "quiz")
        self.assertFalse(record["force_law"]["guidance"])
        quiz = record["quiz"]
        self.assertEqual(quiz["hint_after_misses"], 1)
        self.assertEqual((quiz["strokes_accepted"], quiz["misses"], quiz["hints"], quiz["backwards"]), (1, 1, 1, 1))
        events = quiz["characters"][0]["events"]
        self.assertEqual([e["kind"] for e in events], ["stroke_missed", "hint", "stroke_accepted", "character_completed"])
        self.assertTrue(events[0]["backwards"])
        # The stderr lines the window printed as each verdict came are the saved record's events (strokes
        # numbered from 1 on stderr, from 0 in the record).
        logged = [l.split("quiz 一 ", 1)[1] for l in errors.splitlines() if "quiz 一 stroke" in l]
        expected = ["stroke %d: %s (misses %d on the stroke, %d in all%s)"
                    % (e["stroke"] + 1, e["kind"], e["misses_on_stroke"], e["total_misses"],
                       ", backwards" if e["backwards"] else
                       "" if e["refusal"] == "none" else ", " + e["refusal"]) for e in events]
        self.assertEqual(events[0]["refusal"], "backwards")
        self.assertEqual(logged, expected)

        # What the window showed after each verdict.
        inner = along(median, [i / 20 for i in range(2, 19)])
        missed = read_png(shots / "quiz-01-stroke_missed.png")
        self.assertGreater(fraction([near(missed, box.data_to_px(p), 4, is_red) for p in inner]), 0.9,
                           "the missed trace flashes red along the stroke")
        self.assertGreater(fraction([near(missed, box.data_to_px(p), 4, is_hint) for p in inner]), 0.9,
                           "the expected stroke highlighted after one miss")
        self.assertEqual(fraction([near(missed, box.data_to_px(p), 4, is_accepted) for p in inner]), 0.0)
        accepted = read_png(shots / "quiz-02-stroke_accepted.png")
        self.assertGreater(fraction([near(accepted, box.data_to_px(p), 4, is_accepted) for p in inner]), 0.9,
                           "the accepted stroke filled in green")
        self.assertEqual(fraction([near(accepted, box.data_to_px(p), 4, is_red) for p in inner]), 0.0)
        # Hanzi Writer's quiz shows no reference and no start of the next stroke.
        self.assertEqual(fraction([near(missed, box.data_to_px(p), 4, is_blue) for p in inner]), 0.0)

    def test_the_quiz_credits_a_stroke_assisted_live(self):
        # After --assist-after-misses misses the quiz shows the stroke and credits it (Hanzi Writer's
        # markStrokeCorrectAfterMisses): one miss on 一's only stroke completes the quiz.
        shots = pathlib.Path(self.folder) / "shots"
        shots.mkdir()
        trainer = self.start("一", "--device", "mouse", "--data", SAMPLE, "--quiz", "--assist-after-misses", "1",
                             "--session", "out", "--quiz-screenshots", "shots", "--exit-after", "60")
        (box,) = trainer.boxes()
        window = trainer.window()
        median = medians("一", SAMPLE)[0]
        backwards = [box.data_to_px(p) for p in along(median, [i / 12 for i in range(13)])][::-1]
        time.sleep(0.5)
        self.write_with_the_mouse(window, backwards, trainer=trainer)
        self.assertEqual(trainer.wait(), 0, trainer.errors())
        errors = trainer.errors()
        self.assertIn("quiz 一 stroke 1: stroke_missed (misses 1 on the stroke, 1 in all, backwards)", errors)
        self.assertIn("quiz 一 stroke 1: stroke_assisted (misses 1 on the stroke, 1 in all)", errors)
        self.assertIn("quiz 一 complete, 1 miss\n", errors)
        self.assertIn("quiz: 1 live verdict, the same as in the saved record", errors)

        (record_path,) = saved_trials(pathlib.Path(self.folder) / "out")
        record = json.loads(record_path.read_text(encoding="utf-8"))
        self.assertEqual(record["end_reason"], "completed")
        quiz = record["quiz"]
        self.assertEqual((quiz["assist_after_misses"], quiz["acceptance"]["assist_after_misses"]), (1, 1))
        self.assertEqual((quiz["strokes_accepted"], quiz["strokes_assisted"], quiz["misses"]), (0, 1, 1))
        events = quiz["characters"][0]["events"]
        self.assertEqual([e["kind"] for e in events], ["stroke_missed", "stroke_assisted", "character_completed"])
        self.assertEqual([e["stroke"] for e in events], [0, 0, 0])

        # The assisted stroke filled in the demonstration's ink, as a trial's assisted stroke; not accepted.
        inner = along(median, [i / 20 for i in range(2, 19)])
        shown = read_png(shots / "quiz-01-stroke_missed.png")
        self.assertGreater(fraction([near(shown, box.data_to_px(p), 4, is_demo_ink) for p in inner]), 0.9,
                           "the assisted stroke in the demonstration's ink")
        self.assertEqual(fraction([near(shown, box.data_to_px(p), 4, is_accepted) for p in inner]), 0.0)

    def test_the_quiz_options_need_quiz(self):
        with tempfile.TemporaryDirectory() as folder:
            result = subprocess.run([CLI, "train", "一", "--quiz-screenshots", folder], capture_output=True,
                                    text=True)
        self.assertEqual(result.returncode, 2, result.stderr)
        self.assertIn("--quiz", result.stderr)
        # The miss counts are every trial's (the stroke acceptance's), in its range, refused before a window.
        for option in ("--hint-after-misses", "--assist-after-misses"):
            result = subprocess.run([CLI, "train", "一", option, "1001"], capture_output=True, text=True)
            self.assertEqual(result.returncode, 2, result.stderr)
            self.assertIn(option, result.stderr)
        # The quiz judges with the stroke matcher's tolerances: there is no leniency to set.
        result = subprocess.run([CLI, "train", "一", "--quiz", "--leniency", "2"], capture_output=True, text=True)
        self.assertEqual(result.returncode, 2, result.stderr)
        self.assertIn("--leniency", result.stderr)

    def write_yi_beside_the_stroke(self, guidance, offset):
        """On mouse-hand, presses at the start of 一, then moves the pointer `offset` data units below the
        stroke to its end; returns the saved record."""
        folder = pathlib.Path(self.folder) / guidance
        folder.mkdir()
        trainer = Trainer("一", "--device", "mouse-hand", "--guidance", guidance, "--data", SAMPLE, "--session",
                          "out", "--exit-after", "60", folder=folder)
        try:
            (box,) = trainer.boxes()
            window = trainer.window()
            median = medians("一", SAMPLE)[0]
            below = [box.data_to_px((x, y - offset)) for x, y in along(median, [i / 24 for i in range(1, 25)])]
            below.append(box.data_to_px((median[-1][0] + 30, median[-1][1] - offset)))
            start = box.data_to_px(median[0])
            time.sleep(0.5)
            xdotool("mousemove", "--window", window, round(start[0]), round(start[1]))
            time.sleep(0.8)  # the hand carries the stylus over the start
            xdotool("mousedown", 1)
            time.sleep(0.8)
            for x, y in below:
                try:
                    xdotool("mousemove", "--window", window, round(x), round(y))
                except subprocess.CalledProcessError:
                    # The stroke was written and the trainer is closing its window: nothing left to move.
                    trainer.process.wait(timeout=30)
                    break
                time.sleep(0.1)
            time.sleep(0.8)
            if trainer.process.poll() is None:
                xdotool("mouseup", 1)
            self.assertEqual(trainer.wait(), 0, trainer.errors())
        finally:
            trainer.close()
        (record_path,) = saved_trials(folder / "out")
        return json.loads(record_path.read_text(encoding="utf-8"))

    def test_guidance_pulls_the_mouse_hand_pen_towards_the_stroke(self):
        offset = 40  # data units, 2.3 mm on paper
        guided = self.write_yi_beside_the_stroke("on", offset)
        free = self.write_yi_beside_the_stroke("off", offset)
        for record in (guided, free):
            self.assertEqual(record["device"]["name"], "mouse-hand")
            self.assertEqual(record["strokes_completed"], 1, record)
        self.assertEqual(guided["condition"], "haptic")
        self.assertEqual(free["condition"], "vision")
        self.assertLess(guided["mean_deviation_m"], 0.7 * free["mean_deviation_m"])

    def write_like_a_person(self, device, **timing):
        """Writes 十口人永, one trial each, moving the pointer as a person moves a pen (hand.py): minimum-jerk
        along each displayed median, a 0.3 mm wobble, corners rounded, the pen lifted 0.5-1.5 mm short of
        the end. Every stroke must be written at its first touch. Returns the saved records."""
        characters = "十口人永"
        trainer = self.start(characters, "--device", device, "--session", "out", "--exit-after", "55")
        boxes = trainer.boxes()
        hand = trainer.hand(boxes[0], seed=7, **timing)
        time.sleep(0.5)
        for k, (box, character) in enumerate(zip(boxes, characters)):
            if k > 0:
                trainer.wait_for(f"trial {k} {characters[k - 1]}: completed")
                time.sleep(1.3)  # unattended: the next character's trial starts a second later
            for median in medians(character):
                hand.write([box.data_to_px(p) for p in median])
        self.assertEqual(trainer.wait(timeout=30), 0, trainer.errors())
        self.assertNotIn("not written", trainer.errors())
        records = [json.loads(p.read_text(encoding="utf-8")) for p in saved_trials(pathlib.Path(self.folder) / "out")]
        self.assertEqual([r["characters"] for r in records], list(characters))
        for record in records:
            self.assertEqual(record["device"]["name"], device)
            # A pointer device holds no force against a hand: no stall bound ends its trial on a busy desktop.
            self.assertEqual(record["renderer"]["loop"]["stall_timeout_s"], 0.0)
            self.assertEqual(record["end_reason"], "completed", record["characters"])
            self.assertEqual(record["strokes_completed"], record["strokes_total"], record["characters"])
            self.assertEqual([s["attempts"] for s in record["per_stroke"]], [1] * record["strokes_total"],
                             f"{record['characters']}: one touch, one attempt")
        return records

    def test_a_hand_writes_shi_kou_ren_yong_on_the_mouse(self):
        self.write_like_a_person("mouse")

    def test_a_hand_writes_shi_kou_ren_yong_on_the_mouse_hand(self):
        # The pen follows the pointer through a simulated hand: it needs a moment to get over the start and
        # onto the paper.
        self.write_like_a_person("mouse-hand", settle_s=0.45, press_s=0.3)

    def test_a_refused_stroke_stays_faded_and_the_panel_says_why(self):
        trainer = self.start("十", "--device", "mouse", "--no-demo", "--screenshot", "refused.png")
        (box,) = trainer.boxes()
        hand = trainer.hand(box, seed=11)
        across, down = medians("十")
        time.sleep(0.5)
        # Half of stroke 1: the renderer refuses it as the pen lifts in WS, through the display channel.
        hand.write([box.data_to_px(p) for p in along(across, [i / 10 for i in range(6)])])
        trainer.wait_for("十 stroke 1 not written: too short: carry the stroke to its end (too_short; judged in WS)")
        # Stroke 2 first: the pen never comes near stroke 1's start (no WS); the matcher names it.
        hand.write([box.data_to_px(p) for p in down])
        trainer.wait_for("十 stroke 1 not written: wrong order: that stroke comes later (wrong_order; judged from "
                         "the pen-down path)")
        # Stroke 1 from its end.
        hand.write([box.data_to_px(p) for p in across[::-1]])
        trainer.wait_for("十 stroke 1 not written: backwards: start from the other end (backwards; judged ")
        time.sleep(0.3)
        window = trainer.window()
        xdotool("windowfocus", "--sync", window)
        press_quit(window, trainer)  # the screenshot shows the window as the exit came
        self.assertEqual(trainer.wait(timeout=30), 0, trainer.errors())
        picture = pathlib.Path(self.folder) / "refused.png"
        keep_artifact(picture)
        image = read_png(picture)
        inner = along(across, [i / 20 for i in range(2, 19)])
        self.assertGreater(fraction([near(image, box.data_to_px(p), 5, is_refused) for p in inner]), 0.9,
                           "the refused attempt stays, greyed, along the stroke")
        self.assertEqual(fraction([near(image, box.data_to_px(p), 5, is_green) for p in inner]), 0.0,
                         "nothing written")
        # Only the last refusal is shown: the earlier attempt at stroke 2 went at the touch-down.
        lower = along(down, [i / 20 for i in range(13, 19)])
        self.assertEqual(fraction([near(image, box.data_to_px(p), 5, is_refused) for p in lower]), 0.0)

    def refuse_half_of_shi_stroke_one(self, trainer, hand, box, count):
        """Writes the first half of 十's stroke 1 from its start (refused as too short as the pen lifts in WS)
        and waits until the trainer has said so `count` times in all."""
        hand.write([box.data_to_px(p) for p in along(medians("十")[0], [i / 10 for i in range(6)])])
        deadline = time.time() + 20
        while trainer.errors().count(SHI_STROKE_ONE_TOO_SHORT) < count:
            self.assertLess(time.time(), deadline, f"no miss {count}:\n" + trainer.errors())
            self.assertIsNone(trainer.process.poll(), trainer.errors())
            time.sleep(0.05)

    def test_the_panel_names_the_hinted_stroke_by_its_colour(self):
        """After three misses the learner's panel says the hint and that the stroke to write is the light
        blue one (it is no longer drawn yellow); the picture at exit (Q) is docs/images/trainer-hint.png."""
        text = pathlib.Path(self.folder) / "panel.txt"
        environment = boxes_environment(dict(os.environ, CALLIGRAPHY_PANEL_TEXT=str(text)))
        trainer = self.trainer = Trainer("十", "--device", "mouse", "--no-demo", "--screenshot", "hint.png",
                                         folder=self.folder, environment=environment)
        (box,) = trainer.boxes()
        hand = trainer.hand(box, seed=5)
        time.sleep(0.5)
        for count in (1, 2, 3):
            self.refuse_half_of_shi_stroke_one(trainer, hand, box, count)
        time.sleep(1.0)  # the hint drawn in full
        window = trainer.window()
        corner = box.data_to_px((980, 880))  # the pointer off the strokes, for the picture
        xdotool("mousemove", "--window", window, round(corner[0]), round(corner[1]))
        xdotool("windowfocus", "--sync", window)
        press_quit(window, trainer)
        self.assertEqual(trainer.wait(timeout=30), 0, trainer.errors())
        keep_artifact(pathlib.Path(self.folder) / "hint.png")
        panel = text.read_text(encoding="utf-8")
        self.assertIn("Stroke 1 of 2", panel)
        self.assertIn("Here is stroke 1", panel)
        self.assertIn("the stroke to write is the light blue one", panel)
        self.assertNotIn("yellow", panel, panel)
        image = read_png(pathlib.Path(self.folder) / "hint.png")
        inner = along(medians("十")[0], [i / 20 for i in range(2, 19)])
        self.assertGreater(fraction([near(image, box.data_to_px(p), 4, is_hint) for p in inner]), 0.9)

    def test_misses_bring_the_hint_then_the_assisted_credit_and_the_trial_goes_on(self):
        """`train 十` on the mouse: stroke 1 started at its start and lifted half way (too short) is refused;
        from the third miss the window fills it in the hint colour, at the fifth it is credited assisted
        (drawn in the demonstration's ink) and stroke 2, written, completes the trial. What the window shows
        is read from its own X server's framebuffer (Xvfb -fbdir) while the trial runs."""
        try:
            display = OwnDisplay(framebuffer=True)
        except OSError as e:
            self.skipTest(f"no Xvfb of the test's own: {e}")
        self.addCleanup(display.kill)
        saved = os.environ.get("DISPLAY")  # the trainer, the hand and xdotool below use the test's own display
        os.environ["DISPLAY"] = display.name
        self.addCleanup(lambda: os.environ.__setitem__("DISPLAY", saved) if saved else os.environ.pop("DISPLAY"))
        trainer = self.start("十", "--device", "mouse", "--no-demo", "--session", "out", "--exit-after", "60")
        (box,) = trainer.boxes()
        hand = trainer.hand(box, seed=3)
        across, down = medians("十")
        inner = along(across, [i / 20 for i in range(2, 19)])
        def miss(count, look=True):
            self.refuse_half_of_shi_stroke_one(trainer, hand, box, count)
            if not look:
                return None
            time.sleep(1.0)  # the window draws what the miss brought at the demonstration's pace (0.6 s)
            return display.window_image(trainer.window())

        time.sleep(0.5)
        miss(1, look=False)
        before = miss(2)
        self.assertEqual(fraction([near(before, box.data_to_px(p), 4, is_hint) for p in inner]), 0.0,
                         "no hint after two misses")
        hinted = miss(3)
        keep_artifact(display.save_png(hinted, pathlib.Path(self.folder) / "trainer-hint.png"))
        self.assertGreater(fraction([near(hinted, box.data_to_px(p), 4, is_hint) for p in inner]), 0.9,
                           "stroke 1 filled in the hint colour after three misses")
        across_densely = along(across, [i / 100 for i in range(101)])
        clear = [p for p in along(down, [i / 20 for i in range(2, 19)])  # stroke 2 away from the crossing
                 if min(math.dist(p, q) for q in across_densely) > 80]
        self.assertGreater(len(clear), 10)
        self.assertEqual(fraction([near(hinted, box.data_to_px(p), 4, is_hint) for p in clear]), 0.0,
                         "the hint is the active stroke only")
        self.assertTrue(near(hinted, box.data_to_px(across[0]), 20, is_red), "the hint numbered at its start")
        miss(4, look=False)
        assisted = miss(5)
        keep_artifact(display.save_png(assisted, pathlib.Path(self.folder) / "trainer-assisted.png"))
        self.assertGreater(fraction([near(assisted, box.data_to_px(p), 4, is_demo_ink) for p in inner]), 0.9,
                           "stroke 1 shown in the demonstration's ink once credited")
        self.assertEqual(fraction([near(assisted, box.data_to_px(p), 4, is_hint) for p in inner]), 0.0,
                         "no hint once the stroke is credited")
        hand.write([box.data_to_px(p) for p in down])
        self.assertEqual(trainer.wait(timeout=30), 0, trainer.errors())
        self.assertEqual(trainer.errors().count(SHI_STROKE_ONE_TOO_SHORT), 5, trainer.errors())
        (record_path,) = saved_trials(pathlib.Path(self.folder) / "out")
        record = json.loads(record_path.read_text(encoding="utf-8"))
        self.assertEqual(record["end_reason"], "completed")
        # The assisted stroke is credited, not written: stroke 2 is the one written.
        self.assertEqual((record["strokes_assisted"], record["strokes_completed"], record["strokes_written"]),
                         (1, 1, 1))
        (character,) = record["per_character"]
        self.assertEqual(character["strokes_written"], 1)
        self.assertEqual([s["written"] for s in character["per_stroke"]], [False, True])
        self.assertFalse(record["completed_in_order"])
        first, second = record["per_stroke"]
        self.assertTrue(first["assisted"])
        self.assertFalse(first["completed"])
        self.assertEqual(first["attempts"], 5)
        self.assertTrue(second["completed"])
        self.assertFalse(second["assisted"])

    def test_the_miss_counts_given_to_train_reach_its_trials_and_records(self):
        """`train 十 --hint-after-misses 1 --assist-after-misses 2`: stroke 1 is credited assisted at its second
        miss (not the default fifth), stroke 2 written completes the trial, and the saved record states the
        counts it ran with (its force law's acceptance)."""
        trainer = self.start("十", "--device", "mouse", "--no-demo", "--session", "out", "--exit-after", "60",
                             "--hint-after-misses", "1", "--assist-after-misses", "2")
        (box,) = trainer.boxes()
        hand = trainer.hand(box, seed=3)
        time.sleep(0.5)
        for count in (1, 2):
            self.refuse_half_of_shi_stroke_one(trainer, hand, box, count)
        time.sleep(1.0)
        hand.write([box.data_to_px(p) for p in medians("十")[1]])
        self.assertEqual(trainer.wait(timeout=30), 0, trainer.errors())
        self.assertEqual(trainer.errors().count(SHI_STROKE_ONE_TOO_SHORT), 2, trainer.errors())
        (record_path,) = saved_trials(pathlib.Path(self.folder) / "out")
        record = json.loads(record_path.read_text(encoding="utf-8"))
        self.assertEqual(record["end_reason"], "completed")
        self.assertEqual((record["strokes_assisted"], record["strokes_written"]), (1, 1))
        first, second = record["per_stroke"]
        self.assertTrue(first["assisted"])
        self.assertEqual(first["attempts"], 2)
        self.assertTrue(second["completed"])
        acceptance = record["force_law"]["acceptance"]
        self.assertEqual((acceptance["hint_after_misses"], acceptance["assist_after_misses"]), (1, 2))

    def test_a_stroke_never_started_at_its_start_is_credited_after_the_misses(self):
        """`train 十 --assist-after-misses 3` on the mouse, whose pen nothing draws to the start: stroke 1
        written 8 mm beside itself never comes within the 5 mm start radius (no WS), and each pen-down is a
        miss all the same (docs/stroke-acceptance.md, "No dead end"): at the third it is credited assisted and
        stroke 2, written, completes the trial."""
        trainer = self.start("十", "--device", "mouse", "--no-demo", "--session", "out", "--exit-after", "60",
                             "--hint-after-misses", "2", "--assist-after-misses", "3")
        (box,) = trainer.boxes()
        hand = trainer.hand(box, seed=7)
        across, down = medians("十")
        off = 0.008 / CHARACTER_SIZE_M * 1024  # 8 mm in data units, across the horizontal stroke
        beside = [(x, y + off) for x, y in across]
        said = "十 stroke 1 not written: wrong place"
        time.sleep(0.5)
        for count in (1, 2, 3):
            hand.write([box.data_to_px(p) for p in beside])
            deadline = time.time() + 20
            while trainer.errors().count(said) < count:
                self.assertLess(time.time(), deadline, f"no miss {count}:\n" + trainer.errors())
                self.assertIsNone(trainer.process.poll(), trainer.errors())
                time.sleep(0.05)
        time.sleep(1.0)
        hand.write([box.data_to_px(p) for p in down])
        self.assertEqual(trainer.wait(timeout=30), 0, trainer.errors())
        self.assertEqual(trainer.errors().count("judged from the pen-down path"), 3, trainer.errors())
        (record_path,) = saved_trials(pathlib.Path(self.folder) / "out")
        record = json.loads(record_path.read_text(encoding="utf-8"))
        self.assertEqual(record["end_reason"], "completed")
        self.assertEqual((record["strokes_assisted"], record["strokes_completed"]), (1, 1))
        first, second = record["per_stroke"]
        self.assertTrue(first["assisted"])
        self.assertEqual(first["attempts"], 0, "never in WS: every miss was a pen-down off its start")
        self.assertTrue(second["completed"])

    def test_a_quiz_ends_completed_once_every_stroke_is_accepted(self):
        # 一 written along its median: the quiz accepts it as the renderer completes it (one stroke matcher,
        # the renderer's tolerances), and the trial ends at once. On mouse-hand, where the pen landing on the
        # paper must not count twice.
        trainer = self.start("一", "--device", "mouse-hand", "--data", SAMPLE, "--quiz", "--session", "out",
                             "--exit-after", "50")
        (box,) = trainer.boxes()
        hand = trainer.hand(box, seed=5, settle_s=0.45, press_s=0.3)
        median = medians("一", SAMPLE)[0]
        time.sleep(0.5)
        started = time.time()
        hand.write([box.data_to_px(p) for p in along(median, [i / 12 for i in range(13)])])
        self.assertEqual(trainer.wait(timeout=30), 0, trainer.errors())
        self.assertLess(time.time() - started, 20, "the trial ended with the quiz, not at --exit-after")
        errors = trainer.errors()
        self.assertIn("quiz 一 complete, 0 misses", errors)
        self.assertNotIn("too_short", errors)
        (record_path,) = saved_trials(pathlib.Path(self.folder) / "out")
        record = json.loads(record_path.read_text(encoding="utf-8"))
        self.assertEqual((record["condition"], record["end_reason"]), ("quiz", "completed"))
        self.assertEqual(record["strokes_completed"], 1)  # the renderer's count: the same verdict
        self.assertEqual((record["quiz"]["strokes_accepted"], record["quiz"]["misses"]), (1, 0))
        self.assertEqual(record["quiz"]["acceptance"], record["force_law"]["acceptance"])

    def ended_mid_trial(self, end, status=0):
        """Starts 永 with the simulated writer (no time limit of its own), lets it write a while, then calls
        `end`, and checks the trial was kept whole as an interrupted attempt and the exit `status`."""
        trainer = self.start("永", "--writer", "simulated", "--session", "out", "--subject", "s01")
        trainer.boxes()
        time.sleep(4.0)
        self.assertIsNone(trainer.process.poll(), "the trial should still run: " + trainer.errors())
        end(trainer)
        self.assertEqual(trainer.wait(timeout=30), status, trainer.errors())
        out = pathlib.Path(self.folder) / "out"
        self.assertEqual(saved_trials(out, "s01"), [])
        (record_path,) = kept_attempts(out, "s01")
        self.assertTrue(record_path.name.startswith("001-test-haptic-r1-U6C38.attempt-1"), record_path.name)
        record = json.loads(record_path.read_text(encoding="utf-8"))
        self.assertEqual(record["end_reason"], "interrupted")
        self.assertTrue(record["aborted"])
        self.assertLess(record["strokes_completed"], 5)
        rows = len(saved_trace_rows(record_path))
        self.assertGreater(rows, 3000)  # about 4 s at 1 kHz
        self.assertEqual(rows, record["loop"]["ticks"])
        return record

    def test_closing_the_window_mid_trial_keeps_the_data(self):
        self.ended_mid_trial(lambda trainer: xdotool("windowclose", trainer.window()))

    def test_pressing_q_mid_trial_keeps_the_data(self):
        def press_q(trainer):
            window = trainer.window()
            xdotool("windowfocus", "--sync", window)
            press_quit(window, trainer)
        self.ended_mid_trial(press_q)

    def test_sigterm_mid_trial_keeps_the_data(self):
        record = self.ended_mid_trial(lambda trainer: trainer.process.send_signal(signal.SIGTERM), 128 + 15)
        self.assertEqual(record["abort_reason"], "stopped by SIGTERM")

    def test_record_then_replay_and_fading_name_their_conditions(self):
        first = self.start("一", "--writer", "simulated", "--data", SAMPLE, "--record", "teacher.json",
                           "--session", "out", "--exit-after", "30")
        self.assertEqual(first.wait(), 0, first.errors())
        first.close()
        teacher = json.loads((pathlib.Path(self.folder) / "teacher.json").read_text(encoding="utf-8"))
        self.assertEqual((teacher["format"], teacher["characters"]), ("calligraphy-teacher-recording", "一"))
        self.assertGreater(len(teacher["samples"]["t_s"]), 1000)
        for mode, extra in (("replay", ["--teacher", "teacher.json"]), ("fading", ["--guidance-gain", "0.5"])):
            run = self.start("一", "--writer", "simulated", "--data", SAMPLE, "--guidance-mode", mode, *extra,
                             "--session", "out", "--exit-after", "30")
            self.assertEqual(run.wait(), 0, run.errors())
            run.close()
        conditions = sorted(json.loads(p.read_text(encoding="utf-8"))["condition"]
                            for p in (pathlib.Path(self.folder) / "out").glob("anonymous/train-*/trials/*.json"))
        self.assertEqual(conditions, ["fading", "haptic", "replay"])

    def test_each_run_saves_into_a_new_session_folder(self):
        out = pathlib.Path(self.folder) / "out"
        first = self.start("一", "--device", "mouse", "--data", SAMPLE, "--session", "out", "--exit-after", "2")
        self.assertEqual(first.wait(), 0, first.errors())
        first.close()
        (session,) = out.glob("anonymous/train-*")
        before = {p: p.read_bytes() for p in session.rglob("*") if p.is_file() and p.name != "log.jsonl"}
        self.assertTrue(any(p.name.endswith(".attempt-1.json") for p in before), sorted(before))
        second = self.start("一", "--device", "mouse", "--data", SAMPLE, "--session", "out", "--exit-after", "2")
        self.assertEqual(second.wait(), 0, second.errors())
        self.assertEqual(len(list(out.glob("anonymous/train-*"))), 2)
        self.assertEqual({p: p.read_bytes() for p in before}, before)  # nothing of the first run changed
        record = json.loads(next(p for p in before if p.suffix == ".json" and "attempt" in p.name).read_text())
        self.assertEqual(record["end_reason"], "interrupted")

TINY_PROTOCOL = {
    "format": "calligraphy-study-protocol", "version": 1, "name": "tiny",
    "description": "two trials of one character: vision only, then with the guiding force",
    "conditions": [{"name": "vision", "mode": "vision"}, {"name": "haptic", "mode": "haptic"}],
    "test": {"characters": ["一"], "conditions": ["vision", "haptic"], "repetitions": 1},
    "breaks": {"between_blocks_s": 2},
    "trial": {"max_duration_s": 8, "rate_hz": 1000},
}


SPDLOG_LINE = r"^\[\d{4}-\d\d-\d\d |\[calligraphy\] \[(trace|debug|info|warning|error|critical)\]"


class PeopleOutputTest(unittest.TestCase):
    """What a person reads from `train` (docs/cli.md, "train"): standard output carries no box line and no log
    line of the library; a trial stopped early is summarised truthfully (no "nan"), saying what was kept; the
    quiz's sentences are true for no verdict as for one and many."""

    def setUp(self):
        self.folder = tempfile.mkdtemp(prefix="calligraphy-people-")
        self.trainer = None

    def tearDown(self):
        if self.trainer is not None:
            self.trainer.close()
        shutil.rmtree(self.folder, ignore_errors=True)

    def run_train(self, *args):
        """`train ARGS` to its end, as a person runs it: without asking for the box lines."""
        self.trainer = Trainer(*args, folder=self.folder, environment=dict(os.environ))
        status = self.trainer.wait(timeout=60)
        return status, self.trainer.output(), self.trainer.errors()

    def assert_for_people(self, out, err):
        for line in (out + err).splitlines():
            self.assertNotRegex(line, SPDLOG_LINE, "a log line in the library's own format")
            self.assertFalse(line.startswith("box "), "a box line without CALLIGRAPHY_PRINT_BOXES: " + line)
            self.assertNotRegex(line, r"\bnan\b", line)
        self.assertEqual(out, "", "train prints nothing on standard output")

    def panel_text(self, *args):
        """`train ARGS --screenshot` to its end, with the panel's text of the picture at the end written to a file
        (CALLIGRAPHY_PANEL_TEXT, docs/trainer.md); returns that text, stdout and stderr."""
        text = pathlib.Path(self.folder) / "panel.txt"
        environment = dict(os.environ, CALLIGRAPHY_PANEL_TEXT=str(text))
        self.trainer = Trainer(*args, "--screenshot", "panel.png", folder=self.folder, environment=environment)
        status = self.trainer.wait(timeout=60)
        self.assertEqual(status, 0, self.trainer.errors())
        self.assertTrue(text.exists(), "no panel text: " + self.trainer.errors())
        return text.read_text(encoding="utf-8"), self.trainer.output(), self.trainer.errors()

    def test_the_learner_view_speaks_to_a_learner_and_says_what_to_do_with_a_mouse(self):
        panel, out, err = self.panel_text("一", "--device", "mouse", "--data", SAMPLE, "--exit-after", "1.5")
        self.assert_for_people(out, err)
        self.assertIn("Hold the left mouse button and draw each stroke; a mouse cannot push back, so nothing is "
                      "felt.", panel)
        self.assertIn("Stroke 1 of 1", panel)
        for word in (r"\bSS\b", r"\bAS\b", r"\bCS\b", r"\bWS\b", r"\btick\b", r"\belement\b",
                     r"guidance on", r"\bN\b.*\bnormal\b"):
            self.assertNotRegex(panel, word, "an engineer's term in the learner's view:\n" + panel)

    def test_the_engineer_view_shows_states_ticks_elements_and_forces(self):
        panel, out, err = self.panel_text("一", "--device", "mouse", "--data", SAMPLE, "--exit-after", "1.5",
                                          "--engineer")
        self.assert_for_people(out, err)
        self.assertRegex(panel, r"\b(SS|AS|CS|WS)\b")
        self.assertRegex(panel, r"\btick \d+")
        self.assertRegex(panel, r"\belement \d+")
        self.assertIn("force in plane", panel)
        self.assertNotIn("guidance on", panel, "a mouse feels no guidance:\n" + panel)
        self.assertIn("vision, no force output: guidance not felt", panel)

    def test_the_stroke_order_is_shown_before_writing_and_no_trial_runs_meanwhile(self):
        self.trainer = Trainer("永", "--device", "mouse", "--screenshot", "demo.png", folder=self.folder,
                               environment=boxes_environment())
        (box,) = self.trainer.boxes()
        self.trainer.wait_for("calligraphy train: demonstrating the stroke order of 永 (5 strokes")
        # 0.5 s pause, the dot (at least 0.25 s), 0.5 s pause, then stroke 2 for over a second: at 1.2 s the dot
        # is drawn and the demonstration still runs (4.6 s in all).
        time.sleep(1.2)
        window = self.trainer.window()
        xdotool("windowfocus", "--sync", window)
        press_quit(window, self.trainer)
        self.assertEqual(self.trainer.wait(timeout=30), 0, self.trainer.errors())
        self.assertNotIn("trial 1", self.trainer.errors(), "a trial ran during the demonstration")
        self.assertEqual(self.trainer.output(), "")
        picture = pathlib.Path(self.folder) / "demo.png"
        keep_artifact(picture)
        image = read_png(picture)
        dot = medians("永")[0]
        ink = [near(image, box.data_to_px(p), 4, is_demo_ink) for p in along(dot, [i / 10 for i in range(2, 9)])]
        self.assertGreater(fraction(ink), 0.9, "stroke 1 drawn in the demonstration's ink")
        x, y = box.data_to_px(dot[0])
        self.assertTrue(near(image, (x - 16, y - 16), 12, is_red), "stroke 1 numbered at its start")
        inside = [(x, y) for x in range(int(box.x), int(box.x + box.size), 6)
                  for y in range(int(box.y), int(box.y + box.size), 6)]
        self.assertFalse(any(is_blue(*image.pixel(x, y)) for x, y in inside),
                         "no reference and no trial drawn during the demonstration")

    def test_d_ends_the_trial_and_demonstrates_the_stroke_order(self):
        text = pathlib.Path(self.folder) / "panel.txt"
        environment = boxes_environment(dict(os.environ, CALLIGRAPHY_PANEL_TEXT=str(text)))
        self.trainer = Trainer("十", "--device", "mouse", "--no-demo", "--screenshot", "demo.png", folder=self.folder,
                               environment=environment)
        self.trainer.boxes()
        self.assertNotIn("demonstrating", self.trainer.errors(), "--no-demo: writing starts at once")
        window = self.trainer.window()
        xdotool("windowfocus", "--sync", window)
        xdotool("key", "--window", window, "d")
        self.trainer.wait_for("trial 1 十: interrupted by D (demonstration)")
        self.trainer.wait_for("calligraphy train: demonstrating the stroke order of 十")
        press_quit(window, self.trainer)
        self.assertEqual(self.trainer.wait(timeout=30), 0, self.trainer.errors())
        keep_artifact(pathlib.Path(self.folder) / "demo.png")
        panel = text.read_text(encoding="utf-8")
        self.assertRegex(panel, r"Watch: Stroke [12] of 2")
        self.assertNotIn("trial 2", self.trainer.errors(), "no trial runs during the demonstration")

    def test_a_trial_stopped_by_exit_after_says_what_it_wrote_and_kept(self):
        status, out, err = self.run_train("永", "--writer", "simulated", "--session", "out", "--exit-after", "4")
        self.assertEqual(status, 0, err)
        self.assert_for_people(out, err)
        (line,) = [l for l in err.splitlines() if l.startswith("calligraphy train: trial 1 永: ")]
        self.assertIn("interrupted", line)
        self.assertIn("--exit-after", line)
        self.assertRegex(line, r"\b[0-5] of 5 strokes\b")
        (attempt,) = kept_attempts(pathlib.Path(self.folder) / "out")
        self.assertIn("kept as an attempt", line)
        self.assertIn(attempt.name, line)

    def test_a_trial_stopped_before_any_stroke_says_nothing_was_written(self):
        status, out, err = self.run_train("一", "--device", "mouse", "--data", SAMPLE, "--exit-after", "1.5")
        self.assertEqual(status, 0, err)
        self.assert_for_people(out, err)
        (line,) = [l for l in err.splitlines() if l.startswith("calligraphy train: trial 1 一: ")]
        self.assertIn("no stroke written", line)
        self.assertNotIn("mm", line)  # no deviation of strokes never written
        self.assertIn("not saved", line)

    def test_a_quiz_stopped_before_any_stroke_claims_no_verdict(self):
        status, out, err = self.run_train("一", "--device", "mouse", "--data", SAMPLE, "--quiz", "--session", "out",
                                          "--exit-after", "1.5")
        self.assertEqual(status, 0, err)
        self.assert_for_people(out, err)
        self.assertNotRegex(err, r"\b0 live verdicts?\b")
        self.assertNotRegex(err, r"\b1 (live verdicts|misses)\b")
        self.assertIn("no stroke was judged", err)

    def test_the_box_lines_go_to_stderr_when_asked_for(self):
        self.trainer = Trainer("一", "--device", "mouse", "--data", SAMPLE, "--exit-after", "1", folder=self.folder)
        self.assertEqual(self.trainer.wait(timeout=60), 0, self.trainer.errors())
        self.assertEqual(self.trainer.output(), "")
        self.assertEqual(len([l for l in self.trainer.errors().splitlines() if l.startswith("box 0 一 ")]), 1)


class SessionWindowTest(unittest.TestCase):
    """`calligraphy session run` with a device a person moves runs the session in the trainer window."""

    def setUp(self):
        self.folder = pathlib.Path(tempfile.mkdtemp(prefix="calligraphy-session-"))
        (self.folder / "tiny.json").write_text(json.dumps(TINY_PROTOCOL, ensure_ascii=False), encoding="utf-8")
        self.stdout = open(self.folder / "stdout.txt", "w+")
        self.stderr = open(self.folder / "stderr.txt", "w+")
        self.process = None

    def tearDown(self):
        if self.process is not None and self.process.poll() is None:
            self.process.kill()
            self.process.wait()
        self.stdout.close()
        self.stderr.close()
        shutil.rmtree(self.folder, ignore_errors=True)

    def run_session(self, *extra):
        self.process = subprocess.Popen(
            [CLI, "session", "run", "tiny.json", "--subject", "S01", "--device", "mouse-hand", "--writer", "person",
             "--out", "out", "--data", SAMPLE, *extra], stdout=self.stdout, stderr=self.stderr, cwd=self.folder,
            env=boxes_environment())

    def errors(self):
        return (self.folder / "stderr.txt").read_text()

    def first_box(self, timeout=30):
        return box_lines(self.folder, self.process, "the session", timeout)[0]

    def session_folder(self):
        (session,) = (self.folder / "out" / "S01").glob("tiny-*")
        return session

    def test_a_person_writes_the_session_in_the_window_and_every_trial_is_saved(self):
        self.run_session("--exit-after", "90", "--screenshot", "shot.png")
        box = self.first_box()
        window = program_window(self.process.pid)
        median = medians("一", SAMPLE)[0]
        path = [box.data_to_px(p) for p in along(median, [i / 16 for i in range(17)])]
        path.append(box.data_to_px((median[-1][0] + 30, median[-1][1])))
        time.sleep(1.5)  # unattended: the trial starts a second after it is announced
        xdotool("mousemove", "--window", window, round(path[0][0]), round(path[0][1]))
        time.sleep(0.8)  # the hand carries the stylus over the start
        xdotool("mousedown", 1)
        time.sleep(0.8)
        for x, y in path[1:]:
            xdotool("mousemove", "--window", window, round(x), round(y))
            time.sleep(0.1)
        time.sleep(0.5)
        xdotool("mouseup", 1)
        self.assertEqual(self.process.wait(timeout=120), 0, self.errors())
        trials = sorted((self.session_folder() / "trials").glob("*.json"))
        self.assertEqual([t.name for t in trials], ["001-test-vision-r1-U4E00.json", "002-test-haptic-r1-U4E00.json"])
        first, second = (json.loads(t.read_text(encoding="utf-8")) for t in trials)
        self.assertEqual((first["condition"], first["end_reason"], first["strokes_completed"]), ("vision", "completed", 1))
        self.assertFalse(first["force_law"]["guidance"])
        self.assertEqual((second["condition"], second["end_reason"]), ("haptic", "time_limit"))
        self.assertTrue(second["force_law"]["guidance"])
        # The second trial wrote nothing: its line says so, with no deviation ("nan") of strokes never written.
        (line,) = [l for l in self.errors().splitlines() if l.startswith("calligraphy session: trial 2/2 ")]
        self.assertIn("no stroke written", line)
        self.assertNotRegex(self.errors(), r"\bnan\b")
        for record in (first, second):
            self.assertEqual(record["device"]["name"], "mouse-hand")
            self.assertEqual(record["writer"]["kind"], "person")
            self.assertEqual(record["renderer"]["loop"]["stall_timeout_s"], 0.0)  # no motors: no stall bound
        log = [json.loads(l) for l in (self.session_folder() / "log.jsonl").read_text().splitlines()]
        self.assertIn("session_completed", [e["event"] for e in log])
        image = read_png(self.folder / "shot.png")
        inner = along(median, [i / 20 for i in range(2, 19)])
        self.assertGreater(fraction([near(image, box.data_to_px(p), 6, is_blue) for p in inner]), 0.9)
        self.assertGreater(fraction([near(image, box.data_to_px(p), 15, is_yellow) for p in inner]), 0.9)

    def test_a_bundled_character_in_a_session_is_drawn_with_its_outline(self):
        """一 without --data comes from the bundled store, which holds every character's outlines: the session's
        learner panel sends the person to the stroke's yellow outline, as for an embedded character."""
        text = self.folder / "panel.txt"
        self.process = subprocess.Popen(
            [CLI, "session", "run", "tiny.json", "--subject", "S01", "--device", "mouse-hand", "--writer", "person",
             "--out", "out", "--exit-after", "3", "--screenshot", "shot.png"], stdout=self.stdout,
            stderr=self.stderr, cwd=self.folder,
            env=boxes_environment(dict(os.environ, CALLIGRAPHY_PANEL_TEXT=str(text))))
        # Stopped by --exit-after during its first trial: the session is left to resume (exit 1).
        self.assertIn(self.process.wait(timeout=120), (0, 1), self.errors())
        panel = text.read_text(encoding="utf-8")
        self.assertIn("the darker yellow one", panel, panel)
        self.assertNotIn("no stroke outlines", self.errors())

    def test_sigint_ends_the_session_keeping_the_running_trial_as_an_attempt(self):
        self.run_session()  # attended: the first trial waits for Space
        self.first_box()
        window = program_window(self.process.pid)
        time.sleep(0.5)
        xdotool("windowfocus", "--sync", window)
        xdotool("key", "--window", window, "space")
        time.sleep(2.5)
        self.assertIsNone(self.process.poll(), self.errors())
        self.process.send_signal(signal.SIGINT)
        self.assertEqual(self.process.wait(timeout=60), 130, self.errors())
        session = self.session_folder()
        self.assertEqual(list((session / "trials").glob("*.json")), [])
        (attempt,) = (session / "trials" / "attempts").glob("*.json")
        record = json.loads(attempt.read_text(encoding="utf-8"))
        self.assertEqual(record["end_reason"], "interrupted")
        self.assertIn("session resume", self.errors())


class OwnDisplay:
    """A virtual X server of a test's own (Xvfb), to be killed under the program; None where Xvfb cannot
    start."""

    def __init__(self, framebuffer=False):
        """With `framebuffer`, the screen is also kept as an XWD file in a folder of its own (Xvfb -fbdir),
        read by window_image."""
        self.framebuffer = pathlib.Path(tempfile.mkdtemp(prefix="calligraphy-xvfb-")) if framebuffer else None
        extra = ["-fbdir", str(self.framebuffer)] if framebuffer else []
        read, write = os.pipe()
        self.process = subprocess.Popen(["Xvfb", "-displayfd", str(write), "-screen", "0", "1400x900x24",
                                         "-nolisten", "tcp", *extra], pass_fds=(write,), stdout=subprocess.DEVNULL,
                                        stderr=subprocess.DEVNULL)
        os.close(write)
        with os.fdopen(read) as f:
            number = f.readline().strip()
        if not number:
            self.process.wait()
            raise OSError("Xvfb printed no display number")
        self.name = ":" + number
        self.environment = dict(os.environ, DISPLAY=self.name)

    def xdotool(self, *args):
        return subprocess.run(["xdotool", *map(str, args)], check=True, capture_output=True, text=True,
                              env=self.environment).stdout

    def window_image(self, window):
        """What the screen shows of `window` now (window pixels), from the framebuffer file."""
        position = dict(line.strip().split(": ", 1) for line in
                        self.xdotool("getwindowgeometry", window).splitlines()[1:] if ": " in line)
        x, y = (int(v) for v in position["Position"].split()[0].split(","))
        width, height = (int(v) for v in position["Geometry"].split("x"))
        return read_xwd(self.framebuffer / "Xvfb_screen0").crop(x, y, width, height)

    @staticmethod
    def save_png(image, path):
        write_png(path, image)
        return path

    def kill(self):
        if self.process.poll() is None:
            self.process.kill()
            self.process.wait()
        if self.framebuffer is not None:
            shutil.rmtree(self.framebuffer, ignore_errors=True)


def records_and_rows(attempts):
    """The one interrupted attempt's record and its CSV's row count."""
    (record_path,) = attempts
    record = json.loads(record_path.read_text(encoding="utf-8"))
    rows = len(saved_trace_rows(record_path))
    return record, rows


class EndingTest(unittest.TestCase):
    """A lost display, SIGTERM and SIGHUP mid-trial, in `train --session` and in `session run` in the window:
    the servo side stops, the trial is kept whole as an interrupted attempt naming the reason, the session's
    log records the stop with it, and the program exits with the documented status."""

    def setUp(self):
        self.folder = pathlib.Path(tempfile.mkdtemp(prefix="calligraphy-ending-"))
        (self.folder / "tiny.json").write_text(json.dumps(TINY_PROTOCOL, ensure_ascii=False), encoding="utf-8")
        self.stdout = open(self.folder / "stdout.txt", "w+")
        self.stderr = open(self.folder / "stderr.txt", "w+")
        self.process = None
        self.display = None

    def tearDown(self):
        if self.process is not None and self.process.poll() is None:
            self.process.kill()
            self.process.wait()
        if self.display is not None:
            self.display.kill()
        self.stdout.close()
        self.stderr.close()
        shutil.rmtree(self.folder, ignore_errors=True)

    def errors(self):
        return (self.folder / "stderr.txt").read_text()

    def own_display(self):
        try:
            self.display = OwnDisplay()
        except OSError as e:
            self.skipTest(f"no Xvfb of the test's own: {e}")
        return self.display

    def start(self, command, environment=None):
        # SIGHUP at its default whatever this suite runs under (an ignored one stays ignored, as under nohup).
        self.process = subprocess.Popen([CLI, *command], stdout=self.stdout, stderr=self.stderr, cwd=self.folder,
                                        env=boxes_environment(environment),
                                        preexec_fn=lambda: signal.signal(signal.SIGHUP, signal.SIG_DFL))

    def first_box(self, timeout=30):
        return box_lines(self.folder, self.process, "the program", timeout)[0]

    def move_pointer(self, box, tool):
        """The pointer moved a little over the character's box while the trial runs."""
        window = program_window(self.process.pid, tool)
        for k in range(6):
            x, y = box.data_to_px((300 + 40 * k, 500))
            tool("mousemove", "--window", window, round(x), round(y))
            time.sleep(0.15)

    def check_ended(self, status, reason, session, seconds=1.5):
        """Waits for the program's `status` within a few seconds, then checks the kept attempt and the log
        of `session`, a function returning the session folder."""
        started = time.time()
        self.assertEqual(self.process.wait(timeout=10), status, self.errors())
        self.assertLess(time.time() - started, 8.0)
        folder = session()
        self.assertEqual(list((folder / "trials").glob("*.json")), [])
        record, rows = records_and_rows(sorted((folder / "trials" / "attempts").glob("*.json")))
        self.assertEqual(record["end_reason"], "interrupted")
        self.assertTrue(record["aborted"])
        self.assertEqual(record["abort_reason"], "stopped by " + reason)
        self.assertGreater(rows, seconds * 1000 * 0.8)  # the trial ran about `seconds` at 1 kHz
        self.assertEqual(rows, record["loop"]["ticks"])  # every tick kept
        log = [json.loads(l) for l in (folder / "log.jsonl").read_text().splitlines()]
        (stopped,) = [e for e in log if e["event"] == "session_stopped"]
        self.assertEqual(stopped["reason"], reason)
        return log

    def train(self, environment=None):
        self.start(["train", "永", "--device", "mouse", "--session", "out", "--exit-after", "60"], environment)

    def train_session(self):
        (folder,) = (self.folder / "out").glob("anonymous/train-*")
        return folder

    def session_run(self, environment=None):
        # Unattended: the first trial starts a second after it is announced, and lasts up to 8 s.
        self.start(["session", "run", "tiny.json", "--subject", "S01", "--device", "mouse", "--writer", "person",
                    "--out", "out", "--data", SAMPLE, "--exit-after", "60"], environment)

    def study_session(self):
        (folder,) = (self.folder / "out" / "S01").glob("tiny-*")
        return folder

    def test_a_lost_display_ends_train_keeping_the_trial(self):
        display = self.own_display()
        self.train(display.environment)
        self.move_pointer(self.first_box(), display.xdotool)
        time.sleep(1.0)
        self.assertIsNone(self.process.poll(), self.errors())
        display.kill()
        self.check_ended(4, "display_lost", self.train_session)
        self.assertIn(f"the display was lost (X connection to {display.name} broken)", self.errors())

    def test_a_lost_display_ends_the_session_keeping_the_running_trial(self):
        display = self.own_display()
        self.session_run(display.environment)
        box = self.first_box()
        time.sleep(1.5)  # the trial starts
        self.move_pointer(box, display.xdotool)
        time.sleep(0.5)
        self.assertIsNone(self.process.poll(), self.errors())
        display.kill()
        log = self.check_ended(4, "display_lost", self.study_session, seconds=1.0)
        (interrupted,) = [e for e in log if e["event"] == "trial_interrupted"]
        self.assertEqual(interrupted["reason"], "display_lost")

    def signal_ends_train(self, number, name):
        self.train()
        self.move_pointer(self.first_box(), xdotool)
        time.sleep(1.0)
        self.assertIsNone(self.process.poll(), self.errors())
        self.process.send_signal(number)
        self.check_ended(128 + number, name, self.train_session)
        self.assertIn("stopped by " + name, self.errors())

    def signal_ends_the_session(self, number, name):
        self.session_run()
        box = self.first_box()
        time.sleep(1.5)
        self.move_pointer(box, xdotool)
        time.sleep(0.5)
        self.assertIsNone(self.process.poll(), self.errors())
        self.process.send_signal(number)
        log = self.check_ended(128 + number, name, self.study_session, seconds=1.0)
        (interrupted,) = [e for e in log if e["event"] == "trial_interrupted"]
        self.assertEqual(interrupted["reason"], name)

    def test_sigterm_ends_train_keeping_the_trial(self):
        self.signal_ends_train(signal.SIGTERM, "SIGTERM")

    def test_sighup_ends_train_keeping_the_trial(self):
        self.signal_ends_train(signal.SIGHUP, "SIGHUP")

    def test_sigterm_ends_the_session_keeping_the_running_trial(self):
        self.signal_ends_the_session(signal.SIGTERM, "SIGTERM")

    def test_sighup_ends_the_session_keeping_the_running_trial(self):
        self.signal_ends_the_session(signal.SIGHUP, "SIGHUP")


# CTest runs the tests in these groups (tests/CMakeLists.txt), so that no one CTest test runs for minutes.
# A test is in the first group whose pattern its id contains; a test in no group fails the run.
GROUPS = {
    # What a person reads; first, so that its quiz case is not taken by "quiz" below.
    "people": ("PeopleOutputTest",),
    "writing": ("test_simulated_writer", "test_the_real_pointer", "test_guidance_pulls", "test_a_refused_stroke"),
    # A person's hand on each pointer device, its own group each (about 30 s): the first match wins, so the
    # longer name comes first.
    "hand_mouse_hand": ("test_a_hand_writes_shi_kou_ren_yong_on_the_mouse_hand",),
    "hand_mouse": ("test_a_hand_writes_shi_kou_ren_yong_on_the_mouse",),
    "quiz": ("quiz",),
    "keeps_data": ("keeps_the_data", "test_record_then_replay", "test_each_run"),
    "session": ("SessionWindowTest",),
    # Each test ends its program early (a few seconds each): a lost display, then the stop signals.
    "lost_display": ("test_a_lost_display",),
    "stop_signals": ("EndingTest",),
    "openhaptics": ("test_a_haptic_device_writes_yong_through_the_stand_in_libhd",),
    "hint_assist": ("test_misses_bring_the_hint", "test_the_panel_names_the_hinted_stroke",
                    "test_the_miss_counts_given_to_train", "test_a_stroke_never_started_at_its_start"),
}


def group_of(test_id):
    return next((name for name, patterns in GROUPS.items() if any(p in test_id for p in patterns)), None)


def selected_tests(group):
    everything = unittest.defaultTestLoader.loadTestsFromModule(sys.modules[__name__])
    tests = [t for suite in everything for t in suite]
    orphans = [t.id() for t in tests if group_of(t.id()) is None]
    if orphans:
        sys.exit(f"tests in no group of GROUPS: {', '.join(orphans)}")
    return unittest.TestSuite(t for t in tests if group is None or group_of(t.id()) == group)


if __name__ == "__main__":
    try:
        xdotool("getdisplaygeometry")
    except (OSError, subprocess.CalledProcessError) as e:
        print(f"trainer tests skipped: no X server ({e})")
        sys.exit(77)
    group = sys.argv[2] if len(sys.argv) == 3 and sys.argv[1] == "--group" else None
    if group is not None and group not in GROUPS:
        sys.exit(f"no group {group}: the groups are {', '.join(GROUPS)}")
    result = unittest.TextTestRunner(verbosity=2).run(selected_tests(group))
    sys.exit(0 if result.wasSuccessful() and result.testsRun > 0 else 1)
