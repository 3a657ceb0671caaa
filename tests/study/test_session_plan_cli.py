#!/usr/bin/env python3
"""`calligraphy session plan` and a second `session run` into one study folder, end to end (docs/cli.md,
"session plan" and "session run | resume"), run by CTest as `study_session_plan_cli`:

- the plan, subject by subject, of a between-subjects design, a 2x2 crossover and a three-condition Williams
  crossover, checked against the balanced Latin square written out here (not against the library's own
  output) and against the session.json that `session run` then writes;
- the balance warning for an N that does not fill the counterbalancing square;
- a second `session run` of a one-session protocol into the same folder is refused (exit 2, one line naming
  the subjects and --new-subjects) and changes nothing; --new-subjects adds subjects numbered after them;
- a session 1 of one subject found twice is refused by `report` (and by `calligraphy.study.load` when the
  module is importable), naming the subject and both folders.

CALLIGRAPHY_CLI names the program, CALLIGRAPHY_SOURCE_DIR the source tree. Standard library only (the
Python module is optional).
"""
import json
import os
import shutil
import unittest
from pathlib import Path

from study_protocols import StudyCliTest, digest_tree, williams_row

SOURCE = Path(os.environ.get("CALLIGRAPHY_SOURCE_DIR", Path(__file__).resolve().parents[2]))

CONDITIONS = [{"name": "A", "mode": "vision"}, {"name": "B", "mode": "haptic"}, {"name": "C", "mode": "vision"}]


def between_protocol():
    """Three training groups between subjects, tested before and after on one character; 10 s trials."""
    return {"name": "between", "conditions": CONDITIONS,
            "phases": [{"phase": "pre-test", "condition": "A", "characters": ["十"]},
                       {"phase": "training", "conditions": ["A", "B", "C"], "assignment": "between-subjects",
                        "characters": ["十"], "repetitions": 2},
                       {"phase": "post-test", "condition": "A", "characters": ["十"], "delay_s": 30}],
            "trial": {"max_duration_s": 10}}


def crossover_protocol(k):
    """A crossover of k conditions on k one-character sets, tested before; 10 s trials."""
    sets = [{"name": f"s{i + 1}", "characters": [c]} for i, c in enumerate(["十", "人", "口"][:k])]
    names = [s["name"] for s in sets]
    return {"name": f"crossover{k}", "conditions": CONDITIONS[:k], "item_sets": sets,
            "phases": [{"phase": "pre-test", "condition": "A", "sets": names},
                       {"phase": "training", "conditions": [c["name"] for c in CONDITIONS[:k]],
                        "assignment": "crossover", "sets": names}],
            "trial": {"max_duration_s": 10}}


def williams_letters(n, row):
    """Row `row` of the balanced Latin square of n conditions as letters (A the first condition)."""
    return "".join(chr(ord("A") + i) for i in williams_row(n, row))


