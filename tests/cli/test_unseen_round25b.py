#!/usr/bin/env python3
"""Round 25B: the study commands as a matrix of files and verbs. From the docs alone (README.md,
docs/experiments.md "Protocol files", "Sessions", "Trial records", "The per-trial pages", "Tidy tables";
docs/cli.md "Conventions", "Exit statuses", "corpus", "curriculum", "session run | resume", "report").

Every file `session run`, `session resume`, `report`, `curriculum` and `corpus build|stats` read or write is
forged (one value changed that passes a glance), cut (in the middle, at a line end, to 0 bytes), linked
(symbolic, dangling, hard, output = input), filled (each documented limit reached and passed by one), killed
(SIGTERM, SIGINT, SIGKILL at a random moment), raced and mislabelled (a file of another kind in its place,
another study's session moved in). Each case expects the documented outcome, or one error line naming the file
(and the pointer or option) with the documented exit status; never a file outside the study replaced, never a
study a reader takes without saying so.

Cells left out: `session cohort` (it reads only the protocol, whose cells `session run` covers, and writes a
pair of tables whose journal `report --csv` covers); a journal forged by hand (its format and checksum are
undocumented, so a forgery would be refused for its checksum alone; the file writer's tests forge them); the
study report of Python (round 24A and the Python rounds); `corpus fidelity` and `corpus validate` (no study
file); a person's session (no display here); limits whose run would take seconds (1,000 subjects and
1,000,000 trials are reached with `session plan`, which makes the same checks without writing, and passed
with `session run`).

CALLIGRAPHY_CLI names the program. CALLIGRAPHY_SANITIZED=1 takes five cases.
"""
import glob
import itertools
import json
import os
import random
import shutil
import signal
import socket
import subprocess
import tempfile
import time
import unittest
from pathlib import Path

from outsider import CLI, ENV, OneErrorLine, error_lines, run, run_ok, sanitized_subset

load_tests = sanitized_subset({"test_record_of_another_subject_is_refused_naming_it",
                               "test_session_json_cut_in_the_middle_is_refused_by_report_and_resume",
                               "test_sigkill_of_session_run_then_resume_equals_an_uninterrupted_run",
                               "test_report_output_on_a_session_json_is_refused",
                               "test_another_studys_session_moved_in_is_refused"})

PROTOCOL = {"name": "p", "conditions": [{"name": "V", "mode": "vision"}, {"name": "H", "mode": "haptic"}],
            "test": {"characters": ["一", "十"], "conditions": ["V", "H"], "repetitions": 1},
            "order": {"conditions": "latin_square"}, "trial": {"max_duration_s": 0.4}}
LONG = {**PROTOCOL, "name": "k", "test": {**PROTOCOL["test"], "repetitions": 3}}  # 12 trials, about 0.1 s
CORPUS = Path(os.environ.get("CALLIGRAPHY_CORPUS_DIR", "/nonexistent"))
# What a resumed trial must share with the same trial run straight through.
SAME_VALUES = ("samples", "mean_deviation_m", "total_time_s", "strokes_completed", "end_reason")


def tree_bytes(folder):
    """Every file under `folder` (links as links) and its bytes."""
    out = {}
    for root, dirs, files in os.walk(folder):
        for name in files + [d for d in dirs if os.path.islink(os.path.join(root, d))]:
            p = os.path.join(root, name)
            out[os.path.relpath(p, folder)] = os.readlink(p) if os.path.islink(p) else Path(p).read_bytes()
    return out


