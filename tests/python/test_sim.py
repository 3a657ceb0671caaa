"""Simulated writers and devices from Python, the device registry, and the trial's limits."""

import threading
import time

import numpy as np
import pytest

import calligraphy


def test_writer_profile_objects_equal_the_named_writers():
    by_name = calligraphy.simulate_trial("九", writer="skilled", seed=4, keep_trace=False).metrics
    by_object = calligraphy.simulate_trial("九", writer=calligraphy.WriterProfile.skilled(), seed=4,
                                           keep_trace=False).metrics
    assert by_object == by_name


def test_a_custom_writer_changes_the_trial_and_is_named():
    steady = calligraphy.WriterProfile.novice().replace(name="steady", bias_offset_m=0.0, stroke_jitter_m=0.0,
                                                         scale_error=0.0, tremor_amplitude_n=0.0)
    result = calligraphy.simulate_trial("九", writer=steady, seed=4, guidance=False, keep_trace=False)
    novice = calligraphy.simulate_trial("九", writer="novice", seed=4, guidance=False, keep_trace=False)
    assert (result.metrics["writer"], result.metrics["writer_profile"]) == ("simulated", "steady")
    # Without the systematic bias the unguided writer stays closer to the reference.
    assert result.metrics["mean_deviation_m"] < novice.metrics["mean_deviation_m"]
    # The specification states it as the command line would: the named profile it starts from and the
    # settings that make it the profile that wrote (its name aside), so the specification alone runs it.
    trial = result.metrics["specification"]["trial"]
    settings = {s["key"]: s["value"] for s in trial["writer_parameters"]}
    assert trial["writer_profile"] == "novice"
    assert settings == {"bias_offset_m": 0.0, "stroke_jitter_m": 0.0, "scale_error": 0.0, "tremor_amplitude_n": 0.0}
    assert calligraphy.writer_profile("novice", settings).replace(name="steady") == steady
    # A named profile with writer_params is stated the same way; the profile alone states no setting.
    skilled = calligraphy.simulate_trial("九", writer="skilled", writer_params={"bias_offset_m": 0.001}, seed=4,
                                         max_duration_s=0.01, keep_trace=False).metrics["specification"]["trial"]
    assert (skilled["writer_profile"], skilled["writer_parameters"]) == (
        "skilled", [{"key": "bias_offset_m", "value": 0.001}])
    assert novice.metrics["specification"]["trial"]["writer_parameters"] == []


def test_device_parameters_reach_the_trial():
    heavy = calligraphy.SimulatedDeviceParameters(moving_mass_kg=0.6)
    a = calligraphy.simulate_trial("九", seed=2, keep_trace=False).metrics
    b = calligraphy.simulate_trial("九", seed=2, keep_trace=False, device=heavy).metrics
    assert a != b
    safety = calligraphy.SafetyChainParameters(max_force_n=1.0)
    capped = calligraphy.simulate_trial("九", seed=2, safety=safety)
    assert np.linalg.norm(capped.force_n, axis=1).max() <= 1.0 + 1e-9


def test_trial_length_is_bounded():
    with pytest.raises(ValueError, match="max_duration_s"):
        calligraphy.simulate_trial("九", rate_hz=100000.0, max_duration_s=1000.0)
    with pytest.raises(ValueError):
        calligraphy.simulate_trial("九", max_duration_s=0.0)


def test_trial_result_keeps_its_scene():
    scene = calligraphy.Scene("九心")
    result = calligraphy.simulate_trial(scene, seed=1, keep_trace=False)
    assert result.scene is scene
    assert result.metrics["character"] == "九心"
    assert calligraphy.simulate_trial("九", keep_trace=False).scene.stroke_count == 2


def test_simulated_device_lists_itself():
    survey = calligraphy.list_devices()
    names = [d.name for d in survey.devices]
    assert "simulated" in names
    simulated = survey.devices[names.index("simulated")]
    assert not simulated.hardware
    # What a default simulated device reports: the parameters' info plus its own physical damping.
    assert simulated.info == calligraphy.SimulatedDevice().info
    assert simulated.info.intrinsic_damping_n_s_per_m == calligraphy.SimulatedDeviceParameters().damping_n_s_per_m
    assert simulated.info.max_force_n > 0
    assert all(isinstance(note, str) for note in survey.notes)


def test_simulated_device_open_close_and_forces():
    device = calligraphy.SimulatedDevice()
    assert device.is_open and device.forces_enabled
    device.enable_forces(False)
    device.write_force([1.0, 0.0, 0.0])
    device.advance(0.05)
    np.testing.assert_array_equal(device.applied_force_n, [0.0, 0.0, 0.0])
    np.testing.assert_allclose(device.true_position_m, calligraphy.SimulatedDeviceParameters().initial_position_m)
    device.close()
    assert not device.is_open


def test_a_closed_simulated_device_faults_not_open_and_applies_no_force():
    # As every device: reading or writing a closed one is the link fault not_open, and no force acts.
    parameters = calligraphy.SimulatedDeviceParameters(damping_n_s_per_m=0.0, encoder_resolution_m=0.0)
    device = calligraphy.SimulatedDevice(parameters)
    device.close()
    for call in (lambda: device.write_force([1.0, 0.0, 0.0]), device.read_state):
        with pytest.raises(calligraphy.CommunicationError, match="not open"):
            call()
    device.advance(0.05)
    np.testing.assert_array_equal(device.applied_force_n, [0.0, 0.0, 0.0])
    np.testing.assert_array_equal(device.true_velocity_m_s, [0.0, 0.0, 0.0])
    np.testing.assert_array_equal(device.true_position_m, parameters.initial_position_m)
    device.open()  # open again: the force acts
    device.write_force([1.0, 0.0, 0.0])
    device.advance(0.05)
    assert device.read_state().position_m[0] > 0.0


def test_simulate_trial_releases_the_gil():
    # With the GIL held for the whole trial, this thread could run only before and after it: a couple of
    # 1 ms sleeps. Released, it keeps running while the trial runs.
    started = threading.Event()
    result = {}

    def run():
        started.set()
        result["r"] = calligraphy.simulate_trial("家永我九心", seed=0, keep_trace=True)  # about 0.3 s of CPU

    worker = threading.Thread(target=run)
    worker.start()
    started.wait()
    turns = 0
    while worker.is_alive():
        time.sleep(0.001)
        turns += 1
    worker.join()
    assert result["r"].metrics["strokes_total"] == 10 + 5 + 7 + 2 + 4
    assert turns >= 20
