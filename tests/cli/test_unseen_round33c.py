#!/usr/bin/env python3
"""Round 33C: every command's words for people: its help, its standard output and error, its exit statuses and
the signals that stop it. From the docs alone: docs/cli.md ("Conventions": help and version, mistyped names,
option syntax, numbers, outputs, standard output, the library's log, characters; "Exit statuses"; the error
lines and what they quote; each command's section and option table; "Stopping a trial"; `score`'s progress;
`bench loop`; `session run`'s stop), README.md and every command's `--help`.

What it attacks: the help of every command held to its section of docs/cli.md (each option there and back, one
default a line, the defaults the tables give), `--help` and `--version` anywhere, a group without its command,
mistyped and repeated options on every command, a flag given an empty value, empty arguments, `-` and `--` as
file names, arguments that are not UTF-8 or 100 kB long, file names that are not UTF-8 in every JSON a command
writes, an ASCII locale, a closed or full standard output, `--verbose`'s info lines, `score`'s progress on a
terminal, and SIGHUP, SIGUSR1, SIGXCPU, SIGINT, SIGTERM, SIGQUIT, SIGSTOP/SIGCONT sent to a real-time trial, to
`bench loop` and to `session run` (ignored, blocked and sent before the start too).

CALLIGRAPHY_CLI names the program; PYTHONPATH the built Python package (only for its version);
CALLIGRAPHY_SOURCE_DIR the worktree (docs/cli.md and a character file of data/hanzi-writer-data).
CALLIGRAPHY_SANITIZED=1 takes five cases.
"""
import json
import os
import pty
import re
import select
import shutil
import signal
import subprocess
import tempfile
import time
import unittest
from pathlib import Path

from outsider import CLI, ENV, OneErrorLine, error_lines, run, run_ok, sanitized_subset, start_own_x_server

SOURCE = Path(os.environ.get("CALLIGRAPHY_SOURCE_DIR", Path(__file__).resolve().parents[2]))
DOC = SOURCE / "docs" / "cli.md"

load_tests = sanitized_subset({"test_flag_given_an_empty_value_is_a_usage_error",
                               "test_empty_argument_is_never_an_internal_error",
                               "test_dash_as_an_input_says_standard_input_is_not_read",
                               "test_score_json_of_a_trace_named_in_latin1_is_written_or_refused",
                               "test_version_anywhere_is_the_projects_version_on_stdout_only"})

COMMANDS = ["trial", "train", "score", "trace", "model", "strokes", "characters", "devices", "corpus build",
            "corpus stats", "corpus fidelity", "corpus validate", "bench nearest", "bench jumps", "bench tick",
            "bench loop", "bench acceptance", "curriculum", "session run", "session resume", "session plan",
            "session cohort", "report", "schema"]
GROUPS = ["", "corpus", "bench", "session"]
PROTOCOL = {"name": "two", "conditions": [{"name": "h", "mode": "haptic"}],
            "test": {"characters": ["十", "二"], "conditions": ["h"], "repetitions": 1},
            "trial": {"max_duration_s": 1}}
# A real-time trial of 十 the simulated writer cannot finish in its time: a signal finds it running.
REAL_TIME = ["trial", "十", "--pacing", "real-time", "--json", "t.json", "--csv", "t.csv"]
STOP_STATUS = {signal.SIGINT: 130, signal.SIGTERM: 143, signal.SIGHUP: 129, signal.SIGUSR1: 138,
               signal.SIGUSR2: 140, signal.SIGXCPU: 152}


def doc_region(lines, command):
    """The lines of docs/cli.md about `command`: from its synopsis line (`calligraphy COMMAND ...`: ...) to the
    next command's synopsis or heading."""
    synopsis = re.compile(r"^`calligraphy ([a-z]+(?: [a-z]+)?)[^`]*`(:| or | prints| \(and)")
    starts = [(i, m.group(1) if m.group(1).split()[0] in ("corpus", "bench", "session") else
               m.group(1).split()[0]) for i, line in enumerate(lines) for m in [synopsis.match(line)] if m]
    heads = [i for i, line in enumerate(lines) if line.startswith("#")]
    first = [i for i, name in starts if name == command][0]
    ends = [i for i, name in starts if i > first and name != command] + [i for i in heads if i > first]
    return lines[first:min(ends) if ends else len(lines)]


def help_entries(text):
    """{option: its whole help entry (continuation lines joined)} of a --help text."""
    entries, current = {}, None
    for line in text.splitlines():
        m = re.match(r"^  (?:-h,)?(--[a-z0-9-]+)", line)
        if m:
            current = m.group(1)
            entries[current] = line
        elif current and line.startswith("        "):
            entries[current] += " " + line.strip()
        else:
            current = None
    return entries


