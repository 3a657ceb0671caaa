"""calligraphy.score: any pen trace (a CSV file, a dict of columns, a pandas DataFrame) scored as
`calligraphy score` scores it, with order and direction errors found from the trace."""

import numpy as np
import pytest

import calligraphy


def reference_trace(char, offset_m=0.0, order=None, reverse=()):
    """A trace along the reference strokes (the placed elements sampled densely), pen lifted between
    strokes, moved `offset_m` to the left of each stroke (along its normal); strokes in `order`, those in
    `reverse` written end to start."""
    strokes = calligraphy.Scene(char).characters[0].strokes
    order = range(len(strokes)) if order is None else order
    t, x, y, pen = [], [], [], []
    now = 0.0
    for k in order:
        points = np.vstack([e.point(np.linspace(0.0, 1.0, 50)) for e in strokes[k].elements])
        tangent = np.gradient(points, axis=0)
        normal = np.column_stack([-tangent[:, 1], tangent[:, 0]])
        points = points + offset_m * normal / np.linalg.norm(normal, axis=1, keepdims=True)
        if k in reverse:
            points = points[::-1]
        for p in points:
            t.append(now)
            x.append(p[0])
            y.append(p[1])
            pen.append(1)
            now += 0.002
        t.append(now)  # lifted
        x.append(points[-1][0])
        y.append(points[-1][1])
        pen.append(0)
        now += 0.2
    return {"t": np.array(t), "x": np.array(x), "y": np.array(y), "pen": np.array(pen)}


def test_reference_scores_complete_in_order_near_zero():
    result = calligraphy.score(reference_trace("木"), "木")
    assert result["completed_in_order"] is True
    assert result["order_errors"] == 0
    assert result["mean_deviation_m"] < 0.05e-3


def test_offset_of_one_millimetre_is_measured():
    result = calligraphy.score(reference_trace("木", offset_m=0.001), "木")
    assert result["mean_deviation_m"] == pytest.approx(1e-3, abs=0.1e-3)
    assert result["frechet_m"] == pytest.approx(1e-3, abs=0.15e-3)


def test_swapped_and_reversed_strokes_are_found():
    swapped = calligraphy.score(reference_trace("木", order=[1, 0, 2, 3]), "木")
    assert swapped["order_errors"] == 1
    reversed_stroke = calligraphy.score(reference_trace("木", reverse=(0,)), "木")
    assert reversed_stroke["backwards_strokes"] == 1


def test_segments_carry_the_renderers_verdicts_in_turn():
    reversed_stroke = calligraphy.score(reference_trace("木", reverse=(1,)), "木")
    segments = reversed_stroke["per_character"][0]["segments"]
    assert len(segments) == 4
    verdicts = [s["verdict"] for s in segments]
    # Stroke 0 accepted, stroke 1 refused as backwards; strokes 2 and 3 then come too early.
    assert [v["accepted"] for v in verdicts] == [True, False, False, False]
    assert [v["refusal"] for v in verdicts] == ["none", "backwards", "wrong_order", "wrong_order"]
    assert [v["expected_stroke"] for v in verdicts] == [0, 1, 1, 1]
    assert [v["matched_stroke"] for v in verdicts] == [0, 1, 2, 3]
    assert reversed_stroke["strokes_accepted"] == 1
    assert reversed_stroke["refusals"] == {"too_short": 0, "backwards": 1, "wrong_place": 0,
                                           "wrong_stroke": 0, "wrong_order": 2}
    # The matching for the metrics still pairs every segment with its stroke.
    assert [s["matched_stroke"] for s in segments] == [0, 1, 2, 3]
    assert [s["backwards"] for s in segments] == [False, True, False, False]
    first = calligraphy.Scene("木").characters[0].strokes[0]
    assert segments[0]["begin"] == 0 and segments[0]["end"] == 50 * len(first.elements)  # sample indices


def test_acceptance_and_start_radius_decide_the_verdicts():
    beside = reference_trace("木", offset_m=0.004)  # beyond the 3 mm mean deviation, within the corridor
    strict = calligraphy.score(beside, "木")
    assert strict["strokes_written"] == 0
    assert strict["strokes_accepted"] == 0
    wider = calligraphy.StrokeAcceptance(mean_deviation_m=0.005, mean_deviation_cap_m=0.005)
    lenient = calligraphy.score(beside, "木", acceptance=wider)
    assert lenient["strokes_written"] == 4
    assert lenient["strokes_accepted"] == 4
    # A start neighbourhood smaller than the offset: no stroke is ever entered.
    small = calligraphy.score(beside, "木", acceptance=wider, start_radius_m=0.003)
    assert small["strokes_accepted"] == 0
    assert small["refusals"]["wrong_place"] == 4
    with pytest.raises(calligraphy.InvalidArgument, match="start_radius_m"):
        calligraphy.score(beside, "木", start_radius_m=0.0)
    with pytest.raises(TypeError, match="acceptance"):
        calligraphy.score(beside, "木", acceptance={"corridor_m": 0.01})
    with pytest.raises(TypeError):
        calligraphy.score(beside, "木", leniency=1.0)


