#!/usr/bin/env python3
"""Round 28C: what `score`, `trial`, `model`, `characters` and `devices` tell a teacher and a learner. From the
docs alone (docs/cli.md: Conventions, "Standard output", "The library's log", `trial`, "Stopping a trial",
"Re-running a trial", `score`, `model`, `characters`, `devices`; docs/metrics.md; docs/stroke-acceptance.md;
docs/corpus.md "The bundled store"; docs/devices.md; every command's `--help`).

Each line printed for a person is held to the same command's `--json` and to the other commands: stroke
numbers (from 1 in every table and on the model's SVG, from 0 in the JSON, the same numbers for the same
stroke on every surface), units (mm in the tables, m in the JSON), `score`'s one verdict per stroke (accepted,
assisted, refused and why, with how far off, or not written) and its totals (accepted + assisted + refused +
not written = the strokes; pen-downs refused by reason = the JSON's `refusals`; order errors apart from the
`wrong_order` refusals), trials ended early by the time limit (before the pen touched, in the middle of a
stroke) and by SIGINT (no "nan", no time of writing when nothing was written, no stroke accepted that was never
lifted), standard output holding only the command's lines and standard error one line per warning,
`characters` (stroke counts, typical strokes in every spelling, mixed texts, duplicates, white space, a huge and
an empty text), characters outside the 58 embedded ones with no corpus folder anywhere, `devices` (table and
JSON, every kind and its commands) and one default per option in every `--help`.

Traces are written by hand with numpy along the data's medians of 十 (Python's `Scene`, PlacedStroke.median_m).

CALLIGRAPHY_CLI names the program; PYTHONPATH the built Python package. CALLIGRAPHY_SANITIZED=1 takes five cases.
"""
import itertools
import json
import re
import shutil
import signal
import subprocess
import tempfile
import time
import unittest
from pathlib import Path

from outsider import CLI, ENV, OneErrorLine, run, run_ok, sanitized_subset

try:
    import numpy as np
    import outsider_pen
    import calligraphy as cg
except ImportError:  # reported by setUpClass: the traces need numpy and the package's medians
    np = cg = None


def along(median, offset=(0.0, 0.0), fraction=1.0, n=300):
    """`n` points along a median [m] (outsider_pen.along, this round's density)."""
    return outsider_pen.along(median, offset, fraction, n)


def write_trace(path, ticks):
    outsider_pen.write_trace(path, ticks)

load_tests = sanitized_subset({"test_score_table_and_json_agree_on_a_stroke_written_4_mm_off",
                               "test_score_table_and_json_agree_on_strokes_written_out_of_order",
                               "test_trial_that_wrote_nothing_reports_no_time_of_writing",
                               "test_trial_cut_mid_stroke_accepts_no_stroke_it_did_not_complete",
                               "test_devices_table_and_json_list_the_same_kinds_and_commands"})

RATE_HZ = 1000.0
HOVER_M = 0.002        # above the 0.5 mm contact threshold: the pen is lifted
DOWN_M = -0.0003       # on the paper
TOTAL_KEYS = ("strokes accepted", "strokes assisted", "strokes refused", "strokes not written",
              "pen-downs refused", "pen-downs unmatched", "strokes matched", "mean deviation", "max deviation",
              "RMS deviation", "Frechet (worst stroke)", "DTW (mean)", "pen lifts", "time", "mean speed",
              "velocity peaks", "normalised jerk", "strokes completed", "accepted in turn", "trial time",
              "state transitions", "max |F|", "max per-tick |dF|")
# docs/cli.md, "devices": every kind, who writes on it and the commands that take it with --device.
DOC_KINDS = {
    "simulated": ("simulated", ["trial", "train", "session run"]),
    "emulated-phantom": ("simulated", ["trial", "train", "session run"]),
    "mouse": ("person", ["train", "session run"]),
    "mouse-hand": ("person", ["train", "session run"]),
    "openhaptics": ("person", ["trial", "train", "session run"]),
    "phantom-hid:PATH": ("person", ["trial", "train", "session run"]),
    "phantom-usb:BUS-ADDRESS": ("person", ["trial", "train", "session run"]),
}
COMMANDS = [[], ["trial"], ["train"], ["score"], ["trace"], ["model"], ["strokes"], ["schema"], ["characters"],
            ["devices"], ["corpus", "build"], ["corpus", "stats"], ["corpus", "fidelity"],
            ["corpus", "validate"], ["bench", "nearest"], ["bench", "jumps"], ["bench", "tick"],
            ["bench", "loop"], ["bench", "acceptance"], ["session", "run"], ["session", "resume"],
            ["session", "plan"], ["session", "cohort"], ["report"], ["curriculum"]]


def pen_path(medians, plan):
    """Ticks (t, x, y, z) at 1 kHz of a pen writing `plan`, a list of (stroke, offset [m], fraction; a negative
    fraction: from the stroke's end), each pen-down set down and lifted straight up, carried through the air."""
    points, here = [], None
    for k, offset, fraction in plan:
        median = np.asarray(medians[k])
        p = along(median if fraction > 0 else median[::-1], offset, abs(fraction))
        if here is not None:
            points += [(*(here * (1 - a) + p[0] * a), HOVER_M) for a in np.linspace(0, 1, 100)]
        points += [(*p[0], HOVER_M * (1 - a) + DOWN_M * a) for a in np.linspace(0, 1, 30)]
        points += [(*q, DOWN_M) for q in p]
        points += [(*p[-1], DOWN_M * (1 - a) + HOVER_M * a) for a in np.linspace(0, 1, 30)]
        here = p[-1]
    xyz = np.array(points)
    return np.column_stack([np.arange(len(xyz)) / RATE_HZ, xyz])


