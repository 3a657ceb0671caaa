#!/usr/bin/env python3
"""Round 26C: the R process and the journals as hostile peers. From the docs alone (docs/experiments.md "A
report for a paper", docs/python.md "The design's questions", docs/architecture.md, docs/cli.md "Outputs").

(1) The R process. A fake `Rscript` first on PATH (a small Python script in a temporary folder) misbehaves as a
peer can: garbage, a reply twice, half a reply then its end, Latin-1 and UTF-16, a huge length, a long line, NaN,
infinities, p > 1 and negative variances, a megabyte on standard error, an exit at once, not executable, a folder,
a child that holds the pipe, no answer with SIGTERM ignored, a first frame naming a missing package.
`calligraphy.mixed_models.lmer` runs in this process against it: the fit alone fails (`RAnswerError` naming why,
within seconds), every R started has ended, and the next fit is the fake's again; and in a Python of its own
stopped by SIGTERM or SIGINT while R hangs (fitting, or before its first frame, which says whether the packages
load): no R outlives it, no traceback. The smallest study with a mixed model (three simulated subjects) asked its
questions with its first R broken: that row alone is "not computed". No real R is needed: the fake answers as lme4
did once for the frame below.

(2) The journals of a set (`report --csv/--out`). A journal is what a run killed between two renames leaves
(here killed by strace's fault injection, skipped saying so without strace); its form (a header with the
version, one line per file: name, kept name, temporary name, then a 64-bit FNV-1a checksum of the lines before)
is read off such a journal, so that a forgery passes the checksum: names climbing out through `..` or a link in
the folder, a name that is a folder, holds a NUL or a line break, the journal's own name, a user's file as a
kept name, a huge journal, a newer version, a journal that is a link or a folder, two journals in one folder, a
journal of a run still running (a real race, and a forged one of a live process), folders copied and renamed
between the kill and the next run, a journal in an input folder. Expected (docs/cli.md): the program's own
journal completes its own folder only; anything else is refused (exit 1, one line naming it) and left as it is,
and nothing outside the folder is replaced.

CALLIGRAPHY_CLI names the program, PYTHONPATH the Python package. CALLIGRAPHY_SANITIZED=1 takes five cases.
"""
import json
import os
import shutil
import signal
import subprocess
import sys
import tempfile
import textwrap
import time
import unittest
from pathlib import Path

from outsider import CLI, ENV, OneErrorLine, run, sanitized_subset

load_tests = sanitized_subset({"test_journal_climbing_out_by_dot_dot_is_refused_and_left",
                               "test_journal_naming_a_file_through_a_link_in_its_folder_is_refused",
                               "test_folder_renamed_between_the_kill_and_the_next_run_is_completed",
                               "test_r_that_answers_garbage_fails_the_fit_alone",
                               "test_r_that_ignores_sigterm_is_stopped_with_python_by_sigterm"})

SOURCE = Path(os.environ.get("CALLIGRAPHY_SOURCE_DIR", Path(__file__).resolve().parents[2]))
PROTOCOL = {"name": "p", "conditions": [{"name": "V", "mode": "vision"}, {"name": "H", "mode": "haptic"}],
            "test": {"characters": ["一", "十"], "conditions": ["V", "H"], "repetitions": 1},
            "order": {"conditions": "latin_square"}, "trial": {"max_duration_s": 30}}
JOURNAL_PREFIX = ".calligraphy-set-"
STRACE = shutil.which("strace")
PYTHON = sys.executable


def fnv1a64(data):
    value = 0xcbf29ce484222325
    for byte in data:
        value = ((value ^ byte) * 0x100000001b3) & 0xFFFFFFFFFFFFFFFF
    return value


def journal_bytes(entries, version=3):
    """A journal in the form a killed run leaves: its header, one line per (name, kept name, temporary name),
    and the checksum of the lines before."""
    body = f"calligraphy-set-journal {version}\n".encode()
    body += b"".join(b"\t".join(part if isinstance(part, bytes) else part.encode() for part in entry) + b"\n"
                     for entry in entries)
    return body + b"checksum %016x\n" % fnv1a64(body)


def dead_pid():
    """The id of a process that has ended (and been reaped)."""
    child = subprocess.Popen(["true"])
    child.wait()
    return child.pid


def tree(folder):
    """Every entry under `folder`: a file's bytes, a link's target, a folder as None."""
    out = {}
    for path in sorted(Path(folder).rglob("*")):
        key = str(path.relative_to(folder))
        if path.is_symlink():
            out[key] = ("link", os.readlink(path))
        elif path.is_dir():
            out[key] = None
        else:
            out[key] = path.read_bytes()
    return out


def leftovers(folder):
    return sorted(p.name for p in Path(folder).iterdir() if p.name.startswith("."))


class Shared:
    """One study of three simulated subjects (the fewest a mixed model is fitted to) and its fresh tables,
    made once."""
    root = None

    @classmethod
    def get(cls):
        if cls.root is None:
            cls.scratch = tempfile.TemporaryDirectory(prefix="calligraphy-r26c-")
            root = Path(cls.scratch.name)
            (root / "p.json").write_text(json.dumps(PROTOCOL, ensure_ascii=False), encoding="utf-8")
            made = run(["session", "run", "p.json", "--writer", "simulated", "--subjects", "3", "--out", "study"],
                       root)
            assert made.returncode == 0, made.stderr.decode()
            (root / "fresh").mkdir()
            made = run(["report", root / "study", "--csv", "fresh"], root)
            assert made.returncode == 0, made.stderr.decode()
            cls.root = root
        return cls.root


class Case(OneErrorLine, unittest.TestCase):
    def setUp(self):
        self.folder = tempfile.TemporaryDirectory(prefix="calligraphy-r26c-case-")
        self.cwd = Path(self.folder.name)
        self.study = Shared.get() / "study"
        self.fresh = {p.name: p.read_bytes() for p in (Shared.get() / "fresh").iterdir()}

    def tearDown(self):
        self.folder.cleanup()


# ---------------------------------------------------------------------------------------------------------
# (1) The R process. The fake R below is a Python script named Rscript, started as `lmer_fit.R --serve`. Its
# first frame says whether lme4, lmerTest and pbkrtest load (`@@calligraphy-ready ok`, or `missing HEX(name)`
# and an end, as the mode's "start" says; "hang" never says); then it
# reads its requests one line each, `@@calligraphy-request N HEX(folder) HEX(formula) HEX(ddf)`, and answers as
# the file MODE in its state folder says at that request: `good` writes the result files a real lme4 wrote for
# the frame below (its intercept set to the mode's) and replies `@@calligraphy-reply N ok HEX(name=size;...)`;
# the other modes misbehave. Every process it starts writes its id to `pids` there. (Seen by running the real
# Rscript under a tee: the docs give the framing, not its fields.)

