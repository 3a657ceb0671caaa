"""calligraphy.study.load: a study's tidy tables are the CLI's `report --csv` tables, hold every saved trial with
its record's metrics in SI units, and give each trial's samples on demand."""

import gzip
import json
import subprocess
from pathlib import Path

import pytest

pd = pytest.importorskip("pandas")

import calligraphy.study  # noqa: E402

def record_path(trace_file):
    """The trial record beside a trace: STEM.json for STEM.trace.h5 (or an older folder's STEM.csv.gz or
    STEM.csv)."""
    trace = Path(trace_file)
    stem = trace.name.removesuffix(".h5").removesuffix(".trace").removesuffix(".gz").removesuffix(".csv")
    return trace.with_name(stem + ".json")


def as_older_folder(cli, trace, compress):
    """Makes the trial of `trace` as a folder written before traces were HDF5 holds it: its CSV (`calligraphy
    trace`), gzip-compressed or plain, named by the record's files.csv. Returns the CSV trace's path."""
    text = subprocess.run([cli, "trace", str(trace)], capture_output=True, check=True).stdout
    older = trace.with_name(record_path(trace).stem + (".csv.gz" if compress else ".csv"))
    older.write_bytes(gzip.compress(text) if compress else text)
    trace.unlink()
    record_file = record_path(trace)
    record = json.loads(record_file.read_text(encoding="utf-8"))
    del record["files"]["trace"]
    del record["files"]["trace_sha256"]  # older folders did not bind the trace to its record
    record["files"]["csv"] = older.name
    record_file.write_text(json.dumps(record), encoding="utf-8")
    return older


@pytest.fixture(scope="module")
def study_folder(small_study, tmp_path_factory):
    folder = tmp_path_factory.mktemp("study")
    small_study(folder, subjects=2, repetitions=1)
    return folder


def test_the_tables_are_the_cli_tables_and_the_records(cli, study_folder):
    study = calligraphy.study.load(study_folder / "study")
    records = sorted((study_folder / "study").glob("S*/*/trials/*.json"))
    assert len(study.trials) == len(records) == 2 * (1 + 2 * 2)  # subjects x (practice + characters x conditions)
    assert set(study.trials["phase"]) == {"practice", "test"}
    assert set(study.trials["subject"]) == {"S01", "S02"}
    for _, row in study.trials.iterrows():
        record = json.loads(record_path(row["trace_file"]).read_text(encoding="utf-8"))
        assert row["mean_deviation_m"] == record["mean_deviation_m"]
        assert row["total_time_s"] == record["total_time_s"]
        # Indices count from 1, as the record's and the file's (001-..., r1).
        assert row["repetition"] == record["repetition"] == record["trial"]["repetition"]
        assert row["trial"] == record["trial"]["index"] == int(Path(row["trace_file"]).name[:3])
        assert row["block"] == record["trial"]["block"] >= 1
        assert row["item"] == record["trial"]["item"] >= 1
        assert row["condition"] == record["condition"]
        assert row["completed_in_order"] == record["completed_in_order"]
        assert row["strokes_accepted"] == record["strokes_accepted"]
    assert len(study.strokes) == study.trials["strokes_total"].sum()
    assert study.trials["completed_in_order"].dtype == bool and study.trials["completed_in_order"].any()
    assert study.strokes["written"].dtype == bool
    assert study.strokes["written"].sum() == study.trials["strokes_written"].sum()
    assert study.strokes["stroke"].min() == 1 and study.strokes["character"].min() == 1
    # The CLI writes the same tables.
    (study_folder / "tables").mkdir(exist_ok=True)
    run = subprocess.run([cli, "report", "study", "--csv", "tables"], cwd=study_folder, capture_output=True)
    assert run.returncode == 0, run.stderr.decode()
    cli_trials = pd.read_csv(study_folder / "tables" / "trials.csv")
    assert list(cli_trials.columns) == list(study.trials.columns)
    assert cli_trials["mean_deviation_m"].tolist() == pytest.approx(study.trials["mean_deviation_m"].tolist())
    cli_strokes = pd.read_csv(study_folder / "tables" / "strokes.csv")
    assert len(cli_strokes) == len(study.strokes)
    # With the per-trial pages, the tables come from the pages' read of each record: the same bytes.
    (study_folder / "with_pages").mkdir(exist_ok=True)
    run = subprocess.run([cli, "report", "study", "--csv", "with_pages", "--out", "with_pages/trials.html"],
                         cwd=study_folder, capture_output=True)
    assert run.returncode == 0, run.stderr.decode()
    for name in ("trials.csv", "strokes.csv"):
        assert (study_folder / "with_pages" / name).read_bytes() == (study_folder / "tables" / name).read_bytes()


