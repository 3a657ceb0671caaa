#!/usr/bin/env python3
"""Round 33B: `calligraphy schema` against every file the program writes and reads. From the docs alone
(docs/cli.md "schema", "Re-running a trial", "The trial specification", `trial` JSON keys; docs/experiments.md
"Protocol files", "Sessions", "Trial records", "Tidy tables"; docs/metrics.md "The one metrics record", "The
metric table"; docs/python.md "Running a trial again"; `calligraphy schema --help`).

The five schemas (specification, record, protocol, session, metrics) are held with Python's `jsonschema`
(Draft 2020-12) and by hand: each a valid schema; its Markdown table against its JSON Schema (names, kinds,
units, ranges) and against the docs' pasted tables; every default it states against its own property; the
protocol's quiz acceptance against the record's stroke acceptance; the metrics record's documented totals
against `schema metrics`. The files the program writes (a trial's record and CSV scored again, a trial whose pen
never touched, a session's session.json and its records, the example protocols, a record Python writes for a
simulated device of the caller's) validate; a file changed to break one rule of its schema (a bound, a type,
an unknown key, a missing key, an enumeration spelt otherwise) is refused by its reader in one line naming the
file and the JSON pointer, and files at the schema's bounds are read. The versions the docs say are still read
(a version-1 record's "key=value" writer settings, a version-2 session.json's `human` writer) are held to the
schema that is said to describe them.

CALLIGRAPHY_CLI names the program; PYTHONPATH the built Python package; CALLIGRAPHY_SOURCE_DIR the source tree
(docs/). CALLIGRAPHY_SANITIZED=1 takes five cases.
"""
import copy
import json
import os
import re
import shutil
import tempfile
import unittest
import warnings
from pathlib import Path

from outsider import OneErrorLine, run, run_ok, sanitized_subset

try:
    import jsonschema
except ImportError:  # reported by setUpModule: every case holds a file to a schema with it
    jsonschema = None

try:
    import numpy as np
    import calligraphy as cg
except ImportError:  # only the Python case needs them; it says so
    np = cg = None

SOURCE = Path(os.environ.get("CALLIGRAPHY_SOURCE_DIR", Path(__file__).resolve().parents[2]))
DOCUMENTS = ("specification", "record", "protocol", "session", "metrics")

load_tests = sanitized_subset({"test_every_default_a_schema_states_is_a_value_its_own_property_accepts",
                               "test_schema_usage_errors_are_one_line_and_a_full_output_is_exit_1",
                               "test_record_breaking_one_rule_is_refused_by_schema_and_trial_check_at_its_pointer",
                               "test_version_1_record_with_key_value_writer_settings_is_read_and_valid_to_its_schema",
                               "test_session_json_of_version_2_with_writer_human_is_read_and_valid_to_its_schema"})

TINY_PROTOCOL = {"name": "r33b", "conditions": [{"name": "v", "mode": "vision"}],
                 "test": {"characters": ["十"], "conditions": ["v"], "repetitions": 1},
                 "trial": {"max_duration_s": 30}}


def setUpModule():
    if jsonschema is None:
        raise unittest.SkipTest("Python's jsonschema is needed to hold files to the schemas")


_SCHEMAS = {}


def schema(name, markdown=False):
    """`calligraphy schema NAME [--markdown]`: the JSON Schema as a dict, or the Markdown text (run once)."""
    key = (name, markdown)
    if key not in _SCHEMAS:
        out = run_ok(["schema", name] + (["--markdown"] if markdown else []), tempfile.gettempdir())
        text = out.stdout.decode("utf-8")
        _SCHEMAS[key] = text if markdown else json.loads(text)
    return _SCHEMAS[key]


def validator(name):
    return jsonschema.Draft202012Validator(schema(name))


def errors(name, document):
    """jsonschema's errors of `document` against `calligraphy schema NAME`, as (pointer, message)."""
    return [("/" + "/".join(map(str, e.absolute_path)), e.message[:160])
            for e in validator(name).iter_errors(document)]


