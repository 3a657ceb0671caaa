"""Every reader of a session folder reads its files one way, written from docs/experiments.md ("Sessions") and
docs/cli.md ("session run | resume", "report") alone.

session.json is read strictly by `session resume` (exit 2: it is the input it is given), `report` (exit 1:
damaged data) and `calligraphy.study.load` (DataError): one line naming the file and the value's JSON pointer,
nothing written. A file of the folder that is a symbolic link (session.json, a trial record, a trace) is
refused naming it, wherever the link points (a valid copy elsewhere, /dev/zero, a FIFO): a session's files are
its own, and no reader follows a link out of the folder or waits on a pipe. A hard link is the same file and
reads as it; nothing is written through it.

CALLIGRAPHY_CLI names the program; PYTHONPATH holds the Python module (its cases are skipped without it)."""

import json
import os
import shutil
import sys
import unittest
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from study_protocols import digest_tree  # noqa: E402
from test_unseen_hostile_cli import Hostile, have_module  # noqa: E402

LOAD = ("import sys, calligraphy, calligraphy.study as s\n"
        "try:\n st = s.load(sys.argv[1])\n"
        " if len(sys.argv) > 2:\n  [st.samples(row) for _, row in st.trials.iterrows()]\n"
        "except calligraphy.DataError as e:\n print(e); sys.exit(1)\n")


class Readers(Hostile):
    """Helpers: a copy of the fixture's study with one session edited, and each reader run on it."""

    def session_of(self, study):
        return sorted(p.parent for p in study.rglob("session.json"))[0]

    def unfinished(self):
        """A copy of the study whose first session has its last trial unsaved (a resume has work to do)."""
        study = self.study_copy()
        session = self.session_of(study)
        last = sorted(session.glob("trials/*.json"))[-1]
        last.unlink()
        return study, session

    def every_reader_refuses(self, study, session, names, resume_status=2):
        """`session resume`, `report` and `calligraphy.study.load` each refuse with one line naming `names`;
        nothing in the study folder (or outside it: the caller checks) changes, no table is written."""
        before = digest_tree(study)
        self.refused(self.cli("session", "resume", session, timeout=60), resume_status, *names)
        self.assertEqual(digest_tree(study), before)
        tables = self.cwd / "tables"
        tables.mkdir(exist_ok=True)
        self.refused(self.cli("report", study, "--csv", tables, timeout=60), 1, *names)
        self.assertEqual(list(tables.iterdir()), [])
        self.assertEqual(digest_tree(study), before)
        if have_module():
            out = self.python(LOAD, study, timeout=60)
            self.assertEqual(out.returncode, 1, out.stderr.decode(errors="replace"))
            for name in names:
                self.assertIn(str(name), out.stdout.decode(errors="replace"))
            self.assertEqual(digest_tree(study), before)


