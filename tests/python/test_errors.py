"""Bad input raises Python exceptions carrying the C++ message."""

import subprocess

import numpy as np
import pytest

import calligraphy


def test_exception_hierarchy():
    assert issubclass(calligraphy.CharacterNotFound, KeyError)
    assert issubclass(calligraphy.CharacterNotFound, calligraphy.DataError)
    assert issubclass(calligraphy.InvalidArgument, ValueError)
    assert issubclass(calligraphy.DataError, RuntimeError)
    assert issubclass(calligraphy.DeviceError, RuntimeError)
    assert issubclass(calligraphy.DeviceNotFound, LookupError)
    assert issubclass(calligraphy.CommunicationError, ConnectionError)
    for cls in (calligraphy.DeviceNotFound, calligraphy.DeviceUnavailable, calligraphy.CommunicationError,
                calligraphy.SafetyFault, calligraphy.CalibrationNeeded):
        assert issubclass(cls, calligraphy.DeviceError)
    for cls in (calligraphy.InvalidArgument, calligraphy.DataError, calligraphy.DeviceError):
        assert issubclass(cls, calligraphy.Error)


def test_missing_character_is_key_error(library):
    with pytest.raises(KeyError) as info:
        library.load("龘")
    assert isinstance(info.value, calligraphy.CharacterNotFound)
    message = str(info.value)
    assert "U+9F98" in message
    # The message speaks Python: how to load more characters, no command-line flag.
    assert "CharacterLibrary.from_hanzi_writer" in message and "CharacterLibrary.from_store" in message
    assert "--" not in message


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
        calligraphy.ForceLawParameters(paper_stiffness_n_per_m=-1.0)
    with pytest.raises(ValueError):
        calligraphy.ForceLawParameters(constraint_radius_m=0.0)
    with pytest.raises(ValueError):
        calligraphy.ForceLawParameters(guidance_stiffness_n_per_m=float("nan"))


def test_simulate_trial_bad_input():
    with pytest.raises(ValueError, match="writer"):
        calligraphy.simulate_trial("永", writer="expert")
    with pytest.raises(ValueError):
        calligraphy.simulate_trial("永", rate_hz=10.0)
    with pytest.raises(KeyError):
        calligraphy.simulate_trial("龘")
    with pytest.raises(ValueError):
        calligraphy.simulate_trial("")
    with pytest.raises(TypeError, match="characters"):
        calligraphy.simulate_trial([1, 2])


def test_simulated_device_bad_input():
    with pytest.raises(ValueError, match="moving_mass_kg"):
        calligraphy.SimulatedDeviceParameters(moving_mass_kg=0.0)
    device = calligraphy.SimulatedDevice()
    with pytest.raises(ValueError):
        device.write_force([1.0, 0.0])
    with pytest.raises(ValueError):
        device.advance(-1e-3)


def test_cli_adds_its_own_flag_hint(cli):
    # The library's message is neutral; the command line names its options.
    run = subprocess.run([cli, "model", "龘"], capture_output=True, text=True)
    assert run.returncode == 2  # a character the user names that the library lacks: wrong usage
    assert "U+9F98" in run.stderr and "--data" in run.stderr and "CharacterLibrary" not in run.stderr


@pytest.mark.parametrize(
    "call, name",
    [
        (lambda: calligraphy.simulate_trial("永", rate_hz="fast"), "rate_hz"),
        (lambda: calligraphy.simulate_trial("永", seed=1.5), "seed"),
        (lambda: calligraphy.simulate_trial("永", guidance=None), "guidance"),
        (lambda: calligraphy.simulate_trial("永", writer=3), "writer"),
        (lambda: calligraphy.simulate_trial("永", library="embedded"), "library"),
        (lambda: calligraphy.simulate_trial("永", force_law={"guidance": True}), "force_law"),
        (lambda: calligraphy.simulate_trial(42), "characters"),
        (lambda: calligraphy.nearest_point([[0, 0], [1, 0]], "here"), "point"),
        (lambda: calligraphy.nearest_point([[0, 0], [1, 0]], [0, 1], newton_starts=2.5), "newton_starts"),
        (lambda: calligraphy.nearest_point([[0, 0], [1, 0]], [0, 1], tolerance="small"), "tolerance"),
        (lambda: calligraphy.CharacterLibrary.default().load(0x6C38), "char"),
        (lambda: calligraphy.CharacterLibrary.from_hanzi_writer(3), "path"),
        (lambda: calligraphy.paper_force(-0.001, 0.0, stiffness_n_per_m=None), "stiffness_n_per_m"),
        (lambda: calligraphy.SimulatedDevice().advance("1 ms"), "dt_s"),
        (lambda: calligraphy.SimulatedDevice(parameters=1), "parameters"),
        (lambda: calligraphy.ForceLawParameters(guidance_stiffness_n_per_m="400"), "guidance_stiffness_n_per_m"),
    ],
)
def test_wrong_type_names_the_argument(call, name):
    with pytest.raises(TypeError) as info:
        call()
    message = str(info.value)
    assert name in message
    assert "Unable to cast" not in message and "incompatible function arguments" not in message


def test_out_of_range_integer_is_value_error():
    with pytest.raises(ValueError, match="seed"):
        calligraphy.simulate_trial("永", seed=-1)
    with pytest.raises(ValueError, match="newton_starts"):
        calligraphy.nearest_point([[0, 0], [1, 0]], [0, 1], newton_starts=2**40)
