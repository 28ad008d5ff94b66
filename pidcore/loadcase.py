"""The load case: the (frequency, acceleration, fill, material, direction) a result belongs to.

One type for the DEM (what to simulate), measurements (what was stated about them), the
store, the CLI, reports and the app, with one text key (:attr:`LoadCase.key`,
``f50Hz_a5g_fill50pct_acrylic_z``). Stores written by pidcore 0.1 named DEM runs with the
older key ``acrylic_z_f50_a5_fill50``; :func:`parse_key` reads both.

Public API
----------
LoadCase, LoadCaseError
    The load case (frequency [Hz], acceleration [g], fill [%], material, direction).
parse_key, KEY_PATTERN, KEY_PATTERN_0_1, key_0_1
    Keys of load cases and DEM runs, today's and pidcore 0.1's.
check_fill, check_fill_range, parse_values, parse_count, parse_optional_rate
    Fills in (0, 100] %; numbers typed as ``"50, 100 500"``, a whole number, a rate or none.
normalize_material, normalize_direction
    Canonical material and direction names.
"""

from __future__ import annotations

import math
import re
from collections.abc import Hashable, Iterable
from dataclasses import dataclass

from . import defaults
from .constants import DRIVE_DIRECTIONS, PARTICLE_MATERIALS, STANDARD_GRAVITY
from .errors import ParameterError, as_given, whole_number

_MATERIAL_ALIASES = {"pmma": "acrylic", "aluminum": "aluminium"}

_NUMBER = r"\d+(?:\.\d+)?(?:e[+-]?\d+)?"
#: :attr:`LoadCase.key`, e.g. ``f500Hz_a5g_fill50pct_acrylic_z`` (a run key may follow).
KEY_PATTERN = re.compile(
    rf"^f(?P<f>{_NUMBER})Hz_a(?P<a>{_NUMBER})g_fill(?P<p>{_NUMBER})pct_"
    r"(?P<material>[a-z][a-z0-9_]*?)_(?P<direction>[xyz])(?=$|_)")
#: The DEM run key of pidcore 0.1, e.g. ``acrylic_z_f50_a5_fill50`` (read, never written).
KEY_PATTERN_0_1 = re.compile(
    rf"^(?P<material>[a-z][a-z0-9_]*?)_(?P<direction>[xyz])_f(?P<f>{_NUMBER})_a(?P<a>{_NUMBER})"
    rf"_fill(?P<p>{_NUMBER})(?=$|_)")


class LoadCaseError(ParameterError):
    """A load case is not stated, stated twice differently, or out of range."""


#: Form of a particle material name in a load case: the table's materials and a specimen's
#: own (inline) materials such as ``steel`` or ``tungsten_carbide``.
_MATERIAL_NAME = re.compile(r"^[a-z][a-z0-9_]*$")


def normalize_material(value: str, what: str,
                       known: tuple[str, ...] | None = PARTICLE_MATERIALS) -> str:
    """Canonical material name (``aluminum`` -> ``aluminium``, ``pmma`` -> ``acrylic``).

    ``known``: the names accepted (the materials table by default, plus a specimen's own
    material where one is given); ``None`` accepts any lower-case identifier.
    """
    text = str(value).strip().lower()
    text = _MATERIAL_ALIASES.get(text, text)
    if known is not None and text not in known:
        raise LoadCaseError(f"{what}: unknown particle material {value!r}; expected one of "
                            f"{', '.join(known)}")
    if not _MATERIAL_NAME.match(text):
        raise LoadCaseError(f"{what}: particle material {value!r} is not a name (expected "
                            "lower-case letters, digits and '_', e.g. 'acrylic')")
    return text


def normalize_direction(value: str, what: str) -> str:
    """Canonical drive direction (``'Z'`` -> ``'z'``)."""
    text = str(value).strip().lower()
    if text not in DRIVE_DIRECTIONS:
        raise LoadCaseError(f"{what}: unknown drive direction {value!r}; expected one of "
                            f"{', '.join(DRIVE_DIRECTIONS)}")
    return text


def check_fill(value: float, what: str) -> float:
    """``value`` as a fill in (0, 100] % (packing ratio), or :class:`LoadCaseError`."""
    try:
        if isinstance(value, bool):  # True was a fill of 1 %
            raise TypeError
        fill = float(value)
    except (TypeError, ValueError):
        raise LoadCaseError(f"{what}: fill {value!r} is not a number (packing ratio in %)") \
            from None
    if not (math.isfinite(fill) and 0.0 < fill <= 100.0):
        raise LoadCaseError(f"{what}: fill must be in (0, 100] % (packing ratio), got {value!r}")
    return fill


