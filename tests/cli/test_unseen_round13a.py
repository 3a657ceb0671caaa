#!/usr/bin/env python3
"""Round 13A, written from the documentation alone (README.md, docs/*.md, each command's --help, the outputs of
`calligraphy schema ...` and the Python module's docstrings): one vocabulary across every surface. Run by CTest
as `cli_unseen_round13a_tests`.

The program promises one schema (the fields and enumerations of a trial, a protocol and a session folder), one
trial specification (what runs and what is recorded) and one metric table (every result's name, unit and
levels). Each case takes one name, number or spelling through the surfaces that show it and asserts that they
agree, after the conversion the docs state:

- the schema's fields against the help of `trial` (defaults, ranges, enumerations, the documented option names
  and `--watchdog-ms`' milliseconds), against what a trial with its defaults records, against Python's keyword
  defaults, and `calligraphy schema` JSON against its own `--markdown` table; every option of every command
  with at most one stated default;
- enumerations spelt another way (`assist_as_needed`, `lock_step`, `Novice`, a profile that is none) on the
  command line, in a record, a protocol and Python; the mode names of docs/force-rendering.md; what a record
  writes (guidance modes, end reasons, refusals, writers) is what the others take and list;
- the metric table (`schema metrics`, its Markdown, `calligraphy.metric_table()`) against the keys and levels
  of `trial --json`, `score --json`, a study's records, `report --csv`'s tables and `calligraphy.study.load`;
- one trial's deviation, times and one stroke's numbers through its record, `score` (JSON and table), the
  report's tables and page, Python and the model, in metres and millimetres, numbered from 0 or 1 as each
  surface states; times rounded to whole nanoseconds as docs/metrics.md states;
- the trace's columns as `--csv`'s help, the docs and `calligraphy.trace_columns()` name them, the units
  `score` takes as docs/metrics.md spells them, and the stroke numbering Python's `score` docstring states.

CALLIGRAPHY_CLI names the program; CALLIGRAPHY_SOURCE_DIR the source tree; the built Python package is found on
PYTHONPATH. CALLIGRAPHY_SANITIZED=1 takes a small subset.
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

from outsider import error_lines, run, sanitized_subset

SOURCE = Path(os.environ.get("CALLIGRAPHY_SOURCE_DIR", Path(__file__).resolve().parents[2]))
SHI = "十"
YI = "一"

try:
    import calligraphy as cg
    import calligraphy.study
except ImportError:  # pragma: no cover - a build without the Python bindings
    cg = None

needs_python = unittest.skipIf(cg is None, "the calligraphy Python package (PYTHONPATH) is missing")

# The outcomes docs/cli.md ("JSON keys") lists for `end_reason`, and the stroke matcher's refusals
# (docs/metrics.md, docs/python.md).
END_REASONS = {"completed", "time_limit", "device_fault", "watchdog", "interrupted", "gave_up", "writer_finished"}
REFUSALS = {"too_short", "backwards", "wrong_place", "wrong_stroke", "wrong_order"}

PROTOCOL = {
    "format": "calligraphy-study-protocol", "version": 1, "name": "voc",
    "conditions": [{"name": "h", "mode": "haptic"}, {"name": "q", "mode": "quiz"}],
    "test": {"characters": [SHI, YI], "conditions": ["h", "q"], "repetitions": 1},
    "trial": {"max_duration_s": 20},
}


def ok(result):
    return result.returncode == 0


def out(result):
    return result.stdout.decode("utf-8", "replace")


class Shared:
    """One trial of 十 (seed 1) from the command line with its record, trace and drawing, `score` of its trace,
    the schemas, and one simulated subject's session of 十 and 一 under a haptic and a quiz condition with its
    tables, page and Python tables."""
    folder = None

    @classmethod
    def get(cls):
        if cls.folder is not None:
            return cls
        cls.folder = Path(tempfile.mkdtemp(prefix="unseen13a-"))
        f = cls.folder
        r = run(["trial", SHI, "--seed", "1", "--max-duration", "20", "--json", "t.json", "--csv", "t.csv",
                 "--svg", "t.svg"], f)
        assert ok(r), error_lines(r)
        cls.trial_text = out(r)
        cls.trial = json.loads((f / "t.json").read_text())
        r = run(["score", "t.csv", "--character", SHI, "--json", "s.json"], f)
        assert ok(r), error_lines(r)
        cls.score_text = out(r)
        cls.score = json.loads((f / "s.json").read_text())
        cls.schema = {}
        cls.markdown = {}
        for kind in ("specification", "record", "session", "protocol", "metrics"):
            cls.schema[kind] = json.loads(out(run(["schema", kind], f)))
            cls.markdown[kind] = out(run(["schema", kind, "--markdown"], f))
        (f / "p.json").write_text(json.dumps(PROTOCOL, ensure_ascii=False))
        r = run(["session", "run", "p.json", "--writer", "simulated", "--subjects", "1", "--device", "simulated",
                 "--out", "study"], f)
        assert ok(r), error_lines(r)
        (f / "tables").mkdir()
        (f / "pages").mkdir()
        r = run(["report", "study", "--csv", "tables", "--out", "pages/r.html"], f)
        assert ok(r), error_lines(r)
        cls.session_dir = next((f / "study" / "S01").iterdir())
        cls.manifest = json.loads((cls.session_dir / "session.json").read_text())
        cls.records = {p.name: json.loads(p.read_text()) for p in sorted((cls.session_dir / "trials").glob("*.json"))}
        cls.trials_csv = list(csv.DictReader(io.StringIO((f / "tables" / "trials.csv").read_text())))
        cls.strokes_csv = list(csv.DictReader(io.StringIO((f / "tables" / "strokes.csv").read_text())))
        cls.trials_header = (f / "tables" / "trials.csv").read_text().splitlines()[0].split(",")
        cls.strokes_header = (f / "tables" / "strokes.csv").read_text().splitlines()[0].split(",")
        cls.page = next((f / "pages" / "r_files" / "S01").glob("*.html")).read_text()
        return cls


def tearDownModule():
    if Shared.folder is not None:
        shutil.rmtree(Shared.folder, ignore_errors=True)


def markdown_rows(text):
    """The rows of the Markdown table(s) in `text` as dicts by header."""
    rows, header = [], None
    for line in text.splitlines():
        if not line.startswith("|"):
            header = None
            continue
        cells = [c.strip() for c in re.split(r"(?<!\\)\|", line.strip())[1:-1]]
        if header is None:
            header = cells
        elif set("".join(cells)) <= set("- :"):
            continue
        else:
            rows.append(dict(zip(header, cells)))
    return rows


def help_options(text):
    """`--name` -> (its whole help text, one line) of a command's --help."""
    options, name = {}, None
    for line in text.splitlines():
        m = re.match(r"\s{2}(-\w,)?(--[\w-]+)(.*)", line)
        if m:
            name = m.group(2)
            options[name] = m.group(3).strip()
        elif name and line.startswith(" " * 10) and line.strip():
            options[name] += " " + line.strip()
        elif not line.strip() or not line.startswith(" "):
            name = None
    return options


