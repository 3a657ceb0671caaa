"""Loading characters, the typical strokes and the element data from Python."""

import json
import pathlib
import subprocess

import numpy as np
import pytest

import calligraphy


def test_default_library_lists_and_loads(library):
    chars = library.characters()
    assert "永" in chars and "永" in library
    assert "龘" not in library
    assert chars == sorted(chars, key=ord)
    yong = library.load("永")
    assert yong.char == "永" and yong.code_point == 0x6C38
    assert len(yong) == len(yong.strokes) == 5
    assert yong.typical_stroke_ids == [s.typical_id for s in yong.strokes]


def test_strokes_and_elements_are_consistent(library):
    for ch in ("永", "我", "九", "心"):
        character = library.load(ch)
        for stroke in character.strokes:
            assert 1 <= stroke.typical_id <= 39
            assert stroke.acronym == calligraphy.TYPICAL_STROKES[stroke.typical_id - 1].acronym
            elements = stroke.elements
            assert elements
            fp = stroke.feature_points
            assert fp.shape == (len(elements) + 1, 2)
            assert stroke.attraction_factors.shape == (len(elements) + 1,)
            for k, element in enumerate(elements):
                cp = element.control_points
                assert cp.shape == (element.degree + 1, 2)
                assert cp.dtype == np.float64
                assert element.kind == ("line" if element.degree == 1 else "bezier")
                # Elements are joined at the feature points.
                np.testing.assert_allclose(cp[0], fp[k])
                np.testing.assert_allclose(cp[-1], fp[k + 1])
                # Control points lie in or near the 1024 data box (y up, -124..900).
                assert np.all(cp[:, 0] > -100) and np.all(cp[:, 0] < 1124)
                assert np.all(cp[:, 1] > -224) and np.all(cp[:, 1] < 1000)


def test_element_point_matches_bernstein_form(library):
    element = next(e for s in library.load("永").strokes for e in s.elements if e.degree >= 2)
    cp = element.control_points
    n = element.degree
    t = np.linspace(0.0, 1.0, 11)
    from math import comb

    expected = sum(comb(n, i) * ((1 - t) ** (n - i) * t**i)[:, None] * cp[i] for i in range(n + 1))
    np.testing.assert_allclose(element.point(t), expected, rtol=0, atol=1e-9)
    np.testing.assert_allclose(element.point(0.5), expected[5], rtol=0, atol=1e-9)


def test_typical_strokes_table():
    strokes = calligraphy.TYPICAL_STROKES
    assert len(strokes) == 39
    assert [s.id for s in strokes] == list(range(1, 40))
    acronyms = [s.acronym for s in strokes]
    assert len(set(acronyms)) == 39
    assert {"H", "S", "P", "D", "HZG"} <= set(acronyms)
    for s in strokes:
        assert s.name_zh and s.pinyin
        assert s.unicode is None or 0x31C0 <= ord(s.unicode) <= 0x31E5
        assert len(s.pieces) >= 1 and (s.compound or len(s.pieces) == 1)
        for piece in s.pieces:
            assert piece.kind in ("line", "bezier")
            assert piece.min_length <= piece.max_length


def test_typical_stroke_by_acronym_and_id():
    hzg = calligraphy.typical_stroke("HZG")
    assert hzg.acronym == "HZG" and hzg.name_zh == "横折钩"
    assert calligraphy.typical_stroke(hzg.id).acronym == "HZG"
    for s in calligraphy.TYPICAL_STROKES:
        assert calligraphy.typical_stroke(s.acronym).id == s.id
        assert calligraphy.typical_stroke(s.id).acronym == s.acronym
    assert calligraphy.typical_stroke(np.int64(1)).acronym == calligraphy.TYPICAL_STROKES[0].acronym
    with pytest.raises(ValueError, match="XYZ"):
        calligraphy.typical_stroke("XYZ")
    with pytest.raises(ValueError, match="40"):
        calligraphy.typical_stroke(40)
    with pytest.raises(TypeError, match="key"):
        calligraphy.typical_stroke(1.5)


def test_from_hanzi_writer_folder(tmp_path):
    # A minimal hanzi-writer-data file: one straight horizontal median.
    doc = {"strokes": ["M 100 400 L 900 400"], "medians": [[[100, 400], [500, 410], [900, 420]]]}
    (tmp_path / "一.json").write_text(json.dumps(doc), encoding="utf-8")
    lib = calligraphy.CharacterLibrary.from_hanzi_writer(str(tmp_path))
    assert lib.characters() == ["一"]
    one = lib.load("一")
    assert len(one.strokes) == 1
    assert one.strokes[0].acronym == "H"
    np.testing.assert_allclose(one.strokes[0].feature_points[0], [100, 400], atol=1e-9)
    np.testing.assert_allclose(one.strokes[0].feature_points[-1], [900, 420], atol=1e-9)


@pytest.fixture(scope="module")
def store_path(cli, tmp_path_factory):
    """A corpus store of the embedded set, built by `calligraphy corpus build`."""
    data = pathlib.Path(__file__).resolve().parents[2] / "data" / "hanzi-writer-data"
    path = tmp_path_factory.mktemp("store") / "embedded.store"
    subprocess.run([cli, "corpus", "build", "--data", str(data), "--out", str(path), "--threads", "1"],
                   check=True, capture_output=True)
    return path


def test_from_store_matches_the_fitted_characters(store_path):
    store = calligraphy.CharacterLibrary.from_store(store_path)
    # The store was built from the embedded characters' files: compare with those, fitted when loaded.
    library = calligraphy.CharacterLibrary.from_hanzi_writer(
        pathlib.Path(__file__).resolve().parents[2] / "data" / "hanzi-writer-data")
    assert store.characters() == library.characters()
    assert len(store) == len(library)
    info = store.store_info
    assert info["character_count"] == len(library)
    assert info["version"] == "1.2" and info["medians"] and info["outlines"]
    assert library.store_info is None
    for ch in ("永", "我"):
        stored, fitted = store.load(ch), library.load(ch)
        assert stored.typical_stroke_ids == fitted.typical_stroke_ids
        for s_stored, s_fitted in zip(stored.strokes, fitted.strokes):
            np.testing.assert_array_equal(s_stored.median, s_fitted.median)  # kept exactly (integers)
            np.testing.assert_allclose(s_stored.attraction_factors, s_fitted.attraction_factors)
            # Control points are quantised to 1 / steps_per_unit data units.
            error = np.abs(s_stored.feature_points - s_fitted.feature_points).max()
            assert error <= info["max_quantisation_error"] + 1e-9
    with pytest.raises(calligraphy.CharacterNotFound, match=r"U\+9F98"):
        store.load("龘")
    # A store's character trains like a fitted one.
    result = calligraphy.simulate_trial("永", library=store, seed=3, keep_trace=False)
    assert result.metrics["strokes_total"] == 5


def test_from_store_rejects_a_bad_file(tmp_path):
    with pytest.raises(calligraphy.DataError, match="missing.store"):
        calligraphy.CharacterLibrary.from_store(tmp_path / "missing.store")
    junk = tmp_path / "junk.store"
    junk.write_bytes(b"not a corpus store" * 10)
    with pytest.raises(calligraphy.DataError, match="junk.store"):
        calligraphy.CharacterLibrary.from_store(str(junk))
