#!/usr/bin/env python3
"""Round 28E: a lab's own study protocol, written by hand, and its sessions over days. From the docs alone
(docs/experiments.md "Protocol files", "Phases", "Sessions", "Tidy tables", "A cohort in memory";
docs/learning-study.md; docs/cli.md "Conventions", "Exit statuses", "Pen traces: format and limits" (a key
given twice), "session run | resume", "session plan", "session cohort", "report"; docs/metrics.md).

The protocol is the lab's: two conditions (vision only and the fixed fixture) between subjects, a pre-test,
training and post-test on day 1, retention and transfer on day 2, on 十 and 二 only. Every field is pushed to
its documented bounds and just past them, given the wrong JSON type, null, left out, given twice, a number as
text, 1e400 or -0, a huge list, a name with path separators or odd Unicode: each refusal is exit 2, one line
naming the protocol file and the JSON pointer, and nothing is made under --out (or changed in a study there).
The sessions are then attacked: the protocol edited between the days, a finished series run again, a day's
folder removed and run again, a session folder copied, renamed, given to another subject or another study, a
record copied over another's or removed, a one-session protocol run twice, and runs stopped by SIGTERM and
SIGKILL mid-session (real-time pacing, 0.5 s trials) and resumed: nothing lost, nothing doubled in the tables,
trials numbered 1..n in each session. `session cohort` of the same protocol must give the folders' rows.

CALLIGRAPHY_CLI names the program. CALLIGRAPHY_SANITIZED=1 takes five cases.
"""
import copy
import csv
import hashlib
import json
import os
import shutil
import signal
import subprocess
import tempfile
import time
import unittest
from pathlib import Path

from outsider import CLI, ENV, OneErrorLine, error_lines, run, run_ok, sanitized_subset

load_tests = sanitized_subset({"test_unknown_key_is_refused_naming_its_pointer",
                               "test_key_given_twice_is_refused_naming_its_pointer",
                               "test_number_beyond_a_double_is_refused_as_not_finite",
                               "test_plan_over_a_million_trials_is_refused_naming_its_size",
                               "test_one_session_protocol_run_twice_is_refused_naming_new_subjects"})

# The lab's protocol: two groups (vision only, the fixture), two days.
BASE = {
    "format": "calligraphy-study-protocol", "version": 1, "name": "lab28e",
    "description": "our lab: two groups over two days",
    "conditions": [{"name": "sight", "mode": "vision"},
                   {"name": "guide", "mode": "haptic", "guidance_stiffness_n_per_m": 300}],
    "phases": [
        {"phase": "pre-test", "condition": "sight", "characters": ["十"]},
        {"phase": "training", "conditions": ["sight", "guide"], "assignment": "between-subjects",
         "characters": ["十"], "repetitions": 2},
        {"phase": "post-test", "condition": "sight", "characters": ["十"], "delay_s": 60},
        {"phase": "retention", "condition": "sight", "characters": ["十"], "session": 2, "delay_s": 86400},
        {"phase": "transfer", "condition": "sight", "characters": ["二"], "session": 2}],
    "trial": {"max_duration_s": 12}}
DAY1 = ["pre-test", "training", "training", "post-test"]
DAY2 = ["retention", "transfer"]
# For the stopped runs: one condition, 0.5 s trials (at real-time pacing a trial lasts 0.5 s of wall time).
KILL = {
    "name": "lab28e-kill", "conditions": [{"name": "sight", "mode": "vision"}],
    "phases": [
        {"phase": "pre-test", "condition": "sight", "characters": ["十"]},
        {"phase": "training", "condition": "sight", "characters": ["十"]},
        {"phase": "retention", "condition": "sight", "characters": ["十"], "session": 2, "delay_s": 86400}],
    "trial": {"max_duration_s": 0.5}}
ONE = {
    "name": "lab28e-one", "conditions": [{"name": "sight", "mode": "vision"}, {"name": "guide", "mode": "haptic"}],
    "phases": [{"phase": "test", "conditions": ["sight", "guide"], "assignment": "between-subjects",
                "characters": ["十"]}],
    "trial": {"max_duration_s": 12}}
# Tables' columns that name where a trial is kept, not what it was.
SKILLED = ["--writer-profile", "skilled"]   # quicker trials than the default novice
PLACE = {"session", "start_utc", "trace_file", "trace_sha256"}
# The refusals' protocol: the lab's with 2 s trials, so that a protocol wrongly taken runs cheaply.
CHEAP = json.loads(json.dumps(BASE))
CHEAP["trial"]["max_duration_s"] = 2
TWENTY = ["十", "一", "二", "三", "人", "口", "大", "木", "山", "中", "日", "月", "水", "火", "土", "王", "工",
          "上", "下", "小"]


def sha256(path):
    return hashlib.sha256(Path(path).read_bytes()).hexdigest()


def snapshot(root):
    """Every file and folder under `root` (hidden ones too): a file by its inode, size and time of change, and
    a file under 64 KiB (records, manifests, logs) by its bytes' SHA-256 too; the run locks, whose content
    names the run holding them, left out."""
    found = {}
    for folder, dirs, files in os.walk(root):
        for name in dirs + files:
            path = Path(folder) / name
            rel = str(path.relative_to(root))
            if path.is_file() and not name.endswith(".lock"):
                st = path.stat()
                found[rel] = (st.st_ino, st.st_size, st.st_mtime_ns, sha256(path) if st.st_size < 65536 else "")
            elif path.is_dir():
                found[rel + "/"] = "dir"
    return found


