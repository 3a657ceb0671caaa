#!/usr/bin/env python3
"""Round 25A: the single-trial and data commands as a matrix of files and hostile verbs. From the docs alone
(README.md; docs/cli.md "Conventions", "Exit statuses", "trial", "Re-running a trial", "score", "Pen traces:
format and limits", "trace", "model", "strokes", "characters"; `calligraphy schema record`; each `--help`).

Rows: every file these commands read (a trial record for `trial --spec`, a teacher's recording for `--teacher`,
a pen trace for `score` (CSV, gzip, `.trace.h5`), a `.trace.h5` for `trace`, a corpus store for `--store`, a
character file under `--data`) and every file they write (`trial --json|--csv|--svg|--record`, `score --json`,
`trace --csv`, `model --svg`, `strokes --markdown`, `bench acceptance --markdown`). Columns, the verbs:
- forge: a file of the right kind with one value changed (a record's seed, scene SHA-256, characters or a key's
  units suffix; a teacher of another character or edited after the record; a trace's column renamed to
  millimetres or given both `pen` and `z`; an HDF5 trace's sample count; a character's stroke count);
- cut: in the middle of a byte run, at a line end, after the header only, 0 bytes;
- link: a symbolic link, a dangling one, a loop, a hard link to an input, the input through `./` and `..`,
  an output naming a folder;
- fill: the documented limits at and one past them (1,000 characters in a scene, 10,000 pen-downs in a trace, a
  file name of 255 bytes and of 256);
- kill: SIGTERM, SIGINT and SIGKILL at a random moment of a long lock-step trial and of `trace` writing a big
  CSV (then: the target absent, the old file or a whole new one, no temporary except after SIGKILL, and the next
  run succeeds);
- race: two runs onto one output at once; a record replaced (by rename) while a re-run reads it;
- mislabel: a file of another kind under the expected name (a trace CSV, gzip, HDF5, a protocol, a teacher or
  session.json given as a record; a record given as a trace or teacher; a CSV named `.trace.h5`; UTF-16 with a
  byte-order mark).
Each case expects the documented outcome, or one error line naming the file (and the JSON pointer, line or
option) with the documented exit status; never a crash, a traceback, a silent wrong result or a file lost.

Cells left out, and why: `devices` and `schema` read and write no file (standard output only, which
tests/cli/test_unseen_round_cli.py holds to /dev/full, closed pipes and SIGPIPE); `characters` writes no file,
so only its `--store` input row is here; `train --check` does not exist (`trial --check` is tried on a forged
record instead); kill on inputs, and race on inputs other than the record and the score's trace (a teacher, a
store, a character file are read whole before any work, as those two are, so their race stands for them); fill
on inputs whose limits other tests hold (the 256 MiB trace, 1,000,000 samples and a record's nesting:
tests/cli/test_unseen_round23b.py); after SIGKILL only the target is checked (the docs name no cleanup of a
temporary then); mislabel on outputs (an output is what the command makes; its kind is not read); `bench
acceptance` only with `--characters 2`, its cheap form.

CALLIGRAPHY_CLI names the program. CALLIGRAPHY_SANITIZED=1 takes five cases.
"""
import gzip
import hashlib
import json
import os
import random
import shutil
import signal
import subprocess
import tempfile
import time
import unittest
from pathlib import Path

from outsider import CLI, ENV, OneErrorLine, run, run_ok, sanitized_subset

load_tests = sanitized_subset({"test_record_forged_scene_sha256_is_refused_naming_the_file",
                               "test_trace_cut_in_the_middle_is_refused_naming_it",
                               "test_trial_output_through_dot_slash_onto_the_record_is_refused",
                               "test_trial_sigterm_at_a_random_tick_writes_whole_outputs",
                               "test_score_10001_pen_downs_refused_10000_scored"})

SEED = 7
DATA = os.environ.get("CALLIGRAPHY_CORPUS_DIR", "")
SHORT = ["--max-duration", "0.4"]
PROTOCOL = {"name": "p", "conditions": [{"name": "V", "mode": "vision"}],
            "test": {"characters": ["一"], "conditions": ["V"], "repetitions": 1},
            "trial": {"max_duration_s": 0.4}}


def temporaries(folder):
    """The hidden temporaries of the atomic writer left in `folder`."""
    return sorted(p.name for p in Path(folder).iterdir() if ".tmp-" in p.name)


def pen_trace(segments, samples_per_segment=2):
    """A CSV trace of `segments` short pen-downs along 一's stroke (metres, as `trial` places it), each followed
    by one pen-up sample."""
    lines = ["t,x,y,pen"]
    t = 0
    for s in range(segments):
        for k in range(samples_per_segment):
            lines.append(f"{t / 1000:.3f},{-0.02 + 0.0001 * k:.4f},0.001,1")
            t += 1
        lines.append(f"{t / 1000:.3f},-0.02,0.001,0")
        t += 1
    return ("\n".join(lines) + "\n").encode()


SWAPPER = """import os, sys, time
folder, first, second, target, stop = sys.argv[1:4] + [sys.argv[4], float(sys.argv[5])]
texts = [open(os.path.join(folder, name), "rb").read() for name in (first, second)]
i = 0
while time.time() < stop:
    with open(os.path.join(folder, "swap.tmp"), "wb") as f:
        f.write(texts[i % 2])
    os.rename(os.path.join(folder, "swap.tmp"), os.path.join(folder, target))
    i += 1
"""


def swapping(folder, first, second, target, seconds):
    """A process that puts `first` and `second` in turn at `target` by rename(2) for `seconds`."""
    return subprocess.Popen(["/usr/bin/python3", "-c", SWAPPER, str(folder), first, second, target,
                             str(time.time() + seconds)])


