#!/usr/bin/env python3
"""Hostile cases written from the documentation alone (docs/cli.md, docs/experiments.md, docs/python.md, the
commands' `--help` and `calligraphy schema record|protocol|session`): a conformance sweep of the INPUT side,
file kind by file kind. Each kind the program reads (a trial record given to `trial --spec` and Python's
`check_trial_record`, a study protocol, a teacher's recording, a CSV trace, an HDF5 trace, a session folder's
session.json and saved records, a hanzi-writer character file and `--data` folder, a corpus store, cnchar's
order file) gets the same battery: a part missing, `null`, an unknown key, each numeric field of its schema at
its bound (taken) and just past it (refused), NaN, infinities, 1e308, -0, a text for a number, a key given
twice, a byte-order mark, invalid UTF-8, the file cut at several offsets, zero bytes, 50 MB of padding (peak
memory bounded), a FIFO, a folder, a symbolic-link loop and a file of another kind in its place.

What each case asserts is the documented promise: exit 2 for content refused (1 for a file that cannot be read
or damaged data where docs/cli.md says so), one error line naming the file and the JSON pointer or line, no
traceback, no hang, nothing written. Run by CTest as `cli_unseen_round11d_tests`. CALLIGRAPHY_CLI names the
program; the built Python package is found on PYTHONPATH (its cases are skipped without it).
CALLIGRAPHY_SANITIZED=1 takes a small subset.
"""
import copy
import json
import math
import os
import random
import resource
import shutil
import subprocess
import tempfile
import unittest
from pathlib import Path

from outsider import CLI, ENV, TIMEOUT_S, error_lines, run

SOURCE = Path(os.environ.get("CALLIGRAPHY_SOURCE_DIR", Path(__file__).resolve().parents[2]))
SANITIZED = os.environ.get("CALLIGRAPHY_SANITIZED") == "1"
SHI = "十"

heavy = unittest.skipIf(SANITIZED, "several runs of the program: left to the Release run")

try:
    import calligraphy as cg
    import calligraphy.study as cg_study
except ImportError:  # pragma: no cover - a build without the Python bindings
    cg = None
    cg_study = None
needs_python = unittest.skipIf(cg is None, "the Python bindings are not on PYTHONPATH")


# Fields whose documented maximum is the largest double: known, handled elsewhere.
KNOWN_MAX_DOUBLE = ("box_margin_m", "tolerance")

MB50 = 50 * 1024 * 1024
# Peak resident memory allowed for refusing a 50 MB file: the file may be read a block at a time or once, never
# blown up into a DOM of GBs.
RSS_BOUND_KB = 400 * 1024


def run_rss(args, cwd):
    """Runs the program under /usr/bin/time -v and returns (result, peak RSS in kB)."""
    arguments = [a if isinstance(a, bytes) else str(a) for a in args]
    r = subprocess.run(["/usr/bin/time", "-v", CLI, *arguments], cwd=cwd, stdout=subprocess.PIPE,
                       stderr=subprocess.PIPE, timeout=TIMEOUT_S, env=ENV)
    lines = r.stderr.decode("utf-8", "replace").splitlines()
    rss = [int(l.split(":")[1]) for l in lines if "Maximum resident set size" in l]
    own = [l for l in lines if l.startswith("calligraphy")]
    r = subprocess.CompletedProcess(r.args, r.returncode, r.stdout, "\n".join(own).encode())
    return r, rss[0] if rss else 0


# What runs under the sanitizers (CALLIGRAPHY_SANITIZED=1): five cases, one run of the program or a few each.
SANITIZED_SUBSET = {"test_record_cut_empty_refused", "test_record_text_forms_of_numbers_refused_naming_pointer",
                    "test_protocol_null_unknown_text_twice_missing", "test_csv_duplicate_column_and_other_kinds",
                    "test_store_damaged_refused"}


class Base(unittest.TestCase):
    def setUp(self):
        if SANITIZED and self._testMethodName not in SANITIZED_SUBSET:
            self.skipTest("left to the Release run")

    def refused(self, r, codes, *names, what=""):
        """One error line naming every one of `names`, an exit status of `codes`, no traceback."""
        lines = error_lines(r)
        text = r.stderr.decode("utf-8", "replace")
        self.assertIn(r.returncode, codes, f"{what}: exit {r.returncode}, stderr {text!r}")
        self.assertNotIn("Traceback", text, what)
        errors = [l for l in lines if ": error: " in l]
        self.assertEqual(len(errors), 1, f"{what}: one error line expected, got {lines!r}")
        self.assertEqual(len(lines), 1, f"{what}: nothing but the error line expected, got {lines!r}")
        for name in names:
            self.assertIn(name, errors[0], f"{what}: the line should name {name!r}: {errors[0]!r}")
        return errors[0]


def cuts(data, n, seed):
    rng = random.Random(seed)
    return sorted({rng.randrange(1, len(data) - 1) for _ in range(n)})


def make_loop(folder, name):
    """A symbolic link loop: name -> name.b -> name, both inside `folder`."""
    a = Path(folder) / name
    b = Path(folder) / (name + ".b")
    os.symlink(b.name, a)
    os.symlink(a.name, b)
    return a


