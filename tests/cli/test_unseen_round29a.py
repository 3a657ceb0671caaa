#!/usr/bin/env python3
"""Round 29A: every character offline, `calligraphy characters` and the corpus store. From the docs alone
(docs/cli.md "Conventions" (Characters, Checked before anything runs, Exit statuses), `characters`, `corpus`,
`model`, `score`, `train`, `--data`, `--store`; docs/corpus.md "The bundled store", "Store format", "Checks and
errors", "The character-data loader and fitter"; docs/python.md "Characters", "Scoring any pen trace",
"Simulated trials"; README.md).

The docs promise every hanzi-writer-data 2.0.1 character (9,574) with no fetch and no option: every run here
has CALLIGRAPHY_CORPUS_DIR unset and HOME and XDG_CACHE_HOME pointing at an empty folder. Characters drawn at
random (seeded) from `characters --json`, outside the 58 embedded ones, go through `model` (against the same
JSON fitted with `--data` and stored by `corpus build` with its defaults, the bundled store's recipe),
`score` (a trace the test writes along the JSON file's medians), a short `trial`, `trial --spec` on a store,
`train`'s character check and Python. `characters` is driven at and past its ranges (stroke counts, every
spelling of a typical stroke, texts with ASCII, duplicates, emoji, combining marks, white space, a control
character, a surrogate's bytes, nothing). `--store` is given forged stores (empty, cut, one byte short, a
record flipped; with their checksums recomputed a typical ID 0 or 63, a record of no strokes, a NaN factor,
the index out of order, one character too many, another major version, an unknown flag, a later minor
version; JSON, a folder, links, a FIFO, `-`), `--data` with `--store`, `corpus build|fidelity` outputs aimed at
their inputs (the same file by another spelling, a hard or a symbolic link) and options past their ranges, and
folders of forged characters (cut JSON, outlines and medians of other counts, huge and overflowing numbers, an
empty median, a repeated point, no medians; names of two code points, white space, a control character,
beyond the BMP, a Kangxi radical) and a median the fitter models as 271 elements, one more than a record
takes: each is listed and the store holds the others.

CALLIGRAPHY_CLI names the program; PYTHONPATH the built Python package; the hanzi-writer-data folder is
CALLIGRAPHY_CORPUS_DIR as given, else ~/.cache/calligraphy/hanzi-writer-data-2.0.1 (read by the test as an
input only; the program's CALLIGRAPHY_CORPUS_DIR is unset). CALLIGRAPHY_SANITIZED=1 takes five cases.
"""
import json
import os
import random
import shutil
import struct
import tempfile
import unittest
import zlib
from pathlib import Path

from outsider import ENV, OneErrorLine, error_lines, run, sanitized_subset

HWD = Path(os.environ.get("CALLIGRAPHY_CORPUS_DIR")
           or Path.home() / ".cache/calligraphy/hanzi-writer-data-2.0.1")
os.environ.pop("CALLIGRAPHY_CORPUS_DIR", None)   # Python's default library reads no file either

try:
    import numpy as np
    import calligraphy as cg
except ImportError:  # reported by the Python cases
    np = cg = None

load_tests = sanitized_subset({"test_model_of_random_characters_equals_a_default_store_of_their_json",
                               "test_store_with_a_flipped_record_fails_only_that_character_naming_it",
                               "test_data_and_store_together_are_one_usage_error_naming_both",
                               "test_text_listing_is_its_characters_in_order_once_and_names_the_rest",
                               "test_corpus_build_out_on_a_character_file_is_refused_and_leaves_it"})

TOTAL = 9574
HEADER = struct.Struct("<8sHHIIIfIQQQII")   # docs/corpus.md "Header (64 bytes)"
MAX_QUANTISATION = 0.3536                   # sqrt(2) / (2 * 2) units at the default 2 steps per unit


def decoded(result):
    return result.stdout.decode("utf-8")


SHARED = {}


def setUpModule():
    """Once for every case: the full listing, a seeded choice of characters outside the embedded ones, their
    JSON files in a folder and a store `corpus build` made of it with its defaults."""
    if not HWD.is_dir():
        return
    tmp = Path(tempfile.mkdtemp(prefix="round29a-"))
    home = tmp / "home"
    (home / "cache").mkdir(parents=True)
    env = {k: v for k, v in ENV.items() if k != "CALLIGRAPHY_CORPUS_DIR"}
    env.update(HOME=str(home), XDG_CACHE_HOME=str(home / "cache"))
    SHARED.update(tmp=tmp, env=env)
    listing = run(["characters", "--json"], tmp, env=env)
    assert listing.returncode == 0, listing.stderr
    listing = json.loads(decoded(listing))
    by_char = {c["character"]: c for c in listing["characters"]}
    embedded = set("七不专东个中为乃之乙九也书人以写几凸凹出力北十千去又及口四大天女子家小山弓心我日月木母水永没火"
                   "狗电肃说走这那长风马鼎二刀")
    rng = random.Random(29)
    outside = [c for c in by_char if c not in embedded]
    few = rng.sample([c for c in outside if 2 <= by_char[c]["strokes"] <= 3], 2)
    chosen = rng.sample([c for c in outside if c not in few], 3)
    data = tmp / "data"
    data.mkdir()
    for c in few + chosen + ["十", "二", "刀"]:
        shutil.copyfile(HWD / f"{c}.json", data / f"{c}.json")
    store = tmp / "s.clg"
    built = run(["corpus", "build", "--data", data, "--out", store, "--threads", "1"], tmp, env=env)
    assert built.returncode == 0, built.stderr
    SHARED.update(listing=listing, by_char=by_char, few=few, any=chosen, data=data, store=store)


