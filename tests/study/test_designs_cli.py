#!/usr/bin/env python3
"""Every design docs/experiments.md describes, run as a laboratory would run it (`calligraphy session plan`,
then `session run` with simulated subjects on the simulated device), and checked subject by subject from the
files the run wrote: each subject's group, crossover sequence and set pairing, and per session each trial's
phase, condition, characters, item set, period and trained condition, against expectations written out here
from docs/experiments.md (not from the library's own output), and the plan `session plan` printed against
the session.json `session run` wrote. Run by CTest as `study_designs_cli`:

- the paper's design (a practice block, then the test blocks in a 2x2 Latin square);
- within-subjects blocks in an ABBA order;
- a between-subjects training over two days: pre-test, training, post-test, retention and a transfer test
  chosen by coverage, the group recorded in both sessions;
- a 2x2 crossover with pre-test, post-test (its characters listed, attributed to their sets), retention on
  day 2 and a transfer set;
- a Williams crossover of three conditions;
- a mixed design: a between-subjects familiarisation beside a crossover (each subject its group's one
  condition in practice, every group every sequence), and a between-subjects training on other characters
  beside one;
- random orders of conditions and characters, and groups drawn, run as the plan drew them;
- what is refused when the protocol is read (exit 2, one line naming the JSON pointer, nothing written): a
  second training of a crossover's set, a tested character of no set or of two, a transfer chosen by coverage
  beside a crossover;
- a balance no study can reach, said in the plan `session run` prints and in `session plan --json`, and the
  sequences still balanced subject by subject;
- a second `session run` of a two-session protocol into the same folder: it neither doubles nor loses a
  session, and `--new-subjects` goes on with the counterbalancing; a series whose first session was planned
  by another assignment rule is refused before its next session.

CALLIGRAPHY_CLI names the program. Standard library only.
"""
import json
import unittest
from pathlib import Path

from study_protocols import StudyCliTest, digest_tree, williams_row


# 10 s trials: the simulated writer ends most of its characters in 7-9 s. (Not run under the sanitizers:
# tests/CMakeLists.txt says why.)
TRIAL = {"max_duration_s": 10}


