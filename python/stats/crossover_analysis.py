"""The questions of a crossover study: every subject trains under each condition, each on its own item set, in
counterbalanced sequences (docs/experiments.md, "Crossover designs"; docs/learning-study.md, "A crossover").

The tidy table (``calligraphy.study.load``) names, for every trial, the condition its item set was trained
under (``trained_condition``, also on pre-test and later test trials), the crossover period that set was
trained in (``period``), the subject's ``sequence`` ('AB', 'BA', ...) and the ``item_set``. The functions
here, called by ``calligraphy.design_analysis`` for a design of kind 'crossover':

* ``questions``: for one outcome, each condition against the control and, with three or more, every other
  pair (R's emmeans contrasts of the same fit)
  - in training: ``outcome ~ condition + period + (1 + condition | subject) + (1 | item)``;
  - in each later test (post-test, retention, transfer), by the condition the item's set was trained under:
    ``outcome ~ condition + period + pre + (1 + condition | subject) + (1 | item)``, ``pre`` the subject's
    pre-test mean on the same set (a transfer set not pre-tested: on the set trained under the same
    condition), centred;
  both linear mixed models with subjects and items (characters) crossed, fitted by R's lme4 (REML) with
  lmerTest's Satterthwaite df (Jones & Kenward 2014, Design and Analysis of Cross-Over Trials, 3rd ed., ch. 2).
  The random condition slope per subject tests the condition against how much its effect varies between
  subjects (Barr, Levy, Scheepers & Tily 2013). Where the sets rotate across sequences (the protocol's
  rule), set is separable from condition and period and ``item_set`` is a fixed effect of every model; where
  it is not, the rows' note says why. With few subjects that fit is often singular (a variance at 0 or a
  correlation at +-1), does not converge, or cannot be made at all (as many random effects as trials, e.g. a
  transfer test of one character per set); it is then refitted with the slope's compound-symmetry form,
  ``(1 | subject) + (1 | subject:item_set)`` (a subject trains each set under one condition, so
  subject:item_set is the subject's own condition effect, one variance instead of two and a correlation),
  and while still singular or not converged without the term of the smallest variance
  (``calligraphy.design_models.fit_reduced``; Matuschek, Kliegl, Vasishth, Baayen & Bates 2017, J Mem Lang
  94:305). Each row shows the formula fitted and says what was reduced. These rows form one Holm family per
  outcome and phase.
  A mixed design (a between-subjects phase gives each subject a ``group`` beside the crossover) has ``group``
  as a fixed effect in every model and, as a check, the F test of the condition x group interaction.
  Checks, reported apart and not adjusted: the carry-over (sequence) F test, ``sequence`` added to the
  training model (Grizzle 1965, Biometrics 21:467: in a 2 x 2 design it is the carry-over contrast), and for
  two conditions in two periods Hills & Armitage's (1979, Br J Clin Pharmacol 8:7) two-sample t test on each
  subject's half period difference: the small-sample check of the treatment effect, which needs no model.
* ``within_subject_means``: means by phase and trained condition with Cousineau-Morey within-subject 95 %
  intervals (Cousineau 2005, Tutor Quant Methods Psychol 1:42; Morey 2008, ibid. 4:61).
* ``retention_ratios``: per condition, the share of the gain kept at retention, on the sets trained under it.

n always counts subjects. Differences are always treatment - control.
"""

from __future__ import annotations

import math
import typing

import numpy as np

from . import design_models, mixed_models, statistics
from .design_models import StudyDesign

if typing.TYPE_CHECKING:  # pragma: no cover
    import pandas

__all__ = ["questions", "retention_ratios", "within_subject_means"]

_Z975 = 1.959963984540054


_unit = design_models.unit
_row = design_models.row


def _text(column: "pandas.Series") -> "pandas.Series":
    return column.astype(str).replace({"nan": ""})


def trained(data: "pandas.DataFrame") -> "pandas.DataFrame":
    """The rows whose item set is trained under a condition of the crossover (``trained_condition`` given,
    ``period`` >= 1)."""
    if "trained_condition" not in data.columns or "period" not in data.columns:
        return data.iloc[0:0]
    period = data["period"].astype(float)
    return data[(_text(data["trained_condition"]) != "") & (period >= 1)]


