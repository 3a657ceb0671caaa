"""An outsider's hostile round on every file the program reads or writes, written from the docs alone
(docs/cli.md, docs/experiments.md, docs/python.md): forged, cut, linked, filled, killed, raced and mislabelled
files for `trace`, `trial --spec`, `score`, `report`, `session run|resume|plan`, the Python study report and
readers. Each case runs the program and checks what the docs promise: a clear one-line error naming the file
(and the JSON pointer or line), the documented exit status, no crash, no hang, no silent wrong result, and
nothing outside the output changed.

CALLIGRAPHY_CLI names the program; PYTHONPATH holds the Python module (its cases are skipped without it)."""

import fcntl
import gzip
import hashlib
import json
import os
import resource
import shutil
import signal
import subprocess
import sys
import tempfile
import time
import unittest
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from study_protocols import CLI, digest_tree, two_session_protocol  # noqa: E402

SANITIZED = os.environ.get("CALLIGRAPHY_SANITIZED") == "1"
PYTHON = "/usr/bin/python3" if Path("/usr/bin/python3").exists() else sys.executable


def have_module():
    try:
        import calligraphy  # noqa: F401
        return True
    except ImportError:
        return False


def one_session_protocol(name):
    """Two trials of 十, one session: small enough to run in about a second."""
    return {
        "format": "calligraphy-study-protocol", "version": 1, "name": name,
        "conditions": [{"name": "vision", "mode": "vision"}, {"name": "haptic", "mode": "haptic"}],
        "phases": [{"phase": "pre-test", "condition": "vision", "characters": ["十"]},
                   {"phase": "training", "condition": "haptic", "characters": ["十"]}],
        "trial": {"max_duration_s": 20},
    }


def run(args, cwd, timeout=120, preexec_fn=None, env=None):
    return subprocess.run([str(a) for a in args], cwd=cwd, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                          timeout=timeout, preexec_fn=preexec_fn, env=env)


class Fixture:
    """One small study, one trial record with its CSV, made once for every case (each case works on copies)."""

    def __init__(self):
        self.tmp = tempfile.TemporaryDirectory(prefix="calligraphy-unseen-")
        self.root = Path(self.tmp.name)
        self.protocol = self.root / "one.json"
        self.protocol.write_text(json.dumps(one_session_protocol("one"), ensure_ascii=False), encoding="utf-8")
        self.protocol2 = self.root / "days.json"
        self.protocol2.write_text(json.dumps(two_session_protocol("days"), ensure_ascii=False), encoding="utf-8")
        out = run([CLI, "session", "run", self.protocol, "--writer", "simulated", "--subjects", "2",
                   "--out", self.root / "study"], self.root)
        assert out.returncode == 0, out.stderr.decode()
        self.study = self.root / "study"
        self.sessions = sorted(p.parent for p in self.study.rglob("session.json"))
        self.records = sorted(p for p in self.sessions[0].glob("trials/*.json"))
        self.traces = sorted(p for p in self.sessions[0].glob("trials/*.trace.h5"))
        out = run([CLI, "trial", "十", "--seed", "3", "--json", self.root / "trial.json", "--csv",
                   self.root / "trial.csv"], self.root)
        assert out.returncode == 0, out.stderr.decode()
        self.record = self.root / "trial.json"
        self.csv = self.root / "trial.csv"


FIXTURE = None


