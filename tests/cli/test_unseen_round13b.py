#!/usr/bin/env python3
"""Round 13B: hostile cases written from the documentation alone (docs/cli.md, docs/corpus.md,
docs/experiments.md, docs/typical-strokes.md and each command's `--help`) on the smaller commands and the data
they read: `characters`, `corpus build|stats`, `curriculum`, `model` (and `--svg`), `strokes`, `schema`,
`devices`, `bench` (small runs, never a timing), hanzi-writer-data folders, corpus stores, a learner's saved
trials and the XDG cache folder `corpus build` falls back to. Run by CTest as `cli_unseen_round13b_tests`.

Character files forged (a median of one point and of 10,000 and 10,001, coordinates of NaN, 1e999 and at
and past +-100,000 units, strokes and medians of different counts, 100 MB long, a link outside the folder that
is also an output, a name that is not UTF-8, names that are no character, a compatibility ideograph beside its
unified twin); stores built from them and read by `trial`, `model`, `score`, `characters`; stores whose
header declares more characters than they hold, whose records are flipped with and without their checksums
made to match; `curriculum` given another character set, characters the library lacks, records forged,
linked and of typical strokes out of range; `characters` by stroke counts and typical strokes in every
spelling and past their tables, into a closed pipe and killed mid-listing; `model --svg` onto its store by a
hard link, into a FIFO, a folder its user cannot write and `-`; `strokes --markdown` against
docs/typical-strokes.md; every `schema` a JSON Schema 2020-12 and a `trial --json` record valid against it;
`devices` twice; `bench` small runs; two `corpus build`s racing onto one store.

Each case asserts what the documentation promises: the exit status (2 usage or a character the user names that
the library lacks, 1 data the library cannot read or a failed write), one error line naming the file,
character, option or JSON pointer, nothing written when refused, no crash, no hang, no temporary left.
CALLIGRAPHY_CLI names the program, CALLIGRAPHY_SOURCE_DIR the source tree (its hanzi-writer-data sample).
CALLIGRAPHY_SANITIZED=1 takes five cases.
"""
import json
import os
import pwd
import resource
import shutil
import signal
import struct
import subprocess
import tempfile
import threading
import unittest
import xml.etree.ElementTree as ElementTree
import zlib
from pathlib import Path

from outsider import CLI, ENV, SANITIZED, TIMEOUT_S, OneErrorLine, error_lines, run, sanitized_subset

SOURCE = Path(os.environ.get("CALLIGRAPHY_SOURCE_DIR", Path(__file__).resolve().parents[2]))
SAMPLE = SOURCE / "data" / "hanzi-writer-data"
SHI, REN, KOU, DA, YI = "十", "人", "口", "大", "乙"
GOOD = (SHI, REN, DA, YI)  # the small forged corpus: four good characters (口 is the one damaged where needed)
HEADER = 64
INDEX = 688  # header and the factor table (docs/corpus.md, "Store format")

load_tests = sanitized_subset({"test_median_of_one_point_is_refused_naming_the_file",
                               "test_store_header_declaring_more_characters_is_refused",
                               "test_characters_by_stroke_count_at_and_past_its_range",
                               "test_model_svg_to_standard_output_is_the_drawing_alone",
                               "test_strokes_markdown_is_the_document_byte_for_byte"})

SHARED = {}

try:
    import jsonschema
except ImportError:  # pragma: no cover - the schema cases are skipped, saying why
    jsonschema = None


def strict_json(text):
    def refuse(token):
        raise ValueError(f"not JSON: {token}")
    return json.loads(text, parse_constant=refuse)


def character_json(char):
    return json.loads((SAMPLE / f"{char}.json").read_text(encoding="utf-8"))


def write_character(folder, char, document):
    (Path(folder) / f"{char}.json").write_text(json.dumps(document, ensure_ascii=False), encoding="utf-8")


def small_corpus(folder, chars=GOOD):
    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    for char in chars:
        shutil.copyfile(SAMPLE / f"{char}.json", folder / f"{char}.json")
    return folder


def store_index(blob):
    """The header's count and the index entries (code point, record offset, CRC) of a store."""
    count = struct.unpack_from("<I", blob, 16)[0]
    records = struct.unpack_from("<Q", blob, 40)[0]
    entries = [struct.unpack_from("<III", blob, INDEX + 12 * i) for i in range(count)]
    return count, records, entries


def reseal(blob):
    """The store with its index CRC and header CRC computed again over its bytes as they are."""
    blob = bytearray(blob)
    records = struct.unpack_from("<Q", blob, 40)[0]
    struct.pack_into("<I", blob, 56, zlib.crc32(bytes(blob[HEADER:records])))
    struct.pack_into("<I", blob, 60, zlib.crc32(bytes(blob[:60])))
    return bytes(blob)


def address_space_limit():
    """A reader that took a forged size at its word must not take the machine with it (AddressSanitizer
    reserves terabytes of address space for its shadow, so no limit there)."""
    if not SANITIZED:
        resource.setrlimit(resource.RLIMIT_AS, (2 << 30, 2 << 30))


