"""calligraphy.statistics on synthetic trials whose truth is known: the tests agree with SciPy and
statsmodels computed independently, intervals cover, the mixed model recovers a planted effect, and bad
input is named."""

import itertools
import math
import subprocess
import sys
import warnings

import numpy as np
import pytest

pandas = pytest.importorskip("pandas")
stats = pytest.importorskip("scipy.stats")
pytest.importorskip("statsmodels")
from statsmodels.stats.power import TTestPower  # noqa: E402
from statsmodels.tools.sm_exceptions import ConvergenceWarning  # noqa: E402

from calligraphy import statistics  # noqa: E402

CHARACTERS = "永我九心大木"
VALUE = "mean_deviation_m"


def make_trials(seed, subjects=12, characters=CHARACTERS, effects_m=None, repetitions=2, phases=("test",),
                subject_sd_m=0.2e-3, character_sd_m=0.15e-3, noise_sd_m=0.1e-3, base_m=1.0e-3):
    """One row per trial: subject, character and condition effects plus noise [m], as a study would log."""
    rng = np.random.default_rng(seed)
    effects_m = effects_m or {"vision": 0.0, "haptic": -0.3e-3}
    subject_effect = rng.normal(0.0, subject_sd_m, subjects)
    character_effect = dict(zip(characters, rng.normal(0.0, character_sd_m, len(characters))))
    rows = []
    for s, phase, character, (condition, effect), repetition in itertools.product(
            range(subjects), phases, characters, effects_m.items(), range(1, repetitions + 1)):
        rows.append({
            "subject": f"S{s:02d}", "session": "1", "phase": phase, "condition": condition,
            "characters": character, "repetition": repetition,
            VALUE: base_m + subject_effect[s] + character_effect[character] + effect + rng.normal(0.0, noise_sd_m),
            "total_time_s": 10.0 + rng.normal(0.0, 1.0),
        })
    return pandas.DataFrame(rows)


def subject_means(trials, condition):
    """Each subject's mean under one condition, computed here without the module."""
    rows = trials[(trials.condition == condition) & trials[VALUE].notna()]
    return {subject: float(np.mean(group[VALUE].to_numpy())) for subject, group in rows.groupby("subject")}


def test_importing_the_module_imports_none_of_its_libraries():
    code = ("import sys, calligraphy.statistics; "
            "print(sorted(m for m in ('pandas', 'scipy', 'statsmodels') if m in sys.modules))")
    out = subprocess.run([sys.executable, "-c", code], check=True, capture_output=True, text=True).stdout
    assert out.strip() == "[]"


def test_t_interval_covers_the_true_mean_about_95_percent_of_the_time():
    rng = np.random.default_rng(11)
    true_mean_m, n, samples = 0.8e-3, 8, 300
    trials = pandas.DataFrame({"sample": np.repeat(np.arange(samples), n),
                               VALUE: rng.normal(true_mean_m, 0.3e-3, samples * n)})
    table = statistics.describe(trials, VALUE, by="sample")
    assert len(table) == samples and (table["n"] == n).all()
    covered = (table["ci95_low"] <= true_mean_m) & (true_mean_m <= table["ci95_high"])
    assert 0.90 <= covered.mean() <= 0.99
    first = trials[VALUE].to_numpy()[:n]
    assert table["mean"].iloc[0] == pytest.approx(first.mean(), rel=1e-12)
    assert table["sd"].iloc[0] == pytest.approx(first.std(ddof=1), rel=1e-12)
    half_width = stats.t.ppf(0.975, n - 1) * first.std(ddof=1) / np.sqrt(n)
    assert table["ci95_high"].iloc[0] - table["ci95_low"].iloc[0] == pytest.approx(2 * half_width, rel=1e-9)


def test_describe_by_subject_counts_subjects_and_averages_their_means():
    trials = make_trials(seed=2, subjects=6, repetitions=3)
    trials.loc[[0, 7], VALUE] = np.nan  # trials that wrote nothing
    by_trial = statistics.describe(trials, VALUE, by=("phase", "condition"))
    by_subject = statistics.describe(trials, VALUE, by="condition", unit="subject")
    assert set(by_trial["unit"]) == {"trial"} and set(by_subject["unit"]) == {"subject"}
    for row in by_subject.itertuples():
        means = list(subject_means(trials, row.condition).values())
        assert row.n == 6
        assert row.mean == pytest.approx(np.mean(means), rel=1e-12)
        assert row.sd == pytest.approx(np.std(means, ddof=1), rel=1e-12)
        assert row.n_missing == trials[(trials.condition == row.condition) & trials[VALUE].isna()].shape[0]
    assert by_trial["n"].sum() + by_trial["n_missing"].sum() == len(trials)
    assert by_trial["n_missing"].sum() == 2


