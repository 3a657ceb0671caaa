#!/usr/bin/env python3
"""Round 14F: hostile cases written from the documentation alone (README.md, docs/cli.md, docs/trainer.md,
docs/stroke-acceptance.md, docs/metrics.md, docs/devices.md and each command's `--help`) on every line a
person reads: the help of every command and subcommand, the usage errors of every option, the tables and
one-line summaries of `trial` and `score`, `devices`, and the library's log on standard error. Run by CTest
as `cli_unseen_round14f_tests`.

Each help is held to docs/cli.md: every option of a command's help is in the command's section and every
option of its tables in its help, with the same range, one default and one meaning of `-` stated once, a
number's unit in brackets, a value naming a file read `FILE`, one value name per option name, the top-level
help listing every command the docs describe, `--version` anywhere. Every option of every command given a
wrong value (an enumeration a name it lacks, a number `nan` and past its range, a flag a value): exit 2,
exactly one line on standard error naming the command and the option, nothing on standard output, nothing
written; a misspelt command, subcommand and option name the near one. The summaries of a trial on 一 and 十
(strokes numbered from 1, millimetres, one verdict per stroke) against the JSON of the same run, for a
trial that wrote every stroke, one whose strokes were credited as assisted, one stopped by its time limit at
0.05 s and one stopped by SIGINT after 0.3 s (no "nan", the counts and the time of the JSON); `score`'s
verdicts, the distance of a refused pen-down and the stroke that was due against its JSON, its units;
`session run`'s line per session and its stop by SIGINT; `train` without a display; the library's info lines
only with `--verbose`, on standard error in the command's own form; `devices` listing every kind with the
commands that take it, in text and `--json`, as docs/cli.md's table, and an unknown device named once;
messages naming a character by itself and its code point, a file name quoted on one line.

CALLIGRAPHY_CLI names the program, CALLIGRAPHY_SOURCE_DIR the source tree (its docs). CALLIGRAPHY_SANITIZED=1
takes five cases.
"""
import json
import os
import re
import signal
import subprocess
import tempfile
import time
import unittest
from pathlib import Path

from outsider import CLI, ENV, OneErrorLine, error_lines, run, sanitized_subset

SOURCE = Path(os.environ.get("CALLIGRAPHY_SOURCE_DIR", Path(__file__).resolve().parents[2]))
CLI_MD = (SOURCE / "docs" / "cli.md").read_text(encoding="utf-8")

load_tests = sanitized_subset({"test_misspelt_command_is_one_error_line_naming_the_near_ones",
                               "test_every_help_option_is_in_its_commands_section_of_the_docs",
                               "test_trial_time_limit_summary_has_the_counts_and_no_nan",
                               "test_devices_lists_every_kind_with_its_commands_as_the_docs",
                               "test_usage_error_writes_nothing_and_names_the_option"})

# Every command and subcommand of docs/cli.md, with a positional that lets the parser reach its options.
COMMANDS = {
    "trial": ["一"], "train": ["一"], "score": ["t.csv"], "trace": ["t.trace.h5"], "model": ["一"],
    "strokes": [], "schema": ["record"], "characters": [], "devices": [], "curriculum": ["d"], "report": ["d"],
    "corpus build": [], "corpus stats": ["s.clg"], "corpus fidelity": [], "corpus validate": [],
    "bench nearest": [], "bench jumps": [], "bench tick": [], "bench loop": [], "bench acceptance": [],
    "session run": ["p.json"], "session resume": ["d"], "session plan": ["p.json"], "session cohort": ["p.json"],
}
NUMBER_VALUES = {"N", "HZ", "S", "SECONDS", "MS", "M", "G", "X", "N/M", "M/S", "MM"}
SHARED = {}


def help_of(command):
    """The help of `command` (cached; "" the program's own): exit 0, nothing on standard error."""
    if command not in SHARED.setdefault("help", {}):
        result = run([*command.split(), "--help"], cwd="/")
        SHARED["help"][command] = result
    return SHARED["help"][command]


def help_options(text):
    """(name, value) of every option line of a help, --help and --version left out; value None for a flag."""
    found = []
    for match in re.finditer(r"^  (?:-\w,)?(--[a-z][a-z0-9-]*)(?: ([^ \n]+))?", text, flags=re.M):
        if match.group(1) not in ("--help", "--version"):
            found.append((match.group(1), match.group(2)))
    return found


def help_text(command):
    return help_of(command).stdout.decode("utf-8")


def docs_sections():
    """docs/cli.md's text per command: each `## ` section, and within a section that documents several
    subcommands, each subcommand's paragraphs from its "`calligraphy GROUP SUB" to the next one."""
    sections = {}
    for part in re.split(r"^## ", CLI_MD, flags=re.M)[1:]:
        title, body = part.split("\n", 1)
        words = title.split()
        if "|" not in title:
            sections[title.strip()] = body
            continue
        group = words[0]
        # A subcommand's text starts a paragraph; a line that only quotes one ("`calligraphy session resume DIR`
        # goes on ...") within another's paragraph does not start it.
        body = "\n" + body
        starts = [(m.start(), m.group(1)) for m in
                  re.finditer(rf"(?:\A|\n\n)`calligraphy {group} ([a-z]+)", body)]
        for i, (start, sub) in enumerate(starts):
            end = starts[i + 1][0] if i + 1 < len(starts) else len(body)
            sections.setdefault(f"{group} {sub}", "")
            sections[f"{group} {sub}"] += body[start:end]
    return sections


def table_options(section):
    """The options of the option tables of a section: the first cell of each row that starts with `--`."""
    names = set()
    for line in section.splitlines():
        if line.startswith("| `--"):
            names |= set(re.findall(r"`(--[a-z][a-z0-9-]*)`", line.split("|")[1]))
    return names


def no_nan(testcase, text):
    testcase.assertIsNone(re.search(r"\b(nan|inf)\b", text, flags=re.I), text)


def table_rows(text):
    """The per-stroke rows of a `trial` or `score` table: lines that start with a stroke number."""
    return [line.split() for line in text.splitlines() if re.match(r"^  \d+\s", line)]


