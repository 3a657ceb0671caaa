"""The questions a study's design asks, answered the way a reviewer in motor learning expects.

``trials`` is the tidy table of ``calligraphy.study.load`` (one row per trial: ``subject``, ``phase``,
``condition``, ``group``, ``characters``, ``session_number``, ``block``, ``end_reason``, ``mode`` and the
outcomes in SI units). The functions here:

* ``study_design`` reads the design from the table: between-subjects (each subject trains in one ``group``)
  or within-subjects (every subject writes every condition), the phases in protocol order, the control;
* ``ordered`` makes phase (protocol order), condition and group (control first) ordered categories;
* ``apply_exclusions`` applies a stated exclusion policy (by default only trials that ended ``completed``
  are analysed) and counts what it left out, per phase and group;
* ``design_questions`` answers the design's questions for one outcome, each guided condition against the
  control and, with three or more conditions, every other pair, Holm-adjusted within the family of the
  outcome in one phase:

  - during training (or, within subjects, in the conditions' phase): a linear mixed model with subjects and
    items (the characters) crossed, ``outcome ~ condition + (1 | subject) + (1 | item)`` (within subjects
    ``(1 + condition | subject)``, a random slope per subject), fitted by R's lme4
    with Satterthwaite degrees of freedom from lmerTest (``calligraphy.mixed_models``), the other pairs as
    R's emmeans contrasts of the same fit; fitted in a well-scaled unit and, when singular or not converged,
    reduced by the rule of ``calligraphy.design_models`` (within subjects the slope's compound-symmetry form
    ``(1 | subject) + (1 | subject:condition)`` first); a fit still singular or not converged is reported as
    such and its tests are not given as tests;
  - after training (post-test, retention, transfer), between subjects: an ANCOVA on subject means,
    ``post ~ pre + group`` (ordinary least squares, statsmodels; the same model as R's ``lm``), i.e. the
    groups compared adjusted for the pre-test (Vickers & Altman 2001, BMJ 323:1123; Van Breukelen 2006);
  - within subjects: paired t-tests on subject means (``calligraphy.statistics.paired_comparison``);
  - a crossover (each condition trained on its own item set, in counterbalanced sequences): the models of
    ``calligraphy.crossover_analysis``, with period fixed and each later test by the condition the item's
    set was trained under, adjusted for the same set's pre-test; its carry-over and Hills-Armitage checks
    are reported apart, unadjusted.

  Holm (1979) adjusts the p values within a family: one outcome's comparisons in one phase, each pair of
  conditions once.
  Effect sizes: the difference (adjusted for the pre-test in an ANCOVA) with its 95 % interval in the
  outcome's unit, and Hedges' g with an approximate 95 % interval (Hedges & Olkin 1985, eq. 5.14).
* ``retention_ratios`` gives each group's share of its gain kept at retention, only where the gain is
  reliable; ``transfer_baseline`` says whether a transfer phase has a pre-test on the same characters.

Sources: docs/references.md. pandas, SciPy and statsmodels are imported when a function is called; R (Debian
r-base-core r-cran-lme4 r-cran-lmertest r-cran-pbkrtest) when a mixed model is fitted.
"""

from __future__ import annotations

import dataclasses
import math
import typing

import numpy as np

from . import crossover_analysis, design_models, statistics
from .design_models import QUESTION_COLUMNS, StudyDesign

if typing.TYPE_CHECKING:  # pragma: no cover
    import pandas

__all__ = [
    "ExclusionPolicy",
    "QUESTION_COLUMNS",
    "StudyDesign",
    "UnknownReference",
    "apa_sentence",
    "apply_exclusions",
    "design_questions",
    "ordered",
    "retention_ratios",
    "study_design",
    "transfer_baseline",
]

# Phases that test what training left, in the order a protocol runs them (docs/experiments.md, "Phases").
PRE_TEST = "pre-test"
AFTER_TRAINING = ("post-test", "retention", "transfer")
# Modes that give no guidance: a condition in one of them is the natural control.
_UNGUIDED_MODES = ("vision",)

def _pandas():
    return statistics._pandas()


_unit = design_models.unit
_row = design_models.row
_holm = design_models.holm
_hedges_g_interval = design_models.hedges_g_interval


# ---------------------------------------------------------------------------------------------- design


def _first_appearance(trials: pandas.DataFrame, column: str) -> list[str]:
    """The values of ``column`` in the order the protocol first runs them: by session, block and trial, and
    among trials at the same place by subject (groups are assigned by subject number in turn)."""
    keys = [c for c in ("session_number", "block", "trial", "subject") if c in trials.columns]
    rows = trials.sort_values(keys, kind="stable") if keys else trials
    return [str(v) for v in dict.fromkeys(rows[column].astype(str)) if str(v) != ""]


