"""Reading the third-party UFF exports in ../shared/fixtures/real_exports (see its README).

Expected values come from that README (written from the files and pyuff's own tests), not from
pidcore.
"""

from __future__ import annotations

import hashlib
from pathlib import Path

import numpy as np
import pytest

from pidcore.constants import STANDARD_GRAVITY
from pidcore.errors import InputFileError
from pidcore.io import detect_file_format, read_measurement

FIXTURES = Path(__file__).resolve().parents[1] / ".." / "shared" / "fixtures" / "real_exports"

pytestmark = pytest.mark.skipif(not FIXTURES.is_dir(),
                                reason=f"real UFF fixtures not present at {FIXTURES}")

# UFF writes the sample interval with 6 significant digits (E13.5), so the interval read back
# is exact to half a unit in the 6th digit: relative 5e-6.
DT_RTOL = 5e-6


def _read(name: str):
    return read_measurement(FIXTURES / name)


def _rms(x: np.ndarray) -> float:
    return float(np.sqrt(np.mean(x**2)))


def test_ascii_58_microphone_record():
    m = _read("pyuff_Sample_UFF58_ascii.uff")
    assert m.file_format == "uff"
    assert m.source == str(FIXTURES / "pyuff_Sample_UFF58_ascii.uff")
    assert m.sha256 == "d3e5e2814c0f5d33ab0d570b3fc0907c0097e7bfc4a091b1a424ab514e7d9060"
    (ch,) = m.channels
    assert ch.name == "Mic 01"
    assert ch.quantity == "pressure" and ch.unit == "Pa"
    assert ch.n_samples == 79292
    assert 1.0 / ch.sample_rate_hz == pytest.approx(1.52588e-05, rel=DT_RTOL)
    # The printed interval 1.52588e-05 is 1/65536 to six digits; the reader snaps to 65536 Hz.
    assert ch.sample_rate_hz == 65536.0
    # README gives the RMS to 4 significant digits.
    assert _rms(ch.data) == pytest.approx(0.01434, abs=0.5e-5)


def test_binary_58b_equals_ascii_58():
    ascii_ch = _read("pyuff_Sample_UFF58_ascii.uff").channels[0]
    binary_ch = _read("pyuff_Sample_UFF58b_bin.uff").channels[0]
    assert binary_ch.name == ascii_ch.name
    assert binary_ch.sample_rate_hz == ascii_ch.sample_rate_hz
    assert binary_ch.n_samples == ascii_ch.n_samples
    # ASCII E13.5 keeps 6 significant digits (relative rounding <= 5e-6); float32 adds ~6e-8.
    np.testing.assert_allclose(ascii_ch.data, binary_ch.data, rtol=6e-6, atol=1e-12)


def test_binary_double_precision_sine_in_g_is_converted_to_si():
    (ch,) = _read("pyuff_binary8byte.uff").channels
    assert ch.name == "sine 5 Hz"
    assert ch.quantity == "acceleration" and ch.source_unit == "g"
    assert ch.n_samples == 250
    assert ch.sample_rate_hz == 100.0
    t = np.arange(250) / 100.0
    # Unit amplitude in g. The synthetic samples were computed in float32 (phase error grows
    # with t: up to 7.3e-6 of the amplitude in this file), so compare to 1e-5 g.
    np.testing.assert_allclose(ch.data, STANDARD_GRAVITY * np.sin(2 * np.pi * 5 * t),
                               atol=1e-5 * STANDARD_GRAVITY)
    assert np.max(np.abs(ch.data)) == pytest.approx(STANDARD_GRAVITY, rel=1e-6)


def test_malformed_multichannel_58b_with_duplicate_entity_names():
    m = _read("pyuff_MPSTD_Set001_2024_10_08_10_27_07.uff")
    # The entity names repeat (node 1 twice); the ID lines 1 ("MPS set1 Dof1".."Dof4", the
    # export's own description) tell the records apart, so they name the channels.
    assert m.channel_names == ["MPS set1 Dof1", "MPS set1 Dof2", "MPS set1 Dof3",
                               "MPS set1 Dof4"]
    for ch in m.channels:
        assert ch.quantity == "acceleration" and ch.source_unit == "m/s2"
        assert ch.n_samples == 222400
        assert ch.sample_rate_hz == 3200.0
    # README gives the RMS to 2-3 significant digits.
    rms = [_rms(ch.data) for ch in m.channels]
    np.testing.assert_allclose(rms, [0.079, 0.319, 0.079, 0.131], atol=1e-3)
    assert len(set(m.channel_names)) == 4


