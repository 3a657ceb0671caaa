#!/usr/bin/env python3
"""Round 22C: the commands composed, every documented output fed to the command that reads it. From the docs
alone (docs/cli.md, each command's section, "Conventions", "Pen traces", "Re-running a trial"; docs/experiments.md
"Trace files", "Trial records", "Tidy tables", "A cohort in memory"; docs/metrics.md "Trace CSV"; docs/python.md
"Scoring any pen trace", "Running a trial again", "A study's traces"; each command's --help).

Earlier rounds attacked each command's own inputs; this one checks that what one command writes is what the next
one reads, as a lab scripts them: a trial's CSV, a session's HDF5 trace and `trace`'s CSV scored to the trial's
own metrics; `trace` of a session's trace against `trial --spec` of its record; the records, session.json and
protocol against `schema record|metrics|session|protocol`; `session plan --json` against the session it plans;
`report --csv`'s `trace_file` scored to its row; `session cohort`'s tables against `report --csv` of the same
subject; `characters` fed to `model` and to `strokes`, `curriculum` to `characters` and `trial`, `devices` to
`trial --check`; the shell's ways of passing them (a pipe through /dev/stdin, `-`, process substitution, a FIFO,
`xargs -n1`, `find -exec` writing into the session folder `report` reads, /dev/stdout); Python and the command
line in one pipeline (a DataFrame's CSV scored by the command, the command's CSV scored by Python, teachers
recorded by one and replayed by the other, a study's samples scored by Python against `score` of the trace).

CALLIGRAPHY_CLI names the program, PYTHONPATH its Python module. CALLIGRAPHY_SANITIZED=1 takes five cases.
"""
import csv
import io
import json
import math
import shutil
import subprocess
import tempfile
import unittest
from pathlib import Path

import calligraphy as cg
import jsonschema

from outsider import CLI, ENV, OneErrorLine, run, run_ok, sanitized_subset

load_tests = sanitized_subset({"test_score_of_the_trials_csv_is_the_trials_metrics",
                               "test_trace_of_a_session_trace_is_trial_spec_of_its_record",
                               "test_schema_record_and_metrics_hold_real_records",
                               "test_report_trace_file_scored_is_its_row",
                               "test_characters_fed_one_by_one_to_model_agree"})

TRIAL = ["--seed", "3", "--max-duration", "4"]
PROTOCOL = {"name": "r22c", "conditions": [{"name": "V", "mode": "vision"}],
            "test": {"characters": ["一", "十"], "conditions": ["V"], "repetitions": 1},
            "trial": {"max_duration_s": 6}}
LEARNING = ["--writer-learning", "none"]


def sh(script, cwd):
    """A bash script with the program as $C, its output and errors captured."""
    env = dict(ENV, C=CLI)
    return subprocess.run(["bash", "-c", "set -o pipefail\n" + script], cwd=cwd, env=env, timeout=60,
                          stdout=subprocess.PIPE, stderr=subprocess.PIPE, stdin=subprocess.DEVNULL)


def metric_keys():
    schema = json.loads(run_ok(["schema", "metrics"], ".").stdout)
    return sorted(schema["properties"])


def close(a, b, rel=1e-9, abs_=1e-9):
    if a is None or b is None:
        return a is None and b is None
    if isinstance(a, bool) or isinstance(b, bool) or isinstance(a, str):
        return a == b
    return math.isclose(a, b, rel_tol=rel, abs_tol=abs_)


