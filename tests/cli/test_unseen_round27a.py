#!/usr/bin/env python3
"""Round 27A: the hint and the assisted credit, held across every surface. From the docs alone
(docs/stroke-acceptance.md "No dead end", docs/metrics.md, docs/cli.md `trial`, `train`, `score`, "Re-running a
trial", docs/experiments.md, docs/trainer.md, docs/python.md, include/calligraphy/analysis/quiz.hpp).

Traces are written by hand with numpy along the data's medians: a stroke of 十 begun at its start and lifted
at 40 % of it (a miss the renderer counts: a lift in WS that did not write it) or the whole stroke 8 mm off
(never near its start), N times, then written right. Each is scored by `calligraphy score` and Python's `score`
with the miss counts at 0, 1, the default, 1000 and past the range, ticked through Python's `Renderer` (the
renderer's own hint and credit), and the counts compared. A simulated writer is made to miss by a trial whose
mean deviation allowed is 0.1 mm: its record, its re-run, its record edited, Python's `simulate_trial`, a
study's tables and the quiz's events, which give no assisted credit.

CALLIGRAPHY_CLI names the program; PYTHONPATH the built Python package. CALLIGRAPHY_SANITIZED=1 takes five cases.
"""
import csv
import io
import json
import shutil
import tempfile
import unittest
import warnings
from pathlib import Path

from outsider import OneErrorLine, run, run_ok, sanitized_subset

try:
    import numpy as np
    import outsider_pen
    import calligraphy as cg
except ImportError:  # reported by setUpClass: every case needs the traces numpy and the package draw
    np = cg = None


def along(median, offset=(0.0, 0.0), fraction=1.0, n=400):
    """`n` points along a median [m] (outsider_pen.along, this round's density)."""
    return outsider_pen.along(median, offset, fraction, n)


def write_trace(path, ticks):
    outsider_pen.write_trace(path, ticks)

load_tests = sanitized_subset({"test_score_credits_at_exactly_the_count_and_judges_on",
                               "test_score_count_past_its_range_is_one_error_naming_the_option",
                               "test_trial_credits_assisted_strokes_apart_from_completed_ones",
                               "test_record_contradicting_its_own_counts_is_refused_naming_the_pointer",
                               "test_strokes_csv_gives_each_stroke_its_assisted_credit"})

RATE_HZ = 1000.0
HOVER_M = 0.002        # above the 0.5 mm contact threshold: the pen is lifted
DOWN_M = -0.0003       # on the paper
OFF_M = 0.008          # a stroke written 8 mm across: never within the 5 mm start radius
HALF = 0.4             # begun at the start, lifted at 40 % of the stroke: too short
# A trial every attempt of which is refused (the writer's 0.4 mm mean deviation is over 0.1 mm) and whose
# strokes are shown as a hint after one miss and credited assisted after two.
STRICT = ["--guidance", "off", "--mean-deviation", "0.0001", "--mean-deviation-cap", "0.0001",
          "--hint-after-misses", "1", "--assist-after-misses", "2"]
PROTOCOL = {"name": "assist", "conditions": [
    {"name": "q", "mode": "quiz", "quiz": {"acceptance": {
        "mean_deviation_m": 0.0001, "mean_deviation_cap_m": 0.0001, "assist_after_misses": 2,
        "hint_after_misses": 1}}}],
    "test": {"characters": ["十"], "conditions": ["q"], "repetitions": 1}, "trial": {"max_duration_s": 60}}
COUNT_KEYS = ("strokes_total", "strokes_written", "strokes_accepted", "strokes_assisted", "completed_in_order",
              "order_errors", "backwards_strokes", "unmatched_segments", "refusals")


def pen_path(characters, plan):
    """The ticks (t, x, y, z) of a pen writing `plan`, a list of (character, stroke, offset, fraction; a
    negative fraction: from the stroke's end), each pen-down set down and lifted straight up, the pen carried
    through the air between them, 1 kHz."""
    scene = cg.Scene(characters)
    points, here = [], None
    for c, k, offset, fraction in plan:
        median = np.asarray(scene.characters[c].strokes[k].median_m)
        p = along(median if fraction > 0 else median[::-1], offset, abs(fraction))
        if here is not None:
            points += [(*(here * (1 - a) + p[0] * a), HOVER_M) for a in np.linspace(0, 1, 200)]
        points += [(*p[0], HOVER_M * (1 - a) + DOWN_M * a) for a in np.linspace(0, 1, 50)]
        points += [(*q, DOWN_M) for q in p]
        points += [(*p[-1], DOWN_M * (1 - a) + HOVER_M * a) for a in np.linspace(0, 1, 50)]
        here = p[-1]
    xyz = np.array(points)
    return np.column_stack([np.arange(len(xyz)) / RATE_HZ, xyz])


