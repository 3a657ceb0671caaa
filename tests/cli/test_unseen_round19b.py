#!/usr/bin/env python3
"""Round 19B: a study's outputs read by the tools a lab opens them with, from the docs alone (docs/cli.md
"report", "trace", "Option syntax"; docs/experiments.md "Protocol files", "Sessions", "Trace files", "Tidy
tables", "A report for a paper"). Run by CTest as `cli_unseen_round19b_tests`.

One tiny study shared by every case: a protocol named `-r19b_NA` (a leading `-`, a word readers take for a
missing value), its description full of markup, quotes, a comma, a semicolon, a tab, a line break, a leading
`=`, `+`, `-`, `@`, a right-to-left mark, CJK and an emoji (200 characters), two conditions named `007` and
`1e5` (legal names that a reader guessing types takes for numbers), two simulated subjects `Z_-01`, `Z_-02`
writing 一 and 十. Its `report --out --csv` (twice), the Python study report and `trace`, read by html.parser,
Python's csv module, pandas, R's read.csv (skipped saying so without Rscript), a strict JSON parser and h5py
(skipped saying so without it); the same study copied into a folder whose name holds a comma, a quote, a line
break and a leading `=`; labels the docs refuse refused naming them.

CALLIGRAPHY_CLI names the program, PYTHONPATH its Python module. CALLIGRAPHY_SANITIZED=1 takes five cases.
"""
import csv
import hashlib
import html.parser
import json
import math
import os
import shutil
import subprocess
import sys
import tempfile
import unittest
import urllib.parse
from pathlib import Path

from outsider import ENV, OneErrorLine, error_lines, run, sanitized_subset

load_tests = sanitized_subset({"test_run_of_hostile_labels_succeeds",
                               "test_index_page_is_well_formed",
                               "test_trials_csv_rows_are_the_records",
                               "test_trace_csv_header_and_units",
                               "test_tables_are_the_same_bytes_when_reported_twice"})

YI, SHI = "一", "十"
RLM = "\u200f"
DESCRIPTION = ("<script>alert(1)</script> &amp; \"q\" 'q', a; b\tc\nd =1+2 @x +y -z " + RLM + " 中文 🖋 ")
DESCRIPTION = (DESCRIPTION * 4)[:200]
PROTOCOL = {"name": "-r19b_NA", "description": DESCRIPTION,
            "conditions": [{"name": "007", "mode": "vision"}, {"name": "1e5", "mode": "haptic"}],
            "test": {"characters": [YI, SHI], "conditions": ["007", "1e5"], "repetitions": 1},
            "trial": {"max_duration_s": 3}}
RUN = ["--writer", "simulated", "--writer-learning", "none"]
TRACE_HEADER = "t,x,y,z,fx,fy,fz,state,stroke,element,attempt,rewritten"
# A folder name a lab could be given: a comma, a quote, markup, a line break, a leading `=`, a tab and an `@`.
HOSTILE_DIR = '=cmd,"x"<i>&amp;\n;\t@y'
SHARED = {}


def strict_json(text):
    def refuse(token):
        raise ValueError(f"non-JSON number token {token}")
    return json.loads(text, parse_constant=refuse)


class Page(html.parser.HTMLParser):
    VOID = {"area", "base", "br", "col", "embed", "hr", "img", "input", "link", "meta", "source", "track", "wbr"}

    def __init__(self):
        super().__init__(convert_charrefs=True)
        self.stack, self.errors, self.tags, self.links, self.text = [], [], set(), [], []

    def handle_starttag(self, tag, attrs):
        self.tags.add(tag)
        a = dict(attrs)
        for key in ("href", "src"):
            if a.get(key) is not None:
                self.links.append(a[key])
        if tag not in self.VOID:
            self.stack.append(tag)

    def handle_startendtag(self, tag, attrs):
        self.tags.add(tag)
        a = dict(attrs)
        for key in ("href", "src"):
            if a.get(key) is not None:
                self.links.append(a[key])

    def handle_endtag(self, tag):
        if tag in self.VOID:
            return
        if not self.stack or self.stack[-1] != tag:
            self.errors.append(f"</{tag}> closes {self.stack[-1:] or 'nothing'}")
            if tag in self.stack:
                while self.stack and self.stack.pop() != tag:
                    pass
        else:
            self.stack.pop()

    def handle_data(self, data):
        self.text.append(data)


