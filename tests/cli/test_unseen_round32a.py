#!/usr/bin/env python3
"""Round 32A: trace files. A trial's `.trace.h5` as a session folder saves it, read by others (h5py, pandas
through `calligraphy.study`), exported by `calligraphy trace` and forged on the way. From the docs alone:
docs/cli.md (Conventions "Outputs", "Checked before anything runs", "Standard output", Exit statuses, `trial
--csv`, `score` and "Pen traces: format and limits", `trace`, `session run`), docs/experiments.md ("Sessions",
"Trace files", "Trial records", "Reading a trace"), docs/python.md ("A study's traces"), the headers
include/calligraphy/report/trace_hdf5.hpp and trace_columns.hpp, and the module's docstrings.

One simulated session of 十 (one trial, lock-step) gives the trace. It is read by h5py against its documented
layout (user block, attributes, types, units, decimals, chunks and filters), against `calligraphy trace`'s CSV
to the documented decimals, against `trial --spec`'s `--csv` of the same trial, against `score`, and against
`Study.samples`. A second session of the same subject must give the same bytes. Other programs' honest layouts
of the same columns (made with h5py, given the user block the docs describe: "calligraphy-trace", the version,
the length and CRC-32 of what follows the first 512 bytes) must read as the original; forged ones (a flipped
byte, a cut file, zeros, another type, another byte order, columns of different lengths, a wrong `samples`,
NaN in a position, a state beyond WS, a `rewritten` of 2, an external link, to a file and to a FIFO, wrong
attributes, a missing column, a file over 256 MiB) are refused with exit 1 and one line naming the file, and
nothing written. Outputs: the input itself, a symbolic or hard link to it, a missing folder, a folder,
/dev/full, /dev/stdout on a pipe, a pipe closed early, links to other files, a kept permission, a repeated
option. A large honest trace stays fast.

CALLIGRAPHY_CLI names the program; PYTHONPATH the built Python package. CALLIGRAPHY_SANITIZED=1 takes five cases.
"""
import csv
import hashlib
import io
import json
import os
import re
import resource
import shutil
import stat
import subprocess
import tempfile
import time
import unittest
import zlib
from pathlib import Path

from outsider import CLI, ENV, OneErrorLine, run, run_ok, sanitized_subset

try:
    import numpy as np
    import h5py
except ImportError:  # reported by setUpClass
    np = h5py = None

load_tests = sanitized_subset({"test_h5py_reads_every_documented_column_type_unit_and_decimals",
                               "test_flipped_byte_after_user_block_is_refused_naming_file_nothing_written",
                               "test_csv_output_the_input_itself_is_a_collision_exit_2_input_unchanged",
                               "test_decimals_attribute_3_is_refused_with_the_documented_line",
                               "test_external_link_to_fifo_is_refused_at_once_never_waited_on"})

PROTOCOL = {"name": "tr", "conditions": [{"name": "h", "mode": "haptic"}],
            "test": {"characters": ["十"], "conditions": ["h"], "repetitions": 1},
            "trial": {"max_duration_s": 20}}
HEADER = "t,x,y,z,fx,fy,fz,state,stroke,element,attempt,rewritten"
MEASURED = {"t": ("s", 6), "x": ("m", 7), "y": ("m", 7), "z": ("m", 7),
            "fx": ("N", 4), "fy": ("N", 4), "fz": ("N", 4)}
STATES = {"SS": 0, "AS": 1, "CS": 2, "WS": 3}
USER_BLOCK = 512


def user_block(rest, size=USER_BLOCK):
    """The user block the docs describe, as the saved trace shows it: "calligraphy-trace", the version, the
    length and the CRC-32 (zlib's) of the bytes after the first 512."""
    text = f"calligraphy-trace\nversion 1\nbytes {len(rest)}\ncrc32 {zlib.crc32(rest):08x}\n".encode()
    return text + b"\0" * (size - len(text))


def seal(path):
    """Rewrites the first 512 bytes of `path` (an HDF5 file with a user block) as a valid-looking header."""
    data = Path(path).read_bytes()
    rest = data[USER_BLOCK:]
    Path(path).write_bytes(user_block(rest) + rest)


def write_h5(path, columns, *, root=None, attrs=None, userblock=USER_BLOCK, extra=None, **dataset_kw):
    """An HDF5 trace written by "another program" (h5py): `columns` {name: array} (an array with dtype None
    is left out), the root's attributes `root` (default: format, version, samples), each measured column's
    `unit` and `decimals` unless `attrs` {name: {attr: value or None to leave it out}} says otherwise;
    `extra(f)` adds links. Sealed with the documented user block."""
    n = len(columns["t"])
    with h5py.File(path, "w", userblock_size=userblock) as f:
        root_attrs = {"format": np.bytes_(b"calligraphy-trace"), "version": np.int32(1),
                      "samples": np.uint64(n)}
        root_attrs.update(root or {})
        for key, value in root_attrs.items():
            if value is not None:
                f.attrs[key] = value
        for name, values in columns.items():
            if values is None:
                continue
            if name == "state" and values.dtype == np.uint8 and h5py.check_enum_dtype(values.dtype) is None:
                ds = f.create_dataset(name, data=values, dtype=h5py.enum_dtype(STATES, basetype="u1"),
                                      **dataset_kw)
            else:
                ds = f.create_dataset(name, data=values, **dataset_kw)
            column_attrs = {}
            if name in MEASURED:
                unit, decimals = MEASURED[name]
                column_attrs = {"unit": np.bytes_(unit.encode()), "decimals": np.int32(decimals)}
                if values.dtype.kind == "f":
                    del column_attrs["decimals"]
            column_attrs.update((attrs or {}).get(name, {}))
            for key, value in column_attrs.items():
                if value is not None:
                    ds.attrs[key] = value
        if extra is not None:
            extra(f)
    seal(path)


