#!/usr/bin/env python3
"""The examples of README.md and docs/*.md, run as a reader copies them into a terminal.

Every fenced block is extracted mechanically, so an example added later is run too. A block is a shell block
when it is marked sh/bash/shell/console, or unmarked and its first command is a program the docs use
(`calligraphy`, `build/bin/calligraphy`, `python3`, `scripts/...`, `cmake`, ...); a Python block when marked
python. Other blocks (C++, compiled by the doc_snippets test; R; JSON; diagrams, grammars, folder trees and
printed tables) are counted and listed, not run.

Each document runs in a fresh temporary folder laid out as the source tree the docs speak from: `examples`
and the small character data folder linked, `build/bin/calligraphy` the program under test, `build/python`
the built module. `calligraphy` and `python3` on PATH are the program under test and /usr/bin/python3.
Steps that chain run in order in the one folder of their document; the Python blocks of a document share one
namespace, as in one interpreter session.

A shell step (a logical line, or one part of an `a && b` chain) is skipped only by one of the rules of SKIP
below, or as run by round 15A (RUN_BY_ROUND15A: the README's study, cohort and Table 5, the very commands round
15A runs with this test's checks and more), and the test prints each skip with its rule. Inputs the reader
supplies are given, made by the program itself where it can (FIXTURES): `DIR` is the character data folder, a
study is a session run. Each step run must exit 0 (or what the text beside it says), print no traceback and no
error line, make the files it names as outputs (non-empty), and hold what the docs state about its output
(CHECKS).

CALLIGRAPHY_DOCS_EXAMPLES_ONLY=README.md,python.md restricts the run to some documents (for working on them);
CALLIGRAPHY_DOCS_EXAMPLES_ALL=1 also runs the LONG_DOCUMENTS, skipped otherwise to keep the suite's budget.
"""

import glob
import hashlib
import json
import resource
import os
import re
import shlex
import shutil
import subprocess
import sys
import tempfile
import unittest
from xml.etree import ElementTree

from outsider import strip_comment
import test_unseen_round15a as round15a   # what round 15A runs of each document: its extraction, skips and caps

SOURCE = os.environ.get("CALLIGRAPHY_SOURCE_DIR", os.path.dirname(os.path.dirname(os.path.dirname(
    os.path.abspath(__file__)))))
CLI = os.environ.get("CALLIGRAPHY_CLI", "")
PYTHONPATH = os.environ.get("PYTHONPATH", "")
PYTHON = "/usr/bin/python3"
CHARACTER_DATA = os.path.join(SOURCE, "data", "hanzi-writer-data")   # the 58 embedded characters' files
BUNDLED_STORE = os.path.join(SOURCE, "data", "corpus", "hanzi-writer-data-2.0.1.clg")

FENCE = re.compile(r"^```([A-Za-z0-9_+-]*)[^\n]*\n(.*?)^```[ \t]*$", re.S | re.M)
SHELL_LANGS = {"sh", "bash", "shell", "console"}
COMMAND_START = re.compile(
    r"^(?:[A-Z_]+=\S*\s+)*(?:calligraphy|build/bin/calligraphy|build-fuzz/|python3|/usr/bin/python3|"
    r"scripts/|bash|cmake|ctest|mkdir|nice|lab/|for|data=|/usr/bin/time|strace|CALLIGRAPHY_)")

# Why a step is not run. Each rule is a (name, reason, predicate on the step's text).
SKIP = [
    ("build", "builds, installs or tests the project: this test runs against the build under test",
     re.compile(r"^(?:\S+=\S+\s+)*(?:cmake|ctest|ninja|bash scripts/(?:test|install-deps)\.sh|"
                r"\S*python3? -m pytest|\S*python3 -m venv|lab/bin/pip)\b")),
    ("venv", "uses the virtual environment a skipped install step makes", re.compile(r"^lab/")),
    ("network", "fetches data from the network (scripts/fetch-*.sh); the character data is given instead",
     re.compile(r"^(?:bash )?scripts/fetch-|--cnchar")),
    ("device", "needs a haptic device (a Phantom) plugged in",
     re.compile(r"--device phantom(?!-emulated)(?:\b|-hid)")),
    ("display", "opens the trainer window: needs a display and a person", re.compile(r"\bcalligraphy train\b")),
    ("minutes", "a benchmark, a fuzzer or a scale run: seconds to minutes of CPU by design "
     "(run by the bench and fuzz targets)",
     re.compile(r"\bbench\b|build-fuzz/|study_scale|trace_read_bench|^for |^done$|"
                r"^/usr/bin/time|^strace|corpus_sweep\.py --data|^nice |^mkdir -p /tmp/fuzz")),
    ("realtime", "needs real-time privileges (SCHED_FIFO, locked memory) this test does not ask for",
     re.compile(r"--realtime enforce")),
]


