"""Linear mixed models fitted by the field's reference implementation: R's lme4 (Bates, Maechler, Bolker &
Walker 2015, J Stat Softw 67(1)) with lmerTest's small-sample degrees of freedom (Kuznetsova, Brockhoff &
Christensen 2017, J Stat Softw 82(13)): Satterthwaite (1946) by default, Kenward & Roger (1997, Biometrics
53:983) through pbkrtest.

``lmer(frame, formula, factors)`` writes ``frame`` to a temporary folder and has R fit it with the package's
``lmer_fit.R``; nothing is re-implemented in Python. One R process per Python process serves every fit (loading
lme4 takes longer than most fits), started on the first (or by ``r_available``) and ended at exit; its first
frame says whether lme4, lmerTest and pbkrtest load, so R is started once, not once more to ask. R and its
packages come from Debian:
``apt-get install r-base-core r-cran-lme4 r-cran-lmertest r-cran-pbkrtest`` (scripts/install-deps.sh).
Without them ``lmer`` raises ``RUnavailable``, which callers report as "not computed" and never replace
with a large-sample Wald test. R speaks a framed protocol (each request and reply one line of hex fields
carrying the request's number) and its result files are read only when whole, so a formula, a package's
output or a broken R spoils at most the one fit (``RAnswerError``); R ends with the Python process, on a
signal too.
"""

from __future__ import annotations

import atexit
import csv
import dataclasses
import io
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

__all__ = ["LmerFit", "RAnswerError", "RUnavailable", "lmer", "r_available"]

_SCRIPT = pathlib.Path(__file__).with_name("lmer_fit.R")
# A fit of a few thousand trials takes seconds; a hung R is stopped instead of hanging a report.
_TIMEOUT_S = 600.0
# Loading lme4, lmerTest and pbkrtest takes seconds; an R silent for longer at its start counts as not installed.
_START_TIMEOUT_S = 120.0
# A reply is a few hundred bytes; a package's chatter is lines of text. A longer line is no answer.
_LONGEST_LINE_BYTES = 64 << 20


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
            # lme4's messages break their lines ("very large eigenvalue\n - Rescale variables?"): one line in a
            # table's cell and a page's sentence.
            problems.append("did not converge: " + " ".join(self.messages.split()))
        return ("not tested: " + "; ".join(problems)) if problems else f"variances: {variances}"


def r_available() -> bool:
    """Whether Rscript with lme4, lmerTest and pbkrtest can be run here. Asking starts the process's serving R
    (when none runs), which then serves the fits that follow."""
    try:
        _check_r()
    except RUnavailable:
        return False
    return True


class RAnswerError(RUnavailable):
    """R could not answer one fit as a whole: it ended, hung past the timeout, or answered with something
    other than its one framed reply and the result files that reply names (missing, cut, not UTF-8,
    columns that are not the script's, or numbers no fit gives: an infinite estimate, a negative variance, a
    p outside [0, 1]). Like ``RUnavailable`` the fit is "not computed": a caller never takes it for lme4
    refusing a model, and so never reduces the model because of it. The R that spoilt it is ended with every
    process it started, and the next fit gets a new R process."""


def _hex(text: str) -> str:
    return text.encode("utf-8").hex()


def _keep_with_parent() -> None:  # pragma: no cover - runs in the child between fork and exec
    """Linux: the child gets SIGKILL when the thread that started it ends, so R never outlives a Python
    killed by a signal (prctl PR_SET_PDEATHSIG), not even an R that ignores SIGTERM. Elsewhere R ends when its
    standard input closes."""
    import ctypes
    import signal

    try:
        ctypes.CDLL(None, use_errno=True).prctl(1, int(signal.SIGKILL), 0, 0, 0)
    except (OSError, AttributeError):
        pass


