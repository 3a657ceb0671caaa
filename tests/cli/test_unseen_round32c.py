#!/usr/bin/env python3
"""Round 32C: character data written by hand: `model`, `characters`, `score`, `corpus build|stats` and Python's
`CharacterLibrary`, as a teacher who writes a character file of her own and a lab that builds its own store use
them. From the docs alone: docs/cli.md (Conventions "Characters", Exit statuses, `model`, `characters`, `score`,
"Pen traces: format and limits", `corpus build | stats`), docs/corpus.md (store format 1.2, "Checks and errors",
"The character-data loader and fitter"), docs/references.md "Character data", docs/python.md "Characters" and
"Errors", include/calligraphy/model/character_library.hpp and corpus_store.hpp, and the commands' --help.

A hanzi-writer-data JSON file of 十 (two straight strokes) is written by hand and modelled (typical strokes in
file order, the SVG in the 1024 box y down, a pen path along its medians scored as accepted); then hostile
variants, each refused with one line naming the file and the JSON pointer: medians of one point or one point
repeated, NaN, 1e308, 100,001 units, outlines and medians of different counts, an outline path of 1,048,576
bytes, 129 medians, 10,001 points, UTF-16, 50 MB (sparse), a symbolic link loop, a FIFO, a key given twice, a
NUL and text after the document. `corpus build` over folders of good and bad files, medians in quarter units,
thirds and 5e-324, a character outside the BMP, a stroke of 271 elements and outline paths of 65,536 and
100,001 commands; the store read back by `characters`, `model`, `score`, `corpus stats` and Python; stores cut,
with a flipped byte, a link loop, a FIFO and 5 GiB (sparse) in their place.

CALLIGRAPHY_CLI names the program; PYTHONPATH the built Python package. CALLIGRAPHY_SANITIZED=1 takes five cases.
"""
import json
import os
import re
import shutil
import tempfile
import unittest
import xml.etree.ElementTree as ET
from pathlib import Path

from outsider import OneErrorLine, error_lines, run, run_ok, sanitized_subset

try:
    import numpy as np
    import calligraphy as cg
except ImportError:  # reported by setUpClass
    np = cg = None

load_tests = sanitized_subset({"test_hand_written_character_is_modelled_with_its_strokes_in_file_order",
                               "test_median_of_one_point_is_refused_naming_the_file_and_pointer",
                               "test_nul_and_text_after_the_document_is_refused_as_malformed_json",
                               "test_record_with_a_flipped_byte_is_refused_naming_file_offset_and_character",
                               "test_build_over_good_and_bad_files_lists_the_bad_and_stores_the_others"})

# 十 written by hand: stroke 1 a horizontal (H), stroke 2 a vertical (S); outlines as SVG path strings.
OUTLINES = ["M 100 440 L 900 440 L 900 480 L 100 480 Z", "M 480 800 L 520 800 L 520 -30 L 480 -30 Z"]
MEDIANS = [[[110, 460], [500, 462], [890, 465]], [[500, 800], [500, 400], [500, -30]]]
ONE = {"strokes": OUTLINES[:1], "medians": MEDIANS[:1]}   # 一: the horizontal alone


def doc(strokes=OUTLINES, medians=MEDIANS, **more):
    """A hanzi-writer-data character file's text."""
    d = {"strokes": strokes, "medians": medians}
    d.update(more)
    return json.dumps(d)


def zigzag(points, amplitude=100.0):
    """A median of `points` points zig-zagging along x: every vertex a corner, one line element each."""
    return [[100 + 800 * i / (points - 1), 400 + (amplitude if i % 2 else 0)] for i in range(points)]


