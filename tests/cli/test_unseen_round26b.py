#!/usr/bin/env python3
"""Round 26B: the environment a command runs in. From the docs alone (README.md; docs/cli.md "Conventions",
"Exit statuses", "Stopping a trial", "Pen traces: format and limits", "corpus", "devices", "session run |
resume", "report"; docs/experiments.md "Sessions", "Log events"; docs/devices.md "OpenHaptics"; docs/python.md
"The design's questions"; each `--help`).

Every command and the Python module run in the environments labs and CI machines give them:
- locale: LC_ALL POSIX, C.UTF-8, a name no system has, and a decimal-comma locale compiled into the test's
  own folder with localedef (LOCPATH; ASCII, so that it compiles in milliseconds): records, tables, JSON and
  the table on standard output byte for byte those of the default locale, and a number spelt with a comma
  (`--max-duration 0,4`, `--writer-param KEY=0,004`) refused, never read as 0;
- TZ: zones of +14 h and -3:30 h, a name no zone has, a file that is not a zone: session ids, `created_utc`,
  the log's `time_utc` and a record's start and end in UTC (docs/experiments.md), the tables unchanged;
- umask 000, 077 and 0777: new files 0666 less it, folders 0777 less it, a replaced file's bits kept, and the
  next command still reading what was written;
- HOME unset or a file, XDG_CACHE_HOME a file or 100 kB long; TMPDIR missing, a file, unwritable (/proc) or
  5,000 bytes long;
- the working folder removed, immutable, or named with a space, a line break and a byte that is not UTF-8;
  output folders and trace files named with a line break or an escape sequence, in the lines a command prints;
- standard output closed, /dev/full, a pipe closed early, a non-blocking pipe; standard error closed or
  /dev/full; no standard input; no controlling terminal; a terminal with TERM=dumb and NO_COLOR;
- CALLIGRAPHY_LIBHD a text file, 100 kB long, bytes that are not UTF-8; CALLIGRAPHY_PROGRESS_AFTER_S 0 into a
  log;
- PATH without Rscript, with a broken one, with a folder its user cannot read (Python's mixed models);
- COLUMNS 1 and 100000 for the help texts; nice 19; RLIMIT_CPU ending a lock-step trial; RLIMIT_NPROC 1
  (as nobody) where a command starts a thread or a process.
Each case expects the documented outcome, or one error line naming the thing with the documented exit status;
never a crash, a traceback, a changed byte, a file lost or left half-written.

Left out: `train` and a person's session (they need a display; tests/cli/test_unseen_round11c.py runs the
window), CALLIGRAPHY_PRINT_BOXES and CALLIGRAPHY_PANEL_TEXT (read by the window only), a real-time trial under
a real-time scheduler (the machine gives no SCHED_FIFO), `session cohort` and `corpus build` with data (their
cost).

CALLIGRAPHY_CLI names the program, CALLIGRAPHY_SOURCE_DIR the source tree, PYTHONPATH the Python module.
CALLIGRAPHY_SANITIZED=1 takes five cases.
"""
import calendar
import fcntl
import json
import os
import pty
import re
import resource
import select
import shutil
import signal
import stat
import subprocess
import sys
import tempfile
import time
import unittest
from pathlib import Path

from outsider import CLI, ENV, OneErrorLine, error_lines, run, sanitized_subset

# Not the decimal-comma cases under the sanitizers: glibc keeps an allocation when it loads a locale from
# LOCPATH (argz_add_sep in its locale search), which LeakSanitizer reports as the program's.
load_tests = sanitized_subset({"test_lc_all_posix_trial_outputs_byte_for_byte",
                               "test_umask_077_trace_csv_is_0600_and_scored",
                               "test_session_times_are_utc_under_a_zone_of_plus_14_hours",
                               "test_umask_0777_session_folder_still_read_by_report",
                               "test_rlimit_cpu_ends_a_lock_step_trial_with_152_and_whole_outputs"})

YI = "一"
PYTHON = "/usr/bin/python3"
NOBODY = 65534
# The environment every case starts from: no locale, no zone, the corpus variables kept.
BASE_ENV = {k: v for k, v in ENV.items()
            if not (k.startswith("LC_") or k in ("LANG", "LANGUAGE", "TZ", "COLUMNS", "NO_COLOR", "TERM"))}
# A decimal-comma locale: LC_NUMERIC of German, the rest POSIX; compiled into a folder named by LOCPATH.
COMMA_LOCALE_SOURCE = """LC_CTYPE
copy "POSIX"
END LC_CTYPE
LC_NUMERIC
decimal_point ","
thousands_sep "."
grouping 3;3
END LC_NUMERIC
LC_COLLATE
copy "POSIX"
END LC_COLLATE
LC_TIME
copy "POSIX"
END LC_TIME
LC_MONETARY
copy "POSIX"
END LC_MONETARY
LC_MESSAGES
copy "POSIX"
END LC_MESSAGES
"""
PROTOCOL = {"name": "env", "conditions": [{"name": "h", "mode": "haptic"}],
            "test": {"characters": [YI], "conditions": ["h"], "repetitions": 1},
            "trial": {"max_duration_s": 2.5}}
UTC_STAMP = re.compile(r"^\d{4}-\d{2}-\d{2}T\d{2}:\d{2}:\d{2}(\.\d+)?Z$")


def env_with(**changes):
    """BASE_ENV with each keyword set, or removed when given None."""
    env = dict(BASE_ENV)
    for key, value in changes.items():
        if value is None:
            env.pop(key, None)
        else:
            env[key] = value
    return env


def as_nobody(nproc=None, umask=None):
    """A preexec_fn: the child as nobody (root's limits do not bind root), with RLIMIT_NPROC `nproc`."""
    def become():
        if nproc is not None:
            resource.setrlimit(resource.RLIMIT_NPROC, (nproc, nproc))
        os.setgroups([])
        os.setgid(NOBODY)
        os.setuid(NOBODY)
        if umask is not None:
            os.umask(umask)
    return become


def with_umask(mask):
    return lambda: os.umask(mask)


def python_has_module():
    """Whether the Python module imports here (asked once)."""
    if "python" not in SHARED:
        SHARED["python"] = subprocess.run([PYTHON, "-c", "import calligraphy"], env=BASE_ENV,
                                          capture_output=True, timeout=60).returncode == 0
    return SHARED["python"]