def summary_value(text, label):
    for line in text.splitlines():
        if line.strip().startswith(label):
            return line.strip()[len(label):].strip()
    raise AssertionError(f"no line '{label}' in {text}")


def trial(folder, name, *options, **kw):
    """`trial` with a JSON and CSV of its own in `folder`: (result, record)."""
    json_path, csv_path = Path(folder) / f"{name}.json", Path(folder) / f"{name}.csv"
    result = run(["trial", *options, "--json", json_path, "--csv", csv_path], cwd=folder, **kw)
    record = json.loads(json_path.read_text()) if json_path.exists() else None
    return result, record


TRIALS = {  # the round's trials, each run once when a case first asks for it
    "written": ["十"],  # 十 written by the simulated novice
    "one": ["一"],
    # 十 written backwards with guidance off, each stroke credited as assisted after one miss
    "assisted": ["十", "--guidance", "off", "--writer-param", "backwards_probability=1", "--assist-after-misses", "1",
                 "--max-duration", "20"],
    "time_limit": ["十", "--max-duration", "0.05"],  # stopped by its time limit before a stroke
}


def shared_trial(name):
    """(folder, (result, record)) of the shared trial `name`; its files are NAME.json and NAME.csv in folder."""
    if "folder" not in SHARED:
        SHARED["folder"] = tempfile.mkdtemp(prefix="round14f-")
    trials = SHARED.setdefault("trials", {})
    if name not in trials:
        trials[name] = trial(SHARED["folder"], name, *TRIALS[name])
    return SHARED["folder"], trials[name]


def tearDownModule():
    if "folder" in SHARED:
        subprocess.run(["rm", "-rf", SHARED["folder"]], check=False)