def _frame(rows: "pandas.DataFrame", value: str) -> "pandas.DataFrame":
    pandas = statistics._pandas()
    return pandas.DataFrame({
        "outcome": rows[value].to_numpy(dtype=float),
        "condition": _text(rows["trained_condition"]).to_numpy(),
        "period": rows["period"].astype(float).astype(int).astype(str).to_numpy(),
        "sequence": _text(rows["sequence"]).to_numpy() if "sequence" in rows.columns else "",
        "subject": rows["subject"].astype(str).to_numpy(),
        "item_set": _text(rows["item_set"]).to_numpy() if "item_set" in rows.columns else "",
        "item": rows["characters"].astype(str).to_numpy(),
        "group": _text(rows["group"]).to_numpy() if "group" in rows.columns else ""}, index=rows.index)


def _g_av(difference: float, frame: "pandas.DataFrame", level: str, control: typing.Optional[str]
          ) -> tuple[float, float, float]:
    """Hedges' g_av: the difference over the mean of the two conditions' SDs of subject means, small-sample
    corrected (Lakens 2013, Front Psychol 4:863, eq. 10), with the paired normal-approximation interval."""
    means = frame.groupby(["condition", "subject"])["outcome"].mean()
    if level not in means.index.get_level_values(0) or control not in means.index.get_level_values(0):
        return math.nan, math.nan, math.nan
    a, b = means.loc[level], means.loc[control]
    n = len(set(a.index) & set(b.index))
    sd = (float(a.std(ddof=1)) + float(b.std(ddof=1))) / 2.0
    if n < 3 or not sd > 0:
        return math.nan, math.nan, math.nan
    g = difference / sd * (1.0 - 3.0 / (4.0 * (n - 1) - 1.0))
    se = math.sqrt(1.0 / n + g * g / (2.0 * n))
    return g, g - _Z975 * se, g + _Z975 * se


# The slope's compound-symmetry form and the items' intercept, for a fit the maximal structure cannot make.
_RANDOM_TERMS = ("(1 | subject)", "(1 | subject:item_set)", "(1 | item)")


def _fit(frame: "pandas.DataFrame", fixed: list[str], factors: dict, ddf: str,
         units: design_models.Units = design_models.Units("")) -> tuple["mixed_models.LmerFit", list[str]]:
    """Fits ``outcome ~ fixed + random`` with the random effects the data can estimate
    (``design_models.fit_reduced``): first the maximal structure, a random condition slope per subject and an
    intercept per item; when that fit is singular, does not converge or cannot be made (lme4 refuses as many
    random effects as observations, e.g. one trial per subject and set), the slope's compound-symmetry form
    (an intercept per subject and one per subject and item set: in a crossover each subject trains a set under
    one condition); while singular or not converged, without the term of the smallest variance (while
    refused, without subject:item_set, then item). Returns the last fit and what was reduced. Raises
    RUnavailable, and RuntimeError when even one random intercept cannot be fitted."""
    items = ["(1 | item)"] if frame["item"].nunique() >= 2 else []
    terms = [t for t in _RANDOM_TERMS if t != "(1 | item)" or items]
    return design_models.fit_reduced(frame, fixed, factors, ddf, terms, ["(1 + condition | subject)"] + items,
                                     units)


def _factors(frame: "pandas.DataFrame", design: "StudyDesign") -> dict[str, list]:
    factors: dict[str, list] = {"condition": [c for c in design.conditions if c in set(frame["condition"])],
                                "period": sorted(set(frame["period"]), key=int)}
    sequences = sorted(set(frame["sequence"]) - {""})
    if sequences:
        factors["sequence"] = sequences
    if design.groups:
        factors["group"] = list(design.groups)
    sets = [k for k in design.item_sets if k in set(frame["item_set"])]
    sets += sorted(set(frame["item_set"]) - set(sets) - {""})
    if sets:
        factors["item_set"] = sets
    return factors