def help_default(text):
    m = re.search(r"\(default: (.*)\)\s*$", text)
    return m.group(1) if m else None


def option_of(field):
    """The option of a specification field, by docs/cli.md's mapping."""
    special = {"guidance_stiffness_n_per_m": "--guidance-stiffness", "timing_speed_m_s": "--timing-speed",
               "rate_hz": "--rate", "max_duration_s": "--max-duration", "watchdog_s": "--watchdog-ms",
               "writer_parameters": "--writer-param", "json_file": "--json", "csv_file": "--csv",
               "svg_file": "--svg", "record_file": "--record", "characters": None}
    if field in special:
        return special[field]
    name = field[:-2] if field.endswith("_m") else field
    return "--" + name.replace("_", "-")


def rounded_to_ns(value):
    return value == round(value * 1e9) / 1e9


def close(a, b, rel=1e-6, abs_=2e-7):
    return math.isclose(a, b, rel_tol=rel, abs_tol=abs_)


class Case(unittest.TestCase):
    def setUp(self):
        self.s = Shared.get()
        self.tmp = Path(tempfile.mkdtemp(prefix="case-", dir=self.s.folder))

    def write_record(self, name, edit):
        record = json.loads(json.dumps(self.s.trial))
        edit(record["specification"]["trial"])
        path = self.tmp / name
        path.write_text(json.dumps(record, ensure_ascii=False))
        return path

    def check_spec(self, edit):
        path = self.write_record("r.json", edit)
        return run(["trial", "--spec", path, "--check"], self.tmp)

    def assert_refused(self, result, *names, status=2):
        lines = error_lines(result)
        self.assertEqual(result.returncode, status, lines)
        self.assertEqual(len(lines), 1, lines)
        for name in names:
            self.assertIn(name, lines[0])
        return lines[0]


