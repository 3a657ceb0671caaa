"""Every pairwise comparison of three or more conditions, in between-subjects, crossover and mixed designs, against
R's lme4/lmerTest/emmeans (and lm/emmeans for the ANCOVA) fitted here from the raw table by R code of the test's
own: estimate within 2 %, p and Holm's p within a factor of 1.25 (worst ratios printed; pytest -s shows them).
Also: the same data in metres and in millimetres give the same rows, without lme4's scale warning; the
documented reduction of a singular fit in a between-subjects design; the item set as a term of a crossover whose
sets rotate, and the reason when they do not."""

import math
import os
import select

import numpy as np
import pandas
import pytest

from calligraphy import design_analysis, design_models, mixed_models

from test_design_analysis import GROUPS, between_study
from persistent_rscript import PersistentRscript

needs_r = pytest.mark.skipif(not mixed_models.r_available(), reason="R with lme4, lmerTest and pbkrtest is not "
                             "installed (Debian: r-base-core r-cran-lme4 r-cran-lmertest r-cran-pbkrtest)")

CONDITIONS = ("unguided", "amplify", "fading")
SETS = {"s1": ("十", "人", "口"), "s2": ("山", "中", "日"), "s3": ("大", "木", "土")}
# Williams (1949) for 3 conditions: 6 sequences, each condition once in each period and after each other once.
SEQUENCES = ((0, 1, 2), (1, 2, 0), (2, 0, 1), (0, 2, 1), (1, 0, 2), (2, 1, 0))
WORST = {}