def table(path):
    with open(path, encoding="utf-8", newline="") as f:
        return list(csv.DictReader(f))


def sessions(study, subject):
    """The subject's session folders, by their session number."""
    found = []
    for d in Path(study, subject).iterdir():
        if d.is_dir() and not d.name.startswith(".") and (d / "session.json").exists():
            found.append((json.loads((d / "session.json").read_text(encoding="utf-8")).get("session_number", 1), d))
    return [d for _, d in sorted(found)]


def log_events(session, whole_only=False):
    """The session's log; `whole_only`: a line still being written (not JSON yet) passed over."""
    events = []
    for line in (Path(session) / "log.jsonl").read_text(encoding="utf-8", errors="replace").splitlines():
        try:
            events.append(json.loads(line))
        except ValueError:
            if not whole_only:
                raise
    return events


def setp(obj, pointer, value):
    """A deep copy of `obj` with the value at the JSON pointer set (or removed, for value `DELETE`)."""
    obj = copy.deepcopy(obj)
    parts = [int(p) if p.isdigit() else p for p in pointer.strip("/").split("/")]
    here = obj
    for p in parts[:-1]:
        here = here[p]
    if value is DELETE:
        del here[parts[-1]]
    else:
        here[parts[-1]] = value
    return obj


DELETE = object()


def text_with(obj, pointer, raw):
    """The protocol's JSON text with the value at `pointer` written as the raw text `raw` (1e400, -0, ...)."""
    return json.dumps(setp(obj, pointer, "@@RAW@@"), ensure_ascii=False).replace('"@@RAW@@"', raw)


class Tmp(unittest.TestCase, OneErrorLine):
    @classmethod
    def setUpClass(cls):
        if not CLI:
            raise unittest.SkipTest("CALLIGRAPHY_CLI names the program")
        cls.tmp = Path(tempfile.mkdtemp(prefix="round28e-"))

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.tmp, ignore_errors=True)

    def fresh(self):
        return Path(tempfile.mkdtemp(dir=self.tmp))

    def assertUnchanged(self, now, before):
        changed = sorted(k for k in set(now) | set(before) if now.get(k) != before.get(k))
        self.assertEqual(changed, [], "files made, changed or removed")

    def write(self, d, content, name="p.json"):
        path = Path(d) / name
        if isinstance(content, bytes):
            path.write_bytes(content)
        else:
            path.write_text(content if isinstance(content, str) else json.dumps(content, ensure_ascii=False),
                            encoding="utf-8")
        return path


