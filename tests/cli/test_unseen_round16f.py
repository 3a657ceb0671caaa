#!/usr/bin/env python3
"""Round 16F: the pages and figures the program writes for people, read as a reviewer and a reader of the paper
read them, from the docs alone (docs/cli.md "report" and "model", docs/experiments.md "The per-trial pages" and
"A report for a paper", docs/python.md). Run by CTest as `cli_unseen_round16f_tests`.

One tiny within-subjects study in setUpModule (3 simulated subjects, 一 and 十 under a vision and a haptic condition,
a protocol description full of markup), its `report --out --csv` and the Python study report (`python3 -m
calligraphy.study_report`, no Rscript on PATH: the mixed models' rows say why); a study of characters named `<`,
`&`, `"`, `'` and a right-to-left mark (a hanzi-writer-data folder of their files); a study of one trial that wrote
nothing; a session that saved no trial; an empty folder; an output named with a space, `#`, `&`, `?` and `%20`;
session.json edited to names of markup. Each case checks a documented promise: pages well formed (python3's
html.parser held to balanced tags, every inline and file SVG parsed by xml.etree), UTF-8 declared, a title, no
script and nothing loaded from outside the output folder, every local link and image there (fragments too), an
accessible name on every figure, header cells on every table; the pages' numbers those of the tidy tables within
their printed rounding, in the units the docs give, strokes numbered from 1, no `nan`, `inf` or `None` and no empty
cell without a word why; names shown as text; PNG figures that open, at 150 dpi, not blank; axes named with units; a
report run again over itself giving the same set and nothing else, the study folder unchanged.

CALLIGRAPHY_CLI names the program, PYTHONPATH its Python module, CALLIGRAPHY_SOURCE_DIR the sources (docs/ and
the sample character data). CALLIGRAPHY_SANITIZED=1 takes five cases.
"""
import colorsys
import csv
import hashlib
import html
import os
import re
import shutil
import subprocess
import sys
import tempfile
import unittest
import xml.etree.ElementTree as ET
from html.parser import HTMLParser
from pathlib import Path
from urllib.parse import unquote, urlsplit

from outsider import SANITIZED, OneErrorLine, run, sanitized_subset

load_tests = sanitized_subset({"test_trial_pages_are_well_formed_html",
                               "test_every_link_of_the_trial_pages_resolves",
                               "test_model_svg_of_characters_named_like_markup_is_well_formed",
                               "test_empty_study_is_refused_in_one_line_and_nothing_is_written",
                               "test_characters_named_like_markup_show_as_text_on_the_trial_pages"})

SOURCE = Path(os.environ.get("CALLIGRAPHY_SOURCE_DIR", Path(__file__).resolve().parents[2]))
SAMPLE = SOURCE / "tests" / "data" / "hanzi-writer-sample"
YI, SHI = "一", "十"
HOSTILE_DESCRIPTION = "<script>alert(1)</script> & \"q\" 'a' \u200f RTL\nline two <img src=http://x/y.png>"
HOSTILE_TITLE = "<script>alert('t')</script> & \"quoted\" \u200fRTL\nline <b>two</b>"
# Characters whose names are markup's own: each a copy of 一's hanzi-writer-data file (docs/corpus.md: a data
# folder's files are `<character>.json` by one code point, white space and control characters excepted).
HOSTILE_CHARACTERS = ["<", "&", "\"", "'", "\u200f"]
PROTOCOL = {"name": "r16f", "description": HOSTILE_DESCRIPTION,
            "conditions": [{"name": "V", "mode": "vision"}, {"name": "H", "mode": "haptic"}],
            "test": {"characters": [YI, SHI], "conditions": ["V", "H"], "repetitions": 1},
            "trial": {"max_duration_s": 8}}
HOSTILE = {"name": "r16fh", "conditions": [{"name": "V", "mode": "vision"}],
           "test": {"characters": HOSTILE_CHARACTERS, "conditions": ["V"], "repetitions": 1},
           "trial": {"max_duration_s": 5}}
# One trial too short for the simulated writer to reach the paper: it ends at its time limit having written nothing.
NOTHING = {"name": "r16f0", "conditions": [{"name": "V", "mode": "vision"}],
           "test": {"characters": [SHI], "conditions": ["V"], "repetitions": 1}, "trial": {"max_duration_s": 0.02}}
VOID = {"area", "base", "br", "col", "embed", "hr", "img", "input", "link", "meta", "source", "track", "wbr"}
BAD_WORDS = re.compile(r"(?<![\w-])(nan|NaN|-nan|inf|-inf|Infinity|None|null|undefined)(?![\w-])")
SHARED = {}
# Three subjects: the fewest a mixed model is fitted for, so that its row says why it is not (no Rscript).
SUBJECTS = 3


def cli(args, cwd, ok=True):
    result = run(args, cwd)
    if ok and result.returncode != 0:
        raise AssertionError(f"calligraphy {' '.join(map(str, args))}: {result.returncode}\n"
                             f"{result.stderr.decode('utf-8', 'replace')}")
    return result


def study_report(args, cwd):
    """`python3 -m calligraphy.study_report ARGS` with no Rscript on PATH (docs/experiments.md: its rows say why)."""
    env = {k: v for k, v in os.environ.items() if k not in ("DISPLAY", "WAYLAND_DISPLAY")}
    env["PATH"] = str(Path(cwd) / "no-programs")
    env["MPLBACKEND"] = "Agg"
    return subprocess.run([sys.executable, "-m", "calligraphy.study_report", *map(str, args)], cwd=cwd, env=env,
                          stdout=subprocess.PIPE, stderr=subprocess.PIPE, stdin=subprocess.DEVNULL, timeout=120)


