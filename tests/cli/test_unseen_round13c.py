#!/usr/bin/env python3
"""Round 13C: hostile cases written from the documentation alone (docs/cli.md, docs/python.md,
docs/experiments.md, docs/corpus.md and each command's `--help`): every kind of file the program writes given
to every reader that expects another kind. Run by CTest as `cli_unseen_round13c_tests`.

One small genuine file of each kind is made once (a trial record `trial --json`, a trace CSV `trial --csv`
and its gzip, an SVG, a teacher recording `trial --record`, a protocol, a study of one session with its
session.json, trial record and `.trace.h5`, the tables of `report --csv`, a report page, a corpus store, the
`schema record` output and a hanzi-writer-data character) and each is given to `trial --spec`, `trial
--teacher`, `score`, `trace`, `session plan|run|resume`, `report`, `curriculum`, `--store`, `--data` and
Python's readers (`check_trial_record`, `rerun_trial`, `TeacherRecording.load`, `study.load`, `score`,
`CharacterLibrary.from_store|from_hanzi_writer`), also under a misleading extension (a record named .csv, a
CSV named .trace.h5, an HDF5 named .json).

Each case asserts what the documentation promises: the exit status (2 for a command's own input whose
content is refused: `trial --spec`, a protocol, the session.json of `session resume`; 1 for data the library
cannot read), one error line that names the file, no parser's internal text, no output file written or
replaced, and from Python the documented exception, never a crash.
CALLIGRAPHY_CLI names the program, CALLIGRAPHY_SOURCE_DIR the source tree (its hanzi-writer-data sample).
CALLIGRAPHY_SANITIZED=1 takes five cases.
"""
import gzip
import json
import os
import shutil
import subprocess
import sys
import tempfile
import unittest
from pathlib import Path

from outsider import CLI, ENV, error_lines, run, sanitized_subset

SOURCE = Path(os.environ.get("CALLIGRAPHY_SOURCE_DIR", Path(__file__).resolve().parents[2]))
SAMPLE = SOURCE / "data" / "hanzi-writer-data"
YI, SHI = "一", "十"
PROTOCOL = {"name": "p13c", "conditions": [{"name": "f", "mode": "haptic"}],
            "test": {"characters": [YI], "conditions": ["f"], "repetitions": 1}}

load_tests = sanitized_subset({"test_spec_given_every_other_kind",
                               "test_score_given_files_that_are_no_trace",
                               "test_trace_given_files_that_are_no_hdf5_trace",
                               "test_session_plan_given_every_other_kind",
                               "test_store_given_every_other_kind"})

F = {}  # the genuine files, by kind
# What a JSON reader says a file of another kind is, by its first bytes.
SAYS = {"csv": "CSV text", "tables": "CSV text", "gz": "gzip", "svg": "markup", "html": "markup",
        "trace.h5": "trace file", "h5.json": "trace file", "store": "corpus store"}
INTERNAL = ("json.exception", "parse_error", "what()", "Traceback", "terminate called", "std::")


def setUpModule():
    if not CLI or not Path(CLI).exists():
        raise unittest.SkipTest("CALLIGRAPHY_CLI is not set to the built program")
    d = Path(tempfile.mkdtemp(prefix="r13c-"))
    F["dir"] = d
    made = run(["trial", YI, "--json", "record.json", "--csv", "trace.csv", "--svg", "drawing.svg",
                "--record", "teacher.json", "--max-duration", "6"], d)
    assert made.returncode == 0, made.stderr
    (d / "protocol.json").write_text(json.dumps(PROTOCOL, ensure_ascii=False), encoding="utf-8")
    made = run(["session", "run", "protocol.json", "--subject", "S1", "--out", "study"], d)
    assert made.returncode == 0, made.stderr
    session = next((d / "study" / "S1").iterdir())
    F["session"] = session
    F["session.json"] = session / "session.json"
    F["study_record"] = next((session / "trials").glob("*.json"))
    F["trace.h5"] = next((session / "trials").glob("*.trace.h5"))
    (d / "tables").mkdir()
    made = run(["report", "study", "--out", "report.html", "--csv", "tables"], d)
    assert made.returncode == 0, made.stderr
    (d / "hw").mkdir()
    shutil.copyfile(SAMPLE / f"{SHI}.json", d / "hw" / f"{SHI}.json")
    made = run(["corpus", "build", "--data", "hw", "--out", "store.clg", "--threads", "1"], d)
    assert made.returncode == 0, made.stderr
    made = run(["schema", "record"], d)
    assert made.returncode == 0, made.stderr
    (d / "schema.json").write_bytes(made.stdout)
    (d / "trace.csv.gz").write_bytes(gzip.compress((d / "trace.csv").read_bytes()))
    shutil.copyfile(SAMPLE / f"{SHI}.json", d / "char.json")
    for kind, name in (("record", "record.json"), ("csv", "trace.csv"), ("gz", "trace.csv.gz"),
                       ("svg", "drawing.svg"), ("teacher", "teacher.json"), ("protocol", "protocol.json"),
                       ("tables", "tables/trials.csv"), ("html", "report.html"), ("store", "store.clg"),
                       ("schema", "schema.json"), ("char", "char.json")):
        F[kind] = d / name
    # the misleading names
    shutil.copyfile(F["record"], d / "record-named.csv")
    shutil.copyfile(F["csv"], d / "csv-named.trace.h5")
    shutil.copyfile(F["trace.h5"], d / "h5-named.json")
    F["record.csv"], F["csv.h5"], F["h5.json"] = d / "record-named.csv", d / "csv-named.trace.h5", d / "h5-named.json"


