"""What ``calligraphy.design_analysis`` and ``calligraphy.crossover_analysis`` share: the design read from a
study's table (``StudyDesign``), the rows of the questions table (``QUESTION_COLUMNS``), Holm's adjustment, and
the fitting of a linear mixed model the way every design fits it:

* in a well-scaled unit: the outcome (and a covariate in its unit, such as the pre-test mean) is multiplied by
  a power of ten that brings its SD between 1 and 10 before R fits it, and every estimate, interval and
  variance is converted back to the outcome's unit. Metres (a deviation's SD near 1e-4 m) would otherwise give
  lme4 fixed effects of very different scales ("Some predictor variables are on very different scales") and
  a fit that depends on the unit; t, df and p do not change with the unit.
* with the documented reduction (docs/experiments.md, "The design's questions"): the design's maximal
  random structure first; a fit that is singular (a variance at 0 or a correlation at +-1) or that did not
  converge is refitted with the slope's compound-symmetry form where there is a slope, then, while still
  singular or not converged, without the random term of the smallest variance; a term lme4 refuses (as many
  random effects as observations; the one its error names) is dropped in turn (Matuschek, Kliegl, Vasishth,
  Baayen & Bates 2017, J Mem Lang 94:305; Barr, Levy, Scheepers & Tily 2013, J Mem Lang 68:255). Each row
  shows the formula fitted and names what was reduced.
* every pairwise contrast of the compared factor when it has three or more levels (R's emmeans: estimated
  marginal means, the model's df method), beside the comparisons with the control.
"""

from __future__ import annotations

import dataclasses
import math
import re
import typing

import numpy as np

from . import mixed_models, statistics

if typing.TYPE_CHECKING:  # pragma: no cover
    import pandas

__all__ = ["QUESTION_COLUMNS", "StudyDesign"]

QUESTION_COLUMNS = ["value", "unit", "family", "question", "phase", "comparison", "model", "test", "n", "df",
                    "statistic", "p", "p_holm", "estimate", "ci95_low", "ci95_high", "g", "g_ci95_low",
                    "g_ci95_high", "apa", "note"]

_Z975 = 1.959963984540054


def unit(value: str) -> str:
    """The SI unit of an outcome column, from its name (_m: m, _s: s)."""
    return "m" if value.endswith("_m") else "s" if value.endswith("_s") else ""


def row(**entries: typing.Any) -> dict[str, typing.Any]:
    """One row of the questions table, NaN where not given."""
    out: dict[str, typing.Any] = dict.fromkeys(QUESTION_COLUMNS, math.nan)
    out.update(note="", apa="", model="", test="")
    out.update(entries)
    return out


def holm(p_values: list[float]) -> list[float]:
    """Holm's (1979) step-down adjusted p values; NaN entries stay NaN and are not counted."""
    from statsmodels.stats.multitest import multipletests

    finite = [k for k, p in enumerate(p_values) if isinstance(p, float) and math.isfinite(p)]
    adjusted = [math.nan] * len(p_values)
    if finite:
        _, corrected, _, _ = multipletests([p_values[k] for k in finite], alpha=statistics.ALPHA, method="holm")
        for k, value in zip(finite, corrected):
            adjusted[k] = float(value)
    return adjusted


def hedges_g_interval(difference: float, sd_a: float, sd_b: float, n_a: int, n_b: int
                      ) -> tuple[float, float, float]:
    """Hedges' g (``statistics._hedges_g``: the difference over the pooled SD, small-sample corrected) with
    the normal approximation of its 95 % interval, SE = sqrt((n_a + n_b) / (n_a n_b) + g^2 / (2 (n_a + n_b)))
    (Hedges & Olkin 1985, eq. 5.14)."""
    if n_a < 2 or n_b < 2:
        return math.nan, math.nan, math.nan
    # g has no unit: in the SDs' own size, so that an outcome near 1e300 (or 1e-300) squares to no overflow
    # (or 0) on the way.
    size = max(abs(sd_a), abs(sd_b))
    if math.isfinite(size) and size > 0:
        difference, sd_a, sd_b = difference / size, sd_a / size, sd_b / size
    g = statistics._hedges_g(difference, sd_a ** 2, sd_b ** 2, n_a, n_b)
    if not math.isfinite(g):
        return math.nan, math.nan, math.nan
    se = math.sqrt((n_a + n_b) / (n_a * n_b) + g * g / (2.0 * (n_a + n_b)))
    return g, g - _Z975 * se, g + _Z975 * se


