#!/usr/bin/env python3
"""Round 23A: HDF5 traces made by another tool, with what the HDF5 format allows. From the docs alone
(docs/experiments.md "Trace files", "Trial records"; docs/cli.md "trace", "score", "Pen traces", "report";
docs/python.md "A study's traces"; include/calligraphy/report/trace_hdf5.hpp).

A session's trace (`.trace.h5`) is bound to its record by the SHA-256 of the file's bytes, its 512-byte user
block carries the length and CRC-32 of the HDF5 file after it, and "only the exact column types" are read,
"a layout other than the one the library writes (another program's filters) ... through HDF5's own pipeline".
Earlier rounds forged columns and attributes; this one keeps every documented column and attribute (and a
correct header) and uses HDF5's own indirections: a column whose bytes live outside the file (an external
link, a virtual dataset, external raw storage; to a file beside it, /etc/passwd or a FIFO), links inside the
file (soft, hard, dangling, a group holding itself, columns in a nested group, the root's attributes on a
group), storage and filters (1-sample and huge chunks, an edge chunk, gzip, shuffle, fletcher32 intact and
damaged, deflate before shuffle, a filter this HDF5 lacks, a fill value never written, compact and contiguous
storage, a resizable column), column types HDF5 has (compound, enum of other numbers, vlen, references), a
larger user block and traces written by h5py from scratch in the oldest and newest file formats. Each is
either read as the program's own trace reads (the same CSV from `trace`, byte for byte) or refused in one line
naming the file and the column (exit 1), never hanging, never reading a byte from outside the file, and a
study never takes a changed trace under an unchanged SHA-256.

CALLIGRAPHY_CLI names the program, PYTHONPATH its Python module. CALLIGRAPHY_SANITIZED=1 takes five cases.
"""
import hashlib
import json
import os
import resource
import shutil
import subprocess
import tempfile
import unittest
import zlib
from pathlib import Path

from outsider import OneErrorLine, run, run_ok, sanitized_subset

try:
    import h5py
    import numpy as np
except ImportError:  # pragma: no cover - Debian's python3-h5py is a test dependency
    h5py = None

load_tests = sanitized_subset({"test_external_raw_storage_beside_the_trace_is_refused",
                               "test_external_link_to_a_fifo_is_refused_at_once",
                               "test_virtual_dataset_of_another_file_is_refused",
                               "test_deflate_before_shuffle_reads_as_hdf5_reads_it",
                               "test_trace_from_scratch_in_the_newest_format_reads_as_the_programs_own"})

COLUMNS = ("t", "x", "y", "z", "fx", "fy", "fz", "state", "stroke", "element", "attempt", "rewritten")
PROTOCOL = {"name": "p", "conditions": [{"name": "V", "mode": "vision"}],
            "test": {"characters": ["一"], "conditions": ["V"], "repetitions": 1},
            "trial": {"max_duration_s": 0.4}}


def reheader(path):
    """The documented 512-byte user block (`calligraphy-trace`, the version, the length and CRC-32 of the rest)
    written over the first 512 bytes, so that the reader judges the HDF5 content itself."""
    data = bytearray(Path(path).read_bytes())
    body = bytes(data[512:])
    head = f"calligraphy-trace\nversion 1\nbytes {len(body)}\ncrc32 {zlib.crc32(body):08x}\n".encode()
    data[:512] = head + b"\0" * (512 - len(head))
    Path(path).write_bytes(bytes(data))


def attributes(obj):
    """An object's attributes with their HDF5 types: [(name, value, dtype)]."""
    return [(k, obj.attrs[k], obj.attrs.get_id(k).dtype) for k in obj.attrs]


def copy_attributes(target, attrs):
    for key, value, dtype in attrs:
        target.attrs.create(key, value, dtype=dtype)


def default_column(f, name, data, dtype):
    return f.create_dataset(name, data=data, dtype=dtype, chunks=(len(data),), compression="gzip",
                            shuffle=True)


