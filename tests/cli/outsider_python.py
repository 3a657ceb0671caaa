"""The Python side of an outsider's round: the calligraphy package, numpy and pandas when they are there, and the
skips that say which is missing (a build without the Python bindings runs the command-line cases alone)."""
import unittest

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
