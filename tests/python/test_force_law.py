"""Signs and magnitudes of the force-law terms (paper section 5), single and vectorised."""

import numpy as np
import pytest

import calligraphy


@pytest.fixture
def law():
    return calligraphy.ForceLawParameters(
        guidance_stiffness_n_per_m=400.0, paper_stiffness_n_per_m=800.0, resistance_damping_n_s_per_m=15.0
    )


def test_parameters_are_kept(law):
    assert law.guidance_stiffness_n_per_m == 400.0
    assert law.paper_stiffness_n_per_m == 800.0
    assert law.resistance_damping_n_s_per_m == 15.0
    assert law.guidance is True


def test_paper_force_pushes_out_of_the_paper(law):
    k = law.paper_stiffness_n_per_m
    np.testing.assert_allclose(calligraphy.paper_force(-0.002, 0.0, k), [0.0, 0.0, 800.0 * 0.002])
    np.testing.assert_array_equal(calligraphy.paper_force(0.003, 0.0, k), [0.0, 0.0, 0.0])
    z = np.array([-0.004, -0.001, 0.0, 0.001])
    f = calligraphy.paper_force(z, paper_z_m=0.0, stiffness_n_per_m=k)
    assert f.shape == (4, 3)
    np.testing.assert_allclose(f[:, 2], [3.2, 0.8, 0.0, 0.0])
    assert np.all(f[:, :2] == 0.0)
    # Relative to a raised paper plane.
    assert calligraphy.paper_force(0.009, 0.01, k)[2] == pytest.approx(0.8)


def test_attraction_pulls_towards_the_foot_point(law):
    tip = np.array([0.01, 0.003])
    foot = np.array([0.01, 0.0])
    k = law.guidance_stiffness_n_per_m
    f = calligraphy.attraction_force(tip, foot, k, attraction_factor=0.5)
    np.testing.assert_allclose(f, 400.0 * 0.5 * (foot - tip))
    assert f[1] < 0  # towards the stroke, not away (the paper's printed sign is wrong)
    rng = np.random.default_rng(3)
    tips = rng.normal(scale=0.005, size=(50, 2))
    feet = rng.normal(scale=0.005, size=(50, 2))
    forces = calligraphy.attraction_force(tips, feet, k)
    assert forces.shape == (50, 2)
    assert np.all(np.einsum("ij,ij->i", forces, feet - tips) >= 0.0)
    np.testing.assert_allclose(forces, 400.0 * (feet - tips))


def test_resistance_opposes_only_backward_motion(law):
    tangent = np.array([1.0, 0.0])
    b = law.resistance_damping_n_s_per_m
    np.testing.assert_array_equal(calligraphy.resistance_force([0.05, 0.01], tangent, b), [0.0, 0.0])
    f = calligraphy.resistance_force([-0.02, 0.01], tangent, b)
    np.testing.assert_allclose(f, [15.0 * 0.02, 0.0])
    v = np.array([[0.01, 0.0], [-0.01, 0.0], [0.0, 0.02], [-0.03, -0.03]])
    forces = calligraphy.resistance_force(v, tangent, b)
    assert forces.shape == (4, 2)
    np.testing.assert_allclose(forces[:, 0], [0.0, 0.15, 0.0, 0.45])
    assert np.all(forces[:, 1] == 0.0)


def test_clamp_keeps_direction_and_zeroes_non_finite():
    f = calligraphy.clamp_force([3.0, 4.0, 0.0], 2.5)
    np.testing.assert_allclose(f, [1.5, 2.0, 0.0])
    np.testing.assert_array_equal(calligraphy.clamp_force([0.1, 0.2, 0.3], 2.5), [0.1, 0.2, 0.3])
    many = calligraphy.clamp_force(np.array([[10.0, 0.0, 0.0], [np.nan, 0.0, 1.0], [0.0, 0.0, -1.0]]), 2.0)
    np.testing.assert_allclose(many, [[2.0, 0.0, 0.0], [0.0, 0.0, 0.0], [0.0, 0.0, -1.0]])


def test_smoothing_and_friction_parameters_are_exposed():
    law = calligraphy.ForceLawParameters(friction_coefficient=0.3, crossfade_s=0.1, constraint_taper_m=0.001)
    assert law.friction_coefficient == 0.3
    assert law.crossfade_s == 0.1
    assert law.constraint_taper_m == 0.001
    assert calligraphy.ForceLawParameters().friction_stick_speed_m_s > 0.0
    with pytest.raises(ValueError, match="constraint_taper_m"):
        calligraphy.ForceLawParameters(constraint_radius_m=0.002, constraint_taper_m=0.003)
    with pytest.raises(ValueError, match="friction_coefficient"):
        calligraphy.ForceLawParameters(friction_coefficient=-0.1)
