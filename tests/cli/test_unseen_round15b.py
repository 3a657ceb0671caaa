#!/usr/bin/env python3
"""Round 15B: hostile cases written from the documentation alone (docs/cli.md, docs/experiments.md,
docs/stroke-acceptance.md, docs/force-rendering.md, docs/python.md, docs/corpus.md, `calligraphy schema ...`
and each command's `--help`) on every file format the program writes and reads, across its versions. Run by
CTest as `cli_unseen_round15b_tests`.

Trial records of each older version (1-6) built by hand from what the docs say each lacked or spelt otherwise
(`"key=value"` writer settings, no guidance stiffness, no miss counts, fixed tolerances and no teacher SHA-256,
no end-gap floor, no acceptance in the specification, no centred rule), run again with `trial --spec` and read by
Python's `check_trial_record`: what each runs with, and every note on standard error true of the value taken;
versions newer than this program's and of other spellings (9, 2^40, "7", null, -1, true, 7.5, 2^64, 0,
none); an older record given a field only later versions have, a current one lacking one. Round trips: a record
run again is the record and its trace byte for byte, a study trial record's specification gives its saved
trace, a record Python wrote read by the CLI and the reverse, a teacher recording recorded twice, by the CLI
and by Python and saved again, a protocol through `session plan` and through its copy in session.json, a
corpus store built twice and on one or two threads. Teachers, protocols, session.json (1-3: block and item from
0 in version 1, `human` for `person` in 1-2), the study's trial records (1-3), the study identity and corpus
stores (major 1, any minor) of other versions; `session resume` of a version-1 folder.

Each case asserts what the documentation promises: the exit status, one error line naming the file, the JSON
pointer (or offset) and the version this program reads, nothing written when refused.
CALLIGRAPHY_CLI names the program, CALLIGRAPHY_SOURCE_DIR the source tree (its hanzi-writer-data sample).
CALLIGRAPHY_SANITIZED=1 takes five cases.
"""
import copy
import csv
import glob
import json
import os
import shutil
import struct
import tempfile
import unittest
import zlib
from pathlib import Path

from outsider import OneErrorLine, error_lines, run, sanitized_subset

SOURCE = Path(os.environ.get("CALLIGRAPHY_SOURCE_DIR", Path(__file__).resolve().parents[2]))
SAMPLE = SOURCE / "data" / "hanzi-writer-data"
YI, SHI = "一", "十"
SPEC_VERSION = 9  # docs/cli.md: `calligraphy-trial-specification`, version 9

load_tests = sanitized_subset({"test_record_run_again_is_the_record_byte_for_byte",
                               "test_version_4_record_runs_without_the_end_gap_floor",
                               "test_a_newer_version_is_refused_naming_the_versions_read",
                               "test_session_version_1_counts_from_zero_and_is_read_from_one",
                               "test_store_of_another_major_version_is_refused"})

# The acceptance's fields as docs/stroke-acceptance.md lists them, grouped by the version that added them.
CENTRED = ("centred_coverage_fraction", "centred_balance_fraction", "centred_min_length_m", "centred_max_length_m")
END_GAP = ("end_gap_m", "end_gap_fraction")
GROWTH = ("shortfall_per_length", "shortfall_cap_m", "deviation_per_length", "mean_deviation_cap_m",
          "reference_character_size_m")
CREDIT = ("hint_after_misses", "assist_after_misses")

SHARED = {}

try:
    import calligraphy as cg
except ImportError:  # pragma: no cover - the Python cases are skipped, saying why
    cg = None


def need_python(case):
    if cg is None:
        case.skipTest("the calligraphy Python module is not built (CALLIGRAPHY_BUILD_PYTHON=OFF)")


def setUpModule():
    shared = Path(tempfile.mkdtemp(prefix="round15b-"))
    SHARED["dir"] = shared
    # One trial of 一 that writes its stroke (4 s is enough for the novice), and one with a writer setting.
    for name, extra in (("one", []), ("param", ["--writer-param", "writing_speed_m_s=0.03"])):
        made = run(["trial", YI, "--max-duration", "4", "--seed", "1", *extra, "--json", f"{name}.json", "--csv",
                    f"{name}.csv"], shared)
        assert made.returncode == 0, made.stderr.decode()
    # A teacher recorded by the skilled writer, and a tiny study of two trials of 一.
    made = run(["trial", YI, "--max-duration", "4", "--seed", "1", "--writer-profile", "skilled", "--record",
                "teacher.json"], shared)
    assert made.returncode == 0, made.stderr.decode()
    protocol = {"format": "calligraphy-study-protocol", "version": 1, "name": "tiny",
                "conditions": [{"name": "h", "mode": "haptic"}],
                "test": {"characters": [YI], "conditions": ["h"], "repetitions": 2},
                "trial": {"max_duration_s": 4}}
    (shared / "protocol.json").write_text(json.dumps(protocol, ensure_ascii=False), encoding="utf-8")
    made = run(["session", "run", "protocol.json", "--out", "study", "--subjects", "1"], shared)
    assert made.returncode == 0, made.stderr.decode()
    # A store of 十 from the sample.
    (shared / "hw").mkdir()
    shutil.copy(SAMPLE / f"{SHI}.json", shared / "hw")
    made = run(["corpus", "build", "--data", "hw", "--out", "store.clg", "--threads", "1"], shared)
    assert made.returncode == 0, made.stderr.decode()