class Round25B(unittest.TestCase, OneErrorLine):
    @classmethod
    def setUpClass(cls):
        cls.tmp = Path(tempfile.mkdtemp(prefix="round25b-"))
        d = cls.tmp
        (d / "p.json").write_text(json.dumps(PROTOCOL, ensure_ascii=False), encoding="utf-8")
        (d / "k.json").write_text(json.dumps(LONG, ensure_ascii=False), encoding="utf-8")
        run_ok(["session", "run", "p.json", "--subjects", "2", "--out", "S"], d)
        run_ok(["session", "run", "p.json", "--subjects", "2", "--out", "O"], d)  # another study
        run_ok(["session", "run", "k.json", "--subjects", "1", "--out", "K"], d)  # straight through
        (d / "T").mkdir()
        run_ok(["report", "S", "--csv", "T"], d)
        cls.tables = {n: (d / "T" / n).read_bytes() for n in ("trials.csv", "strokes.csv")}
        cls.straight = cls.values_of(d / "K")
        cls.n = 0

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.tmp, ignore_errors=True)

    # --- helpers -------------------------------------------------------------------------------------------
    def fresh(self):
        """A new working folder holding a copy of the study S (hidden files and links as they are)."""
        Round25B.n += 1
        w = self.tmp / f"w{Round25B.n}"
        w.mkdir()
        shutil.copytree(self.tmp / "S", w / "S", symlinks=True)
        shutil.copy(self.tmp / "p.json", w / "p.json")
        (w / "T").mkdir()
        return w

    @staticmethod
    def session(w, subject="S01", study="S"):
        return Path(glob.glob(str(w / study / subject / f"*-{subject}-*"))[0])

    @staticmethod
    def records(session):
        return sorted((session / "trials").glob("*.json"))

    @staticmethod
    def values_of(study):
        out = {}
        for rec in sorted(glob.glob(str(Path(study) / "*" / "*" / "trials" / "*.json"))):
            r = json.loads(Path(rec).read_text(encoding="utf-8"))
            out[Path(rec).name] = {k: r[k] for k in SAME_VALUES}
        return out

    def report_csv(self, w, *dirs):
        return run(["report", *(dirs or ["S"]), "--csv", "T"], w)

    def refused_by_report(self, w, *needles, pages=False):
        args = ["report", "S", "--csv", "T", "--jobs", "1"] + (["--out", "i.html"] if pages else [])
        line = self.assert_one_error(run(args, w), 1, *needles)
        self.assertEqual(list((w / "T").iterdir()), [], "nothing written for a refused study")
        return line

    def edit_json(self, path, change):
        doc = json.loads(Path(path).read_text(encoding="utf-8"))
        change(doc)
        Path(path).write_text(json.dumps(doc, ensure_ascii=False, indent=1), encoding="utf-8")

    # --- session.json -------------------------------------------------------------------------------------
    def test_session_json_plan_forged_to_another_character_is_refused(self):
        w = self.fresh()
        s = self.session(w)
        self.edit_json(s / "session.json", lambda d: d["plan"][0].update(characters="十"))
        self.refused_by_report(w, "session.json", "/plan/0")

    def test_session_json_plan_file_naming_outside_its_folder_is_refused(self):
        w = self.fresh()
        s = self.session(w)
        self.edit_json(s / "session.json", lambda d: d["plan"][0].update(file="../../../x"))
        self.refused_by_report(w, "session.json", "/plan/0/file")
        self.assert_one_error(run(["session", "resume", s], w), 2, "session.json", "/plan/0/file")
        self.assertFalse((w / "x.json").exists())

    def test_session_json_study_id_forged_is_refused(self):
        w = self.fresh()
        self.edit_json(self.session(w) / "session.json", lambda d: d.update(study_id="0" * 32))
        self.refused_by_report(w, "session.json", "/study_id")

    def test_session_json_subject_forged_to_the_other_subject_is_refused(self):
        w = self.fresh()
        self.edit_json(self.session(w) / "session.json", lambda d: d["subject"].update(id="S02", number=2))
        self.refused_by_report(w, "S01")

    def test_session_json_group_forged_is_refused(self):
        w = self.fresh()
        self.edit_json(self.session(w) / "session.json", lambda d: d.update(group="g"))
        self.refused_by_report(w, "session.json", "/group")

    def test_session_json_protocol_text_forged_is_refused_by_resume(self):
        w = self.fresh()
        s = self.session(w)
        (s / "trials" / self.records(s)[-1].name).unlink()
        self.edit_json(s / "session.json",
                       lambda d: d["protocol"].update(text=d["protocol"]["text"].replace("0.4", "0.5")))
        before = tree_bytes(s)
        self.assert_one_error(run(["session", "resume", s], w), (1, 2), "session.json")
        self.assertEqual(tree_bytes(s), before)

    def test_session_json_key_twice_is_refused_by_resume(self):
        w = self.fresh()
        s = self.session(w)
        text = (s / "session.json").read_text(encoding="utf-8")
        (s / "session.json").write_text(text.replace('"pacing"', '"pacing": "auto", "pacing"', 1),
                                        encoding="utf-8")
        self.assert_one_error(run(["session", "resume", s], w), 2, "session.json", "pacing")

    def test_session_json_cut_in_the_middle_is_refused_by_report_and_resume(self):
        w = self.fresh()
        s = self.session(w)
        data = (s / "session.json").read_bytes()
        (s / "session.json").write_bytes(data[:len(data) // 2])
        self.refused_by_report(w, "session.json")
        self.assert_one_error(run(["session", "resume", s], w), 2, "session.json")

    def test_session_json_cut_at_a_line_end_is_refused(self):
        w = self.fresh()
        s = self.session(w)
        data = (s / "session.json").read_bytes()
        (s / "session.json").write_bytes(data[:data.index(b"\n", len(data) // 3) + 1])
        self.refused_by_report(w, "session.json")

    def test_session_json_of_0_bytes_is_refused_by_report_and_resume(self):
        w = self.fresh()
        s = self.session(w)
        (s / "session.json").write_bytes(b"")
        self.refused_by_report(w, "session.json")
        self.assert_one_error(run(["session", "resume", s], w), 2, "session.json")

    def test_session_json_as_a_symbolic_link_is_refused(self):
        w = self.fresh()
        s = self.session(w)
        shutil.move(s / "session.json", w / "kept.json")
        os.symlink(w / "kept.json", s / "session.json")
        self.refused_by_report(w, "session.json", "symbolic link")
        self.assert_one_error(run(["session", "resume", s], w), 2, "session.json", "symbolic link")

    def test_session_json_dangling_link_is_refused(self):
        w = self.fresh()
        s = self.session(w)
        (s / "session.json").unlink()
        os.symlink(w / "missing.json", s / "session.json")
        self.refused_by_report(w, "session.json")

    def test_record_in_place_of_session_json_is_refused(self):
        w = self.fresh()
        s = self.session(w)
        shutil.copy(self.records(s)[0], s / "session.json")
        self.refused_by_report(w, "session.json")
        self.assert_one_error(run(["session", "resume", s], w), 2, "session.json")

    def test_protocol_in_place_of_session_json_is_refused(self):
        w = self.fresh()
        s = self.session(w)
        shutil.copy(w / "p.json", s / "session.json")
        self.refused_by_report(w, "session.json")

    # --- trial records ------------------------------------------------------------------------------------
    def test_record_of_another_subject_is_refused_naming_it(self):
        w = self.fresh()
        rec = self.records(self.session(w))[0]
        self.edit_json(rec, lambda d: d.update(subject="S02", subject_number=2))
        self.refused_by_report(w, rec.name, "/subject")

    def test_record_of_another_condition_is_refused_naming_it(self):
        w = self.fresh()
        rec = self.records(self.session(w))[0]  # 001-test-V-...
        self.edit_json(rec, lambda d: d.update(condition="H", mode="haptic"))
        self.refused_by_report(w, rec.name)

    def test_record_of_another_mode_is_refused_naming_it(self):
        w = self.fresh()
        rec = self.records(self.session(w))[0]  # 001-test-V-...: vision
        self.edit_json(rec, lambda d: d.update(mode="haptic"))
        self.refused_by_report(w, rec.name, "/mode")

    def test_record_of_another_trial_index_is_refused_naming_it(self):
        w = self.fresh()
        rec = self.records(self.session(w))[0]
        self.edit_json(rec, lambda d: d["trial"].update(index=2))
        self.refused_by_report(w, rec.name, "/trial")

    def test_record_trace_sha256_forged_is_refused_by_the_pages(self):
        w = self.fresh()
        rec = self.records(self.session(w))[0]
        self.edit_json(rec, lambda d: d["files"].update(trace_sha256="0" * 64))
        self.refused_by_report(w, rec.stem, pages=True)
        self.assertFalse((w / "i.html").exists())

    def test_trace_with_a_byte_changed_is_refused_by_the_pages(self):
        w = self.fresh()
        trace = sorted((self.session(w) / "trials").glob("*.trace.h5"))[0]
        data = bytearray(trace.read_bytes())
        data[len(data) // 2] ^= 0x55
        trace.write_bytes(bytes(data))
        self.refused_by_report(w, trace.name, pages=True)

    def test_record_cut_in_the_middle_is_refused(self):
        w = self.fresh()
        rec = self.records(self.session(w))[1]
        data = rec.read_bytes()
        rec.write_bytes(data[:len(data) // 2])
        self.refused_by_report(w, rec.name)

    def test_record_cut_at_a_line_end_is_refused(self):
        w = self.fresh()
        rec = self.records(self.session(w))[1]
        data = rec.read_bytes()
        rec.write_bytes(data[:data.index(b"\n", len(data) // 2) + 1])
        self.refused_by_report(w, rec.name)

    def test_record_of_0_bytes_is_refused_by_report_and_resume_and_kept(self):
        w = self.fresh()
        s = self.session(w)
        rec = self.records(s)[1]
        rec.write_bytes(b"")
        self.refused_by_report(w, rec.name)
        self.assert_one_error(run(["session", "resume", s], w), (1, 2), rec.name)
        self.assertEqual(rec.read_bytes(), b"", "a saved trial is never written again")

    def test_trace_cut_in_the_middle_is_refused_by_the_pages(self):
        w = self.fresh()
        trace = sorted((self.session(w) / "trials").glob("*.trace.h5"))[1]
        data = trace.read_bytes()
        trace.write_bytes(data[:len(data) // 2])
        self.refused_by_report(w, trace.name, pages=True)

    def test_record_as_a_symbolic_link_is_refused(self):
        w = self.fresh()
        rec = self.records(self.session(w))[0]
        shutil.move(rec, w / "kept.json")
        os.symlink(w / "kept.json", rec)
        self.refused_by_report(w, rec.name, "symbolic link")

    def test_trace_as_a_symbolic_link_is_refused(self):
        w = self.fresh()
        trace = sorted((self.session(w) / "trials").glob("*.trace.h5"))[0]
        shutil.move(trace, w / "kept.h5")
        os.symlink(w / "kept.h5", trace)
        self.refused_by_report(w, trace.name, "symbolic link", pages=True)

    def test_record_hard_linked_from_the_other_session_is_refused(self):
        w = self.fresh()
        one, two = self.session(w, "S01"), self.session(w, "S02")
        # S01's trial 1 (V, 一) and S02's trial 3 (V, 一): one condition and character, two subjects.
        src = self.records(one)[0]
        dst = next(r for r in self.records(two) if r.name.startswith("003-"))
        dst.unlink()
        os.link(src, dst)
        self.refused_by_report(w, dst.name)

    def test_session_json_in_place_of_a_record_is_refused(self):
        w = self.fresh()
        s = self.session(w)
        rec = self.records(s)[2]
        shutil.copy(s / "session.json", rec)
        self.refused_by_report(w, rec.name)

    def test_csv_trace_in_place_of_the_hdf5_trace_is_refused(self):
        w = self.fresh()
        trace = sorted((self.session(w) / "trials").glob("*.trace.h5"))[0]
        csv = run_ok(["trace", trace], w).stdout
        trace.write_bytes(csv)
        self.refused_by_report(w, trace.name, pages=True)

    def test_record_copied_in_that_the_plan_lacks_is_refused(self):
        w = self.fresh()
        s = self.session(w)
        rec = self.records(s)[0]
        shutil.copy(rec, s / "trials" / "005-test-V-r2-U4E00.json")
        self.refused_by_report(w, "005-test-V-r2-U4E00.json", "/plan")

    def test_removed_trial_is_run_again_by_resume_to_the_same_values(self):
        w = self.fresh()
        s = self.session(w)
        last = self.records(s)[-1]
        before = json.loads(last.read_text(encoding="utf-8"))
        others = {r.name: r.read_bytes() for r in self.records(s)[:-1]}
        for f in (s / "trials").glob(last.stem + ".*"):
            f.unlink()
        run_ok(["session", "resume", s], w)
        after = json.loads(last.read_text(encoding="utf-8"))
        self.assertEqual({k: after[k] for k in SAME_VALUES}, {k: before[k] for k in SAME_VALUES})
        self.assertEqual({r.name: r.read_bytes() for r in self.records(s)[:-1]}, others)

    # --- the log ------------------------------------------------------------------------------------------
    def test_log_torn_mid_line_is_completed_by_resume_and_kept_before(self):
        w = self.fresh()
        s = self.session(w)
        data = (s / "log.jsonl").read_bytes()
        cut = data[:data.rindex(b"\n", 0, len(data) - 1) + 10]  # the last line torn after 9 bytes
        (s / "log.jsonl").write_bytes(cut)
        run_ok(["session", "resume", s], w)
        now = (s / "log.jsonl").read_bytes()
        self.assertTrue(now.startswith(cut), "the log is append-only")
        self.assertEqual(json.loads(now.splitlines()[-1])["event"], "session_completed")

    def test_log_of_0_bytes_leaves_the_report_as_before(self):
        w = self.fresh()
        (self.session(w) / "log.jsonl").write_bytes(b"")
        run_ok(["report", "S", "--csv", "T"], w)
        self.assertEqual((w / "T" / "trials.csv").read_bytes().count(b"\n"),
                         self.tables["trials.csv"].count(b"\n"))

    def test_log_as_a_symbolic_link_is_refused_by_resume_and_its_target_kept(self):
        w = self.fresh()
        s = self.session(w)
        (s / "trials" / self.records(s)[-1].name).unlink()
        shutil.move(s / "log.jsonl", w / "outside.log")
        os.symlink(w / "outside.log", s / "log.jsonl")
        before = (w / "outside.log").read_bytes()
        self.assert_one_error(run(["session", "resume", s], w), 2, "log.jsonl", "symbolic link")
        self.assertEqual((w / "outside.log").read_bytes(), before)

    def test_log_hard_linked_by_a_copied_study_leaves_the_original_unchanged(self):
        w = self.fresh()
        subprocess.run(["cp", "-al", str(w / "S"), str(w / "C")], check=True)
        s = self.session(w, study="C")
        last = self.records(s)[-1]
        for f in (s / "trials").glob(last.stem + ".*"):
            f.unlink()
        original = self.session(w) / "log.jsonl"
        before = original.read_bytes()
        run_ok(["session", "resume", s], w)
        self.assertEqual(original.read_bytes(), before)
        self.assertTrue((s / "log.jsonl").read_bytes().startswith(before))
        self.assertTrue(self.records(self.session(w))[-1].exists())

    # --- the protocol -------------------------------------------------------------------------------------
    def test_protocol_seed_forged_after_a_run_is_refused_naming_both(self):
        w = self.fresh()
        self.edit_json(w / "p.json", lambda d: d["order"].update(seed=1))
        before = tree_bytes(w / "S")
        self.assert_one_error(run(["session", "run", "p.json", "--subjects", "1", "--new-subjects",
                                   "--out", "S"], w), 1, "p.json", "'p'")
        self.assertEqual(tree_bytes(w / "S"), before)

    def test_protocol_cut_in_the_middle_is_refused_before_anything(self):
        w = self.fresh()
        data = (w / "p.json").read_bytes()
        (w / "p.json").write_bytes(data[:len(data) // 2])
        self.assert_one_error(run(["session", "run", "p.json", "--subjects", "1", "--out", "N"], w), 2,
                              "p.json")
        self.assertFalse((w / "N").exists())

    def test_protocol_of_0_bytes_is_refused(self):
        w = self.fresh()
        (w / "p.json").write_bytes(b"")
        self.assert_one_error(run(["session", "run", "p.json", "--subjects", "1", "--out", "N"], w), 2,
                              "p.json")
        self.assertFalse((w / "N").exists())

    def test_protocol_given_through_a_symbolic_link_runs(self):
        w = self.fresh()
        os.symlink(w / "p.json", w / "link.json")
        run_ok(["session", "run", "link.json", "--subjects", "1", "--out", "N"], w)
        self.assertEqual(len(self.records(self.session(w, study="N"))), 4)

    def test_record_given_as_a_protocol_is_refused(self):
        w = self.fresh()
        rec = self.records(self.session(w))[0]
        self.assert_one_error(run(["session", "run", rec, "--subjects", "1", "--out", "N"], w), 2, rec.name)
        self.assertFalse((w / "N").exists())

    def test_session_json_given_as_a_protocol_is_refused(self):
        w = self.fresh()
        sj = self.session(w) / "session.json"
        self.assert_one_error(run(["session", "run", sj, "--subjects", "1", "--out", "N"], w), 2,
                              "session.json")
        self.assertFalse((w / "N").exists())

    # --- fill: each limit reached and passed by one ------------------------------------------------------
    def plan(self, w, protocol, *args):
        (w / "q.json").write_text(json.dumps(protocol, ensure_ascii=False), encoding="utf-8")
        return run(["session", "plan", "q.json", *args], w)

    def test_protocol_name_of_64_plans_and_of_65_is_refused(self):
        w = self.fresh()
        self.assertEqual(self.plan(w, {**PROTOCOL, "name": "n" * 64}, "--subjects", "1").returncode, 0)
        self.assert_one_error(self.plan(w, {**PROTOCOL, "name": "n" * 65}, "--subjects", "1"), 2,
                              "q.json", "/name")

    def test_26_conditions_plan_and_27_are_refused(self):
        w = self.fresh()

        def conditions(n):
            names = [f"c{i}" for i in range(n)]
            return {**PROTOCOL, "conditions": [{"name": c, "mode": "vision"} for c in names],
                    "test": {**PROTOCOL["test"], "conditions": names}}
        self.assertEqual(self.plan(w, conditions(26), "--subjects", "1").returncode, 0)
        self.assert_one_error(self.plan(w, conditions(27), "--subjects", "1"), 2, "q.json", "/conditions")

    def test_1000_test_strings_plan_and_1001_are_refused(self):
        w = self.fresh()
        strings = ["".join(t) for n in range(1, 11) for t in itertools.product("一十", repeat=n)]

        def items(n):
            return {**PROTOCOL, "test": {**PROTOCOL["test"], "characters": strings[:n], "conditions": ["V"]}}
        self.assertEqual(self.plan(w, items(1000), "--subjects", "1").returncode, 0)
        self.assert_one_error(self.plan(w, items(1001), "--subjects", "1"), 2, "q.json", "/test/characters")

    def test_repetitions_1000_plan_and_1001_are_refused(self):
        w = self.fresh()

        def reps(n):
            return {**PROTOCOL, "test": {**PROTOCOL["test"], "repetitions": n}}
        self.assertEqual(self.plan(w, reps(1000), "--subjects", "1").returncode, 0)
        self.assert_one_error(self.plan(w, reps(1001), "--subjects", "1"), 2, "q.json", "/test/repetitions")

    def test_1000_subjects_plan_and_1001_are_refused_by_run(self):
        w = self.fresh()
        self.assertEqual(self.plan(w, PROTOCOL, "--subjects", "1000").returncode, 0)
        self.assert_one_error(run(["session", "run", "p.json", "--subjects", "1001", "--out", "N"], w), 2,
                              "--subjects")
        self.assertFalse((w / "N").exists())

    def test_subject_id_of_64_runs_and_of_65_is_refused(self):
        w = self.fresh()
        run_ok(["session", "run", "p.json", "--subject", "s" * 63 + "1", "--out", "N"], w)
        self.assert_one_error(run(["session", "run", "p.json", "--subject", "s" * 64 + "1", "--out", "M"], w),
                              2, "--subject")
        self.assertFalse((w / "M").exists())

    def test_max_duration_times_rate_at_the_tick_limit_plans_and_past_it_is_refused(self):
        w = self.fresh()

        def trial(s):
            return {**PROTOCOL, "trial": {"max_duration_s": s, "rate_hz": 1000}}
        self.assertEqual(self.plan(w, trial(10000), "--subjects", "1").returncode, 0)
        self.assert_one_error(self.plan(w, trial(10000.001), "--subjects", "1"), 2, "q.json", "/trial")

    def test_curriculum_count_1000_and_1001(self):
        w = self.fresh()
        ok = run(["curriculum", "S", "--subject", "S01", "--from", "大天木", "--count", "1000"], w)
        self.assertEqual(ok.returncode, 0, ok.stderr)
        self.assert_one_error(run(["curriculum", "S", "--subject", "S01", "--from", "大天木", "--count", "1001"],
                                  w), 2, "--count")

    # --- kill ---------------------------------------------------------------------------------------------
    def kill_then_finish(self, sig, lo=0.0, hi=0.08):
        w = self.fresh()
        shutil.copy(self.tmp / "k.json", w / "k.json")
        proc = subprocess.Popen([CLI, "session", "run", "k.json", "--subjects", "1", "--out", "K"], cwd=w,
                                env=ENV, stdout=subprocess.PIPE, stderr=subprocess.PIPE)
        # A signal before main() has run kills any program; the run's lock names it once it runs.
        lock = w / "K" / ".calligraphy-run.lock"
        deadline = time.monotonic() + 30
        while proc.poll() is None and time.monotonic() < deadline and not (lock.exists() and lock.stat().st_size):
            time.sleep(0.002)
        time.sleep(random.uniform(lo, hi))
        proc.send_signal(sig)
        out, err = proc.communicate(timeout=60)
        self.assertNotIn(b"terminate called", err)
        if sig != signal.SIGKILL:
            self.assertIn(proc.returncode, (0, 128 + sig), err)
        sessions = glob.glob(str(w / "K" / "S01" / "k-S01-*"))
        if sessions:
            run_ok(["session", "resume", sessions[0]], w)
        else:  # killed before the folder was renamed into place: the next run starts it
            run_ok(["session", "run", "k.json", "--subjects", "1", "--out", "K"], w)
        s = self.session(w, study="K")
        self.assertEqual(self.values_of(w / "K"), self.straight)
        self.assertEqual([p for p in (s / "trials").iterdir() if ".part" in p.name or ".tmp" in p.name], [])
        self.assertEqual(glob.glob(str(w / "K" / "S01" / ".partial.*")), [])
        events = [json.loads(x)["event"] for x in (s / "log.jsonl").read_text().splitlines()
                  if x.startswith("{") and x.endswith("}")]
        self.assertEqual(events[-1], "session_completed")
        self.assertEqual(events.count("trial_saved"), 12)
        return w

    def test_sigterm_of_session_run_then_resume_equals_an_uninterrupted_run(self):
        self.kill_then_finish(signal.SIGTERM)

    def test_sigint_of_session_run_then_resume_equals_an_uninterrupted_run(self):
        self.kill_then_finish(signal.SIGINT)

    def test_sigkill_of_session_run_then_resume_equals_an_uninterrupted_run(self):
        self.kill_then_finish(signal.SIGKILL)

    def kill_report(self, sig):
        w = self.fresh()
        (w / "T" / "trials.csv").write_bytes(b"old")
        (w / "T" / "strokes.csv").write_bytes(b"old")
        proc = subprocess.Popen([CLI, "report", "S", "--csv", "T", "--out", "i.html", "--jobs", "1"], cwd=w,
                                env=ENV, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
        time.sleep(random.uniform(0.0, 0.06))
        proc.send_signal(sig)
        err = proc.communicate(timeout=60)[1]
        self.assertNotIn(b"terminate called", err)
        pair = ((w / "T" / "trials.csv").read_bytes(), (w / "T" / "strokes.csv").read_bytes())
        # A reader finds the earlier pair or the new one (a journal may complete it at the next run).
        self.assertIn(pair, [(b"old", b"old"), (self.tables["trials.csv"], self.tables["strokes.csv"])])
        run_ok(["report", "S", "--csv", "T", "--out", "i.html"], w)
        self.assertEqual((w / "T" / "trials.csv").read_bytes(), self.tables["trials.csv"])
        self.assertEqual((w / "T" / "strokes.csv").read_bytes(), self.tables["strokes.csv"])
        self.assertEqual(sorted(p.name for p in (w / "T").iterdir()), ["strokes.csv", "trials.csv"])

    def test_sigkill_of_report_leaves_a_pair_and_the_rerun_completes(self):
        self.kill_report(signal.SIGKILL)

    def test_sigterm_of_report_leaves_a_pair_and_the_rerun_completes(self):
        self.kill_report(signal.SIGTERM)

    def corpus_data(self, w):
        (w / "cd").mkdir()
        for c in "一十":
            shutil.copy(CORPUS / f"{c}.json", w / "cd" / f"{c}.json")

    @unittest.skipUnless((CORPUS / "一.json").is_file(), "CALLIGRAPHY_CORPUS_DIR with hanzi-writer-data")
    def test_sigkill_of_corpus_build_keeps_the_earlier_store(self):
        w = self.fresh()
        self.corpus_data(w)
        (w / "st.bin").write_bytes(b"earlier")
        proc = subprocess.Popen([CLI, "corpus", "build", "--data", "cd", "--out", "st.bin", "--threads", "1"],
                                cwd=w, env=ENV, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
        time.sleep(random.uniform(0.0, 0.03))
        proc.kill()
        proc.communicate(timeout=60)
        now = (w / "st.bin").read_bytes()
        run_ok(["corpus", "build", "--data", "cd", "--out", "st2.bin", "--threads", "1"], w)
        self.assertIn(now, (b"earlier", (w / "st2.bin").read_bytes()))

    # --- race ---------------------------------------------------------------------------------------------
    def test_two_runs_of_the_same_subject_at_once_make_one_session(self):
        w = self.fresh()
        shutil.copy(self.tmp / "k.json", w / "k.json")
        args = [CLI, "session", "run", "k.json", "--subject", "S01", "--out", "R"]
        procs = [subprocess.Popen(args, cwd=w, env=ENV, stdout=subprocess.PIPE, stderr=subprocess.PIPE)
                 for _ in range(2)]
        results = [(p.wait(timeout=60), p.stderr.read()) for p in procs]
        for p in procs:
            p.stdout.close()
            p.stderr.close()
        self.assertEqual(sorted(r[0] for r in results)[0], 0, results)
        for status, err in results:
            self.assertIn(status, (0, 1, 2), err)
            self.assertNotIn(b"terminate called", err)
        self.assertEqual(len(glob.glob(str(w / "R" / "S01" / "k-S01-*"))), 1)
        self.assertEqual(self.values_of(w / "R"), self.straight)

    def test_report_while_session_run_writes_reads_whole_trials_or_says_why(self):
        w = self.fresh()
        shutil.copy(self.tmp / "k.json", w / "k.json")
        proc = subprocess.Popen([CLI, "session", "run", "k.json", "--subjects", "1", "--out", "R"], cwd=w,
                                env=ENV, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        seen, tries = [], 0
        while proc.poll() is None and tries < 4:  # four reports at most while it writes (the CPU budget)
            tries += 1
            r = run(["report", "R", "--csv", "T", "--jobs", "1"], w)
            self.assertNotIn(b"terminate called", r.stderr)
            if r.returncode == 0:
                rows = (w / "T" / "trials.csv").read_text(encoding="utf-8").count("\n") - 1
                self.assertLessEqual(rows, 12)
                seen.append(rows)
            else:
                self.assertEqual(len(error_lines(r)), 1, r.stderr)
        self.assertEqual(proc.wait(), 0)
        run_ok(["report", "R", "--csv", "T"], w)
        self.assertEqual((w / "T" / "trials.csv").read_text(encoding="utf-8").count("\n") - 1, 12)
        self.assertEqual(seen, sorted(seen))

    def test_resume_twice_at_once_saves_each_trial_once(self):
        w = self.fresh()
        s = self.session(w)
        for rec in self.records(s)[1:]:
            for f in (s / "trials").glob(rec.stem + ".*"):
                f.unlink()
        procs = [subprocess.Popen([CLI, "session", "resume", str(s)], cwd=w, env=ENV, stdout=subprocess.PIPE,
                                  stderr=subprocess.PIPE) for _ in range(2)]
        results = [(p.wait(timeout=60), p.communicate()[1]) for p in procs]
        self.assertIn(0, [r[0] for r in results], results)
        for status, err in results:
            self.assertIn(status, (0, 1), err)
            if status == 1:
                self.assertEqual(len(err.decode().strip().splitlines()), 1, err)
        self.assertEqual(len(self.records(s)), 4)
        saved = [e["file"][:3] for e in map(json.loads, (s / "log.jsonl").read_text().splitlines())
                 if e["event"] == "trial_saved"]
        # trial 1 saved by the first run, 2 to 4 by that run and again by one resume, never by both resumes
        self.assertEqual({f: saved.count(f) for f in saved}, {"001": 1, "002": 2, "003": 2, "004": 2})

    # --- report outputs -----------------------------------------------------------------------------------
    def test_report_output_on_a_session_json_is_refused(self):
        w = self.fresh()
        sj = self.session(w) / "session.json"
        before = sj.read_bytes()
        self.assert_one_error(run(["report", "S", "--out", sj], w), 2, "--out")
        self.assertEqual(sj.read_bytes(), before)
        self.assertFalse((sj.parent / "session_files").exists())

    def test_report_output_through_a_link_to_a_record_is_refused(self):
        w = self.fresh()
        rec = self.records(self.session(w))[0]
        before = rec.read_bytes()
        os.symlink(rec, w / "r.html")
        self.assert_one_error(run(["report", "S", "--out", "r.html"], w), 2, "--out")
        self.assertEqual(rec.read_bytes(), before)
        self.assertTrue(os.path.islink(w / "r.html"))

    def test_report_output_hard_linked_to_a_log_is_refused(self):
        w = self.fresh()
        log = self.session(w) / "log.jsonl"
        before = log.read_bytes()
        os.link(log, w / "h.html")
        self.assert_one_error(run(["report", "S", "--out", "h.html"], w), 2, "--out")
        self.assertEqual(log.read_bytes(), before)

    def test_report_csv_folder_inside_a_session_leaves_its_files(self):
        w = self.fresh()
        s = self.session(w)
        before = tree_bytes(s)
        r = run(["report", "S", "--csv", s / "trials"], w)
        if r.returncode == 0:  # the tables beside the records: the records themselves untouched
            now = tree_bytes(s)
            self.assertEqual({k: v for k, v in now.items() if k in before}, before)
            self.assertEqual(sorted(set(now) - set(before)), ["trials/strokes.csv", "trials/trials.csv"])
        else:
            self.assert_one_error(r, 2, "--csv")
            self.assertEqual(tree_bytes(s), before)

    def test_report_pages_folder_as_a_link_out_of_its_folder(self):
        w = self.fresh()
        (w / "elsewhere").mkdir()
        (w / "R").mkdir()
        os.symlink(w / "elsewhere", w / "R" / "i_files")
        r = run(["report", "S", "--out", "R/i.html"], w)
        if r.returncode == 0:
            self.assertTrue(os.path.islink(w / "R" / "i_files") or (w / "R" / "i_files").is_dir())
        else:
            self.assert_one_error(r, (1, 2), "i_files")
        self.assertEqual(list((w / "elsewhere").iterdir()) if r.returncode else [], [])

    # --- the study identity and the folders ---------------------------------------------------------------
    def test_identity_file_forged_is_refused(self):
        w = self.fresh()
        self.edit_json(w / "S" / ".calligraphy-study.json", lambda d: d.update(study_id="1" * 32))
        self.refused_by_report(w, "/study_id")

    def test_identity_file_of_0_bytes_is_refused(self):
        w = self.fresh()
        (w / "S" / ".calligraphy-study.json").write_bytes(b"")
        self.refused_by_report(w, ".calligraphy-study.json")

    def test_identity_file_cut_in_the_middle_is_refused(self):
        w = self.fresh()
        p = w / "S" / ".calligraphy-study.json"
        p.write_bytes(p.read_bytes()[:40])
        self.refused_by_report(w, ".calligraphy-study.json")

    def test_identity_file_left_out_of_a_copy_is_refused(self):
        w = self.fresh()
        (w / "S" / ".calligraphy-study.json").unlink()
        self.refused_by_report(w, "/study_id", ".calligraphy-study.json")

    def test_record_in_place_of_the_identity_file_is_refused(self):
        w = self.fresh()
        shutil.copy(self.records(self.session(w))[0], w / "S" / ".calligraphy-study.json")
        self.refused_by_report(w, ".calligraphy-study.json")

    def test_another_studys_session_moved_in_is_refused(self):
        w = self.fresh()
        other = self.session(Path(self.tmp), "S01", study="O")
        (w / "S" / "S03").mkdir()
        shutil.copytree(other, w / "S" / "S03" / other.name.replace("S01", "S03"))
        self.refused_by_report(w)

    def test_another_studys_session_of_the_same_subject_is_refused(self):
        w = self.fresh()
        other = self.session(Path(self.tmp), "S02", study="O")
        shutil.rmtree(self.session(w, "S02"))
        shutil.copytree(other, w / "S" / "S02" / other.name)
        self.refused_by_report(w, "/study_id")
        self.assert_one_error(run(["session", "resume", self.session(w, "S02")], w), 1, "/study_id")

    def test_session_folder_renamed_is_refused(self):
        w = self.fresh()
        s = self.session(w)
        s.rename(s.parent / (s.name[:-1] + ("1" if s.name[-1] != "1" else "2")))
        self.refused_by_report(w, "/session")

    def test_subject_folder_linked_from_another_study_is_refused(self):
        w = self.fresh()
        os.symlink(self.tmp / "O" / "S02", w / "S" / "S09")
        self.refused_by_report(w, "S09")

    def test_link_back_to_the_study_itself_is_refused(self):
        w = self.fresh()
        os.symlink(w / "S", w / "S" / "S01" / "again")
        self.refused_by_report(w, "again")

    def test_dangling_link_in_the_study_is_passed_over_or_named(self):
        w = self.fresh()
        os.symlink(w / "gone", w / "S" / "S05")
        r = self.report_csv(w)
        if r.returncode == 0:
            self.assertEqual((w / "T" / "trials.csv").read_bytes(), self.tables["trials.csv"])
        else:
            self.assert_one_error(r, 1, "S05")

    def test_trials_folder_as_a_link_is_refused_by_resume(self):
        w = self.fresh()
        s = self.session(w)
        shutil.move(s / "trials", w / "trials-elsewhere")
        os.symlink(w / "trials-elsewhere", s / "trials")
        for f in (w / "trials-elsewhere").glob("004-*"):
            f.unlink()
        before = tree_bytes(w / "trials-elsewhere")
        self.assert_one_error(run(["session", "resume", s], w), 2, "trials")
        self.assertEqual(tree_bytes(w / "trials-elsewhere"), before)

    def test_session_given_through_a_link_is_reported_under_its_own_name(self):
        w = self.fresh()
        s = self.session(w)
        os.symlink(s, w / "alias")
        run_ok(["report", "alias", "--csv", "T"], w)
        text = (w / "T" / "trials.csv").read_text(encoding="utf-8")
        self.assertIn(s.name, text)
        self.assertNotIn(",alias,", text)

    def test_half_made_session_is_skipped_by_report_and_named_by_resume(self):
        w = self.fresh()
        s = self.session(w, "S02")
        half = s.parent / f".partial.999999.nohost.{s.name}-2"
        half.mkdir()
        shutil.copy(s / "session.json", half / "session.json")
        run_ok(["report", "S", "--csv", "T"], w)
        self.assertEqual((w / "T" / "trials.csv").read_bytes(), self.tables["trials.csv"])
        self.assert_one_error(run(["session", "resume", half], w), (1, 2), ".partial.")

    def test_record_part_left_by_a_kill_is_removed_by_resume(self):
        w = self.fresh()
        s = self.session(w)
        last = self.records(s)[-1]
        for f in (s / "trials").glob(last.stem + ".*"):
            f.unlink()
        (s / "trials" / (last.name + ".part")).write_bytes(b'{"format": "calligraphy-study-tri')
        run_ok(["session", "resume", s], w)
        self.assertTrue(last.exists())
        self.assertEqual([p.name for p in (s / "trials").iterdir() if ".part" in p.name], [])

    def test_half_made_session_of_a_gone_process_is_removed_by_the_next_run(self):
        w = self.fresh()
        (w / "S" / "S03").mkdir()
        half = w / "S" / "S03" / f".partial.999999.{socket.gethostname()}.p-S03-20260101-000000"
        half.mkdir()
        (half / "session.json").write_bytes(b"{")
        run_ok(["session", "run", "p.json", "--subjects", "1", "--new-subjects", "--out", "S"], w)
        self.assertFalse(half.exists())
        self.assertEqual(len(self.records(self.session(w, "S03"))), 4)

    def test_identity_temporary_of_a_gone_process_is_removed_and_the_identity_kept(self):
        w = self.fresh()
        identity = (w / "S" / ".calligraphy-study.json").read_bytes()
        tmp = w / "S" / "..calligraphy-study.json.tmp-999999-1"
        tmp.write_bytes(b'{"format": "calligraphy-study", "version": 1, "study_id": "00')
        run_ok(["session", "run", "p.json", "--subjects", "1", "--new-subjects", "--out", "S"], w)
        self.assertFalse(tmp.exists())
        self.assertEqual((w / "S" / ".calligraphy-study.json").read_bytes(), identity)

    def test_run_lock_file_left_by_a_killed_run_does_not_block(self):
        w = self.fresh()
        (w / "S" / ".calligraphy-run.lock").write_text("999999 calligraphy session run p.json\n")
        run_ok(["session", "run", "p.json", "--subjects", "1", "--new-subjects", "--out", "S"], w)
        self.assertEqual(len(self.records(self.session(w, "S03"))), 4)

    def test_condition_name_of_32_plans_and_of_33_is_refused(self):
        w = self.fresh()

        def named(n):
            return {**PROTOCOL, "conditions": [{"name": "c" * n, "mode": "vision"}],
                    "test": {**PROTOCOL["test"], "conditions": ["c" * n]}}
        self.assertEqual(self.plan(w, named(32), "--subjects", "1").returncode, 0)
        self.assert_one_error(self.plan(w, named(33), "--subjects", "1"), 2, "q.json", "/conditions/0/name")

    def test_breaks_every_100000_trials_plans_and_100001_is_refused(self):
        w = self.fresh()

        def every(n):
            return {**PROTOCOL, "breaks": {"every_trials": n, "duration_s": 1}}
        self.assertEqual(self.plan(w, every(100000), "--subjects", "1").returncode, 0)
        self.assert_one_error(self.plan(w, every(100001), "--subjects", "1"), 2, "q.json",
                              "/breaks/every_trials")

    def test_record_given_to_report_as_a_study_folder_is_refused(self):
        w = self.fresh()
        rec = self.records(self.session(w))[0]
        self.assert_one_error(run(["report", rec, "--csv", "T"], w), (1, 2), rec.name)
        self.assertEqual(list((w / "T").iterdir()), [])

    # --- curriculum ---------------------------------------------------------------------------------------
    def test_curriculum_refuses_a_forged_record(self):
        w = self.fresh()
        rec = self.records(self.session(w))[0]
        self.edit_json(rec, lambda d: d.update(subject="S02"))
        self.assert_one_error(run(["curriculum", "S", "--subject", "S01", "--from", "大天"], w), 1, rec.name)

    def test_curriculum_on_a_folder_without_sessions_names_it(self):
        w = self.fresh()
        (w / "empty").mkdir()
        self.assert_one_error(run(["curriculum", "empty", "--subject", "S01", "--from", "大天"], w), 1,
                              "empty")

    def test_curriculum_of_a_subject_without_trials_is_a_usage_error(self):
        w = self.fresh()
        self.assert_one_error(run(["curriculum", "S", "--subject", "S07", "--from", "大天"], w), 2, "S07")

    # --- corpus store -------------------------------------------------------------------------------------
    @unittest.skipUnless((CORPUS / "一.json").is_file(), "CALLIGRAPHY_CORPUS_DIR with hanzi-writer-data")
    def test_corpus_store_cut_and_emptied_is_refused_by_stats(self):
        w = self.fresh()
        self.corpus_data(w)
        run_ok(["corpus", "build", "--data", "cd", "--out", "st.bin", "--threads", "1"], w)
        data = (w / "st.bin").read_bytes()
        for cut in (data[:len(data) // 2], b""):
            (w / "cut.bin").write_bytes(cut)
            r = run(["corpus", "stats", "cut.bin"], w)
            self.assertEqual(r.returncode, 1, r.stderr)
            self.assertIn("cut.bin", r.stderr.decode())
            self.assertNotIn(b"terminate called", r.stderr)

    def test_record_given_to_corpus_stats_is_refused(self):
        w = self.fresh()
        rec = self.records(self.session(w))[0]
        self.assert_one_error(run(["corpus", "stats", rec], w), 1, rec.name)

    @unittest.skipUnless((CORPUS / "一.json").is_file(), "CALLIGRAPHY_CORPUS_DIR with hanzi-writer-data")
    def test_record_mislabelled_as_a_character_file_is_named_and_the_others_stored(self):
        w = self.fresh()
        self.corpus_data(w)
        shutil.copy(self.records(self.session(w))[0], w / "cd" / "丁.json")
        r = run(["corpus", "build", "--data", "cd", "--out", "st.bin", "--threads", "1"], w)
        self.assert_one_error(r, 1, "丁")
        stats = run_ok(["corpus", "stats", "st.bin", "--json"], w).stdout
        self.assertEqual(json.loads(stats)["characters"], 2)

    @unittest.skipUnless((CORPUS / "一.json").is_file(), "CALLIGRAPHY_CORPUS_DIR with hanzi-writer-data")
    def test_corpus_build_onto_its_own_input_is_refused(self):
        w = self.fresh()
        self.corpus_data(w)
        before = (w / "cd" / "一.json").read_bytes()
        r = run(["corpus", "build", "--data", "cd", "--out", "cd/一.json", "--threads", "1"], w)
        self.assertNotEqual(r.returncode, 0, "a store written over a character file it read")
        self.assertEqual((w / "cd" / "一.json").read_bytes(), before)


if __name__ == "__main__":
    unittest.main()