def put(f, name, values, *, compact=False, chunk=None, filters=(), fill_time=None, written=None):
    """A column made through HDF5's own property list (h5py's low-level calls): compact storage, a chunk
    size, `filters` in the order given ("deflate", "shuffle"), a fill time; only `written` (a slice) of it
    written. Its `unit` and `decimals` as this version writes them."""
    dcpl = h5py.h5p.create(h5py.h5p.DATASET_CREATE)
    if compact:
        dcpl.set_layout(h5py.h5d.COMPACT)
    if chunk:
        dcpl.set_chunk((chunk,))
    for kind in filters:
        if kind == "deflate":
            dcpl.set_deflate(4)
        else:
            dcpl.set_shuffle()
    if fill_time is not None:
        dcpl.set_fill_time(fill_time)
    space = h5py.h5s.create_simple((len(values),))
    ds = h5py.Dataset(h5py.h5d.create(f.id, name.encode(), h5py.h5t.py_create(values.dtype), space, dcpl=dcpl))
    if written is None:
        ds[...] = values
    else:
        ds[written] = values[written]
    if name in MEASURED:
        ds.attrs["unit"] = np.bytes_(MEASURED[name][0].encode())
        ds.attrs["decimals"] = np.int32(MEASURED[name][1])
    return ds


def shuffled(values):
    """HDF5's byte shuffle of `values`: the first bytes of every element, then the second bytes, ..."""
    return values.view(np.uint8).reshape(-1, values.dtype.itemsize).T.copy().tobytes()


def library_layout_x(values, chunk, chunks, fillvalue=None):
    """An `extra` for write_h5: column x in the layout this library writes (byte shuffle then deflate, int32,
    its unit and decimals), each chunk of `chunks` {index: raw bytes} written as it is (H5Dwrite_chunk), the
    others never written."""
    def extra(f):
        kw = {} if fillvalue is None else {"fillvalue": fillvalue}
        ds = f.create_dataset("x", shape=(len(values),), dtype="<i4", chunks=(chunk,), shuffle=True,
                              compression="gzip", **kw)
        ds.attrs["unit"] = np.bytes_(b"m")
        ds.attrs["decimals"] = np.int32(7)
        for index, raw in chunks.items():
            ds.id.write_direct_chunk((index * chunk,), raw, 0)
    return extra


def number_texts(line):
    return line.split(",")


