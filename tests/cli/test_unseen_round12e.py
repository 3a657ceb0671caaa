#!/usr/bin/env python3
"""Hostile cases written from the documentation alone (docs/cli.md, docs/python.md and each command's
`--help`), in two mechanical sweeps. Run by CTest as `cli_unseen_round12e_tests`.

1. Every file a single-trial, model, corpus or bench command writes (`trial --json|--csv|--svg|--record`,
   `score --json`, `trace --csv`, `model --svg`, `strokes --markdown`, `corpus build --out`, `corpus
   fidelity|validate --markdown`, `corpus validate --features`, `bench ... --markdown`, `train --record|
   --screenshot|--quiz-screenshots|--session`, Python's `record_teacher`), and the commands that print only:
   the output is one of the command's inputs (same path spelled with `./` or `//`, a symbolic or a hard link),
   its folder missing or a regular file, a folder, a FIFO, a dangling link, a link loop or chain, or a link to
   a folder in its place, a closed standard output, a file-size limit, SIGTERM while it writes and two
   processes writing it at once. docs/cli.md, "Outputs" and "Checked before anything runs": an output that is
   an input is exit 2 before any work naming both; a folder that cannot take it is exit 1 naming the option
   and the path; a failed write is one line and exit 1, the earlier file intact and no temporary left.
2. Every number on the command line: the options taking a value are read from each command's `--help` (so an
   option added later is swept too) and given their documented bound and just past it, NaN, inf, -inf, -0,
   1e308, 0x10, " 1", "1 ", "", "1e" and a non-ASCII digit: exit 2 naming the option, or the value taken as
   documented. Each option gets its bounds and a rotating share of the other values (CPU time is tight);
   across the options of a command every value is tried.

CALLIGRAPHY_CLI names the program; CALLIGRAPHY_SOURCE_DIR the source tree (its hanzi-writer-data sample);
the built Python package is found on PYTHONPATH (its cases are skipped without it). CALLIGRAPHY_SANITIZED=1
takes a small subset.
"""
import json
import math
import os
import re
import resource
import shutil
import signal
import stat
import subprocess
import tempfile
import threading
import time
import unittest
from pathlib import Path

from outsider import CLI, ENV, SANITIZED, TIMEOUT_S, error_lines, run, sanitized_subset

SOURCE = Path(os.environ.get("CALLIGRAPHY_SOURCE_DIR", Path(__file__).resolve().parents[2]))
SAMPLE = SOURCE / "tests" / "data" / "hanzi-writer-sample"
SHI = "十"
YI = "一"

heavy = unittest.skipIf(SANITIZED, "several runs of the program: left to the Release run")

try:
    import calligraphy as cg
except ImportError:  # pragma: no cover - a build without the Python bindings
    cg = None


def run_closed_stdout(args, cwd):
    """Runs with standard output a pipe whose reading end is already closed: every write fails (EPIPE)."""
    read_end, write_end = os.pipe()
    os.close(read_end)
    try:
        return run(args, cwd, stdout=write_end)
    finally:
        os.close(write_end)


def run_file_limit(args, cwd, limit_bytes):
    def limit():
        resource.setrlimit(resource.RLIMIT_FSIZE, (limit_bytes, limit_bytes))
    return run(args, cwd, preexec_fn=limit)


def listing(folder):
    return sorted(p.name for p in Path(folder).iterdir())


PROTOCOL = {"name": "p12e", "conditions": [{"name": "h", "mode": "haptic"}],
            "test": {"characters": [SHI, YI], "conditions": ["h"], "repetitions": 1},
            "trial": {"max_duration_s": 20}}


class Shared:
    """One trial of 十 with every output, a second seed's outputs, a study of one subject (two traces), a data
    folder of three sample characters and its corpus store."""
    folder = None

    @classmethod
    def get(cls):
        if cls.folder is None:
            cls.folder = Path(tempfile.mkdtemp(prefix="unseen12e-"))
            f = cls.folder
            r = run(["trial", SHI, "--json", "a.json", "--csv", "a.csv", "--svg", "a.svg",
                     "--record", "teacher.json"], f)
            assert r.returncode == 0, r.stderr
            r = run(["trial", SHI, "--seed", "1", "--json", "b.json", "--csv", "b.csv"], f)
            assert r.returncode == 0, r.stderr
            (f / "p.json").write_text(json.dumps(PROTOCOL, ensure_ascii=False), encoding="utf-8")
            r = run(["session", "run", "p.json", "--subjects", "1", "--out", "study"], f)
            assert r.returncode == 0, r.stderr
            cls.traces = sorted((f / "study").glob("S01/*/trials/*.trace.h5"))
            assert len(cls.traces) == 2, cls.traces
            cls.trace_csv = []
            for t in cls.traces:
                r = run(["trace", t], f)
                assert r.returncode == 0, r.stderr
                cls.trace_csv.append(r.stdout)
            data = f / "data"
            data.mkdir()
            for name in (f"{YI}.json", "兀.json", "仇.json"):
                shutil.copy(SAMPLE / name, data / name)
            (f / "empty").mkdir()
            r = run(["corpus", "build", "--data", "data", "--out", "store.clg", "--threads", "1"], f)
            assert r.returncode == 0, r.stderr
        return cls.folder


def tearDownModule():
    if Shared.folder is not None:
        shutil.rmtree(Shared.folder, ignore_errors=True)


class Case(unittest.TestCase):
    def setUp(self):
        self.base = Shared.get()
        self.tmp = Path(tempfile.mkdtemp(prefix="case-", dir=self.base))

    def copy(self, name, as_name=None):
        target = self.tmp / (as_name or Path(name).name)
        shutil.copy(self.base / name, target)
        return target

    def refused_as_input(self, args, *names, cwd=None, unchanged=()):
        """Exit 2, one line naming each of `names`; the files of `unchanged` keep their bytes."""
        before = {p: Path(p).read_bytes() for p in unchanged}
        folder_before = listing(cwd or self.tmp)
        r = run(args, cwd or self.tmp)
        lines = error_lines(r)
        self.assertEqual(r.returncode, 2, (args, lines))
        self.assertEqual(len(lines), 1, lines)
        for n in names:
            self.assertIn(n, lines[0])
        for p, content in before.items():
            self.assertEqual(Path(p).read_bytes(), content, f"{p} was overwritten")
        self.assertEqual(listing(cwd or self.tmp), folder_before, "a refused command wrote a file")
        return lines[0]

    def failed_write(self, result, *names):
        lines = error_lines(result)
        self.assertEqual(result.returncode, 1, lines)
        self.assertGreaterEqual(len(lines), 1)
        text = "\n".join(lines)
        for n in names:
            self.assertIn(n, text)
        self.assertNotIn("Traceback", text)
        return lines


