"""The one rule of an SDC beside its standard error (:func:`pidcore.units.value_and_error_texts`),
against cases worked by hand from GUM 7.2.6: the error to two significant digits, the value
rounded at the same decimal place, both in one notation and one exponent, and an error below
what the value's six significant digits can show said so."""

from __future__ import annotations

import math
from decimal import Decimal

import pytest

from pidcore.units import display_value_with_error, value_and_error_texts


@pytest.mark.parametrize(("value", "stderr", "value_text", "error_text"), [
    # the usual look: the error's two digits fix the value's last place
    (0.1856, 0.0042, "0.1856", "0.0042"),
    (0.01234, 0.00056, "0.01234", "0.00056"),
    (4.09, 0.2, "4.09", "0.20"),
    (8.168123, 0.0003, "8.16812", "0.00030"),
    # 0.0996 rounds to 0.10 before it fixes the place (two digits: 0.10, place 1e-2)
    (0.5, 0.0996, "0.50", "0.10"),
    # an error below 1e-4 beside a value above it: fixed decimals on both (was 3.0e-05)
    (0.25, 3e-5, "0.250000", "0.000030"),
    (1.5e-4, 2e-5, "0.000150", "0.000020"),  # was 0.000150 ± 2.0e-05
    # a noise-free record: six digits of 0.25 reach 1e-6; 1.1e-14 is below that place
    (0.25, 1.1e-14, "0.250000", "<0.000001"),
    # 1.5e-6 at the value's last place (1e-6) is 2e-6: one digit, not "<"
    (0.25, 1.5e-6, "0.250000", "0.000002"),
    # a value below 1e-4: one exponent, the larger's (5e-5 ± 3e-6 -> 5.00 ± 0.30 x 1e-5)
    (5.0e-5, 3e-6, "5.00e-05", "0.30e-05"),
    (5.09e-5, 4.4e-5, "5.1e-05", "4.4e-05"),
    (1e-7, 1e-8, "1.00e-07", "0.10e-07"),
    # a value well below its error reads as the error allows: 1e-7 at place 1e-6 is 0.0
    (1e-7, 4.4e-5, "0.0e-05", "4.4e-05"),
    (0.0123, 0.5, "0.01", "0.50"),
    # a loss factor within its noise of zero is kept negative (compare.plausibility):
    # its sign is shown; one rounding to zero is no negative number
    (-3.2e-5, 4.4e-5, "-3.2e-05", "4.4e-05"),
    (-0.5, 0.01, "-0.500", "0.010"),
    (-1e-9, 4.4e-5, "0.0e-05", "4.4e-05"),
    # large values: fixed up to 1e6 (six digits of 999.9999996 carry to 1000.00)
    (1234.5, 60.0, "1234", "60"),
    (999.9999996, 1e-9, "1000.00", "<0.01"),
    (1.5e6, 2.3e3, "1.5000e+06", "0.0023e+06"),
    # zero and exact values
    (0.0, 0.00056, "0.00000", "0.00056"),
    (0.0, 0.0, "0", "0"),
    (0.25, 0.0, "0.250000", "0"),
    (5e-5, 0.0, "5.00000e-05", "0"),
    # not finite: the value alone where the error is unknown, "inf" said where infinite
    (1.5702e-4, math.nan, "0.000157", ""),
    (3.14159, math.inf, "3.142", "inf"),
    (math.nan, 0.1, "—", ""),
    (math.inf, 0.1, "—", ""),
])
def test_value_and_error_by_hand(value, stderr, value_text, error_text):
    assert value_and_error_texts(value, stderr) == (value_text, error_text)


def _mantissa_exponent(text: str) -> tuple[str, int]:
    mantissa, _, exponent = text.lstrip("<").partition("e")
    return mantissa, int(exponent or 0)


@pytest.mark.parametrize("value", [1e-7, 3.3e-6, 5.09e-5, 1.5702e-4, 0.0123, 0.25, 6.2, 870.0,
                                   -4.4e-5, -0.031])
@pytest.mark.parametrize("relative", [1e-14, 1e-7, 1e-5, 3e-3, 0.08, 1.0, 30.0])
def test_value_and_error_share_notation_and_place(value, relative):
    """Over values 1e-7 .. 1e3 and errors from round-off to 30 times the value: one exponent
    on both, the value's last decimal place the error's (or the error below the value's
    sixth digit, said by "<"), and each within half a unit of that place of the truth."""
    stderr = abs(value) * relative
    value_text, error_text = value_and_error_texts(value, stderr)
    (value_mantissa, value_exp), (error_mantissa, error_exp) = map(
        _mantissa_exponent, (value_text, error_text))
    assert value_exp == error_exp, (value_text, error_text)
    value_place = Decimal(value_mantissa).as_tuple().exponent
    assert Decimal(error_mantissa).as_tuple().exponent == value_place, (value_text, error_text)
    if "." not in error_mantissa and not error_text.startswith("<"):
        # "190", "26000": the trailing zeros of whole numbers do not say the place; the
        # error's second digit is the last one shown
        value_place = math.floor(math.log10(float(error_mantissa))) - 1
    unit = 10.0 ** (value_place + value_exp)
    # half a unit of the last place, plus float slack of 1e-9 of that unit
    assert abs(float(value_text) - value) <= unit * (0.5 + 1e-9)
    if error_text.startswith("<"):
        assert stderr < unit and len(value_mantissa.strip("-0.")) <= 6
    else:
        assert abs(float(error_text) - stderr) <= unit * (0.5 + 1e-9)
        assert 1 <= round(float(error_text) / unit) <= 99  # one or two significant digits


def test_the_written_pair_is_the_texts():
    assert display_value_with_error(0.25, 1.1e-14) == "0.250000 ± <0.000001"
    assert display_value_with_error(5.0e-5, 3e-6) == "5.00e-05 ± 0.30e-05"
    assert display_value_with_error(0.25, math.nan) == "0.25"
