#!/usr/bin/env python3
"""Faults injected at every step of writing a study's outputs, as SQLite tests itself; run by CTest as
`fault_injection_cli`.

The shim (fault_shim.c, LD_PRELOAD) fails the Nth call of one kind (open for writing, write, fsync, rename,
link, mkdir, unlink, flock) under the output folder with ENOSPC, EIO, EROFS or ENOLCK, or kills the process
with SIGKILL just before it. A first run without a fault counts the calls of each kind; then every N of every
kind is tried, once failing and once killed. Each command replaces an earlier output set (the report of one
subject) by a new one (the report after a second subject joined). What must hold after every fault:

- a failed run exits 1 with one error line naming a file, never a crash (exit 3 or a signal);
- the visible files are the earlier set or the whole new set, byte for byte, never a mix; a killed run may
  also leave a journal of a set under way, which the next run completes;
- a clean run afterwards writes the new set and leaves no temporary, second name or journal behind.

Commands: `report --csv --out` (the tables, the pages and the index as one set), `report --csv` (the pair of
tables), and the Python report's writer of its set of files (study_report, through the library's writer).
`session cohort` is swept as the report's tables are; `session run`, and `session resume` of a session whose run
was killed after its first trial, are swept with their own check: every trial saved before the fault stays whole and
readable, `report` reads the study as it is, and `session resume` (or a new run when no session folder
appeared) completes the session without rewriting a saved trial or leaving a temporary behind. CALLIGRAPHY_CLI names the program, CALLIGRAPHY_FAULT_SHIM the shim. Standard library only.
"""
import hashlib
import json
import os
import random
import shutil
import signal
import subprocess
import sys
import tempfile
import unittest
import zlib
from pathlib import Path

CLI = os.environ.get("CALLIGRAPHY_CLI", "")
SHIM = os.environ.get("CALLIGRAPHY_FAULT_SHIM", "")
SOURCE = Path(os.environ.get("CALLIGRAPHY_SOURCE_DIR", Path(__file__).resolve().parents[2]))
sys.path.insert(0, str(SOURCE / "tests" / "study"))
from study_protocols import two_session_protocol  # noqa: E402

KINDS = ("open", "write", "fsync", "rename", "link", "mkdir", "unlink", "flock")
ERRNOS = ("ENOSPC", "EIO", "EROFS", "ENOLCK")
TIMEOUT_S = 120
LEFTOVER_MARKS = (".tmp-", ".kept-", ".calligraphy-set-")
SIGNALS = ("TERM", "INT", "HUP")  # the stop signals raised at a step (fault_shim.c, CALLIGRAPHY_FAULT_KILL)

# The Python side: study_report's writer of its set of files (the library's AtomicFileSet), given a study
# folder whose files it writes, scaled, into out/ (a report's page, tables and figures stand in).
PYTHON_WRITER = "python-report-writer"
PYTHON_WRITER_FUNCTION = """
import pathlib, sys
from calligraphy import study_report

def write_set(source):
    \"\"\"(exit status, standard error) of writing the set made from `source` into out/.\"\"\"
    files = {}
    for path in sorted(source.rglob("*.json")):
        relative = path.relative_to(source)
        target = pathlib.Path("out") / ("figures" if len(files) % 2 else "tables") / (relative.stem + ".txt")
        files[target] = path.read_bytes()
    (pathlib.Path("out") / "figures").mkdir(exist_ok=True)
    (pathlib.Path("out") / "tables").mkdir(exist_ok=True)
    files[pathlib.Path("out") / "index.html"] = ("<p>" + str(len(files)) + " files</p>").encode()
    try:
        study_report._write_together(files)
    except OSError as error:
        return 1, f"study_report: error: {error}\\n"
    return 0, ""
"""
# A run of the writer: an interpreter of its own, as each fault needs (the shim is loaded when it starts).
PYTHON_WRITER_CODE = PYTHON_WRITER_FUNCTION + """
status, message = write_set(pathlib.Path(sys.argv[1]))
sys.stderr.write(message)
sys.exit(status)
"""
# The runs without a fault (the sets written first, the clean run after every fault): the same function in one
# interpreter that imported the package once, given the folder to work in and the study, one JSON line each;
# it answers [exit status, standard error] (an exception other than OSError: status 1 and its traceback).
PYTHON_WRITER_SERVER_CODE = PYTHON_WRITER_FUNCTION + """
import json, os, traceback
for line in sys.stdin:
    cwd, source = json.loads(line)
    os.chdir(cwd)
    try:
        answer = write_set(pathlib.Path(source))
    except Exception:
        answer = 1, traceback.format_exc()
    print(json.dumps(answer), flush=True)
"""


