"""Parameter sweeps (calligraphy.experiments.sweep): the same rows on a local process pool and on a Dask
cluster, failed trials as rows, grid names and values checked before anything runs."""

import concurrent.futures
import os

import pytest

import calligraphy
from calligraphy.experiments import DASK_WORKER_ENVIRONMENT, dask_worker_config, parameter_names, sweep

pandas = pytest.importorskip("pandas")

# Short characters, the last one not in hanzi-writer-data (so in no library); 2 x 3 x 2 = 12 trials.
CHARACTERS = "口十\u00e9"
GRID = {"guidance": [True, False], "guidance_stiffness_n_per_m": [250.0]}
SEEDS = [0, 7]


@pytest.fixture(scope="module")
def local_table():
    # Two processes and batches that do not divide the trials evenly.
    return sweep(CHARACTERS, GRID, SEEDS, workers=2, batch_size=5, progress=False)


@pytest.fixture(scope="module")
def dask_table():
    distributed = pytest.importorskip("distributed")
    import dask.config

    # The workers get glibc's malloc thresholds instead of the nanny's trim threshold; the workers' own
    # environment shows that the configuration key still reaches them.
    with dask.config.set(dask_worker_config()), \
            distributed.LocalCluster(n_workers=2, processes=True, threads_per_worker=1, dashboard_address=None,
                                     silence_logs=50) as cluster, distributed.Client(cluster) as client:
        assert len(client.nthreads()) == 2
        seen = client.run(lambda: {key: os.environ.get(key) for key in DASK_WORKER_ENVIRONMENT})
        assert list(seen.values()) == [{key: str(value) for key, value in DASK_WORKER_ENVIRONMENT.items()}] * 2
        return sweep(CHARACTERS, GRID, SEEDS, client=client, progress=False)


def test_one_row_per_combination_character_and_seed_in_order(local_table):
    assert len(local_table) == 2 * 3 * 2
    expected = [(guidance, char, seed) for guidance in (True, False) for char in CHARACTERS for seed in SEEDS]
    assert list(zip(local_table.guidance, local_table.character, local_table.seed)) == expected
    assert (local_table.guidance_stiffness_n_per_m == 250.0).all()
    assert list(local_table.columns[:4]) == ["character", "seed", "guidance", "guidance_stiffness_n_per_m"]
    assert "renderer_strokes" not in local_table.columns and "characters" not in local_table.columns
    assert "error" in local_table.columns


def test_rows_are_the_trials_metrics(local_table):
    law = calligraphy.ForceLawParameters(guidance_stiffness_n_per_m=250.0)
    for _, row in local_table[local_table.character != "\u00e9"].iterrows():
        metrics = calligraphy.simulate_trial(row.character, guidance=bool(row.guidance), seed=int(row.seed),
                                             force_law=law, keep_trace=False).metrics
        for key in ("mean_deviation_m", "max_deviation_m", "total_time_s", "completed_in_order", "strokes_total"):
            assert row[key] == metrics[key], key
        assert row.attempts_total == sum(stroke["attempts"] for stroke in metrics["renderer_strokes"])
        assert row.error is None


def test_a_missing_character_is_an_error_row(local_table):
    failed = local_table[local_table.character == "\u00e9"]
    assert len(failed) == 4
    for text in failed.error:
        assert text.startswith("CharacterNotFound: ") and "U+00E9" in text
    assert failed.mean_deviation_m.isna().all() and failed.completed_in_order.isna().all()
    # The other trials are untouched, and integer and bool columns stay so next to the missing values.
    assert local_table[local_table.character != "\u00e9"].error.isna().all()
    assert str(local_table.strokes_total.dtype) == "Int64"
    assert str(local_table.completed_in_order.dtype) == "boolean"


def test_a_dask_cluster_gives_the_same_rows_as_the_local_pool(local_table, dask_table):
    pandas.testing.assert_frame_equal(dask_table, local_table)


def test_writer_and_nested_fields_reach_the_trial():
    grid = {"writer": ["skilled"], "bias_offset_m": [0.0], "nearest.method": ["newton"]}
    with concurrent.futures.ThreadPoolExecutor(max_workers=2) as executor:
        table = sweep("口", grid, [3], client=executor, progress=False)
    law = calligraphy.ForceLawParameters()
    law.nearest.method = "newton"
    writer = calligraphy.WriterProfile.skilled().replace(bias_offset_m=0.0)
    expected = calligraphy.simulate_trial("口", writer=writer, force_law=law, seed=3, keep_trace=False).metrics
    assert table.error.isna().all()
    assert table.mean_deviation_m[0] == expected["mean_deviation_m"]
    assert table.total_time_s[0] == expected["total_time_s"]
    assert table.writer[0] == "skilled"


def test_unknown_parameter_names_are_rejected_with_the_valid_ones():
    with pytest.raises(ValueError, match="unknown parameter 'stiffness'") as error:
        sweep("口", {"stiffness": [1.0]}, [0], progress=False)
    for name in ("guidance", "rate_hz", "max_duration_s", "writer", "guidance_stiffness_n_per_m",
                 "nearest.method", "hand_stiffness_n_per_m"):
        assert name in str(error.value)
        assert name in parameter_names()


def test_values_and_arguments_are_checked_before_running():
    with pytest.raises(ValueError, match="guidance_stiffness_n_per_m"):
        sweep("口", {"guidance_stiffness_n_per_m": [400.0, -1.0]}, [0], progress=False)
    with pytest.raises(ValueError, match="writer"):
        sweep("口", {"writer": ["expert"]}, [0], progress=False)
    with pytest.raises(ValueError, match="no values"):
        sweep("口", {"guidance": []}, [0], progress=False)
    with pytest.raises(ValueError, match="same parameter"):
        sweep("口", {"friction_coefficient": [0.1], "force_law.friction_coefficient": [0.2]}, [0], progress=False)
    with pytest.raises(ValueError, match="seeds"):
        sweep("口", {}, [], progress=False)
    # Bounds, refused before a list of that size is built.
    with pytest.raises(ValueError, match="seeds: expected a count in 1..1000000"):
        sweep("口", {}, 10**9, progress=False)
    with pytest.raises(ValueError, match="2000000 trials"):
        sweep("口", {"guidance": [True, False]}, 10**6, progress=False)
    with pytest.raises(ValueError, match="workers: expected an int in 1..1024"):
        sweep("口", {}, [0], workers=10**6, progress=False)
    with pytest.raises(calligraphy.DataError, match="no-such-folder"):
        sweep("口", {}, [0], data="no-such-folder", progress=False)
    # A client that is neither a distributed.Client nor an Executor is named, not an AttributeError.
    with pytest.raises(TypeError, match="client: expected a distributed.Client or a concurrent.futures.Executor, got int 3"):
        sweep("口", {}, [0], client=3, progress=False)
