#!/usr/bin/env python3
"""Round 28B: the R process behind the mixed models at its start, played by a hostile peer. From the docs alone
(docs/experiments.md, "A report for a paper": "One R process serves every fit of a Python process", "its first
frame says whether lme4, lmerTest and pbkrtest load", the framed protocol, "an R that has not given its first
frame within 120 s, or ends or garbles it, counts as R not installed, and is ended", "R ends with the Python
process, on a signal too"; docs/python.md, "The design's questions"; docs/learning-study.md, section 5; the
docstrings of `calligraphy.mixed_models` and `calligraphy.design_analysis`).

A fake `Rscript` first on PATH (a shell script in a temporary folder; what it does is read from a file beside
it) misbehaves at its start and around its first frame: it ends at once (status 0 or 3), closes its standard
output or input, forks a child that holds the pipe and ends, writes megabytes to its standard error, prints
text before its frame, forges the package its frame names (not hex, odd-length hex, a line break, shell
metacharacters, 1 MB, Latin-1, CRLF), sends its frame twice, says ok and ends, or ignores SIGTERM while it
"loads" and the Python process is sent SIGTERM or SIGKILL. The first frame's form, `@@calligraphy-ready ok` or
`@@calligraphy-ready missing HEX`, was read off the wire of the real R by a logging wrapper (a peer sees it).
Each Python process is a child of the test (`python3 -c`), so its R's life after it ends can be read off the
process table; the design's questions of a within-subjects study whose R ends at once keep the paired check,
computed here. The positive control runs the real Rscript through a logging wrapper: one R start answers
`r_available()` and two fits, whose estimate, df and t the test computes itself (a balanced paired design).

PYTHONPATH names the built Python package; R with lme4, lmerTest and pbkrtest for the positive control (skipped
saying so without it). CALLIGRAPHY_SANITIZED=1 takes five cases.
"""
import importlib.util
import json
import os
import shutil
import signal
import subprocess
import sys
import tempfile
import time
import unittest
from pathlib import Path

from outsider import sanitized_subset

load_tests = sanitized_subset({"test_honest_missing_lme4_frame_is_runavailable_with_the_documented_message",
                               "test_start_that_exits_3_at_once_is_r_not_installed",
                               "test_r_left_loading_ends_when_python_is_sent_sigterm",
                               "test_r_that_said_ok_ends_when_python_exits_normally",
                               "test_forged_name_with_a_line_break_gives_no_two_line_message"})

HAS_PACKAGE = importlib.util.find_spec("calligraphy") is not None
REAL_RSCRIPT = shutil.which("Rscript")
needs_package = unittest.skipUnless(HAS_PACKAGE, "the calligraphy Python package (PYTHONPATH) is missing")
CHILD_TIMEOUT_S = 90
CALL_LIMIT_S = 12      # a start that does not settle within this counts as hung here (the docs: 120 s only
#                        for an R that never gives its first frame; every fake here gives or refuses it at once)
LME4 = "R's package lme4 is not installed (Debian: apt-get install r-cran-lme4)"

# The fake R: what it does is the line in `mode` beside it; each start appends "MODE PID" to `pids`.
FAKE_RSCRIPT = r"""#!/bin/sh
here=$(dirname "$0")
mode=$(cat "$here/mode")
echo "$mode $$" >> "$here/pids"
frame() { printf '@@calligraphy-ready %s\n' "$1"; }
linger() { trap '' TERM; exec sleep 30; }
case "$mode" in
  exit0) exit 0 ;;
  exit3) echo "Error: cannot open the R library" >&2; exit 3 ;;
  missing_lme4) frame "missing 6c6d6534"; linger ;;
  missing_lmertest) frame "missing 6c6d657254657374"; linger ;;
  missing_pbkrtest) frame "missing 70626b7274657374"; linger ;;
  not_hex) frame "missing zz"; linger ;;
  odd_hex) frame "missing 6c6d653"; linger ;;
  newline) frame "missing $(printf 'lme4\nrm -rf ~' | od -An -v -tx1 | tr -d ' \n')"; linger ;;
  metachar) frame "missing $(printf 'lme4; touch "$HOME/pwned" && echo `id`' | od -An -v -tx1 | tr -d ' \n')"; linger ;;
  forged_name) frame "missing 6576696c"; linger ;;
  megabyte) printf '@@calligraphy-ready missing '; head -c 2000000 /dev/zero | tr '\0' '6'; echo; linger ;;
  latin1_raw) printf '@@calligraphy-ready missing l\351me4\n'; linger ;;
  latin1_hex) frame "missing 6c6d65e9"; linger ;;
  crlf) printf '@@calligraphy-ready missing 6c6d6534\r\n'; linger ;;
  twice) frame "missing 6c6d6534"; frame "missing 6c6d6534"; linger ;;
  close_stdout) exec >&-; linger ;;
  fork_child) (trap '' TERM; exec sleep 30) & echo "child $!" >> "$here/pids"; exit 0 ;;
  stderr_mb) head -c 2000000 /dev/zero | tr '\0' 'x' >&2; frame "missing 6c6d6534"; linger ;;
  ok_then_exit) frame ok; exit 0 ;;
  close_stdin) exec <&-; frame ok; linger ;;
  ok_linger) frame ok; linger ;;
  chatter_ok) echo "Loading required package: Matrix"; echo "Attaching package: 'lmerTest'"; frame ok; exec cat >/dev/null ;;
  loading_forever) trap '' TERM; exec sleep 30 ;;
  *) echo "unknown mode $mode" >&2; exit 9 ;;
esac
"""