def md_rows(text):
    """The rows of a Markdown table whose first cell is a `name`: lists of cells, `\\|` kept inside a cell."""
    rows = []
    for line in text.splitlines():
        if line.startswith("| `"):
            rows.append([c.strip() for c in re.split(r"(?<!\\)\|", line.strip())[1:-1]])
    return rows


def number_text(x):
    text = repr(float(x)) if isinstance(x, float) else str(x)
    return text[:-2] if text.endswith(".0") else text


def unit_of(description):
    found = re.search(r" \[([^\]]+)\]", description or "")
    return found.group(1) if found else ""


def expected_cells(prop):
    """The kind, unit and range cells a JSON Schema property makes in `schema ... --markdown` (the trial
    specification's table, docs/cli.md, shows the form)."""
    kind_of = prop.get("type")
    unit = unit_of(prop.get("description"))
    if "enum" in prop:
        kind = "enumeration"
    elif kind_of == "array":
        kind = "object list"
    elif kind_of is None and "const" in prop:
        kind = "string"
    elif kind_of is None:
        kind = "object"
    else:
        kind = kind_of
    span = ""
    if kind_of == "boolean":
        span = "true\\|false"
    elif "enum" in prop:
        span = "\\|".join(prop["enum"])
    elif kind_of == "integer" and "minimum" in prop and "maximum" in prop:
        span = f"{prop['minimum']}..{prop['maximum']}"
    elif kind_of == "number":
        low = ("[", prop["minimum"]) if "minimum" in prop else \
            ("(", prop["exclusiveMinimum"]) if "exclusiveMinimum" in prop else None
        high = ("]", prop["maximum"]) if "maximum" in prop else \
            (")", prop["exclusiveMaximum"]) if "exclusiveMaximum" in prop else None
        tail = f" {unit}" if unit else ""
        if low and high:
            span = f"in {low[0]}{number_text(low[1])}, {number_text(high[1])}{high[0]}{tail}"
        elif low:
            span = (">= " if low[0] == "[" else "> ") + number_text(low[1]) + tail
    return [kind, unit, span]


def with_defs(sub, whole):
    """`sub` (a property's schema) as a schema of its own: its annotations dropped, the document's $defs kept."""
    if sub is True or sub is False:
        return sub
    own = {k: v for k, v in sub.items() if k not in ("default", "description", "title")}
    own["$defs"] = whole.get("$defs", {})
    return own


def set_at(document, pointer, value):
    parts = [int(p) if p.isdigit() else p for p in pointer.strip("/").split("/")]
    node = document
    for part in parts[:-1]:
        node = node.setdefault(part, {}) if isinstance(node, dict) else node[part]
    if value is DELETE:
        del node[parts[-1]]
    else:
        node[parts[-1]] = value


DELETE = object()


def names_pointer(line, pointer):
    """The error line names `pointer`: itself, a value below it, or (a key missing or unknown) its parent."""
    parent = pointer.rsplit("/", 1)[0] or "/"
    return f"{pointer}:" in line or f"{pointer}/" in line or f"{parent}:" in line


