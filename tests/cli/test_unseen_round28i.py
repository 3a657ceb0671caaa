#!/usr/bin/env python3
"""Round 28I: a study's report read as a reviewer reads it. From the docs alone (docs/experiments.md "A report
for a paper", "Tidy tables", "The per-trial pages", "A cohort in memory"; docs/cli.md `report`, `session run`,
`session cohort`; docs/learning-study.md; docs/python.md `calligraphy.study`, `design_analysis`,
`study_report`; `help(calligraphy.study_report)`).

A small within-subjects study made with `session run` and the simulated writer: 4 subjects, the conditions
`vision` and `haptic` in a Latin square, 十 written twice in each, trials of at most 10 s, so that some end at
the time limit and are excluded (one subject keeps no `vision` trial at all). Its tidy tables
(`calligraphy report --csv`), its per-trial pages (`report --out`) and its study report
(`calligraphy.study_report`, with R made unavailable by PATH, as the docs say what the page then says) are
held to what the test computes itself from trials.csv with the standard library: counts of subjects and
trials per condition, exclusions by end reason, means and SDs over subjects in the tables' SI units and the
page's mm and s, the Cousineau-Morey interval, the paired t on subject means (Student's t computed here), the
Table-5 cells, the links to each trial's article and the per-trial values. Then the study changes: a subject
added with `--new-subjects`, a session removed, the folders given in another order, a cohort in memory; the
report goes into a folder holding an older report, into one where a file of the report is a session's, and is
made with no trial analysed (`keep_end_reasons` naming an end no trial had).

CALLIGRAPHY_CLI names the program; PYTHONPATH the built Python package. CALLIGRAPHY_SANITIZED=1 takes five cases.
"""
import csv
import hashlib
import html
import math
import os
import re
import shutil
import statistics
import struct
import subprocess
import sys
import tempfile
import unittest
import zlib
from pathlib import Path

from outsider import OneErrorLine, run_ok, sanitized_subset

try:
    import calligraphy.study as cstudy
    import calligraphy.study_report as creport
except ImportError:  # reported by setUpClass: the study report is the package's
    cstudy = creport = None

load_tests = sanitized_subset({"test_tables_hold_every_planned_trial_and_each_reference_stroke",
                               "test_page_header_counts_subjects_sessions_trials_and_those_analysed",
                               "test_exclusions_count_each_end_reason_by_phase_and_condition",
                               "test_every_trial_links_to_its_own_article_on_the_per_trial_page",
                               "test_tables_are_the_same_bytes_whatever_the_order_of_the_folders"})

VALUES = ("total_time_s", "mean_deviation_m")
CONDITIONS = ("vision", "haptic")          # vision: the control (the condition in `vision` mode)
PROTOCOL = """{"name": "rev", "conditions": [{"name": "vision", "mode": "vision"}, {"name": "haptic", "mode": "haptic"}],
 "test": {"characters": ["十"], "conditions": ["vision", "haptic"], "repetitions": 2},
 "order": {"conditions": "latin_square"}, "trial": {"max_duration_s": 10}}
"""
REPORT_FILES = {"index.html", "tables/phase_means.csv", "tables/questions.csv", "tables/exclusions.csv",
                "tables/summary.csv", "tables/statistics.csv"} | {
    f"figures/{kind}_{value}.{ext}" for kind in ("phase", "learning") for value in VALUES for ext in ("svg", "png")}
OLDER_REPORT = {"index.html": "<p>an older report</p>", "tables/phase_means.csv": "older\n",
                "figures/phase_total_time_s.svg": "<svg/>"}


