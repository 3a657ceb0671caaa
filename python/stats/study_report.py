"""A study report that reads like a paper: one page whose summary comes first, tables and figures as files.

``write_report(study, out_dir)`` writes, from a ``calligraphy.study.Study`` (``calligraphy.study.load``):

* ``index.html``: a self-contained page (no script, no external resource; the figures are relative links
  to ``figures/*.svg``) holding, in order, a header (protocols, subjects, trials, the writer kind), a table
  per value in the manner of Table 5 of Wang, Zhang & Yao 2006 (Virtual Reality 9:118-132, section 7:
  writing time per subject and character, with and without haptic guidance), the statistics of each value
  (``calligraphy.statistics.statistics_table``), learning curves over repetitions, then one collapsed
  section per subject with its trials;
* ``figures/learning_<value>.svg`` and ``.png`` (150 dpi), for a manuscript;
* ``tables/summary.csv`` and ``tables/statistics.csv``: the page's tables in SI units.

Every file is written atomically (a temporary file in the same folder, flushed, then renamed over the
target), and the report's files together: every temporary is written whole before any file is replaced, so a
failure while writing leaves the earlier report whole. Values stay in SI units (m, s) in the API and the CSV files; the page and figures show lengths in
mm and label every unit. The per-trial figures (trajectory, forces) are the C++ ``calligraphy report``
page's; this page links to it (``per_trial_page``) rather than drawing the trials again.

Command line: ``python3 -m calligraphy.study_report DIR... --out OUT [--title T] [--per-trial-page FILE]``.

pandas, matplotlib, SciPy and statsmodels are imported when a report is made, not with this module
(Debian: python3-pandas python3-matplotlib python3-scipy python3-statsmodels; fonts-arphic-ukai for the
characters in figures). The statistics' sources are those of calligraphy.statistics (docs/references.md).
"""

from __future__ import annotations

import argparse
import dataclasses
import errno
import html
import io
import math
import os
import pathlib
import re
import stat
import sys
import time
import typing
import urllib.parse

from . import _native
from . import study as _study

if typing.TYPE_CHECKING:  # pragma: no cover
    import matplotlib.figure

    from . import design_analysis
    import pandas

__all__ = ["learning_figure", "main", "write_report"]

PathLike = typing.Union[str, "os.PathLike[str]"]

PNG_DPI = 150
# Condition colours in the design's order, the control first: the colour-blind-safe palette of Okabe & Ito
# (2008, "Color Universal Design"), black for the control; the same condition has the same colour on every figure.
_CONDITION_COLOURS = ("#000000", "#E69F00", "#56B4E9", "#009E73", "#D55E00", "#0072B2", "#CC79A7", "#F0E442")
_FIGURE_RC = {"svg.fonttype": "path", "svg.hashsalt": "calligraphy-study-report", "font.size": 9.0}


@dataclasses.dataclass(frozen=True)
class _Display:
    """How a value in SI units is shown: its label, the display unit ('' for none), the factor from SI to
    it, and the decimals of a table cell."""

    label: str
    unit: str
    scale: float
    decimals: int

    def axis_label(self) -> str:
        return f"{self.label} [{self.unit}]" if self.unit else self.label


_DISPLAYS = {
    "total_time_s": _Display("writing time", "s", 1.0, 2),
    "pen_down_time_s": _Display("pen-down time", "s", 1.0, 2),
    "mean_deviation_m": _Display("mean deviation", "mm", 1e3, 2),
    "max_deviation_m": _Display("maximum deviation", "mm", 1e3, 2),
    "rms_deviation_m": _Display("RMS deviation", "mm", 1e3, 2),
    "frechet_m": _Display("Fréchet distance", "mm", 1e3, 2),
    "dtw_m": _Display("DTW distance", "mm", 1e3, 2),
    "order_errors": _Display("stroke order errors", "", 1.0, 2),
    "velocity_peaks": _Display("velocity peaks", "", 1.0, 1),
    "normalised_jerk": _Display("normalised jerk", "", 1.0, 1),
}


def _display(value: str) -> _Display:
    """The display of a column: a known one, else from the unit its name ends with (_m: mm, _s: s)."""
    if value in _DISPLAYS:
        return _DISPLAYS[value]
    if value.endswith("_m"):
        return _Display(value[:-2].replace("_", " "), "mm", 1e3, 2)
    if value.endswith("_s"):
        return _Display(value[:-2].replace("_", " "), "s", 1.0, 2)
    return _Display(value.replace("_", " "), "", 1.0, 2)


def _si_unit(value: str) -> str:
    return "m" if value.endswith("_m") else "s" if value.endswith("_s") else ""


def _pandas():
    try:
        import pandas
    except ImportError as error:  # pragma: no cover - depends on the installation
        raise ImportError("calligraphy.study_report needs pandas (Debian: apt-get install python3-pandas)") from error
    return pandas


def _matplotlib():
    try:
        import matplotlib  # noqa: F401
        import matplotlib.figure
        from matplotlib.backends.backend_agg import FigureCanvasAgg
    except ImportError as error:  # pragma: no cover - depends on the installation
        raise ImportError(
            "calligraphy.study_report needs matplotlib (Debian: apt-get install python3-matplotlib)") from error
    return matplotlib, FigureCanvasAgg


# ---------------------------------------------------------------------------------------------- formatting


def _finite(x: typing.Any) -> bool:
    try:
        return x is not None and math.isfinite(float(x))
    except (TypeError, ValueError):
        return False


def _fixed(x: typing.Any, decimals: int) -> str:
    return f"{float(x):.{decimals}f}" if _finite(x) else "–"


def _significant(x: typing.Any, digits: int = 3) -> str:
    """x with `digits` significant digits, in fixed notation (no exponent); '–' when not finite."""
    if not _finite(x):
        return "–"
    x = float(x)
    if x == 0:
        return "0"
    magnitude = math.floor(math.log10(abs(x)))
    return f"{x:.{max(0, digits - 1 - magnitude)}f}"


def _p_value(p: typing.Any) -> str:
    if not _finite(p):
        return "–"
    return "< 0.001" if float(p) < 0.001 else _significant(p, 3)


def _integer(x: typing.Any) -> str:
    return str(int(x)) if _finite(x) else "–"


def _count(n: int, noun: str) -> str:
    """"1 trial", "2 trials": a count with its noun in the number it takes."""
    return f"{n} {noun}{'' if n == 1 else 's'}"


def _e(text: typing.Any) -> str:
    return html.escape(str(text), quote=True)


def _file_name(value: str) -> str:
    return re.sub(r"[^A-Za-z0-9_.-]", "_", value)


def _has_cjk(text: str) -> bool:
    return any(ord(c) >= 0x2E80 for c in text)


# ---------------------------------------------------------------------------------------------- files


def _write_together(files: dict[pathlib.Path, typing.Union[bytes, str]]) -> None:
    """Writes a set of files that belong together (a report) with the library's one writer of sets
    (AtomicFileSet, include/calligraphy/core/atomic_file.hpp): every temporary written whole first, then
    every target replaced under the folders' locks, each earlier file kept under a second name until the
    last rename, so that a failure at any step (a full disk, a rename refused) leaves the earlier set whole,
    and a run killed between two renames leaves a journal the next write completes. A reader never finds new
    tables beside an old page. Raises OSError naming the file at fault."""
    # A folder where a file goes is refused before anything is written (the C++ writer refuses it too).
    for path in files:
        if path.is_dir():
            raise OSError(errno.EISDIR, f"cannot write {path}: {os.strerror(errno.EISDIR)}")
    payloads = [(os.fspath(path), data.encode("utf-8") if isinstance(data, str) else bytes(data))
                for path, data in files.items()]
    try:
        _native._write_files_together(payloads)
    except _native.DataError as error:
        raise OSError(str(error)) from error  # "PATH: cannot write: REASON"


class OutputOnInput(ValueError):
    """A file the report would write is a file of a session folder it reads (the same path, or a symbolic or
    hard link to it)."""


def _refuse_outputs_on_inputs(outputs: typing.Iterable[pathlib.Path], trace_files: typing.Iterable[str]) -> None:
    """Raises OutputOnInput naming both files when any of `outputs` is, by (device, inode) after following
    symbolic links, a file of the session folders that hold `trace_files` (each trace is
    SESSION/trials/STEM.trace.h5): their records, traces, session.json and log, which the report reads. A
    report never replaces a saved trial, as `calligraphy report` never does (docs/cli.md, "Output identity")."""
    folders = {pathlib.Path(trace).resolve().parent.parent for trace in trace_files if trace}
    inputs = {}
    for folder in folders:
        for path in folder.rglob("*"):
            try:
                status = path.stat()
            except OSError:
                continue
            if stat.S_ISREG(status.st_mode):
                inputs[(status.st_dev, status.st_ino)] = path
    for output in outputs:
        try:
            status = os.stat(output)  # through symbolic links: the file a write would replace
        except OSError:
            continue  # not there yet (or a dangling link): not a file the report reads
        found = inputs.get((status.st_dev, status.st_ino))
        if found is not None:
            raise OutputOnInput(f"--out: {output} is the same file as {found}, a file of a session folder this "
                                f"report reads: refused, nothing written")


