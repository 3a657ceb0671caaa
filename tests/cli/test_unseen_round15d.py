#!/usr/bin/env python3
"""Round 15D: the tables the program writes for analysis, as a lab that publishes reads them with R's base
`read.csv` and with pandas, held to the promises of tidy data (Wickham 2014: one row per observation, one column
per variable, one table per kind of observation) and to what docs/experiments.md ("Tidy tables"),
docs/learning-study.md, docs/metrics.md, docs/cli.md and docs/python.md name. Run by CTest as
`cli_unseen_round15d_tests`.

One tiny study in setUpClass: a between-subjects protocol of two sessions on 一 and 十 (pre-test, training in one
of two groups, post-test; a retention test a day later), `session run` of 3 simulated subjects, `report --csv`,
`session cohort --csv` of the same protocol and of one subject, `calligraphy.study.load` and
`calligraphy.cohort.simulate`, a study whose sessions saved no trial yet, a cohort whose protocol and conditions
are named `NA` and `null`, a crossover cohort (item sets, sequences, periods), a cohort writing a row of two
characters, and one saved trace through `calligraphy trace`. Every table is read once by one
`Rscript` process (skipped visibly without Rscript), the way docs/learning-study.md reads them, and by pandas.
Each case checks a documented promise: each table's key unique, every foreign key in its parent table and no
row missing against the records; every column documented and every documented column there, with its type,
its unit in its name and R-formula-safe; an absent value spelt one way that both readers read as missing;
numbers equal to the JSON records' as R and pandas parse them; R, pandas and `study.load` giving one frame.

CALLIGRAPHY_CLI names the program, PYTHONPATH its Python module, CALLIGRAPHY_SOURCE_DIR the sources (for the
docs). CALLIGRAPHY_SANITIZED=1 takes five cases.
"""
import csv
import json
import math
import os
import re
import shutil
import subprocess
import tempfile
import unittest
from pathlib import Path

from outsider import OneErrorLine, run, sanitized_subset

load_tests = sanitized_subset({"test_trials_key_is_unique_and_counts_the_records",
                               "test_every_trials_column_is_documented_and_present",
                               "test_absent_is_an_empty_field_only",
                               "test_numbers_round_trip_to_the_records",
                               "test_an_empty_study_is_refused_and_a_study_of_no_trial_is_header_only"})

SOURCE = Path(os.environ.get("CALLIGRAPHY_SOURCE_DIR", Path(__file__).resolve().parents[2]))
RSCRIPT = shutil.which("Rscript")
YI, SHI = "一", "十"
SUBJECTS = 3
PROTOCOL = {"name": "r15d",
            "conditions": [{"name": "unguided", "mode": "vision"}, {"name": "fixture", "mode": "haptic"}],
            "phases": [{"phase": "pre-test", "condition": "unguided", "characters": [YI, SHI]},
                       {"phase": "training", "conditions": ["unguided", "fixture"],
                        "assignment": "between-subjects", "characters": [YI, SHI], "repetitions": 1},
                       {"phase": "post-test", "condition": "unguided", "characters": [YI, SHI]},
                       {"phase": "retention", "condition": "unguided", "characters": [YI, SHI], "session": 2,
                        "delay_s": 86400}],
            "trial": {"max_duration_s": 3}}
# Labels of the documented alphabet [A-Za-z0-9_-] that R's read.csv and pandas' read_csv take for missing values.
ODD = {"name": "NA",
       "conditions": [{"name": "NA", "mode": "vision"}, {"name": "null", "mode": "haptic"}],
       "test": {"characters": [YI], "conditions": ["NA", "null"], "repetitions": 1},
       "trial": {"max_duration_s": 2}}
# A crossover of two sets (item_set, sequence, period and trained_condition filled) and a row of two characters.
CROSSOVER = {"name": "xo15d",
             "conditions": [{"name": "unguided", "mode": "vision"}, {"name": "amplify", "mode": "error-amplification"}],
             "item_sets": [{"name": "set1", "characters": [YI]}, {"name": "set2", "characters": [SHI]}],
             "phases": [{"phase": "pre-test", "condition": "unguided", "sets": ["set1", "set2"]},
                        {"phase": "training", "conditions": ["unguided", "amplify"], "assignment": "crossover",
                         "sets": ["set1", "set2"], "repetitions": 1},
                        {"phase": "post-test", "condition": "unguided", "sets": ["set1", "set2"]}],
             "trial": {"max_duration_s": 2}}
ROW = {"name": "row15d", "conditions": [{"name": "V", "mode": "vision"}],
       "test": {"characters": [YI + SHI], "conditions": ["V"], "repetitions": 1}, "trial": {"max_duration_s": 3}}
PHASES = {"practice", "test", "pre-test", "training", "post-test", "retention", "transfer"}
REFUSALS = {"too_short", "backwards", "wrong_place", "wrong_stroke", "wrong_order"}
# Columns that are text (labels, names, times as text); every other column is a number, a count or a flag.
TEXT = {"subject", "session", "protocol", "group", "phase", "condition", "mode", "characters", "item_set", "sequence",
        "trained_condition", "writer", "writer_profile", "writer_learning", "end_reason", "start_utc", "trace_file",
        "trace_sha256", "character_text", "refusal"}
