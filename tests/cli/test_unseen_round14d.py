#!/usr/bin/env python3
"""Round 14D: hostile cases written from the documentation alone (docs/cli.md "score" and "Pen traces: format
and limits", docs/metrics.md "Trace CSV", docs/python.md `score` and `CharacterLibrary`, docs/corpus.md,
docs/stroke-acceptance.md "Another hand's strokes", README.md and each command's `--help`) on data the engine
did not make: pen traces as a tablet, a web canvas or another lab's logger writes them, and character data from
other sets. Run by CTest as `cli_unseen_round14d_tests`.

Traces of 十 and 人 written by hand along the data's medians (a person's 200, 120 and 60 Hz, jittered), then
written the way other programs write them: times in milliseconds or microseconds since the Unix epoch, equal
stamps, one stamp a step back, pressure instead of a pen column, the pen as `true`/`false`, CR LF, a byte-order
mark, comment and trailing empty lines, tabs and semicolons (with decimal commas), header names in capitals or
with their units (`x_mm`), extra columns (tilt, azimuth, pressure), both `pen` and `z`, y growing downwards, a
multi-member gzip (as `cat a.gz b.gz` or a logger appending chunks writes), a pen never down, one sample; the
same through Python's `score` from numpy columns and pandas frames. Character data of other shapes: Make Me a
Hanzi's graphics.txt (as a folder and one of its lines as a character's file), hanzi-writer-data with keys of
another version and without `medians`, an ideograph outside the BMP (U+20000) through a folder, a store and
Python, a traditional and a simplified form, KanjiVG's 109 box and y not flipped, a median of one point
repeated, a name with a variation selector.

Each case asserts a documented result: the same numbers as the canonical trace (within the quantisation of its
times), or the documented exit status with one error line naming the file and line or column, character or
JSON pointer; never a silent wrong score. CALLIGRAPHY_CLI names the program, CALLIGRAPHY_SOURCE_DIR the source
tree (its hanzi-writer-data sample). CALLIGRAPHY_SANITIZED=1 takes five cases.
"""
import gzip
import json
import math
import os
import random
import shutil
import tempfile
import unittest
from pathlib import Path

from outsider import OneErrorLine, run, sanitized_subset

SOURCE = Path(os.environ.get("CALLIGRAPHY_SOURCE_DIR", Path(__file__).resolve().parents[2]))
SAMPLE = SOURCE / "data" / "hanzi-writer-data"
SHI, REN = "十", "人"
EXT_B = "\U00020000"  # 𠀀, CJK Unified Ideographs Extension B, outside the Basic Multilingual Plane

load_tests = sanitized_subset({"test_step_back_in_time_is_refused_naming_line_and_column",
                               "test_pressure_column_instead_of_pen_is_refused_naming_the_columns",
                               "test_multi_member_gzip_is_read_whole",
                               "test_median_of_one_point_repeated_is_refused_naming_file_and_pointer",
                               "test_extension_b_character_through_a_folder_and_a_store"})

try:
    import calligraphy
except ImportError:  # pragma: no cover - the Python cases are skipped, saying why
    calligraphy = None
try:
    import pandas
except ImportError:  # pragma: no cover
    pandas = None

# The standard layout (README.md: the 1024 box, y up, upper-left (0, 900); 60 mm per box, centred on the
# paper's origin): data units to metres.
BOX_M = 0.06


def to_metres(x, y):
    return (x - 512.0) * BOX_M / 1024.0, (y - 388.0) * BOX_M / 1024.0


def medians(char):
    return json.loads((SAMPLE / f"{char}.json").read_text(encoding="utf-8"))["medians"]


def polyline_points(median, step_units):
    """Points along a median every `step_units` data units (its vertices kept)."""
    out = [tuple(map(float, median[0]))]
    for (x0, y0), (x1, y1) in zip(median, median[1:]):
        n = max(1, math.ceil(math.hypot(x1 - x0, y1 - y0) / step_units))
        out += [(x0 + (x1 - x0) * k / n, y0 + (y1 - y0) * k / n) for k in range(1, n + 1)]
    return out


def hand_trace(char, rate_hz=200.0, jitter=0.0, t0=0.0, seed=1, speed_units_s=800.0):
    """Rows (t [s], x [m], y [m], pen) writing each stroke along its median at `speed_units_s`, sampled at
    `rate_hz` (each interval jittered by up to `jitter` of itself), with 0.2 s of pen-up movement between."""
    rng = random.Random(seed)
    rows, t = [], t0
    step = speed_units_s / rate_hz
    strokes = medians(char)
    for i, median in enumerate(strokes):
        for x, y in polyline_points(median, step):
            rows.append((t, *to_metres(x, y), 1))
            t += (1.0 + rng.uniform(-jitter, jitter)) / rate_hz
        if i + 1 < len(strokes):
            (ax, ay), (bx, by) = strokes[i][-1], strokes[i + 1][0]
            for k in range(1, 40):
                rows.append((t, *to_metres(ax + (bx - ax) * k / 40, ay + (by - ay) * k / 40), 0))
                t += 0.2 / 40
    return rows


def csv_text(rows, header=("t", "x", "y", "pen"), sep=",", newline="\n", time_scale=1.0, decimal=".",
             pen=lambda p: str(p), extra=None):
    lines = [sep.join(header + tuple(extra or ()))]
    for t, x, y, p in rows:
        fields = [repr(t * time_scale), repr(x), repr(y), pen(p)] + ["0.5" for _ in (extra or ())]
        if decimal != ".":
            fields = [f.replace(".", decimal) for f in fields]
        lines.append(sep.join(fields))
    return newline.join(lines) + newline


