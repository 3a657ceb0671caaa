#!/usr/bin/env python3
"""Hostile cases written from the documentation alone (docs/python.md, `help()` of the module's public names and
the type stubs the build ships, `_calligraphy.pyi`), holding the docstrings and the stubs themselves to the
runtime. Run by CTest as `cli_unseen_round18c_tests`. Rounds 12I and 16D attacked the module's arguments and its
data-science use; this one takes each written promise as a contract:

- every public callable: each parameter the docstring or stub names exists with that name, kind and default, and
  given by keyword with its documented default gives what leaving it out gives; each documented exception is the
  one raised for the documented cause; each documented shape, dtype and unit holds; each documented default
  value is the value.
- the stubs against the runtime: every name in them exists, every public runtime name is in them, argument names
  and optionality match the runtime signatures, property and field types are what comes back, enum members are
  the members; mypy type-checks a small typed script written from the docs, which then runs.
- a docstring that promises something about another function (`run_trial` "as for simulate_trial", `score`
  "as calligraphy score does" and the trial's metrics, `check_trial_record` "as rerun_trial") is checked against
  it once.

CALLIGRAPHY_CLI names the program; CALLIGRAPHY_SOURCE_DIR the source tree; the built Python package is found on
PYTHONPATH. CALLIGRAPHY_SANITIZED=1 takes a small subset.
"""
import ast
import builtins
import copy
import logging
import os
import re
import subprocess
import sys
import tempfile
import textwrap
import unittest
from pathlib import Path

from outsider import CLI, TIMEOUT_S, sanitized_subset
from outsider_python import SharedTrial, cg, needs_python, np, remove_shared_trial

SOURCE = Path(os.environ.get("CALLIGRAPHY_SOURCE_DIR", Path(__file__).resolve().parents[2]))
SHI = "十"
YI = "一"  # not one of the 58 embedded characters: only the bundled corpus store has it

load_tests = sanitized_subset({"test_every_stub_name_exists_at_runtime_and_every_public_name_is_in_the_stubs",
                               "test_enum_members_in_the_stubs_are_the_runtime_members",
                               "test_trial_result_arrays_have_the_documented_shapes_dtypes_and_units",
                               "test_exception_classes_are_the_documented_table",
                               "test_force_functions_give_the_documented_shapes_and_values"})


def tearDownModule():
    remove_shared_trial()


# ---------------------------------------------------------------------------------------------------------------
# The stubs and the runtime signatures, read with ast


def stub_tree():
    return ast.parse((Path(cg.__file__).parent / "_calligraphy.pyi").read_text(encoding="utf-8"))


def stub_top_level():
    """name -> ast node of every top-level class, function and variable of the stubs."""
    names = {}
    for node in stub_tree().body:
        if isinstance(node, (ast.ClassDef, ast.FunctionDef)):
            names[node.name] = node
        elif isinstance(node, ast.AnnAssign):
            names[node.target.id] = node
    return names


def stub_classes():
    return {n: node for n, node in stub_top_level().items() if isinstance(node, ast.ClassDef) and n != "_EnumField"}


def is_enum(node):
    return any(isinstance(item, ast.AnnAssign) and isinstance(item.target, ast.Name)
               and item.target.id == "__members__" for item in node.body)


def parameters(function):
    """[(name, kind, has_default)] of an ast function, without self."""
    args = function.args
    out = []
    positional = args.posonlyargs + args.args
    first_default = len(positional) - len(args.defaults)
    for i, a in enumerate(positional):
        out.append((a.arg, "positional", i >= first_default))
    for a, default in zip(args.kwonlyargs, args.kw_defaults):
        out.append((a.arg, "keyword", default is not None))
    if args.vararg:
        out.append(("*" + args.vararg.arg, "var", False))
    if args.kwarg:
        out.append(("**" + args.kwarg.arg, "var", False))
    return [p for p in out if p[0] != "self"]


def runtime_signature(doc, name):
    """The ast function of pybind11's first docstring line `name(arg: T = default, ...) -> R`, or None for an
    overloaded function (its docstring lists signatures)."""
    if not doc:
        return None
    first = doc.strip().splitlines()[0]
    if not first.startswith(name + "("):
        return None
    first = re.sub(r"<[^<>]*>", "None", first)  # a default shown as its repr: <NearestPointMethod.exact: 0>
    return ast.parse("def " + first + ": ...").body[0]


def runtime_defaults(doc, name):
    """name -> the literal default of each parameter of pybind11's docstring signature (a repr that is no literal
    is left out)."""
    function = runtime_signature(doc, name)
    args = function.args
    out = {}
    positional = args.posonlyargs + args.args
    for a, default in zip(positional[len(positional) - len(args.defaults):], args.defaults):
        try:
            out[a.arg] = ast.literal_eval(default)
        except ValueError:
            pass
    for a, default in zip(args.kwonlyargs, args.kw_defaults):
        if default is not None:
            try:
                out[a.arg] = ast.literal_eval(default)
            except ValueError:
                pass
    return out


def type_holds(annotation, value):
    """Whether `value` is of the stub's annotation (a string of ast.unparse); None when the annotation is not one
    this check reads."""
    ext = cg._calligraphy
    a = annotation.replace("calligraphy._calligraphy.", "")
    a = re.sub(r"^_EnumField\[(\w+)\]$", r"\1", a)  # an enum field: read as its member
    simple = {"float": float, "str": str, "dict": dict, "list": list}
    if a in simple:
        return isinstance(value, simple[a])
    if a == "int":
        return isinstance(value, int) and not isinstance(value, bool)
    if a == "bool":
        return isinstance(value, bool)
    m = re.fullmatch(r"numpy\.typing\.NDArray\[numpy\.(\w+)\]", a)
    if m:
        return isinstance(value, np.ndarray) and value.dtype == np.dtype(m.group(1))
    m = re.fullmatch(r"Optional\[(.*)\]", a)
    if m:
        return True if value is None else type_holds(m.group(1), value)
    m = re.fullmatch(r"(?:List|Tuple)\[(\w+)(?:, \.\.\.)?\]", a)
    if m:
        return isinstance(value, (list, tuple)) and all(type_holds(m.group(1), v) for v in value)
    if hasattr(ext, a) and isinstance(getattr(ext, a), type):
        return isinstance(value, getattr(ext, a))
    return None


# ---------------------------------------------------------------------------------------------------------------
# Objects of every class the module hands out, made once


class Objects:
    made = None

    @classmethod
    def get(cls):
        if cls.made is None:
            shared = SharedTrial.get()
            trial = shared.trial
            library = cg.CharacterLibrary.embedded()
            character = library.load(SHI)
            scene = cg.Scene(SHI)
            renderer = cg.Renderer(scene)
            stroke = scene.characters[0].strokes[0]
            out = renderer.tick(cg.DeviceState(position_m=(*stroke.start_m, 0.001), time_s=0.0))
            teacher = cg.record_teacher(trial)
            survey = cg.list_devices()
            device = cg.SimulatedDevice()
            cls.made = {
                "CharacterLibrary": library, "Character": character, "Stroke": character.strokes[0],
                "StrokeElement": character.strokes[0].elements[0], "Scene": scene,
                "PlacedCharacter": scene.characters[0], "PlacedStroke": stroke, "Renderer": renderer,
                "RenderOutput": out, "TrialResult": trial, "WriterLog": trial.writer_log,
                "WriterAttempt": trial.writer_log.attempts[0], "TypicalStroke": cg.typical_stroke("HZG"),
                "StrokePieceTemplate": cg.typical_stroke("HZG").pieces[0], "DeviceSurvey": survey,
                "DeviceListing": survey.devices[0], "StrokeMatch": cg.match_stroke(scene, 0, 0, stroke.median_m),
                "TeacherRecording": teacher, "TeacherSample": teacher.samples[0], "SimulatedDevice": device,
            }
        return cls.made


