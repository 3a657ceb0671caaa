#!/usr/bin/env python3
"""Round 29C: every output of every command, one way out. From the docs alone (docs/cli.md's "Conventions":
"Outputs", "Checked before anything runs", "Standard output", the exit statuses; its sections on `trial`,
`trace`, `model`, `strokes`, `score`, `corpus build|validate`, `session run|cohort`, `report` and `train`;
docs/experiments.md on session folders and tidy tables; docs/testing.md for what earlier rounds took).

What is attacked: every file a command writes is written whole or not at all, '-' is standard output (two
outputs never both), an output that is an input (a `--data` file, a `--store`, a trace, a protocol, a file of
a session folder a report reads) is refused with exit 2 before any work, a write that fails is one line and
exit 1 leaving the earlier file as it was and no temporary, and a set (report's pages and tables, a cohort's
tables) never follows a link. The paths are spelt through a symbolically linked parent, `..`, hard links,
chains of dangling links and a loop; the targets are /dev/full, /dev/null, /dev/stdout on a pipe and on a
file opened for appending, a file where a folder is expected, a removed working folder; the limits a file size
limit (RLIMIT_FSIZE), few file descriptors (RLIMIT_NOFILE), a closed standard output, a pipe closed early, and
SIGTERM sent to a report once its temporaries or its page folder appear.

CALLIGRAPHY_CLI names the program; CALLIGRAPHY_SANITIZED=1 takes five cases.
"""
import json
import os
import resource
import shutil
import signal
import stat
import subprocess
import tempfile
import time
import unittest
from pathlib import Path

from outsider import CLI, ENV, OneErrorLine, error_lines, run, run_ok, sanitized_subset

load_tests = sanitized_subset({"test_two_dash_outputs_of_trial_are_one_usage_error_and_nothing_written",
                               "test_corpus_build_out_onto_a_data_file_through_a_linked_folder_is_refused",
                               "test_corpus_build_onto_dev_full_is_one_line_and_exit_1",
                               "test_relative_output_after_the_working_folder_was_removed_is_refused",
                               "test_dash_for_out_and_features_is_refused_naming_the_option"})

CHAR = "十"
DATA_SOURCE = Path(os.environ.get("CALLIGRAPHY_CORPUS_DIR",
                                  "/root/.cache/calligraphy/hanzi-writer-data-2.0.1")) / f"{CHAR}.json"
PROTOCOL = {"name": "tiny", "conditions": [{"name": "h", "mode": "haptic"}],
            "test": {"characters": [CHAR], "conditions": ["h"], "repetitions": 1},
            "trial": {"max_duration_s": 20}}


def snapshot(path):
    """The bytes, mode and mtime of a file (None when it does not exist): what a refusal must leave as it was."""
    p = Path(path)
    if not p.exists() and not p.is_symlink():
        return None
    st = p.lstat()
    data = os.readlink(p) if p.is_symlink() else (p.read_bytes() if p.is_file() else None)
    return data, st.st_mode, st.st_mtime_ns, st.st_ino


def tree(root):
    """Every name under `root`, relative, with links listed as links: what a refusal must leave as it was."""
    root = Path(root)
    found = []
    for dirpath, dirnames, filenames in os.walk(root):
        for name in dirnames + filenames:
            found.append(str((Path(dirpath) / name).relative_to(root)))
    return sorted(found)


def temporaries(root):
    """The temporaries the atomic writer leaves when it fails to remove them (`.NAME.tmp-PID-N`)."""
    return [n for n in tree(root) if ".tmp-" in Path(n).name]


def fsize_limit(nbytes):
    def limit():
        resource.setrlimit(resource.RLIMIT_FSIZE, (nbytes, nbytes))
    return limit


class Fixture(OneErrorLine, unittest.TestCase):
    """One tiny study, one trial's trace and record, a data folder of 十 and its store, made once."""

    @classmethod
    def setUpClass(cls):
        if not CLI or not Path(CLI).exists():
            raise unittest.SkipTest("CALLIGRAPHY_CLI does not name the built program")
        cls.root = Path(tempfile.mkdtemp(prefix="r29c-"))
        root = cls.root
        run_ok(["trial", CHAR, "--csv", "t.csv", "--json", "t.json"], root)
        cls.data = root / "D"
        cls.data.mkdir()
        shutil.copyfile(DATA_SOURCE, cls.data / f"{CHAR}.json")
        run_ok(["corpus", "build", "--data", "D", "--out", "S.clg"], root)
        (root / "p.json").write_text(json.dumps(PROTOCOL), encoding="utf-8")
        run_ok(["session", "run", "p.json", "--subject", "S01", "--out", "study"], root)
        cls.session = next((root / "study" / "S01").glob("tiny-S01-*"))
        cls.h5 = next((cls.session / "trials").glob("*.trace.h5"))

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.root, ignore_errors=True)

    def setUp(self):
        self.tmp = Path(tempfile.mkdtemp(prefix="case-", dir=self.root))

    def tearDown(self):
        shutil.rmtree(self.tmp, ignore_errors=True)

    def study_files(self):
        return {p: snapshot(p) for p in sorted(self.session.rglob("*"))}


