"""One trace, one metrics record: `calligraphy trial --json`, `calligraphy score`, a study session's trial
record, `calligraphy.simulate_trial(...).metrics` and `calligraphy.score(...)` give the same keys and values
for the same trace (docs/metrics.md, "The one metrics record")."""

import json
import subprocess
from pathlib import Path

import pytest

import calligraphy

# The keys of the one metrics record.
RECORD_KEYS = ("strokes_total", "strokes_written", "strokes_accepted", "refusals", "completed_in_order",
               "order_errors", "backwards_strokes", "unmatched_segments", "mean_deviation_m", "max_deviation_m",
               "rms_deviation_m", "frechet_m", "dtw_m", "total_time_s", "pen_down_time_s", "velocity_peaks",
               "normalised_jerk", "per_character")
SOURCE = Path(__file__).resolve().parents[2]


def record_of(document):
    return {key: document[key] for key in RECORD_KEYS}


def approx_record(document):
    """The record as a trace file gives it back: numbers to the trace's precision (times to 1 us, lengths to
    0.1 um: docs/experiments.md), counts, flags and texts exactly."""
    def approx(value):
        if isinstance(value, dict):
            return {key: approx(item) for key, item in value.items()}
        if isinstance(value, list):
            return [approx(item) for item in value]
        if isinstance(value, float):
            return pytest.approx(value, rel=1e-6, abs=1e-9)
        return value
    return approx(record_of(document))


def cli_json(cli, cwd, *args):
    out = Path(cwd) / "out.json"
    completed = subprocess.run([cli, *args, "--json", str(out)], cwd=cwd, capture_output=True)
    assert completed.returncode == 0, completed.stderr.decode()
    return json.loads(out.read_text(encoding="utf-8"))


@pytest.mark.parametrize("characters, guidance, seed", [("永", "off", 5), ("口九", "on", 2)])
def test_trial_score_and_python_agree_on_one_trace(cli, tmp_path, characters, guidance, seed):
    trial = cli_json(cli, tmp_path, "trial", characters, "--guidance", guidance, "--seed", str(seed), "--csv",
                     "trace.csv")
    assert trial["strokes_written"] > 0  # something to compare
    scored = cli_json(cli, tmp_path, "score", "trace.csv", "--character", characters)
    assert record_of(scored) == approx_record(trial)
    simulated = calligraphy.simulate_trial(characters, guidance=guidance == "on", seed=seed, keep_trace=False)
    assert record_of(simulated.metrics) == record_of(trial)
    if len(characters) == 1:  # calligraphy.score takes one character
        assert record_of(calligraphy.score(str(tmp_path / "trace.csv"), characters)) == approx_record(trial)


def test_a_session_record_is_the_score_of_its_own_trace(cli, tmp_path):
    protocol = json.loads((SOURCE / "examples" / "protocols" / "paper-table5.json").read_text(encoding="utf-8"))
    del protocol["practice"]
    protocol["test"].update({"characters": ["永"], "conditions": ["haptic"], "repetitions": 1})
    protocol["order"]["conditions"] = "fixed"
    protocol["breaks"] = {}
    (tmp_path / "small.json").write_text(json.dumps(protocol), encoding="utf-8")
    run = subprocess.run([cli, "session", "run", "small.json", "--writer", "simulated", "--subjects", "1", "--out",
                          "study"], cwd=tmp_path, capture_output=True)
    assert run.returncode == 0, run.stderr.decode()
    (session,) = (tmp_path / "study" / "S01").iterdir()
    (record_file,) = (session / "trials").glob("*.json")
    record = json.loads(record_file.read_text(encoding="utf-8"))
    csv = record_file.parent / record["files"]["trace"]  # the trace, HDF5 (score reads it as a CSV trace)
    assert csv.name.endswith(".trace.h5")
    assert record["strokes_written"] > 0
    scored = cli_json(cli, tmp_path, "score", str(csv), "--character", "永")
    assert record_of(scored) == approx_record(record)
    assert record_of(calligraphy.score(str(csv), "永")) == approx_record(record)