def make_fifo(folder, name):
    p = Path(folder) / name
    os.mkfifo(p)
    return p


def resolve(schema, node):
    while "$ref" in node:
        ref = node["$ref"].split("/")[-1]
        node = schema["$defs"][ref]
    return node


def numeric_leaves(schema, node, value, pointer):
    """(pointer, schema node) of every numeric leaf of `value` the schema bounds, walking properties."""
    node = resolve(schema, node)
    if isinstance(value, dict):
        props = node.get("properties", {})
        for key, sub in value.items():
            if key in props:
                yield from numeric_leaves(schema, props[key], sub, f"{pointer}/{key}")
    elif isinstance(value, (int, float)) and not isinstance(value, bool):
        if node.get("type") in ("number", "integer") and any(
                k in node for k in ("minimum", "maximum", "exclusiveMinimum", "exclusiveMaximum")):
            yield pointer, node


def set_at(document, pointer, value):
    parts = pointer.strip("/").split("/")
    target = document
    for part in parts[:-1]:
        target = target[int(part)] if isinstance(target, list) else target[part]
    target[parts[-1]] = value


def bound_cases(node):
    """(value, taken?) pairs: each bound and the value just past it."""
    integer = node.get("type") == "integer"
    out = []
    for key, inclusive, direction in (("minimum", True, -1), ("maximum", True, 1),
                                      ("exclusiveMinimum", False, -1), ("exclusiveMaximum", False, 1)):
        if key not in node:
            continue
        b = node[key]
        if integer:
            out.append((b, True) if inclusive else (b - direction, True))
            out.append((b + direction, False) if inclusive else (b, False))
        else:
            b = float(b)
            if not math.isfinite(b) or abs(b) >= 1.7e308:
                continue
            past = math.nextafter(b, direction * math.inf)
            inside = math.nextafter(b, -direction * math.inf)
            out.append((b, True) if inclusive else (inside, True))
            out.append((past, False) if inclusive else (b, False))
    return out


class Shared:
    """A trial record of 十 with its CSV trace and a teacher's recording, a small protocol and one session folder."""
    root = None

    @classmethod
    def make(cls):
        if cls.root is not None:
            return
        cls.root = Path(tempfile.mkdtemp(prefix="r11d-"))
        base = cls.root / "base"
        base.mkdir()
        r = run(["trial", SHI, "--seed", "3", "--writer-profile", "skilled", "--json", "rec.json",
                 "--csv", "rec.csv", "--record", "teacher.json"], cwd=base)
        if r.returncode != 0:
            raise RuntimeError(f"trial failed: {r.stderr!r}")
        cls.record = json.loads((base / "rec.json").read_text())
        cls.record_bytes = (base / "rec.json").read_bytes()
        cls.csv_bytes = (base / "rec.csv").read_bytes()
        cls.teacher_bytes = (base / "teacher.json").read_bytes()
        cls.protocol = {"name": "p11d", "conditions": [{"name": "h", "mode": "haptic"}],
                        "test": {"characters": [SHI], "conditions": ["h"], "repetitions": 1},
                        "trial": {"max_duration_s": 20}}
        (base / "p.json").write_text(json.dumps(cls.protocol, ensure_ascii=False))
        cls.schemas = {}
        for kind in ("record", "protocol", "session"):
            s = run(["schema", kind], cwd=base)
            cls.schemas[kind] = json.loads(s.stdout)
        cls.session = None
        if not SANITIZED:
            r = run(["session", "run", "p.json", "--out", "study", "--subjects", "1"], cwd=base)
            if r.returncode != 0:
                raise RuntimeError(f"session run failed: {r.stderr!r}")
            cls.session = next((base / "study" / "S01").glob("p11d-*"))
            cls.session_json = (cls.session / "session.json").read_bytes()

    @classmethod
    def tmp(cls):
        return Path(tempfile.mkdtemp(dir=cls.root))


def setUpModule():
    if CLI:
        Shared.make()


def tearDownModule():
    if Shared.root is not None:
        shutil.rmtree(Shared.root, ignore_errors=True)


