#!/usr/bin/env python3
"""Round 20A: what is promised to be the same, made under changed circumstances, from the docs alone (README.md;
docs/cli.md "trial", "Re-running a trial", "score", "Pen traces", "trace", "session run | resume", "report";
docs/experiments.md "Sessions", "Trial records", "Tidy tables"; docs/python.md "Running a trial again").
Run by CTest as `cli_unseen_round20a_tests`.

Earlier rounds re-ran records in the folder they were made in, under the environment they were made in. This
one makes the same work elsewhere and otherwise: a trial record re-run from another working folder, through a
relative path, a symbolic link, a copy in a folder named with spaces and Unicode (a replay's with and without
its teacher beside it, beside another teacher of that name, with its teacher edited by one byte); the same
trial under TZ=Pacific/Chatham, every installed locale, HOME unset, TMPDIR elsewhere, one core and nice 19; a
session run twice lock-step into two folders, and one killed and resumed against one run straight through
(the records, traces and tables equal but for the times, ids and paths the docs say differ); a record made by
the command line re-run by Python and one made by Python re-run by the command line; `report --csv` twice, of
a moved copy and through a link; `score` of one trace under another name, in CR LF, behind a byte order mark,
quoted, its columns reordered, and of the HDF5 trace against its CSV. And what must differ: another seed
another run, an edited trace refused naming its SHA-256.

CALLIGRAPHY_CLI names the program, PYTHONPATH its Python module. CALLIGRAPHY_SANITIZED=1 takes five cases.
"""
import csv
import hashlib
import io
import json
import os
import shutil
import signal
import subprocess
import tempfile
import time
import unittest
from pathlib import Path

from outsider import CLI, ENV, OneErrorLine, run, sanitized_subset

load_tests = sanitized_subset({"test_rerun_from_another_working_folder_through_a_relative_path",
                               "test_replay_copy_without_its_teacher_beside_it_is_refused_naming_it",
                               "test_two_lock_step_sessions_save_equal_records_but_times_ids_and_paths",
                               "test_report_csv_of_a_moved_copy_differs_in_trace_file_only",
                               "test_score_of_crlf_bom_quoted_and_reordered_columns_gives_the_same_verdicts"})

YI = "一"
SHI = "十"
SEED = "5"
# A folder name an outsider's lab might use: spaces, CJK and an accent.
ODD = "a folder 書法 é"
CORPUS = Path(os.environ.get("CALLIGRAPHY_CORPUS_DIR", Path.home() / ".cache/calligraphy/hanzi-writer-data-2.0.1"))
SIM = ["--writer", "simulated", "--writer-learning", "none", "--individual-differences", "off"]


def protocol(name, chars=YI, max_s=2, rate=None):
    trial = {"max_duration_s": max_s}
    if rate:
        trial["rate_hz"] = rate
    return {"name": name, "conditions": [{"name": "V", "mode": "vision"}],
            "test": {"characters": [chars], "conditions": ["V"], "repetitions": 2}, "trial": trial}


def env_with(**changes):
    """The outsider environment with `changes` (None removes a variable)."""
    env = dict(ENV)
    for key, value in changes.items():
        if value is None:
            env.pop(key, None)
        else:
            env[key] = value
    return env


def hashlib_hex(data):
    return hashlib.sha256(data).hexdigest()


def sessions(study):
    return sorted(p.parent for p in Path(study).glob("*/*/session.json"))


def trial_records(session):
    return sorted((Path(session) / "trials").glob("*.json"))


def read_table(path):
    with open(path, newline="", encoding="utf-8") as f:
        return list(csv.DictReader(f))


# What the docs say differs between two runs of one session: the times (UTC dates, a trial's wall time), the
# session's id (its folder's name, named by its records) and the paths (the protocol's, the study's, the trace
# as reached). Every other value is the same trial's.
def normalised(value, ids, ignore=()):
    if isinstance(value, dict):
        return {k: normalised(v, ids, ignore) for k, v in value.items()
                if not (k.endswith("_utc") or k in ("wall_time_s", "study_id", "protocol_path", "path", *ignore))}
    if isinstance(value, list):
        return [normalised(v, ids, ignore) for v in value]
    if isinstance(value, str):
        for session_id in ids:
            value = value.replace(session_id, "SESSION")
        return value
    return value


