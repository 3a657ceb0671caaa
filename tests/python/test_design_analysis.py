"""calligraphy.design_analysis on planted data: the design read in protocol order, the control first; the
ANCOVA checked against R's lm; the crossed mixed model's Satterthwaite and Kenward-Roger df and t checked
against the split-plot identity (a balanced design: the between-group test on subject means); a singular fit
not reported as a test; Holm within the outcome; the exclusion policy counted; the guarded retention ratio;
the transfer baseline; APA sentences."""

import math
import os
import shutil
import subprocess

import numpy as np
import pandas
import pytest
import statsmodels.formula.api as smf
from statsmodels.stats.multitest import multipletests

from calligraphy import design_analysis, mixed_models

R_MISSING = not mixed_models.r_available()
needs_r = pytest.mark.skipif(R_MISSING, reason="R with lme4, lmerTest and pbkrtest is not installed "
                             "(Debian: r-base-core r-cran-lme4 r-cran-lmertest r-cran-pbkrtest)")

GROUPS = ("vision-only", "fixture", "fading")  # not alphabetical: the control is the unguided one
MODES = {"vision-only": "vision", "fixture": "haptic", "fading": "fading"}
PHASES = ("pre-test", "training", "post-test", "retention", "transfer")  # alphabetical order would differ
CHARACTERS = ("十", "人", "口")


def between_study(seed, subjects_per_group=6, subject_sd_m=0.3e-3, training_effect_m=(0.0, -0.4e-3, -0.2e-3),
                  post_effect_m=(0.0, 0.1e-3, -0.3e-3), gave_up_every=0, transfer=("大", "木")):
    """A between-subjects study in protocol order: each subject's skill (subject_sd_m) carries from the pre-test
    to every phase; training and post-test effects per group are planted; items crossed with subjects."""
    rng = np.random.default_rng(seed)
    rows = []
    number = 0
    for s in range(subjects_per_group * len(GROUPS)):
        group = GROUPS[s % len(GROUPS)]
        k = GROUPS.index(group)
        skill = rng.normal(0.0, subject_sd_m)
        number += 1
        trial = 0
        for block, phase in enumerate(PHASES):
            characters = transfer if phase == "transfer" else CHARACTERS
            repetitions = 3 if phase == "training" else 1
            for repetition in range(repetitions):
                for item, character in enumerate(characters):
                    mean = 2.0e-3 + skill + 0.1e-3 * item
                    if phase == "training":
                        mean += training_effect_m[k] - 0.5e-3
                    elif phase != "pre-test":
                        mean += post_effect_m[k] - 0.6e-3
                    trial += 1
                    reason = "gave_up" if gave_up_every and trial % gave_up_every == 0 else "completed"
                    rows.append({"subject": f"P{number:02d}", "group": group, "phase": phase, "session_number": 1,
                                 "block": block, "trial": trial,
                                 "condition": group if phase == "training" else "vision-only",
                                 "mode": MODES[group] if phase == "training" else "vision", "characters": character,
                                 "repetition": repetition, "end_reason": reason,
                                 "mean_deviation_m": mean + rng.normal(0.0, 0.15e-3)})
    return pandas.DataFrame(rows)


def rscript(code):
    run = subprocess.run([shutil.which("Rscript"), "--vanilla", "-e", code], capture_output=True, text=True,
                         timeout=300)
    assert run.returncode == 0, run.stderr
    return run.stdout


