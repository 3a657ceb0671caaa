#!/usr/bin/env python3
"""One vocabulary across every reader of a trial: what `calligraphy schema specification` states of each field
(its range, its enumeration's spellings) and what the trace column table states (`calligraphy.trace_columns()`,
include/calligraphy/report/trace_columns.hpp) hold identically for a record re-run by `trial --spec`, for the
command line's typed options and for Python.

(a) Every bounded field is taken at each closed bound and refused just past each bound (the next double, the
    next integer, an open bound itself) by `trial --spec RECORD --check` (refused: exit 2, one line naming the
    file and the JSON pointer), by its option (`trial CHARS --OPTION V --check`; refused: exit 2 naming the
    option), by `calligraphy.check_trial_record` (refused: DataError naming the pointer) and by the keyword
    argument of `calligraphy.simulate_trial` of the same name (refused: InvalidArgument naming it). The
    verdicts of all of them must be the schema's.
(b) Every spelling of every enumeration is taken by its option, in a record and by Python, and written back
    as it was given: in the record a trial writes, in what `check_trial_record` returns and in a Python
    trial's record, which Python takes again.
(c) A trial's CSV header and a saved trial's HDF5 datasets are the table's file names; Python's
    `TrialResult.to_dataframe()` and `Study.samples()` name the columns by the table's names; `calligraphy
    score` and Python's `score` read a trace named either way to the same metrics.

(d) A protocol is a reader too: every bounded number of `calligraphy schema protocol` (its trial settings,
    breaks, order, practice and test, each phase, each condition and its mode's parameters, a quiz's
    acceptance, a transfer test's choice) is taken by `session plan` at each closed bound and refused just past
    each bound (exit 2, one line naming the file and the JSON pointer); and a field of the protocol's trial
    settings or of a condition named as a specification field has the specification's type and range, but for
    the one exception the schema states (a protocol's `rate_hz` is the real-time range).

The cases are made only from the program's output (the schema, `trial --help`, `calligraphy devices`,
`calligraphy characters`), never from a list written here; the protocol's fields are tried in two small
protocols written here, one of each form. Under CALLIGRAPHY_SANITIZED=1 every third bound case is taken (deterministically).
Run by CTest as `cli_vocabulary_conformance_tests`; CALLIGRAPHY_CLI names the program and PYTHONPATH the
built Python package.
"""
import ast
import copy
import csv
import io
import json
import math
import os
import re
import subprocess
import tempfile
import unittest
from pathlib import Path

CLI = os.environ.get("CALLIGRAPHY_CLI", "")
SANITIZED = os.environ.get("CALLIGRAPHY_SANITIZED", "") == "1"
CHARS = "十"
SHORT_S = 0.01  # a trial that is stopped by its time limit after a few ticks: the record is still written

try:
    import calligraphy
except ImportError:  # reported by the tests that need it
    calligraphy = None


def _number_text(value):
    """A value as the command line and JSON give it: integers whole, doubles to the last bit."""
    return str(value) if isinstance(value, int) else repr(float(value))


def past_and_at(prop):
    """(values at a closed bound, values just past a bound) of a numeric schema property."""
    at, past = [], []
    if prop.get("type") == "integer":
        for bound, step in (("minimum", -1), ("maximum", 1)):
            if bound in prop:
                at.append(prop[bound])
                past.append(prop[bound] + step)
    elif prop.get("type") == "number":
        for bound, direction in (("minimum", -math.inf), ("maximum", math.inf)):
            if bound in prop and abs(prop[bound]) < 1e300:
                at.append(prop[bound])
                past.append(math.nextafter(prop[bound], direction))
        for bound in ("exclusiveMinimum", "exclusiveMaximum"):
            if bound in prop:
                past.append(prop[bound])
    return at, past



# The protocol (`calligraphy schema protocol`, read by `session plan`) --------------------------------------------
BOUNDS = ("minimum", "maximum", "exclusiveMinimum", "exclusiveMaximum")


