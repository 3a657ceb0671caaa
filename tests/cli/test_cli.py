#!/usr/bin/env python3
"""End-to-end tests of the `calligraphy` program (docs/cli.md), run by CTest as `cli_tests`.

CALLIGRAPHY_CLI names the program and CALLIGRAPHY_SOURCE_DIR the source tree. Standard library only
(unittest), so that no package has to be installed. Each case runs the program in a fresh temporary
folder, so that a stray output file (one named `-` or `--seed`) would show.
"""
import json
import os
import random
import re
import resource
import shutil
import signal
import stat
import subprocess
import sys
import tempfile
import threading
import unittest
from pathlib import Path

CLI = os.environ.get("CALLIGRAPHY_CLI", "")
SOURCE = Path(os.environ.get("CALLIGRAPHY_SOURCE_DIR", Path(__file__).resolve().parents[2]))
DATA = SOURCE / "data" / "hanzi-writer-data"

COMMANDS = [
    [], ["trial"], ["train"], ["score"], ["model"], ["strokes"], ["characters"], ["devices"],
    ["corpus"], ["corpus", "build"], ["corpus", "stats"], ["corpus", "fidelity"], ["corpus", "validate"],
    ["bench"], ["bench", "nearest"], ["bench", "jumps"], ["bench", "tick"], ["bench", "loop"],
]


def project_version():
    text = (SOURCE / "CMakeLists.txt").read_text(encoding="utf-8")
    return re.search(r"project\(calligraphy VERSION ([0-9.]+)", text).group(1)


class CliTestCase(unittest.TestCase):
    def setUp(self):
        if not CLI or not Path(CLI).exists():
            self.fail(f"CALLIGRAPHY_CLI={CLI!r} is not the calligraphy program: run these tests through ctest")
        self.folder = tempfile.TemporaryDirectory(prefix="calligraphy-cli-")
        self.cwd = Path(self.folder.name)

    def tearDown(self):
        self.folder.cleanup()

    def run_cli(self, *args, stdout=subprocess.PIPE, limit_file_bytes=None, timeout=120):
        def limit():
            if limit_file_bytes is not None:  # writes beyond this many bytes fail with EFBIG
                signal.signal(signal.SIGXFSZ, signal.SIG_IGN)
                resource.setrlimit(resource.RLIMIT_FSIZE, (limit_file_bytes, limit_file_bytes))

        return subprocess.run([CLI, *map(str, args)], cwd=self.cwd, stdout=stdout, stderr=subprocess.PIPE,
                              timeout=timeout, preexec_fn=limit)

    def assert_usage_error(self, args, option):
        """Exit status 2 and one line on stderr naming `option`."""
        result = self.run_cli(*args)
        message = result.stderr.decode()
        self.assertEqual(result.returncode, 2, f"{args}: {message}")
        self.assertEqual(len(message.splitlines()), 1, f"{args}: not one line: {message!r}")
        self.assertIn(option, message, f"{args}: the message does not name {option}")
        return message

    def trial_json(self, *args):
        result = self.run_cli("trial", *args, "--json", "-")
        self.assertEqual(result.returncode, 0, result.stderr.decode())
        return json.loads(result.stdout)

    def files_here(self):
        return sorted(p.name for p in self.cwd.iterdir())


class HelpAndVersion(CliTestCase):
    def test_help_of_every_command_lists_each_option_with_default(self):
        for command in COMMANDS:
            for flag in ("--help", "-h"):
                result = self.run_cli(*command, flag)
                self.assertEqual(result.returncode, 0, f"{command} {flag}: {result.stderr.decode()}")
                text = result.stdout.decode()
                self.assertIn("Usage: " + " ".join(["calligraphy", *command]), text)
                # One entry per option: its line and any continuation lines (indented further).
                entries = re.findall(r"^  (--[a-z-]+.*(?:\n {10,}.*)*)", text, flags=re.M)
                self.assertTrue(entries or command in ([], ["corpus"], ["bench"]), command)
                for entry in entries:
                    # An option taking a value ("--seed N ...") shows its default or that it is required.
                    if re.match(r"--[a-z-]+ [A-Z]", entry):
                        self.assertRegex(entry, r"\((default: .+|required)\)", f"{command}: {entry}")
                    # A count ("--jobs N") states the integers it takes.
                    if re.match(r"--[a-z-]+ N(?![/A-Za-z])", entry):
                        self.assertRegex(entry, r"-?\d+\.\.\d+|in [\[(]", f"{command}: {entry}")

    def test_an_option_without_a_default_says_none_once(self):
        # --exit-after has no default (docs/cli.md): its help says so, once, with its range.
        for command in (["train"], ["session", "run"]):
            text = self.run_cli(*command, "--help").stdout.decode()
            entry = re.search(r"^  (--exit-after .*(?:\n {10,}.*)*)", text, flags=re.M).group(1)
            self.assertEqual(re.findall(r"\(default: [^)]*\)", entry), ["(default: none)"], f"{command}: {entry}")
            self.assertIn("(0, 86400]", entry, command)

    def test_version_of_every_command(self):
        expected = f"calligraphy {project_version()}\n"
        for command in COMMANDS:
            result = self.run_cli(*command, "--version")
            self.assertEqual(result.returncode, 0, f"{command}: {result.stderr.decode()}")
            self.assertEqual(result.stdout.decode(), expected)

    def test_train_refuses_bad_options_before_opening_a_window(self):
        # A usage error that only a build with the window finds (its devices): without it, exit 1 saying so.
        probe = self.run_cli("train", "永", "--writer", "simulated", "--device", "mouse")
        if probe.returncode == 1 and b"without the trainer" in probe.stderr:
            self.skipTest("built without the trainer window")
        self.assert_usage_error(["train", "永", "--window", "10x10"], "--window")
        self.assert_usage_error(["train", "永", "--window", "1280"], "--window")
        self.assert_usage_error(["train", "永", "--subject", "../x"], "--subject")
        self.assert_usage_error(["train", "永", "--device", "nope"], "--device")
        self.assert_usage_error(["train", "永", "--writer", "simulated", "--device", "mouse"], "--writer")
        self.assert_usage_error(["train", "永", "--device", "simulated"], "--device")
        self.assert_usage_error(["train", "永", "--exit-after", "0"], "--exit-after")
        self.assert_usage_error(["train", "永", "--watchdog-ms", "60001"], "--watchdog-ms")
        self.assert_usage_error(["train", "永", "--watchdog-ms", "-1"], "--watchdog-ms")
        self.assert_usage_error(["train", "永", "--screenshot", "-"], "--screenshot")

    def test_trial_help_is_help_not_a_character(self):
        result = self.run_cli("trial", "-h")
        self.assertEqual(result.returncode, 0)
        self.assertIn("--watchdog-ms", result.stdout.decode())
        self.assertIn("--rate HZ", result.stdout.decode())  # the servo rate is documented, with its unit
        self.assertIn("[Hz]", result.stdout.decode())

    def test_group_without_subcommand_prints_its_help_and_fails(self):
        for group, subcommands in (("bench", ["nearest", "jumps", "tick", "loop"]),
                                   ("corpus", ["build", "stats", "fidelity", "validate"])):
            result = self.run_cli(group)
            self.assertEqual(result.returncode, 2)
            message = result.stderr.decode()
            for subcommand in subcommands:
                self.assertIn(subcommand, message)
            self.assertTrue(message.splitlines()[-1].startswith(f"calligraphy {group}: error:"))
        self.assertEqual(self.run_cli().returncode, 2)
        self.assertIn("unknown command 'nonsense'", self.run_cli("nonsense").stderr.decode())


