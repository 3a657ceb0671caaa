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
import contextlib
import dataclasses
import errno
import fcntl
import html
import itertools
import io
import math
import os
import pathlib
import re
import secrets
import sys
import time
import typing
import urllib.parse

from . import study as _study

if typing.TYPE_CHECKING:  # pragma: no cover
    import matplotlib.figure
    import pandas

__all__ = ["learning_figure", "main", "write_report"]

PathLike = typing.Union[str, "os.PathLike[str]"]

PNG_DPI = 150
# Condition colours in the conditions' order (matplotlib's tab10 blue and red first, as the C++ report).
_CONDITION_COLOURS = ("#1f77b4", "#d62728", "#2ca02c", "#9467bd", "#ff7f0e", "#8c564b")
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


def _e(text: typing.Any) -> str:
    return html.escape(str(text), quote=True)


def _file_name(value: str) -> str:
    return re.sub(r"[^A-Za-z0-9_.-]", "_", value)


def _has_cjk(text: str) -> bool:
    return any(ord(c) >= 0x2E80 for c in text)


# ---------------------------------------------------------------------------------------------- files


def _write_together(files: dict[pathlib.Path, typing.Union[bytes, str]]) -> None:
    """Writes a set of files that belong together (a report): each to a temporary file beside it, flushed
    and synced, and only once every one is whole, each renamed over its target in the order given. A failure
    while writing (a full disk) removes every temporary and leaves the earlier set whole, so that a reader
    never finds new tables beside an old page. Raises OSError naming the file at fault."""
    # A folder where a file goes would fail only at its rename, after others were replaced: refused first.
    for path in files:
        if path.is_dir():
            raise OSError(errno.EISDIR, f"cannot write {path}: {os.strerror(errno.EISDIR)}")
    written: list[tuple[pathlib.Path, pathlib.Path]] = []
    try:
        for path, data in files.items():
            payload = data.encode("utf-8") if isinstance(data, str) else data
            temporary = path.with_name(f".{path.name}.{os.getpid()}.{secrets.token_hex(4)}.tmp")
            try:
                # os.open with 0o666 lets the umask decide the permissions, as for any new file.
                descriptor = os.open(temporary, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o666)
                written.append((temporary, path))
                with os.fdopen(descriptor, "wb") as handle:
                    handle.write(payload)
                    handle.flush()
                    os.fsync(handle.fileno())
            except OSError as error:
                raise OSError(error.errno, f"cannot write {path}: {error.strerror or error}") from error
        # Renames need no space: once every temporary is whole the set is replaced in one short run, under an
        # exclusive lock of each folder (as the library's write_files_atomically), so that two reports written
        # into one folder at once are never interleaved file by file.
        with contextlib.ExitStack() as locks:
            for folder in sorted({path.parent for path in files}):
                descriptor = os.open(folder, os.O_RDONLY | os.O_DIRECTORY)
                locks.callback(os.close, descriptor)
                fcntl.flock(descriptor, fcntl.LOCK_EX)
            _rename_all(written)
    finally:
        for temporary, _ in written:
            with contextlib.suppress(OSError):
                os.unlink(temporary)


def _rename_all(written: list[tuple[pathlib.Path, pathlib.Path]]) -> None:
    """Each temporary over its target, in order; those renamed are taken off `written`."""
    while written:
        temporary, path = written[0]
        try:
            os.replace(temporary, path)
        except OSError as error:
            raise OSError(error.errno, f"cannot write {path}: {error.strerror or error}") from error
        written.pop(0)


def _make_folder(folder: pathlib.Path) -> None:
    try:
        folder.mkdir(parents=True, exist_ok=True)
    except OSError as error:
        raise OSError(error.errno, f"cannot create the folder {folder}: {error.strerror or error}") from error


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
                rows.append({"quantity": table.value, "si_unit": unit, "row": "subject x character",
                             "subject": subject, "characters": character, "condition": condition, "n": n,
                             "n_of": "trials", "mean": mean, "sd": sd})
    for condition in table.conditions:
        mean, sd, n = table.summary.get(condition, (math.nan, math.nan, 0))
        rows.append({"quantity": table.value, "si_unit": unit, "row": "mean over subjects", "subject": "",
                     "characters": "", "condition": condition, "n": n, "n_of": "subjects", "mean": mean, "sd": sd})
    return rows