def logical_lines(text):
    """Lines joined at a trailing backslash; blank and comment-only lines dropped."""
    out, current = [], ""
    for raw in text.splitlines():
        if raw.rstrip().endswith("\\"):
            current += raw.rstrip()[:-1] + " "
            continue
        current += raw
        if current.strip() and not current.strip().startswith("#"):
            out.append(current.strip())
        current = ""
    return out



def extract(doc):
    with open(os.path.join(SOURCE, doc), encoding="utf-8") as f:
        text = f.read()
    for m in FENCE.finditer(text):
        lang, body = m.group(1).lower(), m.group(2)
        line = text[:m.start()].count("\n") + 1
        kind = "other"
        if lang == "python":
            kind = "python"
        elif lang in SHELL_LANGS:
            kind = "shell"
        elif lang == "":
            first = next(iter(logical_lines(body)), "")
            if COMMAND_START.match(first):
                kind = "shell"
        yield line, lang, kind, body


def documents():
    docs = ["README.md"] + sorted(os.path.relpath(p, SOURCE) for p in glob.glob(os.path.join(SOURCE, "docs", "*.md")))
    only = os.environ.get("CALLIGRAPHY_DOCS_EXAMPLES_ONLY")
    if only:
        docs = [d for d in docs if os.path.basename(d) in only.split(",")]
    return docs


def expand_alternatives(step):
    """`bench nearest|jumps|tick|loop` is the docs' notation for one of them: one step each."""
    m = re.search(r"(\s)(\w+(?:\|\w+)+)(\s|$)", step)
    if not m or "|" in step.replace(m.group(2), ""):
        return [step]
    return [step[:m.start(2)] + alt + step[m.end(2):] for alt in m.group(2).split("|")]


def synopsis(step):
    """A synopsis line (`[--option VALUE]` optional parts) is run as its shortest command, with the one
    optional part the reader supplies here given: `[--data DIR]` (the whole 9,574-character data set otherwise)."""
    step = re.sub(r"\[(--data DIR)\]", r"\1", step)
    return re.sub(r"\s*\[--[^\]]*\]", "", step)


def substitute(step):
    """Inputs the reader supplies, given: DIR is the character data folder (the in-tree 58 characters);
    the fetch scripts' output is that folder; STUDY is a study the document made or the fixture makes."""
    step = re.sub(r'"\$\((?:bash )?scripts/fetch-hanzi-writer-data\.sh\)"', CHARACTER_DATA, step)
    step = re.sub(r"--data DIR\b", "--data " + CHARACTER_DATA, step)
    # A store built from that small folder lacks most characters (字, 法); a step reading the store the
    # reader built from the whole data set reads the bundled store, that command's output on that data
    # (docs/corpus.md, "the bundled store").
    if "corpus build" not in step:
        step = re.sub(r"--store corpus\.clg\b", "--store " + BUNDLED_STORE, step)
    return step


# A study step run already in another document, the same command on the same input, is not run again: its
# output folder is copied from that run (the examples of docs/experiments.md and docs/learning-study.md make
# the same study and report). Keyed by the command and a digest of its study folder (the output left out).
STUDY_STEP = re.compile(r"calligraphy session run .*--out (?P<out>\S+)|-m calligraphy\.study_report (?P<study>\S+) .*--out (?P<rout>\S+)")
_STUDY_CACHE = {}


def _digest(path, leave_out):
    if not os.path.exists(path):
        return "absent"
    h = hashlib.sha256()
    for root, dirs, files in os.walk(path):
        dirs.sort()
        for name in sorted(files):
            p = os.path.join(root, name)
            if p == leave_out or p.startswith(leave_out + os.sep):
                continue
            h.update(os.path.relpath(p, path).encode() + b"\0")
            with open(p, "rb") as f:
                h.update(f.read())
    return h.hexdigest()


def study_key(command, folder):
    """(key, output folder) of a study step, or None."""
    m = STUDY_STEP.search(command)
    if not m:
        return None
    if m.group("out"):
        out = os.path.join(folder, m.group("out"))
        if os.path.exists(out):    # a second run into a study: depends on what is there, never cached
            return None
        return (command, "absent"), out
    out = os.path.join(folder, m.group("rout"))
    return (command, _digest(os.path.join(folder, m.group("study")), out)), out


_SQUARES = {}


def counterbalancing_square(protocol, folder, env):
    """The least number of subjects that fills the protocol's counterbalancing square (`session plan --json`)."""
    if protocol not in _SQUARES:
        proc = subprocess.run(["calligraphy", "session", "plan", protocol, "--subjects", "1", "--json"], cwd=folder,
                              env=env, capture_output=True, text=True, timeout=60)
        _SQUARES[protocol] = json.loads(proc.stdout)["balance"]["square"] if proc.returncode == 0 else None
    return _SQUARES[protocol]


