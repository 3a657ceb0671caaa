#!/usr/bin/env python3
"""Round 33A: `score`, `strokes` and `curriculum` as a teacher uses them on traces from elsewhere. From the docs
alone (docs/cli.md "score", "Pen traces: format and limits", "strokes", "curriculum", "Exit statuses";
docs/metrics.md "Per character", "The one metrics record", "Matching written strokes to the character", "Trace
CSV"; docs/stroke-acceptance.md "The rule", "No dead end"; docs/python.md "Scoring any pen trace", "Scenes";
docs/experiments.md "What to practise next", "Trace files", "Trial records"; docs/typical-strokes.md).

A teacher's traces are written here by hand with numpy along the medians of the placed character
(`Scene(...).strokes[k].median_m`), at a person's pace (0.1 m/s, 1 kHz or 100 Hz), pen-up rows between the
strokes: every stroke in turn, reversed, half, 4 mm and 8 mm off, in the wrong order, one missing, one extra, an
earlier one again, a dot written as a tiny loop, a tap, a stroke written in no time, a stroke missed five times
(the assisted credit; the fifth left down at the trace's end), a row of two characters. Each verdict is held to
what the docs promise (the refusal's name, strokes numbered from 1 in the table and from 0 in the JSON, the
distance in mm, counts that add up, times and lengths computed here) and the same trace is scored by Python's
`calligraphy.score` from the file, from columns and from a Scene of another size. The hostile forms of one trace
(columns in another order, extra and empty ones, names with units, a byte-order mark, CR LF and quotes, comment
and blank lines, gzip in one and two members and under a .csv name, pen spelt as numpy and pandas write it or
with a sign, times in exponent form, from the epoch or in ms, `z` at the 0.5 mm threshold, data units, a 64 MiB
comment line under a memory limit) read as the plain one; the refused ones (no pen column, `x_mm`, upper case,
semicolons, tabs, a column twice, a quoted comma, CR line ends, UTF-16, NaN, 1e308, time going back, pen 0.5,
both pen and z, 1,000,001 rows, 10,001 pen-downs, gzip cut or with trailing bytes) give one line naming the
file, the line and the column. A session's `.trace.h5` scores as its `trace` CSV and as its record, and is
refused cut or damaged; `strokes` prints the docs' table; `curriculum` reads that session.

CALLIGRAPHY_CLI names the program; PYTHONPATH the built Python package; CALLIGRAPHY_SOURCE_DIR the sources (for
docs/typical-strokes.md). CALLIGRAPHY_SANITIZED=1 takes five cases.
"""
import gzip
import json
import math
import os
import re
import resource
import shutil
import tempfile
import unittest
from pathlib import Path

from outsider import SANITIZED, OneErrorLine, run, run_ok, sanitized_subset

try:
    import numpy as np
    import calligraphy as cg
except ImportError:  # reported by setUpClass: every trace is drawn with numpy along the package's medians
    np = cg = None

load_tests = sanitized_subset({"test_median_trace_every_stroke_accepted_in_turn_with_the_counts_computed_here",
                               "test_strokes_swapped_one_order_error_first_refused_wrong_order",
                               "test_nan_in_a_row_refused_naming_file_line_column_and_value",
                               "test_semicolon_separated_trace_refused_for_lacking_column_t",
                               "test_curriculum_subject_without_saved_trials_is_a_usage_error"})

SOURCE = Path(os.environ.get("CALLIGRAPHY_SOURCE_DIR", Path(__file__).resolve().parents[2]))
RATE_HZ = 1000.0
SPEED_M_S = 0.1
UP_ROWS = 20
CONTACT_M = 0.0005           # docs/cli.md: "the pen touches at z <= 0.5 mm"
HOVER_M = 0.002
REASON_WORDS = {"too_short": "too short", "backwards": "backwards", "wrong_place": "wrong place",
                "wrong_stroke": "wrong stroke", "wrong_order": "wrong order"}
# The keys `score --json` adds to the one metrics record (docs/cli.md "score": `character`, `trace`, `units`,
# `samples`, and every key of the metrics record).
SCORE_ONLY_KEYS = {"character", "trace", "units", "samples"}


def resample(points, step):
    """A polyline resampled at equal arc length, at most `step` apart, ends kept."""
    p = np.asarray(points, dtype=float)
    s = np.r_[0.0, np.cumsum(np.hypot(*np.diff(p, axis=0).T))]
    n = max(int(math.ceil(s[-1] / step)), 2)
    u = np.linspace(0.0, s[-1], n + 1)
    return np.column_stack([np.interp(u, s, p[:, 0]), np.interp(u, s, p[:, 1])])


def cut(points, fraction):
    """The first `fraction` of a polyline by arc length."""
    p = resample(points, 1e-5)
    s = np.r_[0.0, np.cumsum(np.hypot(*np.diff(p, axis=0).T))]
    return p[s <= fraction * s[-1]]


def pen_path(character, plan, rate=RATE_HZ, speed=SPEED_M_S):
    """The samples of a pen writing `plan` on `character` as `Scene(character)` places it: a list of (stroke
    index over the scene, kind, (dx, dy) [m]) with kind `whole`, `reversed`, `half`, `loop` (a circle of 1.5 mm
    radius round the stroke's middle) or `tap` (two samples at its start), each pen-down at `speed`, sampled
    at `rate`, pen-up rows carried through the air between them and resting before and after. Returns
    (columns t, x, y, pen as arrays; the pen-down segments as [begin, end) sample indices)."""
    medians = [np.asarray(s.median_m, dtype=float) for s in cg.Scene(character).strokes]
    rows, segments, here = [], [], None
    for k, kind, (dx, dy) in plan:
        m = medians[k]
        if kind == "reversed":
            m = m[::-1]
        elif kind == "half":
            m = cut(m, 0.5)
        elif kind == "tap":                          # two samples 0.1 mm apart: too short to score
            m = np.array([m[0], m[0] + [speed / rate, 0.0]])
        elif kind == "loop":
            middle = cut(m, 0.5)[-1]
            a = np.linspace(0.0, 2 * math.pi, 65)
            m = middle + 0.0015 * np.column_stack([np.cos(a), np.sin(a)])
        p = (m if kind == "tap" else resample(m, speed / rate)) + np.array([dx, dy])
        if here is None:
            rows += [(p[0][0], p[0][1], 0)] * UP_ROWS
        else:
            rows += [(*(here * (1 - a) + p[0] * a), 0) for a in np.linspace(0.0, 1.0, UP_ROWS)]
        segments.append((len(rows), len(rows) + len(p)))
        rows += [(q[0], q[1], 1) for q in p]
        here = p[-1]
    rows += [(here[0], here[1], 0)] * UP_ROWS
    a = np.array(rows, dtype=float)
    columns = {"t": np.round(np.arange(len(a)) / rate, 6), "x": np.round(a[:, 0], 9),
               "y": np.round(a[:, 1], 9), "pen": a[:, 2].astype(int)}
    return columns, segments


def csv_text(columns, order=("t", "x", "y", "pen"), z=False):
    """The columns as the CSV the docs describe (`z` instead of `pen`: on paper at the contact threshold)."""
    names = [("z" if (c == "pen" and z) else c) for c in order]
    lines = [",".join(names)]
    for i in range(len(columns["t"])):
        fields = []
        for c in order:
            if c == "t":
                fields.append("%.6f" % columns["t"][i])
            elif c in ("x", "y"):
                fields.append("%.9f" % columns[c][i])
            elif c == "pen" and z:
                fields.append("%.4f" % (CONTACT_M if columns["pen"][i] else HOVER_M))
            elif c == "pen":
                fields.append("%d" % columns["pen"][i])
            else:
                fields.append(c)
        lines.append(",".join(fields))
    return "\n".join(lines) + "\n"


