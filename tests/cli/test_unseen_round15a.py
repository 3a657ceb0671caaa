#!/usr/bin/env python3
"""Round 15A: every runnable example of README.md and docs/*.md, run as a newcomer copies it, written from the
docs alone. Run by CTest as `cli_unseen_round15a_tests`.

The examples are read from the Markdown when the test runs, so an example added later is covered without
editing this file: each command of a fenced shell block (```` ```sh ````, or unmarked and starting with a
command), each ```` ```python ```` block, and each command in backticks in the prose that runs as written
(`calligraphy characters --strokes 4 --typical HZG`; a synopsis with a placeholder such as `DIR`, `[options]` or
`...` is no example). Each document runs in a fresh folder laid out as the source tree (`build/bin/calligraphy`
the program under test, `build/python` the module, copies of `examples/`, `docs/` and `data/`), its examples in
order, so that a later one finds the files an earlier one made; its Python blocks share one namespace.

What each example is held to, from the docs (docs/cli.md "Conventions" and "Exit statuses", the text beside it):
- its exit status: 0, or the status the docs give the example (`calligraphy trail 永`: a usage error, 2);
- standard error: no error line and no traceback (the library's warnings are allowed, docs/cli.md "The
  library's log"), and never a log line or an error line on standard output;
- standard output: a document alone where an output is `-` or the command takes `--json` as a flag (it parses);
- the files: every file or folder it makes or changes is one it names (an output option's value, `mkdir`'s
  folder, a name in a Python block's text) or a companion its docs name (`report --out X.html`'s `X_files`),
  and no temporary is left; a document the example regenerates (`--markdown docs/X.md`) is unchanged; each
  output option's file or folder is made and not empty, a .json one JSON, a .svg one SVG, a .csv one a table
  with a header line;
- what the text beside it says of its output: a comment `again.csv == out.csv`, the 39 typical strokes, a
  table per stroke, a session per subject, keys in SI units, a Python expression's value or shape given in its
  comment (`yong.typical_stroke_ids  # [4, 10, 8, 3, 5]`), Table 5's table of its four characters, and the
  numbers a document quotes from a run of the example (docs/python.md's Table 5) within their printed rounding.
(test_docs_examples.py leaves the README's study, cohort and Table 5 to this round, which holds them to all of
its checks of them.)

An example is skipped only by a named rule, printed with it: a build or install step, a haptic device or a
person, the trainer window, the network (npm, cnchar), a benchmark or fuzzing campaign (their output is a
timing), R. Where the docs' example would cost more than this round's budget (a cohort of 70 simulated
subjects, 15 subjects of a study, 8 seeds of every trial of Table 5 beside the README's 4, 4 seeds of a sweep,
the corpus sweep's 58 characters), it runs with a smaller count of its own option, said in the printed line; a
real-time trial, which lasts as long as its writing (永 about 14 s), writes the one-stroke 一 (about 4 s) with the
same options; a store built from the whole data set is the bundled one (docs/corpus.md: data/corpus is that
build). A simulated study's `session run` that several documents (and a Python example's input) run alike, on
the same protocol, runs once: the later ones get a copy of its study and its output, said in the printed line.
CALLIGRAPHY_CORPUS_DIR names the fetched hanzi-writer-data package where an example fetches it.
"""
import ast
import atexit
import hashlib
import io
import resource
import json
import os
import re
import shlex
import shutil
import subprocess
import sys
import tempfile
import time
import unittest
import contextlib
from pathlib import Path
from xml.etree import ElementTree

from outsider import CLI, SANITIZED, sanitized_subset, strip_comment

SOURCE = Path(os.environ.get("CALLIGRAPHY_SOURCE_DIR", Path(__file__).resolve().parents[2]))
PYTHONPATH = os.environ.get("PYTHONPATH", "").split(os.pathsep)[0]
CORPUS_DIR = os.environ.get("CALLIGRAPHY_CORPUS_DIR", "")
TIMEOUT_S = 240
ALL = os.environ.get("CALLIGRAPHY_DOCS_EXAMPLES_ALL") == "1"  # the long forms too (docs/testing.md)
LONG_DOCUMENTS = {  # run only with CALLIGRAPHY_DOCS_EXAMPLES_ALL=1, to keep the suite's budget
    "docs/learning-study.md": "two studies and their reports with statistics, about 20 s of CPU",
}

load_tests = sanitized_subset({"test_docs_cli_md", "test_docs_corpus_md", "test_docs_architecture_md",
                               "test_docs_devices_md", "test_docs_metrics_md"})

# Tokens that mark a synopsis, not an example: a placeholder the reader replaces.
PLACEHOLDERS = {"CHARS", "CHAR", "C", "DIR", "FILE", "RECORD", "TRACE", "T", "N", "S", "G", "X", "ID", "PROTOCOL",
                "FOLDER", "DATA", "KANJIVG", "HZ", "P", "PREFIX", "TABLES", "COMMAND", "NAME", "PROFILE", "STEM",
                "FILE.html", "DIR...", "SUBJECT", "K"}
FENCE = re.compile(r"^```(\w*)\s*$")
SHELL_START = re.compile(r"^(build/|calligraphy |python3 |/usr/bin/|PYTHONPATH=|[A-Z_]+=\S* |mkdir |scripts/|bash "
                         r"|cmake |ctest |data=|for |nice |lab/|# )")


