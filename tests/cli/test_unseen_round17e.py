#!/usr/bin/env python3
"""Round 17E: the study plan as a methodologist checks it, from the docs alone (docs/experiments.md "Orders",
"Phases", "Crossover designs", "Planning a study", "Sessions", "Tidy tables"; docs/cli.md "session run | resume",
"session plan", "session cohort"). Run by CTest as `cli_unseen_round17e_tests`.

Earlier rounds attacked the study's files; this one checks the DESIGN: Williams squares (each condition in each
position and each ordered pair of successive conditions equally often), ABBA, between-subjects groups that
differ by at most one, crossover and mixed cells, plans that stay put when subjects are added, seeded orders
that are permutations and reproduce byte for byte, phases with their conditions, items, delays and rests, the
tables' labels equal to the plan's, and degenerate designs. `session plan` (nothing run) wherever it can; a
few tiny sessions (一 二 三 十 人, 0.05 s trials, simulated subjects that do not learn) where a saved trial's
labels must be checked.

CALLIGRAPHY_CLI names the program, PYTHONPATH its Python module. CALLIGRAPHY_SANITIZED=1 takes five cases.
"""
import collections
import csv
import itertools
import json
import math
import shutil
import tempfile
import unittest
from pathlib import Path

from outsider import OneErrorLine, run, sanitized_subset

load_tests = sanitized_subset({"test_even_latin_square_is_a_williams_square",
                               "test_between_groups_fill_in_turn_and_differ_by_at_most_one",
                               "test_report_rows_carry_the_plans_labels",
                               "test_same_seed_same_plan_byte_for_byte",
                               "test_abba_directions_and_repetitions_split_over_two_blocks"})

YI, ER, SAN, SHI, REN = "一", "二", "三", "十", "人"
TINY = {"max_duration_s": 0.05}
LETTERS = "ABCDEFGHIJKLMNOPQRSTUVWXYZ"
RUN = ["--writer", "simulated", "--writer-learning", "none", "--individual-differences", "off"]


def conditions(names, mode="vision"):
    return [{"name": n, "mode": mode} for n in names]


def within(name, names, order="latin_square", items=(YI,), repetitions=1, **extra):
    protocol = {"name": name, "conditions": conditions(names),
                "test": {"characters": list(items), "conditions": list(names), "repetitions": repetitions},
                "order": {"conditions": order}, "trial": TINY}
    protocol["order"].update(extra)
    return protocol


def between(name, names, order="fixed", seed=0):
    return {"name": name, "conditions": conditions(names),
            "phases": [{"phase": "pre-test", "condition": names[0], "characters": [YI]},
                       {"phase": "training", "conditions": list(names), "assignment": "between-subjects",
                        "characters": [YI], "repetitions": 2},
                       {"phase": "post-test", "condition": names[0], "characters": [YI]}],
            "order": {"conditions": order, "seed": seed}, "trial": TINY}


def crossover(name, names, sets=None, extra_phases=()):
    sets = sets or [[c] for c in (YI, ER, SAN, SHI, REN)[:len(names)]]
    set_names = [f"s{i + 1}" for i in range(len(sets))]
    return {"name": name, "conditions": conditions(names),
            "item_sets": [{"name": n, "characters": list(c)} for n, c in zip(set_names, sets)],
            "phases": list(extra_phases) + [
                {"phase": "pre-test", "condition": names[0], "sets": set_names},
                {"phase": "training", "conditions": list(names), "assignment": "crossover", "sets": set_names,
                 "repetitions": 2},
                {"phase": "post-test", "condition": names[0], "sets": set_names}],
            "trial": TINY}


# The design most cases share: a between-subjects familiarisation (a group), a 2x2 crossover with a pre-test and
# a post-test that lists characters of the sets, breaks, and a retention test a day later.
MIXED = {"name": "m17e",
         "conditions": [{"name": "U", "mode": "vision"}, {"name": "X", "mode": "error-amplification"},
                        {"name": "F", "mode": "haptic"}],
         "item_sets": [{"name": "s1", "characters": [YI, ER]}, {"name": "s2", "characters": [SHI, SAN]},
                       {"name": "s3", "characters": ["口"], "transfer_of": "s1"}],
         "phases": [{"phase": "practice", "conditions": ["U", "F"], "assignment": "between-subjects",
                     "characters": [REN]},
                    {"phase": "pre-test", "condition": "U", "sets": ["s1", "s2"]},
                    {"phase": "training", "conditions": ["U", "X"], "assignment": "crossover",
                     "sets": ["s1", "s2"], "repetitions": 2},
                    {"phase": "post-test", "condition": "U", "characters": [YI, SHI], "delay_s": 60},
                    {"phase": "retention", "condition": "U", "sets": ["s1", "s2"], "session": 2,
                     "delay_s": 86400},
                    {"phase": "transfer", "condition": "U", "sets": ["s3"], "session": 2}],
         "order": {"characters": "random", "seed": 17},
         "breaks": {"between_blocks_s": 5, "every_trials": 4, "duration_s": 2},
         "trial": TINY}