def test_paired_comparison_agrees_with_scipy_on_subject_means():
    trials = make_trials(seed=3, subjects=10)
    trials.loc[trials.index[:3], VALUE] = np.nan
    # A subject seen only under vision is not paired and must be left out.
    lone = trials[(trials.subject == "S00") & (trials.condition == "vision")].assign(subject="S99")
    trials = pandas.concat([trials, lone], ignore_index=True)
    result = statistics.paired_comparison(trials, VALUE, "vision", "haptic")

    vision, haptic = subject_means(trials, "vision"), subject_means(trials, "haptic")
    both = sorted(set(vision) & set(haptic))
    x = np.array([vision[s] for s in both])
    y = np.array([haptic[s] for s in both])
    assert result.n_subjects == 10 and result.n_subjects_unpaired == 1 and result.df == 9
    expected = stats.ttest_rel(x, y)
    assert result.t == pytest.approx(expected.statistic, rel=1e-12)
    assert result.p == pytest.approx(expected.pvalue, rel=1e-9)
    signed_rank = stats.wilcoxon(x, y)
    assert result.wilcoxon_statistic == signed_rank.statistic
    assert result.wilcoxon_p == pytest.approx(signed_rank.pvalue, rel=1e-12)
    assert result.mean_difference == pytest.approx(np.mean(x - y), rel=1e-12)
    assert result.ci95_low < result.mean_difference < result.ci95_high
    assert (result.ci95_low + result.ci95_high) / 2 == pytest.approx(result.mean_difference, rel=1e-9)
    # The planted effect: haptic 0.3 mm below vision.
    assert result.ci95_low < 0.3e-3 < result.ci95_high
    frame = result.to_frame()
    assert len(frame) == 1 and frame["t"].iloc[0] == result.t and "subject_means" not in frame.columns
    np.testing.assert_allclose(result.subject_means["difference"].to_numpy(), x - y, rtol=1e-12)


def one_trial_per_condition(a_values, b_values):
    subjects = [f"S{i:02d}" for i in range(len(a_values))]
    return pandas.DataFrame({
        "subject": subjects * 2, "phase": "test", "condition": ["a"] * len(subjects) + ["b"] * len(subjects),
        "characters": "永", VALUE: np.concatenate([a_values, b_values]),
    })


def test_effect_sizes_on_constructed_differences():
    rng = np.random.default_rng(4)
    n = 15
    standard = rng.normal(size=n)
    standard = (standard - standard.mean()) / standard.std(ddof=1)  # mean 0, sd 1 exactly
    mean_m, sd_m = 0.2e-3, 0.4e-3
    b_values = rng.normal(1.0e-3, 0.3e-3, n)
    a_values = b_values + mean_m + sd_m * standard  # differences a - b: mean 0.2 mm, sd 0.4 mm
    result = statistics.paired_comparison(one_trial_per_condition(a_values, b_values), VALUE, "a", "b")
    assert result.d_z == pytest.approx(mean_m / sd_m, rel=1e-9)
    assert result.sd_difference == pytest.approx(sd_m, rel=1e-9)
    d_av = mean_m / ((np.std(a_values, ddof=1) + np.std(b_values, ddof=1)) / 2)
    assert result.d_av == pytest.approx(d_av, rel=1e-9)
    # Hedges' correction shrinks the estimate by 3 / (4 df - 1), df = n - 1.
    assert result.g_av == pytest.approx(d_av * (1 - 3 / (4 * (n - 1) - 1)), rel=1e-9)
    assert abs(result.g_av) < abs(result.d_av)
    # Two subjects (df = 1): the correction is 0, so no g is given beside the d.
    two = statistics.paired_comparison(one_trial_per_condition(a_values[:2], b_values[:2]), VALUE, "a", "b")
    assert math.isfinite(two.d_av) and math.isnan(two.g_av)


