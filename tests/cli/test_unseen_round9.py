#!/usr/bin/env python3
"""Hostile cases written from the documentation alone (docs/cli.md, docs/python.md, the commands' `--help` and
`calligraphy schema record`) on the surfaces changed most recently: trial records re-run with their force law,
safety chain, writer profile or simulated device edited or taken from another record; the multi-file sets of
`report --csv` and `session cohort --csv` with hard links, FIFOs and folders in the places of their files; a
session's trace put in place of another trial's, read by `report` and Python's `study.samples`; and the exit
status of every command that takes characters, given a character the library lacks, an empty string, a
combining mark and the UTF-8 bytes of a lone surrogate. Run by CTest as `cli_unseen_round9_tests`.

Each case asserts what the documentation promises: one error line naming the file and the JSON pointer (or
the option), exit 2 for content refused and 1 for damaged data, a re-run exactly as the record states, nothing
written when refused. CALLIGRAPHY_CLI names the program; the built Python package is found on PYTHONPATH (its
cases are skipped without it). CALLIGRAPHY_SANITIZED=1 takes a small subset.
"""
import copy
import json
import os
import shutil
import subprocess
import sys
import tempfile
import threading
import unittest
from pathlib import Path

from outsider import CLI, ENV, error_lines, last_case, run

SANITIZED = os.environ.get("CALLIGRAPHY_SANITIZED") == "1"
SHI = "十"

heavy = unittest.skipIf(SANITIZED, "several runs of the program: left to the Release run")

try:
    import calligraphy.study as cg_study
    import calligraphy as cg
except ImportError:  # pragma: no cover - a build without the Python bindings
    cg = None
    cg_study = None


PROTOCOL = {"name": "p9", "conditions": [{"name": "h", "mode": "haptic"}, {"name": "v", "mode": "vision"}],
            "test": {"characters": [SHI, "人"], "conditions": ["h", "v"], "repetitions": 1},
            "trial": {"max_duration_s": 20}}

SIMULATED_DEVICE = {"moving_mass_kg": 0.05, "damping_n_s_per_m": 0.5, "encoder_resolution_m": 1e-5,
                    "velocity_cutoff_hz": 50, "physics_substeps": 4, "physics_rate_hz": 4000,
                    "initial_position_m": [0, 0, 0.01],
                    # the figures it reports (records of version 9 state them): the simulated Phantom Desktop's
                    "info": {"model": "Phantom Desktop (simulated)", "manufacturer": "calligraphy",
                             "max_force_n": 7.9, "max_continuous_force_n": 1.75, "max_stiffness_n_per_m": 1000,
                             "max_damping_n_s_per_m": 5, "intrinsic_damping_n_s_per_m": 0,
                             "workspace_radius_m": 0.1, "workspace_size_m": [0.16, 0.12, 0.12]}}


# What `train` says in a build without the trainer window (the sanitizer stage builds none).
WITHOUT_WINDOW = b"built without the trainer window"

class Shared:
    """Two trial records (fixed guidance and fading) with the first one's CSV, and a study of two subjects."""
    folder = None

    @classmethod
    def get(cls):
        if cls.folder is None:
            cls.folder = Path(tempfile.mkdtemp(prefix="unseen9-"))
            f = cls.folder
            r = run(["trial", SHI, "--seed", "7", "--json", "fixed.json", "--csv", "fixed.csv"], f)
            assert r.returncode == 0, r.stderr
            r = run(["trial", SHI, "--guidance-mode", "fading", "--seed", "3", "--json", "fading.json"], f)
            assert r.returncode == 0, r.stderr
            (f / "p.json").write_text(json.dumps(PROTOCOL, ensure_ascii=False), encoding="utf-8")
            if not SANITIZED:
                r = run(["session", "run", "p.json", "--subjects", "2", "--writer", "simulated", "--out", "study"], f)
                assert r.returncode == 0, r.stderr
                if WAITING["early"]:
                    WAITING["run"] = ReportOntoUnreadFifo(f)
        return cls.folder