def tearDownModule():
    if "dir" in F:
        shutil.rmtree(F["dir"], ignore_errors=True)


class Case(unittest.TestCase):
    def refused(self, result, status, path, what=""):
        """Exit `status`, one error line naming the file `path`, no parser's or runtime's own text."""
        lines = error_lines(result)
        self.assertEqual(result.returncode, status, f"{what}: {lines}")
        self.assertEqual(len(lines), 1, f"{what}: {lines}")
        self.assertIn(Path(path).name, lines[0], what)
        for text in INTERNAL:
            self.assertNotIn(text, lines[0], what)
        return lines[0]

    def work(self):
        return Path(tempfile.mkdtemp(prefix="case-", dir=F["dir"]))

    def nothing_written(self, folder, before):
        self.assertEqual(sorted(p.name for p in Path(folder).iterdir()), before)


class TestTrialInputs(Case):
    def test_spec_given_every_other_kind(self):
        """docs/cli.md: a record whose content is refused (malformed JSON, a part missing, an unknown key) is
        exit 2, one line naming the file; nothing written."""
        w = self.work()
        for kind in ("teacher", "protocol", "session.json", "schema", "char", "csv", "gz", "svg", "trace.h5",
                     "h5.json", "tables", "html"):
            with self.subTest(kind=kind):
                r = run(["trial", "--spec", F[kind], "--json", "out.json"], w)
                line = self.refused(r, 2, F[kind], kind)
                if kind in SAYS:
                    self.assertIn(SAYS[kind], line)
                self.nothing_written(w, [])

    def test_spec_of_a_record_named_csv_is_the_record(self):
        """A record is read by its content: named .csv it runs as the record it is (the same JSON back)."""
        w = self.work()
        r = run(["trial", "--spec", F["record.csv"], "--check"], w)
        self.assertEqual(r.returncode, 0, error_lines(r))

    def test_a_study_record_and_a_teacher_named_csv_are_read_by_content(self):
        """A session's trial record is a trial record (`--check` valid), and a teacher recording named .csv
        guides the replay as under its own name: the same trial."""
        w = self.work()
        r = run(["trial", "--spec", F["study_record"], "--check"], w)
        self.assertEqual(r.returncode, 0, error_lines(r))
        shutil.copyfile(F["teacher"], w / "teacher.csv")
        runs = []
        for teacher in (F["teacher"], w / "teacher.csv"):
            r = run(["trial", YI, "--guidance-mode", "replay", "--teacher", teacher, "--max-duration", "6",
                     "--json", "-"], w)
            self.assertEqual(r.returncode, 0, error_lines(r))
            runs.append(json.loads(r.stdout))
        for key in ("mean_deviation_m", "strokes_accepted", "trial_time_s", "pen_down_time_s"):
            self.assertEqual(runs[0][key], runs[1][key], key)
        self.assertEqual(runs[0]["specification"]["teacher_sha256"], runs[1]["specification"]["teacher_sha256"])

    def test_check_given_other_kinds(self):
        w = self.work()
        for kind in ("teacher", "protocol", "session.json"):
            with self.subTest(kind=kind):
                self.refused(run(["trial", "--spec", F[kind], "--check"], w), 2, F[kind], kind)

    def test_teacher_given_every_other_kind(self):
        """A teacher that is another kind of file is refused naming it (exit 1: data the library cannot read);
        no output written."""
        w = self.work()
        for kind in ("record", "study_record", "protocol", "session.json", "csv", "gz", "trace.h5", "h5.json",
                     "char", "schema"):
            with self.subTest(kind=kind):
                r = run(["trial", YI, "--guidance-mode", "replay", "--teacher", F[kind], "--json", "out.json",
                         "--max-duration", "1"], w)
                line = self.refused(r, 1, F[kind], kind)
                self.assertIn(SAYS.get(kind, "not a teacher's recording"), line)
                self.nothing_written(w, [])

    def test_session_run_replay_teacher_of_every_other_kind(self):
        """docs/cli.md, "Teachers": a teacher that is no teacher's recording is refused naming the condition and
        the file (exit 1: data), and no folder is made."""
        w = self.work()
        for kind in ("record", "protocol", "csv", "trace.h5", "gz", "char"):
            with self.subTest(kind=kind):
                shutil.copyfile(F[kind], w / "teacher-file")
                protocol = {"name": "rp", "conditions": [{"name": "echo", "mode": "replay",
                                                          "teachers": {YI: "teacher-file"}}],
                            "test": {"characters": [YI], "conditions": ["echo"], "repetitions": 1}}
                (w / "rp.json").write_text(json.dumps(protocol, ensure_ascii=False), encoding="utf-8")
                r = run(["session", "run", "rp.json", "--subject", "S1", "--out", "out"], w)
                line = self.refused(r, 1, "teacher-file", kind)
                self.assertIn("'echo'", line)
                self.assertIn(SAYS.get(kind, "not a teacher's recording"), line)
                self.nothing_written(w, ["rp.json", "teacher-file"])


