"""Scenes and placements: data units <-> metres on the paper, both ways, vectorised."""

import numpy as np
import pytest

import calligraphy


@pytest.fixture(scope="module")
def scene():
    return calligraphy.Scene("永我九")


def test_placement_maps_both_ways_vectorised():
    placement = calligraphy.Placement(origin_m=(0.01, -0.02), metres_per_unit=5e-5)
    rng = np.random.default_rng(4)
    data = rng.uniform(-124, 1024, size=(50, 2))
    paper = placement.to_paper(data)
    assert paper.shape == (50, 2) and paper.dtype == np.float64
    np.testing.assert_allclose(paper, np.array([0.01, -0.02]) + 5e-5 * data, rtol=0, atol=1e-15)
    np.testing.assert_allclose(placement.to_data(paper), data, rtol=0, atol=1e-9)
    # One point gives one point; rows equal the single calls.
    np.testing.assert_array_equal(placement.to_paper(data[7]), paper[7])
    assert placement.to_data([0.01, -0.02]).shape == (2,)
    with pytest.raises(ValueError, match="points"):
        placement.to_paper(np.zeros((3, 3)))
    with pytest.raises(ValueError, match="metres_per_unit"):
        calligraphy.Placement(metres_per_unit=0.0)


def test_scene_places_each_character_by_its_placement(scene, library):
    assert [c.char for c in scene.characters] == ["永", "我", "九"]
    assert scene.stroke_count == sum(len(library.load(ch)) for ch in "永我九") == len(scene.strokes)
    for placed in scene.characters:
        model = library.load(placed.char)
        for placed_stroke, stroke in zip(placed.strokes, model.strokes):
            assert placed_stroke.typical_id == stroke.typical_id
            np.testing.assert_array_equal(placed_stroke.attraction_factors, stroke.attraction_factors)
            np.testing.assert_allclose(placed_stroke.median_m, placed.placement.to_paper(stroke.median), atol=1e-15)
            for placed_element, element in zip(placed_stroke.elements, stroke.elements):
                np.testing.assert_allclose(
                    placed_element.control_points, placed.placement.to_paper(element.control_points), atol=1e-15
                )
            np.testing.assert_array_equal(placed_stroke.start_m, placed_stroke.elements[0].control_points[0])
            assert placed_stroke.length_m == pytest.approx(sum(e.arc_length() for e in placed_stroke.elements))
        # The bounding box holds every control point, with the layout's margin.
        box = placed.bounding_box_m
        assert box.shape == (2, 2)
        points = np.vstack([e.control_points for s in placed.strokes for e in s.elements])
        assert np.all(points >= box[0]) and np.all(points <= box[1])


def test_layout_sets_size_spacing_and_centre(library):
    layout = calligraphy.SceneLayout(character_size_m=0.04, spacing_m=0.05, centre_m=(0.1, 0.2))
    scene = calligraphy.Scene([library.load("永"), library.load("九")], layout=layout)
    assert scene.layout == layout
    scales = [c.placement.metres_per_unit for c in scene.characters]
    assert scales == pytest.approx([0.04 / 1024] * 2)
    # Centres of the data boxes: spacing apart, around centre_m.
    centres = [c.placement.to_paper([512.0, 388.0]) for c in scene.characters]
    np.testing.assert_allclose(centres[1] - centres[0], [0.05, 0.0], atol=1e-12)
    np.testing.assert_allclose((centres[0] + centres[1]) / 2, [0.1, 0.2], atol=1e-12)
    with pytest.raises(ValueError):
        calligraphy.SceneLayout(spacing_m=-0.01)
    with pytest.raises(TypeError, match="layout"):
        calligraphy.Scene("永", layout={"spacing_m": 0.05})


def test_scene_rejects_bad_characters():
    with pytest.raises(KeyError):
        calligraphy.Scene("龘")
    with pytest.raises(ValueError):
        calligraphy.Scene([])
    with pytest.raises(TypeError, match="characters"):
        calligraphy.Scene(7)