FAKE_R = r"""#!PYTHON
import json, os, signal, subprocess, sys, time
state = os.environ["FAKE_R_STATE"]
with open(os.path.join(state, "pids"), "a") as out:
    out.write(f"{os.getpid()}\n")
def mode():
    with open(os.path.join(state, "mode")) as f:
        return json.load(f)
m = mode()
# The first frame: do lme4, lmerTest and pbkrtest load?
if m.get("start") == "hang":
    signal.signal(signal.SIGTERM, signal.SIG_IGN)
    time.sleep(300)
elif m.get("start") == "missing":
    os.write(1, f"@@calligraphy-ready missing {m['package'].encode().hex()}\n".encode())
    sys.exit(3)
os.write(1, b"@@calligraphy-ready ok\n")
RESULTS = {
    "fixed.csv": '"term","estimate","std_error","df","t","p","ci95_low","ci95_high"\n'
                 '"(Intercept)",INTERCEPT,0.412918926065332,2.6516661721289,0.596265998603122,P,'
                 '-1.1711490885573,1.66356812014225\n"TERM",0.338781215716491,0.30115832773848,'
                 '14.0000000342517,1.12492727084964,0.279537003052569,-0.307139156424333,0.984701587857315\n',
    "random.csv": '"group","variance"\n"subject",VARIANCE\n"Residual",0.408133522648071\n',
    "anova.csv": '"term","num_df","den_df","f","p"\n"condition",1,14.0000000342517,1.26546136470123,'
                 '0.279537003052569\n',
    "fit.csv": '"key","value"\n"n_observations","18"\n"singular","FALSE"\n"converged","TRUE"\n'
               '"messages","MESSAGES"\n"ddf","Satterthwaite"\n"lme4_version","1.1.31"\n'
               '"lmertest_version","3.1.3"\n"r_version","4.2.2"\n"pairs","fewer than 3 levels"\n',
}
def say(data):
    os.write(1, data if isinstance(data, bytes) else data.encode())
def reply(number, sizes):
    field = ";".join(f"{k}={v}" for k, v in sizes.items()).encode().hex()
    say(f"@@calligraphy-reply {number} ok {field}\n")
if m.get("stderr_bytes"):
    os.write(2, b"x" * m["stderr_bytes"])
while True:
    line = sys.stdin.readline()
    if not line:
        sys.exit(0)
    fields = line.split()
    number, folder = fields[1], bytes.fromhex(fields[2]).decode()
    m = mode()
    kind = m["kind"]
    if "then" in m:  # this request alone: the next is answered as "then" says
        with open(os.path.join(state, "mode"), "w") as f:
            json.dump(m["then"], f)
    files = {k: v.replace("INTERCEPT", str(m.get("intercept", 0.25))).replace("P", str(m.get("p", 0.598)))
             .replace("VARIANCE", str(m.get("variance", 0.375))).replace("MESSAGES", m.get("messages", ""))
             .replace("TERM", m.get("term", "conditionH"))
             for k, v in RESULTS.items()}
    files["random.csv"] = m.get("random", files["random.csv"])
    encoding = m.get("encoding", "utf-8")
    sizes = {}
    for name, text in files.items():
        data = text.encode(encoding)
        if kind == "cut" and name == "fixed.csv":
            data = data[:len(data) // 2]
        with open(os.path.join(folder, name), "wb") as f:
            f.write(data)
        sizes[name] = len(data)
    sizes.pop(m.get("drop"), None)
    sizes.update(m.get("sizes", {}))
    if kind == "good":
        reply(number, sizes)
    elif kind == "twice":
        reply(number, sizes)
        reply(number, {"fixed.csv": 1, "random.csv": 1, "anova.csv": 1, "fit.csv": 1})
    elif kind == "error":
        say(f"@@calligraphy-reply {number} error {m['message'].encode().hex()}\n")
    elif kind == "raw":  # a reply line as the mode spells it, NUMBER standing for the request's number
        say(m["line"].replace("NUMBER", number) + "\n")
        sys.exit(0)
    elif kind == "garbage":
        say(b"\x00\xff\xfe garbage \x80\n@@calligraphy-reply\n@@calligraphy-reply x ok zz\n\xc3\x28\n")
        sys.exit(0)
    elif kind == "exit":
        sys.exit(0)
    elif kind == "half":
        field = ";".join(f"{k}={v}" for k, v in sizes.items()).encode().hex()
        say(f"@@calligraphy-reply {number} ok {field[:len(field) // 2]}")
        sys.exit(0)
    elif kind == "utf16":
        field = ";".join(f"{k}={v}" for k, v in sizes.items()).encode().hex()
        say(f"@@calligraphy-reply {number} ok {field}\n".encode("utf-16"))
        sys.exit(0)
    elif kind == "long_line":
        say(b"@@calligraphy-reply " + b"7" * (16 << 20) + b"\n")
        sys.exit(0)
    elif kind == "other_number":
        reply(int(number) + 1000, sizes)
        sys.exit(0)
    elif kind == "fork_and_exit":
        if os.fork() == 0:
            with open(os.path.join(state, "pids"), "a") as out:
                out.write(f"{os.getpid()}\n")
            os.execvp("sleep", ["sleep", "300"])
        os._exit(0)
    elif kind == "close_stdout_and_wait":
        os.close(1)
        time.sleep(300)
    elif kind == "hang":
        if m.get("ignore_sigterm"):
            signal.signal(signal.SIGTERM, signal.SIG_IGN)
            signal.signal(signal.SIGINT, signal.SIG_IGN)
        time.sleep(300)
    else:
        reply(number, sizes)
"""

FRAME_LEVELS = {"condition": ["V", "H"], "subject": ["S1", "S2", "S3"]}
FORMULA = "outcome ~ condition + (1 | subject)"


