#!/usr/bin/env python3
"""Round 32D: a trial specification written by hand, edited and run again: `trial --spec`, its schema and its
record. From the docs alone (docs/cli.md `trial`, "Re-running a trial", "The trial specification" and its
field table, "Pen traces: format and limits" (a key given twice), the exit status table, `schema`;
docs/python.md "Running a trial again", "Errors"; `help(calligraphy.rerun_trial)`,
`help(calligraphy.check_trial_record)`).

A lab takes the record a `trial --json` wrote (十, fading guidance at 0.4, seed 7), changes one field at a
time and gives it to `trial --spec --check` and to Python's `check_trial_record`: each field at both ends of
its documented range (accepted), just beyond (refused naming the file, the JSON pointer and the range as the
table writes it), a length in mm where m is documented, the wrong type, null, a key given twice, an unknown
key, a key left out, an enumeration in Python's member spelling (`assist_as_needed`), a version outside 1..8,
an acceptance field that contradicts its force law's. The record is re-run whole, as the specification alone,
re-serialised with escapes and other number spellings (the CSV byte for byte), then edited: a seed, the
guidance stiffness (a warning that the re-run differs), the characters' SHA-256, a replay's teacher and its
SHA-256 (refused). Python's `rerun_trial` and a record Python writes are compared with the program's.

CALLIGRAPHY_CLI names the program; PYTHONPATH the built Python package. CALLIGRAPHY_SANITIZED=1 takes five cases.
"""
import copy
import csv
import json
import os
import shutil
import tempfile
import unittest
import warnings
from pathlib import Path

from outsider import OneErrorLine, error_lines, run, run_ok, sanitized_subset

try:
    import numpy as np
    import calligraphy as cg
except ImportError:  # reported by setUpClass
    np = cg = None

load_tests = sanitized_subset({"test_rerun_of_the_record_gives_the_csv_byte_for_byte",
                               "test_value_just_past_its_range_is_one_line_naming_pointer_and_range",
                               "test_key_given_twice_is_refused_naming_its_pointer",
                               "test_edited_characters_sha256_is_refused_and_writes_nothing",
                               "test_spec_with_a_trial_option_is_a_usage_error_naming_it"})

# The record the lab starts from: docs/cli.md's example of "Re-running a trial", on a small character.
FIRST = ["trial", "十", "--guidance-mode", "fading", "--guidance-gain", "0.4", "--seed", "7",
         "--max-duration", "30", "--json", "first.json", "--csv", "first.csv"]
ACCEPTANCE = ("corridor_m", "mean_deviation_m", "shortfall_m", "shortfall_fraction", "displacement_m",
              "follow_through_m", "max_gain_ratio", "lookahead_m", "shortfall_per_length", "shortfall_cap_m",
              "deviation_per_length", "mean_deviation_cap_m", "reference_character_size_m", "hint_after_misses",
              "assist_after_misses", "end_gap_m", "end_gap_fraction", "centred_coverage_fraction",
              "centred_balance_fraction", "centred_min_length_m", "centred_max_length_m", "miss_min_path_m")


def set_at(document, pointer, value):
    """`document` with the value at the JSON pointer `pointer` (under the record's root) set; an acceptance
    field of /specification/trial set at the force law's acceptance too (docs/cli.md: since version 6 the two
    must agree), unless `pointer` ends with '!'."""
    alone = pointer.endswith("!")
    pointer = pointer.rstrip("!")
    keys = pointer.strip("/").split("/")
    node = document
    for key in keys[:-1]:
        node = node[int(key)] if isinstance(node, list) else node[key]
    node[keys[-1]] = value
    if not alone and keys[:2] == ["specification", "trial"] and keys[-1] in ACCEPTANCE:
        document["specification"]["force_law"]["acceptance"][keys[-1]] = value
    return document


def delete_at(document, pointer):
    keys = pointer.strip("/").split("/")
    node = document
    for key in keys[:-1]:
        node = node[key]
    del node[keys[-1]]
    return document


