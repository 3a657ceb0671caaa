"""A protocol's numbers against Python's classes of the same fields: where a protocol's value becomes a field
Python binds (a quiz's stroke acceptance, a guidance law's gain, band, force or speed, the guidance stiffness),
`calligraphy schema protocol` states the range Python's class checks, and a value just past a bound is refused by
both (Python: ValueError naming the field), a value at a closed bound accepted by both."""

import json
import math
import subprocess

import pytest

import calligraphy


@pytest.fixture(scope="module")
def protocol_schema(cli):
    result = subprocess.run([cli, "schema", "protocol"], capture_output=True, check=True, timeout=60)
    return json.loads(result.stdout)


def _parameters(schema, mode):
    for rule in schema["$defs"]["StudyCondition"]["allOf"]:
        if rule["if"]["properties"]["mode"]["const"] == mode:
            return rule["then"]["properties"]["parameters"]["properties"]
    raise AssertionError(mode)


def _pairs(schema):
    """(protocol property, Python class, its field) for every protocol number a Python class also takes."""
    acceptance = schema["$defs"]["QuizOptions"]["properties"]["acceptance"]["properties"]
    pairs = [(prop, calligraphy.StrokeAcceptance, key) for key, prop in acceptance.items()]
    stiffness = schema["$defs"]["StudyCondition"]["properties"]["guidance_stiffness_n_per_m"]
    pairs.append((stiffness, calligraphy.ForceLawParameters, "guidance_stiffness_n_per_m"))
    pairs.append((_parameters(schema, "fading")["start_gain"], calligraphy.FadingGuidance, "gain"))
    pairs.append((_parameters(schema, "assist-as-needed")["start_band_m"], calligraphy.AssistAsNeededGuidance,
                  "band_m"))
    amplification = _parameters(schema, "error-amplification")
    pairs.append((amplification["amplification_gain"], calligraphy.ErrorAmplificationGuidance, "gain"))
    pairs.append((amplification["max_force_n"], calligraphy.ErrorAmplificationGuidance, "max_force_n"))
    pairs.append((_parameters(schema, "timing")["speed_m_s"], calligraphy.TimingGuidance, "speed_m_s"))
    return pairs


def _past(prop):
    if prop.get("type") == "integer":  # a count: the next whole number past each bound
        return [prop[bound] + step for bound, step in (("minimum", -1), ("maximum", 1)) if bound in prop]
    out = []
    if "minimum" in prop:
        out.append(math.nextafter(prop["minimum"], -math.inf))
    if "exclusiveMinimum" in prop:
        out.append(prop["exclusiveMinimum"])
    if "maximum" in prop:
        out.append(math.nextafter(prop["maximum"], math.inf))
    if "exclusiveMaximum" in prop:
        out.append(prop["exclusiveMaximum"])
    return out


def test_a_protocol_number_python_also_takes_has_python_s_range(protocol_schema):
    pairs = _pairs(protocol_schema)
    assert len(pairs) >= 20
    refused = accepted = 0
    for prop, cls, field in pairs:
        for value in _past(prop):
            with pytest.raises(ValueError, match=field):
                cls(**{field: value})
            refused += 1
        for bound in ("minimum", "maximum"):
            if bound not in prop:
                continue
            made = cls(**{field: prop[bound]})
            assert getattr(made, field) == prop[bound]
            accepted += 1
    assert refused >= 40
    assert accepted >= 20
