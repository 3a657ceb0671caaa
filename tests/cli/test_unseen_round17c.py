#!/usr/bin/env python3
"""Hostile cases written from the documentation alone (docs/cli.md, docs/python.md, each command's `--help` and
`help()` of the module's public names): the command line and Python are one program, so every documented twin
is held to its other half, a differential test. Run by CTest as `cli_unseen_round17c_tests`. Rounds 12I and 15B
compared one trial and one record across the two; this one takes what they left:

- the same inputs give the same numbers: `trial --json` and `simulate_trial(...).metrics` of one seed (the
  specification's defaults included, a default left out on one side equal to the other's), the largest seed, a
  writer setting, `-0` and a denormal guidance gain, the bounds of the rate, the duration and the miss counts
  accepted by both; `score` of one CSV by both, in metres and in data units, a trace with a byte-order mark, a
  row of two characters as `--character` and as a `Scene`; a session's `.trace.h5` through `trace`, `score` and
  `study.samples`; `report --csv` and `study.load`, `session cohort --csv` and `cohort.simulate`.
- the same bad input is refused by both, naming the same thing: a value past a bound, NaN, infinity, a bool or
  a text for a number, a float for a count, a mode's option without its mode, an unknown writer setting, an
  unknown device, a character neither library has, an unknown unit, a trace with `pen` and `z`; a record out of
  range, contradictory, holding NaN, a bool for a number, a seed of 2^64, checked by `trial --spec --check` and
  `check_trial_record` at the same JSON pointer; a protocol naming a missing character, planned and simulated.
- the same names: `schema metrics` and `metric_table()`, `schema specification` and the keywords and defaults
  of `simulate_trial` and the options of `trial --help`, the CSV header and `trace_columns()`, `characters
  --json` and `CharacterLibrary.default()`, `model --json` and a `Character`, `strokes --json` and
  `TYPICAL_STROKES` (every name `characters --typical` takes, `typical_stroke` takes), `devices --json` and
  `list_devices()`, a `--data` folder and `CharacterLibrary.from_hanzi_writer` of it.

CALLIGRAPHY_CLI names the program; CALLIGRAPHY_SOURCE_DIR the source tree; the built Python package is found on
PYTHONPATH. CALLIGRAPHY_SANITIZED=1 takes a small subset.
"""
import ast
import csv
import io
import json
import math
import os
import shutil
import sys
import tempfile
import unittest
import warnings
from contextlib import nullcontext
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

from outsider import OneErrorLine, run, sanitized_subset  # noqa: E402
from outsider_python import cg, needs_cli, needs_pandas, needs_python, np, pd  # noqa: E402

YI, SHI = "一", "十"
SEED = 1
DURATION = "30"

load_tests = sanitized_subset({"test_trial_json_is_simulate_trial_metrics_defaults_included",
                               "test_score_of_one_csv_is_the_same_dict_on_both_sides",
                               "test_a_record_out_of_range_is_refused_at_one_pointer_by_both",
                               "test_schema_metrics_is_the_metric_table",
                               "test_trace_csv_header_is_trace_columns"})

try:
    import jsonschema
except ImportError:  # pragma: no cover
    jsonschema = None

FOLDER = None


def setUpModule():
    global FOLDER
    FOLDER = Path(tempfile.mkdtemp(prefix="outsider-17c-"))


def tearDownModule():
    if FOLDER is not None:
        shutil.rmtree(FOLDER, ignore_errors=True)


def cli_json(case, *args):
    """`calligraphy ARGS` that must succeed and print one JSON document."""
    result = run(list(args), FOLDER)
    case.assertEqual(result.returncode, 0, result.stderr.decode("utf-8", "replace"))
    return json.loads(result.stdout)


class Shared:
    """One `calligraphy trial 十 --seed 1` with its record and trace, made once."""
    made = False

    @classmethod
    def get(cls, case):
        if not cls.made:
            result = run(["trial", SHI, "--seed", SEED, "--max-duration", DURATION, "--json", "shi.json", "--csv",
                          "shi.csv"], FOLDER)
            case.assertEqual(result.returncode, 0, result.stderr.decode())
            cls.record = json.loads((FOLDER / "shi.json").read_text(encoding="utf-8"))
            cls.csv = FOLDER / "shi.csv"
            cls.made = True
        return cls


def without(d, *keys):
    return {k: v for k, v in d.items() if k not in keys}


def keyword_defaults(function):
    """The keywords of a bound function and their defaults (None where it has none), from the signature its
    docstring's first line states (pybind11's functions have no `inspect.signature`)."""
    first = function.__doc__.strip().splitlines()[0]
    tree = ast.parse("def " + first.split("(", 1)[0] + "(" + first.split("(", 1)[1] + ": pass")
    arguments = tree.body[0].args
    names = [a.arg for a in arguments.args]
    defaults = [None] * (len(names) - len(arguments.defaults)) + [ast.literal_eval(d) for d in arguments.defaults]
    return dict(zip(names, defaults))


def same_numbers(case, a, b, path=""):
    """a and b equal, every number bit for bit (NaN and None alike, -0 and 0 told apart)."""
    if isinstance(a, dict):
        case.assertIsInstance(b, dict, path)
        case.assertEqual(sorted(a), sorted(b), path)
        for k in a:
            same_numbers(case, a[k], b[k], f"{path}/{k}")
    elif isinstance(a, list):
        case.assertIsInstance(b, list, path)
        case.assertEqual(len(a), len(b), path)
        for i, (x, y) in enumerate(zip(a, b)):
            same_numbers(case, x, y, f"{path}/{i}")
    elif isinstance(a, float) and not isinstance(b, bool) and isinstance(b, (int, float)):
        case.assertEqual(math.copysign(1, a) if a == 0 else a, math.copysign(1, b) if b == 0 else b, path)
    else:
        case.assertEqual(a, b, path)


