#!/usr/bin/env python3
"""Round 32B: a study's reports and tables as a lab makes them again and again. From the docs alone
(docs/cli.md "Conventions" (Outputs, sets of files written together, journals, links, limits), "report",
"session cohort"; docs/experiments.md "The per-trial pages", "Tidy tables", "A report for a paper";
docs/learning-study.md section 3; docs/python.md "A study's traces", "A report for a paper"; docs/testing.md
on what a set's journal holds and what a clean run leaves).

A tiny study (十 written twice in one vision condition, two simulated subjects) and a smaller one of another
protocol (one trial) are made once. Their tables and pages are then written again and again: into the same
folder (the same bytes), beside unrelated files (kept), with the DIRs in another order, from a copied study
and through a link to a session (only `trace_file` differs, the session keeps its own id), from a cohort in
memory (the report's rows but `session`, `start_utc` and the trace), from a study reached by a name that is
not UTF-8 (refused for the tables, nothing made), into folders holding links named as a set's file or folder
(refused, the outside file unchanged) or a hard link to an outside file (that name keeps it), a folder the
program cannot write, under a file size limit, killed or stopped by strace's signal injection between the
set's renames (also a set over two folders, killed between them), with journals planted with a right FNV-1a
checksum naming files outside, and two reports racing into one folder. The tables are read back with the csv
module and pandas and held to the records (17 digits: the record's double), to `calligraphy.study.load` and
to the documented numbering; the Python study report's tables (one run, R left off the PATH) to the means
over subjects and the t interval computed here, its links to each trial's anchor on the per-trial pages, and
`write_report`'s refusals of bad arguments.

CALLIGRAPHY_CLI names the program; PYTHONPATH the built Python package. CALLIGRAPHY_SANITIZED=1 takes five cases.
"""
import csv
import glob
import hashlib
import io
import json
import math
import os
import re
import resource
import shutil
import signal
import struct
import subprocess
import sys
import tempfile
import unittest
from pathlib import Path

from outsider import CLI, ENV, OneErrorLine, error_lines, run, run_ok, sanitized_subset

try:
    import pandas as pd
    import calligraphy
    import calligraphy.study as cg_study
except ImportError:  # reported by setUpClass
    pd = calligraphy = cg_study = None

load_tests = sanitized_subset({"test_report_twice_into_one_folder_gives_the_same_bytes_and_keeps_other_files",
                               "test_a_table_named_by_a_link_is_refused_and_the_file_outside_unchanged",
                               "test_file_size_limit_leaves_the_earlier_tables_and_no_page_folder",
                               "test_trials_csv_numbers_read_back_as_the_records_doubles",
                               "test_cohort_tables_are_the_reports_but_session_start_and_trace"})

PROTOCOL = {"name": "tiny", "conditions": [{"name": "v", "mode": "vision"}],
            "test": {"characters": ["十"], "conditions": ["v"], "repetitions": 2},
            "trial": {"max_duration_s": 20}}
OTHER = {"name": "other", "conditions": [{"name": "w", "mode": "vision"}],
         "test": {"characters": ["十"], "conditions": ["w"], "repetitions": 1},
         "trial": {"max_duration_s": 20}}
# docs/experiments.md "Tidy tables": every column of trials.csv the table lists.
TRIALS_COLUMNS = [
    "subject", "session", "protocol", "session_number", "group", "phase", "block", "condition", "mode",
    "characters", "trial", "item", "repetition", "item_set", "sequence", "period", "trained_condition",
    "writer", "end_reason", "start_utc", "writer_profile", "writer_learning", "completed_in_order",
    "strokes_total", "strokes_written", "strokes_accepted", "order_errors", "backwards_strokes",
    "unmatched_segments", "strokes_assisted", "mean_deviation_m", "max_deviation_m", "rms_deviation_m",
    "frechet_m", "dtw_m", "total_time_s", "pen_down_time_s", "velocity_peaks", "normalised_jerk",
    "shape_skill", "order_skill", "timing_skill", "subject_writing_speed_factor",
    "subject_spatial_error_factor", "subject_error_rate_factor", "subject_motor_noise_factor",
    "subject_fast_learning_per_trial", "subject_slow_learning_per_trial", "subject_fast_retention_per_trial",
    "subject_slow_retention_per_trial", "strokes_given_up", "legibility_top1", "legibility_top5",
    "trace_file", "trace_sha256"]
STROKES_COLUMNS = ["subject", "session", "trial", "phase", "condition", "character", "character_text", "stroke",
                   "typical_id", "written", "backwards", "segments", "refused_segments", "refusal",
                   "mean_deviation_m", "max_deviation_m", "rms_deviation_m", "frechet_m", "dtw_m", "time_s",
                   "path_length_m", "assisted"]
LABELS = ["subject", "protocol", "group", "condition", "characters", "item_set", "trained_condition",
          "trace_sha256"]
# The record's own numbers the tables copy (a record's key of the same name as the column).
RECORD_NUMBERS = ["strokes_total", "strokes_written", "strokes_accepted", "strokes_assisted", "order_errors",
                  "backwards_strokes", "unmatched_segments", "mean_deviation_m", "max_deviation_m",
                  "rms_deviation_m", "frechet_m", "dtw_m", "total_time_s", "pen_down_time_s", "velocity_peaks",
                  "normalised_jerk"]


def rows(path):
    """A CSV file's rows as dicts of text, read by the csv module (RFC 4180)."""
    with open(path, newline="", encoding="utf-8") as f:
        return list(csv.DictReader(f))


def header(path):
    with open(path, newline="", encoding="utf-8") as f:
        return next(csv.reader(f))