def protocol_bounded_fields(schema):
    """Every bounded numeric property of the protocol's JSON Schema as (steps, property): steps lead from the
    document's root to it, each ("key", name), ("item",) (an array's element), ("mode", spelling) (a
    condition's mode whose rule allows it) or ("branch", schema) (the alternative of a oneOf it is in)."""
    found = []

    def resolve(node):
        while isinstance(node, dict) and "$ref" in node:
            node = schema["$defs"][node["$ref"].rsplit("/", 1)[1]]
        return node

    def walk(node, steps):
        node = resolve(node)
        if not isinstance(node, dict):
            return
        if node.get("type") in ("integer", "number") and any(bound in node for bound in BOUNDS):
            found.append((steps, node))
        rules = [(rule["if"]["properties"]["mode"]["const"], rule["then"]) for rule in node.get("allOf", [])
                 if "const" in rule.get("if", {}).get("properties", {}).get("mode", {}) and "then" in rule]
        for key, child in node.get("properties", {}).items():
            # A property some modes forbid is tried under the first mode that allows it.
            allowed = [mode for mode, then in rules if then.get("properties", {}).get(key) is not False]
            mode = [("mode", allowed[0])] if len(allowed) < len(rules) and allowed else []
            walk(child, steps + mode + [("key", key)])
        if "items" in node:
            walk(node["items"], steps + [("item",)])
        for alternative in node.get("oneOf", []):
            walk(alternative, steps + [("branch", resolve(alternative))])
        for rule in node.get("allOf", []):
            mode = rule.get("if", {}).get("properties", {}).get("mode", {}).get("const")
            if mode is not None and "then" in rule:
                walk(rule["then"], steps + [("mode", mode)])

    walk(schema, [])
    return found


def place(document, steps, value):
    """Sets the value `steps` lead to in `document` (making the objects on the way) and gives its JSON
    pointer and the object holding it."""
    pointer, cursor = "", document
    for at, step in enumerate(steps):
        rest = steps[at + 1:]
        if step[0] == "key":
            if step[1] not in cursor or not isinstance(cursor[step[1]], (dict, list)) and rest:
                cursor[step[1]] = [] if rest and rest[0][0] == "item" else {}
            pointer += "/" + step[1]
            if rest:
                cursor = cursor[step[1]]
            else:
                cursor[step[1]] = value
        elif step[0] == "item":
            # The first element that already has the rest of the way (a condition of the mode, a phase whose
            # characters are a choice), else the first.
            index = step[1] if len(step) > 1 else next(
                (i for i, element in enumerate(cursor) if has_way(element, rest)), 0)
            pointer += f"/{index}"
            cursor = cursor[index]
        elif step[0] == "mode" and cursor.get("mode") != step[1]:
            for key in ("parameters", "quiz", "teachers"):
                cursor.pop(key, None)
            cursor["mode"] = step[1]
    return pointer, cursor


def has_way(element, steps):
    """Whether `element` already has the way `steps` lead (keys present, the mode and the branch's type)."""
    for step in steps:
        if step[0] == "key":
            if not isinstance(element, dict) or step[1] not in element:
                return False
            element = element[step[1]]
        elif step[0] == "item":
            if not isinstance(element, list) or not element:
                return False
            element = element[0]
        elif step[0] == "mode" and element.get("mode") != step[1]:
            return False
        elif step[0] == "branch" and (step[1].get("type") == "object") != isinstance(element, dict):
            return False
    return True


class VocabularyTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        if not CLI or not Path(CLI).exists():
            raise unittest.SkipTest(f"CALLIGRAPHY_CLI={CLI!r} is not the calligraphy program: run through ctest")
        cls.folder = tempfile.TemporaryDirectory(prefix="calligraphy-vocabulary-")
        cls.cwd = Path(cls.folder.name)
        cls.schema = json.loads(cls.run_cli("schema", "specification").stdout)
        cls.fields = cls.schema["properties"]
        cls.options = cls.help_options()
        cls.option_of = {key: cls.find_option(prop) for key, prop in cls.fields.items()}
        # A teacher's recording for the replay mode's context.
        made = cls.run_cli("trial", CHARS, "--seed", "3", "--writer-profile", "skilled", "--record", "teacher.json")
        if made.returncode != 0:
            raise AssertionError(made.stderr.decode())
        cls.contexts = cls.make_contexts()
        cls.records = {}
        cls.found_contexts = {}

    @classmethod
    def tearDownClass(cls):
        cls.folder.cleanup()

    @classmethod
    def run_cli(cls, *args):
        return subprocess.run([CLI, *map(str, args)], cwd=cls.cwd, capture_output=True, timeout=300)

    @classmethod
    def help_options(cls):
        """`trial --help`'s options: name -> its text (value name and description, wrapped lines joined)."""
        options, last = {}, None
        for line in cls.run_cli("trial", "--help").stdout.decode().splitlines():
            match = re.match(r"^  (--[\w-]+)(.*)$", line)
            if match:
                last = match.group(1)
                options[last] = match.group(2).strip()
            elif last and line.startswith("      ") and line.strip():
                options[last] += " " + line.strip()
            else:
                last = None
        return options

    @classmethod
    def find_option(cls, prop):
        """The option whose help is the field's doc (the schema gives both from one table), or None."""
        doc = prop.get("description", "").split(" [")[0]  # the option states its own unit
        found = [name for name, text in cls.options.items() if doc and doc in text]
        return found[0] if len(found) == 1 else None

    @staticmethod
    def option_value(option, value):
        """A field's value as its option takes it: --watchdog-ms in whole milliseconds, others as they are."""
        if option.endswith("-ms"):
            scaled = value * 1000
            return str(int(scaled)) if float(scaled).is_integer() else repr(scaled)
        if isinstance(value, bool):
            return "on" if value else "off"
        return _number_text(value)

    @classmethod
    def devices_for_trial(cls):
        """The device kinds `calligraphy devices` lists for `trial` (no PATH or address to fill in)."""
        text = cls.run_cli("devices").stdout.decode()
        names = []
        for line in text.splitlines():
            match = re.match(r"^  ([\w-]+)\s+(simulated|person)\s+(.*)$", line)
            if match and "trial" in match.group(3):
                names.append(match.group(1))
        return names

    @classmethod
    def make_contexts(cls):
        """The settings a field may need to apply (its guidance mode, real-time pacing, a device a person
        holds): every spelling of every enumeration with an option, and every device of `trial`, as
        (option arguments, Python keyword arguments, spec-field settings)."""
        contexts = [([], {}, {})]
        for key, prop in cls.fields.items():
            option = cls.option_of.get(key)
            if "enum" not in prop or option is None:
                continue
            for spelling in prop["enum"]:
                arguments = [option, spelling]
                settings = {key: spelling}
                if key == "guidance_mode" and spelling == "replay":
                    arguments += ["--teacher", "teacher.json"]
                    settings["teacher"] = "teacher.json"
                contexts.append((arguments, {key: spelling}, settings))
        for device in cls.devices_for_trial():
            contexts.append((["--device", device], {}, {"device": device}))
        return contexts

    def context_for(self, arguments):
        """The first context in which `arguments` pass `trial --check` (None when there is none), and the
        refusals met on the way. A context setting the option `arguments` set gives only its other arguments
        (a replay's teacher). Looked for once per `arguments`: every bound of a field asks for the context of
        its option at its default, which the same runs of `trial --check` answer."""
        key = tuple(arguments)
        if key not in self.found_contexts:
            self.found_contexts[key] = self.look_for_context(arguments)
        context, refusals = self.found_contexts[key]
        return copy.deepcopy(context), list(refusals)

    def look_for_context(self, arguments):
        refusals = []
        for context in self.contexts:
            given = list(context[0])
            if arguments and arguments[0] in given:
                at = given.index(arguments[0])
                del given[at:at + 2]
            checked = self.run_cli("trial", CHARS, *given, *arguments, "--check")
            if checked.returncode == 0:
                return (given, *context[1:]), refusals
            refusals.append(checked.stderr.decode())
        return None, refusals

    def record_in(self, context, max_duration_s=SHORT_S):
        """A record a trial in `context` wrote (a few ticks: stopped by its time limit)."""
        key = (tuple(context[0]), max_duration_s)
        if key not in self.records:
            path = self.cwd / f"context-{len(self.records)}.json"
            ran = self.run_cli("trial", CHARS, *context[0], "--max-duration", _number_text(max_duration_s),
                               "--json", path.name)
            self.assertTrue(path.exists(), f"trial {context[0]}: {ran.stderr.decode()}")
            self.records[key] = json.loads(path.read_text(encoding="utf-8"))
        return copy.deepcopy(self.records[key])

    def python_keywords(self):
        """The fields of the specification simulate_trial takes as keyword arguments: a keyword of a field's
        name whose default is the field's (or None: not given), read from its signature line."""
        first = calligraphy.simulate_trial.__doc__.splitlines()[0]
        keywords = set()
        for key, prop in self.fields.items():
            match = re.search(rf"\b{key}: [^=]+? = ([^,)]+)", first)
            if match and (match.group(1) == "None" or ast.literal_eval(match.group(1)) == prop.get("default")):
                keywords.add(key)
        return keywords

    def python_context(self, context):
        keywords = dict(context[1])
        if keywords.get("guidance_mode") == "replay":
            keywords["teacher"] = calligraphy.TeacherRecording.load(str(self.cwd / "teacher.json"))
        return keywords

    # (a) ------------------------------------------------------------------------------------------------
    def test_every_bound_gets_one_verdict_from_every_reader(self):
        if calligraphy is None:
            self.fail("the calligraphy Python package is not importable (PYTHONPATH)")
        keywords = self.python_keywords()
        rate = self.fields["rate_hz"]
        cases = []
        for key, prop in sorted(self.fields.items()):
            at, past = past_and_at(prop)
            cases += [(key, value, True) for value in at] + [(key, value, False) for value in past]
        if SANITIZED:
            cases = cases[::3]
        self.assertGreaterEqual(len(cases), 8 if SANITIZED else 25)
        disagreements, checked = [], 0
        for key, value, valid in cases:
            prop = self.fields[key]
            option = self.option_of.get(key)
            # A trial is at most 10^7 ticks: the longest trial is taken at the lowest rate, every other
            # bound in a short trial.
            duration = value if key == "max_duration_s" else SHORT_S
            base_option = [] if key == "max_duration_s" else ["--max-duration", _number_text(SHORT_S)]
            if key == "max_duration_s":
                base_option = ["--rate", _number_text(rate["minimum"])]
            context, _ = self.context_for([option, self.option_value(option, prop.get("default", value))]
                                          if option else [])
            self.assertIsNotNone(context, f"no context takes {key} at its default")
            verdicts = {}
            # The record, re-read by `trial --spec RECORD --check`.
            record = self.record_in(context)
            record["specification"]["trial"][key] = value
            acceptance = record["specification"]["force_law"]["acceptance"]
            if key in acceptance:  # a record states the acceptance its trial ran with in both places
                acceptance[key] = value
            # ... and its guidance mode's own value too, in the force law's guidance_law under its own name
            law = record["specification"]["force_law"].get("guidance_law", {})
            law_key = {"guidance_gain": "gain", "assist_band_m": "band_m", "amplification_gain": "gain",
                       "timing_speed_m_s": "speed_m_s"}.get(key)
            if law_key in law:
                law[law_key] = value
            if key == "max_duration_s":
                record["specification"]["trial"]["rate_hz"] = rate["minimum"]
            pointer = f"/specification/trial/{key}"
            path = self.cwd / "bound.json"
            path.write_text(json.dumps(record), encoding="utf-8")
            result = self.run_cli("trial", "--spec", path.name, "--check")
            stderr = result.stderr.decode()
            verdicts["trial --spec"] = result.returncode == 0
            if result.returncode != 0:
                self.assertEqual(result.returncode, 2, f"{key}={value!r}: {stderr}")
                self.assertIn(f"{path.name}: {pointer}", stderr)
                self.assertEqual(len(stderr.strip().splitlines()), 1, stderr)
            # The option.
            if option:
                result = self.run_cli("trial", CHARS, *context[0], *base_option, option,
                                      self.option_value(option, value), "--check")
                stderr = result.stderr.decode()
                verdicts[option] = result.returncode == 0
                if result.returncode != 0:
                    self.assertEqual(result.returncode, 2, f"{option} {value!r}: {stderr}")
                    self.assertIn(option, stderr)
            # Python: the record, and the keyword argument of the same name.
            try:
                calligraphy.check_trial_record(record)
                verdicts["check_trial_record"] = True
            except calligraphy.DataError as e:
                verdicts["check_trial_record"] = False
                self.assertIn(pointer, str(e))
            if key in keywords:
                arguments = self.python_context(context)
                arguments.update(max_duration_s=duration, keep_trace=False)
                if key == "max_duration_s":
                    arguments["rate_hz"] = rate["minimum"]
                arguments[key] = value
                try:
                    calligraphy.simulate_trial(CHARS, **arguments)
                    verdicts[f"simulate_trial({key}=)"] = True
                except calligraphy.InvalidArgument as e:
                    verdicts[f"simulate_trial({key}=)"] = False
                    self.assertIn(key, str(e))
            checked += len(verdicts)
            wrong = {form: verdict for form, verdict in verdicts.items() if verdict != valid}
            if wrong:
                disagreements.append(f"{key} = {value!r} ({'valid' if valid else 'invalid'}): "
                                     + ", ".join(f"{form} {'takes' if v else 'refuses'} it" for form, v in wrong.items()))
        print(f"bound verdicts checked: {checked} over {len(cases)} values")
        self.assertEqual(disagreements, [], "\n".join(disagreements))

    # (a) for the protocol -------------------------------------------------------------------------------------
    def base_protocols(self):
        """Two small protocols `session plan` takes, one of each form: the paper's practice and test, and
        phases over item sets with a transfer test chosen by coverage."""
        paper = {"format": "calligraphy-study-protocol", "version": 1, "name": "vocabulary",
                 "conditions": [{"name": "A", "mode": "haptic"}],
                 "practice": {"characters": [CHARS], "condition": "A"},
                 "test": {"characters": [CHARS], "conditions": ["A"], "repetitions": 1}}
        phased = {"format": "calligraphy-study-protocol", "version": 1, "name": "vocabulary",
                  "conditions": [{"name": "A", "mode": "haptic"}, {"name": "B", "mode": "vision"}],
                  "item_sets": [{"name": "trained", "characters": [CHARS]}],
                  "phases": [{"phase": "training", "condition": "A", "sets": ["trained"]},
                             {"phase": "transfer", "condition": "B", "characters": {"choose": 1, "from": ["二"]}}]}
        return paper, phased

    def plan(self, document, name="protocol.json"):
        (self.cwd / name).write_text(json.dumps(document, ensure_ascii=False), encoding="utf-8")
        return self.run_cli("session", "plan", name, "--subjects", "1")

    def test_every_protocol_bound_gets_the_schemas_verdict_from_session_plan(self):
        """Every bounded number of `calligraphy schema protocol` (nested objects, arrays' elements, a
        condition's mode's parameters and a transfer test's choice included) is taken by `session plan` at
        each closed bound and refused just past each bound: exit 2, one line naming the file and the JSON
        pointer. A value whose validity rests on another is given that other so that only the range is
        tried (each named below)."""
        protocol_schema = json.loads(self.run_cli("schema", "protocol").stdout)
        bases = self.base_protocols()
        for base in bases:
            planned = self.plan(base)
            self.assertEqual(planned.returncode, 0, planned.stderr.decode())
        # A transfer test chooses among characters not trained made of trained typical strokes: for a choice
        # of up to 1000, training on characters that have every typical stroke (`calligraphy characters`).
        listed = json.loads(self.run_cli("characters", "--json").stdout)["characters"]
        cover, strokes = [], set()
        for entry in sorted(listed, key=lambda c: -len(set(c["typical_ids"]))):
            if not set(entry["typical_ids"]) <= strokes:
                cover.append(entry["character"])
                strokes |= set(entry["typical_ids"])
        candidates = [c["character"] for c in listed if c["character"] not in cover]
        rate = protocol_schema["$defs"]["ProtocolTrialSettings"]["properties"]["rate_hz"]
        cases = []
        for steps, prop in protocol_bounded_fields(protocol_schema):
            at, past = past_and_at(prop)
            cases += [(steps, value, True) for value in at] + [(steps, value, False) for value in past]
        if SANITIZED:
            cases = cases[::3]
        self.assertGreaterEqual(len(cases), 20 if SANITIZED else 60)
        disagreements, pointers = [], set()
        for steps, value, valid in cases:
            base = next((b for b in bases if has_way(b, steps[:1])), bases[0])
            document = copy.deepcopy(base)
            key = steps[-1][1]
            if key == "session" and steps[0] == ("key", "phases"):
                # Sessions are numbered from 1 without gaps: the last phase is tried, after a phase in each
                # session before it (at most 20 phases).
                document["phases"][1:1] = [{"phase": "retention", "condition": "B", "characters": [CHARS],
                                            "session": n, "delay_s": 86400}
                                           for n in range(2, min(int(value), 20))]
                steps = [steps[0], ("item", len(document["phases"]) - 1), steps[-1]]
            pointer, holder = place(document, steps, value)
            pointers.add(pointer)
            if key == "max_duration_s":
                # At most 10^7 servo ticks a trial: the longest trial at the lowest rate.
                document.setdefault("trial", {})["rate_hz"] = rate["minimum"]
            if key == "choose":
                # A choice among as many candidates as it chooses (characters the library has, none trained).
                holder["from"] = candidates[:max(1, min(int(value), 1000))]
                document["item_sets"][0]["characters"] = cover
            if key == "min_band_m":
                # The widest band is at least the narrowest.
                holder["max_band_m"] = max(value, holder.get("max_band_m", 0.0))
            if key == "every_trials" and value > 0:
                # A rest every so many trials has a duration.
                holder["duration_s"] = 1.0
            result = self.plan(document)
            stderr = result.stderr.decode()
            if (result.returncode == 0) != valid:
                disagreements.append(f"{pointer} = {value!r} ({'valid' if valid else 'invalid'}): session plan "
                                     f"{'takes' if result.returncode == 0 else 'refuses'} it: {stderr.strip()}")
            elif not valid and (result.returncode != 2 or f"protocol.json: {pointer}:" not in stderr
                                or len(stderr.strip().splitlines()) != 1):
                disagreements.append(f"{pointer} = {value!r}: refused with exit {result.returncode} and "
                                     f"not one line naming the file and the pointer: {stderr.strip()}")
        print(f"protocol bound verdicts checked: {len(cases)} over {len(pointers)} pointers")
        self.assertEqual(disagreements, [], "\n".join(disagreements))

    def test_a_protocols_trial_fields_have_the_specifications_ranges(self):
        """A field of a protocol's trial settings or of a condition (its parameters included) that has the
        name of a specification field has its type and range, but for the one exception the schema states:
        a protocol's trials may be written by a person, in real time, so its `rate_hz` (described as the
        real-time range) ends at the real-time rate `trial --help` states for --rate."""
        protocol_schema = json.loads(self.run_cli("schema", "protocol").stdout)
        real_time = re.search(r"real-time pacing: at most (\d+) Hz", self.options.get("--rate", ""))
        self.assertIsNotNone(real_time, f"trial --help, --rate: {self.options.get('--rate')}")
        pairs, differences = [], []
        for steps, prop in protocol_bounded_fields(protocol_schema):
            key = steps[-1][1]
            if key not in self.fields or steps[0][1] not in ("trial", "conditions"):
                continue
            pairs.append("/".join(f"({s[1]})" if s[0] == "mode" else s[1] if s[0] == "key" else "*" for s in steps))
            spec = self.fields[key]
            mine = {b: prop[b] for b in ("type", *BOUNDS) if b in prop}
            theirs = {b: spec[b] for b in ("type", *BOUNDS) if b in spec}
            if key == "rate_hz" and "real-time range" in prop.get("description", ""):
                self.assertLess(float(real_time.group(1)), theirs["maximum"])
                theirs["maximum"] = float(real_time.group(1))
            if mine != theirs:
                differences.append(f"{pairs[-1]}: protocol {mine}, specification {theirs}")
        print("protocol fields checked against the specification's: " + ", ".join(pairs))
        self.assertGreaterEqual(len(pairs), 3)
        self.assertEqual(differences, [], "\n".join(differences))

    # (b) ------------------------------------------------------------------------------------------------
    def test_every_spelling_is_taken_and_written_back_by_every_reader(self):
        if calligraphy is None:
            self.fail("the calligraphy Python package is not importable (PYTHONPATH)")
        keywords = self.python_keywords()
        enums = {key: prop for key, prop in self.fields.items() if "enum" in prop}
        self.assertGreaterEqual(len(enums), 3)
        disagreements = []
        for key, prop in sorted(enums.items()):
            option = self.option_of.get(key)
            self.assertIsNotNone(option, f"{key}: no option of `trial --help` has its doc")
            self.assertIn(f"{option} {'|'.join(prop['enum'])}", "\n".join(f"{n} {t}" for n, t in self.options.items()))
            for spelling in prop["enum"]:
                context, refusals = self.context_for([option, spelling])
                runs = context is not None
                path = self.cwd / "spelling.json"
                if runs:
                    path.unlink(missing_ok=True)
                    ran = self.run_cli("trial", CHARS, *context[0], option, spelling, "--max-duration",
                                       _number_text(SHORT_S), "--json", path.name)
                    if not path.exists() and ran.returncode == 1 and b"cannot be used now" in ran.stderr:
                        # `trial --check` needs only the device's kind: a person's device is not attached here.
                        runs, context = False, None
                if context is None:
                    # No trial here takes it (a person needs a hardware device that is not attached): the
                    # option still knows the spelling, and a record states it.
                    unknown = [r for r in refusals if f"{option}: expects" in r or "expected one of" in r]
                    if unknown:
                        disagreements.append(f"{key} '{spelling}': {option} does not know it: {unknown[0]}")
                    context = self.contexts[0]
                    # A record stating it where no trial here can take it is refused as its content: exit 2, naming
                    # the file and the field's pointer.
                    record = self.record_in(context)
                    record["specification"]["trial"][key] = spelling
                    (self.cwd / "untaken.json").write_text(json.dumps(record), encoding="utf-8")
                    refused = self.run_cli("trial", "--spec", "untaken.json", "--check")
                    if refused.returncode != 0 and (
                            refused.returncode != 2
                            or f"untaken.json: /specification/trial/{key}" not in refused.stderr.decode()):
                        disagreements.append(f"{key} '{spelling}' in a record: exit {refused.returncode}, "
                                             f"{refused.stderr.decode().strip()}")
                # Written back in the record of a trial that runs here (a device a person holds does not).
                record = self.record_in(self.contexts[0])
                record["specification"]["trial"][key] = spelling
                if runs:
                    self.assertTrue(path.exists(), f"{option} {spelling}: exit {ran.returncode}, "
                                                   f"{ran.stderr.decode().strip()}")
                    record = json.loads(path.read_text(encoding="utf-8"))
                    written = record["specification"]["trial"][key]
                    # "auto" is resolved: the record states what ran, in another of the table's spellings.
                    if written != spelling and not (spelling == "auto" and written in prop["enum"]):
                        disagreements.append(f"{key} '{spelling}': the record says '{written}'")
                # In a record (that trial's), read back by Python as it was given; a person's record holds no
                # simulated writer's profile (docs/cli.md, "Re-running a trial": `writer` is null for a person).
                if key == "writer" and spelling == "person":
                    record["specification"]["writer"] = None
                expected = record["specification"]["trial"][key]  # as given, or "auto" resolved by the run
                try:
                    back = calligraphy.check_trial_record(record)["trial"][key]
                    if back != expected:
                        disagreements.append(f"{key} '{spelling}': check_trial_record gives '{back}'")
                except calligraphy.Error as e:
                    disagreements.append(f"{key} '{spelling}': check_trial_record refuses it: {e}")
                # The Python keyword, and Python taking its own output again.
                if key in keywords:
                    arguments = self.python_context(context)
                    arguments.update({key: spelling, "max_duration_s": SHORT_S, "keep_trace": False})
                    result = calligraphy.simulate_trial(CHARS, **arguments)
                    given_back = result.metrics["specification"]["trial"][key]
                    if given_back != spelling:
                        disagreements.append(f"{key} '{spelling}': simulate_trial records '{given_back}'")
                    if key in result.metrics and result.metrics[key] != spelling:
                        disagreements.append(f"{key} '{spelling}': simulate_trial's metrics say "
                                             f"'{result.metrics[key]}'")
                    arguments[key] = result.metrics.get(key, given_back)
                    calligraphy.simulate_trial(CHARS, **arguments)  # its own output taken again
                    calligraphy.check_trial_record(result.metrics)
        self.assertEqual(disagreements, [], "\n".join(disagreements))

    # (c) ------------------------------------------------------------------------------------------------
    def test_every_trace_column_has_one_name_per_reader(self):
        if calligraphy is None:
            self.fail("the calligraphy Python package is not importable (PYTHONPATH)")
        import numpy as np
        import pandas as pd

        from calligraphy import study as studies

        table = calligraphy.trace_columns()
        names = [column["name"] for column in table]
        file_names = [column["file_name"] for column in table]
        self.assertGreaterEqual(len(names), 10)
        # The CSV a trial writes, and what the option's help says it writes.
        ran = self.run_cli("trial", CHARS, "--seed", "5", "--csv", "trace.csv", "--json", "trace.json")
        self.assertEqual(ran.returncode, 0, ran.stderr.decode())
        header = (self.cwd / "trace.csv").read_text(encoding="utf-8").splitlines()[0]
        self.assertEqual(header.split(","), file_names)
        for listed in re.findall(r"\((\w+(?:,\w+){3,})", self.options["--csv"]):
            self.assertEqual(listed.split(","), file_names, "trial --help, --csv: the columns it names")
        # Python's DataFrame of the same trial.
        result = calligraphy.simulate_trial(CHARS, seed=5)
        frame = result.to_dataframe()
        self.assertEqual(list(frame.columns), names)
        # A saved trial: its HDF5 datasets, `calligraphy trace`'s CSV and Study.samples().
        protocol = {"name": "vocabulary", "conditions": [{"name": "A", "mode": "haptic"}],
                    "test": {"characters": [CHARS], "conditions": ["A"], "repetitions": 1}}
        (self.cwd / "p.json").write_text(json.dumps(protocol, ensure_ascii=False), encoding="utf-8")
        ran = self.run_cli("session", "run", "p.json", "--writer", "simulated", "--subjects", "1", "--out", "study")
        self.assertEqual(ran.returncode, 0, ran.stderr.decode())
        traces = sorted((self.cwd / "study").rglob("*.trace.h5"))
        self.assertTrue(traces)
        try:
            import h5py
        except ImportError:
            h5py = None
        if h5py is not None:
            with h5py.File(traces[0], "r") as file:
                datasets = []
                file.visititems(lambda name, node: datasets.append(name.split("/")[-1])
                                if isinstance(node, h5py.Dataset) else None)
            self.assertLessEqual(set(file_names), set(datasets), "the HDF5 trace's datasets")
        exported = self.run_cli("trace", traces[0])
        self.assertEqual(exported.returncode, 0, exported.stderr.decode())
        self.assertEqual(exported.stdout.decode().splitlines()[0].split(","), file_names)
        study = studies.load([self.cwd / "study"])
        self.assertEqual(list(study.samples(study.trials.iloc[0]).columns), names)
        # `calligraphy score` and Python's score read a trace named either way to the same metrics.
        scored = {}
        text = (self.cwd / "trace.csv").read_text(encoding="utf-8")
        renamed = self.cwd / "trace-named.csv"
        renamed.write_text(",".join(names) + "\n" + text.split("\n", 1)[1], encoding="utf-8")
        for label, path in (("file names", "trace.csv"), ("names", renamed.name)):
            out = self.cwd / f"score-{len(scored)}.json"
            done = self.run_cli("score", path, "--character", CHARS, "--json", out.name)
            self.assertEqual(done.returncode, 0, f"score, a trace with the table's {label}: {done.stderr.decode()}")
            scored[label] = json.loads(out.read_text(encoding="utf-8"))["mean_deviation_m"]
        self.assertEqual(scored["file names"], scored["names"])
        by_name = calligraphy.score(frame, CHARS)
        by_file_name = calligraphy.score(frame.rename(columns=dict(zip(names, file_names))), CHARS)
        self.assertEqual(by_name["mean_deviation_m"], by_file_name["mean_deviation_m"])
        self.assertTrue(np.isfinite(by_name["mean_deviation_m"]))
        del pd

    # Records written before ---------------------------------------------------------------------------------
    def test_records_of_every_earlier_version_run_again(self):
        """A record of each earlier version (1 to the current one less 1), made from a current record as that
        version wrote it (version 1: the writer's settings as "key=value" strings; before 3: no guidance
        stiffness; before 4: no teacher SHA-256 nor the length-scaled tolerances; before 6: no stroke
        acceptance in the trial's specification), is read by `trial --spec`
        and Python alike and runs to a trace: the same trace as the current record where the fields it lacks
        take values that do not change this trial (versions 1 to 3 here, a trial that completes every stroke
        in order with either tolerances)."""
        record_schema = json.loads(self.run_cli("schema", "record").stdout)
        current = record_schema["properties"]["version"]["maximum"]
        oldest = record_schema["properties"]["version"]["minimum"]
        self.assertGreaterEqual(current, 2)
        made = self.run_cli("trial", CHARS, "--seed", "3", "--writer-param", "bias_offset_m=0.002",
                            "--json", "now.json", "--csv", "now.csv")
        self.assertEqual(made.returncode, 0, made.stderr.decode())
        now = json.loads((self.cwd / "now.json").read_text(encoding="utf-8"))
        self.assertTrue(now["completed_in_order"])
        for version in range(oldest, current):
            with self.subTest(version=version):
                document = copy.deepcopy(now)
                spec = document["specification"]
                spec["version"] = version
                if version < 6:  # the specification did not state the acceptance: its force law's ran
                    for key in spec["force_law"]["acceptance"]:
                        del spec["trial"][key]
                if version < 4:
                    del spec["teacher_sha256"]
                if version < 3:
                    del spec["trial"]["guidance_stiffness_n_per_m"]
                if version < 2:
                    spec["trial"]["writer_parameters"] = [f"{p['key']}={p['value']!r}"
                                                          for p in spec["trial"]["writer_parameters"]]
                name = f"v{version}"
                (self.cwd / f"{name}.json").write_text(json.dumps(document), encoding="utf-8")
                ran = self.run_cli("trial", "--spec", f"{name}.json", "--csv", f"{name}.csv")
                self.assertEqual(ran.returncode, 0, ran.stderr.decode())
                self.assertEqual((self.cwd / f"{name}.csv").read_bytes(), (self.cwd / "now.csv").read_bytes())
                if calligraphy is not None:
                    back = calligraphy.check_trial_record(document)
                    self.assertEqual(back["version"], current)  # written back as this library writes
                    self.assertEqual(back["trial"]["writer_parameters"], now["specification"]["trial"]["writer_parameters"])


if __name__ == "__main__":
    unittest.main()