# The one case that waits the program's documented 10 s (`report --csv` onto a FIFO no process reads): when the
# whole module runs, its run starts as soon as the shared study is made and the case is run last, so that the wait
# passes beside the other cases.
WAITING_CASE = "test_report_fifo_no_process_reads_is_an_error_not_a_hang"
WAITING = {"early": False, "run": None}


class ReportOntoUnreadFifo:
    """`report STUDY --csv tables` in a folder of its own whose tables/strokes.csv is a FIFO no process reads, run
    by a thread: `result()` is its CompletedProcess (or raises what the run raised)."""

    def __init__(self, base):
        self.tmp = Path(tempfile.mkdtemp(prefix="case-", dir=base))
        (self.tmp / "tables").mkdir()
        self.fifo = self.tmp / "tables" / "strokes.csv"
        os.mkfifo(self.fifo)
        self.outcome = []
        self.thread = threading.Thread(target=self.report, args=(base / "study",), daemon=True)
        self.thread.start()

    def report(self, study):
        try:
            self.outcome.append(run(["report", study, "--csv", "tables"], self.tmp, timeout=60))  # waits 10 s
        except BaseException as error:  # noqa: BLE001 - raised again by result()
            self.outcome.append(error)

    def result(self):
        self.thread.join()
        if isinstance(self.outcome[0], BaseException):
            raise self.outcome[0]
        return self.outcome[0]


def load_tests(loader, tests, pattern):  # noqa: ARG001 - unittest's protocol
    """Every case, the one that waits last (see WAITING_CASE)."""
    suite, waits = last_case(tests, WAITING_CASE)
    WAITING["early"] = waits and not SANITIZED
    return suite


def tearDownModule():
    if WAITING["run"] is not None:  # started, its case not run: its run ends within its own 10 s
        WAITING["run"].thread.join()
    if Shared.folder is not None:
        shutil.rmtree(Shared.folder, ignore_errors=True)


@unittest.skipUnless(CLI, "CALLIGRAPHY_CLI not set")
class RecordReRun(unittest.TestCase):
    """`trial --spec RECORD` with parts edited or swapped: refused as content (exit 2, FILE: /pointer) before a
    device is opened, or run exactly as the record states."""

    def setUp(self):
        self.base = Shared.get()
        self.tmp = Path(tempfile.mkdtemp(prefix="case-", dir=self.base))

    def record(self, name="fixed.json"):
        return json.loads((self.base / name).read_text(encoding="utf-8"))

    def refused(self, record, pointer):
        path = self.tmp / "m.json"
        path.write_text(json.dumps(record, ensure_ascii=False), encoding="utf-8")
        for extra in (["--check"], ["--csv", "out.csv"]):
            r = run(["trial", "--spec", path, *extra], self.tmp)
            lines = error_lines(r)
            self.assertEqual(r.returncode, 2, (extra, lines))
            self.assertEqual(len(lines), 1, lines)
            self.assertIn(f"m.json: {pointer}", lines[0])
            self.assertFalse((self.tmp / "out.csv").exists(), "a refused record wrote its CSV")
        return lines[0]

    def test_simulated_device_physics_on_another_device(self):
        rec = self.record()
        rec["specification"]["trial"]["device"] = "emulated-phantom"
        rec["specification"]["simulated_device"] = SIMULATED_DEVICE
        line = self.refused(rec, "/specification/simulated_device")
        self.assertIn("emulated-phantom", line)

    def test_writer_profile_on_a_persons_trial_refused_before_the_device(self):
        rec = self.record()
        rec["specification"]["trial"]["device"] = "openhaptics"
        rec["specification"]["trial"]["writer"] = "person"
        line = self.refused(rec, "/specification/trial/writer")
        self.assertIn("profile", line)
        self.assertNotIn("libHD", line)  # the content is refused, no device library was looked for

    @heavy
    def test_force_law_of_another_record(self):
        rec = self.record()
        rec["specification"]["force_law"] = self.record("fading.json")["specification"]["force_law"]
        self.refused(rec, "/specification/force_law")

    @heavy
    def test_safety_continuous_above_peak(self):
        rec = self.record()
        rec["specification"]["safety"]["max_force_n"] = 1.0
        rec["specification"]["safety"]["max_continuous_force_n"] = 5.0
        self.refused(rec, "/specification/safety")

    @heavy
    def test_the_writer_part_runs_not_the_profile_name(self):
        original = (self.base / "fixed.csv").read_bytes()
        renamed = self.record()
        renamed["specification"]["trial"]["writer_profile"] = "skilled"  # the part states how it wrote
        faster = self.record()
        faster["specification"]["writer"]["writing_speed_m_s"] *= 2
        outputs = {}
        for name, rec in (("renamed", renamed), ("faster", faster)):
            (self.tmp / f"{name}.json").write_text(json.dumps(rec, ensure_ascii=False), encoding="utf-8")
            r = run(["trial", "--spec", f"{name}.json", "--csv", f"{name}.csv"], self.tmp)
            self.assertEqual(r.returncode, 0, r.stderr)
            outputs[name] = (self.tmp / f"{name}.csv").read_bytes()
        self.assertEqual(outputs["renamed"], original)
        self.assertNotEqual(outputs["faster"], original)