class StrictOptions(CliTestCase):
    def test_equals_form_is_the_same_option(self):
        self.assertEqual(self.trial_json("乙", "--seed=3"), self.trial_json("乙", "--seed", "3"))

    def test_option_taking_an_option_as_its_value_is_an_error(self):
        self.assert_usage_error(["trial", "乙", "--json", "--seed", "3"], "--json")
        self.assert_usage_error(["trial", "乙", "--json=--seed"], "--json")
        self.assert_usage_error(["trial", "乙", "--device", "--json", "x.json"], "--device")
        self.assertEqual(self.files_here(), [], "an output file was written after a usage error")

    def test_repeated_option_is_an_error(self):
        self.assert_usage_error(["trial", "乙", "--seed", "3", "--seed", "4"], "--seed")
        self.assert_usage_error(["trial", "乙", "--guidance", "on", "--guidance", "off"], "--guidance")
        self.assert_usage_error(["trial", "乙", "--json", "a.json", "--json", "b.json"], "--json")

    def test_numbers_are_parsed_whole_and_by_kind(self):
        self.assert_usage_error(["corpus", "fidelity", "--tolerances", "2x"], "--tolerances")
        self.assert_usage_error(["corpus", "fidelity", "--tolerances", "2,,5"], "--tolerances")
        self.assert_usage_error(["corpus", "build", "--out", "s.clg", "--threads", "1.5"], "--threads")
        self.assert_usage_error(["bench", "tick", "--passes", "2x"], "--passes")
        self.assert_usage_error(["bench", "tick", "--passes", "0x10"], "--passes")
        self.assert_usage_error(["bench", "tick", "--passes", "0"], "--passes")
        self.assert_usage_error(["trial", "乙", "--seed", "-1"], "--seed")
        self.assert_usage_error(["trial", "乙", "--seed", "18446744073709551616"], "--seed")
        self.assert_usage_error(["trial", "乙", "--rate", "nan"], "--rate")
        self.assert_usage_error(["trial", "乙", "--pacing", "real-time", "--watchdog-ms", "1.5"], "--watchdog-ms")
        self.assert_usage_error(["bench", "loop", "--cpu", "-2"], "--cpu")
        # The run's end is a clock reading: 1e308 s would overflow it (and ran until stopped).
        self.assert_usage_error(["bench", "loop", "--seconds", "1e308"], "--seconds")
        self.assert_usage_error(["bench", "loop", "--seconds", "86400.5"], "--seconds")
        # With a trial, its 10^7-tick limit, named by the options given.
        self.assert_usage_error(["bench", "loop", "--trial", "乙", "--seconds", "20000"], "--seconds")

    def test_negative_integer_where_allowed(self):
        result = self.run_cli("bench", "loop", "--seconds", "0.05", "--cpu", "-1", "--realtime", "off", "--json")
        self.assertEqual(result.returncode, 0, result.stderr.decode())
        self.assertEqual(json.loads(result.stdout)["realtime"]["cpu"], -1)

    def test_64_bit_seed_is_exact(self):
        seed = 9007199254740993  # 2^53 + 1: a double would round it to 2^53
        exact = self.trial_json("乙", "--seed", seed)
        rounded = self.trial_json("乙", "--seed", seed - 1)
        self.assertEqual(exact["seed"], seed)
        self.assertEqual(rounded["seed"], seed - 1)
        self.assertNotEqual(exact["mean_deviation_m"], rounded["mean_deviation_m"],
                            "neighbouring seeds gave the same trial")

    def test_watchdog_only_with_real_time_pacing(self):
        self.assert_usage_error(["trial", "乙", "--watchdog-ms", "10"], "--watchdog-ms")
        self.assert_usage_error(["trial", "乙", "--pacing", "lock-step", "--watchdog-ms", "10"], "--watchdog-ms")

    def test_data_and_store_exclude_each_other(self):
        self.assert_usage_error(["trial", "乙", "--data", "x", "--store", "y"], "--store")

    def test_unknown_device_is_a_usage_error(self):
        self.assert_usage_error(["trial", "乙", "--device", "nope"], "--device")

    def test_library_errors_exit_1_with_one_line(self):
        for args in (["trial", "乙", "--data", self.cwd / "missing"], ["score", "missing.csv", "--character", "乙"],
                     ["corpus", "stats", "missing.clg"], ["model", "永", "--store", "missing.clg"]):
            result = self.run_cli(*args)
            self.assertEqual(result.returncode, 1, f"{args}: {result.stderr.decode()}")
            self.assertEqual(len(result.stderr.decode().splitlines()), 1, f"{args}: {result.stderr.decode()}")
            self.assertIn("missing", result.stderr.decode())


class StandardOutput(CliTestCase):
    def test_dash_writes_to_standard_output_not_to_a_file(self):
        result = self.run_cli("trial", "乙", "--svg", "-")
        self.assertEqual(result.returncode, 0)
        self.assertTrue(result.stdout.startswith(b"<svg"), result.stdout[:80])
        self.assertEqual(self.files_here(), [])
        self.assertEqual(self.run_cli("model", "永", "--svg", "-").stdout,
                         self.run_cli("model", "永", "--svg", "m.svg").returncode == 0
                         and (self.cwd / "m.svg").read_bytes())
        markdown = self.run_cli("strokes", "--markdown", "-")
        self.assertEqual(markdown.returncode, 0)
        self.assertIn(b"| ID |", markdown.stdout[:2000])

    def test_trial_csv_to_standard_output_is_the_file(self):
        to_stdout = self.run_cli("trial", "乙", "--seed", "2", "--csv", "-")
        self.assertEqual(self.run_cli("trial", "乙", "--seed", "2", "--csv", "t.csv").returncode, 0)
        self.assertEqual(to_stdout.stdout, (self.cwd / "t.csv").read_bytes())

    def test_two_outputs_cannot_share_standard_output(self):
        self.assert_usage_error(["trial", "乙", "--json", "-", "--csv", "-"], "--json")
        self.assert_usage_error(["model", "永", "--json", "--svg", "-"], "--svg")

    def test_dash_refused_where_it_makes_no_sense(self):
        self.assert_usage_error(["corpus", "build", "--out", "-"], "--out")
        self.assertEqual(self.files_here(), [])

    def test_devices_json(self):
        result = self.run_cli("devices", "--json")
        self.assertEqual(result.returncode, 0, result.stderr.decode())
        survey = json.loads(result.stdout)
        names = [d["name"] for d in survey["devices"]]
        self.assertIn("simulated", names)
        for device in survey["devices"]:
            self.assertGreater(device["info"]["max_force_n"], 0.0)
            self.assertEqual(len(device["info"]["workspace_size_m"]), 3)
            self.assertLess(max(device["info"]["workspace_size_m"]), 10.0)  # metres, not mm
        self.assertTrue(all(isinstance(note, str) for note in survey["notes"]))
        self.assertEqual(survey["any_hardware"], any(d["hardware"] for d in survey["devices"]))