# ------------------------------------------------------------------------- the schema and the options of trial
class SchemaAgainstOptions(Case):
    def setUp(self):
        super().setUp()
        self.help = help_options(out(run(["trial", "--help"], self.tmp)))
        self.fields = {r["field"].strip("`"): r for r in markdown_rows(self.s.markdown["specification"])}

    def test_trial_help_states_the_schema_default_and_range_of_every_field(self):
        # docs/cli.md: each option is the field of its name (dashed, a length's `_m` dropped); its help states
        # the field's range and default. The help's default must be the schema's, in the option's unit.
        words = {"true": "on", "false": "off", '""': "none"}
        for field, row in self.fields.items():
            option = option_of(field)
            if option is None or field in ("json_file", "csv_file", "svg_file", "record_file"):
                continue
            with self.subTest(field=field, option=option):
                self.assertIn(option, self.help)
                text = self.help[option]
                default = help_default(text)
                schema_default = row["default"].strip("`")
                if field == "watchdog_s":
                    self.assertEqual(float(default), float(schema_default) * 1000)
                    self.assertIn("[ms], 0..60000", text)  # docs/cli.md: "ms, 0..60000", whole ms as integers
                    continue
                if field == "writer":   # auto: "the device's own", which the help spells out
                    self.assertIn("auto", text)
                    continue
                if field == "writer_parameters":
                    self.assertEqual((schema_default, default), ("[]", "none"))
                    continue
                if re.fullmatch(r"-?[\d.e+-]+", schema_default):
                    self.assertEqual(float(default), float(schema_default), text)
                else:
                    self.assertEqual(default, words.get(schema_default, schema_default.strip('"')), text)
                if row["range"] and row["kind"] in ("number", "integer"):
                    self.assertIn(row["range"], text)

    def test_each_enumeration_is_spelt_by_the_help_as_by_the_schema(self):
        # `enum` in the JSON Schema is "the one spelling" (docs/cli.md, "schema"); the help lists the values.
        properties = self.s.schema["specification"]["properties"]
        enums = {k: v["enum"] for k, v in properties.items() if "enum" in v}
        self.assertTrue({"guidance_mode", "writer", "pacing", "realtime"} <= set(enums), enums)
        for field, values in enums.items():
            with self.subTest(field=field):
                listed = re.match(r"([\w-]+(\|[\w-]+)+)", self.help[option_of(field)])
                self.assertIsNotNone(listed, self.help[option_of(field)])
                self.assertEqual(listed.group(1).split("|"), values)

    def test_a_trial_with_its_defaults_records_the_schema_defaults(self):
        # "one trial specification is what runs and what is recorded": a trial given no option records every
        # field at its schema default; `auto` is recorded as what it chose (the device's own: the simulated
        # writer, lock-step), which `trial --spec` runs again.
        r = run(["trial", YI, "--max-duration", "20", "--json", "d.json"], self.tmp)
        self.assertTrue(ok(r), error_lines(r))
        stated = json.loads((self.tmp / "d.json").read_text())["specification"]["trial"]
        defaults = {k: v.get("default") for k, v in self.s.schema["specification"]["properties"].items()}
        for field, default in defaults.items():
            with self.subTest(field=field):
                expected = {"characters": YI, "max_duration_s": 20, "writer": "simulated",
                            "pacing": "lock-step"}.get(field, default)
                self.assertEqual(stated[field], expected)

    def test_watchdog_is_one_field_in_seconds_and_whole_milliseconds(self):
        # docs/cli.md: "The command line gives `watchdog_s` in whole milliseconds (`--watchdog-ms`)". The same
        # bound on both surfaces, the same refusal of a fraction of a millisecond, and the value recorded.
        base = ["trial", YI, "--pacing", "real-time", "--check"]
        self.assertTrue(ok(run(base + ["--watchdog-ms", "60000"], self.tmp)))
        self.assert_refused(run(base + ["--watchdog-ms", "60001"], self.tmp), "--watchdog-ms")
        self.assert_refused(run(base + ["--watchdog-ms", "20.5"], self.tmp), "--watchdog-ms")

        def at(value):
            def edit(t):
                t["pacing"], t["watchdog_s"] = "real-time", value
            return edit
        self.assertTrue(ok(self.check_spec(at(60))))
        self.assert_refused(self.check_spec(at(60.001)), "r.json", "/specification/trial")
        self.assert_refused(self.check_spec(at(0.0205)), "r.json", "watchdog_s")
        r = run(["trial", YI, "--pacing", "real-time", "--watchdog-ms", "20", "--max-duration", "0.05",
                 "--json", "w.json"], self.tmp)
        self.assertIn(r.returncode, (0, 1), error_lines(r))
        self.assertEqual(json.loads((self.tmp / "w.json").read_text())["specification"]["trial"]["watchdog_s"],
                         0.02)

    def test_whole_numbers_are_whole_on_every_surface(self):
        # hint_after_misses is an integer 0..1000 in the schema, and an int in Python (a float is a TypeError).
        self.assertEqual(self.fields["hint_after_misses"]["kind"], "integer")
        self.assert_refused(run(["trial", YI, "--hint-after-misses", "3.5", "--check"], self.tmp),
                            "--hint-after-misses")
        self.assert_refused(self.check_spec(lambda t: t.update(hint_after_misses=3.5)),
                            "/specification/trial/hint_after_misses")
        self.assertTrue(ok(run(["trial", YI, "--hint-after-misses", "1000", "--check"], self.tmp)))
        self.assert_refused(run(["trial", YI, "--hint-after-misses", "1001", "--check"], self.tmp),
                            "--hint-after-misses")
        if cg is None:
            return
        for fraction in (3.5, 7.0):
            with self.assertRaises(TypeError) as caught:
                cg.simulate_trial(YI, hint_after_misses=fraction, max_duration_s=0.01)
            self.assertIn("hint_after_misses", str(caught.exception))
        with self.assertRaises(cg.InvalidArgument):
            cg.simulate_trial(YI, hint_after_misses=1001, max_duration_s=0.01)
        self.assertIs(type(cg.StrokeAcceptance().hint_after_misses), int)
        recorded = cg.simulate_trial(YI, hint_after_misses=7, max_duration_s=0.01).metrics
        value = recorded["specification"]["trial"]["hint_after_misses"]
        self.assertEqual((value, type(value)), (7, int))

    @needs_python
    def test_python_keyword_defaults_are_the_schema_defaults(self):
        # simulate_trial and run_trial take the specification's fields by their names; their defaults are the
        # schema's (docs/python.md: "as `calligraphy trial` does").
        properties = self.s.schema["specification"]["properties"]
        for function in (cg.simulate_trial, cg.run_trial):
            signature = function.__doc__.splitlines()[0]
            with self.subTest(function=function.__name__):
                # simulate_trial's `device` is the simulated device's physics (docs/python.md), run_trial's a name.
                names = ("guidance", "rate_hz", "seed", "max_duration_s", "pacing")
                for field in names + (("device",) if function is cg.run_trial else ()):
                    m = re.search(rf"\b{field}: [^=,]+ = ([^,)]+)", signature)
                    if m is None:
                        continue
                    given = m.group(1).strip("'")
                    default = properties[field]["default"]
                    if isinstance(default, bool):
                        self.assertEqual(given, str(default), field)
                    elif isinstance(default, (int, float)):
                        self.assertEqual(float(given), float(default), field)
                    else:
                        self.assertEqual(given, default, field)
                # `writer` is Python's name of the profile: its default is writer_profile's.
                m = re.search(r"\bwriter: [^=]+ = '(\w+)'", signature)
                self.assertEqual(m.group(1), properties["writer_profile"]["default"])

    def test_schema_json_and_its_markdown_state_each_field_alike(self):
        # Both come from the one schema: default, range, unit and enumeration of each field the same.
        for kind in ("specification", "session"):
            properties = self.s.schema[kind]["properties"]
            for row in markdown_rows(self.s.markdown[kind]):
                field = row["field"].strip("`")
                p = properties[field]
                with self.subTest(kind=kind, field=field):
                    if "enum" in p:
                        self.assertEqual(row["range"].replace("\\|", "|").split("|"), p["enum"])
                        self.assertEqual(row["default"].strip("`"), p["default"])
                    if row["unit"]:
                        # "what it is, `[unit]`, the source of a formula" (docs/cli.md, "schema")
                        self.assertRegex(p["description"], rf"\[{re.escape(row['unit'])}\]( \(.*\))?$")
                    low, high = p.get("minimum", p.get("exclusiveMinimum")), p.get("maximum",
                                                                                    p.get("exclusiveMaximum"))
                    if row["kind"] == "number" and low is not None and high is not None:
                        m = re.match(r"in ([\[(])(\S+), (\S+?)([\])])", row["range"])
                        self.assertIsNotNone(m, row["range"])
                        self.assertEqual(float(m.group(2)), low)
                        self.assertEqual(float(m.group(3)), high)
                        self.assertEqual(m.group(1) == "(", "exclusiveMinimum" in p)
                        self.assertEqual(m.group(4) == ")", "exclusiveMaximum" in p)
                    if row["kind"] in ("number", "integer") and "default" in p and row["default"]:
                        self.assertEqual(float(row["default"].strip("`")), float(p["default"]))

    def test_every_option_of_every_command_states_at_most_one_default(self):
        # docs/cli.md, "Help and version": each option's default "once: '(default: ...)' at the end of its line".
        commands = [[c] for c in ("trial", "train", "score", "model", "strokes", "schema", "characters", "trace",
                                  "devices", "report", "curriculum")]
        for group in ("corpus", "bench", "session"):
            text = out(run([group, "--help"], self.tmp))
            section = text.split("Subcommands:", 1)[1] if "Subcommands:" in text else ""
            commands += [[group, m] for m in re.findall(r"^\s{2}(\w[\w-]*)\s", section, re.M)]
        self.assertGreater(len(commands), 15)
        for command in commands:
            r = run([*command, "--help"], self.tmp)
            with self.subTest(command=" ".join(command)):
                self.assertTrue(ok(r), error_lines(r))
                for option, text in help_options(out(r)).items():
                    self.assertLessEqual(text.count("(default:"), 1, (option, text))
                    self.assertLessEqual(text.count("default:"), 1, (option, text))