def tearDownModule():
    if "tmp" in SHARED:
        shutil.rmtree(SHARED["tmp"], ignore_errors=True)


class Offline(unittest.TestCase, OneErrorLine):
    """The shared listing, characters, folder and store (setUpModule)."""

    @classmethod
    def setUpClass(cls):
        if "store" not in SHARED:
            raise unittest.SkipTest(f"no hanzi-writer-data folder at {HWD}")
        for key, value in SHARED.items():
            setattr(cls, key, value)

    @classmethod
    def cli(cls, args, cwd=None, **kw):
        return run(args, cwd or cls.tmp, env=cls.env, **kw)

    def medians(self, c):
        return json.loads((HWD / f"{c}.json").read_text(encoding="utf-8"))["medians"]


class Listing(Offline):
    def test_listing_counts_every_hanzi_writer_character_once_sorted_with_its_code_point(self):
        chars = self.listing["characters"]
        self.assertEqual(self.listing["count"], TOTAL)
        self.assertEqual(len(chars), TOTAL)
        self.assertEqual(self.listing["not_found"], [])
        names = [c["character"] for c in chars]
        self.assertEqual(names, sorted(set(names), key=ord))
        files = {p.name[:-5] for p in HWD.glob("*.json") if len(p.name[:-5]) == 1}
        self.assertEqual(set(names), files)
        for c in chars:
            self.assertEqual(c["code_point"], f"U+{ord(c['character']):04X}")
            self.assertEqual(c["strokes"], len(c["typical_ids"]))
            self.assertEqual(len(c["typical_strokes"]), c["strokes"])
        for c in self.any:
            self.assertEqual(self.by_char[c]["strokes"], len(self.medians(c)))

    def test_one_stroke_listing_is_the_full_listings_one_stroke_characters(self):
        r = self.cli(["characters", "--strokes", "1", "--json"])
        self.assertEqual(r.returncode, 0, r.stderr)
        got = json.loads(decoded(r))
        want = [c for c in self.listing["characters"] if c["strokes"] == 1]
        self.assertEqual(got["characters"], want)
        self.assertEqual(got["count"], len(want))

    def test_documented_example_typical_hzg_four_strokes_agrees_with_the_full_listing(self):
        r = self.cli(["characters", "--typical", "HZG", "--strokes", "4", "--json"])
        self.assertEqual(r.returncode, 0, r.stderr)
        want = [c for c in self.listing["characters"] if c["strokes"] == 4 and 10 in c["typical_ids"]]
        self.assertTrue(want)
        self.assertEqual(json.loads(decoded(r))["characters"], want)

    def test_every_spelling_of_a_typical_stroke_gives_the_same_characters(self):
        text = "".join(list(self.by_char)[2000:2300])
        want = [self.by_char[c] for c in text if "HZG" in self.by_char[c]["typical_strokes"]]
        self.assertTrue(want)
        for spelling in ("10", "HZG", "hzg", "hZg", "横折钩", "\u31c6"):
            with self.subTest(spelling=spelling):
                r = self.cli(["characters", "--text", text, "--typical", spelling, "--json"])
                self.assertEqual(r.returncode, 0, r.stderr)
                self.assertEqual(json.loads(decoded(r))["characters"], want)

    def test_stroke_counts_past_their_range_are_one_usage_error_naming_the_option(self):
        for value in ("0", "-1", "256", "99999999999999999999", "1.0", "", "２", "+2", "0x2"):
            with self.subTest(value=value):
                self.assert_one_error(self.cli(["characters", "--text", "十", f"--strokes={value}"]), 2,
                                      "--strokes")

    def test_stroke_count_255_lists_nothing_and_names_nothing_as_missing(self):
        r = self.cli(["characters", "--text", "永十a", "--strokes", "255", "--json"])
        self.assertEqual(r.returncode, 0, r.stderr)
        got = json.loads(decoded(r))
        self.assertEqual((got["count"], got["characters"], got["not_found"]), (0, [], ["a"]))

    def test_unknown_typical_strokes_are_usage_errors_naming_the_option(self):
        for value in ("0", "40", "", "-3", " HZG", "㇆㇆", "ＨＺＧ", "HZG\u200b", "\u31c6\ufe0f", "0x0A"):
            with self.subTest(value=value):
                self.assert_one_error(self.cli(["characters", "--text", "十", f"--typical={value}"]), 2,
                                      "--typical")
        line = self.assert_one_error(self.cli(["characters", "--typical", "hzgg"]), 2, "--typical")
        self.assertIn("HZG", line)

    def test_text_listing_is_its_characters_in_order_once_and_names_the_rest(self):
        picked = random.Random(7).sample(list(self.by_char), 12)
        text = ("a" + picked[0] + "\u0301" + " \t\u00a0\u3000".join(picked) + "😀" + picked[3] + "a"
                + "\u2028" + picked[0] + "😀\u0301")
        r = self.cli(["characters", "--text", text, "--json"])
        self.assertEqual(r.returncode, 0, r.stderr)
        got = json.loads(decoded(r))
        self.assertEqual(got["characters"], [self.by_char[c] for c in picked])
        self.assertEqual(got["count"], 12)
        self.assertEqual(got["not_found"], ["a", "\u0301", "😀"])

    def test_text_of_white_space_only_lists_nothing(self):
        r = self.cli(["characters", "--text", " \t\u00a0\u3000\u2003", "--json"])
        self.assertEqual(r.returncode, 0, r.stderr)
        got = json.loads(decoded(r))
        self.assertEqual((got["count"], got["characters"], got["not_found"]), (0, [], []))

    def test_empty_text_is_not_every_character(self):
        r = self.cli(["characters", "--text", "", "--json"])
        if r.returncode == 0:
            got = json.loads(decoded(r))
            self.assertEqual((got["count"], got["characters"]), (0, []))
        else:
            self.assert_one_error(r, 2, "--text")

    def test_control_character_of_a_text_is_named_as_printable_text(self):
        r = self.cli(["characters", "--text", "十\x1b[2J"])
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertNotIn(b"\x1b", r.stdout)
        self.assertIn("\\x1b (U+001B)", decoded(r))

    def test_surrogate_bytes_in_a_text_are_a_usage_error_naming_offset_and_bytes(self):
        line = self.assert_one_error(self.cli(["characters", "--text", "十".encode() + b"\xed\xa0\x80"]), 2,
                                     "--text", "malformed UTF-8", "byte 3")
        self.assertIn("\\xed", line)


