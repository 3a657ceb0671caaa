"""Linear mixed models fitted by the field's reference implementation: R's lme4 (Bates, Maechler, Bolker &
Walker 2015, J Stat Softw 67(1)) with lmerTest's small-sample degrees of freedom (Kuznetsova, Brockhoff &
Christensen 2017, J Stat Softw 82(13)): Satterthwaite (1946) by default, Kenward & Roger (1997, Biometrics
53:983) through pbkrtest.

``lmer(frame, formula, factors)`` writes ``frame`` to a temporary folder and has R fit it with the package's
``lmer_fit.R``; nothing is re-implemented in Python. One R process per Python process serves every fit (loading
lme4 takes longer than most fits), started on the first and ended at exit. R and its packages come from Debian:
``apt-get install r-base-core r-cran-lme4 r-cran-lmertest r-cran-pbkrtest`` (scripts/install-deps.sh).
Without them ``lmer`` raises ``RUnavailable``, which callers report as "not computed" and never replace
with a large-sample Wald test.
"""

from __future__ import annotations

import atexit
import dataclasses
import os
import pathlib
import shutil
import subprocess
import tempfile
import threading
import time
import typing

if typing.TYPE_CHECKING:  # pragma: no cover
    import pandas

__all__ = ["LmerFit", "RUnavailable", "lmer", "r_available"]

_SCRIPT = pathlib.Path(__file__).with_name("lmer_fit.R")
# A fit of a few thousand trials takes seconds; a hung R is stopped instead of hanging a report.
_TIMEOUT_S = 600.0


class RUnavailable(RuntimeError):
    """Rscript, or one of lme4, lmerTest and pbkrtest, is not installed (the message says which and how to
    install it)."""


@dataclasses.dataclass(frozen=True)
class LmerFit:
    """One fitted model. ``fixed``: a DataFrame with one row per fixed effect: ``term`` (R's name, e.g.
    '(Intercept)' or 'groupfixture'), ``factor`` and ``level`` (the factor level a treatment-coded term
    compares with the factor's reference; '' for other terms), ``estimate``, ``std_error``, ``df``
    (Satterthwaite or Kenward-Roger), ``t``, ``p`` (two-sided), ``ci95_low``, ``ci95_high`` (estimate +- t(.975,
    df) SE), in the outcome's unit. ``terms``: one F test per model term (lmerTest's type III table, the same
    df method): ``term`` (the formula's name, e.g. 'sequence'), ``num_df``, ``den_df``, ``f``, ``p``.
    ``variances``: the variance of each random effect and of the residual
    [outcome unit squared], keyed by R's group name ('subject', 'item', 'Residual'). ``singular``: lme4's
    isSingular (a variance estimated as 0 or a correlation as +-1); ``converged``: lme4 reported no
    convergence problem; ``messages``: every warning and message of the fit; ``ddf``; ``formula``;
    ``n_observations``; ``versions`` of R, lme4 and lmerTest. ``pairs``: when the first factor of ``factors``
    has three or more levels, every pairwise contrast of its estimated marginal means (R's emmeans, the same
    df method), ``contrast`` ('later - earlier' in the factor's order), ``estimate``, ``std_error``, ``df``,
    ``t``, ``p``, ``p_holm`` (Holm among these contrasts), ``ci95_low``, ``ci95_high``; else None, and
    ``pairs_note`` says why."""

    formula: str
    ddf: str
    fixed: "pandas.DataFrame"
    terms: "pandas.DataFrame"
    variances: dict[str, float]
    singular: bool
    converged: bool
    messages: str
    n_observations: int
    versions: str
    pairs: typing.Optional["pandas.DataFrame"] = None
    pairs_note: str = ""

    @property
    def trustworthy(self) -> bool:
        """Converged and not singular: only then are its tests reported as tests."""
        return self.converged and not self.singular

    def note(self, variances: str) -> str:
        """What a report says of the fit: "not tested: ..." with why (singular, with ``variances``, the variances
        as the caller writes them; not converged, with lme4's messages), else "variances: ..."."""
        problems = []
        if self.singular:
            problems.append(f"singular fit (a variance estimated at 0 or a correlation at +-1: {variances})")
        if not self.converged:
            problems.append("did not converge: " + self.messages)
        return ("not tested: " + "; ".join(problems)) if problems else f"variances: {variances}"


