#!/usr/bin/env python3
"""Round 28A: what counts as a miss of the stroke due, wherever the pen-down was (records of version 8), and
what follows from it: the hint after `hint_after_misses`, the assisted credit after `assist_after_misses`.
From the docs alone: docs/stroke-acceptance.md ("No dead end" and the table's `miss_min_path_m`), docs/cli.md
(`trial`, `score`, "Re-running a trial", "The trial specification"), docs/metrics.md (`strokes_assisted`),
docs/python.md (`Renderer`, `score`, `StrokeAcceptance`), docs/trainer.md ("Hints and assisted strokes"),
include/calligraphy/model/stroke_progress.hpp (`RefusedPenDown`, `counts_as_miss`, `kMinMissSamples`),
include/calligraphy/render/renderer.hpp (`RenderOutput::missed_off_start`), include/calligraphy/analysis/score.hpp.

Traces of 十 are written by hand with numpy from the data's medians: the pen set down and lifted in one tick
(2 mm above the paper, 0.3 mm into it), so that the samples on the paper are exactly those written. Each kind
of pen-down (8 mm beside stroke 1, 0.8 mm and 1.3 mm of path, 2 and 3 samples, a touch that does not move
beside the stroke and at its start, wholly outside the character's box, partly in it, a lift in WS, stroke 2
out of turn) is written twice while stroke 1 is due and then stroke 2 right, with the assisted credit after
two misses: stroke 1 is credited exactly when the kind counts as a miss. The same traces go through
`calligraphy score --json`, Python's `score` and a `Renderer` ticked here (its `misses`, `hint_shown`,
`missed_off_start`, `stroke_assisted`). A mixed trace is compared across the three at every count from 0 to 6
with the count the docs' rule gives. `miss_min_path_m` 0 (the rule of records before version 8) and 0.1 (its
top) change which pen-downs count; it is not scaled with the character (30 and 120 mm boxes); the box's edge, a
row of two characters, a pen-down slid into WS, a trace in data units and pen-downs held 0.3 mm above the paper
(under `score`'s 0.5 mm contact threshold) are held to the same agreement. A simulated writer whose copy of 十 lies 10 mm off (never within the start
radius) is credited by `calligraphy trial` at version 8 and not with `--miss-min-path 0`; its record is re-run,
edited (the field null, negative, huge, a string, the two places disagreeing) and turned into a version-7
record, which runs with the older rule and says so.

CALLIGRAPHY_CLI names the program; PYTHONPATH the built Python package. CALLIGRAPHY_SANITIZED=1 takes five cases.
"""
import json
import shutil
import tempfile
import unittest
import warnings
from pathlib import Path

from outsider import OneErrorLine, error_lines, run, run_ok, sanitized_subset

try:
    import numpy as np
    import outsider_pen
    import calligraphy as cg
except ImportError:  # reported by setUpClass: every case needs the traces numpy and the package draw
    np = cg = None


def along(median, offset=(0.0, 0.0), fraction=1.0, n=150):
    """`n` points along a median [m] (outsider_pen.along, this round's density)."""
    return outsider_pen.along(median, offset, fraction, n)


def write_trace(path, ticks):
    outsider_pen.write_trace(path, ticks)

load_tests = sanitized_subset({"test_score_and_renderer_count_a_pen_down_8mm_beside_the_stroke",
                               "test_score_and_renderer_count_no_pen_down_wholly_outside_the_box",
                               "test_trial_miss_min_path_out_of_range_or_not_a_number_is_one_error",
                               "test_record_miss_min_path_bad_value_is_refused_at_its_pointer",
                               "test_record_miss_min_path_differing_in_its_two_places_is_refused"})

MM = 1e-3
RATE_HZ = 1000.0
HOVER_M = 0.002      # above the 0.5 mm contact threshold: lifted
DOWN_M = -0.0003     # on the paper
LEAD = 30            # hover ticks before the first pen-down and after the last
TRAVEL = 40          # hover ticks between two pen-downs
# A simulated writer whose copy of 十 lies 10 mm off, never corrected: it never comes within the 5 mm start
# radius of a stroke's start, and every attempt is refused.
OFF_WRITER = ["--guidance", "off", "--writer-param", "bias_offset_m=0.01", "--writer-param",
              "correction_per_attempt=0", "--writer-param", "error_tolerance_m=0.05", "--writer-param",
              "stroke_jitter_m=0", "--hint-after-misses", "1", "--assist-after-misses", "2"]
TRIAL_POINTER = "/specification/trial/miss_min_path_m"
LAW_POINTER = "/specification/force_law/acceptance/miss_min_path_m"


def segment(a_mm, b_mm, n):
    """`n` points from a to b (given in mm), in metres."""
    return np.linspace(np.asarray(a_mm, float), np.asarray(b_mm, float), n) * MM


def path_length(points):
    return float(np.sum(np.linalg.norm(np.diff(points, axis=0), axis=1)))


def ticks_of(downs, end_down=False):
    """(t, x, y, z) at 1 kHz of a pen writing each pen-down of `downs` (one sample per point on the paper), set
    down and lifted in one tick, carried through the air between them; with `end_down` the trace ends with
    the pen still down on the last one."""
    rows, here = [], None
    for p in downs:
        if here is None:
            rows += [(p[0][0], p[0][1], HOVER_M)] * LEAD
        else:
            rows += [(*(here * (1 - a) + p[0] * a), HOVER_M) for a in np.linspace(0.0, 1.0, TRAVEL)]
        rows += [(q[0], q[1], DOWN_M) for q in p]
        here = np.asarray(p[-1])
    if not end_down:
        rows += [(here[0], here[1], HOVER_M)] * LEAD
    xyz = np.asarray(rows, dtype=float)
    return np.column_stack([np.arange(len(xyz)) / RATE_HZ, xyz])


def hovering(ticks, down_downs):
    """`ticks` with the samples of the pen-downs numbered in `down_downs` (0-based) raised to 0.3 mm above the
    paper: under `score`'s 0.5 mm contact threshold, never touching."""
    ticks = ticks.copy()
    down = ticks[:, 3] < 0.0
    starts = np.flatnonzero(down & ~np.concatenate([[False], down[:-1]]))
    for i in down_downs:
        j = starts[i]
        while j < len(ticks) and down[j]:
            ticks[j, 3] = 0.0003
            j += 1
    return ticks


