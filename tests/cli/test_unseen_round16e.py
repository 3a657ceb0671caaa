#!/usr/bin/env python3
"""Round 16E: hostile cases written from the documentation alone (docs/experiments.md, docs/learning-study.md,
docs/cli.md, docs/metrics.md, docs/python.md and each command's `--help`) on time: every place the program keeps
or reads a time. Session folders' names and session.json's dates, a person's next session before and after its
delay, `previous_session` (`ended_utc`, `elapsed_s`, `delay`), trial records' `start_time_utc`, `end_time_utc`,
`wall_time_s` and `trial_time_s`, the log's `time_utc`, the trace's `t`, the tables' `start_utc`, `session
plan`'s delays, `session resume`, `report`, `calligraphy.study.load`, R. Run by CTest as
`cli_unseen_round16e_tests`.

The process's time zone set to UTC, Asia/Shanghai, America/St_Johns (a half hour), Pacific/Kiritimati (+14),
Europe/London across its change of clocks, and a zone that does not exist: a series begun in one zone goes on,
is refused, resumed and reported in another with the same dates and delays. The wall clock moved by editing
what the docs let an experimenter edit (faketime is not used): a previous session's last trial ended a day and
a minute ago, in the future, on 2028-02-29, in 2038 and 1970, on a day that does not exist, with a zone offset
and without a zone. Durations: `--max-duration` at its bounds, trial times against the trace, whole
nanoseconds, wall time against the record's UTC stamps and the device's clock. A study of a dozen days whose
folders' names sort otherwise than their days, read in session order as the cohort in memory gives it.

Each case asserts what the documentation promises: the exit status, one error line naming the record, the
option or the JSON pointer, ISO 8601 UTC dates that Python and R parse to the same instants, nothing made when
refused, no crash, no hang. A person's session runs in the trainer window on an Xvfb of the round's own
(skipped, saying so, where Xvfb or the window is missing). CALLIGRAPHY_CLI names the program; CALLIGRAPHY_SANITIZED=1
takes five cases.
"""
import csv
import datetime
import json
import os
import re
import shutil
import subprocess
import tempfile
import time
import unittest
from pathlib import Path

from outsider import ENV, OneErrorLine, error_lines, run, sanitized_subset, start_own_x_server

load_tests = sanitized_subset({"test_session_folder_is_named_by_the_utc_second_in_every_zone",
                               "test_a_day_that_does_not_exist_is_refused_naming_the_record",
                               "test_session_plan_is_the_same_in_every_zone",
                               "test_max_duration_at_and_past_its_bounds",
                               "test_a_delay_across_a_change_of_clocks_is_counted_in_utc_seconds"})

ZONES = ("UTC", "Asia/Shanghai", "America/St_Johns", "Pacific/Kiritimati", "Nowhere/Atlantis")
ISO_UTC = re.compile(r"^\d{4}-\d\d-\d\dT\d\d:\d\d:\d\d\.\d{3}Z$")
SHARED = {}
RATE_HZ = 1000
# Two readings of the clock a run makes apart (the series' elapsed time and session.json's created_utc; a
# trial's UTC stamps and its wall time): close, but a loaded machine or a sanitizer may put a pause between
# them. A time zone or a change of clocks misread is 1,800 s or more.
CLOCK_S = 2.0
STAMPS_S = 0.02


def protocol(name, sessions=2, max_duration_s=0.3, delay_s=86400):
    """A protocol of one training trial of 一 in session 1 and one retention trial in each later session."""
    phases = [{"phase": "training", "condition": "fixture", "characters": ["一"]}]
    for number in range(2, sessions + 1):
        phases.append({"phase": "retention", "condition": "unguided", "characters": ["一"], "session": number,
                       "delay_s": delay_s})
    return {"format": "calligraphy-study-protocol", "version": 1, "name": name,
            "conditions": [{"name": "unguided", "mode": "vision"}, {"name": "fixture", "mode": "haptic"}],
            "phases": phases, "trial": {"max_duration_s": max_duration_s, "rate_hz": RATE_HZ}}


def write_json(path, document):
    Path(path).write_text(json.dumps(document, ensure_ascii=False), encoding="utf-8")


def read_json(path):
    return json.loads(Path(path).read_text(encoding="utf-8"))


def instant(text):
    """An ISO 8601 UTC date as the program writes it, as a datetime in UTC."""
    return datetime.datetime.fromisoformat(text.replace("Z", "+00:00"))


def seconds(text):
    return instant(text).timestamp()


def zone_env(zone, display=None):
    env = dict(ENV, TZ=zone)
    if display is not None:
        env["DISPLAY"] = display
    return env


