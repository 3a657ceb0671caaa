#!/usr/bin/env python3
"""What the `calligraphy` program checks before its first trial and its first write (docs/cli.md, "Checked
before anything runs" and "Outputs"), run by CTest as `cli_output_tests`.

Each case gives a command inputs or outputs it must refuse and asserts the exit status, the one-line message
(naming the options, paths, character or plan size at fault) and that nothing was made or changed: no folder,
no file, an input byte for byte as it was. Covered: two outputs on one file (the same path, a symbolic link,
a hard link), an output on an input (a teacher's recording, a saved trial record under `report`'s folders,
a session's files for `session resume`), a dangling symbolic link as an output (the file it names is
created, the link stays), an output in a missing folder, a protocol naming a character the library lacks, a
protocol over the plan-size limit, `train --quiz-screenshots` with a missing folder.

CALLIGRAPHY_CLI names the program and CALLIGRAPHY_SOURCE_DIR the source tree. Standard library only.
"""
import hashlib
import json
import os
import subprocess
import tempfile
import time
import unittest
from pathlib import Path

CLI = os.environ.get("CALLIGRAPHY_CLI", "")
SOURCE = Path(os.environ.get("CALLIGRAPHY_SOURCE_DIR", Path(__file__).resolve().parents[2]))
PROTOCOL = SOURCE / "examples" / "protocols" / "paper-table5.json"
TIMEOUT_S = 120
ABSENT = "龘"  # U+9F98, not in the embedded set


def digest(path):
    return hashlib.sha256(Path(path).read_bytes()).hexdigest()


def tree(folder):
    """Every path under `folder` with the digest of each file: what a refused command must leave as it is."""
    found = {}
    for root, folders, files in os.walk(folder):
        for name in folders:
            found[os.path.relpath(os.path.join(root, name), folder)] = "folder"
        for name in files:
            path = os.path.join(root, name)
            found[os.path.relpath(path, folder)] = "link" if os.path.islink(path) else digest(path)
    return found


class OutputTestCase(unittest.TestCase):
    def setUp(self):
        if not CLI or not Path(CLI).exists():
            self.fail(f"CALLIGRAPHY_CLI={CLI!r} is not the calligraphy program: run these tests through ctest")
        self.temp = tempfile.TemporaryDirectory()
        self.cwd = Path(self.temp.name)

    def tearDown(self):
        self.temp.cleanup()

    def run_cli(self, *args):
        return subprocess.run([CLI, *map(str, args)], cwd=self.cwd, capture_output=True, timeout=TIMEOUT_S)

    def assert_refused(self, result, status, *fragments):
        stderr = result.stderr.decode()
        self.assertEqual(result.returncode, status, stderr)
        self.assertEqual(len(stderr.strip().splitlines()), 1, stderr)
        for fragment in fragments:
            self.assertIn(fragment, stderr)
        return stderr

    def protocol(self, name, edit):
        document = json.loads(PROTOCOL.read_text(encoding="utf-8"))
        edit(document)
        path = self.cwd / name
        path.write_text(json.dumps(document, ensure_ascii=False), encoding="utf-8")
        return path

    def small_session(self):
        """One saved trial of 大 in a session under study/: the session folder and its record."""
        def edit(document):
            del document["practice"]
            document["test"].update({"characters": ["大"], "conditions": ["haptic"], "repetitions": 1})
            document["order"]["conditions"] = "fixed"
            document["breaks"] = {}
        protocol = self.protocol("small.json", edit)
        result = self.run_cli("session", "run", protocol, "--writer", "simulated", "--subjects", "1", "--out",
                              "study")
        self.assertEqual(result.returncode, 0, result.stderr.decode())
        (session,) = (self.cwd / "study" / "S01").iterdir()
        (record,) = (session / "trials").glob("*.json")
        return session, record