def test_the_metric_columns_are_the_metric_tables(study_folder):
    """The tables' metric columns are the metric table's, in its places, typed by its kinds."""
    study = calligraphy.study.load(study_folder / "study")
    table = calligraphy.metric_table()
    for frame, key in ((study.trials, "trials_column"), (study.strokes, "strokes_column")):
        metrics = sorted((row for row in table if row[key] > 0), key=lambda row: row[key])
        assert [row[key] for row in metrics] == list(range(1, len(metrics) + 1))
        names = [row["name"] for row in metrics]
        columns = list(frame.columns)
        start = columns.index(names[0])
        assert columns[start:start + len(names)] == names  # together, in the table's order
        for row in metrics:
            dtype = frame[row["name"]].dtype
            if row["kind"] == "flag":
                assert dtype == bool, row["name"]
            else:
                assert pd.api.types.is_numeric_dtype(dtype), row["name"]
    assert study.trials["strokes_assisted"].dtype == "int64"


def test_samples_are_read_on_demand_in_si_units(study_folder):
    study = calligraphy.study.load([study_folder / "study"])
    first = study.trials.iloc[0]
    samples = study.samples(first)
    record = json.loads(record_path(first["trace_file"]).read_text(encoding="utf-8"))
    assert len(samples) == record["samples"]
    assert {"t_s", "x_m", "y_m", "z_m", "fx_n", "fy_n", "fz_n", "state", "stroke", "element"} <= set(samples)
    assert samples["t_s"].is_monotonic_increasing
    assert sum(1 for _ in study.iter_samples()) == len(study.trials)


def test_a_folder_without_sessions_is_named(tmp_path):
    with pytest.raises(calligraphy.DataError, match=str(tmp_path)):
        calligraphy.study.load(tmp_path)
    for nothing in ([], "", [tmp_path, ""]):
        with pytest.raises(ValueError, match="load: paths must name"):
            calligraphy.study.load(nothing)


def test_the_curriculum_is_the_clis(cli, study_folder):
    # paper-table5 shrunk to 永 (practice), 十 and 人: what comes next among characters not written.
    candidates = "大天木山中日千永十"
    proposed = calligraphy.study.propose_characters(study_folder / "study", "S01", candidates, count=3)
    run = subprocess.run([cli, "curriculum", "study", "--subject", "S01", "--from", candidates, "--count", "3",
                          "--json"], cwd=study_folder, capture_output=True)
    assert run.returncode == 0, run.stderr.decode()
    assert proposed == json.loads(run.stdout)
    assert proposed and all(p["character"] not in "永十人" for p in proposed)
    assert proposed[0]["new_strokes"]  # something never written comes first
    with pytest.raises(Exception, match="'nobody' has no saved trial"):
        calligraphy.study.propose_characters(study_folder / "study", "nobody", candidates)


def test_a_damaged_record_is_a_data_error_naming_the_file_and_pointer(study_folder, tmp_path):
    import shutil

    copy = tmp_path / "study"
    shutil.copytree(study_folder / "study", copy)
    record = sorted(copy.glob("S01/*/trials/*.json"))[0]
    text = record.read_text(encoding="utf-8")
    for old, new, pointer in [('"format": "calligraphy-study-trial"', '"format": 5', "/format"),
                              ('"per_character": [', '"per_character": "x", "was": [', "/per_character"),
                              ('"frechet_m": ', '"frechet_m": 1e999, "was": ', "/frechet_m"),
                              ('"end_reason": "', '"end_reason": [], "was": "', "/end_reason")]:
        compact = json.dumps(json.loads(text))  # one spelling of the separators for the replacements
        assert old in compact, old
        record.write_text(compact.replace(old, new, 1), encoding="utf-8")
        with pytest.raises(calligraphy.DataError, match=f"{record.name}: {pointer}"):
            calligraphy.study.load(copy)
    record.write_text(text, encoding="utf-8")


