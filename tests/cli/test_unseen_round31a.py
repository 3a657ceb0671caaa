#!/usr/bin/env python3
"""Round 31A: a lab's analysis in Python, fed what a lab really has. From the docs alone (docs/python.md
"Tables and figures", "Statistics", "The design's questions", "A study's traces", "A report for a paper",
"Errors"; docs/experiments.md "Tidy tables", "A cohort in memory", "A report for a paper"; docs/metrics.md "The
one metrics record"; the docstrings of calligraphy.study, statistics, design_analysis, study_report, cohort).

A small study is made three ways: `calligraphy session cohort --csv` (a three-group between-subjects protocol of
十, 6 subjects) read back with the docs' pandas recipe, `calligraphy.cohort.simulate` of the same protocol, and
`calligraphy session run` of a two-condition within-subjects protocol (2 subjects) read by `study.load` and by
`calligraphy report --csv`. The conditions are named as readers misread names ("NA", "007", "TRUE"; the protocol
"nan"). The tables are then changed as a lab changes them (columns renamed, a text where a number goes, NaN and
inf, a missing subject or condition, rows shuffled, a subject with one trial, a group with one subject, every
trial excluded, an empty table, outcomes near 1e300 and 1e-300, `convert_dtypes()`, two tables concatenated with
their index labels twice, a row of a re-indexed selection) and given to the functions, whose numbers are held to what
this file computes itself (subject means, paired and Welch t, Hedges' g, learning gains, the ANCOVA by least
squares, Holm's adjustment, the retention ratio) or to the documented exception naming the column or argument; the
report (titled with markup) must write its documented files and nothing else. R is made missing
the way the docs name (no `Rscript` on PATH), so no R fit runs: the mixed models' rows must say so.

CALLIGRAPHY_CLI names the program; PYTHONPATH the built Python package. CALLIGRAPHY_SANITIZED=1 takes five cases.
"""
import io
import json
import math
import os
import re
import shutil
import subprocess
import sys
import tempfile
import unittest
import warnings
from pathlib import Path

from outsider import ENV, run_ok, sanitized_subset

try:
    import numpy as np
    import pandas
    from scipy import stats as sps
    import calligraphy as cg
    import calligraphy.cohort
    import calligraphy.study
    from calligraphy import design_analysis, statistics, study_report
except ImportError:  # reported by setUpModule
    np = cg = None

load_tests = sanitized_subset({"test_describe_counts_inf_as_missing_with_a_warning_naming_column_and_count",
                               "test_paired_comparison_equals_the_t_on_subject_means_whatever_the_row_order",
                               "test_learning_gain_relative_gain_and_retention_ratio_are_the_documented_ones",
                               "test_load_refuses_empty_nul_and_non_paths",
                               "test_apa_sentence_is_the_documented_text"})

LABELS = ["subject", "protocol", "group", "condition", "characters", "item_set", "trained_condition",
          "trace_sha256"]
# A lab's names that readers take for a missing value, a number or a logical (docs/experiments.md, "Tidy
# tables"): the control (vision) "NA", the fixture "007", fading guidance "TRUE"; the protocol "nan".
CONTROL, FIXTURE, FADING = "NA", "007", "TRUE"
GROUPS = [CONTROL, FIXTURE, FADING]
PAIRS = {f"{FIXTURE} - {CONTROL}", f"{FADING} - {CONTROL}", f"{FADING} - {FIXTURE}"}
BETWEEN = {
    "name": "nan",
    "conditions": [{"name": CONTROL, "mode": "vision"}, {"name": FIXTURE, "mode": "haptic"},
                   {"name": FADING, "mode": "fading"}],
    "phases": [
        {"phase": "pre-test", "condition": CONTROL, "characters": ["十"]},
        {"phase": "training", "conditions": GROUPS, "assignment": "between-subjects", "characters": ["十"]},
        {"phase": "post-test", "condition": CONTROL, "characters": ["十"]}],
    "trial": {"max_duration_s": 30}}
WITHIN = {
    "name": "within31",
    "conditions": [{"name": "vision", "mode": "vision"}, {"name": "haptic", "mode": "haptic"}],
    "test": {"characters": ["十"], "conditions": ["vision", "haptic"], "repetitions": 1},
    "order": {"conditions": "latin_square"}, "trial": {"max_duration_s": 30}}
SUBJECTS = 6
TITLE = '<script>alert("x")</script> & 十 <img src="http://example.org/x.png">'
SAVED_PATH = None
TMP = None


def setUpModule():
    """No Rscript on PATH for the whole file (the documented way to have no R): no R fit ever runs here."""
    global SAVED_PATH, TMP
    if cg is None:
        raise unittest.SkipTest("numpy, pandas, scipy and the calligraphy Python package (PYTHONPATH) are needed")
    TMP = Path(tempfile.mkdtemp(prefix="round31a-"))
    (TMP / "no-r").mkdir()
    SAVED_PATH = os.environ.get("PATH")
    os.environ["PATH"] = str(TMP / "no-r")


def tearDownModule():
    if SAVED_PATH is not None:
        os.environ["PATH"] = SAVED_PATH
    if TMP is not None:
        shutil.rmtree(TMP, ignore_errors=True)


_COHORT = {}


def cohort():
    """`calligraphy.cohort.simulate` of the between-subjects protocol (made once for the file) and its path."""
    if not _COHORT:
        protocol = TMP / "between.json"
        protocol.write_text(json.dumps(BETWEEN, ensure_ascii=False), encoding="utf-8")
        _COHORT["protocol"] = protocol
        _COHORT["study"] = calligraphy.cohort.simulate(str(protocol), SUBJECTS, workers=1, progress=False)
    return _COHORT["study"], _COHORT["protocol"]


def read_tables_csv(path):
    """The docs' recipe (docs/experiments.md, "Tidy tables")."""
    return pandas.read_csv(path, keep_default_na=False, na_values=[""], float_precision="round_trip",
                           dtype=dict.fromkeys(LABELS, str))


def holm(p):
    """Holm's (1979) step-down adjusted p values, in the given order."""
    p = np.asarray(p, dtype=float)
    order = np.argsort(p)
    m = len(p)
    adjusted = np.empty(m)
    running = 0.0
    for rank, i in enumerate(order):
        running = max(running, min(1.0, (m - rank) * p[i]))
        adjusted[i] = running
    return adjusted