class OutputOnAnInput(Fixture):
    """docs/cli.md, "Output identity": "No output may be the same file as another output of the command ... or
    as an input: --teacher, --spec, --store, any file under --data, the score and trace traces, the protocol,
    and every file of the session folders a command reads ... A collision is refused with exit status 2 naming
    both options and paths and the resolved file." "a refused command creates no folder and no file"."""

    def test_corpus_build_out_onto_a_data_file_through_a_linked_folder_is_refused(self):
        linked = self.tmp / "L"
        linked.symlink_to(self.data, target_is_directory=True)
        before = snapshot(self.data / f"{CHAR}.json")
        names = tree(self.data)
        result = run(["corpus", "build", "--data", str(self.data), "--out", str(linked / f"{CHAR}.json")],
                     self.tmp)
        self.assert_one_error(result, 2, "--out", "--data")
        self.assertEqual(snapshot(self.data / f"{CHAR}.json"), before)
        self.assertEqual(tree(self.data), names)

    def test_model_svg_onto_a_data_file_by_a_dot_dot_spelling_is_refused(self):
        (self.tmp / "sub").mkdir()
        target = self.tmp / "sub" / ".." / ".." / "D" / f"{CHAR}.json"
        before = snapshot(self.data / f"{CHAR}.json")
        result = run(["model", CHAR, "--data", str(self.data), "--svg", str(target)], self.tmp)
        self.assert_one_error(result, 2, "--svg", "--data")
        self.assertEqual(result.stdout, b"")
        self.assertEqual(snapshot(self.data / f"{CHAR}.json"), before)

    def test_trial_json_onto_the_store_through_a_hard_link_is_refused(self):
        store = self.tmp / "S.clg"
        shutil.copyfile(self.root / "S.clg", store)
        os.link(store, self.tmp / "H.json")
        before = snapshot(store)
        result = run(["trial", CHAR, "--store", "S.clg", "--json", "H.json"], self.tmp)
        self.assert_one_error(result, 2, "--json", "--store")
        self.assertEqual(result.stdout, b"", "no trial runs before the outputs are checked")
        self.assertEqual(snapshot(store), before)

    def test_trace_csv_onto_its_trace_through_a_linked_trials_folder_is_refused(self):
        linked = self.tmp / "T"
        linked.symlink_to(self.h5.parent, target_is_directory=True)
        files = self.study_files()
        result = run(["trace", str(self.h5), "--csv", str(linked / self.h5.name)], self.tmp)
        self.assert_one_error(result, 2, "--csv", self.h5.name)
        self.assertEqual(result.stdout, b"")
        self.assertEqual(self.study_files(), files)

    def test_cohort_table_that_is_its_own_protocol_is_refused(self):
        protocol = self.tmp / "trials.csv"
        protocol.write_text(json.dumps(PROTOCOL), encoding="utf-8")
        before = snapshot(protocol)
        result = run(["session", "cohort", "trials.csv", "--subjects", "1", "--csv", "."], self.tmp)
        self.assert_one_error(result, 2, "--csv", "trials.csv")
        self.assertEqual(snapshot(protocol), before)
        self.assertEqual(tree(self.tmp), ["trials.csv"])

    def test_report_page_hard_linked_to_a_session_json_is_refused(self):
        pages = self.tmp / "r_files" / "S01"
        pages.mkdir(parents=True)
        os.link(self.session / "session.json", pages / f"{self.session.name}.html")
        files = self.study_files()
        result = run(["report", str(self.root / "study"), "--out", "r.html"], self.tmp)
        self.assert_one_error(result, 2, "--out")
        self.assertEqual(self.study_files(), files)
        self.assertFalse((self.tmp / "r.html").exists())

    def test_report_table_hard_linked_to_a_session_log_is_refused(self):
        tables = self.tmp / "tables"
        tables.mkdir()
        os.link(self.session / "log.jsonl", tables / "trials.csv")
        files = self.study_files()
        result = run(["report", str(self.root / "study"), "--csv", "tables"], self.tmp)
        self.assert_one_error(result, 2, "--csv")
        self.assertEqual(self.study_files(), files)
        self.assertEqual(tree(tables), ["trials.csv"])

    def test_report_index_on_its_own_table_is_refused_naming_both(self):
        tables = self.tmp / "tables"
        tables.mkdir()
        result = run(["report", str(self.root / "study"), "--csv", "tables", "--out", "tables/trials.csv"],
                     self.tmp)
        self.assert_one_error(result, 2, "--csv", "--out")
        self.assertEqual(tree(self.tmp), ["tables"])

    def test_train_record_and_screenshot_on_one_file_are_refused_before_any_window(self):
        result = run(["train", CHAR, "--record", "r.png", "--screenshot", "./r.png"], self.tmp)
        self.assert_one_error(result, 2, "--record", "--screenshot")
        self.assertEqual(tree(self.tmp), [])


