"""The stroke acceptance's miss counts as keywords of simulate_trial, the trial specification's fields of the same
names (docs/stroke-acceptance.md, "No dead end"): they reach the renderer, the record states them and a re-run
replays them."""
import pytest

import calligraphy

# A writer that always lifts mid-stroke and never corrects: every attempt at a stroke of 人 is refused
# (too short), so each stroke is credited as assisted after assist_after_misses attempts.
ALWAYS_MISSING = {"mid_stroke_lift_probability": 1.0, "correction_per_attempt": 0.0, "max_attempts_per_stroke": 20}


def missing_trial(**keywords):
    return calligraphy.simulate_trial("人", writer_params=ALWAYS_MISSING, seed=3, max_duration_s=120.0,
                                      keep_trace=False, **keywords)


def attempts(result):
    return [(s["attempts"], s["assisted"]) for s in result.metrics["renderer_strokes"]]


def credited_after(result, misses):
    """Both strokes credited: the first after `misses` attempts in WS; the second after at most that many, since
    the writer redoes the first once more before it sees the credit, a pen-down off the second's start that is
    a miss of the second (docs/stroke-acceptance.md)."""
    (first, first_assisted), (second, second_assisted) = attempts(result)
    return first_assisted and second_assisted and first == misses and 0 <= second <= misses


def test_assist_after_misses_credits_a_stroke_sooner_and_is_recorded_and_replayed():
    default = missing_trial()
    sooner = missing_trial(assist_after_misses=1, hint_after_misses=0)
    assert credited_after(default, 5), attempts(default)
    assert credited_after(sooner, 1), attempts(sooner)
    assert sooner.metrics["trial_time_s"] < default.metrics["trial_time_s"]
    spec = sooner.metrics["specification"]
    assert spec["trial"]["assist_after_misses"] == 1
    assert spec["trial"]["hint_after_misses"] == 0
    assert spec["force_law"]["acceptance"]["assist_after_misses"] == 1
    again = calligraphy.rerun_trial(sooner.metrics)
    assert attempts(again) == attempts(sooner)
    assert again.metrics["specification"] == spec


def test_the_keywords_override_the_force_laws_acceptance():
    force = calligraphy.ForceLawParameters()
    force.acceptance = calligraphy.StrokeAcceptance(assist_after_misses=2)
    assert credited_after(missing_trial(force_law=force), 2)
    assert credited_after(missing_trial(force_law=force, assist_after_misses=3), 3)


@pytest.mark.parametrize("keyword, value", [("assist_after_misses", 1001), ("hint_after_misses", -1)])
def test_a_count_out_of_range_is_refused_by_name(keyword, value):
    with pytest.raises(calligraphy.InvalidArgument, match=keyword):
        missing_trial(**{keyword: value})


@pytest.mark.parametrize("keyword, value", [("assist_after_misses", 2.5), ("hint_after_misses", 3.0)])
def test_a_count_is_an_int(keyword, value):
    # A count is an int in Python, as the schema's "integer" and every other count argument: a float is a
    # TypeError naming it, a whole one too (as range(3.0) is).
    with pytest.raises(TypeError, match=keyword):
        missing_trial(**{keyword: value})
    with pytest.raises(TypeError, match=keyword):
        calligraphy.StrokeAcceptance(**{keyword: value})
    assert type(getattr(calligraphy.StrokeAcceptance(), keyword)) is int