def setUpModule():
    """A small corpus of four characters, its store, a trial record of 十 and a saved session of 十 and 人."""
    if not CLI or not Path(CLI).exists():
        raise unittest.SkipTest("CALLIGRAPHY_CLI is not set to the built program")
    shared = Path(tempfile.mkdtemp(prefix="r13b-shared-"))
    SHARED["dir"] = shared
    small_corpus(shared / "hw")
    made = run(["corpus", "build", "--data", "hw", "--out", "small.clg", "--threads", "1"], shared)
    assert made.returncode == 0, made.stderr
    made = run(["trial", SHI, "--json", "r.json", "--csv", "t.csv"], shared)
    assert made.returncode == 0, made.stderr
    protocol = {"name": "p13b", "conditions": [{"name": "h", "mode": "haptic"}],
                "test": {"characters": [SHI, REN], "conditions": ["h"], "repetitions": 1},
                "trial": {"max_duration_s": 20}}
    (shared / "p.json").write_text(json.dumps(protocol))
    made = run(["session", "run", "p.json", "--subject", "S01", "--out", "study"], shared)
    assert made.returncode == 0, made.stderr


def tearDownModule():
    if "dir" in SHARED:
        shutil.rmtree(SHARED["dir"], ignore_errors=True)


class Base(OneErrorLine, unittest.TestCase):
    def setUp(self):
        self.shared = SHARED["dir"]
        self.dir = Path(tempfile.mkdtemp(prefix="r13b-"))
        self.addCleanup(shutil.rmtree, self.dir, True)

    def assert_no_temporary(self, folder):
        left = [p.name for p in Path(folder).iterdir() if ".tmp-" in p.name]
        self.assertEqual(left, [], f"temporaries left in {folder}")

    def listed(self, result):
        """The characters a `characters --json` run printed."""
        self.assertEqual(result.returncode, 0, result.stderr)
        document = strict_json(result.stdout.decode())
        self.assertEqual(document["count"], len(document["characters"]))
        return [c["character"] for c in document["characters"]]

    def store_copy(self, name="s.clg"):
        target = self.dir / name
        shutil.copyfile(self.shared / "small.clg", target)
        return target