class Help(unittest.TestCase):
    """Every command's help against docs/cli.md."""

    def test_every_help_exits_0_on_standard_output_alone(self):
        for command in ["", *COMMANDS, "corpus", "bench", "session"]:
            with self.subTest(command=command):
                result = help_of(command)
                self.assertEqual(result.returncode, 0, result.stderr)
                self.assertEqual(result.stderr, b"")
                self.assertIn(b"Usage: calligraphy", result.stdout)

    def test_top_level_help_lists_every_command_the_docs_list(self):
        listed = set(re.findall(r"^  ([a-z]+)\s", help_text(""), flags=re.M))
        documented = {title.split()[0] for title in re.findall(r"^## ([a-z][a-z |]*)$", CLI_MD, flags=re.M)}
        documented |= {command.split()[0] for command in COMMANDS}
        self.assertEqual(documented - listed, set())
        self.assertEqual(listed - documented, set())
        for group, subs in (("corpus", {"build", "stats", "fidelity", "validate"}),
                            ("bench", {"nearest", "jumps", "tick", "loop", "acceptance"}),
                            ("session", {"run", "resume", "plan", "cohort"})):
            got = set(re.findall(r"^  ([a-z]+)\s", help_text(group), flags=re.M))
            self.assertEqual(got, subs, group)

    def test_every_command_the_docs_quote_is_one(self):
        # `calligraphy WORD [SUB]` in README.md and docs/*.md: WORD a command of the help, SUB one of its
        # group's; `trail`, docs/cli.md's example of a mistyped command, the one exception.
        top = set(re.findall(r"^  ([a-z]+)\s", help_text(""), flags=re.M))
        groups = {group: set(re.findall(r"^  ([a-z]+)\s", help_text(group), flags=re.M))
                  for group in ("corpus", "bench", "session")}
        quoted = set()
        for document in [SOURCE / "README.md", *sorted((SOURCE / "docs").glob("*.md"))]:
            text = document.read_text(encoding="utf-8")
            quoted |= set(re.findall(r"`calligraphy ([a-z]+)(?:\s+([a-z]+))?", text))
        self.assertGreater(len(quoted), 20)
        for word, sub in quoted:
            with self.subTest(command=f"{word} {sub}".strip()):
                if word == "trail":
                    continue
                self.assertIn(word, top)
                if word in groups:
                    self.assertIn(sub, groups[word])

    def test_every_help_option_is_in_its_commands_section_of_the_docs(self):
        sections = docs_sections()
        for command in COMMANDS:
            with self.subTest(command=command):
                documented = set(re.findall(r"--[a-z][a-z0-9-]*", sections[command]))
                shown = {name for name, _ in help_options(help_text(command))} - {"--verbose"}
                self.assertEqual(shown - documented, set(), f"{command}: in --help, not in docs/cli.md")

    def test_every_documented_option_is_in_its_help(self):
        sections = docs_sections()
        for command in COMMANDS:
            with self.subTest(command=command):
                shown = {name for name, _ in help_options(help_text(command))}
                self.assertEqual(table_options(sections[command]) - shown, set(),
                                 f"{command}: in docs/cli.md's table, not in --help")

    def test_documented_ranges_are_the_helps(self):
        # docs/cli.md's tables give each number's range ("0..1", ">= 0", "(0, 86400]"); the help gives it
        # from the specification's schema. A bound one states and the other leaves out is a value one accepts
        # and the other refuses.
        def bounds(text):
            text = text.replace("2^64-1", "18446744073709551615").replace("10^8", "100000000")
            text = text.replace("10^6", "1000000")
            match = re.search(r"[\[(](-?[\d.]+), (-?[\d.]+)[\])]", text) or \
                re.search(r"(?<![\w.])(-?[\d.]+)\.\.(\d[\d.]*)", text)
            if match:  # (low, high, whether the low bound is open)
                return float(match.group(1)), float(match.group(2)), match.group(0).startswith("(")
            match = re.search(r"(>=?) (-?[\d.]+)", text)
            return (float(match.group(2)), None, match.group(1) == ">") if match else None

        checked = 0
        for command, section in docs_sections().items():
            if command in COMMANDS:
                checked += self.ranges_agree(command, section, bounds)
        self.assertGreater(checked, 15)

    def ranges_agree(self, command, section, bounds):
        text = help_text(command)
        checked = 0
        for line in section.splitlines():
            cells = [cell.strip() for cell in re.split(r"(?<!\\)\|", line.strip().strip("|"))]
            names = re.findall(r"`(--[a-z0-9-]+)`", cells[0]) if line.startswith("| `--") else []
            if len(names) != 1 or bounds(cells[1]) is None:
                continue
            shown = next(entry for entry in text.split("\n  --")[1:] if entry.startswith(names[0][2:] + " "))
            with self.subTest(command=command, option=names[0], documented=cells[1]):
                self.assertEqual(bounds(cells[1]), bounds(shown.split("(default:")[0]), shown)
                checked += 1
        return checked

    def test_each_option_states_its_default_once_and_dash_once(self):
        for command in COMMANDS:
            text = help_text(command)
            # An option's text may wrap onto lines of its own: join each option with its continuation lines.
            entries = re.split(r"\n(?=  -)", text.split("Options:", 1)[1].split("\n\n")[0])
            for entry in filter(str.strip, entries):
                with self.subTest(command=command, option=entry.split()[0]):
                    self.assertLessEqual(entry.count("(default:"), 1, entry)
                    self.assertLessEqual(entry.count("'-'"), 1, entry)  # what '-' means, said once
                    if "(default:" in entry:
                        self.assertTrue(entry.rstrip().endswith(")"), entry)

    def test_a_value_that_names_a_file_reads_FILE(self):
        for command in COMMANDS:
            positionals = help_text(command).split("Positionals:", 1)
            if len(positionals) == 1:
                continue
            for line in positionals[1].split("\n\n")[0].splitlines():
                match = re.match(r"^  ([A-Z]+) ([A-Z]+)(?: [A-Z. ]+)?\s{2,}(\S.*)$", line)
                if not match:  # an enumeration's values (`schema DOCUMENT`) or a wrapped description
                    continue
                name, kind, description = match.groups()
                # What the description names first, a file or a folder, is what the value reads.
                first = re.search(r"\b(file|folders?)\b", description)
                with self.subTest(command=command, positional=name):
                    if first and first.group(1) == "file":
                        self.assertEqual(kind, "FILE", line)
                    elif first:
                        self.assertEqual(kind, "DIR", line)
            for name, value in help_options(help_text(command)):
                if value in ("FILE", "FILE|-", "RECORD"):
                    continue
                line = next(line for line in help_text(command).splitlines() if line.startswith(f"  {name} "))
                with self.subTest(command=command, option=name):
                    self.assertNotIn(value, ("TEXT", "PATH"), line)

    def test_a_number_with_a_unit_states_it_in_brackets(self):
        # The unit in brackets, alone or before the range ("[s, (0, 86400]]").
        units = {"M": "m", "S": "s", "SECONDS": "s", "MS": "ms", "HZ": "Hz", "N/M": "N/m", "M/S": "m/s", "MM": "mm"}
        checked = 0
        for command in COMMANDS:
            text = help_text(command)
            for name, value in help_options(text):
                if value not in units:
                    continue
                entry = text.split(f"\n  {name} {value}", 1)[1].split("\n  -", 1)[0]
                with self.subTest(command=command, option=name):
                    self.assertRegex(entry, rf"\[{re.escape(units[value])}[],]", f"{name} {value}{entry}")
                    checked += 1
        self.assertGreater(checked, 20)

    def test_one_value_name_per_option_name(self):
        # --seed is a number of no unit everywhere: never `S`, which names seconds.
        spelt = {}
        for command in COMMANDS:
            for name, value in help_options(help_text(command)):
                if name in ("--seed", "--rate", "--data", "--store", "--json", "--subjects", "--pacing", "--threads"):
                    spelt.setdefault(name, {}).setdefault(value, []).append(command)
        self.assertEqual({value for value in spelt["--seed"]}, {"N"}, spelt["--seed"])
        for name in ("--rate", "--data", "--store", "--threads"):
            self.assertEqual(len(spelt[name]), 1, (name, spelt[name]))

    def test_every_command_takes_verbose(self):
        for command in COMMANDS:
            with self.subTest(command=command):
                self.assertIn("--verbose", {name for name, _ in help_options(help_text(command))})

    def test_version_anywhere_is_the_version_alone(self):
        versions = set()
        for command in ("", "trial", "session run", "corpus stats", "bench loop"):
            result = run([*command.split(), "--version"], cwd="/")
            self.assertEqual(result.returncode, 0, result.stderr)
            self.assertEqual(result.stderr, b"")
            self.assertRegex(result.stdout.decode(), r"^calligraphy \d+\.\d+\.\d+\n$")
            versions.add(result.stdout)
        self.assertEqual(len(versions), 1)


