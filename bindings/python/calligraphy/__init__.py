"""calligraphy: haptic training of Chinese handwriting (Wang, Zhang & Yao, Virtual Reality 2006).

Python bindings of the C++20 library. Units are SI everywhere: lengths in m, forces in N, time in s,
stiffness in N/m, damping in N s/m. Character data (control points of a Character's elements) stays
in hanzi-writer-data's 1024 box, y up.

Main entry points:

* ``CharacterLibrary.default()`` / ``CharacterLibrary.from_hanzi_writer(path)`` and ``.load(char)``
* ``TYPICAL_STROKES``: the 39 typical strokes (dicts: id, acronym, name, pinyin, unicode, ...)
* ``nearest_point(element, point, method="exact")``: one point (2,) or many (N, 2)
* ``ForceLaw(...)``: paper_force, attraction_force, resistance_force, clamp
* ``simulate_trial(chars, writer="novice", guidance=True, rate_hz=1000, seed=0)`` -> ``TrialResult``
* ``SimulatedDevice``: read_state, write_force, advance

Errors: ``CharacterNotFoundError`` (a KeyError), ``InvalidArgumentError`` (a ValueError),
``DataError`` and ``DeviceError`` (RuntimeErrors), all subclasses of ``CalligraphyError``.
"""

from ._calligraphy import (  # noqa: F401
    ADJUSTING,
    CALIBRATION,
    SEPARATION,
    STATE_NAMES,
    TYPICAL_STROKES,
    WRITING,
    CalligraphyError,
    Character,
    CharacterLibrary,
    CharacterNotFoundError,
    DataError,
    DeviceError,
    DeviceState,
    ForceLaw,
    InvalidArgumentError,
    SimulatedDevice,
    Stroke,
    StrokeElement,
    TrialResult,
    nearest_point,
    simulate_trial,
)

__all__ = [
    "ADJUSTING",
    "CALIBRATION",
    "SEPARATION",
    "STATE_NAMES",
    "TYPICAL_STROKES",
    "WRITING",
    "CalligraphyError",
    "Character",
    "CharacterLibrary",
    "CharacterNotFoundError",
    "DataError",
    "DeviceError",
    "DeviceState",
    "ForceLaw",
    "InvalidArgumentError",
    "SimulatedDevice",
    "Stroke",
    "StrokeElement",
    "TrialResult",
    "nearest_point",
    "simulate_trial",
]