# ------------------------------------------------------------------------------------------------ outputs
@unittest.skipUnless(CLI, "CALLIGRAPHY_CLI not set")
class TrialOutputs(Case):
    """`trial --json|--csv|--svg|--record`."""

    def test_two_outputs_spelled_with_dot_and_double_slash_are_one_file(self):
        (self.tmp / "o").mkdir()
        line = self.refused_as_input(["trial", SHI, "--json", "./o//x.json", "--csv", "o/x.json"],
                                     "--json", "--csv")
        self.assertEqual(listing(self.tmp / "o"), [])
        self.assertIn("x.json", line)

    def test_output_hard_linked_to_the_spec_is_refused(self):
        spec = self.copy("a.json", "spec.json")
        os.link(spec, self.tmp / "hard.json")
        self.refused_as_input(["trial", "--spec", "spec.json", "--json", "hard.json"], "--json", "--spec",
                              unchanged=[spec])

    def test_record_through_a_link_to_the_teacher_is_refused(self):
        teacher = self.copy("teacher.json")
        os.symlink("teacher.json", self.tmp / "link.json")
        self.refused_as_input(["trial", SHI, "--guidance-mode", "replay", "--teacher", "teacher.json",
                               "--record", "link.json"], "--record", "--teacher", unchanged=[teacher])

    @heavy
    def test_output_into_the_data_folder_or_onto_the_store_is_refused(self):
        data = self.tmp / "data"
        shutil.copytree(self.base / "data", data)
        store = self.copy("store.clg")
        self.refused_as_input(["trial", YI, "--data", "data", "--svg", f"data/{YI}.json"], "--svg", "--data",
                              unchanged=[data / f"{YI}.json"])
        os.link(store, self.tmp / "store-link.clg")
        self.refused_as_input(["trial", YI, "--store", "store.clg", "--csv", "store-link.clg"], "--csv",
                              "--store", unchanged=[store])

    def test_missing_folder_is_found_before_the_trial(self):
        r = run(["trial", SHI, "--json", "ok.json", "--csv", "nowhere/x.csv"], self.tmp)
        self.failed_write(r, "--csv", "nowhere")
        self.assertEqual(listing(self.tmp), [], "a refused trial wrote its other output")

    @heavy
    def test_regular_file_in_place_of_its_folder(self):
        (self.tmp / "plain").write_text("not a folder\n")
        r = run(["trial", SHI, "--svg", "plain/x.svg", "--json", "ok.json"], self.tmp)
        self.failed_write(r, "--svg", "plain")
        self.assertEqual(listing(self.tmp), ["plain"])
        self.assertEqual((self.tmp / "plain").read_text(), "not a folder\n")

    def test_folder_or_link_to_a_folder_in_its_place(self):
        (self.tmp / "d").mkdir()
        (self.tmp / "d" / "keep").write_text("k")
        os.symlink("d", self.tmp / "ld")
        for target in ("d", "ld", "d/"):
            with self.subTest(target=target):
                r = run(["trial", SHI, "--json", target], self.tmp)
                self.failed_write(r, "--json", target.rstrip("/"))
                self.assertEqual(listing(self.tmp / "d"), ["keep"])
                self.assertTrue((self.tmp / "ld").is_symlink())

    def test_dangling_link_creates_the_file_it_names(self):
        (self.tmp / "made").mkdir()
        os.symlink("made/target.json", self.tmp / "link.json")
        r = run(["trial", SHI, "--json", "link.json"], self.tmp)
        self.assertEqual(r.returncode, 0, error_lines(r))
        self.assertTrue((self.tmp / "link.json").is_symlink())
        self.assertEqual(os.readlink(self.tmp / "link.json"), "made/target.json")
        self.assertEqual(json.loads((self.tmp / "made" / "target.json").read_text())["character"], SHI)
        self.assertEqual(listing(self.tmp / "made"), ["target.json"])

    @heavy
    def test_fifo_is_written_in_place(self):
        fifo = self.tmp / "pipe.csv"
        os.mkfifo(fifo)
        got = []
        reader = threading.Thread(target=lambda: got.append(fifo.read_bytes()))
        reader.start()
        r = run(["trial", SHI, "--csv", "pipe.csv"], self.tmp)
        reader.join(TIMEOUT_S)
        self.assertEqual(r.returncode, 0, error_lines(r))
        self.assertTrue(stat.S_ISFIFO(os.lstat(fifo).st_mode), "the FIFO was replaced")
        self.assertEqual(got, [(self.base / "a.csv").read_bytes()])
        self.assertEqual(listing(self.tmp), ["pipe.csv"])

    def test_json_to_a_closed_standard_output_after_the_files(self):
        r = run_closed_stdout(["trial", SHI, "--json", "-", "--csv", "c.csv"], self.tmp)
        lines = self.failed_write(r)
        self.assertEqual(len(lines), 1, lines)
        self.assertIn("standard output", lines[0])
        self.assertEqual((self.tmp / "c.csv").read_bytes(), (self.base / "a.csv").read_bytes())

    def test_file_size_limit_keeps_the_earlier_file_and_writes_the_others(self):
        (self.tmp / "c.csv").write_text("earlier\n")
        r = run_file_limit(["trial", SHI, "--csv", "c.csv", "--json", "j.json"], self.tmp, 64 * 1024)
        self.failed_write(r, "c.csv")
        self.assertEqual((self.tmp / "c.csv").read_text(), "earlier\n")
        self.assertEqual((self.tmp / "j.json").read_bytes(), (self.base / "a.json").read_bytes())
        self.assertEqual(listing(self.tmp), ["c.csv", "j.json"], "a temporary was left")

    def test_record_of_an_unfinished_trial_keeps_the_earlier_file(self):
        (self.tmp / "t.json").write_text("earlier\n")
        r = run(["trial", SHI, "--max-duration", "0.5", "--record", "t.json", "--json", "j.json"], self.tmp)
        lines = self.failed_write(r, "--record", "t.json")
        self.assertEqual((self.tmp / "t.json").read_text(), "earlier\n")
        self.assertEqual(json.loads((self.tmp / "j.json").read_text())["end_reason"], "time_limit")
        self.assertEqual(listing(self.tmp), ["j.json", "t.json"])

    @heavy
    def test_sigterm_twice_keeps_every_output_whole(self):
        (self.tmp / "j.json").write_text("{}\n")
        p = subprocess.Popen([CLI, "trial", SHI, "--pacing", "real-time", "--json", "j.json", "--csv", "c.csv"],
                             cwd=self.tmp, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, env=ENV)
        time.sleep(0.4)
        p.send_signal(signal.SIGTERM)
        time.sleep(0.002)
        p.send_signal(signal.SIGTERM)
        _, err = p.communicate(timeout=TIMEOUT_S)
        self.assertEqual(p.returncode, 143, err)
        record = json.loads((self.tmp / "j.json").read_text())
        self.assertEqual(record["end_reason"], "interrupted")
        self.assertIn("SIGTERM", record["abort_reason"])
        rows = (self.tmp / "c.csv").read_text().splitlines()
        self.assertGreater(len(rows), 1)
        self.assertEqual({len(row.split(",")) for row in rows}, {12})
        self.assertEqual(listing(self.tmp), ["c.csv", "j.json"], "a temporary was left")

    @heavy
    def test_two_trials_writing_the_same_outputs_leave_one_whole_file_each(self):
        refs = {name: (self.base / name).read_bytes() for name in ("a.json", "a.csv", "b.json", "b.csv")}
        for _ in range(2):
            procs = [subprocess.Popen([CLI, "trial", SHI, "--seed", seed, "--json", "same.json", "--csv",
                                       "same.csv"], cwd=self.tmp, stdout=subprocess.DEVNULL,
                                      stderr=subprocess.PIPE, env=ENV) for seed in ("0", "1")]
            for p in procs:
                p.communicate(timeout=TIMEOUT_S)
                self.assertEqual(p.returncode, 0)
            self.assertIn((self.tmp / "same.json").read_bytes(), (refs["a.json"], refs["b.json"]))
            self.assertIn((self.tmp / "same.csv").read_bytes(), (refs["a.csv"], refs["b.csv"]))
            self.assertEqual(listing(self.tmp), ["same.csv", "same.json"])

    @heavy
    def test_huge_stiffness_is_refused_or_stays_finite(self):
        r = run(["trial", SHI, "--guidance-stiffness", "1e308", "--json", "j.json"], self.tmp)
        self.assertIn(r.returncode, (0, 1, 2), error_lines(r))
        if r.returncode == 2:
            self.assertIn("--guidance-stiffness", error_lines(r)[0])
            return
        record = json.loads((self.tmp / "j.json").read_text())
        for key in ("max_force_n", "max_force_step_n", "mean_deviation_m", "trial_time_s"):
            self.assertIsNotNone(record[key], key)
            self.assertTrue(math.isfinite(record[key]), key)


