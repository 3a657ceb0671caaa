#!/usr/bin/env python3
"""Round 17B: the characters at large, any of the corpus and what a person types, from the docs alone (README.md
"Every character of hanzi-writer-data 2.0.1 (9,574) is there without a download", docs/cli.md "Conventions:
Characters", "Exit statuses", "trial", "score", "model", "characters", "session plan", docs/corpus.md, docs/python.md
"Characters" and "Errors", docs/typical-strokes.md). Run by CTest as `cli_unseen_round17b_tests`.

Characters drawn at random (a fixed seed, printed with the picks) from what `calligraphy characters --json` lists,
never one named in README.md, docs/, examples/ or tests/: the fewest strokes (one), the most (25 or more) and three
middling ones. For each: `model` as text, JSON and SVG (its stroke count and typical strokes those of the listing,
strokes numbered from 1 for people, every typical stroke one of the documented 39), `trial --json` (the simulated
writer writes every stroke, in order), `score` of the trial's own trace (every stroke accepted, the trial's
metrics), Python's `CharacterLibrary.default().load` (the model's numbers, the store's medians) and `simulate_trial`
(the command line's metrics); three of them through `session run` (each record its character's, its trace scored).
`characters` by stroke counts at 0, 1, the listing's maximum, past it, 255 and 256; by every typical stroke, spelt
in turn each documented way, and by names that are none; by a text with duplicates, white space, Latin letters,
punctuation and the odd characters below (named once each, with its code point, exit 0). What a person types where a
character is expected (`model`, `trial`, `score --character`, a protocol's test characters through `session plan`,
Python's `load`, `Scene` and `simulate_trial`): two characters, nothing, a space, an ideographic space, a kana, a
Hangul syllable and its jamo (NFD), U+20000, the Kangxi radical U+2F00 beside 一, the compatibility ideograph U+F900
beside 豈 U+8C48, 永 with the variation selector U+FE00, a combining acute accent, a fullwidth digit, a lone surrogate
(Python) and bytes that are no UTF-8 (the command line): each one error line naming the character and its code point
(or the bytes), the documented status, nothing written, never another character's strokes.

CALLIGRAPHY_CLI names the program, PYTHONPATH its Python module, CALLIGRAPHY_SOURCE_DIR the sources.
CALLIGRAPHY_SANITIZED=1 takes five cases.
"""
import json
import os
import random
import re
import shutil
import sys
import tempfile
import unittest
import xml.etree.ElementTree as ET
from pathlib import Path

from outsider import OneErrorLine, run, run_ok, sanitized_subset

load_tests = sanitized_subset({"test_model_text_of_random_characters_agrees_with_the_listing",
                               "test_kangxi_radical_is_refused_never_read_as_its_twin",
                               "test_bytes_that_are_no_utf8_are_refused_showing_the_bytes",
                               "test_characters_strokes_zero_is_a_usage_error",
                               "test_session_plan_names_an_odd_character_at_its_pointer"})

SOURCE = Path(os.environ.get("CALLIGRAPHY_SOURCE_DIR", Path(__file__).resolve().parents[2]))
SEED = 1717
SHARED = {}
SSW = "\u3000"  # the ideographic space
# What a person may type where a character is expected, none of them in hanzi-writer-data: (text, the code point
# the error must name).
ODD = [("\u3042", "U+3042"),            # あ, a Japanese kana
       ("\ud55c", "U+D55C"),            # 한, a Hangul syllable
       ("\U00020000", "U+20000"),       # 𠀀, outside the Basic Multilingual Plane
       ("\u2f00", "U+2F00"),            # ⼀, the Kangxi radical that looks like 一
       ("\uf900", "U+F900"),            # 豈, the compatibility ideograph of 豈 U+8C48
       ("\uff11", "U+FF11")]            # １, a fullwidth digit
TEXT_SUFFIXES = {".md", ".py", ".cpp", ".hpp", ".h", ".json", ".txt", ".csv", ".cmake", ".sh", ".svg", ".html", ".R",
                 ".ipynb", ".toml", ".cfg", ".yml", ".yaml", ""}