def sessions_of(study, subject):
    """The subject's session folders by session number (session.json's `session_number`)."""
    found = {}
    for folder in (Path(study) / subject).iterdir():
        if folder.is_dir() and not folder.name.startswith("."):
            found[read_json(folder / "session.json").get("session_number", 1)] = folder
    return found


def records(session):
    return sorted(p for p in (Path(session) / "trials").glob("*.json"))


def forge_end(session, value):
    """The session's last trial record with `end_time_utc` set to `value` (text spliced in as JSON)."""
    last = records(session)[-1]
    document = read_json(last)
    document["end_time_utc"] = "@@"
    last.write_text(json.dumps(document, ensure_ascii=False).replace('"@@"', json.dumps(value)),
                    encoding="utf-8")
    return last


def start_xvfb():
    """An X server of the round's own, or None where there is none to start."""
    started = start_own_x_server("800x600x24")
    if started is None:
        return None
    SHARED["xvfb"], display = started
    return display


def setUpModule():  # noqa: N802 - unittest's name
    shared = Path(tempfile.mkdtemp(prefix="calligraphy-unseen16e-"))
    SHARED["dir"] = shared
    write_json(shared / "days.json", protocol("days"))
    write_json(shared / "pdays.json", protocol("pdays", max_duration_s=0.05))
    # A simulated subject's two days run in the zone 14 hours ahead of UTC.
    result = run(["session", "run", shared / "days.json", "--subjects", "1", "--out", "sim"], shared,
                 env=zone_env("Pacific/Kiritimati"))
    if result.returncode != 0:
        raise RuntimeError(result.stderr.decode("utf-8", "replace"))
    SHARED["sim"] = shared / "sim"


def tearDownModule():  # noqa: N802 - unittest's name
    if "xvfb" in SHARED:
        SHARED["xvfb"].terminate()
        SHARED["xvfb"].wait(timeout=10)
    if "dir" in SHARED:
        shutil.rmtree(SHARED["dir"], ignore_errors=True)


def person_study():
    """A person's first session (one trial of 一 in the trainer window, run in Shanghai's zone), made once;
    the case is skipped, saying why, where no window can be shown."""
    if "person" in SHARED:
        return SHARED["person"]
    display = SHARED.get("display") or start_xvfb()
    if display is None:
        raise unittest.SkipTest("no Xvfb: a person's session runs in the trainer window")
    SHARED["display"] = display
    result = run(["session", "run", SHARED["dir"] / "pdays.json", "--subject", "P01", "--device", "mouse-hand",
                  "--exit-after", "60", "--out", "person"], SHARED["dir"], env=zone_env("Asia/Shanghai", display))
    text = result.stderr.decode("utf-8", "replace")
    if result.returncode != 0 and ("trainer" in text or "window" in text):
        raise unittest.SkipTest(f"no trainer window in this build: {error_lines(result)[-1:]}")
    if result.returncode != 0:
        raise RuntimeError(text)
    SHARED["person"] = SHARED["dir"] / "person"
    return SHARED["person"]


class Base(OneErrorLine, unittest.TestCase):
    def setUp(self):
        self.cwd = Path(tempfile.mkdtemp(prefix="case-", dir=SHARED["dir"]))

    def tearDown(self):
        shutil.rmtree(self.cwd, ignore_errors=True)

    def copy(self, study, name="study"):
        self.copies = getattr(self, "copies", 0) + 1
        target = self.cwd / f"{self.copies}-{name}"
        shutil.copytree(study, target, symlinks=True)
        return target

    def first_day_only(self, name="study"):
        """A copy of the simulated study with its second session removed: the next run makes it again."""
        study = self.copy(SHARED["sim"], name)
        shutil.rmtree(sessions_of(study, "S01")[2])
        return study

    def next_day(self, study, zone="UTC", *extra):
        return run(["session", "run", SHARED["dir"] / "days.json", "--subject", "S01", "--writer", "simulated",
                    "--out", study, *extra], self.cwd, env=zone_env(zone))

    def person_next(self, study, zone, *extra):
        # The window's display is checked before the series (docs/cli.md: no display, refused naming DISPLAY).
        return run(["session", "run", SHARED["dir"] / "pdays.json", "--subject", "P01", "--device", "mouse-hand",
                    "--exit-after", "60", "--out", study, *extra], self.cwd, env=zone_env(zone, SHARED["display"]))

    def assert_refusal(self, result, status, *needles):
        """Exit `status` and one error line (after the plan `session run` prints on standard error) naming
        each of `needles`; no traceback, no abort. Returns the line."""
        text = result.stderr.decode("utf-8", "replace")
        self.assertEqual(result.returncode, status, text)
        self.assertNotIn("Traceback", text)
        self.assertNotIn("terminate called", text)
        errors = [line for line in error_lines(result) if "error" in line]
        self.assertEqual(len(errors), 1, f"expected one error line, got {errors!r}")
        for needle in needles:
            self.assertIn(needle, errors[0])
        return errors[0]

    def link_of(self, study, subject="S01", number=2):
        return read_json(sessions_of(study, subject)[number] / "session.json")

    def assert_elapsed_measured(self, study, ended):
        """Session 2's `previous_session` holds `ended` and the UTC seconds from it to its own creation."""
        manifest = self.link_of(study)
        link = manifest["previous_session"]
        self.assertEqual(link["ended_utc"], ended)
        expected = seconds(manifest["created_utc"]) - seconds(ended)
        self.assertAlmostEqual(link["elapsed_s"], expected, delta=CLOCK_S, msg=link)
        # The difference of two clock readings, to the microsecond: never the rounding of two doubles near 1.8e9 s.
        self.assertEqual(link["elapsed_s"], round(link["elapsed_s"], 6), link)
        # A simulated subject's delay is recorded, not waited: `simulated`, or `waited` when it had passed.
        self.assertEqual(link["delay"], "waited" if link["elapsed_s"] >= link["delay_s"] else "simulated", link)
        return link


