"""Unit normalisation to SI at the edges.

Two steps: a small table of the spellings exporters write ("m/s2", "m/s²", "mm/s", "g", "kN",
"lbf", ...) that pins the meanings a general library gets wrong for vibration data (``g`` is
standard gravity here, not the gram), then :mod:`pint` for everything else (``mm/sec``,
``ft/s``, ``dN``, ``km/h``), accepted only when its dimension is one of the quantities pidcore
knows. Every conversion is a pure scale factor. A unit neither step understands is *unknown*:
never taken as SI (the analysis asks for ``--force-unit`` etc.).
"""

from __future__ import annotations

import functools
import math
import re
from dataclasses import dataclass
from decimal import ROUND_HALF_EVEN, Decimal

from .constants import SI_UNITS, STANDARD_GRAVITY
from .errors import ParameterError, a_or_an, instance_of


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

#: The spellings exporters write, with the case SI gives them: a prefix's case is its
#: meaning (m = 1e-3, M = 1e6), so the keys are matched exactly (see :func:`read_unit` for a
#: spelling in another case). ``g`` and its plural spellings are standard gravity, the unit
#: of shaker and accelerometer channels, never the gram.
_TABLE: dict[str, UnitInfo] = {
    # force
    "N": UnitInfo("force", 1.0),
    "newton": UnitInfo("force", 1.0),
    "kN": UnitInfo("force", 1e3),
    "mN": UnitInfo("force", 1e-3),
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
    "g's": UnitInfo("acceleration", STANDARD_GRAVITY),
    "gs": UnitInfo("acceleration", STANDARD_GRAVITY),
    "in/s^2": UnitInfo("acceleration", _INCH),
    # displacement
    "m": UnitInfo("displacement", 1.0),
    "mm": UnitInfo("displacement", 1e-3),
    "um": UnitInfo("displacement", 1e-6),
    "in": UnitInfo("displacement", _INCH),
    # others seen in exports
    "Pa": UnitInfo("pressure", 1.0),
    "kPa": UnitInfo("pressure", 1e3),
    "V": UnitInfo("voltage", 1.0),
    "mV": UnitInfo("voltage", 1e-3),
    "s": UnitInfo("time", 1.0),
    "sec": UnitInfo("time", 1.0),
    # time axes written as words ('Seconds', 'SECS'): no prefix in them, so their case is
    # corrected (noted); a UFF abscissa label of no unit is refused
    "secs": UnitInfo("time", 1.0),
    "second": UnitInfo("time", 1.0),
    "seconds": UnitInfo("time", 1.0),
    "ms": UnitInfo("time", 1e-3),
    "us": UnitInfo("time", 1e-6),
}
#: Each table spelling by its lower-case form, for a label written in another case.
_TABLE_BY_FOLDED = {spelling.lower(): spelling for spelling in _TABLE}

#: SI per unit that an export of each quantity plausibly uses, from the smallest to the
#: largest (both included). A prefix read in the wrong case is a factor of 1e6 to 1e9 (mm/s
#: as Mm/s, mN as MN), far outside; the ranges hold every unit an impedance head (uN to kip),
#: a laser vibrometer (nm/s to m/s), an accelerometer (ug to g) or a time column (ns to
#: min) is exported in.
PLAUSIBLE_FACTORS: dict[str, tuple[float, float]] = {
    "force": (1e-6, 1e4),
    "velocity": (1e-9, 1.0),
    "acceleration": (1e-6, 10.0),
    "displacement": (1e-12, 1.0),
    "time": (1e-9, 60.0),
}
#: Most letters of a label whose other casings :func:`read_unit` reads (2**letters readings).
_MAX_CASED_LETTERS = 8


def canonical_unit_text(text: str) -> str:
    """Normalise the spelling of a unit for comparisons that ignore its case (``none``, ``-``):
    case, blanks, brackets, superscripts, ``**``. Units are read by :func:`read_unit`, which
    keeps the case.

    >>> canonical_unit_text(" (m/s²) ")
    'm/s^2'
    """
    return _cased_text(text).lower()


