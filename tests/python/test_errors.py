"""Bad input raises Python exceptions carrying the C++ message."""

import numpy as np
import pytest

import calligraphy


def test_exception_hierarchy():
    assert issubclass(calligraphy.CharacterNotFoundError, KeyError)
    assert issubclass(calligraphy.CharacterNotFoundError, calligraphy.DataError)
    assert issubclass(calligraphy.InvalidArgumentError, ValueError)
    assert issubclass(calligraphy.DataError, RuntimeError)
    assert issubclass(calligraphy.DeviceError, RuntimeError)
    for cls in (calligraphy.InvalidArgumentError, calligraphy.DataError, calligraphy.DeviceError):
        assert issubclass(cls, calligraphy.CalligraphyError)


def test_missing_character_is_key_error(library):
    with pytest.raises(KeyError) as info:
        library.load("龘")
    assert isinstance(info.value, calligraphy.CharacterNotFoundError)
    assert "U+9F98" in str(info.value)


def test_not_one_character_is_value_error(library):
    with pytest.raises(ValueError, match="exactly one character"):
        library.load("永我")
    with pytest.raises(ValueError):
        library.load("")


def test_missing_folder_is_data_error(tmp_path):
    missing = tmp_path / "nowhere"
    with pytest.raises(calligraphy.DataError) as info:
        calligraphy.CharacterLibrary.from_hanzi_writer(str(missing))
    assert isinstance(info.value, RuntimeError)
    assert "nowhere" in str(info.value)


def test_malformed_json_is_data_error_naming_the_file(tmp_path):
    (tmp_path / "一.json").write_text('{"medians": [[[1, 2], ', encoding="utf-8")
    lib = calligraphy.CharacterLibrary.from_hanzi_writer(str(tmp_path))
    with pytest.raises(calligraphy.DataError, match="一.json"):
        lib.load("一")


def test_nearest_point_bad_input():
    element = calligraphy.StrokeElement([[0, 0], [1, 0]])
    with pytest.raises(ValueError):
        calligraphy.nearest_point(element, [np.nan, 0.0])
    with pytest.raises(ValueError, match="shape"):
        calligraphy.nearest_point(element, [1.0, 2.0, 3.0])
    with pytest.raises(ValueError, match="method"):
        calligraphy.nearest_point(element, [0.5, 1.0], method="magic")
    with pytest.raises(ValueError):
        calligraphy.nearest_point(element, [0.5, 1.0], tolerance=0.0)
    with pytest.raises(ValueError, match="2..5"):
        calligraphy.nearest_point(np.zeros((6, 2)), [0.5, 1.0])
    with pytest.raises(ValueError):
        calligraphy.StrokeElement([[0, 0]])


def test_force_law_rejects_bad_parameters():
    with pytest.raises(ValueError, match="paper_stiffness"):
        calligraphy.ForceLaw(paper_stiffness_n_per_m=-1.0)
    with pytest.raises(ValueError):
        calligraphy.ForceLaw(constraint_radius_m=0.0)
    with pytest.raises(ValueError):
        calligraphy.ForceLaw(guidance_stiffness_n_per_m=float("nan"))


def test_simulate_trial_bad_input():
    with pytest.raises(ValueError, match="writer"):
        calligraphy.simulate_trial("永", writer="expert")
    with pytest.raises(ValueError):
        calligraphy.simulate_trial("永", rate_hz=10.0)
    with pytest.raises(KeyError):
        calligraphy.simulate_trial("龘")
    with pytest.raises(ValueError):
        calligraphy.simulate_trial("")
    with pytest.raises(ValueError):
        calligraphy.simulate_trial([1, 2])


def test_simulated_device_bad_input():
    with pytest.raises(ValueError):
        calligraphy.SimulatedDevice(moving_mass_kg=0.0)
    device = calligraphy.SimulatedDevice()
    with pytest.raises(ValueError):
        device.write_force([1.0, 0.0])
    with pytest.raises(ValueError):
        device.advance(-1e-3)