class TwoOutputsOnOneFile(OutputTestCase):
    def test_the_same_path_twice_is_refused_and_nothing_written(self):
        result = self.run_cli("trial", "乙", "--json", "F", "--csv", "F", "--svg", "./F")
        self.assert_refused(result, 2, "--csv F and --json F are the same file")
        self.assertEqual(os.listdir(self.cwd), [])

    def test_a_symbolic_link_to_another_output_is_refused(self):
        (self.cwd / "F").write_text("earlier\n")
        os.symlink("F", self.cwd / "link")
        result = self.run_cli("trial", "乙", "--json", "F", "--svg", "link")
        self.assert_refused(result, 2, "--svg link and --json F are the same file")
        self.assertEqual((self.cwd / "F").read_text(), "earlier\n")

    def test_a_hard_link_to_another_output_is_refused(self):
        (self.cwd / "F").write_text("earlier\n")
        os.link(self.cwd / "F", self.cwd / "hard")
        result = self.run_cli("trial", "乙", "--csv", "hard", "--json", "F")
        self.assert_refused(result, 2, "--csv hard and --json F are the same file")
        self.assertEqual((self.cwd / "F").read_text(), "earlier\n")

    def test_a_symbolic_link_to_a_file_not_there_yet_is_the_same_file(self):
        os.symlink("new.json", self.cwd / "link")
        result = self.run_cli("trial", "乙", "--json", "new.json", "--csv", "link")
        self.assert_refused(result, 2, "--csv link and --json new.json are the same file")
        self.assertFalse((self.cwd / "new.json").exists())

    def test_devices_may_take_several_outputs(self):
        result = self.run_cli("trial", "乙", "--json", "/dev/null", "--csv", "/dev/null")
        self.assertEqual(result.returncode, 0, result.stderr.decode())

    def test_an_output_on_the_teacher_it_replays_is_refused(self):
        result = self.run_cli("trial", "乙", "--record", "teacher.json")
        self.assertEqual(result.returncode, 0, result.stderr.decode())
        before = digest(self.cwd / "teacher.json")
        result = self.run_cli("trial", "乙", "--guidance-mode", "replay", "--teacher", "teacher.json", "--json",
                              "teacher.json")
        self.assert_refused(result, 2, "--json teacher.json is the same file as --teacher teacher.json")
        self.assertEqual(digest(self.cwd / "teacher.json"), before)

    def test_an_output_in_a_missing_folder_is_refused_before_the_trial(self):
        result = self.run_cli("trial", "乙", "--json", "ok.json", "--csv", "missing/trace.csv")
        self.assert_refused(result, 1, "--csv missing/trace.csv", "does not exist")
        self.assertFalse((self.cwd / "ok.json").exists())

    def test_an_output_that_is_a_folder_is_refused(self):
        result = self.run_cli("model", "永", "--svg", ".")
        self.assert_refused(result, 1, "--svg .: is a folder")


class DanglingLink(OutputTestCase):
    def test_the_file_a_dangling_link_names_is_created_and_the_link_kept(self):
        (self.cwd / "out").mkdir()
        os.symlink("out/model.svg", self.cwd / "link.svg")
        result = self.run_cli("model", "永", "--svg", "link.svg")
        self.assertEqual(result.returncode, 0, result.stderr.decode())
        self.assertTrue(os.path.islink(self.cwd / "link.svg"))
        self.assertEqual(os.readlink(self.cwd / "link.svg"), "out/model.svg")
        self.assertIn("<svg", (self.cwd / "out" / "model.svg").read_text())

    def test_a_dangling_link_into_a_missing_folder_is_refused(self):
        os.symlink("nowhere/model.svg", self.cwd / "link.svg")
        result = self.run_cli("model", "永", "--svg", "link.svg")
        self.assert_refused(result, 1, "--svg link.svg", "does not exist")
        self.assertTrue(os.path.islink(self.cwd / "link.svg"))


class SavedRecords(OutputTestCase):
    def test_report_out_onto_a_saved_record_is_refused_and_the_record_unchanged(self):
        session, record = self.small_session()
        before = tree(self.cwd / "study")
        result = self.run_cli("report", "study", "--out", record)
        self.assert_refused(result, 2, f"--out {record}", "which this command reads")
        os.symlink(record, self.cwd / "page.html")
        result = self.run_cli("report", session, "--out", "page.html")
        self.assert_refused(result, 2, "--out page.html", str(record.name))
        self.assertEqual(tree(self.cwd / "study"), before)
        result = self.run_cli("session", "resume", session)
        self.assertIn("saved already", result.stdout.decode())

    def test_a_report_beside_the_sessions_is_replaced_when_made_again(self):
        self.small_session()
        for _ in range(2):  # the page is no file of a session folder: the second run replaces the first
            result = self.run_cli("report", "study", "--out", "study/report.html")
            self.assertEqual(result.returncode, 0, result.stderr.decode())
        self.assertIn("<html", (self.cwd / "study" / "report.html").read_text(encoding="utf-8").lower())

    def test_a_study_report_is_made_again_after_a_new_subject_joined(self):
        """A running study is re-reported: the new subject's page folder is made under the existing one."""
        self.small_session()
        first = self.run_cli("report", "study", "--out", "report.html")
        self.assertEqual(first.returncode, 0, first.stderr.decode())
        protocol = self.cwd / "small.json"
        joined = self.run_cli("session", "run", protocol, "--writer", "simulated", "--subjects", "1",
                              "--new-subjects", "--out", "study")
        self.assertEqual(joined.returncode, 0, joined.stderr.decode())
        again = self.run_cli("report", "study", "--out", "report.html")
        self.assertEqual(again.returncode, 0, again.stderr.decode())
        subjects = {path.relative_to(self.cwd / "report_files").parts[0]
                    for path in (self.cwd / "report_files").glob("*/*.html")}
        self.assertEqual(subjects, {"S01", "S02"})

    def test_run_screenshot_onto_a_record_under_out_is_refused(self):
        _, record = self.small_session()
        before = tree(self.cwd / "study")
        result = self.run_cli("session", "run", PROTOCOL, "--writer", "simulated", "--subjects", "1", "--out",
                              "study", "--screenshot", record)
        self.assert_refused(result, 2, f"--screenshot {record}", "a file under --out")
        self.assertEqual(tree(self.cwd / "study"), before)  # no second session folder either

    def test_resume_screenshot_onto_the_session_log_is_refused(self):
        session, _ = self.small_session()
        before = tree(self.cwd / "study")
        result = self.run_cli("session", "resume", session, "--screenshot", session / "log.jsonl")
        self.assert_refused(result, 2, "--screenshot", "log.jsonl")
        self.assertEqual(tree(self.cwd / "study"), before)


