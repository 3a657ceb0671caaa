#!/usr/bin/env python3
"""Round 31B: trial records of every version the docs promise to read, and every way a record can be refused.
From the docs alone: docs/cli.md ("Re-running a trial", "The trial specification", `schema`, "Exit statuses",
"Pen traces: format and limits" on keys given twice), docs/experiments.md ("Trial records", "Sessions"),
docs/python.md ("Running a trial again", "Errors", "A study's traces") and `calligraphy schema record`.

A record written now by `trial 一 --json` with the values the older versions' rules fix (no miss at a
pen-down outside WS, no centred rule, no end gap, the fixed tolerances, no assisted credit) and one writer
setting is rewritten as each version 7 .. 1 (the fields the docs say each later version added removed,
`version` set, version 1's writer settings as "key=value" texts): each re-runs to the same trace byte for
byte, says in a note which fields it lacks, and `check_trial_record` gives each the values the docs state.
Then: versions outside 1..8 in every spelling, keys given twice, unknown keys at every level, `null` for each
value, every bounded number of `calligraphy schema record` just past its bound (and some at it), a scene's and
a teacher's SHA-256 that do not match, a replay whose teacher moved, a study's record of every study version
and with a refused specification as `report`, `curriculum` and `calligraphy.study.load` read it, a session
replay whose folder moved; Python (`check_trial_record`, `rerun_trial`) and the CLI naming the same pointer.

CALLIGRAPHY_CLI names the program; PYTHONPATH the built Python package. CALLIGRAPHY_SANITIZED=1 takes five cases.
"""
import copy
import hashlib
import json
import os
import re
import shutil
import tempfile
import unittest
import warnings
from pathlib import Path

from outsider import OneErrorLine, error_lines, run, run_ok, sanitized_subset

try:
    import calligraphy as cg
except ImportError:  # reported by setUpClass
    cg = None

load_tests = sanitized_subset({"test_version_values_outside_1_to_8_are_refused_naming_the_versions_read",
                               "test_key_given_twice_is_refused_naming_its_pointer",
                               "test_doc_examples_of_range_errors_read_as_documented",
                               "test_scene_sha256_of_other_characters_refuses_the_rerun_but_passes_check",
                               "test_teacher_edited_since_is_refused_naming_both_sha256"})

CHAR = "一"
SHORT = ["--max-duration", "5"]
# The values the older versions' rules fix, so that a record of every version states the same trial.
OLD_RULES = ["--miss-min-path", "0", "--centred-coverage-fraction", "0", "--end-gap", "0",
             "--reference-character-size", "0", "--shortfall-per-length", "0", "--deviation-per-length", "0",
             "--shortfall-cap", "0.1", "--mean-deviation-cap", "0.1", "--assist-after-misses", "0",
             "--writer-param", "bias_offset_m=0.004"]
CENTRED = ["centred_coverage_fraction", "centred_balance_fraction", "centred_min_length_m", "centred_max_length_m"]
GROWING = ["shortfall_per_length", "shortfall_cap_m", "deviation_per_length", "mean_deviation_cap_m",
           "reference_character_size_m", "hint_after_misses", "assist_after_misses"]
POINTER = re.compile(r"\.json: (/[^:\s]*):")


def older(spec, version):
    """A version-8 specification rewritten as `version` (docs/cli.md, "Re-running a trial")."""
    s = copy.deepcopy(spec)
    acc, trial = s["force_law"]["acceptance"], s["trial"]
    if version <= 7:
        for part in (acc, trial):
            part.pop("miss_min_path_m")
    if version <= 6:
        for part in (acc, trial):
            for k in CENTRED:
                part.pop(k)
    if version <= 5:  # the trial's specification did not state its acceptance
        for k in list(acc):
            trial.pop(k, None)
    if version <= 4:
        acc.pop("end_gap_m")
        acc.pop("end_gap_fraction")
    if version <= 3:
        for k in GROWING:
            acc.pop(k)
        s.pop("teacher_sha256")
    if version <= 2:
        trial.pop("guidance_stiffness_n_per_m")
    if version <= 1:
        trial["writer_parameters"] = [f"{w['key']}={w['value']!r}" for w in trial["writer_parameters"]]
    s["version"] = version
    return s


def get(doc, path):
    for p in path:
        doc = doc[p]
    return doc


def put(doc, path, value):
    get(doc, path[:-1])[path[-1]] = value


def pointer(path):
    return "/specification/" + "/".join(str(p) for p in path)