@unittest.skipUnless(CLI, "CALLIGRAPHY_CLI not set")
class OutputSets(unittest.TestCase):
    """`session cohort --csv DIR` and `report --csv DIR` with other kinds of files in the places of the set's."""

    def setUp(self):
        self.base = Shared.get()
        self.tmp = Path(tempfile.mkdtemp(prefix="case-", dir=self.base))
        shutil.copy(self.base / "p.json", self.tmp / "p.json")
        (self.tmp / "tables").mkdir()

    @heavy
    def test_cohort_hard_link_keeps_the_other_name(self):
        keep = self.tmp / "keep.csv"
        keep.write_bytes(b"earlier\n")
        os.link(keep, self.tmp / "tables" / "trials.csv")
        r = run(["session", "cohort", "p.json", "--subjects", "2", "--csv", "tables"], self.tmp)
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertEqual(keep.read_bytes(), b"earlier\n")
        self.assertTrue((self.tmp / "tables" / "trials.csv").read_text(encoding="utf-8").startswith("subject,"))

    def test_cohort_link_to_a_sibling_refused(self):
        outside = self.tmp / "outside.csv"
        outside.write_bytes(b"mine\n")
        os.symlink("../outside.csv", self.tmp / "tables" / "strokes.csv")
        r = run(["session", "cohort", "p.json", "--subjects", "2", "--csv", "tables"], self.tmp)
        lines = error_lines(r)
        self.assertEqual(r.returncode, 2, lines)
        self.assertEqual(len(lines), 1, lines)
        self.assertIn("strokes.csv", lines[0])
        self.assertIn("--csv", lines[0])
        self.assertEqual(outside.read_bytes(), b"mine\n")
        self.assertEqual(sorted(p.name for p in (self.tmp / "tables").iterdir()), ["strokes.csv"])

    @heavy
    def test_cohort_folder_in_place_of_a_table(self):
        (self.tmp / "tables" / "trials.csv").mkdir()
        r = run(["session", "cohort", "p.json", "--subjects", "2", "--csv", "tables"], self.tmp)
        lines = error_lines(r)
        self.assertIn(r.returncode, (1, 2), lines)
        self.assertEqual(len(lines), 1, lines)
        self.assertIn("trials.csv", lines[0])
        self.assertEqual(sorted(p.name for p in (self.tmp / "tables").iterdir()), ["trials.csv"])

    @heavy
    def test_report_fifo_in_place_of_a_table_is_written_in_place(self):
        fifo = self.tmp / "tables" / "strokes.csv"
        os.mkfifo(fifo)
        got = {}

        def reader():
            with open(fifo, "rb") as f:  # blocks until the report opens it for writing
                got["bytes"] = f.read()

        thread = threading.Thread(target=reader, daemon=True)
        thread.start()
        r = run(["report", self.base / "study", "--csv", "tables"], self.tmp, timeout=30)
        thread.join(timeout=30)
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertTrue(got.get("bytes", b"").startswith(b"subject,"), got)
        self.assertTrue(fifo.is_fifo(), "the FIFO was replaced by a file")
        self.assertEqual(sorted(p.name for p in (self.tmp / "tables").iterdir()), ["strokes.csv", "trials.csv"])

    @heavy
    def test_report_fifo_no_process_reads_is_an_error_not_a_hang(self):
        waiting = WAITING["run"] or ReportOntoUnreadFifo(self.base)  # started early when the whole module runs
        WAITING["run"] = None
        r = waiting.result()
        lines = error_lines(r)
        self.assertEqual(r.returncode, 1, lines)
        self.assertEqual(len(lines), 1, lines)
        self.assertIn("strokes.csv", lines[0])
        self.assertIn("no process opened for reading", lines[0])
        self.assertTrue(waiting.fifo.is_fifo(), "the FIFO was replaced by a file")


