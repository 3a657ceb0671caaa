#!/usr/bin/env python3
"""Round 18A: a lab's or a teacher's own characters end to end, from the docs alone (docs/corpus.md "Store format",
"The character-data loader and fitter", docs/cli.md "Conventions: Characters", "corpus build | stats", "model",
"trial", "score", "characters", "session run | resume", "session plan", docs/python.md "Characters"). Run by CTest
as `cli_unseen_round18a_tests`.

A folder of the user's own `<char>.json` files in hanzi-writer-data's format: a one-stroke kana (あ, which
hanzi-writer-data lacks) whose outline uses relative commands, S and decimals and whose median has thirds; a
two-stroke Latin X with whole absolute outlines; a 30-stroke character outside the Basic Multilingual Plane
(U+20000); and the user's own one-stroke 十, which the bundled corpus has with two. Built into stores (the
defaults, `--outlines off`, `--medians off`, `--steps 16`), their stats, and each character's model (text, JSON,
SVG), trial and score from the folder and from the store compared (strokes, typical strokes, verdicts; control
points within the store's stated quantisation; medians and outline paths exactly); the store's 十 against the
bundled one; a folder with bad files among good ones; a protocol of the user's characters planned, run, reported
and resumed with and without the option; medians and outlines at and past the loader's and the store's bounds
(coordinates, points, strokes, commands, text length).

CALLIGRAPHY_CLI names the program, PYTHONPATH its Python module, CALLIGRAPHY_SOURCE_DIR the sources.
CALLIGRAPHY_SANITIZED=1 takes five cases.
"""
import json
import math
import shutil
import tempfile
import unittest
import xml.etree.ElementTree as ET
from pathlib import Path

from outsider import OneErrorLine, error_lines, run, sanitized_subset

load_tests = sanitized_subset({"test_store_stats_count_the_users_characters",
                               "test_model_json_from_store_within_quantisation_of_the_folder",
                               "test_store_character_wins_over_the_bundled_one",
                               "test_build_lists_bad_files_and_stores_the_good_ones",
                               "test_median_coordinates_past_the_bound_are_refused_naming_the_file"})

SHARED = {}
KANA = "\u3042"            # あ: hanzi-writer-data has none
BIG = "\U00020000"         # 𠀀: 30 strokes of the user's own
MAX_DURATION = "20"


def box(x0, y0, x1, y1):
    """A whole-number absolute outline: a rectangle, M L L L Z."""
    return f"M {x0} {y0} L {x1} {y0} L {x1} {y1} L {x0} {y1} Z"


def character_files():
    kana = {"strokes": ["M 100.5 480 l 400.25 -10.5 S 700 470 900.75 480 L 900 540 l -800 0.5 Z"],
            "medians": [[[110, 510], [333.3333333333333, 506.6666666666667], [666.6666666666666, 500.25],
                         [890, 510]]]}
    cross = {"strokes": ["M 120 880 L 180 900 L 900 140 L 840 120 Z", "M 840 900 L 900 880 L 180 120 L 120 140 Z"],
             "medians": [[[150, 890], [510, 510], [870, 130]], [[870, 890], [510, 510], [150, 130]]]}
    own_ten = {"strokes": [box(100, 100, 160, 900)], "medians": [[[130, 880], [130, 500], [130, 120]]]}
    rows = [60 + 30 * i for i in range(30)]
    big = {"strokes": [box(100, y - 8, 900, y + 8) for y in rows],
           "medians": [[[110, y], [500, y], [890, y]] for y in rows]}
    return {KANA: kana, "X": cross, "十": own_ten, BIG: big}


def write_folder(folder, files):
    folder.mkdir(parents=True, exist_ok=True)
    for ch, data in files.items():
        text = data if isinstance(data, str) else json.dumps(data, ensure_ascii=False)
        (folder / f"{ch}.json").write_text(text, encoding="utf-8")
    return folder