class UsageErrors(unittest.TestCase, OneErrorLine):
    """The usage errors of every option of every command, swept from its help."""

    def sweep(self, make_bad):
        checked = 0
        for command, positional in COMMANDS.items():
            for name, value in help_options(help_text(command)):
                bad = make_bad(name, value)
                if bad is None:
                    continue
                with self.subTest(command=command, given=bad), tempfile.TemporaryDirectory() as folder:
                    result = run([*command.split(), *positional, *bad], cwd=folder)
                    line = self.assert_one_error(result, 2, f"calligraphy {command}: error:", name)
                    self.assertEqual(result.stdout, b"", line)
                    self.assertEqual(os.listdir(folder), [], line)
                    checked += 1
        return checked

    def test_every_enumeration_given_a_name_it_lacks(self):
        def bad(name, value):
            if value and "|" in value and not value.startswith("FILE") and not value.endswith(".json"):
                return [name, "bogus"]
            return None
        self.assertGreater(self.sweep(bad), 20)

    def test_every_number_given_nan(self):
        def bad(name, value):
            return [name, "nan"] if value in NUMBER_VALUES else None
        self.assertGreater(self.sweep(bad), 50)

    def test_every_flag_given_a_value(self):
        def bad(name, value):
            return [f"{name}=yes"] if value is None else None
        self.assertGreater(self.sweep(bad), 30)

    def test_numbers_past_their_stated_range(self):
        # Read the range each integer option's help states ("0..1000", "in [1, 255]") and give one past it.
        checked = 0
        for command, positional in COMMANDS.items():
            text = help_text(command)
            for name, value in help_options(text):
                line = next(line for line in text.splitlines() if line.startswith(f"  {name} "))
                match = re.search(r"(?<![\w.])(-?\d+)\.\.(\d+)\b", line.split("  ")[-1]) or \
                    re.search(r"in \[(-?\d+), (\d+)\]", line)
                if value not in NUMBER_VALUES or not match:
                    continue
                for past in (int(match.group(1)) - 1, int(match.group(2)) + 1):
                    with self.subTest(command=command, option=name, value=past), \
                            tempfile.TemporaryDirectory() as folder:
                        result = run([*command.split(), *positional, f"{name}={past}"], cwd=folder)
                        self.assert_one_error(result, 2, f"calligraphy {command}: error:", name, str(past))
                        self.assertEqual(result.stdout, b"")
                        checked += 1
        self.assertGreater(checked, 20)

    def test_usage_error_writes_nothing_and_names_the_option(self):
        with tempfile.TemporaryDirectory() as folder:
            for bad in (["--rate", "99"], ["--max-duration", "0"], ["--seed", "-1"], ["--seed", "1", "--seed", "2"],
                        ["--guidance", "off", "--guidance-mode", "fading"], ["--device", "mouse"]):
                with self.subTest(bad=bad):
                    result = run(["trial", "一", "--json", "o.json", "--csv", "o.csv", "--svg", "o.svg", *bad],
                                 cwd=folder)
                    self.assert_one_error(result, 2, "calligraphy trial: error:", bad[0])
                    self.assertEqual(result.stdout, b"")
                    self.assertEqual(os.listdir(folder), [])

    def test_misspelt_command_is_one_error_line_naming_the_near_ones(self):
        for args, needle in ((["trail", "一"], "unknown command 'trail'; did you mean 'trial' or 'train'?"),
                             (["modle", "一"], "did you mean 'model'?"),
                             (["xyzzy"], "unknown command 'xyzzy'")):
            with self.subTest(args=args):
                result = run(args, cwd="/")
                line = self.assert_one_error(result, 2, needle)
                self.assertTrue(line.startswith("calligraphy: error:"), line)
                self.assertEqual(result.stdout, b"")

    def test_misspelt_subcommand_of_each_group_is_one_line(self):
        for group, typo, near in (("session", "rn", "run"), ("corpus", "biuld", "build"), ("bench", "lop", "loop"),
                                  ("session", "cohrot", "cohort")):
            with self.subTest(group=group, typo=typo):
                result = run([group, typo], cwd="/")
                line = self.assert_one_error(result, 2, f"unknown command '{typo}'", f"did you mean '{near}'?")
                self.assertTrue(line.startswith(f"calligraphy {group}: error:"), line)
                self.assertEqual(result.stdout, b"")

    def test_group_without_a_command_prints_its_help_on_standard_error(self):
        for group in ("", "corpus", "bench", "session"):
            with self.subTest(group=group):
                result = run(group.split(), cwd="/")
                self.assertEqual(result.returncode, 2)
                self.assertEqual(result.stdout, b"")
                self.assertIn(b"Usage: calligraphy", result.stderr)

    def test_misspelt_option_names_the_near_one_even_with_a_required_one_missing(self):
        for args, needle in ((["trial", "一", "--guidence", "on"], "did you mean '--guidance'?"),
                             (["score", "t.csv", "--charcter", "一"], "did you mean '--character'?"),
                             (["devices", "--jsno"], "did you mean '--json'?"),
                             (["session", "run", "p.json", "--subjets", "2"], "did you mean '--subjects'?"),
                             (["corpus", "build", "--treads", "2"], "did you mean '--threads'?")):
            with self.subTest(args=args):
                result = run(args, cwd="/")
                self.assert_one_error(result, 2, "unknown option", needle)
                self.assertEqual(result.stdout, b"")

    def test_a_value_that_is_an_option_and_a_flags_own_value(self):
        result = run(["trial", "一", "--json", "--seed", "3"], cwd="/tmp")
        self.assert_one_error(result, 2, "--json", "'--seed'")
        result = run(["devices", "--json=true"], cwd="/")
        self.assertEqual(result.returncode, 0, result.stderr)
        self.assertIn("kinds", json.loads(result.stdout))

    def test_options_that_cannot_go_together_name_the_one_that_does_not_apply(self):
        # docs/cli.md's trial table: each of these "is a usage error" beside the other option.
        for bad, needle in ((["--writer", "person", "--device", "simulated"], "a person cannot hold the device"),
                            (["--guidance", "off", "--guidance-stiffness", "300"], "--guidance-stiffness"),
                            (["--guidance-gain", "0.5"], "--guidance-gain"),
                            (["--guidance-mode", "fading", "--assist-band", "0.002"], "--assist-band"),
                            (["--pacing", "lock-step", "--watchdog-ms", "10"], "--watchdog-ms")):
            with self.subTest(bad=bad), tempfile.TemporaryDirectory() as folder:
                result = run(["trial", "一", "--json", "t.json", *bad], cwd=folder)
                self.assert_one_error(result, 2, "calligraphy trial: error:", needle)
                self.assertEqual(os.listdir(folder), [])

    def test_old_writer_values_say_what_to_write_instead(self):
        result = run(["trial", "一", "--writer", "novice"], cwd="/")
        self.assert_one_error(result, 2, "--writer novice", "--writer-profile novice")
        result = run(["session", "run", "p.json", "--writer", "human", "--out", "o"], cwd="/")
        self.assert_one_error(result, 2, "--writer human", "--writer person")