class StandardOutput(Fixture):
    """docs/cli.md, "Standard output": "the path - means standard output ... two outputs cannot both be - (nor
    - together with a --json flag). --out and --features refuse -." and "Outputs": /dev/stdout on a pipe gets
    "the file ... then whatever the command prints"; on a regular file it is replaced ("`>> f.csv` does not
    append")."""

    def test_two_dash_outputs_of_trial_are_one_usage_error_and_nothing_written(self):
        result = run(["trial", CHAR, "--json", "-", "--svg", "-", "--csv", "c.csv"], self.tmp)
        self.assert_one_error(result, 2)
        self.assertEqual(result.stdout, b"")
        self.assertEqual(tree(self.tmp), [])

    def test_dash_with_a_json_flag_is_a_usage_error(self):
        for args in (["model", CHAR, "--json", "--svg", "-"], ["strokes", "--json", "--markdown", "-"]):
            with self.subTest(args=args):
                result = run(args, self.tmp)
                self.assert_one_error(result, 2)
                self.assertEqual(result.stdout, b"")

    def test_dash_for_out_and_features_is_refused_naming_the_option(self):
        (self.tmp / "cnchar.js").write_text("x", encoding="utf-8")
        cases = [(["report", str(self.root / "study"), "--out", "-"], "--out"),
                 (["corpus", "build", "--data", str(self.data), "--out", "-"], "--out"),
                 (["corpus", "validate", "--cnchar", "cnchar.js", "--data", str(self.data), "--features", "-"],
                  "--features")]
        for args, option in cases:
            with self.subTest(args=args):
                result = run(args, self.tmp)
                self.assert_one_error(result, 2, option)
                self.assertEqual(result.stdout, b"")
                self.assertEqual(tree(self.tmp), ["cnchar.js"])

    def test_dev_stdout_on_a_pipe_gives_the_file_then_the_table(self):
        run_ok(["trial", CHAR, "--csv", "c.csv"], self.tmp)
        result = run(["trial", CHAR, "--csv", "/dev/stdout"], self.tmp)
        self.assertEqual(result.returncode, 0, result.stderr)
        csv = (self.tmp / "c.csv").read_bytes()
        self.assertEqual(result.stdout[:len(csv)], csv)
        self.assertIn(b"strokes completed", result.stdout[len(csv):])

    def test_dev_stdout_on_a_file_opened_for_appending_is_replaced_by_the_document(self):
        run_ok(["trial", CHAR, "--svg", "s.svg"], self.tmp)
        target = self.tmp / "out.svg"
        target.write_bytes(b"OLD\n")
        with open(target, "ab") as out:
            result = run(["trial", CHAR, "--svg", "/dev/stdout"], self.tmp, stdout=out)
        self.assertEqual(result.returncode, 0, result.stderr)
        self.assertEqual(target.read_bytes(), (self.tmp / "s.svg").read_bytes())

    def test_dash_into_a_regular_file_is_the_document_alone(self):
        run_ok(["model", CHAR, "--svg", "m.svg"], self.tmp)
        with open(self.tmp / "out.svg", "wb") as out:
            result = run(["model", CHAR, "--svg", "-"], self.tmp, stdout=out)
        self.assertEqual(result.returncode, 0, result.stderr)
        self.assertEqual((self.tmp / "out.svg").read_bytes(), (self.tmp / "m.svg").read_bytes())