def _make_folder(folder: pathlib.Path, made: list[pathlib.Path]) -> None:
    """Makes `folder` (and its parents) and checks that files can be made in it, before the report's work: the
    set of files is written with a journal in each of its folders, and needs no other folder. Each folder it
    makes is appended to `made`, parents first; one that another process made meanwhile is not (a report
    writing beside this one into the same folder keeps it when this one fails)."""
    for level in (*reversed(folder.parents), folder):
        if level.is_dir():
            continue
        try:
            os.mkdir(level)
        except FileExistsError:
            if level.is_dir():
                continue  # made by another process between the check and the mkdir: not this report's
            raise OSError(errno.EEXIST, f"cannot create the folder {folder}: {level} is a file") from None
        except OSError as error:
            raise OSError(error.errno, f"cannot create the folder {folder}: {error.strerror or error}") from error
        made.append(level)
    if not os.access(folder, os.W_OK | os.X_OK):
        raise OSError(errno.EACCES, f"cannot write in the folder {folder}: {os.strerror(errno.EACCES)}")


def _remove_made_folders(made: list[pathlib.Path]) -> None:
    """Removes the folders a report that failed made (`_make_folder`), the deepest first, each only when empty
    (rmdir): a failed report leaves no folder of its own, as it leaves no file."""
    for folder in reversed(made):
        try:
            folder.rmdir()
        except OSError:
            pass


# ---------------------------------------------------------------------------------------------- data


def _levels(column: "pandas.Series") -> list:
    """The values of a column that occur: in a categorical column's order, else sorted (the order
    calligraphy.statistics compares conditions in)."""
    present = set(column.dropna().tolist())
    if hasattr(column, "cat"):
        return [level for level in column.cat.categories if level in present]
    return sorted(present, key=lambda level: (str(type(level)), level))


def _characters_in_order(trials: "pandas.DataFrame") -> list[str]:
    """The items written, in the protocol's order (by their 0-based `item` when there is one)."""
    if "item" in trials and trials["item"].notna().any():
        first_item = trials.groupby("characters", observed=True)["item"].min()
        return [str(c) for c in first_item.sort_values(kind="stable").index]
    return [str(c) for c in dict.fromkeys(trials["characters"].astype(str))]


def _check_trials(trials: "pandas.DataFrame", values: typing.Sequence[str], phase: typing.Optional[str],
                  caller: str) -> "pandas.DataFrame":
    """`trials` after checking what the report needs; raises ValueError naming what is missing."""
    pandas = _pandas()
    if isinstance(values, str) or not values:
        raise ValueError(f"{caller}: values must be a non-empty sequence of column names, got {values!r}")
    needed = ["subject", "condition", "characters", "repetition", *values] + (["phase"] if phase else [])
    missing = [column for column in dict.fromkeys(needed) if column not in trials.columns]
    if missing:
        raise ValueError(f"{caller}: the trials have no column {', '.join(map(repr, missing))}; its columns: "
                         f"{', '.join(map(repr, trials.columns))}")
    from . import statistics

    for value in values:
        if not pandas.api.types.is_numeric_dtype(trials[value]) or pandas.api.types.is_bool_dtype(trials[value]):
            raise ValueError(f"{caller}: value {value!r} is not a numeric column (dtype {trials[value].dtype})")
        # An infinite value counts as missing in every table and figure, as in the statistics (warned).
        trials = statistics._finite_outcome(trials, value, caller)
    if trials.empty:
        raise ValueError(f"{caller}: there are no trials")
    if phase is not None and phase not in set(trials["phase"].astype(str)):
        raise ValueError(f"{caller}: phase {phase!r} is not in the trials; phases present: "
                         f"{', '.join(repr(p) for p in _levels(trials['phase']))}")
    return trials


def _phase_trials(trials: "pandas.DataFrame", phase: typing.Optional[str]) -> "pandas.DataFrame":
    return trials if phase is None else trials[trials["phase"].astype(str) == phase]


@dataclasses.dataclass
class _Table5:
    """One value's Table-5 table: each subject's mean per character and condition, and per condition the
    mean +- SD over subjects of each subject's mean over all its characters and repetitions."""

    value: str
    subjects: list
    characters: list[str]
    conditions: list
    cells: dict  # (subject, character, condition) -> (mean, sd, n) [SI]
    summary: dict  # condition -> (mean, sd, n subjects) [SI]


def _table5(data: "pandas.DataFrame", value: str) -> _Table5:
    from . import statistics

    subjects = _levels(data["subject"])
    characters = _characters_in_order(data)
    conditions = _levels(data["condition"])
    grouped = data.assign(characters=data["characters"].astype(str)).groupby(
        ["subject", "characters", "condition"], observed=True)[value]
    stats = grouped.agg(["mean", "std", "count"])
    cells = {key: (row["mean"], row["std"], int(row["count"])) for key, row in stats.iterrows()}
    described = statistics.describe(data, value, by=("condition",), unit="subject")
    summary = {row["condition"]: (row["mean"], row["sd"], int(row["n"])) for row in described.to_dict("records")}
    return _Table5(value, subjects, characters, conditions, cells, summary)


def _summary_rows(table: _Table5) -> list[dict]:
    """The Table-5 table as tidy CSV rows in SI units."""
    rows = []
    unit = _si_unit(table.value)
    for subject in table.subjects:
        for character in table.characters:
            for condition in table.conditions:
                mean, sd, n = table.cells.get((subject, character, condition), (math.nan, math.nan, 0))
                rows.append({"quantity": table.value, "unit": unit, "row": "subject x character",
                             "subject": subject, "characters": character, "condition": condition, "n": n,
                             "n_of": "trials", "mean": mean, "sd": sd})
    for condition in table.conditions:
        mean, sd, n = table.summary.get(condition, (math.nan, math.nan, 0))
        rows.append({"quantity": table.value, "unit": unit, "row": "mean over subjects", "subject": "",
                     "characters": "", "condition": condition, "n": n, "n_of": "subjects", "mean": mean, "sd": sd})
    return rows


def _statistics(data: "pandas.DataFrame", value: str, control: typing.Any) -> "pandas.DataFrame":
    """statistics_table of one value, or one row saying why it could not be computed (e.g. a constant
    outcome, which the mixed model refuses)."""
    from . import statistics

    pandas = _pandas()
    try:
        table = statistics.statistics_table(data, value, by="condition", with_mixed_model=False, reference=control)
    except ValueError as error:
        row: dict[str, typing.Any] = {column: math.nan for column in statistics.TABLE_COLUMNS}
        row.update(quantity=value, comparison="condition", test=f"not computed: {error}", assumptions="")
        table = pandas.DataFrame([row], columns=statistics.TABLE_COLUMNS)
    table.insert(0, "value", value)
    table.insert(1, "unit", _si_unit(value))
    return table


# ---------------------------------------------------------------------------------------------- figures


def _condition_colour(conditions: list, condition: typing.Any) -> str:
    return _CONDITION_COLOURS[conditions.index(condition) % len(_CONDITION_COLOURS)]


def learning_figure(trials: "pandas.DataFrame", value: str, phase: typing.Optional[str] = "test",
                    legend_title: str = "condition") -> "matplotlib.figure.Figure":
    """Learning curves of `value` over repetitions: per condition the mean over subjects with its 95 % t
    interval (``calligraphy.statistics.describe(..., unit="subject")``: each subject's trials averaged
    first, n = subjects; Student 1908). Panels: all characters (each subject's mean over them), then one per
    character when there are several; one shared y axis with even ticks (MaxNLocator), the value in its
    display unit (mm for lengths, s for times). The x axis is the tables' ``repetition``, counted from 1.

    trials: one row per trial with subject, condition, characters, repetition, `value` and, for a `phase`,
    phase (None: every row). legend_title: what a line is ('group' on a between-subjects report, whose
    groups each train under their own condition). Returns a matplotlib Figure (not registered with pyplot; Agg canvas).
    Raises ValueError for a missing column or phase, ImportError without matplotlib, pandas or SciPy.
    """
    import numpy
    from matplotlib.ticker import MaxNLocator

    from . import fonts, statistics

    matplotlib, canvas = _matplotlib()
    pandas = _pandas()
    if not isinstance(trials, pandas.DataFrame):
        raise TypeError(f"learning_figure: trials must be a pandas DataFrame, got {type(trials).__name__}")
    data = _phase_trials(_check_trials(trials, (value,), phase, "learning_figure"), phase)
    display = _display(value)
    characters = _characters_in_order(data)
    conditions = _levels(data["condition"])
    panels: list[tuple[str, typing.Optional[str]]] = [("all characters", None)]
    if len(characters) > 1:
        panels += [(character, character) for character in characters]
    with matplotlib.rc_context(_FIGURE_RC):
        figure = matplotlib.figure.Figure(figsize=(min(2.0 * len(panels) + 1.0, 12.0), 2.7), layout="constrained")
        canvas(figure)
        axes = figure.subplots(1, len(panels), sharey=True, squeeze=False)[0]
        offsets = {c: (k - (len(conditions) - 1) / 2) * 0.06 for k, c in enumerate(conditions)}
        repetitions = sorted(int(r) for r in data["repetition"].dropna().unique())
        font = fonts.cjk_font() if any(_has_cjk(c) for c in characters) else None
        for ax, (title, character) in zip(axes, panels):
            rows = data if character is None else data[data["characters"].astype(str) == character]
            curve = statistics.describe(rows, value, by=("condition", "repetition"), unit="subject")
            for condition in conditions:
                line = curve[curve["condition"] == condition].sort_values("repetition")
                if line.empty:
                    continue
                x = line["repetition"].to_numpy(dtype=float) + offsets[condition]
                mean = line["mean"].to_numpy(dtype=float) * display.scale
                low = line["ci95_low"].to_numpy(dtype=float) * display.scale
                high = line["ci95_high"].to_numpy(dtype=float) * display.scale
                colour = _condition_colour(conditions, condition)
                ax.plot(x, mean, "-o", color=colour, ms=3.5, lw=1.4, label=str(condition))
                has_interval = numpy.isfinite(low) & numpy.isfinite(high)  # NaN where fewer than 2 subjects
                if has_interval.any():
                    ax.errorbar(x[has_interval], mean[has_interval],
                                yerr=[mean[has_interval] - low[has_interval], high[has_interval] - mean[has_interval]],
                                fmt="none", ecolor=colour, elinewidth=1.0, capsize=2.5)
            if font is not None and _has_cjk(title):
                glyph_font = font.copy()
                glyph_font.set_size(13)
                ax.set_title(title, fontproperties=glyph_font)
            else:
                ax.set_title(title, fontsize=9)
            ax.set_xlabel("repetition")
            if repetitions:
                ax.set_xlim(repetitions[0] - 0.4, repetitions[-1] + 0.4)
            # Whole repetitions even when there are few: without min_n_ticks=1 the locator gives up on integers
            # for a range holding one (a single repetition got ticks 0.64, 0.72, ... 1.36).
            ax.xaxis.set_major_locator(MaxNLocator(integer=True, min_n_ticks=1))
            ax.yaxis.set_major_locator(MaxNLocator(nbins=5, steps=[1, 2, 2.5, 5, 10]))
            ax.grid(axis="y", color="#dddddd", lw=0.6)
            ax.spines[["top", "right"]].set_visible(False)
        axes[0].set_ylabel(display.axis_label())
        if conditions:  # outside the panels, so that it hides no point
            axes[-1].legend(title=legend_title, fontsize=8, title_fontsize=8, frameon=False, loc="upper left",
                            bbox_to_anchor=(1.02, 1.0))
    return figure


