#!/usr/bin/env python3
"""Round 15E: every documented error of the Python module, written from docs/python.md and the module's
docstrings (`help()`) alone. Run by CTest as `cli_unseen_round15e_tests`; the C++ half of the round is
tests/unseen_round15e_test.cpp (`[unseen15e]`).

Every exception class docs/python.md's "Errors" section lists exists under its name with the bases it states,
and the C++ classes of include/calligraphy/core/errors.hpp each have their Python class; every name of
`__all__` that can have a docstring has one saying more than its signature; `help(calligraphy)` renders and
shows every such name; the type names in the signatures resolve to the module's classes (no C++ type left
unbound); every exception a docstring says a call raises is one the module or Python has; arrays' shapes are
stated where arrays are taken. Then each documented raise is provoked and held to its type and to what its
message is documented to name: typical strokes, trace kinds, log levels, writers, character libraries,
stroke matching's indices and paths, the guidance rules, simulated and real trials, records and teachers.

CALLIGRAPHY_SANITIZED=1 takes five cases.
"""
import builtins
import inspect
import json
import os
import pydoc
import re
import tempfile
import unittest
from pathlib import Path

import numpy as np

import calligraphy as cg
from outsider import sanitized_subset

SOURCE = Path(os.environ.get("CALLIGRAPHY_SOURCE_DIR", Path(__file__).resolve().parents[2]))
PYTHON_MD = (SOURCE / "docs" / "python.md").read_text(encoding="utf-8")
ERRORS_HPP = (SOURCE / "include" / "calligraphy" / "core" / "errors.hpp").read_text(encoding="utf-8")

# docs/python.md, "Errors": each class and the Python classes it is also a subclass of.
DOCUMENTED_BASES = {
    "Error": (Exception,),
    "InvalidArgument": (ValueError,),
    "DataError": (RuntimeError,),
    "CharacterNotFound": (KeyError, "DataError"),
    "DeviceError": (RuntimeError,),
    "DeviceNotFound": (LookupError, "DeviceError"),
    "DeviceUnavailable": ("DeviceError",),
    "CommunicationError": (ConnectionError, "DeviceError"),
    "SafetyFault": ("DeviceError",),
    "CalibrationNeeded": ("DeviceError",),
    "RealtimeError": ("DeviceError",),
    "StateError": (RuntimeError,),
}
# docs/python.md: the C++ classes Python raises as their base, not under their own name.
RAISED_AS_BASE = {"InputError": "DataError"}


def public_callables():
    """(name, object) of every class and function of `__all__` (the constants have no docstring of their own)."""
    return [(n, getattr(cg, n)) for n in cg.__all__ if inspect.isclass(getattr(cg, n)) or callable(getattr(cg, n))]


def signatures(obj):
    """The signature lines pybind11 put at the head of a docstring (one per overload)."""
    doc = getattr(obj, "__doc__", None) or ""
    return [line for line in doc.splitlines() if re.match(r"^\s*(\d+\.\s*)?\w+\(.*\)\s*(->.*)?$", line)]


def own_text(obj):
    """The docstring of `obj` (a property's own) without pybind11's signature lines."""
    doc = (obj.__doc__ if isinstance(obj, property) else getattr(obj, "__doc__", None)) or ""
    sig = signatures(obj.fget if isinstance(obj, property) and obj.fget else obj)
    return "\n".join(line for line in doc.splitlines() if line not in sig).strip()


def members(cls):
    """The public methods and properties of a pybind11 class, as (name, object)."""
    out = []
    for name, value in vars(cls).items():
        if name.startswith("_") and name != "__init__":
            continue
        if isinstance(value, property) or callable(value) or type(value).__name__ == "instancemethod":
            out.append((name, value))
    return out