class ProtocolByHand(Tmp):
    """Each refusal: `session run` exits 2 with one line `p.json: /pointer: ...`; no --out folder is made."""

    def refused(self, content, pointer=None, *needles, status=2, exact=True, extra=()):
        d = self.fresh()
        self.write(d, content)
        result = run(["session", "run", "p.json", "--subjects", "1", "--out", "out", *extra], d)
        wanted = list(needles) + ["p.json"]
        if pointer is not None:
            wanted.append(f"p.json: {pointer}:" if exact else f"p.json: {pointer}")
        line = self.assert_one_error(result, status, *wanted)
        self.assertFalse((d / "out").exists(), "a refused protocol made --out")
        self.assertEqual(sorted(os.listdir(d)), ["p.json"])
        return line

    def planned(self, content, subjects=2):
        d = self.fresh()
        self.write(d, content)
        result = run_ok(["session", "plan", "p.json", "--subjects", str(subjects), "--json"], d)
        return json.loads(result.stdout)

    def test_the_lab_protocol_plans_two_days_by_group(self):
        plan = self.planned(BASE)
        self.assertEqual(plan["sessions"], 2)
        self.assertEqual(plan["protocol_sha256"], hashlib.sha256(json.dumps(BASE, ensure_ascii=False)
                                                                 .encode()).hexdigest())
        self.assertEqual([s["group"] for s in plan["subjects"]], ["sight", "guide"])
        for s in plan["subjects"]:
            self.assertEqual([x["trials"] for x in s["sessions"]], [4, 2])

    # ---- keys ------------------------------------------------------------------------------------------
    def test_unknown_key_is_refused_naming_its_pointer(self):
        for pointer in ("/colour", "/conditions/1/stifness"):
            with self.subTest(pointer=pointer):
                self.refused(setp(CHEAP, pointer, 3), pointer)

    def test_null_is_refused_naming_its_pointer(self):
        for pointer in ("/description", "/phases/2/delay_s", "/phases/1/assignment", "/trial/max_duration_s"):
            with self.subTest(pointer=pointer):
                self.refused(setp(CHEAP, pointer, None), pointer)

    def test_key_given_twice_is_refused_naming_its_pointer(self):
        text = json.dumps(CHEAP, ensure_ascii=False)
        self.refused(text.replace('"name": "lab28e"', '"name": "lab28e", "name": "lab28f"', 1), "/name")
        self.refused(text.replace('"session": 2', '"session": 2, "session": 2', 1), "/phases/3/session")

    def test_number_given_as_text_is_refused_naming_its_pointer(self):
        for pointer, value in (("/phases/1/repetitions", "2"), ("/phases/3/delay_s", "86400")):
            with self.subTest(pointer=pointer):
                self.refused(setp(CHEAP, pointer, value), pointer)

    def test_number_beyond_a_double_is_refused_as_not_finite(self):
        self.refused(text_with(CHEAP, "/trial/max_duration_s", "1e400"), "/trial/max_duration_s",
                     "not a finite number")
        self.refused(text_with(CHEAP, "/phases/3/delay_s", "-1e400"), "/phases/3/delay_s", "not a finite number")

    def test_fraction_where_a_whole_number_is_due_is_refused(self):
        self.refused(setp(CHEAP, "/phases/3/session", 1.5), "/phases/3/session")

    def test_minus_zero_is_zero(self):
        # -0 s of delay is 0 s, inside [0, 366 days]; -0 repetitions is 0, outside 1-1000.
        plan = self.planned(text_with(CHEAP, "/phases/2/delay_s", "-0"))
        self.assertEqual([x["trials"] for x in plan["subjects"][0]["sessions"]], [4, 2])
        self.refused(text_with(CHEAP, "/phases/1/repetitions", "-0"), "/phases/1/repetitions")

    def test_missing_required_key_is_refused_naming_it(self):
        self.refused(setp(CHEAP, "/name", DELETE), "/name")
        self.refused(setp(CHEAP, "/conditions/1/mode", DELETE), "/conditions/1", exact=False)

    def test_wrong_container_type_is_refused_naming_its_pointer(self):
        for pointer, value in (("/conditions", {}), ("/phases/0/characters", "十")):
            with self.subTest(pointer=pointer):
                self.refused(setp(CHEAP, pointer, value), pointer)

    def test_format_and_version_other_than_documented_are_refused(self):
        self.refused(setp(CHEAP, "/format", "calligraphy-study-protocl"), "/format")
        self.refused(setp(CHEAP, "/version", 2), "/version")

    def test_malformed_json_is_refused_naming_the_file(self):
        text = json.dumps(CHEAP, ensure_ascii=False)
        self.refused(text[:text.index('"conditions"')], None, "not valid JSON at byte")
        self.refused(json.dumps([CHEAP], ensure_ascii=False))

    def test_byte_order_mark_is_skipped(self):
        plan = self.planned(b"\xef\xbb\xbf" + json.dumps(CHEAP, ensure_ascii=False).encode())
        self.assertEqual(plan["protocol"], "lab28e")

    def test_protocol_over_a_mebibyte_is_refused_before_it_is_read(self):
        self.refused(setp(CHEAP, "/description", "x" * (1 << 20)), None, status=1)

    # ---- names -----------------------------------------------------------------------------------------
    def test_name_at_its_bounds_and_alphabet(self):
        self.assertEqual(self.planned(setp(CHEAP, "/name", "L" * 64), 1)["protocol"], "L" * 64)
        for name in ("L" * 65, "lab/28e", "lab28e\u202e"):
            with self.subTest(name=name):
                self.refused(setp(CHEAP, "/name", name), "/name")

    def test_condition_name_with_path_separator_or_odd_unicode_is_refused(self):
        text = json.dumps(CHEAP, ensure_ascii=False)
        for name in ("../up", "視覚"):
            with self.subTest(name=name):
                self.refused(text.replace('"sight"', json.dumps(name)), "/conditions/0/name")

    def test_subject_id_with_path_separator_or_odd_unicode_is_a_usage_error(self):
        d = self.fresh()
        self.write(d, CHEAP)
        for subject in ("../S01", "\uff3301"):
            with self.subTest(subject=subject):
                result = run(["session", "run", "p.json", "--subject", subject, "--out", "out"], d)
                self.assert_one_error(result, 2, "--subject")
                self.assertFalse((d / "out").exists())

    # ---- bounds ----------------------------------------------------------------------------------------
    def test_repetitions_at_their_bounds(self):
        plan = self.planned(setp(CHEAP, "/phases/1/repetitions", 1000), 1)
        self.assertEqual(plan["subjects"][0]["sessions"][0]["trials"], 1002)
        for value in (1001, 0):
            with self.subTest(value=value):
                self.refused(setp(CHEAP, "/phases/1/repetitions", value), "/phases/1/repetitions")

    def test_condition_count_at_its_bounds(self):
        def with_conditions(n):
            names = [f"c{i:02d}" for i in range(1, n + 1)]
            return {"name": "many", "conditions": [{"name": c, "mode": "vision"} for c in names],
                    "phases": [{"phase": "pre-test", "condition": "c01", "characters": ["十"]},
                               {"phase": "training", "conditions": names, "characters": ["十"]}],
                    "trial": {"max_duration_s": 2}}
        self.assertEqual(self.planned(with_conditions(26), 1)["subjects"][0]["sessions"][0]["trials"], 27)
        self.refused(with_conditions(27), "/conditions")

    def test_phase_count_at_its_bounds(self):
        def with_training(n):
            phases = [{"phase": "pre-test", "condition": "sight", "characters": ["十"]}]
            phases += [{"phase": "training", "condition": "sight", "characters": [c]} for c in TWENTY[:n]]
            phases.append({"phase": "post-test", "condition": "sight", "characters": ["十"]})
            return dict(CHEAP, conditions=CHEAP["conditions"][:1], phases=phases)
        plan = self.planned(with_training(18), 1)
        self.assertEqual(plan["subjects"][0]["sessions"][0]["trials"], 20)
        self.refused(with_training(19), "/phases")

    def test_delay_at_its_bounds(self):
        days366 = 366 * 86400
        plan = self.planned(setp(CHEAP, "/phases/3/delay_s", days366), 1)
        self.assertEqual(plan["subjects"][0]["sessions"][1]["delay_s"], days366)
        self.refused(setp(CHEAP, "/phases/3/delay_s", days366 + 0.5), "/phases/3/delay_s")

    def test_trial_time_and_rate_at_their_bounds(self):
        at_100 = setp(setp(CHEAP, "/trial/max_duration_s", 86400), "/trial/rate_hz", 100)
        self.assertEqual(self.planned(at_100, 1)["trial_max_duration_s"], 86400)
        for pointer, value in (("/trial/max_duration_s", 0), ("/trial/rate_hz", 99.99)):
            with self.subTest(pointer=pointer, value=value):
                self.refused(setp(CHEAP, pointer, value), pointer)

    def test_ticks_over_ten_million_are_refused_naming_time_and_rate(self):
        self.refused(setp(CHEAP, "/trial/max_duration_s", 86400), None, "/trial/max_duration_s", "/trial/rate_hz")

    def test_seed_at_its_bounds(self):
        with_random = dict(CHEAP, order={"conditions": "random", "seed": 0})
        self.planned(text_with(with_random, "/order/seed", "18446744073709551615"), 1)
        for raw in ("18446744073709551616", "-1"):
            with self.subTest(seed=raw):
                self.refused(text_with(with_random, "/order/seed", raw), "/order/seed")

    def test_guidance_values_out_of_range_are_refused_naming_their_pointer(self):
        self.refused(setp(CHEAP, "/conditions/1/guidance_stiffness_n_per_m", -1),
                     "/conditions/1/guidance_stiffness_n_per_m")
        fading = setp(CHEAP, "/conditions/1", {"name": "guide", "mode": "fading", "parameters": {"start_gain": 1.5}})
        self.refused(fading, "/conditions/1/parameters/start_gain")

    # ---- the design ------------------------------------------------------------------------------------
    def test_session_numbers_that_skip_or_do_not_start_at_one_are_refused(self):
        self.refused(setp(CHEAP, "/phases/3/session", 3), "/phases/3", exact=False)
        self.refused(setp(CHEAP, "/phases/0/session", 2), "/phases/0", exact=False)

    def test_retention_without_delay_or_on_an_untrained_character_is_refused(self):
        self.refused(setp(CHEAP, "/phases/3/delay_s", DELETE), "/phases/3", exact=False)
        self.refused(setp(CHEAP, "/phases/3/characters", ["二"]), "/phases/3", exact=False)

    def test_transfer_of_a_trained_character_is_refused(self):
        self.refused(setp(CHEAP, "/phases/4/characters", ["十"]), "/phases/4", exact=False)

    def test_between_subjects_phase_of_one_condition_is_refused(self):
        self.refused(setp(CHEAP, "/phases/1/conditions", ["guide"]), "/phases/1", exact=False)

    def test_pre_test_after_training_is_refused(self):
        protocol = copy.deepcopy(CHEAP)
        protocol["phases"][0], protocol["phases"][1] = protocol["phases"][1], protocol["phases"][0]
        self.refused(protocol, "/phases/1", exact=False)

    def test_character_twice_in_a_phase_is_refused_naming_the_second(self):
        self.refused(setp(CHEAP, "/phases/0/characters", ["十", "十"]), "/phases/0/characters/1")

    def test_characters_the_library_lacks_are_named_with_their_code_point(self):
        self.refused(setp(CHEAP, "/phases/4/characters", ["あ"]), "/phases/4/characters/0", "U+3042")
        # The Kangxi radical that looks like 十 is a character of its own.
        self.refused(setp(CHEAP, "/phases/4/characters", ["\u2f17"]), "/phases/4/characters/0", "U+2F17")

    def test_plan_over_a_million_trials_is_refused_naming_its_size(self):
        names = [f"c{i:02d}" for i in range(1, 27)]
        strings = [a + b + c for a in TWENTY[:10] for b in TWENTY[:10] for c in TWENTY[:10]]
        huge = {"name": "huge", "conditions": [{"name": c, "mode": "vision"} for c in names],
                "test": {"characters": strings, "conditions": names, "repetitions": 1000}}
        self.refused(huge, "/test", "26,000,000")
        just_over = dict(huge, conditions=huge["conditions"][:1],
                         test={"characters": strings, "conditions": ["c01"], "repetitions": 1000},
                         practice={"characters": ["十"], "condition": "c01", "repetitions": 1})
        self.refused(just_over, None, "1,000,001")


