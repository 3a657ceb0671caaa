#!/usr/bin/env python3
"""Round 22B: a study that lives for months, from the docs alone (docs/experiments.md "Protocol files",
"Phases", "Sessions", "Trial records", "Tidy tables"; docs/cli.md "session run | resume", "report";
docs/python.md `calligraphy.study.load`).

Earlier rounds damaged, forged, raced and re-timed one study folder. This one follows what a lab does to a study
over its life: the protocol amended between sessions (a parameter changed, a character added, only its spacing,
restored, a new version under a new name beside the old), a subject withdrawn (deleted, moved aside, one day of
two deleted), a subject added late, an id reused for another person, a session folder renamed or moved into
another study or subject; the study run on two machines and merged (reported together, copied into one folder,
the whole other study copied over it, the same subject ids twice); the study archived with tar and restored
(with and without mtimes, read-only, the hidden identity left behind). Each case checks what the docs promise:
the exit status, the one error line naming the folder, file or key, tables counting each trial once under the
right subject, condition and protocol, and nothing written in the study.

CALLIGRAPHY_CLI names the program, PYTHONPATH its Python module. CALLIGRAPHY_SANITIZED=1 takes five cases.
"""
import csv
import hashlib
import io
import json
import math
import os
import shutil
import stat
import subprocess
import tarfile
import tempfile
import time
import unittest
from pathlib import Path

from outsider import OneErrorLine, run, run_ok, sanitized_subset

load_tests = sanitized_subset({"test_amended_parameter_run_into_the_study_is_refused_naming_both_sha256",
                               "test_report_of_two_versions_of_one_name_is_refused_naming_both",
                               "test_two_machines_with_other_prefixes_count_every_trial_once",
                               "test_session_copied_in_from_the_other_machine_is_refused_naming_study_id",
                               "test_tar_archive_restored_gives_the_same_tables_byte_for_byte"})

SIM = ["--writer", "simulated", "--writer-learning", "none", "--pacing", "lock-step"]


def protocol(name="life", stiffness=None, characters=("一",)):
    haptic = {"name": "H", "mode": "haptic"}
    if stiffness is not None:
        haptic["guidance_stiffness_n_per_m"] = stiffness
    return {"name": name, "conditions": [{"name": "V", "mode": "vision"}, haptic],
            "test": {"characters": list(characters), "conditions": ["V", "H"], "repetitions": 1},
            "order": {"conditions": "latin_square"}, "trial": {"max_duration_s": 3}}


DAYS = {"name": "days", "conditions": [{"name": "V", "mode": "vision"}],
        "phases": [{"phase": "training", "condition": "V", "characters": ["一"]},
                   {"phase": "retention", "condition": "V", "characters": ["一"], "session": 2, "delay_s": 60}],
        "trial": {"max_duration_s": 3}}


def write_json(path, value, **kw):
    path.write_text(json.dumps(value, ensure_ascii=False, **kw), encoding="utf-8")


def sha256(path):
    return hashlib.sha256(Path(path).read_bytes()).hexdigest()


def tree(root):
    """Every entry under `root` (hidden ones too): its kind, mode and, for a file, its SHA-256."""
    state = {}
    for dirpath, dirnames, filenames in os.walk(root):
        for name in dirnames + filenames:
            p = Path(dirpath) / name
            st = p.lstat()
            kind = "link" if stat.S_ISLNK(st.st_mode) else "dir" if stat.S_ISDIR(st.st_mode) else "file"
            state[str(p.relative_to(root))] = (kind, stat.S_IMODE(st.st_mode),
                                               sha256(p) if kind == "file" else None)
    return state


def sessions(study, subject):
    return sorted(p for p in (study / subject).iterdir() if not p.name.startswith("."))


def next_second():
    """Waits for the clock's next second, so that a session begun now has another id than one begun before."""
    started = time.time()
    time.sleep(math.ceil(started) - started + 0.05)


def rows(text):
    return list(csv.DictReader(io.StringIO(text)))