# ------------------------------------------------------------------------------------------ enumeration spellings
class Spellings(Case):
    def test_underscored_guidance_modes_are_one_spelling_everywhere(self):
        # The schema's spelling is `assist-as-needed`; `assist_as_needed` (the C++ enumerator's) is refused by
        # the option, a record and a protocol, each naming where. Python reads the old spelling for one version
        # with a DeprecationWarning naming the one spelling (docs/python.md says so), and what it records is
        # the one spelling, which `trial --spec` takes back.
        for old, new in (("assist_as_needed", "assist-as-needed"), ("error_amplification", "error-amplification")):
            with self.subTest(spelling=old):
                line = self.assert_refused(run(["trial", YI, "--guidance-mode", old, "--check"], self.tmp),
                                           "--guidance-mode", old)
                self.assertIn(new, line)
                self.assert_refused(self.check_spec(lambda t, old=old: t.update(guidance_mode=old)),
                                    "/specification/trial/guidance_mode", new)
                protocol = dict(PROTOCOL, conditions=[{"name": "h", "mode": old}, PROTOCOL["conditions"][1]])
                path = self.tmp / "p.json"
                path.write_text(json.dumps(protocol, ensure_ascii=False))
                self.assert_refused(run(["session", "plan", path, "--subjects", "1"], self.tmp),
                                    "/conditions/0/mode")
                if cg is None:
                    continue
                with warnings.catch_warnings(record=True) as caught:
                    warnings.simplefilter("always")
                    r = cg.simulate_trial(YI, guidance_mode=old, max_duration_s=0.05)
                self.assertTrue(any(issubclass(w.category, DeprecationWarning) and new in str(w.message)
                                    for w in caught), [str(w.message) for w in caught])
                spec = r.metrics["specification"]
                self.assertEqual(spec["trial"]["guidance_mode"], new)
                (self.tmp / "py.json").write_text(json.dumps(r.metrics, ensure_ascii=False))
                self.assertTrue(ok(run(["trial", "--spec", "py.json", "--check"], self.tmp)))
        docs = (SOURCE / "docs" / "python.md").read_text()
        self.assertIn("assist_as_needed", docs, "docs/python.md does not say Python reads the old spelling")

    def test_pacing_is_spelt_with_dashes_on_every_surface(self):
        self.assert_refused(run(["trial", YI, "--pacing", "lock_step", "--check"], self.tmp), "--pacing")
        self.assert_refused(self.check_spec(lambda t: t.update(pacing="lock_step")),
                            "/specification/trial/pacing")
        self.assert_refused(run(["session", "run", Shared.folder / "p.json", "--subjects", "1", "--writer",
                                 "simulated", "--pacing", "lock_step", "--out", "x"], self.tmp), "--pacing")
        self.assertFalse((self.tmp / "x").exists())
        if cg is not None:
            with self.assertRaises(cg.InvalidArgument) as caught:
                cg.run_trial(YI, pacing="lock_step", max_duration_s=0.01)
            self.assertIn("lock-step", str(caught.exception))

    def test_the_mode_tables_of_the_docs_spell_modes_as_the_program_takes_them(self):
        # docs/force-rendering.md's table of guidance modes names each mode; a reader copies the name into
        # `--guidance-mode` or a record.
        modes = self.s.schema["specification"]["properties"]["guidance_mode"]["enum"]
        text = (SOURCE / "docs" / "force-rendering.md").read_text()
        rows = [r for r in markdown_rows(text) if "mode" in r and "attraction point" in r]
        self.assertGreaterEqual(len(rows), len(modes))
        named = [re.match(r"`([^`]+)`", r["mode"]).group(1) for r in rows]
        self.assertEqual(sorted(named), sorted(modes))

    def test_a_writer_profile_is_one_of_three_on_every_surface(self):
        # `--writer-profile novice|skilled|foreign`; the schema's field says "novice, skilled or foreign". A
        # record naming no profile (or a profile misspelt) must not run where the option and Python refuse it.
        for bad in ("expert", "Novice"):
            with self.subTest(profile=bad):
                self.assert_refused(run(["trial", YI, "--writer-profile", bad, "--check"], self.tmp),
                                    "--writer-profile")
                self.assert_refused(run(["session", "run", Shared.folder / "p.json", "--subjects", "1",
                                         "--writer-profile", bad, "--out", "x"], self.tmp), "--writer-profile")
                self.assert_refused(self.check_spec(lambda t, bad=bad: t.update(writer_profile=bad)),
                                    "r.json", "/specification/trial", "writer_profile", bad)
                if cg is not None:
                    with self.assertRaises(cg.InvalidArgument):
                        cg.simulate_trial(YI, writer=bad, max_duration_s=0.01)

    def test_who_writes_is_one_vocabulary_in_the_session(self):
        # docs/cli.md: --writer is `person` or `simulated`; session.json keeps a person as `human`, and
        # `session run --writer human` points to `--writer person`. The simulated subject is `simulated` in
        # session.json, each record's `writer.kind` and trials.csv; its profile and learning are what the help
        # gives as defaults.
        line = self.assert_refused(run(["session", "run", Shared.folder / "p.json", "--subject", "P01",
                                        "--writer", "human", "--out", "x"], self.tmp), "--writer")
        self.assertIn("--writer person", line)
        help_text = help_options(out(run(["session", "run", "--help"], self.tmp)))
        learning = help_default(help_text["--writer-learning"])
        differences = help_default(help_text["--individual-differences"])
        m = self.s.manifest
        self.assertEqual((m["writer"], m["writer_profile"], m["writer_learning"]), ("simulated", "novice", learning))
        self.assertEqual(m["individual_differences"], differences == "on")
        for name, record in self.s.records.items():
            self.assertEqual(record["writer"]["kind"], "simulated", name)
        for row in self.s.trials_csv:
            self.assertEqual((row["writer"], row["writer_profile"], row["writer_learning"]),
                             ("simulated", "novice", learning))

    def test_what_a_session_records_runs_again_as_it_is_named(self):
        # Each saved record's specification is taken back by `trial --spec --check`, and its enumerations are
        # the schema's spellings; a protocol's `haptic` is the trial's `fixed` guidance.
        enums = {k: v["enum"] for k, v in self.s.schema["specification"]["properties"].items() if "enum" in v}
        for name, record in self.s.records.items():
            with self.subTest(record=name):
                trial = record["specification"]["trial"]
                for field, values in enums.items():
                    self.assertIn(trial[field], values, field)
                r = run(["trial", "--spec", self.s.session_dir / "trials" / name, "--check"], self.tmp)
                self.assertTrue(ok(r), error_lines(r))
                if record["condition"] == "h":
                    self.assertEqual((record["mode"], trial["guidance"], trial["guidance_mode"]),
                                     ("haptic", True, "fixed"))

    def test_end_reasons_are_spelt_alike_by_trial_python_and_a_session(self):
        short = dict(PROTOCOL, name="short", trial={"max_duration_s": 0.3},
                     test={"characters": [YI], "conditions": ["h"], "repetitions": 1})
        (self.tmp / "short.json").write_text(json.dumps(short, ensure_ascii=False))
        r = run(["session", "run", "short.json", "--writer", "simulated", "--subjects", "1", "--out", "st"],
                self.tmp)
        self.assertIn(r.returncode, (0, 1), error_lines(r))
        (self.tmp / "tb").mkdir()
        r = run(["report", "st", "--csv", "tb"], self.tmp)
        self.assertTrue(ok(r), error_lines(r))
        rows = list(csv.DictReader(open(self.tmp / "tb" / "trials.csv", encoding="utf-8")))
        self.assertEqual([row["end_reason"] for row in rows], ["time_limit"])
        r = run(["trial", YI, "--max-duration", "0.3", "--json", "-"], self.tmp)
        self.assertEqual(r.returncode, 1)
        self.assertEqual(json.loads(out(r))["end_reason"], "time_limit")
        if cg is not None:
            self.assertEqual(cg.simulate_trial(YI, max_duration_s=0.3).metrics["end_reason"], "time_limit")
        for name, record in self.s.records.items():
            self.assertIn(record["end_reason"], END_REASONS, name)
        # docs/python.md lists the same outcomes as docs/cli.md.
        python_md = (SOURCE / "docs" / "python.md").read_text()
        listed = re.search(r'metrics\["end_reason"\]\s*#\s*([\w, ]+)', python_md).group(1)
        self.assertEqual({w.strip() for w in listed.split(",")}, END_REASONS)

    def test_a_pen_down_that_never_reached_the_stroke_due_has_no_distance_from_it(self):
        # docs/metrics.md: a segment's verdict gives "the refused or accepted pen-down's mean distance from the
        # stroke due as `mean_deviation_m`"; docs/cli.md: "A value that does not exist is `null` (`-` in the
        # table), never 0". 十 written 30 mm to the right never comes near the start of a stroke: no distance
        # was measured, so none is given, in the JSON, Python or the table ("0.0 mm off" would be false).
        rows = list(csv.DictReader(open(self.s.folder / "t.csv", encoding="utf-8")))
        lines = [",".join(rows[0].keys())]
        for row in rows:
            lines.append(",".join(dict(row, x=repr(float(row["x"]) + 0.03)).values()))
        (self.tmp / "shifted.csv").write_text("\n".join(lines) + "\n")
        r = run(["score", "shifted.csv", "--character", SHI, "--json", "-"], self.tmp)
        self.assertTrue(ok(r), error_lines(r))
        results = [json.loads(out(r))]
        if cg is not None:
            results.append(cg.score(str(self.tmp / "shifted.csv"), SHI))
        for result in results:
            verdicts = [s["verdict"] for s in result["per_character"][0]["segments"] if s["verdict"]]
            self.assertTrue(verdicts)
            for v in verdicts:
                self.assertEqual((v["accepted"], v["refusal"]), (False, "wrong_place"))
                self.assertIsNone(v["mean_deviation_m"], v)
        table = out(run(["score", "shifted.csv", "--character", SHI], self.tmp))
        self.assertIn("refused: wrong place", table)
        self.assertNotIn("0.0 mm off", table)

    def test_refusals_are_spelt_alike_by_score_python_and_the_quiz(self):
        # A trace of 十 written with its two strokes swapped: the first pen-down is refused as `wrong_order`.
        rows = list(csv.DictReader(open(self.s.folder / "t.csv", encoding="utf-8")))
        swapped = [r for r in rows if r["stroke"] == "1"] + [r for r in rows if r["stroke"] == "0"]
        lines = [",".join(rows[0].keys())]
        for i, row in enumerate(swapped):
            lines.append(",".join(dict(row, t=f"{i / 1000:.3f}").values()))
        (self.tmp / "swapped.csv").write_text("\n".join(lines) + "\n")
        r = run(["score", "swapped.csv", "--character", SHI, "--json", "-"], self.tmp)
        self.assertTrue(ok(r), error_lines(r))
        results = [json.loads(out(r))]
        if cg is not None:
            results.append(cg.score(str(self.tmp / "swapped.csv"), SHI))
        for result in results:
            self.assertEqual(set(result["refusals"]), REFUSALS)
            self.assertEqual(result["refusals"]["wrong_order"], 1)
            verdicts = [s["verdict"] for s in result["per_character"][0]["segments"] if s["verdict"]]
            self.assertEqual({v["refusal"] for v in verdicts}, {"none", "wrong_order"})
            refused = [v for v in verdicts if not v["accepted"]][0]
            self.assertEqual((refused["expected_stroke"], refused["matched_stroke"]), (0, 1))
        if len(results) == 2:
            self.assertEqual(results[0]["refusals"], results[1]["refusals"])
        for name, record in self.s.records.items():
            for character in (record.get("quiz") or {}).get("characters", []):
                for event in character.get("events", []):
                    if "refusal" in event:
                        self.assertIn(event["refusal"], REFUSALS | {"none"}, name)
        for row in self.s.strokes_csv:
            self.assertIn(row["refusal"], REFUSALS | {""})