class Example:
    def __init__(self, doc, line, kind, text, comment=""):
        self.doc, self.line, self.kind, self.text, self.comment = doc, line, kind, text, comment

    def __str__(self):
        first = self.text.strip().splitlines()[0] if self.text.strip() else ""
        return f"{self.doc}:{self.line} [{self.kind}] {first[:110]}"



def comment_run(lines, index):
    """The comment of lines[index] and of the comment-only lines that go on from it (indented under it)."""
    parts = [strip_comment(lines[index])[1]]
    for line in lines[index + 1:]:
        code, comment = strip_comment(line)
        if code.strip() or not comment:
            break
        parts.append(comment)
    return " ".join(parts)


def shell_steps(doc, start, lines):
    """The commands of a shell block: continuation lines joined, a `for ... done` loop as one."""
    steps, i = [], 0
    while i < len(lines):
        raw = lines[i]
        line_no = start + i
        if not raw.strip() or raw.lstrip().startswith("#"):
            i += 1
            continue
        text, comment = strip_comment(raw)
        while text.endswith("\\") and i + 1 < len(lines):
            i += 1
            more, more_comment = strip_comment(lines[i])
            text = text[:-1].rstrip() + " " + more.strip()
            comment = comment or more_comment
        if re.match(r"^for\b", text):
            body = [text]
            while not re.match(r"^\s*done\b", lines[i]) and i + 1 < len(lines):
                i += 1
                body.append(strip_comment(lines[i])[0])
            text = "\n".join(body)
        # a block names its own files and folders with single letters (`--out S`): only words are placeholders
        words_only = {p for p in PLACEHOLDERS if len(p) > 1}
        if not runnable(text, words_only):
            text = without_optional(text)
        steps.append(Example(doc, line_no, "sh" if runnable(text, words_only) else "synopsis", text, comment))
        i += 1
    return steps


def inline_examples(doc, text_lines):
    """Commands in backticks in the prose that run as written."""
    found = []
    prose = re.sub(r"<!--.*?-->", lambda m: "\n" * m.group(0).count("\n"), "\n".join(text_lines), flags=re.S)
    for match in re.finditer(r"`((?:build/bin/)?calligraphy [^`]+)`", prose):
        command = " ".join(match.group(1).split())
        line = prose.count("\n", 0, match.start()) + 1
        if runnable_inline(command):
            found.append(Example(doc, line, "inline", command))
    return found


def runnable_inline(command):
    """A command in the prose is an example when it gives a value: a positional or an option's value beyond
    the command's name (`calligraphy trial --json` names an option, it is no example)."""
    words = command.split()
    if re.match(r"^\S+ [\w-]+:", command):  # a quoted message
        return False
    start = 3 if len(words) > 1 and words[1] in ("corpus", "bench", "session") else 2
    if not any(not w.startswith("-") for w in words[start:]):
        return False
    return runnable(command)


def runnable(command, placeholders=PLACEHOLDERS):
    """No placeholder, optional part, alternative or ellipsis left: the reader can run it as written."""
    if "..." in command or re.search(r"\s\[", command) or re.search(r"calligraphy \S+ \S+\|\S", command):
        return False
    return not any(w.rstrip(".,;") in placeholders or re.fullmatch(r"X\.Y\.Z|S\d*N+", w) for w in command.split())


def without_optional(command):
    """A synopsis with its optional parts (`[--json]`) left out, as a reader first runs it."""
    return re.sub(r"\s+\[[^\[\]]*\]", "", command)


def extract(doc_path):
    lines = doc_path.read_text(encoding="utf-8").splitlines()
    rel = str(doc_path.relative_to(SOURCE))
    examples, prose, i = [], [], 0
    while i < len(lines):
        fence = FENCE.match(lines[i])
        if not fence:
            prose.append(lines[i])
            i += 1
            continue
        lang, j = fence.group(1), i + 1
        while j < len(lines) and not lines[j].startswith("```"):
            j += 1
        body = lines[i + 1:j]
        prose.extend([""] * (j - i + 1))
        first = next((b for b in body if b.strip()), "")
        if lang == "python":
            examples.append(Example(rel, i + 2, "python", "\n".join(body)))
        elif lang in ("sh", "bash") or (lang == "" and SHELL_START.match(first)):
            examples.extend(shell_steps(rel, i + 2, body))
        i = j + 1
    examples.extend(inline_examples(rel, prose))
    examples.sort(key=lambda e: e.line)
    return examples


# ---------------------------------------------------------------------------------------------------------------
# Skips by named rule, and the cheaper forms of long examples.