SHARED = {}


def setUpModule():  # noqa: N802 - unittest's name
    """What every case compares with, made once under the default environment: a trial, its record and a
    one-trial session with its tables."""
    shared = Path(tempfile.mkdtemp(prefix="round26b-shared-"))
    os.chmod(shared, 0o755)
    SHARED["shared"] = shared
    trial_args = ["trial", YI, "--writer-profile", "skilled", "--max-duration", "3", "--seed", "3"]
    SHARED["trial_args"] = trial_args
    base = run([*trial_args, "--json", "t.json", "--csv", "t.csv", "--svg", "t.svg"], shared, env=BASE_ENV)
    assert base.returncode == 0, base.stderr
    SHARED["base_trial"] = base
    SHARED["base_files"] = {n: (shared / n).read_bytes() for n in ("t.json", "t.csv", "t.svg")}
    (shared / "p.json").write_text(json.dumps(PROTOCOL, ensure_ascii=False), encoding="utf-8")
    session = run(["session", "run", "p.json", "--subject", "S01", "--out", "study", "--writer-profile", "skilled"],
                  shared, env=BASE_ENV)
    assert session.returncode == 0, session.stderr
    (shared / "tables").mkdir()
    tables = run(["report", "study", "--csv", "tables"], shared, env=BASE_ENV)
    assert tables.returncode == 0, tables.stderr
    SHARED["base_tables"] = {n: (shared / "tables" / n).read_bytes() for n in ("trials.csv", "strokes.csv")}
    SHARED["session_dir"] = next((shared / "study" / "S01").iterdir())
    SHARED["trace_h5"] = next((SHARED["session_dir"] / "trials").glob("*.trace.h5"))
    for path in shared.rglob("*"):
        os.chmod(path, 0o755 if path.is_dir() else 0o644)


def tearDownModule():  # noqa: N802 - unittest's name
    shutil.rmtree(SHARED["shared"], ignore_errors=True)


class Case(unittest.TestCase, OneErrorLine):
    """A folder of the case's own, and the module's shared outputs as attributes."""

    @classmethod
    def setUpClass(cls):
        for key, value in SHARED.items():
            setattr(cls, key, value)

    def setUp(self):
        self.dir = Path(tempfile.mkdtemp(prefix="round26b-"))
        os.chmod(self.dir, 0o777)
        self.addCleanup(shutil.rmtree, self.dir, True)

    def copy_study(self, to):
        shutil.copytree(self.shared / "study", to, symlinks=True)
        return to

    def assert_no_temporaries(self, folder):
        left = [p.name for p in Path(folder).rglob(".*.tmp-*")]
        self.assertEqual(left, [])

    def assert_clean_stderr(self, result):
        text = result.stderr.decode("utf-8", "replace")
        self.assertNotIn("Traceback", text)
        self.assertNotIn("terminate called", text)
        self.assertNotIn("warning", text)