def cli(args, ok=True, cwd=None):
    result = run(args, cwd or SHARED["root"])
    if ok and result.returncode != 0:
        raise AssertionError(f"calligraphy {' '.join(map(str, args))}: {result.returncode}\n"
                             f"{result.stderr.decode('utf-8', 'replace')}")
    return result


def model_json(ch, *source):
    return json.loads(cli(["model", ch, "--json", *source]).stdout)


def control_points(model):
    """Every control point of the model's JSON, stroke by stroke, element by element."""
    out = []

    def walk(node):
        if isinstance(node, dict):
            for key, value in node.items():
                if key == "control_points" and isinstance(value, list):
                    out.append([tuple(p) for p in value])
                else:
                    walk(value)
        elif isinstance(node, list):
            for item in node:
                walk(item)
    walk(model)
    return out


def setUpModule():
    root = Path(tempfile.mkdtemp(prefix="r18a-"))
    SHARED["root"] = root
    own = write_folder(root / "own", character_files())
    (own / "notes.txt").write_text("not a character\n", encoding="utf-8")
    (own / "ab.json").write_text("{}", encoding="utf-8")  # two code points: no character's file, passed over
    SHARED["own"] = own
    for name, extra in (("own.clg", []), ("nooutlines.clg", ["--outlines", "off"]),
                        ("nomedians.clg", ["--medians", "off"]),
                        ("modelsonly.clg", ["--medians", "off", "--outlines", "off"]), ("fine.clg", ["--steps", "16"])):
        SHARED[name] = cli(["corpus", "build", "--data", own, "--out", root / name, "--threads", "1", *extra])


def tearDownModule():
    shutil.rmtree(SHARED["root"], ignore_errors=True)


class Store(unittest.TestCase, OneErrorLine):
    """corpus build of the user's folder and what the store then holds (docs/corpus.md, docs/cli.md)."""

    def test_store_stats_count_the_users_characters(self):
        for name, medians, outlines in (("own.clg", True, True), ("nooutlines.clg", True, False),
                                        ("nomedians.clg", False, True), ("modelsonly.clg", False, False)):
            stats = json.loads(cli(["corpus", "stats", SHARED["root"] / name, "--json"]).stdout)
            self.assertEqual(stats["characters"], 4, name)
            self.assertEqual(stats["strokes"], 34, name)   # 1 + 2 + 1 + 30
            self.assertEqual(sum(row["strokes"] for row in stats["typical_stroke_histogram"]), 34, name)
            self.assertEqual((stats["medians"], stats["outlines"]), (medians, outlines), name)
            self.assertEqual(stats["errors"], [], name)
            self.assertTrue(stats["checksums_ok"], name)

    def test_characters_of_store_and_folder_list_the_same(self):
        by_store = json.loads(cli(["characters", "--json", "--store", SHARED["root"] / "own.clg"]).stdout)
        by_data = json.loads(cli(["characters", "--json", "--data", SHARED["own"]]).stdout)
        rows = {c["character"]: (c["strokes"], c["typical_ids"]) for c in by_store["characters"]}
        self.assertEqual(set(rows), {KANA, "X", "十", BIG})
        self.assertEqual(by_store["count"], 4)
        self.assertEqual(rows, {c["character"]: (c["strokes"], c["typical_ids"]) for c in by_data["characters"]})
        self.assertEqual(rows[BIG][0], 30)
        self.assertEqual(rows["十"][0], 1)
        thirty = json.loads(cli(["characters", "--json", "--strokes", "30", "--store",
                                 SHARED["root"] / "own.clg"]).stdout)
        self.assertEqual([c["character"] for c in thirty["characters"]], [BIG])
        text = json.loads(cli(["characters", "--json", "--text", f"X{KANA}永", "--data", SHARED["own"]]).stdout)
        self.assertEqual([c["character"] for c in text["characters"]], ["X", KANA])
        self.assertEqual([c if isinstance(c, str) else c.get("character") for c in text["not_found"]], ["永"])

    def test_store_versions_follow_the_options(self):
        # Header: minor version 2 when the outlines flag is set, else 1 with the medians, 0 for the models only;
        # flags bit 0 medians, bit 1 outlines.
        for name, minor, flags in (("own.clg", 2, 3), ("nooutlines.clg", 1, 1), ("nomedians.clg", 2, 2),
                                   ("modelsonly.clg", 0, 0)):
            head = (SHARED["root"] / name).read_bytes()[:64]
            self.assertEqual(head[:8], b"CLGSTORE")
            self.assertEqual(int.from_bytes(head[10:12], "little"), minor, name)
            self.assertEqual(int.from_bytes(head[28:32], "little") & 3, flags, name)
            self.assertEqual(int.from_bytes(head[16:20], "little"), 4, name)

    def test_rebuild_is_byte_identical(self):
        out = SHARED["root"] / "again.clg"
        cli(["corpus", "build", "--data", SHARED["own"], "--out", out, "--threads", "2"])
        self.assertEqual(out.read_bytes(), (SHARED["root"] / "own.clg").read_bytes())

    def test_build_options_past_their_bounds_are_usage_errors(self):
        for extra, needle in ((["--tolerance", "0"], "--tolerance"), (["--steps", "3"], "--steps"),
                              (["--medians", "maybe"], "--medians"), (["--outlines", "yes"], "--outlines")):
            out = SHARED["root"] / "never.clg"
            result = cli(["corpus", "build", "--data", SHARED["own"], "--out", out, *extra], ok=False)
            self.assert_one_error(result, 2, needle)
            self.assertFalse(out.exists())