def _set_order(trials: pandas.DataFrame) -> list[str]:
    """The item sets in the protocol's order: by the first phase that writes each, then by the set's first
    ``item`` (its place in the phase's list of items, which lists the sets in the protocol's order), else by
    first appearance; the trials' order within a phase (random character orders) says nothing."""
    named = trials[trials["item_set"].astype(str).replace({"nan": ""}) != ""]
    if named.empty:
        return []
    phases = {p: k for k, p in enumerate(_phase_order(trials))}
    first = _first_appearance(named, "item_set")
    keys = {}
    for name, rows in named.groupby(named["item_set"].astype(str), observed=True):
        phase_rank = min(phases.get(str(p), len(phases)) for p in rows["phase"].astype(str).unique())
        in_phase = rows[rows["phase"].astype(str).map(phases) == phase_rank]
        item = float(in_phase["item"].min()) if "item" in rows.columns and in_phase["item"].notna().any() else 0.0
        keys[str(name)] = (phase_rank, item, first.index(str(name)) if str(name) in first else len(first))
    return sorted(keys, key=lambda name: keys[name])


def _phase_order(trials: pandas.DataFrame) -> list[str]:
    return _first_appearance(trials, "phase")


class UnknownReference(ValueError):
    """The ``reference`` asked for is no condition (group) of the study: the caller's wrong usage, which
    ``python3 -m calligraphy.study_report --reference`` answers with exit status 2, not a data error."""


def _condition_order(trials: pandas.DataFrame, column: str, reference: typing.Optional[str]) -> list[str]:
    """The levels of ``column`` with the control first: ``reference`` when given, else the one condition in an
    unguided mode ('vision'), else the first in protocol order."""
    levels = _first_appearance(trials, column)
    present = trials[trials[column].astype(str) != ""]
    if reference is None and "mode" in trials.columns:
        mode_of = present.assign(key=present[column].astype(str)).groupby("key", observed=True)["mode"].agg(
            lambda modes: "/".join(sorted({str(m) for m in modes})))
        unguided = [level for level in levels if mode_of.get(level, "") in _UNGUIDED_MODES]
        if len(unguided) == 1:
            reference = unguided[0]
    if reference is None:
        return levels
    if reference not in levels:
        raise UnknownReference(f"study_design: reference {reference!r} is not a {column} of the study; present: "
                         f"{', '.join(repr(level) for level in levels)}")
    return [reference] + [level for level in levels if level != reference]


def _crossover_parts(trials: pandas.DataFrame, compared: pandas.DataFrame) -> typing.Optional[dict]:
    """The crossover's sequences, periods, item sets, condition-set pairing and sequence letters when the
    compared phase's trials name the period and the condition their set is trained under (the tables'
    ``period`` and ``trained_condition``) and a subject trains two or more conditions; else None."""
    if compared.empty or not {"period", "trained_condition", "sequence", "item_set"} <= set(compared.columns):
        return None
    period = compared["period"].astype(float)
    named = compared[(period >= 1) & (compared["trained_condition"].astype(str).replace({"nan": ""}) != "")]
    # A subject who stopped before a later period trained one condition: still a crossover's subject.
    if named.empty or (named.groupby("subject", observed=True)["condition"].nunique() < 2).all():
        return None
    named = named.assign(period=named["period"].astype(float).astype(int), subject=named["subject"].astype(str),
                         condition=named["condition"].astype(str), item_set=named["item_set"].astype(str),
                         sequence=named["sequence"].astype(str))
    per_subject = named.drop_duplicates(["subject", "period"])
    sequences = per_subject.drop_duplicates("subject")["sequence"].value_counts().sort_index()
    letters: dict[str, str] = {}
    for row in per_subject.itertuples(index=False):
        if 1 <= row.period <= len(row.sequence):
            letters.setdefault(row.sequence[row.period - 1], row.condition)
    sets: dict[str, str] = {}
    for name in _set_order(trials):
        items = trials.loc[trials["item_set"].astype(str) == name, "characters"].astype(str)
        sets[name] = " ".join(dict.fromkeys(items))
    counted = per_subject.groupby(["condition", "item_set"])["subject"].nunique()
    conditions = _first_appearance(named, "condition")
    pairs = {(c, k): counted[(c, k)] for c in conditions for k in sets if (c, k) in counted.index}
    # A mixed design: the subjects' between-subjects group (from another phase of the protocol) beside it.
    group_of = named.drop_duplicates("subject").set_index("subject")["group"].astype(str) if "group" in named.columns \
        else None
    groups = group_of[group_of != ""].value_counts().sort_index() if group_of is not None else None
    return {"groups": {str(k): int(v) for k, v in groups.items()} if groups is not None and len(groups) >= 2 else {},
            "sequences": {str(k): int(v) for k, v in sequences.items()},
            "periods": tuple(sorted(int(p) for p in named["period"].unique())), "item_sets": sets,
            "pairing": {(str(c), str(k)): int(n) for (c, k), n in pairs.items()},  # conditions, sets in order
            "letters": dict(sorted(letters.items()))}