class WriteErrors(Fixture):
    """docs/cli.md, "Outputs": "A failed write (full disk, file size limit, missing folder, read-only file)
    prints one line naming the file and the reason, exits 1, removes the temporary and leaves any earlier file
    as it was." Sets: "a failure leaves the previous pair whole"; "A command that fails removes the folders it
    made for its outputs"; "Standard output ... flushed and checked: a full disk or closed pipe ... is an error,
    not exit 0"; "The program ignores SIGXFSZ and SIGPIPE"."""

    def test_corpus_build_onto_dev_full_is_one_line_and_exit_1(self):
        result = run(["corpus", "build", "--data", str(self.data), "--out", "/dev/full"], self.tmp)
        self.assert_one_error(result, 1, "/dev/full")
        self.assertTrue(stat.S_ISCHR(os.stat("/dev/full").st_mode))

    def test_corpus_build_under_a_file_size_limit_keeps_the_earlier_store(self):
        store = self.tmp / "S.clg"
        store.write_bytes(b"earlier store\n")
        before = snapshot(store)
        result = run(["corpus", "build", "--data", str(self.data), "--out", "S.clg"], self.tmp,
                     preexec_fn=fsize_limit(500))
        self.assertEqual(result.returncode, 1, result.stderr)
        self.assertEqual([ln for ln in error_lines(result) if "error" in ln].__len__(), 1, error_lines(result))
        self.assertEqual(snapshot(store), before)
        self.assertEqual(tree(self.tmp), ["S.clg"])

    def test_report_csv_under_a_file_size_limit_keeps_the_earlier_pair(self):
        tables = self.tmp / "tables"
        tables.mkdir()
        (tables / "trials.csv").write_bytes(b"earlier trials\n")
        (tables / "strokes.csv").write_bytes(b"earlier strokes\n")
        before = {n: snapshot(tables / n) for n in ("trials.csv", "strokes.csv")}
        result = run(["report", str(self.root / "study"), "--csv", "tables"], self.tmp,
                     preexec_fn=fsize_limit(1000))
        self.assert_one_error(result, 1, "tables")
        self.assertEqual({n: snapshot(tables / n) for n in before}, before)
        self.assertEqual(tree(tables), ["strokes.csv", "trials.csv"])

    def test_cohort_csv_under_a_file_size_limit_keeps_the_earlier_pair(self):
        (self.tmp / "trials.csv").write_bytes(b"earlier trials\n")
        (self.tmp / "strokes.csv").write_bytes(b"earlier strokes\n")
        before = {n: snapshot(self.tmp / n) for n in ("trials.csv", "strokes.csv")}
        result = run(["session", "cohort", str(self.root / "p.json"), "--subjects", "1", "--csv", "."],
                     self.tmp, preexec_fn=fsize_limit(1000))
        self.assert_one_error(result, 1)
        self.assertEqual({n: snapshot(self.tmp / n) for n in before}, before)
        self.assertEqual(tree(self.tmp), ["strokes.csv", "trials.csv"])

    def test_report_out_under_a_file_size_limit_leaves_no_page_folder(self):
        result = run(["report", str(self.root / "study"), "--out", "r.html"], self.tmp,
                     preexec_fn=fsize_limit(1000))
        self.assert_one_error(result, 1)
        self.assertEqual(tree(self.tmp), [], "no index, no r_files/, no temporary")

    def test_session_run_under_a_file_size_limit_leaves_no_session_folder(self):
        result = run(["session", "run", str(self.root / "p.json"), "--subject", "S01", "--out", "out"],
                     self.tmp, preexec_fn=fsize_limit(600))
        self.assertEqual(result.returncode, 1, result.stderr)
        errors = [ln for ln in error_lines(result) if ": error: " in ln]
        self.assertEqual(len(errors), 1, error_lines(result))
        left = tree(self.tmp)
        self.assertEqual([n for n in left if "session.json" in n or ".partial." in n or "tiny-S01" in n], [],
                         left)
        self.assertEqual(temporaries(self.tmp), [])

    def test_trial_under_a_file_size_limit_writes_the_outputs_that_fit(self):
        (self.tmp / "c.csv").write_bytes(b"earlier\n")
        result = run(["trial", CHAR, "--csv", "c.csv", "--json", "j.json", "--svg", "s.svg"], self.tmp,
                     preexec_fn=fsize_limit(20000))
        self.assert_one_error(result, 1, "c.csv", "File too large")
        self.assertEqual((self.tmp / "c.csv").read_bytes(), b"earlier\n")
        self.assertEqual(json.loads((self.tmp / "j.json").read_text(encoding="utf-8"))["character"], CHAR)
        self.assertTrue((self.tmp / "s.svg").read_bytes().rstrip().endswith(b"</svg>"))
        self.assertEqual(tree(self.tmp), ["c.csv", "j.json", "s.svg"])

    def test_few_file_descriptors_fail_a_report_in_one_line_leaving_nothing(self):
        def few():
            resource.setrlimit(resource.RLIMIT_NOFILE, (5, 5))
        result = run(["report", str(self.root / "study"), "--out", "r.html", "--csv", ".", "--jobs", "1"],
                     self.tmp, preexec_fn=few)
        self.assert_one_error(result, 1, "Too many open files")
        self.assertEqual(tree(self.tmp), [])

    def test_few_file_descriptors_fail_a_session_run_leaving_no_session_folder(self):
        def few():
            resource.setrlimit(resource.RLIMIT_NOFILE, (6, 6))
        result = run(["session", "run", str(self.root / "p.json"), "--subject", "S01", "--out", "out"], self.tmp,
                     preexec_fn=few)
        self.assertEqual(result.returncode, 1, result.stderr)
        errors = [ln for ln in error_lines(result) if ": error: " in ln]
        self.assertEqual(len(errors), 1, error_lines(result))
        self.assertIn("Too many open files", errors[0])
        left = tree(self.tmp)
        self.assertEqual([n for n in left if "session.json" in n or ".partial." in n or "tiny-S01" in n], [],
                         left)
        self.assertEqual(temporaries(self.tmp), [])

    def test_record_refused_on_an_unfinished_trial_leaves_the_earlier_record(self):
        (self.tmp / "r.json").write_bytes(b"earlier record\n")
        before = snapshot(self.tmp / "r.json")
        result = run(["trial", CHAR, "--max-duration", "0.5", "--record", "r.json", "--json", "j.json"],
                     self.tmp)
        self.assertEqual(result.returncode, 1, result.stderr)
        self.assertEqual(snapshot(self.tmp / "r.json"), before)
        record = json.loads((self.tmp / "j.json").read_text(encoding="utf-8"))
        self.assertEqual(record["end_reason"], "time_limit")
        self.assertEqual(temporaries(self.tmp), [])

    def test_trial_with_its_standard_output_a_closed_pipe_writes_its_files_then_exits_1(self):
        read_end, write_end = os.pipe()
        os.close(read_end)
        try:
            result = run(["trial", CHAR, "--json", "j.json", "--csv", "c.csv"], self.tmp, stdout=write_end)
        finally:
            os.close(write_end)
        self.assert_one_error(result, 1)
        self.assertEqual(json.loads((self.tmp / "j.json").read_text(encoding="utf-8"))["end_reason"], "completed")
        self.assertTrue((self.tmp / "c.csv").read_bytes().startswith(b"t,x,y,z,"))

    def test_characters_into_a_pipe_closed_early_is_one_error_line(self):
        process = subprocess.Popen([CLI, "characters"], cwd=self.tmp, env=ENV, stdin=subprocess.DEVNULL,
                                   stdout=subprocess.PIPE, stderr=subprocess.PIPE)
        self.assertEqual(len(process.stdout.read(1)), 1)
        process.stdout.close()
        stderr = process.stderr.read()
        process.stderr.close()
        process.wait(timeout=60)
        result = subprocess.CompletedProcess(process.args, process.returncode, b"", stderr)
        self.assert_one_error(result, 1)

    def test_trace_with_its_standard_output_closed_is_one_error_line(self):
        result = run(["trace", str(self.h5)], self.tmp, stdout=None, preexec_fn=lambda: os.close(1))
        self.assert_one_error(result, 1)

    def test_report_with_its_standard_output_full_is_exit_1(self):
        tables = self.tmp / "tables"
        tables.mkdir()
        with open("/dev/full", "wb") as full:
            result = run(["report", str(self.root / "study"), "--csv", "tables"], self.tmp, stdout=full)
        self.assert_one_error(result, 1)