def skip_reason(example):
    t = example.text
    if example.kind == "synopsis":
        return "a synopsis: placeholders or alternatives to choose from, not one command"
    if example.kind == "python":
        if "distributed.LocalCluster(...)" in t:
            return "a Dask cluster of the reader's (`LocalCluster(...)` is elided in the example)"
        if SANITIZED or not PYTHONPATH:
            return "the Python module is not built under the sanitizers (no PYTHONPATH)"
        return None
    rules = [
        (r"(^|&& )(bash )?scripts/(install-deps|test)\.sh|^cmake |(^| )ctest |pip install|-m venv|^lab/bin/",
         "a build, install or test-suite step"),
        (r"-m pytest", "a build, install or test-suite step"),
        (r"fetch-cnchar-order", "the network (cnchar from npm)"),
        (r"^(bash )?scripts/fetch-hanzi-writer-data\.sh$", "the network (npm): CALLIGRAPHY_CORPUS_DIR stands for it"),
        (r"^(?!.*session run).*(--device (phantom|openhaptics|mouse)|--writer person)", "a haptic device held by a "
         "person"),
        (r"calligraphy train\b.*--writer simulated", "the trainer window (a display): seconds of software-drawn "
         "frames under Xvfb, the trainer tests' own subject"),
        (r"calligraphy train\b", "the trainer window and a person at it (display)"),
        (r"calligraphy bench (nearest|jumps|loop|acceptance)|bench/|_bench\b|fuzz", "a benchmark or fuzzing run (its "
         "output is a timing, not checkable, and seconds of CPU)"),
        (r"corpus fidelity", "a sweep of the whole corpus at four tolerances (minutes of CPU)"),
        (r"corpus_sweep\.py --data", "a sweep of the whole corpus (minutes of CPU)"),
        (r"--kanjivg", "KanjiVG data (the network)"),
        (r"strace ", "a measurement of the test suite"),
        (r"/usr/bin/time ", "a measurement of the test suite"),
        # The fetched data, and the store an example before builds from it.
        (r"\$\(scripts/fetch-hanzi-writer-data\.sh\)|\$data|--store corpus\.clg", None),
    ]
    for pattern, reason in rules:
        if re.search(pattern, t):
            if reason is None:
                if not CORPUS_DIR or not os.path.isdir(CORPUS_DIR):
                    return "the network (npm); CALLIGRAPHY_CORPUS_DIR not given"
                continue
            return reason
    if re.search(r"(^|\s)(python3|/usr/bin/python3)\s", t) and (SANITIZED or not PYTHONPATH):
        return "the Python module is not built under the sanitizers (no PYTHONPATH)"
    return None


def cheaper(text):
    """The example in a cheaper form where it runs long, and what was changed (empty: as written)."""
    changes = []
    if re.search(r"corpus build (--data \S+ )?--out (?!data/)", text):
        return None, "a store of the whole data set (minutes of CPU): the bundled store, data/corpus's build of it"
    if re.search(r"corpus build --data \S+ --out data/corpus", text):
        return None, "rebuilding the bundled store (minutes of CPU)"

    def cap(pattern, limit, label):
        nonlocal text
        m = re.search(pattern, text)
        if m and int(m.group(2)) > limit:
            text = text[:m.start(2)] + str(limit) + text[m.end(2):]
            changes.append(f"{label} {m.group(2)} -> {limit}")
    m = re.search(r"session run \S+ .*(--device (phantom|openhaptics|mouse)\S*)", text)
    if m:  # a person at a haptic device: the simulated writer on the simulated device, as docs/cli.md allows
        text = text.replace(m.group(1), "--writer simulated")
        changes.append(f"{m.group(1)} -> --writer simulated")
    cap(r"(session cohort \S+ --subjects )(\d+)", 7, "--subjects")
    cap(r"(retention-transfer\.json .*?--subjects )(\d+)", 3, "--subjects")
    cap(r"(crossover\.json .*?--subjects )(\d+)", 2, "--subjects")
    cap(r"(paper-table5\.json .*?--subjects )(\d+)", 2, "--subjects")
    if not ALL:
        cap(r"(table5\.py --seeds )(\d+)", 1, "--seeds")
        if changes and "table5.py" in text:
            changes.append("the figures it quotes are checked with CALLIGRAPHY_DOCS_EXAMPLES_ALL=1, 11 s of CPU")
    if re.search(r"table5\.py\s*$", text):
        text = text.rstrip() + " --seeds 1"
        changes.append("--seeds 4 -> 1 (docs/python.md's example runs the 8 seeds it quotes)")
    if re.search(r"cohort\.simulate\([^)]*\b70\b", text):
        text = re.sub(r"(cohort\.simulate\([^,]+, )70\b", r"\g<1>12", text)
        changes.append("70 subjects -> 12, two or more in each group it compares")
    # A real-time trial lasts as long as its writing (永 about 14 s, 口 9 s): the one-stroke 一 (4 s) is paced
    # by the same loop with the same options.
    m = re.search(r"calligraphy trial ([\u3400-\u9fff]+) [^\n&|;]*--pacing real-time", text)
    if m and m.group(1) != "一":
        text = text[:m.start(1)] + "一" + text[m.end(1):]
        changes.append(f"{m.group(1)} -> 一: a real-time trial lasts as long as its writing")
    # A sweep's seeds are alike (each a trial per character and grid point): one seed, every character and
    # grid point as written.
    cap(r"(\bsweep\([^)\n]*\bseeds=)(\d+)", 1, "the sweep's seeds")
    # The corpus sweep of every embedded character on the local pool: its own --limit, 4 characters (8 trials,
    # guidance off and on, work for each worker), the table, the summary and the figure as written.
    if re.search(r"examples/python/corpus_sweep\.py\s*$", text):
        text = text.rstrip() + " --limit 4"
        changes.append("the 58 embedded characters -> --limit 4")
    for placeholder, value in PYTHON_PLACEHOLDERS.items():
        if placeholder in text:
            text = text.replace(placeholder, value)
            changes.append(f"{placeholder} -> {value}")
    return text, "; ".join(changes)


# ---------------------------------------------------------------------------------------------------------------
# The folder an example runs in.

