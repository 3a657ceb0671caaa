#!/usr/bin/env python3
"""Round 16C: the study's statistics as a reviewer in motor learning would attack them, from the docs alone
(docs/experiments.md "A report for a paper", docs/learning-study.md sections 4-6, docs/python.md and the
docstrings of calligraphy.design_analysis, calligraphy.statistics, calligraphy.mixed_models and
calligraphy.study_report). Run by CTest as `cli_unseen_round16c_tests`.

Outcomes are planted on the structure of simulated cohorts (`calligraphy.cohort.simulate` of tiny protocols on
the tiny characters 一 二 十 三, every trial then marked completed and given a planted deviation): between subjects
(two and three groups, balanced and not), a crossover of two item sets, and the same beside a between-subjects
group (a mixed design). The library's rows (`design_questions`, the report's
tables) are held to R's lme4/lmerTest/pbkrtest/emmeans and `lm` fitted on the same rows by ONE `Rscript` process
for every reference fit (the whole class is skipped, saying so, without Rscript): estimate, df, t, p, interval,
Holm, the carry-over F, Hills-Armitage's t and the condition x group F. Degenerate designs (one subject per group, a group of none, a
constant outcome, a perfectly separated one, a singular fit, a missing retention cell, 1e-300 and 1e300 outcomes,
every value equal but one, odd group names) must give R's number or no p with a reason, never a made-up one. The
R process itself: absent (the page still made, "not computed"), slow and printing at start-up (the same numbers).

CALLIGRAPHY_CLI names the program, PYTHONPATH its Python module. CALLIGRAPHY_SANITIZED=1 takes five cases.
"""
import csv
import json
import math
import pickle
import shutil
import subprocess
import sys
import tempfile
import unittest
import warnings
from pathlib import Path

from outsider import CLI, ENV, SANITIZED, run, sanitized_subset

load_tests = sanitized_subset({"test_between_training_is_lmertest_satterthwaite",
                               "test_ancova_after_training_is_rs_lm",
                               "test_every_row_is_a_well_formed_result",
                               "test_constant_outcome_has_no_made_up_p",
                               "test_without_r_the_page_is_still_made"})

RSCRIPT = shutil.which("Rscript")
YI, SHI, ER, SAN = "一", "十", "二", "三"
TINY = {"max_duration_s": 0.3}
BETWEEN = {"name": "b16c",
           "conditions": [{"name": "unguided", "mode": "vision"}, {"name": "fixture", "mode": "haptic"}],
           "phases": [{"phase": "pre-test", "condition": "unguided", "characters": [YI, SHI]},
                      {"phase": "training", "conditions": ["unguided", "fixture"], "assignment": "between-subjects",
                       "characters": [YI, SHI], "repetitions": 2},
                      {"phase": "post-test", "condition": "unguided", "characters": [YI, SHI]},
                      {"phase": "retention", "condition": "unguided", "characters": [YI, SHI], "session": 2,
                       "delay_s": 86400}],
           "trial": TINY}
THREE = {"name": "t16c",
         "conditions": [{"name": "unguided", "mode": "vision"}, {"name": "fixture", "mode": "haptic"},
                        {"name": "fading", "mode": "haptic"}],
         "phases": [{"phase": "pre-test", "condition": "unguided", "characters": [YI, SHI]},
                    {"phase": "training", "conditions": ["unguided", "fixture", "fading"],
                     "assignment": "between-subjects", "characters": [YI, SHI], "repetitions": 2},
                    {"phase": "post-test", "condition": "unguided", "characters": [YI, SHI]}],
         "trial": TINY}
CROSSOVER = {"name": "x16c",
             "conditions": [{"name": "unguided", "mode": "vision"}, {"name": "amplify", "mode": "error-amplification"}],
             "item_sets": [{"name": "set1", "characters": [YI, ER]}, {"name": "set2", "characters": [SHI, SAN]}],
             "phases": [{"phase": "pre-test", "condition": "unguided", "sets": ["set1", "set2"]},
                        {"phase": "training", "conditions": ["unguided", "amplify"], "assignment": "crossover",
                         "sets": ["set1", "set2"], "repetitions": 2},
                        {"phase": "post-test", "condition": "unguided", "sets": ["set1", "set2"]}],
             "trial": TINY}
# A mixed design: a between-subjects practice phase (a group per subject) beside the crossover.
MIXED = {"name": "m16c",
         "conditions": [{"name": "unguided", "mode": "vision"}, {"name": "amplify", "mode": "error-amplification"},
                        {"name": "fixture", "mode": "haptic"}],
         "item_sets": CROSSOVER["item_sets"],
         "phases": [{"phase": "practice", "conditions": ["unguided", "fixture"], "assignment": "between-subjects",
                     "characters": [YI]}] + CROSSOVER["phases"],
         "trial": TINY}
VALUE = "mean_deviation_m"
ITEM_MM = {YI: -0.3, SHI: 0.3, ER: -0.1, SAN: 0.1}
# The planted advantage of the treatment, per phase [mm].
EFFECT_MM = {"pre-test": 0.0, "training": -0.5, "post-test": -0.3, "retention": -0.2}
SHARED = {}

# One R process for every reference fit: each job, a line of its standard input, reads its CSV (only the empty
# field missing, as docs/experiments.md says) and runs its code, which calls emit(key, value); errors are emitted
# too.
R_PROGRAM = r"""
suppressPackageStartupMessages({library(lmerTest); library(emmeans); library(pbkrtest)})
args <- commandArgs(trailingOnly = TRUE)
jobs <- file("stdin", open = "r", encoding = "UTF-8")
while (length(line <- readLines(jobs, n = 1, encoding = "UTF-8")) > 0) {
  parts <- strsplit(line, "\t", fixed = TRUE)[[1]]
  label <- parts[1]
  out <- file(file.path(args[1], paste0(label, ".tsv")), open = "w", encoding = "UTF-8")
  emit <- function(key, value) writeLines(paste(key, sprintf("%.17g", as.numeric(value)), sep = "\t"), out)
  d <- read.csv(parts[2], encoding = "UTF-8", na.strings = "", stringsAsFactors = FALSE)
  result <- tryCatch({
    withCallingHandlers(eval(parse(text = readLines(parts[3], encoding = "UTF-8"))),
                        warning = function(w) invokeRestart("muffleWarning"))
    "ok"
  }, error = function(e) conditionMessage(e))
  writeLines(paste("status", gsub("[\t\n]", " ", result), sep = "\t"), out)
  close(out)
}
"""
# A mixed model's fixed effect: `term` of `formula`, R's singular and convergence verdicts, with `ddf`.
R_LMER = r"""
d$subject <- factor(d$subject); d$item <- factor(d$item)
for (f in c(%(factors)s)) d[[f]] <- factor(d[[f]], levels = unique(d[[f]][order(d[[paste0(f, "_rank")]])]))
unit <- 10^(-floor(log10(sd(d$y))))  # the power of ten that brings the outcome's SD between 1 and 10
d$y <- d$y * unit
fit <- lmer(%(formula)s, data = d, REML = TRUE)
emit("singular", isSingular(fit))
emit("converged", length(fit@optinfo$conv$lme4$messages) == 0)
s <- summary(fit, ddf = "%(ddf)s")$coefficients
row <- s["%(term)s", ]
emit("estimate", row[["Estimate"]] / unit); emit("se", row[["Std. Error"]] / unit); emit("df", row[["df"]])
emit("t", row[["t value"]]); emit("p", row[["Pr(>|t|)"]])
%(extra)s
"""