def study_design(trials: pandas.DataFrame, reference: typing.Optional[str] = None) -> StudyDesign:
    """Reads the design from ``trials`` (see the module's docstring). ``reference`` names the control (a group
    or condition); by default the one condition without guidance ('vision' mode), else the first in protocol
    order. Raises TypeError for a table that is not a DataFrame; ValueError naming a missing column or a
    reference not present."""
    statistics._check_frame(trials, "study_design")
    statistics._require_columns(trials, ["subject", "phase", "condition"], "study_design")
    statistics._require_groups(trials, ["subject", "phase", "condition"], "study_design")
    phases = _phase_order(trials)
    per_phase = trials.groupby(trials["phase"].astype(str))["condition"].nunique()
    varied = [p for p in phases if per_phase.get(p, 0) >= 2]
    compared_phase = varied[0] if varied else None
    # A crossover is compared in its crossover phase, which a between-subjects phase (a mixed design) may precede.
    crossover = None
    for phase in varied:
        crossover = _crossover_parts(trials, trials[trials["phase"].astype(str) == phase])
        if crossover is not None:
            compared_phase = phase
            break
    data = trials[trials["phase"].astype(str) == compared_phase] if compared_phase else trials
    groups = data["group"].astype(str) if "group" in data.columns else None
    if crossover is not None:
        # The crossover's own trials: a between-subjects phase of the same kind (a mixed design) is not compared.
        data = data[data["trained_condition"].astype(str).replace({"nan": ""}) != ""]
        conditions = _condition_order(data, "condition", reference)
        counts = data.groupby(data["condition"].astype(str))["subject"].nunique()
        return StudyDesign(kind="crossover", phases=tuple(phases), conditions=tuple(conditions),
                           control=conditions[0], compared_phase=compared_phase,
                           n_per_condition={c: int(counts.get(c, 0)) for c in conditions},
                           pre_test=PRE_TEST if PRE_TEST in phases else None,
                           after_training=tuple(p for p in AFTER_TRAINING if p in phases), **crossover)
    if groups is not None and (groups != "").any() and (data.groupby("subject", observed=True)["condition"].nunique()
                                                        == 1).all():
        data = data[groups != ""]
        conditions = _condition_order(data, "group", reference)
        counts = data.groupby(data["group"].astype(str))["subject"].nunique()
        kind = "between-subjects"
    else:
        conditions = _condition_order(data, "condition", reference)
        counts = data.groupby(data["condition"].astype(str))["subject"].nunique()
        kind = "within-subjects" if len(conditions) >= 2 else "single-condition"
    return StudyDesign(kind=kind, phases=tuple(phases), conditions=tuple(conditions),
                       control=conditions[0] if conditions else None, compared_phase=compared_phase,
                       n_per_condition={c: int(counts.get(c, 0)) for c in conditions},
                       pre_test=PRE_TEST if PRE_TEST in phases else None,
                       after_training=tuple(p for p in AFTER_TRAINING if p in phases))


def ordered(trials: pandas.DataFrame, design: StudyDesign) -> pandas.DataFrame:
    """``trials`` with ``phase`` an ordered categorical in protocol order and ``condition`` and ``group``
    categoricals with the control first (other conditions of other phases after them), so that sorting,
    grouping, patsy and plots follow the design instead of the alphabet."""
    pandas = _pandas()
    out = trials.copy()
    out["phase"] = pandas.Categorical(out["phase"].astype(str), categories=list(design.phases), ordered=True)
    for column in ("condition", "group"):
        if column not in out.columns:
            continue
        values = out[column].astype(str)
        rest = [v for v in dict.fromkeys(values) if v not in design.conditions]
        out[column] = pandas.Categorical(values, categories=list(design.conditions) + rest)
    return out


# ---------------------------------------------------------------------------------------------- exclusions


@dataclasses.dataclass(frozen=True)
class ExclusionPolicy:
    """Which trials enter the outcome analysis. ``keep_end_reasons``: the trials whose ``end_reason`` is one of
    these (default: only 'completed': a trial the writer gave up, that reached its time limit or was
    interrupted measured only part of the character, so its deviation and time are not comparable); None
    keeps every trial. A trial without a value of the outcome is left out of that outcome either way."""

    keep_end_reasons: typing.Optional[tuple[str, ...]] = ("completed",)

    def __post_init__(self) -> None:
        reasons = self.keep_end_reasons
        # One text is one end reason's name, never its letters (which would exclude every trial).
        if reasons is not None and (isinstance(reasons, (str, bytes)) or not all(isinstance(r, str) for r in reasons)):
            raise TypeError(f"keep_end_reasons: expected a sequence of end reasons (e.g. ('completed',)) or None, "
                            f"got {reasons!r}")

    def sentence(self) -> str:
        if self.keep_end_reasons is None:
            return "Every trial is analysed, however it ended."
        return (f"Only trials that ended {' or '.join(repr(r) for r in self.keep_end_reasons)} are analysed; the "
                "others are counted below.")


