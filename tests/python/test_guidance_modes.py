"""Writers by name and settings, guidance modes and the fading rule in simulate_trial / run_trial."""

import statistics

import pytest

import calligraphy

# Embedded characters that examples/python/table5.py does not use by default.
CHARACTER = "大"


def trial(**kwargs):
    kwargs.setdefault("keep_trace", False)
    return calligraphy.simulate_trial(CHARACTER, **kwargs)


@pytest.mark.parametrize("name", ["novice", "skilled", "foreign"])
def test_writer_by_name(name):
    result = trial(writer=name)
    assert result.writer == getattr(calligraphy.WriterProfile, name)()
    assert (result.metrics["writer"], result.metrics["writer_profile"]) == ("simulated", name)


def test_unknown_writer_name_is_named():
    with pytest.raises(calligraphy.InvalidArgument, match="expert"):
        trial(writer="expert")


def test_writer_params_are_applied():
    result = trial(writer="foreign", writer_params={"bias_offset_m": 0.001, "max_attempts_per_stroke": 7})
    assert result.writer.bias_offset_m == 0.001
    assert result.writer.max_attempts_per_stroke == 7
    assert result.writer.order_error_probability == calligraphy.WriterProfile.foreign().order_error_probability


def test_bad_writer_param_names_the_key():
    with pytest.raises(calligraphy.InvalidArgument, match="no_such_key"):
        trial(writer_params={"no_such_key": 1.0})
    with pytest.raises(calligraphy.InvalidArgument, match="scale_error"):
        trial(writer_params={"scale_error": 0.9})
    with pytest.raises(TypeError, match="hesitation_s"):
        trial(writer_params={"hesitation_s": "long"})
    with pytest.raises(TypeError, match="writer_params"):
        trial(writer_params=[("hesitation_s", 1.0)])


def test_run_trial_takes_the_same_writer_arguments():
    result = calligraphy.run_trial(CHARACTER, writer="foreign", writer_params={"learning_rate": 0.2},
                                   guidance_mode="fading", guidance_gain=0.5, keep_trace=False)
    assert result.writer.learning_rate == 0.2
    assert result.writer_log is not None


def test_foreign_writer_without_guidance_makes_order_errors():
    errors = [trial(writer="foreign", guidance=False, seed=seed).writer_log.out_of_order_attempts()
              for seed in range(8)]
    assert any(count > 0 for count in errors)


def test_novice_makes_no_order_errors():
    log = trial(writer="novice", guidance=False, seed=1).writer_log
    assert log.out_of_order_attempts() == 0


def test_guidance_mode_by_name_and_member_agree():
    by_name = trial(guidance_mode="fading", guidance_gain=0.3, seed=2).metrics
    by_member = trial(guidance_mode=calligraphy.GuidanceMode.fading, guidance_gain=0.3, seed=2).metrics
    assert by_name == by_member


def test_fading_gain_scales_the_guidance():
    """Less guidance, more deviation: on average over seeds, gain 0 deviates more than gain 1."""
    def mean_deviation(gain):
        return statistics.mean(
            trial(guidance_mode="fading", guidance_gain=gain, seed=seed).metrics["mean_deviation_m"]
            for seed in range(4))

    assert mean_deviation(0.0) > mean_deviation(1.0)


def test_bad_guidance_arguments_are_named():
    with pytest.raises(calligraphy.InvalidArgument, match="guidance_mode"):
        trial(guidance_mode="strong")
    with pytest.raises(calligraphy.InvalidArgument, match="guidance_gain"):
        trial(guidance_mode="fading", guidance_gain=1.5)
    with pytest.raises(calligraphy.InvalidArgument, match="teacher"):
        trial(guidance_mode="replay")
    samples = [calligraphy.TeacherSample(time_s=0.0, position_m=(0, 0, 0)),
               calligraphy.TeacherSample(time_s=1.0, position_m=(0.01, 0, 0))]
    with pytest.raises(calligraphy.InvalidArgument, match="teacher"):
        trial(guidance_mode="fixed", teacher=samples)
    with pytest.raises(TypeError, match="teacher"):
        trial(teacher="teacher.json")


def test_next_guidance_gain_follows_the_rule():
    # g(n+1) = clamp(f g(n) + k e(n), 0, 1) with the default f = 0.8, k = 200 / m.
    assert calligraphy.next_guidance_gain(0.5, 0.001) == pytest.approx(0.8 * 0.5 + 200.0 * 0.001)
    assert calligraphy.next_guidance_gain(1.0, 0.01) == 1.0
    rule = calligraphy.FadingRule(forgetting_factor=0.5, error_gain_per_m=0.0)
    gains = [1.0]
    for _ in range(3):
        gains.append(calligraphy.next_guidance_gain(gains[-1], 0.002, rule))
    assert gains == [1.0, 0.5, 0.25, 0.125]


def test_next_guidance_gain_refuses_bad_input():
    with pytest.raises(calligraphy.InvalidArgument):
        calligraphy.next_guidance_gain(1.5, 0.001)
    with pytest.raises(calligraphy.InvalidArgument):
        calligraphy.next_guidance_gain(0.5, -0.001)
    with pytest.raises(TypeError, match="error_m"):
        calligraphy.next_guidance_gain(0.5, "small")
    with pytest.raises(calligraphy.InvalidArgument, match="forgetting_factor"):
        calligraphy.FadingRule(forgetting_factor=2.0)


@pytest.mark.parametrize("mode", [m for m in calligraphy.GuidanceMode.__members__ if m != "replay"])
def test_the_library_reads_back_the_mode_it_writes(mode):
    """The metrics spell a mode as the command line and the files do ("assist-as-needed"); Python takes that
    spelling back, and the member's name ("assist_as_needed") for one more version with a DeprecationWarning."""
    first = trial(guidance_mode=getattr(calligraphy.GuidanceMode, mode), seed=1)
    spelled = first.metrics["guidance_mode"]
    assert spelled == mode.replace("_", "-")
    again = trial(guidance_mode=spelled, seed=1)
    assert again.metrics["guidance_mode"] == spelled
    if spelled != mode:
        with pytest.warns(DeprecationWarning, match=spelled):
            trial(guidance_mode=mode, seed=1)
    with pytest.raises(calligraphy.InvalidArgument, match="assist-as-needed"):
        trial(guidance_mode="assist as needed")