class Protocols(OutputTestCase):
    def test_a_character_not_in_the_library_creates_no_folder(self):
        protocol = self.protocol("absent.json",
                                 lambda document: document["test"].update({"characters": ["大", "山", ABSENT, "中"]}))
        result = self.run_cli("session", "run", protocol, "--writer", "simulated", "--subjects", "1", "--out",
                              "study")
        self.assert_refused(result, 2, "absent.json: /test/characters/2", ABSENT, "U+9F98")
        self.assertFalse((self.cwd / "study").exists())

    def test_a_character_not_in_the_practice_is_named_by_its_pointer(self):
        protocol = self.protocol("absent.json",
                                 lambda document: document["practice"].update({"characters": [ABSENT + "永"]}))
        result = self.run_cli("session", "run", protocol, "--writer", "simulated", "--subject", "S1", "--out",
                              "study")
        self.assert_refused(result, 2, "/practice/characters/0", ABSENT)
        self.assertFalse((self.cwd / "study").exists())

    def test_a_plan_over_the_limit_is_refused_quickly_with_its_size(self):
        def edit(document):
            document["conditions"] = [{"name": f"c{i:02d}", "mode": "vision"} for i in range(26)]
            document["practice"]["condition"] = "c00"
            # 1000 distinct strings (an item is listed once): rows of 大, 人 and 口, 7 characters each.
            strings = ["".join("大人口"[(n // 3 ** k) % 3] for k in range(7)) for n in range(1000)]
            document["test"].update({"characters": strings, "conditions": [f"c{i:02d}" for i in range(26)],
                                     "repetitions": 1000})
            document["order"]["conditions"] = "fixed"
        protocol = self.protocol("huge.json", edit)
        start = time.monotonic()
        result = self.run_cli("session", "run", protocol, "--writer", "simulated", "--subjects", "1", "--out",
                              "study")
        self.assertLess(time.monotonic() - start, 10.0)
        self.assert_refused(result, 2, "huge.json: /test: 26,000,002 trials planned",
                            "limit of 1,000,000 trials per session")
        self.assertFalse((self.cwd / "study").exists())

    def test_a_screenshot_in_a_missing_folder_creates_no_session(self):
        result = self.run_cli("session", "run", PROTOCOL, "--writer", "simulated", "--subjects", "1", "--out",
                              "study", "--screenshot", "missing/shot.png")
        self.assert_refused(result, 1, "--screenshot missing/shot.png", "does not exist")
        self.assertFalse((self.cwd / "study").exists())

    def test_out_that_is_a_file_is_refused(self):
        (self.cwd / "study").write_text("a file\n")
        result = self.run_cli("session", "run", PROTOCOL, "--writer", "simulated", "--subjects", "1", "--out",
                              "study")
        self.assert_refused(result, 1, "--out study: is not a folder")
        self.assertEqual((self.cwd / "study").read_text(), "a file\n")


class Train(OutputTestCase):
    def test_quiz_screenshots_in_a_missing_folder_is_refused_before_anything_opens(self):
        result = self.run_cli("train", "永", "--quiz", "--quiz-screenshots", "missing", "--exit-after", "1")
        self.assert_refused(result, 1, "--quiz-screenshots missing", "does not exist")
        self.assertFalse((self.cwd / "missing").exists())

    def test_record_and_screenshot_on_one_file_are_refused(self):
        result = self.run_cli("train", "永", "--record", "x", "--screenshot", "x", "--exit-after", "1")
        self.assert_refused(result, 2, "--screenshot x and --record x are the same file")


if __name__ == "__main__":
    unittest.main()