class Circumstances(unittest.TestCase, OneErrorLine):
    @classmethod
    def setUpClass(cls):
        cls.tmp = tempfile.TemporaryDirectory(prefix="r20a-")
        root = cls.root = Path(cls.tmp.name)
        base = cls.base = root / "base"
        base.mkdir()
        # The trial every re-run is held to: a novice's 一 of seed 5, 2 s.
        r = run(["trial", YI, "--seed", SEED, "--max-duration", "2", "--json", "a.json", "--csv", "a.csv"], base)
        assert r.returncode in (0, 1) and (base / "a.csv").exists(), r.stderr
        cls.a_json = (base / "a.json").read_bytes()
        cls.a_csv = (base / "a.csv").read_bytes()
        # A skilled teacher of 一 and a novice's replay of it, the teacher named by a relative path.
        r = run(["trial", YI, "--writer-profile", "skilled", "--max-duration", "3", "--record", "t.json"], base)
        assert r.returncode == 0, r.stderr
        r = run(["trial", YI, "--guidance-mode", "replay", "--teacher", "t.json", "--seed", SEED,
                 "--max-duration", "2", "--json", "r.json", "--csv", "r.csv"], base)
        assert (base / "r.csv").exists(), r.stderr
        cls.r_csv = (base / "r.csv").read_bytes()
        # One study of one simulated subject, 2 trials of 一, lock-step.
        (root / "p.json").write_text(json.dumps(protocol("r20a")))
        r = run(["session", "run", "p.json", "--subject", "S01", *SIM, "--out", "study"], root)
        assert r.returncode == 0, r.stderr
        cls.study = root / "study"
        cls.session = sessions(cls.study)[0]

    @classmethod
    def tearDownClass(cls):
        cls.tmp.cleanup()

    def folder(self, name):
        path = Path(tempfile.mkdtemp(prefix=name, dir=self.root))
        return path

    def rerun(self, record, cwd, env=None, *extra):
        r = run(["trial", "--spec", record, "--json", "x.json", "--csv", "x.csv", *extra], cwd, env=env)
        self.assertIn(r.returncode, (0, 1), r.stderr)
        self.assertTrue((Path(cwd) / "x.csv").exists(), r.stderr)
        return (Path(cwd) / "x.json").read_bytes(), (Path(cwd) / "x.csv").read_bytes()

    def assert_same_trial(self, got_json, got_csv):
        self.assertEqual(got_csv, self.a_csv, "the trace is not the first run's byte for byte")
        self.assertEqual(got_json, self.a_json, "the JSON is not the first run's (lock-step: the same JSON)")

    # ---- a trial record re-run elsewhere ----

    def test_rerun_from_another_working_folder_through_a_relative_path(self):
        there = self.folder("elsewhere-")
        rel = os.path.relpath(self.base / "a.json", there)
        self.assert_same_trial(*self.rerun(rel, there))

    def test_rerun_through_a_symbolic_link_from_another_folder(self):
        there = self.folder("link-")
        (there / "linked.json").symlink_to(self.base / "a.json")
        self.assert_same_trial(*self.rerun("linked.json", there))

    def test_rerun_of_a_copy_in_a_folder_named_with_spaces_and_unicode(self):
        there = self.folder("copy-") / ODD
        there.mkdir()
        shutil.copy(self.base / "a.json", there / "記録 1.json")
        self.assert_same_trial(*self.rerun("記録 1.json", there))

    def test_a_rerun_of_the_rerun_is_the_first_run(self):
        there = self.folder("again-")
        self.rerun(self.base / "a.json", there)
        (there / "x.json").rename(there / "first-rerun.json")
        self.assert_same_trial(*self.rerun("first-rerun.json", there))

    # ---- a replay's teacher, named by the record ----

    def test_replay_rerun_from_another_folder_with_its_teacher_given(self):
        there = self.folder("teacher-given-")
        _, got = self.rerun(self.base / "r.json", there, None, "--teacher", self.base / "t.json")
        self.assertEqual(got, self.r_csv)

    def test_replay_copy_with_its_teacher_beside_it_reruns_the_same(self):
        there = self.folder("replay-copy-") / ODD
        there.mkdir()
        shutil.copy(self.base / "r.json", there)
        shutil.copy(self.base / "t.json", there)
        _, got = self.rerun("r.json", there)
        self.assertEqual(got, self.r_csv)

    def test_replay_rerun_through_a_link_to_its_teacher_reruns_the_same(self):
        there = self.folder("replay-link-")
        shutil.copy(self.base / "r.json", there)
        (there / "t.json").symlink_to(self.base / "t.json")
        _, got = self.rerun("r.json", there)
        self.assertEqual(got, self.r_csv)

    def test_replay_copy_without_its_teacher_beside_it_is_refused_naming_it(self):
        there = self.folder("replay-alone-")
        shutil.copy(self.base / "r.json", there)
        r = run(["trial", "--spec", "r.json", "--csv", "x.csv"], there)
        self.assert_one_error(r, 1, "t.json")
        self.assertFalse((there / "x.csv").exists(), "a refused re-run wrote its trace")
        # The teacher beside the record, the record run from another working folder: the record's relative
        # name is read from the working folder (docs/cli.md), so it is refused the same way.
        shutil.copy(self.base / "t.json", there)
        elsewhere = self.folder("replay-from-elsewhere-")
        r = run(["trial", "--spec", there / "r.json", "--csv", "x.csv"], elsewhere)
        self.assert_one_error(r, 1, "t.json")
        self.assertFalse((elsewhere / "x.csv").exists())

    def test_replay_beside_another_teacher_of_that_name_is_refused_naming_both_sha256(self):
        there = self.folder("other-teacher-")
        shutil.copy(self.base / "r.json", there)
        r = run(["trial", YI, "--writer-profile", "skilled", "--seed", "9", "--max-duration", "3",
                 "--record", "t.json"], there)
        self.assertEqual(r.returncode, 0, r.stderr)
        other = hashlib.sha256((there / "t.json").read_bytes()).hexdigest()
        recorded = json.loads((there / "r.json").read_text())["specification"]["teacher_sha256"]
        self.assertNotEqual(other, recorded)
        r = run(["trial", "--spec", "r.json", "--csv", "x.csv"], there)
        self.assert_one_error(r, 1, "t.json", other, recorded)
        self.assertFalse((there / "x.csv").exists())

    def test_teacher_edited_by_one_byte_is_refused_naming_the_sha256(self):
        there = self.folder("edited-teacher-")
        shutil.copy(self.base / "r.json", there)
        text = (self.base / "t.json").read_bytes()
        recorded = json.loads((there / "r.json").read_text())["specification"]["teacher_sha256"]
        # One byte more of white space: the same recording to a JSON reader, another file by its SHA-256.
        for edited in (text + b" ", text.replace(b"}", b" }", 1)):
            (there / "t.json").write_bytes(edited)
            r = run(["trial", "--spec", "r.json", "--csv", "x.csv"], there)
            self.assert_one_error(r, 1, "t.json", recorded, "SHA-256")
            self.assertFalse((there / "x.csv").exists())

    # ---- the same trial under another environment ----

    def first_run(self, env, prefix=()):
        there = self.folder("env-")
        argv = [*prefix, CLI, "trial", YI, "--seed", SEED, "--max-duration", "2", "--json", "x.json",
                "--csv", "x.csv"]
        r = subprocess.run(argv, cwd=there, env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                           stdin=subprocess.DEVNULL, timeout=60)
        self.assertIn(r.returncode, (0, 1), r.stderr)
        self.assert_same_trial((there / "x.json").read_bytes(), (there / "x.csv").read_bytes())
        rerun = self.rerun(self.base / "a.json", there, env)
        self.assert_same_trial(*rerun)
        return r

    def test_trial_and_rerun_under_chatham_time_and_every_locale_are_the_same(self):
        locales = subprocess.run(["locale", "-a"], stdout=subprocess.PIPE, text=True).stdout.split()
        for loc in sorted(set(locales) | {"C", "C.UTF-8", "POSIX"}):
            with self.subTest(locale=loc):
                self.first_run(env_with(TZ="Pacific/Chatham", LC_ALL=loc, LANG=loc))

    def test_trial_and_rerun_without_home_and_with_tmpdir_elsewhere_are_the_same(self):
        tmpdir = self.folder("tmp ") / "其他"
        tmpdir.mkdir()
        self.first_run(env_with(HOME=None, TMPDIR=str(tmpdir), XDG_CACHE_HOME=None))
        self.assertEqual(list(tmpdir.iterdir()), [], "a temporary was left in TMPDIR")

    def test_trial_and_rerun_on_one_core_at_nice_19_are_the_same(self):
        if shutil.which("taskset") is None:
            self.skipTest("taskset is missing")
        self.first_run(ENV, ["taskset", "-c", "0", "nice", "-n", "19"])

    # ---- sessions run again ----

    def session_run(self, out, cwd, env=None, proto="p.json"):
        r = run(["session", "run", proto, "--subject", "S01", *SIM, "--out", out], cwd, env=env)
        self.assertEqual(r.returncode, 0, r.stderr)
        return sessions(Path(cwd) / out)[0]

    def assert_sessions_alike(self, one, two, ignore=()):
        ids = [one.name, two.name]
        a, b = trial_records(one), trial_records(two)
        self.assertEqual([p.name for p in a], [p.name for p in b])
        self.assertEqual(len(a), 2)
        for x, y in zip(a, b):
            self.assertEqual(normalised(json.loads(x.read_text()), ids, ignore),
                             normalised(json.loads(y.read_text()), ids, ignore),
                             f"{x.name} differs beyond times, ids and paths")
            tx = run(["trace", x.with_suffix("").with_suffix(".trace.h5")], self.root)
            ty = run(["trace", y.with_suffix("").with_suffix(".trace.h5")], self.root)
            self.assertEqual(tx.returncode, 0, tx.stderr)
            self.assertEqual(tx.stdout, ty.stdout, f"{x.name}: the traces differ")
        sa = normalised(json.loads((one / "session.json").read_text()), ids)
        sb = normalised(json.loads((two / "session.json").read_text()), ids)
        self.assertEqual(sa.get("plan"), sb.get("plan"))

    def test_two_lock_step_sessions_save_equal_records_but_times_ids_and_paths(self):
        there = self.folder("two-")
        shutil.copy(self.root / "p.json", there)
        one = self.session_run("first", there)
        two = self.session_run("second 第二", there, env_with(TZ="Pacific/Chatham", LC_ALL="C", HOME=None))
        self.assert_sessions_alike(one, two)
        if shutil.which("taskset"):  # and on one core at nice 19
            argv = ["taskset", "-c", "0", "nice", "-n", "19", CLI, "session", "run", "p.json", "--subject", "S01",
                    *SIM, "--out", "third"]
            r = subprocess.run(argv, cwd=there, env=ENV, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                               stdin=subprocess.DEVNULL, timeout=60)
            self.assertEqual(r.returncode, 0, r.stderr)
            self.assert_sessions_alike(one, sessions(there / "third")[0])

    def test_two_sessions_tables_differ_in_session_times_and_trace_paths_only(self):
        there = self.folder("tables-")
        shutil.copy(self.root / "p.json", there)
        one = self.session_run("first", there)
        two = self.session_run("second", there)
        tables = []
        for study in ("first", "second"):
            (there / f"t-{study}").mkdir()
            r = run(["report", study, "--csv", f"t-{study}"], there)
            self.assertEqual(r.returncode, 0, r.stderr)
            tables.append((read_table(there / f"t-{study}" / "trials.csv"),
                           read_table(there / f"t-{study}" / "strokes.csv")))
        differing = {"session", "start_utc", "trace_file"}
        for table in (0, 1):
            rows_a, rows_b = tables[0][table], tables[1][table]
            self.assertEqual(len(rows_a), len(rows_b))
            self.assertGreater(len(rows_a), 0)
            for ra, rb in zip(rows_a, rows_b):
                self.assertEqual(ra["session"], one.name)
                self.assertEqual(rb["session"], two.name)
                self.assertEqual({k: v for k, v in ra.items() if k not in differing},
                                 {k: v for k, v in rb.items() if k not in differing})

    def test_session_killed_and_resumed_equals_one_run_straight_through(self):
        there = self.folder("kill-")
        (there / "k.json").write_text(json.dumps(protocol("r20k", SHI, 20, 10000)))
        straight = self.session_run("straight", there, proto="k.json")
        argv = [CLI, "session", "run", "k.json", "--subject", "S01", *SIM, "--out", "killed"]
        p = subprocess.Popen(argv, cwd=there, env=ENV, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
                             stdin=subprocess.DEVNULL)
        # SIGKILL once the first trial is saved: during the second (each takes about 0.1 s here).
        deadline = time.monotonic() + 30
        while (not list((there / "killed").glob("S01/*/trials/001-*.json")) and p.poll() is None
               and time.monotonic() < deadline):
            time.sleep(0.002)
        p.send_signal(signal.SIGKILL)
        p.wait(timeout=30)
        self.assertEqual(p.returncode, -signal.SIGKILL, "the run ended before it was killed")
        made = sessions(there / "killed")
        if made:
            r = run(["session", "resume", made[0]], there)
            self.assertEqual(r.returncode, 0, r.stderr)
        else:  # killed before its folder appeared: nothing was made, the run starts again
            self.session_run("killed", there, proto="k.json")
            made = sessions(there / "killed")
        self.assert_sessions_alike(straight, made[0])
        # The kept attempts (a kill keeps none) aside, nothing half made is left.
        left = [p for p in (there / "killed").rglob("*") if p.name.endswith(".part") or ".partial." in p.name]
        self.assertEqual(left, [])

    def test_session_record_reruns_elsewhere_to_its_saved_trace(self):
        record = trial_records(self.session)[1]
        there = self.folder("session-rerun-") / ODD
        there.mkdir()
        shutil.copy(record, there / "copied.json")
        r = run(["trial", "--spec", "copied.json", "--csv", "again.csv"], there)
        self.assertIn(r.returncode, (0, 1), r.stderr)
        saved = run(["trace", record.with_suffix("").with_suffix(".trace.h5")], there)
        self.assertEqual(saved.returncode, 0, saved.stderr)
        self.assertEqual((there / "again.csv").read_bytes(), saved.stdout)

    def replay_protocol(self, folder):
        """A protocol of one replay condition whose teacher is `t.json` beside it (relative to the protocol)."""
        folder.mkdir(parents=True, exist_ok=True)
        shutil.copy(self.base / "t.json", folder / "t.json")
        text = {"name": "r20r", "conditions": [{"name": "R", "mode": "replay", "teachers": {YI: "t.json"}}],
                "test": {"characters": [YI], "conditions": ["R"], "repetitions": 2}, "trial": {"max_duration_s": 2}}
        (folder / "rp.json").write_text(json.dumps(text))
        return folder / "rp.json"

    def test_replay_session_from_another_folder_saves_what_one_from_the_protocols_folder_saves(self):
        there = self.folder("replay-session-")
        proto = self.replay_protocol(there / ODD)
        here = self.session_run("here", proto.parent, proto="rp.json")
        elsewhere = self.session_run("elsewhere", there, proto=os.path.join(ODD, "rp.json"))
        self.assert_sessions_alike(here, elsewhere, ignore=("source",))
        for session in (here, elsewhere):
            kept = list((session / "teachers").glob("*.json"))
            self.assertEqual(len(kept), 1)
            self.assertEqual(kept[0].read_bytes(), (self.base / "t.json").read_bytes())

    def test_replay_session_record_reruns_from_a_moved_copy_and_refuses_its_teacher_edited(self):
        there = self.folder("replay-moved-")
        proto = self.replay_protocol(there / "protocol")
        session = self.session_run("study", proto.parent, proto="rp.json")
        moved = there / ODD / "copy of 研究"
        shutil.copytree(session.parent.parent, moved, symlinks=True)
        copy = sessions(moved)[0]
        record = trial_records(copy)[1]
        saved = run(["trace", record.with_suffix("").with_suffix(".trace.h5")], there)
        self.assertEqual(saved.returncode, 0, saved.stderr)
        elsewhere = self.folder("replay-rerun-")
        r = run(["trial", "--spec", record, "--csv", "again.csv"], elsewhere)
        self.assertIn(r.returncode, (0, 1), r.stderr)
        self.assertEqual((elsewhere / "again.csv").read_bytes(), saved.stdout, "the re-run is not the saved trace")
        # Its kept teacher edited by one byte (white space): refused naming the SHA-256; given as --teacher, runs.
        kept = next((copy / "teachers").glob("*.json"))
        recorded = hashlib_hex(kept.read_bytes())
        kept.write_bytes(kept.read_bytes() + b"\n")
        (elsewhere / "again.csv").unlink()
        r = run(["trial", "--spec", record, "--csv", "again.csv"], elsewhere)
        self.assert_one_error(r, 1, kept.name, recorded)
        self.assertFalse((elsewhere / "again.csv").exists())
        r = run(["trial", "--spec", record, "--teacher", self.base / "t.json", "--csv", "again.csv"], elsewhere)
        self.assertIn(r.returncode, (0, 1), r.stderr)
        self.assertEqual((elsewhere / "again.csv").read_bytes(), saved.stdout)
        # Removed: refused naming it.
        kept.unlink()
        (elsewhere / "again.csv").unlink()
        r = run(["trial", "--spec", record, "--csv", "again.csv"], elsewhere)
        self.assert_one_error(r, 1, kept.name, "the replay's teacher", "the copy its session kept",
                              "give --teacher FILE")
        self.assertFalse((elsewhere / "again.csv").exists())

    def test_replay_session_record_reruns_in_python_from_another_folder_with_its_kept_teacher(self):
        import calligraphy as cg
        there = self.folder("replay-python-")
        proto = self.replay_protocol(there / "protocol")
        session = self.session_run("study", proto.parent, proto="rp.json")
        record = trial_records(session)[0]
        saved = run(["trace", record.with_suffix("").with_suffix(".trace.h5")], there)
        self.assertEqual(saved.returncode, 0, saved.stderr)
        rows = list(csv.DictReader(io.StringIO(saved.stdout.decode())))
        old = os.getcwd()
        try:
            os.chdir(self.root)
            again = cg.rerun_trial(record)   # the kept teacher, read from its session folder
        finally:
            os.chdir(old)
        self.assertEqual(len(rows), len(again.time_s))
        for i in (0, len(rows) // 2, len(rows) - 1):
            for axis, key in enumerate("xyz"):
                self.assertAlmostEqual(float(rows[i][key]), float(again.position_m[i][axis]), delta=0.6e-7)
        # Its kept teacher edited by one byte: DataError naming it and both SHA-256, as the command line.
        kept = next((session / "teachers").glob("*.json"))
        recorded = hashlib_hex(kept.read_bytes())
        kept.write_bytes(kept.read_bytes() + b" ")
        with self.assertRaises(cg.DataError) as refused:
            cg.rerun_trial(str(record))
        for needle in (kept.name, recorded, hashlib_hex(kept.read_bytes())):
            self.assertIn(needle, str(refused.exception))

    def test_session_id_under_chatham_time_is_its_utc_second(self):
        there = self.folder("chatham-")
        shutil.copy(self.root / "p.json", there)
        session = self.session_run("study", there, env_with(TZ="Pacific/Chatham", LC_ALL="C"))
        created = json.loads((session / "session.json").read_text())["created_utc"]
        self.assertRegex(created, r"Z$")
        stamp = created[:19].replace("-", "").replace(":", "").replace("T", "-")
        self.assertTrue(session.name.endswith(stamp), f"{session.name} is not named by {created}")
        for record in trial_records(session):
            self.assertRegex(json.loads(record.read_text())["start_time_utc"], r"Z$")

    def test_a_protocol_copied_byte_for_byte_is_one_design_and_one_in_crlf_is_refused(self):
        there = self.folder("protocol-copy-")
        shutil.copy(self.root / "p.json", there)
        self.session_run("study", there)
        (there / ODD).mkdir()
        shutil.copy(self.root / "p.json", there / ODD / "p.json")
        r = run(["session", "run", os.path.join(ODD, "p.json"), "--subjects", "1", "--new-subjects", *SIM,
                 "--out", "study"], there)
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertEqual(len(sessions(there / "study")), 2)
        crlf = there / "crlf.json"
        crlf.write_bytes((self.root / "p.json").read_bytes().replace(b"\n", b"\r\n") + b"\r\n")
        before = sorted(str(p) for p in (there / "study").rglob("*"))
        r = run(["session", "run", "crlf.json", "--subjects", "1", "--new-subjects", *SIM, "--out", "study"], there)
        self.assert_one_error(r, 1, "crlf.json", hashlib_hex(crlf.read_bytes()),
                              hashlib_hex((self.root / "p.json").read_bytes()))
        self.assertEqual(sorted(str(p) for p in (there / "study").rglob("*")), before)

    def test_a_record_of_other_character_data_reruns_only_with_that_data(self):
        there = self.folder("data-")
        data = there / "my data"
        data.mkdir()
        corpus = json.loads((CORPUS / f"{YI}.json").read_text())
        corpus["medians"][0][0][1] += 7   # one control point moved: other character data
        (data / f"{YI}.json").write_text(json.dumps(corpus))
        r = run(["trial", YI, "--data", "my data", "--seed", SEED, "--max-duration", "2", "--json", "d.json",
                 "--csv", "d.csv"], there)
        self.assertIn(r.returncode, (0, 1), r.stderr)
        elsewhere = self.folder("data-rerun-")
        rel = os.path.relpath(data, elsewhere)
        _, got = self.rerun(there / "d.json", elsewhere, None, "--data", rel)
        self.assertEqual(got, (there / "d.csv").read_bytes())
        (elsewhere / "x.csv").unlink()
        r = run(["trial", "--spec", there / "d.json", "--csv", "x.csv"], elsewhere)
        self.assert_one_error(r, 1, "SHA-256")
        self.assertFalse((elsewhere / "x.csv").exists())

    def test_plan_trace_and_score_under_another_environment_are_byte_for_byte(self):
        h5 = trial_records(self.session)[0].with_suffix("").with_suffix(".trace.h5")
        there = self.folder("env-tools-")
        shutil.copy(self.root / "p.json", there / "p.json")
        changed = env_with(TZ="Pacific/Chatham", LC_ALL="C", LANG="C", HOME=None, TMPDIR=str(there))
        commands = [["session", "plan", "p.json", "--subjects", "2", "--json"],
                    ["trace", h5],
                    ["score", h5, "--character", YI, "--json", "-"]]
        for argv in commands:
            with self.subTest(command=argv[0]):
                a = run(argv, there)
                b = run(argv, there, env=changed)
                c = subprocess.run(["taskset", "-c", "0", CLI, *map(str, argv)], cwd=there, env=env_with(
                    LC_ALL="C.UTF-8"), stdout=subprocess.PIPE, stderr=subprocess.PIPE, timeout=60)
                self.assertEqual(a.returncode, 0, a.stderr)
                self.assertEqual(a.stdout, b.stdout)
                self.assertEqual(a.stdout, c.stdout)
        self.assertEqual(sorted(p.name for p in there.iterdir()), ["p.json"], "a temporary was left in TMPDIR")

    # ---- report --csv ----

    def report_csv(self, study, cwd, env=None, *extra):
        out = Path(tempfile.mkdtemp(prefix="tables-", dir=self.root))
        r = run(["report", study, "--csv", out, *extra], cwd, env=env)
        self.assertEqual(r.returncode, 0, r.stderr)
        return (out / "trials.csv").read_bytes(), (out / "strokes.csv").read_bytes()

    def test_report_csv_twice_and_under_another_environment_is_byte_for_byte(self):
        first = self.report_csv("study", self.root)
        self.assertEqual(first, self.report_csv("study", self.root))
        changed = env_with(TZ="Pacific/Chatham", LC_ALL="C", LANG="C", HOME=None)
        self.assertEqual(first, self.report_csv("study", self.root, changed, "--jobs", "1"))
        self.assertEqual(first, self.report_csv("study", self.root, env_with(LC_ALL="C.UTF-8"), "--jobs", "2"))

    def assert_tables_differ_in_trace_file_only(self, got, want, prefix):
        for g, w in zip(got, want):
            rows_g = list(csv.DictReader(io.StringIO(g.decode())))
            rows_w = list(csv.DictReader(io.StringIO(w.decode())))
            self.assertEqual(len(rows_g), len(rows_w))
            for rg, rw in zip(rows_g, rows_w):
                if "trace_file" in rw:
                    self.assertEqual(rg["trace_file"], rw["trace_file"].replace("study", prefix, 1))
                self.assertEqual({k: v for k, v in rg.items() if k != "trace_file"},
                                 {k: v for k, v in rw.items() if k != "trace_file"})

    def test_report_csv_of_a_moved_copy_differs_in_trace_file_only(self):
        want = self.report_csv("study", self.root)
        there = self.folder("moved-") / ODD
        shutil.copytree(self.study, there / "研究 copy", symlinks=True)
        got = self.report_csv("研究 copy", there)
        self.assert_tables_differ_in_trace_file_only(got, want, "研究 copy")

    def test_report_csv_through_a_link_and_a_relative_path_differs_in_trace_file_only(self):
        want = self.report_csv("study", self.root)
        there = self.folder("via-link-")
        (there / "linked").symlink_to(self.study)
        self.assert_tables_differ_in_trace_file_only(self.report_csv("linked", there), want, "linked")
        rel = os.path.relpath(self.study, there)
        self.assert_tables_differ_in_trace_file_only(self.report_csv(rel, there), want, rel)

    # ---- score of one trace written otherwise ----

    def score(self, trace, cwd, chars=YI):
        r = run(["score", trace, "--character", chars, "--json", "-"], cwd)
        self.assertEqual(r.returncode, 0, r.stderr)
        got = json.loads(r.stdout)
        got.pop("trace", None)
        return got

    def test_score_of_the_trace_under_another_name_gives_the_same_verdicts(self):
        there = self.folder("renamed-") / ODD
        there.mkdir()
        shutil.copy(self.base / "a.csv", there / "筆跡 trace.txt")
        self.assertEqual(self.score("筆跡 trace.txt", there), self.score(self.base / "a.csv", self.root))

    def test_score_of_crlf_bom_quoted_and_reordered_columns_gives_the_same_verdicts(self):
        want = self.score(self.base / "a.csv", self.root)
        there = self.folder("spelt-")
        text = self.a_csv.decode()
        rows = list(csv.reader(io.StringIO(text)))
        variants = {
            "crlf.csv": text.replace("\n", "\r\n").encode(),
            "bom.csv": b"\xef\xbb\xbf" + self.a_csv,
            "bom-crlf.csv": b"\xef\xbb\xbf" + text.replace("\n", "\r\n").encode(),
            "quoted.csv": "".join(",".join(f'"{c}"' for c in row) + "\n" for row in rows).encode(),
            # Columns in reverse order: they are found by their names in the header.
            "reordered.csv": "".join(",".join(reversed(row)) + "\n" for row in rows).encode(),
            # Only the columns score reads, with the pen as z, in another order.
            "few.csv": "".join(",".join(row[i] for i in (3, 1, 0, 2)) + "\n" for row in rows).encode(),
        }
        for name, data in variants.items():
            with self.subTest(variant=name):
                (there / name).write_bytes(data)
                self.assertEqual(self.score(name, there), want)

    def test_score_of_the_saved_hdf5_trace_equals_score_of_its_csv(self):
        record = trial_records(self.session)[0]
        h5 = record.with_suffix("").with_suffix(".trace.h5")
        there = self.folder("h5-")
        r = run(["trace", h5, "--csv", "t.csv"], there)
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertEqual(self.score(h5, there), self.score("t.csv", there))

    # ---- the command line and Python, each re-running the other's record ----

    def test_python_record_reruns_on_the_command_line_to_the_same_trace(self):
        import calligraphy as cg
        result = cg.simulate_trial(YI, seed=int(SEED), max_duration_s=2.0)
        there = self.folder("python-") / ODD
        there.mkdir()
        (there / "py.json").write_text(json.dumps(result.metrics))
        _, got = self.rerun("py.json", there)
        self.assertEqual(got, self.a_csv, "the command line's re-run of Python's record is not the CLI's trial")

    def test_cli_record_reruns_in_python_from_another_folder(self):
        import calligraphy as cg
        there = self.folder("cli-to-python-") / ODD
        there.mkdir()
        shutil.copy(self.base / "a.json", there / "記録.json")
        old = os.getcwd()
        try:
            os.chdir(self.root)
            again = cg.rerun_trial(str(there / "記録.json"))
        finally:
            os.chdir(old)
        rows = list(csv.DictReader(io.StringIO(self.a_csv.decode())))
        self.assertEqual(len(rows), len(again.time_s))
        for i in (0, len(rows) // 2, len(rows) - 1):
            for axis, key in enumerate("xyz"):
                self.assertAlmostEqual(float(rows[i][key]), float(again.position_m[i][axis]), delta=0.6e-7)
        want = json.loads(self.a_json)
        for key in ("end_reason", "strokes_completed", "total_time_s", "pen_down_time_s", "max_force_n",
                    "mean_deviation_m", "seed", "specification"):
            self.assertEqual(again.metrics[key], want[key], key)

    def test_python_replay_record_reruns_on_the_command_line_with_its_teacher_given(self):
        import calligraphy as cg
        teacher = cg.TeacherRecording.load(str(self.base / "t.json"))
        result = cg.simulate_trial(YI, seed=int(SEED), max_duration_s=2.0, teacher=teacher)
        there = self.folder("python-replay-")
        (there / "py.json").write_text(json.dumps(result.metrics))
        # Its teacher was given as samples: the record names no file, so the command line needs --teacher.
        r = run(["trial", "--spec", "py.json", "--csv", "x.csv"], there)
        self.assert_one_error(r, 2, "--teacher")
        self.assertFalse((there / "x.csv").exists())
        _, got = self.rerun("py.json", there, None, "--teacher", self.base / "t.json")
        self.assertEqual(got, self.r_csv, "Python's replay re-run by the command line is not the CLI's replay")

    def test_cli_replay_record_reruns_in_python_reading_the_teacher_it_names(self):
        import calligraphy as cg
        rows = list(csv.DictReader(io.StringIO(self.r_csv.decode())))
        old = os.getcwd()
        try:
            os.chdir(self.base)   # the record's relative teacher name, read from the working folder
            again = cg.rerun_trial("r.json")
            os.chdir(self.root)   # from elsewhere it is not there: named
            with self.assertRaises(cg.DataError) as refused:
                cg.rerun_trial(str(self.base / "r.json"))
        finally:
            os.chdir(old)
        self.assertIn("t.json", str(refused.exception))
        self.assertEqual(len(rows), len(again.time_s))
        for i in (0, len(rows) // 2, len(rows) - 1):
            for axis, key in enumerate("xyz"):
                self.assertAlmostEqual(float(rows[i][key]), float(again.position_m[i][axis]), delta=0.6e-7)

    # ---- what must differ ----

    def test_another_seed_gives_another_run(self):
        there = self.folder("seed-")
        r = run(["trial", YI, "--seed", "6", "--max-duration", "2", "--csv", "x.csv"], there)
        self.assertIn(r.returncode, (0, 1), r.stderr)
        self.assertNotEqual((there / "x.csv").read_bytes(), self.a_csv)
        import calligraphy as cg
        five = cg.simulate_trial(YI, seed=5, max_duration_s=0.5).position_m
        six = cg.simulate_trial(YI, seed=6, max_duration_s=0.5).position_m
        self.assertFalse((five == six).all(), "seeds 5 and 6 wrote the same trace")

    def test_report_refuses_a_trace_edited_by_one_byte_or_swapped_naming_it(self):
        there = self.folder("edited-trace-")
        shutil.copytree(self.study, there / "study", symlinks=True)
        session = sessions(there / "study")[0]
        first, second = trial_records(session)
        h5 = first.with_suffix("").with_suffix(".trace.h5")
        original = h5.read_bytes()
        # One byte edited: the trace's own check (its length and CRC-32) or its SHA-256 refuses it by name.
        data = bytearray(original)
        data[len(data) // 2] ^= 0x01
        h5.write_bytes(bytes(data))
        r = run(["report", "study", "--out", "page.html"], there)
        self.assert_one_error(r, 1, h5.name)
        self.assertFalse((there / "page.html").exists(), "a page was written from a damaged trace")
        # A whole, valid trace of the other trial in its place: only the SHA-256 the record states tells.
        shutil.copy(second.with_suffix("").with_suffix(".trace.h5"), h5)
        want = json.loads(first.read_text())["files"]["trace_sha256"]
        got = hashlib.sha256(h5.read_bytes()).hexdigest()
        r = run(["report", "study", "--out", "page.html"], there)
        self.assert_one_error(r, 1, h5.name, want, got)
        self.assertFalse((there / "page.html").exists(), "a page was written from a trace not the record's")

if __name__ == "__main__":
    unittest.main()