@unittest.skipUnless(CLI, "CALLIGRAPHY_CLI not set")
@unittest.skipIf(SANITIZED, "a study of two subjects: left to the Release run")
class StudyReportFolders(unittest.TestCase):
    """Python's study report (`python3 -m calligraphy.study_report STUDY --out OUT`) whose own `tables/`
    folder is a symbolic link to a sibling folder: the set's files would leave OUT through it."""

    def test_tables_folder_that_is_a_link(self):
        if cg is None:
            self.skipTest("the Python package is not on PYTHONPATH")
        base = Shared.get()
        tmp = Path(tempfile.mkdtemp(prefix="case-", dir=base))
        (tmp / "elsewhere").mkdir()
        (tmp / "elsewhere" / "mine.txt").write_bytes(b"mine\n")
        (tmp / "paper").mkdir()
        os.symlink("../elsewhere", tmp / "paper" / "tables")
        r = subprocess.run([sys.executable, "-m", "calligraphy.study_report", str(base / "study"), "--out", "paper"],
                           cwd=tmp, stdout=subprocess.PIPE, stderr=subprocess.PIPE, timeout=120, env=ENV)
        lines = error_lines(r)
        self.assertEqual(r.returncode, 1, lines)
        self.assertEqual(len(lines), 1, lines)
        self.assertIn("paper/tables", lines[0])
        self.assertEqual(sorted(p.name for p in (tmp / "elsewhere").iterdir()), ["mine.txt"])
        self.assertEqual(sorted(p.name for p in (tmp / "paper").iterdir()), ["tables"])


@unittest.skipUnless(CLI, "CALLIGRAPHY_CLI not set")
@unittest.skipIf(SANITIZED, "a study of two subjects: left to the Release run")
class SwappedTrace(unittest.TestCase):
    """One trial's trace copied over another's inside a session folder."""

    def test_report_and_samples(self):
        base = Shared.get()
        tmp = Path(tempfile.mkdtemp(prefix="case-", dir=base))
        shutil.copytree(base / "study", tmp / "study")
        trials = next((tmp / "study" / "S01").iterdir()) / "trials"
        shi = next(trials.glob("001-*.trace.h5"))
        ren = next(trials.glob("002-*.trace.h5"))
        shutil.copyfile(shi, ren)
        (tmp / "tables").mkdir()
        r = run(["report", "study", "--csv", "tables"], tmp)
        self.assertEqual(r.returncode, 0, r.stderr)  # the tables come from the records, not the traces
        if cg_study is None:
            self.skipTest("the Python package is not on PYTHONPATH")
        study = cg_study.load([str(tmp / "study")])
        rows = study.trials[study.trials["trace_file"].astype(str).str.endswith(ren.name)
                            & (study.trials["subject"] == "S01")]
        self.assertEqual(len(rows), 1)
        with self.assertRaises(cg.DataError) as caught:
            study.samples(rows.iloc[0])
        self.assertIn(ren.name, str(caught.exception))
        self.assertIn("SHA-256", str(caught.exception))