def _between(design: "StudyDesign") -> list[str]:
    """A mixed design's between-subjects factor as a fixed term: the groups differ in level, which is not the
    question but is the model's to account for."""
    return ["group"] if design.groups else []


def _rank(frame: "pandas.DataFrame", terms: list[str]) -> int:
    """The rank of the fixed effects' model matrix (intercept, treatment-coded factors, numeric covariates)."""
    pandas = statistics._pandas()
    columns = [np.ones(len(frame))]
    for term in terms:
        if term == "pre":
            columns.append(frame["pre"].to_numpy(dtype=float))
        else:
            dummies = pandas.get_dummies(frame[term].astype(str), drop_first=True, dtype=float)
            columns += [dummies[c].to_numpy() for c in dummies.columns]
    return int(np.linalg.matrix_rank(np.column_stack(columns)))


def _set_terms(frame: "pandas.DataFrame", fixed: list[str]) -> tuple[list[str], str]:
    """``['item_set']`` when the item sets are separable from the model's other fixed effects (the sets rotate
    across sequences, so that each set is trained under every condition and in every period), with '' ; else
    no term and why, for the row's note: the sets' difficulty is then part of the condition's (or period's)
    effect, which only the protocol's counterbalancing can average out."""
    sets = sorted(set(frame["item_set"]) - {""})
    if len(sets) < 2:
        return [], ""
    with_sets = _rank(frame, fixed + ["item_set"])
    if with_sets == _rank(frame, fixed) + len(sets) - 1:
        return ["item_set"], ""
    per_set = frame.groupby("item_set")["condition"].nunique()
    if (per_set <= 1).all():
        why = "each set was trained under one condition, so set is not separable from condition"
    else:
        why = "set is not separable from condition and period in these data (the sets do not rotate across sequences)"
    return [], f"item set not a term of the model: {why}"


def _fit_rows(frame: "pandas.DataFrame", fixed: list[str], base: dict, design: "StudyDesign", ddf: str,
              value: str, units: design_models.Units) -> list[dict]:
    """Each condition against the control from one fitted model, and with three or more conditions every
    other pair of conditions (emmeans); a fit that is still singular or did not converge keeps its estimates
    and gives no test. The item set is a term where the design separates it."""
    factors = _factors(frame, design)
    levels = factors["condition"]
    sets, no_set = _set_terms(frame, fixed)
    fixed = fixed + sets
    model = f"{value} ~ " + " + ".join(fixed)
    too_few = design_models.too_few_to_fit(levels, design.control, frame["subject"].nunique())
    if too_few:
        return design_models.not_computed_rows(base, design.conditions, design.control, too_few, model=model)
    try:
        fit, dropped = _fit(frame, fixed, factors, ddf, units)
    except RuntimeError as error:  # RUnavailable among them: R or its packages missing
        return design_models.not_computed_rows(base, design.conditions, design.control, f"not computed: {error}",
                                               model=model)
    model = fit.formula.replace("outcome", value, 1)
    trusted = fit.trustworthy
    note = design_models.fit_note(fit, dropped, units)
    if no_set:
        note += "; " + no_set
    rows = []
    for effect in fit.fixed.itertuples(index=False):
        if effect.factor != "condition":
            continue
        both = frame[frame["condition"].isin([effect.level, design.control])]
        g, g_low, g_high = _g_av(float(effect.estimate), both, effect.level, design.control)
        rows.append(_row(
            **base, model=model, comparison=f"{effect.level} - {design.control}",
            test=f"linear mixed model (REML), lme4 {fit.ddf} t ({fit.versions})",
            n=int(both["subject"].nunique()), df=float(effect.df) if trusted else math.nan,
            statistic=float(effect.t) if trusted else math.nan, p=float(effect.p) if trusted else math.nan,
            estimate=float(effect.estimate), ci95_low=float(effect.ci95_low) if trusted else math.nan,
            ci95_high=float(effect.ci95_high) if trusted else math.nan, g=g, g_ci95_low=g_low, g_ci95_high=g_high,
            note=note))
    rows += design_models.absent_effect_rows(fit, "condition", levels, design.control, base, model=model)
    rows += design_models.pair_rows(
        fit, levels, design.control, {**base, "model": model}, note,
        lambda a, b: int(frame.loc[frame["condition"].isin([a, b]), "subject"].nunique()),
        lambda d, later, earlier: _g_av(d, frame[frame["condition"].isin([later, earlier])], later, earlier))
    # A condition with no trial left keeps its comparisons, each saying so, as between and within subjects.
    return design_models.with_absent_levels(rows, {**base, "model": model}, list(design.conditions), levels,
                                            design.control, f"in {base['phase']} (after the exclusions)")