class Hostile(unittest.TestCase):
    """The fixture and helpers of both rounds."""

    @classmethod
    def setUpClass(cls):
        global FIXTURE
        if not CLI or not Path(CLI).exists():
            raise unittest.SkipTest("CALLIGRAPHY_CLI is not the program: run through ctest")
        if FIXTURE is None:
            FIXTURE = Fixture()
        cls.fx = FIXTURE

    def setUp(self):
        self.tmpdir = tempfile.TemporaryDirectory(prefix="calligraphy-unseen-case-")
        self.cwd = Path(self.tmpdir.name)
        self.mounts = []

    def tearDown(self):
        for point in self.mounts:
            subprocess.run(["umount", "-l", str(point)], stderr=subprocess.DEVNULL)
        # a case may leave a read-only folder: make everything writable again before removing it
        for p in [self.cwd, *self.cwd.rglob("*")]:
            if p.is_dir() and not p.is_symlink():
                os.chmod(p, 0o755)
        self.tmpdir.cleanup()

    def cli(self, *args, timeout=120, **kw):
        return run([CLI, *args], self.cwd, timeout=timeout, **kw)

    def refused(self, out, status, *names):
        """A refusal: the status, one line on standard error naming each of `names`, no crash."""
        err = out.stderr.decode(errors="replace")
        self.assertEqual(out.returncode, status, err)
        lines = [line for line in err.splitlines() if "error" in line]
        self.assertEqual(len(lines), 1, err)
        for name in names:
            self.assertIn(str(name), lines[0], err)
        self.assertNotIn("internal error", err)
        self.assertNotIn("Traceback", err)
        return lines[0]

    def copy(self, src, name=None):
        dst = self.cwd / (name or Path(src).name)
        if Path(src).is_dir():
            shutil.copytree(src, dst, symlinks=True)
        else:
            shutil.copyfile(src, dst)
        return dst

    def study_copy(self):
        return self.copy(self.fx.study, "study")

    def first_record(self, study):
        return sorted(study.rglob("trials/*.json"))[0]

    def forged(self, edit):
        """An unfinished session (the subclass's `unfinished()`: a copy of the study with work left) whose
        session.json is `edit(document)`: a dict edited in place, or a text returned."""
        study, session = self.unfinished()
        manifest = session / "session.json"
        doc = json.loads(manifest.read_text(encoding="utf-8"))
        text = edit(doc)
        manifest.write_text(text if isinstance(text, str) else json.dumps(doc, ensure_ascii=False, indent=2),
                            encoding="utf-8")
        return study, session

    def mount_small_tmpfs(self, size):
        point = self.cwd / "tmpfs"
        point.mkdir()
        done = subprocess.run(["mount", "-t", "tmpfs", "-o", f"size={size}", "tmpfs", str(point)],
                              stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        if done.returncode != 0:
            self.skipTest("mount is not permitted here")
        self.mounts.append(point)
        return point

    def spec_with(self, text, name="r.json"):
        path = self.cwd / name
        path.write_bytes(text if isinstance(text, bytes) else text.encode("utf-8"))
        return path

    def record_text(self):
        return self.fx.record.read_text(encoding="utf-8")

    def csv_with(self, rows, name="s.csv", prefix=b""):
        path = self.cwd / name
        path.write_bytes(prefix + ("\n".join(rows) + "\n").encode())
        return path

    def trace_rows(self):
        return self.fx.csv.read_text().splitlines()

    def days_study(self, out_dir, subject):
        out = self.cli("session", "run", self.fx.protocol2, "--subject", subject, "--writer", "simulated",
                       "--out", out_dir)
        self.assertEqual(out.returncode, 0, out.stderr)
        days = sorted(p.parent for p in (out_dir / subject).glob("*/session.json"))
        self.assertEqual(len(days), 2)
        return days

    def sparse(self, name, size):
        path = self.cwd / name
        with open(path, "wb") as f:
            f.truncate(size)
        return path

    def python(self, code, *args, timeout=300):
        env = dict(os.environ)
        return subprocess.run([PYTHON, "-c", code, *map(str, args)], cwd=self.cwd, stdout=subprocess.PIPE,
                              stderr=subprocess.PIPE, timeout=timeout, env=env)

    def study_report(self, *args, timeout=300):
        return subprocess.run([PYTHON, "-m", "calligraphy.study_report", *map(str, args)], cwd=self.cwd,
                              stdout=subprocess.PIPE, stderr=subprocess.PIPE, timeout=timeout)

    def need_module(self):
        if not have_module():
            self.skipTest("the Python module is not built (PYTHONPATH)")


class FileSurfaces(Hostile):
    """`trace`, `trial --spec`, `trial` outputs and `score`."""

    def test_trace_cut_file_is_named(self):
        t = self.copy(self.fx.traces[0], "cut.trace.h5")
        data = t.read_bytes()
        t.write_bytes(data[: len(data) // 2])
        self.refused(self.cli("trace", t), 1, "cut.trace.h5")

    def test_trace_one_flipped_byte_is_named(self):
        t = self.copy(self.fx.traces[0], "flip.trace.h5")
        data = bytearray(t.read_bytes())
        data[len(data) - 100] ^= 0x40
        t.write_bytes(bytes(data))
        self.refused(self.cli("trace", t), 1, "flip.trace.h5")

    def test_trace_header_declaring_a_huge_length_is_refused_quickly(self):
        t = self.copy(self.fx.traces[0], "huge.trace.h5")
        data = bytearray(t.read_bytes())
        text = bytes(data[:512]).decode("latin-1")
        # the user block names the length of the HDF5 file after it: claim an enormous one
        digits = [i for i, c in enumerate(text) if c.isdigit()]
        self.assertTrue(digits, text)
        forged = text.replace(str(len(data) - 512), "99999999999999999999", 1)
        data[:512] = forged.encode("latin-1")[:512].ljust(512, b"\0")
        t.write_bytes(bytes(data))
        self.refused(self.cli("trace", t, timeout=30), 1, "huge.trace.h5")

    def test_trace_empty_file_is_named(self):
        t = self.cwd / "empty.trace.h5"
        t.write_bytes(b"")
        self.refused(self.cli("trace", t), 1, "empty.trace.h5")

    def test_trace_csv_text_posing_as_hdf5_is_named(self):
        t = self.cwd / "foreign.trace.h5"
        t.write_bytes(self.fx.csv.read_bytes())
        self.refused(self.cli("trace", t), 1, "foreign.trace.h5")

    def test_trace_from_a_fifo_does_not_hang(self):
        fifo = self.cwd / "pipe.trace.h5"
        os.mkfifo(fifo)
        writer = subprocess.Popen(["sh", "-c", f"printf 'xx' > '{fifo}'"])
        try:
            out = self.cli("trace", fifo, timeout=30)
        finally:
            writer.kill()
            writer.wait()
        self.assertIn(out.returncode, (1, 2), out.stderr)
        self.assertIn("pipe.trace.h5", out.stderr.decode())

    def test_trace_csv_over_the_file_size_limit_keeps_the_earlier_file(self):
        dst = self.cwd / "t.csv"
        dst.write_text("earlier\n")

        def limit():
            resource.setrlimit(resource.RLIMIT_FSIZE, (4096, 4096))
        out = self.cli("trace", self.fx.traces[0], "--csv", dst, preexec_fn=limit)
        self.refused(out, 1, "t.csv")
        self.assertEqual(dst.read_text(), "earlier\n")
        self.assertEqual(sorted(p.name for p in self.cwd.iterdir()), ["t.csv"])

    def test_trace_csv_into_a_read_only_folder_is_named(self):
        ro = self.cwd / "ro"
        ro.mkdir()
        os.chmod(ro, 0o555)
        if os.geteuid() == 0:
            subprocess.run(["chattr", "+i", ro], check=False)
        try:
            out = self.cli("trace", self.fx.traces[0], "--csv", ro / "t.csv")
            if os.geteuid() == 0 and out.returncode == 0:
                self.skipTest("root writes into a read-only folder and chattr is not available")
            self.refused(out, 1, "ro")
            self.assertEqual(list(ro.iterdir()), [])
        finally:
            subprocess.run(["chattr", "-i", ro], check=False, stderr=subprocess.DEVNULL)

    def test_trace_csv_onto_its_hard_linked_input_is_refused(self):
        t = self.copy(self.fx.traces[0], "in.trace.h5")
        os.link(t, self.cwd / "alias.csv")
        before = t.read_bytes()
        self.refused(self.cli("trace", t, "--csv", self.cwd / "alias.csv"), 2, "alias.csv")
        self.assertEqual(t.read_bytes(), before)

    def test_trace_csv_onto_a_full_tmpfs_leaves_no_temporary(self):
        small = self.mount_small_tmpfs("64k")
        (small / "fill").write_bytes(b"\0" * (60 * 1024))
        out = self.cli("trace", self.fx.traces[0], "--csv", small / "t.csv")
        self.refused(out, 1, "t.csv")
        self.assertEqual(sorted(p.name for p in small.iterdir()), ["fill"])

    def test_spec_with_a_bare_nan_is_named(self):
        doc = json.loads(self.record_text())
        doc["specification"]["trial"]["rate_hz"] = float("nan")
        path = self.spec_with(json.dumps(doc))  # Python writes NaN, which is not JSON
        self.refused(self.cli("trial", "--spec", path), 2, "r.json")

    def test_spec_with_1e999_names_the_pointer(self):
        text = self.record_text()
        doc = json.loads(text)
        doc["specification"]["trial"]["rate_hz"] = 12345.5
        path = self.spec_with(json.dumps(doc).replace("12345.5", "1e999"))
        self.refused(self.cli("trial", "--spec", path), 2, "r.json", "/specification/trial/rate_hz")

    def test_spec_with_minus_zero_duration_names_the_pointer(self):
        doc = json.loads(self.record_text())
        doc["specification"]["trial"]["max_duration_s"] = 777.25
        path = self.spec_with(json.dumps(doc).replace("777.25", "-0.0"))
        self.refused(self.cli("trial", "--spec", path), 2, "r.json", "/specification/trial/max_duration_s")

    def test_spec_with_a_duplicated_key_is_refused(self):
        doc = json.loads(self.record_text())
        seed = doc["specification"]["trial"]["seed"]
        text = json.dumps(doc).replace(f'"seed": {seed}', f'"seed": {seed}, "seed": {seed + 1}', 1)
        self.assertIn(f'"seed": {seed + 1}', text)
        path = self.spec_with(text)
        line = self.refused(self.cli("trial", "--spec", path), 2, "r.json")
        self.assertIn("seed", line)

    def test_spec_with_a_byte_order_mark_runs(self):
        path = self.spec_with(b"\xef\xbb\xbf" + self.fx.record.read_bytes())
        out = self.cli("trial", "--spec", path, "--csv", self.cwd / "again.csv")
        self.assertEqual(out.returncode, 0, out.stderr)
        self.assertEqual((self.cwd / "again.csv").read_bytes(), self.fx.csv.read_bytes())

    def test_spec_cut_in_half_is_named(self):
        data = self.fx.record.read_bytes()
        path = self.spec_with(data[: len(data) // 2])
        self.refused(self.cli("trial", "--spec", path), 2, "r.json")

    def test_spec_of_a_future_version_is_refused(self):
        doc = json.loads(self.record_text())
        doc["specification"]["version"] = 99
        self.refused(self.cli("trial", "--spec", self.spec_with(json.dumps(doc))), 2, "r.json")

    def test_spec_with_a_forged_scene_digest_is_refused(self):
        doc = json.loads(self.record_text())
        doc["specification"]["scene"]["sha256"] = "0" * 64
        out = self.cli("trial", "--spec", self.spec_with(json.dumps(doc)), "--csv", self.cwd / "x.csv")
        self.refused(out, 1, "r.json")
        self.assertFalse((self.cwd / "x.csv").exists())

    def test_spec_with_a_seed_of_two_to_the_64_names_the_pointer(self):
        doc = json.loads(self.record_text())
        doc["specification"]["trial"]["seed"] = 2 ** 64
        self.refused(self.cli("trial", "--spec", self.spec_with(json.dumps(doc))), 2, "r.json",
                     "/specification/trial/seed")

    def test_spec_with_a_fractional_seed_names_the_pointer(self):
        doc = json.loads(self.record_text())
        doc["specification"]["trial"]["seed"] = 1.5
        self.refused(self.cli("trial", "--spec", self.spec_with(json.dumps(doc))), 2, "r.json",
                     "/specification/trial/seed")

    def test_spec_with_an_unknown_key_names_the_pointer(self):
        doc = json.loads(self.record_text())
        doc["specification"]["trial"]["sneaky"] = 1
        self.refused(self.cli("trial", "--spec", self.spec_with(json.dumps(doc))), 2, "r.json", "sneaky")

    def test_spec_nested_100000_deep_is_refused_without_a_crash(self):
        path = self.spec_with("[" * 100000 + "]" * 100000)
        self.refused(self.cli("trial", "--spec", path, timeout=60), 2, "r.json")

    def test_spec_from_a_fifo_with_no_writer_does_not_hang(self):
        fifo = self.cwd / "r.json"
        os.mkfifo(fifo)
        writer = subprocess.Popen(["sh", "-c", f"printf '{{' > '{fifo}'"])
        try:
            out = self.cli("trial", "--spec", fifo, timeout=30)
        finally:
            writer.kill()
            writer.wait()
        self.assertIn(out.returncode, (1, 2), out.stderr)
        self.assertIn("r.json", out.stderr.decode())

    def test_spec_json_output_onto_the_spec_through_a_symlink_is_refused(self):
        spec = self.copy(self.fx.record, "r.json")
        os.symlink("r.json", self.cwd / "link.json")
        before = spec.read_bytes()
        self.refused(self.cli("trial", "--spec", spec, "--json", self.cwd / "link.json"), 2, "link.json")
        self.assertEqual(spec.read_bytes(), before)

    def test_replay_record_with_another_teacher_is_refused_naming_both_digests(self):
        teacher = self.cwd / "teacher.json"
        out = self.cli("trial", "十", "--writer-profile", "skilled", "--record", teacher)
        self.assertEqual(out.returncode, 0, out.stderr)
        out = self.cli("trial", "十", "--guidance-mode", "replay", "--teacher", teacher, "--json",
                       self.cwd / "replay.json")
        self.assertEqual(out.returncode, 0, out.stderr)
        first = hashlib.sha256(teacher.read_bytes()).hexdigest()
        out = self.cli("trial", "十", "--writer-profile", "skilled", "--seed", "9", "--record", teacher)
        self.assertEqual(out.returncode, 0, out.stderr)
        second = hashlib.sha256(teacher.read_bytes()).hexdigest()
        self.assertNotEqual(first, second)
        line = self.refused(self.cli("trial", "--spec", self.cwd / "replay.json"), 1, "teacher.json")
        self.assertIn(first, line)
        self.assertIn(second, line)

    def test_score_nan_coordinate_names_the_line(self):
        rows = self.trace_rows()
        cells = rows[5].split(",")
        cells[1] = "nan"
        rows[5] = ",".join(cells)
        self.refused(self.cli("score", self.csv_with(rows), "--character", "十"), 1, "s.csv:6")

    def test_score_1e999_coordinate_names_the_line(self):
        rows = self.trace_rows()
        cells = rows[7].split(",")
        cells[2] = "1e999"
        rows[7] = ",".join(cells)
        self.refused(self.cli("score", self.csv_with(rows), "--character", "十"), 1, "s.csv:8")

    def test_score_bom_and_crlf_read_as_the_plain_file(self):
        rows = self.trace_rows()
        plain = self.cli("score", self.fx.csv, "--character", "十", "--json", "-")
        path = self.cwd / "bom.csv"
        path.write_bytes(b"\xef\xbb\xbf" + ("\r\n".join(rows) + "\r\n").encode())
        bom = self.cli("score", path, "--character", "十", "--json", "-")
        self.assertEqual(bom.returncode, 0, bom.stderr)
        a, b = json.loads(plain.stdout), json.loads(bom.stdout)
        a.pop("trace"), b.pop("trace")
        self.assertEqual(a, b)

    def test_score_duplicated_column_is_refused(self):
        rows = self.trace_rows()
        header = rows[0].split(",")
        rows[0] = ",".join(header + ["x"])
        rows[1:] = [r + ",0" for r in rows[1:]]
        self.refused(self.cli("score", self.csv_with(rows), "--character", "十"), 1, "s.csv", "x")

    def test_score_cut_gzip_is_named(self):
        data = gzip.compress(self.fx.csv.read_bytes())
        path = self.cwd / "cut.csv.gz"
        path.write_bytes(data[: len(data) - 20])
        self.refused(self.cli("score", path, "--character", "十"), 1, "cut.csv.gz")

    def test_score_damaged_hdf5_trace_is_named(self):
        t = self.copy(self.fx.traces[0], "d.trace.h5")
        data = bytearray(t.read_bytes())
        data[600] ^= 0xFF
        t.write_bytes(bytes(data))
        self.refused(self.cli("score", t, "--character", "十"), 1, "d.trace.h5")

    def test_score_json_onto_its_trace_is_refused(self):
        t = self.copy(self.fx.csv, "t.csv")
        before = t.read_bytes()
        self.refused(self.cli("score", t, "--character", "十", "--json", self.cwd / "./t.csv"), 2, "t.csv")
        self.assertEqual(t.read_bytes(), before)

    @unittest.skipIf(SANITIZED, "an address-space limit does not go with the sanitizers")
    def test_score_gzip_of_one_endless_line_is_refused_in_bounded_memory(self):
        path = self.cwd / "bomb.csv.gz"
        block = b"1" * (1 << 20)
        with gzip.open(path, "wb", compresslevel=1) as f:
            f.write(b"t,x,y,z\n")
            for _ in range(40):  # 40 MiB of one line, no line break (past 256 MiB the size limit refuses it)
                f.write(block)

        def limit():
            resource.setrlimit(resource.RLIMIT_AS, (1 << 30, 1 << 30))
        out = self.cli("score", path, "--character", "十", timeout=120, preexec_fn=limit)
        self.refused(out, 1, "bomb.csv.gz")

    def test_score_time_column_with_text_names_the_line(self):
        rows = self.trace_rows()
        cells = rows[3].split(",")
        cells[0] = "0x10"
        rows[3] = ",".join(cells)
        self.refused(self.cli("score", self.csv_with(rows), "--character", "十"), 1, "s.csv:4")

    def test_trace_through_a_link_loop_is_named(self):
        os.symlink("loop-b.trace.h5", self.cwd / "loop-a.trace.h5")
        os.symlink("loop-a.trace.h5", self.cwd / "loop-b.trace.h5")
        out = self.cli("trace", self.cwd / "loop-a.trace.h5")
        self.assertIn(out.returncode, (1, 2), out.stderr)
        self.assertIn("loop-a.trace.h5", out.stderr.decode())
        self.assertNotIn("internal", out.stderr.decode())

    def test_score_of_a_sparse_trace_over_the_size_limit_is_refused_unread(self):
        path = self.sparse("big.csv", (256 << 20) + 1)
        started = time.monotonic()
        self.refused(self.cli("score", path, "--character", "十", timeout=60), 1, "big.csv")
        self.assertLess(time.monotonic() - started, 30)  # a bound against a hang, not a measurement

    @unittest.skipIf(SANITIZED, "an address-space limit does not go with the sanitizers")
    def test_spec_of_a_sparse_gigabyte_is_refused_without_reading_it(self):
        path = self.sparse("r.json", 1 << 30)

        def limit():
            resource.setrlimit(resource.RLIMIT_AS, (768 << 20, 768 << 20))
        self.refused(self.cli("trial", "--spec", path, timeout=60, preexec_fn=limit), 1, "r.json")

    def test_trial_csv_onto_dev_full_is_a_write_error(self):
        out = self.cli("trial", "十", "--csv", "/dev/full")
        self.assertEqual(out.returncode, 1, out.stderr)
        self.assertIn("/dev/full", out.stderr.decode())

    def test_a_file_name_with_a_line_break_is_quoted_on_one_line(self):
        folder = self.cwd / "a\nb\x1b[31m"
        folder.mkdir()
        t = folder / "x.trace.h5"
        t.write_bytes(b"not hdf5")
        out = self.cli("trace", t)
        err = out.stderr.decode(errors="replace")
        self.assertEqual(out.returncode, 1, err)
        self.assertEqual(len(err.strip().splitlines()), 1, err)
        self.assertNotIn("\x1b", err)
        self.assertIn("a\\nb", err)

    def test_spec_of_a_record_without_a_specification_says_so(self):
        doc = json.loads(self.record_text())
        del doc["specification"]
        line = self.refused(self.cli("trial", "--spec", self.spec_with(json.dumps(doc))), 2, "r.json")
        self.assertIn("specification", line)


class StudySurfaces(Hostile):
    """`report`, `session run|resume|plan`, the study folder's identity and lock, the Python readers."""

    def test_report_record_with_1e999_names_file_and_pointer(self):
        study = self.study_copy()
        rec = self.first_record(study)
        text = rec.read_text(encoding="utf-8")
        doc = json.loads(text)
        doc["wall_time_s"] = 4242.125
        rec.write_text(json.dumps(doc).replace("4242.125", "1e999"), encoding="utf-8")
        (self.cwd / "tables").mkdir()
        out = self.cli("report", study, "--csv", self.cwd / "tables")
        self.refused(out, 1, rec.name, "/wall_time_s")
        self.assertEqual(list((self.cwd / "tables").iterdir()), [])

    def test_report_trace_swapped_for_another_trials_is_refused_naming_both_digests(self):
        study = self.study_copy()
        traces = sorted(study.rglob("trials/*.trace.h5"))
        a, b = traces[0], traces[1]
        shutil.copyfile(b, a)
        out = self.cli("report", study, "--out", self.cwd / "r.html")
        line = self.refused(out, 1, a.name)
        self.assertIn(hashlib.sha256(a.read_bytes()).hexdigest(), line)

    def test_report_of_a_copied_session_folder_is_refused_naming_both(self):
        study = self.study_copy()
        session = sorted(p.parent for p in study.rglob("session.json"))[0]
        shutil.copytree(session, session.parent / (session.name + "-copy"))
        (self.cwd / "tables").mkdir()
        out = self.cli("report", study, "--csv", self.cwd / "tables")
        self.refused(out, 1, session.name)
        self.assertEqual(list((self.cwd / "tables").iterdir()), [])

    def test_report_cut_record_is_named(self):
        study = self.study_copy()
        rec = self.first_record(study)
        data = rec.read_bytes()
        rec.write_bytes(data[: len(data) // 3])
        (self.cwd / "tables").mkdir()
        self.refused(self.cli("report", study, "--csv", self.cwd / "tables"), 1, rec.name)

    def test_report_csv_into_a_read_only_folder_is_named_and_nothing_changes(self):
        tables = self.cwd / "tables"
        tables.mkdir()
        (tables / "trials.csv").write_text("earlier\n")
        os.chmod(tables, 0o555)
        if os.geteuid() == 0:
            if subprocess.run(["chattr", "+i", tables], stderr=subprocess.DEVNULL).returncode != 0:
                self.skipTest("root writes into read-only folders and chattr is not available")
        try:
            out = self.cli("report", self.fx.study, "--csv", tables)
            self.refused(out, 1, "tables")
            self.assertEqual((tables / "trials.csv").read_text(), "earlier\n")
        finally:
            subprocess.run(["chattr", "-i", tables], stderr=subprocess.DEVNULL)

    def test_report_out_whose_files_folder_is_a_file_is_named(self):
        (self.cwd / "r_files").write_text("a file, not a folder\n")
        out = self.cli("report", self.fx.study, "--out", self.cwd / "r.html")
        self.assertIn(out.returncode, (1, 2), out.stderr)
        self.assertIn("r_files", out.stderr.decode())
        self.assertEqual((self.cwd / "r_files").read_text(), "a file, not a folder\n")
        self.assertFalse((self.cwd / "r.html").exists())

    def test_report_forged_journal_naming_a_file_outside_is_refused_and_kept(self):
        tables = self.cwd / "tables"
        tables.mkdir()
        victim = self.cwd / "victim.txt"
        victim.write_text("keep me\n")
        out = self.cli("report", self.fx.study, "--csv", tables)
        self.assertEqual(out.returncode, 0, out.stderr)
        before = digest_tree(tables)
        # a journal this program did not write, naming a file outside its folder (docs/cli.md, "Outputs")
        forged = tables / ".calligraphy-set-forged.journal"
        forged.write_text(json.dumps({"format": "calligraphy-set-journal", "version": 1, "checksum": "0",
                                      "files": [{"target": "../victim.txt", "kept": "trials.csv"}]}))
        text = forged.read_text()
        out = self.cli("report", self.fx.study, "--csv", tables)
        self.refused(out, 1, ".calligraphy-set-forged.journal")
        self.assertEqual(victim.read_text(), "keep me\n")
        self.assertEqual(forged.read_text(), text)
        forged.unlink()
        self.assertEqual(digest_tree(tables), before)

    def test_resume_waits_for_no_one_while_a_run_holds_the_study_lock(self):
        study = self.study_copy()
        session = sorted(p.parent for p in study.rglob("session.json"))[0]
        rec = sorted(session.glob("trials/*.json"))[-1]
        rec.unlink()  # the session now has a trial to run
        lock = study / ".calligraphy-run.lock"
        with open(lock, "a+") as held:
            fcntl.flock(held, fcntl.LOCK_EX | fcntl.LOCK_NB)
            before = digest_tree(study)
            out = self.cli("session", "resume", session, timeout=60)
            self.refused(out, 1, str(study))
            self.assertEqual(digest_tree(study), before)

    def test_a_resume_holding_the_study_refuses_a_second_resume(self):
        protocol = one_session_protocol("slow")
        protocol["phases"][1]["repetitions"] = 6
        path = self.cwd / "slow.json"
        path.write_text(json.dumps(protocol, ensure_ascii=False), encoding="utf-8")
        study = self.cwd / "study"
        out = self.cli("session", "run", path, "--writer", "simulated", "--subjects", "2", "--out", study)
        self.assertEqual(out.returncode, 0, out.stderr)
        first, second = sorted(p.parent for p in study.rglob("session.json"))
        for session in (first, second):
            for record in sorted(session.glob("trials/*.json"))[1:]:
                record.unlink()
        lock = study / ".calligraphy-run.lock"
        resume = subprocess.Popen([CLI, "session", "resume", str(first)], cwd=self.cwd,
                                  stdout=subprocess.PIPE, stderr=subprocess.PIPE)
        try:
            deadline = time.monotonic() + 60
            while resume.poll() is None and time.monotonic() < deadline:
                if lock.exists() and "resume" in lock.read_text(errors="replace"):
                    resume.send_signal(signal.SIGSTOP)  # the first resume holds the study, stopped
                    break
                time.sleep(0.001)
            if resume.poll() is not None:
                self.fail("the first resume ended before it was seen holding the study's lock (it takes none?): "
                          + resume.stderr.read().decode())
            before = digest_tree(second)
            line = self.refused(self.cli("session", "resume", second, timeout=60), 1, str(study))
            self.assertIn(str(resume.pid), line)
            self.assertEqual(digest_tree(second), before)
        finally:
            resume.send_signal(signal.SIGCONT)
            status = resume.wait(timeout=120)
            resume.stdout.close()
            resume.stderr.close()
        self.assertEqual(status, 0)
        self.assertEqual(self.cli("session", "resume", second).returncode, 0)

    def test_day_one_copied_from_another_study_is_not_followed(self):
        a, b = self.cwd / "a", self.cwd / "b"
        day1, day2 = self.days_study(a, "P01")
        self.days_study(b, "P02")  # study b has begun: it has its own identity
        shutil.rmtree(day2)
        copied = b / "P01" / day1.name
        shutil.copytree(day1, copied)
        before = digest_tree(b)
        out = self.cli("session", "run", self.fx.protocol2, "--subject", "P01", "--writer", "simulated",
                       "--out", b)
        self.refused(out, 1, "session.json", "/study_id")
        self.assertEqual(digest_tree(b), before)

    def test_sessions_copied_from_another_study_are_not_pooled_by_readers(self):
        a, b = self.cwd / "a", self.cwd / "b"
        days = self.days_study(a, "P01")
        self.days_study(b, "P02")
        for day in days:
            shutil.copytree(day, b / "P01" / day.name)
        (self.cwd / "tables").mkdir()
        out = self.cli("report", b, "--csv", self.cwd / "tables")
        self.refused(out, 1, "/study_id")
        self.assertEqual(list((self.cwd / "tables").iterdir()), [])
        if have_module():
            code = ("import sys, calligraphy, calligraphy.study as s\ntry:\n s.load(sys.argv[1])\n"
                    "except calligraphy.DataError as e:\n print(e); sys.exit(1)\n")
            out = self.python(code, b)
            self.assertEqual(out.returncode, 1, out.stderr)
            self.assertIn("/study_id", out.stdout.decode())

    def test_a_study_folder_made_before_study_ids_still_reads_and_goes_on(self):
        a = self.cwd / "a"
        day1, day2 = self.days_study(a, "P01")
        shutil.rmtree(day2)
        # as an earlier build wrote it: no identity file, no study_id in session.json
        identity = a / ".calligraphy-study.json"
        if identity.exists():
            identity.unlink()
        manifest = day1 / "session.json"
        doc = json.loads(manifest.read_text(encoding="utf-8"))
        doc.pop("study_id", None)
        manifest.write_text(json.dumps(doc, ensure_ascii=False, indent=2) + "\n", encoding="utf-8")
        out = self.cli("session", "run", self.fx.protocol2, "--subject", "P01", "--writer", "simulated",
                       "--out", a)
        self.assertEqual(out.returncode, 0, out.stderr)
        (self.cwd / "tables").mkdir()
        out = self.cli("report", a, "--csv", self.cwd / "tables")
        self.assertEqual(out.returncode, 0, out.stderr)

    def test_resume_of_a_partial_folder_names_it_half_made(self):
        study = self.study_copy()
        session = sorted(p.parent for p in study.rglob("session.json"))[0]
        partial = session.parent / f".partial.999999.host.{session.name}"
        session.rename(partial)
        line = self.refused(self.cli("session", "resume", partial), 1, ".partial.")
        self.assertIn("half", line)

    def test_run_with_out_naming_a_file_is_refused(self):
        f = self.cwd / "out"
        f.write_text("a file\n")
        out = self.cli("session", "run", self.fx.protocol, "--writer", "simulated", "--subjects", "1",
                       "--out", f)
        self.refused(out, 1, "out")
        self.assertEqual(f.read_text(), "a file\n")

    def test_run_into_a_tiny_tmpfs_is_refused_before_the_first_trial(self):
        small = self.mount_small_tmpfs("256k")
        out = self.cli("session", "run", self.fx.protocol, "--writer", "simulated", "--subjects", "1",
                       "--out", small / "s")
        self.refused(out, 1)
        self.assertFalse((small / "s").exists() and any((small / "s").rglob("*.json")))

    def test_plan_of_a_protocol_with_a_bom_reads(self):
        p = self.cwd / "p.json"
        p.write_bytes(b"\xef\xbb\xbf" + self.fx.protocol.read_bytes())
        out = self.cli("session", "plan", p, "--subjects", "2")
        self.assertEqual(out.returncode, 0, out.stderr)

    def test_plan_of_a_protocol_with_nan_names_file_and_pointer(self):
        doc = one_session_protocol("one")
        doc["trial"]["max_duration_s"] = 31.75
        p = self.cwd / "p.json"
        p.write_text(json.dumps(doc).replace("31.75", "1e999"))
        self.refused(self.cli("session", "plan", p, "--subjects", "1"), 2, "p.json", "/trial/max_duration_s")

    def test_plan_of_a_fifo_protocol_with_no_end_does_not_hang(self):
        fifo = self.cwd / "p.json"
        os.mkfifo(fifo)
        writer = subprocess.Popen(["sh", "-c", f"printf '{{' > '{fifo}'"])
        try:
            out = self.cli("session", "plan", fifo, "--subjects", "1", timeout=30)
        finally:
            writer.kill()
            writer.wait()
        self.assertEqual(out.returncode, 1, out.stderr)
        self.assertIn("p.json", out.stderr.decode())

    def test_resume_with_an_edited_protocol_copy_is_refused(self):
        study = self.study_copy()
        session = sorted(p.parent for p in study.rglob("session.json"))[0]
        sorted(session.glob("trials/*.json"))[-1].unlink()
        manifest = session / "session.json"
        doc = json.loads(manifest.read_text(encoding="utf-8"))
        text = json.dumps(doc, ensure_ascii=False)
        self.assertIn("max_duration_s", text)
        manifest.write_text(text.replace("\\\"max_duration_s\\\": 20", "\\\"max_duration_s\\\": 21")
                            .replace("\\\"max_duration_s\\\":20", "\\\"max_duration_s\\\":21"), encoding="utf-8")
        if manifest.read_text(encoding="utf-8") == text:
            self.skipTest("the protocol copy is not stored as text here")
        before = digest_tree(study)
        # what the session.json of the folder given holds: refused as a protocol's content is (exit 2)
        self.refused(self.cli("session", "resume", session), 2, "session.json", "/protocol/text")
        self.assertEqual(digest_tree(study), before)

    def test_resume_does_not_append_through_a_log_linked_outside(self):
        study = self.study_copy()
        session = sorted(p.parent for p in study.rglob("session.json"))[0]
        sorted(session.glob("trials/*.json"))[-1].unlink()
        outside = self.cwd / "outside.txt"
        outside.write_text("not a log\n")
        (session / "log.jsonl").unlink()
        os.symlink(outside, session / "log.jsonl")
        out = self.cli("session", "resume", session)
        self.assertEqual(outside.read_text(), "not a log\n", out.stderr)
        # a file of the session folder that is a link: refused by name, as the folder resume is given (exit 2)
        self.assertIn("symbolic link", self.refused(out, 2, "log.jsonl"))

    def test_resume_of_a_manifest_with_a_duplicated_key_is_refused(self):
        study = self.study_copy()
        session = sorted(p.parent for p in study.rglob("session.json"))[0]
        sorted(session.glob("trials/*.json"))[-1].unlink()
        manifest = session / "session.json"
        text = manifest.read_text(encoding="utf-8")
        doc = json.loads(text)
        pacing = json.dumps(doc["pacing"])
        other = json.dumps("real-time" if doc["pacing"] != "real-time" else "lock-step")
        manifest.write_text(text.replace(f'"pacing": {pacing}', f'"pacing": {pacing}, "pacing": {other}', 1),
                            encoding="utf-8")
        self.assertNotEqual(manifest.read_text(encoding="utf-8"), text)
        before = digest_tree(study)
        # the content of the session folder the command was given: refused as a protocol's is (exit 2)
        self.refused(self.cli("session", "resume", session), 2, "session.json", "/pacing")
        self.assertEqual(digest_tree(study), before)

    def test_resume_of_a_session_json_that_is_a_folder_is_named(self):
        study = self.study_copy()
        session = sorted(p.parent for p in study.rglob("session.json"))[0]
        (session / "session.json").unlink()
        (session / "session.json").mkdir()
        self.refused(self.cli("session", "resume", session), 1, "session.json")

    def test_killed_run_leaves_whole_folders_that_report_reads(self):
        out_dir = self.cwd / "s"
        p = subprocess.Popen([CLI, "session", "run", str(self.fx.protocol), "--writer", "simulated",
                              "--subjects", "3", "--out", str(out_dir)], cwd=self.cwd,
                             stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        time.sleep(0.4)
        p.send_signal(signal.SIGKILL)
        p.wait()
        (self.cwd / "tables").mkdir()
        out = self.cli("report", out_dir, "--csv", self.cwd / "tables")
        self.assertIn(out.returncode, (0, 1), out.stderr)
        if out.returncode == 1:  # no session folder yet, or one with a trial left to run
            self.assertNotIn("internal", out.stderr.decode())
        lock = out_dir / ".calligraphy-run.lock"
        if lock.exists():  # the lock file remains, the lock does not
            with open(lock) as f:
                fcntl.flock(f, fcntl.LOCK_EX | fcntl.LOCK_NB)

    @unittest.skipIf(SANITIZED, "an address-space limit does not go with the sanitizers")
    def test_report_of_a_sparse_gigabyte_record_is_refused_without_reading_it(self):
        study = self.study_copy()
        rec = self.first_record(study)
        with open(rec, "r+b") as f:
            f.truncate(1 << 30)

        def limit():
            resource.setrlimit(resource.RLIMIT_AS, (768 << 20, 768 << 20))
        (self.cwd / "tables").mkdir()
        out = self.cli("report", study, "--csv", self.cwd / "tables", timeout=60, preexec_fn=limit)
        self.refused(out, 1, rec.name)

    def test_resume_of_a_sparse_manifest_over_64_mib_names_its_size(self):
        study = self.study_copy()
        session = sorted(p.parent for p in study.rglob("session.json"))[0]
        with open(session / "session.json", "r+b") as f:
            f.truncate((64 << 20) + 1)
        self.refused(self.cli("session", "resume", session, timeout=60), 1, "session.json")

    @unittest.skipIf(SANITIZED, "an address-space limit does not go with the sanitizers")
    def test_plan_of_a_sparse_gigabyte_protocol_is_refused_without_reading_it(self):
        path = self.sparse("p.json", 1 << 30)

        def limit():
            resource.setrlimit(resource.RLIMIT_AS, (768 << 20, 768 << 20))
        self.refused(self.cli("session", "plan", path, "--subjects", "1", timeout=60, preexec_fn=limit), 1,
                     "p.json")

    def test_report_of_a_session_json_linked_to_another_sessions_is_refused(self):
        study = self.study_copy()
        first, second = sorted(p.parent for p in study.rglob("session.json"))[:2]
        (second / "session.json").unlink()
        os.symlink(first / "session.json", second / "session.json")
        (self.cwd / "tables").mkdir()
        out = self.cli("report", study, "--csv", self.cwd / "tables")
        self.assertEqual(out.returncode, 1, out.stderr)
        self.assertEqual(list((self.cwd / "tables").iterdir()), [])

    def test_study_load_of_a_record_with_a_duplicated_key_is_a_data_error(self):
        self.need_module()
        study = self.study_copy()
        rec = self.first_record(study)
        doc = json.loads(rec.read_text(encoding="utf-8"))
        text = json.dumps(doc)
        wall = json.dumps(doc["wall_time_s"])
        rec.write_text(text.replace(f'"wall_time_s": {wall}', f'"wall_time_s": {wall}, "wall_time_s": 99999', 1),
                       encoding="utf-8")
        code = ("import sys, calligraphy, calligraphy.study as s\ntry:\n s.load(sys.argv[1])\n"
                "except calligraphy.DataError as e:\n print(e); sys.exit(1)\n")
        out = self.python(code, study)
        self.assertEqual(out.returncode, 1, out.stderr)
        self.assertIn("/wall_time_s", out.stdout.decode())

    def test_study_report_of_a_record_with_1e999_is_one_line(self):
        self.need_module()
        study = self.study_copy()
        rec = self.first_record(study)
        doc = json.loads(rec.read_text(encoding="utf-8"))
        doc["wall_time_s"] = 4242.125
        rec.write_text(json.dumps(doc).replace("4242.125", "1e999"), encoding="utf-8")
        out = self.study_report(study, "--out", self.cwd / "paper")
        self.assertEqual(out.returncode, 1, out.stderr)
        self.assertIn(rec.name, out.stderr.decode())
        self.assertNotIn("Traceback", out.stderr.decode())
        self.assertFalse((self.cwd / "paper").exists() and any((self.cwd / "paper").rglob("*.html")))

    def test_study_report_out_onto_a_session_folder_file_through_a_hard_link_is_refused(self):
        self.need_module()
        study = self.study_copy()
        session = sorted(p.parent for p in study.rglob("session.json"))[0]
        paper = self.cwd / "paper"
        paper.mkdir()
        os.link(session / "session.json", paper / "index.html")
        before = digest_tree(study)
        out = self.study_report(study, "--out", paper)
        self.assertEqual(out.returncode, 2, out.stderr)
        self.assertEqual(digest_tree(study), before)

    def test_study_load_refuses_a_copied_session(self):
        self.need_module()
        study = self.study_copy()
        session = sorted(p.parent for p in study.rglob("session.json"))[0]
        shutil.copytree(session, self.cwd / "study" / "S99" / session.name)
        out = self.python("import sys, calligraphy.study as s\ntry:\n s.load(sys.argv[1])\nexcept Exception as e:"
                          "\n print(type(e).__name__, e); sys.exit(1)", study)
        self.assertEqual(out.returncode, 1, out.stderr)
        self.assertIn(session.name, out.stdout.decode())

    def test_study_samples_refuses_a_swapped_trace(self):
        self.need_module()
        study = self.study_copy()
        traces = sorted(study.rglob("trials/*.trace.h5"))
        shutil.copyfile(traces[1], traces[0])
        code = ("import sys, calligraphy, calligraphy.study as s\nst = s.load(sys.argv[1])\n"
                "row = st.trials[st.trials.trace_file.astype(str).str.endswith(sys.argv[2])].iloc[0]\n"
                "try:\n st.samples(row)\nexcept calligraphy.DataError as e:\n print('DataError', e); sys.exit(1)\n")
        out = self.python(code, study, traces[0].name)
        self.assertEqual(out.returncode, 1, out.stderr)
        self.assertIn(traces[0].name, out.stdout.decode())

    def test_study_samples_refuses_a_cut_trace(self):
        self.need_module()
        study = self.study_copy()
        t = sorted(study.rglob("trials/*.trace.h5"))[0]
        data = t.read_bytes()
        t.write_bytes(data[: len(data) - 50])
        code = ("import sys, calligraphy, calligraphy.study as s\nst = s.load(sys.argv[1])\n"
                "row = st.trials[st.trials.trace_file.astype(str).str.endswith(sys.argv[2])].iloc[0]\n"
                "try:\n st.samples(row)\nexcept calligraphy.DataError as e:\n print('DataError', e); sys.exit(1)\n")
        out = self.python(code, study, t.name)
        self.assertEqual(out.returncode, 1, out.stderr)
        self.assertIn(t.name, out.stdout.decode())

    def test_rerun_trial_of_a_record_with_1e999_names_the_pointer(self):
        self.need_module()
        doc = json.loads(self.record_text())
        doc["specification"]["trial"]["rate_hz"] = 12345.5
        path = self.spec_with(json.dumps(doc).replace("12345.5", "1e999"))
        code = ("import sys, calligraphy as cg\ntry:\n cg.rerun_trial(sys.argv[1])\n"
                "except cg.DataError as e:\n print(e); sys.exit(1)\n")
        out = self.python(code, path)
        self.assertEqual(out.returncode, 1, out.stderr)
        self.assertIn("/specification/trial/rate_hz", out.stdout.decode())

    def test_rerun_trial_of_a_cut_record_is_a_data_error(self):
        self.need_module()
        data = self.fx.record.read_bytes()
        path = self.spec_with(data[: len(data) // 2])
        code = ("import sys, calligraphy as cg\ntry:\n cg.rerun_trial(sys.argv[1])\n"
                "except cg.DataError as e:\n print(e); sys.exit(1)\n")
        out = self.python(code, path)
        self.assertEqual(out.returncode, 1, out.stderr)
        self.assertIn("r.json", out.stdout.decode())


def tearDownModule():
    if FIXTURE is not None:
        FIXTURE.tmp.cleanup()


if __name__ == "__main__":
    unittest.main(verbosity=2)
