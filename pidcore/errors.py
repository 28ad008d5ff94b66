"""Exception hierarchy.

Every error a user can cause derives from :class:`PidcoreError`; the CLI prints its message as
one line and exits non-zero. Messages name the file, channel or parameter and what was expected.
:func:`whole_number`, :func:`real_number` and :func:`instance_of` refuse a value of the wrong
type (a string, a bool, a fraction where a count is meant) in those words, before any use of it.

A message names a parameter as a Python caller writes it: its keyword (``structure_mass_kg``),
with a value or a placeholder where it says what to give (``key=NAME``, ``force='Fz'``,
``allow_clipped=True``), never a front-end's flag or label. The CLI says it as its flag
(``--structure-mass``: one table, :mod:`pidcore.cli._vocabulary`), the app as its field
(``'structure mass [g]'``: :mod:`pidcore.app.vocabulary`); both through
:func:`outside_user_names`, so a keyword inside the user's own names (a file
``structure_mass_kg.csv``, a folder ``key=1/``, a channel ``'force='``, a specimen
``fill_percent``) is left as the user wrote it.

Public API
----------
PidcoreError
    Base of every error a user can cause (catch it to catch them all).
InputFileError, ChannelError, SignalError, ParameterError
    What was wrong: the file, a channel, the record, a parameter.
SettingsTableError, StoreError, SimulationError
    A settings table (sidecar), the store, a DEM run.
DependencyError
    An installed library older than pidcore needs (the installation, not the user's data).
whole_number, real_number, instance_of, as_given
    The checks of a value's type, and a number shown as the user gave it.
clipped
    A value quoted in a message, whole where short, else by its start and its size.
listed
    Names listed in a message, the first few and how many more.
outside_user_names
    A message rewritten everywhere but in the names the user gave.
KEYWORD_NOT_BEFORE, KEYWORD_NOT_AFTER_WORD
    Where a keyword in a message is the parameter, as both front-ends' tables find it.
"""

import math
import numbers
import re
from collections.abc import Callable, Iterable


class PidcoreError(Exception):
    """Base class of all errors caused by user input or user data."""


class InputFileError(PidcoreError):
    """A file cannot be read, or holds nothing usable (wrong dataset type, corrupt bytes)."""


class ChannelError(PidcoreError):
    """A channel is missing, ambiguous, non-finite, clipped or inconsistent with the others."""


class SignalError(PidcoreError):
    """A record cannot be analysed: too few periods, no dominant drive frequency, ..."""


class ParameterError(PidcoreError, ValueError):
    """A parameter is out of range or of the wrong kind."""


class SettingsTableError(ParameterError):
    """A settings table (a sidecar ``loadcases.csv``) has an unknown column or a bad value. The
    message names the table's own columns (``baseline_loss_factor``), which the CLI must not
    translate to its options (``--baseline-loss-factor``)."""


class StoreError(PidcoreError):
    """The HDF5 store is missing, corrupt, locked or lacks the requested entry."""


class SimulationError(PidcoreError):
    """A DEM run became unphysical (excess overlap, particle escaped) or was refused."""


class DependencyError(PidcoreError):
    """An installed library lacks what pidcore calls (older than pidcore's requirement): the
    message names the library, its version and the version needed, so that an installation
    is not blamed on the user's file."""


def as_given(value: float) -> str:
    """A number in an error message, as the user gave it: ``:g`` where that reads back to the
    same value (``5``, ``0.05``), else the shortest text that does (``1.0000001``).

    ``:g`` alone keeps 6 digits: ``baseline_loss_factor = 1.0000001`` was refused as
    ``1: expected a fraction``, a message about a value that is accepted.
    """
    short = f"{value:g}"
    try:
        return short if float(short) == value else repr(float(value))
    except (TypeError, ValueError):  # not a number: as Python shows it
        return repr(value)


def a_or_an(word: str) -> str:
    """``word`` after its indefinite article, for messages that name a quantity or role:
    "an acceleration", "a force" ("a acceleration unit" was printed)."""
    return f"{'an' if word[:1].lower() in 'aeiou' else 'a'} {word}"