class Summaries(unittest.TestCase, OneErrorLine):
    """The tables and summaries of `trial` and `score` in a learner's terms, against the JSON of the run."""

    def test_trial_table_numbers_strokes_from_1_in_millimetres_as_its_json(self):
        _, (result, record) = shared_trial("written")
        self.assertEqual(result.returncode, 0, result.stderr)
        text = result.stdout.decode()
        self.assertIn("strokes numbered from 1 here, from 0 in the JSON", text)
        rows = table_rows(text)
        self.assertEqual([row[0] for row in rows], ["1", "2"])
        strokes = record["per_character"][0]["per_stroke"]
        for row, stroke in zip(rows, strokes):
            self.assertEqual(row[1], "十")
            self.assertAlmostEqual(float(row[4]), stroke["mean_deviation_m"] * 1000, delta=0.0051)
            self.assertAlmostEqual(float(row[5]), stroke["max_deviation_m"] * 1000, delta=0.0051)
            self.assertEqual(row[-1], "yes")
        self.assertEqual(summary_value(text, "strokes completed"),
                         f"{record['strokes_completed']} / {record['strokes_total']}")
        self.assertEqual(summary_value(text, "mean deviation"), f"{record['mean_deviation_m'] * 1000:.3f} mm")
        self.assertEqual(summary_value(text, "trial time"), f"{record['trial_time_s']:.2f} s")
        self.assertEqual(error_lines(result), [])
        no_nan(self, text)

    def test_trial_with_assisted_strokes_says_so_and_never_contradicts_its_json(self):
        _, (result, record) = shared_trial("assisted")
        self.assertEqual(result.returncode, 0, result.stderr)
        self.assertEqual((record["end_reason"], record["strokes_assisted"], record["strokes_completed"]),
                         ("completed", 2, 0))
        text = result.stdout.decode()
        self.assertEqual([row[-1] for row in table_rows(text)], ["assisted", "assisted"])
        self.assertEqual(summary_value(text, "strokes assisted"), "2")
        # The trial ended completed (every stroke taken, some not by the renderer) and the trace wrote every
        # stroke in order (backwards): no line of the summary may call it incomplete or deny that.
        self.assertTrue(record["completed_in_order"])
        self.assertNotIn("incomplete", text)
        self.assertEqual(summary_value(text, "strokes completed"), f"{record['strokes_completed']} / 2")
        for line in text.splitlines():  # no line says the strokes were not completed in order
            self.assertNotRegex(line, r"completed in order\s+0 /", line)

    def test_trial_time_limit_summary_has_the_counts_and_no_nan(self):
        _, (result, record) = shared_trial("time_limit")
        line = self.assert_one_error(result, 1, "time_limit")
        self.assertTrue(line.startswith("calligraphy trial: error:"), line)
        text = result.stdout.decode()
        no_nan(self, text)
        self.assertEqual(record["end_reason"], "time_limit")
        self.assertEqual([row[-1] for row in table_rows(text)], ["no", "no"])
        self.assertEqual(summary_value(text, "strokes completed"), "0 / 2  (incomplete)")
        self.assertEqual(summary_value(text, "mean deviation"), "-")
        self.assertIsNone(record["mean_deviation_m"])
        self.assertIn(f"ABORTED after {record['trial_time_s']:.3f} s (time_limit)", text)

    def test_trial_stopped_by_sigint_after_0_3_s_prints_what_it_recorded(self):
        with tempfile.TemporaryDirectory() as folder:
            process = subprocess.Popen([CLI, "trial", "十", "--pacing", "real-time", "--json", "s.json"], cwd=folder,
                                       env=ENV, stdin=subprocess.DEVNULL, stdout=subprocess.PIPE,
                                       stderr=subprocess.PIPE)
            # The real-time trial runs its servo loop on a thread of its own: once it is there the trial runs
            # (a signal before would stop a trial that never started); then 0.3 s of it.
            deadline = time.monotonic() + 20
            while time.monotonic() < deadline and len(os.listdir(f"/proc/{process.pid}/task")) < 2:
                time.sleep(0.01)
            time.sleep(0.3)
            process.send_signal(signal.SIGINT)
            out, err = process.communicate(timeout=30)
            self.assertEqual(process.returncode, 130, err)
            # One line says why it stopped; a real-time loop on a loaded machine may warn of a late tick besides.
            lines = [line for line in err.decode().strip().splitlines()
                     if not line.startswith("calligraphy trial: warning: servo loop: tick ")]
            self.assertEqual(len(lines), 1, lines)
            self.assertIn("SIGINT", lines[0])
            self.assertTrue(lines[0].startswith("calligraphy trial:"), lines[0])
            record = json.loads((Path(folder) / "s.json").read_text())
            text = out.decode()
            no_nan(self, text)
            self.assertEqual((record["end_reason"], record["abort_reason"]), ("interrupted", "stopped by SIGINT"))
            self.assertEqual(summary_value(text, "trial time"), f"{record['trial_time_s']:.2f} s")
            self.assertIn(f"{record['trial_time_s']:.3f} s", lines[0])
            self.assertIn(f"{record['loop']['ticks']} ticks", summary_value(text, "servo loop"))
            self.assertEqual(summary_value(text, "strokes completed").split()[:3],
                             [str(record["strokes_completed"]), "/", "2"])

    def test_score_verdicts_are_its_jsons_and_add_up_to_the_strokes(self):
        folder, _ = shared_trial("assisted")
        result = run(["score", "assisted.csv", "--character", "十", "--json", "score.json"], cwd=folder)
        self.assertEqual(result.returncode, 0, result.stderr)
        text = result.stdout.decode()
        no_nan(self, text)
        record = json.loads((Path(folder) / "score.json").read_text())
        rows = table_rows(text)
        self.assertEqual([row[0] for row in rows], ["1", "2"])
        accepted = int(summary_value(text, "strokes accepted").split()[0])
        refused = int(summary_value(text, "strokes refused").split()[0])
        unwritten = int(summary_value(text, "strokes not written").split()[0])
        self.assertEqual(accepted + refused + unwritten, record["strokes_total"])
        self.assertEqual(accepted, record["strokes_accepted"])
        verdicts = [" ".join(row[8:]) for row in rows]
        self.assertEqual(sum(v.startswith("accepted") for v in verdicts), accepted)
        self.assertEqual(sum(v.startswith("refused") for v in verdicts), refused)
        self.assertEqual(sum(v.startswith("not written") for v in verdicts), unwritten)
        self.assertEqual(int(summary_value(text, "strokes matched").split()[0]), record["strokes_written"])
        self.assertEqual(summary_value(text, "mean deviation"), f"{record['mean_deviation_m'] * 1000:.3f} mm")

    def test_score_refusal_names_how_far_off_as_its_json(self):
        folder, _ = shared_trial("one")
        # The trace of 一 moved 4 mm across its stroke: its one pen-down is refused in the wrong place.
        lines = (Path(folder) / "one.csv").read_text().splitlines()
        header = lines[0].split(",")
        y = header.index("y")
        moved = [lines[0]]
        for line in lines[1:]:
            cells = line.split(",")
            cells[y] = repr(float(cells[y]) + 0.004)
            moved.append(",".join(cells))
        (Path(folder) / "moved.csv").write_text("\n".join(moved) + "\n")
        result = run(["score", "moved.csv", "--character", "一", "--json", "moved-score.json"], cwd=folder)
        self.assertEqual(result.returncode, 0, result.stderr)
        record = json.loads((Path(folder) / "moved-score.json").read_text())
        rows = table_rows(result.stdout.decode())
        self.assertEqual(len(rows), 1)
        first = " ".join(rows[0][8:])
        match = re.match(r"refused: wrong place \((\d+\.\d) mm off\)", first)
        self.assertTrue(match, first)
        refusals = [s["verdict"] for s in record["per_character"][0]["segments"] if s["verdict"]]
        self.assertEqual(len(refusals), 1)
        self.assertEqual(refusals[-1]["refusal"], "wrong_place")
        self.assertAlmostEqual(float(match.group(1)), refusals[-1]["mean_deviation_m"] * 1000, delta=0.051)

    def test_a_stroke_written_out_of_turn_names_the_stroke_due_from_1(self):
        folder, _ = shared_trial("written")
        # 十's two strokes from its trace, the second written first, a pen lift of 0.1 s after each.
        lines = (Path(folder) / "written.csv").read_text().splitlines()
        header = lines[0].split(",")
        t, x, y, z = (header.index(name) for name in ("t", "x", "y", "z"))
        segments, current = [], []
        for line in lines[1:]:
            cells = line.split(",")
            if float(cells[z]) <= 0.0005:
                current.append(cells)
            elif current:
                segments.append(current)
                current = []
        if current:
            segments.append(current)
        first, second = sorted(sorted(segments, key=len)[-2:], key=lambda segment: float(segment[0][t]))
        rows = ["t,x,y,pen"]
        for segment in (second, first):
            rows += [f"{cells[x]},{cells[y]},1" for cells in segment]
            rows += [f"{segment[-1][x]},{segment[-1][y]},0"] * 100
        rows[1:] = [f"{tick / 1000:.3f},{row}" for tick, row in enumerate(rows[1:])]
        (Path(folder) / "swapped.csv").write_text("\n".join(rows) + "\n")
        result = run(["score", "swapped.csv", "--character", "十", "--json", "swapped.json"], cwd=folder)
        self.assertEqual(result.returncode, 0, result.stderr)
        verdicts = [" ".join(row[8:]) for row in table_rows(result.stdout.decode())]
        self.assertEqual(verdicts, ["accepted", "refused: wrong order (written while stroke 1 was due)"])
        segments = json.loads((Path(folder) / "swapped.json").read_text())["per_character"][0]["segments"]
        refused = [s["verdict"] for s in segments if s["verdict"] and not s["verdict"]["accepted"]]
        self.assertEqual([(v["refusal"], v["expected_stroke"], v["matched_stroke"]) for v in refused],
                         [("wrong_order", 0, 1)])

    def test_check_prints_one_line_and_writes_nothing(self):
        with tempfile.TemporaryDirectory() as folder:
            result = run(["trial", "一", "--check", "--json", "t.json", "--csv", "t.csv"], cwd=folder)
            self.assertEqual(result.returncode, 0, result.stderr)
            self.assertEqual(len(result.stdout.decode().strip().splitlines()), 1, result.stdout)
            self.assertEqual(result.stderr, b"")
            self.assertEqual(os.listdir(folder), [])
            result = run(["trial", "一", "--check", "--rate", "99"], cwd=folder)
            self.assert_one_error(result, 2, "--rate", "99")
            self.assertEqual(result.stdout, b"")

    def test_json_to_standard_output_carries_the_document_alone(self):
        result = run(["trial", "一", "--max-duration", "0.05", "--json", "-"], cwd="/")
        self.assertEqual(result.returncode, 1)
        record = json.loads(result.stdout)
        self.assertEqual(record["end_reason"], "time_limit")
        self.assertEqual(len(error_lines(result)), 1)

    def test_train_without_a_display_says_one_line(self):
        with tempfile.TemporaryDirectory() as folder:
            result = run(["train", "一", "--session", "s"], cwd=folder)
            line = self.assert_one_error(result, 1, "calligraphy train: error:")
            self.assertEqual(result.stdout, b"")
            self.assertEqual(os.listdir(folder), [], line)

    def test_session_run_in_the_window_without_a_display_makes_no_folder(self):
        # A person's session goes to the trainer window: with no display to open it on, one line ("cannot open
        # a window") and no session folder; a build without the window has no mouse device, and makes nothing.
        protocol = str(SOURCE / "examples" / "protocols" / "paper-table5.json")
        with tempfile.TemporaryDirectory() as folder:
            result = run(["session", "run", protocol, "--writer", "person", "--device", "mouse", "--subject", "P01",
                          "--out", "study"], cwd=folder)
            line = self.assert_one_error(result, (1, 2), "calligraphy session run: error:")
            self.assertEqual(os.listdir(folder), [], line)


