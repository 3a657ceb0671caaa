"""A crossover study's questions (calligraphy.crossover_analysis through design_analysis) on planted data:
the design read with its sequences, periods and sets; every mixed-model row equal to R's lme4/lmerTest fitted
here from the raw table by its own R code (pre-test means per subject and set, period and condition as
factors); Hills-Armitage equal to R's t.test on half period differences; one test per comparison in the
Holm family; n counted as subjects; a planted effect recovered, a planted null not found more often than
chance would allow in one seed."""

import math
import os
import select
import subprocess
import tempfile

import numpy as np
import pandas
import pytest

from calligraphy import design_analysis, mixed_models
from persistent_rscript import PersistentRscript

needs_r = pytest.mark.skipif(not mixed_models.r_available(), reason="R with lme4, lmerTest and pbkrtest is not "
                             "installed (Debian: r-base-core r-cran-lme4 r-cran-lmertest r-cran-pbkrtest)")

CONDITIONS = ("unguided", "amplify")  # listed order: A = unguided, B = amplify
SETS = {"left": ("十", "人", "口"), "right": ("山", "中", "日")}


def crossover_study(seed, subjects=16, effect_m=-0.4e-3, period_m=-0.2e-3, subject_sd_m=0.5e-3,
                    subject_condition_sd_m=0.15e-3, item_sd_m=0.3e-3, noise_m=0.4e-3, gave_up_every=23):
    """Subjects in sequences AB, BA and both set pairings in turn (the protocol's rule): a pre-test on both sets,
    training by period, post-test and retention on both sets by the condition each set trained. The condition
    effect carries to the later tests at half its size; period 2 is easier."""
    rng = np.random.default_rng(seed)
    items = {c: rng.normal(0.0, item_sd_m) for chars in SETS.values() for c in chars}
    rows = []
    for number in range(1, subjects + 1):
        subject = f"S{number:02d}"
        order = (0, 1) if (number - 1) % 2 == 0 else (1, 0)
        rotation = ((number - 1) // 2) % 2
        set_of = {CONDITIONS[k]: list(SETS)[(k + rotation) % 2] for k in range(2)}
        period_of = {CONDITIONS[k]: p + 1 for p, k in enumerate(order)}
        sequence = "".join("AB"[k] for k in order)
        skill = rng.normal(0.0, subject_sd_m)
        by_condition = {c: rng.normal(0.0, subject_condition_sd_m) for c in CONDITIONS}
        trial = 0

        def add(phase, written, item_set, character, shift, repetition=1):
            nonlocal trial
            trained = next(c for c in CONDITIONS if set_of[c] == item_set)
            mean = 3e-3 + skill + items[character] + shift
            if phase != "pre-test":
                mean += by_condition[trained] + (period_m if period_of[trained] == 2 else 0.0)
                if trained == "amplify":
                    mean += effect_m if phase == "training" else effect_m / 2
            trial += 1
            rows.append({"subject": subject, "session_number": 1 if phase != "retention" else 2,
                         "block": trial, "trial": trial, "phase": phase, "condition": written,
                         "mode": "vision" if written == "unguided" else "error-amplification",
                         "characters": character, "repetition": repetition, "item_set": item_set,
                         "sequence": sequence, "period": float(period_of[trained]), "trained_condition": trained,
                         "group": "", "end_reason": "given_up" if trial % gave_up_every == 0 else "completed",
                         "mean_deviation_m": mean + rng.normal(0.0, noise_m)})

        for item_set, characters in SETS.items():
            for character in characters:
                add("pre-test", "unguided", item_set, character, 0.0)
        for k in order:
            condition = CONDITIONS[k]
            for repetition in range(1, 5):
                for character in SETS[set_of[condition]]:
                    add("training", condition, set_of[condition], character, -0.25e-3 * repetition, repetition)
        for phase, shift in (("post-test", -0.9e-3), ("retention", -0.6e-3)):
            for item_set, characters in SETS.items():
                for character in characters:
                    add(phase, "unguided", item_set, character, shift)
    return pandas.DataFrame(rows)


# The test's own R, apart from calligraphy.mixed_models: one Rscript runs every reference script of a run, each in
# an environment of its own given `arguments` (lmerTest loads once, about 1.7 s of CPU each time): a request is a
# line of tab-separated arguments, the script's path first, its answer written to the file it names, then "done".
_R_RUNNER = r"""
suppressPackageStartupMessages(library(lmerTest))
requests <- file("stdin")
open(requests)
while (length(line <- readLines(requests, n = 1)) > 0) {
  request <- strsplit(line, "\t", fixed = TRUE)[[1]]
  script <- new.env(parent = globalenv())
  assign("arguments", request[-1], envir = script)
  sys.source(request[1], envir = script)
  cat("done\n")
  flush(stdout())
}
"""
_R_PROCESS = PersistentRscript(_R_RUNNER, "calligraphy-crossover-r-")


def run_r(code, *arguments):
    """Runs the R code `code` with its variable `arguments` (strings) in the test's one Rscript."""
    process, folder = _R_PROCESS.running()
    with tempfile.NamedTemporaryFile("w", encoding="utf-8", suffix=".R", dir=folder.name, delete=False) as script:
        script.write(code)
    request = (script.name, *map(str, arguments))
    assert not any("\t" in part or "\n" in part for part in request), request
    process.stdin.write("\t".join(request) + "\n")
    process.stdin.flush()
    ready, _, _ = select.select([process.stdout], [], [], 300)
    # "" when R ended on an error (its message is on standard error); nothing within 300 s is a hang
    reply = process.stdout.readline() if ready else "(nothing within 300 s)"
    os.unlink(script.name)
    if reply != "done\n":
        error = _R_PROCESS.abandon()
        pytest.fail(f"Rscript answered {reply!r}: {error}")


_R_REFERENCE = r"""
suppressPackageStartupMessages(library(lmerTest))
trials <- read.csv(arguments[1], encoding = "UTF-8")
models <- read.csv(arguments[2], encoding = "UTF-8", stringsAsFactors = FALSE)
trials <- subset(trials, end_reason == "completed")
pre <- aggregate(mean_deviation_m ~ subject + item_set, data = subset(trials, phase == "pre-test"), FUN = mean)
names(pre)[3] <- "pre"
out <- data.frame()
for (k in seq_len(nrow(models))) {
  data <- subset(trials, phase == models$phase[k])
  data$outcome <- data$mean_deviation_m
  data$condition <- factor(data$trained_condition, levels = c("unguided", "amplify"))
  data$period <- factor(data$period)
  data$sequence <- factor(data$sequence)
  data$item <- data$characters
  if (models$phase[k] != "training") {
    data <- merge(data, pre, by = c("subject", "item_set"))
    data$pre <- data$pre - mean(data$pre)
  }
  fit <- lmer(as.formula(models$formula[k]), data = data, REML = TRUE)
  if (grepl("sequence", models$formula[k])) {
    a <- anova(fit)
    out <- rbind(out, data.frame(phase = models$phase[k], term = "sequence", estimate = NA,
                                 df = a["sequence", "DenDF"], statistic = a["sequence", "F value"],
                                 p = a["sequence", "Pr(>F)"]))
  } else {
    s <- summary(fit)$coefficients
    out <- rbind(out, data.frame(phase = models$phase[k], term = "conditionamplify",
                                 estimate = s["conditionamplify", "Estimate"], df = s["conditionamplify", "df"],
                                 statistic = s["conditionamplify", "t value"], p = s["conditionamplify", "Pr(>|t|)"]))
  }
}
# Hills-Armitage on the training means: half period differences compared between sequences.
training <- subset(trials, phase == "training")
means <- aggregate(mean_deviation_m ~ subject + period + sequence, data = training, FUN = mean)
wide <- reshape(means, idvar = c("subject", "sequence"), timevar = "period", direction = "wide")
wide$half <- (wide$mean_deviation_m.1 - wide$mean_deviation_m.2) / 2
test <- t.test(wide$half[wide$sequence == "BA"], wide$half[wide$sequence == "AB"], var.equal = TRUE)
out <- rbind(out, data.frame(phase = "training", term = "hills-armitage", estimate = unname(test$estimate[1] -
                             test$estimate[2]), df = unname(test$parameter), statistic = unname(test$statistic),
                             p = test$p.value))
write.csv(out, arguments[3], row.names = FALSE)
"""


def _r_reference(trials, rows):
    """R's answers for the models the rows name, fitted from the raw table by the script above."""
    with tempfile.TemporaryDirectory() as folder:
        trials.to_csv(os.path.join(folder, "trials.csv"), index=False, encoding="utf-8")
        models = pandas.DataFrame({"phase": rows["phase"],
                                   "formula": [m.replace("mean_deviation_m", "outcome", 1) for m in rows["model"]]})
        models.to_csv(os.path.join(folder, "models.csv"), index=False, encoding="utf-8")
        run_r(_R_REFERENCE, os.path.join(folder, "trials.csv"), os.path.join(folder, "models.csv"),
              os.path.join(folder, "out.csv"))
        return pandas.read_csv(os.path.join(folder, "out.csv"))


def test_the_crossover_design_is_read_with_sequences_periods_and_sets():
    design = design_analysis.study_design(crossover_study(1))
    assert design.kind == "crossover"
    assert design.conditions == ("unguided", "amplify") and design.control == "unguided"
    assert design.sequences == {"AB": 8, "BA": 8}
    assert design.periods == (1, 2)
    assert design.letters == {"A": "unguided", "B": "amplify"}
    assert design.item_sets == {"left": "十 人 口", "right": "山 中 日"}
    assert design.pairing == {("amplify", "left"): 8, ("amplify", "right"): 8, ("unguided", "left"): 8,
                              ("unguided", "right"): 8}
    sentence = design.sentence()
    assert "sequences AB n = 8, BA n = 8" in sentence and "left: 十 人 口" in sentence


def test_without_the_crossover_columns_it_is_an_ordinary_within_subjects_design():
    trials = crossover_study(1).drop(columns=["trained_condition", "period", "sequence", "item_set"])
    assert design_analysis.study_design(trials).kind == "within-subjects"


@pytest.fixture(scope="module")
def planted():
    """One planted study and its questions, shared: each question is a few R processes."""
    trials = crossover_study(7, subjects=20)
    return trials, design_analysis.design_questions(trials, "mean_deviation_m")


@needs_r
def test_every_question_is_r_lmertest_on_the_raw_table(planted):
    trials, questions = planted
    family = questions[questions["family"].str.startswith("mean_deviation_m, ")]
    checks = questions[questions["family"] == "mean_deviation_m (checks)"]
    assert list(family["phase"]) == ["training", "post-test", "retention"]
    assert list(family["family"]) == [f"mean_deviation_m, {p}" for p in family["phase"]]
    assert all(" + item_set" in m for m in family["model"]), "the sets rotate across sequences: set is a term"
    assert set(family["comparison"]) == {"amplify - unguided"}
    assert (questions["n"].dropna() == 20).all(), "n counts subjects"
    assert family["p"].notna().all()
    for model in family["model"]:
        assert " + period" in model
    assert all(" + pre + " in m for m in family["model"][1:])
    carry = checks[checks["comparison"] == "sequence"]
    reference = _r_reference(trials, pandas.concat([family, carry])[["phase", "model"]])
    ours = pandas.concat([family, carry]).reset_index(drop=True)
    for k in range(len(ours)):
        if math.isfinite(reference.loc[k, "estimate"]):
            assert ours.loc[k, "estimate"] == pytest.approx(reference.loc[k, "estimate"], rel=1e-6)
        assert ours.loc[k, "df"] == pytest.approx(reference.loc[k, "df"], rel=1e-4)
        assert ours.loc[k, "statistic"] == pytest.approx(reference.loc[k, "statistic"], rel=1e-5)
        assert ours.loc[k, "p"] == pytest.approx(reference.loc[k, "p"], rel=1e-4)
    hills = checks[checks["question"].str.contains("Hills-Armitage") & (checks["phase"] == "training")].iloc[0]
    r_hills = reference[reference["term"] == "hills-armitage"].iloc[0]
    assert hills["estimate"] == pytest.approx(r_hills["estimate"], rel=1e-9)
    assert hills["statistic"] == pytest.approx(r_hills["statistic"], rel=1e-9)
    assert hills["p"] == pytest.approx(r_hills["p"], rel=1e-9)
    assert hills["df"] == 18


@needs_r
def test_holm_holds_one_test_per_comparison_and_the_checks_stay_raw(planted):
    _, questions = planted
    for _, family in questions[~questions["family"].str.endswith("(checks)")].groupby("family"):
        p = family["p"].to_numpy()
        order = np.argsort(p)
        expected = np.minimum(1.0, np.maximum.accumulate((len(p) - np.arange(len(p))) * p[order]))
        assert family["p_holm"].to_numpy()[order] == pytest.approx(expected)
    checks = questions[questions["family"].str.endswith("(checks)")]
    assert checks["p_holm"].isna().all() and len(checks) == 4  # carry-over and three Hills-Armitage rows


@needs_r
def test_a_planted_effect_is_found_with_its_sign_and_size(planted):
    _, questions = planted
    training = questions[(questions["family"].str.startswith("mean_deviation_m, ")) & (questions["phase"] == "training")].iloc[0]
    assert training["ci95_low"] < -0.4e-3 < training["ci95_high"]
    assert training["p"] < 0.05 and training["estimate"] < 0
    post = questions[(questions["family"].str.startswith("mean_deviation_m, ")) & (questions["phase"] == "post-test")].iloc[0]
    assert post["ci95_low"] < -0.2e-3 < post["ci95_high"]


@needs_r
def test_a_planted_null_gives_no_carry_over_and_an_interval_around_zero():
    questions = design_analysis.design_questions(crossover_study(5, effect_m=0.0), "mean_deviation_m")
    family = questions[questions["family"].str.startswith("mean_deviation_m, ")]
    assert ((family["ci95_low"] < 0) & (family["ci95_high"] > 0)).all()
    carry = questions[questions["comparison"] == "sequence"].iloc[0]
    assert carry["p"] > 0.05


def test_exclusions_are_counted_by_phase_and_the_condition_each_set_trained():
    trials = crossover_study(2)
    _, counts = design_analysis.apply_exclusions(trials)
    assert list(counts.columns[:2]) == ["phase", "trained_condition"]
    training = counts[counts["phase"] == "training"].set_index("trained_condition")
    expected = trials[trials["phase"] == "training"].groupby("trained_condition")["end_reason"].apply(
        lambda r: int((r != "completed").sum()))
    assert training["excluded_given_up"].to_dict() == expected.to_dict()


def test_a_practice_block_beside_a_crossover_is_counted_under_its_own_condition():
    """A block outside the crossover (practice, familiarisation) trained no item set: its trials are counted
    under the condition they were written in, never under an empty one."""
    trials = crossover_study(2)
    practice = trials[trials["phase"] == "training"].head(6).copy()
    practice["phase"] = "practice"
    practice["trained_condition"] = ""
    practice["condition"] = "unguided"
    practice["end_reason"] = ["completed", "given_up"] * 3
    _, counts = design_analysis.apply_exclusions(pandas.concat([trials, practice], ignore_index=True))
    rows = counts[counts["phase"] == "practice"]
    assert list(rows["trained_condition"]) == ["unguided"]
    assert int(rows["trials"].iloc[0]) == 6 and int(rows["excluded_given_up"].iloc[0]) == 3
    assert (counts["trained_condition"].astype(str) != "").all()


def test_retention_ratios_are_per_condition_on_its_own_sets():
    trials = crossover_study(4)
    design = design_analysis.study_design(trials)
    ratios = design_analysis.retention_ratios(trials, "mean_deviation_m", design)
    assert list(ratios["group"]) == ["unguided", "amplify"]
    assert (ratios["n"] == 16).all()


@needs_r
def test_a_crossover_run_by_session_run_gets_a_page_that_states_its_design(cli, tmp_path):
    """The example protocol, 4 simulated subjects (one full rotation), through session run and the page; its
    training once per character instead of 4 times (what is checked is the design the page states: sequences,
    sets, periods, conditions and phases, none of which the repetitions change)."""
    import json
    import pathlib
    import re

    from calligraphy import study, study_report

    example = pathlib.Path(__file__).resolve().parents[2] / "examples" / "protocols" / "crossover.json"
    protocol_json = json.loads(example.read_text(encoding="utf-8"))
    training = next(phase for phase in protocol_json["phases"] if phase["phase"] == "training")
    assert training["repetitions"] == 4
    training["repetitions"] = 1
    protocol = tmp_path / "crossover.json"
    protocol.write_text(json.dumps(protocol_json, ensure_ascii=False), encoding="utf-8")
    subprocess.run([cli, "session", "run", str(protocol), "--writer", "simulated", "--subjects", "4", "--out",
                    str(tmp_path / "xo")], check=True, capture_output=True, timeout=600)
    loaded = study.load(tmp_path / "xo")
    trials = loaded.trials
    # Each subject trains each condition once, on one set, and its tests name that set's condition and period.
    training = trials[trials["phase"] == "training"]
    assert (training["condition"].astype(str) == training["trained_condition"].astype(str)).all()
    per_set = trials.groupby(["subject", "item_set"], observed=True)["trained_condition"].nunique()
    assert (per_set == 1).all()
    assert sorted(trials.drop_duplicates("subject")["sequence"].astype(str)) == ["AB", "AB", "BA", "BA"]
    index = study_report.write_report(loaded, tmp_path / "paper", values=("mean_deviation_m",))
    text = re.sub(r"<[^>]+>", " ", index.read_text(encoding="utf-8"))
    assert "Crossover (within subjects)" in text and "sequences AB n = 2, BA n = 2" in text
    assert "set1: 十 口 山" in text and "periods 1, 2" in text
    assert "by phase and condition trained" in text
    questions = pandas.read_csv(tmp_path / "paper" / "tables" / "questions.csv")
    assert (questions["n"].dropna() <= 4).all(), "n counts subjects"
    assert set(questions["comparison"]) <= {"amplify - unguided", "sequence", "condition"}
    means = pandas.read_csv(tmp_path / "paper" / "tables" / "phase_means.csv")
    assert set(means["condition"]) == {"unguided", "amplify"} and set(means["phase"]) == {
        "pre-test", "training", "post-test", "retention"}


@needs_r
def test_a_transfer_test_of_one_character_per_set_is_fitted_with_what_lme4_can_estimate():
    """One transfer character per set: one trial per subject and condition, as many random slopes as trials.
    lme4 refuses that model; the row names what it dropped, shows the formula fitted and is still a test,
    with the pre-test of the set each transfer set comes from as covariate."""
    trials = crossover_study(8)
    rng = np.random.default_rng(8)
    extra = []
    for subject, rows in trials[trials["phase"] == "training"].groupby("subject"):
        for condition, source in rows.groupby("trained_condition"):
            source_set = source["item_set"].iloc[0]
            extra.append({**source.iloc[0].to_dict(), "phase": "transfer", "item_set": f"t{source_set}",
                          "characters": "土" if source_set == "left" else "八", "condition": "unguided",
                          "end_reason": "completed", "mean_deviation_m": 2.5e-3 + rng.normal(0.0, 0.4e-3)})
    trials = pandas.concat([trials, pandas.DataFrame(extra)], ignore_index=True)
    questions = design_analysis.design_questions(trials, "mean_deviation_m")
    transfer = questions[(questions["family"].str.startswith("mean_deviation_m, ")) & (questions["phase"] == "transfer")].iloc[0]
    assert "could not fit" in transfer["note"]
    assert "(1 + condition | subject)" not in transfer["model"] and " + pre" in transfer["model"]
    assert math.isfinite(transfer["p"]) or transfer["note"].startswith("not tested")
    assert transfer["n"] == 16


@needs_r
def test_a_mixed_design_has_its_group_in_every_model_and_tests_the_interaction():
    """A between-subjects group beside the crossover (each group every sequence and rotation): group is a fixed
    effect of every model, the condition x group interaction a check, and R gives its F the same."""
    trials = crossover_study(12)
    number = trials["subject"].str[1:].astype(int)
    trials["group"] = np.where(((number - 1) // 4) % 2 == 0, "early", "late")
    design = design_analysis.study_design(trials)
    assert design.kind == "crossover" and design.groups == {"early": 8, "late": 8}
    assert "groups early n = 8, late n = 8" in design.sentence()
    questions = design_analysis.design_questions(trials, "mean_deviation_m", design)
    family = questions[questions["family"].str.startswith("mean_deviation_m, ")]
    assert all(" + group" in model for model in family["model"])
    interaction = questions[questions["comparison"] == "condition:group"].iloc[0]
    assert interaction["family"] == "mean_deviation_m (checks)" and math.isnan(interaction["p_holm"])
    with tempfile.TemporaryDirectory() as folder:
        kept = trials[trials["end_reason"] == "completed"]
        frame = kept[kept["phase"] == "training"].assign(
            outcome=lambda t: t["mean_deviation_m"], condition=lambda t: t["trained_condition"],
            period=lambda t: t["period"].astype(int), item=lambda t: t["characters"])
        frame.to_csv(os.path.join(folder, "training.csv"), index=False, encoding="utf-8")
        script = (
            "suppressPackageStartupMessages(library(lmerTest))\n"
            f"d <- read.csv('{folder}/training.csv', encoding = 'UTF-8')\n"
            "d$condition <- factor(d$condition, levels = c('unguided', 'amplify')); d$period <- factor(d$period)\n"
            "d$group <- factor(d$group, levels = c('early', 'late'))\n"
            f"fit <- lmer({interaction['model'].replace('mean_deviation_m', 'outcome', 1)}, data = d)\n"
            "a <- anova(fit)['condition:group', ]\n"
            "cat(a[['F value']], a[['DenDF']], a[['Pr(>F)']], file = arguments[1])\n")
        run_r(script, os.path.join(folder, "answer.txt"))
        with open(os.path.join(folder, "answer.txt"), encoding="utf-8") as answer:
            f, den_df, p = (float(x) for x in answer.read().split())
    assert interaction["statistic"] == pytest.approx(f, rel=1e-5)
    assert interaction["df"] == pytest.approx(den_df, rel=1e-4)
    assert interaction["p"] == pytest.approx(p, rel=1e-4)


def three_condition_crossover(seed, subjects=12):
    """Three conditions in a Latin square (sequences ABC, BCA, CAB), each trained on its own set of three
    characters, the sets rotated across subjects: a pre-test on every set, training by period, a post-test on
    every set by the condition it trained."""
    rng = np.random.default_rng(seed)
    conditions = ("unguided", "amplify", "fixture")
    sets = {"a": ("十", "人", "口"), "b": ("山", "中", "日"), "c": ("土", "八", "二")}
    rows = []
    for number in range(subjects):
        order = [(number + k) % 3 for k in range(3)]
        rotation = (number // 3) % 3
        set_of = {conditions[c]: list(sets)[(c + rotation) % 3] for c in range(3)}
        period_of = {conditions[c]: p + 1 for p, c in enumerate(order)}
        skill = rng.normal(0.0, 0.5e-3)
        trial = 0
        for phase in ("pre-test", "training", "post-test"):
            for condition in conditions:
                if phase == "training":
                    condition = conditions[order[conditions.index(condition)]]  # in the period's order
                for character in sets[set_of[condition]]:
                    trial += 1
                    rows.append({"subject": f"S{number + 1:02d}", "session_number": 1, "block": trial, "trial": trial,
                                 "phase": phase, "condition": condition if phase == "training" else "unguided",
                                 "mode": "vision", "characters": character, "repetition": 1,
                                 "item_set": set_of[condition], "sequence": "".join("ABC"[c] for c in order),
                                 "period": float(period_of[condition]), "trained_condition": condition, "group": "",
                                 "end_reason": "completed",
                                 "mean_deviation_m": 3e-3 + skill + rng.normal(0.0, 0.4e-3)})
    return pandas.DataFrame(rows)


@needs_r
def test_a_condition_with_no_trial_left_keeps_its_comparisons_saying_so():
    """Every training trial of one of three conditions given up: the other two are still compared, and each
    planned comparison of the missing one keeps its row, saying it has no values, as between subjects."""
    trials = three_condition_crossover(5)
    design = design_analysis.study_design(trials)
    assert design.kind == "crossover" and list(design.conditions) == ["unguided", "amplify", "fixture"]
    lost = (trials["phase"] == "training") & (trials["trained_condition"] == "fixture")
    trials.loc[lost, "end_reason"] = "given_up"
    questions = design_analysis.design_questions(trials, "mean_deviation_m", design)
    training = questions[(questions["family"] == "mean_deviation_m, training")].set_index("comparison")
    assert list(training.index) == ["amplify - unguided", "fixture - unguided", "fixture - amplify"]
    assert math.isfinite(training.loc["amplify - unguided", "p"])
    for comparison in ("fixture - unguided", "fixture - amplify"):
        assert training.loc[comparison, "note"] == "not computed: no values of fixture in training (after the exclusions)"
        assert math.isnan(training.loc[comparison, "p"])