@dataclasses.dataclass(frozen=True)
class Units:
    """How numbers in the notes of an outcome's rows are written for people: the SI value times ``scale`` in
    ``display`` (e.g. 1e3 and 'mm' for a length), labelled; the SI unit when no display unit is given."""

    si: str
    scale: float = 1.0
    display: str = ""

    @property
    def label(self) -> str:
        return self.display or self.si

    def variance(self, v: float) -> str:
        return f"{v * self.scale ** 2:.3g}"

    def variance_unit(self) -> str:
        return f" [{self.label}^2]" if self.label else ""

    def value(self, v: float) -> str:
        return f"{v * self.scale:.3g}"


# ---------------------------------------------------------------------------------------------- the design


@dataclasses.dataclass(frozen=True)
class StudyDesign:
    """What a study's table says about its design.

    ``kind``: 'between-subjects' (each subject in one ``group``), 'within-subjects' (every subject writes
    every condition of a phase) or 'single-condition'. ``phases``: in protocol order (by session, then
    block). ``conditions``: the compared conditions, the control first (the groups for a between-subjects
    design). ``control``: the reference every other condition is compared with. ``compared_phase``: where
    the conditions differ ('training', or the within-subjects phase). ``n_per_condition``: subjects per
    group (between) or subjects writing each condition (within). ``pre_test``: the pre-test phase or None.
    ``after_training``: the post-test, retention and transfer phases present, in order. For a 'crossover' (every
    subject trains every condition, each on its own item set, in counterbalanced sequences): ``sequences``
    (sequence -> subjects), ``periods`` (1, 2, ...), ``item_sets`` (set -> its characters, in the protocol's
    order) and ``pairing`` ((condition, set) -> subjects who trained that set under that condition), ``letters``
    (a sequence's letter -> its condition) and, in a mixed design (a between-subjects phase beside the
    crossover), ``groups`` (the subjects' group -> subjects)."""

    kind: str
    phases: tuple[str, ...]
    conditions: tuple[str, ...]
    control: typing.Optional[str]
    compared_phase: typing.Optional[str]
    n_per_condition: dict[str, int]
    pre_test: typing.Optional[str]
    after_training: tuple[str, ...]
    sequences: dict[str, int] = dataclasses.field(default_factory=dict)
    periods: tuple[int, ...] = ()
    item_sets: dict[str, str] = dataclasses.field(default_factory=dict)
    pairing: dict[tuple[str, str], int] = dataclasses.field(default_factory=dict)
    letters: dict[str, str] = dataclasses.field(default_factory=dict)
    groups: dict[str, int] = dataclasses.field(default_factory=dict)

    def sentence(self) -> str:
        """The design in one sentence, for a report's method section."""
        counts = ", ".join(f"{c} {'(control) ' if c == self.control else ''}n = {self.n_per_condition.get(c, 0)}"
                           for c in self.conditions)
        phases = ", ".join(self.phases)
        if self.kind == "between-subjects":
            return (f"Between-subjects: {len(self.conditions)} groups trained in {self.compared_phase} "
                    f"({counts} subjects); phases in order: {phases}.")
        if self.kind == "crossover":
            return self._crossover_sentence(counts, phases)
        if self.kind == "within-subjects":
            return (f"Within-subjects: every subject wrote {len(self.conditions)} conditions in "
                    f"{self.compared_phase} ({counts} subjects); phases in order: {phases}.")
        return f"One condition ({counts} subjects); phases in order: {phases}."

    def _crossover_sentence(self, counts: str, phases: str) -> str:
        n = max(self.n_per_condition.values(), default=0)
        sequences = ", ".join(f"{s} n = {k}" for s, k in self.sequences.items())
        letters = ", ".join(f"{letter} = {c}" for letter, c in self.letters.items())
        sets = "; ".join(f"{name}: {chars}" for name, chars in self.item_sets.items())
        pairing = "; ".join(f"{c} on {k} n = {m}" for (c, k), m in self.pairing.items())
        return (f"Crossover (within subjects): each of {n} subjects trained {len(self.conditions)} conditions in "
                f"{self.compared_phase} ({counts} subjects), each on its own item set, one per period "
                f"(periods {', '.join(str(p) for p in self.periods)}); sequences {sequences} ({letters}); item sets "
                f"{sets}; which set each condition trained: {pairing}"
                + (f"; and between subjects, a mixed design: groups {', '.join(f'{g} n = {k}' for g, k in self.groups.items())}"
                   if self.groups else "") + f"; phases in order: {phases}.")


