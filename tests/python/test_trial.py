"""Simulated trials from Python: the trace arrays and the metrics, against `calligraphy trial --json`."""

import json
import subprocess

import numpy as np
import pytest

import calligraphy

@pytest.fixture(scope="module")
def yong_seed3():
    return calligraphy.simulate_trial("永", seed=3)


def run_cli(cli, tmp_path, *args):
    out = tmp_path / "trial.json"
    subprocess.run([cli, "trial", *args, "--json", str(out)], check=True, capture_output=True)
    return json.loads(out.read_text(encoding="utf-8"))


def keys(document):
    """The keys of a JSON document, recursively: {key: keys of its value} for dicts, lists by element."""
    if isinstance(document, dict):
        return {key: keys(value) for key, value in document.items()}
    if isinstance(document, list):
        return [keys(item) for item in document]
    return None


def test_metrics_have_the_keys_of_the_cli_json(cli, tmp_path, yong_seed3):
    expected = run_cli(cli, tmp_path, "永", "--seed", "3")
    # One list of keys, in the same order, down to the per-stroke entries.
    assert list(yong_seed3.metrics) == list(expected)
    assert keys(yong_seed3.metrics) == keys(expected)
    assert len(yong_seed3.metrics["per_character"][0]["per_stroke"]) == 5


def test_metrics_equal_the_cli(cli, tmp_path, yong_seed3):
    expected = run_cli(cli, tmp_path, "永", "--seed", "3")
    assert yong_seed3.metrics == expected


def test_metrics_equal_the_cli_skilled_unguided(cli, tmp_path):
    expected = run_cli(cli, tmp_path, "九", "--seed", "11", "--writer-profile", "skilled", "--guidance", "off")
    result = calligraphy.simulate_trial("九", writer="skilled", guidance=False, seed=11, keep_trace=False)
    assert result.metrics == expected
    assert result.time_s.shape == (0,)


def test_trace_arrays(yong_seed3):
    r = yong_seed3
    n = r.time_s.shape[0]
    assert n > 1000
    assert r.position_m.shape == (n, 3) and r.force_n.shape == (n, 3)
    assert r.state.shape == (n,) and r.stroke.shape == (n,) and r.element.shape == (n,)
    assert r.state.dtype == np.uint8 and r.stroke.dtype == np.int64
    np.testing.assert_allclose(np.diff(r.time_s), 1e-3, rtol=1e-6)
    assert set(np.unique(r.state)) <= {int(s) for s in calligraphy.InteractionState.__members__.values()}
    assert calligraphy.InteractionState.writing.short_name == "WS"
    # Writing happened, and forces are zero in SS and AS (Table 2) once the fade-out after leaving CS or
    # WS is over (ForceLawParameters.paper_fade_s = 0.2 s, crossfade_s = 0.05 s: docs/force-rendering.md).
    states = calligraphy.InteractionState
    assert np.any(r.state == states.writing)
    free = (r.state == states.separation) | (r.state == states.adjusting)
    touching = np.where(~free, np.arange(n), -1)
    last_touching = np.maximum.accumulate(touching)
    settled = free & ((np.arange(n) - last_touching) > 200)
    assert np.count_nonzero(settled) > 1000
    assert np.all(r.force_n[settled] == 0.0)
    m = r.metrics
    assert np.max(np.linalg.norm(r.force_n, axis=1)) == pytest.approx(m["max_force_n"], rel=1e-12)
    assert np.max(np.linalg.norm(np.diff(r.force_n, axis=0), axis=1)) == pytest.approx(m["max_force_step_n"], rel=1e-9)
    assert np.count_nonzero(np.diff(r.state.astype(int))) == m["state_transitions"]
    assert r.stroke.min() == 0 and r.stroke.max() <= m["strokes_total"] - 1
    assert np.all(np.diff(r.stroke) >= 0)


def test_characters_can_be_given_as_objects(library, yong_seed3):
    by_object = calligraphy.simulate_trial(library.load("永"), seed=3, keep_trace=False)
    assert by_object.metrics == yong_seed3.metrics
    group = calligraphy.simulate_trial([library.load("九"), library.load("心")], seed=2, keep_trace=False)
    assert group.metrics["character"] == "九心"
    assert group.metrics["strokes_total"] == len(library.load("九")) + len(library.load("心"))


def test_deterministic_for_a_seed_and_seed_matters():
    a = calligraphy.simulate_trial("心", seed=5, keep_trace=False).metrics
    b = calligraphy.simulate_trial("心", seed=5, keep_trace=False).metrics
    c = calligraphy.simulate_trial("心", seed=6, keep_trace=False).metrics
    assert a == b
    assert a["mean_deviation_m"] != c["mean_deviation_m"]


def test_simulated_device_moves_with_the_force():
    parameters = calligraphy.SimulatedDeviceParameters(initial_position_m=(0.0, 0.0, 0.02))
    device = calligraphy.SimulatedDevice(parameters)
    start = device.read_state().position_m
    np.testing.assert_allclose(start, [0.0, 0.0, 0.02], atol=3e-5)
    device.write_force([1.0, 0.0, 0.0])
    for _ in range(100):
        device.advance(1e-3)
    state = device.read_state()
    assert state.time_s == pytest.approx(0.1)
    assert state.position_m[0] > 0.01  # x = F t^2 / 2m ~ 0.025 m, less damping
    assert abs(state.position_m[1]) < 1e-4
    assert device.true_velocity_m_s[0] > 0
    device.write_force([100.0, 0.0, 0.0])
    assert np.linalg.norm(device.applied_force_n) == pytest.approx(device.info.max_force_n)