def tree_digest(folder):
    """Every file and folder under `folder` with its bytes' SHA-256 (a link by its target)."""
    found = {}
    for path in sorted(Path(folder).rglob("*")):
        rel = str(path.relative_to(folder))
        if path.is_symlink():
            found[rel] = "link " + os.readlink(path)
        elif path.is_dir():
            found[rel] = "dir"
        else:
            found[rel] = hashlib.sha256(path.read_bytes()).hexdigest()
    return found


class Page(HTMLParser):
    """One HTML page as a strict reader takes it: tags balanced (void elements aside), and what a reviewer checks."""

    def __init__(self, text):
        super().__init__(convert_charrefs=True)
        self.stack, self.errors, self.starts = [], [], []
        self.title, self.in_title, self.charset = "", False, None
        self.links, self.images, self.ids, self.scripts = [], [], set(), 0
        self.texts, self.tables, self.cells, self.headers = [], [], [], []
        self._row, self._cell, self._table = None, None, None
        self.feed(text)
        self.close()
        if self.stack:
            self.errors.append(f"unclosed at the end: {self.stack}")

    def handle_starttag(self, tag, attrs):
        a = dict(attrs)
        self.starts.append((tag, a))
        if tag == "script":
            self.scripts += 1
        if "id" in a:
            self.ids.add(a["id"])
        if tag == "meta" and "charset" in a:
            self.charset = a["charset"]
        if tag == "meta" and a.get("http-equiv", "").lower() == "content-type":
            self.charset = a.get("content", "").split("charset=")[-1]
        for key in ("href", "src", "xlink:href", "action", "poster", "data"):
            if key in a and a[key] is not None:
                (self.images if tag == "img" and key == "src" else self.links).append((tag, a[key]))
        if tag == "img":
            self.images_alt = getattr(self, "images_alt", []) + [a.get("alt")]
        if tag == "title" and not self.stack[-1:] == ["svg"]:
            self.in_title = "svg" not in self.stack
        if tag == "table":
            self._table = {"th": 0, "rows": [], "head": []}
            self.tables.append(self._table)
        if tag == "tr" and self._table is not None:
            self._row = []
            self._table["rows"].append(self._row)
        if tag in ("td", "th") and self._row is not None:
            self._cell = [tag, "", a]
            self._row.append(self._cell)
            if tag == "th":
                self._table["th"] += 1
        if tag not in VOID:
            self.stack.append(tag)

    def handle_startendtag(self, tag, attrs):
        self.handle_starttag(tag, attrs)
        if tag not in VOID and self.stack and self.stack[-1] == tag:
            self.stack.pop()

    def handle_endtag(self, tag):
        if tag in VOID:
            return
        if not self.stack or self.stack[-1] != tag:
            self.errors.append(f"</{tag}> closes {self.stack[-1:]} at line {self.getpos()[0]}")
            if tag in self.stack:
                while self.stack and self.stack.pop() != tag:
                    pass
            return
        self.stack.pop()
        if tag == "title":
            self.in_title = False
        if tag in ("td", "th"):
            self._cell = None
        if tag == "table":
            self._table, self._row = None, None

    def handle_data(self, data):
        if self.in_title:
            self.title += data
        if self._cell is not None:
            self._cell[1] += data
        if not ({"style", "script"} & set(self.stack)):
            self.texts.append(data)


def read_page(path):
    data = Path(path).read_bytes()
    return Page(data.decode("utf-8")), data.decode("utf-8")


def inline_svgs(text):
    return re.findall(r"<svg\b.*?</svg>", text, flags=re.S)


def table_rows(path):
    with open(path, newline="", encoding="utf-8") as f:
        return list(csv.DictReader(f))


def close_to(printed, value, scale=1.0):
    """`printed` (text as the page shows it) is `value` x `scale` within half a unit of its last digit."""
    digits = len(printed.split(".")[1]) if "." in printed else 0
    return abs(float(printed) - value * scale) <= 0.5 * 10 ** -digits + 1e-9


