"""The stroke matcher from Python: the renderer's verdict on a recorded pen path, and the labelled
person-like paths to check it with."""

import numpy as np
import pytest

import calligraphy

Refusal = calligraphy.StrokeRefusal
States = calligraphy.InteractionState
CHARACTERS = "永口十"

# The stroke matcher reads a path in steps of 0.25 mm (src/analysis/stroke_matcher.cpp); a renderer fed
# the same points, one per tick, sees the pen move exactly as the matcher reads it.
STEP_M = 0.00025


@pytest.fixture(scope="module", params=list(CHARACTERS))
def scene(request):
    return calligraphy.Scene(request.param)


def median(scene, stroke):
    return scene.characters[0].strokes[stroke].median_m


def arc_lengths(path):
    return np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(path, axis=0), axis=1))])


def first_part(path, fraction):
    """The path up to `fraction` of its arc length, ending on it."""
    arc = arc_lengths(path)
    cut = fraction * arc[-1]
    kept = arc < cut
    end = np.array([np.interp(cut, arc, path[:, 0]), np.interp(cut, arc, path[:, 1])])
    return np.vstack([path[kept], end])


def densified(path):
    """The path with points at most STEP_M apart, as the matcher reads it."""
    points = [path[0]]
    for a, b in zip(path[:-1], path[1:]):
        pieces = max(1, int(np.ceil(np.linalg.norm(b - a) / STEP_M)))
        points.extend(a + (b - a) * (k / pieces) for k in range(1, pieces + 1))
    return np.array(points)


def test_every_strokes_median_is_accepted(scene):
    for k, stroke in enumerate(scene.characters[0].strokes):
        match = calligraphy.match_stroke(scene, 0, k, stroke.median_m)
        assert match.accepted, (scene.characters[0].char, k, match)
        assert match.refusal == Refusal.none
        assert match.matched_stroke == k
        assert match.covered_fraction > 0.9
        # The centre line is the median: the median lies on it.
        assert match.mean_deviation_m < 1e-4


def test_a_median_written_from_its_end_is_backwards(scene):
    for k in range(len(scene.characters[0].strokes)):
        match = calligraphy.match_stroke(scene, 0, k, median(scene, k)[::-1])
        assert not match.accepted
        assert match.refusal == Refusal.backwards, (scene.characters[0].char, k, match)


def test_the_first_third_of_a_stroke_is_too_short():
    scene = calligraphy.Scene("十")
    third = first_part(median(scene, 0), 1.0 / 3.0)
    match = calligraphy.match_stroke(scene, 0, 0, third)
    assert not match.accepted
    assert match.refusal == Refusal.too_short
    assert 0.2 < match.covered_fraction < 0.5
    # The whole stroke, from the same start, is written.
    assert calligraphy.match_stroke(scene, 0, 0, median(scene, 0)).accepted


def test_a_later_strokes_median_is_the_wrong_order(scene):
    strokes = scene.characters[0].strokes
    for k in range(1, len(strokes)):
        match = calligraphy.match_stroke(scene, 0, 0, strokes[k].median_m)
        assert not match.accepted
        assert match.refusal == Refusal.wrong_order, (scene.characters[0].char, k, match)
        assert match.matched_stroke == k


def test_an_earlier_strokes_median_is_the_wrong_stroke():
    scene = calligraphy.Scene("十")
    match = calligraphy.match_stroke(scene, 0, 1, median(scene, 0))
    assert match.refusal == Refusal.wrong_stroke and match.matched_stroke == 0


def test_shifted_person_traces_are_refused(scene):
    for k in range(len(scene.characters[0].strokes)):
        for seed in range(3):
            path = calligraphy.person_trace(scene, 0, k, "shifted", seed)
            match = calligraphy.match_stroke(scene, 0, k, path)
            assert not match.accepted, (scene.characters[0].char, k, seed, match)
            assert match.refusal != Refusal.none


def test_person_traces_are_seeded_paths_in_metres(scene):
    box = scene.characters[0].bounding_box_m
    for kind in calligraphy.TraceKind.__members__.values():
        for k in range(len(scene.characters[0].strokes)):
            if not calligraphy.trace_applies(scene, 0, k, kind):
                continue
            path = calligraphy.person_trace(scene, 0, k, kind, seed=7)
            assert path.dtype == np.float64 and path.ndim == 2 and path.shape[1] == 2 and len(path) >= 2
            assert np.isfinite(path).all()
            # On the character's paper, give or take a shift and a scribble: metres, not data units.
            assert (path > box[0] - 0.02).all() and (path < box[1] + 0.02).all()
            np.testing.assert_array_equal(path, calligraphy.person_trace(scene, 0, k, kind.name, seed=7))
    human = [calligraphy.person_trace(scene, 0, 0, "human", seed=s) for s in (1, 2)]
    assert human[0].shape != human[1].shape or not np.array_equal(human[0], human[1])