def tearDownModule():
    if "dir" in SHARED:
        shutil.rmtree(SHARED["dir"], ignore_errors=True)


def record():
    """The whole `trial --json` document of 一 (version 9)."""
    return json.loads((SHARED["dir"] / "one.json").read_text(encoding="utf-8"))


def older(version, document=None):
    """A version-`version` record made by hand from a version-9 one, from what docs/cli.md and
    docs/stroke-acceptance.md say each earlier version lacked or spelt otherwise."""
    whole = copy.deepcopy(document if document is not None else record())
    spec = whole["specification"]
    spec["version"] = version
    trial, acceptance = spec["trial"], spec["force_law"]["acceptance"]
    if version < 9 and spec["simulated_device"]:  # version 8: a simulated device's figures were not stated
        del spec["simulated_device"]["info"]
    if version < 8:  # version 7: written before a pen-down off the stroke's start counted as a miss
        del trial["miss_min_path_m"], acceptance["miss_min_path_m"]
    if version < 7:  # version 6: written before the centred rule and the three fields after it
        for key in CENTRED:
            del trial[key], acceptance[key]
    if version < 6:  # version 5: the specification did not state its acceptance; its force law did
        for key in list(acceptance):
            trial.pop(key, None)
    if version < 5:  # version 4: no floor under the end gap
        for key in END_GAP:
            del acceptance[key]
    if version < 4:  # version 3: fixed tolerances, no hint or assisted credit, no teacher's SHA-256
        for key in GROWTH + CREDIT:
            del acceptance[key]
        del spec["teacher_sha256"]
    if version < 3:  # version 2: written before the trial stated its guidance stiffness
        del trial["guidance_stiffness_n_per_m"]
    if version < 2:  # version 1: the writer's settings were "key=value" strings
        trial["writer_parameters"] = [f"{p['key']}={p['value']!r}" for p in trial["writer_parameters"]]
    return whole


def pointers_absent(whole):
    """The JSON pointers of the version-7 fields a forged older record lacks."""
    spec = whole["specification"]
    current = record()["specification"]
    absent = []
    for part in ("trial",):
        absent += [f"/specification/{part}/{k}" for k in current[part] if k not in spec[part]]
    absent += [f"/specification/force_law/acceptance/{k}" for k in current["force_law"]["acceptance"]
               if k not in spec["force_law"]["acceptance"]]
    absent += [f"/specification/{k}" for k in current if k not in spec]
    return absent


def value_at(spec, pointer):
    node = {"specification": spec}
    for part in pointer.strip("/").split("/"):
        node = node[part]
    return node


def notes(result, name):
    """{pointer: the rest of its line} of `trial --spec`'s notes about `name`."""
    found = {}
    prefix = f"note: --spec {name}: "
    for line in error_lines(result):
        if prefix in line:
            pointer, _, rest = line.split(prefix, 1)[1].partition(" ")
            found[pointer] = rest
    return found


class Base(OneErrorLine, unittest.TestCase):
    def setUp(self):
        self.shared = SHARED["dir"]
        self.cwd = Path(tempfile.mkdtemp(prefix="case-", dir=self.shared))

    def write(self, name, document):
        path = self.cwd / name
        path.write_text(json.dumps(document, ensure_ascii=False), encoding="utf-8")
        return path

    def rerun(self, name, document, *extra):
        """`trial --spec` of `document` saved as `name`: the run and the re-run's record."""
        self.write(name, document)
        out = f"again-{name}"
        result = run(["trial", "--spec", name, "--json", out, *extra], self.cwd)
        self.assertEqual(result.returncode, 0, result.stderr.decode())
        for line in error_lines(result):
            self.assertIn("note:", line)  # a record that runs writes notes, never an error or a warning
        return result, json.loads((self.cwd / out).read_text(encoding="utf-8"))

    def assert_notes_true(self, result, name, whole, ran, *, exempt=()):
        """Every field the forged record lacks is named by a note (but those in `exempt`), and every note says
        what the field took: "its default" only where the re-run's value is the default (version 8's)."""
        said = notes(result, name)
        defaults = record()["specification"]
        for pointer in pointers_absent(whole):
            if pointer in exempt:
                continue
            self.assertIn(pointer, said, f"no note names {pointer}, absent from {name}")
        for pointer, rest in said.items():
            taken = value_at(ran["specification"], pointer)
            if "its default" in rest:
                self.assertEqual(taken, value_at(defaults, pointer),
                                 f"{pointer}: the note says it takes its default ({rest!r}), it took {taken!r}")
            else:
                self.assertIn(f"takes {taken:g}" if isinstance(taken, (int, float)) else f"takes {taken}", rest,
                              f"{pointer}: the note ({rest!r}) does not say the {taken!r} it took")