def keyword_classes():
    """The stub's classes constructed by keywords alone (the parameter classes)."""
    out = {}
    for name, node in stub_classes().items():
        for item in node.body:
            if isinstance(item, ast.FunctionDef) and item.name == "__init__":
                params = parameters(item)
                if params and all(kind == "keyword" and has for _, kind, has in params):
                    out[name] = (node, [p[0] for p in params])
    return out


@needs_python
class StubsAgainstRuntime(unittest.TestCase):
    def test_every_stub_name_exists_at_runtime_and_every_public_name_is_in_the_stubs(self):
        # "The stubs are installed with the module, so mypy and editors check calls": a name mypy accepts must
        # exist, and every public name of the package that comes from the extension must be known to mypy.
        top = stub_top_level()
        missing = sorted(n for n in top if not hasattr(cg._calligraphy, n))
        self.assertEqual(missing, ["_EnumField"], "in the stubs, not in the extension (but the stubs' descriptor)")
        public_stub = sorted(n for n in top if not n.startswith("_"))
        not_exported = [n for n in public_stub if not hasattr(cg, n)]
        self.assertEqual(not_exported, [], "public in the stubs (mypy accepts calligraphy.NAME) but not in calligraphy")
        runtime = [n for n in dir(cg) if not n.startswith("_")
                   and not type(getattr(cg, n)).__name__ == "module"]
        self.assertEqual(sorted(n for n in runtime if n not in top), [], "public at runtime, not in the stubs")
        self.assertEqual(sorted(n for n in cg.__all__ if not n.startswith("_")), sorted(runtime))

    def test_every_type_the_stubs_name_is_defined_or_imported_there(self):
        # A name a stub uses without defining or importing it is no type at all: mypy reads it as Any (or refuses
        # the stub), so a call of the wrong type passes unnoticed.
        tree = stub_tree()
        known = set(vars(builtins))
        for node in tree.body:
            if isinstance(node, ast.ImportFrom):
                known |= {alias.asname or alias.name for alias in node.names}
            elif isinstance(node, ast.Import):
                known |= {(alias.asname or alias.name).split(".")[0] for alias in node.names}
            elif isinstance(node, (ast.ClassDef, ast.FunctionDef)):
                known.add(node.name)
            elif isinstance(node, ast.Assign):
                known |= {t.id for t in node.targets if isinstance(t, ast.Name)}
        annotations = []
        for node in ast.walk(tree):
            if isinstance(node, ast.arg) and node.annotation is not None:
                annotations.append(node.annotation)
            elif isinstance(node, ast.FunctionDef) and node.returns is not None:
                annotations.append(node.returns)
            elif isinstance(node, ast.AnnAssign):
                annotations.append(node.annotation)
        used = {name.id for a in annotations for name in ast.walk(a) if isinstance(name, ast.Name)}
        self.assertEqual(sorted(used - known), [])

    def test_enum_members_in_the_stubs_are_the_runtime_members(self):
        enums = {n: node for n, node in stub_classes().items() if is_enum(node)}
        self.assertGreaterEqual(len(enums), 6)
        for name, node in enums.items():
            stub_members = {item.target.id for item in node.body if isinstance(item, ast.AnnAssign)
                            and not item.target.id.startswith("_")}
            runtime = set(getattr(cg._calligraphy, name).__members__)
            self.assertEqual(stub_members, runtime, name)

    def test_class_members_in_the_stubs_are_the_runtime_members(self):
        # Every public method, property and field the stubs give a class exists on it, and every public one the
        # runtime class has is in the stubs.
        for name, node in stub_classes().items():
            if is_enum(node) or not node.body or isinstance(node.body[0], ast.Expr):
                continue  # enums above; exception classes have no body of their own
            cls = getattr(cg._calligraphy, name)
            stub = {item.name if isinstance(item, ast.FunctionDef) else item.target.id for item in node.body
                    if isinstance(item, (ast.FunctionDef, ast.AnnAssign))}
            stub = {n for n in stub if not n.startswith("_")}
            runtime = {n for n in dir(cls) if not n.startswith("_")}
            self.assertEqual(sorted(stub - runtime), [], f"{name}: in the stubs, not at runtime")
            self.assertEqual(sorted(runtime - stub), [], f"{name}: at runtime, not in the stubs")

    def test_function_signatures_in_the_stubs_are_the_runtime_signatures(self):
        # Argument names, their order, keyword-only or not and optional or not: the stub's against the signature
        # pybind11 writes at the head of each docstring (what help() shows).
        checked = 0
        for name, node in stub_top_level().items():
            targets = []
            if isinstance(node, ast.FunctionDef):
                targets.append((name, node, getattr(cg._calligraphy, name)))
            elif isinstance(node, ast.ClassDef) and not is_enum(node):
                for item in node.body:
                    if isinstance(item, ast.FunctionDef) and not item.name.startswith("__") or (
                            isinstance(item, ast.FunctionDef) and item.name == "__init__"):
                        if any(isinstance(d, ast.Name) and d.id == "property" for d in item.decorator_list):
                            continue
                        targets.append((f"{name}.{item.name}", item,
                                        getattr(getattr(cg._calligraphy, name), item.name)))
            for label, function, runtime in targets:
                short = label.split(".")[-1]
                signature = runtime_signature(getattr(runtime, "__doc__", None), short)
                if signature is None:
                    continue
                checked += 1
                self.assertEqual(parameters(function), parameters(signature), label)
        self.assertGreater(checked, 60)

    def test_property_and_field_types_in_the_stubs_hold_for_what_comes_back(self):
        objects = Objects.get()
        for name, (node, _) in keyword_classes().items():
            objects.setdefault(name, getattr(cg._calligraphy, name)())
        checked, wrong = 0, []
        for name, node in stub_classes().items():
            if name not in objects:
                continue
            obj = objects[name]
            for item in node.body:
                if isinstance(item, ast.FunctionDef) and any(
                        isinstance(d, ast.Name) and d.id == "property" for d in item.decorator_list):
                    attribute, annotation = item.name, ast.unparse(item.returns)
                elif isinstance(item, ast.AnnAssign) and not item.target.id.startswith("_"):
                    attribute, annotation = item.target.id, ast.unparse(item.annotation)
                else:
                    continue
                holds = type_holds(annotation, getattr(obj, attribute))
                if holds is None:
                    continue
                checked += 1
                if not holds:
                    wrong.append(f"{name}.{attribute}: {annotation}, got {type(getattr(obj, attribute))!r}")
        self.assertEqual(wrong, [])
        self.assertGreater(checked, 200)

    def test_function_return_types_in_the_stubs_hold(self):
        objects = Objects.get()
        scene = objects["Scene"]
        median = objects["PlacedStroke"].median_m
        calls = {
            "list_devices": cg.list_devices(), "metric_table": cg.metric_table(), "trace_columns": cg.trace_columns(),
            "writer_parameter_names": cg.writer_parameter_names(), "typical_stroke": cg.typical_stroke(1),
            "writer_profile": cg.writer_profile("novice"), "is_positive": cg.is_positive("median"),
            "trace_applies": cg.trace_applies(scene, 0, 0, "median"),
            "person_trace": cg.person_trace(scene, 0, 0, "median"),
            "match_stroke": cg.match_stroke(scene, 0, 0, median),
            "next_guidance_gain": cg.next_guidance_gain(0.5, 0.001),
            "paper_force": cg.paper_force(-0.001, 0.0, 800.0), "clamp_force": cg.clamp_force([1.0, 0, 0], 0.5),
            "constraint_taper": cg.constraint_taper(0.001, 0.005, 0.002),
            "check_trial_record": cg.check_trial_record(objects["TrialResult"].metrics),
            "score": SharedTrial.get().reference, "record_teacher": objects["TeacherRecording"],
            "flush_log": cg.flush_log(), "default_guidance_law": cg.default_guidance_law("fading"),
            "next_assist_band": cg.next_assist_band(0.001, 0.002), "skill_adaptive_mode": cg.skill_adaptive_mode(0.0),
        }
        top = stub_top_level()
        for name, value in calls.items():
            annotation = ast.unparse(top[name].returns)
            if annotation == "object":
                continue
            if annotation == "None":
                self.assertIsNone(value, name)
                continue
            if annotation.startswith("Union[float"):
                annotation = "float"
            self.assertTrue(type_holds(annotation, value), f"{name} -> {annotation}: {type(value)!r}")

    def test_mypy_checks_a_typed_script_of_the_documented_api_and_it_runs(self):
        # Every line below is the docs' own use (docs/python.md and the docstrings): enum arguments by their
        # spelling ("An enum argument takes a member, its one spelling ... or its member's name"), arrays in,
        # arrays out. mypy must accept it as the stubs type it, and then it must run.
        script = textwrap.dedent('''\
            import numpy as np
            import numpy.typing as npt
            import calligraphy as cg

            scene: cg.Scene = cg.Scene("十", layout=cg.SceneLayout(character_size_m=0.06, spacing_m=0.066))
            box: npt.NDArray[np.float64] = scene.characters[0].bounding_box_m
            law = cg.ForceLawParameters(guidance_stiffness_n_per_m=400, paper_stiffness_n_per_m=800)
            law.friction_coefficient = 0.2
            law.nearest.method = "newton"
            t, foot, d = cg.nearest_point(np.array([[0, 0], [0.02, 0]]), [0.005, 0.003], method="subdivision")
            path: npt.NDArray[np.float64] = cg.person_trace(scene, 0, 1, "human", seed=3)
            match: cg.StrokeMatch = cg.match_stroke(scene, 0, 1, path)
            positive: bool = cg.is_positive("median")
            fading = cg.default_guidance_law("fading")
            r: cg.TrialResult = cg.simulate_trial("十", writer="foreign", writer_params={"learning_rate": 0.3},
                                                  guidance_mode="fading", guidance_gain=0.6, max_duration_s=0.05)
            again: cg.TrialResult = cg.run_trial("十", device="simulated", pacing="lock-step", max_duration_s=0.05)
            g: float = cg.next_guidance_gain(0.6, r.metrics["mean_deviation_m"] or 0.0, cg.FadingRule())
            cg.set_log_level("warning")
            result: dict = cg.score({"t": r.time_s, "x": r.position_m[:, 0], "y": r.position_m[:, 1],
                                     "z": r.position_m[:, 2]}, "十")
            band: float = cg.next_assist_band(0.001, 0.002, cg.AssistBandRule())
            mode: cg.GuidanceMode = cg.skill_adaptive_mode(0.003)
            print(type(match).__name__, positive, type(fading).__name__, len(again.time_s) > 0, 0.0 <= g <= 1.0,
                  mode.name)
            ''')
        with tempfile.TemporaryDirectory(prefix="round18c-mypy-") as folder:
            path = Path(folder) / "use.py"
            path.write_text(script, encoding="utf-8")
            mypy = subprocess.run([sys.executable, "-m", "mypy", "--no-error-summary", "--cache-dir",
                                   str(Path(folder) / "cache"), "--follow-imports=silent", str(path)],
                                  capture_output=True, text=True, timeout=TIMEOUT_S * 3, cwd=folder)
            if "No module named mypy" in mypy.stderr:
                self.skipTest("mypy is not installed")
            self.assertEqual(mypy.returncode, 0, mypy.stdout + mypy.stderr)
            run = subprocess.run([sys.executable, str(path)], capture_output=True, text=True, timeout=TIMEOUT_S,
                                 cwd=folder)
            self.assertEqual(run.returncode, 0, run.stderr)
            self.assertEqual(run.stdout.split(), ["StrokeMatch", "True", "FadingGuidance", "True", "True", "fixed"])