def _family(value: str, phase: typing.Optional[str]) -> str:
    """Holm's family: one outcome in one phase."""
    return f"{value}, {phase}"


def _training_rows(data: "pandas.DataFrame", value: str, design: "StudyDesign", ddf: str,
                   units: design_models.Units) -> list[dict]:
    phase = design.compared_phase
    rows_of = trained(data[(data["phase"].astype(str) == phase) & data[value].notna()])
    frame = _frame(rows_of, value)
    terms = ["condition"] + (["period"] if frame["period"].nunique() >= 2 else []) + _between(design)
    base = {"value": value, "unit": _unit(value), "family": _family(value, phase), "phase": phase,
            "question": f"{phase}: conditions compared (crossover: mixed model, subjects x items crossed, period "
                        "fixed)"}
    return _fit_rows(frame, terms, base, design, ddf, value, units)


def _pre_test_means(data: "pandas.DataFrame", value: str, design: "StudyDesign") -> "pandas.Series":
    """Each subject's pre-test mean per item set, indexed by (subject, item_set)."""
    pre = data[(data["phase"].astype(str) == design.pre_test) & data[value].notna()]
    if pre.empty or "item_set" not in pre.columns:
        return statistics._pandas().Series(dtype=float)
    return pre.groupby([pre["subject"].astype(str), _text(pre["item_set"])])[value].mean()


def _with_pre_test(frame: "pandas.DataFrame", pre: "pandas.Series", training: "pandas.DataFrame"
                   ) -> "pandas.DataFrame":
    """``frame`` with ``pre``: the subject's pre-test mean on the row's set, or, for a set not pre-tested (a
    transfer set), on the set the subject trained under the same condition. Rows without one are dropped."""
    trained_set = training.drop_duplicates(["subject", "condition"]).set_index(["subject", "condition"])["item_set"]
    values = []
    for subject, item_set, condition in zip(frame["subject"], frame["item_set"], frame["condition"]):
        key = (subject, item_set)
        if key not in pre.index:
            key = (subject, trained_set.get((subject, condition), ""))
        values.append(float(pre[key]) if key in pre.index else math.nan)
    out = frame.assign(pre_raw=values).dropna(subset=["pre_raw"])
    return out.assign(pre=out["pre_raw"] - out["pre_raw"].mean())  # centred: the intercept at the average pre-test


def _after_training_rows(data: "pandas.DataFrame", value: str, design: "StudyDesign", phase: str, ddf: str,
                         units: design_models.Units) -> list[dict]:
    rows_of = trained(data[(data["phase"].astype(str) == phase) & data[value].notna()])
    frame = _frame(rows_of, value)
    training = _frame(trained(data[data["phase"].astype(str) == design.compared_phase]), value)
    adjusted = design.pre_test is not None
    if adjusted:
        frame = _with_pre_test(frame, _pre_test_means(data, value, design), training)
    terms = ["condition"] + (["period"] if frame["period"].nunique() >= 2 else []) + (["pre"] if adjusted else []) \
        + _between(design)
    base = {"value": value, "unit": _unit(value), "family": _family(value, phase), "phase": phase,
            "question": f"{phase}: by the condition each set was trained under" +
                        (", adjusted for the same set's pre-test" if adjusted else "") + " (crossover)"}
    return _fit_rows(frame, terms, base, design, ddf, value, units)


