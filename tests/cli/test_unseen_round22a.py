#!/usr/bin/env python3
"""Round 22A: every error the docs promise, taken as a checklist. From the docs alone (docs/cli.md
"Conventions", "Exit statuses", "Checked before anything runs" and each command's section; docs/python.md
"Errors"; each command's --help).

Earlier rounds attacked one surface at a time; this one takes the docs' own sentences that promise a refusal,
an error or an exit status, and provokes each with the cheapest command that reaches it. Every refusal is held
to the general rules as well as to its sentence: the documented status, one line on standard error in the
form `calligraphy COMMAND: error: ...` (no traceback, no `terminate called`, no log prefix) naming the
option, file, JSON pointer or character at fault, nothing on standard output, and no file or folder made or
changed, no temporary left. Where one sentence covers many options, one option of each command that has one.

The promises (docs/cli.md unless said; "status" is the exit status):

| # | command / function | the promise | where |
|---|---|---|---|
| 1 | any | an unknown command is named with the close ones, status 2 | Conventions, Mistyped names |
| 2 | any | an unknown option is named with the close one, status 2, even when a required one is missing | Mistyped names |
| 3 | trial, session run | `--writer`'s old values say what to write instead | One meaning per option name |
| 4 | every command | an option given twice is an error | Option syntax |
| 5 | trial, score | a value starting with `-` is refused, naming the option; no file `--seed` | Option syntax |
| 6 | every flag | `--json=yes`, `--verbose=0`: `--json: a flag takes no value`; `--json=true` is the flag | Option syntax |
| 7 | every integer option | `2x`, `1.5`, `0x10`, `1e3` are errors naming option and value | Numbers |
| 8 | every range | a value past its help's range is an error naming the option | Numbers; each table |
| 9 | seeds | read exactly as 64-bit: 2^64 and -1 refused | Numbers |
| 10 | every real option | `nan`, `inf` refused naming option and value | Numbers |
| 11 | program | `--version` anywhere prints `calligraphy X.Y.Z`, `--help` exits 0 | Help and version |
| 12 | corpus, bench, session, program | a group without a command: status 2, its help on standard error | Exit statuses |
| 13 | CHARS-taking options | malformed UTF-8: status 2 naming the argument, byte offset and bytes | Characters |
| 14 | trial, model, score, bench tick/loop/jumps, curriculum, train | a character the library lacks: status 2 with its code point | Exit statuses |
| 15 | model | more than one character: `CHAR: expects one character, got 2: ...` | model |
| 16 | --data, --store | exclude each other | Characters |
| 17 | trial | a guidance mode other than fixed with guidance off; mode-only options with another mode | trial table |
| 18 | trial | a guidance law's value past its table's range, named as the option or at its pointer, with `--check` too | The trial specification |
| 19 | trial, session run | the writer/device pairings, what only the simulated writer takes, an unknown device, a pointer device, whether or not the device can be used now | trial, devices, session run |
| 19b | trial --check | checks the trial as stated: no device opened, so a device that cannot be used now does not fail it | trial table |
| 20 | trial | more than 10^7 ticks refused | trial table |
| 21 | trial | an unknown `--writer-param` key names the setting and lists the keys | trial table |
| 22 | trial | `--watchdog-ms` with lock-step, `replay` without `--teacher` | trial table |
| 23 | trial | a teacher of other characters: status 1, nothing written | trial table |
| 24 | trial | `--record` of a trial that did not complete: status 1, not written | trial table |
| 25 | trial --spec | another option with it: a usage error naming it | trial table |
| 26 | trial --spec | malformed, twice-given key, version 10 or "9", CSV, a bad value: status 2 naming file and pointer; unreadable 1 | Re-running a trial; Pen traces |
| 27 | outputs | a missing folder: status 1 naming option, path, reason; nothing made | Checked before anything runs |
| 28 | outputs | an output naming a folder: status 1 | Output folders |
| 29 | outputs | two outputs one file, an output that is an input (also a hard link): status 2 naming both | Output identity |
| 30 | outputs | two outputs `-`, `-` with a `--json` flag | Standard output |
| 31 | --out, --features | refuse `-`; `report --out /dev/null` status 2, nothing made | Standard output; report |
| 32 | outputs | a failed write (/dev/full, standard output on /dev/full): status 1, one line | Outputs |
| 33 | report | neither `--out` nor `--csv`: usage; no session folder: status 1 | report |
| 34 | session plan | a protocol's refused content: status 2, `FILE: /pointer: what` (unknown key, a character lacked, malformed, twice-given key, rate, more than 10^6 trials, more than 10^7 ticks) | Protocols; session plan |
| 35 | session plan | a protocol that cannot be read (missing, a folder, a FIFO, over 1 MiB): status 1 | Protocols |
| 36 | session cohort | a `replay` condition: status 2 naming `/conditions/N/mode` | session cohort |
| 37 | session run | a second run of a one-session protocol into the same `--out`: status 2, nothing changes | session run |
| 38 | session run, train | a person's session or train without a display: status 1, no folder made | session run; train |
| 39 | session resume | a damaged session.json (cut, key twice), `trials/` a link: status 2 naming it | Exit statuses |
| 40 | trace, score, corpus stats | a foreign or damaged file: status 1 naming it (and TRACE:LINE and column) | trace; Pen traces; corpus |
| 41 | bench --markdown | a BEGIN marker twice or without END: status 2 naming file and marker, file as it was | bench |
| 42 | bench | options that need another (`--half` without `--kanjivg`, `--priority 0` with enforce, a stall over 60 s) | bench |
| 43 | curriculum | a subject without trials, `--from` empty: 2; a folder without sessions: 1 | curriculum |
| 44 | corpus build, validate | a data folder without characters: 1, no store; `--cnchar` missing: 2 | corpus |
| 45 | Python | the exception classes and messages of docs/python.md "Errors" | python.md Errors |
| 46 | session run | a subject id past `[A-Za-z0-9_-]{1,64}`: 2; an `--out` that is a file: 1 | session run |
| 47 | train | `--window`, `--quiz` with guidance, `--quiz-screenshots` missing, `--exit-after 0`: before any window | train |
| 48 | characters, schema, trial | an unknown `--typical` names the close acronyms; an unknown document; a scene over 1,000 characters: 1 | characters; schema; Pen traces |
| 49 | report | `--out` onto a session folder's file: 2 | report |
| 50 | session run, report | a protocol edited under its name: 1 naming both SHA-256; report of two protocols of one name, or of one session twice: 1, nothing written | session run; report |
| 51 | score | more than 10,000 pen-down segments: 1 at `TRACE:LINE` of the first one too many | Pen traces |

CALLIGRAPHY_CLI names the program, PYTHONPATH its Python module. CALLIGRAPHY_SANITIZED=1 takes five cases.
"""
import json
import os
import shutil
import tempfile
import unittest
from pathlib import Path