@unittest.skipUnless(CLI, "CALLIGRAPHY_CLI not set")
class SingleFileOutputs(Case):
    """`score --json`, `trace --csv`, `model --svg`, `strokes --markdown`."""

    def test_score_json_onto_its_trace(self):
        trace = self.copy("a.csv", "t.csv")
        os.symlink("t.csv", self.tmp / "l.csv")
        for out in ("./t.csv", "l.csv", ".//t.csv"):
            with self.subTest(out=out):
                self.refused_as_input(["score", "t.csv", "--character", SHI, "--json", out], "--json",
                                      unchanged=[trace])

    def test_score_json_closed_stdout_and_missing_folder(self):
        self.copy("a.csv", "t.csv")
        r = run_closed_stdout(["score", "t.csv", "--character", SHI, "--json", "-"], self.tmp)
        self.assertEqual(len(self.failed_write(r, "standard output")), 1)
        r = run(["score", "t.csv", "--character", SHI, "--json", "none/s.json"], self.tmp)
        self.failed_write(r, "--json", "none")
        self.assertEqual(listing(self.tmp), ["t.csv"])

    def test_score_json_through_a_link_loop_or_a_chain_past_40(self):
        self.copy("a.csv", "t.csv")
        os.symlink("loop-b", self.tmp / "loop-a")
        os.symlink("loop-a", self.tmp / "loop-b")
        for i in range(41):
            os.symlink(f"c{i + 1}", self.tmp / f"c{i}")
        before = listing(self.tmp)
        for out in ("loop-a", "c0"):
            with self.subTest(out=out):
                r = run(["score", "t.csv", "--character", SHI, "--json", out], self.tmp)
                lines = error_lines(r)
                self.assertIn(r.returncode, (1, 2), lines)
                self.assertEqual(len(lines), 1, lines)
                self.assertIn(out, lines[0])
                self.assertEqual(listing(self.tmp), before)
        # 40 links are followed: the file the last names is made, every link kept
        r = run(["score", "t.csv", "--character", SHI, "--json", "c1"], self.tmp)
        self.assertEqual(r.returncode, 0, error_lines(r))
        self.assertTrue(json.loads((self.tmp / "c41").read_text()))
        self.assertTrue(all((self.tmp / f"c{i}").is_symlink() for i in range(41)))

    def test_trace_csv_onto_its_trace(self):
        trace = self.tmp / "t.trace.h5"
        shutil.copy(Shared.traces[0], trace)
        os.link(trace, self.tmp / "hard.csv")
        for out in ("./t.trace.h5", "hard.csv"):
            with self.subTest(out=out):
                self.refused_as_input(["trace", "t.trace.h5", "--csv", out], "--csv", unchanged=[trace])

    def test_trace_into_a_closed_pipe(self):
        for extra in ([], ["--csv", "-"]):
            with self.subTest(extra=extra):
                r = run_closed_stdout(["trace", Shared.traces[0], *extra], self.tmp)
                self.assertEqual(len(self.failed_write(r)), 1)

    def test_trace_over_the_file_size_limit_keeps_the_earlier_csv(self):
        (self.tmp / "t.csv").write_text("earlier\n")
        r = run_file_limit(["trace", Shared.traces[0], "--csv", "t.csv"], self.tmp, 100 * 1024)
        self.assertEqual(len(self.failed_write(r, "t.csv")), 1)
        self.assertEqual((self.tmp / "t.csv").read_text(), "earlier\n")
        self.assertEqual(listing(self.tmp), ["t.csv"], "a temporary was left")

    @heavy
    def test_trace_killed_while_it_writes_leaves_the_earlier_or_the_new_file(self):
        earlier = b"earlier\n"
        new = Shared.trace_csv[0]
        for i in range(8):
            (self.tmp / "t.csv").write_bytes(earlier)
            p = subprocess.Popen([CLI, "trace", str(Shared.traces[0]), "--csv", "t.csv"], cwd=self.tmp,
                                 stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, env=ENV)
            time.sleep(0.004 * i)
            p.send_signal(signal.SIGINT if i % 2 else signal.SIGTERM)
            _, err = p.communicate(timeout=TIMEOUT_S)
            with self.subTest(delay_ms=4 * i):
                self.assertIn(p.returncode, (0, 130, 143, -2, -15), err)
                self.assertIn((self.tmp / "t.csv").read_bytes(), (earlier, new))
                self.assertEqual(listing(self.tmp), ["t.csv"], "a temporary was left")

    @heavy
    def test_two_traces_written_to_one_csv_at_once(self):
        for _ in range(3):
            procs = [subprocess.Popen([CLI, "trace", str(t), "--csv", "same.csv"], cwd=self.tmp,
                                      stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, env=ENV)
                     for t in Shared.traces]
            for p in procs:
                p.communicate(timeout=TIMEOUT_S)
                self.assertEqual(p.returncode, 0)
            self.assertIn((self.tmp / "same.csv").read_bytes(), Shared.trace_csv)
            self.assertEqual(listing(self.tmp), ["same.csv"])

    def test_model_svg_onto_its_store_or_its_data(self):
        store = self.copy("store.clg")
        os.link(store, self.tmp / "hard.svg")
        self.refused_as_input(["model", YI, "--store", "store.clg", "--svg", "hard.svg"], "--svg", "--store",
                              unchanged=[store])
        data = self.tmp / "data"
        shutil.copytree(self.base / "data", data)
        self.refused_as_input(["model", YI, "--data", "data", "--svg", f"./data//{YI}.json"], "--svg",
                              unchanged=[data / f"{YI}.json"])

    def test_model_svg_closed_pipe_and_link_to_a_folder(self):
        r = run_closed_stdout(["model", SHI, "--svg", "-"], self.tmp)
        self.assertEqual(len(self.failed_write(r)), 1)
        (self.tmp / "d").mkdir()
        os.symlink("d", self.tmp / "ld.svg")
        r = run(["model", SHI, "--svg", "ld.svg"], self.tmp)
        self.failed_write(r, "--svg", "ld.svg")
        self.assertEqual(listing(self.tmp / "d"), [])

    def test_strokes_markdown_through_a_link_keeps_the_link_and_the_mode(self):
        target = self.tmp / "table.md"
        target.write_text("earlier\n")
        os.chmod(target, 0o640)
        os.symlink("table.md", self.tmp / "link.md")
        r = run(["strokes", "--markdown", "link.md"], self.tmp)
        self.assertEqual(r.returncode, 0, error_lines(r))
        self.assertEqual(r.stdout, b"", "the table was printed as well as written")
        self.assertTrue((self.tmp / "link.md").is_symlink())
        self.assertEqual(stat.S_IMODE(os.lstat(target).st_mode), 0o640)
        text = target.read_text()
        self.assertTrue(text.startswith("|") or "|" in text.splitlines()[0] or "| " in text, text[:200])
        self.assertEqual(sum(1 for line in text.splitlines() if re.match(r"\|\s*\d+\s*\|", line)), 39)
        self.assertEqual(listing(self.tmp), ["link.md", "table.md"])

    def test_strokes_markdown_over_the_file_size_limit(self):
        (self.tmp / "t.md").write_text("earlier\n")
        r = run_file_limit(["strokes", "--markdown", "t.md"], self.tmp, 512)
        self.assertEqual(len(self.failed_write(r, "t.md")), 1)
        self.assertEqual((self.tmp / "t.md").read_text(), "earlier\n")
        self.assertEqual(listing(self.tmp), ["t.md"])

    def test_printers_into_a_closed_pipe(self):
        study = self.base / "study"
        for args in (["schema", "record"], ["schema", "specification", "--markdown"], ["characters"],
                     ["devices", "--json"], ["strokes", "--json"], ["model", SHI, "--json"],
                     ["corpus", "stats", self.base / "store.clg"],
                     ["curriculum", study, "--subject", "S01", "--from", "人大"]):
            with self.subTest(command=" ".join(map(str, args[:2]))):
                r = run_closed_stdout(args, self.tmp)
                lines = self.failed_write(r)
                self.assertEqual(len(lines), 1, lines)
        self.assertEqual(listing(self.tmp), [])