@needs_cli
@needs_python
class TrialTwins(unittest.TestCase, OneErrorLine):
    """`calligraphy trial` and `simulate_trial`: one trial, one set of bounds, one set of refusals."""

    def python_trial(self, **kw):
        kw.setdefault("seed", SEED)
        kw.setdefault("max_duration_s", float(DURATION))
        return cg.simulate_trial(SHI, keep_trace=False, **kw)

    def cli_record(self, *args, chars=SHI):
        if "--seed" not in args:
            args = ("--seed", str(SEED), *args)
        if "--max-duration" not in args:
            args = ("--max-duration", DURATION, *args)
        result = run(["trial", chars, "--json", "-", *args], FOLDER)
        self.assertIn(result.returncode, (0, 1), result.stderr.decode())
        return json.loads(result.stdout)

    def test_trial_json_is_simulate_trial_metrics_defaults_included(self):
        cli = Shared.get(self).record
        py = json.loads(json.dumps(self.python_trial().metrics))
        # The same keys and the same numbers, and the same whole specification: every default the one side
        # leaves out is the other's.
        same_numbers(self, without(cli, "device_time_at_start_s"), without(py, "device_time_at_start_s"))

    def test_the_largest_seed_and_a_writer_setting_give_the_same_numbers(self):
        top = 2 ** 64 - 1
        cli = self.cli_record("--seed", str(top), "--writer-param", "bias_offset_m=0.001")
        py = json.loads(json.dumps(self.python_trial(seed=top, writer_params={"bias_offset_m": 0.001}).metrics))
        self.assertEqual(cli["seed"], top)
        self.assertEqual(cli["specification"]["trial"]["writer_parameters"],
                         py["specification"]["trial"]["writer_parameters"])
        same_numbers(self, without(cli, "device_time_at_start_s"), without(py, "device_time_at_start_s"))

    def test_minus_zero_and_a_denormal_gain_are_taken_alike(self):
        for text, value in (("-0", -0.0), ("1e-320", 1e-320)):
            with self.subTest(gain=text):
                cli = self.cli_record("--guidance-mode", "fading", "--guidance-gain", text)
                py = json.loads(json.dumps(self.python_trial(guidance_mode="fading", guidance_gain=value).metrics))
                self.assertEqual(cli["specification"]["trial"]["guidance_gain"],
                                 py["specification"]["trial"]["guidance_gain"])
                same_numbers(self, without(cli, "device_time_at_start_s"), without(py, "device_time_at_start_s"))

    def test_bounds_accepted_by_one_are_accepted_by_the_other(self):
        # The ends of the documented ranges: rate 100 and 100000 Hz (a short trial), 1000 refused attempts.
        cases = [(("--rate", "100", "--max-duration", "0.5"), {"rate_hz": 100, "max_duration_s": 0.5}),
                 (("--rate", "100000", "--max-duration", "0.01"), {"rate_hz": 100000, "max_duration_s": 0.01}),
                 (("--hint-after-misses", "1000", "--assist-after-misses", "0"),
                  {"hint_after_misses": 1000, "assist_after_misses": 0})]
        for args, kw in cases:
            with self.subTest(args=args):
                result = run(["trial", SHI, "--check", *args], FOLDER)
                self.assertEqual(result.returncode, 0, result.stderr.decode())
                kw.setdefault("max_duration_s", float(DURATION))
                # (100 Hz warns of the passivity bound, below; caught here so that it is not printed)
                with self.assertLogs("calligraphy", "WARNING") if kw.get("rate_hz") == 100 else nullcontext():
                    r = cg.simulate_trial(SHI, keep_trace=False, **kw)
                    cg.flush_log()
                self.assertIn(r.metrics["end_reason"], ("completed", "time_limit"))

    def test_the_same_warnings_reach_both_sides(self):
        # At 100 Hz the default stiffnesses are above the passivity bound: the command line says so on standard
        # error as its own warning lines, Python through the "calligraphy" logger, in the same words.
        result = run(["trial", SHI, "--rate", "100", "--max-duration", "0.5"], FOLDER)
        self.assertEqual(result.returncode, 1)  # the time limit ends it early
        prefix = "calligraphy trial: warning: "
        cli = [line[len(prefix):] for line in result.stderr.decode().splitlines() if line.startswith(prefix)]
        with self.assertLogs("calligraphy", "WARNING") as logged:
            cg.simulate_trial(SHI, rate_hz=100, max_duration_s=0.5, seed=SEED, keep_trace=False)
            cg.flush_log()
        self.assertTrue(cli)
        self.assertEqual(cli, [record.getMessage() for record in logged.records])

    def test_duration_past_its_bound_is_refused_by_both(self):
        # (0, 86400] s in the specification: 86400.5 s at 100 Hz is within the 10^7 ticks but past the bound.
        for value in ("0", "86400.5", "-1"):
            with self.subTest(max_duration=value):
                result = run(["trial", SHI, "--rate", "100", f"--max-duration={value}", "--check"], FOLDER)
                self.assert_one_error(result, 2, "--max-duration")
                with self.assertRaises(cg.InvalidArgument) as caught:
                    cg.simulate_trial(SHI, rate_hz=100, max_duration_s=float(value), keep_trace=False)
                self.assertIn("max_duration_s", str(caught.exception))

    def test_rate_past_its_bounds_nan_and_infinity_refused_by_both(self):
        for value in ("99.999", "100000.01", "nan", "inf"):
            with self.subTest(rate=value):
                result = run(["trial", SHI, "--rate", value, "--check"], FOLDER)
                self.assert_one_error(result, 2, "--rate")
                with self.assertRaises(cg.InvalidArgument) as caught:
                    cg.simulate_trial(SHI, rate_hz=float(value), keep_trace=False)
                self.assertIn("rate_hz", str(caught.exception))

    def test_a_bool_or_text_for_a_number_and_a_float_for_a_count_are_type_errors(self):
        for text in ("true", "1000Hz"):
            self.assert_one_error(run(["trial", SHI, "--rate", text, "--check"], FOLDER), 2, "--rate")
        self.assert_one_error(run(["trial", SHI, "--hint-after-misses", "1.0", "--check"], FOLDER), 2,
                              "--hint-after-misses")
        for keyword, value in (("rate_hz", True), ("rate_hz", "1000"), ("hint_after_misses", 1.0),
                               ("seed", 1.0), ("max_duration_s", "5")):
            with self.subTest(keyword=keyword, value=value):
                with self.assertRaises(TypeError) as caught:
                    cg.simulate_trial(SHI, keep_trace=False, **{keyword: value})
                self.assertIn(keyword, str(caught.exception))

    def test_counts_and_seeds_past_their_bounds_refused_naming_them(self):
        for option, keyword, value in (("--hint-after-misses", "hint_after_misses", 1001),
                                       ("--assist-after-misses", "assist_after_misses", -1),
                                       ("--seed", "seed", 2 ** 64)):
            with self.subTest(option=option):
                self.assert_one_error(run(["trial", SHI, f"{option}={value}", "--check"], FOLDER), 2, option)
                with self.assertRaises(cg.InvalidArgument) as caught:
                    cg.simulate_trial(SHI, keep_trace=False, **{keyword: value})
                self.assertIn(keyword, str(caught.exception))

    def test_a_modes_option_without_its_mode_is_refused_by_both(self):
        line = self.assert_one_error(run(["trial", SHI, "--guidance-gain", "0.5", "--check"], FOLDER), 2,
                                     "--guidance-gain")
        self.assertIn("fading", line)
        with self.assertRaises(cg.InvalidArgument) as caught:
            cg.simulate_trial(SHI, guidance_gain=0.5, keep_trace=False)
        self.assertIn("guidance_gain", str(caught.exception))
        self.assert_one_error(run(["trial", SHI, "--guidance", "off", "--guidance-mode", "fading", "--check"],
                                  FOLDER), 2, "--guidance-mode")
        with self.assertRaises(cg.InvalidArgument) as caught:
            cg.simulate_trial(SHI, guidance=False, guidance_mode="fading", keep_trace=False)
        self.assertIn("guidance_mode", str(caught.exception))
        # A teacher implies replay: with guidance off it is the same contradiction, not an unguided trial
        # recorded as 'fixed'.
        teacher = [cg.TeacherSample(time_s=t, position_m=(0.0, -0.05, 0.0)) for t in (0.0, 0.001)]
        with self.assertRaises(cg.InvalidArgument) as caught:
            cg.simulate_trial(SHI, guidance=False, teacher=teacher, keep_trace=False)
        self.assertIn("guidance_mode", str(caught.exception))
        # guidance_mode 'fixed' with guidance off is no contradiction on either side.
        self.assertEqual(run(["trial", SHI, "--guidance", "off", "--guidance-mode", "fixed", "--check"],
                             FOLDER).returncode, 0)
        r = cg.simulate_trial(SHI, guidance=False, guidance_mode="fixed", max_duration_s=0.01, keep_trace=False)
        self.assertFalse(r.metrics["specification"]["trial"]["guidance"])

    def test_an_unknown_writer_setting_is_refused_by_both_naming_it(self):
        self.assert_one_error(run(["trial", SHI, "--writer-param", "no_such_key=1", "--check"], FOLDER), 2,
                              "no_such_key")
        with self.assertRaises(cg.InvalidArgument) as caught:
            cg.simulate_trial(SHI, writer_params={"no_such_key": 1.0}, keep_trace=False)
        self.assertIn("no_such_key", str(caught.exception))

    def test_a_mode_by_its_member_name_is_the_spelling_in_python_and_refused_on_the_command_line(self):
        self.assert_one_error(run(["trial", SHI, "--guidance-mode", "assist_as_needed", "--check"], FOLDER), 2,
                              "--guidance-mode")
        with warnings.catch_warnings(record=True) as seen:
            warnings.simplefilter("always")
            r = self.python_trial(guidance_mode="assist_as_needed")
        self.assertTrue(any(issubclass(w.category, DeprecationWarning) and "assist-as-needed" in str(w.message)
                            for w in seen), [str(w.message) for w in seen])
        py = json.loads(json.dumps(r.metrics))
        self.assertEqual(py["specification"]["trial"]["guidance_mode"], "assist-as-needed")
        cli = self.cli_record("--seed", str(SEED), "--guidance-mode", "assist-as-needed")
        same_numbers(self, without(cli, "device_time_at_start_s"), without(py, "device_time_at_start_s"))

    def test_a_character_neither_library_has_each_side_in_its_own_words(self):
        self.assert_one_error(run(["trial", "A", "--max-duration", "1"], FOLDER), 2, "A")
        with self.assertRaises(cg.CharacterNotFound) as caught:
            cg.simulate_trial("A", keep_trace=False)
        self.assertIsInstance(caught.exception, KeyError)
        self.assertNotIn("--data", str(caught.exception))
        self.assertIn("from_hanzi_writer", str(caught.exception))

    def test_a_character_outside_the_embedded_set_is_written_by_both(self):
        # Every hanzi-writer-data character is there by default on both sides, not only the 58 embedded.
        character = next(c for c in "丁七乃" if c not in cg.CharacterLibrary.embedded())
        cli = self.cli_record("--seed", "0", "--max-duration", "5", chars=character)
        py = json.loads(json.dumps(cg.simulate_trial(character, max_duration_s=5.0, keep_trace=False).metrics))
        same_numbers(self, without(cli, "device_time_at_start_s"), without(py, "device_time_at_start_s"))

    def test_odd_character_strings_are_refused_alike(self):
        # Nothing, a space, a variation selector after a character, 1001 characters (a scene's limit is 1000):
        # each refused by both, naming the argument (CHARS / characters) and what is wrong.
        cases = [("", 2, cg.InvalidArgument, "no character"),
                 (SHI + " " + YI, 2, cg.CharacterNotFound, "U+0020"),
                 (SHI + "\ufe00", 2, cg.CharacterNotFound, "U+FE00"),
                 (SHI * 1001, 1, cg.InvalidArgument, "1000")]
        for chars, status, error, needle in cases:
            with self.subTest(chars=chars[:3]):
                self.assert_one_error(run(["trial", chars, "--max-duration", "0.01", "--json", "/dev/null"],
                                          FOLDER), status, "CHARS", needle)
                with self.assertRaises(error) as caught:
                    cg.simulate_trial(chars, max_duration_s=0.01, keep_trace=False)
                self.assertIn(needle, str(caught.exception))
                if error is cg.InvalidArgument:
                    self.assertIn("characters", str(caught.exception))

    def test_writer_settings_refused_and_taken_alike(self):
        for text, value, kind in (("nan", float("nan"), cg.InvalidArgument), ("true", True, TypeError),
                                  ("0.3x", "0.3x", TypeError)):
            with self.subTest(value=text):
                self.assert_one_error(run(["trial", SHI, "--writer-param", f"learning_rate={text}", "--check"],
                                          FOLDER), 2, "--writer-param", "learning_rate")
                with self.assertRaises(kind) as caught:
                    cg.simulate_trial(SHI, writer_params={"learning_rate": value}, keep_trace=False)
                self.assertIn("writer_params['learning_rate']", str(caught.exception))
        # a denormal, -0, the profile's own value, two settings in an order: the same record on both sides
        default = cg.writer_profile("novice").bias_offset_m
        for settings in ({"learning_rate": 1e-320}, {"learning_rate": -0.0}, {"bias_offset_m": default},
                         {"learning_rate": 0.3, "bias_offset_m": 0.001}):
            with self.subTest(settings=settings):
                args = [a for k, v in settings.items() for a in ("--writer-param", f"{k}={v!r}")]
                cli = self.cli_record(*args, "--max-duration", "1")
                py = json.loads(json.dumps(self.python_trial(writer_params=settings, max_duration_s=1.0).metrics))
                self.assertEqual(cli["specification"]["trial"]["writer_parameters"],
                                 [{"key": k, "value": v} for k, v in settings.items()])
                same_numbers(self, without(cli, "device_time_at_start_s"), without(py, "device_time_at_start_s"))
        # the tick limit: both name the duration
        self.assert_one_error(run(["trial", SHI, "--rate", "100000", "--max-duration", "100.001", "--check"],
                                  FOLDER), 2, "--max-duration", "--rate")
        with self.assertRaises(cg.InvalidArgument) as caught:
            cg.simulate_trial(SHI, rate_hz=100000, max_duration_s=100.001, keep_trace=False)
        self.assertIn("max_duration_s", str(caught.exception))

    def test_an_unknown_device_is_named_with_the_devices_there_are(self):
        line = self.assert_one_error(run(["trial", SHI, "--device", "no-such-arm", "--max-duration", "1"], FOLDER),
                                     2, "no-such-arm")
        self.assertIn("simulated", line)
        with self.assertRaises(cg.DeviceNotFound) as caught:
            cg.run_trial(SHI, device="no-such-arm", max_duration_s=1.0, keep_trace=False)
        self.assertIsInstance(caught.exception, LookupError)
        self.assertIn("no-such-arm", str(caught.exception))
        self.assertIn("simulated", str(caught.exception))

    def test_run_trial_on_the_simulated_device_is_the_command_lines_trial(self):
        cli = Shared.get(self).record
        py = json.loads(json.dumps(cg.run_trial(SHI, seed=SEED, max_duration_s=float(DURATION),
                                                keep_trace=False).metrics))
        same_numbers(self, without(cli, "device_time_at_start_s"), without(py, "device_time_at_start_s"))