class FolderAndStoreAgree(unittest.TestCase, OneErrorLine):
    """model, trial and score of the user's characters from the folder and from the store."""

    def test_model_json_from_store_within_quantisation_of_the_folder(self):
        for name, bound in (("own.clg", math.sqrt(2) / 4), ("fine.clg", math.sqrt(2) / 32)):
            for ch in (KANA, "X", BIG):
                folder = model_json(ch, "--data", SHARED["own"])
                store = model_json(ch, "--store", SHARED["root"] / name)
                a, b = control_points(folder), control_points(store)
                self.assertEqual([len(e) for e in a], [len(e) for e in b], (name, ch))
                worst = max(math.dist(p, q) for ea, eb in zip(a, b) for p, q in zip(ea, eb))
                self.assertLessEqual(worst, bound + 1e-9, (name, ch))

    def test_model_text_and_svg_number_the_users_strokes(self):
        text = cli(["model", BIG, "--store", SHARED["root"] / "own.clg"]).stdout.decode()
        self.assertIn("30", text)
        svg = SHARED["root"] / "big.svg"
        cli(["model", BIG, "--store", SHARED["root"] / "own.clg", "--svg", svg])
        labels = {t.text.strip() for t in ET.parse(svg).iter() if t.tag.endswith("text") and t.text}
        self.assertIn("30", labels)
        self.assertIn("1", labels)
        self.assertNotIn("0", labels)
        self.assertNotIn("31", labels)

    def trial(self, ch, tag, *source):
        stem = SHARED["root"] / f"t-{tag}"
        result = cli(["trial", ch, *source, "--max-duration", MAX_DURATION, "--json", f"{stem}.json",
                      "--csv", f"{stem}.csv"], ok=False)
        self.assertEqual(result.returncode, 0, result.stderr.decode("utf-8", "replace"))
        return json.loads(Path(f"{stem}.json").read_text(encoding="utf-8")), Path(f"{stem}.csv")

    def test_trial_from_folder_and_store_agree(self):
        for ch in (KANA, "X"):
            a, _ = self.trial(ch, f"data-{ord(ch):X}", "--data", SHARED["own"])
            b, _ = self.trial(ch, f"store-{ord(ch):X}", "--store", SHARED["root"] / "own.clg")
            for record in (a, b):
                self.assertEqual(record["end_reason"], "completed")
            strip = [[(s["typical_id"], s["completed"]) for s in r["renderer_strokes"]] for r in (a, b)]
            self.assertEqual(strip[0], strip[1], ch)
            self.assertEqual(len(strip[0]), 2 if ch == "X" else 1)
            self.assertAlmostEqual(a["trial_time_s"], b["trial_time_s"], delta=0.05)

    def test_score_of_the_trace_from_folder_and_store_agree(self):
        _, trace = self.trial("X", "score-src", "--store", SHARED["root"] / "own.clg")
        scores = []
        for source in (["--data", SHARED["own"]], ["--store", SHARED["root"] / "own.clg"],
                       ["--store", SHARED["root"] / "nooutlines.clg"]):
            scores.append(json.loads(cli(["score", trace, "--character", "X", "--json", "-", *source]).stdout))
        for score in scores:
            verdicts = [seg.get("verdict") for seg in score["per_character"][0]["segments"]]
            self.assertEqual(len(score["per_character"][0]["per_stroke"]), 2)
            self.assertEqual(verdicts, [scores[0]["per_character"][0]["segments"][i].get("verdict")
                                        for i in range(len(verdicts))])
        self.assertEqual(scores[0]["per_character"][0]["segments"], scores[1]["per_character"][0]["segments"])

    def test_medians_off_store_still_trials_following_the_elements(self):
        record, trace = self.trial("X", "nomed", "--store", SHARED["root"] / "nomedians.clg")
        self.assertEqual([s["completed"] for s in record["renderer_strokes"]], [True, True])
        score = json.loads(cli(["score", trace, "--character", "X", "--json", "-",
                                "--store", SHARED["root"] / "nomedians.clg"]).stdout)
        self.assertEqual(len(score["per_character"][0]["per_stroke"]), 2)

    def test_store_character_wins_over_the_bundled_one(self):
        ours = model_json("十", "--store", SHARED["root"] / "own.clg")
        bundled = model_json("十")
        self.assertEqual((len(ours["strokes"]), len(bundled["strokes"])), (1, 2))
        self.assertEqual(cli(["characters", "--json", "--text", "十", "--store", SHARED["root"] / "own.clg"])
                         .stdout.count(b'"strokes": 1'), 1)
        record, _ = self.trial("十", "ten", "--store", SHARED["root"] / "own.clg")
        self.assertEqual(len(record["renderer_strokes"]), 1)

    def test_store_holds_only_its_own_characters(self):
        # --store FILE: "default none" -- the bundled characters are not behind it.
        result = cli(["model", "永", "--store", SHARED["root"] / "own.clg"], ok=False)
        self.assert_one_error(result, 2, "U+6C38")
        result = cli(["model", KANA], ok=False)
        self.assert_one_error(result, 2, "U+3042")

    def test_rerun_with_other_data_is_refused(self):
        record, _ = self.trial("十", "spec", "--store", SHARED["root"] / "own.clg")
        spec = SHARED["root"] / "t-spec.json"
        again = cli(["trial", "--spec", spec, "--store", SHARED["root"] / "own.clg",
                     "--json", SHARED["root"] / "again.json"])
        self.assertEqual(json.loads((SHARED["root"] / "again.json").read_text())["trial_time_s"],
                         record["trial_time_s"])
        self.assertEqual(again.returncode, 0)
        out = SHARED["root"] / "never.json"
        result = cli(["trial", "--spec", spec, "--json", out], ok=False)
        line = self.assert_one_error(result, 1, str(spec), "--data")
        self.assertNotIn("--corpus", line)   # no option of that name
        self.assertFalse(out.exists())


