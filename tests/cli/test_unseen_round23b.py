#!/usr/bin/env python3
"""Round 23B: the worst input at every documented limit, for time and memory. From the docs alone (docs/cli.md
"Pen traces: format and limits", "session run", "Exit status"; docs/experiments.md "Protocols", "Sessions";
docs/corpus.md on the character-data loader; docs/metrics.md on the curve metrics; each command's --help).

Earlier rounds checked each limit and one past it with simple content. This one builds the input AT a limit whose
content makes the work largest: one pen-down segment of the most samples zig-zagging across a stroke end to end,
the most segments of three samples each, a trace header of a hundred thousand columns with the ones read last,
protocols and records nested half a million deep or a hundred thousand keys wide within their byte limit, a
session of the most planned trials (16 characters a string, the library's characters of the most strokes), a
trial of the most characters of many strokes, a character of the most medians and points, a median of the most
points zig-zagging, and a character file near its byte limit of the longest outlines.

Each run has an address-space limit (RLIMIT_AS, 1 GiB unless said) and the hang timeout; the documented outcome
must follow (processed, or one error line naming the limit), never killed by the limit, never an abort. No case
asserts a time. Cases that cost seconds at the limit are measured in docs/testing.md, not run here.

CALLIGRAPHY_CLI names the program. CALLIGRAPHY_SANITIZED=1 takes five cases.
"""
import json
import resource
import shutil
import subprocess
import sys
import tempfile
import unittest
from pathlib import Path

from outsider import ENV, SANITIZED, OneErrorLine, run, sanitized_subset

load_tests = sanitized_subset({"test_the_most_segments_of_three_samples_are_each_scored",
                               "test_a_protocol_nested_half_a_million_deep_is_one_error_line",
                               "test_a_protocol_of_a_hundred_thousand_unknown_keys_names_the_first",
                               "test_a_character_of_the_most_medians_and_points_is_modelled",
                               "test_one_segment_past_the_most_is_refused_at_its_line"})

GIB = 1 << 30
HANG_S = 60


def address_space(limit):
    def set_limit():
        resource.setrlimit(resource.RLIMIT_AS, (limit, limit))
    return set_limit


def bounded(args, cwd, limit=GIB):
    """The program under an address-space limit and the hang timeout (subprocess raises TimeoutExpired on a
    hang, which fails the case). Under the sanitizers, whose shadow memory needs terabytes of address space,
    the hang timeout alone: the outcome is still checked."""
    return run(args, cwd, timeout=HANG_S, preexec_fn=None if SANITIZED else address_space(limit))


def trace(path, rows):
    path.write_text("t,x,y,pen\n" + "".join(rows), encoding="ascii")


def protocol(name, strings, conditions=1, repetitions=1, **extra):
    p = {"name": name, "conditions": [{"name": f"C{i}", "mode": "vision"} for i in range(conditions)],
         "test": {"characters": strings, "conditions": [f"C{i}" for i in range(conditions)],
                  "repetitions": repetitions},
         "trial": {"max_duration_s": 0.01}}
    p.update(extra)
    return p