@needs_cli
@needs_python
class RecordTwins(unittest.TestCase, OneErrorLine):
    """`trial --spec RECORD --check` and `check_trial_record`: one reading of a record."""

    def both(self, record, name):
        path = FOLDER / name
        path.write_text(json.dumps(record), encoding="utf-8")
        result = run(["trial", "--spec", path.name, "--check"], FOLDER)
        try:
            back = cg.check_trial_record(record)
            error = None
        except (cg.DataError, cg.InvalidArgument, TypeError) as e:
            back, error = None, e
        return result, back, error

    def edited(self, pointer, value):
        record = json.loads(json.dumps(Shared.get(self).record))
        node = record
        parts = pointer.strip("/").split("/")
        for p in parts[:-1]:
            node = node[p]
        node[parts[-1]] = value
        return record

    def test_a_record_out_of_range_is_refused_at_one_pointer_by_both(self):
        for pointer, value in (("/specification/trial/rate_hz", 99.0),
                               ("/specification/trial/seed", 2 ** 64),
                               ("/specification/force_law/crossfade_s", -1.0),
                               ("/specification/trial/rate_hz", True),
                               ("/specification/trial/max_duration_s", "5")):
            with self.subTest(pointer=pointer, value=value):
                result, back, error = self.both(self.edited(pointer, value), "range.json")
                self.assert_one_error(result, 2, pointer)
                self.assertIsNotNone(error, f"check_trial_record took {pointer} = {value!r}")
                self.assertIsInstance(error, cg.DataError)
                self.assertIn(pointer, str(error))

    def test_a_contradiction_is_refused_naming_the_field_by_both(self):
        record = self.edited("/specification/trial/guidance", False)
        record["specification"]["trial"]["guidance_mode"] = "fading"
        result, back, error = self.both(record, "contradiction.json")
        # The command line refuses the record's content at its pointer (exit 2); Python as a DataError, the
        # class of a record's content refused (docs/python.md, "Errors"), naming the same pointer and field.
        self.assert_one_error(result, 2, "/specification/trial", "guidance_mode")
        self.assertIsInstance(error, cg.DataError)
        self.assertIn("/specification/trial", str(error))
        self.assertIn("guidance_mode", str(error))

    def test_nan_in_a_record_is_refused_by_both(self):
        # JSON has no NaN; Python's json writes it, nlohmann's reader refuses the text, and a dict holding it is
        # refused at its pointer.
        record = self.edited("/specification/trial/guidance_gain", float("nan"))
        result, back, error = self.both(record, "nan.json")
        self.assert_one_error(result, 2, "nan.json")
        self.assertIsNotNone(error, "check_trial_record took NaN")
        self.assertIn("/specification/trial/guidance_gain", str(error))

    def test_values_at_their_bounds_come_back_the_same_from_both(self):
        record = self.edited("/specification/trial/seed", 2 ** 64 - 1)
        record["specification"]["force_law"]["crossfade_s"] = 1e-320
        record["specification"]["trial"]["guidance_mode"] = "fading"
        record["specification"]["trial"]["guidance_gain"] = -0.0
        record["specification"]["force_law"]["guidance_law"] = {"mode": "fading", "gain": -0.0}
        result, back, error = self.both(record, "bounds.json")
        self.assertEqual(result.returncode, 0, result.stderr.decode())
        self.assertIsNone(error)
        self.assertEqual(back["trial"]["seed"], 2 ** 64 - 1)
        self.assertEqual(back["force_law"]["crossfade_s"], 1e-320)
        # What Python writes back is taken again by the command line, unchanged.
        again = FOLDER / "bounds-back.json"
        again.write_text(json.dumps(back), encoding="utf-8")
        self.assertEqual(run(["trial", "--spec", again.name, "--check"], FOLDER).returncode, 0)
        self.assertEqual(cg.check_trial_record(back), back)

    def test_a_python_record_rerun_by_the_command_line_is_the_same_trial(self):
        r = cg.simulate_trial(SHI, seed=3, max_duration_s=float(DURATION), writer="skilled")
        path = FOLDER / "python-record.json"
        path.write_text(json.dumps(r.metrics), encoding="utf-8")
        result = run(["trial", "--spec", path.name, "--json", "-", "--csv", "python-rerun.csv"], FOLDER)
        self.assertEqual(result.returncode, 0, result.stderr.decode())
        cli = json.loads(result.stdout)
        same_numbers(self, without(cli, "device_time_at_start_s"),
                     without(json.loads(json.dumps(r.metrics)), "device_time_at_start_s"))
        rows = list(csv.DictReader(io.StringIO((FOLDER / "python-rerun.csv").read_text(encoding="utf-8"))))
        self.assertEqual(len(rows), len(r.time_s))
        # x, y, z to 0.1 um, as the CSV writes them.
        for i in (0, len(rows) // 2, len(rows) - 1):
            for axis, name in enumerate("xyz"):
                self.assertAlmostEqual(float(rows[i][name]), r.position_m[i, axis], delta=0.5e-7)


@needs_cli
@needs_python
class ScoreTwins(unittest.TestCase, OneErrorLine):
    """`calligraphy score` and `calligraphy.score`: one scorer."""

    def cli_score(self, trace, *args):
        return cli_json(self, "score", trace, *args, "--json", "-")

    def test_score_of_one_csv_is_the_same_dict_on_both_sides(self):
        shared = Shared.get(self)
        cli = self.cli_score(str(shared.csv), "--character", SHI)
        py = json.loads(json.dumps(cg.score(str(shared.csv), SHI)))
        self.assertEqual(cli["units"], "m")
        same_numbers(self, {k: cli[k] for k in py}, py)
        self.assertEqual(set(cli) - set(py), {"character", "trace", "units", "samples"} - set(py))

    def test_score_in_data_units_and_with_a_byte_order_mark_alike(self):
        shared = Shared.get(self)
        scene = cg.Scene(SHI)
        rows = list(csv.DictReader(io.StringIO(shared.csv.read_text(encoding="utf-8"))))
        xy = np.array([[float(r["x"]), float(r["y"])] for r in rows])
        data = scene.characters[0].placement.to_data(xy)
        text = "t,x,y,z\n" + "".join(f"{r['t']},{d[0]!r},{d[1]!r},{r['z']}\n" for r, d in zip(rows, data))
        path = FOLDER / "data-units.csv"
        path.write_bytes(b"\xef\xbb\xbf" + text.replace("\n", "\r\n").encode("utf-8"))
        cli = self.cli_score(str(path), "--character", SHI, "--units", "data")
        py = json.loads(json.dumps(cg.score(str(path), SHI, units="data")))
        same_numbers(self, {k: cli[k] for k in py}, py)
        self.assertEqual(cli["samples"], len(rows))

    def test_a_row_of_two_characters_as_option_and_as_scene(self):
        result = run(["trial", SHI + YI, "--seed", "2", "--max-duration", "40", "--csv", "row.csv"], FOLDER)
        self.assertIn(result.returncode, (0, 1), result.stderr.decode())
        cli = self.cli_score(str(FOLDER / "row.csv"), "--character", SHI + YI)
        py = json.loads(json.dumps(cg.score(str(FOLDER / "row.csv"), cg.Scene(SHI + YI))))
        same_numbers(self, {k: cli[k] for k in py}, py)
        self.assertEqual(len(py["per_character"]), 2)
        # the characters as text, as --character takes them: the same row
        as_text = json.loads(json.dumps(cg.score(str(FOLDER / "row.csv"), SHI + YI)))
        same_numbers(self, as_text, py)
        # data units are one character's: two refused by both, naming the units
        self.assert_one_error(run(["score", "row.csv", "--character", SHI + YI, "--units", "data"], FOLDER), 2,
                              "--units")
        for character in (SHI + YI, cg.Scene(SHI + YI)):
            with self.assertRaises(cg.InvalidArgument) as caught:
                cg.score(str(FOLDER / "row.csv"), character, units="data")
            self.assertIn("units", str(caught.exception))

    def test_an_unknown_unit_is_refused_by_both_naming_it(self):
        shared = Shared.get(self)
        self.assert_one_error(run(["score", shared.csv.name, "--character", SHI, "--units", "mm"], FOLDER), 2,
                              "--units")
        with self.assertRaises(cg.InvalidArgument) as caught:
            cg.score(str(shared.csv), SHI, units="mm")
        self.assertIn("units", str(caught.exception))

    def test_pen_beside_z_is_refused_by_both(self):
        path = FOLDER / "pen-and-z.csv"
        path.write_text("t,x,y,z,pen\n0,0,0,0,1\n0.001,0.001,0,0,1\n", encoding="utf-8")
        line = self.assert_one_error(run(["score", path.name, "--character", SHI], FOLDER), (1, 2), "pen")
        self.assertIn("z", line)
        with self.assertRaises(cg.DataError) as caught:
            cg.score(str(path), SHI)
        self.assertIn("pen", str(caught.exception))
        columns = {"t": [0.0, 0.001], "x": [0.0, 0.001], "y": [0.0, 0.0], "z": [0.0, 0.0], "pen": [1, 1]}
        with self.assertRaises(cg.InvalidArgument) as caught:
            cg.score({k: np.array(v) for k, v in columns.items()}, SHI)
        self.assertIn("pen", str(caught.exception))

    def test_a_character_neither_library_has_is_refused_by_both(self):
        shared = Shared.get(self)
        self.assert_one_error(run(["score", shared.csv.name, "--character", "A"], FOLDER), 2, "--character")
        with self.assertRaises(cg.CharacterNotFound):
            cg.score(str(shared.csv), "A")

    def test_the_contact_threshold_default_is_the_command_lines_half_millimetre(self):
        # z = 0.5 mm touches on both sides, 0.5 mm + 1 um does not: three samples down, then three lifted.
        path = FOLDER / "contact.csv"
        scene = cg.Scene(SHI)
        stroke = scene.strokes[0]
        line = [stroke.start_m + (stroke.end_m - stroke.start_m) * f for f in np.linspace(0, 1, 60)]
        rows = ["t,x,y,z"]
        for i, p in enumerate(line):
            z = 0.0005 if i < 50 else 0.000501
            rows.append(f"{i * 0.01!r},{p[0]!r},{p[1]!r},{z!r}")
        path.write_text("\n".join(rows) + "\n", encoding="utf-8")
        cli = self.cli_score(str(path), "--character", SHI)
        py = json.loads(json.dumps(cg.score(str(path), SHI)))
        same_numbers(self, {k: cli[k] for k in py}, py)
        self.assertEqual(py["pen_down_time_s"], cli["pen_down_time_s"])
        self.assertAlmostEqual(py["pen_down_time_s"], 0.49, places=9)


@needs_cli
@needs_python
class NameTwins(unittest.TestCase, OneErrorLine):
    """The names, units, defaults and listings both sides print from one table."""

    def test_schema_metrics_is_the_metric_table(self):
        schema = cli_json(self, "schema", "metrics")
        table = {m["name"]: m for m in cg.metric_table() if "scene" in m["levels"]}
        self.assertEqual(set(schema["properties"]), set(table))
        self.assertEqual(set(schema["required"]), set(table))
        kinds = {"number": {"number", "null"}, "count": {"integer"}, "flag": {"boolean"}}
        for name, m in table.items():
            prop = schema["properties"][name]
            types = prop["type"] if isinstance(prop["type"], list) else [prop["type"]]
            self.assertEqual(set(types), kinds[m["kind"]], name)
            if m["unit"]:
                self.assertIn(f"[{m['unit']}]", prop["description"], name)
        # and every key a trial's metrics dict has at its top level that the table names is one of them
        self.assertTrue(set(table) <= set(Shared.get(self).record))

    @unittest.skipIf(jsonschema is None, "jsonschema is not installed")
    def test_what_python_writes_is_valid_against_the_command_lines_schemas(self):
        # A record, its specification written back, its trial part and its metrics from Python, and a score of
        # columns, each valid against `calligraphy schema record|specification|metrics`.
        record_schema = cli_json(self, "schema", "record")
        r = cg.simulate_trial(SHI, seed=SEED, max_duration_s=5.0, keep_trace=False, guidance_mode="timing",
                              writer_params={"learning_rate": 0.3})
        jsonschema.validate(r.metrics["specification"], record_schema)
        jsonschema.validate(cg.check_trial_record(r.metrics), record_schema)
        jsonschema.validate(r.metrics["specification"]["trial"], cli_json(self, "schema", "specification"))
        metrics_schema = cli_json(self, "schema", "metrics")
        jsonschema.validate(json.loads(json.dumps(r.metrics)), metrics_schema)
        jsonschema.validate(json.loads(json.dumps(Shared.get(self).record)), metrics_schema)
        columns = {"t": [0.0, 0.001], "x": [0.0, 0.0], "y": [0.0, 0.0], "pen": [1, 1]}
        jsonschema.validate(json.loads(json.dumps(cg.score({k: np.array(v) for k, v in columns.items()}, SHI))),
                            metrics_schema)

    def test_specification_defaults_are_simulate_trials_defaults(self):
        schema = cli_json(self, "schema", "specification")
        props = schema["properties"]
        signature = keyword_defaults(cg.simulate_trial)
        for field in ("guidance", "rate_hz", "seed", "max_duration_s"):
            with self.subTest(field=field):
                self.assertEqual(props[field]["default"], signature[field])
        acceptance = cg.StrokeAcceptance()
        for field in ("hint_after_misses", "assist_after_misses", "corridor_m", "end_gap_m"):
            with self.subTest(field=field):
                self.assertEqual(props[field]["default"], getattr(acceptance, field))
        self.assertEqual(props["writer_profile"]["default"], signature["writer"])
        law = cg.ForceLawParameters()
        self.assertEqual(props["guidance_stiffness_n_per_m"]["default"], law.guidance_stiffness_n_per_m)

    def test_every_python_keyword_has_its_option_and_back(self):
        # docs/cli.md: a field's option is its name dashed, a length's _m dropped; rate_hz is --rate,
        # max_duration_s --max-duration, writer_parameters --writer-param, watchdog_s --watchdog-ms.
        help_text = run(["trial", "--help"], FOLDER).stdout.decode()
        spec = cli_json(self, "schema", "specification")["properties"]
        special = {"rate_hz": "--rate", "max_duration_s": "--max-duration", "writer_parameters": "--writer-param",
                   "watchdog_s": "--watchdog-ms", "guidance_stiffness_n_per_m": "--guidance-stiffness",
                   "timing_speed_m_s": "--timing-speed", "json_file": "--json", "csv_file": "--csv",
                   "svg_file": "--svg", "record_file": "--record", "characters": None}
        for field in spec:
            option = special.get(field, "--" + (field[:-2] if field.endswith("_m") else field).replace("_", "-"))
            if option is not None:
                self.assertIn(option + " ", help_text, field)
        keywords = keyword_defaults(cg.simulate_trial)
        mapped = {"writer": "--writer-profile", "writer_params": "--writer-param", "library": "--data",
                  "rate_hz": "--rate", "max_duration_s": "--max-duration"}
        for keyword in ("guidance", "rate_hz", "seed", "max_duration_s", "writer", "writer_params",
                        "guidance_mode", "guidance_gain", "teacher", "hint_after_misses", "assist_after_misses"):
            self.assertIn(keyword, keywords)
            option = mapped.get(keyword, "--" + keyword.replace("_", "-"))
            self.assertIn(option + " ", help_text, keyword)

    def test_trace_csv_header_is_trace_columns(self):
        header = Shared.get(self).csv.read_text(encoding="utf-8").splitlines()[0].split(",")
        columns = cg.trace_columns()
        self.assertEqual(header, [c["file_name"] for c in columns])
        r = cg.simulate_trial(YI, seed=SEED, max_duration_s=0.01)
        if pd is not None:
            self.assertEqual(list(r.to_dataframe().columns), [c["name"] for c in columns])
        for c in columns:
            if c["unit"]:
                self.assertTrue(c["name"].endswith("_" + c["unit"].lower()), c)

    def test_characters_listing_is_the_default_library(self):
        listing = cli_json(self, "characters", "--json")
        lib = cg.CharacterLibrary.default()
        names = [c["character"] for c in listing["characters"]]
        self.assertEqual(listing["count"], len(lib))
        self.assertEqual(sorted(names), lib.characters())
        self.assertEqual(len(set(names)), len(names))
        for entry in listing["characters"][:: max(1, len(names) // 40)]:
            character = lib.load(entry["character"])
            self.assertEqual(entry["strokes"], len(character.strokes), entry)
            self.assertEqual(entry["typical_ids"], list(character.typical_stroke_ids), entry)
            self.assertEqual(entry["code_point"], f"U+{ord(entry['character']):04X}")

    def test_characters_text_not_found_is_what_the_library_lacks(self):
        text = "十A\u3000一。\U0002A6D6"
        listing = cli_json(self, "characters", "--text", text, "--json")
        lib = cg.CharacterLibrary.default()
        found = [c["character"] for c in listing["characters"]]
        self.assertEqual(found, [c for c in text if c in lib and not c.isspace()])
        self.assertEqual(listing["not_found"], [c for c in text if c not in lib and not c.isspace()])

    def test_model_json_is_the_python_character(self):
        model = cli_json(self, "model", SHI, "--json")
        character = cg.CharacterLibrary.default().load(SHI)
        self.assertEqual([s["acronym"] for s in model["strokes"]], [s.acronym for s in character.strokes])
        for stroke_json, stroke in zip(model["strokes"], character.strokes):
            self.assertEqual(len(stroke_json["elements"]), len(stroke.elements))
            self.assertEqual(stroke_json["attraction_factors"], list(stroke.attraction_factors))
            for e_json, e in zip(stroke_json["elements"], stroke.elements):
                self.assertEqual(e_json["kind"], e.kind)
                self.assertEqual(e_json["degree"], e.degree)
                self.assertEqual(e_json["control_points"], e.control_points.tolist())

    def test_strokes_json_is_the_typical_stroke_table(self):
        table = cli_json(self, "strokes", "--json")
        self.assertEqual(len(table), len(cg.TYPICAL_STROKES))
        for entry, stroke in zip(table, cg.TYPICAL_STROKES):
            with self.subTest(stroke=entry["acronym"]):
                self.assertEqual(stroke, cg.typical_stroke(entry["id"]))
                # the stroke character: the JSON gives its code point, Python the character (None for neither)
                code_point = f"U+{ord(stroke.unicode):04X}" if stroke.unicode else None
                self.assertEqual((entry["id"], entry["acronym"], entry["name"], entry["pinyin"], entry["unicode"],
                                  entry["compound"], entry["corner_attraction"], entry["default_attraction"]),
                                 (stroke.id, stroke.acronym, stroke.name_zh, stroke.pinyin, code_point,
                                  stroke.compound, stroke.corner_attraction, stroke.default_attraction))
                # every name `characters --typical` takes, Python's typical_stroke takes
                names = [entry["acronym"].lower(), entry["name"]] + ([stroke.unicode] if stroke.unicode else [])
                for name in names:
                    if stroke.id % 8 == 2:  # the command line for a sample of five strokes (a run each)
                        result = run(["characters", "--typical", name, "--text", SHI], FOLDER)
                        self.assertEqual(result.returncode, 0, result.stderr.decode())
                    self.assertEqual(cg.typical_stroke(name), stroke)
                self.assertEqual(len(entry["template"]), len(stroke.pieces))
                for piece_json, piece in zip(entry["template"], stroke.pieces):
                    # no upper bound: JSON's null, Python's inf
                    self.assertEqual({k: getattr(piece, k) for k in piece_json},
                                     {k: math.inf if k == "max_length" and v is None else v
                                      for k, v in piece_json.items()})
        # an ID past the table: a usage error on one side, InvalidArgument on the other, both naming 40
        result = run(["characters", "--typical", "40"], FOLDER)
        self.assertEqual(result.returncode, 2, result.stderr.decode())
        self.assertIn("--typical", result.stderr.decode())
        with self.assertRaises(cg.InvalidArgument) as caught:
            cg.typical_stroke(40)
        self.assertIn("40", str(caught.exception))

    def test_a_data_folder_is_read_alike(self):
        # A hanzi-writer-data folder with 十 as it is, 人 cut short and no 一: 十 written to the same numbers,
        # 人 refused naming its file (status 1: the library has it but cannot read it), 一 not found (status 2).
        source = Path(os.environ.get("CALLIGRAPHY_SOURCE_DIR", Path(__file__).resolve().parents[2]))
        folder = FOLDER / "hanzi-writer-data"
        folder.mkdir()
        shutil.copy(source / "data" / "hanzi-writer-data" / f"{SHI}.json", folder)
        whole = (source / "data" / "hanzi-writer-data" / "人.json").read_bytes()
        (folder / "人.json").write_bytes(whole[: len(whole) // 2])
        lib = cg.CharacterLibrary.from_hanzi_writer(str(folder))
        result = run(["trial", SHI, "--data", str(folder), "--seed", str(SEED), "--max-duration", DURATION,
                      "--json", "-"], FOLDER)
        self.assertEqual(result.returncode, 0, result.stderr.decode())
        py = json.loads(json.dumps(cg.simulate_trial(SHI, library=lib, seed=SEED, max_duration_s=float(DURATION),
                                                     keep_trace=False).metrics))
        cli = json.loads(result.stdout)
        same_numbers(self, without(cli, "device_time_at_start_s"), without(py, "device_time_at_start_s"))
        self.assert_one_error(run(["trial", "人", "--data", str(folder), "--max-duration", "1"], FOLDER), 1,
                              "人.json")
        with self.assertRaises(cg.DataError) as caught:
            cg.simulate_trial("人", library=lib, max_duration_s=1.0, keep_trace=False)
        self.assertNotIsInstance(caught.exception, cg.CharacterNotFound)
        self.assertIn("人.json", str(caught.exception))
        self.assert_one_error(run(["trial", YI, "--data", str(folder), "--max-duration", "1"], FOLDER), 2, YI)
        with self.assertRaises(cg.CharacterNotFound):
            cg.simulate_trial(YI, library=lib, max_duration_s=1.0, keep_trace=False)

    def test_devices_json_is_list_devices(self):
        cli = cli_json(self, "devices", "--json")
        survey = cg.list_devices()
        by_name = {d["name"]: d for d in cli["devices"]}
        self.assertEqual(cli["any_hardware"], survey.any_hardware)
        self.assertTrue(survey.devices)
        for device in survey.devices:
            with self.subTest(device=device.name):
                self.assertIn(device.name, by_name)
                entry = by_name[device.name]
                self.assertEqual(entry["backend"], device.backend)
                self.assertEqual(entry["hardware"], device.hardware)
                info = device.info.to_dict()
                self.assertEqual({k: (list(v) if isinstance(v, (tuple, list)) else v) for k, v in info.items()},
                                 {k: entry["info"][k] for k in info})
                self.assertEqual(set(entry["info"]), set(info))
        # the one device the command line has and the module has not: its Phantom emulator (docs/python.md)
        self.assertEqual(set(by_name) - {d.name for d in survey.devices}, {"emulated-phantom"})
        with self.assertRaises(cg.DeviceNotFound) as caught:
            cg.run_trial(SHI, device="emulated-phantom", max_duration_s=0.01, keep_trace=False)
        self.assertIn("simulated", str(caught.exception))


PROTOCOL = {"format": "calligraphy-study-protocol", "version": 1, "name": "twins",
            "conditions": [{"name": "h", "mode": "haptic"}, {"name": "v", "mode": "vision"}],
            "test": {"characters": [YI], "conditions": ["h", "v"], "repetitions": 1},
            "trial": {"max_duration_s": 4}}


@needs_cli
@needs_python
@needs_pandas
class StudyTwins(unittest.TestCase, OneErrorLine):
    """Sessions, their tables and traces, and cohorts: the folders one side writes, the other reads alike."""

    @classmethod
    def setUpClass(cls):
        cls.dir = FOLDER / "study-twins"
        cls.dir.mkdir()
        (cls.dir / "p.json").write_text(json.dumps(PROTOCOL), encoding="utf-8")
        made = run(["session", "run", "p.json", "--subjects", "1", "--writer-profile", "skilled", "--out", "study"],
                   cls.dir)
        if made.returncode != 0:
            raise AssertionError(made.stderr.decode())
        import calligraphy.study
        cls.study = calligraphy.study.load(str(cls.dir / "study"))

    def test_report_csv_is_study_load(self):
        tables = self.dir / "tables"
        tables.mkdir()
        result = run(["report", "study", "--csv", "tables"], self.dir)
        self.assertEqual(result.returncode, 0, result.stderr.decode())
        for name, loaded in (("trials", self.study.trials), ("strokes", self.study.strokes)):
            written = pd.read_csv(tables / f"{name}.csv", float_precision="round_trip")
            self.assertEqual(list(written.columns), list(loaded.columns), name)
            self.assertEqual(len(written), len(loaded), name)
            for column in written.columns:
                if column == "trace_file":  # the path as reached from the folder given, which differs here
                    continue
                a, b = written[column], loaded[column]
                if pd.api.types.is_numeric_dtype(b) and not pd.api.types.is_bool_dtype(b):
                    self.assertTrue(np.array_equal(a.to_numpy(float), b.to_numpy(float), equal_nan=True),
                                    f"{name}.{column}")
                else:
                    self.assertEqual([str(x) if not pd.isna(x) else "" for x in a],
                                     [str(x) if not pd.isna(x) else "" for x in b], f"{name}.{column}")

    def test_a_saved_trace_reads_alike_through_trace_score_and_samples(self):
        import calligraphy.study
        label = self.study.trials["trial"].iloc[0] if "trial" in self.study.trials else None
        traces = sorted((self.dir / "study").rglob("*.trace.h5"))
        self.assertTrue(traces)
        trace = traces[0]
        result = run(["trace", str(trace)], self.dir)
        self.assertEqual(result.returncode, 0, result.stderr.decode())
        rows = list(csv.DictReader(io.StringIO(result.stdout.decode())))
        samples = None
        for key, frame in self.study.iter_samples():
            if len(frame) == len(rows) and abs(frame["x_m"].iloc[-1] - float(rows[-1]["x"])) < 1e-7:
                samples = frame
                break
        self.assertIsNotNone(samples, f"no trial's samples match {trace.name} ({label})")
        for name, column in (("t", "t_s"), ("x", "x_m"), ("y", "y_m"), ("z", "z_m"), ("fx", "fx_n")):
            self.assertTrue(np.allclose([float(r[name]) for r in rows], samples[column], rtol=0, atol=0.6e-7),
                            name)
        self.assertEqual([r["state"] for r in rows], [str(s) for s in samples["state"]])
        cli = cli_json(self, "score", str(trace), "--character", YI, "--json", "-")
        py = json.loads(json.dumps(cg.score(samples, YI)))
        self.assertEqual(py["trace"], "<columns>")
        same_numbers(self, {k: cli[k] for k in py if k != "trace"}, without(py, "trace"))

    def test_a_saved_record_rerun_by_python_and_the_command_line_is_its_trace(self):
        # The session's record run again: by trial --spec, the CSV `trace` writes of the saved .trace.h5, byte
        # for byte; by rerun_trial, the positions study.samples reads, to the trace's 0.1 um, exactly.
        record = sorted((self.dir / "study").rglob("trials/*.json"))[0]
        trace = record.with_name(record.name[: -len(".json")] + ".trace.h5")
        saved = run(["trace", str(trace), "--csv", "from-trace.csv"], self.dir)
        again = run(["trial", "--spec", str(record), "--csv", "from-spec.csv"], self.dir)
        self.assertEqual((saved.returncode, again.returncode), (0, 0), again.stderr.decode())
        self.assertEqual((self.dir / "from-trace.csv").read_bytes(), (self.dir / "from-spec.csv").read_bytes())
        r = cg.rerun_trial(str(record))
        samples = dict(self.study.iter_samples())
        matching = [f for f in samples.values() if len(f) == len(r.time_s)
                    and np.array_equal(np.round(r.position_m[:, 0] * 1e7) / 1e7, f["x_m"].to_numpy())]
        self.assertEqual(len(matching), 1)
        for axis, column in enumerate(("x_m", "y_m", "z_m")):
            self.assertTrue(np.array_equal(np.round(r.position_m[:, axis] * 1e7) / 1e7, matching[0][column]),
                            column)

    def test_session_cohort_and_cohort_simulate_give_one_table(self):
        import calligraphy.cohort
        out = self.dir / "cohort"
        out.mkdir()
        result = run(["session", "cohort", "p.json", "--subjects", "2", "--writer-profile", "skilled", "--csv",
                      "cohort", "--jobs", "1"], self.dir)
        self.assertEqual(result.returncode, 0, result.stderr.decode())
        cli = pd.read_csv(out / "trials.csv", float_precision="round_trip")
        py = calligraphy.cohort.simulate(str(self.dir / "p.json"), 2, profile="skilled", workers=1,
                                         progress=False).trials
        self.assertEqual(list(cli.columns), list(py.columns))
        for column in ("subject", "phase", "condition", "characters", "total_time_s", "mean_deviation_m"):
            a, b = cli[column], py[column]
            if pd.api.types.is_numeric_dtype(b):
                self.assertTrue(np.array_equal(a.astype(float), b.astype(float), equal_nan=True), column)
            else:
                self.assertEqual([str(x) for x in a], [str(x) for x in b], column)

    def test_a_plan_a_run_and_a_simulated_cohort_assign_alike(self):
        # Between-subjects groups by subject number and a transfer choice from the library: session plan --json,
        # the tables of session run's folders (study.load) and cohort.simulate's, row for row but for the
        # session's id, its start time and the trace file (docs/python.md, "Simulated cohorts").
        import calligraphy.cohort
        import calligraphy.study
        protocol = {"format": "calligraphy-study-protocol", "version": 1, "name": "between",
                    "conditions": [{"name": "unguided", "mode": "vision"}, {"name": "fixture", "mode": "haptic"}],
                    "phases": [{"phase": "pre-test", "condition": "unguided", "characters": [YI]},
                               {"phase": "training", "conditions": ["unguided", "fixture"],
                                "assignment": "between-subjects", "characters": [YI], "repetitions": 1},
                               {"phase": "transfer", "condition": "unguided", "session": 2, "delay_s": 60,
                                "characters": {"choose": 1, "from": [SHI, "大", "人", "二"]}}],
                    "trial": {"max_duration_s": 4}}
        (self.dir / "between.json").write_text(json.dumps(protocol), encoding="utf-8")
        plan = cli_json(self, "session", "plan", str(self.dir / "between.json"), "--subjects", "3", "--json")
        run_result = run(["session", "run", "between.json", "--subjects", "3", "--out", "between-study"], self.dir)
        self.assertEqual(run_result.returncode, 0, run_result.stderr.decode())
        ran = calligraphy.study.load(str(self.dir / "between-study")).trials
        simulated = calligraphy.cohort.simulate(str(self.dir / "between.json"), 3, workers=1, progress=False).trials
        planned = [(s["id"], s["group"], phase["phase"], block["condition"], "".join(phase["items"]))
                   for s in plan["subjects"] for session in s["sessions"] for phase in session["phases"]
                   for block in phase["blocks"]]
        for name, table in (("session run", ran), ("cohort.simulate", simulated)):
            with self.subTest(source=name):
                rows = [(r.subject, str(r.group), str(r.phase), str(r.condition), r.characters)
                        for r in table.itertuples()]
                self.assertEqual(rows, planned)
        self.assertEqual(list(ran.columns), list(simulated.columns))
        for column in ran.columns:
            if column in ("session", "start_utc", "trace_file", "trace_sha256"):  # no trace in memory
                continue
            a, b = ran[column], simulated[column]
            if pd.api.types.is_float_dtype(b):
                self.assertTrue(np.array_equal(a.to_numpy(float), b.to_numpy(float), equal_nan=True), column)
            else:
                self.assertEqual([None if pd.isna(x) else str(x) for x in a],
                                 [None if pd.isna(x) else str(x) for x in b], column)

    def test_subjects_past_their_bounds_refused_by_both(self):
        for n in ("0", "100001"):
            with self.subTest(subjects=n):
                self.assert_one_error(run(["session", "cohort", "p.json", "--subjects", n, "--csv", "."], self.dir),
                                      2, "--subjects")
                import calligraphy.cohort
                with self.assertRaises(ValueError) as caught:
                    calligraphy.cohort.simulate(str(self.dir / "p.json"), int(n), progress=False)
                self.assertIn("subjects", str(caught.exception))
        import calligraphy.cohort
        with self.assertRaises(TypeError) as caught:
            calligraphy.cohort.simulate(str(self.dir / "p.json"), True, progress=False)
        self.assertIn("subjects", str(caught.exception))

    def test_a_protocol_naming_a_missing_character_refused_by_plan_run_and_simulate(self):
        bad = dict(PROTOCOL, name="missing", test=dict(PROTOCOL["test"], characters=[YI, "A"]))
        (self.dir / "bad.json").write_text(json.dumps(bad), encoding="utf-8")
        for command in (["session", "plan", "bad.json", "--subjects", "1"],
                        ["session", "run", "bad.json", "--subjects", "1", "--out", "bad-out"],
                        ["session", "cohort", "bad.json", "--subjects", "1", "--csv", "."]):
            with self.subTest(command=command[1]):
                self.assert_one_error(run(command, self.dir), 2, "bad.json", "/test/characters/1")
        self.assertFalse((self.dir / "bad-out").exists())
        # a protocol file that cannot be read at all is status 1, for plan as for run
        self.assert_one_error(run(["session", "plan", "none.json", "--subjects", "1"], self.dir), 1, "none.json")
        import calligraphy.cohort
        with self.assertRaises(cg.CharacterNotFound) as caught:
            calligraphy.cohort.simulate(str(self.dir / "bad.json"), 1, progress=False)
        self.assertIn("A", str(caught.exception))


if __name__ == "__main__":
    unittest.main()