class _RServer:
    """``Rscript lmer_fit.R --serve``: one framed request a line, one framed reply a line carrying the
    request's number (lmer_fit.R describes the protocol). Owned by the process that started it (a forked child
    starts its own rather than share the pipes) and used under a lock. R is started from a thread of its own
    that lives as long as R, so that R is ended with the process (``_keep_with_parent``) and not with whichever
    thread asked for the first fit."""

    _REPLY = "@@calligraphy-reply "
    _READY = "@@calligraphy-ready "
    process: subprocess.Popen

    def __init__(self, rscript: str) -> None:
        """Starts R and waits for its first frame. Raises RUnavailable when Rscript cannot be run, names a package
        that does not load, or ends, says something else or stays silent (``_START_TIMEOUT_S``) before that
        frame; the R is then ended."""
        self.pid = os.getpid()
        self.log = tempfile.TemporaryFile(mode="w+", encoding="utf-8", errors="replace")
        self.requests = 0
        self.unread = b""  # what R wrote after the last line taken
        # Request folders left while R may still write in them (a Ctrl-C during a fit), by request number:
        # removed once R has answered that request, or has ended.
        self.abandoned: dict[int, str] = {}
        started: list[typing.Any] = []
        ready = threading.Event()

        def keep() -> None:
            try:
                started.append(subprocess.Popen(
                    [rscript, "--vanilla", str(_SCRIPT), "--serve"], stdin=subprocess.PIPE, stdout=subprocess.PIPE,
                    stderr=self.log, bufsize=0, preexec_fn=_keep_with_parent if os.name == "posix" else None,
                    start_new_session=os.name == "posix"))
            except (OSError, subprocess.SubprocessError) as error:  # the latter: the child's set-up failed
                started.append(error)
            finally:
                ready.set()  # whatever happened, the caller is not left waiting
            if isinstance(started[0], subprocess.Popen):
                started[0].wait()

        try:
            try:
                threading.Thread(target=keep, name="calligraphy-r", daemon=True).start()
            except RuntimeError as error:  # no thread to be had (a process limit): no process either
                started.append(OSError(str(error)))
                ready.set()
            ready.wait()
        except BaseException:  # a Ctrl-C while R is being started: that R is ended, not left to this process's end
            if ready.wait(30) and started and isinstance(started[0], subprocess.Popen):
                self.process = started[0]
                self.kill()
                self.close()
            raise
        if not isinstance(started[0], subprocess.Popen):
            self.log.close()
            raise RUnavailable(f"Rscript could not be run: {started[0]}")
        self.process = started[0]
        try:
            self._wait_ready(time.monotonic() + _START_TIMEOUT_S)
        except BaseException:  # also a Ctrl-C while R loads its packages: no R is left behind
            self.kill()
            self.close()
            raise

    def _wait_ready(self, deadline: float) -> None:
        """R's first frame (lmer_fit.R): 'ok', or the first of lme4, lmerTest and pbkrtest that does not load."""
        packages = ("lme4", "lmerTest", "pbkrtest")
        asked = "lme4, lmerTest and pbkrtest"
        while True:
            try:
                line = self._line(deadline)
            except TimeoutError:
                raise RUnavailable(f"Rscript did not answer within {_START_TIMEOUT_S:g} s when asked for "
                                   f"{asked}") from None
            except EOFError as error:  # its standard error, if it wrote any, says why
                raise RUnavailable(f"Rscript ended before saying whether {asked} load"
                                   + (f": {error}" if str(error) else "")) from None
            except ValueError as error:
                raise RUnavailable(f"Rscript answered the question whether {asked} load out of protocol: "
                                   f"{error}") from None
            if not line.startswith(self._READY):
                continue  # a package's or a profile's chatter
            fields = line[len(self._READY):].split(" ")
            if fields == ["ok"]:
                return
            missing = None
            if len(fields) == 2 and fields[0] == "missing":
                try:
                    missing = bytes.fromhex(fields[1]).decode("ascii")
                except (ValueError, UnicodeDecodeError):
                    pass
            # Only a package it was asked about: the frame names one of the three, never what to install.
            if missing not in packages:
                raise RUnavailable(f"Rscript answered the question whether {asked} load out of protocol: "
                                   f"{line[:200]!r}")
            raise RUnavailable(f"R's package {missing} is not installed (Debian: apt-get install "
                               f"r-cran-{missing.lower()})")

    def running(self) -> bool:
        return self.process.returncode is None and self.process.poll() is None

    def fit(self, folder: str, formula: str, ddf: str, timeout_s: float) -> tuple[str, str]:
        """R's reply to one request: ('ok', FILES) or ('error', MESSAGE). Raises TimeoutError when R hangs,
        EOFError when it ends, and ValueError when its reply to this request is not one framed reply."""
        import selectors

        assert self.process.stdin is not None and self.process.stdout is not None
        self.requests += 1
        number = str(self.requests)
        request = f"@@calligraphy-request {number} {_hex(folder)} {_hex(formula)} {_hex(ddf)}\n"
        self.process.stdin.write(request.encode("ascii"))
        self.process.stdin.flush()
        deadline = time.monotonic() + timeout_s
        while True:
            line = self._line(deadline)
            if not line.startswith(self._REPLY):
                continue  # a package's chatter
            fields = line[len(self._REPLY):].split(" ")
            if fields[0] != number:
                if fields[0].isdigit() and int(fields[0]) < self.requests:
                    self._remove_abandoned(int(fields[0]))  # R is done with that request's folder
                    continue  # a second reply to an earlier request: that request was already answered
                raise ValueError(f"a reply to request {fields[0]!r}, not {number}")
            self._remove_abandoned(self.requests - 1)  # R answers in order: every earlier request is done
            if len(fields) != 3 or fields[1] not in ("ok", "error"):
                raise ValueError(f"a reply that is not 'ok' or 'error' with one field: {line[:200]!r}")
            try:
                return fields[1], bytes.fromhex(fields[2]).decode("utf-8")
            except (ValueError, UnicodeDecodeError) as error:
                raise ValueError(f"a reply whose field is not hex UTF-8 ({error})") from error

    def _line(self, deadline: float) -> str:
        """The next line R writes, without its line break (bytes that are not UTF-8 replaced: only the
        marked lines matter, and they are ASCII). Reads the pipe unbuffered, so that a line R wrote with an
        earlier one is never left in a buffer that the wait for the pipe cannot see."""
        import selectors

        assert self.process.stdout is not None
        descriptor = self.process.stdout.fileno()
        pending = bytearray(self.unread)
        searched = 0  # the line break is looked for in what came since, so a long line costs its length once
        with selectors.DefaultSelector() as selector:
            selector.register(descriptor, selectors.EVENT_READ)
            while (end := pending.find(b"\n", searched)) < 0:
                searched = len(pending)
                if searched > _LONGEST_LINE_BYTES:
                    raise ValueError(f"a line of more than {_LONGEST_LINE_BYTES} bytes")
                # In slices, so that an R that ended while a child of its still holds the pipe open is seen
                # to have ended (its output read first), not waited on until the time-out.
                ended = self.process.poll() is not None
                if not selector.select(0.0 if ended else min(0.5, max(0.0, deadline - time.monotonic()))):
                    if ended:
                        raise EOFError(self.stderr_tail())
                    if time.monotonic() >= deadline:
                        raise TimeoutError
                    continue
                chunk = os.read(descriptor, 1 << 20)
                if not chunk:
                    raise EOFError(self.stderr_tail())
                pending += chunk
        line, self.unread = bytes(pending[:end]), bytes(pending[end + 1:])
        return line.decode("utf-8", errors="replace").rstrip("\r")

    def stderr_tail(self) -> str:
        self.log.seek(0)
        return " ".join(self.log.read().split())[-600:]

    def abandon(self, folder: str) -> None:
        """Leaves the folder of the last request to be removed once R is done with it (its answer read, or R
        ended): a fit stopped by a Ctrl-C, whose R goes on and may still write its answer there."""
        self.abandoned[self.requests] = folder

    def _remove_abandoned(self, up_to: int) -> None:
        for number in [n for n in self.abandoned if n <= up_to]:
            shutil.rmtree(self.abandoned.pop(number), ignore_errors=True)

    def kill(self) -> None:
        """R and whatever it started (its process group) ended at once."""
        if os.name == "posix":
            import signal

            try:
                os.killpg(self.process.pid, signal.SIGKILL)
            except OSError:
                pass
        self.process.kill()

    def close(self) -> None:
        if self.running():
            try:
                assert self.process.stdin is not None
                self.process.stdin.close()
                self.process.wait(timeout=5)
            except (OSError, subprocess.TimeoutExpired):
                pass
        self.kill()  # also a child R left behind, which would hold the pipes open
        self.process.wait()
        self._remove_abandoned(self.requests)
        # The pipes too, whether it ended by itself or was killed: none is left for the collector to find.
        for pipe in (self.process.stdin, self.process.stdout):
            if pipe is not None:
                try:
                    pipe.close()
                except OSError:
                    pass
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