class Schemas(unittest.TestCase, OneErrorLine):
    """The schemas themselves, their Markdown and the docs' tables."""
    maxDiff = None

    def test_every_schema_is_valid_draft_2020_12_and_every_ref_resolves(self):
        for name in DOCUMENTS:
            document = schema(name)
            self.assertEqual(document["$schema"], "https://json-schema.org/draft/2020-12/schema", name)
            jsonschema.Draft202012Validator.check_schema(document)
            refs = []

            def walk(node):
                if isinstance(node, dict):
                    if "$ref" in node:
                        refs.append(node["$ref"])
                    for value in node.values():
                        walk(value)
                elif isinstance(node, list):
                    for value in node:
                        walk(value)
            walk(document)
            for ref in refs:
                node = document
                for part in ref.lstrip("#/").split("/"):
                    self.assertIn(part, node, f"{name}: {ref} does not resolve")
                    node = node[part]

    def test_specification_markdown_is_the_docs_table_and_agrees_with_its_json_schema(self):
        text = (SOURCE / "docs" / "cli.md").read_text(encoding="utf-8")
        pasted = text.split("<!-- schema specification -->\n", 1)[1].split("<!-- end schema specification -->", 1)[0]
        self.assertEqual(pasted.strip(), schema("specification", True).strip())
        props = schema("specification")["properties"]
        rows = md_rows(schema("specification", True))
        self.assertEqual([r[0] for r in rows], [f"`{k}`" for k in props])
        for row in rows:
            prop = props[row[0].strip("`")]
            self.assertEqual(row[1:4], expected_cells(prop), row[0])
            default = prop["default"]
            if "enum" in prop:
                self.assertEqual(row[4], f"`{default}`", row[0])
            else:
                self.assertEqual(json.loads(row[4].strip("`")), default, row[0])

    def test_record_session_and_protocol_markdown_rows_agree_with_their_json_schemas(self):
        for name in ("record", "session"):
            props = schema(name)["properties"]
            rows = md_rows(schema(name, True))
            self.assertEqual([r[0] for r in rows], [f"`{k}`" for k in props], name)
            for row in rows:
                self.assertEqual(row[1:4], expected_cells(props[row[0].strip("`")]), f"{name} {row[0]}")
        protocol = schema("protocol")
        parts = schema("protocol", True).split("### ")[1:]
        self.assertEqual([p.split("\n", 1)[0].strip() for p in parts], ["trial", "breaks"])
        for part in parts:
            title = part.split("\n", 1)[0].strip()
            ref = protocol["properties"][title]["$ref"].split("/")[-1]
            props = protocol["$defs"][ref]["properties"]
            rows = md_rows(part)
            self.assertEqual([r[0] for r in rows], [f"`{k}`" for k in props], title)
            for row in rows:
                prop = props[row[0].strip("`")]
                self.assertEqual(row[1:4], expected_cells(prop), f"{title} {row[0]}")
                self.assertEqual(json.loads(row[4].strip("`")), prop["default"], f"{title} {row[0]}")

    def test_every_default_a_schema_states_is_a_value_its_own_property_accepts(self):
        # docs/cli.md "schema": every field a property with its type, `description`, `default`, ranges; the
        # session's `--markdown` prints its top-level fields as a table (default column). A default is what a
        # key left out means: it must be a value the schema (and the reader) takes.
        bad = []
        for name in DOCUMENTS:
            whole = schema(name)

            def walk(node, path):
                if isinstance(node, dict):
                    if "default" in node and not jsonschema.Draft202012Validator(
                            with_defs(node, whole)).is_valid(node["default"]):
                        bad.append(f"{name} {path}: default {node['default']!r}")
                    for key, value in node.items():
                        walk(value, f"{path}/{key}")
                elif isinstance(node, list):
                    for i, value in enumerate(node):
                        walk(value, f"{path}/{i}")
            walk(whole, "")
        for name in ("specification", "record", "session"):
            whole = schema(name)
            for row in md_rows(schema(name, True)):
                cell = row[4].strip("`")
                prop = whole["properties"][row[0].strip("`")]
                try:
                    value = json.loads(cell)
                except ValueError:
                    if "enum" not in prop:
                        continue        # a struct's name (`TrialSpec`): the object's own defaults
                    value = cell
                if not jsonschema.Draft202012Validator(with_defs(prop, whole)).is_valid(value):
                    bad.append(f"{name} --markdown {row[0]}: default {row[4]}")
        self.assertEqual(bad, [])

    def test_protocol_quiz_acceptance_is_the_records_stroke_acceptance(self):
        # docs/experiments.md: a quiz's `acceptance` is "read as a trial specification's and a trial record's
        # acceptance are (one schema)"; its `hint_after_misses` "(optional, 0..1000, 0 never)".
        record = schema("record")["$defs"]["StrokeAcceptance"]["properties"]
        quiz = schema("protocol")["$defs"]["QuizOptions"]["properties"]
        keys = ("type", "minimum", "maximum", "exclusiveMinimum", "exclusiveMaximum")
        self.assertEqual(list(quiz["acceptance"]["properties"]), list(record))
        for field, prop in record.items():
            self.assertEqual({k: quiz["acceptance"]["properties"][field].get(k) for k in keys},
                             {k: prop.get(k) for k in keys}, field)
        self.assertEqual((quiz["hint_after_misses"]["minimum"], quiz["hint_after_misses"]["maximum"]), (0, 1000))
        spec = schema("specification")["properties"]
        for field, prop in record.items():
            self.assertEqual({k: spec[field].get(k) for k in keys + ("default",)},
                             {k: prop.get(k) for k in keys + ("default",)}, field)

    def test_metrics_markdown_is_the_docs_table_and_its_scene_rows_are_the_json_properties(self):
        text = (SOURCE / "docs" / "metrics.md").read_text(encoding="utf-8")
        pasted = text.split("<!-- schema metrics -->\n", 1)[1].split("<!-- end schema metrics -->", 1)[0]
        self.assertEqual(pasted.strip(), schema("metrics", True).strip())
        props = schema("metrics")["properties"]
        self.assertEqual(schema("metrics")["required"], list(props))
        scene = [r for r in md_rows(schema("metrics", True))
                 if "scene" in [level.strip() for level in r[3].split(",")]]
        self.assertEqual([r[0] for r in scene], [f"`{k}`" for k in props])
        kinds = {"count": {"type": "integer", "minimum": 0}, "flag": {"type": "boolean"},
                 "number": {"type": ["number", "null"]}}
        for row in scene:
            prop = props[row[0].strip("`")]
            self.assertEqual({k: prop.get(k) for k in kinds[row[1]]}, kinds[row[1]], row[0])
            self.assertEqual(unit_of(prop["description"]), "" if row[2] in ("-", "1") else row[2], row[0])
            self.assertEqual(re.sub(r" \[[^\]]+\]$", "", prop["description"]), row[4], row[0])

    def test_metrics_record_totals_the_docs_list_are_rows_of_the_metric_table_and_schema(self):
        # docs/metrics.md, "The one metrics record": the totals table lists the record's keys
        # (`strokes_accepted`, `refusals`, ...); "The metric table": "Every metric has one name ... in one
        # table ... The keys of the metrics record (`writing_metrics_json`, so `calligraphy trial --json`, ...)
        # are made from it, value and name, and nothing else."
        text = (SOURCE / "docs" / "metrics.md").read_text(encoding="utf-8")
        totals = text.split("The totals:", 1)[1].split("Every index", 1)[0]
        keys = []
        for row in totals.splitlines():
            if row.startswith("| `"):
                keys += re.findall(r"`([a-z_]+)`", row.split("|")[1])
        keys = [k for k in keys if k != "per_character"]
        self.assertIn("mean_deviation_m", keys)
        table = {r[0].strip("`") for r in md_rows(schema("metrics", True))}
        props = schema("metrics")["properties"]
        self.assertEqual([k for k in keys if k not in table or k not in props], [])

    def test_schema_usage_errors_are_one_line_and_a_full_output_is_exit_1(self):
        d = tempfile.gettempdir()
        self.assert_one_error(run(["schema", "recrod"], d), 2, "DOCUMENT", "recrod")
        self.assert_one_error(run(["schema"], d), 2, "DOCUMENT")
        self.assert_one_error(run(["schema", "record", "--markdown=yes"], d), 2, "--markdown")
        with open("/dev/full", "wb") as full:
            result = run(["schema", "record"], d, stdout=full)
        self.assert_one_error(result, 1)
        again = run_ok(["schema", "record"], d)
        self.assertEqual(json.loads(again.stdout), schema("record"), "the same schema every run")