class SessionJsonContent(Readers):
    """session.json's content against the schema."""

    def refused_everywhere(self, edit, *names):
        study, session = self.forged(edit)
        self.every_reader_refuses(study, session, ("session.json", *names))

    def test_an_unknown_key_is_refused_by_every_reader(self):
        self.refused_everywhere(lambda doc: doc.update(colour="red"), "/colour")

    def test_a_missing_plan_is_refused_by_every_reader(self):
        self.refused_everywhere(lambda doc: doc.pop("plan") and None, "/plan")

    def test_a_missing_subject_is_refused_by_every_reader(self):
        self.refused_everywhere(lambda doc: doc.pop("subject") and None, "/subject")

    def test_a_missing_key_of_a_planned_trial_is_refused_by_every_reader(self):
        self.refused_everywhere(lambda doc: doc["plan"][0].pop("condition") and None, "/plan/0/condition")

    def test_null_for_the_device_is_refused_by_every_reader(self):
        self.refused_everywhere(lambda doc: doc.update(device=None), "/device")

    def test_session_number_0_is_refused_by_every_reader(self):
        def edit(doc):
            self.assertIn("session_number", doc)
            doc["session_number"] = 0
        self.refused_everywhere(edit, "/session_number")

    def test_a_negative_repetition_is_refused_by_every_reader(self):
        def edit(doc):
            doc["plan"][1]["repetition"] = -1
        self.refused_everywhere(edit, "/plan/1/repetition")

    def test_a_plan_given_as_an_object_is_refused_by_every_reader(self):
        def edit(doc):
            doc["plan"] = {"0": doc["plan"][0]}
        self.refused_everywhere(edit, "/plan")

    def test_characters_given_as_a_number_is_refused_by_every_reader(self):
        def edit(doc):
            doc["plan"][0]["characters"] = 21313
        self.refused_everywhere(edit, "/plan/0/characters")

    def test_deeply_nested_arrays_are_refused_without_a_crash(self):
        def edit(doc):
            text = json.dumps(doc, ensure_ascii=False)
            return text.replace('"plan": [', '"plan": [' + "[" * 200000 + "]" * 200000 + ", ", 1)
        study, session = self.forged(edit)
        self.every_reader_refuses(study, session, ("session.json",))

    def test_a_plan_naming_a_condition_the_protocol_lacks_is_refused_by_every_reader(self):
        def edit(doc):
            doc["plan"][1]["condition"] = "telepathy"
        study, session = self.forged(edit)
        self.every_reader_refuses(study, session, ("session.json", "/plan/1/condition"))

    def test_the_subjects_seed_rounded_to_a_double_is_refused_by_every_reader(self):
        # What Node's JSON.parse/stringify or jq 1.6 write back for a seed past 2^53: a valid seed, but not the
        # one the session's saved trials were run with; the message names the seed to put back.
        def edit(doc):
            seed = doc["writer_seed"]
            self.assertGreater(seed, 2 ** 53)
            doc["writer_seed"] = int(float(seed))
            self.assertNotEqual(doc["writer_seed"], seed)
            edit.seed = seed
        study, session = self.forged(edit)
        self.every_reader_refuses(study, session, ("session.json", "/writer_seed", f"put back {edit.seed}"))

    def test_a_session_moved_into_another_subjects_folder_is_refused_by_every_reader(self):
        # ROOT/SUBJECT/SESSION: a session of one subject under another's folder would be reported under its
        # own subject from there, and the series of either subject would not find it.
        study, session = self.unfinished()
        own = session.parent.name
        other = study / (own + "x")
        other.mkdir()
        moved = other / session.name
        session.rename(moved)
        # Where the session lies is not its content: a data error (1) for `session resume` too.
        self.every_reader_refuses(study, moved, ("session.json", "/subject/id", "move it back to"),
                                  resume_status=1)