def setUpModule():
    root = Path(tempfile.mkdtemp(prefix="r16f-"))
    SHARED["root"] = root
    (root / "no-programs").mkdir()
    data = root / "hd"
    data.mkdir()
    for name in HOSTILE_CHARACTERS:
        shutil.copy(SAMPLE / f"{YI}.json", data / f"{name}.json")
    for name, protocol in (("p.json", PROTOCOL), ("h.json", HOSTILE), ("n.json", NOTHING)):
        (root / name).write_text(__import__("json").dumps(protocol, ensure_ascii=False), encoding="utf-8")
    cli(["session", "run", "p.json", "--writer", "simulated", "--subjects", str(SUBJECTS), "--out", "study"], root)
    cli(["session", "run", "h.json", "--writer", "simulated", "--subjects", "1", "--out", "hostile",
         "--data", str(data)], root)
    cli(["session", "run", "n.json", "--writer", "simulated", "--subjects", "1", "--out", "nothing"], root)
    # A session that saved no trial yet: the first session's folder, its plan and no record.
    first = sorted((root / "study" / "S01").iterdir())[0]
    stopped = root / "stopped" / "S01" / first.name
    shutil.copytree(first, stopped)
    for record in (stopped / "trials").iterdir():
        record.unlink()
    shutil.copy(root / "study" / ".calligraphy-study.json", root / "stopped" / ".calligraphy-study.json")
    (root / "empty").mkdir()
    SHARED["study_before"] = tree_digest(root / "study")
    for folder in ("site", "tables", "hsite", "nsite", "ssite", "esite", "odd site"):
        (root / folder).mkdir()
    SHARED["report"] = cli(["report", "study", "--out", "site/trials.html", "--csv", "tables", "--jobs", "1"], root)
    SHARED["site_first"] = tree_digest(root / "site")
    SHARED["report_again"] = cli(["report", "study", "--out", "site/trials.html", "--jobs", "1"], root)
    SHARED["hostile_report"] = cli(["report", "hostile", "--out", "hsite/h.html", "--jobs", "1"], root)
    SHARED["nothing_report"] = cli(["report", "nothing", "--out", "nsite/n.html", "--csv", "nsite", "--jobs", "1"],
                                   root)
    SHARED["stopped_report"] = cli(["report", "stopped", "--out", "ssite/s.html", "--jobs", "1"], root, ok=False)
    SHARED["empty_report"] = cli(["report", "empty", "--out", "esite/e.html", "--jobs", "1"], root, ok=False)
    SHARED["odd_name"] = "r #1 & b?%20.html"
    SHARED["odd_report"] = cli(["report", "study", "--out", f"odd site/{SHARED['odd_name']}", "--jobs", "1"], root)
    SHARED["study_after"] = tree_digest(root / "study")
    if SANITIZED:  # the five cases kept there read no study report (Python, not the sanitized program)
        return
    SHARED["paper"] = study_report(["study", "--out", "site/paper", "--per-trial-page", "site/trials.html",
                                    "--analyse", "all", "--title", HOSTILE_TITLE], root)
    SHARED["paper_first"] = tree_digest(root / "site" / "paper")
    SHARED["paper_again"] = study_report(["study", "--out", "site/paper", "--per-trial-page", "site/trials.html",
                                          "--analyse", "all", "--title", HOSTILE_TITLE], root)
    SHARED["paper_nothing"] = study_report(["nothing", "--out", "nsite/paper", "--per-trial-page", "nsite/n.html"],
                                           root)
    SHARED["study_after"] = tree_digest(root / "study")


def tearDownModule():
    shutil.rmtree(SHARED["root"], ignore_errors=True)


def trial_pages(site, index_name):
    index = site / index_name
    return [index, *sorted((site / (index.stem + "_files")).rglob("*.html"))]