class Round32D(unittest.TestCase, OneErrorLine):
    @classmethod
    def setUpClass(cls):
        if cg is None:
            raise unittest.SkipTest("numpy and the calligraphy Python package (PYTHONPATH) are needed")
        cls.tmp = Path(tempfile.mkdtemp(prefix="round32d-"))
        d = cls.tmp
        cls.first_run = run(FIRST, d)
        cls.first_text = (d / "first.json").read_text(encoding="utf-8")
        cls.record = json.loads(cls.first_text)
        cls.first_csv = (d / "first.csv").read_bytes()
        cls.count = 0

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.tmp, ignore_errors=True)

    def cli(self, *args, cwd=None):
        return run(list(args), cwd or self.tmp)

    def write(self, document, name=None, text=None):
        """The record `document` (or the raw `text`) in a file of its own; its name."""
        type(self).count += 1
        name = name or f"r{self.count}.json"
        (self.tmp / name).write_text(text if text is not None else json.dumps(document, indent=1),
                                     encoding="utf-8")
        return name

    def edited(self, pointer, value):
        return set_at(copy.deepcopy(self.record), pointer, value)

    def spelt_seed(self, spelling):
        """The record's text with the specification's seed (not the metrics' `seed`) spelt as `spelling`."""
        text = json.dumps(self.edited("/specification/trial/seed", "@SEED@"), indent=1)
        return text.replace('"@SEED@"', spelling)

    def mode_record(self, mode):
        """A record of a trial in guidance mode `mode` (Python's simulate_trial: its record states the mode's
        law with its defaults)."""
        r = cg.simulate_trial("十", guidance_mode=mode, max_duration_s=0.2, keep_trace=False)
        return {"specification": copy.deepcopy(r.metrics["specification"])}

    def check(self, name):
        return self.cli("trial", "--spec", name, "--check")

    def assertAccepted(self, document, what):
        name = self.write(document)
        result = self.check(name)
        self.assertEqual(result.returncode, 0, f"{what}: {result.stderr.decode()}")
        cg.check_trial_record(document)

    def assertRefused(self, document, pointer, *needles, status=2):
        """`trial --spec --check` refuses it in one line `FILE: POINTER: ...` holding `needles`, and Python's
        check_trial_record raises DataError naming the same pointer."""
        name = self.write(document)
        line = self.assert_one_error(self.check(name), status, f"{name}: {pointer}", *needles)
        with self.assertRaises(cg.DataError) as caught:
            cg.check_trial_record(str(self.tmp / name))
        self.assertIn(pointer, str(caught.exception))
        return line

    # ---- the record as it was written ----------------------------------------------------------------------
    def test_first_trial_completed_and_its_record_states_what_ran(self):
        self.assertEqual(self.first_run.returncode, 0, self.first_run.stderr.decode())
        spec = self.record["specification"]
        self.assertEqual((spec["format"], spec["version"]), ("calligraphy-trial-specification", 9))
        trial = spec["trial"]
        self.assertEqual((trial["characters"], trial["guidance_mode"], trial["guidance_gain"], trial["seed"]),
                         ("十", "fading", 0.4, 7))
        self.assertEqual(spec["force_law"]["guidance_law"], {"mode": "fading", "gain": 0.4})
        for key in ACCEPTANCE:
            self.assertEqual(trial[key], spec["force_law"]["acceptance"][key], key)

    def test_table_numbers_strokes_from_one_and_the_json_from_zero(self):
        rows = [line.split() for line in self.first_run.stdout.decode().splitlines()]
        numbers = [r[0] for r in rows if len(r) > 3 and r[1] == "十"]
        self.assertEqual(numbers, ["1", "2"])
        self.assertEqual([s["index"] for s in self.record["renderer_strokes"]], [0, 1])

    def test_check_of_the_record_prints_one_line_and_writes_nothing(self):
        before = sorted(os.listdir(self.tmp))
        result = self.cli("trial", "--spec", "first.json", "--check", "--json", "c.json", "--csv", "c.csv")
        self.assertEqual(result.returncode, 0, result.stderr.decode())
        self.assertEqual(len(result.stdout.decode().strip().splitlines()), 1)
        self.assertEqual(sorted(os.listdir(self.tmp)), before)

    # ---- re-running ----------------------------------------------------------------------------------------
    def test_rerun_of_the_record_gives_the_csv_byte_for_byte(self):
        result = self.cli("trial", "--spec", "first.json", "--csv", "again.csv", "--json", "again.json")
        self.assertEqual(result.returncode, self.first_run.returncode, result.stderr.decode())
        self.assertEqual((self.tmp / "again.csv").read_bytes(), self.first_csv)
        self.assertNotIn("warning", result.stderr.decode())
        again = json.loads((self.tmp / "again.json").read_text(encoding="utf-8"))
        self.assertEqual(again["specification"], self.record["specification"])

    def test_specification_alone_reruns_the_same_and_compares_nothing(self):
        name = self.write(None, text=json.dumps(self.record["specification"], sort_keys=True, indent="\t"))
        result = self.cli("trial", "--spec", name, "--csv", "alone.csv")
        self.assertEqual(result.returncode, 0, result.stderr.decode())
        self.assertEqual((self.tmp / "alone.csv").read_bytes(), self.first_csv)
        self.assertEqual(error_lines(result), [])

    def test_record_reserialised_with_escapes_and_other_number_spellings_reruns_the_same(self):
        text = json.dumps(self.record, ensure_ascii=True, separators=(",", ":"))
        text = text.replace('"seed":7', '"\\u0073eed":7e0', 1)
        text = text.replace('"rate_hz":1000.0', '"rate_hz":1E3')
        text = text.replace('"centre_m":[0.0,0.0]', '"centre_m":[-0,-0.0]')
        self.assertIn('\\u0073eed', text)
        self.assertIn('"rate_hz":1E3', text)
        self.assertIn('[-0,-0.0]', text)
        self.assertIn('\\u5341', text)
        name = self.write(None, text=text)
        result = self.cli("trial", "--spec", name, "--csv", "spelt.csv")
        self.assertEqual(result.returncode, 0, result.stderr.decode())
        self.assertEqual((self.tmp / "spelt.csv").read_bytes(), self.first_csv)
        self.assertNotIn("warning", result.stderr.decode())

    def test_seed_spelt_with_a_fraction_or_exponent_below_2_53_is_that_seed(self):
        for spelling in ("7.0", "7e0", "0.7e1"):
            with self.subTest(spelling=spelling):
                name = self.write(None, text=self.spelt_seed(spelling))
                result = self.check(name)
                self.assertEqual(result.returncode, 0, result.stderr.decode())
                self.assertEqual(cg.check_trial_record(str(self.tmp / name))["trial"]["seed"], 7)

    def test_seed_with_exponent_or_fraction_at_or_past_2_53_is_refused_at_its_pointer(self):
        for spelling in ("1.23456789012346e+16", "9007199254740992.0", "9.007199254740992e15", "7.5"):
            with self.subTest(spelling=spelling):
                name = self.write(None, text=self.spelt_seed(spelling))
                self.assert_one_error(self.check(name), 2, f"{name}: /specification/trial/seed")

    def test_edited_seed_reruns_with_one_warning_that_it_differs(self):
        name = self.write(self.edited("/specification/trial/seed", 8))
        result = self.cli("trial", "--spec", name, "--csv", "seed8.csv", "--json", "seed8.json")
        rerun = json.loads((self.tmp / "seed8.json").read_text(encoding="utf-8"))
        self.assertEqual(rerun["specification"]["trial"]["seed"], 8)
        self.assertEqual(result.returncode, 0 if rerun["end_reason"] == "completed" else 1)
        self.assertNotEqual((self.tmp / "seed8.csv").read_bytes(), self.first_csv)
        warned = [line for line in error_lines(result) if "warning" in line]
        self.assertEqual(len(warned), 1, error_lines(result))
        self.assertIn(f"--spec {name}: the re-run differs from the run the record states", warned[0])
        # The specification alone states no run: the same edit says nothing.
        alone = self.write(None, text=json.dumps(self.edited("/specification/trial/seed", 8)["specification"]))
        quiet = self.cli("trial", "--spec", alone, "--csv", "seed8b.csv")
        self.assertEqual(quiet.returncode, result.returncode)
        self.assertEqual((self.tmp / "seed8b.csv").read_bytes(), (self.tmp / "seed8.csv").read_bytes())
        self.assertNotIn("warning", quiet.stderr.decode())

    def test_edited_guidance_stiffness_reruns_with_a_warning_and_states_it(self):
        document = self.edited("/specification/trial/guidance_stiffness_n_per_m", 0.0)
        set_at(document, "/specification/force_law/guidance_stiffness_n_per_m", 0.0)
        name = self.write(document)
        result = self.cli("trial", "--spec", name, "--json", "k0.json")
        rerun = json.loads((self.tmp / "k0.json").read_text(encoding="utf-8"))
        self.assertEqual(rerun["specification"]["trial"]["guidance_stiffness_n_per_m"], 0.0)
        self.assertEqual(rerun["specification"]["force_law"]["guidance_stiffness_n_per_m"], 0.0)
        self.assertIn("the re-run differs from the run the record states", result.stderr.decode())

    def test_edited_characters_sha256_is_refused_and_writes_nothing(self):
        sha = self.record["specification"]["scene"]["sha256"]
        other = ("0" if sha[0] != "0" else "1") + sha[1:]
        name = self.write(self.edited("/specification/scene/sha256", other))
        result = self.cli("trial", "--spec", name, "--csv", "sha.csv", "--json", "sha.json")
        self.assert_one_error(result, 1)
        self.assertFalse((self.tmp / "sha.csv").exists())
        self.assertFalse((self.tmp / "sha.json").exists())
        with self.assertRaises(cg.InvalidArgument):
            cg.rerun_trial(str(self.tmp / name))

    def test_characters_sha256_that_is_no_sha256_is_refused_at_its_pointer(self):
        for value in ("xyz", self.record["specification"]["scene"]["sha256"].upper(),
                      self.record["specification"]["scene"]["sha256"][:63]):
            with self.subTest(value=value):
                self.assertRefused(self.edited("/specification/scene/sha256", value), "/specification/scene/sha256")

    def test_characters_the_library_lacks_are_refused_naming_the_pointer_and_the_character(self):
        document = self.edited("/specification/trial/characters", "\ue000")
        name = self.write(document)
        self.assertEqual(self.check(name).returncode, 0, "--check reads no character")
        self.assert_one_error(self.cli("trial", "--spec", name, "--csv", "pua.csv"), 2,
                              f"{name}: /specification/trial/characters", "\ue000")
        self.assertFalse((self.tmp / "pua.csv").exists())

    # ---- the command line around --spec -----------------------------------------------------------------
    def test_spec_with_a_trial_option_is_a_usage_error_naming_it(self):
        for extra in (["--seed", "3"], ["--guidance-gain", "0.5"], ["--max-duration", "1"],
                      ["--writer-param", "learning_rate=0.3"]):
            with self.subTest(extra=extra):
                result = self.cli("trial", "--spec", "first.json", *extra, "--csv", "u.csv")
                self.assert_one_error(result, 2, extra[0])
                self.assertFalse((self.tmp / "u.csv").exists())
        self.assert_one_error(self.cli("trial", "十", "--spec", "first.json"), 2)

    def test_spec_output_onto_its_own_record_is_refused_and_the_record_kept(self):
        result = self.cli("trial", "--spec", "first.json", "--json", "./first.json")
        self.assert_one_error(result, 2, "--spec", "--json")
        self.assertEqual((self.tmp / "first.json").read_text(encoding="utf-8"), self.first_text)

    # ---- each field at its documented range --------------------------------------------------------------
    ENDS = [("/specification/trial/guidance_gain", 0.0), ("/specification/trial/guidance_gain", 1.0),
            ("/specification/trial/seed", 0), ("/specification/trial/seed", 2 ** 64 - 1),
            ("/specification/trial/rate_hz", 100.0), ("/specification/trial/rate_hz", 100000.0),
            ("/specification/trial/max_duration_s", 10000.0),
            ("/specification/trial/corridor_m", 0.1), ("/specification/trial/max_gain_ratio", 1.0),
            ("/specification/trial/max_gain_ratio", 100.0), ("/specification/trial/shortfall_per_length", 0.0),
            ("/specification/trial/shortfall_per_length", 1.0),
            ("/specification/trial/reference_character_size_m", 0.0),
            ("/specification/trial/reference_character_size_m", 1.0),
            ("/specification/trial/hint_after_misses", 0), ("/specification/trial/hint_after_misses", 1000),
            ("/specification/trial/assist_after_misses", 1000), ("/specification/trial/end_gap_fraction", 0.0),
            ("/specification/trial/centred_balance_fraction", 1.0),
            ("/specification/trial/miss_min_path_m", 0.0), ("/specification/trial/miss_min_path_m", 0.1)]

    def test_each_field_at_both_ends_of_its_range_is_accepted(self):
        for pointer, value in self.ENDS:
            with self.subTest(pointer=pointer, value=value):
                document = self.edited(pointer, value)
                if pointer.endswith("guidance_gain"):
                    set_at(document, "/specification/force_law/guidance_law/gain", value)
                self.assertAccepted(document, f"{pointer} = {value}")

    def test_each_guidance_modes_number_at_both_ends_is_accepted_in_its_mode(self):
        # Each applies to its own mode only (docs/cli.md: `assist-as-needed` only, ...): set with its law's value.
        for mode, field, law_field, values in (("assist-as-needed", "assist_band_m", "band_m", (0.0, 0.1)),
                                               ("error-amplification", "amplification_gain", "gain", (0.0, 1.0)),
                                               ("timing", "timing_speed_m_s", "speed_m_s", (1e-9, 1.0))):
            record = self.mode_record(mode)
            for value in values:
                with self.subTest(mode=mode, value=value):
                    document = set_at(copy.deepcopy(record), f"/specification/trial/{field}", value)
                    set_at(document, f"/specification/force_law/guidance_law/{law_field}", value)
                    self.assertAccepted(document, f"{field} = {value}")

    PAST = [("/specification/trial/assist_band_m", 0.1000001, "[0, 0.1]"),
            ("/specification/trial/assist_band_m", -1e-9, "[0, 0.1]"),
            ("/specification/trial/amplification_gain", 1.0000001, "[0, 1]"),
            ("/specification/trial/timing_speed_m_s", 0.0, "(0, 1]"),
            ("/specification/trial/timing_speed_m_s", 1.0000001, "(0, 1]"),
            ("/specification/trial/rate_hz", 99.999, "[100, 100000]"),
            ("/specification/trial/rate_hz", 100000.01, "[100, 100000]"),
            ("/specification/trial/max_duration_s", 0.0, "(0, 86400]"),
            ("/specification/trial/max_duration_s", 86400.01, "(0, 86400]"),
            ("/specification/trial/guidance_stiffness_n_per_m", -0.001, ">= 0"),
            ("/specification/trial/corridor_m", 0.1000001, "(0, 0.1]"),
            ("/specification/trial/corridor_m", 0.0, "(0, 0.1]"),
            ("/specification/trial/shortfall_fraction", 1.0, "(0, 1)"),
            ("/specification/trial/max_gain_ratio", 0.999, "[1, 100]"),
            ("/specification/trial/max_gain_ratio", 100.001, "[1, 100]"),
            ("/specification/trial/reference_character_size_m", 1.001, "[0, 1]"),
            ("/specification/trial/end_gap_fraction", 1.0, "[0, 1)"),
            ("/specification/trial/miss_min_path_m", 0.1000001, "[0, 0.1]")]

    def test_value_just_past_its_range_is_one_line_naming_pointer_and_range(self):
        for pointer, value, range_text in self.PAST:
            with self.subTest(pointer=pointer, value=value):
                document = self.edited(pointer, value)
                if pointer.endswith("guidance_stiffness_n_per_m"):
                    set_at(document, "/specification/force_law/guidance_stiffness_n_per_m", value)
                self.assertRefused(document, pointer, range_text)

    def test_count_past_its_range_names_the_range_as_the_table_and_the_option_write_it(self):
        # The table (docs/cli.md, `schema specification --markdown`) writes an integer's range 0..1000, as
        # `--hint-after-misses 1001` words it; a record's value past it is worded the same way.
        for pointer, value in (("/specification/trial/hint_after_misses", 1001),
                               ("/specification/trial/assist_after_misses", -1)):
            with self.subTest(pointer=pointer, value=value):
                self.assertRefused(self.edited(pointer, value), pointer, "0..1000")

    def test_guidance_gain_past_its_range_is_refused_as_the_docs_word_it(self):
        document = self.edited("/specification/trial/guidance_gain", 1.5)
        set_at(document, "/specification/force_law/guidance_law/gain", 1.5)
        name = self.write(document)
        line = self.assert_one_error(self.check(name), 2)
        self.assertIn(f"{name}: /specification/trial/guidance_gain: expected a number in [0, 1] "
                      "(TrialSpec.guidance_gain), got 1.5", line)

    def test_seed_past_2_64_or_negative_is_refused_at_its_pointer(self):
        for value in (2 ** 64, -1):
            with self.subTest(value=value):
                self.assertRefused(self.edited("/specification/trial/seed", value), "/specification/trial/seed")

    def test_ticks_past_ten_million_are_refused(self):
        # 10000 s at 1000 Hz is 10^7 ticks (accepted above); 10001 s is past the limit though in (0, 86400].
        name = self.write(self.edited("/specification/trial/max_duration_s", 10001.0))
        line = self.assert_one_error(self.check(name), 2, f"{name}: /specification/trial/")
        self.assertTrue("max_duration_s" in line or "rate_hz" in line, line)

    def test_lengths_in_millimetres_are_refused_as_out_of_range(self):
        for pointer, mm, range_text in (("/specification/trial/corridor_m", 6.5, "(0, 0.1]"),
                                        ("/specification/trial/assist_band_m", 1.0, "[0, 0.1]"),
                                        ("/specification/trial/end_gap_m", 4.5, "[0, 0.1]"),
                                        ("/specification/trial/timing_speed_m_s", 40.0, "(0, 1]"),
                                        ("/specification/scene/layout/character_size_m", 60.0, "(0, 1]")):
            with self.subTest(pointer=pointer):
                self.assertRefused(self.edited(pointer, mm), pointer, range_text)

    # ---- types, null, keys -----------------------------------------------------------------------------------
    def test_value_of_another_type_or_null_is_refused_at_its_pointer(self):
        for pointer, value in (("/specification/trial/seed", "7"), ("/specification/trial/guidance", "true"),
                               ("/specification/trial/guidance", 1), ("/specification/trial/rate_hz", None),
                               ("/specification/trial/rate_hz", "1000"),
                               ("/specification/trial/characters", 5),
                               ("/specification/trial/writer_parameters", {}),
                               ("/specification/trial/hint_after_misses", 3.5),
                               ("/specification/trial/guidance_mode", None),
                               ("/specification/trial/pacing", None),
                               ("/specification/force_law/crossfade_s", None),
                               ("/specification/scene/layout/centre_m", [0.0]),
                               ("/specification/teacher_sha256", None)):
            with self.subTest(pointer=pointer, value=value):
                self.assertRefused(self.edited(pointer, value), pointer)

    def test_key_given_twice_is_refused_naming_its_pointer(self):
        text = self.spelt_seed('7, "seed": 8')
        self.assertEqual(text.count('"seed": 8'), 1)
        name = self.write(None, text=text)
        self.assert_one_error(self.check(name), 2, f"{name}: /specification/trial/seed",
                              "the key is given twice in its object")
        with self.assertRaises(cg.DataError) as caught:
            cg.check_trial_record(str(self.tmp / name))
        self.assertIn("/specification/trial/seed", str(caught.exception))

    def test_unknown_key_is_refused_naming_its_pointer(self):
        for pointer in ("/specification/trial/seeds", "/specification/force_law/acceptance/corridor_mm",
                        "/specification/scene/layout/size_m", "/specification/comment"):
            with self.subTest(pointer=pointer):
                self.assertRefused(self.edited(pointer + "!", 1), pointer)

    def test_key_left_out_of_a_version_8_record_is_refused_naming_it(self):
        for pointer in ("/specification/trial/seed", "/specification/trial/miss_min_path_m",
                        "/specification/force_law/acceptance/miss_min_path_m", "/specification/teacher_sha256",
                        "/specification/scene/sha256"):
            with self.subTest(pointer=pointer):
                self.assertRefused(delete_at(copy.deepcopy(self.record), pointer), pointer)

    # ---- enumerations, versions, contradictions -------------------------------------------------------------
    def test_enumeration_in_another_surface_spelling_is_refused_in_a_file(self):
        document = self.mode_record("assist-as-needed")
        self.assertAccepted(document, "assist-as-needed")
        for pointer, value in (("/specification/trial/guidance_mode", "assist_as_needed"),
                               ("/specification/force_law/guidance_law/mode", "assist_as_needed"),
                               ("/specification/trial/pacing", "lock_step"),
                               ("/specification/trial/writer", "Simulated"),
                               ("/specification/trial/realtime", "IGNORE")):
            with self.subTest(pointer=pointer, value=value):
                self.assertRefused(set_at(copy.deepcopy(document), pointer + "!", value), pointer)

    def test_python_member_name_warns_and_the_record_holds_the_spelling(self):
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            r = cg.simulate_trial("十", guidance_mode="assist_as_needed", max_duration_s=0.2, keep_trace=False)
        said = [str(w.message) for w in caught if issubclass(w.category, DeprecationWarning)]
        self.assertTrue(any("assist-as-needed" in s for s in said), said)
        spec = r.metrics["specification"]
        self.assertEqual(spec["trial"]["guidance_mode"], "assist-as-needed")
        self.assertEqual(spec["force_law"]["guidance_law"]["mode"], "assist-as-needed")

    def test_version_other_than_1_to_9_is_refused_naming_the_versions_read(self):
        name = self.write(self.edited("/specification/version", 10))
        self.assert_one_error(self.check(name), 2, f"{name}: /specification/version: version 10 is not one "
                                                   "this library reads (1 to 9)")
        for value in ("9", None, -1, 7.5, 0):
            with self.subTest(value=value):
                self.assertRefused(self.edited("/specification/version", value), "/specification/version",
                                   "(1 to 9)")

    def test_format_of_another_kind_is_refused_at_its_pointer(self):
        self.assertRefused(self.edited("/specification/format", "calligraphy-trial-spec"), "/specification/format")

    def test_version_7_record_runs_with_miss_min_path_0_and_says_so(self):
        name = self.write(self.edited("/specification/version", 7))
        result = self.cli("trial", "--spec", name, "--json", "v7.json")
        notes = [line for line in error_lines(result) if "note:" in line and "miss_min_path_m" in line]
        self.assertTrue(notes, error_lines(result))
        for line in notes:
            self.assertIn(f"--spec {name}:", line)
            self.assertIn("version 7", line)
            self.assertIn("it takes 0", line)

    def test_acceptance_field_unlike_its_force_laws_is_refused_naming_both(self):
        for field, value in (("corridor_m", 0.005), ("hint_after_misses", 4), ("miss_min_path_m", 0.0)):
            with self.subTest(field=field):
                law = self.record["specification"]["force_law"]["acceptance"][field]
                line = self.assertRefused(self.edited(f"/specification/trial/{field}!", value),
                                          f"/specification/trial/{field}",
                                          f"/specification/force_law/acceptance/{field}")
                self.assertIn(str(law), line)

    def test_mode_value_without_guidance_is_a_contradiction_naming_the_field(self):
        document = self.edited("/specification/trial/guidance", False)
        set_at(document, "/specification/force_law/guidance", False)
        self.assertRefused(document, "/specification/trial/guidance_mode", "fading")

    def test_person_writing_with_a_writer_profile_is_refused_at_the_writer(self):
        self.assertRefused(self.edited("/specification/trial/writer", "person"), "/specification/trial/writer")

    def test_writer_setting_the_writer_lacks_is_refused_at_its_pointer(self):
        r = cg.simulate_trial("十", writer_params={"learning_rate": 0.3}, max_duration_s=0.2, keep_trace=False)
        document = {"specification": copy.deepcopy(r.metrics["specification"])}
        settings = document["specification"]["trial"]["writer_parameters"]
        self.assertEqual(len(settings), 1, settings)
        cg.check_trial_record(document)
        settings[0]["key"] = "learning_speed"
        name = self.write(document)
        self.assert_one_error(self.check(name), 2, f"{name}: /specification/trial/writer_parameters/0")

    def test_device_physics_on_another_device_is_refused_at_simulated_device(self):
        r = cg.simulate_trial("十", device=cg.SimulatedDeviceParameters(), max_duration_s=0.2, keep_trace=False)
        spec = copy.deepcopy(r.metrics["specification"])
        self.assertIsNotNone(spec["simulated_device"])
        cg.check_trial_record({"specification": spec})
        spec["trial"]["device"] = "emulated-phantom"
        self.assertRefused({"specification": spec}, "/specification/simulated_device")

    # ---- the same record through Python ------------------------------------------------------------------------
    def test_python_check_returns_the_specification_as_written(self):
        back = cg.check_trial_record(self.record)
        self.assertEqual(back, self.record["specification"])
        self.assertEqual(cg.check_trial_record({"specification": back}), back)
        self.assertEqual(cg.check_trial_record(str(self.tmp / "first.json")), back)

    def test_python_rerun_of_the_programs_record_is_the_same_trial(self):
        with warnings.catch_warnings():
            warnings.simplefilter("error", RuntimeWarning)
            again = cg.rerun_trial(str(self.tmp / "first.json"))
        self.assertEqual(set(again.metrics), set(self.record))
        self.assertEqual(again.metrics["specification"], self.record["specification"])
        for key in ("end_reason", "trial_time_s", "max_force_n", "max_force_step_n", "mean_deviation_m",
                    "strokes_completed", "renderer_strokes", "state_transitions"):
            self.assertEqual(again.metrics[key], self.record[key], key)
        rows = list(csv.DictReader(self.first_csv.decode().splitlines()))
        self.assertEqual(len(rows), len(again.time_s))
        xyz = np.array([[float(r["x"]), float(r["y"]), float(r["z"])] for r in rows])
        self.assertLessEqual(float(np.abs(xyz - again.position_m).max()), 0.5e-7 + 1e-12)

    def test_python_and_command_line_writer_setting_make_the_same_record(self):
        r = cg.simulate_trial("十", writer_params={"learning_rate": 0.3}, max_duration_s=0.5, keep_trace=False)
        result = self.cli("trial", "十", "--writer-param", "learning_rate=0.3", "--max-duration", "0.5",
                          "--json", "wp.json")
        self.assertIn(result.returncode, (0, 1), result.stderr.decode())
        cli = json.loads((self.tmp / "wp.json").read_text(encoding="utf-8"))
        self.assertEqual(r.metrics["writer_parameters"], cli["writer_parameters"])
        self.assertEqual(r.metrics["specification"]["trial"]["writer_parameters"],
                         cli["specification"]["trial"]["writer_parameters"])
        self.assertEqual(r.metrics["specification"], cli["specification"])