def takes_value(entry):
    """Whether a help entry names a value after its option (`--seed N`), not a flag (`--json   print ...`)."""
    head = entry.strip()
    return bool(re.match(r"^(-h,)?--[a-z0-9-]+ \S", head)) and not re.match(r"^(-h,)?--[a-z0-9-]+ {2,}", head)


def trial_csv(path):
    """A lock-step trial's trace of 十 written to `path`."""
    run_ok(["trial", "十", "--csv", path.name], path.parent)


def start(args, cwd, preexec_fn=None, **kw):
    """The program started with `args` in `cwd`, its output and errors piped."""
    return subprocess.Popen([CLI, *args], cwd=cwd, env=ENV, stdin=subprocess.DEVNULL, stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, preexec_fn=preexec_fn, **kw)


class Round33C(unittest.TestCase, OneErrorLine):
    @classmethod
    def setUpClass(cls):
        cls.tmp = Path(tempfile.mkdtemp(prefix="round33c-"))
        cls.helps = {}
        for command in COMMANDS + GROUPS:
            result = run([*command.split(), "--help"], cls.tmp)
            cls.helps[command] = result
        cls.doc_lines = DOC.read_text(encoding="utf-8").splitlines()
        trial_csv(cls.tmp / "t.csv")
        (cls.tmp / "p.json").write_text(json.dumps(PROTOCOL, ensure_ascii=False), encoding="utf-8")

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.tmp, ignore_errors=True)

    def folder(self):
        d = Path(tempfile.mkdtemp(dir=self.tmp))
        self.addCleanup(shutil.rmtree, d, True)
        return d

    # ---- help and version ---------------------------------------------------------------------------------

    def test_help_exits_0_on_stdout_for_the_program_its_groups_and_every_command(self):
        for command, result in self.helps.items():
            with self.subTest(command=command):
                self.assertEqual(result.returncode, 0, result.stderr)
                self.assertEqual(result.stderr, b"")
                self.assertIn(b"Usage: calligraphy " + command.encode(), result.stdout)
                self.assertNotIn(b"\x1b", result.stdout)

    def test_every_help_option_is_in_its_docs_section_and_every_documented_option_in_its_help(self):
        for command in COMMANDS:
            with self.subTest(command=command):
                region = doc_region(self.doc_lines, command)
                text = "\n".join(region)
                helped = set(help_entries(self.helps[command].stdout.decode())) - {"--help", "--version",
                                                                                   "--verbose"}
                self.assertEqual(sorted(helped - set(re.findall(r"(--[a-z0-9-]+)", text))), [],
                                 "options of --help that the command's section of docs/cli.md never names")
                paragraph = "\n".join(region[:next((i for i, l in enumerate(region) if not l.strip()),
                                                   len(region))])
                documented = set()
                for line in region:
                    if line.startswith("| `--"):
                        documented |= set(re.findall(r"`(--[a-z0-9-]+)`", line.split("|")[1]))
                documented |= set(re.findall(r"\[(--[a-z0-9-]+)", paragraph))
                documented |= set(re.findall(r"\| (--[a-z0-9-]+)", paragraph))
                documented |= set(re.findall(r"`(--[a-z0-9-]+)`", paragraph))
                self.assertEqual(sorted(documented - helped), [],
                                 "options docs/cli.md gives the command that its --help lacks")

    def test_each_help_line_states_one_default_at_most_and_each_value_option_one(self):
        for command in COMMANDS:
            for option, entry in help_entries(self.helps[command].stdout.decode()).items():
                with self.subTest(command=command, option=option):
                    defaults = entry.count("(default:")
                    self.assertLessEqual(defaults + entry.count("(required)"), 1, entry)
                    if takes_value(entry):
                        self.assertEqual(defaults + entry.count("(required)"), 1, entry)
                    else:
                        self.assertEqual(defaults, 0, entry)

    def test_help_defaults_are_the_defaults_of_the_docs_tables(self):
        checked = 0
        for command in COMMANDS:
            entries = help_entries(self.helps[command].stdout.decode())
            for line in doc_region(self.doc_lines, command):
                if not line.startswith("| `--"):
                    continue
                cells = [c.strip() for c in re.split(r"(?<!\\)\|", line.strip().strip("|"))]
                if cells[2].startswith("required"):
                    for option in re.findall(r"`(--[a-z0-9-]+)`", cells[0]):
                        self.assertRegex(entries[option], r"\((default: )?required")
                    continue
                m = re.fullmatch(r"`?([0-9][0-9.]*|[a-z-]+)`?( \(.*\))?", cells[2])
                if not m or cells[2] == "off":
                    continue
                for option in re.findall(r"`(--[a-z0-9-]+)`", cells[0]):
                    with self.subTest(command=command, option=option):
                        said = re.search(r"\(default: (.*)\)\s*$", entries[option])
                        self.assertIsNotNone(said, entries[option])
                        self.assertTrue(said.group(1).startswith(m.group(1)), (cells[2], said.group(1)))
                        checked += 1
        self.assertGreater(checked, 40)

    def test_version_anywhere_is_the_projects_version_on_stdout_only(self):
        try:
            import calligraphy
            expected = f"calligraphy {calligraphy.__version__}\n".encode()
        except ImportError:
            cmake = (SOURCE / "CMakeLists.txt").read_text(encoding="utf-8")
            expected = f"calligraphy {re.search(r'VERSION ([0-9.]+)', cmake).group(1)}\n".encode()
        for args in (["--version"], ["trial", "十", "--version"], ["corpus", "build", "--version"],
                     ["session", "run", "missing.json", "--version"], ["trial", "--seed", "2x", "--version"],
                     ["bench", "loop", "--version"]):
            with self.subTest(args=args):
                result = run(args, self.tmp)
                self.assertEqual((result.returncode, result.stdout, result.stderr), (0, expected, b""))

    def test_help_beside_a_wrong_value_still_prints_the_help_and_exits_0(self):
        # docs/cli.md: "`-h` / `--help` on the program and on every command lists each option ... and exits 0";
        # exit status 0: "success (also `--help` and `--version`)"; `--version` "(anywhere)".
        for args in (["trial", "十", "--seed", "2x", "--help"], ["corpus", "build", "--help", "--out", "-"],
                     ["trial", "十", "--seed", "1", "--seed", "2", "--help"]):
            with self.subTest(args=args):
                result = run(args, self.tmp)
                self.assertEqual(result.returncode, 0, result.stderr)
                words = " ".join(a for a in args[:2] if a.isascii() and a.isalpha())
                self.assertIn(b"Usage: calligraphy " + words.encode(), result.stdout)

    def test_a_group_without_its_command_prints_its_help_on_stderr_only_exit_2(self):
        for group in GROUPS:
            with self.subTest(group=group):
                result = run(group.split(), self.tmp)
                self.assertEqual(result.returncode, 2)
                self.assertEqual(result.stdout, b"")
                self.assertIn(("Usage: calligraphy " + group).strip().encode(), result.stderr)

    # ---- usage errors ---------------------------------------------------------------------------------------

    def test_mistyped_names_are_named_with_the_close_names_exit_2(self):
        cases = [(["trail", "十"], "calligraphy: error: unknown command 'trail'; did you mean 'trial' or 'train'?"),
                 (["shcema", "record"], "calligraphy: error: unknown command 'shcema'; did you mean 'schema'?"),
                 (["sesion", "plan"], "calligraphy: error: unknown command 'sesion'; did you mean 'session'?"),
                 (["bench", "lop"], "calligraphy bench: error: unknown command 'lop'; did you mean 'loop'?"),
                 (["--verison"], "calligraphy: error: unknown option '--verison'; did you mean '--version'?"),
                 (["trial", "十", "--sede", "1"],
                  "calligraphy trial: error: unknown option '--sede'; did you mean '--seed'?"),
                 (["trial", "十", "--max-dur", "1"],
                  "calligraphy trial: error: unknown option '--max-dur'; did you mean '--max-duration'?"),
                 (["report", "x", "--cvs", "y"],
                  "calligraphy report: error: unknown option '--cvs'; did you mean '--csv'?"),
                 (["corpus", "build", "--ot", "x"],
                  "calligraphy corpus build: error: unknown option '--ot'; did you mean '--out'?"),
                 (["trial", "十", "--guid", "on"], "calligraphy trial: error: unknown option '--guid'")]
        for args, line in cases:
            with self.subTest(args=args):
                result = run(args, self.tmp)
                self.assertEqual(result.stdout, b"")
                self.assertEqual(self.assert_one_error(result, 2), line)

    def test_every_command_refuses_an_unknown_option_in_one_line_naming_it(self):
        for command in COMMANDS:
            with self.subTest(command=command):
                result = run([*command.split(), "--zqxv-nothing"], self.tmp)
                self.assertEqual(result.stdout, b"")
                self.assert_one_error(result, 2, f"calligraphy {command}: error:", "'--zqxv-nothing'")

    def test_an_option_given_twice_is_refused_whatever_its_spelling(self):
        for args, option in ((["report", "x", "--csv", "a", "--csv=b"], "--csv"),
                             (["bench", "loop", "--rate", "100", "--rate=100"], "--rate"),
                             (["session", "plan", "p.json", "--subjects", "1", "--subjects", "2"], "--subjects"),
                             (["trace", "x", "--csv", "a", "--csv", "a"], "--csv"),
                             (["trial", "十", "--seed=1", "--seed", "1"], "--seed")):
            with self.subTest(args=args):
                result = run(args, self.tmp)
                self.assert_one_error(result, 2, option, "given 2 times")

    def test_flag_given_an_empty_value_is_a_usage_error(self):
        # docs/cli.md, "Option syntax": "Flags ... take no value: `--json=yes` or `--verbose=0` is a usage error
        # (`--json: a flag takes no value`); only `--json=true`, the flag's own value, is taken as the flag."
        d = self.folder()
        for args, flag in ((["model", "十", "--json="], "--json"), (["strokes", "--json="], "--json"),
                           (["trial", "十", "--check="], "--check"), (["model", "十", "--verbose="], "--verbose")):
            with self.subTest(args=args):
                result = run(args, d)
                self.assertEqual(result.stdout, b"")
                self.assert_one_error(result, 2, flag, "a flag takes no value")

    def test_empty_argument_is_never_an_internal_error(self):
        # Exit status 3 is "an internal error (an exception the library does not document)"; an empty argument
        # is wrong usage or a missing file, one line naming what is at fault.
        d = self.folder()
        for args in (["session", "resume", ""], ["score", "", "--character", "十"], ["trace", ""],
                     ["corpus", "stats", ""], ["session", "plan", "", "--subjects", "1"],
                     ["report", "", "--csv", "."], ["curriculum", "", "--subject", "S", "--from", "十"]):
            with self.subTest(args=args):
                result = run(args, d)
                line = self.assert_one_error(result, (1, 2))
                self.assertNotIn("internal error", line)
                self.assertEqual(sorted(os.listdir(d)), [])

    def test_empty_trace_is_a_usage_error_as_an_empty_file_option_is(self):
        # Exit status 2: "wrong usage: ... a missing or invalid value"; the program itself refuses an empty file
        # name given to an option so (`--spec ""`: "--spec: expects a RECORD name, got an empty value", exit 2).
        spec = run(["trial", "--spec", ""], self.tmp)
        self.assert_one_error(spec, 2, "--spec", "empty")
        for args, name in ((["score", "", "--character", "十"], "TRACE"), (["trace", ""], "TRACE")):
            with self.subTest(args=args):
                self.assert_one_error(run(args, self.tmp), 2, name)

    def test_dash_as_an_input_says_standard_input_is_not_read(self):
        # docs/cli.md, "Pen traces": "Every file a command reads (a trace, a record for `--spec`, a teacher, a
        # protocol, a store) must be a regular file ...; an input given as `-` is a file named `-`, and where none
        # exists the error says that standard input is not read."
        d = self.folder()
        for args in (["score", "-", "--character", "十"], ["trace", "-"], ["corpus", "stats", "-"],
                     ["session", "plan", "-", "--subjects", "1"], ["session", "cohort", "-", "--subjects", "1",
                                                                   "--csv", "."],
                     ["session", "run", "-", "--subject", "S01", "--out", "out"]):
            with self.subTest(args=args), open(self.tmp / "p.json", "rb") as given:
                result = run(args, d, stdin=given)
                self.assert_one_error(result, 1, "standard input is not read")
                self.assertEqual(sorted(os.listdir(d)), [])

    def test_dash_and_names_after_double_dash_are_files_of_that_name(self):
        d = self.folder()
        shutil.copy(self.tmp / "t.csv", d / "-")
        shutil.copy(self.tmp / "t.csv", d / "-t.csv")
        shutil.copy(self.tmp / "p.json", d / "p.json")
        plain = json.loads(run_ok(["score", "t.csv", "--character", "十", "--json", "-"], self.tmp).stdout)
        for args in (["score", "-", "--character", "十", "--json", "-"],
                     ["score", "--character", "十", "--json", "-", "--", "-t.csv"]):
            with self.subTest(args=args):
                got = json.loads(run_ok(args, d).stdout)
                self.assertEqual(got["trace"], args[-1] if args[-2] == "--" else "-")
                self.assertEqual({k: v for k, v in got.items() if k != "trace"},
                                 {k: v for k, v in plain.items() if k != "trace"})
        (d / "-").write_bytes((self.tmp / "p.json").read_bytes())
        plan = run_ok(["session", "plan", "-", "--subjects", "1", "--json"], d)
        self.assertEqual(json.loads(plan.stdout)["protocol"], "two")

    def test_arguments_not_utf8_are_refused_naming_the_argument_and_the_bytes(self):
        for args, name, shown in ((["trial", b"\xe6\xb0"], "CHARS", r"(\xe6\xb0)"),
                                  (["model", b"\xff"], "CHAR", r"(\xff)"),
                                  (["score", "t.csv", "--character", b"\xe5\x8d"], "--character", r"(\xe5\x8d)"),
                                  (["characters", "--text", b"a\xc0\xafb"], "--text", "byte 1"),
                                  (["bench", "tick", "--chars", b"\xed\xa0\x80"], "--chars", r"\xed\xa0\x80"),
                                  (["curriculum", ".", "--subject", "S", "--from", b"\xe6"], "--from", r"\xe6")):
            with self.subTest(args=args):
                result = run(args, self.tmp)
                result.stderr.decode("utf-8")  # printable text: no byte that is not UTF-8
                self.assertEqual(result.stdout, b"")
                self.assert_one_error(result, 2, name, "malformed UTF-8", shown)

    def test_a_100_kB_argument_gives_one_error_line_cut_near_2000_bytes(self):
        long_digits, long_name = "9" * 100_000, "a" * 100_000
        for args in (["trial", "十", "--seed", long_digits], ["trial", "十", "--device", long_name],
                     ["trial", "十", "--" + long_name], [long_name],
                     ["session", "run", "p.json", "--subject", long_name, "--out", "o"]):
            with self.subTest(args=args[:2]):
                result = run(args, self.tmp)
                line = self.assert_one_error(result, 2)
                self.assertLess(len(line.encode()), 2100)
                self.assertRegex(line, r"\.\.\. \(\d+ more bytes\)$")

    def test_an_ascii_locale_prints_the_same_utf8_characters(self):
        outputs = []
        for locale in ("C", "C.UTF-8"):
            env = dict(ENV, LC_ALL=locale, LANG=locale)
            listed = run(["characters", "--text", "十あ"], self.tmp, env=env)
            refused = run(["model", "永字"], self.tmp, env=env)
            outputs.append((listed.returncode, listed.stdout, refused.returncode, refused.stderr))
        self.assertEqual(outputs[0], outputs[1])
        code, listed, status, refused = outputs[0]
        self.assertEqual((code, status), (0, 2))
        self.assertIn("十    U+5341", listed.decode("utf-8"))
        self.assertIn("あ (U+3042)", listed.decode("utf-8"))
        self.assertIn("永 (U+6C38), 字 (U+5B57)", refused.decode("utf-8"))

    # ---- file names that are not UTF-8 in what a command writes ----------------------------------------------

    def assert_written_or_refused(self, result, name, outputs):
        """The run wrote valid JSON (status 0) or refused in one line naming `name` printably (status 1), never
        an internal error (status 3); `outputs`: the files that must then be whole JSON, or absent."""
        self.assertNotIn(b"internal error", result.stderr, result.stderr)
        self.assertIn(result.returncode, (0, 1), result.stderr)
        if result.returncode == 0:
            for path in outputs:
                json.loads(path.read_bytes())
        else:
            self.assert_one_error(result, 1, name)
            for path in outputs:
                self.assertFalse(path.exists(), path)

    def test_score_json_of_a_trace_named_in_latin1_is_written_or_refused(self):
        d = self.folder()
        shutil.copy(self.tmp / "t.csv", os.path.join(os.fsencode(d), b"caf\xe9.csv"))
        to_file = run(["score", b"caf\xe9.csv", "--character", "十", "--json", "s.json"], d)
        self.assert_written_or_refused(to_file, r"caf\xe9.csv", [d / "s.json"])
        to_stdout = run(["score", b"caf\xe9.csv", "--character", "十", "--json", "-"], d)
        self.assert_written_or_refused(to_stdout, r"caf\xe9.csv", [])
        if to_stdout.returncode == 0:
            json.loads(to_stdout.stdout)

    def test_replay_of_a_teacher_named_in_latin1_is_written_or_refused(self):
        d = self.folder()
        run_ok(["trial", "十", "--writer-profile", "skilled", "--record", b"t\xe9.json"], d)
        result = run(["trial", "十", "--guidance-mode", "replay", "--teacher", b"t\xe9.json", "--json", "r.json"],
                     d)
        self.assert_written_or_refused(result, r"t\xe9.json", [d / "r.json"])

    def test_session_plan_json_of_a_protocol_named_in_latin1_is_written_or_refused(self):
        d = self.folder()
        shutil.copy(self.tmp / "p.json", os.path.join(os.fsencode(d), b"p\xe9.json"))
        result = run(["session", "plan", b"p\xe9.json", "--subjects", "1", "--json"], d)
        self.assert_written_or_refused(result, r"p\xe9.json", [])
        if result.returncode == 0:
            self.assertEqual(json.loads(result.stdout)["protocol"], "two")

    def test_session_run_of_a_protocol_named_in_latin1_runs_or_refuses_making_nothing(self):
        d = self.folder()
        shutil.copy(self.tmp / "p.json", os.path.join(os.fsencode(d), b"p\xe9.json"))
        result = run(["session", "run", b"p\xe9.json", "--subject", "S01", "--out", "out"], d)
        self.assert_written_or_refused(result, r"p\xe9.json", [])
        if result.returncode == 0:
            for manifest in (d / "out").glob("S01/*/session.json"):
                json.loads(manifest.read_bytes())
        else:
            self.assertFalse((d / "out").exists())

    def test_characters_and_corpus_stats_json_of_a_data_folder_or_store_named_in_latin1(self):
        d = self.folder()
        data = os.path.join(os.fsencode(d), b"d\xe9")
        os.mkdir(data)
        shutil.copy(SOURCE / "data" / "hanzi-writer-data" / "十.json", os.path.join(data, os.fsencode("十.json")))
        run_ok(["corpus", "build", "--data", b"d\xe9", "--out", b"s\xe9.clg"], d)
        for args in (["characters", "--data", b"d\xe9", "--json"], ["characters", "--store", b"s\xe9.clg", "--json"],
                     ["corpus", "stats", b"s\xe9.clg", "--json"]):
            with self.subTest(args=args):
                result = run(args, d)
                self.assert_written_or_refused(result, "\\xe9", [])
                if result.returncode == 0:
                    json.loads(result.stdout)

    def test_curriculum_reads_a_study_folder_named_in_latin1_as_under_another_name(self):
        # docs/cli.md, curriculum: it reads the learner's saved trials and writes no table; only `report --csv`
        # refuses such a folder, for the tables it would write.
        d = self.folder()
        run_ok(["session", "run", str(self.tmp / "p.json"), "--subject", "S01", "--out", b"o\xe9"], d)
        os.symlink(b"o\xe9", os.path.join(os.fsencode(d), b"study"))
        ask = ["--subject", "S01", "--from", "十二人口", "--json"]
        plain = run_ok(["curriculum", "study", *ask], d)
        latin = run(["curriculum", b"o\xe9", *ask], d)
        self.assertEqual((latin.returncode, latin.stderr), (0, b""))
        self.assertEqual(json.loads(latin.stdout), json.loads(plain.stdout))

    # ---- standard output and error --------------------------------------------------------------------------

    def test_a_closed_or_full_stdout_is_one_error_line_exit_1_with_the_files_whole(self):
        d = self.folder()
        closed = run(["trial", "十", "--json", "f.json", "--csv", "f.csv"], d, stdout=None,
                     preexec_fn=lambda: os.close(1))
        self.assert_one_error(closed, 1, "standard output")
        self.assertEqual(json.loads((d / "f.json").read_text(encoding="utf-8"))["end_reason"], "completed")
        self.assertTrue((d / "f.csv").read_text(encoding="utf-8").startswith("t,x,y,z,"))
        self.assertEqual(sorted(os.listdir(d)), ["f.csv", "f.json"])
        with open("/dev/full", "wb") as full:
            for args in (["strokes"], ["--version"], ["trial", "--help"], ["model", "十", "--svg", "-"]):
                with self.subTest(args=args):
                    self.assert_one_error(run(args, d, stdout=full), 1, "standard output")

    def test_verbose_info_lines_go_to_stderr_in_the_commands_form_only(self):
        d = self.folder()
        quiet = run(["trial", "十", "--pacing", "real-time", "--max-duration", "0.15", "--json", "-"], d)
        loud = run(["trial", "十", "--pacing", "real-time", "--max-duration", "0.15", "--json", "-", "--verbose"], d)
        for result in (quiet, loud):
            self.assertEqual(result.returncode, 1)  # the time limit: an aborted trial
            self.assertEqual(json.loads(result.stdout)["end_reason"], "time_limit")
            for line in error_lines(result):
                self.assertTrue(line.startswith("calligraphy trial: "), line)
        self.assertNotIn("info:", quiet.stderr.decode())
        self.assertIn("calligraphy trial: info: servo loop:", loud.stderr.decode())
        self.assertEqual(sorted(os.listdir(d)), [])

    def test_score_progress_only_on_a_terminal_and_without_escapes_on_a_dumb_one(self):
        piped = run(["score", "t.csv", "--character", "十"], self.tmp,
                    env=dict(ENV, CALLIGRAPHY_PROGRESS_AFTER_S="0"))
        self.assertEqual((piped.returncode, piped.stderr), (0, b""))
        for term in ("dumb", "xterm"):
            with self.subTest(term=term):
                main, side = pty.openpty()
                try:
                    process = subprocess.run([CLI, "score", "t.csv", "--character", "十", "--json", "-"],
                                             cwd=self.tmp, stdin=subprocess.DEVNULL, stdout=subprocess.PIPE,
                                             stderr=side, timeout=60,
                                             env=dict(ENV, CALLIGRAPHY_PROGRESS_AFTER_S="0", TERM=term))
                    os.close(side)
                    side = None
                    shown = b""
                    while select.select([main], [], [], 0.2)[0]:
                        try:
                            chunk = os.read(main, 4096)
                        except OSError:
                            break
                        if not chunk:
                            break
                        shown += chunk
                finally:
                    os.close(main)
                    if side is not None:
                        os.close(side)
                self.assertEqual(process.returncode, 0)
                json.loads(process.stdout)
                self.assertIn(b"scoring t.csv", shown)
                if term == "dumb":
                    self.assertNotIn(b"\x1b", shown)

    def test_a_trace_named_with_an_escape_and_a_line_break_is_printed_as_text(self):
        d = self.folder()
        name = "a\nb\x1b[31m.csv"
        shutil.copy(self.tmp / "t.csv", d / name)
        table = run_ok(["score", name, "--character", "十"], d).stdout.decode()
        self.assertNotIn("\x1b", table)
        self.assertTrue(table.splitlines()[0].startswith("Score of a\\nb\\x1b[31m.csv against 十"))
        missing = run(["score", "x\ny\x1b.csv", "--character", "十"], d)
        self.assertEqual(self.assert_one_error(missing, 1), "calligraphy score: error: x\\ny\\x1b.csv: no such file")

    # ---- signals --------------------------------------------------------------------------------------------

    def stopped_trial(self, sig, preexec_fn=None, max_duration="3", wait_s=0.5):
        d = self.folder()
        process = start([*REAL_TIME, "--max-duration", max_duration], d, preexec_fn)
        time.sleep(wait_s)
        process.send_signal(sig)
        out, err = process.communicate(timeout=30)
        return d, process.returncode, out, err

    def test_stop_signals_end_a_real_time_trial_with_128_plus_n_and_every_tick_written(self):
        for sig in (signal.SIGHUP, signal.SIGUSR1, signal.SIGXCPU):
            with self.subTest(signal=sig.name):
                d, status, out, err = self.stopped_trial(sig)
                self.assertEqual(status, STOP_STATUS[sig], err)
                lines = err.decode().strip().splitlines()
                self.assertEqual(len(lines), 1, lines)
                self.assertTrue(lines[0].startswith(f"calligraphy trial: stopped by {sig.name} "), lines)
                self.assertEqual(sorted(os.listdir(d)), ["t.csv", "t.json"])
                record = json.loads((d / "t.json").read_text(encoding="utf-8"))
                self.assertEqual((record["end_reason"], record["abort_reason"]),
                                 ("interrupted", f"stopped by {sig.name}"))
                rows = (d / "t.csv").read_text(encoding="utf-8").splitlines()
                self.assertEqual(len(rows) - 1, record["loop"]["ticks"])
                self.assertIn(f"stopped by {sig.name}", out.decode())

    def test_sigint_with_json_on_stdout_leaves_stdout_that_json_alone(self):
        d = self.folder()
        process = start(["trial", "十", "--pacing", "real-time", "--max-duration", "3", "--json", "-"], d)
        time.sleep(0.5)
        process.send_signal(signal.SIGINT)
        out, err = process.communicate(timeout=30)
        self.assertEqual(process.returncode, 130, err)
        record = json.loads(out)
        self.assertEqual((record["end_reason"], record["abort_reason"]), ("interrupted", "stopped by SIGINT"))

    def test_an_ignored_sighup_lets_the_trial_go_on_and_an_ignored_sigint_still_stops_it(self):
        def ignoring(sig):
            return lambda: signal.signal(sig, signal.SIG_IGN)
        d, status, _, err = self.stopped_trial(signal.SIGHUP, ignoring(signal.SIGHUP), max_duration="0.8",
                                               wait_s=0.3)
        self.assertEqual(status, 1, err)  # the trial ran on to its time limit, not stopped by the signal
        self.assertEqual(json.loads((d / "t.json").read_text(encoding="utf-8"))["end_reason"], "time_limit")
        d, status, _, err = self.stopped_trial(signal.SIGINT, ignoring(signal.SIGINT))
        self.assertEqual(status, 130, err)
        self.assertEqual(json.loads((d / "t.json").read_text(encoding="utf-8"))["end_reason"], "interrupted")

    def test_a_blocked_stop_signal_pending_at_the_start_stops_it_writing_nothing(self):
        for sig in (signal.SIGTERM, signal.SIGHUP):
            with self.subTest(signal=sig.name):
                d = self.folder()

                def pending(sig=sig):
                    signal.pthread_sigmask(signal.SIG_BLOCK, {sig})
                    os.kill(os.getpid(), sig)
                process = start([*REAL_TIME, "--max-duration", "3"], d, pending)
                out, err = process.communicate(timeout=30)
                self.assertEqual(process.returncode, STOP_STATUS[sig], err)
                self.assertIn(f"stopped by {sig.name}", err.decode())
                self.assertEqual(sorted(os.listdir(d)), [])

    def test_sigquit_ends_the_trial_at_once_writing_nothing(self):
        d, status, out, _ = self.stopped_trial(signal.SIGQUIT, wait_s=0.3)
        self.assertEqual(status, -signal.SIGQUIT)
        self.assertEqual(out, b"")
        self.assertEqual(sorted(os.listdir(d)), [])

    def test_a_pause_longer_than_the_watchdog_ends_the_trial_on_sigcont(self):
        for watchdog, end in (("50", "watchdog"), ("0", "time_limit")):
            with self.subTest(watchdog_ms=watchdog):
                d = self.folder()
                process = start([*REAL_TIME, "--max-duration", "0.6", "--watchdog-ms", watchdog], d)
                time.sleep(0.25)
                process.send_signal(signal.SIGSTOP)
                time.sleep(0.2)
                process.send_signal(signal.SIGCONT)
                _, err = process.communicate(timeout=30)
                self.assertEqual(process.returncode, 1, err)
                record = json.loads((d / "t.json").read_text(encoding="utf-8"))
                self.assertEqual(record["end_reason"], end)
                self.assertGreaterEqual(record["loop"]["late_ticks"], 1)

    def test_bench_loop_stopped_prints_its_statistics_and_an_ignored_sighup_lets_it_run(self):
        process = start(["bench", "loop", "--seconds", "5", "--rate", "200", "--realtime", "off", "--json"],
                        self.tmp)
        time.sleep(0.3)
        process.send_signal(signal.SIGTERM)
        out, err = process.communicate(timeout=30)
        self.assertEqual(process.returncode, 143, err)
        self.assertIn("calligraphy bench loop: stopped by SIGTERM", err.decode())
        self.assertLess(json.loads(out)["ticks"], 5 * 200)
        process = start(["bench", "loop", "--seconds", "0.5", "--rate", "200", "--realtime", "off", "--json"],
                        self.tmp, lambda: signal.signal(signal.SIGHUP, signal.SIG_IGN))
        time.sleep(0.2)
        process.send_signal(signal.SIGHUP)
        out, err = process.communicate(timeout=30)
        self.assertEqual(process.returncode, 0, err)
        self.assertGreaterEqual(json.loads(out)["ticks"], 60)  # stopped at 0.2 s it would hold some 40

    def test_session_run_stopped_names_its_resume_and_the_resume_completes_it(self):
        d = self.folder()
        process = start(["session", "run", str(self.tmp / "p.json"), "--subject", "S01", "--out", "out",
                         "--pacing", "real-time"], d)
        time.sleep(0.5)
        process.send_signal(signal.SIGTERM)
        out, err = process.communicate(timeout=30)
        self.assertEqual(process.returncode, 143, err)
        session = next((d / "out" / "S01").glob("two-S01-*"))
        folder = f"out/S01/{session.name}"
        self.assertIn(f"calligraphy session run: stopped by SIGTERM; resume with: calligraphy session resume "
                      f"{folder}", err.decode().splitlines())
        lines = out.decode().splitlines()
        self.assertEqual(len(lines), 1, lines)
        self.assertTrue(lines[0].startswith(f"S01: 0 of 2 trials saved (0 now, 1 attempt kept) in {folder}, "),
                        lines)
        done = run_ok(["session", "resume", folder, "--pacing", "lock-step"], d)
        self.assertTrue(done.stdout.decode().startswith("S01: 2 of 2 trials saved (2 now"), done.stdout)

    def test_train_that_loses_its_display_exits_4_keeping_the_trial_and_printing_nothing_on_stdout(self):
        server = start_own_x_server(screen="800x600x24")
        if server is None:
            self.skipTest("Xvfb is missing or did not start")
        xvfb, display = server
        self.addCleanup(xvfb.wait)
        self.addCleanup(xvfb.kill)
        d = self.folder()
        env = dict(ENV, DISPLAY=display)
        process = subprocess.Popen([CLI, "train", "十", "--exit-after", "30", "--no-demo", "--window", "800x480",
                                    "--session", "sess"], cwd=d, env=env, stdin=subprocess.DEVNULL,
                                   stdout=subprocess.PIPE, stderr=subprocess.PIPE)
        deadline = time.monotonic() + 20
        while not list((d / "sess").glob("anonymous/train-*")) and process.poll() is None \
                and time.monotonic() < deadline:
            time.sleep(0.05)
        time.sleep(0.5)
        xvfb.kill()
        out, err = process.communicate(timeout=30)
        if process.returncode == 1 and b"CALLIGRAPHY_BUILD_TRAINER" in err:
            self.skipTest("a build without the trainer")
        self.assertEqual(process.returncode, 4, err)
        self.assertEqual(out, b"")
        self.assertIn("the display was lost", err.decode())
        attempts = list((d / "sess").glob("anonymous/train-*/trials/attempts/*.json"))
        self.assertEqual(len(attempts), 1, err)
        record = json.loads(attempts[0].read_text(encoding="utf-8"))
        self.assertEqual((record["end_reason"], record["abort_reason"]), ("interrupted", "stopped by display_lost"))


if __name__ == "__main__":
    unittest.main()