# ---------------------------------------------------------------------------------------------------------------
# Documented defaults


@needs_python
class DocumentedDefaults(unittest.TestCase):
    def test_parameter_classes_defaults_are_the_docstrings_and_given_by_keyword_change_nothing(self):
        # "Every field is keyword-only and defaults to the C++ default shown."
        for name, (node, fields) in keyword_classes().items():
            cls = getattr(cg._calligraphy, name)
            default = cls()
            shown = runtime_defaults(cls.__init__.__doc__, "__init__")
            for field in fields:
                value = getattr(default, field)
                if field in shown:
                    if isinstance(value, np.ndarray):
                        np.testing.assert_array_equal(value, shown[field], err_msg=f"{name}.{field}")
                    elif hasattr(value, "name") and isinstance(shown[field], str):
                        self.assertEqual(value.name, shown[field], f"{name}.{field}")
                    else:
                        self.assertEqual(value, shown[field], f"{name}.{field}")
            if hasattr(default, "__eq__") and name != "ReplayGuidance":
                again = cls(**{f: copy.deepcopy(getattr(default, f)) for f in fields})
                self.assertEqual(again.to_dict(), default.to_dict(), name)

    def test_simulate_trial_every_documented_default_given_by_keyword_gives_the_same_trial(self):
        shared = SharedTrial.get()
        doc = runtime_defaults(cg.simulate_trial.__doc__, "simulate_trial")
        self.assertEqual(doc["writer"], "novice")
        self.assertEqual(doc["rate_hz"], 1000.0)
        self.assertEqual(doc["max_duration_s"], 300.0)
        explicit = cg.simulate_trial(SHI, **{**doc, "seed": 1})
        for field in ("time_s", "position_m", "force_n", "state", "stroke", "element"):
            np.testing.assert_array_equal(getattr(explicit, field), getattr(shared.trial, field), err_msg=field)
        self.assertEqual(explicit.metrics["specification"], shared.trial.metrics["specification"])

    def test_score_and_nearest_point_documented_defaults_given_by_keyword_change_nothing(self):
        shared = SharedTrial.get()
        doc = runtime_defaults(cg.score.__doc__, "score")
        self.assertEqual(doc, {"units": "m", "library": None, "contact_threshold_m": 0.0005, "acceptance": None,
                               "start_radius_m": 0.005})
        self.assertEqual(cg.score(shared.columns, SHI, **doc), shared.reference)
        element = Objects.get()["StrokeElement"]
        points = np.array([[500.0, 600.0], [10.0, 20.0]])
        plain = cg.nearest_point(element, points)
        explicit = cg.nearest_point(element, points, method=cg.NearestPointMethod.exact, tolerance=1e-12,
                                    newton_starts=8, newton_iterations=6)
        for a, b in zip(plain, explicit):
            np.testing.assert_array_equal(a, b)
        options = cg.NearestPointOptions()  # the force law's nearest point: the same defaults
        self.assertEqual((options.method, options.tolerance, options.newton_starts, options.newton_iterations),
                         (cg.NearestPointMethod.exact, 1e-12, 8, 6))

    def test_next_guidance_gain_default_rule_is_the_documented_formula_and_range(self):
        # "clamp(f gain + k error_m, 0, 1) with f, k of `rule` (a FadingRule, default f = 0.8, k = 200 1/m)"
        rule = cg.FadingRule()
        self.assertEqual((rule.forgetting_factor, rule.error_gain_per_m), (0.8, 200.0))
        self.assertAlmostEqual(cg.next_guidance_gain(0.5, 0.001), 0.8 * 0.5 + 200 * 0.001, places=12)
        self.assertEqual(cg.next_guidance_gain(0.5, 0.001, None), cg.next_guidance_gain(0.5, 0.001, rule=rule))
        self.assertEqual(cg.next_guidance_gain(1.0, 1.0), 1.0)
        self.assertEqual(cg.next_guidance_gain(0.0, 0.0), 0.0)
        for gain, error in ((1.5, 0.0), (-0.1, 0.0), (0.5, -1e-3), (0.5, float("nan")), (0.5, float("inf"))):
            with self.assertRaises(cg.InvalidArgument, msg=(gain, error)):
                cg.next_guidance_gain(gain, error)
        with self.assertRaisesRegex(TypeError, "gain"):
            cg.next_guidance_gain("0.5", 0.0)

    def test_person_trace_and_match_stroke_defaults_are_the_documented_ones(self):
        scene = Objects.get()["Scene"]
        plain = cg.person_trace(scene, 0, 1, "human")
        np.testing.assert_array_equal(plain, cg.person_trace(scene, 0, 1, cg.TraceKind.human, seed=0))
        self.assertEqual((plain.ndim, plain.shape[1], plain.dtype), (2, 2, np.float64))
        self.assertFalse(np.array_equal(plain, cg.person_trace(scene, 0, 1, "human", seed=1)))
        # acceptance=None is "the C++ defaults, as ForceLawParameters().acceptance"
        self.assertEqual(cg.StrokeAcceptance().to_dict(), cg.ForceLawParameters().acceptance.to_dict())
        acceptance = cg.StrokeAcceptance()
        self.assertEqual((acceptance.hint_after_misses, acceptance.assist_after_misses), (3, 5))
        for kind in cg.TraceKind.__members__.values():
            if not cg.trace_applies(scene, 0, 1, kind):
                continue
            path = cg.person_trace(scene, 0, 1, kind, seed=2)
            a = cg.match_stroke(scene, 0, 1, path)
            b = cg.match_stroke(scene, 0, 1, path, acceptance=acceptance)
            self.assertEqual((a.accepted, a.refusal, a.covered_fraction, a.mean_deviation_m),
                             (b.accepted, b.refusal, b.covered_fraction, b.mean_deviation_m), kind.name)

    def test_layout_placement_and_renderer_defaults_are_the_documented_ones(self):
        layout = cg.SceneLayout()
        # Scene: "default: 60 mm characters, 66 mm apart, centred at the origin, paper at z = 0"; score: "default
        # the scene's, 0.005"
        self.assertEqual((layout.character_size_m, layout.spacing_m, layout.paper_z_m, layout.start_radius_m),
                         (0.06, 0.066, 0.0, 0.005))
        np.testing.assert_array_equal(layout.centre_m, [0.0, 0.0])
        self.assertEqual(cg.Placement().metres_per_unit, 0.06 / 1024)
        # Renderer: device "default the simulated Phantom Desktop's as SimulatedDevice().info reports it, with its
        # own damping, 0.5 N s/m"
        info = cg.SimulatedDevice().info
        self.assertEqual(info.intrinsic_damping_n_s_per_m, 0.5)
        scene = Objects.get()["Scene"]
        start = scene.strokes[0].start_m
        a, b = cg.Renderer(scene), cg.Renderer(scene, None, info, None)
        for i in range(200):
            state = cg.DeviceState(position_m=(start[0] + 1e-5 * i, start[1], 0.002 - 2e-5 * i),
                                   velocity_m_s=(0.01, 0.0, -0.02), time_s=i * 1e-3)
            oa, ob = a.tick(state), b.tick(state)
            np.testing.assert_array_equal(oa.force_n, ob.force_n)
            self.assertEqual(oa.state, ob.state)

    def test_the_default_character_source_is_the_one_every_docstring_names(self):
        # docs/python.md: simulate_trial's, score's and rerun_trial's `library=` default is "every character, as
        # CharacterLibrary.default()"; a character of the bundled store (一, not embedded) is found without one.
        self.assertNotIn(YI, cg.CharacterLibrary.embedded())
        self.assertIn(YI, cg.CharacterLibrary.default())
        plain = cg.simulate_trial(YI, max_duration_s=0.2)
        default = cg.simulate_trial(YI, max_duration_s=0.2, library=cg.CharacterLibrary.default())
        np.testing.assert_array_equal(plain.position_m, default.position_m)
        self.assertEqual(cg.Scene(YI).strokes[0].length_m, cg.Scene(YI, library=cg.CharacterLibrary.default())
                         .strokes[0].length_m)
        # What the docstrings say of that default must be the same source.
        for function in (cg.simulate_trial, cg.score, cg.rerun_trial, cg.Scene.__init__):
            self.assertNotIn("default the embedded set", " ".join(function.__doc__.split()), function.__name__)