# ---------------------------------------------------------------------------------------------------------
# A hanzi-writer-data folder with forged characters (docs/corpus.md, "The character-data loader": 2 to 10,000
# distinct points per median, coordinates within +-100,000 data units; docs/cli.md: a character the library
# has but cannot read is status 1, naming the file)
# ---------------------------------------------------------------------------------------------------------
class ForgedCharacterFiles(Base):
    def forge(self, mutate, char=SHI):
        data = small_corpus(self.dir / "data")
        document = character_json(char)
        mutate(document)
        write_character(data, char, document)
        return data

    def model(self, char=SHI, *extra):
        return run(["model", char, "--data", "data", *extra], self.dir)

    def test_median_of_one_point_is_refused_naming_the_file(self):
        def one_point(document):
            document["medians"][0] = document["medians"][0][:1]
        self.forge(one_point)
        line = self.assert_one_error(self.model(SHI, "--svg", "m.svg"), 1, f"{SHI}.json")
        self.assertIn("median", line)
        self.assertFalse((self.dir / "m.svg").exists())
        # The same point twice is one distinct point.
        def same_point_twice(document):
            document["medians"][0] = [document["medians"][0][0]] * 2
        self.forge(same_point_twice)
        self.assert_one_error(self.model(), 1, f"{SHI}.json")

    def test_median_of_10000_points_taken_and_10001_refused(self):
        def points(n):
            def mutate(document):
                # distinct points along the horizontal stroke, 0.05 units apart
                document["medians"][0] = [[100 + i * 0.05, 400] for i in range(n)]
            return mutate
        self.forge(points(10000))
        result = self.model(SHI, "--json")
        self.assertEqual(result.returncode, 0, result.stderr)
        self.assertEqual(len(strict_json(result.stdout.decode())["strokes"]), 2)
        self.forge(points(10001))
        line = self.assert_one_error(self.model(), 1, f"{SHI}.json")
        self.assertIn("10", line)

    def test_coordinates_of_nan_1e999_and_past_100000_units(self):
        data = small_corpus(self.dir / "data")
        text = (SAMPLE / f"{SHI}.json").read_text(encoding="utf-8")
        first = json.dumps(character_json(SHI)["medians"][0][0])
        if first not in text:
            first = first.replace(" ", "")
        self.assertIn(first, text)

        def forge(point):
            (data / f"{SHI}.json").write_text(text.replace(first, point, 1), encoding="utf-8")
        for what, point in (("NaN", "[NaN, 400]"), ("1e999", "[1e999, 400]"), ("-1e999", "[100, -1e999]"),
                            ("100001", "[100001, 400]"), ("-100001", "[100, -100001]")):
            with self.subTest(what=what):
                forge(point)
                self.assert_one_error(self.model(), 1, f"{SHI}.json")
        for edge in ("[100000, 400]", "[-100000, 400]", "[100, -100000]"):
            with self.subTest(edge=edge):
                forge(edge)
                result = self.model(SHI, "--json")
                self.assertEqual(result.returncode, 0, result.stderr)

    def test_strokes_and_medians_of_different_counts_are_refused(self):
        def one_median_less(document):
            document["medians"] = document["medians"][:1]
        self.forge(one_median_less)
        self.assert_one_error(self.model(), 1, f"{SHI}.json")
        def one_outline_less(document):
            document["strokes"] = document["strokes"][:1]
        self.forge(one_outline_less)
        self.assert_one_error(self.model(), 1, f"{SHI}.json")
        # ... and the folder as a whole: `corpus build` names it and keeps the others.
        result = run(["corpus", "build", "--data", "data", "--out", "s.clg", "--threads", "1"], self.dir)
        self.assertEqual(result.returncode, 1, result.stderr)
        self.assertIn(SHI, result.stderr.decode())
        stats = run(["corpus", "stats", "s.clg", "--json"], self.dir)
        self.assertEqual(stats.returncode, 0, stats.stderr)
        listed = self.listed(run(["characters", "--store", "s.clg", "--json"], self.dir))
        self.assertEqual(sorted(listed), sorted(set(GOOD) - {SHI}))

    def test_names_that_are_no_character_are_not_characters(self):
        data = small_corpus(self.dir / "data")
        blob = (SAMPLE / f"{SHI}.json").read_bytes()
        for name in ("ab.json", "十十.json", "十.json.bak", ".十.json", "README.md", "U+5341.json", " .json",
                     "\u3000.json", "\x1b.json", "\t.json"):
            (data / name).write_bytes(blob)
        result = run(["characters", "--data", "data", "--json"], self.dir)
        self.assertEqual(sorted(self.listed(result)), sorted(GOOD))
        # a control character or a space is no character the text names either
        result = run(["characters", "--data", "data", "--text", "\x1b十", "--json"], self.dir)
        self.assertEqual(self.listed(result), [SHI])
        self.assertEqual(strict_json(result.stdout.decode())["not_found"], ["\x1b"])

    def test_a_compatibility_ideograph_is_its_own_code_point(self):
        # U+F900 is a compatibility ideograph whose canonical form is 豈 (U+8C48); the library has the latter.
        compat, unified = "\uf900", "\u8c48"
        result = run(["characters", "--text", compat + unified, "--json"], self.dir)
        self.assertEqual(result.returncode, 0, result.stderr)
        document = strict_json(result.stdout.decode())
        self.assertEqual([c["character"] for c in document["characters"]], [unified])
        self.assertEqual([c.get("code_point") for c in document["characters"]], ["U+8C48"])
        self.assertEqual(document["not_found"], [compat])
        # a folder holding both names: each file is its own character, neither read as the other
        data = small_corpus(self.dir / "data")
        shutil.copyfile(SAMPLE / f"{SHI}.json", data / f"{compat}.json")
        listed = self.listed(run(["characters", "--data", "data", "--json"], self.dir))
        self.assertEqual(sorted(listed), sorted([*GOOD, compat]))
        result = run(["model", unified, "--data", "data"], self.dir)
        self.assert_one_error(result, 2, "U+8C48")

    def test_a_data_file_linked_outside_is_an_input_of_the_command(self):
        data = small_corpus(self.dir / "data")
        outside = self.dir / "elsewhere.json"
        shutil.copyfile(SAMPLE / f"{SHI}.json", outside)
        (data / f"{SHI}.json").unlink()
        (data / f"{SHI}.json").symlink_to(outside)
        before = outside.read_bytes()
        result = run(["corpus", "build", "--data", "data", "--out", "elsewhere.json", "--threads", "1"], self.dir)
        self.assert_one_error(result, 2, "--out", "elsewhere.json")
        result = run(["model", SHI, "--data", "data", "--svg", "elsewhere.json"], self.dir)
        self.assert_one_error(result, 2, "--svg", "elsewhere.json")
        self.assertEqual(outside.read_bytes(), before)
        self.assertEqual(sorted(p.name for p in self.dir.iterdir()), ["data", "elsewhere.json"])

    def test_a_file_name_that_is_not_utf8(self):
        data = small_corpus(self.dir / "data")
        os.close(os.open(os.fsencode(data) + b"/\xff\xfe.json", os.O_CREAT | os.O_WRONLY, 0o644))
        with open(os.fsencode(data) + b"/\xff\xfe.json", "wb") as handle:
            handle.write((SAMPLE / f"{SHI}.json").read_bytes())
        for args in (["characters", "--data", "data", "--json"],
                     ["corpus", "build", "--data", "data", "--out", "s.clg", "--threads", "1"]):
            with self.subTest(args=args[:2]):
                result = run(args, self.dir)
                self.assertNotIn(b"\xff\xfe", result.stderr)
                self.assertNotIn(b"\xff\xfe", result.stdout)
                if result.returncode == 0:
                    if args[0] == "characters":
                        self.assertEqual(sorted(self.listed(result)), sorted(GOOD))
                else:
                    self.assertEqual(result.returncode, 1, result.stderr)
                    self.assertIn("\\xFF\\xFE", result.stderr.decode())
                    self.assertFalse((self.dir / "s.clg").exists())

    def test_a_100_mb_character_file_is_refused_by_its_size(self):
        data = small_corpus(self.dir / "data")
        path = data / f"{SHI}.json"
        with open(path, "r+b") as handle:
            handle.truncate(100 << 20)  # the JSON, then 100 MB of zero bytes (a sparse file)
        result = run(["model", SHI, "--data", "data"], self.dir, timeout=30, preexec_fn=address_space_limit)
        self.assert_one_error(result, 1, f"{SHI}.json")
        # spaces after the JSON are JSON, but 100 MB of them (written, not sparse) is past a character file's size
        with open(path, "wb") as handle:
            handle.write((SAMPLE / f"{SHI}.json").read_bytes())
            handle.write(b" " * (100 << 20))
        result = run(["model", SHI, "--data", "data", "--json"], self.dir, timeout=30,
                     preexec_fn=address_space_limit)
        line = self.assert_one_error(result, 1, f"{SHI}.json")
        self.assertIn(str(path.stat().st_size), line)  # refused by its size (at most 16 MiB), not parsed