# Dimensionless numbers that the docs name without a unit (legibility: shares of the characters).
DIMENSIONLESS = {"normalised_jerk", "shape_skill", "order_skill", "timing_skill", "subject_writing_speed_factor",
                 "subject_spatial_error_factor", "subject_error_rate_factor", "subject_motor_noise_factor",
                 "subject_fast_learning_per_trial", "subject_slow_learning_per_trial",
                 "subject_fast_retention_per_trial", "subject_slow_retention_per_trial", "period",
                 "legibility_top1", "legibility_top5"}
MISSING_SPELLINGS = {"nan", "NaN", "NAN", "-nan", "NA", "N/A", "n/a", "null", "NULL", "None", "-", "inf", "-inf",
                     "Inf", "#N/A", "<NA>"}
SHARED = {}

R_PROGRAM = r"""
args <- commandArgs(trailingOnly = TRUE)
out <- args[1]
jobs <- read.csv(args[2], header = FALSE, stringsAsFactors = FALSE, encoding = "UTF-8")
cell <- function(v) {
  if (is.logical(v)) return(ifelse(is.na(v), "\\N", ifelse(v, "TRUE", "FALSE")))
  if (is.integer(v)) return(ifelse(is.na(v), "\\N", as.character(v)))
  if (is.double(v)) return(ifelse(is.na(v), "\\N", sprintf("%.17g", v)))
  ifelse(is.na(v), "\\N", as.character(v))
}
for (i in seq_len(nrow(jobs))) {
  label <- jobs[i, 1]
  frame <- eval(parse(text = sprintf(jobs[i, 3], deparse(jobs[i, 2]))))
  lines <- c(paste(names(frame), collapse = "\t"),
             paste(vapply(frame, function(v) class(v)[1], ""), collapse = "\t"),
             paste(make.names(names(frame)) == names(frame), collapse = "\t"))
  if (nrow(frame) > 0) {
    cells <- vapply(frame, cell, character(nrow(frame)))
    if (is.null(dim(cells))) cells <- matrix(cells, nrow = 1)
    lines <- c(lines, apply(cells, 1, paste, collapse = "\t"))
  }
  con <- file(file.path(out, paste0(label, ".tsv")), open = "w", encoding = "UTF-8")
  writeLines(lines, con)
  close(con)
}
trials <- eval(parse(text = sprintf(jobs[1, 3], deparse(jobs[1, 2]))))
fit <- lm(mean_deviation_m ~ group + phase + total_time_s, data = trials)
writeLines(c(as.character(nobs(fit)), paste(names(coef(fit)), collapse = "\t")), file.path(out, "lm.txt"))
"""


def read_table(path):
    with open(path, encoding="utf-8", newline="") as f:
        return list(csv.reader(f))


def dict_rows(path):
    with open(path, encoding="utf-8", newline="") as f:
        return list(csv.DictReader(f))


def docs_r_read_arguments():
    """The arguments docs/learning-study.md and docs/experiments.md give R's read.csv after the file's name, in
    every example: the one reading the test uses is the first."""
    found = []
    for name in ("learning-study.md", "experiments.md"):
        text = (SOURCE / "docs" / name).read_text(encoding="utf-8")
        found += re.findall(r'read\.csv\("[a-z-]+/trials\.csv"(.*?)\)\s*(?:#.*)?$', text, re.M)
    assert found, "the docs read no trials.csv with read.csv"
    return found


def docs_pandas_read_arguments():
    """The keyword arguments docs/experiments.md ("Tidy tables") gives pandas' read_csv, or None."""
    section = tidy_section()
    found = re.search(r"read_csv\([^,()]+((?:,[^()]*(?:\([^()]*\))?)*)\)", section)
    return None if found is None else found.group(1)


def tidy_section():
    text = (SOURCE / "docs" / "experiments.md").read_text(encoding="utf-8")
    return text.split("## Tidy tables", 1)[1].split("\n## ", 1)[0]


def pandas_read(path):
    import pandas as pd
    arguments = docs_pandas_read_arguments()
    if arguments is None:
        return pd.read_csv(path)
    return eval(f"pd.read_csv(path{arguments})", {"pd": pd, "path": path})  # noqa: S307 - the docs' own code


def canonical(value):
    """One spelling per value across R's cells, pandas' and study.load's: None for missing (an empty text too,
    the docs' "" for none), ('b', bool), ('n', float) for every number, ('s', text)."""
    import numpy as np
    if value is None:
        return None
    if isinstance(value, (bool, np.bool_)):
        return ("b", bool(value))
    if isinstance(value, (int, float, np.integer, np.floating)):
        return None if math.isnan(float(value)) else ("n", float(value))
    if isinstance(value, str):
        return None if value == "" else ("s", value)
    try:
        import pandas as pd
        if pd.isna(value):
            return None
    except (TypeError, ValueError):
        pass
    return ("s", str(value))


def r_cell(text, klass):
    if text == "\\N":
        return None
    if klass == "logical":
        return ("b", text == "TRUE")
    if klass in ("integer", "numeric"):
        return ("n", float(text))
    return canonical(text)