def cap(step, folder, env):
    """Long examples capped, each by an option its docs give the reader:
    `--subjects N` of a study runs the protocol's full counterbalancing square of subjects (at most N): every
    group, sequence and order once, as a smaller study of the same design; examples/python/table5.py runs one
    seed (`--seeds`, documented beside it; 4 by default)."""
    m = re.search(r"(\S+\.json)\b.*--subjects (\d+)", step)
    if m:
        square = counterbalancing_square(m.group(1), folder, env)
        if square and square < int(m.group(2)):
            step = step[:m.start(2)] + str(square) + step[m.end(2):]
    if "examples/python/table5.py" in step:
        step = re.sub(r"--seeds \d+", "", step).rstrip() + " --seeds 1"
    return step


def cap_python(code, folder, env):
    """The same cap for a Python block's study: `cohort.simulate(PROTOCOL, N, ...)` runs two squares (the
    block compares two groups: a comparison takes at least two subjects a group)."""
    def repl(m):
        square = counterbalancing_square(m.group(2), folder, env)
        return m.group(1) + str(min(int(m.group(3)), 2 * square if square else int(m.group(3))))
    return re.sub(r'(cohort\.simulate\("([^"]+)", )(\d+)', repl, code)


# The README's study (`session run`, `report`, `study_report`), its cohort and Table 5 are most of this test's CPU,
# and round 15A (tests/cli/test_unseen_round15a.py, CTest cli_unseen_round15a_tests, registered wherever this test
# is, with the same program, module and sources) runs each of them as well: the same command after the same cap, in
# a folder laid out as here, in the document's order (a study's `session run` that another document runs the same
# way, made once and copied), held to all this test holds them to (exit status 0, no error line on either stream,
# each output it names made, non-empty and of its kind, the study report's index.html, Table 5's table of 永我九心) and
# more (a line and a folder per subject, trials.csv and strokes.csv). Such a step is not run twice: it is skipped
# here, naming round 15A, where round 15A runs that very command in this configuration (not skipped by its rules,
# with its Python module, not under the sanitizers, its document not one it leaves to
# CALLIGRAPHY_DOCS_EXAMPLES_ALL).
RUN_BY_ROUND15A = {"README.md": re.compile(r"calligraphy (?:session run|session cohort|report) |"
                                           r"calligraphy\.study_report |examples/python/table5\.py")}
_ROUND15A_COMMANDS = {}


def run_by_round15a(doc, command):
    """Whether round 15A runs this command, as this test would run it, of this document."""
    steps = RUN_BY_ROUND15A.get(doc)
    if not steps or not steps.search(command) or round15a.SANITIZED or not round15a.PYTHONPATH or (
            doc in round15a.LONG_DOCUMENTS and not round15a.ALL):
        return False
    if doc not in _ROUND15A_COMMANDS:
        commands = set()
        for example in round15a.extract(round15a.SOURCE / doc):
            if example.kind != "sh" or round15a.skip_reason(example):
                continue
            text = round15a.cheaper(example.text)[0]
            commands.update(" ".join(part.split()) for part in (text or "").split("&&"))
        _ROUND15A_COMMANDS[doc] = commands
    return " ".join(command.split()) in _ROUND15A_COMMANDS[doc]


def skip_rule(step):
    for name, reason, pattern in SKIP:
        if pattern.search(step):
            return name, reason
    return None


def output_paths(command):
    """Files and folders a command names as its outputs (the docs' output options and redirections)."""
    try:
        words = shlex.split(command)
    except ValueError:
        return []
    outs = []
    for i, w in enumerate(words[:-1]):
        if w in ("--json", "--svg", "--csv", "--out", "--record", "--markdown", ">") and not words[i + 1].startswith("-"):
            outs.append(words[i + 1])
    return outs


def _nonempty(path):
    if os.path.isdir(path):
        return bool(os.listdir(path))
    return os.path.isfile(path) and os.path.getsize(path) > 0


def check_output_kind(t, path):
    """An output named .json is JSON, .svg an SVG document, .csv a table with a header; a folder is not
    looked into further."""
    if not os.path.isfile(path):
        return
    if path.endswith(".json"):
        with open(path, encoding="utf-8") as f:
            json.load(f)
    elif path.endswith(".svg"):
        root = ElementTree.parse(path).getroot()
        t.assertTrue(root.tag.endswith("svg"), path + ": not an SVG document")
    elif path.endswith(".csv"):
        with open(path, encoding="utf-8") as f:
            header = f.readline()
        t.assertRegex(header, r"^[A-Za-z_][\w ,]*$", path + ": no header line")