def cli(args, cwd=None, ok=True):
    return run_ok(args, cwd or SHARED["root"], ok)


def cjk_named_in_the_sources():
    """Every character above U+2E7F that README.md, docs/, examples/ or tests/ name, in a file's text or name."""
    named = set()
    paths = [SOURCE / "README.md"]
    for folder in ("docs", "examples", "tests"):
        paths += [p for p in (SOURCE / folder).rglob("*") if p.is_file()]
    for path in paths:
        named.update(ch for ch in path.name if ord(ch) >= 0x2E80)
        if path.suffix in TEXT_SUFFIXES and path.stat().st_size < 4_000_000:
            named.update(ch for ch in path.read_bytes().decode("utf-8", "ignore") if ord(ch) >= 0x2E80)
    return named


def code_point(ch):
    return f"U+{ord(ch):04X}"


def setUpModule():
    root = Path(tempfile.mkdtemp(prefix="r17b-"))
    SHARED["root"] = root
    listing = json.loads(cli(["characters", "--json"]).stdout)
    SHARED["listing"] = listing
    rows = {row["character"]: row for row in listing["characters"]}
    SHARED["rows"] = rows
    SHARED["strokes_table"] = json.loads(cli(["strokes", "--json"]).stdout)
    named = cjk_named_in_the_sources()
    free = sorted(ch for ch in rows if ch not in named)
    rng = random.Random(SEED)
    fewest = min(row["strokes"] for row in rows.values())
    picks = [rng.choice([ch for ch in free if rows[ch]["strokes"] == fewest]),
             rng.choice([ch for ch in free if rows[ch]["strokes"] >= 25])]
    picks += rng.sample([ch for ch in free if 8 <= rows[ch]["strokes"] <= 16], 3)
    SHARED["picks"] = picks
    print(f"round 17B: seed {SEED}, characters " + ", ".join(f"{ch} ({code_point(ch)}, {rows[ch]['strokes']} strokes)"
                                                             for ch in picks), file=sys.stderr)
    # One trial of each pick (its record and trace), and the score of that trace.
    for i, ch in enumerate(picks):
        cli(["trial", ch, "--seed", str(i), "--json", f"t{i}.json", "--csv", f"t{i}.csv"])
        cli(["score", f"t{i}.csv", "--character", ch, "--json", f"s{i}.json"])


def tearDownModule():
    shutil.rmtree(SHARED["root"], ignore_errors=True)


def load_json(name):
    return json.loads((SHARED["root"] / name).read_text(encoding="utf-8"))