class RTable:
    """A table as the R program wrote it back: names, classes, whether make.names kept each name, and rows."""

    def __init__(self, path):
        lines = path.read_text(encoding="utf-8").split("\n")
        if lines and lines[-1] == "":
            lines.pop()
        self.names = lines[0].split("\t")
        self.classes = dict(zip(self.names, lines[1].split("\t")))
        self.syntactic = dict(zip(self.names, (v == "TRUE" for v in lines[2].split("\t"))))
        self.rows = [dict(zip(self.names, line.split("\t"))) for line in lines[3:]]

    def column(self, name):
        return [r_cell(row[name], self.classes[name]) for row in self.rows]


def frame_column(frame, name):
    return [canonical(v) for v in frame[name].tolist()]


class Base(unittest.TestCase, OneErrorLine):

    @classmethod
    def setUpClass(cls):
        if "root" not in SHARED:
            SHARED["tmp"] = tempfile.TemporaryDirectory(prefix="r15d-")
            SHARED["root"] = Path(SHARED["tmp"].name)
            build(SHARED["root"])


def cli(args, cwd):
    result = run(args, cwd)
    assert result.returncode == 0, (args, result.stderr.decode("utf-8", "replace"))
    return result


def build(root):
    """The study, its tables, its cohorts and every reader's view of them, made once."""
    (root / "p.json").write_text(json.dumps(PROTOCOL, ensure_ascii=False), encoding="utf-8")
    (root / "odd.json").write_text(json.dumps(ODD), encoding="utf-8")
    (root / "xo.json").write_text(json.dumps(CROSSOVER, ensure_ascii=False), encoding="utf-8")
    (root / "row.json").write_text(json.dumps(ROW, ensure_ascii=False), encoding="utf-8")
    for folder in ("tables", "cohort", "one", "zero", "odd", "xo", "row", "empty", "empty-tables", "r"):
        (root / folder).mkdir()
    cli(["session", "run", "p.json", "--subjects", str(SUBJECTS), "--out", "st"], root)
    cli(["report", str(root / "st"), "--csv", "tables"], root)  # the path study.load is given below
    cli(["session", "cohort", "p.json", "--subjects", str(SUBJECTS), "--csv", "cohort", "--jobs", "1"], root)
    cli(["session", "cohort", "p.json", "--subjects", "1", "--csv", "one", "--jobs", "1"], root)
    cli(["session", "cohort", "odd.json", "--subjects", "2", "--csv", "odd", "--jobs", "1"], root)
    cli(["session", "cohort", "xo.json", "--subjects", "2", "--csv", "xo", "--jobs", "1"], root)
    cli(["session", "cohort", "row.json", "--subjects", "2", "--csv", "row", "--jobs", "1"], root)
    # A study whose one session saved no trial yet: its session folder with the plan and no record.
    first = sorted((root / "st" / "S01").iterdir())[0]
    stopped = root / "st0" / "S01" / first.name
    shutil.copytree(first, stopped)
    for record in (stopped / "trials").iterdir():
        record.unlink()
    shutil.copy(root / "st" / ".calligraphy-study.json", root / "st0" / ".calligraphy-study.json")
    SHARED["report_zero"] = run(["report", "st0", "--csv", "zero"], root)
    SHARED["report_empty"] = run(["report", "empty", "--csv", "empty-tables"], root)
    # One saved trace as `calligraphy trace` writes it.
    trace = sorted((root / "st").glob("S01/*/trials/002-*.trace.h5"))[0]
    SHARED["trace_h5"] = trace
    cli(["trace", str(trace), "--csv", "trace.csv"], root)

    records = {}
    for path in sorted((root / "st").glob("*/*/trials/*.json")):
        records[(path.parts[-4], path.parts[-3], int(path.name[:3]))] = json.loads(path.read_text(encoding="utf-8"))
    SHARED["records"] = records
    plans = {}
    for path in sorted((root / "st").glob("*/*/session.json")):
        plans[(path.parts[-3], path.parts[-2])] = json.loads(path.read_text(encoding="utf-8"))["plan"]
    SHARED["plans"] = plans

    tables = {"trials": root / "tables" / "trials.csv", "strokes": root / "tables" / "strokes.csv",
              "ctrials": root / "cohort" / "trials.csv", "cstrokes": root / "cohort" / "strokes.csv",
              "otrials": root / "one" / "trials.csv", "ostrokes": root / "one" / "strokes.csv",
              "ztrials": root / "zero" / "trials.csv", "zstrokes": root / "zero" / "strokes.csv",
              "xtrials": root / "odd" / "trials.csv", "xstrokes": root / "odd" / "strokes.csv",
              "ktrials": root / "xo" / "trials.csv", "kstrokes": root / "xo" / "strokes.csv",
              "wtrials": root / "row" / "trials.csv", "wstrokes": root / "row" / "strokes.csv",
              "trace": root / "trace.csv"}
    SHARED["tables"] = tables
    SHARED["r"] = None
    SHARED["r_arguments"] = docs_r_read_arguments()
    if RSCRIPT:
        arguments = SHARED["r_arguments"][0]
        jobs = root / "r" / "jobs.csv"
        with open(jobs, "w", encoding="utf-8", newline="") as f:
            writer = csv.writer(f)
            for label, path in tables.items():
                writer.writerow([label, str(path), "read.csv(%s" + arguments + ")"])
        (root / "r" / "read.R").write_text(R_PROGRAM, encoding="utf-8")
        result = subprocess.run([RSCRIPT, "--vanilla", str(root / "r" / "read.R"), str(root / "r"), str(jobs)],
                                capture_output=True, timeout=120)
        assert result.returncode == 0, result.stderr.decode("utf-8", "replace")
        SHARED["r"] = {label: RTable(root / "r" / f"{label}.tsv") for label in tables}
        SHARED["lm"] = (root / "r" / "lm.txt").read_text(encoding="utf-8").split("\n")

    try:
        import calligraphy
        import calligraphy.cohort
        import calligraphy.study
        import pandas
    except ImportError as error:  # a build without the Python module: its cases are skipped, saying so
        SHARED["no_python"] = f"no calligraphy module or pandas: {error}"
        return
    SHARED["pandas_version"] = pandas.__version__
    SHARED["study"] = calligraphy.study.load(str(root / "st"))
    SHARED["study0"] = calligraphy.study.load(str(root / "st0"))
    SHARED["simulated"] = calligraphy.cohort.simulate(str(root / "p.json"), SUBJECTS, workers=1, progress=False)
    SHARED["odd_simulated"] = calligraphy.cohort.simulate(str(root / "odd.json"), 2, workers=1, progress=False)
    SHARED["xo_simulated"] = calligraphy.cohort.simulate(str(root / "xo.json"), 2, workers=1, progress=False)
    SHARED["row_simulated"] = calligraphy.cohort.simulate(str(root / "row.json"), 2, workers=1, progress=False)
    SHARED["metric_table"] = calligraphy.metric_table()
    SHARED["pandas"] = {label: pandas_read(path) for label, path in tables.items() if label != "trace"}


