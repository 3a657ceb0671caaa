"""A teacher's recording from a simulated trial, its file, and replay guidance with it."""

import numpy as np
import pytest

import calligraphy

CHARACTER = "天"


@pytest.fixture(scope="module")
def skilled_trial():
    return calligraphy.simulate_trial(CHARACTER, writer="skilled", guidance=True, seed=5)


def test_recording_holds_the_trace(skilled_trial):
    recording = calligraphy.record_teacher(skilled_trial)
    assert recording.characters == CHARACTER
    assert recording.writer == "skilled" and recording.device == "simulated"
    assert len(recording) == skilled_trial.time_s.size
    assert recording.samples[10].time_s == skilled_trial.time_s[10]
    np.testing.assert_array_equal(recording.samples[10].position_m, skilled_trial.position_m[10])


def test_file_round_trip_is_exact_and_atomic(skilled_trial, tmp_path):
    path = tmp_path / "teacher.json"
    written = calligraphy.record_teacher(skilled_trial, path)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["teacher.json"]  # no temporary left behind
    read = calligraphy.TeacherRecording.load(path)
    assert read.to_json() == written.to_json()
    assert calligraphy.TeacherRecording.from_json(path.read_text(encoding="utf-8")).to_json() == read.to_json()
    # An empty name is refused, not taken as the current folder.
    with pytest.raises(calligraphy.InvalidArgument, match="path: empty"):
        read.save("")
    with pytest.raises(calligraphy.InvalidArgument, match="path: empty"):
        calligraphy.record_teacher(skilled_trial, "")


def test_replayed_teacher_guides_a_novice_through_in_order(skilled_trial, tmp_path):
    path = tmp_path / "teacher.json"
    calligraphy.record_teacher(skilled_trial, path)
    teacher = calligraphy.TeacherRecording.load(path)
    for seed in range(3):
        result = calligraphy.simulate_trial(CHARACTER, writer="novice", teacher=teacher, seed=seed,
                                            keep_trace=False)
        assert result.metrics["completed_in_order"], seed


def test_teacher_samples_list_works_like_the_recording(skilled_trial):
    recording = calligraphy.record_teacher(skilled_trial)
    a = calligraphy.simulate_trial(CHARACTER, teacher=recording, seed=1, keep_trace=False).metrics
    b = calligraphy.simulate_trial(CHARACTER, guidance_mode="replay", teacher=list(recording.samples), seed=1,
                                   keep_trace=False).metrics
    assert a == b


def test_teacher_of_other_characters_is_refused(skilled_trial):
    recording = calligraphy.record_teacher(skilled_trial)
    with pytest.raises(calligraphy.InvalidArgument, match="teacher"):
        calligraphy.simulate_trial("大", teacher=recording, keep_trace=False)


def test_recording_needs_a_trace():
    result = calligraphy.simulate_trial(CHARACTER, writer="skilled", keep_trace=False)
    with pytest.raises(calligraphy.InvalidArgument, match="trace"):
        calligraphy.record_teacher(result)


def test_bad_files_are_named(tmp_path):
    with pytest.raises(calligraphy.DataError, match="missing.json"):
        calligraphy.TeacherRecording.load(tmp_path / "missing.json")
    bad = tmp_path / "bad.json"
    bad.write_text('{"format": "calligraphy-teacher-recording", "version": 1}', encoding="utf-8")
    with pytest.raises(calligraphy.DataError, match="bad.json"):
        calligraphy.TeacherRecording.load(bad)
    # A number beyond a double's range is a data error naming the file and its JSON pointer.
    overflow = tmp_path / "overflow.json"
    overflow.write_text('{"format": "calligraphy-teacher-recording", "version": 1, "rate_hz": 1e999}',
                        encoding="utf-8")
    with pytest.raises(calligraphy.DataError, match="overflow.json: /rate_hz: not a finite number"):
        calligraphy.TeacherRecording.load(overflow)