#: A product or negative power of units written as the SI brochure writes it (m·s⁻¹).
_SI_PRODUCT = re.compile("[·⋅⁻]")
_SI_PRODUCT_CHARACTERS = str.maketrans({"·": "*", "⋅": "*", "⁻": "^-", "¹": "1", "²": "2",
                                        "³": "3", "⁴": "4"})


def _cased_text(text: str) -> str:
    """A unit label without brackets, blanks and typographic variants, its case kept."""
    t = text.strip().strip("()[]{} ")
    t = t.replace("µ", "u").replace("μ", "u")  # micro sign and Greek mu
    if _SI_PRODUCT.search(t):
        # the SI brochure's notation, m·s⁻¹, m s⁻²: a product of powers (refused as no unit,
        # and 'm s^-1' with its blank taken out was 'ms^-1', per millisecond)
        t = re.sub(r"(?<=[^\s/*·⋅])\s+(?=[A-Za-z])", "*", t.strip())
        t = t.translate(_SI_PRODUCT_CHARACTERS)
    t = t.replace("²", "^2").replace("\ufffd", "^2")  # Latin-1 0xB2 decoded with errors='replace'
    t = t.replace("**", "^").replace(" ", "")
    t = re.sub(r"/([sS])2$", r"/\1^2", t)
    t = re.sub(r"(?i)sec\^2$", lambda m: m.group(0)[0] + "^2", t)
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
#: pint units of a quantity that no vibration export is in: pint reads ``kn`` as the knot, a
#: ship's speed, where an export's ``kn`` is kN in lower case.
_PINT_NOT_EXPORTED = frozenset({"knot"})
_PINT_REGISTRY = None


def _pint_lookup(text: str) -> UnitInfo | None:
    """pint's reading of a label (case sensitive: mN is not MN), where it is a quantity
    pidcore knows."""
    global _PINT_REGISTRY
    import pint  # lazy: only for spellings outside the table

    if _PINT_REGISTRY is None:
        _PINT_REGISTRY = pint.UnitRegistry()
    t = _cased_text(text)
    if not re.fullmatch(r"[A-Za-z0-9/^.*()_-]+", t) or not re.search(r"[A-Za-z]", t):
        return None
    try:
        quantity = _PINT_REGISTRY.Quantity(1.0, t.replace("^", "**"))
        names = {str(name) for name, _ in quantity.unit_items()}
        if names & _PINT_NOT_EXPORTED:
            return None
        quantity = quantity.to_base_units()
    except Exception:  # pint raises many kinds (UndefinedUnitError, DefinitionSyntaxError, ...)
        return None
    name = _PINT_DIMENSIONS.get(tuple(sorted(dict(quantity.dimensionality).items())))
    if name is None or not quantity.magnitude > 0:
        return None
    return UnitInfo(name, float(quantity.magnitude))


def _exact_reading(cased: str) -> UnitInfo | None:
    return _TABLE.get(cased) or _pint_lookup(cased)


@dataclass(frozen=True)
class UnitReading:
    """How pidcore reads a unit label: ``info`` where it is taken, else ``problem`` (a phrase,
    empty for a label that names no unit pidcore knows).

    ``spelling`` is the unit read (the label itself, or the table's spelling where the label's
    case was corrected: ``corrected``); ``quantity`` is its quantity also where it is refused
    (a label such as ``Mm/s`` is a unit, of velocity, not free text)."""

    label: str
    info: UnitInfo | None
    spelling: str = ""
    quantity: str | None = None
    corrected: bool = False
    problem: str = ""

    @property
    def correction(self) -> str:
        """The phrase that says a corrected case, ``"'KN' read as kN (1000 N): ..."``, or
        ``""``."""
        if not self.corrected or self.info is None:
            return ""
        return (f"unit {self.label!r} read as {self.spelling} ({_per_unit(self.info)}): unit "
                f"symbols are case-sensitive, and {self.spelling} is the one "
                f"{self.info.quantity} unit it can be")


def _casings(folded: str) -> list[str]:
    letters = [i for i, c in enumerate(folded) if c.isalpha()]
    out = []
    for mask in range(1 << len(letters)):
        chars = list(folded)
        for bit, i in enumerate(letters):
            if mask >> bit & 1:
                chars[i] = chars[i].upper()
        out.append("".join(chars))
    return out


