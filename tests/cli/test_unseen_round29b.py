#!/usr/bin/env python3
"""Round 29B: `score` as a teacher reads it, one verdict per stroke. From the docs alone: docs/cli.md (`score`,
"Pen traces: format and limits", the exit statuses), docs/stroke-acceptance.md ("The rule", "No dead end"),
docs/metrics.md (spatial metrics, "Per character", "The one metrics record", "Matching written strokes to the
character", "Trace CSV") and docs/python.md ("Scoring any pen trace"), `calligraphy score --help`,
`calligraphy model CHAR --json` and `help(calligraphy.score)`.

A learner's pen traces are written by hand with numpy along the data's medians (Python's
`Scene(...).characters[0].strokes[k].median_m`, metres in the trial's layout) at a person's pace (80 mm/s,
200 Hz, 0.1 mm of jitter), the pen lifted 3 mm between strokes; then each documented kind of error is made on
purpose on 十, 二, 人 and 口: a stroke reversed, half a stroke, a stroke 4.5, 6 and 8 mm off, the strokes
swapped, a later stroke out of turn, an earlier stroke again, a stroke missing, an extra stroke, a pen that
never touches, a pen never lifted at the end, misses counted towards the assisted credit (and pen-downs that
are no misses: off the box, under 1 mm). Each verdict, reason and deviation is checked in the table and in the
JSON, the table against the JSON (numbering from 1 and from 0, the totals' arithmetic), the per-stroke
deviations against the distances computed here from `model --json`'s elements, the option at and past its
range, a row of two and three characters, and the trace file's forms (columns in another order, extra
columns, unit names, `pen` spelt by numpy, duplicate and decreasing times, NaN, CRLF, a BOM, quotes, CR alone,
semicolons, millimetres, both `pen` and `z`, neither, 10,000 and 10,001 pen-downs). A simulated trial's CSV
(`trial --csv`) is scored at the default tolerances and at a mean deviation of 0.1 mm, against its record.
Python's `score` is held to the program's JSON, its acceptance, contact threshold, start radius and a Scene of
another layout.

CALLIGRAPHY_CLI names the program; PYTHONPATH the built Python package. CALLIGRAPHY_SANITIZED=1 takes five cases.
"""
import json
import math
import re
import shutil
import tempfile
import unittest
from pathlib import Path

from outsider import OneErrorLine, run, run_ok, sanitized_subset

try:
    import numpy as np
    import calligraphy as cg
except ImportError:  # reported by setUpClass: every case needs the traces numpy and the package draw
    np = cg = None

load_tests = sanitized_subset({"test_whole_character_is_accepted_numbered_from_1_in_the_table_and_0_in_the_json",
                               "test_reversed_stroke_is_refused_backwards_with_the_same_deviation_in_table_and_json",
                               "test_five_misses_8mm_across_credit_stroke_1_assisted_and_stroke_2_is_judged",
                               "test_assist_after_misses_past_its_range_is_one_usage_error_naming_it",
                               "test_time_going_backwards_is_refused_at_its_line"})

RATE_HZ = 200.0        # a tablet's rate
SPEED_M_S = 0.08       # a person's pace
JITTER_M = 0.0001      # a hand's tremor
HOVER_M = 0.003        # lifted: above the 0.5 mm contact threshold
CONTACT_M = 0.0005     # docs/metrics.md "Trace CSV": down when z <= 0.5 mm
REASONS = ("too_short", "backwards", "wrong_place", "wrong_stroke", "wrong_order")


def along(median, n, fraction=1.0):
    """`n` points equally spaced by arc length along the first `fraction` of a polyline."""
    median = np.asarray(median, dtype=float)
    s = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(median, axis=0), axis=1))])
    u = np.linspace(0.0, s[-1] * fraction, n)
    return np.column_stack([np.interp(u, s, median[:, 0]), np.interp(u, s, median[:, 1])])


def pen_path(chars, plan, seed=1, lift_at_end=True):
    """Ticks (t, x, y, z) of a pen writing `plan`: a list of (character, stroke, offset [m], fraction; a
    negative fraction from the stroke's end). Each pen-down at 80 mm/s with 0.1 mm jitter, set down and lifted
    through 1.5 mm, carried 3 mm above the paper between strokes."""
    rng = np.random.default_rng(seed)
    scene = cg.Scene(chars) if isinstance(chars, str) else chars
    paper_z = scene.layout.paper_z_m
    points, here = [], None
    for c, k, offset, fraction in plan:
        stroke = scene.characters[c].strokes[k]
        median = np.asarray(stroke.median_m)
        if fraction < 0:
            median = median[::-1]
        n = max(int(stroke.length_m * abs(fraction) / SPEED_M_S * RATE_HZ), 8)
        p = along(median, n, abs(fraction)) + np.asarray(offset) + rng.normal(0.0, JITTER_M, (n, 2))
        if here is not None:
            points += [(*(here * (1 - a) + p[0] * a), paper_z + HOVER_M) for a in np.linspace(0, 1, 20)]
        points.append((*p[0], paper_z + HOVER_M / 2))
        points += [(*q, paper_z) for q in p]
        points.append((*p[-1], paper_z + HOVER_M / 2))
        here = p[-1]
    if not lift_at_end:
        points.pop()
    xyz = np.array(points)
    return np.column_stack([np.arange(len(xyz)) / RATE_HZ, xyz])


def csv_text(ticks, header=("t", "x", "y", "z"), fmt=("%.6f", "%.7f", "%.7f", "%.7f")):
    return "".join([",".join(header) + "\n"] + [",".join(f % v for f, v in zip(fmt, row)) + "\n" for row in ticks])


def write_csv(path, ticks, **kw):
    Path(path).write_text(csv_text(ticks, **kw), encoding="utf-8")


def read_back(path):
    """The trace as the file holds it (the values the program reads)."""
    return np.loadtxt(path, delimiter=",", skiprows=1)


def pen_down_runs(ticks):
    """[(begin, end)] of the maximal pen-down runs, end one past the last."""
    down = ticks[:, 3] <= CONTACT_M
    runs, begin = [], None
    for i, d in enumerate(down):
        if d and begin is None:
            begin = i
        if not d and begin is not None:
            runs.append((begin, i))
            begin = None
    if begin is not None:
        runs.append((begin, len(down)))
    return runs


def point_segment_distance(p, a, b):
    """Distances of points p (N, 2) from the segment ab."""
    ab = b - a
    u = np.clip(((p - a) @ ab) / (ab @ ab), 0.0, 1.0)
    return np.linalg.norm(p - (a + np.outer(u, ab)), axis=1)


def polyline_distance(p, line):
    return np.min([point_segment_distance(p, line[i], line[i + 1]) for i in range(len(line) - 1)], axis=0)


def parse_table(text):
    """`score`'s table: a list of sections (one per character, then the row's total), each
    {"rows": {number: (fields, verdict)}, "totals": {name: text}}."""
    sections, current = [], None
    for line in text.splitlines():
        parts = line.split()
        if parts[:2] == ["stroke", "type"]:
            current = {"rows": {}, "totals": {}}
            sections.append(current)
            continue
        if line.startswith("All "):
            current = {"rows": {}, "totals": {}}
            sections.append(current)
            continue
        if current is None or not parts:
            continue
        if parts[0].isdigit() and len(parts) > 8:
            current["rows"][int(parts[0])] = (parts[1:8], " ".join(parts[8:]))
            continue
        for key in ("strokes accepted", "strokes assisted", "strokes refused", "strokes not written",
                    "pen-downs refused", "pen-downs unmatched", "strokes matched", "pen lifts"):
            if line.strip().startswith(key):
                current["totals"][key] = line.strip()[len(key):].strip()
    return sections


def first_int(text):
    return int(re.match(r"\s*(\d+)", text).group(1))


def reasons_of(text):
    """'2  (backwards 1, wrong order 1)' -> {"backwards": 1, "wrong_order": 1}."""
    found = re.search(r"\((.*)\)", text)
    out = {}
    if found:
        for part in found.group(1).split(","):
            words = part.split()
            out["_".join(words[:-1])] = int(words[-1])
    return out


def off_mm(verdict):
    """The '(X mm off)' of a table verdict, or None."""
    found = re.search(r"([0-9.]+) mm off\)", verdict)
    return float(found.group(1)) if found else None