def apart(first: float, second: float) -> tuple[str, str]:
    """Two numbers said side by side (a fill asked and the fill of the run used): each as the
    other lines print it (``:g``, 6 significant digits), with only as many more digits as it
    takes to tell them apart where 6 alone would show two different numbers alike.

    :func:`as_given` on both printed a fill of 4 of 23 particles as ``17.391304347826086``
    beside the ``17.3913`` of every other line; ``:g`` on both read "fill 21.7391 % asked;
    reused ... fill 21.7391 %" of two fills that differ in the 7th digit.
    """
    for digits in range(6, 17):  # 17 digits tell any two doubles apart: repr, shorter
        shown = f"{first:.{digits}g}", f"{second:.{digits}g}"
        if shown[0] != shown[1] or first == second:
            return shown
    return repr(float(first)), repr(float(second))


#: Longest value or key quoted whole in a message, characters: a value is a number or a name;
#: a longer one (a 2-million-item array was quoted whole, a 6 MB error "line") is shown by its
#: start and its size (:func:`clipped`).
MAX_SHOWN_CHARS = 80


def clipped(text: str, most: int = MAX_SHOWN_CHARS) -> str:
    """``text`` (a repr, a key, a line of a file) for a one-line message: whole where it has
    at most ``most`` characters, else its first ``most - 20`` and its size, ``"[0.0, 1.0,
    ...... (2000000 characters)"``, which together take about ``most``. Every message that
    quotes a value the user gave shortens it here, so that each says the same of a cut."""
    if len(text) <= most:
        return text
    return f"{text[:max(most - 20, 1)]}... ({len(text)} characters)"


#: Most names a message lists before it counts the rest: a MAT matrix read the wrong way
#: round was thousands of channels, and the "one-line" error naming them 173 kB.
MAX_LISTED_NAMES = 12


def listed(names: Iterable[object], most: int = MAX_LISTED_NAMES) -> str:
    """``'Force', 'Velocity'``: the names quoted (each :func:`clipped`), the first ``most``
    and how many more (``'Signal 1.1', 'Signal 1.2' and 10228 more``); ``"none"`` for none."""
    names = list(names)
    shown = ", ".join(clipped(repr(n)) for n in names[:most])
    return (shown + (f" and {len(names) - most} more" if len(names) > most else "")) or "none"


def whole_number(name: str, value: object) -> int:
    """``value`` as an ``int``, or a :class:`ParameterError` naming ``name``.

    Python and numpy integers and whole floats (``4.0``, as a JSON or HDF5 reader may give
    back) are taken; a bool, a string or a fraction is refused rather than truncated or
    compared (``cells=2.5`` ran, ``cells="4"`` failed with a TypeError naming nothing).
    """
    if isinstance(value, numbers.Integral) and not isinstance(value, bool):
        return int(value)
    if (isinstance(value, numbers.Real) and not isinstance(value, bool)
            and math.isfinite(value) and float(value).is_integer()):
        return int(value)
    raise ParameterError(f"{name}: expected a whole number, got {value!r}")


def real_number(name: str, value: object) -> float:
    """``value`` as a ``float`` (NaN and inf pass: the caller checks the range), or a
    :class:`ParameterError` naming ``name`` for a bool, a string or anything not a number."""
    if isinstance(value, numbers.Real) and not isinstance(value, bool):
        return float(value)
    raise ParameterError(f"{name}: expected a number, got {value!r}")


def instance_of(name: str, value: object, kind: type | tuple[type, ...], *,
                hint: str = "") -> None:
    """Refuse ``value`` unless it is a ``kind``: a :class:`ParameterError` naming ``name``, the
    type expected and the type given (and ``hint``: how to make one), instead of an
    AttributeError from deep inside the first use of it."""
    if isinstance(value, kind):
        return
    kinds = kind if isinstance(kind, tuple) else (kind,)
    # numpy's bool_ is named "bool" too: each name once
    expected = " or ".join(dict.fromkeys("None" if k is type(None) else k.__name__
                                         for k in kinds))
    article = "an" if expected[0].lower() in "aeiou" else "a"
    # one line, whatever the object's repr; the type's name and the hint need the rest
    shown = clipped(" ".join(repr(value).split()), 60)
    raise ParameterError(f"{name}: expected {article} {expected}, got {type(value).__name__} "
                         f"{shown}" + (f" ({hint})" if hint else ""))


