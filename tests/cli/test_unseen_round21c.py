#!/usr/bin/env python3
"""Round 21C: does `curriculum` propose what its docs say, and `characters` list what it says? From the docs
alone (docs/cli.md "curriculum", "characters", "strokes", "model"; docs/experiments.md "What to practise next";
docs/python.md `study.propose_characters`; each command's --help).

Earlier rounds fed `curriculum` damaged study folders; this one recomputes its proposal from the documented rule
(greedily the candidate bringing the most typical strokes the learner never wrote, 2 each, and that it writes
worst, 1 each: a mean deviation above the median of its typical strokes; ties to fewer strokes; characters
written not proposed; candidates adding nothing left out) from a tiny study's tables (`report --csv`
strokes.csv) and the candidates' typical strokes (`characters --json`), for one subject of two, a study where
nothing was written, ties, everything learnt, every option at and past its bounds, text against JSON, and
Python's `propose_characters` against the command. `characters` is held to its filters: each listed character
has what was asked (against the Python module's own load of the character and `model --json`), none missing
(a sample of the library), counts the same between the table and the JSON, a text of mixed scripts, repeats,
characters outside the library, combining marks and a surrogate forged as UTF-8 bytes.

CALLIGRAPHY_CLI names the program, PYTHONPATH its Python module. CALLIGRAPHY_SANITIZED=1 takes five cases.
"""
import csv
import json
import os
import random
import shutil
import statistics
import subprocess
import tempfile
import unittest
from pathlib import Path

from outsider import OneErrorLine, run, run_ok, sanitized_subset

load_tests = sanitized_subset({"test_proposal_follows_the_documented_rule_for_the_first_subject",
                               "test_text_and_json_propose_the_same",
                               "test_count_past_its_bounds_is_a_usage_error_naming_it",
                               "test_typical_stroke_forms_give_one_list",
                               "test_text_of_mixed_scripts_lists_each_character_once_and_names_the_rest"})

SIM = ["--writer", "simulated", "--writer-learning", "none"]
WRITTEN = "一十人八口小"
# Candidates of the study's proposals: common small characters, some sharing strokes with what was written.
POOL = "二三大天木山中日千女子水火王土工心月力七九了也东马长风"


def protocol(name, characters, max_duration_s):
    return {"name": name, "conditions": [{"name": "V", "mode": "vision"}],
            "test": {"characters": list(characters), "conditions": ["V"], "repetitions": 1},
            "trial": {"max_duration_s": max_duration_s}}


def read_strokes(tables):
    with open(tables / "strokes.csv", newline="", encoding="utf-8") as f:
        return list(csv.DictReader(f))