def _save_figure(figure: "matplotlib.figure.Figure", folder: pathlib.Path, stem: str,
                 files: dict[pathlib.Path, typing.Union[bytes, str]]) -> None:
    import matplotlib

    with matplotlib.rc_context(_FIGURE_RC):
        for extension, options in (("svg", {"metadata": {"Date": None}}), ("png", {"dpi": PNG_DPI})):
            buffer = io.BytesIO()
            figure.savefig(buffer, format=extension, **options)
            files[folder / f"{stem}.{extension}"] = buffer.getvalue()


# ---------------------------------------------------------------------------------------------- page

_STYLE = """<style>
body{font-family:"Noto Sans","DejaVu Sans",sans-serif;color:#222;max-width:1220px;margin:1em auto;padding:0 1em;
line-height:1.35}
h1{font-size:1.45em;margin:.2em 0 .3em}h2{font-size:1.15em;margin:1.2em 0 .4em;border-bottom:1px solid #ccc}
p{margin:.3em 0}.lead{font-size:1.02em}.note{color:#8a4b00;font-size:.9em}.files{font-size:.85em;color:#555}
table{border-collapse:collapse;font-size:.82em}td,th{border:1px solid #ccc;padding:.12em .45em}
th{background:#f4f4f4;font-weight:600}tbody th{background:#fafafa}
caption{caption-side:top;text-align:left;font-weight:bold;padding:.2em 0 .3em;font-size:1.05em}
td.num{text-align:right;font-variant-numeric:tabular-nums;white-space:nowrap}
.glyph{font-family:"AR PL UKai CN","AR PL UKai TW","Noto Serif CJK SC","Noto Sans CJK SC",serif;font-size:1.15em}
table.table5 td.glyph{text-align:center}
.n{color:#888;font-size:.85em}tfoot td,tfoot th{border-top:2px solid #888;font-weight:600}
.table5s{display:flex;flex-wrap:wrap;gap:1.6em;align-items:flex-start}
table.statistics{margin-bottom:.2em;width:100%}table.statistics td.test{font-size:.92em;color:#333}
table.statistics tr.group-start td{border-top:2px solid #999}td.quantity{background:#fafafa}
ol.assumptions{font-size:.78em;color:#555;margin:.1em 0 .9em;padding-left:2em}
figure{margin:.3em 0 .8em}figure img{max-width:100%;height:auto;display:block}
figcaption{font-size:.8em;color:#555;max-width:60em}
details{margin:.25em 0;border:1px solid #ddd;border-radius:3px;padding:.2em .6em}
summary{cursor:pointer;font-weight:600}details table{margin:.4em 0}
</style>
"""


def _figure_html(figure: "matplotlib.figure.Figure", stem: str, alt: str, caption: str) -> str:
    """A saved figure (figures/STEM.svg) on the page at its own width, with its alternative text and caption
    (plain text, escaped here)."""
    width_px = round(figure.get_figwidth() * 96)
    return (f"<figure><img src=\"figures/{_e(stem)}.svg\" width=\"{width_px}\" alt=\"{_e(alt)}\"><figcaption>"
            f"{_e(caption)}</figcaption></figure>\n")


def _quantity_text(text: str, value: str, display: _Display) -> str:
    """A statistics_table label for a table whose caption names the value: '[value]' -> '[unit]', and
    'mean of value' -> 'mean'."""
    text = text.replace(f"[{value}]", f"[{display.unit}]" if display.unit else "")
    return text.replace(f" of {value}", "").replace(value, display.label).strip()


def _table_csv(table: "pandas.DataFrame") -> str:
    """A table's CSV text, its count of subjects ``n`` written as a whole number (``6``, not ``6.0``; empty where
    a row has none), as the tidy tables of ``calligraphy report --csv`` write counts."""
    if "n" in table.columns and table["n"].dtype.kind == "f":
        table = table.assign(n=table["n"].astype("Int64"))
    return table.to_csv(index=False)


def _scaled_effect(row: dict, value: str) -> bool:
    """Whether a statistics row's effect is in the value's unit (a mean or difference), not d_z or power."""
    return f"[{value}]" in str(row.get("effect_name", ""))


def _header_html(trials: "pandas.DataFrame", title: str, design: "design_analysis.StudyDesign",
                 per_trial_link: typing.Optional[str], tables: pathlib.Path,
                 files: dict[pathlib.Path, typing.Union[bytes, str]]) -> str:
    protocols = [str(p) for p in _levels(trials["protocol"])] if "protocol" in trials else []
    subjects = trials["subject"].nunique()
    sessions = trials["session"].nunique() if "session" in trials else None
    facts = [f"Protocol{'s' if len(protocols) != 1 else ''} <b>{_e(', '.join(protocols) or 'unnamed')}</b>",
             _count(subjects, "subject")]
    if sessions is not None:
        facts.append(_count(sessions, "session"))
    facts.append(_count(len(trials), "trial"))
    parts = [f"<header>\n<h1>{_e(title)}</h1>\n<p class=\"lead\">{' &middot; '.join(facts)}</p>\n",
             f"<p>{_e(design.sentence())}</p>\n"]
    sentence = _subjects_sentence(trials)
    parts.append(f"<p class=\"{'note' if 'simulated' in sentence else 'lead'}\">{_e(sentence)}</p>\n")
    links = [f"<a href=\"tables/{name}\">tables/{name}</a>" for name in sorted(
        path.name for path in files if path.parent == tables)]
    listed = links + ["figures in <a href=\"figures/\">figures/</a> (SVG and PNG)"]
    if per_trial_link:
        listed.append(f"every trial's trajectory and forces: <a href=\"{_e(per_trial_link)}\">per-trial page</a>")
    parts.append(f"<p class=\"files\">Files: {'; '.join(listed)}.</p>\n</header>\n")
    return "".join(parts)


def _table5_html(table: _Table5, phase: typing.Optional[str]) -> str:
    display = _display(table.value)
    unit = f" [{display.unit}]" if display.unit else ""
    phase_words = f"{phase} trials" if phase else "all trials"
    out = [f"<table class=\"table5\" id=\"table5-{_e(_file_name(table.value))}\" data-value=\"{_e(table.value)}\">\n"
           f"<caption>{_e(display.label.capitalize())}{_e(unit)}, {_e(phase_words)}: each subject's mean over its "
           "repetitions</caption>\n<colgroup span=\"2\" class=\"keys\"></colgroup>"]
    out += [f"<colgroup class=\"condition\" data-condition=\"{_e(c)}\"></colgroup>" for c in table.conditions]
    out.append("\n<thead><tr><th scope=\"col\">subject</th><th scope=\"col\">character</th>")
    out += [f"<th scope=\"col\" style=\"color:{_condition_colour(table.conditions, c)}\">{_e(c)}</th>"
            for c in table.conditions]
    out.append("</tr></thead>\n<tbody>\n")
    for subject in table.subjects:
        for k, character in enumerate(table.characters):
            out.append("<tr class=\"cell\">")
            if k == 0:
                out.append(f"<th scope=\"row\" rowspan=\"{len(table.characters)}\">{_e(subject)}</th>")
            out.append(f"<td class=\"glyph\">{_e(character)}</td>")
            for condition in table.conditions:
                mean = table.cells.get((subject, character, condition), (math.nan,))[0]
                out.append(f"<td class=\"num\">{_fixed(mean * display.scale, display.decimals)}</td>")
            out.append("</tr>\n")
    out.append("</tbody>\n<tfoot><tr class=\"summary\"><th scope=\"row\" colspan=\"2\">mean &plusmn; SD over "
               "subjects (n)</th>")
    for condition in table.conditions:
        mean, sd, n = table.summary.get(condition, (math.nan, math.nan, 0))
        out.append(f"<td class=\"num\">{_fixed(mean * display.scale, display.decimals)} &plusmn; "
                   f"{_fixed(sd * display.scale, display.decimals)} <span class=\"n\">({n})</span></td>")
    out.append("</tr></tfoot>\n</table>\n")
    return "".join(out)


