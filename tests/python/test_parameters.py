"""The C++ parameter structs bound field for field: construction, checks on assignment, repr, pickling."""

import pathlib
import pickle
import re

import numpy as np
import pytest

import calligraphy

INCLUDE = pathlib.Path(__file__).resolve().parents[2] / "include" / "calligraphy"


def cpp_fields(header, struct):
    """The data members of `struct` in the header, in declaration order."""
    text = (INCLUDE / header).read_text(encoding="utf-8")
    body = re.search(r"struct " + struct + r" \{(.*?)\n\};", text, re.S).group(1)
    code = " ".join(line.split("//")[0] for line in body.splitlines())
    fields = []
    for statement in code.split(";"):
        declaration = statement.split("=")[0].split("{")[0].strip()
        match = re.fullmatch(r"[\w:<>]+\s+(\w+)", declaration)
        if match and not statement.strip().startswith(("static", "[[", "void")):
            fields.append(match.group(1))
    return fields


@pytest.mark.parametrize(
    "cls, header, struct",
    [
        (calligraphy.ForceLawParameters, "render/force_law.hpp", "ForceLawParameters"),
        (calligraphy.NearestPointOptions, "model/nearest_point.hpp", "NearestPointOptions"),
        (calligraphy.WriterProfile, "trial/writer_profile.hpp", "WriterProfile"),
        (calligraphy.SimulatedDeviceParameters, "devices/simulated_device.hpp", "SimulatedDeviceParameters"),
        (calligraphy.DeviceInfo, "core/device_types.hpp", "DeviceInfo"),
        (calligraphy.DeviceState, "core/device_types.hpp", "DeviceState"),
    ],
)
def test_every_cpp_field_is_bound(cls, header, struct):
    fields = cpp_fields(header, struct)
    assert len(fields) >= 4
    # Lists (a teacher's recording) are properties, not values of to_dict() and the constructor.
    lists = {"teacher_trajectory"}
    assert list(cls().to_dict()) == [f for f in fields if f not in lists]
    for name in fields:
        assert getattr(cls, name).__doc__, f"{struct}.{name} has no documentation"


def test_every_numeric_force_law_field_documents_its_range():
    # The numeric fields' documentation comes from the C++ parameter tables, which also check them: each
    # states the range its value is checked against.
    classes = [calligraphy.ForceLawParameters, calligraphy.FadingGuidance, calligraphy.ReplayGuidance,
               calligraphy.AssistAsNeededGuidance, calligraphy.ErrorAmplificationGuidance,
               calligraphy.TimingGuidance]
    for cls in classes:
        for name, value in cls().to_dict().items():
            if isinstance(value, float):
                doc = getattr(cls, name).__doc__
                assert any(bound in doc for bound in (">= ", "> ", "in [", "in (")), f"{cls.__name__}.{name}: {doc}"


def test_defaults_are_the_cpp_defaults():
    law = calligraphy.ForceLawParameters()
    assert law.guidance_stiffness_n_per_m == 400.0 and law.paper_stiffness_n_per_m == 800.0
    assert law.nearest.method == calligraphy.NearestPointMethod.exact
    novice = calligraphy.WriterProfile.novice()
    assert novice.name == "novice" and novice.hand_stiffness_n_per_m == 150.0
    assert calligraphy.WriterProfile.skilled().hand_stiffness_n_per_m == 600.0


def test_assignment_is_checked_and_keeps_the_old_value():
    law = calligraphy.ForceLawParameters()
    with pytest.raises(ValueError, match="paper_stiffness_n_per_m"):
        law.paper_stiffness_n_per_m = -5.0
    assert law.paper_stiffness_n_per_m == 800.0
    with pytest.raises(TypeError, match="ForceLawParameters.guidance_stiffness_n_per_m"):
        law.guidance_stiffness_n_per_m = "stiff"
    law.guidance_stiffness_n_per_m = 250  # an int is a number
    assert law.guidance_stiffness_n_per_m == 250.0
    # A nested struct is changed in place, and checked by its own rules.
    law.nearest.method = "newton"
    law.nearest.newton_starts = 16
    assert law.nearest.method == calligraphy.NearestPointMethod.newton and law.nearest.newton_starts == 16
    with pytest.raises(ValueError, match="newton_starts"):
        law.nearest.newton_starts = 1001
    with pytest.raises(ValueError, match="method"):
        law.nearest.method = "bisection"


def test_unknown_field_is_a_type_error():
    with pytest.raises(TypeError, match="unknown field 'stiffness'.*guidance_stiffness_n_per_m"):
        calligraphy.ForceLawParameters(stiffness=1.0)


