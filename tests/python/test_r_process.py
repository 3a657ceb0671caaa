"""The R process behind calligraphy.mixed_models, attacked: a formula with line breaks or tabs is one request;
an R that answers without its result files, in Latin-1, cut short, twice, out of protocol or not at all spoils
only that fit (RAnswerError, "not computed" in a report) and the next fit gets a working R; an R whose first
frame names a missing package, that ends or stays silent before it, is R unavailable in one line; R ends with a
Python killed by SIGTERM. A stand-in Rscript on PATH plays the broken R; the real R is used where it is
installed."""

import os
import signal
import subprocess
import sys
import textwrap
import time

import numpy as np
import pandas
import pytest

from calligraphy import design_analysis, mixed_models

FORMULA = "outcome ~ condition + (1 | subject)"
FACTORS = {"condition": ["a", "b"]}

# Plays `Rscript --vanilla lmer_fit.R --serve` as the mode in CALLIGRAPHY_FAKE_R says. Its first frame says
# every package loads, but in the modes "start-*": no package, another's name, a broken frame, silence, or an
# end before it. Its files hold the request's number as the estimate, so a test sees which request an answer
# belongs to.
FAKE_RSCRIPT = textwrap.dedent("""\
    #!/usr/bin/python3
    import os, sys, time
    mode = os.environ["CALLIGRAPHY_FAKE_R"]
    with open(os.environ["CALLIGRAPHY_FAKE_R_PID"], "w") as stream:
        stream.write(str(os.getpid()))
    # A Latin-1 locale's chatter before the first frame, as R's own messages there are.
    sys.stdout.buffer.write("Chargement requis : Matrix (d\u00e9j\u00e0)\\n".encode("latin-1"))
    sys.stdout.flush()
    if mode == "start-missing":
        print("@@calligraphy-ready missing " + "lmerTest".encode().hex(), flush=True)
        sys.exit(3)
    elif mode == "start-odd-name":
        print("@@calligraphy-ready missing " + "lme4; rm -rf /".encode().hex(), flush=True)
        sys.exit(3)
    elif mode == "start-garbage":
        print("@@calligraphy-ready perhaps", flush=True)
        time.sleep(600)
    elif mode == "start-hang":
        time.sleep(600)
    elif mode == "start-die":
        sys.stderr.write("Error: R could not load its base package\\n")
        sys.exit(2)
    print("@@calligraphy-ready ok", flush=True)

    def files(folder, number, encoding="utf-8", note="ok"):
        tables = {
            "fixed.csv": 'term,estimate,std_error,df,t,p,ci95_low,ci95_high\\n"(Intercept)",%d,1,3,1,0.5,-1,1\\n',
            "random.csv": 'group,variance\\n"subject",1\\n"Residual",1\\n',
            "anova.csv": 'term,num_df,den_df,f,p\\n"condition",1,3,1,0.5\\n',
            "fit.csv": ('key,value\\n"n_observations","4"\\n"singular","FALSE"\\n"converged","TRUE"\\n'
                        '"messages","%s"\\n'),
        }
        sizes = []
        for name, text in tables.items():
            if name == "fixed.csv":
                text = text % number
            elif name == "fit.csv":
                text = text % note
            data = text.encode(encoding)
            with open(os.path.join(folder, name), "wb") as stream:
                stream.write(data)
            sizes.append(f"{name}={len(data)}")
        return ";".join(sizes)

    for line in sys.stdin:
        fields = line.split()
        number = int(fields[1])
        folder = bytes.fromhex(fields[2]).decode()
        formula = bytes.fromhex(fields[3]).decode()
        reply = lambda status, text: print(f"@@calligraphy-reply {number} {status} {text.encode().hex()}", flush=True)
        print("a package's chatter, with a marker in the middle @@calligraphy-reply 1 ok", flush=True)
        if mode == "hang":
            time.sleep(600)
        elif mode == "die":
            sys.exit(3)
        elif mode == "no-files":
            reply("ok", "fixed.csv=10;random.csv=10;anova.csv=10;fit.csv=10")
        elif mode == "latin1":
            reply("ok", files(folder, number, "latin-1", note="R\\u00e9sum\\u00e9"))
        elif mode == "cut":
            sizes = files(folder, number)
            with open(os.path.join(folder, "fixed.csv"), "r+b") as stream:
                stream.truncate(20)
            reply("ok", sizes)
        elif mode == "twice":
            sizes = files(folder, number)
            reply("ok", sizes)
            reply("ok", sizes)
        elif mode == "garbage":
            print(f"@@calligraphy-reply {number} perhaps", flush=True)
        elif mode == "other-number":
            print(f"@@calligraphy-reply {number + 5} ok {files(folder, number).encode().hex()}", flush=True)
        elif mode == "formula":
            reply("ok", files(folder, len(formula)))
    """)