class TwoDays(Tmp):
    """The lab's protocol run for two simulated subjects, both days, once; the cases work on copies."""

    @classmethod
    def setUpClass(cls):
        super().setUpClass()
        d = cls.tmp
        (d / "p.json").write_text(json.dumps(BASE, ensure_ascii=False), encoding="utf-8")
        run_ok(["session", "run", "p.json", "--subjects", "2", *SKILLED, "--out", "study"], d)
        (d / "tables").mkdir()
        run_ok(["report", "study", "--csv", "tables"], d)
        cls.trials = table(d / "tables" / "trials.csv")
        cls.strokes = table(d / "tables" / "strokes.csv")
        cls.before = snapshot(d / "study")

    def copy_study(self, linked=False):
        """A copy of the study; `linked`: its files hard links of the original's (cp -l), for cases that only
        read, rename, remove or add files (a file to be replaced is unlinked first)."""
        target = self.fresh() / "study"
        shutil.copytree(self.tmp / "study", target, symlinks=True,
                        copy_function=os.link if linked else shutil.copyfile)
        return target

    def report(self, study, ok=True):
        tables = self.fresh()
        result = run(["report", str(study), "--csv", str(tables)], self.tmp)
        if ok:
            self.assertEqual(result.returncode, 0, result.stderr.decode("utf-8", "replace"))
            return table(tables / "trials.csv"), table(tables / "strokes.csv")
        self.assertEqual(os.listdir(tables), [], "a refused report wrote tables")
        return result

    def test_day_two_follows_day_one_by_its_folder_and_sha256(self):
        study = self.tmp / "study"
        identity = json.loads((study / ".calligraphy-study.json").read_text(encoding="utf-8"))
        for subject, group in (("S01", "sight"), ("S02", "guide")):
            day1, day2 = sessions(study, subject)
            first = json.loads((day1 / "session.json").read_text(encoding="utf-8"))
            second = json.loads((day2 / "session.json").read_text(encoding="utf-8"))
            link = second["previous_session"]
            self.assertEqual(link["session_id"], day1.name)
            self.assertEqual(link["session_sha256"], sha256(day1 / "session.json"))
            self.assertEqual(link["delay"], "simulated")
            self.assertEqual(link["delay_s"], 86400)
            self.assertEqual((first.get("session_number", 1), second["session_number"]), (1, 2))
            self.assertEqual((first["group"], second["group"]), (group, group))
            self.assertEqual(first["study_id"], identity["study_id"])
            self.assertEqual(second["study_id"], identity["study_id"])
            self.assertEqual(first["protocol"]["sha256"], sha256(self.tmp / "p.json"))
            self.assertEqual([p["phase"] for p in first["plan"]], DAY1)
            self.assertEqual([p["phase"] for p in second["plan"]], DAY2)
            ended = [e for e in log_events(day1) if e["event"] == "trial_saved"]
            self.assertEqual(link["ended_utc"][:19], max(
                json.loads((day1 / "trials" / f"{e['file']}.json").read_text(encoding="utf-8"))["end_time_utc"]
                for e in ended)[:19])

    def test_tables_hold_each_planned_trial_once_numbered_from_one(self):
        self.assertEqual(len(self.trials), 12)
        keys = [(r["session"], r["trial"]) for r in self.trials]
        self.assertEqual(len(keys), len(set(keys)), "a trial twice in trials.csv")
        for subject, group in (("S01", "sight"), ("S02", "guide")):
            for number, (folder, phases) in enumerate(zip(sessions(self.tmp / "study", subject), (DAY1, DAY2)), 1):
                rows = [r for r in self.trials if r["session"] == folder.name]
                self.assertEqual([int(r["trial"]) for r in rows], list(range(1, len(phases) + 1)))
                self.assertEqual([r["phase"] for r in rows], phases)
                self.assertEqual({r["session_number"] for r in rows}, {str(number)})
                self.assertEqual({r["group"] for r in rows}, {group})
                plan = json.loads((folder / "session.json").read_text(encoding="utf-8"))["plan"]
                for row, planned in zip(rows, plan):
                    self.assertEqual(row["condition"], planned["condition"])
                    self.assertEqual(row["characters"], planned["characters"])
                    record = json.loads((folder / "trials" / f"{planned['file']}.json").read_text(encoding="utf-8"))
                    self.assertEqual(float(row["mean_deviation_m"]), record["mean_deviation_m"])
                    self.assertEqual(row["trace_sha256"], sha256(self.tmp / row["trace_file"]))
                    self.assertEqual(row["trace_sha256"], record["files"]["trace_sha256"])
            training = [r for r in self.trials if r["subject"] == subject and r["phase"] == "training"]
            self.assertEqual([(r["condition"], r["mode"], r["repetition"]) for r in training],
                             [(group, "vision" if group == "sight" else "haptic", "1"),
                              (group, "vision" if group == "sight" else "haptic", "2")])
        # One strokes row per reference stroke: 十 and 二 have two each.
        self.assertEqual(len(self.strokes), 2 * len(self.trials))

    def test_cohort_in_memory_gives_the_folders_rows(self):
        d = self.fresh()
        run_ok(["session", "cohort", str(self.tmp / "p.json"), "--subjects", "2", *SKILLED, "--jobs", "1",
                "--csv", str(d)], self.tmp)
        cohort = table(d / "trials.csv")
        key = lambda r: (r["subject"], int(r["session_number"]), int(r["trial"]))  # noqa: E731
        self.assertEqual(len(cohort), len(self.trials))
        for ours, theirs in zip(sorted(self.trials, key=key), sorted(cohort, key=key)):
            self.assertEqual(theirs["session"], f"lab28e-{ours['subject']}-s{ours['session_number']}")
            self.assertEqual(theirs["start_utc"], "")
            self.assertEqual(theirs["trace_file"], "")
            self.assertEqual({k: v for k, v in ours.items() if k not in PLACE},
                             {k: v for k, v in theirs.items() if k not in PLACE})
        self.assertEqual(len(table(d / "strokes.csv")), len(self.strokes))

    def test_running_a_finished_series_again_changes_nothing(self):
        result = run_ok(["session", "run", "p.json", "--subjects", "2", *SKILLED, "--out", "study"], self.tmp)
        self.assertIn("done", result.stdout.decode("utf-8"))
        self.assertUnchanged(snapshot(self.tmp / "study"), self.before)

    def test_protocol_edited_between_days_is_refused_for_any_subject(self):
        original = (self.tmp / "p.json").read_bytes()
        edits = {"description": json.dumps(setp(BASE, "/description", "edited on day 2"),
                                           ensure_ascii=False).encode(),
                 "a trailing newline": original + b"\n"}
        for (what, content), subjects in ((list(edits.items())[0], ["--subjects", "2"]),
                                          (list(edits.items())[1], ["--subject", "T", "--subjects", "1"]),
                                          (list(edits.items())[0], ["--subject", "S01"])):
                with self.subTest(edit=what, subjects=subjects):
                    (self.tmp / "p-edited.json").write_bytes(content)
                    result = run(["session", "run", "p-edited.json", *subjects, *SKILLED, "--out", "study"],
                                 self.tmp)
                    self.assert_one_error(result, 1, "p-edited.json", "lab28e-S0",
                                          hashlib.sha256(content).hexdigest()[:12], sha256(self.tmp / "p.json")[:12])
                    self.assertUnchanged(snapshot(self.tmp / "study"), self.before)

    def test_day_two_run_again_after_its_folder_is_removed_follows_day_one(self):
        study = self.copy_study()
        day1, day2 = sessions(study, "S01")
        shutil.rmtree(day2)
        untouched = {k: v for k, v in snapshot(study).items()}
        # The protocol's same bytes under another file name: the same design (the same SHA-256).
        renamed = study.parent / "renamed.json"
        shutil.copyfile(self.tmp / "p.json", renamed)
        run_ok(["session", "run", str(renamed), "--subject", "S01", *SKILLED, "--out", str(study)], self.tmp)
        now = snapshot(study)
        self.assertEqual({k: v for k, v in now.items() if k in untouched}, untouched, "day 1 or S02 changed")
        again = sessions(study, "S01")
        self.assertEqual(len(again), 2)
        self.assertEqual(again[0], day1)
        link = json.loads((again[1] / "session.json").read_text(encoding="utf-8"))["previous_session"]
        self.assertEqual(link["session_id"], day1.name)
        self.assertEqual(link["session_sha256"], sha256(day1 / "session.json"))
        trials, _ = self.report(study)
        self.assertEqual(len(trials), 12)
        rerun = [r for r in trials if r["session"] == again[1].name]
        first = [r for r in self.trials if r["session"] == day2.name]
        self.assertEqual([r["trial"] for r in rerun], ["1", "2"])
        # S01 writes the same in every run: its day 2 again is its day 2.
        self.assertEqual([{k: v for k, v in r.items() if k not in PLACE} for r in rerun],
                         [{k: v for k, v in r.items() if k not in PLACE} for r in first])

    def test_study_copied_whole_gives_the_same_tables_but_trace_file(self):
        study = self.copy_study(linked=True)
        trials, strokes = self.report(study)
        self.assertEqual(len(trials), len(self.trials))
        for ours, theirs in zip(self.trials, trials):
            self.assertEqual({k: v for k, v in ours.items() if k != "trace_file"},
                             {k: v for k, v in theirs.items() if k != "trace_file"})
            self.assertEqual(Path(theirs["trace_file"]).relative_to(study),
                             Path(ours["trace_file"]).relative_to("study"))
        self.assertEqual(strokes, self.strokes)

    def test_study_copied_without_its_identity_is_refused(self):
        study = self.copy_study(linked=True)
        (study / ".calligraphy-study.json").unlink()
        result = self.report(study, ok=False)
        self.assert_one_error(result, 1, "session.json", "/study_id", ".calligraphy-study.json")

    def test_session_folder_renamed_is_refused_by_report_and_resume(self):
        study = self.copy_study()
        day1, _ = sessions(study, "S01")
        moved = day1.with_name(day1.name.replace("-S01-", "-S01-x"))
        day1.rename(moved)
        before = snapshot(study)
        self.assert_one_error(self.report(study, ok=False), 1, moved.name, "/session")
        result = run(["session", "resume", str(moved)], self.tmp)
        self.assert_one_error(result, 1)
        self.assertUnchanged(snapshot(study), before)

    def test_session_moved_to_another_subject_is_refused(self):
        study = self.copy_study(linked=True)
        day1, _ = sessions(study, "S01")
        day1.rename(study / "S02" / day1.name)
        before = snapshot(study)
        self.assert_one_error(self.report(study, ok=False), 1, f"S02/{day1.name}/session.json", "/subject/id")
        result = run(["session", "run", "p.json", "--subjects", "2", *SKILLED, "--out", str(study)], self.tmp)
        self.assert_one_error(result, 1, day1.name)
        self.assertUnchanged(snapshot(study), before)

    def test_session_copied_to_another_subject_is_refused_as_a_copy(self):
        study = self.copy_study(linked=True)
        day1, _ = sessions(study, "S01")
        shutil.copytree(day1, study / "S02" / day1.name)
        before = snapshot(study)
        self.assert_one_error(self.report(study, ok=False), 1, f"S02/{day1.name}", f"S01/{day1.name}")
        result = run(["session", "run", "p.json", "--subjects", "2", *SKILLED, "--out", str(study)], self.tmp)
        self.assert_one_error(result, 1, day1.name)
        self.assertUnchanged(snapshot(study), before)

    def test_session_of_another_study_is_refused(self):
        study = self.copy_study(linked=True)
        identity = json.loads((study / ".calligraphy-study.json").read_text(encoding="utf-8"))
        identity["study_id"] = "0123456789abcdef0123456789abcdef" if identity["study_id"] != \
            "0123456789abcdef0123456789abcdef" else "fedcba9876543210fedcba9876543210"
        (study / ".calligraphy-study.json").unlink()
        (study / ".calligraphy-study.json").write_text(json.dumps(identity), encoding="utf-8")
        self.assert_one_error(self.report(study, ok=False), 1, "session.json", "/study_id")

    def test_a_day_copied_twice_into_its_subject_is_refused(self):
        study = self.copy_study(linked=True)
        _, day2 = sessions(study, "S01")
        shutil.copytree(day2, day2.with_name(day2.name + "-9"))
        self.assert_one_error(self.report(study, ok=False), 1, day2.name + "-9")

    def test_record_copied_over_another_trial_is_refused(self):
        study = self.copy_study(linked=True)
        day1, _ = sessions(study, "S01")
        trials = day1 / "trials"
        for ext in (".json", ".trace.h5", ".svg"):
            (trials / f"003-training-sight-r2-U5341{ext}").unlink()
            shutil.copyfile(trials / f"002-training-sight-r1-U5341{ext}", trials / f"003-training-sight-r2-U5341{ext}")
        line = self.assert_one_error(self.report(study, ok=False), 1, "003-training-sight-r2-U5341.json")
        self.assertTrue(any(p in line for p in ("/trial/index", "/trial/file", "/repetition", "/trial/repetition")),
                        line)

    def test_record_removed_from_a_followed_day_is_not_resumed(self):
        study = self.copy_study()
        day1, day2 = sessions(study, "S01")
        (day1 / "trials" / "004-post-test-sight-r1-U5341.json").unlink()
        before = snapshot(study)
        result = run(["session", "resume", str(day1)], self.tmp)
        self.assert_one_error(result, 1, "004-post-test-sight-r1-U5341", day2.name)
        self.assertUnchanged(snapshot(study), before)

    def test_resume_in_a_hard_linked_copy_leaves_the_original_unchanged(self):
        study = self.copy_study(linked=True)
        _, day2 = sessions(study, "S01")
        record = day2 / "trials" / "002-transfer-sight-r1-U4E8C.json"
        record.unlink()
        run_ok(["session", "resume", str(day2)], self.tmp)
        self.assertTrue(record.exists())
        events = log_events(day2)
        self.assertEqual([e["event"] for e in events].count("session_completed"), 2)
        self.assertEqual([e["trial"] for e in events if e["event"] == "trial_saved"], [1, 2, 2])
        self.assertUnchanged(snapshot(self.tmp / "study"), self.before)

    def test_refused_protocol_into_the_study_leaves_it_unchanged(self):
        d = self.fresh()
        self.write(d, setp(BASE, "/colour", "blue"))
        result = run(["session", "run", str(d / "p.json"), "--subjects", "2", *SKILLED, "--out", "study"],
                     self.tmp)
        self.assert_one_error(result, 2, "p.json: /colour:")
        self.assertUnchanged(snapshot(self.tmp / "study"), self.before)


