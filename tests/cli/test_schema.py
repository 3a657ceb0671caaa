#!/usr/bin/env python3
"""The published schemas (`calligraphy schema specification|record|protocol|session`, docs/cli.md) held against the program's
real documents by an independent validator (the jsonschema package, draft 2020-12), and against the program's
own reader: a value the schema refuses is refused by `trial --spec` naming the file and the JSON pointer, and a
value at a closed bound is valid to both. Run by CTest as `cli_schema_tests`; CALLIGRAPHY_CLI names the program.
Under CALLIGRAPHY_SANITIZED=1 (the sanitizer build, where each run of the program is ten times slower) the reader
is given every third refused value (deterministically), and `session plan` and `trial --spec` a third of the
protocol's values at and past their bounds, drawn with CALLIGRAPHY_TEST_SEED (random when unset, printed) so that
every value is run by some seed (CALLIGRAPHY_TEST_FULL=1: all); the schema is checked on all of them.
"""
import copy
import json
import math
import os
import random
import shutil
import subprocess
import tempfile
import unittest
from pathlib import Path

import jsonschema

CLI = os.environ.get("CALLIGRAPHY_CLI", "")
SANITIZED = os.environ.get("CALLIGRAPHY_SANITIZED", "") == "1"
SEED = int(os.environ.get("CALLIGRAPHY_TEST_SEED") or random.SystemRandom().randrange(1 << 32))
if SANITIZED and os.environ.get("CALLIGRAPHY_TEST_FULL") != "1":
    print(f"sanitizer build: the protocol's bound values run by the program drawn with CALLIGRAPHY_TEST_SEED={SEED}",
          flush=True)


def program_runs(*case):
    """Whether the program is given `case` (a pointer, a value and what is expected): always in Release and with
    CALLIGRAPHY_TEST_FULL=1; under the sanitizers one case in three, drawn from SEED."""
    if not SANITIZED or os.environ.get("CALLIGRAPHY_TEST_FULL") == "1":
        return True
    return random.Random(f"{SEED}:{case!r}").randrange(3) == 0


class SchemaTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        if not CLI or not Path(CLI).exists():
            raise unittest.SkipTest(f"CALLIGRAPHY_CLI={CLI!r} is not the calligraphy program: run through ctest")
        cls.folder = tempfile.TemporaryDirectory(prefix="calligraphy-schema-")
        cls.cwd = Path(cls.folder.name)
        cls.schemas = {name: json.loads(cls.run_cli("schema", name).stdout) for name in ("specification", "record")}
        # Records of trials in every guidance mode but replay (which needs a teacher: tests/study), made here.
        cls.records = {}
        for name, extra in {
            "fixed": [],
            "fading": ["--guidance-mode", "fading", "--guidance-gain", "0.5"],
            "assist": ["--guidance-mode", "assist-as-needed", "--assist-band", "0.002"],
            "amplify": ["--guidance-mode", "error-amplification", "--amplification-gain", "0.3"],
            "timing": ["--guidance-mode", "timing", "--timing-speed", "0.05"],
            "stiff": ["--guidance-stiffness", "250", "--writer-param", "bias_offset_m=0.002"],
            "off": ["--guidance", "off", "--writer-profile", "skilled"],
        }.items():
            result = cls.run_cli("trial", "十", "--seed", "3", "--json", f"{name}.json", *extra)
            if result.returncode != 0:
                raise AssertionError(f"trial {extra}: {result.stderr.decode()}")
            cls.records[name] = json.loads((cls.cwd / f"{name}.json").read_text())

    @classmethod
    def tearDownClass(cls):
        cls.folder.cleanup()

    @classmethod
    def run_cli(cls, *args):
        return subprocess.run([CLI, *map(str, args)], cwd=cls.cwd, capture_output=True, timeout=120)

    def validator(self, name):
        return jsonschema.Draft202012Validator(self.schemas[name])

    def test_the_schemas_are_json_schema_2020_12(self):
        for name, schema in self.schemas.items():
            jsonschema.Draft202012Validator.check_schema(schema)
            self.assertEqual(schema["$schema"], "https://json-schema.org/draft/2020-12/schema", name)
            self.assertFalse(schema["additionalProperties"], name)

    def test_real_records_and_specifications_validate(self):
        for name, record in self.records.items():
            with self.subTest(name):
                self.validator("record").validate(record["specification"])
                self.validator("specification").validate(record["specification"]["trial"])
        # A specification a person writes may leave out what keeps its default.
        self.validator("specification").validate({"characters": "永", "rate_hz": 500})

    def test_the_new_parameter_reaches_the_record(self):
        stiff = self.records["stiff"]["specification"]
        self.assertEqual(stiff["trial"]["guidance_stiffness_n_per_m"], 250)
        self.assertEqual(stiff["force_law"]["guidance_stiffness_n_per_m"], 250)
        help_text = self.run_cli("trial", "--help").stdout.decode()
        self.assertRegex(help_text, r"--guidance-stiffness N/M .*\[N/m\]")
        refused = self.run_cli("trial", "十", "--guidance-stiffness", "-1")
        self.assertEqual(refused.returncode, 2)
        self.assertIn("--guidance-stiffness", refused.stderr.decode())
        refused = self.run_cli("trial", "十", "--guidance", "off", "--guidance-stiffness", "300")
        self.assertEqual(refused.returncode, 2)
        self.assertIn("--guidance-stiffness", refused.stderr.decode())

    def test_invalid_documents_are_refused_by_both(self):
        """Each value the schema refuses, put into a real record, is refused by the reader naming its pointer."""
        base = self.records["fixed"]
        cases = []
        trial = self.schemas["record"]["$defs"]["TrialSpec"]["properties"]
        for key, prop in trial.items():
            cases.extend(self.past_bounds(["trial", key], prop))
        for part in ("force_law", "safety", "passivity", "writer"):
            definition = {"force_law": "ForceLawParameters", "safety": "SafetyChainParameters",
                          "passivity": "PassivityParameters", "writer": "WriterProfile"}[part]
            for key, prop in self.schemas["record"]["$defs"][definition]["properties"].items():
                cases.extend(self.past_bounds([part, key], prop))
        cases.append((["trial", "guidance_mode"], "assist_as_needed"))
        cases.append((["trial", "surprise"], 1))
        cases.append((["trial", "seed"], None))
        cases.append((["library_version"], None))
        self.assertGreater(len(cases), 40)
        for number, (path, value) in enumerate(cases):
            with self.subTest(path=path, value=value):
                document = copy.deepcopy(base)
                target = document["specification"]
                for key in path[:-1]:
                    target = target[key]
                target[path[-1]] = value
                errors = list(self.validator("record").iter_errors(document["specification"]))
                self.assertTrue(errors, f"the schema takes {path} = {value}")
                if SANITIZED and number % 3 != 0:
                    continue
                (self.cwd / "bad.json").write_text(json.dumps(document))
                result = self.run_cli("trial", "--spec", "bad.json", "--json", "again.json")
                stderr = result.stderr.decode()
                self.assertEqual(result.returncode, 2, stderr)  # the content of --spec: a usage error
                self.assertIn("bad.json: /specification/" + "/".join(path), stderr)
                self.assertEqual(len(stderr.strip().splitlines()), 1, stderr)

    def test_values_at_closed_bounds_are_valid(self):
        trial = self.schemas["record"]["$defs"]["TrialSpec"]["properties"]
        validator = self.validator("record")
        for key, prop in trial.items():
            for bound in ("minimum", "maximum"):
                if bound not in prop or prop["type"] != "number":
                    continue
                document = copy.deepcopy(self.records["fixed"]["specification"])
                document["trial"][key] = prop[bound]
                self.assertEqual(list(validator.iter_errors(document)), [], f"{key} at its {bound}")

    def test_an_earlier_record_reads_and_runs_to_the_same_trace(self):
        document = copy.deepcopy(self.records["fixed"])
        document["specification"]["version"] = 2
        del document["specification"]["trial"]["guidance_stiffness_n_per_m"]
        (self.cwd / "v2.json").write_text(json.dumps(document))
        for name, record in (("now", "fixed.json"), ("v2", "v2.json")):
            result = self.run_cli("trial", "--spec", record, "--csv", f"{name}.csv")
            self.assertEqual(result.returncode, 0, result.stderr.decode())
            if name == "v2":
                self.assertIn("/specification/trial/guidance_stiffness_n_per_m", result.stderr.decode())
                self.assertIn("takes its default", result.stderr.decode())
        self.assertEqual((self.cwd / "now.csv").read_bytes(), (self.cwd / "v2.csv").read_bytes())

    def test_a_replay_record_is_bound_to_its_teacher(self):
        """A replay's record names its teacher's recording by SHA-256: re-run with that recording it gives the
        same trace; with another recording at the same path (the folder it is re-run in holds another
        teacher.json) it is refused, naming the file and both SHA-256; a version-3 record names none."""
        import hashlib

        for seed, name in ((3, "teacher.json"), (4, "other-teacher.json")):
            made = self.run_cli("trial", "十", "--seed", seed, "--record", name)
            self.assertEqual(made.returncode, 0, made.stderr.decode())
        ran = self.run_cli("trial", "十", "--seed", "4", "--guidance-mode", "replay", "--teacher", "teacher.json",
                           "--json", "replay.json", "--csv", "replay.csv")
        self.assertEqual(ran.returncode, 0, ran.stderr.decode())
        record = json.loads((self.cwd / "replay.json").read_text())
        teacher_sha = hashlib.sha256((self.cwd / "teacher.json").read_bytes()).hexdigest()
        self.assertEqual(record["specification"]["teacher_sha256"], teacher_sha)
        self.assertEqual(list(self.validator("record").iter_errors(record["specification"])), [])
        again = self.run_cli("trial", "--spec", "replay.json", "--csv", "again.csv")
        self.assertEqual(again.returncode, 0, again.stderr.decode())
        self.assertEqual((self.cwd / "again.csv").read_bytes(), (self.cwd / "replay.csv").read_bytes())
        for given in (["--teacher", "other-teacher.json"], []):
            if not given:  # the file the record names, replaced by another teacher's recording
                (self.cwd / "teacher.json").write_bytes((self.cwd / "other-teacher.json").read_bytes())
            refused = self.run_cli("trial", "--spec", "replay.json", "--csv", "wrong.csv", *given)
            message = refused.stderr.decode()
            self.assertEqual(refused.returncode, 1, message)
            self.assertIn(teacher_sha, message)
            self.assertIn("teacher_sha256", message)
            self.assertFalse((self.cwd / "wrong.csv").exists())
        # An earlier record named no teacher's SHA-256: it reads, says so, and runs on the file it names.
        earlier = copy.deepcopy(record)
        earlier["specification"]["version"] = 3
        del earlier["specification"]["teacher_sha256"]
        (self.cwd / "replay-v3.json").write_text(json.dumps(earlier))
        old = self.run_cli("trial", "--spec", "replay-v3.json", "--csv", "v3.csv")
        self.assertEqual(old.returncode, 0, old.stderr.decode())
        self.assertIn("/specification/teacher_sha256", old.stderr.decode())
        # A forged SHA-256, or one on a trial that is no replay, is refused by the reader, naming the pointer.
        for document, value in ((record, "ABC"), (self.records["fixed"], teacher_sha)):
            forged = copy.deepcopy(document)
            forged["specification"]["teacher_sha256"] = value
            (self.cwd / "forged.json").write_text(json.dumps(forged))
            refused = self.run_cli("trial", "--spec", "forged.json", "--csv", "forged.csv")
            self.assertNotEqual(refused.returncode, 0)
            self.assertIn("/specification/teacher_sha256", refused.stderr.decode())

    def test_an_option_of_another_guidance_is_refused_at_its_default_too(self):
        """An option read only by another guidance mode (or by guidance on) is a mistake at any value: given at
        its default it is refused as it is at any other value, exit 2, naming the option."""
        trial = self.schemas["specification"]["properties"]
        cases = [(["--guidance-mode", "fading"], "--assist-band", "assist_band_m"),
                 (["--guidance-mode", "assist-as-needed"], "--guidance-gain", "guidance_gain"),
                 (["--guidance-mode", "fixed"], "--amplification-gain", "amplification_gain"),
                 (["--guidance-mode", "fading"], "--timing-speed", "timing_speed_m_s"),
                 (["--guidance", "off"], "--guidance-stiffness", "guidance_stiffness_n_per_m")]
        for mode, option, key in cases:
            default = trial[key]["default"]
            for value in (default, default * 0.5 if default else 0.5):
                refused = self.run_cli("trial", "十", *mode, option, value, "--json", "never.json")
                self.assertEqual(refused.returncode, 2, f"{mode} {option} {value}: {refused.stderr.decode()}")
                self.assertIn(option, refused.stderr.decode())
                self.assertFalse((self.cwd / "never.json").exists())
        # The same option with its own mode, at its default, is taken.
        taken = self.run_cli("trial", "十", "--guidance-mode", "assist-as-needed", "--assist-band",
                             trial["assist_band_m"]["default"])
        self.assertEqual(taken.returncode, 0, taken.stderr.decode())

    def test_enum_spellings_are_the_options_spellings(self):
        help_text = self.run_cli("trial", "--help").stdout.decode()
        trial = self.schemas["specification"]["properties"]
        for key, option in (("guidance_mode", "--guidance-mode"), ("pacing", "--pacing"),
                            ("realtime", "--realtime")):
            self.assertIn(f"{option} {'|'.join(trial[key]['enum'])}", help_text)

    def test_the_docs_table_is_the_schemas(self):
        source = Path(os.environ.get("CALLIGRAPHY_SOURCE_DIR", Path(__file__).resolve().parents[2]))
        text = (source / "docs" / "cli.md").read_text(encoding="utf-8")
        start = text.index("<!-- schema specification -->\n") + len("<!-- schema specification -->\n")
        end = text.index("<!-- end schema specification -->")
        printed = self.run_cli("schema", "specification", "--markdown").stdout.decode()
        self.assertEqual(text[start:end], printed, "docs/cli.md: paste `calligraphy schema specification --markdown`")

    def test_the_metrics_docs_table_is_the_metric_tables(self):
        source = Path(os.environ.get("CALLIGRAPHY_SOURCE_DIR", Path(__file__).resolve().parents[2]))
        text = (source / "docs" / "metrics.md").read_text(encoding="utf-8")
        start = text.index("<!-- schema metrics -->\n") + len("<!-- schema metrics -->\n")
        end = text.index("<!-- end schema metrics -->")
        printed = self.run_cli("schema", "metrics", "--markdown").stdout.decode()
        self.assertEqual(text[start:end], printed, "docs/metrics.md: paste `calligraphy schema metrics --markdown`")

    def test_a_trials_metrics_validate_against_the_metrics_schema(self):
        """`calligraphy schema metrics` against a real trial's record: every scene-level metric is there, of its
        type, and a length in mm would not be."""
        schema = json.loads(self.run_cli("schema", "metrics").stdout.decode())
        out = self.cwd / "metrics-trial.json"
        result = self.run_cli("trial", "十", "--json", str(out))
        self.assertEqual(result.returncode, 0, result.stderr.decode())
        record = json.loads(out.read_text(encoding="utf-8"))
        metrics = {key: record[key] for key in schema["properties"]}
        jsonschema.validate(metrics, schema)
        self.assertIn("mean_deviation_m", schema["required"])
        self.assertFalse(any(key.endswith("_mm") for key in record))
        with self.assertRaises(jsonschema.ValidationError):
            jsonschema.validate(dict(metrics, strokes_total=1.5), schema)

    @staticmethod
    def past_bounds(path, prop):
        """Values just outside a numeric property's range, and a string where a number belongs."""
        if prop.get("type") not in ("number", "integer"):
            return []
        out = [(path, "1")]
        if prop["type"] == "number":
            if "minimum" in prop and prop["minimum"] > -1e300:
                out.append((path, math.nextafter(prop["minimum"], -math.inf)))
            if "exclusiveMinimum" in prop:
                out.append((path, prop["exclusiveMinimum"]))
            if "maximum" in prop and prop["maximum"] < 1e300:
                out.append((path, math.nextafter(prop["maximum"], math.inf)))
            if "exclusiveMaximum" in prop:
                out.append((path, prop["exclusiveMaximum"]))
        elif "minimum" in prop and prop["minimum"] > -(2**63):
            out.append((path, prop["minimum"] - 1))
        return out


