"""Integer arguments of every public function, constructor and method (docs/python.md, "Arguments"): an int
too large for C++ (2**70, 2**64) or negative where it must not be (-1) raises TypeError, ValueError
(InvalidArgument), OverflowError or IndexError naming the argument and its range, never pybind11's
"incompatible function arguments" or "Unable to cast Python instance to C++ type".

The integer arguments are found in the module's signatures (pybind11 writes them into each docstring), so
a new function or keyword with an int argument fails `test_every_integer_argument_has_a_case` until a case
is added to CASES below.
"""

import importlib.util
import inspect
import pathlib
import re

import pytest

import calligraphy
from calligraphy import _calligraphy as native

HOSTILE_VALUES = [2**70, -1, 2**64]

# The stub generator's splitter of a signature's parameter list (commas outside brackets and quotes).
_STUBS = pathlib.Path(__file__).resolve().parents[2] / "bindings" / "python" / "make_stubs.py"
_spec = importlib.util.spec_from_file_location("make_stubs", _STUBS)
make_stubs = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(make_stubs)
ACCEPTED_ERRORS = (TypeError, ValueError, OverflowError, IndexError)


def signatures(doc, name):
    """Every signature line `name(...) -> ...` of a pybind11 docstring (one per overload)."""
    found = []
    for line in (doc or "").splitlines():
        line = re.sub(r"^\d+\. ", "", line.strip())
        if not line.startswith(name + "("):
            continue
        depth, end = 0, None
        for i, ch in enumerate(line[len(name):], start=len(name)):
            depth += ch == "("
            depth -= ch == ")"
            if depth == 0:
                end = i
                break
        found.append(line[len(name) + 1:end])
    return found


def integer_parameters(doc, name):
    """Names of the parameters annotated `int`, or a Union/Optional holding int."""
    names = []
    for signature in signatures(doc, name):
        for parameter in make_stubs.split_top_level(signature):
            match = re.match(r"^(\w+)\s*:\s*([^=]+?)\s*(=.*)?$", parameter)
            if match and re.search(r"(?<![\w.])int(?![\w.])", match.group(2)):
                names.append(match.group(1))
    return names


def is_enum(cls):
    return hasattr(cls, "__members__") and hasattr(cls, "value")


def discovered():
    """{"function.argument" or "Class.argument": ...} over the public API, pybind11's enum and pickling
    methods left out (their int is the enum's value, not an argument of this library)."""
    found = set()
    for name in dir(native):
        if name.startswith("_"):
            continue
        item = getattr(native, name)
        if inspect.isclass(item):
            if is_enum(item):
                continue
            for attribute in ["__init__", *[a for a in vars(item) if not a.startswith("_")]]:
                member = getattr(item, attribute, None)
                if not callable(member) or isinstance(member, type):
                    continue
                owner = name if attribute == "__init__" else f"{name}.{attribute}"
                for parameter in integer_parameters(getattr(member, "__doc__", ""), attribute):
                    found.add(f"{owner}.{parameter}")
        elif callable(item):
            for parameter in integer_parameters(item.__doc__, name):
                found.add(f"{name}.{parameter}")
    return found


@pytest.fixture(scope="module")
def scene():
    return calligraphy.Scene("永")


