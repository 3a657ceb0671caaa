#!/usr/bin/env python3
"""Round 26D: one vocabulary across every surface. From the docs alone (README.md, docs/cli.md, docs/python.md,
docs/metrics.md, docs/experiments.md, `calligraphy schema ...`, each command's `--help`, Python's `help()`).

Every name, spelling, unit, range, default and numbering the program states is held to the same thing stated
elsewhere: the schema's fields against `trial --help`, the docs' tables, a record made without the option and
Python's classes and keywords; each enumeration's spellings in options, files and Python (the docs' other
spellings refused everywhere but Python's deprecated member names); each unit in a column or key against the
numbers (a stroke of a 60 mm box is some centimetres, never metres or micrometres); stroke, trial and character
numbering (0-based in JSON and arrays, 1-based where the docs say a person or a study reads it) with the same
stroke called by the same number; every metric of the metric table by one name in score, the tables and Python;
every docs table listing exactly the fields the program has. Cases loop over the schema's own output where they
can, so a field added later is covered.

CALLIGRAPHY_CLI names the program; PYTHONPATH the built Python package. CALLIGRAPHY_SANITIZED=1 takes five cases.
"""
import csv
import io
import json
import math
import os
import re
import shutil
import tempfile
import unittest
import warnings
from pathlib import Path

from outsider import OneErrorLine, run, run_ok, sanitized_subset

try:
    import calligraphy as cg
except ImportError:  # reported by the cases that need it
    cg = None

load_tests = sanitized_subset({"test_each_specification_default_is_one_in_schema_help_and_record",
                               "test_trace_csv_positions_are_metres_of_a_60_mm_box",
                               "test_trial_table_and_json_number_the_same_stroke",
                               "test_underscore_spellings_are_refused_by_option_and_record",
                               "test_trials_csv_columns_are_the_docs_table"})

SOURCE = Path(os.environ.get("CALLIGRAPHY_SOURCE_DIR", Path(__file__).resolve().parents[2]))
DOCS = SOURCE / "docs"
PROTOCOL = {"name": "vocab", "conditions": [{"name": "h", "mode": "haptic"}, {"name": "v", "mode": "vision"}],
            "test": {"characters": ["十", "口"], "conditions": ["h", "v"], "repetitions": 1},
            "trial": {"max_duration_s": 30}}
# The fields a trial states without a value of their own: `auto` resolves as the docs say (the simulated
# device: the simulated writer, lock-step), the characters are the ones given, output files are left out.
RESOLVED = {"writer": "simulated", "pacing": "lock-step", "characters": "十"}
OUTPUT_FIELDS = ("json_file", "csv_file", "svg_file", "record_file")
PAST = 1e-9  # a step past a bound, far above a double's rounding at these magnitudes


def help_options(text):
    """`--help` as {option: (value name, description with its default)}: wrapped lines joined."""
    options, current = {}, None
    for line in text.splitlines():
        m = re.match(r"^  (?:-\w,)?(--[\w-]+)(?: (\S+))?\s{2,}(.*)$", line) or re.match(
            r"^  (?:-\w,)?(--[\w-]+)(?: (\S+))?$", line)
        if m:
            current = m.group(1)
            options[current] = [m.group(2) or "", m.group(3) if m.lastindex >= 3 and m.group(3) else ""]
        elif current and line.startswith("      ") and line.strip():
            options[current][1] = (options[current][1] + " " + line.strip()).strip()
        elif not line.strip() or not line.startswith(" "):
            current = None
    return {k: tuple(v) for k, v in options.items()}


def help_default(description):
    """The "(default: X)" a help line ends with, or None."""
    m = re.search(r"\(default: (.*)\)\s*$", description)
    return m.group(1) if m else None


def markdown_rows(text):
    """The rows of every Markdown table in `text`, cells stripped."""
    rows = []
    for line in text.splitlines():
        if line.startswith("|") and not re.match(r"^\|\s*-", line):
            rows.append([c.strip() for c in re.split(r"(?<!\\)\|", line.strip())[1:-1]])
    return rows


def section(path, heading):
    """The text of a Markdown section from `heading` to the next heading of its level or higher."""
    text = Path(path).read_text(encoding="utf-8")
    start = text.index("\n" + heading + "\n")
    level = len(heading) - len(heading.lstrip("#"))
    rest = text[start + len(heading) + 2:]
    m = re.search(r"\n#{1,%d} " % level, rest)
    return rest[:m.start()] if m else rest


def ticked(cell):
    """The backticked names of a table cell."""
    return re.findall(r"`([^`]+)`", cell)


def option_of(field):
    """The `trial` option of a specification field, as docs/cli.md names it: the field's name dashed, a unit
    suffix dropped; `watchdog_s` in whole milliseconds; each writer setting one `--writer-param`."""
    special = {"watchdog_s": "--watchdog-ms", "writer_parameters": "--writer-param", "json_file": "--json",
               "csv_file": "--csv", "svg_file": "--svg", "record_file": "--record"}
    if field in special:
        return special[field]
    if field == "characters":
        return None  # the positional CHARS
    name = re.sub(r"_(n_per_m|m_s|hz|m|s)$", "", field)
    return "--" + name.replace("_", "-")


def step_past(bound):
    """A step past a bound that its double does not round away."""
    return max(PAST, abs(bound) * 1e-9)


def float_or_none(text):
    try:
        return float(text)
    except ValueError:
        return None