class RandomCharacters(unittest.TestCase):
    """Characters of the corpus the tests never name, modelled, written, scored and loaded from Python."""

    def test_listing_rows_agree_with_themselves_and_the_stroke_table(self):
        listing, table = SHARED["listing"], SHARED["strokes_table"]
        self.assertEqual(listing["count"], 9574)
        self.assertEqual(len(listing["characters"]), 9574)
        self.assertEqual(len({row["character"] for row in listing["characters"]}), 9574)
        acronyms = {entry["id"]: entry["acronym"] for entry in table}
        self.assertEqual(sorted(acronyms), list(range(1, 40)))
        for row in listing["characters"]:
            ch = row["character"]
            self.assertEqual(len(ch), 1, row)
            self.assertEqual(row["code_point"], code_point(ch))
            self.assertEqual(row["strokes"], len(row["typical_ids"]), row)
            self.assertEqual(row["typical_strokes"], [acronyms[i] for i in row["typical_ids"]], row)

    def test_picks_come_from_the_bundled_store_with_no_fetch(self):
        # README.md: 58 characters are embedded, the others come from the store compiled into the library; the
        # picks are none of the 58 (the tests name those), so `model` reads each from the bundled store.
        rows, picks = SHARED["rows"], SHARED["picks"]
        self.assertEqual(min(row["strokes"] for row in rows.values()), 1)
        self.assertGreaterEqual(max(row["strokes"] for row in rows.values()), 25)
        for ch in picks:
            first = cli(["model", ch]).stdout.decode("utf-8").splitlines()[0]
            self.assertIn("from bundled:hanzi-writer-data-2.0.1.clg", first)
            self.assertIn(f"{ch} ({code_point(ch)})", first)

    def test_model_text_of_random_characters_agrees_with_the_listing(self):
        for ch in SHARED["picks"]:
            row = SHARED["rows"][ch]
            out = cli(["model", ch]).stdout.decode("utf-8")
            self.assertIn(f"{ch} ({row['code_point']})", out.splitlines()[0])
            count = re.search(r"Number of typical strokes\s+(\d+)", out)
            self.assertIsNotNone(count, out)
            self.assertEqual(int(count.group(1)), row["strokes"], ch)
            ids = re.search(r"ID array of typical strokes\s+([\d ]+)", out)
            self.assertEqual([int(i) for i in ids.group(1).split()], row["typical_ids"], ch)
            strokes = re.findall(r"^\s*stroke (\d+): ID (\d+) (\S+)", out, re.M)
            self.assertEqual([int(n) for n, _, _ in strokes], list(range(1, row["strokes"] + 1)), ch)
            self.assertEqual([int(i) for _, i, _ in strokes], row["typical_ids"], ch)
            self.assertEqual([a for _, _, a in strokes], row["typical_strokes"], ch)

    def test_model_json_of_random_characters_agrees_with_the_listing(self):
        for ch in SHARED["picks"]:
            row = SHARED["rows"][ch]
            model = json.loads(cli(["model", ch, "--json"]).stdout)
            self.assertEqual(model["character"], ch)
            self.assertEqual(model["typical_strokes"], row["strokes"])
            self.assertEqual(model["typical_stroke_ids"], row["typical_ids"])
            self.assertEqual(len(model["strokes"]), row["strokes"])
            for stroke, typical, acronym in zip(model["strokes"], row["typical_ids"], row["typical_strokes"]):
                self.assertIn(stroke["typical_id"], range(1, 40))
                self.assertEqual((stroke["typical_id"], stroke["acronym"]), (typical, acronym))
            self.assertEqual(model["feature_points"], sum(len(s["feature_points"]) for s in model["strokes"]))

    def test_model_svg_of_random_characters_numbers_strokes_from_one(self):
        for ch in SHARED["picks"]:
            row = SHARED["rows"][ch]
            svg = ET.fromstring(cli(["model", ch, "--svg", "-"]).stdout)
            title = svg.find("{http://www.w3.org/2000/svg}title")
            self.assertIsNotNone(title)
            self.assertIn(ch, title.text)
            numbers = [t.text for t in svg.iter("{http://www.w3.org/2000/svg}text")]
            self.assertEqual(numbers, [str(n) for n in range(1, row["strokes"] + 1)], ch)

    def test_trial_json_of_random_characters_writes_every_stroke_in_order(self):
        for i, ch in enumerate(SHARED["picks"]):
            row, record = SHARED["rows"][ch], load_json(f"t{i}.json")
            self.assertEqual(record["character"], ch)
            self.assertEqual(record["end_reason"], "completed", ch)
            self.assertEqual(record["strokes_completed"], row["strokes"], ch)
            self.assertEqual(record["strokes_total"], row["strokes"], ch)
            self.assertEqual(record["strokes_assisted"], 0, ch)
            self.assertTrue(record["completed_in_order"], ch)
            strokes = record["renderer_strokes"]
            self.assertEqual([s["index"] for s in strokes], list(range(row["strokes"])))
            self.assertEqual([s["typical_id"] for s in strokes], row["typical_ids"])
            self.assertTrue(all(s["completed"] and not s["assisted"] for s in strokes), ch)

    def test_score_of_each_trials_own_trace_accepts_every_stroke(self):
        for i, ch in enumerate(SHARED["picks"]):
            row, record, score = SHARED["rows"][ch], load_json(f"t{i}.json"), load_json(f"s{i}.json")
            self.assertEqual(score["strokes_total"], row["strokes"], ch)
            self.assertEqual(score["strokes_accepted"], row["strokes"], ch)
            self.assertEqual(score["strokes_written"], row["strokes"], ch)
            self.assertTrue(score["completed_in_order"], ch)
            per_stroke = score["per_character"][0]["per_stroke"]
            self.assertEqual(len(per_stroke), row["strokes"])
            for key in ("mean_deviation_m", "max_deviation_m", "rms_deviation_m", "frechet_m", "dtw_m",
                        "pen_down_time_s", "total_time_s", "strokes_accepted", "order_errors", "velocity_peaks"):
                self.assertAlmostEqual(score[key], record[key], delta=1e-9, msg=f"{ch} {key}")

    def test_characters_text_of_the_picks_gives_their_listing_rows(self):
        picks = SHARED["picks"]
        got = json.loads(cli(["characters", "--text", "".join(reversed(picks)), "--json"]).stdout)
        self.assertEqual(got["characters"], [SHARED["rows"][ch] for ch in reversed(picks)])
        self.assertEqual((got["count"], got["not_found"]), (5, []))

    def test_python_load_of_random_characters_is_the_models(self):
        import calligraphy as cg
        library = cg.CharacterLibrary.default()
        self.assertEqual(len(library), 9574)
        for ch in SHARED["picks"]:
            self.assertIn(ch, library)
            model = json.loads(cli(["model", ch, "--json"]).stdout)
            character = library.load(ch)
            self.assertEqual(list(character.typical_stroke_ids), SHARED["rows"][ch]["typical_ids"])
            self.assertEqual(len(character.strokes), len(model["strokes"]))
            for stroke, mine in zip(character.strokes, model["strokes"]):
                self.assertEqual(stroke.typical_id, mine["typical_id"])
                self.assertEqual(stroke.acronym, mine["acronym"])
                self.assertEqual(stroke.feature_points.shape, (len(mine["feature_points"]), 2))
                for p, q in zip(stroke.feature_points.tolist(), mine["feature_points"]):
                    self.assertAlmostEqual(p[0], q[0], delta=0.051)
                    self.assertAlmostEqual(p[1], q[1], delta=0.051)

    def test_python_medians_of_a_store_character_are_the_models(self):
        # docs/cli.md: the bundled store holds each character's medians, so acceptance and scoring follow them;
        # `model --svg` draws them (the data box's y up flipped into the SVG's y down: 900 - y).
        import calligraphy as cg
        library = cg.CharacterLibrary.default()
        for ch in SHARED["picks"][:3]:
            character = library.load(ch)
            self.assertIn("bundled", character.source)
            svg = ET.fromstring(cli(["model", ch, "--svg", "-"]).stdout)
            medians = [line.get("points") for line in svg.iter("{http://www.w3.org/2000/svg}polyline")
                       if line.get("class") == "median"]
            self.assertEqual(len(medians), len(character.strokes), ch)
            for stroke, points in zip(character.strokes, medians):
                drawn = [tuple(map(float, p.split(","))) for p in points.split()]
                self.assertGreaterEqual(stroke.median.shape[0], 2, ch)
                self.assertEqual(stroke.median.shape, (len(drawn), 2), ch)
                for (x, y), (sx, sy) in zip(stroke.median.tolist(), drawn):
                    self.assertAlmostEqual(x, sx, delta=0.051)
                    self.assertAlmostEqual(900 - y, sy, delta=0.051)

    def test_python_simulate_trial_equals_the_command_lines_trial(self):
        import calligraphy as cg
        for i in (0, 2):
            ch = SHARED["picks"][i]
            record = load_json(f"t{i}.json")
            metrics = cg.simulate_trial(ch, seed=i, keep_trace=False).metrics
            shared = [k for k in record if k in metrics and isinstance(record[k], (int, float, bool))]
            self.assertGreater(len(shared), 15)
            for key in shared:
                self.assertEqual(metrics[key], record[key], f"{ch} {key}")