class TrialRecordVersions(Base):
    def test_record_run_again_is_the_record_byte_for_byte(self):
        result = run(["trial", "--spec", self.shared / "one.json", "--json", "again.json", "--csv", "again.csv"],
                     self.cwd)
        self.assertEqual(result.returncode, 0, result.stderr.decode())
        self.assertEqual(error_lines(result), [])
        self.assertEqual((self.cwd / "again.json").read_bytes(), (self.shared / "one.json").read_bytes())
        self.assertEqual((self.cwd / "again.csv").read_bytes(), (self.shared / "one.csv").read_bytes())
        # ... and once more from the re-run's own record.
        result = run(["trial", "--spec", "again.json", "--json", "third.json"], self.cwd)
        self.assertEqual(result.returncode, 0, result.stderr.decode())
        self.assertEqual((self.cwd / "third.json").read_bytes(), (self.shared / "one.json").read_bytes())

    def test_version_7_record_counts_a_miss_only_at_a_lift_in_ws(self):
        whole = older(7)
        result, ran = self.rerun("v7.json", whole)
        spec = ran["specification"]
        self.assertEqual(spec["version"], SPEC_VERSION)  # written back in this version, as it ran
        self.assertEqual(spec["trial"]["miss_min_path_m"], 0)
        self.assertEqual(spec["force_law"]["acceptance"]["miss_min_path_m"], 0)
        self.assertEqual(spec["trial"]["centred_coverage_fraction"], 0.55)  # version 7 had the centred rule
        self.assert_notes_true(result, "v7.json", whole, ran)

    def test_version_6_record_runs_without_the_centred_rule(self):
        whole = older(6)
        result, ran = self.rerun("v6.json", whole)
        spec = ran["specification"]
        self.assertEqual(spec["version"], SPEC_VERSION)  # written back in this version, as it ran
        self.assertEqual(spec["trial"]["centred_coverage_fraction"], 0)
        self.assertEqual(spec["force_law"]["acceptance"]["centred_coverage_fraction"], 0)
        self.assert_notes_true(result, "v6.json", whole, ran)

    def test_version_5_record_takes_its_force_laws_acceptance(self):
        whole = record()
        acceptance = whole["specification"]["force_law"]["acceptance"]
        acceptance.update(corridor_m=0.007, hint_after_misses=2, assist_after_misses=4, end_gap_m=0.004)
        whole = older(5, whole)
        result, ran = self.rerun("v5.json", whole)
        spec = ran["specification"]
        for key, value in (("corridor_m", 0.007), ("hint_after_misses", 2), ("assist_after_misses", 4),
                           ("end_gap_m", 0.004), ("centred_coverage_fraction", 0)):
            self.assertEqual(spec["trial"][key], value, key)
            self.assertEqual(spec["force_law"]["acceptance"][key], value, key)
        # The specification's acceptance is stated in the record (in its force law): no note need name it, and
        # none may say it took its default.
        trial_acceptance = tuple(f"/specification/trial/{k}" for k in acceptance)
        self.assert_notes_true(result, "v5.json", whole, ran, exempt=trial_acceptance)

    def test_version_4_record_runs_without_the_end_gap_floor(self):
        whole = older(4)
        result, ran = self.rerun("v4.json", whole)
        spec = ran["specification"]
        self.assertEqual(spec["trial"]["end_gap_m"], 0)
        self.assertEqual(spec["force_law"]["acceptance"]["end_gap_m"], 0)
        self.assertEqual(spec["force_law"]["acceptance"]["reference_character_size_m"], 0.06)  # it grew
        trial_acceptance = tuple(f"/specification/trial/{k}" for k in spec["force_law"]["acceptance"])
        self.assert_notes_true(result, "v4.json", whole, ran, exempt=trial_acceptance)

    def test_version_3_record_runs_with_fixed_tolerances_and_no_assisted_credit(self):
        whole = older(3)
        result, ran = self.rerun("v3.json", whole)
        acceptance = ran["specification"]["force_law"]["acceptance"]
        self.assertEqual(acceptance["reference_character_size_m"], 0)  # absolute lengths: fixed tolerances
        for key in ("shortfall_per_length", "deviation_per_length"):
            self.assertEqual(acceptance[key], 0, key)  # nothing grows with the length
        self.assertEqual(acceptance["assist_after_misses"], 0)  # no assisted credit
        self.assertEqual(acceptance["end_gap_m"], 0)
        self.assertEqual(ran["specification"]["teacher_sha256"], "")
        trial_acceptance = tuple(f"/specification/trial/{k}" for k in acceptance)
        self.assert_notes_true(result, "v3.json", whole, ran, exempt=trial_acceptance)

    def test_version_2_record_takes_the_default_guidance_stiffness(self):
        whole = older(2)
        result, ran = self.rerun("v2.json", whole)
        self.assertEqual(ran["specification"]["trial"]["guidance_stiffness_n_per_m"], 400.0)
        self.assertIn("/specification/trial/guidance_stiffness_n_per_m", notes(result, "v2.json"))
        trial_acceptance = tuple(f"/specification/trial/{k}" for k in ran["specification"]["force_law"]["acceptance"])
        self.assert_notes_true(result, "v2.json", whole, ran, exempt=trial_acceptance)

    def test_version_1_writer_settings_as_key_value_strings(self):
        current = json.loads((self.shared / "param.json").read_text(encoding="utf-8"))
        whole = older(1, current)
        self.assertEqual(whole["specification"]["trial"]["writer_parameters"], ["writing_speed_m_s=0.03"])
        _, ran = self.rerun("v1.json", whole)
        self.assertEqual(ran["specification"]["trial"]["writer_parameters"],
                         current["specification"]["trial"]["writer_parameters"])
        self.assertEqual(ran["specification"]["writer"], current["specification"]["writer"])
        # A string that is no key=value is refused naming its pointer, as is a key no writer has.
        for bad in ("writing_speed_m_s", "no_such_key=1"):
            forged = copy.deepcopy(whole)
            forged["specification"]["trial"]["writer_parameters"] = [bad]
            self.write("bad.json", forged)
            refused = run(["trial", "--spec", "bad.json", "--json", "out.json"], self.cwd)
            self.assert_one_error(refused, 2, "bad.json", "/specification/trial/writer_parameters")
            self.assertFalse((self.cwd / "out.json").exists())

    def test_a_newer_version_is_refused_naming_the_versions_read(self):
        for version in (SPEC_VERSION + 1, 2 ** 40):
            whole = record()
            whole["specification"]["version"] = version
            self.write("new.json", whole)
            for check in ([], ["--check"]):
                refused = run(["trial", "--spec", "new.json", "--json", "out.json", *check], self.cwd)
                self.assert_one_error(refused, 2, "new.json", "/specification/version", str(version),
                                      f"1 to {SPEC_VERSION}")
                self.assertFalse((self.cwd / "out.json").exists())

    def test_a_version_of_another_spelling_is_refused_naming_the_versions_read(self):
        """"7" as text, null, -1, true, 7.5 and 2^64 are no version: refused at the pointer, saying which
        versions this program reads (the schema's 1..7), never a range no version has."""
        for version in ("7", None, -1, True, 7.5, 2 ** 64, "", [7]):
            whole = record()
            whole["specification"]["version"] = version
            self.write("odd.json", whole)
            refused = run(["trial", "--spec", "odd.json", "--json", "out.json"], self.cwd)
            line = self.assert_one_error(refused, 2, "odd.json", "/specification/version")
            self.assertTrue(f"1 to {SPEC_VERSION}" in line or f"[1, {SPEC_VERSION}]" in line,
                            f"{version!r}: {line}")
            self.assertNotIn("9223372036854775807", line)
            self.assertFalse((self.cwd / "out.json").exists())

    def test_a_record_without_its_version_or_of_version_0(self):
        whole = record()
        del whole["specification"]["version"]
        self.write("none.json", whole)
        self.assert_one_error(run(["trial", "--spec", "none.json"], self.cwd), 2, "none.json",
                              "/specification/version", "missing")
        whole["specification"]["version"] = 0
        self.write("zero.json", whole)
        self.assert_one_error(run(["trial", "--spec", "zero.json"], self.cwd), 2, "zero.json",
                              "/specification/version", f"1 to {SPEC_VERSION}")

    def test_an_older_record_given_a_field_only_newer_versions_have(self):
        """The fields a version's rule fixes (no centred rule before 7, no end-gap floor before 5) run as that
        version ran whatever the file says, and a note says the value given is not the one taken; a field a
        version lacks that no rule fixes (version 2's guidance stiffness) is read as given."""
        cases = (
            (6, ("trial", "centred_coverage_fraction"), 0.55, 0),
            (6, ("force_law", "acceptance", "centred_coverage_fraction"), 0.55, 0),
            (4, ("force_law", "acceptance", "end_gap_m"), 0.004, 0),
            (3, ("force_law", "acceptance", "assist_after_misses"), 5, 0),
            (2, ("trial", "guidance_stiffness_n_per_m"), 300.0, 300.0),
        )
        for version, path, given, taken in cases:
            with self.subTest(version=version, field=path[-1]):
                whole = older(version)
                node = whole["specification"]
                for part in path[:-1]:
                    node = node[part]
                node[path[-1]] = given
                name = f"v{version}-{path[-1]}.json"
                result, ran = self.rerun(name, whole)
                pointer = "/specification/" + "/".join(path)
                self.assertEqual(value_at(ran["specification"], pointer), taken, pointer)
                said = notes(result, name)
                if given != taken:
                    self.assertIn(pointer, said, f"{pointer}: {given} replaced by {taken} without a word")
                    self.assertIn(f"is {given:g} in the record", said[pointer])
                    self.assertIn(f"takes {taken:g}", said[pointer])
                else:
                    self.assertNotIn(pointer, said)

    def test_a_current_record_lacking_a_field_is_refused_naming_it(self):
        for version, path in ((7, ("trial", "centred_coverage_fraction")),
                              (7, ("force_law", "acceptance", "end_gap_m")),
                              (7, ("teacher_sha256",)),
                              (7, ("trial", "guidance_stiffness_n_per_m")),
                              (6, ("trial", "corridor_m")),
                              (4, ("teacher_sha256",)),
                              (3, ("force_law", "acceptance", "corridor_m"))):
            with self.subTest(version=version, field=path[-1]):
                whole = older(version)
                node = whole["specification"]
                for part in path[:-1]:
                    node = node[part]
                del node[path[-1]]
                self.write("less.json", whole)
                refused = run(["trial", "--spec", "less.json", "--json", "out.json"], self.cwd)
                self.assert_one_error(refused, 2, "less.json", "/specification/" + "/".join(path), "missing")
                self.assertFalse((self.cwd / "out.json").exists())

    def test_a_study_trial_records_specification_gives_its_saved_trace(self):
        trials = sorted(glob.glob(str(self.shared / "study" / "S01" / "*" / "trials" / "001-*")))
        stem = trials[0].rsplit(".", 1)[0].removesuffix(".trace")
        saved = run(["trace", f"{stem}.trace.h5", "--csv", "saved.csv"], self.cwd)
        self.assertEqual(saved.returncode, 0, saved.stderr.decode())
        again = run(["trial", "--spec", f"{stem}.json", "--csv", "again.csv"], self.cwd)
        self.assertEqual(again.returncode, 0, again.stderr.decode())
        self.assertEqual((self.cwd / "again.csv").read_bytes(), (self.cwd / "saved.csv").read_bytes())