class NothingLost(CliTestCase):
    def assert_fails_loudly(self, result, what):
        self.assertNotEqual(result.returncode, 0, f"{what}: exit 0")
        self.assertIn(what, result.stderr.decode())

    def test_full_standard_output_fails(self):
        with open("/dev/full", "wb") as full:
            for args in (["trial", "乙"], ["model", "永", "--json"], ["model", "永"], ["devices", "--json"],
                         ["strokes"], ["--help"], ["--version"], ["trial", "乙", "--json", "-"]):
                result = self.run_cli(*args, stdout=full)
                self.assert_fails_loudly(result, "standard output")

    def test_full_device_as_output_file_fails(self):
        for args in (["trial", "乙", "--json", "/dev/full"], ["trial", "乙", "--csv", "/dev/full"],
                     ["model", "永", "--svg", "/dev/full"], ["strokes", "--markdown", "/dev/full"]):
            result = self.run_cli(*args)
            self.assertEqual(result.returncode, 1, args)
            self.assertIn("/dev/full", result.stderr.decode())
            self.assertIn("No space left on device", result.stderr.decode())

    def test_failed_write_keeps_the_earlier_file(self):
        earlier = self.cwd / "out.json"
        earlier.write_text("earlier\n")
        # The file size limit makes every write past 64 bytes fail (EFBIG), like a full disk.
        result = self.run_cli("trial", "乙", "--json", earlier, limit_file_bytes=64)
        self.assertEqual(result.returncode, 1, result.stderr.decode())
        self.assertIn(str(earlier), result.stderr.decode())
        self.assertEqual(earlier.read_text(), "earlier\n")
        self.assertEqual(self.files_here(), ["out.json"], "a temporary file was left behind")

    def test_failed_corpus_build_keeps_the_earlier_store(self):
        store = self.cwd / "corpus.clg"
        first = self.run_cli("corpus", "build", "--data", DATA, "--out", store, "--threads", "1")
        self.assertEqual(first.returncode, 0, first.stderr.decode())
        good = store.read_bytes()
        # A different store (another tolerance) that cannot be written whole.
        second = self.run_cli("corpus", "build", "--data", DATA, "--out", store, "--threads", "1",
                              "--tolerance", "2", limit_file_bytes=len(good) // 2)
        self.assertEqual(second.returncode, 1)
        self.assertIn(str(store), second.stderr.decode())
        self.assertEqual(store.read_bytes(), good)
        self.assertEqual(self.files_here(), ["corpus.clg"])
        self.assertEqual(self.run_cli("corpus", "stats", store).returncode, 0)

    def test_corpus_build_shows_progress_only_on_a_terminal_or_when_verbose(self):
        store = self.cwd / "corpus.clg"
        quiet = self.run_cli("corpus", "build", "--data", DATA, "--out", store, "--threads", "1")
        self.assertEqual(quiet.returncode, 0, quiet.stderr.decode())
        self.assertEqual(quiet.stderr.decode(), "")  # stderr is a pipe here, not a terminal
        verbose = self.run_cli("corpus", "build", "--data", DATA, "--out", store, "--threads", "1", "--verbose")
        self.assertEqual(verbose.returncode, 0, verbose.stderr.decode())
        self.assertRegex(verbose.stderr.decode(), r"(?m)^fitting: (\d+)/\1$")

    def test_corpus_stats_reports_bad_records_on_standard_error(self):
        store = self.cwd / "corpus.clg"
        self.assertEqual(self.run_cli("corpus", "build", "--data", DATA, "--out", store, "--threads", "1")
                         .returncode, 0)
        whole = bytearray(store.read_bytes())
        whole[len(whole) * 3 // 4] ^= 0x5A  # inside a record: the header and index stay whole
        store.write_bytes(bytes(whole))
        result = self.run_cli("corpus", "stats", store)
        self.assertEqual(result.returncode, 1, result.stderr.decode())
        errors = result.stderr.decode().splitlines()
        self.assertEqual(len(errors), 1, errors)
        self.assertTrue(errors[0].startswith("calligraphy corpus stats: error: "), errors)
        self.assertIn(str(store), errors[0])
        out = result.stdout.decode()
        self.assertIn("checksums           1 bad records", out)  # the statistics stay on standard output
        self.assertNotIn(str(store) + ":", out)

    def test_full_disk_keeps_the_earlier_store(self):
        mount_point = self.cwd / "tiny"
        mount_point.mkdir()
        mounted = subprocess.run(["mount", "-t", "tmpfs", "-o", "size=64k", "tmpfs", str(mount_point)],
                                 stderr=subprocess.PIPE, stdout=subprocess.PIPE)
        if mounted.returncode != 0:
            self.skipTest("cannot mount a small tmpfs here (needs privileges): " + mounted.stderr.decode().strip())
        try:
            store = mount_point / "corpus.clg"
            self.assertEqual(self.run_cli("corpus", "build", "--data", DATA, "--out", store).returncode, 0)
            good = store.read_bytes()
            filler = mount_point / "filler"
            descriptor = os.open(filler, os.O_WRONLY | os.O_CREAT)
            try:  # fill the file system
                while os.write(descriptor, b"\0" * 4096) > 0:
                    pass
            except OSError:
                pass
            finally:
                os.close(descriptor)
            result = self.run_cli("corpus", "build", "--data", DATA, "--out", store, "--tolerance", "2")
            self.assertEqual(result.returncode, 1)
            self.assertIn("No space left on device", result.stderr.decode())
            self.assertEqual(store.read_bytes(), good)
            self.assertEqual(sorted(p.name for p in mount_point.iterdir()), ["corpus.clg", "filler"])
        finally:
            subprocess.run(["umount", str(mount_point)], check=True)

    def test_output_to_a_fifo(self):
        fifo = self.cwd / "pipe"
        os.mkfifo(fifo)
        received = []
        reader = threading.Thread(target=lambda: received.append(fifo.read_bytes()))
        reader.start()
        result = self.run_cli("model", "永", "--svg", fifo)
        reader.join(timeout=60)
        self.assertEqual(result.returncode, 0, result.stderr.decode())
        self.assertEqual(received, [self.run_cli("model", "永", "--svg", "-").stdout])

    def test_replaced_file_keeps_its_permissions_and_links(self):
        target = self.cwd / "real.json"
        target.write_text("old")
        os.chmod(target, 0o640)
        link = self.cwd / "link.json"
        link.symlink_to(target)
        self.assertEqual(self.run_cli("trial", "乙", "--json", link).returncode, 0)
        self.assertTrue(link.is_symlink())
        self.assertEqual(stat.S_IMODE(target.stat().st_mode), 0o640)
        self.assertEqual(json.loads(target.read_text())["character"], "乙")

    def test_markdown_into_a_device_does_not_read_it(self):
        # /dev/zero never ends: the command must only write there.
        result = self.run_cli("bench", "jumps", "--seeds", "1", "--chars", "乙", "--markdown", "/dev/zero")
        self.assertEqual(result.returncode, 0, result.stderr.decode())

    def test_markdown_document_keeps_its_text(self):
        document = self.cwd / "doc.md"
        document.write_text("# Heading\n\nHand-written text.\n")
        result = self.run_cli("bench", "jumps", "--seeds", "1", "--chars", "乙", "--markdown", document)
        self.assertEqual(result.returncode, 0, result.stderr.decode())
        text = document.read_text()
        self.assertTrue(text.startswith("# Heading\n\nHand-written text.\n"))
        self.assertEqual(text.count("<!-- BEGIN generated by `calligraphy bench jumps` -->"), 1)
        again = self.run_cli("bench", "jumps", "--seeds", "1", "--chars", "乙", "--markdown", document)
        self.assertEqual(again.returncode, 0)
        self.assertEqual(document.read_text().count("<!-- BEGIN generated"), 1)  # replaced, not appended

    def test_bench_jumps_takes_any_character_of_its_library_and_names_only_options_it_has(self):
        # 丁 is in the bundled corpus, not the embedded set; the advice for one it lacks names --data alone,
        # the library option bench jumps and bench tick have (not --store).
        result = self.run_cli("bench", "jumps", "--seeds", "1", "--chars", "丁", "--json")
        self.assertEqual(result.returncode, 0, result.stderr.decode())
        self.assertEqual({row["guidance"] for row in json.loads(result.stdout)}, {True, False})
        for command in (["bench", "jumps", "--seeds", "1"], ["bench", "tick"]):
            with self.subTest(command=command):
                result = self.run_cli(*command, "--chars", "\U00020000")
                self.assertEqual(result.returncode, 2)
                line = result.stderr.decode().strip()
                self.assertIn("--chars", line)
                self.assertIn("--data DIR", line)
                self.assertNotIn("--store", line)
        data = self.cwd / "data"
        data.mkdir()
        (data / "乙.json").write_text(json.dumps({"strokes": [], "medians": []}))
        result = self.run_cli("bench", "jumps", "--seeds", "1", "--chars", "丁", "--data", data)
        self.assertEqual(result.returncode, 2, result.stderr.decode())
        self.assertIn("--chars", result.stderr.decode())

    def test_markdown_header_states_the_command_as_run(self):
        document = self.cwd / "doc.md"
        result = self.run_cli("bench", "acceptance", "--characters", "2", "--markdown", document)
        self.assertEqual(result.returncode, 0, result.stderr.decode())
        self.assertIn(f"Made by `calligraphy bench acceptance --markdown {document} --characters 2 --seed 1`",
                      document.read_text())

    def test_markdown_section_without_its_end_is_refused_untouched(self):
        document = self.cwd / "doc.md"
        for command, marker in (
                (["bench", "acceptance", "--characters", "2"], "<!-- BEGIN generated by `calligraphy bench acceptance` -->"),
                (["bench", "jumps", "--seeds", "1", "--chars", "乙"], "<!-- BEGIN generated by `calligraphy bench jumps` -->")):
            with self.subTest(command=command):
                text = f"# Heading\n\n{marker}\nold table, its end marker lost\n\nHand-written text.\n"
                document.write_text(text)
                result = self.run_cli(*command, "--markdown", document)
                self.assertEqual(result.returncode, 2, result.stderr.decode())
                error = result.stderr.decode()
                self.assertEqual(len(error.splitlines()), 1, error)
                self.assertIn(str(document), error)
                self.assertIn(marker, error)
                self.assertEqual(document.read_text(), text)
                self.assertEqual(self.files_here(), ["doc.md"])


def model_trace(model, order=None, reverse=()):
    """A CSV pen trace in data units drawing the model's elements: pen down along each stroke (sampled every
    ~4 data units at 100 Hz-like steps), one lifted sample between strokes."""

    def point(control, s):
        points = [tuple(p) for p in control]
        while len(points) > 1:  # de Casteljau
            points = [((1 - s) * a[0] + s * b[0], (1 - s) * a[1] + s * b[1]) for a, b in zip(points, points[1:])]
        return points[0]

    rows, t = ["t,x,y,pen"], 0.0
    for index in order or range(len(model["strokes"])):
        samples = []
        for element in model["strokes"][index]["elements"]:
            samples += [point(element["control_points"], k / 40) for k in range(41)]
        if index in reverse:
            samples.reverse()
        for x, y in samples:
            rows.append(f"{t:.3f},{x:.4f},{y:.4f},1")
            t += 0.01
        rows.append(f"{t:.3f},{samples[-1][0]:.4f},{samples[-1][1]:.4f},0")
        t += 0.2
    return "\n".join(rows) + "\n"


def assert_same_record(case, scored, recorded, where):
    """The metrics of a trace file and of the trial itself agree: counts, flags and texts exactly, numbers to
    the trace's precision (times to 1 us, lengths to 0.1 um; docs/experiments.md), so to 1e-6 relative."""
    if isinstance(recorded, dict):
        case.assertEqual(sorted(scored), sorted(recorded), where)
        for key in recorded:
            assert_same_record(case, scored[key], recorded[key], f"{where}/{key}")
    elif isinstance(recorded, list):
        case.assertEqual(len(scored), len(recorded), where)
        for index, (a, b) in enumerate(zip(scored, recorded)):
            assert_same_record(case, a, b, f"{where}/{index}")
    elif isinstance(recorded, float) and not isinstance(recorded, bool):
        case.assertAlmostEqual(scored, recorded, delta=1e-6 * max(1.0, abs(recorded)), msg=where)
    else:
        case.assertEqual(scored, recorded, where)


class Score(CliTestCase):
    def score(self, trace_text, character, *args):
        (self.cwd / "trace.csv").write_text(trace_text)
        result = self.run_cli("score", "trace.csv", "--character", character, *args, "--json", "-")
        self.assertEqual(result.returncode, 0, result.stderr.decode())
        return json.loads(result.stdout)

    # The keys of the one metrics record (docs/metrics.md): `trial`, `score` and a session's records carry them.
    METRIC_KEYS = ("strokes_total", "strokes_written", "strokes_accepted", "refusals", "completed_in_order",
                   "order_errors", "backwards_strokes", "unmatched_segments", "mean_deviation_m",
                   "max_deviation_m", "rms_deviation_m", "frechet_m", "dtw_m", "total_time_s",
                   "pen_down_time_s", "velocity_peaks", "normalised_jerk", "per_character")

    def test_a_trials_csv_scores_to_the_trials_own_metrics(self):
        # One trace, one record: the score of the trial's CSV repeats every metric the trial reported.
        for characters, extra in (("永", ["--guidance", "off"]), ("口九", [])):
            trial = self.run_cli("trial", characters, "--seed", "7", "--csv", "t.csv", "--json", "t.json", *extra)
            self.assertEqual(trial.returncode, 0, trial.stderr.decode())
            metrics = json.loads((self.cwd / "t.json").read_text())
            result = self.run_cli("score", "t.csv", "--character", characters, "--json", "s.json")
            self.assertEqual(result.returncode, 0, result.stderr.decode())
            self.assertIn("strokes accepted", result.stdout.decode())  # the table
            score = json.loads((self.cwd / "s.json").read_text())
            for key in self.METRIC_KEYS:
                assert_same_record(self, score[key], metrics[key], f"{characters}: {key}")
            self.assertEqual(len(score["per_character"]), len(characters))
            self.assertGreater(score["strokes_written"], 0)
            self.assertLessEqual(score["mean_deviation_m"], score["max_deviation_m"])
            # Indices count from 0 everywhere.
            self.assertEqual([s["index"] for s in score["per_character"][0]["per_stroke"]],
                             list(range(score["per_character"][0]["strokes_total"])))

    def test_the_reference_itself_scores_near_zero(self):
        model = json.loads(self.run_cli("model", "永", "--json").stdout)
        score = self.score(model_trace(model), "永", "--units", "data")
        self.assertEqual(score["strokes_written"], len(model["strokes"]))
        self.assertTrue(score["completed_in_order"])
        # Samples on the elements themselves: only rounding to 1e-4 data units (6e-6 mm) remains.
        self.assertLess(score["max_deviation_m"], 1e-6)
        self.assertEqual(score["per_character"][0]["pen_lifts"], len(model["strokes"]) - 1)

    def test_order_and_direction_errors_are_counted(self):
        model = json.loads(self.run_cli("model", "永", "--json").stdout)
        n = len(model["strokes"])
        reversed_order = self.score(model_trace(model, order=list(reversed(range(n)))), "永", "--units", "data")
        self.assertEqual(reversed_order["order_errors"], n * (n - 1) // 2)
        self.assertFalse(reversed_order["completed_in_order"])
        backwards = self.score(model_trace(model, reverse={0}), "永", "--units", "data")
        self.assertEqual(backwards["backwards_strokes"], 1)
        self.assertTrue(backwards["per_character"][0]["per_stroke"][0]["backwards"])

    def test_usage(self):
        self.assert_usage_error(["score", "t.csv", "--character", "永我", "--units", "data"], "--character")
        self.assert_usage_error(["score", "t.csv"], "--character")
        self.assert_usage_error(["score", "t.csv", "--character", "永", "--units", "metres"], "--units")


class EveryCharacterOffline(CliTestCase):
    """Any hanzi-writer-data character with no fetched data, no --data and no --store: the default lookup
    falls back to the corpus store compiled into the program (docs/corpus.md)."""

    def run_offline(self, *args):
        environment = {k: v for k, v in os.environ.items() if k != "CALLIGRAPHY_CORPUS_DIR"}
        environment["HOME"] = environment["XDG_CACHE_HOME"] = str(self.cwd)  # no fetched package to find
        return subprocess.run([CLI, *map(str, args)], cwd=self.cwd, stdout=subprocess.PIPE,
                              stderr=subprocess.PIPE, timeout=120, env=environment)

    def json_of(self, *args):
        result = self.run_offline(*args)
        self.assertEqual(result.returncode, 0, f"{args}: {result.stderr.decode()}")
        return json.loads(result.stdout)

    def store_characters(self, count):
        """Characters beyond the embedded ones, drawn at random (seeded): none is named in any test."""
        listed = self.json_of("characters", "--json")
        self.assertEqual(listed["count"], 9574)
        embedded = {p.stem for p in DATA.glob("*.json")}
        pool = [entry for entry in listed["characters"] if entry["character"] not in embedded]
        return random.Random(20261126).sample(pool, count)

    def test_a_store_character_is_modelled_written_in_order_scored_and_listed(self):
        for entry in self.store_characters(3):
            char = entry["character"]
            model = self.json_of("model", char, "--json")
            strokes = len(model["strokes"])
            self.assertEqual(strokes, entry["strokes"], char)
            trial = self.run_offline("trial", char, "--seed", "5", "--writer-profile", "skilled",
                                     "--csv", "t.csv", "--json", "t.json")
            self.assertEqual(trial.returncode, 0, f"{char}: {trial.stderr.decode()}")
            metrics = json.loads((self.cwd / "t.json").read_text())
            self.assertEqual(metrics["strokes_total"], strokes, char)
            self.assertEqual(metrics["strokes_accepted"], strokes, char)  # every stroke, in order
            self.assertTrue(metrics["completed_in_order"], char)
            score = self.json_of("score", "t.csv", "--character", char, "--json", "-")
            for key in Score.METRIC_KEYS:
                assert_same_record(self, score[key], metrics[key], f"{char}: {key}")
            # Listed by its stroke count, by each of its typical strokes (acronym, ID), and from a text.
            by_count = self.json_of("characters", "--strokes", strokes, "--json")
            self.assertIn(char, [e["character"] for e in by_count["characters"]])
            self.assertTrue(all(e["strokes"] == strokes for e in by_count["characters"]))
            acronym, typical_id = entry["typical_strokes"][-1], entry["typical_ids"][-1]
            for value in (acronym, acronym.lower(), typical_id):
                by_stroke = self.json_of("characters", "--typical", value, "--json")
                self.assertIn(char, [e["character"] for e in by_stroke["characters"]], value)
                self.assertTrue(all(typical_id in e["typical_ids"] for e in by_stroke["characters"]))
            text = self.json_of("characters", "--text", f"{char}，{char} 龘", "--json")
            self.assertEqual([e["character"] for e in text["characters"]], [char])
            self.assertEqual(text["not_found"], ["，", "龘"])

    def test_characters_table_and_usage(self):
        table = self.run_offline("characters", "--text", "永字八法", "--strokes", "2")
        self.assertEqual(table.returncode, 0, table.stderr.decode())
        lines = table.stdout.decode().splitlines()
        self.assertTrue(lines[0].startswith("char"), lines)
        self.assertEqual([line.split()[0] for line in lines[1:-1]], ["八"])
        self.assertTrue(lines[-1].startswith("1 character; library: every hanzi-writer-data"), lines)
        for name in ("横折钩", "㇆"):  # HZG by its Chinese name and by its CJK stroke character
            listed = self.json_of("characters", "--typical", name, "--text", "一永月", "--json")
            self.assertEqual([e["character"] for e in listed["characters"]], ["永", "月"], name)
        self.assert_usage_error(["characters", "--typical", "HZZZZZ"], "--typical")
        self.assertIn("did you mean", self.assert_usage_error(["characters", "--typical", "HZGG"], "--typical"))
        self.assert_usage_error(["characters", "--typical", "40"], "--typical")
        self.assert_usage_error(["characters", "--strokes", "0"], "--strokes")
        self.assert_usage_error(["characters", "--strokes", "x"], "--strokes")
        self.assert_usage_error(["characters", "--text", ""], "--text")
        missing = self.run_cli("characters", "--store", "missing.clg")
        self.assertEqual(missing.returncode, 1)
        self.assertIn("missing.clg", missing.stderr.decode())


class Determinism(CliTestCase):
    def test_lock_step_trial_json_is_reproducible(self):
        for name in ("a.json", "b.json"):
            self.assertEqual(self.run_cli("trial", "永", "--seed", "7", "--json", name).returncode, 0)
        self.assertEqual((self.cwd / "a.json").read_bytes(), (self.cwd / "b.json").read_bytes())


class GuidanceModesAndWriters(CliTestCase):
    """`trial --writer-profile`, `--writer-param`, `--guidance-mode`, `--guidance-gain`, `--teacher`, `--record`."""

    def test_foreign_writer_runs_and_is_recorded(self):
        metrics = self.trial_json("十", "--writer-profile", "foreign", "--seed", "2")
        self.assertEqual(metrics["writer"], "simulated")  # who wrote it, spelt as --writer
        self.assertEqual(metrics["writer_profile"], "foreign")
        self.assertEqual(metrics["guidance_mode"], "fixed")
        self.assertGreater(metrics["total_time_s"], 0.0)

    def test_a_stroke_always_written_wrongly_is_assisted_and_the_trial_goes_on(self):
        # Lifted in the middle of every stroke, every attempt (no correction between attempts): each stroke
        # of 人 is refused until assist_after_misses (5) refusals credit it as assisted (docs/stroke-acceptance.md).
        metrics = self.trial_json("人", "--seed", "3", "--writer-param", "mid_stroke_lift_probability=1",
                                  "--writer-param", "correction_per_attempt=0",
                                  "--writer-param", "max_attempts_per_stroke=20")
        self.assertEqual(metrics["end_reason"], "completed")
        self.assertEqual(metrics["strokes_assisted"], 2)
        self.assertEqual(metrics["strokes_completed"], 0)
        self.assertFalse(metrics["completed_in_order"])
        for stroke in metrics["renderer_strokes"]:
            self.assertTrue(stroke["assisted"])
            self.assertFalse(stroke["completed"])
        # `attempts` counts entries into WS. The first stroke's five misses are all such; the writer redoes it
        # once more before it sees the credit, a pen-down off the second's start that is a miss of the second.
        first, second = metrics["renderer_strokes"]
        self.assertEqual(first["attempts"], 5)
        self.assertLessEqual(second["attempts"], 5)
        # The same writer lifting only at the end: written, never assisted.
        careful = self.trial_json("人", "--seed", "3", "--writer-param", "mid_stroke_lift_probability=0")
        self.assertEqual(careful["strokes_assisted"], 0)
        self.assertTrue(all(not s["assisted"] for s in careful["renderer_strokes"]))

    def test_writer_param_changes_the_trial_and_a_bad_key_is_refused(self):
        plain = self.trial_json("十", "--seed", "4")
        biased = self.trial_json("十", "--seed", "4", "--writer-param", "bias_offset_m=0.004",
                                 "--writer-param", "writing_speed_m_s=0.04")
        self.assertEqual(biased["writer_parameters"], ["bias_offset_m=0.004", "writing_speed_m_s=0.04"])
        self.assertNotIn("writer_parameters", plain)
        self.assertNotEqual(plain["total_time_s"], biased["total_time_s"])
        message = self.assert_usage_error(["trial", "十", "--writer-param", "bias_offset=1"], "--writer-param")
        self.assertIn("bias_offset", message)
        self.assertIn("bias_offset_m", message)  # the known keys are listed
        message = self.assert_usage_error(["trial", "十", "--writer-param", "bias_offset_m=far"], "--writer-param")
        self.assertIn("'far' is not a number", message)  # the key is known: the value is named
        self.assert_usage_error(["trial", "十", "--writer-param", "bias_offset_m=-1"], "bias_offset_m")

    def test_recorded_teacher_is_replayed_on_the_same_character(self):
        record = self.run_cli("trial", "十", "--writer-profile", "skilled", "--seed", "1", "--record",
                              "teacher.json")
        self.assertEqual(record.returncode, 0, record.stderr.decode())
        teacher = json.loads((self.cwd / "teacher.json").read_text(encoding="utf-8"))
        self.assertEqual(teacher["format"], "calligraphy-teacher-recording")
        self.assertEqual(teacher["characters"], "十")
        replay = self.trial_json("十", "--seed", "3", "--guidance-mode", "replay", "--teacher", "teacher.json")
        self.assertTrue(replay["completed_in_order"])
        self.assertEqual(replay["guidance_mode"], "replay")
        self.assertEqual(replay["teacher"], {"file": "teacher.json", "characters": "十"})
        other = self.run_cli("trial", "人", "--guidance-mode", "replay", "--teacher", "teacher.json")
        self.assertEqual(other.returncode, 1)
        self.assertIn("teacher.json", other.stderr.decode())
        self.assertIn("人", other.stderr.decode())

    def test_a_replay_record_run_from_another_folder_names_its_teacher_and_what_to_give(self):
        # The record names its teacher as --teacher was given, relative to the folder it ran in.
        self.assertEqual(self.run_cli("trial", "十", "--writer-profile", "skilled", "--record",
                                      "teacher.json").returncode, 0)
        self.assertEqual(self.run_cli("trial", "十", "--guidance-mode", "replay", "--teacher", "teacher.json",
                                      "--json", "replay.json").returncode, 0)
        elsewhere = self.cwd / "elsewhere"
        elsewhere.mkdir()
        refused = subprocess.run([CLI, "trial", "--spec", "../replay.json", "--json", "again.json"], cwd=elsewhere,
                                 stdout=subprocess.PIPE, stderr=subprocess.PIPE, timeout=120)
        message = refused.stderr.decode()
        self.assertEqual(refused.returncode, 1, message)  # a missing file: docs/cli.md's status 1
        self.assertEqual(len(message.splitlines()), 1, message)
        self.assertIn("--spec ../replay.json: the replay's teacher teacher.json (as --teacher was given when it "
                      "ran", message)
        self.assertIn("no such file; give --teacher FILE", message)
        self.assertEqual(list(elsewhere.iterdir()), [])  # nothing written
        given = subprocess.run([CLI, "trial", "--spec", "../replay.json", "--teacher", "../teacher.json", "--json",
                                "again.json"], cwd=elsewhere, stderr=subprocess.PIPE, timeout=120)
        self.assertEqual(given.returncode, 0, given.stderr.decode())
        self.assertEqual(json.loads((elsewhere / "again.json").read_text(encoding="utf-8"))["teacher"]["file"],
                         "../teacher.json")

    def test_record_refused_for_a_trial_not_completed_in_order(self):
        # A writer who gives up on the first attempt at a stroke out of order cannot teach the order.
        result = self.run_cli("trial", "永", "--writer-profile", "foreign", "--seed", "1", "--writer-param",
                              "order_error_probability=1", "--writer-param", "max_attempts_per_stroke=1",
                              "--record", "teacher.json", "--json", "t.json")
        metrics = json.loads((self.cwd / "t.json").read_text(encoding="utf-8"))
        self.assertFalse(metrics["completed_in_order"])
        self.assertEqual(result.returncode, 1)
        self.assertIn("--record", result.stderr.decode())
        self.assertFalse((self.cwd / "teacher.json").exists())

    def test_fading_gain_zero_leaves_a_novice_further_off_than_gain_one(self):
        for character in ("十", "人", "永"):
            faded = self.trial_json(character, "--seed", "5", "--guidance-mode", "fading", "--guidance-gain", "0")
            full = self.trial_json(character, "--seed", "5", "--guidance-mode", "fading", "--guidance-gain", "1")
            self.assertEqual((faded["guidance_gain"], full["guidance_gain"]), (0.0, 1.0))
            self.assertGreater(faded["mean_deviation_m"], full["mean_deviation_m"], character)

    def test_usage_errors(self):
        self.assert_usage_error(["trial", "十", "--guidance", "off", "--guidance-mode", "fading"], "--guidance-mode")
        self.assert_usage_error(["trial", "十", "--guidance-gain", "0.5"], "--guidance-gain")
        self.assert_usage_error(["trial", "十", "--guidance-mode", "fading", "--guidance-gain", "1.5"],
                                "--guidance-gain")
        self.assert_usage_error(["trial", "十", "--guidance-mode", "replay"], "--teacher")
        self.assert_usage_error(["trial", "十", "--teacher", "t.json"], "--teacher")
        self.assert_usage_error(["trial", "十", "--writer", "expert"], "--writer")
        self.assert_usage_error(["trial", "十", "--writer-profile", "expert"], "--writer-profile")
        self.assert_usage_error(["trial", "十", "--record", "-"], "--record")
        self.assertEqual(self.files_here(), [])


# A study protocol of one guided trial of 永, for the session commands' default runs.
ONE_TRIAL_PROTOCOL = {
    "format": "calligraphy-study-protocol", "version": 1, "name": "one",
    "description": "one guided trial of one character",
    "conditions": [{"name": "haptic", "mode": "haptic"}],
    "test": {"characters": ["永"], "conditions": ["haptic"], "repetitions": 1},
    "trial": {"max_duration_s": 60, "rate_hz": 1000},
}


class OneCommandLine(CliTestCase):
    """One meaning per option name, "did you mean" for a typo, DIR and FILE in --help, quiet defaults."""

    def write_protocol(self):
        (self.cwd / "p.json").write_text(json.dumps(ONE_TRIAL_PROTOCOL, ensure_ascii=False), encoding="utf-8")
        return "p.json"

    def last_error_line(self, args):
        """Exit status 2 (usage) and the `calligraphy ...: error:` line, the last on stderr."""
        result = self.run_cli(*args)
        self.assertEqual(result.returncode, 2, f"{args}: {result.stderr.decode()}")
        line = result.stderr.decode().splitlines()[-1]
        self.assertIn(": error: ", line, args)
        return line

    def test_writer_is_who_writes_and_the_old_spellings_say_what_to_write(self):
        for profile in ("novice", "skilled", "foreign"):
            message = self.assert_usage_error(["trial", "十", "--writer", profile], "--writer")
            self.assertIn("who writes (person or simulated)", message)
            self.assertIn(f"the profile is --writer-profile {profile}", message)
        message = self.assert_usage_error(["session", "run", "p.json", "--writer", "human", "--out", "o"],
                                          "--writer")
        self.assertIn("--writer person", message)
        for command in (["train"], ["session", "run"]):
            self.assertIn("--writer person|simulated", self.run_cli(*command, "--help").stdout.decode(), command)
        # trial takes every spelling of the specification's TrialWriter, "auto" (the device's own) too.
        self.assertIn("--writer auto|person|simulated", self.run_cli("trial", "--help").stdout.decode())
        self.assertEqual(self.trial_json("十", "--writer", "auto", "--seed", "1"), self.trial_json("十", "--seed", "1"))
        # The new spellings: the simulated writer with a profile; a person cannot hold the simulated device.
        metrics = self.trial_json("十", "--writer", "simulated", "--writer-profile", "skilled", "--seed", "1")
        self.assertEqual((metrics["writer"], metrics["writer_profile"]), ("simulated", "skilled"))
        self.assertEqual(metrics, self.trial_json("十", "--writer-profile", "skilled", "--seed", "1"))
        for device in ("simulated", "emulated-phantom"):
            message = self.assert_usage_error(["trial", "十", "--device", device, "--writer", "person"], "--writer")
            self.assertIn(f"a person cannot hold the device '{device}'", message)
        protocol = self.write_protocol()
        message = self.assert_usage_error(["session", "run", protocol, "--subject", "S1", "--writer", "person",
                                           "--out", "o"], "--writer person")
        self.assertIn("'simulated'", message)
        self.assertFalse((self.cwd / "o").exists())
        result = self.run_cli("session", "run", protocol, "--writer", "simulated", "--subjects", "1", "--out", "o")
        self.assertEqual(result.returncode, 0, result.stderr.decode())
        (session,) = (self.cwd / "o" / "S01").iterdir()
        self.assertEqual(json.loads((session / "session.json").read_text())["writer"], "simulated")

    def test_a_mistyped_command_is_named_with_the_command_meant(self):
        line = self.last_error_line(["trail", "永"])
        self.assertIn("unknown command 'trail'", line)
        self.assertRegex(line, r"did you mean 'trial'")
        self.assertIn("did you mean 'build'?", self.last_error_line(["corpus", "biuld"]))
        self.assertIn("did you mean 'trial'?", self.last_error_line(["tri", "永"]))  # the one name it begins
        self.assertIn("did you mean 'tick'?", self.last_error_line(["bench", "tik"]))
        far = self.last_error_line(["xyzzy"])  # nothing close: nothing suggested
        self.assertIn("unknown command 'xyzzy'", far)
        self.assertNotIn("did you mean", far)

    def test_a_mistyped_option_is_named_with_the_option_meant(self):
        for args in (["trial", "永", "--guidence", "on"], ["trial", "永", "--guidence=on"]):
            line = self.assert_usage_error(args, "--guidence")
            self.assertIn("unknown option '--guidence'; did you mean '--guidance'?", line)
        # The typo, not the option it left missing, is the error.
        line = self.assert_usage_error(["score", "t.csv", "--charcter", "永"], "--charcter")
        self.assertIn("did you mean '--character'?", line)
        self.assertIn("did you mean '--json'?", self.assert_usage_error(["model", "永", "--jsn"], "--jsn"))
        self.assertIn("did you mean '--version'?", self.last_error_line(["--verison"]))
        far = self.assert_usage_error(["trial", "永", "--zzzzzz"], "--zzzzzz")
        self.assertNotIn("did you mean", far)

    def test_help_says_dir_for_a_folder_and_file_for_a_file(self):
        expected = {
            ("train",): {"--session": "DIR", "--quiz-screenshots": "DIR", "--data": "DIR", "--store": "FILE",
                         "--teacher": "FILE", "--record": "FILE", "--screenshot": "FILE"},
            ("trial",): {"--data": "DIR", "--store": "FILE", "--teacher": "FILE", "--record": "FILE",
                         "--json": "FILE|-", "--csv": "FILE|-", "--svg": "FILE|-"},
            ("session", "run"): {"PROTOCOL": "FILE", "--out": "DIR", "--screenshot": "FILE"},
            ("session", "resume"): {"DIR": "DIR", "--screenshot": "FILE"},
            ("report",): {"DIR": "DIR", "--out": "FILE"},
            ("score",): {"TRACE": "FILE", "--json": "FILE|-"},
            ("corpus", "stats"): {"FILE": "FILE"},
            ("corpus", "build"): {"--out": "FILE", "--data": "DIR"},
            ("corpus", "validate"): {"--cnchar": "FILE", "--data": "DIR", "--features": "FILE"},
        }
        for command, values in expected.items():
            text = self.run_cli(*command, "--help").stdout.decode()
            for name, value in values.items():
                self.assertRegex(text, rf"(?m)^  {re.escape(name)} {re.escape(value)}( |$)", f"{command} {name}")

    def warnings(self, *args, program=(CLI,)):
        """The lines of stderr that warn, of a run that must succeed."""
        result = subprocess.run([*program, *args], cwd=self.cwd, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                                timeout=300)
        self.assertEqual(result.returncode, 0, f"{args}: {result.stderr.decode()}")
        # A tick late on a loaded machine is the servo loop reporting the machine, not a default that warns
        # about itself.
        return [line for line in result.stderr.decode().splitlines()
                if "warn" in line.lower() and "missed its deadline" not in line]

    def test_default_runs_print_no_warning(self):
        protocol = self.write_protocol()
        runs = [
            ["trial", "永", "--csv", "t.csv"], ["score", "t.csv", "--character", "永"], ["model", "永"],
            ["strokes"], ["devices"], ["bench", "tick", "--chars", "永", "--passes", "1"],
            ["bench", "loop", "--seconds", "0.2"], ["bench", "nearest", "--queries", "10"],
            ["session", "run", protocol, "--subject", "S01", "--out", "study"], ["report", "study", "--out", "r.html"],
        ]
        for args in runs:
            self.assertEqual(self.warnings(*args), [], args)

    def test_a_warning_repeated_by_every_trial_of_a_session_is_said_once(self):
        # At 100 Hz the default stiffnesses are above the simulated device's passivity bound, and each trial's
        # renderer says so: the session's standard error says it once (docs/cli.md), a trial alone once too.
        protocol = dict(ONE_TRIAL_PROTOCOL, trial={"max_duration_s": 0.3, "rate_hz": 100})
        protocol["test"] = dict(protocol["test"], characters=["一"], repetitions=3)
        (self.cwd / "p100.json").write_text(json.dumps(protocol, ensure_ascii=False), encoding="utf-8")
        result = self.run_cli("session", "run", "p100.json", "--subject", "S01", "--out", "s100")
        self.assertIn("3 of 3 trials saved", result.stdout.decode(), result.stderr.decode())
        lines = result.stderr.decode().splitlines()
        # The plan's total of three 0.3 s trials is 0.9 s, not the sum's 0.8999999999999999 s.
        self.assertIn("  session 1: 3 trials, at most 0.9 s (0 s of rests)", lines)
        said = [line for line in lines if "passivity bound" in line]
        # The paper's and the guidance's stiffness: two warnings, each said once, not once per trial.
        self.assertEqual(len(said), 2, lines)
        self.assertEqual(len(set(said)), 2, lines)
        for line, stiffness in zip(said, ("paper stiffness", "guidance stiffness")):
            self.assertTrue(line.startswith(f"calligraphy session run: warning: {stiffness} "), line)

    def test_the_emulated_phantom_runs_within_its_stiffness(self):
        # The force law's default paper stiffness (800 N/m) is above the Phantom Omni's stable 700 N/m: the
        # commands cap it at the device's limit instead of warning about their own default.
        protocol = self.write_protocol()
        for args in (["trial", "永", "--device", "emulated-phantom"],
                     ["session", "run", protocol, "--device", "emulated-phantom", "--subject", "S01", "--out", "o"]):
            # The Phantom driver states at every open() what was never checked on hardware (devices module).
            found = [line for line in self.warnings(*args) if "Phantom: NOT verified" not in line]
            self.assertEqual(found, [], args)
        (session,) = (self.cwd / "o" / "S01").iterdir()
        (record,) = (session / "trials").glob("*.json")
        force_law = json.loads(record.read_text(encoding="utf-8"))["force_law"]
        self.assertEqual(force_law["paper_stiffness_n_per_m"], 700.0)

    def test_train_default_run_prints_no_warning(self):
        if not shutil.which("xvfb-run"):
            self.skipTest("xvfb-run is not installed")
        # A usage error that only a build with the window finds (its devices): without it, exit 1 saying so.
        probe = self.run_cli("train", "永", "--writer", "simulated", "--device", "mouse")
        if probe.returncode == 1 and b"without the trainer" in probe.stderr:
            self.skipTest("built without the trainer window")
        self.assertEqual(self.warnings("train", "永", "--exit-after", "1", program=("xvfb-run", "-a", CLI)), [])


if __name__ == "__main__":
    program = unittest.main(exit=False, verbosity=2)
    result = program.result
    sys.exit(0 if result.wasSuccessful() and result.testsRun > 0 else 1)