class Round23A(unittest.TestCase, OneErrorLine):
    @classmethod
    def setUpClass(cls):
        if h5py is None:
            raise unittest.SkipTest("h5py is not installed (Debian: python3-h5py)")
        cls.tmp = Path(tempfile.mkdtemp(prefix="round23a-"))
        (cls.tmp / "p.json").write_text(json.dumps(PROTOCOL), encoding="utf-8")
        run_ok(["session", "run", "p.json", "--subject", "S01", "--out", "study", "--writer", "simulated",
                "--writer-learning", "none"], cls.tmp)
        cls.own = next((cls.tmp / "study").glob("S01/*/trials/*.trace.h5"))
        cls.csv = run_ok(["trace", cls.own], cls.tmp).stdout
        with h5py.File(cls.own, "r") as f:
            cls.root = attributes(f)
            cls.data = {name: (f[name][()], f[name].dtype, attributes(f[name])) for name in f}
        cls.n = len(cls.data["t"][0])
        cls.count = 0

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.tmp, ignore_errors=True)

    def folder(self):
        type(self).count += 1
        path = self.tmp / f"case{self.count:02d}"
        path.mkdir()
        return path

    def build(self, path, column=None, root=None, userblock=512, libver=None, extra=None):
        """A trace of the session's columns and attributes written by h5py: `column(f, name, data, dtype)`
        makes a column (None: the default, leaving it to the next), `root(f)` returns where the root's
        attributes go, `extra(f)` adds to the file; the documented header written last."""
        kwargs = {"userblock_size": userblock}
        if libver:
            kwargs["libver"] = libver
        with h5py.File(path, "w", **kwargs) as f:
            copy_attributes(root(f) if root else f, self.root)
            for name, (data, dtype, attrs) in self.data.items():
                made = column(f, name, data, dtype) if column else None
                if made is None:
                    made = default_column(f, name, data, dtype)
                if made is not False:
                    copy_attributes(made, attrs)
            if extra:
                extra(f)
        reheader(path)
        return path

    def trace(self, path, cwd=None, timeout=20):
        return run(["trace", path], cwd or path.parent, timeout=timeout)

    def assert_same(self, path, cwd=None):
        result = self.trace(path, cwd)
        self.assertEqual(result.returncode, 0, result.stderr.decode("utf-8", "replace"))
        self.assertEqual(result.stdout, self.csv)
        self.assertEqual(result.stderr, b"")

    def assert_refused(self, path, *needles, cwd=None):
        result = self.trace(path, cwd)
        line = self.assert_one_error(result, 1, path.name, *needles)
        self.assertEqual(result.stdout, b"")
        return line

    def x_column(self, csv):
        lines = csv.decode().splitlines()
        index = lines[0].split(",").index("x")
        return [float(line.split(",")[index]) for line in lines[1:]]

    def x_bytes(self, values=None):
        data = self.data["x"][0] if values is None else values
        return np.asarray(data, dtype="<i4").tobytes()

    # --- 1. a column's bytes outside the file --------------------------------------------------------------

    def test_external_raw_storage_beside_the_trace_is_refused(self):
        # `x` stored as raw bytes in x.bin beside the trace (HDF5's external storage): the file's SHA-256
        # does not cover them, so changing x.bin would change the trace. Refused naming the column; x.bin
        # differs from the real x, so a reader that took it would not give the program's CSV either.
        d = self.folder()
        (d / "x.bin").write_bytes(self.x_bytes(self.data["x"][0] + 1000))

        def column(f, name, data, dtype):
            if name == "x":
                return f.create_dataset("x", shape=data.shape, dtype=dtype,
                                        external=[("x.bin", 0, len(data) * 4)])
            return None
        path = self.build(d / "e.trace.h5", column)
        self.assert_refused(path, "'x'", "outside")
        result = run(["score", path, "--character", "一"], d)
        self.assert_one_error(result, 1, path.name, "'x'", "outside")
        self.assertEqual(result.stdout, b"")

    def test_time_and_stroke_columns_outside_the_file_are_refused_naming_each(self):
        # The time column (read first, for the samples) in external storage beside the trace, and `stroke` (an
        # integer column of the scene's indices) an external link to a file beside it.
        d = self.folder()
        (d / "t.bin").write_bytes(np.asarray(self.data["t"][0], dtype="<i4").tobytes())
        with h5py.File(d / "outside.h5", "w") as g:
            g.create_dataset("stroke", data=self.data["stroke"][0])

        def time_outside(f, name, data, dtype):
            if name == "t":
                return f.create_dataset("t", shape=data.shape, dtype=dtype,
                                        external=[("t.bin", 0, len(data) * 4)])
            return None

        def stroke_outside(f, name, data, dtype):
            if name == "stroke":
                f["stroke"] = h5py.ExternalLink("outside.h5", "/stroke")
                return False
            return None
        self.assert_refused(self.build(d / "t.trace.h5", time_outside), "'t'", "outside")
        self.assert_refused(self.build(d / "s.trace.h5", stroke_outside), "'stroke'", "outside")

    def test_external_raw_storage_naming_etc_passwd_reads_nothing_of_it(self):
        d = self.folder()
        size = min(os.path.getsize("/etc/passwd"), self.n * 4) // 4 * 4

        def column(f, name, data, dtype):
            if name == "x":
                return f.create_dataset("x", shape=(size // 4,), dtype=dtype,
                                        external=[("/etc/passwd", 0, size)])
            return None
        # Every column as long as the passwd bytes give, so only the external storage is at fault.
        data = self.data
        try:
            self.data = {k: (v[:size // 4], t, a) for k, (v, t, a) in data.items()}
            self.root = [(k, size // 4 if k == "samples" else v, t) for k, v, t in type(self).root]
            path = self.build(d / "p.trace.h5", column)
        finally:
            self.data, self.root = data, type(self).root
        self.assert_refused(path, "'x'", "outside")

    def test_external_link_to_a_file_beside_it_is_refused(self):
        d = self.folder()
        with h5py.File(d / "outside.h5", "w") as g:
            g.create_dataset("x", data=self.data["x"][0])
            copy_attributes(g["x"], self.data["x"][2])

        def column(f, name, data, dtype):
            if name == "x":
                f["x"] = h5py.ExternalLink("outside.h5", "/x")
                return False
            return None
        path = self.build(d / "l.trace.h5", column)
        self.assert_refused(path, "'x'")

    def test_external_link_to_etc_passwd_is_refused(self):
        d = self.folder()

        def column(f, name, data, dtype):
            if name == "x":
                f["x"] = h5py.ExternalLink("/etc/passwd", "/x")
                return False
            return None
        path = self.build(d / "pw.trace.h5", column)
        self.assert_refused(path, "'x'")

    def test_external_link_to_a_fifo_is_refused_at_once(self):
        d = self.folder()
        os.mkfifo(d / "fifo")

        def column(f, name, data, dtype):
            if name == "x":
                f["x"] = h5py.ExternalLink(str(d / "fifo"), "/x")
                return False
            return None
        path = self.build(d / "f.trace.h5", column)
        self.assert_refused(path, "'x'")

    def test_soft_link_to_an_external_link_to_a_fifo_is_refused_at_once(self):
        # `x` a soft link inside the file to `/ext`, itself an external link to a FIFO: followed by HDF5 only
        # when the column is opened, so the column's own link being soft must not let it through.
        d = self.folder()
        os.mkfifo(d / "fifo")

        def column(f, name, data, dtype):
            if name == "x":
                f["ext"] = h5py.ExternalLink(str(d / "fifo"), "/x")
                f["x"] = h5py.SoftLink("/ext")
                return False
            return None
        path = self.build(d / "sf.trace.h5", column)
        self.assert_refused(path, "'x'", "outside")

    def test_an_external_link_beside_the_columns_is_never_followed(self):
        # Every column in the file, and one more member, an external link to a FIFO: no column needs it, so
        # the trace reads as the program's own without waiting on the FIFO.
        d = self.folder()
        os.mkfifo(d / "fifo")
        path = self.build(d / "xf.trace.h5",
                          extra=lambda f: f.__setitem__("notes", h5py.ExternalLink(str(d / "fifo"), "/n")))
        self.assert_same(path)

    def test_virtual_dataset_of_another_file_is_refused(self):
        d = self.folder()
        with h5py.File(d / "source.h5", "w") as g:
            g.create_dataset("x", data=self.data["x"][0])

        def column(f, name, data, dtype):
            if name == "x":
                layout = h5py.VirtualLayout(shape=data.shape, dtype=dtype)
                layout[:] = h5py.VirtualSource(str(d / "source.h5"), "x", shape=data.shape)
                return f.create_virtual_dataset("x", layout, fillvalue=0)
            return None
        path = self.build(d / "v.trace.h5", column, libver="latest")
        self.assert_refused(path, "'x'")

    def test_virtual_dataset_of_a_fifo_is_refused_at_once(self):
        d = self.folder()
        os.mkfifo(d / "fifo")

        def column(f, name, data, dtype):
            if name == "x":
                layout = h5py.VirtualLayout(shape=data.shape, dtype=dtype)
                layout[:] = h5py.VirtualSource(str(d / "fifo"), "x", shape=data.shape)
                return f.create_virtual_dataset("x", layout, fillvalue=0)
            return None
        path = self.build(d / "vf.trace.h5", column, libver="latest")
        self.assert_refused(path, "'x'")

    def test_a_study_never_takes_a_changed_outside_column_under_the_same_sha256(self):
        # Another tool saved the trial's trace with `x` in external storage and its record names that file's
        # SHA-256: Study.samples and `report --out` refuse it rather than read whatever x.bin holds now.
        d = self.folder()
        shutil.copytree(self.tmp / "study", d / "study")
        trace = next((d / "study").glob("S01/*/trials/*.trace.h5"))
        outside = d / "x.bin"
        outside.write_bytes(self.x_bytes())

        def column(f, name, data, dtype):
            if name == "x":
                return f.create_dataset("x", shape=data.shape, dtype=dtype,
                                        external=[(str(outside), 0, len(data) * 4)])
            return None
        trace.unlink()
        self.build(trace, column)
        record_path = trace.with_name(trace.name.replace(".trace.h5", ".json"))
        record = json.loads(record_path.read_text(encoding="utf-8"))
        record["files"]["trace_sha256"] = hashlib.sha256(trace.read_bytes()).hexdigest()
        record_path.write_text(json.dumps(record, indent=2), encoding="utf-8")
        outside.write_bytes(self.x_bytes(self.data["x"][0] + 5000))
        script = ("import sys, calligraphy, calligraphy.study as s\n"
                  "st = s.load(sys.argv[1])\n"
                  "try:\n    st.samples(0)\nexcept calligraphy.DataError as e:\n    print('DataError', e)\n"
                  "else:\n    print('read')\n")
        got = subprocess.run(["/usr/bin/python3", "-c", script, str(d / "study")], capture_output=True,
                             timeout=60, text=True)
        self.assertEqual(got.returncode, 0, got.stderr)
        self.assertTrue(got.stdout.startswith("DataError"), got.stdout)
        self.assertIn(trace.name, got.stdout)
        result = run(["report", "study", "--out", "r.html"], d)
        self.assert_one_error(result, 1, trace.name, "'x'")

    # --- 2. links inside the file ---------------------------------------------------------------------------

    def test_soft_link_column_reads_as_h5py_reads_it(self):
        # `x` a soft link to `y`: inside the file, covered by its SHA-256; read as h5py reads it (y's values).
        d = self.folder()

        def column(f, name, data, dtype):
            if name == "x":
                return False
            return None
        path = self.build(d / "s.trace.h5", column, extra=lambda f: f.__setitem__("x", h5py.SoftLink("/y")))
        result = self.trace(path)
        self.assertEqual(result.returncode, 0, result.stderr)
        with h5py.File(path, "r") as f:
            expected = f["x"][()] / 10 ** f["x"].attrs["decimals"]
        self.assertEqual(self.x_column(result.stdout), [float(f"{v:.7f}") for v in expected])

    def test_dangling_soft_link_column_is_refused_naming_it(self):
        d = self.folder()

        def column(f, name, data, dtype):
            if name == "x":
                f["x"] = h5py.SoftLink("/nowhere")
                return False
            return None
        path = self.build(d / "dl.trace.h5", column)
        self.assert_refused(path, "'x'")

    def test_group_holding_itself_is_no_hang(self):
        # A hard link from a group to the root (a cycle); the columns are all there.
        d = self.folder()
        path = self.build(d / "c.trace.h5", extra=lambda f: f.__setitem__("loop", f))
        result = self.trace(path)
        if result.returncode == 0:
            self.assertEqual(result.stdout, self.csv)
        else:
            self.assert_one_error(result, 1, path.name, "loop")

    def test_columns_in_a_nested_group_are_refused_naming_one(self):
        d = self.folder()

        def column(f, name, data, dtype):
            group = f.require_group("trace")
            return default_column(group, name, data, dtype)
        path = self.build(d / "n.trace.h5", column)
        self.assert_refused(path)

    def test_root_attributes_on_a_group_are_refused_naming_format(self):
        d = self.folder()
        path = self.build(d / "a.trace.h5", root=lambda f: f.create_group("meta"))
        self.assert_refused(path, "format")

    # --- 3. storage and filters -----------------------------------------------------------------------------

    def chunked(self, **options):
        def column(f, name, data, dtype):
            return f.create_dataset(name, data=data, dtype=dtype, **options)
        return column

    def test_one_sample_chunks_read_as_the_programs_own(self):
        d = self.folder()
        self.assert_same(self.build(d / "c1.trace.h5", self.chunked(chunks=(1,), compression="gzip",
                                                                   shuffle=True)))

    def test_an_edge_chunk_past_the_end_reads_as_the_programs_own(self):
        # Chunks of 3/4 of the trace: the second reaches past the last sample.
        d = self.folder()
        chunk = self.n * 3 // 4
        self.assert_same(self.build(d / "ce.trace.h5", self.chunked(chunks=(chunk,), compression="gzip",
                                                                   shuffle=True, maxshape=(None,))))

    def test_huge_declared_chunks_are_no_crash_under_a_memory_limit(self):
        # A resizable column whose one chunk is declared as 2^26 samples (256 MiB of int32), deflated to a
        # quarter of a megabyte, most of it beyond the data: read, or refused in one line, under a 1 GiB
        # address-space limit. The chunk is written as its deflate stream (HDF5's direct chunk write).
        d = self.folder()
        chunk = 1 << 26

        def column(f, name, data, dtype):
            if name != "x":
                return None
            made = f.create_dataset("x", shape=data.shape, dtype=dtype, chunks=(chunk,), maxshape=(None,),
                                    compression="gzip")
            deflate = zlib.compressobj(1)
            parts = [deflate.compress(self.x_bytes())]
            zeros = bytes(1 << 22)
            rest = chunk * 4 - len(data) * 4
            while rest > 0:
                parts.append(deflate.compress(zeros[:min(rest, len(zeros))]))
                rest -= len(zeros)
            parts.append(deflate.flush())
            made.id.write_direct_chunk((0,), b"".join(parts))
            return made
        path = self.build(d / "ch.trace.h5", column)

        def limit():
            resource.setrlimit(resource.RLIMIT_AS, (1 << 30, 1 << 30))
        result = run(["trace", path], d, timeout=30, preexec_fn=limit)
        if result.returncode == 0:
            self.assertEqual(result.stdout, self.csv)
        else:
            self.assert_one_error(result, 1, path.name)

    def test_gzip_alone_reads_as_the_programs_own(self):
        d = self.folder()
        self.assert_same(self.build(d / "g.trace.h5", self.chunked(chunks=(64,), compression="gzip",
                                                                  compression_opts=9)))

    def test_fletcher32_reads_as_the_programs_own(self):
        d = self.folder()
        self.assert_same(self.build(d / "fl.trace.h5", self.chunked(chunks=(self.n,), compression="gzip",
                                                                   shuffle=True, fletcher32=True)))

    def test_fletcher32_over_a_damaged_chunk_is_refused(self):
        # Contiguous columns but `x`, which is chunked, unfiltered but for its checksum; one byte of its data
        # flipped, then the header's CRC-32 made to match: HDF5's checksum must refuse it.
        d = self.folder()
        marker = np.full(self.n, 0x5A5A5A5A, dtype="<i4")

        def column(f, name, data, dtype):
            if name == "x":
                return f.create_dataset("x", data=marker, dtype=dtype, chunks=(self.n,), fletcher32=True)
            return f.create_dataset(name, data=data, dtype=dtype)
        path = self.build(d / "fd.trace.h5", column)
        raw = bytearray(path.read_bytes())
        at = raw.find(marker.tobytes()[:64])
        self.assertGreater(at, 512)
        raw[at + 5] ^= 0x01
        path.write_bytes(bytes(raw))
        reheader(path)
        self.assert_refused(path, "'x'")

    def test_deflate_before_shuffle_reads_as_hdf5_reads_it(self):
        # The two filters the library writes, in the other order (deflate, then shuffle): their bytes must be
        # undone in that order, as HDF5's pipeline does, or the values come out scrambled.
        d = self.folder()

        def column(f, name, data, dtype):
            space = h5py.h5s.create_simple((len(data),))
            dcpl = h5py.h5p.create(h5py.h5p.DATASET_CREATE)
            dcpl.set_chunk((len(data),))
            dcpl.set_deflate(6)
            dcpl.set_shuffle()
            made = h5py.Dataset(h5py.h5d.create(f.id, name.encode(), h5py.h5t.py_create(dtype, logical=True),
                                                space, dcpl=dcpl))
            made[...] = data
            return made
        self.assert_same(self.build(d / "ds.trace.h5", column))

    def test_a_filter_this_hdf5_lacks_is_refused_naming_the_column(self):
        # LZF is h5py's own filter (id 32000), which the program's HDF5 does not have.
        d = self.folder()

        def column(f, name, data, dtype):
            if name == "x":
                return f.create_dataset("x", data=data, dtype=dtype, chunks=(64,), compression="lzf")
            return None
        path = self.build(d / "lzf.trace.h5", column)
        self.assert_refused(path, "'x'", "filter 32000")

    def test_scale_offset_filter_reads_as_the_programs_own(self):
        # HDF5's scale-offset filter, lossless on integers (its minimum bits found by HDF5), on every integer
        # column, through HDF5's pipeline; the enum `state` as written.
        d = self.folder()

        def column(f, name, data, dtype):
            if name == "state":
                return None
            return f.create_dataset(name, data=data, dtype=dtype, chunks=(100,), scaleoffset=0)
        self.assert_same(self.build(d / "so.trace.h5", column))

    def test_columns_of_committed_types_read_as_the_programs_own(self):
        # Each column's type stored once in the file as a named type (`h5py` committed datatypes) and the
        # columns made of it: the same types, by reference.
        d = self.folder()

        def column(f, name, data, dtype):
            key = "type_" + name
            f[key] = dtype
            return f.create_dataset(name, data=data, dtype=f[key], chunks=(len(data),), compression="gzip",
                                    shuffle=True)
        self.assert_same(self.build(d / "ct.trace.h5", column))

    def test_a_fill_value_never_written_reads_as_h5py_reads_it(self):
        d = self.folder()

        def column(f, name, data, dtype):
            if name == "x":
                return f.create_dataset("x", shape=data.shape, dtype=dtype, chunks=(64,), fillvalue=1234567)
            return None
        path = self.build(d / "fv.trace.h5", column)
        result = self.trace(path)
        self.assertEqual(result.returncode, 0, result.stderr)
        self.assertEqual(self.x_column(result.stdout), [0.1234567] * self.n)

    def test_chunks_never_written_in_the_librarys_own_filters_read_as_h5py_reads_them(self):
        # The layout the library writes (chunks, shuffle, deflate) with only the first chunk of `x` written: the
        # others were never stored, and read as the fill value, by h5py and by the program alike.
        d = self.folder()

        def column(f, name, data, dtype):
            if name == "x":
                made = f.create_dataset("x", shape=data.shape, dtype=dtype, chunks=(100,), compression="gzip",
                                        shuffle=True, fillvalue=7654321)
                made[:100] = data[:100]
                return made
            return None
        path = self.build(d / "fc.trace.h5", column)
        result = self.trace(path)
        self.assertEqual(result.returncode, 0, result.stderr)
        expected = [float(f"{v / 1e7:.7f}") for v in self.data["x"][0][:100]] + [0.7654321] * (self.n - 100)
        self.assertEqual(self.x_column(result.stdout), expected)

    def test_chunks_never_written_and_never_filled_are_refused(self):
        # Fill time "never": the chunks of `x` after its first were never written and HDF5 leaves their values
        # undefined (a reader's buffer as it was: h5py's read_direct and [()] differ). In the library's own
        # filters and unfiltered, refused naming the column rather than read as some value.
        d = self.folder()
        for filtered in (True, False):
            def column(f, name, data, dtype):
                if name != "x":
                    return None
                dcpl = h5py.h5p.create(h5py.h5p.DATASET_CREATE)
                dcpl.set_chunk((100,))
                dcpl.set_fill_time(h5py.h5d.FILL_TIME_NEVER)
                if filtered:
                    dcpl.set_shuffle()
                    dcpl.set_deflate(6)
                made = h5py.Dataset(h5py.h5d.create(f.id, b"x", h5py.h5t.STD_I32LE,
                                                    h5py.h5s.create_simple((len(data),)), dcpl=dcpl))
                made[:100] = data[:100]
                return made
            path = self.build(d / f"nf{int(filtered)}.trace.h5", column)
            self.assert_refused(path, "'x'", "never written")

    def test_compact_and_contiguous_storage_read_as_the_programs_own(self):
        d = self.folder()

        def column(f, name, data, dtype):
            space = h5py.h5s.create_simple((len(data),))
            dcpl = h5py.h5p.create(h5py.h5p.DATASET_CREATE)
            dcpl.set_layout(h5py.h5d.COMPACT if name in ("x", "t", "state") else h5py.h5d.CONTIGUOUS)
            made = h5py.Dataset(h5py.h5d.create(f.id, name.encode(), h5py.h5t.py_create(dtype, logical=True),
                                                space, dcpl=dcpl))
            made[...] = data
            return made
        self.assert_same(self.build(d / "cc.trace.h5", column))

    def test_a_resizable_column_grown_past_samples_is_refused(self):
        # Every column resizable (maxshape None), `x` grown by one sample of its fill value: the columns'
        # lengths differ, which the reader refuses.
        d = self.folder()

        def column(f, name, data, dtype):
            made = f.create_dataset(name, data=data, dtype=dtype, chunks=(128,), maxshape=(None,))
            if name == "x":
                made.resize((len(data) + 1,))
            return made
        self.assert_refused(self.build(d / "rs.trace.h5", column))

    # --- 4. column types HDF5 has ---------------------------------------------------------------------------

    def typed(self, which, make):
        def column(f, name, data, dtype):
            return make(f, data) if name == which else None
        return column

    def test_a_compound_column_is_refused_naming_it(self):
        d = self.folder()
        compound = np.dtype([("v", "<i4")])

        def make(f, data):
            values = np.zeros(len(data), dtype=compound)
            values["v"] = data
            return f.create_dataset("x", data=values)
        self.assert_refused(self.build(d / "cp.trace.h5", self.typed("x", make)), "'x'")

    def test_a_state_enum_of_other_numbers_is_refused_or_read_by_name(self):
        # The states' names on other numbers (WS 0 ... SS 3), the stored numbers changed to match, so that
        # h5py reads the same states: read by name (the same CSV) or refused naming `state`; never the numbers.
        d = self.folder()
        other = h5py.enum_dtype({"WS": 0, "CS": 1, "AS": 2, "SS": 3}, basetype="u1")

        def make(f, data):
            return f.create_dataset("state", data=(3 - data).astype("u1"), dtype=other)
        path = self.build(d / "en.trace.h5", self.typed("state", make))
        result = self.trace(path)
        if result.returncode == 0:
            self.assertEqual(result.stdout, self.csv)
        else:
            self.assert_one_error(result, 1, path.name, "state")

    def test_a_vlen_column_is_refused_naming_it(self):
        d = self.folder()

        def make(f, data):
            made = f.create_dataset("x", shape=data.shape, dtype=h5py.vlen_dtype(np.dtype("<i4")))
            for i, v in enumerate(data):
                made[i] = np.array([v], dtype="<i4")
            return made
        self.assert_refused(self.build(d / "vl.trace.h5", self.typed("x", make)), "'x'")

    def test_a_column_of_references_is_refused_naming_it(self):
        d = self.folder()

        def make(f, data):
            made = f.create_dataset("x", shape=data.shape, dtype=h5py.ref_dtype)
            made[...] = f.ref
            return made
        self.assert_refused(self.build(d / "rf.trace.h5", self.typed("x", make)), "'x'")

    def test_a_big_endian_column_reads_as_h5py_reads_it_or_is_refused_naming_it(self):
        # `x` as big-endian int32 (what h5py writes for numpy's '>i4'): the same values to h5py; read as them
        # or refused naming the column, never read byte-swapped.
        d = self.folder()

        def make(f, data):
            return f.create_dataset("x", data=data.astype(">i4"), dtype=">i4", chunks=(len(data),))
        path = self.build(d / "be.trace.h5", self.typed("x", make))
        result = self.trace(path)
        if result.returncode == 0:
            self.assertEqual(result.stdout, self.csv)
        else:
            self.assert_one_error(result, 1, path.name, "'x'")

    def test_an_empty_dataspace_column_is_refused_naming_it(self):
        # `x` with HDF5's null dataspace (no elements, not even zero of them: h5py.Empty).
        d = self.folder()
        empty = self.typed("x", lambda f, data: f.create_dataset("x", data=h5py.Empty("<i4")))
        self.assert_refused(self.build(d / "em.trace.h5", empty), "'x'")

    # --- 5. another tool's whole file -----------------------------------------------------------------------

    def test_a_user_block_of_1024_bytes_is_read_or_refused_in_one_line(self):
        d = self.folder()
        path = self.build(d / "u.trace.h5", userblock=1024)
        result = self.trace(path)
        if result.returncode == 0:
            self.assertEqual(result.stdout, self.csv)
        else:
            self.assert_one_error(result, 1, path.name)

    def test_trace_from_scratch_in_the_oldest_format_reads_as_the_programs_own(self):
        d = self.folder()
        self.assert_same(self.build(d / "old.trace.h5", libver="earliest"))

    def test_trace_from_scratch_in_the_newest_format_reads_as_the_programs_own(self):
        d = self.folder()
        path = self.build(d / "new.trace.h5", libver="latest")
        self.assert_same(path)
        score = run_ok(["score", path, "--character", "一", "--json", "-"], d).stdout
        own = run_ok(["score", self.own, "--character", "一", "--json", "-"], d).stdout
        mine, theirs = json.loads(score), json.loads(own)
        mine.pop("trace"), theirs.pop("trace")
        self.assertEqual(mine, theirs)


if __name__ == "__main__":
    unittest.main(verbosity=2)
