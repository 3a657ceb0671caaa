"""The directions of the Table 5 effects on simulated writers, with examples/python/table5.py's own code,
on embedded characters its defaults do not use (or, with CALLIGRAPHY_TABLE5_CHARACTERS set, on those).
Only directions are asserted, never sizes: the simulated writers are models, not the paper's subjects.
"""

import importlib.util
import os
import pathlib
import statistics

import pytest

EXAMPLE = pathlib.Path(__file__).resolve().parents[2] / "examples" / "python" / "table5.py"


@pytest.fixture(scope="module")
def table5():
    spec = importlib.util.spec_from_file_location("table5_example", EXAMPLE)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


@pytest.fixture(scope="module")
def characters(table5):
    chosen = os.environ.get("CALLIGRAPHY_TABLE5_CHARACTERS", "大木天")
    assert not set(chosen) & set(table5.CHARACTERS), "pick characters the example does not use by default"
    return chosen


@pytest.fixture(scope="module")
def rows(table5, characters):
    return table5.table5(4, characters=characters)


def cells(rows, writer):
    return [(char, row) for name, _, char, row in rows if name == writer]


def test_guidance_lowers_the_novices_deviation(rows):
    for char, row in cells(rows, "novice"):
        assert statistics.mean(row[True]["deviation_mm"]) < statistics.mean(row[False]["deviation_mm"]), char


def test_guided_foreign_trials_complete_in_order(rows):
    for char, row in cells(rows, "foreign"):
        assert row[True]["in_order"] == len(row[True]["time_s"]), char


def test_unguided_foreign_writer_makes_order_errors(rows):
    assert sum(sum(row[False]["order_errors"]) for _, row in cells(rows, "foreign")) > 0