class EveryCharacter(Offline):
    def test_model_of_random_characters_equals_a_default_store_of_their_json(self):
        for c in self.any:
            with self.subTest(character=c):
                bundled = self.cli(["model", c, "--json"])
                self.assertEqual(bundled.returncode, 0, bundled.stderr)
                stored = self.cli(["model", c, "--json", "--store", self.store])
                self.assertEqual(stored.returncode, 0, stored.stderr)
                self.assertEqual(json.loads(decoded(bundled)), json.loads(decoded(stored)))
                model = json.loads(decoded(bundled))
                self.assertEqual(model["typical_stroke_ids"], self.by_char[c]["typical_ids"])
                self.assertEqual(len(model["strokes"]), len(self.medians(c)))
                text = self.cli(["model", c])
                self.assertIn(f"bundled:hanzi-writer-data-2.0.1.clg#{c} (U+{ord(c):04X})", decoded(text))

    def test_model_from_the_bundled_store_is_its_json_fitted_within_the_quantisation(self):
        for c in self.any:
            with self.subTest(character=c):
                bundled = json.loads(decoded(self.cli(["model", c, "--json"])))
                fitted = json.loads(decoded(self.cli(["model", c, "--json", "--data", self.data])))
                self.assertEqual(bundled["typical_stroke_ids"], fitted["typical_stroke_ids"])
                for a, b in zip(bundled["strokes"], fitted["strokes"]):
                    self.assertEqual(a["attraction_factors"], b["attraction_factors"])
                    pa = np.array([p for e in a["elements"] for p in e["control_points"]])
                    pb = np.array([p for e in b["elements"] for p in e["control_points"]])
                    self.assertEqual(pa.shape, pb.shape)
                    self.assertLessEqual(np.abs(pa * 2 - np.round(pa * 2)).max(), 1e-9)
                    self.assertLessEqual(np.hypot(*(pa - pb).T).max(), MAX_QUANTISATION)

    def test_score_of_a_trace_along_the_data_medians_accepts_every_stroke(self):
        for c in self.few:
            with self.subTest(character=c):
                trace = self.tmp / f"median-{ord(c):x}.csv"
                rows = ["t,x,y,pen"]
                t = 0.0
                for median in self.medians(c):
                    m = np.asarray(median, float)
                    steps = np.linspace(0, 1, 120)
                    length = np.r_[0, np.cumsum(np.hypot(*np.diff(m, axis=0).T))]
                    pts = np.column_stack([np.interp(steps * length[-1], length, m[:, k]) for k in (0, 1)])
                    rows.append(f"{t:.3f},{pts[0][0]},{pts[0][1]},0")
                    for p in pts:
                        t += 0.004
                        rows.append(f"{t:.3f},{p[0]},{p[1]},1")
                    t += 0.004
                    rows.append(f"{t:.3f},{pts[-1][0]},{pts[-1][1]},0")
                    t += 0.2
                trace.write_text("\n".join(rows) + "\n")
                r = self.cli(["score", trace, "--character", c, "--units", "data", "--json", "-"])
                self.assertEqual(r.returncode, 0, r.stderr)
                got = json.loads(decoded(r))
                n = self.by_char[c]["strokes"]
                self.assertEqual((got["strokes_total"], got["strokes_accepted"]), (n, n))
                if cg is not None:
                    py = cg.score(str(trace), c, units="data")
                    self.assertEqual((py["strokes_total"], py["strokes_accepted"]), (n, n))

    def test_short_trial_and_its_rerun_on_a_default_store_of_the_json_agree(self):
        c = self.few[0]
        first = self.cli(["trial", c, "--max-duration", "30", "--json", "r.json"])
        self.assertEqual(first.returncode, 0, first.stderr)
        record = json.loads((self.tmp / "r.json").read_text(encoding="utf-8"))
        self.assertEqual(record["character"], c)
        self.assertEqual(record["strokes_total"], self.by_char[c]["strokes"])
        again = self.cli(["trial", "--spec", "r.json", "--store", self.store, "--json", "r2.json"])
        self.assertEqual(again.returncode, 0, again.stderr)
        second = json.loads((self.tmp / "r2.json").read_text(encoding="utf-8"))
        for key in ("strokes_accepted", "mean_deviation_m", "frechet_m", "total_time_s"):
            self.assertEqual(record[key], second[key], key)
        if cg is not None:
            py = cg.simulate_trial(c, seed=0, max_duration_s=30, keep_trace=False).metrics
            self.assertEqual(py["strokes_total"], record["strokes_total"])
            self.assertEqual(py["specification"]["scene"]["sha256"], record["specification"]["scene"]["sha256"])

    def test_rerun_of_a_bundled_record_on_other_character_data_is_refused(self):
        c = self.few[1]
        first = self.cli(["trial", c, "--max-duration", "30", "--json", "b.json"])
        self.assertEqual(first.returncode, 0, first.stderr)
        models_only = self.tmp / "models-only.clg"
        built = self.cli(["corpus", "build", "--data", self.data, "--out", models_only, "--medians", "off",
                          "--outlines", "off", "--threads", "1"])
        self.assertEqual(built.returncode, 0, built.stderr)
        for source in (["--data", self.data], ["--store", models_only]):
            with self.subTest(source=source[0]):
                r = self.cli(["trial", "--spec", "b.json", *source, "--json", "b2.json"])
                self.assertEqual(r.returncode, 1, r.stderr)
                self.assertIn("SHA-256", r.stderr.decode("utf-8", "replace"))
                self.assertFalse((self.tmp / "b2.json").exists())

    def test_trial_check_reads_no_character(self):
        r = self.cli(["trial", "a\u00e9", "--check"])
        self.assertEqual(r.returncode, 0, r.stderr)

    def test_model_of_a_character_and_a_combining_mark_names_both_code_points(self):
        self.assert_one_error(self.cli(["model", "十\u0301"]), 2, "U+5341", "U+0301")
        if cg is not None:
            with self.assertRaises(cg.InvalidArgument) as caught:
                cg.CharacterLibrary.default().load("十\u0301")
            self.assertIn("U+0301", str(caught.exception))

    def test_train_takes_a_bundled_character_and_refuses_one_the_library_lacks(self):
        lacking = self.cli(["train", "a\u00e9", "--exit-after", "0.1"])
        self.assert_one_error(lacking, 2, "CHARS", "U+0061")
        present = self.cli(["train", self.any[0], "--exit-after", "0.1"])
        self.assertNotEqual(present.returncode, 2, present.stderr)
        self.assertNotIn("is not in the", present.stderr.decode("utf-8", "replace"))

    def test_model_of_a_character_the_library_lacks_is_a_usage_error_naming_its_code_point(self):
        for c, code in (("a", "U+0061"), ("\u2f00", "U+2F00"), ("\U00020000", "U+20000")):
            with self.subTest(character=code):
                self.assert_one_error(self.cli(["model", c]), 2, code)

    def test_python_default_library_is_the_listing_with_the_data_medians(self):
        if cg is None:
            self.skipTest("the calligraphy Python package (PYTHONPATH) and numpy are needed")
        lib = cg.CharacterLibrary.default()
        self.assertEqual(len(lib), TOTAL)
        self.assertEqual(lib.characters(), [c["character"] for c in self.listing["characters"]])
        self.assertIsNone(lib.store_info)
        for c in self.any + self.few:
            with self.subTest(character=c):
                self.assertIn(c, lib)
                ch = lib.load(c)
                self.assertTrue(ch.source.startswith("bundled:hanzi-writer-data-2.0.1.clg#"), ch.source)
                self.assertEqual(list(ch.typical_stroke_ids), self.by_char[c]["typical_ids"])
                for stroke, median in zip(ch.strokes, self.medians(c)):
                    np.testing.assert_array_equal(np.asarray(stroke.median), np.asarray(median, float))
        self.assertNotIn("a", lib)
        with self.assertRaises(cg.CharacterNotFound) as caught:
            lib.load("a")
        self.assertIn("U+0061", str(caught.exception))
        self.assertIsInstance(caught.exception, KeyError)