class Tables(Base):

    def setUp(self):
        self.root = SHARED["root"]
        self.tables = SHARED["tables"]
        self.records = SHARED["records"]

    def python(self):
        """Skips the case, saying why, where the Python module or pandas is missing."""
        if "no_python" in SHARED:
            self.skipTest(SHARED["no_python"])

    def r(self, label):
        if SHARED["r"] is None:
            self.skipTest("Rscript is not installed: R's reading of the tables not checked")
        return SHARED["r"][label]

    # ---- keys: one row per observation, every row's parent there, no row missing ----------------------------

    def test_trials_key_is_unique_and_counts_the_records(self):
        rows = dict_rows(self.tables["trials"])
        keys = [(r["subject"], r["session"], int(r["trial"])) for r in rows]
        self.assertEqual(len(keys), len(set(keys)), "(subject, session, trial) repeats in trials.csv")
        self.assertEqual(set(keys), set(self.records), "trials.csv's rows against the saved records")
        self.assertEqual(len(rows), SUBJECTS * 8)

    def test_trial_numbers_are_every_planned_trial_of_each_session(self):
        rows = dict_rows(self.tables["trials"])
        for (subject, session), plan in SHARED["plans"].items():
            mine = sorted((r for r in rows if r["subject"] == subject and r["session"] == session),
                          key=lambda r: int(r["trial"]))
            self.assertEqual([int(r["trial"]) for r in mine], [entry["index"] for entry in plan], session)
            for row, entry in zip(mine, plan):
                self.assertEqual((row["phase"], int(row["block"]), int(row["item"]), int(row["repetition"]),
                                  row["condition"], row["characters"]),
                                 (entry["phase"], entry["block"], entry["item"], entry["repetition"],
                                  entry["condition"], entry["characters"]), entry["file"])
                self.assertTrue(row["trace_file"].endswith(entry["file"] + ".trace.h5"), row["trace_file"])

    def assert_strokes_belong(self, trials_path, strokes_path):
        trials = {(r["subject"], r["session"], int(r["trial"])): r for r in dict_rows(trials_path)}
        strokes = dict_rows(strokes_path)
        keys = [(r["subject"], r["session"], int(r["trial"]), int(r["character"]), int(r["stroke"]))
                for r in strokes]
        self.assertEqual(len(keys), len(set(keys)), f"{strokes_path}: its key repeats")
        orphans = {k[:3] for k in keys} - set(trials)
        self.assertEqual(orphans, set(), f"{strokes_path}: rows of no trial")
        for key, trial in trials.items():
            mine = [k for k in keys if k[:3] == key]
            self.assertEqual(len(mine), int(trial["strokes_total"]), f"{strokes_path}: strokes of {key}")
        for row in strokes:  # the labels a stroke repeats from its trial are its trial's
            trial = trials[(row["subject"], row["session"], int(row["trial"]))]
            self.assertEqual((row["phase"], row["condition"]), (trial["phase"], trial["condition"]))
            self.assertEqual(row["character_text"], trial["characters"][int(row["character"]) - 1])
        return strokes

    def test_strokes_key_unique_and_every_trial_has_its_strokes(self):
        self.assert_strokes_belong(self.tables["trials"], self.tables["strokes"])

    def test_cohort_keys_and_foreign_keys(self):
        self.assert_strokes_belong(self.tables["ctrials"], self.tables["cstrokes"])
        rows = dict_rows(self.tables["ctrials"])
        keys = [(r["subject"], r["session"], int(r["trial"])) for r in rows]
        self.assertEqual(len(keys), len(set(keys)))
        self.assertEqual(len(rows), len(dict_rows(self.tables["trials"])))
        self.assertEqual({r["session"] for r in rows},
                         {f"r15d-S{n:02d}-s{s}" for n in range(1, SUBJECTS + 1) for s in (1, 2)})

    # ---- columns: every one documented, typed, with its unit, usable in a formula -----------------------------

    def documented_trials_columns(self):
        section = tidy_section()
        table = section.split("`trials.csv`, one row per saved trial:", 1)[1].split("`strokes.csv`", 1)[0]
        names = set()
        for line in table.splitlines():
            if line.startswith("| `"):
                names |= set(re.findall(r"`([a-z_0-9]+)`", line.split(" | ")[0]))
        return names

    def test_every_trials_column_is_documented_and_present(self):
        header = read_table(self.tables["trials"])[0]
        documented = self.documented_trials_columns()
        self.assertEqual(sorted(set(header) - documented), [], "columns of trials.csv the docs' table lacks")
        self.assertEqual(sorted(documented - set(header)), [], "documented columns trials.csv lacks")
        self.assertEqual(len(header), len(set(header)))

    def test_every_strokes_column_is_documented_and_present(self):
        self.python()
        header = read_table(self.tables["strokes"])[0]
        paragraph = tidy_section().split("`strokes.csv`, one row per reference stroke", 1)[1].split("\n\n", 1)[0]
        documented = set(re.findall(r"`([a-z_0-9]+)`", paragraph)) - (REFUSALS - {"backwards"})
        # "the per-stroke deviations [m]": the metric table's stroke-level deviations.
        documented |= {m["name"] for m in SHARED["metric_table"] if m["strokes_column"] > 0 and m["unit"] == "m"}
        self.assertEqual(sorted(set(header) - documented), [], "columns of strokes.csv the docs do not name")
        self.assertEqual(sorted(documented - set(header)), [], "documented columns strokes.csv lacks")

    def test_metric_columns_follow_the_metric_table_in_order(self):
        self.python()
        table = SHARED["metric_table"]
        for path, key, first, last in ((self.tables["trials"], "trials_column", "completed_in_order",
                                        "normalised_jerk"),
                                       (self.tables["strokes"], "strokes_column", "mean_deviation_m",
                                        "assisted")):
            header = read_table(path)[0]
            placed = [m["name"] for m in sorted((m for m in table if m[key] > 0), key=lambda m: m[key])]
            self.assertEqual(header[header.index(first):header.index(last) + 1], placed, path.name)

    def test_units_are_in_the_column_names(self):
        self.python()
        units = {"m": "_m", "s": "_s", "N": "_n", "m/s": "_m_s"}
        for m in SHARED["metric_table"]:
            if m["unit"] in units:
                self.assertTrue(m["name"].endswith(units[m["unit"]]), m)
        study = SHARED["study"]
        for frame in (study.trials, study.strokes):
            for name in frame.columns:
                if str(frame[name].dtype) == "float64" and name not in DIMENSIONLESS:
                    self.assertRegex(name, r"_(m|s|n|m_s)$", f"{name}: a measure without its unit in its name")

    def test_names_are_r_syntactic_for_formulas(self):
        for label in ("trials", "strokes", "trace"):
            table = self.r(label)
            for name in table.names:
                self.assertTrue(table.syntactic[name], f"{label}: {name!r} needs backquotes in an R formula")
                self.assertRegex(name, r"^[a-z][a-z0-9_]*$")
        nobs, terms = SHARED["lm"][0], SHARED["lm"][1].split("\t")
        complete = [r for r in dict_rows(self.tables["trials"]) if r["mean_deviation_m"] and r["total_time_s"]]
        self.assertEqual(int(nobs), len(complete))
        self.assertEqual(terms[0], "(Intercept)")
        self.assertIn("total_time_s", terms)
        for term in terms[1:]:  # each term a column's name, or a factor's name and its level
            self.assertRegex(term, r"^(total_time_s|group(fixture|unguided)|phase(" + "|".join(PHASES) + "))$")

    def test_levels_are_the_documented_spellings_without_spaces(self):
        trials = dict_rows(self.tables["trials"]) + dict_rows(self.tables["ctrials"])
        for row in trials:
            self.assertIn(row["phase"], PHASES)
            self.assertIn(row["writer"], {"simulated", "person"})
            self.assertIn(row["writer_profile"], {"novice", "skilled", "foreign"})
            self.assertIn(row["writer_learning"], {"none", "two-state"})
            self.assertIn(row["group"], {"unguided", "fixture"})
            for name in ("subject", "session", "protocol", "condition", "mode", "end_reason"):
                self.assertRegex(row[name], r"^[A-Za-z0-9_-]+$", name)
        for row in dict_rows(self.tables["strokes"]):
            self.assertIn(row["refusal"], REFUSALS | {""})

    # ---- absent values: one spelling, missing to both readers ---------------------------------------------------

    def test_absent_is_an_empty_field_only(self):
        for label, path in self.tables.items():
            if label in ("trace", "xtrials", "xstrokes"):  # the odd cohort's labels are NA and null on purpose
                continue
            for number, row in enumerate(read_table(path)[1:], 2):
                spelt = set(row) & MISSING_SPELLINGS
                self.assertEqual(spelt, set(), f"{path}:{number}: an absent value spelt {spelt}")

    def test_r_and_pandas_read_every_empty_number_as_missing(self):
        self.python()
        for label in ("trials", "strokes", "ctrials", "cstrokes"):
            raw = dict_rows(self.tables[label])
            table, frame = self.r(label), SHARED["pandas"][label]
            for name in raw[0]:
                if name in TEXT:
                    continue
                empty = [row[name] == "" for row in raw]
                self.assertEqual([v is None for v in table.column(name)], empty, f"{label}.{name} in R")
                self.assertEqual([v is None for v in frame_column(frame, name)], empty, f"{label}.{name} in pandas")

    # ---- types ---------------------------------------------------------------------------------------------

    def kinds(self):
        """Each metric column's kind by the metric table, the other numbers' by the docs' tables."""
        kinds = {m["name"]: m["kind"] for m in SHARED["metric_table"]}
        kinds.update({name: "count" for name in ("session_number", "block", "trial", "item", "repetition",
                                                  "strokes_given_up",
                                                  "character", "stroke", "typical_id", "segments",
                                                  "refused_segments")})
        kinds.update({name: "number" for name in DIMENSIONLESS})
        return kinds

    def test_flags_read_as_logical_by_r_and_bool_by_pandas(self):
        self.python()
        for label, names in (("trials", ["completed_in_order"]), ("strokes", ["written", "backwards"]),
                             ("ctrials", ["completed_in_order"]), ("cstrokes", ["written", "backwards"])):
            for name in names:
                self.assertEqual(self.r(label).classes[name], "logical", f"{label}.{name} in R")
                self.assertEqual(str(SHARED["pandas"][label][name].dtype), "bool", f"{label}.{name} in pandas")

    def test_counts_are_integers_and_measures_doubles_in_every_reader(self):
        self.python()
        kinds = self.kinds()
        study = SHARED["study"]
        for label, frame in (("trials", study.trials), ("strokes", study.strokes)):
            table, pandas_frame = self.r(label), SHARED["pandas"][label]
            raw = dict_rows(self.tables[label])
            for name in table.names:
                kind = kinds.get(name)
                if kind is None or all(row[name] == "" for row in raw):
                    continue  # text, or a column with no value here (R cannot tell its type)
                # A number whose every value here is whole reads as R's integer and pandas' int64 (both
                # numeric): only study.load promises one dtype whatever the values.
                r_classes, pandas_kinds, dtype = {"count": ({"integer"}, "i", "int64"),
                                                  "flag": ({"logical"}, "b", "bool"),
                                                  "number": ({"numeric", "integer"}, "fi", "float64")}[kind]
                self.assertIn(table.classes[name], r_classes, f"{label}.{name} in R")
                self.assertEqual(str(frame[name].dtype), dtype, f"{label}.{name} in study.load")
                self.assertIn(pandas_frame[name].dtype.kind, pandas_kinds, f"{label}.{name} in pandas")

    def test_schema_metrics_types_are_the_tables_types(self):
        schema = json.loads(cli(["schema", "metrics"], self.root).stdout)
        table = self.r("trials")
        for name, spec in schema["properties"].items():
            if name not in table.names:
                continue
            types = spec["type"] if isinstance(spec["type"], list) else [spec["type"]]
            expected = {"integer": "integer", "boolean": "logical", "number": "numeric"}[
                [t for t in types if t != "null"][0]]
            self.assertEqual(table.classes[name], expected, f"{name}: schema {types}, R {table.classes[name]}")

    def test_an_empty_study_frames_have_the_types_of_a_full_one(self):
        self.python()
        full, empty = SHARED["study"], SHARED["study0"]
        for a, b in ((full.trials, empty.trials), (full.strokes, empty.strokes)):
            self.assertEqual(list(a.columns), list(b.columns))
            for name in a.columns:
                kind_a, kind_b = a[name].dtype.kind, b[name].dtype.kind
                if str(a[name].dtype) == "category":
                    kind_a, kind_b = str(a[name].dtype), str(b[name].dtype)
                self.assertEqual(kind_b, kind_a, f"{name}: {b[name].dtype} with no trial, {a[name].dtype} with some")

    # ---- values --------------------------------------------------------------------------------------------

    def test_numbers_round_trip_to_the_records(self):
        self.python()
        trials_r, strokes_r = self.r("trials"), self.r("strokes")
        trials_p, strokes_p = SHARED["pandas"]["trials"], SHARED["pandas"]["strokes"]
        numeric = [m["name"] for m in SHARED["metric_table"] if m["trials_column"] > 0 and m["kind"] != "flag"]
        for i, row in enumerate(trials_r.rows):
            record = self.records[(row["subject"], row["session"], int(row["trial"]))]
            for name in numeric:
                want = record.get(name)
                want = None if want is None else ("n", float(want))
                self.assertEqual(r_cell(row[name], trials_r.classes[name]), want, f"R trials {i} {name}")
                self.assertEqual(canonical(trials_p[name].iloc[i]), want, f"pandas trials {i} {name}")
        stroke_metrics = [m for m in SHARED["metric_table"] if m["strokes_column"] > 0]
        for i, row in enumerate(strokes_r.rows):
            record = self.records[(row["subject"], row["session"], int(row["trial"]))]
            stroke = record["per_character"][int(row["character"]) - 1]["per_stroke"][int(row["stroke"]) - 1]
            self.assertEqual(stroke["index"], int(row["stroke"]) - 1)
            for metric in stroke_metrics:
                name = metric["name"]
                want = stroke.get(name)  # a flag (a stroke's assisted credit) is a logical, every other a number
                want = None if want is None else ("b", bool(want)) if metric["kind"] == "flag" else ("n", float(want))
                self.assertEqual(r_cell(row[name], strokes_r.classes[name]), want, f"R strokes {i} {name}")
                self.assertEqual(canonical(strokes_p[name].iloc[i]), want, f"pandas strokes {i} {name}")

    def assert_one_frame(self, label, r_table, pandas_frame, study_frame, skip=()):
        self.assertEqual(list(study_frame.columns), r_table.names, label)
        self.assertEqual(list(pandas_frame.columns), r_table.names, label)
        self.assertEqual(len(study_frame), len(r_table.rows), label)
        self.assertEqual(len(pandas_frame), len(r_table.rows), label)
        for name in r_table.names:
            if name in skip:
                continue
            want = frame_column(study_frame, name)
            self.assertEqual(r_table.column(name), want, f"{label}.{name}: R against study.load")
            self.assertEqual(frame_column(pandas_frame, name), want, f"{label}.{name}: pandas against study.load")

    def test_r_pandas_and_study_load_give_one_frame(self):
        self.python()
        study = SHARED["study"]
        self.assert_one_frame("trials", self.r("trials"), SHARED["pandas"]["trials"], study.trials)
        self.assert_one_frame("strokes", self.r("strokes"), SHARED["pandas"]["strokes"], study.strokes)

    def test_cohort_simulate_is_the_cohort_tables_as_r_and_pandas_read_them(self):
        self.python()
        simulated = SHARED["simulated"]
        self.assert_one_frame("cohort trials", self.r("ctrials"), SHARED["pandas"]["ctrials"], simulated.trials)
        self.assert_one_frame("cohort strokes", self.r("cstrokes"), SHARED["pandas"]["cstrokes"],
                              simulated.strokes)

    def test_labels_that_readers_take_for_missing_keep_their_spelling(self):
        self.python()
        odd = SHARED["odd_simulated"]
        self.assertEqual(sorted(set(map(str, odd.trials["condition"]))), ["NA", "null"])
        self.assertEqual(set(map(str, odd.trials["protocol"])), {"NA"})
        self.assert_one_frame("odd trials", self.r("xtrials"), SHARED["pandas"]["xtrials"], odd.trials)
        self.assert_one_frame("odd strokes", self.r("xstrokes"), SHARED["pandas"]["xstrokes"], odd.strokes)

    def test_a_crossover_labels_read_alike(self):
        self.python()
        xo = SHARED["xo_simulated"]
        self.assert_one_frame("crossover trials", self.r("ktrials"), SHARED["pandas"]["ktrials"], xo.trials)
        self.assert_strokes_belong(self.tables["ktrials"], self.tables["kstrokes"])
        table = self.r("ktrials")
        self.assertEqual(table.classes["period"], "integer")  # 1-based periods, every row filled here
        self.assertEqual(str(xo.trials["period"].dtype), "float64")  # documented: a float in Python
        for name in ("item_set", "sequence", "trained_condition"):
            self.assertEqual(table.classes[name], "character", name)
        self.assertEqual({row["sequence"] for row in table.rows}, {"AB", "BA"})
        self.assertEqual({row["item_set"] for row in table.rows}, {"set1", "set2"})
        self.assertEqual({row["trained_condition"] for row in table.rows}, {"unguided", "amplify"})

    def test_a_row_of_two_characters_numbers_its_characters_and_shares(self):
        self.python()
        row = SHARED["row_simulated"]
        strokes = self.assert_strokes_belong(self.tables["wtrials"], self.tables["wstrokes"])
        self.assertEqual(sorted({(int(r["character"]), r["character_text"]) for r in strokes}), [(1, YI), (2, SHI)])
        self.assert_one_frame("row trials", self.r("wtrials"), SHARED["pandas"]["wtrials"], row.trials)
        self.assert_one_frame("row strokes", self.r("wstrokes"), SHARED["pandas"]["wstrokes"], row.strokes)
        for name in ("legibility_top1", "legibility_top5"):  # shares of the row's two characters
            self.assertEqual(str(row.trials[name].dtype), "float64", name)
            for value in row.trials[name]:
                self.assertIn(value, (0.0, 0.5, 1.0), name)
            self.assertIn(self.r("wtrials").classes[name], ("numeric", "integer"), name)

    def test_one_reading_in_every_example_of_the_docs(self):
        self.assertEqual(len(set(SHARED["r_arguments"])), 1, SHARED["r_arguments"])
        self.assertIsNotNone(docs_pandas_read_arguments(),
                             "docs/experiments.md (\"Tidy tables\") gives no pandas reading of the tables")

    def test_stroke_numbering_and_time_units_agree_with_the_records(self):
        for row in dict_rows(self.tables["trials"]):
            record = self.records[(row["subject"], row["session"], int(row["trial"]))]
            self.assertEqual(int(row["trial"]), record["trial"]["index"])
            self.assertEqual(row["start_utc"], record["start_time_utc"])
            self.assertRegex(row["start_utc"], r"^\d{4}-\d\d-\d\dT\d\d:\d\d:\d\d\.\d{3}Z$")
            self.assertEqual(float(row["total_time_s"]), record["total_time_s"])
        for row in dict_rows(self.tables["strokes"]):
            record = self.records[(row["subject"], row["session"], int(row["trial"]))]
            stroke = record["per_character"][int(row["character"]) - 1]["per_stroke"][int(row["stroke"]) - 1]
            self.assertEqual(int(row["typical_id"]), stroke["typical_id"])
            if row["time_s"]:
                self.assertEqual(float(row["time_s"]), stroke["time_s"])
                trial = [t for t in dict_rows(self.tables["trials"])
                         if (t["subject"], t["session"], t["trial"]) == (row["subject"], row["session"],
                                                                         row["trial"])][0]
                self.assertLessEqual(float(row["time_s"]), float(trial["pen_down_time_s"]))

    def test_trace_table_read_by_r_and_pandas_is_the_study_samples(self):
        self.python()
        table = self.r("trace")
        self.assertEqual(table.names, ["t", "x", "y", "z", "fx", "fy", "fz", "state", "stroke", "element",
                                       "attempt", "rewritten"])
        for name in ("t", "x", "y", "z", "fx", "fy", "fz"):
            self.assertEqual(table.classes[name], "numeric", name)
        for name in ("stroke", "element", "attempt", "rewritten"):
            self.assertEqual(table.classes[name], "integer", name)
        study = SHARED["study"]
        trials = study.trials
        row = trials[trials.trace_file.str.endswith(SHARED["trace_h5"].name)
                     & (trials.subject == "S01")].iloc[0]
        samples = study.samples(row)
        self.assertEqual(len(samples), len(table.rows))
        digits = {"t": 6, "x": 7, "y": 7, "z": 7, "fx": 4, "fy": 4, "fz": 4}
        for short, name in (("t", "t_s"), ("x", "x_m"), ("y", "y_m"), ("z", "z_m"), ("fx", "fx_n"),
                            ("fy", "fy_n"), ("fz", "fz_n")):
            got = [v[1] for v in table.column(short)]
            want = [round(float(v), digits[short]) for v in samples[name]]
            self.assertEqual(got, want, short)
        self.assertEqual([v[1] for v in table.column("stroke")], [float(v) for v in samples["stroke"]])
        self.assertEqual({v[1] for v in table.column("state")}, set(map(str, samples["state"])))
        self.assertLessEqual({v[1] for v in table.column("state")}, {"SS", "AS", "CS", "WS"})

    # ---- shapes: a cohort's tables, one subject, no trial, no session ---------------------------------------

    def test_cohort_and_session_tables_have_the_same_columns_and_classes(self):
        for a, b in (("trials", "ctrials"), ("strokes", "cstrokes")):
            self.assertEqual(read_table(self.tables[a])[0], read_table(self.tables[b])[0])
            ra, rb = self.r(a), self.r(b)
            for name in ra.names:
                if name in ("start_utc", "trace_file", "trace_sha256"):  # empty in a cohort (documented)
                    continue
                self.assertEqual(rb.classes[name], ra.classes[name], f"{b}.{name}")
        cohort = dict_rows(self.tables["ctrials"])
        self.assertEqual({(r["start_utc"], r["trace_file"], r["trace_sha256"]) for r in cohort}, {("", "", "")})

    def test_one_subject_tables_read_with_the_same_columns_and_classes(self):
        for a, b in (("ctrials", "otrials"), ("cstrokes", "ostrokes")):
            ra, rb = self.r(a), self.r(b)
            self.assertEqual(rb.names, ra.names)
            self.assertEqual(rb.classes, ra.classes, b)
        one = dict_rows(self.tables["otrials"])
        self.assertEqual({r["subject"] for r in one}, {"S01"})
        self.assertEqual(len(one), 8)

    def test_an_empty_study_is_refused_and_a_study_of_no_trial_is_header_only(self):
        self.assert_one_error(SHARED["report_empty"], 1, "empty", "no session folder")
        self.assertEqual(list((self.root / "empty-tables").iterdir()), [])
        self.assertEqual(SHARED["report_zero"].returncode, 0, SHARED["report_zero"].stderr)
        for zero, full in (("ztrials", "trials"), ("zstrokes", "strokes")):
            rows = read_table(self.tables[zero])
            self.assertEqual(rows, [read_table(self.tables[full])[0]], zero)
            if SHARED["r"] is not None:
                self.assertEqual(self.r(zero).names, self.r(full).names)
                self.assertEqual(self.r(zero).rows, [])
        self.python()
        for zero in ("ztrials", "zstrokes"):
            self.assertEqual(len(SHARED["pandas"][zero]), 0)
        study0 = SHARED["study0"]
        self.assertEqual((len(study0.trials), len(study0.strokes)), (0, 0))
        self.assertEqual(list(study0.trials.columns), read_table(self.tables["trials"])[0])


if __name__ == "__main__":
    unittest.main(verbosity=2)
