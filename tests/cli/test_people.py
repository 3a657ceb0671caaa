#!/usr/bin/env python3
"""What a person reads from the `calligraphy` program (docs/cli.md), run by CTest as `cli_people_tests`:
written from the documentation, as a newcomer would try the program.

- standard output carries the command's own lines only; the library's log is shown on standard error as the
  command's own lines (`calligraphy COMMAND: warning: ...`), its info lines only with `--verbose`;
- every option's help states its default once;
- `devices` lists every kind of device and the commands that take it, as a table and in `--json`;
- `score` gives each stroke one verdict, numbers strokes from 1 in its table, and counts that agree.

CALLIGRAPHY_CLI names the program and CALLIGRAPHY_SOURCE_DIR the source tree. Standard library only.
"""
import json
import os
import re
import subprocess
import sys
import tempfile
import unittest
from pathlib import Path

CLI = os.environ.get("CALLIGRAPHY_CLI", "")
SOURCE = Path(os.environ.get("CALLIGRAPHY_SOURCE_DIR", Path(__file__).resolve().parents[2]))
DATA = SOURCE / "data" / "hanzi-writer-data"

# spdlog's own pattern: "[2026-11-26 12:00:00.000] [calligraphy] [info] ..."
SPDLOG_LINE = re.compile(r"^\[\d{4}-\d\d-\d\d |\[calligraphy\]|\[(trace|debug|info|warning|error|critical)\]")
CHARACTER_SIZE_M = 0.06  # a character's box on the paper (SceneLayout)


class PeopleTestCase(unittest.TestCase):
    def setUp(self):
        if not CLI or not Path(CLI).exists():
            self.fail(f"CALLIGRAPHY_CLI={CLI!r} is not the calligraphy program: run these tests through ctest")
        self.folder = tempfile.TemporaryDirectory(prefix="calligraphy-people-")
        self.cwd = Path(self.folder.name)

    def tearDown(self):
        self.folder.cleanup()

    def run_cli(self, *args, timeout=120):
        result = subprocess.run([CLI, *map(str, args)], cwd=self.cwd, stdout=subprocess.PIPE,
                                stderr=subprocess.PIPE, timeout=timeout)
        return result.returncode, result.stdout.decode(), result.stderr.decode()

    def assert_no_spdlog_line(self, text, where):
        for line in text.splitlines():
            self.assertNotRegex(line, SPDLOG_LINE, f"{where}: a log line of the library's own format")


def commands_of(run_cli, command=()):
    """Every command of the program, found by walking each group's --help ("Subcommands:")."""
    _, text, _ = run_cli(*command, "--help")
    found = []
    if "Subcommands:" in text:
        block = text.split("Subcommands:", 1)[1]
        for line in block.splitlines()[1:] if block.startswith("\n") else block.splitlines():
            match = re.match(r"^  ([a-z][a-z-]*)\b", line)
            if match:
                found += commands_of(run_cli, (*command, match.group(1)))
            elif line.strip() and not line.startswith(" "):
                break
    return found or [command]


class TheLibrarysLog(PeopleTestCase):
    def test_a_library_warning_is_one_line_of_the_command(self):
        # The emulated Phantom's driver warns at every open() what was never checked on hardware.
        status, out, err = self.run_cli("trial", "乙", "--device", "emulated-phantom")
        self.assertEqual(status, 0, err)
        self.assert_no_spdlog_line(out, "stdout")
        self.assert_no_spdlog_line(err, "stderr")
        warnings = [l for l in err.splitlines() if "NOT verified" in l]
        self.assertEqual(len(warnings), 1, err)
        self.assertTrue(warnings[0].startswith("calligraphy trial: warning: Phantom: "), warnings[0])
        # Info lines (the driver opening the arm) are quiet unless asked for.
        self.assertNotIn("opening", err)
        status, _, verbose = self.run_cli("trial", "乙", "--device", "emulated-phantom", "--verbose")
        self.assertEqual(status, 0, verbose)
        self.assert_no_spdlog_line(verbose, "stderr with --verbose")
        self.assertTrue(any(l.startswith("calligraphy trial: info: Phantom: opening") for l in verbose.splitlines()),
                        verbose)

    def test_the_servo_loop_statistics_only_when_asked(self):
        status, out, err = self.run_cli("bench", "loop", "--seconds", "0.2")
        self.assertEqual(status, 0, err)
        self.assert_no_spdlog_line(out + err, "bench loop")
        # Its statistics are info lines; a late tick on a busy machine is a warning, and may be said.
        self.assertNotIn(": info: ", err)
        status, out, err = self.run_cli("bench", "loop", "--seconds", "0.2", "--verbose")
        self.assertEqual(status, 0, err)
        self.assert_no_spdlog_line(out + err, "bench loop --verbose")
        self.assertIn("calligraphy bench loop: info: servo loop: ", err)

    def test_every_command_takes_verbose(self):
        for command in commands_of(self.run_cli):
            _, text, _ = self.run_cli(*command, "--help")
            self.assertRegex(text, r"(?m)^  --verbose\b", f"{command}: no --verbose in its help")

    def test_json_on_standard_output_stays_json(self):
        status, out, err = self.run_cli("trial", "乙", "--device", "emulated-phantom", "--verbose", "--json", "-")
        self.assertEqual(status, 0, err)
        json.loads(out)  # nothing else on standard output


