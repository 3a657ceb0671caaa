#!/usr/bin/env python3
"""Hostile cases written from the documentation alone (docs/cli.md, docs/experiments.md, docs/python.md,
docs/learning-study.md, the commands' `--help` and `calligraphy schema protocol|session`) on the study surfaces:
protocols of every design (between subjects, crossover, mixed) with their phases, item sets, transfer choices
and teachers forged, counted past their ranges and spelt oddly; `session plan` held to the counterbalancing
the documentation states; `session run|resume` on names that climb out of the study folder, a run killed by
SIGKILL and run again, two runs at once, a session.json edited to plan other characters or files, a session
copied in from another study, linked days broken; `session cohort` and `report` writing their sets through
links, immutable files, folders given twice and two runs at once; Python's `calligraphy.study.load`,
`calligraphy.cohort.simulate` and `calligraphy.study_report` with arguments of every wrong kind, conditions
named like R's missing values and outcomes that are constant or all missing. Run by CTest as
`cli_unseen_round10b_tests`.

Each case asserts what the documentation promises: one error line naming the file and the JSON pointer (or
the option), exit 2 for content or usage refused and 1 for damaged data or a failed write, nothing written
outside the folders given, no input replaced, no temporary left, and the plan the documentation's tables
give. CALLIGRAPHY_CLI names the program; the built Python package is found on PYTHONPATH (its cases are
skipped without it). CALLIGRAPHY_SANITIZED=1 takes a small subset.
"""
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

from outsider import CLI, ENV, TIMEOUT_S, error_lines, run

SANITIZED = os.environ.get("CALLIGRAPHY_SANITIZED") == "1"
SHI, REN, KOU = "十", "人", "口"

heavy = unittest.skipIf(SANITIZED, "several runs of the program: left to the Release run")

try:
    import calligraphy as cg
    import calligraphy.study as cg_study
except ImportError:  # pragma: no cover - a build without the Python bindings
    cg = None
    cg_study = None

needs_python = unittest.skipIf(cg is None, "the Python package is not on PYTHONPATH")


def tree(folder):
    """Every path under folder (links not followed) with its kind and, for files, its bytes."""
    out = {}
    for root, dirs, files in os.walk(folder):
        for name in dirs + files:
            p = Path(root) / name
            rel = str(p.relative_to(folder))
            if p.is_symlink():
                out[rel] = ("link", os.readlink(p))
            elif p.is_file():
                out[rel] = ("file", p.read_bytes())
            else:
                out[rel] = ("other", None)
    return out


def tiny(name="tiny", **extra):
    doc = {"name": name, "conditions": [{"name": "v", "mode": "vision"}, {"name": "h", "mode": "haptic"}],
           "test": {"characters": [SHI], "conditions": ["v", "h"], "repetitions": 1},
           "trial": {"max_duration_s": 20}}
    doc.update(extra)
    return doc


def phased(phases, conditions=None, item_sets=None, name="ph"):
    doc = {"name": name,
           "conditions": conditions or [{"name": "v", "mode": "vision"}, {"name": "h", "mode": "haptic"}],
           "phases": phases, "trial": {"max_duration_s": 20}}
    if item_sets is not None:
        doc["item_sets"] = item_sets
    return doc


SETS = [{"name": "s1", "characters": [SHI]}, {"name": "s2", "characters": [REN]}]


def crossover(extra_phases=(), sets=None, conditions=("v", "h")):
    phases = [{"phase": "pre-test", "condition": "v", "sets": ["s1", "s2"]},
              {"phase": "training", "conditions": list(conditions), "assignment": "crossover",
               "sets": ["s1", "s2"], "repetitions": 1},
              {"phase": "post-test", "condition": "v", "sets": ["s1", "s2"]}]
    phases.extend(extra_phases)
    return phased(phases, item_sets=sets if sets is not None else SETS, name="cx")


class Case(unittest.TestCase):
    def setUp(self):
        self.tmp = Path(tempfile.mkdtemp(prefix="unseen10b-"))

    def tearDown(self):
        shutil.rmtree(self.tmp, ignore_errors=True)
        if self.tmp.exists():  # a file a case left immutable (chattr +i): made mutable again, then removed
            for p in self.tmp.rglob("*"):
                if not p.is_symlink() and p.is_file():
                    subprocess.run(["chattr", "-i", str(p)], stderr=subprocess.DEVNULL, stdout=subprocess.DEVNULL)
            shutil.rmtree(self.tmp, ignore_errors=True)

    def write(self, doc, name="p.json"):
        path = self.tmp / name
        path.write_text(doc if isinstance(doc, str) else json.dumps(doc, ensure_ascii=False), encoding="utf-8")
        return path

    def refused(self, result, status, *needles, prefix=": error: "):
        lines = error_lines(result)
        text = "\n".join(lines)
        self.assertEqual(result.returncode, status, text)
        self.assertEqual(len(lines), 1, text)
        self.assertIn(prefix, lines[0], text)
        for needle in needles:
            self.assertIn(needle, lines[0], text)
        self.assertNotIn("Traceback", text)
        return lines[0]

    def plan(self, doc, subjects=1, *more):
        return run(["session", "plan", self.write(doc), "--subjects", subjects, *more], self.tmp)

    def plan_ok(self, doc):
        r = self.plan(doc)
        self.assertEqual(r.returncode, 0, r.stderr)

    def plan_refused(self, doc, pointer, *needles):
        line = self.refused(self.plan(doc), 2, "p.json", pointer, *needles)
        return line

    def plan_json(self, doc, subjects):
        r = self.plan(doc, subjects, "--json")
        self.assertEqual(r.returncode, 0, r.stderr)
        return json.loads(r.stdout)


# --------------------------------------------------------------------------------------------------------
# Protocols, read by `session plan` (nothing runs)
# --------------------------------------------------------------------------------------------------------