class PythonRecords(Base):
    def setUp(self):
        need_python(self)
        super().setUp()

    def test_python_reads_each_old_version_as_the_cli_runs_it(self):
        for version in range(1, SPEC_VERSION + 1):
            with self.subTest(version=version):
                whole = older(version)
                checked = cg.check_trial_record(whole)
                self.assertEqual(cg.check_trial_record(checked), checked)  # taken again as it is
                _, ran = self.rerun(f"v{version}.json", whole)
                self.assertEqual(checked, ran["specification"])

    def test_python_record_read_by_the_cli_and_the_reverse(self):
        made = cg.simulate_trial(YI, seed=1, max_duration_s=4)
        self.write("python.json", dict(made.metrics))
        result = run(["trial", "--spec", "python.json", "--json", "cli.json", "--csv", "cli.csv"], self.cwd)
        self.assertEqual(result.returncode, 0, result.stderr.decode())
        self.assertEqual(json.loads((self.cwd / "cli.json").read_text(encoding="utf-8")), dict(made.metrics))
        # The same trial as the CLI's own record, and Python re-running the CLI's record gives its trace.
        self.assertEqual((self.cwd / "cli.csv").read_bytes(), (self.shared / "one.csv").read_bytes())
        again = cg.rerun_trial(str(self.shared / "one.json"))
        with open(self.shared / "one.csv", newline="") as table:
            rows = list(csv.DictReader(table))
        self.assertEqual(len(rows), len(again.position_m))
        for row, position in zip(rows[::97], again.position_m[::97]):
            for axis, value in zip("xyz", position):
                self.assertAlmostEqual(float(row[axis]), float(value), delta=1e-6)

    def test_python_refuses_another_version_naming_the_pointer(self):
        for version in (SPEC_VERSION + 1, "7", None, 0):
            whole = record()
            whole["specification"]["version"] = version
            for reader in (cg.check_trial_record, cg.rerun_trial):
                with self.assertRaises(cg.DataError, msg=repr(version)) as caught:
                    reader(whole)
                self.assertIn("/version", str(caught.exception))
                self.assertIn(f"1 to {SPEC_VERSION}", str(caught.exception), repr(version))