def test_power_and_the_subjects_needed_for_80_percent():
    rng = np.random.default_rng(5)
    b_values = rng.normal(1.0e-3, 0.3e-3, 12)
    a_values = b_values + rng.normal(0.15e-3, 0.3e-3, 12)
    result = statistics.paired_comparison(one_trial_per_condition(a_values, b_values), VALUE, "a", "b")
    n, effect = result.n_subjects, abs(result.d_z)
    # The power of a two-sided paired t-test from the noncentral t distribution, computed here.
    critical = stats.t.ppf(0.975, n - 1)
    noncentral = stats.nct(n - 1, effect * np.sqrt(n))
    assert result.power == pytest.approx(noncentral.sf(critical) + noncentral.cdf(-critical), rel=1e-6)
    needed = int(result.n_for_80_percent_power)
    analysis = TTestPower()
    assert analysis.power(effect_size=effect, nobs=needed, alpha=0.05) >= 0.8
    assert analysis.power(effect_size=effect, nobs=needed - 1, alpha=0.05) < 0.8


def test_phase_restricts_the_comparison():
    trials = make_trials(seed=6, subjects=6, phases=("practice", "test"))
    # Practice under vision was far worse; a test-phase comparison must not see it.
    trials.loc[(trials.phase == "practice") & (trials.condition == "vision"), VALUE] += 5e-3
    test_only = statistics.paired_comparison(trials, VALUE, "vision", "haptic", phase="test")
    direct = statistics.paired_comparison(trials[trials.phase == "test"], VALUE, "vision", "haptic")
    assert test_only.t == direct.t and test_only.phase == "test"
    pooled = statistics.paired_comparison(trials, VALUE, "vision", "haptic")
    assert pooled.mean_difference > test_only.mean_difference + 2e-3


def test_mixed_model_recovers_a_planted_condition_effect():
    effect_m = -0.3e-3
    trials = make_trials(seed=7, subjects=12, repetitions=2, effects_m={"vision": 0.0, "haptic": effect_m})
    dropped = trials.sample(n=5, random_state=1).index
    trials.loc[dropped, VALUE] = np.nan
    with warnings.catch_warnings():
        warnings.simplefilter("error", ConvergenceWarning)
        table = statistics.mixed_model(trials, VALUE, reference="vision")
    assert list(table["term"]) == ["Intercept (condition=vision)", "condition[T.haptic]"]
    haptic = table.iloc[1]
    assert abs(haptic["estimate"] - effect_m) < 3 * haptic["std_error"]
    assert haptic["ci95_low"] < effect_m < haptic["ci95_high"]
    assert haptic["p"] < 0.001
    assert haptic["n_observations"] == len(trials) - 5 and haptic["n_dropped"] == 5
    assert haptic["n_subjects"] == 12 and haptic["n_characters"] == len(CHARACTERS)
    assert haptic["method"] == "REML" and haptic["converged"]
    # In metres every variance is far below statsmodels' absolute boundary threshold (0.01); the fit on
    # the rescaled outcome must not report a boundary it is not on.
    assert haptic["fit_warnings"] == ""
    assert table.attrs["subject_variance"] > 0 and table.attrs["residual_variance"] > 0
    assert "C(condition)" in table.attrs["formula"] and "(1 | subject)" in table.attrs["lme4_formula"]
    # With the other level as reference the effect changes sign and nothing else.
    flipped = statistics.mixed_model(trials, VALUE, reference="haptic")
    assert flipped.iloc[1]["estimate"] == pytest.approx(-haptic["estimate"], rel=1e-5)


def test_mixed_model_records_convergence_warnings_instead_of_raising():
    # Noise whose mean is the same in every subject and character: their variances are 0, on the
    # boundary of the parameter space, where statsmodels warns.
    rng = np.random.default_rng(8)
    trials = pandas.DataFrame([
        {"subject": f"S{s}", "characters": c, "condition": condition, VALUE: rng.normal(0.0, 1e-4)}
        for s in range(8) for c in "永我九" for condition in ("a", "b")])
    cell_mean = trials.groupby(["subject", "characters"])[VALUE].transform("mean")
    trials[VALUE] = trials[VALUE] - cell_mean + 1e-3
    with warnings.catch_warnings():
        warnings.simplefilter("error", ConvergenceWarning)
        table = statistics.mixed_model(trials, VALUE)
    assert table["fit_warnings"].iloc[0] != ""
    assert len(table) == 2
    if not table["converged"].iloc[0]:
        assert "DID NOT CONVERGE" in table["assumptions"].iloc[0]


