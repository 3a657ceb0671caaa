"""An outsider's hostile round on the session folder, written from docs/learning-study.md, docs/cli.md and
docs/experiments.md ("Sessions") alone: session.json forged (types, null, unknown and twice-given keys, huge
numbers, a plan that disagrees with the files, another study's id), cut, linked (session.json, trials/, a
record, as symbolic or hard links to files outside), filled, the study identity killed mid-write, and two runs
of one protocol racing into one study root.

A session.json whose content `session resume` refuses is refused like a protocol's: exit 2, one line
`.../session.json: /json/pointer: what is wrong`, and nothing in the study folder changes. A `trials/`, a
session.json or a record that is a symbolic link is refused by name (exit 2); no link takes a read or a write
outside the session folder.

CALLIGRAPHY_CLI names the program."""

import json
import os
import subprocess
import sys
import threading
import unittest
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from study_protocols import CLI, digest_tree  # noqa: E402
from test_unseen_hostile_cli import Hostile  # noqa: E402


class SessionFolders(Hostile):
    """Each case works on a copy of the fixture's study (two simulated subjects, one session of two trials)."""

    def unfinished(self):
        """A copy of the study whose first session has its last trial unsaved: a resume has work to do."""
        study = self.study_copy()
        session = sorted(p.parent for p in study.rglob("session.json"))[0]
        sorted(session.glob("trials/*.json"))[-1].unlink()
        return study, session

    def resume_refused(self, study, session, status, *names):
        before = digest_tree(study)
        line = self.refused(self.cli("session", "resume", session), status, "session.json", *names)
        self.assertEqual(digest_tree(study), before)
        return line

    # -- forged session.json ------------------------------------------------------------------------------

    def test_a_session_number_given_as_text_names_the_pointer(self):
        def edit(doc):
            doc["session_number"] = "1"
        self.resume_refused(*self.forged(edit), 2, "/session_number")

    def test_null_pacing_names_the_pointer(self):
        def edit(doc):
            doc["pacing"] = None
        self.resume_refused(*self.forged(edit), 2, "/pacing")

    def test_an_unknown_key_names_the_pointer(self):
        def edit(doc):
            doc["subjects_extra"] = 3
        self.resume_refused(*self.forged(edit), 2, "/subjects_extra")

    def test_an_unknown_key_in_a_planned_trial_names_the_pointer(self):
        def edit(doc):
            doc["plan"][1]["speed"] = 2
        self.resume_refused(*self.forged(edit), 2, "/plan/1/speed")

    def test_a_subject_number_of_1e400_names_the_pointer(self):
        def edit(doc):
            return json.dumps(doc, ensure_ascii=False).replace('"number": %d' % doc["subject"]["number"],
                                                               '"number": 1e400', 1)
        self.resume_refused(*self.forged(edit), 2, "/subject/number")

    def test_a_repetition_beyond_64_bits_names_the_pointer(self):
        def edit(doc):
            doc["plan"][0]["repetition"] = 2 ** 70
        self.resume_refused(*self.forged(edit), 2, "/plan/0/repetition")

    def test_a_fractional_index_names_the_pointer(self):
        def edit(doc):
            doc["plan"][1]["index"] = 1.5
        self.resume_refused(*self.forged(edit), 2, "/plan/1/index")

    def test_a_writer_seed_below_zero_names_the_pointer(self):
        def edit(doc):
            doc["writer_seed"] = -1
        self.resume_refused(*self.forged(edit), 2, "/writer_seed")

    def test_a_twice_given_key_names_the_pointer(self):
        def edit(doc):
            text = json.dumps(doc, ensure_ascii=False, indent=2)
            return text.replace('"device": ', '"device": "mouse", "device": ', 1)
        self.resume_refused(*self.forged(edit), 2, "/device")

    def test_a_cut_session_json_is_named(self):
        def edit(doc):
            text = json.dumps(doc, ensure_ascii=False, indent=2)
            return text[: len(text) // 2]
        self.resume_refused(*self.forged(edit), 2)

    def test_a_plan_shorter_than_the_saved_trials_is_refused_naming_the_record(self):
        """The plan says one trial; trials/ holds a second record the plan does not have."""
        study = self.study_copy()
        session = sorted(p.parent for p in study.rglob("session.json"))[0]
        manifest = session / "session.json"
        doc = json.loads(manifest.read_text(encoding="utf-8"))
        extra = sorted(session.glob("trials/*.json"))[-1]
        doc["plan"] = doc["plan"][:1]
        manifest.write_text(json.dumps(doc, ensure_ascii=False, indent=2), encoding="utf-8")
        before = digest_tree(study)
        (self.cwd / "tables").mkdir()
        line = self.refused(self.cli("report", study, "--csv", self.cwd / "tables"), 1, extra.name)
        self.assertIn("plan", line)
        self.assertEqual(list((self.cwd / "tables").iterdir()), [])
        self.assertEqual(digest_tree(study), before)

    def test_a_study_id_of_another_study_is_refused_by_resume(self):
        def edit(doc):
            self.assertIn("study_id", doc)
            doc["study_id"] = "0123456789abcdef0123456789abcdef"
        self.resume_refused(*self.forged(edit), 1, "/study_id")

    def test_a_session_json_of_the_old_shape_still_resumes(self):
        """Written before study ids, writer learning and individual differences: those keys absent."""
        def edit(doc):
            for key in ("study_id", "writer_learning", "individual_differences"):
                doc.pop(key, None)
        study, session = self.forged(edit)
        (study / ".calligraphy-study.json").unlink()
        out = self.cli("session", "resume", session)
        self.assertEqual(out.returncode, 0, out.stderr)
        self.assertEqual(len(list(session.glob("trials/*.json"))), 2)

    def test_a_session_json_of_the_first_version_reads_as_the_same_plan(self):
        """Version 1 counted a planned trial's block and item from 0 and had no session number, group, study id,
        writer learning or individual differences: `report` reads the same blocks and items from it."""
        import csv

        def tables(study, name):
            folder = self.cwd / name
            folder.mkdir()
            out = self.cli("report", study, "--csv", folder)
            self.assertEqual(out.returncode, 0, out.stderr)
            with open(folder / "trials.csv", encoding="utf-8") as f:
                return [(row["subject"], row["block"], row["item"], row["repetition"]) for row in csv.DictReader(f)]

        study = self.study_copy()
        expected = tables(study, "now")
        (study / ".calligraphy-study.json").unlink()
        for manifest in study.rglob("session.json"):
            doc = json.loads(manifest.read_text(encoding="utf-8"))
            doc["version"] = 1
            for key in ("study_id", "writer_learning", "individual_differences", "session_number", "group"):
                doc.pop(key, None)
            for trial in doc["plan"]:
                trial["block"] -= 1
                trial["item"] -= 1
            manifest.write_text(json.dumps(doc, ensure_ascii=False, indent=2) + "\n", encoding="utf-8")
        self.assertEqual(tables(study, "old"), expected)
        self.assertGreater(len(expected), 0)

    # -- links --------------------------------------------------------------------------------------------

    def test_a_symlinked_trials_folder_is_refused_and_nothing_is_written_through_it(self):
        study, session = self.unfinished()
        outside = self.cwd / "elsewhere"
        (session / "trials").rename(outside)
        os.symlink(outside, session / "trials")
        before = digest_tree(outside)
        line = self.refused(self.cli("session", "resume", session), 2, "trials")
        self.assertIn("link", line)
        self.assertEqual(digest_tree(outside), before)

    def test_a_symlinked_session_json_is_refused_and_not_written_through(self):
        """Refused by name, as a link (a session's files are its own); never written."""
        study, session = self.unfinished()
        outside = self.cwd / "session-elsewhere.json"
        (session / "session.json").rename(outside)
        os.symlink(outside, session / "session.json")
        before = outside.read_bytes()
        out = self.cli("session", "resume", session)
        self.assertEqual(outside.read_bytes(), before, out.stderr)
        self.assertIn("symbolic link", self.refused(out, 2, "session.json"))
        self.assertTrue((session / "session.json").is_symlink())

    def test_a_record_symlinked_outside_is_refused_and_not_written_through(self):
        study = self.study_copy()
        session = sorted(p.parent for p in study.rglob("session.json"))[0]
        first, last = sorted(session.glob("trials/*.json"))
        outside = self.cwd / "outside.json"
        outside.write_bytes(first.read_bytes())
        first.unlink()
        os.symlink(outside, first)
        last.unlink()  # work to do
        before = outside.read_bytes()
        out = self.cli("session", "resume", session)
        self.assertEqual(outside.read_bytes(), before, out.stderr)
        self.assertIn("symbolic link", self.refused(out, 2, first.name))
        self.assertFalse(last.exists())
        self.assertTrue(first.is_symlink())

    def test_a_record_hard_linked_outside_is_never_written(self):
        study = self.study_copy()
        session = sorted(p.parent for p in study.rglob("session.json"))[0]
        first, last = sorted(session.glob("trials/*.json"))
        outside = self.cwd / "outside.json"
        os.link(first, outside)
        last.unlink()
        before = outside.read_bytes()
        out = self.cli("session", "resume", session)
        self.assertEqual(out.returncode, 0, out.stderr)
        self.assertEqual(outside.read_bytes(), before)
        self.assertTrue(last.exists())

    # -- fills --------------------------------------------------------------------------------------------

    def test_a_session_json_padded_to_megabytes_still_reads(self):
        def edit(doc):
            return json.dumps(doc, ensure_ascii=False, indent=2) + " " * (8 << 20)
        study, session = self.forged(edit)
        out = self.cli("session", "resume", session)
        self.assertEqual(out.returncode, 0, out.stderr)

    def test_a_sparse_gigabyte_record_is_refused_by_resume_without_reading_it(self):
        study, session = self.unfinished()
        record = sorted(session.glob("trials/*.json"))[0]
        with open(record, "r+b") as f:
            f.truncate(1 << 30)
        self.refused(self.cli("session", "resume", session, timeout=60), 1, record.name)

    # -- the study identity -------------------------------------------------------------------------------

    def test_an_identity_killed_mid_write_leaves_no_half_file_and_the_next_run_makes_it(self):
        """A kill during the identity's write leaves at most a hidden temporary beside it (docs/experiments.md:
        `.NAME.tmp-PID-N`): the next run reads no half file, makes the identity whole, records it in its
        session and removes the dead writer's temporary."""
        root = self.cwd / "study"
        root.mkdir()
        # a writer killed half way through the temporary (pid 2^22 + 1: no process has it)
        left = root / "..calligraphy-study.json.tmp-4194305-0"
        left.write_text('{"format": "calligr')
        out = self.cli("session", "run", self.fx.protocol, "--subject", "P01", "--writer", "simulated",
                       "--out", root)
        self.assertEqual(out.returncode, 0, out.stderr)
        identity = json.loads((root / ".calligraphy-study.json").read_text())
        self.assertEqual(identity["format"], "calligraphy-study")
        manifest = json.loads(next(root.rglob("session.json")).read_text(encoding="utf-8"))
        self.assertEqual(manifest["study_id"], identity["study_id"])
        self.assertFalse(left.exists())

    def test_a_half_written_identity_under_its_own_name_is_refused_by_name(self):
        """What an older writer killed mid-write could leave: the identity cut; refused, nothing written."""
        study, session = self.unfinished()
        (study / ".calligraphy-study.json").write_text('{"format": "calligraphy-study", "vers')
        before = digest_tree(study)
        out = self.cli("session", "run", self.fx.protocol, "--subject", "P09", "--writer", "simulated",
                       "--out", study)
        self.refused(out, 1, ".calligraphy-study.json")
        self.assertEqual(digest_tree(study), before)

    def test_an_empty_identity_file_is_refused_by_name(self):
        study, session = self.unfinished()
        (study / ".calligraphy-study.json").write_bytes(b"")
        before = digest_tree(study)
        self.refused(self.cli("session", "resume", session), 1, ".calligraphy-study.json")
        self.assertEqual(digest_tree(study), before)

    # -- races --------------------------------------------------------------------------------------------

    def test_two_runs_of_one_protocol_into_one_new_root_share_one_identity(self):
        root = self.cwd / "study"
        results = {}

        def go(subject):
            results[subject] = self.cli("session", "run", self.fx.protocol, "--subject", subject, "--writer",
                                        "simulated", "--out", root)

        threads = [threading.Thread(target=go, args=(s,)) for s in ("P01", "P02")]
        for t in threads:
            t.start()
        for t in threads:
            t.join()
        ran = [s for s, out in results.items() if out.returncode == 0]
        for s, out in results.items():
            if out.returncode != 0:  # refused while the other held the study: one line naming the folder
                self.refused(out, 1, str(root))
        self.assertGreaterEqual(len(ran), 1)
        identity = json.loads((root / ".calligraphy-study.json").read_text())["study_id"]
        manifests = sorted(root.rglob("session.json"))
        self.assertEqual(len(manifests), len(ran))
        for m in manifests:
            self.assertEqual(json.loads(m.read_text(encoding="utf-8"))["study_id"], identity)
        self.assertEqual([p.name for p in root.iterdir() if ".tmp" in p.name or ".partial" in p.name], [])


if __name__ == "__main__":
    unittest.main()