class Locale(Case):
    """docs/cli.md "Numbers" and the records' formats: the locale changes no byte read or written."""

    @classmethod
    def setUpClass(cls):
        super().setUpClass()
        cls.locales = cls.shared / "locales"
        cls.locales.mkdir()
        source = cls.locales / "comma.src"
        source.write_text(COMMA_LOCALE_SOURCE)
        made = subprocess.run(["localedef", "-c", "-i", str(source), "-f", "ANSI_X3.4-1968",
                               str(cls.locales / "xx_CM")], capture_output=True, timeout=60)
        cls.comma_reason = None
        if not (cls.locales / "xx_CM" / "LC_NUMERIC").exists():
            cls.comma_reason = f"localedef could not compile a decimal-comma locale: {made.stderr[-300:]!r}"
        for path in cls.locales.rglob("*"):
            os.chmod(path, 0o755 if path.is_dir() else 0o644)

    def comma_env(self, whole=False):
        if self.comma_reason:
            self.skipTest(self.comma_reason)
        if whole:
            return env_with(LOCPATH=str(self.locales), LC_ALL="xx_CM")
        return env_with(LOCPATH=str(self.locales), LANG="C.UTF-8", LC_NUMERIC="xx_CM")

    def assert_trial_as_the_base(self, env):
        result = run([*self.trial_args, "--json", "t.json", "--csv", "t.csv", "--svg", "t.svg"], self.dir,
                     env=env)
        self.assertEqual(result.returncode, 0, result.stderr)
        for name, data in self.base_files.items():
            self.assertEqual((self.dir / name).read_bytes(), data, name)
        self.assertEqual(result.stdout, self.base_trial.stdout)
        self.assertEqual(result.stderr, self.base_trial.stderr)

    def test_lc_all_posix_trial_outputs_byte_for_byte(self):
        self.assert_trial_as_the_base(env_with(LC_ALL="POSIX"))

    def test_lc_all_c_utf8_trial_outputs_byte_for_byte(self):
        self.assert_trial_as_the_base(env_with(LC_ALL="C.UTF-8", LANG="C.UTF-8"))

    def test_unknown_locale_trial_outputs_byte_for_byte_without_a_warning(self):
        # The same standard error as the base: no "cannot change locale" line of the program's own.
        self.assert_trial_as_the_base(env_with(LC_ALL="xx_NOWHERE.UTF-8", LANG="yy_ZZ"))

    def test_decimal_comma_locale_trial_outputs_byte_for_byte(self):
        self.assert_trial_as_the_base(self.comma_env())

    def test_whole_decimal_comma_locale_trial_outputs_byte_for_byte(self):
        self.assert_trial_as_the_base(self.comma_env(whole=True))

    def test_max_duration_with_a_decimal_comma_is_refused(self):
        result = run(["trial", YI, "--max-duration", "0,4", "--json", "x.json"], self.dir, env=self.comma_env())
        self.assert_one_error(result, 2, "--max-duration", "0,4")
        self.assertFalse((self.dir / "x.json").exists())

    def test_writer_param_with_a_decimal_comma_is_refused(self):
        result = run(["trial", YI, "--max-duration", "0.4", "--writer-param", "bias_offset_m=0,004"], self.dir,
                     env=self.comma_env())
        self.assert_one_error(result, 2, "bias_offset_m", "0,004")

    def test_protocol_numbers_planned_the_same_under_a_decimal_comma(self):
        base = run(["session", "plan", "p.json", "--subjects", "1", "--json"], self.shared, env=BASE_ENV)
        comma = run(["session", "plan", str(self.shared / "p.json"), "--subjects", "1", "--json"], self.shared,
                    env=self.comma_env(whole=True))
        self.assertEqual(base.returncode, 0, base.stderr)
        self.assertEqual(comma.returncode, 0, comma.stderr)
        self.assertEqual(json.loads(comma.stdout)["subjects"], json.loads(base.stdout)["subjects"])
        self.assertEqual(json.loads(comma.stdout)["trial_max_duration_s"], 2.5)

    def test_score_json_byte_for_byte_under_a_decimal_comma(self):
        args = ["score", str(self.shared / "t.csv"), "--character", YI, "--json", "-"]
        base = run(args, self.dir, env=BASE_ENV)
        comma = run(args, self.dir, env=self.comma_env())
        self.assertEqual(base.returncode, 0, base.stderr)
        self.assertEqual(comma.stdout, base.stdout)

    def test_record_rerun_under_a_decimal_comma_gives_the_same_trace(self):
        result = run(["trial", "--spec", str(self.shared / "t.json"), "--csv", "again.csv"], self.dir,
                     env=self.comma_env(whole=True))
        self.assertEqual(result.returncode, 0, result.stderr)
        self.assertEqual((self.dir / "again.csv").read_bytes(), self.base_files["t.csv"])
        self.assertNotIn(b"warning", result.stderr)

    def test_schema_byte_for_byte_under_a_decimal_comma(self):
        for kind in ("record", "protocol"):
            base = run(["schema", kind], self.dir, env=BASE_ENV)
            comma = run(["schema", kind], self.dir, env=self.comma_env(whole=True))
            self.assertEqual(comma.stdout, base.stdout, kind)

    def test_report_tables_byte_for_byte_under_a_decimal_comma(self):
        (self.dir / "tables").mkdir()
        result = run(["report", str(self.shared / "study"), "--csv", "tables"], self.dir,
                     env=self.comma_env(whole=True))
        self.assertEqual(result.returncode, 0, result.stderr)
        base = run(["report", str(self.shared / "study"), "--csv", str(self.dir)], self.dir, env=BASE_ENV)
        self.assertEqual(base.returncode, 0, base.stderr)
        for name in ("trials.csv", "strokes.csv"):
            self.assertEqual((self.dir / "tables" / name).read_bytes(), (self.dir / name).read_bytes(), name)

    def test_characters_of_a_text_the_same_under_posix(self):
        args = ["characters", "--text", "一十二", "--json"]
        base = run(args, self.dir, env=env_with(LANG="C.UTF-8"))
        posix = run(args, self.dir, env=env_with(LC_ALL="POSIX"))
        self.assertEqual(base.returncode, 0, base.stderr)
        self.assertEqual(posix.stdout, base.stdout)
        self.assertEqual(json.loads(posix.stdout)["count"], 3)

    def test_python_score_after_setlocale_to_a_decimal_comma(self):
        if not python_has_module():
            self.skipTest("the Python module is not on PYTHONPATH")
        env = self.comma_env()
        code = ("import json, locale, sys, calligraphy as cg\n"
                "locale.setlocale(locale.LC_ALL, '')\n"
                "assert locale.localeconv()['decimal_point'] == ','\n"
                "s = cg.score(sys.argv[1], '\u4e00')\n"
                "print(json.dumps({k: s[k] for k in ('mean_deviation_m', 'frechet_m', 'dtw_m')}))\n")
        result = subprocess.run([PYTHON, "-c", code, str(self.shared / "t.csv")], env=env, capture_output=True,
                                timeout=120)
        self.assertEqual(result.returncode, 0, result.stderr.decode())
        scored = json.loads(run(["score", str(self.shared / "t.csv"), "--character", YI, "--json", "-"],
                                self.dir, env=BASE_ENV).stdout)
        got = json.loads(result.stdout)
        for key, value in got.items():
            self.assertEqual(value, scored[key], key)


class TimeZone(Case):
    """docs/experiments.md "Sessions" and "Log events": every time a session writes is UTC, whatever TZ says."""

    def run_session_under(self, tz):
        shutil.copy(self.shared / "p.json", self.dir / "p.json")
        before = time.time()
        result = run(["session", "run", "p.json", "--subject", "S01", "--out", "study", "--writer-profile",
                      "skilled"], self.dir, env=env_with(TZ=tz))
        after = time.time()
        self.assertEqual(result.returncode, 0, result.stderr)
        self.assert_clean_stderr(result)
        return next((self.dir / "study" / "S01").iterdir()), before, after

    def assert_times_utc(self, tz):
        folder, before, after = self.run_session_under(tz)
        stamp = folder.name.rsplit("-", 2)
        began = calendar.timegm(time.strptime(stamp[1] + stamp[2], "%Y%m%d%H%M%S"))
        self.assertLessEqual(int(before) - 1, began, folder.name)
        self.assertLessEqual(began, after + 1, folder.name)

        def seconds(text):
            self.assertRegex(text, UTC_STAMP)
            whole = time.strptime(text[:19], "%Y-%m-%dT%H:%M:%S")
            return calendar.timegm(whole)
        created = json.loads((folder / "session.json").read_text())["created_utc"]
        self.assertTrue(before - 1 <= seconds(created) <= after + 1, created)
        for line in (folder / "log.jsonl").read_text().splitlines():
            stamp_text = json.loads(line)["time_utc"]
            self.assertTrue(before - 1 <= seconds(stamp_text) <= after + 1, stamp_text)
        record = json.loads(next((folder / "trials").glob("*.json")).read_text())
        for key in ("start_time_utc", "end_time_utc"):
            self.assertTrue(before - 1 <= seconds(record[key]) <= after + 1, record[key])

    def test_session_times_are_utc_under_a_zone_of_plus_14_hours(self):
        self.assert_times_utc("Pacific/Kiritimati")

    def test_session_times_are_utc_under_a_zone_of_minus_3_30(self):
        self.assert_times_utc("America/St_Johns")

    def test_session_times_are_utc_under_a_zone_name_no_system_has(self):
        self.assert_times_utc("Nowhere/Garbage+99:99")

    def test_session_times_are_utc_under_a_zone_file_that_is_not_one(self):
        (self.dir / "zone").write_bytes(b"TZif\x00garbage" * 10)
        self.assert_times_utc(":" + str(self.dir / "zone"))

    def test_report_tables_byte_for_byte_under_another_zone(self):
        (self.dir / "tables").mkdir()
        result = run(["report", str(self.shared / "study"), "--csv", "tables"], self.dir,
                     env=env_with(TZ="Asia/Kathmandu"))
        self.assertEqual(result.returncode, 0, result.stderr)
        (self.dir / "utc").mkdir()
        base = run(["report", str(self.shared / "study"), "--csv", "utc"], self.dir, env=env_with(TZ="UTC"))
        self.assertEqual(base.returncode, 0, base.stderr)
        for name in ("trials.csv", "strokes.csv"):
            self.assertEqual((self.dir / "tables" / name).read_bytes(), (self.dir / "utc" / name).read_bytes())