def _f_sentence(num_df: float, den_df: float, f: float, p: float) -> str:
    if not all(math.isfinite(x) for x in (num_df, den_df, f, p)):
        return ""
    p_text = "p < .001" if p < 0.001 else f"p = {p:.3f}".replace("0.", ".", 1)
    den = f"{den_df:.0f}" if abs(den_df - round(den_df)) < 0.05 else f"{den_df:.1f}"
    return f"F({num_df:.0f}, {den}) = {f:.2f}, {p_text}"


def _f_test_row(data: "pandas.DataFrame", value: str, design: "StudyDesign", ddf: str, term: str,
                question: str, what: str, units: design_models.Units) -> list[dict]:
    """A check of the design: ``term`` added to the training model and tested as a whole (lmerTest's F)."""
    phase = design.compared_phase
    frame = _frame(trained(data[(data["phase"].astype(str) == phase) & data[value].notna()]), value)
    base = {"value": value, "unit": _unit(value), "family": f"{value} (checks)", "phase": phase,
            "comparison": term, "question": f"{phase}: {question}"}
    if frame["period"].nunique() < 2:
        return [_row(**base, note="not computed: fewer than 2 periods")]
    fixed = ["condition", "period"] + _between(design)
    fixed += _set_terms(frame, fixed)[0]
    try:
        fit, dropped = _fit(frame, fixed + [term], _factors(frame, design), ddf, units)
    except RuntimeError as error:
        return [_row(**base, note=f"not computed: {error}")]
    model = fit.formula.replace("outcome", value, 1)
    tested = fit.terms[fit.terms["term"] == term]
    if tested.empty or not fit.trustworthy:
        return [_row(**base, model=model, note=f"not computed: no {term} term" if fit.trustworthy else
                     "not tested: " + ("singular fit" if fit.singular else "did not converge"))]
    num_df, den_df = float(tested["num_df"].iloc[0]), float(tested["den_df"].iloc[0])
    f, p = float(tested["f"].iloc[0]), float(tested["p"].iloc[0])
    return [_row(**base, model=model, n=int(frame["subject"].nunique()),
                 test=f"F test of {what}, lme4 {fit.ddf} ({fit.versions})", df=den_df, statistic=f, p=p,
                 apa=_f_sentence(num_df, den_df, f, p),
                 note=f"F with {num_df:.0f} and {den_df:.1f} df; a check of the design, not in the Holm family" +
                 ("; reduced: refitted without " + "; ".join(dropped) if dropped else ""))]


def _carry_over_row(data: "pandas.DataFrame", value: str, design: "StudyDesign", ddf: str,
                    units: design_models.Units) -> list[dict]:
    """The sequence (carry-over) F test: ``sequence`` added to the training model."""
    if len(design.sequences) < 2:
        return [_row(value=value, unit=_unit(value), family=f"{value} (checks)", phase=design.compared_phase,
                     comparison="sequence", question=f"{design.compared_phase}: carry-over",
                     note="not computed: fewer than 2 sequences")]
    return _f_test_row(data, value, design, ddf, "sequence", "carry-over (do the sequences differ?)",
                       "sequence (carry-over)", units)


def _interaction_row(data: "pandas.DataFrame", value: str, design: "StudyDesign", ddf: str,
                     units: design_models.Units) -> list[dict]:
    """A mixed design's question beside the condition's: does the condition's effect differ between groups?"""
    return _f_test_row(data, value, design, ddf, "condition:group",
                       "does the condition's effect differ between the groups? (mixed design)",
                       "the condition x group interaction", units)


