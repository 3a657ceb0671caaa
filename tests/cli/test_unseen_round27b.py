#!/usr/bin/env python3
"""Round 27B: a study's numbers read as a reviewer in motor learning reads them. From the docs alone
(docs/learning-study.md, docs/experiments.md "A report for a paper", docs/python.md "Statistics" and "The
design's questions", the modules' docstrings).

Each case plants a study whose truth is known and computes the answer independently: R's lme4, lmerTest and
emmeans run by this file's own R code (one Rscript for every planted fit), and NumPy/SciPy for the ANCOVA, the
paired and two-sample tests and Holm. Planted: a group effect in training (between subjects, three groups), a
condition effect within subjects, a post-test effect adjusted for the pre-test, a retention loss, a practice
slope, a crossover with a carry-over, a mixed design (a group beside the crossover). Then the designs a lab
meets: one subject per group, a group with no trial left, a constant outcome, every outcome of one cell NaN, a
pre-test collinear with the group, a crossover subject missing a period, subjects with one trial, an outcome in
the 1e6 mm and in the 1e-9 mm, subject ids spelt like R's missing value, logicals or numbers, and ids that are
numbers in one table and zero-padded text in another. Expected: estimates, intervals, df and p as the
independent fit within the stated tolerance; df by the named method; Holm within each outcome and phase; the
effect sizes as defined; what cannot be estimated says "not computed" (or "not tested") with a reason and
carries no p, df or statistic.

CALLIGRAPHY_SOURCE_DIR and PYTHONPATH name the package. Skipped, saying so, without R's lme4, lmerTest, emmeans
and pbkrtest. CALLIGRAPHY_SANITIZED=1 takes five cases.
"""
import io
import math
import os
import shutil
import subprocess
import tempfile
import unittest
import warnings

import numpy as np
import pandas
from scipy import stats as scipy_stats

from outsider import sanitized_subset

# Under the sanitizers: cases that need no R of this file's own (the library's fits are R's, not sanitized).
load_tests = sanitized_subset({"test_one_subject_per_group_gives_no_test",
                               "test_infinite_outcome_counts_as_missing_with_a_warning",
                               "test_group_comparison_is_welch_and_hedges_g_as_defined",
                               "test_planted_retention_loss_gives_the_documented_ratio",
                               "test_planted_practice_slope_in_subject_means"})

from calligraphy import design_analysis, mixed_models, statistics  # noqa: E402

# The library asks R for lme4, lmerTest and pbkrtest; this file's own R program asks for emmeans (exit 3).
_R_READY = []


def r_ready():
    if not _R_READY:  # asked when a case first needs R: starting R costs seconds
        _R_READY.append(shutil.which("Rscript") is not None and mixed_models.r_available())
    return _R_READY[0]


R_MISSING = ("R with lme4, lmerTest, emmeans and pbkrtest is not installed (Debian: r-base-core r-cran-lme4 "
             "r-cran-lmertest r-cran-emmeans r-cran-pbkrtest)")

VALUE = "mean_deviation_m"
GROUPS = ("unguided", "fixture", "fading")  # the control (vision mode) first, not alphabetical
MODES = {"unguided": "vision", "fixture": "haptic", "fading": "fading", "amplify": "amplify"}
PHASES = ("pre-test", "training", "post-test", "retention")
CHARACTERS = ("十", "人", "口", "山")
# Tolerances: the same REML fit made twice (the library fits in a unit of its own, documented), so the
# variance parameters agree to the optimiser's tolerance: estimates to 1e-6 relative, t to 1e-4 relative,
# Satterthwaite or Kenward-Roger df and an F's df to 1e-3 relative, p to 1e-4 absolute and 1e-3 relative.
EST_RTOL = 1e-6
T_RTOL = 1e-4
DF_RTOL = 1e-3
P_ATOL = 1e-4


def row(subject, phase, condition, character, value_m, *, group="", block=0, trial=0, repetition=1,
        end_reason="completed", item_set="", sequence="", period=math.nan, trained_condition=""):
    return {"subject": subject, "session": f"{subject}-s1", "protocol": "planted", "session_number": 1,
            "group": group, "phase": phase, "block": block, "condition": condition, "mode": MODES[condition],
            "characters": character, "trial": trial, "item": 1, "repetition": repetition,
            "item_set": item_set, "sequence": sequence, "period": period, "trained_condition": trained_condition,
            "writer": "person", "end_reason": end_reason, VALUE: value_m}


def between_study(seed, per_group=6, groups=GROUPS, training_mm=(0.0, -0.6, -0.3), post_mm=(0.0, -0.4, 0.3),
                  retention_loss_mm=(0.0, 0.1, 0.3), subject_sd_mm=0.4, item_sd_mm=0.2, noise_mm=0.15,
                  training_reps=2, slope_mm=0.0):
    """Between subjects, in protocol order: pre-test, training (three groups), post-test, retention. Each
    subject's skill carries over every phase; the characters differ crossed with subjects. Values in m."""
    rng = np.random.default_rng(seed)
    items = dict(zip(CHARACTERS, rng.normal(0.0, item_sd_mm, len(CHARACTERS))))
    rows = []
    for s in range(per_group * len(groups)):
        k = s % len(groups)
        group = groups[k]
        subject = f"S{s + 1:02d}"
        skill = rng.normal(0.0, subject_sd_mm)
        trial = 0
        for block, phase in enumerate(PHASES):
            reps = training_reps if phase == "training" else 1
            for rep in range(reps):
                for character in CHARACTERS:
                    mm = 3.0 + skill + items[character] + rng.normal(0.0, noise_mm)
                    if phase == "training":
                        mm += -0.5 + training_mm[k] + slope_mm * rep
                    elif phase == "post-test":
                        mm += -0.8 + post_mm[k]
                    elif phase == "retention":
                        mm += -0.8 + post_mm[k] + retention_loss_mm[k]
                    trial += 1
                    rows.append(row(subject, phase, group if phase == "training" else "unguided", character,
                                    mm * 1e-3, group=group, block=block, trial=trial, repetition=rep + 1))
    return pandas.DataFrame(rows)