@unittest.skipUnless(CLI, "CALLIGRAPHY_CLI not set")
class OutputNames(Case):
    """Names an output may be given: the longest a file system takes, empty, a folder's spelling, a device, and
    a dangling link naming another output."""

    def test_longest_file_name_is_written(self):
        # NAME_MAX is 255 bytes: the file system takes the name, so the command must too (its temporary as well)
        ascii_name = "a" * 251 + ".csv"
        utf8_name = "b" * 207 + "永" * 15 + ".md"  # 255 bytes, multi-byte characters where a shorter cut falls
        self.assertEqual(len(utf8_name.encode()), 255)
        r = run(["trial", SHI, "--csv", ascii_name], self.tmp)
        self.assertEqual(r.returncode, 0, error_lines(r))
        self.assertEqual((self.tmp / ascii_name).read_bytes(), (self.base / "a.csv").read_bytes())
        for _ in range(2):  # created, then replaced
            r = run(["strokes", "--markdown", utf8_name], self.tmp)
            self.assertEqual(r.returncode, 0, error_lines(r))
        self.assertIn("|", (self.tmp / utf8_name).read_text())
        self.assertEqual(listing(self.tmp), sorted([ascii_name, utf8_name]), "a temporary was left")

    def test_empty_or_folder_spelled_output_names(self):
        self.copy("a.csv", "t.csv")
        store = self.copy("store.clg")
        commands = {"--json": ["trial", SHI], "--csv": ["trace", Shared.traces[0]], "--svg": ["model", SHI],
                    "--markdown": ["strokes"], "--record": ["trial", SHI],
                    "--out": ["corpus", "build", "--data", self.base / "data"]}
        for option, command in commands.items():
            for value in ("", "new.out/"):
                with self.subTest(option=option, value=value):
                    r = run([*command, option, value], self.tmp)
                    lines = error_lines(r)
                    self.assertEqual(r.returncode, 2 if value == "" else 1, lines)
                    self.assertEqual(len(lines), 1, lines)
                    self.assertIn(option, lines[0])
                    self.assertEqual(listing(self.tmp), ["store.clg", "t.csv"])
        self.assertEqual(store.read_bytes(), (self.base / "store.clg").read_bytes())

    def test_a_dangling_link_naming_another_output_is_that_output(self):
        (self.tmp / "made").mkdir()
        os.symlink("made/t.json", self.tmp / "link.json")
        os.symlink("link.json", self.tmp / "link2.json")
        self.refused_as_input(["trial", SHI, "--json", "link2.json", "--csv", "made/t.json"], "--json", "--csv")
        self.assertEqual(listing(self.tmp / "made"), [])

    def test_devices_written_in_place(self):
        r = run(["trial", SHI, "--json", "/dev/null", "--csv", "/dev/null", "--svg", "/dev/null"], self.tmp)
        self.assertEqual(r.returncode, 0, error_lines(r))
        for args in (["strokes", "--markdown", "/dev/full"], ["score", self.base / "a.csv", "--character", SHI,
                                                              "--json", "/dev/full"]):
            with self.subTest(args=args[:1]):
                r = run(args, self.tmp)
                self.assertEqual(len(self.failed_write(r, "/dev/full")), 1)
        with open("/dev/full", "wb") as full:
            for args in (["schema", "protocol"], ["devices"], ["characters", "--strokes", "2"]):
                with self.subTest(args=args[:1], stdout="/dev/full"):
                    r = run(args, self.tmp, stdout=full)
                    self.assertEqual(len(self.failed_write(r)), 1)
        self.assertEqual(listing(self.tmp), [])


