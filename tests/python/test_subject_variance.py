"""Simulated subjects differ like people: a 9-subject pilot of a protocol (three a group, the training once
per character), fitted by lme4 with a random intercept per subject and per character, has a subject variance
that is not zero (a non-singular fit); with the subjects alike it is singular. Needs R with lmerTest (Debian
r-cran-lmertest): skipped, saying so, without it. The same subject draws the same traits from the CLI and
from calligraphy.cohort.simulate."""

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
# each table given is fitted on its own, one line each, in one R process (R and lmerTest load once for the
# four tables of the run).
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


def _trained_once(folder):
    """retention-transfer with its training once per character: both days and every phase, the three groups,
    14 trials a subject instead of 23."""
    document = json.loads((PROTOCOLS / "retention-transfer.json").read_text(encoding="utf-8"))
    training = next(phase for phase in document["phases"] if phase["phase"] == "training")
    assert training["repetitions"] == 4
    training["repetitions"] = 1
    protocol = folder / "retention-transfer.json"
    protocol.write_text(json.dumps(document, ensure_ascii=False), encoding="utf-8")
    return protocol


PROFILES = ("foreign", "novice")


@pytest.fixture(scope="module")
def pilots(cli, tmp_path_factory):
    """{(profile, "on"|"off"): (singular, the subject's SD)}: the pilot of 9 subjects (three a group) of each
    profile with individual differences on and off, the four tables fitted in one R process."""
    rscript = _rscript()
    folder = tmp_path_factory.mktemp("pilots")
    protocol = _trained_once(folder)
    tables = {}
    for profile in PROFILES:
        for differences in ("on", "off"):
            out = folder / f"{profile}-{differences}"
            out.mkdir()
            subprocess.run([cli, "session", "cohort", str(protocol), "--subjects", "9", "--writer-profile", profile,
                            "--individual-differences", differences, "--jobs", "2", "--csv", str(out)], check=True,
                           capture_output=True)
            tables[profile, differences] = out / "trials.csv"
    return dict(zip(tables, _fit(rscript, list(tables.values()), folder)))


@pytest.mark.parametrize("profile", PROFILES)
def test_a_pilot_has_a_subject_variance_only_when_subjects_differ(pilots, profile):
    (singular_on, subject_sd_on), (singular_off, subject_sd_off) = pilots[profile, "on"], pilots[profile, "off"]
    assert not singular_on and subject_sd_on > 1e-4  # metres: a tenth of a millimetre at least
    assert singular_off and subject_sd_off < 1e-6  # lme4 puts it at the boundary (0 or round-off)


def test_the_cli_and_python_draw_the_same_subjects(cli, tmp_path):
    # retention-transfer with its training once per character: each subject's traits on every row, drawn from the
    # subject's id whatever the trials.
    (tmp_path / "protocol").mkdir()
    protocol = _trained_once(tmp_path / "protocol")
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
    # Subjects alike carry no traits, each of them: one says so.
    alike = calligraphy.cohort.simulate(protocol, 1, profile="novice", individual_differences=False, workers=1,
                                        progress=False)
    assert alike.trials.subject_writing_speed_factor.isna().all()
    with pytest.raises(TypeError, match="individual_differences"):
        calligraphy.cohort.simulate(protocol, 3, individual_differences="yes")