def read_trials(path):
    """trials.csv as docs/experiments.md "Tidy tables" reads it with pandas."""
    return pd.read_csv(path, keep_default_na=False, na_values=[""], float_precision="round_trip",
                       dtype=dict.fromkeys(LABELS, str))


def tree(folder):
    """Everything under `folder`: {relative path: bytes of a file, ("link", target), or "dir"}, links not
    followed, hidden names included."""
    found = {}
    for root, dirs, files in os.walk(folder):
        for name in dirs + files:
            p = os.path.join(root, name)
            rel = os.path.relpath(p, folder)
            if os.path.islink(p):
                found[rel] = ("link", os.readlink(p))
            elif os.path.isdir(p):
                found[rel] = "dir"
            else:
                found[rel] = Path(p).read_bytes()
    return found


def hidden(folder):
    """The hidden names left in a folder (temporaries, kept names, journals)."""
    return sorted(n for n in os.listdir(folder) if n.startswith("."))


def fnv1a64(data):
    h = 0xCBF29CE484222325
    for byte in data:
        h = ((h ^ byte) * 0x100000001B3) & 0xFFFFFFFFFFFFFFFF
    return h


def dead_pid():
    """The id of a process that has ended."""
    p = subprocess.Popen(["/bin/true"])
    p.wait()
    return p.pid


def strace_usable():
    if shutil.which("strace") is None:
        return False
    probe = subprocess.run(["strace", "-f", "-o", "/dev/null", "/bin/true"], capture_output=True)
    return probe.returncode == 0