def _statistics_html(table: "pandas.DataFrame", value: str, phase: typing.Optional[str]) -> str:
    display = _display(value)
    notes: dict[str, str] = {}
    unit = f" [{display.unit}]" if display.unit else ""
    out = [f"<table class=\"statistics\" data-value=\"{_e(value)}\">\n<caption>{_e(display.label.capitalize())}"
           f"{_e(unit)}, {_e(phase + ' trials' if phase else 'all trials')}: over subjects</caption>\n"
           "<thead><tr><th>quantity</th><th>comparison</th><th>test</th><th>n</th><th>statistic</th><th>df</th>"
           "<th>p</th><th>effect</th><th>95 % CI</th><th>assumes</th></tr></thead>\n<tbody>\n"]
    records = table.to_dict("records")
    quantities = [_quantity_text(str(row["quantity"]), value, display) for row in records]
    for k, row in enumerate(records):
        scale = display.scale if _scaled_effect(row, value) else 1.0
        effect_name = _quantity_text(str(row["effect_name"]) if isinstance(row["effect_name"], str) else "", value,
                                     display)
        if _finite(row["effect"]):
            effect_number = (_integer(row["effect"]) if effect_name == "n subjects"
                             else _significant(row["effect"] * scale))
            effect = f"{_e(effect_name)} = {effect_number}" if effect_name else effect_number
        else:
            effect = "–"
        interval = (f"[{_significant(row['ci95_low'] * scale)}, {_significant(row['ci95_high'] * scale)}]"
                    if _finite(row["ci95_low"]) and _finite(row["ci95_high"]) else "–")
        assumptions = str(row["assumptions"]) if isinstance(row["assumptions"], str) else ""
        note = ""
        if assumptions:
            letter = notes.setdefault(assumptions, "abcdefghijklmnopqrstuvwxyz"[len(notes) % 26])
            note = f"<a href=\"#assumption-{_e(_file_name(value))}-{letter}\">{letter}</a>"
        # One quantity cell over the consecutive rows of a quantity, as a paper's table groups them.
        quantity_cell = ""
        if k == 0 or quantities[k] != quantities[k - 1]:
            span = 1
            while k + span < len(quantities) and quantities[k + span] == quantities[k]:
                span += 1
            quantity_cell = f"<td rowspan=\"{span}\" class=\"quantity\">{_e(quantities[k])}</td>"
        starts_group = k > 0 and quantities[k] != quantities[k - 1]
        out.append(f"<tr class=\"statistic{' group-start' if starts_group else ''}\">"
                   f"{quantity_cell}<td>{_e(row['comparison'])}</td>"
                   f"<td class=\"test\">{_e(row['test'])}</td><td class=\"num\">{_integer(row['n'])}</td>"
                   f"<td class=\"num\">{_significant(row['statistic'])}</td>"
                   f"<td class=\"num\">{_integer(row['df'])}</td>"
                   f"<td class=\"num\">{_e(_p_value(row['p']))}</td><td class=\"num\">{effect}</td>"
                   f"<td class=\"num\">{interval}</td><td>{note}</td></tr>\n")
    out.append("</tbody>\n</table>\n<ol class=\"assumptions\" type=\"a\">")
    for assumptions, letter in notes.items():
        out.append(f"<li id=\"assumption-{_e(_file_name(value))}-{letter}\">{_e(assumptions)}</li>")
    out.append("</ol>\n")
    return "".join(out)


def _trial_anchor(per_trial_link: str, row: dict) -> str:
    """The link to one trial's drawings on the per-trial pages of ``calligraphy report --out FILE.html``:
    FILE_files/SUBJECT/SESSION.html#trial-SESSION-N, N the tables' 1-based ``trial``."""
    stem = per_trial_link[:-len(".html")] if per_trial_link.endswith(".html") else per_trial_link
    subject, session, trial = (urllib.parse.quote(str(row[c])) for c in ("subject", "session", "trial"))
    return f"{stem}_files/{subject}/{session}.html#trial-{session}-{int(row['trial'])}"


def _subjects_html(trials: "pandas.DataFrame", values: typing.Sequence[str], per_trial_link: typing.Optional[str]
                   ) -> str:
    out = ["<section id=\"subjects\">\n<h2>Subjects</h2>\n"]
    if per_trial_link:
        out.append(f"<p>Each trial's trajectory over the reference and its forces: <a href=\"{_e(per_trial_link)}\">"
                   "the per-trial page</a>.</p>\n")
    displays = [(value, _display(value)) for value in values]
    columns = [c for c in ("session", "trial", "phase", "block", "condition", "characters", "repetition",
                           "end_reason") if c in trials.columns]
    for subject in _levels(trials["subject"]):
        rows = trials[trials["subject"] == subject]
        if "trial" in rows:
            rows = rows.sort_values([c for c in ("session", "trial") if c in rows.columns], kind="stable")
        sessions = rows["session"].nunique() if "session" in rows else 1
        out.append(f"<details id=\"subject-{_e(_file_name(str(subject)))}\"><summary>{_e(subject)}: {_count(len(rows), 'trial')}"
                   f" in {_count(sessions, 'session')}</summary>\n<table class=\"subject-trials\">"
                   "<thead><tr>")
        headings = {"trial": "trial #", "repetition": "repetition", "end_reason": "end"}
        out += [f"<th>{_e(headings.get(c, c))}</th>" for c in columns]
        out += [f"<th>{_e(d.axis_label())}</th>" for _, d in displays]
        out.append("</tr></thead>\n<tbody>\n")
        for row in rows.to_dict("records"):
            out.append("<tr>")
            for column in columns:
                cell = row[column]
                if column in ("trial", "repetition", "block") and _finite(cell):
                    cell = int(cell)  # counted from 1, as in the tables and the per-trial pages
                css = " class=\"glyph\"" if column == "characters" else ""
                if column == "trial" and per_trial_link and _finite(row[column]) and "session" in row:
                    out.append(f"<td><a href=\"{_e(_trial_anchor(per_trial_link, row))}\">{_e(cell)}</a></td>")
                else:
                    out.append(f"<td{css}>{_e(cell)}</td>")
            for value, display in displays:
                out.append(f"<td class=\"num\">{_fixed(row[value] * display.scale, display.decimals)}</td>")
            out.append("</tr>\n")
        out.append("</tbody></table>\n</details>\n")
    out.append("</section>\n")
    return "".join(out)


# ---------------------------------------------------------------------------------------------- the design's answers


def _phase_means(data: "pandas.DataFrame", value: str, design: "design_analysis.StudyDesign") -> "pandas.DataFrame":
    """Per phase and condition (group), the mean over subjects of each subject's mean, its SD over subjects,
    n = subjects and the 95 % t interval (the one definition of a summary on this page), in SI units. In a
    crossover, per phase and the condition each trial's set was trained under, and in any within-subjects
    design with Cousineau-Morey within-subject intervals (``crossover_analysis.within_subject_means``)."""
    from . import crossover_analysis, statistics

    if design.kind == "crossover":
        return crossover_analysis.within_subject_means(data, value, design)
    if design.kind == "within-subjects":
        return crossover_analysis.within_subject_means(data, value, design, by="condition")
    by = "group" if design.kind == "between-subjects" else "condition"
    rows = data[data[value].notna()]
    described = statistics.describe(rows.assign(phase=rows["phase"].astype(str), **{by: rows[by].astype(str)}),
                                    value, by=("phase", by), unit="subject")
    described = described.drop(columns=["unit"]).rename(columns={by: "condition"})
    described.insert(0, "value", value)
    described.insert(1, "unit", _si_unit(value))
    order = {p: k for k, p in enumerate(design.phases)}
    conditions = list(design.conditions)
    described["_p"] = described["phase"].map(order)
    described["_c"] = described["condition"].map(lambda c: conditions.index(c) if c in conditions else len(conditions))
    described = described.sort_values(["_p", "_c"], kind="stable").drop(columns=["_p", "_c"])
    return described[["value", "unit", "phase", "condition", "n", "mean", "sd", "ci95_low", "ci95_high"]]