class Umask(Case):
    """docs/cli.md "Outputs": a new file gets 0666 less the umask, a folder 0777 less it, a replaced file keeps
    its bits; and the next command reads what was written."""

    def mode(self, path):
        return stat.S_IMODE(os.lstat(path).st_mode)

    def test_umask_000_new_trial_outputs_are_0666(self):
        result = run([*self.trial_args, "--json", "t.json", "--csv", "t.csv", "--svg", "t.svg"], self.dir,
                     env=BASE_ENV, preexec_fn=with_umask(0o000))
        self.assertEqual(result.returncode, 0, result.stderr)
        for name in ("t.json", "t.csv", "t.svg"):
            self.assertEqual(self.mode(self.dir / name), 0o666, name)

    def test_umask_077_trace_csv_is_0600_and_scored(self):
        result = run(["trace", str(self.trace_h5), "--csv", "t.csv"], self.dir, env=BASE_ENV,
                     preexec_fn=with_umask(0o077))
        self.assertEqual(result.returncode, 0, result.stderr)
        self.assertEqual(self.mode(self.dir / "t.csv"), 0o600)
        scored = run(["score", "t.csv", "--character", YI], self.dir, env=BASE_ENV)
        self.assertEqual(scored.returncode, 0, scored.stderr)

    def test_umask_0777_new_record_has_no_bits_and_is_rerun(self):
        result = run([*self.trial_args, "--json", "t.json"], self.dir, env=BASE_ENV,
                     preexec_fn=with_umask(0o777))
        self.assertEqual(result.returncode, 0, result.stderr)
        self.assertEqual(self.mode(self.dir / "t.json"), 0o000)
        again = run(["trial", "--spec", "t.json", "--csv", "again.csv"], self.dir, env=BASE_ENV)
        self.assertEqual(again.returncode, 0, again.stderr)
        self.assertEqual((self.dir / "again.csv").read_bytes(), self.base_files["t.csv"])

    def test_umask_0777_session_folder_still_read_by_report(self):
        shutil.copy(self.shared / "p.json", self.dir / "p.json")
        result = run(["session", "run", "p.json", "--subject", "S01", "--out", "study", "--writer-profile",
                      "skilled"], self.dir, env=BASE_ENV, preexec_fn=with_umask(0o777))
        self.assertEqual(result.returncode, 0, result.stderr)
        folder = next((self.dir / "study" / "S01").iterdir())
        self.assertEqual(self.mode(self.dir / "study"), 0o000)
        self.assertEqual(self.mode(folder / "trials"), 0o000)
        self.assertEqual(self.mode(folder / "session.json"), 0o000)
        (self.dir / "tables").mkdir()
        tables = run(["report", "study", "--csv", "tables"], self.dir, env=BASE_ENV)
        self.assertEqual(tables.returncode, 0, tables.stderr)
        rows = (self.dir / "tables" / "trials.csv").read_text().splitlines()
        self.assertEqual(len(rows), 2)
        resumed = run(["session", "resume", str(folder)], self.dir, env=BASE_ENV)
        self.assertEqual(resumed.returncode, 0, resumed.stderr)
        self.assertIn(b"saved already", resumed.stdout + resumed.stderr)

    def test_umask_000_replaced_file_keeps_its_bits(self):
        target = self.dir / "t.json"
        target.write_text("old")
        os.chmod(target, 0o640)
        result = run([*self.trial_args, "--json", "t.json"], self.dir, env=BASE_ENV, preexec_fn=with_umask(0))
        self.assertEqual(result.returncode, 0, result.stderr)
        self.assertEqual(self.mode(target), 0o640)
        self.assertEqual(target.read_bytes(), self.base_files["t.json"])

    def test_umask_077_report_tables_are_0600(self):
        (self.dir / "tables").mkdir()
        result = run(["report", "study", "--csv", str(self.dir / "tables")], self.shared, env=BASE_ENV,
                     preexec_fn=with_umask(0o077))
        self.assertEqual(result.returncode, 0, result.stderr)
        for name in ("trials.csv", "strokes.csv"):
            self.assertEqual(self.mode(self.dir / "tables" / name), 0o600, name)
            self.assertEqual((self.dir / "tables" / name).read_bytes(), self.base_tables[name], name)