# One Python process that starts the fake R in each of the modes given on its command line, one after the
# other (each start refused or spoilt, so the next call starts a new R), calls `r_available()` then `lmer`
# (or `lmer` alone), and writes what each returned or raised, how long it took and which of the fake's
# processes were still alive 2 s after it, as JSON lines.
DRIVER = r"""
import json, os, re, signal, sys, time
from pathlib import Path
from calligraphy import mixed_models
import pandas as pd

here = Path(sys.argv[1])
limit = float(sys.argv[2])
frame = pd.DataFrame({"y": [1.0, 2.5, 3.0, 4.1], "g": ["a", "b", "a", "b"], "s": ["1", "1", "2", "2"]})

def on_alarm(*_):
    raise TimeoutError("no answer within %g s" % limit)
signal.signal(signal.SIGALRM, on_alarm)

def alive(pid):
    try:
        state = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0]
    except OSError:
        return False
    return state not in ("Z", "X")

def pids_since(seen):
    lines = (here / "pids").read_text().splitlines() if (here / "pids").exists() else []
    return [int(l.split()[1]) for l in lines[seen:]], len(lines)

def call(fn):
    t0 = time.monotonic()
    signal.alarm(int(limit))
    try:
        got = fn()
        return {"returned": got if isinstance(got, bool) else type(got).__name__}, time.monotonic() - t0
    except BaseException as e:
        message = str(e)
        return {"raised": type(e).__name__, "classes": [c.__name__ for c in type(e).__mro__],
                "message": message if len(message) <= 6000 else message[:3000] + " ... " + message[-3000:],
                "message_len": len(message), "line_breaks": message.count("\n") + message.count("\r"),
                "install_hints": [h[:100] for h in re.findall(r"apt-get install ([^)]*)", message, re.S)],
                "packages_named": [h[:100] for h in re.findall(r"R's package (.*?) is not installed", message, re.S)]
                }, time.monotonic() - t0
    finally:
        signal.alarm(0)

def questions():
    # the design's questions of a within-subjects study: 4 subjects, the planted differences 0.2, 0.5, 0.1, 0.4 mm
    from calligraphy import design_analysis
    rows = []
    for s, base in enumerate((1.0e-3, 1.3e-3, 0.9e-3, 1.6e-3)):
        for condition, mode, effect in (("unguided", "vision", 0.0),
                                        ("fixture", "fixture", (0.2e-3, 0.5e-3, 0.1e-3, 0.4e-3)[s])):
            for k, character in enumerate("十二"):
                for r in range(2):
                    rows.append(dict(subject=f"S{s + 1}", phase="test", condition=condition, group="all",
                                     characters=character, session_number=1, block=1, end_reason="completed",
                                     mode=mode, mean_deviation_m=base + effect + 1e-4 * r + 5e-5 * k))
    return json.loads(design_analysis.design_questions(pd.DataFrame(rows), "mean_deviation_m").to_json(orient="records"))

seen = 0
for item in sys.argv[3:]:
    mode, _, what = item.partition(":")
    (here / "mode").write_text(mode + "\n")
    record = {"mode": mode}
    if what == "questions":
        record["mode"] = "questions"
        signal.alarm(int(limit))
        try:
            record["rows"] = questions()
        finally:
            signal.alarm(0)
        pids, seen = pids_since(seen)
        record["pids"] = pids
        print(json.dumps(record), flush=True)
        continue
    if what in ("", "both"):
        record["r_available"], record["r_available_s"] = call(mixed_models.r_available)
    record["lmer"], record["lmer_s"] = call(lambda: mixed_models.lmer(frame, "y ~ g + (1 | s)", {"g": ["a", "b"]}))
    pids, seen = pids_since(seen)
    deadline = time.monotonic() + 2.0
    while any(alive(p) for p in pids) and time.monotonic() < deadline:
        time.sleep(0.05)
    record["pids"] = pids
    record["alive_after"] = [p for p in pids if alive(p)]
    print(json.dumps(record), flush=True)
"""

