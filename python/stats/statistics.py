"""Statistics a study publishes, over a tidy table of trials: intervals, paired comparisons between
conditions, a linear mixed model, learning and retention, and groups compared between subjects.

``trials`` is a pandas DataFrame with one row per trial and the columns ``subject``, ``session``,
``phase`` (e.g. 'practice', 'test', or 'pre-test', 'training', 'post-test', 'retention', 'transfer'),
``condition``, ``characters`` (str) and ``repetition`` (int, 1-based, as calligraphy.study gives it), plus numeric outcomes in SI units
named with their unit: ``mean_deviation_m``, ``max_deviation_m``, ``total_time_s``, ``pen_down_time_s``
(NaN for a trial that wrote nothing). Each function needs only the columns it uses, and reports in the
outcome's own unit. An infinite outcome counts as missing, like NaN, with a NonFiniteValueWarning naming
the column.

Trials of one subject are not independent. Inference about conditions therefore takes the subject as
its unit: ``paired_comparison`` averages each subject's trials per condition, ``mixed_model`` gives each
subject a random intercept. ``describe`` offers both units and says which one it used.

Every test and distribution comes from SciPy (Virtanen et al. 2020) and statsmodels (Seabold & Perktold
2010); nothing here replaces them. pandas, scipy and statsmodels are imported when a function is
called, not with ``calligraphy`` or this module (Debian: python3-pandas python3-scipy
python3-statsmodels). Sources are listed in docs/references.md.
"""

from __future__ import annotations

import dataclasses
import itertools
import math
import typing
import warnings

import numpy as np

if typing.TYPE_CHECKING:  # pragma: no cover
    import pandas

__all__ = [
    "GroupComparison",
    "NonFiniteValueWarning",
    "PairedComparison",
    "describe",
    "group_comparison",
    "learning",
    "mixed_model",
    "paired_comparison",
    "statistics_table",
]

# The two-sided level of every test and interval here, and the power a planned study aims at (Cohen 1988).
ALPHA = 0.05
TARGET_POWER = 0.8
# The largest noncentrality handed to scipy's noncentral t (see _power).
_NONCENTRALITY_LIMIT = 1000.0

# The columns of statistics_table, in order.
TABLE_COLUMNS = ["quantity", "comparison", "test", "n", "statistic", "df", "p", "effect", "effect_name",
                 "ci95_low", "ci95_high", "assumptions"]

Phase = typing.Union[str, typing.Sequence[str], None]


class _TooFewData(ValueError):
    """Raised when there are too few subjects, levels or values for a test: statistics_table reports
    such a comparison as not computed instead of failing."""


def _pandas():
    try:
        import pandas
    except ImportError as error:  # pragma: no cover - depends on the installation
        raise ImportError(
            "calligraphy.statistics needs pandas (Debian: apt-get install python3-pandas; or pip install pandas)"
        ) from error
    return pandas


def _scipy_stats():
    try:
        import scipy.stats
    except ImportError as error:  # pragma: no cover - depends on the installation
        raise ImportError(
            "calligraphy.statistics needs SciPy (Debian: apt-get install python3-scipy; or pip install scipy)"
        ) from error
    return scipy.stats


def _statsmodels_import_error(error: ImportError) -> ImportError:
    return ImportError("calligraphy.statistics needs statsmodels (Debian: apt-get install python3-statsmodels; "
                       "or pip install statsmodels)")


def _check_frame(trials: typing.Any, caller: str) -> None:
    pandas = _pandas()
    if not isinstance(trials, pandas.DataFrame):
        raise TypeError(f"{caller}: trials must be a pandas DataFrame (one row per trial), got "
                        f"{type(trials).__name__}")


def _require_columns(trials: pandas.DataFrame, columns: typing.Iterable[str], caller: str) -> None:
    missing = [column for column in dict.fromkeys(columns) if column not in trials.columns]
    if missing:
        names = ", ".join(repr(column) for column in missing)
        present = ", ".join(repr(column) for column in trials.columns)
        raise ValueError(f"{caller}: column {names} is not in trials; its columns: {present}")


def _require_groups(trials: pandas.DataFrame, columns: typing.Iterable[str], caller: str) -> None:
    """Every row names its level of each grouping column (subject, condition, characters, ...): a missing
    one (NaN, None, NaT) raises ValueError naming the column, the count and the first row's index, instead of
    the row being dropped without a word or failing deep inside a fit."""
    for column in dict.fromkeys(columns):
        missing = trials[column].isna()
        if missing.any():
            first = trials.index[missing.to_numpy()][0]
            raise ValueError(f"{caller}: column {column!r} has {int(missing.sum())} missing value(s) (NaN or "
                             f"None), the first at row {first!r}: every trial must name its {column}")


class NonFiniteValueWarning(UserWarning):
    """An outcome column held +inf or -inf: those values were counted as missing, like NaN."""


def _finite_outcome(trials: pandas.DataFrame, value: str, caller: str) -> pandas.DataFrame:
    """``trials`` with ``value`` checked numeric and its infinite values made NaN (missing), so that every
    statistic leaves them out and counts them in ``n_missing`` instead of returning NaN or inf. Warns
    NonFiniteValueWarning naming the column and the count; raises TypeError for a column not numeric."""
    pandas = _pandas()
    if not pandas.api.types.is_numeric_dtype(trials[value]) or pandas.api.types.is_bool_dtype(trials[value]):
        raise TypeError(f"{caller}: column {value!r} must be numeric (an outcome in SI units), "
                        f"it has dtype {trials[value].dtype}")
    # As float64, pandas' missing value (pd.NA of a nullable column: Float64, Int64, convert_dtypes) as NaN,
    # so that every statistic and fit reads one kind of number and one kind of missing.
    numbers = trials[value].to_numpy(dtype=float, na_value=np.nan)
    infinite = np.isinf(numbers)
    if infinite.any():
        warnings.warn(f"{caller}: column {value!r} holds {int(infinite.sum())} infinite value(s); they are counted "
                      "as missing (like NaN)", NonFiniteValueWarning, stacklevel=3)
        numbers = np.where(infinite, np.nan, numbers)
    elif trials[value].dtype == np.float64:
        return trials
    return trials.assign(**{value: pandas.Series(numbers, index=trials.index)})


def _levels(column: pandas.Series) -> list[typing.Any]:
    """The distinct values of a column that occur: in a categorical column's order, else sorted (as patsy
    orders a factor's levels)."""
    present = set(column.dropna().tolist())
    if hasattr(column, "cat"):
        return [level for level in column.cat.categories if level in present]
    return sorted(present, key=lambda level: (str(type(level)), level))