class TeacherRecordings(Base):
    def test_teacher_recorded_twice_and_saved_again_is_the_same_bytes(self):
        first = (self.shared / "teacher.json").read_bytes()
        made = run(["trial", YI, "--max-duration", "4", "--seed", "1", "--writer-profile", "skilled", "--record",
                    "again.json"], self.cwd)
        self.assertEqual(made.returncode, 0, made.stderr.decode())
        self.assertEqual((self.cwd / "again.json").read_bytes(), first)
        if cg is None:
            self.skipTest("the calligraphy Python module is not built: its recordings are not compared")
        teacher = cg.TeacherRecording.load(str(self.shared / "teacher.json"))
        teacher.save(str(self.cwd / "saved.json"))
        self.assertEqual((self.cwd / "saved.json").read_bytes(), first)
        self.assertEqual(cg.TeacherRecording.from_json(teacher.to_json()).to_json(), teacher.to_json())
        recorded = cg.record_teacher(cg.simulate_trial(YI, writer="skilled", seed=1, max_duration_s=4),
                                     str(self.cwd / "python.json"))
        self.assertEqual((self.cwd / "python.json").read_bytes(), first)
        self.assertEqual(recorded.to_json(), teacher.to_json())

    def test_teacher_of_another_version_is_refused(self):
        good = json.loads((self.shared / "teacher.json").read_text(encoding="utf-8"))
        for version in (2, 0, -1, "1", None, 2 ** 70, "missing"):
            with self.subTest(version=version):
                forged = dict(good)
                if version == "missing":
                    del forged["version"]
                else:
                    forged["version"] = version
                self.write("teacher.json", forged)
                refused = run(["trial", YI, "--guidance-mode", "replay", "--teacher", "teacher.json",
                               "--max-duration", "0.05", "--json", "out.json"], self.cwd)
                self.assert_one_error(refused, 1, "teacher.json", "/version")
                self.assertFalse((self.cwd / "out.json").exists())
                if cg is not None:
                    with self.assertRaises(cg.DataError) as caught:
                        cg.TeacherRecording.load(str(self.cwd / "teacher.json"))
                    self.assertIn("/version", str(caught.exception))