def r_lmer(formula, term, factors, ddf="Satterthwaite", extra=""):
    quoted = ", ".join(f'"{f}"' for f in factors)
    return R_LMER % {"formula": formula, "term": term, "factors": quoted, "ddf": ddf, "extra": extra}


def plant(trials, seed, *, effect=EFFECT_MM, subject_sd=0.4, noise_sd=0.15, by="group", treated=("fixture",),
          scale=1e-3):
    """`trials` with every trial completed and a planted deviation [m]: 2 mm, a subject's offset, the item's, the
    treatment's advantage in each phase for the subjects (rows) whose `by` is treated, and noise."""
    import numpy as np
    rng = np.random.default_rng(seed)
    out = trials.copy()
    subjects = {s: rng.normal(0, subject_sd) for s in sorted(out.subject.unique())}
    values = []
    for row in out.itertuples():
        weights = treated if isinstance(treated, dict) else {name: 1.0 for name in treated}
        gain = weights.get(str(getattr(row, by)), 0.0) * effect.get(str(row.phase), 0.0)
        values.append(2.0 + subjects[row.subject] + ITEM_MM[row.characters] + gain + rng.normal(0, noise_sd))
    out[VALUE] = np.array(values) * scale
    out["end_reason"] = "completed"
    return out


def rows(questions, phase=None, comparison=None, family=None):
    """The rows of `questions` for a phase / comparison / family."""
    picked = questions
    if phase is not None:
        picked = picked[picked.phase.astype(str) == phase]
    if comparison is not None:
        picked = picked[picked.comparison == comparison]
    if family is not None:
        picked = picked[picked.family == family]
    return picked


def one(questions, **kw):
    picked = rows(questions, **kw)
    assert len(picked) == 1, \
        f"expected one row for {kw}, got {len(picked)}:\n{questions[['phase', 'comparison', 'family']]}"
    return picked.iloc[0]


def subject_means(trials, phase):
    return trials[trials.phase.astype(str) == phase].groupby("subject", observed=True)[VALUE].mean()


