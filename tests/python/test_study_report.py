"""calligraphy.study_report: the page holds a Table-5 table per value with a row per subject and character, the
statistics naming their tests, learning curves on one y axis, collapsed subject sections; every figure is an SVG
and a decodable PNG; the page is self-contained and reads summary first in Chromium; the command line names what
is wrong. A synthetic study whose condition effect is known needs no C++ session; one test runs a real one."""

import html.parser
import os
import shutil
import subprocess
import sys
import urllib.parse
import xml.etree.ElementTree as ElementTree
from pathlib import Path

import numpy as np
import pytest

pandas = pytest.importorskip("pandas")
pytest.importorskip("matplotlib")
pytest.importorskip("scipy")
pytest.importorskip("statsmodels")
import matplotlib.image  # noqa: E402

import calligraphy  # noqa: E402
import calligraphy.study  # noqa: E402
from calligraphy import study_report  # noqa: E402

SUBJECTS = 6
CHARACTERS = "大山木中"
CONDITIONS = ("vision", "haptic")
REPETITIONS = 3
VALUES = ("total_time_s", "mean_deviation_m")
# The planted effect of guidance: shorter and closer to the reference, as in Wang, Zhang & Yao 2006, Table 5.
HAPTIC_TIME_S = -2.0
HAPTIC_DEVIATION_M = -0.6e-3
CHROMIUM = "/usr/bin/chromium"


def synthetic_study(seed=2006, subjects=SUBJECTS, characters=CHARACTERS):
    """paper-table5's design with `subjects` subjects: 2 practice trials, then `characters` x CONDITIONS x
    REPETITIONS test trials (condition order alternating), with subject, character-within-subject, repetition
    and condition effects plus noise in SI units, and categorical columns as calligraphy.study.load gives them."""
    rng = np.random.default_rng(seed)
    rows = []
    for s in range(subjects):
        subject_time_s, subject_deviation_m = rng.normal(0.0, 1.0), rng.normal(0.0, 0.15e-3)
        haptic_time_s = HAPTIC_TIME_S + rng.normal(0.0, 0.6)
        haptic_deviation_m = HAPTIC_DEVIATION_M + rng.normal(0.0, 0.15e-3)
        # How this subject writes each character (the mixed model's character-within-subject intercepts).
        character_time_s = rng.normal(0.0, 0.8, len(characters))
        character_deviation_m = rng.normal(0.0, 0.15e-3, len(characters))
        order = CONDITIONS if s % 2 == 0 else CONDITIONS[::-1]
        common = {"subject": f"S{s + 1:02d}", "session": f"paper-table5-S{s + 1:02d}", "protocol": "paper-table5",
                  "writer": "simulated", "end_reason": "completed", "completed_in_order": True}
        trial = 0
        for repetition in range(2):
            rows.append({**common, "phase": "practice", "block": 0, "condition": "haptic", "mode": "haptic",
                         "characters": "永", "trial": trial, "item": 0, "repetition": repetition,
                         "total_time_s": 16.0 + rng.normal(0.0, 1.0), "mean_deviation_m": 1.2e-3})
            trial += 1
        for block, condition in enumerate(order, start=1):
            haptic = condition == "haptic"
            for item, character in enumerate(characters):
                for repetition in range(REPETITIONS):
                    rows.append({
                        **common, "phase": "test", "block": block, "condition": condition, "mode": condition,
                        "characters": character, "trial": trial, "item": item, "repetition": repetition,
                        "total_time_s": 12.0 + subject_time_s + character_time_s[item] + 0.8 * item
                        - 0.5 * repetition + haptic * haptic_time_s + rng.normal(0.0, 0.7),
                        "mean_deviation_m": 1.6e-3 + subject_deviation_m + character_deviation_m[item]
                        + haptic * haptic_deviation_m + rng.normal(0.0, 0.2e-3)})
                    trial += 1
    trials = pandas.DataFrame(rows)
    for column in ("subject", "session", "protocol", "phase", "condition", "mode", "writer", "end_reason"):
        trials[column] = trials[column].astype("category")
    return calligraphy.study.Study(trials=trials, strokes=pandas.DataFrame())


