"""The old path of ``calligraphy.stats.study``, kept: importing it gives that very module (the same object,
so a name set on one is set on the other). docs/python.md ("Packages")."""

import sys
import typing

from .stats import study as _module

if typing.TYPE_CHECKING:  # pragma: no cover - what type checkers see here
    from .stats.study import *  # noqa: F401,F403

sys.modules[__name__] = _module