# ------------------------------------------------------------------------------------------------ the metric table
class MetricTable(Case):
    def setUp(self):
        super().setUp()
        self.rows = markdown_rows(self.s.markdown["metrics"])
        self.by_name = {r["metric"].strip("`"): r for r in self.rows}

    def test_the_metrics_schema_keys_are_in_every_metrics_record_with_their_types(self):
        schema = self.s.schema["metrics"]
        records = {"trial --json": self.s.trial, "score --json": self.s.score}
        records.update({f"trials/{k}": v for k, v in self.s.records.items()})
        if cg is not None:
            records["cg.score"] = cg.score(str(self.s.folder / "t.csv"), SHI)
            records["simulate_trial"] = cg.simulate_trial(SHI, seed=1, max_duration_s=20).metrics
        types = {"integer": int, "boolean": bool}
        for where, record in records.items():
            for key in schema["required"]:
                with self.subTest(record=where, key=key):
                    self.assertIn(key, record)
                    declared = schema["properties"][key]["type"]
                    value = record[key]
                    if isinstance(declared, str) and declared in types:
                        self.assertIs(type(value), types[declared])
                    else:
                        self.assertTrue(value is None or type(value) is float, value)

    def test_each_metric_is_at_the_levels_the_table_gives_and_only_there(self):
        levels = {name: {x.strip() for x in row["levels"].split(",")} for name, row in self.by_name.items()}
        where = {"scene": [self.s.score, self.s.trial], "character": [self.s.score["per_character"][0]],
                 "stroke": self.s.score["per_character"][0]["per_stroke"], "run": [self.s.trial]}
        for name, at in levels.items():
            for level, objects in where.items():
                for obj in objects:
                    with self.subTest(metric=name, level=level):
                        if level in at:
                            self.assertIn(name, obj)
                        elif not ({"scene", "run"} & at and obj is self.s.trial):
                            self.assertNotIn(name, obj)
        # The run's figures are the renderer's: not in what `score` gives.
        for name in (n for n, at in levels.items() if at == {"run"}):
            self.assertNotIn(name, self.s.score)

    def test_the_keys_docs_metrics_names_from_the_assignment_are_the_records_keys(self):
        # docs/metrics.md, "Matching written strokes to the character": "From the assignment: `strokes_written`
        # ..., `missing_strokes` ..." names keys of each character's record; each must be one.
        text = (SOURCE / "docs" / "metrics.md").read_text()
        paragraph = text[text.index("From the assignment:"):].split("\n\n", 1)[0]
        names = re.findall(r"`([a-z_]+)`", paragraph)
        self.assertGreaterEqual(len(names), 6, paragraph)
        character = self.s.score["per_character"][0]
        for name in names:
            self.assertIn(name, character, paragraph)

    @needs_python
    def test_pythons_metric_table_is_the_printed_table(self):
        table = cg.metric_table()
        self.assertEqual([m["name"] for m in table], list(self.by_name))
        for m in table:
            row = self.by_name[m["name"]]
            with self.subTest(metric=m["name"]):
                self.assertEqual(m["kind"], row["kind"])
                self.assertEqual(m["levels"], row["levels"])
                self.assertEqual(m["doc"], row["what it is"])
                self.assertEqual(m["legacy_name"], row["before"].strip("`"))
                definition = m["definition"] + (f" ({m['source']})" if m["source"] else "")
                self.assertEqual(definition.replace("|", "\\|"), row["how it is computed"])
                # The unit as docs/metrics.md prints it: `-` for a count or flag, `1` for a dimensionless number.
                unit = m["unit"] or {"count": "-", "flag": "-", "number": "1"}[m["kind"]]
                self.assertEqual(unit, row["unit"])
        text = (SOURCE / "docs" / "metrics.md").read_text()
        self.assertRegex(text, r"metric_table\(\)[^.]*`unit`[^.]*empty", "docs/metrics.md does not say how "
                         "metric_table() gives the unit of a count, a flag and a dimensionless number")

    def test_the_metrics_schema_gives_each_metric_its_table_unit_and_kind(self):
        properties = self.s.schema["metrics"]["properties"]
        kinds = {"count": "integer", "flag": "boolean", "number": ["number", "null"]}
        for name, p in properties.items():
            row = self.by_name[name]
            with self.subTest(metric=name):
                self.assertIn("scene", row["levels"])
                self.assertEqual(p["type"], kinds[row["kind"]])
                if row["unit"] not in ("-", "1"):
                    self.assertTrue(p["description"].endswith(f"[{row['unit']}]"), p["description"])
                else:
                    self.assertNotRegex(p["description"], r"\[[^\]]*\]$")
                self.assertTrue(p["description"].startswith(row["what it is"]))
        scene = [n for n, r in self.by_name.items() if "scene" in r["levels"]]
        self.assertEqual(sorted(properties), sorted(scene))

    def test_the_study_tables_metric_columns_follow_the_table(self):
        if cg is not None:
            table = cg.metric_table()
            trials = [m["name"] for m in sorted((m for m in table if m["trials_column"]),
                                                key=lambda m: m["trials_column"])]
            strokes = [m["name"] for m in sorted((m for m in table if m["strokes_column"]),
                                                 key=lambda m: m["strokes_column"])]
        else:  # the documented order (docs/experiments.md)
            trials, strokes = None, None
        header = self.s.trials_header
        start, end = header.index("completed_in_order"), header.index("normalised_jerk")
        if trials is not None:
            self.assertEqual(header[start:end + 1], trials)
        for name in header[start:end + 1]:
            self.assertIn(name, self.by_name)
        start, end = self.s.strokes_header.index("mean_deviation_m"), self.s.strokes_header.index("assisted")
        if strokes is not None:
            self.assertEqual(self.s.strokes_header[start:end + 1], strokes)
        for name in self.s.strokes_header[start:end + 1]:
            self.assertIn(name, self.by_name)
        if cg is not None:
            study = calligraphy.study.load(str(self.s.folder / "study"))
            self.assertEqual(list(study.trials.columns)[:len(header)], header)
            self.assertEqual(list(study.strokes.columns)[:len(self.s.strokes_header)], self.s.strokes_header)