class Outputs(unittest.TestCase, OneErrorLine):
    """Standard output carries a document alone; an output's error names the option, the path and why."""

    def test_standard_output_is_the_document_alone(self):
        folder, _ = shared_trial("one")
        result = run(["trial", "一", "--max-duration", "0.05", "--svg", "-"], cwd=folder)
        self.assertEqual(result.returncode, 1)
        self.assertTrue(result.stdout.lstrip().startswith(b"<"), result.stdout[:80])
        self.assertNotIn(b"strokes completed", result.stdout)
        result = run(["score", "one.csv", "--character", "一", "--json", "-"], cwd=folder)
        self.assertEqual(result.returncode, 0, result.stderr)
        self.assertEqual(json.loads(result.stdout)["strokes_total"], 1)
        self.assertEqual(result.stderr, b"")
        result = run(["trace", "missing.trace.h5", "--csv", "-", "--verbose"], cwd=folder)
        self.assertEqual(result.stdout, b"")

    def test_two_outputs_to_standard_output_are_refused_naming_both(self):
        with tempfile.TemporaryDirectory() as folder:
            result = run(["trial", "一", "--json", "-", "--csv", "-"], cwd=folder)
            self.assert_one_error(result, 2, "--json", "--csv")
            self.assertEqual(result.stdout, b"")

    def test_an_output_in_a_missing_folder_names_the_option_the_path_and_why(self):
        with tempfile.TemporaryDirectory() as folder:
            result = run(["trial", "一", "--json", "no/such/t.json"], cwd=folder)
            self.assert_one_error(result, 1, "--json", "no/such", "does not exist")
            self.assertEqual(result.stdout, b"")
            self.assertEqual(os.listdir(folder), [])

    def test_a_file_name_with_control_characters_is_quoted_on_one_line(self):
        with tempfile.TemporaryDirectory() as folder:
            result = run(["score", "a\nb\x1b[31m.csv", "--character", "一"], cwd=folder)
            line = self.assert_one_error(result, 1, "a\\nb\\x1b[31m.csv")
            self.assertNotIn("\x1b", line)

    def test_a_score_of_nothing_written_says_so_without_nan(self):
        with tempfile.TemporaryDirectory() as folder:
            (Path(folder) / "up.csv").write_text("t,x,y,pen\n0,0,0,0\n0.01,0.001,0,0\n0.02,0.002,0,0\n")
            result = run(["score", "up.csv", "--character", "十", "--json", "up.json"], cwd=folder)
            self.assertEqual(result.returncode, 0, result.stderr)
            text = result.stdout.decode()
            no_nan(self, text)
            self.assertEqual([" ".join(row[8:]) for row in table_rows(text)], ["not written", "not written"])
            self.assertEqual(summary_value(text, "strokes not written").split()[0], "2")
            self.assertEqual(summary_value(text, "mean deviation"), "-")
            self.assertIsNone(json.loads((Path(folder) / "up.json").read_text())["mean_deviation_m"])

    def test_score_header_names_the_units_of_its_trace(self):
        with tempfile.TemporaryDirectory() as folder:
            (Path(folder) / "d.csv").write_text("t,x,y,pen\n0,100,500,1\n0.5,500,500,1\n1,900,500,1\n")
            for units, needle in (("data", "x and y in data units (1024 per character)"), ("m", "x and y in m;")):
                with self.subTest(units=units):
                    result = run(["score", "d.csv", "--character", "一", "--units", units], cwd=folder)
                    self.assertEqual(result.returncode, 0, result.stderr)
                    self.assertIn(needle, result.stdout.decode().splitlines()[0])

    def test_characters_of_a_text_show_a_control_character_printable(self):
        result = run(["characters", "--text", "一\x1b"], cwd="/")
        text = result.stdout.decode() + result.stderr.decode()
        self.assertNotIn("\x1b", text)
        self.assertIn("\\x1b (U+001B)", text)