def frame_rows():
    """The 18 rows the fake's results were fitted to (two conditions, three subjects, three repetitions)."""
    values = iter([1.1672023355659444, 0.6760212682481732, -0.957573039539575, 1.7509400587379038,
                   1.2919587644287973, 0.3086309567045008, 0.9456905003824289, 0.8752506008518791,
                   0.6095403455121499, 1.6278310908088, 0.3446640171946862, 0.9182081562033003,
                   0.1167268999546493, -0.44239720519831927, -0.7745760636450669, -0.7640277750368203,
                   -0.23931155329884896, 0.026022867838365243])
    return [{"subject": s, "condition": c, "outcome": next(values)}
            for s in ("S1", "S2", "S3") for c in ("V", "H") for _ in range(3)]


def alive(pid):
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    try:  # a zombie is no running process
        with open(f"/proc/{pid}/stat") as f:
            return f.read().rsplit(")", 1)[1].split()[0] != "Z"
    except OSError:
        return False


class FakeR:
    """A folder holding the fake Rscript and its state: the mode it answers in and the ids it started."""

    def __init__(self, folder, name="Rscript"):
        self.bin = Path(folder) / "bin"
        self.state = Path(folder) / "state"
        self.bin.mkdir()
        self.state.mkdir()
        self.script = self.bin / name
        self.script.write_text(FAKE_R.replace("#!PYTHON", "#!" + PYTHON + " -S", 1))
        self.script.chmod(0o755)
        self.set(kind="good")

    def set(self, **mode):
        (self.state / "mode").write_text(json.dumps(mode))

    def pids(self):
        path = self.state / "pids"
        return [int(x) for x in path.read_text().split()] if path.exists() else []

    def environment(self, path=None):
        return dict(os.environ, PATH=path or f"{self.bin}:{os.path.dirname(PYTHON)}:/usr/bin:/bin",
                    FAKE_R_STATE=str(self.state))

    def assert_none_alive(self, case, within_s=5):
        deadline = time.monotonic() + within_s
        while any(alive(p) for p in self.pids()) and time.monotonic() < deadline:
            time.sleep(0.05)
        left = [p for p in self.pids() if alive(p)]
        for pid in left:
            os.kill(pid, signal.SIGKILL)
        case.assertEqual(left, [], "an R process outlived what started it")


class Hang(Exception):
    pass


def _on_alarm(signum, frame):  # noqa: ARG001 - signal's protocol
    raise Hang()


try:
    import pandas
    from calligraphy import mixed_models
except ImportError:  # the package or pandas is missing: the R cases skip, saying so
    mixed_models = None


