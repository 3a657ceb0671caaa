#!/usr/bin/env python3
"""Round 12F, written from the documentation alone (docs/experiments.md, docs/learning-study.md, docs/cli.md,
docs/python.md, the commands' `--help` and `calligraphy schema`): protocols of the three designs (between,
crossover, mixed) with items, conditions and sets listed twice, mislabelled assignments, names outside their
alphabet and plans past their size; `session run|resume|plan|cohort` given subject counts and numbers at their
edges, stopped by SIGTERM and SIGKILL at random moments and resumed, raced, resumed through a link, copied with
hard links, renamed, moved and edited; `report` with its tables in a session's folder, links in the study,
another study's trial swapped in; the R process behind the study report answering in Latin-1, killed with its
Python process, and R's handling of factor names that need quoting; Python's study API given wrong types, an
empty study and a Ctrl-C. Run by CTest as `cli_unseen_round12f_tests`.

Each case asserts what the documentation promises: one error line naming the option, file or JSON pointer;
exit 2 for usage and content refused, 1 for damaged data or a runtime failure; never a crash, a hang, a
traceback, a silent wrong result, a file written outside its folder, an input changed, a temporary or a
process left behind. CALLIGRAPHY_CLI names the program; the built Python package is found on PYTHONPATH (its
cases are skipped without it). CALLIGRAPHY_SANITIZED=1 takes a small subset.
"""
import csv
import hashlib
import json
import os
import random
import shutil
import signal
import subprocess
import sys
import tempfile
import textwrap
import time
import unittest
from pathlib import Path

from outsider import descendants, running

CLI = os.environ.get("CALLIGRAPHY_CLI", "")
TIMEOUT_S = 60
SANITIZED = os.environ.get("CALLIGRAPHY_SANITIZED") == "1"

heavy = unittest.skipIf(SANITIZED, "several runs of the program: left to the Release run")

try:
    import calligraphy.study as cg_study
    import calligraphy as cg
except ImportError:  # pragma: no cover - a build without the Python bindings
    cg = None
    cg_study = None

needs_python = unittest.skipIf(cg is None, "the Python package is not on PYTHONPATH")

ENV = {k: v for k, v in os.environ.items()
       if not k.startswith("CALLIGRAPHY_LIBHD") and k not in ("DISPLAY", "WAYLAND_DISPLAY")}

SHI, REN, KOU = "十", "人", "口"

# Between subjects: an unguided pre-test, training in one of two groups, a post-test (3 trials a subject).
BETWEEN = {"name": "b12", "conditions": [{"name": "u", "mode": "vision"}, {"name": "f", "mode": "haptic"}],
           "phases": [{"phase": "pre-test", "condition": "u", "characters": [SHI]},
                      {"phase": "training", "conditions": ["u", "f"], "assignment": "between-subjects",
                       "characters": [SHI], "repetitions": 1},
                      {"phase": "post-test", "condition": "u", "characters": [SHI]}],
           "trial": {"max_duration_s": 20}}
# Within subjects, the paper's form: 4 trials a subject (8 with two repetitions, long enough to be stopped).
WITHIN = {"name": "w12", "conditions": [{"name": "u", "mode": "vision"}, {"name": "f", "mode": "haptic"}],
          "test": {"characters": [SHI, REN], "conditions": ["u", "f"], "repetitions": 1},
          "trial": {"max_duration_s": 20}}
WITHIN_LONG = json.loads(json.dumps(WITHIN))
WITHIN_LONG["test"]["repetitions"] = 2
# Two days: the retention test a day later.
DAYS = {"name": "r12", "conditions": [{"name": "u", "mode": "vision"}, {"name": "f", "mode": "haptic"}],
        "phases": [{"phase": "pre-test", "condition": "u", "characters": [SHI]},
                   {"phase": "training", "conditions": ["u", "f"], "assignment": "between-subjects",
                    "characters": [SHI], "repetitions": 1},
                   {"phase": "retention", "condition": "u", "characters": [SHI], "session": 2, "delay_s": 86400}],
        "trial": {"max_duration_s": 20}}
# A crossover of two conditions on two sets.
CROSSOVER = {"name": "x12", "conditions": [{"name": "u", "mode": "vision"}, {"name": "a", "mode": "error-amplification"}],
             "item_sets": [{"name": "s1", "characters": [SHI]}, {"name": "s2", "characters": [REN]}],
             "phases": [{"phase": "pre-test", "condition": "u", "sets": ["s1", "s2"]},
                        {"phase": "training", "conditions": ["u", "a"], "assignment": "crossover",
                         "sets": ["s1", "s2"], "repetitions": 1},
                        {"phase": "post-test", "condition": "u", "sets": ["s1", "s2"]}],
             "trial": {"max_duration_s": 20}}


def run(args, cwd, timeout=TIMEOUT_S, env=None):
    arguments = [a if isinstance(a, bytes) else str(a) for a in args]
    return subprocess.run([CLI, *arguments], cwd=cwd, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                          timeout=timeout, env=env or ENV)


def text(result):
    return result.stderr.decode("utf-8", "replace")


def error_lines(result):
    return [line for line in text(result).strip().splitlines() if ": error: " in line]


def write_json(path, value):
    Path(path).write_text(json.dumps(value, ensure_ascii=False), encoding="utf-8")
    return Path(path)


def tree_digest(folder):
    """Every file under folder (relative name -> SHA-256 of its bytes): what 'unchanged' means."""
    digest = {}
    for path in sorted(Path(folder).rglob("*")):
        if path.is_file() and not path.is_symlink():
            digest[str(path.relative_to(folder))] = hashlib.sha256(path.read_bytes()).hexdigest()
    return digest


def read_rows(path):
    with open(path, encoding="utf-8", newline="") as stream:
        return list(csv.DictReader(stream))


def sessions_of(study, subject="S01"):
    return sorted(p for p in (Path(study) / subject).iterdir() if not p.name.startswith("."))


def planned_stems(session):
    return [entry["file"] for entry in json.loads((session / "session.json").read_text("utf-8"))["plan"]]


def leftovers(folder):
    """Temporaries a run may leave only while it runs: a record's .part, a .tmp, a .partial. folder."""
    return [str(p) for p in Path(folder).rglob("*")
            if p.name.endswith(".part") or ".tmp" in p.name or p.name.startswith(".partial.")]