class OneSession(Tmp):
    def test_one_session_protocol_run_twice_is_refused_naming_new_subjects(self):
        d = self.fresh()
        self.write(d, ONE)
        run_ok(["session", "run", "p.json", "--subjects", "2", "--out", "out"], d)
        before = snapshot(d / "out")
        again = run(["session", "run", "p.json", "--subjects", "2", "--out", "out"], d)
        self.assert_one_error(again, 2, "S01", "S02", "--new-subjects")
        one = run(["session", "run", "p.json", "--subject", "S02", "--out", "out"], d)
        self.assert_one_error(one, 2, "S02", "--subject")
        self.assertUnchanged(snapshot(d / "out"), before)
        # --new-subjects goes on with S03, number 3: group (3 - 1) mod 2 = the first condition.
        run_ok(["session", "run", "p.json", "--subjects", "1", "--new-subjects", "--out", "out"], d)
        now = snapshot(d / "out")
        self.assertUnchanged({k: v for k, v in now.items() if k in before}, before)
        (new,) = sessions(d / "out", "S03")
        manifest = json.loads((new / "session.json").read_text(encoding="utf-8"))
        self.assertEqual(manifest["subject"], {"id": "S03", "number": 3})
        self.assertEqual(manifest["group"], "sight")
        (d / "t").mkdir()
        run_ok(["report", "out", "--csv", "t"], d)
        rows = table(d / "t" / "trials.csv")
        self.assertEqual([(r["subject"], r["group"], r["trial"]) for r in rows],
                         [("S01", "sight", "1"), ("S02", "guide", "1"), ("S03", "sight", "1")])