class Zones(Base):
    """The process's time zone changes no date the program writes or reads."""

    def test_session_folder_is_named_by_the_utc_second_in_every_zone(self):
        # docs/experiments.md: the session id is "the protocol, the subject and the UTC second the session
        # began"; session.json's created_utc is ISO 8601 UTC (calligraphy schema session).
        for zone in ZONES:
            with self.subTest(zone=zone):
                out = self.cwd / zone.replace("/", "-")
                result = run(["session", "run", SHARED["dir"] / "days.json", "--subjects", "1", "--out", out],
                             self.cwd, env=zone_env(zone))
                self.assertEqual(result.returncode, 0, result.stderr.decode())
                for number, folder in sessions_of(out, "S01").items():
                    created = read_json(folder / "session.json")["created_utc"]
                    self.assertRegex(created, ISO_UTC)
                    stamp = re.search(r"-(\d{8}-\d{6})(?:-\d+)?$", folder.name).group(1)
                    named = datetime.datetime.strptime(stamp, "%Y%m%d-%H%M%S").replace(
                        tzinfo=datetime.timezone.utc)
                    began = (instant(created) - named).total_seconds()
                    self.assertGreaterEqual(began, 0, f"{folder.name} is later than {created}")
                    self.assertLess(began, 2, f"{folder.name} is not the UTC second of {created}")

    def test_every_written_date_is_iso_8601_utc_and_now(self):
        # Every date of session.json, the trial records and the log: ISO 8601 in UTC ("Z"), parsed back by
        # Python's datetime, and the instant the run happened (not 14 hours off in Kiritimati's zone).
        now = time.time()
        dates = []
        for folder in sessions_of(SHARED["sim"], "S01").values():
            manifest = read_json(folder / "session.json")
            dates.append(manifest["created_utc"])
            if "previous_session" in manifest:
                dates.append(manifest["previous_session"]["ended_utc"])
            for record in records(folder):
                document = read_json(record)
                dates += [document["start_time_utc"], document["end_time_utc"]]
            for line in (folder / "log.jsonl").read_text(encoding="utf-8").splitlines():
                dates.append(json.loads(line)["time_utc"])
        self.assertGreater(len(dates), 10)
        for text in dates:
            self.assertRegex(text, ISO_UTC)
            self.assertLess(abs(seconds(text) - now), 600, text)

    def test_log_times_never_go_back_and_a_day_follows_the_one_before(self):
        days = sessions_of(SHARED["sim"], "S01")
        for folder in days.values():
            times = [seconds(json.loads(line)["time_utc"])
                     for line in (folder / "log.jsonl").read_text(encoding="utf-8").splitlines()]
            self.assertEqual(times, sorted(times), folder.name)
            created = seconds(read_json(folder / "session.json")["created_utc"])
            for record in records(folder):
                document = read_json(record)
                self.assertLessEqual(created, seconds(document["start_time_utc"]), record.name)
                self.assertLessEqual(seconds(document["start_time_utc"]), seconds(document["end_time_utc"]))
        last = read_json(records(days[1])[-1])
        second = read_json(days[2] / "session.json")
        link = second["previous_session"]
        self.assertEqual(link["session_id"], days[1].name)
        self.assertEqual(link["ended_utc"], last["end_time_utc"])
        self.assertEqual(link["delay"], "simulated")
        self.assertEqual(link["delay_s"], 86400)
        self.assertGreaterEqual(link["elapsed_s"], 0)
        self.assertAlmostEqual(link["elapsed_s"], seconds(second["created_utc"]) - seconds(link["ended_utc"]),
                               delta=CLOCK_S)

    def test_report_tables_are_the_same_in_every_zone(self):
        tables = {}
        for zone in ZONES:
            out = self.cwd / zone.replace("/", "-")
            out.mkdir()
            result = run(["report", SHARED["sim"], "--csv", out], self.cwd, env=zone_env(zone))
            self.assertEqual(result.returncode, 0, result.stderr.decode())
            tables[zone] = (out / "trials.csv").read_bytes()
        self.assertEqual(len(set(tables.values())), 1, "trials.csv differs between time zones")
        rows = list(csv.DictReader(tables["UTC"].decode("utf-8").splitlines()))
        starts = sorted(read_json(r)["start_time_utc"] for f in sessions_of(SHARED["sim"], "S01").values()
                        for r in records(f))
        self.assertEqual(sorted(row["start_utc"] for row in rows), starts)

    def test_report_pages_are_the_same_in_every_zone(self):
        pages = {}
        for zone in ("UTC", "Pacific/Kiritimati", "Nowhere/Atlantis"):
            out = self.cwd / zone.replace("/", "-")
            out.mkdir()
            result = run(["report", SHARED["sim"], "--out", out / "index.html"], self.cwd, env=zone_env(zone))
            self.assertEqual(result.returncode, 0, result.stderr.decode())
            pages[zone] = {p.relative_to(out): p.read_bytes() for p in sorted(out.rglob("*")) if p.is_file()}
        self.assertGreaterEqual(len(pages["UTC"]), 3)
        for zone, files in pages.items():
            self.assertEqual(files, pages["UTC"], zone)

    def test_python_reads_the_same_dates_in_every_zone(self):
        try:
            import calligraphy.study as study
        except ImportError:
            self.skipTest("the calligraphy Python module is not built")
        saved = os.environ.get("TZ")
        read = {}
        try:
            for zone in ZONES:
                os.environ["TZ"] = zone
                time.tzset()
                trials = study.load(SHARED["sim"]).trials
                read[zone] = list(zip(trials["session_number"], trials["start_utc"]))
        finally:
            if saved is None:
                os.environ.pop("TZ", None)
            else:
                os.environ["TZ"] = saved
            time.tzset()
        self.assertEqual(len({tuple(v) for v in read.values()}), 1, read)
        starts = sorted(read_json(r)["start_time_utc"] for f in sessions_of(SHARED["sim"], "S01").values()
                        for r in records(f))
        self.assertEqual(sorted(s for _, s in read["UTC"]), starts)
        import pandas
        parsed = pandas.to_datetime(pandas.Series([s for _, s in read["UTC"]]), utc=True)
        self.assertEqual([p.timestamp() for p in parsed], [seconds(s) for _, s in read["UTC"]])

    def test_r_parses_the_tables_dates_to_the_same_instants(self):
        rscript = shutil.which("Rscript")
        if rscript is None:
            self.skipTest("no Rscript")
        result = run(["report", SHARED["sim"], "--csv", self.cwd], self.cwd)
        self.assertEqual(result.returncode, 0, result.stderr.decode())
        script = ('t <- read.csv(commandArgs(TRUE)[1]); '
                  'p <- as.POSIXct(t$start_utc, format = "%Y-%m-%dT%H:%M:%OSZ", tz = "UTC"); '
                  'stopifnot(!any(is.na(p))); cat(sprintf("%.3f", as.numeric(p)), sep = "\\n")')
        parsed = subprocess.run([rscript, "-e", script, self.cwd / "trials.csv"], capture_output=True,
                                timeout=60, env=dict(ENV, TZ="America/St_Johns"))
        self.assertEqual(parsed.returncode, 0, parsed.stderr.decode())
        rows = list(csv.DictReader((self.cwd / "trials.csv").read_text(encoding="utf-8").splitlines()))
        from_r = [float(v) for v in parsed.stdout.decode().split()]
        self.assertEqual(len(from_r), len(rows))
        for row, value in zip(rows, from_r):
            self.assertAlmostEqual(value, seconds(row["start_utc"]), delta=0.0015, msg=row["start_utc"])

    def test_session_plan_is_the_same_in_every_zone(self):
        plans = set()
        for zone in ZONES:
            result = run(["session", "plan", SHARED["dir"] / "days.json", "--subjects", "1", "--json"], self.cwd,
                         env=zone_env(zone))
            self.assertEqual(result.returncode, 0, result.stderr.decode())
            plans.add(result.stdout)
        self.assertEqual(len(plans), 1)
        document = json.loads(plans.pop())
        self.assertEqual([s["delay_s"] for s in document["subjects"][0]["sessions"]], [0, 86400])

    def test_a_session_resumed_in_another_zone_writes_utc_and_the_same_trial(self):
        study = self.copy(SHARED["sim"])
        second = sessions_of(study, "S01")[2]
        record = records(second)[-1]
        before = read_json(record)
        for path in second.glob("trials/" + record.name[:-len(".json")] + ".*"):
            path.unlink()
        began = time.time()
        # Resumed from inside its folder ("."): a learning subject's memory is rebuilt from the day before,
        # the folder beside it.
        result = run(["session", "resume", "."], second, env=zone_env("America/St_Johns"))
        self.assertEqual(result.returncode, 0, result.stderr.decode())
        after = read_json(record)
        for key in ("start_time_utc", "end_time_utc"):
            self.assertRegex(after[key], ISO_UTC)
            self.assertGreaterEqual(seconds(after[key]), began - 1, key)
            self.assertLessEqual(seconds(after[key]), time.time() + 1, key)
        for key in ("mean_deviation_m", "samples", "trial_time_s", "total_time_s"):
            self.assertEqual(after[key], before[key], key)
        self.assertEqual(after["files"]["trace_sha256"], before["files"]["trace_sha256"])
        events = [json.loads(line) for line in (second / "log.jsonl").read_text(encoding="utf-8").splitlines()]
        # No trial of it was saved: the resume starts it again from its first (docs/experiments.md).
        started = [e for e in events if e["event"] == "session_started"]
        self.assertEqual([e["saved_trials"] for e in started], [0, 0])
        self.assertGreaterEqual(seconds(started[-1]["time_utc"]), began - 1)
        self.assertEqual(after["session"], second.name)