class Python(unittest.TestCase):
    """CharacterLibrary.from_hanzi_writer and from_store of the user's data (docs/python.md "Characters")."""

    @classmethod
    def setUpClass(cls):
        import calligraphy as cg
        cls.cg = cg
        cls.folder = cg.CharacterLibrary.from_hanzi_writer(str(SHARED["own"]))
        cls.store = cg.CharacterLibrary.from_store(str(SHARED["root"] / "own.clg"))

    def test_medians_from_store_equal_the_folder_exactly(self):
        for ch in (KANA, "X", BIG):
            a, b = self.folder.load(ch), self.store.load(ch)
            self.assertEqual(len(a.strokes), len(b.strokes))
            for sa, sb in zip(a.strokes, b.strokes):
                self.assertEqual(sa.median.tolist(), sb.median.tolist(), ch)
                self.assertEqual(sa.typical_id, sb.typical_id)
        self.assertEqual(self.store.load(KANA).strokes[0].median[1, 0], 333.3333333333333)

    def test_control_points_within_the_stated_quantisation(self):
        bound = self.store.store_info["max_quantisation_error"]
        self.assertLessEqual(bound, math.sqrt(2) / 4 + 1e-12)
        for ch in (KANA, "X", BIG):
            for sa, sb in zip(self.folder.load(ch).strokes, self.store.load(ch).strokes):
                for ea, eb in zip(sa.elements, sb.elements):
                    d = ((ea.control_points - eb.control_points) ** 2).sum(axis=1) ** 0.5
                    self.assertLessEqual(float(d.max()), bound + 1e-9, ch)

    def test_library_lists_the_users_characters(self):
        self.assertEqual(sorted(self.store.characters()), sorted([KANA, "X", "十", BIG]))
        self.assertEqual(len(self.folder), 4)
        self.assertIn(BIG, self.store)
        with self.assertRaises(self.cg.CharacterNotFound):
            self.store.load("永")

    def test_simulate_trial_matches_the_command_line(self):
        result = self.cg.simulate_trial(KANA, library=self.store, max_duration_s=float(MAX_DURATION), seed=0)
        stem = SHARED["root"] / "py-kana.json"
        cli(["trial", KANA, "--store", SHARED["root"] / "own.clg", "--max-duration", MAX_DURATION,
             "--json", stem])
        record = json.loads(stem.read_text(encoding="utf-8"))
        self.assertEqual(result.metrics["trial_time_s"], record["trial_time_s"])
        self.assertEqual(result.metrics["strokes_completed"], 1)

    def test_stores_without_medians_say_so_and_have_none(self):
        cg = self.cg
        for name, medians in (("own.clg", True), ("nooutlines.clg", True), ("nomedians.clg", False),
                              ("modelsonly.clg", False)):
            lib = cg.CharacterLibrary.from_store(str(SHARED["root"] / name))
            self.assertEqual(lib.store_info["medians"], medians, name)
            stroke = lib.load("X").strokes[0]
            self.assertEqual(stroke.median.shape[0] > 0, medians, name)
            if not medians:
                self.assertEqual(stroke.median.shape, (0, 2))