class TrialPages(OneErrorLine, unittest.TestCase):
    """`calligraphy report --out`: the index and one page per session."""

    def setUp(self):
        self.root = SHARED["root"]
        self.site = self.root / "site"
        self.pages = trial_pages(self.site, "trials.html")

    def test_trial_pages_are_well_formed_html(self):
        self.assertEqual(len(self.pages), 1 + SUBJECTS, self.pages)
        for path in self.pages + trial_pages(self.root / "hsite", "h.html") + trial_pages(self.root / "nsite",
                                                                                          "n.html"):
            page, text = read_page(path)
            self.assertEqual(page.errors, [], path)
            self.assertTrue(text.startswith("<!DOCTYPE html>"), path)
            self.assertEqual(page.scripts, 0, path)

    def test_trial_pages_declare_utf8_and_have_titles(self):
        for path in self.pages:
            page, _ = read_page(path)
            self.assertEqual((page.charset or "").lower(), "utf-8", path)
            self.assertTrue(page.title.strip(), f"{path}: no title")
            self.assertIn("r16f", page.title, path)
            self.assertTrue(any(tag == "html" and a.get("lang") for tag, a in page.starts), f"{path}: no lang")

    def test_trial_pages_load_nothing_from_outside(self):
        for path in self.pages:
            page, text = read_page(path)
            for tag, target in page.links + page.images:
                parts = urlsplit(target)
                self.assertEqual(parts.scheme, "", f"{path}: <{tag}> {target}")
                self.assertEqual(parts.netloc, "", f"{path}: <{tag}> {target}")
                self.assertFalse(parts.path.startswith("/"), f"{path}: <{tag}> {target}")
                if parts.path:
                    resolved = (path.parent / unquote(parts.path)).resolve()
                    self.assertTrue(resolved.is_relative_to(self.site.resolve()), f"{path}: {target} leaves the site")
            self.assertNotRegex(text, r"url\(|@import|<link\b|<iframe|<object|<embed", path)

    def test_every_link_of_the_trial_pages_resolves(self):
        pointed = set()
        for path in self.pages:
            page, _ = read_page(path)
            for tag, target in page.links:
                parts = urlsplit(target)
                goal = (path.parent / unquote(parts.path)).resolve() if parts.path else path.resolve()
                self.assertTrue(goal.is_file(), f"{path}: <{tag} href={target}> names nothing")
                pointed.add(goal)
                if parts.fragment:
                    self.assertIn(unquote(parts.fragment), read_page(goal)[0].ids, f"{path}: {target}")
        for session_page in self.pages[1:]:
            self.assertIn(session_page.resolve(), pointed, "the index links every session page")
        self.assertIn(self.pages[0].resolve(), pointed, "each session page links back to the index")

    def test_every_trial_has_its_article_numbered_as_its_files(self):
        for session in sorted((self.root / "study").glob("S*/*")):
            page_path = self.site / "trials_files" / session.parent.name / f"{session.name}.html"
            page, text = read_page(page_path)
            records = sorted((session / "trials").glob("[0-9][0-9][0-9]-*.json"))
            expected = {f"trial-{session.name}-{int(r.name[:3])}" for r in records}
            articles = {a["id"] for tag, a in page.starts if tag == "article"}
            self.assertEqual(articles, expected, page_path)

    def test_inline_figures_are_well_formed_svg_with_an_accessible_name(self):
        for path in self.pages[1:]:
            _, text = read_page(path)
            svgs = inline_svgs(text)
            self.assertEqual(len(svgs), 2 * 4, f"{path}: a trajectory and a force figure per trial")
            for svg in svgs:
                root = ET.fromstring(svg)
                named = root.get("aria-label") or root.get("aria-labelledby") or root.find(
                    "{http://www.w3.org/2000/svg}title") is not None
                self.assertTrue(named, f"{path}: an inline figure with no accessible name: {svg[:120]}")
                title = root.find("{http://www.w3.org/2000/svg}title")
                if title is not None:
                    self.assertTrue((title.text or "").strip(), path)

    def test_trajectory_figure_colours_as_documented(self):
        """docs/experiments.md: reference strokes blue, pen-down trace green, stroke starts red."""
        def hue(colour):
            r, g, b = (int(colour[i:i + 2], 16) / 255 for i in (1, 3, 5))
            return colorsys.rgb_to_hsv(r, g, b)[0] * 360

        _, text = read_page(self.pages[1])
        for svg in inline_svgs(text):
            root = ET.fromstring(svg)
            if "trajectory" not in text[text.rfind("<figure", 0, text.find(svg)):text.find(svg)]:
                continue
            polylines = [e.get("stroke") for e in root.iter("{http://www.w3.org/2000/svg}polyline")]
            starts = [e.get("stroke") or e.get("fill") for e in root.iter()
                      if e.tag.split("}")[1] in ("ellipse", "circle")]
            hues = {round(hue(c) / 60) * 60 % 360 for c in polylines if c and c.startswith("#")}
            self.assertEqual(hues, {240, 120}, f"blue reference and green pen: {polylines}")
            self.assertTrue(starts and all(c.startswith("#") and round(hue(c) / 60) * 60 % 360 == 0 for c in starts),
                            f"red starts: {starts}")

    def test_force_figure_axes_in_seconds_and_newtons_strokes_numbered_from_1(self):
        page_path = self.pages[1]
        _, text = read_page(page_path)
        forces = [s for s in inline_svgs(text) if "N</text>" in s or " N<" in s]
        self.assertEqual(len(forces), 4, page_path)
        rows = {int(r["trial"]): r for r in table_rows(self.root / "tables" / "trials.csv")
                if r["session"] == page_path.stem}
        for number, svg in enumerate(forces, 1):
            labels = [(e.text or "").strip() for e in ET.fromstring(svg).iter("{http://www.w3.org/2000/svg}text")]
            self.assertTrue(any(re.fullmatch(r"[0-9.]+ N", t) for t in labels), labels)
            self.assertTrue(any(re.fullmatch(r"[0-9.]+ s", t) for t in labels), labels)
            self.assertIn("time", labels)
            strokes = sorted(int(t) for t in labels if t.isdigit() and t != "0")
            total = int(rows[number]["strokes_written"])
            self.assertEqual(strokes, list(range(1, total + 1)), f"trial {number}: stroke spans numbered from 1")
            self.assertFalse([t for t in labels if BAD_WORDS.search(t)], labels)

    def test_trial_values_equal_the_tables(self):
        rows = {(r["session"], int(r["trial"])): r for r in table_rows(self.root / "tables" / "trials.csv")}
        checked = 0
        for path in self.pages[1:]:
            _, text = read_page(path)
            for session, number, body in re.findall(r'<article[^>]*id="trial-(.*?)-(\d+)"[^>]*>(.*?)</article>', text,
                                                    re.S):
                row = rows[(session, int(number))]
                metrics = html.unescape(re.sub(r"<[^>]+>", "", re.search(r'<p class="metrics">(.*?)</p>', body,
                                                                           re.S).group(1)))
                found = dict(re.findall(r"([A-Za-zé ]+?)\s+(-?[0-9.]+) mm", metrics))
                time_s = re.match(r"\s*(-?[0-9.]+) s\b", metrics).group(1)
                self.assertTrue(close_to(time_s, float(row["total_time_s"])), f"{session} #{number}: {metrics}")
                for label, column in (("deviation", "mean_deviation_m"), ("Fréchet", "frechet_m"), ("DTW", "dtw_m")):
                    key = next(k for k in found if k.strip().endswith(label))
                    self.assertTrue(close_to(found[key], float(row[column]), 1000), f"{label}: {metrics} {row[column]}")
                for label, column in (("order errors", "order_errors"), ("backwards", "backwards_strokes")):
                    self.assertEqual(int(re.search(label + r" (\d+)", metrics).group(1)), int(row[column]), metrics)
                if row["end_reason"] != "completed":
                    self.assertIn(row["end_reason"], metrics, "how it ended when it did not complete")
                checked += 1
        self.assertEqual(checked, len(rows))

    def test_no_nan_inf_none_or_unexplained_empty_cell_on_trial_pages(self):
        for path in self.pages + trial_pages(self.root / "nsite", "n.html"):
            page, _ = read_page(path)
            words = [t for t in page.texts if BAD_WORDS.search(t)]
            self.assertEqual(words, [], path)
            for table in page.tables:
                head = [c[1].strip() for c in table["rows"][0]] if table["rows"] else []
                for row in table["rows"][1:]:
                    for column, cell in zip(head, row):
                        self.assertTrue(cell[1].strip(), f"{path}: an empty '{column}' cell says nothing of why")

    def test_tables_have_header_cells(self):
        pages = self.pages + [self.site / "paper" / "index.html"]
        for path in pages:
            page, _ = read_page(path)
            for table in page.tables:
                self.assertTrue(table["rows"] and all(c[0] == "th" for c in table["rows"][0]),
                                f"{path}: a table whose first row is not its header")

    def test_report_run_again_over_itself_writes_the_same_set_and_nothing_else(self):
        now = {k: v for k, v in tree_digest(self.site).items() if not k.startswith("paper")}
        self.assertEqual(now, SHARED["site_first"])
        names = {p.name for p in self.site.iterdir()}
        self.assertEqual(names, {"trials.html", "trials_files", "paper"})
        leftovers = [p for p in self.root.rglob("*") if re.search(r"\.tmp|\.partial\.|journal|~$", p.name)]
        self.assertEqual(leftovers, [])

    def test_study_folder_unchanged_by_every_report(self):
        self.assertEqual(SHARED["study_after"], SHARED["study_before"])
        for name in ("report", "report_again"):
            self.assertEqual(SHARED[name].stdout.count(b"\n") >= 1, True)
            self.assertEqual(SHARED[name].stderr, b"", name)

    def test_out_named_with_space_hash_ampersand_and_percent_links_resolve(self):
        odd = self.root / "odd site"
        self.assertEqual(SHARED["odd_report"].returncode, 0)
        index = odd / SHARED["odd_name"]
        files = odd / (index.name[:-len(".html")] + "_files")
        self.assertTrue(index.is_file() and files.is_dir(), sorted(p.name for p in odd.iterdir()))
        page, _ = read_page(index)
        targets = [t for tag, t in page.links if tag == "a"]
        self.assertEqual(len(targets), SUBJECTS, targets)
        for target in targets:
            parts = urlsplit(target)
            self.assertEqual((parts.scheme, parts.netloc, parts.query), ("", "", ""), target)
            goal = index.parent / unquote(parts.path)
            self.assertTrue(goal.is_file() and goal.parent.parent == files, f"{target} names {goal}")
            back = [t for tag, t in read_page(goal)[0].links if not t.startswith("#")]
            self.assertTrue(back, goal)
            for link in back:
                self.assertEqual((goal.parent / unquote(urlsplit(link).path)).resolve(), index.resolve(), link)