def apply_exclusions(trials: pandas.DataFrame, policy: ExclusionPolicy = ExclusionPolicy()
                     ) -> tuple[pandas.DataFrame, pandas.DataFrame]:
    """The trials the policy keeps, and a count table: one row per phase and group (or condition; in a
    crossover the condition each trial's item set is trained under, ``trained_condition``) with
    ``trials``, ``kept`` and one column per end reason excluded. Raises ValueError naming a missing
    ``end_reason`` column when the policy needs it."""
    pandas = _pandas()
    if policy.keep_end_reasons is None:
        kept = trials
    else:
        statistics._require_columns(trials, ["end_reason"], "apply_exclusions")
        kept = trials[trials["end_reason"].astype(str).isin(policy.keep_end_reasons)]
    trained = (trials["trained_condition"].astype(str).replace({"nan": ""}) if "trained_condition" in trials.columns
               else None)
    if trained is not None and (trained != "").any():
        by = ["phase", "trained_condition"]  # a crossover: a test trial counts for the condition its set trained
        # A block outside the crossover (a practice or familiarisation, or a between-subjects phase beside it)
        # trained no set: its trials count for the condition they were written under.
        if "condition" in trials.columns:
            trials = trials.assign(trained_condition=trained.where(trained != "", trials["condition"].astype(str)))
    elif "group" in trials.columns and (trials["group"].astype(str) != "").any():
        by = ["phase", "group"]
    else:
        by = ["phase", "condition"]
    reasons = trials["end_reason"].astype(str) if "end_reason" in trials.columns else pandas.Series(
        "", index=trials.index)
    excluded = pandas.Series(~trials.index.isin(kept.index), index=trials.index)
    rows = []
    for key, rows_of in trials.groupby(by, observed=True, sort=True):
        dropped = excluded.loc[rows_of.index]
        counts = {"trials": len(rows_of), "kept": int((~dropped).sum())}
        for reason, n in reasons.loc[rows_of.index][dropped].value_counts().items():
            counts[f"excluded_{reason}"] = int(n)
        rows.append({by[0]: key[0], by[1]: key[1], **counts})
    table = pandas.DataFrame(rows).fillna(0)
    for column in table.columns:
        if column.startswith("excluded_") or column in ("trials", "kept"):
            table[column] = table[column].astype(int)
    return kept, table


# ---------------------------------------------------------------------------------------------- numbers


def apa_sentence(df: float, t: float, p: float, g: float = math.nan, ci: tuple[float, float] = (math.nan, math.nan),
                 unit: str = "", scale: float = 1.0, decimals: int = 2) -> str:
    """An APA-style result (APA Publication Manual, 7th ed., 6.43-6.46): 't(7.8) = 2.43, p = .042, g = 1.39,
    95 % CI [0.01, 0.55] mm'; df with one decimal unless whole, p without its leading zero ('< .001' below),
    the interval of the difference multiplied by ``scale`` into ``unit``."""
    if not (math.isfinite(df) and math.isfinite(t)):
        return ""
    df_text = f"{df:.0f}" if abs(df - round(df)) < 0.05 else f"{df:.1f}"
    p_text = "p < .001" if p < 0.001 else f"p = {p:.3f}".replace("0.", ".", 1)
    parts = [f"t({df_text}) = {t:.2f}", p_text]
    if math.isfinite(g):
        parts.append(f"g = {g:.2f}")
    if all(math.isfinite(x) for x in ci):
        parts.append(f"95 % CI [{ci[0] * scale:.{decimals}f}, {ci[1] * scale:.{decimals}f}]{' ' + unit if unit else ''}")
    return ", ".join(parts)


def _subject_means(data: pandas.DataFrame, value: str) -> pandas.Series:
    return data.groupby(data["subject"].astype(str), observed=True)[value].mean().dropna()


# ---------------------------------------------------------------------------------------------- training


def _family(value: str, phase: typing.Optional[str]) -> str:
    """Holm's family: one outcome in one phase."""
    return f"{value}, {phase}"