def test_the_design_is_read_in_protocol_order_with_the_unguided_control_first():
    trials = between_study(1).sample(frac=1.0, random_state=3)  # row order says nothing
    design = design_analysis.study_design(trials)
    assert design.kind == "between-subjects"
    assert design.phases == PHASES
    assert design.conditions == GROUPS and design.control == "vision-only"
    assert design.compared_phase == "training" and design.pre_test == "pre-test"
    assert design.after_training == ("post-test", "retention", "transfer")
    assert design.n_per_condition == {g: 6 for g in GROUPS}
    ordered = design_analysis.ordered(trials, design)
    assert list(ordered.sort_values("phase").phase.drop_duplicates()) == list(PHASES)
    assert list(ordered.group.cat.categories) == list(GROUPS)
    # A named reference is the control; one not in the study is refused, naming those present.
    assert design_analysis.study_design(trials, reference="fading").conditions == ("fading", "vision-only", "fixture")
    with pytest.raises(ValueError, match="reference 'sham' is not a group.*'vision-only', 'fixture', 'fading'"):
        design_analysis.study_design(trials, reference="sham")


def test_a_within_subjects_design_is_told_apart():
    trials = between_study(2)
    trials = trials[trials.phase == "training"].copy()
    # Every subject writes every condition: the paper's design.
    trials["condition"] = [GROUPS[k % 3] for k in range(len(trials))]
    trials["mode"] = trials["condition"].map(MODES)
    trials["group"] = ""
    design = design_analysis.study_design(trials)
    assert design.kind == "within-subjects" and design.control == "vision-only"
    assert design.n_per_condition == {g: 18 for g in GROUPS}


@needs_r
def test_the_ancova_is_r_lm_of_the_subject_means():
    trials = between_study(3)
    design = design_analysis.study_design(trials)
    questions = design_analysis.design_questions(trials, "mean_deviation_m", design)
    post = questions[questions.phase == "post-test"].set_index("comparison")
    means = trials.groupby(["subject", "group", "phase"], observed=True).mean_deviation_m.mean().unstack("phase")
    frame = means.reset_index()[["subject", "group", "pre-test", "post-test"]]
    frame.columns = ["subject", "group", "pre", "post"]
    path = os.path.join(os.environ.get("TMPDIR", "/tmp"), f"ancova-{os.getpid()}.csv")
    frame.to_csv(path, index=False)
    try:
        text = rscript(f"d <- read.csv('{path}'); d$group <- factor(d$group, levels=c('vision-only','fixture',"
                       "'fading')); f <- lm(post ~ pre + group, d); s <- summary(f)$coefficients; "
                       "write.csv(data.frame(term=rownames(s), estimate=s[,1], t=s[,3], p=s[,4], df=f$df.residual),"
                       " row.names=FALSE)")
    finally:
        os.remove(path)
    reference = pandas.read_csv(__import__("io").StringIO(text)).set_index("term")
    for level in ("fixture", "fading"):
        row = post.loc[f"{level} - vision-only"]
        assert row.estimate == pytest.approx(reference.loc[f"group{level}", "estimate"], rel=1e-9)
        assert row.statistic == pytest.approx(reference.loc[f"group{level}", "t"], rel=1e-9)
        assert row.p == pytest.approx(reference.loc[f"group{level}", "p"], rel=1e-7)
        assert row.df == reference.loc[f"group{level}", "df"] == 18 - 4
    # The planted post-test effect of fading (-0.3 mm against the control) is found.
    assert post.loc["fading - vision-only", "ci95_high"] < 0


def test_an_ancova_with_no_residual_variance_is_not_computed():
    """A post-test whose subject means are all equal (or that the pre-test predicts exactly) leaves the ANCOVA
    no residual variance: no t and no p, where OLS would print 0/0 or x/0 as numbers."""
    for make in (lambda t: 2e-3, lambda t: 1e-3 + 0.5 * t["pre"]):
        trials = between_study(4)
        pre = trials[trials["phase"] == "pre-test"].groupby("subject")["mean_deviation_m"].mean()
        post = trials["phase"] == "post-test"
        trials.loc[post, "mean_deviation_m"] = make({"pre": trials.loc[post, "subject"].map(pre)})
        questions = design_analysis.design_questions(trials, "mean_deviation_m")
        rows = questions[(questions.phase == "post-test") & questions.question.str.contains("ANCOVA")]
        # One row per comparison of the family (each group against the control, the other pair), each saying why.
        assert list(rows.comparison) == [f"{g} - {GROUPS[0]}" for g in GROUPS[1:]] + [f"{GROUPS[2]} - {GROUPS[1]}"]
        assert rows.note.str.startswith("not computed: the post-test means leave no residual variance").all()
        assert rows.p.isna().all()