class Round32DReplay(unittest.TestCase, OneErrorLine):
    """A replay's record names its teacher and binds it by SHA-256."""

    @classmethod
    def setUpClass(cls):
        if cg is None:
            raise unittest.SkipTest("numpy and the calligraphy Python package (PYTHONPATH) are needed")
        cls.tmp = Path(tempfile.mkdtemp(prefix="round32d-replay-"))
        run_ok(["trial", "十", "--writer-profile", "skilled", "--max-duration", "30", "--record", "t.json"], cls.tmp)
        run(["trial", "十", "--guidance-mode", "replay", "--teacher", "t.json", "--max-duration", "2",
             "--json", "rp.json", "--csv", "rp.csv"], cls.tmp)
        cls.record = json.loads((cls.tmp / "rp.json").read_text(encoding="utf-8"))
        cls.teacher_bytes = (cls.tmp / "t.json").read_bytes()

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.tmp, ignore_errors=True)

    def cli(self, *args, cwd=None):
        return run(list(args), cwd or self.tmp)

    def test_replay_record_names_its_teacher_and_reruns_the_same(self):
        spec = self.record["specification"]
        self.assertEqual((spec["trial"]["guidance_mode"], spec["trial"]["teacher"]), ("replay", "t.json"))
        self.assertRegex(spec["teacher_sha256"], "^[0-9a-f]{64}$")
        result = self.cli("trial", "--spec", "rp.json", "--csv", "again.csv")
        self.assertEqual((self.tmp / "again.csv").read_bytes(), (self.tmp / "rp.csv").read_bytes(),
                         result.stderr.decode())

    def test_empty_teacher_sha256_on_a_replay_naming_its_file_is_refused(self):
        document = copy.deepcopy(self.record)
        document["specification"]["teacher_sha256"] = ""
        (self.tmp / "nosha.json").write_text(json.dumps(document), encoding="utf-8")
        self.assert_one_error(self.cli("trial", "--spec", "nosha.json", "--csv", "nosha.csv"), 2,
                              "nosha.json: /specification/teacher_sha256")
        self.assertFalse((self.tmp / "nosha.csv").exists())

    def test_edited_teacher_sha256_is_refused_naming_the_file_and_both_hashes(self):
        document = copy.deepcopy(self.record)
        sha = document["specification"]["teacher_sha256"]
        other = ("0" if sha[0] != "0" else "1") + sha[1:]
        document["specification"]["teacher_sha256"] = other
        (self.tmp / "othersha.json").write_text(json.dumps(document), encoding="utf-8")
        self.assert_one_error(self.cli("trial", "--spec", "othersha.json", "--csv", "othersha.csv"), 1,
                              "t.json", sha, other)
        self.assertFalse((self.tmp / "othersha.csv").exists())

    def test_rerun_from_another_folder_asks_for_the_teacher(self):
        elsewhere = self.tmp / "elsewhere"
        elsewhere.mkdir(exist_ok=True)
        result = self.cli("trial", "--spec", str(self.tmp / "rp.json"), cwd=elsewhere)
        self.assert_one_error(result, 1, "t.json", "--teacher")
        given = self.cli("trial", "--spec", str(self.tmp / "rp.json"), "--teacher", str(self.tmp / "t.json"),
                         "--csv", "given.csv", cwd=elsewhere)
        self.assertEqual((elsewhere / "given.csv").read_bytes(), (self.tmp / "rp.csv").read_bytes(),
                         given.stderr.decode())

    def test_teacher_given_to_a_record_that_is_no_replay_is_a_usage_error(self):
        plain = self.tmp / "plain"
        plain.mkdir(exist_ok=True)
        run(["trial", "十", "--max-duration", "0.2", "--json", "plain.json"], plain)
        self.assert_one_error(self.cli("trial", "--spec", "plain/plain.json", "--teacher", "t.json"), 2,
                              "--teacher")
        self.assertEqual((self.tmp / "t.json").read_bytes(), self.teacher_bytes)


if __name__ == "__main__":
    unittest.main()