def check_whole_trace(trace):
    """A saved trace (HDF5 after a 512-byte header, include/calligraphy/report/trace_hdf5.hpp) is whole: the
    header's length and CRC-32 match the bytes after it. Raises AssertionError otherwise."""
    data = trace.read_bytes()
    header = dict(line.split(" ", 1) for line in data[:512].rstrip(b"\0").decode().splitlines()[1:])
    body = data[512:]
    assert data.startswith(b"calligraphy-trace\n"), f"{trace}: not a trace file"
    assert len(body) == int(header["bytes"]), f"{trace}: {len(body)} bytes, header says {header['bytes']}"
    assert zlib.crc32(body) == int(header["crc32"], 16), f"{trace}: CRC-32 differs"


def snapshot(folder):
    """{relative path: SHA-256} of the visible files under `folder` (hidden names are leftovers, below)."""
    files = {}
    for path in sorted(folder.rglob("*")):
        relative = path.relative_to(folder)
        if path.is_file() and not any(part.startswith(".") for part in relative.parts):
            files[str(relative)] = hashlib.sha256(path.read_bytes()).hexdigest()
    return files


# The session sweeps take every Nth write and fsync (the same steps of each atomic write, repeated file after
# file) and every call of the other kinds, which change what a folder holds; CALLIGRAPHY_FAULT_EVERY_CALL=1
# takes every call of every kind (docs/testing.md).
REPEATED_STEP_STRIDE = 1 if os.environ.get("CALLIGRAPHY_FAULT_EVERY_CALL") == "1" else 3
# The Python report's writer is the binding's door to the one writer of sets that the `report` sweeps take at
# every step; each of its runs starts an interpreter and imports the package (a tenth of a second of CPU).
# Its sweep takes, of each kind of more than three calls, every third call from an offset drawn per kind with
# CALLIGRAPHY_TEST_SEED (random when unset, printed), so that every call is swept by some seed, and every call
# of the other kinds; CALLIGRAPHY_FAULT_EVERY_CALL=1 takes every call.
SAMPLED_STRIDE = 1 if os.environ.get("CALLIGRAPHY_FAULT_EVERY_CALL") == "1" else 3
SEED = int(os.environ.get("CALLIGRAPHY_TEST_SEED") or random.SystemRandom().randrange(1 << 32))


def every_fault(counts, repeated_step_stride=1, sampled_stride=1):
    """(kind, N, kill, the shim's environment) for every N of every kind counted (every `repeated_step_stride`th
    write and fsync, and the last; with `sampled_stride` > 1, every `sampled_stride`th call of each kind with
    more calls than that, from an offset drawn per kind from SEED, instead), failing and killed, the errno taken
    in turn from ERRNOS."""
    tried = 0
    for kind in KINDS:
        if sampled_stride > 1 and counts[kind] > sampled_stride:
            offset = random.Random(f"{SEED}:{kind}").randrange(sampled_stride)
            calls = list(range(1 + offset, counts[kind] + 1, sampled_stride))
        else:
            stride = repeated_step_stride if kind in ("write", "fsync") else 1
            calls = sorted(set(range(1, counts[kind] + 1, stride)) | ({counts[kind]} if counts[kind] else set()))
        for n in calls:
            for kill in (False, True):
                yield kind, n, kill, {"CALLIGRAPHY_FAULT_CALL": kind, "CALLIGRAPHY_FAULT_AT": str(n),
                                      "CALLIGRAPHY_FAULT_ERRNO": ERRNOS[tried % len(ERRNOS)],
                                      "CALLIGRAPHY_FAULT_KILL": "1" if kill else "0"}
                tried += 1


# The trials the sweeps run (the studies made first, the sessions, the cohort, a record run again) are trials of 一,
# the shortest character: what is swept is how the outputs are written, whatever they hold.
CHARACTER = "一"


def protocol_of(phases):
    """tests/study's two-session protocol (its phases on 十), cut to its first `phases` phases, on CHARACTER."""
    protocol = two_session_protocol("faults")
    protocol["phases"] = protocol["phases"][:phases]
    for phase in protocol["phases"]:
        phase["characters"] = [CHARACTER]
    return protocol


def scratch_parent():
    """Where the sweeps work: /dev/shm when it is a writable folder (tmpfs), else the default temporary folder.
    Every fsync the program makes is still called, counted and faulted by the shim; on tmpfs it returns at
    once instead of waiting for a disk, which no assertion here can see (a SIGKILL loses nothing the kernel
    holds: durability against a power cut is not what the sweeps test)."""
    shm = Path("/dev/shm")
    return str(shm) if shm.is_dir() and os.access(shm, os.W_OK | os.X_OK) else None