# ------------------------------------------------------------------------------ one trial through every surface
class OneTrial(Case):
    def first_trial(self):
        name = next(n for n in self.s.records if n.startswith("001-"))
        return name, self.s.records[name], self.s.session_dir / "trials" / name.replace(".json", ".trace.h5")

    def test_one_deviation_in_every_surface(self):
        name, record, trace = self.first_trial()
        value = record["mean_deviation_m"]
        row = next(r for r in self.s.trials_csv if r["trial"] == "1")
        self.assertEqual(float(row["mean_deviation_m"]), value)
        r = run(["score", trace, "--character", record["characters"], "--json", "-"], self.tmp)
        self.assertTrue(ok(r), error_lines(r))
        self.assertTrue(close(json.loads(out(r))["mean_deviation_m"], value))
        r = run(["score", trace, "--character", record["characters"]], self.tmp)
        shown = float(re.search(r"mean deviation\s+([\d.]+) mm", out(r)).group(1))
        self.assertAlmostEqual(shown, value * 1000, delta=0.0005 + 1e-9)
        article = self.s.page.split(f'id="trial-{self.s.session_dir.name}-1"', 1)[1].split("</article>")[0]
        page_mm = float(re.search(r"deviation ([\d.]+) mm", article).group(1))
        self.assertAlmostEqual(page_mm, value * 1000, delta=0.005 + 1e-9)
        page_s = float(re.search(r"([\d.]+) s &middot;", article).group(1))
        self.assertAlmostEqual(page_s, record["total_time_s"], delta=0.05 + 1e-9)
        if cg is not None:
            self.assertTrue(close(cg.score(str(trace), record["characters"])["mean_deviation_m"], value))
            study = calligraphy.study.load(str(self.s.folder / "study"))
            self.assertEqual(float(study.trials[study.trials.trial == 1].mean_deviation_m.iloc[0]), value)

    def test_one_stroke_named_alike_in_every_surface(self):
        # The second stroke of 十 (its vertical, typical stroke 2, S): index 1 in JSON and Python, stroke 2 in the
        # tables people read and in the study tables (docs/experiments.md, "Indices count from 1 everywhere a
        # study shows them").
        name, record, trace = self.first_trial()
        stroke = record["per_character"][0]["per_stroke"][1]
        self.assertEqual((stroke["index"], stroke["typical_id"]), (1, 2))
        row = next(r for r in self.s.strokes_csv if r["trial"] == "1" and r["stroke"] == "2")
        self.assertEqual((row["character"], row["character_text"], row["typical_id"]), ("1", SHI, "2"))
        for key in ("mean_deviation_m", "max_deviation_m", "rms_deviation_m", "frechet_m", "dtw_m", "time_s",
                    "path_length_m"):
            self.assertEqual(float(row[key]), stroke[key], key)
        scored = json.loads(out(run(["score", trace, "--character", SHI, "--json", "-"], self.tmp)))
        again = scored["per_character"][0]["per_stroke"][1]
        self.assertEqual(again["index"], 1)
        self.assertTrue(close(again["mean_deviation_m"], stroke["mean_deviation_m"]))
        table = out(run(["score", trace, "--character", SHI], self.tmp))
        line = re.search(r"^\s*2\s+S\s+2\s+([\d.]+)\s+([\d.]+)", table, re.M)
        self.assertIsNotNone(line, table)
        self.assertAlmostEqual(float(line.group(1)), stroke["mean_deviation_m"] * 1000, delta=0.005 + 1e-9)
        model = out(run(["model", SHI], self.tmp))
        self.assertRegex(model, r"stroke 2: ID 2 S ")
        strokes = json.loads(out(run(["model", SHI, "--json"], self.tmp)))["strokes"]
        self.assertEqual((strokes[1]["typical_id"], strokes[1]["acronym"]), (2, "S"))
        run(["model", SHI, "--svg", "m.svg"], self.tmp)
        numbers = re.findall(r'class="stroke-number"[^>]*>(\d+)<', (self.tmp / "m.svg").read_text())
        self.assertEqual(numbers, ["1", "2"])
        if cg is not None:
            study = calligraphy.study.load(str(self.s.folder / "study"))
            s = study.strokes
            picked = s[(s.trial == 1) & (s.stroke == 2)]
            self.assertEqual(len(picked), 1)
            self.assertEqual(float(picked.mean_deviation_m.iloc[0]), stroke["mean_deviation_m"])

    def test_the_command_line_tables_number_strokes_from_one_and_the_json_from_zero(self):
        for text, record in ((self.s.trial_text, self.s.trial), (self.s.score_text, self.s.score)):
            self.assertIn("strokes numbered from 1 here, from 0 in the JSON", text)
            numbers = re.findall(r"^\s{2}(\d+)\s+\S", text.split("stroke", 1)[1], re.M)
            self.assertEqual(numbers[:2], ["1", "2"])
            self.assertEqual([p["index"] for p in record["per_character"][0]["per_stroke"]], [0, 1])
        self.assertEqual([p["index"] for p in self.s.trial["renderer_strokes"]], [0, 1])
        ids = [p["typical_id"] for p in self.s.trial["per_character"][0]["per_stroke"]]
        self.assertEqual([p["typical_id"] for p in self.s.trial["renderer_strokes"]], ids)
        self.assertEqual([p["typical_id"] for p in self.s.score["per_character"][0]["per_stroke"]], ids)
        if cg is not None:
            frame = cg.simulate_trial(SHI, seed=1, max_duration_s=20).per_stroke_dataframe()
            self.assertEqual(list(frame.index), [0, 1])
            self.assertEqual(list(frame.typical_id), ids)

    def test_the_study_numbers_trials_blocks_and_items_alike(self):
        # session.json's plan, each record's `trial`, trials.csv, the file stems and the page's anchors: 1-based.
        plan = self.s.manifest["plan"]
        self.assertEqual([p["index"] for p in plan], [1, 2, 3, 4])
        rows = {int(r["trial"]): r for r in self.s.trials_csv}
        for p in plan:
            with self.subTest(trial=p["index"]):
                stem = p["file"]
                self.assertTrue(stem.startswith(f"{p['index']:03d}-"), stem)
                self.assertIn(f"-r{p['repetition']}-", stem)
                record = self.s.records[stem + ".json"]
                for key in ("index", "block", "item", "repetition"):
                    self.assertEqual(record["trial"][key], p[key], key)
                row = rows[p["index"]]
                for key in ("block", "item", "repetition"):
                    self.assertEqual(int(row[key]), p[key], key)
                self.assertIn(f'id="trial-{self.s.session_dir.name}-{p["index"]}"', self.s.page)
        self.assertEqual(sorted({p["block"] for p in plan}), [1, 2])
        self.assertEqual(sorted({p["item"] for p in plan}), [1, 2])

    def test_a_cohort_in_memory_gives_the_tables_of_the_session(self):
        # `session cohort --help`: "no session folders; the same trials as session run". Its tables have the
        # report's columns and, for the same subject of the same protocol, the same values in every column but
        # those that name a folder, a file or a wall-clock time.
        (self.tmp / "co").mkdir()
        r = run(["session", "cohort", Shared.folder / "p.json", "--subjects", "1", "--csv", "co"], self.tmp)
        self.assertTrue(ok(r), error_lines(r))
        for table, rows in (("trials.csv", self.s.trials_csv), ("strokes.csv", self.s.strokes_csv)):
            text = (self.tmp / "co" / table).read_text()
            self.assertEqual(text.splitlines()[0], (Shared.folder / "tables" / table).read_text().splitlines()[0])
            cohort = list(csv.DictReader(io.StringIO(text)))
            self.assertEqual(len(cohort), len(rows), table)
            for mine, theirs in zip(cohort, rows):
                differing = {k for k in mine if mine[k] != theirs[k]}
                self.assertLessEqual(differing, {"session", "start_utc", "trace_file", "trace_sha256"},
                                     (table, {k: (mine[k], theirs[k]) for k in differing}))

    def test_times_are_rounded_to_whole_nanoseconds_on_every_surface(self):
        # docs/metrics.md: "The times (writing, in-air, total, ...) are rounded to whole nanoseconds ... rounded,
        # n ticks of 1 ms read n ms". A stroke's writing time `time_s` (t_(N-1) - t_0) is such a time.
        found = []
        records = [self.s.trial, self.s.score, *self.s.records.values()]
        for record in records:
            for character in record["per_character"]:
                for key in ("total_time_s", "pen_down_time_s", "in_air_time_s"):
                    if character.get(key) is not None:
                        found.append((key, character[key]))
                for stroke in character["per_stroke"]:
                    if stroke.get("time_s") is not None:
                        found.append(("per_stroke/time_s", stroke["time_s"]))
        found += [("strokes.csv time_s", float(r["time_s"])) for r in self.s.strokes_csv if r["time_s"]]
        self.assertGreater(len(found), 20)
        wrong = [(k, v) for k, v in found if not rounded_to_ns(v)]
        self.assertEqual(wrong, [])

    def test_trial_and_score_name_the_times_of_one_trace_alike(self):
        # The same trace: `trial`'s summary and `score`'s name the total time (first to last pen-down sample)
        # and the pen-down time alike, in the same words; "writing time" is the pen-down time (docs/metrics.md),
        # never the total.
        total, down = self.s.trial["total_time_s"], self.s.trial["pen_down_time_s"]
        self.assertEqual((self.s.score["total_time_s"], self.s.score["pen_down_time_s"]), (total, down))
        for text in (self.s.trial_text, self.s.score_text):
            with self.subTest(text=text.splitlines()[0]):
                line = re.search(r"^\s*time\s+([\d.]+) s \(pen down ([\d.]+) s", text, re.M)
                self.assertIsNotNone(line, text)
                self.assertAlmostEqual(float(line.group(1)), total, delta=0.005 + 1e-9)
                self.assertAlmostEqual(float(line.group(2)), down, delta=0.005 + 1e-9)
                self.assertNotRegex(text, rf"writing(?: time)?\s+{total:.2f} s")

    def test_the_table_millimetres_are_the_record_metres(self):
        # Lengths are metres in files and millimetres only in text for people, labelled (docs/metrics.md).
        for text, record in ((self.s.trial_text, self.s.trial), (self.s.score_text, self.s.score)):
            for label, key in (("mean deviation", "mean_deviation_m"), ("max deviation", "max_deviation_m"),
                               ("DTW \\(mean\\)", "dtw_m"), ("Frechet \\(worst stroke\\)", "frechet_m")):
                m = re.search(rf"{label}\s+([\d.]+) mm", text)
                self.assertIsNotNone(m, (label, text))
                self.assertAlmostEqual(float(m.group(1)), record[key] * 1000, delta=0.0005 + 1e-9)
            rows = re.findall(r"^\s{2}(\d+)\s+(?:\S+\s+)?[A-Z]+\s+\d+\s+([\d.]+)\s+([\d.]+)\s+([\d.]+)\s+([\d.]+)"
                              r"\s+([\d.]+)", text, re.M)
            self.assertEqual(len(rows), 2, text)
            for (number, mean, peak, frechet, dtw, seconds), stroke in zip(rows,
                                                                           record["per_character"][0]["per_stroke"]):
                self.assertEqual(int(number), stroke["index"] + 1)
                for shown, key in ((mean, "mean_deviation_m"), (peak, "max_deviation_m"),
                                   (frechet, "frechet_m"), (dtw, "dtw_m")):
                    self.assertAlmostEqual(float(shown), stroke[key] * 1000, delta=0.005 + 1e-9)
                self.assertAlmostEqual(float(seconds), stroke["time_s"], delta=0.005 + 1e-9)