class BadFiles(unittest.TestCase, OneErrorLine):
    """One bad file among good ones (docs/cli.md "corpus build": listed, the rest stored, exit 1)."""

    def test_build_lists_bad_files_and_stores_the_good_ones(self):
        files = character_files()
        folder = write_folder(SHARED["root"] / "mixed", {KANA: files[KANA], "X": files["X"],
                                                         "Z": '{"strokes": ["M 0 0 Z"], "medians": [[[1, 2]',
                                                         "Y": {"strokes": ["M 0 0 L 1 1 Z"]}})
        out = SHARED["root"] / "mixed.clg"
        result = cli(["corpus", "build", "--data", folder, "--out", out], ok=False)
        self.assertEqual(result.returncode, 1, result.stderr)
        stdout = result.stdout.decode("utf-8", "replace")
        self.assertIn("Z", stdout)
        self.assertIn("Y", stdout)
        self.assertIn("/medians", stdout)
        self.assertEqual(len(error_lines(result)), 1, error_lines(result))
        listing = json.loads(cli(["characters", "--json", "--store", out]).stdout)
        self.assertEqual(sorted(c["character"] for c in listing["characters"]), sorted([KANA, "X"]))

    def test_file_names_say_the_character_whatever_the_file_holds(self):
        # docs/corpus.md: the file's name says which character it is (a `character` key is ignored); a name that
        # is white space is no character's, other files are passed over; a leading byte-order mark is skipped.
        cross = json.dumps(character_files()["X"])
        folder = write_folder(SHARED["root"] / "names", {"K": json.dumps({"character": "永", **json.loads(cross)}),
                                                         " ": cross, "B": "\ufeff" + cross,
                                                         "\u00e9": cross, "e\u0301": cross})
        (folder / "X.txt").write_text(cross, encoding="utf-8")
        out = SHARED["root"] / "names.clg"
        cli(["corpus", "build", "--data", folder, "--out", out])
        listing = json.loads(cli(["characters", "--json", "--store", out]).stdout)
        # é (U+00E9) is one code point, a character; e and a combining acute are two: no character's file.
        self.assertEqual(sorted(c["character"] for c in listing["characters"]), ["B", "K", "\u00e9"])
        self.assert_one_error(cli(["model", "永", "--store", out], ok=False), 2, "U+6C38")

    def test_folder_of_only_bad_files_writes_no_store(self):
        folder = write_folder(SHARED["root"] / "allbad", {"Q": "[]"})
        out = SHARED["root"] / "allbad.clg"
        out.write_bytes(b"earlier")
        result = cli(["corpus", "build", "--data", folder, "--out", out], ok=False)
        self.assertEqual(result.returncode, 1)
        self.assertEqual(out.read_bytes(), b"earlier")
        self.assertIn("allbad", result.stderr.decode("utf-8", "replace"))


