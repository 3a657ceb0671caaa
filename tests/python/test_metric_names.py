"""Python's metric names are the metric table's (include/calligraphy/analysis/metric_table.hpp), in SI units;
the old millimetre names still read for one version, converted, with a DeprecationWarning naming the new one."""
import pickle
import warnings

import pytest

import calligraphy
from calligraphy.metrics import Metrics, legacy_names


def test_the_table_names_every_metric_with_its_unit():
    table = calligraphy.metric_table()
    names = [row["name"] for row in table]
    assert len(names) == len(set(names))
    assert "mean_deviation_m" in names and "frechet_m" in names and "strokes_assisted" in names
    for row in table:
        assert not row["name"].endswith("_mm")
        if row["unit"] == "m":
            assert row["name"].endswith("_m")
    assert legacy_names()["mean_deviation_mm"] == "mean_deviation_m"


def test_a_trials_metrics_are_the_tables_names_at_each_level():
    metrics = calligraphy.simulate_trial("十", seed=1, keep_trace=False).metrics
    table = calligraphy.metric_table()
    scene = {row["name"] for row in table if "scene" in row["levels"].split(", ")}
    run = {row["name"] for row in table if "run" in row["levels"].split(", ")}
    assert scene | run <= set(metrics)
    assert not any(key.endswith("_mm") for key in metrics)
    stroke = {row["name"] for row in table if "stroke" in row["levels"].split(", ")}
    for entry in metrics["per_character"][0]["per_stroke"]:
        assert stroke <= set(entry)


def test_an_old_name_reads_in_millimetres_with_a_deprecation_warning():
    metrics = calligraphy.simulate_trial("十", seed=1, keep_trace=False).metrics
    assert isinstance(metrics, dict) and isinstance(metrics, Metrics)
    with pytest.warns(DeprecationWarning, match="mean_deviation_m"):
        old = metrics["mean_deviation_mm"]
    assert old == metrics["mean_deviation_m"] * 1e3
    stroke = metrics["per_character"][0]["per_stroke"][0]
    with pytest.warns(DeprecationWarning, match="frechet_m"):
        assert stroke["frechet_mm"] == stroke["frechet_m"] * 1e3
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # the new names warn of nothing
        assert metrics["mean_deviation_m"] > 0.0
    with pytest.raises(KeyError):
        metrics["no_such_metric_mm"]
    assert "mean_deviation_mm" not in metrics  # only the one names are keys
    assert pickle.loads(pickle.dumps(metrics)) == metrics


def test_an_old_column_of_a_per_stroke_table_reads_with_a_deprecation_warning():
    pytest.importorskip("pandas")
    frame = calligraphy.simulate_trial("十", seed=1).per_stroke_dataframe()
    assert "mean_deviation_m" in frame.columns and "mean_deviation_mm" not in frame.columns
    with pytest.warns(DeprecationWarning, match="mean_deviation_m"):
        old = frame["mean_deviation_mm"]
    assert list(old) == [value * 1e3 for value in frame["mean_deviation_m"]]
    with pytest.warns(DeprecationWarning):
        assert list(frame.dtw_mm) == [value * 1e3 for value in frame.dtw_m]