class _Page(html.parser.HTMLParser):
    """The parts of index.html the tests look at: tables (with their rows and cells), details, img, order."""

    def __init__(self):
        super().__init__()
        self.tables = []  # {"attrs", "colgroups", "rows": [{"section", "attrs", "cells"}]}
        self.details = []  # attrs of each <details>
        self.images = []
        self.links = []
        self.order = []  # ("section", id) and ("details", id) in document order
        self.scripts = 0
        self._section = None
        self._cell = None

    def handle_starttag(self, tag, attrs):
        attrs = dict(attrs)
        if tag == "table":
            self.tables.append({"attrs": attrs, "colgroups": [], "rows": []})
        elif tag == "colgroup":
            self.tables[-1]["colgroups"].append(attrs)
        elif tag in ("thead", "tbody", "tfoot"):
            self._section = tag
        elif tag == "tr":
            self.tables[-1]["rows"].append({"section": self._section, "attrs": attrs, "cells": []})
        elif tag in ("td", "th"):
            self._cell = []
        elif tag == "details":
            self.details.append(attrs)
            self.order.append(("details", attrs.get("id")))
        elif tag == "section":
            self.order.append(("section", attrs.get("id")))
        elif tag == "img":
            self.images.append(attrs)
        elif tag == "a":
            self.links.append(attrs.get("href"))
        elif tag == "script":
            self.scripts += 1

    def handle_endtag(self, tag):
        if tag in ("td", "th") and self._cell is not None:
            self.tables[-1]["rows"][-1]["cells"].append("".join(self._cell).strip())
            self._cell = None

    def handle_data(self, data):
        if self._cell is not None:
            self._cell.append(data)


def parse(text):
    page = _Page()
    page.feed(text)
    return page


@pytest.fixture(scope="module")
def study():
    return synthetic_study()


@pytest.fixture(scope="module")
def light_study():
    """Two subjects writing one character: for the cases on how a report's files are written, refused and
    waited for, which the study's size does not change (each report of it costs about a third of the CPU)."""
    return synthetic_study(subjects=2, characters=CHARACTERS[:1])


@pytest.fixture(scope="module")
def report(study, tmp_path_factory):
    out = tmp_path_factory.mktemp("report") / "new" / "report"  # the folder and its parent are created
    per_trial = out.parent / "trials.html"
    index = study_report.write_report(study, out, per_trial_page=per_trial)
    return index, parse(index.read_text(encoding="utf-8"))


def test_a_report_claims_only_the_folders_it_made(tmp_path, monkeypatch):
    # Two reports into one new folder: the one that fails removes the folders it made, never one the other made
    # between its check and its mkdir (as if the other report had made `out` first).
    made = []
    real_mkdir = os.mkdir

    def raced_mkdir(path, *args, **kwargs):
        if Path(path).name == "out":
            real_mkdir(path, *args, **kwargs)  # the other report, just before this one
        return real_mkdir(path, *args, **kwargs)

    monkeypatch.setattr(study_report.os, "mkdir", raced_mkdir)
    study_report._make_folder(tmp_path / "top" / "out" / "figures", made)
    assert made == [tmp_path / "top", tmp_path / "top" / "out" / "figures"]
    study_report._remove_made_folders(made)
    assert (tmp_path / "top" / "out").is_dir() and not (tmp_path / "top" / "out" / "figures").exists()
    monkeypatch.undo()
    (tmp_path / "file").write_text("x")
    with pytest.raises(OSError, match="cannot create the folder .*file/sub: .*file is a file"):
        study_report._make_folder(tmp_path / "file" / "sub", [])


def test_importing_the_module_imports_none_of_its_libraries():
    code = ("import sys, calligraphy.study_report; "
            "print(sorted(m for m in ('pandas', 'matplotlib', 'scipy', 'statsmodels') if m in sys.modules))")
    out = subprocess.run([sys.executable, "-c", code], check=True, capture_output=True, text=True).stdout
    assert out.strip() == "[]"