def phase_figure(means: "pandas.DataFrame", value: str, design: "design_analysis.StudyDesign"
                 ) -> "matplotlib.figure.Figure":
    """The study at a glance: ``value`` by phase (protocol order, x) and condition or group (one line each, the
    control black), the mean over subjects with its 95 % t interval (n = subjects), from ``means``
    (``_phase_means``). Returns a matplotlib Figure (Agg canvas)."""
    from matplotlib.ticker import MaxNLocator

    matplotlib, canvas = _matplotlib()
    display = _display(value)
    phases = [p for p in design.phases if p in set(means["phase"])]
    conditions = [c for c in design.conditions if c in set(means["condition"])] + [
        c for c in dict.fromkeys(means["condition"]) if c not in design.conditions]
    with matplotlib.rc_context(_FIGURE_RC):
        figure = matplotlib.figure.Figure(figsize=(max(3.2, 1.15 * len(phases) + 1.6), 2.9), layout="constrained")
        canvas(figure)
        ax = figure.subplots()
        width = 0.5 / max(1, len(conditions))
        for k, condition in enumerate(conditions):
            line = means[means["condition"] == condition]
            x = [phases.index(p) + (k - (len(conditions) - 1) / 2) * width for p in line["phase"]]
            mean = line["mean"].to_numpy(dtype=float) * display.scale
            low = line["ci95_low"].to_numpy(dtype=float) * display.scale
            high = line["ci95_high"].to_numpy(dtype=float) * display.scale
            colour = _condition_colour(list(design.conditions) or conditions, condition) \
                if condition in design.conditions else "#777777"
            label = f"{condition} (control)" if condition == design.control else str(condition)
            ax.plot(x, mean, "-o", color=colour, ms=4, lw=1.3, label=label)
            finite = [i for i in range(len(x)) if math.isfinite(low[i]) and math.isfinite(high[i])]
            if finite:
                ax.errorbar([x[i] for i in finite], [mean[i] for i in finite],
                            yerr=[[mean[i] - low[i] for i in finite], [high[i] - mean[i] for i in finite]],
                            fmt="none", ecolor=colour, elinewidth=1.0, capsize=2.5)
        ax.set_xticks(range(len(phases)), phases)
        ax.set_ylabel(display.axis_label())
        ax.yaxis.set_major_locator(MaxNLocator(nbins=5, steps=[1, 2, 2.5, 5, 10]))
        ax.grid(axis="y", color="#dddddd", lw=0.6)
        ax.spines[["top", "right"]].set_visible(False)
        if conditions:
            ax.legend(title=_factor_name(design), fontsize=8, title_fontsize=8,
                      frameon=False, loc="upper left", bbox_to_anchor=(1.01, 1.0))
        else:  # no trial analysed: the figure says so rather than showing empty axes
            ax.text(0.5, 0.5, "no trial analysed", transform=ax.transAxes, ha="center", va="center", color="#555555")
    return figure


_PHASE_WORDS = {"practice": "familiarisation (practice)", "familiarisation": "familiarisation"}


def _words_html(design: "design_analysis.StudyDesign") -> str:
    """What the page's words mean, once: condition, group and (in a crossover) the condition trained."""
    words = ["a <b>condition</b> is how a trial is written: its guidance (mode), named by the protocol",
             "a <b>group</b> is the subjects a between-subjects phase assigns to one of its conditions, for the "
             "whole study"]
    if design.kind == "crossover":
        words.append("the <b>condition trained</b> of a trial is the condition its item set was trained under in "
                     "the crossover (a test trial written without guidance counts for it)")
    used = {"between-subjects": "groups (in training, each group wrote its own condition)",
            "crossover": "conditions trained", "within-subjects": "conditions"}.get(design.kind, "conditions")
    return (f"<p class=\"files\">Words: {'; '.join(words)}. The figures' lines and the tables' columns are "
            f"{_e(used)}.</p>\n")


def _protocol_html(trials: "pandas.DataFrame", design: "design_analysis.StudyDesign") -> str:
    """Every phase of the protocol in its order, the familiarisation too: its session, the conditions written,
    the items (by set, the sets in the protocol's order), the repetitions, the blocks (a crossover's training:
    one per period) and the trials per subject, and the subjects."""
    rows = []
    for phase in design.phases:
        of = trials[trials["phase"].astype(str) == phase]
        if of.empty:
            continue
        sessions = sorted({int(x) for x in of["session_number"].dropna()}) if "session_number" in of else []
        conditions = [str(c) for c in dict.fromkeys(of["condition"].astype(str))]
        conditions = [c for c in design.conditions if c in conditions] + [c for c in conditions
                                                                          if c not in design.conditions]
        conditions_text = ", ".join(conditions)
        if "group" in of and of["group"].astype(str).replace({"nan": ""}).ne("").any() and len(conditions) >= 2 and (
                of.groupby(of["subject"].astype(str), observed=True)["condition"].nunique() == 1).all():
            conditions_text += " (each group its own)"
        if "item_set" in of and (of["item_set"].astype(str).replace({"nan": ""}) != "").any():
            present = set(of["item_set"].astype(str))
            sets = [k for k in design.item_sets if k in present] + sorted(present - set(design.item_sets) - {"", "nan"})
            items = "; ".join(f"{k}: " + " ".join(dict.fromkeys(of.loc[of["item_set"].astype(str) == k, "characters"]
                                                                 .astype(str))) for k in sets)
        else:
            items = " ".join(_characters_in_order(of))
        repetitions = int(of["repetition"].max()) if of["repetition"].notna().any() else 0
        per_subject = of.groupby(of["subject"].astype(str), observed=True).size()
        blocks = (of.groupby(of["subject"].astype(str), observed=True)["block"].nunique()
                  if "block" in of else per_subject * 0 + 1)
        blocks_text = (f"{int(blocks.min())}" if blocks.min() == blocks.max()
                       else f"{int(blocks.min())}-{int(blocks.max())}")
        if design.kind == "crossover" and phase == design.compared_phase and blocks.min() == blocks.max() == len(
                design.periods):
            blocks_text += f" (one per period, {len(design.periods)} periods)"
        trials_text = (f"{int(per_subject.min())}" if per_subject.min() == per_subject.max()
                       else f"{int(per_subject.min())}-{int(per_subject.max())}")
        rows.append(f"<tr><td>{_e(_PHASE_WORDS.get(phase, phase))}</td><td class=\"num\">"
                    f"{_e(', '.join(str(x) for x in sessions) or '–')}</td><td>{_e(conditions_text)}</td>"
                    f"<td class=\"glyph\">{_e(items)}</td><td class=\"num\">{repetitions}</td>"
                    f"<td class=\"num\">{_e(blocks_text)}</td><td class=\"num\">{_e(trials_text)}</td>"
                    f"<td class=\"num\">{len(per_subject)}</td></tr>\n")
    return ("<table class=\"protocol\" id=\"protocol\"><caption>The protocol, phase by phase</caption>\n"
            "<thead><tr><th>phase</th><th>session</th><th>conditions written</th><th>items</th><th>repetitions</th>"
            "<th>blocks per subject</th><th>trials per subject</th><th>subjects</th></tr></thead><tbody>\n" + "".join(rows)
            + "</tbody></table>\n")


def _factor_name(design: "design_analysis.StudyDesign") -> str:
    """What a line or column of the page is: a group, a condition, or in a crossover the condition a set was
    trained under."""
    return {"between-subjects": "group", "crossover": "condition trained"}.get(design.kind, "condition")


def _interval_words(design: "design_analysis.StudyDesign") -> str:
    if design.kind in ("crossover", "within-subjects"):
        return ("the mean over subjects with its within-subject 95 % interval (Cousineau-Morey: subject means "
                "normalised to remove each subject's level; where a phase has several conditions, over the subjects "
                "with analysed trials in each)")
    return "the mean over subjects with its 95 % t interval"


def _subjects_sentence(trials: "pandas.DataFrame") -> str:
    """Who the subjects were: people, or simulated subjects with their profile and learning model."""
    writers = [str(w) for w in _levels(trials["writer"])] if "writer" in trials else []
    if "simulated" not in writers:
        return f"Subjects: {'people' if writers else 'not recorded'}."
    simulated = trials[trials["writer"].astype(str) == "simulated"]
    profiles = sorted({str(p) for p in simulated.get("writer_profile", []) if str(p)}) or ["not recorded"]
    models = sorted({str(m) for m in simulated.get("writer_learning", []) if str(m)}) or ["not recorded"]
    learns = ("they learn from trial to trial by that model (docs/writer.md)" if models != ["none"]
              else "they do not learn between trials")
    traits = simulated.get("subject_writing_speed_factor")
    if traits is not None and traits.notna().any():
        learns += ("; each subject has its own baseline skill, motor noise and learning rates, drawn from the "
                   "distributions of docs/writer.md (individual differences)")
    else:
        learns += "; all subjects of a profile alike (no individual differences)"
    who = "Some subjects are" if len(writers) > 1 else "The subjects are"
    return (f"{who} simulated (profile {', '.join(profiles)}; learning model {', '.join(models)}: {learns}): a model "
            "of a writer moving a simulated device, not people. Their numbers test the procedure and the analysis; "
            "they are no evidence of how people write or learn.")


def _exclusions_html(counts: "pandas.DataFrame", policy: "design_analysis.ExclusionPolicy") -> str:
    if counts.empty:
        return ""
    key = next(c for c in ("trained_condition", "group", "condition") if c in counts.columns)
    reasons = [c for c in counts.columns if c.startswith("excluded_")]
    total, kept = int(counts["trials"].sum()), int(counts["kept"].sum())
    label = "condition trained" if key == "trained_condition" else key
    head = "".join(f"<th>{_e(c)}</th>" for c in ["phase", label, "trials", "analysed", *(r[9:] for r in reasons)])
    body = "".join(
        "<tr>" + "".join(f"<td>{_e(row[c])}</td>" for c in ("phase", key))
        + "".join(f"<td class=\"num\">{int(row[c])}</td>" for c in ("trials", "kept", *reasons)) + "</tr>\n"
        for row in counts.to_dict("records"))
    return (f"<p>Completion: {kept} of {total} trials analysed ({100.0 * kept / total:.0f} %). {_e(policy.sentence())}"
            f"</p>\n<details id=\"exclusions\"><summary>Trials analysed and excluded, by phase and {_e(label)}"
            "</summary>\n"
            f"<table class=\"exclusions\"><thead><tr>{head}</tr></thead><tbody>\n{body}</tbody></table></details>\n")