from outsider import OneErrorLine, run, run_ok, sanitized_subset

load_tests = sanitized_subset({"test_unknown_command_is_named_with_the_close_ones",
                               "test_an_option_given_twice_is_refused_on_every_command",
                               "test_spec_content_refused_naming_file_and_pointer",
                               "test_two_outputs_that_are_one_file_are_refused_naming_both",
                               "test_protocol_content_refused_naming_file_and_pointer"})

SIM = ["--writer", "simulated", "--writer-learning", "none"]
LACKED = "あ"  # a kana: not in hanzi-writer-data
BAD_UTF8 = b"\xe6\xb0"  # a sequence cut short


def protocol(name, characters, max_duration_s, **extra):
    doc = {"name": name, "conditions": [{"name": "V", "mode": "vision"}],
           "test": {"characters": list(characters), "conditions": ["V"], "repetitions": 1},
           "trial": {"max_duration_s": max_duration_s}}
    doc.update(extra)
    return doc


def twice_seed(text, seed):
    """A record's text with the specification's trial `seed` given twice (the record's own top-level `seed`
    left as it is)."""
    at = text.index('"seed":', text.index('"trial":', text.index('"specification":')))
    return text[:at] + f'"seed": {seed}, ' + text[at:]


def tree(root):
    """Every file under `root` (hidden ones too) with its size and modification time, every folder by name. A
    study folder's run lock (`.calligraphy-run.lock`), which a run or resume takes before it reads anything and
    leaves empty, by its size alone."""
    out = {}
    for dirpath, dirnames, filenames in os.walk(root):
        for d in dirnames:
            out[os.path.relpath(os.path.join(dirpath, d), root)] = "dir"
        for f in filenames:
            st = os.lstat(os.path.join(dirpath, f))
            out[os.path.relpath(os.path.join(dirpath, f), root)] = (
                (st.st_size,) if f == ".calligraphy-run.lock" else (st.st_size, st.st_mtime_ns))
    return out