def _statistics(data: "pandas.DataFrame", value: str) -> "pandas.DataFrame":
    """statistics_table of one value, or one row saying why it could not be computed (e.g. a constant
    outcome, which the mixed model refuses)."""
    from . import statistics

    pandas = _pandas()
    try:
        table = statistics.statistics_table(data, value, by="condition")
    except ValueError as error:
        row: dict[str, typing.Any] = {column: math.nan for column in statistics.TABLE_COLUMNS}
        row.update(quantity=value, comparison="condition", test=f"not computed: {error}", assumptions="")
        table = pandas.DataFrame([row], columns=statistics.TABLE_COLUMNS)
    table.insert(0, "value", value)
    return table


# ---------------------------------------------------------------------------------------------- figures


def _condition_colour(conditions: list, condition: typing.Any) -> str:
    return _CONDITION_COLOURS[conditions.index(condition) % len(_CONDITION_COLOURS)]


def learning_figure(trials: "pandas.DataFrame", value: str, phase: typing.Optional[str] = "test"
                    ) -> "matplotlib.figure.Figure":
    """Learning curves of `value` over repetitions: per condition the mean over subjects with its 95 % t
    interval (``calligraphy.statistics.describe(..., unit="subject")``: each subject's trials averaged
    first, n = subjects; Student 1908). Panels: all characters (each subject's mean over them), then one per
    character when there are several; one shared y axis with even ticks (MaxNLocator), the value in its
    display unit (mm for lengths, s for times). The x axis counts repetitions from 1 (the table's
    0-based ``repetition`` + 1).

    trials: one row per trial with subject, condition, characters, repetition, `value` and, for a `phase`,
    phase (None: every row). Returns a matplotlib Figure (not registered with pyplot; Agg canvas).
    Raises ValueError for a missing column or phase, ImportError without matplotlib, pandas or SciPy.
    """
    import numpy
    from matplotlib.ticker import MaxNLocator

    from . import plot, statistics

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
        font = plot.cjk_font() if any(_has_cjk(c) for c in characters) else None
        for ax, (title, character) in zip(axes, panels):
            rows = data if character is None else data[data["characters"].astype(str) == character]
            curve = statistics.describe(rows, value, by=("condition", "repetition"), unit="subject")
            for condition in conditions:
                line = curve[curve["condition"] == condition].sort_values("repetition")
                if line.empty:
                    continue
                x = line["repetition"].to_numpy(dtype=float) + 1.0 + offsets[condition]
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
                ax.set_xlim(repetitions[0] + 0.6, repetitions[-1] + 1.4)
            ax.xaxis.set_major_locator(MaxNLocator(integer=True))
            ax.yaxis.set_major_locator(MaxNLocator(nbins=5, steps=[1, 2, 2.5, 5, 10]))
            ax.grid(axis="y", color="#dddddd", lw=0.6)
            ax.spines[["top", "right"]].set_visible(False)
        axes[0].set_ylabel(display.axis_label())
        if conditions:  # outside the panels, so that it hides no point
            axes[-1].legend(title="condition", fontsize=8, title_fontsize=8, frameon=False, loc="upper left",
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


def _quantity_text(text: str, value: str, display: _Display) -> str:
    """A statistics_table label for a table whose caption names the value: '[value]' -> '[unit]', and
    'mean of value' -> 'mean'."""
    text = text.replace(f"[{value}]", f"[{display.unit}]" if display.unit else "")
    return text.replace(f" of {value}", "").replace(value, display.label).strip()


def _scaled_effect(row: dict, value: str) -> bool:
    """Whether a statistics row's effect is in the value's unit (a mean or difference), not d_z or power."""
    return f"[{value}]" in str(row.get("effect_name", ""))


def _header_html(trials: "pandas.DataFrame", data: "pandas.DataFrame", title: str, phase: typing.Optional[str],
                 per_trial_link: typing.Optional[str]) -> str:
    protocols = [str(p) for p in _levels(trials["protocol"])] if "protocol" in trials else []
    subjects = trials["subject"].nunique()
    sessions = trials["session"].nunique() if "session" in trials else None
    writers = [str(w) for w in _levels(trials["writer"])] if "writer" in trials else []
    characters = _characters_in_order(data)
    conditions = [str(c) for c in _levels(data["condition"])]
    repetitions = int(data["repetition"].max()) + 1 if data["repetition"].notna().any() else 0
    facts = [f"Protocol{'s' if len(protocols) != 1 else ''} <b>{_e(', '.join(protocols) or 'unnamed')}</b>",
             f"{subjects} subject{'s' if subjects != 1 else ''}"]
    if sessions is not None:
        facts.append(f"{sessions} session{'s' if sessions != 1 else ''}")
    phase_words = f"{phase} " if phase else ""
    facts.append(f"{len(trials)} trials ({len(data)} {phase_words}trials)")
    facts.append(f"writer: {_e(' and '.join(writers) or 'not recorded')}")
    parts = [f"<header>\n<h1>{_e(title)}</h1>\n<p class=\"lead\">{' &middot; '.join(facts)}</p>\n",
             f"<p>Design of the {_e(phase_words)}trials: {len(characters)} item{'s' if len(characters) != 1 else ''} "
             f"(<span class=\"glyph\">{_e(' '.join(characters))}</span>) &times; {len(conditions)} condition"
             f"{'s' if len(conditions) != 1 else ''} ({_e(', '.join(conditions))}) &times; up to {repetitions} "
             f"repetition{'s' if repetitions != 1 else ''}, after Wang, Zhang &amp; Yao 2006, section 7 "
             "(their Table 5 compares the writing time per character with and without haptic guidance).</p>\n"]
    if "simulated" in writers:
        parts.append("<p class=\"note\">" + ("Some subjects are" if len(writers) > 1 else "The subjects are") +
                     " simulated: a model of a writer moving a simulated device, not people. Their numbers test "
                     "the procedure and the analysis; they are no evidence of how people write or learn (a "
                     "simulated subject of a session does not learn between trials).</p>\n")
    files = ["<a href=\"tables/summary.csv\">tables/summary.csv</a>",
             "<a href=\"tables/statistics.csv\">tables/statistics.csv</a>",
             "figures in <a href=\"figures/\">figures/</a> (SVG and PNG)"]
    if per_trial_link:
        files.append(f"every trial's trajectory and forces: <a href=\"{_e(per_trial_link)}\">per-trial page</a>")
    parts.append(f"<p class=\"files\">Files: {'; '.join(files)}.</p>\n</header>\n")
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
                   f"<td class=\"num\">{_p_value(row['p'])}</td><td class=\"num\">{effect}</td>"
                   f"<td class=\"num\">{interval}</td><td>{note}</td></tr>\n")
    out.append("</tbody>\n</table>\n<ol class=\"assumptions\" type=\"a\">")
    for assumptions, letter in notes.items():
        out.append(f"<li id=\"assumption-{_e(_file_name(value))}-{letter}\">{_e(assumptions)}</li>")
    out.append("</ol>\n")
    return "".join(out)


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
        out.append(f"<details id=\"subject-{_e(_file_name(str(subject)))}\"><summary>{_e(subject)}: {len(rows)} trials"
                   f" in {sessions} session{'s' if sessions != 1 else ''}</summary>\n<table class=\"subject-trials\">"
                   "<thead><tr>")
        headings = {"trial": "trial #", "repetition": "repetition", "end_reason": "end"}
        out += [f"<th>{_e(headings.get(c, c))}</th>" for c in columns]
        out += [f"<th>{_e(d.axis_label())}</th>" for _, d in displays]
        out.append("</tr></thead>\n<tbody>\n")
        for row in rows.to_dict("records"):
            out.append("<tr>")
            for column in columns:
                cell = row[column]
                if column in ("trial", "repetition") and _finite(cell):
                    cell = int(cell) + 1  # counted from 1 on the page, as the per-trial page numbers trials
                elif column == "block" and _finite(cell):
                    cell = int(cell)
                css = " class=\"glyph\"" if column == "characters" else ""
                out.append(f"<td{css}>{_e(cell)}</td>")
            for value, display in displays:
                out.append(f"<td class=\"num\">{_fixed(row[value] * display.scale, display.decimals)}</td>")
            out.append("</tr>\n")
        out.append("</tbody></table>\n</details>\n")
    out.append("</section>\n")
    return "".join(out)