class Stores(Offline):
    def forged(self, name, edit):
        """A copy of the small store, `edit(bytearray)` applied, written as `name`."""
        b = bytearray(self.store.read_bytes())
        edit(b)
        path = self.tmp / name
        path.write_bytes(bytes(b))
        return path

    @staticmethod
    def fix_crcs(b):
        """The tables' and header's CRC-32 recomputed after an edit (docs/corpus.md, header offsets 56, 60)."""
        records_offset = struct.unpack_from("<Q", b, 40)[0]
        struct.pack_into("<I", b, 56, zlib.crc32(bytes(b[64:records_offset])))
        struct.pack_into("<I", b, 60, zlib.crc32(bytes(b[:60])))

    def record_of(self, b, char):
        """(index entry offset, record start, record end) of `char` in store bytes `b`."""
        fields = HEADER.unpack_from(b, 0)
        n, index_offset, records_offset, records_size = fields[4], fields[8], fields[9], fields[10]
        entries = [struct.unpack_from("<III", b, index_offset + 12 * i) for i in range(n)]
        for i, (cp, off, _) in enumerate(entries):
            if cp == ord(char):
                end = entries[i + 1][1] if i + 1 < n else records_size
                return index_offset + 12 * i, records_offset + off, records_offset + end
        raise AssertionError(f"{char} not in the store")

    def test_store_header_is_the_documented_one(self):
        b = self.store.read_bytes()
        magic, major, minor, size, n, q, _, flags, index, records, records_size, _, crc = HEADER.unpack_from(b)
        self.assertEqual((magic, major, minor, size, q, flags & 3), (b"CLGSTORE", 1, 2, 64, 2, 3))
        self.assertEqual(n, len(list(self.data.glob("*.json"))))
        self.assertEqual((index, records, records + records_size), (688, 688 + 12 * n, len(b)))
        self.assertEqual(crc, zlib.crc32(b[:60]))

    def test_store_lists_exactly_its_characters_and_stats_agree(self):
        r = self.cli(["characters", "--store", self.store, "--json"])
        self.assertEqual(r.returncode, 0, r.stderr)
        got = json.loads(decoded(r))
        names = sorted((p.name[:-5] for p in self.data.glob("*.json")), key=ord)
        self.assertEqual([c["character"] for c in got["characters"]], names)
        self.assertEqual(got["characters"], [self.by_char[c] for c in names])
        by_count = {}
        for c in got["characters"]:
            by_count[c["strokes"]] = by_count.get(c["strokes"], 0) + 1
        for count, k in by_count.items():
            part = json.loads(decoded(self.cli(["characters", "--store", self.store, "--strokes", count,
                                                "--json"])))
            self.assertEqual(part["count"], k)
        self.assertEqual(sum(by_count.values()), got["count"])
        stats = self.cli(["corpus", "stats", self.store, "--json"])
        self.assertEqual(stats.returncode, 0, stats.stderr)
        s = json.loads(decoded(stats))
        text = json.dumps(s)
        self.assertIn(str(len(names)), text)
        self.assertIn(str(sum(c["strokes"] for c in got["characters"])), text)

    def test_store_with_a_flipped_record_fails_only_that_character_naming_it(self):
        def flip(b):
            _, start, _ = self.record_of(b, "十")
            b[start + 1] ^= 0x40
        bad = self.forged("flipped.clg", flip)
        self.assert_one_error(self.cli(["model", "十", "--store", bad]), 1, "flipped.clg", "U+5341")
        ok = self.cli(["model", "二", "--store", bad])
        self.assertEqual(ok.returncode, 0, ok.stderr)
        self.assert_one_error(self.cli(["trial", "二十", "--store", bad]), 1, "flipped.clg", "U+5341")
        if cg is not None:
            lib = cg.CharacterLibrary.from_store(bad)
            self.assertEqual(lib.load("二").typical_stroke_ids, [1, 1])
            with self.assertRaises(cg.DataError) as caught:
                lib.load("十")
            self.assertIn("U+5341", str(caught.exception))
        stats = self.cli(["corpus", "stats", bad, "--json"])
        self.assertEqual(stats.returncode, 1)
        lines = error_lines(stats)
        self.assertEqual(len(lines), 1, lines)
        self.assertIn("U+5341", lines[0])
        self.assertEqual(len(json.loads(decoded(stats))["errors"]), 1)

    def test_record_with_typical_id_zero_and_its_checksums_recomputed_is_bad_data(self):
        def zero_id(b):
            entry, start, end = self.record_of(b, "十")
            b[start + 1] &= 0xC0                        # typical_id:6, the first bits after stroke_count:8
            struct.pack_into("<I", b, entry + 8, zlib.crc32(bytes(b[start:end])))
            self.fix_crcs(b)
        bad = self.forged("id0.clg", zero_id)
        self.assert_one_error(self.cli(["model", "十", "--store", bad]), 1, "id0.clg", "U+5341")

    def test_record_of_no_strokes_or_id_63_with_valid_checksums_is_bad_data_everywhere(self):
        b = self.store.read_bytes()
        n, index_offset, records_offset, records_size = (HEADER.unpack_from(b)[i] for i in (4, 8, 9, 10))
        entries = [struct.unpack_from("<III", b, index_offset + 12 * i) for i in range(n)]
        records = [(cp, b[records_offset + off:records_offset + (entries[i + 1][1] if i + 1 < n else records_size)])
                   for i, (cp, off, _) in enumerate(entries)]

        def rewritten(name, replace):
            index, body = b"", b""
            for cp, record in records:
                record = replace(record) if cp == ord("十") else record
                index += struct.pack("<III", cp, len(body), zlib.crc32(record))
                body += record
            out = bytearray(b[:index_offset] + index + body)
            struct.pack_into("<Q", out, 48, len(body))
            self.fix_crcs(out)
            (self.tmp / name).write_bytes(bytes(out))
            return self.tmp / name

        self.assertEqual(rewritten("same.clg", lambda r: r).read_bytes(), b)
        zero = rewritten("zero.clg", lambda r: b"\0\0")
        id63 = rewritten("id63.clg", lambda r: r[:1] + bytes([r[1] | 0x3F]) + r[2:])
        (self.tmp / "t.csv").write_text("t,x,y,pen\n0,0,0,0\n0.1,1,1,1\n")
        for store in (zero, id63):
            for command in (["model", "十"], ["trial", "十", "--max-duration", "1"],
                            ["score", "t.csv", "--character", "十"], ["characters", "--text", "十"]):
                with self.subTest(store=store.name, command=command[0]):
                    self.assert_one_error(self.cli([*command, "--store", store]), 1, store.name, "U+5341")

    def test_store_given_as_a_dash_is_a_file_named_dash_or_refused_as_an_option_value(self):
        # `--store -`: a value starting with `-` that is no output is refused (option syntax), or it is the file
        # named `-`, which does not exist ("the error says that standard input is not read")
        r = self.cli(["model", "十", "--store", "-"])
        line = self.assert_one_error(r, (1, 2), "-")
        self.assertIn("--store" if r.returncode == 2 else "standard input", line)
        line = self.assert_one_error(self.cli(["corpus", "stats", "-"]), 1, "-")
        self.assertIn("standard input", line)
        shutil.copyfile(self.store, self.tmp / "-")
        try:
            r = self.cli(["corpus", "stats", "-", "--json"])
            self.assertEqual(r.returncode, 0, r.stderr)
        finally:
            (self.tmp / "-").unlink()

    def test_damaged_or_foreign_stores_are_one_error_naming_the_file(self):
        b = self.store.read_bytes()
        cases = {
            "empty.clg": b"",
            "cut.clg": b[:100],
            "short.clg": b[:-1],
            "json.clg": (self.data / "十.json").read_bytes(),
            "major2.clg": None, "flag.clg": None, "nan.clg": None, "order.clg": None, "count.clg": None,
        }

        def swap_first_two(x):
            index = struct.unpack_from("<Q", x, 32)[0]
            first, second = struct.unpack_from("<I", x, index)[0], struct.unpack_from("<I", x, index + 12)[0]
            struct.pack_into("<I", x, index, second)
            struct.pack_into("<I", x, index + 12, first)
            self.fix_crcs(x)

        def one_more(x):
            struct.pack_into("<I", x, 16, struct.unpack_from("<I", x, 16)[0] + 1)
            self.fix_crcs(x)
        forge = {
            "major2.clg": lambda x: (struct.pack_into("<H", x, 8, 2), self.fix_crcs(x)),
            "flag.clg": lambda x: (struct.pack_into("<I", x, 28, struct.unpack_from("<I", x, 28)[0] | 0x20),
                                   self.fix_crcs(x)),
            "nan.clg": lambda x: (struct.pack_into("<d", x, 64, float("nan")), self.fix_crcs(x)),
            "order.clg": swap_first_two, "count.clg": one_more,
        }
        for name, content in cases.items():
            with self.subTest(store=name):
                path = self.forged(name, forge[name]) if content is None else self.tmp / name
                if content is not None:
                    path.write_bytes(content)
                self.assert_one_error(self.cli(["model", "十", "--store", path]), 1, name)
                if cg is not None:
                    with self.assertRaises(cg.DataError) as caught:
                        cg.CharacterLibrary.from_store(path).load("十")
                    self.assertIn(name, str(caught.exception))

    def test_store_info_and_a_store_without_medians(self):
        if cg is None:
            self.skipTest("the calligraphy Python package (PYTHONPATH) and numpy are needed")
        info = cg.CharacterLibrary.from_store(self.store).store_info
        self.assertEqual(info["character_count"], len(list(self.data.glob("*.json"))))
        self.assertEqual((info["steps_per_unit"], info["fit_tolerance"]), (2, 10))
        self.assertEqual(info["file_bytes"], self.store.stat().st_size)
        self.assertAlmostEqual(info["max_quantisation_error"], 2 ** 0.5 / 4, places=3)
        self.assertEqual((info["medians"], info["outlines"]), (True, True))
        no_medians = self.tmp / "no-medians.clg"
        built = self.cli(["corpus", "build", "--data", self.data, "--out", no_medians, "--medians", "off",
                          "--threads", "1"])
        self.assertEqual(built.returncode, 0, built.stderr)
        minor, flags = struct.unpack_from("<H", no_medians.read_bytes(), 10)[0], \
            struct.unpack_from("<I", no_medians.read_bytes(), 28)[0]
        self.assertEqual((minor, flags), (2, 2))
        lib = cg.CharacterLibrary.from_store(no_medians)
        self.assertEqual((lib.store_info["medians"], lib.store_info["outlines"]), (False, True))
        self.assertEqual(np.asarray(lib.load("十").strokes[0].median).shape, (0, 2))

    def test_later_minor_version_is_read(self):
        def minor(b):
            struct.pack_into("<H", b, 10, 9)
            self.fix_crcs(b)
        later = self.forged("minor9.clg", minor)
        want = self.cli(["model", "十", "--json", "--store", self.store])
        got = self.cli(["model", "十", "--json", "--store", later])
        self.assertEqual(got.returncode, 0, got.stderr)
        self.assertEqual(got.stdout, want.stdout)

    def test_links_folders_and_fifos_as_stores(self):
        link = self.tmp / "link.clg"
        link.symlink_to(self.store)
        want = self.cli(["model", "十", "--json", "--store", self.store])
        got = self.cli(["model", "十", "--json", "--store", link])
        self.assertEqual(got.returncode, 0, got.stderr)
        self.assertEqual(got.stdout, want.stdout)
        dangling = self.tmp / "dangling.clg"
        dangling.symlink_to(self.tmp / "gone.clg")
        self.assert_one_error(self.cli(["model", "十", "--store", dangling]), 1, "dangling.clg")
        self.assert_one_error(self.cli(["model", "十", "--store", self.data]), 1, "data")
        fifo = self.tmp / "fifo.clg"
        os.mkfifo(fifo)
        self.assert_one_error(self.cli(["model", "十", "--store", fifo], timeout=10), 1, "fifo.clg",
                              "not a regular file")

    def test_data_and_store_together_are_one_usage_error_naming_both(self):
        for command in (["model", "十"], ["characters"], ["trial", "十"], ["score", "t.csv", "--character", "十"]):
            with self.subTest(command=command[0]):
                r = self.cli([*command, "--data", self.data, "--store", self.store])
                self.assert_one_error(r, 2, "--data", "--store")

    def test_data_folder_replaces_every_character_rather_than_adds(self):
        self.assert_one_error(self.cli(["model", "永", "--data", self.data]), 2, "U+6C38")
        got = json.loads(decoded(self.cli(["characters", "--data", self.data, "--json"])))
        self.assertEqual([c["character"] for c in got["characters"]],
                         sorted((p.name[:-5] for p in self.data.glob("*.json")), key=ord))
        self.assert_one_error(self.cli(["model", "十", "--data", self.tmp / "no-such-folder"]), 1, "no-such-folder")
        self.assert_one_error(self.cli(["train", "永", "--store", self.store]), 2, "U+6C38")

    def test_character_a_store_lacks_is_a_usage_error_and_one_it_has_is_read(self):
        self.assert_one_error(self.cli(["model", "永", "--store", self.store]), 2, "U+6C38")
        (self.tmp / "empty.csv").write_text("t,x,y,pen\n0,0,0,0\n")
        self.assert_one_error(self.cli(["score", "empty.csv", "--character", "十永", "--store", self.store]), 2,
                              "--character", "U+6C38")
        r = self.cli(["model", "刀", "--store", self.store])
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertIn("s.clg#刀 (U+5200)", decoded(r))

    def test_outputs_onto_the_store_are_refused_and_leave_it(self):
        before = self.store.read_bytes()
        hard = self.tmp / "hard.clg"
        os.link(self.store, hard)
        for out in (["--json", self.store], ["--json", hard], ["--svg", self.tmp / "link2.clg"]):
            with self.subTest(out=str(out[1])):
                if out[1].name == "link2.clg" and not out[1].is_symlink():
                    out[1].symlink_to(self.store)
                command = ["trial", "十", "--store", self.store, *out] if out[0] == "--json" else \
                    ["model", "十", "--store", self.store, *out]
                self.assert_one_error(self.cli(command), 2, "--store", out[0])
                self.assertEqual(self.store.read_bytes(), before)