def distance_to_polyline(points, polyline):
    """Each point's distance [m] to the polyline."""
    best = np.full(len(points), np.inf)
    for a, b in zip(polyline[:-1], polyline[1:]):
        ab = b - a
        t = np.clip(((points - a) @ ab) / (ab @ ab), 0.0, 1.0)
        best = np.minimum(best, np.linalg.norm(points - (a + t[:, None] * ab), axis=1))
    return best


SCORE_ROW = re.compile(r"^  (\d+)\s+(\S+)\s+(\d+)\s+(\S+)\s+(\S+)\s+(\S+)\s+(\S+)\s+(\S+)\s+(\S.*)$")
TRIAL_ROW = re.compile(r"^  (\d+)\s+(\S)\s+(\S+)\s+(\d+)\s+(\S+)\s+(\S+)\s+(\S+)\s+(\S+)\s+(\S+)\s+(\d+)\s+(\S+)$")


def sections(text):
    """`score`'s table per character: [(character or None for a single one, rows, totals)], rows a list of
    (number, type, id, mean, max, frechet, dtw, time, verdict) texts and totals {key: value text}."""
    found, rows, said, name = [], None, None, None
    for line in text.splitlines():
        if line.strip() and not line.startswith(" "):
            if len(line.strip()) == 1:
                name = line.strip()
            else:       # the header, or the totals of every character ("All 2 characters")
                rows = None
            continue
        if line.startswith("  stroke "):
            rows, said = [], {}
            found.append((name, rows, said))
            continue
        if rows is None:
            continue
        m = SCORE_ROW.match(line)
        if m and not said:
            rows.append(m.groups())
            continue
        for key in TOTAL_KEYS:
            if line.startswith("  " + key + "  "):
                said[key] = line[len(key) + 2:].strip()
    return found


def trial_table(text):
    """`trial`'s table: rows (number, char, type, id, mean, max, frechet, dtw, time, attempts, completed) and
    totals {key: value text}."""
    rows, said = [], {}
    for line in text.splitlines():
        m = TRIAL_ROW.match(line)
        if m:
            rows.append(m.groups())
            continue
        for key in TOTAL_KEYS:
            if line.startswith("  " + key + "  "):
                said[key] = line[len(key) + 2:].strip()
    return rows, said


def by_reason(text):
    """`(wrong place 1, backwards 2)` of a total line as {"wrong_place": 1, "backwards": 2}."""
    m = re.search(r"\(([^)]*)\)", text)
    counts = {}
    if m:
        for part in m.group(1).split(","):
            words = part.strip().rsplit(" ", 1)
            if len(words) == 2 and words[1].isdigit():
                counts[words[0].replace(" ", "_")] = int(words[1])
    return counts


def no_corpus_env(home):
    """The program's environment with no corpus folder anywhere: no CALLIGRAPHY_CORPUS_DIR, HOME and
    XDG_CACHE_HOME an empty folder."""
    env = {k: v for k, v in ENV.items() if k != "CALLIGRAPHY_CORPUS_DIR"}
    env["HOME"] = str(home)
    env["XDG_CACHE_HOME"] = str(home)
    return env