class Round26D(unittest.TestCase, OneErrorLine):
    @classmethod
    def setUpClass(cls):
        cls.tmp = Path(tempfile.mkdtemp(prefix="round26d-"))
        d = cls.tmp
        cls.spec_schema = json.loads(run_ok(["schema", "specification"], d).stdout)
        cls.record_schema = json.loads(run_ok(["schema", "record"], d).stdout)
        cls.metrics_schema = json.loads(run_ok(["schema", "metrics"], d).stdout)
        cls.session_schema = json.loads(run_ok(["schema", "session"], d).stdout)
        cls.metric_rows = markdown_rows(run_ok(["schema", "metrics", "--markdown"], d).stdout.decode())
        cls.trial_help = help_options(run_ok(["trial", "--help"], d).stdout.decode())
        run_ok(["trial", "十", "--json", "t.json", "--csv", "t.csv"], d)
        cls.record = json.loads((d / "t.json").read_text(encoding="utf-8"))
        cls.trace = list(csv.DictReader(io.StringIO((d / "t.csv").read_text(encoding="utf-8"))))
        cls.trace_header = (d / "t.csv").read_text(encoding="utf-8").splitlines()[0]
        run_ok(["score", "t.csv", "--character", "十", "--json", "s.json"], d)
        cls.score = json.loads((d / "s.json").read_text(encoding="utf-8"))
        cls.score_table = run_ok(["score", "t.csv", "--character", "十"], d).stdout.decode()
        (d / "p.json").write_text(json.dumps(PROTOCOL, ensure_ascii=False), encoding="utf-8")
        run_ok(["session", "run", "p.json", "--subjects", "1", "--out", "S"], d)
        (d / "T").mkdir()
        run_ok(["report", "S", "--csv", "T", "--out", "pages.html"], d)
        cls.trials_csv = list(csv.DictReader(io.StringIO((d / "T" / "trials.csv").read_text(encoding="utf-8"))))
        cls.strokes_csv = list(csv.DictReader(io.StringIO((d / "T" / "strokes.csv").read_text(encoding="utf-8"))))
        cls.trials_header = (d / "T" / "trials.csv").read_text(encoding="utf-8").splitlines()[0].split(",")
        cls.strokes_header = (d / "T" / "strokes.csv").read_text(encoding="utf-8").splitlines()[0].split(",")
        cls.session_dir = next((d / "S" / "S01").iterdir())
        cls.models = {c: json.loads(run_ok(["model", c, "--json"], d).stdout) for c in ("十", "口")}
        cls.py_trial = None

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.tmp, ignore_errors=True)

    def cli(self, *args):
        return run(list(args), self.tmp)

    def need_python(self):
        if cg is None:
            self.fail("the calligraphy Python package is not importable (PYTHONPATH)")

    @classmethod
    def python_trial(cls):
        if cls.py_trial is None:
            cls.py_trial = cg.simulate_trial("十", seed=0)
        return cls.py_trial

    # ---- defaults ----------------------------------------------------------------------------------------
    def test_each_specification_default_is_one_in_schema_help_and_record(self):
        fields = self.spec_schema["properties"]
        markdown = {ticked(r[0])[0]: r for r in markdown_rows(
            run_ok(["schema", "specification", "--markdown"], self.tmp).stdout.decode()) if ticked(r[0])}
        self.assertEqual(set(markdown), set(fields))
        recorded = self.record["specification"]["trial"]
        for field, prop in fields.items():
            with self.subTest(field=field):
                default = prop["default"]
                # The record of a trial made without the option.
                if field in OUTPUT_FIELDS:
                    self.assertEqual(recorded[field], "", "output files are left out of a record")
                else:
                    self.assertEqual(recorded[field], RESOLVED.get(field, default))
                # The help of its option.
                option = option_of(field)
                if option is None:
                    continue
                self.assertIn(option, self.trial_help, f"{field}: no option {option}")
                said = help_default(self.trial_help[option][1])
                self.assertIsNotNone(said, f"{option} states no default")
                if isinstance(default, bool):
                    self.assertEqual(said, "on" if default else "off")
                elif isinstance(default, (int, float)):
                    scale = 1000 if field == "watchdog_s" else 1
                    self.assertEqual(float_or_none(said), default * scale, f"{option}: {said!r}")
                elif field in OUTPUT_FIELDS:
                    self.assertEqual(said, "not written")
                elif default in ("", []):
                    self.assertEqual(said, "none")
                elif field == "writer":
                    self.assertTrue(said.startswith("simulated on a simulated"), said)
                else:
                    self.assertEqual(said, default)
                # The schema's own table says the same default (an enumeration's unquoted).
                shown = markdown[field][4].strip("`")
                if isinstance(default, (int, float)) and not isinstance(default, bool):
                    self.assertEqual(float(shown), default)
                elif "enum" in prop:
                    self.assertEqual(shown, default)
                else:
                    self.assertEqual(json.loads(shown), default)

    def test_the_trial_options_table_has_the_helps_defaults(self):
        rows = markdown_rows(section(DOCS / "cli.md", "## trial"))
        checked = 0
        for row in rows:
            if len(row) != 4 or not row[0].startswith("`--"):
                continue
            for option in ticked(row[0]):
                if option not in self.trial_help or "," in row[0] or option in ("--data", "--store"):
                    continue
                said = help_default(self.trial_help[option][1])
                with self.subTest(option=option):
                    doc = row[2].strip("`")
                    if said is None:
                        self.assertIn(doc, ("off", "none", "not written"), f"{option}: docs {doc!r}")
                        continue
                    number = float_or_none(said)
                    if number is not None:
                        self.assertEqual(float_or_none(re.split(r"[ (]", doc)[0]), number,
                                         f"{option}: docs {doc!r}, help {said!r}")
                    elif option == "--writer":
                        self.assertTrue(doc.startswith("`simulated` on a simulated") or
                                        doc.startswith("simulated` on a simulated"), doc)
                    else:
                        self.assertEqual(doc.split("`")[0], said.split(" (")[0], f"{option}")
                    checked += 1
        self.assertGreaterEqual(checked, 20)

    def test_python_parameter_classes_default_to_the_record_schemas_defaults(self):
        self.need_python()
        defs = self.record_schema["$defs"]
        compared = 0
        for name, schema in defs.items():
            cls = getattr(cg, name, None)
            if cls is None or "properties" not in schema:
                continue
            try:
                instance = cls()
            except TypeError:
                continue
            for field, prop in schema["properties"].items():
                if "default" not in prop or isinstance(prop["default"], (dict, list)) or prop["default"] is None:
                    continue
                with self.subTest(cls=name, field=field):
                    self.assertTrue(hasattr(instance, field), f"{name} lacks {field}")
                    value = getattr(instance, field)
                    value = getattr(value, "value", value) if not isinstance(value, (int, float, str, bool)) \
                        else value
                    if isinstance(prop["default"], str) and not isinstance(value, str):
                        value = str(getattr(getattr(instance, field), "name", value))
                        self.assertEqual(value.replace("_", "-"), prop["default"].replace("_", "-"))
                    elif isinstance(prop["default"], (int, float)) and not isinstance(prop["default"], bool):
                        self.assertAlmostEqual(float(value), float(prop["default"]), delta=1e-12)
                    else:
                        self.assertEqual(value, prop["default"])
                    compared += 1
        self.assertGreaterEqual(compared, 40)

    def test_python_keywords_named_as_fields_default_as_the_schema(self):
        self.need_python()
        doc = (cg.simulate_trial.__doc__ or "").split("\n")[0] + (cg.run_trial.__doc__ or "").split("\n")[0]
        fields = self.spec_schema["properties"]
        found = 0
        for field, prop in fields.items():
            # docs/python.md: the keyword `writer` is the profile ('novice', ...), the field `writer_profile`.
            keyword = "writer" if field == "writer_profile" else field
            if field == "writer":
                continue
            for m in re.finditer(rf"\b{keyword}: [^=,)]+ = ([^,)]+)", doc):
                if m.group(1) == "None":
                    continue
                said = m.group(1).strip("'\"")
                with self.subTest(field=field, said=said):
                    default = prop["default"]
                    if isinstance(default, bool):
                        self.assertEqual(said, str(default))
                    elif isinstance(default, (int, float)):
                        self.assertEqual(float(said), float(default))
                    else:
                        self.assertEqual(said, default)
                    found += 1
        self.assertGreaterEqual(found, 8, doc[:400])

    def test_python_score_defaults_are_the_layouts_and_the_docs(self):
        self.need_python()
        doc = (cg.score.__doc__ or "").split("\n")[0]
        layout = self.record_schema["$defs"]["SceneLayout"]["properties"]
        radius = float(re.search(r"start_radius_m: float = ([\d.e-]+)", doc).group(1))
        self.assertEqual(radius, layout["start_radius_m"]["default"])
        self.assertEqual(radius, cg.SceneLayout().start_radius_m)
        threshold = float(re.search(r"contact_threshold_m: float = ([\d.e-]+)", doc).group(1))
        # docs/metrics.md: the pen touches at z <= 0.5 mm; docs/cli.md the same for `score`.
        self.assertIn("z <= 0.5 mm", (DOCS / "metrics.md").read_text(encoding="utf-8"))
        self.assertEqual(threshold, 0.0005)
        self.assertIn("units: str = 'm'", doc)
        # A trace lifted 0.4 mm is on the paper for both, 0.6 mm off it for both.
        for z, on in ((0.0004, True), (0.0006, False)):
            rows = ["t,x,y,z"] + [f"{r['t']},{r['x']},{r['y']},{z if float(r['z']) <= 0.0005 else r['z']}"
                                  for r in self.trace]
            path = self.tmp / f"lift-{z}.csv"
            path.write_text("\n".join(rows) + "\n", encoding="utf-8")
            by_cli = json.loads(run_ok(["score", path.name, "--character", "十", "--json", "-"], self.tmp).stdout)
            by_python = cg.score(str(path), "十")
            with self.subTest(z=z):
                self.assertEqual(by_cli["strokes_written"], by_python["strokes_written"])
                self.assertEqual(by_cli["strokes_written"] > 0, on)

    # ---- ranges ------------------------------------------------------------------------------------------
    def test_python_classes_take_the_schemas_bounds_and_refuse_a_step_past(self):
        self.need_python()
        defs = self.record_schema["$defs"]
        tried = 0
        for name in ("ForceLawParameters", "StrokeAcceptance", "SafetyChainParameters", "PassivityParameters",
                     "SceneLayout", "NearestPointOptions", "SimulatedDeviceParameters"):
            schema, cls = defs.get(name), getattr(cg, name, None)
            if schema is None or cls is None:
                continue
            for field, prop in schema["properties"].items():
                if prop.get("type") not in ("number", "integer"):
                    continue
                integer = prop["type"] == "integer"
                ends = []
                if "minimum" in prop:
                    ends.append((prop["minimum"], prop["minimum"] - (1 if integer else step_past(prop["minimum"]))))
                if "maximum" in prop:
                    ends.append((prop["maximum"], prop["maximum"] + (1 if integer else step_past(prop["maximum"]))))
                if "exclusiveMinimum" in prop:
                    ends.append((None, prop["exclusiveMinimum"]))
                if "exclusiveMaximum" in prop:
                    ends.append((None, prop["exclusiveMaximum"]))
                for at, past in ends:
                    with self.subTest(cls=name, field=field, at=at, past=past):
                        instance = cls()
                        if at is not None and abs(at) < 1e300:
                            try:
                                setattr(instance, field, int(at) if integer else float(at))
                            except cg.InvalidArgument as error:
                                # A rule between fields (a taper within its radius) may keep a bound out of
                                # reach alone; it must say so, naming the other field.
                                self.assertRegex(str(error), rf"{field} = .* (must not exceed|must be below|"
                                                             rf"must be above|must be at least) \w+")
                            else:
                                self.assertEqual(getattr(instance, field), at)
                        if abs(past) < 1e300:
                            with self.assertRaises((ValueError, cg.InvalidArgument)) as caught:
                                setattr(instance, field, int(past) if integer else float(past))
                            self.assertIn(field, str(caught.exception))
                        tried += 1
        self.assertGreaterEqual(tried, 30)

    def test_a_ranges_bound_is_named_alike_by_option_and_record(self):
        # The option's error states the bound the help states; the record's names the same bound and the
        # pointer; `trial --check` refuses both with status 2.
        spec = self.record["specification"]
        for option, field, value, bound in (("--corridor", "corridor_m", 0.2, "(0, 0.1]"),
                                            ("--max-gain-ratio", "max_gain_ratio", 0.5, "[1, 100]"),
                                            ("--timing-speed", "timing_speed_m_s", 0.0, "(0, 1]")):
            with self.subTest(option=option):
                self.assertIn(bound, self.trial_help[option][1])
                extra = ["--guidance-mode", "timing"] if field == "timing_speed_m_s" else []
                line = self.assert_one_error(self.cli("trial", "十", *extra, option, repr(value), "--check"), 2,
                                             option)
                self.assertIn(bound, line)
                forged = json.loads(json.dumps(spec))
                forged["trial"][field] = value
                if field == "timing_speed_m_s":
                    forged["trial"]["guidance_mode"] = "timing"
                path = self.tmp / f"forged-{field}.json"
                path.write_text(json.dumps({"specification": forged}), encoding="utf-8")
                line = self.assert_one_error(self.cli("trial", "--spec", path.name, "--check"), 2,
                                             f"/specification/trial/{field}")
                self.assertIn(bound, line)

    def test_rate_takes_the_same_values_as_option_and_record(self):
        # `--rate` is "Hz, 100..100000" in the docs' table and a number in the schema: a fractional rate is
        # either taken by both or refused by both.
        by_option = self.cli("trial", "十", "--rate", "1000.5", "--check").returncode
        forged = json.loads(json.dumps(self.record["specification"]))
        forged["trial"]["rate_hz"] = 1000.5
        (self.tmp / "rate.json").write_text(json.dumps({"specification": forged}), encoding="utf-8")
        by_record = self.cli("trial", "--spec", "rate.json", "--check").returncode
        self.assertEqual(by_option, by_record)
        self.assertIn(by_option, (0, 2))

    # ---- enumerations ------------------------------------------------------------------------------------
    def test_underscore_spellings_are_refused_by_option_and_record(self):
        # docs/python.md: "the command line and the files take only the spelling".
        for option, field, wrong in (("--guidance-mode", "guidance_mode", "assist_as_needed"),
                                     ("--guidance-mode", "guidance_mode", "error_amplification"),
                                     ("--pacing", "pacing", "lock_step"), ("--pacing", "pacing", "real_time")):
            with self.subTest(wrong=wrong):
                self.assert_one_error(self.cli("trial", "十", option, wrong, "--check"), 2, option)
                forged = json.loads(json.dumps(self.record["specification"]))
                forged["trial"][field] = wrong
                path = self.tmp / f"enum-{wrong}.json"
                path.write_text(json.dumps({"specification": forged}), encoding="utf-8")
                self.assert_one_error(self.cli("trial", "--spec", path.name, "--check"), 2,
                                      f"/specification/trial/{field}")

    def test_guidance_takes_one_set_of_spellings_on_trial_and_train(self):
        # "One meaning per option name": `--guidance on|off` on both commands, as both helps say; a spelling
        # the helps do not list (the record's `true`) is refused by both or taken by both, never by one.
        train_help = help_options(run_ok(["train", "--help"], self.tmp).stdout.decode())
        self.assertEqual(self.trial_help["--guidance"][0], "on|off")
        self.assertEqual(train_help["--guidance"][0], "on|off")
        for value in ("true", "false", "ON", "1"):
            with self.subTest(value=value):
                by_trial = self.cli("trial", "十", "--guidance", value, "--check")
                by_train = self.cli("train", "十", "--guidance", value, "--check")
                self.assertEqual(by_trial.returncode, by_train.returncode, (by_trial.stderr, by_train.stderr))
                self.assert_one_error(by_trial, 2, "--guidance")
        # A record states a boolean: the option's words are no JSON value of it.
        forged = json.loads(json.dumps(self.record["specification"]))
        forged["trial"]["guidance"] = "on"
        (self.tmp / "guidance-on.json").write_text(json.dumps({"specification": forged}), encoding="utf-8")
        self.assert_one_error(self.cli("trial", "--spec", "guidance-on.json", "--check"), 2,
                              "/specification/trial/guidance")

    def test_an_option_of_trial_and_train_states_one_range(self):
        train_help = help_options(run_ok(["train", "--help"], self.tmp).stdout.decode())
        for option, past in (("--seed", "-1"), ("--hint-after-misses", "1001"), ("--assist-after-misses", "1001"),
                             ("--guidance-gain", "1.5")):
            with self.subTest(option=option):
                ends = re.findall(r"(?:in \[|, )?(\d+(?:\.\d+)?)(?:\.\.|, |\])", self.trial_help[option][1])
                self.assertTrue(ends, self.trial_help[option][1])
                self.assertEqual(ends[:2], re.findall(r"(?:in \[|, )?(\d+(?:\.\d+)?)(?:\.\.|, |\])",
                                                      train_help[option][1])[:2], "the two helps' ranges")
                extra = ["--guidance-mode", "fading"] if option == "--guidance-gain" else []
                for command in ("trial", "train"):
                    line = self.assert_one_error(self.cli(command, "十", *extra, f"{option}={past}", "--check"), 2,
                                                 option)
                    for end in ends[:2]:
                        self.assertIn(end, line, f"{command}: {line}")

    def test_a_protocol_takes_only_the_spelling_of_a_mode(self):
        for wrong in ("assist_as_needed", "error_amplification", "skill_adaptive"):
            with self.subTest(wrong=wrong):
                protocol = json.loads(json.dumps(PROTOCOL))
                protocol["conditions"][0]["mode"] = wrong
                path = self.tmp / f"mode-{wrong}.json"
                path.write_text(json.dumps(protocol, ensure_ascii=False), encoding="utf-8")
                self.assert_one_error(self.cli("session", "plan", path.name, "--subjects", "1"), 2,
                                      "/conditions/0/mode")

    def test_python_reads_a_member_name_with_a_warning_and_records_the_spelling(self):
        self.need_python()
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            r = cg.simulate_trial("十", guidance_mode="assist_as_needed", max_duration_s=0.05, keep_trace=False)
        self.assertTrue(any(issubclass(w.category, DeprecationWarning) and "assist-as-needed" in str(w.message)
                            for w in caught), [str(w.message) for w in caught])
        self.assertEqual(r.metrics["specification"]["trial"]["guidance_mode"], "assist-as-needed")
        self.assertEqual(r.metrics["guidance_mode"], "assist-as-needed")

    def test_each_guidance_mode_is_written_by_its_spelling_in_trial_json(self):
        # docs/cli.md lists the record's top-level `guidance_mode` as it is run: every mode by the spelling
        # the option took.
        for mode in self.spec_schema["properties"]["guidance_mode"]["enum"]:
            if mode == "replay":
                continue
            with self.subTest(mode=mode):
                out = self.tmp / f"mode-{mode}.json"
                run_ok(["trial", "十", "--guidance-mode", mode, "--max-duration", "0.05", "--json", out.name],
                       self.tmp, ok=False)
                record = json.loads(out.read_text(encoding="utf-8"))
                self.assertEqual(record["guidance_mode"], mode)
                self.assertEqual(record["specification"]["trial"]["guidance_mode"], mode)

    def test_writer_profile_is_one_list_on_every_surface(self):
        profiles = ["novice", "skilled", "foreign"]
        self.assertEqual(self.trial_help["--writer-profile"][0], "|".join(profiles))
        description = self.spec_schema["properties"]["writer_profile"]["description"]
        self.assertIn("novice, skilled or foreign", description)
        cohort = help_options(run_ok(["session", "cohort", "--help"], self.tmp).stdout.decode())
        self.assertEqual(cohort["--writer-profile"][0], "|".join(profiles))
        self.assertEqual(help_default(cohort["--writer-profile"][1]), "novice")
        self.assert_one_error(self.cli("trial", "十", "--writer-profile", "expert", "--check"), 2,
                              "--writer-profile")
        forged = json.loads(json.dumps(self.record["specification"]))
        forged["trial"]["writer_profile"] = "expert"
        (self.tmp / "profile.json").write_text(json.dumps({"specification": forged}), encoding="utf-8")
        self.assert_one_error(self.cli("trial", "--spec", "profile.json", "--check"), 2,
                              "/specification/trial/writer_profile")
        if cg is not None:
            with self.assertRaises(cg.InvalidArgument):
                cg.simulate_trial("十", writer="expert", max_duration_s=0.05, keep_trace=False)

    def test_session_enumerations_are_the_options_values(self):
        props = self.session_schema["properties"]
        run_help = help_options(run_ok(["session", "run", "--help"], self.tmp).stdout.decode())
        cohort_help = help_options(run_ok(["session", "cohort", "--help"], self.tmp).stdout.decode())
        self.assertEqual(run_help["--pacing"][0].split("|"), props["pacing"]["enum"])
        self.assertEqual(self.spec_schema["properties"]["pacing"]["enum"], props["pacing"]["enum"])
        for helps in (run_help, cohort_help):
            self.assertEqual(sorted(helps["--writer-learning"][0].split("|")), sorted(props["writer_learning"]
                                                                                          ["enum"]))
            self.assertEqual(help_default(helps["--writer-learning"][1]), "two-state")
        # session.json's writer also reads `human`, what versions 1 and 2 wrote for a person (docs/experiments.md).
        self.assertEqual(sorted(run_help["--writer"][0].split("|") + ["human"]), sorted(props["writer"]["enum"]))
        # What the session wrote is spelt so, in its session.json, its records and its tables.
        manifest = json.loads((self.session_dir / "session.json").read_text(encoding="utf-8"))
        self.assertEqual(manifest["writer"], "simulated")
        self.assertIn(manifest["pacing"], props["pacing"]["enum"])
        self.assertEqual(manifest.get("writer_learning", "none"), "two-state")
        for row in self.trials_csv:
            self.assertEqual((row["writer"], row["writer_learning"], row["writer_profile"]),
                             ("simulated", "two-state", "novice"))

    def test_refusal_reasons_are_one_list_in_docs_score_and_python(self):
        documented = ["too_short", "backwards", "wrong_place", "wrong_stroke", "wrong_order"]
        metrics_doc = (DOCS / "metrics.md").read_text(encoding="utf-8")
        self.assertIn(", ".join(f"`{r}`" for r in documented[:-1]), metrics_doc)
        self.assertEqual(sorted(self.score["refusals"]), sorted(documented))
        self.assertEqual(sorted(self.record["refusals"]), sorted(documented))
        for reason in self.strokes_csv:
            self.assertIn(reason["refusal"], documented + [""])
        if cg is not None:
            self.assertEqual(sorted(cg.StrokeRefusal.__members__), sorted(documented + ["none"]))

    def test_interaction_states_are_spelt_alike_in_trace_and_python(self):
        states = {row["state"] for row in self.trace}
        self.assertTrue(states <= {"SS", "AS", "CS", "WS"}, states)
        self.assertIn("WS", states)
        if cg is not None:
            self.assertEqual([s.short_name for s in cg.InteractionState.__members__.values()],
                             ["SS", "AS", "CS", "WS"])
            frame = self.python_trial().to_dataframe()
            self.assertEqual(sorted(str(c) for c in frame["state"].cat.categories), ["AS", "CS", "SS", "WS"])

    def test_score_units_are_m_and_data_everywhere(self):
        score_help = help_options(run_ok(["score", "--help"], self.tmp).stdout.decode())
        self.assertEqual(score_help["--units"][0], "m|data")
        self.assertEqual(help_default(score_help["--units"][1]), "m")
        self.assertEqual(self.score["units"], "m")
        self.assert_one_error(self.cli("score", "t.csv", "--character", "十", "--units", "mm"), 2, "--units")
        if cg is not None:
            with self.assertRaises(cg.InvalidArgument) as caught:
                cg.score(str(self.tmp / "t.csv"), "十", units="mm")
            self.assertIn("units", str(caught.exception))

    def test_end_reasons_are_one_list_in_the_docs(self):
        cli_text = section(DOCS / "cli.md", "## trial")
        m = re.search(r"`end_reason` says how the trial ended: (.*?)\(a\s+simulated", cli_text, re.S)
        from_cli = re.findall(r"`(\w+)`", m.group(1))
        python_text = (DOCS / "python.md").read_text(encoding="utf-8")
        m = re.search(r'r\.metrics\["end_reason"\]\s*# ([\w, ]+)', python_text)
        from_python = [w.strip() for w in m.group(1).split(",")]
        self.assertEqual(sorted(from_cli), sorted(from_python))
        self.assertIn(self.record["end_reason"], from_cli)

    # ---- units -------------------------------------------------------------------------------------------
    def test_trace_csv_positions_are_metres_of_a_60_mm_box(self):
        down = [r for r in self.trace if float(r["z"]) <= 0.0005]
        xs, ys = [float(r["x"]) for r in down], [float(r["y"]) for r in down]
        # 十's strokes span most of a 60 mm box: some centimetres, in metres.
        self.assertTrue(0.02 < max(xs) - min(xs) < 0.07, (min(xs), max(xs)))
        self.assertTrue(0.02 < max(ys) - min(ys) < 0.07, (min(ys), max(ys)))
        # Times in s at the servo rate (1000 Hz): a tick is 1 ms.
        ts = [float(r["t"]) for r in self.trace[:50]]
        self.assertAlmostEqual(ts[1] - ts[0], 1.0 / self.record["rate_hz"], places=9)
        # Forces in N: the largest commanded force is the record's max_force_n.
        peak = max(math.sqrt(float(r["fx"]) ** 2 + float(r["fy"]) ** 2 + float(r["fz"]) ** 2)
                   for r in self.trace)
        self.assertAlmostEqual(peak, self.record["max_force_n"], delta=2e-4)

    def test_record_lengths_are_metres_and_the_table_millimetres(self):
        for key in ("mean_deviation_m", "max_deviation_m", "frechet_m", "dtw_m"):
            with self.subTest(key=key):
                value = self.score[key]
                self.assertTrue(1e-6 < value < 0.01, value)
        # The table for people says mm: the same numbers times 1000.
        m = re.search(r"mean deviation\s+([\d.]+) mm", self.score_table)
        self.assertAlmostEqual(float(m.group(1)), self.score["mean_deviation_m"] * 1000, delta=0.0006)
        first = re.search(r"^\s*1\s+H\s+1\s+([\d.]+)\s+([\d.]+)", self.score_table, re.M)
        stroke = self.score["per_character"][0]["per_stroke"][0]
        self.assertAlmostEqual(float(first.group(1)), stroke["mean_deviation_m"] * 1000, delta=0.006)
        self.assertAlmostEqual(float(first.group(2)), stroke["max_deviation_m"] * 1000, delta=0.006)

    def test_path_lengths_and_times_of_a_stroke_agree_with_its_trace(self):
        per_stroke = self.score["per_character"][0]["per_stroke"]
        for i, stroke in enumerate(per_stroke):
            with self.subTest(stroke=i):
                # A stroke of 十 is about 4-5 cm of a 60 mm box.
                self.assertTrue(0.02 < stroke["path_length_m"] < 0.1, stroke["path_length_m"])
                self.assertAlmostEqual(stroke["mean_speed_m_s"], stroke["path_length_m"] / stroke["time_s"],
                                       delta=1e-6)
                self.assertTrue(0.1 < stroke["time_s"] < 30, stroke["time_s"])
        totals = self.score
        self.assertLessEqual(totals["pen_down_time_s"], totals["total_time_s"] + 1e-9)
        last = float(self.trace[-1]["t"])
        self.assertLessEqual(totals["total_time_s"], last + 1e-9)

    def test_tables_carry_the_records_values_in_the_same_units(self):
        records = {p.name.split("-")[0]: json.loads(p.read_text(encoding="utf-8"))
                   for p in (self.session_dir / "trials").glob("*.json")}
        for row in self.trials_csv:
            with self.subTest(trial=row["trial"]):
                record = records[f"{int(row['trial']):03d}"]
                for key in ("mean_deviation_m", "frechet_m", "total_time_s", "pen_down_time_s"):
                    self.assertEqual(float(row[key]), record[key], key)
                self.assertEqual(int(row["strokes_total"]), record["strokes_total"])
        for row in self.strokes_csv:
            with self.subTest(trial=row["trial"], stroke=row["stroke"]):
                record = records[f"{int(row['trial']):03d}"]
                stroke = record["per_character"][int(row["character"]) - 1]["per_stroke"][int(row["stroke"]) - 1]
                self.assertEqual(int(row["typical_id"]), stroke["typical_id"])
                for key in ("path_length_m", "time_s", "mean_deviation_m"):
                    if stroke[key] is None:
                        self.assertEqual(row[key], "")
                    else:
                        self.assertEqual(float(row[key]), stroke[key], key)
                if row["path_length_m"]:
                    self.assertTrue(0.005 < float(row["path_length_m"]) < 0.1, row["path_length_m"])

    def test_model_svg_is_in_the_data_box_with_y_down(self):
        svg = run_ok(["model", "口", "--svg", "-"], self.tmp).stdout.decode()
        self.assertIn('viewBox="0 0 1024 1024"', svg)
        model = self.models["口"]
        for number, stroke in enumerate(model["strokes"], start=1):
            with self.subTest(stroke=number):
                group = re.search(rf'<g class="stroke" id="stroke-{number}" data-typical-id="(\d+)">(.*?)</g>',
                                  svg, re.S)
                self.assertIsNotNone(group, f"no stroke-{number}")
                self.assertEqual(int(group.group(1)), stroke["typical_id"])
                x, y = stroke["feature_points"][0]
                circle = re.search(r'class="feature-point" cx="([\d.-]+)" cy="([\d.-]+)"', group.group(2))
                self.assertAlmostEqual(float(circle.group(1)), x, delta=0.06)
                self.assertAlmostEqual(float(circle.group(2)), 900 - y, delta=0.06)
                self.assertIn(f">{number}</text>", group.group(2))

    def test_trace_of_a_saved_trial_has_trial_csvs_header_and_units(self):
        h5 = next((self.session_dir / "trials").glob("001-*.trace.h5"))
        text = run_ok(["trace", str(h5)], self.tmp).stdout.decode()
        self.assertEqual(text.splitlines()[0], self.trace_header)
        rows = list(csv.DictReader(io.StringIO(text)))
        xs = [float(r["x"]) for r in rows if float(r["z"]) <= 0.0005]
        self.assertTrue(0.02 < max(xs) - min(xs) < 0.07)

    def test_the_csv_header_is_the_one_the_docs_help_and_schema_state(self):
        columns = "t,x,y,z,fx,fy,fz,state,stroke,element,attempt,rewritten"
        self.assertEqual(self.trace_header, columns)
        self.assertIn(columns, self.trial_help["--csv"][1])
        self.assertIn(columns, self.spec_schema["properties"]["csv_file"]["description"])
        self.assertIn(columns, (DOCS / "experiments.md").read_text(encoding="utf-8"))
        if cg is not None:
            names = [c["file_name"] for c in cg.trace_columns()]
            self.assertEqual(",".join(names), columns)

    def test_python_frame_columns_are_the_trace_tables_names(self):
        self.need_python()
        frame = self.python_trial().to_dataframe()
        named = [c["name"] for c in cg.trace_columns()]
        self.assertEqual(list(frame.columns), named)
        self.assertEqual(named[:7], ["t_s", "x_m", "y_m", "z_m", "fx_n", "fy_n", "fz_n"])
        self.assertTrue((frame["t_s"].to_numpy() == self.python_trial().time_s).all())

    def test_time_s_is_read_by_python_with_a_warning_and_named_by_the_cli(self):
        # docs/python.md: `time_s` (the name to_dataframe gave the time before) is read with a warning;
        # docs/metrics.md: a CSV column names `t` or `t_s`, any other name none.
        lines = (self.tmp / "t.csv").read_text(encoding="utf-8").splitlines()
        (self.tmp / "old.csv").write_text("\n".join(["time_s" + lines[0][1:]] + lines[1:]) + "\n",
                                          encoding="utf-8")
        self.assert_one_error(self.cli("score", "old.csv", "--character", "十"), 1, "old.csv")
        if cg is not None:
            r = self.python_trial()
            p = r.position_m
            with warnings.catch_warnings(record=True) as caught:
                warnings.simplefilter("always")
                got = cg.score({"time_s": r.time_s, "x": p[:, 0], "y": p[:, 1], "z": p[:, 2]}, "十")
            self.assertTrue(any(issubclass(w.category, DeprecationWarning) for w in caught))
            self.assertEqual(got["strokes_accepted"], r.metrics["strokes_accepted"])

    def test_python_mm_names_read_a_thousand_times_the_metres(self):
        self.need_python()
        m = self.python_trial().metrics
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            old = m["mean_deviation_mm"]
        self.assertTrue(any("mean_deviation_m" in str(w.message) for w in caught))
        self.assertAlmostEqual(old, m["mean_deviation_m"] * 1000, delta=1e-12)
        self.assertNotIn("mean_deviation_mm", list(m.keys()))

    # ---- numbering ---------------------------------------------------------------------------------------
    def test_trial_table_and_json_number_the_same_stroke(self):
        table = run_ok(["trial", "十", "--max-duration", "30"], self.tmp).stdout.decode()
        self.assertIn("strokes numbered from 1 here, from 0 in the JSON", table)
        lines = re.findall(r"^\s+(\d+)\s+十\s+(\w+)\s+(\d+)\s", table, re.M)
        self.assertEqual([int(n) for n, _, _ in lines], [1, 2])
        model = self.models["十"]["strokes"]
        for (number, acronym, typical), stroke, renderer in zip(lines, model, self.record["renderer_strokes"]):
            with self.subTest(stroke=number):
                self.assertEqual(renderer["index"], int(number) - 1)
                self.assertEqual((acronym, int(typical)), (stroke["acronym"], stroke["typical_id"]))
                self.assertEqual(renderer["typical_id"], stroke["typical_id"])
                per_stroke = self.record["per_character"][0]["per_stroke"][int(number) - 1]
                self.assertEqual((per_stroke["index"], per_stroke["typical_id"]),
                                 (int(number) - 1, stroke["typical_id"]))

    def test_score_table_and_json_number_the_same_stroke(self):
        lines = re.findall(r"^\s+(\d+)\s+(\w+)\s+(\d+)\s+[\d.]+", self.score_table, re.M)
        self.assertEqual([int(n) for n, _, _ in lines], [1, 2])
        for (number, acronym, typical), stroke in zip(lines, self.score["per_character"][0]["per_stroke"]):
            self.assertEqual(stroke["index"], int(number) - 1)
            self.assertEqual(stroke["typical_id"], int(typical))

    def test_trace_stroke_column_counts_from_0_and_attempt_from_1(self):
        strokes = {int(r["stroke"]) for r in self.trace}
        self.assertEqual(strokes, {0, 1})
        attempts = {int(r["attempt"]) for r in self.trace}
        self.assertTrue(attempts <= {0, 1, 2, 3, 4, 5, 6}, attempts)
        self.assertIn(1, attempts)
        # The ticks the trace files under stroke i while writing (WS) lie on that stroke of the record.
        model = self.models["十"]["strokes"]
        for i in (0, 1):
            ws = [r for r in self.trace if r["state"] == "WS" and int(r["stroke"]) == i]
            self.assertTrue(ws, f"no WS tick on stroke {i}")
            xs = [float(r["x"]) for r in ws]
            ys = [float(r["y"]) for r in ws]
            spread_x, spread_y = max(xs) - min(xs), max(ys) - min(ys)
            horizontal = model[i]["acronym"] == "H"
            self.assertEqual(spread_x > spread_y, horizontal, (i, spread_x, spread_y))

    def test_score_segments_end_one_past_their_last_sample(self):
        for segment in self.score["per_character"][0]["segments"]:
            with self.subTest(begin=segment["begin"]):
                begin, end = segment["begin"], segment["end"]
                self.assertLessEqual(float(self.trace[begin]["z"]), 0.0005)
                self.assertLessEqual(float(self.trace[end - 1]["z"]), 0.0005)
                if end < len(self.trace):
                    self.assertGreater(float(self.trace[end]["z"]), 0.0005)
                if begin > 0:
                    self.assertGreater(float(self.trace[begin - 1]["z"]), 0.0005)

    def test_strokes_csv_numbers_from_1_with_the_models_typical_ids(self):
        by_trial = {}
        for row in self.strokes_csv:
            by_trial.setdefault(row["trial"], []).append(row)
        for trial, rows in by_trial.items():
            with self.subTest(trial=trial):
                text = rows[0]["character_text"]
                self.assertEqual([int(r["stroke"]) for r in rows], list(range(1, len(rows) + 1)))
                self.assertEqual({r["character"] for r in rows}, {"1"})
                self.assertEqual([int(r["typical_id"]) for r in rows],
                                 [s["typical_id"] for s in self.models[text]["strokes"]])

    def test_trial_numbers_are_the_files_the_plan_and_the_page_anchors(self):
        manifest = json.loads((self.session_dir / "session.json").read_text(encoding="utf-8"))
        self.assertEqual([p["index"] for p in manifest["plan"]], [1, 2, 3, 4])
        self.assertTrue(all(p["block"] >= 1 and p["item"] >= 1 and p["repetition"] >= 1 for p in manifest["plan"]))
        files = sorted(p.name for p in (self.session_dir / "trials").glob("*.json"))
        self.assertEqual([f[:3] for f in files], ["001", "002", "003", "004"])
        self.assertEqual(sorted(int(r["trial"]) for r in self.trials_csv), [1, 2, 3, 4])
        for row in self.trials_csv:
            plan = manifest["plan"][int(row["trial"]) - 1]
            self.assertEqual((row["characters"], row["condition"], int(row["item"]), int(row["block"])),
                             (plan["characters"], plan["condition"], plan["item"], plan["block"]))
        session = self.session_dir.name
        page = next((self.tmp / "pages_files").rglob("*.html")).read_text(encoding="utf-8")
        self.assertEqual(sorted(int(n) for n in re.findall(rf'<article [^>]*id="trial-{re.escape(session)}-(\d+)"',
                                                            page)), [1, 2, 3, 4])

    def test_python_scene_indexes_the_strokes_score_matched(self):
        self.need_python()
        scene = cg.Scene("十")
        typical = [s.typical_id for s in scene.characters[0].strokes]
        self.assertEqual(typical, [s["typical_id"] for s in self.models["十"]["strokes"]])
        got = cg.score(str(self.tmp / "t.csv"), "十")
        matched = [s["matched_stroke"] for s in got["per_character"][0]["segments"] if s["matched_stroke"] is
                   not None]
        self.assertEqual(matched, [0, 1])
        self.assertEqual(got["per_character"][0]["per_stroke"][1]["typical_id"], typical[1])

    # ---- metric names ------------------------------------------------------------------------------------
    def metric_levels(self):
        """The metric table's rows as {name: (kind, unit, levels)}."""
        return {ticked(r[0])[0]: (r[1], r[2], [x.strip() for x in r[3].split(",")])
                for r in self.metric_rows if ticked(r[0])}

    def assert_kind(self, value, kind, where):
        if kind == "count":
            self.assertIsInstance(value, int, where)
            self.assertNotIsInstance(value, bool, where)
        elif kind == "flag":
            self.assertIsInstance(value, bool, where)
        else:
            self.assertTrue(value is None or isinstance(value, float), f"{where}: {value!r}")

    def test_each_scene_metric_is_a_key_of_trial_score_and_python_of_its_kind(self):
        levels = self.metric_levels()
        scene = [n for n, (_, _, lv) in levels.items() if "scene" in lv]
        self.assertEqual(sorted(scene), sorted(self.metrics_schema["properties"]))
        python_metrics = self.python_trial().metrics if cg is not None else None
        python_score = cg.score(str(self.tmp / "t.csv"), "十") if cg is not None else None
        for name in scene:
            kind = levels[name][0]
            with self.subTest(metric=name):
                for where, document in (("trial --json", self.record), ("score --json", self.score),
                                        ("python metrics", python_metrics), ("python score", python_score)):
                    if document is None:
                        continue
                    self.assertIn(name, document, where)
                    self.assert_kind(document[name], kind, f"{where} {name}")

    def test_character_and_stroke_metrics_are_keys_at_their_levels(self):
        levels = self.metric_levels()
        character = self.score["per_character"][0]
        stroke = character["per_stroke"][0]
        for name, (kind, _, lv) in levels.items():
            with self.subTest(metric=name):
                if "character" in lv:
                    self.assertIn(name, character)
                    self.assertIn(name, self.record["per_character"][0])
                    self.assert_kind(character[name], kind, name)
                if "stroke" in lv:
                    self.assertIn(name, stroke)
                    self.assert_kind(stroke[name], kind, name)
                if "run" in lv:
                    self.assertIn(name, self.record)
                if "run" in lv and "scene" not in lv:
                    self.assertNotIn(name, self.score, "a scored trace has no renderer")

    def test_python_metric_table_is_the_schemas(self):
        self.need_python()
        table = cg.metric_table()
        rows = [dict(r) if isinstance(r, dict) else {k: getattr(r, k) for k in dir(r) if not k.startswith("_")}
                for r in table]
        names = [r["name"] for r in rows]
        levels = self.metric_levels()
        self.assertEqual(names, list(levels))
        for r in rows:
            with self.subTest(metric=r["name"]):
                unit = levels[r["name"]][1]
                self.assertEqual(r["unit"], "" if unit in ("-", "1") else unit)
                suffix = {"m": "_m", "s": "_s", "m/s": "_m_s"}.get(r["unit"])
                if suffix:
                    self.assertTrue(r["name"].endswith(suffix), r["name"])

    def test_table_metric_columns_follow_the_metric_table(self):
        # docs/experiments.md: the metric columns are `completed_in_order` to `normalised_jerk` in trials.csv
        # and `mean_deviation_m` to `assisted` in strokes.csv.
        levels = self.metric_levels()
        trials = self.trials_header
        metric_columns = trials[trials.index("completed_in_order"):trials.index("normalised_jerk") + 1]
        strokes = self.strokes_header
        stroke_columns = strokes[strokes.index("mean_deviation_m"):strokes.index("assisted") + 1]
        for name in metric_columns:
            self.assertTrue({"scene", "run"} & set(levels[name][2]), name)
        for name in stroke_columns:
            self.assertIn("stroke", levels[name][2], name)
        if cg is not None:
            table = cg.metric_table()
            get = (lambda r, k: r.get(k)) if isinstance(table[0], dict) else (lambda r, k: getattr(r, k, None))
            for column, found in (("trials_column", metric_columns), ("strokes_column", stroke_columns)):
                placed = sorted((get(r, column), get(r, "name")) for r in table if get(r, column))
                self.assertEqual([n for _, n in placed], found, column)

    def test_no_millimetre_name_is_written_anywhere(self):
        before = [r[6].strip("`") for r in self.metric_rows if len(r) > 6 and r[6].strip("`")]
        self.assertIn("mean_deviation_mm", before)
        for name in before:
            with self.subTest(name=name):
                self.assertNotIn(name, json.dumps(self.record))
                self.assertNotIn(name, json.dumps(self.score))
                self.assertNotIn(name, self.trials_header + self.strokes_header)

    def test_python_per_stroke_frame_has_the_documented_columns(self):
        self.need_python()
        frame = self.python_trial().per_stroke_dataframe()
        text = (DOCS / "python.md").read_text(encoding="utf-8")
        m = re.search(r"r\.per_stroke_dataframe\(\)\s+# one row per stroke: (.*?)\n\nimport", text, re.S)
        words = re.findall(r"[a-z_/]+", m.group(1).replace("#", " "))
        documented = []
        for word in words:
            if "/" in word:
                stems = word.split("/")
                suffix = stems[-1].split("_", 1)[1]
                documented += [f"{s.split('_')[0]}_{suffix}" for s in stems]
            else:
                documented.append(word)
        self.assertEqual(sorted(frame.columns), sorted(documented))

    # ---- docs tables against the program -----------------------------------------------------------------
    def test_the_record_key_table_lists_exactly_the_schemas_parts(self):
        text = section(DOCS / "cli.md", "### Re-running a trial")
        rows = [r for r in markdown_rows(text) if r and r[0] != "key"]
        documented = {k for r in rows for k in ticked(r[0])} | {"format", "version"}
        self.assertEqual(documented, set(self.record_schema["properties"]))
        self.assertEqual(set(self.record["specification"]), set(self.record_schema["properties"]))

    def test_every_key_of_trial_json_is_named_in_its_docs(self):
        text = section(DOCS / "cli.md", "## trial")
        named = set(re.findall(r"`(\w+)`", text))
        scene = set(self.metrics_schema["properties"])
        for key in self.record:
            with self.subTest(key=key):
                self.assertTrue(key in named or key in scene or key in ("per_character", "refusals"),
                                f"trial --json key {key!r} is named nowhere in docs/cli.md's trial section")

    def test_every_key_of_score_json_is_named_in_its_docs(self):
        text = section(DOCS / "cli.md", "## score")
        named = set(re.findall(r"`(\w+)`", text))
        scene = set(self.metrics_schema["properties"])
        for key in self.score:
            with self.subTest(key=key):
                self.assertTrue(key in named or key in scene, key)
        for key in ("character", "trace", "units", "samples"):
            self.assertIn(key, self.score)

    def test_trials_csv_columns_are_the_docs_table(self):
        text = section(DOCS / "experiments.md", "## Tidy tables")
        start = text.index("`trials.csv`, one row per saved trial:")
        table = markdown_rows(text[start:text.index("`strokes.csv`, one row per reference stroke")])
        documented = [n for r in table[1:] for n in ticked(r[0])]
        self.assertEqual(sorted(documented), sorted(self.trials_header))
        self.assertEqual(len(documented), len(set(documented)))

    def test_strokes_csv_columns_are_the_docs_list(self):
        text = section(DOCS / "experiments.md", "## Tidy tables")
        start = text.index("`strokes.csv`, one row per reference stroke")
        paragraph = text[start:text.index("\n\n", start)]
        documented = [n for n in re.findall(r"`(\w+)`", paragraph) if n != "strokes"]
        # "the per-stroke deviations [m]" are the metric table's stroke-level deviations.
        levels = self.metric_levels()
        deviations = [n for n, (_, unit, lv) in levels.items() if "stroke" in lv and unit == "m"
                      and n in self.strokes_header and n != "path_length_m"]
        named = [n for n in documented if n in self.strokes_header or n not in
                 ("too_short", "backwards", "wrong_place", "wrong_stroke", "wrong_order", "verdict",
                  "matched_stroke")]
        self.assertEqual(sorted(set(named) | set(deviations)), sorted(self.strokes_header))

    def test_a_study_records_keys_are_the_docs_list(self):
        text = section(DOCS / "experiments.md", "### Trial records")
        named = set(re.findall(r"`(\w+)`", text))
        record = json.loads(next((self.session_dir / "trials").glob("001-*.json")).read_text(encoding="utf-8"))
        scene = set(self.metrics_schema["properties"])
        for key in record:
            with self.subTest(key=key):
                self.assertTrue(key in named or key in scene or key in ("format", "version", "refusals",
                                                                          "per_character"), key)

    def test_the_protocol_table_states_the_schemas_ranges_and_defaults(self):
        schema = markdown_rows(run_ok(["schema", "protocol", "--markdown"], self.tmp).stdout.decode())
        by_field = {ticked(r[0])[0]: r for r in schema if ticked(r[0])}
        docs = {ticked(r[0])[0]: r for r in markdown_rows(section(DOCS / "experiments.md", "## Protocol files"))
                if r and ticked(r[0])}
        for key, field in (("trial.max_duration_s", "max_duration_s"), ("trial.rate_hz", "rate_hz"),
                           ("breaks.between_blocks_s", "between_blocks_s")):
            with self.subTest(key=key):
                row = by_field[field]
                self.assertIn(key, docs)
                self.assertEqual(float(row[4].strip("`")), float(docs[key][2]))
                self.assertIn(row[3].replace("in ", ""), docs[key][1])

    def test_session_keys_the_docs_call_optional_are_optional_in_the_schema(self):
        text = section(DOCS / "cli.md", "## schema")
        m = re.search(r"every part required but the keys written only when\s+they have a value or added since the "
                      r"first folders \((.*?)\), and", text, re.S)
        optional = [k for k in re.findall(r"`(\w+)`", m.group(1))]
        top = [k for k in optional if k in self.session_schema["properties"]]
        self.assertGreaterEqual(len(top), 6, optional)
        for key in top:
            self.assertNotIn(key, self.session_schema["required"], key)
        for key in self.session_schema["required"]:
            self.assertNotIn(key, optional)

    def assert_keys_named(self, document, named, where, extra=()):
        """Every key of `document`, at every depth of objects and lists of objects, is one `named`."""
        def walk(value, path):
            if isinstance(value, dict):
                for key, inner in value.items():
                    with self.subTest(where=where, key=f"{path}/{key}"):
                        self.assertTrue(key in named or key in extra, f"{where}: {path}/{key} is in no docs")
                    walk(inner, f"{path}/{key}")
            elif isinstance(value, list):
                for inner in value[:2]:
                    walk(inner, path + "/N")
        walk(document, "")

    def test_session_plan_json_keys_are_the_docs_list(self):
        plan = json.loads(run_ok(["session", "plan", "p.json", "--subjects", "1", "--json"], self.tmp).stdout)
        text = section(DOCS / "cli.md", "## session plan")
        named = set(re.findall(r"`(\w+)`", text))
        self.assert_keys_named(plan, named, "session plan --json")
        first = plan["subjects"][0]["sessions"][0]["phases"][0]
        self.assertEqual(first["first_trial"], 1, "1-based: the index of the phase's first trial in the plan")

    def test_devices_json_keys_are_the_docs_list_and_pythons(self):
        listing = json.loads(run_ok(["devices", "--json"], self.tmp).stdout)
        text = section(DOCS / "cli.md", "## devices")
        named = set(re.findall(r"`(\w+)`", text))
        self.assert_keys_named(listing, named, "devices --json")
        info = next(d for d in listing["devices"] if d["name"] == "simulated")["info"]
        for key, value in info.items():
            if isinstance(value, float):
                self.assertRegex(key, r"_(n|m|n_per_m|n_s_per_m)$", "a number's key carries its unit")
        if cg is not None:
            python = next(d for d in cg.list_devices().devices if d.name == "simulated").info.to_dict()
            self.assertEqual(sorted(python), sorted(info))

    def test_characters_json_keys_and_numbers_are_the_docs_and_the_models(self):
        listing = json.loads(run_ok(["characters", "--text", "十口x", "--json"], self.tmp).stdout)
        text = section(DOCS / "cli.md", "## characters")
        m = re.search(r"`--json` prints an object: (.*?)Exit status", text, re.S)
        named = set(re.findall(r"`(\w+)`", m.group(1)))
        self.assertEqual(named, {"library", "count", "characters", "character", "code_point", "strokes",
                                 "typical_ids", "typical_strokes", "not_found"})
        self.assert_keys_named(listing, named, "characters --json")
        for entry in listing["characters"]:
            model = self.models[entry["character"]]["strokes"]
            self.assertEqual(entry["code_point"], f"U+{ord(entry['character']):04X}")
            self.assertEqual(entry["typical_ids"], [s["typical_id"] for s in model])
            self.assertEqual(entry["typical_strokes"], [s["acronym"] for s in model])
            self.assertEqual(entry["strokes"], len(model))
        self.assertEqual(listing["count"], 2)

    def cohort_tables(self):
        """`session cohort` of the protocol with its defaults, once."""
        if not (self.tmp / "C" / "trials.csv").exists():
            (self.tmp / "C").mkdir(exist_ok=True)
            run_ok(["session", "cohort", "p.json", "--subjects", "1", "--csv", "C"], self.tmp)
        return self.tmp / "C"

    def test_python_cohort_defaults_are_the_commands(self):
        # docs/python.md: simulate(..., profile="novice", learning="two-state", individual_differences=True,
        # prefix="S"), the defaults of `session cohort`'s --writer-profile, --writer-learning,
        # --individual-differences and --subject: the same subjects give the same rows.
        self.need_python()
        import calligraphy.cohort
        folder = self.cohort_tables()
        study = calligraphy.cohort.simulate(str(self.tmp / "p.json"), 1, progress=False)
        rows = list(csv.DictReader(io.StringIO((folder / "trials.csv").read_text(encoding="utf-8"))))
        frame = study.trials
        self.assertEqual(list(frame.columns), self.trials_header)
        self.assertEqual(list(frame["subject"]), [r["subject"] for r in rows])
        for key in ("mean_deviation_m", "total_time_s", "shape_skill", "subject_motor_noise_factor"):
            with self.subTest(key=key):
                self.assertEqual([float(v) for v in frame[key]], [float(r[key]) for r in rows])
        self.assertEqual(set(frame["writer_learning"]), {"two-state"})
        self.assertEqual(set(frame["writer_profile"]), {"novice"})

    def test_cohort_and_report_tables_have_one_header(self):
        self.cohort_tables()
        for name, header in (("trials.csv", self.trials_header), ("strokes.csv", self.strokes_header)):
            with self.subTest(table=name):
                text = (self.tmp / "C" / name).read_text(encoding="utf-8")
                self.assertEqual(text.splitlines()[0].split(","), header)
        rows = list(csv.DictReader(io.StringIO((self.tmp / "C" / "trials.csv").read_text(encoding="utf-8"))))
        self.assertEqual([int(r["trial"]) for r in rows], [1, 2, 3, 4])
        self.assertEqual({r["session"] for r in rows}, {"vocab-S01-s1"})

    def test_log_events_and_fields_are_the_docs_table(self):
        text = section(DOCS / "experiments.md", "## Sessions")
        table = {ticked(r[0])[0]: set(re.findall(r"`(\w+)`", r[2])) for r in markdown_rows(text)
                 if r and ticked(r[0]) and len(r) == 3}
        self.assertIn("trial_saved", table)
        trial_fields = {"trial", "phase", "condition", "characters", "repetition", "file"}
        records = {p.name.split("-")[0]: json.loads(p.read_text(encoding="utf-8"))
                   for p in (self.session_dir / "trials").glob("*.json")}
        lines = (self.session_dir / "log.jsonl").read_text(encoding="utf-8").splitlines()
        for line in lines:
            entry = json.loads(line)
            event = entry["event"]
            with self.subTest(event=event):
                self.assertIn(event, table)
                allowed = table[event] | {"event", "time_utc"} | (trial_fields if event.startswith("trial_")
                                                                  else set())
                self.assertEqual(set(entry) - allowed, set(), event)
                if event == "trial_saved":
                    # `time_s`: the record's `total_time_s`, in s; `trial` 1-based, the NNN of its file.
                    record = records[f"{entry['trial']:03d}"]
                    self.assertEqual(entry["time_s"], record["total_time_s"])
                    self.assertTrue(entry["file"].startswith(f"{entry['trial']:03d}-"))
        self.assertEqual(json.loads(lines[-1])["event"], "session_completed")

    def test_rate_and_duration_count_ticks_in_hz_and_seconds(self):
        out = self.cli("trial", "十", "--rate", "500", "--max-duration", "0.05", "--csv", "r500.csv", "--json",
                       "r500.json")
        self.assertEqual(out.returncode, 1, "a trial at its time limit ended early")
        record = json.loads((self.tmp / "r500.json").read_text(encoding="utf-8"))
        rows = list(csv.DictReader(io.StringIO((self.tmp / "r500.csv").read_text(encoding="utf-8"))))
        # --max-duration x --rate servo ticks: 0.05 s x 500 Hz = 25 ticks, 2 ms apart, from t = 0.
        self.assertEqual(len(rows), 25)
        self.assertEqual([float(r["t"]) for r in rows[:2]], [0.0, 0.002])
        self.assertEqual((record["rate_hz"], record["end_reason"]), (500, "time_limit"))
        self.assertAlmostEqual(record["trial_time_s"], 0.05, delta=1e-9)
        trial = record["specification"]["trial"]
        self.assertEqual((trial["rate_hz"], trial["max_duration_s"]), (500, 0.05))

    def test_writer_settings_are_one_text_from_option_and_python(self):
        out = self.tmp / "param.json"
        self.cli("trial", "十", "--writer-param", "bias_offset_m=0.004", "--max-duration", "0.05", "--json", out.name)
        record = json.loads(out.read_text(encoding="utf-8"))
        self.assertEqual(record["writer_parameters"], ["bias_offset_m=0.004"])
        stated = record["specification"]["trial"]["writer_parameters"]
        self.assertEqual(len(stated), 1)
        if cg is not None:
            r = cg.simulate_trial("十", writer_params={"bias_offset_m": 0.004}, max_duration_s=0.05,
                                  keep_trace=False)
            self.assertEqual(r.metrics["writer_parameters"], record["writer_parameters"])
            self.assertEqual(r.metrics["specification"]["trial"]["writer_parameters"], stated)
            self.assertEqual(r.metrics["specification"]["writer"], record["specification"]["writer"])

    def test_a_trace_in_data_units_scores_in_metres(self):
        self.need_python()
        scene = cg.Scene("十")
        placement = scene.characters[0].placement
        lines = ["t,x,y,z"]
        for r in self.trace:
            x, y = placement.to_data([float(r["x"]), float(r["y"])])
            lines.append(f"{r['t']},{x!r},{y!r},{r['z']}")
        (self.tmp / "data-units.csv").write_text("\n".join(lines) + "\n", encoding="utf-8")
        in_data = json.loads(run_ok(["score", "data-units.csv", "--character", "十", "--units", "data", "--json",
                                     "-"], self.tmp).stdout)
        self.assertEqual(in_data["units"], "data")
        for key in ("mean_deviation_m", "max_deviation_m", "frechet_m", "dtw_m", "total_time_s"):
            with self.subTest(key=key):
                # Lengths stay metres on the paper whatever the trace's units.
                self.assertAlmostEqual(in_data[key], self.score[key], delta=1e-7)
        by_python = cg.score(str(self.tmp / "data-units.csv"), "十", units="data")
        self.assertAlmostEqual(by_python["mean_deviation_m"], self.score["mean_deviation_m"], delta=1e-7)

    def test_a_protocols_trial_settings_reach_plan_session_and_records(self):
        # The protocol's `trial.max_duration_s` (30 here) and `trial.rate_hz` (left out: the schema's default)
        # are the plan's, each study record's specification and each record's renderer figures, in s and Hz.
        schema = {ticked(r[0])[0]: r for r in markdown_rows(run_ok(["schema", "protocol", "--markdown"],
                                                                    self.tmp).stdout.decode()) if ticked(r[0])}
        rate = float(schema["rate_hz"][4].strip("`"))
        plan = json.loads(run_ok(["session", "plan", "p.json", "--subjects", "1", "--json"], self.tmp).stdout)
        self.assertEqual(plan["trial_max_duration_s"], PROTOCOL["trial"]["max_duration_s"])
        session = plan["subjects"][0]["sessions"][0]
        self.assertEqual(session["max_duration_s"], session["trials"] * PROTOCOL["trial"]["max_duration_s"])
        for path in sorted((self.session_dir / "trials").glob("*.json")):
            with self.subTest(record=path.name):
                trial = json.loads(path.read_text(encoding="utf-8"))["specification"]["trial"]
                self.assertEqual((trial["max_duration_s"], trial["rate_hz"]),
                                 (PROTOCOL["trial"]["max_duration_s"], rate))
                self.assertEqual(trial["pacing"], "lock-step")

    def test_python_frames_number_strokes_as_the_trace_and_the_record(self):
        # Python counts from 0 (docs/python.md): the per-stroke frame's `stroke` is the trace's `stroke`
        # column and the record's `renderer_strokes[].index`, the same stroke by the same number.
        self.need_python()
        r = self.python_trial()
        frame = r.per_stroke_dataframe()
        self.assertEqual(frame.index.name, "stroke")
        self.assertEqual(list(frame.index), [s["index"] for s in r.metrics["renderer_strokes"]])
        self.assertEqual(list(frame["typical_id"]), [s["typical_id"] for s in r.metrics["renderer_strokes"]])
        self.assertEqual(sorted(set(int(v) for v in r.stroke)), list(frame.index))
        self.assertEqual(list(frame["typical_id"]), [s["typical_id"] for s in self.models["十"]["strokes"]])

    def test_a_protocols_enumerations_are_the_docs_lists(self):
        schema = json.loads(run_ok(["schema", "protocol"], self.tmp).stdout)
        found = {}

        def walk(value, path):
            if isinstance(value, dict):
                if "enum" in value:
                    found[path.rsplit("/", 1)[-1] if "/order/" not in path else "order." + path.rsplit("/", 1)[-1]] \
                        = value["enum"]
                for key, inner in value.items():
                    walk(inner, f"{path}/{key}")
            elif isinstance(value, list):
                for inner in value:
                    walk(inner, path)
        walk(schema, "")
        text = section(DOCS / "experiments.md", "## Protocol files")
        rows = {ticked(r[0])[0]: r for r in markdown_rows(text) if r and ticked(r[0])}
        phases = section(DOCS / "experiments.md", "### Phases: pre-test, training, post-test, retention, transfer")
        phase_rows = {ticked(r[0])[0]: r for r in markdown_rows(phases) if r and ticked(r[0])}
        documented = {"mode": [ticked(r[0])[0] for r in markdown_rows(text) if len(r) == 3 and ticked(r[0])
                               and r[0] != "`format`" and not ticked(r[0])[0].startswith(("test", "order"))],
                      "order.conditions": ticked(rows["order.conditions"][1]),
                      "order.characters": ticked(rows["order.characters"][1]),
                      "phase": ticked(phase_rows["phase"][1]),
                      "assignment": ticked(phase_rows["assignment"][1])}
        for key, spellings in documented.items():
            with self.subTest(enum=key):
                self.assertIn(key, found)
                self.assertEqual(sorted(found[key]), sorted(spellings))
        # What a session writes is spelt so: trials.csv's `mode` and `phase`.
        for row in self.trials_csv:
            self.assertIn(row["mode"], found["mode"])
            self.assertIn(row["phase"], found["phase"])


if __name__ == "__main__":
    unittest.main()