@unittest.skipIf(mixed_models is None, "calligraphy.mixed_models or pandas cannot be imported")
class RServing(unittest.TestCase):
    """`mixed_models.lmer` in this process against the fake R: each misbehaviour spoils its fit alone
    (RAnswerError naming what went wrong, within seconds), the R that misbehaved does not outlive it, and the
    next fit, answered by a new R, is R's."""

    @classmethod
    def setUpClass(cls):
        cls.scratch = tempfile.TemporaryDirectory(prefix="calligraphy-r26c-r-")
        cls.fake = FakeR(cls.scratch.name)
        cls.saved = {k: os.environ.get(k) for k in ("PATH", "FAKE_R_STATE")}
        os.environ.update({k: cls.fake.environment()[k] for k in ("PATH", "FAKE_R_STATE")})
        cls.frame = pandas.DataFrame(frame_rows())
        cls.next_intercept = 1.5

    @classmethod
    def tearDownClass(cls):
        for key, value in cls.saved.items():
            if value is None:
                os.environ.pop(key, None)
            else:
                os.environ[key] = value
        cls.scratch.cleanup()

    def fit(self, limit_s=30):
        previous = signal.signal(signal.SIGALRM, _on_alarm)
        signal.alarm(limit_s)
        try:
            return mixed_models.lmer(self.frame, FORMULA, FRAME_LEVELS)
        except Hang:
            self.fail(f"lmer still waited for the fake R after {limit_s} s")
        finally:
            signal.alarm(0)
            signal.signal(signal.SIGALRM, previous)

    def assert_good_fit(self):
        """A fit the fake answers well: its numbers are the fake's (this intercept), so R answered it."""
        intercept = type(self).next_intercept
        type(self).next_intercept += 1.0
        self.fake.set(kind="good", intercept=intercept)
        fit = self.fit()
        row = fit.fixed.set_index("term").loc["(Intercept)"]
        self.assertEqual(row["estimate"], intercept)
        self.assertAlmostEqual(fit.variances["Residual"], 0.408133522648071)
        return fit

    def assert_spoils_this_fit_only(self, *needles, **mode):
        self.assert_good_fit()  # a healthy R serving first, so the broken one is the serving R itself
        self.fake.set(**mode)
        with self.assertRaises(mixed_models.RAnswerError) as caught:
            self.fit()
        message = str(caught.exception)
        self.assertGreater(len(message), 10)
        for needle in needles:
            self.assertIn(needle.lower(), message.lower())
        # Every R started so far has ended: the one that spoilt the fit and whatever it started.
        self.fake.assert_none_alive(self)
        self.assert_good_fit()
        return message

    def test_r_that_answers_well_is_taken_at_its_word(self):
        self.assert_good_fit()
        self.assert_good_fit()

    def test_r_that_answers_garbage_fails_the_fit_alone(self):
        self.assert_spoils_this_fit_only(kind="garbage")

    def test_r_that_exits_at_once_fails_the_fit_alone(self):
        self.assert_spoils_this_fit_only(kind="exit")

    def test_r_that_answers_half_a_frame_then_exits_fails_the_fit_alone(self):
        self.assert_spoils_this_fit_only(kind="half")

    def test_r_that_answers_in_utf16_fails_the_fit_alone(self):
        self.assert_spoils_this_fit_only(kind="utf16")

    def test_r_whose_result_files_are_latin1_fails_the_fit_alone(self):
        self.assert_spoils_this_fit_only("UTF-8", kind="good", encoding="latin-1", messages="boundary (singular) é")

    def test_r_whose_result_files_are_utf16_fails_the_fit_alone(self):
        self.assert_spoils_this_fit_only(kind="good", encoding="utf-16")

    def test_r_that_answers_a_16_mib_line_then_exits_fails_the_fit_alone(self):
        started = time.process_time()
        self.assert_spoils_this_fit_only(kind="long_line")
        self.assertLess(time.process_time() - started, 1.0, "reading one long line cost more than its length")

    def test_r_whose_reply_gives_a_size_of_2_to_the_31_fails_the_fit_alone(self):
        self.assert_spoils_this_fit_only("fixed.csv", kind="good", sizes={"fixed.csv": 2 ** 31})

    def test_r_whose_reply_gives_a_negative_or_huge_size_fails_the_fit_alone(self):
        for size in (-1, 2 ** 64, "1e3"):
            with self.subTest(size=size):
                self.assert_spoils_this_fit_only("fixed.csv", kind="good", sizes={"fixed.csv": size})

    def test_r_whose_reply_names_its_table_outside_its_folder_fails_the_fit_alone(self):
        self.assert_spoils_this_fit_only("fixed.csv", kind="good", drop="fixed.csv",
                                         sizes={"../../../../etc/passwd": 10, "../fixed.csv": 339})

    def test_r_whose_result_file_is_cut_fails_the_fit_alone(self):
        self.assert_spoils_this_fit_only("fixed.csv", kind="cut")

    def test_r_that_answers_another_requests_number_fails_the_fit_alone(self):
        self.assert_spoils_this_fit_only(kind="other_number")

    def test_r_that_answers_twice_is_read_once_and_the_next_fit_is_the_next_reply(self):
        self.assert_good_fit()
        self.fake.set(kind="twice", intercept=42.5)
        fit = self.fit()
        self.assertEqual(fit.fixed.set_index("term").loc["(Intercept)", "estimate"], 42.5)
        self.assert_good_fit()  # not the second reply to the request before it

    def test_r_answering_a_p_outside_zero_and_one_fails_the_fit_alone(self):
        for p in (1.5, -0.1, "Inf"):
            with self.subTest(p=p):
                self.assert_spoils_this_fit_only(kind="good", p=p)

    def test_r_answering_a_negative_or_infinite_variance_fails_the_fit_alone(self):
        for variance in (-0.375, "NaN", "Inf"):
            with self.subTest(variance=variance):
                self.assert_spoils_this_fit_only(kind="good", variance=variance)

    def test_r_whose_reply_is_malformed_fails_the_fit_alone(self):
        ok = ";".join(["fixed.csv=339", "random.csv=76", "anova.csv=99", "fit.csv=211"]).encode().hex()
        lines = {"another status": f"@@calligraphy-reply NUMBER maybe {ok}",
                 "an odd hex field": f"@@calligraphy-reply NUMBER ok {ok[:-1]}",
                 "four fields": f"@@calligraphy-reply NUMBER ok {ok} {ok}",
                 "a number spelt 0N": f"@@calligraphy-reply 0NUMBER ok {ok}",
                 "no field": "@@calligraphy-reply NUMBER ok"}
        for name, line in lines.items():
            with self.subTest(reply=name):
                self.assert_spoils_this_fit_only(kind="raw", line=line)

    def test_r_that_cannot_fit_says_why_in_one_line_and_the_next_fit_is_answered(self):
        """lme4 refusing a model is R's answer, not a broken R: a RuntimeError naming R's message (on one line,
        as a table's cell holds it), never taken for R unavailable."""
        self.assert_good_fit()
        self.fake.set(kind="error", message="Error: grouping factors must have > 1 sampled level\n<b>x</b>")
        with self.assertRaises(RuntimeError) as caught:
            self.fit()
        self.assertNotIsInstance(caught.exception, mixed_models.RUnavailable)
        message = str(caught.exception)
        self.assertIn("grouping factors must have > 1 sampled level", message)
        self.assertNotIn("\n", message)
        self.assert_good_fit()

    def test_r_answering_a_negative_covariance_is_taken_at_its_word(self):
        """A covariance of two random effects may be negative (lmer_fit.R names its row "GROUP cov A B"):
        only a variance may not."""
        self.assert_good_fit()
        self.fake.set(kind="good", intercept=5.5, random='"group","variance"\n"subject (Intercept)",0.3\n'
                      '"subject conditionH",0.2\n"subject cov (Intercept) conditionH",-0.1\n"Residual",0.4\n')
        fit = self.fit()
        self.assertEqual(fit.fixed.set_index("term").loc["(Intercept)", "estimate"], 5.5)
        self.assertEqual(fit.variances["subject cov (Intercept) conditionH"], -0.1)

    def test_r_answering_an_infinite_or_overflowing_estimate_fails_the_fit_alone(self):
        for value in ("Inf", "-Inf", "1e999"):
            with self.subTest(value=value):
                self.assert_spoils_this_fit_only(kind="good", intercept=value)

    def test_r_answering_a_nan_p_is_no_tested_p(self):
        self.assert_good_fit()
        self.fake.set(kind="good", p="NaN", intercept=3.25)
        try:
            fit = self.fit()
        except mixed_models.RAnswerError:
            return  # refused as a whole: as good as a p it does not report
        p = fit.fixed.set_index("term").loc["(Intercept)", "p"]
        self.assertTrue(p != p, f"R's NaN p became {p!r}")

    def test_r_that_writes_a_megabyte_to_standard_error_still_answers(self):
        self.assert_good_fit()
        self.fake.set(kind="exit")  # the serving R ends: the next fit starts one that first floods stderr
        with self.assertRaises(mixed_models.RAnswerError):
            self.fit()
        self.fake.set(kind="good", intercept=9.5, stderr_bytes=1 << 20)
        fit = self.fit()
        self.assertEqual(fit.fixed.set_index("term").loc["(Intercept)", "estimate"], 9.5)

    def test_design_questions_with_the_first_r_broken_have_that_row_alone_not_computed(self):
        """The smallest study with a mixed model (three simulated subjects: the docs' model needs three) asked
        its questions while the serving R answers its first fit with garbage: that row says "not computed:
        lmer: R ..." naming why, the other outcome's row is R's (the fake's p), the paired checks are given."""
        from calligraphy import design_analysis, study
        trials = study.load([str(Shared.get() / "study")]).trials
        self.assert_good_fit()
        self.fake.set(kind="garbage", then={"kind": "good", "term": "factorH"})  # the model's column names
        rows = pandas.concat([design_analysis.design_questions(trials, value)
                              for value in ("total_time_s", "mean_deviation_m")])
        mixed = rows[rows["family"].str.contains("(checks)", regex=False) == False]  # noqa: E712
        self.assertEqual(len(mixed), 2, rows.to_dict("records"))
        broken, answered = mixed.iloc[0], mixed.iloc[1]
        self.assertTrue(str(broken["note"]).startswith("not computed: lmer: R "), broken["note"])
        self.assertTrue(broken["p"] != broken["p"], "a row whose fit R spoilt has a p")
        self.assertAlmostEqual(float(answered["p"]), 0.279537003052569, msg=answered.to_dict())
        checks = rows[rows["family"].str.contains("(checks)", regex=False)]
        self.assertEqual(len(checks), 2)
        self.assertTrue(all(0 <= p <= 1 for p in checks["p"]), checks["p"].tolist())

    def test_design_questions_whose_fit_has_no_term_for_a_condition_still_have_its_row(self):
        """R's fit without the fixed effect of the compared condition (lme4 drops a level it cannot estimate):
        the comparison keeps its row, "not computed" saying why, never a table without it."""
        from calligraphy import design_analysis, study
        trials = study.load([str(Shared.get() / "study")]).trials
        self.fake.set(kind="good", term="factorX")
        rows = design_analysis.design_questions(trials, "total_time_s")
        mixed = rows[rows["family"] == "total_time_s, test"]
        self.assertEqual(mixed["comparison"].tolist(), ["H - V"], rows.to_dict("records"))
        self.assertTrue(mixed.iloc[0]["note"].startswith("not computed: "), mixed.iloc[0]["note"])
        self.assertIn("H", mixed.iloc[0]["note"])

    def assert_r_not_installed(self, make):
        """With only `make`'s Rscript on PATH: RUnavailable saying Rscript is not installed."""
        alone = Path(self.scratch.name) / "alone"
        shutil.rmtree(alone, ignore_errors=True)
        alone.mkdir()
        make(alone / "Rscript")
        path = os.environ["PATH"]
        os.environ["PATH"] = str(alone)
        try:
            with self.assertRaises(mixed_models.RUnavailable) as caught:
                self.fit()
        finally:
            os.environ["PATH"] = path
        self.assertIn("Rscript is not installed", str(caught.exception))
        self.assert_good_fit()

    def test_r_whose_first_frame_names_a_missing_package_is_r_not_installed_in_one_line(self):
        """The serving R says at its start that pbkrtest does not load: RUnavailable (not a spoilt fit) naming
        the package and its Debian name, that R ended, and the next R, whose packages load, answers."""
        self.assert_good_fit()
        self.fake.set(kind="exit")  # the serving R ends: the next fit starts one, which lacks the package
        with self.assertRaises(mixed_models.RAnswerError):
            self.fit()
        self.fake.set(kind="good", start="missing", package="pbkrtest")
        with self.assertRaises(mixed_models.RUnavailable) as caught:
            self.fit()
        self.assertNotIsInstance(caught.exception, mixed_models.RAnswerError)
        self.assertEqual(str(caught.exception),
                         "R's package pbkrtest is not installed (Debian: apt-get install r-cran-pbkrtest)")
        self.fake.assert_none_alive(self)
        self.assert_good_fit()

    def test_an_rscript_that_is_not_executable_is_r_not_installed(self):
        def make(path):
            shutil.copy(self.fake.script, path)
            path.chmod(0o644)
        self.assert_r_not_installed(make)

    def test_an_rscript_that_is_a_folder_is_r_not_installed(self):
        self.assert_r_not_installed(lambda path: path.mkdir())

    def test_r_that_forks_a_child_holding_its_pipe_then_exits_fails_the_fit_alone(self):
        self.assert_spoils_this_fit_only(kind="fork_and_exit")

    def test_r_that_closes_its_output_and_waits_fails_the_fit_alone(self):
        self.assert_spoils_this_fit_only(kind="close_stdout_and_wait")