class Protocols(Base):
    def protocol(self):
        return json.loads((self.shared / "protocol.json").read_text(encoding="utf-8"))

    def plan(self, name):
        result = run(["session", "plan", name, "--subjects", "2", "--json"], self.cwd)
        self.assertEqual(result.returncode, 0, result.stderr.decode())
        return json.loads(result.stdout)

    def test_protocol_of_another_version_is_refused(self):
        """The schema says `version` is an integer 1..1: every other value, null too, is refused."""
        for version in (2, 0, "1", None, 2 ** 70, 1.5):
            with self.subTest(version=version):
                forged = self.protocol()
                forged["version"] = version
                self.write("p.json", forged)
                for command in (["session", "plan", "p.json", "--subjects", "1"],
                                ["session", "run", "p.json", "--out", "out", "--subjects", "1"]):
                    refused = run(command, self.cwd)
                    self.assert_one_error(refused, 2, "p.json", "/version")
                    self.assertFalse((self.cwd / "out").exists())

    def test_protocol_without_format_and_version_is_version_1(self):
        bare = self.protocol()
        del bare["format"], bare["version"]
        self.write("bare.json", bare)
        self.write("full.json", self.protocol())
        plans = [self.plan("bare.json"), self.plan("full.json")]
        for plan in plans:
            del plan["protocol_file"], plan["protocol_sha256"]
        self.assertEqual(plans[0], plans[1])

    def test_protocol_through_session_plan_and_its_copy_in_the_session(self):
        shutil.copy(self.shared / "protocol.json", self.cwd / "p.json")
        first = run(["session", "plan", "p.json", "--subjects", "2", "--json"], self.cwd)
        second = run(["session", "plan", "p.json", "--subjects", "2", "--json"], self.cwd)
        self.assertEqual(first.returncode, 0, first.stderr.decode())
        self.assertEqual(first.stdout, second.stdout)
        manifest = json.loads(Path(glob.glob(str(self.shared / "study" / "S01" / "*" / "session.json"))[0])
                              .read_text(encoding="utf-8"))
        copy_text = manifest["protocol"]["text"]
        (self.cwd / "copy.json").write_text(copy_text, encoding="utf-8")
        self.assertEqual((self.cwd / "copy.json").read_bytes(), (self.cwd / "p.json").read_bytes())
        planned = json.loads(first.stdout)
        again = self.plan("copy.json")
        self.assertEqual(again["protocol_sha256"], manifest["protocol"]["sha256"])
        self.assertEqual(planned["protocol_sha256"], manifest["protocol"]["sha256"])
        del planned["protocol_file"], again["protocol_file"]
        self.assertEqual(planned, again)