def restore(pristine, work):
    """`work` made again as a copy of `pristine` (the state a sweep starts each fault from, made once by the
    program itself), hidden files and all."""
    shutil.rmtree(work, ignore_errors=True)
    shutil.copytree(pristine, work, symlinks=True)


def default_stop_signals():
    """In the child before exec: SIGINT, SIGTERM and SIGHUP at their default disposition. A test started in the
    background of a shell (`ctest ... &`) inherits SIGINT ignored, and the program leaves an ignored stop signal
    ignored (as nohup asks), so the signal raised at a step would not stop it."""
    for number in (signal.SIGINT, signal.SIGTERM, signal.SIGHUP):
        signal.signal(number, signal.SIG_DFL)


def leftovers(folder):
    return sorted(str(path.relative_to(folder)) for path in folder.rglob("*")
                  if any(mark in path.name for mark in LEFTOVER_MARKS))


class FaultInjection(unittest.TestCase):
    maxDiff = None
    @classmethod
    def setUpClass(cls):
        if not CLI or not Path(CLI).exists() or not SHIM or not Path(SHIM).exists():
            raise unittest.SkipTest("run through ctest: CALLIGRAPHY_CLI and CALLIGRAPHY_FAULT_SHIM name the "
                                    "program and the shim")
        cls.scratch = tempfile.TemporaryDirectory(prefix="calligraphy-faults-", dir=scratch_parent())
        cls.python_writer = None  # started by the first run of the Python writer without a fault
        root = Path(cls.scratch.name)
        # The studies whose reports are swept: one session of one trial per subject. The report's set is its
        # tables, its index and a page per session whatever a session holds; the Python writer's set is a file
        # per JSON file of the study (5, and the index, for two subjects).
        (root / "p.json").write_text(json.dumps(protocol_of(1), ensure_ascii=False), encoding="utf-8")
        cls.protocol = root / "p.json"
        # The sessions swept: two trials (one saved before a fault, one after; a third saves the same way).
        (root / "session.json").write_text(json.dumps(protocol_of(2), ensure_ascii=False), encoding="utf-8")
        cls.session_protocol = root / "session.json"
        cls.one_subject = root / "one"
        cls.two_subjects = root / "two"
        for folder, subjects in ((cls.one_subject, "1"), (cls.two_subjects, "2")):
            done = subprocess.run([CLI, "session", "run", cls.protocol, "--writer", "simulated", "--subjects",
                                   subjects, "--out", folder / "study"], capture_output=True, timeout=TIMEOUT_S,
                                  env=dict(os.environ))
            assert done.returncode == 0, done.stderr.decode()

    @classmethod
    def tearDownClass(cls):
        if cls.python_writer is not None:
            cls.python_writer.stdin.close()
            cls.python_writer.wait(timeout=TIMEOUT_S)
            cls.python_writer.stdout.close()
        cls.scratch.cleanup()

    def run_cli(self, arguments, cwd, fault=None):
        environment = dict(os.environ)
        if fault is not None:
            environment.update(LD_PRELOAD=SHIM, CALLIGRAPHY_FAULT_UNDER=str(cwd / "out"), **fault)
        elif arguments[0] == PYTHON_WRITER:
            return self.run_python_writer(arguments, cwd, environment)
        program = [CLI] if arguments[0] != PYTHON_WRITER else [sys.executable, "-c", PYTHON_WRITER_CODE]
        return subprocess.run([*program, *map(str, arguments[1:] if program[0] != CLI else arguments)], cwd=cwd,
                              capture_output=True, env=environment, timeout=TIMEOUT_S,
                              preexec_fn=default_stop_signals)

    def run_python_writer(self, arguments, cwd, environment):
        """The Python writer without a fault: write_set in the interpreter that serves those runs (an
        interpreter and the package's import less per run; each fault still runs in an interpreter of its own)."""
        cls = type(self)
        if cls.python_writer is None:
            cls.python_writer = subprocess.Popen([sys.executable, "-c", PYTHON_WRITER_SERVER_CODE], env=environment,
                                                 stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True)
        cls.python_writer.stdin.write(json.dumps([str(cwd), str(arguments[1])]) + "\n")
        cls.python_writer.stdin.flush()
        answer = cls.python_writer.stdout.readline()
        self.assertTrue(answer, f"the Python writer's server ended (status {cls.python_writer.poll()})")
        status, stderr = json.loads(answer)
        return subprocess.CompletedProcess(arguments, status, b"", stderr.encode())

    def sweep(self, arguments_for, signals=False, files=2, repeated_step_stride=1, sampled_stride=1):
        """Every fault at every step of `arguments_for(study)` writing over the output of the one-subject
        study with the output of the two-subject study (every `repeated_step_stride`th write and fsync);
        with `signals`, also SIGTERM, SIGINT or SIGHUP (in turn) raised at every step, after which the run
        has ended by that signal leaving the earlier or the new set and nothing else: no temporary, second
        name or journal."""
        work = Path(self.scratch.name) / "work"
        pristine = Path(self.scratch.name) / "work-earlier"

        def fresh():
            """The work folder holding the earlier set only: written by the program the first time, then a copy
            of that folder (the same bytes as a run writes again, checked below)."""
            if pristine.exists():
                restore(pristine, work)
                return snapshot(work / "out")
            shutil.rmtree(work, ignore_errors=True)
            (work / "out").mkdir(parents=True)
            done = self.run_cli(arguments_for(self.one_subject / "study"), work)
            self.assertEqual(done.returncode, 0, done.stderr.decode())
            shutil.copytree(work, pristine, symlinks=True)
            return snapshot(work / "out")

        earlier = fresh()
        # The new set, as a clean run writes it over the earlier one (pages of sessions the new study lacks,
        # if any, stay as they were).
        done = self.run_cli(arguments_for(self.two_subjects / "study"), work)
        self.assertEqual(done.returncode, 0, done.stderr.decode())
        new = snapshot(work / "out")
        self.assertNotEqual(earlier, new)
        # The program writes the earlier set again as it wrote it the first time: the copy stands for a run.
        shutil.rmtree(work)
        (work / "out").mkdir(parents=True)
        done = self.run_cli(arguments_for(self.one_subject / "study"), work)
        self.assertEqual(done.returncode, 0, done.stderr.decode())
        self.assertEqual(snapshot(work / "out"), earlier)
        self.assertEqual(leftovers(work / "out"), [])
        self.assertEqual(fresh(), earlier)
        counts_file = Path(self.scratch.name) / "counts.txt"
        counted = self.run_cli(arguments_for(self.two_subjects / "study"), work,
                               {"CALLIGRAPHY_FAULT_COUNTS": str(counts_file)})
        self.assertEqual(counted.returncode, 0, counted.stderr.decode())
        counts = {kind: int(n) for kind, n in (line.split() for line in counts_file.read_text().splitlines())}
        self.assertGreaterEqual(counts["rename"], files, counts)  # the set's files are renamed into place
        self.assertGreaterEqual(counts["fsync"], files, counts)
        tried = 0
        for kind, n, kill, fault in every_fault(counts, repeated_step_stride, sampled_stride):
            with self.subTest(kind=kind, n=n, errno=fault["CALLIGRAPHY_FAULT_ERRNO"], kill=kill):
                self.assertEqual(fresh(), earlier)
                result = self.run_cli(arguments_for(self.two_subjects / "study"), work, fault)
                stderr = result.stderr.decode(errors="replace")
                after = snapshot(work / "out")
                if kill:
                    self.assertEqual(result.returncode, -9, stderr)
                    journals = [name for name in leftovers(work / "out") if ".calligraphy-set-" in name]
                    self.assertTrue(after in (earlier, new) or journals,
                                    f"a mix of the sets and no journal: {sorted(after)}")
                else:
                    self.assertIn(result.returncode, (0, 1), stderr)
                    self.assertNotIn("internal error", stderr)
                    self.assertIn(after, (earlier, new), "a mix of the earlier and the new set")
                    if result.returncode == 1:
                        self.assertEqual(len(stderr.strip().splitlines()), 1, stderr)
                        self.assertIn(": error: ", stderr)
                again = self.run_cli(arguments_for(self.two_subjects / "study"), work)
                self.assertEqual(again.returncode, 0, again.stderr.decode())
                self.assertEqual(snapshot(work / "out"), new)
                self.assertEqual(leftovers(work / "out"), [])
            tried += 1
        for kind in KINDS if signals else ():
            for n in range(1, counts[kind] + 1):
                name = SIGNALS[tried % len(SIGNALS)]
                number = getattr(signal, "SIG" + name)
                with self.subTest(kind=kind, n=n, signal=name):
                    self.assertEqual(fresh(), earlier)
                    result = self.run_cli(arguments_for(self.two_subjects / "study"), work,
                                          {"CALLIGRAPHY_FAULT_CALL": kind, "CALLIGRAPHY_FAULT_AT": str(n),
                                           "CALLIGRAPHY_FAULT_KILL": name})
                    self.assertIn(result.returncode, (-number, 128 + number), result.stderr.decode())
                    self.assertIn(snapshot(work / "out"), (earlier, new), "a mix of the earlier and the new set")
                    self.assertEqual(leftovers(work / "out"), [], f"left behind by {name} at {kind} {n}")
                tried += 1
        every = "" if repeated_step_stride == 1 else f", every {repeated_step_stride}th write and fsync"
        if sampled_stride > 1:
            every = f", every {sampled_stride}th call of each kind from offsets of CALLIGRAPHY_TEST_SEED={SEED}"
        print(f"{' '.join(map(str, arguments_for(Path('STUDY'))))}: {tried} faults at every step{every} "
              f"({', '.join(f'{kind} {counts[kind]}' for kind in KINDS)})", flush=True)
        shutil.rmtree(pristine)

    def test_report_tables_and_pages(self):
        # One thread: the Nth call of a kind is then the same step in every run.
        # Its writes and syncs repeat one atomic write file after file: every third, as the session sweeps
        # take them (report --csv alone, below, takes every one).
        self.sweep(lambda study: ["report", study, "--csv", "out", "--out", "out/report.html", "--jobs", "1"],
                   repeated_step_stride=REPEATED_STEP_STRIDE)

    def test_python_report_set(self):
        print(f"python-report-writer: every {SAMPLED_STRIDE} call of each kind, CALLIGRAPHY_TEST_SEED={SEED}",
              flush=True)  # before the sweep: a failure's subTest names its kind and N, this its draw
        self.sweep(lambda study: [PYTHON_WRITER, study], sampled_stride=SAMPLED_STRIDE)

    def test_report_tables_alone(self):
        self.sweep(lambda study: ["report", study, "--csv", "out"], signals=True)

    def test_trace_output(self):
        """`trace TRACE --csv out/trace.csv` replacing an earlier export: every fault and stop signal at every
        step."""
        def arguments_for(study):
            traces = sorted(study.rglob("*.trace.h5"))
            trace = (traces[0] if study == self.one_subject / "study" else traces[-1]) if traces else study
            return ["trace", trace, "--csv", "out/trace.csv"]
        self.sweep(arguments_for, signals=True, files=1)

    def test_trial_spec_output(self):
        """`trial --spec RECORD --csv out/trial.csv` (a session's trial run again) replacing an earlier trace:
        every fault at every step of the write. No stop signals: one that comes while a trial's outputs are
        written is ignored (docs/cli.md, "Stopping a trial"), so the run ends as a clean one."""
        def arguments_for(study):
            records = sorted(study.rglob("trials/*.json"))
            record = (records[0] if study == self.one_subject / "study" else records[-1]) if records else study
            return ["trial", "--spec", record, "--csv", "out/trial.csv"]
        self.sweep(arguments_for, files=1)

    def test_journal_recovery(self):
        """A `report --csv` killed between its two renames leaves a journal and a mix of the two sets; the next
        run completes that set first. Every fault and kill at every step of that next run: a failed run exits 1
        with one line, the visible files are the new set or the mix with its journal still there (never a mix
        without one), and a clean run afterwards writes the new set and leaves nothing behind."""
        work = Path(self.scratch.name) / "journal"
        pristine = Path(self.scratch.name) / "journal-earlier"
        arguments = ["report", self.two_subjects / "study", "--csv", "out", "--jobs", "1"]

        def killed_between_renames():
            """The earlier set (written by the program the first time, then a copy of that folder, which holds
            no temporary or journal), then a run killed between its renames. The kill is made each time: the
            names of what it leaves carry its process id, which must be one that just died."""
            if pristine.exists():
                restore(pristine, work)
            else:
                shutil.rmtree(work, ignore_errors=True)
                (work / "out").mkdir(parents=True)
                done = self.run_cli(["report", self.one_subject / "study", "--csv", "out", "--jobs", "1"], work)
                self.assertEqual(done.returncode, 0, done.stderr.decode())
                self.assertEqual(leftovers(work / "out"), [])
                shutil.copytree(work, pristine, symlinks=True)
            killed = self.run_cli(arguments, work, {"CALLIGRAPHY_FAULT_CALL": "rename", "CALLIGRAPHY_FAULT_AT": "2",
                                                    "CALLIGRAPHY_FAULT_KILL": "1"})
            self.assertEqual(killed.returncode, -9, killed.stderr.decode())
            self.assertEqual(len([n for n in leftovers(work / "out") if ".calligraphy-set-" in n]), 1)
            return snapshot(work / "out")

        mix = killed_between_renames()
        done = self.run_cli(arguments, work)
        self.assertEqual(done.returncode, 0, done.stderr.decode())
        new = snapshot(work / "out")
        self.assertNotEqual(mix, new)
        self.assertEqual(leftovers(work / "out"), [])
        killed_between_renames()
        counts_file = Path(self.scratch.name) / "journal-counts.txt"
        counted = self.run_cli(arguments, work, {"CALLIGRAPHY_FAULT_COUNTS": str(counts_file)})
        self.assertEqual(counted.returncode, 0, counted.stderr.decode())
        counts = {kind: int(n) for kind, n in (line.split() for line in counts_file.read_text().splitlines())}
        # The calls that change what the folder holds (the completion's renames and removals); the new set's own
        # writes and syncs are swept by test_report_tables_alone.
        swept = {kind: (n if kind in ("open", "rename", "link", "unlink") else 0) for kind, n in counts.items()}
        tried = 0
        for kind, n, kill, fault in every_fault(swept):
            with self.subTest(kind=kind, n=n, errno=fault["CALLIGRAPHY_FAULT_ERRNO"], kill=kill):
                self.assertEqual(killed_between_renames(), mix)
                result = self.run_cli(arguments, work, fault)
                stderr = result.stderr.decode(errors="replace")
                after = snapshot(work / "out")
                journals = [name for name in leftovers(work / "out") if ".calligraphy-set-" in name]
                if kill:
                    self.assertEqual(result.returncode, -9, stderr)
                else:
                    self.assertIn(result.returncode, (0, 1), stderr)
                    self.assertNotIn("internal error", stderr)
                    if result.returncode == 1:
                        self.assertEqual(len(stderr.strip().splitlines()), 1, stderr)
                self.assertTrue(after == new or journals, f"a mix of the sets and no journal: {sorted(after)}")
                again = self.run_cli(arguments, work)
                self.assertEqual(again.returncode, 0, again.stderr.decode())
                self.assertEqual(snapshot(work / "out"), new)
                self.assertEqual(leftovers(work / "out"), [])
            tried += 1
        print(f"report --csv completing a killed set's journal: {tried} faults at every step "
              f"({', '.join(f'{kind} {counts[kind]}' for kind in KINDS)})", flush=True)

    def test_set_over_two_folders(self):
        """`report --csv out/tables --out out/site/report.html` is one set over sibling folders (the tables, the
        index, the pages' folders below it), each folder with its own journal. SIGKILL at every rename: every
        folder holds its earlier files, its new ones, or a journal of its own (a kill between two folders leaves
        each folder earlier or new); a later set written into each journalled folder completes that folder on
        its own, and once every journal was written before the kill, that gives the whole new set; a clean run
        afterwards leaves nothing behind."""
        work = Path(self.scratch.name) / "folders"
        later_code = ("import pathlib, sys\nfrom calligraphy import study_report\n"
                      "study_report._write_together({pathlib.Path(f) / 'later.txt': b'later' for f in sys.argv[1:]})\n")

        def arguments_for(study):
            return ["report", study, "--csv", "out/tables", "--out", "out/site/report.html", "--jobs", "1"]

        def by_folder(files):
            folders = {}
            for name, digest in files.items():
                folder, _, base = name.rpartition("/")
                if base != "later.txt":
                    folders.setdefault(folder, {})[base] = digest
            return folders

        def journals():  # a journal's own temporary ("..calligraphy-set-...journal.tmp-...") is none
            return [name for name in leftovers(work / "out")
                    if Path(name).name.startswith(".calligraphy-set-") and name.endswith(".journal")]

        pristine = Path(self.scratch.name) / "folders-earlier"

        def fresh():
            """The earlier set: written by the program the first time, then a copy of that folder."""
            if pristine.exists():
                restore(pristine, work)
                return by_folder(snapshot(work / "out"))
            shutil.rmtree(work, ignore_errors=True)
            for folder in ("out/tables", "out/site"):
                (work / folder).mkdir(parents=True)
            done = self.run_cli(arguments_for(self.one_subject / "study"), work)
            self.assertEqual(done.returncode, 0, done.stderr.decode())
            self.assertEqual(leftovers(work / "out"), [])
            shutil.copytree(work, pristine, symlinks=True)
            return by_folder(snapshot(work / "out"))

        earlier = fresh()
        done = self.run_cli(arguments_for(self.two_subjects / "study"), work)
        self.assertEqual(done.returncode, 0, done.stderr.decode())
        new = by_folder(snapshot(work / "out"))
        self.assertGreaterEqual(len(new), 3, sorted(new))  # tables, site and the pages' folders
        self.assertEqual(fresh(), earlier)
        counts_file = Path(self.scratch.name) / "folders-counts.txt"
        counted = self.run_cli(arguments_for(self.two_subjects / "study"), work,
                               {"CALLIGRAPHY_FAULT_COUNTS": str(counts_file)})
        self.assertEqual(counted.returncode, 0, counted.stderr.decode())
        renames = {kind: int(n) for kind, n in (line.split() for line in counts_file.read_text().splitlines())}["rename"]
        files = sum(len(folder) for folder in new.values())
        journals_written = renames - files  # the first renames put each folder's journal in place
        between_folders = 0
        after_every_journal = 0
        for n in range(1, renames + 1):
            with self.subTest(rename=n):
                self.assertEqual(fresh(), earlier)
                killed = self.run_cli(arguments_for(self.two_subjects / "study"), work,
                                      {"CALLIGRAPHY_FAULT_CALL": "rename", "CALLIGRAPHY_FAULT_AT": str(n),
                                       "CALLIGRAPHY_FAULT_KILL": "1"})
                self.assertEqual(killed.returncode, -9, killed.stderr.decode())
                after = by_folder(snapshot(work / "out"))
                journalled = sorted({str(Path(name).parent) for name in journals()})
                for folder in set(earlier) | set(new):
                    if folder not in journalled:
                        self.assertIn(after.get(folder, {}), (earlier.get(folder, {}), new.get(folder, {})),
                                      f"{folder}: a mix of the sets and no journal in it (rename {n})")
                if all(after.get(f, {}) in (earlier.get(f, {}), new.get(f, {})) for f in set(earlier) | set(new)) \
                        and after != earlier and after != new:
                    between_folders += 1
                if journalled:
                    later = subprocess.run([sys.executable, "-c", later_code, *[Path("out") / f for f in journalled]],
                                           cwd=work, capture_output=True, timeout=TIMEOUT_S)
                    self.assertEqual(later.returncode, 0, later.stderr.decode())
                completed = by_folder(snapshot(work / "out"))
                for folder in set(earlier) | set(new):
                    self.assertIn(completed.get(folder, {}), (earlier.get(folder, {}), new.get(folder, {})),
                                  f"{folder}: a mix of the sets after the later set (rename {n})")
                    if folder in journalled:
                        self.assertEqual(completed.get(folder, {}), new.get(folder, {}), folder)
                # Every journal was written before this kill when each folder the set changes either holds its
                # journal or is new already: observed, not inferred from the counted run's renames. On a loaded
                # machine a kill at the first rename past that count has left the last folder earlier and with
                # no journal (a rename before the last journal's, which the loop above holds as it should).
                changing = {f for f in set(earlier) | set(new) if earlier.get(f, {}) != new.get(f, {})}
                every_journal = all(f in journalled or after.get(f, {}) == new.get(f, {}) for f in changing)
                if n > journals_written and every_journal:
                    self.assertEqual(completed, new, f"killed at rename {n}, after every journal was written")
                    after_every_journal += 1
                self.assertEqual(journals(), [])
                again = self.run_cli(arguments_for(self.two_subjects / "study"), work)
                self.assertEqual(again.returncode, 0, again.stderr.decode())
                self.assertEqual(by_folder(snapshot(work / "out")), new)
                self.assertEqual(leftovers(work / "out"), [])
        self.assertGreater(between_folders, 0, "no kill fell between two folders")
        self.assertGreater(after_every_journal, 0, "no kill fell after every journal was written")
        print(f"report over {len(new)} folders: SIGKILL at each of {renames} renames ({journals_written} journals, "
              f"{between_folders} kills between folders)", flush=True)

    def saved_trials(self, out):
        """{record path: SHA-256 of the record, its trace and its drawing} of every trial saved in a whole
        session folder under `out`; each record must read as JSON and each trace must be whole (its header's
        length and CRC-32)."""
        saved = {}
        for record in sorted(out.glob("*/*/trials/*.json")):
            if any(part.startswith(".") for part in record.relative_to(out).parts):
                continue
            json.loads(record.read_text(encoding="utf-8"))
            trace = record.with_suffix(".trace.h5")
            check_whole_trace(trace)
            digest = hashlib.sha256()
            for path in (record, trace, record.with_suffix(".svg")):
                digest.update(path.read_bytes())
            saved[str(record.relative_to(out))] = digest.hexdigest()
        return saved

    def session_folders(self, out):
        return sorted(path for path in out.glob("*/*") if path.is_dir() and not path.name.startswith("."))

    def test_session_run_then_resume(self):
        """Faults at every step of `session run` writing a session (every_fault): what was saved before the fault stays
        whole and readable, the study reads, and `session resume` (or a new run, when no session folder
        appeared) completes the session without rewriting what was saved."""
        run = ["session", "run", self.session_protocol, "--writer", "simulated", "--subject", "S01", "--out", "out"]
        self.sweep_session("session run then resume", run, lambda work: None)

    def test_session_resume(self):
        """The same for `session resume` of a session whose first trial was saved before its run was killed."""
        run = ["session", "run", self.session_protocol, "--writer", "simulated", "--subject", "S01", "--out", "out"]
        pristine = Path(self.scratch.name) / "session-killed"

        def first_trial_saved(work):
            """The session as a run killed at the second trial's link left it (the first trial's record is
            linked to its name first): made by the program the first time, then a copy of that folder. What the
            kill leaves names no process (a `.part` record, the study lock's note, which only informs): the copy
            is the same state."""
            if not pristine.exists():
                killed = self.run_cli(run, work, {"CALLIGRAPHY_FAULT_CALL": "link", "CALLIGRAPHY_FAULT_AT": "2",
                                                  "CALLIGRAPHY_FAULT_KILL": "1"})
                self.assertEqual(killed.returncode, -9, killed.stderr.decode())
                shutil.copytree(work, pristine, symlinks=True)
            else:
                restore(pristine, work)
            self.assertEqual(len(self.saved_trials(work / "out")), 1)
            return ["session", "resume", self.session_folders(work / "out")[0]]

        self.sweep_session("session resume", None, first_trial_saved)

    def sweep_session(self, name, command, prepare):
        """Every fault at every step of `command` (or of what `prepare(work)` returns, after it made the
        session it resumes) writing a session under work/out."""
        work = Path(self.scratch.name) / "session"

        def fresh():
            shutil.rmtree(work, ignore_errors=True)
            (work / "out").mkdir(parents=True)
            return prepare(work) or command

        counts_file = Path(self.scratch.name) / "session-counts.txt"
        counted = self.run_cli(fresh(), work, {"CALLIGRAPHY_FAULT_COUNTS": str(counts_file)})
        self.assertEqual(counted.returncode, 0, counted.stderr.decode())
        counts = {kind: int(n) for kind, n in (line.split() for line in counts_file.read_text().splitlines())}
        planned = len(self.saved_trials(work / "out"))
        self.assertEqual(planned, 2)
        tried = 0
        for kind, n, kill, fault in every_fault(counts, REPEATED_STEP_STRIDE):
            with self.subTest(kind=kind, n=n, errno=fault["CALLIGRAPHY_FAULT_ERRNO"], kill=kill):
                arguments = fresh()
                before = self.saved_trials(work / "out")
                result = self.run_cli(arguments, work, fault)
                stderr = result.stderr.decode(errors="replace")
                if kill:
                    self.assertEqual(result.returncode, -9, stderr)
                else:
                    self.assertIn(result.returncode, (0, 1), stderr)
                    self.assertNotIn("internal error", stderr)
                    if result.returncode == 1:
                        self.assertIn(": error: ", stderr.strip().splitlines()[-1], stderr)
                saved = self.saved_trials(work / "out")
                for record, digest in before.items():
                    self.assertEqual(saved.get(record), digest, f"{record} was lost or rewritten")
                folders = self.session_folders(work / "out")
                self.assertLessEqual(len(folders), 1, folders)
                # The study reads as it is, whatever was saved.
                tables = work / "tables"
                shutil.rmtree(tables, ignore_errors=True)
                tables.mkdir()
                read = self.run_cli(["report", "out", "--csv", "tables"], work)
                self.assertEqual(read.returncode, 0 if folders else 1, read.stderr.decode())
                # Completed: resumed, or run again when no session folder appeared.
                completed = self.run_cli(["session", "resume", folders[0]] if folders else arguments, work)
                self.assertEqual(completed.returncode, 0, completed.stderr.decode())
                after = self.saved_trials(work / "out")
                self.assertEqual(len(after), planned, sorted(after))
                for record, digest in saved.items():
                    self.assertEqual(after.get(record), digest, f"{record} was lost or rewritten")
                self.assertEqual(leftovers(work / "out"), [])
                self.assertEqual([p.name for p in (work / "out").rglob(".partial.*")], [])
                self.assertEqual([p.name for p in (work / "out").rglob("*.part")], [])
                again = self.run_cli(["report", "out", "--csv", "tables"], work)
                self.assertEqual(again.returncode, 0, again.stderr.decode())
            tried += 1
        print(f"{name}: {tried} faults, every {REPEATED_STEP_STRIDE} write and fsync and every other call "
              f"({', '.join(f'{kind} {counts[kind]}' for kind in KINDS)})", flush=True)

    def test_cohort_tables(self):
        """`session cohort` replacing its tables of one subject with those of two, each subject writing one trial:
        the two tables are written in the same steps whatever their rows (every run simulates its cohort again)."""
        protocol = json.loads(self.protocol.read_text(encoding="utf-8"))
        protocol["phases"] = protocol["phases"][:1]
        one_trial = Path(self.scratch.name) / "one-trial.json"
        one_trial.write_text(json.dumps(protocol, ensure_ascii=False), encoding="utf-8")

        def cohort(study):
            subjects = "1" if study == self.one_subject / "study" else "2"
            return ["session", "cohort", one_trial, "--subjects", subjects, "--csv", "out", "--jobs", "1"]
        self.sweep(cohort)


if __name__ == "__main__":
    unittest.main(verbosity=2)