def _per_unit(info: UnitInfo) -> str:
    return f"{info.factor:.6g} {info.si_unit}"


def _implausible(label: str, info: UnitInfo, spelling: str) -> str:
    low, high = PLAUSIBLE_FACTORS.get(info.quantity, (0.0, math.inf))
    if low <= info.factor <= high:
        return ""
    folded = _TABLE_BY_FOLDED.get(spelling.lower())
    meant = (f", such as {folded!r}" if folded is not None and folded != spelling
             and _TABLE[folded].quantity == info.quantity else "")
    return (f"{label!r} is {_per_unit(info)}, not a plausible {info.quantity} unit (expected "
            f"{low:g} to {high:g} {info.si_unit} per unit{meant})")


@functools.lru_cache(maxsize=1024)
def read_unit(text: str) -> UnitReading:
    """Read a unit label as SI units write it: case-sensitive (``mm/s`` is 1e-3 m/s, ``Mm/s``
    1e6 m/s), then checked against :data:`PLAUSIBLE_FACTORS`.

    A label of no unit in its own case (``KN``, ``G``, ``M/S``, all capitals) is read as the
    table's spelling of another case where that is its only reading of the quantity (another
    case of a spelling pint alone reads is not guessed: ``Nm`` is no nanometre); where
    another casing reads as the same quantity by another factor (``MM/S``: mm/s or Mm/s;
    ``MN``: mN or MN) it is refused as ambiguous, as is a reading outside the plausible range
    (``Mm/s``, ``MN``, ``km/s``): ``info`` None and ``problem`` says why.

    >>> read_unit("KN").info.factor, read_unit("KN").corrected, read_unit("kN").corrected
    (1000.0, True, False)
    >>> read_unit("Mm/s").info is None, read_unit("MM/S").info is None
    (True, True)
    """
    label = text.strip()
    cased = _cased_text(label)
    if not cased:
        return UnitReading(label, None)
    folded = cased.lower()
    exact = _TABLE.get(cased)
    if exact is None and (exact := _pint_lookup(cased)) is not None:
        # pint reads many a mis-cased label as something else: 'pa' a picoyear, 'Gs' a
        # gigasecond. Only a reading of the quantity the table's spelling names (Mm/s beside
        # mm/s, MN beside mN) is what the label says; another is its case slipped.
        meant = _TABLE_BY_FOLDED.get(folded)
        if meant is not None and _TABLE[meant].quantity != exact.quantity:
            exact = None
    if exact is not None:
        problem = _implausible(label, exact, cased)
        return UnitReading(label, None if problem else exact, cased, exact.quantity,
                           problem=problem)
    if sum(c.isalpha() for c in folded) > _MAX_CASED_LETTERS or (
            folded not in _TABLE_BY_FOLDED and _pint_lookup(folded) is None):
        # no unit in lower case either: its other cases are not parsed one by one (a header
        # cell such as 'Velocity', tried as a possible unit row, was parsed 256 times)
        return UnitReading(label, None)
    readings = {c: r for c in _casings(folded) if (r := _exact_reading(c)) is not None}
    if not readings:
        return UnitReading(label, None)
    spelling = _TABLE_BY_FOLDED.get(folded)
    if spelling is None:
        # only the table's spellings are corrected: another case of a pint unit is often
        # another unit ('Nm', a torque, is no nanometre); several readings are refused below
        if len({(r.quantity, r.factor) for r in readings.values()}) == 1:
            return UnitReading(label, None)
        spelling = min(readings)
    meant = readings[spelling]
    others = {c: r for c, r in readings.items() if r.quantity == meant.quantity
              and not math.isclose(r.factor, meant.factor, rel_tol=1e-9)}
    if others:
        said = " or ".join(f"{c} ({_per_unit(r)})" for c, r in
                           sorted({spelling: meant, **others}.items(), key=lambda cr: cr[1].factor))
        return UnitReading(label, None, spelling, meant.quantity, problem=(
            f"{label!r} is ambiguous: unit prefixes are case-sensitive, and it reads as {said}"))
    problem = _implausible(label, meant, spelling)
    return UnitReading(label, None if problem else meant, spelling, meant.quantity,
                       corrected=not problem, problem=problem)