# Paths a Python example leaves to the reader, and the names its fragments use without defining them.
PYTHON_PLACEHOLDERS = {'"path/to/hanzi-writer-data"': '"data/hanzi-writer-data"'}
PYTHON_INPUTS = {  # a study a Python example reads that its document does not make: a simulated one
    "S": "build/bin/calligraphy session run examples/protocols/paper-table5.json --writer simulated --subjects 2 "
         "--out S",
    "study": "build/bin/calligraphy session run examples/protocols/retention-transfer.json --writer simulated "
             "--subjects 3 --out study && build/bin/calligraphy report study --out study/trials.html",
}
FREE_NAMES = {
    "points": "np.array([[500.0, 600.0], [100.0, -50.0]])", "points_m": "np.array([[0.01, 0.02]])",
    "t_s": "0.0", "x": "0.01", "y": "0.02", "z": "0.001", "vx": "0.0", "vy": "0.01", "vz": "0.0", "t": "0.0",
    "tip_z_m": "-0.001", "tip_m": "np.array([0.01, 0.02])", "foot_m": "np.array([0.0105, 0.02])",
    "velocity_m_s": "np.array([0.01, 0.0])", "tangent": "np.array([1.0, 0.0])", "normal_force_n": "1.0",
    "distance_m": "0.002", "forces_n": "np.array([10.0, 0.0, 0.0])",
    "trials": "__import__('calligraphy.study').study.load('S').trials",
}
LAYOUT = ("build", "examples", "docs", "data", "scripts", "README.md")


def lay_out(folder):
    (folder / "build" / "bin").mkdir(parents=True)
    os.symlink(CLI, folder / "build" / "bin" / "calligraphy")
    if PYTHONPATH:
        os.symlink(os.path.abspath(PYTHONPATH), folder / "build" / "python")
    for name in ("examples", "docs", "scripts"):
        shutil.copytree(SOURCE / name, folder / name, symlinks=True)
    (folder / "data").mkdir()
    os.symlink(SOURCE / "data" / "hanzi-writer-data", folder / "data" / "hanzi-writer-data")
    shutil.copy(SOURCE / "README.md", folder / "README.md")
    bindir = folder / ".bin"
    bindir.mkdir()
    os.symlink(CLI, bindir / "calligraphy")
    os.symlink("/usr/bin/python3", bindir / "python3")


def snapshot(folder):
    """Every path under the folder but the source tree's layout, with its size and modification time."""
    seen = {}
    for root, dirs, files in os.walk(folder):
        rel_root = Path(root).relative_to(folder)
        if rel_root.parts and rel_root.parts[0] in (".bin", "build", "examples", "data", "scripts"):
            continue
        for name in dirs + files:
            p = Path(root) / name
            st = p.lstat()
            seen[str(rel_root / name)] = (st.st_size, st.st_mtime_ns, p.is_dir())
    return seen


def named_outputs(example, text):
    """The files and folders the example names as what it writes."""
    names = set()
    if example.kind == "python":
        for literal in re.findall(r"\"([^\"\n]+)\"", text):
            if re.fullmatch(r"[\w./-]+", literal) and not literal.startswith("examples/"):
                names.add(literal.strip("/"))
        return names
    for command in re.split(r"&&|;|\n", text):
        try:
            words = shlex.split(command, comments=True)
        except ValueError:
            words = command.split()
        for k, w in enumerate(words):
            if w in ("--json", "--svg", "--csv", "--out", "--record", "--markdown", "--screenshot") and k + 1 < len(
                    words) and not words[k + 1].startswith("-"):
                names.add(words[k + 1].rstrip("/"))
            if w.startswith("--") and "=" in w and w.split("=")[0] in ("--json", "--csv", "--out", "--svg"):
                names.add(w.split("=", 1)[1])
        if words[:1] == ["mkdir"]:
            names.update(x.rstrip("/") for x in words[1:] if not x.startswith("-"))
    names.update(f.rstrip("/") for f in re.findall(r"(?:^|\s)([\w.-]+/)(?=[\s,;:)]|$)", example.comment))  # `into X/`
    for name in list(names):
        if name.endswith(".html"):
            names.add(name[:-5] + "_files")  # report --out X.html: X_files (docs/cli.md "report")
    return names


def covered(path, names):
    return any(path == n or path.startswith(n + "/") or n.startswith(path + "/") for n in names)


# ---------------------------------------------------------------------------------------------------------------
# What the text beside an example says of its output.

# An error line on either stream (what test_docs_examples.py holds the same examples to).
ERROR_LINE = re.compile(r"^(?:error|Error|ERROR|calligraphy[\w .-]*: error)\b|Traceback \(most recent call last\)",
                        re.M)


def option_outputs(text):
    """The values of the output options of the example's commands (`--json`, `--svg`, `--csv`, `--out`,
    `--record`, `--markdown`) and of its redirections (`> FILE`): files and folders it makes, never empty."""
    outs = []
    for command in re.split(r"&&|;|\n", text):
        try:
            words = shlex.split(command, comments=True)
        except ValueError:
            continue
        for k, w in enumerate(words[:-1]):
            if w in ("--json", "--svg", "--csv", "--out", "--record", "--markdown", ">") and not words[
                    k + 1].startswith(("-", "/dev/")):
                outs.append(words[k + 1])
    return outs


def nonempty(path):
    return any(path.iterdir()) if path.is_dir() else path.is_file() and path.stat().st_size > 0


# A simulated study's `session run` alone (the same command in several documents, and the study a Python
# example reads): run once in this process, and where the same command runs again on the same protocol with
# its output folder absent, its study copied and its exit status and output given again, so that each
# document's checks read the one run's outputs.
STUDY_RUN = re.compile(r"build/bin/calligraphy session run (\S+\.json) --writer simulated --subjects \d+ --out (\S+)")
_STUDIES = {}  # (command, protocol's SHA-256) -> (result, copy of its study, where it ran)
_STUDY_COPIES = []