def joined(*traces):
    """The traces one after another, each starting 0.2 s after the one before ends."""
    out = {k: [] for k in ("t", "x", "y", "pen")}
    start = 0.0
    for trace in traces:
        for k in ("x", "y", "pen"):
            out[k].append(trace[k])
        out["t"].append(trace["t"] + start)
        start = out["t"][-1][-1] + 0.2
    return {k: np.concatenate(v) for k, v in out.items()}


def test_a_stroke_refused_often_enough_is_credited_assisted_as_the_renderer_credits_it():
    # 4 mm beside the first stroke: within its start radius, beyond the mean deviation allowed.
    missed = [reference_trace("木", offset_m=0.004, order=[0]) for _ in range(5)]
    trace = joined(*missed, reference_trace("木", order=[1, 2, 3]))
    credited = calligraphy.score(trace, "木")  # the renderer's default: credited after 5 refusals
    assert credited["strokes_assisted"] == 1
    assert credited["strokes_accepted"] == 3
    assert credited["refusals"]["wrong_order"] == 0
    character = credited["per_character"][0]
    assert [s["assisted"] for s in character["per_stroke"]] == [True, False, False, False]
    verdicts = [s["verdict"] for s in character["segments"]]
    assert [v["assists_due"] for v in verdicts] == [False] * 4 + [True] + [False] * 3
    assert [v["expected_stroke"] for v in verdicts] == [0] * 5 + [1, 2, 3]
    never = calligraphy.score(trace, "木", acceptance=calligraphy.StrokeAcceptance(assist_after_misses=0))
    assert never["strokes_assisted"] == 0
    assert never["strokes_accepted"] == 0
    assert never["refusals"]["wrong_order"] == 3
    # 8 mm beside it the pen never comes within the start radius: refused, and each a miss all the same (no
    # dead end): credited after the fifth, as the renderer credits it.
    far = joined(*[reference_trace("木", offset_m=0.008, order=[0]) for _ in range(5)],
                 reference_trace("木", order=[1, 2, 3]))
    apart = calligraphy.score(far, "木")
    assert apart["strokes_assisted"] == 1
    assert apart["strokes_accepted"] == 3
    assert apart["refusals"]["wrong_place"] == 5
    # As records before version 8 counted misses (a lift in WS only): no attempt at the stroke, no credit.
    in_ws_only = calligraphy.score(far, "木", acceptance=calligraphy.StrokeAcceptance(miss_min_path_m=0))
    assert in_ws_only["strokes_assisted"] == 0
    assert in_ws_only["refusals"]["wrong_place"] == 5


def test_dataframe_and_csv_give_the_dict_result(tmp_path):
    pandas = pytest.importorskip("pandas")
    columns = reference_trace("大", offset_m=0.0005)
    frame = pandas.DataFrame(columns)
    by_dict = calligraphy.score(columns, "大")
    by_frame = calligraphy.score(frame, "大")
    path = tmp_path / "trace.csv"
    frame.to_csv(path, index=False, float_format="%.17g")
    by_file = calligraphy.score(path, "大")
    assert by_frame["mean_deviation_m"] == by_dict["mean_deviation_m"]
    assert by_file["mean_deviation_m"] == pytest.approx(by_dict["mean_deviation_m"], rel=1e-12)
    assert by_file["trace"] == str(path)


def test_a_simulated_trials_trace_scores_in_order():
    trial = calligraphy.simulate_trial("中", seed=2)
    p = trial.position_m  # (N, 3), the paper at z = 0
    result = calligraphy.score({"t": trial.time_s, "x": p[:, 0], "y": p[:, 1], "z": p[:, 2]}, "中")
    assert result["completed_in_order"] == trial.metrics["completed_in_order"]


def test_bad_input_names_the_column_or_sample():
    columns = reference_trace("大")
    with pytest.raises(calligraphy.InvalidArgument, match="'pen' or 'z'"):
        calligraphy.score({k: v for k, v in columns.items() if k != "pen"}, "大")
    bad_pen = dict(columns, pen=np.where(columns["pen"] == 1, 2, 0))
    with pytest.raises(calligraphy.InvalidArgument, match="sample 0: pen"):
        calligraphy.score(bad_pen, "大")
    with pytest.raises(calligraphy.InvalidArgument, match="different lengths"):
        calligraphy.score(dict(columns, x=columns["x"][:-1]), "大")
    with pytest.raises(calligraphy.DataError, match="no such file"):
        calligraphy.score("/nonexistent/trace.csv", "大")
    with pytest.raises(TypeError):
        calligraphy.score(42, "大")
    # A complex column is not scored as its real part, nor a column of text parsed as numbers.
    with pytest.raises(calligraphy.InvalidArgument, match="column 'x' holds complex128 values"):
        calligraphy.score(dict(columns, x=columns["x"] + 0j), "大")
    with pytest.raises(calligraphy.InvalidArgument, match="column 'y' holds <U"):
        calligraphy.score(dict(columns, y=columns["y"].astype(str)), "大")
