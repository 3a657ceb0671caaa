#!/usr/bin/env python3
"""Round 28F: the schemas against the files, and the smaller commands. From the docs alone (docs/cli.md
"schema", "Re-running a trial", "The trial specification", `curriculum`, `corpus`, `characters`, `strokes`;
docs/experiments.md "Protocol files", "Phases", "Sessions", "Trial records", "What to practise next";
docs/metrics.md "The one metrics record", "The metric table"; docs/corpus.md "Store format", "Checks and
errors"; docs/typical-strokes.md).

`calligraphy schema specification|record|protocol|session|metrics` is held against the files the program
writes (a `trial --json` record, a time-limited one, a session's session.json, its trial record and protocol
copy) with an independent validator (Python's `jsonschema`, Draft 2020-12), and both ways against the readers:
files built by hand at each field's bound (optional keys left out) must be taken by `trial --spec --check`,
`session plan`, `session resume` and `report`, and values just past a bound, of another type, null or an
unknown key refused by the reader and the schema alike, the JSON pointer named. The defaults the schemas state
are held to `trial --help`, the docs' tables and `--markdown`. `curriculum` is given its own subject's history,
another subject, a history with its records removed or damaged, and odd options; `corpus stats` a store built
from four characters of the source tree's data, copied, cut, with records damaged and with header fields edited
(their CRCs put right, so that only the documented field checks can refuse them); `characters` and `strokes`
are held to their tables.

CALLIGRAPHY_CLI names the program; CALLIGRAPHY_SOURCE_DIR the source tree (docs, data/hanzi-writer-data).
CALLIGRAPHY_SANITIZED=1 takes five cases.
"""
import copy
import json
import os
import re
import shutil
import struct
import tempfile
import unittest
import zlib
from pathlib import Path

from outsider import OneErrorLine, error_lines, run, run_ok, sanitized_subset

try:
    from jsonschema import Draft202012Validator
except ImportError:  # reported by setUpClass
    Draft202012Validator = None

load_tests = sanitized_subset({"test_every_schema_is_a_draft_2020_12_schema",
                               "test_record_past_a_bound_is_refused_by_schema_and_check_alike",
                               "test_store_cut_by_one_byte_is_one_error_naming_it",
                               "test_schema_usage_errors_name_what_is_wrong",
                               "test_strokes_json_is_the_table_of_typical_strokes_md"})

SOURCE = Path(os.environ.get("CALLIGRAPHY_SOURCE_DIR", Path(__file__).resolve().parents[2]))
KINDS = ("specification", "record", "protocol", "session", "metrics")
DRAFT = "https://json-schema.org/draft/2020-12/schema"
# The smallest protocol: every optional key left out, so that its trial takes the schema's defaults.
PROTOCOL = {"name": "tiny", "conditions": [{"name": "v", "mode": "vision"}],
            "test": {"characters": ["十"], "conditions": ["v"], "repetitions": 1}}
STORE_CHARS = "十人口乙"          # all four in data/hanzi-writer-data of the source tree
RECORD_PARTS = ("format", "version", "trial", "force_law", "safety", "passivity", "writer", "simulated_device",
                "scene", "library_version", "teacher_sha256")


def pointer(path):
    """A jsonschema error's path as a JSON pointer."""
    return "".join("/" + str(p).replace("~", "~0").replace("/", "~1") for p in path)


def put(doc, ptr, value=None, delete=False):
    """A copy of `doc` with the value at `ptr` set, objects missing on the way made (or the key removed)."""
    doc = copy.deepcopy(doc)
    parts = ptr.strip("/").split("/")
    parent = doc
    for part in parts[:-1]:
        parent = parent[int(part)] if isinstance(parent, list) else parent.setdefault(part, {})
    key = int(parts[-1]) if isinstance(parent, list) else parts[-1]
    if delete:
        del parent[key]
    else:
        parent[key] = value
    return doc


def help_defaults(text):
    """`--help`'s options: {"--name": "default text"}, continuation lines joined."""
    found, current = {}, None
    for line in text.splitlines():
        m = re.match(r"^  (?:-\w,)?(--[a-z-]+)", line)
        if m:
            current = m.group(1)
            found[current] = line
        elif current and line.startswith("      "):
            found[current] += " " + line.strip()
        else:
            current = None
    return {k: re.search(r"\(default: ([^)]*)\)\s*$", v).group(1) for k, v in found.items()
            if re.search(r"\(default: ([^)]*)\)\s*$", v)}


def cells_of(line):
    """A Markdown table row's cells, split at the pipes that are not escaped (`a\\|b` is one cell)."""
    return [c.strip() for c in re.split(r"(?<!\\)\|", line)]


def crc(data):
    return zlib.crc32(data) & 0xFFFFFFFF


class Store:
    """A corpus store's header and index as docs/corpus.md "Store format" lays them out."""

    def __init__(self, data):
        self.data = bytearray(data)
        (self.magic, self.major, self.minor, self.header_size, self.count, self.steps, self.tolerance, self.flags,
         self.index_offset, self.records_offset, self.records_size, self.tables_crc,
         self.header_crc) = struct.unpack_from("<8sHHIIIfIQQQII", self.data, 0)
        self.index = [struct.unpack_from("<III", self.data, self.index_offset + 12 * i) for i in range(self.count)]

    def record_span(self, i):
        start = self.records_offset + self.index[i][1]
        end = (self.records_offset + self.index[i + 1][1] if i + 1 < self.count
               else self.records_offset + self.records_size)
        return start, end

    def fix_crcs(self):
        """Every CRC put right after an edit: each record's in the index, the tables', the header's."""
        for i in range(self.count):
            start, end = self.record_span(i)
            code, offset, _ = struct.unpack_from("<III", self.data, self.index_offset + 12 * i)
            struct.pack_into("<III", self.data, self.index_offset + 12 * i, code, offset, crc(self.data[start:end]))
        struct.pack_into("<I", self.data, 56, crc(self.data[64:self.records_offset]))
        struct.pack_into("<I", self.data, 60, crc(self.data[0:60]))
        return bytes(self.data)