def test_a_record_whose_specification_cannot_run_again_is_a_data_error_naming_the_pointer(study_folder, tmp_path):
    """study.load reads a record's specification as `trial --spec` does (one reader): a field it refuses is a
    DataError naming the record and the pointer; the untouched copy loads the same tables."""
    import shutil

    copy = tmp_path / "study"
    shutil.copytree(study_folder / "study", copy)
    before = calligraphy.study.load(copy)
    record = sorted(copy.glob("S01/*/trials/*.json"))[0]
    text = record.read_text(encoding="utf-8")
    for part, key, value in [(None, "version", 10), ("force_law", "crossfade_s", -1.0),
                             ("trial", "max_duration_s", "20")]:
        document = json.loads(text)
        (document["specification"] if part is None else document["specification"][part])[key] = value
        record.write_text(json.dumps(document), encoding="utf-8")
        pointer = "/specification/" + (key if part is None else f"{part}/{key}")
        with pytest.raises(calligraphy.DataError, match=f"{record.name}: {pointer}:"):
            calligraphy.study.load(copy)
    record.write_text(text, encoding="utf-8")
    after = calligraphy.study.load(copy)
    pd.testing.assert_frame_equal(after.trials, before.trials)
    pd.testing.assert_frame_equal(after.strokes, before.strokes)