# ---------------------------------------------------------------------------------------------------------
# Stores built from such a folder, forged stores (docs/corpus.md, "Store format" and "Checks and errors")
# ---------------------------------------------------------------------------------------------------------
class Stores(Base):
    def test_a_store_built_from_a_folder_with_a_bad_character_keeps_the_others(self):
        data = small_corpus(self.dir / "data")
        document = character_json(KOU)
        document["medians"][1] = document["medians"][1][:1]
        write_character(data, KOU, document)
        result = run(["corpus", "build", "--data", "data", "--out", "s.clg", "--threads", "1"], self.dir)
        self.assert_one_error(result, 1, f"{KOU}.json", "U+53E3", "s.clg")
        self.assertIn(f"{KOU} (U+53E3)", result.stdout.decode())  # listed with the others' summary
        self.assertEqual(sorted(self.listed(run(["characters", "--store", "s.clg", "--json"], self.dir))),
                         sorted(GOOD))
        for args in (["model", KOU, "--store", "s.clg"], ["trial", KOU, "--store", "s.clg"],
                     ["score", self.shared / "t.csv", "--character", KOU, "--store", "s.clg"]):
            with self.subTest(command=args[0]):
                self.assert_one_error(run(args, self.dir), 2, KOU)
        result = run(["trial", SHI, "--store", "s.clg", "--json", "r.json"], self.dir)
        self.assertEqual(result.returncode, 0, result.stderr)
        result = run(["score", self.shared / "t.csv", "--character", SHI, "--store", "s.clg", "--json", "-"],
                     self.dir)
        self.assertEqual(result.returncode, 0, result.stderr)
        strict_json(result.stdout.decode())
        self.assert_no_temporary(self.dir)

    def test_a_store_scores_as_its_data_folder_within_the_quantisation(self):
        # docs/corpus.md: a 1.1 store keeps every median exactly, so acceptance (which follows the median)
        # gives the same verdicts; the deviations (against the elements, docs/metrics.md) move by at most the
        # quantisation error, 0.35 data units at 2 steps per unit: 0.35 * 60 mm / 1024 = 0.0205 mm.
        scored = {}
        for source in (["--data", self.shared / "hw"], ["--store", self.shared / "small.clg"]):
            result = run(["score", self.shared / "t.csv", "--character", SHI, *source, "--json", "-"], self.dir)
            self.assertEqual(result.returncode, 0, result.stderr)
            scored[source[0]] = strict_json(result.stdout.decode())
        data, store = scored["--data"], scored["--store"]
        for key in ("strokes_accepted", "strokes_written", "strokes_total", "refusals", "order_errors"):
            self.assertEqual(data[key], store[key], key)
        self.assertGreater(data["strokes_written"], 0)
        for key in ("mean_deviation_m", "max_deviation_m", "rms_deviation_m"):
            self.assertAlmostEqual(data[key], store[key], delta=0.35 * 0.060 / 1024, msg=key)

    def test_store_header_declaring_more_characters_is_refused(self):
        blob = self.store_copy().read_bytes()
        count = struct.unpack_from("<I", blob, 16)[0]
        forged = bytearray(blob)
        struct.pack_into("<I", forged, 16, count + 1)
        sealed = bytearray(reseal(forged))
        # and with the records offset moved to match the larger index, sealed again
        moved = bytearray(forged)
        struct.pack_into("<Q", moved, 40, INDEX + 12 * (count + 1))
        moved = reseal(moved)
        huge = bytearray(blob)
        struct.pack_into("<I", huge, 16, 0xFFFFFFFF)
        huge = reseal(huge)
        for name, content in (("plain.clg", forged), ("sealed.clg", sealed), ("moved.clg", moved),
                              ("huge.clg", huge)):
            (self.dir / name).write_bytes(bytes(content))
            for args in (["corpus", "stats", name], ["model", SHI, "--store", name],
                         ["characters", "--store", name, "--json"]):
                with self.subTest(store=name, command=args[0]):
                    result = run(args, self.dir, preexec_fn=address_space_limit)
                    self.assert_one_error(result, 1, name)
                    self.assertEqual(result.stdout, b"")

    def test_store_index_naming_a_character_twice_or_out_of_order_is_refused(self):
        blob = self.store_copy().read_bytes()
        count, _, entries = store_index(blob)
        self.assertGreaterEqual(count, 2)
        twice = bytearray(blob)
        struct.pack_into("<I", twice, INDEX + 12, entries[0][0])  # the second entry names the first character
        swapped = bytearray(blob)
        struct.pack_into("<I", swapped, INDEX, entries[1][0])
        struct.pack_into("<I", swapped, INDEX + 12, entries[0][0])
        for name, content in (("twice.clg", twice), ("swapped.clg", swapped)):
            (self.dir / name).write_bytes(reseal(content))
            for args in (["corpus", "stats", name], ["model", chr(entries[0][0]), "--store", name],
                         ["characters", "--store", name]):
                with self.subTest(store=name, command=args[0]):
                    self.assert_one_error(run(args, self.dir), 1, name)

    def test_store_record_flipped_after_its_checksummed_tables(self):
        store = self.store_copy()
        blob = bytearray(store.read_bytes())
        count, records, entries = store_index(blob)
        code_point, offset, _ = entries[-1]
        victim = chr(code_point)
        blob[records + offset + 1] ^= 0xFF
        store.write_bytes(bytes(blob))
        result = run(["corpus", "stats", "s.clg"], self.dir)
        self.assertEqual(result.returncode, 1, result.stderr)
        lines = error_lines(result)
        self.assertEqual(len(lines), 1, lines)
        self.assertIn(victim, lines[0])
        self.assertIn("s.clg", lines[0])
        result = run(["corpus", "stats", "s.clg", "--json"], self.dir)
        self.assertEqual(result.returncode, 1, result.stderr)
        self.assertEqual(len(strict_json(result.stdout.decode())["errors"]), 1)
        self.assert_one_error(run(["model", victim, "--store", "s.clg"], self.dir), 1, "s.clg", victim)
        self.assert_one_error(run(["characters", "--store", "s.clg"], self.dir), 1, "s.clg", victim)
        other = next(chr(e[0]) for e in entries if chr(e[0]) != victim)
        result = run(["model", other, "--store", "s.clg", "--json"], self.dir)
        self.assertEqual(result.returncode, 0, result.stderr)  # loaded on demand: only its record is read

    def test_store_records_flipped_with_their_checksums_made_to_match(self):
        blob = self.store_copy().read_bytes()
        count, records, entries = store_index(blob)
        changes = 0
        for index, (code_point, offset, _) in enumerate(entries):
            end = entries[index + 1][1] if index + 1 < count else len(blob) - records
            for position in range(offset, end, max(1, (end - offset) // 6)):  # 6 or 7 places a record
                for mask in (0x01, 0xFF):
                    forged = bytearray(blob)
                    forged[records + position] ^= mask
                    record = bytes(forged[records + offset:records + end])
                    struct.pack_into("<I", forged, INDEX + 12 * index + 8, zlib.crc32(record))
                    (self.dir / "f.clg").write_bytes(reseal(forged))
                    result = run(["model", chr(code_point), "--store", "f.clg", "--json"], self.dir,
                                 preexec_fn=address_space_limit)
                    changes += 1
                    if result.returncode == 0:
                        strict_json(result.stdout.decode())
                    else:
                        self.assert_one_error(result, 1, "f.clg", chr(code_point))
        self.assertGreater(changes, 40)


# ---------------------------------------------------------------------------------------------------------
# curriculum: a learner's saved trials (docs/cli.md "curriculum", docs/experiments.md "What to practise next"
# and "Sessions": a record is its session's; a file of a session folder that is a symbolic link is refused)
# ---------------------------------------------------------------------------------------------------------
class Curriculum(Base):
    def study_copy(self, name="study"):
        study = self.dir / name
        shutil.copytree(self.shared / "study", study, symlinks=True)
        record = sorted(study.rglob("trials/*-U5341.json"))[0]
        return study, record

    def curriculum(self, study, *args):
        return run(["curriculum", study, "--subject", "S01", *args], self.dir)

    def test_a_history_of_another_character_set_proposes_nothing_new(self):
        study, _ = self.study_copy()
        result = self.curriculum(study, "--from", SHI + REN, "--json")
        self.assertEqual(result.returncode, 0, result.stderr)
        self.assertEqual(strict_json(result.stdout.decode()), [])
        result = self.curriculum(study, "--from", "大口", "--count", "1000", "--json")
        self.assertEqual(result.returncode, 0, result.stderr)
        proposed = strict_json(result.stdout.decode())
        self.assertLessEqual(len(proposed), 2)
        for item in proposed:
            self.assertIn(item["character"], "大口")
            for stroke in [*item["new_strokes"], *item["weak_strokes"]]:
                self.assertTrue(1 <= stroke <= 39, item)

    def test_candidates_the_library_lacks_are_a_usage_error(self):
        study, _ = self.study_copy()
        for text, named in (("abc", "U+0061"), (SHI + "x", "U+0078"), ("\u9fff", "U+9FFF")):
            with self.subTest(text=text):
                result = self.curriculum(study, "--from", text)
                self.assert_one_error(result, 2, "--from", named)

    def test_count_at_and_past_its_range(self):
        study, _ = self.study_copy()
        for count in ("1", "1000"):
            with self.subTest(count=count):
                result = self.curriculum(study, "--from", "大口", "--count", count, "--json")
                self.assertEqual(result.returncode, 0, result.stderr)
                self.assertLessEqual(len(strict_json(result.stdout.decode())), int(count))
        for count in ("0", "1001", "-1", "1e3", "", " 3", "99999999999999999999"):
            with self.subTest(count=count):
                self.assert_one_error(self.curriculum(study, "--from", "大口", "--count", count), 2, "--count")

    def test_a_record_linked_to_a_copy_outside_is_refused_naming_it(self):
        study, record = self.study_copy()
        outside = self.dir / "copy.json"
        shutil.copyfile(record, outside)
        record.unlink()
        record.symlink_to(outside)
        result = self.curriculum(study, "--from", "大口")
        self.assert_one_error(result, 1, record.name, "symbolic link")

    def test_a_history_given_twice_or_hard_linked_counts_once(self):
        study, record = self.study_copy()
        once = self.curriculum(study, "--from", "大口木", "--json")
        self.assertEqual(once.returncode, 0, once.stderr)
        session = record.parent.parent
        for folders in ([study, study], [study, session], [session, study / "S01"]):
            with self.subTest(folders=[str(f.relative_to(self.dir)) for f in folders]):
                result = run(["curriculum", *folders, "--subject", "S01", "--from", "大口木", "--json"], self.dir)
                self.assertEqual(result.returncode, 0, result.stderr)
                self.assertEqual(result.stdout, once.stdout)
        # a hard link is the file itself (docs/experiments.md, "Sessions")
        os.link(record, self.dir / "kept.json")
        result = self.curriculum(study, "--from", "大口木", "--json")
        self.assertEqual(result.stdout, once.stdout)

    def test_records_forged_out_of_their_ranges_are_refused_naming_the_pointer(self):
        # what a curriculum reads of a record: its subject and each character's strokes' typical IDs (1-39)
        typical = "/per_character/0/per_stroke/0/typical_id"
        for number, (pointer, value) in enumerate(((typical, 40), (typical, -1), (typical, "1"),
                                                   ("/subject", "S02"))):
            with self.subTest(pointer=pointer, value=value):
                study, record = self.study_copy(f"study{number}")
                document = json.loads(record.read_text(encoding="utf-8"))
                target = document
                parts = pointer.strip("/").split("/")
                for part in parts[:-1]:
                    target = target[int(part)] if isinstance(target, list) else target[part]
                target[parts[-1]] = value
                record.write_text(json.dumps(document, ensure_ascii=False), encoding="utf-8")
                result = self.curriculum(study, "--from", "大口")
                self.assert_one_error(result, 1, record.name, pointer)

    def test_a_record_with_1e999_is_refused_naming_the_record(self):
        study, record = self.study_copy()
        text = record.read_text(encoding="utf-8")
        key = '"mean_deviation_m":'
        start = text.index(key) + len(key)
        end = min(i for i in (text.find(",", start), text.find("}", start)) if i >= 0)
        record.write_text(text[:start] + " 1e999" + text[end:], encoding="utf-8")
        result = self.curriculum(study, "--from", "大口")
        self.assert_one_error(result, 1, record.name)


# ---------------------------------------------------------------------------------------------------------
# characters (docs/cli.md "characters": --strokes 1..255; --typical by ID 1-39, acronym in any case, Chinese
# name or CJK stroke character; anything else a usage error naming the option and close acronyms)
# ---------------------------------------------------------------------------------------------------------
TEXT = "一二十人八入乙九口大天木山中日千女子小水火永我心鼎书这那说长风马狗电肃走凸凹母"
# Seventeen characters of TEXT that hold every typical stroke TEXT holds (31 of the 39): each of the 192 runs
# of the every-spelling case reads these rather than all 39 (each character read costs its run about 0.3 ms).
STROKES_TEXT = "我鼎永这说乙山女子心那长马狗凸凹母"


class Characters(Base):
    def test_characters_by_stroke_count_at_and_past_its_range(self):
        for value in ("0", "256", "1e9", "1000000000", "-1", "x", "", "1.0", "٣"):
            with self.subTest(value=value):
                self.assert_one_error(run(["characters", "--strokes", value, "--text", TEXT], self.dir), 2,
                                      "--strokes")
        one = run(["characters", "--strokes", "1", "--text", TEXT, "--json"], self.dir)
        document = strict_json(one.stdout.decode())
        self.assertEqual(sorted(c["character"] for c in document["characters"]), ["一", "乙"])
        self.assertTrue(all(c["strokes"] == 1 for c in document["characters"]))
        none = run(["characters", "--strokes", "255", "--text", TEXT, "--json"], self.dir)
        self.assertEqual(strict_json(none.stdout.decode())["count"], 0)

    def test_characters_by_every_spelling_of_every_typical_stroke(self):
        table = strict_json(run(["strokes", "--json"], self.dir).stdout.decode())
        self.assertEqual([row["id"] for row in table], list(range(1, 40)))
        for row in table:
            by_id = run(["characters", "--typical", str(row["id"]), "--text", STROKES_TEXT, "--json"], self.dir)
            expected = strict_json(by_id.stdout.decode())["characters"]
            for c in expected:
                self.assertIn(row["id"], c["typical_ids"])
            spellings = [row["acronym"], row["acronym"].lower(), row["name"]]
            if row["unicode"]:
                spellings.append(chr(int(row["unicode"][2:], 16)))
            for spelling in spellings:
                with self.subTest(stroke=row["id"], spelling=spelling):
                    result = run(["characters", "--typical", spelling, "--text", STROKES_TEXT, "--json"],
                                 self.dir)
                    self.assertEqual(result.returncode, 0, result.stderr)
                    self.assertEqual(strict_json(result.stdout.decode())["characters"], expected)
        for value in ("0", "40", "-1", "HZGX", "", "1.5", "U+31D0", "横 "):
            with self.subTest(value=value):
                self.assert_one_error(run(["characters", "--typical", value, "--text", TEXT], self.dir), 2,
                                      "--typical")

    def test_every_character_into_a_closed_pipe_and_killed_mid_listing(self):
        listing = subprocess.Popen([CLI, "characters"], stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                                   stdin=subprocess.DEVNULL, env=ENV, cwd=self.dir)
        first = listing.stdout.readline()
        listing.stdout.close()  # `| head -1`
        _, errors = listing.communicate(timeout=TIMEOUT_S)
        self.assertTrue(first.strip())
        self.assertEqual(listing.returncode, 1, errors)
        lines = errors.decode().strip().splitlines()
        self.assertEqual(len(lines), 1, lines)
        self.assertIn("error", lines[0])
        listing = subprocess.Popen([CLI, "characters", "--json"], stdout=subprocess.PIPE,
                                   stderr=subprocess.PIPE, stdin=subprocess.DEVNULL, env=ENV, cwd=self.dir)
        listing.stdout.read(1)
        listing.send_signal(signal.SIGTERM)
        listing.stdout.close()
        listing.communicate(timeout=TIMEOUT_S)
        self.assertIn(listing.returncode, (-signal.SIGTERM, 128 + signal.SIGTERM))

    def test_every_character_counted_once(self):
        result = run(["characters", "--json"], self.dir)
        document = strict_json(result.stdout.decode())
        characters = [c["character"] for c in document["characters"]]
        self.assertEqual(document["count"], 9574)
        self.assertEqual(len(set(characters)), 9574)
        for c in document["characters"][:50]:
            self.assertEqual(c["code_point"], f"U+{ord(c['character']):04X}")
            self.assertEqual(len(c["typical_ids"]), c["strokes"])
            self.assertEqual(len(c["typical_strokes"]), c["strokes"])


# ---------------------------------------------------------------------------------------------------------
# model --svg (docs/cli.md "Outputs", "Checked before anything runs", "Standard output")
# ---------------------------------------------------------------------------------------------------------
class ModelSvg(Base):
    def test_model_svg_onto_its_store_through_a_hard_link(self):
        store = self.store_copy()
        os.link(store, self.dir / "other-name.svg")
        before = store.read_bytes()
        result = run(["model", SHI, "--store", "s.clg", "--svg", "other-name.svg"], self.dir)
        self.assert_one_error(result, 2, "--svg", "--store")
        self.assertEqual(store.read_bytes(), before)
        self.assert_no_temporary(self.dir)

    def test_model_svg_into_a_fifo_with_a_reader(self):
        fifo = self.dir / "pipe.svg"
        os.mkfifo(fifo)
        got = {}

        def read():
            with open(fifo, "rb") as handle:
                got["bytes"] = handle.read()
        reader = threading.Thread(target=read)
        reader.start()
        result = run(["model", SHI, "--svg", "pipe.svg"], self.dir)
        reader.join(TIMEOUT_S)
        self.assertEqual(result.returncode, 0, result.stderr)
        self.assertEqual(ElementTree.fromstring(got["bytes"]).tag.rsplit("}", 1)[-1], "svg")
        self.assertTrue(fifo.is_fifo())

    def as_a_user_who_is_not_root(self):
        """The command prefix that runs the program as a user who is not root: none when this process is not
        root, else nobody through setpriv or runuser. Skips, saying why, when neither can run the program."""
        if os.geteuid() != 0:
            return []
        try:
            nobody = pwd.getpwnam("nobody")
        except KeyError:
            self.skipTest("running as root, and there is no user nobody to run as")
        tried = []
        for prefix in (["setpriv", f"--reuid={nobody.pw_uid}", f"--regid={nobody.pw_gid}", "--clear-groups"],
                       ["runuser", "-u", "nobody", "--"]):
            if shutil.which(prefix[0]) is None:
                tried.append(f"{prefix[0]}: not installed")
                continue
            probe = subprocess.run([*prefix, CLI, "--version"], capture_output=True, timeout=TIMEOUT_S, cwd="/")
            if probe.returncode == 0:
                return prefix
            tried.append(f"{prefix[0]}: {probe.stderr.decode(errors='replace').strip()[:200]}")
        self.skipTest("running as root, and cannot run the program as nobody (" + "; ".join(tried) + ")")

    def test_model_svg_into_a_folder_its_user_cannot_write(self):
        prefix = self.as_a_user_who_is_not_root()
        locked = self.dir / "locked"
        locked.mkdir()
        locked.chmod(0o555)
        self.dir.chmod(0o755)
        result = subprocess.run([*prefix, CLI, "model", SHI, "--svg", str(locked / "m.svg")], cwd="/",
                                env=ENV, stdin=subprocess.DEVNULL, capture_output=True, timeout=TIMEOUT_S)
        self.assert_one_error(result, 1, "--svg", str(locked))
        self.assertEqual(list(locked.iterdir()), [])

    def test_model_svg_to_standard_output_is_the_drawing_alone(self):
        result = run(["model", SHI, "--svg", "-"], self.dir)
        self.assertEqual(result.returncode, 0, result.stderr)
        self.assertEqual(ElementTree.fromstring(result.stdout).tag.rsplit("}", 1)[-1], "svg")
        self.assert_one_error(run(["model", SHI, "--svg", "-", "--json"], self.dir), 2, "--json")
        self.assertEqual(list(self.dir.iterdir()), [])


# ---------------------------------------------------------------------------------------------------------
# strokes, schema, devices, bench (small runs)
# ---------------------------------------------------------------------------------------------------------
class Tables(Base):
    def test_strokes_markdown_is_the_document_byte_for_byte(self):
        document = (SOURCE / "docs" / "typical-strokes.md").read_bytes()
        result = run(["strokes", "--markdown", "-"], self.dir)
        self.assertEqual(result.returncode, 0, result.stderr)
        self.assertEqual(result.stdout, document)
        result = run(["strokes", "--markdown", "t.md"], self.dir)
        self.assertEqual(result.returncode, 0, result.stderr)
        self.assertEqual((self.dir / "t.md").read_bytes(), document)

    @unittest.skipIf(jsonschema is None, "python3-jsonschema is not installed")
    def test_every_schema_is_a_json_schema_2020_12(self):
        for kind in ("specification", "record", "protocol", "session", "metrics"):
            with self.subTest(kind=kind):
                result = run(["schema", kind], self.dir)
                self.assertEqual(result.returncode, 0, result.stderr)
                schema = strict_json(result.stdout.decode())
                self.assertEqual(schema["$schema"], "https://json-schema.org/draft/2020-12/schema")
                jsonschema.Draft202012Validator.check_schema(schema)

    @unittest.skipIf(jsonschema is None, "python3-jsonschema is not installed")
    def test_a_trial_record_a_session_and_a_protocol_validate_against_their_schemas(self):
        record = strict_json((self.shared / "r.json").read_text(encoding="utf-8"))
        schemas = {kind: strict_json(run(["schema", kind], self.dir).stdout.decode())
                   for kind in ("record", "metrics")}
        validator = jsonschema.Draft202012Validator(schemas["record"])
        validator.validate(record["specification"])
        metrics = {key: record[key] for key in schemas["metrics"]["properties"]}
        jsonschema.Draft202012Validator(schemas["metrics"]).validate(metrics)
        # a saved session's session.json and the protocol it ran, against theirs
        for kind, document in (("session", next((self.shared / "study").rglob("session.json"))),
                               ("protocol", self.shared / "p.json")):
            with self.subTest(kind=kind):
                schema = strict_json(run(["schema", kind], self.dir).stdout.decode())
                jsonschema.Draft202012Validator(schema).validate(strict_json(document.read_text(encoding="utf-8")))
        # what the schema refuses, `trial --spec` refuses naming the pointer
        forged = json.loads(json.dumps(record))
        forged["specification"]["trial"]["rate_hz"] = "fast"
        self.assertFalse(validator.is_valid(forged["specification"]))
        (self.dir / "f.json").write_text(json.dumps(forged, ensure_ascii=False), encoding="utf-8")
        self.assert_one_error(run(["trial", "--spec", "f.json", "--check"], self.dir), 2, "f.json",
                              "/specification/trial/rate_hz")

    def test_devices_are_listed_the_same_twice_as_documented(self):
        first, second = (run(["devices", "--json"], self.dir) for _ in range(2))
        self.assertEqual(first.returncode, 0, first.stderr)
        self.assertEqual(first.stdout, second.stdout)
        document = strict_json(first.stdout.decode())
        self.assertEqual(set(document), {"devices", "notes", "any_hardware", "kinds"})
        for device in document["devices"]:
            self.assertTrue({"name", "backend", "hardware", "moved_by_simulated_hand", "needs_calibration",
                             "details", "limits_known", "info"} <= set(device), device)
            self.assertTrue({"model", "manufacturer", "max_force_n", "max_continuous_force_n",
                             "max_stiffness_n_per_m", "max_damping_n_s_per_m", "workspace_radius_m",
                             "workspace_size_m"} <= set(device["info"]), device)
            self.assertEqual(len(device["info"]["workspace_size_m"]), 3)
        kinds = [kind["name"] for kind in document["kinds"]]
        self.assertEqual(kinds[:7], ["simulated", "emulated-phantom", "mouse", "mouse-hand", "openhaptics",
                                     "phantom-hid:PATH", "phantom-usb:BUS-ADDRESS"])
        for kind in document["kinds"]:
            self.assertEqual(set(kind), {"name", "backend", "writer", "commands", "what"})
            self.assertIn(kind["writer"], ("simulated", "person"))
        text = [run(["devices"], self.dir).stdout for _ in range(2)]
        self.assertEqual(text[0], text[1])

    def test_bench_small_runs_print_what_they_say(self):
        for args in (["nearest", "--queries", "1", "--json"], ["tick", "--passes", "1", "--chars", SHI, "--json"],
                     ["loop", "--seconds", "0.05", "--json"]):
            with self.subTest(args=args[0]):
                result = run(["bench", *args], self.dir)
                self.assertEqual(result.returncode, 0, result.stderr)
                strict_json(result.stdout.decode())
        # a character the library lacks, named by the user: a usage error naming the option (docs/cli.md)
        result = run(["bench", "tick", "--passes", "1", "--chars", "a", "--json"], self.dir)
        self.assert_one_error(result, 2, "--chars", "U+0061")
        result = run(["bench", "loop", "--seconds", "0.05", "--trial", SHI + "\u9fff", "--json"], self.dir)
        self.assert_one_error(result, 2, "--trial", "U+9FFF")
        self.assertEqual(result.stdout, b"")
        result = run(["bench", "jumps", "--seeds", "1", "--chars", "", "--json"], self.dir)
        self.assert_one_error(result, 2, "--chars")
        self.assertEqual(list(self.dir.iterdir()), [])


# ---------------------------------------------------------------------------------------------------------
# corpus build: two at once onto one store; the cache folder it falls back to (docs/corpus.md)
# ---------------------------------------------------------------------------------------------------------
class CorpusBuild(Base):
    def test_two_builds_racing_onto_one_store(self):
        args = [CLI, "corpus", "build", "--data", str(self.shared / "hw"), "--out", "s.clg", "--threads", "1"]
        runs = [subprocess.Popen(args, cwd=self.dir, env=ENV, stdin=subprocess.DEVNULL,
                                 stdout=subprocess.PIPE, stderr=subprocess.PIPE) for _ in range(2)]
        for process in runs:
            _, errors = process.communicate(timeout=TIMEOUT_S)
            self.assertEqual(process.returncode, 0, errors)
        self.assertEqual((self.dir / "s.clg").read_bytes(), (self.shared / "small.clg").read_bytes())
        self.assertEqual([p.name for p in self.dir.iterdir()], ["s.clg"])

    def test_the_cache_folder_is_the_default_data(self):
        cache = self.dir / "cache"
        cache.mkdir()
        env = dict(ENV, XDG_CACHE_HOME=str(cache), HOME=str(self.dir / "home"))
        result = run(["corpus", "build", "--out", "s.clg"], self.dir, env=env)
        line = self.assert_one_error(result, 2)
        self.assertIn("fetch-hanzi-writer-data", line)
        self.assertFalse((self.dir / "s.clg").exists())
        # a folder the fetch script has not finished (no `.complete` yet: it writes that last) is not taken
        fetched = small_corpus(cache / "calligraphy" / "hanzi-writer-data-2.0.1")
        self.assert_one_error(run(["corpus", "build", "--out", "s.clg"], self.dir, env=env), 2, str(fetched))
        (fetched / ".complete").write_bytes(b"")
        result = run(["corpus", "build", "--out", "s.clg", "--threads", "1"], self.dir, env=env)
        self.assertEqual(result.returncode, 0, result.stderr)
        self.assertEqual((self.dir / "s.clg").read_bytes(), (self.shared / "small.clg").read_bytes())


if __name__ == "__main__":
    unittest.main()