def _model_html(model: typing.Any) -> str:
    """The model as fitted (a formula with '~'), under the test's name; nothing for a descriptive label."""
    return f"<br><code>{_e(model)}</code>" if isinstance(model, str) and "~" in model else ""


def _questions_html(questions: "pandas.DataFrame", value: str, factor: str = "condition") -> str:
    display = _display(value)
    unit = f" [{display.unit}]" if display.unit else ""
    out = [f"<table class=\"questions\" data-value=\"{_e(value)}\">\n<caption>{_e(display.label.capitalize())}"
           f"{_e(unit)}: each {_e(factor)} against the control, and with three or more every other pair (Holm "
           "within each phase)</caption>\n<thead><tr><th>phase</th><th>comparison</th>"
           "<th>model</th><th>result</th><th>p (Holm)</th><th>difference [95 % CI]</th><th>note</th></tr></thead>"
           "\n<tbody>\n"]
    for row in questions.to_dict("records"):
        difference = "–"
        if _finite(row["estimate"]):
            difference = _fixed(row["estimate"] * display.scale, display.decimals)
            if _finite(row["ci95_low"]) and _finite(row["ci95_high"]):
                difference += (f" [{_fixed(row['ci95_low'] * display.scale, display.decimals)}, "
                               f"{_fixed(row['ci95_high'] * display.scale, display.decimals)}]")
        note = str(row["note"]) if isinstance(row["note"], str) else ""
        css = " class=\"not-tested\"" if note.startswith(("not tested", "not computed")) else ""
        out.append(f"<tr{css}><td>{_e(row['phase'])}</td><td>{_e(row['comparison'])}</td>"
                   f"<td class=\"test\">{_e(row['test'] or '–')}{_model_html(row['model'])}</td>"
                   f"<td>{_e(row['apa'] or '–')}</td>"
                   f"<td class=\"num\">{_e(_p_value(row['p_holm']))}</td><td class=\"num\">{difference}</td>"
                   f"<td class=\"test\">{_e(note)}</td></tr>\n")
    if questions.empty:
        out.append(f"<tr class=\"not-tested\"><td colspan=\"7\">none: no two {_e(factor)}s with analysed trials "
                   "to compare</td></tr>\n")
    out.append("</tbody></table>\n")
    return "".join(out)


def _phase_means_html(means: "pandas.DataFrame", value: str, design: "design_analysis.StudyDesign") -> str:
    display = _display(value)
    unit = f" [{display.unit}]" if display.unit else ""
    conditions = [c for c in design.conditions if c in set(means["condition"])]
    phases = [p for p in design.phases if p in set(means["phase"])]
    cells = {(r["phase"], r["condition"]): r for r in means.to_dict("records")}
    head = "".join(f"<th>{_e(c)}{' (control)' if c == design.control else ''}</th>" for c in conditions)
    body = []
    for phase in phases:
        row = [f"<th>{_e(phase)}</th>"]
        for condition in conditions:
            cell = cells.get((phase, condition))
            row.append("<td class=\"num\">–</td>" if cell is None else
                       f"<td class=\"num\">{_fixed(cell['mean'] * display.scale, display.decimals)} &plusmn; "
                       f"{_fixed(cell['sd'] * display.scale, display.decimals)} <span class=\"n\">({int(cell['n'])})"
                       "</span></td>")
        body.append("<tr>" + "".join(row) + "</tr>\n")
    if not body:
        body.append("<tr><td>none: no trial analysed</td></tr>\n")
    return (f"<table class=\"phase-means\" data-value=\"{_e(value)}\"><caption>{_e(display.label.capitalize())}{_e(unit)}"
            f": mean &plusmn; SD over subjects (n subjects)</caption><thead><tr><th>phase</th>{head}</tr></thead>"
            f"<tbody>\n{''.join(body)}</tbody></table>\n")


def _retention_note(row: dict, display: _Display) -> str:
    """A retention row's note with its gain interval in the table's unit (the tables keep SI units)."""
    note = str(row["note"]) if isinstance(row["note"], str) else ""
    if not (_finite(row["gain_ci95_low"]) and _finite(row["gain_ci95_high"])):
        return note
    interval = (f"95 % CI [{_significant(row['gain_ci95_low'] * display.scale)}, "
                f"{_significant(row['gain_ci95_high'] * display.scale)}]" + (f" {display.unit}" if display.unit else ""))
    return re.sub(r"95 % CI \[[^\]]*\]", lambda _: interval, note)


def _retention_html(ratios: "pandas.DataFrame", factor: str, display: typing.Optional[_Display] = None) -> str:
    if ratios.empty:
        return ""
    display = display or _Display("", "", 1.0, 2)
    rows = "".join(f"<tr><td>{_e(r['group'])}</td><td class=\"num\">{_integer(r['n'])}</td><td class=\"num\">"
                   f"{_significant(r['retention_ratio'])}</td><td class=\"test\">{_e(_retention_note(r, display))}"
                   "</td></tr>\n" for r in ratios.to_dict("records"))
    return ("<table class=\"retention\"><caption>Share of the gain kept at retention, mean(pre - retention) / "
            f"mean(pre - post) per {_e(factor)}</caption><thead><tr><th>{_e(factor)}</th><th>n</th><th>ratio</th><th>note</th></tr>"
            f"</thead><tbody>\n{rows}</tbody></table>\n")


def _relative_link(target: PathLike, out_dir: pathlib.Path) -> str:
    relative = os.path.relpath(os.path.abspath(os.fspath(target)), os.path.abspath(out_dir))
    return urllib.parse.quote(pathlib.PurePath(relative).as_posix())


# The tables a report may write (tables/NAME.csv), each only for the designs that have it.
_TABLE_NAMES = ("phase_means", "questions", "exclusions", "retention", "summary", "statistics")


# The mixed models' denominator degrees of freedom (lmerTest's ddf): Satterthwaite (1946) or Kenward & Roger
# (1997).
_DDF_METHODS = ("Satterthwaite", "Kenward-Roger")