def check_characters_listed(t, out, folder, strokes, typical_id):
    """`characters --strokes N --typical ACRONYM`: each character listed has N strokes, one of them that one."""
    listed = sorted(set(re.findall(r"[\u2e80-\u2fdf\u3400-\u9fff\uf900-\ufaff]", out)))
    t.assertTrue(listed, "characters listed")
    code = ("import calligraphy as cg, sys\nlib = cg.CharacterLibrary.default()\nbad = []\n"
            "for c in sys.argv[1]:\n    ids = list(lib.load(c).typical_stroke_ids)\n"
            "    if len(ids) != %d or %d not in ids: bad.append((c, ids))\nprint(bad)\n" % (strokes, typical_id))
    proc = subprocess.run([PYTHON, "-c", code, "".join(listed)], capture_output=True, text=True, timeout=120,
                          env=dict(os.environ, PYTHONPATH=PYTHONPATH))
    t.assertEqual(proc.stdout.strip(), "[]", proc.stderr[-2000:])


def _typical_acronyms():
    with open(os.path.join(SOURCE, "docs", "typical-strokes.md"), encoding="utf-8") as f:
        return [m.group(2) for m in re.finditer(r"^\| (\d+) \| ([A-Z][A-Z0-9]*) \|", f.read(), re.M)]


def check_strokes(t, out, folder):
    acronyms = _typical_acronyms()
    t.assertEqual(len(acronyms), 39, "docs/typical-strokes.md lists the 39 typical strokes")
    words = set(re.findall(r"[A-Z][A-Z0-9]*", out))
    t.assertEqual([a for a in acronyms if a not in words], [], "`calligraphy strokes` shows every typical stroke")


def check_json_stdout(t, out, folder):
    json.loads(out)


def check_devices(t, out, folder):
    devices = json.loads(out)
    text = json.dumps(devices)
    t.assertRegex(text, r'"\w+_(m|n|s|hz)"', "devices --json: limits in SI units, units in names")


def check_two_stroke(t, out, folder):
    for ch in "二八十":
        t.assertIn(ch, out, "characters --strokes 2 lists 二 八 十 ...")


def check_rerun(t, out, folder):
    with open(os.path.join(folder, "again.csv"), "rb") as a, open(os.path.join(folder, "out.csv"), "rb") as b:
        t.assertEqual(a.read(), b.read(), "trial --spec out.json --csv again.csv: again.csv == out.csv")


def check_score(t, out, folder):
    result = json.loads(out)
    for key in ("order_errors", "mean_deviation_m", "frechet_m", "strokes_accepted"):
        t.assertIn(key, result)
    t.assertGreater(result["mean_deviation_m"], 0.0)
    t.assertLess(result["mean_deviation_m"], 0.01, "a simulated trace stays within a centimetre of the model")


def check_strokes_accepted_print(t, out, folder):
    t.assertRegex(out.strip(), r"^\d+$", "prints the number of strokes accepted")


def check_deviation_print(t, out, folder):
    value = float(out.strip())
    t.assertTrue(0.0 < value < 0.01, "mean_deviation_m in metres: a simulated trace is within 10 mm")


def check_version(t, out, folder):
    t.assertRegex(out.strip(), r"^\d+\.\d+\.\d+", "prints the version")


def check_table5(t, out, folder):
    # docs/python.md prints the table: writer, char, time off/on [s], dev off/on [mm], in order off/on, paper.
    t.assertIn("dev off [mm]", out)
    for ch in "永我九心":
        t.assertIn(ch, out)


def check_study_report(t, out, folder, out_dir):
    t.assertTrue(os.path.isfile(os.path.join(folder, out_dir, "index.html")), out_dir + "/index.html")


def _stroke_rows(out):
    """(number, character) of each row of the per-stroke table a trial prints (strokes numbered from 1)."""
    return [(int(m.group(1)), m.group(2)) for m in re.finditer(r"^\s+(\d+)\s+(\S)\s+[A-Z]", out, re.M)]


def check_trial_table(t, out, folder):
    # README: "table per stroke and in total"; strokes are numbered from 1 where people read them.
    t.assertEqual(_stroke_rows(out), [(i, "永") for i in range(1, 6)], "one row per stroke of 永, from 1")
    t.assertRegex(out, r"(?m)^\s+mean deviation\s+[0-9.]+ mm$", "and the totals, in millimetres for people")


def check_group_order(t, out, folder):
    # README: "a character group, written left to right": 口's strokes, then 九's.
    chars = [c for _, c in _stroke_rows(out)]
    t.assertTrue(chars and set(chars) == {"口", "九"}, chars)
    t.assertEqual(chars, sorted(chars, key="口九".index), "口 written before 九")