class Round22C(unittest.TestCase, OneErrorLine):
    @classmethod
    def setUpClass(cls):
        cls.tmp = Path(tempfile.mkdtemp(prefix="round22c-"))
        t = cls.tmp
        # One trial of 一 with every output, a skilled writer's teacher of 一.
        run_ok(["trial", "一", *TRIAL, "--json", "t.json", "--csv", "t.csv", "--svg", "t.svg"], t)
        run_ok(["trial", "一", "--writer-profile", "skilled", "--max-duration", "4", "--record", "teach.json"], t)
        cls.record = json.loads((t / "t.json").read_text(encoding="utf-8"))
        # One study of one subject writing 一 and 十, its tables.
        (t / "p.json").write_text(json.dumps(PROTOCOL), encoding="utf-8")
        run_ok(["session", "run", "p.json", "--subject", "S01", "--out", "study", *LEARNING], t)
        (t / "tables").mkdir()
        run_ok(["report", "study", "--csv", "tables"], t)
        sessions = sorted((t / "study" / "S01").iterdir())
        assert len(sessions) == 1, sessions
        cls.session = sessions[0]
        cls.records = sorted(p for p in (cls.session / "trials").glob("*.json"))
        cls.traces = sorted((cls.session / "trials").glob("*.trace.h5"))
        assert len(cls.records) == 2 and len(cls.traces) == 2, (cls.records, cls.traces)
        cls.keys = metric_keys()

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.tmp, ignore_errors=True)

    def assert_metrics_equal(self, got, want, what):
        for k in self.keys:
            self.assertIn(k, got, f"{what}: {k}")
            self.assertTrue(close(got[k], want[k]), f"{what}: {k}: {got[k]!r} against {want[k]!r}")

    def assert_tree_close(self, got, want, what):
        """Two JSON values alike, numbers to a relative 1e-9 (the same arithmetic in another order)."""
        if isinstance(want, dict):
            self.assertEqual(sorted(got), sorted(want), what)
            for k in want:
                self.assert_tree_close(got[k], want[k], f"{what}/{k}")
        elif isinstance(want, list):
            self.assertEqual(len(got), len(want), what)
            for i, (a, b) in enumerate(zip(got, want)):
                self.assert_tree_close(a, b, f"{what}/{i}")
        else:
            self.assertTrue(close(got, want), f"{what}: {got!r} against {want!r}")

    def score(self, trace, character, cwd=None):
        r = run_ok(["score", trace, "--character", character, "--json", "-"], cwd or self.tmp)
        return json.loads(r.stdout)

    # --- traces scored: trial CSV, session HDF5, trace's CSV, the records -----------------------------------

    def test_score_of_the_trials_csv_is_the_trials_metrics(self):
        # docs/cli.md "trial": every key of the metrics record "with the values calligraphy score gives for the
        # trial's CSV".
        self.assert_metrics_equal(self.score("t.csv", "一"), self.record, "score t.csv")
        self.assert_tree_close(self.score("t.csv", "一")["per_character"], self.record["per_character"], "score t.csv")

    def test_session_trace_its_csv_and_its_record_score_alike(self):
        for rec, h5 in zip(self.records, self.traces):
            record = json.loads(rec.read_text(encoding="utf-8"))
            ch = record["characters"]
            out = self.tmp / (h5.name + ".csv")
            run_ok(["trace", h5, "--csv", out], self.tmp)
            by_h5, by_csv = self.score(h5, ch), self.score(out, ch)
            self.assert_metrics_equal(by_h5, record, f"score {h5.name}")
            self.assert_metrics_equal(by_csv, by_h5, f"score of trace's CSV of {h5.name}")
            self.assert_tree_close(by_csv["per_character"], by_h5["per_character"], h5.name)
            self.assertEqual(by_h5["samples"], record["samples"])

    def test_trace_of_a_session_trace_is_trial_spec_of_its_record(self):
        # docs/cli.md "trace": "the same text, byte for byte, as trial --csv of that trial would have written";
        # "Re-running a trial": a session's record runs again to the same trace.
        for rec, h5 in zip(self.records, self.traces):
            traced = run_ok(["trace", h5], self.tmp).stdout
            again = run(["trial", "--spec", rec, "--csv", "-"], self.tmp)
            self.assertIn(again.returncode, (0, 1), again.stderr)
            self.assertEqual(traced, again.stdout, rec.name)

    def test_trace_to_standard_output_in_every_form_is_one_text(self):
        h5 = self.traces[1]
        plain = run_ok(["trace", h5], self.tmp).stdout
        self.assertEqual(run_ok(["trace", h5, "--csv", "-"], self.tmp).stdout, plain)
        self.assertEqual(run_ok(["trace", h5, "--csv", "/dev/stdout"], self.tmp).stdout, plain)
        run_ok(["trace", h5, "--csv", "std.csv"], self.tmp)
        self.assertEqual((self.tmp / "std.csv").read_bytes(), plain)

    def test_trial_outputs_to_standard_output_are_the_files(self):
        # `-` means standard output, which then carries that document only.
        for opt, name in (("--json", "t.json"), ("--csv", "t.csv"), ("--svg", "t.svg")):
            got = run_ok(["trial", "一", *TRIAL, opt, "-"], self.tmp).stdout
            self.assertEqual(got, (self.tmp / name).read_bytes(), opt)

    def test_an_output_named_dev_stdout_on_a_pipe_is_written_in_place(self):
        # /dev/stdout on a pipe is no regular file: "written directly", as a FIFO; `strokes --markdown` prints
        # nothing else, so it is `--markdown -` byte for byte, and a trial's outputs come before its table.
        dash = run_ok(["strokes", "--markdown", "-"], self.tmp).stdout
        self.assertEqual(run_ok(["strokes", "--markdown", "/dev/stdout"], self.tmp).stdout, dash)
        got = run_ok(["trial", "一", *TRIAL, "--json", "/dev/stdout"], self.tmp).stdout
        self.assertTrue(got.startswith((self.tmp / "t.json").read_bytes()), got[:200])
        self.assertGreater(len(got), len((self.tmp / "t.json").read_bytes()))  # then the table
        self.assertFalse(list(self.tmp.glob(".*.tmp-*")))

    def test_model_svg_to_standard_output_is_the_file(self):
        run_ok(["model", "十", "--svg", "m.svg"], self.tmp)
        self.assertEqual(run_ok(["model", "十", "--svg", "-"], self.tmp).stdout, (self.tmp / "m.svg").read_bytes())

    # --- the shell's ways of passing a file ---------------------------------------------------------------

    # Inputs are regular files (docs/metrics.md "Trace CSV": "Only regular files up to 256 MiB are read"; a FIFO
    # refused at once, never waited on): a pipe, /dev/stdin, `<(...)` and a FIFO are refused in one line naming
    # the path, and the same trace saved first is read.

    def assert_refused_as_not_regular(self, result, path):
        self.assert_one_error(result, 1, path, "not a regular file")

    def test_score_of_a_trace_through_a_pipe_is_refused_naming_it(self):
        r = sh('cat t.csv | "$C" score /dev/stdin --character 一 --json -', self.tmp)
        self.assert_refused_as_not_regular(r, "/dev/stdin")
        self.assertEqual(r.stdout, b"")

    def test_score_of_trace_by_process_substitution_is_refused_and_the_saved_csv_read(self):
        h5 = self.traces[0]
        r = sh(f'"$C" score <("$C" trace "{h5}" 2>/dev/null) --character 一 --json -', self.tmp)
        self.assert_refused_as_not_regular(r, "/dev/fd/")
        r = sh(f'"$C" trace "{h5}" > saved.csv && "$C" score saved.csv --character 一 --json -', self.tmp)
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assert_metrics_equal(json.loads(r.stdout), self.score(h5, "一"), "score of trace > saved.csv")

    def test_trace_into_a_fifo_is_written_and_score_of_a_fifo_refused(self):
        # `trace --csv FIFO` writes in place (a reader there); `score FIFO` refuses it at once.
        h5 = self.traces[0]
        r = sh(f'mkfifo ff && {{ "$C" trace "{h5}" --csv ff & }} && cat ff > got.csv; wait $!; s=$?; rm -f ff; '
               'exit $s', self.tmp)
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertEqual((self.tmp / "got.csv").read_bytes(), run_ok(["trace", h5], self.tmp).stdout)
        r = sh('mkfifo ff2 && "$C" score ff2 --character 一; s=$?; rm -f ff2; exit $s', self.tmp)
        self.assert_refused_as_not_regular(r, "ff2")

    def test_trial_record_through_a_pipe_is_refused_naming_it(self):
        r = sh('"$C" trial 一 --seed 3 --max-duration 4 --json - 2>/dev/null | "$C" trial --spec /dev/stdin --csv -',
               self.tmp)
        self.assert_refused_as_not_regular(r, "/dev/stdin")
        self.assertEqual(r.stdout, b"")
        r = sh('"$C" trial 一 --seed 3 --max-duration 4 --json - > piped.json && '
               '"$C" trial --spec piped.json --csv -', self.tmp)
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertEqual(r.stdout, (self.tmp / "t.csv").read_bytes())

    def test_dash_is_no_standard_input(self):
        # `-` is standard output for outputs only: as an option's value it is refused (a value starting with
        # `-`), as the trace `score` reads it is a file named `-`, here none.
        r = run(["trial", "--spec", "-"], self.tmp)
        self.assert_one_error(r, 2, "--spec", "'-'")
        with open(self.tmp / "t.csv", "rb") as trace:
            r = run(["score", "-", "--character", "一"], self.tmp, stdin=trace)
        self.assert_one_error(r, 1, "-: no such file", "standard input is not read")

    def test_protocol_by_process_substitution_is_refused_naming_it(self):
        # docs/cli.md "Protocols": a FIFO in the protocol's place is refused before it is read (exit 1).
        r = sh('"$C" session run <(cat p.json) --subject S09 --out piped ' + " ".join(LEARNING), self.tmp)
        self.assert_one_error(r, 1, "/dev/fd/")
        self.assertFalse((self.tmp / "piped").exists())
        r = sh('"$C" session plan <(cat p.json) --subjects 1 --json', self.tmp)
        self.assert_one_error(r, 1, "/dev/fd/")

    def test_find_exec_trace_into_the_session_leaves_report_and_resume_as_they_were(self):
        # Outputs written into the folder the next command reads: the CSV beside each HDF5 trace.
        study = self.tmp / "study2"
        shutil.copytree(self.tmp / "study", study, symlinks=True)
        r = sh('find study2 -name "*.trace.h5" -exec "$C" trace {} --csv {}.csv \\;', self.tmp)
        self.assertEqual(r.returncode, 0, r.stderr)
        csvs = sorted(study.rglob("*.trace.h5.csv"))
        self.assertEqual(len(csvs), 2)
        for c in csvs:
            self.assertEqual(c.read_bytes(), run_ok(["trace", str(c)[:-4]], self.tmp).stdout)
        (self.tmp / "tables2").mkdir()
        run_ok(["report", "study2", "--csv", "tables2"], self.tmp)
        for name in ("trials.csv", "strokes.csv"):
            self.assertEqual((self.tmp / "tables2" / name).read_text(encoding="utf-8").replace("study2/", "study/"),
                             (self.tmp / "tables" / name).read_text(encoding="utf-8"), name)
        session = next((study / "S01").iterdir())
        r = run_ok(["session", "resume", session], self.tmp)
        self.assertIn("saved already", r.stdout.decode() + r.stderr.decode())
        self.assertFalse(list(study.rglob("*.tmp-*")))

    # --- schemas hold the real files -------------------------------------------------------------------------

    def schema(self, what):
        return json.loads(run_ok(["schema", what], self.tmp).stdout)

    def test_schema_record_and_metrics_hold_real_records(self):
        record_schema, metrics_schema = self.schema("record"), self.schema("metrics")
        python = cg.simulate_trial("一", seed=3, max_duration_s=4, keep_trace=False).metrics
        for what, rec in [("trial --json", self.record), ("python", dict(python))] + \
                [(p.name, json.loads(p.read_text(encoding="utf-8"))) for p in self.records]:
            jsonschema.validate(rec["specification"], record_schema)
            jsonschema.validate(rec, metrics_schema)
        jsonschema.validate(self.score("t.csv", "一"), metrics_schema)

    def test_schema_session_holds_session_json_and_schema_protocol_the_protocol(self):
        manifest = json.loads((self.session / "session.json").read_text(encoding="utf-8"))
        jsonschema.validate(manifest, self.schema("session"))
        protocol_schema = self.schema("protocol")
        jsonschema.validate(PROTOCOL, protocol_schema)
        copies = [v for v in manifest.values() if isinstance(v, dict) and "conditions" in v]
        for copy in copies:
            jsonschema.validate(copy, protocol_schema)

    def test_session_plan_json_is_the_session_it_planned(self):
        plan = json.loads(run_ok(["session", "plan", "p.json", "--subjects", "1", "--json"], self.tmp).stdout)
        manifest = json.loads((self.session / "session.json").read_text(encoding="utf-8"))
        self.assertEqual(plan["format"], "calligraphy-session-plan")
        subject = plan["subjects"][0]
        self.assertEqual(subject["id"], "S01")
        session = subject["sessions"][0]
        self.assertEqual(session["trials"], len(manifest["plan"]))
        self.assertEqual(len(self.records), session["trials"])
        items = [i for ph in session["phases"] for i in ph["items"]]
        self.assertEqual(items, [p["characters"] for p in manifest["plan"]])
        shas = {json.loads(r.read_text(encoding="utf-8"))["protocol"]["sha256"] for r in self.records}
        self.assertEqual(shas, {plan["protocol_sha256"]})

    # --- tables -----------------------------------------------------------------------------------------------

    def test_report_trace_file_scored_is_its_row(self):
        # From another folder through a relative path: `trace_file` is the trace as reached from the DIR given.
        sub = self.tmp / "elsewhere"
        sub.mkdir(exist_ok=True)
        (sub / "t").mkdir(exist_ok=True)
        run_ok(["report", "../study", "--csv", "t"], sub)
        with open(sub / "t" / "trials.csv", newline="", encoding="utf-8") as f:
            rows = list(csv.DictReader(f))
        self.assertEqual(len(rows), 2)
        for row in rows:
            got = self.score(row["trace_file"], row["characters"], cwd=sub)
            for k in ("mean_deviation_m", "frechet_m", "dtw_m", "total_time_s", "order_errors"):
                self.assertIn(k, row)
                want = float(row[k]) if row[k] != "" else None
                self.assertTrue(close(None if got[k] is None else float(got[k]), want), (k, got[k], row[k]))

    def test_cohort_tables_are_report_tables_of_the_same_subject(self):
        # docs/cli.md "session cohort": the tables report --csv would write, but `session`, an empty `start_utc`
        # and no trace (`trace_file`, `trace_sha256` empty).
        (self.tmp / "cohort").mkdir()
        run_ok(["session", "cohort", "p.json", "--subjects", "1", "--csv", "cohort", "--jobs", "1", *LEARNING],
               self.tmp)
        for name in ("trials.csv", "strokes.csv"):
            with open(self.tmp / "cohort" / name, newline="", encoding="utf-8") as f:
                cohort = list(csv.DictReader(f))
            with open(self.tmp / "tables" / name, newline="", encoding="utf-8") as f:
                report = list(csv.DictReader(f))
            self.assertEqual(len(cohort), len(report), name)
            self.assertEqual(list(cohort[0]), list(report[0]), name)
            for a, b in zip(cohort, report):
                for k in ("start_utc", "trace_file", "trace_sha256"):
                    self.assertEqual(a.get(k, ""), "", (name, k))
                for k in b:
                    if k in ("session", "start_utc", "trace_file", "trace_sha256"):
                        continue
                    self.assertIn(k, a, f"{name}: {k}")
                    self.assertEqual(a[k], b[k], f"{name}: {k}")

    # --- lists fed one by one ---------------------------------------------------------------------------------

    def test_characters_fed_one_by_one_to_model_agree(self):
        # `characters --json`'s list through `xargs -n1` to `model --json`: one document each, in order, of the
        # character named, its strokes' typical strokes those the list gave.
        listed = json.loads(run_ok(["characters", "--strokes", "1", "--json"], self.tmp).stdout)
        (self.tmp / "one-stroke.txt").write_text("\n".join(c["character"] for c in listed["characters"]) + "\n",
                                               encoding="utf-8")
        r = sh('xargs -n1 "$C" model --json < one-stroke.txt', self.tmp)
        self.assertEqual(r.returncode, 0, r.stderr)
        text, models, at = r.stdout.decode("utf-8"), [], 0
        decoder = json.JSONDecoder()
        while text[at:].strip():
            at += len(text[at:]) - len(text[at:].lstrip())
            doc, at = decoder.raw_decode(text, at)
            models.append(doc)
        self.assertEqual(len(models), listed["count"])
        self.assertGreater(listed["count"], 1)
        for c, m in zip(listed["characters"], models):
            self.assertEqual(m["character"], c["character"])
            self.assertEqual(len(m["strokes"]), c["strokes"], c["character"])
            self.assertEqual([s["typical_id"] for s in m["strokes"]], c["typical_ids"], c["character"])
            self.assertEqual([s["acronym"] for s in m["strokes"]], c["typical_strokes"], c["character"])

    def test_characters_acronyms_are_the_strokes_tables(self):
        table = json.loads(run_ok(["strokes", "--json"], self.tmp).stdout)
        rows = table["strokes"] if isinstance(table, dict) else table
        acronym = {s["id"]: s["acronym"] for s in rows}
        listed = json.loads(run_ok(["characters", "--text", "一十永八", "--json"], self.tmp).stdout)
        self.assertEqual(listed["count"], 4)
        for c in listed["characters"]:
            self.assertEqual([acronym[i] for i in c["typical_ids"]], c["typical_strokes"], c["character"])

    def test_curriculum_proposal_fed_to_characters_and_trial(self):
        prop = json.loads(run_ok(["curriculum", "study", "--subject", "S01", "--from", "二三人八口", "--count", "2",
                                  "--json"], self.tmp).stdout)
        self.assertTrue(prop)
        chars = "".join(p["character"] for p in prop)
        listed = json.loads(run_ok(["characters", "--text", chars, "--json"], self.tmp).stdout)
        by = {c["character"]: c for c in listed["characters"]}
        for p in prop:
            self.assertLessEqual(set(p["new_strokes"]) | set(p["weak_strokes"]), set(by[p["character"]]["typical_ids"]))
        r = sh(f'printf "%s\\n" {" ".join(p["character"] for p in prop)} | '
               'xargs -n1 -I{} "$C" trial {} --max-duration 0.2 --check', self.tmp)
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertEqual(len(r.stdout.decode().strip().splitlines()), len(prop))

    def test_devices_listed_are_names_trial_takes(self):
        listed = json.loads(run_ok(["devices", "--json"], self.tmp).stdout)
        names = [d["name"] for d in listed["devices"]]
        self.assertIn("simulated", names)
        for d in listed["devices"]:
            writer = "simulated" if d["moved_by_simulated_hand"] else "person"
            r = run(["trial", "一", "--device", d["name"], "--writer", writer, "--check"], self.tmp)
            self.assertEqual(r.returncode, 0, (d["name"], r.stderr))

    # --- Python and the command line in one pipeline ---------------------------------------------------------

    def test_python_dataframe_csv_scored_by_the_command_is_its_metrics(self):
        r = cg.simulate_trial("十", seed=5, max_duration_s=6)
        path = self.tmp / "py.csv"
        r.to_dataframe().to_csv(path)      # pandas' own CSV, with its index column
        got = self.score(path, "十")
        py = cg.score(r.to_dataframe(), "十")
        self.assert_metrics_equal(got, py, "score of pandas' CSV against cg.score of the frame")
        for k in ("mean_deviation_m", "frechet_m", "order_errors", "strokes_accepted"):
            self.assertTrue(close(got[k], r.metrics[k], rel=1e-5, abs_=2e-7), (k, got[k], r.metrics[k]))

    def test_python_score_of_the_commands_csv_is_score_json(self):
        got = cg.score(str(self.tmp / "t.csv"), "一")
        self.assert_metrics_equal(dict(got), self.score("t.csv", "一"), "cg.score(t.csv)")
        self.assert_tree_close(dict(got)["per_character"], self.score("t.csv", "一")["per_character"], "cg.score")

    def test_study_samples_scored_by_python_is_score_of_the_trace(self):
        study = cg.study.load([str(self.tmp / "study")])
        trials = study.trials
        self.assertEqual(len(trials), 2)
        for i in range(len(trials)):
            row = trials.iloc[i]
            samples = study.samples(row)
            ch = row["characters"]
            h5 = next(p for p in self.traces if p.name.startswith(Path(row["trace_file"]).name[:3]))
            self.assert_metrics_equal(dict(cg.score(samples, ch)), self.score(h5, ch), f"samples of {h5.name}")

    def test_teachers_cross_between_python_and_the_command(self):
        # A teacher recorded by the command replayed by Python, and one recorded by Python replayed by the command.
        teacher = cg.TeacherRecording.load(str(self.tmp / "teach.json"))
        r = cg.simulate_trial("一", teacher=teacher, max_duration_s=4)
        self.assertEqual(r.metrics["end_reason"], "completed")
        cg.record_teacher(cg.simulate_trial("一", writer="skilled", max_duration_s=4), str(self.tmp / "pyteach.json"))
        run_ok(["trial", "一", "--guidance-mode", "replay", "--teacher", "pyteach.json", "--max-duration", "4",
                "--json", "replay.json"], self.tmp)
        rec = json.loads((self.tmp / "replay.json").read_text(encoding="utf-8"))
        self.assertEqual(rec["end_reason"], "completed")
        again = run(["trial", "--spec", "replay.json", "--json", "-"], self.tmp)
        self.assertEqual(again.returncode, 0, again.stderr)
        self.assertEqual(again.stdout, (self.tmp / "replay.json").read_bytes())

    def test_python_rerun_of_a_session_record_is_the_trace(self):
        rec = self.records[1]
        again = cg.rerun_trial(str(rec))
        rows = list(csv.DictReader(io.StringIO(run_ok(["trace", self.traces[1]], self.tmp).stdout.decode())))
        self.assertEqual(len(rows), len(again.time_s))
        for i in (0, len(rows) // 2, len(rows) - 1):
            self.assertAlmostEqual(float(rows[i]["x"]), float(again.position_m[i, 0]), delta=1e-7)
            self.assertAlmostEqual(float(rows[i]["t"]), float(again.time_s[i]), delta=1e-6)


if __name__ == "__main__":
    unittest.main()