# ---------------------------------------------------------------------------------------------- fitting


def outcome_factor(values: "pandas.Series") -> float:
    """The power of ten that brings the SD of ``values`` (an outcome) between 1 and 10 (1 for a constant
    outcome): the unit R fits in and the ANCOVA is computed in. The same data in metres and in millimetres get
    the same scaled numbers, and so do data near 1e-300 or 1e300, whose squares leave the range of a double:
    the SD is taken of the values divided by their largest size. The power stays within a double's range."""
    values = np.asarray(values, dtype=float)
    values = values[np.isfinite(values)]
    size = float(np.max(np.abs(values))) if len(values) > 1 else 0.0
    if size <= 0:
        return 1.0
    sd = float(np.std(values / size, ddof=1)) * size
    if not math.isfinite(sd) or sd <= 0:
        return 1.0
    return 10.0 ** min(max(-math.floor(math.log10(sd)), -307), 307)


# Columns in the outcome's unit: scaled with it.
_OUTCOME_COLUMNS = ("outcome", "pre")


def lmer_scaled(frame: "pandas.DataFrame", formula: str, factors: dict, ddf: str) -> "mixed_models.LmerFit":
    """``mixed_models.lmer`` on ``frame`` with the outcome (and ``pre``) in the unit of ``outcome_factor``, its
    results converted back to the outcome's unit: estimates, SEs and intervals of every fixed effect but a
    covariate in the outcome's unit (whose slope has no unit), variances, the pairwise contrasts."""
    factor = outcome_factor(frame["outcome"])
    # Rounded to 10 decimals (SD 1 to 10: 11 or more significant digits): the same data in two units give R
    # the same numbers, not numbers that differ in the last bit and a fit that ends on the other side of a
    # convergence tolerance.
    scaled = frame.assign(**{c: (frame[c] * factor).round(10) for c in _OUTCOME_COLUMNS if c in frame.columns})
    fit = mixed_models.lmer(scaled, formula, factors, ddf=ddf)
    if factor == 1.0:
        return fit
    fixed = fit.fixed.copy()
    in_unit = ~fixed["term"].isin([c for c in _OUTCOME_COLUMNS if c != "outcome"])
    for column in ("estimate", "std_error", "ci95_low", "ci95_high"):
        fixed.loc[in_unit, column] = fixed.loc[in_unit, column] / factor
    pairs = fit.pairs
    if pairs is not None:
        pairs = pairs.copy()
        for column in ("estimate", "std_error", "ci95_low", "ci95_high"):
            pairs[column] = pairs[column] / factor
    variances = {k: v / factor / factor for k, v in fit.variances.items()}
    return dataclasses.replace(fit, fixed=fixed, pairs=pairs, variances=variances)


def _group(term: str) -> str:
    """R's group name of a random intercept term '(1 | g)'."""
    return term.split("|", 1)[1].strip(" )")


def _problem(fit: "mixed_models.LmerFit") -> str:
    return "singular" if fit.singular else "did not converge"