class Session(unittest.TestCase, OneErrorLine):
    """A protocol naming the user's characters (docs/cli.md "session plan", "session run | resume", "report")."""

    def protocol(self):
        path = SHARED["root"] / "own-protocol.json"
        path.write_text(json.dumps({"name": "own", "conditions": [{"name": "V", "mode": "vision"}],
                                    "test": {"characters": [KANA, "十"], "conditions": ["V"], "repetitions": 1},
                                    "trial": {"max_duration_s": 20}}, ensure_ascii=False), encoding="utf-8")
        return path

    def test_plan_without_the_store_names_the_character(self):
        result = cli(["session", "plan", self.protocol(), "--subjects", "1"], ok=False)
        self.assert_one_error(result, 2, "own-protocol.json", "/test/characters/0", "U+3042")
        plan = json.loads(cli(["session", "plan", self.protocol(), "--subjects", "1", "--json",
                               "--store", SHARED["root"] / "own.clg"]).stdout)
        items = [i for s in plan["subjects"][0]["sessions"] for p in s["phases"] for i in p["items"]]
        self.assertEqual(sorted(items), sorted([KANA, "十"]))

    def test_run_report_and_resume_with_and_without_the_store(self):
        study = SHARED["root"] / "study"
        store = SHARED["root"] / "own.clg"
        cli(["session", "run", self.protocol(), "--subjects", "1", "--out", study, "--store", store])
        sessions = list(study.glob("S01/own-*"))
        self.assertEqual(len(sessions), 1)
        records = sorted(sessions[0].glob("trials/*.json"))
        self.assertEqual(len(records), 2)
        by_char = {json.loads(r.read_text(encoding="utf-8"))["characters"]: r for r in records}
        ten = json.loads(by_char["十"].read_text(encoding="utf-8"))
        self.assertEqual(ten["strokes_total"], 1)   # the user's 十, not the bundled one
        report = SHARED["root"] / "report.html"
        cli(["report", study, "--out", report])
        pages = list((SHARED["root"] / "report_files").rglob("*.html"))
        self.assertEqual(len(pages), 1, pages)
        page = pages[0].read_text(encoding="utf-8")
        self.assertIn("十", page)
        self.assertIn(KANA, page)
        # Make the session unfinished: the last trial's files removed, as after a crash while it ran.
        last = records[-1]
        last_char = json.loads(last.read_text(encoding="utf-8"))["characters"]
        for f in sessions[0].glob(f"trials/{last.stem}*"):
            f.unlink()
        without = cli(["session", "resume", sessions[0]], ok=False)
        self.assert_one_error(without, 2, "U+3042")
        self.assertFalse(any(sessions[0].glob(f"trials/{last.stem}*")))
        cli(["session", "resume", sessions[0], "--store", store])
        again = list(sessions[0].glob(f"trials/{last.stem}*.json"))
        self.assertEqual(len(again), 1)
        redone = json.loads(again[0].read_text(encoding="utf-8"))
        self.assertEqual(redone["characters"], last_char)
        self.assertEqual(redone["end_reason"], "completed")


    def test_resume_goes_on_with_the_data_the_session_ran_with(self):
        # The bundled corpus has 十 too, with two strokes: a session of the user's one-stroke 十 resumed without
        # its --store (or with another folder) would write another shape of 十 into the same session. It is
        # refused naming the saved record and the character, nothing written; with the same data it goes on.
        protocol = SHARED["root"] / "ten-protocol.json"
        protocol.write_text(json.dumps({"name": "ten", "conditions": [{"name": "V", "mode": "vision"}],
                                        "test": {"characters": ["十"], "conditions": ["V"], "repetitions": 2},
                                        "trial": {"max_duration_s": 20}}, ensure_ascii=False), encoding="utf-8")
        study = SHARED["root"] / "ten-study"
        store = SHARED["root"] / "own.clg"
        cli(["session", "run", protocol, "--subjects", "1", "--out", study, "--store", store])
        session = next(study.glob("S01/ten-*"))
        first, last = sorted(session.glob("trials/*.json"))
        for f in session.glob(f"trials/{last.stem}*"):
            f.unlink()
        moved = write_folder(SHARED["root"] / "moved", {"十": {"strokes": [box(110, 100, 170, 900)],
                                                              "medians": [[[140, 880], [140, 500], [140, 120]]]}})
        for option in ([], ["--data", moved]):
            refused = cli(["session", "resume", session, *option], ok=False)
            self.assert_one_error(refused, 1, first.name, "十")
            self.assertFalse(any(session.glob(f"trials/{last.stem}*")))
        # The user's folder gives the same 十 as the store (whole units, a line: nothing quantised away).
        cli(["session", "resume", session, "--data", SHARED["own"]])
        redone = json.loads(last.read_text(encoding="utf-8"))
        self.assertEqual(redone["strokes_total"], 1)
        self.assertEqual(redone["specification"]["scene"]["sha256"],
                         json.loads(first.read_text(encoding="utf-8"))["specification"]["scene"]["sha256"])