def unfinish(session, keep):
    """Remove every saved trial after the first `keep`: a session stopped there, made without timing."""
    for stem in planned_stems(session)[keep:]:
        for path in (session / "trials").glob(stem + ".*"):
            path.unlink()


def process_group_members(sid):
    members = []
    for entry in os.listdir("/proc"):
        if not entry.isdigit():
            continue
        try:
            stat = Path(f"/proc/{entry}/stat").read_text().rsplit(")", 1)[1].split()
        except OSError:
            continue
        if int(stat[3]) == sid:  # the session id: every process the started one made, reparented or not
            members.append(int(entry))
    return members


def command_of(pid):
    try:
        return Path(f"/proc/{pid}/comm").read_text().strip()
    except OSError:
        return ""


def reap_session(sid):
    for pid in process_group_members(sid):
        try:
            os.kill(pid, signal.SIGKILL)
        except ProcessLookupError:
            pass


class Shared:
    """A between-subjects study of four simulated subjects (12 trials), made once."""
    folder = None

    @classmethod
    def make(cls):
        if cls.folder is None:
            cls.folder = Path(tempfile.mkdtemp(prefix="round12f-shared-"))
            write_json(cls.folder / "b.json", BETWEEN)
            result = run(["session", "run", "b.json", "--writer", "simulated", "--subjects", "4", "--out", "study"],
                         cls.folder)
            assert result.returncode == 0, text(result)
        return cls.folder

    @classmethod
    def remove(cls):
        if cls.folder is not None:
            shutil.rmtree(cls.folder, ignore_errors=True)
            cls.folder = None


class Made:
    """Complete studies of one simulated subject (`session run --subjects 1`), each protocol's run once: a case
    that stops, edits, moves or resumes such a study works on a copy of it (the same files; none of them names
    the folder it is in)."""
    folder = None
    studies = {}

    @classmethod
    def copy(cls, name, document, target):
        """The session folders of a copy, at `target`, of the study of `document` (run under `name`)."""
        if name not in cls.studies:
            if cls.folder is None:
                cls.folder = Path(tempfile.mkdtemp(prefix="round12f-made-"))
            write_json(cls.folder / f"{name}.json", document)
            result = run(["session", "run", f"{name}.json", "--writer", "simulated", "--subjects", "1", "--out",
                          name], cls.folder)
            assert result.returncode == 0, text(result)
            cls.studies[name] = cls.folder / name
        shutil.copytree(cls.studies[name], target, symlinks=True)
        return sessions_of(target)

    @classmethod
    def remove(cls):
        if cls.folder is not None:
            shutil.rmtree(cls.folder, ignore_errors=True)
            cls.folder = None
            cls.studies = {}