class Round23B(unittest.TestCase, OneErrorLine):
    @classmethod
    def setUpClass(cls):
        cls.tmp = Path(tempfile.mkdtemp(prefix="round23b-"))

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.tmp, ignore_errors=True)

    def assert_processed(self, result):
        text = result.stderr.decode("utf-8", "replace")
        self.assertEqual(result.returncode, 0, text)
        self.assertNotIn("terminate called", text)
        self.assertNotIn("out of memory", text)

    def folder(self, name):
        d = self.tmp / name
        d.mkdir()
        return d

    # --- score: the traces at their limits --------------------------------------------------------------------

    def test_one_segment_of_the_most_samples_zigzagging_along_a_stroke_is_scored(self):
        # 1,000,000 samples (the limit), one pen-down, each from one end of 一's stroke to the other: the longest
        # written curve the trace can hold; the curve metrics resample it to 2000 points (docs/metrics.md).
        d = self.folder("zigzag")
        ends = ("121", "920")
        trace(d / "z.csv", (f"{i},{ends[i % 2]},{400 + i % 7},1\n" for i in range(1_000_000)))
        result = bounded(["score", "z.csv", "--character", "一", "--units", "data", "--json", "-"], d)
        self.assert_processed(result)
        score = json.loads(result.stdout)
        self.assertEqual(score["samples"], 1_000_000)
        self.assertEqual(len(score["per_character"][0]["segments"]), 1)

    def test_the_most_segments_of_three_samples_are_each_scored(self):
        # 10,000 pen-downs (the limit) of three samples across 十 near its first stroke: each tried on every stroke.
        d = self.folder("segments")
        rows = []
        for s in range(10_000):
            t = 4 * s
            rows += [f"{t},121,400,1\n", f"{t + 1},500,400,1\n", f"{t + 2},920,400,1\n", f"{t + 3},920,400,0\n"]
        trace(d / "s.csv", rows)
        result = bounded(["score", "s.csv", "--character", "十", "--units", "data", "--json", "-"], d)
        self.assert_processed(result)
        score = json.loads(result.stdout)
        self.assertEqual(len(score["per_character"][0]["segments"]), 10_000)

    def test_one_segment_past_the_most_is_refused_at_its_line(self):
        # 10,001 one-sample pen-downs: refused at the line of the first one too many, the rest unread.
        d = self.folder("past")
        trace(d / "p.csv", (f"{2 * s},500,400,1\n{2 * s + 1},500,400,0\n" for s in range(10_001)))
        result = bounded(["score", "p.csv", "--character", "一", "--units", "data"], d)
        # The header is line 1; pen-down k (from 0) starts on line 2 + 2k.
        self.assert_one_error(result, 1, "p.csv:20002", "10000")

    def test_a_header_of_a_hundred_thousand_columns_read_last_is_read(self):
        # Other columns are ignored (docs/cli.md "score"): 100,000 of them before t, x, y and pen.
        d = self.folder("wide")
        extra = 100_000
        header = ",".join([f"c{i}" for i in range(extra)] + ["t", "x", "y", "pen"])
        filler = "0," * extra
        rows = "".join(f"{filler}{i},{121 + 40 * i},400,1\n" for i in range(20))
        (d / "w.csv").write_text(header + "\n" + rows, encoding="ascii")
        result = bounded(["score", "w.csv", "--character", "一", "--units", "data", "--json", "-"], d)
        self.assert_processed(result)
        self.assertEqual(json.loads(result.stdout)["samples"], 20)

    def test_a_header_of_a_hundred_thousand_columns_with_the_last_named_twice_names_it(self):
        # A name given twice is refused naming it (docs/cli.md "score"), here the last of 100,001 columns.
        d = self.folder("wide-twice")
        names = ["t", "x", "y", "pen"] + [f"c{i}" for i in range(100_000)] + ["c99999"]
        (d / "w.csv").write_text(",".join(names) + "\n" + "0," * 100_004 + "0\n", encoding="ascii")
        self.assert_one_error(bounded(["score", "w.csv", "--character", "一", "--units", "data"], d), 1,
                              "w.csv:1", "c99999", "twice")

    def test_python_scores_the_most_segments_from_columns_and_refuses_one_more(self):
        # docs/python.md: `score` refuses more than 10,000 pen-down segments from columns as from a file.
        code = """
import resource
resource.setrlimit(resource.RLIMIT_AS, (1 << 30, 1 << 30))
import numpy as np, calligraphy
n = 10_000
columns = {"t": np.arange(4.0 * n), "x": np.tile([121.0, 500.0, 920.0, 920.0], n), "y": np.full(4 * n, 400.0),
           "pen": np.tile([1.0, 1.0, 1.0, 0.0], n)}
print(len(calligraphy.score(columns, "十", units="data")["per_character"][0]["segments"]))
more = {k: np.append(v, [4.0 * n, 4.0 * n + 1] if k == "t" else [500.0, 500.0] if k != "pen" else [1.0, 0.0])
        for k, v in columns.items()}
try:
    calligraphy.score(more, "十", units="data")
except calligraphy.InvalidArgument as e:
    print(str(e))
"""
        result = subprocess.run([sys.executable, "-c", code], capture_output=True, timeout=HANG_S, env=ENV)
        self.assertEqual(result.returncode, 0, result.stderr.decode("utf-8", "replace"))
        lines = result.stdout.decode("utf-8").splitlines()
        self.assertEqual(lines[0], "10000")
        self.assertEqual(len(lines), 2, lines)
        self.assertIn("10001 pen-down segments", lines[1])
        self.assertIn("10000", lines[1])

    # --- JSON within the byte limits, nested deep and wide ----------------------------------------------------

    def test_a_protocol_nested_half_a_million_deep_is_one_error_line(self):
        # 1,000,000 bytes of brackets, within the 1 MiB of a protocol.
        d = self.folder("deep")
        depth = 500_000
        (d / "p.json").write_text('{"name":"d","description":' + "[" * depth + "]" * depth + "}", encoding="ascii")
        self.assert_one_error(bounded(["session", "plan", "p.json", "--subjects", "1"], d), 2, "p.json",
                              "/description")

    def test_a_protocol_nested_a_hundred_thousand_objects_deep_is_one_error_line(self):
        d = self.folder("deep-objects")
        depth = 100_000
        (d / "p.json").write_text('{"name":"d","x":' + '{"a":' * depth + "1" + "}" * depth + "}", encoding="ascii")
        self.assert_one_error(bounded(["session", "plan", "p.json", "--subjects", "1"], d), 2, "p.json")

    def test_a_record_nested_two_million_deep_is_one_error_line(self):
        d = self.folder("deep-record")
        depth = 2_000_000
        (d / "r.json").write_text('{"format":"calligraphy-study-trial","specification":' + "[" * depth +
                                  "]" * depth + "}", encoding="ascii")
        self.assert_one_error(bounded(["trial", "--spec", "r.json", "--check"], d), 2, "r.json")

    def test_a_protocol_of_a_hundred_thousand_unknown_keys_names_the_first(self):
        d = self.folder("wide-keys")
        body = json.dumps(protocol("w", ["一"]))[:-1]
        (d / "p.json").write_text(body + "," + ",".join(f'"k{i}":0' for i in range(90_000)) + "}",
                                  encoding="ascii")
        self.assertLess((d / "p.json").stat().st_size, 1 << 20)
        self.assert_one_error(bounded(["session", "plan", "p.json", "--subjects", "1"], d), 2, "p.json", "/k0")

    def test_a_protocol_of_a_half_million_element_array_names_its_pointer(self):
        d = self.folder("wide-array")
        body = json.dumps(protocol("w", ["一"]))[:-1]
        (d / "p.json").write_text(body + ',"description":[' + ",".join(["0"] * 500_000) + "]}", encoding="ascii")
        self.assertLess((d / "p.json").stat().st_size, 1 << 20)
        self.assert_one_error(bounded(["session", "plan", "p.json", "--subjects", "1"], d), 2, "p.json",
                              "/description")

    # --- protocols at their trial limit -----------------------------------------------------------------------

    @classmethod
    def most_strokes_first(cls):
        # The library's characters, those of the most strokes first (`characters --json`), listed once.
        if not hasattr(cls, "_most_strokes_first"):
            listed = json.loads(bounded(["characters", "--json"], cls.tmp).stdout)["characters"]
            cls._most_strokes_first = [c["character"] for c in sorted(listed, key=lambda c: -c["strokes"])]
        return cls._most_strokes_first

    def big_strings(self):
        # 1,000 distinct strings of 16 characters (the most a string holds), of the library's 9,000 characters of
        # the most strokes.
        chars = self.most_strokes_first()[:9000]
        return ["".join(chars[(9 * i + k) % len(chars)] for k in range(16)) for i in range(1000)]

    def test_a_plan_one_trial_past_the_limit_is_refused_naming_its_size(self):
        # 1,000 strings x 1 condition x 1,000 repetitions + one practice trial: 1,000,001.
        d = self.folder("plan-past")
        p = protocol("past", self.big_strings(), repetitions=1000)
        p["practice"] = {"characters": ["一"], "condition": "C0", "repetitions": 1}
        (d / "p.json").write_text(json.dumps(p, ensure_ascii=False), encoding="utf-8")
        self.assert_one_error(bounded(["session", "plan", "p.json", "--subjects", "1"], d), 2, "p.json",
                              "1,000,001", "1,000,000")

    def test_a_latin_square_of_the_most_conditions_for_the_most_subjects_is_planned(self):
        # 26 conditions (the most) in a Latin square, 1,000 subjects (the most `--subjects` takes).
        d = self.folder("square")
        p = protocol("square", ["一"], conditions=26, order={"conditions": "latin_square"})
        (d / "p.json").write_text(json.dumps(p), encoding="ascii")
        result = bounded(["session", "plan", "p.json", "--subjects", "1000", "--json"], d)
        self.assert_processed(result)
        subjects = json.loads(result.stdout)["subjects"]
        self.assertEqual(len(subjects), 1000)
        self.assertEqual(len({s["id"] for s in subjects}), 1000)
        names = sorted(f"C{i}" for i in range(26))
        orders = set()
        for s in subjects:
            blocks = [b["condition"] for b in s["sessions"][0]["phases"][0]["blocks"]]
            self.assertEqual(sorted(blocks), names)
            orders.add(tuple(blocks))
        self.assertEqual(len(orders), 26)  # the square's 26 rows, each subject on one

    def test_a_session_of_the_most_trials_is_refused_by_its_manifest_size_before_any_folder(self):
        # 1,000,000 planned trials (the limit) need about 250 MB of session.json, more than the 64 MiB every
        # reader takes: refused naming the session, its trials and its size, before anything is made.
        d = self.folder("run-most")
        (d / "p.json").write_text(json.dumps(protocol("most", self.big_strings(), repetitions=1000),
                                             ensure_ascii=False), encoding="utf-8")
        result = bounded(["session", "run", "p.json", "--subject", "S01", "--out", "out", "--writer", "simulated"], d)
        self.assert_one_error(result, 1, "1000000", "64 MiB")
        self.assertFalse((d / "out" / "S01").exists())

    # --- scenes and characters at their limits ----------------------------------------------------------------

    def test_a_trial_of_the_most_characters_of_many_strokes_ends_at_its_time_limit(self):
        d = self.folder("scene")
        result = bounded(["trial", "鼎" * 1000, "--max-duration", "0.01", "--json", "r.json"], d)
        self.assert_one_error(result, 1, "time_limit")
        record = json.loads((d / "r.json").read_text(encoding="utf-8"))
        self.assertEqual(record["end_reason"], "time_limit")
        self.assertEqual(len(record["per_character"]), 1000)

    def test_a_trial_of_the_thousand_characters_of_the_most_strokes_ends_at_its_time_limit(self):
        d = self.folder("scene-distinct")
        chars = "".join(self.most_strokes_first()[:1000])
        result = bounded(["trial", chars, "--max-duration", "0.01", "--json", "r.json"], d)
        self.assert_one_error(result, 1, "time_limit")
        record = json.loads((d / "r.json").read_text(encoding="utf-8"))
        self.assertEqual([c["character"] for c in record["per_character"]], list(chars))

    def write_character(self, d, name, medians, strokes=None):
        data = d / "data"
        data.mkdir(exist_ok=True)
        doc = {"medians": medians} if strokes is None else {"strokes": strokes, "medians": medians}
        (data / f"{name}.json").write_text(json.dumps(doc), encoding="ascii")

    def test_a_character_of_the_most_medians_and_points_is_modelled(self):
        # 128 medians (the most), 20,000 points in all (the most), each median zig-zagging across the box.
        d = self.folder("medians")
        medians = []
        for s in range(128):
            n = 20_000 // 128 + (20_000 % 128 if s == 0 else 0)
            medians.append([[50 + 900 * k // (n - 1) + 3 * (k % 2), 50 + 7 * s + 5 * (k % 2)] for k in range(n)])
        self.write_character(d, "丁", medians)
        result = bounded(["model", "丁", "--data", "data", "--json"], d)
        self.assert_processed(result)
        self.assertEqual(len(json.loads(result.stdout)["strokes"]), 128)
        self.assert_one_error(bounded(["trial", "丁", "--data", "data", "--max-duration", "0.01"], d), 1,
                              "time_limit")

    def test_a_median_of_the_most_points_zigzagging_is_modelled(self):
        # One median of 10,000 points (the most for one), each 40 units off the last, and 127 of two points.
        d = self.folder("median")
        medians = [[[50 + 900 * k // 9999, 500 + 40 * (k % 2)] for k in range(10_000)]]
        medians += [[[50, 10 + 7 * s], [950, 10 + 7 * s]] for s in range(127)]
        self.write_character(d, "七", medians)
        result = bounded(["model", "七", "--data", "data", "--json"], d)
        self.assert_processed(result)
        self.assertEqual(len(json.loads(result.stdout)["strokes"]), 128)

    def test_a_character_file_near_its_byte_limit_of_the_longest_outlines_is_read(self):
        # 15 outlines of 1,048,575 bytes (the most a path may have) in a file under 16 MiB.
        d = self.folder("outlines")
        step = "L 900 900 L 100 100 "
        path = "M 100 100 " + step * ((1_048_575 - 12) // len(step))
        path += " " * (1_048_575 - len(path) - 1) + "Z"
        medians = [[[50 + 900 * k // 99, 100 + 7 * s + 3 * (k % 2)] for k in range(100)] for s in range(128)]
        self.write_character(d, "三", medians, [path] * 15 + ["M 0 0 L 1 1 Z"] * 113)
        self.assertLess((d / "data" / "三.json").stat().st_size, 16 << 20)
        result = bounded(["model", "三", "--data", "data", "--json"], d)
        self.assert_processed(result)
        self.assertEqual(len(json.loads(result.stdout)["strokes"]), 128)


if __name__ == "__main__":
    unittest.main()