class Links(Readers):
    """Files of the folder that are links."""

    def target(self, kind, original):
        """What the link points to: a valid copy outside the study, /dev/zero, or a FIFO (nobody writes it)."""
        if kind == "copy":
            outside = self.cwd / ("outside-" + original.name)
            shutil.copyfile(original, outside)
            return outside
        if kind == "zero":
            return Path("/dev/zero")
        fifo = self.cwd / "pipe"
        os.mkfifo(fifo)
        return fifo

    def linked(self, which, kind):
        """An unfinished session whose `which` ("session.json", "record", "trace") is a symbolic link."""
        study, session = self.unfinished()
        if which == "session.json":
            path = session / "session.json"
        elif which == "record":
            path = sorted(session.glob("trials/*.json"))[0]
        else:
            path = sorted(session.glob("trials/*.trace.h5"))[0]
        to = self.target(kind, path)
        path.unlink()
        os.symlink(to, path)
        return study, session, path, to

    def refused_as_a_link(self, which, kind, resume_status):
        study, session, path, to = self.linked(which, kind)
        outside = to.read_bytes() if kind == "copy" else None
        self.every_reader_refuses(study, session, (path.name, "symbolic link"), resume_status)
        self.assertTrue(path.is_symlink())
        if outside is not None:
            self.assertEqual(to.read_bytes(), outside)

    def test_session_json_linked_to_a_valid_copy_is_refused(self):
        self.refused_as_a_link("session.json", "copy", 2)

    def test_session_json_linked_to_dev_zero_is_refused(self):
        self.refused_as_a_link("session.json", "zero", 2)

    def test_session_json_linked_to_a_fifo_is_refused_without_waiting(self):
        self.refused_as_a_link("session.json", "fifo", 2)

    def test_a_record_linked_to_a_valid_copy_is_refused(self):
        self.refused_as_a_link("record", "copy", 2)

    def test_a_record_linked_to_dev_zero_is_refused(self):
        self.refused_as_a_link("record", "zero", 2)

    def test_a_record_linked_to_a_fifo_is_refused_without_waiting(self):
        self.refused_as_a_link("record", "fifo", 2)

    def test_a_trace_linked_outside_is_refused_by_the_readers_of_traces(self):
        """`report` reads each trial's trace (its curves); Python reads it with `samples`."""
        for kind in ("copy", "zero", "fifo"):
            with self.subTest(kind=kind):
                study, session, path, to = self.linked("trace", kind)
                tables = self.cwd / "tables"
                try:
                    before = digest_tree(study)
                    tables.mkdir()
                    out = self.cli("report", study, "--csv", tables, timeout=60)
                    if out.returncode != 0:
                        self.refused(out, 1, path.name, "symbolic link")
                    if have_module():
                        out = self.python(LOAD, study, "samples", timeout=60)
                        self.assertEqual(out.returncode, 1, out.stderr.decode(errors="replace"))
                        self.assertIn(path.name, out.stdout.decode(errors="replace"))
                        self.assertIn("symbolic link", out.stdout.decode(errors="replace"))
                    self.assertEqual(digest_tree(study), before)
                finally:
                    shutil.rmtree(study)
                    shutil.rmtree(tables, ignore_errors=True)
                    if kind != "zero":
                        to.unlink()

    def test_the_series_refuses_an_earlier_sessions_linked_session_json(self):
        """A later session of a subject reads the one before it (the series): through no link either."""
        root = self.cwd / "days"
        day1, day2 = self.days_study(root, "P01")
        shutil.rmtree(day2)
        manifest = day1 / "session.json"
        outside = self.cwd / "outside-session.json"
        shutil.copyfile(manifest, outside)
        manifest.unlink()
        os.symlink(outside, manifest)
        before = digest_tree(root)
        out = self.cli("session", "run", self.fx.protocol2, "--subject", "P01", "--writer", "simulated",
                       "--out", root)
        self.assertIn("symbolic link", self.refused(out, 1, "session.json"))
        self.assertEqual(digest_tree(root), before)

    def test_a_hard_linked_session_json_reads_and_is_not_written(self):
        study, session = self.unfinished()
        outside = self.cwd / "outside-session.json"
        os.link(session / "session.json", outside)
        before = outside.read_bytes()
        out = self.cli("session", "resume", session)
        self.assertEqual(out.returncode, 0, out.stderr)
        self.assertEqual(outside.read_bytes(), before)
        self.assertEqual(len(list(session.glob("trials/*.json"))), 2)
        tables = self.cwd / "tables"
        tables.mkdir()
        out = self.cli("report", study, "--csv", tables)
        self.assertEqual(out.returncode, 0, out.stderr)

    def test_a_record_given_by_the_user_through_a_link_still_reads(self):
        """Only the files found inside a session folder are refused as links: `trial --spec` takes a link the
        user gives it on the command line."""
        record = self.first_record(self.fx.study)
        link = self.cwd / "mine.json"
        os.symlink(record, link)
        out = self.cli("trial", "--spec", link, "--json", self.cwd / "again.json")
        self.assertEqual(out.returncode, 0, out.stderr)
        self.assertTrue((self.cwd / "again.json").exists())


if __name__ == "__main__":
    unittest.main()