def fit_reduced(frame: "pandas.DataFrame", fixed: list[str], factors: dict, ddf: str, terms: list[str],
                maximal: typing.Optional[list[str]] = None, units: Units = Units("")
                ) -> tuple["mixed_models.LmerFit", list[str]]:
    """Fits ``outcome ~ fixed + random`` with the random effects the data can estimate (see the module's
    docstring): ``maximal`` first when given (its first term the random slope), else ``terms``; a fit that is
    singular or did not converge, with ``terms`` (the slope's compound-symmetry form and the items' intercept);
    while still singular or not converged, without the term of the smallest variance; a term lme4 refuses is
    dropped, the first of ``terms`` last. Returns the last fit and what was reduced, one entry per step.
    Raises RUnavailable, and RuntimeError when even one random intercept cannot be fitted."""
    formula = "outcome ~ " + " + ".join(fixed) + " + "
    dropped: list[str] = []
    if maximal:
        try:
            fit = lmer_scaled(frame, formula + " + ".join(maximal), factors, ddf)
            if fit.trustworthy:
                return fit, []
            dropped.append(f"the random slope {maximal[0]}, {_problem(fit)}")
        except mixed_models.RUnavailable:
            raise
        except RuntimeError:
            dropped.append(f"the random slope {maximal[0]}, which lme4 could not fit")
    terms = list(terms)
    while True:
        try:
            fit = lmer_scaled(frame, formula + " + ".join(terms), factors, ddf)
        except mixed_models.RUnavailable:
            raise
        except RuntimeError as error:
            if len(terms) == 1:
                raise
            # lme4 names the grouping factors it refuses ("... (problems: subject)"): that term goes, the
            # subject's intercept last of those named; naming none, the items' before the subject's.
            named = re.search(r"\(problems: ([^)]*)\)", str(error))
            problems = {p.strip() for p in named.group(1).split(",")} if named else set()
            candidates = [t for t in terms[1:] + terms[:1] if _group(t) in problems] or terms[1:]
            refused = candidates[0]
            terms.remove(refused)
            dropped.append(f"{refused}, which lme4 could not fit")
            continue
        if fit.trustworthy or len(terms) == 1:
            return fit, dropped
        smallest = min(terms, key=lambda t: fit.variances.get(_group(t), 0.0))
        terms.remove(smallest)
        variance = units.variance(fit.variances.get(_group(smallest), 0.0))
        dropped.append(f"{smallest}, {_problem(fit)} (variance {variance}{units.variance_unit()})")


def fit_note(fit: "mixed_models.LmerFit", dropped: list[str], units: Units, name: typing.Callable[[str], str] = str
             ) -> str:
    """A row's note on its fit: the variances in the note's unit (``units``), or why the fit is no test; what
    was reduced ("reduced: refitted without ..."); lme4's warnings of a fit that is a test."""
    variances = ", ".join(f"{name(k)} {units.variance(v)}" for k, v in fit.variances.items()) + units.variance_unit()
    note = fit.note(variances)
    if dropped:
        note += "; reduced: refitted without " + "; ".join(dropped)
    if fit.trustworthy and fit.messages.strip():
        note += "; lme4 said: " + fit.messages.strip()
    return note


def planned_pairs(levels: list[str], control: str) -> list[tuple[str, str]]:
    """The comparisons a family holds as (later, earlier): each level against the control, then every other
    pair in the levels' order (``pair_rows``)."""
    others = [level for level in levels if level != control]
    return [(level, control) for level in others] + [(b, a) for i, a in enumerate(others) for b in others[i + 1:]]


def planned_comparisons(levels: list[str], control: str) -> list[str]:
    """The comparisons a family holds, as its rows name them: each level against the control
    ('level - control'), then every other pair 'later - earlier' in the levels' order (``pair_rows``)."""
    return [f"{b} - {a}" for b, a in planned_pairs(levels, control)]


def no_values_note(absent: typing.Sequence[str], where: str) -> str:
    """Why a comparison of levels without values ``where`` (every trial excluded, every value missing) has no
    numbers: the one wording of the models' rows and the paired check's."""
    return f"not computed: no values of {' or '.join(absent)} {where}"


def with_absent_levels(rows: list[dict], base: dict, levels: list[str], present: typing.Collection[str],
                       control: str, where: str) -> list[dict]:
    """``rows`` and a "not computed" row for each planned comparison (``planned_pairs``) of a level without
    values ``where`` (every trial excluded, every value missing), in the planned order: a group that lost
    every trial is a finding, not a row that silently leaves the table."""
    have = {r["comparison"]: r for r in rows}
    out = []
    for later, earlier in planned_pairs(levels, control):
        comparison = f"{later} - {earlier}"
        if comparison in have:
            out.append(have.pop(comparison))
            continue
        absent = [level for level in (later, earlier) if level not in present]
        if absent:
            out.append(row(**base, comparison=comparison, note=no_values_note(absent, where)))
    return out + list(have.values())