class TestTraceReaders(Case):
    def test_score_given_files_that_are_no_trace(self):
        """score reads CSV, gzip of CSV and HDF5 traces; another kind is refused naming it (exit 1)."""
        w = self.work()
        for kind in ("record", "teacher", "protocol", "session.json", "svg", "schema", "char", "store",
                     "tables", "html", "record.csv"):
            with self.subTest(kind=kind):
                r = run(["score", F[kind], "--character", YI, "--json", "out.json"], w)
                self.refused(r, 1, F[kind], kind)
                self.nothing_written(w, [])

    def test_score_of_a_gzipped_record_is_refused_naming_it(self):
        """A gzip is decompressed by its first bytes; what it holds must still be a trace (exit 1, one line)."""
        w = self.work()
        (w / "record.json.gz").write_bytes(gzip.compress(F["record"].read_bytes()))
        r = run(["score", "record.json.gz", "--character", YI, "--json", "out.json"], w)
        self.refused(r, 1, "record.json.gz", "gzip of a record")
        self.nothing_written(w, ["record.json.gz"])

    def test_score_reads_every_trace_kind_alike_whatever_its_name(self):
        """The CSV, its gzip and the HDF5 trace score alike under their own names and under misleading ones
        (a CSV named .trace.h5, an HDF5 named .json): each is read by its content."""
        w = self.work()
        scores = {}
        for kind in ("csv", "gz", "csv.h5"):
            r = run(["score", F[kind], "--character", YI, "--json", "-"], w)
            self.assertEqual(r.returncode, 0, (kind, error_lines(r)))
            scores[kind] = json.loads(r.stdout)
        for key in ("mean_deviation_m", "strokes_accepted", "order_errors"):
            self.assertEqual(scores["csv"][key], scores["gz"][key], key)
            self.assertEqual(scores["csv"][key], scores["csv.h5"][key], key)
        h5 = run(["score", F["trace.h5"], "--character", YI, "--json", "-"], w)
        h5_named = run(["score", F["h5.json"], "--character", YI, "--json", "-"], w)
        self.assertEqual(h5.returncode, 0, error_lines(h5))
        self.assertEqual(h5_named.returncode, 0, error_lines(h5_named))
        a, b = json.loads(h5.stdout), json.loads(h5_named.stdout)
        self.assertEqual(a["mean_deviation_m"], b["mean_deviation_m"])

    def test_trace_given_files_that_are_no_hdf5_trace(self):
        """trace: a damaged, cut or foreign file is refused naming it (exit 1); no CSV written."""
        w = self.work()
        for kind in ("csv", "gz", "csv.h5", "record", "study_record", "teacher", "store", "svg"):
            with self.subTest(kind=kind):
                r = run(["trace", F[kind], "--csv", "out.csv"], w)
                self.refused(r, 1, F[kind], kind)
                self.nothing_written(w, [])

    def test_trace_of_an_hdf5_named_json_is_the_same_csv(self):
        w = self.work()
        a = run(["trace", F["trace.h5"]], w)
        b = run(["trace", F["h5.json"]], w)
        self.assertEqual(a.returncode, 0, error_lines(a))
        self.assertEqual(b.returncode, 0, error_lines(b))
        self.assertEqual(a.stdout, b.stdout)