class Round31B(unittest.TestCase, OneErrorLine):
    @classmethod
    def setUpClass(cls):
        if cg is None:
            raise unittest.SkipTest("the calligraphy Python package (PYTHONPATH) is needed")
        cls.tmp = Path(tempfile.mkdtemp(prefix="round31b-"))
        d = cls.tmp
        run_ok(["trial", CHAR, *SHORT, *OLD_RULES, "--json", "base.json", "--csv", "base.csv"], d)
        cls.record = json.loads((d / "base.json").read_text(encoding="utf-8"))
        cls.spec = cls.record["specification"]
        cls.base_csv = (d / "base.csv").read_bytes()
        cls.schema = json.loads(run_ok(["schema", "record"], d).stdout)
        # A teacher and a replay of it.
        run_ok(["trial", CHAR, "--writer-profile", "skilled", "--max-duration", "10", "--record", "teacher.json"], d)
        run_ok(["trial", CHAR, *SHORT, "--guidance-mode", "replay", "--teacher", "teacher.json",
                "--json", "rp.json", "--csv", "rp.csv"], d)
        cls.replay = json.loads((d / "rp.json").read_text(encoding="utf-8"))
        # A study: a haptic trial and a replay of the teacher kept in the session folder.
        (d / "proto").mkdir()
        shutil.copy(d / "teacher.json", d / "proto" / "teacher.json")
        (d / "proto" / "p.json").write_text(json.dumps({
            "name": "p", "conditions": [{"name": "h", "mode": "haptic"},
                                        {"name": "r", "mode": "replay", "teachers": {CHAR: "teacher.json"}}],
            "test": {"characters": [CHAR], "conditions": ["h", "r"], "repetitions": 1},
            "trial": {"max_duration_s": 10}}), encoding="utf-8")
        run_ok(["session", "run", "proto/p.json", "--writer", "simulated", "--subjects", "1", "--device",
                "simulated", "--out", "study"], d)
        (cls.session,) = (d / "study" / "S01").iterdir()
        trials = sorted((cls.session / "trials").glob("*.json"))
        cls.study_h = next(t for t in trials if "-h-" in t.name).relative_to(d)
        cls.study_r = next(t for t in trials if "-r-" in t.name).relative_to(d)

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.tmp, ignore_errors=True)

    # -- helpers -------------------------------------------------------------------------------------------
    def write(self, name, doc=None, text=None):
        path = self.tmp / name
        path.write_text(text if text is not None else json.dumps(doc), encoding="utf-8")
        return path

    def with_spec(self, spec):
        r = copy.deepcopy(self.record)
        r["specification"] = spec
        return r

    def device_at_defaults(self):
        """A simulated device's physics at the schema's defaults, and the figures (`info`) it reports by default."""
        defs = self.schema["$defs"]
        physics = {k: v["default"] for k, v in defs["SimulatedDeviceParameters"]["properties"].items()
                   if k != "info"}
        info = cg.SimulatedDeviceParameters().info
        physics["info"] = {k: getattr(info, k) if isinstance(getattr(info, k), (str, float))
                           else [float(x) for x in getattr(info, k)] for k in defs["DeviceInfo"]["properties"]}
        return physics

    def py_refusal(self, path):
        """Python's check_trial_record of the file: the DataError's text."""
        with self.assertRaises(cg.DataError) as caught:
            cg.check_trial_record(str(path))
        return str(caught.exception)

    def assert_refused_alike(self, name, doc=None, text=None, pointers=(), status=2):
        """`trial --spec NAME --check` exits `status` in one line naming the file and one of `pointers`, and
        Python's check_trial_record raises DataError naming the same pointer. Returns the CLI's pointer."""
        path = self.write(name, doc, text)
        line = self.assert_one_error(run(["trial", "--spec", name, "--check"], self.tmp), status, name)
        got = POINTER.search(line)
        self.assertIsNotNone(got, line)
        self.assertIn(got.group(1), pointers, line)
        message = self.py_refusal(path)
        got_py = POINTER.search(message)
        self.assertIsNotNone(got_py, message)
        self.assertEqual(got_py.group(1), got.group(1), f"CLI: {line}\nPython: {message}")
        return line

    # -- every version read ----------------------------------------------------------------------------
    def test_each_older_version_reruns_to_the_same_trace_byte_for_byte(self):
        for version in range(7, 0, -1):
            with self.subTest(version=version):
                name = f"v{version}.json"
                self.write(name, self.with_spec(older(self.spec, version)))
                result = run(["trial", "--spec", name, "--csv", f"v{version}.csv"], self.tmp)
                text = result.stderr.decode("utf-8", "replace")
                self.assertEqual(result.returncode, 0, text)
                self.assertNotIn("warning", text)       # the run the record states is the run it gives
                self.assertEqual((self.tmp / f"v{version}.csv").read_bytes(), self.base_csv)

    def test_rerun_notes_name_the_fields_each_version_lacks(self):
        expected = {
            7: ["/specification/force_law/acceptance/miss_min_path_m is not in this earlier version of the "
                "record; it takes 0, as records of version 7 ran with 0",
                "/specification/trial/miss_min_path_m"],
            6: ["/specification/force_law/acceptance/centred_coverage_fraction is not in this earlier version of "
                "the record; it takes 0, as records of version 6 ran with 0",
                "/specification/force_law/acceptance/miss_min_path_m is not in this earlier version of the "
                "record; it takes 0, as records of version 6 ran with 0"],
            4: ["/specification/force_law/acceptance/end_gap_m is not in this earlier version of the record; it "
                "takes 0, as records of version 4 ran with 0"],
            3: ["/specification/force_law/acceptance/assist_after_misses is not in this earlier version of the "
                "record; it takes 0, as records of version 3 ran with 0"],
            2: ["/specification/trial/guidance_stiffness_n_per_m is not in this earlier version of the record; "
                "it takes its default"],
        }
        for version, needles in expected.items():
            with self.subTest(version=version):
                name = f"note{version}.json"
                self.write(name, self.with_spec(older(self.spec, version)))
                result = run_ok(["trial", "--spec", name], self.tmp)
                notes = [l for l in error_lines(result) if l.startswith("calligraphy trial: note: --spec " + name)]
                for needle in needles:
                    self.assertTrue(any(needle in l for l in notes), f"{needle!r} not in {notes!r}")

    def test_check_trial_record_gives_each_version_the_values_the_docs_state(self):
        for version in range(8, 0, -1):
            with self.subTest(version=version):
                back = cg.check_trial_record(self.with_spec(older(self.spec, version)))
                for part in (back["trial"], back["force_law"]["acceptance"]):
                    self.assertEqual(part["miss_min_path_m"], 0)
                    self.assertEqual(part["centred_coverage_fraction"], 0)
                    self.assertEqual(part["end_gap_m"], 0)
                    self.assertEqual(part["assist_after_misses"], 0)
                    self.assertEqual(part["hint_after_misses"], 3)
                    self.assertEqual(part["reference_character_size_m"], 0)
                    self.assertEqual(part["shortfall_per_length"], 0)
                    self.assertEqual(part["deviation_per_length"], 0)
                    self.assertEqual(part["shortfall_cap_m"], 0.1)
                    self.assertEqual(part["mean_deviation_cap_m"], 0.1)
                    if version <= 6:   # added in 7: the defaults of the schema
                        self.assertEqual(part["centred_balance_fraction"], 0.1)
                        self.assertEqual(part["centred_min_length_m"], 0.008)
                        self.assertEqual(part["centred_max_length_m"], 0.02)
                    if version <= 4:
                        self.assertEqual(part["end_gap_fraction"], 0.4)
                self.assertEqual(back["trial"]["guidance_stiffness_n_per_m"], 400)
                self.assertEqual(back["trial"]["writer_parameters"], [{"key": "bias_offset_m", "value": 0.004}])
                self.assertEqual(cg.check_trial_record(back), back)   # taken again as written back

    def test_python_rerun_of_each_version_gives_the_same_arrays_without_warning(self):
        with warnings.catch_warnings():
            warnings.simplefilter("error", RuntimeWarning)
            first = cg.rerun_trial(self.record)
            for version in range(7, 0, -1):
                with self.subTest(version=version):
                    again = cg.rerun_trial(self.with_spec(older(self.spec, version)))
                    self.assertEqual(again.position_m.shape, first.position_m.shape)
                    self.assertTrue((again.position_m == first.position_m).all())
                    self.assertTrue((again.force_n == first.force_n).all())

    def test_version4_record_giving_an_end_gap_takes_zero_and_says_so(self):
        spec = older(self.spec, 4)
        spec["force_law"]["acceptance"]["end_gap_m"] = 0.004
        self.write("gap4.json", self.with_spec(spec))
        result = run_ok(["trial", "--spec", "gap4.json", "--csv", "gap4.csv"], self.tmp)
        self.assertIn("/specification/force_law/acceptance/end_gap_m is 0.004 in the record, but records of "
                      "version 4 ran with 0; it takes 0", result.stderr.decode())
        self.assertEqual((self.tmp / "gap4.csv").read_bytes(), self.base_csv)
        back = cg.check_trial_record(spec)
        self.assertEqual(back["force_law"]["acceptance"]["end_gap_m"], 0)
        self.assertEqual(back["trial"]["end_gap_m"], 0)

    def test_version3_record_giving_growing_tolerances_and_credit_takes_the_fixed_ones(self):
        spec = older(self.spec, 3)
        spec["force_law"]["acceptance"].update(assist_after_misses=2, reference_character_size_m=0.06,
                                               shortfall_per_length=0.15, deviation_per_length=0.01,
                                               shortfall_cap_m=0.013, mean_deviation_cap_m=0.0032)
        back = cg.check_trial_record(spec)
        for part in (back["trial"], back["force_law"]["acceptance"]):
            self.assertEqual((part["assist_after_misses"], part["reference_character_size_m"],
                              part["shortfall_per_length"], part["deviation_per_length"],
                              part["shortfall_cap_m"], part["mean_deviation_cap_m"]), (0, 0, 0, 0, 0.1, 0.1))

    def test_version2_record_giving_a_guidance_stiffness_reads_it_as_given(self):
        spec = older(self.spec, 2)
        spec["trial"]["guidance_stiffness_n_per_m"] = 300.0
        spec["force_law"]["guidance_stiffness_n_per_m"] = 300.0
        self.assertEqual(cg.check_trial_record(spec)["trial"]["guidance_stiffness_n_per_m"], 300.0)
        self.write("k2.json", spec)
        run_ok(["trial", "--spec", "k2.json", "--check"], self.tmp)

    def test_version5_takes_the_acceptance_its_force_law_ran_with(self):
        spec = older(self.spec, 5)
        spec["force_law"]["acceptance"].update(hint_after_misses=4, corridor_m=0.005)
        back = cg.check_trial_record(spec)
        self.assertEqual(back["trial"]["hint_after_misses"], 4)
        self.assertEqual(back["trial"]["corridor_m"], 0.005)
        # The same fields given (as version 6 added them), equal to the force law's: read as given.
        given = copy.deepcopy(spec)
        given["trial"].update({k: v for k, v in given["force_law"]["acceptance"].items()})
        self.write("given5.json", given)
        run_ok(["trial", "--spec", "given5.json", "--check"], self.tmp)

    def test_acceptance_differing_from_the_force_laws_is_refused_at_the_trial_field(self):
        for version in (6, 8):
            with self.subTest(version=version):
                spec = older(self.spec, version)
                spec["trial"]["corridor_m"] = 0.005
                line = self.assert_refused_alike(f"corr{version}.json", self.with_spec(spec),
                                                 pointers=("/specification/trial/corridor_m",))
                self.assertIn("/specification/force_law/acceptance/corridor_m", line)
                self.assertIn("0.0065", line)

    def test_writer_settings_as_text_in_a_version8_record_are_refused(self):
        spec = copy.deepcopy(self.spec)
        spec["trial"]["writer_parameters"] = ["bias_offset_m=0.004"]
        self.assert_refused_alike("text8.json", self.with_spec(spec),
                                  pointers=("/specification/trial/writer_parameters/0",
                                            "/specification/trial/writer_parameters"))

    def test_writer_setting_of_an_unknown_key_is_refused_at_its_pointer_in_versions_1_and_8(self):
        for version in (1, 8):
            with self.subTest(version=version):
                spec = older(self.spec, 8)
                spec["trial"]["writer_parameters"] = [{"key": "no_such_setting", "value": 1.0}]
                spec = older(spec, version) if version < 8 else spec
                self.assert_refused_alike(f"wkey{version}.json", self.with_spec(spec),
                                          pointers=("/specification/trial/writer_parameters/0",
                                                    "/specification/trial/writer_parameters/0/key"))

    # -- the version itself ---------------------------------------------------------------------------
    def test_version_values_outside_1_to_9_are_refused_naming_the_versions_read(self):
        text = json.dumps(self.with_spec({**self.spec, "version": "VERSION"}))
        for value in ("10", '"9"', "null", "-1", "7.5", "8.5", "0", "true", "1e999", "[8]", "18446744073709551624"):
            with self.subTest(version=value):
                line = self.assert_refused_alike("ver.json", text=text.replace('"VERSION"', value),
                                                 pointers=("/specification/version",))
                self.assertIn("1 to 9", line)

    def test_version_spelt_as_a_whole_number_reads_as_that_version(self):
        text = json.dumps(self.with_spec({**older(self.spec, 7), "version": "VERSION"}))
        for value in ("7.0", "7e0", "70E-1", "7.000"):
            with self.subTest(version=value):
                path = self.write("v7spelt.json", text=text.replace('"VERSION"', value))
                run_ok(["trial", "--spec", "v7spelt.json", "--check"], self.tmp)
                self.assertEqual(cg.check_trial_record(str(path))["trial"]["miss_min_path_m"], 0)

    def test_version_or_format_missing_or_other_is_refused(self):
        for key, value, where in (("version", None, "/specification/version"),
                                  ("format", None, "/specification/format"),
                                  ("format", "calligraphy-study-trial", "/specification/format")):
            with self.subTest(key=key, value=value):
                spec = copy.deepcopy(self.spec)
                if value is None:
                    del spec[key]
                else:
                    spec[key] = value
                self.assert_refused_alike("fv.json", self.with_spec(spec), pointers=(where, "/specification"))

    def test_record_without_a_specification_is_refused_saying_so(self):
        r = copy.deepcopy(self.record)
        del r["specification"]
        self.write("nospec.json", r)
        self.assert_one_error(run(["trial", "--spec", "nospec.json", "--check"], self.tmp), 2, "nospec.json",
                              "no trial specification")
        with self.assertRaises(cg.DataError):
            cg.check_trial_record(r)

    # -- the JSON itself --------------------------------------------------------------------------------
    def test_key_given_twice_is_refused_naming_its_pointer(self):
        for path in (("trial", "seed"), ("version",), ("force_law", "acceptance", "corridor_m"),
                     ("scene", "layout", "character_size_m")):
            with self.subTest(key="/".join(path)):
                spec = copy.deepcopy(self.spec)
                value = get(spec, path)
                parent = get(spec, path[:-1])
                del parent[path[-1]]
                parent["TWICE"] = value
                text = json.dumps(self.with_spec(spec)).replace(
                    '"TWICE": ' + json.dumps(value), f'"{path[-1]}": {json.dumps(value)}, "{path[-1]}": '
                    + json.dumps(value))
                line = self.assert_refused_alike("twice.json", text=text, pointers=(pointer(path),))
                self.assertIn("given twice", line)

    def test_unknown_key_at_every_level_is_refused_naming_it(self):
        levels = [(), ("trial",), ("force_law",), ("force_law", "acceptance"), ("force_law", "nearest"),
                  ("force_law", "guidance_law"), ("safety",), ("passivity",), ("writer",), ("scene",),
                  ("scene", "layout"), ("trial", "writer_parameters", 0)]
        for level in levels:
            with self.subTest(level="/".join(map(str, level))):
                spec = copy.deepcopy(self.spec)
                get(spec, level)["bogus_key"] = 1
                pointers = (pointer((*level, "bogus_key")),)
                if level == ("force_law", "guidance_law"):   # one of the modes' objects (oneOf)
                    pointers += (pointer(level),)
                self.assert_refused_alike("unknown.json", self.with_spec(spec), pointers=pointers)

    def test_another_modes_value_under_the_guidance_law_is_refused(self):
        spec = copy.deepcopy(self.spec)
        spec["force_law"]["guidance_law"]["gain"] = 0.5   # fading's, under "fixed"
        self.assert_refused_alike("law.json", self.with_spec(spec),
                                  pointers=("/specification/force_law/guidance_law/gain",
                                            "/specification/force_law/guidance_law"))

    def test_null_for_each_value_is_refused_at_its_pointer_in_python(self):
        leaves = []

        def walk(doc, path):
            if isinstance(doc, dict):
                for k, v in doc.items():
                    walk(v, (*path, k))
            elif isinstance(doc, list) and doc:
                for i, v in enumerate(doc):
                    walk(v, (*path, i))
            if path and path not in (("writer",), ("simulated_device",)):
                leaves.append(path)
        walk(self.spec, ())
        self.assertGreater(len(leaves), 150)
        for path in leaves:
            with self.subTest(pointer=pointer(path)):
                spec = copy.deepcopy(self.spec)
                put(spec, path, None)
                with self.assertRaises(cg.DataError) as caught:
                    cg.check_trial_record(self.with_spec(spec))
                if path[:2] == ("force_law", "guidance_law"):   # one of the modes' objects (oneOf) by its mode
                    self.assertIn(pointer(path[:2]), str(caught.exception))
                else:
                    self.assertIn(pointer(path), str(caught.exception))

    def test_null_for_a_value_is_refused_alike_by_the_cli(self):
        for path in (("trial", "seed"), ("force_law", "crossfade_s"), ("force_law", "acceptance", "end_gap_m"),
                     ("scene", "sha256"), ("library_version",), ("teacher_sha256",), ("passivity",)):
            with self.subTest(pointer=pointer(path)):
                spec = copy.deepcopy(self.spec)
                put(spec, path, None)
                pointers = (pointer(path),)
                if path[-1] == "end_gap_m":
                    pointers += ("/specification/trial/end_gap_m",)
                self.assert_refused_alike("null.json", self.with_spec(spec), pointers=pointers)

    # -- the ranges of `calligraphy schema record` ------------------------------------------------------
    def bounded(self):
        """(path, bad values) of every bounded number of the schema's parts."""
        defs = self.schema["$defs"]

        def ref(prop):
            for p in [prop, *prop.get("anyOf", [])]:
                if "$ref" in p:
                    return defs[p["$ref"].rsplit("/", 1)[1]]
            return None

        def past(prop, integer):
            bad = []
            step = (lambda m: 1) if integer else (lambda m: max(abs(m) * 1e-6, 1e-9))
            if "minimum" in prop and abs(prop["minimum"]) < 1e300:
                bad.append(prop["minimum"] - step(prop["minimum"]))
            if "exclusiveMinimum" in prop:
                bad.append(prop["exclusiveMinimum"])
            if "maximum" in prop and abs(prop["maximum"]) < 1e300:
                bad.append(prop["maximum"] + step(prop["maximum"]))
            if "exclusiveMaximum" in prop:
                bad.append(prop["exclusiveMaximum"])
            return bad

        found = []

        def walk(definition, path):
            for key, prop in definition.get("properties", {}).items():
                sub = ref(prop)
                if sub is not None:
                    walk(sub, (*path, key))
                elif prop.get("type") in ("number", "integer"):
                    found.append(((*path, key), past(prop, prop["type"] == "integer")))
                elif prop.get("type") == "array" and prop.get("items", {}).get("type") == "number":
                    found.append(((*path, key, 0), past(prop["items"], False)))
        walk(self.schema, ())
        return [(p, bad) for p, bad in found if bad]

    def test_every_bounded_number_just_past_its_bound_is_refused_at_its_pointer(self):
        spec0 = copy.deepcopy(self.spec)
        spec0["simulated_device"] = self.device_at_defaults()
        cg.check_trial_record(spec0)   # the physics of the simulated device, at its defaults, are read
        acceptance = set(spec0["force_law"]["acceptance"])
        fields = self.bounded()
        self.assertGreater(len(fields), 100)
        for path, bad in fields:
            for value in bad:
                with self.subTest(pointer=pointer(path), value=value):
                    spec = copy.deepcopy(spec0)
                    put(spec, path, value)
                    pointers = {pointer(path)}
                    twin = None
                    if path[0] == "trial" and path[1] in acceptance:
                        twin = ("force_law", "acceptance", path[1])
                    elif path[:2] == ("force_law", "acceptance"):
                        twin = ("trial", path[2])
                    elif path in (("trial", "guidance_stiffness_n_per_m"), ("force_law", "guidance_stiffness_n_per_m")):
                        twin = ("force_law" if path[0] == "trial" else "trial", path[1])
                    if twin is not None:
                        put(spec, twin, value)
                        pointers.add(pointer(twin))
                    with self.assertRaises(cg.DataError) as caught:
                        cg.check_trial_record(self.with_spec(spec))
                    got = re.search(r": (/specification/[^:\s]*):", str(caught.exception))
                    self.assertIsNotNone(got, str(caught.exception))
                    self.assertIn(got.group(1), pointers, str(caught.exception))

    def test_numbers_at_their_bounds_are_read(self):
        cases = [((("trial", "seed"),), 2 ** 64 - 1), ((("trial", "seed"),), 0),
                 ((("force_law", "crossfade_s"),), 10.0), ((("force_law", "crossfade_s"),), 0.0),
                 ((("safety", "max_force_n"),), 100.0), ((("force_law", "nearest", "newton_starts"),), 1000),
                 ((("force_law", "nearest", "newton_iterations"),), 1),
                 ((("safety", "continuous_time_constant_s"),), 86400.0),
                 ((("force_law", "nearest", "tolerance"),), 0.001),
                 ((("scene", "layout", "box_margin_m"),), 0.1), ((("scene", "layout", "centre_m"),), [1.0, -1.0]),
                 ((("trial", "hint_after_misses"), ("force_law", "acceptance", "hint_after_misses")), 1000),
                 ((("trial", "max_gain_ratio"), ("force_law", "acceptance", "max_gain_ratio")), 100.0),
                 ((("trial", "corridor_m"), ("force_law", "acceptance", "corridor_m")), 0.1)]
        for paths, value in cases:
            with self.subTest(pointer=pointer(paths[0]), value=value):
                spec = copy.deepcopy(self.spec)
                for path in paths:
                    put(spec, path, value)
                back = cg.check_trial_record(spec)
                self.assertEqual(get(back, paths[0]), value)
        spec = copy.deepcopy(self.spec)
        spec["trial"].update(max_duration_s=86400.0, rate_hz=100.0)   # 8,640,000 ticks: within 10^7
        self.write("long.json", self.with_spec(spec))
        run_ok(["trial", "--spec", "long.json", "--check"], self.tmp)
        spec["trial"]["rate_hz"] = 1000.0                                # 86,400,000 ticks
        line = self.assert_refused_alike("toolong.json", self.with_spec(spec),
                                         pointers=("/specification/trial/max_duration_s",
                                                   "/specification/trial/rate_hz"))
        self.assertIn("max_duration_s", line)

    def test_doc_examples_of_range_errors_read_as_documented(self):
        spec = copy.deepcopy(self.spec)
        spec["force_law"]["crossfade_s"] = -1.0
        line = self.assert_refused_alike("r.json", self.with_spec(spec),
                                         pointers=("/specification/force_law/crossfade_s",))
        self.assertIn("r.json: /specification/force_law/crossfade_s: expected a number in [0, 10] s "
                      "(ForceLawParameters.crossfade_s), got -1.0", line)
        spec = copy.deepcopy(self.spec)
        spec["trial"]["guidance_gain"] = 1.5
        line = self.assert_refused_alike("r.json", self.with_spec(spec),
                                         pointers=("/specification/trial/guidance_gain",))
        self.assertIn("r.json: /specification/trial/guidance_gain: expected a number in [0, 1] "
                      "(TrialSpec.guidance_gain), got 1.5", line)

    def test_seed_with_an_exponent_at_or_past_2_53_is_refused_and_below_read(self):
        text = json.dumps(self.record).replace('"seed": 0, "shortfall_cap_m"', '"seed": SEED, "shortfall_cap_m"')
        self.assertIn("SEED", text)
        line = self.assert_refused_alike("seed.json", text=text.replace("SEED", "1.23456789012346e+16"),
                                         pointers=("/specification/trial/seed",))
        self.assertIn("seed.json", line)
        path = self.write("seed7.json", text=text.replace("SEED", "7e0"))
        self.assertEqual(cg.check_trial_record(str(path))["trial"]["seed"], 7)

    def test_person_with_a_profile_and_physics_on_another_device_are_refused_at_their_pointers(self):
        spec = copy.deepcopy(self.spec)
        spec["trial"]["writer"] = "person"
        spec["trial"]["writer_parameters"] = []   # the profile alone (`writer`) left on a person's trial
        self.assert_refused_alike("person.json", self.with_spec(spec), pointers=("/specification/trial/writer",))
        spec = copy.deepcopy(self.spec)
        spec["simulated_device"] = self.device_at_defaults()
        spec["trial"]["device"] = "no-such-device"
        self.assert_refused_alike("physics.json", self.with_spec(spec), pointers=("/specification/simulated_device",))

    # -- SHA-256s -----------------------------------------------------------------------------------------
    def test_scene_sha256_of_other_characters_refuses_the_rerun_but_passes_check(self):
        spec = copy.deepcopy(self.spec)
        spec["scene"]["sha256"] = hashlib.sha256(b"other characters").hexdigest()
        path = self.write("scene.json", self.with_spec(spec))
        run_ok(["trial", "--spec", "scene.json", "--check"], self.tmp)   # no character is read
        self.assert_one_error(run(["trial", "--spec", "scene.json", "--csv", "scene.csv"], self.tmp), 1,
                              "scene.json")
        self.assertFalse((self.tmp / "scene.csv").exists())
        with self.assertRaises(cg.InvalidArgument):
            cg.rerun_trial(str(path))
        spec["scene"]["sha256"] = self.spec["scene"]["sha256"].upper()
        self.assert_refused_alike("upper.json", self.with_spec(spec), pointers=("/specification/scene/sha256",))

    def test_replay_reruns_from_its_folder_to_the_same_trace(self):
        run_ok(["trial", "--spec", "rp.json", "--csv", "rp-again.csv"], self.tmp)
        self.assertEqual((self.tmp / "rp-again.csv").read_bytes(), (self.tmp / "rp.csv").read_bytes())

    def test_replay_whose_teacher_moved_is_refused_until_given_teacher(self):
        away = self.tmp / "away"
        away.mkdir(exist_ok=True)
        shutil.copy(self.tmp / "rp.json", away / "rp.json")
        self.assert_one_error(run(["trial", "--spec", "rp.json", "--csv", "x.csv"], away), 1, "teacher.json",
                              "no such file", "--teacher")
        self.assertFalse((away / "x.csv").exists())
        run_ok(["trial", "--spec", "rp.json", "--teacher", "../teacher.json", "--csv", "x.csv"], away)
        self.assertEqual((away / "x.csv").read_bytes(), (self.tmp / "rp.csv").read_bytes())
        with self.assertRaises(cg.DataError) as caught:   # the test's working folder holds no teacher.json
            cg.rerun_trial(str(away / "rp.json"))
        self.assertIn("teacher.json", str(caught.exception))
        self.assertIn("teacher=", str(caught.exception))

    def test_teacher_edited_since_is_refused_naming_both_sha256(self):
        edited = self.tmp / "edited-teacher.json"
        edited.write_bytes((self.tmp / "teacher.json").read_bytes() + b"\n")
        want = hashlib.sha256((self.tmp / "teacher.json").read_bytes()).hexdigest()
        have = hashlib.sha256(edited.read_bytes()).hexdigest()
        self.assertEqual(self.replay["specification"]["teacher_sha256"], want)
        line = self.assert_one_error(run(["trial", "--spec", "rp.json", "--teacher", edited.name, "--csv",
                                          "e.csv"], self.tmp), 1, edited.name, want, have)
        self.assertFalse((self.tmp / "e.csv").exists(), line)
        r = copy.deepcopy(self.replay)
        r["specification"]["trial"]["teacher"] = str(edited)
        self.write("rp-edited.json", r)
        self.assert_one_error(run(["trial", "--spec", "rp-edited.json"], self.tmp), 1, edited.name, want, have)
        with self.assertRaises(cg.DataError) as caught:
            cg.rerun_trial(r)
        self.assertIn(want, str(caught.exception))
        self.assertIn(have, str(caught.exception))

    def test_replay_teacher_sha256_empty_missing_or_uppercase_is_refused_from_version_4(self):
        for version in (4, 8):
            for value in ("", None, self.replay["specification"]["teacher_sha256"].upper()):
                with self.subTest(version=version, value=value):
                    spec = older(self.replay["specification"], version)
                    if value is None:
                        del spec["teacher_sha256"]
                    else:
                        spec["teacher_sha256"] = value
                    self.assert_refused_alike("tsha.json", self.with_spec(spec),
                                              pointers=("/specification/teacher_sha256",))
        spec = older(self.replay["specification"], 3)        # before teacher_sha256: read
        self.write("rp3.json", spec)
        run_ok(["trial", "--spec", "rp3.json", "--check"], self.tmp)

    # -- a study's records -----------------------------------------------------------------------------
    def study_copy(self, name):
        dest = self.tmp / name
        shutil.rmtree(dest, ignore_errors=True)
        shutil.copytree(self.tmp / "study", dest, symlinks=True)
        return dest, dest / self.study_h.relative_to("study"), dest / self.study_r.relative_to("study")

    def test_study_record_of_each_study_version_is_read_and_others_refused(self):
        rec = json.loads((self.tmp / self.study_h).read_text(encoding="utf-8"))
        run_ok(["trial", "--spec", str(self.study_h), "--check"], self.tmp)
        cg.check_trial_record(str(self.tmp / self.study_h))
        for version in (2, 3):
            with self.subTest(version=version):
                self.write("study-v.json", {**rec, "version": version})
                run_ok(["trial", "--spec", "study-v.json", "--check"], self.tmp)
        for key, value in (("version", 4), ("version", 0), ("version", "3"), ("version", 2.5), ("version", None),
                           ("format", "calligraphy-trial-specification")):
            with self.subTest(key=key, value=value):
                self.assert_refused_alike("study-bad.json", {**rec, key: value}, pointers=("/" + key,))

    def test_study_record_of_version_1_counts_block_and_item_from_0(self):
        dest, rec_path, _ = self.study_copy("study-v1")
        (self.tmp / "t-now").mkdir(exist_ok=True)
        (self.tmp / "t-v1").mkdir(exist_ok=True)
        run_ok(["report", str(self.tmp / "study"), "--csv", "t-now"], self.tmp)
        rec = json.loads(rec_path.read_text(encoding="utf-8"))
        rec["version"] = 1
        rec["trial"]["block"] -= 1
        rec["trial"]["item"] -= 1
        rec_path.write_text(json.dumps(rec), encoding="utf-8")
        run_ok(["report", "study-v1", "--csv", "t-v1"], self.tmp)
        now = (self.tmp / "t-now" / "trials.csv").read_text(encoding="utf-8").replace(str(self.tmp / "study"), "S")
        v1 = (self.tmp / "t-v1" / "trials.csv").read_text(encoding="utf-8").replace("study-v1", "S")
        self.assertEqual(v1, now)

    def test_study_record_with_an_older_specification_is_read_by_report(self):
        dest, rec_path, _ = self.study_copy("study-old")
        rec = json.loads(rec_path.read_text(encoding="utf-8"))
        rec["specification"] = older(rec["specification"], 5)
        kept = rec["specification"]["force_law"]["acceptance"]   # the summary of a record of that time
        rec["force_law"]["acceptance"] = {k: v for k, v in rec["force_law"]["acceptance"].items() if k in kept}
        rec_path.write_text(json.dumps(rec), encoding="utf-8")
        (self.tmp / "t-old").mkdir(exist_ok=True)
        run_ok(["report", "study-old", "--csv", "t-old"], self.tmp)
        run_ok(["trial", "--spec", str(rec_path.relative_to(self.tmp)), "--check"], self.tmp)

    def test_study_record_whose_specification_is_refused_is_damaged_data_for_every_reader(self):
        dest, rec_path, _ = self.study_copy("study-bad")
        rec = json.loads(rec_path.read_text(encoding="utf-8"))
        rec["specification"]["force_law"]["crossfade_s"] = -1.0
        rec_path.write_text(json.dumps(rec), encoding="utf-8")
        where = "/specification/force_law/crossfade_s"
        tables = self.tmp / "t-bad"
        tables.mkdir(exist_ok=True)
        self.assert_one_error(run(["report", "study-bad", "--csv", "t-bad"], self.tmp), 1, rec_path.name, where)
        self.assertEqual(list(tables.iterdir()), [])
        self.assert_one_error(run(["curriculum", "study-bad", "--subject", "S01", "--from", "十"], self.tmp), 1,
                              rec_path.name, where)
        self.assert_one_error(run(["trial", "--spec", str(rec_path.relative_to(self.tmp)), "--check"], self.tmp),
                              2, rec_path.name, where)
        import calligraphy.study
        with self.assertRaises(cg.DataError) as caught:
            calligraphy.study.load(str(dest))
        self.assertIn(rec_path.name, str(caught.exception))
        self.assertIn(where, str(caught.exception))

    def test_study_record_with_a_key_given_twice_is_damaged_data_for_report(self):
        dest, rec_path, _ = self.study_copy("study-twice")
        text = rec_path.read_text(encoding="utf-8")
        rec = json.loads(text)
        rec["specification"]["trial"]["TWICE"] = rec["specification"]["trial"].pop("guidance_mode")
        rec_path.write_text(json.dumps(rec).replace('"TWICE": "fixed"', '"guidance_mode": "fixed", '
                                                    '"guidance_mode": "fixed"'), encoding="utf-8")
        self.assertIn('"guidance_mode": "fixed", "guidance_mode"', rec_path.read_text(encoding="utf-8"))
        (self.tmp / "t-twice").mkdir(exist_ok=True)
        self.assert_one_error(run(["report", "study-twice", "--csv", "t-twice"], self.tmp), 1, rec_path.name,
                              "/specification/trial/guidance_mode", "given twice")

    def test_study_trace_not_the_one_its_record_names_is_refused_naming_both_sha256(self):
        dest, rec_path, _ = self.study_copy("study-trace")
        rec = json.loads(rec_path.read_text(encoding="utf-8"))
        trace = rec_path.parent / rec["files"]["trace"]
        actual = hashlib.sha256(trace.read_bytes()).hexdigest()
        self.assertEqual(rec["files"]["trace_sha256"], actual)
        stated = hashlib.sha256(b"another trace").hexdigest()
        rec["files"]["trace_sha256"] = stated
        rec_path.write_text(json.dumps(rec), encoding="utf-8")
        self.assert_one_error(run(["report", "study-trace", "--out", "trace.html"], self.tmp), 1, trace.name,
                              stated, actual)
        import calligraphy.study
        study = calligraphy.study.load(str(dest))
        row = next(i for i, t in study.trials.iterrows() if t["condition"] == "h")
        with self.assertRaises(cg.DataError) as caught:
            study.samples(row)
        self.assertIn(stated, str(caught.exception))
        self.assertIn(actual, str(caught.exception))

    def test_session_replay_reruns_from_its_moved_folder_and_refuses_its_teacher_removed(self):
        run_ok(["trial", "--spec", str(self.study_r), "--csv", "sr-here.csv"], self.tmp)
        dest, _, rec_r = self.study_copy("study-moved")
        elsewhere = self.tmp / "elsewhere"
        elsewhere.mkdir(exist_ok=True)
        run_ok(["trial", "--spec", str(rec_r), "--csv", "sr-moved.csv"], elsewhere)
        self.assertEqual((elsewhere / "sr-moved.csv").read_bytes(), (self.tmp / "sr-here.csv").read_bytes())
        teachers = list((rec_r.parent.parent / "teachers").iterdir())
        self.assertEqual(len(teachers), 1)
        teachers[0].unlink()
        self.assert_one_error(run(["trial", "--spec", str(rec_r), "--csv", "sr-gone.csv"], elsewhere), 1,
                              teachers[0].name)
        self.assertFalse((elsewhere / "sr-gone.csv").exists())
        with self.assertRaises(cg.DataError) as caught:
            cg.rerun_trial(str(rec_r))
        self.assertIn(teachers[0].name, str(caught.exception))


if __name__ == "__main__":
    unittest.main()
