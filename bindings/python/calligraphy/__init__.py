"""calligraphy: haptic training of Chinese handwriting (Wang, Zhang & Yao, Virtual Reality 2006).

Python bindings of the C++20 library, its types bound directly. Units are SI everywhere and named in
every field and argument: lengths in m, forces in N, time in s, stiffness in N/m, damping in N s/m.
Character data (control points of a Character's elements) stays in hanzi-writer-data's 1024 box, y up.

Main entry points:

* ``CharacterLibrary.default()``, ``.from_hanzi_writer(folder)``, ``.from_store(path)``; ``.load(char)``
* ``typical_stroke("HZG")`` / ``typical_stroke(10)`` and ``TYPICAL_STROKES``: the 39 typical strokes
* ``Scene(chars)``: characters placed on the paper in metres; ``Placement.to_paper`` / ``to_data``
* ``nearest_point(element, point, method="exact")``: one point (2,) or many (N, 2)
* ``match_stroke(scene, character_index, stroke_index, path_m)`` -> ``StrokeMatch`` (accepted,
  ``StrokeRefusal``): the renderer's verdict on one pen-down path (N, 2) [m];
  ``person_trace(scene, character_index, stroke_index, kind, seed)``: a labelled path (``TraceKind``)
* ``ForceLawParameters(...)`` and the force law: ``paper_force``, ``attraction_force``,
  ``resistance_force``, ``friction_force``, ``constraint_taper``, ``clamp_force``
* ``Renderer(scene, force_law).tick(DeviceState(...))`` -> ``RenderOutput``
* ``simulate_trial(chars, writer="novice", guidance=True, rate_hz=1000, seed=0)`` -> ``TrialResult``
  (``.to_dataframe()``, ``.per_stroke_dataframe()`` with pandas; ``calligraphy.plot`` with matplotlib);
  ``rerun_trial(result.metrics)`` (or a trial record, or its file) runs it again, bit for bit
* ``calligraphy.experiments.sweep(chars, grid, seeds)``: one trial per grid combination x character x
  seed on every core or a Dask cluster -> a pandas DataFrame, one row per trial
* ``SimulatedDevice(SimulatedDeviceParameters(...))``, ``WriterProfile``, ``list_devices()``
* guidance modes: ``simulate_trial(..., guidance_mode="fading", guidance_gain=g)``, or a law with its
  parameters: ``ForceLawParameters(guidance_law=AssistAsNeededGuidance(band_m=0.002))`` (one class per mode),
  ``next_guidance_gain(g, error_m)``; ``record_teacher(result)`` -> ``TeacherRecording`` for
  ``simulate_trial(..., teacher=recording)`` (replay)
* writers: ``writer="foreign"``, ``writer_params={"key": value}``, ``writer_profile(name, params)``;
  learning: ``next_repetition_profile(result.writer, RepetitionOutcome.from_log(result.writer_log, share))``
* ``set_log_level(level)``: the C++ log goes to ``logging.getLogger("calligraphy")``

Errors carry the C++ class names: ``Error`` (the base), ``InvalidArgument`` (a ValueError),
``DataError`` (a RuntimeError), ``CharacterNotFound`` (a KeyError and a DataError), ``DeviceError``
(a RuntimeError) with ``DeviceNotFound`` (a LookupError), ``DeviceUnavailable`` (a known device that cannot
be used now: its backend's reason), ``CommunicationError`` (a ConnectionError), ``SafetyFault`` and
``CalibrationNeeded``. An argument of the wrong type raises TypeError naming it.
The statistics and the study page are the subpackage ``calligraphy.stats`` (``study``, ``statistics``,
``mixed_models``, ``design_models``, ``design_analysis``, ``crossover_analysis``, ``study_report``); their
old paths ``calligraphy.statistics`` and so on are the same modules. See docs/python.md.
"""

import typing as _typing

# numpy is imported here, not first inside a call that returns an array: an import that a Ctrl-C interrupts
# half way leaves a module without its names for the rest of the process.
import numpy as _numpy  # noqa: F401

