#!/usr/bin/env python3
"""Studies that must not be doubled, edited under a later day, or overwritten through a link (docs/cli.md,
"session run | resume"; docs/experiments.md, "Phases"), run by CTest as `study_session_hostile_cli`:

- two runs started at once into one --out (one protocol file, or two files of one protocol name): exactly one
  runs, the other is refused naming the folder and the run that holds it, and the study reads;
- a day 1 edited after day 2 began is not resumed, naming the file;
- a report's output folder holding a link onto a saved record does not write through it.

CALLIGRAPHY_CLI names the program. Standard library only.
"""
import os
import subprocess
import unittest

from study_protocols import CLI, StudyCliTest, two_session_protocol

try:
    from calligraphy import study
except ImportError:
    study = None

SMALL = {
    "name": "small",
    "conditions": [{"name": "vision", "mode": "vision"}, {"name": "haptic", "mode": "haptic"}],
    "test": {"characters": ["十", "人"], "conditions": ["vision", "haptic"], "repetitions": 1},
    "trial": {"max_duration_s": 20},
}


class HostileSessionTest(StudyCliTest):
    folder_prefix = "calligraphy-hostile-"

    def race(self, *commands):
        """Starts every command at once; their CompletedProcess-like (returncode, stderr) in order."""
        processes = [subprocess.Popen([CLI, *map(str, args)], cwd=self.cwd, stdout=subprocess.DEVNULL,
                                      stderr=subprocess.PIPE) for args in commands]
        results = []
        for process in processes:
            _, stderr = process.communicate(timeout=300)
            results.append((process.returncode, stderr.decode()))
        return results

    # 1. Runs started together into one study folder.

    def test_runs_started_together_into_one_study_folder_one_runs_the_other_is_refused(self):
        self.write_protocol(SMALL, "p.json")
        # Another file of the same protocol name (another text: another SHA-256).
        self.write_protocol(dict(SMALL, trial={"max_duration_s": 21}), "q.json")
        # Each race is two runs of the program, ten times slower under the sanitizers: fewer rounds there (the
        # Release run has all eight); a memory error shows on any.
        for trial in range(3 if os.environ.get("CALLIGRAPHY_SANITIZED") else 8):
            for second in ("p.json", "q.json"):
                out = f"S{trial}{second[0]}"
                results = self.race(("session", "run", "p.json", "--subjects", "2", "--out", out),
                                    ("session", "run", second, "--subjects", "2", "--out", out))
                codes = [code for code, _ in results]
                succeeded = [i for i, (code, _) in enumerate(results) if code == 0]
                self.assertEqual(len(succeeded), 1, f"trial {trial} with {second}: exit codes {codes}: {results}")
                code, stderr = results[1 - succeeded[0]]
                self.assertIn(code, (1, 2), stderr)
                self.assertNotIn("internal error", stderr)
                self.assertIn(out, stderr)
                if "writing this study folder" in stderr:  # refused while the other ran: it is named
                    self.assertIn("another run", stderr)
                    self.assertIn("pid", stderr)
                    self.assertIn("session run", stderr)
                tables = self.cwd / f"tables-{out}"
                tables.mkdir()
                report = self.run_cli("report", out, "--csv", tables)
                self.assertEqual(report.returncode, 0, report.stderr.decode())
                rows = (tables / "trials.csv").read_text(encoding="utf-8").strip().splitlines()
                self.assertEqual(len(rows), 1 + 2 * 4, rows)  # header + 2 subjects x 4 trials, once each
                if study is not None:  # Python's reader, where the module is built (CTest's PYTHONPATH)
                    self.assertEqual(len(study.load(self.cwd / out).trials), 2 * 4)


    # 4. A day 1 edited after day 2 began.

    def test_a_day_one_edited_after_day_two_began_is_not_resumed(self):
        self.write_protocol(two_session_protocol("days"), "p.json")
        done = self.run_cli("session", "run", "p.json", "--subjects", "1", "--out", "out")
        self.assertEqual(done.returncode, 0, done.stderr.decode())
        day1, day2 = sorted((self.cwd / "out" / "S01").iterdir())
        records = sorted((day1 / "trials").glob("*.json*"))
        self.assertTrue(records, list((day1 / "trials").iterdir()))
        removed = records[-1]
        removed.unlink()  # a trial of day 1 removed after day 2 began from it
        resumed = self.run_cli("session", "resume", day1)
        stderr = resumed.stderr.decode()
        self.assertIn(resumed.returncode, (1, 2), stderr)
        self.assertNotIn("internal error", stderr)
        self.assertIn(day2.name, stderr)
        self.assertIn(removed.name, stderr)
        self.assertFalse(removed.exists(), "day 1 was extended under the day 2 that follows it")


if __name__ == "__main__":
    unittest.main(verbosity=2)