def _hills_armitage_row(frame: "pandas.DataFrame", value: str, design: "StudyDesign", phase: str, what: str
                        ) -> dict:
    """Hills & Armitage (1979): each subject's half difference between its period-1 and period-2 means,
    compared between the two sequences by Student's t; the difference of the sequences' means estimates
    treatment - control."""
    from scipy import stats

    base = {"value": value, "unit": _unit(value), "family": f"{value} (checks)", "phase": phase,
            "model": f"subject's (period 1 - period 2) / 2 of {what}, compared between sequences",
            "question": f"{phase}: condition against the control (Hills-Armitage, no model)"}
    level = [c for c in design.conditions if c != design.control]
    if len(design.conditions) != 2 or frame["period"].nunique() != 2:
        return _row(**base, comparison="condition", note="not computed: only for 2 conditions in 2 periods")
    level = level[0]
    means = frame.groupby(["subject", "period"])["outcome"].mean().unstack("period")
    first = frame[frame["period"] == "1"].groupby("subject")["condition"].first()
    means = means.dropna()
    half = (means["1"] - means["2"]) / 2.0
    treatment_first = half[first.reindex(half.index) == level].to_numpy(dtype=float)
    control_first = half[first.reindex(half.index) == design.control].to_numpy(dtype=float)
    n1, n2 = len(treatment_first), len(control_first)
    if n1 < 2 or n2 < 2:
        return _row(**base, comparison=f"{level} - {design.control}",
                    note=f"not computed: {n1} and {n2} subjects in the two sequences (2 each needed)")
    estimate = float(treatment_first.mean() - control_first.mean())
    pooled = ((n1 - 1) * treatment_first.var(ddof=1) + (n2 - 1) * control_first.var(ddof=1)) / (n1 + n2 - 2)
    se = math.sqrt(pooled * (1.0 / n1 + 1.0 / n2))
    df = n1 + n2 - 2
    t = estimate / se if se > 0 else math.nan
    p = float(2.0 * stats.t.sf(abs(t), df)) if math.isfinite(t) else math.nan
    half_width = float(stats.t.ppf(0.975, df)) * se
    return _row(**base, comparison=f"{level} - {design.control}", test="Hills-Armitage: Student's t on subject "
                "half period differences (scipy)", n=n1 + n2, df=float(df), statistic=t, p=p, estimate=estimate,
                ci95_low=estimate - half_width, ci95_high=estimate + half_width,
                note=f"{n1} subjects trained {level} first, {n2} {design.control} first; a small-sample check, "
                     "not in the Holm family")


def _hills_armitage_rows(data: "pandas.DataFrame", value: str, design: "StudyDesign") -> list[dict]:
    if len(design.conditions) != 2 or len(design.periods) != 2:  # one row says why, not one per phase
        return [_row(value=value, unit=_unit(value), family=f"{value} (checks)", phase=design.compared_phase,
                     comparison="condition", question=f"{design.compared_phase}: Hills-Armitage",
                     note="not computed: Hills-Armitage is for 2 conditions in 2 periods")]
    rows = []
    training = _frame(trained(data[(data["phase"].astype(str) == design.compared_phase) & data[value].notna()]),
                      value)
    rows.append(_hills_armitage_row(training, value, design, design.compared_phase, "the training means"))
    pre = _pre_test_means(data, value, design) if design.pre_test else None
    for phase in design.after_training:
        frame = _frame(trained(data[(data["phase"].astype(str) == phase) & data[value].notna()]), value)
        what = f"the {phase} means"
        if pre is not None and not pre.empty:
            # Change from the same set's pre-test: the small-sample counterpart of the covariate.
            frame = _with_pre_test(frame, pre, training)
            frame = frame.assign(outcome=frame["outcome"] - frame["pre_raw"])
            what = f"the {phase} mean minus the same set's pre-test mean"
        rows.append(_hills_armitage_row(frame, value, design, phase, what))
    return rows


def questions(data: "pandas.DataFrame", value: str, design: "StudyDesign", ddf: str,
              units: typing.Optional[design_models.Units] = None) -> list[dict]:
    """The crossover's rows of ``design_analysis.design_questions`` for ``value`` on the analysed trials
    ``data`` (see the module's docstring): one Holm family per phase (family = ``'VALUE, PHASE'``) and the
    checks (family = ``value + ' (checks)'``). ``units``: how the notes write variances (default the SI
    unit)."""
    units = units or design_models.Units(_unit(value))
    rows = _training_rows(data, value, design, ddf, units)
    for phase in design.after_training:
        rows += _after_training_rows(data, value, design, phase, ddf, units)
    rows += _carry_over_row(data, value, design, ddf, units)
    if design.groups:
        rows += _interaction_row(data, value, design, ddf, units)
    rows += _hills_armitage_rows(data, value, design)
    return rows