from ._calligraphy import (  # noqa: F401
    __version__,
    TYPICAL_STROKES,
    CalibrationNeeded,
    RealtimeError,
    StateError,
    Character,
    CharacterLibrary,
    CharacterNotFound,
    CommunicationError,
    DataError,
    DeviceError,
    DeviceInfo,
    DeviceListing,
    DeviceNotFound,
    DeviceUnavailable,
    DeviceState,
    DeviceSurvey,
    Error,
    ForceLawParameters,
    InteractionState,
    GuidanceMode,
    FixedGuidance,
    FadingGuidance,
    ReplayGuidance,
    AssistAsNeededGuidance,
    ErrorAmplificationGuidance,
    TimingGuidance,
    default_guidance_law,
    TeacherSample,
    InvalidArgument,
    NearestPointMethod,
    NearestPointOptions,
    PassivityParameters,
    PlacedCharacter,
    PlacedStroke,
    Placement,
    RenderOutput,
    Renderer,
    RendererOptions,
    SafetyChainParameters,
    SafetyFault,
    Scene,
    SceneLayout,
    SimulatedDevice,
    SimulatedDeviceParameters,
    Stroke,
    StrokeAcceptance,
    StrokeElement,
    StrokeMatch,
    StrokeRefusal,
    StrokePieceTemplate,
    TrialResult,
    TraceKind,
    TypicalStroke,
    WriterProfile,
    attraction_force,
    clamp_force,
    constraint_taper,
    flush_log,
    friction_force,
    is_positive,
    list_devices,
    match_stroke,
    nearest_point,
    paper_force,
    person_trace,
    resistance_force,
    set_log_level,
    run_trial,
    score,
    simulate_trial,
    rerun_trial,
    check_trial_record,
    trace_applies,
    metric_table,
    trace_columns,
    typical_stroke,
    AttemptEnd,
    FadingRule,
    AssistBandRule,
    SkillAdaptiveRule,
    RepetitionOutcome,
    TeacherRecording,
    WriterAttempt,
    WriterLog,
    next_guidance_gain,
    next_assist_band,
    skill_adaptive_mode,
    next_repetition_profile,
    record_teacher,
    writer_parameter_names,
    writer_profile,
)

__all__ = [
    "__version__",
    "TYPICAL_STROKES",
    "CalibrationNeeded",
    "RealtimeError",
    "StateError",
    "Character",
    "CharacterLibrary",
    "CharacterNotFound",
    "CommunicationError",
    "DataError",
    "DeviceError",
    "DeviceInfo",
    "DeviceListing",
    "DeviceNotFound",
    "DeviceUnavailable",
    "DeviceState",
    "DeviceSurvey",
    "Error",
    "ForceLawParameters",
    "InteractionState",
    "GuidanceMode",
    "FixedGuidance",
    "FadingGuidance",
    "ReplayGuidance",
    "AssistAsNeededGuidance",
    "ErrorAmplificationGuidance",
    "TimingGuidance",
    "default_guidance_law",
    "TeacherSample",
    "InvalidArgument",
    "NearestPointMethod",
    "NearestPointOptions",
    "PassivityParameters",
    "PlacedCharacter",
    "PlacedStroke",
    "Placement",
    "RenderOutput",
    "Renderer",
    "RendererOptions",
    "SafetyChainParameters",
    "SafetyFault",
    "Scene",
    "SceneLayout",
    "SimulatedDevice",
    "SimulatedDeviceParameters",
    "Stroke",
    "StrokeAcceptance",
    "StrokeElement",
    "StrokeMatch",
    "StrokeRefusal",
    "StrokePieceTemplate",
    "TrialResult",
    "TraceKind",
    "TypicalStroke",
    "WriterProfile",
    "attraction_force",
    "clamp_force",
    "constraint_taper",
    "flush_log",
    "friction_force",
    "is_positive",
    "list_devices",
    "match_stroke",
    "nearest_point",
    "paper_force",
    "person_trace",
    "resistance_force",
    "set_log_level",
    "run_trial",
    "score",
    "simulate_trial",
    "rerun_trial",
    "check_trial_record",
    "trace_applies",
    "metric_table",
    "trace_columns",
    "typical_stroke",
    "AttemptEnd",
    "FadingRule",
    "AssistBandRule",
    "SkillAdaptiveRule",
    "RepetitionOutcome",
    "TeacherRecording",
    "WriterAttempt",
    "WriterLog",
    "next_guidance_gain",
    "next_assist_band",
    "skill_adaptive_mode",
    "next_repetition_profile",
    "record_teacher",
    "writer_parameter_names",
    "writer_profile",
]

# The modules that moved to calligraphy.stats stay attributes of the package, as they were once imported:
# `calligraphy.statistics` is calligraphy.stats.statistics, imported when first asked for. Hidden from type
# checkers, for which a module-level __getattr__ would make every unknown name of the package valid.
_STATS_MODULES = frozenset({"statistics", "mixed_models", "design_models", "design_analysis", "crossover_analysis",
                            "study", "study_report"})

if not _typing.TYPE_CHECKING:
    def __getattr__(name):
        if name in _STATS_MODULES:
            import importlib

            return importlib.import_module(f"{__name__}.{name}")
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