def lookup_unit(text: str) -> UnitInfo | None:
    """Return the :class:`UnitInfo` of a unit string, or ``None`` if it is not known or is
    refused (:func:`read_unit` says why).

    >>> lookup_unit("mm/sec").factor, lookup_unit("g").quantity, lookup_unit("V^2")
    (0.001, 'acceleration', None)
    """
    return read_unit(text).info


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
    reading = read_unit(unit)
    info = reading.info
    if info is None:
        if reading.problem:
            raise ParameterError(f"{what}: {reading.problem}")
        raise ParameterError(f"{what}: unknown unit {unit!r}; expected one of "
                             f"{', '.join(sorted(_TABLE))}")
    if quantity is not None and info.quantity != quantity:
        raise ParameterError(f"{what}: unit {unit!r} is {a_or_an(info.quantity)} unit, "
                             f"expected {a_or_an(quantity)} unit ({SI_UNITS[quantity]})")
    return info.factor


def given_time_unit(time_unit: str | None) -> UnitReading | None:
    """The reading of ``time_unit``, the unit a user states for a file's time base (a UFF
    abscissa, a time column), or None where none is given; a unit that is not one of time
    is refused naming the keyword."""
    if time_unit is None:
        return None
    instance_of("time_unit", time_unit, str, hint="e.g. 'ms'")
    why = why_not_a_time_unit(time_unit)
    if why is not None:
        raise ParameterError(f"time_unit={time_unit!r}: not a unit of time{why}; expected "
                             "s, ms or us")
    return read_unit(time_unit)


def why_not_a_time_unit(text: str) -> str | None:
    """None where ``text`` reads as a unit of time; else what to add to "not a unit of
    time": ``": <what is wrong with it>"``, or ``""`` where there is no more to say. The one
    reason of every refusal of a given time unit (the keyword, a settings cell, the app's
    field), each naming its own source."""
    reading = read_unit(text)
    if reading.info is not None and reading.info.quantity == "time":
        return None
    if reading.quantity not in (None, "time"):
        # a unit of another quantity: 'furlong' was refused as "not a plausible displacement
        # unit (expected 1e-12 to 1 m per unit)", rules the user never gave a unit for
        return ""
    return f": {reading.problem}" if reading.problem else ""


def overrides_stated_time(stated: str, given: UnitReading) -> bool:
    """Whether the user's ``given`` time unit (:func:`given_time_unit`) reads a time base
    otherwise than the label its file states (``stated``: none, no unit of time, or one of
    another factor), which the readers then say."""
    reading = read_unit(stated)
    return (reading.info is None or reading.quantity != "time"
            or not math.isclose(reading.info.factor, given.info.factor, rel_tol=1e-12))


#: Spellings of milli-g (1e-3 standard gravity) that accelerometer channels are exported in.
#: SI reads ``mg`` as the milligram, a mass, so :func:`read_unit` does not take them: only a
#: channel that is an acceleration by its name or role is read so (:func:`milli_g`), and said.
MILLI_G_SPELLINGS = frozenset({"mg", "mgn", "milli-g", "milli-gn"})


def milli_g(label: str) -> UnitInfo | None:
    """1e-3 g where ``label`` is a spelling of milli-g (:data:`MILLI_G_SPELLINGS`, its case
    kept: ``MG`` is no milli-g), else None. For a channel known to be an acceleration only.

    >>> milli_g("mg").factor, milli_g("mm")
    (0.00980665, None)
    """
    return (UnitInfo("acceleration", 1e-3 * STANDARD_GRAVITY)
            if _cased_text(label) in MILLI_G_SPELLINGS else None)


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