@unittest.skipUnless(CLI, "CALLIGRAPHY_CLI is not set")
class Protocols(unittest.TestCase):
    """Every design's protocol read by `session plan` (nothing runs, nothing is written)."""

    def setUp(self):
        self.dir = Path(tempfile.mkdtemp(prefix="round12f-protocol-"))

    def tearDown(self):
        shutil.rmtree(self.dir, ignore_errors=True)

    def plan(self, protocol, *extra, name="p.json"):
        write_json(self.dir / name, protocol)
        return run(["session", "plan", name, "--subjects", "2", *extra], self.dir)

    def assert_refused_at(self, result, pointer):
        lines = error_lines(result)
        self.assertEqual(result.returncode, 2, text(result))
        self.assertEqual(len(lines), 1, text(result))
        self.assertIn("p.json: " + pointer, lines[0])
        self.assertEqual(result.stdout, b"")

    def test_a_character_listed_twice_is_refused_or_counted_as_its_next_repetition(self):
        # docs/experiments.md: `repetition` counts how often a string was written in that condition (1-based).
        # Listing 十 twice in one phase, in the paper's `test` or in one item set must not give two trials both
        # labelled the first repetition: either the protocol is refused naming the second, or it is counted.
        cases = []
        between = json.loads(json.dumps(BETWEEN))
        between["phases"][0]["characters"] = [SHI, SHI]
        cases.append((between, "/phases/0/characters/1"))
        within = json.loads(json.dumps(WITHIN))
        within["test"]["characters"] = [SHI, REN, SHI]
        cases.append((within, "/test/characters/2"))
        crossover = json.loads(json.dumps(CROSSOVER))
        crossover["item_sets"][0]["characters"] = [SHI, SHI]
        cases.append((crossover, "/item_sets/0/characters/1"))
        for protocol, pointer in cases:
            with self.subTest(pointer=pointer):
                result = self.plan(protocol, "--json")
                if result.returncode == 2:
                    self.assert_refused_at(result, pointer)
                    continue
                self.assertEqual(result.returncode, 0, text(result))
                # Run it: the saved trials of one string in one condition carry 1, 2, ... as repetition.
                run_result = run(["session", "run", "p.json", "--writer", "simulated", "--subjects", "1",
                                  "--out", "s"], self.dir)
                self.assertEqual(run_result.returncode, 0, text(run_result))
                seen = {}
                for record in sorted((self.dir / "s" / "S01").glob("*/trials/*.json")):
                    trial = json.loads(record.read_text("utf-8"))
                    key = (trial["phase"], trial["condition"], trial["characters"], trial["repetition"])
                    self.assertNotIn(key, seen, f"{record.name} and {seen.get(key)} are both {key}")
                    seen[key] = record.name
                shutil.rmtree(self.dir / "s")

    def test_conditions_and_sets_listed_twice_are_refused_naming_the_second(self):
        between = json.loads(json.dumps(BETWEEN))
        between["phases"][1]["conditions"] = ["u", "u"]
        self.assert_refused_at(self.plan(between), "/phases/1/conditions/1")
        crossover = json.loads(json.dumps(CROSSOVER))
        crossover["phases"][1]["conditions"] = ["a", "a"]
        self.assert_refused_at(self.plan(crossover), "/phases/1/conditions/1")
        crossover = json.loads(json.dumps(CROSSOVER))
        crossover["phases"][1]["sets"] = ["s2", "s2"]
        self.assert_refused_at(self.plan(crossover), "/phases/1/sets/1")
        crossover = json.loads(json.dumps(CROSSOVER))
        crossover["item_sets"][1]["characters"] = [REN, SHI]  # 十 in both sets
        result = self.plan(crossover)
        self.assertEqual(result.returncode, 2, text(result))
        self.assertIn("/item_sets/", error_lines(result)[0])

    def test_mislabelled_designs_are_refused_naming_the_assignment(self):
        # A crossover given characters instead of sets, a between-subjects phase of one condition, a crossover
        # on the familiarisation, a spelling of another case and a design named in another language.
        cases = []
        p = json.loads(json.dumps(BETWEEN))
        p["phases"][1]["assignment"] = "crossover"
        cases.append((p, "/phases/1"))
        p = json.loads(json.dumps(BETWEEN))
        p["phases"][0]["assignment"] = "between-subjects"
        cases.append((p, "/phases/0"))
        p = json.loads(json.dumps(BETWEEN))
        p["phases"][1]["assignment"] = "Between-Subjects"
        cases.append((p, "/phases/1/assignment"))
        p = json.loads(json.dumps(BETWEEN))
        p["phases"][1]["assignment"] = "between_subjects"
        cases.append((p, "/phases/1/assignment"))
        p = json.loads(json.dumps(CROSSOVER))
        p["phases"].insert(0, {"phase": "practice", "conditions": ["u", "a"], "assignment": "crossover",
                               "sets": ["s1", "s2"]})
        cases.append((p, "/phases/0"))
        for protocol, pointer in cases:
            with self.subTest(pointer=pointer, assignment=json.dumps(protocol["phases"])[:80]):
                self.assert_refused_at(self.plan(protocol), pointer)

    def test_names_outside_their_alphabet_or_length_are_refused_naming_the_pointer(self):
        for key, value, pointer in (("name", "ｐ１２", "/name"), ("name", "p" * 65, "/name"),
                                    ("name", "p12\u200b", "/name"), ("name", "", "/name"),
                                    ("condition", "ü", "/conditions/0/name"),
                                    ("condition", "u" * 33, "/conditions/0/name"),
                                    ("set", "集", "/item_sets/0/name"), ("set", "s\n1", "/item_sets/0/name")):
            with self.subTest(key=key, value=value):
                p = json.loads(json.dumps(CROSSOVER))
                if key == "name":
                    p["name"] = value
                elif key == "condition":
                    p["conditions"][0]["name"] = value
                    for phase in p["phases"]:
                        if "condition" in phase:
                            phase["condition"] = value
                        else:
                            phase["conditions"][0] = value
                else:
                    p["item_sets"][0]["name"] = value
                    for phase in p["phases"]:
                        phase["sets"][0] = value
                result = self.plan(p)
                self.assert_refused_at(result, pointer)
                self.assertNotIn("\n", error_lines(result)[0].rstrip("\n"))
        # At the bound: 64 and 32 characters are names.
        p = json.loads(json.dumps(CROSSOVER))
        p["name"] = "p" * 64
        self.assertEqual(self.plan(p).returncode, 0)
        # A subject prefix of another alphabet is a usage error naming --subject.
        result = self.plan(CROSSOVER, "--subject", "主")
        self.assertEqual(result.returncode, 2, text(result))
        self.assertIn("--subject", error_lines(result)[0])

    def test_a_delay_at_and_past_366_days_and_numbers_of_other_spellings(self):
        year = 366 * 86400
        p = json.loads(json.dumps(DAYS))
        p["phases"][2]["delay_s"] = year
        self.assertEqual(self.plan(p).returncode, 0)
        for value in (year + 0.5, 1e308, -1e-300, -1):
            with self.subTest(value=value):
                p["phases"][2]["delay_s"] = value
                self.assert_refused_at(self.plan(p), "/phases/2/delay_s")
        p["phases"][2]["delay_s"] = 86400
        p["phases"][2]["session"] = 3  # skips session 2
        self.assert_refused_at(self.plan(p), "/phases/2")
        # Text that is not JSON's number: hex, NaN, a number in a string.
        for spelled in ("0x10", "NaN", '"86400"', "8.64e4.0"):
            with self.subTest(spelled=spelled):
                body = json.dumps(DAYS, ensure_ascii=False).replace('"delay_s": 86400', '"delay_s": ' + spelled)
                (self.dir / "p.json").write_text(body, encoding="utf-8")
                result = run(["session", "plan", "p.json", "--subjects", "2"], self.dir)
                self.assertEqual(result.returncode, 2, text(result))
                self.assertEqual(len(error_lines(result)), 1, text(result))
                self.assertIn("p.json", error_lines(result)[0])

    def test_a_phases_plan_past_a_million_trials_is_refused_before_it_is_made(self):
        # 1000 strings x 26 conditions x 1000 repetitions in one training phase: 26 million trials. The limit is
        # documented for `test`; the phases' plan must be sized before it is built, under a memory cap too.
        strings = ["".join((SHI, REN, KOU)[(n // 3 ** k) % 3] for k in range(7)) for n in range(1000)]
        conditions = [{"name": f"c{i}", "mode": "vision"} for i in range(26)]
        p = {"name": "huge", "conditions": conditions,
             "phases": [{"phase": "pre-test", "condition": "c0", "characters": [SHI]},
                        {"phase": "training", "conditions": [c["name"] for c in conditions],
                         "characters": strings, "repetitions": 1000},
                        {"phase": "post-test", "condition": "c0", "characters": [SHI]}],
             "trial": {"max_duration_s": 10}}
        write_json(self.dir / "p.json", p)

        def cap():
            import resource
            resource.setrlimit(resource.RLIMIT_AS, (2 << 30, 2 << 30))

        for command in (["session", "plan", "p.json", "--subjects", "1"],
                        ["session", "run", "p.json", "--writer", "simulated", "--subjects", "1", "--out", "s"]):
            with self.subTest(command=command[1]):
                result = subprocess.run([CLI, *command], cwd=self.dir, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                                        timeout=TIMEOUT_S, env=ENV, preexec_fn=cap)
                self.assertEqual(result.returncode, 2, text(result))
                self.assertIn("1,000,000", error_lines(result)[0])
                self.assertFalse((self.dir / "s").exists())

    def test_crossovers_of_25_and_26_conditions_follow_the_williams_square(self):
        chars = "一二三四五六七八九十人口大天木山中日千女子小水火土王"
        for k, square, reachable in ((25, 1250, False), (26, 676, True)):
            with self.subTest(k=k):
                conditions = [{"name": f"c{i}", "mode": "vision"} for i in range(k)]
                sets = [{"name": f"s{i}", "characters": [chars[i]]} for i in range(k)]
                p = {"name": f"x{k}", "conditions": conditions, "item_sets": sets,
                     "phases": [{"phase": "training", "conditions": [c["name"] for c in conditions],
                                 "assignment": "crossover", "sets": [s["name"] for s in sets]}],
                     "trial": {"max_duration_s": 10}}
                result = self.plan(p, "--json")
                self.assertEqual(result.returncode, 0, text(result))
                document = json.loads(result.stdout)
                self.assertEqual(document["balance"]["square"], square)
                self.assertEqual(document["balance"]["reachable"], reachable)
                self.assertTrue(document["balance"]["warning"])
                # Row 0: 0, 1, k-1, 2, k-2, ...; subject 2 is row 1 (each position one more, mod k).
                row0 = [0, 1]
                low, high = 2, k - 1
                while len(row0) < k:
                    row0.append(high)
                    high -= 1
                    if len(row0) < k:
                        row0.append(low)
                        low += 1
                letters = "ABCDEFGHIJKLMNOPQRSTUVWXYZ"
                expected = "".join(letters[(c + 1) % k] for c in row0)
                self.assertEqual(document["subjects"][1]["sequence"], expected)


@unittest.skipUnless(CLI, "CALLIGRAPHY_CLI is not set")
class Sessions(unittest.TestCase):
    """session run, resume and cohort: counts at their edges, signals, races, links, copies and edits."""

    def setUp(self):
        self.dir = Path(tempfile.mkdtemp(prefix="round12f-session-"))
        write_json(self.dir / "b.json", BETWEEN)
        write_json(self.dir / "w.json", WITHIN)
        write_json(self.dir / "long.json", WITHIN_LONG)
        write_json(self.dir / "r.json", DAYS)

    def tearDown(self):
        shutil.rmtree(self.dir, ignore_errors=True)

    def complete(self, protocol="w.json", out="study"):
        """The sessions of a complete study of one subject of `protocol` (w.json or r.json) at `out`: a copy of
        the one run for every case."""
        return Made.copy(protocol[:-len(".json")], {"w.json": WITHIN, "r.json": DAYS}[protocol], self.dir / out)

    def test_subjects_zero_is_refused_not_taken_as_none(self):
        # `--subjects N (0-1000)`: zero subjects is either nothing run or a usage error naming --subjects; it must
        # never run a subject the option did not ask for.
        result = run(["session", "run", "b.json", "--writer", "simulated", "--subject", "P3", "--subjects", "0",
                      "--out", "study"], self.dir)
        self.assertFalse((self.dir / "study" / "P3").exists(), "--subjects 0 ran subject P3")
        self.assertEqual(result.returncode, 2, text(result))
        self.assertIn("--subjects", error_lines(result)[0])

    def test_a_subject_number_no_group_can_take_is_a_usage_error(self):
        # The digits ending the id are its number; 0 (or digits past any integer) assigns no group: the value the
        # user gave is wrong, exit 2 naming it, nothing written.
        for subject in ("X0", "X" + "9" * 25):
            with self.subTest(subject=subject):
                result = run(["session", "run", "b.json", "--writer", "simulated", "--subject", subject,
                              "--out", "study"], self.dir)
                self.assertEqual(len(error_lines(result)), 1, text(result))
                self.assertIn(subject, error_lines(result)[0])
                self.assertFalse((self.dir / "study").exists())
                self.assertEqual(result.returncode, 2, text(result))

    @heavy
    def test_sigterm_at_random_moments_then_resume_completes_the_plan(self):
        rng = random.Random(12)
        for attempt in range(1):
            out = self.dir / f"study{attempt}"
            process = subprocess.Popen([CLI, "session", "run", "long.json", "--writer", "simulated", "--subjects", "1",
                                        "--out", out.name], cwd=self.dir, stdout=subprocess.PIPE,
                                       stderr=subprocess.PIPE, env=ENV)
            time.sleep(rng.uniform(0.08, 0.35))
            process.send_signal(signal.SIGTERM)
            _, stderr = process.communicate(timeout=TIMEOUT_S)
            self.assertIn(process.returncode, (0, 143), stderr)
            if not out.exists():
                continue
            sessions = sessions_of(out)
            if not sessions:
                continue
            session = sessions[0]
            before = tree_digest(session / "trials")
            result = run(["session", "resume", session], self.dir)
            self.assertEqual(result.returncode, 0, text(result))
            saved = {p.name[: -len(".json")] for p in (session / "trials").glob("*.json")}
            self.assertEqual(saved, set(planned_stems(session)))
            after = tree_digest(session / "trials")
            for name, digest in before.items():
                self.assertEqual(after.get(name), digest, f"{name} changed by the resume")
            for attempt_record in (session / "trials" / "attempts").glob("*.json"):
                self.assertIn("SIGTERM", json.loads(attempt_record.read_text("utf-8"))["abort_reason"])
            self.assertEqual(leftovers(out), [])

    @heavy
    def test_a_resume_killed_then_resumed_again_changes_no_saved_trial(self):
        session = self.complete()[0]
        unfinish(session, 1)
        before = tree_digest(session / "trials")
        process = subprocess.Popen([CLI, "session", "resume", str(session)], cwd=self.dir, stdout=subprocess.PIPE,
                                   stderr=subprocess.PIPE, env=ENV)
        time.sleep(0.15)
        process.kill()
        process.communicate(timeout=TIMEOUT_S)
        result = run(["session", "resume", session], self.dir)
        self.assertEqual(result.returncode, 0, text(result))
        after = tree_digest(session / "trials")
        for name, digest in before.items():
            self.assertEqual(after.get(name), digest)
        self.assertEqual({p.name[:-5] for p in (session / "trials").glob("*.json")}, set(planned_stems(session)))
        self.assertEqual(leftovers(self.dir / "study"), [])

    @heavy
    def test_two_resumes_raced_on_one_folder_save_each_trial_once(self):
        session = self.complete()[0]
        unfinish(session, 1)
        processes = [subprocess.Popen([CLI, "session", "resume", str(session)], cwd=self.dir, stdout=subprocess.PIPE,
                                      stderr=subprocess.PIPE, env=ENV) for _ in range(2)]
        results = [(p, *p.communicate(timeout=TIMEOUT_S)) for p in processes]
        for process, _, stderr in results:
            self.assertIn(process.returncode, (0, 1), stderr)
            if process.returncode == 1:
                lines = [line for line in stderr.decode().splitlines() if ": error: " in line]
                self.assertEqual(len(lines), 1, stderr)
        self.assertEqual({p.name[:-5] for p in (session / "trials").glob("*.json")}, set(planned_stems(session)))
        self.assertEqual(leftovers(self.dir / "study"), [])
        self.assertEqual(run(["report", "study", "--csv", "."], self.dir).returncode, 0)

    def test_resume_through_a_link_writes_only_in_the_study(self):
        session = self.complete()[0]
        unfinish(session, 2)
        elsewhere = self.dir / "elsewhere" / "deeper"
        elsewhere.mkdir(parents=True)
        (elsewhere / "link").symlink_to(session)
        result = run(["session", "resume", "elsewhere/deeper/link"], self.dir)
        self.assertEqual(result.returncode, 0, text(result))
        self.assertEqual(sorted(os.listdir(self.dir / "elsewhere")), ["deeper"])
        self.assertEqual(sorted(os.listdir(elsewhere)), ["link"])
        self.assertFalse((self.dir / ".calligraphy-run.lock").exists())
        self.assertEqual({p.name[:-5] for p in (session / "trials").glob("*.json")}, set(planned_stems(session)))
        # Every record names the session by its folder's name, not by the link's.
        named = {json.loads(p.read_text("utf-8"))["session"] for p in (session / "trials").glob("*.json")}
        self.assertEqual(named, {session.name})
        self.assertEqual(run(["report", "study", "--csv", "."], self.dir).returncode, 0)

    def test_resuming_a_hard_linked_copy_leaves_the_original_unchanged(self):
        # `cp -al` copies a study as hard links: the copy's files are the original's. Resuming the copy must
        # not write into the original (its log would tell of trials its trials/ does not hold).
        session = self.complete()[0]
        unfinish(session, 2)
        subprocess.run(["cp", "-al", "study", "copy"], cwd=self.dir, check=True)
        before = tree_digest(self.dir / "study")
        copy = self.dir / "copy" / session.relative_to(self.dir / "study")
        result = run(["session", "resume", copy], self.dir)
        self.assertIn(result.returncode, (0, 2), text(result))
        if result.returncode == 2:
            self.assertEqual(len(error_lines(result)), 1)
        self.assertEqual(tree_digest(self.dir / "study"), before)
        if result.returncode == 0:  # the copy's log is its own now and tells of the resume
            self.assertEqual((copy / "log.jsonl").stat().st_nlink, 1)
            self.assertIn(b"session_resumed", (copy / "log.jsonl").read_bytes())

    def test_a_renamed_session_folder_is_not_reported_under_two_ids(self):
        # The session id is the folder's name, and every record names its session. A folder renamed and then
        # resumed must not leave records naming two sessions that the tables report as one.
        session = self.complete()[0]
        unfinish(session, 2)
        renamed = session.with_name("renamed")
        session.rename(renamed)
        before = tree_digest(renamed)
        resumed = run(["session", "resume", renamed], self.dir)
        if resumed.returncode != 0:  # refused, as a session of another study is (status 1), nothing written
            self.assertEqual(resumed.returncode, 1, text(resumed))
            self.assertEqual(len(error_lines(resumed)), 1, text(resumed))
            self.assertIn("/session", error_lines(resumed)[0])
            self.assertEqual(tree_digest(renamed), before)
        report = run(["report", "study", "--csv", "."], self.dir)
        if report.returncode != 0:
            self.assertEqual(report.returncode, 1, text(report))
            self.assertEqual(len(error_lines(report)), 1, text(report))
            return
        records = {json.loads(p.read_text("utf-8"))["session"] for p in (renamed / "trials").glob("*.json")}
        table = {row["session"] for row in read_rows(self.dir / "trials.csv")}
        self.assertEqual(len(records), 1, records)
        self.assertEqual(table, records)

    def test_two_days_swapped_are_refused_by_the_next_run(self):
        first, second = self.complete("r.json")
        temporary = first.with_name("swap")
        first.rename(temporary)
        second.rename(first)
        temporary.rename(second)
        result = run(["session", "run", "r.json", "--writer", "simulated", "--subjects", "1", "--out", "study"],
                     self.dir)
        self.assertEqual(result.returncode, 1, text(result))
        lines = error_lines(result)
        self.assertEqual(len(lines), 1, text(result))
        self.assertIn("study/S01/", lines[0])

    def test_a_study_moved_resumes_where_it_now_is(self):
        session = self.complete()[0]
        unfinish(session, 3)
        (self.dir / "study").rename(self.dir / "moved")
        moved = self.dir / "moved" / session.relative_to(self.dir / "study")
        result = run(["session", "resume", moved], self.dir)
        self.assertEqual(result.returncode, 0, text(result))
        self.assertFalse((self.dir / "study").exists())
        self.assertEqual({p.name[:-5] for p in (moved / "trials").glob("*.json")}, set(planned_stems(moved)))

    def test_elapsed_seconds_at_and_past_the_documented_range(self):
        # docs/experiments.md: the manifest's reader takes a negative elapsed_s (a clock set back) within the
        # range the schema gives, [-1e15, 1e15] s; past it, and a number no double holds, are named. (The docs
        # said "any finite elapsed_s" when this case was written: -1e308 was refused.)
        second = self.complete("r.json")[1]
        manifest = second / "session.json"
        document = json.loads(manifest.read_text("utf-8"))
        for value, status in ((-1e15, 0), (1e15, 0), (-1.0000001e15, 1), (-1e308, 1), ("1e309", 1)):
            with self.subTest(value=value):
                document["previous_session"]["elapsed_s"] = 0.5
                body = json.dumps(document, ensure_ascii=False).replace('"elapsed_s": 0.5', f'"elapsed_s": {value}')
                manifest.write_text(body, encoding="utf-8")
                result = run(["report", "study", "--csv", "."], self.dir)
                self.assertEqual(result.returncode, status, text(result))
                if status:
                    self.assertEqual(len(error_lines(result)), 1)
                    self.assertIn("session.json: /previous_session/elapsed_s", error_lines(result)[0])

    def test_a_plan_entry_given_twice_or_out_of_order_is_refused_naming_it(self):
        session = self.complete()[0]
        unfinish(session, 2)
        manifest = session / "session.json"
        original = json.loads(manifest.read_text("utf-8"))
        edits = []
        doubled = json.loads(json.dumps(original))
        doubled["plan"][3] = doubled["plan"][2]
        edits.append(("doubled", doubled))
        swapped = json.loads(json.dumps(original))
        swapped["plan"][2], swapped["plan"][3] = swapped["plan"][3], swapped["plan"][2]
        edits.append(("swapped", swapped))
        for label, document in edits:
            with self.subTest(edit=label):
                manifest.write_text(json.dumps(document, ensure_ascii=False), encoding="utf-8")
                before = tree_digest(session)
                result = run(["session", "resume", session], self.dir)
                self.assertEqual(result.returncode, 2, text(result))
                self.assertIn("/plan/", error_lines(result)[0])
                self.assertEqual(tree_digest(session), before)
                report = run(["report", "study", "--csv", "."], self.dir)
                self.assertEqual(report.returncode, 1, text(report))
                self.assertIn("/plan/", error_lines(report)[0])

    def test_a_cohort_csv_aimed_at_its_protocol_by_name_or_by_link_is_refused(self):
        tables = self.dir / "tables"
        tables.mkdir()
        write_json(tables / "trials.csv", BETWEEN)
        write_json(tables / "strokes.csv", BETWEEN)
        (tables / "p.json").symlink_to("strokes.csv")
        before = tree_digest(tables)
        for protocol in ("tables/trials.csv", "tables/p.json"):
            with self.subTest(protocol=protocol):
                result = run(["session", "cohort", protocol, "--subjects", "1", "--csv", "tables", "--jobs", "1"],
                             self.dir)
                self.assertEqual(result.returncode, 2, text(result))
                self.assertIn("--csv", error_lines(result)[0])
                self.assertEqual(tree_digest(tables), before)
                self.assertEqual(leftovers(tables), [])


@unittest.skipUnless(CLI, "CALLIGRAPHY_CLI is not set")
class Reports(unittest.TestCase):
    """`report` given its tables in a session, links and copies in the study, another study's trial."""

    def setUp(self):
        self.dir = Path(tempfile.mkdtemp(prefix="round12f-report-"))
        write_json(self.dir / "b.json", BETWEEN)

    def tearDown(self):
        shutil.rmtree(self.dir, ignore_errors=True)

    def make(self, out, fresh=False):
        """The session of a complete study of one subject of b.json at `out`: a copy of the one run for every
        case or, `fresh`, a run of its own (a study of its own id)."""
        if not fresh:
            return Made.copy("b", BETWEEN, self.dir / out)[0]
        result = run(["session", "run", "b.json", "--writer", "simulated", "--subjects", "1", "--out", out], self.dir)
        self.assertEqual(result.returncode, 0, text(result))
        return sessions_of(self.dir / out)[0]

    def test_tables_written_into_a_sessions_own_folders_leave_it_readable(self):
        session = self.make("study")
        for tables in (session / "trials", session):
            with self.subTest(tables=tables.name):
                result = run(["report", "study", "--csv", tables], self.dir)
                self.assertEqual(result.returncode, 0, text(result))
                again = run(["report", "study", "--csv", "."], self.dir)
                self.assertEqual(again.returncode, 0, text(again))
                resumed = run(["session", "resume", session], self.dir)
                self.assertEqual(resumed.returncode, 0, text(resumed))
        rows = read_rows(self.dir / "trials.csv")
        self.assertEqual(len(rows), 3)

    def test_links_in_the_study_neither_loop_nor_count_a_session_twice(self):
        session = self.make("study")
        self.make("other", fresh=True)
        (self.dir / "study" / "S01" / "loop").symlink_to("..")
        (self.dir / "study" / "S09").symlink_to(self.dir / "other" / "S01")
        result = run(["report", "study", "--csv", "."], self.dir, timeout=30)
        # Neither taken nor skipped in silence (a subject lost): each link to session folders is named.
        self.assertEqual(result.returncode, 1, text(result))
        self.assertEqual(len(error_lines(result)), 1)
        self.assertIn("symbolic link", error_lines(result)[0])
        (self.dir / "study" / "S01" / "loop").unlink()
        result = run(["report", "study", "--csv", "."], self.dir, timeout=30)
        self.assertEqual(result.returncode, 1, text(result))
        self.assertIn("S09", error_lines(result)[0])
        (self.dir / "study" / "S09").unlink()
        (self.dir / "empty").mkdir()
        (self.dir / "study" / "notes").symlink_to(self.dir / "empty")
        result = run(["report", "study", "--csv", "."], self.dir, timeout=30)
        self.assertEqual(result.returncode, 0, text(result))
        self.assertEqual(len(read_rows(self.dir / "trials.csv")), 3, "a link to a folder of no session is skipped")
        # A copy of a session beside it is refused naming both (docs/experiments.md).
        shutil.copytree(session, session.with_name("copy"), symlinks=True)
        result = run(["report", "study", "--csv", "."], self.dir)
        self.assertEqual(result.returncode, 1, text(result))
        self.assertIn("copy", error_lines(result)[0])

    def test_a_trial_of_another_study_swapped_in_is_not_reported_as_this_ones(self):
        # Two studies of the same protocol and subject, one of skilled writers; their second trial's files
        # swapped. The tables must not report the skilled writer's trial as the novice subject's.
        both = [subprocess.Popen([CLI, "session", "run", "b.json", "--writer", "simulated", "--subjects", "1",
                                  "--out", out, *extra], cwd=self.dir, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                                 env=ENV) for out, extra in (("a", []), ("b", ["--writer-profile", "skilled"]))]
        for process in both:
            process.communicate(timeout=TIMEOUT_S)
            self.assertEqual(process.returncode, 0)
        mine, theirs = sessions_of(self.dir / "a")[0], sessions_of(self.dir / "b")[0]
        stem = planned_stems(mine)[1]
        for path in (theirs / "trials").glob(stem + ".*"):
            shutil.copy2(path, mine / "trials" / path.name)
        result = run(["report", "a", "--csv", "."], self.dir)
        if result.returncode != 0:
            self.assertEqual(result.returncode, 1, text(result))
            self.assertIn(stem, error_lines(result)[0])
            return
        record = json.loads((mine / "trials" / (stem + ".json")).read_text("utf-8"))
        rows = read_rows(self.dir / "trials.csv")
        self.assertEqual(rows[1]["writer_profile"], record["writer"]["profile"]["name"])


PYTHON_ENV = dict(ENV)


@needs_python
@unittest.skipUnless(CLI, "CALLIGRAPHY_CLI is not set")
class PythonStudy(unittest.TestCase):
    """calligraphy.study and calligraphy.study_report in this process, with an R that answers in Latin-1."""

    @classmethod
    def setUpClass(cls):
        cls.shared = Shared.make()
        cls.work = Path(tempfile.mkdtemp(prefix="round12f-python-"))
        cls.bin = cls.work / "bin"
        cls.bin.mkdir()
        rscript = cls.bin / "Rscript"
        # An R that answers every request with Latin-1 bytes (café, ÿþ, naïve) and ends.
        rscript.write_bytes(b"#!/bin/sh\nprintf 'caf\\351 \\377\\376 na\\357ve\\n'\nexit 0\n")
        rscript.chmod(0o755)
        cls.saved_path = os.environ.get("PATH", "")
        os.environ["PATH"] = f"{cls.bin}:/usr/bin:/bin"
        import calligraphy.study_report  # noqa: F401  (pandas, matplotlib: once for the class)
        cls.study = cg_study.load(str(cls.shared / "study"))

    @classmethod
    def tearDownClass(cls):
        os.environ["PATH"] = cls.saved_path
        shutil.rmtree(cls.work, ignore_errors=True)

    def test_an_r_answering_in_latin1_spoils_only_its_fits(self):
        import calligraphy.study_report as report
        out = self.work / "latin1"
        index = report.write_report(self.study, str(out), values=("mean_deviation_m",))
        self.assertTrue(Path(index).is_file())
        with open(out / "tables" / "questions.csv", encoding="utf-8") as stream:
            rows = list(csv.DictReader(stream))
        mixed = [row for row in rows if "| subject)" in row["model"]]  # lme4's models, not the ANCOVA
        self.assertTrue(mixed)
        for row in mixed:
            self.assertIn("not computed", row["note"])

    def test_keep_end_reasons_given_as_one_string_is_not_taken_letter_by_letter(self):
        import calligraphy.study_report as report
        out = self.work / "string"
        try:
            report.write_report(self.study, str(out), values=("mean_deviation_m",), keep_end_reasons="completed")
        except (TypeError, ValueError) as error:
            self.assertIn("keep_end_reasons", str(error))
            return
        except UnicodeDecodeError:  # the Latin-1 R of the case above; the exclusions are written before it
            pass
        with open(out / "tables" / "exclusions.csv", encoding="utf-8") as stream:
            rows = list(csv.DictReader(stream))
        self.assertGreater(sum(int(row["kept"]) for row in rows), 0, "every trial excluded")

    def test_an_unknown_ddf_is_refused_before_anything_is_written(self):
        import calligraphy.study_report as report
        out = self.work / "wald"
        for ddf in ("Wald", "satterthwaite", ""):
            with self.subTest(ddf=ddf), self.assertRaises(ValueError) as caught:
                report.write_report(self.study, str(out), values=("mean_deviation_m",), ddf=ddf)
            self.assertIn("write_report: ddf", str(caught.exception))
            self.assertFalse(out.exists(), "written before the argument was checked")

    def test_load_of_nothing_or_of_the_wrong_type_names_the_argument(self):
        empty = self.work / "empty"
        empty.mkdir(exist_ok=True)
        for value, kind in (([], ValueError), (None, TypeError), (12, TypeError), (3.5, TypeError)):
            with self.subTest(value=value):
                with self.assertRaises(kind) as caught:
                    cg_study.load(value)
                self.assertIn("paths", str(caught.exception))
        with self.assertRaises(cg.DataError) as caught:
            cg_study.load(str(empty))
        self.assertIn("empty", str(caught.exception))

    def test_reports_of_an_empty_study_or_wrong_arguments_name_them_and_write_nothing(self):
        import calligraphy.study_report as report
        empty = cg_study.Study(self.study.trials.iloc[0:0], self.study.strokes.iloc[0:0])
        for label, call, word in (
                ("empty", lambda out: report.write_report(empty, out), "no trials"),
                ("values", lambda out: report.write_report(self.study, out, values="mean_deviation_m"), "values"),
                ("missing", lambda out: report.write_report(self.study, out, values=("no_such_m",)), "no_such_m"),
                ("reference", lambda out: report.write_report(self.study, out, reference=float("nan")), "nan"),
                ("out", lambda out: report.write_report(self.study, ""), "out_dir")):
            with self.subTest(label=label):
                out = self.work / ("bad-" + label)
                with self.assertRaises((ValueError, TypeError, LookupError)) as caught:
                    call(str(out))
                self.assertIn(word, str(caught.exception))
                self.assertFalse(out.exists() and any(out.iterdir()), f"{label}: files written")

    def test_samples_of_a_row_label_past_the_table_is_a_key_error(self):
        with self.assertRaises(KeyError):
            self.study.samples(10 ** 6)
        with self.assertRaises((KeyError, TypeError)):
            self.study.samples(float("nan"))


@needs_python
@unittest.skipUnless(CLI, "CALLIGRAPHY_CLI is not set")
class StudyReportProcess(unittest.TestCase):
    """python3 -m calligraphy.study_report as a process: signals, a slow R, usage errors."""

    @classmethod
    def setUpClass(cls):
        cls.shared = Shared.make()
        cls.work = Path(tempfile.mkdtemp(prefix="round12f-process-"))
        cls.slow = cls.work / "slow"
        cls.slow.mkdir()
        rscript = cls.slow / "Rscript"
        rscript.write_text("#!/bin/sh\nexec sleep 300\n")  # an R that never answers
        rscript.chmod(0o755)

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.work, ignore_errors=True)

    def start(self, out, path, command=None):
        env = dict(ENV, PATH=f"{path}:/usr/bin:/bin")
        command = command or [sys.executable, "-m", "calligraphy.study_report", str(self.shared / "study"),
                              "--out", str(out)]
        process = subprocess.Popen(command, env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                                   start_new_session=True)
        self.addCleanup(reap_session, process.pid)
        deadline = time.monotonic() + TIMEOUT_S
        while True:  # until the R it started is there (the stand-in's `sleep`)
            self.r_pids = [pid for pid in set(process_group_members(process.pid) + descendants(process.pid))
                           if command_of(pid) == "sleep"]
            if self.r_pids:
                break
            if process.poll() is not None:
                self.fail("the report ended before it started R: " + process.stderr.read().decode())
            if time.monotonic() > deadline:
                process.kill()
                self.fail(f"no R was started within {TIMEOUT_S} s")
            time.sleep(0.05)
        self.addCleanup(lambda pids=self.r_pids: [os.kill(p, signal.SIGKILL) for p in pids if running(p)])
        return process

    def assert_no_r_left(self, process):
        """Neither the R found at the start nor anything else of the Python process's session runs."""
        deadline = time.monotonic() + 5
        while ((process_group_members(process.pid) or any(running(p) for p in self.r_pids))
               and time.monotonic() < deadline):
            time.sleep(0.05)
        self.assertEqual(process_group_members(process.pid), [], "a process outlived the Python process")
        self.assertEqual([p for p in self.r_pids if running(p)], [], "an R outlived the Python process")

    @heavy
    def test_sigkill_of_the_python_process_ends_its_r(self):
        # The first R of a fit (still loading its packages, which it never says it did), as every report starts it.
        fit = ("import pandas; from calligraphy import mixed_models; mixed_models.lmer(pandas.DataFrame("
               "{'y': [1.0, 2.0, 3.0], 'subject': ['a', 'b', 'c']}), 'y ~ 1 + (1 | subject)', {})")
        process = self.start(self.work / "killed", self.slow, [sys.executable, "-c", fit])
        process.kill()
        process.communicate(timeout=TIMEOUT_S)
        self.assert_no_r_left(process)

    @heavy
    def test_ctrl_c_while_r_is_slow_is_one_line_and_leaves_nothing(self):
        out = self.work / "interrupted"
        process = self.start(out, self.slow)
        process.send_signal(signal.SIGINT)
        _, stderr = process.communicate(timeout=TIMEOUT_S)
        self.assertIn(process.returncode, (130, -signal.SIGINT), stderr)
        self.assertNotIn(b"Traceback", stderr)
        self.assertLessEqual(len(stderr.decode().strip().splitlines()), 1, stderr)
        self.assert_no_r_left(process)
        self.assertEqual(leftovers(out) if out.exists() else [], [])

    def test_usage_errors_name_the_option_before_any_work(self):
        env = dict(ENV, PATH=f"{self.slow}:/usr/bin:/bin")
        for extra, option in ((["--ddf", "Wald"], "--ddf"), (["--analyse=,"], "--analyse")):
            with self.subTest(extra=extra):
                arguments = [sys.executable, "-m", "calligraphy.study_report", str(self.shared / "study")]
                if extra[0] != "--out=":
                    arguments += ["--out", str(self.work / "usage")]
                result = subprocess.run(arguments + extra, env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                                        timeout=TIMEOUT_S, start_new_session=True)
                self.assertEqual(result.returncode, 2, result.stderr)
                self.assertNotIn(b"Traceback", result.stderr)
                self.assertIn(option.encode(), result.stderr)
                self.assertFalse((self.work / "usage").exists())


@needs_python
@unittest.skipUnless(shutil.which("Rscript"), "R is not installed")
class RealR(unittest.TestCase):
    """calligraphy.mixed_models.lmer with R itself (in this process): names and levels R must quote."""

    @heavy
    def test_factor_names_and_levels_with_spaces_breaks_quotes_and_unicode(self):
        import numpy as np
        import pandas as pd
        from calligraphy import mixed_models
        rng = np.random.default_rng(12)
        levels = ["ctl", "a\nb", "é\"`'\\", "NA"]
        rows = [{"subject": f"s{s}", "f": c, "y": rng.normal() + (1.0 if c == "NA" else 0.0)}
                for s in range(8) for c in levels for _ in range(3)]
        frame = pd.DataFrame(rows)
        fits = []
        # A name with a space, and one with a line break and CJK characters: R writes both in backquotes.
        for name in ("con dition", "条件\nf"):
            quoted = "`" + name.replace("\\", "\\\\").replace("`", "\\`") + "`"
            fit = mixed_models.lmer(frame.rename(columns={"f": name}), f"y ~ {quoted} + (1 | subject)",
                                    {name: levels})
            fits.append((name, fit.fixed))
        for name, fixed in fits:
            with self.subTest(name=name):
                self.assertEqual(fixed["level"].tolist()[1:], ["a\nb", "é\"`'\\", "NA"])
                self.assertEqual(fixed["factor"].tolist()[1:], [name] * 3)
                # The same data under another name: the same estimates.
                for a, b in zip(fixed["estimate"], fits[0][1]["estimate"]):
                    self.assertAlmostEqual(a, b, places=9)


def tearDownModule():
    Shared.remove()
    Made.remove()


if __name__ == "__main__":
    if SANITIZED:
        # Four cases, under ~8 s with the sanitizers: a protocol each way and a session edit. Not the plan of a
        # million trials: it runs under an address-space limit, and ASan reserves terabytes of shadow memory.
        suite = unittest.TestSuite()
        for name in ("test_conditions_and_sets_listed_twice_are_refused_naming_the_second",
                     "test_mislabelled_designs_are_refused_naming_the_assignment"):
            suite.addTest(Protocols(name))
        for name in ("test_a_cohort_csv_aimed_at_its_protocol_by_name_or_by_link_is_refused",
                     "test_resume_through_a_link_writes_only_in_the_study"):
            suite.addTest(Sessions(name))
        sys.exit(0 if unittest.TextTestRunner(verbosity=2).run(suite).wasSuccessful() else 1)
    unittest.main(verbosity=2)