def within_study(seed, subjects=10, effect_mm=-0.5, slope_sd_mm=0.35, subject_sd_mm=0.5, noise_mm=0.2):
    """Within subjects: every subject writes every character under both conditions in one `test` phase."""
    rng = np.random.default_rng(seed)
    items = dict(zip(CHARACTERS, rng.normal(0.0, 0.2, len(CHARACTERS))))
    rows = []
    for s in range(subjects):
        subject = f"W{s + 1:02d}"
        skill, own_effect = rng.normal(0.0, subject_sd_mm), rng.normal(0.0, slope_sd_mm)
        trial = 0
        for block, condition in enumerate(("unguided", "fixture") if s % 2 == 0 else ("fixture", "unguided")):
            for rep in range(2):
                for character in CHARACTERS:
                    mm = 3.0 + skill + items[character] + rng.normal(0.0, noise_mm)
                    if condition == "fixture":
                        mm += effect_mm + own_effect
                    trial += 1
                    rows.append(row(subject, "test", condition, character, mm * 1e-3, block=block, trial=trial,
                                    repetition=rep + 1))
    return pandas.DataFrame(rows)


SETS = {"set1": ("十", "口", "山"), "set2": ("人", "又", "小")}


def crossover_study(seed, subjects=16, effect_mm=-0.5, carry_mm=0.0, period_mm=-0.2, slope_sd_mm=0.3,
                    group_of=None, group_effect_mm=None, drop_period2_of=()):
    """A 2 x 2 crossover by the protocol's rule: subjects 1-4 AB/BA on set1 then set2, then the sets swapped.
    Training only, plus a pre-test of both sets. `carry_mm` is added to period 2 of sequence AB (A's
    carry-over into B), so the sequences differ beyond the treatment. `group_of(s)` makes a mixed design."""
    rng = np.random.default_rng(seed)
    items = {c: rng.normal(0.0, 0.2) for chars in SETS.values() for c in chars}
    rows = []
    for s in range(subjects):
        subject = f"X{s + 1:02d}"
        sequence = "AB" if s % 2 == 0 else "BA"
        rotation = (s // 2) % 2
        a_set, b_set = ("set1", "set2") if rotation == 0 else ("set2", "set1")
        group = group_of(s) if group_of else ""
        skill, own_effect = rng.normal(0.0, 0.5), rng.normal(0.0, slope_sd_mm)
        group_shift = group_effect_mm.get(group, 0.0) if group_effect_mm else 0.0
        trained = {a_set: ("unguided", 1 if sequence == "AB" else 2), b_set: ("amplify", 2 if sequence == "AB" else 1)}
        trial = 0
        for item_set, chars in SETS.items():
            for character in chars:
                trial += 1
                condition, period = trained[item_set]
                rows.append(row(subject, "pre-test", "unguided", character,
                                (3.0 + skill + items[character] + rng.normal(0.0, 0.15)) * 1e-3, group=group,
                                block=0, trial=trial, item_set=item_set, sequence=sequence, period=period,
                                trained_condition=condition))
        periods = sorted(trained.items(), key=lambda kv: kv[1][1])
        for item_set, (condition, period) in periods:
            if period == 2 and s in drop_period2_of:
                continue
            for rep in range(2):
                for character in SETS[item_set]:
                    mm = 2.5 + skill + items[character] + rng.normal(0.0, 0.15) + period_mm * (period - 1)
                    if condition == "amplify":
                        mm += effect_mm + own_effect + group_shift
                    if sequence == "AB" and period == 2:
                        mm += carry_mm
                    trial += 1
                    rows.append(row(subject, "training", condition, character, mm * 1e-3, group=group,
                                    block=period, trial=trial, repetition=rep + 1, item_set=item_set,
                                    sequence=sequence, period=period, trained_condition=condition))
    return pandas.DataFrame(rows)


def ancova_ols(frame, phase, groups):
    """phase mean ~ pre-test mean + group on subject means, by NumPy's least squares: per group against the
    first, (estimate, se, df, t, p)."""
    means = frame.groupby(["subject", "group", "phase"]).agg(v=(VALUE, "mean")).reset_index()
    wide = means.pivot_table(index=["subject", "group"], columns="phase", values="v").reset_index()
    wide = wide[wide.group.isin(groups)].dropna(subset=["pre-test", phase])
    design = np.column_stack([np.ones(len(wide)), wide["pre-test"].to_numpy()] +
                             [(wide.group == g).to_numpy(float) for g in groups[1:]])
    y = wide[phase].to_numpy()
    beta, *_ = np.linalg.lstsq(design, y, rcond=None)
    df = len(y) - design.shape[1]
    sigma2 = float(((y - design @ beta) ** 2).sum() / df)
    cov = sigma2 * np.linalg.inv(design.T @ design)
    result = {}
    for i, g in enumerate(groups[1:]):
        est, se = beta[2 + i], math.sqrt(cov[2 + i, 2 + i])
        t = est / se
        result[g] = (est, se, df, t, 2 * scipy_stats.t.sf(abs(t), df))
    return result


def holm(p_values):
    p = np.asarray(p_values, float)
    order = np.argsort(p)
    m = len(p)
    adjusted = np.empty(m)
    running = 0.0
    for rank, i in enumerate(order):
        running = max(running, (m - rank) * p[i])
        adjusted[i] = min(1.0, running)
    return adjusted


# ---- the independent R fits, all in one Rscript ----------------------------------------------------------

R_PROGRAM = r"""
if (!requireNamespace("emmeans", quietly = TRUE)) quit(status = 3)
suppressMessages({library(lmerTest); library(emmeans)})
args <- commandArgs(trailingOnly = TRUE)
folder <- args[1]
out <- list()
add <- function(job, kind, term, est, se, df, stat, p, singular) {
  out[[length(out) + 1]] <<- data.frame(job = job, kind = kind, term = term, estimate = est, se = se, df = df,
                                        stat = stat, p = p, singular = singular)
}
load <- function(name) {
  d <- read.csv(file.path(folder, paste0(name, ".csv")), encoding = "UTF-8", na.strings = "",
                colClasses = c(subject = "character", group = "character", condition = "character",
                               characters = "character", item_set = "character", sequence = "character"))
  d$y <- d$y * 1000
  d
}
coefs <- function(job, fit, ddf) {
  s <- summary(fit, ddf = ddf)$coefficients
  for (r in rownames(s)) add(job, "coef", r, s[r, 1], s[r, 2], s[r, 3], s[r, 4], s[r, 5], isSingular(fit))
}
# Between subjects, training: the group effect, Satterthwaite and Kenward-Roger; the pairs by emmeans.
d <- load("between")
d$group <- factor(d$group, levels = c("unguided", "fixture", "fading"))
fit <- lmer(y ~ group + (1 | subject) + (1 | characters), data = d)
coefs("between", fit, "Satterthwaite")
coefs("between_kr", fit, "Kenward-Roger")
pr <- as.data.frame(pairs(emmeans(fit, "group", lmer.df = "satterthwaite"), reverse = TRUE, adjust = "none"))
for (i in seq_len(nrow(pr))) add("between", "pair", as.character(pr$contrast[i]), pr$estimate[i], pr$SE[i],
                                 pr$df[i], pr$t.ratio[i], pr$p.value[i], isSingular(fit))
# Subjects with one trial each: lme4 refuses (1 | subject); the model without it.
d <- load("one_trial")
d$group <- factor(d$group, levels = c("unguided", "fixture", "fading"))
coefs("one_trial", lmer(y ~ group + (1 | characters), data = d), "Satterthwaite")
# Within subjects: a random condition slope per subject.
d <- load("within")
d$condition <- factor(d$condition, levels = c("unguided", "fixture"))
coefs("within", lmer(y ~ condition + (1 + condition | subject) + (1 | characters), data = d), "Satterthwaite")
# A crossover: period and item set fixed; the carry-over F of sequence added.
for (job in c("crossover", "mixed")) {
  d <- load(job)
  d$condition <- factor(d$condition, levels = c("unguided", "amplify"))
  d$period <- factor(d$period)
  d$item_set <- factor(d$item_set)
  d$sequence <- factor(d$sequence)
  if (job == "crossover") {
    fit <- lmer(y ~ condition + period + item_set + (1 + condition | subject) + (1 | characters), data = d)
    coefs(job, fit, "Satterthwaite")
    carry <- lmer(y ~ condition + period + item_set + sequence + (1 + condition | subject) + (1 | characters),
                  data = d)
    a <- anova(carry, ddf = "Satterthwaite")
    add(job, "F", "sequence", NA, NA, a["sequence", "DenDF"], a["sequence", "F value"], a["sequence", "Pr(>F)"],
        isSingular(carry))
  } else {
    d$group <- factor(d$group, levels = c("unguided", "fixture"))
    fit <- lmer(y ~ condition + period + item_set + group + (1 + condition | subject) + (1 | characters), data = d)
    coefs(job, fit, "Satterthwaite")
    inter <- lmer(y ~ condition + period + item_set + group + condition:group + (1 + condition | subject) +
                    (1 | characters), data = d)
    a <- anova(inter, ddf = "Satterthwaite")
    add(job, "F", "condition:group", NA, NA, a["condition:group", "DenDF"], a["condition:group", "F value"],
        a["condition:group", "Pr(>F)"], isSingular(inter))
  }
}
write.csv(do.call(rbind, out), file.path(folder, "reference.csv"), row.names = FALSE)
"""


def r_frame(frame):
    return frame.rename(columns={VALUE: "y"})[["subject", "group", "condition", "characters", "item_set",
                                              "sequence", "period", "y"]]


class Planted:
    """The planted studies, built once, and R's answers for them, from one Rscript run when a case first asks."""
    built = False
    asked_r = False
    reference = None
    error = None
    missing = None

    @classmethod
    def build(cls):
        if cls.built:
            return
        cls.built = True
        cls.between = between_study(11)
        cls.one_trial = between_study(12, training_reps=1, item_sd_mm=1.0)
        # One training trial a subject: each writes one character, in turn.
        keep = []
        for subject, part in cls.one_trial[cls.one_trial.phase == "training"].groupby("subject", sort=False):
            keep.append(part.iloc[[int(subject[1:]) % len(CHARACTERS)]])
        cls.one_trial = pandas.concat([cls.one_trial[cls.one_trial.phase != "training"], *keep])
        cls.within = within_study(13)
        cls.crossover = crossover_study(14, carry_mm=1.2)
        cls.mixed = crossover_study(15, group_of=lambda s: ("unguided", "fixture")[(s // 4) % 2],
                                    group_effect_mm={"fixture": -0.4})

    @classmethod
    def fit_in_r(cls):
        if cls.asked_r:
            return
        cls.asked_r = True
        folder = tempfile.mkdtemp(prefix="round27b-r-")
        try:
            for name, frame in (("between", cls.between[cls.between.phase == "training"]),
                                ("one_trial", cls.one_trial[cls.one_trial.phase == "training"]),
                                ("within", cls.within),
                                ("crossover", cls.crossover[cls.crossover.phase == "training"]),
                                ("mixed", cls.mixed[cls.mixed.phase == "training"])):
                r_frame(frame).to_csv(os.path.join(folder, f"{name}.csv"), index=False, float_format="%.17g")
            script = os.path.join(folder, "reference.R")
            with open(script, "w", encoding="utf-8") as handle:
                handle.write(R_PROGRAM)
            run = subprocess.run(["Rscript", "--vanilla", script, folder], capture_output=True, text=True,
                                 timeout=300)
            if run.returncode == 3:
                cls.missing = "R's emmeans is not installed (Debian: r-cran-emmeans)"
                return
            if run.returncode != 0:
                cls.error = run.stderr
                return
            cls.reference = pandas.read_csv(os.path.join(folder, "reference.csv"), keep_default_na=False,
                                            na_values=["NA"])
        finally:
            shutil.rmtree(folder, ignore_errors=True)

    @classmethod
    def r(cls, job, kind, term):
        table = cls.reference
        hit = table[(table.job == job) & (table.kind == kind) & (table.term == term)]
        assert len(hit) == 1, f"no R result {job} {kind} {term}: {table[table.job == job].term.tolist()}"
        return hit.iloc[0]


def questions(trials, **kw):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        design = design_analysis.study_design(trials)
        return design_analysis.design_questions(trials, VALUE, design, **kw)


def one(table, phase, comparison, family_suffix=None):
    hit = table[(table.phase == phase) & (table.comparison == comparison)]
    if family_suffix is not None:
        hit = hit[hit.family.str.endswith(family_suffix)]
    assert len(hit) == 1, f"{phase} {comparison}: {len(hit)} rows in\n{table[['phase', 'comparison', 'family']]}"
    return hit.iloc[0]


def is_missing(x):
    return x is None or (isinstance(x, float) and math.isnan(x)) or (isinstance(x, str) and x == "")


class Round27bStatistics(unittest.TestCase):
    """The numbers of a study's analysis against independent fits of planted data."""

    @classmethod
    def setUpClass(cls):
        Planted.build()
        cls._cache = {}

    def asked(self, name, trials, **kw):
        if name not in self._cache:
            self._cache[name] = questions(trials, **kw)
        return self._cache[name]

    def require_r(self):
        if not r_ready():
            self.skipTest(R_MISSING)
        Planted.fit_in_r()
        if Planted.missing:
            self.skipTest(Planted.missing)
        self.assertIsNone(Planted.error, f"the test's own R failed: {Planted.error}")

    def assert_matches_r(self, got, ref, scale=1e-3, what=""):
        """A row against R's (estimate, se, df, t, p) in mm, to the tolerances above; the interval is the
        estimate +- the t quantile of R's df times R's standard error."""
        self.assertFalse(bool(ref.singular), f"{what}: the planted data give R a singular fit (test's own)")
        self.assertAlmostEqual(got.estimate / (ref.estimate * scale), 1.0, delta=EST_RTOL, msg=what)
        self.assertAlmostEqual(got.df / ref.df, 1.0, delta=DF_RTOL, msg=what)
        self.assertAlmostEqual(got.statistic / ref.stat, 1.0, delta=T_RTOL, msg=what)
        self.assert_p(got.p, ref.p, what)
        half = scipy_stats.t.ppf(0.975, ref.df) * ref.se * scale
        self.assertAlmostEqual(got.ci95_low, ref.estimate * scale - half, delta=abs(half) * DF_RTOL, msg=what)
        self.assertAlmostEqual(got.ci95_high, ref.estimate * scale + half, delta=abs(half) * DF_RTOL, msg=what)

    def assert_p(self, got, expected, what):
        self.assertAlmostEqual(got, expected, delta=P_ATOL, msg=what)
        self.assertAlmostEqual(got / expected, 1.0, delta=1e-3, msg=what)

    def assert_no_test(self, got, what):
        for column in ("df", "statistic", "p", "p_holm", "ci95_low", "ci95_high"):
            self.assertTrue(is_missing(got[column]), f"{what}: {column} = {got[column]!r} for a row with no test")
        self.assertRegex(str(got.note), r"not (computed|tested)", what)
        self.assertNotRegex(str(got.apa), r"p [=<]", f"{what}: the APA sentence reports a p")

    # ---- planted effects ---------------------------------------------------------------------------------

    def test_planted_group_effect_in_training_is_lmertest_satterthwaite(self):
        self.require_r()
        got = self.asked("between", Planted.between)
        for group in ("fixture", "fading"):
            self.assert_matches_r(one(got, "training", f"{group} - unguided"),
                                  Planted.r("between", "coef", f"group{group}"), what=group)
        self.assertEqual(int(one(got, "training", "fixture - unguided").n), 12, "n: the two groups' subjects")

    def test_kenward_roger_df_are_pbkrtests(self):
        self.require_r()
        got = self.asked("between_kr", Planted.between, ddf="Kenward-Roger")
        self.assert_matches_r(one(got, "training", "fixture - unguided"),
                              Planted.r("between_kr", "coef", "groupfixture"), what="Kenward-Roger")

    def test_pair_without_the_control_is_emmeans_of_the_same_fit(self):
        self.require_r()
        got = self.asked("between", Planted.between)
        self.assert_matches_r(one(got, "training", "fading - fixture"),
                              Planted.r("between", "pair", "fading - fixture"), what="fading - fixture")

    def test_holm_is_within_one_outcome_and_phase(self):
        self.require_r()
        got = self.asked("between", Planted.between)
        for phase in ("training", "post-test", "retention"):
            family = got[(got.phase == phase) & (got.family == f"{VALUE}, {phase}")]
            self.assertEqual(len(family), 3, f"{phase}: three pairs of three groups")
            np.testing.assert_allclose(family.p_holm.to_numpy(float), holm(family.p.to_numpy(float)),
                                       rtol=1e-12, err_msg=phase)

    def test_ancova_of_a_planted_post_test_effect_is_ols(self):
        got = self.asked("between", Planted.between)
        expected = ancova_ols(Planted.between, "post-test", GROUPS)
        for group, (est, se, df, t, p) in expected.items():
            r = one(got, "post-test", f"{group} - unguided")
            self.assertAlmostEqual(r.estimate / est, 1.0, delta=1e-9)
            self.assertEqual(float(r.df), df)
            self.assertAlmostEqual(r.statistic / t, 1.0, delta=1e-9)
            self.assertAlmostEqual(r.p / p, 1.0, delta=1e-7)
            half = scipy_stats.t.ppf(0.975, df) * se
            self.assertAlmostEqual(r.ci95_low, est - half, delta=half * 1e-9)
            self.assertEqual(int(r.n), 12, "n counts the subjects of the two groups compared")

    def test_ancova_hedges_g_interval_is_hedges_olkin_5_14(self):
        got = self.asked("between", Planted.between)
        r = one(got, "post-test", "fixture - unguided")
        n1 = n2 = 6
        half = 1.959963984540054 * math.sqrt((n1 + n2) / (n1 * n2) + r.g ** 2 / (2 * (n1 + n2)))
        self.assertTrue(math.isfinite(r.g) and r.g < 0, f"g = {r.g} for a planted lower post-test")
        self.assertAlmostEqual(r.g_ci95_low, r.g - half, delta=1e-3)
        self.assertAlmostEqual(r.g_ci95_high, r.g + half, delta=1e-3)

    def test_planted_retention_loss_gives_the_documented_ratio(self):
        design = design_analysis.study_design(Planted.between)
        got = design_analysis.retention_ratios(Planted.between, VALUE, design).set_index("group")
        means = Planted.between.groupby(["subject", "group", "phase"]).agg(v=(VALUE, "mean")).reset_index()
        wide = means.pivot_table(index=["subject", "group"], columns="phase", values="v").reset_index()
        for group in GROUPS:
            part = wide[wide.group == group]
            gains = (part["pre-test"] - part["post-test"]).to_numpy()
            ratio = (part["pre-test"] - part["retention"]).mean() / gains.mean()
            half = scipy_stats.t.ppf(0.975, len(gains) - 1) * gains.std(ddof=1) / math.sqrt(len(gains))
            self.assertLess(half, gains.mean(), "the planted gain is reliable (test's own)")
            self.assertAlmostEqual(got.loc[group, "retention_ratio"], ratio, delta=1e-9, msg=group)
            self.assertAlmostEqual(got.loc[group, "gain"], gains.mean(), delta=1e-12)
        self.assertLess(got.loc["fading", "retention_ratio"], got.loc["unguided", "retention_ratio"])

    def test_group_without_a_reliable_gain_has_no_retention_ratio(self):
        trials = between_study(21, post_mm=(0.0, 0.8, 0.0))  # fixture's post-test undoes the -0.8 mm gain
        design = design_analysis.study_design(trials)
        got = design_analysis.retention_ratios(trials, VALUE, design).set_index("group")
        self.assertTrue(math.isnan(got.loc["fixture", "retention_ratio"]))
        self.assertRegex(str(got.loc["fixture", "note"]), r"not computed|gain")
        self.assertTrue(math.isfinite(got.loc["unguided", "retention_ratio"]))

    def test_planted_practice_slope_in_subject_means(self):
        trials = between_study(22, slope_mm=-0.25, training_reps=4)
        training = trials[trials.phase == "training"]
        got = statistics.describe(training, VALUE, by=("repetition",), unit="subject").set_index("repetition")
        subject_means = training.groupby(["repetition", "subject"])[VALUE].mean()
        for rep, part in subject_means.groupby(level=0):
            self.assertEqual(int(got.loc[rep, "n"]), 18)
            self.assertAlmostEqual(got.loc[rep, "mean"], part.mean(), delta=1e-15)
            self.assertAlmostEqual(got.loc[rep, "sd"], part.std(ddof=1), delta=1e-15)
        slope = np.polyfit(got.index.to_numpy(float), got["mean"].to_numpy(), 1)[0]
        self.assertAlmostEqual(slope, -0.25e-3, delta=0.05e-3, msg="the planted slope per repetition")

    def test_within_subjects_condition_effect_is_lmertest_with_a_random_slope(self):
        self.require_r()
        got = self.asked("within", Planted.within)
        mixed = got[(got.phase == "test") & (got.comparison == "fixture - unguided") &
                    ~got.family.str.endswith("(checks)")]
        self.assertEqual(len(mixed), 1)
        self.assertIn("(1 + condition | subject)", mixed.iloc[0].model)
        self.assert_matches_r(mixed.iloc[0], Planted.r("within", "coef", "conditionfixture"), what="within")

    def test_within_subjects_paired_check_is_scipy_ttest_rel_and_g_av_as_defined(self):
        got = self.asked("within", Planted.within)
        check = got[(got.phase == "test") & got.family.str.endswith("(checks)")]
        self.assertEqual(len(check), 1)
        check = check.iloc[0]
        means = Planted.within.groupby(["subject", "condition"])[VALUE].mean().unstack()
        test = scipy_stats.ttest_rel(means["fixture"], means["unguided"])
        self.assertAlmostEqual(check.statistic, test.statistic, delta=1e-9 * abs(test.statistic))
        self.assertAlmostEqual(check.p, test.pvalue, delta=1e-9)
        self.assertEqual(float(check.df), len(means) - 1)
        self.assertTrue(is_missing(check.p_holm) or check.p_holm == check.p, "a check is not adjusted")
        diff = means["fixture"] - means["unguided"]
        d_av = diff.mean() / ((means["fixture"].std(ddof=1) + means["unguided"].std(ddof=1)) / 2)
        g_av = d_av * (1 - 3 / (4 * (len(diff) - 1) - 1))
        self.assertAlmostEqual(check.g, g_av, delta=1e-9)

    def test_crossover_condition_effect_is_lmertest_with_period_and_set(self):
        self.require_r()
        got = self.asked("crossover", Planted.crossover)
        r = got[(got.phase == "training") & (got.comparison == "amplify - unguided") &
                ~got.family.str.endswith("(checks)")]
        self.assertEqual(len(r), 1, got[["phase", "comparison", "family"]])
        self.assertIn("period", r.iloc[0].model)
        self.assertIn("item_set", r.iloc[0].model)
        self.assert_matches_r(r.iloc[0], Planted.r("crossover", "coef", "conditionamplify"), what="crossover")

    def test_planted_carry_over_is_the_f_test_of_sequence(self):
        self.require_r()
        got = self.asked("crossover", Planted.crossover)
        ref = Planted.r("crossover", "F", "sequence")
        self.assert_f_check(got, "carry-over", ref)
        self.assertLess(ref.p, 0.05, "test's own: the planted carry-over is found")

    def assert_f_check(self, got, words, ref):
        """The design's check whose test names `words` against R's F: F and its df to DF_RTOL (an F is a
        square: twice a t's error), p to P_ATOL; unadjusted."""
        checks = got[got.family.str.endswith("(checks)")]
        hit = checks[checks.test.str.contains(words, na=False)]
        self.assertEqual(len(hit), 1, checks[["question", "test"]])
        hit = hit.iloc[0]
        self.assertFalse(bool(ref.singular), f"test's own: R's model with {words} is singular")
        self.assertAlmostEqual(hit.statistic / ref.stat, 1.0, delta=DF_RTOL, msg=words)
        self.assertAlmostEqual(hit.df / ref.df, 1.0, delta=DF_RTOL, msg=words)
        self.assertAlmostEqual(hit.p, ref.p, delta=P_ATOL, msg=words)
        self.assertTrue(is_missing(hit.p_holm), f"{words}: a check is not adjusted")
        return hit

    def hills_armitage(self, trials):
        training = trials[trials.phase == "training"]
        means = training.groupby(["subject", "sequence", "period"])[VALUE].mean().unstack("period").dropna()
        half = (means[1] - means[2]) / 2
        seq = means.index.get_level_values("sequence")
        return scipy_stats.ttest_ind(half[seq == "BA"], half[seq == "AB"]), len(half)

    def hills_armitage_row(self, got):
        checks = got[got.family.str.endswith("(checks)") & (got.phase == "training")]
        hit = checks[checks.test.str.contains("Hills", case=False, na=False) |
                     checks.question.str.contains("Hills", case=False, na=False) |
                     checks.model.str.contains("Hills", case=False, na=False)]
        self.assertEqual(len(hit), 1, checks[["question", "test", "model"]])
        return hit.iloc[0]

    def test_hills_armitage_is_a_two_sample_t_of_half_period_differences(self):
        got = self.asked("crossover", Planted.crossover)
        test, n = self.hills_armitage(Planted.crossover)
        r = self.hills_armitage_row(got)
        self.assertEqual(float(r.df), n - 2)
        self.assertAlmostEqual(r.statistic, test.statistic, delta=1e-9 * abs(test.statistic))
        self.assertAlmostEqual(r.p, test.pvalue, delta=1e-9)

    def test_crossover_subject_missing_a_period_leaves_hills_armitage_with_those_complete(self):
        trials = crossover_study(16, drop_period2_of=(0, 5))
        got = questions(trials)
        test, n = self.hills_armitage(trials)
        self.assertEqual(n, 14)
        r = self.hills_armitage_row(got)
        self.assertEqual(float(r.df), 12.0)
        self.assertAlmostEqual(r.statistic, test.statistic, delta=1e-9 * abs(test.statistic))
        main = got[(got.phase == "training") & (got.comparison == "amplify - unguided") &
                   ~got.family.str.endswith("(checks)")]
        self.assertEqual(len(main), 1)
        self.assertEqual(int(main.iloc[0].n), 16, "n counts every subject the model has")

    def test_mixed_design_has_group_and_its_condition_by_group_f(self):
        self.require_r()
        got = self.asked("mixed", Planted.mixed)
        r = got[(got.phase == "training") & (got.comparison == "amplify - unguided") &
                ~got.family.str.endswith("(checks)")]
        self.assertEqual(len(r), 1)
        self.assertIn("group", r.iloc[0].model)
        self.assert_matches_r(r.iloc[0], Planted.r("mixed", "coef", "conditionamplify"), what="mixed")
        self.assert_f_check(got, "condition x group", Planted.r("mixed", "F", "condition:group"))

    def test_group_comparison_is_welch_and_hedges_g_as_defined(self):
        table = statistics.learning(Planted.between, VALUE, pre="pre-test", post="post-test",
                                    retention="retention")
        got = statistics.group_comparison(table, "gain", "fixture", "unguided")
        a = table[table.group == "fixture"].gain.to_numpy()
        b = table[table.group == "unguided"].gain.to_numpy()
        welch = scipy_stats.ttest_ind(a, b, equal_var=False)
        self.assertAlmostEqual(got.t, welch.statistic, delta=1e-9 * abs(welch.statistic))
        self.assertAlmostEqual(got.p, welch.pvalue, delta=1e-9)
        va, vb = a.var(ddof=1) / len(a), b.var(ddof=1) / len(b)
        self.assertAlmostEqual(got.df, (va + vb) ** 2 / (va ** 2 / (len(a) - 1) + vb ** 2 / (len(b) - 1)), delta=1e-9)
        pooled = math.sqrt(((len(a) - 1) * a.var(ddof=1) + (len(b) - 1) * b.var(ddof=1)) / (len(a) + len(b) - 2))
        g = (a.mean() - b.mean()) / pooled * (1 - 3 / (4 * (len(a) + len(b)) - 9))
        self.assertAlmostEqual(got.g, g, delta=1e-9)

    # ---- degenerate designs -----------------------------------------------------------------------------

    def test_one_subject_per_group_gives_no_test(self):
        trials = between_study(31, per_group=1)
        got = questions(trials)
        self.assertGreater(len(got), 0)
        for _, r in got.iterrows():
            self.assert_no_test(r, f"{r.phase} {r.comparison} with one subject per group")

    def test_group_with_no_trial_left_keeps_its_rows_not_computed(self):
        self.require_r()
        trials = between_study(32)
        trials.loc[trials.group == "fading", "end_reason"] = "gave_up"
        got = questions(trials)
        for phase in ("training", "post-test"):
            self.assert_no_test(one(got, phase, "fading - unguided"), f"{phase}: fading has no trial")
            self.assertTrue(math.isfinite(one(got, phase, "fixture - unguided").p), phase)

    def test_constant_outcome_gives_no_p_anywhere(self):
        trials = between_study(33)
        trials[VALUE] = 2e-3
        got = questions(trials)
        self.assertGreater(len(got), 0)
        for _, r in got.iterrows():
            self.assert_no_test(r, f"{r.phase} {r.comparison} of a constant outcome")

    def test_infinite_outcome_counts_as_missing_with_a_warning(self):
        trials = Planted.between[Planted.between.phase == "post-test"].copy()
        trials.iloc[[0, 5], trials.columns.get_loc(VALUE)] = [math.inf, -math.inf]
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            got = statistics.describe(trials, VALUE, by=("group",), unit="trial").set_index("group")
        self.assertTrue(any(issubclass(w.category, statistics.NonFiniteValueWarning) and VALUE in str(w.message)
                            for w in caught), [str(w.message) for w in caught])
        self.assertEqual(int(got["n_missing"].sum()), 2)
        finite = trials[np.isfinite(trials[VALUE])]
        for group, part in finite.groupby("group"):
            self.assertEqual(int(got.loc[group, "n"]), len(part))
            self.assertAlmostEqual(got.loc[group, "mean"], part[VALUE].mean(), delta=1e-15)

    def test_constant_outcome_is_refused_by_group_comparison_naming_it(self):
        table = pandas.DataFrame({"subject": [f"S{i}" for i in range(8)], "group": ["a"] * 4 + ["b"] * 4,
                                  "gain": [1e-3] * 8})
        with self.assertRaisesRegex(ValueError, "'gain'"):
            statistics.group_comparison(table, "gain", "a", "b")

    def test_every_outcome_nan_in_one_cell_leaves_that_row_alone_not_computed(self):
        trials = between_study(34)
        trials.loc[(trials.group == "fixture") & (trials.phase == "post-test"), VALUE] = math.nan
        got = questions(trials)
        self.assert_no_test(one(got, "post-test", "fixture - unguided"), "fixture's post-test all NaN")
        est, se, df, t, p = ancova_ols(trials, "post-test", ("unguided", "fading"))["fading"]
        r = one(got, "post-test", "fading - unguided")
        self.assertAlmostEqual(r.estimate / est, 1.0, delta=1e-9)
        self.assertEqual(float(r.df), df)
        self.assertTrue(math.isfinite(one(got, "retention", "fixture - unguided").p))

    def test_pre_test_collinear_with_group_is_not_computed(self):
        trials = between_study(35)
        pre = trials.phase == "pre-test"
        # Each group's pre-test the same for all its subjects, different between groups: pre-test is group.
        trials.loc[pre, VALUE] = trials.loc[pre, "group"].map({"unguided": 3e-3, "fixture": 3.2e-3,
                                                               "fading": 2.9e-3})
        got = questions(trials)
        for phase in ("post-test", "retention"):
            for comparison in ("fixture - unguided", "fading - unguided", "fading - fixture"):
                self.assert_no_test(one(got, phase, comparison), f"{phase} {comparison}: pre-test is the group")

    def test_subjects_with_one_trial_are_fitted_without_the_subject_term(self):
        self.require_r()
        got = self.asked("one_trial", Planted.one_trial)
        r = one(got, "training", "fixture - unguided")
        self.assertNotIn("(1 | subject)", r.model)
        self.assertRegex(str(r.note), r"subject")
        self.assert_matches_r(r, Planted.r("one_trial", "coef", "groupfixture"), what="one trial a subject")

    def assert_same_rows_scaled(self, factor):
        base = self.asked("between", Planted.between)
        trials = Planted.between.copy()
        trials[VALUE] = trials[VALUE] * factor
        got = questions(trials)
        self.assertEqual(list(got.comparison), list(base.comparison))
        for (_, a), (_, b) in zip(base.iterrows(), got.iterrows()):
            what = f"{a.phase} {a.comparison} x {factor:g}"
            self.assertEqual(a.model, b.model, what)
            self.assertAlmostEqual(b.estimate / (a.estimate * factor), 1.0, delta=1e-6, msg=what)
            for column in ("df", "statistic", "p", "g"):
                if is_missing(a[column]):
                    self.assertTrue(is_missing(b[column]), what)
                else:
                    self.assertAlmostEqual(b[column], a[column], delta=1e-5 * max(1.0, abs(a[column])), msg=what)

    def test_outcome_at_1e6_mm_gives_the_same_tests(self):
        self.require_r()
        self.assert_same_rows_scaled(1e6)

    def test_outcome_at_1e_9_mm_gives_the_same_tests(self):
        self.require_r()
        self.assert_same_rows_scaled(1e-9)

    def test_subject_ids_spelt_like_r_values_are_each_their_own_subject(self):
        self.require_r()
        names = ["NA", "TRUE", "FALSE", "T", "F", "1e5", "100000", "Inf", "-1", "1.0", "1", "01", "NaN", "null",
                 "0x10", "16", "007", "7"]
        relabel = {f"S{i + 1:02d}": name for i, name in enumerate(names)}
        trials = Planted.between.copy()
        trials["subject"] = trials["subject"].map(relabel)
        got = questions(trials)
        self.assert_matches_r(one(got, "training", "fixture - unguided"),
                              Planted.r("between", "coef", "groupfixture"), what="ids like R's values")
        self.assertEqual(int(one(got, "training", "fixture - unguided").n), 12, "n: the two groups' subjects")

    def test_subject_ids_numbers_in_one_table_and_padded_text_in_another_stay_apart(self):
        self.require_r()
        trials = Planted.between.copy()
        # Half the subjects from a table read with numbers guessed (7), half with ids kept as text ("07"):
        # subject 7 and subject "07" are two people.
        number = trials["subject"].str[1:].astype(int)
        trials["subject"] = [n if n % 2 else f"0{n - 1}" for n in number]  # 1 and "01", 3 and "03", ...
        self.assertEqual(trials["subject"].map(repr).nunique(), 18, "test's own: 18 distinct ids")
        try:
            got = questions(trials)
        except (TypeError, ValueError) as error:
            self.assertIn("subject", str(error))
            return
        self.assertEqual(int(one(got, "training", "fixture - unguided").n), 12, "n: the two groups' subjects")
        self.assert_matches_r(one(got, "training", "fixture - unguided"),
                              Planted.r("between", "coef", "groupfixture"), what="ids of two types")


if __name__ == "__main__":
    unittest.main()