# ---------------------------------------------------------------------------------------------------------
# Trial records: `trial --spec RECORD --check` and Python's check_trial_record
# ---------------------------------------------------------------------------------------------------------
@unittest.skipUnless(CLI, "CALLIGRAPHY_CLI is not set")
class Records(Base):
    def spec(self, content, name="r.json"):
        d = Shared.tmp()
        p = d / name
        p.write_bytes(content if isinstance(content, bytes) else json.dumps(content, ensure_ascii=False).encode())
        return run(["trial", "--spec", p.name, "--check"], cwd=d), d

    def edited(self, pointer, value):
        doc = copy.deepcopy(Shared.record)
        set_at(doc, pointer, value)
        return doc

    def test_record_as_written_is_taken(self):
        r, _ = self.spec(Shared.record_bytes)
        self.assertEqual(r.returncode, 0, r.stderr)

    def test_record_text_forms_of_numbers_refused_naming_pointer(self):
        # NaN, Infinity, hex, 1e999 and a number in quotes at /specification/trial/rate_hz.
        text = Shared.record_bytes.decode()
        # The record's own rate, in its specification (the metrics at the top level are not read back).
        key = '"rate_hz": '
        start = text.index(key, text.index('"trial": ', text.index('"specification": '))) + len(key)
        end = start
        while text[end] not in ",}\n":
            end += 1
        for literal in ("NaN", "Infinity", "-Infinity", "0x3e8", "1e999", '"1000"', "1000 1", ""):
            r, _ = self.spec((text[:start] + literal + text[end:]).encode())
            self.refused(r, (2,), "r.json", what=literal)
        for literal in ('"1000"', "1e999", "null"):
            r, _ = self.spec((text[:start] + literal + text[end:]).encode())
            self.refused(r, (2,), "r.json", "/specification/trial/rate_hz", what=literal)

    @heavy
    def test_record_part_missing_null_unknown_twice_refused(self):
        spec = Shared.record["specification"]
        for part in spec:
            doc = copy.deepcopy(Shared.record)
            del doc["specification"][part]
            r, _ = self.spec(doc)
            self.refused(r, (2,), "r.json", "/specification", what=f"without {part}")
        for part in ("force_law", "safety", "passivity", "scene", "trial"):
            r, _ = self.spec(self.edited(f"/specification/{part}", None))
            self.refused(r, (2,), "r.json", f"/specification/{part}", what=f"{part} null")
        doc = copy.deepcopy(Shared.record)
        doc["specification"]["force_law"]["stiffnes_n_per_m"] = 1
        r, _ = self.spec(doc)
        self.refused(r, (2,), "r.json", "/specification/force_law/stiffnes_n_per_m")
        text = Shared.record_bytes.decode()
        twice = text.replace('"seed": ', '"seed": 1, "seed": ', 1)
        self.assertNotEqual(twice, text)
        r, _ = self.spec(twice.encode())
        self.refused(r, (2,), "r.json", "/seed", what="seed twice")

    def test_record_bom_taken_invalid_utf8_refused(self):
        r, _ = self.spec(b"\xef\xbb\xbf" + Shared.record_bytes)
        self.assertEqual(r.returncode, 0, r.stderr)
        # Invalid UTF-8 inside the writer's profile name: a content error naming the file.
        text = Shared.record_bytes
        i = text.index(b'"writer_profile": "') + len(b'"writer_profile": "')
        r, _ = self.spec(text[:i] + b"\xff\xfe" + text[i:])
        line = self.refused(r, (2,), "r.json")
        self.assertTrue(line.isprintable(), line)

    def test_record_cut_empty_refused(self):
        data = Shared.record_bytes
        for offset in cuts(data, 6, 11) + [0]:
            r, _ = self.spec(data[:offset])
            self.refused(r, (2,), "r.json", what=f"cut at {offset}")

    @heavy
    def test_record_padding_fifo_folder_loop(self):
        d = Shared.tmp()
        (d / "pad.json").write_bytes(Shared.record_bytes + b" " * 16 + b"x" * MB50)
        r, rss = run_rss(["trial", "--spec", "pad.json", "--check"], d)
        self.refused(r, (2,), "pad.json", what="50 MB after the record")
        self.assertLess(rss, RSS_BOUND_KB)
        make_fifo(d, "fifo.json")
        r = run(["trial", "--spec", "fifo.json", "--check"], d, timeout=20)
        self.refused(r, (1,), "fifo.json", what="FIFO")
        (d / "dir.json").mkdir()
        r = run(["trial", "--spec", "dir.json", "--check"], d)
        self.refused(r, (1,), "dir.json", what="folder")
        make_loop(d, "loop.json")
        r = run(["trial", "--spec", "loop.json", "--check"], d)
        self.refused(r, (1,), "loop.json", what="link loop")

    def test_other_kinds_in_place_of_a_record(self):
        for name, data in (("protocol", json.dumps(Shared.protocol).encode()), ("teacher", Shared.teacher_bytes),
                           ("csv", Shared.csv_bytes), ("array", b"[]"), ("number", b"7")):
            r, _ = self.spec(data)
            self.refused(r, (2,), "r.json", what=name)

    def test_record_version_past_current_and_format_refused(self):
        doc = copy.deepcopy(Shared.record)
        version = doc["specification"]["version"]
        for pointer, value in (("/specification/version", version + 1), ("/specification/version", 0),
                               ("/specification/version", -0.0 - 1), ("/specification/version", 7.5),
                               ("/specification/format", "calligraphy-teacher-recording")):
            r, _ = self.spec(self.edited(pointer, value))
            self.refused(r, (2,), "r.json", what=f"{pointer}={value}")

    def test_record_numbers_at_and_past_bounds_cli(self):
        # Three fields through the command itself; the Python sweep below takes every field.
        for pointer in ("/specification/trial/rate_hz", "/specification/trial/guidance_gain",
                        "/specification/trial/hint_after_misses"):
            node = self.node_of(pointer)
            for value, taken in bound_cases(node):
                r, _ = self.spec(self.edited(pointer, value))
                if taken:
                    self.assertNotIn(b"expected", r.stderr, f"{pointer}={value!r}: {r.stderr!r}")
                else:
                    self.refused(r, (2,), "r.json", pointer, what=f"{pointer}={value!r}")

    def node_of(self, pointer):
        schema = Shared.schemas["record"]
        node = schema
        for part in pointer.split("/")[2:]:
            node = resolve(schema, node)["properties"][part]
        return resolve(schema, node)