class TrialFiles(unittest.TestCase, OneErrorLine):
    """A trial's record, its CSV scored again, and `trial --spec --check` against `schema record`."""

    @classmethod
    def setUpClass(cls):
        cls.tmp = Path(tempfile.mkdtemp(prefix="round33b-trial-"))
        run_ok(["trial", "十", "--guidance-mode", "fading", "--guidance-gain", "0.4", "--writer-param",
                "bias_offset_m=0.004", "--max-duration", "30", "--seed", "7", "--json", "t.json",
                "--csv", "t.csv"], cls.tmp)
        cls.record = json.loads((cls.tmp / "t.json").read_text(encoding="utf-8"))

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.tmp, ignore_errors=True)

    def check(self, record, name="m.json"):
        (self.tmp / name).write_text(json.dumps(record, ensure_ascii=False), encoding="utf-8")
        return run(["trial", "--spec", name, "--check"], self.tmp)

    def test_trial_json_validates_against_record_specification_and_metrics_schemas(self):
        self.assertEqual(errors("record", self.record["specification"]), [])
        self.assertEqual(errors("specification", self.record["specification"]["trial"]), [])
        self.assertEqual(errors("metrics", self.record), [])
        self.assertEqual(self.record["specification"]["force_law"]["guidance_law"],
                         {"mode": "fading", "gain": 0.4})

    def test_score_json_of_the_trace_and_a_pen_that_never_touched_validate_against_metrics(self):
        scored = json.loads(run_ok(["score", "t.csv", "--character", "十", "--json", "-"], self.tmp).stdout)
        self.assertEqual(errors("metrics", scored), [])
        for key in schema("metrics")["properties"]:
            if isinstance(scored[key], float):
                self.assertAlmostEqual(scored[key], self.record[key], delta=1e-6 * max(1.0, abs(scored[key])))
            else:
                self.assertEqual(scored[key], self.record[key], key)
        # A trial too short to touch the paper: every distance and time null, never 0 (docs/cli.md).
        result = run(["trial", "十", "--max-duration", "0.01", "--json", "n.json", "--csv", "n.csv"], self.tmp)
        self.assert_one_error(result, 1, "time_limit")
        never = json.loads((self.tmp / "n.json").read_text(encoding="utf-8"))
        self.assertEqual(errors("metrics", never), [])
        self.assertEqual(errors("record", never["specification"]), [])
        self.assertIsNone(never["total_time_s"])
        self.assertIsNone(never["mean_deviation_m"])
        rescored = json.loads(run_ok(["score", "n.csv", "--character", "十", "--json", "-"], self.tmp).stdout)
        self.assertEqual(errors("metrics", rescored), [])

    def test_record_breaking_one_rule_is_refused_by_schema_and_trial_check_at_its_pointer(self):
        # docs/cli.md "schema": "every value it refuses is refused by `trial --spec` naming the pointer";
        # "Re-running a trial": exit 2, one line naming the file and the JSON pointer.
        cases = [("/specification/force_law/crossfade_s", 10.5),              # past its maximum 10 s
                 ("/specification/trial/seed", "7"),                          # a text for an integer
                 ("/specification/safety/peak_n", 1.0),                       # an unknown key
                 ("/specification/passivity/enabled", DELETE),                # a required key missing
                 ("/specification/force_law/nearest/method", "Exact"),        # an enumeration spelt otherwise
                 ("/specification/scene/layout/start_radius_m", 0.0)]         # an open bound
        for pointer, value in cases:
            with self.subTest(pointer=pointer, value=value if value is not DELETE else "missing"):
                record = copy.deepcopy(self.record)
                set_at(record, pointer, value)
                self.assertNotEqual(errors("record", record["specification"]), [])
                line = self.assert_one_error(self.check(record), 2, "m.json")
                self.assertTrue(names_pointer(line, pointer), line)

    def test_record_at_its_schemas_bounds_is_valid_to_both(self):
        low = {"/specification/force_law/crossfade_s": 0.0, "/specification/force_law/paper_fade_s": 0.0,
               "/specification/force_law/contact_hysteresis_m": 0.0,
               "/specification/force_law/constraint_taper_m": 0.0,
               "/specification/safety/low_pass_cutoff_hz": 0.0, "/specification/safety/start_ramp_n_per_s": 0.0,
               "/specification/force_law/nearest/newton_starts": 1,
               "/specification/force_law/nearest/newton_iterations": 1,
               "/specification/scene/layout/paper_z_m": -1.0, "/specification/trial/seed": 0,
               "/specification/trial/rate_hz": 100.0}
        high = {"/specification/force_law/crossfade_s": 10.0, "/specification/force_law/paper_fade_s": 10.0,
                "/specification/force_law/contact_hysteresis_m": 0.1, "/specification/safety/max_force_n": 100.0,
                "/specification/safety/max_continuous_force_n": 100.0,
                "/specification/safety/continuous_time_constant_s": 86400.0,
                "/specification/force_law/nearest/newton_starts": 1000,
                "/specification/force_law/nearest/newton_iterations": 1000,
                "/specification/force_law/nearest/tolerance": 0.001,
                "/specification/scene/layout/paper_z_m": 1.0, "/specification/trial/seed": 2 ** 64 - 1,
                "/specification/trial/max_duration_s": 100.0, "/specification/trial/rate_hz": 100000.0}
        props = {"crossfade_s": schema("record")["$defs"]["ForceLawParameters"]["properties"]["crossfade_s"]}
        self.assertEqual((props["crossfade_s"]["minimum"], props["crossfade_s"]["maximum"]), (0.0, 10.0))
        for label, values in (("low", low), ("high", high)):
            record = copy.deepcopy(self.record)
            for pointer, value in values.items():
                set_at(record, pointer, value)
            self.assertEqual(errors("record", record["specification"]), [], label)
            result = self.check(record, f"{label}.json")
            self.assertEqual(result.returncode, 0, result.stderr.decode("utf-8", "replace"))

    def test_version_1_record_with_key_value_writer_settings_is_read_and_valid_to_its_schema(self):
        # docs/cli.md "Re-running a trial": "version 2, written before the trial stated its guidance
        # stiffness, and version 1, whose writer settings were `"key=value"` strings, are still read";
        # "schema": "every value it refuses is refused by `trial --spec` naming the pointer".
        spec = copy.deepcopy(self.record["specification"])
        acceptance = spec["force_law"]["acceptance"]
        for field in schema("record")["$defs"]["StrokeAcceptance"]["properties"]:
            spec["trial"].pop(field, None)                      # the trial's acceptance: version 6
        for field in ("miss_min_path_m", "centred_coverage_fraction", "centred_balance_fraction",
                      "centred_min_length_m", "centred_max_length_m", "end_gap_m", "end_gap_fraction",
                      "shortfall_per_length", "shortfall_cap_m", "deviation_per_length", "mean_deviation_cap_m",
                      "reference_character_size_m", "hint_after_misses", "assist_after_misses"):
            acceptance.pop(field)                               # versions 8, 7, 5 and 4
        spec.pop("teacher_sha256")                              # version 4
        spec["trial"].pop("guidance_stiffness_n_per_m")         # version 3
        self.assertEqual(spec["trial"]["writer_parameters"], [{"key": "bias_offset_m", "value": 0.004}])
        spec["trial"]["writer_parameters"] = ["bias_offset_m=0.004"]
        v2 = copy.deepcopy(spec)
        v2["version"] = 2
        # A version 2 record with a setting as text: refused by both, at the setting's pointer.
        self.assertNotEqual(errors("record", v2), [])
        self.assert_one_error(self.check(dict(self.record, specification=v2), "v2.json"), 2, "v2.json",
                              "/specification/trial/writer_parameters/0")
        spec["version"] = 1
        result = self.check(dict(self.record, specification=spec), "v1.json")
        self.assertEqual(result.returncode, 0, result.stderr.decode("utf-8", "replace"))
        self.assertIn(b"v1.json: a valid trial specification", result.stdout)
        self.assertEqual(errors("record", spec), [], "schema record refuses the version-1 record trial --spec reads")