def _phase_text(phase: Phase) -> str | None:
    if phase is None:
        return None
    return phase if isinstance(phase, str) else ", ".join(str(p) for p in phase)


def _select_phase(trials: pandas.DataFrame, phase: Phase, caller: str) -> pandas.DataFrame:
    """The rows of the given phase (a name or several), or every row for None. Raises ValueError naming a
    phase not present and listing those present."""
    if phase is None:
        return trials
    phases = [phase] if isinstance(phase, str) else list(phase)
    if not phases:
        raise ValueError(f"{caller}: phase is an empty list; give a phase name, several, or None for all rows")
    _require_columns(trials, ["phase"], caller)
    present = _levels(trials["phase"])
    for name in phases:
        if name not in present:
            raise ValueError(f"{caller}: phase {name!r} is not in trials' 'phase' column; phases present: "
                             f"{', '.join(repr(p) for p in present)}")
    return trials[trials["phase"].isin(phases)]


def _column_names(columns: str | typing.Sequence[str], argument: str, caller: str) -> list[str]:
    if isinstance(columns, str):
        return [columns]
    if not isinstance(columns, typing.Sequence):
        raise TypeError(f"{caller}: {argument} must be a column name or a sequence of them, got "
                        f"{type(columns).__name__}")
    return list(columns)


RETENTION_COLUMNS = ["group", "n", "gain", "gain_ci95_low", "gain_ci95_high", "retention_ratio", "note"]


def _power_of_two(values) -> float:
    """A power of two that brings the largest finite size among ``values`` into [0.5, 1). Sums of squares of
    values near 1e-300 or 1e300 then stay within a double's range; a power of two scales exactly, so any other
    data give the same result to the bit."""
    sizes = np.abs(np.asarray(values, dtype=float))
    sizes = sizes[np.isfinite(sizes)]
    largest = float(sizes.max()) if sizes.size else 0.0
    if not largest > 0:
        return 1.0
    return math.ldexp(1.0, min(max(-math.frexp(largest)[1], -1000), 1000))


def sample_sd(values) -> float:
    """The sample standard deviation (n - 1) of ``values`` (NaN skipped in a pandas Series, as its ``std``),
    taken at the scale of ``_power_of_two``: an outcome near 1e-300 does not read as constant nor one near 1e300
    as infinitely spread."""
    scale = _power_of_two(values)
    scaled = values * scale if hasattr(values, "std") else np.asarray(values, dtype=float) * scale
    return float(scaled.std(ddof=1)) / scale


def retention_row(group: str, pre, post, retention, too_few: str, whose_gain: str) -> dict:
    """One row of a retention-ratio table (columns RETENTION_COLUMNS) from per-subject means of the same
    subjects [n] (errors and times: lower is better): the gain pre - post with its 95 % t interval, and
    mean(pre - retention) / mean(pre - post), computed only when the mean gain is reliably above 0 (its
    interval excludes 0), as a ratio of a gain near 0 is unbounded. ``too_few`` is the note when fewer than 2
    subjects have all three means; ``whose_gain`` names the gain in the note when it is not reliable ("the
    group's gain")."""
    pre, post, retention = (np.asarray(x, dtype=float) for x in (pre, post, retention))
    gains = pre - post
    n = len(gains)
    low, high = _t_interval(np.array([gains.mean() if n else math.nan]),
                            np.array([sample_sd(gains) if n > 1 else math.nan]), np.array([n]))
    ratio, note = math.nan, ""
    if n < 2:
        note = too_few
    elif not low[0] > 0:
        note = f"not computed: {whose_gain} is not reliably above 0 (95 % CI [{low[0]:.3g}, {high[0]:.3g}])"
    else:
        ratio = float((pre - retention).mean() / gains.mean())
    return {"group": group, "n": n, "gain": float(gains.mean()) if n else math.nan,
            "gain_ci95_low": float(low[0]), "gain_ci95_high": float(high[0]), "retention_ratio": ratio,
            "note": note}