def test_learning_gives_exact_gain_and_retention():
    # Per-subject phase means built to known values; labels as a pre/post/retention protocol names them.
    design = {"S1": (2.0e-3, 1.0e-3, 1.5e-3, 1.8e-3), "S2": (1.6e-3, 0.8e-3, 0.8e-3, 1.2e-3),
              "S3": (1.0e-3, 1.0e-3, 1.2e-3, 0.9e-3), "S4": (1.0e-3, 0.99e-3, 1.3e-3, 1.0e-3)}
    labels = ("baseline", "after", "one week", "new characters")
    rows = []
    for subject, means in design.items():
        for label, mean in zip(labels, means):
            for offset in (-0.1e-3, 0.1e-3):  # two trials averaging to the mean
                rows.append({"subject": subject, "phase": label, VALUE: mean + offset})
        rows.append({"subject": subject, "phase": "after", VALUE: np.nan})  # wrote nothing: left out
    table = statistics.learning(pandas.DataFrame(rows), VALUE, pre="baseline", post="after",
                                retention="one week", transfer="new characters").set_index("subject")
    for subject, (pre, post, kept, transfer) in design.items():
        row = table.loc[subject]
        assert row["pre"] == pytest.approx(pre) and row["post"] == pytest.approx(post)
        assert row["gain"] == pytest.approx(pre - post)
        assert row["relative_gain"] == pytest.approx((pre - post) / pre)
        assert row["transfer_gain"] == pytest.approx(pre - transfer)
    assert table.loc["S1", "retention_ratio"] == pytest.approx(0.5)  # half of 1 mm gain kept
    assert table.loc["S2", "retention_ratio"] == pytest.approx(1.0)  # all kept
    assert np.isnan(table.loc["S3", "retention_ratio"])  # no gain: no ratio
    assert np.isnan(table.loc["S4", "retention_ratio"])  # a 1 % gain: a ratio of -30 would say nothing
    assert table.attrs["phases"]["retention"] == "one week"
    scores = statistics.learning(pandas.DataFrame(rows), VALUE, pre="baseline", post="after",
                                 lower_is_better=False).set_index("subject")
    assert scores.loc["S1", "gain"] == pytest.approx(-1.0e-3)
    assert "retention_ratio" not in scores.columns


def test_statistics_table_gathers_every_comparison():
    trials = make_trials(seed=9, subjects=8, effects_m={"vision": 0.0, "haptic": -0.3e-3, "fading": -0.1e-3},
                         phases=("practice", "test"))
    table = statistics.statistics_table(trials, VALUE, phase="test")
    assert list(table.columns) == ["quantity", "comparison", "test", "n", "statistic", "df", "p", "effect",
                                   "effect_name", "ci95_low", "ci95_high", "assumptions"]
    means = table[table.quantity == f"mean of {VALUE}"]
    assert sorted(means["comparison"]) == ["condition=fading", "condition=haptic", "condition=vision"]
    assert (means["n"] == 8).all()
    t_rows = table[table.test.str.startswith("paired t-test")]
    assert sorted(t_rows["comparison"]) == ["fading - haptic", "fading - vision", "haptic - vision"]
    direct = statistics.paired_comparison(trials, VALUE, "haptic", "vision", phase="test")
    row = t_rows[t_rows.comparison == "haptic - vision"].iloc[0]
    assert row["statistic"] == direct.t and row["p"] == direct.p and row["effect"] == direct.mean_difference
    assert set(table[table.comparison == "haptic - vision"]["effect_name"]) >= {"d_z", "g_av", "power"}
    fixed = table[table.quantity == "fixed effect"]
    assert len(fixed) == 3 and (fixed["n"] == (trials.phase == "test").sum()).all()
    # One subject: the description stands, the comparisons say why they are missing.
    alone = statistics.statistics_table(trials[trials.subject == "S00"], VALUE, phase="test")
    assert alone.test.str.startswith("not computed").sum() == 4


def test_a_constant_outcome_is_described_and_not_modelled(recwarn):
    trials = make_trials(seed=11, subjects=5)
    trials["order_errors"] = 0
    described = statistics.describe(trials, "order_errors", unit="subject")
    assert (described["ci95_low"] == 0).all() and (described["ci95_high"] == 0).all()
    table = statistics.statistics_table(trials, "order_errors")
    assert (table.quantity == "fixed effect").sum() == 1
    assert table[table.quantity == "fixed effect"].test.iloc[0].startswith("not computed")
    assert (table.quantity == "mean of order_errors").sum() == 2  # the description stands
    assert not [w for w in recwarn if issubclass(w.category, RuntimeWarning)]