def within_subject_means(data: "pandas.DataFrame", value: str, design: "StudyDesign", by: str = "trained_condition"
                         ) -> "pandas.DataFrame":
    """Per phase and condition (``by``: in a crossover the condition each trial's set trained under; in another
    within-subjects design the condition written): n subjects, the mean of subject means, their SD (between
    subjects) and the Cousineau-Morey within-subject 95 % interval: subject means normalised by removing each
    subject's mean over the phase's conditions, t interval widened by sqrt(J / (J - 1)) for J conditions
    (Morey 2008). In a phase of two or more conditions only the subjects with analysed trials in every one of
    them count (``n`` says how many): the comparison within subjects is of those subjects, and means over
    different subjects would show who completed, not what the condition did. A phase of one condition gets
    the between-subjects t interval."""
    from scipy import stats

    pandas = statistics._pandas()
    rows_of = data[data[value].notna()]
    rows_of = rows_of.assign(arm=_text(rows_of[by]))
    rows_of = rows_of[rows_of["arm"] != ""]
    out = []
    for phase in design.phases:
        phase_rows = rows_of[rows_of["phase"].astype(str) == phase]
        if phase_rows.empty:
            continue
        means = phase_rows.groupby(["subject", "arm"], observed=True)[value].mean().unstack("arm")
        conditions = [c for c in design.conditions if c in means.columns] + [
            c for c in means.columns if c not in design.conditions]
        j = len(conditions)
        complete = means[conditions].dropna()
        normalised = complete.sub(complete.mean(axis=1), axis=0) if j >= 2 else complete
        n = len(complete)
        for condition in conditions:
            column = complete[condition]
            sd = float(column.std(ddof=1)) if n > 1 else math.nan
            spread = float(normalised[condition].std(ddof=1)) * math.sqrt(j / (j - 1)) if j >= 2 else sd
            half = float(stats.t.ppf(0.975, n - 1)) * spread / math.sqrt(n) if n > 1 else math.nan
            mean = float(column.mean()) if n else math.nan
            out.append({"value": value, "unit": _unit(value), "phase": phase, "condition": condition, "n": n,
                        "mean": mean, "sd": sd, "ci95_low": mean - half, "ci95_high": mean + half})
    return pandas.DataFrame(out, columns=["value", "unit", "phase", "condition", "n", "mean", "sd", "ci95_low",
                                          "ci95_high"])


def retention_ratios(data: "pandas.DataFrame", value: str, design: "StudyDesign") -> "pandas.DataFrame":
    """Per trained condition, mean(pre - retention) / mean(pre - post) over subjects, each subject's means on
    the set trained under the condition; computed only where the condition's mean gain is reliably above 0
    (its 95 % t interval excludes 0). Columns as ``design_analysis.retention_ratios`` (``group`` holds the
    condition)."""
    pandas = statistics._pandas()
    columns = statistics.RETENTION_COLUMNS
    needed = [design.pre_test, "post-test", "retention"]
    if design.pre_test is None or not {"post-test", "retention"} <= set(design.after_training):
        return pandas.DataFrame(columns=columns)
    rows_of = data[data[value].notna() & data["phase"].astype(str).isin(needed)]
    rows_of = rows_of.assign(arm=_text(rows_of["trained_condition"]))
    means = rows_of[rows_of["arm"] != ""].groupby(
        ["arm", rows_of["subject"].astype(str), rows_of["phase"].astype(str)], observed=True)[value].mean()
    table = means.unstack()
    out = []
    for condition in design.conditions:
        if condition in table.index.get_level_values(0) and set(needed) <= set(table.columns):
            subset = table.loc[condition].dropna(subset=needed)
        else:  # no subject has all three on the condition's set
            subset = pandas.DataFrame(columns=needed, dtype=float)
        out.append(statistics.retention_row(
            condition, subset[design.pre_test], subset["post-test"], subset["retention"],
            "not computed: fewer than 2 subjects with pre-test, post-test and retention on the condition's set",
            "the gain"))
    return pandas.DataFrame(out, columns=columns)