CHECKS = [   # (pattern on the step as written, check(test, stdout, folder))
    (re.compile(r"characters --typical HZG --strokes 4"), lambda t, o, f: check_characters_listed(t, o, f, 4, 10)),
    (re.compile(r"characters --strokes 5 --typical HZG"), lambda t, o, f: check_characters_listed(t, o, f, 5, 10)),
    (re.compile(r"calligraphy trial 永\s*$"), check_trial_table),
    (re.compile(r"calligraphy trial 口九 --writer-profile skilled\s*$"), check_group_order),
    (re.compile(r"calligraphy strokes\s*$"), check_strokes),
    (re.compile(r"calligraphy model 永 --json\s*$"), check_json_stdout),
    (re.compile(r"calligraphy devices --json"), check_devices),
    (re.compile(r"calligraphy characters --strokes 2\s*$"), check_two_stroke),
    (re.compile(r"--text \"永字八法\" --json"), check_json_stdout),
    (re.compile(r"--spec out\.json --csv again\.csv"), check_rerun),
    (re.compile(r"score trace\.csv --character 永 --json -"), check_score),
    (re.compile(r"strokes_accepted'\]\)\"$"), check_strokes_accepted_print),
    (re.compile(r"mean_deviation_m'\]\)\"$"), check_deviation_print),
    (re.compile(r"print\(calligraphy\.__version__\)"), check_version),
    (re.compile(r"table5\.py"), check_table5),
    (re.compile(r"study_report S --out S/paper"), lambda t, o, f: check_study_report(t, o, f, "S/paper")),
    (re.compile(r"study_report study --out study/paper"),
     lambda t, o, f: check_study_report(t, o, f, "study/paper")),
    (re.compile(r"study_report xo --out xo/paper"), lambda t, o, f: check_study_report(t, o, f, "xo/paper")),
]

# Exit statuses the text beside a step states (none yet: every example is documented to succeed).
EXPECTED_STATUS = {}

ERROR_LINE = re.compile(r"^(?:error|Error|ERROR|calligraphy[\w .-]*: error)\b|Traceback \(most recent call last\)", re.M)

# Inputs a Python block's reader supplies (names a fragment uses without making them), given before it runs.
# Keyed by a line of the block. Made with the library itself where a file is needed.
PY_FIXTURES = {
    'with h5py.File("001-practice-haptic-r1-U6C38.trace.h5")':
        "import glob as _g, os as _o\n_back = _o.getcwd()\n"
        "_o.chdir(_o.path.dirname(sorted(_g.glob('S/*/*/trials/001-*.trace.h5'))[0]))\n",
    'lib = cg.CharacterLibrary.from_hanzi_writer("path/to/hanzi-writer-data")':
        "import os as _o, shutil as _s, subprocess as _sp\n"
        "_o.makedirs('path/to', exist_ok=True)\n"
        "_s.copytree(%r, 'path/to/hanzi-writer-data', dirs_exist_ok=True)\n"
        "_sp.run(['calligraphy', 'corpus', 'build', '--data', 'path/to/hanzi-writer-data', '--out', 'corpus.store'],"
        " check=True, stdout=_sp.DEVNULL)\n" % CHARACTER_DATA,
    "scene.characters[0].placement.to_paper(points)":
        "points = np.array([[500.0, 500.0], [400.0, 300.0]])\npoints_m = np.array([0.01, 0.02])\n",
    "cg.paper_force(tip_z_m, 0.0, law.paper_stiffness_n_per_m)":
        "tip_z_m = -0.001\ntip_m = np.array([0.01, 0.02])\nfoot_m = np.array([0.011, 0.02])\n"
        "velocity_m_s = np.array([0.05, 0.0])\ntangent = np.array([1.0, 0.0])\nnormal_force_n = 1.0\n"
        "distance_m = 0.002\nforces_n = np.array([10.0, 0.0, 0.0])\n",
    "out = renderer.tick(cg.DeviceState(":
        "x, y, z = 0.0, 0.0, 0.01\nvx, vy, vz = 0.0, 0.0, 0.0\nt_s = 0.0\n",
    # docs/experiments.md reads "study" before its shell block makes one: the study its first block made (S).
    "# a `session run --out` folder, a session folder, or a list":
        "import shutil as _s\n_s.copytree('S', 'study')\n",
    # docs/python.md's statistics read a study of its reader's: one made by `session run` (the paper's Table 5).
    'statistics.describe(trials, "mean_deviation_m", by=("phase", "condition"), unit="subject")':
        "import subprocess as _sp, calligraphy.study as _st\n"
        "_sp.run(['calligraphy', 'session', 'run', 'examples/protocols/paper-table5.json', '--writer', 'simulated',"
        " '--subjects', '4', '--out', 'study'], check=True, stdout=_sp.DEVNULL)\n"
        "trials = _st.load('study').trials\n",
}