class CharactersFilters(unittest.TestCase, OneErrorLine):
    """`calligraphy characters` by stroke count, typical stroke and text."""

    def listed(self, *args):
        return json.loads(cli(["characters", "--json", *args]).stdout)

    def test_characters_strokes_zero_is_a_usage_error(self):
        for value in ("0", "256", "-1"):
            result = cli(["characters", "--strokes", value], ok=False)
            self.assert_one_error(result, 2, "--strokes", value)
            self.assertEqual(result.stdout, b"")

    def test_characters_strokes_one_lists_every_one_stroke_character(self):
        got = self.listed("--strokes", "1")
        want = [row for row in SHARED["listing"]["characters"] if row["strokes"] == 1]
        self.assertEqual(got["characters"], want)
        self.assertEqual(got["count"], len(want))
        self.assertIn("一", [row["character"] for row in want])

    def test_characters_strokes_at_the_maximum_and_past_it(self):
        most = max(row["strokes"] for row in SHARED["listing"]["characters"])
        self.assertGreaterEqual(most, 25)
        got = self.listed("--strokes", str(most))
        self.assertGreaterEqual(got["count"], 1)
        self.assertTrue(all(row["strokes"] == most for row in got["characters"]))
        for past in (most + 1, 255):
            result = cli(["characters", "--strokes", str(past)])
            self.assertEqual(result.stderr, b"")
            lines = result.stdout.decode("utf-8").splitlines()
            self.assertTrue(lines and lines[-1].startswith("0 characters"), lines)
            self.assertEqual(self.listed("--strokes", str(past))["characters"], [])

    def test_characters_typical_every_stroke_in_each_documented_spelling(self):
        # A text of corpus characters in random order that holds every typical stroke and characters without it;
        # each typical stroke, spelt in turn by its ID, acronym, acronym in lower case, Chinese name and CJK
        # stroke character (every spelling used on about eight strokes; round 13B spelt each stroke every way),
        # must pick the text's characters whose listed typical strokes hold it, in the text's order.
        rows = SHARED["rows"]
        order = random.Random(SEED + 1).sample(sorted(rows), len(rows))
        text, held = [], set()
        for ch in order:
            if not set(rows[ch]["typical_ids"]) <= held or len(text) < 20:
                text.append(ch)
                held |= set(rows[ch]["typical_ids"])
        # Every typical stroke some character of the corpus has (14, HXG 横斜钩, is none's in hanzi-writer-data
        # 2.0.1: the strokes cnchar labels 横斜钩 are fitted as HZWG and others, docs/classification.md).
        in_corpus = {i for row in rows.values() for i in row["typical_ids"]}
        self.assertEqual(held, in_corpus)
        self.assertGreaterEqual(len(in_corpus), 38)
        text = "".join(text)
        kinds = 0
        for n, entry in enumerate(SHARED["strokes_table"]):
            want = [rows[ch] for ch in text if entry["id"] in rows[ch]["typical_ids"]]
            self.assertEqual(bool(want), entry["id"] in in_corpus)
            self.assertLess(len(want), len(text))
            spellings = [str(entry["id"]), entry["acronym"], entry["acronym"].lower(), entry["name"]]
            if entry["unicode"]:  # null where the CJK Strokes block has none
                spellings.append(chr(int(entry["unicode"][2:], 16)))
            spelling = spellings[n % len(spellings)]
            kinds |= 1 << (n % len(spellings))
            got = self.listed("--typical", spelling, "--text", text)
            self.assertEqual(got["characters"], want, f"--typical {spelling}")
        self.assertEqual(kinds, 0b11111)

    def test_characters_typical_names_that_are_no_stroke_are_usage_errors(self):
        # 0 and 40 are past the IDs, HZX no acronym, ㇣ (U+31E3) a CJK stroke the table lacks, 横折X no name.
        for value in ("0", "40", "HZX", "\u31e3", "横折X", "1.0", "H Z G"):
            result = cli(["characters", "--typical", value], ok=False)
            self.assert_one_error(result, 2, "--typical")
            self.assertEqual(result.stdout, b"")
        line = self.assert_one_error(cli(["characters", "--typical", "HZX"], ok=False), 2)
        self.assertIn("HZ", line)  # the close acronyms named

    def test_characters_text_names_what_the_library_lacks_once_each(self):
        text = "永 a永，b\t a 。!" + SSW + "十十"
        result = cli(["characters", "--text", text])
        self.assertEqual(result.stderr, b"")
        lines = result.stdout.decode("utf-8").splitlines()
        missing = [line for line in lines if "not in the library" in line]
        self.assertEqual(len(missing), 1, lines)
        for ch in "a，b。!":
            self.assertEqual(missing[0].count(f"{ch} ({code_point(ch)})"), 1, missing[0])
        self.assertNotIn("U+0020", missing[0])
        self.assertNotIn("U+3000", missing[0])
        got = self.listed("--text", text)
        self.assertEqual([row["character"] for row in got["characters"]], ["永", "十"])
        self.assertEqual(got["not_found"], ["a", "，", "b", "。", "!"])

    def test_characters_text_names_each_odd_character_with_its_code_point(self):
        text = "".join(ch for ch, _ in ODD) + "永\ufe00" + "十\u0301" + "\u1112\u1161\u11ab"
        got = self.listed("--text", text)
        listed = [row["character"] for row in got["characters"]]
        self.assertEqual(listed, ["永", "十"])  # never 一 for ⼀, nor 豈 U+8C48 for U+F900
        self.assertEqual(got["not_found"], [ch for ch, _ in ODD] + ["\ufe00", "\u0301", "\u1112", "\u1161",
                                                                      "\u11ab"])
        line = [line for line in cli(["characters", "--text", text]).stdout.decode("utf-8").splitlines()
                if "not in the library" in line]
        self.assertEqual(len(line), 1)
        for cp in [cp for _, cp in ODD] + ["U+FE00", "U+0301", "U+1112", "U+1161", "U+11AB"]:
            self.assertIn(f"({cp})", line[0])