class TestStudyReaders(Case):
    def test_session_plan_given_every_other_kind(self):
        """A protocol whose content is refused is exit 2, one line naming the file."""
        w = self.work()
        for kind in ("record", "teacher", "session.json", "schema", "char", "csv", "tables", "svg"):
            with self.subTest(kind=kind):
                self.refused(run(["session", "plan", F[kind], "--subjects", "1"], w), 2, F[kind], kind)

    def test_session_plan_given_binary_files(self):
        """An HDF5 trace, a gzip or a store is malformed JSON as a protocol: exit 2, one line naming the file and
        what it is (not the parser's words for its first byte)."""
        w = self.work()
        for kind, what in (("trace.h5", "trace"), ("gz", "gzip"), ("store", "corpus store")):
            with self.subTest(kind=kind):
                line = self.refused(run(["session", "plan", F[kind], "--subjects", "1"], w), 2, F[kind], kind)
                self.assertIn(what, line)

    def test_session_run_given_other_kinds_makes_no_folder(self):
        w = self.work()
        for kind in ("record", "session.json", "teacher"):
            with self.subTest(kind=kind):
                r = run(["session", "run", F[kind], "--subject", "S1", "--out", "out"], w)
                self.refused(r, 2, F[kind], kind)
                self.nothing_written(w, [])

    def copied_session(self):
        w = self.work()
        copy = w / "study"
        shutil.copytree(F["dir"] / "study", copy, symlinks=True)
        session = copy / F["session"].relative_to(F["dir"] / "study")
        return w, copy, session

    def test_session_resume_with_a_foreign_session_json(self):
        """session.json refused by `session resume`: exit 2, `DIR/session.json: /pointer: ...`; the folder
        unchanged."""
        for kind in ("record", "protocol", "teacher", "schema"):
            with self.subTest(kind=kind):
                w, copy, session = self.copied_session()
                shutil.copyfile(F[kind], session / "session.json")
                before = sorted(p.relative_to(copy) for p in copy.rglob("*"))
                r = run(["session", "resume", session], w)
                line = self.refused(r, 2, "session.json", kind)
                self.assertIn(": /", line, kind)
                self.assertEqual(sorted(p.relative_to(copy) for p in copy.rglob("*")), before)

    def test_session_resume_with_an_hdf5_for_session_json(self):
        w, copy, session = self.copied_session()
        shutil.copyfile(F["trace.h5"], session / "session.json")
        r = run(["session", "resume", session], w)
        self.refused(r, 2, "session.json", "hdf5")

    def test_report_with_a_foreign_session_json(self):
        """report reads session.json as data: damaged data, exit 1 naming it; no page or table written."""
        for kind in ("record", "protocol"):
            with self.subTest(kind=kind):
                w, copy, session = self.copied_session()
                shutil.copyfile(F[kind], session / "session.json")
                r = run(["report", "study", "--out", "r.html"], w)
                self.refused(r, 1, "session.json", kind)
                self.assertFalse((w / "r.html").exists())

    def test_report_with_a_trial_record_of_another_kind(self):
        """A session's trial record replaced by a teacher recording or a protocol: exit 1 naming it."""
        for kind in ("teacher", "protocol", "record"):
            with self.subTest(kind=kind):
                w, copy, session = self.copied_session()
                target = session / "trials" / F["study_record"].name
                shutil.copyfile(F[kind], target)
                (w / "tables").mkdir()
                r = run(["report", "study", "--csv", "tables"], w)
                self.refused(r, 1, target.name, kind)
                self.assertEqual(list((w / "tables").iterdir()), [])

    def test_report_with_a_csv_for_its_hdf5_trace(self):
        """The pages read the traces: a CSV under the .trace.h5 name is refused naming it (exit 1)."""
        w, copy, session = self.copied_session()
        target = session / "trials" / F["trace.h5"].name
        shutil.copyfile(F["csv"], target)
        r = run(["report", "study", "--out", "r.html"], w)
        self.refused(r, 1, target.name, "csv as h5")
        self.assertFalse((w / "r.html").exists())

    def test_folders_of_other_kinds_given_for_a_session_or_a_study(self):
        """session resume of the study folder, a subject's folder or a tables folder, and report and
        curriculum of a folder of tables or report pages: one line naming the folder and what it lacks (exit 1,
        a missing file), nothing written."""
        w = self.work()
        shutil.copytree(F["dir"] / "tables", w / "tables")
        shutil.copytree(F["dir"] / "report_files", w / "pages")
        before = sorted(p.name for p in w.iterdir())
        for folder in (F["dir"] / "study", F["dir"] / "study" / "S1", w / "tables"):
            with self.subTest(resume=folder.name):
                line = self.refused(run(["session", "resume", folder], w), 1, folder, "resume")
                self.assertIn("session.json", line)
        for folder in ("tables", "pages"):
            with self.subTest(report=folder):
                self.refused(run(["report", folder, "--out", "r.html"], w), 1, folder, "report")
                self.refused(run(["curriculum", folder, "--subject", "S1", "--from", SHI], w), 1, folder,
                             "curriculum")
        self.nothing_written(w, before)

    def test_curriculum_with_a_trial_record_of_another_kind(self):
        w, copy, session = self.copied_session()
        target = session / "trials" / F["study_record"].name
        shutil.copyfile(F["protocol"], target)
        r = run(["curriculum", "study", "--subject", "S1", "--from", "十人"], w)
        self.refused(r, 1, target.name, "protocol as record")