class Round28F(unittest.TestCase, OneErrorLine):
    @classmethod
    def setUpClass(cls):
        if Draft202012Validator is None:
            raise unittest.SkipTest("Python's jsonschema is needed")
        cls.tmp = Path(tempfile.mkdtemp(prefix="round28f-"))
        d = cls.tmp
        cls.schema = {k: json.loads(run_ok(["schema", k], d).stdout) for k in KINDS}
        # A trial record of 十.
        run_ok(["trial", "十", "--json", "t.json"], d)
        cls.trial = json.loads((d / "t.json").read_text(encoding="utf-8"))

    @classmethod
    def build_study(cls):
        """A study of one trial, every optional protocol key left out (made once, when a case needs it)."""
        d = cls.tmp
        if "session" in cls.__dict__:
            return
        (d / "p.json").write_text(json.dumps(PROTOCOL, ensure_ascii=False), encoding="utf-8")
        run_ok(["session", "run", "p.json", "--subject", "S01", "--out", "study", "--writer-learning", "none",
                "--individual-differences", "off"], d)
        session = next((d / "study" / "S01").glob("tiny-S01-*"))
        cls.manifest = json.loads((session / "session.json").read_text(encoding="utf-8"))
        cls.record_file = next((session / "trials").glob("*.json"))
        cls.record = json.loads(cls.record_file.read_text(encoding="utf-8"))
        cls.session = session

    @classmethod
    def build_store(cls):
        """A store of four characters of the source tree's data (made once, when a case needs it)."""
        d = cls.tmp
        if "store_bytes" in cls.__dict__:
            return
        (d / "data").mkdir()
        for c in STORE_CHARS:
            shutil.copy(SOURCE / "data" / "hanzi-writer-data" / f"{c}.json", d / "data")
        run_ok(["corpus", "build", "--data", "data", "--out", "s.clg", "--threads", "1"], d)
        cls.store_bytes = (d / "s.clg").read_bytes()

    def __getattr__(self, name):
        if name in ("session", "manifest", "record", "record_file"):
            type(self).build_study()
        elif name == "store_bytes":
            type(self).build_store()
        else:
            raise AttributeError(name)
        return type(self).__dict__[name]

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.tmp, ignore_errors=True)

    def cli(self, *args):
        return run(list(args), self.tmp)

    def validator(self, kind):
        return Draft202012Validator(self.schema[kind], format_checker=Draft202012Validator.FORMAT_CHECKER)

    def schema_errors(self, kind, doc):
        return [pointer(e.absolute_path) for e in self.validator(kind).iter_errors(doc)]

    def assertValid(self, kind, doc, what):
        errors = [f"{pointer(e.absolute_path)}: {e.message[:200]}" for e in self.validator(kind).iter_errors(doc)]
        self.assertEqual(errors, [], f"{what} against `schema {kind}`")

    def assertSchemaRefuses(self, kind, doc, ptr):
        """The schema refuses `doc` at `ptr` or at an object holding it (an unknown key's parent)."""
        errors = self.schema_errors(kind, doc)
        self.assertTrue(errors, f"`schema {kind}` takes the document the reader refuses at {ptr}")
        self.assertTrue(any(ptr == e or ptr.startswith(e + "/") for e in errors),
                        f"`schema {kind}` refuses at {errors}, not at {ptr}")

    # ---- the schemas themselves ---------------------------------------------------------------------------
    def test_every_schema_is_a_draft_2020_12_schema(self):
        for kind in KINDS:
            with self.subTest(kind=kind):
                self.assertEqual(self.schema[kind].get("$schema"), DRAFT)
                Draft202012Validator.check_schema(self.schema[kind])

    def test_record_schema_requires_every_part_the_docs_list(self):
        # cli.md: "Every part is required (`null` only for `writer` and `simulated_device`)"; `schema record`:
        # "a trial record's `specification` object (every part required)". First run: a finding (the schema did
        # not require `teacher_sha256` at all). The schema describes every version a reader takes, and a part
        # added in a later version is required from that version on, as the reader requires it: a record of
        # today's version without any part is refused by the schema, one of version 3 may lack the teacher's.
        schema = self.schema["record"]
        self.assertEqual(set(schema["properties"]), set(RECORD_PARTS))
        validator = Draft202012Validator(schema)
        spec = self.trial["specification"]
        for part in RECORD_PARTS:
            with self.subTest(part=part):
                lacking = {k: v for k, v in spec.items() if k != part}
                self.assertFalse(validator.is_valid(lacking), f"a record without {part} is valid to the schema")
        old = {k: v for k, v in spec.items() if k != "teacher_sha256"}
        old["version"] = 3
        self.assertTrue(validator.is_valid(old), "a version-3 record may lack the teacher's SHA-256")

    def test_record_schema_defaults_for_format_and_version_are_those_records_state(self):
        # cli.md: "`format` `calligraphy-trial-specification`, `version` 9, both checked by every read"; the
        # schema gives every field its `default`.
        props = self.schema["record"]["properties"]
        self.assertEqual(self.trial["specification"]["format"], "calligraphy-trial-specification")
        self.assertEqual(self.trial["specification"]["version"], 9)
        self.assertEqual(props["version"].get("default"), 9, "the schema's default version")
        self.assertEqual(props["format"].get("default"), "calligraphy-trial-specification",
                         "the schema's default format")

    def test_metrics_schema_holds_every_scene_metric_of_the_table_required(self):
        table = run_ok(["schema", "metrics", "--markdown"], self.tmp).stdout.decode("utf-8")
        scene = set()
        for line in table.splitlines():
            cells = cells_of(line)
            if len(cells) > 5 and cells[1].startswith("`") and "scene" in cells[4]:
                scene.add(cells[1].strip("`"))
        schema = self.schema["metrics"]
        self.assertEqual(set(schema["properties"]), scene)
        self.assertEqual(set(schema["required"]), scene)
        # docs/metrics.md shows the metric table as `--markdown` prints it.
        self.assertIn(table.strip(), (SOURCE / "docs" / "metrics.md").read_text(encoding="utf-8"))

    def test_specification_markdown_is_the_table_of_cli_md(self):
        table = run_ok(["schema", "specification", "--markdown"], self.tmp).stdout.decode("utf-8")
        doc = (SOURCE / "docs" / "cli.md").read_text(encoding="utf-8")
        between = doc.split("<!-- schema specification -->")[1].split("<!-- end schema specification -->")[0]
        self.assertEqual(table.strip(), between.strip())

    def test_specification_schema_defaults_are_those_of_trial_help(self):
        defaults = help_defaults(run_ok(["trial", "--help"], self.tmp).stdout.decode("utf-8"))
        props = self.schema["specification"]["properties"]
        special = {"guidance_stiffness_n_per_m": "--guidance-stiffness", "timing_speed_m_s": "--timing-speed",
                   "rate_hz": "--rate", "max_duration_s": "--max-duration", "watchdog_s": "--watchdog-ms"}
        compared = 0
        for field, p in props.items():
            option = special.get(field, "--" + re.sub(r"_m$", "", field).replace("_", "-"))
            if option not in defaults or "default" not in p:
                continue
            given = defaults[option]
            with self.subTest(field=field, option=option):
                if p.get("type") in ("number", "integer"):
                    scale = 1000.0 if field == "watchdog_s" else 1.0
                    self.assertAlmostEqual(float(given), p["default"] * scale, places=12)
                elif p.get("type") == "boolean":
                    self.assertEqual(given, "on" if p["default"] else "off")
                elif "enum" in p or field in ("device", "writer_profile"):
                    if field != "writer":        # its help names the device's own writer
                        self.assertEqual(given, p["default"])
                compared += 1
        self.assertGreaterEqual(compared, 30)

    def test_protocol_schema_defaults_are_the_docs_and_markdown_defaults(self):
        defs = self.schema["protocol"]["$defs"]
        props = self.schema["protocol"]["properties"]
        # docs/experiments.md, "Protocol files": trial.max_duration_s 120, rate_hz 1000, breaks 0, order fixed.
        self.assertEqual(defs["ProtocolTrialSettings"]["properties"]["max_duration_s"]["default"], 120)
        self.assertEqual(defs["ProtocolTrialSettings"]["properties"]["rate_hz"]["default"], 1000)
        for key in ("between_blocks_s", "every_trials", "duration_s"):
            self.assertEqual(defs["BreakRules"]["properties"][key]["default"], 0)
        self.assertEqual(props["order"]["properties"]["conditions"]["default"], "fixed")
        self.assertEqual(props["order"]["properties"]["characters"]["default"], "fixed")
        self.assertEqual(props["order"]["properties"]["seed"]["default"], 0)
        table = run_ok(["schema", "protocol", "--markdown"], self.tmp).stdout.decode("utf-8")
        rows = {}
        for line in table.splitlines():
            cells = cells_of(line)
            if len(cells) > 6 and cells[1].startswith("`"):
                rows[cells[1].strip("`")] = cells[5].strip("`")
        for name, where in (("max_duration_s", "ProtocolTrialSettings"), ("rate_hz", "ProtocolTrialSettings"),
                            ("between_blocks_s", "BreakRules"), ("every_trials", "BreakRules"),
                            ("duration_s", "BreakRules")):
            self.assertEqual(float(rows[name]), defs[where]["properties"][name]["default"], name)
        # The study ran a protocol without `trial`: its record's trial took those defaults.
        trial = self.record["specification"]["trial"]
        self.assertEqual(trial["max_duration_s"], 120.0)
        self.assertEqual(trial["rate_hz"], 1000.0)
        self.assertEqual(self.manifest["plan"][0]["break_before_s"], 0.0)

    def test_session_markdown_rows_are_the_top_level_fields_with_their_defaults(self):
        table = run_ok(["schema", "session", "--markdown"], self.tmp).stdout.decode("utf-8")
        props = self.schema["session"]["properties"]
        rows = {}
        for line in table.splitlines():
            cells = cells_of(line)
            if len(cells) > 6 and cells[1].startswith("`"):
                rows[cells[1].strip("`")] = cells[5].strip("`")
        self.assertEqual(list(rows), list(props))
        for name, p in props.items():
            if "default" in p and not isinstance(p["default"], (dict, list)):
                with self.subTest(field=name):
                    # an enumeration's value by its spelling (`simulated`), any other string as JSON writes it,
                    # quoted, as every field table writes them
                    shown = p["default"] if "enum" in p else json.dumps(p["default"], ensure_ascii=False)
                    self.assertEqual(rows[name], shown)

    def test_schema_usage_errors_name_what_is_wrong(self):
        self.assert_one_error(self.cli("schema"), 2)
        self.assert_one_error(self.cli("schema", "records"), 2, "records")
        self.assert_one_error(self.cli("schema", "record", "--markdown=yes"), 2, "--markdown")

    # ---- the files the program writes, against their schemas ----------------------------------------------
    def test_trial_json_record_validates_against_record_and_metrics_schemas(self):
        self.assertValid("record", self.trial["specification"], "trial --json's specification")
        self.assertValid("metrics", self.trial, "trial --json's metrics")
        # A person's specification file may state every key: the record's trial is one.
        self.assertValid("specification", self.trial["specification"]["trial"], "the record's trial")

    def test_session_files_validate_against_their_schemas(self):
        self.assertValid("session", self.manifest, "session.json")
        self.assertValid("protocol", json.loads(self.manifest["protocol"]["text"]), "session.json's protocol copy")
        self.assertValid("protocol", PROTOCOL, "the protocol file")
        self.assertValid("record", self.record["specification"], "the study record's specification")
        self.assertValid("metrics", self.record, "the study record's metrics")

    def test_trial_whose_pen_never_touched_gives_null_times_that_validate(self):
        # metrics.md: "`total_time_s` | first pen-down sample to last pen-down sample, whole trace; null when
        # the pen never touched"; cli.md: "A value that does not exist is `null` ..., never 0".
        d = self.tmp
        # 10 ms from the start, 20 mm above the paper: the pen never comes down.
        limited = self.cli("trial", "十", "--max-duration", "0.01", "--json", "tl.json", "--csv", "tl.csv")
        self.assertEqual(limited.returncode, 1, "a trial ended by its time limit exits 1")
        rows = (d / "tl.csv").read_text(encoding="utf-8").splitlines()
        z = [float(r.split(",")[3]) for r in rows[1:]]
        self.assertTrue(z and min(z) > 0.0005, "the pen stayed more than 0.5 mm above the paper")
        limited = json.loads((d / "tl.json").read_text(encoding="utf-8"))
        self.assertEqual(limited["end_reason"], "time_limit")
        self.assertValid("metrics", limited, "a time-limited trial's metrics")
        self.assertEqual(limited["strokes_written"], 0)
        self.assertIsNone(limited["mean_deviation_m"])
        self.assertIsNone(limited["total_time_s"], "total_time_s of a trace whose pen never touched")

    # ---- trial records: the schema and `trial --spec --check` both ways -----------------------------------
    def check_record(self, spec, name="r.json"):
        (self.tmp / name).write_text(json.dumps({"specification": spec}, ensure_ascii=False), encoding="utf-8")
        return self.cli("trial", "--spec", name, "--check")

    def bounded(self, defname):
        """The numeric fields of a record part that the schema bounds, with their schemas."""
        for field, p in self.schema["record"]["$defs"][defname]["properties"].items():
            if p.get("type") in ("number", "integer") and any(
                    k in p and abs(p[k]) < 1e300 for k in ("minimum", "maximum", "exclusiveMinimum",
                                                           "exclusiveMaximum")):
                yield field, p

    PARTS = (("/force_law/acceptance", "StrokeAcceptance"), ("/force_law/nearest", "NearestPointOptions"),
             ("/safety", "SafetyChainParameters"), ("/passivity", "PassivityParameters"),
             ("/writer", "WriterProfile"), ("/scene/layout", "SceneLayout"))

    def test_record_at_every_schema_bound_is_checked_valid(self):
        for side in ("max", "min"):
            spec = copy.deepcopy(self.trial["specification"])
            for where, defname in self.PARTS:
                for field, p in self.bounded(defname):
                    integer = p["type"] == "integer"
                    if side == "max":
                        if "maximum" in p:
                            value = p["maximum"]
                        elif "exclusiveMaximum" in p:
                            x = p["exclusiveMaximum"]
                            value = x - 1 if integer else x * (1 - 1e-9)
                        else:
                            continue
                    else:
                        if "minimum" in p:
                            value = p["minimum"]
                        elif "exclusiveMinimum" in p:
                            x = p["exclusiveMinimum"]
                            value = x + 1 if integer else (1e-9 if x == 0 else x + abs(x) * 1e-9)
                        else:
                            continue
                    if abs(value) > 1e300:
                        continue
                    value = int(value) if integer else float(value)
                    spec = put(spec, f"{where}/{field}", value)
                    if defname == "StrokeAcceptance":
                        spec = put(spec, f"/trial/{field}", value)
            with self.subTest(side=side):
                self.assertValid("record", spec, f"a record at every {side} bound")
                result = self.check_record(spec)
                self.assertEqual(result.returncode, 0, result.stderr.decode("utf-8", "replace"))

    def test_record_past_a_bound_is_refused_by_schema_and_check_alike(self):
        for where, defname in self.PARTS + (("/trial", "TrialSpec"),):
            fields = [(f, p) for f, p in self.bounded(defname) if "maximum" in p and p["maximum"] < 1e300]
            if fields:
                field, p = fields[-1]
                value = p["maximum"] + 1 if p["type"] == "integer" else p["maximum"] * (1 + 1e-6) + 1e-9
            else:                                   # bounded below only: its bound itself, or just under it
                field, p = next(iter(self.bounded(defname)))
                value = p["exclusiveMinimum"] if "exclusiveMinimum" in p else p["minimum"] - 1e-9
            spec = put(self.trial["specification"], f"{where}/{field}", value)
            pointers = [f"{where}/{field}"]
            if defname == "StrokeAcceptance":
                spec = put(spec, f"/trial/{field}", value)
                pointers.append(f"/trial/{field}")
            with self.subTest(pointer=pointers[0], value=value):
                self.assertSchemaRefuses("record", spec, pointers[0])
                line = self.assert_one_error(self.check_record(spec), 2, "r.json")
                self.assertTrue(any(f"/specification{ptr}:" in line for ptr in pointers), line)

    def test_record_wrong_type_null_and_unknown_key_are_refused_by_both_at_the_pointer(self):
        spec = self.trial["specification"]
        cases = {"/passivity/enabled": put(spec, "/passivity/enabled", None),
                 "/force_law/crossfade_s": put(spec, "/force_law/crossfade_s", "0.05"),
                 "/force_law/nearest/newton_starts": put(spec, "/force_law/nearest/newton_starts", 8.5),
                 "/safety/colour": put(spec, "/safety/colour", "red"),
                 "/trial/writer_parameters/0/value": put(spec, "/trial/writer_parameters",
                                                         [{"key": "bias_offset_m", "value": "0.004"}])}
        for ptr, doc in cases.items():
            with self.subTest(pointer=ptr):
                self.assertSchemaRefuses("record", doc, ptr)
                self.assert_one_error(self.check_record(doc), 2, f"r.json: /specification{ptr}")

    def test_record_whole_numbers_spelt_as_fractions_are_taken_by_both(self):
        # cli.md: below 2^53 "`7.0` or `7e0` is the seed 7, as for any other number".
        spec = put(self.trial["specification"], "/trial/seed", 7.0)
        spec = put(spec, "/force_law/nearest/newton_starts", 8.0)
        spec = put(spec, "/writer/max_attempts_per_stroke", 5.0)
        self.assertValid("record", spec, "whole numbers written 7.0")
        result = self.check_record(spec)
        self.assertEqual(result.returncode, 0, result.stderr.decode("utf-8", "replace"))

    def test_record_without_a_key_the_reader_requires_is_refused_by_the_schema_too(self):
        # cli.md: "In JSON a key left out keeps its default; in a record every key is present."
        spec = self.trial["specification"]
        for ptr in ("/trial/corridor_m", "/trial/guidance_stiffness_n_per_m", "/teacher_sha256"):
            doc = put(spec, ptr, delete=True)
            with self.subTest(pointer=ptr):
                self.assert_one_error(self.check_record(doc), 2, f"r.json: /specification{ptr}")
                self.assertSchemaRefuses("record", doc, ptr.rsplit("/", 1)[0] or "")

    def test_record_format_and_teacher_sha256_the_reader_refuses_are_refused_by_the_schema(self):
        spec = self.trial["specification"]
        for ptr, value in (("/format", "calligraphy-trial-specificatio"), ("/teacher_sha256", "xyz")):
            doc = put(spec, ptr, value)
            with self.subTest(pointer=ptr):
                self.assert_one_error(self.check_record(doc), 2, f"r.json: /specification{ptr}")
                self.assertSchemaRefuses("record", doc, ptr)

    # ---- session.json: the schema and the readers both ways ------------------------------------------------
    def study_copy(self, manifest=None, name="w"):
        """A copy of the study with its session.json replaced by `manifest`; the copy's session folder."""
        self.build_study()
        target = self.tmp / name
        shutil.rmtree(target, ignore_errors=True)
        shutil.copytree(self.tmp / "study", target)
        folder = target / "S01" / self.session.name
        if manifest is not None:
            (folder / "session.json").write_text(json.dumps(manifest, ensure_ascii=False), encoding="utf-8")
        return folder

    def test_session_json_past_a_bound_is_refused_by_schema_and_resume_naming_the_pointer(self):
        cases = {"/session_number": 21, "/subject/number": 1000000001, "/plan/0/break_before_s": 86400.5,
                 "/plan/0/period": 27, "/study_id": self.manifest["study_id"].upper(),
                 "/created_utc": self.manifest["created_utc"][:-1] + "+00:00"}
        for ptr, value in cases.items():
            doc = put(self.manifest, ptr, value)
            with self.subTest(pointer=ptr):
                self.assertSchemaRefuses("session", doc, ptr)
                folder = self.study_copy(doc)
                log = (folder / "log.jsonl").read_bytes()
                written = (folder / "session.json").read_bytes()
                line = self.assert_one_error(self.cli("session", "resume", folder), 2, "session.json", f"{ptr}:")
                self.assertIn(str(folder), line)
                self.assertEqual((folder / "log.jsonl").read_bytes(), log)
                self.assertEqual((folder / "session.json").read_bytes(), written)

    def test_session_json_at_bounds_without_its_later_keys_is_read_by_resume_and_report(self):
        doc = self.manifest
        for key in ("session_number", "group", "writer_seed", "writer_learning", "individual_differences"):
            doc = put(doc, f"/{key}", delete=True)
        for key in ("break_before_s", "file"):
            doc = put(doc, f"/plan/0/{key}", delete=True)
        doc = put(doc, "/created_utc", self.manifest["created_utc"].split(".")[0] + "Z")   # no fraction
        self.assertValid("session", doc, "session.json without its later keys")
        folder = self.study_copy(doc)
        log = (folder / "log.jsonl").read_bytes()
        result = self.cli("session", "resume", folder)
        self.assertEqual(result.returncode, 0, result.stderr.decode("utf-8", "replace"))
        self.assertIn("saved already", result.stdout.decode("utf-8"))
        self.assertEqual((folder / "log.jsonl").read_bytes(), log, "a completed session's log is left as it is")
        # The other bound: a rest of the schema's most, 86400 s.
        folder = self.study_copy(put(doc, "/plan/0/break_before_s", 86400.0))
        (self.tmp / "tables").mkdir(exist_ok=True)
        result = self.cli("report", folder.parent.parent, "--csv", "tables")
        self.assertEqual(result.returncode, 0, result.stderr.decode("utf-8", "replace"))

    def test_session_json_refused_by_the_schema_is_damaged_data_for_report(self):
        folder = self.study_copy(put(self.manifest, "/session_number", 21))
        (self.tmp / "tables2").mkdir(exist_ok=True)
        self.assert_one_error(self.cli("report", folder.parent.parent, "--csv", "tables2"), 1, "session.json",
                              "/session_number:")
        self.assertEqual(list((self.tmp / "tables2").iterdir()), [])

    def test_session_created_utc_with_a_second_no_calendar_has_is_refused(self):
        # experiments.md: the dates are "times in UTC as the program writes them" ("format": "date-time", RFC
        # 3339, whose section 5.7 allows a second 60 only at the end of a month's last minute, a leap second);
        # "a day or hour the calendar lacks ... is refused naming the file and the pointer". 06:17:60 is no
        # second of any day. (jsonschema 4.10 without rfc3339-validator checks no date-time: the pattern
        # alone, which it matches.)
        doc = put(self.manifest, "/created_utc", self.manifest["created_utc"][:11] + "06:17:60Z")
        folder = self.study_copy(doc)
        self.assert_one_error(self.cli("session", "resume", folder), 2, "session.json", "/created_utc:")

    # ---- protocols: the schema and `session plan` both ways ------------------------------------------------
    def plan(self, protocol, name="q.json"):
        (self.tmp / name).write_text(json.dumps(protocol, ensure_ascii=False), encoding="utf-8")
        return self.cli("session", "plan", name, "--subjects", "1")

    def test_protocol_at_its_schema_bounds_is_planned(self):
        protocol = {"name": "b" * 64, "description": "",
                    "conditions": [{"name": "q" * 32, "mode": "quiz",
                                    "quiz": {"hint_after_misses": 1000, "accept_backwards": True,
                                             "acceptance": {"corridor_m": 0.1, "max_gain_ratio": 100,
                                                            "assist_after_misses": 1000}}},
                                   {"name": "r", "mode": "replay", "parameters": {"max_lead_m": 0.006}},
                                   {"name": "f", "mode": "fading", "parameters": {
                                       "start_gain": 1, "forgetting_factor": 0, "error_gain_per_m": 1e6}}],
                    "test": {"characters": ["十" * 16], "conditions": ["q" * 32, "f"], "repetitions": 1},
                    "order": {"seed": 18446744073709551615},
                    "breaks": {"between_blocks_s": 86400, "every_trials": 100000, "duration_s": 86400},
                    "trial": {"max_duration_s": 1000, "rate_hz": 10000}}
        self.assertValid("protocol", protocol, "a protocol at its bounds")
        result = self.plan(protocol)
        self.assertEqual(result.returncode, 0, result.stderr.decode("utf-8", "replace"))

    def test_protocol_past_a_bound_is_refused_by_schema_and_plan_naming_the_pointer(self):
        cases = {"/trial/rate_hz": 10000.5, "/breaks/every_trials": 100001, "/test/characters/0": "十" * 17,
                 "/conditions/0/name": "c" * 33, "/order/seed": 18446744073709551616}
        for ptr, value in cases.items():
            doc = put(PROTOCOL, ptr, value)
            with self.subTest(pointer=ptr):
                self.assertSchemaRefuses("protocol", doc, ptr)
                self.assert_one_error(self.plan(doc), 2, f"q.json: {ptr}:")

    def test_transfer_choice_without_its_candidates_is_refused_by_the_schema_too(self):
        # experiments.md, "Phases": "for `transfer` also `{"choose": N, "from": [characters]}`"; cli.md:
        # "Rules between values (...) are the reader's alone" - a key missing is not one of them.
        protocol = {"name": "tr", "conditions": [{"name": "v", "mode": "vision"}, {"name": "h", "mode": "haptic"}],
                    "phases": [{"phase": "training", "condition": "h", "characters": ["十"]},
                               {"phase": "transfer", "condition": "v", "characters": {"choose": 1}}]}
        self.assert_one_error(self.plan(protocol), 2, "q.json: /phases/1/characters/from")
        self.assertSchemaRefuses("protocol", protocol, "/phases/1/characters")

    # ---- curriculum ------------------------------------------------------------------------------------------
    def expected_proposal(self, candidates, count):
        """What experiments.md, "What to practise next", proposes from the record of S01: new typical strokes
        2 each, weak ones (mean deviation above the median of the learner's typical strokes) 1 each, ties to
        fewer strokes, written characters and candidates that add nothing left out."""
        listing = json.loads(run_ok(["characters", "--text", candidates, "--json"], self.tmp).stdout)
        typical = {c["character"]: c["typical_ids"] for c in listing["characters"]}
        per_typical = {}
        for s in self.record["per_character"][0]["per_stroke"]:
            per_typical.setdefault(s["typical_id"], []).append(s["mean_deviation_m"])
        means = {k: sum(v) / len(v) for k, v in per_typical.items()}
        ordered = sorted(means.values())
        mid = len(ordered) // 2
        median = ordered[mid] if len(ordered) % 2 else (ordered[mid - 1] + ordered[mid]) / 2
        weak = {k for k, v in means.items() if v > median}
        written = set(self.record["characters"])
        scored = []
        for i, c in enumerate(candidates):
            if c in written:
                continue
            new = sorted({t for t in typical[c] if t not in means})
            again = sorted({t for t in typical[c] if t in weak})
            score = 2 * len(new) + len(again)
            if score:
                scored.append((-score, len(typical[c]), i, {"character": c, "new_strokes": new,
                                                              "weak_strokes": again}))
        return [entry for *_, entry in sorted(scored, key=lambda e: e[:3])][:count]

    def test_curriculum_json_proposes_new_then_weak_strokes_as_the_record_gives(self):
        self.build_study()
        # 人 (P N) and 口 (S HZ H) share no typical stroke, so the greedy order is the scores' order.
        out = run_ok(["curriculum", "study", "--subject", "S01", "--from", "十人口", "--json"], self.tmp)
        got = json.loads(out.stdout)
        self.assertEqual([{k: sorted(e[k]) if isinstance(e[k], list) else e[k] for k in e} for e in got],
                         self.expected_proposal("十人口", 3))
        out = run_ok(["curriculum", self.session, "--subject", "S01", "--from", "十人口", "--count", "1",
                      "--json"], self.tmp)
        self.assertEqual(json.loads(out.stdout), got[:1], "a session folder given itself, --count 1")

    def test_curriculum_subject_without_saved_trials_is_a_usage_error(self):
        self.build_study()
        self.assert_one_error(self.cli("curriculum", "study", "--subject", "S02", "--from", "十人"), 2)
        folder = self.study_copy(name="emptied")
        for f in (folder / "trials").glob("*.json"):
            f.unlink()
        self.assert_one_error(self.cli("curriculum", folder.parent.parent, "--subject", "S01", "--from", "十人"), 2)

    def test_curriculum_folder_without_sessions_is_a_data_error_naming_it(self):
        (self.tmp / "nothing").mkdir(exist_ok=True)
        self.assert_one_error(self.cli("curriculum", "nothing", "--subject", "S01", "--from", "十人"), 1, "nothing")

    def test_curriculum_record_whose_specification_check_refuses_is_named_with_its_pointer(self):
        # experiments.md: "a record whose trial could not be run again (a specification `trial --spec RECORD
        # --check` refuses) is damaged data, one line naming the record and the JSON pointer ... exit 1".
        folder = self.study_copy(name="damaged")
        record_file = folder / "trials" / self.record_file.name
        damaged = put(self.record, "/specification/force_law/crossfade_s", -1.0)
        record_file.write_text(json.dumps(damaged, ensure_ascii=False), encoding="utf-8")
        self.assert_one_error(self.cli("trial", "--spec", record_file, "--check"), 2,
                              "/specification/force_law/crossfade_s")
        self.assert_one_error(self.cli("curriculum", folder.parent.parent, "--subject", "S01", "--from", "十人"), 1,
                              self.record_file.name, "/specification/force_law/crossfade_s")

    def test_curriculum_record_of_a_study_version_not_read_is_named(self):
        # cli.md: a study record's "`version` a whole number from 1 to 3 ..., or it is refused naming ...
        # `/version`", and "those readers (`report`, `curriculum`, ...) refuse" it "(exit 1, damaged data)".
        folder = self.study_copy(name="v4")
        record_file = folder / "trials" / self.record_file.name
        record_file.write_text(json.dumps(put(self.record, "/version", 4), ensure_ascii=False), encoding="utf-8")
        self.assert_one_error(self.cli("trial", "--spec", record_file, "--check"), 2, "/version")
        self.assert_one_error(self.cli("curriculum", folder.parent.parent, "--subject", "S01", "--from", "十人"), 1,
                              self.record_file.name, "/version")

    def test_curriculum_count_and_from_out_of_range_are_usage_errors(self):
        self.build_study()
        base = ["curriculum", "study", "--subject", "S01"]
        self.assert_one_error(self.cli(*base, "--from", "人", "--count", "0"), 2, "--count")
        self.assert_one_error(self.cli(*base, "--from", "人", "--count", "1001"), 2, "--count")
        self.assert_one_error(self.cli(*base, "--from", ""), 2, "--from")
        self.assert_one_error(self.cli(*base, "--from", "人あ"), 2, "U+3042")
        self.assert_one_error(self.cli(*base, "--from", b"\xe4\xba"), 2, "--from")
        result = self.cli(*base, "--from", "人", "--count", "1000", "--json")
        self.assertEqual(result.returncode, 0, result.stderr.decode("utf-8", "replace"))

    # ---- corpus store ----------------------------------------------------------------------------------------
    def write_store(self, name, data):
        (self.tmp / name).write_bytes(data)
        return name

    def test_store_header_index_and_checksums_are_as_corpus_md_lays_them_out(self):
        data = self.store_bytes
        s = Store(data)
        self.assertEqual(s.magic, b"CLGSTORE")
        self.assertEqual((s.major, s.minor, s.header_size, s.count, s.steps), (1, 2, 64, 4, 2))
        self.assertEqual(s.tolerance, 10.0)
        self.assertEqual(s.flags, 3, "medians and outlines")
        self.assertEqual(s.index_offset, 688)
        self.assertEqual(s.records_offset, 688 + 12 * s.count)
        self.assertEqual(len(data), s.records_offset + s.records_size)
        self.assertEqual(s.tables_crc, crc(data[64:s.records_offset]))
        self.assertEqual(s.header_crc, crc(data[0:60]))
        self.assertEqual([chr(code) for code, _, _ in s.index], sorted(STORE_CHARS))
        self.assertEqual(s.index[0][1], 0)
        for i in range(s.count):
            start, end = s.record_span(i)
            self.assertLess(start, end)
            self.assertEqual(s.index[i][2], crc(data[start:end]))
        stats = json.loads(run_ok(["corpus", "stats", "s.clg", "--json"], self.tmp).stdout)
        self.assertEqual((stats["characters"], stats["bytes"], stats["steps_per_unit"], stats["format_version"],
                          stats["checksums_ok"], stats["errors"]), (4, len(data), 2, "1.2", True, []))
        listing = json.loads(run_ok(["characters", "--store", "s.clg", "--json"], self.tmp).stdout)
        self.assertEqual(stats["strokes"], sum(c["strokes"] for c in listing["characters"]))

    def test_store_build_is_the_same_bytes_whatever_the_threads_and_a_copy_reads_the_same(self):
        run_ok(["corpus", "build", "--data", "data", "--out", "s2.clg", "--threads", "2"], self.tmp)
        self.assertEqual((self.tmp / "s2.clg").read_bytes(), self.store_bytes)
        a = json.loads(run_ok(["corpus", "stats", "s.clg", "--json"], self.tmp).stdout)
        b = json.loads(run_ok(["corpus", "stats", "s2.clg", "--json"], self.tmp).stdout)
        a.pop("file"), b.pop("file")
        self.assertEqual(a, b)

    def test_store_cut_by_one_byte_is_one_error_naming_it(self):
        name = self.write_store("cut.clg", self.store_bytes[:-1])
        self.assert_one_error(self.cli("corpus", "stats", name), 1, name)
        self.assert_one_error(self.cli("characters", "--store", name), 1, name)
        self.assertEqual((self.tmp / name).read_bytes(), self.store_bytes[:-1])

    def test_two_damaged_records_are_two_error_lines_naming_each_character(self):
        s = Store(self.store_bytes)
        data = bytearray(self.store_bytes)
        damaged = []
        for i in (1, 3):
            start, end = s.record_span(i)
            data[(start + end) // 2] ^= 0xFF
            damaged.append(chr(s.index[i][0]))
        name = self.write_store("two.clg", bytes(data))
        result = self.cli("corpus", "stats", name)
        self.assertEqual(result.returncode, 1)
        lines = error_lines(result)
        self.assertEqual(len(lines), 2, lines)
        for line, c in zip(lines, damaged):
            self.assertIn("error", line)
            self.assertIn(name, line)
            self.assertIn(f"U+{ord(c):04X}", line)
        stats = json.loads(self.cli("corpus", "stats", name, "--json").stdout)
        self.assertEqual(len(stats["errors"]), 2)
        self.assertFalse(stats["checksums_ok"])

    def test_record_with_typical_id_0_and_its_checksums_put_right_is_refused_naming_it(self):
        # corpus.md: `load` checks "IDs 1-39"; each failure names "the file, the byte offset, the character".
        s = Store(self.store_bytes)
        i = [chr(code) for code, _, _ in s.index].index("十")
        start, _ = s.record_span(i)
        s.data[start + 1] &= 0xC0           # the first stroke's typical_id:6, least significant bits first
        name = self.write_store("id0.clg", s.fix_crcs())
        line = self.assert_one_error(self.cli("model", "十", "--store", name), 1, name)
        self.assertIn("U+5341", line)
        result = self.cli("corpus", "stats", name)
        self.assertEqual(result.returncode, 1)
        self.assertEqual(len(error_lines(result)), 1, error_lines(result))
        self.assertIn("U+5341", error_lines(result)[0])

    def test_store_header_fields_are_checked_as_corpus_md_says(self):
        def edited(offset, fmt, value):
            s = Store(self.store_bytes)
            struct.pack_into(fmt, s.data, offset, value)
            return s.fix_crcs()
        # "Later minors only add meaning ...; readers accept any minor".
        name = self.write_store("minor.clg", edited(10, "<H", 9))
        result = self.cli("corpus", "stats", name)
        self.assertEqual(result.returncode, 0, result.stderr.decode("utf-8", "replace"))
        for what, offset, fmt, value in (("major 2", 8, "<H", 2), ("unknown flag", 28, "<I", 7),
                                         ("steps 3", 20, "<I", 3)):
            with self.subTest(what=what):
                name = self.write_store("header.clg", edited(offset, fmt, value))
                self.assert_one_error(self.cli("corpus", "stats", name), 1, name)

    def test_index_out_of_code_point_order_is_refused(self):
        s = Store(self.store_bytes)
        first, second = s.index[0], s.index[1]
        struct.pack_into("<I", s.data, s.index_offset, second[0])
        struct.pack_into("<I", s.data, s.index_offset + 12, first[0])
        data = bytearray(s.data)
        struct.pack_into("<I", data, 56, crc(data[64:s.records_offset]))
        struct.pack_into("<I", data, 60, crc(data[0:60]))
        name = self.write_store("order.clg", bytes(data))
        self.assert_one_error(self.cli("corpus", "stats", name), 1, name)

    # ---- characters and strokes ------------------------------------------------------------------------------
    def test_strokes_json_is_the_table_of_typical_strokes_md(self):
        strokes = json.loads(run_ok(["strokes", "--json"], self.tmp).stdout)
        rows = {}
        for line in (SOURCE / "docs" / "typical-strokes.md").read_text(encoding="utf-8").splitlines():
            cells = cells_of(line.strip())[1:-1]
            if len(cells) == 8 and cells[0].isdigit():
                rows[int(cells[0])] = cells
        self.assertEqual(sorted(rows), list(range(1, 40)))
        self.assertEqual([s["id"] for s in strokes], list(range(1, 40)))
        for s in strokes:
            ident, acronym, name, pinyin, code, kind, _, attraction = rows[s["id"]][:8]
            with self.subTest(id=s["id"]):
                self.assertEqual((s["acronym"], s["name"], s["pinyin"]), (acronym, name, pinyin))
                self.assertEqual(s["unicode"] or "-", code.split()[0] if code != "-" else "-")
                self.assertEqual(s["compound"], kind == "compound")
                default, corner = (float(x) for x in attraction.split("/"))
                self.assertEqual((s["default_attraction"], s["corner_attraction"]), (default, corner))
        markdown = run_ok(["strokes", "--markdown", "-"], self.tmp).stdout
        self.assertEqual(markdown, (SOURCE / "docs" / "typical-strokes.md").read_bytes())

    def test_characters_typical_by_id_acronym_name_and_stroke_character_agree(self):
        self.build_store()

        def chars(*args):
            out = run_ok(["characters", "--store", "s.clg", "--json", *args], self.tmp)
            listing = json.loads(out.stdout)
            self.assertEqual(listing["count"], len(listing["characters"]))
            return [c["character"] for c in listing["characters"]]
        full = json.loads(run_ok(["characters", "--store", "s.clg", "--json"], self.tmp).stdout)
        acronyms = {s["id"]: s["acronym"] for s in json.loads(run_ok(["strokes", "--json"], self.tmp).stdout)}
        for c in full["characters"]:
            self.assertEqual(c["typical_strokes"], [acronyms[t] for t in c["typical_ids"]])
            self.assertEqual(c["code_point"], f"U+{ord(c['character']):04X}")
        with_h = [c["character"] for c in full["characters"] if 1 in c["typical_ids"]]
        for spelling in ("1", "h", "横", "㇐"):
            with self.subTest(typical=spelling):
                self.assertEqual(chars("--typical", spelling), with_h)
        self.assertEqual(chars("--strokes", "3"), [c["character"] for c in full["characters"] if c["strokes"] == 3])
        self.assertEqual(chars("--typical", "HZG"), [])
        self.assert_one_error(self.cli("characters", "--store", "s.clg", "--typical", "40"), 2, "--typical")

    def test_characters_text_lists_each_once_in_order_and_names_the_rest(self):
        self.build_store()
        out = run_ok(["characters", "--store", "s.clg", "--json", "--text", "a口b十a\u3000口\t人"], self.tmp)
        listing = json.loads(out.stdout)
        self.assertEqual([c["character"] for c in listing["characters"]], ["口", "十", "人"])
        self.assertEqual(listing["not_found"], ["a", "b"])
        self.assertEqual(listing["count"], 3)


if __name__ == "__main__":
    unittest.main()
