"""The old path of ``calligraphy.stats.study_report``, kept: importing it gives that very module (the same object,
so a name set on one is set on the other). docs/python.md ("Packages")."""

import sys
import typing

from .stats import study_report as _module

if typing.TYPE_CHECKING:  # pragma: no cover - what type checkers see here
    from .stats.study_report import *  # noqa: F401,F403

if __name__ == "__main__":  # python3 -m calligraphy.study_report, the command the report pages name
    sys.exit(_module.main())
else:
    sys.modules[__name__] = _module