def alive(pid):
    """Whether process `pid` runs (a zombie has ended)."""
    try:
        state = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0]
    except OSError:
        return False
    return state not in ("Z", "X")


def wait_gone(pids, within_s=3.0):
    """The processes of `pids` still running after up to `within_s`."""
    deadline = time.monotonic() + within_s
    while any(alive(p) for p in pids) and time.monotonic() < deadline:
        time.sleep(0.05)
    return [p for p in pids if alive(p)]


class FakeR:
    """A temporary folder holding the fake Rscript, its mode and the log of its starts."""

    def __init__(self, case=None):
        self.dir = Path(tempfile.mkdtemp(prefix="r28b-"))
        if case is not None:
            case.addCleanup(self.cleanup)
        self.bin = self.dir / "bin"
        self.bin.mkdir()
        script = self.bin / "Rscript"
        script.write_text(FAKE_RSCRIPT)
        script.chmod(0o755)
        self.env = dict(os.environ, PATH=f"{self.bin}:/usr/bin:/bin", HOME=str(self.dir))

    def set_mode(self, mode):
        (self.bin / "mode").write_text(mode + "\n")

    def starts(self):
        log = self.bin / "pids"
        return [line.split() for line in log.read_text().splitlines()] if log.exists() else []

    def pids(self):
        return [int(pid) for _, pid in self.starts()]

    def cleanup(self):
        for pid in self.pids():  # only the processes this case's fake started
            if alive(pid):
                try:
                    os.kill(pid, signal.SIGKILL)
                except OSError:
                    pass
        shutil.rmtree(self.dir, ignore_errors=True)

    def python(self, code, *args, timeout=CHILD_TIMEOUT_S):
        return subprocess.run([sys.executable, "-c", code, *map(str, args)], env=self.env, cwd=self.dir,
                              stdin=subprocess.DEVNULL, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                              timeout=timeout)

    def popen(self, code):
        return subprocess.Popen([sys.executable, "-c", code], env=self.env, cwd=self.dir,
                                stdin=subprocess.DEVNULL, stdout=subprocess.PIPE, stderr=subprocess.PIPE)

    def wait_for_start(self, within_s=10.0):
        deadline = time.monotonic() + within_s
        while not self.starts() and time.monotonic() < deadline:
            time.sleep(0.02)
        return self.pids()