def write_report(study: "_study.Study", out_dir: PathLike, *, title: typing.Optional[str] = None,
                 values: typing.Sequence[str] = ("total_time_s", "mean_deviation_m"),
                 per_trial_page: typing.Optional[PathLike] = None, reference: typing.Optional[str] = None,
                 keep_end_reasons: typing.Optional[typing.Sequence[str]] = ("completed",),
                 ddf: str = "Satterthwaite") -> pathlib.Path:
    """Writes the report of `study` into `out_dir` (created if missing) and returns the path of its index.html.

    study: a calligraphy.study.Study (``calligraphy.study.load``; its ``trials`` need subject, phase,
    condition, characters, repetition, the `values`, and optionally group, mode, session, session_number,
    block, trial, writer, writer_profile, writer_learning, end_reason). values: numeric columns in SI units
    (lengths shown in mm, times in s). reference: the control every other condition (group) is compared with
    (default: the one condition without guidance, else the first in protocol order). keep_end_reasons: the
    trials analysed by how they ended (default: only 'completed'; None: all); the others are counted on the
    page. ddf: the mixed model's degrees of freedom, 'Satterthwaite' or 'Kenward-Roger'. per_trial_page: the
    C++ ``calligraphy report`` page, linked (relative to `out_dir`) for each trial's figures.

    The page (``calligraphy.design_analysis`` gives its numbers): a header (protocols, subjects and what they
    were, the design, completion and exclusions); the summary: per value a figure of the outcome by phase and
    condition with 95 % intervals and the table of the design's questions, each condition against the control
    with its APA sentence and Holm-adjusted p; then the details: phase means, retention and transfer, for a
    within-subjects design the Table-5 grids (Wang, Zhang & Yao 2006, section 7) and the paired statistics,
    learning curves over repetitions, one collapsed section per subject. One definition of a summary
    throughout: each subject's trials averaged first, SD over subjects, n = subjects.

    Writes index.html, figures/phase_<value>.svg/.png and figures/learning_<value>.svg/.png (150 dpi), and
    tidy tables with a ``unit`` column in SI units: tables/phase_means.csv, tables/questions.csv
    (``design_analysis.QUESTION_COLUMNS``), tables/exclusions.csv, tables/retention.csv (when there is a
    retention phase), and for a within-subjects design tables/summary.csv (the Table-5 cells) and
    tables/statistics.csv (``statistics.statistics_table``). docs/experiments.md lists every column.

    Raises TypeError when `study` has no trials DataFrame; ValueError naming a missing or non-numeric column,
    an unknown reference, a `ddf` not in ('Satterthwaite', 'Kenward-Roger') or an empty `out_dir`; OutputOnInput (a ValueError) naming both files when a file it
    would write is a file of a session folder it reads (through a symbolic or hard link), before anything is
    written; OSError naming a file or folder that could not be written; ImportError without pandas, matplotlib, SciPy or statsmodels. Without R (lme4, lmerTest) the mixed
    models' rows say "not computed" and name the packages.
    """
    from . import design_analysis

    pandas = _pandas()
    trials = getattr(study, "trials", None)
    if not isinstance(trials, pandas.DataFrame):
        raise TypeError(f"write_report: study must be a calligraphy.study.Study (calligraphy.study.load), "
                        f"got {type(study).__name__}")
    trials = _check_trials(trials, values, None, "write_report")
    if "phase" not in trials.columns:
        raise ValueError("write_report: the trials have no column 'phase'")
    if not os.fspath(out_dir).strip():
        raise ValueError("write_report: out_dir is empty; name the report folder")
    design = design_analysis.study_design(trials, reference)
    trials = design_analysis.ordered(trials, design)
    if isinstance(keep_end_reasons, (str, bytes)):
        raise TypeError(f"write_report: keep_end_reasons must be a sequence of end reasons (e.g. ('completed',)) "
                        f"or None, got {keep_end_reasons!r}")
    if ddf not in _DDF_METHODS:
        raise ValueError(f"write_report: ddf must be one of {', '.join(_DDF_METHODS)}, got {ddf!r}")
    policy = design_analysis.ExclusionPolicy(None if keep_end_reasons is None else tuple(keep_end_reasons))
    if policy.keep_end_reasons is not None and "end_reason" not in trials.columns:
        policy = design_analysis.ExclusionPolicy(None)
    kept, exclusions = design_analysis.apply_exclusions(trials, policy)
    out = pathlib.Path(out_dir)
    figures, tables = out / "figures", out / "tables"
    for folder in (figures, tables):
        # The report's own subfolders are part of its set: one that is a symbolic link would carry the set's
        # files out of out_dir, as a link in a file's place would (refused by the file set), so it is refused.
        if folder.is_symlink():
            raise OSError(errno.ELOOP, f"{folder}: is a symbolic link: the report's files are written only in "
                          "its own folders, never through a link (nothing written; remove the link or write the "
                          "report elsewhere)")
    # A file of the set that is a symbolic link is refused before any work (docs/cli.md, "Outputs"): the set's
    # writer refuses it too, but only after every fit and figure.
    table_file = {name: tables / f"{name}.csv" for name in _TABLE_NAMES}  # the one list of the set's tables
    names = [out / "index.html", *table_file.values()]
    names += [figures / f"{kind}_{_file_name(value)}.{ext}" for value in values for kind in ("phase", "learning")
              for ext in ("svg", "png")]
    # A link onto a file the report reads is named as that first (exit 2 from the command line).
    _refuse_outputs_on_inputs(names, study.trials["trace_file"] if "trace_file" in study.trials else ())
    for path in names:
        if path.is_symlink():
            raise OSError(f"{path}: is a symbolic link: a file of a set is written only in its own "
                          "folder, never through a link (nothing written; remove the link or write the set elsewhere)")
    made: list[pathlib.Path] = []  # the folders this report made: removed again if it is not written
    try:
        for folder in (out, figures, tables):
            _make_folder(folder, made)
        files = _report_set(trials, kept, exclusions, design, policy, values, title=title, out=out,
                            table_file=table_file, per_trial_page=per_trial_page, ddf=ddf)
        _refuse_outputs_on_inputs(files, study.trials["trace_file"] if "trace_file" in study.trials else ())
        _write_together(files)
    except BaseException:
        _remove_made_folders(made)
        raise
    return out / "index.html"


def _report_set(trials: "pandas.DataFrame", kept: "pandas.DataFrame", exclusions: "pandas.DataFrame",
                design: "design_analysis.StudyDesign", policy: "design_analysis.ExclusionPolicy",
                values: typing.Sequence[str], *, title: typing.Optional[str], out: pathlib.Path,
                table_file: dict[str, pathlib.Path], per_trial_page: typing.Optional[PathLike],
                ddf: str) -> dict[pathlib.Path, typing.Union[bytes, str]]:
    """The files of `write_report`'s set, made in memory (nothing written): its page, figures and tables, by path
    under `out`, the page last."""
    from . import design_analysis

    pandas = _pandas()
    figures, tables = out / "figures", out / "tables"
    phase = design.compared_phase
    data = _phase_trials(kept, phase)
    per_trial_link = _relative_link(per_trial_page, out) if per_trial_page is not None else None
    protocols = [str(p) for p in _levels(trials["protocol"])] if "protocol" in trials else []
    title = title or f"Study report: {', '.join(protocols) or 'study'}"
    within = design.kind == "within-subjects"

    files: dict[pathlib.Path, typing.Union[bytes, str]] = {}  # written together at the end, the page last
    summary_html, question_html, means_html, learning_html = [], [], [], []
    all_means, all_questions, all_ratios = [], [], []
    for value in values:
        display = _display(value)
        means = _phase_means(kept, value, design)
        all_means.append(means)
        stem = f"phase_{_file_name(value)}"
        figure = phase_figure(means, value, design)
        _save_figure(figure, figures, stem, files)
        summary_html.append(_figure_html(
            figure, stem, f"{display.label.capitalize()} by phase and {_factor_name(design)}",
            f"{display.label.capitalize()} by phase and {_factor_name(design)}: {_interval_words(design)} (each "
            "subject's analysed trials averaged first; n = subjects)."))
        questions = design_analysis.design_questions(trials, value, design, policy=policy, ddf=ddf,
                                                     scale=display.scale, display_unit=display.unit)
        all_questions.append(questions)
        question_html.append(_questions_html(questions, value, _factor_name(design)))
        means_html.append(_phase_means_html(means, value, design))
        ratios = design_analysis.retention_ratios(trials, value, design, policy)
        if not ratios.empty:
            all_ratios.append(ratios.assign(value=value, unit=_si_unit(value)))
            means_html.append(_retention_html(ratios, _factor_name(design), display))
        if phase is not None and not data.empty:
            stem = f"learning_{_file_name(value)}"
            figure = learning_figure(data, value, phase=None,
                                     legend_title="group" if design.kind == "between-subjects" else "condition")
            _save_figure(figure, figures, stem, files)
            learning_html.append(_figure_html(
                figure, stem, f"Learning curves of {display.label}",
                f"{display.label.capitalize()} over repetitions in {phase} (counted from 1): per "
                f"{'group' if design.kind == 'between-subjects' else 'condition'} the mean over subjects with its "
                "95 % t interval (n = subjects). Left: all characters; then each character. One y axis for all "
                "panels."))
    files[table_file["phase_means"]] = _table_csv(pandas.concat(all_means, ignore_index=True))
    files[table_file["questions"]] = _table_csv(pandas.concat(all_questions, ignore_index=True))
    files[table_file["exclusions"]] = _table_csv(exclusions)
    if all_ratios:
        files[table_file["retention"]] = _table_csv(pandas.concat(all_ratios, ignore_index=True))
    table5_html = ""
    statistics_html = ""
    if within and not data.empty:
        table5s = [_table5(data, value) for value in values]
        statistics_tables = [_statistics(data, value, design.control) for value in values]
        files[table_file["summary"]] = pandas.DataFrame(
            [row for t in table5s for row in _summary_rows(t)]).to_csv(index=False)
        files[table_file["statistics"]] = pandas.concat(statistics_tables, ignore_index=True).to_csv(index=False)
        table5_html = ("<section id=\"table5\">\n<h2>Means per subject and character (after Table 5)</h2>\n"
                       "<div class=\"table5s\">\n" + "".join(_table5_html(t, phase) for t in table5s) + "</div>\n"
                       "</section>\n")
        statistics_html = ("<section id=\"statistics\">\n<h2>Paired statistics of the " + _e(phase) + " trials</h2>\n"
                           "<p class=\"files\">Over subjects: each subject's trials are averaged per condition. n "
                           "counts subjects (trials for the mixed model); effects are in the unit shown, d_z and g_av "
                           "standardized; p two-sided, not adjusted (the adjusted ones are above). The power and "
                           "the subjects for 80 % power take the observed d_z as true" + _power_basis(trials)
                           + ".</p>\n"
                           + "".join(_statistics_html(t, v, phase) for t, v in zip(statistics_tables, values))
                           + "</section>\n")
    transfer = design_analysis.transfer_baseline(kept, design)
    page = ["<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">"
            "<meta name=\"viewport\" content=\"width=device-width\">"
            f"<title>{_e(title)}</title>\n{_STYLE}</head><body>\n",
            _header_html(trials, title, design, per_trial_link, tables, files),
            _words_html(design), _protocol_html(trials, design),
            _exclusions_html(exclusions, policy),
            "<section id=\"summary\">\n<h2>Summary</h2>\n<div class=\"figures\">\n", *summary_html, "</div>\n</section>\n",
            "<section id=\"questions\">\n<h2>The design's questions</h2>\n<p class=\"files\">",
            _e(_methods_sentence(design, ddf, pandas.concat(all_questions, ignore_index=True))), "</p>\n", *question_html, "</section>\n",
            "<section id=\"phases\">\n<h2>Means by phase</h2>\n", *means_html,
            f"<p>{_e(transfer)}</p>\n" if transfer else "", "</section>\n",
            table5_html, statistics_html,
            *(["<section id=\"learning\">\n<h2>Learning curves</h2>\n", *learning_html, "</section>\n"]
              if learning_html else []),
            _subjects_html(trials, values, per_trial_link),
            "</body></html>\n"]
    files[out / "index.html"] = "".join(page)
    return files