# What a Python block's text states about its result, checked after it runs (in its namespace).
PY_CHECKS = {
    "yong.typical_stroke_ids": "assert list(yong.typical_stroke_ids) == [4, 10, 8, 3, 5], yong.typical_stroke_ids\n"
                               "assert len(cg.CharacterLibrary.embedded()) == 58\n"
                               "assert len(cg.TYPICAL_STROKES) == 39\n"
                               "assert e.point(np.linspace(0, 1, 5)).shape == (5, 2)\n"
                               "assert e.control_points.shape == (e.degree + 1, 2)\n"
                               "assert cg.typical_stroke('HZG').id == 10\n",
    "scene.characters[0].bounding_box_m": "assert np.asarray(scene.characters[0].bounding_box_m).shape == (2, 2)\n"
                                          "_p = scene.characters[0].placement\n"
                                          "assert np.allclose(_p.to_data(_p.to_paper(points)), points)\n",
    "t, foot, d = cg.nearest_point(e, np.random.rand(100, 2) * 1024)":
        "assert np.shape(t) == (100,) and np.shape(foot) == (100, 2) and np.shape(d) == (100,)\n"
        "assert np.linalg.norm(cg.clamp_force(np.array([10.0, 0, 0]), 7.9)) <= 7.9 + 1e-12\n",
    "m = cg.match_stroke(scene, 0, 1, path_m)":
        "assert m.accepted\n"
        "assert cg.match_stroke(scene, 0, 1, path_m[::-1]).refusal == cg.StrokeRefusal.backwards\n"
        "assert cg.match_stroke(scene, 0, 0, path_m).refusal == cg.StrokeRefusal.wrong_order\n",
    'r.metrics["end_reason"]':
        "assert r.metrics['end_reason'] in ('completed', 'time_limit', 'device_fault', 'watchdog', 'interrupted',"
        " 'gave_up', 'writer_finished'), r.metrics['end_reason']\n",
    "teacher.save(\"copy.json\")": "import os as _o\nassert _o.path.getsize('teacher.json') > 0 and _o.path.getsize('copy.json') > 0\n",
    'r.time_s, r.position_m, r.force_n, r.state': "_n = len(r.time_s)\n"
        "assert r.position_m.shape == (_n, 3) and r.force_n.shape == (_n, 3) and r.state.dtype == np.uint8\n"
        "assert r.element.dtype == np.int64 and r.stroke_trace_range.shape == (len(r.scene.strokes), 2)\n",
    'with h5py.File("001-practice-haptic-r1-U6C38.trace.h5")':
        "_o.chdir(_back)\nassert 0 < len(x_m) and abs(x_m).max() < 1.0, 'x in metres, within the workspace'\n",
    'result["per_character"][0]["segments"]':
        "assert result['refusals']['wrong_order'] == sum(s['verdict'] is not None and "
        "s['verdict']['refusal'] == 'wrong_order' for s in result['per_character'][0]['segments'])\n",
    "r.to_dataframe()": "_cols = list(r.to_dataframe().columns)\n"
                        "assert _cols == ['t_s', 'x_m', 'y_m', 'z_m', 'fx_n', 'fy_n', 'fz_n', 'state', 'stroke', 'element',"
                        " 'attempt', 'rewritten'],"
                        " _cols\n"
                        "assert set(r.to_dataframe()['state'].cat.categories) <= {'SS', 'AS', 'CS', 'WS'}\n",
    "index = calligraphy.study_report.write_report(": "import os as _o\nassert _o.path.isfile('paper/index.html')\n",
    "# a `session run --out` folder, a session folder, or a list":
        "import shutil as _s\n_s.rmtree('study')\n"
        "assert {'t_s', 'x_m', 'y_m', 'fx_n', 'state', 'stroke', 'element'} <= set(samples.columns)\n",
}

# Python blocks not run, by rule.
PY_SKIP = [
    ("network", "starts a Dask cluster (worker processes and ports)", re.compile(r"distributed\.LocalCluster")),
]

PY_RUNNER = r'''
import json, sys, traceback, io, contextlib, os
blocks = json.load(open(sys.argv[1]))
ns = {"__name__": "__main__"}
def cpu():
    t = os.times()
    return t.user + t.system + t.children_user + t.children_system
for b in blocks:
    start = cpu()
    buf = io.StringIO()
    try:
        with contextlib.redirect_stdout(buf):
            for part in (b["fixture"], b["code"], b["check"]):
                if part:
                    exec(compile(part, b["name"], "exec"), ns)
        print(json.dumps({"name": b["name"], "ok": True, "out": buf.getvalue()[-2000:], "cpu": cpu() - start}),
              flush=True)
    except BaseException:
        print(json.dumps({"name": b["name"], "ok": False, "out": buf.getvalue()[-2000:],
                          "error": traceback.format_exc()[-3000:], "cpu": cpu() - start}), flush=True)
'''


def _children_cpu():
    usage = resource.getrusage(resource.RUSAGE_CHILDREN)
    return usage.ru_utime + usage.ru_stime