@pytest.fixture
def fake_r(tmp_path, monkeypatch):
    """Puts the stand-in Rscript first on PATH and returns a function that sets its mode; the module's R is
    forgotten before and after, so no other test meets the stand-in."""
    script = tmp_path / "bin" / "Rscript"
    script.parent.mkdir()
    script.write_text(FAKE_RSCRIPT)
    script.chmod(0o755)
    monkeypatch.setenv("PATH", f"{script.parent}{os.pathsep}{os.environ['PATH']}")
    monkeypatch.setenv("CALLIGRAPHY_FAKE_R_PID", str(tmp_path / "r.pid"))
    mixed_models._close_server()

    def mode(name):
        mixed_models._close_server()  # a new mode needs a new process
        os.environ["CALLIGRAPHY_FAKE_R"] = name

    yield mode
    mixed_models._close_server()
    os.environ.pop("CALLIGRAPHY_FAKE_R", None)


def frame(seed=1, subjects=6):
    rng = np.random.default_rng(seed)
    rows = [{"subject": f"S{s}", "condition": c, "outcome": 1.0 + 0.3 * (c == "b") + level + rng.normal(0, 0.2)}
            for s, level in enumerate(rng.normal(0, 0.5, subjects)) for c in ("a", "b") for _ in range(2)]
    return pandas.DataFrame(rows)


def intercept(fit):
    return float(fit.fixed.set_index("term").loc["(Intercept)", "estimate"])


@pytest.mark.parametrize("mode, message", [
    ("no-files", "fixed.csv missing"),
    ("latin1", "fit.csv not UTF-8"),
    ("cut", "fixed.csv 20 bytes where R's reply says"),
    ("garbage", "out of protocol"),
    ("other-number", "out of protocol: a reply to request '6'"),
    ("die", "ended while fitting"),
])
def test_a_broken_answer_spoils_that_fit_alone(fake_r, mode, message):
    fake_r(mode)
    with pytest.raises(mixed_models.RAnswerError, match=message):
        mixed_models.lmer(frame(), FORMULA, FACTORS)
    # The broken process is gone; a working one answers the next fit whole.
    fake_r("twice")
    assert intercept(mixed_models.lmer(frame(), FORMULA, FACTORS)) == 1.0


def test_a_second_answer_to_one_request_is_not_taken_for_the_next(fake_r):
    fake_r("twice")
    assert [intercept(mixed_models.lmer(frame(), FORMULA, FACTORS)) for _ in range(3)] == [1.0, 2.0, 3.0]


def test_a_hung_r_is_stopped_and_named(fake_r, monkeypatch):
    fake_r("hang")
    monkeypatch.setattr(mixed_models, "_TIMEOUT_S", 0.5)
    with pytest.raises(mixed_models.RAnswerError, match="did not finish fitting outcome ~ condition"):
        mixed_models.lmer(frame(), FORMULA, FACTORS)


def test_a_missing_package_is_r_unavailable_in_one_line(fake_r, tmp_path):
    """R's first frame names the package that does not load: the fit raises RUnavailable saying which and how to
    install it (no fit was spoilt, so not RAnswerError), r_available() is False, and that R has ended."""
    fake_r("start-missing")
    with pytest.raises(mixed_models.RUnavailable) as caught:
        mixed_models.lmer(frame(), FORMULA, FACTORS)
    assert not isinstance(caught.value, mixed_models.RAnswerError)
    assert str(caught.value) == "R's package lmerTest is not installed (Debian: apt-get install r-cran-lmertest)"
    assert not running(r_pid_of(tmp_path))
    assert not mixed_models.r_available()
    fake_r("twice")
    assert intercept(mixed_models.lmer(frame(), FORMULA, FACTORS)) == 1.0


@pytest.mark.parametrize("mode, message", [
    ("start-die", "Rscript ended before saying whether lme4, lmerTest and pbkrtest load: Error: R could not load "
                  "its base package"),
    ("start-garbage", "Rscript answered the question whether lme4, lmerTest and pbkrtest load out of protocol: "
                      "'@@calligraphy-ready perhaps'"),
    ("start-odd-name", "Rscript answered the question whether lme4, lmerTest and pbkrtest load out of protocol"),
])
def test_an_r_that_ends_or_garbles_its_first_frame_is_r_unavailable(fake_r, tmp_path, mode, message):
    fake_r(mode)
    with pytest.raises(mixed_models.RUnavailable) as caught:
        mixed_models.lmer(frame(), FORMULA, FACTORS)
    assert str(caught.value).startswith(message) and "\n" not in str(caught.value), str(caught.value)
    assert not running(r_pid_of(tmp_path)), "the R that garbled its first frame was left running"
    fake_r("twice")
    assert intercept(mixed_models.lmer(frame(), FORMULA, FACTORS)) == 1.0


def test_an_r_silent_at_its_start_is_stopped_and_named(fake_r, tmp_path, monkeypatch):
    """An R that never says whether its packages load counts as R not installed after _START_TIMEOUT_S, ended;
    the fit's own time-out is not what stops it."""
    fake_r("start-hang")
    monkeypatch.setattr(mixed_models, "_START_TIMEOUT_S", 0.5)
    started = time.monotonic()
    with pytest.raises(mixed_models.RUnavailable) as caught:
        mixed_models.lmer(frame(), FORMULA, FACTORS)
    assert time.monotonic() - started < 30
    assert str(caught.value) == "Rscript did not answer within 0.5 s when asked for lme4, lmerTest and pbkrtest"
    assert not running(r_pid_of(tmp_path))