class Round15E(unittest.TestCase):
    def raised(self, exc_type, call, *needles):
        """`call()` raises exactly `exc_type` (not a subclass, not a base) with each of `needles` in its message."""
        with self.assertRaises(BaseException) as caught:
            call()
        self.assertIs(type(caught.exception), exc_type, f"{type(caught.exception).__name__}: {caught.exception}")
        text = str(caught.exception)
        for needle in needles:
            self.assertIn(needle, text)
        return text

    # ------------------------------------------------------------------ the classes and the docstrings

    def test_every_documented_exception_class_has_its_bases(self):
        for name, bases in DOCUMENTED_BASES.items():
            with self.subTest(name=name):
                cls = getattr(cg, name)
                self.assertTrue(issubclass(cls, BaseException))
                self.assertTrue(issubclass(cls, cg.Error))
                for base in bases:
                    self.assertTrue(issubclass(cls, getattr(cg, base) if isinstance(base, str) else base), base)
                self.assertIn(name, cg.__all__)
                self.assertTrue((cls.__doc__ or "").strip(), name)

    def test_every_cpp_exception_class_is_a_python_class_of_its_name(self):
        # docs/python.md: every C++ class of errors.hpp is a Python exception of its name, or documented as raised
        # as its base.
        cpp = re.findall(r"^class (\w+) : public ([\w:]+)", ERRORS_HPP, re.M)
        self.assertGreaterEqual(len(cpp), 10)
        for name, base in cpp:
            with self.subTest(name=name):
                if name in RAISED_AS_BASE:
                    self.assertFalse(hasattr(cg, name))
                    self.assertRegex(PYTHON_MD, rf"`{name}`[^|]*raises as\s+its base `{RAISED_AS_BASE[name]}`")
                    continue
                self.assertTrue(hasattr(cg, name), f"calligraphy.{name} (errors.hpp) is missing")
                cls = getattr(cg, name)
                self.assertIn(name, cg.__all__)
                if base != "std::runtime_error":
                    self.assertTrue(issubclass(cls, getattr(cg, base)), f"{name} is not a {base}")
                # docs/python.md's table lists every class but the base's own row.
                self.assertRegex(PYTHON_MD, rf"`{name}`")

    def test_every_public_name_has_a_docstring_beyond_its_signature(self):
        missing = []
        for name, obj in public_callables():
            if not own_text(obj):
                missing.append(name)
            if inspect.isclass(obj) and not issubclass(obj, BaseException) and not hasattr(obj, "__members__"):
                for member, value in members(obj):
                    if member != "__init__" and not own_text(value):
                        missing.append(f"{name}.{member}")
        self.assertEqual(missing, [], "public names without a docstring of their own")

    def test_help_renders_and_shows_every_public_name(self):
        text = pydoc.render_doc(cg, renderer=pydoc.plaintext)
        self.assertGreater(len(text), 10_000)
        for name, _ in public_callables():
            with self.subTest(name=name):
                self.assertRegex(text, rf"\b{re.escape(name)}\b")
        self.assertNotIn("<unknown>", text)

    def test_the_type_names_of_every_signature_exist(self):
        unbound, unknown = [], set()
        known = set(vars(cg)) | set(vars(builtins)) | {"numpy", "os", "typing", "Union", "Optional", "Sequence",
                                                      "Mapping", "Callable", "Iterable", "List", "Dict", "Tuple",
                                                      "Any", "None", "object"}
        objects = list(public_callables())
        for name, obj in list(objects):
            if inspect.isclass(obj):
                objects += [(f"{name}.{m}", v) for m, v in members(obj)]
        for name, obj in objects:
            sig_source = obj.fget if isinstance(obj, property) and obj.fget else obj
            for line in signatures(sig_source):
                if re.search(r"calligraphy::|std::|Eigen::|<[a-z_]+::", line):
                    unbound.append(f"{name}: {line}")
                for dotted in re.findall(r"calligraphy\._calligraphy\.(\w+)", line):
                    if not hasattr(cg, dotted):
                        unknown.add(f"{name}: calligraphy._calligraphy.{dotted}")
                for bare in re.findall(r"(?:\[|: |, |-> )([A-Z]\w+)(?=[\],)\s=]|$)", line):
                    if bare not in known:
                        unknown.add(f"{name}: {bare}")
        self.assertEqual(unbound, [], "C++ types in Python signatures")
        self.assertEqual(sorted(unknown), [], "type names that are no class of the module")

    def test_every_raised_exception_a_docstring_names_exists(self):
        unknown = []
        for name, obj in public_callables():
            docs = [obj.__doc__ or ""]
            if inspect.isclass(obj):
                docs += [getattr(v, "__doc__", "") or "" for _, v in members(obj)]
            for doc in docs:
                for clause in re.findall(r"Raises?\s+([^.;]*)", doc):
                    for word in re.findall(r"\b([A-Z][A-Za-z]*(?:Error|Exception|Argument|NotFound|Fault|Needed|"
                                           r"Unavailable|Interrupt))\b", clause):
                        if not (hasattr(cg, word) or hasattr(builtins, word)):
                            unknown.append(f"{name}: {word}")
        self.assertEqual(unknown, [])

    def test_functions_taking_arrays_state_the_shape_and_units(self):
        for name in ("nearest_point", "match_stroke", "person_trace", "score", "clamp_force", "attraction_force"):
            with self.subTest(name=name):
                doc = getattr(cg, name).__doc__
                self.assertRegex(doc, r"\((?:N|n|\d), ?(?:2|3)\)|shape|1-D", "no array shape stated")
                self.assertRegex(doc, r"\[(?:m|N|s|m/s|N/m)\]|\bmetres\b|\bunits\b", "no unit stated")

    # ------------------------------------------------------------------ each documented raise

    def test_typical_stroke_errors(self):
        self.raised(cg.InvalidArgument, lambda: cg.typical_stroke(40), "key: typical-stroke ID 40 is not in 1..39")
        self.raised(cg.InvalidArgument, lambda: cg.typical_stroke(0), "0")
        self.raised(cg.InvalidArgument, lambda: cg.typical_stroke("NOPE"), "NOPE")
        self.raised(TypeError, lambda: cg.typical_stroke(1.5), "key")
        self.raised(cg.InvalidArgument, lambda: cg.typical_stroke("\ud800"), "key")
        self.assertEqual(cg.typical_stroke("HZG").id, cg.typical_stroke(cg.typical_stroke("HZG").id).id)

    def test_trace_kind_and_log_level_errors(self):
        self.raised(cg.InvalidArgument, lambda: cg.is_positive("no-such-kind"), "no-such-kind")
        self.raised(TypeError, lambda: cg.is_positive(3.5), "kind")
        self.raised(cg.InvalidArgument, lambda: cg.is_positive(cg.TraceKind(-1)), "kind")
        self.raised(cg.InvalidArgument, lambda: cg.set_log_level("loudest"), "loudest")
        self.raised(TypeError, lambda: cg.set_log_level(2.5))
        cg.set_log_level("warning")

    def test_writer_profile_errors(self):
        self.raised(cg.InvalidArgument, lambda: cg.writer_profile("expert"), "expert")
        self.raised(cg.InvalidArgument, lambda: cg.writer_profile("novice", {"bias_m": 1.0}), "bias_m")
        self.raised(cg.InvalidArgument, lambda: cg.writer_profile("novice", {"bias_offset_m": float("nan")}),
                    "bias_offset_m")
        self.raised(TypeError, lambda: cg.writer_profile("novice", {"bias_offset_m": "far"}))
        self.assertIn("bias_offset_m", cg.writer_parameter_names())

    def test_character_library_errors(self):
        library = cg.CharacterLibrary.default()
        text = self.raised(cg.CharacterNotFound, lambda: library.load("\U0001F600"), "U+1F600")
        self.assertIn("\U0001F600", text)
        self.assertIsInstance(cg.CharacterNotFound("x"), KeyError)
        self.raised(cg.InvalidArgument, lambda: library.load("一十"))
        self.raised(TypeError, lambda: library.load(0x4E00))
        with tempfile.TemporaryDirectory() as folder:
            missing = os.path.join(folder, "none")
            self.raised(cg.DataError, lambda: cg.CharacterLibrary.from_hanzi_writer(missing), missing)
            junk = Path(folder) / "junk.clg"
            junk.write_bytes(b"\x5a" * 64)
            self.raised(cg.DataError, lambda: cg.CharacterLibrary.from_store(junk), "junk.clg")
            self.raised(cg.InvalidArgument, lambda: cg.CharacterLibrary.from_hanzi_writer("a\0b"))

    def test_stroke_matching_errors(self):
        scene = cg.Scene("十")
        path = cg.person_trace(scene, 0, 0, "median")
        self.assertEqual(path.ndim, 2)
        self.assertEqual(path.shape[1], 2)
        self.raised(IndexError, lambda: cg.match_stroke(scene, 0, 5, path), "stroke_index")
        self.raised(IndexError, lambda: cg.match_stroke(scene, 1, 0, path), "character_index")
        self.raised(cg.InvalidArgument, lambda: cg.match_stroke(scene, 0, 0, np.zeros((4, 3))), "path_m")
        self.raised(cg.InvalidArgument, lambda: cg.match_stroke(scene, 0, 0, np.zeros((0, 2))), "path_m")
        bad = path.copy()
        bad[1, 0] = np.nan
        self.raised(cg.InvalidArgument, lambda: cg.match_stroke(scene, 0, 0, bad), "path_m")
        self.raised(TypeError, lambda: cg.match_stroke(scene, "0", 0, path), "character_index")
        self.raised(IndexError, lambda: cg.trace_applies(scene, 0, 2, "median"), "stroke_index")
        self.raised(cg.InvalidArgument, lambda: cg.trace_applies(scene, 0, 0, "sideways"), "kind")
        self.raised(cg.InvalidArgument, lambda: cg.person_trace(scene, 0, 0, "median", seed=2**64), "seed")

    def test_guidance_rule_errors(self):
        self.raised(cg.InvalidArgument, lambda: cg.next_guidance_gain(1.5, 0.001), "gain")
        self.raised(cg.InvalidArgument, lambda: cg.next_guidance_gain(0.5, -0.001))
        self.raised(cg.InvalidArgument, lambda: cg.next_guidance_gain(0.5, float("inf")))
        self.raised(TypeError, lambda: cg.next_guidance_gain(0.5, "small"), "error_m")
        self.assertTrue(0.0 <= cg.next_guidance_gain(0.5, 0.001) <= 1.0)

    def test_simulated_trial_errors(self):
        self.raised(cg.CharacterNotFound, lambda: cg.simulate_trial("\U0001F600", max_duration_s=0.05), "U+1F600")
        self.raised(TypeError, lambda: cg.simulate_trial("一", rate_hz="fast", max_duration_s=0.05),
                    "rate_hz: expected float, got str 'fast'")
        self.raised(cg.InvalidArgument, lambda: cg.simulate_trial("一", writer="expert", max_duration_s=0.05),
                    "expert")
        self.raised(cg.InvalidArgument,
                    lambda: cg.simulate_trial("一", writer_params={"no_key": 1.0}, max_duration_s=0.05), "no_key")
        self.raised(cg.InvalidArgument, lambda: cg.simulate_trial("一", seed=2**64, max_duration_s=0.05),
                    "seed: 18446744073709551616 is out of range: expected an int in 0..18446744073709551615")
        self.raised(cg.InvalidArgument, lambda: cg.simulate_trial("一", guidance_mode="replay", max_duration_s=0.05),
                    "teacher")

    def test_real_trial_on_an_unknown_device_names_the_devices_there_are(self):
        text = self.raised(cg.DeviceNotFound, lambda: cg.run_trial("一", device="no-such-arm", max_duration_s=0.05),
                           "no-such-arm")
        self.assertIn("simulated", text)
        self.assertIsInstance(cg.DeviceNotFound("x"), LookupError)

    def test_record_and_teacher_errors(self):
        result = cg.simulate_trial("一", max_duration_s=0.05, keep_trace=False)
        self.raised(cg.InvalidArgument, lambda: cg.record_teacher(result), "trace")
        kept = cg.simulate_trial("一", max_duration_s=0.05)
        with tempfile.TemporaryDirectory() as folder:
            target = os.path.join(folder, "no-folder", "teacher.json")
            with self.assertRaises(cg.Error) as caught:
                cg.record_teacher(kept, target)
            self.assertIn(target, str(caught.exception))
            self.assertFalse(os.path.exists(os.path.dirname(target)))
        self.raised(cg.DataError, lambda: cg.check_trial_record({}), "/")
        with tempfile.TemporaryDirectory() as folder:
            record = Path(folder) / "record.json"
            record.write_text("{}", encoding="utf-8")
            # The C++ InputError of a file's refused content: DataError, naming the file.
            self.raised(cg.DataError, lambda: cg.check_trial_record(record), "record.json")
            self.raised(cg.DataError, lambda: cg.rerun_trial(str(record)), "record.json")
        self.raised(TypeError, lambda: cg.check_trial_record(42))
        self.raised(TypeError, lambda: cg.rerun_trial(json.dumps({"format": "calligraphy-trial"})))

    def test_a_lone_surrogate_is_a_value_error_naming_the_argument_wherever_a_str_is_taken(self):
        # docs/python.md: a str UTF-8 cannot encode is InvalidArgument naming the argument, not a TypeError.
        columns = {"t": [0.0, 1.0], "x": [0.0, 0.0], "y": [0.0, 0.0], "pen": [1, 1]}
        calls = {
            "key": lambda: cg.typical_stroke("\ud800"),
            "level": lambda: cg.set_log_level("\ud800"),
            "writer": lambda: cg.writer_profile("\ud800"),
            "writer_params key": lambda: cg.writer_profile("novice", {"\ud800": 1.0}),
            "units": lambda: cg.score(columns, "一", units="\ud800"),
            "characters": lambda: cg.Scene("\ud800"),
            "record": lambda: cg.rerun_trial("\ud800"),
            "record key": lambda: cg.check_trial_record({"\ud800": 1}),
        }
        for name, call in calls.items():
            with self.subTest(argument=name):
                text = self.raised(cg.InvalidArgument, call, name)
                self.assertEqual(text.count(f"{name}:"), 1, text)  # named once, not prefixed twice
        with self.subTest(argument="simulate_trial writer"):
            self.raised(cg.InvalidArgument, lambda: cg.simulate_trial("一", writer="\ud800", max_duration_s=0.05),
                        "writer")
        # Membership asks, it does not refuse: a str that names no character is not in the library.
        self.assertNotIn("\ud800", cg.CharacterLibrary.default())
        self.assertIn("一", cg.CharacterLibrary.default())
        cg.set_log_level("warning")

    def test_score_arguments_of_another_type_are_type_errors_naming_them(self):
        columns = {"t": [0.0, 1.0], "x": [0.0, 0.0], "y": [0.0, 0.0], "pen": [1, 1]}
        for name, value in (("units", 5), ("contact_threshold_m", "x"), ("start_radius_m", "x")):
            with self.subTest(argument=name):
                text = self.raised(TypeError, lambda: cg.score(columns, "一", **{name: value}), name)
                self.assertNotIn("incompatible function arguments", text)
        self.raised(cg.InvalidArgument, lambda: cg.score(columns, "一", units="feet"), "units")

    def test_score_errors_name_the_line_and_column(self):
        with tempfile.TemporaryDirectory() as folder:
            csv = Path(folder) / "pen.csv"
            csv.write_text("t,x,y,pen\n0,0,0,1\n0.001,oops,0,1\n", encoding="utf-8")
            text = self.raised(cg.DataError, lambda: cg.score(str(csv), "一"), "pen.csv")
            self.assertRegex(text, r":3\b")
            self.assertIn("x", text)
            missing = Path(folder) / "none.csv"
            self.raised(cg.DataError, lambda: cg.score(str(missing), "一"), "none.csv")
        short_x = {"t": [0.0, 1.0], "x": [0.0], "y": [0.0, 0.0], "pen": [1, 1]}
        self.raised(cg.InvalidArgument, lambda: cg.score(short_x, "一"), "x")
        columns = {"t": [0.0, 1.0], "x": [0.0, 0.0], "y": [0.0, 0.0], "pen": [1, 1]}
        self.raised(cg.CharacterNotFound, lambda: cg.score(columns, "\U0001F600"), "U+1F600")

load_tests = sanitized_subset({
    "test_every_documented_exception_class_has_its_bases", "test_typical_stroke_errors",
    "test_writer_profile_errors", "test_guidance_rule_errors", "test_trace_kind_and_log_level_errors"})

if __name__ == "__main__":
    unittest.main()