@unittest.skipUnless(CLI, "CALLIGRAPHY_CLI not set")
class CorpusBenchTrainOutputs(Case):
    """`corpus build --out`, `corpus fidelity|validate --markdown`, `--features`, `bench ... --markdown`,
    `train --record|--screenshot|--quiz-screenshots|--session`."""

    def test_corpus_build_out_into_its_data_or_to_standard_output(self):
        data = self.tmp / "data"
        shutil.copytree(self.base / "data", data)
        self.refused_as_input(["corpus", "build", "--data", "data", "--out", f"data/{YI}.json"], "--out",
                              unchanged=[data / f"{YI}.json"])
        self.refused_as_input(["corpus", "build", "--data", "data", "--out", "-"], "--out")
        r = run(["corpus", "build", "--data", "data", "--out", "data"], self.tmp)
        self.failed_write(r, "--out")
        self.assertEqual(listing(data), listing(self.base / "data"))

    @heavy
    def test_corpus_build_over_the_file_size_limit_keeps_the_earlier_store(self):
        store = self.copy("store.clg")
        before = store.read_bytes()
        r = run_file_limit(["corpus", "build", "--data", self.base / "data", "--out", "store.clg",
                            "--tolerance", "2", "--threads", "1"], self.tmp, 64)
        self.failed_write(r, "store.clg")
        self.assertEqual(store.read_bytes(), before)
        self.assertEqual(listing(self.tmp), ["store.clg"])

    @heavy
    def test_corpus_build_two_writers_at_once_leave_one_whole_store(self):
        data = self.base / "data"
        refs = []
        for medians in ("on", "off"):
            r = run(["corpus", "build", "--data", data, "--out", f"ref-{medians}.clg", "--medians", medians,
                     "--threads", "1"], self.tmp)
            self.assertEqual(r.returncode, 0, error_lines(r))
            refs.append((self.tmp / f"ref-{medians}.clg").read_bytes())
        self.assertNotEqual(refs[0], refs[1])
        for _ in range(3):
            procs = [subprocess.Popen([CLI, "corpus", "build", "--data", str(data), "--out", "same.clg", "--medians",
                                       medians, "--threads", "1"], cwd=self.tmp, stdout=subprocess.DEVNULL,
                                      stderr=subprocess.PIPE, env=ENV) for medians in ("on", "off")]
            for p in procs:
                p.communicate(timeout=TIMEOUT_S)
                self.assertEqual(p.returncode, 0)
            self.assertIn((self.tmp / "same.clg").read_bytes(), refs)
            self.assertEqual(listing(self.tmp), ["ref-off.clg", "ref-on.clg", "same.clg"])

    def test_corpus_validate_outputs_onto_the_cnchar_file_or_each_other(self):
        cnchar = self.tmp / "cnchar.order.min.js"
        cnchar.write_text("/* not cnchar */\n")
        self.refused_as_input(["corpus", "validate", "--cnchar", cnchar.name, "--markdown", f"./{cnchar.name}"],
                              "--markdown", "--cnchar", unchanged=[cnchar])
        os.link(cnchar, self.tmp / "hard.csv")
        self.refused_as_input(["corpus", "validate", "--cnchar", cnchar.name, "--features", "hard.csv"],
                              "--features", unchanged=[cnchar])
        self.refused_as_input(["corpus", "validate", "--cnchar", cnchar.name, "--markdown", "m.md",
                               "--features", "m.md"], "--markdown", "--features")
        self.refused_as_input(["corpus", "validate", "--cnchar", cnchar.name, "--features", "-"], "--features")

    def test_corpus_fidelity_markdown_checked_before_the_fits(self):
        r = run(["corpus", "fidelity", "--data", self.base / "data", "--markdown", "none/f.md"], self.tmp)
        self.failed_write(r, "--markdown", "none")
        self.assertEqual(r.stdout, b"", "the table was made before the output was checked")
        data = self.tmp / "data"
        shutil.copytree(self.base / "data", data)
        self.refused_as_input(["corpus", "fidelity", "--data", "data", "--markdown", f"data/{YI}.json"],
                              "--markdown", unchanged=[data / f"{YI}.json"])

    def test_bench_markdown_checked_before_the_measurement(self):
        data = self.tmp / "data"
        shutil.copytree(self.base / "data", data)
        self.refused_as_input(["bench", "acceptance", "--data", "data", "--markdown", f"data/{YI}.json"],
                              "--markdown", unchanged=[data / f"{YI}.json"])
        (self.tmp / "d").mkdir()
        os.symlink("d", self.tmp / "ld.md")
        for args in (["bench", "nearest", "--markdown", "d"], ["bench", "jumps", "--markdown", "ld.md"],
                     ["bench", "acceptance", "--markdown", "none/x.md"]):
            with self.subTest(args=args):
                started = time.monotonic()
                r = run(args, self.tmp, timeout=20)
                self.failed_write(r, "--markdown")
                self.assertEqual(r.stdout, b"", "measured before the output was checked")
                self.assertLess(time.monotonic() - started, 15)
        self.assertEqual(listing(self.tmp / "d"), [])

    def test_train_record_onto_its_teacher(self):
        teacher = self.copy("teacher.json")
        self.refused_as_input(["train", SHI, "--guidance-mode", "replay", "--teacher", "teacher.json",
                               "--record", "./teacher.json"], "--record", "--teacher", unchanged=[teacher])
        os.symlink("teacher.json", self.tmp / "l.png")
        self.refused_as_input(["train", SHI, "--guidance-mode", "replay", "--teacher", "teacher.json",
                               "--screenshot", "l.png"], "--screenshot", "--teacher", unchanged=[teacher])

    def test_train_output_folders_checked_before_the_window(self):
        (self.tmp / "plain").write_text("x")
        for args, option in ((["--screenshot", "none/x.png"], "--screenshot"),
                             (["--quiz", "--quiz-screenshots", "plain"], "--quiz-screenshots"),
                             (["--session", "plain"], "--session"),
                             (["--record", "plain/r.json"], "--record")):
            with self.subTest(option=option):
                r = run(["train", SHI, *args], self.tmp)
                lines = self.failed_write(r, option)
                self.assertNotIn("window", lines[0])
        self.assertEqual(listing(self.tmp), ["plain"])