class FoldersAndLinks(Fixture):
    """docs/cli.md, "Outputs" and "Output folders": links followed for a single output ("A dangling symbolic
    link is kept too: the file it names is created (through a chain of links, each relative target read from
    its link's folder) ... a chain of more than 40 links is an error"), never for a set ("a set's file that is
    a symbolic link (dangling or not) is refused before any work, exit 2 naming the option and the file ... so
    is a folder the set makes itself (... report --out's FILE_files/ and its subjects' folders)"; "A set's file
    with other hard links is replaced by rename"); permission bits ("a replaced file keeps its permission bits,
    and a new one gets 0666 less the umask (a folder a command makes, 0777 less it)"); "a relative path ...
    once the working directory was removed ... cannot resolve it against the working directory"."""

    def test_dangling_link_chain_creates_the_file_named_from_each_links_folder(self):
        (self.tmp / "out" / "sub").mkdir(parents=True)
        (self.tmp / "out" / "l1").symlink_to("sub/l2")
        (self.tmp / "out" / "sub" / "l2").symlink_to("../real.svg")
        result = run(["model", CHAR, "--svg", "out/l1"], self.tmp)
        self.assertEqual(result.returncode, 0, result.stderr)
        self.assertEqual(os.readlink(self.tmp / "out" / "l1"), "sub/l2")
        self.assertEqual(os.readlink(self.tmp / "out" / "sub" / "l2"), "../real.svg")
        svg = run_ok(["model", CHAR, "--svg", "-"], self.tmp).stdout
        self.assertEqual((self.tmp / "out" / "real.svg").read_bytes(), svg)
        self.assertEqual(temporaries(self.tmp), [])

    def test_output_link_loop_is_one_error_before_the_trial_and_the_link_kept(self):
        (self.tmp / "loop").symlink_to("loop")
        result = run(["trial", CHAR, "--json", "loop"], self.tmp)
        self.assert_one_error(result, (1, 2), "--json", "loop")
        self.assertEqual(result.stdout, b"", "the outputs are checked before the trial")
        self.assertEqual(os.readlink(self.tmp / "loop"), "loop")
        self.assertEqual(tree(self.tmp), ["loop"])

    def test_report_pages_folder_that_is_a_link_is_refused(self):
        elsewhere = self.tmp / "elsewhere"
        elsewhere.mkdir()
        (self.tmp / "r_files").symlink_to("elsewhere", target_is_directory=True)
        result = run(["report", str(self.root / "study"), "--out", "r.html"], self.tmp)
        self.assert_one_error(result, 2, "--out", "r_files")
        self.assertEqual(tree(self.tmp), ["elsewhere", "r_files"])

    def test_report_subject_folder_that_is_a_link_is_refused(self):
        elsewhere = self.tmp / "elsewhere"
        elsewhere.mkdir()
        (self.tmp / "r_files").mkdir()
        (self.tmp / "r_files" / "S01").symlink_to("../elsewhere", target_is_directory=True)
        result = run(["report", str(self.root / "study"), "--out", "r.html"], self.tmp)
        self.assert_one_error(result, 2, "--out", "S01")
        self.assertEqual(tree(self.tmp), ["elsewhere", "r_files", "r_files/S01"])

    def test_report_pages_folder_that_is_a_file_is_refused_before_writing(self):
        (self.tmp / "r_files").write_bytes(b"a file\n")
        before = snapshot(self.tmp / "r_files")
        result = run(["report", str(self.root / "study"), "--out", "r.html"], self.tmp)
        self.assert_one_error(result, 1, "r_files")
        self.assertEqual(snapshot(self.tmp / "r_files"), before)
        self.assertEqual(tree(self.tmp), ["r_files"])

    def test_cohort_table_that_is_a_dangling_link_is_refused_and_its_target_not_made(self):
        (self.tmp / "strokes.csv").symlink_to("../carried-out.csv")
        result = run(["session", "cohort", str(self.root / "p.json"), "--subjects", "1", "--csv", "."],
                     self.tmp)
        self.assert_one_error(result, 2, "--csv", "strokes.csv")
        self.assertEqual(tree(self.tmp), ["strokes.csv"])
        self.assertFalse((self.root / "carried-out.csv").exists())

    def test_table_with_another_hard_link_is_replaced_by_rename(self):
        tables = self.tmp / "tables"
        tables.mkdir()
        (self.tmp / "keep.csv").write_bytes(b"earlier trials\n")
        os.link(self.tmp / "keep.csv", tables / "trials.csv")
        run_ok(["report", str(self.root / "study"), "--csv", "tables"], self.tmp)
        self.assertEqual((self.tmp / "keep.csv").read_bytes(), b"earlier trials\n")
        rows = (tables / "trials.csv").read_text(encoding="utf-8").splitlines()
        self.assertEqual(len(rows), 2, "a header and the one saved trial")
        self.assertNotEqual(os.stat(tables / "trials.csv").st_ino, os.stat(self.tmp / "keep.csv").st_ino)

    def test_permission_bits_kept_on_a_replaced_file_and_the_umask_on_new_ones(self):
        kept = self.tmp / "kept.svg"
        kept.write_bytes(b"earlier\n")
        kept.chmod(0o604)
        umask = lambda: os.umask(0o027)  # noqa: E731
        for args in (["model", CHAR, "--svg", "kept.svg"], ["model", CHAR, "--svg", "new.svg"],
                     ["report", str(self.root / "study"), "--out", "r.html"]):
            result = run(args, self.tmp, preexec_fn=umask)
            self.assertEqual(result.returncode, 0, result.stderr)
        self.assertEqual(stat.S_IMODE(kept.stat().st_mode), 0o604)
        self.assertEqual(stat.S_IMODE((self.tmp / "new.svg").stat().st_mode), 0o640)
        self.assertEqual(stat.S_IMODE((self.tmp / "r.html").stat().st_mode), 0o640)
        self.assertEqual(stat.S_IMODE((self.tmp / "r_files").stat().st_mode), 0o750)
        self.assertEqual(stat.S_IMODE((self.tmp / "r_files" / "S01").stat().st_mode), 0o750)

    def test_relative_output_after_the_working_folder_was_removed_is_refused(self):
        gone = self.tmp / "gone"
        cases = [(["model", CHAR, "--svg", "a.svg"], "--svg a.svg"),
                 (["score", str(self.root / "t.csv"), "--character", CHAR, "--json", "a.json"], "--json a.json"),
                 (["trial", CHAR, "--csv", "a.csv"], "--csv a.csv")]
        for args, needle in cases:
            with self.subTest(args=args):
                gone.mkdir()
                result = run(args, gone, preexec_fn=lambda: os.rmdir(os.getcwd()))
                self.assert_one_error(result, 1, needle, "cannot resolve it against the working directory")
                self.assertEqual(result.stdout, b"")
                self.assertFalse(gone.exists())

    def test_relative_input_after_the_working_folder_was_removed_is_refused(self):
        gone = self.tmp / "gone"
        gone.mkdir()
        result = run(["score", "../../t.csv", "--character", CHAR, "--json", str(self.tmp / "s.json")], gone,
                     preexec_fn=lambda: os.rmdir(os.getcwd()))
        self.assert_one_error(result, 1, "../../t.csv", "cannot resolve it against the working directory")
        self.assertEqual(tree(self.tmp), [])

    def test_report_index_that_is_a_link_is_refused(self):
        (self.tmp / "target.html").write_bytes(b"not a report\n")
        (self.tmp / "r.html").symlink_to("target.html")
        before = snapshot(self.tmp / "target.html")
        result = run(["report", str(self.root / "study"), "--out", "r.html"], self.tmp)
        self.assert_one_error(result, 2, "--out", "r.html")
        self.assertEqual(snapshot(self.tmp / "target.html"), before)
        self.assertEqual(tree(self.tmp), ["r.html", "target.html"])

    def test_dev_stdout_on_a_file_that_is_another_output_is_refused_naming_both(self):
        target = self.tmp / "f.csv"
        target.write_bytes(b"earlier\n")
        with open(target, "ab") as out:
            result = run(["trial", CHAR, "--csv", "f.csv", "--json", "/dev/stdout"], self.tmp, stdout=out)
        self.assert_one_error(result, 2, "--csv", "--json")
        self.assertEqual(target.read_bytes(), b"earlier\n")

    def test_session_run_out_below_a_regular_file_is_refused_naming_out(self):
        (self.tmp / "F").write_bytes(b"a file\n")
        before = snapshot(self.tmp / "F")
        result = run(["session", "run", str(self.root / "p.json"), "--subject", "S01", "--out", "F/study"],
                     self.tmp)
        self.assert_one_error(result, 1, "--out", "F/study")
        self.assertEqual(snapshot(self.tmp / "F"), before)
        self.assertEqual(tree(self.tmp), ["F"])

    def test_missing_folder_named_with_a_line_break_and_an_escape_on_one_line(self):
        name = "a\nb\x1b[31m/s.json"
        result = run(["score", str(self.root / "t.csv"), "--character", CHAR, "--json", name], self.tmp)
        line = self.assert_one_error(result, 1, "--json", "a\\nb", "\\x1b")
        self.assertNotIn("\x1b", line)
        self.assertEqual(tree(self.tmp), [])