class SessionFolders(Base):
    def study(self, edit_manifest=None, edit_record=None, drop_second=False):
        """A copy of the shared study, its session.json and first trial record edited."""
        folder = self.cwd / "study"
        shutil.copytree(self.shared / "study", folder)
        session = Path(glob.glob(str(folder / "S01" / "*"))[0])
        if drop_second:
            for path in glob.glob(str(session / "trials" / "002-*")):
                os.remove(path)
        for path, edit in ((session / "session.json", edit_manifest),
                           (Path(sorted(glob.glob(str(session / "trials" / "001-*.json")))[0]), edit_record)):
            if edit is None:
                continue
            document = json.loads(path.read_text(encoding="utf-8"))
            edit(document)
            path.write_text(json.dumps(document, ensure_ascii=False, indent=1), encoding="utf-8")
        return folder, session

    def tables(self, folder):
        out = self.cwd / "tables"
        out.mkdir(exist_ok=True)
        result = run(["report", folder, "--csv", out], self.cwd)
        self.assertEqual(result.returncode, 0, result.stderr.decode())
        with open(out / "trials.csv", newline="", encoding="utf-8") as table:
            return list(csv.DictReader(table))

    def loaded(self, folder):
        if cg is None:
            return None
        import calligraphy.study as study
        return study.load(str(folder)).trials

    @staticmethod
    def version_1(manifest):
        manifest["version"] = 1
        for key in ("study_id", "writer_learning", "individual_differences", "session_number", "group"):
            manifest.pop(key, None)  # keys added since the first folders
        for planned in manifest["plan"]:
            planned["block"] -= 1
            planned["item"] -= 1

    @staticmethod
    def record_version_1(document):
        document["version"] = 1
        document["trial"]["block"] -= 1
        document["trial"]["item"] -= 1

    def test_session_version_1_counts_from_zero_and_is_read_from_one(self):
        folder, _ = self.study(self.version_1, self.record_version_1)
        rows = self.tables(folder)
        self.assertEqual([(r["trial"], r["block"], r["item"], r["repetition"]) for r in rows],
                         [("1", "1", "1", "1"), ("2", "1", "1", "2")])
        trials = self.loaded(folder)
        if trials is not None:
            self.assertEqual(trials[["trial", "block", "item"]].values.tolist(), [[1, 1, 1], [2, 1, 1]])

    def test_session_version_2_human_is_read_as_person(self):
        def manifest(m):
            m["version"] = 2
            m["writer"] = "human"

        def person(document):
            document["version"] = 2
            document["writer"] = {"kind": "human"}
            # A person's specification as trial --spec reads it: no simulated writer's profile or settings.
            document["specification"]["writer"] = None
            document["specification"]["trial"]["writer"] = "person"
            document["specification"]["trial"]["writer_parameters"] = []

        folder, _ = self.study(manifest, person, drop_second=True)
        rows = self.tables(folder)
        self.assertEqual([(r["writer"], r["writer_profile"]) for r in rows], [("person", "")])
        trials = self.loaded(folder)
        if trials is not None:
            self.assertEqual(list(trials["writer"]), ["person"])

    def test_session_version_3_human_is_refused(self):
        folder, session = self.study(lambda m: m.__setitem__("writer", "human"))
        refused = run(["report", folder, "--csv", self.cwd], self.cwd)
        self.assert_one_error(refused, 1, "session.json", "/writer", "person")
        self.assertFalse((self.cwd / "trials.csv").exists())
        self.assert_one_error(run(["session", "resume", session], self.cwd), 2, "session.json", "/writer")

    def test_session_and_study_record_of_another_version_are_refused(self):
        for which, value in (("session", 4), ("session", "3"), ("session", None), ("session", 0),
                             ("record", 4), ("record", "3"), ("record", 0)):
            with self.subTest(which=which, version=value):
                edit = lambda d, v=value: d.__setitem__("version", v)  # noqa: E731
                folder, session = self.study(edit if which == "session" else None,
                                             edit if which == "record" else None)
                name = "session.json" if which == "session" else "001-test-h-r1-U4E00.json"
                out = self.cwd / "out"
                out.mkdir()
                refused = run(["report", folder, "--csv", out], self.cwd)
                self.assert_one_error(refused, 1, name, "/version", "3")
                self.assertEqual(list(out.iterdir()), [])
                if which == "session":
                    self.assert_one_error(run(["session", "resume", session], self.cwd), 2, name, "/version")
                if cg is not None:
                    import calligraphy.study as study
                    with self.assertRaises(cg.DataError) as caught:
                        study.load(str(folder))
                    self.assertIn("/version", str(caught.exception))
                shutil.rmtree(folder)
                shutil.rmtree(out)

    def test_resume_of_a_version_1_session_goes_on_counting_from_one(self):
        folder, session = self.study(self.version_1, self.record_version_1, drop_second=True)
        resumed = run(["session", "resume", session], self.cwd)
        self.assertEqual(resumed.returncode, 0, resumed.stderr.decode())
        saved = sorted(glob.glob(str(session / "trials" / "002-*.json")))
        self.assertEqual(len(saved), 1)
        written = json.loads(Path(saved[0]).read_text(encoding="utf-8"))
        self.assertEqual((written["trial"]["block"], written["trial"]["item"]), (1, 1))  # a version-3 record
        self.assertEqual(written["version"], 3)
        self.assertEqual(json.loads((session / "session.json").read_text(encoding="utf-8"))["version"], 1)
        # A version-1 folder has none of the keys added since (individual differences, the writer's learning):
        # they take what those folders meant, so the resumed trial's writer is its named profile unchanged.
        self.assertEqual(written["specification"]["trial"]["writer_parameters"], [])
        rows = self.tables(folder)
        self.assertEqual([(r["block"], r["item"], r["repetition"]) for r in rows], [("1", "1", "1"), ("1", "1", "2")])

    def test_study_identity_of_another_version_is_refused(self):
        for value in (2, "1", 0):
            with self.subTest(version=value):
                folder, _ = self.study()
                identity = folder / ".calligraphy-study.json"
                document = json.loads(identity.read_text(encoding="utf-8"))
                document["version"] = value
                identity.write_text(json.dumps(document), encoding="utf-8")
                before = sorted(p.name for p in (folder / "S01").iterdir())
                refused = run(["session", "run", self.shared / "protocol.json", "--out", folder, "--subjects", "2",
                               "--new-subjects"], self.cwd)
                self.assert_one_error(refused, 1, ".calligraphy-study.json", "/version")
                self.assertFalse((folder / "S02").exists())
                self.assertEqual(sorted(p.name for p in (folder / "S01").iterdir()), before)
                out = self.cwd / "out"
                out.mkdir()
                self.assert_one_error(run(["report", folder, "--csv", out], self.cwd), 1, ".calligraphy-study.json",
                                      "/version")
                shutil.rmtree(folder)
                shutil.rmtree(out)