class TestCharacterSources(Case):
    def test_store_given_every_other_kind(self):
        """--store of another kind of file: data the library cannot read, exit 1 naming it."""
        w = self.work()
        for kind in ("record", "csv", "gz", "trace.h5", "schema", "char", "svg"):
            with self.subTest(kind=kind):
                r = run(["model", SHI, "--store", F[kind]], w)
                self.refused(r, 1, F[kind], kind)
                r = run(["trial", SHI, "--store", F[kind], "--json", "out.json"], w)
                self.refused(r, 1, F[kind], kind)
                self.nothing_written(w, [])

    def test_corpus_stats_given_every_other_kind(self):
        """corpus stats of a file that is no store: exit 1, one line naming it."""
        w = self.work()
        for kind in ("record", "gz", "trace.h5", "csv", "char"):
            with self.subTest(kind=kind):
                self.refused(run(["corpus", "stats", F[kind]], w), 1, F[kind], kind)

    def test_data_folder_of_other_kinds_named_as_characters(self):
        """A --data folder whose 十.json is a trial record, a teacher or a protocol: the character the library
        has but cannot read is exit 1 naming its file."""
        for kind in ("record", "teacher", "protocol", "session.json", "h5.json"):
            with self.subTest(kind=kind):
                w = self.work()
                (w / "hw").mkdir()
                shutil.copyfile(F[kind], w / "hw" / f"{SHI}.json")
                r = run(["model", SHI, "--data", "hw"], w)
                self.refused(r, 1, f"{SHI}.json", kind)

    def test_corpus_build_from_a_folder_of_other_kinds(self):
        """corpus build: characters that could not be modelled are named (exit 1), the others stored; a folder
        of none that can be is an error naming the folder and no store is written."""
        w = self.work()
        (w / "hw").mkdir()
        shutil.copyfile(SAMPLE / f"{SHI}.json", w / "hw" / f"{SHI}.json")
        shutil.copyfile(F["record"], w / "hw" / "人.json")
        r = run(["corpus", "build", "--data", "hw", "--out", "s.clg", "--threads", "1"], w)
        lines = error_lines(r)
        self.assertEqual(r.returncode, 1, lines)
        self.assertEqual(len(lines), 1, lines)
        self.assertIn("人", lines[0])
        self.assertEqual(run(["model", SHI, "--store", "s.clg"], w).returncode, 0)
        (w / "hw" / f"{SHI}.json").unlink()
        r = run(["corpus", "build", "--data", "hw", "--out", "t.clg", "--threads", "1"], w)
        self.refused(r, 1, "hw", "only foreign")
        self.assertFalse((w / "t.clg").exists())