def misses_then_right(kind, n):
    """十's stroke 1 missed `n` times (`half`: lifted at 40 %; `off`: 8 mm across), then both strokes right."""
    miss = (0, 0, (0.0, 0.0), HALF) if kind == "half" else (0, 0, (0.0, OFF_M), 1.0)
    return [miss] * n + [(0, 0, (0.0, 0.0), 1.0), (0, 1, (0.0, 0.0), 1.0)]


def renderer_story(characters, ticks, hint_after, assist_after):
    """The renderer's own view of the ticks: per lift out of WS the active stroke, its misses and whether the
    hint is shown; the strokes credited assisted and those completed, in order."""
    acceptance = cg.StrokeAcceptance(hint_after_misses=hint_after, assist_after_misses=assist_after)
    renderer = cg.Renderer(cg.Scene(characters), cg.ForceLawParameters(acceptance=acceptance),
                           device=cg.SimulatedDevice().info, options=cg.RendererOptions(rate_hz=RATE_HZ))
    lifts, assisted, completed = [], [], []
    previous, active, writing = ticks[0][1:], 0, False
    for t, *p in ticks:
        velocity = (np.asarray(p) - np.asarray(previous)) * RATE_HZ
        previous = p
        out = renderer.tick(cg.DeviceState(position_m=tuple(p), velocity_m_s=tuple(velocity), time_s=float(t)))
        if out.stroke_assisted:
            assisted.append(active)
        if out.stroke_completed:
            completed.append(active)
        now_writing = out.state == cg.InteractionState.writing
        if writing and not now_writing:
            lifts.append((active, out.misses, out.hint_shown))
        writing, active = now_writing, out.stroke
    return lifts, assisted, completed


def table_rows(text):
    """`score`'s table per stroke: {stroke number: verdict text}."""
    rows = {}
    for line in text.splitlines():
        parts = line.split()
        if len(parts) > 8 and parts[0].isdigit() and parts[1] in ("H", "S", "D", "P"):
            rows[int(parts[0])] = " ".join(parts[8:])
    return rows


def totals(text):
    """`score`'s total lines: {"strokes accepted": "1 of 2 ...", ...}."""
    found = {}
    for line in text.splitlines():
        for key in ("strokes accepted", "strokes assisted", "strokes refused", "strokes not written"):
            if line.strip().startswith(key):
                found[key] = line.strip()[len(key):].split()[0]
    return found