@unittest.skipUnless(CLI, "CALLIGRAPHY_CLI not set")
class CharacterStatuses(unittest.TestCase):
    """Every command that takes characters, given what it cannot write (docs/cli.md, "Exit statuses")."""

    LACKING = {"Latin letter": "A".encode(), "combining mark": "\u0301".encode()}
    MALFORMED = {"empty": b"", "lone surrogate": b"\xed\xa0\x80"}

    def commands(self, text):
        return {"trial": ["trial", text], "model": ["model", text], "train": ["train", text],
                "score": ["score", "fixed.csv", "--character", text], "characters": ["characters", "--text", text]}

    def test_malformed_text_is_usage_everywhere(self):
        base = Shared.get()
        for label, text in self.MALFORMED.items():
            for name, args in self.commands(text).items():
                with self.subTest(text=label, command=name):
                    r = run(args, base)
                    lines = error_lines(r)
                    if WITHOUT_WINDOW in r.stderr:  # the sanitizer stage's build: `train` only says so
                        continue
                    self.assertEqual(r.returncode, 2, lines)
                    self.assertEqual(len(lines), 1, lines)

    @heavy
    def test_a_character_the_library_lacks(self):
        base = Shared.get()
        for label, text in self.LACKING.items():
            code = "U+%04X" % ord(text.decode())
            for name, args in self.commands(text).items():
                with self.subTest(text=label, command=name):
                    r = run(args, base)
                    lines = error_lines(r)
                    if WITHOUT_WINDOW in r.stderr:
                        continue
                    if name == "characters":  # named on its list, not an error
                        self.assertEqual(r.returncode, 0, lines)
                        continue
                    self.assertEqual(len(lines), 1, lines)
                    self.assertIn(code, lines[0])
                    # The table: wrong usage, naming the argument that gave it, as a protocol's is.
                    self.assertEqual(r.returncode, 2, lines)
                    self.assertIn("--character" if name == "score" else "CHAR", lines[0])
            # A trial record whose characters were edited to one the library lacks: named at its pointer.
            record = base / f"lacking-{code}.record.json"
            if not record.exists():
                made = run(["trial", SHI, "--json", record.name], base)
                self.assertEqual(made.returncode, 0, made.stderr)
                document = json.loads(record.read_text(encoding="utf-8"))
                document["specification"]["trial"]["characters"] = SHI + text.decode()
                record.write_text(json.dumps(document, ensure_ascii=False), encoding="utf-8")
            r = run(["trial", "--spec", record.name, "--json", "again.json"], base)
            lines = error_lines(r)
            with self.subTest(text=label, command="trial --spec"):
                self.assertEqual(r.returncode, 2, lines)
                self.assertEqual(len(lines), 1, lines)
                self.assertIn(f"{record.name}: /specification/trial/characters", lines[0])
                self.assertIn(code, lines[0])
            protocol = copy.deepcopy(PROTOCOL)
            protocol["test"]["characters"] = [SHI + text.decode()]
            path = base / f"lacking-{code}.json"
            path.write_text(json.dumps(protocol, ensure_ascii=False), encoding="utf-8")
            r = run(["session", "plan", path.name, "--subjects", "1"], base)
            lines = error_lines(r)
            with self.subTest(text=label, command="session plan"):
                self.assertEqual(r.returncode, 2, lines)
                self.assertEqual(len(lines), 1, lines)
                self.assertIn(f"{path.name}: /test/characters/0", lines[0])
                self.assertIn(code, lines[0])


if __name__ == "__main__":
    unittest.main(verbosity=2)
