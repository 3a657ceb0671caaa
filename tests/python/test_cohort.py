"""Simulated cohorts (calligraphy.cohort.simulate): the rows of `calligraphy session run`'s folders for the same
subjects, the same on C++ threads, on a Dask cluster and from `calligraphy session cohort`, ready for the
statistics; bad arguments named."""

import json
import subprocess

import pytest

import calligraphy.cohort
import calligraphy.statistics as statistics
import calligraphy.study

pandas = pytest.importorskip("pandas")

# Two days, two schedules that adapt, a learning memory: 2 + 4 + 1 + 1 = 8 trials a subject.
PROTOCOL = {
    "name": "py-cohort",
    "conditions": [{"name": "free", "mode": "vision"},
                   {"name": "band", "mode": "assist-as-needed"},
                   {"name": "push", "mode": "error-amplification"}],
    "phases": [{"phase": "pre-test", "condition": "free", "characters": ["十", "人"]},
               {"phase": "training", "conditions": ["band", "push"], "assignment": "between-subjects",
                "characters": ["十", "人"], "repetitions": 2},
               {"phase": "post-test", "condition": "free", "characters": ["十"]},
               {"phase": "retention", "condition": "free", "characters": ["十"], "session": 2, "delay_s": 86400}],
    "trial": {"max_duration_s": 40},
}
SUBJECTS = 4
# What only a session folder has.
FOLDER_ONLY = ["session", "start_utc", "trace_file", "trace_sha256"]


@pytest.fixture(scope="module")
def protocol(tmp_path_factory):
    path = tmp_path_factory.mktemp("cohort") / "p.json"
    path.write_text(json.dumps(PROTOCOL, ensure_ascii=False), encoding="utf-8")
    return path


@pytest.fixture(scope="module")
def threads(protocol):
    return calligraphy.cohort.simulate(protocol, SUBJECTS, profile="foreign", workers=2)


def test_the_rows_are_those_of_the_session_folders(cli, protocol, threads):
    out = protocol.parent / "study"
    subprocess.run([cli, "session", "run", str(protocol), "--writer", "simulated", "--subjects", str(SUBJECTS),
                    "--writer-profile", "foreign", "--writer-learning", "two-state", "--out", str(out)],
                   check=True, capture_output=True)
    folders = calligraphy.study.load(out)
    assert len(threads.trials) == SUBJECTS * 8
    pandas.testing.assert_frame_equal(threads.trials.drop(columns=FOLDER_ONLY),
                                      folders.trials.drop(columns=FOLDER_ONLY), check_categorical=False)
    pandas.testing.assert_frame_equal(threads.strokes.drop(columns=["session"]),
                                      folders.strokes.drop(columns=["session"]), check_categorical=False)
    # Session ids are keys across subjects: the protocol, the subject, the session number.
    assert set(threads.trials.session) == {f"py-cohort-{subject}-s{number}"
                                           for subject in threads.trials.subject.unique() for number in (1, 2)}


def test_a_dask_cluster_and_the_cli_give_the_same_tables(cli, protocol, threads):
    distributed = pytest.importorskip("distributed")
    with distributed.LocalCluster(n_workers=2, processes=True, threads_per_worker=1, dashboard_address=None,
                                  silence_logs=50) as cluster, distributed.Client(cluster) as client:
        on_dask = calligraphy.cohort.simulate(protocol, SUBJECTS, profile="foreign", client=client, batch_size=3,
                                              progress=False)
    pandas.testing.assert_frame_equal(on_dask.trials, threads.trials)
    pandas.testing.assert_frame_equal(on_dask.strokes, threads.strokes)
    tables = protocol.parent / "tables"
    tables.mkdir()
    subprocess.run([cli, "session", "cohort", str(protocol), "--subjects", str(SUBJECTS), "--writer-profile",
                    "foreign", "--jobs", "2", "--csv", str(tables)], check=True, capture_output=True)
    from_cli = pandas.read_csv(tables / "trials.csv", float_precision="round_trip")
    pandas.testing.assert_series_equal(from_cli.mean_deviation_m, threads.trials.mean_deviation_m)
    assert from_cli.subject.tolist() == threads.trials.subject.astype(str).tolist()


def test_the_tables_feed_the_statistics(threads):
    learning = statistics.learning(threads.trials, "mean_deviation_m", pre="pre-test", post="post-test",
                                   retention="retention")
    assert sorted(learning.group.unique()) == ["band", "push"]
    assert len(learning) == SUBJECTS
    assert threads.trials.shape_skill.notna().all()


def test_bad_arguments_are_named(protocol):
    with pytest.raises(ValueError, match="subjects"):
        calligraphy.cohort.simulate(protocol, 0)
    # The CLI's bound, refused before anything is built (a list of 10**9 ids would fill the memory).
    with pytest.raises(ValueError, match="1 to 100000 subjects, got 1000000000"):
        calligraphy.cohort.simulate(protocol, 10**9)
    with pytest.raises(TypeError, match="subjects"):
        calligraphy.cohort.simulate(protocol, "4")
    with pytest.raises(ValueError, match="workers"):
        calligraphy.cohort.simulate(protocol, 1, workers=0)
    with pytest.raises(ValueError, match="workers: expected an int in 1..1024"):
        calligraphy.cohort.simulate(protocol, 1, workers=10**6)
    with pytest.raises(ValueError, match="writer_profile"):
        calligraphy.cohort.simulate(protocol, 1, profile="expert")
    with pytest.raises(ValueError, match="writer_learning"):
        calligraphy.cohort.simulate(protocol, 1, learning="three-state")
    replay = protocol.parent / "replay.json"
    replay.write_text(json.dumps({"name": "r", "conditions": [{"name": "teacher", "mode": "replay"}],
                                  "test": {"characters": ["十"], "conditions": ["teacher"], "repetitions": 1}}),
                      encoding="utf-8")
    with pytest.raises(ValueError, match="condition 'teacher'"):
        calligraphy.cohort.simulate(replay, 1)