class DocsExamples(unittest.TestCase):
    tally = {"blocks": 0, "shell": 0, "python": 0, "other": 0, "steps": 0, "run": 0, "skipped": 0,
             "python_run": 0, "python_skipped": 0}
    skips = []
    costs = []   # (CPU seconds, what): the examples' cost, the largest printed at the end


    @classmethod
    def tearDownClass(cls):
        if cls._cache_dir:
            shutil.rmtree(cls._cache_dir, True)
        t = cls.tally
        print("\nblocks found: %d (shell %d, Python %d, other %d); shell steps %d: run %d, skipped %d; "
              "Python blocks run %d, skipped %d" % (t["blocks"], t["shell"], t["python"], t["other"], t["steps"],
                                                    t["run"], t["skipped"], t["python_run"], t["python_skipped"]),
              file=sys.stderr)
        for s in cls.skips:
            print("  skipped %s" % s, file=sys.stderr)
        print("CPU of the examples: %.1f s; the largest:" % sum(c for c, w in cls.costs if not w.startswith(" ")), file=sys.stderr)
        for cost, what in sorted(cls.costs, reverse=True)[:12]:
            print("  %5.1f s %s" % (cost, what), file=sys.stderr)

    _cache_dir = None

    @classmethod
    def cache_dir(cls):
        if cls._cache_dir is None:
            cls._cache_dir = tempfile.mkdtemp(prefix="docs-examples-studies-")
        return cls._cache_dir

    def folder_for(self, doc):
        folder = tempfile.mkdtemp(prefix="docs-examples-")
        self.addCleanup(shutil.rmtree, folder, True)
        os.makedirs(os.path.join(folder, "build", "bin"))
        os.symlink(os.path.abspath(CLI), os.path.join(folder, "build", "bin", "calligraphy"))
        if PYTHONPATH:
            os.symlink(os.path.abspath(PYTHONPATH.split(os.pathsep)[0]), os.path.join(folder, "build", "python"))
        for name in ("examples", "scripts"):
            os.symlink(os.path.join(SOURCE, name), os.path.join(folder, name))
        os.makedirs(os.path.join(folder, "data", "corpus"))
        os.symlink(CHARACTER_DATA, os.path.join(folder, "data", "hanzi-writer-data"))
        path_dir = os.path.join(folder, ".bin")
        os.makedirs(path_dir)
        os.symlink(os.path.abspath(CLI), os.path.join(path_dir, "calligraphy"))
        os.symlink(PYTHON, os.path.join(path_dir, "python3"))
        env = dict(os.environ)
        env["PATH"] = path_dir + os.pathsep + env.get("PATH", "")
        env["PYTHONPATH"] = os.path.join(folder, "build", "python")
        env["MPLBACKEND"] = "Agg"   # no display: a figure is drawn, not shown
        # An example run without its output option writes under the temporary folder (tempfile.mkdtemp):
        # one of this test's own, removed with it.
        scratch = tempfile.mkdtemp(prefix="docs-examples-tmp-")
        self.addCleanup(shutil.rmtree, scratch, True)
        env["TMPDIR"] = scratch
        env.pop("DISPLAY", None)
        return folder, env

    def run_shell(self, doc, line, body, folder, env, variables):
        for logical in logical_lines(body):
            for step in logical.split(" && "):
                command = synopsis(strip_comment(step.strip())[0])
                for one in expand_alternatives(command):
                    self.tally["steps"] += 1
                    rule = skip_rule(one)
                    if rule:
                        self.tally["skipped"] += 1
                        self.skips.append("%s:%d `%s`: %s (%s)" % (doc, line, one, rule[0], rule[1]))
                        continue
                    one_run = cap(substitute(one), folder, env)
                    if re.match(r"^\w+=\S+$", one_run):    # an assignment the later lines use
                        variables.append(one_run)
                        continue
                    if run_by_round15a(doc, one_run):
                        self.tally["skipped"] += 1
                        self.skips.append("%s:%d `%s`: round15a (run as `%s` by round 15A, cli_unseen_round15a_tests,"
                                          " with this test's checks and more)" % (doc, line, one, one_run))
                        continue
                    self.tally["run"] += 1
                    script = "\n".join(variables + [one_run])
                    with self.subTest(doc=doc, line=line, step=one):
                        keyed = study_key(one_run, folder)
                        if keyed and keyed[0] in _STUDY_CACHE:
                            copy, proc, where = _STUDY_CACHE[keyed[0]]
                            shutil.copytree(copy, keyed[1])
                            self.skips.append("%s:%d `%s`: not run again, its output copied from the same "
                                              "command on the same input at %s" % (doc, line, one, where))
                        else:
                            before = _children_cpu()
                            proc = subprocess.run(["bash", "-c", script], cwd=folder, env=env, capture_output=True,
                                                  text=True, timeout=300)
                            self.costs.append((_children_cpu() - before, "%s:%d `%s`" % (doc, line, one_run)))
                            if keyed and proc.returncode == 0 and os.path.isdir(keyed[1]):
                                copy = os.path.join(self.cache_dir(), str(len(_STUDY_CACHE)))
                                shutil.copytree(keyed[1], copy)
                                _STUDY_CACHE[keyed[0]] = (copy, proc, "%s:%d" % (doc, line))
                        expected = EXPECTED_STATUS.get(one, 0)
                        self.assertEqual(proc.returncode, expected,
                                         "%s:%d `%s` exit %d\n%s" % (doc, line, one, proc.returncode, proc.stderr[-3000:]))
                        self.assertIsNone(ERROR_LINE.search(proc.stderr + proc.stdout),
                                          "%s:%d `%s` printed an error\n%s" % (doc, line, one, proc.stderr[-3000:]))
                        for out in output_paths(one_run):
                            self.assertTrue(_nonempty(os.path.join(folder, out)),
                                            "%s:%d `%s`: %s not made or empty" % (doc, line, one, out))
                            check_output_kind(self, os.path.join(folder, out))
                        for pattern, check in CHECKS:
                            if pattern.search(one):
                                check(self, proc.stdout, folder)

    def run_python(self, doc, blocks, folder, env):
        payload = []
        for line, body in blocks:
            name = "%s:%d" % (doc, line)
            rule = next(((n, r) for n, r, p in PY_SKIP if p.search(body)), None)
            if rule:
                self.tally["python_skipped"] += 1
                self.skips.append("%s (Python block): %s (%s)" % (name, rule[0], rule[1]))
                continue
            fixture = "".join(v for k, v in PY_FIXTURES.items() if k in body)
            check = "".join(v for k, v in PY_CHECKS.items() if k in body)
            payload.append({"name": name, "code": cap_python(body, folder, env), "fixture": fixture, "check": check})
            self.tally["python_run"] += 1
        if not payload:
            return
        spec = os.path.join(folder, ".blocks.json")
        with open(spec, "w", encoding="utf-8") as f:
            json.dump(payload, f)
        before = _children_cpu()
        proc = subprocess.run([PYTHON, "-c", PY_RUNNER, spec], cwd=folder, env=env, capture_output=True, text=True,
                              timeout=600)
        self.costs.append((_children_cpu() - before, "%s: %d Python blocks" % (doc, len(payload))))
        results = [json.loads(l) for l in proc.stdout.splitlines() if l.startswith("{")]
        self.assertEqual(len(results), len(payload), proc.stderr[-3000:])
        self.assertIsNone(ERROR_LINE.search(proc.stderr), "%s's Python blocks printed an error\n%s" % (
            doc, proc.stderr[-3000:]))
        for r in results:
            self.costs.append((r.get("cpu", 0.0), "  of which the Python block " + r["name"]))
            with self.subTest(block=r["name"]):
                self.assertTrue(r["ok"], "%s raised:\n%s" % (r["name"], r.get("error", "")))

    def run_document(self, doc):
        folder, env = self.folder_for(doc)
        variables = []
        python_blocks = []
        for line, lang, kind, body in extract(doc):
            self.tally["blocks"] += 1
            self.tally[kind] += 1
            if kind == "shell":
                # Python blocks before this shell block run first: the document's order is kept.
                if python_blocks:
                    self.run_python(doc, python_blocks, folder, env)
                    python_blocks = []
                self.run_shell(doc, line, body, folder, env, variables)
            elif kind == "python":
                python_blocks.append((line, body))
        if python_blocks:
            self.run_python(doc, python_blocks, folder, env)


