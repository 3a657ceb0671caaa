#!/usr/bin/env python3
"""Round 20B: files from earlier versions, and versions that do not exist, from the docs alone (docs/cli.md
"Re-running a trial", "The trial specification", "schema", "Pen traces"; docs/experiments.md "Protocol files",
"Sessions", "Trace files", "Trial records"; docs/corpus.md "Store format"; docs/stroke-acceptance.md; docs/python.md
"Running a trial again", "A study's traces"). Run by CTest as `cli_unseen_round20b_tests`.

Earlier rounds forged current files and each version's record alone; this one forges the history from one made
record, one session and one store: trial records of versions 2 to 6 edited into what the docs say each held,
re-run with the tolerances the docs say that version ran with and held to a trial run with those tolerances as
options (the credits too), an older record stating a field its version's rule fixes; version numbers a 32- or
64-bit reader would wrap onto a real one, whole numbers written as fractions, a file of another kind with a
valid version (a session.json, a protocol or a study record where another is read); a session folder holding
trials of several record versions (an old trial copied in, one mislabelled) through `report`, `session resume`
and `study.load`; a session.json without the keys added since the first folders; an older folder's gzip and
plain CSV traces; HDF5 traces whose version attribute (and user block) is changed, missing or of another type;
stores of another minor, major or header size and a 1.0 store (no medians) under a record made with medians, refused;
Python's `check_trial_record`, `rerun_trial` and `study.load` given each.

CALLIGRAPHY_CLI names the program, PYTHONPATH its Python module. CALLIGRAPHY_SANITIZED=1 takes five cases.
"""
import copy
import csv
import gzip
import hashlib
import json
import os
import shutil
import struct
import tempfile
import unittest
import zlib
from pathlib import Path

from outsider import CLI, OneErrorLine, error_lines, run, sanitized_subset

load_tests = sanitized_subset({"test_version_3_record_credits_what_the_fixed_tolerances_give",
                               "test_record_versions_a_narrower_integer_would_wrap_are_refused",
                               "test_report_reads_a_version_1_trial_beside_version_3_ones",
                               "test_trace_version_attribute_changed_missing_or_of_another_type",
                               "test_store_of_another_minor_major_or_header_size"})

YI = "一"
CORPUS = Path(os.environ.get("CALLIGRAPHY_CORPUS_DIR", Path.home() / ".cache/calligraphy/hanzi-writer-data-2.0.1"))
# The made record: a mean deviation so tight that only the tolerances that grow with the stroke accept the novice's
# 一 at once; the fixed tolerances of version 3 refuse an attempt first (checked below, so the cases can fail).
TRIAL = [YI, "--mean-deviation", "0.0003", "--seed", "1", "--max-duration", "8"]
SIM = ["--writer", "simulated", "--writer-learning", "none", "--individual-differences", "off"]
# What docs/cli.md "Re-running a trial" says each version ran with, as the trial's options.
FIXED_V3 = ["--reference-character-size", "0", "--shortfall-per-length", "0", "--deviation-per-length", "0",
            "--shortfall-cap", "0.1", "--mean-deviation-cap", "0.1", "--assist-after-misses", "0",
            "--hint-after-misses", "3"]
NO_END_GAP = ["--end-gap", "0"]
NO_CENTRED = ["--centred-coverage-fraction", "0"]
# The stroke acceptance's fields, as the trial states them from version 6 (docs/cli.md's table).
ACCEPTANCE = ["corridor_m", "mean_deviation_m", "shortfall_m", "shortfall_fraction", "displacement_m",
              "follow_through_m", "max_gain_ratio", "lookahead_m", "shortfall_per_length", "shortfall_cap_m",
              "deviation_per_length", "mean_deviation_cap_m", "reference_character_size_m", "hint_after_misses",
              "assist_after_misses", "end_gap_m", "end_gap_fraction", "centred_coverage_fraction",
              "centred_balance_fraction", "centred_min_length_m", "centred_max_length_m"]
# What version 3 lacked: growing tolerances, the hint and assisted credit, the end gap and the centred rule.
AFTER_V3 = ["reference_character_size_m", "shortfall_per_length", "shortfall_cap_m", "deviation_per_length",
            "mean_deviation_cap_m", "hint_after_misses", "assist_after_misses"]
END_GAP = ["end_gap_m", "end_gap_fraction"]
CENTRED = ["centred_coverage_fraction", "centred_balance_fraction", "centred_min_length_m", "centred_max_length_m"]
WRAPPING = [2 ** 31, 2 ** 31 - 1, 2 ** 32 + 7, -(2 ** 32) + 7, 2 ** 63, 2 ** 64 + 7]


def sha256(path):
    return hashlib.sha256(Path(path).read_bytes()).hexdigest()


def read_json(path):
    return json.loads(Path(path).read_text(encoding="utf-8"))


def write_json(path, value):
    Path(path).write_text(json.dumps(value, ensure_ascii=False, indent=1), encoding="utf-8")
    return Path(path)


def older_specification(spec, version, stated=None):
    """The record's specification edited into what the docs say `version` held: the trial's acceptance fields
    out before 6, the miss's least path out before 8, the centred rule out before 7, the end gap out before 5, and before 4 the growing tolerances,
    the hint and assisted credit and the teacher's SHA-256. `stated`: force-law acceptance values to give anyway."""
    s = copy.deepcopy(spec)
    s["version"] = version
    dropped = []
    if version < 8:
        dropped += ["miss_min_path_m"]
    if version < 7:
        dropped += CENTRED
    if version < 5:
        dropped += END_GAP
    if version < 4:
        dropped += AFTER_V3
        del s["teacher_sha256"]
    for key in dropped:
        del s["force_law"]["acceptance"][key]
        s["trial"].pop(key, None)
    if version < 6:
        for key in ACCEPTANCE:
            s["trial"].pop(key, None)
    for key, value in (stated or {}).items():
        s["force_law"]["acceptance"][key] = value
    return s