def test_a_table5_table_per_value_has_a_row_per_subject_and_character(study, report):
    index, page = report
    table5s = [t for t in page.tables if t["attrs"].get("class") == "table5"]
    assert [t["attrs"]["data-value"] for t in table5s] == list(VALUES)
    test = study.trials[study.trials.phase == "test"]
    for table in table5s:
        body = [row for row in table["rows"] if row["section"] == "tbody"]
        footer = [row for row in table["rows"] if row["section"] == "tfoot"]
        assert len(body) == SUBJECTS * len(CHARACTERS)
        assert len(footer) == 1
        assert sorted(g["data-condition"] for g in table["colgroups"] if g.get("class") == "condition") == sorted(
            CONDITIONS)
        # Each row ends in one cell per condition; the first row of a subject also names the subject.
        assert [len(row["cells"]) for row in body] == [
            1 + len(CONDITIONS) + (k % len(CHARACTERS) == 0) for k in range(len(body))]
        header = [row for row in table["rows"] if row["section"] == "thead"][0]["cells"]
        value = table["attrs"]["data-value"]
        scale = 1e3 if value.endswith("_m") else 1.0
        # S01's first character, each condition: the mean of its repetitions, in the display unit.
        first = test[(test.subject == "S01") & (test.characters == CHARACTERS[0])]
        for condition in CONDITIONS:
            expected = first[first.condition == condition][value].mean() * scale
            assert float(body[0]["cells"][header.index(condition)]) == pytest.approx(expected, abs=0.006)
        # The last row: mean +- SD over the subjects' means (n subjects).
        subject_means = test.groupby(["condition", "subject"], observed=True)[value].mean()
        for condition in CONDITIONS:
            cell = footer[0]["cells"][header.index(condition) - 1]
            mean_text, rest = cell.split("±")
            sd_text, n_text = rest.split()
            assert float(mean_text) == pytest.approx(subject_means[condition].mean() * scale, abs=0.006)
            assert float(sd_text) == pytest.approx(subject_means[condition].std() * scale, abs=0.006)
            assert n_text == f"({SUBJECTS})"
    assert "writing time [s]" in index.read_text(encoding="utf-8").lower()
    assert "mean deviation [mm]" in index.read_text(encoding="utf-8").lower()


def test_the_summary_csv_holds_the_table_in_si_units(study, report):
    index, _ = report
    summary = pandas.read_csv(index.parent / "tables" / "summary.csv", keep_default_na=False,
                              na_values={"mean": [""], "sd": [""]})
    for value in VALUES:
        rows = summary[summary.quantity == value]
        assert (rows.row == "subject x character").sum() == SUBJECTS * len(CHARACTERS) * len(CONDITIONS)
        assert set(rows.n[rows.row == "subject x character"]) == {REPETITIONS}
        overall = rows[rows.row == "mean over subjects"].set_index("condition")
        test = study.trials[study.trials.phase == "test"]
        means = test.groupby(["condition", "subject"], observed=True)[value].mean()
        for condition in CONDITIONS:
            assert overall.loc[condition, "mean"] == pytest.approx(means[condition].mean(), rel=1e-9)
            assert overall.loc[condition, "n"] == SUBJECTS
        assert set(rows.unit) == {"m" if value.endswith("_m") else "s"}


def test_the_statistics_name_their_test_and_n_and_find_the_planted_effect(report):
    index, page = report
    tables = [t for t in page.tables if t["attrs"].get("class") == "statistics"]
    assert [t["attrs"]["data-value"] for t in tables] == list(VALUES)
    for table in tables:
        header = [row for row in table["rows"] if row["section"] == "thead"][0]["cells"]
        body = [row for row in table["rows"] if row["section"] == "tbody"]
        assert len(body) == 2 + 6  # a mean per condition, one pair's six rows (the mixed model is above)
        # The quantity cell spans its rows, so a row without it is one cell shorter: read from the right.
        test_cells = [row["cells"][header.index("test") - len(header)] for row in body]
        n_cells = [row["cells"][header.index("n") - len(header)] for row in body]
        assert all(test_cells) and not any(text.startswith("not computed") for text in test_cells)
        assert n_cells.count(str(SUBJECTS)) == 8
        t_test = dict(zip(header[::-1], body[2]["cells"][::-1]))
        assert "paired t-test" in t_test["test"]
        # p with 3 significant digits or "< 0.001"; the planted effect is large against its noise.
        assert t_test["p"] == "< 0.001" or (len(t_test["p"].replace(".", "").lstrip("0")) == 3
                                             and float(t_test["p"]) < 0.05)
        # One direction on the whole page: treatment - control, as the design's questions.
        assert t_test["comparison"] == "haptic - vision"
        assert t_test["effect"].startswith("mean difference [")
        assert float(t_test["effect"].split("=")[1]) < 0  # guidance is faster and closer
    statistics = pandas.read_csv(index.parent / "tables" / "statistics.csv")
    assert list(statistics.columns[:4]) == ["value", "unit", "quantity", "comparison"]
    paired = statistics[statistics.test.str.startswith("paired t-test")].set_index("value")
    assert paired.loc["total_time_s", "effect"] == pytest.approx(HAPTIC_TIME_S, abs=1.0)  # SI units: s
    assert paired.loc["mean_deviation_m", "effect"] == pytest.approx(HAPTIC_DEVIATION_M, abs=0.3e-3)  # m