class Folder(unittest.TestCase, OneErrorLine):
    """Each case gets its own temporary folder; `data(name, files)` makes a character data folder in it."""

    @classmethod
    def setUpClass(cls):
        if cg is None:
            raise unittest.SkipTest("numpy and the calligraphy Python package (PYTHONPATH) are needed")

    def setUp(self):
        self.tmp = Path(tempfile.mkdtemp(prefix="round32c-"))
        self.addCleanup(shutil.rmtree, self.tmp, True)

    def data(self, name, files):
        folder = self.tmp / name
        folder.mkdir()
        for file_name, content in files.items():
            path = folder / file_name
            if callable(content):
                content(path)
            elif isinstance(content, bytes):
                path.write_bytes(content)
            else:
                path.write_text(content, encoding="utf-8")
        return folder

    def cli(self, *args):
        return run([str(a) for a in args], self.tmp)

    def model_json(self, char, *source):
        return json.loads(run_ok(["model", char, *source, "--json"], self.tmp).stdout)


class HandWrittenCharacter(Folder):
    def test_hand_written_character_is_modelled_with_its_strokes_in_file_order(self):
        self.data("a", {"十.json": doc()})
        self.data("b", {"十.json": doc(medians=MEDIANS[::-1], strokes=OUTLINES[::-1])})
        m = self.model_json("十", "--data", "a")
        self.assertEqual(m["typical_stroke_ids"], [1, 2])            # H then S, as the file orders them
        self.assertEqual(m["typical_strokes"], 2)
        for stroke, median in zip(m["strokes"], MEDIANS):            # straight medians: one line each, end to end
            self.assertEqual(stroke["feature_points"], [median[0], median[-1]])
        self.assertEqual(self.model_json("十", "--data", "b")["typical_stroke_ids"], [2, 1])
        text = run_ok(["model", "十", "--data", "a"], self.tmp).stdout.decode()
        self.assertIn("十 (U+5341)", text)
        self.assertIn("十.json", text)

    def test_model_svg_draws_each_stroke_in_order_in_the_1024_box_y_down(self):
        # references.md: the data box is 1024 units, y up, upper-left (0, 900): on the SVG y is 900 - y.
        self.data("a", {"十.json": doc()})
        m = self.model_json("十", "--data", "a")
        svg = ET.fromstring(run_ok(["model", "十", "--data", "a", "--svg", "-"], self.tmp).stdout)
        ns = "{http://www.w3.org/2000/svg}"
        groups = [g for g in svg.iter(ns + "g") if g.get("class") == "stroke"]
        self.assertEqual([g.get("id") for g in groups], ["stroke-1", "stroke-2"])
        self.assertEqual([int(g.get("data-typical-id")) for g in groups], [1, 2])
        for g, median, stroke in zip(groups, MEDIANS, m["strokes"]):
            line = [e for e in g.iter(ns + "polyline") if e.get("class") == "median"][0]
            drawn = [tuple(map(float, p.split(","))) for p in line.get("points").split()]
            self.assertEqual(drawn, [(x, 900.0 - y) for x, y in median])
            path = [e for e in g.iter(ns + "path") if e.get("class") == "element"][0]
            numbers = [float(v) for v in re.findall(r"-?\d+(?:\.\d+)?", path.get("d"))]
            (x0, y0), (x1, y1) = stroke["feature_points"]
            self.assertEqual((numbers[0], numbers[1], numbers[-2], numbers[-1]), (x0, 900 - y0, x1, 900 - y1))

    def test_score_of_a_pen_along_the_medians_accepts_both_strokes_from_folder_and_store(self):
        self.data("a", {"十.json": doc()})
        rows, t = ["t,x,y,pen"], 0.0
        for median in MEDIANS:
            m = np.asarray(median, float)
            path = np.concatenate([np.linspace(m[i], m[i + 1], 100, endpoint=False) for i in range(len(m) - 1)]
                                  + [m[-1:]])
            for x, y in path:
                rows.append(f"{t:.3f},{x:.3f},{y:.3f},1")
                t += 0.004
            rows.append(f"{t:.3f},{path[-1][0]:.3f},{path[-1][1]:.3f},0")
            t += 0.2
        (self.tmp / "t.csv").write_text("\n".join(rows) + "\n")
        run_ok(["corpus", "build", "--data", "a", "--out", "s.clg"], self.tmp)
        for source in (["--data", "a"], ["--store", "s.clg"]):
            s = json.loads(run_ok(["score", "t.csv", "--character", "十", *source, "--units", "data", "--json", "-"],
                                  self.tmp).stdout)
            self.assertEqual((s["strokes_accepted"], s["order_errors"]), (2, 0), source)

    def test_character_key_is_ignored_the_file_name_says_which_character(self):
        self.data("a", {"二.json": doc(character="十")})
        m = self.model_json("二", "--data", "a")
        self.assertEqual(m["character"], "二")
        self.assert_one_error(self.cli("model", "十", "--data", "a"), 2, "U+5341")

    def test_kangxi_radical_file_is_its_own_character_not_the_ideograph(self):
        self.data("a", {"⼀.json": doc(**ONE)})
        self.assertEqual(self.model_json("⼀", "--data", "a")["typical_stroke_ids"], [1])
        self.assert_one_error(self.cli("model", "一", "--data", "a"), 2, "U+4E00")

    def test_names_of_white_space_or_control_characters_are_no_characters(self):
        files = {name + ".json": doc() for name in ("\u3000", "\u0085", "\u2028", "\u00a0", "\t", " ")}
        files["十.json"] = doc()
        self.data("a", files)
        listed = json.loads(run_ok(["characters", "--data", "a", "--json"], self.tmp).stdout)
        self.assertEqual([c["character"] for c in listed["characters"]], ["十"])
        self.assertEqual(listed["count"], 1)

    def test_byte_order_mark_and_repeated_points_are_accepted(self):
        repeated = [MEDIANS[0], [[500, 800], [500, 800], [500, 800], [500, -30], [500, -30]]]
        self.data("a", {"十.json": ("\ufeff" + doc(medians=repeated)).encode()})
        m = self.model_json("十", "--data", "a")
        self.assertEqual(m["typical_stroke_ids"], [1, 2])
        self.assertEqual(m["strokes"][1]["feature_points"], [[500, 800], [500, -30]])

    def test_coordinate_at_100000_is_accepted_and_100001_refused(self):
        at = [MEDIANS[0], [[500, 800], [500, -100000]]]
        past = [MEDIANS[0], [[500, 800], [500, -100001]]]
        self.data("a", {"十.json": doc(medians=at)})
        self.data("b", {"十.json": doc(medians=past)})
        self.assertEqual(self.model_json("十", "--data", "a")["strokes"][1]["feature_points"][-1], [500, -100000])
        self.assert_one_error(self.cli("model", "十", "--data", "b"), 1, "十.json", "/medians/1/1/1")