def _power_basis(trials: "pandas.DataFrame") -> str:
    """What a power figure of these subjects rests on: people, or simulated subjects whose spread is the
    model's (individual differences drawn from the distributions of docs/writer.md, or none)."""
    writers = {str(w) for w in trials["writer"]} if "writer" in trials else set()
    if "simulated" not in writers:
        return ""
    traits = trials.get("subject_writing_speed_factor")
    if traits is not None and traits.notna().any():
        return ("; these subjects are simulated, so it is the spread between subjects that the model's "
                "individual differences assume (log-normal factors on the profile, docs/writer.md, \"Individual "
                "differences\"), not people's")
    return ("; these subjects are simulated without individual differences, so the spread between them is only "
            "their trial-to-trial noise: the power is far too high for people")


_RANDOM_TERM = re.compile(r"\(([^()|]+)\|\s*([A-Za-z_.:]+)\s*\)")
_GROUPING_WORDS = {"subject": "subject", "item": "character", "subject:condition": "subject and condition",
                   "subject:item_set": "subject and item set (in a crossover: per subject and condition)"}


def _model_words(formula: str) -> str:
    """A fitted lme4 formula in words: its fixed effects and, from its random terms, what varies by subject and
    by character, so that the methods sentence says what was fitted, not a template."""
    outcome, _, right = formula.partition("~")
    fixed = [t.strip() for t in _RANDOM_TERM.sub("", right).split("+") if t.strip()]
    names = {"condition": "condition", "group": "group", "period": "period", "pre": "the same set's pre-test mean",
             "sequence": "sequence", "item_set": "item set"}
    words = [f"fixed effects of {', '.join(names.get(t, t) for t in fixed)}"]
    for inside, grouping in _RANDOM_TERM.findall(right):
        slopes = [t.strip() for t in inside.split("+") if t.strip() not in ("1", "")]
        who = _GROUPING_WORDS.get(grouping, grouping)
        words.append(f"a random intercept{' and ' + ', '.join(slopes) + ' slope' if slopes else ''} per {who}")
    return f"{outcome.strip()} ~ {right.strip()}: " + "; ".join(words)


def _methods_sentence(design: "design_analysis.StudyDesign", ddf: str, questions: "pandas.DataFrame") -> str:
    """The analysis as fitted: each mixed model's formula (as it was given to R) in words, then the tests and
    the adjustment."""
    control = design.control or "the first condition"
    parts = [f"Each {_factor_name(design)} is compared with the control, {control} (differences are "
             f"{_factor_name(design)} - control), and with three or more each other pair (later - earlier in the "
             "order of the tables' columns, the control first)."]
    mixed = questions[questions["test"].astype(str).str.startswith("linear mixed model")]
    by_model: dict[str, list[str]] = {}
    for row in mixed.drop_duplicates(["phase", "model"]).to_dict("records"):
        by_model.setdefault(str(row["model"]), []).append(str(row["phase"]))
    for model, phases in by_model.items():
        parts.append(f"{_display(model.split(' ~ ', 1)[0].strip()).label.capitalize()} in "
                     f"{', '.join(dict.fromkeys(phases))}: a linear mixed model, {_model_words(model)}, fitted by REML "
                     f"with R's lme4, t tests with {ddf} df (lmerTest).")
    if by_model:
        slope = {"crossover": "; the full model's random condition slope per subject is first replaced by its "
                              "compound-symmetry form (intercepts per subject and per subject and item set)",
                 "within-subjects": "; the full model's random condition slope per subject is first replaced by its "
                                    "compound-symmetry form (intercepts per subject and per subject and condition)"
                 }.get(design.kind, "")
        parts.append("Each model is the one fitted, by the documented reduction: a fit that is singular or does not "
                     f"converge is refitted{slope}; then, while still singular or not converged, without the random "
                     "term of the smallest variance (the row's note names each step). The outcome is fitted in the "
                     "power of ten of its unit that brings its SD between 1 and 10, so that the fit does not depend on "
                     "the unit; the tables show the results in their unit. A fit that stays singular, or does not "
                     "converge, is reported without a test.")
    if design.kind == "crossover":
        parts.append("The item set is a fixed effect where the design separates it from condition and period (sets "
                     "rotating across sequences); where it does not, the row's note says so.")
    if design.kind == "crossover":
        parts.append("After training each test trial counts for the condition its item set was trained under, "
                     "and period is the period that set was trained in. Checks, not adjusted: the carry-over F test "
                     "(sequence added to the training model) and, for two conditions in two periods, Hills-Armitage's "
                     "t test on each subject's half period difference.")
    if design.kind == "between-subjects" and design.pre_test and design.after_training:
        parts.append(f"After training ({', '.join(design.after_training)}): an ANCOVA on subject means, the phase's "
                     "mean adjusted for the pre-test mean (statsmodels OLS).")
    if design.kind == "within-subjects":
        parts.append("Paired t-tests on subject means, a check of the same comparison (not adjusted).")
    parts.append("p values are Holm-adjusted within each outcome and phase (each comparison with the control and, "
                 "with three or more, every other pair of them once: R's emmeans for a mixed model); g "
                 "is Hedges' g (g_av within subjects) with an approximate 95 % interval; the difference and its 95 % "
                 "interval are in the unit of the table.")
    return " ".join(parts)


# ---------------------------------------------------------------------------------------------- command line


def main(argv: typing.Optional[typing.Sequence[str]] = None) -> int:
    """``python3 -m calligraphy.study_report DIR... --out OUT [--title T] [--per-trial-page FILE]``: loads the
    session folders under DIR (calligraphy.study.load), writes the report into OUT and prints one line: the
    index path, subjects, trials and seconds taken. Exit status 0; 2 for bad usage (naming the option); 1 for
    a data or file error (naming the file)."""
    parser = argparse.ArgumentParser(
        prog="python3 -m calligraphy.study_report",
        description="Writes a study report that reads like a paper: index.html (summary first), figures/ and "
                    "tables/.")
    parser.add_argument("folders", nargs="+", metavar="DIR",
                        help="a session folder or a study folder of `calligraphy session run --out`")
    parser.add_argument("--out", required=True, metavar="OUT", help="the report folder (created if missing)")
    parser.add_argument("--title", help="the page's title (default: 'Study report: ' and the protocols)")
    parser.add_argument("--per-trial-page", metavar="FILE",
                        help="the page of `calligraphy report DIR --out FILE`, linked for each trial's figures")
    parser.add_argument("--reference", metavar="NAME",
                        help="the control group or condition (default: the one without guidance, 'vision' mode)")
    parser.add_argument("--analyse", metavar="END_REASONS", default="completed",
                        help="the trials analysed, by how they ended: a comma-separated list of end reasons, or "
                             "'all' (default: completed)")
    parser.add_argument("--ddf", choices=_DDF_METHODS, default="Satterthwaite",
                        help="the mixed models' degrees of freedom (default: Satterthwaite)")
    arguments = parser.parse_args(argv)
    if arguments.title is not None and not arguments.title.strip():
        parser.error("argument --title: is empty")
    if arguments.per_trial_page is not None and not os.path.isfile(arguments.per_trial_page):
        parser.error(f"argument --per-trial-page: {arguments.per_trial_page} is not a file")
    if not arguments.out.strip():
        parser.error("argument --out: is empty; name the report folder")
    reasons = [r.strip() for r in arguments.analyse.split(",")]
    if not all(reasons):
        parser.error(f"argument --analyse: {arguments.analyse!r} has an empty end reason")
    keep = None if reasons == ["all"] else tuple(reasons)
    if os.path.exists(arguments.out) and not os.path.isdir(arguments.out):
        parser.error(f"argument --out: {arguments.out} exists and is not a folder")

    started = time.monotonic()
    try:
        return _run_main(arguments, keep, started)
    except KeyboardInterrupt:
        # Ctrl-C: one line and 130, as the command line; R ends with this process.
        print("calligraphy.study_report: stopped by SIGINT (Ctrl-C)", file=sys.stderr)
        return 130


def _run_main(arguments: argparse.Namespace, keep: typing.Optional[tuple[str, ...]], started: float) -> int:
    from ._native import DataError
    from .design_analysis import UnknownReference

    try:
        study = _study.load(arguments.folders)
        index = write_report(study, arguments.out, title=arguments.title, per_trial_page=arguments.per_trial_page,
                             reference=arguments.reference, keep_end_reasons=keep, ddf=arguments.ddf)
    except OutputOnInput as error:  # wrong usage, as the command line's exit 2
        print(f"calligraphy.study_report: error: {error}", file=sys.stderr)
        return 2
    except UnknownReference as error:  # wrong usage: --reference names no condition (group)
        print(f"calligraphy.study_report: error: argument --reference: {error}", file=sys.stderr)
        return 2
    except (DataError, ValueError, TypeError, OSError, ImportError) as error:
        print(f"calligraphy.study_report: {error}", file=sys.stderr)
        return 1
    print(f"{index}: {study.trials['subject'].nunique()} subjects, {len(study.trials)} trials, "
          f"{time.monotonic() - started:.1f} s")
    return 0


if __name__ == "__main__":
    sys.exit(main())