def crossover_of(conditions, sets, number, groups=1):
    """Subject `number`'s crossover (docs/experiments.md, "Crossover designs"): (sequence letters, the
    condition of each period, the set of each period, {set: (condition, period)}). With G = `groups`, the
    subject's group g = (n - 1) mod G and its place in the group j = (n - 1) // G give the cell m = j + g."""
    k = len(conditions)
    rows = k if k % 2 == 0 else 2 * k
    m = (number - 1) // groups + (number - 1) % groups
    order = williams_row(k, m % rows)
    rotation = (m // rows) % k
    period_sets = [sets[(i + rotation) % k] for i in order]
    trained = {s: (conditions[i], p + 1) for p, (i, s) in enumerate(zip(order, period_sets))}
    return "".join(chr(ord("A") + i) for i in order), [conditions[i] for i in order], period_sets, trained


class DesignsCliTest(StudyCliTest):
    folder_prefix = "calligraphy-designs-"

    def run_design(self, protocol, subjects, out="out"):
        """`session plan --json`, then `session run`; returns the plan and, per subject id, its sessions in
        order, each (session.json, {file stem: trial record})."""
        path = self.write_protocol(protocol)
        planned = self.run_cli("session", "plan", path, "--subjects", subjects, "--json")
        self.assertEqual(planned.returncode, 0, planned.stderr.decode())
        plan = json.loads(planned.stdout)
        run = self.run_cli("session", "run", path, "--writer", "simulated", "--subjects", subjects,
                           "--writer-learning", "none", "--out", out)
        self.assertEqual(run.returncode, 0, run.stderr.decode())
        self.run_stderr = run.stderr.decode()
        return plan, self.read_sessions(out, plan)

    def read_sessions(self, out, plan):
        written = {}
        for subject in plan["subjects"]:
            folders = [p for p in (self.cwd / out / subject["id"]).iterdir() if (p / "session.json").is_file()]
            sessions = []
            for folder in folders:
                manifest = json.loads((folder / "session.json").read_text(encoding="utf-8"))
                records = {p.name[:-len(".json")]: json.loads(p.read_text(encoding="utf-8"))
                           for p in (folder / "trials").glob("*.json")}
                sessions.append((manifest, records))
            sessions.sort(key=lambda s: s[0]["session_number"])
            written[subject["id"]] = sessions
        return written

    def check_run(self, plan, written, expected_trials):
        """Each subject's sessions hold exactly the trials `expected_trials(subject)` gives, per session a
        list of dicts of the fields to check, in order; every trial saved, its record's `trial` its plan entry;
        the plan `session plan` printed is what ran: the subject's group and sequence, each session's phases,
        blocks and trial counts."""
        for subject in plan["subjects"]:
            sessions = written[subject["id"]]
            expected = expected_trials(subject["number"])
            self.assertEqual(len(sessions), len(expected), subject["id"])
            self.assertEqual(len(subject["sessions"]), len(expected))
            for number, ((manifest, records), wanted, shown) in enumerate(
                    zip(sessions, expected, subject["sessions"]), start=1):
                where = f"{subject['id']} session {number}"
                self.assertEqual(manifest["session_number"], number, where)
                self.assertEqual(manifest["subject"]["number"], subject["number"], where)
                self.assertEqual(manifest.get("group", ""), subject["group"], where)
                trials = manifest["plan"]
                self.assertEqual(len(trials), len(wanted), where)
                self.assertEqual(shown["trials"], len(trials), where)
                for index, (trial, fields) in enumerate(zip(trials, wanted), start=1):
                    for key, value in fields.items():
                        self.assertEqual(trial.get(key, "" if key != "period" else None), value,
                                         f"{where} trial {index} {key}")
                    self.assertEqual(trial.get("sequence", ""), subject["sequence"], f"{where} trial {index}")
                    record = records[trial["file"]]
                    self.assertEqual(record["trial"], trial, f"{where} trial {index}")
                    self.assertEqual((record["phase"], record["condition"], record["characters"]),
                                     (trial["phase"], trial["condition"], trial["characters"]))
                self.assertEqual(len(records), len(trials), where)
                # The plan's blocks, phase by phase, are the conditions of the trials that ran.
                for phase in shown["phases"]:
                    ran = trials[phase["first_trial"] - 1:phase["first_trial"] - 1 + phase["trials"]]
                    self.assertEqual(ran[0]["index"], phase["first_trial"], where)
                    self.assertEqual({t["phase"] for t in ran}, {phase["phase"]}, where)
                    blocks = []
                    for t in ran:
                        if not blocks or blocks[-1][0] != t["block"]:
                            blocks.append((t["block"], t["condition"]))
                    self.assertEqual([b[1] for b in blocks], [b["condition"] for b in phase["blocks"]], where)

    # ------------------------------------------------------------------------------------------- designs

    def test_the_papers_design_practice_then_a_latin_square(self):
        protocol = {"name": "paper", "conditions": [{"name": "vision", "mode": "vision"},
                                                    {"name": "haptic", "mode": "haptic"}],
                    "practice": {"characters": ["口"], "condition": "haptic", "repetitions": 1},
                    "test": {"characters": ["十", "人"], "conditions": ["vision", "haptic"], "repetitions": 1},
                    "order": {"conditions": "latin_square"}, "trial": TRIAL}
        plan, written = self.run_design(protocol, 2)

        def expected(number):
            order = ["vision", "haptic"] if number % 2 == 1 else ["haptic", "vision"]
            trials = [{"phase": "practice", "condition": "haptic", "characters": "口", "block": 1}]
            for b, condition in enumerate(order, start=2):
                trials += [{"phase": "test", "condition": condition, "characters": c, "block": b,
                            "repetition": 1} for c in ("十", "人")]
            return [trials]

        self.check_run(plan, written, expected)
        phase = plan["subjects"][0]["sessions"][0]["phases"][0]
        self.assertEqual((phase["phase"], phase["pointer"]), ("practice", "/practice"))
        self.assertEqual(plan["balance"]["square"], 2)
        self.assertEqual(plan["balance"]["warning"], "")

    def test_within_subjects_blocks_in_an_abba_order(self):
        protocol = {"name": "abba", "conditions": [{"name": "A", "mode": "vision"}, {"name": "B", "mode": "haptic"}],
                    "test": {"characters": ["十"], "conditions": ["A", "B"], "repetitions": 2},
                    "order": {"conditions": "abba"}, "trial": TRIAL}
        plan, written = self.run_design(protocol, 2)

        def expected(number):
            order = "ABBA" if number % 2 == 1 else "BAAB"
            seen = {}
            trials = []
            for b, condition in enumerate(order, start=1):
                seen[condition] = seen.get(condition, 0) + 1
                trials.append({"phase": "test", "condition": condition, "block": b, "repetition": seen[condition]})
            return [trials]

        self.check_run(plan, written, expected)

    def test_between_subjects_training_over_two_days_with_retention_and_transfer(self):
        protocol = {"name": "between",
                    "conditions": [{"name": "free", "mode": "vision"}, {"name": "fixture", "mode": "haptic"},
                                   {"name": "fading", "mode": "fading"}],
                    "phases": [{"phase": "pre-test", "condition": "free", "characters": ["十"]},
                               {"phase": "training", "conditions": ["fixture", "fading"],
                                "assignment": "between-subjects", "characters": ["十", "口"]},
                               {"phase": "post-test", "condition": "free", "characters": ["十"], "delay_s": 5},
                               {"phase": "retention", "condition": "free", "characters": ["十"], "session": 2,
                                "delay_s": 86400},
                               {"phase": "transfer", "condition": "free", "session": 2,
                                "characters": {"choose": 1, "from": ["大", "山", "日"]}}],
                    "trial": TRIAL}
        plan, written = self.run_design(protocol, 3)
        self.assertEqual([s["group"] for s in plan["subjects"]], ["fixture", "fading", "fixture"])

        def expected(number):
            group = "fixture" if number % 2 == 1 else "fading"
            day1 = [{"phase": "pre-test", "condition": "free", "characters": "十"},
                    {"phase": "training", "condition": group, "characters": "十"},
                    {"phase": "training", "condition": group, "characters": "口"},
                    {"phase": "post-test", "condition": "free", "characters": "十", "break_before_s": 5}]
            # 十 and 口 trained: of 大, 山 and 日 only 日 is made of their typical strokes (docs/experiments.md).
            day2 = [{"phase": "retention", "condition": "free", "characters": "十"},
                    {"phase": "transfer", "condition": "free", "characters": "日"}]
            return [day1, day2]

        self.check_run(plan, written, expected)
        self.assertIn("N=3 does not fill the counterbalancing square of 2 subjects", self.run_stderr)

    def crossover_protocol(self, k, name, post_test_characters=False, practice_groups=None):
        conditions = [{"name": "A", "mode": "vision"}, {"name": "B", "mode": "error-amplification"},
                      {"name": "C", "mode": "haptic"}][:k]
        sets = [{"name": f"s{i + 1}", "characters": [c]} for i, c in enumerate(["十", "人", "口"][:k])]
        names = [s["name"] for s in sets]
        phases = []
        if practice_groups:
            phases.append({"phase": "practice", "conditions": practice_groups, "assignment": "between-subjects",
                           "characters": ["大"]})
        phases += [{"phase": "pre-test", "condition": "A", "sets": names},
                   {"phase": "training", "conditions": [c["name"] for c in conditions], "assignment": "crossover",
                    "sets": names, "repetitions": 2},
                   {"phase": "post-test", "condition": "A", "delay_s": 5,
                    **({"characters": [s["characters"][0] for s in sets]} if post_test_characters
                       else {"sets": names})}]
        return {"name": name, "conditions": conditions, "item_sets": sets, "phases": phases, "trial": TRIAL}

    @staticmethod
    def crossover_trials(conditions, sets, characters, number, groups=1, tests=("pre-test", "post-test")):
        """The trials of one session of a pre-test, crossover (2 repetitions) and post-test design."""
        _, period_conditions, period_sets, trained = crossover_of(conditions, sets, number, groups)

        def tested(phase):
            return [{"phase": phase, "condition": "A", "characters": characters[s], "item_set": s,
                     "trained_condition": trained[s][0], "period": trained[s][1]} for s in sets]

        trials = tested(tests[0])
        for condition, s in zip(period_conditions, period_sets):
            trials += [{"phase": "training", "condition": condition, "characters": characters[s], "item_set": s,
                        "trained_condition": condition, "period": trained[s][1], "repetition": r}
                       for r in (1, 2)]
        return trials + tested(tests[1])

    def test_a_2x2_crossover_with_retention_on_day_2_and_a_transfer_set(self):
        protocol = self.crossover_protocol(2, "crossover2", post_test_characters=True)
        protocol["item_sets"].append({"name": "t1", "characters": ["大"], "transfer_of": "s1"})
        protocol["phases"] += [{"phase": "retention", "condition": "A", "sets": ["s1", "s2"], "session": 2,
                                "delay_s": 86400},
                               {"phase": "transfer", "condition": "A", "sets": ["t1"], "session": 2}]
        plan, written = self.run_design(protocol, 4)
        characters = {"s1": "十", "s2": "人", "t1": "大"}
        self.assertEqual([s["sequence"] for s in plan["subjects"]], ["AB", "BA", "AB", "BA"])
        self.assertEqual([s["set_pairing"] for s in plan["subjects"]],
                         ["A:s1 B:s2", "A:s1 B:s2", "A:s2 B:s1", "A:s2 B:s1"])
        # The post-test lists characters: each is attributed to the set holding it, as a post-test of sets.
        post = plan["subjects"][0]["sessions"][0]["phases"][2]
        self.assertEqual((post["sets"], post["item_sets"]), ([], ["s1", "s2"]))

        def expected(number):
            day1 = self.crossover_trials(["A", "B"], ["s1", "s2"], characters, number)
            _, _, _, trained = crossover_of(["A", "B"], ["s1", "s2"], number)
            day2 = [{"phase": "retention", "item_set": s, "characters": characters[s],
                     "trained_condition": trained[s][0], "period": trained[s][1]} for s in ("s1", "s2")]
            day2.append({"phase": "transfer", "item_set": "t1", "characters": "大",
                         "trained_condition": trained["s1"][0], "period": trained["s1"][1]})
            return [day1, day2]

        self.check_run(plan, written, expected)
        self.assertEqual(plan["balance"]["warning"], "")

    def test_a_williams_crossover_of_three_conditions(self):
        protocol = self.crossover_protocol(3, "williams")
        plan, written = self.run_design(protocol, 6)
        self.assertEqual([s["sequence"] for s in plan["subjects"]], ["ABC", "BCA", "CAB", "CBA", "ACB", "BAC"])
        characters = {"s1": "十", "s2": "人", "s3": "口"}
        self.check_run(plan, written, lambda number: [
            self.crossover_trials(["A", "B", "C"], ["s1", "s2", "s3"], characters, number)])
        self.assertIn("N=6 does not fill the counterbalancing square of 18 subjects", plan["balance"]["warning"])

    def test_a_mixed_design_a_between_subjects_familiarisation_beside_a_crossover(self):
        protocol = self.crossover_protocol(2, "mixed", practice_groups=["A", "B"])
        plan, written = self.run_design(protocol, 8)
        groups = [s["group"] for s in plan["subjects"]]
        self.assertEqual(groups, ["A", "B"] * 4)
        characters = {"s1": "十", "s2": "人"}

        def expected(number):
            group = "A" if number % 2 == 1 else "B"
            practice = [{"phase": "practice", "condition": group, "characters": "大", "item_set": "",
                         "block": 1}]
            return [practice + self.crossover_trials(["A", "B"], ["s1", "s2"], characters, number, groups=2)]

        self.check_run(plan, written, expected)
        # Every group gets every sequence and pairing over its 4 subjects, and the sequences alternate over all.
        cells = {}
        for subject in plan["subjects"]:
            cells.setdefault(subject["group"], []).append((subject["sequence"], subject["set_pairing"]))
        for group, seen in cells.items():
            self.assertEqual(len(set(seen)), 4, group)
        self.assertEqual([s["sequence"] for s in plan["subjects"][:4]].count("AB"), 2)
        self.assertEqual(plan["balance"]["square"], 8)
        self.assertEqual(plan["balance"]["warning"], "")
        # The tables carry each subject's group (the analysis reads them there).
        tables = self.cwd / "tables"
        tables.mkdir()
        report = self.run_cli("report", "out", "--csv", tables)
        self.assertEqual(report.returncode, 0, report.stderr.decode())
        lines = (tables / "trials.csv").read_text(encoding="utf-8").splitlines()
        header = lines[0].split(",")
        rows = [dict(zip(header, line.split(","))) for line in lines[1:]]
        self.assertEqual(len(rows), 8 * (1 + 2 + 4 + 2))
        for row in rows:
            self.assertEqual(row["group"], "A" if int(row["subject"][1:]) % 2 == 1 else "B")
            if row["phase"] == "practice":
                self.assertEqual(row["condition"], row["group"])

    def test_a_mixed_design_a_between_subjects_training_on_other_characters_beside_a_crossover(self):
        protocol = self.crossover_protocol(2, "mixed-training")
        protocol["conditions"] += [{"name": "F", "mode": "haptic"}, {"name": "G", "mode": "fading"},
                                   {"name": "H", "mode": "vision"}]
        protocol["phases"].insert(1, {"phase": "training", "conditions": ["F", "G", "H"],
                                      "assignment": "between-subjects", "characters": ["大"]})
        plan, written = self.run_design(protocol, 6)
        self.assertEqual([s["group"] for s in plan["subjects"]], ["F", "G", "H"] * 2)
        characters = {"s1": "十", "s2": "人"}

        def expected(number):
            trials = self.crossover_trials(["A", "B"], ["s1", "s2"], characters, number, groups=3)
            group = "FGH"[(number - 1) % 3]
            # After the pre-test (2 trials), the group's training on a character of no set.
            return [trials[:2] + [{"phase": "training", "condition": group, "characters": "大", "item_set": "",
                                   "trained_condition": "", "period": None}] + trials[2:]]

        self.check_run(plan, written, expected)
        # G = 3 groups beside a 2x2 crossover: every 12 subjects; the first 6 alternate the sequences.
        self.assertEqual(plan["balance"]["square"], 12)
        self.assertEqual([s["sequence"] for s in plan["subjects"]].count("AB"), 3)

    def test_random_orders_and_drawn_groups_are_run_as_planned(self):
        protocol = {"name": "drawn", "conditions": [{"name": "A", "mode": "vision"}, {"name": "B", "mode": "haptic"},
                                                    {"name": "C", "mode": "fading"}],
                    "phases": [{"phase": "pre-test", "conditions": ["A", "B", "C"], "characters": ["十", "人"]},
                               {"phase": "training", "conditions": ["B", "C"], "assignment": "between-subjects",
                                "characters": ["十"]}],
                    "order": {"conditions": "random", "characters": "random", "seed": 7}, "trial": TRIAL}
        plan, written = self.run_design(protocol, 3)
        self.assertTrue(plan["balance"]["drawn"])
        # The orders and groups are drawn per subject; what ran is what the plan drew, each condition once, each
        # round every character once, the training in the subject's group.
        orders = []
        for subject in plan["subjects"]:
            self.assertIn(subject["group"], ("B", "C"))
            pre_test = subject["sessions"][0]["phases"][0]
            order = [b["condition"] for b in pre_test["blocks"]]
            self.assertEqual(sorted(order), ["A", "B", "C"])
            orders.append(order)

            def expected(number, order=order, group=subject["group"], id=subject["id"]):
                manifest, _ = written[id][0]
                characters = [t["characters"] for t in manifest["plan"]]
                trials = []
                for b, condition in enumerate(order):
                    self.assertEqual(sorted(characters[2 * b:2 * b + 2]), ["人", "十"])
                    trials += [{"phase": "pre-test", "condition": condition, "block": b + 1,
                                "characters": characters[2 * b + i]} for i in (0, 1)]
                return [trials + [{"phase": "training", "condition": group, "characters": "十"}]]

            self.check_run({**plan, "subjects": [subject]}, written, expected)
        # Drawn again for the same ids, the same orders.
        self.assertEqual([[b["condition"] for b in s["sessions"][0]["phases"][0]["blocks"]]
                          for s in self.plan_again("drawn.json", 3)["subjects"]], orders)

    def plan_again(self, name, subjects):
        again = self.run_cli("session", "plan", self.cwd / name, "--subjects", subjects, "--json")
        self.assertEqual(again.returncode, 0, again.stderr.decode())
        return json.loads(again.stdout)

    # ----------------------------------------------------------------------------------------- refusals

    def refused(self, protocol, pointer, *words):
        path = self.write_protocol(protocol)
        for command in (["session", "plan", path, "--subjects", 2],
                        ["session", "run", path, "--writer", "simulated", "--subjects", 2, "--out", "out"]):
            result = self.run_cli(*command)
            self.assertEqual(result.returncode, 2, result.stderr.decode())
            lines = result.stderr.decode().strip().splitlines()
            self.assertEqual(len(lines), 1, lines)
            self.assertIn(f"{path.name}: {pointer}: ", lines[0])
            for word in words:
                self.assertIn(word, lines[0])
            self.assertFalse((self.cwd / "out").exists())

    def test_a_second_training_of_a_crossover_set_is_refused_naming_its_pointer(self):
        protocol = self.crossover_protocol(2, "twice")
        protocol["phases"].insert(2, {"phase": "training", "conditions": ["A", "B"],
                                      "assignment": "between-subjects", "sets": ["s2"]})
        self.refused(protocol, "/phases/2/sets/0", 'the item set "s2" is trained in the crossover phase /phases/1')
        protocol["phases"][2] = {"phase": "training", "condition": "B", "characters": ["口", "十"]}
        self.refused(protocol, "/phases/2/characters/1", '"十" is in the item set "s1"')

    def test_a_tested_character_of_no_set_or_of_two_is_refused_beside_a_crossover(self):
        protocol = self.crossover_protocol(2, "unset", post_test_characters=True)
        protocol["phases"][2]["characters"] = ["十", "大"]
        self.refused(protocol, "/phases/2/characters/1", '"大" is in no item set')
        protocol["phases"][2]["characters"] = ["十人"]
        self.refused(protocol, "/phases/2/characters/0", 'holds characters of the item sets "s1" and "s2"')
        protocol["phases"][2] = {"phase": "post-test", "condition": "A", "sets": ["s1", "s2"]}
        protocol["phases"].append({"phase": "transfer", "condition": "A",
                                   "characters": {"choose": 1, "from": ["大", "山"]}})
        self.refused(protocol, "/phases/3/characters", "chosen by coverage are in no set")

    # ------------------------------------------------------------------------------------------ balance

    def test_a_balance_no_study_reaches_is_said_and_the_sequences_still_alternate(self):
        # Between-subjects phases of 23, 25 and 26 conditions repeat their groups every 14,950 subjects: with
        # a 2x2 crossover a full square is 59,800.
        conditions = [{"name": f"c{i}", "mode": "vision"} for i in range(1, 27)]
        names = [c["name"] for c in conditions]
        protocol = {"name": "huge", "conditions": conditions,
                    "item_sets": [{"name": "s1", "characters": ["十"]}, {"name": "s2", "characters": ["人"]}],
                    "phases": [{"phase": "practice", "conditions": names, "assignment": "between-subjects",
                                "characters": ["口"]},
                               {"phase": "training", "conditions": names[:23], "assignment": "between-subjects",
                                "characters": ["大"]},
                               {"phase": "training", "conditions": names[:25], "assignment": "between-subjects",
                                "characters": ["山"]},
                               {"phase": "training", "conditions": ["c1", "c2"], "assignment": "crossover",
                                "sets": ["s1", "s2"]}],
                    "trial": TRIAL}
        plan, written = self.run_design(protocol, 4)
        balance = plan["balance"]
        self.assertEqual((balance["square"], balance["reachable"], balance["filled"]), (59800, False, False))
        self.assertIn("a full counterbalancing square is 59,800 subjects (the between-subjects groups alone "
                      "repeat every 14,950), more than any study can recruit", balance["warning"])
        self.assertIn("group: 14,946 of its 14,950 levels with 0 subjects, 4 with 1", balance["warning"])
        self.assertLess(len(balance["warning"]), 400)
        warnings = [line for line in self.run_stderr.splitlines() if line.startswith("warning: ")]
        self.assertEqual(warnings, ["warning: " + balance["warning"]])
        self.assertEqual([s["sequence"] for s in plan["subjects"]], ["AB", "BA", "AB", "BA"])
        self.assertEqual([s["group"] for s in plan["subjects"]], [f"c{n}/c{n}/c{n}" for n in range(1, 5)])
        characters = {"s1": "十", "s2": "人"}

        def expected(number):
            name = f"c{number}"
            _, period_conditions, period_sets, trained = crossover_of(["c1", "c2"], ["s1", "s2"], number, 14950)
            trials = [{"phase": "practice", "condition": name, "characters": "口"},
                      {"phase": "training", "condition": name, "characters": "大"},
                      {"phase": "training", "condition": name, "characters": "山"}]
            trials += [{"phase": "training", "condition": c, "item_set": s, "characters": characters[s],
                        "trained_condition": c, "period": trained[s][1]}
                       for c, s in zip(period_conditions, period_sets)]
            return [trials]

        self.check_run(plan, written, expected)

    # ------------------------------------------------------------------------------------- a second run

    def test_a_second_run_of_a_two_session_design_neither_doubles_nor_loses_a_session(self):
        protocol = self.crossover_protocol(2, "days")
        protocol["phases"].append({"phase": "retention", "condition": "A", "sets": ["s1", "s2"], "session": 2,
                                   "delay_s": 86400})
        self.run_design(protocol, 2)
        before = digest_tree(self.cwd / "out")
        self.assertEqual(sum(1 for name in before if name.endswith("session.json")), 4)
        path = self.cwd / "days.json"
        again = self.run_cli("session", "run", path, "--writer", "simulated", "--subjects", 2,
                             "--writer-learning", "none", "--out", "out")
        self.assertEqual(again.returncode, 0, again.stderr.decode())
        for subject in ("S01", "S02"):
            self.assertIn(f"{subject}: every session of days is done (2)", again.stdout.decode())
        self.assertEqual(digest_tree(self.cwd / "out"), before)
        # Further subjects go on with the counterbalancing: S03 and S04 are numbers 3 and 4.
        more = self.run_cli("session", "run", path, "--writer", "simulated", "--subjects", 2, "--new-subjects",
                            "--writer-learning", "none", "--out", "out")
        self.assertEqual(more.returncode, 0, more.stderr.decode())
        self.assertIn("balance: with the 2 subjects before them", more.stderr.decode())
        after = digest_tree(self.cwd / "out")
        subjects = ("S01", "S02")  # the study folder also holds the run lock (docs/cli.md), empty between runs
        self.assertEqual({k: v for k, v in after.items() if k.split("/")[0] in subjects},
                         {k: v for k, v in before.items() if k.split("/")[0] in subjects})
        for subject, number in (("S03", 3), ("S04", 4)):
            folders = sorted(p for p in (self.cwd / "out" / subject).iterdir() if p.is_dir())
            self.assertEqual(len(folders), 2)
            for folder in folders:
                manifest = json.loads((folder / "session.json").read_text(encoding="utf-8"))
                self.assertEqual(manifest["subject"]["number"], number)
                sequence, _, _, trained = crossover_of(["A", "B"], ["s1", "s2"], number)
                for trial in manifest["plan"]:
                    self.assertEqual(trial["sequence"], sequence)
                    self.assertEqual(trial["trained_condition"], trained[trial["item_set"]][0])

    def test_a_series_planned_by_another_assignment_is_refused_before_its_next_session(self):
        # Session 1 of a two-day mixed design as an earlier rule planned it (every subject of the first G in
        # sequence AB): its session 2 would put S02 in another sequence, and is refused naming session 1.
        protocol = self.crossover_protocol(2, "earlier", practice_groups=["A", "B"])
        protocol["phases"].append({"phase": "retention", "condition": "A", "sets": ["s1", "s2"], "session": 2,
                                   "delay_s": 86400})
        self.run_design(protocol, 2)
        (first, second) = sorted(p for p in (self.cwd / "out" / "S02").iterdir() if p.is_dir())
        for file in sorted(second.rglob("*"), reverse=True):
            file.unlink() if file.is_file() else file.rmdir()
        second.rmdir()
        manifest_file = first / "session.json"
        manifest = json.loads(manifest_file.read_text(encoding="utf-8"))
        self.assertEqual({t["sequence"] for t in manifest["plan"]}, {"BA"})
        for trial in manifest["plan"]:
            trial["sequence"] = "AB"
        manifest_file.write_text(json.dumps(manifest, ensure_ascii=False), encoding="utf-8")
        before = digest_tree(self.cwd / "out")
        again = self.run_cli("session", "run", self.cwd / "earlier.json", "--writer", "simulated", "--subjects", 2,
                             "--writer-learning", "none", "--out", "out")
        self.assertEqual(again.returncode, 1, again.stderr.decode())
        message = again.stderr.decode()
        self.assertIn(str(Path("out") / "S02" / first.name / "session.json"), message)
        self.assertIn("was planned with group 'B' and sequence 'AB', but the protocol now assigns subject number 2 "
                      "group 'B' and sequence 'BA'", message)
        self.assertEqual(digest_tree(self.cwd / "out"), before)


if __name__ == "__main__":
    unittest.main()