def parse_page(path):
    page = Page()
    page.feed(Path(path).read_text(encoding="utf-8"))
    page.close()
    return page


def local_target(page_path, link):
    """The file a relative link names (without its fragment), or None for a fragment-only link."""
    parts = urllib.parse.urlsplit(link)
    if not parts.path:
        return None
    return (Path(page_path).parent / urllib.parse.unquote(parts.path))


def tree_digest(root):
    out = {}
    for p in sorted(Path(root).rglob("*")):
        if p.is_file():
            out[str(p.relative_to(root))] = hashlib.sha256(p.read_bytes()).hexdigest()
    return out


def read_rows(path):
    with open(path, newline="", encoding="utf-8") as f:
        return list(csv.DictReader(f))


def sessions(study):
    return sorted(p.parent for p in Path(study).glob("*/*/session.json"))


def records(study):
    out = {}
    for s in sessions(study):
        for p in sorted((s / "trials").glob("*.json")):
            out[(s.name, p.name[:-len(".json")])] = strict_json(p.read_text(encoding="utf-8"))
    return out


def documented_block(language, needle):
    """The block of docs/experiments.md in `language` that holds `needle`, as its text."""
    source = os.environ.get("CALLIGRAPHY_SOURCE_DIR") or Path(__file__).resolve().parents[2]
    text = (Path(source) / "docs" / "experiments.md").read_text(encoding="utf-8")
    for block in text.split("```" + language + "\n")[1:]:
        block = block.split("```")[0]
        if needle in block:
            return block
    raise AssertionError(f"docs/experiments.md has no {language} block holding {needle!r}")


def documented_pandas_options():
    """The keyword arguments of docs/experiments.md's pandas.read_csv of trials.csv ("Tidy tables")."""
    block = documented_block("python", 'pandas.read_csv("tables/trials.csv"')
    names = {}
    exec(block.replace("import pandas", "").replace('pandas.read_csv("tables/trials.csv",', "dict("), {}, names)
    return names["trials"]


def documented_r_read():
    """docs/experiments.md's R lines reading trials.csv ("Tidy tables")."""
    return documented_block("r", 'read.csv("tables/trials.csv"').strip()


def setUpModule():
    tmp = Path(tempfile.mkdtemp(prefix="r19b-"))
    SHARED["tmp"] = tmp
    (tmp / "p.json").write_text(json.dumps(PROTOCOL, ensure_ascii=False), encoding="utf-8")
    r = run(["session", "run", "p.json", *RUN, "--subjects", "2", "--subject", "Z_-", "--out", "st"], tmp)
    SHARED["run"] = r
    if r.returncode != 0:
        return
    SHARED["before"] = tree_digest(tmp / "st")
    for name in ("a", "b"):
        (tmp / f"tables-{name}").mkdir()
        (tmp / f"site-{name}").mkdir()
        SHARED[f"report-{name}"] = run(["report", "st", "--out", f"site-{name}/index.html",
                                        "--csv", f"tables-{name}"], tmp)
    trace = next((tmp / "st").glob("Z_-01/*/trials/002-*.trace.h5"))
    SHARED["trace"] = trace
    SHARED["trace-run"] = run(["trace", trace, "--csv", "trace.csv"], tmp)
    # The Python study report with an empty PATH, so no Rscript (its mixed models say so): cheap and the same on
    # every machine.
    env = dict(ENV)
    (tmp / "nobin").mkdir()
    env["PATH"] = str(tmp / "nobin")
    env["MPLBACKEND"] = "Agg"
    title = "<b>T</b> &amp; \"q\" " + RLM + " 中 🖋, =1"
    SHARED["title"] = title
    SHARED["paper-run"] = subprocess.run(
        [sys.executable, "-m", "calligraphy.study_report", "st", "--out", "paper", "--title", title,
         "--analyse", "all", "--per-trial-page", "site-a/index.html"], cwd=tmp, env=env, stdout=subprocess.PIPE,
        stderr=subprocess.PIPE, timeout=120)


def tearDownModule():
    shutil.rmtree(SHARED["tmp"], ignore_errors=True)