@needs_r
@pytest.mark.parametrize("ddf", ["Satterthwaite", "Kenward-Roger"])
def test_the_crossed_mixed_model_gives_the_split_plot_test_on_a_balanced_design(ddf):
    """With subjects nested in groups, every subject writing every item equally often, the group contrast's
    small-sample test is exactly the test of the group difference between subject means, with
    n_subjects - n_groups df (the classical split-plot ANOVA): lmerTest's Satterthwaite and Kenward-Roger df
    must find it, where a Wald z would have infinite df."""
    trials = between_study(4)
    design = design_analysis.study_design(trials)
    questions = design_analysis.design_questions(trials, "mean_deviation_m", design, ddf=ddf)
    training = questions[questions.phase == "training"].set_index("comparison")
    # Each group against the control, and the two treatments against each other (three groups).
    assert len(training) == 3 and (training.note.str.startswith("variances: subject")).all()
    assert "fading - fixture" in training.index
    data = trials[trials.phase == "training"]
    means = data.groupby(["subject", "group"], observed=True).mean_deviation_m.mean().reset_index()
    means["group"] = pandas.Categorical(means["group"], categories=list(GROUPS))
    fit = smf.ols("mean_deviation_m ~ C(group)", data=means).fit()
    for level in ("fixture", "fading"):
        row = training.loc[f"{level} - vision-only"]
        name = f"C(group)[T.{level}]"
        assert row.df == pytest.approx(18 - 3, rel=1e-4)
        assert row.statistic == pytest.approx(fit.tvalues[name], rel=1e-4)
        assert row.p == pytest.approx(fit.pvalues[name], rel=1e-3)
        assert row.estimate == pytest.approx(fit.params[name], rel=1e-6)
        assert ddf in row.test
    assert training.loc["fixture - vision-only", "ci95_high"] < 0  # the planted -0.4 mm


@needs_r
def test_a_singular_fit_keeps_its_estimate_but_is_no_test():
    trials = between_study(5, subject_sd_m=0.0)  # all subjects alike: the subject variance is 0
    trials = trials[trials.characters == "十"]  # one character: no item term to keep, nothing left to reduce
    questions = design_analysis.design_questions(trials, "mean_deviation_m")
    training = questions[questions.phase == "training"]
    assert (training.note.str.startswith("not tested: singular fit")).all()
    assert training.p.isna().all() and training.df.isna().all() and training.apa.eq("").all()
    assert training.estimate.notna().all()
    assert training.p_holm.isna().all()


@needs_r
def test_holm_adjusts_every_comparison_of_an_outcome_in_a_phase_together():
    questions = design_analysis.design_questions(between_study(6), "mean_deviation_m")
    # Three pairs of groups (two against the control, one between the treatments) in training, post-test,
    # retention and transfer: one family per phase.
    assert len(questions) == 3 * 4
    assert set(questions.family) == {f"mean_deviation_m, {p}" for p in PHASES[1:]} and set(questions.unit) == {"m"}
    for _, family in questions.groupby("family"):
        finite = family.p.notna()
        assert finite.sum() == 3
        _, expected, _, _ = multipletests(family.p[finite], method="holm")
        assert family.p_holm[finite].to_numpy() == pytest.approx(expected)
        assert (family.p_holm[finite] >= family.p[finite]).all()