class Round27A(unittest.TestCase, OneErrorLine):
    @classmethod
    def setUpClass(cls):
        if cg is None:
            raise unittest.SkipTest("numpy and the calligraphy Python package (PYTHONPATH) are needed")
        cls.tmp = Path(tempfile.mkdtemp(prefix="round27a-"))
        d = cls.tmp
        cls.ticks = {}
        for kind, n in (("half", 3), ("half", 7), ("half", 5), ("off", 5)):
            ticks = pen_path("十", misses_then_right(kind, n))
            cls.ticks[kind, n] = ticks
            write_trace(d / f"{kind}{n}.csv", ticks)
        run_ok(["trial", "十", *STRICT, "--json", "w.json", "--csv", "w.csv"], d)
        cls.record = json.loads((d / "w.json").read_text(encoding="utf-8"))
        cls.scores = {}

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.tmp, ignore_errors=True)

    def cli(self, *args):
        return run(list(args), self.tmp)

    def score(self, trace, count=None):
        """`score --json` of a trace with `--assist-after-misses count` (None: the option left out)."""
        key = (trace, count)
        if key not in self.scores:
            extra = [] if count is None else ["--assist-after-misses", str(count)]
            out = run_ok(["score", trace, "--character", "十", "--json", "-", *extra], self.tmp)
            self.scores[key] = json.loads(out.stdout)
        return self.scores[key]

    def assisted(self, scored, character=0):
        return [s["assisted"] for s in scored["per_character"][character]["per_stroke"]]

    def assertCredit(self, scored, assisted, accepted, completed_in_order=True):
        self.assertEqual(self.assisted(scored), assisted)
        self.assertEqual(scored["strokes_assisted"], sum(assisted))
        self.assertEqual(scored["per_character"][0]["strokes_assisted"], sum(assisted))
        self.assertEqual(scored["strokes_accepted"], accepted)
        # The record measures what the trace wrote: both strokes were written right at last.
        self.assertEqual(scored["strokes_written"], 2)
        self.assertEqual(scored["completed_in_order"], completed_in_order)

    # ---- score: the miss counts --------------------------------------------------------------------------
    def test_score_default_gives_no_credit_after_three_misses(self):
        scored = self.score("half3.csv")
        self.assertCredit(scored, [False, False], 2)
        self.assertEqual(scored["refusals"]["too_short"], 3)
        self.assertEqual(scored, self.score("half3.csv", 5), "the default is 5")

    def test_score_default_credits_at_the_fifth_miss(self):
        scored = self.score("half5.csv")
        # Stroke 1 credited at its fifth miss; stroke 1 written right while stroke 2 is due is refused as an
        # earlier stroke again, and stroke 2 is accepted.
        self.assertCredit(scored, [True, False], 1)
        verdicts = [s["verdict"] for s in scored["per_character"][0]["segments"]]
        self.assertEqual([v["refusal"] for v in verdicts], ["too_short"] * 5 + ["wrong_stroke", "none"])
        self.assertEqual([v["assists_due"] for v in verdicts], [False] * 4 + [True, False, False])

    def test_score_zero_never_credits_after_seven_misses(self):
        scored = self.score("half7.csv", 0)
        self.assertCredit(scored, [False, False], 2)
        self.assertEqual(scored["refusals"]["too_short"], 7)

    def test_score_one_credits_the_due_stroke_at_its_first_miss_as_the_renderer(self):
        scored = self.score("half3.csv", 1)
        # Miss 1 credits stroke 1. The next pen-down begins at stroke 1's start, not stroke 2's, on the
        # character's box: a miss of stroke 2 (docs/stroke-acceptance.md, "No dead end": wherever it was), which
        # credits stroke 2 too at a count of 1, for the renderer and the score alike.
        self.assertCredit(scored, [True, True], 0)
        _, assisted, completed = renderer_story("十", self.ticks["half", 3], 3, 1)
        self.assertEqual((assisted, completed), ([0, 1], []))

    def test_score_credits_at_exactly_the_count_and_judges_on(self):
        scored = self.score("half3.csv", 3)
        self.assertCredit(scored, [True, False], 1)
        segments = scored["per_character"][0]["segments"]
        self.assertEqual([s["verdict"]["expected_stroke"] for s in segments], [0, 0, 0, 1, 1])
        self.assertEqual(segments[3]["verdict"]["refusal"], "wrong_stroke")
        self.assertEqual(segments[3]["matched_stroke"], 0, "the assignment gives stroke 1 its right pen-down")

    def test_score_thousand_is_never_reached(self):
        scored = self.score("half7.csv", 1000)
        self.assertCredit(scored, [False, False], 2)
        self.assertEqual(scored, self.score("half7.csv", 0))

    def test_score_count_past_its_range_is_one_error_naming_the_option(self):
        for value in ("1001", "-1", "2.5", "", "five", "0x5", "1e400"):
            with self.subTest(value=value):
                self.assert_one_error(self.cli("score", "half3.csv", "--character", "十",
                                               "--assist-after-misses", value), 2, "--assist-after-misses")
        self.assert_one_error(self.cli("score", "half3.csv", "--character", "十", "--assist-after-misses", "1",
                                       "--assist-after-misses", "2"), 2, "--assist-after-misses")

    def test_score_table_says_assisted_and_its_totals_add_up(self):
        for count in (0, 1, 3, 5):
            with self.subTest(count=count):
                text = run_ok(["score", "half3.csv", "--character", "十", "--assist-after-misses", str(count)],
                              self.tmp).stdout.decode()
                scored = self.score("half3.csv", count)
                rows = table_rows(text)
                for i, flag in enumerate(self.assisted(scored)):
                    self.assertEqual(rows[i + 1].startswith("assisted (last refused: "), flag, rows)
                    if not flag:
                        self.assertEqual(rows[i + 1], "accepted")
                said = totals(text)
                self.assertEqual(int(said.get("strokes assisted", "0")), scored["strokes_assisted"])
                parts = (int(said["strokes accepted"]) + int(said.get("strokes assisted", "0"))
                         + int(said["strokes refused"]) + int(said["strokes not written"]))
                self.assertEqual(parts, scored["strokes_total"], text)

    def test_score_assisted_flags_are_the_segments_credit(self):
        for count in range(0, 7):
            with self.subTest(count=count):
                scored = self.score("half5.csv", count)
                segments = scored["per_character"][0]["segments"]
                due = [s["verdict"]["expected_stroke"] for s in segments
                       if s["verdict"] and s["verdict"]["assists_due"]]
                flags = self.assisted(scored)
                self.assertEqual(sorted(due), [i for i, f in enumerate(flags) if f])
                self.assertEqual(scored["strokes_accepted"] + scored["strokes_assisted"], 2)
                self.assertLessEqual(sum(scored["refusals"].values()), 5 + 1)

    # ---- names: one meaning everywhere -------------------------------------------------------------------
    def test_score_json_carries_every_scene_metric_of_the_schema(self):
        schema = json.loads(run_ok(["schema", "metrics"], self.tmp).stdout)
        scored = self.score("half3.csv", 3)
        for name in schema["properties"]:
            with self.subTest(metric=name):
                self.assertIn(name, scored)
                self.assertIn(name, self.record, "a trial's record carries it too")
        table = {row["name"]: row for row in cg.metric_table()}
        self.assertIn("strokes_assisted", schema["properties"])
        for level in ("scene", "character", "run"):
            self.assertIn(level, table["strokes_assisted"]["levels"])
        self.assertIn("stroke", table["assisted"]["levels"])
        for stroke in scored["per_character"][0]["per_stroke"] + self.record["per_character"][0]["per_stroke"]:
            self.assertIs(type(stroke["assisted"]), bool)

    def test_python_score_is_the_cli_score_at_each_count(self):
        for count in (0, 1, 3, 5, 1000):
            with self.subTest(count=count):
                got = cg.score(str(self.tmp / "half5.csv"), "十",
                               acceptance=cg.StrokeAcceptance(assist_after_misses=count))
                want = self.score("half5.csv", count)
                for key in COUNT_KEYS:
                    self.assertEqual(got[key], want[key], key)
                self.assertEqual(got["per_character"][0]["segments"], want["per_character"][0]["segments"])
                self.assertEqual([s["assisted"] for s in got["per_character"][0]["per_stroke"]],
                                 self.assisted(want))

    def test_python_count_out_of_range_names_the_count(self):
        for value in (1001, -1):
            with self.subTest(value=value):
                with self.assertRaises(cg.InvalidArgument) as caught:
                    cg.StrokeAcceptance(assist_after_misses=value)
                self.assertIn("assist_after_misses", str(caught.exception))
                with self.assertRaises(cg.InvalidArgument) as caught:
                    cg.simulate_trial("十", hint_after_misses=value)
                self.assertIn("hint_after_misses", str(caught.exception))
        with self.assertRaises(TypeError):
            cg.simulate_trial("十", assist_after_misses=2.0)

    def test_row_of_two_characters_credits_the_stroke_of_its_character(self):
        plan = [(0, 0, (0.0, 0.0), 1.0), (0, 1, (0.0, 0.0), 1.0), (1, 0, (0.0, 0.0), 1.0)]
        plan += [(1, 1, (0.0, 0.0), HALF)] * 2 + [(1, 1, (0.0, 0.0), 1.0), (1, 2, (0.0, 0.0), 1.0)]
        write_trace(self.tmp / "row.csv", pen_path("十三", plan))
        scored = json.loads(run_ok(["score", "row.csv", "--character", "十三", "--assist-after-misses", "2",
                                    "--json", "-"], self.tmp).stdout)
        self.assertEqual(self.assisted(scored, 0), [False, False])
        self.assertEqual(self.assisted(scored, 1), [False, True, False])
        self.assertEqual([c["strokes_assisted"] for c in scored["per_character"]], [0, 1])
        self.assertEqual(scored["strokes_assisted"], 1)
        self.assertEqual(scored["strokes_accepted"], 4)

    def test_strokes_written_backwards_until_credited_are_written_and_in_order(self):
        # docs/stroke-acceptance.md: every stroke written backwards and then credited assisted has
        # strokes_written = strokes_total and is completed_in_order, with strokes_accepted 0.
        ticks = pen_path("十", [(0, 0, (0.0, 0.0), -1.0)] * 5 + [(0, 1, (0.0, 0.0), -1.0)] * 5)
        write_trace(self.tmp / "backwards.csv", ticks)
        scored = self.score("backwards.csv")
        self.assertEqual(self.assisted(scored), [True, True])
        self.assertEqual(scored["refusals"]["backwards"], 10)
        self.assertEqual((scored["strokes_written"], scored["strokes_accepted"]), (2, 0))
        self.assertEqual(scored["backwards_strokes"], 2)
        self.assertTrue(scored["completed_in_order"])
        # The renderer counts each as a lift in WS (the pen ends at the start) and credits both.
        _, assisted, completed = renderer_story("十", ticks, 3, 5)
        self.assertEqual((assisted, completed), ([0, 1], []))

    # ---- the renderer's own credit on the same trace -----------------------------------------------------
    def test_renderer_and_score_credit_the_same_stroke(self):
        lifts, assisted, completed = renderer_story("十", self.ticks["half", 5], 3, 5)
        # Misses 1 to 4 counted, the hint from the third; the fifth lift credits stroke 1 and stroke 2 is due.
        self.assertEqual([m for _, m, _ in lifts[:4]], [1, 2, 3, 4])
        self.assertEqual([h for _, _, h in lifts[:4]], [False, False, True, True])
        self.assertEqual(lifts[4][:2], (0, 0))
        self.assertEqual(assisted, [0])
        self.assertEqual(completed, [1])
        self.assertEqual(self.assisted(self.score("half5.csv")), [True, False])

    def test_renderer_hints_after_one_miss_and_credits_after_two(self):
        lifts, assisted, _ = renderer_story("十", self.ticks["half", 3], 1, 2)
        self.assertEqual(lifts[0][1:], (1, True))
        self.assertEqual(assisted[0], 0)
        # The score of the same trace credits as the renderer did, one stroke after the other.
        scored = self.score("half3.csv", 2)
        self.assertEqual([i for i, f in enumerate(self.assisted(scored)) if f], assisted)

    def test_hint_count_above_the_assist_count_never_hints(self):
        lifts, assisted, _ = renderer_story("十", self.ticks["half", 5], 6, 5)
        self.assertEqual(assisted[:1], [0])
        self.assertFalse(any(h for _, _, h in lifts), lifts)
        self.assertEqual(run_ok(["trial", "十", "--hint-after-misses", "10", "--assist-after-misses", "5",
                                 "--check"], self.tmp).returncode, 0)

    def test_renderer_zero_never_credits_and_hints_after_each_further_miss(self):
        lifts, assisted, completed = renderer_story("十", self.ticks["half", 7], 3, 0)
        self.assertEqual(assisted, [])
        self.assertEqual(completed, [0, 1])
        self.assertEqual([h for _, _, h in lifts[:7]], [False, False] + [True] * 5)

    def test_pen_downs_never_near_the_start_count_alike_for_renderer_and_score(self):
        # 8 mm across the stroke the pen never comes within the start radius (no WS), and each pen-down is a
        # miss all the same (docs/stroke-acceptance.md, "No dead end"): the fifth credits stroke 1, and stroke 1
        # written right after it is a miss of stroke 2, which is then taken. score says it credits "as the
        # renderer and the trainer credit it, so that the strokes after it are judged as they were".
        lifts, assisted, completed = renderer_story("十", self.ticks["off", 5], 3, 5)
        self.assertEqual(assisted, [0])
        self.assertEqual(completed, [1])
        scored = self.score("off5.csv")
        self.assertEqual(self.assisted(scored), [True, False])
        self.assertEqual(scored["strokes_accepted"], 1)

    # ---- a trial whose writer is made to miss ------------------------------------------------------------
    def test_trial_credits_assisted_strokes_apart_from_completed_ones(self):
        r = self.record
        self.assertEqual(r["end_reason"], "completed")
        self.assertEqual((r["strokes_completed"], r["strokes_assisted"]), (0, 2))
        self.assertEqual([(s["assisted"], s["completed"], s["attempts"]) for s in r["renderer_strokes"]],
                         [(True, False, 2), (True, False, 2)])
        self.assertEqual(r["strokes_written"], 0)
        self.assertFalse(r["completed_in_order"])
        text = run_ok(["trial", "十", *STRICT], self.tmp).stdout.decode()
        self.assertRegex(text, r"strokes assisted\s+2")
        self.assertRegex(text, r"strokes completed\s+0 / 2")

    def test_trial_record_states_its_counts_in_specification_and_force_law(self):
        spec = self.record["specification"]
        for where in (spec["trial"], spec["force_law"]["acceptance"]):
            self.assertEqual((where["hint_after_misses"], where["assist_after_misses"]), (1, 2))
        self.assertEqual(spec["version"], 9)

    def test_trial_rerun_gives_the_same_credits(self):
        again = self.cli("trial", "--spec", "w.json", "--json", "again.json", "--csv", "again.csv")
        self.assertEqual(again.returncode, 0, again.stderr)
        self.assertEqual(again.stderr, b"", "a record re-run as it was says nothing")
        a = json.loads((self.tmp / "again.json").read_text(encoding="utf-8"))
        self.assertEqual(a["renderer_strokes"], self.record["renderer_strokes"])
        self.assertEqual(a["strokes_assisted"], 2)
        self.assertEqual((self.tmp / "again.csv").read_bytes(), (self.tmp / "w.csv").read_bytes())

    def test_trial_csv_scored_with_its_acceptance_gives_its_record(self):
        acceptance = cg.StrokeAcceptance(**self.record["specification"]["force_law"]["acceptance"])
        got = cg.score(str(self.tmp / "w.csv"), "十", acceptance=acceptance)
        for key in COUNT_KEYS:
            self.assertEqual(got[key], self.record[key], key)
        self.assertEqual(got["per_character"][0]["per_stroke"], self.record["per_character"][0]["per_stroke"])

    def test_trial_and_train_counts_out_of_range_are_usage_errors(self):
        for command in ("trial", "train"):
            for option in ("--hint-after-misses", "--assist-after-misses"):
                for value in ("1001", "-1", "2.5"):
                    with self.subTest(command=command, option=option, value=value):
                        extra = ["--check"] if command == "trial" else []
                        self.assert_one_error(self.cli(command, "十", option, value, *extra), 2, option)

    def test_python_trial_gives_the_command_s_credits_and_reruns_them(self):
        law = cg.ForceLawParameters(acceptance=cg.StrokeAcceptance(mean_deviation_m=0.0001,
                                                                   mean_deviation_cap_m=0.0001))
        r = cg.simulate_trial("十", guidance=False, force_law=law, hint_after_misses=1, assist_after_misses=2)
        self.assertEqual(r.metrics["strokes_assisted"], self.record["strokes_assisted"])
        self.assertEqual(r.metrics["renderer_strokes"], self.record["renderer_strokes"])
        frame = r.per_stroke_dataframe()
        self.assertEqual(list(frame["assisted"]), [True, True])
        self.assertEqual(list(frame["completed"]), [False, False])
        self.assertEqual(list(frame["written"]), [False, False])
        spec = r.metrics["specification"]
        self.assertEqual(spec["trial"]["assist_after_misses"], 2)
        self.assertEqual(spec["force_law"]["acceptance"]["assist_after_misses"], 2)
        again = cg.rerun_trial(r.metrics)
        self.assertEqual(again.metrics["renderer_strokes"], r.metrics["renderer_strokes"])

    # ---- records edited ----------------------------------------------------------------------------------
    def edited(self, name, change):
        record = json.loads(json.dumps(self.record))
        change(record)
        (self.tmp / name).write_text(json.dumps(record, ensure_ascii=False), encoding="utf-8")
        return name

    def test_record_count_out_of_range_is_refused_naming_the_pointer(self):
        for pointer in ("/specification/trial/assist_after_misses", "/specification/trial/hint_after_misses",
                        "/specification/force_law/acceptance/assist_after_misses",
                        "/specification/force_law/acceptance/hint_after_misses"):
            # Every kind of wrong value at one pointer, one past the range and one not whole at the others.
            values = (1001, -1, 2.5, "2", None, True) if pointer.endswith("trial/assist_after_misses") else (1001, 2.5)
            for value in values:
                with self.subTest(pointer=pointer, value=value):
                    def change(r, pointer=pointer, value=value):
                        *parents, key = pointer.strip("/").split("/")
                        node = r
                        for part in parents:
                            node = node[part]
                        node[key] = value
                    name = self.edited("bad.json", change)
                    self.assert_one_error(self.cli("trial", "--spec", name, "--check"), 2, pointer)
                    with self.assertRaises(cg.DataError) as caught:
                        cg.check_trial_record(str(self.tmp / name))
                    self.assertIn(pointer, str(caught.exception))

    def test_record_contradicting_its_own_counts_is_refused_naming_the_pointer(self):
        # The specification says 5 misses, the force law 2: which one ran is not for a reader to guess.
        for where, value in (("trial", 5), ("force_law", 5)):
            with self.subTest(where=where):
                def change(r, where=where, value=value):
                    node = r["specification"]["trial"] if where == "trial" else \
                        r["specification"]["force_law"]["acceptance"]
                    node["assist_after_misses"] = value
                name = self.edited("contradiction.json", change)
                self.assert_one_error(self.cli("trial", "--spec", name, "--json", "c.json"), 2,
                                      "assist_after_misses")
                with self.assertRaises(cg.DataError):
                    cg.check_trial_record(str(self.tmp / name))

    def test_record_forged_credits_are_said_to_differ_from_the_re_run(self):
        def change(r):
            r["strokes_assisted"] = 0
            r["strokes_completed"] = 2
        name = self.edited("forged.json", change)
        result = self.cli("trial", "--spec", name, "--json", "f.json")
        self.assertEqual(result.returncode, 0, result.stderr)
        lines = result.stderr.decode().strip().splitlines()
        self.assertEqual(len(lines), 1, lines)
        self.assertIn("differs", lines[0])
        self.assertIn("strokes_assisted recorded 0, now 2", lines[0])
        self.assertIn("strokes_completed recorded 2, now 0", lines[0])
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            again = cg.rerun_trial(str(self.tmp / name))
        self.assertTrue(any(issubclass(w.category, RuntimeWarning) and "strokes_assisted" in str(w.message)
                            for w in caught))
        self.assertEqual(again.metrics["strokes_assisted"], 2)

    def test_record_of_version_3_runs_without_the_credit_and_says_so(self):
        name = self.edited("v3.json", lambda r: r["specification"].__setitem__("version", 3))
        result = self.cli("trial", "--spec", name, "--json", "v3out.json")
        self.assertNotIn(b"Traceback", result.stderr)
        self.assertIn(result.returncode, (0, 1))
        notes = result.stderr.decode()
        self.assertIn("/specification/force_law/acceptance/assist_after_misses is 2 in the record", notes)
        out = json.loads((self.tmp / "v3out.json").read_text(encoding="utf-8"))
        self.assertEqual(out["strokes_assisted"], 0)
        self.assertFalse(any(s["assisted"] for s in out["renderer_strokes"]))
        self.assertEqual(out["specification"]["force_law"]["acceptance"]["assist_after_misses"], 0)

    def test_record_of_version_5_takes_its_counts_from_its_force_law(self):
        def change(r):
            r["specification"]["version"] = 5
            for key in r["specification"]["force_law"]["acceptance"]:
                r["specification"]["trial"].pop(key, None)
        name = self.edited("v5.json", change)
        result = self.cli("trial", "--spec", name, "--json", "v5out.json")
        self.assertEqual(result.returncode, 0, result.stderr)
        out = json.loads((self.tmp / "v5out.json").read_text(encoding="utf-8"))
        self.assertEqual(out["renderer_strokes"], self.record["renderer_strokes"])
        self.assertEqual((out["specification"]["trial"]["hint_after_misses"],
                          out["specification"]["trial"]["assist_after_misses"]), (1, 2))

    # ---- a study: its tables and the quiz ----------------------------------------------------------------
    @classmethod
    def study(cls):
        if not hasattr(cls, "_study"):
            d = cls.tmp
            (d / "p.json").write_text(json.dumps(PROTOCOL), encoding="utf-8")
            run_ok(["session", "run", "p.json", "--subjects", "1", "--out", "S"], d)
            (d / "T").mkdir()
            run_ok(["report", "S", "--csv", "T"], d)
            tables = {name: list(csv.DictReader(io.StringIO((d / "T" / f"{name}.csv").read_text(encoding="utf-8"))))
                      for name in ("trials", "strokes")}
            record = json.loads(next((d / "S" / "S01").glob("*/trials/*.json")).read_text(encoding="utf-8"))
            cls._study = tables, record
        return cls._study

    def test_trials_csv_counts_assisted_strokes_apart_from_written_ones(self):
        tables, record = self.study()
        row = tables["trials"][0]
        self.assertEqual(row["strokes_assisted"], "2")
        self.assertEqual(row["strokes_written"], "0")
        self.assertEqual(row["strokes_accepted"], "0")
        self.assertEqual(row["end_reason"], "completed")
        self.assertEqual(int(row["strokes_assisted"]), record["strokes_assisted"])

    def test_strokes_csv_gives_each_stroke_its_assisted_credit(self):
        # docs/stroke-acceptance.md: per stroke `assisted: true` (the trial's JSON, its record, the study tables).
        tables, record = self.study()
        rows = tables["strokes"]
        self.assertEqual(len(rows), 2)
        for row in rows:
            self.assertIn("assisted", row, "strokes.csv has no column for a stroke's assisted credit")
            self.assertEqual(row["assisted"].upper(), "TRUE")
            self.assertEqual(row["written"].upper(), "FALSE")
        study = __import__("calligraphy.study").study.load(str(self.tmp / "S"))
        self.assertEqual(list(study.strokes["assisted"]), [True, True])

    def test_quiz_credits_after_its_misses_and_hints_after_each_other_miss(self):
        # quiz.hpp: after the acceptance's assist_after_misses misses on a stroke (2 here) the quiz credits it
        # assisted (`stroke_assisted` right after the miss, no hint beside it) and expects the next; a hint
        # after hint_after_misses misses (1) and after each further miss but the one that credits it.
        _, record = self.study()
        quiz = record["quiz"]
        self.assertEqual(quiz["hint_after_misses"], 1)
        self.assertEqual(quiz["strokes_accepted"], 0)
        kinds = [e["kind"] for e in quiz["characters"][0]["events"] if e["kind"] != "too_short"]
        self.assertEqual(kinds, ["stroke_missed", "hint", "stroke_missed", "stroke_assisted"] * 2 +
                         ["character_completed"])
        missed = [e for e in quiz["characters"][0]["events"] if e["kind"] == "stroke_missed"]
        self.assertEqual([(e["stroke"], e["misses_on_stroke"]) for e in missed], [(0, 1), (0, 2), (1, 1), (1, 2)])
        self.assertEqual(quiz["misses"], 4)
        self.assertEqual(quiz["hints"], 2)
        self.assertEqual(quiz["strokes_assisted"], 2)
        self.assertEqual(record["strokes_assisted"], 2, "the renderer of the quiz trial credited both")

    def test_quiz_own_hint_count_overrides_the_acceptance_s(self):
        protocol = json.loads(json.dumps(PROTOCOL))
        protocol["name"] = "assist2"
        protocol["conditions"][0]["quiz"]["hint_after_misses"] = 3
        d = self.tmp
        (d / "p2.json").write_text(json.dumps(protocol), encoding="utf-8")
        run_ok(["session", "run", "p2.json", "--subjects", "1", "--out", "S2"], d)
        record = json.loads(next((d / "S2" / "S01").glob("*/trials/*.json")).read_text(encoding="utf-8"))
        quiz = record["quiz"]
        self.assertEqual(quiz["hint_after_misses"], 3)
        # Each stroke credited at its 2nd miss, before a 3rd could bring the hint.
        self.assertEqual(quiz["hints"], 0)
        self.assertEqual(quiz["strokes_assisted"], 2)
        # The trial's renderer took the acceptance's counts: both strokes credited after two misses.
        self.assertEqual(record["strokes_assisted"], 2)


if __name__ == "__main__":
    unittest.main()