class Protocols(Case):
    def test_a_name_that_climbs_out_of_the_study_folder_is_refused(self):
        # The name names the session folders: a slash, dots, spaces, letters of other scripts, more than 64.
        for name in ("../up", "a/b", ".", "..", "", " x", "名字", "x" * 65, "a\nb"):
            with self.subTest(name=name):
                self.plan_refused(tiny(name=name), "/name")
        r = self.plan(tiny(name="x" * 64))
        self.assertEqual(r.returncode, 0, r.stderr)
        # A run of such a protocol makes nothing anywhere.
        before = tree(self.tmp)
        r = run(["session", "run", self.write(tiny(name="../../up"), "q.json"), "--subjects", "1", "--out",
                 "study"], self.tmp)
        self.refused(r, 2, "/name")
        self.assertEqual(set(tree(self.tmp)) - set(before), {"q.json"})

    def test_counts_at_and_past_their_ranges(self):
        conditions = [{"name": f"c{i}", "mode": "vision"} for i in range(27)]
        doc = tiny(conditions=conditions[:26], test={"characters": [SHI], "conditions": ["c0"],
                                                     "repetitions": 1})
        self.plan_ok(doc)
        doc["conditions"] = conditions
        self.plan_refused(doc, "/conditions")
        for count, ok in ((1000, True), (1001, False)):
            # distinct strings (a string is listed once): rows of 7 of 十, 人 and 口
            strings = ["".join((SHI, "人", "口")[(n // 3 ** k) % 3] for k in range(7)) for n in range(count)]
            doc = tiny(test={"characters": strings, "conditions": ["v"], "repetitions": 1})
            if ok:
                self.plan_ok(doc)
            else:
                self.plan_refused(doc, "/test/characters")
        doc = tiny(test={"characters": [SHI * 16], "conditions": ["v"], "repetitions": 1})
        self.plan_ok(doc)
        doc = tiny(test={"characters": [SHI * 17], "conditions": ["v"], "repetitions": 1})
        self.plan_refused(doc, "/test/characters/0")
        doc = tiny(test={"characters": [""], "conditions": ["v"], "repetitions": 1})
        self.plan_refused(doc, "/test/characters/0")
        sets = [{"name": f"s{i}", "characters": [c]} for i, c in enumerate("十人口山大天木中日千小又工土王干三上下")]
        sets += [{"name": f"t{i}", "characters": [c]} for i, c in enumerate("一二八九")]
        sets += [{"name": "u1", "characters": ["了"]}, {"name": "u2", "characters": ["子"]},
                 {"name": "u3", "characters": ["女"]}, {"name": "u4", "characters": ["川"]}]
        self.assertEqual(len(sets), 27)
        self.plan_refused(phased([{"phase": "test", "condition": "v", "sets": ["s0"]}], item_sets=sets),
                          "/item_sets")
        phases = [{"phase": "test", "condition": "v", "characters": [SHI]} for _ in range(21)]
        self.plan_refused(phased(phases), "/phases")

    def test_numbers_spelt_at_and_past_their_bounds(self):
        cases = [
            ('"repetitions": 0', "/test/repetitions"), ('"repetitions": -0', "/test/repetitions"),
            ('"repetitions": 1001', "/test/repetitions"), ('"repetitions": 1.5', "/test/repetitions"),
            ('"repetitions": "1"', "/test/repetitions"), ('"repetitions": 1e999', "/test/repetitions"),
            ('"repetitions": null', "/test/repetitions"),
            ('"repetitions": 18446744073709551617', "/test/repetitions"),
        ]
        for spelling, pointer in cases:
            with self.subTest(spelling=spelling):
                text = json.dumps(tiny(), ensure_ascii=False).replace('"repetitions": 1', spelling)
                self.plan_refused(text, pointer)
        for order, ok in (({"seed": 18446744073709551615}, True), ({"seed": 18446744073709551616}, False),
                          ({"seed": -1}, False), ({"seed": 1.5}, False), ({"seed": "0x10"}, False)):
            with self.subTest(order=order):
                doc = tiny(order=dict(order, conditions="random"))
                if ok:
                    self.plan_ok(doc)
                else:
                    self.plan_refused(doc, "/order/seed")
        for breaks, pointer in (({"every_trials": 100001}, "/breaks/every_trials"),
                                ({"duration_s": 86400.5}, "/breaks/duration_s"),
                                ({"between_blocks_s": -1e-300}, "/breaks/between_blocks_s"),
                                ({"between_blocks_s": 1e308}, "/breaks/between_blocks_s")):
            with self.subTest(breaks=breaks):
                self.plan_refused(tiny(breaks=breaks), pointer)
        self.plan_refused(tiny(trial={"rate_hz": 10000.5}), "/trial/rate_hz")
        line = self.plan_refused(tiny(trial={"rate_hz": 1000, "max_duration_s": 86400}), "/trial/")
        self.assertIn("max_duration_s", line)
        self.assertIn("rate_hz", line)
        # delay_s: [0, 366 days]; -0 is 0.
        day366 = 366 * 86400
        for delay, ok in ((day366, True), (-0.0, True), (day366 + 0.5, False), (1e308, False)):
            with self.subTest(delay=delay):
                doc = phased([{"phase": "test", "condition": "v", "characters": [SHI]},
                              {"phase": "test", "condition": "v", "characters": [SHI], "session": 2,
                               "delay_s": delay}])
                if ok:
                    self.plan_ok(doc)
                else:
                    self.plan_refused(doc, "/phases/1/delay_s")

    def test_sessions_that_skip_go_back_or_pass_twenty(self):
        def doc(*sessions):
            return phased([{"phase": "test", "condition": "v", "characters": [SHI], "session": s,
                            "delay_s": 60 if i else 0} for i, s in enumerate(sessions)])
        self.plan_refused(doc(1, 3), "/phases/1/session")
        self.plan_refused(doc(1, 2, 1), "/phases/2/session")
        self.plan_refused(doc(2), "/phases/0/session")
        self.plan_refused(doc(1, 21), "/phases/1/session")
        self.plan_refused(doc(1, 0), "/phases/1/session")
        self.assertEqual(self.plan(doc(*range(1, 21))).returncode, 0)

    def test_phase_order_and_design_rules(self):
        train = {"phase": "training", "conditions": ["v", "h"], "assignment": "between-subjects",
                 "characters": [SHI, REN]}
        pre = {"phase": "pre-test", "condition": "v", "characters": [SHI, REN]}
        post = {"phase": "post-test", "condition": "v", "characters": [SHI, REN]}
        self.plan_refused(phased([train, pre]), "/phases/1")
        self.plan_refused(phased([pre, post]), "/phases/1")
        self.plan_refused(phased([post, pre, train]), "/phases/0")
        self.plan_refused(phased([pre, train, {"phase": "retention", "condition": "v", "characters": [SHI],
                                               "session": 2}]), "/phases/2")
        self.plan_refused(phased([pre, train, {"phase": "retention", "condition": "v", "characters": [KOU],
                                               "session": 2, "delay_s": 86400}]), "/phases/2")
        self.plan_refused(phased([pre, train, {"phase": "transfer", "condition": "v", "characters": [SHI]}]),
                          "/phases/2")
        one = dict(train, conditions=["v"])
        self.plan_refused(phased([pre, one]), "/phases/1")
        self.plan_ok(phased([pre, train, post]))

    def test_a_phases_keys_that_conflict_or_name_nothing(self):
        base = {"phase": "test", "condition": "v", "characters": [SHI]}
        cases = [
            (dict(base, conditions=["v"]), "/phases/0"),
            ({"phase": "test", "characters": [SHI]}, "/phases/0"),
            (dict(base, sets=["s1"]), "/phases/0"),
            ({"phase": "test", "condition": "v"}, "/phases/0"),
            ({"phase": "test", "condition": "v", "sets": ["s1", "s1"]}, "/phases/0/sets/1"),
            ({"phase": "test", "condition": "v", "sets": ["nope"]}, "/phases/0/sets/0"),
            (dict(base, condition="nope"), "/phases/0/condition"),
            ({"phase": "test", "conditions": [], "characters": [SHI]}, "/phases/0/conditions"),
            (dict(base, sets=None), "/phases/0/sets"),
            (dict(base, repetition=2), "/phases/0/repetition"),
            (dict(base, phase="Test"), "/phases/0/phase"),
            (dict(base, assignment="crossover "), "/phases/0/assignment"),
        ]
        for phase, pointer in cases:
            with self.subTest(phase=phase):
                self.plan_refused(phased([phase], item_sets=SETS), pointer)

    def test_item_sets_forged(self):
        use = [{"phase": "test", "condition": "v", "sets": ["s1"]}]
        cases = [
            ([SETS[0], dict(SETS[1], name="s1")], "/item_sets/1/name"),
            ([SETS[0], {"name": "s2", "characters": [SHI]}], "/item_sets/1/characters/0"),
            ([SETS[0], dict(SETS[1], transfer_of="s2")], "/item_sets/1/transfer_of"),
            ([SETS[0], dict(SETS[1], transfer_of="nope")], "/item_sets/1/transfer_of"),
            ([SETS[0], dict(SETS[1], transfer_of="s1"), {"name": "s3", "characters": [KOU], "transfer_of": "s2"}],
             "/item_sets/2/transfer_of"),
            ([{"name": "s 1", "characters": [SHI]}], "/item_sets/0/name"),
            ([{"name": "s1", "characters": []}], "/item_sets/0/characters"),
            ([{"name": "s1"}], "/item_sets/0"),
            ([{"name": "s1", "characters": [SHI], "extra": 1}], "/item_sets/0/extra"),
            ([], "/item_sets"),
        ]
        for sets, pointer in cases:
            with self.subTest(sets=sets):
                self.plan_refused(phased(use, item_sets=sets), pointer)

    def test_crossover_shapes_the_documentation_refuses(self):
        self.plan_ok(crossover())
        three = crossover(conditions=("v", "h", "a"))
        three["conditions"].append({"name": "a", "mode": "error-amplification"})
        self.plan_refused(three, "/phases/1")
        one = crossover(conditions=("v",))
        self.plan_refused(one, "/phases/1")
        prac = crossover()
        prac["phases"][1]["phase"] = "practice"
        self.plan_refused(prac, "/phases/1")
        twice = crossover(extra_phases=[{"phase": "training", "conditions": ["v", "h"],
                                         "assignment": "crossover", "sets": ["s3", "s4"]}],
                          sets=SETS + [{"name": "s3", "characters": [KOU]}, {"name": "s4", "characters": ["山"]}])
        self.plan_refused(twice, "/phases/3/assignment")
        transfer = crossover(sets=[SETS[0], dict(SETS[1], transfer_of="s1")])
        self.plan_refused(transfer, "/phases/1")
        again = crossover(extra_phases=[{"phase": "training", "condition": "h", "sets": ["s2"]}])
        self.plan_refused(again, "/phases/3/sets/0", "s2")
        by_char = crossover(extra_phases=[{"phase": "training", "condition": "h", "characters": [KOU, SHI]}])
        self.plan_refused(by_char, "/phases/3/characters/1")
        stray = crossover()
        stray["phases"][2] = {"phase": "post-test", "condition": "v", "characters": [SHI, "大"]}
        self.plan_refused(stray, "/phases/2/characters/1", "大")
        both = crossover()
        both["phases"][2] = {"phase": "post-test", "condition": "v", "characters": [SHI + REN]}
        self.plan_refused(both, "/phases/2/characters/0")

    def test_transfer_choices_forged(self):
        pre = {"phase": "pre-test", "condition": "v", "characters": [SHI, REN, KOU]}
        train = {"phase": "training", "condition": "h", "characters": [SHI, REN, KOU]}

        def doc(choice):
            return phased([pre, train, {"phase": "transfer", "condition": "v", "characters": choice}])
        cases = [({}, "/phases/2/characters"), ({"choose": 2}, "/phases/2/characters"),
                 ({"from": ["木", "中"]}, "/phases/2/characters"),
                 ({"choose": 0, "from": ["木"]}, "/phases/2/characters/choose"),
                 ({"choose": 1001, "from": ["木"]}, "/phases/2/characters/choose"),
                 ({"choose": "1", "from": ["木"]}, "/phases/2/characters/choose"),
                 ({"choose": 2, "from": []}, "/phases/2/characters/from"),
                 ({"choose": 5, "from": ["木", "中", "大"]}, "/phases/2"),
                 ({"choose": 1, "from": ["木中"]}, "/phases/2/characters/from/0"),
                 ({"choose": 1, "from": [SHI]}, "/phases/2/characters/from/0")]
        for choice, pointer in cases:
            with self.subTest(choice=choice):
                self.plan_refused(doc(choice), pointer)
        self.plan_ok(doc({"choose": 1, "from": ["大", "木"]}))

    def test_documents_that_are_not_protocols(self):
        for text in ("", "\ufeff", "[]", '"x"', "null", "1", json.dumps(tiny())[:40], "{} {}",
                     json.dumps(tiny()) + "x"):
            with self.subTest(text=text):
                self.refused(self.plan(text), 2, "p.json")
        twice = json.dumps(tiny(), ensure_ascii=False).replace('"name": "tiny"', '"name": "tiny", "name": "tiny"')
        self.refused(self.plan(twice), 2, "p.json", "/name")
        for fmt, pointer in (({"format": "calligraphy-study-protocol "}, "/format"), ({"version": 2}, "/version"),
                             ({"version": "1"}, "/version"), ({"version": 0}, "/version")):
            with self.subTest(fmt=fmt):
                self.plan_refused(tiny(**fmt), pointer)
        # A folder, a missing file and a FIFO no one writes: status 1, no wait.
        (self.tmp / "dir.json").mkdir()
        os.mkfifo(self.tmp / "fifo.json")
        for name in ("dir.json", "missing.json", "fifo.json"):
            with self.subTest(name=name):
                r = run(["session", "plan", name, "--subjects", "1"], self.tmp, timeout=20)
                self.refused(r, 1, name)

    def test_subject_counts_and_prefixes_of_plan(self):
        p = self.write(tiny())
        for value in ("0", "-1", "1e3", "0x10", " 2", "", "1001"):
            with self.subTest(value=value):
                r = run(["session", "plan", p, "--subjects", value], self.tmp)
                self.refused(r, 2, "--subjects")
        for prefix in ("../x", "a/b", "", "x y"):
            with self.subTest(prefix=prefix):
                r = run(["session", "plan", p, "--subjects", "1", "--subject", prefix], self.tmp)
                self.refused(r, 2, "--subject")


# --------------------------------------------------------------------------------------------------------
# The plan holds to the documentation's tables
# --------------------------------------------------------------------------------------------------------

class Plans(Case):
    def test_crossover_follows_the_documented_table(self):
        d = self.plan_json(crossover(), 5)
        got = [(s["sequence"], s["set_pairing"]) for s in d["subjects"]]
        self.assertEqual(got, [("AB", "A:s1 B:s2"), ("BA", "A:s1 B:s2"), ("AB", "A:s2 B:s1"),
                               ("BA", "A:s2 B:s1"), ("AB", "A:s1 B:s2")])
        self.assertEqual(d["balance"]["square"], 4)
        self.assertFalse(d["balance"]["filled"])
        self.assertIn("N=5", d["balance"]["warning"])
        training = d["subjects"][1]["sessions"][0]["phases"][1]
        self.assertEqual([b["condition"] for b in training["blocks"]], ["h", "v"])
        self.assertEqual([b["set"] for b in training["blocks"]], ["s2", "s1"])
        d4 = self.plan_json(crossover(), 4)
        self.assertEqual(d4["balance"]["warning"], "")
        self.assertTrue(d4["balance"]["filled"])

    def test_a_mixed_design_gives_the_documented_cells(self):
        doc = crossover()
        doc["phases"].insert(0, {"phase": "practice", "conditions": ["v", "h"], "assignment": "between-subjects",
                                 "characters": [KOU]})
        d = self.plan_json(doc, 8)
        # docs/experiments.md: subjects 1 to 8 get A AB 0, B BA 0, A BA 0, B AB 1, A AB 1, B BA 1, A BA 1, B AB 0.
        rot = {0: "A:s1 B:s2", 1: "A:s2 B:s1"}
        want = [("v", "AB", 0), ("h", "BA", 0), ("v", "BA", 0), ("h", "AB", 1), ("v", "AB", 1), ("h", "BA", 1),
                ("v", "BA", 1), ("h", "AB", 0)]
        got = [(s["group"], s["sequence"], s["set_pairing"]) for s in d["subjects"]]
        self.assertEqual(got, [(g, q, rot[r]) for g, q, r in want])
        self.assertEqual(d["balance"]["square"], 8)

    def test_a_three_condition_crossover_repeats_every_eighteen(self):
        doc = crossover(conditions=("v", "h", "a"),
                        sets=SETS + [{"name": "s3", "characters": [KOU]}])
        doc["conditions"].append({"name": "a", "mode": "error-amplification"})
        for p in doc["phases"]:
            p["sets"] = ["s1", "s2", "s3"]
        d = self.plan_json(doc, 19)
        self.assertEqual(d["balance"]["square"], 18)
        seqs = [s["sequence"] for s in d["subjects"]]
        self.assertEqual(len(set(seqs[:6])), 6, seqs)
        cells = [(s["sequence"], s["set_pairing"]) for s in d["subjects"]]
        self.assertEqual(len(set(cells[:18])), 18, cells)
        self.assertEqual(cells[18], cells[0])
        # Each condition in each period equally often over every six subjects.
        for period in range(3):
            self.assertEqual(sorted(s[period] for s in seqs[:6]), ["A", "A", "B", "B", "C", "C"])


# --------------------------------------------------------------------------------------------------------
# session run | resume
# --------------------------------------------------------------------------------------------------------

def sessions(study):
    return sorted(p.parent for p in Path(study).glob("*/*/session.json"))


def strip_tmp(study):
    return [p for p in Path(study).rglob("*") if ".tmp" in p.name or p.name.endswith(".part")
            or ".partial." in p.name]


class Runs(Case):
    def test_subject_ids_and_numbers_that_climb_out_or_break_the_square(self):
        p = self.write(tiny())
        before = set(tree(self.tmp))
        for subject in ("../x", "a/b", "", "x y", ".", "..", "S\x01"):
            with self.subTest(subject=subject):
                r = run(["session", "run", p, "--subject", subject, "--out", "study"], self.tmp)
                self.refused(r, 2, "--subject")
        cx = self.write(crossover(), "cx.json")
        before = set(tree(self.tmp))
        for number in ("0", "-1", "18446744073709551616", "1e3", "0x1"):
            with self.subTest(number=number):
                r = run(["session", "run", cx, "--subject", "P", "--subject-number", number, "--out", "study"],
                        self.tmp)
                self.refused(r, 2)
        r = run(["session", "run", cx, "--subject", "P0", "--out", "study"], self.tmp)
        self.refused(r, 2, "P0")
        for value in ("1001", "-1", "2.0"):
            with self.subTest(subjects=value):
                r = run(["session", "run", p, "--subjects", value, "--out", "study"], self.tmp)
                self.refused(r, 2, "--subjects")
        self.assertEqual(set(tree(self.tmp)), before)

    @heavy
    def test_new_subjects_go_on_from_the_highest_number(self):
        p = self.write(tiny())
        self.assertEqual(run(["session", "run", p, "--subjects", "1", "--out", "st"], self.tmp).returncode, 0)
        snap = tree(self.tmp / "st")
        r = run(["session", "run", p, "--subjects", "1", "--out", "st"], self.tmp)
        self.refused(r, 2, "S01", "--new-subjects")
        self.assertEqual(tree(self.tmp / "st"), snap)
        r = run(["session", "run", p, "--subject", "S01", "--new-subjects", "--out", "st"], self.tmp)
        self.refused(r, 2, "S01")
        r = run(["session", "run", p, "--subjects", "1", "--new-subjects", "--out", "st"], self.tmp)
        self.assertEqual(r.returncode, 0, r.stderr)
        made = [json.loads((s / "session.json").read_text()) for s in sessions(self.tmp / "st")]
        self.assertEqual(sorted((m["subject"]["id"], m["subject"]["number"]) for m in made), [("S01", 1), ("S02", 2)])

    @heavy
    def test_two_runs_at_once_leave_one_series(self):
        p = self.write(tiny())
        procs = [subprocess.Popen([CLI, "session", "run", str(p), "--subjects", "2", "--out", "st"], cwd=self.tmp,
                                  stdout=subprocess.PIPE, stderr=subprocess.PIPE, env=ENV) for _ in range(2)]
        results = [(pr.wait(timeout=TIMEOUT_S), pr.stderr.read().decode()) for pr in procs]
        statuses = sorted(s for s, _ in results)
        self.assertEqual(statuses[0], 0, results)
        self.assertIn(statuses[1], (1, 2), results)
        loser = [e for s, e in results if s != 0][0]
        self.assertEqual(len(loser.strip().splitlines()), 1, loser)
        self.assertEqual(len(sessions(self.tmp / "st")), 2)
        (self.tmp / "t").mkdir()
        r = run(["report", "st", "--csv", "t"], self.tmp)
        self.assertEqual(r.returncode, 0, r.stderr)
        rows = (self.tmp / "t" / "trials.csv").read_text().splitlines()[1:]
        self.assertEqual(len(rows), 4)

    @heavy
    def test_kill_9_then_run_again_then_resume(self):
        doc = tiny(test={"characters": [SHI, REN], "conditions": ["v", "h"], "repetitions": 2})
        p = self.write(doc)
        pr = subprocess.Popen([CLI, "session", "run", str(p), "--subject", "S01", "--out", "st"], cwd=self.tmp,
                              stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, env=ENV)
        deadline = time.monotonic() + TIMEOUT_S
        while time.monotonic() < deadline and pr.poll() is None:
            if len(list((self.tmp / "st").glob("S01/tiny-*/trials/*.json"))) >= 2:
                break
            time.sleep(0.005)
        if pr.poll() is not None:
            self.skipTest("the run ended before it could be killed")
        pr.send_signal(signal.SIGKILL)
        pr.wait()
        folders = sessions(self.tmp / "st")
        self.assertEqual(len(folders), 1)
        saved = {q.name: q.read_bytes() for q in (folders[0] / "trials").glob("*.json")}
        r = run(["session", "run", p, "--subject", "S01", "--out", "st"], self.tmp)
        self.assertIn(r.returncode, (1, 2), r.stderr)
        self.assertEqual(len(error_lines(r)), 1, r.stderr)
        self.assertIn("session resume", error_lines(r)[0])
        r = run(["session", "resume", folders[0]], self.tmp)
        self.assertEqual(r.returncode, 0, r.stderr)
        records = sorted((folders[0] / "trials").glob("*.json"))
        self.assertEqual(len(records), 8)
        for name, data in saved.items():
            self.assertEqual((folders[0] / "trials" / name).read_bytes(), data, name)
        self.assertEqual(strip_tmp(self.tmp / "st"), [])

    def _one_session(self, doc=None, subject="S01"):
        p = self.write(doc or tiny(test={"characters": [SHI, REN], "conditions": ["v"], "repetitions": 1}))
        r = run(["session", "run", p, "--subject", subject, "--out", "st"], self.tmp)
        self.assertEqual(r.returncode, 0, r.stderr)
        folder = sessions(self.tmp / "st")[0]
        return p, folder

    def _drop_last_trial(self, folder):
        last = sorted((folder / "trials").glob("*.json"))[-1]
        stem = last.name[:-len(".json")]
        for q in (folder / "trials").glob(stem + ".*"):
            q.unlink()
        return stem

    def _edit_manifest(self, folder, edit):
        path = folder / "session.json"
        doc = json.loads(path.read_text(encoding="utf-8"))
        edit(doc)
        path.write_text(json.dumps(doc, ensure_ascii=False, indent=1), encoding="utf-8")

    def test_resume_of_a_plan_edited_to_write_elsewhere_or_otherwise(self):
        _, folder = self._one_session()
        stem = self._drop_last_trial(folder)
        keep = folder.parent.parent.parent
        before = {k for k in tree(keep)}

        def outward(doc):
            doc["plan"][-1]["file"] = "../../../../escaped"
        self._edit_manifest(folder, outward)
        r = run(["session", "resume", folder], self.tmp)
        self.refused(r, 2, "session.json", "/plan/1/file")
        self.assertEqual({k for k in tree(keep)} - before, set())
        self.assertFalse(list(self.tmp.rglob("escaped*")))

        def other_characters(doc):
            doc["plan"][-1]["file"] = stem
            doc["plan"][-1]["characters"] = "永"
        self._edit_manifest(folder, other_characters)
        r = run(["session", "resume", folder], self.tmp)
        self.refused(r, 2, "session.json", "/plan/1")
        self.assertFalse(list((folder / "trials").glob("*U6C38*")))

        def other_condition(doc):
            doc["plan"][-1]["characters"] = REN
            doc["plan"][-1]["condition"] = "nope"
        self._edit_manifest(folder, other_condition)
        r = run(["session", "resume", folder], self.tmp)
        self.refused(r, 2, "session.json", "/plan/1/condition")

    @heavy
    def test_a_protocol_copy_edited_in_session_json(self):
        _, folder = self._one_session()
        self._drop_last_trial(folder)
        path = folder / "session.json"
        text = path.read_text(encoding="utf-8")
        doc = json.loads(text)
        # The protocol's text kept in session.json, edited to a second repetition; its SHA-256 left as it was.
        key = [k for k, v in doc["protocol"].items() if isinstance(v, str) and '"repetitions"' in v]
        if not key:
            self.skipTest("session.json keeps no protocol text under /protocol")
        doc["protocol"][key[0]] = doc["protocol"][key[0]].replace('"repetitions": 1', '"repetitions": 2')
        path.write_text(json.dumps(doc, ensure_ascii=False), encoding="utf-8")
        r = run(["session", "resume", folder], self.tmp)
        self.assertIn(r.returncode, (1, 2), r.stderr)
        self.assertEqual(len(error_lines(r)), 1, r.stderr)
        self.assertIn("session.json", error_lines(r)[0])
        self.assertEqual(len(list((folder / "trials").glob("*.json"))), 1)

    @heavy
    def test_a_session_copied_in_from_another_study(self):
        p, folder = self._one_session()
        other = self.tmp / "other"
        r = run(["session", "run", p, "--subject", "S01", "--out", other], self.tmp)
        self.assertEqual(r.returncode, 0, r.stderr)
        # Study st now also holds other's S01 session, under S01 (the same subject and protocol).
        theirs = sessions(other)[0]
        copy = folder.parent / (theirs.name + "x")
        shutil.copytree(theirs, copy)
        (self.tmp / "t").mkdir()
        r = run(["report", "st", "--csv", "t"], self.tmp)
        self.refused(r, 1, "session.json")
        self.assertFalse((self.tmp / "t" / "trials.csv").exists())
        self._drop_last_trial(copy)
        r = run(["session", "resume", copy], self.tmp)
        self.refused(r, 1, "/study_id")
        with self.assertRaises(cg.Error if cg else Exception):
            if cg is None:
                raise RuntimeError("no Python")
            cg_study.load(str(self.tmp / "st"))

    @heavy
    def test_linked_days_broken(self):
        doc = phased([{"phase": "test", "condition": "v", "characters": [SHI]},
                      {"phase": "test", "condition": "v", "characters": [SHI, REN], "session": 2, "delay_s": 60}],
                     name="days")
        p = self.write(doc)
        r = run(["session", "run", p, "--subject", "S01", "--out", "st"], self.tmp)
        self.assertEqual(r.returncode, 0, r.stderr)
        day1, day2 = sessions(self.tmp / "st")
        if json.loads((day1 / "session.json").read_text()).get("session_number", 1) == 2:
            day1, day2 = day2, day1
        # Day 1's record removed: day 2 already follows it, so it is not resumed.
        rec1 = sorted((day1 / "trials").glob("*.json"))[0]
        saved = rec1.read_bytes()
        self._drop_last_trial(day1)
        r = run(["session", "resume", day1], self.tmp)
        self.refused(r, 1, day2.name)
        rec1.write_bytes(saved)
        # Day 1's session.json rewritten with the same content in other bytes: day 2 no longer follows it.
        self._drop_last_trial(day2)
        text = (day1 / "session.json").read_text(encoding="utf-8")
        (day1 / "session.json").write_text(text + "\n", encoding="utf-8")
        r = run(["session", "resume", day2], self.tmp)
        self.refused(r, 1, "session.json")
        self.assertEqual(len(list((day2 / "trials").glob("*.json"))), 1)


# --------------------------------------------------------------------------------------------------------
# session cohort and report: the sets they write
# --------------------------------------------------------------------------------------------------------

class Shared:
    folder = None

    @classmethod
    def study(cls):
        if cls.folder is None:
            cls.folder = Path(tempfile.mkdtemp(prefix="unseen10b-study-"))
            (cls.folder / "p.json").write_text(json.dumps(tiny(), ensure_ascii=False), encoding="utf-8")
            r = run(["session", "run", "p.json", "--subjects", "2", "--out", "st"], cls.folder)
            assert r.returncode == 0, r.stderr
        return cls.folder


def tearDownModule():
    if Shared.folder is not None:
        shutil.rmtree(Shared.folder, ignore_errors=True)


class Sets(Case):
    def copy_study(self):
        shutil.copytree(Shared.study() / "st", self.tmp / "st")
        shutil.copy(Shared.study() / "p.json", self.tmp / "p.json")
        return self.tmp / "st"

    def test_cohort_counts_and_prefixes(self):
        p = self.write(tiny())
        (self.tmp / "t").mkdir()
        for option, value in (("--subjects", "0"), ("--subjects", "100001"), ("--subjects", "-1"),
                              ("--subjects", "1e2"), ("--jobs", "0"), ("--jobs", "1025"), ("--jobs", "1.0"),
                              ("--subject", "../x"), ("--subject", ""), ("--writer-profile", "novice,skilled")):
            with self.subTest(option=option, value=value):
                args = ["session", "cohort", p, "--subjects", "1", "--csv", "t"]
                if option == "--subjects":
                    args[4] = value
                else:
                    args += [option, value]
                self.refused(run(args, self.tmp), 2, option)
        self.assertEqual(list((self.tmp / "t").iterdir()), [])

    def test_cohort_refuses_a_replay_condition_and_writes_nothing(self):
        doc = tiny(conditions=[{"name": "v", "mode": "vision"}, {"name": "h", "mode": "replay"}])
        (self.tmp / "t").mkdir()
        r = run(["session", "cohort", self.write(doc), "--subjects", "1", "--csv", "t"], self.tmp)
        self.refused(r, 2, "replay")
        self.assertEqual(list((self.tmp / "t").iterdir()), [])

    def test_cohort_names_the_threads_it_ran(self):
        # One subject is simulated on one thread whatever --jobs asks for; the summary says so.
        (self.tmp / "t").mkdir()
        r = run(["session", "cohort", self.write(tiny()), "--subjects", "1", "--jobs", "4", "--csv", "t"], self.tmp)
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertIn(b" on 1 thread in ", r.stdout)

    @heavy
    def test_two_cohorts_into_one_folder_at_once_leave_one_pair(self):
        p = self.write(tiny())
        (self.tmp / "t").mkdir()
        for _ in range(2):
            procs = [subprocess.Popen([CLI, "session", "cohort", str(p), "--subjects", "2", "--subject", prefix,
                                       "--csv", "t", "--jobs", "1"], cwd=self.tmp, stdout=subprocess.PIPE,
                                      stderr=subprocess.PIPE, env=ENV) for prefix in ("A", "B")]
            for pr in procs:
                self.assertIn(pr.wait(timeout=TIMEOUT_S), (0, 1))
            trials = (self.tmp / "t" / "trials.csv").read_text().splitlines()[1:]
            strokes = (self.tmp / "t" / "strokes.csv").read_text().splitlines()[1:]
            self.assertEqual({row[0] for row in trials}, {row[0] for row in strokes})
            self.assertEqual(len({row[0] for row in trials}), 1)
            self.assertEqual(len(trials), 4)
            self.assertEqual(sorted(q.name for q in (self.tmp / "t").iterdir()), ["strokes.csv", "trials.csv"])

    def test_cohort_into_a_folder_that_is_a_link(self):
        p = self.write(tiny())
        real = self.tmp / "real"
        real.mkdir()
        (self.tmp / "link").symlink_to("real")
        r = run(["session", "cohort", p, "--subjects", "1", "--csv", "link"], self.tmp)
        if r.returncode == 0:
            self.assertTrue((self.tmp / "link").is_symlink())
            self.assertEqual(sorted(q.name for q in real.iterdir()), ["strokes.csv", "trials.csv"])
        else:
            self.refused(r, 2, "link")
            self.assertEqual(list(real.iterdir()), [])

    def test_an_immutable_table_fails_the_pair_and_keeps_the_earlier(self):
        p = self.write(tiny())
        (self.tmp / "t").mkdir()
        r = run(["session", "cohort", p, "--subjects", "1", "--subject", "A", "--csv", "t"], self.tmp)
        self.assertEqual(r.returncode, 0, r.stderr)
        earlier = tree(self.tmp / "t")
        if subprocess.run(["chattr", "+i", str(self.tmp / "t" / "strokes.csv")],
                          stderr=subprocess.DEVNULL).returncode != 0:
            self.skipTest("chattr +i is not permitted here")
        r = run(["session", "cohort", p, "--subjects", "1", "--subject", "B", "--csv", "t"], self.tmp)
        subprocess.run(["chattr", "-i", str(self.tmp / "t" / "strokes.csv")])
        self.refused(r, 1, "strokes.csv")
        self.assertEqual(tree(self.tmp / "t"), earlier)

    def test_report_of_one_study_given_twice_counts_each_trial_once(self):
        st = self.copy_study()
        (self.tmp / "again").symlink_to("st")
        (self.tmp / "t").mkdir()
        for dirs in (["st", "st"], ["st", "st/S01"], ["st", "again"], ["st", "./st/"]):
            with self.subTest(dirs=dirs):
                r = run(["report", *dirs, "--csv", "t"], self.tmp)
                if r.returncode == 0:
                    rows = (self.tmp / "t" / "trials.csv").read_text().splitlines()[1:]
                    self.assertEqual(len(rows), 4, rows)
                else:
                    self.refused(r, 1)
        if cg_study is not None:
            for dirs in ([str(st), str(st)], [str(st), str(st / "S01")]):
                try:
                    study = cg_study.load(dirs)
                except cg.Error:
                    continue
                self.assertEqual(len(study.trials), 4)

    def test_report_pages_folder_that_is_a_link_carries_nothing_out(self):
        self.copy_study()
        elsewhere = self.tmp / "elsewhere"
        elsewhere.mkdir()
        (self.tmp / "r_files").symlink_to("elsewhere")
        r = run(["report", "st", "--out", "r.html"], self.tmp)
        self.assertEqual(list(elsewhere.iterdir()), [], r.stderr)
        if r.returncode != 0:
            self.refused(r, 2, "r_files")
        self.assertTrue((self.tmp / "r_files").is_symlink())

    def test_report_index_with_another_hard_link_keeps_the_other_name(self):
        self.copy_study()
        keep = self.tmp / "keep.html"
        keep.write_text("mine")
        os.link(keep, self.tmp / "r.html")
        (self.tmp / "t").mkdir()
        (self.tmp / "t" / "trials.csv").symlink_to("../keep.html")
        r = run(["report", "st", "--out", "r.html", "--csv", "t"], self.tmp)
        self.refused(r, 2, "--csv", "trials.csv")
        self.assertEqual(keep.read_text(), "mine")
        self.assertFalse((self.tmp / "r_files").exists())
        (self.tmp / "t" / "trials.csv").unlink()
        r = run(["report", "st", "--out", "r.html"], self.tmp)
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertEqual(keep.read_text(), "mine")
        self.assertIn("<html", (self.tmp / "r.html").read_text().lower())

    def test_report_jobs_and_missing_study(self):
        self.copy_study()
        (self.tmp / "t").mkdir()
        for jobs in ("0", "257", "-1", "1.5", "0x2", ""):
            with self.subTest(jobs=jobs):
                self.refused(run(["report", "st", "--csv", "t", "--jobs", jobs], self.tmp), 2, "--jobs")
        (self.tmp / "empty").mkdir()
        self.refused(run(["report", "empty", "--csv", "t"], self.tmp), 1, "empty")
        self.refused(run(["report", "st", "--out", "-"], self.tmp), 2, "--out")
        self.assertEqual(list((self.tmp / "t").iterdir()), [])

    def test_report_of_a_manifest_swapped_between_subjects(self):
        st = self.copy_study()
        s1, s2 = sessions(st)
        shutil.copy(s2 / "session.json", s1 / "session.json")
        (self.tmp / "t").mkdir()
        r = run(["report", "st", "--csv", "t"], self.tmp)
        self.refused(r, 1, s1.name)
        self.assertFalse((self.tmp / "t" / "trials.csv").exists())

    def test_report_of_a_record_copied_over_another_trial_of_its_session(self):
        # The record and its trace of trial 1 copied over trial 2's (the same character in the other condition):
        # the checksums agree, the session is the same; the record is still another trial's.
        st = self.copy_study()
        first, second = sorted(sessions(st)[0].glob("trials/*.json"))[:2]
        for ext in (".json", ".trace.h5"):
            shutil.copy(str(first)[:-len(".json")] + ext, str(second)[:-len(".json")] + ext)
        (self.tmp / "t").mkdir()
        r = run(["report", "st", "--csv", "t"], self.tmp)
        self.refused(r, 1, second.name, "/trial/index", "copied from another trial")
        self.assertFalse((self.tmp / "t" / "trials.csv").exists())
        (self.tmp / "page").mkdir()
        r = run(["report", "st", "--out", "page/index.html"], self.tmp)
        self.refused(r, 1, second.name, "/trial/index")
        self.assertEqual(list((self.tmp / "page").iterdir()), [])
        if cg is not None:
            with self.assertRaisesRegex(cg.DataError, "/trial/index"):
                cg_study.load(str(st))

    def test_report_of_a_record_with_numbers_no_double_holds(self):
        st = self.copy_study()
        record = sorted(sessions(st)[0].glob("trials/*.json"))[0]
        doc = json.loads(record.read_text(encoding="utf-8"))
        self.assertIn("mean_deviation_m", doc)
        for value in ("1e999", "-1e400", '"NaN"', "[]"):
            with self.subTest(value=value):
                record.write_text(json.dumps(dict(doc, mean_deviation_m="@@")).replace('"@@"', value),
                                  encoding="utf-8")
                (self.tmp / "t").mkdir(exist_ok=True)
                r = run(["report", "st", "--csv", "t"], self.tmp)
                self.refused(r, 1, record.name, "/mean_deviation_m")
                self.assertFalse((self.tmp / "t" / "trials.csv").exists())


# --------------------------------------------------------------------------------------------------------
# Python: the study API
# --------------------------------------------------------------------------------------------------------

@needs_python
class Python(Case):
    def test_load_given_what_is_no_study(self):
        (self.tmp / "empty").mkdir()
        (self.tmp / "file.txt").write_text("x")
        for arg, kinds in ((123, (TypeError,)), (None, (TypeError,)), (b"st", (TypeError, cg.Error)),
                           ([], (ValueError, cg.Error)), ("", (ValueError, cg.Error)),
                           (str(self.tmp / "empty"), (cg.Error,)), (str(self.tmp / "missing"), (cg.Error, OSError)),
                           (str(self.tmp / "file.txt"), (cg.Error, OSError)), ("a\0b", (ValueError, cg.Error))):
            with self.subTest(arg=arg):
                with self.assertRaises(kinds) as caught:
                    cg_study.load(arg)
                self.assertTrue(str(caught.exception))

    def test_cohort_simulate_given_wrong_values(self):
        import calligraphy.cohort as cohort
        p = str(self.write(tiny()))
        cases = [((p, 0), {}, ValueError), ((p, 100001), {}, ValueError), ((p, -1), {}, ValueError),
                 ((p, 2.0), {}, TypeError), ((p, True), {}, TypeError), ((p, "2"), {}, TypeError),
                 ((p, 1), {"workers": 0}, ValueError), ((p, 1), {"workers": 1025}, ValueError),
                 ((p, 1), {"profile": 3}, TypeError), ((p, 1), {"profile": "expert"}, ValueError),
                 ((p, 1), {"learning": "two_state"}, ValueError), ((p, 1), {"individual_differences": 1}, TypeError),
                 ((p, 1), {"individual_differences": "yes"}, TypeError), ((123, 1), {}, TypeError),
                 ((str(self.tmp), 1), {}, cg.Error), ((str(self.tmp / "missing.json"), 1), {}, cg.Error),
                 ((p, 1), {"batch_size": 0}, ValueError), ((p, 1), {"batch_size": 1.5}, (TypeError, ValueError)),
                 ((p, 1), {"client": 3}, TypeError), ((p, 1), {"client": "tcp://localhost:1"}, TypeError)]
        for args, kwargs, kind in cases:
            with self.subTest(args=args[1:], kwargs=kwargs):
                with self.assertRaises(kind) as caught:
                    cohort.simulate(*args, progress=False, **kwargs)
                self.assertTrue(str(caught.exception))

    def test_cohort_on_an_executor_is_the_cohort_on_threads(self):
        """docs/python.md: any concurrent.futures.Executor runs the batches as a Dask client would, and the
        tables do not depend on the threads, workers or batches."""
        import calligraphy.cohort as cohort
        from concurrent.futures import ThreadPoolExecutor
        p = str(self.write(tiny()))
        threads = cohort.simulate(p, 2, progress=False, workers=1)
        with ThreadPoolExecutor(max_workers=2) as pool:
            executor = cohort.simulate(p, 2, progress=False, client=pool, batch_size=1)
        self.assertEqual(threads.trials.drop(columns=["start_utc"]).to_csv(),
                         executor.trials.drop(columns=["start_utc"]).to_csv())
        self.assertEqual(threads.strokes.to_csv(), executor.strokes.to_csv())

    def test_samples_of_a_cohort_trial_say_there_is_no_trace(self):
        import calligraphy.cohort as cohort
        study = cohort.simulate(str(self.write(tiny())), 1, progress=False, workers=1)
        self.assertEqual(len(study.trials), 2)
        with self.assertRaises((cg.Error, KeyError, ValueError, LookupError)) as caught:
            study.samples(study.trials.iloc[0])
        self.assertTrue(str(caught.exception))

    def test_study_report_refuses_links_in_its_set_before_any_work(self):
        import calligraphy.study_report as sr
        shutil.copytree(Shared.study() / "st", self.tmp / "st")
        victim = self.tmp / "victim.html"
        victim.write_text("mine")
        out = self.tmp / "paper"
        out.mkdir()
        (out / "index.html").symlink_to("../victim.html")
        r = subprocess.run([sys.executable, "-m", "calligraphy.study_report", "st", "--out", "paper"],
                           cwd=self.tmp, stdout=subprocess.PIPE, stderr=subprocess.PIPE, timeout=TIMEOUT_S)
        self.refused(r, 1, "index.html", prefix="calligraphy.study_report: ")
        self.assertEqual(victim.read_text(), "mine")
        self.assertTrue((out / "index.html").is_symlink())
        study = cg_study.load(str(self.tmp / "st"))
        with self.assertRaises((OSError, cg.Error, ValueError)):
            sr.write_report(study, str(out))
        self.assertEqual(victim.read_text(), "mine")
        # A table or a figure of the set planted as a link: refused as well, before the fits and figures.
        (out / "index.html").unlink()
        for planted in ("tables/questions.csv", "figures/phase_mean_deviation_m.png"):
            (out / planted).parent.mkdir(exist_ok=True)
            (out / planted).symlink_to(victim)
            with self.assertRaises(OSError) as caught:
                sr.write_report(study, str(out), values=("mean_deviation_m",))
            self.assertIn(planted.split("/")[1], str(caught.exception))
            (out / planted).unlink()
        self.assertEqual(victim.read_text(), "mine")
        self.assertEqual(sorted(p.name for p in out.rglob("*")), ["figures", "tables"])
        for bad in ("", " "):
            r = subprocess.run([sys.executable, "-m", "calligraphy.study_report", "st", "--out", bad],
                               cwd=self.tmp, stdout=subprocess.PIPE, stderr=subprocess.PIPE, timeout=TIMEOUT_S)
            self.assertEqual(r.returncode, 2, r.stderr)
            self.assertIn("--out", error_lines(r)[-1])  # argparse: its usage, then one error line

    @heavy
    def test_study_report_with_conditions_named_like_missing_values(self):
        """Conditions named NA and TRUE (R's and pandas' missing value and logical spellings), an outcome that
        is the same in every trial and one missing in every trial (a skill without a learning model): the page is made, the NA condition is
        analysed as a condition, and no row shows a NaN as a number."""
        import calligraphy.study_report as sr
        doc = tiny(name="odd", conditions=[{"name": "NA", "mode": "vision"}, {"name": "TRUE", "mode": "haptic"}],
                   test={"characters": [SHI], "conditions": ["NA", "TRUE"], "repetitions": 1})
        r = run(["session", "run", self.write(doc), "--subjects", "4", "--writer-learning", "none", "--out", "st"],
                self.tmp)
        self.assertEqual(r.returncode, 0, r.stderr)
        study = cg_study.load(str(self.tmp / "st"))
        self.assertTrue(study.trials["shape_skill"].isna().all())  # no learning model: no skill
        self.assertEqual(sorted(map(str, study.trials["condition"].unique())), ["NA", "TRUE"])
        self.assertEqual(int(study.trials["condition"].isna().sum()), 0)
        keep = self.tmp / "keep.html"
        keep.write_text("mine")
        (self.tmp / "paper").mkdir()
        os.link(keep, self.tmp / "paper" / "index.html")
        index = sr.write_report(study, str(self.tmp / "paper"),
                                values=("mean_deviation_m", "strokes_total", "shape_skill"),
                                reference="NA")
        self.assertEqual(keep.read_text(), "mine")
        page = Path(index).read_text(encoding="utf-8")
        import re
        text = re.sub(r"<style.*?</style>|<[^>]+>", " ", page, flags=re.S)
        self.assertIsNone(re.search(r"\bnan\b", text, re.I), re.findall(r".{60}\bnan\b.{60}", text, re.I | re.S)[:3])
        import csv
        with open(self.tmp / "paper" / "tables" / "phase_means.csv", encoding="utf-8") as f:
            rows = list(csv.DictReader(f))
        conditions = {row["condition"] for row in rows if row["value"] == "mean_deviation_m"}
        self.assertEqual(conditions, {"NA", "TRUE"})
        with open(self.tmp / "paper" / "tables" / "questions.csv", encoding="utf-8") as f:
            questions = list(csv.DictReader(f))
        dev = [q for q in questions if q["value"] == "mean_deviation_m" and "mixed" in q["question"]]
        self.assertTrue(dev, questions)
        for q in dev:
            self.assertIn("NA", q["comparison"])
            self.assertNotIn("not computed", q["note"], q)
        for q in questions:
            if q["value"] in ("strokes_total", "shape_skill"):
                self.assertEqual(q["p"], "", q)
                self.assertTrue(q["note"], q)


if __name__ == "__main__":
    if not CLI:
        print("CALLIGRAPHY_CLI is not set", file=sys.stderr)
        sys.exit(2)
    if SANITIZED:
        suite = unittest.TestSuite()
        for name in ("test_a_name_that_climbs_out_of_the_study_folder_is_refused",
                     "test_sessions_that_skip_go_back_or_pass_twenty", "test_documents_that_are_not_protocols"):
            suite.addTest(Protocols(name))
        suite.addTest(Plans("test_a_mixed_design_gives_the_documented_cells"))
        suite.addTest(Sets("test_cohort_refuses_a_replay_condition_and_writes_nothing"))
        suite.addTest(Runs("test_resume_of_a_plan_edited_to_write_elsewhere_or_otherwise"))
        result = unittest.TextTestRunner(verbosity=2).run(suite)
        sys.exit(0 if result.wasSuccessful() else 1)
    unittest.main(verbosity=2)