def test_positive_kinds_are_the_ones_that_write_the_stroke():
    positive = {"median", "human", "corners_cut", "corners_overshot", "ends_short", "ends_past", "pointer"}
    for name, kind in calligraphy.TraceKind.__members__.items():
        assert calligraphy.is_positive(kind) == (name in positive)
        assert calligraphy.is_positive(name) == (name in positive)
    scene = calligraphy.Scene("十")
    assert calligraphy.trace_applies(scene, 0, 0, "swapped_order")
    assert not calligraphy.trace_applies(scene, 0, 1, "swapped_order")  # no next stroke


def test_a_tighter_acceptance_refuses_what_the_default_accepts():
    scene = calligraphy.Scene("十")
    path = median(scene, 0) + [0.0, 0.002]  # 2 mm across the stroke, along all of it
    assert calligraphy.match_stroke(scene, 0, 0, path).accepted
    strict = calligraphy.StrokeAcceptance(mean_deviation_m=0.001)
    match = calligraphy.match_stroke(scene, 0, 0, path, acceptance=strict)
    assert not match.accepted
    assert match.mean_deviation_m == pytest.approx(0.002, abs=2e-4)


def test_bad_arguments_raise_naming_them():
    scene = calligraphy.Scene("十")
    path = median(scene, 0)
    with_nan = path.copy()
    with_nan[1, 0] = np.nan
    for bad in (with_nan, path[:, :1], np.zeros((len(path), 3)), path[0], np.zeros((0, 2)), [[0.0, np.inf]]):
        with pytest.raises(ValueError, match="path_m"):
            calligraphy.match_stroke(scene, 0, 0, bad)
    with pytest.raises(TypeError, match="path_m"):
        calligraphy.match_stroke(scene, 0, 0, "along")
    for call in (calligraphy.match_stroke, lambda *a: calligraphy.person_trace(*a[:3], "human")):
        with pytest.raises(IndexError, match="character_index"):
            call(scene, 1, 0, path)
        with pytest.raises(IndexError, match="stroke_index"):
            call(scene, 0, 2, path)
        with pytest.raises(IndexError, match="stroke_index"):
            call(scene, 0, -1, path)
        with pytest.raises(TypeError, match="stroke_index"):
            call(scene, 0, 0.5, path)
        with pytest.raises(TypeError, match="scene"):
            call("十", 0, 0, path)
    with pytest.raises(TypeError, match="acceptance"):
        calligraphy.match_stroke(scene, 0, 0, path, acceptance={"corridor_m": 0.01})
    with pytest.raises(ValueError, match="kind"):
        calligraphy.person_trace(scene, 0, 0, "sideways")
    with pytest.raises(ValueError, match="seed"):
        calligraphy.person_trace(scene, 0, 0, "human", seed=-1)
    with pytest.raises(ValueError, match="swapped_order"):
        calligraphy.person_trace(scene, 0, 1, "swapped_order")  # the last stroke has no next one


def renderer_accepts(scene, stroke, path, law):
    """Whether a Renderer writes stroke `stroke` of the scene's only character when its pen, after writing
    the strokes before it along their medians, moves along `path` on the paper one point per tick and is
    lifted: it completes the stroke before (or at) the lift rather than abandoning it."""
    renderer = calligraphy.Renderer(scene, law, options=calligraphy.RendererOptions(rate_hz=1000.0))
    ticks = 0

    def pen_along(points):
        nonlocal ticks
        positions = [(x, y, -0.001) for x, y in points] + [(points[-1][0], points[-1][1], 0.01)]
        for position in positions:
            output = renderer.tick(calligraphy.DeviceState(position_m=position, time_s=ticks * 1e-3))
            ticks += 1
            if output.stroke_completed or output.stroke_abandoned:
                return output
        return None  # never entered the stroke at its start

    for earlier in range(stroke):
        written = pen_along(densified(median(scene, earlier)))
        assert written is not None and written.stroke_completed
    output = pen_along(path)
    return output is not None and output.stroke_completed


@pytest.mark.parametrize("stroke", [0, 1])
def test_the_renderer_gives_the_matchers_verdict(scene, stroke):
    law = calligraphy.ForceLawParameters()
    paths = {
        "median": median(scene, stroke),
        "reversed": median(scene, stroke)[::-1],
        "first third": first_part(median(scene, stroke), 1.0 / 3.0),
        "first four fifths": first_part(median(scene, stroke), 0.8),
    }
    for kind in ("human", "corners_cut", "ends_short", "ends_past", "pointer", "half", "shifted", "scribble"):
        for seed in range(2):
            paths[f"{kind} {seed}"] = calligraphy.person_trace(scene, 0, stroke, kind, seed)
    verdicts = set()
    for name, path in paths.items():
        dense = densified(path)
        expected = calligraphy.match_stroke(scene, 0, stroke, dense, acceptance=law.acceptance).accepted
        assert renderer_accepts(scene, stroke, dense, law) == expected, (scene.characters[0].char, name)
        verdicts.add(expected)
    assert verdicts == {True, False}  # both verdicts were compared