class RefusedAtTheDoor(Folder):
    """Each hostile file: `model` exits 1 with one line naming the file, the character and the JSON pointer."""

    def refused(self, content, *needles, name="十"):
        self.data("a", {name + ".json": content})
        result = self.cli("model", name, "--data", "a")
        return self.assert_one_error(result, 1, name + ".json", *needles)

    def test_median_of_one_point_is_refused_naming_the_file_and_pointer(self):
        self.refused(doc(medians=[MEDIANS[0], [[500, 800]]]), "U+5341", "/medians/1")

    def test_median_of_one_point_repeated_is_refused_naming_it(self):
        self.refused(doc(medians=[MEDIANS[0], [[500, 800], [500, 800]]]), "/medians/1")

    def test_nan_is_malformed_json_at_its_line_column_and_pointer(self):
        line = self.refused(doc().replace("[500, 400]", "[500, NaN]"), "/medians/1/1/1")
        self.assertRegex(line, r"\b1:\d+")

    def test_1e308_and_1e400_are_refused_at_their_pointer(self):
        self.refused(doc().replace("[500, 400]", "[500, 1e308]"), "/medians/1/1/1")
        shutil.rmtree(self.tmp / "a")
        self.refused(doc().replace("[500, 400]", "[1e400, 400]"), "/medians/1/1/0")

    def test_outlines_and_medians_of_different_counts_are_refused_naming_strokes(self):
        self.refused(doc(strokes=OUTLINES[:1]), "/strokes")

    def test_outline_path_of_1048576_bytes_is_refused_naming_it(self):
        path = "M 0 0 L 10 0 L 10 10 Z"
        self.refused(doc(strokes=[path + " " * (1048576 - len(path)), OUTLINES[1]]), "/strokes/0")

    def test_129_medians_and_10001_points_are_refused_at_the_first_too_many(self):
        self.refused(json.dumps({"medians": [[[10 * i, 400], [10 * i, 300]] for i in range(129)]}),
                     "/medians/128")
        shutil.rmtree(self.tmp / "a")
        self.refused(json.dumps({"medians": [zigzag(10001, 1)]}), "/medians/0/10000")

    def test_utf16_text_is_refused_naming_the_file(self):
        self.refused(doc().encode("utf-16"))

    def test_50_mb_file_is_refused_naming_its_size_before_it_is_read(self):
        def sparse(path):
            path.write_text(doc())
            os.truncate(path, 50 << 20)
        self.refused(sparse, "52428800")

    def test_symbolic_link_loop_and_fifo_are_refused_without_a_wait(self):
        self.refused(lambda p: os.symlink(p.name, p))
        shutil.rmtree(self.tmp / "a")
        self.refused(lambda p: os.mkfifo(p), "FIFO")

    def test_medians_given_twice_is_refused_naming_the_key(self):
        text = '{"medians": %s, "strokes": %s, "medians": %s}' % (
            json.dumps(MEDIANS), json.dumps(OUTLINES), json.dumps(MEDIANS[:1]))
        self.refused(text, "/medians")

    def test_strokes_given_twice_is_refused_naming_the_key(self):
        # cli.md: "Every JSON file the program reads ... refuses a key given twice in one object, naming the file
        # and the key's JSON pointer"; `strokes` is read (the outlines), so one of two would be taken silently.
        text = '{"strokes": %s, "medians": %s, "strokes": %s}' % (
            json.dumps(OUTLINES), json.dumps(MEDIANS), json.dumps(["M 0 0 L 9 0 L 9 9 Z", "M 1 1 L 8 1 L 8 8 Z"]))
        self.refused(text, "/strokes")

    def test_nul_and_text_after_the_document_is_refused_as_malformed_json(self):
        # A document followed by other text is malformed (`} x` is refused: "expected end of input"); a NUL
        # byte and text after it are no less so.
        self.refused(doc().encode() + b"\0 and then {{{ anything")

    def test_text_after_the_document_is_refused(self):
        self.refused(doc() + " x", "line:column")

    def test_python_load_raises_data_error_naming_file_and_pointer(self):
        self.data("a", {"十.json": doc(medians=[MEDIANS[0], [[500, 800]]]), "一.json": json.dumps(ONE)})
        lib = cg.CharacterLibrary.from_hanzi_writer(self.tmp / "a")
        self.assertEqual(lib.characters(), ["一", "十"])
        with self.assertRaises(cg.DataError) as caught:
            lib.load("十")
        self.assertIn("十.json", str(caught.exception))
        self.assertIn("/medians/1", str(caught.exception))
        self.assertEqual(lib.load("一").typical_stroke_ids, [1])
        with self.assertRaises(cg.DataError):
            cg.CharacterLibrary.from_hanzi_writer(self.tmp / "none")