class MovedClock(Base):
    """A previous session's end as an experimenter may find it edited: the delay is counted in UTC seconds."""

    def test_a_delay_across_a_change_of_clocks_is_counted_in_utc_seconds(self):
        # Europe/London's clocks went back at 01:00 UTC on 2026-10-25; St John's at 04:30 UTC on 2026-11-01.
        for zone, ended in (("Europe/London", "2026-10-25T00:30:00.000Z"),
                            ("America/St_Johns", "2026-11-01T03:45:00.000Z"),
                            ("Pacific/Kiritimati", "2026-03-08T06:59:59.999Z")):
            with self.subTest(zone=zone):
                study = self.first_day_only(zone.replace("/", "-"))
                forge_end(sessions_of(study, "S01")[1], ended)
                result = self.next_day(study, zone)
                self.assertEqual(result.returncode, 0, result.stderr.decode())
                self.assert_elapsed_measured(study, ended)

    def test_leap_day_2028_and_the_years_2038_and_1970(self):
        for ended in ("2028-02-29T12:00:00.000Z", "2038-01-19T03:14:08.000Z", "1970-01-01T00:00:00.000Z",
                      "1969-12-31T23:59:59.000Z"):
            with self.subTest(ended=ended):
                study = self.first_day_only(ended[:4])
                forge_end(sessions_of(study, "S01")[1], ended)
                result = self.next_day(study, "Asia/Shanghai")
                self.assertEqual(result.returncode, 0, result.stderr.decode())
                self.assert_elapsed_measured(study, ended)
                read = run(["report", study, "--csv", self.cwd], self.cwd)
                self.assertEqual(read.returncode, 0, read.stderr.decode())

    def test_a_day_that_does_not_exist_is_refused_naming_the_record(self):
        for ended in ("2027-02-29T12:00:00.000Z", "2026-04-31T12:00:00.000Z", "2026-13-01T00:00:00.000Z",
                      "2026-11-28T24:00:01.000Z", "2026-11-28T12:60:00.000Z", "2026-11-28T12:00:61.000Z",
                      "2026-00-10T00:00:00.000Z", "2026-11-00T00:00:00.000Z"):
            with self.subTest(ended=ended):
                study = self.first_day_only(ended[:10])
                last = forge_end(sessions_of(study, "S01")[1], ended)
                result = self.next_day(study)
                self.assert_refusal(result, 1, last.name, "/end_time_utc")
                self.assertEqual(list(sessions_of(study, "S01")), [1])

    def test_an_end_with_a_zone_offset_is_that_instant_or_refused_alike_in_every_zone(self):
        # ISO 8601 allows an offset: read as the instant it names, or refused naming the field, never read
        # as UTC with the offset dropped, and the same in every zone of the reader.
        for ended, utc in (("2026-11-27T09:30:00.000+08:00", "2026-11-27T01:30:00.000Z"),
                           ("2026-11-26T22:00:00.000-03:30", "2026-11-27T01:30:00.000Z"),
                           ("2026-11-27T01:30:00.000", "2026-11-27T01:30:00.000Z"),
                           ("2026-11-27T01:30:00Z", "2026-11-27T01:30:00.000Z"),
                           ("2026-11-27 01:30:00.000Z", "2026-11-27T01:30:00.000Z")):
            outcomes = set()
            for zone in ("UTC", "Pacific/Kiritimati"):
                with self.subTest(ended=ended, zone=zone):
                    study = self.first_day_only(f"{len(outcomes)}-{zone.replace('/', '-')}")
                    last = forge_end(sessions_of(study, "S01")[1], ended)
                    result = self.next_day(study, zone)
                    if result.returncode == 0:
                        manifest = self.link_of(study)
                        elapsed = manifest["previous_session"]["elapsed_s"]
                        self.assertAlmostEqual(elapsed, seconds(manifest["created_utc"]) - seconds(utc), delta=CLOCK_S)
                        outcomes.add("read")
                    else:
                        self.assert_refusal(result, 1, last.name, "/end_time_utc")
                        outcomes.add("refused")
            self.assertEqual(len(outcomes), 1, f"{ended}: read in one zone, refused in another")

    def test_the_same_trial_whatever_the_dates_say(self):
        # A simulated subject's delay is recorded, not waited (docs/experiments.md): its second day is the same
        # trial whether the first ended a minute, 56 years before, or 12 years after.
        original = read_json(records(sessions_of(SHARED["sim"], "S01")[2])[-1])
        for ended in ("1970-01-01T00:00:00.000Z", "2038-01-19T03:14:08.000Z"):
            with self.subTest(ended=ended):
                study = self.first_day_only(ended[:4])
                forge_end(sessions_of(study, "S01")[1], ended)
                result = self.next_day(study, "America/St_Johns")
                self.assertEqual(result.returncode, 0, result.stderr.decode())
                again = read_json(records(sessions_of(study, "S01")[2])[-1])
                for key in ("mean_deviation_m", "samples", "trial_time_s", "total_time_s", "end_reason"):
                    self.assertEqual(again[key], original[key], key)
                self.assertEqual(again["files"]["trace_sha256"], original["files"]["trace_sha256"])

    def test_a_session_manifest_date_that_is_no_date_is_refused_naming_its_pointer(self):
        # session.json is read strictly (docs/experiments.md): created_utc and ended_utc are "ISO 8601, UTC"
        # (calligraphy schema session); a value out of its range is refused naming the file and the pointer.
        for pointer, wrong in (("/created_utc", "yesterday"), ("/created_utc", "2027-02-29T12:00:00.000Z"),
                               ("/previous_session/ended_utc", "28/11/2026 01:45"),
                               ("/previous_session/ended_utc", "")):
            with self.subTest(pointer=pointer, wrong=wrong):
                study = self.copy(SHARED["sim"], f"m{len(list(self.cwd.iterdir()))}")
                manifest = sessions_of(study, "S01")[2] / "session.json"
                document = read_json(manifest)
                if pointer == "/created_utc":
                    document["created_utc"] = wrong
                else:
                    document["previous_session"]["ended_utc"] = wrong
                write_json(manifest, document)
                result = run(["report", study, "--csv", self.cwd], self.cwd)
                self.assert_one_error(result, 1, "session.json", pointer)