class Round32B(unittest.TestCase, OneErrorLine):
    @classmethod
    def setUpClass(cls):
        if pd is None:
            raise unittest.SkipTest("pandas and the calligraphy Python package (PYTHONPATH) are needed")
        cls.tmp = Path(tempfile.mkdtemp(prefix="round32b-"))
        d = cls.tmp
        (d / "p.json").write_text(json.dumps(PROTOCOL, ensure_ascii=False), encoding="utf-8")
        (d / "o.json").write_text(json.dumps(OTHER, ensure_ascii=False), encoding="utf-8")
        run_ok(["session", "run", "p.json", "--subjects", "2", "--out", "study"], d)
        run_ok(["session", "run", "o.json", "--subjects", "1", "--subject", "O", "--out", "other"], d)
        cls.sessions = sorted(Path(p).relative_to(d) for p in glob.glob(str(d / "study" / "S0*" / "tiny-*")))
        assert len(cls.sessions) == 2, cls.sessions
        for name, study in (("ref", "study"), ("refo", "other")):
            (d / name).mkdir()
            run_ok(["report", study, "--csv", name, "--jobs", "1"], d)
        cls.ref_t = (d / "ref" / "trials.csv").read_bytes()
        cls.ref_s = (d / "ref" / "strokes.csv").read_bytes()
        cls.other_t = (d / "refo" / "trials.csv").read_bytes()
        cls.other_s = (d / "refo" / "strokes.csv").read_bytes()
        cls.counter = 0

    @classmethod
    def tearDownClass(cls):
        for root, dirs, _ in os.walk(cls.tmp):  # an immutable folder left by a failed case
            for name in dirs:
                subprocess.run(["chattr", "-i", os.path.join(root, name)], capture_output=True)
        shutil.rmtree(cls.tmp, ignore_errors=True)

    def fresh(self, name):
        """A new empty folder under the study's temporary folder, returned relative to it."""
        type(self).counter += 1
        rel = Path(f"{name}{self.counter}")
        (self.tmp / rel).mkdir()
        return rel

    def cli(self, *args, **kw):
        return run(list(args), self.tmp, **kw)

    def traced(self, injection, *args):
        """The program under strace with a fault injected (`-e inject=...`), --jobs 1 (one thread renames)."""
        return subprocess.run(["strace", "-f", "-o", "/dev/null", "-e", "trace=rename", "-e",
                               f"inject={injection}", CLI, *args], cwd=self.tmp, env=ENV, capture_output=True,
                              stdin=subprocess.DEVNULL, timeout=60)

    def records(self):
        """{trace path as in trace_file: the trial record beside it}."""
        found = {}
        for s in self.sessions:
            for record in sorted((self.tmp / s / "trials").glob("*.json")):
                data = json.loads(record.read_text(encoding="utf-8"))
                found[str(s / "trials" / data["files"]["trace"])] = data
        return found

    # ---- the tables ------------------------------------------------------------------------------------------
    def test_trials_csv_has_the_documented_columns_and_one_row_per_saved_trial(self):
        self.assertEqual(set(header(self.tmp / "ref" / "trials.csv")), set(TRIALS_COLUMNS))
        self.assertEqual(set(header(self.tmp / "ref" / "strokes.csv")), set(STROKES_COLUMNS))
        table = read_trials(self.tmp / "ref" / "trials.csv")
        self.assertEqual(len(table), 4, "two subjects, one session each, two trials each")
        self.assertEqual(sorted(table.trace_file), sorted(self.records()))
        for (subject, session), part in table.groupby(["subject", "session"]):
            self.assertEqual(list(part.trial), [1, 2], "1-based, the NNN of its files")
            self.assertEqual(list(part.repetition), [1, 2])
            self.assertEqual(set(part.block) | set(part.item) | set(part.session_number), {1})
            self.assertTrue(session.startswith(f"tiny-{subject}-"), session)
        self.assertEqual(set(table.protocol), {"tiny"})
        self.assertEqual(set(table.phase), {"test"})
        self.assertEqual(set(table["mode"]), {"vision"})
        self.assertEqual(set(table.writer), {"simulated"})
        self.assertEqual(set(table.writer_profile), {"novice"})
        self.assertEqual(set(table.writer_learning), {"two-state"}, "session run's default")
        self.assertTrue(table.group.isna().all(), "no between-subjects phase: an empty field")
        self.assertEqual(str(table.completed_in_order.dtype), "bool")
        text = (self.tmp / "ref" / "trials.csv").read_text(encoding="utf-8")
        flags = {r["completed_in_order"] for r in csv.DictReader(io.StringIO(text))}
        self.assertLessEqual(flags, {"TRUE", "FALSE"})

    def test_trials_csv_numbers_read_back_as_the_records_doubles(self):
        records = self.records()
        for row in rows(self.tmp / "ref" / "trials.csv"):
            record = records[row["trace_file"]]
            for column in RECORD_NUMBERS:
                with self.subTest(trial=row["trace_file"], column=column):
                    value = record[column]
                    if value is None:
                        self.assertEqual(row[column], "")
                    else:
                        self.assertEqual(float(row[column]), float(value))
            self.assertEqual(row["completed_in_order"], "TRUE" if record["completed_in_order"] else "FALSE")
            self.assertEqual(row["end_reason"], record["end_reason"])
            self.assertEqual(row["start_utc"], record["start_time_utc"])
            self.assertEqual(row["session"], record["session"])
            trace = (self.tmp / row["trace_file"]).read_bytes()
            self.assertEqual(row["trace_sha256"], hashlib.sha256(trace).hexdigest())
            self.assertEqual(row["trace_sha256"], record["files"]["trace_sha256"])

    def test_strokes_csv_numbers_each_reference_stroke_from_one(self):
        records = self.records()
        by_trial = {}
        for row in rows(self.tmp / "ref" / "strokes.csv"):
            by_trial.setdefault((row["session"], int(row["trial"])), []).append(row)
        trials = rows(self.tmp / "ref" / "trials.csv")
        self.assertEqual(sorted(by_trial), sorted((t["session"], int(t["trial"])) for t in trials))
        for t in trials:
            record = records[t["trace_file"]]
            strokes = by_trial[t["session"], int(t["trial"])]
            with self.subTest(trial=t["trace_file"]):
                self.assertEqual(len(strokes), int(t["strokes_total"]), "one row per reference stroke")
                self.assertEqual([int(s["stroke"]) for s in strokes], [1, 2])
                self.assertEqual({s["character"] for s in strokes}, {"1"})
                self.assertEqual({s["character_text"] for s in strokes}, {"十"})
                self.assertEqual([int(s["typical_id"]) for s in strokes],
                                 [p["typical_id"] for p in record["per_stroke"]])
                for s in strokes:
                    self.assertTrue(1 <= int(s["typical_id"]) <= 39)
                    self.assertIn(s["written"], ("TRUE", "FALSE"))
                    self.assertIn(s["backwards"], ("TRUE", "FALSE"))
                    self.assertEqual(s["assisted"], "FALSE")
                    self.assertEqual((s["subject"], s["phase"], s["condition"]),
                                     (t["subject"], t["phase"], t["condition"]))

    def test_study_load_gives_the_csv_tables_value_for_value(self):
        study = cg_study.load(str(self.tmp / "study"))
        table = read_trials(self.tmp / "ref" / "trials.csv")
        self.assertEqual(list(study.trials.columns), list(table.columns))
        self.assertEqual(len(study.trials), len(table))
        loaded = study.trials.reset_index(drop=True)
        for column in table.columns:
            if column == "trace_file":
                continue  # reached from the folder given: an absolute path here
            with self.subTest(column=column):
                mine = [None if (isinstance(v, float) and math.isnan(v)) or v == "" else v for v in table[column]]
                theirs = [None if (isinstance(v, float) and math.isnan(v)) or v == "" else v
                          for v in loaded[column].astype(object)]
                self.assertEqual([str(v) if isinstance(v, str) else v for v in theirs],
                                 [str(v) if isinstance(v, str) else v for v in mine])
        self.assertEqual([Path(p).name for p in loaded.trace_file], [Path(p).name for p in table.trace_file])
        self.assertEqual(len(study.strokes), len(rows(self.tmp / "ref" / "strokes.csv")))
        # A list of session folders in another order gives the same rows (sorted by the folders' paths).
        listed = cg_study.load([str(self.tmp / s) for s in reversed(self.sessions)]).trials.reset_index(drop=True)
        self.assertEqual(list(listed.session), list(loaded.session))
        self.assertEqual(list(listed.trial), list(loaded.trial))
        self.assertEqual(list(listed.mean_deviation_m), list(loaded.mean_deviation_m))

    def test_tables_are_the_same_bytes_whatever_the_order_of_the_dirs(self):
        a, b = self.fresh("order"), self.fresh("order")
        first, second = (str(s) for s in self.sessions)
        run_ok(["report", second, first, "--csv", a, "--jobs", "1"], self.tmp)
        run_ok(["report", first, second, "--csv", b, "--jobs", "2"], self.tmp)
        for name in ("trials.csv", "strokes.csv"):
            self.assertEqual((self.tmp / a / name).read_bytes(), (self.tmp / b / name).read_bytes(), name)
        # The same folders, reached through the same paths, as `report study` reached them.
        self.assertEqual((self.tmp / a / "trials.csv").read_bytes(), self.ref_t)
        self.assertEqual((self.tmp / a / "strokes.csv").read_bytes(), self.ref_s)

    def test_report_twice_into_one_folder_gives_the_same_bytes_and_keeps_other_files(self):
        out = self.fresh("again")
        (self.tmp / out / "notes.txt").write_text("the lab's notes\n")
        (self.tmp / out / ".hidden-mine").write_text("mine\n")
        (self.tmp / out / "figures").mkdir()
        (self.tmp / out / "figures" / "f.svg").write_text("<svg/>")
        before = tree(self.tmp / out)
        for time in (1, 2):
            result = run_ok(["report", "study", "--csv", out], self.tmp)
            with self.subTest(time=time):
                self.assertIn("trials.csv (4 rows), strokes.csv (8 rows)", result.stdout.decode())
                now = tree(self.tmp / out)
                self.assertEqual(now.pop("trials.csv"), self.ref_t)
                self.assertEqual(now.pop("strokes.csv"), self.ref_s)
                self.assertEqual(now, before, "unrelated files kept, nothing else left")

    def test_copied_study_tables_differ_only_in_trace_file(self):
        shutil.copytree(self.tmp / "study", self.tmp / "copied", symlinks=True)
        out = self.fresh("copy")
        run_ok(["report", "copied", "--csv", out], self.tmp)
        self.assertEqual((self.tmp / out / "strokes.csv").read_bytes(), self.ref_s)
        mine, theirs = rows(self.tmp / out / "trials.csv"), rows(self.tmp / "ref" / "trials.csv")
        self.assertEqual(len(mine), len(theirs))
        for a, b in zip(mine, theirs):
            self.assertEqual(a.pop("trace_file"), "copied/" + b.pop("trace_file")[len("study/"):])
            self.assertEqual(a, b)

    def test_session_given_through_a_link_keeps_its_own_id(self):
        session = self.sessions[0]
        link = self.fresh("alias") / "s"
        os.symlink(self.tmp / session, self.tmp / link)
        out = self.fresh("alias")
        run_ok(["report", link, "--csv", out], self.tmp)
        mine = rows(self.tmp / out / "trials.csv")
        theirs = [r for r in rows(self.tmp / "ref" / "trials.csv") if r["session"] == session.name]
        self.assertEqual(len(mine), 2)
        for a, b in zip(mine, theirs):
            self.assertEqual(a["session"], session.name, "the folder's own name, not the link's")
            self.assertTrue(a.pop("trace_file").startswith(str(link) + "/"))
            b.pop("trace_file")
            self.assertEqual(a, b)

    def test_cohort_tables_are_the_reports_but_session_start_and_trace(self):
        out = self.fresh("cohort")
        run_ok(["session", "cohort", "p.json", "--subjects", "2", "--csv", out, "--jobs", "1"], self.tmp)
        mine, theirs = rows(self.tmp / out / "trials.csv"), rows(self.tmp / "ref" / "trials.csv")
        self.assertEqual(header(self.tmp / out / "trials.csv"), header(self.tmp / "ref" / "trials.csv"))
        self.assertEqual(len(mine), len(theirs))
        for a, b in zip(mine, theirs):
            with self.subTest(subject=b["subject"], trial=b["trial"]):
                self.assertEqual(a.pop("session"), f"tiny-{b['subject']}-s1")
                self.assertEqual((a.pop("start_utc"), a.pop("trace_file"), a.pop("trace_sha256")), ("", "", ""))
                for key in ("session", "start_utc", "trace_file", "trace_sha256"):
                    b.pop(key)
                self.assertEqual(a, b)
        strokes = rows(self.tmp / out / "strokes.csv")
        ref_strokes = rows(self.tmp / "ref" / "strokes.csv")
        self.assertEqual(len(strokes), len(ref_strokes))
        for a, b in zip(strokes, ref_strokes):
            a.pop("session")
            b.pop("session")
            self.assertEqual(a, b)

    def test_a_dir_named_in_latin_1_is_refused_for_the_tables_and_nothing_is_made(self):
        name = b"st\xe9" + str(self.counter).encode()
        try:
            os.symlink(b"study", bytes(self.tmp) + b"/" + name)
        except (OSError, UnicodeError):
            self.skipTest("the file system takes no name that is not UTF-8")
        out = self.fresh("latin")
        for args in (["--csv", out], ["--csv", out, "--out", out / "r.html"]):
            with self.subTest(args=args):
                result = self.cli("report", name, *args)
                line = self.assert_one_error(result, 1, "\\xe9", ".trace.h5")
                self.assertNotIn("\ufffd", line)
                self.assertEqual(os.listdir(self.tmp / out), [], "nothing written, no page folder")
        with self.assertRaises(calligraphy.DataError) as caught:
            cg_study.load(os.fsdecode(bytes(self.tmp) + b"/" + name))
        self.assertIn(".trace.h5", str(caught.exception))
        # The pages alone carry no path of a trace: they are written.
        run_ok(["report", name, "--out", out / "r.html"], self.tmp)
        self.assertTrue((self.tmp / out / "r.html").is_file())

    # ---- the pages ---------------------------------------------------------------------------------------------
    def test_pages_hold_one_article_per_trial_numbered_from_one(self):
        site = self.fresh("site")
        result = run_ok(["report", "study", "--out", site / "trials.html"], self.tmp)
        self.assertIn("2 sessions, 4 trials, 2 pages", result.stdout.decode())
        index = (self.tmp / site / "trials.html").read_text(encoding="utf-8")
        for s in self.sessions:
            page = self.tmp / site / "trials_files" / s.parent.name / f"{s.name}.html"
            text = page.read_text(encoding="utf-8")
            with self.subTest(session=s.name):
                self.assertEqual(sorted(set(re.findall(r'<article\b[^>]*\bid="(trial-[^"]+)"', text))),
                                 [f"trial-{s.name}-1", f"trial-{s.name}-2"])
                self.assertNotIn("<script", text.lower())
                self.assertIn(f"trials_files/{s.parent.name}/{s.name}.html", index)
        self.assertNotIn("<script", index.lower())
        self.assertEqual(hidden(self.tmp / site), [])

    def test_pages_of_sessions_no_longer_reported_are_left_as_they_were(self):
        site = self.fresh("keep")
        run_ok(["report", "study", "--out", site / "r.html"], self.tmp)
        kept, redone = self.sessions[1], self.sessions[0]
        page = self.tmp / site / "r_files" / kept.parent.name / f"{kept.name}.html"
        page.write_bytes(page.read_bytes() + b"<!-- the lab's note -->\n")
        annotated = page.read_bytes()
        run_ok(["report", redone, "--out", site / "r.html"], self.tmp)
        self.assertEqual(page.read_bytes(), annotated, "a page of a session not under the DIRs is left as it was")
        self.assertTrue((self.tmp / site / "r_files" / redone.parent.name / f"{redone.name}.html").is_file())

    def test_out_without_html_puts_the_pages_in_its_name_files(self):
        site = self.fresh("bare")
        run_ok(["report", self.sessions[0], "--out", site / "index"], self.tmp)
        s = self.sessions[0]
        self.assertTrue((self.tmp / site / "index").is_file())
        self.assertTrue((self.tmp / site / "index_files" / s.parent.name / f"{s.name}.html").is_file())
        self.assertEqual(sorted(os.listdir(self.tmp / site)), ["index", "index_files"])

    # ---- links planted in the set's folders ------------------------------------------------------------------
    def test_a_table_named_by_a_link_is_refused_and_the_file_outside_unchanged(self):
        for name, dangling in (("trials.csv", False), ("strokes.csv", False), ("strokes.csv", True)):
            with self.subTest(name=name, dangling=dangling):
                out = self.fresh("linked")
                outside = self.tmp / self.fresh("outside") / "victim.csv"
                if not dangling:
                    outside.write_bytes(b"the lab's own table\n")
                os.symlink(outside, self.tmp / out / name)
                before = tree(self.tmp / out)
                result = self.cli("report", "study", "--csv", out)
                self.assert_one_error(result, 2, "--csv", name)
                self.assertEqual(tree(self.tmp / out), before, "nothing written")
                if dangling:
                    self.assertFalse(outside.exists(), "no file created through a dangling link")
                else:
                    self.assertEqual(outside.read_bytes(), b"the lab's own table\n")

    def test_every_file_and_folder_of_the_pages_set_that_is_a_link_is_refused(self):
        s = self.sessions[0]
        plants = {"index": "r.html", "pages folder": "r_files", "subject folder": f"r_files/{s.parent.name}",
                  "session page": f"r_files/{s.parent.name}/{s.name}.html"}
        for what, name in plants.items():
            with self.subTest(what=what):
                site = self.fresh("plant")
                outside = self.fresh("elsewhere")
                target = self.tmp / outside
                if name.endswith(".html"):
                    target = target / "victim.html"
                    target.write_bytes(b"<p>the lab's page</p>\n")
                (self.tmp / site / name).parent.mkdir(parents=True, exist_ok=True)
                os.symlink(target, self.tmp / site / name)
                before, outside_before = tree(self.tmp / site), tree(self.tmp / outside)
                result = self.cli("report", s, "--out", site / "r.html")
                self.assert_one_error(result, 2, "--out")
                self.assertIn(Path(name).name, error_lines(result)[0])
                self.assertEqual(tree(self.tmp / site), before)
                self.assertEqual(tree(self.tmp / outside), outside_before, "nothing written outside")

    def test_cohort_table_named_by_a_link_is_refused(self):
        out = self.fresh("cohortlink")
        victim = self.tmp / self.fresh("outside") / "victim.csv"
        victim.write_bytes(b"kept\n")
        os.symlink(victim, self.tmp / out / "trials.csv")
        result = self.cli("session", "cohort", "p.json", "--subjects", "1", "--csv", out)
        self.assert_one_error(result, 2, "--csv", "trials.csv")
        self.assertEqual(victim.read_bytes(), b"kept\n")
        self.assertEqual(sorted(os.listdir(self.tmp / out)), ["trials.csv"])

    def test_a_table_with_another_hard_link_is_replaced_by_rename_the_other_name_kept(self):
        out = self.fresh("hard")
        victim = self.tmp / self.fresh("outside") / "victim.csv"
        victim.write_bytes(b"the lab's own table\n")
        os.link(victim, self.tmp / out / "trials.csv")
        run_ok(["report", "study", "--csv", out], self.tmp)
        self.assertEqual(victim.read_bytes(), b"the lab's own table\n")
        self.assertEqual((self.tmp / out / "trials.csv").read_bytes(), self.ref_t)
        self.assertEqual(os.stat(victim).st_nlink, 1)

    def test_pages_folder_that_is_a_file_is_refused_and_nothing_made(self):
        site = self.fresh("notdir")
        (self.tmp / site / "r_files").write_bytes(b"a file of the lab's\n")
        before = tree(self.tmp / site)
        result = self.cli("report", "study", "--out", site / "r.html")
        self.assert_one_error(result, (1, 2), "--out", "r_files")
        self.assertEqual(tree(self.tmp / site), before, "a refused command creates no folder and no file")

    # ---- failures ----------------------------------------------------------------------------------------------
    def test_a_folder_the_program_cannot_write_is_refused_naming_the_option(self):
        for option in ("--csv", "--out"):
            with self.subTest(option=option):
                out = self.fresh("ro")
                target = out if option == "--csv" else out / "r.html"
                if os.geteuid() == 0:
                    if subprocess.run(["chattr", "+i", self.tmp / out], capture_output=True).returncode != 0:
                        self.skipTest("root, and chattr +i is not permitted here")
                else:
                    os.chmod(self.tmp / out, 0o555)
                try:
                    result = self.cli("report", "study", option, target)
                finally:
                    subprocess.run(["chattr", "-i", self.tmp / out], capture_output=True)
                    os.chmod(self.tmp / out, 0o755)
                self.assert_one_error(result, 1, option, str(out))
                self.assertEqual(os.listdir(self.tmp / out), [])

    def test_file_size_limit_leaves_the_earlier_tables_and_no_page_folder(self):
        out = self.fresh("fsize")
        shutil.copy(self.tmp / "refo" / "trials.csv", self.tmp / out / "trials.csv")
        shutil.copy(self.tmp / "refo" / "strokes.csv", self.tmp / out / "strokes.csv")
        before = tree(self.tmp / out)

        def limit():
            resource.setrlimit(resource.RLIMIT_FSIZE, (1500, 1500))
        for args in (["--csv", out], ["--out", out / "r.html"], ["--csv", out, "--out", out / "r.html"]):
            with self.subTest(args=args):
                result = run(["report", "study", *args], self.tmp, preexec_fn=limit)
                self.assert_one_error(result, 1)
                self.assertEqual(tree(self.tmp / out), before,
                                 "earlier tables whole, no temporary, no page folder made")

    def test_stop_signal_between_the_renames_leaves_one_whole_pair_and_nothing_else(self):
        if not strace_usable():
            self.skipTest("strace is missing or cannot trace here")
        for sig, when in (("SIGTERM", 1), ("SIGTERM", 2), ("SIGTERM", 3), ("SIGINT", 2), ("SIGHUP", 3)):
            with self.subTest(signal=sig, rename=when):
                out = self.fresh("stop")
                (self.tmp / out / "trials.csv").write_bytes(self.other_t)
                (self.tmp / out / "strokes.csv").write_bytes(self.other_s)
                result = self.traced(f"rename:signal={sig}:when={when}",
                                     "report", "study", "--csv", out, "--jobs", "1")
                number = getattr(signal, sig)
                self.assertIn(result.returncode, (-number, 128 + number), result.stderr.decode())
                pair = ((self.tmp / out / "trials.csv").read_bytes(),
                        (self.tmp / out / "strokes.csv").read_bytes())
                self.assertIn(pair, [(self.other_t, self.other_s), (self.ref_t, self.ref_s)])
                self.assertEqual(sorted(os.listdir(self.tmp / out)), ["strokes.csv", "trials.csv"],
                                 "no temporary, second name or journal")

    def kill_between_renames(self):
        """A tables folder holding the other study's tables, into which `report study --csv` was killed
        after renaming its trials.csv and before its strokes.csv (strace: SIGKILL at the third rename)."""
        out = self.fresh("killed")
        (self.tmp / out / "trials.csv").write_bytes(self.other_t)
        (self.tmp / out / "strokes.csv").write_bytes(self.other_s)
        result = self.traced("rename:signal=SIGKILL:when=3", "report", "study", "--csv", out, "--jobs", "1")
        self.assertIn(result.returncode, (-9, 137))
        return out

    def test_killed_report_is_completed_by_the_next_set_in_its_folder(self):
        if not strace_usable():
            self.skipTest("strace is missing or cannot trace here")
        out = self.kill_between_renames()
        journals = [n for n in hidden(self.tmp / out) if n.endswith(".journal")]
        self.assertEqual(len(journals), 1, hidden(self.tmp / out))
        # A copy taken with its journal completes only the copy.
        copy = self.fresh("copyof")
        shutil.rmtree(self.tmp / copy)
        shutil.copytree(self.tmp / out, self.tmp / copy, symlinks=True)
        original = tree(self.tmp / out)
        # The next set written in the folder (the pages' index, no table) completes the killed set there.
        run_ok(["report", self.sessions[0], "--out", copy / "r.html"], self.tmp)
        self.assertEqual((self.tmp / copy / "trials.csv").read_bytes(), self.ref_t)
        self.assertEqual((self.tmp / copy / "strokes.csv").read_bytes(), self.ref_s, "the journal completed")
        self.assertEqual(hidden(self.tmp / copy), [], "nothing left behind")
        self.assertEqual(tree(self.tmp / out), original, "the original folder is not the copy's")
        # And a cohort's tables written there afterwards (a set of the same names) are the cohort's, nothing left.
        cohort = self.fresh("cohortref")
        run_ok(["session", "cohort", "o.json", "--subjects", "1", "--csv", cohort, "--jobs", "1"], self.tmp)
        run_ok(["session", "cohort", "o.json", "--subjects", "1", "--csv", out, "--jobs", "1"], self.tmp)
        for name in ("trials.csv", "strokes.csv"):
            self.assertEqual((self.tmp / out / name).read_bytes(), (self.tmp / cohort / name).read_bytes(), name)
        self.assertEqual(sorted(os.listdir(self.tmp / out)), ["strokes.csv", "trials.csv"])

    def test_set_over_two_folders_killed_between_them_is_completed_by_the_same_command(self):
        if not strace_usable():
            self.skipTest("strace is missing or cannot trace here")
        s = self.sessions[0]
        site, clean = self.fresh("twofold"), self.fresh("twofold")
        run_ok(["report", s, "--csv", clean, "--out", clean / "r.html", "--jobs", "1"], self.tmp)
        run_ok(["report", "other", "--csv", site, "--out", site / "r.html", "--jobs", "1"], self.tmp)
        # Renames: the two journals, trials.csv, strokes.csv, r.html, then the session's page: killed at its.
        result = self.traced("rename:signal=SIGKILL:when=6", "report", s, "--csv", site, "--out", site / "r.html",
                             "--jobs", "1")
        self.assertIn(result.returncode, (-9, 137))
        page_folder = self.tmp / site / "r_files" / s.parent.name
        # The tables' folder had all its renames: its files are the new ones (the earlier ones kept under second
        # names until the set's last rename), and the page's folder holds its journal.
        for name in ("trials.csv", "strokes.csv", "r.html"):
            self.assertEqual((self.tmp / site / name).read_bytes(), (self.tmp / clean / name).read_bytes(), name)
        self.assertTrue(any(n.endswith(".journal") for n in hidden(page_folder)), hidden(page_folder))
        run_ok(["report", s, "--csv", site, "--out", site / "r.html", "--jobs", "1"], self.tmp)
        for name in ("trials.csv", "strokes.csv", "r.html", f"r_files/{s.parent.name}/{s.name}.html"):
            self.assertEqual((self.tmp / site / name).read_bytes(), (self.tmp / clean / name).read_bytes(), name)
        for folder in (self.tmp / site, self.tmp / site / "r_files", page_folder):
            self.assertEqual(hidden(folder), [], f"nothing left in {folder}")

    def test_planted_journals_naming_files_outside_are_refused_and_left(self):
        if not strace_usable():
            self.skipTest("strace is missing or cannot trace here")
        out = self.kill_between_renames()
        journal = [n for n in hidden(self.tmp / out) if n.endswith(".journal")][0]
        text = (self.tmp / out / journal).read_bytes()
        body, checksum = text.rsplit(b"checksum ", 1)
        self.assertEqual(checksum.strip().decode(), f"{fnv1a64(body):016x}", "the journal as docs/testing.md says")
        lines = body.decode().splitlines()
        first_entry = lines[1].split("\t")  # NAME, its kept name, its temporary
        self.assertEqual(first_entry[0], "trials.csv")
        victims = self.fresh("victims")
        victim = self.tmp / victims / "victim.csv"
        os.symlink(victim, self.tmp / out / ".kept-link")
        forgeries = {
            "kept name climbing out": ["trials.csv", f"../{victims}/victim.csv", first_entry[2]],
            "kept name absolute": ["trials.csv", str(victim), first_entry[2]],
            "target climbing out": [f"../{victims}/victim.csv", first_entry[1], first_entry[2]],
            "kept name a link out": ["trials.csv", ".kept-link", first_entry[2]],
        }
        for what, entry in forgeries.items():
            with self.subTest(what=what):
                victim.write_bytes(b"the lab's own file\n")
                forged_body = (lines[0] + "\n" + "\t".join(entry) + "\n").encode()
                forged = forged_body + f"checksum {fnv1a64(forged_body):016x}\n".encode()
                for n in hidden(self.tmp / out):
                    if n.endswith(".journal"):
                        os.unlink(self.tmp / out / n)
                name = f".calligraphy-set-{dead_pid()}-0.journal"
                (self.tmp / out / name).write_bytes(forged)
                before = tree(self.tmp / out)
                result = self.cli("report", "study", "--csv", out)
                self.assert_one_error(result, 1, name)
                self.assertEqual(victim.read_bytes(), b"the lab's own file\n")
                self.assertEqual(tree(self.tmp / out), before, "refused and left as it is")
        with self.subTest(what="a wrong checksum"):
            for n in hidden(self.tmp / out):
                if n.endswith(".journal"):
                    os.unlink(self.tmp / out / n)
            name = f".calligraphy-set-{dead_pid()}-0.journal"
            (self.tmp / out / name).write_bytes(body.replace(b"trials.csv\t", b"trialz.csv\t", 1)
                                                + b"checksum " + checksum)
            before = tree(self.tmp / out)
            result = self.cli("report", "study", "--csv", out)
            self.assert_one_error(result, 1, name)
            self.assertEqual(tree(self.tmp / out), before)

    def test_two_reports_racing_into_one_folder_leave_one_whole_pair(self):
        out = self.fresh("race")
        for round_ in range(2):
            with self.subTest(round=round_):
                runs = [subprocess.Popen([CLI, "report", study, "--csv", out, "--jobs", "1"], cwd=self.tmp,
                                         env=ENV, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                                         stdin=subprocess.DEVNULL) for study in ("study", "other")]
                for p in runs:
                    _, err = p.communicate(timeout=60)
                    self.assertEqual(p.returncode, 0, err.decode())
                pair = ((self.tmp / out / "trials.csv").read_bytes(), (self.tmp / out / "strokes.csv").read_bytes())
                self.assertIn(pair, [(self.ref_t, self.ref_s), (self.other_t, self.other_s)])
                self.assertEqual(sorted(os.listdir(self.tmp / out)), ["strokes.csv", "trials.csv"])

    # ---- the Python study report -------------------------------------------------------------------------------
    def test_python_report_tables_hold_the_means_over_subjects_in_si_units(self):
        paper = self.tmp / "paper"
        (paper / "tables").mkdir(parents=True)
        (paper / "notes.txt").write_text("the lab's notes\n")
        (paper / "tables" / "mine.csv").write_text("a,b\n1,2\n")
        nobin = self.fresh("nobin")  # R left out: the report's models say "not computed", the rest is given
        env = dict(ENV, PATH=str(self.tmp / nobin))
        site = self.fresh("pertrial")
        run_ok(["report", "study", "--out", site / "trials.html"], self.tmp)
        result = subprocess.run([sys.executable, "-m", "calligraphy.study_report", "study", "--out", "paper",
                                 "--per-trial-page", site / "trials.html"],
                                cwd=self.tmp, env=env, capture_output=True, timeout=120)
        self.assertEqual(result.returncode, 0, result.stderr.decode())
        self.assertEqual((paper / "notes.txt").read_text(), "the lab's notes\n")
        self.assertEqual((paper / "tables" / "mine.csv").read_text(), "a,b\n1,2\n")
        self.assertTrue((paper / "index.html").is_file())
        means = rows(paper / "tables" / "phase_means.csv")
        self.assertEqual(header(paper / "tables" / "phase_means.csv"),
                         ["value", "unit", "phase", "condition", "n", "mean", "sd", "ci95_low", "ci95_high"])
        trials = read_trials(self.tmp / "ref" / "trials.csv")
        units = {"total_time_s": "s", "mean_deviation_m": "m"}
        self.assertEqual(sorted(r["value"] for r in means), sorted(units))
        for r in means:
            with self.subTest(value=r["value"]):
                self.assertEqual(r["unit"], units[r["value"]])
                self.assertEqual((r["phase"], r["condition"], r["n"]), ("test", "v", "2"))
                per_subject = trials.groupby("subject")[r["value"]].mean()
                self.assertAlmostEqual(float(r["mean"]), per_subject.mean(), delta=1e-12 * abs(per_subject.mean()))
                self.assertAlmostEqual(float(r["sd"]), per_subject.std(ddof=1),
                                       delta=1e-9 * abs(per_subject.mean()))
                # The 95 % t interval over 2 subjects: t(0.975, 1 df) = tan(0.475 pi), the Cauchy quantile.
                half = math.tan(0.475 * math.pi) * per_subject.std(ddof=1) / math.sqrt(2)
                scale = abs(per_subject.mean()) + half
                self.assertAlmostEqual(float(r["ci95_low"]), per_subject.mean() - half, delta=1e-9 * scale)
                self.assertAlmostEqual(float(r["ci95_high"]), per_subject.mean() + half, delta=1e-9 * scale)
        exclusions = rows(paper / "tables" / "exclusions.csv")
        self.assertEqual(header(paper / "tables" / "exclusions.csv")[:4], ["phase", "condition", "trials", "kept"])
        self.assertEqual([(r["phase"], r["trials"], r["kept"]) for r in exclusions],
                         [("test", "4", str(int((trials.end_reason == "completed").sum())))])
        self.assertEqual(header(paper / "tables" / "questions.csv"),
                         ["value", "unit", "family", "question", "phase", "comparison", "model", "test", "n", "df",
                          "statistic", "p", "p_holm", "estimate", "ci95_low", "ci95_high", "g", "g_ci95_low",
                          "g_ci95_high", "apa", "note"])
        for value in units:
            self.assertTrue((paper / "figures" / f"phase_{value}.svg").is_file())
            png = (paper / "figures" / f"phase_{value}.png").read_bytes()
            at = png.find(b"pHYs")
            self.assertGreater(at, 0, "a PNG with its resolution")
            x, y, unit = struct.unpack(">IIB", png[at + 4:at + 13])
            self.assertEqual(unit, 1)
            self.assertAlmostEqual(x / 39.3700787, 150, delta=0.5, msg="150 dpi")
        # Each trial linked to its drawing on the per-trial page: the file is there and holds the anchor.
        index = (paper / "index.html").read_text(encoding="utf-8")
        self.assertNotIn("<script", index.lower())
        self.assertNotRegex(index, r'src="(https?:)?//')
        links = set(re.findall(r'href="([^"#]*)#(trial-[^"]+)"', index))
        self.assertEqual(len(links), 4, "a link for each trial")
        for href, anchor in links:
            with self.subTest(link=href + "#" + anchor):
                target = (paper / href).resolve()
                self.assertTrue(target.is_file(), target)
                self.assertIn(f'id="{anchor}"', target.read_text(encoding="utf-8"))
        for folder in (paper, paper / "tables", paper / "figures"):
            self.assertEqual([n for n in hidden(folder)], [], f"nothing half-written left in {folder}")

    def test_write_report_refuses_bad_arguments_naming_them_and_makes_no_folder(self):
        import calligraphy.study_report as report
        study = cg_study.load(str(self.tmp / "study"))
        out = self.tmp / self.fresh("args") / "paper"
        cases = [({"out_dir": ""}, ValueError, "out_dir"),
                 ({"out_dir": out, "keep_end_reasons": "completed"}, TypeError, "keep_end_reasons"),
                 ({"out_dir": out, "values": ("no_such_column",)}, ValueError, "no_such_column"),
                 ({"out_dir": out, "values": ("writer",)}, ValueError, "writer"),
                 ({"out_dir": out, "reference": "zzz"}, ValueError, "zzz")]
        for kw, kind, needle in cases:
            with self.subTest(kw=kw):
                with self.assertRaises(kind) as caught:
                    report.write_report(study, **kw)
                self.assertIn(needle, str(caught.exception))
                self.assertFalse(out.exists(), "a folder the report made for itself is removed when it fails")

    def test_python_report_refuses_a_tables_folder_that_is_a_link(self):
        paper = self.fresh("linkedpaper")
        outside = self.fresh("outside")
        os.symlink(self.tmp / outside, self.tmp / paper / "tables")
        result = subprocess.run([sys.executable, "-m", "calligraphy.study_report", "study", "--out", paper],
                                cwd=self.tmp, env=ENV, capture_output=True, timeout=120)
        text = result.stderr.decode()
        self.assertEqual(result.returncode, 1, text)
        self.assertNotIn("Traceback", text)
        self.assertEqual(len(error_lines(result)), 1, text)
        self.assertIn(f"{paper}/tables", text)
        self.assertEqual(os.listdir(self.tmp / outside), [])
        self.assertEqual(sorted(os.listdir(self.tmp / paper)), ["tables"])


if __name__ == "__main__":
    unittest.main()