# ---------------------------------------------------------------------------------------------------------------
# Documented shapes, dtypes and units


@needs_python
class DocumentedShapes(unittest.TestCase):
    def test_trial_result_arrays_have_the_documented_shapes_dtypes_and_units(self):
        r = SharedTrial.get().trial
        n = len(r.time_s)
        self.assertGreater(n, 100)
        expected = {"time_s": ((n,), np.float64), "position_m": ((n, 3), np.float64),
                    "force_n": ((n, 3), np.float64), "state": ((n,), np.uint8), "stroke": ((n,), np.int64),
                    "element": ((n,), np.int64)}
        for name, (shape, dtype) in expected.items():
            array = getattr(r, name)
            self.assertEqual((array.shape, array.dtype), (shape, dtype), name)
            self.assertFalse(array.flags.writeable, name)
        self.assertEqual(r.stroke_trace_range.shape, (2, 2))  # (S, 2): 十 has two strokes
        self.assertEqual(r.stroke_trace_range.dtype, np.int64)
        np.testing.assert_allclose(np.diff(r.time_s), 1e-3, rtol=1e-9)  # seconds at 1000 Hz
        self.assertLess(np.abs(r.position_m).max(), 0.2)  # metres: a 60 mm character
        self.assertLess(np.linalg.norm(r.force_n, axis=1).max(), 10.0)  # newtons
        writing = r.state == cg.InteractionState.writing  # "works on a trace's uint8 array"
        self.assertEqual(writing.dtype, np.bool_)
        self.assertTrue(writing.any())
        self.assertEqual([s.short_name for s in cg.InteractionState.__members__.values()], ["SS", "AS", "CS", "WS"])
        self.assertEqual([int(s) for s in cg.InteractionState.__members__.values()], [0, 1, 2, 3])
        empty = cg.simulate_trial(SHI, seed=1, keep_trace=False)
        for name, (shape, dtype) in expected.items():
            self.assertEqual((getattr(empty, name).shape[0], getattr(empty, name).dtype), (0, dtype), name)
        self.assertEqual(empty.metrics["mean_deviation_m"], r.metrics["mean_deviation_m"])

    def test_force_functions_give_the_documented_shapes_and_values(self):
        one = cg.paper_force(-0.002, 0.0, 800.0)  # eq. (9): K (z0 - z) e_z below the paper, a number -> (3,)
        np.testing.assert_allclose(one, [0, 0, 1.6])
        many = cg.paper_force(np.array([-0.001, 0.001]), 0.0, 800.0)
        self.assertEqual((many.shape, many.dtype), ((2, 3), np.float64))
        np.testing.assert_allclose(many, [[0, 0, 0.8], [0, 0, 0]])
        pull = cg.attraction_force([0.001, 0.0], [0.0, 0.0], 400.0)  # attraction_factor default 1.0
        np.testing.assert_allclose(pull, [-0.4, 0.0])
        np.testing.assert_array_equal(pull, cg.attraction_force([0.001, 0.0], [0.0, 0.0], 400.0, 1.0))
        self.assertEqual(cg.attraction_force(np.zeros((5, 2)), [0.0, 0.0], 400.0).shape, (5, 2))
        back = cg.resistance_force([-0.01, 0.0], [1.0, 0.0], 2.0)
        np.testing.assert_allclose(back, [0.02, 0.0])  # -b (v.t) t when v.t < 0
        np.testing.assert_array_equal(cg.resistance_force([0.01, 0.0], [1.0, 0.0], 2.0), [0.0, 0.0])
        slide = cg.friction_force([0.02, 0.0], 1.0, 0.2, 0.01)
        np.testing.assert_allclose(slide, [-0.2, 0.0])  # -mu N v/|v| above the stick band
        stick = cg.friction_force([0.005, 0.0], 1.0, 0.2, 0.01)
        np.testing.assert_allclose(stick, [-0.1, 0.0])  # -mu N v / v_band inside it
        taper = cg.constraint_taper(0.001, 0.005, 0.002)
        self.assertIs(type(taper), float)  # a number -> float
        self.assertEqual(taper, 1.0)
        self.assertEqual(cg.constraint_taper(0.006, 0.005, 0.002), 0.0)
        middle = cg.constraint_taper(np.array([0.004, 0.0035, 0.0]), 0.005, 0.002)
        self.assertEqual((middle.shape, middle.dtype), ((3,), np.float64))
        self.assertTrue(((middle >= 0) & (middle <= 1)).all())
        clamped = cg.clamp_force([[3.0, 4.0, 0.0], [np.nan, 0.0, 0.0]], 1.0)
        np.testing.assert_allclose(clamped, [[0.6, 0.8, 0.0], [0.0, 0.0, 0.0]])

    def test_scene_character_and_element_shapes_are_the_documented_ones(self):
        scene = cg.Scene(SHI + "十")
        self.assertEqual(scene.stroke_count, len(scene.strokes))
        placed = scene.characters[1]
        self.assertEqual(placed.bounding_box_m.shape, (2, 2))
        self.assertTrue((placed.bounding_box_m[1] > placed.bounding_box_m[0]).all())  # [[min], [max]]
        self.assertAlmostEqual(scene.characters[1].placement.origin_m[0] - scene.characters[0].placement.origin_m[0],
                               0.066)  # spacing_m
        one = placed.placement.to_paper([512.0, 512.0])
        self.assertEqual(one.shape, (2,))
        many = placed.placement.to_paper(np.array([[0.0, 0.0], [1024.0, 1024.0]]))
        self.assertEqual(many.shape, (2, 2))
        np.testing.assert_allclose(many[1] - many[0], [0.06, 0.06])  # the 1024-unit box is 60 mm, y up
        np.testing.assert_allclose(placed.placement.to_data(many), [[0.0, 0.0], [1024.0, 1024.0]], atol=1e-9)
        s = placed.strokes[0]
        for name, shape in (("start_m", (2,)), ("end_m", (2,))):
            self.assertEqual(getattr(s, name).shape, shape, name)
        for name in ("median_m", "centre_line_m"):
            self.assertEqual(getattr(s, name).shape[1], 2, name)
        self.assertAlmostEqual(s.length_m, float(np.linalg.norm(np.diff(s.centre_line_m, axis=0), axis=1).sum()),
                               delta=0.002)
        character = cg.CharacterLibrary.embedded().load(SHI)
        stroke = character.strokes[0]
        k = len(stroke.elements)
        self.assertEqual(stroke.feature_points.shape, (k + 1, 2))
        self.assertEqual(stroke.attraction_factors.shape, (k + 1,))
        for element in stroke.elements:
            self.assertEqual(element.control_points.shape, (element.degree + 1, 2))
            self.assertEqual(element.kind, "line" if element.degree == 1 else "bezier")
            self.assertFalse(element.control_points.flags.writeable)
            self.assertEqual(element.point(np.linspace(0, 1, 5)).shape, (5, 2))
        with self.assertRaises(cg.InvalidArgument):
            cg.StrokeElement(np.zeros((6, 2)))
        with self.assertRaisesRegex(cg.InvalidArgument, "control_points"):
            cg.StrokeElement([["a", "b"], ["c", "d"]])  # text: no real numbers (docs/python.md)
        with self.assertRaisesRegex(TypeError, "control_points"):
            cg.StrokeElement(None)

    def test_metric_table_and_trace_columns_have_the_documented_keys_and_order(self):
        keys = {"name", "kind", "unit", "doc", "definition", "source", "levels", "legacy_name", "legacy_factor",
                "trials_column", "strokes_column"}
        table = cg.metric_table()
        for row in table:
            self.assertLessEqual(keys, set(row), row.get("name"))
            self.assertIn(row["kind"], ("number", "count", "flag"), row["name"])
        names = {row["name"] for row in table}
        for name in ("mean_deviation_m", "frechet_m", "total_time_s"):
            self.assertIn(name, names)
        columns = cg.trace_columns()
        for row in columns:
            self.assertLessEqual({"name", "file_name", "unit", "doc"}, set(row))
            self.assertIn(row["unit"], ("s", "m", "N", ""))
        self.assertEqual([row["file_name"] for row in columns[:4]], ["t", "x", "y", "z"])
        self.assertEqual([row["name"] for row in columns[:4]], ["t_s", "x_m", "y_m", "z_m"])
        # "score reads a column by either name"
        shared = SharedTrial.get()
        by_unit = {"t_s": shared.columns["t"], "x_m": shared.columns["x"], "y_m": shared.columns["y"],
                   "z_m": shared.columns["z"]}
        self.assertEqual(cg.score(by_unit, SHI), shared.reference)