class SessionFiles(unittest.TestCase, OneErrorLine):
    """A session's session.json and records against `schema session|record|metrics|protocol`, and their
    readers (`session resume`, `report`, `session plan`)."""

    @classmethod
    def setUpClass(cls):
        cls.tmp = Path(tempfile.mkdtemp(prefix="round33b-session-"))
        (cls.tmp / "p.json").write_text(json.dumps(TINY_PROTOCOL, ensure_ascii=False), encoding="utf-8")
        run_ok(["session", "run", "p.json", "--subjects", "1", "--out", "S"], cls.tmp)
        cls.folder = next((cls.tmp / "S" / "S01").glob("r33b-S01-*"))
        cls.manifest = json.loads((cls.folder / "session.json").read_text(encoding="utf-8"))
        # A copy of the whole study (its identity file too) whose session.json the cases edit.
        shutil.copytree(cls.tmp / "S", cls.tmp / "C", ignore=shutil.ignore_patterns(".calligraphy-run.lock"))
        cls.copy = cls.tmp / "C" / "S01" / cls.folder.name
        (cls.tmp / "csv").mkdir()

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.tmp, ignore_errors=True)

    def readers(self, manifest):
        """session.json of the copy set to `manifest`; `session resume` and `report --csv` of it."""
        (self.copy / "session.json").write_text(json.dumps(manifest, ensure_ascii=False), encoding="utf-8")
        return (run(["session", "resume", str(self.copy)], self.tmp),
                run(["report", str(self.tmp / "C"), "--csv", str(self.tmp / "csv")], self.tmp))

    def test_session_json_its_protocol_copy_and_records_validate(self):
        self.assertEqual(errors("session", self.manifest), [])
        self.assertEqual(errors("protocol", json.loads(self.manifest["protocol"]["text"])), [])
        records = sorted((self.folder / "trials").glob("*.json"))
        self.assertEqual(len(records), 1)
        record = json.loads(records[0].read_text(encoding="utf-8"))
        self.assertEqual(errors("record", record["specification"]), [])
        self.assertEqual(errors("metrics", record), [])
        self.assertEqual(record["specification"]["trial"]["max_duration_s"], 30.0)

    def test_session_json_breaking_one_rule_is_refused_by_resume_and_report_at_its_pointer(self):
        # docs/cli.md "schema": "every value the schema refuses, the readers refuse, naming the file and the
        # JSON pointer (`session resume` exit 2, the others 1)".
        cases = [("/session_number", 21), ("/writer", "Simulated"), ("/pacing", "lock_step"),
                 ("/plan/0/index", 1.5), ("/device", DELETE), ("/subject/age", 30)]
        try:
            for pointer, value in cases:
                with self.subTest(pointer=pointer):
                    manifest = copy.deepcopy(self.manifest)
                    set_at(manifest, pointer, value)
                    self.assertNotEqual(errors("session", manifest), [])
                    resume, report = self.readers(manifest)
                    for result, status in ((resume, 2), (report, 1)):
                        line = self.assert_one_error(result, status, "session.json")
                        self.assertTrue(names_pointer(line, pointer), line)
        finally:
            self.readers(self.manifest)

    def test_session_json_of_version_2_with_writer_human_is_read_and_valid_to_its_schema(self):
        # docs/experiments.md "Tidy tables": "versions 1 and 2 called a person writing `human` in
        # session.json's `writer`, read as `person`"; docs/cli.md "schema": the session schema is "made from
        # the schema every reader of session.json reads it with ... every value the schema refuses, the
        # readers refuse".
        try:
            manifest = copy.deepcopy(self.manifest)
            manifest["version"], manifest["writer"] = 3, "human"
            resume, _ = self.readers(manifest)
            self.assert_one_error(resume, 2, "session.json", "/writer")
            self.assertNotEqual(errors("session", manifest), [])
            manifest["version"] = 2
            resume, _ = self.readers(manifest)
            self.assertEqual(resume.returncode, 0, resume.stderr.decode("utf-8", "replace"))
            self.assertEqual(errors("session", manifest), [],
                             "schema session refuses the version-2 session.json session resume reads")
        finally:
            self.readers(self.manifest)

    def test_example_protocols_validate_and_session_plan_reads_them(self):
        # docs/experiments.md: "every protocol under `examples/protocols/` ... validates against it".
        protocols = sorted((SOURCE / "examples" / "protocols").glob("*.json"))
        self.assertGreaterEqual(len(protocols), 5)
        for path in protocols:
            with self.subTest(protocol=path.name):
                self.assertEqual(errors("protocol", json.loads(path.read_text(encoding="utf-8"))), [])
                run_ok(["session", "plan", str(path), "--subjects", "1"], self.tmp)

    def test_protocol_breaking_one_rule_is_refused_by_session_plan_and_at_its_bounds_read(self):
        # docs/cli.md "schema": "every value the schema refuses, the reader refuses (exit 2, as every
        # protocol refused, one line naming the file and the JSON pointer)".
        cases = [("/trial/rate_hz", 10001), ("/order/conditions", "latin"), ("/conditions/0/mode", "Vision"),
                 ("/test/items", ["十"]), ("/test/repetitions", DELETE), ("/test/conditions", ["v", "v"]),
                 ("/test/characters/0", "十" * 17), ("/name", "r33b.x")]
        for pointer, value in cases:
            with self.subTest(pointer=pointer):
                protocol = copy.deepcopy(TINY_PROTOCOL)
                set_at(protocol, pointer, value)
                self.assertNotEqual(errors("protocol", protocol), [])
                (self.tmp / "bad.json").write_text(json.dumps(protocol, ensure_ascii=False), encoding="utf-8")
                line = self.assert_one_error(run(["session", "plan", "bad.json", "--subjects", "1"], self.tmp),
                                             2, "bad.json")
                self.assertTrue(names_pointer(line, pointer), line)
        # Each value at the schema's bound at once: valid to both.
        protocol = {"name": "A" * 64, "conditions": [{"name": "v" * 32, "mode": "vision"}],
                    "test": {"characters": ["十" * 16], "conditions": ["v" * 32], "repetitions": 1000},
                    "order": {"seed": 2 ** 64 - 1},
                    "breaks": {"every_trials": 100000, "duration_s": 86400, "between_blocks_s": 86400},
                    "trial": {"max_duration_s": 1000, "rate_hz": 10000}}
        self.assertEqual(errors("protocol", protocol), [])
        (self.tmp / "edge.json").write_text(json.dumps(protocol, ensure_ascii=False), encoding="utf-8")
        run_ok(["session", "plan", "edge.json", "--subjects", "1"], self.tmp)