@unittest.skipUnless(cg is not None, "the Python bindings are not on PYTHONPATH")
class PythonTeacher(unittest.TestCase):
    """`calligraphy.record_teacher(result, path)`, written atomically (docs/python.md)."""

    @classmethod
    def setUpClass(cls):
        cls.result = cg.simulate_trial(SHI, writer="skilled")

    def setUp(self):
        self.tmp = Path(tempfile.mkdtemp(prefix="unseen12e-py-"))
        self.addCleanup(shutil.rmtree, self.tmp, True)

    def test_missing_folder_or_a_folder_in_its_place_raises_naming_it(self):
        (self.tmp / "d").mkdir()
        for name in ("none/t.json", "d"):
            with self.subTest(path=name):
                with self.assertRaises(Exception) as caught:
                    cg.record_teacher(self.result, str(self.tmp / name))
                self.assertIn(name.split("/")[0], str(caught.exception))
                self.assertNotIsInstance(caught.exception, (TypeError, SystemError))
        self.assertEqual(listing(self.tmp), ["d"])
        self.assertEqual(listing(self.tmp / "d"), [])

    def test_nul_in_the_path_and_the_longest_name(self):
        with self.assertRaises(Exception) as caught:
            cg.record_teacher(self.result, str(self.tmp / "a\0b.json"))
        self.assertNotIsInstance(caught.exception, (TypeError, SystemError))
        self.assertEqual(listing(self.tmp), [])
        longest = self.tmp / ("t" * 250 + ".json")
        cg.record_teacher(self.result, str(longest))
        self.assertEqual(listing(self.tmp), [longest.name])
        self.assertEqual(cg.TeacherRecording.load(str(longest)).characters, SHI)

    def test_teacher_save_to_a_folder_or_a_missing_one_raises_naming_it(self):
        teacher = cg.record_teacher(self.result, str(self.tmp / "t.json"))
        (self.tmp / "d").mkdir()
        for name in ("d", "none/t.json"):
            with self.subTest(path=name):
                with self.assertRaises(cg.Error) as caught:
                    teacher.save(str(self.tmp / name))
                self.assertIn(name, str(caught.exception))
        self.assertEqual(listing(self.tmp), ["d", "t.json"])
        self.assertEqual(listing(self.tmp / "d"), [])

    def test_through_a_dangling_link(self):
        (self.tmp / "made").mkdir()
        os.symlink("made/t.json", self.tmp / "link.json")
        cg.record_teacher(self.result, str(self.tmp / "link.json"))
        self.assertTrue((self.tmp / "link.json").is_symlink())
        self.assertEqual(listing(self.tmp / "made"), ["t.json"])
        teacher = cg.TeacherRecording.load(str(self.tmp / "made" / "t.json"))
        r = cg.simulate_trial(SHI, writer="novice", teacher=teacher)
        self.assertEqual(r.metrics["guidance_mode"], "replay")


# ------------------------------------------------------------------------------------------------ numbers
NUMERIC_PLACEHOLDERS = {"N", "N/M", "G", "M", "M/S", "HZ", "MS", "S", "X", "UNITS", "SECONDS", "P", "MM"}
GENERIC = ["nan", "inf", "-inf", "1e308", "0x10", " 1", "1 ", "", "1e", "\u0663", "-0"]
ROTATE = 2  # generic values per option at least, rotating through GENERIC so that each command tries them all

# Bounds docs/cli.md gives where `--help` states none: (lower, lower included, upper, upper included, integer)
DOC_BOUNDS = {
    ("train", "--guidance-gain"): (0, True, 1, True, False),
    ("train", "--seed"): (0, True, 2 ** 64 - 1, True, True),
    ("train", "--hint-after-misses"): (0, True, 1000, True, True),
    ("train", "--assist-after-misses"): (0, True, 1000, True, True),
    ("train", "--exit-after"): (0, False, 86400, True, False),
    ("train", "--watchdog-ms"): (0, True, 60000, True, True),
    ("characters", "--strokes"): (1, True, 255, True, True),
    ("curriculum", "--count"): (1, True, 1000, True, True),
    ("corpus build", "--tolerance"): (0, False, None, False, False),
    ("corpus build", "--threads"): (1, True, 256, True, True),
    ("corpus fidelity", "--threads"): (1, True, 256, True, True),
    ("corpus validate", "--threads"): (1, True, 64, True, True),
    ("bench nearest", "--queries"): (1, True, 10 ** 8, True, True),
    ("bench nearest", "--seed"): (0, True, 2 ** 64 - 1, True, True),
    ("bench jumps", "--seeds"): (1, True, 10 ** 6, True, True),
    ("bench tick", "--passes"): (1, True, 1000, True, True),
    ("bench tick", "--rate"): (100, True, 100000, True, False),
    ("bench loop", "--rate"): (100, True, 10000, True, False),
    ("bench loop", "--seconds"): (0, False, 86400, True, False),
    ("bench loop", "--priority"): (0, True, 99, True, True),
    ("bench loop", "--cpu"): (-1, True, 1023, True, True),
    ("bench loop", "--watchdog-periods"): (0, True, 10 ** 6, True, True),
    ("bench acceptance", "--assist-after-misses"): (0, True, 1000, True, True),
    ("bench acceptance", "--form-tolerance-mm"): (0, False, 60, True, False),
    ("bench acceptance", "--characters"): (1, True, 100000, True, True),
    ("bench acceptance", "--seed"): (0, True, 2 ** 64 - 1, True, True),
}


HELP = {}


def help_of(command):
    """The run of `command --help`, made once for every case that reads it."""
    if command not in HELP:
        HELP[command] = run([*command.split(), "--help"], ".")
    return HELP[command]


def numeric_options(command):
    """(option, placeholder, help text) of each option of `command` whose value is a number."""
    r = help_of(command)
    assert r.returncode == 0, r.stderr
    options, current = [], None
    for line in r.stdout.decode().splitlines():
        m = re.match(r"^  (--[\w-]+)(?: (\S+))?\s*(.*)$", line)
        if m:
            current = [m.group(1), m.group(2) or "", m.group(3)]
            options.append(current)
        elif current and line.startswith("       "):
            current[2] += " " + line.strip()
        else:
            current = None
    return [tuple(o) for o in options
            if o[1] in NUMERIC_PLACEHOLDERS or re.fullmatch(r"\d+(\|\d+)+", o[1])]


def help_bounds(text):
    """Bounds the help text gives: 'in [a, b] unit', 'in (a, b)', '>= a', 'a..b'."""
    m = re.search(r"in ([\[(])([-\d.e]+), ([-\d.e]+)([\])])", text)
    if m:
        return (float(m.group(2)), m.group(1) == "[", float(m.group(3)), m.group(4) == "]", False)
    m = re.search(r"(-?\d+)\.\.(\d+)", text)
    if m:
        return (int(m.group(1)), True, int(m.group(2)), True, True)
    m = re.search(r">= ([-\d.e]+)", text)
    if m:
        return (float(m.group(1)), True, None, False, False)
    return None