class Build(Offline):
    def test_corpus_build_out_on_a_character_file_is_refused_and_leaves_it(self):
        target = self.data / "十.json"
        before = target.read_bytes()
        r = self.cli(["corpus", "build", "--data", self.data, "--out", target])
        self.assert_one_error(r, 2, "--out", "--data")
        self.assertEqual(target.read_bytes(), before)
        hard = self.tmp / "hard-十.json"
        os.link(target, hard)
        link = self.tmp / "link-十.json"
        link.symlink_to(target)
        for out in (hard, link, self.tmp / "data" / ".." / "data" / "十.json"):
            with self.subTest(out=str(out)):
                r = self.cli(["corpus", "build", "--data", self.data, "--out", out])
                self.assert_one_error(r, 2, "--out", "--data")
                self.assertEqual(target.read_bytes(), before)
        hard.unlink()
        link.unlink()
        self.assertEqual(sorted(p.name for p in self.data.iterdir()),
                         sorted(f"{c}.json" for c in {*self.few, *self.any, "十", "二", "刀"}))

    def test_corpus_build_out_on_a_folder_or_standard_output_is_refused(self):
        self.assert_one_error(self.cli(["corpus", "build", "--data", self.data, "--out", self.data]), 1, "--out")
        self.assert_one_error(self.cli(["corpus", "build", "--data", self.data, "--out", "-"]), 2, "--out")

    def test_build_options_past_their_ranges_are_usage_errors_naming_them(self):
        for option, value in (("--threads", "0"), ("--threads", "257"), ("--tolerance", "0"),
                              ("--tolerance", "nan"), ("--steps", "3"), ("--medians", "yes")):
            with self.subTest(option=option, value=value):
                r = self.cli(["corpus", "build", "--data", self.data, "--out", "x.clg", f"{option}={value}"])
                self.assert_one_error(r, 2, option)
                self.assertFalse((self.tmp / "x.clg").exists())

    def test_folder_names_one_code_point_each_beyond_the_bmp_and_radicals_apart(self):
        folder = self.tmp / "names"
        folder.mkdir()
        ten = (HWD / "十.json").read_bytes()
        for name in ("\U00020000", "\u2f00", "十", "ab", "\u3000", "\x01", "\u3000十"):
            (folder / f"{name}.json").write_bytes(ten)
        out = self.tmp / "names.clg"
        r = self.cli(["corpus", "build", "--data", folder, "--out", out, "--threads", "1"])
        self.assertEqual(r.returncode, 0, r.stderr)
        for source in (["--store", out], ["--data", folder]):
            with self.subTest(source=source[0]):
                got = json.loads(decoded(self.cli(["characters", *source, "--json"])))
                self.assertEqual([(c["character"], c["code_point"]) for c in got["characters"]],
                                 [("\u2f00", "U+2F00"), ("十", "U+5341"), ("\U00020000", "U+20000")])
                model = self.cli(["model", "\U00020000", *source])
                self.assertEqual(model.returncode, 0, model.stderr)
                self.assertIn("U+20000", decoded(model))
        self.assert_one_error(self.cli(["model", "\u4e00", "--store", out]), 2, "U+4E00")

    def test_build_gives_the_same_bytes_whatever_the_threads(self):
        two = self.tmp / "two.clg"
        r = self.cli(["corpus", "build", "--data", self.data, "--out", two, "--threads", "2"])
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertEqual(two.read_bytes(), self.store.read_bytes())

    def test_fidelity_markdown_onto_a_character_file_and_tolerances_past_range_are_refused(self):
        target = self.data / "二.json"
        before = target.read_bytes()
        r = self.cli(["corpus", "fidelity", "--data", self.data, "--tolerances", "10", "--markdown", target])
        self.assert_one_error(r, 2, "--markdown", "--data")
        self.assertEqual(target.read_bytes(), before)
        for value in ("0", "10,0", "10,nan", "10,,20"):
            with self.subTest(tolerances=value):
                r = self.cli(["corpus", "fidelity", "--data", self.data, f"--tolerances={value}"])
                self.assert_one_error(r, 2, "--tolerances")

    def test_data_that_is_a_file_writes_no_store(self):
        r = self.cli(["corpus", "build", "--data", self.data / "十.json", "--out", "file.clg"])
        self.assert_one_error(r, (1, 2), "十.json")
        self.assertFalse((self.tmp / "file.clg").exists())

    def test_character_of_more_elements_than_a_record_holds_is_listed_and_the_store_holds_the_others(self):
        # a median of 273 points zig-zagging 120 units (within every bound of the loader: at most 10,000 points)
        # that the fitter models as 272 elements, one more than a record's count and its extension hold
        # (docs/corpus.md, "Record": 15 + 1 + 255); a straight one beside it
        folder = self.tmp / "zigzag"
        folder.mkdir()
        zigzag = [[100 + i * 800 / 272, 500 + (60 if i % 2 else -60)] for i in range(273)]
        (folder / "乙.json").write_text(json.dumps({"strokes": ["M 0 0 L 10 10 Z"], "medians": [zigzag]}))
        (folder / "一.json").write_text(json.dumps({"strokes": ["M 0 0 L 10 10 Z"],
                                                    "medians": [[[100, 500], [900, 500]]]}))
        model = self.cli(["model", "乙", "--data", folder])
        self.assertEqual(model.returncode, 0, model.stderr)     # the library reads and models it
        out = self.tmp / "zigzag.clg"
        r = self.cli(["corpus", "build", "--data", folder, "--out", out, "--threads", "1"])
        self.assert_one_error(r, 1, "乙")
        self.assertIn("乙 (U+4E59)", decoded(r))                  # listed on standard output with the reason
        self.assertTrue(out.exists(), "no store written: it should hold the others")
        got = json.loads(decoded(self.cli(["characters", "--store", out, "--json"])))
        self.assertEqual([c["character"] for c in got["characters"]], ["一"])

    def test_empty_folder_writes_no_store_and_keeps_an_earlier_one(self):
        empty = self.tmp / "empty"
        empty.mkdir()
        (empty / "ab.json").write_text("{}")
        (empty / " .json").write_text("{}")
        earlier = self.tmp / "earlier.clg"
        shutil.copyfile(self.store, earlier)
        r = self.cli(["corpus", "build", "--data", empty, "--out", earlier])
        self.assert_one_error(r, 1, "empty")
        self.assertEqual(earlier.read_bytes(), self.store.read_bytes())

    def test_forged_characters_are_listed_and_the_store_holds_the_others(self):
        forged = self.tmp / "forged"
        forged.mkdir()
        for c in ("十", "二"):
            shutil.copyfile(HWD / f"{c}.json", forged / f"{c}.json")
        good = json.loads((HWD / "人.json").read_text(encoding="utf-8"))
        (forged / "人.json").write_text('{"strokes": ["M 0 0 L 1 1 Z"], "medians": [[[0, 0], [5')   # cut
        (forged / "八.json").write_text(json.dumps({"strokes": good["strokes"] + good["strokes"][:1],
                                                    "medians": good["medians"]}))   # 3 outlines, 2 medians
        huge = [[[1e300, 0.0], [2e300, 5.0]], good["medians"][1]]
        (forged / "丁.json").write_text(json.dumps({"strokes": good["strokes"], "medians": huge}))
        overflow = json.dumps({"strokes": good["strokes"], "medians": good["medians"]}).replace(
            str(good["medians"][0][0][0]), "1e999", 1)
        (forged / "乂.json").write_text(overflow)
        (forged / "丫.json").write_text(json.dumps({"strokes": good["strokes"],
                                                    "medians": [good["medians"][0], []]}))
        (forged / "大.json").write_text(json.dumps({"strokes": good["strokes"],
                                                    "medians": [good["medians"][0], [[5, 5], [5, 5], [5, 5]]]}))
        (forged / "七.json").write_text(json.dumps({"strokes": good["strokes"]}))
        out = self.tmp / "forged.clg"
        r = self.cli(["corpus", "build", "--data", forged, "--out", out, "--threads", "1"])
        bad = ["人", "八", "丁", "乂", "丫", "大", "七"]
        line = self.assert_one_error(r, 1, "7")
        self.assertTrue(any(c in line for c in bad), line)
        listed = decoded(r)
        for c in bad:
            self.assertIn(c, listed)
        got = json.loads(decoded(self.cli(["characters", "--store", out, "--json"])))
        self.assertEqual([c["character"] for c in got["characters"]], ["二", "十"])
        for c in bad:
            with self.subTest(character=c):
                self.assert_one_error(self.cli(["model", c, "--store", out]), 2, f"U+{ord(c):04X}")
                self.assert_one_error(self.cli(["model", c, "--data", forged]), 1, f"{c}.json")
        self.assert_one_error(self.cli(["model", "大", "--data", forged]), 1, "/medians/1")
        self.assert_one_error(self.cli(["model", "七", "--data", forged]), 1, "/medians")


if __name__ == "__main__":
    unittest.main()