class PythonRecord(unittest.TestCase):
    """docs/python.md "Running a trial again": a record Python writes for a simulated device of its own."""

    def test_record_of_a_callers_simulated_device_validates_and_reruns_the_same(self):
        # docs/python.md: "`r.metrics["specification"]` is the whole specification that ran ... a simulated
        # device's physics ... `rerun_trial` runs it again; on the simulated device the arrays are equal
        # element for element"; docs/cli.md: `simulated_device` "the physics of a simulated device made by the
        # caller (Python's `simulate_trial(device=...)`)".
        if cg is None:
            self.skipTest("numpy and the calligraphy Python package (PYTHONPATH) are needed")
        own = cg.SimulatedDeviceParameters().info
        info = cg.DeviceInfo(model="weak", manufacturer="round33b", max_force_n=0.5,
                             max_continuous_force_n=0.4, max_stiffness_n_per_m=own.max_stiffness_n_per_m,
                             max_damping_n_s_per_m=own.max_damping_n_s_per_m,
                             intrinsic_damping_n_s_per_m=own.intrinsic_damping_n_s_per_m,
                             workspace_radius_m=own.workspace_radius_m, workspace_size_m=own.workspace_size_m)
        first = cg.simulate_trial("十", device=cg.SimulatedDeviceParameters(info=info), max_duration_s=20)
        record = first.metrics
        self.assertEqual(errors("record", record["specification"]), [])
        self.assertEqual(errors("metrics", dict(record)), [])
        self.assertLessEqual(record["max_force_n"], 0.5 + 1e-9, "the device's peak force bounds the run")
        with warnings.catch_warnings(record=True) as said:
            warnings.simplefilter("always")
            again = cg.rerun_trial(record)
        self.assertEqual([str(w.message)[:200] for w in said if issubclass(w.category, RuntimeWarning)], [])
        self.assertEqual(again.metrics["max_force_n"], record["max_force_n"])
        self.assertTrue(np.array_equal(again.position_m, first.position_m))


if __name__ == "__main__":
    unittest.main()