class Round32A(unittest.TestCase, OneErrorLine):
    @classmethod
    def setUpClass(cls):
        if np is None:
            raise unittest.SkipTest("numpy and h5py are needed")
        cls.tmp = Path(tempfile.mkdtemp(prefix="round32a-"))
        d = cls.tmp
        (d / "p.json").write_text(json.dumps(PROTOCOL, ensure_ascii=False), encoding="utf-8")
        run_ok(["session", "run", "p.json", "--subject", "S01", "--out", "out"], d)
        traces = sorted(d.glob("out/S01/*/trials/*.trace.h5"))
        assert len(traces) == 1, traces
        cls.trace = traces[0]
        cls.record_path = cls.trace.with_name(cls.trace.name[:-len(".trace.h5")] + ".json")
        cls.record = json.loads(cls.record_path.read_text(encoding="utf-8"))
        cls.bytes = cls.trace.read_bytes()
        cls.csv = run_ok(["trace", cls.trace], d).stdout
        with h5py.File(cls.trace, "r") as f:
            cls.columns = {name: f[name][()] for name in f}
            cls.state_dtype = f["state"].dtype
        cls.n = len(cls.columns["t"])
        # The documented header, rebuilt here, must be the saved one: else the forged files below test nothing.
        assert user_block(cls.bytes[USER_BLOCK:]) == cls.bytes[:USER_BLOCK], cls.bytes[:80]
        cls.work = 0

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.tmp, ignore_errors=True)

    # ---- helpers ------------------------------------------------------------------------------------------
    def folder(self):
        type(self).work += 1
        path = self.tmp / f"w{self.work}"
        path.mkdir()
        return path

    def cols(self, **changes):
        """The saved trace's columns (copies), with `changes` {name: array or None}."""
        out = {name: values.copy() for name, values in self.columns.items()}
        out["state"] = out["state"].astype(self.state_dtype)
        out.update(changes)
        return out

    def csv_rows(self, text):
        return text.decode("utf-8").splitlines()

    def assert_reads_as_original(self, name, build, expected=None):
        """`build(path)` writes a trace of another program's layout: `trace` reads it, exit 0, the CSV that
        of the saved trace (or `expected`)."""
        d = self.folder()
        build(d / name)
        result = run(["trace", name, "--csv", "out.csv"], d)
        self.assertEqual(result.returncode, 0, result.stderr.decode("utf-8", "replace"))
        self.assertEqual((d / "out.csv").read_bytes(), self.csv if expected is None else expected)

    def assert_refused(self, name, build, *needles, status=1, timeout=None, keep=True):
        """`build(path)` writes a forged trace: `trace NAME --csv out.csv` exits `status` with one error line
        naming NAME (and `needles`), the trace unchanged (`keep`), nothing else in its folder."""
        d = self.folder()
        build(d / name)
        before = (d / name).read_bytes() if keep and (d / name).is_file() else None
        listing = sorted(os.listdir(d))
        kw = {} if timeout is None else {"timeout": timeout}
        result = run(["trace", name, "--csv", "out.csv"], d, **kw)
        line = self.assert_one_error(result, status, name, *needles)
        self.assertEqual(sorted(os.listdir(d)), listing)
        if before is not None:
            self.assertEqual((d / name).read_bytes(), before)
        return line

    # ---- the saved trace read by others ------------------------------------------------------------------
    def test_h5py_reads_every_documented_column_type_unit_and_decimals(self):
        with h5py.File(self.trace, "r") as f:
            self.assertEqual(f.userblock_size, 512)
            self.assertEqual(f.attrs["format"], b"calligraphy-trace")
            self.assertEqual(int(f.attrs["version"]), 1)
            self.assertEqual(int(f.attrs["samples"]), self.n)
            self.assertEqual(sorted(f.keys()), sorted(HEADER.split(",")))
            for name in HEADER.split(","):
                ds = f[name]
                self.assertEqual(ds.shape, (self.n,), name)
                self.assertEqual(ds.dtype.byteorder in "<=|", True, name)
                if ds.chunks is not None:
                    self.assertLessEqual(ds.chunks[0], 65536, name)
                    self.assertTrue(ds.shuffle, name)
                    self.assertEqual(ds.compression, "gzip", name)
            for name, (unit, decimals) in MEASURED.items():
                self.assertIn(f[name].dtype, (np.dtype("<i4"), np.dtype("<i8"), np.dtype("<f8")), name)
                self.assertEqual(f[name].attrs["unit"], unit.encode(), name)
                if f[name].dtype.kind == "i":
                    self.assertEqual(int(f[name].attrs["decimals"]), decimals, name)
            self.assertEqual(h5py.check_enum_dtype(f["state"].dtype), STATES)
            self.assertEqual(f["state"].dtype.itemsize, 1)
            self.assertEqual(f["stroke"].dtype, np.dtype("<u4"))
            self.assertEqual(f["element"].dtype, np.dtype("<u4"))
            self.assertEqual(f["attempt"].dtype, np.dtype("<i4"))
            self.assertEqual(f["rewritten"].dtype, np.dtype("u1"))
            self.assertTrue(set(np.unique(f["rewritten"][()])) <= {0, 1})
            self.assertTrue(set(np.unique(f["state"][()].astype(np.uint8))) <= {0, 1, 2, 3})
            self.assertGreaterEqual(int(f["attempt"][()].min()), 0)

    def test_h5py_values_equal_the_trace_csv_bit_for_bit_to_the_decimals(self):
        reader = csv.reader(io.StringIO(self.csv.decode("utf-8")))
        header = next(reader)
        self.assertEqual(",".join(header), HEADER)
        rows = list(reader)
        self.assertEqual(len(rows), self.n)
        names = {v: k for k, v in STATES.items()}
        with h5py.File(self.trace, "r") as f:
            for j, name in enumerate(header):
                values = f[name][()]
                texts = [r[j] for r in rows]
                if name in MEASURED:
                    got = values / 10 ** f[name].attrs["decimals"]
                    want = np.array([float(t) for t in texts])
                    self.assertTrue(np.array_equal(got, want), name)
                elif name == "state":
                    self.assertEqual([names[int(v)] for v in values.astype(np.uint8)], texts)
                else:
                    self.assertEqual([str(int(v)) for v in values], texts, name)

    def test_trace_csv_numbers_have_the_documented_decimals_and_no_trailing_zeros(self):
        rows = self.csv_rows(self.csv)
        pattern = re.compile(r"-?\d+(\.\d*[1-9])?\Z")
        for line in rows[1:]:
            fields = number_texts(line)
            for name, text in zip(HEADER.split(","), fields):
                if name in MEASURED:
                    self.assertRegex(text, pattern, (name, line))
                    if "." in text:
                        self.assertLessEqual(len(text.split(".")[1]), MEASURED[name][1], (name, line))

    def test_trace_stdout_csv_file_and_dash_are_the_same_bytes(self):
        d = self.folder()
        run_ok(["trace", self.trace, "--csv", "a.csv"], d)
        dash = run_ok(["trace", self.trace, "--csv", "-"], d)
        self.assertEqual((d / "a.csv").read_bytes(), self.csv)
        self.assertEqual(dash.stdout, self.csv)
        self.assertTrue(self.csv.startswith(HEADER.encode() + b"\n"))

    def test_trace_csv_is_trial_spec_rerun_csv_byte_for_byte(self):
        d = self.folder()
        run_ok(["trial", "--spec", self.record_path, "--csv", "re.csv"], d)
        self.assertEqual((d / "re.csv").read_bytes(), self.csv)

    def test_record_names_the_trace_its_sha256_and_samples(self):
        files = self.record["files"]
        self.assertEqual(files["trace"], self.trace.name)
        self.assertEqual(files["trace_sha256"], hashlib.sha256(self.bytes).hexdigest())
        self.assertEqual(self.record["samples"], self.n)

    def test_second_session_of_the_subject_saves_the_same_trace_bytes(self):
        d = self.folder()
        shutil.copy(self.tmp / "p.json", d / "p.json")
        run_ok(["session", "run", "p.json", "--subject", "S01", "--out", "out"], d)
        again = sorted(d.glob("out/S01/*/trials/*.trace.h5"))
        self.assertEqual([p.name for p in again], [self.trace.name])
        self.assertEqual(again[0].read_bytes(), self.bytes)

    def test_score_of_the_h5_is_the_score_of_its_csv(self):
        d = self.folder()
        (d / "t.csv").write_bytes(self.csv)
        from_h5 = json.loads(run_ok(["score", self.trace, "--character", "十", "--json", "-"], d).stdout)
        from_csv = json.loads(run_ok(["score", "t.csv", "--character", "十", "--json", "-"], d).stdout)
        self.assertEqual(from_h5["samples"], self.n)
        for doc in (from_h5, from_csv):
            doc.pop("trace")
        self.assertEqual(from_h5, from_csv)

    def test_trace_columns_table_names_the_h5_datasets_and_units(self):
        import calligraphy
        table = calligraphy.trace_columns()
        self.assertEqual([c["file_name"] for c in table], HEADER.split(","))
        with h5py.File(self.trace, "r") as f:
            for column in table:
                ds = f[column["file_name"]]
                if column["unit"]:
                    self.assertEqual(ds.attrs["unit"].decode(), column["unit"], column)
                    self.assertTrue(column["name"].endswith("_" + column["unit"].lower()), column)
                else:
                    self.assertNotIn("unit", ds.attrs, column)

    def test_study_samples_equal_h5py_bit_for_bit(self):
        import calligraphy.study
        study = calligraphy.study.load(str(self.tmp / "out"))
        self.assertEqual(len(study.trials), 1)
        samples = study.samples(study.trials.index[0])
        self.assertEqual(list(samples.columns), ["t_s", "x_m", "y_m", "z_m", "fx_n", "fy_n", "fz_n", "state",
                                                 "stroke", "element", "attempt", "rewritten"])
        self.assertEqual(len(samples), self.n)
        with h5py.File(self.trace, "r") as f:
            for name in MEASURED:
                want = f[name][()] / 10 ** f[name].attrs["decimals"]
                got = samples[name + "_" + MEASURED[name][0].lower()].to_numpy()
                self.assertEqual(got.dtype, np.float64)
                self.assertTrue(np.array_equal(got, want), name)
            names = {v: k for k, v in STATES.items()}
            self.assertEqual(list(samples["state"]), [names[int(v)] for v in f["state"][()].astype(np.uint8)])
            for name in ("stroke", "element", "attempt", "rewritten"):
                self.assertTrue(np.array_equal(samples[name].to_numpy(), f[name][()].astype(np.int64)), name)
                self.assertEqual(samples[name].dtype, np.int64, name)

    def test_study_iter_samples_yields_the_trace_of_each_trial(self):
        import calligraphy.study
        study = calligraphy.study.load(str(self.tmp / "out"))
        items = list(study.iter_samples())
        self.assertEqual(len(items), 1)
        self.assertTrue(items[0][1].equals(study.samples(study.trials.index[0])))
        self.assertEqual(len(items[0][1]), self.n)

    def test_study_samples_of_a_flipped_trace_is_a_data_error_naming_it(self):
        import calligraphy
        import calligraphy.study
        d = self.folder()
        shutil.copytree(self.tmp / "out", d / "out", symlinks=True)
        trace = next(d.glob("out/S01/*/trials/*.trace.h5"))
        data = bytearray(trace.read_bytes())
        data[USER_BLOCK + (len(data) - USER_BLOCK) // 2] ^= 0x40
        trace.write_bytes(bytes(data))
        study = calligraphy.study.load(str(d / "out"))
        with self.assertRaises(calligraphy.DataError) as caught:
            study.samples(study.trials.index[0])
        self.assertIn(trace.name, str(caught.exception))

    # ---- other programs' honest layouts ------------------------------------------------------------------
    def test_contiguous_unfiltered_h5py_layout_reads_as_the_saved_trace(self):
        self.assert_reads_as_original("plain.trace.h5", lambda p: write_h5(p, self.cols()))

    def test_small_chunks_gzip_and_fletcher32_read_as_the_saved_trace(self):
        self.assert_reads_as_original("chunked.trace.h5", lambda p: write_h5(
            p, self.cols(), chunks=(1000,), compression="gzip", fletcher32=True))

    def test_int64_time_and_float64_position_read_as_the_saved_trace(self):
        def build(p):
            write_h5(p, self.cols(t=self.columns["t"].astype("<i8"),
                                  y=self.columns["y"] / 10 ** 7))
        self.assert_reads_as_original("wide.trace.h5", build)

    def test_soft_link_inside_the_file_reads_as_the_dataset_it_names(self):
        def build(p):
            write_h5(p, self.cols(z=None), extra=lambda f: f.__setitem__("z", h5py.SoftLink("/x")))
        rows = self.csv_rows(self.csv)
        expected = [rows[0]]
        for line in rows[1:]:
            fields = line.split(",")
            fields[3] = fields[1]
            expected.append(",".join(fields))
        self.assert_reads_as_original("soft.trace.h5", build, ("\n".join(expected) + "\n").encode())

    def test_compact_storage_reads_as_the_saved_trace(self):
        self.assert_reads_as_original("compact.trace.h5", lambda p: write_h5(
            p, self.cols(x=None), extra=lambda f: put(f, "x", self.columns["x"], compact=True)))

    def test_deflate_before_shuffle_reads_as_the_saved_trace(self):
        self.assert_reads_as_original("order.trace.h5", lambda p: write_h5(
            p, self.cols(y=None), extra=lambda f: put(f, "y", self.columns["y"], chunk=777,
                                                      filters=("deflate", "shuffle"))))

    def test_scaleoffset_filter_of_hdf5_reads_as_the_saved_trace(self):
        self.assert_reads_as_original("scaleoffset.trace.h5", lambda p: write_h5(
            p, self.cols(x=None), extra=lambda f: f.create_dataset(
                "x", data=self.columns["x"], chunks=(4096,), scaleoffset=0).attrs.update(
                    {"unit": np.bytes_(b"m"), "decimals": np.int32(7)})))

    def test_larger_user_block_reads_as_the_saved_trace(self):
        self.assert_reads_as_original("ub1024.trace.h5", lambda p: write_h5(p, self.cols(), userblock=1024))

    def test_samples_never_written_read_as_the_fill_value(self):
        half = self.n // 2
        rows = self.csv_rows(self.csv)
        expected = [rows[0]]
        for i, line in enumerate(rows[1:]):
            fields = line.split(",")
            if i >= half:
                fields[1] = "0"
            expected.append(",".join(fields))
        # chunks of 4096, the first `half` samples written: the rest of its chunk and the chunk after never written.
        self.assert_reads_as_original("fill.trace.h5", lambda p: write_h5(
            p, self.cols(x=None), extra=lambda f: put(f, "x", self.columns["x"], chunk=4096,
                                                      written=slice(0, half))),
            ("\n".join(expected) + "\n").encode())

    def test_nan_in_a_force_is_read_as_a_faulted_tick(self):
        fx = self.columns["fx"] / 10 ** 4
        fx[10] = np.nan
        d = self.folder()
        write_h5(d / "nanf.trace.h5", self.cols(fx=fx))
        result = run(["trace", "nanf.trace.h5", "--csv", "out.csv"], d)
        self.assertEqual(result.returncode, 0, result.stderr.decode("utf-8", "replace"))
        got = self.csv_rows((d / "out.csv").read_bytes())
        want = self.csv_rows(self.csv)
        self.assertEqual(len(got), len(want))
        self.assertTrue(np.isnan(float(got[11].split(",")[4])), got[11])
        self.assertEqual(got[:11] + got[12:], want[:11] + want[12:])

    def test_chunks_never_written_in_the_library_layout_read_as_the_fill_value(self):
        x = self.columns["x"]
        first = np.ascontiguousarray(x[:4096])
        rows = self.csv_rows(self.csv)
        expected = [rows[0]]
        for i, line in enumerate(rows[1:]):
            fields = line.split(",")
            if i >= 4096:
                fields[1] = "0.0012345"
            expected.append(",".join(fields))
        self.assert_reads_as_original("fillvalue.trace.h5", lambda p: write_h5(
            p, self.cols(x=None), extra=library_layout_x(x, 4096, {0: zlib.compress(shuffled(first))},
                                                         fillvalue=12345)),
            ("\n".join(expected) + "\n").encode())

    # ---- forged files ------------------------------------------------------------------------------------
    def copy_with(self, mutate):
        def build(p):
            data = bytearray(self.bytes)
            p.write_bytes(bytes(mutate(data)))
        return build

    def test_flipped_byte_after_user_block_is_refused_naming_file_nothing_written(self):
        def flip(data):
            data[USER_BLOCK + (len(data) - USER_BLOCK) // 2] ^= 0x01
            return data
        self.assert_refused("flipped.trace.h5", self.copy_with(flip))

    def test_cut_file_is_refused_naming_file(self):
        self.assert_refused("cut.trace.h5", self.copy_with(lambda d: d[:len(d) * 2 // 3]))
        self.assert_refused("block.trace.h5", self.copy_with(lambda d: d[:USER_BLOCK]))

    def test_file_of_zeros_and_empty_file_are_refused_naming_them(self):
        self.assert_refused("zeros.trace.h5", lambda p: p.write_bytes(b"\0" * len(self.bytes)))
        self.assert_refused("empty.trace.h5", lambda p: p.write_bytes(b""))

    def test_csv_given_as_trace_is_refused_naming_it(self):
        self.assert_refused("t.csv", lambda p: p.write_bytes(self.csv))

    def test_header_with_wrong_length_is_refused(self):
        def build(p):
            rest = self.bytes[USER_BLOCK:]
            p.write_bytes(user_block(rest + b"\0") + rest)
        self.assert_refused("length.trace.h5", build)

    def test_appended_bytes_after_a_valid_trace_are_refused(self):
        self.assert_refused("longer.trace.h5", lambda p: p.write_bytes(self.bytes + b"\0" * 16))

    def test_column_of_float32_is_refused_naming_the_column(self):
        self.assert_refused("f32.trace.h5", lambda p: write_h5(
            p, self.cols(x=self.columns["x"].astype("<f4")), attrs={"x": {"decimals": np.int32(7)}}), "x")

    def test_big_endian_column_is_refused_naming_the_column(self):
        self.assert_refused("be.trace.h5", lambda p: write_h5(p, self.cols(x=self.columns["x"].astype(">i4"))),
                            "x")

    def test_state_stored_as_plain_uint8_is_refused_naming_it(self):
        def build(p):
            cols = self.cols(state=None)
            write_h5(p, cols, extra=lambda f: f.create_dataset(
                "state", data=self.columns["state"].astype(np.uint8).view(np.dtype("u1"))))
        # the enum's metadata dropped: a plain uint8 dataset
        d_line = self.assert_refused("plainstate.trace.h5", build, "state")
        self.assertIn("state", d_line)

    def test_columns_of_different_lengths_are_refused(self):
        self.assert_refused("ragged.trace.h5", lambda p: write_h5(p, self.cols(y=self.columns["y"][:-1])))

    def test_missing_column_is_refused_naming_it(self):
        self.assert_refused("nofz.trace.h5", lambda p: write_h5(p, self.cols(fz=None)), "fz")

    def test_samples_attribute_other_than_the_columns_is_refused(self):
        for name, samples in (("plus1.trace.h5", self.n + 1), ("big.trace.h5", 9_000_000),
                              ("huge.trace.h5", 20_000_000)):
            with self.subTest(samples=samples):
                self.assert_refused(name, lambda p: write_h5(p, self.cols(), root={"samples": np.uint64(samples)}),
                                    "samples")

    def test_nan_in_a_position_is_refused(self):
        x = self.columns["x"] / 10 ** 7
        x[self.n // 2] = np.nan
        self.assert_refused("nan.trace.h5", lambda p: write_h5(p, self.cols(x=x)))

    def test_nan_in_time_is_refused(self):
        t = self.columns["t"] / 10 ** 6
        t[3] = np.nan
        self.assert_refused("nant.trace.h5", lambda p: write_h5(p, self.cols(t=t)))

    def test_state_beyond_ws_is_refused(self):
        state = self.columns["state"].astype(np.uint8).copy()
        state[self.n // 2] = 4
        def build(p):
            write_h5(p, self.cols(state=state))
            with h5py.File(p, "r") as f:  # the forged value is in the file
                assert int(f["state"][self.n // 2]) == 4
        self.assert_refused("ws.trace.h5", build)

    def test_rewritten_of_2_is_refused(self):
        rewritten = self.columns["rewritten"].copy()
        rewritten[7] = 2
        self.assert_refused("rw.trace.h5", lambda p: write_h5(p, self.cols(rewritten=rewritten)))

    def test_external_link_to_another_trace_is_refused_outside_the_file(self):
        def build(p):
            write_h5(p.with_name("other.h5"), self.cols())
            write_h5(p, self.cols(x=None), extra=lambda f: f.__setitem__("x", h5py.ExternalLink("other.h5", "/x")))
        self.assert_refused_keep_other("ext.trace.h5", build, "x", "outside")

    def assert_refused_keep_other(self, name, build, *needles, timeout=None):
        d = self.folder()
        build(d / name)
        listing = sorted(os.listdir(d))
        kw = {} if timeout is None else {"timeout": timeout}
        result = run(["trace", name, "--csv", "out.csv"], d, **kw)
        self.assert_one_error(result, 1, name, *needles)
        self.assertEqual(sorted(os.listdir(d)), listing)

    def test_external_link_to_fifo_is_refused_at_once_never_waited_on(self):
        def build(p):
            os.mkfifo(p.with_name("pipe.h5"))
            write_h5(p, self.cols(x=None), extra=lambda f: f.__setitem__("x", h5py.ExternalLink("pipe.h5", "/x")))
        start = time.monotonic()
        try:
            self.assert_refused_keep_other("fifo.trace.h5", build, "x", timeout=10)
        except subprocess.TimeoutExpired:
            self.fail("trace waited on the FIFO an external link names")
        self.assertLess(time.monotonic() - start, 5)

    def test_samples_never_written_without_fill_are_refused_naming_the_column(self):
        self.assert_refused("nofill.trace.h5", lambda p: write_h5(
            p, self.cols(x=None), extra=lambda f: put(f, "x", self.columns["x"], chunk=4096,
                                                      fill_time=h5py.h5d.FILL_TIME_NEVER,
                                                      written=slice(0, self.n // 2))), "x")

    def test_lzf_filter_is_refused_naming_the_column_and_32000(self):
        self.assert_refused("lzf.trace.h5", lambda p: write_h5(
            p, self.cols(x=None), extra=lambda f: f.create_dataset(
                "x", data=self.columns["x"], compression="lzf").attrs.update(
                    {"unit": np.bytes_(b"m"), "decimals": np.int32(7)})), "x", "32000")

    def test_virtual_dataset_of_another_file_is_refused_outside_the_file(self):
        def build(p):
            write_h5(p.with_name("other.h5"), self.cols())
            def vds(f):
                layout = h5py.VirtualLayout(shape=(self.n,), dtype="<i4")
                layout[:] = h5py.VirtualSource("other.h5", "x", shape=(self.n,))
                f.create_virtual_dataset("x", layout).attrs.update(
                    {"unit": np.bytes_(b"m"), "decimals": np.int32(7)})
            write_h5(p, self.cols(x=None), extra=vds)
        self.assert_refused_keep_other("vds.trace.h5", build, "x", "outside")

    def test_external_raw_storage_is_refused_outside_the_file(self):
        def build(p):
            def ext(f):
                f.create_dataset("x", data=self.columns["x"],
                                 external=[(str(p.with_name("raw.bin")), 0, self.n * 4)]).attrs.update(
                    {"unit": np.bytes_(b"m"), "decimals": np.int32(7)})
            write_h5(p, self.cols(x=None), extra=ext)
        self.assert_refused_keep_other("raw.trace.h5", build, "x", "outside")

    def test_two_dimensional_column_is_refused_naming_it(self):
        self.assert_refused("twod.trace.h5", lambda p: write_h5(
            p, self.cols(z=self.columns["z"].reshape(-1, 1))), "z")

    def test_mistyped_label_columns_are_refused_naming_them(self):
        for name, values in (("stroke", self.columns["stroke"].astype("<i8")),
                             ("attempt", self.columns["attempt"].astype("<u4"))):
            with self.subTest(column=name):
                self.assert_refused(f"{name}.trace.h5", lambda p: write_h5(p, self.cols(**{name: values})), name)

    def test_attribute_of_another_class_or_shape_is_refused_naming_it(self):
        for name, root in (("sfloat.trace.h5", {"samples": np.float64(self.n)}),
                           ("fmt2.trace.h5", {"format": np.array([b"calligraphy-trace", b"calligraphy-trace"])})):
            with self.subTest(file=name):
                self.assert_refused(name, lambda p: write_h5(p, self.cols(), root=root),
                                    next(iter(root)))

    def test_header_of_version_2_is_refused(self):
        def build(p):
            rest = self.bytes[USER_BLOCK:]
            p.write_bytes(user_block(rest).replace(b"version 1", b"version 2") + rest)
        self.assert_refused("hv2.trace.h5", build)

    def test_score_of_a_flipped_trace_is_refused_naming_it(self):
        d = self.folder()
        data = bytearray(self.bytes)
        data[USER_BLOCK + 100] ^= 0x10
        (d / "s.trace.h5").write_bytes(bytes(data))
        result = run(["score", "s.trace.h5", "--character", "十", "--json", "out.json"], d)
        self.assert_one_error(result, 1, "s.trace.h5")
        self.assertEqual(os.listdir(d), ["s.trace.h5"])

    def test_refused_name_with_line_break_and_escape_is_printed_as_printable_text(self):
        name = "bad\nname\x1b[31m.trace.h5"
        d = self.folder()
        (d / name).write_bytes(b"\0" * 1024)
        result = run(["trace", name, "--csv", "out.csv"], d)
        self.assert_one_error(result, 1, "bad\\nname\\x1b[31m.trace.h5")
        self.assertNotIn("\x1b", result.stderr.decode("utf-8", "replace"))
        self.assertEqual(sorted(os.listdir(d)), [name])

    def test_chunk_inflating_to_fewer_samples_than_it_holds_is_refused(self):
        # The library's own layout, one chunk of all N samples whose deflate stream holds only the first 100:
        # HDF5 leaves the other samples undefined (h5py reads other values on every run).
        x = self.columns["x"]
        raw = zlib.compress(shuffled(np.ascontiguousarray(x[:100])))
        d = self.folder()
        write_h5(d / "short.trace.h5", self.cols(x=None), extra=library_layout_x(x, self.n, {0: raw}))
        listing = sorted(os.listdir(d))
        first = run(["trace", "short.trace.h5", "--csv", "out.csv"], d)
        if first.returncode == 0:
            once = (d / "out.csv").read_bytes()
            run(["trace", "short.trace.h5", "--csv", "out.csv"], d)
            again = (d / "out.csv").read_bytes()
            self.fail(f"a chunk holding 100 of {self.n} samples was read (exit 0); two runs "
                      f"{'differ' if once != again else 'agree'}")
        self.assert_one_error(first, 1, "short.trace.h5", "x")
        self.assertEqual(sorted(os.listdir(d)), listing)

    def test_study_samples_of_another_valid_trace_names_it_and_both_sha256(self):
        import calligraphy
        import calligraphy.study
        d = self.folder()
        shutil.copytree(self.tmp / "out", d / "out", symlinks=True)
        trace = next(d.glob("out/S01/*/trials/*.trace.h5"))
        write_h5(trace, self.cols())  # the same columns in another layout: other bytes, another SHA-256
        study = calligraphy.study.load(str(d / "out"))
        with self.assertRaises(calligraphy.DataError) as caught:
            study.samples(study.trials.index[0])
        # "naming both": the trace's SHA-256 and the one its record names (docs/experiments.md, "Trial records")
        self.assertIn(trace.name, str(caught.exception))
        self.assertIn(hashlib.sha256(trace.read_bytes()).hexdigest(), str(caught.exception))
        self.assertIn(self.record["files"]["trace_sha256"], str(caught.exception))

    def test_decimals_attribute_3_is_refused_with_the_documented_line(self):
        line = self.assert_refused("dec.trace.h5", lambda p: write_h5(
            p, self.cols(), attrs={"x": {"decimals": np.int32(3)}}))
        self.assertIn("column 'x': attribute /x/decimals is 3, this version writes 7", line)

    def test_missing_decimals_on_an_integer_column_is_refused_naming_it(self):
        self.assert_refused("nodec.trace.h5", lambda p: write_h5(p, self.cols(), attrs={"fx": {"decimals": None}}),
                            "/fx/decimals")

    def test_unit_other_than_written_is_refused_naming_it(self):
        self.assert_refused("unit.trace.h5", lambda p: write_h5(
            p, self.cols(), attrs={"x": {"unit": np.bytes_(b"mm")}}), "/x/unit")

    def test_newer_version_is_refused(self):
        self.assert_refused("v2.trace.h5", lambda p: write_h5(p, self.cols(), root={"version": np.int32(2)}),
                            "version")

    def test_foreign_format_attribute_is_refused(self):
        self.assert_refused("fmt.trace.h5", lambda p: write_h5(
            p, self.cols(), root={"format": np.bytes_(b"other-trace")}), "format")

    def test_file_over_256_mib_is_refused_before_it_is_read(self):
        def build(p):
            with open(p, "wb") as f:
                f.write(self.bytes)
                f.truncate((256 << 20) + 1)
        before = resource.getrusage(resource.RUSAGE_CHILDREN)
        self.assert_refused("large.trace.h5", build, keep=False)
        after = resource.getrusage(resource.RUSAGE_CHILDREN)
        self.assertLess(after.ru_utime + after.ru_stime - before.ru_utime - before.ru_stime, 0.5)

    def test_fifo_as_trace_is_refused_at_once(self):
        try:
            line = self.assert_refused("in.fifo", lambda p: os.mkfifo(p), timeout=10)
        except subprocess.TimeoutExpired:
            self.fail("trace waited on a FIFO given as its input")
        self.assertIn("not a regular file", line)

    def test_folder_as_trace_is_refused_naming_it(self):
        self.assert_refused("dir.trace.h5", lambda p: p.mkdir())

    def test_dash_as_trace_says_standard_input_is_not_read(self):
        d = self.folder()
        result = run(["trace", "-"], d)
        self.assert_one_error(result, 1, "standard input")
        self.assertEqual(os.listdir(d), [])

    # ---- outputs -----------------------------------------------------------------------------------------
    def trace_copy(self, d):
        (d / "T.trace.h5").write_bytes(self.bytes)
        return d / "T.trace.h5"

    def assert_unchanged(self, d, listing, trace):
        self.assertEqual(sorted(os.listdir(d)), listing)
        self.assertEqual(trace.read_bytes(), self.bytes)

    def test_csv_output_the_input_itself_is_a_collision_exit_2_input_unchanged(self):
        d = self.folder()
        trace = self.trace_copy(d)
        listing = sorted(os.listdir(d))
        result = run(["trace", "T.trace.h5", "--csv", "./T.trace.h5"], d)
        self.assert_one_error(result, 2, "--csv", "T.trace.h5")
        self.assert_unchanged(d, listing, trace)

    def test_csv_output_a_symbolic_link_to_the_input_is_a_collision(self):
        d = self.folder()
        trace = self.trace_copy(d)
        os.symlink("T.trace.h5", d / "link.csv")
        listing = sorted(os.listdir(d))
        result = run(["trace", "T.trace.h5", "--csv", "link.csv"], d)
        self.assert_one_error(result, 2, "--csv", "link.csv")
        self.assert_unchanged(d, listing, trace)
        self.assertEqual(os.readlink(d / "link.csv"), "T.trace.h5")

    def test_csv_output_a_hard_link_to_the_input_is_a_collision(self):
        d = self.folder()
        trace = self.trace_copy(d)
        os.link(trace, d / "hard.csv")
        listing = sorted(os.listdir(d))
        result = run(["trace", "T.trace.h5", "--csv", "hard.csv"], d)
        self.assert_one_error(result, 2, "--csv", "hard.csv")
        self.assert_unchanged(d, listing, trace)
        self.assertEqual(os.stat(d / "hard.csv").st_ino, os.stat(trace).st_ino)

    def test_csv_into_a_missing_folder_is_refused_naming_it(self):
        d = self.folder()
        trace = self.trace_copy(d)
        listing = sorted(os.listdir(d))
        result = run(["trace", "T.trace.h5", "--csv", "missing/t.csv"], d)
        self.assert_one_error(result, 1, "--csv", "missing", "does not exist")
        self.assert_unchanged(d, listing, trace)

    def test_csv_naming_a_folder_is_refused_folder_unchanged(self):
        d = self.folder()
        trace = self.trace_copy(d)
        (d / "sub").mkdir()
        listing = sorted(os.listdir(d))
        result = run(["trace", "T.trace.h5", "--csv", "sub"], d)
        self.assert_one_error(result, 1, "--csv", "sub")
        self.assert_unchanged(d, listing, trace)
        self.assertEqual(os.listdir(d / "sub"), [])

    def test_csv_to_dev_full_is_one_error_exit_1(self):
        d = self.folder()
        self.trace_copy(d)
        result = run(["trace", "T.trace.h5", "--csv", "/dev/full"], d)
        self.assert_one_error(result, 1, "/dev/full")

    def test_standard_output_to_dev_full_is_one_error_exit_1(self):
        d = self.folder()
        self.trace_copy(d)
        with open("/dev/full", "wb") as full:
            result = run(["trace", "T.trace.h5"], d, stdout=full)
        self.assert_one_error(result, 1)

    def test_csv_to_dev_stdout_on_a_pipe_gives_the_csv(self):
        d = self.folder()
        self.trace_copy(d)
        result = run_ok(["trace", "T.trace.h5", "--csv", "/dev/stdout"], d)
        self.assertTrue(result.stdout.startswith(self.csv), result.stdout[-200:])

    def test_pipe_closed_early_is_one_error_exit_1(self):
        d = self.folder()
        self.trace_copy(d)
        process = subprocess.Popen([CLI, "trace", "T.trace.h5"], cwd=d, env=ENV, stdin=subprocess.DEVNULL,
                                   stdout=subprocess.PIPE, stderr=subprocess.PIPE)
        first = process.stdout.readline()
        process.stdout.close()
        err = process.stderr.read()
        process.stderr.close()
        status = process.wait(timeout=30)
        self.assertEqual(first.decode(), HEADER + "\n")
        self.assertEqual(status, 1, err)
        lines = err.decode("utf-8", "replace").strip().splitlines()
        self.assertEqual(len(lines), 1, lines)
        self.assertIn("error", lines[0])

    def test_csv_through_a_symbolic_link_replaces_the_file_it_names(self):
        d = self.folder()
        self.trace_copy(d)
        (d / "real.csv").write_text("old\n")
        os.symlink("real.csv", d / "link.csv")
        os.symlink("new.csv", d / "dangling.csv")
        run_ok(["trace", "T.trace.h5", "--csv", "link.csv"], d)
        run_ok(["trace", "T.trace.h5", "--csv", "dangling.csv"], d)
        self.assertEqual(os.readlink(d / "link.csv"), "real.csv")
        self.assertEqual(os.readlink(d / "dangling.csv"), "new.csv")
        self.assertEqual((d / "real.csv").read_bytes(), self.csv)
        self.assertEqual((d / "new.csv").read_bytes(), self.csv)
        self.assertEqual(sorted(os.listdir(d)), ["T.trace.h5", "dangling.csv", "link.csv", "new.csv", "real.csv"])

    def test_replaced_csv_keeps_its_permission_bits(self):
        d = self.folder()
        self.trace_copy(d)
        (d / "t.csv").write_text("old\n")
        os.chmod(d / "t.csv", 0o640)
        run_ok(["trace", "T.trace.h5", "--csv", "t.csv"], d)
        self.assertEqual(stat.S_IMODE(os.stat(d / "t.csv").st_mode), 0o640)
        self.assertEqual((d / "t.csv").read_bytes(), self.csv)

    def test_csv_given_twice_is_a_usage_error(self):
        d = self.folder()
        self.trace_copy(d)
        result = run(["trace", "T.trace.h5", "--csv", "a.csv", "--csv", "b.csv"], d)
        self.assert_one_error(result, 2, "--csv")
        self.assertEqual(sorted(os.listdir(d)), ["T.trace.h5"])

    def test_csv_value_starting_with_dash_is_refused_naming_csv(self):
        d = self.folder()
        self.trace_copy(d)
        result = run(["trace", "T.trace.h5", "--csv", "--verbose"], d)
        self.assert_one_error(result, 2, "--csv")
        self.assertEqual(sorted(os.listdir(d)), ["T.trace.h5"])

    def test_csv_of_the_longest_file_name_is_written_no_temporary_left(self):
        d = self.folder()
        self.trace_copy(d)
        name = "a" * 251 + ".csv"
        run_ok(["trace", "T.trace.h5", "--csv", name], d)
        self.assertEqual((d / name).read_bytes(), self.csv)
        self.assertEqual(sorted(os.listdir(d)), ["T.trace.h5", name])

    def test_input_through_a_symbolic_link_and_output_the_file_it_names_collide(self):
        d = self.folder()
        trace = self.trace_copy(d)
        os.symlink("T.trace.h5", d / "in.h5")
        listing = sorted(os.listdir(d))
        result = run(["trace", "in.h5", "--csv", "T.trace.h5"], d)
        self.assert_one_error(result, 2, "--csv")
        self.assert_unchanged(d, listing, trace)

    def test_file_size_limit_is_one_error_earlier_file_kept_no_temporary(self):
        d = self.folder()
        self.trace_copy(d)
        (d / "t.csv").write_text("old\n")
        listing = sorted(os.listdir(d))

        def limit():
            resource.setrlimit(resource.RLIMIT_FSIZE, (4096, 4096))
        result = run(["trace", "T.trace.h5", "--csv", "t.csv"], d, preexec_fn=limit)
        self.assert_one_error(result, 1, "t.csv")
        self.assertEqual((d / "t.csv").read_text(), "old\n")
        self.assertEqual(sorted(os.listdir(d)), listing)

    def test_csv_into_a_fifo_with_a_reader_is_written_in_place(self):
        import threading
        d = self.folder()
        self.trace_copy(d)
        os.mkfifo(d / "out.fifo")
        got = []

        def reader():
            with open(d / "out.fifo", "rb") as f:
                got.append(f.read())
        thread = threading.Thread(target=reader, daemon=True)
        thread.start()
        result = run(["trace", "T.trace.h5", "--csv", "out.fifo"], d)
        if thread.is_alive():  # the program never opened it: let the reader go
            with open(d / "out.fifo", "wb"):
                pass
        thread.join(5)
        self.assertEqual(result.returncode, 0, result.stderr.decode("utf-8", "replace"))
        self.assertEqual(got, [self.csv])
        self.assertTrue(stat.S_ISFIFO(os.lstat(d / "out.fifo").st_mode))
        self.assertEqual(sorted(os.listdir(d)), ["T.trace.h5", "out.fifo"])

    # ---- a large honest trace ----------------------------------------------------------------------------
    def test_large_honest_trace_of_200000_samples_is_read_fast(self):
        n = 200_000
        reps = -(-n // self.n)

        def tile(values):
            return np.tile(values, reps)[:n]
        cols = {name: tile(values) for name, values in self.columns.items()}
        cols["t"] = np.arange(n, dtype="<i4") * 1000
        cols["state"] = tile(self.columns["state"].astype(np.uint8)).astype(self.state_dtype)
        d = self.folder()
        write_h5(d / "big.trace.h5", cols, chunks=(65536,), shuffle=True, compression="gzip",
                 compression_opts=1)
        before = resource.getrusage(resource.RUSAGE_CHILDREN)
        result = run(["trace", "big.trace.h5", "--csv", "big.csv"], d)
        after = resource.getrusage(resource.RUSAGE_CHILDREN)
        self.assertEqual(result.returncode, 0, result.stderr.decode("utf-8", "replace"))
        cpu = after.ru_utime + after.ru_stime - before.ru_utime - before.ru_stime
        self.assertLess(cpu, 1.5)
        with open(d / "big.csv", "rb") as f:
            lines = f.read().split(b"\n")
        self.assertEqual(len(lines), n + 2)
        self.assertEqual(lines[-1], b"")
        self.assertEqual(lines[n].split(b",")[0], b"199.999")


if __name__ == "__main__":
    unittest.main()
