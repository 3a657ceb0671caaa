#!/usr/bin/env python3
"""Hostile cases written from the documentation alone (docs/cli.md, docs/experiments.md, docs/python.md and
the program's own `--help` and `schema` output) on the protocol's conditions, the session folders, the trial
records `trial --spec` runs again, and the stroke numbers people read. Run by CTest as
`cli_unseen_round7_tests`.

Each case asserts what the documentation promises: exit status 2 for content a command is given (a protocol,
`session resume`'s session.json, a `--spec` record), 1 for damaged data another reader finds (`report`,
Python's `DataError`), one error line naming the file and the JSON pointer or the file at fault, nothing
written when refused, no hang on a FIFO, strokes numbered from 1 in every table and from 0 in every JSON.

CALLIGRAPHY_CLI names the program, CALLIGRAPHY_SOURCE_DIR the source tree; the built Python package is found
on PYTHONPATH (its cases are skipped without it). CALLIGRAPHY_SANITIZED=1 takes a subset of the spellings.
"""
import hashlib
import json
import os
import shutil
import subprocess
import tempfile
import unittest
from pathlib import Path

CLI = os.environ.get("CALLIGRAPHY_CLI", "")
TIMEOUT_S = 60
SANITIZED = os.environ.get("CALLIGRAPHY_SANITIZED") == "1"
SHI = "十"


def sample(cases):
    return cases[::3] if SANITIZED else cases


# Under the sanitizers (ten times slower) the cases that run several trials or parse megabytes are left out.
heavy = unittest.skipIf(SANITIZED, "several trials or megabytes of JSON: left to the Release run")


try:
    import numpy  # noqa: F401  (the package needs it)
    import calligraphy as cg
    import calligraphy.study as cg_study
except ImportError:  # pragma: no cover - a build without the Python bindings
    cg = None
    cg_study = None


def run(args, cwd):
    return subprocess.run([CLI, *map(str, args)], cwd=cwd, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                          timeout=TIMEOUT_S)


def protocol(*conditions, trial=None, extra=None):
    """A protocol text: the conditions given (JSON texts, so that any spelling can be given), 十 once each."""
    names = []
    for text in conditions:
        try:
            names.append(json.loads(text)["name"])
        except (ValueError, KeyError, TypeError):
            names.append("c")
    test = {"characters": [SHI], "conditions": sorted(set(n for n in names if isinstance(n, str))) or ["c"],
            "repetitions": 1}
    body = ('{"name": "p", "conditions": [' + ", ".join(conditions) + '], "test": ' + json.dumps(test)
            + ', "trial": ' + json.dumps(trial or {"max_duration_s": 20}))
    if extra:
        body += ", " + extra
    return body + "}"


def snapshot(folder):
    """Every entry under `folder`: its kind and, for a regular file, the SHA-256 of its bytes."""
    state = {}
    for path in sorted(Path(folder).rglob("*")):
        rel = str(path.relative_to(folder))
        if path.is_symlink():
            state[rel] = ("link", os.readlink(path))
        elif path.is_file():
            state[rel] = ("file", hashlib.sha256(path.read_bytes()).hexdigest())
        else:
            state[rel] = ("other", None)
    return state


class Shared:
    """A study of two simulated subjects through a haptic and a quiz trial of 十, made once, and a trial record."""
    folder = None

    @classmethod
    def get(cls):
        if cls.folder is None:
            cls.folder = tempfile.TemporaryDirectory(prefix="calligraphy-unseen7-shared-")
            root = Path(cls.folder.name)
            (root / "p.json").write_text(protocol('{"name": "h", "mode": "haptic"}',
                                                  '{"name": "q", "mode": "quiz"}'), encoding="utf-8")
            result = run(["session", "run", "p.json", "--subjects", "2", "--out", "study"], root)
            assert result.returncode == 0, result.stderr.decode(errors="replace")
            result = run(["trial", SHI, "--seed", "1", "--json", "r.json", "--csv", "r.csv"], root)
            assert result.returncode == 0, result.stderr.decode(errors="replace")
            result = run(["trial", "人", "--seed", "1", "--json", "other.json"], root)
            assert result.returncode == 0, result.stderr.decode(errors="replace")
        return Path(cls.folder.name)


class Case(unittest.TestCase):
    def setUp(self):
        if not CLI or not Path(CLI).exists():
            self.fail(f"CALLIGRAPHY_CLI={CLI!r} is not the calligraphy program: run these tests through ctest")
        self.folder = tempfile.TemporaryDirectory(prefix="calligraphy-unseen7-")
        self.cwd = Path(self.folder.name)

    def tearDown(self):
        self.folder.cleanup()

    def cli(self, *args):
        return run(args, self.cwd)

    def error_line(self, result, status):
        message = result.stderr.decode(errors="replace")
        self.assertEqual(result.returncode, status, message)
        errors = [line for line in message.splitlines() if ": error: " in line]
        self.assertEqual(len(errors), 1, message)
        self.assertNotIn("Traceback", message)
        return errors[0]

    def assert_error(self, result, status, *names):
        line = self.error_line(result, status)
        for name in names:
            self.assertIn(str(name), line)
        return line

    def assert_ok(self, result):
        self.assertEqual(result.returncode, 0, result.stderr.decode(errors="replace"))

    # The study made once, copied for each case that edits it.
    def study(self):
        target = self.cwd / "study"
        if target.exists():
            shutil.rmtree(target)
        tables = self.cwd / "tables"
        if tables.exists():
            shutil.rmtree(tables)
        shutil.copytree(Shared.get() / "study", target, symlinks=True)
        shutil.copy(Shared.get() / "p.json", self.cwd / "p.json")
        sessions = sorted(p for p in target.glob("S0*/p-*") if p.is_dir())
        self.assertEqual(len(sessions), 2)
        return target, sessions

    def records(self, session):
        return sorted((session / "trials").glob("*.json"))