def too_few_to_fit(levels: typing.Sequence[str], control: str, subjects: int, between: bool = False
                   ) -> typing.Optional[str]:
    """Why a mixed model of ``levels`` (the conditions or groups with values) against ``control`` over ``subjects``
    cannot be fitted, naming what is short ("not computed: ..."); None when it can be. ``between``: each subject
    in one level (groups), so the levels need more subjects than levels."""
    if control not in levels:
        return f"not computed: the control '{control}' has no values"
    if len(levels) < 2:
        return "not computed: only one condition has values (a comparison needs 2)"
    if subjects < 3:
        return f"not computed: {subjects} subject{'' if subjects == 1 else 's'} with values (the model needs at least 3)"
    if between and subjects <= len(levels):
        # Each subject in one group: the groups' difference is tested against the subjects' spread, which
        # needs more subjects than groups; the trials' spread would make a test of the trials, not of people.
        return (f"not computed: {subjects} subjects in {len(levels)} groups (a between-subjects comparison needs more "
                "subjects than groups)")
    return None


def not_computed_rows(base: dict, levels: list[str], control: str, note: str, **kw) -> list[dict]:
    """One row per planned comparison of ``levels`` (``planned_comparisons``), each with the same note: why
    none was computed. The rows name the contrasts a reader looks for, not only the factor."""
    return [row(**base, comparison=comparison, note=note, **kw)
            for comparison in planned_comparisons(levels, control)]


def absent_effect_rows(fit: "mixed_models.LmerFit", factor: str, levels: list[str], control: str, base: dict,
                       **kw) -> list[dict]:
    """A "not computed" row for each level against the control that R's fit has no fixed effect for (lme4
    drops the column of a level it cannot tell apart from the others, a rank-deficient design), so that no
    planned comparison leaves the table without a word."""
    present = set(fit.fixed.loc[fit.fixed["factor"] == factor, "level"])
    return [row(**base, comparison=f"{level} - {control}", note=f"not computed: R's fit has no fixed effect for "
                f"{level} (lme4 drops a level it cannot estimate)", **kw)
            for level in levels if level != control and level not in present]


def pair_rows(fit: "mixed_models.LmerFit", levels: list[str], control: typing.Optional[str], base: dict, note: str,
              counts: typing.Callable[[str, str], int],
              g: typing.Optional[typing.Callable[[float, str, str], tuple[float, float, float]]] = None
              ) -> list[dict]:
    """The pairwise contrasts of a fit that do not involve the control (those are the fixed effects' rows):
    'later - earlier' in the levels' order, from R's emmeans; no test when the fit is none. ``counts(a, b)``:
    the subjects in the two levels; ``g(difference, later, earlier)``: the effect size and its interval.
    Empty for fewer than three levels; one row per pair saying why when emmeans gave none."""
    if len(levels) < 3:
        return []
    pairs = [(levels[i], levels[j]) for i in range(len(levels)) for j in range(i + 1, len(levels))]
    if fit.pairs is None or len(fit.pairs) != len(pairs):
        why = fit.pairs_note or "emmeans gave none"
        return [row(**base, comparison=f"{b} - {a}", note=f"not computed: the pairwise contrast ({why})")
                for a, b in pairs if control not in (a, b)]
    trusted = fit.trustworthy
    out = []
    for (a, b), contrast in zip(pairs, fit.pairs.itertuples(index=False)):
        if control in (a, b):
            continue
        effect = g(float(contrast.estimate), b, a) if g is not None else (math.nan, math.nan, math.nan)
        out.append(row(
            **base, comparison=f"{b} - {a}",
            test=f"linear mixed model (REML), emmeans pairwise contrast, {fit.ddf} t ({fit.versions})",
            n=counts(a, b), df=float(contrast.df) if trusted else math.nan,
            statistic=float(contrast.t) if trusted else math.nan, p=float(contrast.p) if trusted else math.nan,
            estimate=float(contrast.estimate), ci95_low=float(contrast.ci95_low) if trusted else math.nan,
            ci95_high=float(contrast.ci95_high) if trusted else math.nan, g=effect[0], g_ci95_low=effect[1],
            g_ci95_high=effect[2], note=note))
    return out