class NamesAndFigures(OneErrorLine, unittest.TestCase):
    """Names that are markup's own, and the SVGs of `trial --svg`, the session folders and `model --svg`."""

    def setUp(self):
        self.root = SHARED["root"]

    def test_characters_named_like_markup_show_as_text_on_the_trial_pages(self):
        pages = trial_pages(self.root / "hsite", "h.html")
        self.assertEqual(len(pages), 2)
        page, text = read_page(pages[1])
        self.assertEqual(page.errors, [])
        self.assertEqual(page.scripts, 0)
        glyphs = [t for tag, a in page.starts if tag == "span" and a.get("class") == "glyph" for t in [a]]
        shown = re.findall(r'<span class="glyph">(.*?)</span>', text, re.S)
        self.assertEqual([html.unescape(s) for s in shown], HOSTILE_CHARACTERS, glyphs)
        for svg in inline_svgs(text):
            ET.fromstring(svg)
        self.assertEqual({tag for tag, _ in page.starts} & {"img", "script", "iframe"}, set())

    def test_session_json_edited_to_names_of_markup_is_refused(self):
        """A subject id of markup is refused at its JSON pointer (its alphabet, docs/cli.md), and a group edited
        to markup at its own (not the group the protocol copy gives the subject, docs/experiments.md); nothing
        written."""
        import json
        for key, pointer in (("subject", "/subject/id"), ("group", "/group")):
            study = self.root / f"edited-{key}"
            shutil.copytree(self.root / "study", study)
            session = sorted(study.glob("S01/*/session.json"))[0]
            document = json.loads(session.read_text(encoding="utf-8"))
            if key == "subject":
                document["subject"]["id"] = "<b>S</b>&\""
            else:
                document["group"] = "<i>g</i>&\""
            session.write_text(json.dumps(document, ensure_ascii=False), encoding="utf-8")
            site = self.root / f"edited-{key}-site"
            site.mkdir()
            result = run(["report", study, "--out", site / "t.html", "--jobs", "1"], self.root)
            self.assert_one_error(result, 1, "session.json", pointer)
            self.assertEqual(list(site.iterdir()), [])

    def test_protocol_description_never_becomes_markup(self):
        for path in trial_pages(SHARED["root"] / "site", "trials.html") + [self.root / "site/paper/index.html"]:
            page, text = read_page(path)
            self.assertEqual(page.scripts, 0, path)
            self.assertNotIn("<img src=http", text, path)
            self.assertNotIn("alert(1)</script>", text, path)

    def test_session_and_trial_svgs_of_characters_named_like_markup_are_well_formed(self):
        svgs = sorted((self.root / "hostile").glob("S01/*/trials/*.svg"))
        self.assertEqual(len(svgs), len(HOSTILE_CHARACTERS))
        for path in svgs:
            root = ET.parse(path).getroot()
            self.assertEqual(root.tag, "{http://www.w3.org/2000/svg}svg", path)
            text = path.read_text(encoding="utf-8")
            self.assertNotRegex(text, r"(href|src)=\"(https?:|//|/)", path)
        for name in HOSTILE_CHARACTERS[:3]:
            out = self.root / f"trial-{ord(name):x}.svg"
            cli(["trial", name, "--data", "hd", "--svg", out, "--max-duration", "8"], self.root)
            root = ET.parse(out).getroot()
            colours = {e.get("stroke") for e in root.iter() if e.get("stroke")}
            self.assertTrue({"blue", "green"} <= colours or len(colours) >= 2, colours)

    def test_model_svg_of_characters_named_like_markup_is_well_formed(self):
        for name in HOSTILE_CHARACTERS:
            out = self.root / f"model-{ord(name):x}.svg"
            cli(["model", name, "--data", "hd", "--svg", out], self.root)
            try:
                root = ET.parse(out).getroot()
            except ET.ParseError as e:
                self.fail(f"model {name!r} --svg: {e}")
            title = root.find("{http://www.w3.org/2000/svg}title")
            self.assertIsNotNone(title)
            self.assertIn(name, title.text)
            self.assertIn(f"U+{ord(name):04X}", title.text)

    def test_model_svg_is_well_formed_with_strokes_numbered_from_1(self):
        out = self.root / "shi-model.svg"
        cli(["model", SHI, "--svg", out], self.root)
        root = ET.parse(out).getroot()
        numbers = [e.text.strip() for e in root.iter("{http://www.w3.org/2000/svg}text")
                   if "stroke-number" in (e.get("class") or "")]
        self.assertEqual(numbers, ["1", "2"])
        text = out.read_text(encoding="utf-8")
        self.assertTrue(text.startswith("<?xml") and "UTF-8" in text.splitlines()[0])
        self.assertNotRegex(text, r"(href|src)=\"(https?:|//|/)")
        self.assertFalse(BAD_WORDS.search(" ".join(e.text or "" for e in root.iter())))

    def test_docs_images_exist_open_and_are_not_blank(self):
        from PIL import Image
        named = set()
        for doc in [SOURCE / "README.md", *sorted((SOURCE / "docs").glob("*.md"))]:
            for target in re.findall(r"!\[[^\]]*\]\(([^)\s]+)\)", doc.read_text(encoding="utf-8")):
                path = (doc.parent / target).resolve()
                self.assertTrue(path.is_file(), f"{doc.name}: {target}")
                named.add(path)
        self.assertTrue(named)
        for path in named:
            with Image.open(path) as image:
                image.verify()
            with Image.open(path) as image:
                small = image.convert("RGB").resize((64, 64))
                self.assertGreater(len(set(small.getdata())), 8, f"{path}: blank")