class Round25A(unittest.TestCase, OneErrorLine):
    @classmethod
    def setUpClass(cls):
        cls.tmp = Path(tempfile.mkdtemp(prefix="round25a-"))
        d = cls.tmp
        # A skilled 一 that completes: its record, trace and teacher's recording; and a teacher of 十.
        run_ok(["trial", "一", "--writer-profile", "skilled", "--seed", SEED, "--max-duration", "3",
                "--json", "r.json", "--csv", "r.csv", "--record", "t.json"], d)
        run_ok(["trial", "十", "--writer-profile", "skilled", "--max-duration", "10", "--record", "t10.json"], d)
        run_ok(["score", "r.csv", "--character", "一", "--json", "s.json"], d)
        cls.record = (d / "r.json").read_bytes()
        cls.csv = (d / "r.csv").read_bytes()
        cls.score = json.loads((d / "s.json").read_text())
        # A session with one short trial: its HDF5 trace and record.
        (d / "p.json").write_text(json.dumps(PROTOCOL, ensure_ascii=False), encoding="utf-8")
        run_ok(["session", "run", "p.json", "--writer", "simulated", "--subjects", "1", "--out", "S"], d)
        cls.h5 = next((d / "S").glob("S01/*/trials/*.trace.h5"))
        cls.study_record = next((d / "S").glob("S01/*/trials/*.json"))
        cls.session_json = next((d / "S").glob("S01/*/session.json"))
        run_ok(["trace", cls.h5, "--csv", "h5.csv"], d)
        cls.h5_csv = (d / "h5.csv").read_bytes()
        # A store of three characters and a data folder of them.
        (d / "hw").mkdir()
        for c in "一十二":
            shutil.copy(Path(DATA) / f"{c}.json", d / "hw" / f"{c}.json")
        run_ok(["corpus", "build", "--data", "hw", "--out", "st.clg", "--threads", "1"], d)
        run_ok(["model", "一", "--svg", "m.svg"], d)
        cls.model_svg = (d / "m.svg").read_bytes()

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.tmp, ignore_errors=True)

    def setUp(self):
        self.d = Path(tempfile.mkdtemp(dir=self.tmp))
        (self.d / "r.json").write_bytes(self.record)
        (self.d / "r.csv").write_bytes(self.csv)

    def record_with(self, change):
        r = json.loads(self.record)
        change(r)
        path = self.d / "f.json"
        path.write_text(json.dumps(r, ensure_ascii=False), encoding="utf-8")
        return path.name

    def assert_csv_is_the_trial(self, name):
        self.assertEqual((self.d / name).read_bytes(), self.csv)

    # ---- the record (trial --spec): forge ----

    def test_record_forged_seed_warns_that_the_rerun_differs(self):
        name = self.record_with(lambda r: r["specification"]["trial"].update(seed=SEED + 1))
        result = run(["trial", "--spec", name, "--csv", "again.csv"], self.d)
        text = result.stderr.decode()
        self.assertIn(result.returncode, (0, 1), text)
        self.assertIn("warning", text)
        self.assertIn("differs from the run the record states", text)
        self.assertIn(name, text)

    def test_record_forged_scene_sha256_is_refused_naming_the_file(self):
        def forge(r):
            sha = r["specification"]["scene"]["sha256"]
            r["specification"]["scene"]["sha256"] = ("0" if sha[0] != "0" else "1") + sha[1:]
        name = self.record_with(forge)
        self.assert_one_error(run(["trial", "--spec", name, "--csv", "x.csv"], self.d), 1, name)
        self.assertFalse((self.d / "x.csv").exists())

    def test_record_forged_characters_with_the_old_sha256_is_refused(self):
        name = self.record_with(lambda r: r["specification"]["trial"].update(characters="十"))
        self.assert_one_error(run(["trial", "--spec", name, "--csv", "x.csv"], self.d), 1, name)
        self.assertFalse((self.d / "x.csv").exists())

    def test_record_forged_units_suffix_is_refused_at_its_pointer(self):
        def forge(r):
            t = r["specification"]["trial"]
            t["max_duration_ms"] = t.pop("max_duration_s") * 1000
        name = self.record_with(forge)
        self.assert_one_error(run(["trial", "--spec", name], self.d), 2, name,
                              "/specification/trial/max_duration_ms")

    def test_record_forged_rate_checked_by_trial_check(self):
        name = self.record_with(lambda r: r["specification"]["trial"].update(rate_hz=100001))
        self.assert_one_error(run(["trial", "--spec", name, "--check"], self.d), 2, name,
                              "/specification/trial/rate_hz")

    def test_record_seed_with_an_exponent_reruns_below_2_53_and_is_refused_above(self):
        # Below 2^53 every integer is exact as a double: 7.0e0 is the seed 7. Above, R's 15 digits may be a
        # rounded seed: refused at its pointer.
        for spelt, same in (("7.0e0", True), ("1.23456789012346e+16", False)):
            name = self.record_with(lambda r: r["specification"]["trial"].update(seed="SEED_HERE"))
            text = (self.d / name).read_text(encoding="utf-8").replace('"SEED_HERE"', spelt)
            (self.d / name).write_text(text, encoding="utf-8")
            result = run(["trial", "--spec", name, "--csv", "again.csv"], self.d)
            if same:
                self.assertEqual(result.returncode, 0, result.stderr.decode())
                self.assertEqual(result.stderr, b"")
                self.assert_csv_is_the_trial("again.csv")
            else:
                self.assert_one_error(result, 2, name, "/specification/trial/seed")

    # ---- the record: cut ----

    def test_record_cut_in_the_middle_is_refused_naming_the_file(self):
        (self.d / "c.json").write_bytes(self.record[:len(self.record) // 2])
        self.assert_one_error(run(["trial", "--spec", "c.json", "--json", "o.json"], self.d), 2, "c.json")
        self.assertEqual(temporaries(self.d), [])
        self.assertFalse((self.d / "o.json").exists())

    def test_record_cut_at_a_line_end_is_refused_naming_the_file(self):
        pretty = json.dumps(json.loads(self.record), indent=1).encode()
        cut = pretty[:pretty.index(b"\n", len(pretty) // 3) + 1]
        (self.d / "c.json").write_bytes(cut)
        self.assert_one_error(run(["trial", "--spec", "c.json"], self.d), 2, "c.json")

    def test_record_of_its_header_only_is_refused_naming_the_missing_part(self):
        spec = json.loads(self.record)["specification"]
        head = {"specification": {"format": spec["format"], "version": spec["version"]}}
        (self.d / "c.json").write_text(json.dumps(head))
        self.assert_one_error(run(["trial", "--spec", "c.json"], self.d), 2, "c.json", "/specification/")

    def test_record_of_zero_bytes_is_refused_naming_the_file(self):
        (self.d / "c.json").write_bytes(b"")
        self.assert_one_error(run(["trial", "--spec", "c.json"], self.d), (1, 2), "c.json")

    # ---- the record: link ----

    def test_record_through_a_symbolic_link_reruns_the_same_trace(self):
        os.symlink("r.json", self.d / "l.json")
        run_ok(["trial", "--spec", "l.json", "--csv", "again.csv"], self.d)
        self.assert_csv_is_the_trial("again.csv")
        self.assertTrue((self.d / "l.json").is_symlink())

    def test_record_as_a_dangling_link_is_refused_naming_it(self):
        os.symlink("gone.json", self.d / "l.json")
        self.assert_one_error(run(["trial", "--spec", "l.json"], self.d), 1, "l.json")

    def test_record_as_a_link_loop_is_refused_naming_it(self):
        os.symlink("b.json", self.d / "a.json")
        os.symlink("a.json", self.d / "b.json")
        self.assert_one_error(run(["trial", "--spec", "a.json"], self.d), 1, "a.json")

    def test_trial_output_through_dot_slash_onto_the_record_is_refused(self):
        result = run(["trial", "--spec", "r.json", "--csv", "./r.json"], self.d)
        self.assert_one_error(result, 2, "--spec", "--csv")
        self.assertEqual((self.d / "r.json").read_bytes(), self.record)

    def test_trial_output_through_dot_dot_onto_the_record_is_refused(self):
        (self.d / "sub").mkdir()
        result = run(["trial", "--spec", "r.json", "--json", "sub/../r.json"], self.d)
        self.assert_one_error(result, 2, "--spec", "--json")
        self.assertEqual((self.d / "r.json").read_bytes(), self.record)

    def test_trial_output_on_a_hard_link_to_the_record_is_refused(self):
        os.link(self.d / "r.json", self.d / "h.json")
        result = run(["trial", "--spec", "r.json", "--svg", "h.json"], self.d)
        self.assert_one_error(result, 2, "--spec", "--svg")
        self.assertEqual((self.d / "h.json").read_bytes(), self.record)

    # ---- the record: mislabel ----

    def test_record_given_a_trace_csv_is_named_as_csv(self):
        shutil.copy(self.d / "r.csv", self.d / "x.json")
        self.assert_one_error(run(["trial", "--spec", "x.json"], self.d), 2, "x.json", "CSV")

    def test_record_gzipped_is_named_for_what_it_is(self):
        (self.d / "x.json").write_bytes(gzip.compress(self.record))
        self.assert_one_error(run(["trial", "--spec", "x.json"], self.d), 2, "x.json", "gzip")

    def test_record_given_an_hdf5_trace_is_named_for_what_it_is(self):
        shutil.copy(self.h5, self.d / "x.json")
        self.assert_one_error(run(["trial", "--spec", "x.json"], self.d), 2, "x.json", ".trace.h5")

    def test_record_in_utf16_with_a_bom_is_refused_naming_the_file(self):
        (self.d / "x.json").write_bytes(self.record.decode().encode("utf-16"))
        self.assert_one_error(run(["trial", "--spec", "x.json"], self.d), 2, "x.json")

    def test_record_given_a_protocol_is_refused_naming_the_file(self):
        shutil.copy(self.tmp / "p.json", self.d / "x.json")
        self.assert_one_error(run(["trial", "--spec", "x.json"], self.d), 2, "x.json")

    def test_record_given_a_teacher_recording_is_refused_naming_the_file(self):
        shutil.copy(self.tmp / "t.json", self.d / "x.json")
        self.assert_one_error(run(["trial", "--spec", "x.json"], self.d), 2, "x.json")

    def test_record_given_session_json_is_refused_naming_the_file(self):
        shutil.copy(self.session_json, self.d / "x.json")
        self.assert_one_error(run(["trial", "--spec", "x.json"], self.d), 2, "x.json")

    def test_study_trial_record_reruns_as_documented(self):
        shutil.copy(self.study_record, self.d / "x.json")
        result = run(["trial", "--spec", "x.json", "--json", "o.json"], self.d)
        self.assertIn(result.returncode, (0, 1), result.stderr.decode())
        self.assertNotIn("differs", result.stderr.decode())
        out = json.loads((self.d / "o.json").read_text())
        self.assertEqual(out["specification"]["trial"]["characters"], "一")

    # ---- the record: race ----

    def test_record_replaced_while_a_rerun_reads_it_runs_one_or_the_other(self):
        other = json.loads(self.record)
        other["specification"]["trial"]["seed"] = SEED + 1
        # The specification alone: it states no run to compare with, so its re-run does not warn.
        (self.d / "other.json").write_text(json.dumps({"specification": other["specification"]}))
        run_ok(["trial", "--spec", "other.json", "--csv", "other.csv"], self.d, ok=False)
        other_csv = (self.d / "other.csv").read_bytes()
        (self.d / "one.json").write_bytes(self.record)
        swapper = swapping(self.d, "other.json", "one.json", "live.json", 0.4)
        try:
            time.sleep(0.05)
            for _ in range(4):  # the swapper renames for 0.4 s: each run reads while it does
                result = run(["trial", "--spec", "live.json", "--csv", "got.csv"], self.d)
                self.assertIn(result.returncode, (0, 1), result.stderr.decode())
                got = (self.d / "got.csv").read_bytes()
                self.assertIn(got, (self.csv, other_csv))
        finally:
            swapper.wait(timeout=10)

    def test_record_of_1001_characters_is_refused_at_its_pointer(self):
        name = self.record_with(lambda r: r["specification"]["trial"].update(characters="一" * 1001))
        self.assert_one_error(run(["trial", "--spec", name], self.d), 2, name, "/specification/trial/characters")

    def test_record_of_1001_characters_is_refused_by_check(self):
        name = self.record_with(lambda r: r["specification"]["trial"].update(characters="一" * 1001))
        self.assert_one_error(run(["trial", "--spec", name, "--check"], self.d), 2, name,
                              "/specification/trial/characters")

    def test_record_replay_teacher_swapped_for_a_link_to_another_is_refused(self):
        shutil.copy(self.tmp / "t.json", self.d / "t.json")
        run_ok(["trial", "一", "--guidance-mode", "replay", "--teacher", "t.json", *SHORT, "--json", "rep.json"],
               self.d, ok=False)
        run_ok(["trial", "一", "--writer-profile", "skilled", "--seed", "9", "--max-duration", "3",
                "--record", "t2.json"], self.d)
        (self.d / "t.json").unlink()
        os.symlink("t2.json", self.d / "t.json")
        self.assert_one_error(run(["trial", "--spec", "rep.json", "--csv", "x.csv"], self.d), 1, "t.json")
        self.assertFalse((self.d / "x.csv").exists())

    # ---- the teacher (--teacher) ----

    def test_teacher_of_another_character_is_refused(self):
        shutil.copy(self.tmp / "t10.json", self.d / "t.json")
        result = run(["trial", "一", "--guidance-mode", "replay", "--teacher", "t.json", *SHORT], self.d)
        self.assert_one_error(result, 1, "t.json")

    def test_teacher_edited_after_the_record_is_refused_naming_both_sha256(self):
        shutil.copy(self.tmp / "t.json", self.d / "t.json")
        run_ok(["trial", "一", "--guidance-mode", "replay", "--teacher", "t.json", *SHORT, "--json", "rep.json"],
               self.d, ok=False)
        teacher = json.loads((self.d / "t.json").read_text())
        teacher["writer"] = "novice"
        (self.d / "t.json").write_text(json.dumps(teacher, ensure_ascii=False))
        new_sha = hashlib.sha256((self.d / "t.json").read_bytes()).hexdigest()
        line = self.assert_one_error(run(["trial", "--spec", "rep.json"], self.d), 1, "t.json")
        self.assertIn(new_sha[:12], line)

    def test_teacher_cut_in_the_middle_is_refused_naming_it(self):
        data = (self.tmp / "t.json").read_bytes()
        (self.d / "t.json").write_bytes(data[:len(data) // 2])
        result = run(["trial", "一", "--guidance-mode", "replay", "--teacher", "t.json", *SHORT], self.d)
        self.assert_one_error(result, (1, 2), "t.json")

    def test_teacher_as_a_dangling_link_is_refused_naming_it(self):
        os.symlink("gone.json", self.d / "t.json")
        result = run(["trial", "一", "--guidance-mode", "replay", "--teacher", "t.json", *SHORT], self.d)
        self.assert_one_error(result, 1, "t.json")

    def test_output_on_the_teacher_through_a_link_is_refused(self):
        shutil.copy(self.tmp / "t.json", self.d / "t.json")
        os.symlink("t.json", self.d / "l.json")
        before = (self.d / "t.json").read_bytes()
        result = run(["trial", "一", "--guidance-mode", "replay", "--teacher", "t.json", *SHORT,
                      "--json", "l.json"], self.d)
        self.assert_one_error(result, 2, "--teacher", "--json")
        self.assertEqual((self.d / "t.json").read_bytes(), before)

    def test_teacher_given_a_trial_record_is_refused(self):
        result = run(["trial", "一", "--guidance-mode", "replay", "--teacher", "r.json", *SHORT], self.d)
        self.assert_one_error(result, 1, "r.json")

    def test_teacher_given_a_trace_csv_is_named_as_csv(self):
        result = run(["trial", "一", "--guidance-mode", "replay", "--teacher", "r.csv", *SHORT], self.d)
        self.assert_one_error(result, (1, 2), "r.csv", "CSV")

    # ---- the score's trace (CSV, gzip, HDF5) ----

    def score_json(self, trace, *extra):
        run_ok(["score", trace, "--character", "一", "--json", "o.json", *extra], self.d)
        return json.loads((self.d / "o.json").read_text())

    def test_trace_with_a_column_renamed_to_millimetres_is_refused(self):
        text = self.csv.decode().replace("t,x,y,z,", "t,x_mm,y,z,", 1)
        (self.d / "x.csv").write_text(text)
        self.assert_one_error(run(["score", "x.csv", "--character", "一"], self.d), 1, "x.csv")

    def test_trace_with_both_pen_and_z_is_refused(self):
        lines = self.csv.decode().splitlines()
        lines[0] += ",pen"
        lines[1:] = [ln + ",1" for ln in lines[1:]]
        (self.d / "x.csv").write_text("\n".join(lines) + "\n")
        self.assert_one_error(run(["score", "x.csv", "--character", "一"], self.d), 1, "x.csv")

    def test_trace_of_another_character_scores_as_not_that_character(self):
        run_ok(["trial", "二", "--writer-profile", "skilled", "--max-duration", "10", "--csv", "two.csv"], self.d)
        two = self.score_json("two.csv")
        self.assertLess(two["strokes_accepted"], 1 + two["strokes_total"])
        self.assertEqual(two["strokes_total"], 1)
        own = run_ok(["score", "two.csv", "--character", "二", "--json", "-"], self.d)
        self.assertEqual(json.loads(own.stdout)["strokes_accepted"], 2)

    def test_trace_cut_in_the_middle_is_refused_naming_it(self):
        cut = self.csv[:len(self.csv) // 2]
        cut = cut[:cut.rindex(b",") + 1]  # a row ending after a comma: a field missing
        (self.d / "x.csv").write_bytes(cut)
        line = self.assert_one_error(run(["score", "x.csv", "--character", "一"], self.d), 1, "x.csv:")
        rows = cut.count(b"\n")
        self.assertIn(f"x.csv:{rows + 1}", line)

    def test_trace_cut_at_a_line_end_scores_its_rows(self):
        cut = self.csv[:self.csv.index(b"\n", len(self.csv) // 2) + 1]
        (self.d / "x.csv").write_bytes(cut)
        got = self.score_json("x.csv")
        self.assertEqual(got["samples"], cut.count(b"\n") - 1)

    def test_trace_of_its_header_only_has_no_samples(self):
        (self.d / "x.csv").write_bytes(self.csv[:self.csv.index(b"\n") + 1])
        result = run(["score", "x.csv", "--character", "一", "--json", "o.json"], self.d)
        if result.returncode == 0:
            self.assertEqual(json.loads((self.d / "o.json").read_text())["samples"], 0)
            self.assertEqual(json.loads((self.d / "o.json").read_text())["strokes_accepted"], 0)
        else:
            self.assert_one_error(result, 1, "x.csv")

    def test_trace_of_zero_bytes_is_refused_naming_it(self):
        (self.d / "x.csv").write_bytes(b"")
        self.assert_one_error(run(["score", "x.csv", "--character", "一"], self.d), 1, "x.csv")

    def test_trace_through_a_symbolic_link_scores_the_same(self):
        os.symlink("r.csv", self.d / "l.csv")
        got = self.score_json("l.csv")
        self.assertEqual(got["per_character"], self.score["per_character"])

    def test_trace_as_a_link_loop_is_refused_naming_it(self):
        os.symlink("b.csv", self.d / "a.csv")
        os.symlink("a.csv", self.d / "b.csv")
        self.assert_one_error(run(["score", "a.csv", "--character", "一"], self.d), 1, "a.csv")

    def test_score_json_onto_its_trace_through_dot_slash_is_refused(self):
        result = run(["score", "r.csv", "--character", "一", "--json", "./r.csv"], self.d)
        self.assert_one_error(result, 2, "r.csv")
        self.assert_csv_is_the_trial("r.csv")

    def test_score_json_onto_a_hard_link_of_its_trace_is_refused(self):
        os.link(self.d / "r.csv", self.d / "h.json")
        result = run(["score", "r.csv", "--character", "一", "--json", "h.json"], self.d)
        self.assert_one_error(result, 2, "h.json")
        self.assert_csv_is_the_trial("r.csv")

    def test_score_json_naming_a_folder_is_refused(self):
        (self.d / "out").mkdir()
        result = run(["score", "r.csv", "--character", "一", "--json", "out"], self.d)
        self.assert_one_error(result, 1, "--json", "out")

    def test_score_10001_pen_downs_refused_10000_scored(self):
        (self.d / "at.csv").write_bytes(pen_trace(10000))
        got = self.score_json("at.csv")
        self.assertEqual(got["samples"], 30000)
        (self.d / "past.csv").write_bytes(pen_trace(10001))
        line = self.assert_one_error(run(["score", "past.csv", "--character", "一"], self.d), 1, "past.csv:")
        self.assertIn("past.csv:30002", line)

    def test_score_race_two_runs_onto_one_json(self):
        procs = [subprocess.Popen([CLI, "score", "r.csv", "--character", "一", "--json", "o.json"], cwd=self.d,
                                  env=ENV, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE) for _ in range(2)]
        for p in procs:
            _, err = p.communicate(timeout=60)
            self.assertEqual(p.returncode, 0, err.decode())
        self.assertEqual(json.loads((self.d / "o.json").read_text())["per_character"],
                         self.score["per_character"])
        self.assertEqual(temporaries(self.d), [])

    def test_score_given_a_record_as_its_trace_is_refused_naming_it(self):
        self.assert_one_error(run(["score", "r.json", "--character", "一"], self.d), 1, "r.json")

    def test_trace_gzipped_under_a_csv_name_scores_the_same(self):
        (self.d / "x.csv").write_bytes(gzip.compress(self.csv))
        self.assertEqual(self.score_json("x.csv")["per_character"], self.score["per_character"])

    def test_trace_hdf5_under_a_csv_name_scores_as_its_csv(self):
        shutil.copy(self.h5, self.d / "x.csv")
        (self.d / "h.csv").write_bytes(self.h5_csv)
        want = self.score_json("h.csv")
        result = run(["score", "x.csv", "--character", "一", "--json", "o.json"], self.d)
        if result.returncode == 0:
            self.assertEqual(json.loads((self.d / "o.json").read_text())["samples"], want["samples"])
        else:
            self.assert_one_error(result, 1, "x.csv")

    def test_trace_csv_under_an_h5_name_is_scored_or_named(self):
        (self.d / "x.trace.h5").write_bytes(self.csv)
        result = run(["score", "x.trace.h5", "--character", "一", "--json", "o.json"], self.d)
        if result.returncode == 0:
            self.assertEqual(json.loads((self.d / "o.json").read_text())["per_character"],
                             self.score["per_character"])
        else:
            self.assert_one_error(result, 1, "x.trace.h5")

    def test_trace_in_utf16_with_a_bom_is_refused_naming_it(self):
        (self.d / "x.csv").write_bytes(self.csv.decode().encode("utf-16"))
        self.assert_one_error(run(["score", "x.csv", "--character", "一"], self.d), 1, "x.csv")

    def test_score_of_1001_characters_is_refused_naming_the_limit(self):
        result = run(["score", "r.csv", "--character", "一" * 1001], self.d)
        self.assert_one_error(result, 1, "--character", "1000")  # a limit: status 1 (docs/cli.md)

    def test_score_json_onto_the_store_is_refused(self):
        shutil.copy(self.tmp / "st.clg", self.d / "st.clg")
        result = run(["score", "r.csv", "--character", "一", "--store", "st.clg", "--json", "st.clg"], self.d)
        self.assert_one_error(result, 2, "--store", "--json")
        self.assertEqual((self.d / "st.clg").read_bytes(), (self.tmp / "st.clg").read_bytes())

    def test_trace_replaced_while_score_reads_it_scores_one_or_the_other(self):
        run_ok(["trial", "一", "--writer-profile", "skilled", "--seed", "9", "--max-duration", "3",
                "--csv", "other.csv"], self.d)
        other = self.score_json("other.csv")["per_character"]
        swapper = swapping(self.d, "other.csv", "r.csv", "live.csv", 0.35)
        try:
            time.sleep(0.05)
            for _ in range(4):  # the swapper renames for 0.35 s: each run reads while it does
                got = self.score_json("live.csv")["per_character"]
                self.assertIn(got, (self.score["per_character"], other))
        finally:
            swapper.wait(timeout=10)

    def test_trace_file_whose_folder_is_a_file_as_output_is_refused(self):
        result = run(["score", "r.csv", "--character", "一", "--json", "r.csv/o.json"], self.d)
        self.assert_one_error(result, 1, "--json")
        self.assert_csv_is_the_trial("r.csv")

    # ---- the HDF5 trace (trace) ----

    def test_h5_forged_sample_count_is_refused_naming_it(self):
        import h5py
        shutil.copy(self.h5, self.d / "f.trace.h5")
        with h5py.File(self.d / "f.trace.h5", "r+") as f:
            f.attrs["samples"] = int(f.attrs["samples"]) - 1
        self.assert_one_error(run(["trace", "f.trace.h5", "--csv", "o.csv"], self.d), 1, "f.trace.h5")
        self.assertFalse((self.d / "o.csv").exists())

    def test_h5_forged_without_a_column_is_refused_naming_it(self):
        import h5py
        shutil.copy(self.h5, self.d / "f.trace.h5")
        with h5py.File(self.d / "f.trace.h5", "r+") as f:
            del f["y"]
        self.assert_one_error(run(["trace", "f.trace.h5", "--csv", "o.csv"], self.d), 1, "f.trace.h5")

    def test_h5_cut_in_the_middle_is_refused_naming_it(self):
        data = self.h5.read_bytes()
        (self.d / "c.trace.h5").write_bytes(data[:len(data) // 2])
        self.assert_one_error(run(["trace", "c.trace.h5", "--csv", "o.csv"], self.d), 1, "c.trace.h5")
        self.assertFalse((self.d / "o.csv").exists())

    def test_h5_of_zero_bytes_is_refused_naming_it(self):
        (self.d / "c.trace.h5").write_bytes(b"")
        self.assert_one_error(run(["trace", "c.trace.h5"], self.d), 1, "c.trace.h5")

    def test_h5_through_a_symbolic_link_gives_the_same_csv(self):
        os.symlink(self.h5, self.d / "l.trace.h5")
        run_ok(["trace", "l.trace.h5", "--csv", "o.csv"], self.d)
        self.assertEqual((self.d / "o.csv").read_bytes(), self.h5_csv)

    def test_h5_as_a_dangling_link_is_refused_naming_it(self):
        os.symlink("gone.trace.h5", self.d / "l.trace.h5")
        self.assert_one_error(run(["trace", "l.trace.h5"], self.d), 1, "l.trace.h5")

    def test_trace_csv_onto_its_h5_through_dot_dot_is_refused(self):
        shutil.copy(self.h5, self.d / "x.trace.h5")
        (self.d / "sub").mkdir()
        result = run(["trace", "x.trace.h5", "--csv", "sub/../x.trace.h5"], self.d)
        self.assert_one_error(result, 2, "x.trace.h5")
        self.assertEqual((self.d / "x.trace.h5").read_bytes(), self.h5.read_bytes())

    def test_trace_csv_onto_a_hard_link_of_its_h5_is_refused(self):
        shutil.copy(self.h5, self.d / "x.trace.h5")
        os.link(self.d / "x.trace.h5", self.d / "h.csv")
        self.assert_one_error(run(["trace", "x.trace.h5", "--csv", "h.csv"], self.d), 2, "h.csv")
        self.assertEqual((self.d / "h.csv").read_bytes(), self.h5.read_bytes())

    def test_trace_csv_naming_a_folder_is_refused(self):
        (self.d / "out").mkdir()
        self.assert_one_error(run(["trace", self.h5, "--csv", "out/"], self.d), 1, "--csv")

    def test_trace_race_two_runs_onto_one_csv(self):
        procs = [subprocess.Popen([CLI, "trace", str(self.h5), "--csv", "o.csv"], cwd=self.d, env=ENV,
                                  stdout=subprocess.DEVNULL, stderr=subprocess.PIPE) for _ in range(2)]
        for p in procs:
            _, err = p.communicate(timeout=60)
            self.assertEqual(p.returncode, 0, err.decode())
        self.assertEqual((self.d / "o.csv").read_bytes(), self.h5_csv)
        self.assertEqual(temporaries(self.d), [])

    def test_h5_forged_format_attribute_is_refused_naming_it(self):
        import h5py
        shutil.copy(self.h5, self.d / "f.trace.h5")
        with h5py.File(self.d / "f.trace.h5", "r+") as f:
            f.attrs["format"] = b"calligraphy-traces"
        self.assert_one_error(run(["trace", "f.trace.h5", "--csv", "o.csv"], self.d), 1, "f.trace.h5")

    def test_h5_forged_column_of_another_length_is_refused_naming_it(self):
        import h5py
        shutil.copy(self.h5, self.d / "f.trace.h5")
        with h5py.File(self.d / "f.trace.h5", "r+") as f:
            x = f["x"][:]
            del f["x"]
            f["x"] = x[:-1]
        self.assert_one_error(run(["trace", "f.trace.h5", "--csv", "o.csv"], self.d), 1, "f.trace.h5")
        result = run(["score", "f.trace.h5", "--character", "一"], self.d)
        self.assert_one_error(result, 1, "f.trace.h5")

    def test_trace_csv_onto_its_h5_through_a_symbolic_link_is_refused(self):
        shutil.copy(self.h5, self.d / "x.trace.h5")
        os.symlink("x.trace.h5", self.d / "l.csv")
        self.assert_one_error(run(["trace", "x.trace.h5", "--csv", "l.csv"], self.d), 2, "l.csv")
        self.assertEqual((self.d / "x.trace.h5").read_bytes(), self.h5.read_bytes())

    def test_trace_given_a_csv_is_refused_naming_it(self):
        self.assert_one_error(run(["trace", "r.csv"], self.d), 1, "r.csv")

    def test_trace_given_gzip_is_refused_naming_it(self):
        (self.d / "x.trace.h5").write_bytes(gzip.compress(self.csv))
        self.assert_one_error(run(["trace", "x.trace.h5"], self.d), 1, "x.trace.h5")

    def test_trace_given_a_record_is_refused_naming_it(self):
        self.assert_one_error(run(["trace", "r.json"], self.d), 1, "r.json")

    # ---- trial's outputs: link, fill, kill, race ----

    def test_trial_json_through_a_symbolic_link_replaces_its_target(self):
        (self.d / "old.json").write_text("old")
        os.symlink("old.json", self.d / "l.json")
        run_ok(["trial", "--spec", "r.json", "--json", "l.json"], self.d)
        self.assertTrue((self.d / "l.json").is_symlink())
        self.assertEqual(json.loads((self.d / "old.json").read_text())["seed"], SEED)

    def test_trial_csv_through_a_dangling_link_creates_its_file(self):
        os.symlink("made.csv", self.d / "l.csv")
        run_ok(["trial", "--spec", "r.json", "--csv", "l.csv"], self.d)
        self.assertTrue((self.d / "l.csv").is_symlink())
        self.assert_csv_is_the_trial("made.csv")

    def test_trial_svg_through_a_link_loop_is_refused(self):
        os.symlink("b.svg", self.d / "a.svg")
        os.symlink("a.svg", self.d / "b.svg")
        result = run(["trial", "一", *SHORT, "--svg", "a.svg"], self.d)
        self.assert_one_error(result, (1, 2), "a.svg")

    def test_trial_record_naming_a_folder_is_refused_before_the_trial(self):
        (self.d / "out").mkdir()
        result = run(["trial", "一", *SHORT, "--record", "out"], self.d)
        self.assert_one_error(result, 1, "--record", "out")

    def test_trial_json_and_csv_on_one_file_through_dot_slash_are_refused(self):
        result = run(["trial", "一", *SHORT, "--json", "o.txt", "--csv", "./o.txt"], self.d)
        self.assert_one_error(result, 2, "--json", "--csv")
        self.assertFalse((self.d / "o.txt").exists())

    def test_trial_output_name_of_255_bytes_is_written_256_refused(self):
        name = "a" * 250 + ".json"
        run_ok(["trial", "--spec", "r.json", "--json", name], self.d)
        self.assertEqual(json.loads((self.d / name).read_text())["seed"], SEED)
        self.assertEqual(temporaries(self.d), [])
        longer = "a" * 251 + ".json"
        self.assert_one_error(run(["trial", "--spec", "r.json", "--json", longer], self.d), 1, "--json")

    def test_trial_of_1000_characters_runs_1001_refused(self):
        result = run(["trial", "一" * 1000, "--max-duration", "0.01", "--json", "o.json"], self.d)
        self.assertIn(result.returncode, (0, 1), result.stderr.decode())
        self.assertEqual(json.loads((self.d / "o.json").read_text())["strokes_total"], 1000)
        self.assert_one_error(run(["trial", "一" * 1001, "--max-duration", "0.01"], self.d), 1, "CHARS", "1000")

    def test_trial_json_naming_a_link_to_a_folder_is_refused(self):
        (self.d / "out").mkdir()
        os.symlink("out", self.d / "l")
        self.assert_one_error(run(["trial", "一", *SHORT, "--json", "l"], self.d), 1, "--json")
        self.assertEqual(list((self.d / "out").iterdir()), [])

    def test_trial_json_past_path_max_is_written_or_refused_in_one_line(self):
        # A relative path of some 4,300 bytes through 17 folders of 250 bytes: past PATH_MAX (4096).
        here = os.getcwd()
        os.chdir(self.d)
        try:
            for _ in range(17):
                os.mkdir("d" * 250)
                os.chdir("d" * 250)
        finally:
            os.chdir(here)
        path = "/".join(["d" * 250] * 17) + "/o.json"
        self.assertGreater(len(path), 4096)
        result = run(["trial", "--spec", "r.json", "--json", path], self.d)
        if result.returncode == 0:
            fd = os.open(self.d, os.O_RDONLY)
            try:
                for _ in range(17):
                    fd2 = os.open("d" * 250, os.O_RDONLY, dir_fd=fd)
                    os.close(fd)
                    fd = fd2
                names = os.listdir(fd)
                self.assertEqual(names, ["o.json"])
            finally:
                os.close(fd)
        else:
            self.assert_one_error(result, 1, "--json")

    def test_trial_race_two_seeds_onto_one_json_leaves_one_whole(self):
        procs = [subprocess.Popen([CLI, "trial", "一", "--writer-profile", "skilled", "--seed", str(seed),
                                   "--max-duration", "3", "--json", "o.json"], cwd=self.d, env=ENV,
                                  stdout=subprocess.DEVNULL, stderr=subprocess.PIPE) for seed in (1, 2)]
        for p in procs:
            _, err = p.communicate(timeout=60)
            self.assertIn(p.returncode, (0, 1), err.decode())
        self.assertIn(json.loads((self.d / "o.json").read_text())["seed"], (1, 2))
        self.assertEqual(temporaries(self.d), [])

    def test_trial_sighup_and_sigusr1_stop_it_with_their_statuses(self):
        for sig in (signal.SIGHUP, signal.SIGUSR1):
            status, err = self.long_trial(sig)
            self.assert_stopped_or_finished(sig, status, err)

    def long_trial(self, sig):
        """`trial 永` of some 0.1 s of CPU with an earlier o.json, `sig` sent at a random moment (while the program
        starts, runs the trial or writes). Returns the status (-N: ended by the signal's default action, before
        its handler was set) and the standard error."""
        (self.d / "o.json").write_text("old")
        (self.d / "o.csv").unlink(missing_ok=True)
        args = [CLI, "trial", "永", "--max-duration", "60", "--seed", "3", "--json", "o.json", "--csv", "o.csv"]
        p = subprocess.Popen(args, cwd=self.d, env=ENV, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
        time.sleep(random.uniform(0.0, 0.3))
        p.send_signal(sig)
        _, err = p.communicate(timeout=60)
        return p.returncode, err.decode()

    def assert_stopped_or_finished(self, sig, status, err):
        """Ended by the signal before it started (nothing written), stopped by it (128 + N, every recorded
        tick written, `end_reason` interrupted), or finished first (0 or 1; 128 + N too when the signal came
        while the files were written): the outputs whole in each case, no temporary, and a record saying
        `interrupted` only with the signal's status."""
        self.assertIn(status, (-sig, 0, 1, 128 + sig), err)
        self.assertEqual(temporaries(self.d), [])
        if status == -sig:
            # Ended by the signal's default action: before the handler was set (nothing written), or after
            # the trial had written its outputs and let its handler go, as the program ended (a trial that
            # finished within the random wait, as one under the sanitizers may not): whole, either way.
            if (self.d / "o.json").read_text() == "old":
                self.assertFalse((self.d / "o.csv").exists())
                return None
            self.assertGreater((self.d / "o.csv").read_text().count("\n") - 1, 0)
            return json.loads((self.d / "o.json").read_text())
        record = json.loads((self.d / "o.json").read_text())
        if record["end_reason"] == "interrupted":
            self.assertEqual(status, 128 + sig, err)
            self.assertIn(signal.Signals(sig).name, record["abort_reason"])
        rows = (self.d / "o.csv").read_text().count("\n") - 1
        self.assertGreater(rows, 0)
        return record

    def test_trial_sigterm_at_a_random_tick_writes_whole_outputs(self):
        status, err = self.long_trial(signal.SIGTERM)
        if self.assert_stopped_or_finished(signal.SIGTERM, status, err) is not None:
            run_ok(["score", "o.csv", "--character", "永"], self.d)

    def test_trial_sigint_at_a_random_tick_writes_whole_outputs(self):
        status, err = self.long_trial(signal.SIGINT)
        self.assert_stopped_or_finished(signal.SIGINT, status, err)

    def test_trial_sigkill_leaves_the_old_file_or_a_whole_new_one(self):
        status, _ = self.long_trial(signal.SIGKILL)
        text = (self.d / "o.json").read_text()
        if text != "old":
            json.loads(text)
        if (self.d / "o.csv").exists():
            run_ok(["score", "o.csv", "--character", "永"], self.d)
        run_ok(["trial", "--spec", "r.json", "--json", "o.json"], self.d)
        self.assertEqual(json.loads((self.d / "o.json").read_text())["seed"], SEED)

    def test_trial_race_two_reruns_onto_one_csv(self):
        procs = [subprocess.Popen([CLI, "trial", "--spec", "r.json", "--csv", "o.csv"], cwd=self.d, env=ENV,
                                  stdout=subprocess.DEVNULL, stderr=subprocess.PIPE) for _ in range(2)]
        for p in procs:
            _, err = p.communicate(timeout=60)
            self.assertEqual(p.returncode, 0, err.decode())
        self.assert_csv_is_the_trial("o.csv")
        self.assertEqual(temporaries(self.d), [])

    # ---- trace --csv: kill ----

    def big_h5(self):
        if not hasattr(Round25A, "_big_h5"):
            d = self.tmp
            # 永 at 3 kHz: a trace of some 55,000 rows, so that a signal lands while it is written.
            protocol = dict(PROTOCOL, name="big", trial={"max_duration_s": 60, "rate_hz": 3000})
            protocol["test"] = dict(PROTOCOL["test"], characters=["永"])
            (d / "big.json").write_text(json.dumps(protocol, ensure_ascii=False), encoding="utf-8")
            run_ok(["session", "run", "big.json", "--writer", "simulated", "--subjects", "1", "--out", "B"], d)
            Round25A._big_h5 = next((d / "B").glob("S01/*/trials/*.trace.h5"))
        return Round25A._big_h5

    def kill_trace(self, sig):
        h5 = self.big_h5()
        (self.d / "o.csv").write_text("old")
        p = subprocess.Popen([CLI, "trace", str(h5), "--csv", "o.csv"], cwd=self.d, env=ENV,
                             stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
        time.sleep(random.uniform(0.0, 0.1))
        p.send_signal(sig)
        _, err = p.communicate(timeout=60)
        text = (self.d / "o.csv").read_text()
        if text != "old":
            self.assertTrue(text.startswith("t,x,y,z,") and text.endswith("\n"), text[-200:])
        self.assertTrue(text == "old" or p.returncode == 0, (p.returncode, err))
        return p.returncode, err.decode()

    def test_trace_sigterm_while_writing_leaves_no_temporary(self):
        self.kill_trace(signal.SIGTERM)
        self.assertEqual(temporaries(self.d), [])
        run_ok(["trace", self.big_h5(), "--csv", "o.csv"], self.d)

    def test_trace_sigkill_while_writing_keeps_the_old_file_or_a_whole_new_one(self):
        self.kill_trace(signal.SIGKILL)
        run_ok(["trace", self.big_h5(), "--csv", "o.csv"], self.d)
        import h5py
        with h5py.File(self.big_h5(), "r") as f:
            samples = int(f.attrs["samples"])
        self.assertEqual((self.d / "o.csv").read_text().count("\n"), samples + 1)

    # ---- the store (--store) and the character files (--data) ----

    def test_store_cut_in_the_middle_is_refused_naming_it(self):
        data = (self.tmp / "st.clg").read_bytes()
        (self.d / "c.clg").write_bytes(data[:len(data) // 2])
        self.assert_one_error(run(["model", "一", "--store", "c.clg"], self.d), 1, "c.clg")

    def test_store_of_zero_bytes_is_refused_naming_it(self):
        (self.d / "c.clg").write_bytes(b"")
        self.assert_one_error(run(["characters", "--store", "c.clg"], self.d), 1, "c.clg")

    def test_store_through_a_symbolic_link_is_read(self):
        os.symlink(self.tmp / "st.clg", self.d / "l.clg")
        got = json.loads(run_ok(["characters", "--store", "l.clg", "--json"], self.d).stdout)
        self.assertEqual(got["count"], 3)

    def test_model_svg_onto_the_store_is_refused(self):
        shutil.copy(self.tmp / "st.clg", self.d / "st.clg")
        result = run(["model", "一", "--store", "st.clg", "--svg", "./st.clg"], self.d)
        self.assert_one_error(result, 2, "--store", "--svg")
        self.assertEqual((self.d / "st.clg").read_bytes(), (self.tmp / "st.clg").read_bytes())

    def test_store_given_a_gzip_is_refused_naming_it(self):
        (self.d / "x.clg").write_bytes(gzip.compress((self.tmp / "st.clg").read_bytes()))
        self.assert_one_error(run(["model", "一", "--store", "x.clg"], self.d), 1, "x.clg")

    def test_store_given_a_record_is_refused_naming_it(self):
        self.assert_one_error(run(["trial", "一", *SHORT, "--store", "r.json"], self.d), 1, "r.json")

    def test_character_file_forged_stroke_count_is_refused_naming_it(self):
        shutil.copytree(self.tmp / "hw", self.d / "hw")
        c = json.loads((self.d / "hw" / "十.json").read_text())
        c["medians"] = c["medians"][:1]
        (self.d / "hw" / "十.json").write_text(json.dumps(c))
        self.assert_one_error(run(["model", "十", "--data", "hw"], self.d), 1, "十.json")

    def test_character_file_cut_is_refused_naming_it(self):
        shutil.copytree(self.tmp / "hw", self.d / "hw")
        data = (self.d / "hw" / "一.json").read_bytes()
        (self.d / "hw" / "一.json").write_bytes(data[:len(data) // 2])
        self.assert_one_error(run(["model", "一", "--data", "hw"], self.d), 1, "一.json")

    def test_character_file_as_a_link_loop_is_refused_naming_it(self):
        shutil.copytree(self.tmp / "hw", self.d / "hw")
        (self.d / "hw" / "一.json").unlink()
        os.symlink("一.json", self.d / "hw" / "一.json")
        self.assert_one_error(run(["model", "一", "--data", "hw"], self.d), 1, "一.json")

    def test_character_file_in_utf16_is_refused_naming_it(self):
        shutil.copytree(self.tmp / "hw", self.d / "hw")
        text = (self.d / "hw" / "一.json").read_text(encoding="utf-8")
        (self.d / "hw" / "一.json").write_bytes(text.encode("utf-16"))
        self.assert_one_error(run(["model", "一", "--data", "hw"], self.d), 1, "一.json")

    def test_model_svg_onto_a_character_file_under_data_is_refused(self):
        shutil.copytree(self.tmp / "hw", self.d / "hw")
        before = (self.d / "hw" / "二.json").read_bytes()
        result = run(["model", "一", "--data", "hw", "--svg", "hw/../hw/二.json"], self.d)
        self.assert_one_error(result, 2, "--data", "--svg")
        self.assertEqual((self.d / "hw" / "二.json").read_bytes(), before)

    def test_characters_store_as_a_link_loop_is_refused_naming_it(self):
        os.symlink("b.clg", self.d / "a.clg")
        os.symlink("a.clg", self.d / "b.clg")
        self.assert_one_error(run(["characters", "--store", "a.clg"], self.d), 1, "a.clg")

    def test_store_replaced_by_a_character_file_is_refused_naming_it(self):
        shutil.copy(self.tmp / "hw" / "一.json", self.d / "x.clg")
        self.assert_one_error(run(["characters", "--store", "x.clg", "--strokes", "1"], self.d), 1, "x.clg")

    # ---- model --svg, strokes --markdown, bench acceptance --markdown ----

    def test_model_svg_through_a_dangling_link_creates_its_file(self):
        os.symlink("made.svg", self.d / "l.svg")
        run_ok(["model", "一", "--svg", "l.svg"], self.d)
        self.assertTrue((self.d / "l.svg").is_symlink())
        self.assertEqual((self.d / "made.svg").read_bytes(), self.model_svg)

    def test_model_svg_naming_a_folder_is_refused(self):
        (self.d / "out").mkdir()
        self.assert_one_error(run(["model", "一", "--svg", "out"], self.d), 1, "--svg", "out")

    def test_model_svg_race_two_runs_onto_one_file(self):
        procs = [subprocess.Popen([CLI, "model", "一", "--svg", "m.svg"], cwd=self.d, env=ENV,
                                  stdout=subprocess.DEVNULL, stderr=subprocess.PIPE) for _ in range(2)]
        for p in procs:
            _, err = p.communicate(timeout=60)
            self.assertEqual(p.returncode, 0, err.decode())
        self.assertEqual((self.d / "m.svg").read_bytes(), self.model_svg)
        self.assertEqual(temporaries(self.d), [])

    def test_strokes_markdown_through_a_link_keeps_the_link(self):
        (self.d / "t.md").write_text("old\n")
        os.symlink("t.md", self.d / "l.md")
        run_ok(["strokes", "--markdown", "l.md"], self.d)
        self.assertTrue((self.d / "l.md").is_symlink())
        self.assertIn("|", (self.d / "t.md").read_text())

    def test_strokes_markdown_naming_a_folder_is_refused(self):
        (self.d / "out").mkdir()
        self.assert_one_error(run(["strokes", "--markdown", "out"], self.d), 1, "--markdown", "out")

    def test_bench_acceptance_markdown_onto_a_character_file_is_refused(self):
        shutil.copytree(self.tmp / "hw", self.d / "hw")
        before = (self.d / "hw" / "一.json").read_bytes()
        result = run(["bench", "acceptance", "--characters", "2", "--data", "hw",
                      "--markdown", "hw/./一.json"], self.d)
        self.assert_one_error(result, 2, "--markdown", "--data")
        self.assertEqual((self.d / "hw" / "一.json").read_bytes(), before)


if __name__ == "__main__":
    unittest.main()