def cases(scene):
    """{"owner.argument": call(value)}: a valid call with `value` as that argument."""
    c = calligraphy
    path = c.person_trace(scene, 0, 0, "human")
    line = [[0.0, 0.0], [1.0, 1.0]]
    return {
        "match_stroke.character_index": lambda v: c.match_stroke(scene, v, 0, path),
        "match_stroke.stroke_index": lambda v: c.match_stroke(scene, 0, v, path),
        "trace_applies.character_index": lambda v: c.trace_applies(scene, v, 0, "human"),
        "trace_applies.stroke_index": lambda v: c.trace_applies(scene, 0, v, "human"),
        "person_trace.character_index": lambda v: c.person_trace(scene, v, 0, "human"),
        "person_trace.stroke_index": lambda v: c.person_trace(scene, 0, v, "human"),
        "person_trace.seed": lambda v: c.person_trace(scene, 0, 0, "human", v),
        "nearest_point.newton_starts": lambda v: c.nearest_point(line, [0, 0], newton_starts=v),
        "nearest_point.newton_iterations": lambda v: c.nearest_point(line, [0, 0], newton_iterations=v),
        "simulate_trial.seed": lambda v: c.simulate_trial("一", seed=v),
        "run_trial.seed": lambda v: c.run_trial("一", seed=v),
        "set_log_level.level": lambda v: c.set_log_level(v),
        "typical_stroke.key": lambda v: c.typical_stroke(v),
        "NearestPointOptions.newton_starts": lambda v: c.NearestPointOptions(newton_starts=v),
        "NearestPointOptions.newton_iterations": lambda v: c.NearestPointOptions(newton_iterations=v),
        "DeviceState.buttons": lambda v: c.DeviceState(buttons=v),
        "RepetitionOutcome.out_of_order_attempts": lambda v: c.RepetitionOutcome(out_of_order_attempts=v),
        "RepetitionOutcome.refused_out_of_order": lambda v: c.RepetitionOutcome(refused_out_of_order=v),
        "RepetitionOutcome.backwards_attempts": lambda v: c.RepetitionOutcome(backwards_attempts=v),
        "RepetitionOutcome.refused_backwards": lambda v: c.RepetitionOutcome(refused_backwards=v),
        "SimulatedDeviceParameters.physics_substeps": lambda v: c.SimulatedDeviceParameters(physics_substeps=v),
        "WriterProfile.max_attempts_per_stroke": lambda v: c.WriterProfile(max_attempts_per_stroke=v),
        "StrokeAcceptance.hint_after_misses": lambda v: c.StrokeAcceptance(hint_after_misses=v),
        "StrokeAcceptance.assist_after_misses": lambda v: c.StrokeAcceptance(assist_after_misses=v),
        "simulate_trial.hint_after_misses": lambda v: c.simulate_trial("一", hint_after_misses=v),
        "simulate_trial.assist_after_misses": lambda v: c.simulate_trial("一", assist_after_misses=v),
        "run_trial.hint_after_misses": lambda v: c.run_trial("一", hint_after_misses=v),
        "run_trial.assist_after_misses": lambda v: c.run_trial("一", assist_after_misses=v),
    }


def test_the_signatures_are_read():
    # The reader itself: a few arguments every version of the module has.
    found = discovered()
    for known in ("person_trace.seed", "match_stroke.stroke_index", "DeviceState.buttons"):
        assert known in found


def test_every_integer_argument_has_a_case(scene):
    missing = discovered() - set(cases(scene))
    assert not missing, f"integer arguments without a case in CASES: {sorted(missing)}"


def assert_refused(call, argument, value):
    with pytest.raises(ACCEPTED_ERRORS) as raised:
        call(value)
    message = str(raised.value)
    assert argument in message, f"{argument}={value}: the message does not name it: {message!r}"
    assert re.search(r"-?\d+\s*\.\.\s*-?\d+|\[\s*-?\d+\s*,\s*-?\d+\s*\]", message), (
        f"{argument}={value}: the message names no range: {message!r}"
    )
    assert "incompatible function arguments" not in message and "Unable to cast" not in message


@pytest.mark.parametrize("value", HOSTILE_VALUES, ids=["2**70", "-1", "2**64"])
def test_hostile_integers_are_refused_naming_the_argument_and_its_range(scene, value):
    for key, call in cases(scene).items():
        assert_refused(call, key.rsplit(".", 1)[1], value)


def test_attribute_assignment_is_checked_as_the_constructor(scene):
    for key in cases(scene):
        owner, argument = key.rsplit(".", 1)
        cls = getattr(calligraphy, owner, None)
        if not inspect.isclass(cls):
            continue
        instance = cls()
        for value in HOSTILE_VALUES:
            assert_refused(lambda v: setattr(instance, argument, v), argument, value)


def test_the_largest_valid_seed_is_taken(scene):
    first = calligraphy.person_trace(scene, 0, 0, "human", 2**64 - 1)
    again = calligraphy.person_trace(scene, 0, 0, "human", 2**64 - 1)
    assert (first == again).all()


def test_an_index_past_the_end_names_the_valid_range(scene):
    with pytest.raises(IndexError, match=r"stroke_index: 5 is not in 0\.\.4"):
        calligraphy.person_trace(scene, 0, 5, "human")
    with pytest.raises(IndexError, match=r"character_index: 1180591620717411303424 is not in 0\.\.0"):
        calligraphy.person_trace(scene, 2**70, 0, "human")


def test_an_enum_instance_that_is_no_member_is_refused(scene):
    # pybind11's enums take any int in their constructor; the functions refuse what is no member.
    with pytest.raises(ValueError, match=r"kind: .* is not a member of TraceKind"):
        calligraphy.person_trace(scene, 0, 0, calligraphy.TraceKind(-1))