PROTOCOL = {"name": "tiny", "conditions": [{"name": "fixture", "mode": "haptic"}],
            "test": {"characters": ["一"], "conditions": ["fixture"], "repetitions": 2},
            "trial": {"max_duration_s": 10}}
SESSION_LINE = r"^(S\d+): (\d+) of (\d+) trials saved \((\d+) now, (\d+) attempts? kept\) in (\S+), \d+\.\d s$"


class Sessions(unittest.TestCase):
    """`session run` and `resume`: one line per session on standard output, the plan and the stop on standard
    error, each naming its command."""

    def test_session_run_prints_one_line_per_session_and_its_plan_on_standard_error(self):
        with tempfile.TemporaryDirectory() as folder:
            (Path(folder) / "p.json").write_text(json.dumps(PROTOCOL, ensure_ascii=False))
            result = run(["session", "run", "p.json", "--subjects", "2", "--out", "study"], cwd=folder)
            self.assertEqual(result.returncode, 0, result.stderr)
            lines = result.stdout.decode().splitlines()
            self.assertEqual(len(lines), 2, lines)
            for number, line in enumerate(lines, 1):
                match = re.match(SESSION_LINE, line)
                self.assertTrue(match, line)
                subject, saved, planned, now, attempts, path = match.groups()
                self.assertEqual((subject, saved, planned, now, attempts), (f"S0{number}", "2", "2", "2", "0"))
                self.assertEqual(len(list((Path(folder) / path / "trials").glob("*.json"))), 2)
            err = result.stderr.decode()
            self.assertIn("plan of tiny", err)
            self.assertIn("items 一", err)
            self.assertNotIn("error", err)
            self.assertNotIn("warning", err)

    def test_a_session_stopped_by_sigint_names_its_command_the_signal_and_the_resume(self):
        with tempfile.TemporaryDirectory() as folder:
            (Path(folder) / "p.json").write_text(json.dumps(PROTOCOL, ensure_ascii=False))
            process = subprocess.Popen([CLI, "session", "run", "p.json", "--subject", "S01", "--out", "study",
                                        "--pacing", "real-time"], cwd=folder, env=ENV, stdin=subprocess.DEVNULL,
                                       stdout=subprocess.PIPE, stderr=subprocess.PIPE)
            deadline = time.monotonic() + 20
            while time.monotonic() < deadline and not any(
                    b"trial_started" in log.read_bytes() for log in Path(folder).glob("study/S01/*/log.jsonl")):
                time.sleep(0.05)
            time.sleep(0.3)
            process.send_signal(signal.SIGINT)
            out, err = process.communicate(timeout=30)
            self.assertEqual(process.returncode, 130, err)
            match = re.match(SESSION_LINE, out.decode().strip())
            self.assertTrue(match, out)
            subject, saved, planned, now, attempts, path = match.groups()
            self.assertEqual((saved, planned, now, attempts), ("0", "2", "0", "1"))
            self.assertEqual(len(list((Path(folder) / path / "trials" / "attempts").glob("*.json"))), 1)
            last = err.decode().strip().splitlines()[-1]
            self.assertEqual(last, f"calligraphy session run: stopped by SIGINT; resume with: "
                                   f"calligraphy session resume {path}")
            result = run(["session", "resume", path, "--pacing", "lock-step"], cwd=folder)
            self.assertEqual(result.returncode, 0, result.stderr)
            match = re.match(SESSION_LINE, result.stdout.decode().strip())
            self.assertTrue(match, result.stdout)
            # Every trial saved now; the attempt the stop kept was kept by the run, not by this resume.
            self.assertEqual(match.groups()[1:5], ("2", "2", "2", "0"))