class WhatAPersonTypes(unittest.TestCase, OneErrorLine):
    """A character where one is expected: `model`, `trial` and `score --character`."""

    @classmethod
    def setUpClass(cls):
        root = SHARED["root"]
        (root / "ten.csv").write_text("t,x,y,pen\n0,0,0,1\n0.01,0.001,0,1\n0.02,0.002,0,0\n", encoding="utf-8")

    def refused(self, args, *needles, status=2):
        """Each of `model X`, `trial X --json`/`--csv` and `score --character X`: one line naming the needles,
        nothing on standard output, nothing written in the folder."""
        root = SHARED["root"]
        before = sorted(p.name for p in root.iterdir())
        for command in (["model", *args], ["trial", *args, "--json", "new.json", "--csv", "new.csv"],
                        ["score", "ten.csv", "--character", *args, "--json", "new.json"]):
            result = cli(command, ok=False)
            self.assert_one_error(result, status, *needles)
            self.assertEqual(result.stdout, b"", command)
            self.assertEqual(sorted(p.name for p in root.iterdir()), before, command)

    def test_two_characters_where_one_is_expected(self):
        result = cli(["model", "永字"], ok=False)
        line = self.assert_one_error(result, 2, "CHAR", "永 (U+6C38)", "字 (U+5B57)")
        self.assertIn("one character", line)
        self.assertEqual(result.stdout, b"")

    def test_nothing_and_white_space_are_refused(self):
        for text in ("", " ", SSW, "\t"):
            with self.subTest(text=repr(text)):
                self.refused([text])

    def test_kana_hangul_and_a_fullwidth_digit_are_named_with_their_code_points(self):
        for ch, cp in (ODD[0], ODD[1], ODD[5]):
            with self.subTest(cp=cp):
                self.refused([ch], ch, cp)

    def test_a_character_outside_the_bmp_is_named_whole(self):
        ch, cp = ODD[2]
        self.refused([ch], ch, cp)
        line = self.assert_one_error(cli(["model", ch], ok=False), 2)
        self.assertNotIn("U+D840", line)

    def test_kangxi_radical_is_refused_never_read_as_its_twin(self):
        ch, cp = ODD[3]
        self.refused([ch], cp)
        twin = cli(["model", "一", "--json"])
        self.assertEqual(json.loads(twin.stdout)["character"], "一")

    def test_compatibility_ideograph_is_refused_never_read_as_its_twin(self):
        ch, cp = ODD[4]
        self.refused([ch], cp)
        self.assertEqual(json.loads(cli(["model", "\u8c48", "--json"]).stdout)["character"], "\u8c48")

    def test_variation_selector_after_a_character_is_named(self):
        result = cli(["model", "永\ufe00"], ok=False)
        self.assert_one_error(result, 2, "U+FE00")
        result = cli(["trial", "永\ufe00", "--json", "new.json"], ok=False)
        self.assert_one_error(result, 2, "U+FE00")
        result = cli(["score", "ten.csv", "--character", "永\ufe00"], ok=False)
        self.assert_one_error(result, 2, "U+FE00")

    def test_combining_marks_and_decomposed_hangul_are_named(self):
        for text, cp in (("十\u0301", "U+0301"), ("\u1112\u1161\u11ab", "U+1112")):
            with self.subTest(cp=cp):
                for command in (["trial", text], ["score", "ten.csv", "--character", text]):
                    self.assert_one_error(cli(command, ok=False), 2, cp)
                self.assert_one_error(cli(["model", text], ok=False), 2)

    def test_bytes_that_are_no_utf8_are_refused_showing_the_bytes(self):
        # A stray byte, 永 cut short, an overlong '1', a surrogate's bytes and a code point past U+10FFFF.
        for raw, shown in ((b"\xff", "\\xff"), (b"\xe6\xb0", "\\xe6\\xb0"), (b"\xc0\xb1", "\\xc0\\xb1"),
                           (b"\xed\xa0\x80", "\\xed\\xa0\\x80"), (b"\xf4\x90\x80\x80", "\\xf4\\x90\\x80\\x80")):
            for command in ([b"model", raw], [b"trial", raw], [b"score", b"ten.csv", b"--character", raw],
                            [b"characters", b"--text", raw]):
                with self.subTest(command=command):
                    result = cli(command, ok=False)
                    line = self.assert_one_error(result, 2, "UTF-8")
                    self.assertIn(shown.lower(), line.lower())
                    self.assertEqual(result.stdout, b"")

    def test_a_character_of_a_row_missing_is_named_the_others_not(self):
        pick = SHARED["picks"][2]
        line = self.assert_one_error(cli(["trial", pick + "\u3042" + "十"], ok=False), 2, "U+3042")
        self.assertNotIn(code_point(pick), line)