def notes(result):
    return [line for line in error_lines(result) if ": note: " in line]


def reseal_trace(path):
    """The trace's 512-byte user block rewritten for the HDF5 file after it, as docs/experiments.md says it
    holds it: the name, the version, the length and the CRC-32 (lines as the program writes them)."""
    data = Path(path).read_bytes()
    body = data[512:]
    lines = data[:512].rstrip(b"\0").decode().splitlines()
    fields = dict(line.split(" ", 1) for line in lines[1:])
    block = (f"{lines[0]}\nversion {fields['version']}\nbytes {len(body)}\ncrc32 {zlib.crc32(body):08x}\n").encode()
    Path(path).write_bytes(block.ljust(512, b"\0") + body)


def reseal_store(data):
    """The store's header CRC (bytes [0, 60) at 60) made again, as docs/corpus.md defines it."""
    data = bytearray(data)
    struct.pack_into("<I", data, 60, zlib.crc32(bytes(data[:60])))
    return bytes(data)


class Round20B(unittest.TestCase, OneErrorLine):
    @classmethod
    def setUpClass(cls):
        if not CLI:
            raise unittest.SkipTest("CALLIGRAPHY_CLI is not set")
        cls.tmp = Path(tempfile.mkdtemp(prefix="round20b-"))
        t = cls.tmp
        made = run(["trial", *TRIAL, "--json", "r7.json", "--csv", "r7.csv"], cwd=t)
        assert made.returncode == 0, made.stderr
        cls.r7 = read_json(t / "r7.json")
        protocol = {"name": "hist", "conditions": [{"name": "V", "mode": "vision"}],
                    "test": {"characters": [YI], "conditions": ["V"], "repetitions": 2},
                    "trial": {"max_duration_s": 4}}
        write_json(t / "p.json", protocol)
        ran = run(["session", "run", "p.json", *SIM, "--subjects", "1", "--device", "simulated", "--out", "st"],
                  cwd=t)
        assert ran.returncode == 0, ran.stderr
        (cls.session,) = (t / "st" / "S01").iterdir()
        (t / "tables0").mkdir()
        reported = run(["report", "st", "--csv", "tables0", "--jobs", "1"], cwd=t)
        assert reported.returncode == 0, reported.stderr
        cls.trials0 = cls.rows(t / "tables0" / "trials.csv")

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.tmp, ignore_errors=True)

    @staticmethod
    def rows(path):
        with open(path, newline="", encoding="utf-8") as f:
            return list(csv.DictReader(f))

    def setUp(self):
        self.dir = Path(tempfile.mkdtemp(dir=self.tmp))

    def cli(self, *args, cwd=None):
        return run(list(args), cwd=cwd or self.dir)

    def record(self, spec, name="r.json"):
        r = copy.deepcopy(self.r7)
        r["specification"] = spec
        return write_json(self.dir / name, r)

    def study_copy(self):
        """A copy of the made study; its one session folder."""
        shutil.copytree(self.tmp / "st", self.dir / "st", symlinks=True)
        (session,) = (self.dir / "st" / "S01").iterdir()
        return session

    def report(self, study="st"):
        tables = self.dir / "tables"
        tables.mkdir(exist_ok=True)
        return self.cli("report", study, "--csv", tables, "--jobs", "1"), tables / "trials.csv"

    def python(self):
        try:
            import calligraphy
            import calligraphy.study
        except ImportError as e:  # the module is built with the program; pandas may be missing
            self.skipTest(f"the Python module cannot be imported: {e}")
        return calligraphy

    # --- trial records of each earlier version -------------------------------------------------------------

    def test_version_3_record_credits_what_the_fixed_tolerances_give(self):
        spec = older_specification(self.r7["specification"], 3)
        got = self.cli("trial", "--spec", self.record(spec), "--json", "again.json", "--csv", "again.csv")
        self.assertEqual(got.returncode, 0, got.stderr)
        direct = self.cli("trial", *TRIAL, *FIXED_V3, *NO_END_GAP, *NO_CENTRED, "--json", "d.json",
                          "--csv", "d.csv")
        self.assertEqual(direct.returncode, 0, direct.stderr)
        self.assertEqual((self.dir / "again.csv").read_bytes(), (self.dir / "d.csv").read_bytes())
        again, d = read_json(self.dir / "again.json"), read_json(self.dir / "d.json")
        for key in ("strokes_completed", "strokes_assisted", "refusals", "per_character"):
            self.assertEqual(again[key], d[key], key)
        # The fixed tolerances refused what the growing ones took: the re-run is not the version-7 record's.
        self.assertGreater(sum(again["refusals"].values()), sum(self.r7["refusals"].values()))
        said = "\n".join(notes(got))
        for key, value in (("reference_character_size_m", "0"), ("shortfall_cap_m", "0.1"),
                           ("assist_after_misses", "0"), ("end_gap_m", "0"), ("centred_coverage_fraction", "0")):
            self.assertIn(f"/specification/force_law/acceptance/{key} is not in this earlier version of the record;"
                          f" it takes {value}", said)
        self.assertIn("version 3", said)

    def test_version_4_record_stating_an_end_gap_runs_without_it(self):
        spec = older_specification(self.r7["specification"], 4, stated={"end_gap_m": 0.004})
        got = self.cli("trial", "--spec", self.record(spec), "--csv", "again.csv")
        self.assertEqual(got.returncode, 0, got.stderr)
        self.assertIn("/specification/force_law/acceptance/end_gap_m is 0.004 in the record, but records of version "
                      "4 ran with 0; it takes 0", "\n".join(notes(got)))
        direct = self.cli("trial", *TRIAL, *NO_END_GAP, *NO_CENTRED, "--csv", "d.csv")
        self.assertEqual(direct.returncode, 0, direct.stderr)
        self.assertEqual((self.dir / "again.csv").read_bytes(), (self.dir / "d.csv").read_bytes())
        cg = self.python()
        checked = cg.check_trial_record(str(self.dir / "r.json"))
        self.assertEqual(checked["force_law"]["acceptance"]["end_gap_m"], 0)
        self.assertEqual(checked["trial"]["end_gap_m"], 0)

    def test_version_5_record_takes_the_acceptance_its_force_law_states(self):
        spec = older_specification(self.r7["specification"], 5)
        self.assertNotIn("mean_deviation_m", spec["trial"])
        got = self.cli("trial", "--spec", self.record(spec), "--csv", "again.csv")
        self.assertEqual(got.returncode, 0, got.stderr)
        direct = self.cli("trial", *TRIAL, *NO_CENTRED, "--csv", "d.csv")
        self.assertEqual(direct.returncode, 0, direct.stderr)
        self.assertEqual((self.dir / "again.csv").read_bytes(), (self.dir / "d.csv").read_bytes())
        checked = self.python().check_trial_record(str(self.dir / "r.json"))
        self.assertEqual(checked["trial"]["mean_deviation_m"], 0.0003)
        self.assertEqual(checked["trial"]["centred_coverage_fraction"], 0)

    def test_version_6_record_stating_the_centred_rule_runs_without_it(self):
        spec = older_specification(self.r7["specification"], 6, stated={"centred_coverage_fraction": 0.55})
        spec["trial"]["centred_coverage_fraction"] = 0.55
        got = self.cli("trial", "--spec", self.record(spec), "--check")
        self.assertEqual(got.returncode, 0, got.stderr)
        said = "\n".join(notes(got))
        self.assertIn("centred_coverage_fraction is 0.55 in the record, but records of version 6 ran with 0; "
                      "it takes 0", said)
        checked = self.python().check_trial_record(str(self.dir / "r.json"))
        self.assertEqual(checked["trial"]["centred_coverage_fraction"], 0)
        self.assertEqual(checked["force_law"]["acceptance"]["centred_coverage_fraction"], 0)

    def test_python_reruns_a_version_3_record_as_the_command_line_does(self):
        cg = self.python()
        path = self.record(older_specification(self.r7["specification"], 3))
        again = cg.rerun_trial(str(path))
        got = self.cli("trial", "--spec", path, "--json", "again.json")
        self.assertEqual(got.returncode, 0, got.stderr)
        cli = read_json(self.dir / "again.json")
        for key in ("strokes_completed", "strokes_assisted", "refusals"):
            self.assertEqual(again.metrics[key], cli[key], key)
        self.assertEqual(again.metrics["specification"]["trial"]["reference_character_size_m"], 0)

    def test_an_old_record_written_back_runs_as_it_ran_without_a_note(self):
        # A re-run's record, and check_trial_record's answer, state the trial in this version as it ran: run
        # again, they give the old record's trace, with nothing left for a note to say.
        path = self.record(older_specification(self.r7["specification"], 3))
        first = self.cli("trial", "--spec", path, "--json", "v3.json", "--csv", "v3.csv")
        self.assertEqual(first.returncode, 0, first.stderr)
        written = read_json(self.dir / "v3.json")
        self.assertEqual(written["specification"]["version"], self.r7["specification"]["version"])
        self.assertEqual(written["specification"]["force_law"]["acceptance"]["reference_character_size_m"], 0)
        again = self.cli("trial", "--spec", "v3.json", "--csv", "again.csv")
        self.assertEqual(again.returncode, 0, again.stderr)
        self.assertEqual(notes(again), [])
        self.assertEqual((self.dir / "again.csv").read_bytes(), (self.dir / "v3.csv").read_bytes())
        cg = self.python()
        checked = cg.check_trial_record(str(path))
        self.assertEqual(checked["version"], self.r7["specification"]["version"])
        self.assertEqual(cg.check_trial_record(checked), checked)
        self.assertEqual(checked, written["specification"])
        python = cg.rerun_trial(checked)
        self.assertEqual(python.metrics["refusals"], written["refusals"])

    # --- versions that do not exist ------------------------------------------------------------------------

    def test_record_versions_a_narrower_integer_would_wrap_are_refused(self):
        for version in WRAPPING:
            with self.subTest(version=version):
                spec = copy.deepcopy(self.r7["specification"])
                spec["version"] = version
                path = self.record(spec)
                for extra in ([], ["--check"]):
                    self.assert_one_error(self.cli("trial", "--spec", path, *extra), 2, "r.json",
                                          "/specification/version", "(1 to 9)")

    def test_record_version_written_with_a_fraction_or_an_exponent(self):
        # A whole number is a whole number however JSON writes it (as the schema's "integer" says): 9.0 is
        # version 9 and 3.0 version 3, with version 3's notes; 1e3 is version 1000 and -0 version 0, refused.
        def with_version(text, spec):
            r = copy.deepcopy(self.r7)
            r["specification"] = dict(spec, version="@")
            path = self.dir / "r.json"
            path.write_text(json.dumps(r).replace('"version": "@"', f'"version": {text}'), encoding="utf-8")
            return path
        current = self.cli("trial", "--spec", with_version("9.0", self.r7["specification"]), "--csv", "a.csv")
        self.assertEqual(current.returncode, 0, current.stderr)
        self.assertEqual(notes(current), [])
        self.assertEqual((self.dir / "a.csv").read_bytes(), (self.tmp / "r7.csv").read_bytes())
        old = self.cli("trial", "--spec", with_version("3.0", older_specification(self.r7["specification"], 3)),
                       "--check")
        self.assertEqual(old.returncode, 0, old.stderr)
        ruled = [n for n in notes(old) if "records of version" in n]
        self.assertTrue(ruled)
        self.assertTrue(all("records of version 3 ran with" in n for n in ruled), ruled)
        for text, shown in (("1e3", "version 1000"), ("-0", "version 0"), ("0.0", "version 0"),
                            ("6.5", "/specification/version")):
            with self.subTest(version=text):
                self.assert_one_error(self.cli("trial", "--spec", with_version(text, self.r7["specification"]),
                                               "--check"), 2, "r.json", "/specification/version", shown, "(1 to 9)")

    def test_specification_of_another_files_format_with_a_valid_version(self):
        for fmt, version in (("calligraphy-study-session", 3), ("calligraphy-study-protocol", 1),
                             ("calligraphy-study-trial", 3), ("calligraphy-trace", 1)):
            with self.subTest(format=fmt):
                spec = copy.deepcopy(self.r7["specification"])
                spec["format"], spec["version"] = fmt, version
                line = self.assert_one_error(self.cli("trial", "--spec", self.record(spec), "--check"), 2,
                                             "r.json", "/specification/format", "calligraphy-trial-specification")
                self.assertIn(fmt, line)

    def test_a_session_json_or_a_protocol_given_as_a_record(self):
        for path in (self.session / "session.json", self.tmp / "p.json"):
            with self.subTest(file=path.name):
                got = self.cli("trial", "--spec", path)
                self.assert_one_error(got, 2, path.name, "no trial specification")
                self.assertEqual(sorted(os.listdir(self.dir)), [])

    def test_a_record_or_a_session_json_given_as_a_protocol(self):
        study_record = self.session / "trials" / "001-test-V-r1-U4E00.json"
        for path, fmt in ((self.session / "session.json", "calligraphy-study-session"),
                          (study_record, "calligraphy-study-trial")):
            with self.subTest(file=path.name):
                self.assert_one_error(self.cli("session", "plan", path, "--subjects", "1"), 2, path.name,
                                      "/format", "calligraphy-study-protocol", fmt)
        # A trial --json record has no format of its own: it is refused as a protocol, naming a pointer.
        self.assert_one_error(self.cli("session", "plan", self.tmp / "r7.json", "--subjects", "1"), 2, "r7.json",
                              ": /")

    def test_protocol_versions_a_narrower_integer_would_wrap_or_a_fraction(self):
        base = read_json(self.tmp / "p.json")
        for text in [str(v) for v in (2 ** 32 + 1, -(2 ** 32) + 1, 2 ** 64 + 1, 0, 2)] + ["1.5", "1e1"]:
            with self.subTest(version=text):
                p = dict(base, version="@")
                (self.dir / "p.json").write_text(json.dumps(p).replace('"@"', text), encoding="utf-8")
                self.assert_one_error(self.cli("session", "plan", "p.json", "--subjects", "1"), 2, "p.json",
                                      "/version")

    def test_python_refuses_versions_that_do_not_exist_naming_the_record(self):
        cg = self.python()
        for version in (2 ** 32 + 7, 7.5, 0, -7, "7"):
            with self.subTest(version=version):
                spec = copy.deepcopy(self.r7["specification"])
                spec["version"] = version
                path = self.record(spec)
                for check in (cg.check_trial_record, cg.rerun_trial):
                    with self.assertRaises(cg.DataError) as caught:
                        check(str(path))
                    self.assertIn("r.json", str(caught.exception))
                    self.assertIn("/specification/version", str(caught.exception))

    # --- a session folder of several versions ---------------------------------------------------------------

    def forge_study_record(self, session, stem, edit):
        path = session / "trials" / f"{stem}.json"
        r = read_json(path)
        edit(r)
        write_json(path, r)
        return path

    def test_report_reads_a_version_1_trial_beside_version_3_ones(self):
        session = self.study_copy()

        def to_version_1(r):
            r["version"] = 1
            r["trial"]["block"] -= 1
            r["trial"]["item"] -= 1
        self.forge_study_record(session, "001-test-V-r1-U4E00", to_version_1)
        got, trials = self.report()
        self.assertEqual(got.returncode, 0, got.stderr)
        self.assertEqual(self.rows(trials), self.trials0)
        study = self.python().study.load(str(self.dir / "st"))
        self.assertEqual(sorted(study.trials["block"].tolist()), [1, 1])
        self.assertEqual(sorted(study.trials["item"].tolist()), [1, 1])

    def test_a_version_1_trial_counting_from_1_is_not_reported_as_another_block(self):
        session = self.study_copy()
        path = self.forge_study_record(session, "001-test-V-r1-U4E00", lambda r: r.update(version=1))
        # Read as counting from 0 it names block 2 and item 2 of a plan of one block and one item: the tables
        # hold the plan's (or the record is refused naming it), never block 2.
        got, trials = self.report()
        if got.returncode == 0:
            self.assertEqual(self.rows(trials), self.trials0)
            study = self.python().study.load(str(self.dir / "st"))
            self.assertEqual(sorted(study.trials["block"].tolist()), [1, 1])
            self.assertEqual(sorted(study.trials["item"].tolist()), [1, 1])
        else:
            self.assert_one_error(got, 1, path.name)

    def test_resume_of_a_session_with_an_old_trial_saved_runs_the_missing_one(self):
        session = self.study_copy()
        old = self.forge_study_record(session, "001-test-V-r1-U4E00",
                                      lambda r: r.update(version=2, trial=dict(r["trial"])))
        before = old.read_bytes()
        for suffix in (".json", ".trace.h5", ".svg"):
            (session / "trials" / f"002-test-V-r2-U4E00{suffix}").unlink()
        log = (session / "log.jsonl").read_text(encoding="utf-8").splitlines(keepends=True)
        kept = [line for line in log if json.loads(line).get("trial") != 2 and
                json.loads(line)["event"] != "session_completed"]
        (session / "log.jsonl").write_text("".join(kept), encoding="utf-8")
        got = self.cli("session", "resume", session)
        self.assertEqual(got.returncode, 0, got.stderr)
        self.assertEqual(old.read_bytes(), before)
        self.assertTrue((session / "trials" / "002-test-V-r2-U4E00.json").is_file())
        reported, _ = self.report()
        self.assertEqual(reported.returncode, 0, reported.stderr)

    def test_a_trial_record_of_a_version_that_does_not_exist_in_a_session(self):
        cg = self.python()
        for text in ("4", "0", str(2 ** 32 + 3), "2.5", "null"):
            with self.subTest(version=text):
                shutil.rmtree(self.dir / "st", ignore_errors=True)
                session = self.study_copy()
                path = self.forge_study_record(session, "002-test-V-r2-U4E00", lambda r: r.update(version="@"))
                path.write_text(path.read_text(encoding="utf-8").replace('"version": "@"', f'"version": {text}'),
                                encoding="utf-8")
                got, _ = self.report()
                self.assert_one_error(got, 1, path.name, "/version")
                with self.assertRaises(cg.DataError) as caught:
                    cg.study.load(str(self.dir / "st"))
                self.assertIn(path.name, str(caught.exception))
                self.assertIn("/version", str(caught.exception))

    def test_session_json_of_a_version_that_does_not_exist(self):
        cg = self.python()
        for text in ("4", str(2 ** 32 + 3), "2.5", "-1"):
            with self.subTest(version=text):
                shutil.rmtree(self.dir / "st", ignore_errors=True)
                session = self.study_copy()
                manifest = session / "session.json"
                d = read_json(manifest)
                d["version"] = "@"
                manifest.write_text(json.dumps(d).replace('"version": "@"', f'"version": {text}'), encoding="utf-8")
                got, _ = self.report()
                self.assert_one_error(got, 1, "session.json", "/version")
                self.assert_one_error(self.cli("session", "resume", session), 2, "session.json", "/version")
                with self.assertRaises(cg.DataError) as caught:
                    cg.study.load(str(self.dir / "st"))
                self.assertIn("session.json", str(caught.exception))

    def test_session_json_without_the_keys_added_since_the_first_folders(self):
        # A folder made before studies had an identity: no .calligraphy-study.json and no study_id.
        session = self.study_copy()
        (self.dir / "st" / ".calligraphy-study.json").unlink()
        manifest = session / "session.json"
        d = read_json(manifest)
        for key in ("study_id", "writer_learning", "individual_differences", "session_number", "group",
                    "writer_seed"):
            d.pop(key, None)
        write_json(manifest, d)
        got, trials = self.report()
        self.assertEqual(got.returncode, 0, got.stderr)
        rows = self.rows(trials)
        kept = ("trial", "block", "item", "phase", "condition", "strokes_accepted", "mean_deviation_m", "trace_sha256")
        self.assertEqual([[r[k] for k in kept] for r in rows], [[r[k] for k in kept] for r in self.trials0])
        resumed = self.cli("session", "resume", session)
        self.assertEqual(resumed.returncode, 0, resumed.stderr)
        self.assertEqual(len(self.python().study.load(str(self.dir / "st")).trials), 2)

    def test_a_study_record_whose_specification_is_of_version_6(self):
        session = self.study_copy()
        path = self.forge_study_record(
            session, "001-test-V-r1-U4E00",
            lambda r: r.update(specification=older_specification(r["specification"], 6)))
        got, trials = self.report()
        self.assertEqual(got.returncode, 0, got.stderr)
        self.assertEqual(self.rows(trials), self.trials0)
        checked = self.cli("trial", "--spec", path, "--check")
        self.assertEqual(checked.returncode, 0, checked.stderr)
        self.assertTrue(any("centred_coverage_fraction" in n and "version 6" in n for n in notes(checked)))

    # --- traces of older folders and of other versions -------------------------------------------------------

    def test_an_older_folders_gzip_and_plain_csv_traces_read_as_the_hdf5_one(self):
        cg = self.python()
        stem = "001-test-V-r1-U4E00"
        h5_samples = self.samples_of_trial_1(cg, self.tmp / "st")
        # The third: a plain CSV saved before traces had `attempt` and `rewritten`, read as before.
        for kind in ("csv.gz", "csv", "csv without attempt"):
            with self.subTest(kind=kind):
                shutil.rmtree(self.dir / "st", ignore_errors=True)
                session = self.study_copy()
                trials = session / "trials"
                text = self.cli("trace", trials / f"{stem}.trace.h5")
                self.assertEqual(text.returncode, 0, text.stderr)
                body = text.stdout
                if kind == "csv without attempt":
                    body = b"".join(line.rsplit(b",", 2)[0] + b"\n" for line in body.splitlines())
                    self.assertTrue(body.startswith(b"t,x,y,z,fx,fy,fz,state,stroke,element\n"))
                name = f"{stem}.{kind.split()[0]}"
                (trials / name).write_bytes(gzip.compress(body) if kind == "csv.gz" else body)
                (trials / f"{stem}.trace.h5").unlink()
                self.forge_study_record(session, stem, lambda r: r.update(
                    files={"svg": r["files"]["svg"], "csv": name, "trace_sha256": sha256(trials / name)}))
                got, table = self.report()
                self.assertEqual(got.returncode, 0, got.stderr)
                for old, new in zip(self.trials0, self.rows(table)):
                    for key in old:
                        if key not in ("trace_file", "trace_sha256"):
                            self.assertEqual(old[key], new[key], key)
                samples = self.samples_of_trial_1(cg, self.dir / "st")
                # docs/python.md: the same columns, value for value, but the two a trace saved before them lacks.
                same = [c for c in h5_samples.columns if kind != "csv without attempt" or
                        c not in ("attempt", "rewritten")]
                self.assertEqual(list(samples.columns), same)
                self.assertTrue(samples.equals(h5_samples[same]))
                scored = self.cli("score", trials / name, "--character", YI, "--json", "-")
                self.assertEqual(scored.returncode, 0, scored.stderr)
                self.assertEqual(json.loads(scored.stdout)["strokes_accepted"], int(self.trials0[0]["strokes_accepted"]))

    @staticmethod
    def samples_of_trial_1(cg, folder):
        study = cg.study.load(str(folder))
        (label,) = study.trials.index[study.trials["trial"] == 1]
        return study.samples(label)

    def trace_copy(self):
        src = self.session / "trials" / "001-test-V-r1-U4E00.trace.h5"
        dst = self.dir / "t.trace.h5"
        shutil.copyfile(src, dst)
        return dst

    def test_trace_version_attribute_changed_missing_or_of_another_type(self):
        try:
            import h5py
            import numpy
        except ImportError as e:
            self.skipTest(f"h5py is missing: {e}")
        forgeries = {"2": lambda a: a.__setitem__("version", numpy.int32(2)),
                     "0": lambda a: a.__setitem__("version", numpy.int32(0)),
                     "-1": lambda a: a.__setitem__("version", numpy.int32(-1)),
                     "2^32+1": lambda a: a.__setitem__("version", numpy.int64(2 ** 32 + 1)),
                     "missing": lambda a: a.__delitem__("version"),
                     "text": lambda a: a.__setitem__("version", "1"),
                     "float": lambda a: a.__setitem__("version", 1.0)}
        for name, forge in forgeries.items():
            with self.subTest(version=name):
                path = self.trace_copy()
                with h5py.File(path, "r+") as f:
                    forge(f.attrs)
                reseal_trace(path)
                for command in (["trace", path], ["score", path, "--character", YI]):
                    self.assert_one_error(self.cli(*command), 1, "t.trace.h5", "version")

    def test_trace_user_block_of_another_version_or_format(self):
        for old, new in ((b"version 1\n", b"version 2\n"), (b"version 1\n", b"version 0\n"),
                         (b"calligraphy-trace\n", b"calligraphy-trial\n")):
            with self.subTest(block=new):
                path = self.trace_copy()
                data = path.read_bytes()
                path.write_bytes(data[:512].replace(old, new, 1) + data[512:])
                self.assert_one_error(self.cli("trace", path), 1, "t.trace.h5")

    def test_trace_format_attribute_of_another_kind(self):
        try:
            import h5py
            import numpy
        except ImportError as e:
            self.skipTest(f"h5py is missing: {e}")
        cg = self.python()
        session = self.study_copy()
        path = session / "trials" / "001-test-V-r1-U4E00.trace.h5"
        with h5py.File(path, "r+") as f:  # the type the program writes (fixed-length), another file kind's name
            f.attrs["format"] = numpy.bytes_(b"calligraphy-trial-specification")
        reseal_trace(path)
        self.forge_study_record(session, "001-test-V-r1-U4E00",
                                lambda r: r["files"].update(trace_sha256=sha256(path)))
        self.assert_one_error(self.cli("score", path, "--character", YI), 1, path.name, "format")
        with self.assertRaises(cg.DataError) as caught:
            self.samples_of_trial_1(cg, self.dir / "st")
        self.assertIn(path.name, str(caught.exception))
        self.assertIn("format", str(caught.exception))

    # --- stores of other versions -----------------------------------------------------------------------------

    def build_store(self, *extra):
        data = self.dir / "data"
        data.mkdir(exist_ok=True)
        shutil.copyfile(CORPUS / f"{YI}.json", data / f"{YI}.json")
        out = self.dir / f"s{len(extra)}.clg"
        got = self.cli("corpus", "build", "--data", data, "--out", out, "--threads", "1", *extra)
        if got.returncode != 0 and not (CORPUS / f"{YI}.json").is_file():
            self.skipTest(f"no hanzi-writer-data at {CORPUS}")
        self.assertEqual(got.returncode, 0, got.stderr)
        return out

    def test_store_of_another_minor_major_or_header_size(self):
        store = self.build_store()
        base = store.read_bytes()
        made = self.cli("trial", YI, "--store", store, "--seed", "1", "--max-duration", "8", "--csv", "base.csv")
        self.assertEqual(made.returncode, 0, made.stderr)
        for minor in (0, 1, 65535):
            with self.subTest(minor=minor):
                forged = self.dir / "m.clg"
                forged.write_bytes(reseal_store(base[:10] + struct.pack("<H", minor) + base[12:]))
                got = self.cli("trial", YI, "--store", forged, "--seed", "1", "--max-duration", "8", "--csv", "m.csv")
                self.assertEqual(got.returncode, 0, got.stderr)
                self.assertEqual((self.dir / "m.csv").read_bytes(), (self.dir / "base.csv").read_bytes())
        for offset, fmt, value in ((8, "<H", 0), (8, "<H", 2), (8, "<H", 65535), (12, "<I", 65), (12, "<I", 0)):
            with self.subTest(offset=offset, value=value):
                forged = self.dir / "m.clg"
                forged.write_bytes(reseal_store(base[:offset] + struct.pack(fmt, value)
                                                + base[offset + struct.calcsize(fmt):]))
                self.assert_one_error(self.cli("trial", YI, "--store", forged, "--max-duration", "1"), 1, "m.clg",
                                      f"offset {offset}")
                self.assert_one_error(self.cli("characters", "--store", forged), 1, "m.clg", f"offset {offset}")

    def test_a_record_made_on_a_store_with_medians_rerun_on_a_1_0_store(self):
        # The characters' SHA-256 covers the models and their medians (docs/cli.md): a store of the models only
        # (1.0), which measures along the fitted elements, is other character data, refused; and the reverse.
        with_medians = self.build_store()
        models_only = self.build_store("--medians", "off", "--outlines", "off")
        made = self.cli("trial", YI, "--store", with_medians, "--seed", "1", "--max-duration", "8", "--json", "m.json",
                        "--csv", "m.csv")
        self.assertEqual(made.returncode, 0, made.stderr)
        same = self.cli("trial", "--spec", "m.json", "--store", with_medians, "--csv", "same.csv")
        self.assertEqual(same.returncode, 0, same.stderr)
        self.assertEqual(notes(same), [])
        self.assertEqual((self.dir / "same.csv").read_bytes(), (self.dir / "m.csv").read_bytes())
        self.assert_one_error(self.cli("trial", "--spec", "m.json", "--store", models_only, "--csv", "again.csv"),
                              1, "other character data")
        self.assertFalse((self.dir / "again.csv").exists())
        made = self.cli("trial", YI, "--store", models_only, "--seed", "1", "--max-duration", "8", "--json",
                        "e.json")
        self.assertEqual(made.returncode, 0, made.stderr)
        self.assert_one_error(self.cli("trial", "--spec", "e.json", "--store", with_medians, "--csv", "again.csv"),
                              1, "other character data")

    # --- what each schema says of the versions, and a few more histories ---------------------------------------

    def test_schemas_state_the_versions_the_readers_read(self):
        session = self.study_copy()
        manifest = session / "session.json"
        readers = {"record": (lambda v: self.cli("trial", "--spec", self.record(
                                  dict(self.r7["specification"], version=v)), "--check"), 9, "r.json", 2),
                   "session": (lambda v: self.cli("session", "resume", write_json(
                                   manifest, dict(read_json(self.session / "session.json"), version=v)).parent),
                               3, "session.json", 2),
                   "protocol": (lambda v: self.cli("session", "plan", write_json(
                                    self.dir / "p.json", dict(read_json(self.tmp / "p.json"), version=v)),
                                    "--subjects", "1"), 1, "p.json", 2)}
        for kind, (read, current, name, status) in readers.items():
            with self.subTest(kind=kind):
                got = self.cli("schema", kind)
                self.assertEqual(got.returncode, 0, got.stderr)
                version = json.loads(got.stdout)["properties"]["version"]
                self.assertEqual(version["type"], "integer")
                self.assertEqual((version["minimum"], version["maximum"]), (1, current))
                self.assert_one_error(read(current + 1), status, name, "/version")
                self.assert_one_error(read(0), status, name, "/version")

    def test_a_version_2_record_reads_a_guidance_stiffness_it_states(self):
        spec = older_specification(self.r7["specification"], 2)
        spec["trial"]["guidance_stiffness_n_per_m"] = 300.0
        spec["force_law"]["guidance_stiffness_n_per_m"] = 300.0
        got = self.cli("trial", "--spec", self.record(spec), "--csv", "again.csv")
        self.assertEqual(got.returncode, 0, got.stderr)
        self.assertFalse(any("guidance_stiffness" in n for n in notes(got)), notes(got))
        direct = self.cli("trial", *TRIAL, *FIXED_V3, *NO_END_GAP, *NO_CENTRED, "--guidance-stiffness", "300",
                          "--csv", "d.csv")
        self.assertEqual(direct.returncode, 0, direct.stderr)
        self.assertEqual((self.dir / "again.csv").read_bytes(), (self.dir / "d.csv").read_bytes())
        default = self.cli("trial", *TRIAL, *FIXED_V3, *NO_END_GAP, *NO_CENTRED, "--csv", "400.csv")
        self.assertEqual(default.returncode, 0, default.stderr)
        self.assertNotEqual((self.dir / "d.csv").read_bytes(), (self.dir / "400.csv").read_bytes())

    def test_a_version_1_session_json_beside_version_3_records(self):
        session = self.study_copy()
        manifest = session / "session.json"
        d = read_json(manifest)
        d["version"] = 1
        for planned in d["plan"]:
            planned["block"] -= 1
            planned["item"] -= 1
        write_json(manifest, d)
        got, trials = self.report()
        self.assertEqual(got.returncode, 0, got.stderr)
        kept = ("trial", "block", "item", "phase", "condition", "strokes_accepted", "trace_sha256")
        self.assertEqual([[r[k] for k in kept] for r in self.rows(trials)],
                         [[r[k] for k in kept] for r in self.trials0])
        study = self.python().study.load(str(self.dir / "st"))
        self.assertEqual(sorted(study.trials["item"].tolist()), [1, 1])

    def test_study_identity_of_a_version_that_does_not_exist(self):
        cg = self.python()
        for text in (str(2 ** 32 + 1), "2", "0", "-1", "null", '"1"'):
            with self.subTest(version=text):
                shutil.rmtree(self.dir / "st", ignore_errors=True)
                self.study_copy()
                identity = self.dir / "st" / ".calligraphy-study.json"
                d = read_json(identity)
                d["version"] = "@"
                identity.write_text(json.dumps(d).replace('"version": "@"', f'"version": {text}'), encoding="utf-8")
                got, _ = self.report()
                self.assert_one_error(got, 1, ".calligraphy-study.json", "/version")
                with self.assertRaises(cg.DataError) as caught:
                    cg.study.load(str(self.dir / "st"))
                self.assertIn(".calligraphy-study.json", str(caught.exception))

    def test_trace_samples_attribute_other_than_its_columns(self):
        try:
            import h5py
            import numpy
        except ImportError as e:
            self.skipTest(f"h5py is missing: {e}")
        for change in (1, -1, 2 ** 32):
            with self.subTest(change=change):
                path = self.trace_copy()
                with h5py.File(path, "r+") as f:
                    f.attrs["samples"] = numpy.uint64(int(f.attrs["samples"]) + change)
                reseal_trace(path)
                self.assert_one_error(self.cli("trace", path), 1, "t.trace.h5", "samples")

    def test_trace_column_attributes_of_another_type_or_missing(self):
        try:
            import h5py
            import numpy
        except ImportError as e:
            self.skipTest(f"h5py is missing: {e}")
        cg = self.python()
        original = self.cli("trace", self.trace_copy())
        self.assertEqual(original.returncode, 0, original.stderr)
        # An integer of another width is the same whole number: read as the file the program writes.
        path = self.trace_copy()
        with h5py.File(path, "r+") as f:
            f["x"].attrs["decimals"] = numpy.int64(7)
        reseal_trace(path)
        wider = self.cli("trace", path)
        self.assertEqual((wider.returncode, wider.stdout), (0, original.stdout), wider.stderr)
        forgeries = {"decimals as a double": lambda f: f["x"].attrs.__setitem__("decimals", numpy.float64(7.0)),
                     "decimals missing": lambda f: f["x"].attrs.__delitem__("decimals"),
                     "decimals of another version": lambda f: f["x"].attrs.__setitem__("decimals", numpy.int32(4)),
                     "unit in mm": lambda f: f["x"].attrs.__setitem__("unit", numpy.bytes_(b"mm")),
                     "unit missing": lambda f: f["t"].attrs.__delitem__("unit")}
        for name, forge in forgeries.items():
            with self.subTest(forgery=name):
                path = self.trace_copy()
                with h5py.File(path, "r+") as f:
                    forge(f)
                reseal_trace(path)
                column = "/t/" if name == "unit missing" else "/x/"
                self.assert_one_error(self.cli("trace", path), 1, "t.trace.h5", column)
                with self.assertRaises(cg.DataError) as caught:
                    self.samples_of_forged(cg, path)
                self.assertIn("001-test-V-r1-U4E00.trace.h5", str(caught.exception))
                self.assertIn(column, str(caught.exception))

    def samples_of_forged(self, cg, trace):
        """The forged trace as trial 1's of a copy of the study, its record naming its SHA-256: study.samples."""
        shutil.rmtree(self.dir / "st", ignore_errors=True)
        session = self.study_copy()
        stem = "001-test-V-r1-U4E00"
        shutil.copyfile(trace, session / "trials" / f"{stem}.trace.h5")
        self.forge_study_record(session, stem, lambda r: r["files"].update(
            trace_sha256=sha256(session / "trials" / f"{stem}.trace.h5")))
        return self.samples_of_trial_1(cg, self.dir / "st")

    def test_teacher_recording_of_a_version_a_narrower_integer_would_wrap(self):
        made = self.cli("trial", YI, "--writer-profile", "skilled", "--seed", "1", "--max-duration", "8",
                        "--record", "t.json")
        self.assertEqual(made.returncode, 0, made.stderr)
        good = read_json(self.dir / "t.json")
        for text in (str(good["version"] + 2 ** 32), str(good["version"] - 2 ** 32), "0", str(2 ** 64 + 1)):
            with self.subTest(version=text):
                teacher = self.dir / "bad.json"
                teacher.write_text(json.dumps(dict(good, version="@")).replace('"version": "@"', f'"version": {text}'),
                                   encoding="utf-8")
                got = self.cli("trial", YI, "--guidance-mode", "replay", "--teacher", teacher, "--max-duration", "1")
                self.assert_one_error(got, (1, 2), "bad.json", "/version")


if __name__ == "__main__":
    unittest.main()