def test_the_exclusion_policy_is_applied_and_counted():
    trials = between_study(7, gave_up_every=5)
    kept, counts = design_analysis.apply_exclusions(trials)
    assert (kept.end_reason == "completed").all()
    assert counts.trials.sum() == len(trials) and counts.kept.sum() == len(kept)
    assert counts.excluded_gave_up.sum() == (trials.end_reason == "gave_up").sum()
    assert set(counts.columns) >= {"phase", "group", "trials", "kept"}
    everything, counted = design_analysis.apply_exclusions(trials, design_analysis.ExclusionPolicy(None))
    assert len(everything) == len(trials) and "excluded_gave_up" not in counted.columns


def test_the_retention_ratio_needs_a_reliable_gain():
    trials = between_study(8)
    design = design_analysis.study_design(trials)
    ratios = design_analysis.retention_ratios(trials, "mean_deviation_m", design).set_index("group")
    # Every group gained 0.6 mm +- its effect and kept it all (retention = post-test in the planted data).
    assert ratios.retention_ratio.to_numpy() == pytest.approx(1.0, abs=0.25)
    flat = trials.copy()
    flat.loc[flat.phase != "pre-test", "mean_deviation_m"] = flat.loc[flat.phase == "pre-test",
                                                                      "mean_deviation_m"].mean()
    flat.loc[flat.phase != "pre-test", "mean_deviation_m"] += np.random.default_rng(1).normal(
        0.0, 0.3e-3, (flat.phase != "pre-test").sum())
    none = design_analysis.retention_ratios(flat, "mean_deviation_m", design)
    unreliable = none[none.note.str.startswith("not computed")]
    assert len(unreliable) >= 1 and unreliable.retention_ratio.isna().all()


def test_transfer_without_a_pre_test_on_its_characters_has_no_gain():
    trials = between_study(9)
    design = design_analysis.study_design(trials)
    assert design_analysis.transfer_baseline(trials, design).startswith(
        "No transfer gain is computed: the transfer characters (大 木) were not written in the pre-test")
    same = between_study(9, transfer=("十",))
    assert "also pre-tested" in design_analysis.transfer_baseline(same, design_analysis.study_design(same))


def test_apa_sentences():
    assert design_analysis.apa_sentence(7.83, 2.431, 0.0421, 1.391, (0.01e-3, 0.55e-3), "mm", 1e3) == (
        "t(7.8) = 2.43, p = .042, g = 1.39, 95 % CI [0.01, 0.55] mm")
    assert design_analysis.apa_sentence(14.0, -5.1, 2e-5) == "t(14) = -5.10, p < .001"
    assert design_analysis.apa_sentence(math.nan, math.nan, math.nan) == ""


def test_without_r_the_mixed_model_is_not_computed_and_says_why(monkeypatch):
    monkeypatch.setattr(mixed_models.shutil, "which", lambda name: None)
    questions = design_analysis.design_questions(between_study(10), "mean_deviation_m")
    training = questions[questions.phase == "training"]
    assert list(training.comparison) == [f"{g} - {GROUPS[0]}" for g in GROUPS[1:]] + [f"{GROUPS[2]} - {GROUPS[1]}"]
    assert training.note.str.startswith("not computed: Rscript is not installed").all() and training.p.isna().all()
    assert questions[questions.phase == "post-test"].p.notna().all()  # the ANCOVA needs no R


def test_a_model_not_fitted_for_too_few_values_says_what_is_short():
    from calligraphy import design_models
    assert design_models.too_few_to_fit(["unguided", "fixture"], "unguided", 3) is None
    assert design_models.too_few_to_fit(["unguided", "fixture"], "unguided", 2) == (
        "not computed: 2 subjects with values (the model needs at least 3)")
    assert design_models.too_few_to_fit(["unguided", "fixture"], "unguided", 1) == (
        "not computed: 1 subject with values (the model needs at least 3)")
    assert design_models.too_few_to_fit(["unguided"], "unguided", 8) == (
        "not computed: only one condition has values (a comparison needs 2)")
    assert design_models.too_few_to_fit(["fixture"], "unguided", 8) == (
        "not computed: the control 'unguided' has no values")