def _t_interval(mean: np.ndarray, sd: np.ndarray, n: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The 95 % t interval of a mean from its sample's sd and size (Student 1908, scipy.stats.t); NaN where
    n < 2."""
    stats = _scipy_stats()
    mean, sd, n = (np.asarray(x, dtype=float) for x in (mean, sd, n))
    low = np.full(mean.shape, np.nan)
    high = np.full(mean.shape, np.nan)
    valid = (n >= 2) & (sd > 0)
    if np.any(valid):
        low[valid], high[valid] = stats.t.interval(1.0 - ALPHA, df=n[valid] - 1, loc=mean[valid],
                                                   scale=sd[valid] / np.sqrt(n[valid]))
    # Values that do not vary have no spread to estimate: the interval is the mean itself.
    constant = (n >= 2) & (sd == 0)
    low[constant] = high[constant] = mean[constant]
    return low, high


def describe(trials: pandas.DataFrame, value: str, by: str | typing.Sequence[str] = ("phase", "condition"),
             unit: str = "trial") -> pandas.DataFrame:
    """Mean, standard deviation and 95 % t interval of ``value`` per group of ``by``.

    ``unit="trial"`` (default) describes the trials of each group as they are; ``unit="subject"`` first
    averages each subject's trials within the group and describes those subject means, so that n counts
    subjects, the unit of inference when trials of one subject are not independent. NaN values (a trial
    that wrote nothing) and infinite values (warned as NonFiniteValueWarning) are left out and counted.

    Returns a DataFrame with one row per group (sorted by ``by``; one row in all for ``by=()``): the
    ``by`` columns, ``unit`` ('trial' or 'subject'), ``n`` (trials or subjects with a value),
    ``n_missing`` (trials with NaN), ``mean``, ``sd`` (sample, n - 1), ``sem`` (sd / sqrt(n)),
    ``ci95_low`` and ``ci95_high`` in the unit of ``value`` (sd, sem and the interval NaN for n < 2),
    ``test`` and ``assumptions`` (text). The interval is mean +- t(0.975, n - 1) sem (Student 1908,
    ``scipy.stats.t.interval``); it assumes independent units and a mean approximately normal.

    Raises TypeError when ``trials`` is not a DataFrame or ``value`` is not numeric; ValueError naming a
    missing column or an unknown ``unit``.
    """
    pandas = _pandas()
    caller = "describe"
    _check_frame(trials, caller)
    by = _column_names(by, "by", caller)
    if unit not in ("trial", "subject"):
        raise ValueError(f"describe: unit must be 'trial' or 'subject', got {unit!r}")
    if unit == "subject" and "subject" in by:
        raise ValueError("describe: by contains 'subject', so each group holds one subject; use unit='trial'")
    needed = [*by, value] + (["subject"] if unit == "subject" else [])
    _require_columns(trials, needed, caller)
    _require_groups(trials, [column for column in needed if column != value], caller)
    trials = _finite_outcome(trials, value, caller)

    # A constant key stands in for the groups when the whole table is one group.
    everything = "__all__"
    keys = by if by else [everything]
    data = trials[list(dict.fromkeys(needed))].assign(**({everything: 0} if not by else {}))
    missing = data[value].isna()
    n_missing = missing.groupby([data[k] for k in keys], observed=True, sort=True).sum()
    if not by:  # the whole table is one group, also when it has no rows: one row in all, with n = 0
        n_missing = n_missing.reindex(pandas.Index([0], name=everything), fill_value=0)
    units = data[~missing]
    if unit == "subject":
        units = units.groupby([*keys, "subject"], observed=True, sort=True)[value].mean().reset_index()
    # At the scale of _power_of_two (exact): values near 1e-300 or 1e300 keep their spread.
    scale = _power_of_two(units[value])
    summary = units.assign(**{value: units[value] * scale}).groupby(keys, observed=True, sort=True)[value].agg(
        ["count", "mean", "std"])
    summary[["mean", "std"]] = summary[["mean", "std"]] / scale
    summary = summary.reindex(n_missing.index)  # groups whose every trial is NaN keep a row with n = 0
    n = summary["count"].fillna(0).astype(int).to_numpy()
    sd = np.where(n >= 2, summary["std"].to_numpy(dtype=float), np.nan)
    low, high = _t_interval(summary["mean"].to_numpy(dtype=float), sd, n)
    table = pandas.DataFrame(index=n_missing.index).reset_index()
    if not by:
        table = table.drop(columns=[everything])
    table["unit"] = unit
    table["n"] = n
    table["n_missing"] = n_missing.to_numpy().astype(int)
    table["mean"] = summary["mean"].to_numpy(dtype=float)
    table["sd"] = sd
    table["sem"] = sd / np.sqrt(np.where(n > 0, n, np.nan))
    table["ci95_low"] = low
    table["ci95_high"] = high
    if by:
        # pandas 1.5 leaves categorical groups in order of appearance when observed=True.
        table = table.sort_values(by, kind="stable").reset_index(drop=True)
    table["test"] = "95 % t interval (Student 1908), scipy.stats.t"
    table["assumptions"] = (
        "trials independent; mean approximately normal (trials of one subject are correlated: use "
        "unit='subject' for inference)" if unit == "trial" else
        "subjects independent; mean of the subject means approximately normal; each subject's trials averaged"
    )
    return table


@dataclasses.dataclass(frozen=True)
class PairedComparison:
    """A paired comparison of ``value`` between conditions ``a`` and ``b`` of column ``by`` over the
    subjects who have both (``paired_comparison``). Means and differences are in the unit of ``value``;
    the difference is a - b.

    Fields: ``value``, ``by``, ``a``, ``b``, ``phase`` (the phases compared, comma-separated, or None for
    all rows); ``n_subjects`` (subjects with both), ``n_subjects_unpaired`` (subjects with only one, left
    out); ``mean_a``, ``mean_b`` (means of the subject means); ``mean_difference``, ``sd_difference``
    (sample sd of the subjects' differences), ``ci95_low``, ``ci95_high`` (its 95 % t interval); ``t``,
    ``df`` (n - 1), ``p`` (two-sided paired t-test, Student 1908, ``scipy.stats.ttest_rel``);
    ``wilcoxon_statistic``, ``wilcoxon_p`` (two-sided signed-rank test, Wilcoxon 1945,
    ``scipy.stats.wilcoxon``; NaN when every difference is 0); ``d_z`` = mean difference / sd of the
    differences, ``d_av`` = mean difference / mean of the two conditions' sds (Lakens 2013, eqs. 6 and 10),
    ``g_av`` = d_av x (1 - 3 / (4 df - 1)), Hedges' small-sample correction with the paired test's df
    (Hedges 1981; Lakens 2013's eq. 4 is the same with df = n1 + n2 - 2; NaN with 2 subjects, whose df of 1
    makes the correction 0); ``power``, the power of
    a two-sided paired t-test at alpha .05 with n subjects for an effect of |d_z|, and
    ``n_for_80_percent_power``, the subjects such a test needs for power 0.8 at that effect, rounded up
    (Cohen 1988, ``statsmodels.stats.power.TTestPower``; NaN when d_z is 0 or undefined); ``test`` and
    ``assumptions`` (text); ``subject_means``, a DataFrame indexed by subject with columns ``a``, ``b``
    and ``difference``.

    The power of the observed effect follows from p and adds no evidence of its own; n for 80 % power
    is for planning the next study, taking the observed d_z (biased upwards in small samples) as true.
    """

    value: str
    by: str
    a: typing.Any
    b: typing.Any
    phase: str | None
    n_subjects: int
    n_subjects_unpaired: int
    mean_a: float
    mean_b: float
    mean_difference: float
    sd_difference: float
    ci95_low: float
    ci95_high: float
    t: float
    df: int
    p: float
    wilcoxon_statistic: float
    wilcoxon_p: float
    d_z: float
    d_av: float
    g_av: float
    power: float
    n_for_80_percent_power: float
    test: str
    assumptions: str
    subject_means: pandas.DataFrame = dataclasses.field(repr=False, compare=False)

    def to_frame(self) -> pandas.DataFrame:
        """One row with every field but ``subject_means``, the fields' names as columns."""
        pandas = _pandas()
        row = {field.name: getattr(self, field.name) for field in dataclasses.fields(self)
               if field.name != "subject_means"}
        return pandas.DataFrame([row])


def _subject_means(data: pandas.DataFrame, value: str, by: str, a: typing.Any, b: typing.Any
                   ) -> tuple[pandas.DataFrame, int]:
    """Each subject's mean of ``value`` under a and under b (NaN trials left out), for the subjects with
    both; and how many subjects had only one."""
    chosen = data[data[by].isin([a, b]) & data[value].notna()]
    means = chosen.groupby(["subject", by], observed=True, sort=True)[value].mean().unstack(by)
    means = means.reindex(columns=[a, b])
    paired = means.dropna()
    paired.columns = ["a", "b"]
    paired = paired.assign(difference=paired["a"] - paired["b"])
    return paired, len(means) - len(paired)


def _power(analysis: typing.Any, effect: float, nobs: int) -> float:
    """statsmodels' power of a two-sided one-sample (paired) t-test at alpha .05."""
    # scipy's noncentral t (Boost) aborts the process for noncentralities above about 65,000. Power is
    # monotone in the noncentrality and already 1 in double precision at 1000, so the effect is capped there.
    capped = min(effect, _NONCENTRALITY_LIMIT / math.sqrt(nobs))
    # Boost's noncentral t sets divide-by-zero and invalid flags in far tails whose values come out right
    # (0 or 1); numpy would turn them into RuntimeWarnings about nothing.
    with np.errstate(divide="ignore", invalid="ignore"):
        return float(analysis.power(effect_size=capped, nobs=nobs, alpha=ALPHA, alternative="two-sided"))


def _subjects_for_power(analysis: typing.Any, effect: float) -> float:
    """The fewest subjects (at least 2, the t-test's minimum) whose two-sided paired t-test reaches
    TARGET_POWER at alpha .05 for a standardized effect ``effect`` > 0, from statsmodels' solve_power;
    NaN when it finds none."""
    if _power(analysis, effect, 2) >= TARGET_POWER:
        return 2.0  # below 2 there is no test; solve_power's search would also leave the valid range
    # As in _power; solve_power's root search also tries sample sizes below 2, where t has no df.
    with np.errstate(divide="ignore", invalid="ignore"):
        solved = np.asarray(analysis.solve_power(effect_size=effect, nobs=None, alpha=ALPHA, power=TARGET_POWER,
                                                 alternative="two-sided"), dtype=float).ravel()
    if solved.size != 1 or not math.isfinite(solved[0]):
        return math.nan
    # statsmodels returns its starting value when the search fails: accept only an n that reaches the
    # power where one subject fewer does not (one more allowed for the root's rounding).
    for candidate in (max(2, math.ceil(solved[0])), max(2, math.ceil(solved[0])) + 1):
        if _power(analysis, effect, candidate) >= TARGET_POWER and (
                candidate == 2 or _power(analysis, effect, candidate - 1) < TARGET_POWER):
            return float(candidate)
    return math.nan


def paired_comparison(trials: pandas.DataFrame, value: str, a: typing.Any, b: typing.Any, by: str = "condition",
                      phase: Phase = None) -> PairedComparison:
    """Compares ``value`` between conditions ``a`` and ``b`` (values of column ``by``) within subjects.

    Each subject's trials are averaged per condition (NaN trials left out); the subjects with a mean
    under both are compared, each counting once, by a two-sided paired t-test (Student 1908,
    ``scipy.stats.ttest_rel``) with the 95 % t interval of the mean difference a - b, and by the Wilcoxon
    signed-rank test (Wilcoxon 1945, ``scipy.stats.wilcoxon``) as the check that needs no normality.
    Effect sizes are Cohen's d_z and Hedges' g_av (Lakens 2013, for within-subjects designs); the
    power of the observed d_z and the subjects needed for 80 % power come from
    ``statsmodels.stats.power.TTestPower`` (Cohen 1988). ``phase`` (a name, several, or None for every
    row) restricts the trials first.

    Returns a ``PairedComparison`` (its fields are documented there; ``.to_frame()`` gives one row).

    Raises TypeError when ``trials`` is not a DataFrame or ``value`` is not numeric; ValueError naming a
    missing column, a condition or phase not present (listing those present), a = b, or fewer than 2
    subjects with values under both conditions.
    """
    caller = "paired_comparison"
    stats = _scipy_stats()
    try:
        from statsmodels.stats.power import TTestPower
    except ImportError as error:  # pragma: no cover - depends on the installation
        raise _statsmodels_import_error(error) from error
    _check_frame(trials, caller)
    _require_columns(trials, ["subject", by, value], caller)
    _require_groups(trials, ["subject", by], caller)
    trials = _finite_outcome(trials, value, caller)
    data = _select_phase(trials, phase, caller)
    present = _levels(data[by])
    for name in (a, b):
        if name not in present:
            where = f" in phase {_phase_text(phase)}" if phase is not None else ""
            raise ValueError(f"{caller}: {by} {name!r} is not in trials' {by!r} column{where}; present: "
                             f"{', '.join(repr(level) for level in present)}")
    if a == b:
        raise ValueError(f"{caller}: a and b are both {a!r}; compare two different values of {by!r}")

    means, unpaired = _subject_means(data, value, by, a, b)
    n = len(means)
    if n < 2:
        raise _TooFewData(f"{caller}: {n} subject(s) have values of {value!r} under both {a!r} and {b!r}; "
                          "a paired comparison needs at least 2")
    x = means["a"].to_numpy(dtype=float)
    y = means["b"].to_numpy(dtype=float)
    difference = means["difference"].to_numpy(dtype=float)
    df = n - 1
    mean_difference = float(np.mean(difference))
    sd_difference = float(np.std(difference, ddof=1))
    low, high = _t_interval(np.array([mean_difference]), np.array([sd_difference]), np.array([n]))
    t_test = stats.ttest_rel(x, y)
    if np.all(difference == 0):
        # scipy.stats.wilcoxon refuses differences that are all 0: there is nothing to rank.
        wilcoxon_statistic, wilcoxon_p = math.nan, math.nan
    else:
        signed_rank = stats.wilcoxon(x, y)
        wilcoxon_statistic, wilcoxon_p = float(signed_rank.statistic), float(signed_rank.pvalue)

    d_z = mean_difference / sd_difference if sd_difference > 0 else math.nan
    sd_average = (np.std(x, ddof=1) + np.std(y, ddof=1)) / 2.0
    d_av = mean_difference / sd_average if sd_average > 0 else math.nan
    # Hedges' approximation of the bias correction, with the paired test's df (Hedges 1981). At df = 1 (two
    # subjects) the correction is 0, exactly as the exact one is: a g of 0 beside any d would be no estimate.
    g_av = d_av * (1.0 - 3.0 / (4.0 * df - 1.0)) if df >= 2 else math.nan
    power = needed = math.nan
    if math.isfinite(d_z) and d_z != 0:
        power = _power(TTestPower(), abs(d_z), n)
        needed = _subjects_for_power(TTestPower(), abs(d_z))

    return PairedComparison(
        value=value, by=by, a=a, b=b, phase=_phase_text(phase),
        n_subjects=n, n_subjects_unpaired=unpaired,
        mean_a=float(np.mean(x)), mean_b=float(np.mean(y)),
        mean_difference=mean_difference, sd_difference=sd_difference,
        ci95_low=float(low[0]), ci95_high=float(high[0]),
        t=float(t_test.statistic), df=df, p=float(t_test.pvalue),
        wilcoxon_statistic=wilcoxon_statistic, wilcoxon_p=wilcoxon_p,
        d_z=d_z, d_av=float(d_av), g_av=float(g_av), power=power, n_for_80_percent_power=needed,
        test=("paired t-test (Student 1908), scipy.stats.ttest_rel; Wilcoxon signed-rank (Wilcoxon 1945), "
              "scipy.stats.wilcoxon; d_z, g_av (Lakens 2013); power, statsmodels TTestPower (Cohen 1988)"),
        assumptions=("subjects independent; each subject's trials averaged per condition; differences "
                     "approximately normal (t-test) or symmetric about their median (Wilcoxon)"),
        subject_means=means,
    )


def _fixed_effect_label(name: str, fixed: str, levels: list[typing.Any], reference: typing.Any) -> str:
    """statsmodels' 'C(factor)[T.level]' in the caller's names: 'condition[T.level]'."""
    if name == "Intercept":
        return f"Intercept ({fixed}={reference})"
    for level in levels:
        if name.endswith(f"[T.{level}]"):
            return f"{fixed}[T.{level}]"
    return name  # pragma: no cover - statsmodels names every level so


def mixed_model(trials: pandas.DataFrame, value: str, fixed: str = "condition", phase: Phase = None,
                *, reference: typing.Any = None) -> pandas.DataFrame:
    """A linear mixed model of ``value`` with ``fixed`` as a categorical fixed effect, a random intercept
    per subject and the characters as a variance component, fitted by REML with statsmodels (Lindstrom &
    Bates 1988; Seabold & Perktold 2010):
    ``MixedLM.from_formula("value ~ C(fixed)", groups="subject", re_formula="1",
    vc_formula={"character": "0 + C(characters)"})``, in lme4's notation (Bates et al. 2015)
    ``value ~ fixed + (1 | subject) + (1 | subject:characters)``: the character component is one
    intercept per character within each subject. With a single character it is left out. Wald z is a
    large-sample test: a study with few subjects, every subject writing every character, is analysed with
    subjects and items crossed and Satterthwaite df by ``calligraphy.design_analysis`` (R's lme4, lmerTest).

    Rows whose ``value`` is NaN are dropped and counted. ``phase`` (a name, several, or None for every
    row) restricts the trials first. ``reference`` is the level the others are compared with (default:
    the first in sorted order, or a categorical column's first category). The outcome is divided by its
    standard deviation for the fit and the results multiplied back: REML is equivariant under scaling,
    and statsmodels' check for a variance on the boundary (below 0.01) is absolute, so outcomes in
    metres would always trip it.

    Returns a DataFrame with one row per fixed effect: ``term`` ('Intercept (condition=ref)', the
    reference level's mean, and 'condition[T.level]', a level's difference from it), ``estimate``,
    ``std_error``, ``ci95_low``, ``ci95_high`` (Wald, in the unit of ``value``), ``z``, ``p`` (two-sided),
    and on every row ``n_observations``, ``n_subjects``, ``n_characters``, ``n_dropped`` (NaN rows),
    ``formula``, ``method`` ('REML'), ``converged`` (statsmodels' optimizer converged), ``fit_warnings``
    (statsmodels' ConvergenceWarnings of this fit, e.g. a variance on the boundary, '' for none),
    ``test`` and ``assumptions``. ``.attrs`` holds the same plus ``subject_variance``,
    ``character_variance`` and ``residual_variance`` [unit of value squared] and ``lme4_formula``.
    ConvergenceWarnings are caught for this fit only and recorded, not raised; other warnings pass on.

    Raises TypeError when ``trials`` is not a DataFrame or ``value`` is not numeric; ValueError naming a
    missing column, a phase or reference not present, fewer than 2 levels of ``fixed`` or 2 subjects with
    values, or a constant outcome.
    """
    caller = "mixed_model"
    pandas = _pandas()
    try:
        from statsmodels.regression.mixed_linear_model import MixedLM
        from statsmodels.tools.sm_exceptions import ConvergenceWarning
    except ImportError as error:  # pragma: no cover - depends on the installation
        raise _statsmodels_import_error(error) from error
    _check_frame(trials, caller)
    _require_columns(trials, ["subject", "characters", fixed, value], caller)
    _require_groups(trials, ["subject", "characters", fixed], caller)
    trials = _finite_outcome(trials, value, caller)
    data = _select_phase(trials, phase, caller)
    kept = data[data[value].notna()]
    n_dropped = len(data) - len(kept)
    levels = _levels(kept[fixed])
    if len(levels) < 2:
        raise _TooFewData(f"{caller}: {fixed!r} has {len(levels)} level(s) with values of {value!r}; a fixed "
                          "effect needs at least 2")
    if reference is None:
        reference = levels[0]
    elif reference not in levels:
        raise ValueError(f"{caller}: reference {reference!r} is not a level of {fixed!r} with values; levels: "
                         f"{', '.join(repr(level) for level in levels)}")
    n_subjects = kept["subject"].nunique()
    if n_subjects < 2:
        raise _TooFewData(f"{caller}: {n_subjects} subject(s) have values of {value!r}; a random subject "
                          "intercept needs at least 2")
    n_characters = kept["characters"].nunique()
    scale = float(kept[value].std(ddof=1))
    if not scale > 0:
        raise _TooFewData(f"{caller}: {value!r} is constant over the {len(kept)} trials with a value; "
                          "nothing to model")

    # Fixed internal names keep patsy away from column names that are not Python identifiers; the
    # factor's categories put the reference first, which patsy takes as the baseline.
    order = [reference] + [level for level in levels if level != reference]
    frame = pandas.DataFrame({
        "outcome": kept[value].to_numpy(dtype=float) / scale,
        "factor": pandas.Categorical(kept[fixed].tolist(), categories=order),
        "subject": kept["subject"].astype(str).to_numpy(),
        "characters": kept["characters"].astype(str).to_numpy(),
    })
    with_characters = n_characters >= 2
    vc_formula = {"character": "0 + C(characters)"} if with_characters else None
    formula = (f"{value} ~ C({fixed}); groups=subject, re_formula='1'"
               + (", vc_formula={'character': '0 + C(characters)'}" if with_characters else ""))
    lme4_formula = (f"{value} ~ {fixed} + (1 | subject)"
                    + (" + (1 | subject:characters)" if with_characters else ""))

    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        # eval_env=-1: patsy evaluates the formulas in a clean namespace, not this function's locals.
        model = MixedLM.from_formula("outcome ~ C(factor)", data=frame, groups="subject", re_formula="1",
                                     vc_formula=vc_formula, eval_env=-1)
        result = model.fit(reml=True)
    fit_warnings = []
    for record in caught:
        if issubclass(record.category, ConvergenceWarning):
            fit_warnings.append(str(record.message))
        else:
            warnings.warn_explicit(record.message, record.category, record.filename, record.lineno)

    names = list(result.fe_params.index)
    estimate = result.fe_params.to_numpy(dtype=float)
    std_error = result.bse_fe.to_numpy(dtype=float)
    interval = result.conf_int(alpha=ALPHA).loc[names].to_numpy(dtype=float)
    converged = bool(result.converged)
    variances = {
        "subject_variance": float(result.cov_re.iloc[0, 0]) * scale**2,
        "character_variance": float(result.vcomp[0]) * scale**2 if with_characters else math.nan,
        "residual_variance": float(result.scale) * scale**2,
    }
    summary = {
        "n_observations": len(frame),
        "n_subjects": n_subjects,
        "n_characters": n_characters,
        "n_dropped": n_dropped,
        "formula": formula,
        "method": "REML",
        "converged": converged,
        "fit_warnings": "; ".join(dict.fromkeys(message.rstrip(". ") for message in fit_warnings)),
        "test": "linear mixed model (REML), statsmodels MixedLM; Wald z",
        "assumptions": (
            "subjects independent; random intercepts per subject and per character within subject, normal; "
            "residuals normal with one variance; Wald z and intervals are large-sample"
            + ("" if with_characters else "; one character: no character component")
            + ("" if converged else "; THE FIT DID NOT CONVERGE")
        ),
    }
    table = pandas.DataFrame({
        "term": [_fixed_effect_label(name, fixed, order, reference) for name in names],
        "estimate": estimate * scale,
        "std_error": std_error * scale,
        "ci95_low": interval[:, 0] * scale,
        "ci95_high": interval[:, 1] * scale,
        "z": result.tvalues.loc[names].to_numpy(dtype=float),
        "p": result.pvalues.loc[names].to_numpy(dtype=float),
    })
    for column, entry in summary.items():
        table[column] = entry
    table.attrs.update(summary)
    table.attrs.update(variances)
    table.attrs["lme4_formula"] = lme4_formula
    return table


def learning(trials: pandas.DataFrame, value: str, pre: str, post: str, retention: str | None = None,
             transfer: str | None = None, by: str = "phase", *, lower_is_better: bool = True,
             min_relative_gain: float = 0.05) -> pandas.DataFrame:
    """Each subject's learning between named phases, as motor learning studies measure it (Schmidt & Lee
    2019): performance before practice, right after it, after a delay (retention) and on a new task
    (transfer).

    ``pre``, ``post``, ``retention`` and ``transfer`` are values of column ``by`` (any labels a protocol
    uses: 'pre-test', 'post-test', 'retention', ...). Each subject's trials in a phase are averaged (NaN
    trials left out).

    Returns a DataFrame with one row per subject (sorted): ``subject``; ``group`` when ``trials`` has that
    column (the subject's between-subjects group); ``pre``, ``post`` and, when
    named, ``retention`` and ``transfer``, the subject's means in those phases [unit of value; NaN when
    the subject has no value there]; ``gain`` = pre - post, since the outcomes here are errors and times,
    lower being better (post - pre with ``lower_is_better=False``); ``relative_gain`` = gain / pre (NaN
    when pre is 0); with retention, ``retention_ratio`` = (pre - retention) / (pre - post): 1 when all of
    the gain was kept, 0 when all was lost, below 0 when worse than before practice; NaN unless the subject
    gained at least ``min_relative_gain`` of its pre-test (a ratio over a gain near 0 is unbounded: a
    subject who gained 1 % and lost 30 % would read -30); with transfer, ``transfer_gain`` = pre - transfer
    (sign as for gain), which measures transfer only when the transfer characters were also pre-tested
    (``calligraphy.design_analysis.transfer_baseline``). ``.attrs['phases']``
    maps pre/post/retention/transfer to the phase names.

    Raises TypeError when ``trials`` is not a DataFrame or ``value`` is not numeric; ValueError naming a
    missing column, a phase not present in ``by`` (listing those present), or a phase named twice.
    """
    caller = "learning"
    pandas = _pandas()
    _check_frame(trials, caller)
    _require_columns(trials, ["subject", by, value], caller)
    _require_groups(trials, ["subject", by], caller)
    trials = _finite_outcome(trials, value, caller)
    phases = {role: name for role, name in
              (("pre", pre), ("post", post), ("retention", retention), ("transfer", transfer)) if name is not None}
    present = _levels(trials[by])
    for role, name in phases.items():
        if name not in present:
            raise ValueError(f"{caller}: {role} phase {name!r} is not in trials' {by!r} column; present: "
                             f"{', '.join(repr(p) for p in present)}")
    if len(set(phases.values())) < len(phases):
        raise ValueError(f"{caller}: a phase is named twice: {phases}")

    chosen = trials[trials[by].isin(list(phases.values()))]
    means = chosen.groupby(["subject", by], observed=True, sort=True)[value].mean().unstack(by)
    table = pandas.DataFrame({"subject": means.index.to_numpy()})
    if "group" in trials.columns:  # the subject's between-subjects group (one per subject)
        groups = chosen.groupby("subject", observed=True, sort=True)["group"].agg(
            lambda g: "/".join(sorted({str(x) for x in g})))
        table.insert(1, "group", groups.reindex(means.index).to_numpy())
    for role, name in phases.items():
        table[role] = means[name].to_numpy(dtype=float) if name in means.columns else np.nan
    sign = 1.0 if lower_is_better else -1.0
    table["gain"] = sign * (table["pre"] - table["post"])
    table["relative_gain"] = table["gain"] / table["pre"].where(table["pre"] != 0)
    if retention is not None:
        gained = table["pre"] - table["post"]
        reliable = (gained > 0) & (gained >= min_relative_gain * table["pre"].abs())
        table["retention_ratio"] = (table["pre"] - table["retention"]) / gained.where(reliable)
    if transfer is not None:
        table["transfer_gain"] = sign * (table["pre"] - table["transfer"])
    table.attrs["phases"] = dict(phases)
    table.attrs["value"] = value
    return table


@dataclasses.dataclass(frozen=True)
class GroupComparison:
    """``value`` compared between two groups of subjects (``group_comparison``); the difference is a - b.

    Fields: ``value``, ``by``, ``a``, ``b``; ``n_a``, ``n_b`` (subjects with a value); ``mean_a``,
    ``mean_b``, ``sd_a``, ``sd_b``; ``mean_difference`` with ``ci95_low``, ``ci95_high`` (Welch's
    interval); ``t``, ``df`` (Welch-Satterthwaite), ``p`` (two-sided Welch t-test, Welch 1947,
    ``scipy.stats.ttest_ind(equal_var=False)``); ``mann_whitney_u``, ``mann_whitney_p`` (two-sided,
    Mann & Whitney 1947, ``scipy.stats.mannwhitneyu``); ``g`` (Hedges' g: the difference over the pooled
    sd, times 1 - 3 / (4 (n_a + n_b) - 9); Hedges 1981, Lakens 2013 eq. 4); ``power`` of a two-sided
    two-sample t-test at alpha .05 for |g| with these group sizes, and ``n_per_group_for_80_percent_power``
    (equal groups; statsmodels TTestIndPower, Cohen 1988; NaN when g is 0 or undefined); ``test``,
    ``assumptions``.
    """

    value: str
    by: str
    a: typing.Any
    b: typing.Any
    n_a: int
    n_b: int
    mean_a: float
    mean_b: float
    sd_a: float
    sd_b: float
    mean_difference: float
    ci95_low: float
    ci95_high: float
    t: float
    df: float
    p: float
    mann_whitney_u: float
    mann_whitney_p: float
    g: float
    power: float
    n_per_group_for_80_percent_power: float
    test: str
    assumptions: str

    def to_frame(self) -> pandas.DataFrame:
        """One row with every field, the fields' names as columns."""
        return _pandas().DataFrame([dataclasses.asdict(self)])


def _independent_power(effect: float, n_a: int, n_b: int) -> float:
    from statsmodels.stats.power import TTestIndPower
    capped = min(effect, _NONCENTRALITY_LIMIT / math.sqrt(n_a * n_b / (n_a + n_b)))  # as in _power
    with np.errstate(divide="ignore", invalid="ignore"):
        return float(TTestIndPower().power(effect_size=capped, nobs1=n_a, ratio=n_b / n_a, alpha=ALPHA,
                                           alternative="two-sided"))


def _per_group_for_power(effect: float) -> float:
    """The fewest subjects per group (equal groups, at least 2) reaching TARGET_POWER for ``effect`` > 0."""
    n = 2
    while _independent_power(effect, n, n) < TARGET_POWER:
        n = n * 2 if n < 1_000_000 else n
        if n >= 1_000_000:
            return math.nan
    low = max(2, n // 2)  # power grows with n: bisect between the last miss and the first hit
    while low < n:
        middle = (low + n) // 2
        if _independent_power(effect, middle, middle) >= TARGET_POWER:
            n = middle
        else:
            low = middle + 1
    return float(n)


def _hedges_g(difference: float, variance_a: float, variance_b: float, n_a: int, n_b: int) -> float:
    """Hedges' g of a difference between two independent groups: the difference over the pooled sd, times
    J = 1 - 3 / (4 (n_a + n_b) - 9) (Hedges 1981; Lakens 2013 eq. 4); NaN when the pooled sd is 0. The
    variances are the groups' sample variances (n - 1); n_a + n_b > 2."""
    pooled = math.sqrt(((n_a - 1) * variance_a + (n_b - 1) * variance_b) / (n_a + n_b - 2))
    return difference / pooled * (1.0 - 3.0 / (4.0 * (n_a + n_b) - 9.0)) if pooled > 0 else math.nan


def group_comparison(table: pandas.DataFrame, value: str, a: typing.Any, b: typing.Any, by: str = "group"
                     ) -> GroupComparison:
    """Compares ``value`` between the subjects of groups ``a`` and ``b`` (values of column ``by``), for a
    between-subjects design: a protocol phase with ``"assignment": "between-subjects"``.

    ``table`` has one row per subject, e.g. ``learning(trials, ...)`` (columns ``group``, ``gain``,
    ``retention``, ``retention_ratio``, ``transfer``, ...). Rows with NaN ``value`` are left out. Tests:
    Welch's t-test (unequal variances) and the Mann-Whitney U test as the check that needs no normality;
    effect size Hedges' g; power from statsmodels' TTestIndPower. Returns a ``GroupComparison``.

    Raises TypeError when ``table`` is not a DataFrame or ``value`` is not numeric; ValueError naming a
    missing column, a group not present (listing those present), a = b, a subject in more than one row,
    fewer than 2 subjects with a value in either group, or a value constant within both groups.
    """
    caller = "group_comparison"
    stats = _scipy_stats()
    _check_frame(table, caller)
    _require_columns(table, ["subject", by, value], caller)
    _require_groups(table, ["subject", by], caller)
    table = _finite_outcome(table, value, caller)
    if table["subject"].duplicated().any():
        raise ValueError(f"{caller}: expected one row per subject (e.g. from learning()); "
                         f"{table['subject'][table['subject'].duplicated()].iloc[0]!r} has several")
    present = _levels(table[by])
    for name in (a, b):
        if name not in present:
            raise ValueError(f"{caller}: group {name!r} is not in the {by!r} column; present: "
                             f"{', '.join(repr(level) for level in present)}")
    if a == b:
        raise ValueError(f"{caller}: a and b are both {a!r}; compare two different groups")
    x = table.loc[(table[by] == a) & table[value].notna(), value].to_numpy(dtype=float)
    y = table.loc[(table[by] == b) & table[value].notna(), value].to_numpy(dtype=float)
    if len(x) < 2 or len(y) < 2:
        raise _TooFewData(f"{caller}: {len(x)} subject(s) in {a!r} and {len(y)} in {b!r} have a value of "
                          f"{value!r}; a comparison needs at least 2 in each")
    if np.ptp(x) == 0 and np.ptp(y) == 0:
        raise ValueError(f"{caller}: {value!r} does not vary within either group; a test of the difference "
                         "says nothing (the difference is exact)")
    welch = stats.ttest_ind(x, y, equal_var=False)
    # Welch-Satterthwaite df and interval (scipy 1.10's ttest_ind returns neither).
    share_a, share_b = np.var(x, ddof=1) / len(x), np.var(y, ddof=1) / len(y)
    standard_error = math.sqrt(share_a + share_b)
    denominator = share_a ** 2 / (len(x) - 1) + share_b ** 2 / (len(y) - 1)
    df = (share_a + share_b) ** 2 / denominator if denominator > 0 else math.nan
    u_test = stats.mannwhitneyu(x, y, alternative="two-sided")
    n_a, n_b = len(x), len(y)
    difference = float(np.mean(x) - np.mean(y))
    g = _hedges_g(difference, float(np.var(x, ddof=1)), float(np.var(y, ddof=1)), n_a, n_b)
    half_width = float(stats.t.ppf(0.975, df) * standard_error) if math.isfinite(df) else math.nan
    power = needed = math.nan
    if math.isfinite(g) and g != 0:
        power = _independent_power(abs(g), n_a, n_b)
        needed = _per_group_for_power(abs(g))
    return GroupComparison(
        value=value, by=by, a=a, b=b, n_a=n_a, n_b=n_b,
        mean_a=float(np.mean(x)), mean_b=float(np.mean(y)),
        sd_a=float(np.std(x, ddof=1)), sd_b=float(np.std(y, ddof=1)),
        mean_difference=difference, ci95_low=difference - half_width, ci95_high=difference + half_width,
        t=float(welch.statistic), df=float(df), p=float(welch.pvalue),
        mann_whitney_u=float(u_test.statistic), mann_whitney_p=float(u_test.pvalue),
        g=float(g), power=power, n_per_group_for_80_percent_power=needed,
        test=("Welch t-test (Welch 1947), scipy.stats.ttest_ind(equal_var=False); Mann-Whitney U (Mann & "
              "Whitney 1947), scipy.stats.mannwhitneyu; Hedges' g (Hedges 1981); power, statsmodels "
              "TTestIndPower (Cohen 1988)"),
        assumptions=("subjects independent, each in one group; values approximately normal within groups "
                     "(t-test; variances may differ) or distributions of the same shape (Mann-Whitney)"),
    )


def _row(**entries: typing.Any) -> dict[str, typing.Any]:
    row = dict.fromkeys(TABLE_COLUMNS, math.nan)
    row.update(entries)
    return row


def _paired_rows(comparison: PairedComparison) -> list[dict[str, typing.Any]]:
    c = comparison
    label = f"{c.a} - {c.b}"
    shared = {"comparison": label, "n": c.n_subjects, "assumptions": c.assumptions}
    return [
        _row(quantity=f"mean difference of {c.value}", test="paired t-test (Student 1908), scipy.stats.ttest_rel",
             statistic=c.t, df=c.df, p=c.p, effect=c.mean_difference, effect_name=f"mean difference [{c.value}]",
             ci95_low=c.ci95_low, ci95_high=c.ci95_high, **shared),
        _row(quantity=f"mean difference of {c.value}",
             test="Wilcoxon signed-rank (Wilcoxon 1945), scipy.stats.wilcoxon",
             statistic=c.wilcoxon_statistic, p=c.wilcoxon_p, effect_name="", **shared),
        _row(quantity="standardized difference", test="Cohen's d_z = mean / sd of differences (Lakens 2013)",
             effect=c.d_z, effect_name="d_z", **shared),
        _row(quantity="standardized difference", test="Hedges' g_av, small-sample corrected (Lakens 2013)",
             effect=c.g_av, effect_name="g_av", **shared),
        _row(quantity="power of the observed d_z", test="statsmodels TTestPower (Cohen 1988), alpha .05",
             effect=c.power, effect_name="power", **shared),
        _row(quantity="subjects for 80 % power", test="statsmodels TTestPower.solve_power (Cohen 1988), alpha .05",
             effect=c.n_for_80_percent_power, effect_name="n subjects", **shared),
    ]


def statistics_table(trials: pandas.DataFrame, value: str, by: str = "condition", phase: Phase = None,
                     *, with_mixed_model: bool = True, reference: typing.Any = None) -> pandas.DataFrame:
    """One tidy table of ``value`` for a report: per condition (value of ``by``) its mean over subjects
    (``describe(..., unit="subject")``), every pairwise ``paired_comparison`` between the conditions
    present (in sorted order or a categorical column's order, a - b; a pair with ``reference``, the control, is
    the other condition - reference, the direction of ``design_analysis``'s questions), and the fixed effects of
    ``mixed_model(trials, value, fixed=by)`` (left out with ``with_mixed_model=False``; the small-sample
    model with subjects and items crossed is ``calligraphy.design_analysis.design_questions``). ``phase`` (a name, several, or None for every row)
    restricts the trials first; without it, trials of all phases are pooled.

    Returns a DataFrame with the columns ``quantity``, ``comparison``, ``test``, ``n`` (subjects; trials
    for the mixed model), ``statistic`` (t, Wilcoxon's statistic or Wald z), ``df``, ``p``, ``effect`` and
    ``effect_name`` (what ``effect`` is: a mean or mean difference in the unit of ``value``, d_z, g_av,
    power, n subjects for 80 % power, or a fixed effect), ``ci95_low``, ``ci95_high`` (the 95 % interval
    of ``effect`` where there is one) and ``assumptions``; NaN where a column does not apply. Rows per
    pair: the t-test, the Wilcoxon test, d_z, g_av, power, subjects for 80 % power. A comparison or model
    that has too few subjects or levels is one row whose ``test`` says why it was not computed. The
    sources are those of describe, paired_comparison and mixed_model.

    Raises TypeError when ``trials`` is not a DataFrame or ``value`` is not numeric; ValueError naming a
    missing column or a phase not present.
    """
    caller = "statistics_table"
    pandas = _pandas()
    _check_frame(trials, caller)
    _require_columns(trials, ["subject", "characters", by, value], caller)
    _require_groups(trials, ["subject", "characters", by], caller)
    trials = _finite_outcome(trials, value, caller)
    data = _select_phase(trials, phase, caller)
    rows = []
    for described in describe(data, value, by=(by,), unit="subject").to_dict("records"):
        rows.append(_row(quantity=f"mean of {value}", comparison=f"{by}={described[by]}", test=described["test"],
                         n=described["n"], df=described["n"] - 1 if described["n"] >= 1 else math.nan,
                         effect=described["mean"], effect_name=f"mean [{value}]", ci95_low=described["ci95_low"],
                         ci95_high=described["ci95_high"], assumptions=described["assumptions"]))
    for a, b in itertools.combinations(_levels(data[by]), 2):
        if reference is not None and a == reference:
            a, b = b, a
        try:
            comparison = paired_comparison(data, value, a, b, by=by)
        except _TooFewData as error:
            rows.append(_row(quantity=f"mean difference of {value}", comparison=f"{a} - {b}",
                             test=f"not computed: {error}", assumptions=""))
            continue
        rows.extend(_paired_rows(comparison))
    try:
        model = mixed_model(data, value, fixed=by) if with_mixed_model else None
    except _TooFewData as error:
        rows.append(_row(quantity="fixed effect", comparison=by, test=f"not computed: {error}", assumptions=""))
    else:
        for effect in (model.itertuples(index=False) if model is not None else ()):
            rows.append(_row(quantity="fixed effect", comparison=effect.term, test=effect.test,
                             n=effect.n_observations, statistic=effect.z, p=effect.p, effect=effect.estimate,
                             effect_name=f"estimate [{value}]", ci95_low=effect.ci95_low,
                             ci95_high=effect.ci95_high,
                             assumptions=effect.assumptions + (f"; {effect.fit_warnings}" if effect.fit_warnings
                                                               else "")))
    table = pandas.DataFrame(rows, columns=TABLE_COLUMNS)
    table["n"] = table["n"].astype("Int64")
    table["df"] = table["df"].astype("Int64")
    return table
