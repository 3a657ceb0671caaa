"""Every hanzi-writer-data character from Python with no data folder and no store file: the default
library falls back to the corpus store compiled into the module (docs/corpus.md)."""

import pathlib
import random

import pytest

import calligraphy

EMBEDDED = {p.stem for p in (pathlib.Path(__file__).resolve().parents[2] / "data" / "hanzi-writer-data").glob("*.json")}


@pytest.fixture(scope="module")
def store_characters():
    """A few characters of the store that are not embedded, drawn at random (seeded): none is named here."""
    library = calligraphy.CharacterLibrary.default()
    pool = [c for c in library.characters() if c not in EMBEDDED]
    return random.Random(20261126).sample(pool, 3)


def test_the_default_library_holds_every_character():
    library = calligraphy.CharacterLibrary.default()
    assert len(library) == 9574
    assert "(9574: 58 embedded, the others from the bundled corpus store)" in library.description
    assert "龘" not in library  # not in hanzi-writer-data either
    embedded = calligraphy.CharacterLibrary.embedded()  # the small set alone, for quick sweeps
    assert set(embedded.characters()) == EMBEDDED
    assert all(c in library for c in EMBEDDED)


def test_a_store_character_is_modelled_with_its_medians(store_characters):
    library = calligraphy.CharacterLibrary.default()
    for char in store_characters:
        assert char in library
        model = library.load(char)
        assert model.char == char and len(model.strokes) > 0
        for stroke in model.strokes:
            assert stroke.median.shape[0] >= 2 and stroke.median.shape[1] == 2
            assert 1 <= stroke.typical_id <= 39


def test_a_store_character_is_written_in_a_trial_and_scored(store_characters):
    for char in store_characters:
        trial = calligraphy.simulate_trial(char, writer="skilled", seed=4)
        strokes = len(calligraphy.CharacterLibrary.default().load(char).strokes)
        assert trial.metrics["strokes_total"] == strokes
        assert trial.metrics["completed_in_order"] is True, char
        assert trial.metrics["strokes_accepted"] == strokes, char
        p = trial.position_m
        score = calligraphy.score({"t": trial.time_s, "x": p[:, 0], "y": p[:, 1], "z": p[:, 2]}, char)
        assert score["strokes_total"] == strokes
        assert score["completed_in_order"] is True, char
        assert score["strokes_accepted"] == strokes, char