# ------------------------------------------------------------------------------------- trace columns and units
class TraceAndUnits(Case):
    def test_the_trace_columns_are_named_alike_by_help_docs_files_and_python(self):
        header = (self.s.folder / "t.csv").read_text().splitlines()[0]
        help_text = help_options(out(run(["trial", "--help"], self.tmp)))["--csv"]
        self.assertIn(f"({header}; s, m, N)", help_text)
        for doc in ("cli.md", "experiments.md"):
            self.assertIn(header, (SOURCE / "docs" / doc).read_text())
        name, _, trace = OneTrial.first_trial(self)
        self.assertEqual(out(run(["trace", trace], self.tmp)).splitlines()[0], header)
        if cg is not None:
            columns = cg.trace_columns()
            self.assertEqual(",".join(c["file_name"] for c in columns), header)
            frame = cg.simulate_trial(YI, max_duration_s=0.01).to_dataframe()
            self.assertEqual(list(frame.columns), [c["name"] for c in columns])
            for c in columns:
                if c["unit"]:
                    self.assertTrue(c["name"].endswith("_" + c["unit"].lower()), c)

    def test_a_devices_limits_are_one_object_in_devices_records_and_python(self):
        # `calligraphy devices --json` gives each device's `info` (its limits in SI units); a trial record's
        # `device.info` is "every DeviceInfo field in SI units" (docs/experiments.md), and Python's
        # `list_devices()` is the same listing (docs/cli.md). One device, one set of names and values.
        listing = json.loads(out(run(["devices", "--json"], self.tmp)))
        info = next(d for d in listing["devices"] if d["name"] == "simulated")["info"]
        name, record, _ = OneTrial.first_trial(self)
        self.assertEqual(record["device"]["name"], "simulated")
        self.assertEqual(info, record["device"]["info"])
        if cg is not None:
            python = next(d for d in cg.list_devices().devices if d.name == "simulated").info.to_dict()
            self.assertEqual(json.loads(json.dumps(python)), info)

    def test_a_typical_stroke_is_named_alike_by_strokes_model_and_python(self):
        # `strokes --json`, `model --json` and Python's TYPICAL_STROKES (docs/python.md: `name` is `name_zh`
        # there) give each of the 39 strokes one id, acronym, name, pinyin and code point; the JSON writes the
        # code point as U+XXXX, Python the character itself.
        table = json.loads(out(run(["strokes", "--json"], self.tmp)))
        self.assertEqual([t["id"] for t in table], list(range(1, 40)))
        by_id = {t["id"]: t for t in table}
        model = json.loads(out(run(["model", SHI, "--json"], self.tmp)))
        for stroke in model["strokes"]:
            t = by_id[stroke["typical_id"]]
            self.assertEqual((stroke["acronym"], stroke["name"], stroke["pinyin"], stroke["unicode"]),
                             (t["acronym"], t["name"], t["pinyin"], t["unicode"]))
        if cg is None:
            return
        self.assertEqual(len(cg.TYPICAL_STROKES), 39)
        for p in cg.TYPICAL_STROKES:
            t = by_id[p.id]
            with self.subTest(id=p.id):
                self.assertEqual((p.acronym, p.name_zh, p.pinyin, p.compound),
                                 (t["acronym"], t["name"], t["pinyin"], t["compound"]))
                self.assertEqual(f"U+{ord(p.unicode):04X}" if p.unicode else None,
                                 t["unicode"] if t["unicode"] not in ("", "-") else None)
                self.assertEqual(cg.typical_stroke(p.acronym).id, p.id)

    def test_score_takes_the_units_docs_metrics_spells(self):
        # docs/metrics.md, "Trace CSV": "Units of `x`, `y`: ..." names the values of `score --units` and of
        # Python's `units=`.
        text = (SOURCE / "docs" / "metrics.md").read_text()
        sentence = re.search(r"Units of `x`, `y`: (.*?)\.", text, re.S).group(1)
        spelled = re.findall(r"`(\w+)` \(", sentence)
        self.assertEqual(len(spelled), 2, sentence)
        help_text = help_options(out(run(["score", "--help"], self.tmp)))["--units"]
        listed = help_text.split()[0].split("|")
        self.assertEqual(spelled, listed)
        for units in spelled:
            r = run(["score", self.s.folder / "t.csv", "--character", SHI, "--units", units, "--json", "-"],
                    self.tmp)
            self.assertTrue(ok(r), error_lines(r))
            self.assertEqual(json.loads(out(r))["units"], units)
            if cg is not None:
                self.assertEqual(cg.score(str(self.s.folder / "t.csv"), SHI, units=units)["units"], units)

    @needs_python
    def test_pythons_score_states_the_stroke_numbering_it_gives(self):
        # docs/python.md: "Stroke numbers count from 0 (`matched_stroke` indexes `Scene(...).characters[0]
        # .strokes`)"; help(calligraphy.score) must say the same of the dict it returns.
        result = cg.score(str(self.s.folder / "t.csv"), SHI)
        strokes = result["per_character"][0]["per_stroke"]
        self.assertEqual([s["index"] for s in strokes], [0, 1])
        matched = [s["matched_stroke"] for s in result["per_character"][0]["segments"]
                   if s["matched_stroke"] is not None]
        self.assertEqual(sorted(matched), [0, 1])
        doc = cg.score.__doc__
        self.assertNotRegex(doc, r"1-based", doc)
        self.assertRegex(doc, r"0-based|from 0", doc)


SANITIZED_CASES = {
    "test_each_enumeration_is_spelt_by_the_help_as_by_the_schema",
    "test_watchdog_is_one_field_in_seconds_and_whole_milliseconds",
    "test_pacing_is_spelt_with_dashes_on_every_surface",
    "test_the_study_numbers_trials_blocks_and_items_alike",
    "test_the_trace_columns_are_named_alike_by_help_docs_files_and_python",
}
load_tests = sanitized_subset(SANITIZED_CASES)


if __name__ == "__main__":
    unittest.main(verbosity=2)