class ProtocolConditionCases(Case):
    """Every mode's parameters abused, through `session plan` (and `session run` for a few): exit 2, one line
    naming the protocol file and the value's JSON pointer, no folder made."""

    def refused(self, text, *pointer_parts, command="plan"):
        """`text` a whole protocol, or one condition (put in a protocol of its own)."""
        if '"test"' not in text:
            text = protocol(text)
        (self.cwd / "bad.json").write_text(text, encoding="utf-8")
        if command == "plan":
            result = self.cli("session", "plan", "bad.json", "--subjects", "1")
        else:
            result = self.cli("session", "run", "bad.json", "--subjects", "1", "--out", "out")
            self.assertFalse((self.cwd / "out").exists(), "a refused protocol made the study folder")
        return self.assert_error(result, 2, "bad.json", *pointer_parts)

    def test_unknown_key_in_each_mode(self):
        modes = ["vision", "haptic", "quiz", "fading", "assist-as-needed", "error-amplification", "skill-adaptive",
                 "timing"]
        for mode in sample(modes):
            with self.subTest(mode=mode):
                self.refused(json.dumps({"name": "c", "mode": mode, "bogus_key": 1}), "/conditions/0", "bogus_key")

    def test_key_of_another_mode(self):
        cases = [
            ('{"name": "c", "mode": "vision", "guidance_stiffness_n_per_m": 300}', "/conditions/0"),
            ('{"name": "c", "mode": "haptic", "parameters": {"speed_m_s": 0.04}}', "/conditions/0"),
            ('{"name": "c", "mode": "timing", "parameters": {"start_gain": 1.0}}', "/conditions/0/parameters"),
            ('{"name": "c", "mode": "fading", "parameters": {"max_lead_m": 0.01}}', "/conditions/0/parameters"),
            ('{"name": "c", "mode": "haptic", "quiz": {"hint_after_misses": 2}}', "/conditions/0"),
            ('{"name": "c", "mode": "vision", "teachers": {}}', "/conditions/0"),
        ]
        for text, pointer in sample(cases):
            with self.subTest(text=text):
                self.refused(text, pointer)

    def test_null_string_and_negative_stiffness(self):
        for value in sample(["null", '"400"', "-1", "true", "[400]", "{}"]):
            with self.subTest(value=value):
                self.refused('{"name": "c", "mode": "haptic", "guidance_stiffness_n_per_m": ' + value + "}",
                             "/conditions/0/guidance_stiffness_n_per_m")

    def test_null_for_each_optional_key(self):
        """null is no value: each optional key of a condition and of a quiz given null is refused by name."""
        cases = [
            ('{"name": "c", "mode": "timing", "parameters": null}', "/conditions/0/parameters"),
            ('{"name": "c", "mode": "quiz", "quiz": null}', "/conditions/0/quiz"),
            ('{"name": "c", "mode": "vision", "quiz": null}', "/conditions/0/quiz"),
            ('{"name": "c", "mode": "quiz", "quiz": {"hint_after_misses": null}}', "/conditions/0/quiz/hint_after_misses"),
            ('{"name": "c", "mode": "quiz", "quiz": {"accept_backwards": null}}', "/conditions/0/quiz/accept_backwards"),
            ('{"name": "c", "mode": "timing", "parameters": {"speed_m_s": null}}',
             "/conditions/0/parameters/speed_m_s"),
            ('{"name": "c", "mode": "fading", "guidance_stiffness_n_per_m": null}',
             "/conditions/0/guidance_stiffness_n_per_m"),
            ('{"name": "c", "mode": null}', "/conditions/0/mode"),
            ('{"name": null, "mode": "vision"}', "/conditions/0/name"),
        ]
        for text, pointer in sample(cases):
            with self.subTest(text=text):
                self.refused(text, pointer)

    def test_non_finite_spellings(self):
        for value in sample(["NaN", "nan", "Infinity", "-Infinity", "inf", "1e999", "-1e400", "0x10", "+1", "01"]):
            with self.subTest(value=value):
                self.refused('{"name": "c", "mode": "timing", "parameters": {"speed_m_s": ' + value + "}}")

    def test_huge_stiffness_is_no_crash(self):
        (self.cwd / "p.json").write_text(
            protocol('{"name": "c", "mode": "haptic", "guidance_stiffness_n_per_m": 1e308}'), encoding="utf-8")
        result = self.cli("session", "plan", "p.json", "--subjects", "1")
        self.assertIn(result.returncode, (0, 2), result.stderr.decode(errors="replace"))
        if result.returncode == 2:
            self.assert_error(result, 2, "p.json", "/conditions/0/guidance_stiffness_n_per_m")

    @heavy
    def test_each_bounded_parameter_beyond_its_schema_bounds(self):
        """The bounds `schema protocol` states for each mode's parameters, crossed on each side."""
        schema = json.loads(self.cli("schema", "protocol").stdout)
        text = json.dumps(schema)
        self.assertIn("StudyCondition", text)
        cases = []

        def walk(node, path):
            if isinstance(node, dict):
                props = node.get("properties")
                if isinstance(props, dict) and "parameters" in path:
                    for key, spec in props.items():
                        if isinstance(spec, dict) and spec.get("type") in ("number", "integer"):
                            cases.append((path, key, spec))
                for key, value in node.items():
                    walk(value, path + [key])
            elif isinstance(node, list):
                for i, value in enumerate(node):
                    walk(value, path + [str(i)])

        walk(schema, [])
        self.assertGreater(len(cases), 0, "no mode parameter found in the schema")
        modes = {"start_gain": "fading", "forgetting_factor": "fading", "error_gain_per_m": "fading",
                 "start_band_m": "assist-as-needed", "target_error_m": "assist-as-needed",
                 "band_rate": "assist-as-needed", "min_band_m": "assist-as-needed", "max_band_m": "assist-as-needed",
                 "amplification_gain": "error-amplification", "max_force_n": "error-amplification",
                 "threshold_m": "skill-adaptive", "speed_m_s": "timing", "max_lead_m": "replay"}
        tried = 0
        for _, key, spec in sample(cases):
            mode = modes.get(key)
            if mode is None or mode == "replay":
                continue
            bad = []
            if "minimum" in spec:
                bad.append(spec["minimum"] - max(1.0, abs(spec["minimum"])))
            if "exclusiveMinimum" in spec:
                bad.append(spec["exclusiveMinimum"])
            if "maximum" in spec:
                bad.append(spec["maximum"] * 2 + 1)
            if "exclusiveMaximum" in spec:
                bad.append(spec["exclusiveMaximum"])
            if spec.get("type") == "integer":
                bad.append(2.5)
            for value in bad:
                with self.subTest(mode=mode, key=key, value=value):
                    tried += 1
                    self.refused(json.dumps({"name": "c", "mode": mode, "parameters": {key: value}}),
                                 "/conditions/0/parameters/" + key)
        self.assertGreater(tried, 0)

    def test_quiz_acceptance_abused(self):
        cases = [
            ('{"acceptance": {"corridor_m": 0}}', "/conditions/0/quiz/acceptance/corridor_m"),
            ('{"acceptance": {"corridor_m": 0.2}}', "/conditions/0/quiz/acceptance/corridor_m"),
            ('{"acceptance": {"corridor_m": null}}', "/conditions/0/quiz/acceptance/corridor_m"),
            ('{"acceptance": {"corridor_m": "0.005"}}', "/conditions/0/quiz/acceptance/corridor_m"),
            ('{"acceptance": {"shortfall_fraction": 1}}', "/conditions/0/quiz/acceptance/shortfall_fraction"),
            ('{"acceptance": {"shortfall_fraction": 0}}', "/conditions/0/quiz/acceptance/shortfall_fraction"),
            ('{"acceptance": {"max_gain_ratio": 0.5}}', "/conditions/0/quiz/acceptance/max_gain_ratio"),
            ('{"acceptance": {"max_gain_ratio": 101}}', "/conditions/0/quiz/acceptance/max_gain_ratio"),
            ('{"acceptance": {"hint_after_misses": 2.5}}', "/conditions/0/quiz/acceptance/hint_after_misses"),
            ('{"acceptance": {"assist_after_misses": 2.5}}', "/conditions/0/quiz/acceptance/assist_after_misses"),
            ('{"acceptance": {"assist_after_misses": -1}}', "/conditions/0/quiz/acceptance/assist_after_misses"),
            ('{"acceptance": {"corridor": 0.005}}', "/conditions/0/quiz/acceptance"),
            ('{"acceptance": [0.005]}', "/conditions/0/quiz/acceptance"),
            ('{"acceptance": null}', "/conditions/0/quiz/acceptance"),
            ('{"leniency": 2}', "/conditions/0/quiz"),
            ('{"hint_after_misses": 2.5}', "/conditions/0/quiz/hint_after_misses"),
            ('{"hint_after_misses": 1001}', "/conditions/0/quiz/hint_after_misses"),
            ('{"hint_after_misses": -1}', "/conditions/0/quiz/hint_after_misses"),
            ('{"hint_after_misses": 1e999}', "/conditions/0/quiz/hint_after_misses"),
            ('{"accept_backwards": "false"}', "/conditions/0/quiz/accept_backwards"),
            ('{"accept_backwards": 0}', "/conditions/0/quiz/accept_backwards"),
        ]
        for quiz, pointer in sample(cases):
            with self.subTest(quiz=quiz):
                self.refused('{"name": "c", "mode": "quiz", "quiz": ' + quiz + "}", pointer)
        self.refused('{"name": "c", "mode": "quiz", "quiz": "strict"}', "/conditions/0/quiz")

    def test_quiz_acceptance_within_range_is_taken(self):
        (self.cwd / "p.json").write_text(protocol(
            '{"name": "c", "mode": "quiz", "quiz": {"acceptance": {"corridor_m": 0.1, "shortfall_fraction": 0.5,'
            ' "max_gain_ratio": 100, "assist_after_misses": 0}, "hint_after_misses": 0}}'), encoding="utf-8")
        self.assert_ok(self.cli("session", "plan", "p.json", "--subjects", "1"))

    def test_integer_fields_given_a_fraction(self):
        cases = [
            (protocol('{"name": "c", "mode": "vision"}').replace('"repetitions": 1', '"repetitions": 2.5'),
             "/test/repetitions"),
            (protocol('{"name": "c", "mode": "vision"}', extra='"breaks": {"every_trials": 2.5}'),
             "/breaks/every_trials"),
            (protocol('{"name": "c", "mode": "vision"}', extra='"order": {"seed": 1.5}'), "/order/seed"),
            (protocol('{"name": "c", "mode": "vision"}', extra='"order": {"seed": -1}'), "/order/seed"),
            (protocol('{"name": "c", "mode": "vision"}', extra='"order": {"seed": 18446744073709551616}'),
             "/order/seed"),
        ]
        for text, pointer in sample(cases):
            with self.subTest(pointer=pointer, text=text[-60:]):
                self.refused(text, pointer)

    def test_same_condition_name_twice(self):
        text = protocol('{"name": "c", "mode": "vision"}', '{"name": "c", "mode": "haptic"}')
        self.refused(text, "/conditions/1")
        self.refused(text, "/conditions/1", command="run")

    def test_mode_spellings(self):
        for mode in sample(["error_amplification", "Haptic", "HAPTIC", "assist_as_needed", " haptic", "haptic ",
                            "Skill-Adaptive", "", "fixed"]):
            with self.subTest(mode=mode):
                self.refused(json.dumps({"name": "c", "mode": mode}), "/conditions/0/mode")

    def test_condition_names(self):
        for name in sample(["a b", "x" * 33, "", "ç", "a/b", "..", 7]):
            with self.subTest(name=name):
                self.refused(json.dumps({"name": name, "mode": "vision"}), "/conditions/0/name")

    def test_refused_run_writes_nothing(self):
        self.refused('{"name": "c", "mode": "haptic", "guidance_stiffness_n_per_m": -5}',
                     "/conditions/0/guidance_stiffness_n_per_m", command="run")

    def test_trial_settings(self):
        cases = [({"max_duration_s": 0}, "/trial/max_duration_s"), ({"max_duration_s": 86401}, "/trial/max_duration_s"),
                 ({"rate_hz": 99}, "/trial/rate_hz"), ({"rate_hz": 10001}, "/trial/rate_hz"),
                 ({"max_duration_s": 20, "rate_hz": None}, "/trial/rate_hz"),
                 ({"max_duration_s": 20, "seed": 3}, "/trial")]
        for trial, pointer in sample(cases):
            with self.subTest(trial=trial):
                self.refused(protocol('{"name": "c", "mode": "vision"}', trial=trial), pointer)

    def replay_protocol(self, teacher):
        (self.cwd / "rp.json").write_text(protocol(json.dumps(
            {"name": "c", "mode": "replay", "teachers": {SHI: teacher}})), encoding="utf-8")

    @heavy
    def test_replay_teacher_that_is_no_recording_is_named_without_waiting(self):
        os.mkfifo(self.cwd / "fifo")
        shutil.copy(Shared.get() / "r.json", self.cwd / "record.json")
        for teacher in sample(["fifo", "missing.json", "record.json", "/dev/zero"]):
            with self.subTest(teacher=teacher):
                self.replay_protocol(teacher)
                out = self.cwd / ("out-" + Path(teacher).name)
                result = self.cli("session", "run", "rp.json", "--subjects", "1", "--out", out)
                self.assertIn(result.returncode, (1, 2), result.stderr.decode(errors="replace"))
                self.assertIn(teacher, self.error_line(result, result.returncode))

    def test_replay_teacher_that_is_no_recording_makes_no_folder(self):
        os.mkfifo(self.cwd / "fifo-early")
        shutil.copy(Shared.get() / "r.json", self.cwd / "record-early.json")
        for teacher in ["missing.json", "fifo-early", "record-early.json", "/dev/zero"]:
            with self.subTest(teacher=teacher):
                self.replay_protocol(teacher)
                result = self.cli("session", "run", "rp.json", "--subjects", "1", "--out", "out")
                self.assertIn(result.returncode, (1, 2), result.stderr.decode(errors="replace"))
                self.assertIn(teacher, self.error_line(result, result.returncode))
                self.assertFalse((self.cwd / "out").exists(), "a session folder was made for a protocol refused")

    @unittest.skipIf(cg is None, "the Python package is not built")
    def test_python_cohort_refuses_a_bad_protocol(self):
        (self.cwd / "bad.json").write_text(protocol('{"name": "c", "mode": "Haptic"}'), encoding="utf-8")
        import calligraphy.cohort as cohort
        with self.assertRaises(cg.DataError) as caught:
            cohort.simulate(str(self.cwd / "bad.json"), 1)
        self.assertIn("/conditions/0/mode", str(caught.exception))