# ---------------------------------------------------------------------------------------------------------------
# Documented errors


@needs_python
class DocumentedErrors(unittest.TestCase):
    def test_exception_classes_are_the_documented_table(self):
        table = {"Error": (Exception,), "InvalidArgument": (cg.Error, ValueError),
                 "DataError": (cg.Error, RuntimeError),
                 "CharacterNotFound": (KeyError, cg.DataError), "DeviceError": (cg.Error, RuntimeError),
                 "DeviceNotFound": (LookupError, cg.DeviceError), "DeviceUnavailable": (cg.DeviceError,),
                 "CommunicationError": (ConnectionError, cg.DeviceError), "SafetyFault": (cg.DeviceError,),
                 "CalibrationNeeded": (cg.DeviceError,), "RealtimeError": (cg.DeviceError,),
                 "StateError": (cg.Error, RuntimeError)}
        for name, bases in table.items():
            cls = getattr(cg, name)
            for base in bases:
                self.assertTrue(issubclass(cls, base), f"{name} is a {base.__name__}")
        self.assertFalse(hasattr(cg, "InputError"))  # raised as its base DataError

    def test_load_and_typical_stroke_raise_what_their_docs_say(self):
        library = cg.CharacterLibrary.default()
        with self.assertRaises(cg.InvalidArgument) as two:
            library.load("一二")
        self.assertIn("U+4E00", str(two.exception))
        self.assertIn("U+4E8C", str(two.exception))
        with self.assertRaises(cg.InvalidArgument):
            library.load("")
        with self.assertRaises(cg.CharacterNotFound) as missing:
            library.load("é")
        self.assertIn("U+00E9", str(missing.exception))
        with self.assertRaises(TypeError):
            library.load(7)
        # typical_stroke: the ID, the acronym in any case, the Chinese name or the CJK stroke character
        hzg = cg.typical_stroke("HZG")
        for key in ("hzg", hzg.id, hzg.name_zh, hzg.unicode):
            self.assertEqual(cg.typical_stroke(key).acronym, "HZG", key)
        with self.assertRaises(cg.InvalidArgument) as forty:
            cg.typical_stroke(40)
        self.assertIn("key: typical-stroke ID 40 is not in 1..39", str(forty.exception))
        with self.assertRaises(TypeError):
            cg.typical_stroke(1.5)
        self.assertEqual(len(cg.TYPICAL_STROKES), 39)
        self.assertIsInstance(cg.TYPICAL_STROKES, tuple)

    def test_integer_and_type_errors_have_the_documented_messages(self):
        with self.assertRaises(cg.InvalidArgument) as seed:
            cg.simulate_trial(SHI, seed=2 ** 64, keep_trace=False)
        self.assertIn("seed: 18446744073709551616 is out of range: expected an int in 0..18446744073709551615 "
                      "(0..2**64-1)", str(seed.exception))
        scene = Objects.get()["Scene"]
        with self.assertRaises(IndexError) as index:
            cg.person_trace(scene, 0, 2 ** 70, "median")
        self.assertIn("stroke_index: 1180591620717411303424 is not in 0..1 (the character's strokes has 2)",
                      str(index.exception))
        with self.assertRaises(cg.InvalidArgument) as starts:
            cg.NearestPointOptions(newton_starts=-1)
        self.assertIn("newton_starts = -1 must be in 1..1000", str(starts.exception))
        with self.assertRaises(TypeError) as rate:
            cg.simulate_trial(SHI, rate_hz="fast")
        self.assertIn("rate_hz: expected float, got str 'fast'", str(rate.exception))
        law = cg.ForceLawParameters()
        with self.assertRaisesRegex(ValueError, "friction_coefficient"):
            law.friction_coefficient = -1.0

    def test_simulate_trial_ranges_are_the_documented_ones(self):
        # rate_hz: 100..100000; max_duration_s > 0, at most 10^7 ticks (rate_hz * max_duration_s)
        for kwargs, named in (({"rate_hz": 99.0}, "rate_hz"), ({"rate_hz": 100001.0}, "rate_hz"),
                              ({"max_duration_s": 0.0}, "max_duration_s"),
                              ({"rate_hz": 100000.0, "max_duration_s": 100.001}, "max_duration_s"),
                              ({"hint_after_misses": 1001}, "hint_after_misses"),
                              ({"guidance": False, "guidance_mode": "fading"}, "guidance_mode"),
                              ({"guidance_mode": "replay"}, "teacher")):
            with self.assertRaises(cg.InvalidArgument, msg=kwargs) as caught:
                cg.simulate_trial(SHI, keep_trace=False, **kwargs)
            self.assertIn(named, str(caught.exception), kwargs)
        with self.assertRaises(TypeError):
            cg.simulate_trial(SHI, hint_after_misses=1.0)
        with self.assertLogs("calligraphy", logging.WARNING) as said:  # Renderer: "logs a warning when a stiffness
            edge = cg.simulate_trial(SHI, rate_hz=100.0, max_duration_s=0.5, keep_trace=False)  # exceeds ..."
        self.assertTrue(any("passivity bound" in line for line in said.output), said.output)
        self.assertEqual(edge.metrics["end_reason"], "time_limit")
        self.assertEqual(cg.simulate_trial(SHI, rate_hz=100000.0, max_duration_s=100.0 / 100000.0).time_s.shape,
                         (100,))

    def test_writer_profiles_and_parameter_names_are_what_the_docs_say(self):
        numeric = {item.target.id for item in stub_classes()["WriterProfile"].body
                   if isinstance(item, ast.AnnAssign) and ast.unparse(item.annotation) in ("float", "int")}
        self.assertEqual(set(cg.writer_parameter_names()), numeric)
        self.assertEqual(cg.writer_profile("novice"), cg.WriterProfile.novice())
        self.assertEqual(cg.WriterProfile(), cg.WriterProfile.novice())  # the constructor's defaults are 'novice'
        self.assertEqual(cg.writer_profile("foreign", {"learning_rate": 0.3}).learning_rate, 0.3)
        base = cg.WriterProfile.skilled()
        copied = cg.writer_profile(base, {"learning_rate": 0.2})
        self.assertEqual(base.learning_rate, cg.WriterProfile.skilled().learning_rate)  # `writer` copied
        self.assertEqual(copied.learning_rate, 0.2)
        with self.assertRaisesRegex(cg.InvalidArgument, "no_such_key"):
            cg.writer_profile("novice", {"no_such_key": 1.0})
        with self.assertRaisesRegex(cg.InvalidArgument, "expert"):
            cg.writer_profile("expert")
        with self.assertRaises(TypeError):
            cg.writer_profile("novice", {"learning_rate": "fast"})
        with self.assertRaisesRegex(cg.InvalidArgument, "scale_error"):
            cg.simulate_trial(SHI, writer_params={"scale_error": float("nan")}, keep_trace=False)

    def test_enum_arguments_take_the_member_its_spelling_and_its_name(self):
        self.assertEqual(cg.default_guidance_law("fading"), cg.default_guidance_law(cg.GuidanceMode.fading))
        self.assertEqual(cg.default_guidance_law("fading"), cg.FadingGuidance())
        self.assertEqual(type(cg.default_guidance_law("assist-as-needed")).__name__, "AssistAsNeededGuidance")
        self.assertEqual(cg.ForceLawParameters().guidance_mode, cg.GuidanceMode.fixed)
        self.assertIs(cg.is_positive("median"), True)
        self.assertIs(cg.is_positive(cg.TraceKind.reversed), False)
        with self.assertRaises(cg.InvalidArgument):
            cg.is_positive("sideways")
        with self.assertRaisesRegex(TypeError, "kind"):
            cg.is_positive(1.5)
        with self.assertRaisesRegex(cg.InvalidArgument, "kind"):
            cg.is_positive(cg.TraceKind(-1))
        options = cg.NearestPointOptions()
        options.method = "newton"
        self.assertEqual(options.method, cg.NearestPointMethod.newton)

    def test_set_log_level_takes_names_and_levels_as_documented(self):
        logger = logging.getLogger("calligraphy")
        before = logger.level
        try:
            cg.set_log_level("WARNING")
            self.assertEqual(logger.level, logging.WARNING)
            cg.set_log_level(logging.DEBUG)
            self.assertEqual(logger.level, logging.DEBUG)
            cg.set_log_level("error")
            self.assertEqual(logger.level, logging.ERROR)
            with self.assertRaises(cg.InvalidArgument):
                cg.set_log_level("loud")
            with self.assertRaises(TypeError):
                cg.set_log_level(1.5)
        finally:
            cg.set_log_level(before or logging.WARNING)

    def test_record_teacher_without_a_trace_raises_invalid_argument(self):
        # record_teacher: "Raises InvalidArgument when the trial kept no trace (keep_trace=False)"
        empty = cg.simulate_trial(SHI, seed=1, keep_trace=False)
        with self.assertRaises(cg.InvalidArgument) as caught:
            cg.record_teacher(empty)
        self.assertIn("trace", str(caught.exception))
        with tempfile.TemporaryDirectory(prefix="round18c-") as folder:
            with self.assertRaises(cg.Error) as unwritable:
                cg.record_teacher(SharedTrial.get().trial, Path(folder) / "missing" / "teacher.json")
            self.assertIn("teacher.json", str(unwritable.exception))
            self.assertEqual(os.listdir(folder), [])


