#!/usr/bin/env python3
"""Round 30A: numbers and words on every option of every command. From the docs alone: `calligraphy --help`
and each command's `--help`, `calligraphy schema specification` (and `--markdown`), docs/cli.md ("Conventions":
"Option syntax", "Numbers"; "Checked before anything runs"; "Exit statuses"; each command's section and table,
"The trial specification"), docs/typical-strokes.md (the ID, acronym, name and character of 横折钩).

The options are not listed here: they are read from the help texts (each `--name VALUE ... (default: X)`
line, its range `in [a, b]`, `in (a, b]`, `a..b`, `>= a`, `> a`, its words `a|b|c`), and held
- to the schema (`schema specification`: one default and one range per field, the same on `trial`, `score`
  and `train`) and to docs/cli.md's tables (the same range, default and words);
- at the ends of each range: the inclusive ends taken (`trial --check`, a few runs of all ends together),
  one past an end refused (for a real, the next double past it; an exclusive end itself) with exit status 2
  and one error line naming the option and the value, before any file is read or written. Within the 4 s of
  CPU a round has (a run of the program costs some 16 ms), every end of trial's own options and of each other
  command's options is tried, and of the stroke acceptance's 22 options (one table, shared with score) each
  upper end but for 9 of the 12 lengths of (0, 0.1] m, and one lower end of each form;
- in every spelling a number can be given (hex, exponents, spaces, units, commas, `nan`, `inf`, `1e309`, a
  400-digit number, `-0`, `+5`, full-width digits), given twice, given as `--x=v` and `--x v`;
- in the words of each enumeration (upper case, underscores, misspellings) and the documented old values;
- and in what a trial then records: its specification in the documented units (m, s, Hz; `--watchdog-ms` as
  `watchdog_s`), a 64-bit seed exactly, a trace of `--max-duration` x `--rate` ticks.

CALLIGRAPHY_CLI names the program, CALLIGRAPHY_SOURCE_DIR the source tree (docs/). CALLIGRAPHY_SANITIZED=1
takes five cases.
"""
import csv
import io
import json
import math
import os
import re
import resource
import shutil
import tempfile
import unittest
from pathlib import Path

from outsider import OneErrorLine, run, sanitized_subset

SOURCE = Path(os.environ.get("CALLIGRAPHY_SOURCE_DIR") or Path(__file__).resolve().parents[2])

load_tests = sanitized_subset({"test_trial_watchdog_ms_with_lock_step_is_refused",
                               "test_trial_option_given_twice_is_an_error_even_with_one_value",
                               "test_flag_given_a_value_is_refused_and_true_is_the_flag",
                               "test_value_starting_with_a_dash_is_refused_naming_the_option_before_it",
                               "test_schema_document_words_are_the_one_spelling"})

# The commands whose options take numbers or words, and what each run needs besides the option tried, so
# that a value taken by mistake ends the run at once (a missing file, an empty data folder, a short loop)
# rather than running a benchmark or a corpus fit. Names in braces are filled in per run.
COMMANDS = {
    "trial": ["十"],
    "score": ["{trace}", "--character", "十"],
    "train": ["十"],
    "characters": ["--text", "十"],
    "curriculum": ["{missing}", "--subject", "S01", "--from", "十"],
    "report": ["{missing}", "--csv", "{tmp}"],
    "session plan": ["{missing}.json", "--subjects", "1"],
    "session run": ["{missing}.json", "--out", "{tmp}/out", "--subjects", "1"],
    "session resume": ["{missing}"],
    "session cohort": ["{missing}.json", "--subjects", "1", "--csv", "{tmp}"],
    "corpus build": ["--out", "{tmp}/store.clg", "--data", "{empty}"],
    "corpus fidelity": ["--data", "{empty}"],
    "corpus validate": ["--cnchar", "{missing}.js", "--data", "{empty}"],
    "bench nearest": ["--queries", "1"],
    "bench jumps": ["--chars", "十", "--seeds", "1"],
    "bench tick": ["--chars", "十", "--passes", "1"],
    "bench loop": ["--seconds", "0.01", "--realtime", "off"],
    "bench acceptance": ["--kanjivg", "{empty}", "--characters", "1"],
}
# What an option needs beside it to be taken at all on `trial` (docs/cli.md, trial's table).
TRIAL_CONTEXT = {
    "--guidance-gain": ["--guidance-mode", "fading"],
    "--assist-band": ["--guidance-mode", "assist-as-needed"],
    "--amplification-gain": ["--guidance-mode", "error-amplification"],
    "--timing-speed": ["--guidance-mode", "timing"],
    "--watchdog-ms": ["--pacing", "real-time"],
    # 10^7 ticks at most: each end of one of the two is tried with the other where the product stays within.
    "--rate": ["--max-duration", "1"],
    "--max-duration": ["--rate", "100"],
}
# A field of the specification whose option is not its name dashed with the unit dropped, and the factor
# from the option's unit to the field's (docs/cli.md, "The trial specification").
FIELD_OF = {"--rate": ("rate_hz", 1.0), "--watchdog-ms": ("watchdog_s", 0.001),
            "--max-duration": ("max_duration_s", 1.0)}
NUMBER = r"-?(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?"