class Log(unittest.TestCase):
    """The library's log: on standard error as the command's own lines, info only with --verbose."""

    def test_info_lines_only_with_verbose_in_the_commands_form(self):
        for verbose in ([], ["--verbose"]):
            with self.subTest(verbose=verbose):
                result = run(["trial", "一", "--pacing", "real-time", "--max-duration", "0.1", *verbose], cwd="/")
                out, err = result.stdout.decode(), result.stderr.decode()
                for text in (out, err):
                    self.assertNotRegex(text, r"\[\d{4}-\d\d-\d\d")
                    self.assertNotIn("[calligraphy]", text)
                    self.assertNotIn("[info]", text)
                info = [line for line in err.splitlines() if ": info: " in line]
                self.assertTrue(all(line.startswith("calligraphy trial: info: ") for line in info), info)
                self.assertEqual(bool(info), bool(verbose), err)
                self.assertNotIn("info:", out)

    def test_defaults_print_no_warning(self):
        for args in (["trial", "一", "--max-duration", "0.05"], ["model", "一"], ["strokes"],
                     ["characters", "--strokes", "1"], ["devices"]):
            with self.subTest(args=args):
                result = run(args, cwd="/")
                self.assertNotIn(b"warning", result.stderr)
                self.assertNotIn(b"warning", result.stdout)


class Devices(unittest.TestCase, OneErrorLine):
    """`devices` against docs/cli.md's table of kinds."""

    KINDS = {"simulated", "emulated-phantom", "mouse", "mouse-hand", "openhaptics", "phantom-hid", "phantom-usb"}

    def documented_kinds(self):
        section = CLI_MD.split("\n## devices", 1)[1].split("\n## ", 1)[0]
        kinds = {}
        for line in section.splitlines():
            match = re.match(r"^\| `([a-z-]+)(?::[A-Z-]+)?` \| (\w+) \| ([^|]*) \|", line)
            if match:
                kinds[match.group(1)] = (match.group(2), sorted(re.findall(r"`([a-z ]+)`", match.group(3))))
        return kinds

    def test_devices_lists_every_kind_with_its_commands_as_the_docs(self):
        documented = self.documented_kinds()
        self.assertEqual(set(documented), self.KINDS)
        listing = run(["devices", "--json"], cwd="/")
        self.assertEqual(listing.returncode, 0, listing.stderr)
        kinds = {kind["name"].split(":")[0]: kind for kind in json.loads(listing.stdout)["kinds"]}
        self.assertEqual(set(kinds), self.KINDS)
        text = run(["devices"], cwd="/").stdout.decode().split("Kinds of device", 1)[1]
        # docs/cli.md: "In a build without the trainer window no kind lists `train`, and the pointer kinds are
        # listed with no command" (the sanitizer builds have no window).
        windowless = any("not in this build" in kind["what"] for kind in kinds.values())
        for name, (writer, commands) in documented.items():
            with self.subTest(kind=name):
                if windowless:
                    commands = [] if name in ("mouse", "mouse-hand") else [c for c in commands if c != "train"]
                self.assertEqual(kinds[name]["writer"], writer)
                self.assertEqual(sorted(kinds[name]["commands"]), commands)
                line = next(line for line in text.splitlines() if line.split() and
                            line.split()[0].split(":")[0] == name)
                self.assertEqual(line.split()[1], writer, line)
                columns = re.split(r"\s{2,}", line.strip())
                listed = [] if columns[2] == "none" else [c.strip() for c in columns[2].split(",")]
                self.assertEqual(sorted(listed), commands, line)

    def test_a_device_no_command_takes_says_which_commands_do(self):
        result = run(["trial", "一", "--device", "mouse-hand"], cwd="/")
        self.assert_one_error(result, 2, "--device mouse-hand", "train", "session run")
        for command in (["trial", "一"], ["train", "一"], ["session", "run", "p.json", "--out", "o"]):
            with self.subTest(command=command[:2]), tempfile.TemporaryDirectory() as folder:
                (Path(folder) / "p.json").write_text(json.dumps(PROTOCOL, ensure_ascii=False))
                result = run([*command, "--device", "nosuch"], cwd=folder)
                self.assertEqual(os.listdir(folder), ["p.json"])
                if command[0] == "train" and b"built without the trainer window" in result.stderr:
                    continue  # the sanitizer builds: train says only that (exit 1), before any option
                line = self.assert_one_error(result, 2, "--device", "'nosuch'", "simulated", "emulated-phantom")
                self.assertEqual(line.count("nosuch"), 1, line)  # the name once, then the devices there are


class Names(unittest.TestCase, OneErrorLine):
    """Messages name a character by itself (and its code point), a file by its name, a stroke from 1."""

    def test_a_character_the_library_lacks_is_named_by_itself_and_its_code_point(self):
        for args in (["trial", "龘"], ["model", "龘"], ["score", "t.csv", "--character", "龘"]):
            with self.subTest(args=args), tempfile.TemporaryDirectory() as folder:
                (Path(folder) / "t.csv").write_text("t,x,y,pen\n0,0,0,1\n0.01,0.001,0,1\n")
                result = run(args, cwd=folder)
                self.assert_one_error(result, 2, "龘", "U+9F98")

    def test_a_missing_trace_is_named_by_its_file(self):
        for args in (["score", "missing.csv", "--character", "一"], ["trace", "missing.trace.h5"]):
            with self.subTest(args=args):
                result = run(args, cwd="/tmp")
                self.assert_one_error(result, (1, 2), "missing.")


if __name__ == "__main__":
    unittest.main()
