"""The fonts figures and PDF pages are drawn in, and the characters none of them has.

matplotlib's default font, DejaVu Sans, has Latin, Greek and Cyrillic but no CJK: a specimen
named ``сталь_6мм_鋼`` was drawn with a box for 鋼, and each drawing printed matplotlib's
"Glyph 37628 (...) missing from font(s) DejaVu Sans" UserWarning with its source line on the
terminal of ``pidcore report`` and ``pidcore model figures``. Within :func:`figure_fonts` a
CJK font installed on the machine (:data:`FALLBACK_FAMILIES`) draws what DejaVu Sans has not,
and a character no font has is collected, for the command to say once
(:func:`missing_glyphs_note`), instead of warned of per drawing.
"""

from __future__ import annotations

import re
import warnings
from collections.abc import Iterator
from contextlib import contextmanager

#: Families with CJK glyphs (those of Linux distributions' CJK font packages, macOS and
#: Windows), tried in this order after matplotlib's default where installed.
FALLBACK_FAMILIES: tuple[str, ...] = (
    "Noto Sans CJK JP", "Noto Sans CJK SC", "Noto Sans CJK TC", "Noto Sans CJK KR",
    "Source Han Sans", "Source Han Sans JP", "Source Han Sans SC", "WenQuanYi Zen Hei",
    "WenQuanYi Micro Hei", "Droid Sans Fallback", "IPAGothic", "IPAexGothic", "TakaoGothic",
    "UnDotum", "Hiragino Sans", "PingFang SC", "Microsoft YaHei", "Yu Gothic", "MS Gothic",
    "Malgun Gothic", "Arial Unicode MS",
)
#: matplotlib's warning of a character its fonts have no glyph for.
_MISSING_GLYPH = re.compile(r"Glyph (\d+) \(.*\) missing from font")


def installed_fallback_families() -> list[str]:
    """Those of :data:`FALLBACK_FAMILIES` matplotlib finds on this machine."""
    from matplotlib import font_manager

    names = {font.name for font in font_manager.fontManager.ttflist}
    return [family for family in FALLBACK_FAMILIES if family in names]


@contextmanager
def figure_fonts() -> Iterator[set[str]]:
    """Within: text drawn in matplotlib's default family, then in the installed
    :func:`installed_fallback_families` (matplotlib takes each glyph from the first family
    that has it); a character none has is drawn as a box and added to the set yielded, its
    warning not shown (every other warning is). The figures must be made and drawn within,
    since a text takes its font when it is made."""
    import matplotlib

    missing: set[str] = set()
    with warnings.catch_warnings():
        shown = warnings.showwarning

        def collect(message, category, filename, lineno, file=None, line=None) -> None:
            found = _MISSING_GLYPH.match(str(message))
            if found and issubclass(category, UserWarning):
                missing.add(chr(int(found.group(1))))
            else:
                shown(message, category, filename, lineno, file, line)

        warnings.showwarning = collect
        # every time, not once per source line: each character is collected
        warnings.filterwarnings("always", message=_MISSING_GLYPH.pattern,
                                category=UserWarning)
        family = matplotlib.rcParams["font.family"]
        with matplotlib.rc_context({"font.family": [*family,
                                                    *installed_fallback_families()]}):
            yield missing


def missing_glyphs_note(missing: set[str], where: str = "the figures") -> str:
    """What a command says of the characters :func:`figure_fonts` collected ("" for none)."""
    if not missing:
        return ""
    chars = "".join(sorted(missing))
    return (f"{len(missing)} character(s) could not be drawn in {where} ({chars}): no font "
            "matplotlib finds has them, so they are boxes there; a font with them installed "
            f"(e.g. {FALLBACK_FAMILIES[0]}) draws them")