# ---------------------------------------------------------------------------------------------------------------
# Docstrings that promise something about another function


@needs_python
class PromisesAboutOtherFunctions(unittest.TestCase):
    def test_check_trial_record_refuses_a_contradiction_as_its_docs_say(self):
        # docs/python.md: a contradiction between fields raises DataError naming its part's pointer and the field;
        # the docstring must say the same, and rerun_trial ("as rerun_trial ... check it") refuses it alike.
        record = copy.deepcopy(SharedTrial.get().trial.metrics)
        trial = record["specification"]["trial"]
        trial["guidance"] = False
        trial["guidance_mode"] = "fading"
        with self.assertRaises(cg.DataError) as checked:
            cg.check_trial_record(record)
        message = str(checked.exception)
        self.assertIn("/specification/trial", message)
        self.assertIn("guidance_mode", message)
        with self.assertRaises(cg.DataError) as rerun:
            cg.rerun_trial(record)
        self.assertIn("guidance_mode", str(rerun.exception))
        doc = " ".join(cg.check_trial_record.__doc__.split())
        self.assertNotIn("InvalidArgument naming the field of a contradiction", doc)
        with self.assertRaises(TypeError):
            cg.check_trial_record(42)

    def test_rerun_and_check_give_the_same_trial_and_specification(self):
        r = SharedTrial.get().trial
        again = cg.rerun_trial(r.metrics)
        np.testing.assert_array_equal(again.position_m, r.position_m)  # "the same bit for bit"
        spec = cg.check_trial_record(r.metrics)
        self.assertEqual(cg.check_trial_record(spec), spec)  # "which check_trial_record and rerun_trial take again"
        np.testing.assert_array_equal(cg.rerun_trial(spec).position_m, r.position_m)

    def test_run_trial_takes_what_simulate_trial_takes_and_gives_its_trial(self):
        # run_trial: "The other arguments as for simulate_trial"; the simulated device runs lock-step.
        shared = SharedTrial.get()
        run = cg.run_trial(SHI, device="simulated", pacing="auto", seed=1)
        np.testing.assert_array_equal(run.position_m, shared.trial.position_m)
        self.assertEqual(run.metrics["end_reason"], "completed")
        sim_doc = runtime_signature(cg.simulate_trial.__doc__, "simulate_trial")
        run_doc = runtime_signature(cg.run_trial.__doc__, "run_trial")
        # device, pacing and watchdog_s (the real-time loop's stall bound) are documented as run_trial's own
        own = {"device", "pacing", "watchdog_s"}
        shared_names = {p[0] for p in parameters(run_doc)} - own
        self.assertLessEqual(shared_names, {p[0] for p in parameters(sim_doc)})
        sim_defaults = runtime_defaults(cg.simulate_trial.__doc__, "simulate_trial")
        run_defaults = runtime_defaults(cg.run_trial.__doc__, "run_trial")
        self.assertEqual(set(run_defaults) - own, shared_names - {"characters"})
        self.assertEqual({k: run_defaults[k] for k in run_defaults if k in shared_names},
                         {k: sim_defaults[k] for k in run_defaults if k in shared_names})
        with self.assertRaises(cg.InvalidArgument):
            cg.run_trial(SHI, device="simulated", pacing="sometimes", keep_trace=False)

    def test_run_trial_devices_are_the_ones_list_devices_lists(self):
        # docs/python.md: the registry has the simulated device and the hardware backends, and not the command
        # line's Phantom emulator; run_trial's docstring must not promise what the registry lacks.
        names = [d.name for d in cg.list_devices().devices]
        self.assertIn("simulated", names)
        self.assertNotIn("emulated-phantom", names)
        with self.assertRaises(cg.DeviceNotFound) as caught:
            cg.run_trial(SHI, device="emulated-phantom", max_duration_s=0.05, keep_trace=False)
        self.assertIn("simulated", str(caught.exception))
        self.assertNotIn("'emulated-phantom' are moved", " ".join(cg.run_trial.__doc__.split()))

    def test_score_of_a_trial_is_its_metrics_as_the_docs_say(self):
        # score: "the same keys and values as simulate_trial(...).metrics and calligraphy score --json give"
        shared = SharedTrial.get()
        metrics, scored = shared.trial.metrics, shared.reference
        for key in ("order_errors", "backwards_strokes", "mean_deviation_m", "frechet_m", "dtw_m",
                    "strokes_accepted"):
            self.assertIn(key, scored)
            if isinstance(metrics[key], float):
                self.assertAlmostEqual(scored[key], metrics[key], delta=1e-9, msg=key)
            else:
                self.assertEqual(scored[key], metrics[key], key)
        segments = scored["per_character"][0]["segments"]
        for segment in segments:
            self.assertLessEqual({"begin", "end", "matched_stroke", "verdict"}, set(segment))
            self.assertLess(segment["begin"], segment["end"])
        # a Scene is scored as it is laid out: the trial's own scene gives the same result as its characters
        self.assertEqual(cg.score(shared.columns, shared.trial.scene)["mean_deviation_m"], scored["mean_deviation_m"])
        with self.assertRaisesRegex(cg.InvalidArgument, "units"):
            cg.score(shared.columns, SHI, units="mm")


