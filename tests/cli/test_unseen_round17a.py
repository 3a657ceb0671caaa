#!/usr/bin/env python3
"""Round 17A: whatever the file system hands a command in place of a regular file, as its input or its output,
from the docs alone (docs/cli.md "Outputs", "Checked before anything runs", "Pen traces: format and limits";
docs/metrics.md on the traces `score` reads; docs/experiments.md on a session's files; docs/python.md "Errors").
Run by CTest as `cli_unseen_round17a_tests`.

Inputs: a FIFO no process writes to (no wait without end), a FIFO whose writer sends half a document and closes,
/dev/zero, /dev/urandom and /dev/null, a UNIX socket, a /proc file (size 0 in its stat, text when read), a
device node in a session folder, a FIFO in a character data folder, a trace that grows or is truncated while it
is read, a relative path of 4,000 characters, a name of 255 bytes, a name holding a line break, a name that
begins with `-` after `--`, `~` (no shell expands it) and `..` out of a folder and back. Outputs: /dev/null
(written in place, as the docs allow), /dev/full, a FIFO no process reads (the documented 10 s, then exit 1),
a symbolic link to one, a socket, a folder, a path under a file, a read-only file system (a tmpfs remounted
read-only in a mount namespace of the test's own; skipped saying why where `unshare` cannot make one) and the
page folder `report --out /dev/null` would make beside a device. Each run has a timeout of a few seconds that
fails the case when hit; each refusal is checked for its exit status, one error line naming the file, no
temporary left and nothing else changed. Python's readers and writers raise the documented classes.

CALLIGRAPHY_CLI names the program, PYTHONPATH its Python module, CALLIGRAPHY_SOURCE_DIR the sources.
CALLIGRAPHY_SANITIZED=1 takes five cases.
"""
import json
import os
import shutil
import socket
import stat
import subprocess
import sys
import tempfile
import threading
import time
import unittest
from pathlib import Path

from outsider import ENV, OneErrorLine, error_lines, last_case, run, sanitized_subset

run_sanitized_subset = sanitized_subset({"test_score_of_a_fifo_no_one_writes_to_is_refused_without_waiting",
                                        "test_score_of_endless_devices_is_refused_at_once",
                                        "test_dev_null_takes_every_output_in_place",
                                        "test_an_output_under_a_file_is_refused_naming_it",
                                        "test_a_name_of_255_bytes_is_written_and_read"})
# The one case that waits the program's documented 10 s (outputs onto a FIFO no process reads): when it runs with
# the others, its two runs start with the module's set-up and the case is run last, so that the wait passes beside
# the other cases.
WAITING_CASE = "test_a_fifo_no_one_reads_as_an_output_fails_after_the_stated_wait"


def load_tests(loader, tests, pattern):
    """The cases sanitized_subset keeps, the one that waits last (see WAITING_CASE)."""
    suite, SHARED["start_waiting_early"] = last_case(run_sanitized_subset(loader, tests, pattern), WAITING_CASE)
    return suite

SOURCE = Path(os.environ.get("CALLIGRAPHY_SOURCE_DIR", Path(__file__).resolve().parents[2]))
SAMPLE = SOURCE / "tests" / "data" / "hanzi-writer-sample"
YI = "一"
# A few seconds for every run: a command that waits on a file without end fails its case instead of the suite.
QUICK_S = 5
# docs/cli.md "Outputs": a FIFO no process opens for reading within 10 s is a failed write.
FIFO_WAIT_S = 10
PROTOCOL = {"name": "r17a", "conditions": [{"name": "V", "mode": "vision"}],
            "test": {"characters": [YI], "conditions": ["V"], "repetitions": 1}, "trial": {"max_duration_s": 4}}
SHARED = {}


def setUpModule():
    root = Path(tempfile.mkdtemp(prefix="r17a-"))
    SHARED["root"] = root
    base = root / "base"
    base.mkdir()
    trial = run(["trial", YI, "--writer-profile", "skilled", "--max-duration", "4", "--json", "r.json",
                 "--csv", "t.csv", "--record", "teacher.json"], base, timeout=30)
    if trial.returncode != 0:
        raise AssertionError(trial.stderr.decode("utf-8", "replace"))
    (base / "p.json").write_text(json.dumps(PROTOCOL), encoding="utf-8")
    session = run(["session", "run", "p.json", "--out", "study", "--subjects", "1"], base, timeout=30)
    if session.returncode != 0:
        raise AssertionError(session.stderr.decode("utf-8", "replace"))
    SHARED["trace_h5"] = next((base / "study").glob("S01/*/trials/*.trace.h5"))
    SHARED["session"] = SHARED["trace_h5"].parents[1]
    SHARED["samples"] = sum(1 for _ in open(base / "t.csv", encoding="utf-8")) - 1
    if SHARED.get("start_waiting_early"):
        waiting = root / "waiting"
        waiting.mkdir()
        shutil.copy(base / "t.csv", waiting / "t.csv")
        SHARED["waiting"] = OntoUnreadFifo(waiting)