class PythonTypes(unittest.TestCase):
    """The same through Python: `CharacterLibrary.load`, `Scene` and `simulate_trial`."""

    def test_python_load_names_each_odd_character(self):
        import calligraphy as cg
        library = cg.CharacterLibrary.default()
        for ch, cp in ODD + [(" ", "U+0020"), ("\u0301", "U+0301")]:
            with self.subTest(cp=cp):
                self.assertNotIn(ch, library)
                with self.assertRaises(cg.CharacterNotFound) as caught:
                    library.load(ch)
                self.assertIsInstance(caught.exception, KeyError)
                self.assertIn(cp, str(caught.exception))
        for text, named in (("永字", "U+5B57"), ("", "0"), ("永\ufe00", "U+FE00"), ("十\u0301", "U+0301")):
            with self.subTest(text=repr(text)):
                with self.assertRaises(cg.InvalidArgument) as caught:
                    library.load(text)
                self.assertIn("one character", str(caught.exception))
                self.assertIn(named, str(caught.exception))
        with self.assertRaises(cg.InvalidArgument) as caught:
            library.load("\ud800")
        self.assertIsInstance(caught.exception, ValueError)
        self.assertNotIsInstance(caught.exception, TypeError)

    def test_python_scene_and_simulate_trial_name_each_odd_character(self):
        import calligraphy as cg
        for ch, cp in ODD + [("永\ufe00", "U+FE00"), ("十\u0301", "U+0301")]:
            with self.subTest(cp=cp):
                for make in (lambda: cg.Scene(ch), lambda: cg.simulate_trial(ch, keep_trace=False)):
                    with self.assertRaises(cg.CharacterNotFound) as caught:
                        make()
                    self.assertIn(cp, str(caught.exception))
        for bad in ("\ud800", "永\udfff"):
            for make in (lambda: cg.Scene(bad), lambda: cg.simulate_trial(bad, keep_trace=False)):
                with self.assertRaises(cg.InvalidArgument):
                    make()
        for empty in ("", " "):
            with self.assertRaises((cg.InvalidArgument, cg.CharacterNotFound)):
                cg.simulate_trial(empty, keep_trace=False)