class Round21C(unittest.TestCase, OneErrorLine):
    @classmethod
    def setUpClass(cls):
        cls.tmp = Path(tempfile.mkdtemp(prefix="round21c-"))
        t = cls.tmp
        # Two simulated subjects (own skills, so own weak strokes) write six small characters whole; a third
        # study's subject has half a second for 十: a trial saved, no stroke written.
        (t / "a.json").write_text(json.dumps(protocol("a", WRITTEN, 12)), encoding="utf-8")
        (t / "b.json").write_text(json.dumps(protocol("b", "十", 0.5)), encoding="utf-8")
        run_ok(["session", "run", "a.json", "--subjects", "2", "--subject", "S", "--out", "sa", *SIM], t)
        run_ok(["session", "run", "b.json", "--subject", "S01", "--out", "sb", *SIM], t)
        rows = {}
        for study in ("sa", "sb"):
            (t / f"csv-{study}").mkdir()
            run_ok(["report", study, "--csv", f"csv-{study}"], t)
            rows[study] = read_strokes(t / f"csv-{study}")
        cls.rows = rows
        cls.all = json.loads(run_ok(["characters", "--json"], t).stdout)
        cls.by_char = {c["character"]: c for c in cls.all["characters"]}
        cls.table = json.loads(run_ok(["strokes", "--json"], t).stdout)

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.tmp, ignore_errors=True)

    # --- the documented rule, recomputed -------------------------------------------------------------------

    def learner(self, study, subject):
        """(typical strokes written, weak ones, characters written) of `subject` from the study's strokes.csv:
        a typical stroke's mean deviation over its written strokes; weak above the median of those means."""
        rows = [r for r in self.rows[study] if r["subject"] == subject]
        devs = {}
        for r in rows:
            if r["written"] == "TRUE":
                devs.setdefault(int(r["typical_id"]), []).append(float(r["mean_deviation_m"]))
        means = {k: statistics.fmean(v) for k, v in devs.items()}
        median = statistics.median(means.values()) if means else 0.0
        weak = {k for k, m in means.items() if m > median}
        return set(means), weak, {r["character_text"] for r in rows}

    def expected(self, study, subject, candidates, count=3):
        written, weak, chars = self.learner(study, subject)
        covered, weak_left, chosen, order = set(written), set(weak), [], []
        for c in candidates:
            if c not in chars and c not in order:
                order.append(c)
        while len(chosen) < count:
            best = None
            for i, c in enumerate(order):
                if c in [x["character"] for x in chosen]:
                    continue
                ids = set(self.by_char[c]["typical_ids"])
                new, again = ids - covered, ids & weak_left
                key = (-(2 * len(new) + len(again)), self.by_char[c]["strokes"], i)
                if 2 * len(new) + len(again) > 0 and (best is None or key < best[0]):
                    best = (key, c, new, again)
            if best is None:
                break
            _, c, new, again = best
            chosen.append({"character": c, "new_strokes": sorted(new), "weak_strokes": sorted(again)})
            covered |= new
            weak_left -= again
        return chosen

    def proposal(self, study, subject, candidates, *extra):
        r = run_ok(["curriculum", study, "--subject", subject, "--from", candidates, "--json", *extra], self.tmp)
        got = json.loads(r.stdout)
        return [{"character": p["character"], "new_strokes": sorted(p["new_strokes"]),
                 "weak_strokes": sorted(p["weak_strokes"])} for p in got]

    def test_proposal_follows_the_documented_rule_for_the_first_subject(self):
        self.assertEqual(self.proposal("sa", "S01", POOL, "--count", "8"), self.expected("sa", "S01", POOL, 8))

    def test_second_subject_of_the_study_gets_its_own_proposal(self):
        got = self.proposal("sa", "S02", POOL, "--count", "8")
        self.assertEqual(got, self.expected("sa", "S02", POOL, 8))
        # Each learner's weak strokes are its own: those the proposal repeats are weak for S02, not S01's.
        _, weak, _ = self.learner("sa", "S02")
        for p in got:
            self.assertLessEqual(set(p["weak_strokes"]), weak, p)

    def test_default_count_is_three(self):
        self.assertEqual(self.proposal("sa", "S01", POOL), self.expected("sa", "S01", POOL, 3))

    def test_a_shorter_proposal_is_the_start_of_a_longer_one(self):
        longer = self.proposal("sa", "S01", POOL, "--count", "1000")
        self.assertEqual(longer, self.expected("sa", "S01", POOL, 1000))
        for n in (1, 2, 5):
            self.assertEqual(self.proposal("sa", "S01", POOL, "--count", str(n)), longer[:n])

    def test_weak_strokes_alone_bring_a_character(self):
        # A candidate made only of strokes the learner wrote is proposed when one of them is weak, as "again".
        written, weak, chars = self.learner("sa", "S01")
        self.assertTrue(weak, "the study should leave some weak typical strokes")
        only_written = [c for c in POOL if c not in chars and set(self.by_char[c]["typical_ids"]) <= written]
        self.assertTrue(only_written)
        got = self.proposal("sa", "S01", "".join(only_written), "--count", "1000")
        self.assertEqual(got, self.expected("sa", "S01", "".join(only_written), 1000))
        for p in got:
            self.assertEqual(p["new_strokes"], [])
            self.assertTrue(p["weak_strokes"])
        proposed = {p["character"] for p in got}
        for c in only_written:
            if not set(self.by_char[c]["typical_ids"]) & weak:
                self.assertNotIn(c, proposed, "a candidate adding nothing is left out")

    def test_everything_learnt_proposes_nothing(self):
        r = run_ok(["curriculum", "sa", "--subject", "S01", "--from", WRITTEN, "--json"], self.tmp)
        self.assertEqual(json.loads(r.stdout), [])
        text = run_ok(["curriculum", "sa", "--subject", "S01", "--from", WRITTEN], self.tmp)
        self.assertEqual(text.returncode, 0)
        self.assertNotIn("new:", text.stdout.decode())

    def test_nothing_written_proposes_by_new_strokes_only(self):
        written, weak, chars = self.learner("sb", "S01")
        self.assertEqual((written, weak, chars), (set(), set(), {"十"}))
        got = self.proposal("sb", "S01", POOL, "--count", "6")
        self.assertEqual(got, self.expected("sb", "S01", POOL, 6))
        for p in got:
            self.assertEqual(p["weak_strokes"], [])
        first = run_ok(["curriculum", "sb", "--subject", "S01", "--from", POOL], self.tmp).stdout.decode()
        self.assertTrue(first.startswith("S01: 0 of 39 typical strokes written"), first)

    def test_ties_go_to_fewer_strokes_then_to_the_order_given(self):
        # Nothing written: 二 and 一 each bring H (2), 一 with fewer strokes; after it 二 adds nothing.
        self.assertEqual([p["character"] for p in self.proposal("sb", "S01", "二一", "--count", "5")], ["一"])
        # 八 and 人: the same two typical strokes, two strokes each: the order of --from decides.
        self.assertEqual([p["character"] for p in self.proposal("sb", "S01", "八人", "--count", "5")], ["八"])
        self.assertEqual([p["character"] for p in self.proposal("sb", "S01", "人八", "--count", "5")], ["人"])

    def test_a_repeated_candidate_is_proposed_once(self):
        got = self.proposal("sb", "S01", "一一二一", "--count", "5")
        self.assertEqual([p["character"] for p in got], ["一"])

    def test_text_and_json_propose_the_same(self):
        got = self.proposal("sa", "S01", POOL, "--count", "6")
        text = run_ok(["curriculum", "sa", "--subject", "S01", "--from", POOL, "--count", "6"], self.tmp)
        lines = text.stdout.decode().strip().splitlines()
        written, _, _ = self.learner("sa", "S01")
        self.assertEqual(lines[0], f"S01: {len(written)} of 39 typical strokes written; next:")
        acronym = {s["id"]: s["acronym"] for s in self.table}
        self.assertEqual(len(lines) - 1, len(got))
        for line, p in zip(lines[1:], got):
            char, rest = line.split(None, 1)
            self.assertEqual(char, p["character"])
            new, again = rest.split("; again:")
            new_ids = sorted(k for k, a in acronym.items() if a in new.replace("new:", "").split())
            again_ids = sorted(k for k, a in acronym.items() if a in again.split())
            self.assertEqual(new_ids, p["new_strokes"], line)
            self.assertEqual(again_ids, p["weak_strokes"], line)

    def test_count_at_its_bounds(self):
        self.assertEqual(len(self.proposal("sa", "S01", POOL, "--count", "1")), 1)
        self.assertEqual(self.proposal("sa", "S01", POOL, "--count", "1000"), self.expected("sa", "S01", POOL, 1000))

    def test_count_past_its_bounds_is_a_usage_error_naming_it(self):
        for bad in ("0", "1001", "-1", "2.5", "three", ""):
            with self.subTest(count=bad):
                r = run(["curriculum", "sa", "--subject", "S01", "--from", POOL, "--count", bad], self.tmp)
                self.assert_one_error(r, 2, "--count")

    def test_subject_without_trials_is_a_usage_error(self):
        for subject in ("S03", "s01", "S01/../S02"):
            with self.subTest(subject=subject):
                r = run(["curriculum", "sa", "--subject", subject, "--from", POOL], self.tmp)
                self.assert_one_error(r, 2)

    def test_from_empty_or_not_utf8_is_a_usage_error_naming_it(self):
        for bad in ("", b"\xff\xfe", b"\xed\xa0\x80", b"\xc0\xaf"):
            with self.subTest(value=bad):
                r = run(["curriculum", "sa", "--subject", "S01", "--from", bad], self.tmp)
                self.assert_one_error(r, 2, "--from")

    def test_a_candidate_the_library_lacks_is_a_usage_error_naming_it(self):
        for bad, name in (("一A", "U+0041"), ("十\u0301", "U+0301"), ("二\U0001F642", "U+1F642")):
            with self.subTest(value=bad):
                r = run(["curriculum", "sa", "--subject", "S01", "--from", bad], self.tmp)
                self.assert_one_error(r, 2, name)

    def test_a_folder_without_sessions_is_a_data_error_naming_it(self):
        (self.tmp / "empty").mkdir(exist_ok=True)
        r = run(["curriculum", "empty", "--subject", "S01", "--from", POOL], self.tmp)
        self.assert_one_error(r, 1, "empty")

    def test_python_proposes_what_the_command_does(self):
        import calligraphy
        from calligraphy import study
        for subject in ("S01", "S02"):
            with self.subTest(subject=subject):
                got = study.propose_characters(self.tmp / "sa", subject, POOL, 5,
                                               library=calligraphy.CharacterLibrary.default())
                want = self.proposal("sa", subject, POOL, "--count", "5")
                self.assertEqual([{"character": p["character"], "new_strokes": sorted(p["new_strokes"]),
                                   "weak_strokes": sorted(p["weak_strokes"])} for p in got], want)
        with self.assertRaises(calligraphy.InvalidArgument):
            study.propose_characters(self.tmp / "sa", "S03", POOL)
        with self.assertRaises(calligraphy.CharacterNotFound):
            study.propose_characters(self.tmp / "sa", "S01", "一A", library=calligraphy.CharacterLibrary.default())

    def test_python_holds_the_commands_bounds(self):
        import calligraphy
        from calligraphy import study
        for count in (0, -1, 1001, 10**12, 2**64):
            with self.subTest(count=count), self.assertRaisesRegex(calligraphy.InvalidArgument, "^count: "):
                study.propose_characters(self.tmp / "sa", "S01", POOL, count)
        for count in (2.5, "3", None, True):
            with self.subTest(count=count), self.assertRaisesRegex(TypeError, "^count: "):
                study.propose_characters(self.tmp / "sa", "S01", POOL, count)
        self.assertEqual(len(study.propose_characters(self.tmp / "sa", "S01", POOL, 1000)),
                         len(self.proposal("sa", "S01", POOL, "--count", "1000")))
        for bad in ("", "\udc80"):
            with self.subTest(candidates=bad), self.assertRaisesRegex(calligraphy.InvalidArgument, "^candidates: "):
                study.propose_characters(self.tmp / "sa", "S01", bad)

    def test_python_default_library_is_the_commands(self):
        # The default reaches past the 58 embedded characters, as the command's does.
        from calligraphy import study
        import calligraphy
        self.assertNotIn("八", calligraphy.CharacterLibrary.embedded())
        got = study.propose_characters(self.tmp / "sb", "S01", "八大", 2)
        self.assertEqual([p["character"] for p in got], [p["character"] for p in self.proposal("sb", "S01", "八大",
                                                                                               "--count", "2")])

    def test_folders_add_up_and_a_session_folder_reads_as_its_study(self):
        session = next((self.tmp / "sa" / "S01").iterdir()).relative_to(self.tmp)
        want = self.proposal("sa", "S01", POOL, "--count", "6")
        self.assertEqual(self.proposal(str(session), "S01", POOL, "--count", "6"), want)
        self.assertEqual(self.proposal("sa/S01", "S01", POOL, "--count", "6"), want)
        # The same folder twice, or through a link, is the same trials once.
        link = self.tmp / "sa-link"
        if not link.exists():
            link.symlink_to(self.tmp / "sa")
        self.assertEqual(self.proposal("sa", "S01", POOL, "--count", "6", "sa-link"), want)
        # Two studies' folders: S01's trials of both (十 without a stroke written in sb changes no mean).
        both = self.proposal("sa", "S01", POOL, "--count", "6", "sb")
        self.assertEqual(both, want)

    def test_data_folder_is_where_characters_and_candidates_come_from(self):
        corpus = Path(os.environ.get("CALLIGRAPHY_CORPUS_DIR",
                                     Path.home() / ".cache/calligraphy/hanzi-writer-data-2.0.1"))
        if not (corpus / "十.json").is_file():
            self.skipTest(f"no hanzi-writer-data at {corpus}")
        data = self.tmp / "data"
        data.mkdir(exist_ok=True)
        for c in "二十大":
            shutil.copy(corpus / f"{c}.json", data / f"{c}.json")
        got = self.listed("--data", "data")
        self.assertEqual([c["character"] for c in got["characters"]], sorted("二十大"))
        self.assertEqual(got["count"], 3)
        self.assertEqual([c["typical_ids"] for c in got["characters"]],
                         [self.by_char[c]["typical_ids"] for c in sorted("二十大")])
        self.assertEqual(self.proposal("sb", "S01", "大二", "--data", "data"), self.proposal("sb", "S01", "大二"))
        r = run(["curriculum", "sb", "--subject", "S01", "--from", "大木", "--data", "data"], self.tmp)
        self.assert_one_error(r, 2, "木")

    # --- characters ---------------------------------------------------------------------------------------

    def listed(self, *args):
        return json.loads(run_ok(["characters", *args, "--json"], self.tmp).stdout)

    def test_every_character_has_what_the_library_loads(self):
        import calligraphy
        library = calligraphy.CharacterLibrary.default()
        self.assertEqual(self.all["count"], len(self.all["characters"]))
        self.assertEqual(sorted(self.by_char), sorted(library.characters()))
        for c in random.Random(21).sample(library.characters(), 400):
            ch = library.load(c)
            entry = self.by_char[c]
            self.assertEqual(entry["strokes"], len(ch.strokes), c)
            self.assertEqual(entry["typical_ids"], [s.typical_id for s in ch.strokes], c)
            self.assertEqual(entry["code_point"], f"U+{ord(c):04X}")

    def test_model_agrees_with_the_list(self):
        for c in "一十永":
            model = json.loads(run_ok(["model", c, "--json"], self.tmp).stdout)
            entry = self.by_char[c]
            self.assertEqual([s["acronym"] for s in model["strokes"]], entry["typical_strokes"], c)
            self.assertEqual(len(model["strokes"]), entry["strokes"], c)

    def test_stroke_count_filter_lists_exactly_those(self):
        for n in ("1", "2", "4"):
            got = self.listed("--strokes", n)
            want = [c for c in self.all["characters"] if c["strokes"] == int(n)]
            self.assertEqual(got["characters"], want, n)
            self.assertEqual(got["count"], len(want))
        self.assertEqual(self.listed("--strokes", "255")["characters"],
                         [c for c in self.all["characters"] if c["strokes"] == 255])

    def test_stroke_count_past_its_bounds_is_a_usage_error(self):
        for bad in ("0", "256", "-2", "2x"):
            with self.subTest(strokes=bad):
                self.assert_one_error(run(["characters", "--strokes", bad], self.tmp), 2, "--strokes")

    def test_typical_stroke_forms_give_one_list(self):
        hzg = next(s for s in self.table if s["acronym"] == "HZG")
        want = [c for c in self.all["characters"] if hzg["id"] in c["typical_ids"] and c["strokes"] == 4]
        self.assertTrue(want)
        forms = [str(hzg["id"]), "HZG", "hzg", "hZg", hzg["name"], chr(int(hzg["unicode"][2:], 16))]
        self.assertEqual(forms[-1], "㇆")
        for form in forms:
            with self.subTest(form=form):
                self.assertEqual(self.listed("--typical", form, "--strokes", "4")["characters"], want)

    def test_unknown_typical_stroke_is_a_usage_error_naming_the_option(self):
        for bad in ("0", "40", "HZX", "", "横折钩钩", "U+31C6"):
            with self.subTest(typical=bad):
                self.assert_one_error(run(["characters", "--typical", bad], self.tmp), 2, "--typical")

    def test_text_of_mixed_scripts_lists_each_character_once_and_names_the_rest(self):
        text = "永A永 十\u3000e\u0301字\x1b\U0001F642\u00a0\u0085\u2028二\tA"
        got = self.listed("--text", text)
        self.assertEqual([c["character"] for c in got["characters"]], ["永", "十", "字", "二"])
        self.assertEqual(got["characters"], [self.by_char[c] for c in "永十字二"])
        self.assertEqual(got["count"], 4)
        self.assertEqual(got["not_found"], ["A", "e", "\u0301", "\x1b", "\U0001F642"])
        table = run_ok(["characters", "--text", text], self.tmp).stdout.decode()
        self.assertNotIn("\x1b", table)
        self.assertIn("\\x1b (U+001B)", table)
        self.assertIn("U+0301", table)
        self.assertIn("U+1F642", table)
        lines = table.strip().splitlines()
        self.assertEqual(sum(1 for l in lines if l.split() and l.split()[0] in set("永十字二")), 4)

    def test_text_forged_as_not_utf8_is_a_usage_error_naming_it(self):
        for bad in (b"\xed\xa0\x80", b"\xe6\xb0", b"\xf4\x90\x80\x80"):
            with self.subTest(text=bad):
                self.assert_one_error(run(["characters", "--text", bad], self.tmp), 2, "--text")

    def test_filters_combine_and_white_space_is_no_character(self):
        got = self.listed("--text", "一二十人口\u3000", "--strokes", "2", "--typical", "S")
        self.assertEqual([c["character"] for c in got["characters"]], ["十"])
        self.assertEqual(got["not_found"], [])
        blank = self.listed("--text", " \t\u3000\u00a0\u2029")
        self.assertEqual((blank["count"], blank["characters"], blank["not_found"]), (0, [], []))

    def test_option_syntax_of_both_commands(self):
        # docs/cli.md "Option syntax", "Numbers": a value option once, flags without a value, whole decimal
        # numbers, no option where a value belongs, --data and --store not together.
        base = ["curriculum", "sb", "--subject", "S01", "--from", "二"]
        refused = [(base + ["--count", "2", "--count", "3"], "--count"),
                   (base + ["--subject", "S02"], "--subject"),
                   (base + ["--json=yes"], "--json"),
                   (base + ["--count=0x10"], "--count"),
                   (base + ["--count", "1e3"], "--count"),
                   (["curriculum", "sb", "--subject", "S01", "--from", "-一"], "--from"),
                   (base + ["--data", "sb", "--store", "x.bin"], "--store"),
                   (["characters", "--strokes", "2", "--strokes", "3"], "--strokes"),
                   (["characters", "--strokes", "+2"], "--strokes"),
                   (["characters", "--text", "-一"], "--text"),
                   (["characters", "--data", "sb", "--store", "x.bin"], "--store")]
        for args, name in refused:
            with self.subTest(args=args):
                self.assert_one_error(run(args, self.tmp), 2, name)
        self.assertEqual(self.proposal("sb", "S01", "大二", "--count=1", "--json=true"),
                         self.proposal("sb", "S01", "大二", "--count", "1"))
        self.assertEqual(self.listed("--typical=hzg", "--strokes=4")["characters"],
                         self.listed("--typical", "10", "--strokes", "4")["characters"])
        for args in (base + ["--store", "missing.bin"], ["characters", "--store", "missing.bin"]):
            with self.subTest(args=args):
                self.assert_one_error(run(args, self.tmp), 1, "missing.bin")

    def test_table_and_json_count_the_same(self):
        for args in (["--strokes", "3"], ["--typical", "HZG"], ["--text", "十一人口abc"]):
            with self.subTest(args=args):
                got = self.listed(*args)
                table = run_ok(["characters", *args], self.tmp).stdout.decode().strip().splitlines()
                rows = [l for l in table if l.split()[0] in {c["character"] for c in got["characters"]}]
                self.assertEqual(len(rows), got["count"])
                self.assertTrue(any(str(got["count"]) in l for l in table[-2:]), table[-2:])


if __name__ == "__main__":
    unittest.main()