class Stopped(Tmp):
    """Runs at real-time pacing (0.5 s trials) stopped by a signal as a given trial starts, then resumed."""

    def start_and_signal(self, out, sig, session_number, trial):
        d = out.parent
        self.write(d, KILL, "k.json")
        found = []
        with open(d / "stdout", "wb") as so, open(d / "stderr", "wb") as se:
            process = subprocess.Popen([CLI, "session", "run", "k.json", "--subject", "S01", "--out", out.name,
                                        "--pacing", "real-time"], cwd=d, env=ENV, stdin=subprocess.DEVNULL,
                                       stdout=so, stderr=se)
            deadline = time.monotonic() + 40
            try:
                while time.monotonic() < deadline and process.poll() is None:
                    found = [s for s in (sessions(out, "S01") if (out / "S01").exists() else [])
                             if json.loads((s / "session.json").read_text(encoding="utf-8"))
                             .get("session_number", 1) == session_number]
                    if found and any(e.get("event") == "trial_started" and e.get("trial") == trial
                                     for e in log_events(found[0], whole_only=True)):
                        process.send_signal(sig)
                        break
                    time.sleep(0.05)
                status = process.wait(timeout=30)
            finally:
                if process.poll() is None:
                    process.kill()
                    process.wait()
        self.assertTrue(found, f"the run never started trial {trial} of session {session_number}")
        return status, found[0], (d / "stderr").read_text(encoding="utf-8", errors="replace")

    def test_sigterm_on_day_two_then_day_one_edited_refuses_resume_and_restored_completes(self):
        out = self.fresh() / "k"
        status, day2, stderr = self.start_and_signal(out, signal.SIGTERM, 2, 1)
        self.assertEqual(status, 143, stderr)
        stop = [line for line in stderr.splitlines() if "stopped by SIGTERM" in line]
        self.assertEqual(len(stop), 1, stderr)
        self.assertIn("calligraphy session resume", stop[0])
        self.assertIn(day2.name, stop[0])
        self.assertEqual(list((day2 / "trials").glob("*.json")), [])
        (attempt,) = (day2 / "trials" / "attempts").glob("*.json")
        self.assertTrue(attempt.name.startswith("001-retention-sight-r1-U5341.attempt-"), attempt.name)
        self.assertEqual(json.loads(attempt.read_text(encoding="utf-8"))["abort_reason"], "stopped by SIGTERM")
        events = log_events(day2)
        self.assertEqual([e["event"] for e in events[-2:]], ["trial_interrupted", "session_stopped"])
        self.assertEqual([e["reason"] for e in events[-2:]], ["SIGTERM", "SIGTERM"])
        # Day 1's session.json edited (one byte more): its SHA-256 is no longer the one day 2 recorded.
        day1 = sessions(out, "S01")[0]
        manifest = day1 / "session.json"
        original = manifest.read_bytes()
        manifest.write_bytes(original + b"\n")
        before = snapshot(out)
        refused = run(["session", "resume", str(day2), "--pacing", "lock-step"], out.parent)
        self.assert_one_error(refused, 1, day1.name)
        with self.subTest("the refused resume writes nothing"):
            self.assertUnchanged(snapshot(out), before)
        manifest.write_bytes(original)
        attempt_bytes = attempt.read_bytes()
        logged = len(log_events(day2))
        run_ok(["session", "resume", str(day2), "--pacing", "lock-step"], out.parent)
        self.assertEqual(attempt.read_bytes(), attempt_bytes)
        after = log_events(day2)[logged:]
        self.assertEqual(after[0]["event"], "session_started")
        self.assertEqual(after[0]["next_trial"], 1)
        self.assertEqual([e["event"] for e in after[1:]], ["trial_started", "trial_saved", "session_completed"])
        (out.parent / "t").mkdir()
        run_ok(["report", str(out), "--csv", "t"], out.parent)
        rows = table(out.parent / "t" / "trials.csv")
        self.assertEqual([(r["session_number"], r["trial"], r["phase"]) for r in rows],
                         [("1", "1", "pre-test"), ("1", "2", "training"),
                          ("2", "1", "retention")])

    def test_sigkill_on_day_one_blocks_day_two_until_resumed_nothing_lost_or_doubled(self):
        out = self.fresh() / "k"
        status, day1, stderr = self.start_and_signal(out, signal.SIGKILL, 1, 2)
        self.assertEqual(status, -signal.SIGKILL, stderr)
        saved = {p.name: p.read_bytes() for p in (day1 / "trials").iterdir() if p.is_file()}
        self.assertEqual(sorted(n for n in saved if n.endswith(".json")), ["001-pre-test-sight-r1-U5341.json"])
        killed = log_events(day1)
        self.assertEqual(killed[-1]["event"], "trial_started")
        self.assertEqual(killed[-1]["trial"], 2)
        # Day 2 is not started while day 1 has an unsaved trial: the error names the resume.
        before = snapshot(out)
        again = run(["session", "run", "k.json", "--subject", "S01", "--out", "k"], out.parent)
        self.assertNotEqual(again.returncode, 0)
        self.assertIn("session resume", error_lines(again)[-1])
        self.assertIn(day1.name, error_lines(again)[-1])
        self.assertUnchanged(snapshot(out), before)
        run_ok(["session", "resume", str(day1)], out.parent)
        for name, content in saved.items():
            if not name.startswith("."):
                self.assertEqual((day1 / "trials" / name).read_bytes(), content, name)
        self.assertEqual(sorted(p.name for p in (day1 / "trials").iterdir() if p.is_file()
                                and p.name.endswith(".json")),
                         ["001-pre-test-sight-r1-U5341.json", "002-training-sight-r1-U5341.json"])
        self.assertEqual([p.name for p in (day1 / "trials").iterdir() if p.name.startswith(".")
                          or p.name.endswith(".part")], [])
        after = log_events(day1)[len(killed):]
        self.assertEqual(after[0]["event"], "session_resumed")
        self.assertEqual((after[0]["saved_trials"], after[0]["next_trial"]), (1, 2))
        saves = [e["trial"] for e in log_events(day1) if e["event"] == "trial_saved"]
        self.assertEqual(saves, [1, 2])
        self.assertEqual(after[-1]["event"], "session_completed")
        run_ok(["session", "run", "k.json", "--subject", "S01", "--out", "k"], out.parent)
        day2 = sessions(out, "S01")[1]
        link = json.loads((day2 / "session.json").read_text(encoding="utf-8"))["previous_session"]
        self.assertEqual((link["session_id"], link["session_sha256"]), (day1.name, sha256(day1 / "session.json")))
        (out.parent / "t").mkdir()
        run_ok(["report", str(out), "--csv", "t"], out.parent)
        rows = table(out.parent / "t" / "trials.csv")
        self.assertEqual([(r["session_number"], r["trial"]) for r in rows], [("1", "1"), ("1", "2"),
                                                                             ("2", "1")])


if __name__ == "__main__":
    unittest.main()
