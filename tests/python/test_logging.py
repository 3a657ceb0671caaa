"""The C++ log in Python's logging, and the module's version."""

import logging
import pathlib
import re

import pytest

import calligraphy


@pytest.fixture
def stiff_paper():
    # Above the simulated device's stable stiffness and its passivity bound 2 b / T (b = 0.5 N s/m, the default
    # device's own damping): the renderer logs two warnings at construction (not per tick).
    return calligraphy.ForceLawParameters(paper_stiffness_n_per_m=5000.0)


@pytest.fixture(autouse=True)
def default_level():
    yield
    calligraphy.set_log_level("info")
    logging.getLogger("calligraphy").setLevel(logging.NOTSET)


def test_cpp_warnings_reach_python_logging(caplog, stiff_paper):
    caplog.set_level(logging.DEBUG, logger="calligraphy")
    calligraphy.Renderer(calligraphy.Scene("九"), stiff_paper)
    records = [r for r in caplog.records if r.name == "calligraphy"]
    assert len(records) == 2
    assert all(r.levelno == logging.WARNING and "5000" in r.getMessage() for r in records)
    assert "stable maximum" in records[0].getMessage() and "passivity bound" in records[1].getMessage()


def test_set_log_level_filters_on_the_cpp_side(caplog, stiff_paper):
    caplog.set_level(logging.DEBUG, logger="calligraphy")
    calligraphy.set_log_level(logging.ERROR)
    assert logging.getLogger("calligraphy").level == logging.ERROR
    calligraphy.Renderer(calligraphy.Scene("九"), stiff_paper)
    calligraphy.flush_log()
    assert not [r for r in caplog.records if r.name == "calligraphy"]
    calligraphy.set_log_level("warning")
    calligraphy.Renderer(calligraphy.Scene("九"), stiff_paper)
    assert len([r for r in caplog.records if r.name == "calligraphy"]) == 2


def test_set_log_level_rejects_unknown_levels():
    with pytest.raises(ValueError, match="loud"):
        calligraphy.set_log_level("loud")
    with pytest.raises(TypeError, match="level"):
        calligraphy.set_log_level(2.5)


def test_version_is_the_projects():
    cmake = (pathlib.Path(__file__).resolve().parents[2] / "CMakeLists.txt").read_text(encoding="utf-8")
    version = re.search(r"project\(calligraphy VERSION ([0-9.]+)", cmake).group(1)
    assert calligraphy.__version__ == version