class Protocols(unittest.TestCase, OneErrorLine):
    """A protocol's test characters through `session plan` (docs/cli.md: a character the library lacks is exit 2,
    `FILE: /json/pointer: ...` naming the character)."""

    def protocol(self, name, characters):
        path = SHARED["root"] / name
        path.write_text(json.dumps({"name": "r17b", "conditions": [{"name": "V", "mode": "vision"}],
                                    "test": {"characters": characters, "conditions": ["V"], "repetitions": 1},
                                    "trial": {"max_duration_s": 120}}, ensure_ascii=False), encoding="utf-8")
        return name

    def test_session_plan_of_random_corpus_characters(self):
        picks = SHARED["picks"]
        result = cli(["session", "plan", self.protocol("p.json", picks), "--subjects", "1", "--json"])
        plan = json.loads(result.stdout)
        items = [item for session in plan["subjects"][0]["sessions"] for phase in session["phases"]
                 for item in phase["items"]]
        self.assertEqual(sorted(items), sorted(picks))

    def test_session_run_writes_random_corpus_characters(self):
        # docs/experiments.md: each trial saved as trials/STEM.json and STEM.trace.h5, STEM ending in the
        # character's code point (`U6C38`); `score STEM.trace.h5 --character C` scores it again.
        picks, rows = SHARED["picks"][:3], SHARED["rows"]
        name = self.protocol("run.json", picks)
        cli(["session", "run", name, "--writer", "simulated", "--subjects", "1", "--out", "run-study"])
        records = sorted((SHARED["root"] / "run-study").glob("S01/*/trials/*.json"))
        self.assertEqual(len(records), len(picks))
        for path, ch in zip(records, picks):
            record = json.loads(path.read_text(encoding="utf-8"))
            self.assertTrue(path.stem.endswith(f"-U{ord(ch):04X}"), path.name)
            self.assertEqual(record["characters"], ch)
            self.assertEqual((record["end_reason"], record["strokes_completed"], record["strokes_assisted"]),
                             ("completed", rows[ch]["strokes"], 0), path.name)
            self.assertEqual([s["typical_id"] for s in record["per_stroke"]], rows[ch]["typical_ids"])
            trace = path.with_name(path.stem + ".trace.h5")
            score = json.loads(cli(["score", str(trace), "--character", ch, "--json", "-"]).stdout)
            self.assertEqual(score["strokes_accepted"], rows[ch]["strokes"], path.name)

    def test_session_plan_names_an_odd_character_at_its_pointer(self):
        for ch, cp in ODD + [("永\ufe00", "U+FE00")]:
            with self.subTest(cp=cp):
                name = self.protocol("odd.json", ["十", ch])
                result = cli(["session", "plan", name, "--subjects", "1"], ok=False)
                self.assert_one_error(result, 2, "odd.json", "/test/characters/1", cp)
                self.assertEqual(result.stdout, b"")

    def test_session_plan_of_a_lone_surrogate_or_bytes_that_are_no_utf8(self):
        root = SHARED["root"]
        base = ('{"name": "r17b", "conditions": [{"name": "V", "mode": "vision"}], "trial": {"max_duration_s": 5}, '
                '"test": {"characters": [%s], "conditions": ["V"], "repetitions": 1}}')
        (root / "surrogate.json").write_text(base % '"\\ud800"', encoding="utf-8")
        (root / "bytes.json").write_bytes((base % '"@"').encode().replace(b"@", b"\xe6\xb0"))  # 永 cut short
        for name in ("surrogate.json", "bytes.json"):
            with self.subTest(name=name):
                result = cli(["session", "plan", name, "--subjects", "1"], ok=False)
                self.assert_one_error(result, 2, name)
                self.assertEqual(result.stdout, b"")


if __name__ == "__main__":
    unittest.main()