def test_every_figure_is_an_svg_and_a_decodable_png(report):
    index, page = report
    figures = index.parent / "figures"
    stems = sorted(path.stem for path in figures.glob("*.svg"))
    assert stems == sorted([f"learning_{value}" for value in VALUES] + [f"phase_{value}" for value in VALUES])
    for stem in stems:
        ElementTree.parse(figures / f"{stem}.svg")  # well-formed
        image = matplotlib.image.imread(figures / f"{stem}.png")
        assert image.shape[0] > 100 and image.shape[1] > 100
        assert np.ptp(image[..., :3]) > 0.5  # something is drawn on the white
    assert sorted(Path(img["src"]).stem for img in page.images) == stems
    for img in page.images:
        assert not os.path.isabs(img["src"]) and (index.parent / img["src"]).is_file()


def test_the_learning_curve_panels_share_one_y_axis_with_even_ticks(study):
    figure = study_report.learning_figure(study.trials, "mean_deviation_m")
    axes = figure.axes
    assert len(axes) == 1 + len(CHARACTERS)  # all characters, then each
    assert all(ax.get_ylim() == axes[0].get_ylim() for ax in axes)
    assert all(axes[0].get_shared_y_axes().joined(axes[0], ax) for ax in axes)
    ticks = [t for t in axes[0].get_yticks() if axes[0].get_ylim()[0] <= t <= axes[0].get_ylim()[1]]
    assert len(ticks) >= 3 and np.allclose(np.diff(ticks), np.diff(ticks)[0])
    assert axes[0].get_ylabel() == "mean deviation [mm]"
    # The values are drawn in mm: the haptic line of the first panel is the subjects' mean per repetition.
    test = study.trials[(study.trials.phase == "test") & (study.trials.condition == "haptic")]
    expected_mm = test.groupby(["repetition", "subject"], observed=True).mean_deviation_m.mean().groupby(
        level=0).mean().to_numpy() * 1e3
    haptic = [line for line in axes[0].get_lines() if line.get_label() == "haptic"][0]
    assert haptic.get_ydata() == pytest.approx(expected_mm)


def test_the_page_is_self_contained_and_the_subjects_are_collapsed(report):
    index, page = report
    text = index.read_text(encoding="utf-8")
    assert page.scripts == 0 and "<script" not in text.lower()
    assert "http://" not in text and "https://" not in text
    assert len(page.details) == 1 + SUBJECTS  # the exclusion counts, then one per subject
    assert all("open" not in attrs for attrs in page.details)
    sections = [name for kind, name in page.order if kind == "section"]
    assert sections == ["summary", "questions", "phases", "table5", "statistics", "learning", "subjects"]
    first_subject = next(k for k, (kind, name) in enumerate(page.order) if kind == "details" and name != "exclusions")
    assert page.order.index(("section", "learning")) < first_subject
    assert "../trials.html" in page.links  # the per-trial page, relative to the report
    # The simulated subjects are said to be a model.
    assert "simulated" in text and "not people" in text
    assert len(text) < 200_000  # the figures are links, not inlined
    assert not list(index.parent.rglob("*.tmp"))  # every temporary file was renamed


def test_a_file_that_cannot_be_written_is_named(light_study, tmp_path):
    out = tmp_path / "report"
    (out / "index.html").mkdir(parents=True)  # a folder where the page goes
    with pytest.raises(OSError, match="index.html"):
        study_report.write_report(light_study, out, values=("total_time_s",))
    assert not list(out.glob(".*.tmp"))
    assert not (out / "tables" / "summary.csv").exists()  # refused before any file of the set is written