CANONICAL = {}


def spatial(score):
    """What does not depend on the clock: verdicts, assignments and distances (metres), per stroke too."""
    pc = score["per_character"][0]
    keys = ("strokes_accepted", "strokes_written", "backwards_strokes", "order_errors", "mean_deviation_m",
            "max_deviation_m", "frechet_m", "dtw_m", "path_length_m")
    out = {k: pc[k] for k in keys}
    out["per_stroke"] = [(s["written"], s["mean_deviation_m"], s["max_deviation_m"], s["frechet_m"])
                         for s in pc["per_stroke"]]
    out["verdicts"] = [(s["begin"], s["end"], s["verdict"] and s["verdict"]["refusal"]) for s in pc["segments"]]
    return out


class Round14D(OneErrorLine, unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.dir = Path(tempfile.mkdtemp(prefix="calligraphy-r14d-"))
        for char in (SHI, REN):
            rows = hand_trace(char)
            path = cls.dir / f"canonical-{char}.csv"
            path.write_text(csv_text(rows), encoding="utf-8")
            CANONICAL[char] = (rows, cls.score_file(path, char))

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.dir, ignore_errors=True)

    @classmethod
    def score_file(cls, path, char, *options):
        result = run(["score", path, "--character", char, "--json", "-", *options], cls.dir)
        if result.returncode != 0:
            raise AssertionError(f"score {path} exited {result.returncode}: {result.stderr.decode()}")
        return json.loads(result.stdout)

    def write(self, name, text, encoding="utf-8"):
        path = self.dir / name
        (path.write_bytes(text) if isinstance(text, bytes) else path.write_text(text, encoding=encoding,
                                                                                newline=""))
        return path

    def assertSameSpatial(self, score, char, places=12):
        got, want = spatial(score), spatial(CANONICAL[char][1])
        for key in want:
            if isinstance(want[key], float):
                self.assertAlmostEqual(got[key], want[key], places=places, msg=key)
            elif key == "per_stroke":
                for g, w in zip(got[key], want[key]):
                    self.assertEqual(g[0], w[0])
                    for a, b in zip(g[1:], w[1:]):
                        self.assertAlmostEqual(a, b, places=places, msg=key)
            else:
                self.assertEqual(got[key], want[key], key)

    # -- the canonical trace itself: what the other cases are held to -------------------------------------

    def test_canonical_hand_traces_are_written_in_order(self):
        for char in (SHI, REN):
            score = CANONICAL[char][1]
            self.assertEqual(score["strokes_accepted"], score["strokes_total"], char)
            self.assertTrue(score["completed_in_order"], char)
            # written on the data's median: within a millimetre of the fitted elements the deviation is measured from
            self.assertLess(score["max_deviation_m"], 1e-3, char)

    # -- clocks of other programs ------------------------------------------------------------------------

    def test_milliseconds_since_the_epoch_read_as_seconds_scale_the_times_only(self):
        # A web canvas's `performance.timeOrigin + now()` in ms: read as seconds (docs: `t` [s]), so every
        # time is 1000 times longer and nothing spatial changes.
        rows = [(1.7e9 + t, x, y, p) for t, x, y, p in CANONICAL[SHI][0]]
        path = self.write("epoch-ms.csv", csv_text(rows, time_scale=1000.0))
        score = self.score_file(path, SHI)
        self.assertSameSpatial(score, SHI, places=9)
        want = CANONICAL[SHI][1]
        self.assertAlmostEqual(score["total_time_s"], 1000 * want["total_time_s"], delta=1e-3)
        self.assertAlmostEqual(score["pen_down_time_s"], 1000 * want["pen_down_time_s"], delta=1e-3)

    def test_microseconds_since_the_epoch_are_read_without_losing_the_order(self):
        # A lab logger's 1.7e15 us: finite, increasing, read as seconds; doubles hold whole microseconds there.
        rows = [(round((1.7e9 + t) * 1e6), x, y, p) for t, x, y, p in CANONICAL[SHI][0]]
        path = self.write("epoch-us.csv", csv_text(rows))
        score = self.score_file(path, SHI)
        self.assertSameSpatial(score, SHI, places=9)
        self.assertAlmostEqual(score["pen_down_time_s"], 1e6 * CANONICAL[SHI][1]["pen_down_time_s"],
                               delta=0.5 * len(rows))

    def test_epoch_seconds_shift_changes_no_number_but_rounding(self):
        rows = [(1.7e9 + t, x, y, p) for t, x, y, p in CANONICAL[REN][0]]
        score = self.score_file(self.write("epoch-s.csv", csv_text(rows)), REN)
        self.assertSameSpatial(score, REN)
        self.assertAlmostEqual(score["total_time_s"], CANONICAL[REN][1]["total_time_s"], delta=1e-6)

    def test_equal_stamps_repeated_samples_are_taken(self):
        # A 120 Hz tablet polled at 200 Hz repeats samples with their stamps: times that do not decrease.
        rows = []
        for row in CANONICAL[SHI][0]:
            rows += [row, row] if len(rows) % 3 == 0 else [row]
        score = self.score_file(self.write("repeated.csv", csv_text(rows)), SHI)
        want = CANONICAL[SHI][1]
        for key in ("strokes_accepted", "max_deviation_m", "frechet_m", "pen_down_time_s", "total_time_s"):
            self.assertAlmostEqual(score[key], want[key], places=12, msg=key)
        self.assertAlmostEqual(score["per_character"][0]["path_length_m"],
                               want["per_character"][0]["path_length_m"], places=12)

    def test_equal_stamps_at_two_places_give_finite_numbers(self):
        # A logger with a millisecond clock and two samples within one millisecond: the same stamp at two
        # places. The times do not decrease, so it is read; no number may become infinite or NaN.
        rows = [(math.floor(t * 100) / 100, x, y, p) for t, x, y, p in CANONICAL[SHI][0]]
        result = run(["score", self.write("ms-clock.csv", csv_text(rows)), "--character", SHI, "--json", "-"],
                     self.dir)
        self.assertEqual(result.returncode, 0, result.stderr)

        def refuse(token):
            raise AssertionError(f"non-finite {token} in the score")
        score = json.loads(result.stdout, parse_constant=refuse)
        self.assertEqual(score["strokes_accepted"], 2)
        self.assertAlmostEqual(score["max_deviation_m"], CANONICAL[SHI][1]["max_deviation_m"], places=12)

    def test_step_back_in_time_is_refused_naming_line_and_column(self):
        rows = list(CANONICAL[SHI][0])
        t, x, y, p = rows[50]
        rows[50] = (rows[49][0] - 0.004, x, y, p)  # one stamp 4 ms before the one above it
        path = self.write("step-back.csv", csv_text(rows))
        line = self.assert_one_error(run(["score", path, "--character", SHI], self.dir), 1,
                                     f"step-back.csv:{50 + 2}")
        self.assertIn("t", line)

    def test_jittered_60_hz_canvas_writes_each_stroke(self):
        rows = hand_trace(REN, rate_hz=60.0, jitter=0.4, seed=7)
        score = self.score_file(self.write("canvas-60.csv", csv_text(rows)), REN)
        self.assertEqual(score["strokes_accepted"], 2)
        self.assertTrue(score["completed_in_order"])
        self.assertLess(score["max_deviation_m"], 1e-3)
        self.assertEqual(score["samples"], len(rows))

    def test_jittered_120_hz_from_an_epoch_equals_its_zero_based_copy(self):
        rows = hand_trace(REN, rate_hz=120.0, jitter=0.3, seed=3)
        a = self.score_file(self.write("t120.csv", csv_text(rows)), REN)
        b = self.score_file(self.write("t120-epoch.csv",
                                       csv_text([(t + 1.7e9, x, y, p) for t, x, y, p in rows])), REN)
        self.assertEqual(spatial(a), spatial(b))
        self.assertAlmostEqual(a["pen_down_time_s"], b["pen_down_time_s"], delta=1e-6)

    # -- columns of other programs --------------------------------------------------------------------

    def test_pressure_column_instead_of_pen_is_refused_naming_the_columns(self):
        text = csv_text(CANONICAL[SHI][0], header=("t", "x", "y", "pressure"),
                        pen=lambda p: "0.42" if p else "0")
        path = self.write("pressure.csv", text)
        line = self.assert_one_error(run(["score", path, "--character", SHI], self.dir), 1, "pressure.csv")
        self.assertIn("pen", line)
        self.assertIn("z", line)

    def test_extra_tablet_columns_are_ignored(self):
        text = csv_text(CANONICAL[SHI][0], extra=("pressure", "tilt_x", "tilt_y", "azimuth"))
        self.assertSameSpatial(self.score_file(self.write("tablet.csv", text), SHI), SHI)

    def test_pen_as_true_false_text_is_refused_naming_the_column(self):
        text = csv_text(CANONICAL[SHI][0], pen=lambda p: "true" if p else "false")
        line = self.assert_one_error(run(["score", self.write("bool.csv", text), "--character", SHI],
                                         self.dir), 1, "bool.csv:2", "pen")
        self.assertIn("true", line)

    def test_header_with_units_in_its_names_is_refused_not_guessed(self):
        # x_mm is no name of the trace column table (x, x_m): a trace in millimetres must not be read as metres.
        rows = [(t, x * 1000, y * 1000, p) for t, x, y, p in CANONICAL[SHI][0]]
        text = csv_text(rows, header=("t_s", "x_mm", "y_mm", "pen"))
        line = self.assert_one_error(run(["score", self.write("mm.csv", text), "--character", SHI], self.dir),
                                     1, "mm.csv")
        self.assertIn("x", line)

    def test_header_in_capitals_names_no_column(self):
        text = csv_text(CANONICAL[SHI][0], header=("T", "X", "Y", "PEN"))
        self.assert_one_error(run(["score", self.write("caps.csv", text), "--character", SHI], self.dir), 1,
                              "caps.csv:1", "'t'")

    def test_semicolons_and_decimal_commas_are_refused_naming_the_file(self):
        # A European spreadsheet's "CSV": `t;x;y;pen` with `0,005`.
        text = csv_text(CANONICAL[SHI][0], sep=";", decimal=",")
        self.assert_one_error(run(["score", self.write("semicolon.csv", text), "--character", SHI], self.dir),
                              1, "semicolon.csv")

    def test_tab_separated_values_are_refused_for_the_column_they_lack(self):
        path = self.write("tabs.tsv", csv_text(CANONICAL[SHI][0], sep="\t"))
        self.assert_one_error(run(["score", path, "--character", SHI], self.dir), 1, "tabs.tsv:1", "'t'")

    def test_excel_unicode_text_is_refused_saying_utf16(self):
        # Excel's "Unicode Text (*.txt)": UTF-16 with its byte-order mark, tab-separated.
        path = self.write("unicode.txt", csv_text(CANONICAL[SHI][0], sep="\t").encode("utf-16"))
        self.assert_one_error(run(["score", path, "--character", SHI], self.dir), 1, "unicode.txt:1", "UTF-16")

    def test_lines_ending_in_cr_alone_are_refused_saying_so(self):
        # Classic Mac OS's "CSV (Macintosh)": every line ends in CR alone, so the file is one line of text.
        path = self.write("mac.csv", csv_text(CANONICAL[SHI][0], newline="\r"))
        self.assert_one_error(run(["score", path, "--character", SHI], self.dir), 1, "mac.csv:1", "CR alone")

    def test_iso_8601_time_stamps_are_refused_naming_line_and_column(self):
        # A logger writing dates, not seconds: refused at its first row, never read as a number of something.
        lines = ["t,x,y,pen"] + [f"2026-11-27T20:00:{i / 200:06.3f}Z,{x!r},{y!r},{p}"
                                 for i, (_, x, y, p) in enumerate(CANONICAL[SHI][0][:5])]
        path = self.write("iso.csv", "\n".join(lines) + "\n")
        line = self.assert_one_error(run(["score", path, "--character", SHI], self.dir), 1, "iso.csv:2",
                                     "column 1 (t)")
        self.assertIn("2026-11-27T20:00:00.000Z", line)

    def test_a_space_after_each_comma_changes_nothing(self):
        # `t, x, y, pen` and `0.005, -0.02, ...`, as many loggers and hand-written files space their fields.
        self.assertSameSpatial(self.score_file(self.write("spaced.csv", csv_text(CANONICAL[SHI][0], sep=", ")),
                                               SHI), SHI)

    def test_spreadsheet_encodings_together_change_nothing(self):
        # Excel's "CSV UTF-8": a byte-order mark, CR LF, columns reordered, a comment, blank and trailing lines.
        rows = CANONICAL[REN][0]
        lines = ["# exported by a tablet logger, 200 Hz", "pen,y,x,t"]
        lines += [f"{p},{y!r},{x!r},{t!r}" for t, x, y, p in rows]
        text = "\ufeff" + "\r\n".join(lines) + "\r\n\r\n\r\n"
        score = self.score_file(self.write("excel.csv", text), REN)
        self.assertSameSpatial(score, REN)
        self.assertEqual(score["samples"], len(rows))

    def test_pen_and_z_together_are_refused(self):
        # Both a `pen` column and a `z` column, disagreeing: the pen says down throughout the second stroke, z
        # says it is 1 cm above the paper. Neither is guessed: the header is refused.
        rows = CANONICAL[SHI][0]
        first_down = [i for i, r in enumerate(rows) if r[3] == 1]
        gap = [i for i, r in enumerate(rows) if r[3] == 0]
        second = [i for i in first_down if i > gap[-1]]
        lines = ["t,x,y,z,pen"]
        for i, (t, x, y, p) in enumerate(rows):
            z = 0.01 if i in second or p == 0 else 0.0
            lines.append(f"{t!r},{x!r},{y!r},{z},{p}")
        path = self.write("pen-and-z.csv", "\n".join(lines) + "\n")
        self.assert_one_error(run(["score", path, "--character", SHI, "--json", "-"], self.dir), 1,
                              "pen-and-z.csv:1", "'pen'", "'z'")

    def test_y_growing_downwards_is_scored_as_written(self):
        # Screen coordinates (y down) given as data units: there is no flag; the trace is the character turned
        # upside down, which 人 is not, so the score must show it rather than pass it.
        rows = [(t, *(((x * 1024 / BOX_M) + 512), 900 - ((y * 1024 / BOX_M) + 388) - 124), p)
                for t, x, y, p in CANONICAL[REN][0]]
        path = self.write("y-down.csv", csv_text(rows))
        score = self.score_file(path, REN, "--units", "data")
        self.assertLess(score["strokes_accepted"], 2)
        upright = self.score_file(self.write("y-up.csv", csv_text(
            [(t, (x * 1024 / BOX_M) + 512, (y * 1024 / BOX_M) + 388, p) for t, x, y, p in CANONICAL[REN][0]])),
            REN, "--units", "data")
        self.assertSameSpatial(upright, REN, places=9)

    def test_multi_member_gzip_is_read_whole(self):
        # gzip files may hold several members (RFC 1952 2.2; `cat a.gz b.gz`, a logger that appends a chunk
        # at a time): gunzip reads them all, and so must `score`, or the second stroke is silently lost.
        text = csv_text(CANONICAL[SHI][0]).encode()
        cut = text.index(b"\n", len(text) // 2) + 1
        path = self.write("chunks.csv.gz", gzip.compress(text[:cut]) + gzip.compress(text[cut:]))
        result = run(["score", path, "--character", SHI, "--json", "-"], self.dir)
        self.assertEqual(result.returncode, 0, result.stderr)
        score = json.loads(result.stdout)
        self.assertEqual(score["samples"], len(CANONICAL[SHI][0]))
        self.assertSameSpatial(score, SHI)

    def test_bytes_after_the_gzip_data_are_refused_naming_where(self):
        # After the last member, bytes that start no other: a logger's zero padding, plain rows appended with
        # `>>`, a second chunk whose first byte was damaged. gunzip says "trailing garbage ignored"; a score
        # that left them out would be a silent score of part of the trace, so each is refused (exit 1, nothing
        # written), naming the file and the byte where they start.
        text = csv_text(CANONICAL[SHI][0]).encode()
        cut = text.index(b"\n", len(text) // 2) + 1
        first, second = gzip.compress(text[:cut]), bytearray(gzip.compress(text[cut:]))
        second[0] ^= 0x01
        whole = gzip.compress(text)
        for name, data, at in (("padded.csv.gz", whole + b"\0" * 512, len(whole)),
                               ("appended.csv.gz", whole + text[cut:], len(whole)),
                               ("damaged.csv.gz", first + bytes(second), len(first))):
            with self.subTest(name=name):
                path = self.write(name, data)
                out = self.dir / "out.json"
                self.assert_one_error(run(["score", path, "--character", SHI, "--json", out], self.dir), 1,
                                      name, f"at byte {at}")
                self.assertFalse(out.exists())
        if calligraphy is not None:
            with self.assertRaises(calligraphy.DataError) as caught:
                calligraphy.score(str(self.dir / "damaged.csv.gz"), SHI)
            self.assertIn(f"at byte {len(first)}", str(caught.exception))

    def test_numpy_savetxt_trace_scores_as_its_canonical_text(self):
        # numpy.savetxt writes every column as `%.18e`: the pen as 1.000000000000000000e+00, the number 1.
        import numpy
        path = self.dir / "savetxt.csv"
        numpy.savetxt(path, numpy.array(CANONICAL[SHI][0], dtype=float), delimiter=",", header="t,x,y,pen",
                      comments="")
        self.assertSameSpatial(self.score_file(path, SHI), SHI)

    def test_pandas_to_csv_of_a_float_pen_with_its_index_scores_alike(self):
        # A frame whose pen column became float (1.0, 0.0), written with its unnamed index column first.
        if pandas is None:
            self.skipTest("pandas is not installed")
        frame = pandas.DataFrame(CANONICAL[REN][0], columns=["t", "x", "y", "pen"]).astype(float)
        path = self.dir / "frame.csv"
        frame.to_csv(path)
        self.assertSameSpatial(self.score_file(path, REN), REN)
        if calligraphy is not None:  # the frame as columns and as its CSV: one score
            self.assertEqual(spatial(calligraphy.score(frame, REN)), spatial(calligraphy.score(str(path), REN)))

    def test_pen_spelt_otherwise_than_zero_or_one_is_still_refused(self):
        for value in ("0.5", "1.0000001", "2e0", "nan", "0x1", "1.", "+1"):
            with self.subTest(value=value):
                text = csv_text(CANONICAL[SHI][0][:3], pen=lambda p, v=value: v)
                path = self.write("odd-pen.csv", text)
                if value in ("1.", "+1"):  # a number 1 however spelt: read as 1, or refused as any other
                    result = run(["score", path, "--character", SHI], self.dir)
                    if result.returncode == 0:
                        continue
                    self.assert_one_error(result, 1, "odd-pen.csv:2", "pen")
                else:
                    self.assert_one_error(run(["score", path, "--character", SHI], self.dir), 1,
                                          "odd-pen.csv:2", "pen")

    def test_height_below_the_paper_and_unit_named_columns_are_pen_down(self):
        # A haptic logger's z: the pen pressed 2 mm into the paper (negative), lifted 1 cm; columns named as
        # Python's frames name them (t_s, x_m, y_m, z_m).
        lines = ["t_s,x_m,y_m,z_m"]
        lines += [f"{t!r},{x!r},{y!r},{-0.002 if p else 0.01}" for t, x, y, p in CANONICAL[SHI][0]]
        score = self.score_file(self.write("pressed.csv", "\n".join(lines) + "\n"), SHI)
        self.assertSameSpatial(score, SHI)

    def test_cut_second_gzip_member_is_refused_naming_the_file(self):
        # A logger killed while appending its second chunk: the file ends inside a member.
        text = csv_text(CANONICAL[SHI][0]).encode()
        cut = text.index(b"\n", len(text) // 2) + 1
        second = gzip.compress(text[cut:])
        path = self.write("killed.csv.gz", gzip.compress(text[:cut]) + second[:len(second) // 2])
        self.assert_one_error(run(["score", path, "--character", SHI, "--json", self.dir / "k.json"],
                                  self.dir), 1, "killed.csv.gz")
        self.assertFalse((self.dir / "k.json").exists())

    def test_pen_never_down_scores_nothing_written(self):
        rows = [(t, x, y, 0) for t, x, y, _ in CANONICAL[SHI][0]]
        score = self.score_file(self.write("hover.csv", csv_text(rows)), SHI)
        pc = score["per_character"][0]
        self.assertEqual((score["strokes_accepted"], score["strokes_written"]), (0, 0))
        self.assertEqual(pc["missing_strokes"], [0, 1])
        self.assertEqual(pc["segments"], [])
        self.assertIsNone(score["mean_deviation_m"])
        self.assertTrue(all(not s["written"] and s["mean_deviation_m"] is None for s in pc["per_stroke"]))

    def test_one_sample_is_an_ignored_segment(self):
        t, x, y, _ = CANONICAL[SHI][0][0]
        score = self.score_file(self.write("one.csv", csv_text([(t, x, y, 1)])), SHI)
        pc = score["per_character"][0]
        self.assertEqual(score["samples"], 1)
        self.assertEqual(pc["ignored_segments"], 1)
        self.assertEqual(pc["pen_lifts"], 0)
        self.assertEqual(score["strokes_accepted"], 0)


@unittest.skipIf(calligraphy is None, "the Python module is not on PYTHONPATH")
class PythonTraces(unittest.TestCase):
    """Python's `score` given columns from other sources: numpy arrays and pandas frames."""

    @classmethod
    def setUpClass(cls):
        import numpy
        cls.np = numpy
        rows = hand_trace(SHI)
        cls.rows = rows
        cls.columns = {k: numpy.array([r[i] for r in rows], dtype=float) for i, k in enumerate("txyp")}
        cls.want = spatial(calligraphy.score(
            {"t": cls.columns["t"], "x": cls.columns["x"], "y": cls.columns["y"], "pen": cls.columns["p"]}, SHI))

    def test_canonical_columns_score_as_the_cli(self):
        self.assertEqual(self.want["strokes_accepted"], 2)

    def test_pressure_key_instead_of_pen_is_refused_naming_it(self):
        c = self.columns
        with self.assertRaises(calligraphy.InvalidArgument) as caught:
            calligraphy.score({"t": c["t"], "x": c["x"], "y": c["y"], "pressure": c["p"] * 0.4}, SHI)
        self.assertIn("pen", str(caught.exception))

    def test_epoch_microseconds_from_a_frame_keep_the_spatial_numbers(self):
        if pandas is None:
            self.skipTest("pandas is not installed")
        c = self.columns
        frame = pandas.DataFrame({"t": (c["t"] + 1.7e9) * 1e6, "x": c["x"], "y": c["y"], "pen": c["p"],
                                  "tilt": 0.5, "azimuth": 1.0})
        got = spatial(calligraphy.score(frame, SHI))
        self.assertEqual(got["verdicts"], self.want["verdicts"])
        self.assertAlmostEqual(got["max_deviation_m"], self.want["max_deviation_m"], places=9)

    def test_a_step_back_in_time_is_refused_from_columns_as_from_a_file(self):
        c = {k: v.copy() for k, v in self.columns.items()}
        c["t"][50] = c["t"][49] - 0.004
        with self.assertRaises((calligraphy.InvalidArgument, calligraphy.DataError)) as caught:
            calligraphy.score({"t": c["t"], "x": c["x"], "y": c["y"], "pen": c["p"]}, SHI)
        self.assertIn("t", str(caught.exception))
        self.assertIn("50", str(caught.exception))

    def test_pen_and_z_columns_together_are_refused_as_the_csv_header_is(self):
        # A logger's frame with both a pen flag and a height that disagree (z 1 cm up where pen says down):
        # `calligraphy score` refuses such a CSV's header; the same columns must not be scored by either.
        c = self.columns
        z = self.np.full(len(c["t"]), 0.01)
        for key in ("z", "z_m"):
            with self.subTest(key=key):
                with self.assertRaises(calligraphy.InvalidArgument) as caught:
                    calligraphy.score({"t": c["t"], "x": c["x"], "y": c["y"], "pen": c["p"], key: z}, SHI)
                self.assertIn("pen", str(caught.exception))
                self.assertIn(key, str(caught.exception))

    def test_unit_suffixed_millimetre_columns_are_refused_not_read_as_metres(self):
        c = self.columns
        with self.assertRaises(calligraphy.InvalidArgument) as caught:
            calligraphy.score({"t_s": c["t"], "x_mm": c["x"] * 1e3, "y_mm": c["y"] * 1e3, "pen": c["p"]}, SHI)
        self.assertIn("x", str(caught.exception))

    def test_a_semicolon_file_is_refused_naming_it(self):
        with tempfile.TemporaryDirectory() as folder:
            path = Path(folder) / "semi.csv"
            path.write_text(csv_text(self.rows, sep=";"), encoding="utf-8")
            with self.assertRaises(calligraphy.Error) as caught:
                calligraphy.score(str(path), SHI)
            self.assertIn("semi.csv", str(caught.exception))


def hanzi_writer_document(char):
    return json.loads((SAMPLE / f"{char}.json").read_text(encoding="utf-8"))


def write_json(path, document):
    Path(path).write_text(json.dumps(document, ensure_ascii=False), encoding="utf-8")


class CharacterData(OneErrorLine, unittest.TestCase):
    """Character data from other sets where the docs take a hanzi-writer-data folder or a store."""

    def setUp(self):
        self.dir = Path(tempfile.mkdtemp(prefix="calligraphy-r14d-chars-"))

    def tearDown(self):
        shutil.rmtree(self.dir, ignore_errors=True)

    def folder(self, name, files):
        folder = self.dir / name
        folder.mkdir()
        for file_name, document in files.items():
            if isinstance(document, (bytes, str)):
                (folder / file_name).write_bytes(document if isinstance(document, bytes) else document.encode())
            else:
                write_json(folder / file_name, document)
        return folder

    def model_json(self, char, *source):
        result = run(["model", char, "--json", *source], self.dir)
        self.assertEqual(result.returncode, 0, result.stderr)
        return json.loads(result.stdout)

    def strip_source(self, model):
        """A model's geometry: its own name and source file left out."""
        if isinstance(model, dict):
            return {k: self.strip_source(v) for k, v in model.items() if k not in ("character", "source",
                                                                                   "codepoint", "code_point")}
        if isinstance(model, list):
            return [self.strip_source(v) for v in model]
        return model

    def test_make_me_a_hanzi_graphics_txt_folder_has_no_character_files(self):
        # Make Me a Hanzi ships one graphics.txt of JSON lines; a folder of it holds no `<character>.json`.
        lines = []
        for char in (SHI, REN):
            document = hanzi_writer_document(char)
            lines.append(json.dumps({"character": char, "strokes": document["strokes"],
                                     "medians": document["medians"]}, ensure_ascii=False))
        folder = self.folder("mmah", {"graphics.txt": "\n".join(lines) + "\n"})
        self.assert_one_error(run(["model", SHI, "--data", folder], self.dir), 2, SHI)
        out = self.dir / "mmah.clg"
        self.assert_one_error(run(["corpus", "build", "--data", folder, "--out", out, "--threads", "1"],
                                  self.dir), 1, "mmah")
        self.assertFalse(out.exists())

    def test_graphics_txt_given_as_the_data_folder_is_refused_naming_it(self):
        # Make Me a Hanzi's one file given where a folder is taken: `model`, `corpus build` and Python alike.
        document = hanzi_writer_document(SHI)
        graphics = self.dir / "graphics.txt"
        graphics.write_text(json.dumps({"character": SHI, **document}, ensure_ascii=False) + "\n", encoding="utf-8")
        self.assert_one_error(run(["model", SHI, "--data", graphics], self.dir), 1, "graphics.txt", "folder")
        out = self.dir / "g.clg"
        self.assert_one_error(run(["corpus", "build", "--data", graphics, "--out", out], self.dir), 1,
                              "graphics.txt", "folder")
        self.assertFalse(out.exists())
        if calligraphy is not None:
            with self.assertRaises(calligraphy.DataError) as caught:
                calligraphy.CharacterLibrary.from_hanzi_writer(graphics)
            self.assertIn("graphics.txt", str(caught.exception))

    def test_graphics_txt_named_as_a_character_is_refused_naming_the_file(self):
        lines = [json.dumps({"character": c, "strokes": hanzi_writer_document(c)["strokes"],
                             "medians": hanzi_writer_document(c)["medians"]}, ensure_ascii=False)
                 for c in (SHI, REN)]
        folder = self.folder("lines", {f"{SHI}.json": "\n".join(lines) + "\n"})
        self.assert_one_error(run(["model", SHI, "--data", folder], self.dir), 1, f"{SHI}.json")

    def test_one_make_me_a_hanzi_line_as_a_character_file_is_its_file_names_character(self):
        # One line of graphics.txt saved as 十.json carries a "character" key of its own, here another
        # character's: the file's name says which character it is, the geometry is the file's.
        document = hanzi_writer_document(SHI)
        line = {"character": REN, "strokes": document["strokes"], "medians": document["medians"]}
        folder = self.folder("one-line", {f"{SHI}.json": line})
        got = self.model_json(SHI, "--data", folder)
        self.assertEqual(got["character"], SHI)
        reference = self.model_json(SHI, "--data", self.folder("plain", {f"{SHI}.json": document}))
        self.assertEqual(self.strip_source(got), self.strip_source(reference))
        self.assert_one_error(run(["model", REN, "--data", folder], self.dir), 2, REN)

    def test_keys_of_another_version_are_ignored(self):
        document = hanzi_writer_document(REN)
        other = dict(document, radStrokes=[0], version="3.0.0", source="another set")
        a = self.model_json(REN, "--data", self.folder("v2", {f"{REN}.json": document}))
        b = self.model_json(REN, "--data", self.folder("v3", {f"{REN}.json": other}))
        self.assertEqual(self.strip_source(b), self.strip_source(a))

    def test_missing_medians_is_refused_naming_file_and_pointer(self):
        document = hanzi_writer_document(REN)
        del document["medians"]
        folder = self.folder("no-medians", {f"{REN}.json": document})
        self.assert_one_error(run(["model", REN, "--data", folder], self.dir), 1, f"{REN}.json", "/medians")

    def test_median_of_one_point_repeated_is_refused_naming_file_and_pointer(self):
        document = hanzi_writer_document(SHI)
        document["medians"][1] = [[500, 500]] * 4  # four samples of one point: one distinct point
        folder = self.folder("dot", {f"{SHI}.json": document})
        self.assert_one_error(run(["model", SHI, "--data", folder], self.dir), 1, f"{SHI}.json",
                              "/medians/1")

    def test_extension_b_character_through_a_folder_and_a_store(self):
        # 𠀀 (U+20000), four bytes of UTF-8, given 十's strokes: the same model from the folder, from a store
        # built of it, and the same score of a 十 trace.
        document = hanzi_writer_document(SHI)
        folder = self.folder("extb", {f"{EXT_B}.json": document, f"{SHI}.json": document})
        a = self.model_json(EXT_B, "--data", folder)
        b = self.model_json(SHI, "--data", folder)
        self.assertEqual(self.strip_source(a), self.strip_source(b))
        store = self.dir / "extb.clg"
        built = run(["corpus", "build", "--data", folder, "--out", store, "--threads", "1"], self.dir)
        self.assertEqual(built.returncode, 0, built.stderr)
        c = self.model_json(EXT_B, "--store", store)
        d = self.model_json(SHI, "--store", store)
        self.assertEqual(self.strip_source(c), self.strip_source(d))
        listed = run(["characters", "--store", store], self.dir)
        self.assertEqual(listed.returncode, 0, listed.stderr)
        self.assertIn(EXT_B, listed.stdout.decode())
        trace = self.dir / "shi.csv"
        trace.write_text(csv_text(hand_trace(SHI)), encoding="utf-8")
        scores = []
        for char in (EXT_B, SHI):
            result = run(["score", trace, "--character", char, "--store", store, "--json", "-"], self.dir)
            self.assertEqual(result.returncode, 0, result.stderr)
            scores.append(spatial(json.loads(result.stdout)))
        self.assertEqual(scores[0], scores[1])
        self.assertEqual(scores[0]["strokes_accepted"], 2)

    def test_traditional_and_simplified_forms_are_two_characters(self):
        # 為 and 为, one character in two forms: each file is its own character, never the other's.
        folder = self.folder("forms", {"為.json": hanzi_writer_document(SHI),
                                       "为.json": hanzi_writer_document(REN)})
        trad = self.model_json("為", "--data", folder)
        simp = self.model_json("为", "--data", folder)
        self.assertEqual(self.strip_source(trad), self.strip_source(self.model_json(SHI, "--data", SAMPLE)))
        self.assertEqual(self.strip_source(simp), self.strip_source(self.model_json(REN, "--data", SAMPLE)))

    def test_name_with_a_variation_selector_is_no_characters_file(self):
        # `十︀.json` (十 U+FE00): two code points, so no character's file, passed over.
        folder = self.folder("vs", {f"{SHI}\ufe00.json": hanzi_writer_document(SHI)})
        self.assert_one_error(run(["model", SHI, "--data", folder], self.dir), 2, SHI)

    def test_kanjivg_box_and_unflipped_y_are_taken_as_data_units(self):
        # KanjiVG's 109 box, y down: read as 1024-box data units, y up, as given. The model is a small
        # character in the box's lower-left corner turned upside down, and a trace of the real 十 finds none
        # of its strokes.
        document = hanzi_writer_document(SHI)
        document["medians"] = [[[x * 109 / 1024, (900 - y) * 109 / 1024] for x, y in m]
                               for m in document["medians"]]
        del document["strokes"]
        folder = self.folder("kanjivg", {f"{SHI}.json": document})
        model = self.model_json(SHI, "--data", folder)
        points = [p for stroke in model["strokes"] for e in stroke["elements"] for p in e["control_points"]]
        self.assertTrue(points)
        for x, y in points:  # within the 109 box as given (the fit within its tolerance), y not flipped back
            self.assertTrue(-11 <= x <= 120 and -11 <= y <= 120, (x, y))
        horizontal = model["strokes"][0]["elements"]
        self.assertGreater(horizontal[0]["control_points"][0][1], 40)  # 十's bar: 900 - 442 units, scaled
        trace = self.dir / "shi.csv"
        trace.write_text(csv_text(hand_trace(SHI)), encoding="utf-8")
        result = run(["score", trace, "--character", SHI, "--data", folder, "--json", "-"], self.dir)
        self.assertEqual(result.returncode, 0, result.stderr)
        self.assertEqual(json.loads(result.stdout)["strokes_accepted"], 0)

    def test_character_file_with_a_byte_order_mark_or_in_utf16(self):
        # Saved by a Windows editor: UTF-8 with a byte-order mark (skipped, docs/corpus.md) and UTF-16 (refused
        # naming the file).
        text = json.dumps(hanzi_writer_document(REN), ensure_ascii=False)
        reference = self.model_json(REN, "--data", SAMPLE)
        folder = self.folder("bom", {f"{REN}.json": "\ufeff" + text})
        self.assertEqual(self.strip_source(self.model_json(REN, "--data", folder)), self.strip_source(reference))
        folder = self.folder("utf16", {f"{REN}.json": text.encode("utf-16")})
        self.assert_one_error(run(["model", REN, "--data", folder], self.dir), 1, f"{REN}.json")

    def test_trial_of_an_extension_b_character_keeps_it_in_its_record(self):
        folder = self.folder("extb-trial", {f"{EXT_B}.json": hanzi_writer_document(SHI)})
        record = self.dir / "r.json"
        result = run(["trial", EXT_B, "--data", folder, "--writer", "simulated", "--max-duration", "30",
                      "--json", record], self.dir)
        self.assertEqual(result.returncode, 0, result.stderr)
        document = json.loads(record.read_text(encoding="utf-8"))
        self.assertEqual(document["specification"]["trial"]["characters"], EXT_B)
        check = run(["trial", "--spec", record, "--check", "--data", folder], self.dir)
        self.assertEqual(check.returncode, 0, check.stderr)

    @unittest.skipIf(calligraphy is None, "the Python module is not on PYTHONPATH")
    def test_python_library_of_other_sets(self):
        folder = self.folder("py", {f"{EXT_B}.json": hanzi_writer_document(SHI),
                                    "graphics.txt": "{}\n", "README.md": "another set\n"})
        lib = calligraphy.CharacterLibrary.from_hanzi_writer(folder)
        self.assertIn(EXT_B, lib)
        self.assertEqual(len(lib), 1)
        character = lib.load(EXT_B)
        self.assertEqual(character.typical_stroke_ids,
                         calligraphy.CharacterLibrary.embedded().load(SHI).typical_stroke_ids)
        self.assertIn(EXT_B, character.source)
        with self.assertRaises(calligraphy.CharacterNotFound):
            lib.load(SHI)
        trace = {k: [r[i] for r in hand_trace(SHI)] for i, k in enumerate(("t", "x", "y", "pen"))}
        self.assertEqual(spatial(calligraphy.score(trace, EXT_B, library=lib)), spatial(calligraphy.score(trace, SHI)))


if __name__ == "__main__":
    unittest.main(verbosity=2)