# Documents whose examples run whole studies or cohorts for most of a minute of CPU each: run when
# CALLIGRAPHY_DOCS_EXAMPLES_ALL=1 (docs/testing.md, the long sweeps), skipped visibly otherwise, so that the
# suite keeps its time budget. Their commands are the ones the other documents' studies run, on more subjects.
LONG_DOCUMENTS = {
    os.path.join("docs", "learning-study.md"): "two crossover studies of 4 subjects and their paper, about 45 s of CPU",
    os.path.join("docs", "experiments.md"): "a learning study of 3 subjects and its paper, about 30 s of CPU",
    os.path.join("docs", "python.md"): "a cohort of 14 simulated subjects, sweeps and statistics, about 45 s of CPU",
}
ALL = os.environ.get("CALLIGRAPHY_DOCS_EXAMPLES_ALL") == "1"


def _make_test(doc):
    def test(self):
        self.run_document(doc)
    test.__doc__ = "every example of %s, run as written" % doc
    if doc in LONG_DOCUMENTS and not ALL:
        return unittest.skip("%s (CALLIGRAPHY_DOCS_EXAMPLES_ALL=1 runs it)" % LONG_DOCUMENTS[doc])(test)
    return test


for _doc in documents():
    setattr(DocsExamples, "test_" + re.sub(r"\W", "_", os.path.basename(_doc)[:-3]), _make_test(_doc))


if __name__ == "__main__":
    if not CLI:
        print("CALLIGRAPHY_CLI is not set", file=sys.stderr)
        sys.exit(2)
    unittest.main(verbosity=2)