def test_vectors_are_numpy_and_read_only():
    p = calligraphy.SimulatedDeviceParameters(initial_position_m=[0.01, 0.02, 0.03])
    position = p.initial_position_m
    assert position.shape == (3,) and position.dtype == np.float64
    with pytest.raises(ValueError):
        position[0] = 1.0  # a copy: writing to it would change nothing
    with pytest.raises(ValueError, match="initial_position_m"):
        p.initial_position_m = [0.0, 0.0]
    with pytest.raises(ValueError, match="finite"):
        p.initial_position_m = [0.0, np.nan, 0.0]
    np.testing.assert_array_equal(p.initial_position_m, [0.01, 0.02, 0.03])


def test_repr_replace_equality_and_pickle():
    law = calligraphy.ForceLawParameters(guidance=False, friction_coefficient=0.2, nearest={"method": "newton"})
    namespace = {name: getattr(calligraphy, name) for name in calligraphy.__all__}
    assert eval(repr(law), namespace) == law
    assert pickle.loads(pickle.dumps(law)) == law
    other = law.replace(friction_coefficient=0.3)
    assert other != law and other.friction_coefficient == 0.3 and law.friction_coefficient == 0.2
    assert other.replace(friction_coefficient=0.2) == law
    writer = calligraphy.WriterProfile.novice().replace(name="slow", writing_speed_m_s=0.01)
    assert pickle.loads(pickle.dumps(writer)) == writer
    with pytest.raises(TypeError):
        hash(law)


def test_writer_profile_checks_every_value():
    with pytest.raises(ValueError, match="tremor_frequency_hz"):
        calligraphy.WriterProfile(tremor_frequency_hz=float("nan"))
    with pytest.raises(ValueError, match="bias_offset_m"):
        calligraphy.WriterProfile(bias_offset_m=float("inf"))
    with pytest.raises(ValueError, match="max_attempts_per_stroke"):
        calligraphy.WriterProfile(max_attempts_per_stroke=0)


def test_interaction_state_is_an_enum_equal_to_its_int():
    states = calligraphy.InteractionState
    assert [s.short_name for s in states.__members__.values()] == ["SS", "AS", "CS", "WS"]
    assert states.writing == 3 and states(3) == states.writing
    stored = np.array([0, 3, 2, 3], dtype=np.uint8)
    np.testing.assert_array_equal(stored == states.writing, [False, True, False, True])
    assert states.writing != states.calibration and states.writing != "WS"


def test_guidance_law_is_one_class_per_mode_with_its_own_parameters():
    law = calligraphy.ForceLawParameters()
    assert law.guidance_law == calligraphy.FixedGuidance()
    assert law.guidance_mode == calligraphy.GuidanceMode.fixed
    law.guidance_law = calligraphy.AssistAsNeededGuidance(band_m=0.002)
    assert law.guidance_mode == calligraphy.GuidanceMode.assist_as_needed
    assert law.guidance_law.band_m == 0.002
    assert law.to_dict()["guidance_law"] == {"law": "AssistAsNeededGuidance", "band_m": 0.002}
    namespace = {name: getattr(calligraphy, name) for name in calligraphy.__all__}
    assert eval(repr(law), namespace) == law
    assert pickle.loads(pickle.dumps(law)) == law
    assert calligraphy.ForceLawParameters(guidance_law={"law": "FadingGuidance", "gain": 0.5}).guidance_law == \
        calligraphy.FadingGuidance(gain=0.5)
    classes = {"fixed": "FixedGuidance", "fading": "FadingGuidance", "replay": "ReplayGuidance",
               "assist_as_needed": "AssistAsNeededGuidance", "error_amplification": "ErrorAmplificationGuidance",
               "timing": "TimingGuidance"}
    for name, mode in calligraphy.GuidanceMode.__members__.items():
        assert type(calligraphy.default_guidance_law(mode)).__name__ == classes[name]
    # Each law checks its own fields, naming them; the force law checks a moving target's lead against R_res.
    with pytest.raises(ValueError, match="FadingGuidance.gain"):
        calligraphy.FadingGuidance(gain=1.5)
    with pytest.raises(ValueError, match="ErrorAmplificationGuidance.max_force_n"):
        calligraphy.ErrorAmplificationGuidance(max_force_n=-1.0)
    with pytest.raises(ValueError, match="TimingGuidance.max_lead_m"):
        calligraphy.ForceLawParameters(guidance_law=calligraphy.TimingGuidance(max_lead_m=0.01))
    with pytest.raises(TypeError, match="ForceLawParameters.guidance_law"):
        law.guidance_law = 0.5
    assert law.guidance_law.band_m == 0.002  # unchanged by the refused assignment
    replay = calligraphy.ReplayGuidance(max_lead_m=0.002)
    replay.teacher_trajectory = [calligraphy.TeacherSample(time_s=0.0, position_m=[0.0, 0.0, 0.0]),
                                 calligraphy.TeacherSample(time_s=1.0, position_m=[0.01, 0.0, 0.0])]
    assert len(replay.teacher_trajectory) == 2
    with pytest.raises(ValueError, match="teacher trajectory"):
        calligraphy.ForceLawParameters(guidance_law=calligraphy.ReplayGuidance())