@unittest.skipUnless(CLI, "CALLIGRAPHY_CLI is not set")
@unittest.skipUnless(RSCRIPT, "Rscript is not installed: the library's statistics cannot be checked against R here")
class Round16C(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        import numpy as np
        import pandas as pd
        from calligraphy import design_analysis
        cls.np, cls.pd, cls.da = np, pd, design_analysis
        cls.tmp = Path(tempfile.mkdtemp(prefix="r16c-"))
        # The reference R loads its packages and fits each job as it is sent, beside the library's fits.
        cls.start_r()
        try:
            cls.make_scenarios()
        except BaseException:
            cls.r_process.kill()
            cls.r_process.wait()
            raise

    @classmethod
    def make_scenarios(cls):
        np, design_analysis = cls.np, cls.da
        from calligraphy import cohort
        structure = {}
        for name, protocol, n in (("between", BETWEEN, 12), ("three", THREE, 9), ("crossover", CROSSOVER, 8),
                                     ("mixed", MIXED, 8)):
            path = cls.tmp / f"{name}.json"
            path.write_text(json.dumps(protocol, ensure_ascii=False), encoding="utf-8")
            structure[name] = cohort.simulate(path, n, progress=False).trials
        cls.structure = structure
        cls.frames, cls.questions, cls.errors, cls.jobs = {}, {}, {}, []

        def analyse(label, frame, **kw):
            cls.frames[label] = frame
            try:
                with warnings.catch_warnings(record=True) as caught:
                    warnings.simplefilter("always")
                    cls.questions[label] = design_analysis.design_questions(frame, VALUE, **kw)
                cls.questions[label].attrs["warnings"] = [str(w.message) for w in caught]
            except Exception as error:  # noqa: BLE001 - each case reports its own scenario's error
                cls.errors[label] = error

        between = plant(structure["between"], 1)
        three = plant(structure["three"], 2, treated={"fixture": 1.0, "fading": 0.5})
        crossover = plant(structure["crossover"], 3, by="trained_condition", treated=("amplify",), subject_sd=0.5,
                          noise_sd=0.1)
        mixed = plant(structure["mixed"], 5, by="trained_condition", treated=("amplify",), subject_sd=0.5,
                      noise_sd=0.1)
        # Unbalanced: 3 unguided against 6 fixture subjects.
        keep = sorted(between.subject.unique())
        unguided = [s for s in keep if (between[between.subject == s].group.astype(str) == "unguided").all()][:3]
        unbalanced = between[between.subject.isin(unguided) | (between.group.astype(str) == "fixture")]
        unbalanced = unbalanced.reset_index(drop=True)
        # A subject without the retention session.
        lost = between[~((between.subject == keep[0]) & (between.phase.astype(str) == "retention"))]
        lost = lost.reset_index(drop=True)
        # The reference fits that need the rows alone are sent now; those of a row's model once it is fitted.
        cls.frames.update({"between": between, "three": three, "unbalanced": unbalanced, "no_retention": lost})
        cls.build_r_jobs_of_rows()

        analyse("between", between)
        analyse("between_kr", between, ddf="Kenward-Roger")
        analyse("three", three)
        analyse("crossover", crossover)
        cls.crossover_jobs()
        analyse("mixed", mixed)
        cls.mixed_jobs()
        analyse("unbalanced", unbalanced)
        # One subject per group.
        firsts = [keep[0], keep[1]]
        analyse("one_each", between[between.subject.isin(firsts)].reset_index(drop=True))
        cls.degenerate_jobs("one_each")
        # A group of none: every fixture subject's trials ended otherwise than completed.
        none = between.copy()
        none.loc[none.group.astype(str) == "fixture", "end_reason"] = "gave_up"
        analyse("group_of_none", none)
        # A constant outcome; a perfectly separated one (constant within each group, the groups apart): analysed
        # last, below.
        constant = between.copy()
        constant[VALUE] = 0.002
        separated = between.copy()
        separated[VALUE] = np.where(separated.group.astype(str) == "fixture", 0.001, 0.002)
        # Every value equal but one.
        but_one = constant.copy()
        but_one.loc[but_one.index[(but_one.phase.astype(str) == "training")][0], VALUE] = 0.003
        analyse("but_one", but_one)
        cls.degenerate_jobs("but_one")
        # Subjects who all start alike: no subject variance at all, tiny noise (a singular fit).
        alike = plant(structure["between"], 4, subject_sd=0.0, noise_sd=0.05)
        analyse("alike", alike)
        cls.degenerate_jobs("alike")
        analyse("no_retention", lost)
        # The same rows at 1e-300 and 1e300 (metres).
        for label, factor in (("tiny", 1e-300), ("huge", 1e300)):
            scaled = between.copy()
            scaled[VALUE] = scaled[VALUE] * factor
            analyse(label, scaled)
        # Groups named as R's missing value, a logical, a number, with a comma, a quote and a line break.
        cls.odd_names = {"unguided": "NA", "fixture": 'a,"b\nc'}
        odd = between.copy()
        for column in ("group", "condition"):
            odd[column] = odd[column].astype(str).map(lambda v: cls.odd_names.get(v, v))
        analyse("odd", odd, design=design_analysis.study_design(odd, reference="NA"))
        # The cases that fit in R themselves (the page of the odd names, the paired check; not among the cases run
        # under the sanitizers) are fitted here, before the constant and the separated outcome: the library ends its
        # R server after R's answer to each of those (an infinite interval) and starts another for the next fit, so
        # that they come last.
        if not SANITIZED:
            cls.make_page()
            cls.make_paired()
        for label, frame in (("constant", constant), ("separated", separated)):
            analyse(label, frame)
            cls.degenerate_jobs(label)
        cls.run_r()

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.tmp, ignore_errors=True)

    # ---- the reference fits -------------------------------------------------------------------------------------
    @classmethod
    def data_for_r(cls, label, frame, column="group", levels=None):
        """The rows of `frame` for R: subject, item (the characters), the factor, its rank (the control first), the
        outcome in mm (REML and OLS are equivariant under scaling), phase, and the crossover's columns."""
        pd = cls.pd
        kept = frame[frame.end_reason == "completed"]
        table = pd.DataFrame({"subject": kept.subject.astype(str), "item": kept.characters.astype(str),
                              "phase": kept.phase.astype(str), "y": kept[VALUE] * 1e3})
        for name in ("group", "condition", "trained_condition", "item_set", "sequence", "period"):
            if name in kept:
                table[name] = kept[name].astype(str) if name != "period" else kept[name]
        order = levels or []
        table[f"{column}_rank"] = table[column].map(lambda v: order.index(v) if v in order else len(order))
        path = cls.tmp / f"{label}.csv"
        table.to_csv(path, index=False, encoding="utf-8")
        return path

    @classmethod
    def job(cls, label, data, code):
        """Sends R the job `label`: its rows `data` and its `code`."""
        path = cls.tmp / f"{label}.R"
        path.write_text(code, encoding="utf-8")
        cls.jobs.append(f"{label}\t{data}\t{path}")
        try:
            cls.r_process.stdin.write((cls.jobs[-1] + "\n").encode("utf-8"))
            cls.r_process.stdin.flush()
        except OSError:  # R ended: the cases find no result for the job and show what R said
            pass

    @classmethod
    def ancova_job(cls, label, data, phase, group_levels, extra=""):
        code = f"""
unit <- 1
means <- aggregate(y ~ subject + group + phase, data = d, FUN = mean)
pre <- means[means$phase == "pre-test", c("subject", "y")]; names(pre)[2] <- "pre"
post <- means[means$phase == "{phase}", c("subject", "group", "y")]
w <- merge(post, pre, by = "subject")
w$group <- factor(w$group, levels = c({", ".join(json.dumps(g) for g in group_levels)}))
fit <- lm(y ~ pre + group, data = w)
emit("n", nrow(w)); emit("df", df.residual(fit))
co <- summary(fit)$coefficients
term <- paste0("group", levels(w$group)[2])
if (term %in% rownames(co)) {{
  emit("estimate", co[term, 1]); emit("se", co[term, 2]); emit("t", co[term, 3]); emit("p", co[term, 4])
  ci <- confint(fit)[term, ]; emit("ci_low", ci[1]); emit("ci_high", ci[2])
}}
{extra}
"""
        cls.job(label, data, code)

    @classmethod
    def build_r_jobs_of_rows(cls):
        """The reference fits that need only the rows of a scenario."""
        levels = ["unguided", "fixture"]
        data = cls.data_for_r("between", cls.frames["between"], "group", levels)
        training = 'd <- d[d$phase == "training", ]\n'
        for label, ddf in (("between", "Satterthwaite"), ("between_kr", "Kenward-Roger")):
            cls.job(f"{label}_training", data,
                    training + r_lmer("y ~ group + (1 | subject) + (1 | item)", "groupfixture", ["group"], ddf))
        for phase in ("post-test", "retention"):
            cls.ancova_job(f"between_{phase}", data, phase, levels)
        # Three groups: the mixed model's pairs by emmeans, Holm by p.adjust; the ANCOVA's pairs by emmeans of lm.
        three_levels = ["unguided", "fixture", "fading"]
        data3 = cls.data_for_r("three", cls.frames["three"], "group", three_levels)
        pairs = r"""
pr <- as.data.frame(pairs(emmeans(fit, "group", lmer.df = "%s"), reverse = TRUE, adjust = "none"))
for (i in seq_len(nrow(pr))) {
  key <- gsub(" ", "", as.character(pr$contrast[i]))
  emit(paste0(key, ".estimate"), pr$estimate[i] / unit); emit(paste0(key, ".df"), pr$df[i])
  emit(paste0(key, ".t"), pr$t.ratio[i]); emit(paste0(key, ".p"), pr$p.value[i])
}
holm <- p.adjust(pr$p.value, "holm")
for (i in seq_len(nrow(pr))) emit(paste0(gsub(" ", "", as.character(pr$contrast[i])), ".holm"), holm[i])
"""
        cls.job("three_training", data3,
                training + r_lmer("y ~ group + (1 | subject) + (1 | item)", "groupfixture", ["group"],
                                  extra=pairs % "satterthwaite"))
        cls.ancova_job("three_post-test", data3, "post-test", three_levels,
                       extra=(pairs % "satterthwaite").replace(', lmer.df = "satterthwaite"', ""))
        # Unbalanced groups, a missing retention cell, the odd names (the between rows again).
        data_u = cls.data_for_r("unbalanced", cls.frames["unbalanced"], "group", levels)
        cls.job("unbalanced_training", data_u,
                training + r_lmer("y ~ group + (1 | subject) + (1 | item)", "groupfixture", ["group"]))
        cls.ancova_job("unbalanced_post-test", data_u, "post-test", levels)
        data_n = cls.data_for_r("no_retention", cls.frames["no_retention"], "group", levels)
        cls.ancova_job("no_retention_retention", data_n, "retention", levels)

    @classmethod
    def degenerate_jobs(cls, label):
        """A degenerate design's reference fits: R's verdict on the formula each row says it fitted."""
        if label not in cls.questions:
            return
        levels = ["unguided", "fixture"]
        data_d = cls.data_for_r(label, cls.frames[label], "group", levels)
        for i, row in cls.questions[label].iterrows():
            if "(1 |" in str(row.model) or "(1 +" in str(row.model):
                formula = str(row.model).split("~", 1)[1]
                cls.job(f"{label}_mixed{i}", data_d, f'd <- d[d$phase == "{row.phase}", ]\n'
                        + r_lmer("y ~" + formula, "groupfixture", ["group"]))
            elif "ANCOVA" in str(row.test):
                cls.ancova_job(f"{label}_ancova{i}", data_d, str(row.phase), levels)
        if label == "alike":
            cls.job("alike_full", data_d, 'd <- d[d$phase == "training", ]\n'
                    + r_lmer("y ~ group + (1 | subject) + (1 | item)", "groupfixture", ["group"]))

    @classmethod
    def crossover_jobs(cls):
        if "crossover" not in cls.questions:
            return
        levels = ["unguided", "amplify"]
        frame = cls.frames["crossover"].copy()
        data = cls.data_for_r("crossover", frame, "trained_condition", levels)
        prelude = ('d <- d[d$phase == "training", ]\nd$condition <- d$trained_condition\n'
                   'd$condition_rank <- d$trained_condition_rank\nd$period <- factor(d$period)\n'
                   'd$item_set <- factor(d$item_set); d$sequence <- factor(d$sequence)\n')
        q = cls.questions["crossover"]
        training = q[(q.phase.astype(str) == "training") & (q.family == f"{VALUE}, training")]
        if len(training) == 1:
            formula = str(training.iloc[0].model).split("~", 1)[1]
            cls.job("crossover_row", data, prelude + r_lmer("y ~" + formula, "conditionamplify", ["condition"]))
        cls.job("crossover_full", data, prelude + r_lmer(
            "y ~ condition + period + item_set + (1 + condition | subject) + (1 | item)", "conditionamplify",
            ["condition"]))
        carry = r"""
unit <- 10^(-floor(log10(sd(d$y))))
d$y <- d$y * unit
carry <- lmer(y ~ condition + period + item_set + sequence + %s, data = d, REML = TRUE)
a <- anova(carry)["sequence", ]
emit("carry.f", a[["F value"]]); emit("carry.den_df", a[["DenDF"]]); emit("carry.p", a[["Pr(>F)"]])
means <- aggregate(y ~ subject + period + sequence, data = d, FUN = mean)
wide <- reshape(means, idvar = c("subject", "sequence"), timevar = "period", direction = "wide")
half <- (wide$y.1 - wide$y.2) / 2
ha <- t.test(half[wide$sequence == "BA"], half[wide$sequence == "AB"], var.equal = TRUE)
emit("ha.estimate", (ha$estimate[1] - ha$estimate[2]) / unit); emit("ha.t", ha$statistic); emit("ha.df", ha$parameter)
emit("ha.p", ha$p.value)
"""
        random = "(1 | subject) + (1 | item)"
        if len(training) == 1:
            random = str(training.iloc[0].model).split("item_set +", 1)[-1].strip() \
                if "item_set +" in str(training.iloc[0].model) else random
        cls.job("crossover_checks", data, prelude + "library(lmerTest)\n" + carry % random)

    @classmethod
    def mixed_jobs(cls):
        """The mixed design's check: the F test of condition:group in the model its row shows."""
        if "mixed" not in cls.questions:
            return
        q = cls.questions["mixed"]
        check = q[q.comparison == "condition:group"]
        if len(check) != 1:
            return
        data = cls.data_for_r("mixed", cls.frames["mixed"], "trained_condition", ["unguided", "amplify"])
        code = ('d <- d[d$phase == "training", ]\nd$condition <- factor(d$trained_condition, '
                'levels = c("unguided", "amplify"))\nd$group <- factor(d$group, levels = c("unguided", "fixture"))\n'
                'd$period <- factor(d$period); d$item_set <- factor(d$item_set)\n'
                'd$y <- d$y * 10^(-floor(log10(sd(d$y))))\n'
                f'fit <- lmer(y ~{str(check.iloc[0].model).split("~", 1)[1]}, data = d, REML = TRUE)\n'
                'a <- anova(fit)["condition:group", ]\n'
                'emit("f", a[["F value"]]); emit("den_df", a[["DenDF"]]); emit("p", a[["Pr(>F)"]])\n')
        cls.job("mixed_interaction", data, code)

    @classmethod
    def start_r(cls):
        """The one R process of the reference fits, reading its jobs from its standard input (`job`)."""
        (cls.tmp / "r").mkdir()
        (cls.tmp / "fit.R").write_text(R_PROGRAM, encoding="utf-8")
        with open(cls.tmp / "r-output.txt", "wb") as output:
            cls.r_process = subprocess.Popen([RSCRIPT, "--vanilla", str(cls.tmp / "fit.R"), str(cls.tmp / "r")],
                                             stdin=subprocess.PIPE, stdout=output, stderr=subprocess.STDOUT)

    @classmethod
    def run_r(cls):
        """Ends the jobs, waits for R and reads its results."""
        try:
            cls.r_process.stdin.close()
        except OSError:
            pass
        try:
            cls.r_process.wait(timeout=300)
        except subprocess.TimeoutExpired:
            cls.r_process.kill()
            cls.r_process.wait()
        cls.r_stderr = (cls.tmp / "r-output.txt").read_text(encoding="utf-8", errors="replace")
        cls.r = {}
        for path in (cls.tmp / "r").glob("*.tsv"):
            values = {}
            for line in path.read_text(encoding="utf-8").splitlines():
                key, _, value = line.partition("\t")
                values[key] = value if key == "status" else float(value)
            cls.r[path.stem] = values

    @classmethod
    def make_page(cls):
        """`page`: the folder and what `study_report.write_report` gave (its index, or what it raised) for the odd
        names' rows, read by test_page_tables_name_model_contrast_correction_and_n."""
        from calligraphy import study, study_report
        out = cls.tmp / "page"
        strokes = cls.pd.DataFrame(columns=["subject", "session", "trial", "phase", "condition"])
        try:
            index = study_report.write_report(study.Study(cls.frames["odd"], strokes), out, values=(VALUE,),
                                              reference="NA")
        except Exception as error:  # noqa: BLE001 - the case reports it
            index = error
        cls.page = (out, index)

    @classmethod
    def make_paired(cls):
        """`paired`: a within-subjects design of six subjects (its trials) and its design_questions (or what they
        raised), read by test_paired_check_within_subjects_is_scipys."""
        pd, np = cls.pd, cls.np
        rng = np.random.default_rng(7)
        records = []
        for s in range(6):
            offset = rng.normal(0, 0.3)
            for cond, mode, effect in (("vision", "vision", 0.0), ("haptic", "haptic", -0.4)):
                for rep in (1, 2):
                    for ch in (YI, SHI):
                        records.append({"subject": f"S{s:02d}", "session": "s1", "session_number": 1, "group": "",
                                        "phase": "test", "block": 1, "condition": cond, "mode": mode,
                                        "characters": ch, "trial": len(records) + 1, "item": 1, "repetition": rep,
                                        "end_reason": "completed",
                                        VALUE: (2 + offset + effect + ITEM_MM[ch] + rng.normal(0, 0.1)) * 1e-3})
        trials = pd.DataFrame(records)
        try:
            questions = cls.da.design_questions(trials, VALUE)
        except Exception as error:  # noqa: BLE001 - the case reports it
            questions = error
        cls.paired = (trials, questions)

    # ---- helpers --------------------------------------------------------------------------------------------------
    def q(self, label):
        if label in self.errors:
            self.fail(f"design_questions raised on the {label} rows: {self.errors[label]!r}")
        return self.questions[label]

    def reference(self, label):
        self.assertIn(label, self.r, f"R wrote no result for {label}: {self.r_stderr[-2000:]}")
        result = self.r[label]
        self.assertEqual(result.get("status"), "ok", f"R's {label}: {result.get('status')}")
        return result

    def assert_row_is_rs(self, row, ref, *, unit=1e-3, rtol=1e-4, ptol=1e-4):
        """A test row equal to R's: estimate (R in mm), df, t, p and the interval estimate +- t(.975, df) SE."""
        from scipy import stats
        self.assertTrue(math.isclose(row.estimate, ref["estimate"] * unit, rel_tol=rtol), (row.estimate, ref))
        self.assertTrue(math.isclose(row.df, ref["df"], rel_tol=rtol), (row.df, ref["df"]))
        self.assertTrue(math.isclose(row.statistic, ref["t"], rel_tol=rtol), (row.statistic, ref["t"]))
        self.assertLess(abs(row.p - ref["p"]), ptol, (row.p, ref["p"]))
        half = stats.t.ppf(0.975, ref["df"]) * ref["se"] * unit
        self.assertTrue(math.isclose(row.ci95_low, ref["estimate"] * unit - half, rel_tol=rtol, abs_tol=1e-12))
        self.assertTrue(math.isclose(row.ci95_high, ref["estimate"] * unit + half, rel_tol=rtol, abs_tol=1e-12))

    def assert_no_test(self, row, why=""):
        """A row with no df, statistic, p or interval and a note saying why."""
        for column in ("df", "statistic", "p", "p_holm", "ci95_low", "ci95_high"):
            self.assertTrue(self.pd.isna(row[column]), f"{why}: {column} = {row[column]} in {dict(row)}")
        self.assertRegex(str(row.note), r"not (computed|tested)", f"{why}: {dict(row)}")

    def assert_rs_verdict(self, label):
        """Each row of a degenerate design: R's number for the formula it says it fitted, or no test with a
        reason where R's fit is singular, did not converge, or could not be made; never a made-up p."""
        questions = self.q(label)
        self.assertGreater(len(questions), 0)
        for i, row in questions.iterrows():
            if "(1 |" in str(row.model) or "(1 +" in str(row.model):
                ref = self.r.get(f"{label}_mixed{i}", {})
                usable = ref.get("status") == "ok" and ref.get("singular") == 0 and ref.get("converged") == 1 \
                    and math.isfinite(ref.get("p", math.nan))
            elif "ANCOVA" in str(row.test):
                ref = self.r.get(f"{label}_ancova{i}", {})
                usable = ref.get("status") == "ok" and ref.get("df", 0) > 0 and math.isfinite(ref.get("p", math.nan))
            else:
                continue
            if not self.pd.isna(row.p):  # a p given is R's, of a fit R makes and trusts
                self.assertTrue(usable, f"{label}: a p where R has none for {row.model} ({ref}): {dict(row)}")
                self.assert_row_is_rs(row, ref)
            else:  # no p: the note says why, and never calls a fit R trusts singular or not converged
                self.assert_no_test(row, f"{label}: {row.model} ({ref})")
                if usable:
                    self.assertNotRegex(row.note, "singular|did not converge", f"{label}: R trusts the fit ({ref})")

    # ---- planted effects against R ------------------------------------------------------------------------------
    def test_between_training_is_lmertest_satterthwaite(self):
        row = one(self.q("between"), phase="training")
        self.assertEqual(row.comparison, "fixture - unguided")
        self.assertEqual(row.model, f"{VALUE} ~ group + (1 | subject) + (1 | item)")
        self.assertIn("Satterthwaite", row.test)
        self.assert_row_is_rs(row, self.reference("between_training"))
        self.assertLess(row.estimate, 0)  # the planted -0.5 mm

    def test_between_training_kenward_roger_is_pbkrtests(self):
        row = one(self.q("between_kr"), phase="training")
        self.assertIn("Kenward-Roger", row.test)
        self.assert_row_is_rs(row, self.reference("between_kr_training"))

    def test_ancova_after_training_is_rs_lm(self):
        for phase in ("post-test", "retention"):
            row = one(self.q("between"), phase=phase)
            ref = self.reference(f"between_{phase}")
            self.assertIn("ANCOVA", row.test)
            self.assertEqual(row.n, ref["n"])
            self.assert_row_is_rs(row, ref, rtol=1e-9, ptol=1e-9)
            self.assertEqual(row.df, ref["df"])

    def test_three_groups_pairs_are_emmeans_and_holm_is_p_adjust(self):
        questions = self.q("three")
        ref = self.reference("three_training")
        training = rows(questions, phase="training")
        self.assertEqual(sorted(training.comparison),
                         sorted(["fixture - unguided", "fading - unguided", "fading - fixture"]))
        self.assertEqual(set(training.family), {f"{VALUE}, training"})
        for row in training.itertuples():
            key = row.comparison.replace(" ", "")
            self.assertTrue(math.isclose(row.estimate, ref[f"{key}.estimate"] * 1e-3, rel_tol=1e-4), key)
            self.assertTrue(math.isclose(row.df, ref[f"{key}.df"], rel_tol=1e-4), key)
            self.assertTrue(math.isclose(row.statistic, ref[f"{key}.t"], rel_tol=1e-4), key)
            self.assertLess(abs(row.p - ref[f"{key}.p"]), 1e-4, key)
            self.assertLess(abs(row.p_holm - ref[f"{key}.holm"]), 1e-4, key)

    def test_three_groups_ancova_pairs_are_emmeans_of_lm(self):
        ref = self.reference("three_post-test")
        post = rows(self.q("three"), phase="post-test")
        self.assertEqual(len(post), 3, post[["comparison", "note"]])
        for row in post.itertuples():
            key = row.comparison.replace(" ", "")
            self.assertTrue(math.isclose(row.estimate, ref[f"{key}.estimate"] * 1e-3, rel_tol=1e-9), key)
            self.assertEqual(row.df, ref[f"{key}.df"], key)
            self.assertTrue(math.isclose(row.statistic, ref[f"{key}.t"], rel_tol=1e-9), key)
            self.assertLess(abs(row.p - ref[f"{key}.p"]), 1e-9, key)
            self.assertLess(abs(row.p_holm - ref[f"{key}.holm"]), 1e-9, key)

    def test_crossover_training_is_rs_fit_of_its_formula(self):
        questions = self.q("crossover")
        row = one(questions, family=f"{VALUE}, training")
        full = self.reference("crossover_full")
        self.assertIn("period", row.model)
        self.assertIn("item_set", row.model)  # the sets rotate across the sequences
        if full["singular"] == 1 or full["converged"] == 0:
            self.assertIn("reduced", row.note, "R finds the full model singular or not converged")
        else:
            self.assertEqual(row.model.split("~", 1)[1].replace(" ", ""),
                             "condition+period+item_set+(1+condition|subject)+(1|item)")
        ref = self.reference("crossover_row")
        if ref["singular"] == 1 or ref["converged"] == 0:
            self.assert_no_test(row, "R: the row's own formula is singular")
        else:
            self.assert_row_is_rs(row, ref)
        self.assertEqual(row.comparison, "amplify - unguided")
        self.assertEqual(row.n, 8)

    def test_crossover_checks_are_rs_carry_over_and_hills_armitage(self):
        checks = rows(self.q("crossover"), family=f"{VALUE} (checks)")
        ref = self.reference("crossover_checks")
        carry = checks[checks.question.str.contains("carry", case=False)]
        hills = checks[checks.question.str.contains("Hills", case=False)
                       & (checks.phase.astype(str) == "training")]
        self.assertEqual(len(carry), 1, checks[["question", "phase"]])
        self.assertEqual(len(hills), 1, checks[["question", "phase"]])
        carry, hills = carry.iloc[0], hills.iloc[0]
        # The random slope's optimum is flat: lme4 ends within 1e-3 of it from another start (another row order).
        self.assertTrue(math.isclose(carry.statistic, ref["carry.f"], rel_tol=1e-3), (carry.statistic, ref))
        self.assertTrue(math.isclose(carry.df, ref["carry.den_df"], rel_tol=1e-3), (carry.df, ref))
        self.assertLess(abs(carry.p - ref["carry.p"]), 1e-4)
        self.assertTrue(math.isclose(hills.statistic, ref["ha.t"], rel_tol=1e-9), (hills.statistic, ref))
        self.assertEqual(hills.df, ref["ha.df"])
        self.assertLess(abs(hills.p - ref["ha.p"]), 1e-9)
        self.assertTrue(math.isclose(hills.estimate, ref["ha.estimate"] * 1e-3, rel_tol=1e-9))
        # Checks are not adjusted: no Holm beyond the p itself.
        for row in checks.itertuples():
            self.assertTrue(self.pd.isna(row.p_holm) or row.p_holm == row.p, row)

    def test_mixed_design_condition_by_group_check_is_rs(self):
        questions = self.q("mixed")
        training = one(questions, family=f"{VALUE}, training")
        self.assertIn("group", training.model)  # every model of a mixed design has group
        check = one(questions, comparison="condition:group")
        self.assertEqual(check.family, f"{VALUE} (checks)")
        ref = self.reference("mixed_interaction")
        self.assertTrue(math.isclose(check.statistic, ref["f"], rel_tol=1e-3), (check.statistic, ref))
        self.assertTrue(math.isclose(check.df, ref["den_df"], rel_tol=1e-3), (check.df, ref))
        self.assertLess(abs(check.p - ref["p"]), 1e-3)

    def test_unbalanced_groups_are_rs_with_n_per_group(self):
        questions = self.q("unbalanced")
        self.assert_row_is_rs(one(questions, phase="training"), self.reference("unbalanced_training"))
        post = one(questions, phase="post-test")
        self.assert_row_is_rs(post, self.reference("unbalanced_post-test"), rtol=1e-9, ptol=1e-9)
        self.assertEqual(post.n, 9)
        self.assertIn("unguided 3", post.note)
        self.assertIn("fixture 6", post.note)

    def test_odd_group_names_give_the_same_numbers(self):
        """Groups named `NA` and 'a,"b<newline>c': R's missing value and CSV's separators are names."""
        base, odd = self.q("between"), self.q("odd")
        self.assertEqual(len(base), len(odd))
        for b, o in zip(base.itertuples(), odd.itertuples()):
            self.assertEqual(o.comparison, 'a,"b\nc - NA')
            for column in ("estimate", "df", "statistic", "p", "p_holm", "ci95_low", "ci95_high", "g"):
                self.assertTrue(math.isclose(getattr(o, column), getattr(b, column), rel_tol=1e-6),
                                (o.phase, column, getattr(o, column), getattr(b, column)))

    # ---- degenerate designs -------------------------------------------------------------------------------------
    def test_one_subject_per_group_has_no_made_up_p(self):
        questions = self.q("one_each")
        for row in questions.itertuples():
            self.assertTrue(self.pd.isna(row.p) or 0 <= row.p <= 1, row)
        for phase in ("post-test", "retention"):  # ANCOVA of 2 subjects, 3 coefficients: no residual df
            self.assert_no_test(one(questions, phase=phase), "ANCOVA of 2 subjects")
        self.assert_rs_verdict("one_each")

    def test_a_group_of_none_is_not_computed_and_counted(self):
        from calligraphy import design_analysis
        questions = self.q("group_of_none")
        for row in questions.itertuples():
            self.assertTrue(self.pd.isna(row.p), f"a p for a group with no analysed trial: {row}")
            self.assertRegex(row.note, "not (computed|tested)")
        kept, counts = design_analysis.apply_exclusions(self.frames["group_of_none"])
        fixture = counts[counts.group.astype(str) == "fixture"]
        self.assertEqual(int(fixture.kept.sum()), 0)
        self.assertEqual(int(fixture["excluded_gave_up"].sum()), int(fixture.trials.sum()))
        self.assertFalse((kept.group.astype(str) == "fixture").any())

    def test_constant_outcome_has_no_made_up_p(self):
        questions = self.q("constant")
        for row in questions.itertuples():
            self.assertTrue(self.pd.isna(row.p), f"a p of a constant outcome: {row}")
            self.assertRegex(row.note, "not (computed|tested)")
            self.assertFalse(math.isinf(row.g) if isinstance(row.g, float) else False, row)

    def test_perfectly_separated_outcome_is_rs_or_no_test(self):
        questions = self.q("separated")
        for row in questions.itertuples():
            self.assertTrue(self.pd.isna(row.p) or 0 <= row.p <= 1, row)
            self.assertFalse(self.pd.notna(row.statistic) and math.isinf(row.statistic), row)
            if self.pd.notna(row.estimate):
                expected = {"training": -0.001}.get(str(row.phase))
                if expected is not None:
                    self.assertAlmostEqual(row.estimate, expected, places=12)
        self.assert_rs_verdict("separated")

    def test_every_value_equal_but_one_is_rs_or_no_test(self):
        self.assert_rs_verdict("but_one")

    def test_singular_fit_is_reduced_as_r_sees_it(self):
        row = one(self.q("alike"), phase="training")
        full = self.reference("alike_full")
        if full["singular"] == 1:
            self.assertIn("reduced", row.note)
            self.assertNotEqual(row.model, f"{VALUE} ~ group + (1 | subject) + (1 | item)")
        else:
            self.assertEqual(row.model, f"{VALUE} ~ group + (1 | subject) + (1 | item)")
        self.assert_rs_verdict("alike")

    def test_missing_retention_cell_leaves_that_subject_out(self):
        questions = self.q("no_retention")
        self.assertEqual(one(questions, phase="post-test").n, 12)
        row = one(questions, phase="retention")
        ref = self.reference("no_retention_retention")
        self.assertEqual(row.n, 11)
        self.assertEqual(ref["n"], 11)
        self.assert_row_is_rs(row, ref, rtol=1e-9, ptol=1e-9)
        # The retention ratio of that subject's group counts the subjects with all three means.
        frame = self.frames["no_retention"]
        design = self.da.study_design(frame)
        ratios = self.da.retention_ratios(frame, VALUE, design)
        lost_group = str(frame[frame.subject == sorted(frame.subject.unique())[0]].group.iloc[0])
        counts = {str(r.group): r.n for r in ratios.itertuples()}
        self.assertEqual(counts[lost_group], 5, ratios)
        self.assertEqual(sum(counts.values()), 11, ratios)

    def test_tiny_and_huge_outcomes_give_the_same_tests(self):
        base = self.q("between")
        for label, factor in (("tiny", 1e-300), ("huge", 1e300)):
            scaled = self.q(label)
            self.assertEqual(list(scaled.model), list(base.model), label)
            for b, s in zip(base.itertuples(), scaled.itertuples()):
                for column in ("df", "statistic", "p", "p_holm", "g", "g_ci95_low", "g_ci95_high"):
                    self.assertTrue(math.isclose(getattr(s, column), getattr(b, column), rel_tol=1e-6),
                                    (label, s.phase, column, getattr(s, column), getattr(b, column)))
                for column in ("estimate", "ci95_low", "ci95_high"):
                    self.assertTrue(math.isclose(getattr(s, column) / factor, getattr(b, column), rel_tol=1e-6),
                                    (label, s.phase, column))
                self.assertNotIn("nan", s.note, (label, s.note))
                self.assertNotIn("not", s.note, (label, s.note))

    def test_tiny_and_huge_outcomes_give_the_same_means_and_retention(self):
        """The page's phase means (over subject means, SD and t interval) and retention ratios of the same data at
        1e-300 and 1e300 m: those of the data in m, that many times smaller or larger; never an SD of 0 or inf."""
        from calligraphy import statistics
        base = self.frames["between"]
        design = self.da.study_design(base)
        means = statistics.describe(base, VALUE, by=("phase", "group"), unit="subject")
        ratios = self.da.retention_ratios(base, VALUE, design)
        for label, factor in (("tiny", 1e-300), ("huge", 1e300)):
            frame = self.frames[label]
            scaled = statistics.describe(frame, VALUE, by=("phase", "group"), unit="subject")
            for column in ("mean", "sd", "sem", "ci95_low", "ci95_high"):
                self.assertTrue(np_allclose(scaled[column] / factor, means[column], rtol=1e-12), (label, column))
            got = self.da.retention_ratios(frame, VALUE, design)
            for column in ("gain", "gain_ci95_low", "gain_ci95_high"):
                self.assertTrue(np_allclose(got[column] / factor, ratios[column], rtol=1e-12), (label, column))
            self.assertTrue(np_allclose(got.retention_ratio, ratios.retention_ratio, rtol=1e-12), label)
            self.assertEqual(list(got.note), list(ratios.note), label)

    # ---- what a number is ---------------------------------------------------------------------------------------
    def test_every_row_is_a_well_formed_result(self):
        """Across every scenario: p and Holm in [0, 1], Holm never below p, intervals holding their estimate,
        the family 'VALUE, PHASE' or 'VALUE (checks)', n the subjects analysed, the APA sentence the row's."""
        from calligraphy import design_analysis
        checked = 0
        for label, questions in self.questions.items():
            frame = self.frames[label]
            for row in questions.itertuples():
                where = f"{label}, {row.phase}, {row.comparison}"
                self.assertIn(row.family, (f"{VALUE}, {row.phase}", f"{VALUE} (checks)"), where)
                self.assertEqual(row.unit, "m", where)
                if row.family != f"{VALUE} (checks)":  # which contrast, also where none was computed
                    self.assertRegex(row.comparison, r"(?s)^.+ - .+$", where)
                if self.pd.isna(row.p):
                    self.assertTrue(self.pd.isna(row.p_holm), where)
                    continue
                checked += 1
                self.assertTrue(0 <= row.p <= 1, where)
                if row.family != f"{VALUE} (checks)":
                    self.assertTrue(0 <= row.p_holm <= 1, where)
                    self.assertGreaterEqual(row.p_holm, row.p - 1e-15, where)
                if self.pd.notna(row.ci95_low):
                    self.assertLessEqual(row.ci95_low, row.estimate, where)
                    self.assertGreaterEqual(row.ci95_high, row.estimate, where)
                if self.pd.notna(row.g) and self.pd.notna(row.g_ci95_low):
                    self.assertLessEqual(row.g_ci95_low, row.g, where)
                    self.assertGreaterEqual(row.g_ci95_high, row.g, where)
                kept = frame[frame.end_reason == "completed"]
                self.assertLessEqual(row.n, kept.subject.nunique(), where)
                if row.family != f"{VALUE} (checks)" and "t(" in row.apa:
                    expected = design_analysis.apa_sentence(row.df, row.statistic, row.p, row.g,
                                                            (row.ci95_low, row.ci95_high), "", 1.0)
                    self.assertEqual(row.apa.split(", g =")[0], expected.split(", g =")[0], where)
        self.assertGreater(checked, 15)

    def test_apa_sentence_rounds_as_apa_says(self):
        from calligraphy import design_analysis
        self.assertTrue(design_analysis.apa_sentence(7.8, 2.43, 0.042).startswith("t(7.8) = 2.43, p = .042"))
        self.assertIn("p < .001", design_analysis.apa_sentence(10, 9.0, 1e-9))
        self.assertNotIn("p = .000", design_analysis.apa_sentence(10, 5.0, 0.0004))
        # A p that is no probability or a df of none is no sentence of a test.
        for df, t, p in ((10, 1.0, math.nan), (math.nan, 1.0, 0.3), (10, 1.0, 1.5), (10, 1.0, -0.1)):
            sentence = design_analysis.apa_sentence(df, t, p)
            self.assertNotRegex(sentence, r"p = \.\d", (df, t, p, sentence))

    def test_retention_ratio_only_where_the_gain_is_reliable(self):
        from calligraphy import design_analysis
        frame = self.frames["between"]
        design = design_analysis.study_design(frame)
        ratios = design_analysis.retention_ratios(frame, VALUE, design)
        pre, post, ret = (subject_means(frame, p) for p in ("pre-test", "post-test", "retention"))
        groups = frame.groupby("subject", observed=True).group.first().astype(str)
        for row in ratios.itertuples():
            members = groups[groups == str(row.group)].index
            gain = pre[members] - post[members]
            self.assertEqual(row.n, len(members))
            self.assertAlmostEqual(row.gain, gain.mean(), places=15)
            self.assertLessEqual(row.gain_ci95_low, row.gain)
            self.assertGreaterEqual(row.gain_ci95_high, row.gain)
            if row.gain_ci95_low > 0:
                self.assertAlmostEqual(row.retention_ratio, (pre[members] - ret[members]).mean() / gain.mean(),
                                       places=12)
            else:
                self.assertTrue(math.isnan(row.retention_ratio), row)
                self.assertTrue(row.note, row)

    def test_statistics_refuse_too_few_subjects_and_constant_groups(self):
        from calligraphy import statistics
        pd = self.pd
        table = pd.DataFrame({"subject": ["A", "B"], "group": ["x", "y"], "gain": [1.0, 2.0]})
        with self.assertRaisesRegex(ValueError, "at least 2"):
            statistics.group_comparison(table, "gain", "x", "y")
        flat = pd.DataFrame({"subject": list("ABCD"), "group": ["x", "x", "y", "y"], "gain": [1.0, 1.0, 2.0, 2.0]})
        with self.assertRaisesRegex(ValueError, "does not vary"):
            statistics.group_comparison(flat, "gain", "x", "y")
        trials = pd.DataFrame({"subject": ["A", "A"], "condition": ["a", "b"], "characters": [YI, YI],
                               "repetition": [1, 1], VALUE: [0.001, 0.002]})
        with self.assertRaisesRegex(ValueError, "at least 2"):
            statistics.paired_comparison(trials, VALUE, "a", "b")
        described = statistics.describe(trials, VALUE, by="condition", unit="subject")
        self.assertTrue(described.sd.isna().all() and described.ci95_low.isna().all())

    def test_paired_check_within_subjects_is_scipys(self):
        """A within-subjects design's paired t on subject means, beside the mixed model: scipy's ttest_rel."""
        from scipy import stats
        trials, questions = self.paired
        if isinstance(questions, Exception):
            self.fail(f"design_questions raised on the within-subjects rows: {questions!r}")
        checks = rows(questions, family=f"{VALUE} (checks)")
        self.assertEqual(len(checks), 1, questions[["family", "comparison", "model"]])
        row = checks.iloc[0]
        means = trials.groupby(["subject", "condition"])[VALUE].mean().unstack()
        expected = stats.ttest_rel(means["haptic"], means["vision"])
        self.assertAlmostEqual(row.statistic, expected.statistic, places=9)
        self.assertAlmostEqual(row.p, expected.pvalue, places=12)
        self.assertEqual(row.df, 5)
        self.assertEqual(row.n, 6)
        mixed = one(questions, family=f"{VALUE}, test")
        self.assertIn("(1 + condition | subject)", mixed.model + mixed.note)

    # ---- the page and its tables --------------------------------------------------------------------------------
    def test_page_tables_name_model_contrast_correction_and_n(self):
        pd = self.pd
        frame = self.frames["odd"]
        out, index = self.page  # the study report of the odd names' rows (setUpClass, make_page)
        if isinstance(index, Exception):
            self.fail(f"write_report raised on the odd names' rows: {index!r}")
        self.assertTrue(Path(index).is_file())
        questions = pd.read_csv(out / "tables" / "questions.csv", keep_default_na=False, na_values=[""],
                                float_precision="round_trip")
        expected = self.q("odd")
        self.assertEqual(list(questions.comparison), list(expected.comparison))
        for column in ("p", "p_holm", "df", "estimate"):
            self.assertTrue(np_allclose(questions[column], expected[column]), column)
        means = pd.read_csv(out / "tables" / "phase_means.csv", keep_default_na=False, na_values=[""],
                            float_precision="round_trip")
        groups = frame.groupby("subject").group.first()
        for row in means.itertuples():
            members = groups[groups == row.condition].index
            values = subject_means(frame[frame.subject.isin(members)], row.phase)
            self.assertEqual(row.n, len(values), row)
            self.assertAlmostEqual(row.mean, values.mean(), places=15)
            self.assertAlmostEqual(row.sd, values.std(ddof=1), places=15)
            self.assertLessEqual(row.ci95_low, row.mean)
            self.assertGreaterEqual(row.ci95_high, row.mean)
        page = Path(index).read_text(encoding="utf-8")
        self.assertIn("Holm", page)
        self.assertIn("Hedges", page)  # the effect size named as the docs name it
        self.assertIn("(1 | subject) + (1 | item)", page)
        self.assertIn("n = 6", page)
        self.assertNotIn('a,"b\nc', page)  # escaped in HTML

    # ---- the R process ------------------------------------------------------------------------------------------
    def python(self, code, env_extra, timeout=300):
        env = dict(ENV)
        env.update(env_extra)
        return subprocess.run([sys.executable, "-c", code], capture_output=True, env=env, timeout=timeout,
                              cwd=self.tmp)

    def test_slow_and_chatty_r_gives_the_same_numbers(self):
        """An Rscript that takes 2 s to start and an R profile printing a line, a message and a warning."""
        folder = self.tmp / "chatty"
        folder.mkdir()
        wrapper = folder / "Rscript"
        wrapper.write_text(f'#!/bin/sh\n/bin/sleep 2\necho "Loading required package: nothing"\n'
                           f'echo "chatter" >&2\nexec {RSCRIPT} "$@"\n', encoding="utf-8")
        wrapper.chmod(0o755)
        profile = folder / "Rprofile"
        profile.write_text('cat("profile says hello\\n"); message("profile message"); warning("profile warning")\n',
                           encoding="utf-8")
        with open(self.tmp / "between.pickle", "wb") as f:
            pickle.dump(self.frames["between"], f)
        code = ("import pickle, json; from calligraphy import design_analysis\n"
                f"frame = pickle.load(open({str(self.tmp / 'between.pickle')!r}, 'rb'))\n"
                f"q = design_analysis.design_questions(frame, {VALUE!r})\n"
                "print(json.dumps([[r.model, r.df, r.p, r.note] for r in q.itertuples()]))\n")
        done = self.python(code, {"PATH": f"{folder}:/usr/bin:/bin", "R_PROFILE_USER": str(profile)})
        self.assertEqual(done.returncode, 0, done.stderr.decode()[-3000:])
        got = json.loads(done.stdout.decode().strip().splitlines()[-1])
        base = self.q("between")
        self.assertEqual(len(got), len(base))
        for (model, df, p, note), row in zip(got, base.itertuples()):
            self.assertEqual(model, row.model)
            self.assertNotIn("not computed", note)
            self.assertTrue(math.isclose(df, row.df, rel_tol=1e-6) and math.isclose(p, row.p, rel_tol=1e-6),
                            (row.phase, df, p, row.df, row.p, note))

    def test_without_r_the_page_is_still_made(self):
        """A real tiny study (session run, report --csv) and the study report without Rscript on PATH."""
        study = self.tmp / "study"
        protocol = dict(BETWEEN, name="real16c", trial={"max_duration_s": 4})
        protocol["phases"] = [dict(p, characters=[YI]) for p in BETWEEN["phases"]]
        (self.tmp / "real.json").write_text(json.dumps(protocol, ensure_ascii=False), encoding="utf-8")
        done = run(["session", "run", self.tmp / "real.json", "--writer", "simulated", "--writer-profile", "skilled",
                    "--subjects", "6",
                    "--out", study], cwd=self.tmp)
        self.assertEqual(done.returncode, 0, done.stderr.decode()[-2000:])
        tables = self.tmp / "study-tables"
        tables.mkdir()
        done = run(["report", study, "--csv", tables], cwd=self.tmp)
        self.assertEqual(done.returncode, 0, done.stderr.decode()[-2000:])
        empty = self.tmp / "no-r"
        empty.mkdir()
        env = dict(ENV)
        env["PATH"] = str(empty)
        paper = self.tmp / "paper"
        done = subprocess.run([sys.executable, "-m", "calligraphy.study_report", str(study), "--out", str(paper),
                               "--analyse", "all"], capture_output=True, env=env, timeout=300, cwd=self.tmp)
        self.assertEqual(done.returncode, 0, done.stderr.decode()[-3000:])
        self.assertTrue((paper / "index.html").is_file())
        with open(paper / "tables" / "questions.csv", encoding="utf-8", newline="") as f:
            table = list(csv.DictReader(f))
        mixed = [r for r in table if r["phase"] == "training"]
        after = [r for r in table if r["phase"] in ("post-test", "retention")]
        self.assertTrue(mixed and after, table)
        for r in mixed:
            self.assertIn("not computed: Rscript is not installed", r["note"])
            self.assertEqual(r["p"], "")
        for r in after:  # the ANCOVA needs no R
            self.assertNotEqual(r["p"], "", r)
            self.assertTrue(0 <= float(r["p"]) <= 1)
        page = (paper / "index.html").read_text(encoding="utf-8")
        self.assertIn("not computed: Rscript is not installed", page)
        # The tables the page read are the CLI's: n subjects as trials.csv has them.
        with open(tables / "trials.csv", encoding="utf-8", newline="") as f:
            subjects = {r["subject"] for r in csv.DictReader(f)}
        for r in table:  # a count of subjects is a whole number
            self.assertRegex(r["n"], r"^(\d+)?$", r)
        for r in after:
            self.assertEqual(int(r["n"]), len(subjects))


def np_allclose(a, b, rtol=1e-12):
    import numpy as np
    return bool(np.allclose(np.asarray(a, dtype=float), np.asarray(b, dtype=float), rtol=rtol, atol=0,
                            equal_nan=True))


if __name__ == "__main__":
    unittest.main()
