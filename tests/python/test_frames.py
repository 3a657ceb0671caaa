"""pandas tables of a trial: one row per tick, one row per stroke; pandas is optional."""

import subprocess
import sys

import numpy as np
import pytest

import calligraphy

pandas = pytest.importorskip("pandas")


@pytest.fixture(scope="module")
def result():
    return calligraphy.simulate_trial("九心", seed=2)


def test_one_row_per_tick_with_units_in_the_column_names(result):
    frame = result.to_dataframe()
    assert list(frame.columns) == ["t_s", "x_m", "y_m", "z_m", "fx_n", "fy_n", "fz_n", "state", "stroke",
                                   "element", "attempt", "rewritten"]
    assert len(frame) == result.time_s.size
    np.testing.assert_array_equal(frame["t_s"], result.time_s)
    np.testing.assert_array_equal(frame[["x_m", "y_m", "z_m"]].to_numpy(), result.position_m)
    np.testing.assert_array_equal(frame[["fx_n", "fy_n", "fz_n"]].to_numpy(), result.force_n)
    np.testing.assert_array_equal(frame["stroke"], result.stroke)
    np.testing.assert_array_equal(frame["attempt"], result.attempt)
    np.testing.assert_array_equal(frame["rewritten"], result.rewritten)
    # Every tick of a written stroke belongs to an attempt at it (1-based); rewritten is 0 or 1.
    assert frame.loc[frame["state"] == "WS", "attempt"].min() >= 1
    assert set(frame["rewritten"].unique()) <= {0, 1}
    # The state column names the states as the paper does, in InteractionState's order.
    names = [s.short_name for s in calligraphy.InteractionState.__members__.values()]
    assert list(frame["state"].cat.categories) == names
    np.testing.assert_array_equal(frame["state"].to_numpy(), np.array(names)[result.state])
    # The metrics agree with the table.
    assert np.hypot(frame.fx_n, np.hypot(frame.fy_n, frame.fz_n)).max() == pytest.approx(result.metrics["max_force_n"])


def test_one_row_per_stroke(result):
    frame = result.per_stroke_dataframe()
    scene = result.scene
    assert list(frame.index) == list(range(scene.stroke_count))
    assert frame.index.name == "stroke"
    assert list(frame["character"]) == ["九"] * 2 + ["心"] * 4
    assert list(frame["acronym"]) == [s.acronym for s in scene.strokes]
    written = [entry for character in result.metrics["per_character"] for entry in character["per_stroke"]]
    for stroke, entry, live in zip(frame.itertuples(), written, result.metrics["renderer_strokes"]):
        assert stroke.mean_deviation_m == entry["mean_deviation_m"]
        assert stroke.completed == live["completed"] and stroke.attempts == live["attempts"]
    # The renderer's last attempt at each stroke, which stroke_trace_range locates in the trace: its ticks are
    # all of that stroke.
    for k, (begin, end) in enumerate(result.stroke_trace_range):
        assert end > begin
        assert np.all(result.stroke[begin:end] == k)


def test_without_a_trace_the_table_is_empty():
    result = calligraphy.simulate_trial("九", seed=1, keep_trace=False)
    assert len(result.to_dataframe()) == 0
    assert len(result.per_stroke_dataframe()) == 2


def test_import_does_not_load_pandas_or_matplotlib_and_says_what_is_missing():
    code = (
        "import sys; sys.modules['pandas'] = None\n"  # pandas made unimportable
        "import calligraphy\n"
        "assert 'matplotlib' not in sys.modules\n"
        "r = calligraphy.simulate_trial('九', keep_trace=False)\n"
        "try:\n"
        "    r.to_dataframe()\n"
        "except ImportError as e:\n"
        "    print(e)\n"
    )
    run = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert "pandas" in run.stdout and "python3-pandas" in run.stdout


def test_the_librarys_own_frames_are_scored(tmp_path):
    """A trial's DataFrame names its columns as the one trace column table does, and score reads it as it is,
    and by the files' names, alike; the old time column's name is read for one more version with a note."""
    trial = calligraphy.simulate_trial("十", seed=4)
    frame = trial.to_dataframe()
    table = calligraphy.trace_columns()
    assert [c["name"] for c in table] == list(frame.columns)
    from_frame = calligraphy.score(frame, "十")
    by_file_names = {c["file_name"]: frame[c["name"]].to_numpy() for c in table[:4]}
    assert calligraphy.score(by_file_names, "十") == from_frame
    assert from_frame["strokes_accepted"] == trial.metrics["strokes_accepted"] == 2
    with pytest.warns(DeprecationWarning, match="t_s"):
        assert calligraphy.score(frame.rename(columns={"t_s": "time_s"}), "十") == from_frame