def cpu_capped():
    """A child that takes a value it should refuse is ended after 3 s of CPU, not left to run a benchmark."""
    resource.setrlimit(resource.RLIMIT_CPU, (3, 4))


class Range:
    """A range as a help line or a docs table gives it: `kind` int or real, each end a number or None and open
    or not; `lo_text`/`hi_text` the ends as written."""

    def __init__(self, kind, lo, hi, lo_open=False, hi_open=False, lo_text=None, hi_text=None):
        self.kind, self.lo, self.hi, self.lo_open, self.hi_open = kind, lo, hi, lo_open, hi_open
        self.lo_text = lo_text if lo_text is not None else (None if lo is None else str(lo))
        self.hi_text = hi_text if hi_text is not None else (None if hi is None else str(hi))

    def __repr__(self):
        return (f"{'(' if self.lo_open else '['}{self.lo_text}, {self.hi_text}{')' if self.hi_open else ']'}"
                f" {self.kind}")

    def refused(self):
        """One value past each end: the integer beside it, an exclusive end itself, or the next double."""
        out = []
        for end, text, is_open, way in ((self.lo, self.lo_text, self.lo_open, -math.inf),
                                        (self.hi, self.hi_text, self.hi_open, math.inf)):
            if end is None:
                continue
            if self.kind == "int":
                out.append(str(end + (1 if way > 0 else -1)))
            elif is_open:
                out.append(text)
            else:
                out.append(repr(math.nextafter(float(end), way)))
        return out


def power(text):
    """`10^8`, `2^64-1`, `-1`: an integer as the docs write one."""
    m = re.fullmatch(r"(-?\d+)(?:\^(\d+))?(?:-(\d+))?", text)
    if not m:
        return None
    value = int(m.group(1)) ** int(m.group(2)) if m.group(2) else int(m.group(1))
    return value - int(m.group(3)) if m.group(3) else value


def parse_range(text, dash=False):
    """The range a help line or a docs table cell states, or None; `dash`: `1-1000` too (the docs' tables; in
    a help line `A-Z a-z 0-9` is no range)."""
    for m in re.finditer(r"([\[(])\s*(" + NUMBER + r")\s*,\s*(" + NUMBER + r")\s*([\])])", text):
        return Range("real", float(m.group(2)), float(m.group(3)), m.group(1) == "(", m.group(4) == ")",
                     m.group(2), m.group(3))
    found = re.findall(r"(?<![\w.^])(-?[\d^]+(?:-1)?)\.\.(-?[\d^]+(?:-1)?)(?![\w.])", text)
    if found:
        lo, hi = (power(t) for t in found[-1])
        if lo is not None and hi is not None:
            return Range("int", lo, hi, lo_text=found[-1][0], hi_text=found[-1][1])
    m = re.search(r"(?<![\w.^-])(\d+)-(\d+)(?![\w.^])", text) if dash else None
    if m:
        return Range("int", int(m.group(1)), int(m.group(2)))
    m = re.search(r"(>=?)\s*(" + NUMBER + ")", text)
    if m:
        return Range("real", float(m.group(2)), None, m.group(1) == ">", lo_text=m.group(2))
    return None


OPTION_LINE = re.compile(r"^  (--[a-z][a-z0-9-]*)(?: (\S+))?(?:\s{2,}(.*))?$")


def parse_help(text):
    """{--name: {"value", "desc", "default", "range", "words"}} of a command's help text."""
    options, current, inside = {}, None, False
    for line in text.splitlines():
        if line.startswith("Options:"):
            inside = True
            continue
        if not inside:
            continue
        if not line.strip():
            current = None
            continue
        m = OPTION_LINE.match(line)
        if m:
            current = {"value": m.group(2), "desc": m.group(3) or ""}
            options[m.group(1)] = current
        elif current is not None and line.startswith(" " * 10):
            current["desc"] = (current["desc"] + " " + line.strip()).strip()
    for o in options.values():
        d = re.search(r"\(default: (.*)\)$", o["desc"])
        o["default"] = d.group(1) if d else None
        body = o["desc"][:d.start()] if d else o["desc"]
        o["range"] = parse_range(body) if o["value"] and "|" not in o["value"] else None
        words = o["value"].split("|") if o["value"] and "|" in o["value"] else None
        # FILE|- names a file or standard output: no words.
        o["words"] = words if words and all(re.fullmatch(r"[a-z0-9-]+", w) for w in words) else None
    return options


def leading_number(text):
    m = re.match(r"\s*(" + NUMBER + r")(?![\w.])", text or "")
    return float(m.group(1)) if m else None


def names_number(line, value):
    """The line holds `value` as written, or a number equal to it."""
    if value in line:
        return True
    try:
        wanted = float(value)
    except ValueError:
        return False
    for token in re.findall(NUMBER, line):
        try:
            if float(token) == wanted:
                return True
        except ValueError:
            pass
    return False