def t_two_sided_p(t, df):
    """Two-sided p of Student's t with a whole number of degrees of freedom (Abramowitz & Stegun 26.7.3-4)."""
    theta = math.atan(abs(t) / math.sqrt(df))
    c2, s = math.cos(theta) ** 2, math.sin(theta)
    term, total = 1.0, 1.0
    if df % 2:
        for k in range(1, (df - 1) // 2):
            term *= c2 * (2 * k) / (2 * k + 1)
            total += term
        return 1.0 - 2 / math.pi * (theta + (s * math.cos(theta) * total if df > 1 else 0.0))
    for k in range(1, df // 2):
        term *= c2 * (2 * k - 1) / (2 * k)
        total += term
    return 1.0 - s * total


def t_975(df):
    """The 97.5 % quantile of Student's t by bisection of t_two_sided_p."""
    lo, hi = 0.0, 100.0
    for _ in range(200):
        mid = (lo + hi) / 2
        lo, hi = (mid, hi) if t_two_sided_p(mid, df) > 0.05 else (lo, mid)
    return (lo + hi) / 2


def sessions_only(folder, names):
    """copytree's `ignore`: a study folder's session folders only, not the pages or the report made in it."""
    return {"paper", "trials.html", "trials_files"} & set(names) if Path(folder).name == "study" else set()


def read_csv(path):
    with open(path, encoding="utf-8", newline="") as f:
        return list(csv.DictReader(f))


def tree_digest(root, skip=()):
    """{relative path: SHA-256} of every file under `root`, the top-level names in `skip` left out."""
    found = {}
    for path in sorted(Path(root).rglob("*")):
        rel = path.relative_to(root)
        if rel.parts[0] in skip or not path.is_file():
            continue
        found[rel.as_posix()] = hashlib.sha256(path.read_bytes()).hexdigest()
    return found


def subject_means(rows, value, analysed=("completed",)):
    """{(subject, condition): mean of the subject's analysed trials}: each subject's trials averaged first."""
    cells = {}
    for r in rows:
        if analysed is None or r["end_reason"] in analysed:
            cells.setdefault((r["subject"], r["condition"]), []).append(float(r[value]))
    return {k: statistics.fmean(v) for k, v in cells.items()}


def table_bodies(page, css_class, value):
    """The body rows (HTML text) of the page's <table class=css_class data-value=value>."""
    found = re.search(rf'<table class="{css_class}"[^>]*data-value="{value}".*?</table>', page, re.S)
    if found is None:
        return None
    body = re.search(r"<tbody>(.*?)</tbody>", found.group(0), re.S)
    return re.findall(r"<tr[ >].*?</tr>", body.group(1), re.S) if body else []


def cells(row):
    return [html.unescape(re.sub(r"<[^>]+>", "", c)).strip()
            for c in re.findall(r"<t[dh][^>]*>(.*?)</t[dh]>", row, re.S)]


def png_dpi(path):
    """The PNG's pHYs resolution in dots per inch (x, y), or None without one; the file's CRCs checked."""
    data = Path(path).read_bytes()
    assert data[:8] == b"\x89PNG\r\n\x1a\n", path
    at, dpi = 8, None
    while at < len(data):
        length, kind = struct.unpack(">I4s", data[at:at + 8])
        chunk = data[at + 8:at + 8 + length]
        crc, = struct.unpack(">I", data[at + 8 + length:at + 12 + length])
        assert zlib.crc32(kind + chunk) == crc, f"{path}: bad CRC in {kind!r}"
        if kind == b"pHYs":
            x, y, unit = struct.unpack(">IIB", chunk)
            if unit == 1:
                dpi = (x * 0.0254, y * 0.0254)
        at += 12 + length
    return dpi


class Round28I(unittest.TestCase, OneErrorLine):
    @classmethod
    def setUpClass(cls):
        if cstudy is None:
            raise unittest.SkipTest("the calligraphy Python package (PYTHONPATH) is needed")
        cls.tmp = Path(tempfile.mkdtemp(prefix="round28i-"))
        d = cls.tmp
        (d / "p.json").write_text(PROTOCOL, encoding="utf-8")
        run_ok(["session", "run", "p.json", "--writer", "simulated", "--subjects", "4", "--out", "study"], d)
        (d / "tables").mkdir()
        run_ok(["report", "study", "--csv", "tables", "--out", "study/trials.html"], d)
        cls.trials = read_csv(d / "tables/trials.csv")
        cls.strokes = read_csv(d / "tables/strokes.csv")
        cls.sessions_before = tree_digest(d / "study", skip=("paper", "trials.html", "trials_files"))
        cls.pages_before = tree_digest(d / "study", skip=("S01", "S02", "S03", "S04", "paper"))
        # An older report in the folder the new one goes to.
        cls.paper = d / "study" / "paper"
        for name, text in OLDER_REPORT.items():
            (cls.paper / name).parent.mkdir(parents=True, exist_ok=True)
            (cls.paper / name).write_text(text, encoding="utf-8")
        # R made unavailable: the page says what it then says; nothing else of the report needs a program.
        (d / "bin").mkdir()
        saved_path = os.environ.get("PATH", "")
        os.environ["PATH"] = str(d / "bin")
        try:
            cls.study = cstudy.load(str(d / "study"))
            cls.index = creport.write_report(cls.study, str(cls.paper), per_trial_page=str(d / "study/trials.html"))
            cls.none_index = creport.write_report(cls.study, str(d / "none"), keep_end_reasons=("interrupted",))
        finally:
            os.environ["PATH"] = saved_path
        cls.page = Path(cls.index).read_text(encoding="utf-8")
        cls.phase_means = read_csv(cls.paper / "tables/phase_means.csv")
        cls.questions = read_csv(cls.paper / "tables/questions.csv")
        cls.summary = read_csv(cls.paper / "tables/summary.csv")

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.tmp, ignore_errors=True)

    def completed(self):
        return [r for r in self.trials if r["end_reason"] == "completed"]

    def python_report(self, *args):
        env = dict(os.environ, PATH=str(self.tmp / "bin"))
        return subprocess.run([sys.executable, "-m", "calligraphy.study_report", *args], cwd=self.tmp, env=env,
                              stdout=subprocess.PIPE, stderr=subprocess.PIPE, stdin=subprocess.DEVNULL, timeout=120)

    # The tidy tables

    def test_tables_hold_every_planned_trial_and_each_reference_stroke(self):
        # docs/experiments.md "Tidy tables": one row per saved trial; strokes.csv one row per reference stroke.
        self.assertEqual(len(self.trials), 16)
        self.assertEqual(sorted({r["subject"] for r in self.trials}), ["S01", "S02", "S03", "S04"])
        for c in CONDITIONS:
            self.assertEqual(sum(r["condition"] == c for r in self.trials), 8, c)
        self.assertEqual(len(self.strokes), 32)           # 十: two strokes a trial
        by_trial = {}
        for s in self.strokes:
            self.assertEqual(s["character_text"], "十")
            by_trial.setdefault((s["session"], s["trial"]), []).append(s["stroke"])
        self.assertEqual(sorted(by_trial), sorted((r["session"], r["trial"]) for r in self.trials))
        for strokes in by_trial.values():
            self.assertEqual(sorted(strokes), ["1", "2"])
        self.assertTrue(any(r["end_reason"] == "time_limit" for r in self.trials),
                        "the 10 s limit is meant to end some trials")

    def test_tables_give_lengths_in_metres_and_the_report_tables_name_their_unit(self):
        # "Lengths are in m and times in s, the unit in the column's name"; the report's tables "in SI units
        # (m, s) with a `unit` column on every long-format table".
        for r in self.trials:
            self.assertLess(1e-5, float(r["mean_deviation_m"]), r["trial"])
            self.assertLess(float(r["mean_deviation_m"]), 0.01, r["trial"])   # a 6 cm character: never 1 cm
            self.assertLess(float(r["pen_down_time_s"]), float(r["total_time_s"]) + 1e-12)
        for table in (self.phase_means, self.questions, self.summary):
            for row in table:
                value = row.get("value") or row.get("quantity")
                self.assertEqual(row["unit"], {"mean_deviation_m": "m", "total_time_s": "s"}[value], row)

    def test_tables_are_the_same_bytes_whatever_the_order_of_the_folders(self):
        # docs/cli.md `report`: "the same folders give the same tables byte for byte whatever the order the
        # DIRs are given in".
        d = self.tmp
        folders = sorted(p.name for p in (d / "study").iterdir() if p.name.startswith("S"))
        for name, order in (("fwd", folders), ("rev", folders[::-1])):
            (d / name).mkdir()
            run_ok(["report", *[f"study/{f}" for f in order], "--csv", name], d)
        for table in ("trials.csv", "strokes.csv"):
            self.assertEqual((d / "fwd" / table).read_bytes(), (d / "rev" / table).read_bytes(), table)
        self.assertEqual((d / "fwd/trials.csv").read_bytes(), (d / "tables/trials.csv").read_bytes())

    def test_added_subject_adds_rows_and_continues_the_latin_square(self):
        # `--new-subjects` "runs N new subjects numbered after the highest number ... so that counterbalancing
        # goes on where it stopped"; Latin square rows: subject n gets row (n - 1) mod rows.
        d = self.tmp / "added"
        shutil.copytree(self.tmp / "study", d / "study", ignore=sessions_only)
        shutil.copy(self.tmp / "p.json", d / "p.json")
        run_ok(["session", "run", "p.json", "--writer", "simulated", "--subjects", "1", "--new-subjects",
                "--out", "study"], d)
        (d / "tables").mkdir()
        run_ok(["report", "study", "--csv", "tables"], d)
        rows = read_csv(d / "tables/trials.csv")
        self.assertEqual(len(rows), 20)
        self.assertEqual([r for r in rows if r["subject"] != "S05"], self.trials)
        order = {s: [r["condition"] for r in rows if r["subject"] == s] for s in ("S01", "S02", "S05")}
        self.assertEqual(order["S05"], order["S01"])
        self.assertNotEqual(order["S05"], order["S02"])

    def test_removed_session_drops_its_rows_and_leaves_its_page_as_it_was(self):
        # docs/cli.md `report --out`: "pages of sessions no longer under the DIRs are left as they were".
        d = self.tmp / "removed"
        shutil.copytree(self.tmp / "study", d / "study", ignore=sessions_only)
        run_ok(["report", "study", "--out", "study/trials.html"], d)
        s04 = next((d / "study/trials_files/S04").glob("*.html"))
        page_before = s04.read_bytes()
        shutil.move(str(d / "study/S04"), str(d / "S04-away"))
        (d / "tables").mkdir()
        run_ok(["report", "study", "--out", "study/trials.html", "--csv", "tables"], d)
        self.assertEqual(s04.read_bytes(), page_before)
        index = (d / "study/trials.html").read_text(encoding="utf-8")
        self.assertNotIn("S04/", index)
        self.assertEqual(read_csv(d / "tables/trials.csv"), [r for r in self.trials if r["subject"] != "S04"])

    def test_cohort_rows_are_the_session_folders_but_session_start_and_trace(self):
        # docs/cli.md `session cohort`: "DIR/trials.csv and DIR/strokes.csv are the tables `report --csv`
        # would write for those folders, except `session` (`PROTOCOL-SUBJECT-sN`), an empty `start_utc` and
        # no trace (`trace_file` and `trace_sha256` empty)".
        d = self.tmp
        (d / "cohort").mkdir()
        run_ok(["session", "cohort", "p.json", "--subjects", "1", "--csv", "cohort", "--jobs", "1"], d)
        rows = read_csv(d / "cohort/trials.csv")
        mine = [r for r in self.trials if r["subject"] == "S01"]
        self.assertEqual(len(rows), len(mine))
        for got, want in zip(rows, mine):
            self.assertEqual(got["session"], "rev-S01-s1")
            for key in ("start_utc", "trace_file", "trace_sha256"):
                self.assertEqual(got[key], "", key)
            same = [k for k in want if k not in ("session", "start_utc", "trace_file", "trace_sha256")]
            self.assertEqual({k: got[k] for k in same}, {k: want[k] for k in same})
        strokes = read_csv(d / "cohort/strokes.csv")
        self.assertEqual([{**s, "session": ""} for s in strokes],
                         [{**s, "session": ""} for s in self.strokes if s["subject"] == "S01"])

    # The study report: header, exclusions, means

    def test_page_header_counts_subjects_sessions_trials_and_those_analysed(self):
        # "a header: protocols, subjects, sessions, trials; ... the completion count (trials analysed of all".
        self.assertIn("4 subjects &middot; 4 sessions &middot; 16 trials", self.page)
        kept = len(self.completed())
        self.assertIn(f"Completion: {kept} of 16 trials analysed", self.page)
        self.assertIn("simulated", self.page)
        self.assertIn("novice", self.page)        # "simulated with their profile and learning model"
        self.assertIn("two-state", self.page)

    def test_exclusions_count_each_end_reason_by_phase_and_condition(self):
        # "Excluded trials are counted by phase and group on the page and in `tables/exclusions.csv`".
        rows = read_csv(self.paper / "tables/exclusions.csv")
        key = "group" if "group" in rows[0] else "condition"
        got = {(r["phase"], r[key]): r for r in rows}
        self.assertEqual(sorted(got), [("test", "haptic"), ("test", "vision")])
        for c in CONDITIONS:
            mine = [r for r in self.trials if r["condition"] == c]
            row = got[("test", c)]
            self.assertEqual(int(row["trials"]), len(mine))
            self.assertEqual(int(row["kept"]), sum(r["end_reason"] == "completed" for r in mine))
            self.assertEqual(int(row["excluded_time_limit"]), sum(r["end_reason"] == "time_limit" for r in mine))

    def test_exclusions_table_has_the_documented_columns(self):
        # First run: a finding (the docs listed a `group` column, the table of this study without groups has
        # `condition`). docs/experiments.md now says: "`phase`, `group` (`condition` in a design without
        # groups), `trials`, `kept`, `excluded_<end_reason>`".
        with open(self.paper / "tables/exclusions.csv", encoding="utf-8") as f:
            header = f.readline().strip().split(",")
        self.assertEqual(header[:4], ["phase", "condition", "trials", "kept"])
        self.assertTrue(all(h.startswith("excluded_") for h in header[4:]), header)

    def test_means_over_subjects_count_the_subjects_their_definition_names(self):
        # "each subject's analysed trials are averaged first, the SD is over subjects, and n counts subjects".
        # First run: a finding (phase_means.csv gave haptic over 3 subjects where summary.csv gave it over 4,
        # and the docs said only "over subjects"). docs/experiments.md now says: within subjects the means by
        # phase are "over the subjects with analysed trials in every condition of the phase ... (n says how
        # many; the Table-5 summary below is over every subject)".
        for value in VALUES:
            means = subject_means(self.trials, value)
            complete = {s for s, _ in means if all((s, c) in means for c in CONDITIONS)}
            for c in CONDITIONS:
                every = [m for (s, cc), m in sorted(means.items()) if cc == c]
                both = [m for (s, cc), m in sorted(means.items()) if cc == c and s in complete]
                row = next(r for r in self.phase_means if r["value"] == value and r["condition"] == c)
                total = next(r for r in self.summary if r["quantity"] == value and r["condition"] == c
                             and r["row"] == "mean over subjects")
                for name, got, per_subject in (("phase_means.csv", row, both), ("summary.csv", total, every)):
                    want = (len(per_subject), statistics.fmean(per_subject), statistics.stdev(per_subject))
                    with self.subTest(value=value, condition=c, table=name):
                        self.assertEqual(int(got["n"]), want[0])
                        self.assertAlmostEqual(float(got["mean"]) / want[1], 1.0, places=12)
                        self.assertAlmostEqual(float(got["sd"]) / want[2], 1.0, places=9)

    def test_phase_means_interval_of_the_complete_condition_is_cousineau_morey(self):
        # "within subjects ... the Cousineau-Morey within-subject interval": subject means normalised by the
        # subject's level (over the subjects with both conditions), SD x sqrt(J / (J - 1)), t interval.
        value = "mean_deviation_m"
        means = subject_means(self.trials, value)
        both = sorted(s for s, c in means if c == "vision" and (s, "haptic") in means)
        self.assertEqual(both, sorted(s for s, c in means if c == "vision"))
        level = {s: (means[(s, "vision")] + means[(s, "haptic")]) / 2 for s in both}
        grand = statistics.fmean(level.values())
        normed = [means[(s, "vision")] - level[s] + grand for s in both]
        half = t_975(len(both) - 1) * statistics.stdev(normed) * math.sqrt(2) / math.sqrt(len(both))
        centre = statistics.fmean(means[(s, "vision")] for s in both)
        row = next(r for r in self.phase_means if r["value"] == value and r["condition"] == "vision")
        self.assertAlmostEqual(float(row["ci95_low"]), centre - half, delta=1e-9 * centre)
        self.assertAlmostEqual(float(row["ci95_high"]), centre + half, delta=1e-9 * centre)

    def test_page_means_by_phase_are_the_table_rows_in_mm_and_s(self):
        # The page shows lengths in mm; phase_means.csv is in SI units: every cell traceable to a row.
        for value, scale in (("total_time_s", 1.0), ("mean_deviation_m", 1000.0)):
            body = table_bodies(self.page, "phase-means", value)
            self.assertEqual(len(body), 1, value)
            got = cells(body[0])
            self.assertEqual(got[0], "test")
            for c, text in zip(CONDITIONS, got[1:]):
                row = next(r for r in self.phase_means if r["value"] == value and r["condition"] == c)
                want = f"{float(row['mean']) * scale:.2f} ± {float(row['sd']) * scale:.2f} ({row['n']})"
                self.assertEqual(text, want, (value, c))

    def test_table5_cells_are_each_subjects_mean_over_its_analysed_repetitions(self):
        # "a table per value in the manner of Table 5 ... the mean over its repetitions"; summary.csv its cells.
        for value, scale in (("total_time_s", 1.0), ("mean_deviation_m", 1000.0)):
            means = subject_means(self.trials, value)
            body = table_bodies(self.page, "table5", value)
            self.assertEqual(len(body), 4, value)
            for row in body:
                subject, character, *shown = cells(row)
                self.assertEqual(character, "十")
                for c, text in zip(CONDITIONS, shown):
                    want = means.get((subject, c))
                    self.assertEqual(text, "–" if want is None else f"{want * scale:.2f}", (value, subject, c))
                    cell = next(r for r in self.summary if r["quantity"] == value and r["subject"] == subject
                                and r["condition"] == c)
                    n = sum(r["subject"] == subject and r["condition"] == c and r["end_reason"] == "completed"
                            for r in self.trials)
                    self.assertEqual(int(cell["n"]), n)
                    if want is not None:
                        self.assertAlmostEqual(float(cell["mean"]) / want, 1.0, places=12)

    # The study report: the design's questions

    def test_paired_check_is_students_t_on_the_subjects_with_both_conditions(self):
        # "within subjects: a paired t-test on subject means, a check beside the mixed model's test of the same
        # comparison (not adjusted, not in its family)"; difference treatment - control; g_av = d_av (1 - 3 /
        # (4 df - 1)); the APA sentence "in the page's unit, mm or s".
        for value, scale, unit in (("total_time_s", 1.0, "s"), ("mean_deviation_m", 1000.0, "mm")):
            means = subject_means(self.trials, value)
            both = sorted(s for s, c in means if c == "vision" and (s, "haptic") in means)
            diffs = [means[(s, "haptic")] - means[(s, "vision")] for s in both]
            n, df = len(diffs), len(diffs) - 1
            mean, se = statistics.fmean(diffs), statistics.stdev(diffs) / math.sqrt(len(diffs))
            t = mean / se
            sd_av = (statistics.stdev(means[(s, "haptic")] for s in both)
                     + statistics.stdev(means[(s, "vision")] for s in both)) / 2
            g = mean / sd_av * (1 - 3 / (4 * df - 1))
            row = next(r for r in self.questions if r["value"] == value and r["family"] == f"{value} (checks)")
            with self.subTest(value=value):
                self.assertEqual(row["comparison"], "haptic - vision")
                self.assertEqual(int(row["n"]), n)
                self.assertEqual(float(row["df"]), df)
                self.assertAlmostEqual(float(row["statistic"]), t, places=9)
                self.assertAlmostEqual(float(row["p"]), t_two_sided_p(t, df), places=9)
                self.assertEqual(row["p_holm"], "")
                self.assertAlmostEqual(float(row["estimate"]) / mean, 1.0, places=12)
                self.assertAlmostEqual(float(row["ci95_low"]), mean - t_975(df) * se, delta=1e-7 * abs(mean))
                self.assertAlmostEqual(float(row["ci95_high"]), mean + t_975(df) * se, delta=1e-7 * abs(mean))
                self.assertAlmostEqual(float(row["g"]), g, places=9)
                low, high = (mean - t_975(df) * se) * scale, (mean + t_975(df) * se) * scale
                self.assertTrue(row["apa"].startswith(f"t({df}) = {t:.2f}, p = "), row["apa"])
                self.assertTrue(row["apa"].endswith(f"95 % CI [{low:.2f}, {high:.2f}] {unit}"), row["apa"])
                self.assertIn(html.escape(row["apa"]), self.page)

    def test_mixed_model_rows_without_rscript_say_not_computed_and_hold_no_test(self):
        # "Without R their rows say "not computed: Rscript is not installed" and the ANCOVA and paired tests are
        # still given"; "a family that is not computed ... keeps one row per comparison ..., with no df,
        # statistic or p".
        for value in VALUES:
            rows = [r for r in self.questions if r["family"] == f"{value}, test"]
            self.assertEqual(len(rows), 1, value)
            row = rows[0]
            self.assertEqual(row["comparison"], "haptic - vision")
            self.assertTrue(row["note"].startswith("not computed: Rscript is not installed"), row["note"])
            for key in ("n", "df", "statistic", "p", "p_holm"):
                self.assertEqual(row[key], "", key)

    # The study report: the page as a file

    def test_every_trial_links_to_its_own_article_on_the_per_trial_page(self):
        # "links to `trials_files/SUBJECT/SESSION.html#trial-SESSION-N` for each trial".
        links = set(re.findall(r'href="([^"]*trials_files/[^"]+)"', self.page))
        for r in self.trials:
            n = int(r["trial"])
            want = f"../trials_files/{r['subject']}/{r['session']}.html#trial-{r['session']}-{n}"
            self.assertIn(want, links)
            target = (self.paper / want.split("#")[0]).resolve()
            self.assertIn(f'id="trial-{r["session"]}-{n}"', target.read_text(encoding="utf-8"))

    def test_per_trial_articles_show_the_records_values_and_how_a_trial_ended(self):
        # docs/cli.md `report --out`: each trial's "own values (total time, mean deviation, ... how it ended)".
        for r in self.trials:
            page = (self.tmp / f"study/trials_files/{r['subject']}/{r['session']}.html").read_text(encoding="utf-8")
            article = re.search(rf'<article[^>]*id="trial-{r["session"]}-{int(r["trial"])}".*?</article>',
                                page, re.S).group(0)
            metrics = html.unescape(re.search(r'<p class="metrics">(.*?)</p>', article, re.S).group(1))
            self.assertIn(f"{float(r['total_time_s']):.1f} s", metrics)
            self.assertIn(f"deviation {float(r['mean_deviation_m']) * 1000:.2f} mm", metrics)
            self.assertEqual(r["end_reason"] != "completed", r["end_reason"] in metrics, metrics)

    def test_page_has_no_script_nor_external_resource_and_its_figures_are_150_dpi(self):
        # "The page has no script and no external resource; its figures are relative links"; "each also as a
        # 150 dpi PNG".
        self.assertNotIn("<script", self.page.lower())
        self.assertIsNone(re.search(r'\s(src|href)="(https?:)?//', self.page))
        for src in re.findall(r'<img[^>]*src="([^"]+)"', self.page):
            self.assertTrue((self.paper / src).is_file(), src)
        for value in VALUES:
            for kind in ("phase", "learning"):
                self.assertIn(f'src="figures/{kind}_{value}.svg"', self.page)
                dpi = png_dpi(self.paper / f"figures/{kind}_{value}.png")
                self.assertIsNotNone(dpi)
                self.assertAlmostEqual(dpi[0], 150, delta=0.5)

    def test_report_replaces_an_older_report_whole_and_touches_nothing_of_the_study(self):
        # The set of files written as one: "the earlier file kept under a second name until the last rename";
        # a report's files are not a session's; the per-trial pages are not the report's.
        written = {p.relative_to(self.paper).as_posix() for p in self.paper.rglob("*") if p.is_file()}
        self.assertEqual(written, REPORT_FILES)
        for name, text in OLDER_REPORT.items():
            self.assertNotEqual((self.paper / name).read_text(encoding="utf-8"), text, name)
        self.assertEqual(tree_digest(self.tmp / "study", skip=("paper", "trials.html", "trials_files")),
                         self.sessions_before)
        self.assertEqual(tree_digest(self.tmp / "study", skip=("S01", "S02", "S03", "S04", "paper")),
                         self.pages_before)

    def test_report_with_no_trial_analysed_says_none_and_not_computed_in_its_tables(self):
        # First run: a finding (the docs said each table of questions had one row saying `none`; the page kept a
        # row per comparison, one of them "not computed: paired_comparison: condition 'haptic' is not in
        # trials' 'condition' column; present: ", a helper's error). The docs now say: "each table of means has
        # one row saying `none` and why, each table of questions keeps a row per comparison it would have
        # held, each saying "not computed" and why"; the paired check says which condition has no values.
        d = self.tmp / "none"
        page = Path(self.none_index).read_text(encoding="utf-8")
        self.assertIn("Completion: 0 of 16 trials analysed", page)
        for value in VALUES:
            with self.subTest(value=value, table="phase-means"):
                body = table_bodies(page, "phase-means", value)
                self.assertIsNotNone(body)
                self.assertEqual(len(body), 1, body)
                self.assertIn("none", " ".join(cells(body[0])))
            with self.subTest(value=value, table="questions"):
                body = table_bodies(page, "questions", value)
                self.assertIsNotNone(body)
                self.assertGreaterEqual(len(body), 1, body)
                for row in body:
                    text = " ".join(cells(row))
                    self.assertIn("not computed", text)
                    self.assertNotIn("present:", text, "a helper's error, not the page's words")
                self.assertTrue(any("no values of" in " ".join(cells(row)) for row in body), body)
            self.assertIn("no trial analysed", (d / f"figures/phase_{value}.svg").read_text(encoding="utf-8"))
            self.assertFalse((d / f"figures/learning_{value}.svg").exists())
        self.assertNotIn('id="learning"', page)

    # The command line's refusals

    def test_reference_naming_no_condition_is_one_usage_error_naming_the_conditions(self):
        # "A `--reference` that names no condition or group of the study is wrong usage too (exit status 2,
        # naming the option and the conditions there are)."
        result = self.python_report("study", "--out", "ref-out", "--reference", "placebo")
        self.assert_one_error(result, 2, "--reference", "placebo", "vision", "haptic")
        self.assertFalse((self.tmp / "ref-out").exists())

    def test_report_file_that_is_a_session_file_is_refused_before_anything_is_written(self):
        # "A file of the report that is a file of a session folder it reads (... also through a symbolic or
        # hard link) is refused with exit status 2 and one line naming both, before anything is written."
        out = self.tmp / "linked-out"
        (out / "tables").mkdir(parents=True)
        session_json = next((self.tmp / "study/S02").glob("*/session.json"))
        before = session_json.read_bytes()
        os.symlink(session_json, out / "tables/questions.csv")
        result = self.python_report("study", "--out", "linked-out")
        self.assert_one_error(result, 2, "questions.csv", "session.json")
        self.assertEqual(session_json.read_bytes(), before)
        self.assertEqual(sorted(p.relative_to(out).as_posix() for p in out.rglob("*")),
                         ["tables", "tables/questions.csv"])


if __name__ == "__main__":
    unittest.main()