class SessionFolderCases(Case):
    """Session folders edited, cut, linked, swapped: `session resume` exits 2, `report` 1, Python DataError;
    nothing written when refused."""

    def resume_refused(self, session, *names, status=2):
        before = snapshot(session)
        result = self.cli("session", "resume", session)
        line = self.assert_error(result, status, *names)
        self.assertEqual(snapshot(session), before, "a refused resume changed the session folder")
        return line

    def report_refused(self, study, *names):
        (self.cwd / "tables").mkdir(exist_ok=True)
        result = self.cli("report", study, "--csv", "tables", "--out", "page.html")
        self.assert_error(result, 1, *names)
        self.assertEqual(list((self.cwd / "tables").iterdir()), [], "a refused report wrote tables")
        self.assertFalse((self.cwd / "page.html").exists())

    def edit_manifest(self, session, edit):
        path = session / "session.json"
        data = json.loads(path.read_text(encoding="utf-8"))
        edit(data)
        path.write_text(json.dumps(data), encoding="utf-8")

    def test_completed_session_resumes_to_nothing(self):
        study, (a, _) = self.study()
        before = snapshot(a)
        result = self.cli("session", "resume", a)
        self.assert_ok(result)
        self.assertIn("saved already", result.stdout.decode() + result.stderr.decode())
        after = snapshot(a)
        for key, value in before.items():
            if key != "log.jsonl":
                self.assertEqual(after.get(key), value, key)

    def test_plan_index_fraction_and_text(self):
        for value in sample([1.5, "1", None, -1, 2 ** 64]):
            with self.subTest(value=value):
                study, (a, _) = self.study()

                def edit(data):
                    data["plan"][0]["index"] = value

                self.edit_manifest(a, edit)
                self.resume_refused(a, "session.json", "/plan/0/index")
                self.report_refused(study, "session.json", "/plan/0/index")
                shutil.rmtree(study)
                (self.cwd / "tables").rmdir()

    def test_manifest_unknown_key_and_key_twice(self):
        study, (a, _) = self.study()
        self.edit_manifest(a, lambda data: data.__setitem__("bogus", 1))
        self.resume_refused(a, "session.json", "/bogus")
        study2 = self.cwd / "study"
        shutil.rmtree(study2)
        study, (a, _) = self.study()
        text = (a / "session.json").read_text(encoding="utf-8")
        self.assertTrue(text.lstrip().startswith("{"))
        first_key = next(iter(json.loads(text)))
        value = json.dumps(json.loads(text)[first_key])
        (a / "session.json").write_text("{" + json.dumps(first_key) + ": " + value + ", " + text.lstrip()[1:],
                                        encoding="utf-8")
        self.resume_refused(a, "session.json", "/" + first_key)

    def test_manifest_cut_empty_directory_fifo_link(self):
        kinds = ["cut", "empty", "directory", "fifo", "link"]
        for kind in sample(kinds) if not SANITIZED else kinds:
            with self.subTest(kind=kind):
                study, (a, b) = self.study()
                path = a / "session.json"
                text = path.read_bytes()
                path.unlink()
                if kind == "cut":
                    path.write_bytes(text[: len(text) // 2])
                elif kind == "empty":
                    path.write_bytes(b"")
                elif kind == "directory":
                    path.mkdir()
                elif kind == "fifo":
                    os.mkfifo(path)
                else:
                    (self.cwd / "copy.json").write_bytes(text)
                    path.symlink_to(self.cwd / "copy.json")
                # a file that cannot be read at all (a folder, a FIFO) is status 1, its content refused 2
                status = 1 if kind in ("directory", "fifo") else 2
                self.resume_refused(a, "session.json", status=status)
                (self.cwd / "tables").mkdir()
                result = self.cli("report", study, "--csv", "tables")
                line = self.assert_error(result, 1, "session.json")
                if kind == "link":
                    self.assertIn("symbolic link", line)
                self.assertEqual(list((self.cwd / "tables").iterdir()), [])
                shutil.rmtree(study)
                (self.cwd / "tables").rmdir()
                if (self.cwd / "copy.json").exists():
                    (self.cwd / "copy.json").unlink()

    def test_trials_folder_a_link(self):
        study, (a, _) = self.study()
        elsewhere = self.cwd / "elsewhere"
        shutil.move(str(a / "trials"), elsewhere)
        (a / "trials").symlink_to(elsewhere)
        self.resume_refused(a, "trials")

    def test_record_a_link_fifo_or_empty(self):
        for kind in sample(["link", "fifo", "empty", "directory"]) if not SANITIZED else ["link", "fifo"]:
            with self.subTest(kind=kind):
                study, (a, _) = self.study()
                record = self.records(a)[0]
                text = record.read_bytes()
                record.unlink()
                if kind == "link":
                    (self.cwd / "copy.json").write_bytes(text)
                    record.symlink_to(self.cwd / "copy.json")
                elif kind == "fifo":
                    os.mkfifo(record)
                elif kind == "empty":
                    record.write_bytes(b"")
                else:
                    record.mkdir()
                self.report_refused(study, record.name)
                shutil.rmtree(study)
                (self.cwd / "tables").rmdir()
                if (self.cwd / "copy.json").exists():
                    (self.cwd / "copy.json").unlink()

    def test_record_not_in_the_plan(self):
        study, (a, _) = self.study()
        record = self.records(a)[0]
        shutil.copy(record, record.parent / ("009" + record.name[3:]))
        self.report_refused(study, "009", "/plan")

    def test_shorter_plan(self):
        study, (a, _) = self.study()
        self.edit_manifest(a, lambda data: data.__setitem__("plan", data["plan"][:1]))
        self.report_refused(study, self.records(a)[1].name, "/plan")

    def test_record_swapped_with_another_sessions(self):
        """A record of subject S02 copied over S01's record of the same plan entry: the record names another
        session and another subject; taking it would put S02's trial in S01's rows."""
        study, (a, b) = self.study()
        mine = self.records(a)[0]
        theirs = b / "trials" / mine.name
        self.assertTrue(theirs.exists())
        shutil.copy(theirs, mine)
        self.report_refused(study, mine.name)

    def test_record_labels_forged(self):
        """A record's own labels edited (subject, session, condition, characters): refused naming the record, or
        the tables keep the plan's labels; the forged values never reach a row."""
        import csv
        forged = {"subject": "S09", "session": "p-S09-20000101-000000", "condition": "zz", "characters": "人"}
        for key, value in sample(list(forged.items())):
            with self.subTest(key=key):
                study, (a, _) = self.study()
                record = self.records(a)[0]
                data = json.loads(record.read_text(encoding="utf-8"))
                self.assertIn(key, data)
                data[key] = value
                record.write_text(json.dumps(data), encoding="utf-8")
                (self.cwd / "tables").mkdir()
                result = self.cli("report", study, "--csv", "tables")
                if result.returncode != 0:
                    self.assert_error(result, 1, record.name)
                    continue
                for table in ("trials.csv", "strokes.csv"):
                    with open(self.cwd / "tables" / table, newline="", encoding="utf-8") as f:
                        for row in csv.DictReader(f):
                            self.assertNotIn(value, row.values(), (table, row))

    def test_trace_swapped_between_trials(self):
        study, (a, b) = self.study()
        traces = sorted((a / "trials").glob("*.trace.h5"))
        self.assertEqual(len(traces), 2)
        shutil.copy(b / "trials" / traces[0].name, traces[0])  # another subject's trace of the same trial
        (self.cwd / "tables").mkdir()
        result = self.cli("report", study, "--out", "page.html")
        self.assert_error(result, 1, traces[0].name)
        self.assertFalse((self.cwd / "page.html").exists())

    def test_trace_empty_or_cut(self):
        for kind in ["empty", "cut"]:
            with self.subTest(kind=kind):
                study, (a, _) = self.study()
                trace = sorted((a / "trials").glob("*.trace.h5"))[0]
                data = trace.read_bytes()
                trace.write_bytes(b"" if kind == "empty" else data[: len(data) // 2])
                result = self.cli("report", study, "--out", "page.html")
                self.assert_error(result, 1, trace.name)
                self.assertFalse((self.cwd / "page.html").exists())
                result = self.cli("score", trace, "--character", SHI)
                self.assert_error(result, 1, trace.name)
                result = self.cli("trace", trace)
                self.assert_error(result, 1, trace.name)
                shutil.rmtree(study)

    def test_record_trace_sha256_edited(self):
        study, (a, _) = self.study()
        record = self.records(a)[0]
        data = json.loads(record.read_text(encoding="utf-8"))
        data["files"]["trace_sha256"] = "0" * 64
        record.write_text(json.dumps(data), encoding="utf-8")
        result = self.cli("report", study, "--out", "page.html")
        self.assert_error(result, 1, record.name.replace(".json", ""))
        self.assertFalse((self.cwd / "page.html").exists())

    def test_resume_after_a_record_removed(self):
        study, (a, _) = self.study()
        last = self.records(a)[-1]
        stem = last.name[: -len(".json")]
        for path in list((a / "trials").glob(stem + ".*")):
            path.unlink()
        before = snapshot(a)
        result = self.cli("session", "resume", a)
        self.assert_ok(result)
        after = snapshot(a)
        for key, value in before.items():
            if key != "log.jsonl":
                self.assertEqual(after.get(key), value, key)
        self.assertTrue(last.exists())

    @unittest.skipIf(cg_study is None, "the Python package is not built")
    def test_python_load_refuses_an_edited_manifest(self):
        study, (a, _) = self.study()
        self.edit_manifest(a, lambda data: data["plan"][0].__setitem__("repetition", "1"))
        with self.assertRaises(cg.DataError) as caught:
            cg_study.load(str(study))
        self.assertIn("/plan/0/repetition", str(caught.exception))
        self.assertIn("session.json", str(caught.exception))

    @unittest.skipIf(cg_study is None, "the Python package is not built")
    def test_python_samples_refuse_a_swapped_trace(self):
        study, (a, b) = self.study()
        loaded = cg_study.load(str(study))
        trace = sorted((a / "trials").glob("*.trace.h5"))[0]
        shutil.copy(b / "trials" / trace.name, trace)
        rows = loaded.trials
        row = rows[rows["trace_file"].astype(str).str.endswith(trace.name)
                   & (rows["session"].astype(str) == a.name)]
        self.assertEqual(len(row), 1)
        with self.assertRaises(cg.DataError) as caught:
            loaded.samples(row.iloc[0])
        self.assertIn(trace.name, str(caught.exception))


class TrialRecordCases(Case):
    """`trial --spec RECORD` given records edited, cut, mixed and inflated: exit 2 for content, 1 for a record
    that cannot be read or for other data, one line naming the file and the pointer; nothing written."""

    def record(self, name="r.json"):
        data = json.loads((Shared.get() / name).read_text(encoding="utf-8"))
        return data

    def spec_refused(self, data, status, *names, raw=None):
        path = self.cwd / "bad.json"
        path.write_text(raw if raw is not None else json.dumps(data), encoding="utf-8")
        result = self.cli("trial", "--spec", "bad.json", "--csv", "out.csv", "--json", "out.json")
        line = self.assert_error(result, status, "bad.json", *names)
        self.assertFalse((self.cwd / "out.csv").exists())
        self.assertFalse((self.cwd / "out.json").exists())
        return line

    @heavy
    def test_specification_alone_runs_the_same_trial(self):
        spec = self.record()["specification"]
        (self.cwd / "spec.json").write_text(json.dumps(spec), encoding="utf-8")
        self.assert_ok(self.cli("trial", "--spec", "spec.json", "--csv", "again.csv"))
        self.assertEqual((self.cwd / "again.csv").read_bytes(), (Shared.get() / "r.csv").read_bytes())

    def test_version_and_format(self):
        for version in sample([99, 0, 10, "6", 6.5, None]):
            with self.subTest(version=version):
                data = self.record()
                data["specification"]["version"] = version
                self.spec_refused(data, 2, "/specification/version")
        data = self.record()
        data["specification"]["format"] = "calligraphy-study-trial"
        self.spec_refused(data, 2, "/specification/format")

    def test_scene_of_another_character(self):
        data = self.record()
        data["specification"]["scene"] = self.record("other.json")["specification"]["scene"]
        self.spec_refused(data, 1)

    def test_scene_sha256_edited(self):
        data = self.record()
        data["specification"]["scene"]["sha256"] = "f" * 64
        self.spec_refused(data, 1)

    def test_teacher_sha256_without_a_teacher(self):
        data = self.record()
        data["specification"]["teacher_sha256"] = "0" * 64
        result = self.cli_spec(data)
        self.assertIn(result.returncode, (1, 2), result.stderr.decode(errors="replace"))
        self.error_line(result, result.returncode)

    def cli_spec(self, data):
        (self.cwd / "bad.json").write_text(json.dumps(data), encoding="utf-8")
        return self.cli("trial", "--spec", "bad.json", "--csv", "out.csv")

    def test_force_law_out_of_range(self):
        data = self.record()
        data["specification"]["force_law"]["crossfade_s"] = -1.0
        self.spec_refused(data, 2, "/specification/force_law/crossfade_s")

    def test_parts_missing_null_unknown(self):
        for part in sample(["trial", "force_law", "safety", "passivity", "scene", "library_version",
                            "teacher_sha256"]):
            with self.subTest(part=part, edit="missing"):
                data = self.record()
                del data["specification"][part]
                self.spec_refused(data, 2, "/specification")
            with self.subTest(part=part, edit="null"):
                data = self.record()
                data["specification"][part] = None
                self.spec_refused(data, 2, "/specification/" + part)
        data = self.record()
        data["specification"]["trial"]["bogus"] = 1
        self.spec_refused(data, 2, "/specification/trial/bogus")

    def test_writer_null_on_the_simulated_device(self):
        """`writer` null states a person; on the simulated device the re-run is refused, or it is the recorded
        trial bit for bit, never another trial."""
        data = self.record()
        data["specification"]["writer"] = None
        result = self.cli_spec(data)
        if result.returncode == 0:
            self.assertEqual((self.cwd / "out.csv").read_bytes(), (Shared.get() / "r.csv").read_bytes())
        else:
            self.assertIn(result.returncode, (1, 2), result.stderr.decode(errors="replace"))
            self.error_line(result, result.returncode)
            self.assertFalse((self.cwd / "out.csv").exists())

    @heavy
    def test_huge_array(self):
        data = self.record()
        data["specification"]["scene"]["layout"] = [0.0] * 2_000_000
        line = self.spec_refused(data, 2, "/specification/scene/layout")
        self.assertLess(len(line), 2100)

    @heavy
    def test_deep_nesting_and_cut_json(self):
        self.spec_refused(None, 2, raw="[" * 100000 + "]" * 100000)
        text = json.dumps(self.record())
        self.spec_refused(None, 2, raw=text[: len(text) // 2])

    def test_output_on_the_record(self):
        shutil.copy(Shared.get() / "r.json", self.cwd / "r.json")
        before = (self.cwd / "r.json").read_bytes()
        result = self.cli("trial", "--spec", "r.json", "--json", "r.json")
        self.assert_error(result, 2, "r.json")
        self.assertEqual((self.cwd / "r.json").read_bytes(), before)

    def test_check_writes_nothing(self):
        shutil.copy(Shared.get() / "r.json", self.cwd / "r.json")
        result = self.cli("trial", "--spec", "r.json", "--check", "--csv", "out.csv")
        self.assertIn(result.returncode, (0, 2))
        self.assertFalse((self.cwd / "out.csv").exists())

    @heavy
    def test_session_record_reruns_to_its_trace(self):
        study, (a, _) = (None, (None, None))
        session = sorted(p for p in (Shared.get() / "study").glob("S01/p-*"))[0]
        record = sorted((session / "trials").glob("*.json"))[0]
        self.assert_ok(self.cli("trial", "--spec", record, "--csv", "again.csv"))
        trace = record.with_name(record.name[: -len(".json")] + ".trace.h5")
        self.assert_ok(self.cli("trace", trace, "--csv", "saved.csv"))
        self.assertEqual((self.cwd / "again.csv").read_bytes(), (self.cwd / "saved.csv").read_bytes())

    @heavy
    def test_parts_swapped_between_a_fixed_and_a_fading_record(self):
        self.assert_ok(self.cli("trial", SHI, "--guidance-mode", "fading", "--guidance-gain", "0.4", "--seed", "1",
                                "--json", "fading.json"))
        fading = json.loads((self.cwd / "fading.json").read_text(encoding="utf-8"))
        data = self.record()
        data["specification"]["force_law"] = fading["specification"]["force_law"]
        self.spec_refused(data, 2, "/specification/force_law")
        fading["specification"]["trial"] = self.record()["specification"]["trial"]
        self.spec_refused(fading, 2, "/specification")

    @heavy
    def test_replay_teacher_changed(self):
        for args in (["--writer-profile", "skilled", "--record", "teacher.json"],
                     ["--writer-profile", "skilled", "--seed", "5", "--record", "other-teacher.json"],
                     ["--guidance-mode", "replay", "--teacher", "teacher.json", "--json", "replay.json"]):
            self.assert_ok(self.cli("trial", SHI, *args))
        replay = json.loads((self.cwd / "replay.json").read_text(encoding="utf-8"))
        sha = replay["specification"]["teacher_sha256"]
        self.assertEqual(len(sha), 64)
        # another recording given for it: refused naming the file and both SHA-256
        result = self.cli("trial", "--spec", "replay.json", "--teacher", "other-teacher.json", "--csv", "out.csv")
        self.assert_error(result, 1, "other-teacher.json", sha)
        self.assertFalse((self.cwd / "out.csv").exists())
        # the record's SHA-256 edited: the file it names is no longer the one it ran on
        replay["specification"]["teacher_sha256"] = "0" * 64
        (self.cwd / "edited.json").write_text(json.dumps(replay), encoding="utf-8")
        result = self.cli("trial", "--spec", "edited.json", "--csv", "out.csv")
        self.assert_error(result, 1, "teacher.json", sha)
        self.assertFalse((self.cwd / "out.csv").exists())
        # the teacher file itself replaced by the other recording
        shutil.copy(self.cwd / "other-teacher.json", self.cwd / "teacher.json")
        result = self.cli("trial", "--spec", "replay.json", "--csv", "out.csv")
        self.assert_error(result, 1, "teacher.json", sha)

    @unittest.skipIf(cg is None, "the Python package is not built")
    def test_python_rerun_and_check(self):
        data = self.record()
        data["specification"]["version"] = 99
        with self.assertRaises(cg.DataError) as caught:
            cg.rerun_trial(data)
        self.assertIn("/specification/version", str(caught.exception))
        data = self.record()
        data["specification"]["force_law"]["crossfade_s"] = -1.0
        with self.assertRaises(cg.DataError) as caught:
            cg.check_trial_record(data)
        self.assertIn("/specification/force_law/crossfade_s", str(caught.exception))


class StrokeNumberCases(Case):
    """Strokes numbered from 1 in every table people read, from 0 in every JSON."""

    def table_strokes(self, text):
        rows = []
        lines = text.splitlines()
        for i, line in enumerate(lines):
            if line.strip().startswith("stroke") and ("mean[mm]" in line or "type" in line):
                for row in lines[i + 1:]:
                    parts = row.split()
                    if not parts or not parts[0].isdigit():
                        break
                    rows.append(int(parts[0]))
                break
        return rows

    def test_trial_and_score_tables(self):
        trial = self.cli("trial", SHI, "--seed", "1", "--json", "t.json", "--csv", "t.csv")
        self.assert_ok(trial)
        self.assertEqual(self.table_strokes(trial.stdout.decode()), [1, 2])
        data = json.loads((self.cwd / "t.json").read_text(encoding="utf-8"))
        self.assertEqual([s["index"] for s in data["renderer_strokes"]], [0, 1])
        score = self.cli("score", "t.csv", "--character", SHI)
        self.assert_ok(score)
        self.assertEqual(self.table_strokes(score.stdout.decode()), [1, 2])

    def test_json_and_trace_count_from_0(self):
        trial = self.cli("trial", SHI, "--seed", "1", "--csv", "t.csv")
        self.assert_ok(trial)
        score = self.cli("score", "t.csv", "--character", SHI, "--json", "-")
        self.assert_ok(score)
        per_character = json.loads(score.stdout)["per_character"][0]
        self.assertEqual([s["index"] for s in per_character["per_stroke"]], [0, 1])
        matched = {s["matched_stroke"] for s in per_character["segments"]} - {None}
        self.assertTrue(matched <= {0, 1} and matched, matched)
        session = sorted((Shared.get() / "study").glob("S01/p-*"))[0]
        trace = sorted((session / "trials").glob("001-*.trace.h5"))[0]
        csv_text = self.cli("trace", trace).stdout.decode().splitlines()
        column = csv_text[0].split(",").index("stroke")
        self.assertEqual(sorted({int(line.split(",")[column]) for line in csv_text[1:]}), [0, 1])
        quiz_record = json.loads(sorted((session / "trials").glob("002-*.json"))[0].read_text(encoding="utf-8"))
        events = [e for c in quiz_record["quiz"]["characters"] for e in c["events"]]
        self.assertTrue(events)
        self.assertTrue({e["stroke"] for e in events} <= {0, 1}, events)

    def test_model_lists_strokes_from_1(self):
        result = self.cli("model", SHI)
        self.assert_ok(result)
        numbers = [int(line.split()[1].rstrip(":")) for line in result.stdout.decode().splitlines()
                   if line.strip().startswith("stroke ")]
        self.assertEqual(numbers, [1, 2])

    def test_report_tables_count_from_1(self):
        study = Shared.get() / "study"
        (self.cwd / "tables").mkdir()
        self.assert_ok(self.cli("report", study, "--csv", "tables"))
        import csv
        with open(self.cwd / "tables" / "strokes.csv", newline="", encoding="utf-8") as f:
            rows = list(csv.DictReader(f))
        self.assertEqual(sorted({int(r["stroke"]) for r in rows}), [1, 2])
        self.assertEqual({int(r["character"]) for r in rows}, {1})
        with open(self.cwd / "tables" / "trials.csv", newline="", encoding="utf-8") as f:
            trials = list(csv.DictReader(f))
        self.assertEqual(sorted({int(r["trial"]) for r in trials}), [1, 2])


if __name__ == "__main__":
    unittest.main(verbosity=1)