SOURCE = Path(os.environ.get("CALLIGRAPHY_SOURCE_DIR", Path(__file__).resolve().parents[2]))


def _protocol(**parts):
    """A minimal protocol of the paper's format, with `parts` added or replacing its own."""
    document = {
        "name": "bounds",
        "conditions": [{"name": "A", "mode": "haptic"}],
        "test": {"characters": ["十"], "conditions": ["A"], "repetitions": 1},
    }
    document.update(parts)
    return document


def _phased(phase):
    return {"name": "bounds", "conditions": [{"name": "A", "mode": "haptic"}], "phases": [phase]}


class ProtocolSchemaTest(unittest.TestCase):
    """`calligraphy schema protocol` against the protocol reader: the files shipped validate, and every bounded
    field is refused just past its bound and accepted at a closed bound by both jsonschema and `session plan`."""

    @classmethod
    def setUpClass(cls):
        if not CLI or not Path(CLI).exists():
            raise unittest.SkipTest(f"CALLIGRAPHY_CLI={CLI!r} is not the calligraphy program: run through ctest")
        cls.folder = tempfile.TemporaryDirectory(prefix="calligraphy-protocol-schema-")
        cls.cwd = Path(cls.folder.name)
        cls.schema = json.loads(SchemaTest.run_cli.__func__(cls, "schema", "protocol").stdout)
        cls.validator = jsonschema.Draft202012Validator(cls.schema)

    @classmethod
    def tearDownClass(cls):
        cls.folder.cleanup()

    # `session plan p.json --subjects 2` of each document text given so far. A quarter of the documents the cases
    # give are given by another case as well (a field shared with the trial record is one of the protocol's
    # bounds, on the same base): the program reads the same bytes under the same name, and each case checks that
    # one run's exit status and message.
    planned = {}

    def plan(self, document):
        text = json.dumps(document, ensure_ascii=False)
        if text not in self.planned:
            path = self.cwd / "p.json"
            path.write_text(text, encoding="utf-8")
            self.planned[text] = subprocess.run([CLI, "session", "plan", str(path), "--subjects", "2"],
                                                cwd=self.cwd, capture_output=True, timeout=60)
        return self.planned[text]

    def sites(self):
        """(base document, JSON pointer of the object, its properties, bounds not to accept there) for every
        object a bound sits in."""
        defs = self.schema["$defs"]
        props = self.schema["properties"]
        out = [
            (_protocol(), "", props),
            (_protocol(trial={"rate_hz": 100}), "/trial", defs["ProtocolTrialSettings"]["properties"]),
            (_protocol(breaks={"duration_s": 1}), "/breaks", defs["BreakRules"]["properties"]),
            (_protocol(order={}), "/order", props["order"]["properties"]),
            (_protocol(practice={"characters": ["十"], "condition": "A"}), "/practice",
             props["practice"]["properties"]),
            (_protocol(), "/test", props["test"]["properties"]),
            (_protocol(), "/conditions/0", defs["StudyCondition"]["properties"]),
            (_phased({"phase": "test", "conditions": ["A"], "characters": ["十"]}), "/phases/0",
             defs["ProtocolPhase"]["properties"]),
        ]
        out = [(*site, set()) for site in out]
        # Sessions are numbered from 1 without gaps: the last session is the 20th phase's.
        out[-1][3].add(("session", "maximum"))
        phases = [{"phase": "test", "conditions": ["A"], "characters": ["十"], "session": i + 1} for i in range(20)]
        twenty = {"name": "bounds", "conditions": [{"name": "A", "mode": "haptic"}], "phases": phases}
        session = {"session": defs["ProtocolPhase"]["properties"]["session"]}
        out.append((twenty, "/phases/19", session, {("session", "minimum")}))
        quiz = [{"name": "A", "mode": "quiz", "quiz": {}}]
        out.append((_protocol(conditions=quiz), "/conditions/0/quiz", defs["QuizOptions"]["properties"], set()))
        quiz = [{"name": "A", "mode": "quiz", "quiz": {"acceptance": {}}}]
        out.append((_protocol(conditions=quiz), "/conditions/0/quiz/acceptance",
                    defs["QuizOptions"]["properties"]["acceptance"]["properties"], set()))
        for rule in defs["StudyCondition"]["allOf"]:
            parameters = rule["then"].get("properties", {}).get("parameters")
            if not parameters:
                continue
            mode = rule["if"]["properties"]["mode"]["const"]
            # The widest band, so that the narrowest may take its whole range (max_band_m >= min_band_m).
            base = {"max_band_m": 0.1} if mode == "assist-as-needed" else {}
            condition = [{"name": "A", "mode": mode, "parameters": base}]
            out.append((_protocol(conditions=condition), "/conditions/0/parameters", parameters["properties"], set()))
        return out

    @staticmethod
    def with_value(document, pointer, value):
        document = copy.deepcopy(document)
        keys = pointer.strip("/").split("/")
        node = document
        for key in keys[:-1]:
            node = node[int(key)] if isinstance(node, list) else node.setdefault(key, {})
        node[keys[-1]] = value
        return document

    def test_the_schema_is_json_schema_2020_12(self):
        jsonschema.Draft202012Validator.check_schema(self.schema)
        self.assertFalse(self.schema["additionalProperties"])

    def test_every_protocol_shipped_validates_and_plans(self):
        shipped = []
        for folder in ("docs", "examples", "tests"):
            for path in sorted((SOURCE / folder).rglob("*.json")):
                text = path.read_text(encoding="utf-8-sig")
                if '"calligraphy-study-protocol"' in text or ('"conditions"' in text and '"name"' in text):
                    shipped.append(path)
        self.assertGreaterEqual(len(shipped), 7, shipped)
        for path in shipped:
            with self.subTest(path=path.name):
                errors = [e.message for e in self.validator.iter_errors(json.loads(path.read_text("utf-8-sig")))]
                self.assertEqual(errors, [])
                result = subprocess.run([CLI, "session", "plan", str(path), "--subjects", "2"], cwd=self.cwd,
                                        capture_output=True, timeout=60)
                self.assertEqual(result.returncode, 0, result.stderr.decode())

    def test_the_docs_protocol_fragments_and_phase_table_are_the_schemas(self):
        """The protocol parts docs/ shows (```json blocks of "phases" and "item_sets") validate against the
        schema's definitions, and the docs' table of a phase's keys states the ranges of its schema."""
        import re

        defs = self.schema["$defs"]
        checked = 0
        for name in ("experiments.md", "learning-study.md"):
            text = (SOURCE / "docs" / name).read_text(encoding="utf-8")
            for block in re.findall(r"```json\n(.*?)```", text, re.S):
                body = block.strip()
                document = json.loads(body if body.startswith("{") else "{" + body + "}")
                for key, definition in (("phases", "ProtocolPhase"), ("item_sets", "ItemSet")):
                    validator = jsonschema.Draft202012Validator({"$defs": defs, "$ref": f"#/$defs/{definition}"})
                    for element in document.get(key, []):
                        with self.subTest(doc=name, element=element):
                            self.assertEqual([e.message for e in validator.iter_errors(element)], [])
                            checked += 1
        self.assertGreaterEqual(checked, 10)
        phase = defs["ProtocolPhase"]["properties"]
        table = (SOURCE / "docs" / "experiments.md").read_text(encoding="utf-8")
        for key in ("repetitions", "session"):
            self.assertIn(f"| `{key}` | {phase[key]['minimum']}-{phase[key]['maximum']} |", table)
        self.assertEqual(phase["delay_s"]["maximum"], 366 * 86400)
        self.assertIn("| `delay_s` | [0, 366 days] s |", table)
        for key, enum in (("phase", phase["phase"]["enum"]), ("assignment", phase["assignment"]["enum"])):
            self.assertIn(f"| `{key}` | " + ", ".join(f"`{value}`" for value in enum) + " |", table)

    def test_structure_the_reader_refuses_the_schema_refuses(self):
        cases = {
            "/surprise": _protocol(surprise=1),
            "/trial/rate": _protocol(trial={"rate": 1000}),
            "/trial/rate_hz": _protocol(trial={"rate_hz": None}),
            "/conditions/0/parameters": _protocol(conditions=[{"name": "A", "mode": "vision", "parameters": {}}]),
            "/conditions/0/guidance_stiffness_n_per_m": _protocol(
                conditions=[{"name": "A", "mode": "quiz", "guidance_stiffness_n_per_m": 100}]),
            "/conditions/0/parameters/end_gain": _protocol(
                conditions=[{"name": "A", "mode": "fading", "parameters": {"end_gain": 0}}]),
            "/conditions/0/quiz": _protocol(conditions=[{"name": "A", "mode": "haptic", "quiz": {}}]),
            "/conditions/0/teachers": _protocol(conditions=[{"name": "A", "mode": "haptic", "teachers": {}}]),
            "/conditions/0/mode": _protocol(conditions=[{"name": "A", "mode": "telepathy"}]),
            "/conditions/0/name": _protocol(conditions=[{"name": "A B", "mode": "haptic"}]),
            "/order/conditions": _protocol(order={"conditions": "latin"}),
            "/test/characters/0": _protocol(test={"characters": [""], "conditions": ["A"], "repetitions": 1}),
            "/phases": {**_phased({"phase": "test", "conditions": ["A"], "characters": ["十"]}),
                        "test": {"characters": ["十"], "conditions": ["A"], "repetitions": 1}},
        }
        for pointer, document in cases.items():
            with self.subTest(pointer=pointer):
                self.assertFalse(self.validator.is_valid(document))
                result = self.plan(document)
                self.assertEqual(result.returncode, 2, result.stderr.decode())
                self.assertIn(f"p.json: {pointer}", result.stderr.decode())

    def test_every_part_refused_is_a_usage_error_of_plan_run_and_cohort_alike(self):
        """A protocol's content refused exits 2 with one line `FILE: /pointer: ...` and writes nothing, from
        each part of the file; a protocol file that cannot be read at all exits 1."""
        training = {"phase": "training", "condition": "A", "characters": ["十"]}
        sets = [{"name": "one", "characters": ["十"]}, {"name": "two", "characters": ["大"]}]
        cases = {
            "/format": _protocol(format="calligraphy-protocol"),
            "/version": _protocol(version=2),
            "/name": _protocol(name="two words"),
            "/description": _protocol(description=3),
            "/conditions": _protocol(conditions=[]),
            "/conditions/1/name": _protocol(conditions=[{"name": "A", "mode": "haptic"},
                                                        {"name": "A", "mode": "vision"}]),
            "/conditions/0/mode": _protocol(conditions=[{"name": "A", "mode": "Haptic"}]),
            "/conditions/0/parameters/start_gain": _protocol(
                conditions=[{"name": "A", "mode": "fading", "parameters": {"start_gain": 2}}]),
            "/conditions/0/quiz/hint_after_misses": _protocol(
                conditions=[{"name": "A", "mode": "quiz", "quiz": {"hint_after_misses": 1001}}]),
            "/conditions/0/teachers/大": _protocol(
                conditions=[{"name": "A", "mode": "replay", "teachers": {"大": "t.json"}}]),
            "/item_sets/1/characters/0": _protocol(
                item_sets=[{"name": "one", "characters": ["十"]}, {"name": "two", "characters": ["十"]}]),
            "/item_sets/0/transfer_of": _protocol(
                item_sets=[{"name": "one", "characters": ["十"], "transfer_of": "none"}]),
            "/phases/0/phase": _phased({"phase": "warm-up", "condition": "A", "characters": ["十"]}),
            "/phases/0/assignment": _phased({**training, "assignment": "crossed"}),
            "/phases/0/repetitions": _phased({**training, "repetitions": 0}),
            "/phases/0/delay_s": _phased({**training, "delay_s": -1}),
            "/phases/0/sets/0": _phased({"phase": "training", "condition": "A", "sets": ["three"]}),
            "/phases/1/session": {**_phased(training), "phases": [training, {**training, "session": 3}]},
            "/phases/1/delay_s": {**_phased(training), "phases": [training, {**training, "phase": "retention"}]},
            "/phases/0/characters/0": {**_phased({"phase": "training", "conditions": ["A", "B"],
                                                   "assignment": "crossover", "sets": ["one", "two"]}),
                                       "conditions": [{"name": "A", "mode": "haptic"},
                                                      {"name": "B", "mode": "vision"}],
                                       "item_sets": sets,
                                       "phases": [{**training, "characters": ["十"]},
                                                  {"phase": "training", "conditions": ["A", "B"],
                                                   "assignment": "crossover", "sets": ["one", "two"]}]},
            "/order/conditions": _protocol(order={"conditions": "latin"}),
            "/order/seed": _protocol(order={"seed": -1}),
            "/test/repetitions": _protocol(order={"conditions": "abba"}),
            "/practice/condition": _protocol(practice={"characters": ["十"], "condition": "B"}),
            "/breaks/duration_s": _protocol(breaks={"every_trials": 3}),
            "/trial/rate_hz": _protocol(trial={"rate_hz": 10}),
            # A character the library lacks (no data to write it with).
            "/test/characters/0": _protocol(test={"characters": ["龘"], "conditions": ["A"], "repetitions": 1}),
        }
        path = self.cwd / "p.json"
        commands = (["session", "plan", path, "--subjects", 2],
                    ["session", "run", path, "--writer", "simulated", "--subjects", 2, "--out", "out"],
                    ["session", "cohort", path, "--subjects", 2, "--csv", "."])
        for pointer, document in cases.items():
            path.write_text(json.dumps(document, ensure_ascii=False), encoding="utf-8")
            for command in commands:
                with self.subTest(pointer=pointer, command=command[1]):
                    result = subprocess.run([CLI, *map(str, command)], cwd=self.cwd, capture_output=True,
                                            timeout=120)
                    lines = result.stderr.decode().strip().splitlines()
                    self.assertEqual(result.returncode, 2, lines)
                    self.assertEqual(len(lines), 1, lines)
                    self.assertIn(f"p.json: {pointer}: ", lines[0])
                    self.assertFalse((self.cwd / "out").exists())
                    self.assertFalse((self.cwd / "trials.csv").exists())
        # Malformed JSON is refused as the content, by its byte offset.
        path.write_text('{"name": "x",', encoding="utf-8")
        for command in commands:
            result = subprocess.run([CLI, *map(str, command)], cwd=self.cwd, capture_output=True, timeout=120)
            self.assertEqual(result.returncode, 2, result.stderr.decode())
            self.assertIn("p.json", result.stderr.decode())
        # A file that cannot be read is no usage error: missing, or a folder.
        for unreadable in (self.cwd / "missing.json", self.cwd):
            for command in commands:
                command = [unreadable if part == path else part for part in command]
                result = subprocess.run([CLI, *map(str, command)], cwd=self.cwd, capture_output=True, timeout=120)
                self.assertEqual(result.returncode, 1, result.stderr.decode())
                self.assertEqual(len(result.stderr.decode().strip().splitlines()), 1, result.stderr.decode())

    def test_resume_refuses_a_character_of_its_protocol_the_library_lacks_as_run_does(self):
        """`session resume` looks up its protocol's characters as `session run` does: one the library given
        lacks is a usage error (exit 2) naming the protocol's pointer; a library that cannot be opened is 1."""
        path = self.cwd / "r.json"
        path.write_text(json.dumps(_protocol(name="resumed", test={"characters": ["十", "人"], "conditions": ["A"],
                                                                   "repetitions": 1}), ensure_ascii=False),
                        encoding="utf-8")
        run = [CLI, "session", "run", path, "--writer", "simulated", "--subject", "S1", "--out", "resumed"]
        made = subprocess.run(run, cwd=self.cwd, capture_output=True, timeout=300)
        self.assertEqual(made.returncode, 0, made.stderr.decode())
        (folder,) = (self.cwd / "resumed" / "S1").iterdir()
        sorted((folder / "trials").glob("002-*.json"))[0].unlink()  # its last trial unsaved: to be resumed
        (self.cwd / "empty").mkdir()
        for library, status, words in ((["--data", "empty"], 2, "r.json: /test/characters/0: the character 十"),
                                       (["--data", "nowhere"], 1, "nowhere")):
            result = subprocess.run([CLI, "session", "resume", folder, *library], cwd=self.cwd,
                                    capture_output=True, timeout=300)
            lines = result.stderr.decode().strip().splitlines()
            self.assertEqual(result.returncode, status, lines)
            self.assertEqual(len(lines), 1, lines)
            self.assertIn(words, lines[0])
        self.assertEqual(len(list((folder / "trials").glob("*.json"))), 1)
        # The same library given to `session run` is refused the same way.
        result = subprocess.run(run[:-2] + ["--out", "again", "--data", "empty"], cwd=self.cwd,
                                capture_output=True, timeout=300)
        self.assertEqual(result.returncode, 2, result.stderr.decode())
        self.assertIn("r.json: /test/characters/0: the character 十", result.stderr.decode())

    def test_a_field_shared_with_the_trial_record_has_its_range_and_is_refused_past_it_by_both(self):
        """Where a protocol's value becomes a trial's, the protocol's schema states the record's range, and each
        value past it is refused by `session plan` and by `trial --spec` (exit 2 both: their content), each
        naming its pointer."""
        record_schema = json.loads(SchemaTest.run_cli.__func__(self.__class__, "schema", "record").stdout)
        records = {}
        for name, extra in {"fixed": [], "fading": ["--guidance-mode", "fading"],
                            "assist": ["--guidance-mode", "assist-as-needed"],
                            "amplify": ["--guidance-mode", "error-amplification"],
                            "timing": ["--guidance-mode", "timing"]}.items():
            made = subprocess.run([CLI, "trial", "十", "--seed", "3", "--json", f"{name}.json", *extra],
                                  cwd=self.cwd, capture_output=True, timeout=120)
            self.assertEqual(made.returncode, 0, made.stderr.decode())
            records[name] = json.loads((self.cwd / f"{name}.json").read_text())
        defs = record_schema["$defs"]

        def law(mode):
            for alternative in defs["ForceLawParameters"]["properties"]["guidance_law"]["oneOf"]:
                if alternative["properties"]["mode"]["const"] == mode:
                    return alternative["properties"]
            raise AssertionError(mode)

        def condition(mode, **extra):
            return _protocol(conditions=[{"name": "A", "mode": mode, **extra}])

        quiz = {"quiz": {"acceptance": {}}}
        pairs = [
            (_protocol(trial={}), "/trial/max_duration_s", "fixed", ["trial", "max_duration_s"],
             defs["TrialSpec"]["properties"]["max_duration_s"]),
            (condition("haptic"), "/conditions/0/guidance_stiffness_n_per_m", "fixed",
             ["force_law", "guidance_stiffness_n_per_m"],
             defs["ForceLawParameters"]["properties"]["guidance_stiffness_n_per_m"]),
            (condition("fading", parameters={}), "/conditions/0/parameters/start_gain", "fading",
             ["force_law", "guidance_law", "gain"], law("fading")["gain"]),
            (condition("assist-as-needed", parameters={"max_band_m": 0.1}), "/conditions/0/parameters/start_band_m",
             "assist", ["force_law", "guidance_law", "band_m"], law("assist-as-needed")["band_m"]),
            (condition("error-amplification", parameters={}), "/conditions/0/parameters/amplification_gain",
             "amplify", ["force_law", "guidance_law", "gain"], law("error-amplification")["gain"]),
            (condition("error-amplification", parameters={}), "/conditions/0/parameters/max_force_n", "amplify",
             ["force_law", "guidance_law", "max_force_n"], law("error-amplification")["max_force_n"]),
            (condition("timing", parameters={}), "/conditions/0/parameters/speed_m_s", "timing",
             ["force_law", "guidance_law", "speed_m_s"], law("timing")["speed_m_s"]),
        ]
        for key, prop in defs["StrokeAcceptance"]["properties"].items():
            pairs.append((condition("quiz", **quiz), f"/conditions/0/quiz/acceptance/{key}", "fixed",
                          ["force_law", "acceptance", key], prop))
        self.assertGreaterEqual(len(pairs), 20)
        bounds = ("minimum", "maximum", "exclusiveMinimum", "exclusiveMaximum")
        refused = ran = 0
        for base, pointer, record, path, record_prop in pairs:
            parts = pointer.strip("/").split("/")
            # The protocol schema's property: through $defs, the mode's parameters, the quiz's acceptance.
            if parts[0] == "trial":
                prop = self.schema["$defs"]["ProtocolTrialSettings"]["properties"][parts[1]]
            elif parts[2] == "parameters":
                mode = base["conditions"][0]["mode"]
                rule = next(r for r in self.schema["$defs"]["StudyCondition"]["allOf"]
                            if r["if"]["properties"]["mode"]["const"] == mode)
                prop = rule["then"]["properties"]["parameters"]["properties"][parts[3]]
            elif parts[2] == "quiz":
                prop = self.schema["$defs"]["QuizOptions"]["properties"]["acceptance"]["properties"][parts[4]]
            else:
                prop = self.schema["$defs"]["StudyCondition"]["properties"][parts[2]]
            with self.subTest(pointer=pointer):
                self.assertEqual({b: prop[b] for b in bounds if b in prop},
                                 {b: record_prop[b] for b in bounds if b in record_prop})
            for _, value in SchemaTest.past_bounds(pointer, prop):
                refused += 1
                if not program_runs(pointer, value, "refused by both"):
                    continue
                ran += 1
                with self.subTest(pointer=pointer, value=value):
                    result = self.plan(self.with_value(base, pointer, value))
                    self.assertEqual(result.returncode, 2, result.stderr.decode())
                    self.assertIn(f"p.json: {pointer}:", result.stderr.decode())
                    document = copy.deepcopy(records[record])
                    target = document["specification"]
                    for key in path[:-1]:
                        target = target[key]
                    target[path[-1]] = value
                    (self.cwd / "bad.json").write_text(json.dumps(document))
                    spec = subprocess.run([CLI, "trial", "--spec", "bad.json", "--json", "again.json"],
                                          cwd=self.cwd, capture_output=True, timeout=120)
                    self.assertEqual(spec.returncode, 2, spec.stderr.decode())
                    self.assertIn("bad.json: /specification/" + "/".join(path), spec.stderr.decode())
        self.assertGreaterEqual(refused, 40)
        print(f"protocol fields shared with the trial record, values refused by both: {refused} ({ran} run)")

    def test_each_bound_is_refused_past_it_and_accepted_at_it_by_both(self):
        checked = ran = 0
        for base, prefix, properties, not_at in self.sites():
            for key, prop in properties.items():
                pointer = f"{prefix}/{key}"
                for _, value in SchemaTest.past_bounds(pointer, prop):
                    document = self.with_value(base, pointer, value)
                    with self.subTest(pointer=pointer, value=value, expect="refused"):
                        self.assertFalse(self.validator.is_valid(document))
                        checked += 1
                        if not program_runs(pointer, value, "refused"):
                            continue
                        ran += 1
                        result = self.plan(document)
                        # A protocol's content refused: a usage error (exit 2, docs/cli.md), by pointer.
                        self.assertEqual(result.returncode, 2, result.stderr.decode())
                        self.assertIn(f"p.json: {pointer}:", result.stderr.decode())
                for bound in ("minimum", "maximum"):
                    if bound not in prop or abs(prop[bound]) > 1e300 or (key, bound) in not_at:
                        continue
                    document = self.with_value(base, pointer, prop[bound])
                    with self.subTest(pointer=pointer, value=prop[bound], expect="accepted"):
                        self.assertEqual([e.message for e in self.validator.iter_errors(document)], [])
                        checked += 1
                        if not program_runs(pointer, prop[bound], "accepted"):
                            continue
                        ran += 1
                        result = self.plan(document)
                        self.assertEqual(result.returncode, 0, result.stderr.decode())
        # trial 2, breaks 3, guidance stiffness, every mode's parameters, the quiz's tolerances, the phases'.
        self.assertGreaterEqual(checked, 100)
        print(f"protocol bounds checked: {checked} ({ran} run by the program)")