# ---------------------------------------------------------------------------------------------- learning


_LEARNING_PHASES = ("pre-test", "post-test", "retention", "transfer")


def _learning_tables(trials: "pandas.DataFrame", value: str) -> tuple["pandas.DataFrame", "pandas.DataFrame"]:
    """Per group (or 'all'), the subjects' mean pre, post, retention and transfer values, gain and retention
    ratio (``statistics.learning``); and every pair of groups compared on gain and retention
    (``statistics.group_comparison``; pairs with fewer than 2 subjects a side are left out)."""
    from . import statistics

    pandas = _pandas()
    present = set(trials["phase"].astype(str))
    table = statistics.learning(trials, value, "pre-test", "post-test",
                                retention="retention" if "retention" in present else None,
                                transfer="transfer" if "transfer" in present else None)
    if "group" not in table or not table["group"].astype(str).str.len().any():
        table["group"] = "all"
    columns = [c for c in ("pre", "post", "retention", "transfer", "gain", "retention_ratio", "transfer_gain")
               if c in table]
    summary = table.groupby("group", sort=True)[columns].agg(["mean", "std", "count"])
    comparisons = []
    groups = sorted(str(g) for g in table["group"].unique())
    for a, b in itertools.combinations(groups, 2):
        for quantity in ("gain", "retention", "transfer"):
            if quantity not in table:
                continue
            try:
                c = statistics.group_comparison(table, quantity, a, b)
            except ValueError:  # fewer than 2 subjects with a value in a group
                continue
            comparisons.append({"value": value, "quantity": quantity, "a": a, "b": b, "n_a": c.n_a, "n_b": c.n_b,
                                "mean_difference": c.mean_difference, "ci95_low": c.ci95_low,
                                "ci95_high": c.ci95_high, "t": c.t, "df": c.df, "p": c.p, "g": c.g,
                                "mann_whitney_p": c.mann_whitney_p, "test": c.test})
    return summary, pandas.DataFrame(comparisons)