def test_a_damaged_trace_is_a_data_error_naming_the_file_and_line(cli, study_folder, tmp_path):
    import shutil

    copy = tmp_path / "study"
    shutil.copytree(study_folder / "study", copy)
    study = calligraphy.study.load(copy)
    trace = Path(study.trials.iloc[0]["trace_file"])
    assert trace.name.endswith(".trace.h5")
    # A byte changed anywhere in the HDF5 file: refused by its CRC-32, naming the file.
    data = bytearray(trace.read_bytes())
    data[len(data) // 3] ^= 0x40
    trace.write_bytes(bytes(data))
    with pytest.raises(calligraphy.DataError, match=f"{trace.name}: damaged"):
        study.samples(study.trials.iloc[0])
    # An older folder's gzip CSV: its line and column are named.
    shutil.rmtree(copy)
    shutil.copytree(study_folder / "study", copy)
    csv = as_older_folder(cli, trace, compress=True)
    study = calligraphy.study.load(copy)
    lines = gzip.decompress(csv.read_bytes()).decode("utf-8").splitlines()
    for line, damaged, column in [(3, lines[2].replace(",", ",1e999x", 1), "x"), (4, "inf" + lines[3][1:], "t"),
                                  (1, "t,x,y", None)]:
        text = "\n".join(lines[:line - 1] + [damaged] + lines[line:]) + "\n"
        csv.write_bytes(gzip.compress(text.encode("utf-8")))
        expected = f"{csv.name}:{line}: column {column}" if column else f"{csv.name}:1: expected the header"
        with pytest.raises(calligraphy.DataError, match=expected):
            study.samples(study.trials.iloc[0])


@pytest.mark.parametrize("compress", [True, False])
def test_the_csv_trace_of_an_older_folder_reads_as_the_hdf5_one(cli, study_folder, tmp_path, compress):
    """Folders written before traces were HDF5 name a gzip CSV trace (or, earlier still, a plain .csv) in their
    records: the same samples, column for column and bit for bit."""
    import shutil

    copy = tmp_path / "study"
    shutil.copytree(study_folder / "study", copy)
    current = calligraphy.study.load(copy)
    expected = current.samples(current.trials.iloc[0])
    older_trace = as_older_folder(cli, Path(current.trials.iloc[0]["trace_file"]), compress)
    older = calligraphy.study.load(copy)
    assert older.trials.iloc[0]["trace_file"] == str(older_trace)
    pd.testing.assert_frame_equal(older.samples(older.trials.iloc[0]), expected, check_exact=True)
    # The C++ readers take it too: the per-trial pages.
    run = subprocess.run([cli, "report", str(copy), "--out", str(tmp_path / "t.html")],
                         capture_output=True)
    assert run.returncode == 0, run.stderr.decode()


def test_a_truncated_or_foreign_trace_is_a_data_error_naming_the_file(study_folder, tmp_path):
    import shutil

    copy = tmp_path / "study"
    shutil.copytree(study_folder / "study", copy)
    study = calligraphy.study.load(copy)
    trace = Path(study.trials.iloc[0]["trace_file"])
    data = trace.read_bytes()
    trace.write_bytes(data[: len(data) // 2])
    with pytest.raises(calligraphy.DataError, match=f"{trace.name}: .*cut short"):
        study.samples(study.trials.iloc[0])
    trace.write_bytes(b"\x89HDF\r\n\x1a\n" + b"another program's HDF5 file" * 10)
    with pytest.raises(calligraphy.DataError, match=f"{trace.name}: not a calligraphy trace"):
        study.samples(study.trials.iloc[0])
    trace.unlink()
    with pytest.raises(FileNotFoundError, match=trace.name):
        study.samples(study.trials.iloc[0])


def test_h5py_reads_a_saved_trace_to_the_same_values(study_folder):
    """The trace is HDF5 as any reader sees it: h5py (another HDF5 reader, as MATLAB's and R's are) gives the
    columns, and integer / 10**decimals is, bit for bit, what the library reads."""
    h5py = pytest.importorskip("h5py")
    import numpy as np

    study = calligraphy.study.load(study_folder / "study")
    row = study.trials.iloc[0]
    ours = study.samples(row)
    with h5py.File(row["trace_file"], "r") as trace:
        assert trace.attrs["format"] == b"calligraphy-trace" or trace.attrs["format"] == "calligraphy-trace"
        assert int(trace.attrs["samples"]) == len(ours)
        for name, column, unit in [("t", "t_s", "s"), ("x", "x_m", "m"), ("y", "y_m", "m"), ("z", "z_m", "m"),
                                   ("fx", "fx_n", "N"), ("fy", "fy_n", "N"), ("fz", "fz_n", "N")]:
            dataset = trace[name]
            assert dataset.attrs["unit"] in (unit, unit.encode())
            values = dataset[()] / 10.0 ** int(dataset.attrs["decimals"])
            np.testing.assert_array_equal(values, ours[column].to_numpy(), err_msg=name)
        names = {value: key for key, value in h5py.check_enum_dtype(trace["state"].dtype).items()}
        assert [names[v] for v in trace["state"][()]] == list(ours["state"])
        for name in ("stroke", "element", "attempt", "rewritten"):
            np.testing.assert_array_equal(trace[name][()], ours[name].to_numpy(), err_msg=name)


def test_a_crossover_gives_each_trials_set_sequence_period_and_trained_condition(cli, tmp_path):
    """examples/protocols/crossover.json with one training round: the four crossover columns follow
    `repetition`, as categoricals and a float period, and agree with the training blocks in every phase."""
    source = Path(__file__).resolve().parents[2] / "examples" / "protocols" / "crossover.json"
    protocol = json.loads(source.read_text(encoding="utf-8"))
    protocol["phases"][1]["repetitions"] = 1
    (tmp_path / "p.json").write_text(json.dumps(protocol), encoding="utf-8")
    run = subprocess.run([cli, "session", "run", "p.json", "--writer", "simulated", "--subjects", "4", "--out",
                          "study"], cwd=tmp_path, capture_output=True)
    assert run.returncode == 0, run.stderr.decode()
    trials = calligraphy.study.load(tmp_path / "study").trials
    columns = list(trials.columns)
    at = columns.index("repetition")
    assert columns[at + 1:at + 5] == ["item_set", "sequence", "period", "trained_condition"]
    for column in ("item_set", "sequence", "trained_condition"):
        assert isinstance(trials[column].dtype, pd.CategoricalDtype), column
    assert trials["period"].dtype == "float64"
    sequences = trials.groupby("subject", observed=True)["sequence"].agg(lambda s: set(s.astype(str)))
    assert [next(iter(s)) for s in sequences] == ["AB", "BA", "AB", "BA"]
    training = trials[trials["phase"] == "training"]
    assert (training["trained_condition"].astype(str) == training["condition"].astype(str)).all()
    for subject, rows in trials.groupby("subject", observed=True):
        trained = training[training["subject"] == subject].drop_duplicates("item_set").set_index("item_set")
        assert sorted(trained["period"]) == [1.0, 2.0]
        for _, row in rows.iterrows():
            assert row["trained_condition"] == trained.loc[row["item_set"], "condition"]
            assert row["period"] == trained.loc[row["item_set"], "period"]


def test_a_study_without_item_sets_has_empty_crossover_columns(study_folder):
    trials = calligraphy.study.load(study_folder / "study").trials
    assert trials["period"].dtype == "float64" and trials["period"].isna().all()
    for column in ("item_set", "sequence", "trained_condition"):
        assert set(trials[column].astype(str)) == {""}, column


def test_a_trace_swapped_with_another_trials_is_refused(cli, study_folder, tmp_path):
    """Each record names its trace by SHA-256: a trace copied over from another trial (intact, readable) is
    not drawn or analysed as this trial's, by Python and by the C++ report alike, naming both."""
    import shutil

    copy = tmp_path / "study"
    shutil.copytree(study_folder / "study", copy)
    study = calligraphy.study.load(copy)
    first, second = (Path(study.trials.iloc[k]["trace_file"]) for k in (0, 1))
    assert study.trials.iloc[0]["trace_sha256"] != study.trials.iloc[1]["trace_sha256"]
    assert len(study.trials.iloc[0]["trace_sha256"]) == 64
    first.write_bytes(second.read_bytes())
    with pytest.raises(calligraphy.DataError, match=f"{first.name}: SHA-256 .* not this trial's trace"):
        study.samples(study.trials.iloc[0])
    original = calligraphy.study.load(study_folder / "study")
    pd.testing.assert_frame_equal(study.samples(study.trials.iloc[1]), original.samples(original.trials.iloc[1]),
                                  check_exact=True)
    run = subprocess.run([cli, "report", str(copy), "--out", str(tmp_path / "t.html")], capture_output=True)
    assert run.returncode != 0
    message = run.stderr.decode()
    assert "/files/trace_sha256" in message and "not this trial's trace" in message and first.name in message
    assert not (tmp_path / "t.html").exists()


@pytest.mark.parametrize("samples", [16_000_000, 10_000_002])
def test_a_small_trace_declaring_more_samples_than_any_trial_is_refused_unread(cli, tmp_path, samples):
    """A trace file of a few kilobytes whose columns declare millions of samples (chunks never written read as
    their fill value, and constant chunks compress 1000-fold) is refused by its length before a column is
    allocated: no trial has more ticks than 10^7 (kMaxTrialTicks), so no trace file has more samples. Built
    with h5py as a forger would, with a valid header (format, version, length and CRC-32)."""
    import zlib

    h5py = pytest.importorskip("h5py")
    body = tmp_path / "body.h5"
    numpy = __import__("numpy")
    with h5py.File(body, "w", userblock_size=512) as forged:
        # The root's attributes as the writer makes them (the reader checks them), declaring that many.
        forged.attrs["format"] = numpy.bytes_(b"calligraphy-trace")
        forged.attrs["version"] = numpy.int32(1)
        forged.attrs["samples"] = numpy.uint64(samples)
        for column in ("t", "x", "y", "z", "fx", "fy", "fz"):
            forged.create_dataset(column, shape=(samples,), dtype="<i8", chunks=(65536,), compression="gzip")
        # Some bytes that do not compress, so that the file is large enough to hold that many samples at the
        # deflate's best ratio: only the samples' bound refuses it.
        forged["t"][:30000] = __import__("numpy").random.default_rng(1).integers(0, 2**62, 30000)
    hdf5 = body.read_bytes()[512:]
    header = f"calligraphy-trace\nversion 1\nbytes {len(hdf5)}\ncrc32 {zlib.crc32(hdf5):08x}\n".encode()
    trace = tmp_path / "forged.trace.h5"
    trace.write_bytes(header + bytes(512 - len(header)) + hdf5)
    assert 4 * samples / 1032 < trace.stat().st_size < 1_000_000
    run = subprocess.run([cli, "trace", str(trace)], capture_output=True, timeout=60)
    assert run.returncode == 1, run.stderr.decode()
    assert f"{samples} samples, more than a trace file holds" in run.stderr.decode()
    assert "forged.trace.h5" in run.stderr.decode()
    with pytest.raises(calligraphy.DataError, match=f"{samples} samples, more than"):
        calligraphy.study._read_trace(str(trace))