class CorpusBuild(Folder):
    def test_build_over_good_and_bad_files_lists_the_bad_and_stores_the_others(self):
        self.data("a", {"十.json": doc(), "一.json": json.dumps(ONE), "README.md": "not a character",
                        "二.json": doc(medians=[MEDIANS[0], [[5, 5]]]), "八.json": "{"})
        result = self.cli("corpus", "build", "--data", "a", "--out", "s.clg")
        line = self.assert_one_error(result, 1, "2 of", "s.clg")
        self.assertTrue("二.json: " in line or "八.json: " in line, line)      # names the first
        out = result.stdout.decode()
        self.assertIn("二 (U+4E8C)", out)
        self.assertIn("/medians/1", out)
        self.assertIn("八 (U+516B)", out)
        listed = json.loads(run_ok(["characters", "--store", "s.clg", "--json"], self.tmp).stdout)
        self.assertEqual([c["character"] for c in listed["characters"]], ["一", "十"])
        self.assertEqual(self.model_json("十", "--store", "s.clg")["typical_stroke_ids"], [1, 2])
        self.assert_one_error(self.cli("model", "二", "--store", "s.clg"), 2, "U+4E8C")
        stats = json.loads(run_ok(["corpus", "stats", "s.clg", "--json"], self.tmp).stdout)
        self.assertEqual((stats["characters"], stats["strokes"], stats["format_version"]), (2, 3, "1.2"))

    def test_build_where_nothing_can_be_modelled_keeps_the_earlier_store(self):
        self.data("a", {"十.json": "{", "二.json": lambda p: os.mkfifo(p)})
        self.data("empty", {"notes.txt": "x"})
        (self.tmp / "s.clg").write_bytes(b"earlier store")
        self.assert_one_error(self.cli("corpus", "build", "--data", "a", "--out", "s.clg"), 1, "s.clg")
        self.assert_one_error(self.cli("corpus", "build", "--data", "empty", "--out", "s.clg"), 1, "empty")
        self.assertEqual((self.tmp / "s.clg").read_bytes(), b"earlier store")
        self.assertEqual(sorted(p.name for p in self.tmp.iterdir()), ["a", "empty", "s.clg"])

    def test_output_onto_a_character_file_is_refused_and_the_file_kept(self):
        self.data("a", {"十.json": doc()})
        self.assert_one_error(self.cli("corpus", "build", "--data", "a", "--out", "a/十.json"), 2,
                              "--out", "--data", "十.json")
        self.assertEqual((self.tmp / "a" / "十.json").read_text(encoding="utf-8"), doc())

    def test_medians_come_back_exactly_and_elements_within_the_quantisation(self):
        exact = [[[110.25, 460.5], [500.75, 462], [890, 465.25]],
                 [[500, 800], [500, 1 / 3], [5e-324, -30], [0.5, -100000]]]
        self.data("a", {"十.json": doc(medians=exact), "𠀀.json": doc(medians=MEDIANS),
                        "一.json": json.dumps({"medians": [zigzag(31, 3)]})})
        run_ok(["corpus", "build", "--data", "a", "--out", "s.clg"], self.tmp)
        store = cg.CharacterLibrary.from_store(self.tmp / "s.clg")
        folder = cg.CharacterLibrary.from_hanzi_writer(self.tmp / "a")
        self.assertEqual(store.characters(), ["一", "十", "𠀀"])
        bound = store.store_info["max_quantisation_error"]
        self.assertLessEqual(bound, 0.36)
        sources = {"十": exact, "𠀀": MEDIANS, "一": [zigzag(31, 3)]}
        for char, medians in sources.items():
            stored, fitted = store.load(char), folder.load(char)
            self.assertEqual(stored.source, f"{self.tmp / 's.clg'}#{char} (U+{ord(char):04X})")
            for s, f, m in zip(stored.strokes, fitted.strokes, medians):
                self.assertTrue(np.array_equal(np.asarray(s.median), np.asarray(m, dtype=float)), char)
                self.assertEqual(len(s.elements), len(f.elements))
                for es, ef in zip(s.elements, f.elements):
                    gap = np.linalg.norm(np.asarray(es.control_points) - np.asarray(ef.control_points), axis=1)
                    self.assertLessEqual(gap.max(), bound + 1e-9, char)

    def test_build_is_the_same_bytes_whatever_the_threads(self):
        self.data("a", {"十.json": doc(), "一.json": json.dumps(ONE), "二.json": doc(medians=MEDIANS[::-1])})
        run_ok(["corpus", "build", "--data", "a", "--out", "one.clg", "--threads", "1"], self.tmp)
        run_ok(["corpus", "build", "--data", "a", "--out", "two.clg", "--threads", "2"], self.tmp)
        self.assertEqual((self.tmp / "one.clg").read_bytes(), (self.tmp / "two.clg").read_bytes())

    def test_stroke_of_271_elements_is_stored_as_the_format_allows(self):
        # corpus.md, Record: "count:4 [count_extension:8 if count = 15]  elements = count + 1 (+ extension)":
        # 15 + 1 + 255 = 271 elements at most.
        self.data("a", {"乙.json": json.dumps({"medians": [zigzag(272)]})})
        self.assertEqual(self.model_json("乙", "--data", "a")["strokes"][0]["element_count"], 271)
        result = self.cli("corpus", "build", "--data", "a", "--out", "s.clg")
        self.assertEqual(result.returncode, 0, result.stderr.decode())
        self.assertEqual(self.model_json("乙", "--store", "s.clg")["strokes"][0]["element_count"], 271)

    def test_stroke_of_272_elements_is_listed_as_not_modelled(self):
        self.data("a", {"乙.json": json.dumps({"medians": [zigzag(273)]}), "十.json": doc()})
        result = self.cli("corpus", "build", "--data", "a", "--out", "s.clg")
        self.assert_one_error(result, 1, "1 of", "乙")
        self.assertIn("乙 (U+4E59)", result.stdout.decode())
        listed = json.loads(run_ok(["characters", "--store", "s.clg", "--json"], self.tmp).stdout)
        self.assertEqual([c["character"] for c in listed["characters"]], ["十"])

    def test_outline_paths_of_65536_and_100001_commands_are_stored_and_read_back(self):
        def path(n):  # n commands: M, n - 2 L, Z
            return "M 0 0 " + " ".join(f"L {i % 1000} {1 + i // 1000}" for i in range(1, n - 1)) + " Z"
        self.data("a", {"一.json": doc(strokes=[path(65536)], medians=MEDIANS[:1]),
                        "十.json": doc(strokes=[path(100001), OUTLINES[1]])})
        run_ok(["corpus", "build", "--data", "a", "--out", "s.clg"], self.tmp)
        stats = json.loads(run_ok(["corpus", "stats", "s.clg", "--json"], self.tmp).stdout)
        self.assertEqual((stats["characters"], stats["checksums_ok"], stats["errors"]), (2, True, []))
        self.assertTrue(stats["outlines"])
        self.assertEqual(self.model_json("十", "--store", "s.clg")["typical_stroke_ids"], [1, 2])

    def test_medians_off_and_outlines_off_give_the_documented_formats(self):
        self.data("a", {"十.json": doc()})
        run_ok(["corpus", "build", "--data", "a", "--out", "m.clg", "--medians", "off"], self.tmp)
        run_ok(["corpus", "build", "--data", "a", "--out", "n.clg", "--medians", "off", "--outlines", "off"],
               self.tmp)
        for name, version, medians, outlines in (("m.clg", "1.2", False, True), ("n.clg", "1.0", False, False)):
            info = cg.CharacterLibrary.from_store(self.tmp / name).store_info
            self.assertEqual((info["version"], info["medians"], info["outlines"]), (version, medians, outlines))
            stroke = cg.CharacterLibrary.from_store(self.tmp / name).load("十").strokes[0]
            self.assertEqual(np.asarray(stroke.median).shape, (0, 2))
            stats = json.loads(run_ok(["corpus", "stats", name, "--json"], self.tmp).stdout)
            self.assertEqual(stats["format_version"], version)