@needs_python
@unittest.skipUnless(CLI, "CALLIGRAPHY_CLI is not set")
class RecordSweepPython(Base):
    """Every bounded numeric field of a real record, by the record's schema, through check_trial_record."""

    def leaves(self):
        schema = Shared.schemas["record"]
        spec = Shared.record["specification"]
        return [(p, n) for p, n in numeric_leaves(schema, schema, spec, "/specification")
                if p.rsplit("/", 1)[-1] not in KNOWN_MAX_DOUBLE]

    def check(self, pointer, value, both_places=False):
        doc = copy.deepcopy(Shared.record)
        set_at(doc, pointer, value)
        # A record states its stroke acceptance in its specification and in its force law, the same in both: a
        # value taken at its bound is given in both places, or it is refused as a contradiction between them.
        field = pointer.rsplit("/", 1)[-1]
        acceptance = doc["specification"]["force_law"]["acceptance"]
        if both_places and field in acceptance and field in doc["specification"]["trial"]:
            acceptance[field] = doc["specification"]["trial"][field] = value
        try:
            cg.check_trial_record(doc)
        except (cg.DataError, cg.InvalidArgument, TypeError) as e:
            return e
        return None

    def test_every_bound_field_at_and_past_its_bound(self):
        leaves = self.leaves()
        self.assertGreater(len(leaves), 40, "the sweep should reach every field of the record")
        wrong = []
        for pointer, node in leaves:
            for value, taken in bound_cases(node):
                e = self.check(pointer, value, both_places=taken)
                # A field that applies to another mode or pacing only, or whose value contradicts another
                # field's (86,400 s at 1,000 Hz: more than 10^7 ticks), is refused naming its own pointer and
                # the rule or the other field: that is no refusal of the value at its bound.
                rule = e is not None and (": applies to " in str(e) or str(e).count("(--") >= 2)
                if taken and isinstance(e, cg.DataError) and pointer in str(e) and not rule:
                    wrong.append(f"{pointer}={value!r} refused at its bound: {e}")
                if not taken and (e is None or pointer not in str(e)):
                    wrong.append(f"{pointer}={value!r} past its bound: {'taken' if e is None else e}")
        self.assertEqual(wrong, [])

    def test_every_bound_field_nan_inf_huge_text_negative_zero(self):
        wrong = []
        for pointer, node in self.leaves():
            integer = node.get("type") == "integer"
            hostile = [float("nan"), float("inf"), -float("inf"), "1", [1]]
            if not integer:
                top = node.get("maximum", node.get("exclusiveMaximum"))
                if top is not None and top < 1e308:  # a field with no maximum takes it, as its schema says
                    hostile.append(1e308)
            else:
                hostile.append(1.5)
            for value in hostile:
                e = self.check(pointer, value)
                if e is None or pointer not in str(e):
                    wrong.append(f"{pointer}={value!r}: {'taken' if e is None else e}")
            low = node.get("minimum")
            if not integer and low is not None and low <= 0 <= node.get("maximum", math.inf):
                # -0 is 0: taken or refused (a rule between fields) exactly as 0 is.
                e, zero = self.check(pointer, -0.0), self.check(pointer, 0.0)
                if str(e) != str(zero):
                    wrong.append(f"{pointer}=-0.0: {e}, but 0.0: {zero}")
        self.assertEqual(wrong, [])

    def test_rerun_trial_of_damaged_paths(self):
        d = Shared.tmp()
        (d / "cut.json").write_bytes(Shared.record_bytes[:len(Shared.record_bytes) // 2])
        (d / "empty.json").write_bytes(b"")
        (d / "dir.json").mkdir()
        make_loop(d, "loop.json")
        for name in ("cut.json", "empty.json", "dir.json", "loop.json"):
            with self.assertRaises(cg.Error, msg=name) as c:
                cg.rerun_trial(str(d / name))
            self.assertIn(name, str(c.exception))


# ---------------------------------------------------------------------------------------------------------
# Study protocols: `session plan PROTOCOL`
# ---------------------------------------------------------------------------------------------------------
@unittest.skipUnless(CLI, "CALLIGRAPHY_CLI is not set")
class Protocols(Base):
    def plan(self, content, name="p.json"):
        d = Shared.tmp()
        p = d / name
        p.write_bytes(content if isinstance(content, bytes) else json.dumps(content, ensure_ascii=False).encode())
        return run(["session", "plan", p.name, "--subjects", "1"], cwd=d)

    def test_protocol_trial_and_breaks_fields_at_and_past_bounds(self):
        schema = Shared.schemas["protocol"]
        props = resolve(schema, schema)["properties"]
        wrong = []
        for part in ("trial", "breaks"):
            fields = resolve(schema, props[part])["properties"]
            for key, node in fields.items():
                node = resolve(schema, node)
                for value, taken in bound_cases(node):
                    doc = copy.deepcopy(Shared.protocol)
                    doc.setdefault(part, {})[key] = value
                    r = self.plan(doc)
                    pointer = f"/{part}/{key}"
                    if taken and r.returncode != 0 and pointer in r.stderr.decode():
                        if b"ticks" not in r.stderr:  # the tick bound is a rule between values
                            wrong.append(f"{pointer}={value!r} refused at its bound: {r.stderr!r}")
                    if not taken:
                        lines = error_lines(r)
                        if r.returncode != 2 or len(lines) != 1 or pointer not in lines[0]:
                            wrong.append(f"{pointer}={value!r}: exit {r.returncode} {lines!r}")
        self.assertEqual(wrong, [])

    def test_protocol_null_unknown_text_twice_missing(self):
        cases = []
        for pointer, value in (("/trial/max_duration_s", None), ("/trial/max_duration_s", "20"),
                               ("/test/repetitions", 1.5), ("/test/repetitions", -0.0),
                               ("/conditions/0/mode", None), ("/test/characters", None)):
            doc = copy.deepcopy(Shared.protocol)
            set_at(doc, pointer, value)
            cases.append((pointer, doc))
        doc = copy.deepcopy(Shared.protocol)
        doc["trial"]["max_duraton_s"] = 3
        cases.append(("/trial/max_duraton_s", doc))
        doc = copy.deepcopy(Shared.protocol)
        del doc["conditions"]
        cases.append(("/conditions", doc))
        for pointer, doc in cases:
            r = self.plan(doc)
            self.refused(r, (2,), "p.json", pointer, what=pointer)
        text = json.dumps(Shared.protocol)
        r = self.plan(text.replace('"name": "p11d"', '"name": "p11d", "name": "other"').encode())
        self.refused(r, (2,), "p.json", "/name", what="name twice")

    def test_protocol_nan_inf_huge_in_text(self):
        text = json.dumps(Shared.protocol)
        for literal in ("NaN", "Infinity", "1e308", "-1e308", "0x14", "1e999", "20 "):
            r = self.plan(text.replace('"max_duration_s": 20', '"max_duration_s": ' + literal).encode())
            if literal == "20 ":
                self.assertEqual(r.returncode, 0, r.stderr)
                continue
            self.refused(r, (2,), "p.json", what=literal)

    def test_protocol_bom_taken_invalid_utf8_cut_empty_refused(self):
        data = json.dumps(Shared.protocol, ensure_ascii=False).encode()
        r = self.plan(b"\xef\xbb\xbf" + data)
        self.assertEqual(r.returncode, 0, r.stderr)
        bad = data.replace(SHI.encode(), b"\xe5\x8d")  # 十 cut in the middle of its bytes
        r = self.plan(bad)
        line = self.refused(r, (2,), "p.json", what="invalid UTF-8")
        self.assertTrue(line.isprintable(), line)
        for offset in cuts(data, 5, 12) + [0]:
            r = self.plan(data[:offset])
            self.refused(r, (2,), "p.json", what=f"cut at {offset}")

    @heavy
    def test_protocol_padding_fifo_folder_loop_other_kind(self):
        d = Shared.tmp()
        data = json.dumps(Shared.protocol, ensure_ascii=False).encode()
        (d / "pad.json").write_bytes(data[:-1] + b', "x": "' + b"y" * MB50 + b'"}')
        r, rss = run_rss(["session", "plan", "pad.json", "--subjects", "1"], d)
        # A protocol is at most 1 MiB: refused before it is read, as a file that cannot be read (exit 1).
        self.refused(r, (1,), "pad.json", "1048576", what="50 MB in an unknown key")
        self.assertLess(rss, RSS_BOUND_KB)
        make_fifo(d, "fifo.json")
        r = run(["session", "plan", "fifo.json", "--subjects", "1"], d, timeout=20)
        self.refused(r, (1,), "fifo.json", what="FIFO")
        (d / "dir.json").mkdir()
        self.refused(run(["session", "plan", "dir.json", "--subjects", "1"], d), (1,), "dir.json", what="folder")
        make_loop(d, "loop.json")
        self.refused(run(["session", "plan", "loop.json", "--subjects", "1"], d), (1,), "loop.json", what="loop")
        for name, blob in (("record", Shared.record_bytes), ("teacher", Shared.teacher_bytes)):
            r = self.plan(blob)
            self.refused(r, (2,), "p.json", what=name)

    @heavy
    def test_session_run_refuses_bad_protocol_before_any_folder(self):
        d = Shared.tmp()
        doc = copy.deepcopy(Shared.protocol)
        doc["trial"]["max_duration_s"] = -0.0
        (d / "p.json").write_text(json.dumps(doc))
        r = run(["session", "run", "p.json", "--out", "study", "--subjects", "1"], d)
        self.refused(r, (2,), "p.json", "/trial/max_duration_s")
        self.assertFalse((d / "study").exists())


# ---------------------------------------------------------------------------------------------------------
# Teachers' recordings: `trial --guidance-mode replay --teacher FILE` and TeacherRecording.load
# ---------------------------------------------------------------------------------------------------------
@unittest.skipUnless(CLI, "CALLIGRAPHY_CLI is not set")
class Teachers(Base):
    def replay(self, d, name):
        return run(["trial", SHI, "--guidance-mode", "replay", "--teacher", name, "--json", "out.json",
                    "--csv", "out.csv"], d, timeout=20)

    @heavy
    def test_teacher_damaged_refused_nothing_written(self):
        d = Shared.tmp()
        data = Shared.teacher_bytes
        files = {"empty.json": b"", "array.json": b"[]", "record.json": Shared.record_bytes,
                 "protocol.json": json.dumps(Shared.protocol).encode(), "csv.json": Shared.csv_bytes,
                 "twice.json": data.replace(b'"version":', b'"version":1,"version":', 1),
                 "nan.json": data.replace(b'"rate_hz":1000.0', b'"rate_hz":NaN', 1)}
        self.assertNotIn(data, (files["twice.json"], files["nan.json"]))
        for offset in cuts(data, 3, 13):
            files[f"cut{offset}.json"] = data[:offset]
        for name, blob in files.items():
            (d / name).write_bytes(blob)
        make_fifo(d, "fifo.json")
        (d / "dir.json").mkdir()
        make_loop(d, "loop.json")
        for name in [*files, "fifo.json", "dir.json", "loop.json"]:
            r = self.replay(d, name)
            self.refused(r, (1, 2), name, what=name)
            self.assertFalse((d / "out.json").exists(), name)
            self.assertFalse((d / "out.csv").exists(), name)

    def test_teacher_bom_taken(self):
        d = Shared.tmp()
        (d / "t.json").write_bytes(b"\xef\xbb\xbf" + Shared.teacher_bytes)
        r = self.replay(d, "t.json")
        self.assertIn(r.returncode, (0, 1), r.stderr)  # 1 only when the trial itself ends early
        self.assertTrue((d / "out.json").exists())
        self.assertNotIn(b"t.json", r.stderr)

    @needs_python
    def test_teacher_load_python_damaged(self):
        d = Shared.tmp()
        (d / "cut.json").write_bytes(Shared.teacher_bytes[:50])
        (d / "rec.json").write_bytes(Shared.record_bytes)
        (d / "dir.json").mkdir()
        make_loop(d, "loop.json")
        for name in ("cut.json", "rec.json", "dir.json", "loop.json"):
            with self.assertRaises(cg.Error, msg=name) as c:
                cg.TeacherRecording.load(str(d / name))
            self.assertIn(name, str(c.exception))


# ---------------------------------------------------------------------------------------------------------
# CSV traces (`score`) and HDF5 traces (`trace`)
# ---------------------------------------------------------------------------------------------------------
@unittest.skipUnless(CLI, "CALLIGRAPHY_CLI is not set")
class Traces(Base):
    def score(self, d, name):
        return run(["score", name, "--character", SHI, "--json", "s.json"], d, timeout=20)

    def test_csv_cut_inside_a_row_refused_naming_line(self):
        d = Shared.tmp()
        data = Shared.csv_bytes
        lines = data.split(b"\n")
        for k, n in enumerate((2, 10, len(lines) // 2)):
            cut = b"\n".join(lines[:n]) + b"\n" + lines[n].split(b",")[0] + b",0.0"  # t and part of x
            name = f"cut{k}.csv"
            (d / name).write_bytes(cut)
            r = self.score(d, name)
            self.refused(r, (1, 2), f"{name}:{n + 1}", what=name)
            self.assertFalse((d / "s.json").exists())

    def test_csv_duplicate_column_and_other_kinds(self):
        d = Shared.tmp()
        header, rest = Shared.csv_bytes.split(b"\n", 1)
        (d / "twice.csv").write_bytes(header + b",x\n" + rest.replace(b"\n", b",0.5\n"))
        r = self.score(d, "twice.csv")
        self.refused(r, (1, 2), "twice.csv", what="column x twice")
        for name, blob in (("record.csv", Shared.record_bytes), ("empty.csv", b""),
                           ("protocol.csv", json.dumps(Shared.protocol).encode())):
            (d / name).write_bytes(blob)
            self.refused(self.score(d, name), (1, 2), name, what=name)
        self.assertFalse((d / "s.json").exists())

    @heavy
    def test_csv_padding_fifo_folder_loop(self):
        d = Shared.tmp()
        with open(d / "pad.csv", "wb") as f:
            f.write(b"t,x,y,z\n")
            f.write(b"0" * MB50)
        r, rss = run_rss(["score", "pad.csv", "--character", SHI], d)
        self.refused(r, (1, 2), "pad.csv", what="a 50 MB line")
        self.assertLess(rss, RSS_BOUND_KB)
        make_fifo(d, "fifo.csv")
        self.refused(self.score(d, "fifo.csv"), (1, 2), "fifo.csv", what="FIFO")
        (d / "dir.csv").mkdir()
        self.refused(self.score(d, "dir.csv"), (1, 2), "dir.csv", what="folder")
        make_loop(d, "loop.csv")
        self.refused(self.score(d, "loop.csv"), (1, 2), "loop.csv", what="loop")

    @heavy
    def test_hdf5_trace_fifo_folder_loop_other_kind_cut(self):
        d = Shared.tmp()
        h5 = next((Shared.session / "trials").glob("*.trace.h5"))
        data = h5.read_bytes()
        for offset in cuts(data, 3, 14):
            (d / f"cut{offset}.trace.h5").write_bytes(data[:offset])
        (d / "csv.trace.h5").write_bytes(Shared.csv_bytes)
        (d / "rec.trace.h5").write_bytes(Shared.record_bytes)
        make_fifo(d, "fifo.trace.h5")
        (d / "dir.trace.h5").mkdir()
        make_loop(d, "loop.trace.h5")
        names = [p.name for p in d.iterdir() if not p.name.endswith(".b")]
        for name in names:
            r = run(["trace", name, "--csv", "out.csv"], d, timeout=20)
            self.refused(r, (1,), name, what=f"trace {name}")
            self.assertFalse((d / "out.csv").exists(), name)
        for name in ("fifo.trace.h5", "dir.trace.h5", f"cut{cuts(data, 3, 14)[0]}.trace.h5"):
            self.refused(self.score(d, name), (1, 2), name, what=f"score {name}")


# ---------------------------------------------------------------------------------------------------------
# A session folder: `session resume DIR`, `report DIR`, calligraphy.study.load
# ---------------------------------------------------------------------------------------------------------
@unittest.skipIf(SANITIZED, "a session folder: left to the Release run")
@unittest.skipUnless(CLI, "CALLIGRAPHY_CLI is not set")
class SessionFolders(Base):
    def copy(self):
        d = Shared.tmp()
        study = d / "study"
        shutil.copytree(Shared.session.parent.parent, study, symlinks=True)
        return d, next((study / "S01").glob("p11d-*"))

    def session_json(self, blob):
        d, s = self.copy()
        (s / "session.json").write_bytes(blob)
        return d, s

    def test_resume_session_json_content_refused_exit_2(self):
        text = Shared.session_json.decode()
        doc = json.loads(text)
        cases = {"null subject": text.replace('"subject": ', '"subject": null, "x_": ', 1),
                 "unknown key": json.dumps({**doc, "extra_key": 1}),
                 "twice": text.replace('"subject": ', '"subject": "S01", "subject": ', 1),
                 "cut": text[:len(text) // 3], "empty": "",
                 "NaN": json.dumps({**doc, "version": float("nan")}),
                 "1e308": json.dumps({**doc, "version": 1e308}),
                 "record": Shared.record_bytes.decode()}
        for what, blob in cases.items():
            d, s = self.session_json(blob.encode())
            r = run(["session", "resume", s], d)
            self.refused(r, (2,), "session.json", what=what)
        d, s = self.session_json(b"\xef\xbb\xbf" + Shared.session_json)
        r = run(["session", "resume", s], d)
        self.assertNotIn(b"Traceback", r.stderr)
        self.assertIn(r.returncode, (0, 1, 2), r.stderr)

    def test_resume_session_json_fifo_folder_loop_padding(self):
        d, s = self.copy()
        (s / "session.json").unlink()
        os.mkfifo(s / "session.json")
        r = run(["session", "resume", s], d, timeout=20)
        self.refused(r, (1, 2), "session.json", what="FIFO")
        (s / "session.json").unlink()
        (s / "session.json").mkdir()
        self.refused(run(["session", "resume", s], d), (1, 2), "session.json", what="folder")
        (s / "session.json").rmdir()
        make_loop(s, "session.json")
        self.refused(run(["session", "resume", s], d), (2,), "session.json", what="loop")
        (s / "session.json").unlink()
        (s / "session.json.b").unlink()
        (s / "session.json").write_bytes(Shared.session_json.rstrip() + b" " + b"x" * MB50)
        r, rss = run_rss(["session", "resume", s], d)
        self.refused(r, (2,), "session.json", what="50 MB after it")
        self.assertLess(rss, RSS_BOUND_KB)

    def test_report_damaged_session_json_and_record_exit_1_nothing_written(self):
        d, s = self.session_json(Shared.session_json.replace(b'"subject": ', b'"subject": 7, "s_": ', 1))
        (d / "tables").mkdir()
        r = run(["report", "study", "--csv", "tables", "--out", "r.html"], d)
        self.refused(r, (1,), "session.json", what="report: damaged session.json")
        self.assertEqual(list((d / "tables").iterdir()), [])
        self.assertFalse((d / "r.html").exists())
        d, s = self.copy()
        record = next((s / "trials").glob("*.json"))
        data = record.read_bytes()
        record.write_bytes(data[:len(data) // 2])
        (d / "tables").mkdir()
        r = run(["report", "study", "--csv", "tables"], d)
        self.refused(r, (1,), record.name, what="report: cut record")
        self.assertEqual(list((d / "tables").iterdir()), [])

    def test_report_trace_replaced_by_fifo_loop_protocol(self):
        for kind in ("fifo", "loop", "protocol"):
            d, s = self.copy()
            h5 = next((s / "trials").glob("*.trace.h5"))
            h5.unlink()
            if kind == "fifo":
                os.mkfifo(h5)
            elif kind == "loop":
                make_loop(h5.parent, h5.name)
            else:
                h5.write_text(json.dumps(Shared.protocol))
            r = run(["report", "study", "--out", "r.html"], d, timeout=20)
            self.refused(r, (1,), h5.name, what=kind)
            self.assertFalse((d / "r.html").exists(), kind)

    @needs_python
    def test_study_load_damaged_session_json(self):
        for what, blob in (("twice", Shared.session_json.replace(b'"subject": ', b'"subject": "S01", "subject": ', 1)),
                           ("cut", Shared.session_json[:100]), ("empty", b"")):
            d, s = self.session_json(blob)
            with self.assertRaises(cg.Error, msg=what) as c:
                cg_study.load(str(d / "study"))
            self.assertIn("session.json", str(c.exception), what)


# ---------------------------------------------------------------------------------------------------------
# Character data (`--data`), the corpus store (`--store`, `corpus stats`) and cnchar's order file
# ---------------------------------------------------------------------------------------------------------
@unittest.skipUnless(CLI, "CALLIGRAPHY_CLI is not set")
class CharacterData(Base):
    def data_dir(self):
        d = Shared.tmp()
        data = d / "data"
        data.mkdir()
        return d, data

    def test_character_file_damaged_refused(self):
        good = (SOURCE / "data" / "hanzi-writer-data" / f"{SHI}.json").read_bytes()
        kinds = {"cut": good[:len(good) // 2], "empty": b"", "record": Shared.record_bytes,
                 "protocol": json.dumps(Shared.protocol).encode(), "nan": good.replace(b"[", b"[NaN,", 1)}
        for what, blob in kinds.items():
            d, data = self.data_dir()
            (data / f"{SHI}.json").write_bytes(blob)
            r = run(["model", SHI, "--data", "data"], d)
            self.refused(r, (1,), f"{SHI}.json", what=what)
        for what in ("fifo", "loop", "dir"):
            d, data = self.data_dir()
            if what == "fifo":
                make_fifo(data, f"{SHI}.json")
            elif what == "loop":
                make_loop(data, f"{SHI}.json")
            else:
                (data / f"{SHI}.json").mkdir()
            r = run(["model", SHI, "--data", "data", "--svg", "m.svg"], d, timeout=20)
            self.refused(r, (1, 2), f"{SHI}.json", what=what)
            self.assertFalse((d / "m.svg").exists(), what)

    def test_data_given_a_file_and_a_loop(self):
        d, data = self.data_dir()
        (d / "file").write_bytes(b"x")
        self.refused(run(["model", SHI, "--data", "file"], d), (1, 2), "file", what="--data a file")
        make_loop(d, "loopdir")
        self.refused(run(["model", SHI, "--data", "loopdir"], d), (1, 2), "loopdir", what="--data a loop")

    def test_store_damaged_refused(self):
        d = Shared.tmp()
        store = (SOURCE / "fuzz" / "seeds" / "one_character.clg").read_bytes()
        blobs = {"empty.clg": b"", "record.clg": Shared.record_bytes, "teacher.clg": Shared.teacher_bytes}
        for offset in cuts(store, 4, 15):
            blobs[f"cut{offset}.clg"] = store[:offset]
        for name, blob in blobs.items():
            (d / name).write_bytes(blob)
        make_fifo(d, "fifo.clg")
        (d / "dir.clg").mkdir()
        make_loop(d, "loop.clg")
        for name in [*blobs, "fifo.clg", "dir.clg", "loop.clg"]:
            r = run(["model", SHI, "--store", name], d, timeout=20)
            self.refused(r, (1, 2), name, what=name)

    @heavy
    def test_store_padding_rss(self):
        d = Shared.tmp()
        store = (SOURCE / "fuzz" / "seeds" / "one_character.clg").read_bytes()
        (d / "pad.clg").write_bytes(store[:16] + b"\xff" * MB50)
        r, rss = run_rss(["model", SHI, "--store", "pad.clg"], d)
        self.refused(r, (1, 2), "pad.clg", what="50 MB store")
        self.assertLess(rss, RSS_BOUND_KB)

    @needs_python
    def test_python_store_and_folder_damaged(self):
        d = Shared.tmp()
        (d / "empty.clg").write_bytes(b"")
        (d / "proto.clg").write_text(json.dumps(Shared.protocol))
        make_loop(d, "loop.clg")
        for name in ("empty.clg", "proto.clg", "loop.clg"):
            with self.assertRaises(cg.Error, msg=name) as c:
                cg.CharacterLibrary.from_store(str(d / name)).load(SHI)
            self.assertIn(name, str(c.exception))
        data = d / "data"
        data.mkdir()
        (data / f"{SHI}.json").write_bytes(b"{")
        with self.assertRaises(cg.Error) as c:
            cg.CharacterLibrary.from_hanzi_writer(str(data)).load(SHI)
        self.assertIn(f"{SHI}.json", str(c.exception))

    @heavy
    def test_cnchar_file_damaged_refused_nothing_written(self):
        d = Shared.tmp()
        (d / "empty.js").write_bytes(b"")
        (d / "record.js").write_bytes(Shared.record_bytes)
        (d / "dir.js").mkdir()
        make_fifo(d, "fifo.js")
        make_loop(d, "loop.js")
        data = d / "data"
        data.mkdir()
        shutil.copy(SOURCE / "data" / "hanzi-writer-data" / f"{SHI}.json", data)
        for name in ("empty.js", "record.js", "dir.js", "fifo.js", "loop.js"):
            r = run(["corpus", "validate", "--cnchar", name, "--data", "data", "--markdown", "v.md",
                     "--threads", "1"], d, timeout=30)
            self.refused(r, (1, 2), name, what=name)
            self.assertFalse((d / "v.md").exists(), name)


if __name__ == "__main__":
    unittest.main()