@needs_package
class StartsThatFail(unittest.TestCase):
    """One Python process plays every start R refuses, ends or garbles (each one counts as R not installed),
    then the ones that say ok and end or cannot read: each record is checked by its own case."""

    MODES = ["exit0:both", "exit3:both", "missing_lme4:both", "missing_lmertest", "missing_pbkrtest", "not_hex",
             "odd_hex", "newline", "metachar", "megabyte", "latin1_raw", "latin1_hex", "crlf", "twice",
             "forged_name", "close_stdout:both", "fork_child:both", "stderr_mb:both", "ok_then_exit", "close_stdin",
             "exit0", "exit3:questions"]

    @classmethod
    def setUpClass(cls):
        cls.fake = FakeR()
        cls.fake.set_mode("exit0")
        cls.result = cls.fake.python(DRIVER, cls.fake.bin, CALL_LIMIT_S, *cls.MODES,
                                     timeout=CALL_LIMIT_S * 2 * len(cls.MODES))
        cls.records = {}
        for line in cls.result.stdout.decode("utf-8", "replace").splitlines():
            record = json.loads(line)
            cls.records.setdefault(record["mode"], record)

    @classmethod
    def tearDownClass(cls):
        cls.fake.cleanup()

    def record(self, mode):
        self.assertIn(mode, self.records, "the driver stopped before this start: "
                      + self.result.stderr.decode("utf-8", "replace")[-2000:])
        return self.records[mode]

    def assert_not_installed(self, mode, ask_first=False):
        """The start counts as R not installed: r_available() False, lmer RUnavailable, both within the
        limit (no 120 s wait), the fake R (and every process it started) ended."""
        record = self.record(mode)
        if ask_first:
            self.assertEqual(record["r_available"], {"returned": False}, record)
        got = record["lmer"]
        self.assertIn("RUnavailable", got.get("classes", []), got)
        self.assertNotEqual(got.get("raised"), "TimeoutError", got)
        self.assertLess(record["lmer_s"], CALL_LIMIT_S, record)
        self.assertEqual(record["alive_after"], [], f"R processes left running: {record}")
        return got

    def assert_sober_message(self, got):
        """One line (no line feed, no carriage return), and a package named as not installed, with its install
        hint, only when it is one of the three the first frame speaks of."""
        self.assertEqual(got["line_breaks"], 0, got["message"][:300])
        self.assertLessEqual(set(got["packages_named"]), {"lme4", "lmerTest", "pbkrtest"}, got["message"][:300])
        self.assertLessEqual(set(got["install_hints"]), {"r-cran-lme4", "r-cran-lmertest", "r-cran-pbkrtest"},
                             got["message"][:300])

    def test_driver_ran_every_start_and_ended_cleanly(self):
        self.assertEqual(self.result.returncode, 0, self.result.stderr.decode("utf-8", "replace")[-2000:])
        self.assertEqual(set(self.records), {m.split(":")[0] for m in self.MODES} | {"questions"})
        self.assertNotIn("Traceback", self.result.stderr.decode("utf-8", "replace")[-4000:])

    def test_start_that_exits_0_at_once_is_r_not_installed(self):
        self.assert_sober_message(self.assert_not_installed("exit0", ask_first=True))

    def test_start_that_exits_3_at_once_is_r_not_installed(self):
        self.assert_sober_message(self.assert_not_installed("exit3", ask_first=True))

    def test_honest_missing_lme4_frame_is_runavailable_with_the_documented_message(self):
        got = self.assert_not_installed("missing_lme4", ask_first=True)
        self.assertEqual(got["message"], LME4)

    def test_missing_lmertest_frame_names_the_lowercase_debian_package(self):
        got = self.assert_not_installed("missing_lmertest")
        self.assertEqual(got["message"],
                         "R's package lmerTest is not installed (Debian: apt-get install r-cran-lmertest)")

    def test_missing_pbkrtest_frame_names_its_debian_package(self):
        got = self.assert_not_installed("missing_pbkrtest")
        self.assertEqual(got["message"],
                         "R's package pbkrtest is not installed (Debian: apt-get install r-cran-pbkrtest)")

    def test_forged_name_not_hex_is_not_taken_for_a_package(self):
        self.assert_sober_message(self.assert_not_installed("not_hex"))

    def test_forged_name_of_odd_length_hex_is_not_taken_for_a_package(self):
        self.assert_sober_message(self.assert_not_installed("odd_hex"))

    def test_forged_name_with_a_line_break_gives_no_two_line_message(self):
        got = self.assert_not_installed("newline")
        self.assert_sober_message(got)
        self.assertNotIn("rm -rf", got["message"])

    def test_forged_name_with_shell_metacharacters_is_no_install_hint(self):
        got = self.assert_not_installed("metachar")
        self.assert_sober_message(got)
        self.assertNotIn("touch", got["message"])
        self.assertFalse((self.fake.dir / "pwned").exists())

    def test_forged_name_of_one_megabyte_is_no_install_hint(self):
        self.assert_sober_message(self.assert_not_installed("megabyte"))

    def test_forged_name_of_no_package_the_frame_speaks_of_is_no_install_hint(self):
        # "evil" in hex: well formed, but neither lme4, lmerTest nor pbkrtest
        got = self.assert_not_installed("forged_name")
        self.assert_sober_message(got)
        self.assertNotIn("r-cran-evil", got["message"])

    def test_frame_in_raw_latin1_is_r_not_installed_not_a_decode_error(self):
        got = self.assert_not_installed("latin1_raw")
        self.assertNotIn("UnicodeDecodeError", got["classes"])
        self.assert_sober_message(got)

    def test_frame_whose_hex_is_latin1_not_utf8_is_r_not_installed(self):
        got = self.assert_not_installed("latin1_hex")
        self.assertNotIn("UnicodeDecodeError", got["classes"])
        self.assert_sober_message(got)

    def test_frame_ended_by_crlf_leaves_no_carriage_return_in_the_message(self):
        self.assert_sober_message(self.assert_not_installed("crlf"))

    def test_frame_sent_twice_gives_the_one_documented_message(self):
        got = self.assert_not_installed("twice")
        self.assertEqual(got["message"], LME4)

    def test_r_that_closes_its_output_is_not_installed_and_ended_at_once(self):
        self.assert_sober_message(self.assert_not_installed("close_stdout", ask_first=True))

    def test_r_whose_child_holds_the_pipe_is_not_installed_without_waiting(self):
        got = self.assert_not_installed("fork_child", ask_first=True)
        self.assert_sober_message(got)
        record = self.record("fork_child")
        self.assertEqual(len(record["pids"]), 4, record)  # r_available() and lmer: each the fake and its child

    def test_r_writing_megabytes_to_stderr_still_gives_its_frame(self):
        got = self.assert_not_installed("stderr_mb", ask_first=True)
        self.assertEqual(got["message"], LME4)

    def test_r_that_says_ok_and_ends_spoils_only_the_fit(self):
        record = self.record("ok_then_exit")
        got = record["lmer"]
        self.assertIn("RUnavailable", got.get("classes", []), got)
        self.assertLess(record["lmer_s"], CALL_LIMIT_S, record)
        self.assertEqual(record["alive_after"], [], record)

    def test_r_that_closes_its_input_is_an_ranswererror_not_a_broken_pipe(self):
        record = self.record("close_stdin")
        got = record["lmer"]
        self.assertIn("RAnswerError", got.get("classes", []), got)
        self.assertNotIn("BrokenPipeError", got.get("classes", []), got)
        self.assertLess(record["lmer_s"], CALL_LIMIT_S, record)
        self.assertEqual(record["alive_after"], [], f"the R that spoilt the fit still runs: {record}")

    def test_design_questions_without_r_say_not_computed_and_keep_the_paired_check(self):
        rows = self.record("questions")["rows"]
        mixed = [r for r in rows if r["family"] == "mean_deviation_m, test"]
        checks = [r for r in rows if r["family"] == "mean_deviation_m (checks)"]
        self.assertEqual([r["comparison"] for r in mixed], ["fixture - unguided"])
        self.assertTrue(mixed[0]["note"].startswith("not computed: "), mixed[0]["note"])
        for column in ("df", "statistic", "p"):
            self.assertIsNone(mixed[0][column], column)
        # the paired t-test on subject means, computed here: the differences are the planted effects
        differences = [0.2e-3, 0.5e-3, 0.1e-3, 0.4e-3]
        n = len(differences)
        mean = sum(differences) / n
        sd = (sum((d - mean) ** 2 for d in differences) / (n - 1)) ** 0.5
        self.assertEqual(len(checks), 1)
        self.assertEqual(checks[0]["df"], n - 1)
        self.assertAlmostEqual(checks[0]["statistic"], mean / (sd / n ** 0.5), places=6)
        self.assertEqual(len(self.record("questions")["pids"]), 1, "more than one R start for one outcome")

    def test_next_fit_after_a_spoilt_one_starts_a_new_r(self):
        # the last mode repeats exit0 after close_stdin spoilt a fit: a new R was started for it
        modes = [line.split()[0] for line in (self.fake.bin / "pids").read_text().splitlines()]
        self.assertEqual(modes[-2:], ["exit0", "exit3"], modes[-4:])
        self.assertIn("close_stdin", modes)