def test_catman_partly_filled_last_line_and_3_digit_exponents():
    (ch,) = _read("pyuff_time-history-not-all-columns-filled.uff").channels
    assert ch.n_samples == 13
    assert ch.sample_rate_hz == 20000.0
    assert ch.quantity == "acceleration"  # from the label "m/s²" (code 1 = general)
    assert ch.data[0] == pytest.approx(-3.81956)
    assert ch.data[-1] == pytest.approx(-5.84096)


def test_zero_padded_force_record_is_truncated_to_num_pts():
    (ch,) = _read("UFFFilesjl_dataset58_time.unv").channels
    assert ch.name == ".1.Z-"
    assert ch.quantity == "force" and ch.unit == "N"
    assert ch.n_samples == 4096  # not the 4098 numbers of the padded last line
    assert 1.0 / ch.sample_rate_hz == pytest.approx(4.88281e-04, rel=DT_RTOL)
    assert ch.sample_rate_hz == 2048.0
    assert ch.data.min() == pytest.approx(-12.8, abs=0.05)
    assert ch.data.max() == pytest.approx(114.8, abs=0.05)
    assert ch.duration_s == pytest.approx(2.0, rel=DT_RTOL)


def test_fixed_columns_without_blanks_and_unknown_unit_kept():
    (ch,) = _read("UFFFilesjl_dataset58_nospacing.uff").channels
    assert ch.n_samples == 66
    assert 1.0 / ch.sample_rate_hz == pytest.approx(4.99942e-04, rel=1e-12)  # not snapped
    # (V^2) is no unit pidcore knows: the values are kept as written.
    assert ch.quantity == "unknown" and ch.source_unit == "(V^2)"
    # First data line: "-3.09944E-004-2.74181E-004  -0.00115633-6.31809E-004..."
    np.testing.assert_allclose(ch.data[:4], [-3.09944e-4, -2.74181e-4, -0.00115633, -6.31809e-4])
    assert ch.data[-1] == pytest.approx(-5.48363e-4)


@pytest.mark.parametrize(("name", "expected"), [
    ("pyuff_TestLab_161_164_18_15_82.uff",
     ["151, 164, 18, 15, 82", "header, units, coordinate systems, nodes, trace lines"]),
    ("pyuff_non_ascii_header.uff", ["58", "frequency response function"]),
    ("murmlgrmpf-uff_UFF58B.FRF", ["58", "frequency response function"]),
])
def test_files_without_time_records_say_what_they_hold(name, expected):
    with pytest.raises(InputFileError) as info:
        _read(name)
    message = str(info.value)
    assert name in message
    assert "no UFF58 time record" in message
    for text in expected:
        assert text in message


def test_every_fixture_is_detected_as_uff():
    for path in sorted(FIXTURES.iterdir()):
        if path.suffix.lower() in (".uff", ".unv", ".frf"):
            assert detect_file_format(path) == "uff", path.name


def test_sha256_is_of_the_file_bytes():
    path = FIXTURES / "pyuff_binary8byte.uff"
    assert read_measurement(path).sha256 == hashlib.sha256(path.read_bytes()).hexdigest()


@pytest.mark.parametrize("name", [
    "pyuff_Sample_UFF58_ascii.uff", "pyuff_time-history-not-all-columns-filled.uff",
    "UFFFilesjl_dataset58_time.unv", "UFFFilesjl_dataset58_nospacing.uff",
])
def test_fallback_ascii_parser_agrees_with_pyuff(name):
    """The fallback (used when pyuff rejects Fortran numbers) reads the same fixed columns."""
    import pyuff

    from pidcore.io._uff_ascii import parse_uff_ascii

    path = FIXTURES / name
    ours = [d for t, d in parse_uff_ascii(path.read_bytes().decode("latin-1")) if t == 58]
    theirs = pyuff.UFF(str(path)).read_sets()
    theirs = theirs if isinstance(theirs, list) else [theirs]
    assert len(ours) == len(theirs)
    for a, b in zip(ours, theirs, strict=True):
        # (Unit labels are not compared: '²' decodes differently as Latin-1 and UTF-8.)
        for key in ("func_type", "num_pts", "abscissa_inc", "ordinate_spec_data_type",
                    "rsp_ent_name"):
            assert a[key] == b[key], key
        n = a["num_pts"]
        np.testing.assert_array_equal(a["data"][:n], b["data"][:n])


def test_roles_on_real_exports():
    from pidcore.errors import ChannelError
    from pidcore.io import assign_roles

    four_acc = _read("pyuff_MPSTD_Set001_2024_10_08_10_27_07.uff")
    with pytest.raises(ChannelError, match=r"no force channel among 'MPS set1 Dof1'.*force=NAME"):
        assign_roles(four_acc)
    force_only = _read("UFFFilesjl_dataset58_time.unv")
    with pytest.raises(ChannelError, match="no velocity or acceleration channel"):
        assign_roles(force_only)