class CorpusStores(Base):
    HEADER_FIELDS = "<8sHHIIIfI"

    def forge(self, name, major=None, minor=None, flags=None):
        data = bytearray((self.shared / "store.clg").read_bytes())
        if major is not None:
            struct.pack_into("<H", data, 8, major)
        if minor is not None:
            struct.pack_into("<H", data, 10, minor)
        if flags is not None:
            struct.pack_into("<I", data, 28, flags)
        struct.pack_into("<I", data, 60, zlib.crc32(bytes(data[:60])))  # the header's CRC made to match
        (self.cwd / name).write_bytes(bytes(data))
        return name

    def model(self, store):
        return run(["model", SHI, "--store", store, "--json"], self.cwd)

    def test_store_built_twice_is_the_same_bytes(self):
        shutil.copytree(self.shared / "hw", self.cwd / "hw")
        for threads in ("1", "2"):
            made = run(["corpus", "build", "--data", "hw", "--out", f"s{threads}.clg", "--threads", threads], self.cwd)
            self.assertEqual(made.returncode, 0, made.stderr.decode())
            self.assertEqual((self.cwd / f"s{threads}.clg").read_bytes(), (self.shared / "store.clg").read_bytes())
        for name in ("a.clg", "b.clg"):  # a 1.0 store, of the models only
            made = run(["corpus", "build", "--data", "hw", "--out", name, "--medians", "off", "--outlines", "off"],
                       self.cwd)
            self.assertEqual(made.returncode, 0, made.stderr.decode())
        self.assertEqual((self.cwd / "a.clg").read_bytes(), (self.cwd / "b.clg").read_bytes())
        header = struct.unpack_from(self.HEADER_FIELDS, (self.cwd / "a.clg").read_bytes())
        self.assertEqual(header[:3], (b"CLGSTORE", 1, 0))
        header = struct.unpack_from(self.HEADER_FIELDS, (self.cwd / "s1.clg").read_bytes())
        self.assertEqual((header[1], header[2], header[7] & 3), (1, 2, 3))  # 1.2: medians and outlines

    def test_store_of_a_later_minor_version_reads_as_its_own(self):
        own = self.model(self.shared / "store.clg")
        self.assertEqual(own.returncode, 0, own.stderr.decode())
        self.assertIn(SHI, own.stdout.decode())
        for minor in (2, 7, 65535):
            later = self.model(self.forge(f"minor{minor}.clg", minor=minor))
            self.assertEqual(later.returncode, 0, later.stderr.decode())
            self.assertEqual(later.stdout, own.stdout)

    def test_store_of_another_major_version_is_refused(self):
        for major in (0, 2, 65535):
            name = self.forge(f"major{major}.clg", major=major)
            for command in (["model", SHI, "--store", name],
                            ["trial", SHI, "--store", name, "--max-duration", "0.05", "--json", "out.json"]):
                refused = run(command, self.cwd)
                self.assert_one_error(refused, 1, name, "offset 8", f"{major}.", "1.x")
                self.assertFalse((self.cwd / "out.json").exists())
        name = self.forge("flags.clg", flags=4)
        self.assert_one_error(self.model(name), 1, name, "offset 28", "flags")


if __name__ == "__main__":
    unittest.main()