def table_rows(text):
    """`score`'s table per reference stroke: {number: (acronym, typical id, verdict text)}."""
    rows = {}
    for line in text.splitlines():
        m = re.match(r"^\s+(\d+)\s+(\S+)\s+(\d+)\s+(?:\S+\s+){5}(\S.*)$", line)
        if m:
            rows[int(m.group(1))] = (m.group(2), int(m.group(3)), m.group(4).strip())
    return rows


def total(text, key):
    """The first number of `score`'s total line `key`."""
    for line in text.splitlines():
        if line.strip().startswith(key):
            return int(line.strip()[len(key):].split()[0])
    raise AssertionError(f"no total line {key!r} in\n{text}")


def without(d, keys):
    return {k: v for k, v in d.items() if k not in keys}


class Traces(unittest.TestCase, OneErrorLine):
    """Shared: a temporary folder and the scores of traces written into it."""

    @classmethod
    def setUpClass(cls):
        if cg is None:
            raise unittest.SkipTest("numpy and the calligraphy Python package (PYTHONPATH) are needed")
        cls.tmp = Path(tempfile.mkdtemp(prefix="round33a-"))

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.tmp, ignore_errors=True)

    def write(self, name, data):
        path = self.tmp / name
        if isinstance(data, str):
            path.write_bytes(data.encode("utf-8"))
        else:
            path.write_bytes(data)
        return name

    def score(self, name, character="十", *extra):
        """`score NAME --character C --json -` and its table (a second run): (json, table text)."""
        out = run_ok(["score", name, "--character", character, "--json", "-", *extra], self.tmp)
        self.assertEqual(out.stderr, b"")
        table = run_ok(["score", name, "--character", character, *extra], self.tmp)
        return json.loads(out.stdout), table.stdout.decode("utf-8")

    def score_json(self, name, character="十", *extra):
        out = run_ok(["score", name, "--character", character, "--json", "-", *extra], self.tmp)
        return json.loads(out.stdout)

    def segments(self, scored, character=0):
        return scored["per_character"][character]["segments"]

    def verdicts(self, scored, character=0):
        return [s["verdict"] and s["verdict"]["refusal"] for s in self.segments(scored, character)]

    def assert_totals_add_up(self, scored, table):
        """docs/cli.md: strokes accepted, refused and not written add up to the strokes; pen-downs refused are
        the JSON's `refusals`."""
        accepted, refused = total(table, "strokes accepted"), total(table, "strokes refused")
        not_written = total(table, "strokes not written")
        self.assertEqual(accepted, scored["strokes_accepted"])
        self.assertEqual(accepted + refused + not_written + scored["strokes_assisted"], scored["strokes_total"])
        self.assertEqual(total(table, "pen-downs refused"), sum(scored["refusals"].values()))

    def off_words(self, verdict):
        """The table's words for how far off a refused pen-down was (docs/cli.md "score")."""
        v = verdict["mean_deviation_m"]
        return "(never near its start)" if v is None else f"({v * 1000:.1f} mm off)"