def test_a_report_that_fails_while_writing_leaves_the_earlier_report_whole(light_study, tmp_path):
    import hashlib
    import resource
    import signal

    out = tmp_path / "report"
    study_report.write_report(light_study, out, values=("total_time_s",))

    def digests():
        return {p.relative_to(out): hashlib.sha256(p.read_bytes()).hexdigest() for p in sorted(out.rglob("*"))
                if p.is_file()}

    before = digests()
    largest = max(p.stat().st_size for p in out.rglob("*") if p.is_file())
    smallest = min(p.stat().st_size for p in out.rglob("*") if p.is_file())
    assert smallest < largest // 2
    # Files beyond half the largest cannot be written (EFBIG), as on a full disk: some of the new report is
    # written, then a file fails. A title makes every new page differ from the earlier one.
    saved_limit = resource.getrlimit(resource.RLIMIT_FSIZE)
    saved_handler = signal.signal(signal.SIGXFSZ, signal.SIG_IGN)
    resource.setrlimit(resource.RLIMIT_FSIZE, (largest // 2, saved_limit[1]))
    try:
        with pytest.raises(OSError, match="cannot write"):
            study_report.write_report(light_study, out, values=("total_time_s",), title="the second report")
    finally:
        resource.setrlimit(resource.RLIMIT_FSIZE, saved_limit)
        signal.signal(signal.SIGXFSZ, saved_handler)
    assert digests() == before
    assert not [p for p in out.rglob(".*") if p.is_file()]


def test_an_infinite_value_is_missing_on_the_page_and_said(light_study, tmp_path):
    damaged = calligraphy.study.Study(trials=light_study.trials.copy(), strokes=pandas.DataFrame())
    damaged.trials.loc[damaged.trials.index[-1], "total_time_s"] = np.inf
    with pytest.warns(calligraphy.statistics.NonFiniteValueWarning, match="'total_time_s'"):
        index = study_report.write_report(damaged, tmp_path / "report", values=("total_time_s",))
    page = index.read_text(encoding="utf-8")
    assert "inf" not in page.replace("info", "")
    summary = pandas.read_csv(tmp_path / "report" / "tables" / "summary.csv")
    assert np.isfinite(summary["mean"].dropna()).all()


def test_a_report_waits_for_another_writer_of_its_folder(light_study, tmp_path):
    import fcntl
    import threading
    import time

    out = tmp_path / "report"
    study_report.write_report(light_study, out, values=("total_time_s",))
    before = (out / "index.html").read_bytes()
    other_writer = os.open(out, os.O_RDONLY | os.O_DIRECTORY)  # another report in the middle of its renames
    fcntl.flock(other_writer, fcntl.LOCK_EX)
    thread = threading.Thread(target=study_report.write_report, args=(light_study, out),
                              kwargs={"values": ("total_time_s",), "title": "the second report"})
    thread.start()
    try:
        # Its set made, it writes every temporary first, the page's last, then takes the folder's lock to rename
        # them: once the page's temporary is there it is at the lock (within 5 s at most, as before), and a
        # writer that did not wait would have renamed within the half second more.
        deadline = time.monotonic() + 5.0
        while not list(out.glob(".index.html.tmp*")) and thread.is_alive() and time.monotonic() < deadline:
            time.sleep(0.02)
        thread.join(timeout=0.5)
        assert thread.is_alive()  # waiting for the folder
        assert (out / "index.html").read_bytes() == before
    finally:
        os.close(other_writer)
    thread.join(timeout=60.0)
    assert not thread.is_alive()
    assert "the second report" in (out / "index.html").read_text(encoding="utf-8")


def test_an_empty_output_folder_is_refused(study, tmp_path):
    (tmp_path / "index.html").write_text("someone's page", encoding="utf-8")
    with pytest.raises(ValueError, match="out_dir is empty"):
        study_report.write_report(study, "")
    empty = run_module(tmp_path, "--out", "", cwd=tmp_path)
    assert empty.returncode == 2 and "--out" in empty.stderr
    assert (tmp_path / "index.html").read_text(encoding="utf-8") == "someone's page"


def test_bad_arguments_are_named(study, tmp_path):
    with pytest.raises(ValueError, match="'pen_up_time_s'"):
        study_report.write_report(study, tmp_path, values=("pen_up_time_s",))
    with pytest.raises(ValueError, match="reference 'none' is not a condition.*'vision', 'haptic'"):
        study_report.write_report(study, tmp_path, reference="none")
    with pytest.raises(TypeError, match="study must be"):
        study_report.write_report(study.trials, tmp_path)


def run_module(*arguments, cwd):
    return subprocess.run([sys.executable, "-m", "calligraphy.study_report", *map(str, arguments)], cwd=cwd,
                          capture_output=True, text=True, timeout=120)


def test_the_command_line_names_a_bad_option_and_a_bad_folder(tmp_path):
    missing_out = run_module(tmp_path, cwd=tmp_path)
    assert missing_out.returncode == 2 and "--out" in missing_out.stderr
    page = run_module(tmp_path, "--out", tmp_path / "r", "--per-trial-page", tmp_path / "nothing.html", cwd=tmp_path)
    assert page.returncode == 2 and "--per-trial-page" in page.stderr and "nothing.html" in page.stderr
    if not hasattr(calligraphy._calligraphy, "_study_tables_csv"):
        pytest.skip("this calligraphy build has no study tables binding (calligraphy.study.load)")
    empty = tmp_path / "empty"
    empty.mkdir()
    data_error = run_module(empty, "--out", tmp_path / "r", cwd=tmp_path)
    assert data_error.returncode == 1 and str(empty) in data_error.stderr


def chromium(*arguments, profile, timeout=60):
    return subprocess.run([CHROMIUM, "--headless", "--no-sandbox", "--disable-gpu", "--disable-quic",
                           "--no-first-run", "--disable-background-networking", "--disable-component-update",
                           "--disable-sync", f"--user-data-dir={profile}", *arguments],
                          capture_output=True, text=True, timeout=timeout)


def test_chromium_shows_the_summary_first_at_1280_px(report, tmp_path):
    if not os.path.exists(CHROMIUM):
        pytest.skip(f"{CHROMIUM} is not installed (Debian: apt-get install chromium)")
    index, _ = report
    shot = tmp_path / "shot.png"
    # One Chromium takes the screenshot and dumps the DOM; one that does only one of them per run is asked again.
    taken = chromium("--window-size=1280,4000", f"--screenshot={shot}", "--dump-dom", index.as_uri(),
                     profile=tmp_path / "p1")
    assert shot.is_file(), taken.stderr
    image = matplotlib.image.imread(shot)
    assert image.shape[1] == 1280
    if os.environ.get("CALLIGRAPHY_SCREENSHOT"):
        shutil.copyfile(shot, os.environ["CALLIGRAPHY_SCREENSHOT"])
    dom = taken.stdout
    if "</html>" not in dom:
        dom = chromium("--dump-dom", index.as_uri(), profile=tmp_path / "p2").stdout
    first_subject = dom.index('<details id="subject-')
    order = [dom.index(section) for section in ('id="summary"', 'id="questions"', 'id="table5"', 'id="statistics"',
                                                'id="learning"')]
    assert order == sorted(order) and order[-1] < first_subject  # the summary first, the subjects last
    assert dom.count('class="cell"') == SUBJECTS * len(CHARACTERS) * len(VALUES)
    assert "<details open" not in dom


def test_a_real_study_from_session_run(small_study, tmp_path):
    """paper-table5 shrunk to 2 characters x 2 repetitions, 3 simulated subjects, through the CLI and load."""
    if not hasattr(calligraphy._calligraphy, "_study_tables_csv"):
        pytest.skip("this calligraphy build has no study tables binding (calligraphy.study.load)")
    small_study(tmp_path, subjects=3, repetitions=2)
    drawn = subprocess.run([os.environ["CALLIGRAPHY_CLI"], "report", "study", "--out", "trials.html"], cwd=tmp_path,
                           capture_output=True, text=True, timeout=120)
    assert drawn.returncode == 0, drawn.stderr
    made = run_module(tmp_path / "study", "--out", tmp_path / "report", "--title", "Three simulated subjects",
                      "--per-trial-page", tmp_path / "trials.html", cwd=tmp_path)
    assert made.returncode == 0, made.stderr
    index = tmp_path / "report" / "index.html"
    assert made.stdout.startswith(f"{index}: 3 subjects, {3 * (1 + 2 * 2 * 2)} trials,")
    page = parse(index.read_text(encoding="utf-8"))
    table5s = [t for t in page.tables if t["attrs"].get("class") == "table5"]
    assert [sum(row["section"] == "tbody" for row in t["rows"]) for t in table5s] == [3 * 2, 3 * 2]
    statistics = pandas.read_csv(tmp_path / "report" / "tables" / "statistics.csv")
    assert (statistics.n[statistics.test.str.startswith("paired t-test")] == 3).all()
    assert len(page.details) == 1 + 3  # the exclusion counts, then one per subject
    # Every trial links to its drawing on its session's per-trial page, and the anchor is there.
    anchors = [link for link in page.links if link and "#trial-" in link]
    assert len(anchors) == 3 * (1 + 2 * 2 * 2)
    for link in anchors:
        path, anchor = urllib.parse.unquote(link).split("#")
        assert f'id="{anchor}"' in (tmp_path / "report" / path).resolve().read_text(encoding="utf-8"), link
    questions = pandas.read_csv(tmp_path / "report" / "tables" / "questions.csv", keep_default_na=False)
    assert set(questions.comparison) == {"haptic - vision"} and set(questions.phase) == {"test"}
    for stem in ("learning_total_time_s", "learning_mean_deviation_m"):
        assert matplotlib.image.imread(tmp_path / "report" / "figures" / f"{stem}.png").size > 0


def test_a_study_of_phases_gets_learning_retention_and_transfer_by_group(tmp_path):
    """Between-subjects groups through pre-test, training, post-test, retention and transfer, with a planted
    retention advantage of the 'fading' group: the section, its CSV tables and the group comparison."""
    rng = np.random.default_rng(24)
    rows = []
    for s in range(8):
        group = ("fixture", "fading")[s % 2]
        kept_m = 0.2e-3 if group == "fading" else 0.8e-3  # error regained by retention
        means = {"pre-test": 2.0e-3, "training": 1.2e-3, "post-test": 1.0e-3, "retention": 1.0e-3 + kept_m,
                 "transfer": 1.6e-3}
        trial = 0
        for phase, mean in means.items():
            for repetition in range(2):
                rows.append({"subject": f"S{s + 1:02d}", "group": group, "phase": phase,
                             "condition": group if phase == "training" else "free", "characters": "十",
                             "repetition": repetition, "trial": trial,
                             "mean_deviation_m": mean + rng.normal(0.0, 0.05e-3),
                             "total_time_s": 10.0 + rng.normal(0.0, 0.5)})
                trial += 1
    trials = pandas.DataFrame(rows)
    for column in ("subject", "group", "phase", "condition"):
        trials[column] = trials[column].astype("category")
    index = study_report.write_report(calligraphy.study.Study(trials=trials, strokes=pandas.DataFrame()),
                                      tmp_path / "report")
    page = index.read_text(encoding="utf-8")
    # The design read from the table: groups between subjects, the first group in protocol order the control.
    assert "Between-subjects: 2 groups trained in training (fixture (control) n = 4, fading n = 4" in page
    means = pandas.read_csv(tmp_path / "report" / "tables" / "phase_means.csv", keep_default_na=False)
    deviation = means[means.value == "mean_deviation_m"]
    assert list(dict.fromkeys(deviation.phase)) == ["pre-test", "training", "post-test", "retention", "transfer"]
    assert set(deviation.unit) == {"m"} and (deviation.n == 4).all()  # n = subjects, SD over subjects
    retention_means = deviation[deviation.phase == "retention"].set_index("condition")["mean"]
    assert retention_means["fading"] == pytest.approx(1.2e-3, abs=0.1e-3)
    assert retention_means["fixture"] == pytest.approx(1.8e-3, abs=0.1e-3)
    questions = pandas.read_csv(tmp_path / "report" / "tables" / "questions.csv", keep_default_na=False)
    retention = questions[(questions.value == "mean_deviation_m") & (questions.phase == "retention")].iloc[0]
    assert retention.comparison == "fading - fixture" and retention.unit == "m"
    assert retention.estimate == pytest.approx(-0.6e-3, abs=0.1e-3)  # adjusted for the pre-test
    assert float(retention.df) == 8 - 3  # subjects - (intercept, pre-test slope, one group contrast)
    assert float(retention.p) < 0.001 and float(retention.p_holm) >= float(retention.p)
    assert retention.apa.startswith("t(5) = -") and retention.apa.endswith(" mm")
    ratios = pandas.read_csv(tmp_path / "report" / "tables" / "retention.csv")
    kept = ratios[ratios.value == "mean_deviation_m"].set_index("group")["retention_ratio"]
    assert kept["fading"] == pytest.approx(0.8, abs=0.1) and kept["fixture"] == pytest.approx(0.2, abs=0.1)
    assert "十 were also pre-tested" in page