def _training_rows(data: pandas.DataFrame, value: str, design: StudyDesign, ddf: str,
                   units: design_models.Units) -> list[dict]:
    """The crossed mixed model of the compared phase: each condition against the control and, with three or
    more, every other pair (emmeans); reduced by the documented rule when singular or not converged."""
    pandas = _pandas()
    column = "group" if design.kind == "between-subjects" else "condition"
    phase = design.compared_phase
    rows_of = data[(data["phase"].astype(str) == phase) & data[value].notna()]
    # Within subjects the condition's effect varies by subject: a random slope keeps its test at the subjects'
    # level (Barr, Levy, Scheepers & Tily 2013, J Mem Lang 68:255); without it the df are the trials'.
    within = design.kind == "within-subjects"
    subject_term = "(1 + factor | subject)" if within else "(1 | subject)"
    model = f"{value} ~ {column} + {subject_term.replace('factor', column)} + (1 | item)"
    base = {"value": value, "unit": _unit(value), "family": _family(value, phase), "phase": phase, "model": model,
            "question": f"{phase}: {column}s compared (mixed model, subjects x items crossed)"}
    n_items = rows_of["characters"].nunique()
    items = ["(1 | item)"] if n_items >= 2 else []
    frame = pandas.DataFrame({"outcome": rows_of[value].to_numpy(dtype=float),
                              "factor": rows_of[column].astype(str).to_numpy(),
                              "subject": rows_of["subject"].astype(str).to_numpy(),
                              "item": rows_of["characters"].astype(str).to_numpy()})
    levels = [c for c in design.conditions if c in set(frame["factor"])]
    too_few = design_models.too_few_to_fit(levels, design.control, frame["subject"].nunique(),
                                           between=design.kind == "between-subjects")
    if too_few:
        return design_models.not_computed_rows(base, design.conditions, design.control, too_few)
    # The documented reduction (design_models.fit_reduced): within subjects the slope's compound-symmetry form
    # is an intercept per subject and one per subject and condition.
    terms = ["(1 | subject)"] + (["(1 | subject:factor)"] if within else []) + items
    try:
        fit, dropped = design_models.fit_reduced(frame, ["factor"], {"factor": levels}, ddf, terms,
                                                 ([subject_term] + items) if within else None, units)
    except RuntimeError as error:  # RUnavailable among them: R or its packages missing
        return design_models.not_computed_rows(base, design.conditions, design.control, f"not computed: {error}")
    # One fit: whether it is a test, its note, subjects per level and subject means hold for every row.
    trusted = fit.trustworthy
    base["model"] = fit.formula.replace("outcome", value, 1).replace("factor", column)

    def name(group: str) -> str:  # R's names of the variances: 'subject factorfixture' -> 'subject group fixture'
        return group.replace("subject:factor", f"subject:{column}").replace("factor", column + " ").lower()

    note = design_models.fit_note(fit, [d.replace("factor", column) for d in dropped], units, name)
    counts = frame.groupby("factor")["subject"].nunique()
    subject_means = frame.groupby(["factor", "subject"])["outcome"].mean()
    factor = design_models.outcome_factor(frame["outcome"])
    rows = []

    def g_between(estimate: float, level: str, control: str) -> tuple[float, float, float]:
        if design.kind != "between-subjects":
            return math.nan, math.nan, math.nan
        # In the fit's unit (design_models.outcome_factor): g has none, and SDs near 1e-300 would underflow.
        a, b = subject_means.loc[level] * factor, subject_means.loc[control] * factor
        return _hedges_g_interval(estimate * factor, float(a.std(ddof=1)), float(b.std(ddof=1)), len(a), len(b))

    test = f"linear mixed model (REML), lme4 {fit.ddf} t ({fit.versions})"
    for effect in fit.fixed.itertuples(index=False):
        if effect.factor != "factor":
            continue
        g, g_low, g_high = g_between(float(effect.estimate), effect.level, design.control)
        rows.append(_row(
            **base, comparison=f"{effect.level} - {design.control}", test=test,
            n=int(counts.get(effect.level, 0) + counts.get(design.control, 0)),
            df=float(effect.df) if trusted else math.nan, statistic=float(effect.t) if trusted else math.nan,
            p=float(effect.p) if trusted else math.nan, estimate=float(effect.estimate),
            ci95_low=float(effect.ci95_low) if trusted else math.nan,
            ci95_high=float(effect.ci95_high) if trusted else math.nan, g=g, g_ci95_low=g_low, g_ci95_high=g_high,
            note=note))
    rows += design_models.absent_effect_rows(fit, "factor", levels, design.control, base)
    rows += design_models.pair_rows(
        fit, levels, design.control, base, note,
        lambda a, b: int(frame.loc[frame["factor"].isin([a, b]), "subject"].nunique()), g_between)
    return design_models.with_absent_levels(rows, base, list(design.conditions), levels, design.control,
                                            f"in {phase} (after the exclusions)")


# ---------------------------------------------------------------------------------------------- after training