def within_table(seed=7):
    """A within-subjects table of trials: S1..S4 write 十 and 二 twice under haptic and vision; S5 wrote one
    vision trial only. Values in metres."""
    rng = np.random.default_rng(seed)
    rows = []
    for s in range(1, 5):
        for condition, shift in (("haptic", 0.0), ("vision", 0.0004)):
            for characters in ("十", "二"):
                for repetition in (1, 2):
                    rows.append({"subject": f"S{s}", "session": f"w-S{s}", "phase": "test", "condition": condition,
                                 "characters": characters, "repetition": repetition,
                                 "mean_deviation_m": 0.0006 + shift + rng.normal(0, 0.0002) + 0.0001 * s,
                                 "total_time_s": 8.0 + rng.normal(0, 1.0)})
    rows.append({"subject": "S5", "session": "w-S5", "phase": "test", "condition": "vision", "characters": "十",
                 "repetition": 1, "mean_deviation_m": 0.0011, "total_time_s": 9.0})
    return pandas.DataFrame(rows)


class TidyTablesOfACohort(unittest.TestCase):
    """`session cohort --csv` read by the docs' recipe beside `calligraphy.cohort.simulate` of the same protocol."""

    @classmethod
    def setUpClass(cls):
        cls.tmp = Path(tempfile.mkdtemp(prefix="cohort-", dir=TMP))
        cls.study, cls.protocol = cohort()
        (cls.tmp / "csv").mkdir()
        run_ok(["session", "cohort", cls.protocol, "--subjects", SUBJECTS, "--csv", "csv", "--jobs", 1], cls.tmp)
        cls.csv_trials = read_tables_csv(cls.tmp / "csv" / "trials.csv")
        cls.csv_strokes = pandas.read_csv(cls.tmp / "csv" / "strokes.csv", keep_default_na=False, na_values=[""],
                                          float_precision="round_trip",
                                          dtype=dict.fromkeys(["subject", "condition", "character_text"], str))

    def keyed(self, frame):
        frame = frame.copy()
        for column in ("subject", "phase", "condition", "group", "characters"):
            frame[column] = frame[column].astype(str)
        return frame.sort_values(["subject", "session_number", "trial"]).reset_index(drop=True)

    def test_cohort_csv_read_by_the_docs_recipe_equals_simulate_value_for_value(self):
        csv, memory = self.keyed(self.csv_trials), self.keyed(self.study.trials)
        self.assertEqual(len(csv), SUBJECTS * 3)
        for column in ("subject", "phase", "condition", "group", "characters", "repetition", "end_reason"):
            self.assertEqual(list(csv[column].astype(str)), list(memory[column].astype(str)), column)
        # 17 significant digits read back as the record's double: equal bit for bit.
        for column in ("mean_deviation_m", "frechet_m", "total_time_s", "pen_down_time_s", "normalised_jerk"):
            np.testing.assert_array_equal(csv[column].to_numpy(float), memory[column].to_numpy(float), column)
        # Flags logical, counts integers.
        self.assertEqual(csv["completed_in_order"].dtype, bool)
        self.assertTrue(pandas.api.types.is_integer_dtype(csv["strokes_written"].dtype))

    def test_completed_in_order_is_every_stroke_written_and_no_order_error(self):
        for trials, strokes in ((self.csv_trials, self.csv_strokes), (self.study.trials, self.study.strokes)):
            expected = (trials["strokes_written"] == trials["strokes_total"]) & (trials["order_errors"] == 0)
            self.assertEqual(list(trials["completed_in_order"].astype(bool)), list(expected))
            per_trial = strokes.assign(written=strokes["written"].astype(bool)).groupby(
                [strokes["subject"].astype(str), strokes["session"].astype(str), strokes["trial"]])["written"]
            counts = per_trial.size()
            written = per_trial.sum()
            for _, row in trials.iterrows():
                key = (str(row["subject"]), str(row["session"]), row["trial"])
                self.assertEqual(counts[key], row["strokes_total"], key)
                self.assertEqual(written[key], row["strokes_written"], key)

    def test_design_read_from_csv_text_in_any_row_order_is_protocol_order_with_vision_control(self):
        shuffled = self.csv_trials.sample(frac=1.0, random_state=3).reset_index(drop=True)
        design = design_analysis.study_design(shuffled)
        self.assertEqual(design.kind, "between-subjects")
        self.assertEqual(tuple(design.phases), ("pre-test", "training", "post-test"))
        self.assertEqual(design.control, CONTROL)
        self.assertEqual(design.conditions[0], CONTROL)
        self.assertEqual(set(design.conditions), set(GROUPS))
        self.assertEqual(dict(design.n_per_condition), {g: SUBJECTS // 3 for g in GROUPS})
        self.assertEqual(design.compared_phase, "training")
        self.assertEqual(design.pre_test, "pre-test")
        self.assertEqual(tuple(design.after_training), ("post-test",))
        self.assertEqual(design, design_analysis.study_design(self.study.trials))

    def test_cohort_trial_has_no_trace_and_says_so(self):
        with self.assertRaises(cg.DataError):
            self.study.samples(self.study.trials.index[0])


class Statistics(unittest.TestCase):
    """calligraphy.statistics on tables made here, changed as a lab changes them."""

    def test_describe_by_subject_counts_subjects_and_averages_their_means(self):
        trials = within_table()
        trials = trials.drop(index=[0, 1, 2]).sample(frac=1.0, random_state=1)   # S1 has fewer haptic trials
        got = statistics.describe(trials, "mean_deviation_m", by="condition", unit="subject")
        self.assertEqual(list(got["condition"].astype(str)), ["haptic", "vision"])
        for _, row in got.iterrows():
            part = trials[trials["condition"] == row["condition"]]
            means = part.groupby("subject")["mean_deviation_m"].mean().to_numpy()
            n = len(means)
            self.assertEqual(row["n"], n)
            self.assertEqual(row["unit"], "subject")
            self.assertAlmostEqual(row["mean"], means.mean(), delta=1e-15)
            sd = means.std(ddof=1)
            self.assertAlmostEqual(row["sd"], sd, delta=1e-15)
            half = sps.t.ppf(0.975, n - 1) * sd / math.sqrt(n)
            self.assertAlmostEqual(row["ci95_low"], means.mean() - half, delta=1e-13)
            self.assertAlmostEqual(row["ci95_high"], means.mean() + half, delta=1e-13)

    def test_describe_counts_inf_as_missing_with_a_warning_naming_column_and_count(self):
        trials = within_table()
        trials.loc[[0, 5], "mean_deviation_m"] = [math.inf, -math.inf]
        trials.loc[9, "mean_deviation_m"] = math.nan
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            got = statistics.describe(trials, "mean_deviation_m", by=())
        said = [w for w in caught if issubclass(w.category, statistics.NonFiniteValueWarning)]
        self.assertTrue(said, [str(w.message) for w in caught])
        self.assertIn("mean_deviation_m", str(said[0].message))
        self.assertIn("2", str(said[0].message))
        self.assertEqual(len(got), 1)
        self.assertEqual(got["n_missing"].iloc[0], 3)
        self.assertEqual(got["n"].iloc[0], len(trials) - 3)
        finite = trials["mean_deviation_m"][np.isfinite(trials["mean_deviation_m"])]
        self.assertAlmostEqual(got["mean"].iloc[0], finite.mean(), delta=1e-15)
        self.assertTrue(np.isfinite(got["sd"].iloc[0]))

    def test_describe_of_values_near_1e300_and_1e_minus_300_gives_their_sd(self):
        for scale in (1e300, 1e-300):
            trials = pandas.DataFrame({"phase": ["test"] * 3, "condition": ["a"] * 3,
                                       "subject": ["S1", "S2", "S3"], "v": [1 * scale, 2 * scale, 3 * scale]})
            got = statistics.describe(trials, "v", by=("phase", "condition"))
            self.assertEqual(got["n"].iloc[0], 3)
            self.assertTrue(math.isclose(got["mean"].iloc[0], 2 * scale, rel_tol=1e-12), got["mean"].iloc[0])
            # The sample sd of (1, 2, 3) is 1: that many times the scale, neither 0 nor infinite.
            self.assertTrue(math.isclose(got["sd"].iloc[0], scale, rel_tol=1e-12), (scale, got["sd"].iloc[0]))
            half = sps.t.ppf(0.975, 2) / math.sqrt(3)
            self.assertTrue(math.isclose(got["ci95_high"].iloc[0], (2 + half) * scale, rel_tol=1e-9))

    def test_describe_of_a_filtered_categorical_table_has_rows_only_for_groups_with_trials(self):
        trials = within_table()
        trials["phase"] = pandas.Categorical(trials["phase"], categories=["pre-test", "test", "retention"],
                                             ordered=True)
        trials["condition"] = pandas.Categorical(trials["condition"], categories=["vision", "haptic", "quiz"])
        test = trials[trials["condition"] == "haptic"]          # as a lab filters study.trials
        got = statistics.describe(test, "total_time_s", by=("phase", "condition"))
        self.assertEqual(len(got), 1, got.to_string())
        self.assertEqual(got["n"].iloc[0], len(test))

    def test_outcome_holding_a_text_is_a_type_error_naming_the_column(self):
        trials = within_table()
        trials["mean_deviation_m"] = trials["mean_deviation_m"].astype(object)
        trials.loc[4, "mean_deviation_m"] = "n/a"
        for call in (lambda: statistics.describe(trials, "mean_deviation_m"),
                     lambda: statistics.paired_comparison(trials, "mean_deviation_m", "haptic", "vision"),
                     lambda: statistics.learning(trials.assign(phase=["pre"] * 20 + ["post"] * 13),
                                                 "mean_deviation_m", "pre", "post")):
            with self.assertRaises(TypeError) as caught:
                call()
            self.assertIn("mean_deviation_m", str(caught.exception))

    def test_renamed_columns_are_value_errors_naming_the_missing_column(self):
        trials = within_table()
        with self.assertRaises(ValueError) as caught:
            statistics.paired_comparison(trials.rename(columns={"subject": "participant"}), "mean_deviation_m",
                                         "haptic", "vision")
        self.assertIn("subject", str(caught.exception))
        with self.assertRaises(ValueError) as caught:
            statistics.describe(trials.rename(columns={"mean_deviation_m": "mean_dev_mm"}), "mean_deviation_m")
        self.assertIn("mean_deviation_m", str(caught.exception))
        with self.assertRaises(ValueError) as caught:
            statistics.learning(trials.rename(columns={"phase": "Phase"}), "total_time_s", "test", "test2")
        self.assertIn("phase", str(caught.exception))

    def test_row_with_a_missing_subject_is_named_with_count_and_first_row(self):
        trials = within_table()
        trials.index = trials.index + 700
        trials["subject"] = trials["subject"].astype(object)
        trials.loc[[703, 711], "subject"] = [None, math.nan]
        with self.assertRaises(ValueError) as caught:
            statistics.paired_comparison(trials, "mean_deviation_m", "haptic", "vision")
        message = str(caught.exception)
        self.assertIn("subject", message)
        self.assertIn("2", message)
        self.assertIn("703", message)

    def test_paired_comparison_equals_the_t_on_subject_means_whatever_the_row_order(self):
        trials = within_table()
        trials.loc[3, "mean_deviation_m"] = math.nan           # a trial that wrote nothing
        got = statistics.paired_comparison(trials, "mean_deviation_m", "haptic", "vision", phase="test")
        shuffled = statistics.paired_comparison(trials.sample(frac=1.0, random_state=5), "mean_deviation_m",
                                                "haptic", "vision", phase="test")
        means = trials.groupby(["subject", "condition"])["mean_deviation_m"].mean().unstack()
        both = means.dropna()
        a, b = both["haptic"].to_numpy(), both["vision"].to_numpy()
        d = a - b
        n = len(d)
        sd = d.std(ddof=1)
        t = d.mean() / (sd / math.sqrt(n))
        self.assertEqual(got.n_subjects, 4)
        self.assertEqual(got.n_subjects_unpaired, 1)
        self.assertEqual(got.df, n - 1)
        self.assertAlmostEqual(got.mean_difference, d.mean(), delta=1e-15)
        self.assertAlmostEqual(got.sd_difference, sd, delta=1e-15)
        self.assertTrue(math.isclose(got.t, t, rel_tol=1e-9), (got.t, t))
        self.assertTrue(math.isclose(got.p, 2 * sps.t.sf(abs(t), n - 1), rel_tol=1e-9))
        half = sps.t.ppf(0.975, n - 1) * sd / math.sqrt(n)
        self.assertAlmostEqual(got.ci95_low, d.mean() - half, delta=1e-13)
        self.assertTrue(math.isclose(got.d_z, d.mean() / sd, rel_tol=1e-9))
        d_av = d.mean() / ((a.std(ddof=1) + b.std(ddof=1)) / 2)
        self.assertTrue(math.isclose(got.d_av, d_av, rel_tol=1e-9))
        self.assertTrue(math.isclose(got.g_av, d_av * (1 - 3 / (4 * (n - 1) - 1)), rel_tol=1e-9))
        for field in ("mean_difference", "t", "p", "d_z", "g_av", "wilcoxon_p", "ci95_low", "ci95_high"):
            self.assertEqual(getattr(got, field), getattr(shuffled, field), field)

    def test_paired_comparison_refuses_too_few_subjects_and_an_absent_condition(self):
        trials = within_table()
        one = trials[trials["subject"].isin(["S1", "S5"])]
        with self.assertRaises(ValueError):
            statistics.paired_comparison(one, "mean_deviation_m", "haptic", "vision")
        with self.assertRaises(ValueError):
            statistics.paired_comparison(trials.iloc[0:0], "mean_deviation_m", "haptic", "vision")
        with self.assertRaises(ValueError) as caught:
            statistics.paired_comparison(trials, "mean_deviation_m", "haptic", "Vision")
        self.assertIn("Vision", str(caught.exception))
        self.assertIn("vision", str(caught.exception).replace("Vision", ""))

    def test_learning_gain_relative_gain_and_retention_ratio_are_the_documented_ones(self):
        plan = {"A": (0.002, 0.001, 0.0015, 0.0012), "B": (0.001, 0.00098, 0.0005, 0.0009),
                "C": (0.003, 0.0015, None, 0.002)}
        rows = []
        for subject, values in plan.items():
            for phase, value in zip(("pre-test", "post-test", "retention", "transfer"), values):
                if value is None:
                    continue
                for k, wobble in enumerate((-0.0001, 0.0001)):      # two trials, mean = value
                    rows.append({"subject": subject, "group": "g1" if subject != "C" else "g2", "phase": phase,
                                 "condition": "unguided", "characters": "十", "repetition": k + 1,
                                 "mean_deviation_m": value + wobble})
        trials = pandas.DataFrame(rows).sample(frac=1.0, random_state=2)
        got = statistics.learning(trials, "mean_deviation_m", "pre-test", "post-test", retention="retention",
                                  transfer="transfer").set_index("subject")
        self.assertEqual(list(got.index), ["A", "B", "C"])
        self.assertEqual(list(got["group"].astype(str)), ["g1", "g1", "g2"])
        for subject, (pre, post, retention, transfer) in plan.items():
            row = got.loc[subject]
            self.assertAlmostEqual(row["pre"], pre, delta=1e-15)
            self.assertAlmostEqual(row["gain"], pre - post, delta=1e-15)
            self.assertAlmostEqual(row["relative_gain"], (pre - post) / pre, delta=1e-12)
            self.assertAlmostEqual(row["transfer_gain"], pre - transfer, delta=1e-15)
        self.assertAlmostEqual(got.loc["A", "retention_ratio"], (0.002 - 0.0015) / (0.002 - 0.001), delta=1e-12)
        self.assertTrue(math.isnan(got.loc["B", "retention_ratio"]), "a 2 % gain is under min_relative_gain")
        self.assertTrue(math.isnan(got.loc["C", "retention"]))
        self.assertTrue(math.isnan(got.loc["C", "retention_ratio"]))

    def test_learning_refuses_a_phase_named_twice_or_absent(self):
        trials = within_table().assign(phase=["pre-test"] * 16 + ["post-test"] * 17)
        with self.assertRaises(ValueError):
            statistics.learning(trials, "total_time_s", "pre-test", "pre-test")
        with self.assertRaises(ValueError) as caught:
            statistics.learning(trials, "total_time_s", "pre-test", "post-test", retention="retention")
        self.assertIn("retention", str(caught.exception))
        self.assertIn("post-test", str(caught.exception))

    def test_group_comparison_equals_welch_and_hedges_g_computed_here(self):
        a = [0.31, 0.42, 0.18, 0.55, 0.29]
        b = [0.12, 0.20, 0.05, 0.11]
        table = pandas.DataFrame({"subject": [f"S{i}" for i in range(9)], "group": ["x"] * 5 + ["y"] * 4,
                                  "gain": a + b}).sample(frac=1.0, random_state=4)
        got = statistics.group_comparison(table, "gain", "x", "y")
        xa, xb = np.array(a), np.array(b)
        va, vb = xa.var(ddof=1) / 5, xb.var(ddof=1) / 4
        se = math.sqrt(va + vb)
        t = (xa.mean() - xb.mean()) / se
        df = (va + vb) ** 2 / (va ** 2 / 4 + vb ** 2 / 3)
        pooled = math.sqrt((4 * xa.var(ddof=1) + 3 * xb.var(ddof=1)) / 7)
        g = (xa.mean() - xb.mean()) / pooled * (1 - 3 / (4 * 9 - 9))
        self.assertEqual((got.n_a, got.n_b), (5, 4))
        self.assertAlmostEqual(got.mean_difference, xa.mean() - xb.mean(), delta=1e-14)
        self.assertTrue(math.isclose(got.t, t, rel_tol=1e-9))
        self.assertTrue(math.isclose(got.df, df, rel_tol=1e-9))
        self.assertTrue(math.isclose(got.p, 2 * sps.t.sf(abs(t), df), rel_tol=1e-9))
        self.assertTrue(math.isclose(got.ci95_low, xa.mean() - xb.mean() - sps.t.ppf(0.975, df) * se,
                                     rel_tol=1e-9))
        self.assertTrue(math.isclose(got.g, g, rel_tol=1e-9), (got.g, g))

    def test_group_comparison_refuses_a_subject_twice_and_a_group_of_one(self):
        table = pandas.DataFrame({"subject": ["S1", "S2", "S3", "S4", "S5"], "group": ["x", "x", "x", "y", "y"],
                                  "gain": [0.1, 0.2, 0.3, 0.05, 0.07]})
        with self.assertRaises(ValueError):
            statistics.group_comparison(pandas.concat([table, table.iloc[[0]]]), "gain", "x", "y")
        with self.assertRaises(ValueError):
            statistics.group_comparison(table[table["subject"] != "S5"], "gain", "x", "y")
        with self.assertRaises(ValueError) as caught:
            statistics.group_comparison(table, "gain", "x", "z")
        self.assertIn("z", str(caught.exception))

    def test_statistics_table_with_one_subject_says_why_instead_of_raising(self):
        trials = within_table()
        one = trials[trials["subject"] == "S1"]
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            table = statistics.statistics_table(one, "mean_deviation_m", phase="test")
        compared = table[table["comparison"].fillna("").astype(str) != ""]
        self.assertTrue(len(compared) > 0, table.to_string())
        self.assertTrue(table["p"].isna().all(), table.to_string())
        self.assertTrue(all(isinstance(t, str) and t for t in compared["test"]), table.to_string())

    def test_mixed_model_counts_inf_and_nan_as_dropped(self):
        trials = within_table()
        trials.loc[2, "total_time_s"] = math.inf
        trials.loc[6, "total_time_s"] = math.nan
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            got = statistics.mixed_model(trials, "total_time_s", fixed="condition", reference="vision")
        self.assertTrue(any(issubclass(w.category, statistics.NonFiniteValueWarning) for w in caught))
        self.assertEqual(set(got["n_dropped"]), {2})
        self.assertEqual(set(got["n_observations"]), {len(trials) - 2})
        self.assertEqual(set(got["n_subjects"]), {5})


    def test_a_table_through_convert_dtypes_gives_the_same_numbers(self):
        trials = within_table()
        trials.loc[3, "mean_deviation_m"] = math.nan
        lab = trials.convert_dtypes()                # Float64 with pd.NA, string, Int64: a lab's habit
        self.assertEqual(str(lab["mean_deviation_m"].dtype), "Float64")
        pandas.testing.assert_frame_equal(
            statistics.describe(lab, "mean_deviation_m", by="condition", unit="subject")[["n", "n_missing", "mean",
                                                                                          "sd", "ci95_low"]],
            statistics.describe(trials, "mean_deviation_m", by="condition", unit="subject")[["n", "n_missing",
                                                                                             "mean", "sd",
                                                                                             "ci95_low"]],
            check_dtype=False)
        mine = statistics.paired_comparison(trials, "mean_deviation_m", "haptic", "vision")
        theirs = statistics.paired_comparison(lab, "mean_deviation_m", "haptic", "vision")
        for field in ("n_subjects", "n_subjects_unpaired", "mean_difference", "t", "p", "d_z"):
            self.assertEqual(getattr(theirs, field), getattr(mine, field), field)

    def test_a_missing_condition_or_group_value_is_named_never_dropped(self):
        trials = within_table()
        trials["condition"] = trials["condition"].astype(object)
        trials.loc[[4, 6, 8], "condition"] = None
        with self.assertRaises(ValueError) as caught:
            statistics.describe(trials, "total_time_s", by="condition")
        self.assertIn("condition", str(caught.exception))
        self.assertIn("3", str(caught.exception))
        table = pandas.DataFrame({"subject": ["S1", "S2", "S3", "S4", "S5"], "group": ["x", "x", None, "y", "y"],
                                  "gain": [0.1, 0.2, 0.3, 0.05, 0.07]})
        with self.assertRaises(ValueError) as caught:
            statistics.group_comparison(table, "gain", "x", "y")
        self.assertIn("group", str(caught.exception))

    def test_describe_of_an_empty_table_is_one_row_of_nothing(self):
        empty = within_table().iloc[0:0]
        got = statistics.describe(empty, "mean_deviation_m", by=())
        self.assertEqual(len(got), 1, got.to_string())
        self.assertEqual(got["n"].iloc[0], 0)
        self.assertEqual(got["n_missing"].iloc[0], 0)
        self.assertTrue(math.isnan(got["mean"].iloc[0]))
        with self.assertRaises(ValueError) as caught:
            statistics.describe(within_table(), "mean_deviation_m", unit="subjects")
        self.assertIn("unit", str(caught.exception))

    def test_apa_sentence_is_the_documented_text(self):
        self.assertEqual(design_analysis.apa_sentence(7.8, 2.43, 0.042, 1.39, (0.00001, 0.00055), "mm", 1e3),
                         "t(7.8) = 2.43, p = .042, g = 1.39, 95 % CI [0.01, 0.55] mm")
        text = design_analysis.apa_sentence(12.0, 5.0, 0.00004)
        self.assertTrue(text.startswith("t(12) = 5.00, p < .001"), text)

class DesignQuestions(unittest.TestCase):
    """calligraphy.design_analysis on a simulated between-subjects cohort, without R."""

    @classmethod
    def setUpClass(cls):
        cls.study = cohort()[0]
        cls.trials = cls.study.trials
        cls.questions = design_analysis.design_questions(cls.trials, "mean_deviation_m")

    def test_ancova_rows_equal_least_squares_on_subject_means_and_holm_within_the_family(self):
        t = self.trials[self.trials["end_reason"].astype(str) == "completed"]
        means = t.groupby([t["subject"].astype(str), t["phase"].astype(str)])["mean_deviation_m"].mean().unstack()
        group = t.groupby(t["subject"].astype(str))["group"].first().astype(str)
        subjects = sorted(means.index)
        pre = means.loc[subjects, "pre-test"].to_numpy()
        post = means.loc[subjects, "post-test"].to_numpy()
        g = group.loc[subjects].to_numpy()
        X = np.column_stack([np.ones(len(subjects)), pre, g == FIXTURE, g == FADING]).astype(float)
        beta, *_ = np.linalg.lstsq(X, post, rcond=None)
        dof = len(subjects) - X.shape[1]
        sigma2 = float(np.sum((post - X @ beta) ** 2)) / dof
        cov = sigma2 * np.linalg.inv(X.T @ X)
        rows = self.questions[self.questions["phase"].astype(str) == "post-test"].set_index("comparison")
        self.assertEqual(set(rows.index), PAIRS)
        for comparison, c in ((f"{FIXTURE} - {CONTROL}", [0, 0, 1, 0]), (f"{FADING} - {CONTROL}", [0, 0, 0, 1]),
                              (f"{FADING} - {FIXTURE}", [0, 0, -1, 1])):
            c = np.array(c, float)
            estimate = float(c @ beta)
            se = math.sqrt(float(c @ cov @ c))
            row = rows.loc[comparison]
            self.assertTrue(math.isclose(row["estimate"], estimate, rel_tol=1e-8), (comparison, row["estimate"]))
            self.assertTrue(math.isclose(row["df"], dof), row["df"])
            self.assertTrue(math.isclose(row["statistic"], estimate / se, rel_tol=1e-8))
            self.assertTrue(math.isclose(row["p"], 2 * sps.t.sf(abs(estimate / se), dof), rel_tol=1e-8))
        self.assertEqual(set(rows["family"]), {"mean_deviation_m, post-test"})
        np.testing.assert_allclose(rows["p_holm"].to_numpy(float), holm(rows["p"].to_numpy(float)), rtol=1e-12)

    def test_without_rscript_the_mixed_rows_say_so_and_hold_no_test(self):
        rows = self.questions[self.questions["phase"].astype(str) == "training"]
        self.assertEqual(set(rows["comparison"]), PAIRS)
        for _, row in rows.iterrows():
            self.assertIn("not computed: Rscript is not installed", row["note"])
            for column in ("df", "statistic", "p", "p_holm", "ci95_low", "ci95_high"):
                self.assertTrue(pandas.isna(row[column]), (row["comparison"], column, row[column]))
        self.assertEqual(list(self.questions.columns), list(design_analysis.QUESTION_COLUMNS))

    def test_outcome_near_1e300_or_1e_minus_300_gives_the_same_tests_scaled(self):
        base = self.questions[self.questions["phase"].astype(str) == "post-test"].set_index("comparison")
        for scale in (1e303, 1e-297):       # mean deviations of about 1e-3 m: outcomes near 1e300 and 1e-300
            trials = self.trials.assign(mean_deviation_m=self.trials["mean_deviation_m"] * scale)
            got = design_analysis.design_questions(trials, "mean_deviation_m")
            rows = got[got["phase"].astype(str) == "post-test"].set_index("comparison")
            self.assertEqual(set(rows.index), PAIRS, got.to_string())
            for comparison in PAIRS:
                mine, theirs = base.loc[comparison], rows.loc[comparison]
                for column in ("statistic", "p", "p_holm", "g", "df"):
                    self.assertTrue(math.isclose(theirs[column], mine[column], rel_tol=1e-9),
                                    (scale, comparison, column, theirs[column], mine[column], theirs["note"]))
                for column in ("estimate", "ci95_low", "ci95_high"):
                    self.assertTrue(math.isclose(theirs[column], mine[column] * scale, rel_tol=1e-9),
                                    (scale, comparison, column, theirs[column]))

    def test_retention_ratio_of_gains_near_1e300_is_the_ratio_of_the_same_data(self):
        rows = []
        # Subject n: pre-test 3 + 0.01 n, post-test 1 + 0.03 n, retention 2 - 0.01 n (seconds, say).
        plan = (("pre-test", 1, 1, 3.0, 0.01), ("training", 1, 2, 2.0, 0.0), ("post-test", 1, 3, 1.0, 0.03),
                ("retention", 2, 1, 2.0, -0.01))
        for n in range(1, 7):
            group = GROUPS[(n - 1) % 2]
            for phase, session, block, level, slope in plan:
                condition = group if phase == "training" else CONTROL
                value = level + slope * n
                rows.append({"subject": f"S{n:02d}", "session": f"x-S{n:02d}-s{session}", "protocol": "x",
                             "session_number": session, "group": group, "phase": phase, "block": block,
                             "trial": block, "condition": condition, "mode": "vision" if condition == CONTROL
                             else "haptic", "characters": "十", "item": 1, "repetition": 1,
                             "end_reason": "completed", "total_time_s": value})
        trials = pandas.DataFrame(rows)
        design = design_analysis.study_design(trials)
        self.assertEqual(tuple(design.phases), ("pre-test", "training", "post-test", "retention"))
        plain = design_analysis.retention_ratios(trials, "total_time_s", design).set_index("group")
        huge = design_analysis.retention_ratios(trials.assign(total_time_s=trials["total_time_s"] * 1e300),
                                                "total_time_s", design).set_index("group")
        for group in GROUPS[:2]:
            part = trials[trials["group"] == group].pivot(index="subject", columns="phase", values="total_time_s")
            expected = (part["pre-test"] - part["retention"]).mean() / (part["pre-test"] - part["post-test"]).mean()
            self.assertTrue(math.isclose(plain.loc[group, "retention_ratio"], expected, rel_tol=1e-12),
                            plain.to_string())
            self.assertTrue(math.isclose(huge.loc[group, "retention_ratio"], expected, rel_tol=1e-12),
                            huge.to_string())
            self.assertTrue(math.isclose(huge.loc[group, "gain"], plain.loc[group, "gain"] * 1e300, rel_tol=1e-12))
            self.assertTrue(np.isfinite(huge.loc[group, "gain_ci95_high"]), huge.to_string())

    def assertSameQuestions(self, trials, name):
        base = self.questions.set_index(["phase", "comparison"]).sort_index()
        got = design_analysis.design_questions(trials, "mean_deviation_m")
        got = got.set_index(["phase", "comparison"]).sort_index()
        self.assertEqual(list(got.index.map(lambda k: (str(k[0]), k[1]))),
                         list(base.index.map(lambda k: (str(k[0]), k[1]))), name)
        for column in ("n", "df", "statistic", "p", "p_holm", "estimate", "g"):
            np.testing.assert_allclose(got[column].to_numpy(float), base[column].to_numpy(float), rtol=1e-12,
                                       err_msg=f"{name} {column}")

    def test_questions_of_two_tables_concatenated_with_index_labels_twice_are_the_same(self):
        half = len(self.trials) // 2
        joined = pandas.concat([self.trials.iloc[:half].reset_index(drop=True),
                                self.trials.iloc[half:].reset_index(drop=True)])
        self.assertFalse(joined.index.is_unique)
        self.assertSameQuestions(joined, "concat")

    def test_questions_of_a_table_through_convert_dtypes_are_the_same(self):
        lab = self.trials.convert_dtypes()            # Float64, Int64, string: a lab's habit
        self.assertEqual(str(lab["mean_deviation_m"].dtype), "Float64")
        self.assertSameQuestions(lab, "convert_dtypes")

    def test_every_trial_excluded_keeps_a_row_per_comparison_not_computed(self):
        trials = self.trials.copy()
        trials["end_reason"] = "time_limit"
        got = design_analysis.design_questions(trials, "mean_deviation_m")
        pairs = {(str(p), c) for p, c in zip(got["phase"], got["comparison"])}
        expected = {(phase, c) for phase in ("training", "post-test")
                    for c in PAIRS}
        self.assertEqual(pairs, expected)
        for _, row in got.iterrows():
            self.assertIn("not computed", row["note"])
            self.assertTrue(pandas.isna(row["p"]) and pandas.isna(row["statistic"]), row.to_dict())

    def test_one_subject_a_group_is_not_computed_and_says_why(self):
        first = sorted(self.trials["subject"].astype(str).unique())[:3]    # S01, S02, S03: one in each group
        trials = self.trials[self.trials["subject"].astype(str).isin(first)]
        design = design_analysis.study_design(trials)
        self.assertEqual(dict(design.n_per_condition), {g: 1 for g in GROUPS})
        got = design_analysis.design_questions(trials, "mean_deviation_m", design)
        post = got[got["phase"].astype(str) == "post-test"]
        self.assertEqual(len(post), 3)
        for _, row in post.iterrows():
            self.assertIn("not computed", row["note"])
            self.assertTrue(pandas.isna(row["p"]), row.to_dict())

    def test_apply_exclusions_counts_each_end_reason_per_phase_and_group(self):
        trials = self.trials.copy()
        trials["end_reason"] = trials["end_reason"].astype(str)
        post = trials.index[(trials["phase"].astype(str) == "post-test") & (trials["group"].astype(str) == FADING)]
        trials.loc[post[:1], "end_reason"] = "time_limit"
        kept, counts = design_analysis.apply_exclusions(trials)
        self.assertEqual(len(kept), len(trials) - 1)
        self.assertNotIn(post[0], kept.index)
        row = counts[(counts["phase"].astype(str) == "post-test") & (counts["group"].astype(str) == FADING)]
        self.assertEqual(len(row), 1, counts.to_string())
        self.assertEqual(int(row["trials"].iloc[0]), SUBJECTS // 3)
        self.assertEqual(int(row["kept"].iloc[0]), SUBJECTS // 3 - 1)
        self.assertEqual(int(row["excluded_time_limit"].iloc[0]), 1)
        self.assertEqual(int(counts["kept"].sum()), len(trials) - 1)
        kept_all, _ = design_analysis.apply_exclusions(trials, design_analysis.ExclusionPolicy(None))
        self.assertEqual(len(kept_all), len(trials))
        with self.assertRaises(ValueError) as caught:
            design_analysis.apply_exclusions(trials.drop(columns=["end_reason"]))
        self.assertIn("end_reason", str(caught.exception))

    def test_unknown_reference_is_a_value_error_naming_it(self):
        with self.assertRaises(ValueError) as caught:
            design_analysis.study_design(self.trials, reference="sham")
        self.assertIsInstance(caught.exception, design_analysis.UnknownReference)
        self.assertIn("sham", str(caught.exception))
        self.assertIn(CONTROL, str(caught.exception))


class Report(unittest.TestCase):
    """calligraphy.study_report on the simulated cohort, without R."""

    @classmethod
    def setUpClass(cls):
        cls.tmp = Path(tempfile.mkdtemp(prefix="report-", dir=TMP))
        (cls.tmp / "kept.txt").write_text("a lab's own file\n", encoding="utf-8")
        cls.study = cohort()[0]
        cls.before = cls.study.trials.copy(deep=True)
        cls.out = cls.tmp / "paper"
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            cls.index = study_report.write_report(cls.study, cls.out, values=("mean_deviation_m",), title=TITLE)

    def test_report_writes_the_documented_files_only_and_leaves_the_study_as_it_was(self):
        self.assertEqual(Path(self.index), self.out / "index.html")
        found = sorted(str(p.relative_to(self.out)) for p in self.out.rglob("*"))
        expected = sorted(["index.html", "figures", "tables", "figures/phase_mean_deviation_m.svg",
                           "figures/phase_mean_deviation_m.png", "figures/learning_mean_deviation_m.svg",
                           "figures/learning_mean_deviation_m.png", "tables/phase_means.csv",
                           "tables/questions.csv", "tables/exclusions.csv"])
        self.assertEqual(found, expected)
        self.assertEqual(sorted(p.name for p in self.tmp.iterdir() if p.name not in ("a-file", "never")),
                         ["kept.txt", "paper"])
        self.assertEqual((self.tmp / "kept.txt").read_text(encoding="utf-8"), "a lab's own file\n")
        pandas.testing.assert_frame_equal(self.study.trials, self.before)

    def test_page_escapes_its_title_loads_nothing_external_and_says_who_wrote(self):
        page = (self.out / "index.html").read_text(encoding="utf-8")
        self.assertNotIn("<script", page.lower())
        self.assertIn("&lt;script&gt;", page)
        for tag in re.findall(r"<(?:img|link|iframe|object|embed|source)\b[^>]*>", page, flags=re.I):
            for url in re.findall(r"""(?:src|href|data)\s*=\s*["']([^"']*)""", tag, flags=re.I):
                self.assertFalse(re.match(r"(?:[a-z]+:)?//", url, flags=re.I), tag)
        self.assertIn('src="figures/phase_mean_deviation_m.svg"', page)
        # Simulated subjects: their profile and learning model, and that they are a model.
        self.assertIn("novice", page)
        self.assertIn("two-state", page)
        self.assertIn("model", page)

    def test_phase_means_are_over_subject_means_with_n_subjects(self):
        table = pandas.read_csv(self.out / "tables" / "phase_means.csv", keep_default_na=False, na_values=[""],
                                float_precision="round_trip", dtype={"condition": str, "phase": str})
        t = self.study.trials
        t = t[t["end_reason"].astype(str) == "completed"]
        self.assertEqual(len(table), 3 * 3)
        for _, row in table.iterrows():
            self.assertEqual(row["value"], "mean_deviation_m")
            self.assertEqual(row["unit"], "m")
            part = t[(t["phase"].astype(str) == row["phase"]) & (t["group"].astype(str) == row["condition"])]
            means = part.groupby(part["subject"].astype(str))["mean_deviation_m"].mean().to_numpy()
            self.assertEqual(row["n"], len(means), (row["phase"], row["condition"]))
            self.assertTrue(math.isclose(row["mean"], means.mean(), rel_tol=1e-12))
            self.assertTrue(math.isclose(row["sd"], means.std(ddof=1), rel_tol=1e-9))
            half = sps.t.ppf(0.975, len(means) - 1) * means.std(ddof=1) / math.sqrt(len(means))
            self.assertTrue(math.isclose(row["ci95_low"], means.mean() - half, rel_tol=1e-9, abs_tol=1e-15))

    def test_questions_csv_n_is_a_whole_number_or_empty_and_no_test_where_not_computed(self):
        text = (self.out / "tables" / "questions.csv").read_text(encoding="utf-8")
        table = pandas.read_csv(io.StringIO(text), keep_default_na=False, na_values=[""], dtype=str)
        self.assertEqual(list(table.columns), list(design_analysis.QUESTION_COLUMNS))
        self.assertEqual(len(table), 6)
        for _, row in table.iterrows():
            n = row["n"]
            self.assertTrue(pandas.isna(n) or n.isdigit(), repr(n))
            if str(row["note"]).startswith("not computed"):
                self.assertTrue(pandas.isna(n) and pandas.isna(row["p"]) and pandas.isna(row["df"]), row.to_dict())

    def test_report_refuses_bad_arguments_naming_them_and_writes_nothing(self):
        never = self.tmp / "never"
        for kwargs, error, needle in (({"values": ("no_such_m",)}, ValueError, "no_such_m"),
                                      ({"values": ("condition",)}, ValueError, "condition"),
                                      ({"keep_end_reasons": "completed"}, TypeError, "keep_end_reasons"),
                                      ({"ddf": "Wald"}, ValueError, "Wald")):
            with self.assertRaises(error) as caught:
                study_report.write_report(self.study, never, **kwargs)
            self.assertIn(needle, str(caught.exception), kwargs)
            self.assertFalse(never.exists(), kwargs)
        with self.assertRaises(ValueError):
            study_report.write_report(self.study, "")

    def test_report_into_a_path_that_is_a_file_is_an_os_error_naming_it_and_leaves_it(self):
        target = self.tmp / "a-file"
        target.write_bytes(b"keep me\n")
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            with self.assertRaises(OSError) as caught:
                study_report.write_report(self.study, target, values=("mean_deviation_m",))
        self.assertIn("a-file", str(caught.exception))
        self.assertEqual(target.read_bytes(), b"keep me\n")
        target.unlink()

    def test_learning_figure_of_a_learning_study_without_a_test_phase_is_a_value_error(self):
        with self.assertRaises(ValueError) as caught:
            study_report.learning_figure(self.study.trials, "total_time_s")
        self.assertIn("test", str(caught.exception))
        with self.assertRaises(ValueError) as caught:
            study_report.learning_figure(self.study.trials, "no_such_s", phase="training")
        self.assertIn("no_such_s", str(caught.exception))

    def test_module_command_with_an_empty_out_is_a_usage_error(self):
        env = dict(ENV)
        result = subprocess.run([sys.executable, "-m", "calligraphy.study_report", str(self.tmp), "--out", ""],
                                env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, timeout=60,
                                stdin=subprocess.DEVNULL)
        text = result.stderr.decode("utf-8", "replace")
        self.assertEqual(result.returncode, 2, text)
        self.assertIn("--out", text)
        self.assertNotIn("Traceback", text)


class StudyFolders(unittest.TestCase):
    """`session run` folders read by `calligraphy.study.load` and by `calligraphy report --csv`."""

    @classmethod
    def setUpClass(cls):
        cls.tmp = Path(tempfile.mkdtemp(prefix="folders-", dir=TMP))
        (cls.tmp / "within.json").write_text(json.dumps(WITHIN, ensure_ascii=False), encoding="utf-8")
        run_ok(["session", "run", "within.json", "--subjects", 2, "--out", "S"], cls.tmp)
        (cls.tmp / "T").mkdir()
        run_ok(["report", "S", "--csv", "T"], cls.tmp)
        cls.study = calligraphy.study.load(str(cls.tmp / "S"))
        old = os.getcwd()
        try:
            os.chdir(cls.tmp)
            cls.relative = calligraphy.study.load("S")
        finally:
            os.chdir(old)

    def test_study_load_equals_report_csv_read_by_the_docs_recipe(self):
        csv = read_tables_csv(self.tmp / "T" / "trials.csv")
        loaded = self.relative.trials
        self.assertEqual(list(csv.columns), list(loaded.columns))
        self.assertEqual(len(csv), 4)
        for column in csv.columns:
            mine, theirs = loaded[column], csv[column]
            if pandas.api.types.is_numeric_dtype(mine.dtype) and not pandas.api.types.is_bool_dtype(mine):
                np.testing.assert_array_equal(mine.to_numpy(float), theirs.to_numpy(float), column)
            else:   # a label; a column with no value reads in pandas as float NaN, in study.load as ""
                self.assertEqual([str(v) for v in mine.astype(object).fillna("")],
                                 [str(v) for v in theirs.astype(object).fillna("")], column)

    def test_within_paired_check_is_the_paired_t_on_subject_means(self):
        trials = self.study.trials
        got = design_analysis.design_questions(trials, "total_time_s")
        checks = got[got["family"] == "total_time_s (checks)"]
        self.assertEqual(list(checks["comparison"]), ["haptic - vision"], got.to_string())
        means = trials.groupby([trials["subject"].astype(str), trials["condition"].astype(str)],
                               observed=True)["total_time_s"].mean().unstack()
        d = (means["haptic"] - means["vision"]).to_numpy()
        t = d.mean() / (d.std(ddof=1) / math.sqrt(len(d)))
        row = checks.iloc[0]
        self.assertEqual(row["df"], len(d) - 1)
        self.assertTrue(math.isclose(row["statistic"], t, rel_tol=1e-9), (row["statistic"], t))
        self.assertTrue(math.isclose(row["estimate"], d.mean(), rel_tol=1e-9))
        self.assertTrue(pandas.isna(row["p_holm"]), "a check is not adjusted")
        mixed = got[(got["family"] == "total_time_s, test") & (got["comparison"] == "haptic - vision")]
        self.assertEqual(len(mixed), 1, got.to_string())
        self.assertTrue(mixed["note"].iloc[0].startswith("not computed"), mixed["note"].iloc[0])
        self.assertTrue(pandas.isna(mixed["p"].iloc[0]))

    def test_samples_of_a_row_from_a_reindexed_selection_are_that_trials_or_refused(self):
        trials = self.study.trials
        haptic = trials[trials["condition"].astype(str) == "haptic"]
        label = haptic.index[-1]
        lab = haptic.reset_index(drop=True)          # a lab's selection, numbered again from 0
        row = lab.iloc[len(lab) - 1]
        self.assertNotEqual(row.name, label)
        try:
            samples = self.study.samples(row)
        except (KeyError, ValueError, TypeError):
            return
        pandas.testing.assert_frame_equal(samples, self.study.samples(label))

    def test_sessions_listed_in_any_order_give_the_folders_tables(self):
        sessions = sorted(p.parent for p in (self.tmp / "S").glob("*/*/session.json"))
        self.assertEqual(len(sessions), 2)
        listed = calligraphy.study.load([str(p) for p in reversed(sessions)])
        whole = self.study.trials.drop(columns=["trace_file"])
        pandas.testing.assert_frame_equal(listed.trials.drop(columns=["trace_file"]).reset_index(drop=True),
                                          whole.reset_index(drop=True))

    def test_samples_refuse_none_list_bool_and_an_unknown_label(self):
        for bad in (None, [0], True):
            with self.assertRaises(TypeError) as caught:
                self.study.samples(bad)
            self.assertIn("trial", str(caught.exception), repr(bad))
        with self.assertRaises(KeyError):
            self.study.samples(10 ** 6)

    def test_samples_are_the_documented_si_frame(self):
        row = self.study.trials.iloc[0]
        samples = self.study.samples(row)
        self.assertEqual(list(samples.columns), ["t_s", "x_m", "y_m", "z_m", "fx_n", "fy_n", "fz_n", "state",
                                                 "stroke", "element", "attempt", "rewritten"])
        for column in ("t_s", "x_m", "y_m", "z_m", "fx_n", "fy_n", "fz_n"):
            self.assertEqual(samples[column].dtype, np.float64, column)
        for column in ("stroke", "element", "attempt", "rewritten"):
            self.assertEqual(samples[column].dtype, np.int64, column)
        self.assertTrue(set(samples["state"].astype(str)) <= {"SS", "AS", "CS", "WS"})
        self.assertTrue((np.diff(samples["t_s"].to_numpy()) >= 0).all())
        pandas.testing.assert_frame_equal(samples, self.study.samples(self.study.trials.index[0]))



class LoadArguments(unittest.TestCase):
    """`calligraphy.study.load` given what is no study folder's path."""

    def test_load_refuses_empty_nul_and_non_paths(self):
        with self.assertRaises(ValueError):
            calligraphy.study.load("")
        with self.assertRaises(ValueError):
            calligraphy.study.load([])
        with self.assertRaises(TypeError) as caught:
            calligraphy.study.load(42)
        self.assertIn("paths", str(caught.exception))
        with self.assertRaises(cg.InvalidArgument):
            calligraphy.study.load("a\0b")

if __name__ == "__main__":
    unittest.main()