class Bounds(unittest.TestCase, OneErrorLine):
    """Medians and outlines at and past the documented bounds in a user's file (docs/corpus.md)."""

    def build(self, tag, files, ok=True):
        folder = write_folder(SHARED["root"] / f"b-{tag}", files)
        out = SHARED["root"] / f"b-{tag}.clg"
        result = cli(["corpus", "build", "--data", folder, "--out", out, "--threads", "1"], ok=ok)
        return folder, out, result

    def test_median_coordinates_at_the_bound_are_stored_exactly(self):
        median = [[-100000, -100000], [100000, 100000]]
        files = {"B": {"strokes": [box(-100000, -100000, 100000, 100000)], "medians": [median]}}
        folder, out, _ = self.build("edge", files)
        import calligraphy as cg
        loaded = cg.CharacterLibrary.from_store(str(out)).load("B")
        self.assertEqual(loaded.strokes[0].median.tolist(), median)
        model = model_json("B", "--store", out)
        self.assertEqual(len(control_points(model)), len(control_points(model_json("B", "--data", folder))))

    def test_median_coordinates_past_the_bound_are_refused_naming_the_file(self):
        files = {"C": {"strokes": [box(0, 0, 10, 10)], "medians": [[[0, 0], [100000.5, 10]]]}}
        folder, out, result = self.build("past", files, ok=False)
        self.assertEqual(result.returncode, 1)
        self.assertIn("C.json", result.stdout.decode("utf-8", "replace") + result.stderr.decode())
        self.assertFalse(out.exists())
        self.assert_one_error(cli(["model", "C", "--data", folder], ok=False), 1, "C.json", "/medians")

    def test_median_of_the_most_points_round_trips(self):
        points = [[i * 0.1, 500] for i in range(10000)]
        ok = {"M": {"strokes": [box(0, 490, 1000, 510)], "medians": [points]}}
        folder, out, _ = self.build("most", ok)
        import calligraphy as cg
        self.assertEqual(cg.CharacterLibrary.from_store(str(out)).load("M").strokes[0].median.tolist(),
                         cg.CharacterLibrary.from_hanzi_writer(str(folder)).load("M").strokes[0].median.tolist())
        over = {"N": {"strokes": [box(0, 490, 1000, 510)], "medians": [points + [[1000.5, 500]]]}}
        folder, out, result = self.build("over", over, ok=False)
        self.assertEqual(result.returncode, 1)
        self.assert_one_error(cli(["model", "N", "--data", folder], ok=False), 1, "N.json", "/medians/0")

    def test_strokes_at_and_past_the_loaders_bound(self):
        # 128 strokes (medians) at most: the 129th is refused at its pointer, the rest of the folder stored.
        def lines(n):
            rows = [4 + 7 * i for i in range(n)]
            return {"strokes": [box(100, y, 900, y + 3) for y in rows],
                    "medians": [[[110, y + 1], [890, y + 1]] for y in rows]}
        folder, out, result = self.build("many", {"V": lines(128), "W": lines(129)}, ok=False)
        self.assertEqual(result.returncode, 1, result.stderr)
        stdout = result.stdout.decode("utf-8", "replace")
        self.assertIn("W.json", stdout)
        self.assertIn("/medians/128", stdout)
        listing = json.loads(cli(["characters", "--json", "--store", out]).stdout)
        self.assertEqual([(c["character"], c["strokes"]) for c in listing["characters"]], [("V", 128)])

    def test_outline_of_many_commands_and_long_text(self):
        # A compact outline counts at most 65,535 commands (more: kept as text); a path kept as text is at most
        # 1,048,575 bytes: a longer one is refused naming the file and its pointer, the rest of the folder stored.
        many = "M 0 0 " + " ".join(f"L {i % 1000} {i // 1000}" for i in range(1, 70001)) + " Z"
        long = "M 0 0 " + " ".join(f"l 0.0001 {0.001 if i % 2 else -0.001}" for i in range(80000)) + " Z"
        self.assertGreater(len(long.encode()), 1_048_575)
        median = [[[10, 10], [900, 10]]]
        files = {"P": {"strokes": [many], "medians": median}, "T": {"strokes": [long], "medians": median},
                 "X": character_files()["X"]}
        folder, out, result = self.build("outl", files, ok=False)
        self.assertEqual(result.returncode, 1, result.stderr)
        stdout = result.stdout.decode("utf-8", "replace")
        self.assertIn("T.json", stdout)
        self.assertIn("/strokes/0", stdout)
        listing = json.loads(cli(["characters", "--json", "--store", out]).stdout)
        self.assertEqual(sorted(c["character"] for c in listing["characters"]), ["P", "X"])
        stats = json.loads(cli(["corpus", "stats", out, "--json"]).stdout)
        self.assertEqual(stats.get("errors", []), [])
        self.assert_one_error(cli(["model", "T", "--data", folder], ok=False), 1, "T.json", "/strokes/0")


if __name__ == "__main__":
    unittest.main(verbosity=2)