class HomeAndCache(Case):
    """HOME and XDG_CACHE_HOME: docs/cli.md "corpus" names the folder they give; nothing else reads them."""

    def test_home_unset_trial_and_characters_without_a_warning(self):
        env = env_with(HOME=None, XDG_CACHE_HOME=None)
        result = run([*self.trial_args, "--json", "t.json"], self.dir, env=env)
        self.assertEqual(result.returncode, 0, result.stderr)
        self.assertEqual((self.dir / "t.json").read_bytes(), self.base_files["t.json"])
        self.assert_clean_stderr(result)
        listed = run(["characters", "--text", "一十"], self.dir, env=env)
        self.assertEqual(listed.returncode, 0, listed.stderr)
        self.assertIn(YI.encode(), listed.stdout)

    def test_home_a_file_corpus_build_without_data_names_the_folder(self):
        home = self.dir / "home-file"
        home.write_text("not a folder")
        result = run(["corpus", "build", "--out", "c.clg"], self.dir,
                     env=env_with(HOME=str(home), XDG_CACHE_HOME=None))
        text = result.stderr.decode("utf-8", "replace")
        self.assertEqual(result.returncode, 2, text)
        self.assertIn(str(home), text)
        self.assertIn("fetch", text)
        self.assertNotIn("Traceback", text)
        self.assertFalse((self.dir / "c.clg").exists())

    def test_xdg_cache_home_a_file_corpus_build_names_the_folder_under_it(self):
        cache = self.dir / "cache-file"
        cache.write_text("not a folder")
        result = run(["corpus", "build", "--out", "c.clg"], self.dir,
                     env=env_with(HOME=str(self.dir), XDG_CACHE_HOME=str(cache)))
        text = result.stderr.decode("utf-8", "replace")
        self.assertEqual(result.returncode, 2, text)
        self.assertIn(str(cache), text)
        self.assertFalse((self.dir / "c.clg").exists())

    def test_xdg_cache_home_of_100_kb_is_named_within_the_line_bound(self):
        cache = "/" + "c" * 100_000
        result = run(["corpus", "build", "--out", "c.clg"], self.dir,
                     env=env_with(HOME=str(self.dir), XDG_CACHE_HOME=cache))
        text = result.stderr.decode("utf-8", "replace")
        self.assertEqual(result.returncode, 2, text[:3000])
        for line in error_lines(result):
            self.assertLess(len(line.encode()), 2300, line[:200])
        self.assertFalse((self.dir / "c.clg").exists())

    def test_python_import_with_home_a_file(self):
        if not python_has_module():
            self.skipTest("the Python module is not on PYTHONPATH")
        home = self.dir / "home-file"
        home.write_text("not a folder")
        code = "import sys, calligraphy as cg; print(cg.score(sys.argv[1], '\u4e00')['strokes_total'])"
        result = subprocess.run([PYTHON, "-c", code, str(self.shared / "t.csv")], capture_output=True, timeout=120,
                                env=env_with(HOME=str(home), XDG_CACHE_HOME=None, MPLCONFIGDIR=None))
        self.assertEqual(result.returncode, 0, result.stderr.decode())
        self.assertEqual(result.stdout.strip(), b"1")


class TemporaryFolder(Case):
    """docs/cli.md "Outputs": temporaries go beside the target, so TMPDIR is never needed."""

    def test_tmpdir_missing_session_run(self):
        env = env_with(TMPDIR=str(self.dir / "no" / "such"))
        shutil.copy(self.shared / "p.json", self.dir / "p.json")
        session = run(["session", "run", "p.json", "--subject", "S01", "--out", "study", "--writer-profile",
                       "skilled"], self.dir, env=env)
        self.assertEqual(session.returncode, 0, session.stderr)

    def test_tmpdir_a_file_report_tables(self):
        (self.dir / "tmp-file").write_text("x")
        (self.dir / "tables").mkdir()
        result = run(["report", "study", "--csv", str(self.dir / "tables")], self.shared,
                     env=env_with(TMPDIR=str(self.dir / "tmp-file")))
        self.assertEqual(result.returncode, 0, result.stderr)
        self.assertEqual((self.dir / "tables" / "trials.csv").read_bytes(), self.base_tables["trials.csv"])

    def test_tmpdir_unwritable_session_run(self):
        shutil.copy(self.shared / "p.json", self.dir / "p.json")
        result = run(["session", "run", "p.json", "--subject", "S01", "--out", "study", "--writer-profile",
                      "skilled"], self.dir, env=env_with(TMPDIR="/proc"))
        self.assertEqual(result.returncode, 0, result.stderr)
        self.assert_no_temporaries(self.dir)

    def test_tmpdir_5000_bytes_long_trial(self):
        result = run([*self.trial_args, "--json", "t.json"], self.dir, env=env_with(TMPDIR="/" + "t" * 5000))
        self.assertEqual(result.returncode, 0, result.stderr)
        self.assertEqual((self.dir / "t.json").read_bytes(), self.base_files["t.json"])

    def test_python_score_with_tmpdir_missing(self):
        if not python_has_module():
            self.skipTest("the Python module is not on PYTHONPATH")
        code = "import sys, calligraphy as cg; print(cg.score(sys.argv[1], '\u4e00')['strokes_accepted'])"
        result = subprocess.run([PYTHON, "-c", code, str(self.shared / "t.csv")], capture_output=True, timeout=120,
                                env=env_with(TMPDIR=str(self.dir / "gone")))
        self.assertEqual(result.returncode, 0, result.stderr.decode())
        self.assertEqual(result.stdout.strip(), b"1")