def run_bash(text, folder, env, where):
    """`bash -c` the text in the folder (pipefail, no standard input, output captured)."""
    m = STUDY_RUN.fullmatch(text.strip())
    key = None
    if m and (folder / m.group(1)).is_file() and not os.path.lexists(folder / m.group(2)):
        key = (text.strip(), hashlib.sha256((folder / m.group(1)).read_bytes()).hexdigest())
        if key in _STUDIES:
            result, copy, first = _STUDIES[key]
            shutil.copytree(copy, folder / m.group(2), symlinks=True)
            print(f"     (not run again: the study and output of the same command on the same protocol at {first})",
                  file=sys.stderr)
            return result
    result = subprocess.run(["bash", "-c", "set -o pipefail\n" + text], cwd=folder, env=env,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, stdin=subprocess.DEVNULL,
                            timeout=TIMEOUT_S)
    if key and result.returncode == 0 and (folder / m.group(2)).is_dir():
        if not _STUDY_COPIES:
            _STUDY_COPIES.append(tempfile.mkdtemp(prefix="r15a-studies-"))
            atexit.register(shutil.rmtree, _STUDY_COPIES[0], True)
        copy = Path(_STUDY_COPIES[0]) / str(len(_STUDIES))
        shutil.copytree(folder / m.group(2), copy, symlinks=True)
        _STUDIES[key] = (result, copy, where)
    return result


def stdout_is_one_document(text):
    for command in re.split(r"&&|\n", text):
        words = command.split()
        if "calligraphy" not in " ".join(words[:2]):
            continue
        for k, w in enumerate(words):
            if w in ("--json", "--svg", "--csv", "--out", "--markdown") and k + 1 < len(words) and words[k + 1] == "-":
                return "svg" if w == "--svg" else ("csv" if w == "--csv" else "json" if w == "--json" else "text")
            if w == "--json" and (k + 1 == len(words) or words[k + 1].startswith("-")):
                return "json"
    return None


SI_SUFFIXES = ("_m", "_n", "_s", "_hz", "_kg", "_n_per_m", "_n_s_per_m", "_m_s", "_m_per_s")

EXIT_STATUS = {  # examples the docs give as refused, with the status the docs give them
    r"calligraphy trail 永": 2,
    r"--guidence on": 2,
    r"> /dev/full": 1,
}


def cpu_seconds():
    """This process's and its waited-for children's processor time [s]."""
    usage = [resource.getrusage(who) for who in (resource.RUSAGE_SELF, resource.RUSAGE_CHILDREN)]
    return sum(u.ru_utime + u.ru_stime for u in usage)