class OneDefaultPerOption(PeopleTestCase):
    def test_every_option_states_its_default_once(self):
        commands = commands_of(self.run_cli)
        self.assertGreater(len(commands), 15, commands)
        for command in commands:
            status, text, err = self.run_cli(*command, "--help")
            self.assertEqual(status, 0, f"{command}: {err}")
            entries = re.findall(r"^  (-[-a-zA-Z]+.*(?:\n {10,}.*)*)", text, flags=re.M)
            for entry in entries:
                flat = " ".join(entry.split())
                defaults = re.findall(r"\bdefaults?\b", flat, flags=re.I)
                self.assertLessEqual(len(defaults), 1, f"{' '.join(command)}: two defaults in: {flat}")


class EveryKindOfDevice(PeopleTestCase):
    KINDS = ("simulated", "emulated-phantom", "mouse", "mouse-hand")

    def kinds(self):
        status, out, err = self.run_cli("devices", "--json")
        self.assertEqual(status, 0, err)
        listing = json.loads(out)
        self.assertIn("kinds", listing)
        return {kind["name"]: kind for kind in listing["kinds"]}

    def test_json_names_every_kind_and_the_commands_that_take_it(self):
        kinds = self.kinds()
        # A build without the trainer window (the sanitizer builds) lists the pointer kinds and says why no
        # command takes them.
        window = "not in this build" not in kinds["mouse"]["what"]
        for name in self.KINDS:
            self.assertIn(name, kinds)
            if window or name not in ("mouse", "mouse-hand"):
                self.assertTrue(kinds[name]["commands"], name)
            self.assertTrue(kinds[name]["what"], name)
        for name in ("mouse", "mouse-hand"):
            if window:
                self.assertIn("train", kinds[name]["commands"])
                self.assertIn("session run", kinds[name]["commands"])
            else:
                self.assertEqual(kinds[name]["commands"], [], name)
                self.assertIn("no trainer window", kinds[name]["what"])
            self.assertNotIn("trial", kinds[name]["commands"])
        for name in ("simulated", "emulated-phantom"):
            for command in ("trial", "train", "session run"):
                if window or command != "train":  # without the window no kind lists train
                    self.assertIn(command, kinds[name]["commands"], name)
            if not window:
                self.assertNotIn("train", kinds[name]["commands"], name)
        # Every backend of the registry is a kind, whether or not a device of it is found here.
        for backend in ("phantom-hid", "phantom-usb", "openhaptics"):
            self.assertTrue(any(k["backend"] == backend for k in kinds.values()), backend)

    def test_the_table_names_the_same_kinds(self):
        status, out, err = self.run_cli("devices")
        self.assertEqual(status, 0, err)
        self.assertIn("Kinds of device", out)
        table = out.split("Kinds of device", 1)[1]
        for name, kind in self.kinds().items():
            row = [l for l in table.splitlines() if l.split()[:1] == [name]]
            self.assertEqual(len(row), 1, f"{name}: no one row in\n{out}")
            for command in kind["commands"]:
                self.assertIn(command, row[0], name)

    def test_what_the_listing_says_trial_takes_it_takes(self):
        kinds = self.kinds()
        for name in ("mouse", "mouse-hand", "simulated"):
            status, _, err = self.run_cli("trial", "乙", "--device", name, "--max-duration", "0.05")
            if "trial" in kinds[name]["commands"]:
                self.assertNotEqual(status, 2, f"{name}: {err}")
            else:
                self.assertEqual(status, 2, f"{name}: {err}")


def median_trace(medians, offsets):
    """A CSV pen trace in data units along the medians (pen down along each stroke in order, lifted between),
    each stroke moved by its (dx, dy) in `offsets`."""
    rows, t = ["t,x,y,pen"], 0.0
    for index, median in enumerate(medians):
        dx, dy = offsets.get(index, (0.0, 0.0))
        points = []
        for (ax, ay), (bx, by) in zip(median, median[1:]):
            steps = max(1, int(((bx - ax) ** 2 + (by - ay) ** 2) ** 0.5 / 4))
            points += [(ax + (bx - ax) * k / steps, ay + (by - ay) * k / steps) for k in range(steps)]
        points.append(tuple(median[-1]))
        for x, y in points:
            rows.append(f"{t:.3f},{x + dx:.4f},{y + dy:.4f},1")
            t += 0.01
        rows.append(f"{t:.3f},{points[-1][0] + dx:.4f},{points[-1][1] + dy:.4f},0")
        t += 0.3
    return "\n".join(rows) + "\n"