SHARED = {}


def orders(plan):
    """Each subject's block conditions of its first phase, as a tuple, by subject number."""
    return {s["number"]: tuple(b["condition"] for b in s["sessions"][0]["phases"][0]["blocks"])
            for s in plan["subjects"]}


def williams_rows(n):
    """The balanced Latin square docs/experiments.md describes: first row 0, 1, n-1, 2, n-2, ..., row r adds r
    mod n; for odd n the rows followed by their reverses."""
    first, low, high = [0], 1, n - 1
    while len(first) < n:
        first.append(low)
        low += 1
        if len(first) < n:
            first.append(high)
            high -= 1
    rows = [[(c + r) % n for c in first] for r in range(n)]
    return rows + [row[::-1] for row in rows] if n % 2 else rows


def successive_pairs(sequences):
    return collections.Counter(pair for seq in sequences for pair in zip(seq, seq[1:]))


def read_csv(path):
    with open(path, encoding="utf-8", newline="") as f:
        return list(csv.DictReader(f))


def manifests(out):
    """{(subject, session_number): session.json} of a study folder."""
    found = {}
    for path in sorted(Path(out).glob("*/*/session.json")):
        manifest = json.loads(path.read_text(encoding="utf-8"))
        manifest["folder"] = path.parent.name
        found[(manifest["subject"]["id"], manifest.get("session_number", 1))] = manifest
    return found