def test_an_r_whose_start_fails_before_it_runs_is_r_unavailable_not_a_wait(fake_r, monkeypatch):
    """The child's set-up between fork and exec failing (subprocess's SubprocessError, not an OSError) is
    "Rscript could not be run", at once."""
    fake_r("twice")

    def broken():
        raise ValueError("no prctl here")

    monkeypatch.setattr(mixed_models, "_keep_with_parent", broken)
    started = time.monotonic()
    with pytest.raises(mixed_models.RUnavailable, match="^Rscript could not be run: "):
        mixed_models.lmer(frame(), FORMULA, FACTORS)
    assert time.monotonic() - started < 30


def test_line_breaks_and_tabs_in_a_formula_are_one_request(fake_r):
    fake_r("formula")
    formula = "outcome ~ condition\n  +\t(1 | subject)\n"
    assert intercept(mixed_models.lmer(frame(), formula, FACTORS)) == len(formula)  # reached R whole


def test_a_report_row_says_not_computed_and_the_rest_is_made(fake_r):
    from test_design_analysis import between_study

    fake_r("latin1")
    questions = pandas.DataFrame(design_analysis.design_questions(between_study(3), "mean_deviation_m"))
    spoiled = questions[questions["note"].astype(str).str.contains("not whole")]
    assert len(spoiled) >= 1 and spoiled["note"].str.startswith("not computed").all()
    # The rows that need no mixed model (the ANCOVA of the post-test, by R's lm in Python) are still made.
    assert questions["note"].astype(str).str.contains("not whole").sum() < len(questions)


def r_pid_of(tmp_path):
    deadline = time.monotonic() + 30
    while time.monotonic() < deadline:
        if (tmp_path / "r.pid").exists() and (tmp_path / "r.pid").read_text():
            return int((tmp_path / "r.pid").read_text())
        time.sleep(0.05)
    raise AssertionError("the stand-in R never started")


def running(pid):
    try:
        with open(f"/proc/{pid}/stat") as stream:
            return stream.read().rsplit(")", 1)[1].split()[0] != "Z"  # a zombie has ended
    except FileNotFoundError:
        return False


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="reads /proc")
@pytest.mark.parametrize("in_thread", [False, True])
def test_r_ends_with_a_python_killed_by_sigterm(fake_r, tmp_path, in_thread):
    """R mid-fit, its Python killed by SIGTERM (no atexit runs): R ends too. Started from a worker thread that
    has since ended, R still serves (it is tied to the process, not to that thread)."""
    fake_r("hang")
    child = textwrap.dedent(f"""\
        import threading, time, pandas
        from calligraphy import mixed_models
        frame = pandas.DataFrame({{"subject": ["a", "a", "b", "b"], "condition": ["a", "b", "a", "b"],
                                   "outcome": [1.0, 2.0, 1.5, 2.5]}})
        fit = lambda: mixed_models.lmer(frame, "outcome ~ condition + (1 | subject)", {{"condition": ["a", "b"]}})
        if {in_thread}:
            worker = threading.Thread(target=mixed_models.r_available)  # starts the serving R
            worker.start()
            worker.join()
        fit()
        """)
    python = subprocess.Popen([sys.executable, "-c", child], env=dict(os.environ))
    try:
        r_pid = r_pid_of(tmp_path)
        time.sleep(0.5)
        assert python.poll() is None and running(r_pid), "R should be fitting when Python is killed"
        python.send_signal(signal.SIGTERM)
        python.wait(timeout=30)
        deadline = time.monotonic() + 10
        while running(r_pid) and time.monotonic() < deadline:
            time.sleep(0.05)
        assert not running(r_pid), "R outlived its Python"
    finally:
        if python.poll() is None:
            python.kill()


def test_real_r_fits_a_formula_written_over_lines_as_on_one():
    mixed_models._close_server()  # no stand-in left serving
    # Asked here, not when the file is collected: the R that answers is the one that serves the fits below
    # (the stand-ins' cases end any R running before them).
    if not mixed_models.r_available():
        pytest.skip("R with lme4, lmerTest and pbkrtest is not installed")
    one_line = mixed_models.lmer(frame(subjects=8), FORMULA, FACTORS)
    over_lines = mixed_models.lmer(frame(subjects=8), "outcome ~ condition +\n\t(1 | subject)", FACTORS)
    estimate = lambda fit: float(fit.fixed.set_index("term").loc["conditionb", "estimate"])
    assert estimate(over_lines) == estimate(one_line)
    with pytest.raises(RuntimeError, match="could not fit"):
        mixed_models.lmer(frame(), "outcome ~ condition +\n missing + (1 | subject)", FACTORS)
    assert estimate(mixed_models.lmer(frame(subjects=8), FORMULA, FACTORS)) == estimate(one_line)
