"""Text of pidcore's figures drawn as typed: a name or note holding ``$...$`` is not TeX math.

matplotlib parses every text with an even number of ``$`` as mathtext by default: a file or
specimen named ``r$\\x$.uff`` failed the whole report ("ParseFatalException: Unknown symbol:
\\x"), and ``$^$`` was drawn as a superscript. pidcore writes no math into its figures, so its
figure functions make their text with ``text.parse_math`` off (:func:`text_as_typed`); a text
keeps the setting it was made with, so a figure returned and saved later is drawn the same.
"""

from __future__ import annotations

import functools
from collections.abc import Callable
from typing import ParamSpec, TypeVar

_P = ParamSpec("_P")
_R = TypeVar("_R")


def text_as_typed(func: Callable[_P, _R]) -> Callable[_P, _R]:
    """``func`` with every text it makes in matplotlib drawn as its characters, not mathtext."""
    @functools.wraps(func)
    def wrapper(*args: _P.args, **kwargs: _P.kwargs) -> _R:
        import matplotlib

        with matplotlib.rc_context({"text.parse_math": False}):
            return func(*args, **kwargs)

    return wrapper


__all__ = ["text_as_typed"]
