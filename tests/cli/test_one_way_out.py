#!/usr/bin/env python3
"""Every file a command writes leaves by one way (docs/cli.md, "Outputs" and "Checked before anything runs"),
run by CTest as `cli_one_way_out_tests`: hostile cases written from the documentation, as an outsider would.

- Forge and link: an output that is an input of the same command (the same path, another spelling of it, a
  symbolic or a hard link to it) for `trace`, `trial --csv/--json/--svg/--record` beside `--spec` and
  `--teacher`, `score` and `report --csv` is refused with exit 2 and one line naming both, and the input is
  unchanged byte for byte.
- Fill: under a file size limit (RLIMIT_FSIZE, SIGXFSZ left at its default as `ulimit -f` leaves it) each
  command exits 1 with one line naming the file, leaves no temporary and keeps the earlier file.
- Cut: standard output closed by its reader (`calligraphy trace T | head -1`, SIGPIPE at its default) is one
  error line and exit 1, not a silent death by SIGPIPE.
- Race: runs writing one output (or one pair of tables) at once leave whole files and no temporary.
- The journal of a set killed between its renames (Release builds, with the fault shim): copied with its folder,
  it completes the copy only; planted in another folder, it changes nothing outside that folder, for `report
  --csv` and for the Python report's writer. And the Python study report onto a link to a session's file.
- A set over sibling folders its user owns under a folder that user cannot write (as nobody through setpriv or
  runuser when run as root): written with no journal or temporary left, and an output in the folder it cannot
  write refused before any work.

CALLIGRAPHY_CLI names the program and CALLIGRAPHY_SOURCE_DIR the source tree. Standard library only.
"""
import hashlib
import json
import os
import pwd
import resource
import shutil
import sys
import subprocess
import tempfile
import unittest
from pathlib import Path

CLI = os.environ.get("CALLIGRAPHY_CLI", "")
SHIM = os.environ.get("CALLIGRAPHY_FAULT_SHIM", "")  # set in Release builds (tests/fault_injection)
SOURCE = Path(os.environ.get("CALLIGRAPHY_SOURCE_DIR", Path(__file__).resolve().parents[2]))
PROTOCOL = SOURCE / "examples" / "protocols" / "paper-table5.json"
TIMEOUT_S = 120
TEMPORARY_MARKS = (".tmp-", ".kept-", ".calligraphy-set-")


def digest(path):
    return hashlib.sha256(Path(path).read_bytes()).hexdigest()


def temporaries(folder):
    return sorted(str(path) for path in Path(folder).rglob("*") if any(m in path.name for m in TEMPORARY_MARKS))