def _serving(rscript: str) -> _RServer:
    """This process's R server, started (its packages checked by its first frame) when none runs. Called with
    ``_SERVER_LOCK`` held. Raises RUnavailable as ``_RServer`` does."""
    if _SERVER and (_SERVER[0].pid != os.getpid() or not _SERVER[0].running()):
        ended = _SERVER.pop()  # a parent's (after fork) or one that ended: start another
        if ended.pid == os.getpid():
            ended.close()  # and end what the one that ended left running
    if not _SERVER:
        _SERVER.append(_RServer(rscript))
    return _SERVER[0]


def _fit_in_r(rscript: str, folder: str, formula: str, ddf: str) -> dict[str, "pandas.DataFrame"]:
    """Has the process's R server fit the model in ``folder`` and returns the result tables its reply names,
    each checked whole (``_read_answer``). Raises RuntimeError naming the formula and R's message when lme4
    cannot fit it; RAnswerError when R hangs past the timeout, ends, answers out of protocol or with result
    files that are not whole (the server is then stopped, and the next fit starts another); RUnavailable when
    the R started for it says a package is missing (``_RServer``). Removes ``folder`` when it returns or
    raises; after a Ctrl-C (any exception that is not an Exception) while R works on it, the server removes
    it once R has answered or ended, so that the folder is never removed while R writes in it."""
    one_line = " ".join(formula.split())
    left_to_server = False
    try:
        with _SERVER_LOCK:
            server = _serving(rscript)
            try:
                return _answer_of_r(server, folder, formula, ddf, one_line)
            except BaseException as error:
                # A Ctrl-C: R goes on with the request and writes its answer in the folder. (On an Exception
                # the server was stopped where R cannot go on, _answer_of_r, or R answered already.)
                if not isinstance(error, Exception) and server.running():
                    server.abandon(folder)
                    left_to_server = True
                raise
    finally:
        if not left_to_server:
            shutil.rmtree(folder, ignore_errors=True)


