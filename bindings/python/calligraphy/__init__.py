"""calligraphy: haptic training of Chinese handwriting (Wang, Zhang & Yao, Virtual Reality 2006).

Python bindings of the C++20 library. Units are SI everywhere: lengths in m, forces in N, time in s,
stiffness in N/m, damping in N s/m. Character data (control points of a Character's elements) stays
in hanzi-writer-data's 1024 box, y up.

Main entry points:

* ``CharacterLibrary.default()`` / ``CharacterLibrary.from_hanzi_writer(path)`` and ``.load(char)``
* ``TYPICAL_STROKES``: the 39 typical strokes
* ``nearest_point(element, point, method="exact")``: one point (2,) or many (N, 2)
* ``ForceLawParameters(...)`` and the force law: ``paper_force``, ``attraction_force``,
  ``resistance_force``, ``friction_force``, ``constraint_taper``, ``clamp_force``
* ``simulate_trial(chars, writer="novice", guidance=True, rate_hz=1000, seed=0)`` -> ``TrialResult``
* ``SimulatedDevice(SimulatedDeviceParameters(...))``: read_state, write_force, advance
* ``list_devices()``: the device registry

Errors carry the C++ class names: ``Error`` (the base), ``InvalidArgument`` (a ValueError),
``DataError`` (a RuntimeError), ``CharacterNotFound`` (a KeyError and a DataError), ``DeviceError``
(a RuntimeError) with ``DeviceNotFound`` (a LookupError), ``CommunicationError`` (a ConnectionError),
``SafetyFault`` and ``CalibrationNeeded``.
"""

from ._calligraphy import (  # noqa: F401
    TYPICAL_STROKES,
    CalibrationNeeded,
    Character,
    CharacterLibrary,
    CharacterNotFound,
    CommunicationError,
    DataError,
    DeviceError,
    DeviceInfo,
    DeviceListing,
    DeviceNotFound,
    DeviceState,
    DeviceSurvey,
    Error,
    ForceLawParameters,
    InteractionState,
    InvalidArgument,
    NearestPointMethod,
    NearestPointOptions,
    SafetyFault,
    SimulatedDevice,
    SimulatedDeviceParameters,
    Stroke,
    StrokeElement,
    TrialResult,
    WriterProfile,
    attraction_force,
    clamp_force,
    constraint_taper,
    friction_force,
    list_devices,
    nearest_point,
    paper_force,
    resistance_force,
    simulate_trial,
)

__all__ = [
    "TYPICAL_STROKES",
    "CalibrationNeeded",
    "Character",
    "CharacterLibrary",
    "CharacterNotFound",
    "CommunicationError",
    "DataError",
    "DeviceError",
    "DeviceInfo",
    "DeviceListing",
    "DeviceNotFound",
    "DeviceState",
    "DeviceSurvey",
    "Error",
    "ForceLawParameters",
    "InteractionState",
    "InvalidArgument",
    "NearestPointMethod",
    "NearestPointOptions",
    "SafetyFault",
    "SimulatedDevice",
    "SimulatedDeviceParameters",
    "Stroke",
    "StrokeElement",
    "TrialResult",
    "WriterProfile",
    "attraction_force",
    "clamp_force",
    "constraint_taper",
    "friction_force",
    "list_devices",
    "nearest_point",
    "paper_force",
    "resistance_force",
    "simulate_trial",
]
