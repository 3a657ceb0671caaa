"""A quiz condition's records credit a stroke assisted (docs/experiments.md, "The quiz"):
after the acceptance's assist_after_misses misses the quiz's stroke_assisted event follows the miss, the next
stroke is expected, and the record counts the credit apart from the strokes written; with 0 never."""
import json
import re
import subprocess

import pytest

PROTOCOL = {
    "name": "quiz-credit",
    "conditions": [{"name": "Q1", "mode": "quiz", "quiz": {"acceptance": {"assist_after_misses": 1}}},
                   {"name": "Q0", "mode": "quiz", "quiz": {"acceptance": {"assist_after_misses": 0}}}],
    "test": {"characters": ["一", "十", "人"], "conditions": ["Q1", "Q0"], "repetitions": 2},
    "trial": {"max_duration_s": 6},
}


@pytest.fixture(scope="module")
def folder(cli, tmp_path_factory):
    folder = tmp_path_factory.mktemp("quiz")
    (folder / "p.json").write_text(json.dumps(PROTOCOL, ensure_ascii=False), encoding="utf-8")
    subprocess.run([cli, "session", "run", "p.json", "--subjects", "2", "--writer-profile", "foreign", "--out",
                    "st"], cwd=folder, check=True, capture_output=True)
    return folder


@pytest.fixture(scope="module")
def records(folder):
    return [json.loads(p.read_text(encoding="utf-8")) for p in sorted(folder.glob("st/*/*/trials/*.json"))]


def test_the_quiz_credits_as_the_score_and_counts_the_credit_apart(records):
    assert len(records) == 2 * 2 * 3 * 2  # subjects, conditions, characters, repetitions
    credited = {"Q1": 0, "Q0": 0}
    for record in records:
        quiz = record["quiz"]
        assist = {"Q1": 1, "Q0": 0}[record["condition"]]
        assert quiz["assist_after_misses"] == quiz["acceptance"]["assist_after_misses"] == assist
        events = [e for c in quiz["characters"] for e in c["events"]]
        kinds = [e["kind"] for e in events]
        # Each credit right after the miss that earned it, on the same stroke, with the misses that earned it.
        for i, event in enumerate(events):
            if event["kind"] == "stroke_assisted":
                assert events[i - 1]["kind"] == "stroke_missed"
                assert events[i - 1]["stroke"] == event["stroke"]
                assert event["misses_on_stroke"] == assist
        assert quiz["strokes_assisted"] == kinds.count("stroke_assisted")
        assert quiz["strokes_accepted"] == kinds.count("stroke_accepted")
        # Where the quiz gave no credit its verdicts are score_trace's on the same trace (with a credit they
        # may part: the quiz counts every mismatch as a miss, as Hanzi Writer does, the score only attempts
        # begun in the stroke's start neighbourhood, as the renderer does).
        if quiz["strokes_assisted"] == 0 and sum(c["strokes_assisted"] for c in record["per_character"]) == 0:
            assert quiz["strokes_accepted"] == record["strokes_accepted"]
            assert quiz["misses"] == sum(record["refusals"].values())
        # A character is complete once each stroke is written or credited.
        for judged, scene_character in zip(quiz["characters"], record["scene"]["characters"]):
            done = sum(e["kind"] in ("stroke_accepted", "stroke_assisted") for e in judged["events"])
            strokes = len(scene_character["strokes"])
            assert (judged["events"][-1:] and judged["events"][-1]["kind"] == "character_completed") == \
                (done == strokes)
        credited[record["condition"]] += quiz["strokes_assisted"]
    assert credited["Q1"] > 0
    assert credited["Q0"] == 0


def test_the_pages_show_the_quizs_assisted_strokes(cli, folder, records):
    subprocess.run([cli, "report", "st", "--out", "index.html"], cwd=folder, check=True, capture_output=True)
    pages = "".join(p.read_text(encoding="utf-8") for p in folder.glob("index_files/*/*.html"))
    shown = [int(n) for n in re.findall(r"quiz strokes assisted (\d+)", pages)]
    assert sorted(shown) == sorted(r["quiz"]["strokes_assisted"] for r in records if r["quiz"]["strokes_assisted"])
    assert shown
