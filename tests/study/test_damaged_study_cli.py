#!/usr/bin/env python3
"""Damaged study files through the program, run by CTest as `study_damaged_cli`: every value of a trial
record, a session manifest and a protocol replaced by one of another type or beyond a double's range gives
the data error (exit 1) naming the file, never an internal error (exit 3); a record whose specification
`trial --spec` refuses is refused by every reader naming the record and the pointer, and `trial --spec` of a
study's record checks its own format and version; a trial that wrote no stroke is
shown on the report page; subnormal option values are finite; the cohort's tables are replaced together or
not at all, also when the cohort is killed.

Every damaged copy of a file is one or two runs of the program: all of them (about 1,200) take minutes, so
each run of the tests draws CALLIGRAPHY_DAMAGE_SAMPLE of them per file (default 60; 0 for all) with the seed
CALLIGRAPHY_TEST_SEED (random when unset, printed), as the C++ sweeps do (tests/test_sizing.hpp).

CALLIGRAPHY_CLI names the program, CALLIGRAPHY_SOURCE_DIR the source tree. Standard library only.
"""
import hashlib
import json
import os
import random
import resource
import shutil
import signal
import subprocess
import tempfile
import time
import unittest
from pathlib import Path

from study_protocols import two_session_protocol

CLI = os.environ.get("CALLIGRAPHY_CLI", "")
SOURCE = Path(os.environ.get("CALLIGRAPHY_SOURCE_DIR", Path(__file__).resolve().parents[2]))

PROTOCOL = two_session_protocol("damage")

# Values of other types, and numbers a double cannot hold (written into the text: json.dumps refuses them).
SAMPLE = int(os.environ.get("CALLIGRAPHY_DAMAGE_SAMPLE", "60"))
SEED = int(os.environ.get("CALLIGRAPHY_TEST_SEED") or random.SystemRandom().randrange(1 << 32))
print(f"study_damaged_cli: {SAMPLE or 'all'} damaged copies per file, seed {SEED} "
      f"(CALLIGRAPHY_DAMAGE_SAMPLE, CALLIGRAPHY_TEST_SEED)", flush=True)
# The cohort that is killed: 8 subjects, 4 under the sanitizers (ten times slower there; the property is
# about the moment of the kill, not the cohort's size).
COHORT = "8"
WRONG_VALUES = ["5", "\"x\"", "[]", "{}", "true", "null", "[1e999]", "1e999", "-1e999", "1e400"]


def digest(path):
    return hashlib.sha256(path.read_bytes()).hexdigest()


class DamagedStudyTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        if not CLI or not Path(CLI).exists():
            raise unittest.SkipTest(f"CALLIGRAPHY_CLI={CLI!r} is not the calligraphy program: run through ctest")
        cls.pristine = tempfile.TemporaryDirectory(prefix="calligraphy-damaged-")
        root = Path(cls.pristine.name)
        (root / "p.json").write_text(json.dumps(PROTOCOL, ensure_ascii=False), encoding="utf-8")
        done = subprocess.run([CLI, "session", "run", "p.json", "--writer", "simulated", "--subjects", "1",
                               "--out", "S"], cwd=root, capture_output=True, timeout=600)
        assert done.returncode == 0, done.stderr.decode()
        cls.sessions = sorted(p for p in (root / "S" / "S01").iterdir() if p.is_dir())
        assert len(cls.sessions) == 2

    @classmethod
    def tearDownClass(cls):
        cls.pristine.cleanup()

    def setUp(self):
        self.folder = tempfile.TemporaryDirectory(prefix="calligraphy-damaged-run-")
        self.cwd = Path(self.folder.name)
        shutil.copytree(Path(self.pristine.name), self.cwd, dirs_exist_ok=True)

    def tearDown(self):
        self.folder.cleanup()

    def run_cli(self, *args):
        return subprocess.run([CLI, *map(str, args)], cwd=self.cwd, capture_output=True, timeout=600)

    def first_session(self):
        return self.cwd / "S" / "S01" / self.sessions[0].name

    def assert_data_error(self, result, file_name, what):
        stderr = result.stderr.decode()
        self.assertEqual(result.returncode, 1, f"{what}: exit {result.returncode}: {stderr}")
        self.assertNotIn("internal error", stderr, what)
        self.assertIn(file_name, stderr, what)

    def assert_protocol_error(self, result, file_name, what):
        """A protocol's content refused: a usage error (exit 2), one line naming the file."""
        stderr = result.stderr.decode()
        self.assertEqual(result.returncode, 2, f"{what}: exit {result.returncode}: {stderr}")
        self.assertNotIn("internal error", stderr, what)
        self.assertEqual(len(stderr.strip().splitlines()), 1, stderr)
        self.assertIn(file_name, stderr, what)

    def damaged_copies(self, path):
        """(description, text) for the JSON file at `path` with one value replaced by a wrong one: every
        member at any depth (every element of an array of up to 3, else the first), each top-level one by
        every wrong value, deeper ones by three in turn."""
        original = json.loads(path.read_text(encoding="utf-8"))
        paths = []

        def walk(value, at):
            paths.append(at)
            if isinstance(value, dict):
                for key, member in value.items():
                    walk(member, at + [key])
            elif isinstance(value, list):
                for index, element in enumerate(value if len(value) <= 3 else value[:1]):
                    walk(element, at + [index])

        walk(original, [])
        cases = []
        for number, at in enumerate(paths[1:]):
            wrongs = WRONG_VALUES if len(at) == 1 else [WRONG_VALUES[(number + k) % len(WRONG_VALUES)]
                                                        for k in (0, 3, 6)]
            cases.extend((at, wrong) for wrong in wrongs)
        if 0 < SAMPLE < len(cases):
            cases = random.Random(f"{SEED}:{path.name}").sample(cases, SAMPLE)
        for at, wrong in cases:
            document = json.loads(json.dumps(original))
            parent = document
            for step in at[:-1]:
                parent = parent[step]
            parent[at[-1]] = "@@"
            pointer = "/" + "/".join(str(step) for step in at)
            yield f"{path.name}: {pointer} = {wrong}", json.dumps(document).replace("\"@@\"", wrong)

    def test_every_wrong_value_of_a_trial_record_is_a_data_error_naming_the_file(self):
        record = sorted((self.first_session() / "trials").glob("*.json"))[0]
        text = record.read_text(encoding="utf-8")
        for what, damaged in self.damaged_copies(record):
            with self.subTest(what):
                record.write_text(damaged, encoding="utf-8")
                for command in (["report", "S", "--csv", "."], ["report", "S", "--out", "r.html"]):
                    result = self.run_cli(*command)
                    # A key its readers do not need may hold anything; one they read is named.
                    if result.returncode != 0:
                        self.assert_data_error(result, record.name, f"{what} ({command[2]})")
        record.write_text(text, encoding="utf-8")

    def test_a_record_of_an_unknown_version_is_refused_by_every_reader(self):
        """A newer (or damaged) version is never read as the current one: every command that reads records
        refuses it naming the file and /version; the current version is read."""
        record = sorted((self.first_session() / "trials").glob("*.json"))[0]
        original = json.loads(record.read_text(encoding="utf-8"))
        subject = original["subject"]
        readers = (["report", "S", "--csv", "."], ["report", "S", "--out", "r.html"],
                   ["curriculum", "S", "--subject", subject, "--from", "永十"])
        for version in (4, 99, 0, -1, "2", 2.5, None):
            with self.subTest(version=version):
                document = dict(original)
                if version is None:
                    del document["version"]
                else:
                    document["version"] = version
                record.write_text(json.dumps(document), encoding="utf-8")
                for command in readers:
                    result = self.run_cli(*command)
                    self.assert_data_error(result, record.name, f"version {version!r} ({' '.join(command[:2])})")
                    self.assertIn("/version", result.stderr.decode())
        record.write_text(json.dumps(original), encoding="utf-8")
        for command in readers:
            result = self.run_cli(*command)
            self.assertEqual(result.returncode, 0, result.stderr.decode())

    # One field of a record's specification forged as `trial --spec RECORD --check` refuses it: (pointer, value).
    FORGED_SPECIFICATIONS = (("/specification/version", 10), ("/specification/force_law/crossfade_s", -1.0),
                             ("/specification/trial/max_duration_s", "20"))

    def forge(self, document, pointer, value):
        """A copy of `document` with the member at the JSON `pointer` set to `value`."""
        forged = json.loads(json.dumps(document))
        *path, last = pointer.strip("/").split("/")
        parent = forged
        for step in path:
            parent = parent[step]
        parent[last] = value
        return forged

    def assert_one_line(self, result, status, *needles):
        stderr = result.stderr.decode()
        self.assertEqual(result.returncode, status, stderr)
        self.assertNotIn("internal error", stderr)
        self.assertEqual(len(stderr.strip().splitlines()), 1, stderr)
        for needle in needles:
            self.assertIn(needle, stderr)

    def test_a_record_whose_specification_cannot_run_again_is_refused_by_every_reader(self):
        """The study's readers read a record's specification through `trial --spec`'s one reader: a field that
        reader refuses is refused by the report's tables and page and the curriculum (damaged data, exit 1) and by
        `session resume`, whose folder's content it is (exit 2, as for its session.json), each in one line naming
        the record and the pointer; the untouched study reports the same tables byte for byte."""
        record = sorted((self.first_session() / "trials").glob("*.json"))[0]
        text = record.read_text(encoding="utf-8")
        original = json.loads(text)
        (self.cwd / "before").mkdir()
        self.assertEqual(self.run_cli("report", "S", "--csv", "before").returncode, 0)
        before = {p.name: p.read_bytes() for p in (self.cwd / "before").iterdir()}
        readers = (["report", "S", "--csv", "."], ["report", "S", "--out", "r.html"],
                   ["curriculum", "S", "--subject", original["subject"], "--from", "十"],
                   ["session", "resume", self.first_session()])
        for pointer, value in self.FORGED_SPECIFICATIONS:
            with self.subTest(pointer=pointer, value=value):
                record.write_text(json.dumps(self.forge(original, pointer, value)), encoding="utf-8")
                self.assert_one_line(self.run_cli("trial", "--spec", record, "--check"), 2, record.name, pointer)
                for command in readers:
                    status = 2 if command[:2] == ["session", "resume"] else 1
                    self.assert_one_line(self.run_cli(*command), status, record.name, pointer)
                self.assertFalse((self.cwd / "r.html").exists())
        record.write_text(text, encoding="utf-8")
        for command in readers[2:]:
            result = self.run_cli(*command)
            self.assertEqual(result.returncode, 0, result.stderr.decode())
        (self.cwd / "after").mkdir()
        self.assertEqual(self.run_cli("report", "S", "--csv", "after").returncode, 0)
        self.assertEqual({p.name: p.read_bytes() for p in (self.cwd / "after").iterdir()}, before)

    def test_trial_spec_of_a_study_record_checks_the_records_own_format_and_version(self):
        """`trial --spec` of a study's record reads its top-level format and version as the study's readers do:
        another format or a version they do not read is refused (exit 2, one line naming the record and the
        pointer); the record as written is a valid specification."""
        record = sorted((self.first_session() / "trials").glob("*.json"))[0]
        original = json.loads(record.read_text(encoding="utf-8"))
        for pointer, value in (("/format", "calligraphy-session"), ("/format", 5), ("/version", 4),
                               ("/version", 0), ("/version", "3")):
            with self.subTest(pointer=pointer, value=value):
                record.write_text(json.dumps(self.forge(original, pointer, value)), encoding="utf-8")
                self.assert_one_line(self.run_cli("trial", "--spec", record, "--check"), 2, record.name, pointer)
                self.assertEqual(self.run_cli("report", "S", "--csv", ".").returncode, 1)
        record.write_text(json.dumps(original), encoding="utf-8")
        result = self.run_cli("trial", "--spec", record, "--check")
        self.assertEqual(result.returncode, 0, result.stderr.decode())

    def test_a_huge_or_odd_subject_id_is_refused_before_it_reaches_a_table(self):
        manifest = self.first_session() / "session.json"
        original = json.loads(manifest.read_text(encoding="utf-8"))
        for subject, words in (("X" * 15_000_000, "at most 65536 bytes"), ("S 01\n", "letters, digits"),
                               ("", "letters, digits")):
            with self.subTest(subject=subject[:10]):
                document = json.loads(json.dumps(original))
                document["subject"]["id"] = subject
                manifest.write_text(json.dumps(document), encoding="utf-8")
                result = self.run_cli("report", "S", "--csv", ".")
                self.assert_data_error(result, "session.json", f"subject {subject[:10]!r}")
                self.assertIn("/subject/id", result.stderr.decode())
                self.assertIn(words, result.stderr.decode())
                self.assertLess(len(result.stderr), 3000)
        manifest.write_text(json.dumps(original), encoding="utf-8")

    def test_an_unknown_writer_or_profile_in_a_session_manifest_names_the_manifest(self):
        manifest = self.first_session() / "session.json"
        original = json.loads(manifest.read_text(encoding="utf-8"))
        for key, wrong in (("writer", "x"), ("writer", "human"), ("writer_profile", "x")):
            with self.subTest(key=key, wrong=wrong):
                manifest.write_text(json.dumps(dict(original, **{key: wrong})), encoding="utf-8")
                result = self.run_cli("report", "S", "--csv", ".")
                self.assert_data_error(result, "session.json", f"{key} = {wrong!r}")
                self.assertIn(f"/{key}", result.stderr.decode())
        manifest.write_text(json.dumps(original), encoding="utf-8")

    def test_every_wrong_value_of_a_session_manifest_is_a_data_error_naming_the_file(self):
        manifest = self.first_session() / "session.json"
        for what, damaged in self.damaged_copies(manifest):
            with self.subTest(what):
                manifest.write_text(damaged, encoding="utf-8")
                result = self.run_cli("report", "S", "--csv", ".")
                if result.returncode != 0:
                    self.assert_data_error(result, "session.json", what)

    def test_a_previous_session_end_of_another_type_is_named_by_session_run(self):
        shutil.rmtree(self.cwd / "S" / "S01" / self.sessions[1].name)
        last = sorted((self.first_session() / "trials").glob("*.json"))[-1]
        original = json.loads(last.read_text(encoding="utf-8"))
        for wrong in ["12345", "null", "[]", "\"yesterday\"", "1e999"]:
            with self.subTest(end_time_utc=wrong):
                document = dict(original, end_time_utc="@@")
                last.write_text(json.dumps(document).replace("\"@@\"", wrong), encoding="utf-8")
                result = self.run_cli("session", "run", "p.json", "--writer", "simulated", "--subject", "S01",
                                      "--out", "S")
                self.assert_data_error(result, last.name, f"end_time_utc {wrong}")
                self.assertIn("/end_time_utc", result.stderr.decode())
                if wrong == "null":  # no end recorded: not the session's creation time in its place
                    self.assertIn("did not end", result.stderr.decode())

    def test_every_wrong_value_of_a_protocol_is_refused_naming_the_file(self):
        # A protocol with guidance parameters, groups and a transfer choice: more members to damage.
        protocol = self.cwd / "retention-transfer.json"
        shutil.copyfile(SOURCE / "examples" / "protocols" / "retention-transfer.json", protocol)
        for what, damaged in self.damaged_copies(protocol):
            with self.subTest(what):
                (self.cwd / "bad.json").write_text(damaged, encoding="utf-8")
                result = self.run_cli("session", "run", "bad.json", "--writer", "simulated", "--subjects", "1",
                                      "--out", "T")
                shutil.rmtree(self.cwd / "T", ignore_errors=True)
                if result.returncode != 0:
                    self.assert_protocol_error(result, "bad.json", what)

    def test_protocol_numbers_beyond_a_double_name_the_pointer(self):
        for wrong in ["1e999", "-1e999", "1e400"]:
            with self.subTest(wrong):
                text = json.dumps(PROTOCOL).replace("\"max_duration_s\": 20", f"\"max_duration_s\": {wrong}")
                (self.cwd / "bad.json").write_text(text, encoding="utf-8")
                result = self.run_cli("session", "run", "bad.json", "--writer", "simulated", "--subjects", "1",
                                      "--out", "T")
                self.assert_protocol_error(result, "bad.json", wrong)
                self.assertIn("/trial/max_duration_s", result.stderr.decode())

    def test_a_trial_that_wrote_no_stroke_is_shown_on_the_page(self):
        record = sorted((self.first_session() / "trials").glob("*.json"))[0]
        document = json.loads(record.read_text(encoding="utf-8"))
        for key in ("mean_deviation_m", "max_deviation_m", "rms_deviation_m", "frechet_m", "dtw_m",
                    "normalised_jerk"):
            document[key] = None
        document["end_reason"] = "time_limit"
        for stroke in document["per_stroke"]:
            stroke.update(start_s=None, end_s=None)
        record.write_text(json.dumps(document), encoding="utf-8")
        result = self.run_cli("report", "S", "--out", "r.html")
        self.assertEqual(result.returncode, 0, result.stderr.decode())
        # The trial is on its session's page, beside the index.
        page = (self.cwd / "r_files" / "S01" / f"{record.parents[1].name}.html").read_text(encoding="utf-8")
        self.assertIn("time_limit", page)
        self.assertNotIn("nan", page.lower().replace("nano", ""))

    def test_subnormal_numbers_are_finite_options(self):
        for option in (["--guidance-mode", "assist-as-needed", "--assist-band", "1e-310"],
                       ["--guidance-mode", "fading", "--guidance-gain", "1e-310"]):
            with self.subTest(option):
                result = self.run_cli("trial", "十", *option, "--json", "t.json")
                self.assertEqual(result.returncode, 0, result.stderr.decode())
        refused = self.run_cli("trial", "十", "--guidance-gain", "1e999", "--json", "t.json")
        self.assertEqual(refused.returncode, 2)
        self.assertIn("--guidance-gain", refused.stderr.decode())

    def test_a_cohort_that_fails_while_writing_keeps_the_previous_pair_of_tables(self):
        first = self.run_cli("session", "cohort", "p.json", "--subjects", "1", "--csv", ".")
        self.assertEqual(first.returncode, 0, first.stderr.decode())
        before = {name: digest(self.cwd / name) for name in ("trials.csv", "strokes.csv")}
        # The sizes the next run's tables will have (the same subjects give the same rows), measured apart.
        (self.cwd / "sizes").mkdir()
        measured = self.run_cli("session", "cohort", "p.json", "--subjects", "3", "--csv", "sizes")
        self.assertEqual(measured.returncode, 0, measured.stderr.decode())
        sizes = {name: (self.cwd / "sizes" / name).stat().st_size for name in ("trials.csv", "strokes.csv")}
        self.assertNotEqual(sizes["trials.csv"], sizes["strokes.csv"])
        larger = max(sizes, key=sizes.get)
        # Files beyond this size cannot be written (EFBIG), as on a full disk: the smaller table is written
        # whole, the larger fails.
        limit = sum(sizes.values()) // 2

        def small_files():
            signal.signal(signal.SIGXFSZ, signal.SIG_IGN)
            resource.setrlimit(resource.RLIMIT_FSIZE, (limit, limit))

        failed = subprocess.run([CLI, "session", "cohort", "p.json", "--subjects", "3", "--csv", "."],
                                cwd=self.cwd, capture_output=True, timeout=600, preexec_fn=small_files)
        self.assertEqual(failed.returncode, 1, failed.stderr.decode())
        self.assertIn(larger, failed.stderr.decode())
        self.assertEqual(before, {name: digest(self.cwd / name) for name in before})
        self.assertEqual([p.name for p in self.cwd.glob(".*tmp*")], [])

    @unittest.skipIf(os.environ.get("CALLIGRAPHY_SANITIZED"), "kills at moments of a run: the Release run's "
                     "(what a sanitizer looks for shows in the cohort runs the other cases make)")
    def test_a_cohort_killed_at_any_moment_leaves_one_whole_pair_of_tables(self):
        first = self.run_cli("session", "cohort", "p.json", "--subjects", "1", "--csv", ".")
        self.assertEqual(first.returncode, 0, first.stderr.decode())
        pairs = [{name: (self.cwd / name).read_bytes() for name in ("trials.csv", "strokes.csv")}]
        (self.cwd / "whole").mkdir()
        whole = self.run_cli("session", "cohort", "p.json", "--subjects", COHORT, "--csv", "whole")
        self.assertEqual(whole.returncode, 0, whole.stderr.decode())
        pairs.append({name: (self.cwd / "whole" / name).read_bytes() for name in ("trials.csv", "strokes.csv")})
        # SIGKILL at moments spread over a run, the last ones about when the tables are written.
        moments = (0.2, 0.5, 0.8, 0.9, 0.95, 1.0, 1.05)
        for fraction in moments:
            run = subprocess.Popen([CLI, "session", "cohort", "p.json", "--subjects", COHORT, "--csv", "."],
                                   cwd=self.cwd, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
            time.sleep(fraction * self.cohort_seconds)
            run.kill()
            run.wait()
            found = {name: (self.cwd / name).read_bytes() for name in ("trials.csv", "strokes.csv")}
            self.assertIn(found, pairs, f"killed after {fraction:.2f} of a run")

    @property
    def cohort_seconds(self):
        """How long a cohort of COHORT subjects takes here, measured once."""
        if not hasattr(self, "_cohort_seconds"):
            (self.cwd / "timed").mkdir(exist_ok=True)
            begin = time.monotonic()
            timed = self.run_cli("session", "cohort", "p.json", "--subjects", COHORT, "--csv", "timed")
            self.assertEqual(timed.returncode, 0, timed.stderr.decode())
            self._cohort_seconds = time.monotonic() - begin
        return self._cohort_seconds


class DamagedRecogniserModelTest(unittest.TestCase):
    """A damaged zinnia model (the legibility recogniser's, CALLIGRAPHY_ZINNIA_MODEL) never costs a trial: each
    forged model below (a character count of 2^31 - 1 that makes zinnia allocate gigabytes, a file cut inside
    a character, a foreign file, an empty one) leaves the trials saved without legibility, exit 0, and one
    warning naming the model and what is wrong with it."""

    def test_a_damaged_model_keeps_every_trial_and_says_why(self):
        import struct

        magic = 0x0F6E6FA1
        character = "一".encode("utf-8").ljust(16, b"\0") + struct.pack("<f", 0.5)
        models = {
            "count": (struct.pack("<iii", magic, 1, 2**31 - 1) + character + struct.pack("<if", -1, 0.0),
                      "declares 2147483647 characters"),
            "cut": (struct.pack("<iii", magic, 1, 2) + character + struct.pack("<if", 3, 0.25) * 8, "cut in character 1"),
            "foreign": (b"%PDF-1.4 not a model at all" * 10, "not a zinnia model"),
            "empty": (b"", "not a zinnia model"),
        }
        protocol = {"name": "legible", "conditions": [{"name": "free", "mode": "vision"}],
                    "test": {"characters": ["十"], "conditions": ["free"], "repetitions": 1},
                    "trial": {"max_duration_s": 30}}
        with tempfile.TemporaryDirectory(prefix="calligraphy-zinnia-") as folder:
            cwd = Path(folder)
            (cwd / "p.json").write_text(json.dumps(protocol, ensure_ascii=False), encoding="utf-8")
            for name, (data, why) in models.items():
                with self.subTest(model=name):
                    model = cwd / f"{name}.model"
                    model.write_bytes(data)
                    run = subprocess.run([CLI, "session", "run", "p.json", "--writer", "simulated", "--subjects", "1",
                                          "--out", f"S-{name}"], cwd=cwd, capture_output=True, timeout=300,
                                         env={**os.environ, "CALLIGRAPHY_ZINNIA_MODEL": str(model)})
                    stderr = run.stderr.decode()
                    self.assertEqual(run.returncode, 0, stderr)
                    warnings = [line for line in stderr.splitlines() if "legibility" in line]
                    self.assertEqual(len(warnings), 1, stderr)
                    self.assertIn(str(model), warnings[0])
                    self.assertIn(why, warnings[0])
                    records = [p for p in (cwd / f"S-{name}").rglob("trials/*.json")]
                    self.assertEqual(len(records), 1)
                    self.assertNotIn("legibility", json.loads(records[0].read_text(encoding="utf-8")))


if __name__ == "__main__":
    unittest.main()