class DamagedStore(Folder):
    def setUp(self):
        super().setUp()
        self.data("a", {"十.json": doc(), "一.json": json.dumps(ONE)})
        run_ok(["corpus", "build", "--data", "a", "--out", "s.clg"], self.tmp)
        self.good = (self.tmp / "s.clg").read_bytes()

    def test_store_cut_anywhere_is_refused_naming_the_file_and_offset(self):
        for cut in (0, 40, 63, 64, 700, len(self.good) - 1):
            (self.tmp / "c.clg").write_bytes(self.good[:cut])
            for args in (["model", "十", "--store", "c.clg"], ["corpus", "stats", "c.clg"],
                         ["characters", "--store", "c.clg"]):
                self.assert_one_error(self.cli(*args), 1, "c.clg", "offset")
        with self.assertRaises(cg.DataError) as caught:
            cg.CharacterLibrary.from_store(self.tmp / "c.clg")
        self.assertIn("c.clg", str(caught.exception))

    def test_flipped_header_and_index_bytes_are_refused_naming_the_file(self):
        for offset in (0, 9, 20, 60, 64, 700):
            damaged = bytearray(self.good)
            damaged[offset] ^= 0x10
            (self.tmp / "f.clg").write_bytes(damaged)
            self.assert_one_error(self.cli("model", "一", "--store", "f.clg"), 1, "f.clg", "offset")

    def test_record_with_a_flipped_byte_is_refused_naming_file_offset_and_character(self):
        damaged = bytearray(self.good)
        damaged[-3] ^= 0x01                    # in the last record: 十's (the index is sorted by code point)
        (self.tmp / "f.clg").write_bytes(damaged)
        line = self.assert_one_error(self.cli("model", "十", "--store", "f.clg"), 1,
                                     "f.clg", "offset", "十 (U+5341)", "checksum")
        self.assertRegex(line, r"offset \d+")
        self.assertEqual(self.model_json("一", "--store", "f.clg")["typical_stroke_ids"], [1])
        stats = self.cli("corpus", "stats", "f.clg", "--json")
        self.assertEqual(stats.returncode, 1)
        self.assertEqual(len(json.loads(stats.stdout)["errors"]), 1)
        self.assertEqual(len(error_lines(stats)), 1)
        with self.assertRaises(cg.DataError) as caught:
            cg.CharacterLibrary.from_store(self.tmp / "f.clg").load("十")
        self.assertIn("U+5341", str(caught.exception))

    def test_fifo_and_5_gib_file_as_store_are_refused_at_once(self):
        os.mkfifo(self.tmp / "fifo.clg")
        with open(self.tmp / "huge.clg", "wb") as f:
            f.truncate(5 << 30)
        for name in ("fifo.clg", "huge.clg"):
            self.assert_one_error(self.cli("corpus", "stats", name), 1, name)
            self.assert_one_error(self.cli("model", "十", "--store", name), 1, name)

    def test_link_loop_as_store_is_named_as_a_loop_not_a_missing_file(self):
        # corpus.md: "Each failure is a DataError naming the file, ... and what is wrong"; `model --store`
        # says "cannot resolve the symbolic link: Too many levels of symbolic links".
        os.symlink("loop.clg", self.tmp / "loop.clg")
        for args in (["model", "十", "--store", "loop.clg"], ["corpus", "stats", "loop.clg"],
                     ["characters", "--store", "loop.clg"]):
            line = self.assert_one_error(self.cli(*args), 1, "loop.clg")
            self.assertNotIn("no such file", line, args)
            self.assertRegex(line, "symbolic link|Too many levels")
        with self.assertRaises(cg.DataError) as caught:
            cg.CharacterLibrary.from_store(self.tmp / "loop.clg")
        self.assertNotIn("no such file", str(caught.exception))


if __name__ == "__main__":
    unittest.main()
