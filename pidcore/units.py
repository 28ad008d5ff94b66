"""Unit normalisation to SI at the edges.

Two steps: a small table of the spellings exporters write ("m/s2", "m/s²", "mm/s", "g", "kN",
"lbf", ...) that pins the meanings a general library gets wrong for vibration data (``g`` is
standard gravity here, not the gram), then :mod:`pint` for everything else (``mm/sec``,
``ft/s``, ``dN``, ``km/h``), accepted only when its dimension is one of the quantities pidcore
knows. Every conversion is a pure scale factor. A unit neither step understands is *unknown*:
never taken as SI (the analysis asks for ``--force-unit`` etc.).
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass

from .constants import SI_UNITS, STANDARD_GRAVITY
from .errors import ParameterError, a_or_an


@dataclass(frozen=True)
class UnitInfo:
    """What a unit string means: its quantity and the factor that takes it to SI."""

    quantity: str
    factor: float  # value_SI = factor * value_in_unit

    @property
    def si_unit(self) -> str:
        return SI_UNITS[self.quantity]


_LBF = 4.4482216152605
_INCH = 0.0254

_TABLE: dict[str, UnitInfo] = {
    # force
    "n": UnitInfo("force", 1.0),
    "newton": UnitInfo("force", 1.0),
    "kn": UnitInfo("force", 1e3),
    "mn": UnitInfo("force", 1e-3),
    "lbf": UnitInfo("force", _LBF),
    # velocity
    "m/s": UnitInfo("velocity", 1.0),
    "mm/s": UnitInfo("velocity", 1e-3),
    "cm/s": UnitInfo("velocity", 1e-2),
    "um/s": UnitInfo("velocity", 1e-6),
    "in/s": UnitInfo("velocity", _INCH),
    "ips": UnitInfo("velocity", _INCH),
    # acceleration
    "m/s^2": UnitInfo("acceleration", 1.0),
    "mm/s^2": UnitInfo("acceleration", 1e-3),
    "g": UnitInfo("acceleration", STANDARD_GRAVITY),
    "g0": UnitInfo("acceleration", STANDARD_GRAVITY),
    "gn": UnitInfo("acceleration", STANDARD_GRAVITY),
    "in/s^2": UnitInfo("acceleration", _INCH),
    # displacement
    "m": UnitInfo("displacement", 1.0),
    "mm": UnitInfo("displacement", 1e-3),
    "um": UnitInfo("displacement", 1e-6),
    "in": UnitInfo("displacement", _INCH),
    # others seen in exports
    "pa": UnitInfo("pressure", 1.0),
    "kpa": UnitInfo("pressure", 1e3),
    "v": UnitInfo("voltage", 1.0),
    "mv": UnitInfo("voltage", 1e-3),
    "s": UnitInfo("time", 1.0),
    "sec": UnitInfo("time", 1.0),
    "ms": UnitInfo("time", 1e-3),
}


def canonical_unit_text(text: str) -> str:
    """Normalise the spelling of a unit: case, blanks, brackets, superscripts, ``**``.

    >>> canonical_unit_text(" (m/s²) ")
    'm/s^2'
    """
    t = text.strip().strip("()[]{} ").lower()
    t = t.replace("µ", "u").replace("μ", "u")  # micro sign and Greek mu
    t = t.replace("²", "^2").replace("\ufffd", "^2")  # Latin-1 0xB2 decoded with errors='replace'
    t = t.replace("**", "^").replace(" ", "")
    t = re.sub(r"/s2$", "/s^2", t)
    t = t.replace("sec^2", "s^2")
    if t in {"g's", "gs"}:
        t = "g"
    return t


#: Quantity of each dimension, as {base dimension: exponent}.
_PINT_DIMENSIONS = {
    (("[length]", 1), ("[mass]", 1), ("[time]", -2)): "force",
    (("[length]", 1), ("[time]", -1)): "velocity",
    (("[length]", 1), ("[time]", -2)): "acceleration",
    (("[length]", 1),): "displacement",
    (("[length]", -1), ("[mass]", 1), ("[time]", -2)): "pressure",
    (("[current]", -1), ("[length]", 2), ("[mass]", 1), ("[time]", -3)): "voltage",
    (("[time]", 1),): "time",
}
_PINT_REGISTRY = None


def _pint_lookup(text: str) -> UnitInfo | None:
    global _PINT_REGISTRY
    import pint  # lazy: only for spellings outside the table

    if _PINT_REGISTRY is None:
        _PINT_REGISTRY = pint.UnitRegistry()
    # pint is case sensitive (mN vs MN): keep the case, normalise the rest as the table does
    t = text.strip().strip("()[]{} ").replace("µ", "u").replace("μ", "u")
    t = t.replace("²", "^2").replace("\ufffd", "^2").replace("**", "^").replace(" ", "")
    t = re.sub(r"/s2$", "/s^2", t)
    if not re.fullmatch(r"[A-Za-z0-9/^.*()_-]+", t) or not re.search(r"[A-Za-z]", t):
        return None
    try:
        quantity = _PINT_REGISTRY.Quantity(1.0, t.replace("^", "**")).to_base_units()
    except Exception:  # pint raises many kinds (UndefinedUnitError, DefinitionSyntaxError, ...)
        return None
    name = _PINT_DIMENSIONS.get(tuple(sorted(dict(quantity.dimensionality).items())))
    if name is None or not quantity.magnitude > 0:
        return None
    return UnitInfo(name, float(quantity.magnitude))


def lookup_unit(text: str) -> UnitInfo | None:
    """Return the :class:`UnitInfo` of a unit string, or ``None`` if it is not known.

    >>> lookup_unit("mm/sec").factor, lookup_unit("g").quantity, lookup_unit("V^2")
    (0.001, 'acceleration', None)
    """
    canonical = canonical_unit_text(text)
    if canonical == "mn" and "M" in text:
        return UnitInfo("force", 1e6)  # MN (meganewton), not the table's mN
    info = _TABLE.get(canonical)
    return info if info is not None else _pint_lookup(text)


def to_si_factor(unit: str, quantity: str | None = None, *, what: str = "unit") -> float:
    """Factor that converts values in ``unit`` to SI.

    Parameters
    ----------
    unit : str
        Unit as written in a file or on the command line (``"mm/s"``, ``"g"``, ``"kN"``).
    quantity : str, optional
        Expected quantity; a unit of another quantity raises :class:`ParameterError`.
    what : str
        Name used in the error message (file and channel).

    Examples
    --------
    >>> to_si_factor("mm/s")
    0.001
    >>> round(to_si_factor("g", "acceleration"), 5)
    9.80665
    """
    info = lookup_unit(unit)
    if info is None:
        raise ParameterError(f"{what}: unknown unit {unit!r}; expected one of "
                             f"{', '.join(sorted(_TABLE))}")
    if quantity is not None and info.quantity != quantity:
        raise ParameterError(f"{what}: unit {unit!r} is {a_or_an(info.quantity)} unit, "
                             f"expected {a_or_an(quantity)} unit ({SI_UNITS[quantity]})")
    return info.factor


def g_to_si(value_g: float) -> float:
    """Acceleration in g to m/s^2 (standard gravity)."""
    return value_g * STANDARD_GRAVITY


def si_to_g(value_m_s2: float) -> float:
    """Acceleration in m/s^2 to g (standard gravity)."""
    return value_m_s2 / STANDARD_GRAVITY


def display_number(value: float | None, *, decimals: int = 4, missing: str = "—") -> str:
    """A number as shown on a page: ``decimals`` fixed decimals (``0.1856``, ``0.0010``) down
    to 10**(1 - decimals), where they would show a single digit; three significant digits
    below (``0.000157``, ``4.4e-05``), so that no nonzero value reads 0.0000; ``missing`` for
    NaN, inf or None."""
    if value is None or not math.isfinite(value):
        return missing
    if value == 0 or abs(round(value, decimals)) >= 10.0 ** (1 - decimals):  # as printed
        return f"{value:.{decimals}f}"
    return f"{value:.3g}"


def display_sigmas(multiple: float) -> str:
    """A multiple of sigma as a verdict states it: three significant digits, without an
    exponent or a trailing ``.0`` (``"4874.0 σ"`` read as a measured, exact count).

    >>> display_sigmas(4874.04), display_sigmas(0.8312), display_sigmas(12.0), display_sigmas(2.0)
    ('4870', '0.831', '12', '2')
    """
    rounded = float(f"{multiple:.3g}")
    return f"{rounded:.0f}" if abs(rounded) >= 100 else f"{rounded:g}"


def display_with_uncertainty(value: float, stderr: float, *, digits: int = 4,
                             missing: str = "—") -> str:
    """``value`` rounded at the first significant digit of its standard error ``stderr`` (the
    last digit shown is the uncertain one), with at least two significant digits; ``digits``
    significant digits where the error is unknown or zero; ``missing`` for NaN or inf.

    >>> display_with_uncertainty(0.46662, 0.0081), display_with_uncertainty(0.2563, 0.0009)
    ('0.467', '0.2563')
    >>> display_with_uncertainty(1234.5, 60.0), display_with_uncertainty(0.01518, float("nan"))
    ('1230', '0.01518')
    """
    if value is None or not math.isfinite(value):
        return missing
    if stderr is None or not (math.isfinite(stderr) and stderr > 0):
        return f"{value:.{digits}g}"
    place = math.floor(math.log10(stderr))
    if value != 0:
        place = min(place, math.floor(math.log10(abs(value))) - 1)
    if place < 0:
        return f"{value:.{-place}f}"
    return f"{round(value, -place):.0f}"