class ScoreVerdicts(Traces):
    """One trace per thing a teacher's pupil does, each verdict held to the docs."""

    def trace(self, name, plan, character="十", **kw):
        columns, segments = pen_path(character, plan, **kw)
        self.write(name, csv_text(columns))
        return columns, segments

    def test_median_trace_every_stroke_accepted_in_turn_with_the_counts_computed_here(self):
        columns, segments = self.trace("whole.csv", [(0, "whole", (0, 0)), (1, "whole", (0, 0))])
        scored, table = self.score("whole.csv")
        self.assertEqual(scored["samples"], len(columns["t"]))
        self.assertEqual((scored["strokes_total"], scored["strokes_written"], scored["strokes_accepted"]), (2, 2, 2))
        self.assertTrue(scored["completed_in_order"])
        self.assertEqual(scored["order_errors"], 0)
        self.assertEqual(sum(scored["refusals"].values()), 0)
        self.assertEqual([(s["begin"], s["end"]) for s in self.segments(scored)], segments)
        self.assertEqual(self.verdicts(scored), ["none", "none"])
        self.assertEqual([s["matched_stroke"] for s in self.segments(scored)], [0, 1])
        t = columns["t"]
        down = [t[e - 1] - t[b] for b, e in segments]
        self.assertAlmostEqual(scored["pen_down_time_s"], sum(down), delta=1e-9)
        self.assertAlmostEqual(scored["total_time_s"], t[segments[-1][1] - 1] - t[segments[0][0]], delta=1e-9)
        character = scored["per_character"][0]
        self.assertEqual(character["pen_lifts"], 1)
        for k, (b, e) in enumerate(segments):
            length = float(np.sum(np.hypot(np.diff(columns["x"][b:e]), np.diff(columns["y"][b:e]))))
            self.assertAlmostEqual(character["per_stroke"][k]["path_length_m"], length, delta=1e-7)
            self.assertEqual(character["per_stroke"][k]["index"], k)
        self.assertLess(scored["mean_deviation_m"], 0.001)
        rows = table_rows(table)
        self.assertEqual(rows, {1: ("H", 1, "accepted"), 2: ("S", 2, "accepted")}, table)
        self.assert_totals_add_up(scored, table)

    def test_same_trace_in_data_units_gives_the_same_verdicts_and_deviations(self):
        columns, segments = pen_path("十", [(0, "whole", (0, 0)), (1, "whole", (0, 0))])
        self.write("m.csv", csv_text(columns))
        placement = cg.Scene("十").characters[0].placement
        data = placement.to_data(np.column_stack([columns["x"], columns["y"]]))
        lines = ["t,x,y,pen"] + ["%.6f,%.9f,%.9f,%d" % (columns["t"][i], data[i, 0], data[i, 1], columns["pen"][i])
                                 for i in range(len(data))]
        self.write("d.csv", "\n".join(lines) + "\n")
        metres = self.score_json("m.csv")
        units = self.score_json("d.csv", "十", "--units", "data")
        self.assertEqual(units["units"], "data")
        self.assertEqual(self.verdicts(units), self.verdicts(metres))
        self.assertEqual(units["strokes_accepted"], 2)
        for key in ("mean_deviation_m", "max_deviation_m", "frechet_m", "dtw_m"):
            self.assertAlmostEqual(units[key], metres[key], delta=1e-8, msg=key)
        python = cg.score(str(self.tmp / "d.csv"), "十", units="data")
        self.assertEqual(self.verdicts(python), self.verdicts(units))
        self.assertAlmostEqual(python["mean_deviation_m"], units["mean_deviation_m"], delta=1e-12)

    def test_hundred_hertz_trace_with_z_at_the_contact_threshold_is_on_paper(self):
        columns, segments = pen_path("十", [(0, "whole", (0, 0)), (1, "whole", (0, 0))], rate=100.0)
        self.write("z100.csv", csv_text(columns, z=True))
        scored = self.score_json("z100.csv")
        self.assertEqual([(s["begin"], s["end"]) for s in self.segments(scored)], segments)
        self.assertEqual(self.verdicts(scored), ["none", "none"])
        self.assertTrue(scored["completed_in_order"])
        frame = {"t_s": columns["t"], "x_m": columns["x"], "y_m": columns["y"],
                 "z_m": np.where(columns["pen"] == 1, CONTACT_M, HOVER_M)}
        import pandas
        python = cg.score(pandas.DataFrame(frame), "十")
        self.assertEqual(self.verdicts(python), self.verdicts(scored))
        self.assertEqual([(s["begin"], s["end"]) for s in self.segments(python)], segments)

    def test_both_strokes_reversed_refused_backwards_then_wrong_place(self):
        self.trace("rev.csv", [(0, "reversed", (0, 0)), (1, "reversed", (0, 0))])
        scored, table = self.score("rev.csv")
        # docs/stroke-acceptance.md: `backwards` names a path reversed along the stroke that is due; a later
        # stroke written backwards while an earlier one is due is `wrong_place`.
        self.assertEqual(self.verdicts(scored), ["backwards", "wrong_place"])
        self.assertEqual(scored["backwards_strokes"], 2)
        self.assertEqual((scored["strokes_written"], scored["strokes_accepted"]), (2, 0))
        rows = table_rows(table)
        first = self.segments(scored)[0]["verdict"]
        self.assertEqual(rows[1][2], "refused: backwards " + self.off_words(first), table)
        self.assertEqual(rows[2][2], "refused: wrong place (written backwards while stroke 1 was due)", table)
        self.assert_totals_add_up(scored, table)

    def test_half_stroke_refused_too_short_then_both_accepted(self):
        self.trace("half.csv", [(0, "half", (0, 0)), (0, "whole", (0, 0)), (1, "whole", (0, 0))])
        scored, table = self.score("half.csv")
        self.assertEqual(self.verdicts(scored), ["too_short", "none", "none"])
        self.assertEqual(scored["refusals"]["too_short"], 1)
        self.assertEqual(scored["strokes_accepted"], 2)
        self.assertEqual(scored["unmatched_segments"], 1)
        self.assertEqual(scored["per_character"][0]["pen_lifts"], 2)
        self.assertEqual({k: v[2] for k, v in table_rows(table).items()}, {1: "accepted", 2: "accepted"})
        self.assertEqual(total(table, "pen-downs refused"), 1)

    def test_stroke_4mm_off_refused_wrong_place_with_its_distance_in_mm(self):
        self.trace("off4.csv", [(0, "whole", (0.0, -0.004))])
        scored, table = self.score("off4.csv")
        self.assertEqual(self.verdicts(scored), ["wrong_place"])
        verdict = self.segments(scored)[0]["verdict"]
        self.assertIsNotNone(verdict["mean_deviation_m"], "4 mm off begins within the 5 mm start radius")
        self.assertTrue(0.0035 <= verdict["mean_deviation_m"] <= 0.0045, verdict)
        rows = table_rows(table)
        self.assertEqual(rows[1][2], "refused: wrong place " + self.off_words(verdict), table)
        self.assertEqual(rows[2][2], "not written", table)
        self.assertEqual(scored["strokes_written"], 0)
        self.assertIsNone(scored["per_character"][0]["per_stroke"][0]["mean_deviation_m"])
        self.assert_totals_add_up(scored, table)

    def test_stroke_8mm_off_never_near_its_start_and_never_credited(self):
        self.trace("off8.csv", [(0, "whole", (0.0, -0.008)), (1, "whole", (0, 0))])
        scored, table = self.score("off8.csv")
        verdict = self.segments(scored)[0]["verdict"]
        self.assertEqual(verdict["refusal"], "wrong_place", verdict)
        self.assertIsNone(verdict["mean_deviation_m"])
        self.assertEqual(scored["strokes_accepted"], 0)
        self.assertEqual(table_rows(table)[1][2], "refused: wrong place (never near its start)", table)
        self.assert_totals_add_up(scored, table)

    def test_stroke_missed_five_times_is_credited_assisted_and_the_next_judged_due(self):
        plan = [(0, "whole", (0.0, -0.004))] * 5 + [(1, "whole", (0, 0))]
        self.trace("assist.csv", plan)
        scored, table = self.score("assist.csv")
        self.assertEqual(self.verdicts(scored), ["wrong_place"] * 5 + ["none"])
        self.assertEqual([s["verdict"]["assists_due"] for s in self.segments(scored)], [False] * 4 + [True, False])
        self.assertEqual((scored["strokes_assisted"], scored["strokes_accepted"]), (1, 1))
        self.assertEqual([s["assisted"] for s in scored["per_character"][0]["per_stroke"]], [True, False])
        last = self.segments(scored)[4]["verdict"]
        off = self.off_words(last)[1:-1]
        rows = table_rows(table)
        self.assertEqual(rows[1][2], f"assisted (last refused: wrong place, {off})", table)
        self.assertEqual(rows[2][2], "accepted", table)
        self.assert_totals_add_up(scored, table)

    def test_strokes_swapped_one_order_error_first_refused_wrong_order(self):
        self.trace("swap.csv", [(1, "whole", (0, 0)), (0, "whole", (0, 0))])
        scored, table = self.score("swap.csv")
        self.assertEqual(self.verdicts(scored), ["wrong_order", "none"])
        self.assertEqual((scored["order_errors"], scored["strokes_written"], scored["strokes_accepted"]), (1, 2, 1))
        self.assertFalse(scored["completed_in_order"])
        rows = table_rows(table)
        self.assertEqual(rows[1][2], "accepted", table)
        self.assertEqual(rows[2][2], "refused: wrong order (written while stroke 1 was due)", table)
        self.assert_totals_add_up(scored, table)

    def test_missing_stroke_is_not_written_null_and_counted(self):
        self.trace("one.csv", [(0, "whole", (0, 0))])
        scored, table = self.score("one.csv")
        character = scored["per_character"][0]
        self.assertEqual(character["missing_strokes"], [1])
        self.assertFalse(character["per_stroke"][1]["written"])
        for key in ("mean_deviation_m", "frechet_m", "dtw_m", "time_s"):
            self.assertIsNone(character["per_stroke"][1][key], key)
        self.assertFalse(scored["completed_in_order"])
        self.assertEqual({k: v[2] for k, v in table_rows(table).items()}, {1: "accepted", 2: "not written"})
        self.assertEqual(total(table, "strokes not written"), 1)
        self.assert_totals_add_up(scored, table)

    def test_extra_stroke_after_every_stroke_accepted_has_no_verdict_and_is_unmatched(self):
        self.trace("extra.csv", [(0, "whole", (0, 0)), (1, "whole", (0, 0)), (1, "whole", (0, 0))])
        scored, table = self.score("extra.csv")
        # docs/metrics.md: "none once every stroke has been accepted"; the repeat goes to no stroke.
        self.assertEqual(self.verdicts(scored), ["none", "none", None])
        self.assertEqual(scored["unmatched_segments"], 1)
        self.assertEqual(scored["strokes_accepted"], 2)
        self.assertTrue(scored["completed_in_order"])
        self.assertEqual(scored["per_character"][0]["pen_lifts"], 2)
        self.assert_totals_add_up(scored, table)

    def test_dot_written_as_a_tiny_loop_is_refused_and_the_dot_then_accepted(self):
        self.assertEqual(cg.CharacterLibrary.default().load("六").typical_stroke_ids[0], 4, "六 begins with a dot")
        self.trace("loop.csv", [(0, "loop", (0, 0)), (0, "whole", (0, 0))], character="六")
        scored, table = self.score("loop.csv", "六")
        verdicts = self.verdicts(scored)
        self.assertEqual(len(verdicts), 2)
        self.assertNotIn(verdicts[0], ("none", None), "a loop on the dot is no dot")
        self.assertEqual(verdicts[1], "none")
        self.assertEqual(scored["strokes_accepted"], 1)
        self.assertEqual(sum(scored["refusals"].values()), 1)
        rows = table_rows(table)
        self.assertEqual([rows[k][2] for k in (1, 2, 3, 4)], ["accepted"] + ["not written"] * 3, table)
        self.assert_totals_add_up(scored, table)

    def test_two_characters_each_scored_in_its_own_box_as_python_scores_them(self):
        columns, segments = self.trace("row.csv", [(0, "whole", (0, 0)), (1, "whole", (0, 0)), (2, "whole", (0, 0))],
                                       character="一十")
        scored = self.score_json("row.csv", "一十")
        self.assertEqual(len(scored["per_character"]), 2)
        self.assertEqual([c["character"] for c in scored["per_character"]], ["一", "十"])
        self.assertEqual((scored["strokes_total"], scored["strokes_accepted"]), (3, 3))
        self.assertTrue(scored["completed_in_order"])
        got = [(s["begin"], s["end"]) for c in scored["per_character"] for s in c["segments"]]
        self.assertEqual(got, segments)
        python = cg.score(str(self.tmp / "row.csv"), "一十")
        self.assertEqual([self.verdicts(python, i) for i in (0, 1)], [self.verdicts(scored, i) for i in (0, 1)])

    def test_trace_ending_pen_down_judges_its_last_pen_down_but_counts_no_miss(self):
        columns, segments = pen_path("十", [(0, "whole", (0.0, -0.004))] * 5)
        end = segments[-1][0] + (segments[-1][1] - segments[-1][0]) // 2
        self.write("cut.csv", csv_text({k: v[:end] for k, v in columns.items()}))
        scored = self.score_json("cut.csv")
        # docs/metrics.md: a pen-down the trace ends in is judged there as if lifted, and counts no miss: four
        # misses, not the five that credit the stroke.
        self.assertEqual(self.verdicts(scored), ["wrong_place"] * 5)
        self.assertEqual(scored["strokes_assisted"], 0)
        self.assertEqual([s["verdict"]["assists_due"] for s in self.segments(scored)], [False] * 5)
        self.assertEqual(self.segments(scored)[-1]["end"], end)

    def test_tap_too_short_to_score_is_ignored_but_counted_as_a_pen_lift(self):
        columns, segments = self.trace("tap.csv", [(0, "whole", (0, 0)), (1, "tap", (0, 0)), (1, "whole", (0, 0))])
        scored = self.score_json("tap.csv")
        character = scored["per_character"][0]
        self.assertEqual(character["ignored_segments"], 1)
        self.assertEqual(character["pen_lifts"], 2)
        self.assertEqual(self.verdicts(scored), ["none", None, "none"])
        self.assertEqual(scored["strokes_accepted"], 2)
        t = columns["t"]
        in_air = sum(t[segments[i + 1][0]] - t[segments[i][1] - 1] for i in range(2))
        self.assertAlmostEqual(character["in_air_time_s"], in_air, delta=1e-9)

    def test_assist_after_misses_zero_never_credits_in_cli_and_python_alike(self):
        self.trace("never.csv", [(0, "whole", (0.0, -0.004))] * 6 + [(1, "whole", (0, 0))])
        scored = self.score_json("never.csv", "十", "--assist-after-misses", "0")
        self.assertEqual(scored["strokes_assisted"], 0)
        self.assertEqual(self.verdicts(scored), ["wrong_place"] * 6 + ["wrong_order"])
        python = cg.score(str(self.tmp / "never.csv"), "十", acceptance=cg.StrokeAcceptance(assist_after_misses=0))
        self.assertEqual(self.verdicts(python), self.verdicts(scored))
        self.assertEqual(python["strokes_assisted"], 0)
        result = run(["score", "never.csv", "--character", "十", "--assist-after-misses", "1001"], self.tmp)
        self.assert_one_error(result, 2, "--assist-after-misses", "1001")

    def test_python_score_refuses_unknown_units_and_columns_of_other_lengths_naming_them(self):
        columns, _ = pen_path("十", [(0, "whole", (0, 0))])
        columns = {k: np.asarray(v) for k, v in columns.items()}
        with self.assertRaisesRegex(cg.InvalidArgument, "mm"):
            cg.score(columns, "十", units="mm")
        short = dict(columns, y=columns["y"][:-1])
        n = len(columns["t"])
        with self.assertRaises(cg.InvalidArgument) as caught:
            cg.score(short, "十")
        self.assertIn(str(n), str(caught.exception))
        self.assertIn(str(n - 1), str(caught.exception))

    def test_stroke_written_in_no_time_is_ignored_and_the_stroke_stays_due(self):
        columns, segments = pen_path("十", [(0, "whole", (0, 0)), (1, "whole", (0, 0))])
        b, e = segments[0]
        columns["t"][b:e] = columns["t"][b]
        self.write("notime.csv", csv_text(columns))
        scored = self.score_json("notime.csv")
        # docs/metrics.md: a segment with no time span is ignored, neither matched nor scored, and gets no
        # verdict; stroke 1 is then still due when stroke 2 is written.
        character = scored["per_character"][0]
        self.assertEqual(character["ignored_segments"], 1)
        self.assertEqual(self.verdicts(scored), [None, "wrong_order"])
        self.assertEqual(scored["strokes_accepted"], 0)

    def test_json_to_a_file_keeps_the_table_on_standard_output(self):
        self.trace("keep.csv", [(0, "whole", (0, 0)), (1, "whole", (0, 0))])
        out = run_ok(["score", "keep.csv", "--character", "十", "--json", "keep.json"], self.tmp)
        self.assertEqual(set(table_rows(out.stdout.decode("utf-8"))), {1, 2})
        self.assertEqual(json.loads((self.tmp / "keep.json").read_text(encoding="utf-8")),
                         self.score_json("keep.csv"))

    def test_earlier_stroke_written_again_is_refused_wrong_stroke(self):
        self.trace("again.csv", [(0, "whole", (0, 0)), (0, "whole", (0, 0)), (1, "whole", (0, 0))])
        scored, table = self.score("again.csv")
        # docs/stroke-acceptance.md: `wrong_stroke` (an earlier stroke again, ...).
        self.assertEqual(self.verdicts(scored), ["none", "wrong_stroke", "none"])
        self.assertEqual(scored["strokes_accepted"], 2)
        self.assertEqual({k: v[2] for k, v in table_rows(table).items()}, {1: "accepted", 2: "accepted"})
        self.assert_totals_add_up(scored, table)

    def test_python_scores_a_scene_as_it_is_laid_out_and_a_name_at_the_default_layout(self):
        scene = cg.Scene("十", layout=cg.SceneLayout(character_size_m=0.03))
        medians = [np.asarray(s.median_m) for s in scene.strokes]
        # the pen of `pen_path`, along the 30 mm character's medians
        rows, here = [], None
        for m in medians:
            p = resample(m, SPEED_M_S / RATE_HZ)
            if here is not None:
                rows += [(*(here * (1 - a) + p[0] * a), 0) for a in np.linspace(0.0, 1.0, UP_ROWS)]
            rows += [(q[0], q[1], 1) for q in p]
            here = p[-1]
        a = np.array(rows)
        small = {"t": np.arange(len(a)) / RATE_HZ, "x": a[:, 0], "y": a[:, 1], "pen": a[:, 2].astype(int)}
        self.assertEqual(cg.score(small, scene)["strokes_accepted"], 2)
        by_name = cg.score(small, "十")
        self.assertEqual(by_name["strokes_accepted"], 0)
        self.write("small.csv", csv_text(small))
        self.assertEqual(self.verdicts(self.score_json("small.csv")), self.verdicts(by_name))

    def test_python_scores_file_and_columns_with_the_cli_verdicts(self):
        plans = {"p_whole": [(0, "whole", (0, 0)), (1, "whole", (0, 0))],
                 "p_rev": [(0, "reversed", (0, 0)), (1, "whole", (0, 0))],
                 "p_swap": [(1, "whole", (0, 0)), (0, "whole", (0, 0))],
                 "p_assist": [(0, "whole", (0.0, 0.004))] * 5 + [(1, "whole", (0, 0))]}
        for name, plan in plans.items():
            with self.subTest(name):
                columns, _ = self.trace(name + ".csv", plan)
                cli = self.score_json(name + ".csv")
                from_file = cg.score(str(self.tmp / (name + ".csv")), "十")
                metrics_keys = set(cli) - SCORE_ONLY_KEYS
                self.assertLessEqual(metrics_keys, set(from_file))
                self.assertEqual({k: from_file[k] for k in metrics_keys}, without(cli, SCORE_ONLY_KEYS))
                from_columns = cg.score({k: np.asarray(v) for k, v in columns.items()}, "十")
                self.assertEqual(self.verdicts(from_columns), self.verdicts(cli))
                for key in ("strokes_accepted", "strokes_assisted", "strokes_written", "order_errors",
                            "backwards_strokes", "refusals", "completed_in_order"):
                    self.assertEqual(from_columns[key], cli[key], key)
                self.assertAlmostEqual(from_columns["mean_deviation_m"], cli["mean_deviation_m"], delta=1e-9)