@dataclass(frozen=True)
class LoadCase:
    """One harmonic load case of the paper's grid (or between its points).

    Attributes
    ----------
    frequency_hz : float
        Drive frequency, Hz (> 0).
    acceleration_g : float
        Acceleration amplitude of the drive, g (standard gravity, > 0).
    fill_percent : float
        Packing ratio: particles per cell over the full-cell count, % (0 < fill <= 100).
    material : str
        Particle material (:data:`pidcore.constants.ParticleMaterial`; ``pmma`` and
        ``aluminum`` are read as ``acrylic`` and ``aluminium``).
    direction : str
        Drive direction in the cell frame (:data:`pidcore.constants.DriveDirection`).

    Examples
    --------
    >>> LoadCase(500.0, 5.0, 50.0).key
    'f500Hz_a5g_fill50pct_acrylic_z'
    """

    frequency_hz: float
    acceleration_g: float
    fill_percent: float
    material: str = defaults.COMPARE_DEFAULT_MATERIAL
    direction: str = defaults.COMPARE_DEFAULT_DIRECTION

    def __post_init__(self) -> None:
        for name in ("frequency_hz", "acceleration_g"):
            value = getattr(self, name)
            try:  # text as a table holds it is read; True is not 1 Hz
                number = math.nan if isinstance(value, bool) else float(value)
            except (TypeError, ValueError):
                number = math.nan
            if not (math.isfinite(number) and number > 0):
                raise LoadCaseError(f"load case: {name} must be a positive finite number, "
                                    f"got {value!r}")
            object.__setattr__(self, name, number)
        object.__setattr__(self, "fill_percent", check_fill(self.fill_percent, "load case"))
        # any material name: a specimen may define its own (the edges check the vocabulary)
        object.__setattr__(self, "material",
                           normalize_material(self.material, "load case", known=None))
        object.__setattr__(self, "direction", normalize_direction(self.direction, "load case"))

    @property
    def omega_rad_s(self) -> float:
        """Drive angular frequency ``2 pi f``, rad/s."""
        return 2.0 * math.pi * self.frequency_hz

    @property
    def acceleration_m_s2(self) -> float:
        """Acceleration amplitude, m/s^2."""
        return self.acceleration_g * STANDARD_GRAVITY

    @property
    def key(self) -> str:
        """Stable text key; numbers to 6 significant digits so float noise does not split keys."""
        return (f"f{self.frequency_hz:.6g}Hz_a{self.acceleration_g:.6g}g_"
                f"fill{self.fill_percent:.6g}pct_{self.material}_{self.direction}")

    def as_record(self, origin: str) -> dict[str, object]:
        """The fields a stored analysis carries about its load case; ``origin`` says who stated
        fill, material and direction."""
        return {"fill_percent": self.fill_percent, "material": self.material,
                "direction": self.direction, "load_case_key": self.key,
                "load_case_origin": origin}

    def columns(self) -> dict[str, float | str]:
        """The load case as the first columns of a table row, units in the names
        (``frequency [Hz]``, ``acceleration [g]``, ``packing ratio [%]``, ``material``,
        ``direction``): one spelling for the alignment's rows and the report's table."""
        return {"frequency [Hz]": self.frequency_hz, "acceleration [g]": self.acceleration_g,
                "packing ratio [%]": self.fill_percent, "material": self.material,
                "direction": self.direction}

    def label(self) -> str:
        """Short human label, e.g. ``'500 Hz, 5 g, 50 %'``."""
        return f"{self.frequency_hz:.4g} Hz, {self.acceleration_g:.3g} g, {self.fill_percent:.3g} %"

    def full_label(self) -> str:
        """:meth:`label` with material and direction, e.g. ``'500 Hz, 1 g, 40 %, steel, z'``
        (rounded; :attr:`key` spells the measured values out, f500Hz_a1.00003g_...)."""
        return f"{self.label()}, {self.material}, {self.direction}"


def parse_key(text: str) -> LoadCase:
    """The load case a key (or a DEM run key starting with one) names.

    Reads :attr:`LoadCase.key` and the DEM run key of pidcore 0.1 (``acrylic_z_f50_a5_fill50``
    followed by ``_seed...``).

    Examples
    --------
    >>> parse_key("acrylic_z_f50_a5_fill50_seed12345_cells8_0123456789").key
    'f50Hz_a5g_fill50pct_acrylic_z'
    """
    for pattern in (KEY_PATTERN, KEY_PATTERN_0_1):
        m = pattern.match(str(text))
        if m:
            return LoadCase(float(m["f"]), float(m["a"]), float(m["p"]), m["material"],
                            m["direction"])
    raise LoadCaseError(f"load case key {text!r}: expected e.g. 'f50Hz_a5g_fill50pct_acrylic_z' "
                        "(or 0.1's 'acrylic_z_f50_a5_fill50')")