def past(bound, upper, integer):
    if integer:
        return str(bound + 1 if upper else bound - 1)
    if bound == 0:
        return "-1e-9" if not upper else "1e-9"
    return repr(bound * (1 + 1e-9) if upper else bound * (1 - 1e-9))


def expectations(option, placeholder, text, command):
    """[(value, must be refused)] for one option; `None` for a value whose acceptance is not checked."""
    steps = re.fullmatch(r"\d+(\|\d+)+", placeholder)
    bounds = DOC_BOUNDS.get((command, option)) or help_bounds(text)
    integer = bool(steps) or placeholder in ("N", "P") or (bounds is not None and bounds[4])
    cases = []
    if steps:
        allowed = [int(v) for v in placeholder.split("|")]
        cases += [(str(allowed[-1] * 2), True), ("3", True), ("0", True), (str(allowed[-1]), False)]
    elif bounds:
        lo, lo_in, hi, hi_in, _ = bounds
        lo_v = int(lo) if integer else lo
        cases.append((str(lo_v), not lo_in))
        cases.append((past(lo_v, False, integer), True) if lo_in else (past(lo_v, True, integer), False))
        if hi is not None:
            hi_v = int(hi) if integer else hi
            cases.append((str(hi_v) if integer else repr(hi_v), not hi_in))
            cases.append((past(hi_v, True, integer), True))
    for value in GENERIC:
        if value == "1e308":
            refused = integer or (bounds is not None and bounds[2] is not None)
            cases.append((value, True if refused else None))
        elif value == "-0":
            if integer:
                refused = bounds is None or bounds[0] >= 0
            else:
                refused = bounds is not None and bounds[0] == 0 and not bounds[1]
                refused = True if refused else None
            cases.append((value, refused))
        else:
            cases.append((value, True))
    return cases, bool(bounds or steps)


# The guidance mode an option of that mode needs (another mode with it is a contradiction)
MODE_OF = {"--guidance-gain": ["--guidance-mode", "fading"],
           "--assist-band": ["--guidance-mode", "assist-as-needed"],
           "--amplification-gain": ["--guidance-mode", "error-amplification"],
           "--timing-speed": ["--guidance-mode", "timing"]}
# What else an option's documented bound needs: the watchdog is real-time pacing's, and a trial is at most
# 10^7 servo ticks (max_duration_s x rate_hz), so each of the two is taken to its bound with the other low.
TRIAL_COMPANION = {"--watchdog-ms": ["--pacing", "real-time"], "--rate": ["--max-duration", "1"],
                   "--max-duration": ["--rate", "100"]}