def columns(ticks):
    return {"t": ticks[:, 0], "x": ticks[:, 1], "y": ticks[:, 2], "z": ticks[:, 3]}


def renderer_story(ticks, scene="十", **acceptance):
    """The renderer's own view of the ticks: per pen-down, after it (at the next touch-down, or the end) the
    active stroke, its misses, whether its hint is shown and how many ticks said `missed_off_start` since the
    pen-down began; the strokes credited assisted and those completed, in order."""
    scene = cg.Scene(scene) if isinstance(scene, str) else scene
    renderer = cg.Renderer(scene, cg.ForceLawParameters(acceptance=cg.StrokeAcceptance(**acceptance)),
                           device=cg.SimulatedDevice().info, options=cg.RendererOptions(rate_hz=RATE_HZ))
    after, assisted, completed = [], [], []
    previous, out, was_down, seen_down, off_start, active = ticks[0][1:], None, False, False, 0, 0
    for t, x, y, z in ticks:
        down = z < 0.0
        if down and not was_down:
            if seen_down:
                after.append((None if out.finished else out.stroke, out.misses, out.hint_shown, off_start))
            seen_down, off_start = True, 0
        was_down = down
        velocity = (np.array((x, y, z)) - np.asarray(previous)) * RATE_HZ
        previous = (x, y, z)
        out = renderer.tick(cg.DeviceState(position_m=(float(x), float(y), float(z)),
                                           velocity_m_s=tuple(float(v) for v in velocity), time_s=float(t)))
        if out.stroke_assisted:
            assisted.append(active)
        if out.stroke_completed:
            completed.append(active)
        off_start += int(out.missed_off_start)
        if not out.finished:
            active = out.stroke if len(scene.characters) == 1 else (out.character, out.stroke)
    after.append((None if out.finished else out.stroke, out.misses, out.hint_shown, off_start))
    return after, assisted, completed


def model(kinds, assist):
    """The docs' rule on a sequence of pen-downs of 十: `kinds` holds per pen-down (counts as a miss, the stroke it
    writes right or None). Returns (assisted, accepted) per stroke."""
    due, misses, assisted, accepted = 0, 0, [False, False], [False, False]
    for counts, writes in kinds:
        if due >= 2:
            break
        if writes == due:
            accepted[due] = True
            due, misses = due + 1, 0
        elif counts:
            misses += 1
            if assist and misses == assist:
                assisted[due] = True
                due, misses = due + 1, 0
    return assisted, accepted