def key_0_1(case: LoadCase) -> str:
    """The DEM run key prefix pidcore 0.1 wrote for ``case`` (to find runs of old stores)."""
    return (f"{case.material}_{case.direction}_f{case.frequency_hz:g}"
            f"_a{case.acceleration_g:g}_fill{case.fill_percent:g}")


def check_fill_range(fill: float, where: str) -> None:
    """Refuse a fill outside (0, 100] % in one wording for ``pidcore dem`` and the app's DEM
    tab, naming where it was given (``--fill``, ``fills [%]``)."""
    if not (math.isfinite(fill) and 0.0 < fill <= 100.0):
        raise ParameterError(f"{where} {as_given(fill)}: expected a fill in (0, 100] %")


def _typed_number(token: str, *, name: str) -> float:
    """One number as typed in a field, or a one-line error naming ``name`` and the text."""
    try:
        return float(token)
    except ValueError:
        raise ParameterError(f"{name}: {token!r} is not a number") from None


def parse_values(text: str, *, name: str) -> list[float]:
    """Numbers typed as ``"50, 100 500"``: positive floats, or a one-line error naming
    ``name``."""
    values = []
    for token in text.replace(",", " ").replace(";", " ").split():
        value = _typed_number(token, name=name)
        if not (math.isfinite(value) and value > 0):
            raise ParameterError(f"{name}: {token!r}, expected a positive number")
        values.append(value)
    if not values:
        raise ParameterError(f"{name}: give at least one value")
    return values


def parse_count(text: str, *, name: str, minimum: int = 0, maximum: int | None = None) -> int:
    """A whole number typed in a field (``"8"``, ``"1e3"``), or a one-line error naming
    ``name``: a browser's number box read ``"2,5"`` as 25 and ``"1e3"`` as 1 without a word,
    so such fields are text read here."""
    token = text.strip()
    try:
        # the rule of a count given in code (a fraction, inf or NaN is none), on the typed text
        count = whole_number(name, float(token))
    except ValueError:  # ParameterError is one: the typed text, not its float, is shown
        raise ParameterError(f"{name}: {token!r} is not a whole number") from None
    if count < minimum or (maximum is not None and count > maximum):
        expected = (f"{minimum} to {maximum}" if maximum is not None
                    else f"at least {minimum}")
        raise ParameterError(f"{name}: {token!r}, expected {expected}")
    return count


def parse_optional_rate(text: str, *, name: str) -> float | None:
    """A positive rate typed in a field, None where it is blank or 0 (none given), or a
    one-line error naming ``name`` (``"25,6"`` is refused, not read as 256)."""
    token = text.strip()
    if not token:
        return None
    value = _typed_number(token, name=name)
    if value == 0:
        return None
    if not (math.isfinite(value) and value > 0):
        raise ParameterError(f"{name}: {token!r}, expected a positive number (0 or blank: none)")
    return value


__all__ = ["KEY_PATTERN", "KEY_PATTERN_0_1", "LoadCase", "LoadCaseError", "check_fill",
           "check_fill_range",
           "key_0_1", "normalize_material", "normalize_direction", "parse_count", "parse_key",
           "parse_optional_rate", "parse_values"]


def refuse_identical_contents_stating_apart(files: Iterable[tuple[str, str, Hashable, str]],
                                            *, remedy: str = "") -> None:
    """Refuse byte-identical files that state different load cases (or specimens or analysis
    settings), as :class:`LoadCaseError`.

    ``files``: per file (name, content key, what it states, that statement in words); the
    content key is the file's SHA-256 or the store's key of it ("" when unknown: not
    compared). Identical bytes are one measurement (the store keeps one record of them), so
    two statements about it cannot both hold; ``remedy`` ends the message.
    """
    first: dict[str, tuple[str, Hashable, str]] = {}
    clashes = []
    for name, key, stated, words in files:
        if not key:
            continue
        other = first.setdefault(key, (name, stated, words))
        if other[1] != stated:
            # "different load cases" alone misled where only the settings or specimen differ
            clashes.append(f"{name} and {other[0]} have identical contents but state "
                           f"different load cases, specimens or settings ({words} vs "
                           f"{other[2]})")
    if clashes:  # every one named: fixing one should not reveal the next
        raise LoadCaseError("; ".join(clashes) + (f"; {remedy}" if remedy else ""))