def _learning_html(trials: "pandas.DataFrame", values: typing.Sequence[str], tables: pathlib.Path,
                   files: dict[pathlib.Path, typing.Union[bytes, str]]) -> str:
    """The section on learning, retention and transfer of a protocol with a pre-test and a post-test
    (docs/experiments.md, "Phases"); '' without them. Also adds tables/learning.csv and
    tables/group_comparisons.csv to `files`."""
    pandas = _pandas()
    present = set(trials["phase"].astype(str))
    if not {"pre-test", "post-test"} <= present:
        return ""
    parts = ["<section id=\"learning-retention\">\n<h2>Learning, retention and transfer</h2>\n"
             "<p class=\"files\">Each subject's trials averaged per phase; gain = pre-test - post-test (lower "
             "is better); retention ratio = (pre - retention) / (pre - post): 1 kept, 0 lost. Groups are the "
             "between-subjects training conditions. Mean ± SD over subjects (n).</p>\n"]
    summaries, comparisons = [], []
    for value in values:
        summary, compared = _learning_tables(trials, value)
        display = _display(value)
        unit = f" [{display.unit}]" if display.unit else ""
        columns = list(dict.fromkeys(c for c, _ in summary.columns))
        header = "".join(f"<th>{_e(c.replace('_', ' '))}</th>" for c in columns)
        rows = []
        for group, row in summary.iterrows():
            cells = []
            for column in columns:
                scale = 1.0 if column == "retention_ratio" else display.scale
                mean, sd, n = row[(column, "mean")], row[(column, "std")], row[(column, "count")]
                cells.append(f"<td>{_fixed(mean * scale, display.decimals)} ± {_fixed(sd * scale, display.decimals)}"
                             f" ({_integer(n)})</td>")
            rows.append(f"<tr><th>{_e(group)}</th>{''.join(cells)}</tr>")
        parts.append(f"<table><caption>{_e(display.label.capitalize())}{_e(unit)} by phase (retention ratio "
                     f"without unit)</caption><tr><th>group</th>{header}</tr>{''.join(rows)}</table>\n")
        flat = summary.copy()
        flat.columns = [f"{c}_{stat}" for c, stat in summary.columns]
        summaries.append(flat.reset_index().assign(value=value))
        if not compared.empty:
            comparisons.append(compared)
            lines = "".join(
                f"<tr><td>{_e(r.quantity)}</td><td>{_e(r.a)} - {_e(r.b)}</td><td>{r.n_a}, {r.n_b}</td>"
                f"<td>{_fixed(r.mean_difference * display.scale, display.decimals)} "
                f"[{_fixed(r.ci95_low * display.scale, display.decimals)}, "
                f"{_fixed(r.ci95_high * display.scale, display.decimals)}]</td><td>{_significant(r.t)}</td>"
                f"<td>{_significant(r.df)}</td><td>{_p_value(r.p)}</td><td>{_significant(r.g)}</td></tr>"
                for r in compared.itertuples())
            parts.append(f"<table><caption>Groups compared, {_e(display.label)}{_e(unit)}: Welch t-test, "
                         "Hedges' g</caption><tr><th>quantity</th><th>groups</th><th>n</th><th>difference "
                         f"[95 % CI]</th><th>t</th><th>df</th><th>p</th><th>g</th></tr>{lines}</table>\n")
    files[tables / "learning.csv"] = pandas.concat(summaries, ignore_index=True).to_csv(index=False)
    if comparisons:
        files[tables / "group_comparisons.csv"] = pandas.concat(comparisons, ignore_index=True).to_csv(index=False)
    parts.append("</section>\n")
    return "".join(parts)


