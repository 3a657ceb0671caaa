"""A font with the Chinese characters for matplotlib's figures: the study report's and ``calligraphy.plot``'s.

matplotlib is imported when a font is looked up, not with this module (Debian: python3-matplotlib; for the
characters fonts-arphic-ukai or fonts-noto-cjk). Without such a font the characters may show as boxes.
"""

from __future__ import annotations

import functools
import re
import typing
import warnings

if typing.TYPE_CHECKING:  # pragma: no cover
    import matplotlib.font_manager

__all__ = ["cjk_font"]

# Font families with the CJK Unified Ideographs, most wanted first (Kai, like the data's Arphic glyphs).
_CJK_FAMILIES = (
    "AR PL UKai CN", "AR PL UKai TW", "AR PL UKai HK", "AR PL UMing CN", "AR PL UMing TW",
    "Noto Sans CJK SC", "Noto Serif CJK SC", "Noto Sans CJK JP", "Source Han Sans CN",
    "WenQuanYi Zen Hei", "WenQuanYi Micro Hei", "Droid Sans Fallback",
)
_CJK_FILES = re.compile(r"ukai|uming|notosanscjk|notoserifcjk|sourcehan|wqy|droidsansfallback", re.I)


@functools.lru_cache(maxsize=None)
def cjk_font() -> matplotlib.font_manager.FontProperties | None:
    """A font with Chinese characters from matplotlib's font manager, or None (with a warning) when
    none is installed. Prefers AR PL UKai (fonts-arphic-ukai), then UMing, Noto CJK (fonts-noto-cjk),
    Source Han, WenQuanYi, Droid Sans Fallback. ImportError naming the package when matplotlib is missing."""
    try:
        from matplotlib import font_manager
    except ImportError as error:  # pragma: no cover - depends on the installation
        raise ImportError(
            "calligraphy.stats.fonts needs matplotlib (Debian: apt-get install python3-matplotlib; or pip install "
            "matplotlib)"
        ) from error

    fonts = font_manager.fontManager.ttflist
    for family in _CJK_FAMILIES:
        for font in fonts:
            if font.name == family:
                return font_manager.FontProperties(fname=font.fname)
    for font in fonts:
        if _CJK_FILES.search(font.fname):
            return font_manager.FontProperties(fname=font.fname)
    warnings.warn("calligraphy: no CJK font found (install fonts-arphic-ukai or fonts-noto-cjk); "
                  "characters will not show", stacklevel=2)
    return None
