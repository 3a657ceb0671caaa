#!/usr/bin/env python3
"""The record is the specification (docs/cli.md, "Re-running a trial"), run by CTest as `trial_replay_cli`: a
trial record of every front-end that writes one through the program (`trial --json`, `session run` with a
learning subject), with a non-default value in every part it can set, is run again by `trial --spec RECORD` to the same
trace, byte for byte, on the simulated device; what cannot be re-run is refused by name.

CALLIGRAPHY_CLI names the program. Standard library only.
"""
import json
import os
import subprocess
import tempfile
import unittest
from pathlib import Path

CLI = os.environ.get("CALLIGRAPHY_CLI", "")

# A protocol whose conditions set the force law's parts a specification alone does not: stiffness, error
# amplification's bound, fading's schedule; a quiz condition with its own acceptance.
PROTOCOL = {
    "format": "calligraphy-study-protocol",
    "version": 1,
    "name": "replayed",
    "conditions": [
        {"name": "fade", "mode": "fading", "guidance_stiffness_n_per_m": 310,
         "parameters": {"start_gain": 0.7, "forgetting_factor": 0.6, "error_gain_per_m": 150}},
        {"name": "amplify", "mode": "error-amplification", "guidance_stiffness_n_per_m": 250,
         "parameters": {"amplification_gain": 0.2, "max_force_n": 0.21}},
        {"name": "quiz", "mode": "quiz", "quiz": {"acceptance": {"corridor_m": 0.007}}},
        {"name": "replay", "mode": "replay", "parameters": {"max_lead_m": 0.0025}},
    ],
    "phases": [
        {"phase": "training", "condition": "fade", "characters": ["十"], "repetitions": 2},
        {"phase": "training", "condition": "amplify", "characters": ["人"]},
        {"phase": "training", "condition": "replay", "characters": ["十"]},
        {"phase": "post-test", "condition": "quiz", "characters": ["十"]},
    ],
    "trial": {"max_duration_s": 20, "rate_hz": 800},
}


