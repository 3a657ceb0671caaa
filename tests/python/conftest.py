"""pytest configuration of the Python binding tests.

Run from CTest (``ctest -R python``) with PYTHONPATH set to the build's ``python`` folder and
CALLIGRAPHY_CLI to the ``calligraphy`` program. A run that collects fewer tests than expected fails,
so that a broken import or a renamed file cannot pass as "no tests ran".
"""

import json
import os
import pathlib
import subprocess

import pytest

# The suite has more tests than this; collecting fewer means files were lost or skipped wholesale.
MINIMUM_TESTS = 90


def pytest_collection_finish(session):
    whole_suite = not session.config.option.keyword and all(os.path.isdir(a) for a in session.config.args)
    if whole_suite and len(session.items) < MINIMUM_TESTS:
        raise pytest.UsageError(
            f"only {len(session.items)} tests collected, expected at least {MINIMUM_TESTS}"
        )


def pytest_sessionstart(session):
    # check_wheel.py runs some of these tests in a venv: they must test the package installed there.
    expected = os.environ.get("CALLIGRAPHY_EXPECT_PACKAGE_UNDER")
    if expected:
        import calligraphy

        location = pathlib.Path(calligraphy.__file__).resolve()
        if not location.is_relative_to(pathlib.Path(expected).resolve()):
            raise pytest.UsageError(f"calligraphy imported from {location}, not from {expected}")


@pytest.fixture(scope="session")
def cli():
    path = os.environ.get("CALLIGRAPHY_CLI")
    if not path:
        pytest.fail("CALLIGRAPHY_CLI is not set: run these tests through ctest")
    if not os.path.exists(path):
        pytest.fail(f"CALLIGRAPHY_CLI={path} does not exist")
    return path


@pytest.fixture(scope="session")
def library():
    import calligraphy

    return calligraphy.CharacterLibrary.default()


@pytest.fixture(scope="session")
def small_study(cli):
    """Makes FOLDER/study: paper-table5 (examples/protocols) shrunk to one practice trial and the characters 十
    and 人 with `repetitions`, written by `subjects` simulated subjects through `calligraphy session run`."""

    def make(folder: pathlib.Path, subjects: int, repetitions: int) -> pathlib.Path:
        source = pathlib.Path(__file__).resolve().parents[2] / "examples" / "protocols" / "paper-table5.json"
        protocol = json.loads(source.read_text(encoding="utf-8"))
        protocol["practice"]["repetitions"] = 1
        protocol["test"].update({"characters": ["十", "人"], "repetitions": repetitions})
        protocol["breaks"] = {}
        (folder / "p.json").write_text(json.dumps(protocol), encoding="utf-8")
        run = subprocess.run([cli, "session", "run", "p.json", "--writer", "simulated", "--subjects", str(subjects),
                              "--out", "study"], cwd=folder, capture_output=True)
        assert run.returncode == 0, run.stderr.decode()
        return folder / "study"

    return make