class TestPythonReaders(Case):
    def python(self, code):
        env = dict(ENV)
        r = subprocess.run([sys.executable, "-c", code], cwd=F["dir"], env=env, stdout=subprocess.PIPE,
                           stderr=subprocess.PIPE, timeout=120)
        self.assertEqual(r.returncode, 0, r.stderr.decode())
        return json.loads(r.stdout)

    def test_python_readers_given_other_kinds(self):
        """check_trial_record, rerun_trial and TeacherRecording.load raise DataError (or InvalidArgument for
        a record's contradiction) naming the file, never another exception."""
        cases = {
            "check_trial_record": ["teacher", "protocol", "session.json", "csv", "trace.h5", "h5.json", "char"],
            "rerun_trial": ["teacher", "protocol", "csv", "trace.h5"],
            "TeacherRecording.load": ["record", "protocol", "session.json", "csv", "gz", "trace.h5", "schema"],
            "CharacterLibrary.from_store": ["record", "csv", "trace.h5", "char"],
        }
        code = f"""
import json, calligraphy as cg
cases = {json.dumps({fn: [str(F[k]) for k in kinds] for fn, kinds in cases.items()})}
out = []
for fn, paths in cases.items():
    call = {{"check_trial_record": cg.check_trial_record, "rerun_trial": cg.rerun_trial,
            "TeacherRecording.load": cg.TeacherRecording.load,
            "CharacterLibrary.from_store": cg.CharacterLibrary.from_store}}[fn]
    for p in paths:
        try:
            call(p)
            out.append([fn, p, "returned", ""])
        except Exception as e:
            out.append([fn, p, type(e).__name__, str(e)])
print(json.dumps(out))
"""
        for fn, path, kind, message in self.python(code):
            with self.subTest(fn=fn, path=path):
                self.assertEqual(kind, "DataError", message)
                self.assertIn(Path(path).name, message)
                self.assertEqual(len(message.splitlines()), 1, message)
                for text in INTERNAL:
                    self.assertNotIn(text, message)

    def test_python_score_of_the_wrong_table_and_study_load_of_a_foreign_folder(self):
        """score of the trials table (no t/x/y) is InvalidArgument naming a column; score of a record's path
        a DataError naming it; study.load of a study whose session.json is a protocol, Study.samples of a trial
        whose .trace.h5 is a CSV and a hanzi-writer folder whose character file is a gzip: DataError naming the
        file."""
        w = self.work()
        copy = w / "study"
        shutil.copytree(F["dir"] / "study", copy)
        session = copy / F["session"].relative_to(F["dir"] / "study")
        shutil.copyfile(F["protocol"], session / "session.json")
        (w / "hw").mkdir()
        shutil.copyfile(F["gz"], w / "hw" / f"{SHI}.json")
        other = w / "other"  # the study whose trace is the trial's CSV under the .trace.h5 name
        shutil.copytree(F["dir"] / "study", other)
        trace = other / F["trace.h5"].relative_to(F["dir"] / "study")
        shutil.copyfile(F["csv"], trace)
        code = f"""
import json, calligraphy as cg, calligraphy.study as st
import pandas as pd
out = []
def attempt(what, f):
    try:
        f(); out.append([what, "returned", ""])
    except Exception as e:
        out.append([what, type(e).__name__, str(e)])
attempt("score-table", lambda: cg.score(pd.read_csv({str(F["tables"])!r}), "一"))
attempt("score-record", lambda: cg.score({str(F["record"])!r}, "一"))
attempt("score-record.csv", lambda: cg.score({str(F["record.csv"])!r}, "一"))
attempt("study.load", lambda: st.load({str(copy)!r}))
def samples():
    other = st.load({str(other)!r})
    other.samples(0)
attempt("samples", samples)
attempt("from_hanzi_writer", lambda: cg.CharacterLibrary.from_hanzi_writer({str(w / "hw")!r}).load("十"))
print(json.dumps(out))
"""
        got = {what: (kind, message) for what, kind, message in self.python(code)}
        self.assertEqual(got["score-table"][0], "InvalidArgument", got["score-table"])
        for what, name in (("score-record", "record.json"), ("score-record.csv", "record-named.csv"),
                           ("study.load", "session.json"), ("from_hanzi_writer", f"{SHI}.json"),
                           ("samples", trace.name)):
            self.assertEqual(got[what][0], "DataError", got[what])
            self.assertIn(name, got[what][1], got[what])
            for text in INTERNAL:
                self.assertNotIn(text, got[what][1])
        self.assertIn("gzip", got["from_hanzi_writer"][1])


if __name__ == "__main__":
    unittest.main()