CHILD = textwrap.dedent("""\
    import sys
    import pandas
    from calligraphy import mixed_models
    rows = %r
    frame = pandas.DataFrame(rows)
    print("fitting", flush=True)
    try:
        fit = mixed_models.lmer(frame, %r, %r)
        print("fitted", fit.fixed["estimate"].tolist())
    except mixed_models.RUnavailable as error:
        print(type(error).__name__, error)
    except KeyboardInterrupt:  # what a script does with Ctrl-C: this one ends quietly
        sys.exit(130)
    """)


@unittest.skipIf(mixed_models is None, "calligraphy.mixed_models or pandas cannot be imported")
class RProcessLife(unittest.TestCase):
    """A Python process of its own per case, stopped by a signal while R hangs: no R outlives it."""

    def setUp(self):
        self.folder = tempfile.TemporaryDirectory(prefix="calligraphy-r26c-life-")
        self.fake = FakeR(self.folder.name)

    def tearDown(self):
        self.folder.cleanup()

    def child(self, path=None, **popen):
        code = CHILD % (frame_rows(), FORMULA, FRAME_LEVELS)
        return subprocess.Popen([PYTHON, "-c", code], env=self.fake.environment(path), stdout=subprocess.PIPE,
                                stderr=subprocess.PIPE, **popen)

    def stopped(self, signum, **mode):
        self.fake.set(**mode)
        process = self.child()
        deadline = time.monotonic() + 20
        stage = "--serve"  # one R both checks its packages and serves
        while True:
            started = [p for p in self.fake.pids() if alive(p)]
            if any(stage.encode() in Path(f"/proc/{p}/cmdline").read_bytes() for p in started if alive(p)):
                break
            if time.monotonic() > deadline or process.poll() is not None:
                process.kill()
                self.fail(f"the fake R never reached {stage}: {process.communicate()[1][-500:]!r}")
            time.sleep(0.02)
        process.send_signal(signum)
        try:
            _, err = process.communicate(timeout=30)
        except subprocess.TimeoutExpired:
            process.kill()
            process.communicate()
            self.fake.assert_none_alive(self, within_s=0)
            self.fail("Python did not end on the signal while R hung")
        self.assertNotIn(b"Traceback", err, err.decode(errors="replace"))
        self.fake.assert_none_alive(self)

    def test_r_that_never_answers_and_ignores_sigterm_is_stopped_with_python_by_sigint(self):
        self.stopped(signal.SIGINT, kind="hang", ignore_sigterm=True)

    def test_r_that_ignores_sigterm_is_stopped_with_python_by_sigterm(self):
        self.stopped(signal.SIGTERM, kind="hang", ignore_sigterm=True)

    def test_the_first_r_that_never_answers_is_stopped_with_python(self):
        self.stopped(signal.SIGTERM, kind="good", start="hang")


# ---------------------------------------------------------------------------------------------------------
# (2) Journals.