@needs_package
class PythonEndsItsR(unittest.TestCase):
    """R ends with the Python process: at its normal exit, on SIGTERM (an R that ignores SIGTERM too) and on
    SIGKILL, also while R is still loading its packages."""

    def test_r_that_said_ok_ends_when_python_exits_normally(self):
        fake = FakeR(self)
        fake.set_mode("ok_linger")
        result = fake.python("from calligraphy import mixed_models; print(mixed_models.r_available())")
        self.assertEqual(result.returncode, 0, result.stderr)
        self.assertEqual(result.stdout.decode().strip(), "True")
        self.assertEqual(len(fake.pids()), 1)
        self.assertEqual(wait_gone(fake.pids()), [], "the serving R outlived its Python process")

    def test_text_before_the_first_frame_is_not_the_frame(self):
        fake = FakeR(self)
        fake.set_mode("chatter_ok")
        result = fake.python("from calligraphy import mixed_models; print(mixed_models.r_available())")
        self.assertEqual(result.returncode, 0, result.stderr)
        self.assertEqual(result.stdout.decode().strip(), "True", result.stderr)
        self.assertEqual(wait_gone(fake.pids()), [])

    def ended_by_signal(self, signum):
        fake = FakeR(self)
        fake.set_mode("loading_forever")
        child = fake.popen("from calligraphy import mixed_models; print(mixed_models.r_available())")
        try:
            pids = fake.wait_for_start()
            self.assertEqual(len(pids), 1, "the fake R was not started")
            time.sleep(0.2)
            self.assertTrue(alive(pids[0]))
            child.send_signal(signum)
            child.communicate(timeout=10)
            self.assertEqual(child.returncode, -signum)
        finally:
            if child.poll() is None:
                child.kill()
                child.communicate()
        self.assertEqual(wait_gone(pids), [], "R still loading outlived the Python process")

    def test_r_left_loading_ends_when_python_is_sent_sigterm(self):
        self.ended_by_signal(signal.SIGTERM)

    def test_r_left_loading_ends_when_python_is_sent_sigkill(self):
        self.ended_by_signal(signal.SIGKILL)