class SessionSchemaTest(unittest.TestCase):
    """`calligraphy schema session` against the readers of session.json: a real one validates, as do the
    older shapes the readers take (keys added since the first folders missing, version 1 counting from 0); a
    value the schema refuses (past a bound, null, a key unknown or missing) is refused by `session resume`
    naming the file and the JSON pointer (exit 2), and a value at a bound is read by `report`."""

    @classmethod
    def setUpClass(cls):
        if not CLI or not Path(CLI).exists():
            raise unittest.SkipTest(f"CALLIGRAPHY_CLI={CLI!r} is not the calligraphy program: run through ctest")
        cls.folder = tempfile.TemporaryDirectory(prefix="calligraphy-session-schema-")
        cls.cwd = Path(cls.folder.name)
        cls.schema = json.loads(SchemaTest.run_cli.__func__(cls, "schema", "session").stdout)
        cls.validator = jsonschema.Draft202012Validator(cls.schema)
        protocol = {"format": "calligraphy-study-protocol", "version": 1, "name": "one",
                    "conditions": [{"name": "vision", "mode": "vision"}, {"name": "haptic", "mode": "haptic"}],
                    "phases": [{"phase": "pre-test", "condition": "vision", "characters": ["十"]},
                               {"phase": "training", "condition": "haptic", "characters": ["十"]}],
                    "trial": {"max_duration_s": 20}}
        (cls.cwd / "one.json").write_text(json.dumps(protocol, ensure_ascii=False), encoding="utf-8")
        out = SchemaTest.run_cli.__func__(cls, "session", "run", "one.json", "--writer", "simulated",
                                          "--subjects", "2", "--out", "study")
        if out.returncode != 0:
            raise AssertionError(out.stderr.decode())
        cls.manifests = sorted((cls.cwd / "study").rglob("session.json"))
        cls.document = json.loads(cls.manifests[0].read_text(encoding="utf-8"))

    @classmethod
    def tearDownClass(cls):
        cls.folder.cleanup()

    def edited(self, document):
        """A copy of the first subject's session, its last trial unsaved, with `document` as its session.json."""
        folder = Path(tempfile.mkdtemp(dir=self.cwd))
        session = folder / "study" / self.manifests[0].parent.relative_to(self.cwd / "study")
        shutil.copytree(self.manifests[0].parent, session)
        # with its study's identity: a session naming a study in a folder without one is refused by every reader
        shutil.copy2(self.cwd / "study" / ".calligraphy-study.json", folder / "study")
        sorted(session.glob("trials/*.json"))[-1].unlink()
        (session / "session.json").write_text(json.dumps(document, ensure_ascii=False, indent=2) + "\n",
                                              encoding="utf-8")
        return folder, session

    def resume(self, session):
        return subprocess.run([CLI, "session", "resume", str(session)], cwd=self.cwd, capture_output=True,
                              timeout=120)

    def report(self, folder):
        tables = folder / "tables"
        tables.mkdir()
        return subprocess.run([CLI, "report", str(folder / "study"), "--csv", str(tables)], cwd=self.cwd,
                              capture_output=True, timeout=120)

    def refused_by_both(self, document, pointer):
        self.assertFalse(self.validator.is_valid(document), pointer)
        folder, session = self.edited(document)
        out = self.resume(session)
        self.assertEqual(out.returncode, 2, out.stderr.decode())
        self.assertIn(f"session.json: {pointer}:", out.stderr.decode())
        shutil.rmtree(folder)

    def test_the_schema_is_json_schema_2020_12(self):
        jsonschema.Draft202012Validator.check_schema(self.schema)
        self.assertFalse(self.schema["additionalProperties"])
        self.assertEqual(self.schema["properties"]["format"]["const"], "calligraphy-study-session")

    def test_real_session_jsons_validate(self):
        self.assertEqual(len(self.manifests), 2)
        for path in self.manifests:
            with self.subTest(path.name):
                self.validator.validate(json.loads(path.read_text(encoding="utf-8")))

    def test_the_older_shapes_the_readers_take_validate(self):
        old = copy.deepcopy(self.document)
        for key in ("study_id", "writer_learning", "individual_differences", "session_number", "group"):
            old.pop(key)
        self.validator.validate(old)
        first = copy.deepcopy(old)
        first["version"] = 1
        for trial in first["plan"]:
            trial["block"] -= 1
            trial["item"] -= 1
        self.validator.validate(first)
        folder, _ = self.edited(first)
        out = self.report(folder)
        self.assertEqual(out.returncode, 0, out.stderr.decode())
        # version 1's range: from 0 to 999,999
        for value in (-1, 1000000):
            past = copy.deepcopy(first)
            past["plan"][0]["item"] = value
            self.refused_by_both(past, "/plan/0/item")
        # version 2 counts from 1: its block 0 is refused by both
        second = copy.deepcopy(first)
        second["version"] = 2
        self.refused_by_both(second, "/plan/0/block")

    def test_unknown_null_and_missing_are_refused_by_both(self):
        cases = []
        for pointer in ("/colour", "/subject/colour", "/library/colour", "/protocol/colour", "/plan/0/colour"):
            document = copy.deepcopy(self.document)
            *parents, key = pointer.strip("/").split("/")
            node = document
            for part in parents:
                node = node[int(part)] if isinstance(node, list) else node[part]
            node[key] = 1
            cases.append((document, pointer))
        for pointer in ("/device", "/pacing", "/subject/number", "/plan/1/phase"):
            document = copy.deepcopy(self.document)
            *parents, key = pointer.strip("/").split("/")
            node = document
            for part in parents:
                node = node[int(part)] if isinstance(node, list) else node[part]
            node[key] = None
            cases.append((document, pointer))
        for key in self.schema["required"]:
            document = copy.deepcopy(self.document)
            document.pop(key)
            cases.append((document, "/" + key))
        for key in self.schema["$defs"]["PlannedTrial"]["required"]:
            document = copy.deepcopy(self.document)
            document["plan"][0].pop(key)
            cases.append((document, "/plan/0/" + key))
        for document, pointer in cases:
            with self.subTest(pointer=pointer):
                self.refused_by_both(document, pointer)

    def test_each_bound_is_refused_past_it_and_accepted_at_it_by_both(self):
        sites = [("", self.schema["properties"]),
                 ("/subject", self.schema["$defs"]["SessionSubject"]["properties"]),
                 ("/plan/1", self.schema["$defs"]["PlannedTrial"]["properties"])]
        # Values at a bound that a rule between values refuses: the trials in order, a record's file name (its
        # repetition), a session after the first with no previous one, version 1's counting.
        rules = {"/version", "/session_number", "/plan/1/index", "/plan/1/repetition", "/plan/1/block",
                 "/plan/1/item"}
        checked = 0
        for prefix, properties in sites:
            for key, prop in properties.items():
                if prop.get("type") not in ("number", "integer"):
                    continue
                pointer = f"{prefix}/{key}"
                past = ["1"]
                if prop["type"] == "integer":
                    past += [prop["minimum"] - 1, prop["maximum"] + 1]
                else:
                    past += [math.nextafter(prop["minimum"], -math.inf), math.nextafter(prop["maximum"], math.inf)]
                for value in past:
                    document = ProtocolSchemaTest.with_value(self.document, pointer, value)
                    with self.subTest(pointer=pointer, value=value, expect="refused"):
                        self.refused_by_both(document, pointer)
                        checked += 1
                if pointer in rules:
                    continue
                for bound in ("minimum", "maximum"):
                    document = ProtocolSchemaTest.with_value(self.document, pointer, prop[bound])
                    with self.subTest(pointer=pointer, value=prop[bound], expect="accepted"):
                        self.assertEqual([e.message for e in self.validator.iter_errors(document)], [])
                        folder, _ = self.edited(document)
                        out = self.report(folder)
                        self.assertEqual(out.returncode, 0, out.stderr.decode())
                        shutil.rmtree(folder)
                        checked += 1
        self.assertGreaterEqual(checked, 30)
        print(f"session.json bounds checked: {checked}")


if __name__ == "__main__":
    unittest.main()
