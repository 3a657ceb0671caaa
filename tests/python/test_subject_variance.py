"""Simulated subjects differ like people: a 15-subject pilot of a protocol, fitted by lme4 with a random
intercept per subject and per character, has a subject variance that is not zero (a non-singular fit); with
the subjects alike it is singular. Needs R with lmerTest (Debian r-cran-lmertest): skipped, saying so, without
it. The same subject draws the same traits from the CLI and from calligraphy.cohort.simulate."""

import functools
import json
import pathlib
import shutil
import subprocess

import pytest

import calligraphy.cohort

pandas = pytest.importorskip("pandas")

PROTOCOLS = pathlib.Path(__file__).resolve().parents[2] / "examples" / "protocols"

# The mixed model of the study report: mean deviation by group, random intercepts for subject and characters;
# each table given is fitted on its own, one line each, in one R process (R and lmerTest load once).
FIT = r"""
suppressMessages(library(lmerTest))
for (path in commandArgs(trailingOnly = TRUE)) {
  d <- read.csv(path)
  d <- d[!is.na(d$mean_deviation_m), ]
  d$group[is.na(d$group) | d$group == ""] <- "all"
  f <- if (length(unique(d$group)) > 1) mean_deviation_m ~ group + (1|subject) + (1|characters) else
    mean_deviation_m ~ 1 + (1|subject) + (1|characters)
  fit <- suppressMessages(suppressWarnings(lmer(f, data = d)))
  vc <- as.data.frame(VarCorr(fit))
  cat(isSingular(fit), vc$sdcor[vc$grp == "subject"], "\n")
}
"""


@functools.lru_cache(maxsize=None)  # one probe per run (a skip is raised again, not cached)
def _rscript():
    rscript = shutil.which("Rscript")
    if rscript is None:
        pytest.skip("Rscript is not installed (Debian r-base-core): the lme4 fit cannot run")
    probe = subprocess.run([rscript, "-e", "quit(status = !requireNamespace('lmerTest', quietly = TRUE))"],
                           capture_output=True)
    if probe.returncode != 0:
        pytest.skip("R has no lmerTest (Debian r-cran-lmertest): the lme4 fit cannot run")
    return rscript


def _fit(rscript, trials_csvs, tmp_path):
    """[(singular, the subject's SD)] of each table, in order."""
    script = tmp_path / "fit.R"
    script.write_text(FIT, encoding="utf-8")
    out = subprocess.run([rscript, str(script), *map(str, trials_csvs)], capture_output=True, text=True,
                         check=True)
    lines = out.stdout.splitlines()
    assert len(lines) == len(trials_csvs), out.stdout
    return [(singular == "TRUE", float(subject_sd)) for singular, subject_sd in map(str.split, lines)]


@pytest.mark.parametrize("profile", ["foreign", "novice"])
def test_a_pilot_has_a_subject_variance_only_when_subjects_differ(cli, tmp_path, profile):
    rscript = _rscript()
    tables = {}
    for differences in ("on", "off"):
        tables[differences] = tmp_path / differences
        tables[differences].mkdir()
        subprocess.run([cli, "session", "cohort", str(PROTOCOLS / "retention-transfer.json"), "--subjects", "15",
                        "--writer-profile", profile, "--individual-differences", differences, "--jobs", "2",
                        "--csv", str(tables[differences])], check=True, capture_output=True)
    (singular_on, subject_sd_on), (singular_off, subject_sd_off) = _fit(
        rscript, [tables["on"] / "trials.csv", tables["off"] / "trials.csv"], tmp_path)
    assert not singular_on and subject_sd_on > 1e-4  # metres: a tenth of a millimetre at least
    assert singular_off and subject_sd_off < 1e-6  # lme4 puts it at the boundary (0 or round-off)


def test_the_cli_and_python_draw_the_same_subjects(cli, tmp_path):
    # retention-transfer with its training once per character: both days and every phase, each subject's traits
    # on every row (14 a subject instead of 23), drawn from the subject's id whatever the trials.
    document = json.loads((PROTOCOLS / "retention-transfer.json").read_text(encoding="utf-8"))
    training = next(phase for phase in document["phases"] if phase["phase"] == "training")
    assert training["repetitions"] == 4
    training["repetitions"] = 1
    protocol = tmp_path / "protocol" / "retention-transfer.json"
    protocol.parent.mkdir()
    protocol.write_text(json.dumps(document, ensure_ascii=False), encoding="utf-8")
    subprocess.run([cli, "session", "cohort", str(protocol), "--subjects", "3", "--writer-profile", "novice",
                    "--csv", str(tmp_path)], check=True, capture_output=True)
    from_cli = pandas.read_csv(tmp_path / "trials.csv", float_precision="round_trip")
    study = calligraphy.cohort.simulate(protocol, 3, profile="novice", workers=1, progress=False)
    columns = [c for c in from_cli.columns if c.startswith("subject_")]
    assert len(columns) == 8
    for column in columns:
        pandas.testing.assert_series_equal(from_cli[column], study.trials[column], check_names=False)
    assert from_cli.groupby("subject").subject_writing_speed_factor.nunique().eq(1).all()  # one person each
    assert from_cli.subject_writing_speed_factor.nunique() == 3
    alike = calligraphy.cohort.simulate(protocol, 3, profile="novice", individual_differences=False, workers=1,
                                        progress=False)
    assert alike.trials.subject_writing_speed_factor.isna().all()
    with pytest.raises(TypeError, match="individual_differences"):
        calligraphy.cohort.simulate(protocol, 3, individual_differences="yes")