def _ancova_rows(data: pandas.DataFrame, value: str, design: StudyDesign, phase: str) -> list[dict]:
    """``post ~ pre + group`` on subject means: each group against the control, adjusted for the pre-test."""
    import statsmodels.formula.api as smf

    pandas = _pandas()
    base = {"value": value, "unit": _unit(value), "family": _family(value, phase), "phase": phase,
            "model": f"{phase} mean ~ pre-test mean + group (subject means, OLS)",
            "question": f"{phase}: groups compared, adjusted for the pre-test (ANCOVA)"}
    groups = data.groupby(data["subject"].astype(str), observed=True)["group"].agg(lambda g: str(g.iloc[0]))
    pre = _subject_means(data[data["phase"].astype(str) == design.pre_test], value)
    post = _subject_means(data[data["phase"].astype(str) == phase], value)
    subjects = sorted(set(pre.index) & set(post.index))
    frame = pandas.DataFrame({"post": post.reindex(subjects).to_numpy(), "pre": pre.reindex(subjects).to_numpy(),
                              "group": groups.reindex(subjects).to_numpy()})
    levels = [g for g in design.conditions if g in set(frame["group"])]
    if design.control not in levels or len(levels) < 2 or len(frame) < len(levels) + 2:
        return design_models.not_computed_rows(base, design.conditions, design.control, f"not computed: {len(frame)} "
                                               f"subjects with a pre-test and a {phase} value in {len(levels)} group(s)")
    frame["group"] = pandas.Categorical(frame["group"], categories=levels)
    # In the unit that brings the phase's SD between 1 and 10 (as the mixed models are fitted): OLS is the same
    # in any unit, but sums of squares of an outcome near 1e-300 or 1e300 leave a double's range.
    factor = design_models.outcome_factor(frame["post"])
    frame["post"], frame["pre"] = frame["post"] * factor, frame["pre"] * factor
    fit = smf.ols("post ~ pre + C(group, Treatment(reference=0))", data=frame).fit()
    # A pre-test mean that the groups determine (the same within each group) leaves the adjusted difference
    # unidentified: OLS's pseudo-inverse would still give a number, one of infinitely many.
    rank = int(np.linalg.matrix_rank(fit.model.exog))
    if rank < fit.model.exog.shape[1]:
        return design_models.not_computed_rows(
            base, design.conditions, design.control, f"not computed: the pre-test mean is collinear with the groups "
            f"(the model's {fit.model.exog.shape[1]} columns have rank {rank}), so no adjusted difference is defined")
    # No residual variance (every subject's mean the same, or fitted exactly): t and p would be 0/0 or x/0,
    # numbers that are no test. R's lm warns of "essentially perfect fit" in the same case.
    # Rounding leaves ~1e-16 of the values' size where the exact answer is 0: below a part in 1e9 is none.
    rounding = (1e-9 * float(frame["post"].abs().max())) ** 2 * len(frame)
    spread = float(((frame["post"] - frame["post"].mean()) ** 2).sum())
    residual = float(fit.ssr)
    if not math.isfinite(residual) or residual <= max(rounding, 1e-12 * spread):
        return design_models.not_computed_rows(
            base, design.conditions, design.control, f"not computed: the {phase} means leave no residual variance "
            + ("(the outcome is the same for every subject)" if spread <= rounding else "(the model fits them exactly)"))
    interval = fit.conf_int(alpha=statistics.ALPHA)
    rows = []
    for k, level in enumerate(levels[1:], start=1):
        name = f"C(group, Treatment(reference=0))[T.{level}]"
        a = frame.loc[frame["group"] == level, "post"]
        b = frame.loc[frame["group"] == design.control, "post"]
        estimate = float(fit.params[name])
        g, g_low, g_high = _hedges_g_interval(estimate, float(a.std(ddof=1)), float(b.std(ddof=1)), len(a), len(b))
        rows.append(_row(**base, comparison=f"{level} - {design.control}",
                         test="ANCOVA (OLS on subject means, statsmodels); t of the adjusted difference",
                         n=len(a) + len(b), df=float(fit.df_resid), statistic=float(fit.tvalues[name]),
                         p=float(fit.pvalues[name]), estimate=estimate / factor,
                         ci95_low=float(interval.loc[name, 0]) / factor,
                         ci95_high=float(interval.loc[name, 1]) / factor, g=g, g_ci95_low=g_low, g_ci95_high=g_high,
                         note=f"pre-test slope {float(fit.params['pre']):.3g}; n per group "
                              + ", ".join(f"{lv} {int((frame['group'] == lv).sum())}" for lv in levels)))
    # With three or more groups every other pair: the difference of their adjusted means (the contrast of
    # their coefficients, as R's emmeans(lm(...), "group") |> pairs() gives it).
    for i, earlier in enumerate(levels[1:], start=1):
        for later in levels[i + 1:]:
            weights = np.zeros(len(fit.params))
            weights[list(fit.params.index).index(f"C(group, Treatment(reference=0))[T.{later}]")] = 1.0
            weights[list(fit.params.index).index(f"C(group, Treatment(reference=0))[T.{earlier}]")] = -1.0
            contrast = fit.t_test(weights)
            estimate = float(np.squeeze(contrast.effect))
            low, high = (float(x) for x in np.squeeze(contrast.conf_int(alpha=statistics.ALPHA)))
            a = frame.loc[frame["group"] == later, "post"]
            b = frame.loc[frame["group"] == earlier, "post"]
            g, g_low, g_high = _hedges_g_interval(estimate, float(a.std(ddof=1)), float(b.std(ddof=1)), len(a),
                                                  len(b))
            rows.append(_row(**base, comparison=f"{later} - {earlier}",
                             test="ANCOVA (OLS on subject means, statsmodels); t of the contrast of adjusted means",
                             n=len(a) + len(b), df=float(fit.df_resid), statistic=float(np.squeeze(contrast.tvalue)),
                             p=float(np.squeeze(contrast.pvalue)), estimate=estimate / factor, ci95_low=low / factor,
                             ci95_high=high / factor, g=g, g_ci95_low=g_low, g_ci95_high=g_high,
                             note=rows[0]["note"]))
    return design_models.with_absent_levels(rows, base, list(design.conditions), levels, design.control,
                                            f"with a pre-test and a {phase} value (after the exclusions)")


