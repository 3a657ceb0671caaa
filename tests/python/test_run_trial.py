"""run_trial: a trial on a device of the registry, by name, lock-step or in real time."""
import pytest

import calligraphy


def test_run_trial_on_the_simulated_device_is_simulate_trial():
    by_name = calligraphy.run_trial("九", device="simulated", seed=2, keep_trace=False)
    simulated = calligraphy.simulate_trial("九", seed=2, keep_trace=False)
    for key in ("mean_deviation_m", "total_time_s", "strokes_completed", "end_reason"):
        assert by_name.metrics[key] == simulated.metrics[key]
    assert by_name.metrics["device"] == "simulated"


def test_run_trial_in_real_time_keeps_its_ticks():
    result = calligraphy.run_trial("永", device="simulated", pacing="real-time", max_duration_s=0.3)
    assert result.metrics["end_reason"] == "time_limit"
    assert result.metrics["aborted"]
    assert len(result.time_s) == 300  # the time limit counts ticks: 0.3 s at 1 kHz


def test_run_trial_names_what_is_wrong():
    with pytest.raises(calligraphy.DeviceNotFound, match="simulated"):
        calligraphy.run_trial("九", device="no-such-device")
    with pytest.raises(ValueError, match="pacing"):
        calligraphy.run_trial("九", pacing="fast")
    with pytest.raises(TypeError, match="device"):
        calligraphy.run_trial("九", device=3)


def test_a_known_device_that_cannot_be_used_says_why(monkeypatch, tmp_path):
    # A damaged CALLIGRAPHY_LIBHD: the OpenHaptics device is known, and its backend's reason is the error.
    (tmp_path / "libHD.so").write_bytes(b"")
    monkeypatch.setenv("CALLIGRAPHY_LIBHD", str(tmp_path / "libHD.so"))
    with pytest.raises(calligraphy.DeviceUnavailable, match="empty"):
        calligraphy.run_trial("九", device="openhaptics", pacing="real-time", max_duration_s=0.1)
    # The simulated device never loads it.
    result = calligraphy.run_trial("九", device="simulated", keep_trace=False)
    assert result.metrics["strokes_completed"] >= 0


def test_every_error_class_of_the_library_is_there():
    assert issubclass(calligraphy.RealtimeError, calligraphy.DeviceError)
    assert issubclass(calligraphy.StateError, calligraphy.Error)
    assert issubclass(calligraphy.StateError, RuntimeError)


def test_run_trial_takes_the_specifications_watchdog():
    # watchdog_s is the specification's field (`calligraphy trial --watchdog-ms`): stated in the record,
    # refused in lock-step (no wall clock to bound) and off a whole millisecond, naming it.
    result = calligraphy.run_trial("一", device="simulated", pacing="real-time", max_duration_s=0.05,
                                   watchdog_s=0.2)
    assert calligraphy.check_trial_record(result.metrics)["trial"]["watchdog_s"] == 0.2
    for pacing, seconds in (("lock-step", 1.0), ("real-time", 0.0125), ("real-time", -1.0)):
        with pytest.raises(calligraphy.InvalidArgument, match="watchdog_s"):
            calligraphy.run_trial("一", device="simulated", pacing=pacing, max_duration_s=0.05, watchdog_s=seconds)