def docs_tables(synopses=None):
    """docs/cli.md's option tables: {command: [(option names, value cell, default cell)]}, a table belonging to
    the command its section names or the last line that begins with `calligraphy COMMAND ...`:; `synopses`, a
    dict, gets {command: the options that line names}."""
    text = (SOURCE / "docs" / "cli.md").read_text(encoding="utf-8")
    tables, command, in_table = {}, None, False
    synopses = {} if synopses is None else synopses
    known = set(COMMANDS) | {"model", "strokes", "trace", "devices", "schema"}
    for line in text.splitlines():
        if line.startswith("## "):
            command = line[3:].strip() if line[3:].strip() in known else None
            in_table = False
            continue
        start = re.match(r"^`calligraphy ((?:\w+)(?: \w+)?)[^`]*`(?::| or )", line)
        if start:
            words = start.group(1)
            command = words if words in known else words.split()[0] if words.split()[0] in known else None
            if command:
                synopses.setdefault(command, set()).update(re.findall(r"--[a-z0-9-]+", line.split("`")[1]))
        if line.startswith("| option | value | default | meaning |"):
            in_table = True
            continue
        if in_table and line.startswith("|"):
            cells = [c.strip() for c in re.split(r"(?<!\\)\|", line.strip().strip("|"))]
            if len(cells) < 3 or set(cells[0]) <= {"-", " "}:
                continue
            names = re.findall(r"`(--[a-z0-9-]+)`", cells[0])
            if names and command:
                tables.setdefault(command, []).append((names, cells[1], cells[2]))
        elif in_table:
            in_table = False
    return tables


def doc_words(cell):
    """The words of a value cell made only of backticked words (`on`\\|`off`, `none`, `two-state`)."""
    if not re.fullmatch(r"`[^`]+`(?:\s*(?:\\\||,)\s*`[^`]+`)+", cell.strip()):
        return None
    return re.findall(r"`([^`]+)`", cell)