class ReplayTest(unittest.TestCase):
    def setUp(self):
        if not CLI:
            self.skipTest("CALLIGRAPHY_CLI is not set")
        self.folder = tempfile.TemporaryDirectory()
        self.cwd = Path(self.folder.name)

    def tearDown(self):
        self.folder.cleanup()

    def run_cli(self, *args, timeout=600):
        return subprocess.run([CLI, *map(str, args)], cwd=self.cwd, capture_output=True, timeout=timeout)

    def ok(self, *args):
        result = self.run_cli(*args)
        self.assertEqual(result.returncode, 0, result.stderr.decode())
        return result

    def rerun_to(self, record, csv_name):
        """The trace of `trial --spec record`; a trial that ended as the record's did exits 0, or 1 naming how
        it ended early (a writer who gave up), its outputs written either way."""
        result = self.run_cli("trial", "--spec", record, "--csv", csv_name, "--json", csv_name + ".json")
        end = json.loads((self.cwd / record).read_text())["end_reason"]
        if end == "completed":
            self.assertEqual(result.returncode, 0, result.stderr.decode())
        else:
            self.assertIn(result.returncode, (0, 1), result.stderr.decode())
        self.assertEqual(json.loads((self.cwd / (csv_name + ".json")).read_text())["end_reason"], end)
        return (self.cwd / csv_name).read_bytes()

    def test_a_trial_json_runs_again_to_the_same_trace(self):
        self.ok("trial", "永", "--guidance-mode", "fading", "--guidance-gain", "0.4", "--writer-profile", "foreign",
                "--writer-param", "bias_offset_m=0.0035", "--seed", "77", "--rate", "700", "--max-duration", "40",
                "--json", "first.json", "--csv", "first.csv")
        first = json.loads((self.cwd / "first.json").read_text())
        spec = first["specification"]
        self.assertEqual(spec["format"], "calligraphy-trial-specification")
        # Every part is there, including what the old record left out.
        for key in ("off_stroke_force_n", "off_stroke_travel_m", "off_stroke_damping_n_s_per_m",
                    "off_stroke_speed_m_s", "off_stroke_velocity_cutoff_hz"):
            self.assertIn(key, spec["force_law"])
        self.assertEqual(spec["force_law"]["guidance_law"], {"mode": "fading", "gain": 0.4})
        self.assertEqual(spec["writer"]["bias_offset_m"], 0.0035)
        again = self.rerun_to("first.json", "again.csv")
        self.assertEqual(again, (self.cwd / "first.csv").read_bytes())
        # The re-run's record states the same trial.
        self.assertEqual(json.loads((self.cwd / "again.csv.json").read_text())["specification"], spec)

    def test_session_records_run_again_to_their_saved_traces(self):
        (self.cwd / "p.json").write_text(json.dumps(PROTOCOL, ensure_ascii=False))
        # A learning subject with its own traits: what it has learned is in the profile each record holds.
        self.ok("session", "run", "p.json", "--subject", "S01", "--out", "out", "--writer-profile", "foreign",
                "--writer-learning", "two-state")
        records = sorted((self.cwd / "out").rglob("trials/*.json"))
        self.assertEqual(len(records), 5, [str(r) for r in records])
        profiles = {json.dumps(json.loads(r.read_text())["specification"]["writer"], sort_keys=True) for r in records}
        self.assertGreater(len(profiles), 1, "the learning subject wrote every trial with one profile")
        modes = set()
        for number, record in enumerate(records):
            document = json.loads(record.read_text())
            spec = document["specification"]
            modes.add(spec["force_law"]["guidance_law"]["mode"] if spec["force_law"]["guidance"] else "off")
            # The saved HDF5 trace as trial --csv's text (`calligraphy trace`), byte for byte.
            saved = self.ok("trace", record.with_suffix(".trace.h5")).stdout
            with self.subTest(record=str(record.relative_to(self.cwd))):
                self.assertEqual(self.rerun_to(record, f"r{number}.csv"), saved)
        # The conditions' own values reached the record: stiffness and bound from the protocol.
        amplified = [json.loads(r.read_text())["specification"]["force_law"] for r in records
                     if json.loads(r.read_text())["condition"] == "amplify"]
        self.assertTrue(amplified)
        for force in amplified:
            self.assertEqual(force["guidance_stiffness_n_per_m"], 250)
            self.assertEqual(force["guidance_law"], {"mode": "error-amplification", "gain": 0.2, "max_force_n": 0.21})
        # A replay re-runs on the teacher kept in the session folder (the record names it and its SHA-256).
        self.assertTrue({"fading", "error-amplification", "replay", "off"} <= modes, modes)

    def test_what_cannot_be_run_again_is_refused_by_name(self):
        self.ok("trial", "十", "--json", "r.json", "--max-duration", "60")
        both = self.run_cli("trial", "十", "--spec", "r.json")
        self.assertEqual(both.returncode, 2)
        self.assertIn("CHARS", both.stderr.decode())
        option = self.run_cli("trial", "--spec", "r.json", "--guidance", "off")
        self.assertEqual(option.returncode, 2)
        self.assertIn("--guidance", option.stderr.decode())
        document = json.loads((self.cwd / "r.json").read_text())
        del document["specification"]
        (self.cwd / "old.json").write_text(json.dumps(document))
        old = self.run_cli("trial", "--spec", "old.json")
        self.assertEqual(old.returncode, 2)
        self.assertIn("old.json", old.stderr.decode())
        self.assertIn("no trial specification", old.stderr.decode())
        document = json.loads((self.cwd / "r.json").read_text())
        document["specification"]["version"] = 10
        (self.cwd / "newer.json").write_text(json.dumps(document))
        newer = self.run_cli("trial", "--spec", "newer.json")
        self.assertEqual(newer.returncode, 2)
        self.assertIn("newer.json: /specification/version", newer.stderr.decode())
        document = json.loads((self.cwd / "r.json").read_text())
        document["specification"]["scene"]["sha256"] = "0" * 64
        (self.cwd / "other.json").write_text(json.dumps(document))
        other = self.run_cli("trial", "--spec", "other.json")
        self.assertEqual(other.returncode, 1)
        self.assertIn("not the recorded ones", other.stderr.decode())
        missing = self.run_cli("trial", "--spec", "absent.json")
        self.assertNotEqual(missing.returncode, 0)
        self.assertIn("absent.json", missing.stderr.decode())


if __name__ == "__main__":
    unittest.main()