class Round15A(unittest.TestCase):
    maxDiff = None

    def run_document(self, name):
        if name in LONG_DOCUMENTS and not ALL:
            self.skipTest(f"{name}: {LONG_DOCUMENTS[name]}; run with CALLIGRAPHY_DOCS_EXAMPLES_ALL=1")
        doc = SOURCE / name
        self.cpu_before = cpu_seconds()
        examples = extract(doc)
        if not examples:
            self.skipTest(f"{name}: no runnable example")
        tmp = tempfile.mkdtemp(prefix="r15a-")
        self.addCleanup(shutil.rmtree, tmp, True)
        folder = Path(tmp) / "reader"
        folder.mkdir()
        lay_out(folder)
        env = {k: v for k, v in os.environ.items() if k not in ("DISPLAY", "WAYLAND_DISPLAY")
               and not k.startswith("CALLIGRAPHY_LIBHD")}
        env["PATH"] = f"{folder / '.bin'}:{env.get('PATH', '/usr/bin:/bin')}"
        env["PYTHONPATH"] = str(folder / "build" / "python")
        env["MPLBACKEND"] = "Agg"
        env["XDG_CACHE_HOME"] = str(Path(tmp) / "cache")
        # An example run without its output option writes under the temporary folder: this round's own.
        (Path(tmp) / "tmp").mkdir()
        env["TMPDIR"] = str(Path(tmp) / "tmp")
        self.env = env
        namespace = {"__name__": "__docs__"}
        self.trial_outputs = {}  # a trial's --csv trace: its --json record
        ran = 0
        for example in examples:
            reason = skip_reason(example)
            text, change = (example.text, "") if reason else cheaper(example.text)
            if not reason and text is None:
                reason = change
                if change.startswith("a store of the whole"):
                    out = re.search(r"--out (\S+)", example.text).group(1)
                    shutil.copy(SOURCE / "data" / "corpus" / "hanzi-writer-data-2.0.1.clg", folder / out)
            if reason:
                print(f"SKIP {example}: {reason}", file=sys.stderr)
                continue
            print(f"RUN  {example}" + (f"  (cheaper: {change})" if change else ""), file=sys.stderr)
            ran += 1
            started = time.monotonic(), cpu_seconds()
            with self.subTest(example=str(example)):
                if example.kind == "python":
                    self.run_python(example, text, folder, namespace)
                else:
                    self.run_shell(example, text, folder, env)
            print(f"     {time.monotonic() - started[0]:.1f} s wall, {cpu_seconds() - started[1]:.1f} s of CPU",
                  file=sys.stderr)
        cpu = cpu_seconds() - self.cpu_before
        print(f"{name}: {ran} examples run of {len(examples)} ({cpu:.1f} s of CPU)", file=sys.stderr)

    # -- shell -------------------------------------------------------------------------------------------------
    def run_shell(self, example, text, folder, env):
        if CORPUS_DIR:
            text = text.replace('"$(scripts/fetch-hanzi-writer-data.sh)"', shlex.quote(CORPUS_DIR))
            text = text.replace('"$(bash scripts/fetch-hanzi-writer-data.sh)"', shlex.quote(CORPUS_DIR))
        before = snapshot(folder)
        docs_before = {p: p.read_bytes() for p in (folder / "docs").glob("*.md")}
        result = run_bash(text, folder, env, f"{example.doc}:{example.line}")
        out = result.stdout.decode("utf-8", "replace")
        err = result.stderr.decode("utf-8", "replace")
        expected = next((s for p, s in EXIT_STATUS.items() if re.search(p, text)), 0)
        self.assertEqual(result.returncode, expected, f"{example}: exit {result.returncode}\n{err[-2000:]}")
        self.assertNotIn("Traceback", err, f"{example}\n{err[-2000:]}")
        if expected == 0:
            self.assertNotRegex(err, r"(?m)^calligraphy [\w ]+: error:|^Error|^error", f"{example}\n{err[-2000:]}")
            self.assertIsNone(ERROR_LINE.search(out), f"{example}: an error line on standard output\n{out[-2000:]}")
            self.assertIsNone(ERROR_LINE.search(err), f"{example}: an error line\n{err[-2000:]}")
        self.assertNotRegex(out, r"(?m)^calligraphy [\w ]+: (warning|info|error):|\[(info|warning)\]",
                            f"{example}: the library's log on standard output")
        kind = stdout_is_one_document(text)
        if kind == "json" and expected == 0:
            try:
                json.loads(out)
            except ValueError as e:
                self.fail(f"{example}: standard output is not one JSON document ({e}): {out[:300]!r}")
        elif kind == "svg" and expected == 0:
            self.assertRegex(out.lstrip(), r"^(<\?xml|<svg)", f"{example}: standard output is not an SVG alone")
        self.check_files(example, text, folder, before)
        if expected == 0:
            for name in option_outputs(text):
                self.assertTrue(nonempty(folder / name), f"{example}: {name} not made or empty")
                self.check_output_kind(example, folder / name)
        for path, data in docs_before.items():
            self.assertEqual(path.read_bytes(), data, f"{example}: regenerated {path.name} differs from the document")
        self.check_said(example, text, folder, out, err)

    def check_files(self, example, text, folder, before):
        after = snapshot(folder)
        names = named_outputs(example, text)
        changed = sorted(p for p, v in after.items() if before.get(p) != v and not (v[2] and p in before))
        stray = [p for p in changed if not covered(p, names) and not p.startswith("docs/")]
        self.assertEqual(stray, [], f"{example}: wrote what it does not name (it names {sorted(names)})")
        temporaries = [p for p in after if re.search(r"\.(tmp|part)\b|~$|\.partial\.", Path(p).name)]
        self.assertEqual(temporaries, [], f"{example}: temporaries left")
        for name in names:
            if example.kind != "python" and not name.startswith("-") and not name.endswith("_files"):
                self.assertTrue((folder / name).exists(), f"{example}: {name} was not written")

    def check_output_kind(self, example, path):
        """An output named .json is JSON, .svg an SVG document, .csv a table with a header line."""
        if not path.is_file():
            return
        if path.suffix == ".json":
            try:
                json.loads(path.read_text(encoding="utf-8"))
            except ValueError as e:
                self.fail(f"{example}: {path.name} is not JSON ({e})")
        elif path.suffix == ".svg":
            self.assertTrue(ElementTree.parse(path).getroot().tag.endswith("svg"), f"{example}: {path.name}")
        elif path.suffix == ".csv":
            with path.open(encoding="utf-8") as f:
                self.assertRegex(f.readline(), r"^[A-Za-z_][\w ,]*$", f"{example}: {path.name} has no header line")

    def check_said(self, example, text, folder, out, err):
        """What the text beside the example says of its output."""
        comment = example.comment
        same = re.search(r"(\S+) == (\S+)", comment)
        if same:
            a, b = (folder / same.group(1)), (folder / same.group(2))
            self.assertEqual(a.read_bytes(), b.read_bytes(), f"{example}: {same.group(0)} does not hold")
        if re.search(r"calligraphy strokes\s*$", text):
            ids = [int(m) for m in re.findall(r"(?m)^\s*(\d+)\b", out)]
            self.assertEqual(sorted(set(ids)), list(range(1, 40)), f"{example}: not the 39 typical strokes")
        m = re.search(r"calligraphy trial (\S+)\s*$", text) or re.search(r"calligraphy trial (\S+) --", text)
        if m and "table per stroke" in comment:
            rows = re.findall(r"(?m)^\s*(\d+)\s", out)
            self.assertEqual(rows[:5], ["1", "2", "3", "4", "5"], f"{example}: no row per stroke from 1\n{out}")
            self.assertRegex(out, r"(?m)^\s*strokes completed\s+\d+ / \d+", f"{example}: no summary in total")
        if "devices --json" in text and "SI" in comment:
            for device in json.loads(out)["devices"]:
                for key, value in device["info"].items():
                    if isinstance(value, (int, float)) or isinstance(value, list):
                        self.assertTrue(key.endswith(SI_SUFFIXES), f"{example}: {key} names no SI unit")
        m = re.search(r"session run \S+ .*--subjects (\d+)", text)
        if m and "--subject " not in text:
            # one line per session run (docs/cli.md), and a line when every session is done (docs/experiments.md)
            lines = [line for line in out.splitlines() if line.strip()]
            saved = [line for line in lines if re.match(r"^\S+: \d+ of \d+ trials saved .* in \S+", line)]
            done = [line for line in lines if re.match(r"^\S+: every session of \S+ is done", line)]
            self.assertEqual(len(saved) + len(done), len(lines), f"{example}: other lines on standard output\n{out}")
            self.assertEqual(len({line.split(":")[0] for line in saved}), int(m.group(1)), f"{example}\n{out}")
            for line in saved:
                self.assertTrue((folder / line.rsplit(" in ", 1)[1].split(",")[0]).is_dir(), f"{example}: {line}")
        m = re.search(r"report (\S+) .*--csv (\S+)", text)
        if m:
            for table in ("trials.csv", "strokes.csv"):
                self.assertTrue((folder / m.group(2) / table).is_file(), f"{example}: no {table}")
        m = re.search(r"study_report \S+ --out (\S+)", text)
        if m:
            self.assertTrue((folder / m.group(1) / "index.html").is_file(), f"{example}: no index.html")
        m = re.search(r"print\(c\.simulate_trial\('永', seed=1\)\.metrics\['mean_deviation_m'\]\)", text)
        if m:
            value = float(out.strip())
            self.assertTrue(0 < value < 0.005, f"{example}: {value} is not a deviation in metres")
        if "examples/python/table5.py" in text:
            # (a) the table of the paper's four characters, with and without guidance, whatever the seeds
            self.assertIn("dev off [mm]", out, f"{example}: no Table 5\n{out[-2000:]}")
            for char in "永我九心":
                self.assertIn(char, out, f"{example}: no row of {char}")
        if "table5.py --seeds 8" in text:
            self.check_table5(example, out)
        if "corpus stats" in text and "--json" in text:
            json.loads(out)
        listed = re.match(r"^((?:[\u3400-\u9fff] )+)", comment)  # `# 二 八 十 ... : every two-stroke character`
        if listed:
            for char in listed.group(1).split():
                self.assertIn(char, out, f"{example}: {char} is not listed")
        m = re.search(r"calligraphy trial .*--json (\S+) .*--csv (\S+)|calligraphy trial .*--csv (\S+) .*--json (\S+)",
                      text)
        if m and "--spec" not in text:
            record, trace = (m.group(1), m.group(2)) if m.group(1) else (m.group(4), m.group(3))
            self.trial_outputs[trace] = record
        m = re.search(r"calligraphy score (\S+) --character \S+ --json -", text)
        if m and m.group(1) in self.trial_outputs:
            # docs/cli.md: the trial's JSON holds every key of the metrics record "with the values `calligraphy
            # score` gives for the trial's CSV"
            trial = json.loads((folder / self.trial_outputs[m.group(1)]).read_text(encoding="utf-8"))
            scored = json.loads(out)
            shared = sorted(set(trial) & set(scored))
            self.assertIn("mean_deviation_m", shared, f"{example}: {sorted(scored)}")
            for key in shared:
                self.assert_same(trial[key], scored[key], f"{example}: /{key}")

    def assert_same(self, a, b, where):
        """Equal, numbers to 1e-9 relative (the trace's printed precision is far coarser; the sums may differ
        in their last bits)."""
        if isinstance(a, dict) and isinstance(b, dict):
            self.assertEqual(sorted(a), sorted(b), where)
            for k in a:
                self.assert_same(a[k], b[k], f"{where}/{k}")
        elif isinstance(a, list) and isinstance(b, list):
            self.assertEqual(len(a), len(b), where)
            for i, (x, y) in enumerate(zip(a, b)):
                self.assert_same(x, y, f"{where}/{i}")
        elif isinstance(a, float) or isinstance(b, float):
            self.assertAlmostEqual(a, b, delta=1e-9 * max(abs(a), abs(b), 1e-300), msg=where)
        else:
            self.assertEqual(a, b, where)

    def check_table5(self, example, out):
        """docs/python.md quotes the run of `table5.py --seeds 8`: each number within its printed rounding."""
        doc = (SOURCE / example.doc).read_text(encoding="utf-8").splitlines()[example.line:]
        doc = doc[:next((i for i, line in enumerate(doc) if line.startswith("## ")), len(doc))]
        rows = re.compile(r"^(novice|foreign|none|fixed|fading|replay)\s")
        quoted = [line for line in doc if "|" in line and rows.match(line)]
        printed = {line.split("|")[0].strip(): line for line in out.splitlines()
                   if rows.match(line)}
        self.assertEqual(len(quoted), 12)
        for line in quoted:
            key = line.split("|")[0].strip()
            self.assertIn(key, printed, f"{example}: no row {key!r}")
            want = re.findall(r"\d+\.\d+|\d+/\d+", line)
            got = re.findall(r"\d+\.\d+|\d+/\d+", printed[key])
            self.assertEqual(len(want), len(got), f"{example}: {key}: {printed[key]}")
            for w, g in zip(want, got):
                if "/" in w:
                    self.assertEqual(w, g, f"{example}: row {key!r}: docs {line!r}, run {printed[key]!r}")
                else:
                    ulp = 10 ** -len(w.split(".")[1])
                    self.assertLessEqual(abs(float(w) - float(g)), ulp * 1.01,
                                         f"{example}: row {key!r}: the docs quote {w}, the run gives {g}\n"
                                         f"docs: {line}\nrun:  {printed[key]}")

    # -- python ------------------------------------------------------------------------------------------------
    def run_python(self, example, text, folder, namespace):
        for name, command in PYTHON_INPUTS.items():
            if re.search(rf"load\(\"{name}\"\)|load\('{name}'\)", text + FREE_NAMES["trials"]) and not (
                    folder / name).exists():
                print(f"     (the study {name!r} it reads: {command})", file=sys.stderr)
                made = run_bash(command, folder, self.env, f"{example.doc}:{example.line}")
                if made.returncode != 0:
                    raise subprocess.CalledProcessError(made.returncode, command, made.stdout, made.stderr)
        where = folder
        for literal in re.findall(r"\"([\w.-]+\.(?:h5|json))\"", text):
            if not (folder / literal).exists():  # a file of a study made earlier, read where it lies
                found = sorted(folder.rglob(literal))
                if found:
                    where = found[0].parent
        before = snapshot(folder)
        cwd = os.getcwd()
        os.chdir(where)
        sys.path.insert(0, os.path.abspath(PYTHONPATH))
        for store in re.findall(r"\"([\w.-]+\.(?:store|clg))\"", text):
            if not (folder / store).exists():  # a store the reader built of the whole data set: the bundled one
                shutil.copy(SOURCE / "data" / "corpus" / "hanzi-writer-data-2.0.1.clg", folder / store)
                before = snapshot(folder)
        captured = io.StringIO()
        try:
            tree = ast.parse(text)
            lines = text.splitlines()
            with contextlib.redirect_stdout(captured):
                for node in tree.body:
                    code = compile(ast.Module(body=[node], type_ignores=[]), f"{example.doc}:{example.line}", "exec")
                    if isinstance(node, ast.Expr):
                        expression = compile(ast.Expression(node.value), f"{example.doc}", "eval")
                        value = self.with_free_names(lambda: eval(expression, namespace), namespace)
                        self.check_comment_value(example, lines[node.end_lineno - 1], value)
                        self.check_columns(example, comment_run(lines, node.end_lineno - 1), value)
                    else:
                        self.with_free_names(lambda: exec(code, namespace), namespace)
                        comment = comment_run(lines, node.end_lineno - 1)
                        if isinstance(node, ast.Assign) and isinstance(node.targets[0], ast.Name) and re.fullmatch(
                                r"[a-z][a-z0-9_]*(, [a-z][a-z0-9_]*){2,}", comment):  # `x = ...  # t_s, x_m, ...`
                            self.check_columns(example, "one row per sample: " + comment,
                                               namespace[node.targets[0].id])
        finally:
            sys.path.pop(0)
            os.chdir(cwd)
        self.assertNotIn("Traceback", captured.getvalue())
        self.check_files(example, text, folder, before)

    def with_free_names(self, run, namespace):
        """A fragment's statement; a name it uses without defining gets a value (FREE_NAMES), once."""
        for _ in range(len(FREE_NAMES)):
            try:
                return run()
            except NameError as e:
                name = getattr(e, "name", None)
                if name not in FREE_NAMES or name in namespace:
                    raise
                exec("import numpy as np", namespace)
                namespace[name] = eval(FREE_NAMES[name], namespace)
        return run()

    def check_columns(self, example, comment, value):
        """`frame()  # one row per tick: t_s, x_m, ... state (categorical ...), mean/max_deviation_m`: the
        columns the comment names (it may go on over the next comment lines) are the frame's."""
        m = re.search(r"one row per \w+: (.*)", comment, re.S)
        if not m or not hasattr(value, "columns"):
            return
        text = re.sub(r"\([^)]*\)", "", m.group(1))
        names = []
        for item in re.split(r"[,\s]+", text):
            item = item.strip(" .")
            if "/" in item and "_" in item:  # mean/max/rms_deviation_m
                heads, tail = item.split("_", 1)
                names.extend(f"{h}_{tail}" for h in heads.split("/"))
            elif re.fullmatch(r"[a-z][a-z0-9_]*", item):
                names.append(item)
        missing = [n for n in names if n not in value.columns]
        self.assertEqual(missing, [], f"{example}: columns the comment names, not in {list(value.columns)}")

    def check_comment_value(self, example, line, value):
        """`expr   # [4, 10, 8, 3, 5]` or `# (5, 2)`: the value, or the array's shape, the comment gives."""
        _, comment = strip_comment(line)
        m = re.fullmatch(r"(\[[\d, ]*\]|\((?:\d+, ?)+\d*\)|\(\d+,\))(\s*\[[^\]]*\])?", comment)
        if not m:
            return
        literal = ast.literal_eval(m.group(1))
        if isinstance(literal, tuple) and hasattr(value, "shape"):
            self.assertEqual(tuple(value.shape), literal, f"{example}: {line.strip()}")
        elif isinstance(literal, list):
            self.assertEqual(list(value), literal, f"{example}: {line.strip()}")


def _document_test(name):
    def test(self):
        self.run_document(name)
    test.__doc__ = f"every runnable example of {name}"
    return test


DOCUMENTS = ["README.md"] + sorted(f"docs/{p.name}" for p in (SOURCE / "docs").glob("*.md"))
for _doc in DOCUMENTS:
    setattr(Round15A, "test_docs_" + re.sub(r"\W", "_", Path(_doc).name.lower()), _document_test(_doc))

if __name__ == "__main__":
    unittest.main(verbosity=2)