class Round30A(unittest.TestCase, OneErrorLine):
    @classmethod
    def setUpClass(cls):
        cls.tmp = Path(tempfile.mkdtemp(prefix="round30a-"))
        (cls.tmp / "empty").mkdir()
        cls.fill = {"tmp": str(cls.tmp), "empty": str(cls.tmp / "empty"), "missing": str(cls.tmp / "missing"),
                    "trace": str(cls.tmp / "r1.csv")}
        cls._help, cls._cache = {}, {}

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.tmp, ignore_errors=True)

    # ---- helpers ---------------------------------------------------------------------------------------
    def cli(self, *args, cwd=None):
        # Only a benchmark or a corpus fit could run long on a value taken by mistake: those are capped (a
        # preexec_fn makes each start a fork of this process, dearer than the spawn the others get).
        capped = {"preexec_fn": cpu_capped} if args and args[0] in ("bench", "corpus") else {}
        return run(list(args), cwd or self.tmp, timeout=30, **capped)

    def help(self, command):
        if command not in self._help:
            result = self.cli(*command.split(), "--help")
            self.assertEqual(result.returncode, 0, result.stderr)
            self._help[command] = parse_help(result.stdout.decode())
        return self._help[command]

    def context(self, command):
        return [a.format(**self.fill) for a in COMMANDS[command]]

    def without(self, args, option):
        """`args` without `option` and its value."""
        out, skip = [], False
        for a in args:
            if skip:
                skip = False
            elif a == option:
                skip = True
            else:
                out.append(a)
        return out

    def schema(self):
        if "schema" not in self._cache:
            self._cache["schema"] = json.loads(self.cli("schema", "specification").stdout)
        return self._cache["schema"]

    def record(self, name, *args, status=0):
        """A trial of 十 run once with `args`, its JSON record (read from NAME.json) and CSV trace bytes."""
        if name not in self._cache:
            result = self.cli("trial", "十", *args, "--json", f"{name}.json", "--csv", f"{name}.csv")
            self.assertEqual(result.returncode, status, result.stderr)
            self._cache[name] = (json.loads((self.tmp / f"{name}.json").read_text(encoding="utf-8")),
                                 (self.tmp / f"{name}.csv").read_bytes())
        return self._cache[name]

    R1 = ["--seed", "9007199254740993", "--rate", "500", "--max-duration", "120", "--corridor", "0.007",
          "--end-gap", "0.004", "--hint-after-misses", "2", "--assist-after-misses", "7", "--miss-min-path", "0",
          "--guidance-stiffness", "300"]
    # The same values spelt otherwise: `=`, exponents, a trailing zero, leading zeros on an integer.
    R2 = ["--seed=9007199254740993", "--rate=5e2", "--max-duration=1.2E2", "--corridor=7e-3",
          "--end-gap=0.0040", "--hint-after-misses=02", "--assist-after-misses=007", "--miss-min-path=0.0",
          "--guidance-stiffness=3e2"]

    def assert_refused(self, result, option, value=None):
        line = self.assert_one_error(result, 2, option)
        if value not in (None, ""):
            self.assertTrue(names_number(line, value.strip()), f"the value {value!r} is not named: {line}")
        return line

    # ---- the help against the schema and the docs ------------------------------------------------------
    def numeric_trial_options(self):
        return {name: o for name, o in self.help("trial").items() if o["range"] is not None}

    def field_for(self, option):
        if option in FIELD_OF:
            return FIELD_OF[option]
        props = self.schema()["properties"]
        base = option[2:].replace("-", "_")
        for suffix in ("", "_m", "_n_per_m", "_m_s", "_hz", "_s"):
            if base + suffix in props:
                return base + suffix, 1.0
        return None, None

    def test_help_finds_the_numeric_options_the_docs_table_lists(self):
        # The parse of the help is what every case below stands on: each numeric option of trial's table.
        found = self.numeric_trial_options()
        for option in ("--seed", "--rate", "--watchdog-ms", "--max-duration", "--corridor", "--max-gain-ratio",
                       "--hint-after-misses", "--assist-after-misses", "--guidance-gain", "--timing-speed",
                       "--guidance-stiffness", "--miss-min-path", "--end-gap-fraction"):
            self.assertIn(option, found)
        self.assertEqual(len(found), 31, sorted(found))

    def test_trial_help_default_and_range_are_the_schema_s(self):
        props = self.schema()["properties"]
        for option, o in self.numeric_trial_options().items():
            field, factor = self.field_for(option)
            with self.subTest(option=option, field=field):
                self.assertIsNotNone(field, "an option with no field of the specification")
                p = props[field]
                self.assertAlmostEqual(leading_number(o["default"]) * factor, p["default"], delta=1e-12)
                r = o["range"]
                lo = p.get("minimum", p.get("exclusiveMinimum"))
                hi = p.get("maximum", p.get("exclusiveMaximum"))
                scale = (lambda v: v) if factor == 1.0 else (lambda v: v * factor)
                self.assertEqual(scale(r.lo) if r.lo is not None else None, lo)
                self.assertEqual(scale(r.hi) if r.hi is not None else None, hi)
                self.assertEqual(r.lo_open, "exclusiveMinimum" in p)
                self.assertEqual(r.hi_open, "exclusiveMaximum" in p)
                # An option in another unit (whole ms for a field in s) is written as the integers it takes.
                self.assertEqual(r.kind == "int", p["type"] == "integer" or factor != 1.0)
        # The words: the schema's enumeration is the help's, its default the help's.
        helped = self.help("trial")
        for option, field in (("--guidance-mode", "guidance_mode"), ("--pacing", "pacing"),
                              ("--realtime", "realtime")):
            with self.subTest(option=option):
                self.assertEqual(helped[option]["words"], props[field]["enum"])
                self.assertEqual(helped[option]["default"], props[field]["default"])
        self.assertEqual(helped["--guidance"]["default"], {True: "on", False: "off"}[props["guidance"]["default"]])
        self.assertEqual(helped["--writer-profile"]["default"], props["writer_profile"]["default"])
        self.assertEqual(helped["--device"]["default"], props["device"]["default"])

    def test_score_and_train_give_the_options_they_share_with_trial_its_range_and_default(self):
        trial = self.help("trial")
        for command in ("score", "train"):
            for option, o in self.help(command).items():
                if option not in trial or o["range"] is None:
                    continue
                with self.subTest(command=command, option=option):
                    t = trial[option]
                    self.assertEqual(repr(o["range"]).split()[0], repr(t["range"]).split()[0])
                    if option != "--watchdog-ms":  # train's default depends on the device, as documented
                        self.assertEqual(leading_number(o["default"]), leading_number(t["default"]))
        # score: "every other field of the stroke acceptance, each option trial has for it with its unit,
        # range and default".
        score = self.help("score")
        for option in [n for n in trial if self.field_for(n)[0] in self.acceptance_fields()]:
            with self.subTest(score_lacks=option):
                self.assertIn(option, score)
                self.assertEqual(score[option]["desc"], trial[option]["desc"])

    def acceptance_fields(self):
        props = list(self.schema()["properties"])
        return props[props.index("corridor_m"):props.index("miss_min_path_m") + 1]

    def test_docs_specification_table_is_what_schema_markdown_prints(self):
        text = (SOURCE / "docs" / "cli.md").read_text(encoding="utf-8")
        table = text.split("<!-- schema specification -->\n", 1)[1].split("<!-- end schema specification -->")[0]
        printed = self.cli("schema", "specification", "--markdown").stdout.decode()
        self.assertEqual(printed.strip(), table.strip())

    def test_docs_tables_give_each_option_the_help_s_range_default_and_words(self):
        tables = docs_tables()
        self.assertIn("trial", tables)
        self.assertIn("bench loop", tables)
        for command, rows in tables.items():
            helped = self.help(command)
            for names, value, default in rows:
                for name in names:
                    with self.subTest(command=command, option=name):
                        self.assertIn(name, helped, f"docs/cli.md lists {name} for {command}; its help does not")
                if len(names) != 1 or names[0] not in helped:
                    continue
                o = helped[names[0]]
                with self.subTest(command=command, option=names[0], cell=value):
                    words = doc_words(value)
                    if words and o["words"]:
                        self.assertEqual(words, o["words"])
                    r = parse_range(value, dash=True)
                    if r is not None and o["range"] is not None:
                        self.assertEqual((r.lo, r.hi), (o["range"].lo, o["range"].hi))
                        if r.kind == "real" and o["range"].kind == "real" and re.search(r"[\[(]", value):
                            self.assertEqual((r.lo_open, r.hi_open), (o["range"].lo_open, o["range"].hi_open))
                    elif r is not None:
                        self.fail(f"the docs give {value!r}, the help no range: {o['desc']!r}")
                    dn, hn = leading_number(default.replace("`", "")), leading_number(o["default"])
                    if dn is not None and hn is not None:
                        self.assertEqual(dn, hn, f"docs {default!r}, help {o['default']!r}")

    def test_every_option_of_the_help_is_in_the_docs(self):
        synopses = {}
        tables = docs_tables(synopses)
        for command, rows in tables.items():
            # The table, or the command's line above it (`curriculum ... [--data DIR | --store FILE]`).
            listed = {n for names, _, _ in rows for n in names} | synopses.get(command, set())
            for option in self.help(command):
                if option in ("--version", "--verbose"):
                    continue
                with self.subTest(command=command, option=option):
                    self.assertIn(option, listed)

    # ---- trial: the ends of each range ---------------------------------------------------------------
    def test_trial_takes_every_inclusive_end_of_every_range(self):
        options = self.numeric_trial_options()
        groups = {"lo": [], "hi": []}
        special = {}
        for option, o in options.items():
            r = o["range"]
            for end, text in (("lo", r.lo_text if not r.lo_open and r.lo is not None else None),
                              ("hi", r.hi_text if not r.hi_open and r.hi is not None else None)):
                if text is None:
                    continue
                if option == "--rate" and end == "hi":
                    special.setdefault(option, []).append(text)
                elif option in TRIAL_CONTEXT and option not in ("--watchdog-ms", "--rate", "--max-duration"):
                    special.setdefault(option, []).append(text)
                else:
                    groups[end] += [option, text]
        # All the lower ends together, then all the upper ends, real-time (so that --watchdog-ms is taken);
        # 86400 s at 100 Hz stays within 10^7 ticks; --rate's upper end on its own, each mode's ends in it.
        runs = [groups["lo"] + ["--pacing", "real-time"],
                groups["hi"] + ["--pacing", "real-time", "--rate", options["--rate"]["range"].lo_text]]
        for option, texts in special.items():
            for text in texts:
                runs.append(TRIAL_CONTEXT[option] + [option, text])
        for args in runs:
            with self.subTest(args=" ".join(args)):
                result = self.cli("trial", "十", *args, "--check")
                self.assertEqual(result.returncode, 0, result.stderr.decode())
                self.assertEqual(len(result.stdout.decode().strip().splitlines()), 1)

    def test_trial_refuses_one_past_each_end_naming_option_and_value(self):
        # Both ends of the trial's own options. The stroke acceptance's 22 come from one table (the same on
        # score): the lower end of the first option of each form of lower end ((0, [0, [1, 0..), the upper end
        # of each that is not a length, and of the first, a middle and the last of the 12 lengths (0.1 m).
        acceptance = {"--" + f.removesuffix("_m").replace("_", "-") for f in self.acceptance_fields()}
        options = self.numeric_trial_options()
        lengths = [n for n in options if n in acceptance and options[n]["range"].hi == 0.1]
        self.assertEqual(len(lengths), 12, lengths)
        sampled = {lengths[0], lengths[len(lengths) // 2], lengths[-1]}
        forms_seen = set()
        for option, o in options.items():
            values = o["range"].refused()
            if option in acceptance:
                form = (o["range"].kind, o["range"].lo, o["range"].lo_open)
                lo, hi = (values[:1] if form not in forms_seen else []), values[1:]
                forms_seen.add(form)
                values = lo + (hi if option not in lengths or option in sampled else [])
            for value in values:
                with self.subTest(option=option, value=value):
                    extra = TRIAL_CONTEXT.get(option, [])
                    result = self.cli("trial", "十", *extra, f"{option}={value}", "--check")
                    self.assert_refused(result, option, value)

    def test_trial_tick_limit_is_ten_million_at_the_rate(self):
        self.assertEqual(self.cli("trial", "十", "--max-duration", "10000", "--check").returncode, 0)
        result = self.cli("trial", "十", "--max-duration", "10000.001", "--check")
        self.assert_one_error(result, 2, "--max-duration")

    def test_trial_real_time_rate_is_at_most_ten_thousand(self):
        ok = self.cli("trial", "十", "--pacing", "real-time", "--rate", "10000", "--check")
        self.assertEqual(ok.returncode, 0, ok.stderr)
        self.assert_one_error(self.cli("trial", "十", "--pacing", "real-time", "--rate", "10001", "--check"), 2,
                              "--rate")

    def test_trial_watchdog_ms_with_lock_step_is_refused(self):
        # "real-time pacing only (an error with lock-step)"
        self.assert_one_error(self.cli("trial", "十", "--watchdog-ms", "20", "--check"), 2, "--watchdog-ms")

    def test_watchdog_ms_takes_whole_milliseconds_only(self):
        for command, args in (("trial", ["--pacing", "real-time", "--check"]), ("train", [])):
            with self.subTest(command=command):
                self.assert_refused(self.cli(command, "十", *args, "--watchdog-ms", "20.5"), "--watchdog-ms", "20.5")

    def test_trial_mode_options_out_of_their_mode_are_usage_errors(self):
        self.assert_one_error(self.cli("trial", "十", "--guidance-gain", "0.5", "--check"), 2, "--guidance-gain")
        self.assert_one_error(self.cli("trial", "十", "--guidance", "off", "--guidance-stiffness", "300",
                                       "--check"), 2, "--guidance-stiffness")

    # ---- trial: spellings of a number ------------------------------------------------------------------
    def test_integer_option_takes_decimal_digits_only(self):
        # "an integer option takes decimal digits only (2x, 1.5, 0x10, 1e3 are errors)"
        for value in ("0x10", "1e3", "1.5", "2x", " 5", "", "+5", "-0", "\uff15", "1" + "0" * 399):
            with self.subTest(value=value):
                self.assert_refused(self.cli("trial", "十", f"--hint-after-misses={value}", "--check"),
                                    "--hint-after-misses", value if value.strip() else None)

    def test_seed_is_read_exactly_to_two_to_the_64(self):
        self.assertEqual(self.cli("trial", "十", "--seed", "18446744073709551615", "--check").returncode, 0)
        for value in ("18446744073709551616", "1e19"):
            with self.subTest(value=value):
                self.assert_refused(self.cli("trial", "十", f"--seed={value}", "--check"), "--seed", value)

    def test_real_option_must_be_finite_and_whole(self):
        # "a real number must be finite (nan, inf are errors). The error names the option and the value."
        for value in ("nan", "inf", "-inf", "1e309", "1" + "0" * 399, "5mm", "0,005", " 0.005", "", "5e-3x"):
            with self.subTest(value=value):
                self.assert_refused(self.cli("trial", "十", f"--corridor={value}", "--check"), "--corridor",
                                    value if value.strip() else None)

    def test_guidance_stiffness_without_upper_end_refuses_overflow(self):
        # ">= 0 N/m": no upper end, but a real must be finite: 1e309 is no double.
        for value in ("1e309", "inf"):
            with self.subTest(value=value):
                self.assert_refused(self.cli("trial", "十", "--guidance-stiffness", value, "--check"),
                                    "--guidance-stiffness", value)

    def test_trial_option_given_twice_is_an_error_even_with_one_value(self):
        # "giving it twice is an error (no silent "last one wins")"
        for args in (["--seed", "1", "--seed", "2"], ["--seed", "1", "--seed=1"],
                     ["--corridor", "0.005", "--corridor", "0.005"]):
            with self.subTest(args=args):
                self.assert_one_error(self.cli("trial", "十", *args, "--check"), 2, args[0])

    def test_options_of_other_commands_given_twice_are_errors(self):
        for command, args in (("score", ["--units", "m", "--units", "data"]),
                              ("characters", ["--strokes", "2", "--strokes", "2"]),
                              ("curriculum", ["--count", "2", "--count", "3"]),
                              ("session plan", ["--subjects", "2"]),
                              ("bench loop", ["--cpu", "-1", "--cpu", "-1"])):
            with self.subTest(command=command):
                self.assert_one_error(self.cli(*command.split(), *self.context(command), *args), 2, args[0])

    def test_flag_given_a_value_is_refused_and_true_is_the_flag(self):
        line = self.assert_one_error(self.cli("trial", "十", "--check=yes"), 2, "--check")
        self.assertIn("flag takes no value", line)
        self.assert_one_error(self.cli("characters", "--text", "十", "--json=0"), 2, "--json")
        ok = self.cli("characters", "--text", "十", "--json=true")
        self.assertEqual(ok.returncode, 0, ok.stderr)
        self.assertEqual(json.loads(ok.stdout)["count"], 1)

    def test_value_starting_with_a_dash_is_refused_naming_the_option_before_it(self):
        result = self.cli("trial", "十", "--csv", "--seed", "3")
        self.assert_one_error(result, 2, "--csv")
        self.assertFalse((self.tmp / "--seed").exists())

    # ---- the other commands: each numeric option from its help ---------------------------------------
    def test_other_commands_refuse_past_each_end_before_reading_anything(self):
        for command in COMMANDS:
            if command in ("trial", "score"):
                continue
            base = self.context(command)
            for option, o in self.help(command).items():
                r = o["range"]
                if r is None:
                    continue
                values = r.refused()
                # A lower end of 0 or 1 (an integer count) and the lower end of a real (tried on trial) once: here
                # the upper end, a lower end of another form (-1) and the exclusive 0 of a real with no upper end
                # or of the first command with (0, 86400].
                if len(values) == 2 and ((r.kind == "int" and r.lo in (0, 1)) or (r.kind == "real" and (
                        not r.lo_open or (r.hi == 86400 and command != "train")))):
                    values = values[1:]
                # train's seed and miss counts are the trial specification's fields, tried on trial.
                if command == "train" and option in ("--seed", "--hint-after-misses", "--assist-after-misses"):
                    continue
                for value in values:
                    with self.subTest(command=command, option=option, value=value):
                        args = self.without(base, option) + [f"{option}={value}"]
                        result = self.cli(*command.split(), *args)
                        self.assert_refused(result, option, value)
        self.assertFalse((self.tmp / "out").exists(), "session run made its --out folder")
        self.assertFalse((self.tmp / "store.clg").exists(), "corpus build wrote its store")

    def test_score_refuses_a_length_in_millimetres_and_a_count_past_its_range(self):
        trace = self.trace()
        for option, value in (("--corridor", "6.5"), ("--assist-after-misses", "1001"),
                              ("--shortfall-fraction", "1")):
            with self.subTest(option=option):
                self.assert_refused(self.cli("score", trace, "--character", "十", option, value, "--json",
                                             "s.json"), option, value)
        self.assertFalse((self.tmp / "s.json").exists())

    def test_score_takes_every_end_of_the_acceptance_ranges(self):
        trace = self.trace()
        score = self.help("score")
        for end in ("lo", "hi"):
            args = []
            for option, o in score.items():
                r = o["range"]
                if r is None:
                    continue
                text = (r.lo_text if not r.lo_open else None) if end == "lo" else (r.hi_text if not r.hi_open
                                                                                    else None)
                if text is not None:
                    args += [option, text]
            with self.subTest(end=end, args=" ".join(args)):
                result = self.cli("score", trace, "--character", "十", *args, "--json", "-")
                self.assertEqual(result.returncode, 0, result.stderr.decode())
                self.assertEqual(json.loads(result.stdout)["character"], "十")

    def test_bench_loop_watchdog_is_at_most_sixty_seconds_of_periods(self):
        ok = self.cli("bench", "loop", "--seconds", "0.01", "--realtime", "off", "--rate", "100",
                      "--watchdog-periods", "6000", "--json")
        self.assertEqual(ok.returncode, 0, ok.stderr)
        line = self.assert_one_error(self.cli("bench", "loop", "--seconds", "0.01", "--realtime", "off", "--rate",
                                              "100", "--watchdog-periods", "6001"), 2, "--watchdog-periods")
        self.assertIn("--rate", line)

    def test_bench_acceptance_kanjivg_options_without_kanjivg_are_named(self):
        self.assert_one_error(self.cli("bench", "acceptance", "--characters", "1", "--half", "both"), 2, "--half")

    def test_corpus_fidelity_tolerances_each_a_positive_number(self):
        for value in ("2,,5", "2,0", "2,nan", "2;5"):
            with self.subTest(value=value):
                self.assert_one_error(self.cli("corpus", "fidelity", "--data", self.fill["empty"],
                                               f"--tolerances={value}"), 2, "--tolerances")

    def test_train_window_size_within_its_bounds(self):
        # "window size in pixels (at least 800x480, at most 8192x8192)"; a taken size goes on to the window,
        # which has no display here (exit 1), a refused one is a usage error before it (exit 2).
        for value in ("800x480", "8192x8192"):
            with self.subTest(value=value):
                result = self.cli("train", "十", "--window", value)
                self.assertNotEqual(result.returncode, 2, result.stderr)
        for value in ("799x480", "8193x800", "1280x800x1"):
            with self.subTest(value=value):
                self.assert_one_error(self.cli("train", "十", "--window", value), 2, "--window")

    # ---- words ---------------------------------------------------------------------------------------
    def word_options(self):
        """(command, option, words) for each list of words an option takes, each list once (the first option
        and command that take it)."""
        seen, out = set(), []
        for command in COMMANDS:
            for option, o in self.help(command).items():
                if o["words"] and tuple(o["words"]) not in seen:
                    seen.add(tuple(o["words"]))
                    out.append((command, option, o["words"]))
        return out

    def test_word_options_refuse_other_spellings(self):
        options = self.word_options()
        self.assertGreaterEqual(len(options), 12)
        for i, (command, option, words) in enumerate(options):
            hyphenated = [w for w in words if "-" in w]
            if hyphenated:
                value = hyphenated[0].replace("-", "_")
            elif words[0].isdigit():
                value = str(int(words[-1]) * 2)
            elif i % 2 or len(words[0]) < 3:
                value = words[0].capitalize() if len(words[0]) > 1 else words[0].upper()
            else:
                value = words[0][:-1]
            with self.subTest(command=command, option=option, value=value):
                args = self.context(command)
                if command == "trial":
                    args = args + ["--max-duration", "5"]
                result = self.cli(*command.split(), *args, option, value)
                self.assert_one_error(result, 2, option)

    def test_old_writer_values_name_the_spelling_to_use(self):
        line = self.assert_one_error(self.cli("trial", "十", "--writer", "novice"), 2, "--writer")
        self.assertIn("--writer is who writes (person or simulated); the profile is --writer-profile novice", line)
        line = self.assert_one_error(self.cli("session", "run", *self.context("session run"), "--writer", "human"),
                                     2, "--writer")
        self.assertIn("--writer person", line)

    def test_device_names_are_spelt_as_devices_lists_them(self):
        line = self.assert_one_error(self.cli("trial", "十", "--device", "Simulated"), 2, "Simulated")
        self.assertIn("simulated", line)
        line = self.assert_one_error(self.cli("trial", "十", "--device", "mouse"), 2, "mouse")
        self.assertIn("train", line)

    def test_typical_stroke_in_every_documented_spelling(self):
        # docs/typical-strokes.md: | 10 | HZG | 横折钩 | ... | U+31C6 ㇆ |; 月 has one, 十 none.
        for value in ("HZG", "hzg", "横折钩", "\u31c6", "10"):
            with self.subTest(value=value):
                result = self.cli("characters", "--text", "月十", "--typical", value, "--json")
                self.assertEqual(result.returncode, 0, result.stderr)
                self.assertEqual([c["character"] for c in json.loads(result.stdout)["characters"]], ["月"])
        line = self.assert_one_error(self.cli("characters", "--text", "月十", "--typical", "HZGG"), 2, "--typical")
        self.assertIn("HZG", line)

    def test_schema_document_words_are_the_one_spelling(self):
        for value in ("Specification", "records"):
            with self.subTest(value=value):
                self.assert_one_error(self.cli("schema", value), 2)

    # ---- what a run records ------------------------------------------------------------------------
    def trace(self):
        self.record("r1", *self.R1)
        return str(self.tmp / "r1.csv")

    def test_trial_records_the_values_given_in_the_documented_units(self):
        r, _ = self.record("r1", *self.R1)
        spec = r["specification"]
        trial, acceptance = spec["trial"], spec["force_law"]["acceptance"]
        self.assertEqual(trial["seed"], 9007199254740993)
        self.assertIs(type(trial["seed"]), int)
        self.assertEqual(r["seed"], 9007199254740993)
        expected = {"rate_hz": 500, "max_duration_s": 120, "corridor_m": 0.007, "end_gap_m": 0.004,
                    "hint_after_misses": 2, "assist_after_misses": 7, "miss_min_path_m": 0,
                    "guidance_stiffness_n_per_m": 300}
        for key, value in expected.items():
            with self.subTest(key=key):
                self.assertEqual(trial[key], value)
                if key in acceptance:
                    self.assertEqual(acceptance[key], value)
        self.assertEqual(r["rate_hz"], 500)
        # Every field not given is the schema's default.
        for key, p in self.schema()["properties"].items():
            # writer and pacing: `auto` is recorded as what it chose (the record states the trial that ran).
            if key in expected or key in ("seed", "characters", "writer", "pacing", "json_file", "csv_file") or \
                    "default" not in p:
                continue
            with self.subTest(default=key):
                self.assertEqual(trial[key], p["default"])

    def test_equals_form_and_other_spellings_give_the_same_trial(self):
        a, a_csv = self.record("r1", *self.R1)
        b, b_csv = self.record("r2", *self.R2)
        self.assertEqual(b["specification"]["trial"] | {"json_file": "", "csv_file": ""},
                         a["specification"]["trial"] | {"json_file": "", "csv_file": ""})
        self.assertEqual(b["specification"]["force_law"], a["specification"]["force_law"])
        self.assertEqual(b_csv, a_csv)

    def test_time_limit_is_max_duration_times_rate_ticks_in_seconds(self):
        r, data = self.record("r3", "--rate", "200", "--max-duration", "0.25", status=1)
        self.assertEqual(r["end_reason"], "time_limit")
        self.assertEqual((r["specification"]["trial"]["rate_hz"], r["specification"]["trial"]["max_duration_s"]),
                         (200, 0.25))
        rows = list(csv.DictReader(io.StringIO(data.decode())))
        self.assertEqual(len(rows), 50, "0.25 s x 200 Hz")
        t = [float(row["t"]) for row in rows]
        for step in (b - a for a, b in zip(t, t[1:])):
            self.assertAlmostEqual(step, 0.005, delta=2e-6)

    def test_watchdog_ms_is_recorded_in_seconds(self):
        result = self.cli("trial", "十", "--pacing", "real-time", "--watchdog-ms", "250", "--max-duration", "0.05",
                          "--json", "rt.json")
        self.assertIn(result.returncode, (0, 1), result.stderr)
        spec = json.loads((self.tmp / "rt.json").read_text(encoding="utf-8"))["specification"]["trial"]
        self.assertEqual(spec["watchdog_s"], 0.25)
        self.assertEqual(spec["pacing"], "real-time")

    def test_mode_values_are_recorded_in_their_units_and_spelling(self):
        for mode, option, value, field in (("assist-as-needed", "--assist-band", "0.002", "assist_band_m"),
                                           ("timing", "--timing-speed", "0.05", "timing_speed_m_s"),
                                           ("fading", "--guidance-gain", "0.4", "guidance_gain")):
            with self.subTest(mode=mode):
                result = self.cli("trial", "十", "--guidance-mode", mode, f"{option}={value}", "--json", "-")
                self.assertEqual(result.returncode, 0, result.stderr)
                r = json.loads(result.stdout)
                self.assertEqual(r["specification"]["trial"][field], float(value))
                self.assertEqual(r["specification"]["trial"]["guidance_mode"], mode)
                self.assertEqual(r["guidance_mode"], mode)
                law = r["specification"]["force_law"]["guidance_law"]
                self.assertEqual(law["mode"], mode)
                self.assertIn(float(value), [v for v in law.values() if isinstance(v, float)])
                if mode == "fading":
                    self.assertEqual(r["guidance_gain"], 0.4)

    def test_score_units_word_is_what_its_json_says(self):
        trace = self.trace()
        outs = {}
        for args in ([], ["--units", "m"], ["--units=data"]):
            result = self.cli("score", trace, "--character", "十", *args, "--json", "-")
            self.assertEqual(result.returncode, 0, result.stderr)
            outs[" ".join(args)] = json.loads(result.stdout)
        self.assertEqual(outs[""], outs["--units m"])
        self.assertEqual(outs[""]["units"], "m")
        self.assertEqual(outs["--units=data"]["units"], "data")


if __name__ == "__main__":
    unittest.main()