@pytest.mark.parametrize("missing", [np.nan, None])
@pytest.mark.parametrize("column", ["condition", "subject", "characters"])
def test_a_missing_level_of_a_grouping_column_is_a_value_error_naming_it(column, missing):
    """A row that names no condition (or subject, or character) is neither dropped without a word nor a crash
    inside a fit: every function raises ValueError naming the column."""
    trials = make_trials(seed=12, subjects=4)
    trials[column] = trials[column].astype(object)
    trials.loc[trials.index[5], column] = missing
    calls = {
        "mixed_model": lambda: statistics.mixed_model(trials, VALUE),
        "statistics_table": lambda: statistics.statistics_table(trials, VALUE),
    }
    if column != "characters":  # a paired comparison pools a subject's characters
        calls["paired_comparison"] = lambda: statistics.paired_comparison(trials, VALUE, "vision", "haptic")
    if column == "condition":
        calls["describe"] = lambda: statistics.describe(trials, VALUE)
    for name, call in calls.items():
        with pytest.raises(ValueError, match=f"{name}: column '{column}' has 1 missing value"):
            call()


def test_errors_name_the_problem():
    trials = make_trials(seed=10, subjects=4)
    with pytest.raises(ValueError, match="'pen_lifts'"):
        statistics.describe(trials, "pen_lifts")
    with pytest.raises(ValueError, match="column 'condition'"):
        statistics.paired_comparison(trials.drop(columns="condition"), VALUE, "vision", "haptic")
    with pytest.raises(ValueError, match=r"'fading' is not in .*present: 'haptic', 'vision'"):
        statistics.paired_comparison(trials, VALUE, "vision", "fading")
    with pytest.raises(ValueError, match=r"phase 'retention' is not in .*'test'"):
        statistics.paired_comparison(trials, VALUE, "vision", "haptic", phase="retention")
    with pytest.raises(ValueError, match="1 subject.*at least 2"):
        statistics.paired_comparison(trials[trials.subject == "S00"], VALUE, "vision", "haptic")
    with pytest.raises(ValueError, match="at least 2"):
        statistics.mixed_model(trials[trials.condition == "vision"], VALUE)
    with pytest.raises(ValueError, match="reference 'fading'"):
        statistics.mixed_model(trials, VALUE, reference="fading")
    with pytest.raises(ValueError, match="post phase 'post-test' is not in"):
        statistics.learning(trials, VALUE, pre="test", post="post-test")
    with pytest.raises(ValueError, match="unit must be"):
        statistics.describe(trials, VALUE, unit="session")
    with pytest.raises(TypeError, match="'condition' must be numeric"):
        statistics.describe(trials, "condition")
    with pytest.raises(TypeError, match="pandas DataFrame"):
        statistics.describe(trials.to_dict("list"), VALUE)


def test_an_overwhelming_effect_has_power_1_and_needs_2_subjects():
    # Differences all but constant: d_z near 1e9, far beyond what scipy's noncentral t can evaluate.
    rng = np.random.default_rng(12)
    b_values = rng.normal(1.0e-3, 0.3e-3, 6)
    a_values = b_values + 1.0e-3 + rng.normal(0.0, 1e-12, 6)
    result = statistics.paired_comparison(one_trial_per_condition(a_values, b_values), VALUE, "a", "b")
    assert result.d_z > 1e6
    assert result.power == 1.0 and result.n_for_80_percent_power == 2


def test_categorical_columns_give_the_same_results_as_strings():
    # Study tables keep subject, session, phase and condition as pandas categoricals.
    trials = make_trials(seed=13, subjects=5, phases=("practice", "test"))
    categorical = trials.astype({column: "category" for column in ("subject", "session", "phase", "condition")})
    pandas.testing.assert_frame_equal(statistics.statistics_table(trials, VALUE, phase="test"),
                                      statistics.statistics_table(categorical, VALUE, phase="test"))
    described = statistics.describe(categorical, VALUE).astype({"phase": str, "condition": str})
    pandas.testing.assert_frame_equal(statistics.describe(trials, VALUE), described)
    learned = statistics.learning(categorical, VALUE, pre="practice", post="test")
    pandas.testing.assert_frame_equal(statistics.learning(trials, VALUE, pre="practice", post="test"),
                                      learned.astype({"subject": str}))