def _paired_rows(data: pandas.DataFrame, value: str, design: StudyDesign) -> list[dict]:
    phase = design.compared_phase
    rows_of = data[data["phase"].astype(str) == phase]
    # The same comparison as the mixed model's: a check beside it, not a second test in its Holm family.
    base = {"value": value, "unit": _unit(value), "family": f"{value} (checks)", "phase": phase,
            "model": "subject means per condition", "question": f"{phase}: condition against the control "
            "(paired, within subjects)"}
    rows = []
    present = set(rows_of.loc[rows_of[value].notna(), "condition"].astype(str))
    for level in design.conditions[1:]:
        absent = [c for c in (level, design.control) if c not in present]
        if absent:  # every trial excluded or missing: said as the models say it, not as the helper's error
            rows.append(_row(**base, comparison=f"{level} - {design.control}",
                             note=design_models.no_values_note(absent, f"in {phase} (after the exclusions)")))
            continue
        try:
            c = statistics.paired_comparison(rows_of, value, level, design.control, by="condition")
        except ValueError as error:
            rows.append(_row(**base, comparison=f"{level} - {design.control}", note=f"not computed: {error}"))
            continue
        g_se = math.sqrt(1.0 / c.n_subjects + c.g_av ** 2 / (2.0 * c.n_subjects)) if math.isfinite(c.g_av) else math.nan
        # Differences that do not vary (an outcome the same in every trial) leave t undefined: the row says why.
        note = "" if math.isfinite(c.t) else ("not tested: every subject's difference is the same (no variance), "
                                              "so there is no t statistic")
        rows.append(_row(**base, comparison=f"{level} - {design.control}",
                         test="paired t-test on subject means (scipy.stats.ttest_rel); Hedges' g_av",
                         n=c.n_subjects, df=float(c.df), statistic=float(c.t), p=float(c.p),
                         estimate=float(c.mean_difference), ci95_low=float(c.ci95_low), ci95_high=float(c.ci95_high),
                         g=float(c.g_av), g_ci95_low=c.g_av - 1.96 * g_se, g_ci95_high=c.g_av + 1.96 * g_se,
                         note=note))
    return rows