class Round22B(unittest.TestCase, OneErrorLine):
    @classmethod
    def setUpClass(cls):
        cls.tmp = Path(tempfile.mkdtemp(prefix="round22b-"))
        t = cls.tmp / "pristine"
        t.mkdir()
        write_json(t / "p.json", protocol())
        # Machine B: the same protocol, byte for byte, from its own folder.
        (t / "mb").mkdir()
        shutil.copy2(t / "p.json", t / "mb" / "p.json")
        # The amended protocol of the same name: the haptic condition's stiffness changed.
        (t / "amended").mkdir()
        write_json(t / "amended" / "p.json", protocol(stiffness=150.0))
        write_json(t / "days.json", DAYS)
        run_ok(["session", "run", "p.json", "--subjects", "2", "--out", "A", *SIM], t)
        run_ok(["session", "run", "p.json", "--subjects", "2", "--subject", "T", "--out", "../B", *SIM], t / "mb")
        # The other machine's S01 begins in another second than this one's: another session id.
        next_second()
        run_ok(["session", "run", "p.json", "--subjects", "2", "--out", "../Bs", *SIM], t / "mb")
        run_ok(["session", "run", "p.json", "--subjects", "1", "--subject", "U", "--out", "../C", *SIM],
               t / "amended")
        run_ok(["session", "run", "days.json", "--subjects", "1", "--out", "D", *SIM], t)
        cls.pristine = t
        cls.tables = {}
        for study in ("A", "B", "C"):
            cls.tables[study] = cls.report_csv(t, study)
        cls.count = 0

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.tmp, ignore_errors=True)

    @classmethod
    def report_csv(cls, cwd, *dirs, ok=True):
        """`report DIRS --csv` into a fresh folder: (result, trials.csv text, strokes.csv text), the texts None
        when not written."""
        out = Path(tempfile.mkdtemp(prefix="tables-", dir=cls.tmp))
        result = run(["report", *dirs, "--csv", out], cwd)
        if ok and result.returncode != 0:
            raise AssertionError(result.stderr.decode("utf-8", "replace"))
        texts = [(out / n).read_text(encoding="utf-8") if (out / n).exists() else None
                 for n in ("trials.csv", "strokes.csv")]
        if result.returncode != 0:
            assert os.listdir(out) == [], os.listdir(out)
        return (result, *texts)

    def case(self, *studies):
        """A copy of the pristine folder's protocols and of the studies named (A when none) for one case."""
        Round22B.count += 1
        where = self.tmp / f"case{Round22B.count}"
        for protocol_file in ("p.json", "days.json", "mb/p.json", "amended/p.json"):
            (where / protocol_file).parent.mkdir(parents=True, exist_ok=True)
            shutil.copy2(self.pristine / protocol_file, where / protocol_file)
        for study in studies or ("A",):
            shutil.copytree(self.pristine / study, where / study, symlinks=True)
        return where

    def session_of(self, study, subject):
        (only,) = sessions(study, subject)
        return only

    def records(self, study):
        return sorted(p for p in Path(study).rglob("trials/*.json"))

    # --- the protocol amended ---------------------------------------------------------------------------------

    def assert_amended_refused(self, w, protocol_file):
        before = tree(w / "A")
        r = run(["session", "run", protocol_file, "--subjects", "1", "--new-subjects", "--out", "A", *SIM], w)
        old, new = sha256(w / "p.json"), sha256(w / protocol_file)
        line = self.assert_one_error(r, 1, protocol_file, old, new, "life")
        self.assertTrue(any(s.name in line for s in sessions(w / "A", "S01") + sessions(w / "A", "S02")), line)
        self.assertEqual(tree(w / "A"), before)

    def test_amended_parameter_run_into_the_study_is_refused_naming_both_sha256(self):
        w = self.case()
        self.assert_amended_refused(w, "amended/p.json")

    def test_amended_character_list_run_into_the_study_is_refused(self):
        w = self.case()
        write_json(w / "p3.json", protocol(characters=("一", "十")))
        self.assert_amended_refused(w, "p3.json")

    def test_protocol_only_respaced_is_another_text_and_refused(self):
        # The docs compare protocols by their SHA-256: the same design reformatted is an edit all the same.
        w = self.case()
        write_json(w / "p4.json", protocol(), indent=2)
        self.assertEqual(json.loads((w / "p4.json").read_text()), json.loads((w / "p.json").read_text()))
        self.assert_amended_refused(w, "p4.json")

    def test_restored_protocol_runs_on_as_the_same_design(self):
        w = self.case()
        original = (w / "p.json").read_bytes()
        write_json(w / "p.json", protocol(stiffness=150.0))
        self.assertEqual(run(["session", "run", "p.json", "--subjects", "1", "--new-subjects", "--out", "A", *SIM],
                             w).returncode, 1)
        (w / "p.json").write_bytes(original)
        run_ok(["session", "run", "p.json", "--subjects", "1", "--new-subjects", "--out", "A", *SIM], w)
        (s3,) = sessions(w / "A", "S03")
        manifest = json.loads((s3 / "session.json").read_text(encoding="utf-8"))
        self.assertEqual(manifest["subject"], {"id": "S03", "number": 3})
        _, trials, _ = self.report_csv(w, "A")
        got = rows(trials)
        self.assertEqual(len(got), 6)
        self.assertEqual({r["protocol"] for r in got}, {"life"})
        self.assertEqual([r for r in got if r["subject"] != "S03"], rows(self.tables["A"][1]))

    def test_protocol_moved_and_renamed_unchanged_is_the_same_design(self):
        # The same bytes from another folder under another file name: the same SHA-256, so the same design.
        w = self.case()
        (w / "protocols").mkdir()
        (w / "p.json").rename(w / "protocols" / "life-2026.json")
        run_ok(["session", "run", "protocols/life-2026.json", "--subjects", "1", "--new-subjects", "--out", "A",
                *SIM], w)
        _, trials, _ = self.report_csv(w, "A")
        got = rows(trials)
        self.assertEqual([r["subject"] for r in got], ["S01", "S01", "S02", "S02", "S03", "S03"])
        self.assertEqual({r["protocol"] for r in got}, {"life"})

    def test_new_version_under_a_new_name_is_reported_apart(self):
        w = self.case()
        write_json(w / "p5.json", protocol(name="life-v2", stiffness=150.0, characters=("一", "十")))
        run_ok(["session", "run", "p5.json", "--subjects", "1", "--subject", "V", "--out", "A", *SIM], w)
        _, trials, _ = self.report_csv(w, "A")
        got = rows(trials)
        self.assertEqual(len(got), len(self.records(w / "A")))
        v2 = [r for r in got if r["protocol"] == "life-v2"]
        self.assertEqual({r["subject"] for r in v2}, {"V01"})
        self.assertEqual(sorted(r["characters"] for r in v2), ["一", "一", "十", "十"])
        self.assertEqual([r for r in got if r["protocol"] == "life"], rows(self.tables["A"][1]))
        v1_sha, v2_sha = sha256(w / "p.json"), sha256(w / "p5.json")
        for rec in self.records(w / "A"):
            data = json.loads(rec.read_text(encoding="utf-8"))
            self.assertEqual(data["protocol"]["sha256"], v2_sha if data["subject"] == "V01" else v1_sha, rec)

    def test_report_of_two_versions_of_one_name_is_refused_naming_both(self):
        w = self.case("A", "C")
        before = tree(w)
        (r, trials, strokes) = self.report_csv(w, "A", "C", ok=False)
        line = self.assert_one_error(r, 1, sha256(w / "p.json"), sha256(w / "amended" / "p.json"))
        self.assertIn("session.json", line)
        self.assertIn(str(Path("C") / "U01"), line)
        self.assertIsNone(trials)
        pages = w / "pages.html"
        r = run(["report", "A", "C", "--out", pages], w)
        self.assert_one_error(r, 1, sha256(w / "p.json"))
        self.assertFalse(pages.exists())
        self.assertFalse((w / "pages_files").exists())
        self.assertEqual(tree(w), before)

    def test_study_load_of_two_versions_of_one_name_is_refused(self):
        import calligraphy
        import calligraphy.study
        w = self.case("A", "C")
        with self.assertRaises(calligraphy.DataError) as caught:
            calligraphy.study.load([str(w / "A"), str(w / "C")])
        message = str(caught.exception)
        self.assertIn(sha256(w / "p.json"), message)
        self.assertIn(sha256(w / "amended" / "p.json"), message)

    def test_resume_after_the_protocol_file_was_edited_follows_the_session_copy(self):
        w = self.case()
        s = self.session_of(w / "A", "S01")
        last = sorted((s / "trials").glob("002-*"))
        self.assertEqual(len(last), 3)
        for f in last:
            f.unlink()
        write_json(w / "p.json", protocol(stiffness=150.0, characters=("一", "十")))
        run_ok(["session", "resume", s, "--pacing", "lock-step"], w)
        (record,) = (s / "trials").glob("002-*.json")
        data = json.loads(record.read_text(encoding="utf-8"))
        manifest = json.loads((s / "session.json").read_text(encoding="utf-8"))
        self.assertEqual(data["protocol"]["sha256"], manifest["protocol"]["sha256"])
        self.assertEqual(data["protocol"]["sha256"], sha256(self.pristine / "p.json"))
        self.assertNotIn("十", data["characters"])
        _, trials, _ = self.report_csv(w, "A")
        self.assertEqual(len(rows(trials)), 4)

    # --- subjects withdrawn, added late, ids reused ----------------------------------------------------------

    def test_withdrawn_subject_deleted_leaves_the_others_rows_as_they_were(self):
        w = self.case()
        shutil.rmtree(w / "A" / "S02")
        _, trials, strokes = self.report_csv(w, "A")
        self.assertEqual(rows(trials), [r for r in rows(self.tables["A"][1]) if r["subject"] == "S01"])
        self.assertEqual(rows(strokes), [r for r in rows(self.tables["A"][2]) if r["subject"] == "S01"])

    def test_subject_moved_aside_inside_the_study_is_refused_not_counted(self):
        # A/withdrawn/S02/SESSION lies in the study folder A/withdrawn, which has no identity: the session names
        # A's, so every reader refuses it (as `session run` does), rather than count a withdrawn subject.
        w = self.case()
        (w / "A" / "withdrawn").mkdir()
        (w / "A" / "S02").rename(w / "A" / "withdrawn" / "S02")
        moved = self.session_of(w / "A" / "withdrawn", "S02")
        result, _, _ = self.report_csv(w, "A", ok=False)
        self.assert_one_error(result, 1, moved.name, "/study_id")
        r = run(["session", "run", "p.json", "--subjects", "1", "--new-subjects", "--out", "A", *SIM], w)
        self.assert_one_error(r, 1, moved.name)
        (w / "A" / "withdrawn" / "S02").rename(w / "A" / "S02")
        self.assertEqual(self.report_csv(w, "A")[1:], self.tables["A"][1:])

    def test_day_one_deleted_stops_the_series_naming_what_to_put_back(self):
        w = self.case("D")
        day1, day2 = sessions(w / "D", "S01")
        shutil.rmtree(day1)
        before = tree(w / "D")
        r = run(["session", "run", "days.json", "--subject", "S01", "--out", "D", *SIM], w)
        self.assert_one_error(r, 1, day1.name)
        self.assertEqual(tree(w / "D"), before)
        result, trials, _ = self.report_csv(w, "D", ok=False)
        if result.returncode == 0:  # day 2 alone is still day 2
            got = rows(trials)
            self.assertEqual([(r["session"], r["session_number"], r["phase"]) for r in got],
                             [(day2.name, "2", "retention")])

    def test_day_two_deleted_is_written_again_after_day_one(self):
        w = self.case("D")
        day1, day2 = sessions(w / "D", "S01")
        shutil.rmtree(day2)
        run_ok(["session", "run", "days.json", "--subject", "S01", "--out", "D", *SIM], w)
        got = sessions(w / "D", "S01")
        self.assertEqual(len(got), 2)
        self.assertEqual(got[0], day1)
        manifest = json.loads((got[1] / "session.json").read_text(encoding="utf-8"))
        self.assertEqual(manifest["session_number"], 2)
        self.assertEqual(manifest["previous_session"]["session_id"], day1.name)
        self.assertEqual(manifest["previous_session"]["session_sha256"], sha256(day1 / "session.json"))
        _, trials, _ = self.report_csv(w, "D")
        self.assertEqual([(r["session_number"], r["phase"]) for r in rows(trials)],
                         [("1", "training"), ("2", "retention")])

    def test_subject_added_late_is_numbered_after_those_there(self):
        w = self.case()
        r = run_ok(["session", "run", "p.json", "--subjects", "1", "--new-subjects", "--out", "A", *SIM], w)
        self.assertIn("S03", r.stdout.decode())
        manifest = json.loads((self.session_of(w / "A", "S03") / "session.json").read_text(encoding="utf-8"))
        self.assertEqual(manifest["subject"], {"id": "S03", "number": 3})
        _, trials, _ = self.report_csv(w, "A")
        got = rows(trials)
        self.assertEqual([r for r in got if r["subject"] != "S03"], rows(self.tables["A"][1]))
        # Number 3 takes the first row of the square again: V, then H.
        self.assertEqual([r["condition"] for r in got if r["subject"] == "S03"], ["V", "H"])

    def test_id_reused_after_deletion_is_only_the_new_person(self):
        w = self.case()
        old = self.session_of(w / "A", "S02")
        shutil.rmtree(w / "A" / "S02")
        run_ok(["session", "run", "p.json", "--subjects", "1", "--new-subjects", "--out", "A", *SIM], w)
        new = self.session_of(w / "A", "S02")
        _, trials, _ = self.report_csv(w, "A")
        got = [r for r in rows(trials) if r["subject"] == "S02"]
        self.assertEqual([r["session"] for r in got], [new.name, new.name])
        self.assertNotEqual(new.name, old.name)

    def test_id_reused_beside_the_old_one_moved_aside_is_never_pooled(self):
        w = self.case()
        (w / "A" / "withdrawn").mkdir()
        old = self.session_of(w / "A", "S02")
        (w / "A" / "S02").rename(w / "A" / "withdrawn" / "S02")
        r = run(["session", "run", "p.json", "--subject", "S02", "--out", "A", *SIM], w)
        if r.returncode != 0:  # the series refuses a session found outside its subject's folder
            self.assert_one_error(r, 1, "S02", old.name)
            return
        result, trials, _ = self.report_csv(w, "A", ok=False)
        new = self.session_of(w / "A", "S02")
        line = self.assert_one_error(result, 1, "S02", new.name)
        self.assertIn(self.session_of(w / "A" / "withdrawn", "S02").name, line)

    # --- session folders renamed and moved -----------------------------------------------------------------------

    def test_renamed_session_folder_is_refused_naming_the_session_key(self):
        w = self.case()
        s = self.session_of(w / "A", "S01")
        s.rename(s.with_name(s.name + "-renamed"))
        result, trials, _ = self.report_csv(w, "A", ok=False)
        self.assert_one_error(result, 1, s.name + "-renamed", "/session")

    def test_session_moved_into_another_study_is_refused_naming_study_id(self):
        w = self.case("A", "B")
        s = self.session_of(w / "A", "S02")
        (w / "B" / "S02").mkdir()
        s.rename(w / "B" / "S02" / s.name)
        result, _, _ = self.report_csv(w, "B", ok=False)
        self.assert_one_error(result, 1, s.name, "session.json", "/study_id")

    def test_session_moved_into_another_subjects_folder_is_not_reported_as_that_subject(self):
        w = self.case()
        s = self.session_of(w / "A", "S01")
        s.rename(w / "A" / "S02" / s.name)
        (w / "A" / "S01").rmdir()
        result, trials, _ = self.report_csv(w, "A", ok=False)
        if result.returncode != 0:
            self.assert_one_error(result, 1, s.name)
            return
        got = rows(trials)
        self.assertEqual(len(got), 4)
        self.assertEqual({r["subject"] for r in got if r["session"] == s.name}, {"S01"})

    def test_session_given_as_dot_or_through_a_link_is_read_as_its_studys(self):
        # "a session folder may be given by any name that reaches it": its study is the folder it lies in.
        w = self.case()
        s = self.session_of(w / "A", "S01")
        expect = [r for r in rows(self.tables["A"][1]) if r["subject"] == "S01"]
        for r in expect:
            r.pop("trace_file")
        (w / "elsewhere").mkdir()
        (w / "elsewhere" / "link").symlink_to(s)
        for cwd, name in ((s, "."), (w / "elsewhere", "link"), (w / "elsewhere", "link/")):
            _, trials, _ = self.report_csv(cwd, name)
            got = rows(trials)
            for r in got:
                r.pop("trace_file")
            self.assertEqual(got, expect, name)

    # --- two machines ------------------------------------------------------------------------------------------

    def test_two_machines_with_the_same_subject_ids_are_refused_naming_subject_and_both(self):
        w = self.case("A", "Bs")
        before = tree(w)
        result, _, _ = self.report_csv(w, "A", "Bs", ok=False)
        line = self.assert_one_error(result, 1, "S01")
        self.assertIn(self.session_of(w / "A", "S01").name, line)
        self.assertIn(self.session_of(w / "Bs", "S01").name, line)
        self.assertEqual(tree(w), before)

    def test_two_machines_with_other_prefixes_count_every_trial_once(self):
        w = self.case("A", "B")
        before = tree(w)
        _, trials, strokes = self.report_csv(w, "A", "B")
        _, trials2, strokes2 = self.report_csv(w, "B", "A")
        self.assertEqual((trials, strokes), (trials2, strokes2))
        self.assertEqual(rows(trials), rows(self.tables["A"][1]) + rows(self.tables["B"][1]))
        self.assertEqual(rows(strokes), rows(self.tables["A"][2]) + rows(self.tables["B"][2]))
        self.assertEqual(len(rows(trials)), len(self.records(w / "A")) + len(self.records(w / "B")))
        self.assertEqual(tree(w), before)

    def test_session_copied_in_from_the_other_machine_is_refused_naming_study_id(self):
        w = self.case("A", "B")
        shutil.copytree(w / "B" / "T01", w / "A" / "T01")
        copied = self.session_of(w / "A", "T01")
        result, _, _ = self.report_csv(w, "A", ok=False)
        line = self.assert_one_error(result, 1, "/study_id", "session.json")
        self.assertIn(copied.name, line)

    def test_whole_other_study_copied_over_the_identity_is_refused(self):
        # `cp -r B/. A/`: the other machine's identity replaces this one's; A's own sessions are then strangers.
        w = self.case("A", "B")
        subprocess.run(["cp", "-r", f"{w / 'B'}/.", str(w / "A")], check=True)
        self.assertEqual(sha256(w / "A" / ".calligraphy-study.json"), sha256(w / "B" / ".calligraphy-study.json"))
        result, _, _ = self.report_csv(w, "A", ok=False)
        line = self.assert_one_error(result, 1, "/study_id", "session.json")
        self.assertTrue("S01" in line or "S02" in line, line)

    def test_same_subject_from_the_other_machine_copied_beside_it_is_refused(self):
        w = self.case("A", "Bs")
        theirs = self.session_of(w / "Bs", "S01")
        shutil.copytree(theirs, w / "A" / "S01" / theirs.name)
        result, _, _ = self.report_csv(w, "A", ok=False)
        self.assert_one_error(result, 1, theirs.name)
        r = run(["session", "run", "p.json", "--subjects", "1", "--new-subjects", "--out", "A", *SIM], w)
        self.assert_one_error(r, (1, 2), theirs.name)

    def test_study_load_of_two_machines_is_the_report(self):
        import calligraphy.study
        w = self.case("A", "B")
        study = calligraphy.study.load([str(w / "B"), str(w / "A")])
        _, trials, _ = self.report_csv(w, str(w / "A"), str(w / "B"))
        expect = rows(trials)
        self.assertEqual(list(study.trials["subject"].astype(str)), [r["subject"] for r in expect])
        self.assertEqual(list(study.trials["session"].astype(str)), [r["session"] for r in expect])
        self.assertEqual(list(study.trials["condition"].astype(str)), [r["condition"] for r in expect])
        self.assertEqual(study.trials.groupby("subject", observed=True).size().to_dict(),
                         {"S01": 2, "S02": 2, "T01": 2, "T02": 2})

    # --- archived and restored -------------------------------------------------------------------------------

    def restore(self, w, members=None, **extract):
        archive = w / "study.tar.gz"
        with tarfile.open(archive, "w:gz") as tar:
            for name in members or ["A"]:
                tar.add(w / name, arcname=name)
        place = w / "restored"
        place.mkdir()
        with tarfile.open(archive) as tar:
            if extract.get("no_mtimes"):
                for member in tar.getmembers():
                    member.mtime = 0
            tar.extractall(place)
        return place

    def test_tar_archive_restored_gives_the_same_tables_byte_for_byte(self):
        w = self.case()
        place = self.restore(w)
        self.assertEqual(self.report_csv(place, "A")[1:], self.tables["A"][1:])

    def test_tar_restored_without_mtimes_gives_the_same_tables(self):
        w = self.case()
        place = self.restore(w, no_mtimes=True)
        self.assertEqual(os.stat(self.session_of(place / "A", "S01") / "session.json").st_mtime, 0)
        self.assertEqual(self.report_csv(place, "A")[1:], self.tables["A"][1:])

    def test_read_only_restored_study_reports_the_same_and_is_not_written(self):
        w = self.case()
        place = self.restore(w)
        for dirpath, dirnames, filenames in os.walk(place / "A"):
            for name in dirnames + filenames + ["."]:
                p = Path(dirpath) / name
                p.chmod(stat.S_IMODE(p.stat().st_mode) & ~0o222)
        before = tree(place / "A")
        try:
            self.assertEqual(self.report_csv(place, "A")[1:], self.tables["A"][1:])
            pages = place / "pages.html"
            run_ok(["report", "A", "--out", pages], place)
            self.assertTrue(pages.exists())
            self.assertEqual(tree(place / "A"), before)
        finally:
            for dirpath, dirnames, filenames in os.walk(place):
                for name in dirnames + filenames + ["."]:
                    p = Path(dirpath) / name
                    p.chmod(stat.S_IMODE(p.stat().st_mode) | 0o700)

    def visible_files_only(self, w):
        """`tar czf study.tgz A/*` restored: the shell's glob leaves the hidden .calligraphy-study.json behind."""
        archive = w / "study.tar.gz"
        with tarfile.open(archive, "w:gz") as tar:
            for p in sorted((w / "A").iterdir()):
                if not p.name.startswith("."):
                    tar.add(p, arcname=f"A/{p.name}")
        place = w / "restored"
        place.mkdir()
        with tarfile.open(archive) as tar:
            tar.extractall(place)
        self.assertFalse((place / "A" / ".calligraphy-study.json").exists())
        return place

    def test_archive_of_the_visible_files_only_is_refused_until_its_identity_is_restored(self):
        # Its sessions name the study's id and the folder has none: every reader refuses them the same way.
        import calligraphy
        import calligraphy.study
        w = self.case()
        place = self.visible_files_only(w)
        identity = place / "A" / ".calligraphy-study.json"
        result, _, _ = self.report_csv(place, "A", ok=False)
        self.assert_one_error(result, 1, "/study_id", "session.json", str(identity.resolve()))
        with self.assertRaises(calligraphy.DataError) as caught:
            calligraphy.study.load(str(place / "A"))
        self.assertIn("/study_id", str(caught.exception))
        before = tree(place / "A")
        session = self.session_of(place / "A", "S01")
        r = run(["session", "resume", session, "--pacing", "lock-step"], place)
        self.assert_one_error(r, 1, "/study_id", ".calligraphy-study.json")
        r = run(["session", "run", w / "p.json", "--subjects", "1", "--new-subjects", "--out", "A", *SIM], place)
        self.assert_one_error(r, 1, "/study_id", ".calligraphy-study.json")
        self.assertEqual({k: v for k, v in tree(place / "A").items() if k != ".calligraphy-run.lock"},
                         {k: v for k, v in before.items() if k != ".calligraphy-run.lock"})
        shutil.copy2(w / "A" / ".calligraphy-study.json", identity)
        self.assertEqual(self.report_csv(place, "A")[1:], self.tables["A"][1:])
        run_ok(["session", "run", w / "p.json", "--subjects", "1", "--new-subjects", "--out", "A", *SIM], place)
        self.assertEqual(len(sessions(place / "A", "S03")), 1)

    def test_session_copied_into_a_study_made_before_identities_is_refused(self):
        # A study folder of an earlier build (no identity file, no study_id) and a session of this one copied in.
        w = self.case("A", "B")
        (w / "B" / ".calligraphy-study.json").unlink()
        for manifest in (w / "B").rglob("session.json"):
            doc = json.loads(manifest.read_text(encoding="utf-8"))
            del doc["study_id"]
            write_json(manifest, doc, indent=2)
        self.assertEqual(len(rows(self.report_csv(w, "B")[1])), 4)
        shutil.copytree(w / "A" / "S01", w / "B" / "S01")
        result, _, _ = self.report_csv(w, "B", ok=False)
        self.assert_one_error(result, 1, "/study_id", self.session_of(w / "B", "S01").name)

    # --- a study split across machines as copies of one folder -------------------------------------------------

    def clone_and_run(self, w, *subject):
        """The study folder copied to a second machine (its identity with it), a subject run there."""
        shutil.copytree(w / "A", w / "A2", symlinks=True)
        run_ok(["session", "run", "p.json", "--subjects", "1", *subject, "--out", "A2", *SIM], w)

    def test_clone_on_a_second_machine_merged_back_counts_its_subject_once(self):
        w = self.case()
        self.clone_and_run(w, "--subject", "T")
        _, clone_trials, _ = self.report_csv(w, "A2")
        shutil.copytree(w / "A2" / "T01", w / "A" / "T01")
        _, trials, _ = self.report_csv(w, "A")
        got = rows(trials)
        self.assertEqual(len(got), 6)
        clone = rows(clone_trials)
        for r in got + clone:
            r.pop("trace_file")
        self.assertEqual([r for r in got if r["subject"] == "T01"], [r for r in clone if r["subject"] == "T01"])

    def test_clones_that_each_added_the_next_subject_are_never_pooled_as_one(self):
        # Both machines ran --new-subjects on a copy of one study: each made its own S03.
        w = self.case()
        self.clone_and_run(w, "--new-subjects")
        next_second()  # another session id
        run_ok(["session", "run", "p.json", "--subjects", "1", "--new-subjects", "--out", "A", *SIM], w)
        ours, theirs = self.session_of(w / "A", "S03"), self.session_of(w / "A2", "S03")
        self.assertNotEqual(ours.name, theirs.name)
        shutil.copytree(theirs, w / "A" / "S03" / theirs.name)
        result, _, _ = self.report_csv(w, "A", ok=False)
        line = self.assert_one_error(result, 1, "S03", ours.name, theirs.name)
        self.assertIn("twice", line)

    def test_days_protocol_amended_before_the_second_day_is_refused_naming_the_first(self):
        w = self.case("D")
        day1, day2 = sessions(w / "D", "S01")
        shutil.rmtree(day2)
        amended = json.loads(json.dumps(DAYS))
        amended["phases"][1]["delay_s"] = 120
        write_json(w / "days.json", amended)
        before = tree(w / "D")
        r = run(["session", "run", "days.json", "--subject", "S01", "--out", "D", *SIM], w)
        self.assert_one_error(r, 1, "days.json", day1.name, sha256(self.pristine / "days.json"),
                              sha256(w / "days.json"))
        self.assertEqual(tree(w / "D"), before)

    def test_two_machines_pages_index_every_session_once(self):
        w = self.case("A", "B")
        before = tree(w)
        run_ok(["report", "A", "B", "--out", "pages.html"], w)
        index = (w / "pages.html").read_text(encoding="utf-8")
        for study, subject in (("A", "S01"), ("A", "S02"), ("B", "T01"), ("B", "T02")):
            s = self.session_of(w / study, subject)
            self.assertEqual(index.count(f"{s.name}.html"), 1, s.name)
            self.assertTrue((w / "pages_files" / subject / f"{s.name}.html").is_file())
        after = tree(w)
        self.assertEqual({k: v for k, v in after.items() if not k.startswith("pages")}, before)


if __name__ == "__main__":
    unittest.main()