# What a message quotes or names as the user's: a quoted name ('force=', "x"; an apostrophe
# inside a word is no quote, and a keyword's quoted value is the keyword's table's:
# fill_reference='paper'), a path (/data/key=1/a.csv, runs/x=1/, C:\\runs\\x.csv), a file
# name with its extension (structure_mass_kg.csv; a path or file after "=" is a keyword's
# value: store_path=/data/s.h5), and the word after "specimen", "key",
# "channel", "store", "file" or "folder", which the library writes unquoted (store keys,
# specimen names).
_USER_NAME = re.compile(
    r"(?<![\w=])'[^'\n]*'(?!\w)"
    r'|(?<![\w=])"[^"\n]*"(?!\w)'
    r"|(?P<path>[^\s'\"(),;=]*[/\\][^\s'\"(),;]*)"
    r"|(?<![\w.-])[\w.+-]*\w\.[A-Za-z][A-Za-z0-9]{0,4}(?![\w.])"
    r"|(?:(?<=specimen )|(?<=key )|(?<=channel )|(?<=store )|(?<=file )|(?<=folder ))"
    r"[^\s,;()']+")
# a private-use code point: never written by the library, nor in a name typed by a user
_HELD = "\ue000{}\ue001"
_HELD_BACK = re.compile("\ue000(\\d+)\ue001")


def _is_path(token: str) -> bool:
    # "fit/priors" (two keywords) and "m/s" are no paths: one slash between plain words
    return ("\\" in token or token.startswith(("/", "~", ".")) or token.endswith("/")
            or token.count("/") > 1 or any(c in token for c in ".=\ue000"))


def outside_user_names(message: str, rewrite: Callable[[str], str], *,
                       names: Iterable[str] = ()) -> str:
    """``rewrite(message)`` applied to all but the user's names in it (quoted, a path, a file
    name, a store key or specimen, and each of ``names`` standing alone): a front-end says a
    parameter keyword in its own words without renaming a file ``structure_mass_kg.csv``.

    A held name reaches ``rewrite`` as a placeholder of non-word characters, so a keyword
    before it keeps its value (``force='Fz'`` -> ``--force 'Fz'``)."""
    held: list[str] = []

    def hold(m: re.Match) -> str:
        if m.groupdict().get("path") and not _is_path(m.group(0)):
            return m.group(0)
        held.append(m.group(0))
        return _HELD.format(len(held) - 1)

    def restore(text: str) -> str:  # a held path may hold a name given in ``names``
        return _HELD_BACK.sub(lambda m: restore(held[int(m.group(1))]), text)

    given = sorted({n for n in names if len(n) >= 2}, key=len, reverse=True)
    if given:
        # standing alone: within quotes it is a quoted name or a keyword's value
        # (fill_reference='paper' for a typed "paper"), which the table says
        message = re.sub(r"(?<![\w'=])(?:" + "|".join(map(re.escape, given)) + r")(?![\w'])",
                         hold, message)
    return restore(rewrite(_USER_NAME.sub(hold, message)))


# A keyword names the parameter, not a file's own column, attribute, field or variable of the
# same name ("column baseline_loss_factor '-1' of loadcases.csv", "a baseline_loss_factor
# column", "field sample_rate_hz", "('fs' or 'sample_rate_hz')"), nor part of a longer name
# ("my_frequency_hz_col", "--structure-mass"), nor a specimen file's key ("[coupon]
# baseline_loss_factor 0.01"): the CLI's flags and the app's labels must agree on which.
#: Regex look-behinds before a keyword that is the parameter (:mod:`pidcore.cli._vocabulary`,
#: :mod:`pidcore.app.vocabulary`).
KEYWORD_NOT_BEFORE = r"(?<![\w'=-])(?<!\] )(?<!column )(?<!attribute )(?<!field )(?<!variable )"
#: Regex look-aheads after a keyword ending in a word character that is the parameter.
KEYWORD_NOT_AFTER_WORD = r"(?![\w'])(?! column)"


__all__ = ["ChannelError", "DependencyError", "InputFileError", "KEYWORD_NOT_AFTER_WORD",
           "KEYWORD_NOT_BEFORE", "ParameterError", "PidcoreError",
           "SettingsTableError", "SignalError", "SimulationError", "StoreError", "as_given",
           "clipped", "instance_of", "listed", "outside_user_names", "real_number", "whole_number"]