class EdgeStudies(OneErrorLine, unittest.TestCase):
    """An empty study, a session that saved no trial, a study of one trial that wrote nothing."""

    def setUp(self):
        self.root = SHARED["root"]

    def test_empty_study_is_refused_in_one_line_and_nothing_is_written(self):
        self.assert_one_error(SHARED["empty_report"], 1, "empty", "session")
        self.assertEqual(list((self.root / "esite").iterdir()), [])

    def test_session_that_saved_no_trial_has_a_page_saying_so(self):
        result = SHARED["stopped_report"]
        self.assertEqual(result.returncode, 0, result.stderr)
        pages = trial_pages(self.root / "ssite", "s.html")
        self.assertEqual(len(pages), 2)
        for path in pages:
            page, text = read_page(path)
            self.assertEqual(page.errors, [], path)
            self.assertFalse([t for t in page.texts if BAD_WORDS.search(t)], path)
        index_text = " ".join(read_page(pages[0])[0].texts)
        self.assertRegex(index_text, r"\b0 of 4\b")
        session_text = " ".join(read_page(pages[1])[0].texts)
        self.assertRegex(session_text, r"(?i)no trial|0 of 4")

    def test_trial_that_wrote_nothing_shows_a_dash_for_its_time_and_deviation(self):
        rows = table_rows(self.root / "nsite" / "trials.csv")
        self.assertEqual(len(rows), 1)
        self.assertEqual(rows[0]["end_reason"], "time_limit")
        self.assertEqual(rows[0]["mean_deviation_m"], "", "it wrote nothing")
        pages = trial_pages(self.root / "nsite", "n.html")
        self.assertEqual(len(pages), 2)
        page, text = read_page(pages[1])
        metrics = html.unescape(re.sub(r"<[^>]+>", "", re.search(r'<p class="metrics">(.*?)</p>', text, re.S).group(1)))
        # The pen never touched: no first or last pen-down sample, so no writing time (docs/metrics.md:
        # total_time_s is null then), a dash as for the deviation.
        self.assertRegex(metrics, r"^\s*(-|–|—) s\b", "no writing time")
        self.assertRegex(metrics, r"deviation\s+(-|–|—)", "a dash for what it lacks")
        self.assertIn("time_limit", metrics)
        self.assertEqual([t for t in page.texts if BAD_WORDS.search(t)], [])
        self.assertEqual(len(inline_svgs(text)), 2)
        for svg in inline_svgs(text):
            ET.fromstring(svg)

    def test_study_report_of_one_trial_that_wrote_nothing_says_so(self):
        result = SHARED["paper_nothing"]
        self.assertEqual(result.returncode, 0, result.stderr.decode())
        self.assertNotIn(b"Traceback", result.stderr)
        index = self.root / "nsite" / "paper" / "index.html"
        page, text = read_page(index)
        self.assertEqual(page.errors, [])
        words = " ".join(page.texts)
        self.assertFalse(BAD_WORDS.findall(words), BAD_WORDS.findall(words))
        self.assertRegex(words, r"0 of 1 trials? analysed")
        self.assertEqual(result.stderr.decode(), "", "no library's warning on standard error")
        for table in page.tables:
            self.assertGreater(len(table["rows"]), 1, f"a table of no row that does not say why: {table['rows']}")
        for path in (self.root / "nsite" / "paper" / "figures").glob("*.svg"):
            ET.parse(path)