def _relative_link(target: PathLike, out_dir: pathlib.Path) -> str:
    relative = os.path.relpath(os.path.abspath(os.fspath(target)), os.path.abspath(out_dir))
    return urllib.parse.quote(pathlib.PurePath(relative).as_posix())


def write_report(study: "_study.Study", out_dir: PathLike, *, title: typing.Optional[str] = None,
                 values: typing.Sequence[str] = ("total_time_s", "mean_deviation_m"),
                 phase: typing.Optional[str] = "auto", per_trial_page: typing.Optional[PathLike] = None
                 ) -> pathlib.Path:
    """Writes the report of `study` into `out_dir` (created if missing) and returns the path of its
    index.html.

    study: a calligraphy.study.Study (``calligraphy.study.load``; its ``trials`` need subject, condition,
    characters, repetition (0-based), phase, the `values`, and optionally protocol, session, writer, trial,
    block, end_reason). values: numeric columns in SI units, one Table-5 table, statistics table and
    learning-curve figure each (lengths shown in mm, times in s). phase: the trials the tables, statistics
    and curves use ('test', as the paper's Table 5; None for all; 'auto': 'test' when present, else
    'training' when present, else all); the per-subject sections list every trial. A study with a pre-test
    and a post-test also gets a section on learning, retention and transfer per group
    (``statistics.learning`` and ``statistics.group_comparison``; tables/learning.csv and
    tables/group_comparisons.csv). per_trial_page: the C++ ``calligraphy report`` page, linked (relative to `out_dir`) for each
    trial's figures.

    Writes index.html, figures/learning_<value>.svg and .png (150 dpi), tables/summary.csv (per value the
    Table-5 cells: quantity, si_unit, row ('subject x character' or 'mean over subjects'), subject,
    characters, condition, n, n_of (trials or subjects), mean, sd, in SI units) and tables/statistics.csv
    (``calligraphy.statistics.statistics_table`` of each value, a `value` column first). Table 5 after
    Wang, Zhang & Yao 2006, section 7; the statistics' sources are those of calligraphy.statistics.

    Raises TypeError when `study` has no trials DataFrame; ValueError naming a missing or non-numeric column,
    a phase not present (listing those present) or an empty `out_dir`; OSError naming a file or folder that could not be
    written; ImportError without pandas, matplotlib, SciPy or statsmodels.
    """
    pandas = _pandas()
    trials = getattr(study, "trials", None)
    if not isinstance(trials, pandas.DataFrame):
        raise TypeError(f"write_report: study must be a calligraphy.study.Study (calligraphy.study.load), "
                        f"got {type(study).__name__}")
    if phase == "auto":
        present = set(trials["phase"].astype(str)) if "phase" in trials else set()
        phase = "test" if "test" in present else "training" if "training" in present else None
    trials = _check_trials(trials, values, phase, "write_report")
    data = _phase_trials(trials, phase)
    if not os.fspath(out_dir).strip():
        raise ValueError("write_report: out_dir is empty; name the report folder")
    out = pathlib.Path(out_dir)
    figures, tables = out / "figures", out / "tables"
    for folder in (out, figures, tables):
        _make_folder(folder)
    per_trial_link = _relative_link(per_trial_page, out) if per_trial_page is not None else None
    protocols = [str(p) for p in _levels(trials["protocol"])] if "protocol" in trials else []
    title = title or f"Study report: {', '.join(protocols) or 'study'}"

    table5s = [_table5(data, value) for value in values]
    statistics_tables = [_statistics(data, value) for value in values]
    files: dict[pathlib.Path, typing.Union[bytes, str]] = {}  # written together at the end, the page last
    files[tables / "summary.csv"] = pandas.DataFrame([row for t in table5s for row in _summary_rows(t)]).to_csv(index=False)
    files[tables / "statistics.csv"] = pandas.concat(statistics_tables, ignore_index=True).to_csv(index=False)

    figure_html = []
    for value in values:
        stem = f"learning_{_file_name(value)}"
        figure = learning_figure(data, value, phase=None)
        _save_figure(figure, figures, stem, files)
        width_px = round(figure.get_figwidth() * 96)  # the SVG's size in CSS px (its pt x 96/72)
        display = _display(value)
        figure_html.append(
            f"<figure><img src=\"figures/{_e(stem)}.svg\" width=\"{width_px}\" "
            f"alt=\"Learning curves of {_e(display.label)}\"><figcaption>{_e(display.label.capitalize())} over "
            "repetitions (counted from 1): per condition the mean over subjects with its 95 % t interval (each "
            "subject's trials averaged first; n = subjects). Left: all characters; then each character. One y "
            "axis for all panels.</figcaption></figure>\n")

    page = ["<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">"
            "<meta name=\"viewport\" content=\"width=device-width\">"
            f"<title>{_e(title)}</title>\n{_STYLE}</head><body>\n",
            _header_html(trials, data, title, phase, per_trial_link),
            "<section id=\"table5\">\n<h2>Means per subject and character (after Table 5)</h2>\n"
            "<div class=\"table5s\">\n", *(_table5_html(t, phase) for t in table5s), "</div>\n</section>\n",
            "<section id=\"statistics\">\n<h2>Statistics</h2>\n<p class=\"files\">Over subjects: each subject's "
            "trials are averaged per condition. n counts subjects (trials for the mixed model); effects are in the "
            "unit shown, d_z and g_av standardized; p two-sided.</p>\n",
            *(_statistics_html(t, v, phase) for t, v in zip(statistics_tables, values)), "</section>\n",
            "<section id=\"learning\">\n<h2>Learning curves</h2>\n", *figure_html, "</section>\n",
            _learning_html(trials, values, tables, files) if "phase" in trials else "",
            _subjects_html(trials, values, per_trial_link),
            "</body></html>\n"]
    index = out / "index.html"
    files[index] = "".join(page)
    _write_together(files)
    return index


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
    arguments = parser.parse_args(argv)
    if arguments.title is not None and not arguments.title.strip():
        parser.error("argument --title: is empty")
    if arguments.per_trial_page is not None and not os.path.isfile(arguments.per_trial_page):
        parser.error(f"argument --per-trial-page: {arguments.per_trial_page} is not a file")
    if not arguments.out.strip():
        parser.error("argument --out: is empty; name the report folder")
    if os.path.exists(arguments.out) and not os.path.isdir(arguments.out):
        parser.error(f"argument --out: {arguments.out} exists and is not a folder")

    from . import DataError

    started = time.monotonic()
    try:
        study = _study.load(arguments.folders)
        index = write_report(study, arguments.out, title=arguments.title, per_trial_page=arguments.per_trial_page)
    except (DataError, ValueError, TypeError, OSError, ImportError) as error:
        print(f"calligraphy.study_report: {error}", file=sys.stderr)
        return 1
    print(f"{index}: {study.trials['subject'].nunique()} subjects, {len(study.trials)} trials, "
          f"{time.monotonic() - started:.1f} s")
    return 0


if __name__ == "__main__":
    sys.exit(main())