def r_available() -> bool:
    """Whether Rscript with lme4, lmerTest and pbkrtest can be run here."""
    try:
        _check_r()
    except RUnavailable:
        return False
    return True


_R_CHECKED: list[bool] = []


class _RServer:
    """``Rscript lmer_fit.R --serve``: one request a line, one marked reply a line. Owned by the process that
    started it (a forked child starts its own rather than share the pipes) and used under a lock."""

    _MARK = "@@calligraphy "

    def __init__(self, rscript: str) -> None:
        self.pid = os.getpid()
        self.log = tempfile.TemporaryFile(mode="w+", encoding="utf-8")
        self.process = subprocess.Popen([rscript, "--vanilla", str(_SCRIPT), "--serve"], stdin=subprocess.PIPE,
                                        stdout=subprocess.PIPE, stderr=self.log, text=True, encoding="utf-8",
                                        bufsize=1)

    def fit(self, folder: str, formula: str, ddf: str, timeout_s: float) -> str:
        """R's reply ('ok' or 'error MESSAGE'); raises TimeoutError or EOFError when R hangs or ends."""
        import selectors

        assert self.process.stdin is not None and self.process.stdout is not None
        self.process.stdin.write(f"{folder}\t{formula}\t{ddf}\n")
        self.process.stdin.flush()
        deadline = time.monotonic() + timeout_s
        with selectors.DefaultSelector() as selector:
            selector.register(self.process.stdout, selectors.EVENT_READ)
            while True:
                if not selector.select(max(0.0, deadline - time.monotonic())):
                    raise TimeoutError
                line = self.process.stdout.readline()
                if not line:
                    raise EOFError(self.stderr_tail())
                if line.startswith(self._MARK):
                    return line[len(self._MARK):].strip()

    def stderr_tail(self) -> str:
        self.log.seek(0)
        return " ".join(self.log.read().split())[-600:]

    def close(self) -> None:
        if self.process.poll() is None:
            try:
                assert self.process.stdin is not None
                self.process.stdin.close()
                self.process.wait(timeout=5)
            except (OSError, subprocess.TimeoutExpired):
                self.process.kill()
                self.process.wait()
        self.log.close()


_SERVER: list[_RServer] = []
_SERVER_LOCK = threading.Lock()


def _close_server() -> None:
    with _SERVER_LOCK:
        while _SERVER:
            server = _SERVER.pop()
            if server.pid == os.getpid():
                server.close()


atexit.register(_close_server)


def _fit_in_r(rscript: str, folder: str, formula: str, ddf: str) -> None:
    """Has the process's R server fit the model in ``folder``; raises RuntimeError naming the formula and R's
    message when the fit fails, R hangs past the timeout (it is then stopped) or R ends."""
    with _SERVER_LOCK:
        if _SERVER and (_SERVER[0].pid != os.getpid() or _SERVER[0].process.poll() is not None):
            _SERVER.pop()  # a parent's (after fork) or one that ended: start another
        if not _SERVER:
            _SERVER.append(_RServer(rscript))
        server = _SERVER[0]
        try:
            reply = server.fit(folder, formula, ddf, _TIMEOUT_S)
        except TimeoutError as error:
            _SERVER.pop()
            server.process.kill()
            server.close()
            raise RuntimeError(f"lmer: R did not finish fitting {formula} in {_TIMEOUT_S:.0f} s") from error
        except (EOFError, OSError) as error:
            _SERVER.pop()
            server.close()
            raise RuntimeError(f"lmer: R ended while fitting {formula}: {error}") from error
    if reply != "ok":
        raise RuntimeError(f"lmer: R could not fit {formula}: {reply.removeprefix('error').strip()[-600:]}")


