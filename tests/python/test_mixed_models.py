"""calligraphy.mixed_models' one R process: started once, its first frame the package check; a failed fit is an
error naming the formula and R's message and leaves the process serving; a hung fit is stopped at the timeout
and the next fit gets a new process; a forked child fits with its own process; every answer is the one-shot
script's."""

import multiprocessing
import os
import shlex
import shutil
import subprocess
import sys
import tempfile
import textwrap

import numpy as np
import pandas
import pytest

from calligraphy import mixed_models

pytestmark = pytest.mark.skipif(not mixed_models.r_available(), reason="R with lme4, lmerTest and pbkrtest is not "
                                "installed (Debian: r-base-core r-cran-lme4 r-cran-lmertest r-cran-pbkrtest)")

FORMULA = "outcome ~ condition + (1 | subject)"


def frame(seed=1, subjects=8):
    rng = np.random.default_rng(seed)
    rows = [{"subject": f"S{s}", "condition": c, "outcome": 1.0 + 0.3 * (c == "b") + level + rng.normal(0, 0.2)}
            for s, level in enumerate(rng.normal(0, 0.5, subjects)) for c in ("a", "b") for _ in range(3)]
    return pandas.DataFrame(rows)


def estimate(fit):
    return float(fit.fixed.set_index("term").loc["conditionb", "estimate"])


def test_one_r_start_checks_the_packages_and_serves_every_fit(tmp_path):
    """A Python process that asks r_available() and fits twice starts R once (a stand-in Rscript on PATH logs
    each start, then runs the real one): the serving R's first frame is the package check. A process of its own,
    as this one has R running and its check done already."""
    log = tmp_path / "starts"
    wrapper = tmp_path / "bin" / "Rscript"
    wrapper.parent.mkdir()
    wrapper.write_text(f'#!/bin/sh\necho "$*" >> {shlex.quote(str(log))}\n'
                       f'exec {shlex.quote(shutil.which("Rscript"))} "$@"\n')
    wrapper.chmod(0o755)
    code = textwrap.dedent(f"""\
        import pandas
        from calligraphy import mixed_models
        assert mixed_models.r_available()
        for seed in (1, 2):
            frame = pandas.read_csv({str(tmp_path / "frame")!r} + str(seed) + ".csv")
            fit = mixed_models.lmer(frame, {FORMULA!r}, {{"condition": ["a", "b"]}})
            print(fit.fixed.set_index("term").loc["conditionb", "estimate"])
        """)
    for seed in (1, 2):
        frame(seed=seed).to_csv(tmp_path / f"frame{seed}.csv", index=False)
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=300,
                          env=dict(os.environ, PATH=f"{wrapper.parent}{os.pathsep}{os.environ['PATH']}"))
    assert done.returncode == 0, done.stderr[-2000:]
    estimates = [float(line) for line in done.stdout.split()]
    assert len(estimates) == 2 and estimates[0] != estimates[1]  # two fits, each of its own data
    starts = log.read_text().splitlines()
    assert len(starts) == 1 and starts[0].endswith("lmer_fit.R --serve"), starts


def test_the_served_fit_is_the_one_shot_scripts():
    data = frame()
    served = mixed_models.lmer(data, FORMULA, {"condition": ["a", "b"]})
    with tempfile.TemporaryDirectory() as folder:
        data.to_csv(os.path.join(folder, "data.csv"), index=False)
        pandas.DataFrame({"factor": ["condition", "condition"], "level": ["a", "b"]}).to_csv(
            os.path.join(folder, "levels.csv"), index=False)
        subprocess.run([shutil.which("Rscript"), "--vanilla", str(mixed_models._SCRIPT), folder, FORMULA,
                        "Satterthwaite"], check=True, capture_output=True, timeout=120)
        fixed = pandas.read_csv(os.path.join(folder, "fixed.csv")).set_index("term")
    assert estimate(served) == pytest.approx(float(fixed.loc["conditionb", "estimate"]), rel=1e-9)
    assert float(served.fixed.set_index("term").loc["conditionb", "p"]) == pytest.approx(
        float(fixed.loc["conditionb", "p"]), rel=1e-9)


def test_a_failed_fit_names_the_formula_and_the_process_serves_on():
    with pytest.raises(RuntimeError, match="could not fit outcome ~ condition \\+ missing_column"):
        mixed_models.lmer(frame(), "outcome ~ condition + missing_column + (1 | subject)", {"condition": ["a", "b"]})
    assert estimate(mixed_models.lmer(frame(), FORMULA, {"condition": ["a", "b"]})) > 0


def test_a_fit_past_the_timeout_is_stopped_and_the_next_gets_a_new_process(monkeypatch):
    monkeypatch.setattr(mixed_models, "_TIMEOUT_S", 1e-6)
    with pytest.raises(RuntimeError, match="did not finish"):
        mixed_models.lmer(frame(subjects=40), FORMULA, {"condition": ["a", "b"]})
    monkeypatch.setattr(mixed_models, "_TIMEOUT_S", 600.0)
    assert estimate(mixed_models.lmer(frame(), FORMULA, {"condition": ["a", "b"]})) > 0


def _fit_in_child(queue):
    queue.put(estimate(mixed_models.lmer(frame(), FORMULA, {"condition": ["a", "b"]})))


def test_a_forked_child_fits_with_its_own_process():
    parent = estimate(mixed_models.lmer(frame(), FORMULA, {"condition": ["a", "b"]}))  # the parent's process runs
    context = multiprocessing.get_context("fork")
    queue = context.Queue()
    child = context.Process(target=_fit_in_child, args=(queue,))
    child.start()
    child.join(120)
    assert child.exitcode == 0
    assert queue.get(timeout=5) == pytest.approx(parent, rel=1e-12)
    assert estimate(mixed_models.lmer(frame(), FORMULA, {"condition": ["a", "b"]})) == pytest.approx(parent)


def test_a_fits_note_is_one_line_whatever_lme4_writes():
    fit = mixed_models.LmerFit(formula=FORMULA, ddf="Satterthwaite", fixed=pandas.DataFrame(),
                               terms=pandas.DataFrame(), variances={}, singular=False, converged=False,
                               messages="Model is nearly unidentifiable: very large eigenvalue\n - Rescale variables?",
                               n_observations=0, versions="")
    note = fit.note("subject 0.1")
    assert "\n" not in note
    assert note == ("not tested: did not converge: Model is nearly unidentifiable: very large eigenvalue - Rescale "
                    "variables?")