def expected_crossover(k, number):
    """Sequence and each letter's set for subject `number` (docs/experiments.md, "Crossover designs")."""
    rows = k if k % 2 == 0 else 2 * k
    sequence = williams_letters(k, (number - 1) % rows)
    rotation = ((number - 1) // rows) % k
    pairing = " ".join(f"{chr(ord('A') + i)}:s{(i + rotation) % k + 1}" for i in range(k))
    return sequence, pairing


class SessionPlanCliTest(StudyCliTest):
    folder_prefix = "calligraphy-plan-"

    def plan(self, protocol, subjects):
        result = self.run_cli("session", "plan", protocol, "--subjects", subjects, "--json")
        self.assertEqual(result.returncode, 0, result.stderr.decode())
        return json.loads(result.stdout)

    def run_subjects(self, protocol, subjects, *more):
        return self.run_cli("session", "run", protocol, "--writer", "simulated", "--subjects", subjects,
                            "--writer-learning", "none", "--out", "out", *more)

    def session_json(self, subject):
        found = [p for p in (self.cwd / "out" / subject).iterdir() if (p / "session.json").is_file()]
        self.assertEqual(len(found), 1, f"{subject}: {found}")
        return json.loads((found[0] / "session.json").read_text(encoding="utf-8"))

    def test_between_subjects_groups_in_turn_and_the_warning(self):
        protocol = self.write_protocol(between_protocol())
        plan = self.plan(protocol, 4)
        self.assertEqual([s["id"] for s in plan["subjects"]], ["S01", "S02", "S03", "S04"])
        self.assertEqual([s["group"] for s in plan["subjects"]], ["A", "B", "C", "A"])
        for subject in plan["subjects"]:
            self.assertEqual(subject["sequence"], "")
            (session,) = subject["sessions"]
            phases = session["phases"]
            self.assertEqual([p["phase"] for p in phases], ["pre-test", "training", "post-test"])
            self.assertEqual(phases[1]["blocks"], [{"condition": subject["group"], "set": ""}])
            self.assertEqual([p["trials"] for p in phases], [1, 2, 1])
            self.assertEqual(session["trials"], 4)
            self.assertEqual(session["rest_s"], 30)
            self.assertEqual(session["max_duration_s"], 4 * 10 + 30)
        balance = plan["balance"]
        self.assertEqual(balance["square"], 3)
        self.assertFalse(balance["filled"])
        self.assertIn("N=4 does not fill the counterbalancing square of 3 subjects", balance["warning"])
        self.assertIn("group B with 1 subject, C with 1 and A with 2", balance["warning"])
        text = self.run_cli("session", "plan", protocol, "--subjects", 3)
        self.assertEqual(text.returncode, 0, text.stderr.decode())
        self.assertIn("S03 (number 3): group C", text.stdout.decode())
        self.assertNotIn("warning", text.stdout.decode())

    def test_a_2x2_crossover_subject_by_subject_as_run(self):
        protocol = self.write_protocol(crossover_protocol(2))
        plan = self.plan(protocol, 5)
        for number, subject in enumerate(plan["subjects"], start=1):
            sequence, pairing = expected_crossover(2, number)
            self.assertEqual((subject["sequence"], subject["set_pairing"]), (sequence, pairing), number)
            training = subject["sessions"][0]["phases"][1]
            sets = dict(part.split(":") for part in pairing.split())
            self.assertEqual(training["blocks"], [{"condition": c, "set": sets[c]} for c in sequence])
        self.assertEqual(plan["balance"]["square"], 4)
        self.assertIn("sequence BA with 2 subjects and AB with 3", plan["balance"]["warning"])
        self.assertEqual(self.plan(protocol, 4)["balance"]["warning"], "")
        # What `session run` writes is what the plan said, and the run prints the plan first (stderr).
        run = self.run_subjects(protocol, 5)
        self.assertEqual(run.returncode, 0, run.stderr.decode())
        stderr = run.stderr.decode()
        self.assertIn("plan of crossover2", stderr)
        self.assertIn("warning: N=5 does not fill", stderr)
        for subject in plan["subjects"]:
            manifest = self.session_json(subject["id"])
            trials = manifest["plan"]
            self.assertEqual(len(trials), subject["sessions"][0]["trials"])
            self.assertEqual({t["sequence"] for t in trials}, {subject["sequence"]})

    def test_a_williams_crossover_of_three_conditions(self):
        protocol = self.write_protocol(crossover_protocol(3))
        plan = self.plan(protocol, 7)
        sequences = [s["sequence"] for s in plan["subjects"]]
        self.assertEqual(sequences, ["ABC", "BCA", "CAB", "CBA", "ACB", "BAC", "ABC"])
        for number, subject in enumerate(plan["subjects"], start=1):
            self.assertEqual((subject["sequence"], subject["set_pairing"]), expected_crossover(3, number))
            self.assertEqual(subject["sessions"][0]["trials"], 3 + 3)
        balance = plan["balance"]
        self.assertEqual(balance["square"], 18)
        self.assertIn("N=7 does not fill the counterbalancing square of 18 subjects", balance["warning"])
        self.assertIn("sequence BCA with 1 subject", balance["warning"])
        self.assertEqual(self.plan(protocol, 18)["balance"]["warning"], "")

    def test_a_second_run_neither_doubles_nor_loses_a_session(self):
        protocol = self.write_protocol(between_protocol())
        first = self.run_subjects(protocol, 2)
        self.assertEqual(first.returncode, 0, first.stderr.decode())
        before = digest_tree(self.cwd / "out")
        second = self.run_subjects(protocol, 2)
        self.assertEqual(second.returncode, 2, second.stderr.decode())
        lines = second.stderr.decode().strip().splitlines()
        self.assertEqual(len(lines), 1, lines)
        self.assertIn("S01, S02", lines[0])
        self.assertIn("--new-subjects", lines[0])
        self.assertEqual(digest_tree(self.cwd / "out"), before)
        # --new-subjects goes on with S03, numbered 3 (the next group), and leaves S01 and S02 as they were.
        more = self.run_subjects(protocol, 1, "--new-subjects")
        self.assertEqual(more.returncode, 0, more.stderr.decode())
        # The balance is the study's: S01 to S03, one in each of the three groups.
        self.assertIn("balance: with the 2 subjects before them", more.stderr.decode())
        self.assertNotIn("warning", more.stderr.decode())
        manifest = self.session_json("S03")
        self.assertEqual(manifest["subject"]["number"], 3)
        self.assertEqual({t["condition"] for t in manifest["plan"] if t["phase"] == "training"}, {"C"})
        after = digest_tree(self.cwd / "out")
        self.assertEqual({k: v for k, v in after.items() if not k.startswith("S03/")}, before)
        for subject in ("S01", "S02", "S03"):
            self.session_json(subject)  # one session folder each
        tables = self.cwd / "tables"
        tables.mkdir()
        report = self.run_cli("report", "out", "--csv", tables)
        self.assertEqual(report.returncode, 0, report.stderr.decode())
        rows = (tables / "trials.csv").read_text(encoding="utf-8").strip().splitlines()
        self.assertEqual(len(rows) - 1, 3 * 4)

    def test_a_session_found_twice_is_refused_by_the_readers(self):
        protocol = self.write_protocol(between_protocol())
        run = self.run_subjects(protocol, 1)
        self.assertEqual(run.returncode, 0, run.stderr.decode())
        (session,) = [p for p in (self.cwd / "out" / "S01").iterdir() if p.is_dir()]
        # What runs before this refusal left behind: a second session 1 of S01 started later.
        twin = session.with_name(session.name + "-again")
        shutil.copytree(session, twin)
        manifest = json.loads((twin / "session.json").read_text(encoding="utf-8"))
        manifest["created_utc"] = "2099-01-01T00:00:00Z"
        (twin / "session.json").write_text(json.dumps(manifest, ensure_ascii=False), encoding="utf-8")
        tables = self.cwd / "tables"
        tables.mkdir()
        report = self.run_cli("report", "out", "--csv", tables)
        self.assertEqual(report.returncode, 1)
        message = report.stderr.decode()
        self.assertIn("subject S01 has session 1 of protocol 'between' twice", message)
        self.assertIn(str(Path("out") / "S01" / session.name), message)
        self.assertIn(str(Path("out") / "S01" / twin.name), message)
        self.assertFalse((tables / "trials.csv").exists())
        try:
            import calligraphy.study as study
        except ImportError:
            return  # the module is not built: the C++ reader it uses is the one checked above
        with self.assertRaises(Exception) as caught:
            study.load(self.cwd / "out")
        self.assertIn("subject S01 has session 1 of protocol 'between' twice", str(caught.exception))


if __name__ == "__main__":
    unittest.main()