def tearDownModule():
    if SHARED.get("waiting") is not None:  # started, its case not run: its runs end within their own 10 s
        SHARED["waiting"].results()
    shutil.rmtree(SHARED["root"], ignore_errors=True)


class OntoUnreadFifo:
    """Two runs at once in `folder` (which holds t.csv): `trace` onto the FIFO out.fifo and `score` onto link.json,
    a symbolic link to it; no process reads the FIFO. Each run is waited on by a thread of its own, which notes
    when it ended and fails it (killing both) when it still runs FIFO_WAIT_S + 5 s after it started."""

    def __init__(self, folder):
        self.dir = Path(folder)
        os.mkfifo(self.dir / "out.fifo")
        os.symlink("out.fifo", self.dir / "link.json")
        self.runs = {
            "out.fifo": ["trace", str(SHARED["trace_h5"]), "--csv", "out.fifo"],
            "link.json": ["score", "--character", YI, "t.csv", "--json", "link.json"],
        }
        self.started = time.monotonic()
        self.procs = {k: subprocess.Popen([os.environ["CALLIGRAPHY_CLI"], *a], cwd=self.dir, env=ENV,
                                          stdin=subprocess.DEVNULL, stdout=subprocess.PIPE, stderr=subprocess.PIPE)
                      for k, a in self.runs.items()}
        self.ended, self.outputs, self.late = {}, {}, []
        self.threads = [threading.Thread(target=self.wait, args=(name,), daemon=True) for name in self.procs]
        for thread in self.threads:
            thread.start()

    def wait(self, name):
        try:
            self.outputs[name] = self.procs[name].communicate(timeout=FIFO_WAIT_S + 5)
        except subprocess.TimeoutExpired:
            self.late.append(name)
            for q in self.procs.values():
                q.kill()
            self.outputs[name] = self.procs[name].communicate()
        self.ended[name] = time.monotonic()

    def results(self):
        """{name: CompletedProcess} once both runs ended; the names of those that ran too long."""
        for thread in self.threads:
            thread.join()
        return ({name: subprocess.CompletedProcess(self.runs[name], p.returncode, *self.outputs[name])
                 for name, p in self.procs.items()}, self.late)


def temporaries(folder):
    """The hidden temporaries (`.NAME.tmp-PID-N`, docs/cli.md "Outputs") left in `folder`."""
    return sorted(p.name for p in Path(folder).iterdir() if p.name.startswith(".") and ".tmp-" in p.name)


def listing(folder):
    """Every path under `folder` with its kind and size, to see that nothing was added, removed or changed."""
    out = {}
    for dirpath, dirnames, filenames in os.walk(folder):
        for name in dirnames + filenames:
            p = os.path.join(dirpath, name)
            st = os.lstat(p)
            if name == ".calligraphy-run.lock":  # a study's run lock, taken (and emptied) by a resume
                continue
            out[os.path.relpath(p, folder)] = (stat.S_IFMT(st.st_mode), st.st_size if stat.S_ISREG(st.st_mode) else 0,
                                               st.st_mtime_ns if stat.S_ISREG(st.st_mode) else 0)
    return out


