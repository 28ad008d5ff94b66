"""The characters none of the figures' fonts has, said once by a command.

Every figure function draws its text in matplotlib's default family followed by the CJK
families installed (:func:`pidcore.plot_text.text_as_typed`), so a specimen named
``сталь_6мм_鋼`` is drawn where such a font is installed. A character no font has is still a
box, and each drawing printed matplotlib's "Glyph 37628 (...) missing from font(s) DejaVu
Sans" UserWarning with its source line on the terminal of ``pidcore report`` and ``pidcore
model figures``: within :func:`figure_fonts` it is collected instead, for the command to say
once (:func:`missing_glyphs_note`).
"""

from __future__ import annotations

import re
import warnings
from collections.abc import Iterator
from contextlib import contextmanager

from ..plot_text import FALLBACK_FAMILIES, fallback_font_families

#: matplotlib's warning of a character its fonts have no glyph for.
_MISSING_GLYPH = re.compile(r"Glyph (\d+) \(.*\) missing from font")


@contextmanager
def figure_fonts() -> Iterator[set[str]]:
    """Within: text drawn in matplotlib's default family, then in the installed fallback
    families (:func:`pidcore.plot_text.fallback_font_families`: every figure function's, and
    here also of text made outside one); a character none has is drawn as a box and added to
    the set yielded, its warning not shown (every other warning is). The figures must be
    drawn within, for their warnings to be collected."""
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
        with matplotlib.rc_context({"font.family": fallback_font_families()}):
            yield missing


def missing_glyphs_note(missing: set[str], where: str = "the figures") -> str:
    """What a command says of the characters :func:`figure_fonts` collected ("" for none)."""
    if not missing:
        return ""
    chars = "".join(sorted(missing))
    return (f"{len(missing)} character(s) could not be drawn in {where} ({chars}): no font "
            "matplotlib finds has them, so they are boxes there; a font with them installed "
            f"(e.g. {FALLBACK_FAMILIES[0]}) draws them")