def _check_r() -> str:
    rscript = shutil.which("Rscript")
    if rscript is None:
        raise RUnavailable("Rscript is not installed (Debian: apt-get install r-base-core r-cran-lme4 "
                           "r-cran-lmertest r-cran-pbkrtest)")
    if not _R_CHECKED:
        probe = subprocess.run(
            [rscript, "--vanilla", "-e",
             "for (p in c('lme4','lmerTest','pbkrtest')) if (!requireNamespace(p, quietly=TRUE)) "
             "{cat(p); quit(status=3)}"],
            capture_output=True, text=True, timeout=120)
        if probe.returncode != 0:
            missing = probe.stdout.strip() or "lme4/lmerTest/pbkrtest"
            raise RUnavailable(f"R's package {missing} is not installed (Debian: apt-get install "
                               f"r-cran-{missing.lower()})")
        _R_CHECKED.append(True)
    return rscript


def lmer(frame: "pandas.DataFrame", formula: str, factors: typing.Mapping[str, typing.Sequence[typing.Any]],
         *, ddf: str = "Satterthwaite") -> LmerFit:
    """Fits ``formula`` (lme4 syntax, e.g. ``outcome ~ group + (1 | subject) + (1 | item)``) to ``frame`` by
    REML and tests the fixed effects with ``ddf`` degrees of freedom ('Satterthwaite' or 'Kenward-Roger').

    frame: a pandas DataFrame with the formula's columns (names that are R identifiers); rows with a missing
    outcome must be dropped by the caller. factors: for each categorical column, its levels in order, the
    reference (the control) first; those columns are R factors with treatment coding. Returns an
    ``LmerFit``. Raises ValueError for an unknown ``ddf`` or an empty frame; RUnavailable without R and its
    packages; RuntimeError naming R's message when the fit fails (e.g. a factor with one level).
    """
    import pandas

    if ddf not in ("Satterthwaite", "Kenward-Roger"):
        raise ValueError(f"lmer: ddf must be 'Satterthwaite' or 'Kenward-Roger', got {ddf!r}")
    if frame.empty:
        raise ValueError("lmer: the frame has no rows")
    rscript = _check_r()
    with tempfile.TemporaryDirectory(prefix="calligraphy-lmer-") as folder:
        frame.to_csv(os.path.join(folder, "data.csv"), index=False, encoding="utf-8")
        levels = [{"factor": name, "level": str(level)} for name, values in factors.items() for level in values]
        pandas.DataFrame(levels, columns=["factor", "level"]).to_csv(os.path.join(folder, "levels.csv"),
                                                                    index=False, encoding="utf-8")
        _fit_in_r(rscript, folder, formula, ddf)
        fixed = pandas.read_csv(os.path.join(folder, "fixed.csv"), encoding="utf-8")
        random = pandas.read_csv(os.path.join(folder, "random.csv"), encoding="utf-8")
        terms = pandas.read_csv(os.path.join(folder, "anova.csv"), encoding="utf-8")
        info = dict(pandas.read_csv(os.path.join(folder, "fit.csv"), encoding="utf-8", dtype=str,
                                    keep_default_na=False).itertuples(index=False, name=None))
        pairs_file = os.path.join(folder, "pairs.csv")
        pairs = (pandas.read_csv(pairs_file, encoding="utf-8", dtype={"contrast": str})
                 if os.path.exists(pairs_file) else None)
    owners = {}
    for name, values in factors.items():
        for level in list(values)[1:]:
            owners[f"{name}{level}"] = (name, str(level))
    fixed.insert(1, "factor", [owners.get(term, ("", ""))[0] for term in fixed["term"]])
    fixed.insert(2, "level", [owners.get(term, ("", ""))[1] for term in fixed["term"]])
    variances = {str(group): float(variance) for group, variance in zip(random["group"], random["variance"])}
    return LmerFit(formula=formula, ddf=ddf, fixed=fixed, terms=terms, variances=variances,
                   singular=info.get("singular") == "TRUE", converged=info.get("converged") == "TRUE",
                   messages=info.get("messages", ""), pairs=pairs, pairs_note=info.get("pairs", ""),
                   n_observations=int(info.get("n_observations", "0") or 0),
                   versions=(f"R {info.get('r_version', '?')}, lme4 {info.get('lme4_version', '?')}, lmerTest "
                             f"{info.get('lmertest_version', '?')}"))
