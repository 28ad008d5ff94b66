"""An acceleration-only export (no velocity channel: the velocity is integrated from the
acceleration) whose acceleration starts a fraction of a sample off the force's instants is
corrected as a velocity's start offset is, and said in the same words; it was refused
("starts +0.370 samples off the force channel's sample grid").

Analytic truth: F = F0 cos(wt), a = A cos(wt + phi), so V_1 = A/(jw) e^{j phi} and
P_c = 1/2 F conj(V) = F0 A / (2w) (sin phi + j cos phi): loss factor tan(phi), SDC
2 pi tan(phi), Im(P_c) = F0 A cos(phi) / (2w).
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from pidcore.cli import main
from pidcore.errors import ParameterError
from pidcore.io import write_measurement
from pidcore.measure import analyze_file
from pidcore.records import Channel, Measurement
from pidcore.signal import analyze_power

F0, A0, FREQ, ETA, FS = 10.0, 30.0, 100.0, 0.05, 5120.0
W = 2 * math.pi * FREQ
PHI = math.atan(ETA)  # the acceleration leads the force by phi: loss factor tan(phi) = ETA
N = int(2 * FS)  # 200 periods
# The UFF abscissa minimum is printed with 6 significant digits (E13.5): up to 5e-6 of a start
# of at most 3.4 samples (6.6e-4 s) is 3.3e-9 s, 2.1e-6 rad at 100 Hz and so 2.1e-6 in the loss
# factor; the CSV's 9-digit time columns and the binary formats are closer. An uncorrected
# 0.37-sample offset is w x 0.37 / FS = 0.045 rad, 0.045 in the loss factor.
LOSS_TOLERANCE = 1e-5


def _force(t: np.ndarray) -> np.ndarray:
    return F0 * np.cos(W * t)


def _acceleration(t: np.ndarray) -> np.ndarray:
    return A0 * np.cos(W * t + PHI)


def _velocity(t: np.ndarray) -> np.ndarray:
    return A0 / W * np.sin(W * t + PHI)  # the integral of _acceleration


def _export(path: Path, response: Channel, force_rate_hz: float = FS) -> Path:
    """Force sampled from t = 0 and ``response`` (its own start and rate) as the export
    ``path`` names: UFF ASCII or 58b (``.uff58b`` is written as ``.uff``, binary), MAT or
    HDF5 through :func:`write_measurement`; CSV by hand, one time column per channel (the
    writer needs one start for all)."""
    t_force = np.arange(N) / force_rate_hz
    force = Channel("Force", "force", _force(t_force), force_rate_hz, "N")
    if path.suffix == ".csv":
        t_resp = response.start_time_s + np.arange(response.n_samples) / response.sample_rate_hz
        unit = response.source_unit
        rows = "".join(f"{a:.9g},{b:.9g},{c:.9g},{d:.9g}\n" for a, b, c, d in
                       zip(t_force, force.data, t_resp, response.data, strict=True))
        path.write_text(f"Time [s],Force [N],Time [s],{response.name} [{unit}]\n" + rows)
        return path
    binary = path.suffix == ".uff58b"
    path = path.with_suffix(".uff") if binary else path
    write_measurement(Measurement(path.name, (force, response)), path, binary=binary)
    return path


def _response(role: str, start_samples: float, rate_hz: float = FS,
              n: int = N) -> Channel:
    start = start_samples / rate_hz
    t = start + np.arange(n) / rate_hz
    if role == "acceleration":
        return Channel("Acceleration", role, _acceleration(t), rate_hz, "m/s^2",
                       start_time_s=start)
    return Channel("Velocity", role, _velocity(t), rate_hz, "m/s", start_time_s=start)


def _offset_notes(notes) -> list[str]:
    return [n for n in notes if "samples off the force's grid" in n]


@pytest.mark.parametrize("start_samples", [0.37, -0.37, 3.37])
@pytest.mark.parametrize("suffix", [".uff", ".uff58b", ".csv", ".mat", ".h5"])
def test_acceleration_only_fractional_start_offset_is_corrected_like_the_velocitys(
        tmp_path, suffix, start_samples):
    path = _export(tmp_path / f"acc{suffix}", _response("acceleration", start_samples))
    record = analyze_file(path)
    a = record.analysis
    assert a.corrections["velocity_from_acceleration"] is True
    assert a.loss_factor == pytest.approx(ETA, abs=LOSS_TOLERANCE)
    assert a.sdc == pytest.approx(2 * math.pi * ETA, abs=2 * math.pi * LOSS_TOLERANCE)
    # |P_c| is not touched by a phase error: its printed digits only (relative 5e-6)
    assert a.complex_power_w.imag == pytest.approx(F0 * A0 * math.cos(PHI) / (2 * W), rel=1e-5)
    fraction = start_samples - round(start_samples)
    assert record.corrections | a.corrections == record.to_dict()["corrections"]
    # the delay that corrects it: -fraction/FS, as read back from the file (6 digits in UFF)
    assert a.corrections["start_offset_delay_s"] == pytest.approx(-fraction / FS, rel=1e-5)
    assert a.corrections["velocity_delay_s"] == 0.0  # no vibrometer delay was given

    # the velocity of the same motion, exported alike, is corrected by the same rule and
    # said in the same words (but for the channel's name)
    velocity_path = _export(tmp_path / f"vel{suffix}", _response("velocity", start_samples))
    by_velocity = analyze_file(velocity_path)
    assert by_velocity.analysis.loss_factor == pytest.approx(a.loss_factor, abs=1e-9)
    (said,) = _offset_notes(record.notes)
    (said_for_velocity,) = _offset_notes(by_velocity.notes)
    assert said.replace("'Acceleration'", "'X'") == said_for_velocity.replace("'Velocity'", "'X'")
    head = (f"channel 'Acceleration' starts {fraction:+.4g} samples off the force's grid: "
            "corrected as a velocity delay of ")
    assert said.startswith(head) and said.endswith(" s")
    assert float(said[len(head):-2]) == pytest.approx(-fraction / FS, rel=1e-5)


def test_the_correction_is_printed_by_pidcore_analyze(tmp_path, capsys):
    path = _export(tmp_path / "acc.uff", _response("acceleration", 0.37))
    assert main(["analyze", str(path), "--no-store", "--no-progress"]) == 0
    out = capsys.readouterr().out
    assert ("note: channel 'Acceleration' starts +0.37 samples off the force's grid: "
            "corrected as a velocity delay of -7.22656e-05 s") in out


# starts the UFF's six digits hold exactly (2/5120 = 3.90625e-4 s, -4/5120 = -7.8125e-4 s):
# -3/5120 = -5.859375e-4 s needs seven: printed with six it is 2.6e-6 samples off the grid,
# which the file then states and pidcore corrects as a delay, as it does a velocity's
@pytest.mark.parametrize("start_samples", [0, 2, -4])
@pytest.mark.parametrize("suffix", [".uff", ".csv"])
def test_acceleration_only_whole_sample_or_no_offset_is_cut_not_delayed(tmp_path, suffix,
                                                                         start_samples):
    path = _export(tmp_path / f"acc{suffix}", _response("acceleration", start_samples))
    record = analyze_file(path)
    # noise-free, on the force's grid: only the printed digits (9 or more, relative 5e-9 of
    # each sample) are left, far below a sample's 0.12 rad
    assert record.analysis.loss_factor == pytest.approx(ETA, abs=1e-7)
    assert not _offset_notes(record.notes)
    assert "start_offset_delay_s" not in record.to_dict()["corrections"]
    aligned = [n for n in record.notes if "aligned on their common time span" in n]
    assert len(aligned) == (1 if start_samples else 0)


def _refusal(path: Path, capsys, *args: str) -> str:
    store = path.parent / "store.h5"
    assert main(["analyze", str(path), "--store", str(store), "--no-progress", *args]) == 2
    out, err = capsys.readouterr()
    assert not store.exists() and out == ""
    assert len(err.strip().splitlines()) == 1, err
    assert path.name in err
    return err


def test_an_acceleration_that_starts_after_the_force_ends_is_refused(tmp_path, capsys):
    path = _export(tmp_path / "late.uff", _response("acceleration", N + 0.37))
    err = _refusal(path, capsys)
    assert "do not overlap in time" in err and "'Acceleration'" in err and "'Force'" in err


def test_an_acceleration_at_another_sample_rate_is_refused(tmp_path, capsys):
    # 5000 Hz beside 5120 Hz: no start offset is a fraction of one sample of both
    path = _export(tmp_path / "rates.uff", _response("acceleration", 0.37, rate_hz=5000.0))
    err = _refusal(path, capsys)
    assert "'Acceleration'" in err and "5000 Hz differs from 5120 Hz of channel 'Force'" in err


def test_a_vibrometer_delay_is_still_refused_without_a_velocity_channel(tmp_path, capsys):
    # the start offset is corrected for the acceleration; a vibrometer's delay is not its
    path = _export(tmp_path / "acc.uff", _response("acceleration", 0.37))
    err = _refusal(path, capsys, "--velocity-delay", "2e-4")
    assert "a vibrometer delay needs a velocity channel" in err


def test_an_acceleration_beside_a_velocity_off_the_grid_is_still_refused(tmp_path, capsys):
    # mass cancellation takes m a off the force at the force's instants: the acceleration
    # there is not the channel the velocity comes from, and its own offset is not corrected
    t = np.arange(N) / FS
    start = 0.37 / FS
    path = tmp_path / "both.uff"
    write_measurement(Measurement(path.name, (
        Channel("Force", "force", _force(t), FS, "N"),
        Channel("Velocity", "velocity", _velocity(t), FS, "m/s"),
        Channel("Acceleration", "acceleration", _acceleration(t + start), FS, "m/s^2",
                start_time_s=start))), path)
    err = _refusal(path, capsys, "--mass-below-gauge", "0.01")
    assert "channel 'Acceleration' starts +0.370 samples off the force channel's" in err


def test_a_start_offset_delay_beyond_half_a_sample_is_refused():
    # what is left of an offset once whole samples are cut is half a sample at most; more is
    # samples that belong cut (or a time in another unit), whose phase would wrap unnoticed
    t = np.arange(N) / FS
    with pytest.raises(ParameterError, match=r"^acc\.uff: start_offset_delay_s: .*half a "
                                             r"sample at 5120 Hz"):
        analyze_power(_force(t), None, FS, acceleration=_acceleration(t),
                      start_offset_delay_s=0.6 / FS, source="acc.uff")
    exact = analyze_power(_force(t), None, FS, acceleration=_acceleration(t + 0.5 / FS),
                          start_offset_delay_s=-0.5 / FS)
    assert exact.loss_factor == pytest.approx(ETA, abs=1e-9)  # noise-free float64



# A UFF states each record's start (abscissa minimum, E13.5) with six significant digits: two
# records 0.37 samples apart from 0.5 s at 51.2 kHz read 0.358 samples apart (0.5 and
# 0.500007), each start known to +-5e-7 s. At 1 kHz that is up to 6.3e-3 rad, and the loss
# factor came out 1.4e-3 off (3 % of 0.05) with a note saying the offset was corrected.
LATE_START_S, FAST_RATE_HZ, FAST_DRIVE_HZ = 0.5, 51_200.0, 1000.0


def _late_export(path: Path, role: str, start_samples: float) -> Path:
    w = 2 * math.pi * FAST_DRIVE_HZ
    n = int(0.5 * FAST_RATE_HZ)
    t = LATE_START_S + np.arange(n) / FAST_RATE_HZ
    t_resp = t + start_samples / FAST_RATE_HZ
    response = (A0 * np.cos(w * t_resp + PHI) if role == "acceleration" else
                A0 / w * np.sin(w * t_resp + PHI))
    unit = "m/s^2" if role == "acceleration" else "m/s"
    write_measurement(Measurement(path.name, (
        Channel("Force", "force", F0 * np.cos(w * t), FAST_RATE_HZ, "N",
                start_time_s=LATE_START_S),
        Channel("Response", role, response, FAST_RATE_HZ, unit,
                start_time_s=float(t_resp[0])))), path)
    return path


@pytest.mark.parametrize("start_samples", [0.37, 3.0])
@pytest.mark.parametrize("role", ["acceleration", "velocity"])
def test_a_start_offset_finer_than_a_uffs_six_digits_is_refused(tmp_path, capsys, role,
                                                                start_samples):
    path = _late_export(tmp_path / "late.uff", role, start_samples)
    err = _refusal(path, capsys)
    assert "channel 'Response' starts" in err and "channel 'Force'" in err
    assert "6 significant digits" in err and "±0.051 samples" in err  # 2 x 5e-7 s x 51.2 kHz
    # the same channels with their starts in float64: corrected to the truth (noise-free;
    # the 0.5 s start leaves 1e-16 s x 2 pi 1 kHz of phase)
    exact = analyze_file(_late_export(tmp_path / "late.h5", role, start_samples))
    assert exact.analysis.loss_factor == pytest.approx(ETA, abs=1e-7)


def test_uff_records_of_one_start_are_one_clock_reading(tmp_path):
    # both records from 0.5 s print the same six digits: no offset between them to doubt
    path = _late_export(tmp_path / "together.uff", "acceleration", 0.0)
    assert analyze_file(path).analysis.loss_factor == pytest.approx(ETA, abs=1e-7)


def test_a_start_offset_of_a_millionth_of_a_sample_is_said_as_it_is(tmp_path):
    # -3 samples at 5120 Hz (-5.859375e-4 s) is printed with six digits (E13.5) in the UFF:
    # the file states 2.6e-6 samples off the grid, which is corrected; the note said "starts
    # +0.0000 samples off the force's grid", a correction of nothing by its own words
    path = _export(tmp_path / "acc.uff", _response("acceleration", -3))
    (said,) = _offset_notes(analyze_file(path).notes)
    stated = float(f"{-3 / FS:.5e}") * FS + 3  # the fraction the six digits leave
    assert abs(stated) > 1e-6  # beyond the 1e-6 samples taken for none
    fraction = float(said.split(" starts ")[1].split(" samples")[0])
    assert fraction == pytest.approx(stated, rel=1e-3)  # printed with 4 digits