class Person(Base):
    """A person's next session against the wall clock, in the trainer window on the round's X server."""

    def test_before_its_delay_a_person_is_refused_naming_the_utc_end_and_the_seconds_left_in_any_zone(self):
        study = self.copy(person_study())
        first = sessions_of(study, "P01")[1]
        ended = read_json(records(first)[-1])["end_time_utc"]
        for zone in ("America/St_Johns", "Pacific/Kiritimati", "Nowhere/Atlantis"):
            with self.subTest(zone=zone):
                result = self.person_next(study, zone)
                now = time.time()
                line = self.assert_refusal(result, 1, ended, "--ignore-delay")
                left = 86400 - (now - seconds(ended))
                numbers = [int(n) for n in re.findall(r"(\d+) s\b", line)]
                self.assertTrue(any(abs(n - left) <= 3 for n in numbers), f"{line!r}: {left:.0f} s left")
                self.assertEqual(list(sessions_of(study, "P01")), [1])

    def test_a_series_begun_in_shanghai_goes_on_in_st_johns_once_a_day_has_passed(self):
        study = self.copy(person_study())
        ended = datetime.datetime.now(datetime.timezone.utc) - datetime.timedelta(seconds=86460)
        text = ended.strftime("%Y-%m-%dT%H:%M:%S.") + f"{ended.microsecond // 1000:03d}Z"
        forge_end(sessions_of(study, "P01")[1], text)
        result = self.person_next(study, "America/St_Johns")
        self.assertEqual(result.returncode, 0, result.stderr.decode())
        manifest = self.link_of(study, "P01")
        link = manifest["previous_session"]
        self.assertEqual((link["ended_utc"], link["delay"], link["delay_s"]), (text, "waited", 86400))
        self.assertAlmostEqual(link["elapsed_s"], seconds(manifest["created_utc"]) - seconds(text), delta=CLOCK_S)
        self.assertGreater(link["elapsed_s"], 86400)

    def test_a_person_after_a_session_ending_in_2038_is_refused_naming_the_record(self):
        study = self.copy(person_study())
        last = forge_end(sessions_of(study, "P01")[1], "2038-01-19T03:14:08.000Z")
        result = self.person_next(study, "Pacific/Kiritimati")
        self.assert_refusal(result, 1, last.name, "2038-01-19T03:14:08.000Z")
        self.assertEqual(list(sessions_of(study, "P01")), [1])

    def test_ignore_delay_records_overridden_and_the_measured_negative_elapsed(self):
        study = self.copy(person_study())
        forge_end(sessions_of(study, "P01")[1], "2028-02-29T12:00:00.000Z")
        result = self.person_next(study, "Asia/Shanghai", "--ignore-delay")
        self.assertEqual(result.returncode, 0, result.stderr.decode())
        manifest = self.link_of(study, "P01")
        link = manifest["previous_session"]
        self.assertEqual((link["ended_utc"], link["delay"]), ("2028-02-29T12:00:00.000Z", "overridden"))
        self.assertAlmostEqual(link["elapsed_s"], seconds(manifest["created_utc"]) - seconds(link["ended_utc"]),
                               delta=CLOCK_S)
        self.assertLess(link["elapsed_s"], 0)

    def test_a_persons_trial_lasts_its_device_time_in_wall_time_and_utc_stamps(self):
        # Real time: the device's clock and the wall clock agree; the record's UTC stamps bracket the trial.
        session = sessions_of(person_study(), "P01")[1]
        document = read_json(records(session)[-1])
        self.assertLessEqual(document["trial_time_s"], 0.05 + 1.0 / RATE_HZ)
        self.assertAlmostEqual(document["wall_time_s"], document["trial_time_s"], delta=0.05)
        span = seconds(document["end_time_utc"]) - seconds(document["start_time_utc"])
        self.assertAlmostEqual(span, document["wall_time_s"], delta=STAMPS_S)