class NothingWritten(Fixture):
    """docs/cli.md: `trial --check` "No character is read, no device opened, nothing written"; "a refused
    command creates no folder and no file"; "An existing device or FIFO (/dev/null) is written in place, never
    replaced, and may be given to several outputs"; "a stop signal ... while a file is written (outside a trial
    or session ...) removes its temporary before the signal ends the program"."""

    def test_trial_check_writes_no_output(self):
        (self.tmp / "c.csv").write_bytes(b"earlier\n")
        before = snapshot(self.tmp / "c.csv")
        result = run(["trial", CHAR, "--check", "--json", "j.json", "--csv", "c.csv", "--svg", "s.svg"],
                     self.tmp)
        self.assertEqual(result.returncode, 0, result.stderr)
        self.assertEqual(snapshot(self.tmp / "c.csv"), before)
        self.assertEqual(tree(self.tmp), ["c.csv"])

    def test_usage_errors_after_outputs_create_nothing(self):
        cases = [["trial", CHAR, "--json", "j.json", "--seed", "1.5"],
                 ["trial", CHAR, "--json", "j.json", "--record", "sub/r.json"],
                 ["session", "run", str(self.root / "p.json"), "--subject", "S01", "--out", "newout",
                  "--writer-profile", "expert"],
                 ["trial", "--spec", str(self.root / "t.json"), "--record", "r.json"]]
        for args in cases:
            with self.subTest(args=args):
                result = run(args, self.tmp)
                self.assertIn(result.returncode, (1, 2), result.stderr)
                self.assertEqual(len(error_lines(result)), 1, error_lines(result))
                self.assertEqual(tree(self.tmp), [])

    def test_dev_null_for_every_output_of_a_trial_at_once(self):
        result = run(["trial", CHAR, "--json", "/dev/null", "--csv", "/dev/null", "--svg", "/dev/null",
                      "--record", "/dev/null"], self.tmp)
        self.assertEqual(result.returncode, 0, result.stderr)
        self.assertTrue(stat.S_ISCHR(os.stat("/dev/null").st_mode))
        self.assertEqual(tree(self.tmp), [])

    def start_report(self, args):
        return subprocess.Popen([CLI, "report", str(self.root / "study"), *args], cwd=self.tmp, env=ENV,
                                stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)

    @staticmethod
    def wait_for(predicate, process, limit_s=10.0):
        """Polls `predicate` until it holds or the process ended; True when it held first."""
        end = time.monotonic() + limit_s
        while time.monotonic() < end and process.poll() is None:
            if predicate():
                return True
        return False

    def test_sigterm_while_a_report_replaces_its_files_leaves_no_temporary(self):
        site = self.tmp / "site"
        site.mkdir()
        run_ok(["report", str(self.root / "study"), "--out", "site/r.html", "--csv", "site"], self.tmp)
        earlier = {n: (site / n).read_bytes() for n in ("r.html", "trials.csv", "strokes.csv")}
        for attempt in range(3):
            with self.subTest(attempt=attempt):
                process = self.start_report(["--out", "site/r.html", "--csv", "site"])
                self.wait_for(lambda: any(n.startswith(".") for n in os.listdir(site)), process)
                process.send_signal(signal.SIGTERM)
                process.wait(timeout=60)
                self.assertIn(process.returncode, (0, -signal.SIGTERM, 128 + signal.SIGTERM))
                self.assertEqual(temporaries(self.tmp), [])
                for name, data in earlier.items():
                    self.assertEqual((site / name).read_bytes(), data, "the same study gives the same files")

    def test_sigterm_once_the_page_folder_is_made_leaves_no_page_folder_without_its_index(self):
        for attempt in range(3):
            with self.subTest(attempt=attempt):
                site = self.tmp / f"site{attempt}"
                site.mkdir()
                process = self.start_report(["--out", f"site{attempt}/r.html"])
                made = self.wait_for(lambda: (site / "r_files").exists(), process)
                process.send_signal(signal.SIGTERM)
                process.wait(timeout=60)
                self.assertIn(process.returncode, (0, -signal.SIGTERM, 128 + signal.SIGTERM))
                self.assertEqual(temporaries(site), [])
                if not (site / "r.html").exists():
                    self.assertEqual(tree(site), [], f"killed with the page folder made: {made}")

if __name__ == "__main__":
    unittest.main()
