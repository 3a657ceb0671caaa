"""rerun_trial: a trial's metrics hold its whole specification, which runs it again bit for bit."""
import hashlib
import json

import numpy as np
import pytest

import calligraphy


def tuned_trial():
    """A trial with a value away from its default in every part Python can set."""
    force = calligraphy.ForceLawParameters(
        guidance_law=calligraphy.AssistAsNeededGuidance(band_m=0.0015),
        off_stroke_force_n=0.3,
        friction_coefficient=0.2,
        guidance_stiffness_n_per_m=350.0,
    )
    return calligraphy.simulate_trial(
        "九",
        writer="skilled",
        writer_params={"bias_offset_m": 0.0024, "hesitation_probability": 0.1},
        seed=31,
        rate_hz=900.0,
        max_duration_s=40.0,
        force_law=force,
        device=calligraphy.SimulatedDeviceParameters(moving_mass_kg=0.15, damping_n_s_per_m=0.7),
        safety=calligraphy.SafetyChainParameters(max_force_change_n_per_tick=0.2),
        passivity=calligraphy.PassivityParameters(enabled=True),
    )


def same_trace(a, b):
    for name in ("time_s", "position_m", "force_n", "state", "stroke", "element"):
        assert np.array_equal(getattr(a, name), getattr(b, name)), name


def test_a_trial_runs_again_from_its_metrics_and_from_its_file(tmp_path):
    first = tuned_trial()
    spec = first.metrics["specification"]
    assert spec["simulated_device"]["moving_mass_kg"] == 0.15
    assert spec["force_law"]["off_stroke_force_n"] == 0.3
    assert spec["passivity"]["enabled"] is True
    again = calligraphy.rerun_trial(first.metrics)
    same_trace(first, again)
    assert again.metrics["specification"] == spec
    path = tmp_path / "trial.json"
    path.write_text(json.dumps(first.metrics))
    same_trace(first, calligraphy.rerun_trial(path))
    # The specification alone is enough.
    same_trace(first, calligraphy.rerun_trial(spec))


def test_the_record_carries_what_the_arguments_alone_do_not():
    first = tuned_trial()
    # Without the device's physics the same arguments give another trace: the record held them.
    other = calligraphy.simulate_trial(
        "九", writer="skilled", writer_params={"bias_offset_m": 0.0024, "hesitation_probability": 0.1}, seed=31,
        rate_hz=900.0, max_duration_s=40.0)
    assert not np.array_equal(first.position_m[: len(other.position_m)], other.position_m[: len(first.position_m)])


def test_what_is_not_a_record_is_refused():
    with pytest.raises(calligraphy.DataError, match="no trial specification"):
        calligraphy.rerun_trial({"end_reason": "completed"})
    with pytest.raises(TypeError, match="record"):
        calligraphy.rerun_trial(3)
    spec = calligraphy.simulate_trial("十", max_duration_s=1.0, keep_trace=False).metrics["specification"]
    current = spec["version"]
    spec["version"] = current + 1  # a version this library does not read yet
    with pytest.raises(calligraphy.DataError, match="/version"):
        calligraphy.rerun_trial(spec)
    # A record's JSON text is not a path: it is named as such, not echoed back as a missing file.
    spec["version"] = current
    with pytest.raises(TypeError, match="JSON text, not a path"):
        calligraphy.rerun_trial(json.dumps(spec))
    with pytest.raises(TypeError, match="JSON text, not a path"):
        calligraphy.check_trial_record("  " + json.dumps(spec))


def test_a_replay_record_run_from_another_folder_says_its_teacher_is_the_one_it_names(tmp_path, monkeypatch):
    # A record names its teacher's file as --teacher was given, relative to the folder it ran in; from
    # another folder the file is not there: the DataError says it is the record's teacher and what to give.
    monkeypatch.chdir(tmp_path)
    teacher = calligraphy.record_teacher(calligraphy.simulate_trial("十", writer="skilled"), "teacher.json")
    record = calligraphy.simulate_trial("十", teacher=teacher, keep_trace=False).metrics
    record["specification"]["trial"]["teacher"] = "teacher.json"  # as `calligraphy trial --teacher` names it
    record["specification"]["teacher_sha256"] = hashlib.sha256((tmp_path / "teacher.json").read_bytes()).hexdigest()
    here = calligraphy.rerun_trial(record)  # from the folder it names its teacher in
    (tmp_path / "elsewhere").mkdir()
    monkeypatch.chdir(tmp_path / "elsewhere")
    with pytest.raises(calligraphy.DataError) as refused:
        calligraphy.rerun_trial(record)
    message = str(refused.value)
    assert "the replay's teacher teacher.json (as --teacher was given when it ran" in message
    assert "no such file" in message and "give teacher=" in message
    again = calligraphy.rerun_trial(record, teacher=teacher)
    assert again.metrics["mean_deviation_m"] == here.metrics["mean_deviation_m"]