class WorkingFolder(Case):
    """docs/cli.md "Output folders": a relative path once the working folder was removed is one line naming the
    option; a folder that cannot be written is named; any name a file system takes is a name."""

    def in_removed_folder(self, args):
        gone = self.dir / "gone"
        gone.mkdir()

        def enter_and_remove():
            os.chdir(gone)
            os.rmdir(gone)
        return run(args, self.dir, env=BASE_ENV, preexec_fn=enter_and_remove)

    def test_model_svg_relative_in_a_removed_folder(self):
        result = self.in_removed_folder(["model", YI, "--svg", "m.svg"])
        self.assert_one_error(result, 1, "--svg", "m.svg", "working directory")

    def test_trace_relative_input_in_a_removed_folder(self):
        result = self.in_removed_folder(["trace", "x.trace.h5", "--csv", str(self.dir / "x.csv")])
        self.assert_one_error(result, 1, "x.trace.h5")
        self.assertFalse((self.dir / "x.csv").exists())

    def test_curriculum_relative_folder_in_a_removed_folder(self):
        result = self.in_removed_folder(["curriculum", "study", "--subject", "S01", "--from", "十二"])
        self.assert_one_error(result, (1, 2), "study")

    def test_immutable_working_folder_trial_output_named(self):
        work = self.dir / "frozen"
        work.mkdir()
        frozen = subprocess.run(["chattr", "+i", str(work)], capture_output=True)
        if frozen.returncode != 0:
            self.skipTest(f"chattr +i is not permitted here: {frozen.stderr.decode().strip()}")
        self.addCleanup(subprocess.run, ["chattr", "-i", str(work)])
        result = run([*self.trial_args, "--json", "t.json"], work, env=BASE_ENV)
        self.assert_one_error(result, 1, "--json", "t.json")
        self.assertEqual(list(work.iterdir()), [])

    def test_folder_with_a_space_a_line_break_and_a_stray_byte(self):
        odd = os.fsencode(str(self.dir)) + b"/a b\nc\xff"
        os.mkdir(odd)
        shutil.copy(self.shared / "p.json", os.fsdecode(odd + b"/p.json"))
        trial = run([*self.trial_args, "--json", "t.json", "--csv", "t.csv"], odd, env=BASE_ENV)
        self.assertEqual(trial.returncode, 0, trial.stderr)
        self.assertEqual(Path(os.fsdecode(odd + b"/t.csv")).read_bytes(), self.base_files["t.csv"])
        session = run(["session", "run", "p.json", "--subject", "S01", "--out", "study", "--writer-profile",
                       "skilled"], odd, env=BASE_ENV)
        self.assertEqual(session.returncode, 0, session.stderr)
        os.mkdir(odd + b"/tables")
        tables = run(["report", "study", "--csv", "tables"], odd, env=BASE_ENV)
        self.assertEqual(tables.returncode, 0, tables.stderr)
        rows = Path(os.fsdecode(odd + b"/tables/trials.csv")).read_bytes()
        self.assertEqual(rows.count(b"\n"), 2)

    def test_session_run_line_for_a_folder_with_a_line_break_and_an_escape(self):
        # "Prints one line per session": a folder's line break and escape sequence stay inside that line.
        shutil.copy(self.shared / "p.json", self.dir / "p.json")
        result = run(["session", "run", "p.json", "--subject", "S01", "--out", "o\x1b[2Jut\nx", "--writer-profile",
                      "skilled"], self.dir, env=BASE_ENV)
        self.assertEqual(result.returncode, 0, result.stderr)
        self.assertEqual(len(result.stdout.splitlines()), 1, result.stdout)
        self.assertNotIn(b"\x1b", result.stdout)
        self.assertNotIn(b"\x1b", result.stderr)

    def test_report_lines_for_a_tables_folder_with_a_line_break_and_an_escape(self):
        tables = self.dir / "t\x1b[31mab\nles"
        tables.mkdir()
        result = run(["report", "study", "--csv", str(tables)], self.shared, env=BASE_ENV)
        self.assertEqual(result.returncode, 0, result.stderr)
        self.assertEqual((tables / "trials.csv").read_bytes(), self.base_tables["trials.csv"])
        self.assertNotIn(b"\x1b", result.stdout)
        self.assertEqual(len(result.stdout.splitlines()), 1, result.stdout)

    def test_error_naming_a_path_with_a_line_break_is_one_line(self):
        result = run([*self.trial_args, "--json", "no\nsuch/x.json"], self.dir, env=BASE_ENV)
        line = self.assert_one_error(result, 1, "--json")
        self.assertIn("\\n", line)

    def test_error_naming_a_path_with_a_stray_byte_shows_it_escaped(self):
        result = run(["score", b"t\xff.csv", "--character", YI], self.dir, env=BASE_ENV)
        line = self.assert_one_error(result, 1)
        self.assertIn("\\xff", line.lower())

    def test_report_of_an_absolute_folder_with_a_stray_byte(self):
        odd = os.fsencode(str(self.dir)) + b"/st\xffudy"
        shutil.copytree(self.shared / "study", os.fsdecode(odd), symlinks=True)
        (self.dir / "tables").mkdir()
        result = run(["report", odd, "--csv", "tables"], self.dir, env=BASE_ENV)
        if result.returncode == 0:
            # The tables are UTF-8 (docs/experiments.md): the trace's path must be readable as such.
            table = (self.dir / "tables" / "trials.csv").read_bytes()
            table.decode("utf-8")
            self.assertEqual(table.count(b"\n"), 2)
        else:
            self.assert_one_error(result, 1, "\\xff", "UTF-8")
            self.assertEqual(list((self.dir / "tables").iterdir()), [])