class Round28A(unittest.TestCase, OneErrorLine):
    @classmethod
    def setUpClass(cls):
        if cg is None:
            raise unittest.SkipTest("numpy and the calligraphy Python package (PYTHONPATH) are needed")
        cls.tmp = Path(tempfile.mkdtemp(prefix="round28a-"))
        scene = cg.Scene("十")
        s1, s2 = (np.asarray(s.median_m, dtype=float) for s in scene.characters[0].strokes)
        box = np.asarray(scene.characters[0].bounding_box_m)
        cls.box = box
        start = s1[0]
        beside = start + np.array([0.0, 8 * MM])          # 8 mm above stroke 1's start: outside its 5 mm radius
        away = np.array([10 * MM, -15 * MM])               # in the box, far from both strokes' starts
        left = box[0][0] * 1e3                             # the box's left side [mm]
        cls.kinds = {
            # name: (pen-down, counts as a miss of stroke 1 by the docs, enters stroke 1's WS)
            "beside": (along(s1, (0.0, 8 * MM)), True, False),
            "short_under": (np.linspace(beside, beside + [0.8 * MM, 0.0], 40), False, False),
            "short_over": (np.linspace(beside, beside + [1.3 * MM, 0.0], 40), True, False),
            "two_samples": (np.array([away, away + [3 * MM, 0.0]]), False, False),
            "three_samples": (np.array([away, away + [1.5 * MM, 0.0], away + [3 * MM, 0.0]]), True, False),
            "touch_beside": (np.repeat([beside], 150, axis=0), False, False),
            "touch_start": (np.repeat([start], 150, axis=0), False, True),
            "outside": (segment((left - 16, -10), (left - 16, 10), 80), False, False),
            "partly": (segment((left - 16, -15), (left + 3.6, -15), 80), True, False),
            "half": (along(s1, fraction=0.4), True, True),
            "stroke2": (along(s2), True, False),
            # Set down 8 mm above stroke 1's start, slid onto it, then 40 % along it: it enters WS on the way.
            "slide_in_half": (np.concatenate([np.linspace(beside, start, 30), along(s1, fraction=0.4)[1:]]),
                              True, True),
        }
        cls.slide_in_whole = np.concatenate([np.linspace(beside, start, 30), along(s1)[1:]])
        cls.right1, cls.right2 = along(s1), along(s2)
        cls.s1, cls.s2 = s1, s2
        # Sanity of the hand-made kinds against the docs' thresholds, so that a case tests what its name says.
        assert path_length(cls.kinds["short_under"][0]) < 0.95 * MM < 1.05 * MM < path_length(
            cls.kinds["short_over"][0])
        assert np.all(cls.kinds["outside"][0][:, 0] < box[0][0] - 10 * MM)
        assert np.linalg.norm(beside - start) > 7.9 * MM
        cls.cache = {}

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.tmp, ignore_errors=True)

    def cli(self, *args):
        return run(list(args), self.tmp)

    def trace_file(self, name, ticks):
        path = self.tmp / f"{name}.csv"
        if not path.exists():
            write_trace(path, ticks)
        return path.name

    def cli_score(self, name, ticks, assist):
        key = ("cli", name, assist)
        if key not in self.cache:
            out = run_ok(["score", self.trace_file(name, ticks), "--character", "十", "--json", "-",
                          "--assist-after-misses", str(assist)], self.tmp)
            self.cache[key] = json.loads(out.stdout)
        return self.cache[key]

    @staticmethod
    def assisted(scored):
        return [s["assisted"] for s in scored["per_character"][0]["per_stroke"]]

    @staticmethod
    def due_flags(scored):
        return [bool(s["verdict"] and s["verdict"]["assists_due"]) for s in scored["per_character"][0]["segments"]]

    # ---- each kind of pen-down, twice while stroke 1 is due, then stroke 2 right --------------------------
    def check_kind(self, name):
        down, counts, enters_ws = self.kinds[name]
        downs = [down, down, self.right2]
        ticks = ticks_of(downs)
        # Docs: credited at the second miss (assist 2), then stroke 2 written right is accepted; otherwise stroke
        # 2 written while stroke 1 is due is the first miss and nothing is credited.
        scored = self.cli_score(name, ticks, 2)
        self.assertEqual(self.assisted(scored), [counts, False], scored["per_character"][0]["segments"])
        self.assertEqual(scored["strokes_assisted"], int(counts))
        self.assertEqual(scored["strokes_accepted"], int(counts))
        self.assertEqual(self.due_flags(scored), [False, counts, False])
        python = cg.score(columns(ticks), "十", acceptance=cg.StrokeAcceptance(assist_after_misses=2))
        self.assertEqual(self.assisted(python), self.assisted(scored))
        self.assertEqual(python["strokes_accepted"], scored["strokes_accepted"])
        # The renderer, with the hint after one miss and the credit after two.
        after, assisted, completed = renderer_story(ticks, hint_after_misses=1, assist_after_misses=2)
        self.assertEqual(len(after), 3, after)
        self.assertEqual(after[0][:3], (0, 1, True) if counts else (0, 0, False), after)
        self.assertEqual(after[0][3], int(counts and not enters_ws), "missed_off_start at the first lift")
        self.assertEqual(after[1][3], int(counts and not enters_ws), "missed_off_start at the second lift")
        self.assertEqual((assisted, completed), ([0], [1]) if counts else ([], []))
        if not counts:
            self.assertEqual(after[2][:3], (0, 1, True), "stroke 2 written while stroke 1 is due is a miss")
        return scored

    def test_score_and_renderer_count_a_pen_down_8mm_beside_the_stroke(self):
        self.check_kind("beside")

    def test_score_and_renderer_count_no_pen_down_of_0_8mm_path(self):
        scored = self.check_kind("short_under")
        self.assertEqual(scored["per_character"][0]["ignored_segments"], 2)

    def test_score_and_renderer_count_a_pen_down_of_1_3mm_path(self):
        self.check_kind("short_over")

    def test_score_and_renderer_count_no_pen_down_of_two_samples(self):
        scored = self.check_kind("two_samples")
        self.assertEqual(scored["per_character"][0]["ignored_segments"], 2)

    def test_score_and_renderer_count_a_pen_down_of_three_samples(self):
        self.check_kind("three_samples")

    def test_score_and_renderer_count_no_touch_that_does_not_move_beside_the_stroke(self):
        self.check_kind("touch_beside")

    def test_score_and_renderer_count_no_touch_that_does_not_move_at_the_start(self):
        self.check_kind("touch_start")

    def test_score_and_renderer_count_no_pen_down_wholly_outside_the_box(self):
        scored = self.check_kind("outside")
        segments = scored["per_character"][0]["segments"]
        self.assertEqual(scored["per_character"][0]["ignored_segments"], 0, "a 20 mm pen-down is judged")
        for s in segments[:2]:
            self.assertIsNotNone(s["verdict"])
            self.assertFalse(s["verdict"]["accepted"])

    def test_score_and_renderer_count_a_pen_down_partly_in_the_box(self):
        self.check_kind("partly")

    def test_score_and_renderer_count_a_lift_in_ws_short_of_the_end(self):
        scored = self.check_kind("half")
        self.assertEqual(scored["per_character"][0]["segments"][0]["verdict"]["refusal"], "too_short")

    def test_score_and_renderer_count_another_stroke_written_out_of_turn(self):
        scored = self.check_kind("stroke2")
        verdicts = [s["verdict"] for s in scored["per_character"][0]["segments"]]
        self.assertEqual([v["refusal"] for v in verdicts], ["wrong_order", "wrong_order", "none"])

    def test_score_and_renderer_count_a_pen_down_slid_into_ws_and_lifted_short(self):
        self.check_kind("slide_in_half")

    def test_score_and_renderer_take_a_stroke_begun_beside_and_slid_into_ws(self):
        # python.md: a Renderer whose pen moves along the points "writes the stroke exactly when the matcher
        # accepts it"; the matcher enters a stroke where the path first comes within the start radius.
        ticks = ticks_of([self.slide_in_whole, self.right2])
        python = cg.score(columns(ticks), "十", acceptance=cg.StrokeAcceptance(assist_after_misses=1))
        verdicts = [s["verdict"] for s in python["per_character"][0]["segments"]]
        _, assisted, completed = renderer_story(ticks, assist_after_misses=1)
        self.assertEqual(assisted, [i for i, f in enumerate(self.assisted(python)) if f])
        self.assertEqual(completed, [v["expected_stroke"] for v in verdicts if v and v["accepted"]])

    def test_score_and_renderer_agree_on_a_pen_down_whose_samples_all_lie_outside_the_box(self):
        # Three samples, left of the box, right of it, left again: the path crosses the box, no sample is in it.
        left, right = self.box[0][0] - 15 * MM, self.box[1][0] + 15 * MM
        across = np.array([[left, -15 * MM], [right, -15 * MM], [left, -15 * MM]])
        ticks = ticks_of([across, across, self.right2])
        python = cg.score(columns(ticks), "十", acceptance=cg.StrokeAcceptance(assist_after_misses=2))
        _, assisted, _ = renderer_story(ticks, assist_after_misses=2)
        self.assertEqual(assisted, [i for i, f in enumerate(self.assisted(python)) if f])

    def test_score_in_data_units_counts_the_misses_it_counts_in_metres(self):
        placement = cg.Scene("十").characters[0].placement
        for name in ("short_under", "short_over", "two_samples", "beside"):
            with self.subTest(kind=name):
                down, counts, _ = self.kinds[name]
                ticks = ticks_of([down, down, self.right2])
                data = ticks.copy()
                data[:, 1:3] = placement.to_data(ticks[:, 1:3])
                scored = json.loads(run_ok(["score", self.trace_file(f"data-{name}", data), "--character", "十",
                                            "--units", "data", "--json", "-", "--assist-after-misses", "2"],
                                           self.tmp).stdout)
                self.assertEqual(self.assisted(scored), [counts, False])

    def test_pen_hovering_within_half_a_millimetre_writes_in_score_and_not_in_the_renderer(self):
        # Two pen-downs 8 mm beside stroke 1 held 0.3 mm above the paper. First run: a finding (`score` credited
        # stroke 1, the renderer nothing, where the docs said they count misses the same way); the docs now say
        # why the two differ there (stroke-acceptance.md, "No dead end": "a pen that hovers within 0.5 mm of the
        # paper without touching it writes in `score` and not in the renderer"), kept so that older records are
        # scored as they were.
        beside = self.kinds["beside"][0]
        ticks = hovering(ticks_of([beside, beside, self.right2]), (0, 1))
        python = cg.score(columns(ticks), "十", acceptance=cg.StrokeAcceptance(assist_after_misses=2))
        _, assisted, completed = renderer_story(ticks, assist_after_misses=2)
        self.assertEqual(self.assisted(python), [True, False], "score: two misses, stroke 1 credited")
        self.assertEqual((assisted, completed), ([], []), "the renderer: the pen never touched before stroke 2")

    # ---- the pen-down the trace ends in; the count reached exactly -------------------------------------
    def test_pen_down_the_trace_ends_in_is_no_miss(self):
        beside = self.kinds["beside"][0]
        ticks = ticks_of([beside, beside], end_down=True)
        scored = self.cli_score("ends_down", ticks, 2)
        self.assertEqual(self.assisted(scored), [False, False])
        self.assertEqual(self.due_flags(scored), [False, False])
        after, assisted, _ = renderer_story(ticks, hint_after_misses=3, assist_after_misses=2)
        self.assertEqual(assisted, [])
        self.assertEqual(after[-1][:2], (0, 1), "one miss: the pen-down still down is none")
        # The same two pen-downs lifted: the second is the second miss.
        lifted = self.cli_score("ends_up", ticks_of([beside, beside]), 2)
        self.assertEqual(self.assisted(lifted), [True, False])

    def test_credit_comes_at_exactly_the_assist_count_and_the_hint_before_it(self):
        beside = self.kinds["beside"][0]
        ticks = ticks_of([beside] * 3 + [self.right2])
        at3 = self.cli_score("beside3", ticks, 3)
        self.assertEqual(self.assisted(at3), [True, False])
        self.assertEqual(self.due_flags(at3), [False, False, True, False])
        self.assertEqual(at3["strokes_accepted"], 1)
        at4 = self.cli_score("beside3", ticks, 4)
        # Stroke 2 written while stroke 1 is due is the fourth miss: it credits stroke 1, and nothing is accepted.
        self.assertEqual(self.assisted(at4), [True, False])
        self.assertEqual(self.due_flags(at4), [False, False, False, True])
        self.assertEqual(at4["strokes_accepted"], 0)
        after, assisted, completed = renderer_story(ticks, hint_after_misses=2, assist_after_misses=3)
        self.assertEqual([a[:3] for a in after[:2]], [(0, 1, False), (0, 2, True)])
        self.assertEqual(after[2][:3], (1, 0, False), "credited at the third: stroke 2 is active, no hint")
        self.assertEqual((assisted, completed), ([0], [1]))
        after, assisted, completed = renderer_story(ticks, hint_after_misses=2, assist_after_misses=4)
        self.assertEqual([a[1] for a in after[:3]], [1, 2, 3])
        self.assertEqual((assisted, completed), ([0], []))

    # ---- one mixed trace, every count ------------------------------------------------------------------
    MIXED = ["touch_start", "short_under", "outside", "two_samples", "beside", "half", "partly", "three_samples",
             "stroke2", "touch_beside", "right1", "right2"]

    def mixed(self):
        downs, kinds = [], []
        for name in self.MIXED:
            if name == "right1":
                downs.append(self.right1)
                kinds.append((True, 0))
            elif name == "right2":
                downs.append(self.right2)
                kinds.append((True, 1))
            else:
                down, counts, _ = self.kinds[name]
                downs.append(down)
                kinds.append((counts, 1 if name == "stroke2" else None))
        return ticks_of(downs), kinds

    def test_mixed_trace_renderer_counts_the_misses_the_docs_count(self):
        ticks, _ = self.mixed()
        after, assisted, completed = renderer_story(ticks, hint_after_misses=3, assist_after_misses=0)
        want = [0, 0, 0, 0, 1, 2, 3, 4, 5, 5]
        self.assertEqual([a[1] for a in after[:10]], want, after)
        self.assertEqual([a[2] for a in after[:10]], [m >= 3 for m in want])
        self.assertEqual([a[3] > 0 for a in after[:10]],
                         [False, False, False, False, True, False, True, True, True, False])
        self.assertEqual((assisted, completed), ([], [0, 1]))

    def test_mixed_trace_score_python_and_renderer_credit_alike_at_every_count(self):
        ticks, kinds = self.mixed()
        for assist in range(0, 7):
            with self.subTest(assist=assist):
                want_assisted, want_accepted = model(kinds, assist)
                python = cg.score(columns(ticks), "十", acceptance=cg.StrokeAcceptance(assist_after_misses=assist))
                self.assertEqual(self.assisted(python), want_assisted)
                self.assertEqual(python["strokes_accepted"], sum(want_accepted))
                _, assisted, completed = renderer_story(ticks, hint_after_misses=3, assist_after_misses=assist)
                self.assertEqual(assisted, [i for i, f in enumerate(want_assisted) if f])
                self.assertEqual(completed, [i for i, f in enumerate(want_accepted) if f])
                if assist in (0, 3):
                    scored = self.cli_score("mixed", ticks, assist)
                    self.assertEqual(self.assisted(scored), want_assisted)
                    # The file the command read (to 0.1 um), read by Python: the same verdicts.
                    from_file = cg.score(str(self.tmp / "mixed.csv"), "十",
                                         acceptance=cg.StrokeAcceptance(assist_after_misses=assist))
                    self.assertEqual(scored["per_character"][0]["segments"],
                                     from_file["per_character"][0]["segments"])

    def test_score_table_says_assisted_for_a_stroke_never_started_in_ws(self):
        beside = self.kinds["beside"][0]
        name = self.trace_file("beside2", ticks_of([beside, beside, self.right2]))
        text = run_ok(["score", name, "--character", "十", "--assist-after-misses", "2"], self.tmp).stdout.decode()
        rows = [line.split() for line in text.splitlines()]
        row1 = next(" ".join(r) for r in rows if len(r) > 2 and r[0] == "1" and r[1] in ("H", "十"))
        row2 = next(" ".join(r) for r in rows if len(r) > 2 and r[0] == "2" and r[1] in ("S", "十"))
        self.assertIn("assisted (last refused: wrong place", row1)
        self.assertTrue(row2.endswith("accepted"), row2)

    # ---- the older rule (0) and the top of the range (0.1 m) -------------------------------------------
    def test_miss_min_path_zero_counts_a_lift_in_ws_only(self):
        beside, half = self.kinds["beside"][0], self.kinds["half"][0]
        ticks = ticks_of([beside] * 3 + [half] * 2 + [self.right1, self.right2])
        for rule, want in ((0.001, [True, True]), (0.0, [True, False])):
            with self.subTest(miss_min_path_m=rule):
                acceptance = dict(assist_after_misses=2, miss_min_path_m=rule)
                python = cg.score(columns(ticks), "十", acceptance=cg.StrokeAcceptance(**acceptance))
                self.assertEqual(self.assisted(python), want)
                after, assisted, completed = renderer_story(ticks, hint_after_misses=1, **acceptance)
                self.assertEqual(assisted, [i for i, f in enumerate(want) if f])
                if rule == 0.0:
                    self.assertEqual([a[1] for a in after[:4]], [0, 0, 0, 1])
                    self.assertEqual(sum(a[3] for a in after), 0, "no pen-down off the start counts")
                    self.assertEqual(completed, [1])

    def test_miss_min_path_at_its_top_counts_no_shorter_pen_down(self):
        half, beside = self.kinds["half"][0], self.kinds["beside"][0]
        acceptance = dict(assist_after_misses=1, miss_min_path_m=0.1)
        ticks = ticks_of([half] * 3 + [self.right1, self.right2])
        python = cg.score(columns(ticks), "十", acceptance=cg.StrokeAcceptance(**acceptance))
        self.assertEqual(self.assisted(python), [False, False])
        self.assertEqual(python["strokes_accepted"], 2)
        after, assisted, completed = renderer_story(ticks, **acceptance)
        self.assertEqual((assisted, completed), ([], [0, 1]))
        self.assertEqual([a[1] for a in after[:3]], [0, 0, 0])
        # 8 mm beside, forth, back and forth again: 147 mm of path, a miss.
        long = np.concatenate([beside, beside[::-1], beside])
        self.assertGreater(path_length(long), 0.1)
        ticks = ticks_of([long, self.right2])
        python = cg.score(columns(ticks), "十", acceptance=cg.StrokeAcceptance(**acceptance))
        self.assertEqual(self.assisted(python), [True, False])
        _, assisted, completed = renderer_story(ticks, **acceptance)
        self.assertEqual((assisted, completed), ([0], [1]))

    def test_miss_min_path_is_not_scaled_with_the_character_size(self):
        # stroke-acceptance.md: "All lengths but miss_min_path_m (a pen's jitter, not a stroke's size) ... scale".
        for size in (0.03, 0.12):
            scene = cg.Scene("十", layout=cg.SceneLayout(character_size_m=size, spacing_m=size + 0.01))
            s1, s2 = (np.asarray(s.median_m, dtype=float) for s in scene.characters[0].strokes)
            beside, right2 = s1[0] + [0.0, 8 * MM], along(s2, n=300)
            for path_mm, counts in ((0.8, False), (1.3, True)):
                with self.subTest(size=size, path_mm=path_mm):
                    short = np.linspace(beside, beside + [path_mm * MM, 0.0], 40)
                    ticks = ticks_of([short, short, right2])
                    python = cg.score(columns(ticks), scene, acceptance=cg.StrokeAcceptance(assist_after_misses=2))
                    self.assertEqual(self.assisted(python), [counts, False])
                    _, assisted, completed = renderer_story(ticks, scene=scene, hint_after_misses=1,
                                                            assist_after_misses=2)
                    self.assertEqual((assisted, completed), ([0], [1]) if counts else ([], []))

    def test_box_edge_score_and_renderer_agree_on_which_pen_downs_count(self):
        scene = cg.Scene("一")
        s1 = np.asarray(scene.characters[0].strokes[0].median_m, dtype=float)
        top = float(np.asarray(scene.characters[0].bounding_box_m)[1][1])
        right1 = along(s1)
        # 1 mm inside the box's top; 7 mm above it (inside the 60 mm data box); 15 mm above the data box.
        for name, y, want in (("inside", top - 1 * MM, True), ("between", top + 7 * MM, None),
                              ("outside", 0.045, False)):
            with self.subTest(where=name):
                line = segment((-10, y / MM), (10, y / MM), 80)
                ticks = ticks_of([line, line, right1])
                scored = json.loads(run_ok(["score", self.trace_file(f"edge-{name}", ticks), "--character", "一",
                                            "--json", "-", "--assist-after-misses", "2"], self.tmp).stdout)
                credit = self.assisted(scored)[0]
                python = cg.score(columns(ticks), "一", acceptance=cg.StrokeAcceptance(assist_after_misses=2))
                self.assertEqual(self.assisted(python)[0], credit)
                _, assisted, completed = renderer_story(ticks, scene=scene, assist_after_misses=2)
                self.assertEqual(assisted, [0] if credit else [], "the renderer credits as the score does")
                self.assertEqual(completed, [] if credit else [0])
                if want is not None:
                    self.assertEqual(credit, want)

    def test_older_rule_counts_a_short_lift_in_ws_for_the_renderer_and_not_for_score(self):
        # stroke_progress.hpp: miss_min_path_m "0: only a lift in WS is a miss, however short (records before
        # version 8)". First run: a finding (the docs said `score` counts the misses the same way); the docs now
        # say `score` "never judges a touch too short to score (under 3 samples or 1 mm), so with
        # `miss_min_path_m` 0 such a touch lifted in WS is a miss for the renderer and not for `score`", as the
        # records of that rule were scored.
        start = self.s1[0]
        for name, nudge in (("0.5 mm over 40 samples", np.linspace(start, start + [0.5 * MM, 0.0], 40)),
                            ("3 mm over 2 samples", np.array([start, start + [3 * MM, 0.0]]))):
            with self.subTest(pen_down=name):
                ticks = ticks_of([nudge, nudge, self.right2])
                acceptance = dict(assist_after_misses=2, miss_min_path_m=0.0)
                _, assisted, _ = renderer_story(ticks, hint_after_misses=1, **acceptance)
                python = cg.score(columns(ticks), "十", acceptance=cg.StrokeAcceptance(**acceptance))
                self.assertEqual(assisted, [0], "the renderer: two lifts in WS are two misses")
                self.assertEqual(self.assisted(python), [False, False], "score: a touch too short is no miss")

    def test_row_pen_downs_beside_the_second_character_count_for_it(self):
        scene = cg.Scene("十二")
        (t1, t2), (e1, e2) = ([np.asarray(s.median_m, dtype=float) for s in c.strokes] for c in scene.characters)
        beside = along(e1, (0.0, -8 * MM))  # 8 mm below 二's first stroke, between its two strokes
        ticks = ticks_of([along(t1), along(t2), beside, beside, along(e2)])
        scored = json.loads(run_ok(["score", self.trace_file("row", ticks), "--character", "十二", "--json", "-",
                                    "--assist-after-misses", "2"], self.tmp).stdout)
        self.assertEqual([[s["assisted"] for s in c["per_stroke"]] for c in scored["per_character"]],
                         [[False, False], [True, False]])
        self.assertEqual(scored["strokes_accepted"], 3)
        _, assisted, completed = renderer_story(ticks, scene=scene, assist_after_misses=2)
        self.assertEqual(assisted, [(1, 0)])
        self.assertEqual(completed, [(0, 0), (0, 1), (1, 1)])

    def test_python_trial_records_the_miss_min_path_of_its_force_law(self):
        law = cg.ForceLawParameters(acceptance=cg.StrokeAcceptance(miss_min_path_m=0.0025))
        r = cg.simulate_trial("十", force_law=law, hint_after_misses=2, max_duration_s=0.05)
        spec = r.metrics["specification"]
        self.assertEqual(spec["trial"]["miss_min_path_m"], 0.0025)
        self.assertEqual(spec["force_law"]["acceptance"]["miss_min_path_m"], 0.0025)
        self.assertEqual(spec["trial"]["hint_after_misses"], 2)

    def test_python_acceptance_takes_the_range_of_miss_min_path(self):
        self.assertEqual(cg.StrokeAcceptance().miss_min_path_m, 0.001)
        for value in (0.0, 0.1):
            self.assertEqual(cg.StrokeAcceptance(miss_min_path_m=value).miss_min_path_m, value)
        for value in (-0.001, 0.1000001, float("nan"), float("inf")):
            with self.subTest(value=value):
                with self.assertRaises(cg.InvalidArgument) as caught:
                    cg.StrokeAcceptance(miss_min_path_m=value)
                self.assertIn("miss_min_path_m", str(caught.exception))
        with self.assertRaises(TypeError):
            cg.StrokeAcceptance(miss_min_path_m="0.001")

    # ---- calligraphy trial: the option --------------------------------------------------------------
    def test_trial_miss_min_path_in_range_and_either_spelling_is_recorded(self):
        for args in (["--miss-min-path", "0"], ["--miss-min-path=0.1"], ["--miss-min-path", "1e-3"]):
            with self.subTest(args=args):
                self.assertEqual(run_ok(["trial", "十", *args, "--check"], self.tmp).returncode, 0)
        specs = []
        for i, args in enumerate((["--miss-min-path", "0.0025"], ["--miss-min-path=0.0025"])):
            result = self.cli("trial", "十", *args, "--max-duration", "0.05", "--json", f"short{i}.json")
            self.assertIn(result.returncode, (0, 1), result.stderr)
            record = json.loads((self.tmp / f"short{i}.json").read_text(encoding="utf-8"))
            spec = record["specification"]
            self.assertEqual(spec["version"], 9)
            self.assertEqual(spec["trial"]["miss_min_path_m"], 0.0025)
            self.assertEqual(spec["force_law"]["acceptance"]["miss_min_path_m"], 0.0025)
            specs.append(spec)
        self.assertEqual(specs[0], specs[1])
        self.assertEqual(run_ok(["trial", "--spec", "short0.json", "--check"], self.tmp).returncode, 0)
        cg.check_trial_record(str(self.tmp / "short0.json"))
        acceptance = cg.StrokeAcceptance(**specs[0]["force_law"]["acceptance"])
        self.assertEqual(acceptance.miss_min_path_m, 0.0025)

    def test_trial_miss_min_path_out_of_range_or_not_a_number_is_one_error(self):
        # Metres: 1 (a user thinking in millimetres) is 1 m, past the range [0, 0.1] m.
        for value in ("0.1000001", "-0.001", "1", "nan", "inf", "1e400", "", "1mm", "0x1", "-"):
            with self.subTest(value=value):
                self.assert_one_error(self.cli("trial", "十", "--miss-min-path", value, "--check"), 2,
                                      "--miss-min-path")
        self.assert_one_error(self.cli("trial", "十", "--miss-min-path", "0.001", "--miss-min-path", "0.002",
                                       "--check"), 2, "--miss-min-path")

    def test_trial_miss_min_path_misspelt_is_named_with_the_right_name(self):
        for spelt in ("--miss-min-path-m", "--miss_min_path", "--miss-min-paht"):
            with self.subTest(spelt=spelt):
                line = self.assert_one_error(self.cli("trial", "十", spelt, "0.001", "--check"), 2, spelt)
                self.assertIn("did you mean '--miss-min-path'", line)

    def test_schema_and_help_state_the_range_and_unit_of_miss_min_path(self):
        schema = json.loads(run_ok(["schema", "specification"], self.tmp).stdout)
        text = json.dumps(schema)
        self.assertIn("miss_min_path_m", text)

        def find(node):
            if isinstance(node, dict):
                if "miss_min_path_m" in node.get("properties", {}):
                    return node["properties"]["miss_min_path_m"]
                for value in node.values():
                    got = find(value)
                    if got is not None:
                        return got
            elif isinstance(node, list):
                for value in node:
                    got = find(value)
                    if got is not None:
                        return got
            return None
        field = find(schema)
        self.assertEqual((field.get("minimum"), field.get("maximum"), field.get("default")), (0, 0.1, 0.001))
        help_line = next(line for line in run_ok(["trial", "--help"], self.tmp).stdout.decode().splitlines()
                         if "--miss-min-path" in line)
        self.assertIn("[m]", help_line)
        self.assertIn("(default: 0.001)", help_line)

    def test_protocol_quiz_acceptance_takes_the_range_of_miss_min_path(self):
        def protocol(value):
            quiz = {"acceptance": {"miss_min_path_m": value, "assist_after_misses": 2}}
            return {"name": "m", "conditions": [{"name": "q", "mode": "quiz", "quiz": quiz}],
                    "test": {"characters": ["十"], "conditions": ["q"], "repetitions": 1},
                    "trial": {"max_duration_s": 60}}
        pointer = "/conditions/0/quiz/acceptance/miss_min_path_m"
        for value, ok in ((0, True), (0.1, True), (-0.001, False), (0.5, False), (None, False), ("0.001", False)):
            with self.subTest(value=value):
                (self.tmp / "pq.json").write_text(json.dumps(protocol(value)), encoding="utf-8")
                result = self.cli("session", "plan", "pq.json", "--subjects", "1")
                if ok:
                    self.assertEqual(result.returncode, 0, result.stderr)
                else:
                    self.assert_one_error(result, 2, "pq.json", pointer)

    def test_record_miss_min_path_at_its_bounds_and_in_any_spelling_is_read(self):
        record = json.dumps(self.off_trials()[1], ensure_ascii=False)
        for spelt in ("0", "-0", "0.1", "1E-3", "0.0010"):
            with self.subTest(spelt=spelt):
                text = record.replace('"miss_min_path_m": 0.001', f'"miss_min_path_m": {spelt}')
                self.assertEqual(text.count(f'"miss_min_path_m": {spelt}'), 2)
                (self.tmp / "spelt.json").write_text(text, encoding="utf-8")
                result = self.cli("trial", "--spec", "spelt.json", "--check")
                self.assertEqual(result.returncode, 0, result.stderr)
                cg.check_trial_record(str(self.tmp / "spelt.json"))

    def test_trial_spec_takes_no_miss_min_path_option_beside_it(self):
        # cli.md: with --spec "only --json, --csv, --svg, --teacher (a replay's) and --data/--store go with it
        # (another is a usage error naming it)".
        self.off_trials()
        self.assert_one_error(self.cli("trial", "--spec", "a.json", "--miss-min-path", "0", "--json", "s.json"), 2,
                              "--miss-min-path")
        self.assertFalse((self.tmp / "s.json").exists())

    # ---- calligraphy trial: a writer who never reaches the start ------------------------------------
    @classmethod
    def off_trials(cls):
        if not hasattr(cls, "_off"):
            d = cls.tmp
            a = run(["trial", "十", *OFF_WRITER, "--json", "a.json", "--csv", "a.csv"], d)
            b = run(["trial", "十", *OFF_WRITER, "--miss-min-path", "0", "--json", "b.json", "--csv", "b.csv"], d)
            cls._off = (a, json.loads((d / "a.json").read_text(encoding="utf-8")),
                        b, json.loads((d / "b.json").read_text(encoding="utf-8")))
        return cls._off

    def test_trial_credits_a_writer_who_never_reaches_the_start(self):
        result, record, _, _ = self.off_trials()
        self.assertEqual(result.returncode, 0, result.stderr)
        self.assertEqual(record["end_reason"], "completed")
        self.assertEqual(record["strokes_assisted"], 2)
        self.assertEqual(record["strokes_completed"], 0)
        self.assertEqual([(s["assisted"], s["completed"], s["attempts"]) for s in record["renderer_strokes"]],
                         [(True, False, 0), (True, False, 0)], "no attempt in WS, credited all the same")
        spec = record["specification"]
        self.assertEqual(spec["version"], 9)
        self.assertEqual((spec["trial"]["miss_min_path_m"], spec["force_law"]["acceptance"]["miss_min_path_m"]),
                         (0.001, 0.001))
        self.assertRegex(result.stdout.decode(), r"strokes assisted\s+2")

    def test_trial_with_miss_min_path_zero_gives_that_writer_no_credit(self):
        _, _, result, record = self.off_trials()
        self.assertNotEqual(record["end_reason"], "completed")
        self.assertEqual(record["strokes_assisted"], 0)
        self.assertFalse(any(s["assisted"] for s in record["renderer_strokes"]))
        spec = record["specification"]
        self.assertEqual((spec["trial"]["miss_min_path_m"], spec["force_law"]["acceptance"]["miss_min_path_m"]),
                         (0.0, 0.0))
        self.assertNotEqual(result.returncode, 0, "a trial that ended early exits 1")

    def test_trial_csv_scored_gives_the_trial_s_credits(self):
        _, a, _, b = self.off_trials()
        scored = self.cli_score_file("a.csv", 2)
        self.assertEqual(self.assisted(scored), [s["assisted"] for s in a["renderer_strokes"]])
        self.assertEqual(scored["strokes_assisted"], a["strokes_assisted"])
        for record, trace in ((a, "a.csv"), (b, "b.csv")):
            with self.subTest(trace=trace):
                acceptance = cg.StrokeAcceptance(**record["specification"]["force_law"]["acceptance"])
                python = cg.score(str(self.tmp / trace), "十", acceptance=acceptance)
                self.assertEqual(python["strokes_assisted"], record["strokes_assisted"])
                self.assertEqual(self.assisted(python), [s["assisted"] for s in record["renderer_strokes"]])

    def cli_score_file(self, name, assist):
        out = run_ok(["score", name, "--character", "十", "--json", "-", "--assist-after-misses", str(assist)],
                     self.tmp)
        return json.loads(out.stdout)

    def test_trial_rerun_of_its_record_gives_the_same_credits(self):
        self.off_trials()
        again = self.cli("trial", "--spec", "a.json", "--json", "a2.json", "--csv", "a2.csv")
        self.assertEqual(again.returncode, 0, again.stderr)
        self.assertEqual(again.stderr, b"", "a version-8 record re-run as it was says nothing")
        a2 = json.loads((self.tmp / "a2.json").read_text(encoding="utf-8"))
        self.assertEqual(a2["renderer_strokes"], self.off_trials()[1]["renderer_strokes"])
        self.assertEqual((self.tmp / "a2.csv").read_bytes(), (self.tmp / "a.csv").read_bytes())

    # ---- records edited --------------------------------------------------------------------------------
    def edited(self, name, change, source=1):
        record = json.loads(json.dumps(self.off_trials()[source]))
        change(record)
        (self.tmp / name).write_text(json.dumps(record, ensure_ascii=False), encoding="utf-8")
        return name

    @staticmethod
    def set_at(record, pointer, value):
        *parents, key = pointer.strip("/").split("/")
        node = record
        for part in parents:
            node = node[part]
        if value is KeyError:
            node.pop(key)
        else:
            node[key] = value

    def test_record_miss_min_path_bad_value_is_refused_at_its_pointer(self):
        cases = [(TRIAL_POINTER, v) for v in (None, -0.001, 0.5, 1e300, "0.001", True, [0.001])]
        cases += [(LAW_POINTER, v) for v in (None, -0.001, 0.5, "0.001")]
        for pointer, value in cases:
            with self.subTest(pointer=pointer, value=value):
                name = self.edited("bad.json", lambda r, p=pointer, v=value: self.set_at(r, p, v))
                self.assert_one_error(self.cli("trial", "--spec", name, "--check"), 2, "bad.json", pointer)
                with self.assertRaises(cg.DataError) as caught:
                    cg.check_trial_record(str(self.tmp / name))
                self.assertIn(pointer, str(caught.exception))

    def test_record_miss_min_path_differing_in_its_two_places_is_refused(self):
        name = self.edited("differ.json", lambda r: self.set_at(r, TRIAL_POINTER, 0.002))
        line = self.assert_one_error(self.cli("trial", "--spec", name, "--json", "differ-out.json"), 2, TRIAL_POINTER)
        self.assertIn(LAW_POINTER, line, "the error names the force law's value and pointer")
        self.assertFalse((self.tmp / "differ-out.json").exists())

    def test_record_edited_to_miss_min_path_zero_runs_with_it_and_says_it_differs(self):
        def change(r):
            self.set_at(r, TRIAL_POINTER, 0)
            self.set_at(r, LAW_POINTER, 0)
        name = self.edited("zero.json", change)
        result = self.cli("trial", "--spec", name, "--json", "zero-out.json")
        out = json.loads((self.tmp / "zero-out.json").read_text(encoding="utf-8"))
        self.assertEqual(out["strokes_assisted"], 0)
        self.assertEqual(out["specification"]["trial"]["miss_min_path_m"], 0)
        warning = [line for line in error_lines(result) if "differs" in line]
        self.assertEqual(len(warning), 1, error_lines(result))
        self.assertIn("strokes_assisted recorded 2, now 0", warning[0])

    def test_record_of_version_7_runs_with_a_lift_in_ws_only_and_says_so(self):
        name = self.edited("v7.json", lambda r: r["specification"].__setitem__("version", 7))
        result = self.cli("trial", "--spec", name, "--json", "v7out.json")
        self.assertIn(result.returncode, (0, 1), result.stderr)
        lines = error_lines(result)
        notes = [line for line in lines if "miss_min_path_m" in line]
        self.assertTrue(notes, lines)
        for line in notes:
            self.assertIn("note", line)
            self.assertIn("0.001 in the record", line)
            self.assertIn("version 7", line)
            self.assertIn("it takes 0", line)
        self.assertTrue(any(LAW_POINTER in line for line in notes), notes)
        self.assertTrue(any("strokes_assisted recorded 2, now 0" in line for line in lines), lines)
        out = json.loads((self.tmp / "v7out.json").read_text(encoding="utf-8"))
        self.assertEqual(out["strokes_assisted"], 0)
        self.assertEqual(out["specification"]["force_law"]["acceptance"]["miss_min_path_m"], 0)
        self.assertEqual(out["specification"]["trial"]["miss_min_path_m"], 0)
        self.assertEqual(out["specification"]["version"], 9)

    def test_record_of_version_7_without_the_field_takes_zero_and_says_so(self):
        def change(r):
            r["specification"]["version"] = 7
            self.set_at(r, TRIAL_POINTER, KeyError)
            self.set_at(r, LAW_POINTER, KeyError)
        name = self.edited("v7missing.json", change)
        result = self.cli("trial", "--spec", name, "--json", "v7m-out.json")
        self.assertIn(result.returncode, (0, 1), result.stderr)
        notes = [line for line in error_lines(result) if "miss_min_path_m" in line]
        self.assertTrue(notes, error_lines(result))
        self.assertTrue(all("not in this earlier version of the record" in n and "it takes 0" in n for n in notes),
                        notes)
        out = json.loads((self.tmp / "v7m-out.json").read_text(encoding="utf-8"))
        self.assertEqual(out["specification"]["force_law"]["acceptance"]["miss_min_path_m"], 0)
        self.assertEqual(out["strokes_assisted"], 0)

    def test_python_rerun_of_a_version_7_record_runs_the_older_rule(self):
        name = self.edited("v7py.json", lambda r: r["specification"].__setitem__("version", 7))
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            again = cg.rerun_trial(str(self.tmp / name))
        self.assertEqual(again.metrics["strokes_assisted"], 0)
        self.assertEqual(again.metrics["specification"]["force_law"]["acceptance"]["miss_min_path_m"], 0)
        self.assertTrue(any(issubclass(w.category, RuntimeWarning) and "strokes_assisted" in str(w.message)
                            for w in caught), [str(w.message) for w in caught])


if __name__ == "__main__":
    unittest.main()