class StudyReport(OneErrorLine, unittest.TestCase):
    """`python3 -m calligraphy.study_report`: index.html, figures/ and tables/."""

    def setUp(self):
        self.root = SHARED["root"]
        self.paper = self.root / "site" / "paper"
        self.index = self.paper / "index.html"

    def test_study_report_ran_in_one_line_without_r(self):
        result = SHARED["paper"]
        self.assertEqual(result.returncode, 0, result.stderr.decode())
        self.assertEqual(result.stderr.decode(), "", "no warning of a library on standard error")
        self.assertEqual(len(result.stdout.decode().strip().splitlines()), 1)
        self.assertIn("Rscript is not installed", " ".join(read_page(self.index)[0].texts))

    def test_study_report_is_well_formed_with_utf8_and_a_title(self):
        page, text = read_page(self.index)
        self.assertEqual(page.errors, [])
        self.assertEqual((page.charset or "").lower(), "utf-8")
        self.assertTrue(text.startswith("<!DOCTYPE html>"))
        self.assertEqual(page.scripts, 0)
        for tag, a in page.starts:
            if tag == "img":
                self.assertTrue((a.get("alt") or "").strip(), f"<img src={a.get('src')}> without alt text")

    def test_study_report_hostile_title_is_text(self):
        page, text = read_page(self.index)
        self.assertEqual(" ".join(page.title.split()), " ".join(HOSTILE_TITLE.split()))
        self.assertEqual(page.scripts, 0)
        self.assertNotIn("<b>two</b>", text)
        heading = re.search(r"<h1>(.*?)</h1>", text, re.S).group(1)
        self.assertEqual(" ".join(html.unescape(heading).split()), " ".join(HOSTILE_TITLE.split()))

    def test_study_report_links_and_images_are_present_and_inside(self):
        page, _ = read_page(self.index)
        per_trial = (self.root / "site" / "trials.html").resolve()
        per_trial_files = (self.root / "site" / "trials_files").resolve()
        self.assertTrue(page.images)
        for tag, target in page.links + page.images:
            parts = urlsplit(target)
            if not parts.path:
                self.assertIn(parts.fragment, page.ids, target)
                continue
            self.assertEqual((parts.scheme, parts.netloc), ("", ""), target)
            goal = (self.index.parent / unquote(parts.path)).resolve()
            self.assertTrue(goal.exists(), f"<{tag}> {target} names nothing")
            inside = goal.is_relative_to(self.paper.resolve())
            self.assertTrue(inside or goal == per_trial or goal.is_relative_to(per_trial_files),
                            f"{target} leaves the report's folder and is no per-trial page")
            if parts.fragment:
                self.assertIn(parts.fragment, read_page(goal)[0].ids, target)

    def test_study_report_links_a_per_trial_page_named_with_space_hash_ampersand_and_percent(self):
        odd = self.root / "odd site" / SHARED["odd_name"]
        result = study_report(["study", "--out", "odd-paper", "--per-trial-page", odd, "--analyse", "all"], self.root)
        self.assertEqual(result.returncode, 0, result.stderr.decode())
        index = self.root / "odd-paper" / "index.html"
        page, _ = read_page(index)
        outside = [t for _, t in page.links if "odd" in t]
        self.assertGreater(len(outside), 3 * 4, outside)
        for target in outside:
            parts = urlsplit(target)
            self.assertEqual((parts.scheme, parts.netloc, parts.query), ("", "", ""), target)
            goal = (index.parent / unquote(parts.path)).resolve()
            self.assertTrue(goal.is_file(), f"{target} names nothing")
            self.assertTrue(goal == odd.resolve() or goal.parent.parent.name == odd.name[:-5] + "_files", target)
            if parts.fragment:
                self.assertIn(parts.fragment, read_page(goal)[0].ids, target)

    def test_study_report_figures_are_svg_and_150_dpi_png_not_blank(self):
        from PIL import Image
        figures = sorted((self.paper / "figures").glob("*.svg"))
        self.assertEqual({p.stem for p in figures}, {f"{kind}_{value}" for kind in ("phase", "learning")
                                                     for value in ("total_time_s", "mean_deviation_m")})
        for svg in figures:
            root = ET.parse(svg).getroot()
            width_pt = float(root.get("width").removesuffix("pt"))
            height_pt = float(root.get("height").removesuffix("pt"))
            hrefs = [v for e in root.iter() for k, v in e.attrib.items() if k.endswith("href")]
            self.assertFalse([h for h in hrefs if not h.startswith("#")], svg)
            png = svg.with_suffix(".png")
            with Image.open(png) as image:
                image.verify()
            with Image.open(png) as image:
                self.assertEqual(image.format, "PNG")
                self.assertAlmostEqual(image.width, width_pt / 72 * 150, delta=2, msg=png)
                self.assertAlmostEqual(image.height, height_pt / 72 * 150, delta=2, msg=png)
                pixels = image.convert("L").resize((100, 100))
                dark = sum(1 for v in pixels.getdata() if v < 200)
                self.assertGreater(dark, 100, f"{png}: next to blank")

    def test_study_report_figure_axes_are_named_with_units(self):
        units = {"total_time_s": "[s]", "mean_deviation_m": "[mm]"}
        for svg in sorted((self.paper / "figures").glob("*.svg")):
            labels = re.findall(r"<!-- (.*?) -->", svg.read_text(encoding="utf-8"))
            value = svg.stem.split("_", 1)[1]
            self.assertTrue(any(units[value] in label for label in labels), f"{svg.name}: {labels}")
            if svg.stem.startswith("learning"):
                self.assertIn("repetition", labels)
            self.assertFalse([t for t in labels if BAD_WORDS.search(t)], svg)

    def test_learning_curves_count_whole_repetitions_from_1(self):
        """docs/experiments.md: the learning curves' x axis is the tables' repetition, counted from 1 (here one
        repetition: a tick at 1, never 0.64 or 1.04)."""
        for value in ("total_time_s", "mean_deviation_m"):
            text = (self.paper / "figures" / f"learning_{value}.svg").read_text(encoding="utf-8")
            ticks = re.findall(r'<g id="xtick_\d+">.*?<!-- (.*?) -->', text, re.S)
            self.assertTrue(ticks, value)
            self.assertEqual(set(ticks), {"1"}, f"learning_{value}.svg: x ticks {ticks}")

    def test_study_report_numbers_equal_the_tables(self):
        trials = table_rows(self.root / "tables" / "trials.csv")
        means = table_rows(self.paper / "tables" / "phase_means.csv")
        _, text = read_page(self.index)
        for value, scale in (("total_time_s", 1), ("mean_deviation_m", 1000)):
            table = re.search(rf'<table class="phase-means" data-value="{value}">(.*?)</table>', text, re.S).group(1)
            head = [html.unescape(re.sub("<[^>]+>", "", h)).replace(" (control)", "")
                    for h in re.findall(r"<th>(.*?)</th>", table.split("</thead>")[0])]
            for row in re.findall(r"<tr><th>(.*?)</th>(.*?)</tr>", table, re.S):
                phase, cells = row
                for condition, cell in zip(head[1:], re.findall(r"<td[^>]*>(.*?)</td>", cells, re.S)):
                    shown = html.unescape(re.sub("<[^>]+>", "", cell))
                    mean, sd, n = re.fullmatch(r"\s*(-?[0-9.]+) ± (-?[0-9.]+) \((\d+)\)\s*", shown).groups()
                    line = next(m for m in means if (m["value"], m["phase"], m["condition"]) == (value, phase,
                                                                                               condition))
                    self.assertTrue(close_to(mean, float(line["mean"]), scale), (value, condition, shown, line))
                    self.assertTrue(close_to(sd, float(line["sd"]), scale), (value, condition, shown, line))
                    self.assertEqual(int(n), int(line["n"]))
                    by_subject = {}
                    for t in trials:
                        if t["condition"] == condition and t["phase"] == phase:
                            by_subject.setdefault(t["subject"], []).append(float(t[value]))
                    subject_means = [sum(v) / len(v) for v in by_subject.values()]
                    self.assertAlmostEqual(float(line["mean"]), sum(subject_means) / len(subject_means), places=12)
        rows = {(t["session"], t["trial"]): t for t in trials}
        listed = re.findall(r'href="[^"]*#trial-(.*?)-(\d+)">\d+</a></td>(.*?)</tr>', text, re.S)
        self.assertEqual(len(listed), len(rows))
        for session, number, rest in listed:
            cells = [html.unescape(re.sub("<[^>]+>", "", c)) for c in re.findall(r"<td[^>]*>(.*?)</td>", rest, re.S)]
            row = rows[(session, number)]
            self.assertTrue(close_to(cells[-2], float(row["total_time_s"])), (cells, row["total_time_s"]))
            self.assertTrue(close_to(cells[-1], float(row["mean_deviation_m"]), 1000), (cells, row["mean_deviation_m"]))

    def test_study_report_no_nan_inf_none_or_unexplained_empty_cell(self):
        page, _ = read_page(self.index)
        self.assertEqual([t for t in page.texts if BAD_WORDS.search(t)], [])
        for table in page.tables:
            head = [c[1].strip() for c in table["rows"][0]] if table["rows"] else []
            for row in table["rows"][1:]:
                for column, cell in zip(head, row):
                    if column == "note":
                        continue  # an empty note is no note
                    self.assertTrue(cell[1].strip(), f"an empty '{column}' cell says nothing of why")
        for path in (self.paper / "tables").glob("*.csv"):
            for row in table_rows(path):
                for key, value in row.items():
                    self.assertNotIn(value, ("nan", "NaN", "inf", "-inf", "None"), f"{path.name}: {key}")

    def test_study_report_run_again_over_itself_gives_the_same_set(self):
        result = SHARED["paper_again"]
        self.assertEqual(result.returncode, 0, result.stderr.decode())
        self.assertEqual(tree_digest(self.paper), SHARED["paper_first"])
        self.assertEqual({p.name for p in self.paper.iterdir()}, {"index.html", "figures", "tables"})


if __name__ == "__main__":
    unittest.main()