def design_questions(trials: pandas.DataFrame, value: str, design: typing.Optional[StudyDesign] = None, *,
                     policy: ExclusionPolicy = ExclusionPolicy(), ddf: str = "Satterthwaite",
                     scale: float = 1.0, display_unit: str = "") -> pandas.DataFrame:
    """The design's questions for the outcome ``value`` (see the module's docstring), one row per comparison
    against the control, with the columns of ``QUESTION_COLUMNS``: ``value``, ``unit`` (the SI unit of
    ``estimate`` and its interval), ``family`` (Holm's family: the outcome in one phase, 'VALUE, PHASE'; a
    design's checks 'VALUE (checks)', not adjusted), ``question``, ``phase``, ``comparison`` ('level -
    control', and with three or more conditions 'later - earlier' for every other pair), ``model``, ``test``, ``n`` (subjects), ``df``, ``statistic`` (t),
    ``p`` (two-sided), ``p_holm`` (Holm-adjusted within the family), ``estimate`` with ``ci95_low`` and
    ``ci95_high`` [SI unit], ``g`` with ``g_ci95_low``/``g_ci95_high`` (Hedges' g; g_av within subjects),
    ``apa`` (the sentence, its interval multiplied by ``scale`` into ``display_unit``) and ``note`` (why a
    row is not computed or not tested, or the variances, written times ``scale`` in ``display_unit`` when
    given, and what the documented reduction dropped). A model that is still singular or did not converge
    after the reduction keeps its estimate but has no df, statistic, p or interval: it is no test.

    ``trials`` are filtered by ``policy`` first. Raises ValueError naming a missing column."""
    pandas = _pandas()
    units = design_models.Units(_unit(value), scale if display_unit else 1.0, display_unit)
    statistics._check_frame(trials, "design_questions")
    statistics._require_columns(trials, ["subject", "phase", "condition", "characters", value], "design_questions")
    statistics._require_groups(trials, ["subject", "phase", "condition", "characters"], "design_questions")
    trials = statistics._finite_outcome(trials, value, "design_questions")
    design = design or study_design(trials)
    data, _ = apply_exclusions(trials, policy)
    rows: list[dict] = []
    if design.kind == "crossover":
        rows += crossover_analysis.questions(data, value, design, ddf, units)
    elif design.kind != "single-condition" and design.compared_phase is not None:
        rows += _training_rows(data, value, design, ddf, units)
    if design.kind == "between-subjects" and design.pre_test is not None:
        for phase in design.after_training:
            rows += _ancova_rows(data, value, design, phase)
    elif design.kind == "within-subjects":
        rows += _paired_rows(data, value, design)
    # Holm within each family: the outcome's comparisons in one phase, each pair of conditions once. A design's
    # checks (a crossover's carry-over test and Hills-Armitage) are their own family and are not adjusted.
    for family in dict.fromkeys(r["family"] for r in rows):
        members = [r for r in rows if r["family"] == family]
        checks = family.endswith("(checks)")
        adjusted = [math.nan] * len(members) if checks else _holm([float(r["p"]) for r in members])
        for row, p_holm in zip(members, adjusted):
            row["p_holm"] = p_holm
    for row in rows:
        if not row["apa"]:
            row["apa"] = apa_sentence(row["df"], row["statistic"], row["p"], row["g"],
                                      (row["ci95_low"], row["ci95_high"]), display_unit, scale)
    return pandas.DataFrame(rows, columns=QUESTION_COLUMNS)


# ---------------------------------------------------------------------------------------------- retention, transfer


def retention_ratios(trials: pandas.DataFrame, value: str, design: StudyDesign,
                     policy: ExclusionPolicy = ExclusionPolicy()) -> pandas.DataFrame:
    """Per group, the share of its gain kept at retention, mean(pre - retention) / mean(pre - post) over the
    group's subjects (errors and times: lower is better), computed only when the group's mean gain is
    reliably above 0 (its 95 % t interval excludes 0): a ratio of a gain near 0 is unbounded. Columns:
    ``group``, ``n``, ``gain`` with ``gain_ci95_low``/``gain_ci95_high`` [SI unit], ``retention_ratio``
    (NaN when not computed) and ``note``. Empty without pre-test, post-test and retention phases."""
    pandas = _pandas()
    if design.pre_test is None or not {"post-test", "retention"} <= set(design.after_training):
        return pandas.DataFrame(columns=statistics.RETENTION_COLUMNS)
    data, _ = apply_exclusions(statistics._finite_outcome(trials, value, "retention_ratios"), policy)
    if design.kind == "crossover":
        return crossover_analysis.retention_ratios(data, value, design)
    table = statistics.learning(data, value, design.pre_test, "post-test", retention="retention")
    column = "group" if "group" in table.columns else None
    rows = []
    for group in (design.conditions if column else ("all",)):
        subset = table[table[column].astype(str) == group] if column else table
        both = subset.dropna(subset=["pre", "post", "retention"])
        rows.append(statistics.retention_row(
            group, both["pre"], both["post"], both["retention"],
            "not computed: fewer than 2 subjects with pre-test, post-test and retention", "the group's gain"))
    return pandas.DataFrame(rows, columns=statistics.RETENTION_COLUMNS)


def transfer_baseline(trials: pandas.DataFrame, design: StudyDesign) -> str:
    """Why a transfer gain can or cannot be computed: a gain needs the transfer characters written in the
    pre-test too (the same characters before and after), else it measures the characters' difficulty."""
    if "transfer" not in design.after_training or design.pre_test is None:
        return ""
    pre = set(trials.loc[trials["phase"].astype(str) == design.pre_test, "characters"].astype(str))
    transfer = set(trials.loc[trials["phase"].astype(str) == "transfer", "characters"].astype(str))
    shared = sorted(pre & transfer)
    if shared:
        return (f"The transfer characters {' '.join(shared)} were also pre-tested: their gain is a gain on the "
                "same characters.")
    return ("No transfer gain is computed: the transfer characters (" + " ".join(sorted(transfer)) + ") were not "
            "written in the pre-test, so a difference from the pre-test would be the characters' difficulty, not "
            "transfer. The transfer row compares the groups' transfer performance adjusted for their pre-test skill "
            "on the trained characters. For a transfer gain, add the transfer characters to the pre-test.")