class Journals(Case):
    def tables(self, name="tables", earlier=True):
        folder = self.cwd / name
        folder.mkdir()
        if earlier:
            for table in ("trials.csv", "strokes.csv"):
                (folder / table).write_text(f"earlier {table}\n")
        return folder

    def report(self, *args, timeout=60):
        return run(["report", self.study, *args], self.cwd, timeout=timeout)

    def killed_at_rename(self, folder, at, *extra, journal=True):
        """`report --csv FOLDER` killed by SIGKILL at its `at`-th rename (strace's fault injection); the journal
        it leaves (with `journal`)."""
        if STRACE is None:
            self.skipTest("strace is not installed: no run killed between two renames")
        killed = subprocess.run([STRACE, "-f", "-qq", "-o", "/dev/null", "-e", "trace=rename,renameat,renameat2",
                                 "-e", f"inject=rename,renameat,renameat2:signal=KILL:when={at}", CLI, "report",
                                 str(self.study), "--csv", str(folder), "--jobs", "1", *extra],
                                cwd=self.cwd, capture_output=True, timeout=60, env=ENV)
        self.assertNotEqual(killed.returncode, 0, killed.stderr.decode())
        if not journal:
            return None
        journals = [p for p in folder.iterdir() if p.name.startswith(JOURNAL_PREFIX)]
        self.assertEqual(len(journals), 1, sorted(os.listdir(folder)))
        return journals[0]

    def plant(self, folder, entries, version=3, pid=None, name=None):
        pid = dead_pid() if pid is None else pid
        path = folder / (name or f"{JOURNAL_PREFIX}{pid}-9.journal")
        path.write_bytes(journal_bytes(entries, version))
        return path

    def assert_refused_and_left(self, result, journal, outside=None, outside_before=None):
        before = journal.read_bytes() if not journal.is_symlink() else None
        self.assert_one_error(result, 1, journal.name)
        if before is not None:
            self.assertEqual(journal.read_bytes(), before)
        if outside is not None:
            self.assertEqual(tree(outside), outside_before, "a file outside the journal's folder changed")

    def outside(self):
        folder = self.cwd / "outside"
        folder.mkdir()
        (folder / "victim.csv").write_text("precious\n")
        return folder, tree(folder)

    # --- forged, checksum right --------------------------------------------------------------------------

    def test_journal_climbing_out_by_dot_dot_is_refused_and_left(self):
        tables = self.tables()
        outside, before = self.outside()
        pid = dead_pid()
        (tables / f".victim.csv.tmp-{pid}-0").write_text("forged\n")
        journal = self.plant(tables, [("../outside/victim.csv", f".victim.csv.kept-{pid}-0",
                                       f".victim.csv.tmp-{pid}-0")], pid=pid)
        listing = tree(tables)
        self.assert_refused_and_left(self.report("--csv", "tables"), journal, outside, before)
        self.assertEqual(tree(tables), listing, "the refused journal's folder changed")

    def test_journal_naming_a_file_through_a_link_in_its_folder_is_refused(self):
        tables = self.tables()
        outside, before = self.outside()
        (tables / "sub").symlink_to(outside)
        pid = dead_pid()
        (tables / f".t.tmp-{pid}-0").write_text("forged\n")
        journal = self.plant(tables, [("sub/victim.csv", f".t.kept-{pid}-0", f".t.tmp-{pid}-0")], pid=pid)
        self.assert_refused_and_left(self.report("--csv", "tables"), journal, outside, before)

    def test_journal_whose_temporary_is_a_link_to_a_file_outside_is_refused(self):
        tables = self.tables()
        outside, before = self.outside()
        pid = dead_pid()
        (tables / f".trials.csv.tmp-{pid}-0").symlink_to(outside / "victim.csv")
        journal = self.plant(tables, [("trials.csv", f".trials.csv.kept-{pid}-0", f".trials.csv.tmp-{pid}-0")],
                             pid=pid)
        self.assert_refused_and_left(self.report("--csv", "tables"), journal, outside, before)
        self.assertEqual((tables / "trials.csv").read_text(), "earlier trials.csv\n")

    def test_journal_whose_kept_name_is_a_link_to_a_file_outside_is_refused(self):
        tables = self.tables()
        outside, before = self.outside()
        pid = dead_pid()
        (tables / f".trials.csv.tmp-{pid}-0").write_text("new\n")
        (tables / f".trials.csv.kept-{pid}-0").symlink_to(outside / "victim.csv")
        journal = self.plant(tables, [("trials.csv", f".trials.csv.kept-{pid}-0", f".trials.csv.tmp-{pid}-0")],
                             pid=pid)
        self.assert_refused_and_left(self.report("--csv", "tables"), journal, outside, before)

    def test_journal_naming_a_folder_loses_nothing(self):
        tables = self.tables()
        pid = dead_pid()
        inner = tables / f".trials.csv.tmp-{pid}-0"
        inner.mkdir()
        (inner / "keep.txt").write_text("keep\n")
        journal = self.plant(tables, [("trials.csv", f".trials.csv.kept-{pid}-0", inner.name)], pid=pid)
        result = self.report("--csv", "tables")
        self.assert_refused_and_left(result, journal)
        self.assertEqual((inner / "keep.txt").read_text(), "keep\n")
        self.assertTrue((tables / "trials.csv").is_file())

    def test_journal_with_a_nul_in_a_name_is_refused(self):
        tables = self.tables()
        pid = dead_pid()
        journal = self.plant(tables, [(b"trials.csv\0x", f".trials.csv.kept-{pid}-0", f".trials.csv.tmp-{pid}-0")],
                             pid=pid)
        self.assert_refused_and_left(self.report("--csv", "tables"), journal)
        self.assertEqual((tables / "trials.csv").read_text(), "earlier trials.csv\n")

    def test_journal_with_a_line_break_in_a_name_is_refused(self):
        tables = self.tables()
        pid = dead_pid()
        name = ".trials.csv.tmp-\n0"
        (tables / name).write_text("forged\n")
        journal = self.plant(tables, [("trials.csv", f".trials.csv.kept-{pid}-0", name)], pid=pid)
        self.assert_refused_and_left(self.report("--csv", "tables"), journal)
        self.assertEqual((tables / "trials.csv").read_text(), "earlier trials.csv\n")

    def test_journal_naming_itself_is_refused(self):
        tables = self.tables()
        pid = dead_pid()
        name = f"{JOURNAL_PREFIX}{pid}-9.journal"
        journal = self.plant(tables, [("trials.csv", f".trials.csv.kept-{pid}-0", name)], pid=pid, name=name)
        self.assert_refused_and_left(self.report("--csv", "tables"), journal)
        self.assertEqual((tables / "trials.csv").read_text(), "earlier trials.csv\n")

    def test_journal_naming_itself_as_the_file_it_completes_is_refused(self):
        tables = self.tables()
        pid = dead_pid()
        name = f"{JOURNAL_PREFIX}{pid}-9.journal"
        (tables / f".j.tmp-{pid}-0").write_text("forged\n")
        journal = self.plant(tables, [(name, f".j.kept-{pid}-0", f".j.tmp-{pid}-0")], pid=pid, name=name)
        self.assert_refused_and_left(self.report("--csv", "tables"), journal)

    def test_journal_whose_kept_name_is_a_users_file_does_not_remove_it(self):
        tables = self.tables()
        pid = dead_pid()
        (tables / "notes.txt").write_text("the user's notes\n")
        (tables / f".trials.csv.tmp-{pid}-0").write_text("new\n")
        journal = self.plant(tables, [("trials.csv", "notes.txt", f".trials.csv.tmp-{pid}-0")], pid=pid)
        self.assert_refused_and_left(self.report("--csv", "tables"), journal)
        self.assertEqual((tables / "notes.txt").read_text(), "the user's notes\n")

    def test_journal_whose_temporary_is_a_users_file_does_not_move_it(self):
        tables = self.tables()
        pid = dead_pid()
        (tables / "notes.txt").write_text("the user's notes\n")
        journal = self.plant(tables, [("trials.csv", f".trials.csv.kept-{pid}-0", "notes.txt")], pid=pid)
        self.assert_refused_and_left(self.report("--csv", "tables"), journal)
        self.assertEqual((tables / "notes.txt").read_text(), "the user's notes\n")
        self.assertEqual((tables / "trials.csv").read_text(), "earlier trials.csv\n")

    def test_journal_naming_one_file_twice_leaves_a_whole_set(self):
        tables = self.tables()
        pid = dead_pid()
        for n in (0, 1):
            (tables / f".trials.csv.tmp-{pid}-{n}").write_text(f"forged {n}\n")
        journal = self.plant(tables, [("trials.csv", f".trials.csv.kept-{pid}-{n}", f".trials.csv.tmp-{pid}-{n}")
                                      for n in (0, 1)], pid=pid)
        result = self.report("--csv", "tables")
        if result.returncode == 0:
            self.assertEqual(tree(tables), self.fresh)
        else:
            self.assert_refused_and_left(result, journal)
            self.assertEqual((tables / "trials.csv").read_text(), "earlier trials.csv\n")

    def test_journal_naming_no_file_leaves_a_whole_set(self):
        tables = self.tables()
        journal = self.plant(tables, [])
        result = self.report("--csv", "tables")
        if result.returncode == 0:
            self.assertEqual(tree(tables), self.fresh)
        else:
            self.assert_refused_and_left(result, journal)

    def test_journal_whose_temporary_is_a_hard_link_to_a_file_outside_leaves_that_file(self):
        tables = self.tables()
        outside, before = self.outside()
        pid = dead_pid()
        os.link(outside / "victim.csv", tables / f".trials.csv.tmp-{pid}-0")
        self.plant(tables, [("trials.csv", f".trials.csv.kept-{pid}-0", f".trials.csv.tmp-{pid}-0")], pid=pid)
        result = self.report("--csv", "tables")
        self.assertIn(result.returncode, (0, 1), result.stderr.decode())
        if result.returncode == 0:
            self.assertEqual(tree(tables), self.fresh)
        self.assertEqual(tree(outside), before, "the file outside changed through its hard link")

    def test_huge_journal_is_refused_without_reading_it_all(self):
        tables = self.tables()
        journal = tables / f"{JOURNAL_PREFIX}{dead_pid()}-9.journal"
        with open(journal, "wb") as out:
            out.write(b"calligraphy-set-journal 3\n")
            out.truncate(1 << 30)  # 1 GiB, sparse
        started = time.process_time()
        result = self.report("--csv", "tables", timeout=30)
        self.assert_one_error(result, 1, journal.name)
        self.assertEqual(journal.stat().st_size, 1 << 30)
        self.assertLess(time.process_time() - started, 5)

    def test_journal_of_a_newer_version_is_refused(self):
        tables = self.tables()
        pid = dead_pid()
        (tables / f".trials.csv.tmp-{pid}-0").write_text("new\n")
        journal = self.plant(tables, [("trials.csv", f".trials.csv.kept-{pid}-0", f".trials.csv.tmp-{pid}-0")],
                             version=4, pid=pid)
        self.assert_refused_and_left(self.report("--csv", "tables"), journal)
        self.assertEqual((tables / "trials.csv").read_text(), "earlier trials.csv\n")

    def test_journal_that_is_a_link_to_a_real_journal_elsewhere_is_refused(self):
        elsewhere = self.tables("elsewhere")
        real = self.killed_at_rename(elsewhere, 3)
        before = tree(elsewhere)
        tables = self.tables()
        link = tables / real.name
        link.symlink_to(real)
        result = self.report("--csv", "tables")
        self.assert_one_error(result, 1, link.name)
        self.assertTrue(link.is_symlink())
        self.assertEqual(tree(elsewhere), before, "a journal linked into tables/ changed the folder it names")

    def test_journal_that_is_a_folder_is_named(self):
        tables = self.tables()
        journal = tables / f"{JOURNAL_PREFIX}{dead_pid()}-9.journal"
        journal.mkdir()
        result = self.report("--csv", "tables")
        self.assert_one_error(result, 1, journal.name)
        self.assertTrue(journal.is_dir())

    def test_journal_cut_before_its_checksum_is_refused(self):
        tables = self.tables()
        real = self.killed_at_rename(tables, 3)
        text = real.read_bytes()
        real.write_bytes(text[:text.rindex(b"checksum")])
        self.assert_refused_and_left(self.report("--csv", "tables"), real)

    # --- journals the program wrote ------------------------------------------------------------------------

    def test_killed_between_renames_then_completed(self):
        tables = self.tables()
        self.killed_at_rename(tables, 3)
        result = self.report("--csv", "tables")
        self.assertEqual(result.returncode, 0, result.stderr.decode())
        self.assertEqual(tree(tables), self.fresh)

    def test_folder_renamed_between_the_kill_and_the_next_run_is_completed(self):
        tables = self.tables()
        self.killed_at_rename(tables, 3)
        moved = self.cwd / "moved"
        tables.rename(moved)
        result = self.report("--csv", "moved")
        self.assertEqual(result.returncode, 0, result.stderr.decode())
        self.assertEqual(tree(moved), self.fresh)

    def test_folder_copied_after_the_kill_completes_each_copy_alone(self):
        tables = self.tables()
        self.killed_at_rename(tables, 3)
        shutil.copytree(tables, self.cwd / "copy", symlinks=True)
        copy_before = tree(self.cwd / "copy")
        result = self.report("--csv", "tables")
        self.assertEqual(result.returncode, 0, result.stderr.decode())
        self.assertEqual(tree(tables), self.fresh)
        self.assertEqual(tree(self.cwd / "copy"), copy_before, "completing tables/ changed its copy")
        result = self.report("--csv", "copy")
        self.assertEqual(result.returncode, 0, result.stderr.decode())
        self.assertEqual(tree(self.cwd / "copy"), self.fresh)

    def test_two_journals_in_one_folder_leave_a_whole_set(self):
        tables = self.tables()
        self.killed_at_rename(tables, 3)
        other = self.tables("other")
        for table in ("trials.csv", "strokes.csv"):
            (other / table).write_text(f"other {table}\n")
        second = self.killed_at_rename(other, 2)
        for path in other.iterdir():
            if path.name.startswith("."):
                shutil.copy(path, tables / path.name, follow_symlinks=False)
        self.assertEqual(len([p for p in tables.iterdir() if p.name.startswith(JOURNAL_PREFIX)]), 2)
        result = self.report("--csv", "tables")
        if result.returncode == 0:
            self.assertEqual(tree(tables), self.fresh)
        else:
            self.assert_one_error(result, 1, JOURNAL_PREFIX)
            pair = ((tables / "trials.csv").read_bytes(), (tables / "strokes.csv").read_bytes())
            self.assertIn(pair, [(b"earlier trials.csv\n", b"earlier strokes.csv\n"),
                                 (b"other trials.csv\n", b"other strokes.csv\n"),
                                 (self.fresh["trials.csv"], self.fresh["strokes.csv"])])
        self.assertTrue(second.exists())

    def test_a_run_racing_a_run_stopped_between_its_renames_leaves_a_whole_set(self):
        if STRACE is None:
            self.skipTest("strace is not installed: no run held between two renames")
        tables = self.tables()
        slow = subprocess.Popen([STRACE, "-f", "-qq", "-o", "/dev/null", "-e", "trace=rename,renameat,renameat2",
                                 "-e", "inject=rename,renameat,renameat2:delay_enter=1500000:when=2", CLI, "report",
                                 str(self.study), "--csv", str(tables), "--jobs", "1"], cwd=self.cwd, env=ENV,
                                stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
        deadline = time.monotonic() + 20
        while not any(p.name.startswith(JOURNAL_PREFIX) for p in tables.iterdir()):
            self.assertLess(time.monotonic(), deadline, "the held run never wrote its journal")
            time.sleep(0.02)
        result = self.report("--csv", "tables")
        slow_error = slow.communicate(timeout=60)[1]
        self.assertEqual(slow.returncode, 0, slow_error.decode())
        self.assertEqual(result.returncode, 0, result.stderr.decode())
        self.assertEqual(tree(tables), self.fresh)

    def test_journal_naming_a_live_process_that_holds_no_lock_is_completed(self):
        """The renames happen under the folder's lock (docs/experiments.md), so a journal whose id is a live
        process's (an id reused) but whose folder no writer holds is a dead writer's: completed, never waited
        on."""
        tables = self.tables()
        live = subprocess.Popen(["sleep", "30"])
        self.addCleanup(live.wait)
        self.addCleanup(live.kill)
        tmp = tables / f".trials.csv.tmp-{live.pid}-0"
        tmp.write_text("the dead writer's table\n")
        self.plant(tables, [("trials.csv", f".trials.csv.kept-{live.pid}-0", tmp.name)], pid=live.pid)
        result = self.report("--csv", "tables", timeout=30)
        self.assertEqual(result.returncode, 0, result.stderr.decode())
        self.assertEqual(tree(tables), self.fresh)

    def test_journal_in_an_input_session_folder_changes_no_session_file(self):
        study = self.cwd / "study"
        shutil.copytree(self.study, study, symlinks=True)
        (session,) = study.glob("S01/*")
        pid = dead_pid()
        (session / f".session.json.tmp-{pid}-0").write_text("{}\n")
        journal = self.plant(session, [("session.json", f".session.json.kept-{pid}-0",
                                        f".session.json.tmp-{pid}-0")], pid=pid)
        before = tree(study)
        (self.cwd / "tables").mkdir()
        result = run(["report", study, "--csv", "tables"], self.cwd)
        if result.returncode != 0:
            self.assert_one_error(result, 1, journal.name)
        self.assertEqual(tree(study), before, "a journal in an input folder changed the study")

    def test_journal_beside_the_index_page_forged_to_replace_it_with_another_file(self):
        site = self.cwd / "site"
        site.mkdir()
        made = self.report("--out", "site/r.html")
        self.assertEqual(made.returncode, 0, made.stderr.decode())
        page = (site / "r.html").read_bytes()
        pid = dead_pid()
        (site / f".r.html.tmp-{pid}-0").write_text("<p>planted</p>\n")
        self.plant(site, [("r.html", f".r.html.kept-{pid}-0", f".r.html.tmp-{pid}-0")], pid=pid)
        result = self.report("--out", "site/r.html")
        self.assertIn(result.returncode, (0, 1), result.stderr.decode())
        if result.returncode == 0:
            self.assertEqual((site / "r.html").read_bytes(), page)
            self.assertEqual(leftovers(site), [])
        else:
            self.assert_one_error(result, 1, JOURNAL_PREFIX)
            self.assertEqual((site / "r.html").read_bytes(), page)

    def test_set_over_two_folders_killed_then_one_folder_renamed(self):
        tables = self.tables()
        site = self.cwd / "site"
        site.mkdir()
        self.killed_at_rename(tables, 3, "--out", str(site / "r.html"), journal=False)
        tables.rename(self.cwd / "moved")
        result = self.report("--csv", "moved", "--out", "site/r.html")
        self.assertEqual(result.returncode, 0, result.stderr.decode())
        self.assertEqual(tree(self.cwd / "moved"), self.fresh)
        self.assertEqual(leftovers(site), [])


if __name__ == "__main__":
    unittest.main()