class Round29B(unittest.TestCase, OneErrorLine):
    @classmethod
    def setUpClass(cls):
        if cg is None:
            raise unittest.SkipTest("numpy and the calligraphy Python package (PYTHONPATH) are needed")
        cls.tmp = Path(tempfile.mkdtemp(prefix="round29b-"))
        d = cls.tmp
        ok = (0, 0, (0.0, 0.0), 1.0)
        plans = {
            "good": ("十", [ok, (0, 1, (0.0, 0.0), 1.0)], True),
            "reversed": ("十", [(0, 0, (0.0, 0.0), -1.0), (0, 1, (0.0, 0.0), 1.0)], True),
            "half": ("十", [(0, 0, (0.0, 0.0), 0.5), (0, 1, (0.0, 0.0), 1.0)], True),
            "off8": ("十", [(0, 0, (0.0, 0.008), 1.0), (0, 1, (0.0, 0.0), 1.0)], True),
            "off45": ("十", [(0, 0, (0.0, 0.0045), 1.0), (0, 1, (0.0, 0.0), 1.0)], True),
            "left6": ("十", [ok, (0, 1, (-0.006, 0.0), 1.0)], True),
            "swapped": ("十", [(0, 1, (0.0, 0.0), 1.0), ok], True),
            "missing": ("十", [ok], True),
            "extra": ("十", [ok, (0, 1, (0.0, 0.0), 1.0), ok], True),
            "again": ("十", [ok, ok, (0, 1, (0.0, 0.0), 1.0)], True),
            "nolift": ("十", [ok, (0, 1, (0.0, 0.0), 1.0)], False),
            "assist": ("十", [(0, 0, (0.0, 0.008), 1.0)] * 5 + [(0, 1, (0.0, 0.0), 1.0)], True),
            "offbox": ("十", [(0, 0, (0.0, 0.04), 1.0)] * 5 + [ok, (0, 1, (0.0, 0.0), 1.0)], True),
            "kou13": ("口", [(0, 0, (0.0, 0.0), 1.0), (0, 2, (0.0, 0.0), 1.0)], True),
            "laterback": ("十", [(0, 1, (0.0, 0.0), -1.0), ok], True),
            "allback": ("十", [(0, 0, (0.0, 0.0), -1.0)] * 2 + [(0, 1, (0.0, 0.0), -1.0)] * 2, True),
        }
        cls.ticks, cls.chars = {}, {}
        for name, (chars, plan, lift) in plans.items():
            write_csv(d / f"{name}.csv", pen_path(chars, plan, lift_at_end=lift))
            cls.ticks[name] = read_back(d / f"{name}.csv")
            cls.chars[name] = chars
        air = pen_path("十", plans["good"][1])
        air[:, 3] = HOVER_M
        write_csv(d / "air.csv", air)
        cls.ticks["air"], cls.chars["air"] = read_back(d / "air.csv"), "十"
        cls.scores = {name: cls.score(name) for name in cls.ticks if name != "allback"}
        cls.scores["allback"] = cls.score("allback", "--assist-after-misses", "2")

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.tmp, ignore_errors=True)

    @classmethod
    def score(cls, name, *options, chars=None, trace=None):
        """(JSON, table sections) of `calligraphy score NAME.csv --character C OPTIONS --json`."""
        out = f"{trace or name}-{'_'.join(options)}.json"
        result = run_ok(["score", trace or f"{name}.csv", "--character", chars or cls.chars[name], *options,
                         "--json", out], cls.tmp)
        return (json.loads((cls.tmp / out).read_text(encoding="utf-8")),
                parse_table(result.stdout.decode("utf-8")))

    def verdicts(self, record, character=0):
        return [s["verdict"] for s in record["per_character"][character]["segments"]]

    # ---- one verdict per stroke, each kind of error -------------------------------------------------------

    def test_whole_character_is_accepted_numbered_from_1_in_the_table_and_0_in_the_json(self):
        record, table = self.scores["good"]
        self.assertEqual({n: v for n, (_, v) in table[0]["rows"].items()}, {1: "accepted", 2: "accepted"})
        self.assertEqual([s["index"] for s in record["per_character"][0]["per_stroke"]], [0, 1])
        self.assertEqual([(v["expected_stroke"], v["matched_stroke"], v["accepted"], v["refusal"])
                          for v in self.verdicts(record)], [(0, 0, True, "none"), (1, 1, True, "none")])
        self.assertEqual((record["strokes_total"], record["strokes_written"], record["strokes_accepted"],
                          record["strokes_assisted"], record["completed_in_order"]), (2, 2, 2, 0, True))
        self.assertEqual(record["refusals"], {r: 0 for r in REASONS})

    def test_reversed_stroke_is_refused_backwards_with_the_same_deviation_in_table_and_json(self):
        record, table = self.scores["reversed"]
        first, second = self.verdicts(record)
        self.assertEqual((first["refusal"], first["expected_stroke"], first["matched_stroke"]), ("backwards", 0, 0))
        # docs/metrics.md: "A stroke written from its end to its start comes within the radius where it ends,
        # and is measured from there": a number, which the table prints as `(X mm off)`.
        self.assertIsNotNone(first["mean_deviation_m"])
        verdict = table[0]["rows"][1][1]
        self.assertTrue(verdict.startswith("refused: backwards ("), verdict)
        self.assertAlmostEqual(off_mm(verdict), first["mean_deviation_m"] * 1e3, delta=0.051)
        self.assertEqual(table[0]["rows"][2][1], "refused: wrong order (written while stroke 1 was due)")
        self.assertEqual((second["refusal"], second["expected_stroke"], second["matched_stroke"]),
                         ("wrong_order", 0, 1))
        self.assertEqual(record["backwards_strokes"], 1)
        self.assertTrue(record["per_character"][0]["per_stroke"][0]["backwards"])
        self.assertEqual(record["strokes_accepted"], 0)

    def test_half_stroke_is_refused_too_short_and_not_written(self):
        record, table = self.scores["half"]
        self.assertEqual(self.verdicts(record)[0]["refusal"], "too_short")
        self.assertTrue(table[0]["rows"][1][1].startswith("refused: too short"), table[0]["rows"][1][1])
        stroke = record["per_character"][0]["per_stroke"][0]
        self.assertFalse(stroke["written"])
        self.assertIsNone(stroke["mean_deviation_m"])
        self.assertEqual(table[0]["rows"][1][0][2:], ["-"] * 5)
        self.assertEqual((record["strokes_written"], record["unmatched_segments"]), (1, 1))

    def test_stroke_8mm_across_is_wrong_place_never_near_its_start_its_deviation_null(self):
        record, table = self.scores["off8"]
        first = self.verdicts(record)[0]
        self.assertEqual((first["refusal"], first["mean_deviation_m"]), ("wrong_place", None))
        self.assertEqual(table[0]["rows"][1][1], "refused: wrong place (never near its start)")

    def test_stroke_4_5mm_across_is_wrong_place_by_its_mean_distance_from_the_median(self):
        record, table = self.scores["off45"]
        first = self.verdicts(record)[0]
        self.assertEqual(first["refusal"], "wrong_place")
        # docs/stroke-acceptance.md: on the track (within the 6.5 mm corridor) the distance is the pen's from
        # the line, the data's median; mean over the attempt.
        ticks = self.ticks["off45"]
        begin, end = pen_down_runs(ticks)[0]
        median = np.asarray(cg.Scene("十").characters[0].strokes[0].median_m)
        expected = polyline_distance(ticks[begin:end, 1:3], median).mean()
        self.assertAlmostEqual(first["mean_deviation_m"], expected, delta=0.0002)
        verdict = table[0]["rows"][1][1]
        self.assertEqual(verdict, f"refused: wrong place ({first['mean_deviation_m'] * 1e3:.1f} mm off)")

    def test_stroke_2_written_6mm_left_reads_11_2mm_off_as_the_docs_show(self):
        # docs/stroke-acceptance.md: "十's stroke 2 written 6 mm to its left ... measures 11.2 mm (`score`:
        # `refused: wrong place (11.2 mm off)`)".
        record, table = self.scores["left6"]
        verdict = table[0]["rows"][2][1]
        self.assertTrue(verdict.startswith("refused: wrong place ("), verdict)
        self.assertAlmostEqual(off_mm(verdict), 11.2, delta=0.25)
        self.assertEqual(self.verdicts(record)[1]["refusal"], "wrong_place")
        self.assertLessEqual(self.verdicts(record)[1]["mean_deviation_m"], 0.013)

    def test_swapped_strokes_refuse_the_first_pen_down_wrong_order_and_count_one_order_error(self):
        record, table = self.scores["swapped"]
        first, second = self.verdicts(record)
        self.assertEqual((first["refusal"], first["expected_stroke"], first["matched_stroke"]), ("wrong_order", 0, 1))
        self.assertTrue(second["accepted"])
        self.assertEqual((record["order_errors"], record["strokes_written"], record["completed_in_order"]),
                         (1, 2, False))
        self.assertEqual(table[0]["rows"][1][1], "accepted")
        self.assertEqual(table[0]["rows"][2][1], "refused: wrong order (written while stroke 1 was due)")

    def test_later_stroke_out_of_turn_names_the_due_stroke_from_1(self):
        # 口: stroke 1, then stroke 3 while stroke 2 is due, and nothing more.
        record, table = self.scores["kou13"]
        second = self.verdicts(record)[1]
        self.assertEqual((second["refusal"], second["expected_stroke"], second["matched_stroke"]),
                         ("wrong_order", 1, 2))
        rows = {n: v for n, (_, v) in table[0]["rows"].items()}
        self.assertEqual(rows, {1: "accepted", 2: "not written",
                                3: "refused: wrong order (written while stroke 2 was due)"})

    def test_missing_stroke_is_not_written_and_its_metrics_null(self):
        record, table = self.scores["missing"]
        stroke = record["per_character"][0]["per_stroke"][1]
        self.assertFalse(stroke["written"])
        for key in ("mean_deviation_m", "max_deviation_m", "frechet_m", "dtw_m", "time_s"):
            self.assertIsNone(stroke[key], key)
        self.assertEqual(table[0]["rows"][2], (["S", "2", "-", "-", "-", "-", "-"], "not written"))
        self.assertEqual((record["strokes_written"], record["completed_in_order"]), (1, False))
        self.assertEqual(record["per_character"][0]["missing_strokes"], [1])

    def test_extra_stroke_after_the_last_gets_no_verdict_and_is_unmatched(self):
        record, table = self.scores["extra"]
        self.assertIsNone(self.verdicts(record)[2])
        self.assertEqual((record["unmatched_segments"], record["strokes_accepted"],
                          record["per_character"][0]["pen_lifts"]), (1, 2, 2))
        self.assertEqual(record["refusals"], {r: 0 for r in REASONS})

    def test_earlier_stroke_again_is_wrong_stroke_naming_it(self):
        record, table = self.scores["again"]
        second = self.verdicts(record)[1]
        self.assertEqual((second["refusal"], second["expected_stroke"], second["matched_stroke"]),
                         ("wrong_stroke", 1, 0))
        self.assertEqual(reasons_of(table[0]["totals"]["pen-downs refused"]), {"wrong_stroke": 1})

    def test_pen_that_never_touches_writes_nothing_and_its_times_are_null(self):
        record, table = self.scores["air"]
        self.assertEqual({n: v for n, (_, v) in table[0]["rows"].items()}, {1: "not written", 2: "not written"})
        self.assertEqual((record["strokes_written"], record["strokes_accepted"], record["pen_down_time_s"]),
                         (0, 0, 0))
        for key in ("total_time_s", "mean_deviation_m", "frechet_m"):
            self.assertIsNone(record[key], key)
        self.assertEqual(record["per_character"][0]["segments"], [])

    def test_pen_never_lifted_at_the_end_is_judged_there_as_if_lifted(self):
        record, table = self.scores["nolift"]
        last = record["per_character"][0]["segments"][-1]
        self.assertTrue(last["verdict"]["accepted"])
        self.assertEqual(last["end"], record["samples"])
        self.assertEqual(record["samples"], len(self.ticks["nolift"]))
        self.assertEqual(table[0]["rows"][2][1], "accepted")

    def test_refused_pen_down_the_trace_ends_in_counts_no_miss(self):
        # docs/metrics.md: a pen-down the trace ends in "is judged there as if lifted, and counts no miss".
        plan = [(0, 0, (0.0, 0.0), 1.0), (0, 1, (0.0, 0.0), -1.0)]
        write_csv(self.tmp / "open.csv", pen_path("十", plan, lift_at_end=False))
        write_csv(self.tmp / "closed.csv", pen_path("十", plan, lift_at_end=True))
        still_down, _ = self.score("open", "--assist-after-misses", "1", chars="十")
        lifted, table = self.score("closed", "--assist-after-misses", "1", chars="十")
        self.assertEqual(self.verdicts(still_down)[1]["refusal"], "backwards")
        self.assertEqual(still_down["strokes_assisted"], 0)
        self.assertEqual(lifted["strokes_assisted"], 1)
        self.assertTrue(table[0]["rows"][2][1].startswith("assisted (last refused: backwards"),
                        table[0]["rows"][2][1])

    def test_later_stroke_written_backwards_while_another_is_due_is_wrong_place_saying_so(self):
        # docs/cli.md: "a later stroke written from its end while another was due `refused: wrong place
        # (written backwards while stroke 1 was due)`".
        record, table = self.scores["laterback"]
        first, second = self.verdicts(record)
        self.assertEqual((first["refusal"], first["expected_stroke"]), ("wrong_place", 0))
        self.assertTrue(second["accepted"])
        self.assertEqual(table[0]["rows"][2][1], "refused: wrong place (written backwards while stroke 1 was due)")
        # a refused pen-down that still matches the stroke counts in strokes_written (docs/stroke-acceptance.md)
        self.assertTrue(record["per_character"][0]["per_stroke"][1]["backwards"])
        self.assertEqual((record["strokes_written"], record["backwards_strokes"]), (2, 1))

    def test_every_stroke_backwards_then_assisted_is_written_and_completed_in_order(self):
        # docs/stroke-acceptance.md: "A trial whose every stroke was written backwards and then credited as
        # assisted has strokes_written = strokes_total and is completed_in_order, with strokes_accepted ... 0".
        record, table = self.scores["allback"]
        self.assertEqual((record["strokes_written"], record["strokes_total"], record["strokes_accepted"],
                          record["strokes_assisted"], record["completed_in_order"], record["backwards_strokes"]),
                         (2, 2, 0, 2, True, 2))
        for number in (1, 2):
            verdict = table[0]["rows"][number][1]
            self.assertRegex(verdict, r"^assisted \(last refused: backwards, [0-9.]+ mm off\)$")
        self.assertEqual(first_int(table[0]["totals"]["strokes assisted"]), 2)

    def test_character_written_last_to_first_counts_every_inversion(self):
        # docs/metrics.md: order_errors are the inversions of the matched stroke indices in writing order.
        plan = [(0, 2, (0.0, 0.0), 1.0), (0, 1, (0.0, 0.0), 1.0), (0, 0, (0.0, 0.0), 1.0)]
        write_csv(self.tmp / "kou321.csv", pen_path("口", plan))
        record, table = self.score("kou321", chars="口")
        self.assertEqual((record["order_errors"], record["strokes_written"], record["strokes_accepted"]), (3, 3, 1))
        self.assertEqual([(v["expected_stroke"], v["matched_stroke"], v["refusal"]) for v in self.verdicts(record)],
                         [(0, 2, "wrong_order"), (0, 1, "wrong_order"), (0, 0, "none")])
        self.assertEqual({n: v for n, (_, v) in table[0]["rows"].items()},
                         {1: "accepted", 2: "refused: wrong order (written while stroke 1 was due)",
                          3: "refused: wrong order (written while stroke 1 was due)"})

    def test_stroke_left_out_and_another_written_twice_reports_the_left_out_one_missing(self):
        # docs/metrics.md: the assignment "gives the repeat to its own stroke and reports the left-out one
        # missing".
        plan = [(0, 0, (0.0, 0.0), 1.0), (0, 1, (0.0, 0.0), 1.0), (0, 1, (0.0, 0.0), 1.0)]
        write_csv(self.tmp / "kou122.csv", pen_path("口", plan))
        record, table = self.score("kou122", chars="口")
        character = record["per_character"][0]
        self.assertEqual(character["missing_strokes"], [2])
        self.assertEqual((character["strokes_written"], character["unmatched_segments"]), (2, 1))
        self.assertEqual(table[0]["rows"][3][1], "not written")

    # ---- the table and the JSON say the same thing --------------------------------------------------------

    def test_table_totals_add_up_to_the_strokes_and_agree_with_the_json(self):
        for name, (record, table) in self.scores.items():
            with self.subTest(trace=name):
                character = record["per_character"][0]
                totals = table[0]["totals"]
                rows = [v for _, v in table[0]["rows"].values()]
                accepted = first_int(totals["strokes accepted"])
                assisted = first_int(totals.get("strokes assisted", "0"))
                refused = first_int(totals["strokes refused"])
                not_written = first_int(totals["strokes not written"])
                self.assertEqual(accepted + assisted + refused + not_written, character["strokes_total"])
                self.assertIn(f"of {character['strokes_total']}", totals["strokes accepted"])
                self.assertEqual((accepted, assisted), (character["strokes_accepted"], character["strokes_assisted"]))
                self.assertEqual(accepted, rows.count("accepted"))
                self.assertEqual(not_written, rows.count("not written"))
                self.assertEqual(refused, sum(v.startswith("refused") for v in rows))
                self.assertEqual(assisted, sum(v.startswith("assisted") for v in rows))
                self.assertEqual(assisted, sum(s["assisted"] for s in character["per_stroke"]))
                self.assertEqual(sum(reasons_of(totals["strokes refused"]).values()), refused)
                pen_downs = reasons_of(totals["pen-downs refused"])
                self.assertEqual(first_int(totals["pen-downs refused"]), sum(character["refusals"].values()))
                self.assertEqual(pen_downs, {r: n for r, n in character["refusals"].items() if n})
                unmatched = totals["pen-downs unmatched"]
                self.assertEqual(first_int(unmatched), character["unmatched_segments"])
                self.assertEqual(int(unmatched.split("too short to score")[1]), character["ignored_segments"])
                self.assertEqual(first_int(totals["strokes matched"]), character["strokes_written"])
                if "pen lifts" in totals:
                    self.assertEqual(first_int(totals["pen lifts"]), character["pen_lifts"])

    def test_table_deviations_and_times_are_the_json_per_stroke_values(self):
        for name, (record, table) in self.scores.items():
            for stroke in record["per_character"][0]["per_stroke"]:
                with self.subTest(trace=name, stroke=stroke["index"]):
                    fields, _ = table[0]["rows"][stroke["index"] + 1]
                    keys = ("mean_deviation_m", "max_deviation_m", "frechet_m", "dtw_m")
                    if stroke["written"]:
                        for key, text in zip(keys, fields[2:6]):
                            self.assertAlmostEqual(float(text), stroke[key] * 1e3, delta=0.0051, msg=key)
                        self.assertAlmostEqual(float(fields[6]), stroke["time_s"], delta=0.0051)
                    else:
                        self.assertEqual(fields[2:], ["-"] * 5)

    # ---- the deviations and times, computed here --------------------------------------------------------

    def test_per_stroke_deviation_is_the_samples_distance_to_the_placed_elements_of_model_json(self):
        model = json.loads(run_ok(["model", "十", "--json"], self.tmp).stdout)
        placement = cg.Scene("十").characters[0].placement
        record, _ = self.scores["good"]
        ticks = self.ticks["good"]
        runs = pen_down_runs(ticks)
        self.assertEqual([(s["begin"], s["end"]) for s in record["per_character"][0]["segments"]], runs)
        for k, (begin, end) in enumerate(runs):
            with self.subTest(stroke=k + 1):
                elements = [placement.to_paper(np.asarray(e["control_points"], dtype=float))
                            for e in model["strokes"][k]["elements"]]
                self.assertTrue(all(e["kind"] == "line" for e in model["strokes"][k]["elements"]))
                p = ticks[begin:end, 1:3]
                d = np.min([point_segment_distance(p, e[0], e[-1]) for e in elements], axis=0)
                got = record["per_character"][0]["per_stroke"][k]
                self.assertAlmostEqual(got["mean_deviation_m"], d.mean(), delta=1e-7)
                self.assertAlmostEqual(got["max_deviation_m"], d.max(), delta=1e-7)
                self.assertAlmostEqual(got["rms_deviation_m"], math.sqrt((d ** 2).mean()), delta=1e-7)
                self.assertEqual(got["outside_tube_share"], float((d > 0.002).mean()))
                self.assertAlmostEqual(got["time_s"], ticks[end - 1, 0] - ticks[begin, 0], delta=1e-9)
                self.assertAlmostEqual(got["path_length_m"],
                                       np.linalg.norm(np.diff(p, axis=0), axis=1).sum(), delta=1e-8)

    def test_character_totals_pool_the_strokes_as_documented(self):
        record, _ = self.scores["extra"]
        character = record["per_character"][0]
        ticks = self.ticks["extra"]
        runs = pen_down_runs(ticks)
        matched = [s for s in character["per_stroke"] if s["written"]]
        n = {s["matched_stroke"]: s["end"] - s["begin"] for s in character["segments"]
             if s["matched_stroke"] is not None}
        pooled = sum(n[s["index"]] * s["mean_deviation_m"] for s in matched) / sum(n[s["index"]] for s in matched)
        self.assertAlmostEqual(record["mean_deviation_m"], pooled, delta=1e-12)
        self.assertEqual(record["max_deviation_m"], max(s["max_deviation_m"] for s in matched))
        self.assertEqual(record["frechet_m"], max(s["frechet_m"] for s in matched))
        self.assertEqual(character["pen_lifts"], len(runs) - 1)
        self.assertAlmostEqual(record["pen_down_time_s"], sum(ticks[e - 1, 0] - ticks[b, 0] for b, e in runs),
                               delta=1e-9)
        self.assertAlmostEqual(character["in_air_time_s"],
                               sum(ticks[runs[i + 1][0], 0] - ticks[runs[i][1] - 1, 0] for i in range(len(runs) - 1)),
                               delta=1e-9)
        self.assertAlmostEqual(record["total_time_s"], ticks[runs[-1][1] - 1, 0] - ticks[runs[0][0], 0], delta=1e-9)
        self.assertAlmostEqual(record["total_time_s"], character["pen_down_time_s"] + character["in_air_time_s"],
                               delta=1e-9)
        for stroke in matched:
            self.assertAlmostEqual(stroke["mean_speed_m_s"], stroke["path_length_m"] / stroke["time_s"], delta=1e-9)

    def test_the_reference_itself_sampled_densely_scores_frechet_within_an_eighth_of_a_millimetre(self):
        # docs/metrics.md, "Discretisation": "the reference itself, sampled densely, scores Frechet <= 0.125 mm,
        # not 0"; its deviation from the elements is 0 to the file's 0.1 um.
        scene = cg.Scene("十")
        elements = [np.asarray(e.control_points) for e in scene.characters[0].strokes[1].elements]
        path = np.vstack([along(e, max(int(np.linalg.norm(e[-1] - e[0]) / 0.0001), 2)) for e in elements])
        first = pen_path("十", [(0, 0, (0.0, 0.0), 1.0)])
        t0 = first[-1, 0] + 0.1
        rows = [(t0, *path[0], HOVER_M)] + [(t0 + (i + 1) / 1000, *q, 0.0) for i, q in enumerate(path)]
        write_csv(self.tmp / "itself.csv", np.vstack([first, np.array(rows)]))
        record, _ = self.score("itself", chars="十")
        stroke = record["per_character"][0]["per_stroke"][1]
        self.assertTrue(stroke["written"], "the stroke's own elements were matched to it")
        self.assertLessEqual(stroke["frechet_m"], 0.000125 + 1e-7)
        self.assertLess(stroke["mean_deviation_m"], 1e-7)

    def test_minimum_jerk_line_gives_the_documented_normalised_jerk_and_one_peak(self):
        # docs/metrics.md, "Measured (L = 30 mm)", the 10 Hz filter: 0.2 s at 100 Hz 14.93, 0.6 s at 1 kHz
        # 17.76, 1.5 s at 1 kHz 18.49. A scored segment counts matched or not.
        for duration, rate, expected in ((0.2, 100, 14.93), (0.6, 1000, 17.76), (1.5, 1000, 18.49)):
            with self.subTest(duration=duration, rate=rate):
                tau = np.linspace(0.0, 1.0, int(round(duration * rate)) + 1)
                s = 0.03 * (10 * tau ** 3 - 15 * tau ** 4 + 6 * tau ** 5)
                rows = np.column_stack([tau * duration, s - 0.015, np.full_like(s, 0.02), np.zeros_like(s)])
                write_csv(self.tmp / "jerk.csv", rows, fmt=("%.6f", "%.9f", "%.9f", "%.7f"))
                record, _ = self.score("jerk", chars="十", trace="jerk.csv")
                self.assertAlmostEqual(record["normalised_jerk"], expected, delta=0.02)
                self.assertEqual(record["velocity_peaks"], 1)

    def test_pen_down_with_no_time_span_is_ignored_and_gets_no_verdict(self):
        # docs/metrics.md "Per character": a segment with "no time span is ignored"; "none for an ignored
        # segment", so stroke 2 is then written while stroke 1 is due.
        ticks = self.ticks["good"].copy()
        begin, end = pen_down_runs(ticks)[0]
        ticks[begin:end, 0] = ticks[begin, 0]
        write_csv(self.tmp / "frozen.csv", ticks)
        record, table = self.score("good", trace="frozen.csv")
        character = record["per_character"][0]
        self.assertEqual((character["ignored_segments"], character["segments"][0]["verdict"]), (1, None))
        self.assertEqual(character["segments"][1]["verdict"]["refusal"], "wrong_order")
        self.assertEqual(table[0]["rows"][1][1], "not written")

    # ---- the assisted credit --------------------------------------------------------------------------

    def test_five_misses_8mm_across_credit_stroke_1_assisted_and_stroke_2_is_judged(self):
        record, table = self.scores["assist"]
        stroke = record["per_character"][0]["per_stroke"][0]
        self.assertEqual((stroke["assisted"], stroke["written"]), (True, False))
        self.assertEqual((record["strokes_assisted"], record["strokes_accepted"]), (1, 1))
        self.assertEqual(record["refusals"]["wrong_place"], 5)
        self.assertEqual([v["assists_due"] for v in self.verdicts(record)], [False] * 4 + [True, False])
        self.assertTrue(self.verdicts(record)[5]["accepted"])
        self.assertEqual(table[0]["rows"][1][1], "assisted (last refused: wrong place, never near its start)")
        self.assertEqual(table[0]["rows"][2][1], "accepted")

    def test_assist_after_misses_credits_at_exactly_its_count(self):
        # Five pen-downs 8 mm across stroke 1, then stroke 2: written while stroke 1 is due, it is a miss too
        # (docs/stroke-acceptance.md: "another stroke out of turn"); a miss after stroke 1's credit is stroke
        # 2's; once every stroke is credited no pen-down gets a verdict.
        for count, assisted, due in ((7, 0, []), (6, 1, [5]), (5, 1, [4]), (4, 1, [3]), (1, 2, [0, 1]), (0, 0, [])):
            with self.subTest(count=count):
                record, _ = self.score("assist", "--assist-after-misses", str(count))
                self.assertEqual(record["strokes_assisted"], assisted)
                verdicts = self.verdicts(record)
                self.assertEqual([i for i, v in enumerate(verdicts) if v and v["assists_due"]], due)
                if count == 1:
                    self.assertEqual(verdicts[2:], [None] * 4)
                if assisted == 0:
                    self.assertEqual(verdicts[5]["refusal"], "wrong_order")

    def test_pen_downs_off_the_character_box_are_no_misses(self):
        record, _ = self.score("offbox", "--assist-after-misses", "1")
        self.assertEqual((record["strokes_assisted"], record["strokes_accepted"]), (0, 2))
        self.assertEqual(record["refusals"]["wrong_place"], 5)

    def test_touches_under_1mm_are_ignored_and_no_misses(self):
        scene = cg.Scene("十")
        start = np.asarray(scene.characters[0].strokes[0].median_m)[0]
        rows, t = [], 0.0
        for _ in range(5):  # five touches at stroke 1's start, 0.4 mm of path each
            for j in range(5):
                rows.append((t, start[0] + 0.0001 * j, start[1], 0.0 if 0 < j < 4 else HOVER_M))
                t += 1 / RATE_HZ
        good = pen_path("十", [(0, 0, (0.0, 0.0), 1.0), (0, 1, (0.0, 0.0), 1.0)])
        good[:, 0] += t
        write_csv(self.tmp / "touches.csv", np.vstack([np.array(rows), good]))
        record, table = self.score("touches", "--assist-after-misses", "1", chars="十")
        character = record["per_character"][0]
        self.assertEqual((record["strokes_assisted"], record["strokes_accepted"]), (0, 2))
        self.assertEqual(character["ignored_segments"], 5)
        # "pen-up gaps between two pen-down segments (ignored ones included)"
        self.assertEqual(character["pen_lifts"], 6)
        self.assertEqual([(s["ignored"], s["verdict"]) for s in character["segments"][:5]], [(True, None)] * 5)
        self.assertTrue(table[0]["totals"]["pen-downs unmatched"].endswith("too short to score 5"))

    def test_three_samples_over_1mm_count_a_miss_and_under_1mm_do_not(self):
        # docs/metrics.md: a segment with fewer than 3 samples or a path under 1 mm is ignored; a refused
        # pen-down that touched the box and moved 1 mm or more is a miss (docs/stroke-acceptance.md).
        start = np.asarray(cg.Scene("十").characters[0].strokes[0].median_m)[0]
        good = pen_path("十", [(0, 0, (0.0, 0.0), 1.0), (0, 1, (0.0, 0.0), 1.0)])
        for step, assisted in ((0.0006, 1), (0.0004, 0)):   # 1.2 mm and 0.8 mm over 3 samples
            with self.subTest(path_mm=2 * step * 1e3):
                touch = ([(0.0, *start, HOVER_M)]
                         + [(0.01 * (j + 1), start[0] + step * j, start[1], 0.0) for j in range(3)]
                         + [(0.04, start[0] + 2 * step, start[1], HOVER_M)])
                ticks = good.copy()
                ticks[:, 0] += 0.1
                write_csv(self.tmp / "touch3.csv", np.vstack([np.array(touch), ticks]))
                record, _ = self.score("touch3", "--assist-after-misses", "1", chars="十")
                character = record["per_character"][0]
                self.assertEqual(character["ignored_segments"], 1 - assisted)
                self.assertEqual(character["per_stroke"][0]["assisted"], bool(assisted))
                verdict = character["segments"][0]["verdict"]
                if assisted:
                    self.assertTrue(verdict["assists_due"])
                else:
                    self.assertIsNone(verdict)
                    self.assertEqual((record["strokes_assisted"], record["strokes_accepted"]), (0, 2))

    # ---- the option ------------------------------------------------------------------------------------

    def test_assist_after_misses_past_its_range_is_one_usage_error_naming_it(self):
        for value in ("1001", "-1", "1.5", "2x", "1e3", "nan"):
            with self.subTest(value=value):
                result = run(["score", "good.csv", "--character", "十", "--assist-after-misses", value,
                              "--json", "bad.json"], self.tmp)
                self.assert_one_error(result, 2, "--assist-after-misses")
                self.assertFalse((self.tmp / "bad.json").exists())

    def test_assist_after_misses_at_1000_is_taken(self):
        record, _ = self.score("good", "--assist-after-misses", "1000")
        self.assertEqual(record["strokes_accepted"], 2)

    def test_assist_after_misses_given_twice_is_a_usage_error(self):
        result = run(["score", "good.csv", "--character", "十", "--assist-after-misses", "1",
                      "--assist-after-misses", "1"], self.tmp)
        self.assert_one_error(result, 2, "--assist-after-misses")

    def test_units_data_with_a_row_is_a_usage_error(self):
        result = run(["score", "good.csv", "--character", "十二", "--units", "data"], self.tmp)
        line = self.assert_one_error(result, 2)
        self.assertTrue("--units" in line or "--character" in line, line)

    def test_trace_in_data_units_scores_as_the_same_trace_in_metres(self):
        placement = cg.Scene("十").characters[0].placement
        for name in ("good", "assist", "reversed"):
            with self.subTest(trace=name):
                ticks = self.ticks[name].copy()
                ticks[:, 1:3] = placement.to_data(ticks[:, 1:3])
                write_csv(self.tmp / f"{name}-data.csv", ticks, fmt=("%.6f", "%.9f", "%.9f", "%.7f"))
                record, _ = self.score(name, "--units", "data", trace=f"{name}-data.csv")
                metres, _ = self.scores[name]
                self.assertEqual(record["units"], "data")
                for got, want in zip(self.verdicts(record), self.verdicts(metres), strict=True):
                    if want is None:
                        self.assertIsNone(got)
                        continue
                    reals = ("mean_deviation_m", "covered_fraction")  # the same to the units' conversion
                    self.assertEqual({k: v for k, v in got.items() if k not in reals},
                                     {k: v for k, v in want.items() if k not in reals})
                    for key in reals:
                        if want[key] is None:
                            self.assertIsNone(got[key], key)
                        else:
                            self.assertAlmostEqual(got[key], want[key], delta=1e-7, msg=key)
                for key in ("strokes_accepted", "strokes_assisted", "strokes_written", "refusals"):
                    self.assertEqual(record[key], metres[key], key)
                for a, b in zip(record["per_character"][0]["per_stroke"], metres["per_character"][0]["per_stroke"]):
                    if b["written"]:
                        self.assertAlmostEqual(a["mean_deviation_m"], b["mean_deviation_m"], delta=1e-7)

    # ---- a row ----------------------------------------------------------------------------------------

    def test_row_of_two_numbers_strokes_from_1_within_each_character(self):
        plan = [(0, 0, (0.0, 0.0), 1.0), (0, 1, (0.0, 0.0), 1.0), (1, 1, (0.0, 0.0), 1.0), (1, 0, (0.0, 0.0), 1.0)]
        write_csv(self.tmp / "row2.csv", pen_path("十二", plan))
        record, table = self.score("row2", chars="十二")
        self.assertEqual([c["character"] for c in record["per_character"]], ["十", "二"])
        self.assertEqual([[s["index"] for s in c["per_stroke"]] for c in record["per_character"]], [[0, 1], [0, 1]])
        self.assertEqual((record["strokes_total"], record["strokes_accepted"], record["order_errors"]), (4, 3, 1))
        self.assertEqual(sorted(table[0]["rows"]), [1, 2])
        self.assertEqual(sorted(table[1]["rows"]), [1, 2])
        self.assertEqual(table[1]["rows"][2][1], "refused: wrong order (written while stroke 1 was due)")
        first = self.verdicts(record, 1)[0]
        self.assertEqual((first["expected_stroke"], first["matched_stroke"]), (0, 1))
        self.assertIn("3 of 4", table[2]["totals"]["strokes accepted"])

    def test_row_of_three_with_the_middle_character_left_out(self):
        plan = [(0, 0, (0.0, 0.0), 1.0), (0, 1, (0.0, 0.0), 1.0), (2, 0, (0.0, 0.0), 1.0), (2, 1, (0.0, 0.0), 1.0)]
        write_csv(self.tmp / "row3.csv", pen_path("十二人", plan))
        record, table = self.score("row3", chars="十二人")
        self.assertEqual([c["strokes_accepted"] for c in record["per_character"]], [2, 0, 2])
        self.assertEqual((record["strokes_total"], record["strokes_written"], record["completed_in_order"]),
                         (6, 4, False))
        self.assertEqual({n: v for n, (_, v) in table[1]["rows"].items()}, {1: "not written", 2: "not written"})
        self.assertEqual(record["strokes_accepted"], sum(c["strokes_accepted"] for c in record["per_character"]))

    def test_row_credits_the_misses_of_one_character_to_its_own_stroke(self):
        # Five pen-downs 8 mm below 二's stroke 1, inside 二's box, then 二's stroke 2, after 十 written right:
        # each pen-down goes to the character whose box holds it (docs/metrics.md), so 二's stroke 1 is assisted.
        plan = ([(0, 0, (0.0, 0.0), 1.0), (0, 1, (0.0, 0.0), 1.0)] + [(1, 0, (0.0, -0.008), 1.0)] * 5
                + [(1, 1, (0.0, 0.0), 1.0)])
        write_csv(self.tmp / "rowassist.csv", pen_path("十二", plan))
        record, table = self.score("rowassist", chars="十二")
        self.assertEqual([c["strokes_assisted"] for c in record["per_character"]], [0, 1])
        self.assertEqual([c["strokes_accepted"] for c in record["per_character"]], [2, 1])
        self.assertEqual((record["strokes_assisted"], record["strokes_accepted"]), (1, 3))
        verdict = table[1]["rows"][1][1]
        self.assertTrue(verdict.startswith("assisted (last refused: wrong place"), verdict)
        self.assertEqual(table[1]["rows"][2][1], "accepted")

    # ---- the trace file's forms ------------------------------------------------------------------------

    def same_as_good(self, trace):
        record, _ = self.score("good", trace=trace)
        expected, _ = self.scores["good"]
        self.assertEqual({k: v for k, v in record.items() if k != "trace"},
                         {k: v for k, v in expected.items() if k != "trace"})

    def test_columns_in_another_order_with_extra_columns_score_the_same(self):
        ticks = self.ticks["good"]
        lines = ["state,z,y,fx,t,x,pressure,note"]
        for t, x, y, z in ticks:
            lines.append(f"2,{z:.7f},{y:.7f},0.5,{t:.6f},{x:.7f},0.3,hello")
        (self.tmp / "order.csv").write_text("\n".join(lines) + "\n", encoding="utf-8")
        self.same_as_good("order.csv")

    def test_column_names_with_units_score_the_same(self):
        write_csv(self.tmp / "units.csv", self.ticks["good"], header=("t_s", "x_m", "y_m", "z_m"))
        self.same_as_good("units.csv")

    def test_pen_column_as_numpy_and_pandas_spell_it_scores_the_same(self):
        ticks = self.ticks["good"]
        for spelling in ("%.18e", "%.1f"):
            with self.subTest(spelling=spelling):
                lines = ["t,x,y,pen"] + [f"{t:.6f},{x:.7f},{y:.7f}," + spelling % float(z <= CONTACT_M)
                                         for t, x, y, z in ticks]
                (self.tmp / "pen.csv").write_text("\n".join(lines) + "\n", encoding="utf-8")
                self.same_as_good("pen.csv")

    def test_crlf_and_a_byte_order_mark_score_the_same(self):
        text = csv_text(self.ticks["good"]).replace("\n", "\r\n")
        (self.tmp / "crlf.csv").write_bytes(b"\xef\xbb\xbf" + text.encode("utf-8"))
        self.same_as_good("crlf.csv")

    def test_quoted_fields_score_the_same(self):
        lines = ['"t","x","y","z"'] + [",".join(f'"{v}"' for v in line.split(","))
                                       for line in csv_text(self.ticks["good"]).splitlines()[1:]]
        (self.tmp / "quoted.csv").write_text("\n".join(lines) + "\n", encoding="utf-8")
        self.same_as_good("quoted.csv")

    def test_duplicate_timestamps_are_taken(self):
        ticks = self.ticks["good"].copy()
        ticks[30, 0] = ticks[29, 0]
        ticks[31, 0] = ticks[29, 0]
        write_csv(self.tmp / "dup.csv", ticks)
        record, _ = self.score("good", trace="dup.csv")
        self.assertEqual(record["strokes_accepted"], 2)

    def test_time_going_backwards_is_refused_at_its_line(self):
        ticks = self.ticks["good"].copy()
        ticks[50, 0] = ticks[48, 0] - 0.001
        write_csv(self.tmp / "back.csv", ticks)
        result = run(["score", "back.csv", "--character", "十", "--json", "back.json"], self.tmp)
        self.assert_one_error(result, 1, "back.csv:52")  # the header is line 1, row 50 line 52
        self.assertFalse((self.tmp / "back.json").exists())

    def test_row_of_nan_is_refused_at_its_line(self):
        lines = csv_text(self.ticks["good"]).splitlines()
        lines[40] = "nan,nan,nan,nan"
        (self.tmp / "nan.csv").write_text("\n".join(lines) + "\n", encoding="utf-8")
        self.assert_one_error(run(["score", "nan.csv", "--character", "十"], self.tmp), 1, "nan.csv:41")

    def test_nan_in_x_is_refused_naming_the_line_and_column(self):
        lines = csv_text(self.ticks["good"]).splitlines()
        t, _, y, z = lines[40].split(",")
        lines[40] = f"{t},nan,{y},{z}"
        (self.tmp / "nanx.csv").write_text("\n".join(lines) + "\n", encoding="utf-8")
        line = self.assert_one_error(run(["score", "nanx.csv", "--character", "十"], self.tmp), 1, "nanx.csv:41")
        self.assertRegex(line, r"\bx\b")

    def test_cr_alone_is_refused_saying_so(self):
        (self.tmp / "cr.csv").write_text(csv_text(self.ticks["good"]).replace("\n", "\r"), encoding="utf-8")
        line = self.assert_one_error(run(["score", "cr.csv", "--character", "十"], self.tmp), 1, "cr.csv")
        self.assertIn("CR", line.upper())

    def test_semicolons_leave_the_header_without_t(self):
        (self.tmp / "semi.csv").write_text(csv_text(self.ticks["good"]).replace(",", ";"), encoding="utf-8")
        line = self.assert_one_error(run(["score", "semi.csv", "--character", "十"], self.tmp), 1, "semi.csv")
        self.assertRegex(line, r"\bt\b")

    def test_x_in_millimetres_or_capitals_is_refused_for_the_x_it_lacks(self):
        # docs/metrics.md: "`X`, `x_mm` or `pressure` name no column, so a trace in other units or with a
        # pressure instead of a pen is refused for the column it lacks, never read as another".
        for header, lacking in ((("t", "x_mm", "y_mm", "z"), r"\bx\b"), (("t", "X", "y", "z"), r"\bx\b"),
                                (("t", "x", "y", "pressure"), r"\b(pen|z)\b")):
            with self.subTest(header=header):
                write_csv(self.tmp / "mm.csv", self.ticks["good"], header=header)
                line = self.assert_one_error(run(["score", "mm.csv", "--character", "十"], self.tmp), 1, "mm.csv")
                self.assertRegex(line, lacking)

    def test_row_with_a_field_missing_is_refused_at_its_line(self):
        lines = csv_text(self.ticks["good"]).splitlines()
        lines[25] = lines[25].rsplit(",", 1)[0]
        (self.tmp / "short.csv").write_text("\n".join(lines) + "\n", encoding="utf-8")
        self.assert_one_error(run(["score", "short.csv", "--character", "十"], self.tmp), 1, "short.csv:26")

    def test_header_with_both_pen_and_z_is_refused(self):
        lines = ["t,x,y,z,pen"] + [f"{t:.6f},{x:.7f},{y:.7f},{z:.7f},{int(z <= CONTACT_M)}"
                                   for t, x, y, z in self.ticks["good"]]
        (self.tmp / "both.csv").write_text("\n".join(lines) + "\n", encoding="utf-8")
        line = self.assert_one_error(run(["score", "both.csv", "--character", "十"], self.tmp), 1, "both.csv")
        self.assertIn("pen", line)

    def test_header_with_neither_pen_nor_z_is_refused(self):
        lines = ["t,x,y"] + [f"{t:.6f},{x:.7f},{y:.7f}" for t, x, y, _ in self.ticks["good"]]
        (self.tmp / "neither.csv").write_text("\n".join(lines) + "\n", encoding="utf-8")
        line = self.assert_one_error(run(["score", "neither.csv", "--character", "十"], self.tmp), 1, "neither.csv")
        self.assertTrue("pen" in line or "z" in line, line)

    def test_pen_true_or_a_half_is_refused_at_its_line(self):
        for value in ("true", "0.5", "2"):
            with self.subTest(value=value):
                lines = ["t,x,y,pen"] + [f"{t:.6f},{x:.7f},{y:.7f},{int(z <= CONTACT_M)}"
                                         for t, x, y, z in self.ticks["good"]]
                lines[10] = lines[10].rsplit(",", 1)[0] + "," + value
                (self.tmp / "pen2.csv").write_text("\n".join(lines) + "\n", encoding="utf-8")
                self.assert_one_error(run(["score", "pen2.csv", "--character", "十"], self.tmp), 1, "pen2.csv:11")

    def test_pen_within_half_a_millimetre_of_the_paper_writes_and_above_it_does_not(self):
        # docs/metrics.md "Trace CSV": down when z <= 0.5 mm.
        for z, written in (("0.0005", 2), ("0.0004", 2), ("0.0005001", 0)):
            with self.subTest(z=z):
                lines = csv_text(self.ticks["good"]).splitlines()
                for i, row in enumerate(self.ticks["good"]):
                    if row[3] <= CONTACT_M:
                        lines[i + 1] = lines[i + 1].rsplit(",", 1)[0] + "," + z
                (self.tmp / "hover.csv").write_text("\n".join(lines) + "\n", encoding="utf-8")
                record, _ = self.score("good", trace="hover.csv")
                self.assertEqual((record["strokes_written"], record["strokes_accepted"]), (written, written))

    def test_times_in_milliseconds_keep_distances_and_verdicts_and_multiply_the_times(self):
        ticks = self.ticks["good"].copy()
        ticks[:, 0] *= 1000.0
        write_csv(self.tmp / "ms.csv", ticks, fmt=("%.3f", "%.7f", "%.7f", "%.7f"))
        record, _ = self.score("good", trace="ms.csv")
        expected, _ = self.scores["good"]
        self.assertEqual(self.verdicts(record), self.verdicts(expected))
        for got, want in zip(record["per_character"][0]["per_stroke"], expected["per_character"][0]["per_stroke"]):
            for key in ("mean_deviation_m", "max_deviation_m", "frechet_m", "dtw_m", "path_length_m"):
                self.assertEqual(got[key], want[key], key)
            self.assertAlmostEqual(got["time_s"], want["time_s"] * 1000.0, delta=1e-6)

    def test_epoch_times_give_the_same_verdicts_and_times_to_a_quarter_microsecond(self):
        ticks = self.ticks["good"].copy()
        ticks[:, 0] += 1.7e9
        write_csv(self.tmp / "epoch.csv", ticks)
        record, _ = self.score("good", trace="epoch.csv")
        expected, _ = self.scores["good"]
        self.assertEqual(self.verdicts(record), self.verdicts(expected))
        for got, want in zip(record["per_character"][0]["per_stroke"], expected["per_character"][0]["per_stroke"]):
            self.assertEqual(got["mean_deviation_m"], want["mean_deviation_m"])
            self.assertAlmostEqual(got["time_s"], want["time_s"], delta=5e-7)

    def test_blank_and_comment_lines_are_skipped(self):
        lines = csv_text(self.ticks["good"]).splitlines()
        lines[20:20] = ["", "# the pen slipped here", ""]
        lines.insert(1, "# recorded on a tablet")
        (self.tmp / "comments.csv").write_text("\n".join(lines) + "\n", encoding="utf-8")
        self.same_as_good("comments.csv")

    def test_quoted_field_holding_a_comma_is_refused_naming_its_line(self):
        lines = csv_text(self.ticks["good"]).splitlines()
        t, x, y, z = lines[9].split(",")
        lines[9] = f'{t},"{x.replace(".", ",")}",{y},{z}'
        (self.tmp / "comma.csv").write_text("\n".join(lines) + "\n", encoding="utf-8")
        self.assert_one_error(run(["score", "comma.csv", "--character", "十"], self.tmp), 1, "comma.csv:10")

    def test_gzip_trace_scores_the_same_and_bytes_after_its_member_are_refused(self):
        import gzip
        data = gzip.compress(csv_text(self.ticks["good"]).encode("utf-8"))
        (self.tmp / "good.csv.gz").write_bytes(data)
        self.same_as_good("good.csv.gz")
        (self.tmp / "padded.csv.gz").write_bytes(data + b"\0" * 16)
        line = self.assert_one_error(run(["score", "padded.csv.gz", "--character", "十"], self.tmp), 1,
                                     "padded.csv.gz")
        self.assertIn(str(len(data)), line)

    def test_utf16_text_is_refused_saying_so(self):
        (self.tmp / "u16.csv").write_bytes(csv_text(self.ticks["good"][:40]).encode("utf-16"))
        line = self.assert_one_error(run(["score", "u16.csv", "--character", "十"], self.tmp), 1, "u16.csv")
        self.assertIn("UTF-16", line.upper())

    def test_column_named_twice_is_refused(self):
        lines = ["t,x,y,z,x_m"] + [f"{t:.6f},{x:.7f},{y:.7f},{z:.7f},{x:.7f}" for t, x, y, z in self.ticks["good"]]
        (self.tmp / "twice.csv").write_text("\n".join(lines) + "\n", encoding="utf-8")
        line = self.assert_one_error(run(["score", "twice.csv", "--character", "十"], self.tmp), 1, "twice.csv")
        self.assertRegex(line, r"\bx(_m)?\b")

    def test_position_with_no_place_in_data_units_is_refused_naming_its_column(self):
        lines = csv_text(self.ticks["good"]).splitlines()
        t, x, _, z = lines[30].split(",")
        lines[30] = f"{t},{x},1e308,{z}"
        (self.tmp / "far.csv").write_text("\n".join(lines) + "\n", encoding="utf-8")
        line = self.assert_one_error(run(["score", "far.csv", "--character", "十"], self.tmp), 1, "far.csv:31")
        self.assertRegex(line, r"\by\b")

    def test_the_10001st_pen_down_is_refused_at_its_line_and_10000_are_taken(self):
        ticks = self.ticks["good"]
        x, y = ticks[5, 1], ticks[5, 2]
        for count, status in ((10000, 0), (10001, 1)):
            with self.subTest(pen_downs=count):
                rows = [f"{i / 1000:.3f},{x:.7f},{y:.7f},{1 - i % 2}" for i in range(2 * count)]
                (self.tmp / "many.csv").write_text("t,x,y,pen\n" + "\n".join(rows) + "\n", encoding="utf-8")
                result = run(["score", "many.csv", "--character", "十", "--json", "many.json"], self.tmp)
                if status:
                    # the 10,001st pen-down is the data row 20,000: line 20,002
                    self.assert_one_error(result, 1, "many.csv:20002")
                else:
                    self.assertEqual(result.returncode, 0, result.stderr)
                    record = json.loads((self.tmp / "many.json").read_text(encoding="utf-8"))
                    self.assertEqual(record["per_character"][0]["ignored_segments"], count)
                    self.assertEqual(record["strokes_written"], 0)

    def test_trace_name_with_an_escape_sequence_is_printed_as_text(self):
        name = "e\x1b[31mred.csv"
        write_csv(self.tmp / name, self.ticks["good"])
        result = run_ok(["score", name, "--character", "十"], self.tmp)
        self.assertNotIn(b"\x1b", result.stdout)
        self.assertIn(b"e\\x1b[31mred.csv", result.stdout)

    def test_json_on_its_own_trace_is_refused_and_the_trace_left_unchanged(self):
        before = (self.tmp / "good.csv").read_bytes()
        result = run(["score", "good.csv", "--character", "十", "--json", "./good.csv"], self.tmp)
        self.assert_one_error(result, 2, "--json")
        self.assertEqual((self.tmp / "good.csv").read_bytes(), before)

    def test_character_the_library_lacks_is_a_usage_error_naming_it(self):
        result = run(["score", "good.csv", "--character", "Q"], self.tmp)
        self.assert_one_error(result, 2, "Q")

    def test_samples_in_the_table_heading_are_the_json_samples(self):
        result = run_ok(["score", "good.csv", "--character", "十"], self.tmp)
        expected, _ = self.scores["good"]
        heading = result.stdout.decode("utf-8").splitlines()[0]
        self.assertIn(f"({expected['samples']} samples", heading)
        self.assertEqual(expected["samples"], len(self.ticks["good"]))

    STRICT = ["--guidance", "off", "--mean-deviation", "0.0001", "--mean-deviation-cap", "0.0001",
              "--assist-after-misses", "2"]

    def trial_and_its_score(self, name, options, assist, *acceptance):
        """A simulated trial of 十 with `options` (run once), its record and `score` of its CSV with the stroke
        acceptance's options `acceptance`."""
        if not (self.tmp / f"{name}.json").exists():
            run_ok(["trial", "十", *options, "--json", f"{name}.json", "--csv", f"{name}.csv"], self.tmp)
        trial = json.loads((self.tmp / f"{name}.json").read_text(encoding="utf-8"))
        record, _ = self.score(name, "--assist-after-misses", assist, *acceptance, chars="十")
        return trial, record

    def test_a_trials_csv_scored_gives_the_trials_verdicts(self):
        # docs/cli.md `trial`: the record has "every key of the one metrics record of what was written ... with
        # the values `calligraphy score` gives for the trial's CSV".
        trial, record = self.trial_and_its_score("trial", ["--assist-after-misses", "2"], "2")
        for key in ("strokes_written", "strokes_accepted", "refusals", "order_errors", "unmatched_segments"):
            self.assertEqual(trial[key], record[key], key)

    def test_a_strict_trials_csv_scored_gives_the_trials_verdicts(self):
        # The same trial, judged with a mean deviation of 0.1 mm (`trial --mean-deviation`): docs/cli.md
        # promises `score`'s values for its CSV, scored with the trial's stroke acceptance options (found here
        # first: `score` had only the assist count, so it judged with the default tolerances).
        trial, record = self.trial_and_its_score("strict", self.STRICT, "2", *self.STRICT[2:6])
        for key in ("strokes_written", "strokes_accepted", "refusals", "unmatched_segments"):
            self.assertEqual(trial[key], record[key], key)

    def test_a_strict_trials_csv_scored_by_python_with_its_acceptance_gives_its_verdicts(self):
        trial, _ = self.trial_and_its_score("strict", self.STRICT, "2")
        acceptance = cg.StrokeAcceptance(mean_deviation_m=0.0001, mean_deviation_cap_m=0.0001, assist_after_misses=2)
        record = cg.score(str(self.tmp / "strict.csv"), "十", acceptance=acceptance)
        for key in ("strokes_written", "strokes_accepted", "strokes_assisted", "refusals", "unmatched_segments"):
            self.assertEqual(trial[key], record[key], key)

    # ---- Python's score ---------------------------------------------------------------------------------

    def test_python_score_gives_the_programs_json(self):
        for name in ("good", "assist", "kou13"):
            with self.subTest(trace=name):
                got = cg.score(str(self.tmp / f"{name}.csv"), self.chars[name])
                expected, _ = self.scores[name]
                self.assertEqual({k: v for k, v in got.items() if k != "trace"},
                                 {k: v for k, v in expected.items() if k != "trace"})

    def test_python_acceptance_assist_after_misses_is_the_programs_option(self):
        got = cg.score(str(self.tmp / "assist.csv"), "十", acceptance=cg.StrokeAcceptance(assist_after_misses=4))
        expected, _ = self.score("assist", "--assist-after-misses", "4")
        self.assertEqual({k: v for k, v in got.items() if k != "trace"},
                         {k: v for k, v in expected.items() if k != "trace"})

    def test_python_columns_with_units_in_another_order_score_the_same(self):
        ticks = self.ticks["good"]
        got = cg.score({"z_m": ticks[:, 3], "y_m": ticks[:, 2], "t_s": ticks[:, 0], "x_m": ticks[:, 1]}, "十")
        expected, _ = self.scores["good"]
        self.assertEqual({k: v for k, v in got.items() if k != "trace"},
                         {k: v for k, v in expected.items() if k != "trace"})

    def test_python_units_other_than_m_or_data_is_invalid_argument_naming_it(self):
        with self.assertRaisesRegex(cg.InvalidArgument, "units"):
            cg.score(str(self.tmp / "good.csv"), "十", units="mm")

    def test_python_columns_of_other_lengths_are_refused_naming_each(self):
        ticks = self.ticks["good"]
        with self.assertRaises(cg.InvalidArgument) as caught:
            cg.score({"t": ticks[:, 0], "x": ticks[:-1, 1], "y": ticks[:, 2], "z": ticks[:, 3]}, "十")
        self.assertIn(str(len(ticks) - 1), str(caught.exception))
        self.assertIn(str(len(ticks)), str(caught.exception))

    def test_python_start_radius_out_of_its_range_is_invalid_argument_naming_it(self):
        for value in (0.0, -0.001, float("nan")):
            with self.subTest(start_radius_m=value):
                with self.assertRaisesRegex(cg.InvalidArgument, "start_radius_m"):
                    cg.score(str(self.tmp / "good.csv"), "十", start_radius_m=value)

    def test_python_contact_threshold_decides_which_samples_are_down(self):
        ticks = self.ticks["good"].copy()
        ticks[ticks[:, 3] <= CONTACT_M, 3] = 0.0004
        columns = {"t": ticks[:, 0], "x": ticks[:, 1], "y": ticks[:, 2], "z": ticks[:, 3]}
        for threshold, written in ((0.0004, 2), (0.0003, 0)):
            with self.subTest(contact_threshold_m=threshold):
                self.assertEqual(cg.score(columns, "十", contact_threshold_m=threshold)["strokes_written"], written)

    def test_python_scene_of_another_layout_scores_as_laid_out_and_by_name_finds_nothing(self):
        # docs/python.md: a Scene is "scored as it is laid out: its placement, its start radius ... and its
        # paper height"; "a character given by name would be placed at the default layout and find nothing".
        scene = cg.Scene("十", layout=cg.SceneLayout(character_size_m=0.03, paper_z_m=0.01))
        ticks = pen_path(scene, [(0, 0, (0.0, 0.0), 1.0), (0, 1, (0.0, 0.0), 1.0)])
        columns = {"t": ticks[:, 0], "x": ticks[:, 1], "y": ticks[:, 2], "z": ticks[:, 3]}
        laid_out = cg.score(columns, scene)
        self.assertEqual((laid_out["strokes_accepted"], laid_out["strokes_written"]), (2, 2))
        by_name = cg.score(columns, "十")
        self.assertEqual((by_name["strokes_accepted"], by_name["strokes_written"]), (0, 0))

    def test_python_pen_beside_z_is_refused(self):
        ticks = self.ticks["good"]
        with self.assertRaises(cg.InvalidArgument):
            cg.score({"t": ticks[:, 0], "x": ticks[:, 1], "y": ticks[:, 2], "z": ticks[:, 3],
                      "pen": (ticks[:, 3] <= CONTACT_M).astype(float)}, "十")


if __name__ == "__main__":
    unittest.main()