class Round22A(unittest.TestCase, OneErrorLine):
    @classmethod
    def setUpClass(cls):
        cls.tmp = Path(tempfile.mkdtemp(prefix="round22a-"))
        t = cls.tmp
        # A skilled writer's trial of 一: its record, its trace and a teacher's recording of it.
        run_ok(["trial", "一", "--writer-profile", "skilled", "--max-duration", "4", "--json", "rec.json",
                "--csv", "rec.csv", "--record", "teacher.json"], t)
        # A study of one subject writing 一 once, a second or two of simulated writing.
        (t / "p.json").write_text(json.dumps(protocol("p", "一", 3)), encoding="utf-8")
        run_ok(["session", "run", "p.json", "--subject", "S01", "--out", "study", *SIM], t)
        cls.session = next((t / "study" / "S01").glob("p-S01-*"))
        cls.h5 = next((cls.session / "trials").glob("*.trace.h5"))
        (t / "empty").mkdir()
        cls.record = json.loads((t / "rec.json").read_text(encoding="utf-8"))

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.tmp, ignore_errors=True)

    # --- the general rules of a refusal ---------------------------------------------------------------------

    def refused(self, args, status, *needles, cwd=None, stdout_empty=True):
        """Run `args` in the shared folder: `status`, one error line `calligraphy ...: error: ...` holding each
        of `needles`, nothing on standard output, nothing under the folder made, changed or left behind."""
        before = tree(self.tmp)
        result = run(args, cwd or self.tmp)
        line = self.assert_one_error(result, status, *needles)
        self.assertRegex(line, r"^calligraphy( [a-z]+)*: error: ", line)
        if stdout_empty:
            self.assertEqual(result.stdout, b"", result.stdout[:300])
        self.assertEqual(tree(self.tmp), before, f"{args}: the folder changed")
        return line

    def scratch(self, name):
        """A fresh folder outside the shared one, removed with it."""
        path = self.tmp.parent / f"{self.tmp.name}-{name}"
        shutil.rmtree(path, ignore_errors=True)
        path.mkdir()
        self.addCleanup(shutil.rmtree, path, True)
        return path

    # --- 1, 2, 3: names -------------------------------------------------------------------------------------

    def test_unknown_command_is_named_with_the_close_ones(self):
        line = self.refused(["trail", "一"], 2, "unknown command 'trail'", "'trial'", "'train'")
        self.assertIn("did you mean", line)

    def test_unknown_option_is_the_error_even_with_a_required_one_missing(self):
        self.refused(["trial", "一", "--guidence", "on"], 2, "'--guidence'", "'--guidance'")
        # score's --character is required: the mistyped name is still what is said.
        line = self.refused(["score", "rec.csv", "--charcter", "一"], 2, "'--charcter'", "'--character'")
        self.assertNotIn("required", line)

    def test_old_writer_values_say_what_to_write_instead(self):
        self.refused(["trial", "一", "--writer", "novice"], 2, "--writer-profile novice")
        self.refused(["session", "run", "p.json", "--subject", "S09", "--out", "o", "--writer", "human"], 2,
                     "--writer person")

    # --- 4-10: option syntax and numbers --------------------------------------------------------------------

    def test_an_option_given_twice_is_refused_on_every_command(self):
        cases = [
            (["trial", "一", "--seed", "1", "--seed", "2", "--check"], "--seed"),
            (["model", "一", "--svg", "a.svg", "--svg", "b.svg"], "--svg"),
            (["score", "rec.csv", "--character", "一", "--character", "十"], "--character"),
            (["trace", str(self.h5), "--csv", "a.csv", "--csv", "b.csv"], "--csv"),
            (["characters", "--strokes", "1", "--strokes", "2"], "--strokes"),
            (["strokes", "--markdown", "a.md", "--markdown", "b.md"], "--markdown"),
            (["curriculum", "study", "--subject", "S01", "--from", "十", "--count", "1", "--count", "2"],
             "--count"),
            (["report", "study", "--csv", "empty", "--jobs", "1", "--jobs", "2"], "--jobs"),
            (["session", "plan", "p.json", "--subjects", "1", "--subjects", "2"], "--subjects"),
            (["session", "cohort", "p.json", "--subjects", "1", "--csv", "empty", "--jobs", "1", "--jobs", "1"],
             "--jobs"),
            (["session", "run", "p.json", "--subject", "A1", "--subject", "A2", "--out", "o"], "--subject"),
            (["session", "resume", str(self.session), "--pacing", "auto", "--pacing", "auto"], "--pacing"),
            (["bench", "nearest", "--queries", "1", "--queries", "2"], "--queries"),
            (["bench", "loop", "--seconds", "0.01", "--seconds", "0.01"], "--seconds"),
            (["corpus", "build", "--out", "a.clg", "--out", "b.clg", "--data", "empty"], "--out"),
        ]
        for args, option in cases:
            with self.subTest(args=args):
                self.refused(args, 2, option)

    def test_a_value_that_starts_with_a_dash_is_refused_naming_the_option(self):
        self.refused(["trial", "一", "--json", "--seed", "3"], 2, "--json")
        self.assertFalse((self.tmp / "--seed").exists())
        self.refused(["score", "rec.csv", "--json", "--character", "一"], 2, "--json")
        self.refused(["session", "plan", "p.json", "--subjects", "1", "--subject", "-x"], 2, "--subject")

    def test_a_flag_takes_no_value_on_every_command_that_has_one(self):
        cases = [["model", "一", "--json=yes"], ["strokes", "--json=1"], ["characters", "--json=no"],
                 ["devices", "--json=yes"], ["corpus", "stats", "rec.csv", "--json=yes"],
                 ["bench", "nearest", "--json=yes", "--queries", "1"], ["curriculum", "study", "--subject", "S01",
                                                                         "--from", "十", "--json=0"],
                 ["session", "plan", "p.json", "--subjects", "1", "--json=yes"],
                 ["model", "一", "--verbose=0"], ["trial", "一", "--check=yes"]]
        for args in cases:
            flag = next(a for a in args if "=" in a).split("=")[0]
            with self.subTest(args=args):
                self.refused(args, 2, f"{flag}: a flag takes no value")
        # --json=true, the flag's own value, is the flag.
        r = run_ok(["model", "一", "--json=true"], self.tmp)
        self.assertIsInstance(json.loads(r.stdout), dict)

    def test_integer_options_take_decimal_digits_only(self):
        forms = ["2x", "1.5", "0x10", "1e3"]
        cases = [
            ["trial", "一", "--check", "--hint-after-misses"],
            ["characters", "--strokes"],
            ["curriculum", "study", "--subject", "S01", "--from", "十", "--count"],
            ["report", "study", "--csv", "empty", "--jobs"],
            ["session", "plan", "p.json", "--subjects"],
            ["session", "cohort", "p.json", "--subjects", "1", "--csv", "empty", "--jobs"],
            ["session", "run", "p.json", "--out", "o", "--subject", "S", "--subjects"],
            ["bench", "nearest", "--queries"],
            ["bench", "jumps", "--chars", "一", "--seeds"],
            ["bench", "tick", "--chars", "一", "--passes"],
            ["bench", "loop", "--seconds", "0.01", "--priority"],
            ["bench", "acceptance", "--characters"],
            ["corpus", "build", "--out", "s.clg", "--data", "empty", "--threads"],
            ["corpus", "validate", "--cnchar", "rec.csv", "--threads"],
            ["train", "一", "--hint-after-misses"],
        ]
        for i, args in enumerate(cases):
            value = forms[i % len(forms)]
            with self.subTest(args=args, value=value):
                self.refused([*args, value], 2, args[-1], value)

    def test_an_integer_past_its_documented_range_is_refused_naming_the_option(self):
        cases = [
            (["characters", "--strokes"], ["0", "256"]),
            (["trial", "一", "--check", "--rate"], ["99", "100001"]),
            (["trial", "一", "--check", "--assist-after-misses"], ["1001"]),
            (["bench", "loop", "--seconds", "0.01", "--cpu"], ["-2", "1024"]),
            (["bench", "loop", "--seconds", "0.01", "--priority"], ["100"]),
            (["report", "study", "--csv", "empty", "--jobs"], ["0", "257"]),
            (["curriculum", "study", "--subject", "S01", "--from", "十", "--count"], ["1001"]),
            (["session", "cohort", "p.json", "--csv", "empty", "--subjects"], ["0", "100001"]),
            (["session", "run", "p.json", "--out", "o", "--subject", "S", "--subjects"], ["1001"]),
            (["corpus", "validate", "--cnchar", "rec.csv", "--threads"], ["65"]),
            (["corpus", "build", "--out", "s.clg", "--data", "empty", "--threads"], ["257"]),
            (["bench", "nearest", "--queries"], ["100000001"]),
            (["bench", "acceptance", "--characters"], ["100001"]),
        ]
        for args, values in cases:
            for value in values:
                with self.subTest(args=args, value=value):
                    self.refused([*args, value], 2, args[-1])

    def test_a_seed_is_read_exactly_and_2_to_the_64_refused(self):
        for args in (["trial", "一", "--check", "--seed"], ["bench", "nearest", "--queries", "1", "--seed"],
                     ["bench", "acceptance", "--characters", "1", "--seed"], ["train", "一", "--seed"]):
            for value in ("18446744073709551616", "-1"):
                with self.subTest(args=args, value=value):
                    self.refused([*args, value], 2, "--seed", value)
        r = run_ok(["trial", "一", "--check", "--seed", "9007199254740993"], self.tmp)
        self.assertEqual(r.returncode, 0)

    def test_a_real_option_refuses_nan_and_inf_naming_it(self):
        cases = [
            ["trial", "一", "--check", "--max-duration", "nan"],
            ["trial", "一", "--check", "--corridor", "inf"],
            ["bench", "loop", "--seconds", "nan"],
            ["corpus", "build", "--out", "s.clg", "--data", "empty", "--tolerance", "inf"],
            ["corpus", "fidelity", "--data", "empty", "--tolerances", "2,nan"],
            ["train", "一", "--exit-after", "inf"],
            ["session", "run", "p.json", "--subject", "S09", "--out", "o", "--exit-after", "nan"],
        ]
        for args in cases:
            with self.subTest(args=args):
                self.refused(args, 2, args[-2], args[-1])

    # --- 11, 12: help, version and groups -------------------------------------------------------------------

    def test_version_anywhere_and_help_exit_zero(self):
        for args in (["--version"], ["trial", "--version"], ["session", "plan", "--version"]):
            r = run_ok(args, self.tmp)
            self.assertRegex(r.stdout.decode(), r"^calligraphy \d+\.\d+\.\d+\n$")
        r = run_ok(["score", "--help"], self.tmp)
        self.assertIn("--character", r.stdout.decode())

    def test_a_group_without_a_command_prints_its_help_on_stderr_status_2(self):
        for args in ([], ["corpus"], ["bench"], ["session"]):
            with self.subTest(args=args):
                r = run(args, self.tmp)
                self.assertEqual(r.returncode, 2)
                self.assertEqual(r.stdout, b"")
                self.assertIn("Usage", r.stderr.decode())
                self.assertNotIn("terminate called", r.stderr.decode())

    # --- 13-16: characters ----------------------------------------------------------------------------------

    def test_malformed_utf8_is_refused_naming_argument_offset_and_bytes(self):
        line = self.refused(["trial", BAD_UTF8], 2)
        self.assertIn("CHARS: malformed UTF-8 at byte 0 (\\xe6\\xb0): truncated sequence", line)
        cases = [(["model", BAD_UTF8], "CHAR"), (["score", "rec.csv", "--character", BAD_UTF8], "--character"),
                 (["characters", "--text", b"a" + BAD_UTF8], "--text"),
                 (["curriculum", "study", "--subject", "S01", "--from", BAD_UTF8], "--from"),
                 (["bench", "tick", "--chars", BAD_UTF8], "--chars"),
                 (["bench", "loop", "--trial", BAD_UTF8], "--trial"),
                 (["bench", "jumps", "--chars", BAD_UTF8], "--chars"), (["train", BAD_UTF8], "CHARS")]
        for args, name in cases:
            with self.subTest(args=args):
                self.refused(args, 2, name, "malformed UTF-8 at byte", "\\xe6\\xb0")

    def test_a_character_the_library_lacks_is_named_with_its_code_point(self):
        cases = [["trial", LACKED, "--json", "x.json"], ["model", LACKED, "--svg", "x.svg"],
                 ["score", "rec.csv", "--character", LACKED, "--json", "x.json"],
                 ["bench", "tick", "--chars", LACKED], ["bench", "loop", "--trial", LACKED],
                 ["bench", "jumps", "--chars", LACKED, "--seeds", "1"],
                 ["curriculum", "study", "--subject", "S01", "--from", LACKED], ["train", LACKED]]
        for args in cases:
            with self.subTest(args=args):
                self.refused(args, 2, f"{LACKED} (U+3042)")

    def test_model_takes_one_character(self):
        self.refused(["model", "一十"], 2, "CHAR: expects one character, got 2: 一 (U+4E00), 十 (U+5341)")
        self.refused(["model", "一\ufe00"], 2, "got 2", "U+FE00")

    def test_data_and_store_exclude_each_other(self):
        for args in (["model", "一"], ["characters"], ["trial", "一", "--json", "x.json"],
                     ["score", "rec.csv", "--character", "一"], ["session", "plan", "p.json", "--subjects", "1"],
                     ["curriculum", "study", "--subject", "S01", "--from", "十"]):
            with self.subTest(args=args):
                self.refused([*args, "--data", "empty", "--store", "rec.csv"], 2, "--data", "--store")

    # --- 17-26: trial ---------------------------------------------------------------------------------------

    def test_guidance_options_that_need_another_are_usage_errors(self):
        for extra in ([], ["--check"]):
            with self.subTest(check=extra):
                self.refused(["trial", "一", "--guidance", "off", "--guidance-mode", "fading", *extra], 2,
                             "guidance_mode (--guidance-mode): 'fading' needs guidance on")
        cases = [(["--guidance", "off", "--guidance-stiffness", "300"], "--guidance-stiffness"),
                 (["--guidance-gain", "0.5"], "--guidance-gain"),
                 (["--assist-band", "0.002"], "--assist-band"),
                 (["--guidance-mode", "fading", "--amplification-gain", "0.5"], "--amplification-gain"),
                 (["--timing-speed", "0.05"], "--timing-speed")]
        for extra, name in cases:
            with self.subTest(extra=extra):
                self.refused(["trial", "一", "--json", "x.json", *extra], 2, name)

    def test_fading_gain_past_its_table_range_names_the_table_entry(self):
        for extra in ([], ["--check"]):
            with self.subTest(check=extra):
                self.refused(["trial", "一", "--guidance-mode", "fading", "--guidance-gain", "1.5", *extra], 2,
                             "--guidance-gain: guidance_gain = 1.5 must be in [0, 1]")
        work = self.scratch("gain")
        for part, pointer, entry in (("trial", "/specification/trial/guidance_gain", "TrialSpec.guidance_gain"),
                                     ("force_law", "/specification/force_law/guidance_law/gain",
                                      "FadingGuidance.gain")):
            doc = json.loads(json.dumps(self.record))
            spec = doc["specification"]
            spec["trial"]["guidance_mode"] = "fading"
            spec["force_law"]["guidance_law"] = {"mode": "fading", "gain": 1.0}
            if part == "trial":
                spec["trial"]["guidance_gain"] = 1.5
            else:
                spec["force_law"]["guidance_law"]["gain"] = 1.5
            (work / f"{part}.json").write_text(json.dumps(doc), encoding="utf-8")
            with self.subTest(record=part):
                r = run(["trial", "--spec", f"{part}.json", "--check"], work)
                self.assert_one_error(r, 2, f"{part}.json: {pointer}: expected a number in [0, 1] ({entry}), "
                                            "got 1.5")

    def test_writer_and_device_pairings_are_usage_errors(self):
        self.refused(["trial", "一", "--writer", "person", "--device", "simulated"], 2,
                     "a person cannot hold the device 'simulated'")
        line = self.refused(["trial", "一", "--device", "mouse"], 2, "mouse")
        self.assertIn("train", line)
        line = self.refused(["trial", "一", "--device", "no-such-device"], 2, "no-such-device")
        self.assertIn("simulated", line)  # the devices there are
        # Whether or not an OpenHaptics device can be used now, lock-step on a person's device is usage.
        self.refused(["trial", "一", "--device", "openhaptics", "--pacing", "lock-step"], 2, "lock-step")
        self.refused(["trial", "一", "--writer", "simulated", "--device", "openhaptics"], 2, "openhaptics")

    def test_what_only_the_simulated_writer_takes_is_usage_also_while_the_device_cannot_be_used(self):
        # Written after the first run (the case above found it): a person's device that cannot be used now
        # (no OpenHaptics library here, no Phantom on this path) hid these usage errors behind its exit 1.
        for device in ("openhaptics", "phantom-hid:/dev/no-such-hidraw"):
            for extra, name in ((["--writer-profile", "skilled"], "--writer-profile"),
                                (["--writer-param", "bias_offset_m=0.001"], "--writer-param")):
                with self.subTest(device=device, option=name):
                    self.refused(["trial", "一", "--device", device, *extra, "--json", "x.json"], 2, name)
        for extra, name in ((["--subject", "P1", "--writer-profile", "skilled"], "--writer-profile"),
                            (["--subject", "P1", "--writer-learning", "two-state"], "--writer-learning"),
                            (["--subjects", "2"], "--subjects"),
                            (["--subjects", "2", "--writer", "person"], "--subjects")):
            with self.subTest(session=extra):
                self.refused(["session", "run", "p.json", "--out", "o", "--device", "openhaptics", *extra], 2,
                             name)

    def test_check_needs_the_kind_of_device_not_the_device(self):
        # Written after the first run. `--check`: "no device opened"; a trial stated for a Phantom is valid on
        # a computer it is not plugged into, and what the kind refuses is still refused.
        for device in ("openhaptics", "phantom-hid:/dev/no-such-hidraw"):
            with self.subTest(device=device):
                before = tree(self.tmp)
                r = run(["trial", "一", "--device", device, "--check"], self.tmp)
                self.assertEqual(r.returncode, 0, r.stderr.decode())
                self.assertEqual(r.stderr, b"")
                self.assertEqual(len(r.stdout.decode().splitlines()), 1, r.stdout)
                self.assertEqual(tree(self.tmp), before)
                self.refused(["trial", "一", "--device", device, "--check", "--pacing", "lock-step"], 2,
                             "lock-step")
                self.refused(["trial", "一", "--device", device, "--check", "--writer-profile", "foreign"], 2,
                             "--writer-profile")
        # A person's device is paced in real time: the watchdog applies (and is refused under lock-step above).
        r = run(["trial", "一", "--device", "openhaptics", "--check", "--watchdog-ms", "20"], self.tmp)
        self.assertEqual(r.returncode, 0, r.stderr.decode())
        self.refused(["trial", "一", "--device", "no-such-device", "--check"], 2, "no-such-device")

    def test_a_trial_of_more_than_ten_million_ticks_is_refused(self):
        self.refused(["trial", "一", "--max-duration", "86400", "--json", "x.json"], 2, "--max-duration")
        self.refused(["trial", "一", "--max-duration", "86401", "--check"], 2, "--max-duration")
        self.refused(["trial", "一", "--max-duration", "0", "--check"], 2, "--max-duration")

    def test_an_unknown_writer_setting_is_named_and_the_keys_listed(self):
        line = self.refused(["trial", "一", "--writer-param", "no_such_key=1", "--json", "x.json"], 2,
                            "no_such_key")
        self.assertIn("bias_offset_m", line)
        self.refused(["trial", "一", "--writer-param", "bias_offset_m", "--check"], 2, "bias_offset_m")

    def test_watchdog_with_lock_step_and_replay_without_teacher(self):
        self.refused(["trial", "一", "--watchdog-ms", "10", "--pacing", "lock-step", "--check"], 2,
                     "--watchdog-ms")
        self.refused(["trial", "一", "--guidance-mode", "replay", "--json", "x.json"], 2, "--teacher")
        self.refused(["trial", "一", "--teacher", "teacher.json", "--json", "x.json"], 2, "--teacher")

    def test_a_teacher_of_other_characters_is_refused_and_nothing_written(self):
        self.refused(["trial", "十", "--guidance-mode", "replay", "--teacher", "teacher.json", "--json", "x.json"],
                     1, "teacher.json")

    def test_record_of_a_trial_that_did_not_complete_is_not_written(self):
        work = self.scratch("record")
        r = run(["trial", "一", "--max-duration", "0.02", "--record", "r.json", "--json", "j.json"], work)
        text = r.stderr.decode()
        self.assertEqual(r.returncode, 1, text)
        self.assertNotIn("Traceback", text)
        self.assertNotIn("terminate called", text)
        self.assertIn("r.json", text)
        self.assertEqual(sorted(os.listdir(work)), ["j.json"])  # the other output, no temporary
        self.assertEqual(json.loads((work / "j.json").read_text())["end_reason"], "time_limit")

    def test_spec_with_an_option_that_states_a_trial_names_it(self):
        self.refused(["trial", "--spec", "rec.json", "--seed", "3"], 2, "--seed")
        self.refused(["trial", "--spec", "rec.json", "--guidance", "off"], 2, "--guidance")
        self.refused(["trial", "一", "--spec", "rec.json"], 2, "CHARS")

    def test_spec_content_refused_naming_file_and_pointer(self):
        work = self.scratch("spec")
        text = (self.tmp / "rec.json").read_text(encoding="utf-8")
        spec = self.record["specification"]

        def forged(change):
            doc = json.loads(text)
            change(doc["specification"])
            return json.dumps(doc)

        cases = {
            "cut.json": (text[:len(text) // 2], ["cut.json", "not valid JSON at byte"]),
            "twice.json": (twice_seed(text, spec["trial"]["seed"]),
                           ["twice.json", "/specification/trial/seed", "twice"]),
            "v10.json": (forged(lambda s: s.update(version=10)), ["v10.json", "/specification/version", "1 to 9"]),
            "v9text.json": (forged(lambda s: s.update(version="9")), ["v9text.json", "/specification/version"]),
            "crossfade.json": (forged(lambda s: s["force_law"].update(crossfade_s=-1.0)),
                               ["crossfade.json", "/specification/force_law/crossfade_s"]),
            "nullseed.json": (forged(lambda s: s["trial"].update(seed=None)),
                              ["nullseed.json", "/specification/trial/seed"]),
            "param.json": (forged(lambda s: s["trial"].update(writer_parameters=[{"key": "no_such_key",
                                                                                    "value": 1}])),
                           ["param.json", "/specification/trial/writer_parameters"]),
            "unknown.json": (forged(lambda s: s["trial"].update(no_such_field=1)),
                             ["unknown.json", "/specification/trial/no_such_field"]),
        }
        for name, (content, needles) in cases.items():
            (work / name).write_text(content, encoding="utf-8")
        shutil.copy(self.tmp / "rec.csv", work / "trace.csv")
        cases["trace.csv"] = (None, ["trace.csv", "not a JSON document: it is CSV text"])
        for name, (_, needles) in cases.items():
            for extra in ([], ["--check"]):
                with self.subTest(name=name, check=extra):
                    before = tree(work)
                    r = run(["trial", "--spec", name, "--json", "out.json", *extra] if not extra else
                            ["trial", "--spec", name, *extra], work)
                    self.assert_one_error(r, 2, *needles)
                    self.assertEqual(r.stdout, b"")
                    self.assertEqual(tree(work), before)
        self.refused(["trial", "--spec", "missing.json", "--json", "x.json"], 1, "missing.json")

    # --- 27-33: outputs -------------------------------------------------------------------------------------

    def test_an_output_in_a_missing_folder_is_refused_before_anything_runs(self):
        cases = [["trial", "一", "--json", "nodir/x.json"], ["model", "一", "--svg", "nodir/m.svg"],
                 ["strokes", "--markdown", "nodir/s.md"], ["score", "rec.csv", "--character", "一", "--json",
                                                           "nodir/s.json"],
                 ["trace", str(self.h5), "--csv", "nodir/t.csv"],
                 ["bench", "nearest", "--queries", "1", "--markdown", "nodir/n.md"],
                 ["trial", "--spec", "rec.json", "--svg", "nodir/x.svg"]]
        for args in cases:
            with self.subTest(args=args):
                self.refused(args, 1, args[-2], "nodir", "does not exist")

    def test_an_output_that_names_a_folder_is_refused(self):
        for args in (["trial", "一", "--csv", "empty"], ["model", "一", "--svg", "empty"],
                     ["score", "rec.csv", "--character", "一", "--json", "empty"]):
            with self.subTest(args=args):
                self.refused(args, 1, args[-2], "empty")

    def test_two_outputs_that_are_one_file_are_refused_naming_both(self):
        self.refused(["trial", "一", "--json", "F", "--csv", "./F"], 2, "--json", "--csv")
        self.refused(["score", "rec.csv", "--character", "一", "--json", "rec.csv"], 2, "--json", "rec.csv")
        self.refused(["trial", "--spec", "rec.json", "--json", "rec.json"], 2, "--json", "--spec")
        self.refused(["trial", "十", "--guidance-mode", "replay", "--teacher", "teacher.json", "--csv",
                      "teacher.json"], 2, "--csv", "--teacher")
        work = self.scratch("links")
        shutil.copy(self.tmp / "rec.csv", work / "t.csv")
        os.link(work / "t.csv", work / "hard.csv")
        os.symlink("t.csv", work / "soft.csv")
        for other in ("hard.csv", "soft.csv"):
            with self.subTest(link=other):
                before = tree(work)
                r = run(["score", "t.csv", "--character", "一", "--json", other], work)
                self.assert_one_error(r, 2, "--json", other)
                self.assertEqual(tree(work), before)

    def test_two_outputs_on_standard_output_are_refused(self):
        self.refused(["trial", "一", "--json", "-", "--csv", "-"], 2, "--json", "--csv")
        self.refused(["model", "一", "--json", "--svg", "-"], 2, "--svg")

    def test_out_and_features_refuse_standard_output_and_a_device(self):
        self.refused(["corpus", "build", "--out", "-", "--data", "empty"], 2, "--out")
        self.refused(["corpus", "validate", "--cnchar", "rec.csv", "--features", "-"], 2, "--features")
        self.refused(["report", "study", "--out", "-"], 2, "--out")
        self.refused(["report", "study", "--out", "/dev/null"], 2, "--out")
        self.assertFalse(Path("/dev/null_files").exists())

    def test_a_failed_write_is_one_line_and_status_1(self):
        self.refused(["model", "一", "--svg", "/dev/full"], 1, "/dev/full", stdout_empty=False)
        with open("/dev/full", "wb") as full:
            r = run(["strokes"], self.tmp, stdout=full)
        self.assert_one_error(r, 1)

    def test_report_needs_an_output_and_a_session(self):
        self.refused(["report", "study"], 2, "--out", "--csv")
        self.refused(["report", "empty", "--csv", "empty"], 1, "empty")

    # --- 34-39: protocols and sessions ----------------------------------------------------------------------

    def test_protocol_content_refused_naming_file_and_pointer(self):
        work = self.scratch("protocols")
        base = protocol("q", "一", 3)
        docs = {
            "key.json": (dict(base, bogus=1), ["key.json", "/bogus"]),
            "lacked.json": (protocol("q", "一" + LACKED, 3), ["lacked.json", "/test/characters/1",
                                                             f"{LACKED} (U+3042)"]),
            "rate.json": (dict(base, trial={"max_duration_s": 3, "rate_hz": 10001}), ["rate.json",
                                                                                     "/trial/rate_hz"]),
            "ticks.json": (dict(base, trial={"max_duration_s": 86400, "rate_hz": 1000}),
                           ["ticks.json", "/trial/max_duration_s", "/trial/rate_hz"]),
            "huge.json": (protocol("q", "一", 3, conditions=[{"name": "V", "mode": "vision"},
                                                            {"name": "W", "mode": "vision"}],
                                   test={"characters": ["一"] * 1000, "conditions": ["V", "W"],
                                         "repetitions": 1000}),
                          ["huge.json", "/test", "2,000,000 trials planned",
                           "more than the limit of 1,000,000 trials"]),
        }
        for name, (doc, _) in docs.items():
            (work / name).write_text(json.dumps(doc), encoding="utf-8")
        good = json.dumps(base)
        (work / "cut.json").write_text(good[:-5], encoding="utf-8")
        docs["cut.json"] = (None, ["cut.json", "not valid JSON at byte"])
        (work / "twice.json").write_text(good.replace('"name": "q"', '"name": "q", "name": "r"'), encoding="utf-8")
        docs["twice.json"] = (None, ["twice.json", "/name", "twice"])
        for name, (_, needles) in docs.items():
            with self.subTest(name=name):
                before = tree(work)
                r = run(["session", "plan", name, "--subjects", "1"], work)
                self.assert_one_error(r, 2, *needles)
                self.assertEqual(r.stdout, b"")
                self.assertEqual(tree(work), before)

    def test_a_protocol_that_cannot_be_read_is_status_1(self):
        work = self.scratch("unreadable")
        big = json.dumps(protocol("q", "一", 3))
        (work / "big.json").write_text(big + " " * (1024 * 1024), encoding="utf-8")
        os.mkfifo(work / "fifo.json")
        (work / "folder.json").mkdir()
        for name in ("missing.json", "big.json", "fifo.json", "folder.json"):
            with self.subTest(name=name):
                before = tree(work)
                r = run(["session", "plan", name, "--subjects", "1"], work, timeout=20)
                self.assert_one_error(r, 1, name)
                self.assertEqual(r.stdout, b"")
                self.assertEqual(tree(work), before)

    def test_cohort_refuses_a_replay_condition(self):
        work = self.scratch("cohort")
        shutil.copy(self.tmp / "teacher.json", work / "teacher.json")
        doc = protocol("r", "一", 3)
        doc["conditions"] = [{"name": "R", "mode": "replay", "teachers": {"一": "teacher.json"}}]
        doc["test"]["conditions"] = ["R"]
        (work / "r.json").write_text(json.dumps(doc), encoding="utf-8")
        (work / "tables").mkdir()
        before = tree(work)
        r = run(["session", "cohort", "r.json", "--subjects", "1", "--csv", "tables"], work)
        self.assert_one_error(r, 2, "r.json", "/conditions/0/mode")
        self.assertEqual(tree(work), before)

    def test_a_second_run_of_a_one_session_protocol_is_refused(self):
        self.refused(["session", "run", "p.json", "--subject", "S01", "--out", "study", *SIM], 2, "--out",
                     "S01")

    def test_a_person_without_a_display_makes_no_folder(self):
        self.refused(["session", "run", "p.json", "--subject", "P1", "--writer", "person", "--device",
                      "mouse-hand", "--out", "people"], 1, "DISPLAY")
        self.refused(["train", "一", "--session", "trained"], 1)

    def test_resume_refuses_a_damaged_session_folder_naming_it(self):
        damage = {
            "cut": lambda s: (s / "session.json").write_bytes((s / "session.json").read_bytes()[:-40]),
            "twice": lambda s: (s / "session.json").write_text(
                (s / "session.json").read_text(encoding="utf-8").replace('"version":', '"version": 2, "version":',
                                                                         1), encoding="utf-8"),
            "link": lambda s: (shutil.move(str(s / "trials"), str(s.parent / "elsewhere")),
                               os.symlink(s.parent / "elsewhere", s / "trials")),
        }
        for name, change in damage.items():
            with self.subTest(name=name):
                work = self.scratch(f"resume-{name}")
                shutil.copytree(self.tmp / "study", work / "study", symlinks=True)
                session = work / "study" / "S01" / self.session.name
                change(session)
                before = tree(work)
                r = run(["session", "resume", str(session)], work)
                needle = "trials" if name == "link" else "session.json"
                self.assert_one_error(r, 2, needle)
                self.assertEqual(r.stdout, b"")
                self.assertEqual(tree(work), before)

    # --- 40-44: the other commands --------------------------------------------------------------------------

    def test_a_foreign_or_damaged_file_is_refused_naming_it(self):
        self.refused(["trace", "rec.csv"], 1, "rec.csv")
        self.refused(["corpus", "stats", "rec.csv"], 1, "rec.csv")
        work = self.scratch("damaged")
        data = self.h5.read_bytes()
        (work / "cut.trace.h5").write_bytes(data[:len(data) // 2])
        lines = (self.tmp / "rec.csv").read_text(encoding="utf-8").splitlines()
        header = lines[0].split(",")
        x = header.index("x")
        far = lines[3].split(",")
        far[x] = "1e308"
        (work / "far.csv").write_text("\n".join([lines[0], lines[1], lines[2], ",".join(far), *lines[4:]]) + "\n",
                                      encoding="utf-8")
        (work / "both.csv").write_text("t,x,y,z,pen\n0,0,0,0,1\n0.001,0,0,0,1\n", encoding="utf-8")
        (work / "quoted.csv").write_text('t,x,y,pen\n0,0,0,1\n"0,001",0,0,1\n', encoding="utf-8")
        cases = [(["trace", "cut.trace.h5"], ["cut.trace.h5"]),
                 (["score", "cut.trace.h5", "--character", "一"], ["cut.trace.h5"]),
                 (["score", "far.csv", "--character", "一"], ["far.csv:4", "x"]),
                 (["score", "both.csv", "--character", "一"], ["both.csv", "pen", "z"]),
                 (["score", "quoted.csv", "--character", "一"], ["quoted.csv:3"])]
        for args, needles in cases:
            with self.subTest(args=args):
                before = tree(work)
                r = run([*args, "--json" if args[0] == "score" else "--csv", "out"], work)
                self.assert_one_error(r, 1, *needles)
                self.assertEqual(r.stdout, b"")
                self.assertEqual(tree(work), before)

    def test_a_markdown_document_with_a_broken_section_is_left_as_it_was(self):
        begin = "<!-- BEGIN generated by `calligraphy bench jumps` -->"
        end = "<!-- END generated -->"
        work = self.scratch("markdown")
        (work / "twice.md").write_text(f"# Doc\n{begin}\nold\n{end}\n{begin}\nold\n{end}\n", encoding="utf-8")
        (work / "open.md").write_text(f"# Doc\n{begin}\nold\n", encoding="utf-8")
        for name in ("twice.md", "open.md"):
            with self.subTest(name=name):
                before = tree(work)
                r = run(["bench", "jumps", "--chars", "一", "--seeds", "1", "--markdown", name], work)
                self.assert_one_error(r, 2, name, "BEGIN")
                self.assertEqual(r.stdout, b"")
                self.assertEqual(tree(work), before)

    def test_bench_options_that_need_another_are_usage_errors(self):
        for option, value in (("--half", "both"), ("--assist-after-misses", "3"), ("--form-tolerance-mm", "5")):
            with self.subTest(option=option):
                self.refused(["bench", "acceptance", "--characters", "1", option, value], 2, option)
        self.refused(["bench", "loop", "--seconds", "0.01", "--priority", "0", "--realtime", "enforce"], 2,
                     "--priority")
        self.refused(["bench", "loop", "--seconds", "0.01", "--rate", "10000", "--watchdog-periods", "1000000"], 2,
                     "--watchdog-periods", "--rate")
        self.refused(["bench", "loop", "--trial", "一", "--seconds", "86400", "--rate", "1000"], 2, "--seconds")

    def test_curriculum_refusals(self):
        self.refused(["curriculum", "study", "--subject", "nobody", "--from", "十"], 2, "nobody")
        self.refused(["curriculum", "study", "--subject", "S01", "--from", ""], 2, "--from")
        self.refused(["curriculum", "empty", "--subject", "S01", "--from", "十"], 1, "empty")

    def test_corpus_refusals(self):
        self.refused(["corpus", "build", "--data", "empty", "--out", "s.clg"], 1, "empty")
        self.refused(["corpus", "validate", "--data", "empty"], 2, "--cnchar")
        self.refused(["corpus", "validate", "--cnchar", "missing.js"], 1, "missing.js")

    def test_session_run_refuses_a_subject_id_and_an_out_it_cannot_take(self):
        for subject in ("a.b", "x" * 65, "S 1"):
            with self.subTest(subject=subject):
                self.refused(["session", "run", "p.json", "--subject", subject, "--out", "o", *SIM], 2,
                             "--subject")
        # --out must be a folder or not exist yet below one (a file is neither).
        self.refused(["session", "run", "p.json", "--subject", "S02", "--out", "rec.csv", *SIM], 1, "--out",
                     "rec.csv")

    def test_train_refuses_before_any_window_opens(self):
        self.refused(["train", "一", "--window", "799x480"], 2, "--window", "799x480")
        self.refused(["train", "一", "--window", "8193x800"], 2, "--window")
        self.refused(["train", "一", "--quiz", "--guidance-mode", "fading"], 2, "--quiz")
        self.refused(["train", "一", "--quiz", "--teacher", "teacher.json"], 2, "--teacher")
        self.refused(["train", "一", "--quiz", "--quiz-screenshots", "nodir"], 1, "--quiz-screenshots", "nodir")
        self.refused(["train", "一", "--exit-after", "0"], 2, "--exit-after")
        self.refused(["train", "一", "--subject", "a/b", "--session", "s"], 2, "--subject")

    def test_the_smaller_refusals_of_characters_schema_and_a_scene(self):
        line = self.refused(["characters", "--typical", "HZX"], 2, "--typical", "HZX")
        self.assertIn("HZG", line)  # the close acronyms
        self.refused(["schema", "spec"], 2, "spec")
        # A scene of more than 1,000 characters, refused before any is loaded (status 1, docs/cli.md "Pen
        # traces: format and limits"), with --check too.
        for extra in ([], ["--check"]):
            with self.subTest(check=extra):
                self.refused(["trial", "一" * 1001, *extra], 1, "CHARS", "1000")

    def test_report_out_onto_a_session_file_is_refused(self):
        for name in ("session.json", "log.jsonl"):
            with self.subTest(name=name):
                self.refused(["report", "study", "--out", str(self.session / name)], 2, "--out", name)

    def test_one_protocol_name_for_two_protocols_is_refused(self):
        work = self.scratch("edited")
        shutil.copytree(self.tmp / "study", work / "study", symlinks=True)
        (work / "p.json").write_text(json.dumps(protocol("p", "一", 4)), encoding="utf-8")  # edited since
        before = tree(work)
        r = run(["session", "run", "p.json", "--subject", "S02", "--out", "study", *SIM], work)
        self.assert_one_error(r, 1, "p.json", "'p'", self.session.name, "SHA-256")
        self.assertEqual(r.stdout, b"")
        self.assertEqual(tree(work), before)
        # Its sessions run into another folder, then reported together with the first study's: nothing written.
        run_ok(["session", "run", "p.json", "--subject", "S02", "--out", "other", *SIM], work)
        shutil.copytree(work / "study", work / "again", symlinks=True)  # the same session twice
        (work / "tables").mkdir()
        for dirs, needles in ((["study", "other"], ["session.json", "SHA-256"]),
                              (["study", "again"], ["S01", "twice"])):
            with self.subTest(dirs=dirs):
                before = tree(work)
                r = run(["report", *dirs, "--csv", "tables", "--out", "r.html"], work)
                self.assert_one_error(r, 1, *needles)
                self.assertEqual(tree(work), before)

    def test_a_trace_of_more_than_ten_thousand_segments_is_refused_at_its_line(self):
        work = self.scratch("segments")
        lines = ["t,x,y,pen"]
        for i in range(10001):
            lines += [f"{2 * i / 1000:.3f},0,0,1", f"{(2 * i + 1) / 1000:.3f},0,0,0"]
        (work / "seg.csv").write_text("\n".join(lines) + "\n", encoding="utf-8")
        before = tree(work)
        r = run(["score", "seg.csv", "--character", "一", "--json", "s.json"], work)
        self.assert_one_error(r, 1, "seg.csv:20002", "10000")
        self.assertEqual(r.stdout, b"")
        self.assertEqual(tree(work), before)

    # --- 45: Python -----------------------------------------------------------------------------------------

    def test_python_errors_are_the_documented_classes_naming_the_argument(self):
        import numpy as np

        import calligraphy as cg
        self.assertTrue(issubclass(cg.InvalidArgument, ValueError))
        self.assertTrue(issubclass(cg.CharacterNotFound, KeyError) and issubclass(cg.CharacterNotFound,
                                                                                   cg.DataError))
        with self.assertRaisesRegex(cg.InvalidArgument, r"key: typical-stroke ID 40 is not in 1\.\.39"):
            cg.typical_stroke(40)
        for seed in (2**64, -1, np.int64(-1)):
            with self.subTest(seed=seed), self.assertRaisesRegex(cg.InvalidArgument, "seed"):
                cg.simulate_trial("一", seed=seed, max_duration_s=0.01)
        with self.assertRaisesRegex(TypeError, "rate_hz"):
            cg.simulate_trial("一", rate_hz="fast", max_duration_s=0.01)
        with self.assertRaisesRegex(cg.InvalidArgument, "characters: .*surrogate"):
            cg.simulate_trial("\ud800", max_duration_s=0.01)
        lib = cg.CharacterLibrary.embedded()
        with self.assertRaisesRegex(cg.CharacterNotFound, "U\\+3042"):
            lib.load(LACKED)
        with self.assertRaisesRegex(cg.InvalidArgument, "U\\+4E00.*U\\+5341"):
            lib.load("一十")
        with self.assertRaisesRegex(cg.InvalidArgument, "characters: 1001 .*1,?000"):
            cg.Scene("一" * 1001)
        from calligraphy import study
        with self.assertRaisesRegex(cg.InvalidArgument, "NUL"):
            study.load("a\0b")
        # Columns of different lengths are refused naming each column and its length.
        with self.assertRaisesRegex(cg.InvalidArgument, r"(?s)(t\b.*3.*x\b.*2)|(x\b.*2.*t\b.*3)"):
            cg.score({"t": [0.0, 0.001, 0.002], "x": [0.0, 0.0], "y": [0.0, 0.0, 0.0], "pen": [1, 1, 1]}, "一")
        # A record's refused content is InputError in C++, DataError in Python.
        cut = self.scratch("python") / "cut.json"
        cut.write_text((self.tmp / "rec.json").read_text(encoding="utf-8")[:100], encoding="utf-8")
        with self.assertRaisesRegex(cg.DataError, "cut.json"):
            cg.rerun_trial(str(cut))


if __name__ == "__main__":
    unittest.main()