class TheTrialsTable(PeopleTestCase):
    """`trial`'s table numbers strokes as `score`'s does: from 1, where the JSON counts from 0."""

    def test_strokes_are_numbered_from_one_and_the_json_from_zero(self):
        status, text, err = self.run_cli("trial", "十", "--seed", "3", "--json", "t.json")
        self.assertEqual(status, 0, err)
        rows = [l for l in text.splitlines() if re.match(r"^\s*\d+\s+十", l)]
        self.assertEqual([int(r.split()[0]) for r in rows], [1, 2], text)
        self.assertIn("strokes numbered from 1 here, from 0 in the JSON", text)
        record = json.loads((self.cwd / "t.json").read_text())
        self.assertEqual([s["index"] for s in record["renderer_strokes"]], [0, 1])


class TheTeachersScore(PeopleTestCase):
    """十: a horizontal stroke written 4 mm too high, then its vertical stroke well."""

    def score(self):
        medians = json.loads((DATA / "十.json").read_text(encoding="utf-8"))["medians"]
        four_mm = 4e-3 * 1024 / CHARACTER_SIZE_M
        (self.cwd / "t.csv").write_text(median_trace(medians, {0: (0.0, four_mm)}))
        status, out, err = self.run_cli("score", "t.csv", "--character", "十", "--units", "data",
                                        "--json", "s.json")
        self.assertEqual(status, 0, err)
        return out, json.loads((self.cwd / "s.json").read_text())

    def stroke_rows(self, text):
        """The rows of the per-stroke table: lines starting with a stroke number."""
        return [l for l in text.splitlines() if re.match(r"^\s*\d+\s", l)]

    def test_each_stroke_has_one_verdict_numbered_from_one(self):
        text, score = self.score()
        rows = self.stroke_rows(text)
        self.assertEqual([int(r.split()[0]) for r in rows], [1, 2], text)
        # Stroke 1: refused for its place, with how far off it was; never "not written" beside that.
        self.assertRegex(rows[0], r"refused", text)
        self.assertRegex(rows[0], r"wrong place", text)
        off = re.search(r"\((\d+\.\d) mm off\)", rows[0])
        self.assertIsNotNone(off, text)
        self.assertLess(abs(float(off.group(1)) - 4.0), 0.5, text)  # the median is not the fitted stroke
        # The same deviation as the JSON's verdict on that pen-down.
        (first,) = [s for s in score["per_character"][0]["segments"] if s["verdict"]][:1]
        self.assertEqual(off.group(1), "%.1f" % (first["verdict"]["mean_deviation_m"] * 1e3))
        self.assertNotRegex(rows[0], r"\bno\b", text)
        # Stroke 2: refused, written before stroke 1 was accepted.
        self.assertRegex(rows[1], r"refused", text)
        self.assertRegex(rows[1], r"wrong order", text)
        # The JSON keeps its documented numbering from 0.
        strokes = score["per_character"][0]["per_stroke"]
        self.assertEqual([s["index"] for s in strokes], [0, 1])

    def test_the_counts_agree(self):
        text, score = self.score()
        rows = self.stroke_rows(text)
        refused_rows = sum("refused" in r for r in rows)
        accepted_rows = sum("accepted" in r for r in rows)
        accepted = re.search(r"(?m)^\s*strokes accepted\s+(\d+) of (\d+)", text)
        refused = re.search(r"(?m)^\s*strokes refused\s+(\d+)", text)
        self.assertIsNotNone(accepted, text)
        self.assertIsNotNone(refused, text)
        self.assertEqual(int(accepted.group(1)), accepted_rows, text)
        self.assertEqual(int(accepted.group(2)), len(rows), text)
        self.assertEqual(int(refused.group(1)), refused_rows, text)
        self.assertEqual(score["strokes_accepted"], accepted_rows)
        # No line says there was no order error while a stroke was refused for its order.
        for line in text.splitlines():
            if re.match(r"^\s*order errors\s+0\b", line):
                self.assertFalse(any("wrong order" in r for r in rows), text)

    def test_a_good_trace_is_accepted_stroke_by_stroke(self):
        medians = json.loads((DATA / "十.json").read_text(encoding="utf-8"))["medians"]
        (self.cwd / "t.csv").write_text(median_trace(medians, {}))
        status, text, err = self.run_cli("score", "t.csv", "--character", "十", "--units", "data")
        self.assertEqual(status, 0, err)
        rows = self.stroke_rows(text)
        self.assertEqual(len(rows), 2, text)
        for row in rows:
            self.assertIn("accepted", row)
            self.assertNotIn("refused", row)
        self.assertRegex(text, r"(?m)^\s*strokes accepted\s+2 of 2")
        self.assertRegex(text, r"(?m)^\s*strokes refused\s+0")


if __name__ == "__main__":
    program = unittest.main(exit=False, verbosity=2)
    result = program.result
    sys.exit(0 if result.wasSuccessful() and result.testsRun > 0 else 1)