def _answer_of_r(server: _RServer, folder: str, formula: str, ddf: str, one_line: str) -> dict:
    """`_fit_in_r`'s request to a running server, under the server lock."""
    try:
        status, text = server.fit(folder, formula, ddf, _TIMEOUT_S)
        if status != "ok":
            raise RuntimeError(f"lmer: R could not fit {one_line}: {' '.join(text.split())[-600:]}")
        return _read_answer(folder, formula, _named_files(text, one_line))
    except (TimeoutError, EOFError, OSError, ValueError, RAnswerError) as error:
        _SERVER.pop()
        server.kill()
        server.close()
        if isinstance(error, RAnswerError):
            raise
        if isinstance(error, TimeoutError):
            why = f"did not finish fitting {one_line} in {_TIMEOUT_S:.0f} s"
        elif isinstance(error, ValueError):
            why = f"answered the fit of {one_line} out of protocol: {error}"
        else:
            why = f"ended while fitting {one_line}: {error}"
        raise RAnswerError("lmer: R " + why) from error


def _named_files(text: str, one_line: str) -> dict[str, int]:
    """The result files an 'ok' reply names, with their sizes in bytes."""
    files: dict[str, int] = {}
    for entry in text.split(";"):
        name, _, size = entry.partition("=")
        if not (size.isascii() and size.isdigit()):
            raise RAnswerError(f"lmer: R answered the fit of {one_line} with an unreadable file list {text[:200]!r}")
        files[name] = int(size)
    return files


_RESULT_COLUMNS = {
    "fixed.csv": ("term", "estimate", "std_error", "df", "t", "p", "ci95_low", "ci95_high"),
    "random.csv": ("group", "variance"),
    "anova.csv": ("term", "num_df", "den_df", "f", "p"),
    "fit.csv": ("key", "value"),
    # only when the compared factor has three or more levels (lmer_fit.R)
    "pairs.csv": ("contrast", "estimate", "std_error", "df", "t", "p", "p_holm", "ci95_low", "ci95_high"),
}
_OPTIONAL_RESULTS = ("pairs.csv",)