def test_group_comparison_agrees_with_scipy_and_finds_a_planted_group_effect():
    rng = np.random.default_rng(11)
    n = 12
    table = pandas.DataFrame({
        "subject": [f"S{k:02d}" for k in range(2 * n)],
        "group": ["fixture"] * n + ["fading"] * n,
        # retention error [m]: the fading group keeps 1 mm less error, sd 0.5 mm.
        "retention": np.concatenate([rng.normal(3e-3, 5e-4, n), rng.normal(2e-3, 7e-4, n)]),
    })
    result = statistics.group_comparison(table, "retention", "fixture", "fading")
    x = table.retention[:n].to_numpy()
    y = table.retention[n:].to_numpy()
    welch = stats.ttest_ind(x, y, equal_var=False)
    assert result.t == pytest.approx(welch.statistic) and result.p == pytest.approx(welch.pvalue)
    assert result.p < 0.01 and result.mean_difference == pytest.approx(x.mean() - y.mean())
    assert result.ci95_low < result.mean_difference < result.ci95_high
    assert result.ci95_low > 0  # the planted 1 mm lies in a clearly positive interval
    assert min(n, n) - 1 <= result.df <= 2 * n - 2  # Welch-Satterthwaite bounds
    assert result.g > 1.0 and result.power > 0.9
    # The n per group for 80 % power reaches it, and one fewer does not.
    from statsmodels.stats.power import TTestIndPower
    needed = int(result.n_per_group_for_80_percent_power)
    assert TTestIndPower().power(abs(result.g), needed, 0.05) >= 0.8
    assert needed == 2 or TTestIndPower().power(abs(result.g), needed - 1, 0.05) < 0.8
    assert "Welch" in result.test and len(result.to_frame()) == 1
    with pytest.raises(ValueError, match="'none' is not in the 'group' column"):
        statistics.group_comparison(table, "retention", "fixture", "none")
    constant = table.assign(retention=np.where(table.group == "fixture", 3e-3, 2e-3))
    with pytest.raises(ValueError, match="does not vary within either group"):
        statistics.group_comparison(constant, "retention", "fixture", "fading")
    with pytest.raises(ValueError, match="one row per subject"):
        statistics.group_comparison(pandas.concat([table, table]), "retention", "fixture", "fading")


def test_learning_keeps_each_subjects_group():
    trials = pandas.DataFrame({
        "subject": ["A", "A", "B", "B"], "group": ["fixture", "fixture", "fading", "fading"],
        "phase": ["pre-test", "post-test"] * 2, VALUE: [3e-3, 2e-3, 3e-3, 1e-3]})
    table = statistics.learning(trials, VALUE, "pre-test", "post-test")
    assert list(table.group) == ["fixture", "fading"]
    assert list(table.gain) == pytest.approx([1e-3, 2e-3])


@pytest.mark.parametrize("infinity", [np.inf, -np.inf])
def test_an_infinite_outcome_counts_as_missing_and_is_said(infinity):
    trials = make_trials(seed=21)
    finite = trials.copy()
    damaged = trials.copy()
    damaged.loc[damaged.index[5], VALUE] = infinity
    finite.loc[finite.index[5], VALUE] = np.nan  # what the infinite value must count as

    with pytest.warns(statistics.NonFiniteValueWarning, match=f"'{VALUE}' holds 1 infinite"):
        described = statistics.describe(damaged, VALUE)
    expected = statistics.describe(finite, VALUE)
    pandas.testing.assert_frame_equal(described, expected)
    assert described["n_missing"].sum() == 1
    assert np.isfinite(described["mean"]).all()

    with pytest.warns(statistics.NonFiniteValueWarning):
        model = statistics.mixed_model(damaged, VALUE, fixed="condition", phase="test")
    reference = statistics.mixed_model(finite, VALUE, fixed="condition", phase="test")
    assert model["n_dropped"].iloc[0] == reference["n_dropped"].iloc[0] == 1
    np.testing.assert_allclose(model["estimate"], reference["estimate"])

    with pytest.warns(statistics.NonFiniteValueWarning):
        paired = statistics.paired_comparison(damaged, VALUE, "vision", "haptic")
    assert np.isfinite(paired.mean_difference)