# ---------------------------------------------------------------------------------------------------------------
# Classes' own promises: a corpus store's medians, a teacher's file, the simulated device, the repetition rules


@needs_python
class ClassPromises(unittest.TestCase):
    def test_a_corpus_stores_strokes_have_their_datas_medians_as_the_docs_say(self):
        # docs/python.md: every store `corpus build` writes now holds each stroke's median as the data has it; only
        # a store of format 1.0 (--medians off) has none, Stroke.median (0, 2). from_store's docstring must agree.
        if not CLI:
            self.skipTest("CALLIGRAPHY_CLI not set")
        with tempfile.TemporaryDirectory(prefix="round18c-store-") as folder:
            data = Path(folder) / "data"
            data.mkdir()
            sample = SOURCE / "tests" / "data" / "hanzi-writer-sample" / "舍.json"
            (data / sample.name).write_bytes(sample.read_bytes())
            stores = {}
            for medians in ("on", "off"):
                stores[medians] = Path(folder) / f"{medians}.clg"
                built = subprocess.run([CLI, "corpus", "build", "--data", str(data), "--out", str(stores[medians]),
                                        "--threads", "1", "--medians", medians], capture_output=True, text=True,
                                       timeout=TIMEOUT_S)
                self.assertEqual(built.returncode, 0, built.stderr)
            fitted = cg.CharacterLibrary.from_hanzi_writer(data).load("舍")
            with_medians = cg.CharacterLibrary.from_store(stores["on"])
            self.assertTrue(with_medians.store_info["medians"])
            for stored, original in zip(with_medians.load("舍").strokes, fitted.strokes):
                np.testing.assert_allclose(stored.median, original.median, atol=1.0)
                self.assertGreater(len(stored.median), 1)
            for stroke in cg.CharacterLibrary.from_store(stores["off"]).load("舍").strokes:
                self.assertEqual(stroke.median.shape, (0, 2))
        bundled = cg.CharacterLibrary.default().load(YI)  # the bundled store's 一
        self.assertGreater(len(bundled.strokes[0].median), 1)
        self.assertEqual(cg.person_trace(cg.Scene(YI), 0, 0, "median").shape[1], 2)
        self.assertNotIn("Its Strokes have no median", cg.CharacterLibrary.from_store.__doc__)

    def test_a_teacher_recording_reads_back_and_its_files_fail_as_documented(self):
        teacher = Objects.get()["TeacherRecording"]
        again = cg.TeacherRecording.from_json(teacher.to_json())  # "numbers read back exactly"
        self.assertEqual(len(again), len(teacher))
        self.assertEqual((again.characters, again.rate_hz), (teacher.characters, teacher.rate_hz))
        for a, b in zip(again.samples[::97], teacher.samples[::97]):
            self.assertEqual(a.time_s, b.time_s)
            np.testing.assert_array_equal(a.position_m, b.position_m)
        with self.assertRaisesRegex(cg.DataError, "mine"):
            cg.TeacherRecording.from_json("{}", source="mine")  # `source` names the text in errors
        with tempfile.TemporaryDirectory(prefix="round18c-") as folder:
            path = Path(folder) / "teacher.json"
            teacher.save(path)
            self.assertEqual(cg.TeacherRecording.load(path).to_json(), teacher.to_json())
            with self.assertRaisesRegex(cg.DataError, "absent.json"):
                cg.TeacherRecording.load(Path(folder) / "absent.json")
            with self.assertRaises(cg.InvalidArgument):
                teacher.save("")
            with self.assertRaisesRegex(cg.Error, "teacher.json"):
                teacher.save(Path(folder) / "no" / "teacher.json")
            self.assertEqual(sorted(os.listdir(folder)), ["teacher.json"])  # no temporary left
        with self.assertRaises(TypeError):
            cg.TeacherSample(time_s=0.0)  # both keywords are required (the stubs give no default)

    def test_the_simulated_device_behaves_as_its_docstrings_say(self):
        device = cg.SimulatedDevice(cg.SimulatedDeviceParameters(initial_position_m=(0, 0, 0.02)))
        self.assertTrue(device.is_open)  # "Opened on creation"
        device.write_force([1.0, 0, 0])
        device.advance(1e-3)
        state = device.read_state()
        self.assertEqual((state.position_m.shape, state.velocity_m_s.shape), ((3,), (3,)))
        self.assertGreater(device.true_position_m[0], 0.0)  # moved along the force
        self.assertAlmostEqual(state.time_s, 1e-3)
        device.write_force([100.0, 0, 0])  # "saturated at info.max_force_n"
        self.assertAlmostEqual(float(np.linalg.norm(device.applied_force_n)), device.info.max_force_n)
        for bad in (-1e-3, float("nan"), float("inf")):
            with self.assertRaises(cg.InvalidArgument, msg=bad):
                device.advance(bad)
        device.advance(0.0)  # dt_s >= 0
        device.close()  # "Forces off and closed"
        self.assertFalse(device.is_open)
        np.testing.assert_array_equal(device.applied_force_n, [0.0, 0.0, 0.0])
        device.open()
        self.assertTrue(device.is_open)

    def test_the_repetition_rules_are_the_documented_formulas(self):
        rule = cg.AssistBandRule()  # b(n+1) = clamp(b(n) + k (e* - e(n)), b_min, b_max)
        self.assertAlmostEqual(cg.next_assist_band(0.001, 0.001), 0.001 + rule.rate * (rule.target_error_m - 0.001))
        self.assertEqual(cg.next_assist_band(0.001, 0.001), cg.next_assist_band(0.001, 0.001, rule))
        self.assertEqual(cg.next_assist_band(0.0039, 0.0), rule.max_band_m)
        self.assertEqual(cg.next_assist_band(0.0, 1.0), rule.min_band_m)
        for band, error in ((-0.001, 0.0), (0.001, -0.001), (0.001, float("nan"))):
            with self.assertRaises(cg.InvalidArgument, msg=(band, error)):
                cg.next_assist_band(band, error)
        threshold = cg.SkillAdaptiveRule().threshold_m  # "fixed at or above threshold_m (2 mm)"
        self.assertEqual(threshold, 0.002)
        self.assertEqual(cg.skill_adaptive_mode(threshold), cg.GuidanceMode.fixed)
        self.assertEqual(cg.skill_adaptive_mode(0.0019), cg.GuidanceMode.error_amplification)
        with self.assertRaises(cg.InvalidArgument):
            cg.skill_adaptive_mode(-0.001)
        log = SharedTrial.get().trial.writer_log
        with self.assertRaises(cg.InvalidArgument):
            cg.RepetitionOutcome.from_log(log, 1.5)  # "a share outside [0, 1]"
        profile = cg.writer_profile("foreign")  # learning_rate 0: "the profile comes back unchanged"
        self.assertEqual(profile.learning_rate, 0.0)
        self.assertEqual(cg.next_repetition_profile(profile, cg.RepetitionOutcome.from_log(log, 1.0)), profile)
        learner = cg.writer_profile("foreign", {"learning_rate": 0.3})
        self.assertNotEqual(cg.next_repetition_profile(learner, cg.RepetitionOutcome.from_log(log, 1.0)), learner)

    def test_match_stroke_and_score_raise_what_their_docstrings_name(self):
        scene = Objects.get()["Scene"]
        median = scene.strokes[0].median_m
        with self.assertRaisesRegex(IndexError, "character_index"):
            cg.match_stroke(scene, 1, 0, median)
        with self.assertRaisesRegex(IndexError, "stroke_index"):
            cg.match_stroke(scene, 0, 2, median)
        for bad in (np.zeros((0, 2)), np.zeros((3, 3)), np.array([[0.0, np.nan]])):
            with self.assertRaisesRegex(cg.InvalidArgument, "path_m"):
                cg.match_stroke(scene, 0, 0, bad)
        with self.assertRaisesRegex(TypeError, "acceptance"):
            cg.match_stroke(scene, 0, 0, median, acceptance="strict")
        with tempfile.TemporaryDirectory(prefix="round18c-") as folder:
            csv = Path(folder) / "trace.csv"
            csv.write_text("t,x,y,pen\n0,0,0,1\n0.001,zero,0,1\n", encoding="utf-8")
            with self.assertRaises(cg.DataError) as bad_row:  # "bad row: naming line and column"
                cg.score(str(csv), SHI)
            self.assertIn("3", str(bad_row.exception))
            self.assertIn("x", str(bad_row.exception))
            with self.assertRaisesRegex(cg.DataError, "absent.csv"):
                cg.score(str(Path(folder) / "absent.csv"), SHI)
        with self.assertRaises(cg.CharacterNotFound):
            cg.score(SharedTrial.get().columns, "é")


if __name__ == "__main__":
    unittest.main(verbosity=2)