def value_and_error_texts(value: float, stderr: float, *, max_digits: int = 6,
                          missing: str = "—") -> tuple[str, str]:
    """``value`` and its standard error ``stderr`` as every page and the terminal write them
    (GUM 7.2.6), the one rule of reports, ``pidcore analyze``, ``dem run`` and the app:

    * the error with two significant digits, the value rounded at the same decimal place
      (``0.01234 ± 0.00056``; a value below its error reads ``0.00 ± 0.25``, not finer than
      what its error allows);
    * both in one notation with one exponent: fixed decimals where the larger of the two is
      from 1e-4 up to 1e6, else the exponent of the larger on both (``5.00e-05 ± 0.30e-05``,
      never ``5.00e-05`` beside ``0.0000030``);
    * the value with ``max_digits`` significant digits at most: an error below its last
      place is said to be below one unit of that place (``0.250000 ± <0.000001``, a
      noise-free record), one at or above it is shown at that place with one digit;
    * a negative value (a loss factor within its noise of zero is kept) keeps its sign,
      except where it rounds to zero (``0.0e-05``, not ``-0.0e-05``);
    * the error's text ``"0"`` where it is zero (the value at ``max_digits`` significant
      digits), ``"inf"`` where infinite, ``""`` where unknown (NaN: the value alone, with
      four significant digits, as an SDC shown alone, ``sdc_text``); ``(missing, "")`` for
      a value that is not a number.

    Before, the value was cut at six significant digits while the error kept its own
    (``0.250000 ± 1.1e-14``), an error below 1e-4 had an exponent beside a value of fixed
    decimals (``0.000150 ± 2.0e-05``), each number its own exponent (``5.00e-05 ±
    3.0e-06``), and a value below its error kept two digits finer than it (``1.0e-07 ±
    4.4e-05``, ``0.012 ± 0.50``).

    >>> value_and_error_texts(0.01234, 0.00056), value_and_error_texts(4.09, 0.2)
    (('0.01234', '0.00056'), ('4.09', '0.20'))
    >>> value_and_error_texts(8.168123, 0.0003), value_and_error_texts(0.25, 3e-5)
    (('8.16812', '0.00030'), ('0.250000', '0.000030'))
    >>> value_and_error_texts(0.25, 1.1e-14), value_and_error_texts(5.09e-5, 4.4e-5)
    (('0.250000', '<0.000001'), ('5.1e-05', '4.4e-05'))
    >>> value_and_error_texts(5.0e-5, 3e-6), value_and_error_texts(-3.2e-5, 4.4e-5)
    (('5.00e-05', '0.30e-05'), ('-3.2e-05', '4.4e-05'))
    """
    if value is None or not math.isfinite(value):
        return missing, ""
    if stderr is None or math.isnan(stderr):
        return f"{value:.4g}", ""
    if math.isinf(stderr):
        return f"{value:.4g}", "inf"
    exact = Decimal(repr(float(value)))
    if stderr == 0:
        if value == 0:
            return "0", "0"
        error = error_top = error_place = None
    else:
        error = Decimal(f"{abs(stderr):.1e}")  # two significant digits: 0.0996 reads 0.10
        error_top = error.adjusted()
        place = error_place = error_top - 1
    top = None
    if value != 0:
        top = exact.adjusted()
        for _ in range(2):  # once more where rounding carries into a new decade (0.0996)
            cap = top - max_digits + 1
            place = cap if error_place is None else max(error_place, cap)
            rounded = exact.quantize(Decimal(1).scaleb(place), rounding=ROUND_HALF_EVEN)
            if rounded == 0 or rounded.adjusted() <= top:
                break
            top = rounded.adjusted()
    larger = max(t for t in (top, error_top) if t is not None)
    exponent = 0 if -4 <= larger < 6 else larger

    def shown(number: Decimal) -> str:
        at = number.scaleb(-exponent).quantize(Decimal(1).scaleb(place - exponent),
                                               rounding=ROUND_HALF_EVEN)
        text = f"{abs(at) if at == 0 else at:f}"
        return text if exponent == 0 else f"{text}e{exponent:+03d}"

    if error is None:
        error_text = "0"
    elif place > error_place and error.quantize(Decimal(1).scaleb(place),
                                                  rounding=ROUND_HALF_EVEN) == 0:
        error_text = "<" + shown(Decimal(1).scaleb(place))  # below the value's last place
    else:
        error_text = shown(error)
    return shown(exact), error_text


def display_value_with_error(value: float, stderr: float, *, missing: str = "—") -> str:
    """``"value ± error"`` by :func:`value_and_error_texts` (``"0.01234 ± 0.00056"``,
    ``"4.09 ± 0.20"``); the value alone where its error is unknown."""
    value_text, error_text = value_and_error_texts(value, stderr, missing=missing)
    return f"{value_text} ± {error_text}" if error_text else value_text


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