@unittest.skipUnless(CLI, "CALLIGRAPHY_CLI not set")
class NumberSweep(unittest.TestCase):
    """Every number option of a command, from its `--help`."""
    tmp = None

    @classmethod
    def setUpClass(cls):
        cls.tmp = Path(tempfile.mkdtemp(prefix="unseen12e-n-"))
        (cls.tmp / "empty").mkdir()
        (cls.tmp / "cnchar.js").write_text("/* no */\n")

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.tmp, ignore_errors=True)

    def sweep(self, command, base_args, accepted_status, check_accepted=True, skip=()):
        options = [o for o in numeric_options(command) if o[0] not in skip]
        self.assertTrue(options, f"{command}: no number option found in --help")
        for index, (option, placeholder, text) in enumerate(options):
            cases, bounded = expectations(option, placeholder, text, command)
            with self.subTest(option=option, what="a documented range"):
                self.assertTrue(bounded, f"{command} {option}: neither --help nor docs/cli.md gives a range")
            bound_cases = cases[:len(cases) - len(GENERIC)]
            generic = cases[len(cases) - len(GENERIC):]
            share = max(ROTATE, -(-len(generic) // len(options)))
            chosen = [generic[(index * share + k) % len(generic)] for k in range(share)]
            if SANITIZED:
                chosen, bound_cases = chosen[:1], []
            for value, refused in bound_cases + chosen:
                if refused is None or (not refused and not check_accepted):
                    continue
                args = [*command.split(), *base_args(option), option, value]
                r = run(args, self.tmp, timeout=30)
                lines = error_lines(r)
                with self.subTest(option=option, value=value):
                    if refused:
                        self.assertEqual(r.returncode, 2, lines)
                        self.assertEqual(len(lines), 1, lines)
                        self.assertIn(option, lines[0])
                    else:
                        self.assertIn(r.returncode, accepted_status, lines)

    def test_trial(self):
        self.sweep("trial", lambda option: [SHI, "--check", *MODE_OF.get(option, []),
                                            *TRIAL_COMPANION.get(option, [])], (0,))
        # the tick limit joins two options: the error names both, whichever was given
        for args in (["--rate", "100000"], ["--max-duration", "86400"]):
            with self.subTest(limit=args):
                r = run(["trial", SHI, "--check", *args], self.tmp)
                lines = error_lines(r)
                self.assertEqual(r.returncode, 2, lines)
                self.assertEqual(len(lines), 1, lines)
                self.assertIn("--rate", lines[0])
                self.assertIn("--max-duration", lines[0])

    def test_train(self):
        # accepted values reach the window, which cannot open here (exit 1); refused ones are exit 2
        self.sweep("train", lambda option: [SHI] + (["--guidance-mode", "fading"] if option == "--guidance-gain"
                                                   else []), (1,))
        for value in ("799x480", "8193x800", "nanx800", "1280x", "0x10", " 1280x800", "1280x800 ", "１２８０x800"):
            with self.subTest(option="--window", value=value):
                r = run(["train", SHI, "--window", value], self.tmp)
                lines = error_lines(r)
                self.assertEqual(r.returncode, 2, lines)
                self.assertIn("--window", lines[0])

    def test_writer_parameters_and_typical_stroke_ids(self):
        # the keys from the program's own list (an unknown key names them), each given a hostile spelling
        r = run(["trial", SHI, "--check", "--writer-param", "nokey=1"], self.tmp)
        self.assertEqual(r.returncode, 2)
        keys = error_lines(r)[0].split("known: ")[1].split(", ")
        self.assertGreater(len(keys), 10)
        hostile = ["nan", "inf", "-inf", "1e308", "0x10", " 1", "1 ", "", "1e", "\u0663", "1=2"]
        for index, key in enumerate(keys):
            value = hostile[index % len(hostile)]
            with self.subTest(key=key, value=value):
                r = run(["trial", SHI, "--check", "--writer-param", f"{key}={value}"], self.tmp)
                lines = error_lines(r)
                self.assertEqual(r.returncode, 2, lines)
                self.assertEqual(len(lines), 1, lines)
                self.assertIn("--writer-param", lines[0])
                self.assertIn(key, lines[0])
        for value in ("0", "40", "-0", "0x10", " 1", "1 ", "\u0663", "", "+1", "1e1"):
            with self.subTest(option="--typical", value=value):
                r = run(["characters", "--typical", value], self.tmp)
                lines = error_lines(r)
                self.assertEqual(r.returncode, 2, lines)
                self.assertEqual(len(lines), 1, lines)
                self.assertIn("--typical", lines[0])

    def test_characters_and_curriculum(self):
        self.sweep("characters", lambda option: ["--text", SHI], (0,))
        self.sweep("curriculum", lambda option: [str(self.tmp / "empty"), "--subject", "S1", "--from", SHI],
                   (2,), check_accepted=False)

    @heavy
    def test_corpus(self):
        # accepted values meet an empty data folder (exit 1); refused ones are exit 2 naming the option
        self.sweep("corpus build", lambda option: ["--data", "empty", "--out", "s.clg"], (1,))
        self.sweep("corpus fidelity", lambda option: ["--data", "empty"], (1,))
        self.sweep("corpus validate", lambda option: ["--data", "empty", "--cnchar", "cnchar.js"], (1,))
        for value in ("nan", "0", "-1", "2,,5", "2,inf", " 2", "", "0x10", "2,5,"):
            with self.subTest(option="--tolerances", value=value):
                r = run(["corpus", "fidelity", "--data", "empty", "--tolerances", value], self.tmp)
                lines = error_lines(r)
                self.assertEqual(r.returncode, 2, lines)
                self.assertIn("--tolerances", lines[0])

    @heavy
    def test_bench(self):
        for command in ("bench nearest", "bench jumps", "bench tick", "bench loop", "bench acceptance"):
            self.sweep(command, lambda option: [], (0,), check_accepted=False)


@unittest.skipUnless(CLI, "CALLIGRAPHY_CLI not set")
class HelpDefaults(Case):
    def test_trial_help_defaults_are_the_record_of_a_trial_with_defaults(self):
        spec = json.loads((self.base / "a.json").read_text())["specification"]
        fields = {}

        def walk(node):
            for key, value in node.items():
                if isinstance(value, dict):
                    walk(value)
                elif isinstance(value, (int, float)) and not isinstance(value, bool):
                    fields.setdefault(key, value)
        walk(spec)
        for option, placeholder, text in numeric_options("trial"):
            m = re.search(r"\(default: ([-\d.e]+)\)\s*$", text)
            if not m:
                continue
            stem = option[2:].replace("-", "_")
            if stem == "watchdog_ms":
                stem, scale = "watchdog", 1e-3
            else:
                scale = 1.0
            keys = [k for k in fields if k == stem or re.fullmatch(re.escape(stem) + r"_(m|s|hz|n_per_m|m_s)", k)]
            with self.subTest(option=option):
                self.assertEqual(len(keys), 1, (option, keys))
                self.assertAlmostEqual(fields[keys[0]], float(m.group(1)) * scale, delta=1e-12,
                                       msg=f"{option}: help default {m.group(1)}, record {keys[0]}={fields[keys[0]]}")

    def test_help_defaults_agree_with_the_tables_of_docs_cli(self):
        """Each option's numeric default in docs/cli.md's tables is the one its `--help` shows."""
        command, rows = None, {}
        for line in (SOURCE / "docs" / "cli.md").read_text(encoding="utf-8").splitlines():
            m = re.match(r"^## ([a-z]+)\s*$", line)
            if m:
                command = m.group(1)
            m = re.match(r"^`calligraphy ([a-z]+)(?: ([a-z]+))?", line)
            if m:
                command = " ".join(w for w in m.groups() if w)
            m = re.match(r"^\| `(--[\w-]+)`[^|]*\| [^|]* \| ([^|]*) \|", line)
            if m and command and not command.startswith(("session", "report")):
                rows.setdefault(command, {})[m.group(1)] = m.group(2).strip().strip("`")
        compared = 0
        for command, table in rows.items():
            r = help_of(command)
            self.assertEqual(r.returncode, 0, command)
            helped, current = {}, None
            for line in r.stdout.decode().splitlines():
                m = re.match(r"^  (--[\w-]+)(?: \S+)?\s*(.*)$", line)
                if m:
                    current = m.group(1)
                    helped[current] = m.group(2)
                elif current and line.startswith("       "):
                    helped[current] += " " + line.strip()
            for option, documented in table.items():
                m = re.search(r"\(default: ([-\d.e]+)\)\s*$", helped.get(option, ""))
                if not m or not re.fullmatch(r"-?[\d.]+(e-?\d+)?", documented):
                    continue
                compared += 1
                with self.subTest(command=command, option=option):
                    self.assertEqual(float(documented), float(m.group(1)))
        self.assertGreater(compared, 15)

    def test_trial_values_at_their_bounds_are_taken_exactly(self):
        args, wanted = ["trial", SHI], {}
        for option, placeholder, text in numeric_options("trial"):
            bounds = help_bounds(text)
            if option in ("--rate", "--max-duration", "--seed", "--watchdog-ms") or option in MODE_OF \
                    or not bounds or bounds[2] is None:
                continue
            value = bounds[2] if bounds[3] else (bounds[2] + bounds[0]) / 2
            value = int(value) if bounds[4] else value
            args += [option, str(value)]
            wanted[option[2:].replace("-", "_")] = value
        args += ["--seed", "9007199254740993", "--max-duration", "1", "--json", "j.json"]
        r = run(args, self.tmp)
        self.assertIn(r.returncode, (0, 1), error_lines(r))
        record = json.loads((self.tmp / "j.json").read_text())
        self.assertEqual(record["seed"], 9007199254740993)
        flat = {}

        def walk(node):
            for key, value in node.items():
                if isinstance(value, dict):
                    walk(value)
                else:
                    flat.setdefault(key, value)
        walk(record["specification"])
        for stem, value in wanted.items():
            keys = [k for k in flat if k == stem or re.fullmatch(re.escape(stem) + r"_(m|s|hz|n_per_m|m_s)", k)]
            with self.subTest(option=stem):
                self.assertEqual(len(keys), 1, (stem, keys))
                self.assertEqual(flat[keys[0]], value)


# Under the sanitizers each run of the program is slow: a few cases, one of each kind.
SANITIZED_CASES = {"test_two_outputs_spelled_with_dot_and_double_slash_are_one_file",
                   "test_file_size_limit_keeps_the_earlier_file_and_writes_the_others",
                   "test_trace_into_a_closed_pipe", "test_longest_file_name_is_written",
                   "test_characters_and_curriculum"}


load_tests = sanitized_subset(SANITIZED_CASES)


if __name__ == "__main__":
    unittest.main(verbosity=2)
