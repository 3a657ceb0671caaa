"""The Python side of an outsider's round: the calligraphy package, numpy and pandas when they are there, and the
skips that say which is missing (a build without the Python bindings runs the command-line cases alone)."""
import shutil
import tempfile
import unittest
from pathlib import Path

from outsider import CLI

try:
    import numpy as np
    import calligraphy as cg
except ImportError:  # pragma: no cover - a build without the Python bindings
    np = None
    cg = None

try:
    import pandas as pd
except ImportError:  # pragma: no cover
    pd = None

needs_python = unittest.skipIf(cg is None, "the calligraphy Python package (PYTHONPATH) or numpy is missing")
needs_pandas = unittest.skipIf(pd is None, "pandas is not installed")
needs_cli = unittest.skipUnless(CLI, "CALLIGRAPHY_CLI not set")


class SharedTrial:
    """One trial of 十 (seed 1) from Python with its trace, its columns and its score, and a temporary folder: made
    once for a test file (`SharedTrial.get()`), removed by `remove_shared_trial` (its tearDownModule)."""
    folder = None

    @classmethod
    def get(cls):
        if cls.folder is None:
            cls.folder = Path(tempfile.mkdtemp(prefix="outsider-python-"))
            cls.trial = cg.simulate_trial("十", seed=1)
            p = cls.trial.position_m
            cls.columns = {"t": cls.trial.time_s, "x": p[:, 0], "y": p[:, 1], "z": p[:, 2]}
            cls.reference = cg.score(cls.columns, "十")
        return cls


def remove_shared_trial():
    if SharedTrial.folder is not None:
        shutil.rmtree(SharedTrial.folder, ignore_errors=True)