def _read_answer(folder: str, formula: str, files: typing.Mapping[str, int]) -> dict[str, "pandas.DataFrame"]:
    """The result files of one fit, checked whole: each named by R's reply at the size it gave, UTF-8, with the
    script's columns, and numbers where numbers belong. Raises RAnswerError naming the file otherwise."""
    import pandas

    one_line = " ".join(formula.split())
    tables = {}
    for name, columns in _RESULT_COLUMNS.items():
        path = os.path.join(folder, name)
        if name in _OPTIONAL_RESULTS and name not in files and not os.path.exists(path):
            continue
        problem = None
        try:
            size = os.path.getsize(path)
            if name not in files:
                problem = "not named in R's reply"
            elif size != files[name]:
                problem = f"{size} bytes where R's reply says {files[name]}"
            else:
                with open(path, encoding="utf-8", errors="strict") as stream:
                    text = stream.read()
                table = pandas.read_csv(io.StringIO(text), dtype={"fit.csv": str, "pairs.csv": {"contrast": str}}.get(
                    name), keep_default_na=name != "fit.csv")
                if tuple(table.columns) != columns:
                    problem = f"columns {list(table.columns)} where {list(columns)} belong"
                elif name != "fit.csv" and len(table) and any(not pandas.api.types.is_numeric_dtype(table[c])
                                               for c in columns[1:]):
                    problem = "a value that is not a number"
                else:
                    problem = _cut_row(text, len(columns)) or _impossible_number(name, table)
                tables[name] = table
        except FileNotFoundError:
            problem = "missing"
        except UnicodeDecodeError:
            problem = "not UTF-8"
        except (OSError, ValueError, pandas.errors.ParserError) as error:
            problem = f"unreadable ({error})"
        if problem is not None:
            raise RAnswerError(f"lmer: R's answer to the fit of {one_line} is not whole: {name} {problem}")
    return tables


def _cut_row(text: str, width: int) -> typing.Optional[str]:
    """What shows a result file cut at its size (R's write.csv ends every row, the last too, with a line
    break, and gives every row every column), or None."""
    if text and not text.endswith("\n"):
        return "cut: no line break at its end"
    for number, row in enumerate(csv.reader(io.StringIO(text)), start=1):
        if len(row) != width:
            return f"cut: row {number} has {len(row)} fields where {width} belong"
    return None


# The numbers no fit of finite data gives: an infinite or missing estimate or variance, a negative standard
# error, variance, F or degrees of freedom, a p outside [0, 1]. (A missing df, t, F or p is R's NA, which a
# fit may give; random.csv's rows named "GROUP cov A B" are covariances, which may be negative.)
_NUMBER_RULES = {
    "fixed.csv": {"finite": ("estimate",), "not_infinite": ("std_error", "ci95_low", "ci95_high"),
                  "non_negative": ("std_error", "df"), "probability": ("p",)},
    # emmeans gives NA for a contrast it cannot estimate
    "pairs.csv": {"not_infinite": ("estimate", "std_error", "ci95_low", "ci95_high"),
                  "non_negative": ("std_error", "df"), "probability": ("p", "p_holm")},
    "random.csv": {"finite": ("variance",), "non_negative": ("variance",)},
    "anova.csv": {"non_negative": ("num_df", "den_df", "f"), "probability": ("p",)},
}


def _impossible_number(name: str, table: "pandas.DataFrame") -> typing.Optional[str]:
    """The first number of ``table`` (result file ``name``) no fit gives, named by column and row, or None."""
    import numpy

    rules = _NUMBER_RULES.get(name, {})
    checks = {
        "finite": lambda v: numpy.isfinite(v),
        "not_infinite": lambda v: ~numpy.isinf(v),
        "non_negative": lambda v: numpy.isnan(v) | (v >= 0),
        "probability": lambda v: numpy.isnan(v) | ((v >= 0) & (v <= 1)),
    }
    words = {"finite": "not a finite number", "not_infinite": "infinite", "non_negative": "negative",
             "probability": "outside [0, 1]"}
    covariance = (table["group"].astype(str).str.contains(" cov ", regex=False).to_numpy() if name == "random.csv"
                  else numpy.zeros(len(table), dtype=bool))
    for rule, columns in rules.items():
        for column in columns:
            values = table[column].to_numpy(dtype=float)
            bad = numpy.flatnonzero(~checks[rule](values) & ~(covariance & (rule == "non_negative")))
            if bad.size:
                return f"{column} {values[bad[0]]!r} in row {bad[0] + 2} is {words[rule]}"
    return None


def _r_backquoted(name: str) -> str:
    """The text R's deparse() puts between backquotes for a non-syntactic name."""
    escapes = {"\\": "\\\\", "`": "\\`", "\n": "\\n", "\t": "\\t", "\r": "\\r"}
    return "".join(escapes.get(character, character) for character in name)