POSITIVE = r"""
import json
from calligraphy import mixed_models
import pandas as pd
out = {"available": mixed_models.r_available()}
frame = pd.DataFrame({"y": [1.0, 2.5, 3.0, 4.1, 2.0, 3.9, 1.2, 2.2], "g": ["a", "b"] * 4,
                      "s": ["1", "1", "2", "2", "3", "3", "4", "4"]})
fits = []
for _ in range(2):
    fit = mixed_models.lmer(frame, "y ~ g + (1 | s)", {"g": ["a", "b"]})
    row = fit.fixed.set_index("term").loc["gb"]
    fits.append({"estimate": float(row["estimate"]), "df": float(row["df"]), "t": float(row["t"]),
                 "singular": bool(fit.singular)})
out["fits"] = fits
print(json.dumps(out))
"""


@needs_package
@unittest.skipUnless(REAL_RSCRIPT, "Rscript is not installed: the positive control needs the real R")
class RealR(unittest.TestCase):
    def test_one_real_r_start_serves_r_available_and_two_fits_then_ends(self):
        folder = Path(tempfile.mkdtemp(prefix="r28b-real-"))
        self.addCleanup(shutil.rmtree, folder, True)
        (folder / "bin").mkdir()
        wrapper = folder / "bin" / "Rscript"
        wrapper.write_text(f'#!/bin/sh\necho "$$ $*" >> "{folder}/starts"\nexec {REAL_RSCRIPT} "$@"\n')
        wrapper.chmod(0o755)
        env = dict(os.environ, PATH=f"{folder / 'bin'}:/usr/bin:/bin")
        result = subprocess.run([sys.executable, "-c", POSITIVE], env=env, cwd=folder, stdin=subprocess.DEVNULL,
                                stdout=subprocess.PIPE, stderr=subprocess.PIPE, timeout=CHILD_TIMEOUT_S)
        starts = (folder / "starts").read_text().splitlines() if (folder / "starts").exists() else []
        pids = [int(line.split()[0]) for line in starts]
        self.addCleanup(lambda: [os.kill(p, signal.SIGKILL) for p in pids if alive(p)])
        self.assertEqual(result.returncode, 0, result.stderr.decode("utf-8", "replace")[-2000:])
        out = json.loads(result.stdout)
        if not out["available"]:
            self.skipTest("R here lacks lme4, lmerTest or pbkrtest")
        self.assertEqual(len(starts), 1, starts)
        self.assertIn("--serve", starts[0])
        # balanced pairs: the fixed effect is the mean difference, its df n - 1 and its t the paired t
        a, b = [1.0, 3.0, 2.0, 1.2], [2.5, 4.1, 3.9, 2.2]
        differences = [y - x for x, y in zip(a, b)]
        n = len(differences)
        mean = sum(differences) / n
        sd = (sum((d - mean) ** 2 for d in differences) / (n - 1)) ** 0.5
        for fit in out["fits"]:
            self.assertFalse(fit["singular"])
            self.assertAlmostEqual(fit["estimate"], mean, places=9)
            self.assertAlmostEqual(fit["df"], n - 1, places=4)
            self.assertAlmostEqual(fit["t"], mean / (sd / n ** 0.5), places=5)
        self.assertEqual(wait_gone(pids), [], "the real R outlived its Python process")


if __name__ == "__main__":
    unittest.main()
