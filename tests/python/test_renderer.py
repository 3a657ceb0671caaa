"""The per-tick renderer from Python: states of Table 2 and the paper force of eq. (9)."""

import gc

import numpy as np
import pytest

import calligraphy

States = calligraphy.InteractionState


@pytest.fixture
def scene():
    return calligraphy.Scene("永")


def state_at(x, y, z, t=0.0):
    return calligraphy.DeviceState(position_m=(x, y, z), velocity_m_s=(0.0, 0.0, 0.0), time_s=t)


def test_free_pen_gives_zero_force(scene):
    renderer = calligraphy.Renderer(scene)
    output = renderer.tick(state_at(0.0, 0.0, 0.01))
    assert output.state == States.separation and renderer.state == States.separation
    np.testing.assert_array_equal(output.force_n, [0.0, 0.0, 0.0])
    # Touching outside the character's box: AS, still no force (Table 2).
    box = scene.characters[0].bounding_box_m
    outside = box[1] + 0.02
    output = renderer.tick(state_at(outside[0], outside[1], -0.001, 0.001))
    assert output.state == States.adjusting
    np.testing.assert_array_equal(output.force_n, [0.0, 0.0, 0.0])


def test_pressing_at_the_start_point_writes_and_the_paper_pushes_back(scene):
    law = calligraphy.ForceLawParameters(paper_stiffness_n_per_m=800.0)
    renderer = calligraphy.Renderer(scene, law, options=calligraphy.RendererOptions(rate_hz=1000.0))
    start = scene.strokes[0].start_m
    depth = 0.001
    outputs = [renderer.tick(state_at(start[0], start[1], -depth, k * 1e-3)) for k in range(1500)]
    assert outputs[-1].state == States.writing
    assert outputs[-1].stroke == 0 and outputs[-1].element == 0 and not outputs[-1].finished
    # After the fade-in and the start ramp: K_en * depth out of the paper, nothing in the plane (the tip
    # is on the stroke and at rest).
    np.testing.assert_allclose(outputs[-1].force_n, [0.0, 0.0, 800.0 * depth], atol=1e-6)
    # On the way there no tick stepped the force by more than the safety chain allows.
    forces = np.array([o.force_n for o in outputs])
    steps = np.linalg.norm(np.diff(forces, axis=0), axis=1)
    assert steps.max() <= calligraphy.SafetyChainParameters().max_force_change_n_per_tick + 1e-12
    assert any("start_ramp" in o.limit_names for o in outputs)


def test_non_finite_state_gives_zero_force(scene):
    renderer = calligraphy.Renderer(scene)
    start = scene.strokes[0].start_m
    for k in range(300):
        renderer.tick(state_at(start[0], start[1], -0.001, k * 1e-3))
    output = renderer.tick(state_at(np.nan, start[1], -0.001, 0.3))
    assert output.input_rejected
    np.testing.assert_array_equal(output.force_n, [0.0, 0.0, 0.0])
    renderer.reset()
    assert renderer.state == States.separation


def test_renderer_keeps_its_scene_alive():
    renderer = calligraphy.Renderer(calligraphy.Scene("九"))
    gc.collect()
    assert renderer.scene.stroke_count == 2
    start = renderer.scene.strokes[0].start_m
    assert renderer.tick(state_at(start[0], start[1], 0.01)).state == States.separation


def test_renderer_rejects_bad_arguments(scene):
    with pytest.raises(TypeError, match="scene"):
        calligraphy.Renderer("永")
    with pytest.raises(ValueError, match="rate_hz"):
        calligraphy.RendererOptions(rate_hz=10.0)
    with pytest.raises(ValueError, match="max_force_n"):
        calligraphy.Renderer(scene, device=calligraphy.DeviceInfo(max_force_n=0.0))
    renderer = calligraphy.Renderer(scene)
    with pytest.raises(TypeError, match="state"):
        renderer.tick((0.0, 0.0, 0.0))
