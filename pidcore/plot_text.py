"""Text of pidcore's figures drawn as typed: a name or note holding ``$...$`` is not TeX math,
and one in a script the default font lacks (CJK) is drawn in an installed font that has it.

matplotlib parses every text with an even number of ``$`` as mathtext by default: a file or
specimen named ``r$\\x$.uff`` failed the whole report ("ParseFatalException: Unknown symbol:
\\x"), and ``$^$`` was drawn as a superscript. pidcore writes no math into its figures, so its
figure functions make their text with ``text.parse_math`` off (:func:`text_as_typed`); a text
keeps the setting it was made with, so a figure returned and saved later is drawn the same.

matplotlib's default font, DejaVu Sans, has Latin, Greek and Cyrillic but no CJK: a specimen
named ``сталь_6мм_鋼`` was drawn with a box for 鋼, with a "Glyph 37628 (...) missing from
font(s) DejaVu Sans" warning per drawing. :func:`text_as_typed` also makes the text in the
default family followed by the installed :data:`FALLBACK_FAMILIES`
(:func:`fallback_font_families`), matplotlib taking each glyph from the first family that has
it: every figure of the library's ``.plot()`` methods, the app and the commands passes through
it. A command says once which characters no installed font has
(:func:`pidcore.report.fonts.figure_fonts`).
"""

from __future__ import annotations

import functools
from collections.abc import Callable
from typing import ParamSpec, TypeVar

_P = ParamSpec("_P")
_R = TypeVar("_R")


#: Families with CJK glyphs (those of Linux distributions' CJK font packages, macOS and
#: Windows), tried in this order after matplotlib's default where installed.
FALLBACK_FAMILIES: tuple[str, ...] = (
    "Noto Sans CJK JP", "Noto Sans CJK SC", "Noto Sans CJK TC", "Noto Sans CJK KR",
    "Source Han Sans", "Source Han Sans JP", "Source Han Sans SC", "WenQuanYi Zen Hei",
    "WenQuanYi Micro Hei", "Droid Sans Fallback", "IPAGothic", "IPAexGothic", "TakaoGothic",
    "UnDotum", "Hiragino Sans", "PingFang SC", "Microsoft YaHei", "Yu Gothic", "MS Gothic",
    "Malgun Gothic", "Arial Unicode MS",
)


def installed_fallback_families() -> list[str]:
    """Those of :data:`FALLBACK_FAMILIES` matplotlib finds on this machine."""
    from matplotlib import font_manager

    names = {font.name for font in font_manager.fontManager.ttflist}
    return [family for family in FALLBACK_FAMILIES if family in names]


def fallback_font_families() -> list[str]:
    """matplotlib's ``font.family`` of the moment followed by
    :func:`installed_fallback_families` (each once: a figure function called by another
    within its settings adds none again)."""
    import matplotlib

    return list(dict.fromkeys([*matplotlib.rcParams["font.family"],
                               *installed_fallback_families()]))


def text_as_typed(func: Callable[_P, _R]) -> Callable[_P, _R]:
    """``func`` with every text it makes in matplotlib drawn as its characters, not mathtext,
    in :func:`fallback_font_families` (a text takes its font when it is made)."""
    @functools.wraps(func)
    def wrapper(*args: _P.args, **kwargs: _P.kwargs) -> _R:
        import matplotlib

        with matplotlib.rc_context({"text.parse_math": False,
                                    "font.family": fallback_font_families()}):
            return func(*args, **kwargs)

    return wrapper


__all__ = ["FALLBACK_FAMILIES", "fallback_font_families", "installed_fallback_families",
           "text_as_typed"]