def crossover3_study(seed, subjects=18, effect_m=(0.0, -0.4e-3, -0.9e-3), groups=False):
    """Three conditions, three sets rotating across the sequences (the protocol's rule: condition i on set
    (i + q) mod 3, q = ((n - 1) // 6) mod 3); pre-test and post-test on every set, by the condition each set
    trained, the effect at half its size after training; with ``groups`` a between-subjects group beside it."""
    rng = np.random.default_rng(seed)
    items = {c: rng.normal(0.0, 0.3e-3) for chars in SETS.values() for c in chars}
    names = list(SETS)
    rows = []
    for number in range(1, subjects + 1):
        order = SEQUENCES[(number - 1) % 6]
        rotation = ((number - 1) // 6) % 3
        set_of = {CONDITIONS[k]: names[(k + rotation) % 3] for k in range(3)}
        period_of = {CONDITIONS[k]: p + 1 for p, k in enumerate(order)}
        sequence = "".join("ABC"[k] for k in order)
        group = ("early", "late")[(number - 1) % 2] if groups else ""
        skill = rng.normal(0.0, 0.5e-3) + (0.2e-3 if group == "late" else 0.0)
        by_condition = {c: rng.normal(0.0, 0.15e-3) for c in CONDITIONS}
        trial = 0

        def add(phase, written, item_set, character, repetition=1):
            nonlocal trial
            trained = next(c for c in CONDITIONS if set_of[c] == item_set)
            mean = 3e-3 + skill + items[character]
            if phase != "pre-test":
                mean += by_condition[trained] - 0.1e-3 * (period_of[trained] - 1)
                mean += effect_m[CONDITIONS.index(trained)] * (1.0 if phase == "training" else 0.5)
                mean -= 0.3e-3 * repetition if phase == "training" else 0.9e-3
            trial += 1
            rows.append({"subject": f"S{number:02d}", "session_number": 1, "block": trial, "trial": trial,
                         "phase": phase, "condition": written, "item": trial,
                         "mode": "vision" if written == "unguided" else "haptic", "characters": character,
                         "repetition": repetition, "item_set": item_set, "sequence": sequence,
                         "period": float(period_of[trained]), "trained_condition": trained, "group": group,
                         "end_reason": "completed", "mean_deviation_m": mean + rng.normal(0.0, 0.4e-3)})

        for item_set, characters in SETS.items():
            for character in characters:
                add("pre-test", "unguided", item_set, character)
        for k in order:
            for repetition in range(1, 4):
                for character in SETS[set_of[CONDITIONS[k]]]:
                    add("training", CONDITIONS[k], set_of[CONDITIONS[k]], character, repetition)
        for item_set, characters in SETS.items():
            for character in characters:
                add("post-test", "unguided", item_set, character)
    return pandas.DataFrame(rows)


# One Rscript answers every pairs request of a run (lmerTest and emmeans load once, about 1.4 s of CPU each
# time): a request is a line of tab-separated arguments, the answer written to the file it names, then "done".
_R_EMMEANS = r"""
suppressPackageStartupMessages({library(lmerTest); library(emmeans)})
requests <- file("stdin")
open(requests)
while (length(line <- readLines(requests, n = 1)) > 0) {
  arguments <- strsplit(line, "\t", fixed = TRUE)[[1]]
  d <- read.csv(arguments[1], encoding = "UTF-8")
  levels <- strsplit(arguments[3], ",", fixed = TRUE)[[1]]
  d[[arguments[4]]] <- factor(d[[arguments[4]]], levels = levels)
  for (f in c("period", "item_set", "group", "subject", "item")) if (f %in% names(d)) d[[f]] <- factor(d[[f]])
  if (arguments[5] == "lm") fit <- lm(as.formula(arguments[2]), data = d) else
    fit <- lmer(as.formula(arguments[2]), data = d, REML = TRUE)
  means <- emmeans(fit, arguments[4], lmer.df = arguments[6])
  raw <- as.data.frame(summary(pairs(means, reverse = TRUE, adjust = "none")))
  holm <- as.data.frame(summary(pairs(means, reverse = TRUE, adjust = "holm")))
  write.csv(data.frame(estimate = raw$estimate, df = raw$df, p = raw$p.value, p_holm = holm$p.value),
            arguments[7], row.names = FALSE)
  cat("done\n")
  flush(stdout())
}
"""
_R_PROCESS = PersistentRscript(_R_EMMEANS, "calligraphy-emmeans-")


def r_pairs(frame, formula, factor, levels, kind="lmer", ddf="Satterthwaite"):
    """R's every pairwise contrast (later - earlier, in ``levels``' order) of ``factor`` in ``formula`` fitted
    to ``frame`` (the outcome in mm), raw and Holm-adjusted."""
    process, folder = _R_PROCESS.running()
    data, answer = (os.path.join(folder.name, name) for name in ("d.csv", "answer.csv"))
    frame.to_csv(data, index=False, encoding="utf-8")
    request = (data, formula, ",".join(levels), factor, kind,
               "kenward-roger" if ddf == "Kenward-Roger" else "satterthwaite", answer)
    assert not any("\t" in part or "\n" in part for part in request), request
    process.stdin.write("\t".join(request) + "\n")
    process.stdin.flush()
    ready, _, _ = select.select([process.stdout], [], [], 300)
    # "" when R ended on an error (its message is on standard error); nothing within 300 s is a hang
    reply = process.stdout.readline() if ready else "(nothing within 300 s)"
    if reply != "done\n":
        error = _R_PROCESS.abandon()
        pytest.fail(f"Rscript answered {reply!r}: {error}")
    answer_frame = pandas.read_csv(answer)
    os.unlink(answer)
    return answer_frame


def assert_matches_r(ours, reference, levels, check):
    """Our rows of one family against R's pairs, in R's order (2-1, 3-1, 3-2): estimate within 2 %, p and
    Holm's p within x1.25; the worst ratios kept under ``check``."""
    pairs = [(levels[i], levels[j]) for i in range(len(levels)) for j in range(i + 1, len(levels))]
    assert len(ours) == len(pairs) == len(reference), (ours, reference)
    rows = ours.set_index("comparison")
    worst = WORST.setdefault(check, [1.0, 1.0, 1.0])
    for (earlier, later), r in zip(pairs, reference.itertuples(index=False)):
        row = rows.loc[f"{later} - {earlier}"]
        assert math.isfinite(row["p"]), row["note"]
        ratio = row["estimate"] * 1e3 / r.estimate
        p_ratio, holm_ratio = row["p"] / r.p, row["p_holm"] / r.p_holm
        assert ratio == pytest.approx(1.0, abs=0.02)
        assert 1 / 1.25 <= p_ratio <= 1.25
        assert 1 / 1.25 <= holm_ratio <= 1.25
        worst[0] = max(worst[0], abs(ratio - 1.0) + 1.0)
        worst[1] = max(worst[1], p_ratio, 1 / p_ratio)
        worst[2] = max(worst[2], holm_ratio, 1 / holm_ratio)
    print(f"\n{check}: worst estimate ratio {worst[0]:.6f}, p ratio {worst[1]:.6f}, Holm ratio {worst[2]:.6f}")


def _formula(model, value="mean_deviation_m"):
    return model.replace(value, "outcome", 1)


@needs_r
@pytest.mark.parametrize("ddf", ["Satterthwaite", "Kenward-Roger"])
def test_between_subjects_training_pairs_are_emmeans(ddf):
    trials = between_study(11, training_effect_m=(0.0, -0.4e-3, 0.1e-3))
    questions = design_analysis.design_questions(trials, "mean_deviation_m", ddf=ddf)
    family = questions[questions["family"] == "mean_deviation_m, training"]
    assert set(family["comparison"]) == {"fixture - vision-only", "fading - vision-only", "fading - fixture"}
    training = trials[trials["phase"] == "training"]
    frame = pandas.DataFrame({"outcome": training["mean_deviation_m"] * 1e3, "group": training["group"],
                              "subject": training["subject"], "item": training["characters"]})
    reference = r_pairs(frame, _formula(family["model"].iloc[0]), "group", GROUPS, ddf=ddf)
    assert_matches_r(family, reference, GROUPS, f"between training ({ddf})")
    # The planted difference of the two treatments, +0.5 mm, is found and tested.
    pair = family.set_index("comparison").loc["fading - fixture"]
    assert pair["ci95_low"] < 0.5e-3 < pair["ci95_high"] and pair["p"] < 0.05


@needs_r
def test_between_subjects_ancova_pairs_are_emmeans_of_lm():
    trials = between_study(12, post_effect_m=(0.0, 0.2e-3, -0.3e-3))
    questions = design_analysis.design_questions(trials, "mean_deviation_m")
    for phase in ("post-test", "retention"):
        family = questions[questions["family"] == f"mean_deviation_m, {phase}"]
        means = trials.groupby(["subject", "group", "phase"]).mean_deviation_m.mean().unstack("phase").reset_index()
        frame = pandas.DataFrame({"post": means[phase] * 1e3, "pre": means["pre-test"] * 1e3, "group": means["group"]})
        reference = r_pairs(frame, "post ~ pre + group", "group", GROUPS, kind="lm")
        assert_matches_r(family, reference, GROUPS, "between ANCOVA")


def _crossover_frame(trials, phase):
    kept = trials[trials["end_reason"] == "completed"]
    rows = kept[kept["phase"] == phase]
    frame = pandas.DataFrame({"outcome": rows["mean_deviation_m"] * 1e3, "condition": rows["trained_condition"],
                              "period": rows["period"].astype(int), "subject": rows["subject"],
                              "item_set": rows["item_set"], "item": rows["characters"], "group": rows["group"]})
    if phase != "training":
        pre = kept[kept["phase"] == "pre-test"].groupby(["subject", "item_set"]).mean_deviation_m.mean() * 1e3
        frame["pre"] = [pre[(s, k)] for s, k in zip(frame["subject"], frame["item_set"])]
        frame["pre"] -= frame["pre"].mean()
    return frame


@pytest.fixture(scope="module")
def crossover3():
    """crossover3_study(21) and its questions in metres, made once: the pairs are checked on them against R,
    and the same rows in millimetres against them."""
    trials = crossover3_study(21)
    return trials, design_analysis.design_questions(trials, "mean_deviation_m")


@needs_r
@pytest.mark.parametrize("groups", [False, True], ids=["crossover", "mixed"])
def test_crossover_and_mixed_pairs_are_emmeans(groups, request):
    trials = crossover3_study(21, groups=groups)
    design = design_analysis.study_design(trials)
    assert design.kind == "crossover" and design.conditions == CONDITIONS and bool(design.groups) == groups
    if groups:
        questions = design_analysis.design_questions(trials, "mean_deviation_m", design)
    else:  # the same table as the fixture's, whose questions are of the design read from it
        shared, questions = request.getfixturevalue("crossover3")
        pandas.testing.assert_frame_equal(trials, shared)
    for phase in ("training", "post-test"):
        family = questions[questions["family"] == f"mean_deviation_m, {phase}"]
        model = family["model"].iloc[0]
        assert " + item_set" in model, "the sets rotate: set is a term"
        assert (" + group" in model) == groups
        reference = r_pairs(_crossover_frame(trials, phase), _formula(model), "condition", CONDITIONS)
        assert_matches_r(family, reference, CONDITIONS, "mixed" if groups else "crossover")
    assert len(questions[questions["family"] == "mean_deviation_m (checks)"]) >= 1


@needs_r
def test_sets_that_do_not_rotate_are_no_term_and_the_note_says_why():
    trials = crossover3_study(22)
    # Every subject trains each condition on the same set: set is condition.
    set_of = {"unguided": "s1", "amplify": "s2", "fading": "s3"}
    trials["item_set"] = trials["trained_condition"].map(set_of)
    questions = design_analysis.design_questions(trials, "mean_deviation_m")
    training = questions[questions["family"] == "mean_deviation_m, training"]
    assert not any("item_set" in m for m in training["model"])
    assert training["note"].str.contains("item set not a term of the model: each set was trained under one "
                                         "condition").all()


@needs_r
def test_metres_and_millimetres_give_the_same_rows_without_a_scale_warning(crossover3):
    trials, metres = crossover3
    in_mm = trials.assign(deviation_mm=trials["mean_deviation_m"] * 1e3)
    millimetres = design_analysis.design_questions(in_mm, "deviation_mm")
    assert len(metres) == len(millimetres)
    for a, b in zip(metres.to_dict("records"), millimetres.to_dict("records")):
        assert a["comparison"] == b["comparison"] and a["phase"] == b["phase"]
        assert a["model"].replace("mean_deviation_m", "deviation_mm", 1) == b["model"]
        for key in ("estimate", "ci95_low", "ci95_high"):
            if math.isfinite(a[key]):
                assert a[key] * 1e3 == pytest.approx(b[key], rel=1e-6)
        for key in ("df", "statistic", "p", "p_holm"):
            if math.isfinite(a[key]):
                assert a[key] == pytest.approx(b[key], rel=1e-6)
        assert "scale" not in a["note"] and "scale" not in b["note"]
    # The test can fail: the same post-test model given to R in metres draws lme4's warning.
    post = _crossover_frame(trials, "post-test")
    post = post.assign(outcome=post["outcome"] / 1e3, pre=post["pre"] / 1e3)
    formula = "outcome ~ condition + period + pre + item_set + (1 | subject) + (1 | item)"
    factors = {"condition": list(CONDITIONS), "period": ["1", "2", "3"], "item_set": list(SETS)}
    unscaled = mixed_models.lmer(post.astype({"period": str}), formula, factors)
    scaled = design_models.lmer_scaled(post.astype({"period": str}), formula, factors, "Satterthwaite")
    assert "very different scales" in unscaled.messages
    assert "scale" not in scaled.messages
    assert scaled.fixed["estimate"].to_numpy() == pytest.approx(unscaled.fixed["estimate"].to_numpy(), rel=1e-3)


@needs_r
def test_a_singular_between_subjects_fit_is_reduced_by_the_documented_rule():
    trials = between_study(5, subject_sd_m=0.0)  # all subjects alike: the subject variance is 0
    questions = design_analysis.design_questions(trials, "mean_deviation_m")
    training = questions[questions["phase"] == "training"]
    assert len(training) == 3
    assert training["note"].str.contains(r"reduced: refitted without \(1 \| subject\), singular").all()
    assert (training["model"] == "mean_deviation_m ~ group + (1 | item)").all()
    assert training["p"].notna().all() and training["p_holm"].notna().all()
    # One character, no subject variance: nothing left to drop, the row stays no test and says so.
    one = trials[trials["characters"] == "十"]
    rows = design_analysis.design_questions(one, "mean_deviation_m")
    rows = rows[rows["phase"] == "training"]
    assert rows["note"].str.startswith("not tested: singular fit").all() and rows["p"].isna().all()


def test_the_shared_parts_keep_their_public_names():
    assert design_analysis.StudyDesign is design_models.StudyDesign
    assert design_analysis.QUESTION_COLUMNS is design_models.QUESTION_COLUMNS
    import inspect

    import calligraphy.crossover_analysis as crossover

    # No import circle: the crossover's module imports the shared parts, never design_analysis.
    source = inspect.getsource(crossover)
    assert "design_analysis import" not in source and "import design_analysis" not in source
    assert crossover.StudyDesign is design_models.StudyDesign


@needs_r
def test_the_page_keeps_one_unit_per_table_and_escapes_what_it_shows(tmp_path):
    import calligraphy.study
    from calligraphy import study_report

    hostile = "fading<script>alert(1)</script>"
    trials = between_study(13, subject_sd_m=0.1e-3, training_effect_m=(0.0, -0.4e-3, 0.1e-3))
    trials = trials.replace({"group": {"fading": hostile}, "condition": {"fading": hostile}})
    index = study_report.write_report(calligraphy.study.Study(trials=trials, strokes=pandas.DataFrame()), tmp_path,
                                      values=("mean_deviation_m",))
    page = index.read_text(encoding="utf-8")
    assert "<script" not in page and "fading&lt;script&gt;alert(1)&lt;/script&gt;" in page
    # A p below 0.001 is text, escaped; never a bare '<' in a cell.
    assert "&lt; 0.001" in page and ">< 0.001<" not in page
    # The questions of a table in mm write their variances in mm^2 and nothing in metres.
    questions = page[page.index("<table class=\"questions\""):]
    questions = questions[:questions.index("</table>")]
    assert "[mm^2]" in questions and "[m^2]" not in questions
    assert f"{hostile.replace('<', '&lt;').replace('>', '&gt;')} - fixture" in questions
    # Words defined once, the table's word used: groups here.
    assert "Words: a <b>condition</b>" in page and "each group against the control" in page
    # Every phase of the protocol described, in order.
    protocol = page[page.index("id=\"protocol\""):]
    protocol = protocol[:protocol.index("</table>")]
    positions = [protocol.index(f"<tr><td>{phase}</td>") for phase in ("pre-test", "training", "post-test",
                                                                        "retention", "transfer")]
    assert positions == sorted(positions)


def test_retention_notes_on_the_page_are_in_its_unit():
    from calligraphy import study_report

    row = {"group": "x", "n": 6, "retention_ratio": math.nan, "gain_ci95_low": -5.88e-05, "gain_ci95_high": 8.2e-05,
           "note": "not computed: the group's gain is not reliably above 0 (95 % CI [-5.88e-05, 8.2e-05])"}
    html = study_report._retention_html(pandas.DataFrame([row]), "group", study_report._display("mean_deviation_m"))
    assert "95 % CI [-0.0588, 0.0820] mm" in html and "e-05" not in html


def test_item_sets_are_in_the_protocols_order_and_every_phase_is_on_the_page():
    from calligraphy import study_report

    trials = crossover3_study(24)
    trials["item_set"] = trials["item_set"].map({"s1": "zeta", "s2": "alpha", "s3": "mid"})
    practice = trials[trials["phase"] == "pre-test"].head(3).assign(
        phase="practice", condition="unguided", item_set="", period=math.nan, trained_condition="", block=0, trial=0,
        characters="一")
    trials = pandas.concat([practice, trials], ignore_index=True)
    design = design_analysis.study_design(trials)
    assert list(design.item_sets) == ["zeta", "alpha", "mid"]  # the pre-test lists them so, not the alphabet
    assert [k for _, k in design.pairing][:3] == [k for k in ("zeta", "alpha", "mid")
                                                  if ("unguided", k) in design.pairing]
    assert "item sets zeta: 十 人 口; alpha: 山 中 日; mid: 大 木 土" in design.sentence()
    html = study_report._protocol_html(trials, design)
    assert "familiarisation (practice)" in html
    assert "zeta: 十 人 口; alpha: 山 中 日; mid: 大 木 土" in html