class Round17E(OneErrorLine, unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.tmp = Path(tempfile.mkdtemp(prefix="r17e-"))
        if "mixed" not in SHARED:
            protocol = cls.write_protocol(cls.tmp, "mixed.json", MIXED)
            out = cls.tmp / "mixed-study"
            done = run(["session", "run", protocol, "--subjects", "4", "--out", out, *RUN], cwd=cls.tmp)
            assert done.returncode == 0, done.stderr.decode()
            SHARED["mixed"] = (protocol, out, done)

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.tmp, ignore_errors=True)

    @staticmethod
    def write_protocol(folder, name, protocol):
        path = Path(folder) / name
        path.write_text(json.dumps(protocol, ensure_ascii=False), encoding="utf-8")
        return path

    def protocol(self, protocol, name=None):
        return self.write_protocol(self.tmp, name or protocol["name"] + ".json", protocol)

    def plan(self, protocol, subjects, *extra):
        path = protocol if isinstance(protocol, Path) else self.protocol(protocol)
        done = run(["session", "plan", path, "--subjects", subjects, "--json", *extra], cwd=self.tmp)
        self.assertEqual(done.returncode, 0, done.stderr.decode())
        return json.loads(done.stdout)

    def study(self, protocol, subjects, name, *extra):
        out = self.tmp / name
        done = run(["session", "run", self.protocol(protocol), "--subjects", subjects, "--out", out, *RUN, *extra],
                   cwd=self.tmp)
        self.assertEqual(done.returncode, 0, done.stderr.decode())
        return out

    def assert_balanced(self, counter, levels, times, what):
        self.assertEqual(set(counter), set(levels), what)
        self.assertEqual(set(counter.values()), {times}, f"{what}: {dict(counter)}")

    # ---- counterbalancing ----------------------------------------------------------------------------------

    def test_even_latin_square_is_a_williams_square(self):
        plan = self.plan(within("w4", "ABCD"), 8)
        got = orders(plan)
        expected = ["".join("ABCD"[c] for c in row) for row in williams_rows(4)]
        self.assertEqual(["".join(got[n]) for n in range(1, 9)], expected * 2)
        for position in range(4):
            self.assert_balanced(collections.Counter(o[position] for o in got.values()), "ABCD", 2,
                                 f"position {position + 1}")
        self.assert_balanced(successive_pairs(got.values()), itertools.permutations("ABCD", 2), 2,
                             "ordered pairs of successive conditions")
        self.assertEqual(plan["balance"]["square"], 4)
        self.assertTrue(plan["balance"]["filled"])
        self.assertEqual(plan["balance"]["warning"], "")

    def test_odd_latin_square_is_its_rows_then_their_reverses(self):
        for n in (3, 5):
            names = LETTERS[:n]
            plan = self.plan(within(f"w{n}", names), 2 * n)
            got = orders(plan)
            self.assertEqual(["".join(got[i]) for i in range(1, 2 * n + 1)],
                             ["".join(names[c] for c in row) for row in williams_rows(n)])
            for position in range(n):
                self.assert_balanced(collections.Counter(o[position] for o in got.values()), names, 2,
                                     f"n={n} position {position + 1}")
            self.assert_balanced(successive_pairs(got.values()), itertools.permutations(names, 2), 2,
                                 f"n={n} successive pairs")
            self.assertEqual(plan["balance"]["square"], 2 * n)

    def test_two_conditions_alternate_and_an_odd_count_is_named(self):
        plan = self.plan(within("w2", "AB"), 5)
        self.assertEqual(["".join(plan_order) for _, plan_order in sorted(orders(plan).items())],
                         ["AB", "BA", "AB", "BA", "AB"])
        self.assertFalse(plan["balance"]["filled"])
        self.assertIn("N=5", plan["balance"]["warning"])
        self.assertIn("with 2", plan["balance"]["warning"])
        self.assertIn("with 3", plan["balance"]["warning"])

    def test_the_balance_counts_are_the_plans_own(self):
        for names, n in (("ABCD", 5), ("ABC", 7), ("ABCD", 8)):
            plan = self.plan(within(f"b{len(names)}", names), n)
            counted = collections.Counter(" ".join(o) for o in orders(plan).values())
            factors = plan["balance"]["factors"]
            self.assertEqual(len(factors), 1, factors)
            stated = {level["level"]: level["subjects"] for level in factors[0]["levels"]}
            self.assertEqual({k: v for k, v in stated.items() if v}, dict(counted))
            self.assertEqual(sum(stated.values()), n)
            filled = n % plan["balance"]["square"] == 0
            self.assertEqual(plan["balance"]["filled"], filled)
            self.assertEqual(plan["balance"]["warning"] == "", filled, plan["balance"]["warning"])

    def test_between_groups_fill_in_turn_and_differ_by_at_most_one(self):
        names = ["G1", "G2", "G3"]
        protocol = between("g3", names)
        protocol["phases"].insert(0, {"phase": "practice", "conditions": names,
                                      "assignment": "between-subjects", "characters": [REN]})
        for n in (1, 2, 3, 4, 7, 9):
            plan = self.plan(protocol, n)
            sizes = collections.Counter()
            for subject in plan["subjects"]:
                expected = names[(subject["number"] - 1) % 3]
                # two between-subjects phases (the familiarisation and the training): both conditions, joined
                self.assertEqual(subject["group"], f"{expected}/{expected}")
                phases = subject["sessions"][0]["phases"]
                # the familiarisation and the training both in the group's one condition
                self.assertEqual([b["condition"] for b in phases[0]["blocks"]], [expected])
                self.assertEqual([b["condition"] for b in phases[2]["blocks"]], [expected])
                sizes[expected] += 1
            present = [sizes[g] for g in names]
            self.assertLessEqual(max(present) - min(present), 1, f"N={n}: {present}")
            self.assertEqual(plan["balance"]["square"], 3)

    def test_adding_subjects_keeps_every_earlier_plan(self):
        designs = [within("k1", "ABC"), between("k2", ["G1", "G2", "G3"]), crossover("k3", "ABC"), MIXED,
                   within("k5", "ABCD", order="random", seed=3),
                   within("k6", "AB", order="abba", repetitions=2)]
        for design in designs:
            path = self.protocol(design)
            few = self.plan(path, 3)
            many = self.plan(path, 11)
            self.assertEqual(few["subjects"], many["subjects"][:3], design["name"])

    def test_new_subjects_get_the_plan_of_their_numbers(self):
        names = ["G1", "G2", "G3"]
        protocol = between("n17e", names)
        out = self.study(protocol, 2, "new-subjects")
        before = {p: p.read_bytes() for p in out.glob("*/*/session.json")}
        done = run(["session", "run", self.protocol(protocol), "--subjects", 2, "--new-subjects", "--out", out, *RUN],
                   cwd=self.tmp)
        self.assertEqual(done.returncode, 0, done.stderr.decode())
        for path, text in before.items():
            self.assertEqual(path.read_bytes(), text, path)
        planned = {s["id"]: s for s in self.plan(protocol, 4)["subjects"]}
        found = manifests(out)
        self.assertEqual(sorted(s for s, _ in found), ["S01", "S02", "S03", "S04"])
        for (subject, _), manifest in found.items():
            self.assertEqual(manifest["group"], planned[subject]["group"], subject)
            training = [p["condition"] for p in manifest["plan"] if p["phase"] == "training"]
            self.assertEqual(set(training), {planned[subject]["group"]}, subject)

    def test_three_condition_crossover_is_williams_and_pairs_every_set(self):
        plan = self.plan(crossover("x3", "ABC"), 18)
        sequences = [s["sequence"] for s in plan["subjects"]]
        self.assertEqual(sequences[:6], ["".join("ABC"[c] for c in row) for row in williams_rows(3)])
        for period in range(3):
            self.assert_balanced(collections.Counter(q[period] for q in sequences), "ABC", 6, f"period {period}")
        self.assert_balanced(successive_pairs(sequences), itertools.permutations("ABC", 2), 6, "successive pairs")
        pairs = collections.Counter()
        for subject in plan["subjects"]:
            training = subject["sessions"][0]["phases"][1]
            self.assertEqual(training["assignment"], "crossover")
            pairs.update((b["condition"], b["set"]) for b in training["blocks"])
            self.assertEqual([b["condition"] for b in training["blocks"]], list(subject["sequence"]))
        self.assert_balanced(pairs, [(c, s) for c in "ABC" for s in ("s1", "s2", "s3")], 6, "condition x set")
        self.assertEqual(len({(s["sequence"], s["set_pairing"]) for s in plan["subjects"]}), 18)
        self.assertTrue(plan["balance"]["filled"])

    def test_three_groups_beside_a_crossover_get_every_cell(self):
        protocol = crossover("g3x", "AB", extra_phases=[
            {"phase": "practice", "conditions": ["A", "B", "C"], "assignment": "between-subjects",
             "characters": [REN]}])
        protocol["conditions"] = conditions("ABC")
        plan = self.plan(protocol, 24)
        self.assertEqual(plan["balance"]["square"], 12)
        cells = collections.defaultdict(collections.Counter)
        for subject in plan["subjects"]:
            cells[subject["group"]][(subject["sequence"], subject["set_pairing"])] += 1
        self.assertEqual(sorted(cells), ["A", "B", "C"])
        for group, cell in cells.items():
            self.assertEqual(len(cell), 4, f"group {group}: {dict(cell)}")
            self.assertEqual(set(cell.values()), {2}, f"group {group}: {dict(cell)}")

    def test_a_within_order_is_not_confounded_with_the_group(self):
        # Between-subjects training beside unguided tests of two conditions in a Latin-square order: once N fills
        # the square (no warning), every group must hold every order equally often, or the order is the group.
        names = ["A", "B"]
        protocol = {"name": "gw17e", "conditions": conditions(names),
                    "phases": [{"phase": "pre-test", "conditions": names, "characters": [YI]},
                               {"phase": "training", "conditions": names, "assignment": "between-subjects",
                                "characters": [YI]},
                               {"phase": "post-test", "conditions": names, "characters": [YI]}],
                    "order": {"conditions": "latin_square"}, "trial": TINY}
        for n in (4, 8):
            plan = self.plan(protocol, n)
            self.assertEqual(plan["balance"]["warning"] == "", n % plan["balance"]["square"] == 0)
            if plan["balance"]["warning"]:
                continue
            cells = collections.Counter((s["group"], orders(plan)[s["number"]]) for s in plan["subjects"])
            self.assert_balanced(cells, [(g, o) for g in names for o in (("A", "B"), ("B", "A"))], n // 4,
                                 f"N={n}: group x order of the pre-test")

    def test_two_between_phases_name_the_group_by_both(self):
        protocol = between("gg17e", ["G1", "G2", "G3"])
        protocol["conditions"] += conditions(["P1", "P2"])
        protocol["phases"].insert(0, {"phase": "practice", "conditions": ["P1", "P2"],
                                      "assignment": "between-subjects", "characters": [REN]})
        plan = self.plan(protocol, 6)
        self.assertEqual(plan["balance"]["square"], 6)
        seen = set()
        for subject in plan["subjects"]:
            phases = subject["sessions"][0]["phases"]
            practice, training = phases[0]["blocks"][0]["condition"], phases[2]["blocks"][0]["condition"]
            self.assertEqual(practice, ["P1", "P2"][(subject["number"] - 1) % 2])
            self.assertEqual(training, ["G1", "G2", "G3"][(subject["number"] - 1) % 3])
            self.assertEqual(subject["group"], f"{practice}/{training}")
            seen.add(subject["group"])
        self.assertEqual(len(seen), 6, "every combination of the two factors over the square")

    def test_practice_comes_first_as_listed_whatever_the_order(self):
        for order in ("latin_square", "abba", "random"):
            protocol = within(f"pr{order}", "AB", order=order, repetitions=2, seed=4)
            protocol["practice"] = {"characters": [REN], "condition": "B", "repetitions": 2}
            plan = self.plan(protocol, 4)
            for subject in plan["subjects"]:
                phases = subject["sessions"][0]["phases"]
                self.assertEqual(phases[0]["phase"], "practice", order)
                self.assertEqual([b["condition"] for b in phases[0]["blocks"]], ["B"], order)
                self.assertEqual((phases[0]["items"], phases[0]["trials"]), ([REN], 2), order)
                self.assertEqual(phases[1]["phase"], "test", order)

    def test_abba_directions_and_repetitions_split_over_two_blocks(self):
        out = self.study(within("abba17e", "AB", order="abba", items=(YI, SHI), repetitions=4), 2, "abba")
        for (subject, _), manifest in manifests(out).items():
            plan = manifest["plan"]
            blocks = [[p for p in plan if p["block"] == b] for b in sorted({p["block"] for p in plan})]
            got = "".join(block[0]["condition"] for block in blocks)
            self.assertEqual(got, "ABBA" if subject == "S01" else "BAAB", subject)
            for block in blocks:
                self.assertEqual({p["condition"] for p in block}, {block[0]["condition"]})
            for condition in "AB":
                for item in (YI, SHI):
                    reps = [p["repetition"] for p in plan if p["condition"] == condition and p["characters"] == item]
                    self.assertEqual(reps, [1, 2, 3, 4], f"{subject} {condition} {item}")
                first = [b for b in blocks if b[0]["condition"] == condition][0]
                self.assertEqual(sorted({p["repetition"] for p in first}), [1, 2])

    def test_abba_odd_repetitions_and_three_conditions(self):
        odd = self.protocol(within("abba3r", "AB", order="abba", repetitions=3))
        done = run(["session", "plan", odd, "--subjects", 2], cwd=self.tmp)
        self.assert_one_error(done, (1, 2), str(odd.name), "/test/repetitions")
        plan = self.plan(within("abba3c", "ABC", order="abba", repetitions=2), 4)
        self.assertEqual(["".join(o) for _, o in sorted(orders(plan).items())], ["ABCCBA", "CBAABC"] * 2)
        self.assertEqual(plan["balance"]["square"], 2)

    # ---- randomisation -------------------------------------------------------------------------------------

    def test_same_seed_same_plan_byte_for_byte(self):
        path = self.protocol(within("seed17e", "ABCD", order="random", items=(YI, ER, SAN), seed=99,
                                    characters="random"))
        texts = [run(["session", "plan", path, "--subjects", 6, "--json"], cwd=self.tmp).stdout for _ in range(2)]
        self.assertEqual(texts[0], texts[1])
        first = self.study(within("seed17e", "ABCD", order="random", items=(YI, ER, SAN), seed=99,
                                  characters="random"), 2, "seed-a")
        second = self.study(within("seed17e", "ABCD", order="random", items=(YI, ER, SAN), seed=99,
                                   characters="random"), 2, "seed-b")
        a, b = manifests(first), manifests(second)
        self.assertEqual(sorted(a), sorted(b))
        for key in a:
            self.assertEqual(a[key]["plan"], b[key]["plan"], key)

    def test_another_seed_another_plan(self):
        plans = [orders(self.plan(within(f"s{seed}", "ABCD", order="random", seed=seed), 12)) for seed in (1, 2)]
        self.assertNotEqual(plans[0], plans[1])
        for plan in plans:
            for order in plan.values():
                self.assertEqual(sorted(order), list("ABCD"))
            self.assertGreater(len(set(plan.values())), 1, "one order for every subject is no draw")

    def test_random_items_are_a_permutation_in_every_round(self):
        items = (YI, ER, SAN, SHI, REN)
        out = self.study(within("perm17e", "AB", order="fixed", items=items, repetitions=3, seed=5,
                                characters="random"), 2, "perm")
        sequences = []
        for manifest in manifests(out).values():
            plan = manifest["plan"]
            self.assertEqual([p["index"] for p in plan], list(range(1, 31)))
            for condition in "AB":
                trials = [p for p in plan if p["condition"] == condition]
                self.assertEqual(len(trials), 15)
                for r in range(3):
                    round_ = trials[5 * r:5 * r + 5]
                    self.assertEqual(sorted(p["characters"] for p in round_), sorted(items))
                    self.assertEqual({p["repetition"] for p in round_}, {r + 1})
                    for p in round_:
                        self.assertEqual(items[p["item"] - 1], p["characters"])
                sequences.append(tuple(p["characters"] for p in trials))
        self.assertGreater(len(set(sequences)), 1, "a random order that is the same every time")

    def test_random_groups_are_drawn_from_the_seed_and_said_so(self):
        names = ["G1", "G2", "G3"]
        draws = []
        for seed in (1, 2):
            plan = self.plan(between(f"rg{seed}", names, order="random", seed=seed), 12)
            self.assertTrue(plan["balance"]["drawn"])
            groups = [s["group"] for s in plan["subjects"]]
            self.assertTrue(set(groups) <= set(names), groups)
            for subject in plan["subjects"]:
                training = subject["sessions"][0]["phases"][1]
                self.assertEqual([b["condition"] for b in training["blocks"]], [subject["group"]])
            draws.append(groups)
        self.assertNotEqual(draws[0], draws[1])
        out = self.study(between("rg1", names, order="random", seed=1), 3, "random-groups")
        for (subject, _), manifest in manifests(out).items():
            self.assertEqual(manifest["group"], draws[0][int(subject[1:]) - 1], subject)

    # ---- phases --------------------------------------------------------------------------------------------

    def test_phases_in_order_with_their_conditions_and_items(self):
        _, out, _ = SHARED["mixed"]
        planned = {s["id"]: s for s in self.plan(self.tmp / "mixed.json", 4)["subjects"]}
        for (subject, number), manifest in manifests(out).items():
            plan = manifest["plan"]
            phases = [p["phase"] for p in plan]
            expected = (["practice", "pre-test"] + ["pre-test"] * 3 + ["training"] * 8 + ["post-test"] * 2
                        if number == 1 else ["retention"] * 4 + ["transfer"])
            self.assertEqual(phases, expected, subject)
            who = planned[subject]
            for p in plan:
                if p["phase"] == "practice":
                    self.assertEqual((p["condition"], p["characters"]), (who["group"], REN))
                elif p["phase"] == "training":
                    period = p["period"]
                    self.assertEqual(p["condition"], "UX"["AB".index(who["sequence"][period - 1])])
                    self.assertEqual(p["trained_condition"], p["condition"])
                else:
                    self.assertEqual(p["condition"], "U")
                if p["phase"] == "post-test":
                    self.assertIn(p["characters"], (YI, SHI))
            training = [p for p in plan if p["phase"] == "training"]
            for block in {p["block"] for p in training}:
                trials = [p for p in training if p["block"] == block]
                self.assertEqual(len({p["item_set"] for p in trials}), 1, f"{subject} block {block}")
                self.assertEqual(collections.Counter(p["characters"] for p in trials),
                                 collections.Counter({c: 2 for c in {p["characters"] for p in trials}}))

    def test_retention_comes_a_session_later_after_the_documented_delay(self):
        _, out, _ = SHARED["mixed"]
        found = manifests(out)
        plan = self.plan(self.tmp / "mixed.json", 4)
        for subject in ("S01", "S02", "S03", "S04"):
            second = found[(subject, 2)]
            first = found[(subject, 1)]
            self.assertEqual(second["previous_session"]["delay_s"], 86400)
            self.assertEqual(second["previous_session"]["delay"], "simulated")
            self.assertEqual(second["previous_session"]["session_id"], first["folder"])
            self.assertEqual({p["phase"] for p in second["plan"]}, {"retention", "transfer"})
            self.assertNotIn("retention", {p["phase"] for p in first["plan"]})
        sessions = plan["subjects"][0]["sessions"]
        self.assertEqual([s["delay_s"] for s in sessions], [0, 86400])

    def test_every_trial_names_the_condition_and_period_its_set_is_trained_in(self):
        _, out, _ = SHARED["mixed"]
        found = manifests(out)
        for subject in ("S01", "S02", "S03", "S04"):
            training = [p for p in found[(subject, 1)]["plan"] if p["phase"] == "training"]
            trained = {p["item_set"]: (p["condition"], p["period"]) for p in training}
            self.assertEqual(sorted(trained), ["s1", "s2"], subject)
            self.assertEqual(sorted(period for _, period in trained.values()), [1, 2], subject)
            trained["s3"] = trained["s1"]  # a transfer_of set takes its source's period and condition
            for number in (1, 2):
                for p in found[(subject, number)]["plan"]:
                    if p["phase"] == "practice":
                        continue
                    expected = {YI: "s1", ER: "s1", SHI: "s2", SAN: "s2", "口": "s3"}[p["characters"]]
                    self.assertEqual(p["item_set"], expected, (subject, p["file"]))
                    self.assertEqual((p["trained_condition"], p["period"]), trained[expected], (subject, p["file"]))

    def test_rests_are_where_the_protocol_puts_them(self):
        _, out, _ = SHARED["mixed"]
        plan = {s["id"]: s for s in self.plan(self.tmp / "mixed.json", 4)["subjects"]}
        for (subject, number), manifest in manifests(out).items():
            trials = manifest["plan"]
            planned = plan[subject]["sessions"][number - 1]
            self.assertEqual(trials[0]["break_before_s"], 0)
            self.assertAlmostEqual(sum(p["break_before_s"] for p in trials), planned["rest_s"], places=9)
            self.assertAlmostEqual(planned["max_duration_s"], planned["rest_s"] + len(trials) * TINY["max_duration_s"],
                                   places=9)
            for before, p in zip(trials, trials[1:]):
                if p["block"] != before["block"]:
                    self.assertGreaterEqual(p["break_before_s"], 5, f"{subject} trial {p['index']}")
                if p["phase"] == "post-test" and before["phase"] != "post-test":
                    self.assertGreaterEqual(p["break_before_s"], 60, f"{subject} trial {p['index']}")
                if (p["index"] - 1) % 4 == 0:
                    self.assertGreaterEqual(p["break_before_s"], 2, f"{subject} trial {p['index']}")

    def test_plan_phases_start_where_the_session_json_numbers_them(self):
        _, out, _ = SHARED["mixed"]
        plan = {s["id"]: s for s in self.plan(self.tmp / "mixed.json", 4)["subjects"]}
        for (subject, number), manifest in manifests(out).items():
            for phase in plan[subject]["sessions"][number - 1]["phases"]:
                trials = [p for p in manifest["plan"] if p["phase"] == phase["phase"]]
                self.assertEqual(len(trials), phase["trials"])
                # "Indices count from 1 everywhere a study shows them" (docs/experiments.md, "Tidy tables")
                self.assertEqual(phase["first_trial"], trials[0]["index"], f"{subject} {phase['phase']}")

    def test_a_transfer_choice_is_the_documented_one_for_every_subject(self):
        protocol = {"name": "t17e", "conditions": conditions(["unguided", "fixture"]),
                    "phases": [{"phase": "pre-test", "condition": "unguided", "characters": [SHI, REN, "口"]},
                               {"phase": "training", "conditions": ["unguided", "fixture"],
                                "assignment": "between-subjects", "characters": [SHI, REN, "口"]},
                               {"phase": "transfer", "condition": "unguided", "characters": {
                                   "choose": 2, "from": ["大", "天", "木", "山", "中", "日", "千"]}}],
                    "trial": TINY}
        plan = self.plan(protocol, 3)
        for subject in plan["subjects"]:
            transfer = subject["sessions"][0]["phases"][2]
            self.assertEqual(transfer["items"], ["木", "中"])
            self.assertEqual([b["condition"] for b in transfer["blocks"]], ["unguided"])
        protocol["phases"][2]["characters"]["choose"] = 7
        done = run(["session", "plan", self.protocol(protocol, "t17e-3.json"), "--subjects", 1], cwd=self.tmp)
        self.assert_one_error(done, (1, 2), "t17e-3.json", "/phases/2")

    def test_retention_without_a_delay_or_on_untrained_characters_is_refused(self):
        base = between("ret17e", ["A", "B"])
        cases = [({"phase": "retention", "condition": "A", "characters": [YI]}, "/phases/3"),
                 ({"phase": "retention", "condition": "A", "characters": [SHI], "delay_s": 60}, "/phases/3"),
                 ({"phase": "transfer", "condition": "A", "characters": [YI]}, "/phases/3")]
        for i, (phase, pointer) in enumerate(cases):
            protocol = json.loads(json.dumps(base))
            protocol["phases"].append(phase)
            path = self.protocol(protocol, f"ret{i}.json")
            done = run(["session", "plan", path, "--subjects", 1], cwd=self.tmp)
            self.assert_one_error(done, (1, 2), f"ret{i}.json", pointer)

    # ---- the tables ----------------------------------------------------------------------------------------

    LABELS = ("phase", "block", "condition", "characters", "item", "repetition", "item_set", "sequence", "period",
              "trained_condition")

    def planned_rows(self, out):
        rows = {}
        for (subject, number), manifest in manifests(out).items():
            for p in manifest["plan"]:
                rows[(subject, number, p["index"])] = (manifest["group"], p)
        return rows

    def assert_row_is_planned(self, row, group, p, where):
        self.assertEqual(row["group"], group, where)
        for key in self.LABELS:
            value = p.get(key, "")
            if key == "period" and value in ("", 0):
                value = ""
            self.assertEqual(str(row[key]), str(value), f"{where}: {key}")

    def test_report_rows_carry_the_plans_labels(self):
        _, out, _ = SHARED["mixed"]
        tables = self.tmp / "tables"
        tables.mkdir(exist_ok=True)
        done = run(["report", out, "--csv", tables], cwd=self.tmp)
        self.assertEqual(done.returncode, 0, done.stderr.decode())
        planned = self.planned_rows(out)
        rows = read_csv(tables / "trials.csv")
        self.assertEqual(len(rows), len(planned))
        for row in rows:
            key = (row["subject"], int(row["session_number"]), int(row["trial"]))
            group, p = planned[key]
            self.assert_row_is_planned(row, group, p, key)
        SHARED["tables"] = rows

    def test_trial_records_hold_their_plan_entry(self):
        _, out, _ = SHARED["mixed"]
        for path in sorted(out.glob("*/*/session.json")):
            manifest = json.loads(path.read_text(encoding="utf-8"))
            for p in manifest["plan"]:
                record = json.loads((path.parent / "trials" / (p["file"] + ".json")).read_text(encoding="utf-8"))
                trial = record["trial"]
                for key in ("index", "phase", "block", "condition", "item", "repetition", "item_set", "sequence",
                            "period", "trained_condition"):
                    if key in p:
                        self.assertEqual(trial.get(key), p[key], f"{p['file']}: {key}")
                self.assertEqual(record["characters"], p["characters"], p["file"])

    def test_study_load_labels_equal_the_plan(self):
        from calligraphy import study
        _, out, _ = SHARED["mixed"]
        trials = study.load(str(out)).trials
        planned = self.planned_rows(out)
        self.assertEqual(len(trials), len(planned))
        for _, row in trials.iterrows():
            key = (row["subject"], int(row["session_number"]), int(row["trial"]))
            group, p = planned[key]
            values = {k: row[k] for k in self.LABELS + ("group",)}
            if isinstance(values["period"], float):
                values["period"] = "" if math.isnan(values["period"]) else int(values["period"])
            self.assert_row_is_planned(values, group, p, key)

    def test_cohort_tables_label_trials_as_session_run_does(self):
        protocol, out, _ = SHARED["mixed"]
        tables = self.tmp / "cohort"
        tables.mkdir(exist_ok=True)
        done = run(["session", "cohort", protocol, "--subjects", 4, "--csv", tables, "--writer-learning", "none",
                    "--individual-differences", "off", "--jobs", 1], cwd=self.tmp)
        self.assertEqual(done.returncode, 0, done.stderr.decode())
        rows = read_csv(tables / "trials.csv")
        planned = self.planned_rows(out)
        self.assertEqual(len(rows), len(planned))
        for row in rows:
            key = (row["subject"], int(row["session_number"]), int(row["trial"]))
            group, p = planned[key]
            self.assert_row_is_planned(row, group, p, key)

    # ---- degenerate designs --------------------------------------------------------------------------------

    def test_one_subject_of_a_williams_design_is_planned_and_warned(self):
        plan = self.plan(within("one17e", "ABC"), 1)
        self.assertEqual(len(plan["subjects"]), 1)
        self.assertEqual(orders(plan)[1], ("A", "B", "C"))
        self.assertFalse(plan["balance"]["filled"])
        self.assertIn("N=1", plan["balance"]["warning"])
        self.assertIn("recruit a multiple of 6", plan["balance"]["warning"])

    def test_one_condition_needs_no_counterbalancing_and_no_group_of_one(self):
        for order in ("latin_square", "abba", "random", "fixed"):
            plan = self.plan(within(f"c1{order}", "A", order=order, repetitions=2), 3)
            self.assertEqual(plan["balance"]["square"], 1, order)
            self.assertEqual(plan["balance"]["warning"], "", order)
            self.assertEqual(set(orders(plan).values()), {("A",) * (2 if order == "abba" else 1)}, order)
        path = self.protocol(between("g1", ["A"]))
        done = run(["session", "plan", path, "--subjects", 2], cwd=self.tmp)
        self.assert_one_error(done, (1, 2), "g1.json", "/phases/1")

    def test_more_groups_than_subjects(self):
        names = ["G1", "G2", "G3", "G4", "G5"]
        plan = self.plan(between("g5", names), 2)
        self.assertEqual([s["group"] for s in plan["subjects"]], ["G1", "G2"])
        self.assertEqual(plan["balance"]["square"], 5)
        levels = {level["level"]: level["subjects"] for level in plan["balance"]["factors"][0]["levels"]}
        self.assertEqual(levels, {"G1": 1, "G2": 1, "G3": 0, "G4": 0, "G5": 0})
        warning = plan["balance"]["warning"]
        for name in names:
            self.assertIn(name, warning)

    def test_an_odd_number_of_subjects_in_a_williams_crossover(self):
        plan = self.plan(crossover("x3odd", "ABC"), 3)
        self.assertEqual([s["sequence"] for s in plan["subjects"]], ["ABC", "BCA", "CAB"])
        for subject in plan["subjects"]:
            training = subject["sessions"][0]["phases"][1]
            self.assertEqual(sorted(b["set"] for b in training["blocks"]), ["s1", "s2", "s3"])
        self.assertEqual(plan["balance"]["square"], 18)
        self.assertIn("recruit a multiple of 18", plan["balance"]["warning"])

    def test_crossover_sets_of_other_sizes_or_counts(self):
        protocol = crossover("xs", "AB", sets=[[YI], [ER, SAN, SHI]])
        plan = self.plan(protocol, 2)
        for subject in plan["subjects"]:
            training = subject["sessions"][0]["phases"][1]
            self.assertEqual(training["trials"], 2 * 1 + 2 * 3)
        protocol["phases"][1]["sets"] = ["s1"]
        path = self.protocol(protocol, "xs-count.json")
        done = run(["session", "plan", path, "--subjects", 2], cwd=self.tmp)
        self.assert_one_error(done, (1, 2), "xs-count.json", "/phases/1")

    def test_session_run_prints_the_plan_session_plan_prints(self):
        protocol, _, done = SHARED["mixed"]
        printed = run(["session", "plan", protocol, "--subjects", 4], cwd=self.tmp)
        self.assertEqual(printed.returncode, 0)
        plan_text = printed.stdout.decode().strip().splitlines()
        self.assertTrue(plan_text)
        stderr = done.stderr.decode().strip().splitlines()
        self.assertEqual(stderr[:len(plan_text)], plan_text)


if __name__ == "__main__":
    unittest.main()