class Streams(Case):
    """docs/cli.md "Standard output", "Outputs" (SIGPIPE ignored) and "Exit statuses"."""

    def test_schema_with_standard_output_closed(self):
        result = run(["schema", "record"], self.dir, env=BASE_ENV, stdout=subprocess.DEVNULL,
                     preexec_fn=lambda: os.close(1))
        self.assert_one_error(result, 1, "standard output")

    def test_devices_into_dev_full(self):
        with open("/dev/full", "wb") as full:
            result = run(["devices"], self.dir, env=BASE_ENV, stdout=full)
        self.assert_one_error(result, 1, "standard output")

    def test_trial_with_standard_error_closed_writes_its_outputs(self):
        result = run([*self.trial_args, "--json", "t.json", "--csv", "t.csv"], self.dir, env=BASE_ENV,
                     preexec_fn=lambda: os.close(2))
        self.assertEqual(result.returncode, 0)
        self.assertEqual((self.dir / "t.csv").read_bytes(), self.base_files["t.csv"])

    def test_early_ending_trial_with_standard_error_on_dev_full_exits_1_with_outputs(self):
        with open("/dev/full", "wb") as full:
            result = run(["trial", YI, "--max-duration", "0.4", "--json", "t.json"], self.dir, env=BASE_ENV,
                         stderr=full)
        self.assertEqual(result.returncode, 1)
        self.assertEqual(json.loads((self.dir / "t.json").read_text())["end_reason"], "time_limit")

    def test_usage_error_with_standard_error_on_dev_full_exits_2(self):
        with open("/dev/full", "wb") as full:
            result = run(["trial", YI, "--guidence", "on"], self.dir, env=BASE_ENV, stderr=full)
        self.assertEqual(result.returncode, 2)

    def test_session_run_without_standard_input_or_a_terminal(self):
        shutil.copy(self.shared / "p.json", self.dir / "p.json")
        result = run(["session", "run", "p.json", "--subject", "S01", "--out", "study", "--writer-profile",
                      "skilled"], self.dir, env=BASE_ENV, stdin=subprocess.DEVNULL, start_new_session=True,
                     preexec_fn=lambda: os.close(0))
        self.assertEqual(result.returncode, 0, result.stderr)
        self.assertIn(b"1 of 1 trials saved", result.stdout)

    def test_trace_into_a_pipe_closed_early(self):
        reader, writer = os.pipe()
        os.close(reader)
        try:
            result = run(["trace", str(self.trace_h5)], self.dir, env=BASE_ENV, stdout=writer)
        finally:
            os.close(writer)
        self.assert_one_error(result, 1, "standard output")

    def test_trace_into_a_non_blocking_pipe_is_whole_or_an_error(self):
        reader, writer = os.pipe()
        fcntl.fcntl(writer, fcntl.F_SETFL, fcntl.fcntl(writer, fcntl.F_GETFL) | os.O_NONBLOCK)
        process = subprocess.Popen([CLI, "trace", str(self.trace_h5)], stdout=writer, stderr=subprocess.PIPE,
                                   stdin=subprocess.DEVNULL, env=BASE_ENV, cwd=self.dir)
        os.close(writer)
        time.sleep(0.3)  # the pipe fills: a write that would block answers EAGAIN
        received = bytearray()
        while True:
            chunk = os.read(reader, 1 << 16)
            if not chunk:
                break
            received += chunk
        os.close(reader)
        stderr = process.stderr.read()
        process.stderr.close()
        status = process.wait(timeout=60)
        expected = run(["trace", str(self.trace_h5)], self.dir, env=BASE_ENV).stdout
        if status == 0:
            self.assertEqual(bytes(received), expected)
        else:
            self.assertEqual(status, 1, stderr)
            self.assertEqual(len(stderr.decode().strip().splitlines()), 1, stderr)
            self.assertIn(b"standard output", stderr)

    def test_score_writes_no_progress_into_a_log_even_after_0_s(self):
        with open(self.dir / "err.log", "wb") as log:
            result = run(["score", str(self.shared / "t.csv"), "--character", YI, "--json", "-"], self.dir,
                         env=env_with(CALLIGRAPHY_PROGRESS_AFTER_S="0"), stderr=log)
        self.assertEqual(result.returncode, 0)
        self.assertEqual((self.dir / "err.log").read_bytes(), b"")

    def on_a_terminal(self, args, env):
        leader, follower = pty.openpty()
        process = subprocess.Popen([CLI, *args], stdout=follower, stderr=follower, stdin=follower, env=env,
                                   cwd=self.dir, start_new_session=True)
        os.close(follower)
        said = bytearray()
        while True:
            ready, _, _ = select.select([leader], [], [], 30)
            if not ready:
                break
            try:
                chunk = os.read(leader, 65536)
            except OSError:
                break
            if not chunk:
                break
            said += chunk
        os.close(leader)
        return process.wait(timeout=60), bytes(said)

    def test_trial_table_on_a_dumb_terminal_has_no_escape_sequence(self):
        status, said = self.on_a_terminal(self.trial_args, env_with(TERM="dumb", NO_COLOR="1"))
        self.assertEqual(status, 0, said)
        self.assertIn(b"strokes completed", said)
        self.assertNotIn(b"\x1b", said)

    def test_score_progress_on_a_dumb_terminal_has_no_escape_sequence(self):
        status, said = self.on_a_terminal(["score", str(self.shared / "t.csv"), "--character", YI],
                                          env_with(TERM="dumb", NO_COLOR="1", CALLIGRAPHY_PROGRESS_AFTER_S="0"))
        self.assertEqual(status, 0, said)
        self.assertIn(b"accepted", said)
        self.assertNotIn(b"\x1b", said)


    def test_score_on_a_terminal_shows_a_trace_name_escaped(self):
        # The name's escape sequence (clear the screen) must reach the terminal as text, never act on it.
        name = "t\x1b[2J\x1b]0;owned\x07.csv"
        shutil.copy(self.shared / "t.csv", self.dir / name)
        status, said = self.on_a_terminal(["score", name, "--character", YI],
                                          env_with(TERM="xterm", CALLIGRAPHY_PROGRESS_AFTER_S="0"))
        self.assertEqual(status, 0, said)
        self.assertIn(b"accepted", said)
        self.assertNotIn(b"\x1b[2J", said)
        self.assertNotIn(b"\x1b]0;", said)
        self.assertIn(b"\\x1b[2J", said)

class DeviceLibraryVariable(Case):
    """docs/devices.md "Loading safely": a refused CALLIGRAPHY_LIBHD is one line naming it (exit 1), a note of
    `devices` (exit 0), never another library."""

    def assert_refused(self, value, *needles):
        env = env_with(CALLIGRAPHY_LIBHD=value)
        result = run(["trial", YI, "--device", "openhaptics", "--json", "t.json"], self.dir, env=env)
        line = self.assert_one_error(result, 1, "CALLIGRAPHY_LIBHD", *needles)
        self.assertLess(len(line.encode()), 2300)
        self.assertFalse((self.dir / "t.json").exists())
        listed = run(["devices", "--json"], self.dir, env=env)
        self.assertEqual(listed.returncode, 0, listed.stderr)
        found = json.loads(listed.stdout)
        self.assertIn("simulated", [d["name"] for d in found["devices"]])
        self.assertTrue(any("CALLIGRAPHY_LIBHD" in note for note in found["notes"]), found["notes"])
        return line

    def test_libhd_a_text_file(self):
        (self.dir / "libHD.so").write_text("not a library\n")
        self.assert_refused(str(self.dir / "libHD.so"), str(self.dir / "libHD.so"))

    def test_libhd_of_100_kb(self):
        line = self.assert_refused("/" + "L" * 100_000)
        self.assertIn("more bytes", line)

    def test_libhd_with_bytes_that_are_not_utf8(self):
        env = dict(env_with(), CALLIGRAPHY_LIBHD="/tmp/x")
        env_bytes = {os.fsencode(k): os.fsencode(v) for k, v in env.items()}
        env_bytes[b"CALLIGRAPHY_LIBHD"] = b"/tmp/lib\xff\x1b[31mHD.so"
        result = subprocess.run([CLI, "trial", YI, "--device", "openhaptics"], env=env_bytes, cwd=self.dir,
                                capture_output=True, stdin=subprocess.DEVNULL, timeout=60)
        line = self.assert_one_error(result, 1, "CALLIGRAPHY_LIBHD")
        self.assertNotIn("\x1b", line)
        self.assertIn("\\xff", line.lower())