class Durations(Base):
    def test_max_duration_at_and_past_its_bounds(self):
        # docs/cli.md: --max-duration in (0, 86400] s, at most 10^7 servo ticks (--max-duration x --rate); a
        # trial the time limit ends exits 1 with its outputs written.
        for value, rate in (("0", "1000"), ("86400.001", "100"), ("86400", "1000"), ("10000.001", "1000")):
            with self.subTest(value=value, rate=rate):
                result = run(["trial", "一", "--max-duration", value, "--rate", rate, "--json", "-"], self.cwd)
                self.assert_one_error(result, 2, "--max-duration")
                self.assertEqual(result.stdout, b"")
        for value, rate, status in (("86400", "100", 0), ("10000", "1000", 0), ("0.001", "1000", 1),
                                    ("1e-12", "1000", 1)):
            with self.subTest(value=value, rate=rate):
                result = run(["trial", "一", "--max-duration", value, "--rate", rate, "--json", "-"], self.cwd)
                self.assertEqual(result.returncode, status, result.stderr.decode())
                document = json.loads(result.stdout)
                self.assertEqual(document["end_reason"], "completed" if status == 0 else "time_limit")
                self.assertLessEqual(document["trial_time_s"], max(float(value), 1.0 / int(rate)) + 1e-12)
                if status:
                    self.assert_one_error(result, 1, "time_limit")

    def test_exit_after_at_and_past_its_bounds(self):
        # docs/cli.md: --exit-after in (0, 86400] s, a usage error (2) past it, before any folder is made.
        for value in ("0", "-1", "86400.001", "nan"):
            with self.subTest(value=value):
                result = run(["session", "run", SHARED["dir"] / "pdays.json", "--subject", "P01", "--device",
                              "mouse-hand", "--exit-after", value, "--out", "study"], self.cwd)
                self.assert_one_error(result, 2, "--exit-after")
                self.assertFalse((self.cwd / "study").exists())

    def test_a_trace_never_goes_back_and_the_record_is_its_time(self):
        import h5py
        for folder in sessions_of(SHARED["sim"], "S01").values():
            for record in records(folder):
                document = read_json(record)
                with h5py.File(folder / "trials" / document["files"]["trace"]) as trace:
                    t = trace["t"][()].astype("int64")
                    decimals = int(trace["t"].attrs["decimals"])
                    unit = trace["t"].attrs["unit"]
                self.assertEqual(unit.decode() if isinstance(unit, bytes) else str(unit), "s")
                steps = set((t[1:] - t[:-1]).tolist())
                self.assertEqual(steps, {10 ** decimals // RATE_HZ}, record.name)
                self.assertEqual(len(t), document["samples"])
                last = t[-1] / 10 ** decimals
                self.assertLessEqual(last, 0.3 + 1e-9)
                self.assertAlmostEqual(document["trial_time_s"], last, delta=1.0 / RATE_HZ + 1e-9)
                for stroke in document["per_stroke"]:
                    if stroke.get("start_s") is not None:
                        self.assertLessEqual(t[0] / 10 ** decimals, stroke["start_s"])
                        self.assertLessEqual(stroke["start_s"], stroke["end_s"])
                        self.assertLessEqual(stroke["end_s"], last)

    def test_lock_step_wall_time_is_the_utc_stamps_and_not_the_device_time(self):
        # A simulated writer runs lock-step: the device's clock (trial_time_s, the trace) is not the wall clock
        # (wall_time_s), which the record's UTC stamps bracket to their millisecond.
        for folder in sessions_of(SHARED["sim"], "S01").values():
            for record in records(folder):
                document = read_json(record)
                span = seconds(document["end_time_utc"]) - seconds(document["start_time_utc"])
                self.assertGreaterEqual(document["wall_time_s"], 0)
                self.assertAlmostEqual(span, document["wall_time_s"], delta=STAMPS_S, msg=record.name)
                self.assertAlmostEqual(document["trial_time_s"], 0.3, delta=1.0 / RATE_HZ + 1e-9)

    def test_times_are_whole_nanoseconds(self):
        # docs/metrics.md: total_time_s, pen_down_time_s and each stroke's time_s are rounded to whole
        # nanoseconds.
        result = run(["trial", "一", "--max-duration", "10", "--json", "-"], self.cwd)
        self.assertEqual(result.returncode, 0, result.stderr.decode())
        document = json.loads(result.stdout)
        values = [document["total_time_s"], document["pen_down_time_s"]]
        for character in document.get("per_character", []):
            values += [s["time_s"] for s in character["per_stroke"] if s.get("time_s") is not None]
        self.assertGreaterEqual(len(values), 3, document.keys())
        for value in values:
            self.assertAlmostEqual(value * 1e9, round(value * 1e9), delta=1e-3, msg=value)

    def test_a_dozen_days_are_read_in_session_order_not_by_folder_name(self):
        # Twelve sessions of one simulated subject made in one second: ...-2 to ...-12, whose names do not
        # sort by day. The tables read them in session order, as the cohort in memory gives them (docs/cli.md,
        # "session cohort": the tables report --csv writes, but for session, start_utc and trace_file).
        write_json(self.cwd / "weeks.json", protocol("weeks", sessions=12, max_duration_s=0.05, delay_s=7 * 86400))
        result = run(["session", "run", "weeks.json", "--subjects", "1", "--out", "study"], self.cwd)
        self.assertEqual(result.returncode, 0, result.stderr.decode())
        self.assertEqual(sorted(sessions_of(self.cwd / "study", "S01")), list(range(1, 13)))
        for out in ("report", "cohort"):
            (self.cwd / out).mkdir()
        result = run(["report", "study", "--csv", "report"], self.cwd)
        self.assertEqual(result.returncode, 0, result.stderr.decode())
        result = run(["session", "cohort", "weeks.json", "--subjects", "1", "--csv", "cohort"], self.cwd)
        self.assertEqual(result.returncode, 0, result.stderr.decode())
        tables = {}
        for out in ("report", "cohort"):
            rows = list(csv.DictReader((self.cwd / out / "trials.csv").read_text(encoding="utf-8").splitlines()))
            tables[out] = [{k: v for k, v in row.items()
                            if k not in ("session", "start_utc", "trace_file", "trace_sha256")} for row in rows]
        self.assertEqual([r["session_number"] for r in tables["report"]], [str(n) for n in range(1, 13)])
        self.assertEqual(tables["report"], tables["cohort"])


if __name__ == "__main__":
    unittest.main()