def _check_r() -> str:
    """The Rscript on PATH, once this process's serving R has said in its first frame that lme4, lmerTest and
    pbkrtest load (started here when none runs: one R start both checks and serves). Raises RUnavailable
    naming what is missing."""
    rscript = shutil.which("Rscript")
    if rscript is None:
        raise RUnavailable("Rscript is not installed (Debian: apt-get install r-base-core r-cran-lme4 "
                           "r-cran-lmertest r-cran-pbkrtest)")
    with _SERVER_LOCK:
        _serving(rscript)
    return rscript


def lmer(frame: "pandas.DataFrame", formula: str, factors: typing.Mapping[str, typing.Sequence[typing.Any]],
         *, ddf: str = "Satterthwaite") -> LmerFit:
    """Fits ``formula`` (lme4 syntax, e.g. ``outcome ~ group + (1 | subject) + (1 | item)``) to ``frame`` by
    REML and tests the fixed effects with ``ddf`` degrees of freedom ('Satterthwaite' or 'Kenward-Roger').

    frame: a pandas DataFrame with the formula's columns (a name that is no R identifier, with a space or a
    line break, is written in backquotes in the formula); rows with a missing outcome must be dropped by the
    caller. factors: for each categorical column, its levels in order, the
    reference (the control) first; those columns are R factors with treatment coding. Returns an
    ``LmerFit``. Raises ValueError for an unknown ``ddf`` or an empty frame; RUnavailable without R and its
    packages; RuntimeError naming R's message when lme4 cannot fit it (e.g. a factor with one level);
    RAnswerError (an RUnavailable) when R ends, hangs or does not answer the fit whole.
    """
    import pandas

    if ddf not in ("Satterthwaite", "Kenward-Roger"):
        raise ValueError(f"lmer: ddf must be 'Satterthwaite' or 'Kenward-Roger', got {ddf!r}")
    if frame.empty:
        raise ValueError("lmer: the frame has no rows")
    rscript = _check_r()
    folder = tempfile.mkdtemp(prefix="calligraphy-lmer-")
    try:  # the folder is _fit_in_r's to remove once it is called
        frame.to_csv(os.path.join(folder, "data.csv"), index=False, encoding="utf-8")
        # R is told which columns are text, so that a level spelt like a number, a logical or R's NA stays text.
        numeric = pandas.api.types.is_numeric_dtype
        types = ["number" if numeric(frame[c]) and not pandas.api.types.is_bool_dtype(frame[c]) else "text"
                 for c in frame.columns]
        pandas.DataFrame({"column": [str(c) for c in frame.columns], "type": types}).to_csv(
            os.path.join(folder, "types.csv"), index=False, encoding="utf-8")
        levels = [{"factor": name, "level": str(level)} for name, values in factors.items() for level in values]
        pandas.DataFrame(levels, columns=["factor", "level"]).to_csv(os.path.join(folder, "levels.csv"),
                                                                    index=False, encoding="utf-8")
    except BaseException:
        shutil.rmtree(folder, ignore_errors=True)
        raise
    answer = _fit_in_r(rscript, folder, formula, ddf)
    fixed, random, terms = answer["fixed.csv"], answer["random.csv"], answer["anova.csv"]
    info = dict(answer["fit.csv"].itertuples(index=False, name=None))
    pairs = answer.get("pairs.csv")
    owners = {}
    for name, values in factors.items():
        for level in list(values)[1:]:
            owners[f"{name}{level}"] = (name, str(level))
            # R names the term of a factor whose name is not syntactic (a space, a line break) by the name in
            # backquotes, escaped as deparse() escapes it.
            owners[f"`{_r_backquoted(str(name))}`{level}"] = (name, str(level))
    fixed.insert(1, "factor", [owners.get(term, ("", ""))[0] for term in fixed["term"]])
    fixed.insert(2, "level", [owners.get(term, ("", ""))[1] for term in fixed["term"]])
    variances = {str(group): float(variance) for group, variance in zip(random["group"], random["variance"])}
    return LmerFit(formula=formula, ddf=ddf, fixed=fixed, terms=terms, variances=variances,
                   singular=info.get("singular") == "TRUE", converged=info.get("converged") == "TRUE",
                   messages=info.get("messages", ""), pairs=pairs, pairs_note=info.get("pairs", ""),
                   n_observations=int(info.get("n_observations", "0") or 0),
                   versions=(f"R {info.get('r_version', '?')}, lme4 {info.get('lme4_version', '?')}, lmerTest "
                             f"{info.get('lmertest_version', '?')}"))