class OneWayOut(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        if not CLI or not Path(CLI).exists():
            raise AssertionError(f"CALLIGRAPHY_CLI={CLI!r} is not the calligraphy program: run through ctest")
        cls.scratch = tempfile.TemporaryDirectory(prefix="calligraphy-one-way-")
        root = Path(cls.scratch.name)
        document = json.loads(PROTOCOL.read_text(encoding="utf-8"))
        del document["practice"]
        document["test"].update({"characters": ["大"], "conditions": ["haptic"], "repetitions": 1})
        document["order"]["conditions"] = "fixed"
        document["breaks"] = {}
        (root / "small.json").write_text(json.dumps(document, ensure_ascii=False), encoding="utf-8")
        done = subprocess.run([CLI, "session", "run", root / "small.json", "--writer", "simulated", "--subjects",
                               "1", "--out", root / "study"], capture_output=True, timeout=TIMEOUT_S)
        assert done.returncode == 0, done.stderr.decode()
        (cls.session,) = (root / "study" / "S01").iterdir()
        (cls.record,) = (cls.session / "trials").glob("*.json")
        cls.trace = cls.record.with_suffix(".trace.h5")

    @classmethod
    def tearDownClass(cls):
        cls.scratch.cleanup()

    def setUp(self):
        self.folder = tempfile.TemporaryDirectory(prefix="calligraphy-one-way-case-")
        self.cwd = Path(self.folder.name)

    def tearDown(self):
        self.folder.cleanup()

    def run_cli(self, *args, limit_file_bytes=None, stdout=subprocess.PIPE):
        def limit():  # as `ulimit -f` leaves it: SIGXFSZ at its default
            resource.setrlimit(resource.RLIMIT_FSIZE, (limit_file_bytes, limit_file_bytes))

        return subprocess.run([CLI, *map(str, args)], cwd=self.cwd, stdout=stdout, stderr=subprocess.PIPE,
                              timeout=TIMEOUT_S, preexec_fn=limit if limit_file_bytes is not None else None)

    def assert_one_error(self, result, status, *names):
        message = result.stderr.decode(errors="replace")
        self.assertEqual(result.returncode, status, message)
        self.assertEqual(len(message.strip().splitlines()), 1, message)
        self.assertIn(": error: ", message)
        for name in names:
            self.assertIn(str(name), message)
        return message

    def copy(self, source, name):
        target = self.cwd / name
        target.write_bytes(Path(source).read_bytes())
        return target

    def trial_record(self):
        result = self.run_cli("trial", "乙", "--seed", "3", "--json", "R.json")
        self.assertEqual(result.returncode, 0, result.stderr.decode())
        return self.cwd / "R.json"

    def assert_output_on_input_refused(self, arguments, input_path, output_spelling):
        before = digest(input_path)
        listing = sorted(os.listdir(self.cwd))
        result = self.run_cli(*arguments)
        self.assert_one_error(result, 2, output_spelling, Path(input_path).name)
        self.assertEqual(digest(input_path), before, f"{input_path} was changed")
        self.assertEqual(sorted(os.listdir(self.cwd)), listing)

    # --- trace -----------------------------------------------------------------------------------------------

    def test_trace_onto_its_own_trace(self):
        trace = self.copy(self.trace, "T.trace.h5")
        self.assert_output_on_input_refused(("trace", "T.trace.h5", "--csv", "T.trace.h5"), trace, "T.trace.h5")

    def test_trace_onto_its_trace_spelled_another_way(self):
        trace = self.copy(self.trace, "T.trace.h5")
        (self.cwd / "sub").mkdir()
        self.assert_output_on_input_refused(("trace", "T.trace.h5", "--csv", "sub/../T.trace.h5"), trace,
                                            "sub/../T.trace.h5")

    def test_trace_onto_a_symbolic_link_to_its_trace(self):
        trace = self.copy(self.trace, "T.trace.h5")
        os.symlink("T.trace.h5", self.cwd / "link.csv")
        self.assert_output_on_input_refused(("trace", "T.trace.h5", "--csv", "link.csv"), trace, "link.csv")

    def test_trace_onto_a_hard_link_to_its_trace(self):
        trace = self.copy(self.trace, "T.trace.h5")
        os.link(trace, self.cwd / "hard.csv")
        self.assert_output_on_input_refused(("trace", "T.trace.h5", "--csv", "hard.csv"), trace, "hard.csv")

    def test_trace_read_through_a_link_onto_the_file(self):
        trace = self.copy(self.trace, "T.trace.h5")
        os.symlink("T.trace.h5", self.cwd / "in.trace.h5")
        self.assert_output_on_input_refused(("trace", "in.trace.h5", "--csv", "T.trace.h5"), trace, "T.trace.h5")

    def test_trace_under_a_file_size_limit(self):
        (self.cwd / "out.csv").write_text("earlier\n")
        result = self.run_cli("trace", self.trace, "--csv", "out.csv", limit_file_bytes=4096)
        self.assert_one_error(result, 1, "out.csv")
        self.assertEqual((self.cwd / "out.csv").read_text(), "earlier\n")
        self.assertEqual(temporaries(self.cwd), [])

    def test_trace_into_a_closed_pipe(self):
        reading, writing = os.pipe()
        os.close(reading)
        try:
            result = self.run_cli("trace", self.trace, stdout=writing)
        finally:
            os.close(writing)
        self.assert_one_error(result, 1, "standard output")

    def test_trace_onto_a_folder(self):
        (self.cwd / "folder").mkdir()
        result = self.run_cli("trace", self.trace, "--csv", "folder")
        self.assert_one_error(result, 1, "folder")

    def test_two_traces_racing_onto_one_file(self):
        out = self.cwd / "out.csv"
        whole = self.run_cli("trace", self.trace).stdout
        runs = [subprocess.Popen([CLI, "trace", str(self.trace), "--csv", str(out)], stderr=subprocess.PIPE)
                for _ in range(4)]
        for run in runs:
            _, stderr = run.communicate(timeout=TIMEOUT_S)
            self.assertEqual(run.returncode, 0, stderr.decode())
        self.assertEqual(out.read_bytes(), whole)
        self.assertEqual(temporaries(self.cwd), [])

    # --- trial -----------------------------------------------------------------------------------------------

    def test_trial_csv_onto_the_record_it_reruns(self):
        record = self.trial_record()
        self.assert_output_on_input_refused(("trial", "--spec", "R.json", "--csv", "R.json"), record, "--csv")

    def test_trial_json_onto_a_symbolic_link_to_its_record(self):
        record = self.trial_record()
        os.symlink("R.json", self.cwd / "link.json")
        self.assert_output_on_input_refused(("trial", "--spec", "R.json", "--json", "link.json"), record,
                                            "link.json")

    def test_trial_svg_onto_a_hard_link_to_its_record(self):
        record = self.trial_record()
        os.link(record, self.cwd / "hard.svg")
        self.assert_output_on_input_refused(("trial", "--spec", "R.json", "--svg", "hard.svg"), record,
                                            "hard.svg")

    def test_trial_record_onto_its_teacher(self):
        result = self.run_cli("trial", "乙", "--record", "teacher.json")
        self.assertEqual(result.returncode, 0, result.stderr.decode())
        self.assert_output_on_input_refused(("trial", "乙", "--guidance-mode", "replay", "--teacher",
                                             "teacher.json", "--record", "./teacher.json"),
                                            self.cwd / "teacher.json", "./teacher.json")

    def test_trial_under_a_file_size_limit(self):
        (self.cwd / "out.csv").write_text("earlier\n")
        result = self.run_cli("trial", "乙", "--csv", "out.csv", limit_file_bytes=4096)
        self.assert_one_error(result, 1, "out.csv")
        self.assertEqual((self.cwd / "out.csv").read_text(), "earlier\n")
        self.assertEqual(temporaries(self.cwd), [])

    def test_trial_csv_into_a_closed_pipe(self):
        reading, writing = os.pipe()
        os.close(reading)
        try:
            result = self.run_cli("trial", "乙", "--csv", "-", stdout=writing)
        finally:
            os.close(writing)
        self.assert_one_error(result, 1, "standard output")

    # --- score -----------------------------------------------------------------------------------------------

    def score_trace(self):
        result = self.run_cli("trial", "乙", "--seed", "3", "--csv", "T.csv")
        self.assertEqual(result.returncode, 0, result.stderr.decode())
        return self.cwd / "T.csv"

    def test_score_json_onto_its_trace(self):
        trace = self.score_trace()
        self.assert_output_on_input_refused(("score", "T.csv", "--character", "乙", "--json", "./T.csv"), trace,
                                            "./T.csv")

    def test_score_json_onto_a_hard_link_to_its_trace(self):
        trace = self.score_trace()
        os.link(trace, self.cwd / "hard.json")
        self.assert_output_on_input_refused(("score", "T.csv", "--character", "乙", "--json", "hard.json"), trace,
                                            "hard.json")

    def test_score_under_a_file_size_limit(self):
        self.score_trace()
        (self.cwd / "S.json").write_text("earlier\n")
        result = self.run_cli("score", "T.csv", "--character", "乙", "--json", "S.json", limit_file_bytes=64)
        self.assert_one_error(result, 1, "S.json")
        self.assertEqual((self.cwd / "S.json").read_text(), "earlier\n")
        self.assertEqual(temporaries(self.cwd), [])

    # --- report --csv ----------------------------------------------------------------------------------------

    def test_report_tables_onto_a_hard_link_to_a_saved_record(self):
        tables = self.cwd / "tables"
        tables.mkdir()
        study = self.cwd / "study"
        subprocess.run(["cp", "-a", str(self.session.parent.parent), str(study)], check=True)
        (record,) = study.glob("S01/*/trials/*.json")
        os.link(record, tables / "trials.csv")
        before = digest(record)
        result = self.run_cli("report", "study", "--csv", "tables")
        self.assert_one_error(result, 2, "trials.csv", record.name)
        self.assertEqual(digest(record), before)

    def test_report_tables_onto_a_symbolic_link_to_session_json(self):
        tables = self.cwd / "tables"
        tables.mkdir()
        study = self.cwd / "study"
        subprocess.run(["cp", "-a", str(self.session.parent.parent), str(study)], check=True)
        (manifest,) = study.glob("S01/*/session.json")
        os.symlink(manifest, tables / "strokes.csv")
        before = digest(manifest)
        result = self.run_cli("report", "study", "--csv", "tables")
        self.assert_one_error(result, 2, "strokes.csv", "session.json")
        self.assertEqual(digest(manifest), before)

    def test_reports_racing_onto_one_tables_folder(self):
        tables = self.cwd / "tables"
        tables.mkdir()
        study = str(self.session.parent.parent)
        runs = [subprocess.Popen([CLI, "report", study, "--csv", str(tables)], stdout=subprocess.DEVNULL,
                                 stderr=subprocess.PIPE) for _ in range(4)]
        for run in runs:
            _, stderr = run.communicate(timeout=TIMEOUT_S)
            self.assertEqual(run.returncode, 0, stderr.decode())
        self.assertEqual(sorted(os.listdir(tables)), ["strokes.csv", "trials.csv"])

    def test_report_tables_under_a_file_size_limit(self):
        tables = self.cwd / "tables"
        tables.mkdir()
        result = self.run_cli("report", self.session.parent.parent, "--csv", "tables", limit_file_bytes=256)
        self.assert_one_error(result, 1, "tables")
        self.assertEqual(sorted(os.listdir(tables)), [])

    def test_study_report_onto_a_symbolic_link_to_session_json(self):
        found = subprocess.run([sys.executable, "-c", "import pandas, calligraphy.study_report"], cwd=self.cwd,
                               capture_output=True, timeout=TIMEOUT_S)
        if found.returncode != 0:  # sanitizer builds have no Python module; the report needs pandas
            self.skipTest(f"no Python module or no pandas: {found.stderr.decode().strip().splitlines()[-1:]}")
        study = self.cwd / "study"
        shutil.copytree(self.session.parent.parent, study, symlinks=True)
        (manifest,) = study.glob("S01/*/session.json")
        (self.cwd / "report").mkdir()
        os.symlink(manifest, self.cwd / "report" / "index.html")
        before = digest(manifest)
        result = subprocess.run([sys.executable, "-m", "calligraphy.study_report", "study", "--out", "report"],
                                cwd=self.cwd, capture_output=True, timeout=TIMEOUT_S)
        self.assert_one_error(result, 2, "index.html", "session.json")
        self.assertEqual(digest(manifest), before)

    def test_study_report_through_a_link_planted_in_its_folder_writes_nothing_outside_it(self):
        # A set of files is written only in its own folders (docs/cli.md, "Outputs"): a link in the report
        # folder to a file elsewhere is refused, naming it, and the file it names is left alone.
        found = subprocess.run([sys.executable, "-c", "import pandas, calligraphy.study_report"], cwd=self.cwd,
                               capture_output=True, timeout=TIMEOUT_S)
        if found.returncode != 0:  # sanitizer builds have no Python module; the report needs pandas
            self.skipTest(f"no Python module or no pandas: {found.stderr.decode().strip().splitlines()[-1:]}")
        outside = self.cwd / "outside"
        outside.mkdir()
        victim = outside / "precious.txt"
        victim.write_text("keep me\n")
        (self.cwd / "report").mkdir()
        os.symlink(victim, self.cwd / "report" / "index.html")
        result = subprocess.run([sys.executable, "-m", "calligraphy.study_report", str(self.session.parent.parent),
                                 "--out", "report"], cwd=self.cwd, capture_output=True, timeout=TIMEOUT_S)
        message = result.stderr.decode(errors="replace")
        self.assertEqual(result.returncode, 1, message)
        self.assertEqual(len(message.strip().splitlines()), 1, message)
        self.assertIn("index.html", message)
        self.assertIn("symbolic link", message)
        self.assertEqual(victim.read_text(), "keep me\n")
        self.assertEqual(sorted(p.name for p in outside.iterdir()), ["precious.txt"])
        self.assertTrue((self.cwd / "report" / "index.html").is_symlink())

    # --- the journal of a set (report --csv, study_report) ---------------------------------------------------

    def killed_between_renames(self, tables):
        """`report --csv TABLES` replacing an earlier pair, killed between its two renames: the journal it
        leaves (as an outsider makes one). Returns {name: bytes} of the files under TABLES, hidden ones too."""
        if not SHIM or not Path(SHIM).exists():
            self.skipTest("the fault shim is built for Release only (tests/fault_injection)")
        tables.mkdir()
        for name in ("trials.csv", "strokes.csv"):
            (tables / name).write_text(f"earlier {name}\n")
        environment = dict(os.environ, LD_PRELOAD=SHIM, CALLIGRAPHY_FAULT_UNDER=str(tables),
                           CALLIGRAPHY_FAULT_CALL="rename", CALLIGRAPHY_FAULT_AT="2", CALLIGRAPHY_FAULT_KILL="1")
        killed = subprocess.run([CLI, "report", str(self.session.parent.parent), "--csv", str(tables), "--jobs",
                                 "1"], cwd=self.cwd, capture_output=True, env=environment, timeout=TIMEOUT_S)
        self.assertEqual(killed.returncode, -9, killed.stderr.decode())
        journals = [p for p in tables.iterdir() if p.name.startswith(".calligraphy-set-")]
        self.assertEqual(len(journals), 1, sorted(os.listdir(tables)))
        return journals[0]

    def files_under(self, folder):
        return {str(p.relative_to(folder)): p.read_bytes() for p in sorted(Path(folder).rglob("*")) if p.is_file()}

    def test_a_journal_copied_with_its_folder_completes_only_the_copy(self):
        tables = self.cwd / "tables"
        self.killed_between_renames(tables)
        original = self.files_under(tables)
        shutil.copytree(tables, self.cwd / "copy", symlinks=True)
        result = self.run_cli("report", self.session.parent.parent, "--csv", "copy")
        self.assertEqual(result.returncode, 0, result.stderr.decode())
        self.assertEqual(self.files_under(tables), original, "reporting into the copy changed the original")
        self.assertEqual(temporaries(self.cwd / "copy"), [])

    def test_a_journal_planted_in_another_folder_changes_nothing_outside_it(self):
        tables = self.cwd / "tables"
        journal = self.killed_between_renames(tables)
        original = self.files_under(tables)
        figures = self.cwd / "figures"
        figures.mkdir()
        shutil.copy(journal, figures / journal.name)
        self.run_cli("report", self.session.parent.parent, "--csv", "figures")
        self.assertEqual(self.files_under(tables), original, "a journal planted in figures/ changed tables/")

    def test_a_journal_planted_for_the_python_report_changes_nothing_outside_its_folder(self):
        tables = self.cwd / "tables"
        journal = self.killed_between_renames(tables)
        original = self.files_under(tables)
        figures = self.cwd / "figures"
        figures.mkdir()
        shutil.copy(journal, figures / journal.name)
        code = ("import pathlib, sys\nfrom calligraphy import study_report\n"
                "try:\n    study_report._write_together({pathlib.Path('figures/a.txt'): b'a'})\n"
                "except OSError as error:\n    print(f'study_report: error: {error}', file=sys.stderr)\n"
                "    sys.exit(1)\n")
        result = subprocess.run([sys.executable, "-c", code], cwd=self.cwd, capture_output=True, timeout=TIMEOUT_S)
        self.assertIn(result.returncode, (0, 1), result.stderr.decode())  # ran: the module was found
        self.assertEqual(self.files_under(tables), original, "a journal planted in figures/ changed tables/")


    # --- a set over folders that share no folder the user can write -----------------------------------------

    def as_a_user_who_is_not_root(self):
        """(command prefix, uid, gid) running a program as a user who is not root: this process's own user when
        it is not root, else nobody through setpriv or runuser. Skips, saying why, when neither works."""
        if os.geteuid() != 0:
            return [], os.geteuid(), os.getegid()
        try:
            nobody = pwd.getpwnam("nobody")
        except KeyError:
            self.skipTest("running as root, and there is no user nobody to run as")
        uid, gid = nobody.pw_uid, nobody.pw_gid
        tried = []
        for prefix in (["setpriv", f"--reuid={uid}", f"--regid={gid}", "--clear-groups"],
                       ["runuser", "-u", "nobody", "--"]):
            if shutil.which(prefix[0]) is None:
                tried.append(f"{prefix[0]}: not installed")
                continue
            probe = subprocess.run([*prefix, "id", "-u"], capture_output=True, timeout=TIMEOUT_S)
            if probe.returncode == 0 and probe.stdout.strip() == str(uid).encode():
                return prefix, uid, gid
            tried.append(f"{prefix[0]}: {probe.stderr.decode(errors='replace').strip()[:200]}")
        self.skipTest("running as root, and cannot run a program as nobody (" + "; ".join(tried) + ")")

    def test_a_set_over_sibling_folders_under_a_folder_the_user_cannot_write(self):
        """`report --csv BASE/tables --out BASE/site/report.html`, run by a user who owns tables/ and site/ but
        cannot write BASE (nor /): the set is written, twice (the second replacing the first), and no journal,
        temporary or second name is left anywhere. An --out in BASE itself is refused before any work (exit 1,
        one line naming the folder), and nothing changes."""
        prefix, uid, gid = self.as_a_user_who_is_not_root()
        base = Path(tempfile.mkdtemp(prefix="calligraphy-one-way-base-"))
        self.addCleanup(shutil.rmtree, base, ignore_errors=True)
        self.addCleanup(os.chmod, base, 0o755)
        study = base / "study"
        shutil.copytree(self.session.parent.parent, study, symlinks=True)
        for path in [study, *study.rglob("*")]:
            if not path.is_symlink():
                path.chmod(0o755 if path.is_dir() else 0o644)
        for name in ("tables", "site"):
            (base / name).mkdir()
            os.chown(base / name, uid, gid)
        base.chmod(0o555)  # readable, not writable: a user who is not root cannot make a file in it

        def report(out):
            return subprocess.run([*prefix, CLI, "report", study, "--csv", base / "tables", "--out", out],
                                  cwd=base, capture_output=True, timeout=TIMEOUT_S)

        for attempt in ("first", "second"):
            result = report(base / "site" / "report.html")
            self.assertEqual(result.returncode, 0, f"{attempt} run: {result.stderr.decode(errors='replace')}")
            self.assertEqual(sorted(os.listdir(base / "tables")), ["strokes.csv", "trials.csv"])
            self.assertTrue((base / "site" / "report.html").is_file())
            self.assertEqual(temporaries(base), [], f"left behind by the {attempt} run")
        before = self.files_under(base)
        refused = report(base / "report.html")
        self.assert_one_error(refused, 1, str(base))
        self.assertIn("not writable", refused.stderr.decode())
        self.assertEqual(self.files_under(base), before)
        self.assertEqual(temporaries(base), [])

if __name__ == "__main__":
    unittest.main(verbosity=2)