class SearchPath(Case):
    """docs/python.md "The design's questions": without a working Rscript on PATH the mixed models raise
    RUnavailable, at once, with no traceback of the search."""

    def lmer_under(self, path, preexec_fn=None, fit=True):
        """Python asked whether R is there and, with `fit`, for a fit (pandas is imported for it)."""
        if not python_has_module():
            self.skipTest("the Python module is not on PYTHONPATH")
        code = ("from calligraphy import mixed_models as m\n"
                "print('available', m.r_available())\n"
                "if not %r:\n"
                "    raise SystemExit(0)\n"
                "import pandas as pd\n"
                "frame = pd.DataFrame({'y': [1.0, 2.0, 3.0, 4.0], 'condition': ['a', 'b', 'a', 'b'],\n"
                "                      'subject': ['s1', 's1', 's2', 's2']})\n"
                "try:\n"
                "    m.lmer(frame, 'y ~ condition + (1 | subject)', {'condition': ['a', 'b']})\n"
                "except m.RUnavailable as error:\n"
                "    print('RUnavailable', error)\n") % fit
        started = time.monotonic()
        result = subprocess.run([PYTHON, "-c", code], capture_output=True, timeout=150, cwd=self.dir,
                                env=env_with(PATH=path), preexec_fn=preexec_fn)
        return result, time.monotonic() - started

    def test_mixed_model_without_rscript_on_path(self):
        empty = self.dir / "bin"
        empty.mkdir()
        result, _ = self.lmer_under(str(empty))
        self.assertEqual(result.returncode, 0, result.stderr.decode())
        self.assertIn(b"available False", result.stdout)
        self.assertIn(b"RUnavailable Rscript is not installed", result.stdout)

    def test_mixed_model_with_a_broken_rscript(self):
        fake = self.dir / "bin"
        fake.mkdir()
        (fake / "Rscript").write_text("#!/bin/sh\necho 'Error: something broke' >&2\nexit 3\n")
        os.chmod(fake / "Rscript", 0o755)
        result, took = self.lmer_under(f"{fake}:/usr/bin:/bin", fit=False)
        self.assertEqual(result.returncode, 0, result.stderr.decode())
        self.assertEqual(result.stdout, b"available False\n")
        self.assertLess(took, 60)

    def test_mixed_model_with_an_unreadable_folder_on_path(self):
        locked = self.dir / "locked"
        locked.mkdir()
        (locked / "Rscript").write_text("#!/bin/sh\nexit 0\n")
        os.chmod(locked / "Rscript", 0o755)
        os.chmod(locked, 0o000)
        self.addCleanup(os.chmod, locked, 0o755)
        result, _ = self.lmer_under(str(locked), preexec_fn=as_nobody(), fit=False)
        self.assertEqual(result.returncode, 0, result.stderr.decode())
        self.assertEqual(result.stdout, b"available False\n")


class HelpTexts(Case):
    """docs/cli.md "Help and version": the help lists every option once with its default, whatever the width."""

    def help_of(self, env, *command):
        result = run([*command, "--help"], self.dir, env=env)
        self.assertEqual(result.returncode, 0, result.stderr)
        return result.stdout

    def test_help_under_columns_1_is_the_help(self):
        for command in (["trial"], ["session", "run"]):
            self.assertEqual(self.help_of(env_with(COLUMNS="1"), *command), self.help_of(BASE_ENV, *command))

    def test_help_under_columns_100000_is_the_help(self):
        for command in (["score"], ["report"]):
            self.assertEqual(self.help_of(env_with(COLUMNS="100000", LINES="1"), *command),
                             self.help_of(BASE_ENV, *command))


class Limits(Case):
    """docs/cli.md "Limits of the machine" and "Stopping a trial"."""

    def test_nice_19_trial_byte_for_byte(self):
        result = run([*self.trial_args, "--json", "t.json", "--csv", "t.csv"], self.dir, env=BASE_ENV,
                     preexec_fn=lambda: os.nice(19))
        self.assertEqual(result.returncode, 0, result.stderr)
        for name in ("t.json", "t.csv"):
            self.assertEqual((self.dir / name).read_bytes(), self.base_files[name], name)

    def test_rlimit_cpu_ends_a_lock_step_trial_with_152_and_whole_outputs(self):
        def limit():
            resource.setrlimit(resource.RLIMIT_CPU, (1, 4))
        # 永 at 100 kHz: some 2 s of CPU to its end, so the soft limit of 1 s comes first.
        result = run(["trial", "永", "--rate", "100000", "--max-duration", "100", "--json", "t.json"], self.dir,
                     env=BASE_ENV, preexec_fn=limit, timeout=120)
        text = result.stderr.decode("utf-8", "replace")
        self.assertEqual(result.returncode, 152, text)
        self.assertIn("SIGXCPU", text)
        record = json.loads((self.dir / "t.json").read_text())
        self.assertEqual(record["end_reason"], "interrupted")
        self.assertIn("SIGXCPU", record["abort_reason"])
        self.assert_no_temporaries(self.dir)

    def test_rlimit_nproc_1_real_time_trial_names_the_thread(self):
        result = run(["trial", YI, "--pacing", "real-time", "--max-duration", "0.4", "--json", "t.json"],
                     self.dir, env=BASE_ENV, preexec_fn=as_nobody(nproc=1))
        self.assert_one_error(result, 1, "cannot start a thread")

    def test_rlimit_nproc_1_report_tables_on_its_own_thread(self):
        (self.dir / "tables").mkdir()
        os.chmod(self.dir / "tables", 0o777)
        result = run(["report", "study", "--csv", str(self.dir / "tables"), "--jobs", "4"], self.shared,
                     env=BASE_ENV, preexec_fn=as_nobody(nproc=1))
        self.assertEqual(result.returncode, 0, result.stderr)
        for name in ("trials.csv", "strokes.csv"):
            self.assertEqual((self.dir / "tables" / name).read_bytes(), self.base_tables[name], name)

    def test_rlimit_nproc_1_devices_probe_is_a_note(self):
        stand_in = Path(CLI).resolve().parent.parent / "lib" / "hd_stand_in" / "libHD.so"
        if not stand_in.exists():
            self.skipTest(f"no stand-in libHD at {stand_in}")
        result = run(["devices", "--json"], self.dir, env=env_with(CALLIGRAPHY_LIBHD=str(stand_in)),
                     preexec_fn=as_nobody(nproc=1))
        self.assertEqual(result.returncode, 0, result.stderr)
        found = json.loads(result.stdout)
        self.assertIn("simulated", [d["name"] for d in found["devices"]])
        names = [d["name"] for d in found["devices"]]
        if "openhaptics" not in names:
            self.assertTrue(any(str(stand_in) in note for note in found["notes"]), found["notes"])


if __name__ == "__main__":
    unittest.main()
