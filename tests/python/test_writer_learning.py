"""A simulated writer's log and learning across repetitions from Python."""

import pytest

import calligraphy

CHARACTER = "木"


def test_trial_result_carries_the_writers_log():
    result = calligraphy.simulate_trial(CHARACTER, writer="skilled", keep_trace=False, seed=1)
    log = result.writer_log
    assert isinstance(log, calligraphy.WriterLog)
    assert result.metrics["completed_in_order"]
    # A skilled writer attempts every stroke once, in the reference order; the trial ends as the last
    # stroke is recognised, before the writer lifts the pen, so that attempt may stay unfinished.
    assert [a.scene_stroke for a in log.attempts] == list(range(result.metrics["strokes_total"]))
    assert log.completed_order() == list(range(len(log.attempts) - 1)) or log.completed_order() == list(
        range(len(log.attempts)))
    assert all(a.end == calligraphy.AttemptEnd.completed for a in log.attempts[:-1])
    assert log.out_of_order_attempts() == 0 and not log.gave_up and log.strokes_given_up == 0


def train(profile, repetitions, guidance):
    profiles = [profile]
    for repetition in range(repetitions):
        result = calligraphy.simulate_trial(CHARACTER, writer=profiles[-1], guidance=guidance,
                                            seed=100 + repetition, keep_trace=False)
        outcome = calligraphy.RepetitionOutcome.from_log(result.writer_log, 1.0 if guidance else 0.0)
        profiles.append(calligraphy.next_repetition_profile(profiles[-1], outcome))
    return profiles


def test_learning_lowers_bias_over_repetitions():
    learner = calligraphy.writer_profile("novice", {"learning_rate": 0.5})
    profiles = train(learner, 3, guidance=True)
    biases = [p.bias_offset_m for p in profiles]
    scales = [abs(p.scale_error) for p in profiles]
    assert all(later < earlier for earlier, later in zip(biases, biases[1:]))
    assert all(later < earlier for earlier, later in zip(scales, scales[1:]))
    assert biases[-1] >= calligraphy.WriterProfile.skilled().bias_offset_m


def test_guided_practice_teaches_more_than_unguided():
    learner = calligraphy.writer_profile("novice", {"learning_rate": 0.5})
    guided = train(learner, 2, guidance=True)[-1]
    unguided = train(learner, 2, guidance=False)[-1]
    assert guided.bias_offset_m < unguided.bias_offset_m


def test_without_learning_rate_the_profile_stays():
    profile = calligraphy.WriterProfile.foreign()
    assert train(profile, 1, guidance=True)[-1] == profile


def test_outcome_from_log_counts_the_errors():
    log = calligraphy.simulate_trial("天", writer="foreign", guidance=True, seed=3, keep_trace=False).writer_log
    outcome = calligraphy.RepetitionOutcome.from_log(log, 0.25)
    assert outcome.guidance_share == 0.25
    assert outcome.out_of_order_attempts == log.out_of_order_attempts()
    assert outcome.refused_out_of_order == log.refused_out_of_order()
    assert outcome.backwards_attempts == log.backwards_attempts()
    with pytest.raises(calligraphy.InvalidArgument):
        calligraphy.RepetitionOutcome.from_log(log, 1.5)
    with pytest.raises(calligraphy.InvalidArgument):
        calligraphy.RepetitionOutcome(out_of_order_attempts=1, refused_out_of_order=2)


def test_writer_profile_by_name_with_settings():
    profile = calligraphy.writer_profile("skilled", {"writing_speed_m_s": 0.05})
    assert profile.writing_speed_m_s == 0.05
    assert "learning_rate" in calligraphy.writer_parameter_names()
    with pytest.raises(calligraphy.InvalidArgument, match="bogus"):
        calligraphy.writer_profile("skilled", {"bogus": 1.0})