class Unseen17A(OneErrorLine, unittest.TestCase):
    def setUp(self):
        self.dir = Path(tempfile.mkdtemp(prefix="c", dir=SHARED["root"]))
        base = SHARED["root"] / "base"
        for name in ("r.json", "t.csv", "teacher.json", "p.json"):
            shutil.copy(base / name, self.dir / name)
        self.sockets = []

    def tearDown(self):
        for s in self.sockets:
            s.close()
        # No page folder of a report beside a device (docs/cli.md "report"): nothing of the command's in /dev.
        self.assertEqual([p for p in os.listdir("/dev") if p.endswith("_files")], [])

    def socket_at(self, path):
        s = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
        s.bind(str(path))
        s.listen(1)
        self.sockets.append(s)
        return path

    def quick(self, args, cwd=None, timeout=QUICK_S, **kw):
        """The program, failing the case (not hanging the suite) when it runs past `timeout`."""
        try:
            return run(args, self.dir if cwd is None else cwd, timeout=timeout, **kw)
        except subprocess.TimeoutExpired:
            self.fail(f"calligraphy {' '.join(map(str, args))} still ran after {timeout} s")

    def refused(self, args, status, *needles, cwd=None):
        before = listing(self.dir)
        result = self.quick(args, cwd)
        line = self.assert_one_error(result, status, *needles)
        self.assertEqual(temporaries(self.dir), [])
        self.assertEqual(listing(self.dir), before, f"{args}: the folder changed")
        return line

    def py(self, code, timeout=20):
        """A Python process importing the module, its standard output as JSON."""
        try:
            result = subprocess.run([sys.executable, "-c", code], cwd=self.dir, env=ENV, timeout=timeout,
                                    stdout=subprocess.PIPE, stderr=subprocess.PIPE, stdin=subprocess.DEVNULL)
        except subprocess.TimeoutExpired:
            self.fail(f"python still ran after {timeout} s:\n{code}")
        self.assertEqual(result.returncode, 0, result.stderr.decode("utf-8", "replace"))
        return json.loads(result.stdout)

    # ---- inputs: FIFOs, devices, sockets, /proc --------------------------------------------------------------

    def test_score_of_a_fifo_no_one_writes_to_is_refused_without_waiting(self):
        # docs/metrics.md: only regular files up to 256 MiB are read.
        os.mkfifo(self.dir / "f.csv")
        self.refused(["score", "--character", YI, "f.csv"], 1, "f.csv")

    def test_json_inputs_given_a_fifo_no_one_writes_to_end_in_one_line(self):
        # A record, a teacher and a protocol that cannot be read at all: status 1 (docs/cli.md "Exit statuses").
        os.mkfifo(self.dir / "f.json")
        self.refused(["trial", "--spec", "f.json", "--check"], 1, "f.json")
        self.refused(["trial", "--spec", "f.json"], 1, "f.json")
        self.refused(["trial", YI, "--guidance-mode", "replay", "--teacher", "f.json", "--max-duration", "1"], 1,
                     "f.json")
        self.refused(["session", "plan", "--subjects", "1", "f.json"], 1, "f.json")
        self.refused(["trace", "f.json"], 1, "f.json")

    def test_a_fifo_whose_writer_sends_half_a_document_and_closes(self):
        # Either refused as no regular file (1) or read and refused as cut JSON/CSV (2 for `--spec` and a
        # protocol, 1 for a trace): one line naming the file, never a wait for the rest.
        halves = {"half.json": (self.dir / "r.json").read_bytes()[:3000],
                  "halfp.json": (self.dir / "p.json").read_bytes()[:40],
                  "half.csv": (self.dir / "t.csv").read_bytes()[:5000]}
        cases = [(["trial", "--spec", "half.json", "--check"], "half.json", (1, 2)),
                 (["session", "plan", "--subjects", "1", "halfp.json"], "halfp.json", (1, 2)),
                 (["score", "--character", YI, "half.csv"], "half.csv", (1,))]
        for args, name, statuses in cases:
            with self.subTest(name=name):
                os.mkfifo(self.dir / name)
                stop = threading.Event()

                def writer(path=self.dir / name, data=halves[name]):
                    # Open without blocking until the command opens it for reading, send half, close.
                    while not stop.is_set():
                        try:
                            fd = os.open(path, os.O_WRONLY | os.O_NONBLOCK)
                        except OSError:
                            time.sleep(0.005)
                            continue
                        try:
                            os.set_blocking(fd, True)
                            os.write(fd, data)
                        except OSError:
                            pass
                        finally:
                            os.close(fd)
                        return

                t = threading.Thread(target=writer)
                t.start()
                try:
                    result = self.quick(args)
                finally:
                    stop.set()
                    t.join()
                self.assert_one_error(result, statuses, name)
                self.assertEqual(temporaries(self.dir), [])
                os.unlink(self.dir / name)

    def test_score_of_endless_devices_is_refused_at_once(self):
        for device in ("/dev/zero", "/dev/urandom", "/dev/null"):
            with self.subTest(device=device):
                self.refused(["score", "--character", YI, device], 1, device)

    def test_json_inputs_of_endless_devices_end_in_one_line(self):
        for device in ("/dev/urandom", "/dev/null", "/dev/zero"):
            with self.subTest(device=device):
                self.refused(["trial", "--spec", device, "--check"], (1, 2), device)
                self.refused(["session", "plan", "--subjects", "1", device], (1, 2), device)
                self.refused(["trace", device], 1, device)
                self.refused(["trial", YI, "--guidance-mode", "replay", "--teacher", device, "--max-duration",
                              "1"], 1, device)

    def test_a_unix_socket_as_every_input_is_refused_naming_it(self):
        self.socket_at(self.dir / "s")
        self.refused(["score", "--character", YI, "s"], 1, "s")
        self.refused(["trace", "s"], 1, "s")
        self.refused(["trial", "--spec", "s", "--check"], 1, "s")
        self.refused(["session", "plan", "--subjects", "1", "s"], 1, "s")
        self.refused(["trial", YI, "--store", "s"], 1, "s")

    def test_a_proc_file_is_read_for_its_content_not_its_size(self):
        # /proc/self/status is a regular file whose stat says 0 bytes: read, it is text, not JSON or CSV. A
        # reader that trusted the size would find the document ending before its first byte.
        line = self.refused(["trial", "--spec", "/proc/self/status", "--check"], (1, 2), "/proc/self/status")
        self.assertNotIn("end of input", line)
        line = self.refused(["session", "plan", "--subjects", "1", "/proc/self/status"], (1, 2),
                            "/proc/self/status")
        self.assertNotIn("end of input", line)
        line = self.refused(["trial", YI, "--guidance-mode", "replay", "--teacher", "/proc/self/status",
                             "--max-duration", "1"], (1, 2), "/proc/self/status")
        self.assertNotIn("end of input", line)
        line = self.refused(["score", "--character", YI, "/proc/self/status"], 1, "/proc/self/status")
        self.assertNotIn("empty", line)

    def test_a_device_node_for_a_sessions_file_is_refused_without_reading_it(self):
        # docs/experiments.md: a session's files are its own; a FIFO or a device there is refused, never read
        # without end. session.json made a character device reading as /dev/zero (mknod as root; skipped else).
        study = self.dir / "study"
        shutil.copytree(SHARED["session"].parents[1], study, symlinks=True)
        session = next(study.glob("S01/*/session.json"))
        session.unlink()
        try:
            os.mknod(session, 0o644 | stat.S_IFCHR, os.makedev(1, 5))
        except PermissionError:
            self.skipTest("mknod is not permitted: no device node can be planted")
        name = str(session.relative_to(self.dir))
        self.refused(["report", "study", "--csv", "."], 1, name)
        self.refused(["curriculum", "--subject", "S01", "--from", "一", "study"], 1, name)
        self.refused(["session", "resume", str(session.parent.relative_to(self.dir))], (1, 2), "session.json")

    def test_a_fifo_in_a_character_folder_does_not_hang_a_command(self):
        data = self.dir / "data"
        data.mkdir()
        shutil.copy(SAMPLE / f"{YI}.json", data / f"{YI}.json")
        os.mkfifo(data / "人.json")
        result = self.quick(["corpus", "build", "--data", "data", "--out", "s.store"])
        self.assertIn(result.returncode, (0, 1), result.stderr)
        self.assertIn("人.json", result.stderr.decode())
        self.assertNotIn("Traceback", result.stderr.decode())
        self.assertEqual(temporaries(self.dir), [])
        result = self.quick(["trial", YI, "--data", "data", "--max-duration", "0.05"])
        self.assertIn(result.returncode, (0, 1), result.stderr)
        result = self.quick(["model", "人", "--data", "data"])
        self.assert_one_error(result, 1, "人.json")

    def test_folder_arguments_given_what_is_no_folder(self):
        os.mkfifo(self.dir / "fifo")
        self.socket_at(self.dir / "sock")
        for name in ("fifo", "sock", "/dev/null", "t.csv"):
            with self.subTest(name=name):
                self.refused(["session", "resume", name], (1, 2), name)
                self.refused(["report", name, "--csv", "."], (1, 2), name)
                self.refused(["curriculum", "--subject", "S01", "--from", "一", name], (1, 2), name)
                self.refused(["trial", YI, "--data", name], (1, 2), name)

    # ---- inputs that change while they are read ---------------------------------------------------------------

    def test_a_trace_that_grows_while_it_is_scored(self):
        # Whole lines are appended while `score` reads: it scores the lines it read (whole ones, never a torn
        # number), from the first sample to at most the last written, or refuses in one line naming the file.
        trace = self.dir / "t.csv"
        rows = trace.read_text(encoding="utf-8").splitlines()[1:]
        last_t = float(rows[-1].split(",")[0])
        stop = threading.Event()
        appended = [0]

        def grow():
            with open(trace, "a", encoding="utf-8") as f:
                k = 0
                while not stop.is_set() and k < 20000:
                    k += 1
                    f.write(f"{last_t + k * 1e-3:.6f},0.05,0.05,0.01,0,0,0,idle,-1,-1,0,0\n")
                    f.flush()
                    appended[0] = k

        t = threading.Thread(target=grow)
        t.start()
        try:
            result = self.quick(["score", "--character", YI, "t.csv", "--json", "-"])
        finally:
            stop.set()
            t.join()
        if result.returncode == 0:
            samples = json.loads(result.stdout)["samples"]
            self.assertGreaterEqual(samples, SHARED["samples"])
            self.assertLessEqual(samples, SHARED["samples"] + appended[0])
        else:
            self.assert_one_error(result, 1, "t.csv")

    def test_a_trace_truncated_while_it_is_scored(self):
        trace = self.dir / "t.csv"
        body = trace.read_bytes()
        # Blank lines are skipped (docs/metrics.md): 8 MB of them make the read long enough to be cut under it.
        trace.write_bytes(body + b"\n" * 8_000_000)
        done = threading.Event()

        def cut():
            time.sleep(0.01)
            with open(trace, "r+b") as f:
                f.truncate(len(body) // 2)
            done.set()

        t = threading.Thread(target=cut)
        t.start()
        result = self.quick(["score", "--character", YI, "t.csv", "--json", "-"])
        t.join()
        if result.returncode == 0:
            json.loads(result.stdout)
        else:
            self.assert_one_error(result, 1, "t.csv")

    # ---- names and paths -----------------------------------------------------------------------------------

    def test_a_relative_path_of_4000_characters_is_written_and_read(self):
        # Each folder name 250 bytes, 16 deep: a relative name the kernel takes (4,016 + 12 bytes), its
        # absolute name past PATH_MAX. The file is written (no temporary left beside it) and read back.
        rel = os.path.join(*(["d" * 250] * 16))
        os.makedirs(self.dir / rel)
        out = os.path.join(rel, "r.json")
        self.assertGreater(len(out), 4000)
        result = self.quick(["trial", YI, "--max-duration", "0.05", "--json", out, "--csv", rel + "/t.csv"])
        if result.returncode not in (0, 1) or not os.path.exists(self.dir / out):
            self.fail(f"exit {result.returncode}: {error_lines(result)}")
        self.assertEqual(temporaries(self.dir / rel), [])
        self.assertEqual(self.quick(["trial", "--spec", out, "--check"]).returncode, 0)
        self.assertIn(self.quick(["score", "--character", YI, rel + "/t.csv"]).returncode, (0,))

    def test_a_name_of_255_bytes_is_written_and_read(self):
        # docs/cli.md: the temporary's NAME is cut to fit the 255-byte limit, so any name the file system
        # takes can be written. 83 three-byte characters and "x.json": 255 bytes.
        name = "一" * 83 + "x.json"
        csv = "十" * 83 + "x.csv" + "v"
        self.assertEqual(len(name.encode()), 255)
        self.assertEqual(len(csv.encode()), 255)
        result = self.quick(["trial", YI, "--max-duration", "0.05", "--json", name, "--csv", csv,
                             "--svg", "s" * 251 + ".svg"])
        self.assertIn(result.returncode, (0, 1), result.stderr)
        self.assertTrue((self.dir / name).is_file() and (self.dir / csv).is_file())
        self.assertEqual(temporaries(self.dir), [])
        # Replaced too (the temporary's name cut again), then read back.
        before = (self.dir / name).stat().st_ino
        self.assertIn(self.quick(["trial", YI, "--max-duration", "0.05", "--json", name]).returncode, (0, 1))
        self.assertNotEqual((self.dir / name).stat().st_ino, before)
        self.assertEqual(temporaries(self.dir), [])
        self.assertEqual(self.quick(["trial", "--spec", name, "--check"]).returncode, 0)
        self.assertEqual(self.quick(["score", "--character", YI, csv]).returncode, 0)
        # One byte more is no name: refused naming the option.
        self.refused(["trial", YI, "--max-duration", "0.05", "--json", "x" + name], 1, "--json")

    def test_a_name_with_a_line_break_is_written_and_named_on_one_line(self):
        name = "a\nb.json"
        result = self.quick(["trial", YI, "--max-duration", "0.05", "--json", name])
        self.assertIn(result.returncode, (0, 1), result.stderr)
        self.assertTrue((self.dir / name).is_file())
        self.assertEqual(self.quick(["trial", "--spec", name, "--check"]).returncode, 0)
        (self.dir / "c\nd.json").write_text("{\"a\": ", encoding="utf-8")
        self.refused(["trial", "--spec", "c\nd.json", "--check"], 2, "c\\nd.json")
        self.refused(["score", "--character", YI, "e\rf.csv"], 1, "e\\rf.csv")

    def test_names_beginning_with_a_dash_after_double_dash(self):
        for src, dst in (("t.csv", "-t.csv"), ("p.json", "-p.json")):
            shutil.copy(self.dir / src, self.dir / dst)
        shutil.copy(SHARED["trace_h5"], self.dir / "-x.trace.h5")
        result = self.quick(["score", "--character", YI, "--json", "s.json", "--", "-t.csv"])
        self.assertEqual(result.returncode, 0, result.stderr)
        self.assertEqual(json.loads((self.dir / "s.json").read_text())["samples"], SHARED["samples"])
        self.assertEqual(self.quick(["session", "plan", "--subjects", "1", "--", "-p.json"]).returncode, 0)
        result = self.quick(["trace", "--csv", "x.csv", "--", "-x.trace.h5"])
        self.assertEqual(result.returncode, 0, result.stderr)
        self.assertTrue((self.dir / "x.csv").stat().st_size > 0)
        # An option's value beginning with `-` is refused (docs/cli.md "Option syntax"); `./-o.json` is the file.
        self.refused(["trial", YI, "--max-duration", "0.05", "--json", "-o.json"], 2, "--json")
        self.assertIn(self.quick(["trial", YI, "--max-duration", "0.05", "--json", "./-o.json"]).returncode, (0, 1))
        self.assertTrue((self.dir / "-o.json").is_file())
        # A missing file after `--` is named as a file, not taken for an option.
        self.refused(["score", "--character", YI, "--", "-missing.csv"], 1, "-missing.csv")

    def test_a_tilde_is_a_name_no_shell_expanded(self):
        home = self.dir / "home"
        home.mkdir()
        env = dict(ENV, HOME=str(home))
        result = run(["trial", YI, "--max-duration", "0.05", "--json", "~/x.json"], self.dir, timeout=QUICK_S, env=env)
        self.assert_one_error(result, 1, "--json", "~/x.json")
        self.assertEqual(list(home.iterdir()), [])
        result = run(["score", "--character", YI, "~/t.csv"], self.dir, timeout=QUICK_S, env=env)
        self.assert_one_error(result, 1, "~/t.csv")
        (self.dir / "~").mkdir()
        result = run(["trial", YI, "--max-duration", "0.05", "--json", "~/x.json"], self.dir, timeout=QUICK_S, env=env)
        self.assertIn(result.returncode, (0, 1), result.stderr)
        self.assertTrue((self.dir / "~" / "x.json").is_file())
        self.assertEqual(list(home.iterdir()), [])

    def test_relative_paths_through_dotdot_out_of_a_folder_and_back(self):
        sub = self.dir / "a" / "b"
        sub.mkdir(parents=True)
        # Inputs and outputs reached by leaving the working folder and coming back into it.
        result = self.quick(["score", "--character", YI, "../../t.csv", "--json", "../b/../../s.json"], cwd=sub)
        self.assertEqual(result.returncode, 0, result.stderr)
        self.assertTrue((self.dir / "s.json").is_file())
        self.assertEqual(self.quick(["session", "plan", "--subjects", "1", "../../" + "p.json"], cwd=sub).returncode, 0)
        # The same file by two spellings is one output: refused naming both options (exit 2), nothing written.
        self.refused(["trial", YI, "--max-duration", "0.05", "--json", "x.json", "--csv", "../b/x.json"], 2,
                     "--json", "--csv", cwd=sub)
        self.assertFalse((sub / "x.json").exists())
        # An output onto an input through `..`: refused (exit 2), the trace unchanged.
        self.refused(["score", "--character", YI, "t.csv", "--json", "a/b/../../t.csv"], 2, "--json")

    # ---- outputs -------------------------------------------------------------------------------------------

    def test_dev_null_takes_every_output_in_place(self):
        # docs/cli.md: an existing device (/dev/null) is written in place, never replaced, and may be given to
        # several outputs.
        result = self.quick(["trial", YI, "--writer-profile", "skilled", "--max-duration", "4", "--json",
                             "/dev/null", "--csv", "/dev/null", "--svg", "/dev/null", "--record", "/dev/null"])
        self.assertEqual(result.returncode, 0, result.stderr)
        self.assertEqual(self.quick(["trace", str(SHARED["trace_h5"]), "--csv", "/dev/null"]).returncode, 0)
        self.assertEqual(self.quick(["model", YI, "--svg", "/dev/null"]).returncode, 0)
        self.assertEqual(self.quick(["score", "--character", YI, "t.csv", "--json", "/dev/null"]).returncode, 0)
        result = self.quick(["corpus", "build", "--data", str(SAMPLE), "--out", "/dev/null"], timeout=20)
        self.assertIn(result.returncode, (0, 1), result.stderr)
        self.assertNotIn("/dev/null", result.stderr.decode())
        self.assertTrue(stat.S_ISCHR(os.stat("/dev/null").st_mode))
        self.assertEqual([p for p in os.listdir("/dev") if p.startswith(".null")], [])

    def test_report_out_on_a_device_or_fifo_makes_no_folder_beside_it(self):
        # The pages go to NAME_files/ beside the index page (docs/cli.md "report"): beside a device that would
        # be a folder in /dev. Refused as `--out -` is (exit 2 naming --out), no folder made anywhere.
        os.mkfifo(self.dir / "index.fifo")
        self.socket_at(self.dir / "index.sock")
        for out in ("/dev/null", "/dev/full", "index.fifo", "index.sock"):
            with self.subTest(out=out):
                before = set(os.listdir("/dev"))
                try:
                    self.refused(["report", str(SHARED["session"]), "--out", out, "--csv", "."], 2, "--out", out)
                finally:
                    for extra in set(os.listdir("/dev")) - before:
                        if extra.endswith("_files"):
                            shutil.rmtree(os.path.join("/dev", extra), ignore_errors=True)
                self.assertEqual(sorted(set(os.listdir("/dev")) - before), [])
                self.assertFalse((self.dir / "trials.csv").exists())

    def test_dev_full_as_every_output_is_one_line_and_exit_1(self):
        cases = [["trace", str(SHARED["trace_h5"]), "--csv", "/dev/full"],
                 ["score", "--character", YI, "t.csv", "--json", "/dev/full"],
                 ["model", YI, "--svg", "/dev/full"],
                 ["trial", YI, "--max-duration", "0.05", "--csv", "/dev/full"],
                 ["corpus", "build", "--data", str(SAMPLE), "--out", "/dev/full"]]
        for args in cases:
            with self.subTest(args=args[0]):
                self.refused(args, 1, "/dev/full")

    def test_a_fifo_no_one_reads_as_an_output_fails_after_the_stated_wait(self):
        # docs/cli.md: a FIFO that no process opens for reading within 10 s is a failed write (exit 1). Two runs
        # at once: onto the FIFO itself, and onto a symbolic link to it (the link kept, the FIFO kept). Started
        # with the module's set-up when the case runs with the others (load_tests), else here.
        waiting = SHARED.pop("waiting", None) or OntoUnreadFifo(self.dir)
        results, late = waiting.results()
        for name in late:
            self.fail(f"{name}: still waiting {FIFO_WAIT_S + 5} s after it started")
        self.assertGreaterEqual(max(waiting.ended.values()) - waiting.started, FIFO_WAIT_S - 1)
        for name, result in results.items():
            with self.subTest(name=name):
                self.assert_one_error(result, 1, name if name != "link.json" else "link.json")
        self.assertTrue(stat.S_ISFIFO(os.stat(waiting.dir / "out.fifo").st_mode))
        self.assertTrue(os.path.islink(waiting.dir / "link.json"))
        self.assertEqual(temporaries(waiting.dir), [])

    def test_a_link_to_a_fifo_with_a_reader_gets_the_document(self):
        os.mkfifo(self.dir / "out.fifo")
        os.symlink("out.fifo", self.dir / "link.json")
        got = []
        t = threading.Thread(target=lambda: got.append(open(self.dir / "out.fifo", "rb").read()))
        t.start()
        result = self.quick(["score", "--character", YI, "t.csv", "--json", "link.json"])
        t.join(QUICK_S)
        self.assertEqual(result.returncode, 0, result.stderr)
        self.assertEqual(json.loads(got[0])["samples"], SHARED["samples"])
        self.assertTrue(os.path.islink(self.dir / "link.json"))
        self.assertTrue(stat.S_ISFIFO(os.stat(self.dir / "out.fifo").st_mode))

    def test_a_socket_as_an_output_is_refused_and_kept(self):
        self.socket_at(self.dir / "out.sock")
        for args in (["trial", YI, "--max-duration", "0.05", "--json", "out.sock"],
                     ["score", "--character", YI, "t.csv", "--json", "out.sock"],
                     ["model", YI, "--svg", "out.sock"]):
            with self.subTest(args=args[0]):
                self.refused(args, 1, "out.sock")
                self.assertTrue(stat.S_ISSOCK(os.lstat(self.dir / "out.sock").st_mode))

    def test_a_folder_as_an_output_file_is_refused_naming_it(self):
        (self.dir / "dir").mkdir()
        cases = [["trial", YI, "--max-duration", "0.05", "--json", "dir"],
                 ["score", "--character", YI, "t.csv", "--json", "dir"],
                 ["model", YI, "--svg", "dir"],
                 ["trace", str(SHARED["trace_h5"]), "--csv", "dir"],
                 ["corpus", "build", "--data", str(SAMPLE), "--out", "dir"],
                 ["report", str(SHARED["session"]), "--out", "dir"]]
        for args in cases:
            with self.subTest(args=args[0]):
                self.refused(args, 1, "dir")
        # A file where a folder goes.
        self.refused(["report", str(SHARED["session"]), "--csv", "t.csv"], (1, 2), "--csv", "t.csv")
        self.refused(["session", "run", "p.json", "--subjects", "1", "--out", "t.csv"], 1, "--out", "t.csv")

    def test_an_output_under_a_file_is_refused_naming_it(self):
        cases = [["trial", YI, "--max-duration", "0.05", "--json", "t.csv/x.json"],
                 ["score", "--character", YI, "t.csv", "--json", "r.json/s.json"],
                 ["model", YI, "--svg", "t.csv/m.svg"],
                 ["trace", str(SHARED["trace_h5"]), "--csv", "r.json/t.csv"],
                 ["corpus", "build", "--data", str(SAMPLE), "--out", "t.csv/s.store"],
                 ["report", str(SHARED["session"]), "--out", "t.csv/r.html"],
                 ["report", str(SHARED["session"]), "--csv", "t.csv/tables"],
                 ["session", "run", "p.json", "--subjects", "1", "--out", "t.csv/study"]]
        for args in cases:
            with self.subTest(args=args[:2]):
                self.refused(args, 1, "t.csv/" if "t.csv/" in " ".join(args) else "r.json/")

    def test_a_read_only_file_system_refuses_every_output(self):
        ro = self.dir / "ro"
        ro.mkdir()
        probe = subprocess.run(["unshare", "-m", "--propagation", "private", "sh", "-c",
                                'mount -t tmpfs -o size=64k tmpfs "$0" && mount -o remount,ro "$0"', str(ro)],
                               stdout=subprocess.PIPE, stderr=subprocess.PIPE, timeout=QUICK_S)
        if probe.returncode != 0:
            self.skipTest(f"no read-only file system can be made here: {probe.stderr.decode().strip()}")
        cli = os.environ["CALLIGRAPHY_CLI"]
        shell = 'mount -t tmpfs -o size=1m tmpfs ro && printf old > ro/kept.json && mount -o remount,ro ro && exec "$@"'
        cases = [([cli, "trial", YI, "--max-duration", "0.05", "--json", "ro/new.json"], 1, "ro/new.json"),
                 ([cli, "trial", YI, "--max-duration", "0.05", "--json", "ro/kept.json"], 1, "ro/kept.json"),
                 ([cli, "score", "--character", YI, "t.csv", "--json", "ro/kept.json"], 1, "ro/kept.json"),
                 ([cli, "session", "run", "p.json", "--subjects", "1", "--out", "ro/study"], 1, "ro/study"),
                 ([cli, "report", str(SHARED["session"]), "--csv", "ro"], 1, "ro")]
        for args, status, needle in cases:
            with self.subTest(args=args[1]):
                try:
                    result = subprocess.run(["unshare", "-m", "--propagation", "private", "sh", "-c",
                                             shell + '; ', "sh", *args], cwd=self.dir, env=ENV, timeout=QUICK_S,
                                            stdin=subprocess.DEVNULL, stdout=subprocess.PIPE,
                                            stderr=subprocess.PIPE)
                except subprocess.TimeoutExpired:
                    self.fail(f"{args} still ran after {QUICK_S} s")
                line = self.assert_one_error(result, status, needle)
                self.assertTrue("Read-only file system" in line or "cannot" in line, line)
        self.assertEqual(list(ro.iterdir()), [])

    # ---- Python ----------------------------------------------------------------------------------------------

    def test_python_readers_given_what_is_no_regular_file_raise_data_error(self):
        os.mkfifo(self.dir / "f.csv")
        self.socket_at(self.dir / "s")
        got = self.py(
            "import json, calligraphy as cg\n"
            "out = {}\n"
            "cases = [('score', lambda p: cg.score(p, '一'), ['f.csv', '/dev/zero', '/dev/urandom', '/dev/null', 's',"
            " '/proc/self/status', '.']),\n"
            "         ('load', cg.TeacherRecording.load, ['f.csv', '/dev/urandom', '/dev/null', 's',"
            " '/proc/self/status', '.']),\n"
            "         ('rerun', cg.rerun_trial, ['f.csv', '/dev/urandom', 's', '/proc/self/status', '.'])]\n"
            "for kind, f, paths in cases:\n"
            "    for p in paths:\n"
            "        try:\n"
            "            f(p); out[kind + ' ' + p] = 'returned'\n"
            "        except Exception as e:\n"
            "            out[kind + ' ' + p] = [type(e).__name__, isinstance(e, cg.DataError), str(e)]\n"
            "print(json.dumps(out))\n")
        for key, value in got.items():
            with self.subTest(case=key):
                self.assertNotEqual(value, "returned")
                self.assertTrue(value[1], f"{key}: {value[0]}: {value[2]}")
                path = key.split(" ", 1)[1]
                self.assertIn(path if path != "." else "", value[2])
                self.assertNotIn("\n", value[2])

    def test_python_writers_given_what_is_no_regular_file(self):
        (self.dir / "dir").mkdir()
        os.mkfifo(self.dir / "f.json")
        got = self.py(
            "import json, calligraphy as cg\n"
            "t = cg.TeacherRecording.load('teacher.json')\n"
            "out = {}\n"
            "for p in ['/dev/full', 'dir', 't.csv/x.json', '/dev/null']:\n"
            "    try:\n"
            "        t.save(p); out[p] = 'returned'\n"
            "    except Exception as e:\n"
            "        out[p] = [type(e).__name__, isinstance(e, (cg.Error, OSError)), str(e)]\n"
            "print(json.dumps(out))\n")
        self.assertEqual(got.pop("/dev/null"), "returned")
        for path, value in got.items():
            with self.subTest(path=path):
                self.assertNotEqual(value, "returned")
                self.assertTrue(value[1], f"{path}: {value[0]}: {value[2]}")
                self.assertIn(path, value[2])
        self.assertEqual(temporaries(self.dir), [])
        self.assertEqual(list((self.dir / "dir").iterdir()), [])


if __name__ == "__main__":
    unittest.main()