class TraceForms(Traces):
    """One trace of 十 in every form a teacher's file may take: read as the plain one or refused by name."""

    @classmethod
    def setUpClass(cls):
        super().setUpClass()
        cls.columns, cls.segs = pen_path("十", [(0, "whole", (0, 0)), (1, "whole", (0, 0))])
        cls.text = csv_text(cls.columns)
        (cls.tmp / "plain.csv").write_text(cls.text, encoding="utf-8")
        out = run_ok(["score", "plain.csv", "--character", "十", "--json", "-"], cls.tmp)
        cls.plain = json.loads(out.stdout)

    def assert_reads_as_plain(self, name):
        scored = self.score_json(name)
        self.assertEqual(scored["trace"], name)
        self.assertEqual(without(scored, {"trace"}), without(self.plain, {"trace"}))

    def lines(self):
        return self.text.splitlines()

    def test_plain_trace_is_accepted_in_turn(self):
        self.assertEqual(self.plain["strokes_accepted"], 2)
        self.assertEqual(self.plain["samples"], len(self.columns["t"]))

    def test_columns_in_another_order_with_extra_columns_read_the_same(self):
        order = ("note", "y", "pen", "pressure", "x", "t")
        self.write("order.csv", csv_text(self.columns, order=order))
        self.assert_reads_as_plain("order.csv")

    def test_byte_order_mark_crlf_and_quoted_fields_read_the_same(self):
        quoted = [",".join(f'"{f}"' for f in line.split(",")) for line in self.lines()]
        self.write("excel.csv", "\ufeff" + "\r\n".join(quoted) + "\r\n")
        self.assert_reads_as_plain("excel.csv")

    def test_gzip_in_one_and_in_two_members_reads_the_same(self):
        data = self.text.encode("utf-8")
        self.write("one.csv.gz", gzip.compress(data))
        half = self.text.index("\n", len(self.text) // 2) + 1
        self.write("two.csv.gz", gzip.compress(data[:half]) + gzip.compress(data[half:]))
        self.assert_reads_as_plain("one.csv.gz")
        self.assert_reads_as_plain("two.csv.gz")

    def test_gzip_with_trailing_zero_bytes_refused_naming_the_byte(self):
        packed = gzip.compress(self.text.encode("utf-8"))
        self.write("pad.csv.gz", packed + b"\0" * 64)
        result = run(["score", "pad.csv.gz", "--character", "十"], self.tmp)
        line = self.assert_one_error(result, 1, "pad.csv.gz")
        self.assertIn(str(len(packed)), line)

    def test_pen_spelt_as_numpy_and_pandas_write_it_reads_as_one_and_zero(self):
        lines = [self.lines()[0]]
        for i, line in enumerate(self.lines()[1:]):
            head, pen = line.rsplit(",", 1)
            lines.append(head + "," + ("%.18e" % float(pen) if i % 2 else "%.1f" % float(pen)))
        self.write("numpy.csv", "\n".join(lines) + "\n")
        self.assert_reads_as_plain("numpy.csv")

    def test_duplicate_timestamps_are_taken(self):
        lines = [self.lines()[0]]
        previous = None
        for i, line in enumerate(self.lines()[1:]):
            t, rest = line.split(",", 1)
            if i % 10 == 5:
                t = previous
            lines.append(t + "," + rest)
            previous = t
        self.write("dup.csv", "\n".join(lines) + "\n")
        scored = self.score_json("dup.csv")
        self.assertEqual(self.verdicts(scored), ["none", "none"])
        self.assertEqual([(s["begin"], s["end"]) for s in self.segments(scored)], self.segs)

    def test_header_only_is_scored_as_nothing_written_or_refused_naming_the_file(self):
        self.write("header.csv", "t,x,y,pen\n")
        result = run(["score", "header.csv", "--character", "十", "--json", "-"], self.tmp)
        if result.returncode == 0:
            scored = json.loads(result.stdout)
            self.assertEqual((scored["samples"], scored["strokes_written"], scored["strokes_accepted"]), (0, 0, 0))
            self.assertIsNone(scored["total_time_s"])
            self.assertIsNone(scored["mean_deviation_m"])
        else:
            self.assert_one_error(result, 1, "header.csv")

    def test_missing_pen_column_refused_naming_the_file_and_the_column(self):
        lines = ["t,x,y,pressure"] + self.lines()[1:]
        self.write("nopen.csv", "\n".join(lines) + "\n")
        result = run(["score", "nopen.csv", "--character", "十"], self.tmp)
        self.assert_one_error(result, 1, "nopen.csv", "pen")

    def test_millimetre_column_names_refused_for_the_column_lacked(self):
        lines = ["t,x_mm,y_mm,pen"] + self.lines()[1:]
        self.write("mm_names.csv", "\n".join(lines) + "\n")
        result = run(["score", "mm_names.csv", "--character", "十"], self.tmp)
        line = self.assert_one_error(result, 1, "mm_names.csv")
        self.assertRegex(line, r"\bx\b")

    def test_semicolon_separated_trace_refused_for_lacking_column_t(self):
        self.write("semi.csv", self.text.replace(",", ";"))
        result = run(["score", "semi.csv", "--character", "十"], self.tmp)
        line = self.assert_one_error(result, 1, "semi.csv")
        self.assertRegex(line, r"\bt\b")

    def test_tab_separated_trace_refused_for_lacking_column_t(self):
        self.write("tabs.csv", self.text.replace(",", "\t"))
        result = run(["score", "tabs.csv", "--character", "十"], self.tmp)
        line = self.assert_one_error(result, 1, "tabs.csv")
        self.assertRegex(line, r"\bt\b")

    def test_nan_in_a_row_refused_naming_file_line_column_and_value(self):
        lines = self.lines()
        row = 300                                    # a pen-down row; the header is line 1
        t, x, y, pen = lines[row].split(",")
        lines[row] = ",".join([t, x, "nan", pen])
        self.write("nan.csv", "\n".join(lines) + "\n")
        result = run(["score", "nan.csv", "--character", "十"], self.tmp)
        line = self.assert_one_error(result, 1, f"nan.csv:{row + 1}", "nan")
        self.assertRegex(line, r"\b3\b.*\by\b")

    def test_time_going_back_refused_at_its_line_naming_column_t(self):
        lines = self.lines()
        row = 500
        t, rest = lines[row].split(",", 1)
        lines[row] = "%.6f," % (float(t) - 0.0025) + rest
        self.write("back.csv", "\n".join(lines) + "\n")
        result = run(["score", "back.csv", "--character", "十"], self.tmp)
        line = self.assert_one_error(result, 1, f"back.csv:{row + 1}")
        self.assertRegex(line, r"\b1\b.*\bt\b")

    def test_pen_value_one_half_refused_naming_line_and_column(self):
        lines = self.lines()
        row = 100
        head, _ = lines[row].rsplit(",", 1)
        lines[row] = head + ",0.5"
        self.write("half_pen.csv", "\n".join(lines) + "\n")
        result = run(["score", "half_pen.csv", "--character", "十"], self.tmp)
        self.assert_one_error(result, 1, f"half_pen.csv:{row + 1}", "pen", "0.5")

    def test_header_with_both_pen_and_z_refused_as_python_refuses_both_columns(self):
        lines = ["t,x,y,pen,z"] + [line + ",0" for line in self.lines()[1:]]
        self.write("both.csv", "\n".join(lines) + "\n")
        result = run(["score", "both.csv", "--character", "十"], self.tmp)
        self.assert_one_error(result, 1, "both.csv")
        columns = {k: np.asarray(v) for k, v in self.columns.items()}
        columns["z"] = np.zeros(len(columns["t"]))
        with self.assertRaises(cg.InvalidArgument):
            cg.score(columns, "十")

    def test_millimetre_values_in_a_metres_file_score_nothing_and_credit_nothing(self):
        lines = ["t,x,y,pen"] + ["%.6f,%.6f,%.6f,%d" % (self.columns["t"][i], 1000 * self.columns["x"][i],
                                                         1000 * self.columns["y"][i], self.columns["pen"][i])
                                 for i in range(len(self.columns["t"]))]
        self.write("mm.csv", "\n".join(lines) + "\n")
        scored = self.score_json("mm.csv")
        self.assertEqual((scored["strokes_written"], scored["strokes_accepted"], scored["strokes_assisted"]),
                         (0, 0, 0))
        self.assertIsNone(scored["mean_deviation_m"])
        self.assertFalse(scored["completed_in_order"])
        self.assertNotIn("none", self.verdicts(scored))

    def test_comment_and_blank_lines_are_skipped(self):
        lines = ["# exported by a tablet", self.lines()[0], ""]
        for i, line in enumerate(self.lines()[1:]):
            lines.append(line)
            if i % 100 == 50:
                lines += ["", "# pen lifted?"]
        self.write("comments.csv", "\n".join(lines) + "\n")
        self.assert_reads_as_plain("comments.csv")

    def test_gzip_under_a_csv_name_reads_the_same_and_cut_short_is_refused(self):
        packed = gzip.compress(self.text.encode("utf-8"))
        self.write("packed.csv", packed)
        self.assert_reads_as_plain("packed.csv")
        self.write("cut.csv.gz", packed[: len(packed) // 2])
        result = run(["score", "cut.csv.gz", "--character", "十"], self.tmp)
        self.assert_one_error(result, 1, "cut.csv.gz")

    def test_epoch_times_keep_verdicts_and_times_to_a_microsecond(self):
        lines = [self.lines()[0]]
        for line in self.lines()[1:]:
            t, rest = line.split(",", 1)
            lines.append("%.6f,%s" % (1.7e9 + float(t), rest))
        self.write("epoch.csv", "\n".join(lines) + "\n")
        scored = self.score_json("epoch.csv")
        self.assertEqual(self.verdicts(scored), self.verdicts(self.plain))
        self.assertEqual(scored["mean_deviation_m"], self.plain["mean_deviation_m"])
        for key in ("total_time_s", "pen_down_time_s"):
            self.assertAlmostEqual(scored[key], self.plain[key], delta=1e-6, msg=key)

    def test_milliseconds_read_as_seconds_keep_distances_and_verdicts_and_multiply_times(self):
        lines = [self.lines()[0]]
        for line in self.lines()[1:]:
            t, rest = line.split(",", 1)
            lines.append("%.3f,%s" % (1000 * float(t), rest))
        self.write("ms.csv", "\n".join(lines) + "\n")
        scored = self.score_json("ms.csv")
        self.assertEqual(self.verdicts(scored), self.verdicts(self.plain))
        for key in ("mean_deviation_m", "max_deviation_m", "frechet_m", "dtw_m"):
            self.assertAlmostEqual(scored[key], self.plain[key], delta=1e-12, msg=key)
        for key in ("total_time_s", "pen_down_time_s"):
            self.assertAlmostEqual(scored[key], 1000 * self.plain[key], delta=1e-6, msg=key)

    def test_upper_case_header_names_no_column(self):
        self.write("upper.csv", "T,X,Y,PEN\n" + "\n".join(self.lines()[1:]) + "\n")
        result = run(["score", "upper.csv", "--character", "十"], self.tmp)
        line = self.assert_one_error(result, 1, "upper.csv")
        self.assertRegex(line, r"\bt\b")

    def test_column_under_both_its_names_refused_naming_it(self):
        lines = ["t,x,y,pen,x_m"] + [line + "," + line.split(",")[1] for line in self.lines()[1:]]
        self.write("twice.csv", "\n".join(lines) + "\n")
        result = run(["score", "twice.csv", "--character", "十"], self.tmp)
        self.assert_one_error(result, 1, "twice.csv", "x_m")

    def test_quoted_field_holding_a_comma_refused_naming_its_line(self):
        lines = self.lines()
        t, x, rest = lines[40].split(",", 2)
        lines[40] = '%s,"%s",%s' % (t, x.replace(".", ","), rest)
        self.write("comma.csv", "\n".join(lines) + "\n")
        result = run(["score", "comma.csv", "--character", "十"], self.tmp)
        self.assert_one_error(result, 1, "comma.csv:41")

    def test_cr_only_line_ends_and_utf16_text_refused_saying_so(self):
        self.write("mac.csv", self.text.replace("\n", "\r"))
        result = run(["score", "mac.csv", "--character", "十"], self.tmp)
        self.assert_one_error(result, 1, "mac.csv", "CR")
        self.write("utf16.csv", self.text.encode("utf-16"))
        result = run(["score", "utf16.csv", "--character", "十"], self.tmp)
        self.assert_one_error(result, 1, "utf16.csv", "UTF-16")

    def test_position_with_no_place_in_data_units_refused_naming_its_column(self):
        lines = self.lines()
        t, x, rest = lines[60].split(",", 2)
        lines[60] = "%s,1e308,%s" % (t, rest)
        self.write("far.csv", "\n".join(lines) + "\n")
        result = run(["score", "far.csv", "--character", "十"], self.tmp)
        line = self.assert_one_error(result, 1, "far.csv:61")
        self.assertRegex(line, r"\bx\b")

    def test_trace_name_with_a_line_break_and_an_escape_stays_one_printable_line(self):
        name = "tab\x1b[2Jlet\n.csv"
        lines = self.lines()
        t, x, y, pen = lines[10].split(",")
        lines[10] = ",".join([t, x, "nan", pen])
        self.write(name, "\n".join(lines) + "\n")
        result = run(["score", name, "--character", "十"], self.tmp)
        line = self.assert_one_error(result, 1, "\\x1b", "\\n")
        self.assertNotIn("\x1b", line)

    def test_dash_is_a_file_named_dash_never_standard_input(self):
        result = run(["score", "-", "--character", "十"], self.tmp)
        self.assert_one_error(result, 1, "standard input")
        self.write("-", self.text)
        scored = json.loads(run_ok(["score", "-", "--character", "十", "--json", "-"], self.tmp).stdout)
        self.assertEqual(without(scored, {"trace"}), without(self.plain, {"trace"}))
        (self.tmp / "-").unlink()

    def test_character_the_library_lacks_and_two_in_data_units_are_usage_errors(self):
        result = run(["score", "plain.csv", "--character", "あ"], self.tmp)
        self.assert_one_error(result, 2, "U+3042")
        result = run(["score", "plain.csv", "--character", "一十", "--units", "data"], self.tmp)
        self.assert_one_error(result, 2, "--units")

    def test_pen_spelt_with_a_plus_sign_reads_as_the_number(self):
        lines = [self.lines()[0]]
        for line in self.lines()[1:]:
            head, pen = line.rsplit(",", 1)
            lines.append(head + ",+" + pen)
        self.write("plus_pen.csv", "\n".join(lines) + "\n")
        self.assert_reads_as_plain("plus_pen.csv")

    def test_times_and_positions_with_a_plus_sign_as_printf_writes_them_read_as_the_numbers(self):
        lines = [self.lines()[0]]
        for line in self.lines()[1:]:
            fields = line.split(",")
            lines.append(",".join(f if f.startswith("-") or i == 3 else "+" + f for i, f in enumerate(fields)))
        self.write("plus.csv", "\n".join(lines) + "\n")
        self.assert_reads_as_plain("plus.csv")

    def test_times_in_exponent_notation_and_an_empty_extra_field_read_the_same(self):
        lines = [self.lines()[0] + ",note"]
        for line in self.lines()[1:]:
            t, rest = line.split(",", 1)
            lines.append("%.6e,%s," % (float(t), rest))
        self.write("exp.csv", "\n".join(lines) + "\n")
        self.assert_reads_as_plain("exp.csv")

    def test_ten_thousand_pen_downs_read_and_one_more_refused_at_its_line(self):
        rows = []
        for k in range(10_001):
            rows += ["%d,0.%04d,0,1" % (2 * k, k), "%d,0.%04d,0,0" % (2 * k + 1, k)]
        self.write("taps.csv", "t,x,y,pen\n" + "\n".join(rows[:-2]) + "\n")
        scored = self.score_json("taps.csv")
        self.assertEqual(scored["per_character"][0]["ignored_segments"], 10_000)
        self.assertEqual(scored["per_character"][0]["pen_lifts"], 9_999)
        self.write("taps1.csv", "t,x,y,pen\n" + "\n".join(rows) + "\n")
        result = run(["score", "taps1.csv", "--character", "十"], self.tmp)
        self.assert_one_error(result, 1, "taps1.csv:20002")

    def test_data_folder_scores_an_embedded_character_as_the_default_and_excludes_store(self):
        corpus = os.environ.get("CALLIGRAPHY_CORPUS_DIR", "")
        if not corpus or not Path(corpus).is_dir():
            self.skipTest("CALLIGRAPHY_CORPUS_DIR (hanzi-writer-data) is not set")
        scored = self.score_json("plain.csv", "十", "--data", corpus)
        self.assertEqual(without(scored, {"trace"}), without(self.plain, {"trace"}))
        result = run(["score", "plain.csv", "--character", "十", "--data", corpus, "--store", "x.clg"], self.tmp)
        self.assert_one_error(result, 2, "--data", "--store")

    def test_column_names_with_their_units_read_the_same(self):
        self.write("units.csv", "t_s,x_m,y_m,pen\n" + "\n".join(self.lines()[1:]) + "\n")
        self.assert_reads_as_plain("units.csv")

    def test_long_comment_line_is_read_in_the_memory_of_its_samples(self):
        if SANITIZED:
            self.skipTest("an address-space limit and the sanitizers' shadow memory do not mix")
        # docs/cli.md: "The file is read a block at a time (memory holds the samples, not the file)"; `#` lines
        # are skipped (docs/metrics.md). The same 64 MiB of comment in 1 KiB lines, and as one line, before the
        # trace, each read under a 100 MiB address-space limit (the program scores a trace in 40 MiB).
        limit = 100 << 20

        def limited():
            resource.setrlimit(resource.RLIMIT_AS, (limit, limit))
        mib_of_lines = (b"# " + b"x" * 1021 + b"\n") * 1024
        with open(self.tmp / "short_comments.csv", "wb") as f:
            for _ in range(64):
                f.write(mib_of_lines)
            f.write(self.text.encode("utf-8"))
        result = run(["score", "short_comments.csv", "--character", "十", "--json", "-"], self.tmp,
                     preexec_fn=limited)
        self.assertEqual(result.returncode, 0, result.stderr)
        (self.tmp / "short_comments.csv").unlink()
        with open(self.tmp / "long_comment.csv", "wb") as f:
            mib_of_x = b"x" * (1 << 20)
            f.write(b"# " + mib_of_x[2:])
            for _ in range(63):
                f.write(mib_of_x)
            f.write(b"\n" + self.text.encode("utf-8"))
        result = run(["score", "long_comment.csv", "--character", "十", "--json", "-"], self.tmp,
                     preexec_fn=limited)
        (self.tmp / "long_comment.csv").unlink()
        self.assertEqual(result.returncode, 0, result.stderr)
        self.assertEqual(without(json.loads(result.stdout), {"trace"}), without(self.plain, {"trace"}))

    def test_a_million_rows_read_and_one_more_refused_at_its_line(self):
        row = b"0,0.1,0.1,0\n"
        self.write("million.csv", b"t,x,y,pen\n" + row * 1_000_000)
        scored = self.score_json("million.csv")
        self.assertEqual(scored["samples"], 1_000_000)
        self.assertIsNone(scored["total_time_s"])
        self.write("million1.csv", b"t,x,y,pen\n" + row * 1_000_001)
        result = run(["score", "million1.csv", "--character", "十"], self.tmp)
        self.assert_one_error(result, 1, "million1.csv:1000002")
        (self.tmp / "million.csv").unlink()
        (self.tmp / "million1.csv").unlink()


class StrokesTable(Traces):
    """`calligraphy strokes`: the docs' table, its JSON, and the acronyms `score` prints."""

    def test_strokes_markdown_is_the_docs_table_byte_for_byte(self):
        out = run_ok(["strokes", "--markdown", "-"], self.tmp)
        self.assertEqual(out.stdout.decode("utf-8"),
                         (SOURCE / "docs" / "typical-strokes.md").read_text(encoding="utf-8"))

    def test_strokes_json_lists_39_ids_in_order_with_the_python_acronyms(self):
        table = json.loads(run_ok(["strokes", "--json"], self.tmp).stdout)
        self.assertEqual([s["id"] for s in table], list(range(1, 40)))
        self.assertEqual([s["acronym"] for s in table], [s.acronym for s in cg.TYPICAL_STROKES])
        columns, _ = pen_path("六", [(k, "whole", (0, 0)) for k in range(4)])
        self.write("liu.csv", csv_text(columns))
        rows = table_rows(run_ok(["score", "liu.csv", "--character", "六"], self.tmp).stdout.decode("utf-8"))
        by_id = {s["id"]: s["acronym"] for s in table}
        self.assertEqual(sorted(rows), [1, 2, 3, 4])
        for number, (acronym, typical_id, _) in rows.items():
            self.assertEqual(acronym, by_id[typical_id], rows)

    def test_strokes_markdown_to_a_file_prints_nothing_else(self):
        out = run_ok(["strokes", "--markdown", "t.md"], self.tmp)
        self.assertEqual(out.stdout, b"")
        self.assertEqual((self.tmp / "t.md").read_text(encoding="utf-8"),
                         (SOURCE / "docs" / "typical-strokes.md").read_text(encoding="utf-8"))

    def test_strokes_markdown_to_stdout_with_json_is_a_usage_error(self):
        result = run(["strokes", "--markdown", "-", "--json"], self.tmp)
        self.assert_one_error(result, 2)
        self.assertEqual(result.stdout, b"")


class SessionTraceAndCurriculum(Traces):
    """One simulated session writing 一: its `.trace.h5` scored, and `curriculum` on it."""

    @classmethod
    def setUpClass(cls):
        super().setUpClass()
        protocol = {"name": "r33a", "conditions": [{"name": "v", "mode": "haptic"}],
                    "test": {"characters": ["一"], "conditions": ["v"], "repetitions": 1},
                    "trial": {"max_duration_s": 10}}
        (cls.tmp / "p.json").write_text(json.dumps(protocol), encoding="utf-8")
        run_ok(["session", "run", "p.json", "--subject", "S01", "--out", "study", "--pacing", "lock-step"], cls.tmp)
        cls.h5 = next((cls.tmp / "study").glob("S01/*/trials/*.trace.h5"))
        cls.record = json.loads(next((cls.tmp / "study").glob("S01/*/trials/*.json")).read_text(encoding="utf-8"))

    def test_session_trace_h5_scores_as_its_trace_csv_and_as_its_record(self):
        h5 = str(self.h5.relative_to(self.tmp))
        from_h5 = self.score_json(h5, "一")
        run_ok(["trace", h5, "--csv", "trace.csv"], self.tmp)
        from_csv = self.score_json("trace.csv", "一")
        self.assertEqual(without(from_h5, {"trace"}), without(from_csv, {"trace"}))
        for key in ("strokes_accepted", "strokes_written", "order_errors", "backwards_strokes", "refusals",
                    "completed_in_order", "strokes_total", "unmatched_segments"):
            self.assertEqual(from_h5[key], self.record[key], key)
        for key in ("mean_deviation_m", "max_deviation_m", "frechet_m", "dtw_m"):
            self.assertAlmostEqual(from_h5[key], self.record[key], delta=1e-7, msg=key)
        for key in ("total_time_s", "pen_down_time_s"):
            self.assertAlmostEqual(from_h5[key], self.record[key], delta=1e-6, msg=key)
        python = cg.score(str(self.h5), "一")
        self.assertEqual(self.verdicts(python), self.verdicts(from_h5))

    def test_curriculum_after_writing_yi_proposes_shi_for_its_new_vertical(self):
        out = run_ok(["curriculum", "study", "--subject", "S01", "--from", "一二十", "--json"], self.tmp)
        self.assertEqual(json.loads(out.stdout), [{"character": "十", "new_strokes": [2], "weak_strokes": []}])
        text = run_ok(["curriculum", "study", "--subject", "S01", "--from", "一二十"], self.tmp).stdout.decode()
        lines = text.strip().splitlines()
        self.assertTrue(lines[0].startswith("S01: 1 of 39 typical strokes written"), text)
        self.assertEqual(len(lines), 2, text)
        self.assertRegex(lines[1], r"十\s+new: S; again: -")

    def test_curriculum_of_the_session_folder_itself_as_of_its_study_and_nothing_left_to_add(self):
        session = str(self.h5.parent.parent.relative_to(self.tmp))
        args = ["--subject", "S01", "--from", "一二十", "--json"]
        by_study = json.loads(run_ok(["curriculum", "study", *args], self.tmp).stdout)
        by_session = json.loads(run_ok(["curriculum", session, *args], self.tmp).stdout)
        self.assertEqual(by_session, by_study)
        nothing = run_ok(["curriculum", "study", "--subject", "S01", "--from", "一二", "--json"], self.tmp)
        self.assertEqual(json.loads(nothing.stdout), [])

    def test_curriculum_proposes_greedily_the_most_new_strokes_first_never_the_same_new_twice(self):
        out = run_ok(["curriculum", "study", "--subject", "S01", "--from", "十口工", "--json"], self.tmp)
        proposal = json.loads(out.stdout)
        self.assertEqual(proposal[0]["character"], "口")
        self.assertEqual(sorted(proposal[0]["new_strokes"]), [2, 7])
        seen = set()
        for item in proposal:
            self.assertFalse(seen & set(item["new_strokes"]), proposal)
            seen |= set(item["new_strokes"])
            self.assertTrue(item["new_strokes"] or item["weak_strokes"], proposal)

    def test_session_trace_cut_or_damaged_refused_naming_it(self):
        data = self.h5.read_bytes()
        self.write("cut.trace.h5", data[: len(data) // 2])
        result = run(["score", "cut.trace.h5", "--character", "一"], self.tmp)
        self.assert_one_error(result, 1, "cut.trace.h5")
        flipped = bytearray(data)
        flipped[len(data) - 100] ^= 0xFF
        self.write("flip.trace.h5", bytes(flipped))
        result = run(["score", "flip.trace.h5", "--character", "一"], self.tmp)
        self.assert_one_error(result, 1, "flip.trace.h5")

    def test_curriculum_tie_goes_to_the_character_of_fewer_strokes_and_count_bounds_the_list(self):
        # 工 (H S H) and 十 (H S) each bring the one new vertical: ties to fewer strokes; after 十, 工 adds nothing.
        out = run_ok(["curriculum", "study", "--subject", "S01", "--from", "工十", "--json"], self.tmp)
        self.assertEqual([p["character"] for p in json.loads(out.stdout)], ["十"])
        out = run_ok(["curriculum", "study", "--subject", "S01", "--from", "十口工", "--count", "1", "--json"],
                     self.tmp)
        self.assertEqual([p["character"] for p in json.loads(out.stdout)], ["口"])

    def test_curriculum_subject_without_saved_trials_is_a_usage_error(self):
        result = run(["curriculum", "study", "--subject", "S02", "--from", "十"], self.tmp)
        self.assert_one_error(result, 2, "S02")

    def test_curriculum_from_empty_or_naming_a_character_the_library_lacks_is_a_usage_error(self):
        result = run(["curriculum", "study", "--subject", "S01", "--from", ""], self.tmp)
        self.assert_one_error(result, 2, "--from")
        result = run(["curriculum", "study", "--subject", "S01", "--from", "十あ"], self.tmp)
        self.assert_one_error(result, 2, "U+3042")
        result = run(["curriculum", "study", "--subject", "S01", "--from", b"\xe5\x8d"], self.tmp)
        self.assert_one_error(result, 2, "--from", "byte 0")

    def test_curriculum_folder_without_sessions_is_a_data_error_naming_it(self):
        (self.tmp / "empty").mkdir(exist_ok=True)
        result = run(["curriculum", "empty", "--subject", "S01", "--from", "十"], self.tmp)
        self.assert_one_error(result, 1, "empty")

    def test_curriculum_count_past_its_range_is_a_usage_error(self):
        result = run(["curriculum", "study", "--subject", "S01", "--from", "十", "--count", "1001"], self.tmp)
        self.assert_one_error(result, 2, "--count", "1001")


if __name__ == "__main__":
    unittest.main()