class Round28C(unittest.TestCase, OneErrorLine):
    @classmethod
    def setUpClass(cls):
        if cg is None:
            raise unittest.SkipTest("numpy and the calligraphy Python package (PYTHONPATH) are needed")
        cls.tmp = Path(tempfile.mkdtemp(prefix="round28c-"))
        (cls.tmp / "home").mkdir()
        cls.medians = [np.asarray(s.median_m) for s in cg.Scene("十").characters[0].strokes]
        plans = {
            "off4": [(0, (0.0, 0.004), 1.0)],                         # stroke 1 4 mm across, then nothing
            "off8": [(0, (0.0, 0.008), 1.0)],                         # never within the 5 mm start radius
            "order": [(1, (0.0, 0.0), 1.0), (0, (0.0, 0.0), 1.0)],    # stroke 2 first, then stroke 1
            "back2": [(1, (0.0, 0.0), -1.0), (0, (0.0, 0.0), 1.0)],   # stroke 2 backwards first, then 1
            "missing": [(0, (0.0, 0.0), 1.0)],                        # stroke 2 left out
            "back5": [(0, (0.0, 0.0), -1.0)] * 5 + [(1, (0.0, 0.0), 1.0)],  # 5 backwards: assisted
            "half": [(0, (0.0, 0.0), 0.4)],                           # lifted at 40 %
        }
        for name, plan in plans.items():
            write_trace(cls.tmp / f"{name}.csv", pen_path(cls.medians, plan))
        cls.scored = {}

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.tmp, ignore_errors=True)

    def cli(self, *args, env=None):
        return run(list(args), self.tmp, env=env)

    def score(self, name):
        """`score NAME.csv --character 十 --json NAME.json` once: (its table text, its JSON, its stderr)."""
        if name not in self.scored:
            result = run_ok(["score", f"{name}.csv", "--character", "十", "--json", f"{name}.json"], self.tmp)
            self.scored[name] = (result.stdout.decode("utf-8"),
                                 json.loads((self.tmp / f"{name}.json").read_text(encoding="utf-8")),
                                 result.stderr.decode("utf-8", "replace"))
        return self.scored[name]

    # ---- score: one verdict per stroke, its table and its JSON ------------------------------------------------
    def assert_table_is_json(self, name):
        """Rows and totals of the table against the JSON: stroke numbers 1..N, mm = m x 1000, the totals add
        up. Returns (verdicts per stroke, JSON)."""
        text, scored, err = self.score(name)
        self.assertEqual(err, "", "score with its defaults into a pipe writes nothing on standard error")
        self.assertNotIn("nan", text.lower())
        found = sections(text)
        self.assertEqual(len(found), 1, text)
        _, rows, said = found[0]
        character = scored["per_character"][0]
        strokes = character["per_stroke"]
        self.assertEqual([int(r[0]) for r in rows], list(range(1, len(strokes) + 1)), text)
        for row, stroke in zip(rows, strokes):
            self.assertEqual(int(row[2]), stroke["typical_id"])
            for text_value, key, places in ((row[3], "mean_deviation_m", 2), (row[4], "max_deviation_m", 2),
                                            (row[5], "frechet_m", 2), (row[6], "dtw_m", 2)):
                if stroke[key] is None:
                    self.assertEqual(text_value, "-", (key, row))
                else:
                    self.assertAlmostEqual(float(text_value), stroke[key] * 1000, delta=0.006, msg=(key, row))
            if stroke["time_s"] is None:
                self.assertEqual(row[7], "-")
            else:
                self.assertAlmostEqual(float(row[7]), stroke["time_s"], delta=0.006)
            self.assertEqual(row[8].startswith("assisted"), stroke["assisted"], row)
        verdicts = [r[8] for r in rows]
        # Totals: accepted, assisted, refused (by reason) and not written add up to the strokes.
        accepted = int(said["strokes accepted"].split()[0])
        assisted = int(said.get("strokes assisted", "0").split()[0])
        refused = int(said["strokes refused"].split()[0])
        not_written = int(said["strokes not written"].split()[0])
        self.assertEqual(accepted + assisted + refused + not_written, scored["strokes_total"], text)
        self.assertEqual(said["strokes accepted"].split()[:3], [str(scored["strokes_accepted"]), "of",
                                                                  str(scored["strokes_total"])])
        self.assertEqual(assisted, scored["strokes_assisted"])
        self.assertEqual(accepted, sum(v == "accepted" for v in verdicts))
        self.assertEqual(refused, sum(v.startswith("refused") for v in verdicts))
        self.assertEqual(not_written, sum(v == "not written" for v in verdicts))
        self.assertEqual(sum(by_reason(said["strokes refused"]).values()), refused, said)
        # Pen-downs refused by reason: the JSON's refusals.
        refusals = {k: v for k, v in scored["refusals"].items() if v}
        self.assertEqual(int(said["pen-downs refused"].split()[0]), sum(refusals.values()))
        self.assertEqual(by_reason(said["pen-downs refused"]), refusals, said)
        unmatched = re.match(r"(\d+), too short to score (\d+)$", said["pen-downs unmatched"])
        self.assertIsNotNone(unmatched, said)
        self.assertEqual(int(unmatched.group(1)), scored["unmatched_segments"])
        self.assertEqual(int(unmatched.group(2)), character["ignored_segments"])
        self.assertEqual(int(said["strokes matched"].split()[0]), scored["strokes_written"])
        # Units: mm in the table, m in the JSON; seconds both.
        for key, json_key in (("mean deviation", "mean_deviation_m"), ("max deviation", "max_deviation_m"),
                              ("RMS deviation", "rms_deviation_m"), ("Frechet (worst stroke)", "frechet_m"),
                              ("DTW (mean)", "dtw_m")):
            if scored[json_key] is None:
                self.assertEqual(said[key], "-")
            else:
                self.assertTrue(said[key].endswith(" mm"), said[key])
                self.assertAlmostEqual(float(said[key].split()[0]), scored[json_key] * 1000, delta=0.0006)
        times = re.match(r"(\S+) s \(pen down (\S+) s, in the air (\S+) s\)$", said["time"])
        self.assertIsNotNone(times, said["time"])
        self.assertAlmostEqual(float(times.group(1)), scored["total_time_s"], delta=0.006)
        self.assertAlmostEqual(float(times.group(2)), scored["pen_down_time_s"], delta=0.006)
        self.assertAlmostEqual(float(times.group(3)), character["in_air_time_s"], delta=0.006)
        self.assertEqual(int(said["pen lifts"]), character["pen_lifts"])
        self.assertEqual(int(said["velocity peaks"]), scored["velocity_peaks"])
        return verdicts, scored

    def off_mm(self, verdict):
        """The `X mm off` of a verdict, or None for `never near its start`."""
        if "never near its start" in verdict:
            return None
        m = re.search(r"(\d+\.\d) mm off", verdict)
        self.assertIsNotNone(m, verdict)
        return float(m.group(1))

    def test_score_table_and_json_agree_on_a_stroke_written_4_mm_off(self):
        verdicts, scored = self.assert_table_is_json("off4")
        self.assertEqual(verdicts[1], "not written")
        self.assertTrue(verdicts[0].startswith("refused: wrong place ("), verdicts)
        segment = [s for s in scored["per_character"][0]["segments"] if s["verdict"]][0]
        self.assertEqual(segment["verdict"]["refusal"], "wrong_place")
        off = self.off_mm(verdicts[0])
        # The verdict's mean distance, printed in mm, is the JSON's in m; and the pen's own distance from the
        # median it was written beside (on the track: the distance from the line, docs/stroke-acceptance.md).
        self.assertAlmostEqual(off, segment["verdict"]["mean_deviation_m"] * 1000, delta=0.051)
        mine = distance_to_polyline(along(self.medians[0], (0.0, 0.004)), self.medians[0]).mean() * 1000
        self.assertAlmostEqual(off, mine, delta=0.3)
        self.assertEqual((scored["strokes_written"], scored["strokes_accepted"], scored["refusals"]["wrong_place"]),
                         (0, 0, 1))

    def test_score_says_never_near_its_start_and_json_null_for_8_mm_off(self):
        verdicts, scored = self.assert_table_is_json("off8")
        self.assertEqual(verdicts, ["refused: wrong place (never near its start)", "not written"])
        segment = [s for s in scored["per_character"][0]["segments"] if s["verdict"]][0]
        self.assertIsNone(segment["verdict"]["mean_deviation_m"])

    def test_score_table_and_json_agree_on_strokes_written_out_of_order(self):
        verdicts, scored = self.assert_table_is_json("order")
        self.assertEqual(verdicts, ["accepted", "refused: wrong order (written while stroke 1 was due)"])
        # Order errors (the assignment) and wrong_order refusals (the verdicts) are two counts.
        self.assertEqual(scored["order_errors"], 1)
        self.assertEqual(scored["refusals"]["wrong_order"], 1)
        self.assertEqual(scored["strokes_written"], 2)
        self.assertFalse(scored["completed_in_order"])
        segments = [s for s in scored["per_character"][0]["segments"] if s["verdict"]]
        self.assertEqual([s["verdict"]["expected_stroke"] for s in segments], [0, 0], "JSON counts from 0")

    def test_score_names_a_later_stroke_written_backwards_as_wrong_place(self):
        verdicts, scored = self.assert_table_is_json("back2")
        self.assertEqual(verdicts, ["accepted", "refused: wrong place (written backwards while stroke 1 was due)"])
        self.assertEqual((scored["order_errors"], scored["backwards_strokes"]), (1, 1))
        self.assertTrue(scored["per_character"][0]["per_stroke"][1]["backwards"])

    def test_score_says_not_written_with_dashes_and_json_nulls_for_a_missing_stroke(self):
        verdicts, scored = self.assert_table_is_json("missing")
        self.assertEqual(verdicts, ["accepted", "not written"])
        missing = scored["per_character"][0]["per_stroke"][1]
        self.assertFalse(missing["written"])
        for key in ("mean_deviation_m", "max_deviation_m", "frechet_m", "dtw_m", "time_s"):
            self.assertIsNone(missing[key], key)
        self.assertEqual(scored["per_character"][0]["missing_strokes"], [1])

    def test_score_says_assisted_with_the_last_refusal_after_five_backwards(self):
        verdicts, scored = self.assert_table_is_json("back5")
        self.assertTrue(verdicts[0].startswith("assisted (last refused: backwards, "), verdicts)
        self.assertEqual(verdicts[1], "accepted")
        due = [s for s in scored["per_character"][0]["segments"] if s["verdict"] and s["verdict"]["assists_due"]]
        self.assertEqual(len(due), 1)
        self.assertEqual(due[0]["verdict"]["refusal"], "backwards")
        self.assertAlmostEqual(self.off_mm(verdicts[0]), due[0]["verdict"]["mean_deviation_m"] * 1000, delta=0.051)
        self.assertEqual((scored["strokes_assisted"], scored["strokes_accepted"], scored["refusals"]["backwards"]),
                         (1, 1, 5))

    def test_score_says_too_short_with_the_share_written(self):
        verdicts, scored = self.assert_table_is_json("half")
        self.assertTrue(verdicts[0].startswith("refused: too short"), verdicts)
        self.assertEqual(verdicts[1], "not written")
        verdict = [s for s in scored["per_character"][0]["segments"] if s["verdict"]][0]["verdict"]
        share = re.search(r"(\d+) % of it", verdicts[0])
        if share:
            self.assertEqual(int(share.group(1)), round(verdict["covered_fraction"] * 100))
        self.assertAlmostEqual(self.off_mm(verdicts[0]), verdict["mean_deviation_m"] * 1000, delta=0.051)

    # ---- trial: its table, its JSON and score's table of its trace -------------------------------------------
    def test_trial_table_is_its_json_and_score_of_its_trace(self):
        result = run_ok(["trial", "十", "--json", "t.json", "--csv", "t.csv"], self.tmp)
        self.assertEqual(result.stderr, b"", "a trial with its defaults prints no warning")
        text = result.stdout.decode("utf-8")
        record = json.loads((self.tmp / "t.json").read_text(encoding="utf-8"))
        rows, said = trial_table(text)
        strokes = record["per_character"][0]["per_stroke"]
        self.assertEqual([int(r[0]) for r in rows], [1, 2])
        for row, stroke, renderer in zip(rows, strokes, record["renderer_strokes"]):
            self.assertEqual(row[1], "十")
            self.assertEqual(int(row[3]), stroke["typical_id"])
            for value, key in zip(row[4:8], ("mean_deviation_m", "max_deviation_m", "frechet_m", "dtw_m")):
                self.assertAlmostEqual(float(value), stroke[key] * 1000, delta=0.006, msg=key)
            self.assertAlmostEqual(float(row[8]), stroke["time_s"], delta=0.006)
            self.assertEqual(int(row[9]), renderer["attempts"])
            self.assertEqual(row[10], "yes" if renderer["completed"] else "no")
        self.assertEqual(said["strokes completed"].split()[:3], [str(record["strokes_completed"]), "/",
                                                                   str(record["strokes_total"])])
        self.assertAlmostEqual(float(said["mean deviation"].split()[0]), record["mean_deviation_m"] * 1000,
                               delta=0.0006)
        self.assertAlmostEqual(float(said["trial time"].split()[0]), record["trial_time_s"], delta=0.006)
        self.assertEqual(int(said["state transitions"]), record["state_transitions"])
        # score of the trial's CSV: the same strokes, numbered the same, the same values in the same units.
        scored = run_ok(["score", "t.csv", "--character", "十"], self.tmp).stdout.decode("utf-8")
        _, score_rows, score_said = sections(scored)[0]
        self.assertEqual([r[:8] for r in score_rows], [(r[0], r[2], *r[3:9]) for r in rows])
        self.assertEqual(score_said["mean deviation"], said["mean deviation"])
        self.assertTrue(score_said["time"].startswith(said["time"].split(" (")[0] + " (pen down "), score_said)

    def test_trial_strokes_of_two_characters_are_numbered_as_score_numbers_them(self):
        # docs/cli.md, trial: "Prints a table per stroke, numbered from 1 as `score` and the trainer number them".
        text = run_ok(["trial", "十二", "--csv", "t2.csv"], self.tmp).stdout.decode("utf-8")
        rows, _ = trial_table(text)
        scored = run_ok(["score", "t2.csv", "--character", "十二"], self.tmp).stdout.decode("utf-8")
        score_numbers = [(name, int(r[0])) for name, score_rows, _ in sections(scored)
                         if name is not None for r in score_rows]
        self.assertEqual(len(score_numbers), 4, scored)
        trial_numbers = [(r[1], int(r[0])) for r in rows]
        self.assertEqual(trial_numbers, score_numbers,
                         "the same stroke has the same number in trial's table and in score's")

    def test_trial_with_assisted_strokes_says_so_in_table_and_json(self):
        result = run_ok(["trial", "十", "--guidance", "off", "--mean-deviation", "0.0001",
                         "--mean-deviation-cap", "0.0001", "--hint-after-misses", "1",
                         "--assist-after-misses", "2", "--json", "a.json"], self.tmp)
        record = json.loads((self.tmp / "a.json").read_text(encoding="utf-8"))
        rows, said = trial_table(result.stdout.decode("utf-8"))
        self.assertEqual(record["end_reason"], "completed")
        flags = [s["assisted"] for s in record["renderer_strokes"]]
        self.assertEqual(flags, [s["assisted"] for s in record["per_character"][0]["per_stroke"]])
        self.assertEqual(record["strokes_assisted"], sum(flags))
        self.assertGreater(sum(flags), 0)
        for row, flag in zip(rows, flags):
            self.assertEqual(row[10] == "assisted", flag, row)
        self.assertEqual(int(said.get("strokes assisted", "0").split()[0]), record["strokes_assisted"])
        self.assertEqual(said["strokes completed"].split()[0], str(record["strokes_completed"]))
        self.assertEqual(record["strokes_completed"] + record["strokes_assisted"], 2)

    # ---- trials ended early ---------------------------------------------------------------------------------
    def test_trial_that_wrote_nothing_reports_no_time_of_writing(self):
        # Ended by the time limit at 0.3 s, before the simulated writer's pen touched the paper.
        result = self.cli("trial", "十", "--max-duration", "0.3", "--json", "n.json")
        self.assertEqual(result.returncode, 1, "a trial that ended early exits 1")
        text = result.stdout.decode("utf-8")
        record = json.loads((self.tmp / "n.json").read_text(encoding="utf-8"))
        self.assertEqual((record["end_reason"], record["strokes_written"]), ("time_limit", 0))
        self.assertNotIn("nan", text.lower())
        # docs/metrics.md: total_time_s is "first pen-down sample to last pen-down sample"; docs/cli.md, trial:
        # "A value that does not exist is `null` (`-` in the table), never 0."
        self.assertIsNone(record["total_time_s"], "no pen-down sample: no first to last pen-down time")
        _, said = trial_table(text)
        self.assertTrue(said["time"].startswith("-"), f"the table's time of writing: {said['time']!r}")

    def test_trial_cut_mid_stroke_says_its_last_pen_down_was_judged_at_the_end(self):
        # Lock-step, ended by the time limit at 3.0 s with the pen down on stroke 1, never lifted. First run: a
        # finding (the table said "strokes completed 0 / 2" and "accepted in turn 1 / 2" with no word why). The
        # docs now say which reading holds (docs/metrics.md: a pen-down the trace ends in "is judged there as if
        # lifted, and counts no miss ... `trial`'s table says \"the last pen-down judged at the trial's end, not
        # lifted\""): the record agrees with `score` of its own CSV, and the table says so.
        result = self.cli("trial", "十", "--max-duration", "3", "--json", "c.json", "--csv", "c.csv")
        self.assertEqual(result.returncode, 1)
        record = json.loads((self.tmp / "c.json").read_text(encoding="utf-8"))
        self.assertEqual(record["end_reason"], "time_limit")
        self.assertEqual(record["strokes_completed"], 0)
        self.assertEqual(record["renderer_strokes"][0]["attempts"], 1)
        self.assertFalse(record["renderer_strokes"][0]["completed"])
        self.assertEqual(record["strokes_accepted"], 1, "the whole of stroke 1 written, judged at the trace's end")
        scored = json.loads(run_ok(["score", "c.csv", "--character", "十", "--json", "-"], self.tmp).stdout)
        self.assertEqual(scored["strokes_accepted"], record["strokes_accepted"])
        text = result.stdout.decode("utf-8")
        self.assertIn("the last pen-down judged at the trial's end, not lifted", text)

    def test_trial_cut_mid_stroke_judges_its_half_stroke_at_the_end_and_counts_no_miss(self):
        # Lock-step, ended at 2.5 s with the pen down halfway along stroke 1. First run: a finding (refused
        # `too_short` with no word why); docs/metrics.md now says a pen-down the trace ends in is judged at the
        # trace's end "as if lifted, and counts no miss", and the table says so.
        result = self.cli("trial", "十", "--max-duration", "2.5", "--json", "h.json", "--csv", "h.csv")
        self.assertEqual(result.returncode, 1)
        record = json.loads((self.tmp / "h.json").read_text(encoding="utf-8"))
        self.assertEqual(record["renderer_strokes"][0]["attempts"], 1)
        self.assertEqual(record["strokes_completed"], 0)
        self.assertEqual({k: v for k, v in record["refusals"].items() if v}, {"too_short": 1},
                         "half a stroke, judged at the trial's end")
        # The pen-down the trial ends in is no miss: with a credit after one miss, nothing is credited.
        once = json.loads(run_ok(["score", "h.csv", "--character", "十", "--json", "-", "--assist-after-misses", "1"],
                                 self.tmp).stdout)
        self.assertEqual((once["strokes_assisted"], once["refusals"]["too_short"]), (0, 1))
        self.assertIn("the last pen-down judged at the trial's end, not lifted", result.stdout.decode("utf-8"))

    def test_trial_stopped_by_sigint_prints_a_true_table_and_one_line(self):
        process = subprocess.Popen([CLI, "trial", "十", "--pacing", "real-time", "--json", "i.json"],
                                   cwd=self.tmp, env=ENV, stdin=subprocess.DEVNULL, stdout=subprocess.PIPE,
                                   stderr=subprocess.PIPE)
        try:
            time.sleep(1.5)
            process.send_signal(signal.SIGINT)
            out, err = process.communicate(timeout=30)
        finally:
            if process.poll() is None:
                process.kill()
                process.wait()
        self.assertEqual(process.returncode, 130, err)
        text = out.decode("utf-8")
        lines = err.decode("utf-8", "replace").strip().splitlines()
        self.assertEqual(sum("SIGINT" in line for line in lines), 1, lines)
        for line in lines:
            self.assertTrue(line.startswith("calligraphy trial: "), line)
        record = json.loads((self.tmp / "i.json").read_text(encoding="utf-8"))
        self.assertEqual((record["end_reason"], record["abort_reason"]), ("interrupted", "stopped by SIGINT"))
        self.assertNotIn("nan", text.lower())
        _, said = trial_table(text)
        self.assertAlmostEqual(float(said["trial time"].split()[0]), record["trial_time_s"], delta=0.006)
        aborted = re.search(r"ABORTED after (\S+) s \(interrupted\)", text)
        self.assertIsNotNone(aborted, text)
        self.assertAlmostEqual(float(aborted.group(1)), record["trial_time_s"], delta=0.0006)

    # ---- standard output and standard error -----------------------------------------------------------------
    def test_log_goes_to_stderr_as_the_commands_lines_and_stdout_stays_the_same(self):
        quiet = run_ok(["trial", "十", "--device", "emulated-phantom"], self.tmp)
        verbose = run_ok(["trial", "十", "--device", "emulated-phantom", "--verbose"], self.tmp)
        self.assertEqual(quiet.stdout, verbose.stdout, "--verbose changes standard error only")
        for line in quiet.stdout.decode("utf-8").splitlines():
            self.assertNotRegex(line, r"warning|info:|Phantom:|\d\d:\d\d:\d\d")
        quiet_lines = quiet.stderr.decode("utf-8").splitlines()
        verbose_lines = verbose.stderr.decode("utf-8").splitlines()
        for line in quiet_lines:
            self.assertTrue(line.startswith("calligraphy trial: warning: "), line)
        for line in verbose_lines:
            self.assertRegex(line, r"^calligraphy trial: (warning|info): ")
        self.assertEqual(len(set(quiet_lines)), len(quiet_lines), "a warning is said once")
        self.assertEqual([l for l in verbose_lines if ": warning: " in l], quiet_lines)
        self.assertTrue(any(": info: " in l for l in verbose_lines))

    def test_a_rerun_that_differs_warns_in_one_line_and_prints_the_table(self):
        first = run_ok(["trial", "十", "--json", "r.json"], self.tmp)
        record = json.loads((self.tmp / "r.json").read_text(encoding="utf-8"))
        record["trial_time_s"] = 99.5
        (self.tmp / "r2.json").write_text(json.dumps(record, ensure_ascii=False), encoding="utf-8")
        again = run_ok(["trial", "--spec", "r2.json"], self.tmp)
        lines = again.stderr.decode("utf-8").strip().splitlines()
        self.assertEqual(len(lines), 1, lines)
        self.assertTrue(lines[0].startswith("calligraphy trial: warning: --spec r2.json: the re-run differs"),
                        lines)
        self.assertIn("trial_time_s recorded 99.5", lines[0])
        self.assertEqual(again.stdout, first.stdout, "standard output: the trial's table, as the first run's")

    def test_reading_commands_with_defaults_write_nothing_on_stderr(self):
        for args in (["model", "十"], ["characters", "--text", "十二"], ["devices"], ["devices", "--json"],
                     ["strokes"], ["score", "missing.csv", "--character", "十"]):
            with self.subTest(args=args):
                result = run_ok(args, self.tmp)
                self.assertEqual(result.stderr, b"")
                self.assertNotRegex(result.stdout.decode("utf-8"), r"(?m)^calligraphy \w+: (warning|info|error)")

    # ---- model: strokes numbered from 1 in its text and on its SVG ----------------------------------------------
    def test_model_numbers_strokes_from_1_in_text_and_svg_as_trial_and_score(self):
        text = run_ok(["model", "十"], self.tmp).stdout.decode("utf-8")
        self.assertEqual(re.findall(r"(?m)^  stroke (\d+):", text), ["1", "2"])
        svg = run_ok(["model", "十", "--svg", "-"], self.tmp).stdout.decode("utf-8")
        numbers = re.findall(r"<text[^>]*>\s*(\d+)\s*</text>", svg)
        self.assertEqual(sorted(numbers), ["1", "2"], "the SVG's stroke numbers")
        model = json.loads(run_ok(["model", "十", "--json"], self.tmp).stdout)
        self.assertEqual(len(model["strokes"]), 2)

    # ---- characters outside the embedded 58, with no corpus folder ------------------------------------------
    def test_character_beyond_the_embedded_needs_no_corpus_folder_on_any_command(self):
        env = no_corpus_env(self.tmp / "home")
        self.assertNotIn("乜", cg.CharacterLibrary.embedded())
        listed = json.loads(self.cli("characters", "--text", "乜", "--json", env=env).stdout)
        self.assertEqual(listed["count"], 1)
        ids = listed["characters"][0]["typical_ids"]
        model = self.cli("model", "乜", env=env)
        self.assertEqual(model.returncode, 0, model.stderr)
        model_text = model.stdout.decode("utf-8")
        self.assertIn("bundled:hanzi-writer-data-2.0.1.clg#乜 (U+4E5C)", model_text.splitlines()[0])
        self.assertIn("ID array of typical strokes " + " ".join(map(str, ids)), model_text)
        trial = self.cli("trial", "乜", "--json", "y.json", "--csv", "y.csv", env=env)
        self.assertEqual(trial.returncode, 0, trial.stderr)
        rows, _ = trial_table(trial.stdout.decode("utf-8"))
        self.assertEqual([int(r[3]) for r in rows], ids)
        score = self.cli("score", "y.csv", "--character", "乜", "--json", "y.score.json", env=env)
        self.assertEqual(score.returncode, 0, score.stderr)
        _, score_rows, _ = sections(score.stdout.decode("utf-8"))[0]
        self.assertEqual([int(r[2]) for r in score_rows], ids)
        record = json.loads((self.tmp / "y.json").read_text(encoding="utf-8"))
        scored = json.loads((self.tmp / "y.score.json").read_text(encoding="utf-8"))
        for key in ("strokes_total", "strokes_written", "strokes_accepted", "order_errors", "refusals",
                    "completed_in_order", "velocity_peaks"):
            self.assertEqual(record[key], scored[key], key)
        for key in ("mean_deviation_m", "max_deviation_m", "frechet_m", "dtw_m", "total_time_s"):
            self.assertAlmostEqual(record[key], scored[key], delta=1e-6 * max(1.0, abs(scored[key])), msg=key)

    # ---- characters ------------------------------------------------------------------------------------------
    def test_characters_by_stroke_count_lists_every_one_with_that_count_and_counts_them(self):
        result = self.cli("characters", "--strokes", "2", env=no_corpus_env(self.tmp / "home"))
        self.assertEqual((result.returncode, result.stderr), (0, b""))
        lines = result.stdout.decode("utf-8").splitlines()
        rows = [l.split() for l in lines if re.match(r"^\S\s+U\+[0-9A-F]{4,6}\s", l)]
        for row in rows:
            self.assertEqual(f"U+{ord(row[0]):04X}", row[1])
            self.assertEqual(int(row[2]), 2, row)
            self.assertEqual(len(row[3:]), 2, f"{row}: two typical strokes' acronyms")
        self.assertRegex(lines[-1], rf"^{len(rows)} characters; library: ")
        listed = {r[0] for r in rows}
        for character in "十二八人乜乂丁":
            self.assertIn(character, listed)

    def test_characters_of_a_mixed_text_in_its_order_once_each_table_and_json(self):
        text = "乜a十 十\u3000a。\t字😀乜Ｘ二"
        table = run_ok(["characters", "--text", text], self.tmp).stdout.decode("utf-8")
        listed = json.loads(run_ok(["characters", "--text", text, "--json"], self.tmp).stdout)
        self.assertEqual([c["character"] for c in listed["characters"]], ["乜", "十", "字", "二"])
        self.assertEqual(listed["count"], 4)
        self.assertEqual(listed["not_found"], ["a", "。", "😀", "Ｘ"])
        rows = [l.split() for l in table.splitlines() if re.match(r"^\S\s+U\+", l)]
        self.assertEqual([r[0] for r in rows], ["乜", "十", "字", "二"])
        for row, entry in zip(rows, listed["characters"]):
            self.assertEqual(row[1], entry["code_point"])
            self.assertEqual(int(row[2]), entry["strokes"])
            self.assertEqual(row[3:], entry["typical_strokes"])
            self.assertEqual(len(entry["typical_ids"]), entry["strokes"])
        self.assertTrue(any(l.startswith("4 characters; library: ") for l in table.splitlines()), table)
        missing = [l for l in table.splitlines() if "U+0061" in l]
        self.assertEqual(len(missing), 1, table)
        for name in ("a (U+0061)", "。 (U+3002)", "😀 (U+1F600)", "Ｘ (U+FF38)"):
            self.assertEqual(missing[0].count(name), 1, missing[0])
        for space in ("U+0020", "U+3000", "U+0009"):
            self.assertNotIn(space, table, "white space is skipped")

    def test_characters_typical_stroke_in_every_spelling_gives_the_same_list(self):
        strokes = json.loads(run_ok(["strokes", "--json"], self.tmp).stdout)
        hzg = [s for s in strokes if s["acronym"] == "HZG"][0]
        stroke_character = chr(int(hzg["unicode"][2:], 16))
        text = "永字乜刀力口十月"
        lists = {}
        for spelling in ("HZG", "hzg", str(hzg["id"]), hzg["name"], stroke_character):
            listed = json.loads(run_ok(["characters", "--typical", spelling, "--text", text, "--json"],
                                       self.tmp).stdout)
            lists[spelling] = [c["character"] for c in listed["characters"]]
            for entry in listed["characters"]:
                self.assertIn("HZG", entry["typical_strokes"])
                self.assertIn(hzg["id"], entry["typical_ids"])
        first = lists["HZG"]
        self.assertTrue(first, "some of the text's characters have a 横折钩")
        for spelling, found in lists.items():
            self.assertEqual(found, first, spelling)

    def test_characters_of_a_huge_text_of_two_characters_are_two(self):
        listed = json.loads(run_ok(["characters", "--text", "十二" * 15000, "--json"], self.tmp).stdout)
        self.assertEqual(([c["character"] for c in listed["characters"]], listed["count"], listed["not_found"]),
                         (["十", "二"], 2, []))

    def test_characters_of_an_empty_text_list_none_or_refuse_it_in_one_line(self):
        result = self.cli("characters", "--text", "", "--json")
        if result.returncode == 0:
            listed = json.loads(result.stdout)
            self.assertEqual((listed["count"], listed["characters"]), (0, []))
        else:
            self.assert_one_error(result, 2, "--text")

    # ---- devices ---------------------------------------------------------------------------------------------
    def test_devices_table_and_json_list_the_same_kinds_and_commands(self):
        table = run_ok(["devices"], self.tmp).stdout.decode("utf-8")
        listed = json.loads(run_ok(["devices", "--json"], self.tmp).stdout)
        kinds = {k["name"]: (k["writer"], k["commands"]) for k in listed["kinds"]}
        trainer = any("train" in commands for _, commands in kinds.values())
        for name, (writer, commands) in DOC_KINDS.items():
            expected = commands if trainer else [c for c in commands if c != "train"]
            if not trainer and name in ("mouse", "mouse-hand"):
                expected = []
            self.assertEqual(kinds.get(name), (writer, expected), name)
        lines = table.splitlines()
        start = [i for i, l in enumerate(lines) if l.startswith("Kinds of device")]
        self.assertEqual(len(start), 1, table)
        rows = {}
        for line in lines[start[0] + 2:]:
            m = re.match(r"^  (\S+)\s+(simulated|person)\s+(.*?)\s{2,}\S", line)
            if m:  # "none": no command takes it (a build without the trainer window, for the mouse)
                commands = [c.strip() for c in m.group(3).split(",") if c.strip()]
                rows[m.group(1)] = (m.group(2), [] if commands == ["none"] else commands)
        self.assertEqual(rows, kinds)
        # The survey: every device's limits as its JSON gives them, in SI units; every note.
        for device in listed["devices"]:
            info = device["info"]
            after = ("\n" + table).split("\n" + device["name"] + "  ", 1)
            self.assertEqual(len(after), 2, device["name"])
            below = after[1].split("\n")
            block = "\n".join(itertools.takewhile(lambda l: l.startswith(" "), below[1:]))
            self.assertIn(f"max force:          {info['max_force_n']:g} N (continuous "
                          f"{info['max_continuous_force_n']:g} N)", block)
            self.assertIn(f"max stiffness:      {info['max_stiffness_n_per_m']:g} N/m", block)
            x, y, z = info["workspace_size_m"]
            self.assertIn(f"radius {info['workspace_radius_m']:g} m, box {x:g} x {y:g} x {z:g} m", block)
        for note in listed["notes"]:
            self.assertIn("note: " + note.splitlines()[0], table)
        # trial refuses a pointer device naming the commands that take it, as devices lists them.
        refused = self.assert_one_error(self.cli("trial", "十", "--device", "mouse"), 2, "--device mouse")
        for command in kinds["mouse"][1]:
            self.assertIn(command, refused)

    # ---- help: one default per option ------------------------------------------------------------------------
    def test_every_help_gives_each_option_at_most_one_default(self):
        for command in COMMANDS:
            with self.subTest(command=" ".join(command)):
                result = run_ok([*command, "--help"], self.tmp)
                self.assertEqual(result.stderr, b"")
                entries, current = [], None
                for line in result.stdout.decode("utf-8").splitlines():
                    if re.match(r"^  -", line):
                        current = [line.strip()]
                        entries.append(current)
                    elif current is not None and re.match(r"^ {20,}\S", line):
                        current.append(line.strip())
                    else:
                        current = None
                self.assertTrue(entries)
                for entry in entries:
                    text = " ".join(entry)
                    self.assertLessEqual(len(re.findall(r"\bdefault", text, re.I)), 1, text)
                    if "(default:" in text:
                        self.assertTrue(text.endswith(")"), text)


if __name__ == "__main__":
    unittest.main()