class Study(unittest.TestCase, OneErrorLine):
    def setUp(self):
        self.tmp = SHARED["tmp"]
        if SHARED["run"].returncode != 0:
            self.fail(SHARED["run"].stderr.decode())

    # -- the run and the labels the docs allow or refuse ----------------------------------------------------
    def test_run_of_hostile_labels_succeeds(self):
        lines = SHARED["run"].stdout.decode().splitlines()
        self.assertEqual(len(lines), 2, lines)
        self.assertEqual(len(records(self.tmp / "st")), 8)
        for s in sessions(self.tmp / "st"):
            self.assertTrue(s.name.startswith("-r19b_NA-Z_-0"), s.name)
            manifest = strict_json((s / "session.json").read_text(encoding="utf-8"))
            self.assertEqual(manifest["subject"]["id"] if isinstance(manifest["subject"], dict)
                             else manifest["subject"], s.parent.name)

    def test_protocol_names_outside_the_alphabet_are_refused_naming_name(self):
        for bad in ("a<b", "中", "a,b", "x" * 65, "a b", ""):
            with self.subTest(name=bad):
                d = Path(tempfile.mkdtemp(dir=self.tmp))
                (d / "p.json").write_text(json.dumps(dict(PROTOCOL, name=bad), ensure_ascii=False), encoding="utf-8")
                r = run(["session", "run", "p.json", *RUN, "--subjects", "1", "--out", "o"], d)
                self.assert_one_error(r, 2, "p.json", "/name")
                self.assertFalse((d / "o").exists())

    def test_condition_names_outside_the_alphabet_are_refused_naming_the_pointer(self):
        for bad in ("<i>", "a;b", "=1", "x" * 33):
            with self.subTest(name=bad):
                d = Path(tempfile.mkdtemp(dir=self.tmp))
                p = json.loads(json.dumps(PROTOCOL))
                p["conditions"][0]["name"] = bad
                p["test"]["conditions"][0] = bad
                (d / "p.json").write_text(json.dumps(p, ensure_ascii=False), encoding="utf-8")
                r = run(["session", "run", "p.json", *RUN, "--subjects", "1", "--out", "o"], d)
                self.assert_one_error(r, 2, "p.json", "/conditions/0/name")
                self.assertFalse((d / "o").exists())

    def test_subject_ids_outside_the_alphabet_are_refused_naming_subject(self):
        for bad in ("a,b", "主体", "a<b>", "a\tb", "=1", "@x", "+1", "S" + RLM):
            with self.subTest(subject=bad):
                d = Path(tempfile.mkdtemp(dir=self.tmp))
                r = run(["session", "run", self.tmp / "p.json", *RUN, "--subject", bad, "--out", "o"], d)
                self.assert_one_error(r, 2, "--subject")
                self.assertFalse((d / "o").exists())

    def test_subject_id_starting_with_a_dash_is_refused_as_an_option_value(self):
        d = Path(tempfile.mkdtemp(dir=self.tmp))
        r = run(["session", "run", self.tmp / "p.json", *RUN, "--subject=-x1", "--out", "o"], d)
        self.assert_one_error(r, 2, "--subject")
        self.assertFalse((d / "o").exists())

    def test_subject_ids_at_and_past_64_characters(self):
        # docs/cli.md: 1-64 of [A-Za-z0-9_-], each id a prefix and a number make too. With a 64-character protocol
        # name the session folder's name is 145 bytes: within a file name's 255.
        d = Path(tempfile.mkdtemp(dir=self.tmp))
        p = dict(PROTOCOL, name="P" * 64, test={"characters": [YI], "conditions": ["007"], "repetitions": 1},
                 trial={"max_duration_s": 0.3})
        (d / "p.json").write_text(json.dumps(p, ensure_ascii=False), encoding="utf-8")
        for args in (["--subject", "S" * 64 + "1"], ["--subject", "S" * 63, "--subjects", "2"]):
            with self.subTest(args=args[1:]):
                r = run(["session", "run", "p.json", *RUN, *args, "--out", "o"], d)
                self.assert_one_error(r, 2, "--subject", "64")
                self.assertFalse((d / "o").exists())
        r = run(["session", "run", "p.json", *RUN, "--subject", "S" * 63 + "1", "--out", "o"], d)
        self.assertEqual(r.returncode, 0, r.stderr.decode())
        self.assertEqual([s.parent.name for s in sessions(d / "o")], ["S" * 63 + "1"])

    # -- the HTML pages -------------------------------------------------------------------------------------
    def pages(self, site="site-a"):
        root = self.tmp / site
        return [root / "index.html", *sorted((root / "index_files").rglob("*.html"))]

    def test_report_runs_print_no_error(self):
        for name in ("a", "b"):
            r = SHARED[f"report-{name}"]
            self.assertEqual(r.returncode, 0, r.stderr.decode())
            self.assertEqual(error_lines(r), [])

    def test_index_page_is_well_formed(self):
        page = parse_page(self.tmp / "site-a" / "index.html")
        self.assertEqual(page.errors, [])
        self.assertEqual(page.stack, [])

    def test_session_pages_are_well_formed(self):
        pages = self.pages()
        self.assertEqual(len(pages), 3)
        for path in pages[1:]:
            with self.subTest(page=path.name):
                page = parse_page(path)
                self.assertEqual(page.errors, [])
                self.assertEqual(page.stack, [])

    def test_no_label_becomes_markup(self):
        for path in self.pages() + [self.tmp / "paper" / "index.html"]:
            with self.subTest(page=str(path.relative_to(self.tmp))):
                page = parse_page(path)
                source = Path(path).read_text(encoding="utf-8")
                self.assertNotIn("script", page.tags)
                self.assertNotIn("<b>T</b>", source)
                self.assertNotIn("alert(1)</script>", source)
                text = "".join(page.text)
                if "alert(1)" in text:
                    self.assertIn("<script>alert(1)</script>", text)

    def test_labels_are_shown_as_written(self):
        text = "".join(parse_page(self.tmp / "site-a" / "index.html").text)
        for label in ("-r19b_NA", "Z_-01", "Z_-02"):
            self.assertIn(label, text)
        session_text = "".join(parse_page(self.pages()[1]).text)
        for label in ("007", "1e5", YI, SHI):
            self.assertIn(label, session_text)

    def test_every_link_and_image_is_relative_and_exists(self):
        for path in self.pages():
            page = parse_page(path)
            for link in page.links:
                with self.subTest(page=path.name, link=link):
                    parts = urllib.parse.urlsplit(link)
                    self.assertEqual(parts.scheme, "")
                    self.assertEqual(parts.netloc, "")
                    self.assertFalse(parts.path.startswith("/"))
                    target = local_target(path, link)
                    if target is not None:
                        self.assertTrue(target.is_file(), target)
                        self.assertTrue(target.resolve().is_relative_to((self.tmp / "site-a").resolve()))

    def test_pages_are_whole_when_their_folder_is_moved(self):
        moved = self.tmp / "moved" / "deeper"
        shutil.copytree(self.tmp / "site-a", moved)
        for path in [moved / "index.html", *sorted((moved / "index_files").rglob("*.html"))]:
            for link in parse_page(path).links:
                target = local_target(path, link)
                if target is not None:
                    self.assertTrue(target.is_file(), (path, link))
                    fragment = urllib.parse.urlsplit(link).fragment
                    if fragment and target.suffix == ".html":
                        self.assertIn(f'id="{fragment}"', target.read_text(encoding="utf-8"))

    def test_pages_reported_twice_are_the_same_bytes(self):
        a = tree_digest(self.tmp / "site-a")
        b = tree_digest(self.tmp / "site-b")
        self.assertEqual(sorted(a), sorted(b))
        differ = [name for name in a if a[name] != b[name]]
        self.assertEqual(differ, [], "pages of the same study differ")

    def test_study_folder_unchanged_and_no_temporary_left(self):
        self.assertEqual(tree_digest(self.tmp / "st"), SHARED["before"])
        leftovers = [p for p in self.tmp.rglob("*") if ".tmp-" in p.name or ".partial." in p.name]
        self.assertEqual(leftovers, [])

    # -- the tidy tables ------------------------------------------------------------------------------------
    def test_trials_csv_rows_are_the_records(self):
        rows = read_rows(self.tmp / "tables-a" / "trials.csv")
        recs = records(self.tmp / "st")
        self.assertEqual(len(rows), len(recs))
        for row in rows:
            rec = recs[(row["session"], Path(row["trace_file"]).name[:-len(".trace.h5")])]
            self.assertEqual(row["protocol"], "-r19b_NA")
            self.assertEqual(row["condition"], rec["condition"])
            self.assertEqual(row["subject"], rec["subject"] if isinstance(rec["subject"], str)
                             else rec["subject"]["id"])
            self.assertEqual(row["characters"], rec["characters"])

    def test_csv_values_are_the_records_doubles(self):
        # docs/experiments.md: 17 significant digits, read back as the record's double.
        rows = read_rows(self.tmp / "tables-a" / "trials.csv")
        recs = records(self.tmp / "st")
        for row in rows:
            rec = recs[(row["session"], Path(row["trace_file"]).name[:-len(".trace.h5")])]
            for column in ("total_time_s", "pen_down_time_s", "mean_deviation_m", "max_deviation_m",
                           "rms_deviation_m", "frechet_m", "dtw_m", "normalised_jerk"):
                with self.subTest(column=column, trial=row["trial"]):
                    if rec[column] is None:
                        self.assertEqual(row[column], "")
                    else:
                        self.assertEqual(float(row[column]), rec[column])
                        self.assertEqual(row["end_reason"], rec["end_reason"])
                        self.assertEqual(row["condition"], rec["condition"])

    def test_tables_are_the_same_bytes_when_reported_twice(self):
        for name in ("trials.csv", "strokes.csv"):
            self.assertEqual((self.tmp / "tables-a" / name).read_bytes(), (self.tmp / "tables-b" / name).read_bytes())

    def test_tables_are_the_same_whatever_the_order_of_the_dirs(self):
        outs = []
        for order in (("st/Z_-02", "st/Z_-01"), ("st/Z_-01", "st/Z_-02")):
            out = self.tmp / ("tables-" + "-".join(d[-2:] for d in order))
            out.mkdir()
            r = run(["report", *order, "--csv", out], self.tmp)
            self.assertEqual(r.returncode, 0, r.stderr.decode())
            outs.append(out)
        for name in ("trials.csv", "strokes.csv"):
            self.assertEqual((outs[0] / name).read_bytes(), (outs[1] / name).read_bytes(), name)

    def test_pandas_reads_the_labels_as_written(self):
        import pandas
        trials = pandas.read_csv(self.tmp / "tables-a" / "trials.csv", **documented_pandas_options())
        self.assertEqual(sorted(set(trials["condition"])), ["007", "1e5"])
        self.assertEqual(set(trials["protocol"]), {"-r19b_NA"})
        self.assertEqual(list(trials["subject"]), [row["subject"] for row in read_rows(
            self.tmp / "tables-a" / "trials.csv")])

    def test_pandas_and_study_load_are_one_frame(self):
        import pandas
        from calligraphy import study
        loaded = study.load(str(self.tmp / "st")).trials
        read = pandas.read_csv(self.tmp / "tables-a" / "trials.csv", **documented_pandas_options())
        self.assertEqual(list(read.columns), list(loaded.columns))
        for column in ("subject", "session", "protocol", "condition", "characters", "trace_sha256"):
            self.assertEqual(list(read[column]), list(loaded[column]), column)
        self.assertEqual(sorted(set(loaded["condition"])), ["007", "1e5"])
        for column in ("total_time_s", "mean_deviation_m"):
            self.assertEqual(list(read[column]), list(loaded[column]), column)

    def test_r_read_csv_reads_the_labels_as_written(self):
        rscript = shutil.which("Rscript")
        if not rscript:
            self.skipTest("Rscript is not installed")
        script = (documented_r_read().replace("tables/trials.csv", "tables-a/trials.csv") + ";"
                  'cat(trials$condition, sep = "\\n"); cat("--\\n"); cat(trials$protocol, sep = "\\n");'
                  'cat("--\\n"); cat(trials$subject, sep = "\\n")')
        r = subprocess.run([rscript, "-e", script], cwd=self.tmp, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                           timeout=60)
        self.assertEqual(r.returncode, 0, r.stderr.decode())
        self.assertEqual(r.stderr.decode(), "")
        condition, protocol, subject = r.stdout.decode().split("--\n")
        rows = read_rows(self.tmp / "tables-a" / "trials.csv")
        self.assertEqual(condition.splitlines(), [row["condition"] for row in rows])
        self.assertEqual(protocol.splitlines(), [row["protocol"] for row in rows])
        self.assertEqual(subject.splitlines(), [row["subject"] for row in rows])

    def test_strokes_csv_has_one_row_per_reference_stroke(self):
        rows = read_rows(self.tmp / "tables-a" / "strokes.csv")
        trials = read_rows(self.tmp / "tables-a" / "trials.csv")
        expected = sum(1 if t["characters"] == YI else 2 for t in trials)
        self.assertEqual(len(rows), expected)
        for row in rows:
            self.assertIn(row["written"], ("TRUE", "FALSE"))
            self.assertIn(row["backwards"], ("TRUE", "FALSE"))

    def test_a_copy_in_a_hostile_folder_differs_in_trace_file_only(self):
        copy = self.tmp / HOSTILE_DIR
        shutil.copytree(self.tmp / "st", copy)
        out = self.tmp / "tables-copy"
        out.mkdir()
        r = run(["report", HOSTILE_DIR, "--csv", out], self.tmp)
        self.assertEqual(r.returncode, 0, r.stderr.decode())
        raw = (out / "trials.csv").read_bytes()
        copied, original = read_rows(out / "trials.csv"), read_rows(self.tmp / "tables-a" / "trials.csv")
        self.assertEqual(len(copied), len(original))
        for a, b in zip(copied, original):
            self.assertEqual(set(a), set(b))
            self.assertEqual({k for k in a if a[k] != b[k]}, {"trace_file"})
            self.assertTrue(a["trace_file"].startswith(HOSTILE_DIR + "/"), a["trace_file"])
            self.assertTrue((self.tmp / a["trace_file"]).is_file())
        self.assertEqual(raw.count(b"\n"), len(copied) * (1 + HOSTILE_DIR.count("\n")) + 1)

    def test_pages_of_the_copy_in_a_hostile_folder_are_whole(self):
        copy = self.tmp / "copy-for-pages" / HOSTILE_DIR
        shutil.copytree(self.tmp / "st", copy)
        site = self.tmp / "copy-for-pages" / "site"
        site.mkdir()
        r = run(["report", HOSTILE_DIR, "--out", "site/index.html"], copy.parent)
        self.assertEqual(r.returncode, 0, r.stderr.decode())
        pages = [site / "index.html", *sorted((site / "index_files").rglob("*.html"))]
        self.assertEqual(len(pages), 3)
        for path in pages:
            with self.subTest(page=path.name):
                page = parse_page(path)
                self.assertEqual((page.errors, page.stack), ([], []))
                self.assertNotIn("i", page.tags)
                for link in page.links:
                    target = local_target(path, link)
                    if target is not None:
                        self.assertTrue(target.is_file(), link)

    def test_a_trial_that_wrote_nothing_is_absent_in_every_reader(self):
        import pandas
        from calligraphy import study
        d = Path(tempfile.mkdtemp(dir=self.tmp))
        p = dict(PROTOCOL, name="none19b", test={"characters": [YI], "conditions": ["007"], "repetitions": 1},
                 trial={"max_duration_s": 0.01})
        (d / "p.json").write_text(json.dumps(p, ensure_ascii=False), encoding="utf-8")
        r = run(["session", "run", "p.json", *RUN, "--subject", "N1", "--out", "o"], d)
        self.assertEqual(r.returncode, 0, r.stderr.decode())
        (d / "t").mkdir()
        r = run(["report", "o", "--csv", "t"], d)
        self.assertEqual(r.returncode, 0, r.stderr.decode())
        (record,) = records(d / "o").values()
        self.assertIsNone(record["mean_deviation_m"])
        (row,) = read_rows(d / "t" / "trials.csv")
        self.assertEqual(row["mean_deviation_m"], "")
        self.assertEqual(row["condition"], "007")
        read = pandas.read_csv(d / "t" / "trials.csv", **documented_pandas_options())
        loaded = study.load(str(d / "o")).trials
        for frame in (read, loaded):
            self.assertTrue(math.isnan(frame["mean_deviation_m"][0]))
            self.assertEqual(frame["condition"][0], "007")

    def test_flags_and_absent_values_as_documented(self):
        rows = read_rows(self.tmp / "tables-a" / "trials.csv")
        for row in rows:
            self.assertIn(row["completed_in_order"], ("TRUE", "FALSE"))
            for column in ("group", "item_set", "sequence", "period", "trained_condition"):
                self.assertEqual(row[column], "", column)
            for value in row.values():
                self.assertNotIn(value.lower(), ("nan", "inf", "-inf", "null", "na"))

    # -- JSON outputs ---------------------------------------------------------------------------------------
    def test_every_json_output_parses_strictly(self):
        files = list((self.tmp / "st").rglob("*.json")) + [self.tmp / "st" / ".calligraphy-study.json"]
        self.assertGreater(len(files), 8)
        for path in files:
            with self.subTest(file=path.name):
                strict_json(path.read_text(encoding="utf-8"))
        for log in (self.tmp / "st").rglob("log.jsonl"):
            for line in log.read_text(encoding="utf-8").splitlines():
                strict_json(line)

    def test_description_round_trips_in_session_json(self):
        for s in sessions(self.tmp / "st"):
            manifest = strict_json((s / "session.json").read_text(encoding="utf-8"))
            self.assertEqual(strict_json(manifest["protocol"]["text"])["description"], DESCRIPTION)

    def test_record_numbers_equal_the_table_numbers(self):
        rows = read_rows(self.tmp / "tables-a" / "trials.csv")
        recs = records(self.tmp / "st")

        def numbers(obj, out):
            if isinstance(obj, dict):
                for v in obj.values():
                    numbers(v, out)
            elif isinstance(obj, list):
                for v in obj:
                    numbers(v, out)
            elif isinstance(obj, float):
                out.add(obj)
            return out
        for row in rows:
            rec = recs[(row["session"], Path(row["trace_file"]).name[:-len(".trace.h5")])]
            found = numbers(rec, set())
            for column in ("mean_deviation_m", "max_deviation_m", "frechet_m", "dtw_m", "pen_down_time_s"):
                if row[column] != "":
                    self.assertIn(float(row[column]), found, column)

    def test_session_plan_json_is_strict_and_names_as_written(self):
        r = run(["session", "plan", "p.json", "--subjects", "2", "--subject", "Z_-", "--json"], self.tmp)
        self.assertEqual(r.returncode, 0, r.stderr.decode())
        plan = strict_json(r.stdout.decode("utf-8"))
        self.assertEqual(plan["protocol"], "-r19b_NA")
        self.assertEqual([s["id"] for s in plan["subjects"]], ["Z_-01", "Z_-02"])
        self.assertIn('"007"', r.stdout.decode("utf-8"))
        self.assertIn('"1e5"', r.stdout.decode("utf-8"))

    def test_session_cohort_tables_keep_the_labels(self):
        import pandas
        (self.tmp / "cohort").mkdir()
        r = run(["session", "cohort", "p.json", "--subjects", "1", "--subject", "Z_-", "--csv", "cohort"], self.tmp)
        self.assertEqual(r.returncode, 0, r.stderr.decode())
        rows = read_rows(self.tmp / "cohort" / "trials.csv")
        self.assertEqual([row["condition"] for row in rows], ["007", "007", "1e5", "1e5"])
        read = pandas.read_csv(self.tmp / "cohort" / "trials.csv", **documented_pandas_options())
        self.assertEqual(list(read["condition"]), ["007", "007", "1e5", "1e5"])
        self.assertEqual(set(read["protocol"]), {"-r19b_NA"})

    # -- traces ---------------------------------------------------------------------------------------------
    def test_trace_csv_header_and_units(self):
        r = SHARED["trace-run"]
        self.assertEqual(r.returncode, 0, r.stderr.decode())
        lines = (self.tmp / "trace.csv").read_text(encoding="utf-8").splitlines()
        self.assertEqual(lines[0], TRACE_HEADER)
        rows = list(csv.reader(lines[1:]))
        self.assertGreater(len(rows), 10)
        t = [float(row[0]) for row in rows]
        self.assertEqual(t, sorted(t))
        self.assertLess(t[-1], 3.01)
        for row in rows:
            self.assertEqual(len(row), 12)
            self.assertLess(max(abs(float(v)) for v in row[1:4]), 1.0)

    def test_trace_to_standard_output_is_the_same_bytes(self):
        r = run(["trace", SHARED["trace"]], self.tmp)
        self.assertEqual(r.returncode, 0, r.stderr.decode())
        self.assertEqual(r.stdout, (self.tmp / "trace.csv").read_bytes())

    def h5(self):
        try:
            import h5py
        except ImportError:
            self.skipTest("h5py is not installed")
        return h5py

    def test_trace_h5_datasets_attributes_and_shapes(self):
        h5py = self.h5()
        with h5py.File(SHARED["trace"], "r") as f:
            self.assertEqual(f.attrs["format"], b"calligraphy-trace" if isinstance(f.attrs["format"], bytes)
                             else "calligraphy-trace")
            self.assertEqual(int(f.attrs["version"]), 1)
            n = int(f.attrs["samples"])
            for name in TRACE_HEADER.split(","):
                self.assertIn(name, f)
                self.assertEqual(f[name].shape, (n,), name)
            for name, unit in (("t", "s"), ("x", "m"), ("y", "m"), ("z", "m"), ("fx", "N"), ("fy", "N"), ("fz", "N")):
                u = f[name].attrs["unit"]
                self.assertEqual(u.decode() if isinstance(u, bytes) else u, unit, name)
            self.assertEqual(int(f["t"].attrs["decimals"]), 6)
            self.assertEqual(int(f["x"].attrs["decimals"]), 7)
            self.assertEqual(int(f["fx"].attrs["decimals"]), 4)
            for name in ("stroke", "element"):
                self.assertEqual(f[name].dtype.kind, "u")
                self.assertEqual(f[name].dtype.itemsize, 4)
            self.assertEqual(f["attempt"].dtype.str[1:], "i4")
            self.assertEqual(f["rewritten"].dtype.str[1:], "u1")
            names = h5py.check_enum_dtype(f["state"].dtype)
            self.assertEqual(set(names or {}), {"SS", "AS", "CS", "WS"})

    def test_trace_h5_values_are_the_trace_csv(self):
        h5py = self.h5()
        rows = list(csv.reader((self.tmp / "trace.csv").read_text(encoding="utf-8").splitlines()[1:]))
        with h5py.File(SHARED["trace"], "r") as f:
            self.assertEqual(len(rows), int(f.attrs["samples"]))
            for i, name in enumerate(("t", "x", "y", "z", "fx", "fy", "fz")):
                d = f[name]
                values = d[()] / 10 ** int(d.attrs["decimals"]) if "decimals" in d.attrs else d[()]
                self.assertEqual([float(v) for v in values], [float(row[i]) for row in rows], name)
            for i, name in ((8, "stroke"), (9, "element"), (10, "attempt"), (11, "rewritten")):
                self.assertEqual([int(v) for v in f[name][()]], [int(row[i]) for row in rows], name)

    # -- the Python study report ----------------------------------------------------------------------------
    def test_study_report_page_is_well_formed_and_relative(self):
        r = SHARED["paper-run"]
        self.assertEqual(r.returncode, 0, r.stderr.decode())
        index = self.tmp / "paper" / "index.html"
        page = parse_page(index)
        self.assertEqual(page.errors, [])
        self.assertEqual(page.stack, [])
        for link in page.links:
            parts = urllib.parse.urlsplit(link)
            self.assertEqual(parts.scheme, "", link)
            target = local_target(index, link)
            if target is not None:
                self.assertTrue(target.exists(), link)

    def test_study_report_title_is_text(self):
        source = (self.tmp / "paper" / "index.html").read_text(encoding="utf-8")
        page = parse_page(self.tmp / "paper" / "index.html")
        self.assertIn(SHARED["title"], "".join(page.text))
        self.assertNotIn("<b>T</b>", source)

    def test_study_report_names_the_conditions_as_written(self):
        page = parse_page(self.tmp / "paper" / "index.html")
        text = "".join(page.text)
        for label in ("007", "1e5", "-r19b_NA"):
            self.assertTrue(label in text, f"{label} is not on the page")
        for guess in ("7.0", "100000"):
            self.assertFalse(guess in text, f"{guess} is on the page")
        for table in sorted((self.tmp / "paper" / "tables").glob("*.csv")):
            with self.subTest(table=table.name):
                content = table.read_text(encoding="utf-8")
                self.assertNotIn(",7.0,", content)
                self.assertNotIn("100000.0", content)

    def test_study_report_tables_are_whole_rows(self):
        tables = sorted((self.tmp / "paper" / "tables").glob("*.csv"))
        self.assertTrue(tables)
        for table in tables:
            with self.subTest(table=table.name):
                with open(table, newline="", encoding="utf-8") as f:
                    rows = list(csv.reader(f))
                self.assertTrue(all(len(row) == len(rows[0]) for row in rows), table.name)
                for row in rows[1:]:
                    for value in row:
                        self.assertNotIn(value.lower(), ("nan", "inf", "-inf", "none"))

    def test_study_report_is_whole_when_moved_with_its_study_pages(self):
        moved = self.tmp / "moved-all"
        moved.mkdir()
        for name in ("paper", "site-a"):
            shutil.copytree(self.tmp / name, moved / name)
        index = moved / "paper" / "index.html"
        for link in parse_page(index).links:
            target = local_target(index, link)
            if target is not None:
                self.assertTrue(target.exists(), link)


if __name__ == "__main__":
    unittest.main()
