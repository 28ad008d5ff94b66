"""pidcore.signal.analyze_channels validation: one-line errors naming source and channel."""

from __future__ import annotations

import tracemalloc

import numpy as np
import pytest

from pidcore.errors import ChannelError, SignalError
from pidcore.records import Channel
from pidcore.signal import analyze_channels, synthesize_shaker_record
from pidcore.signal.validate import clipped_samples

G = 9.80665
FS = 10240.0


def _record(n_periods=40.5, **kw):
    rec = synthesize_shaker_record(mass_kg=0.5, acceleration_amplitude_m_s2=2 * G,
                                   frequency_hz=100.0, sample_rate_hz=FS, n_periods=n_periods,
                                   viscous_damping_n_s_m=2.0, with_acceleration=True, **kw)
    force = Channel("Fz", "force", rec.force_n, FS, "N")
    vel = Channel("vib", "velocity", rec.velocity_m_s, FS, "mm/s")
    acc = Channel("Az", "acceleration", rec.acceleration_m_s2, FS, "g")
    return force, vel, acc


def _with(ch: Channel, data=None, **kw) -> Channel:
    fields = dict(name=ch.name, quantity=ch.quantity, data=ch.data if data is None else data,
                  sample_rate_hz=ch.sample_rate_hz, source_unit=ch.source_unit)
    fields.update(kw)
    return Channel(**fields)


def _one_line(exc) -> str:
    msg = str(exc.value)
    assert "\n" not in msg
    return msg


def test_valid_channels_give_truth():
    force, vel, acc = _record()
    res = analyze_channels(force, vel, acceleration=acc, source="ok.uff", frequency_hz=100.0)
    w = 2 * np.pi * 100.0
    assert res.loss_factor == pytest.approx(2.0 / (0.5 * w), rel=1e-9)  # c / (m w), noise-free
    assert res.source == "ok.uff"


def test_nan_samples_named_with_count_and_first_index():
    force, vel, _ = _record()
    data = vel.data.copy()
    data[[17, 40, 99]] = [np.nan, np.inf, np.nan]
    with pytest.raises(ChannelError) as exc:
        analyze_channels(force, _with(vel, data), source="bad.uff")
    msg = _one_line(exc)
    assert "bad.uff" in msg and "'vib'" in msg and "3 non-finite samples" in msg
    assert "first at index 17" in msg


def test_clipped_channel_reported_and_allowed_on_request():
    force, vel, _ = _record()
    level = 0.8 * np.max(force.data)
    clipped = np.clip(force.data, -np.inf, level)
    expected = int(np.sum(clipped == level))  # every clipped sample sits in a long run here
    with pytest.raises(ChannelError) as exc:
        analyze_channels(_with(force, clipped), vel, source="clip.uff")
    msg = _one_line(exc)
    assert f"'Fz' clipped: {expected} samples at {level:+.6g} N" in msg
    assert "allow_clipped=True" in msg
    res = analyze_channels(_with(force, clipped), vel, source="clip.uff", allow_clipped=True)
    assert np.isfinite(res.loss_factor)
    # analysed on request, but still reported: the same count and level as the refusal
    assert any(f"'Fz' clipped: {expected} samples at {level:+.6g} N" in n for n in res.notes)
    clean = analyze_channels(force, vel, source="clip.uff", allow_clipped=True)
    assert not any("clipped" in n for n in clean.notes)


def test_clipped_samples_counts_only_runs():
    data = np.array([0.0, 5.0, 0.0, 5.0, 5.0, 5.0, 5.0, 5.0, 1.0, -2.0, -2.0, -2.0])
    # one isolated 5.0 (not clipping), a run of five 5.0, a run of three -2.0 (< 4: not clipping)
    assert clipped_samples(data, min_run=4) == (5, 5.0)
    assert clipped_samples(data, min_run=3) == (5, 5.0)
    assert clipped_samples(np.sin(np.arange(1000) * 0.1)) == (0, pytest.approx(np.nan, nan_ok=True))


def test_too_few_periods():
    force, vel, _ = _record(n_periods=7.25)
    with pytest.raises(SignalError) as exc:
        analyze_channels(force, vel, source="short.uff")
    msg = _one_line(exc)
    assert "short.uff" in msg and "'vib'" in msg and "7.25 drive periods" in msg
    assert "at least 10" in msg


def test_different_sample_rate_and_length():
    force, vel, _ = _record()
    with pytest.raises(ChannelError) as exc:
        analyze_channels(force, _with(vel, sample_rate_hz=2 * FS), source="r.uff")
    msg = _one_line(exc)
    assert "'vib'" in msg and "sample rate 20480 Hz differs from 10240 Hz" in msg
    # rates 1e-7 apart (above the round-off tolerance of one clock) are refused in digits that
    # show the difference, not as '10240 Hz differs from 10240 Hz'
    with pytest.raises(ChannelError) as exc:
        analyze_channels(force, _with(vel, sample_rate_hz=FS * (1 + 1e-7)), source="r.uff")
    assert "sample rate 10240.001 Hz differs from 10240 Hz" in _one_line(exc)
    with pytest.raises(ChannelError) as exc:
        analyze_channels(force, _with(vel, vel.data[:-3]), source="r.uff")
    msg = _one_line(exc)
    assert "'vib'" in msg and f"{vel.n_samples - 3} samples differs" in msg


@pytest.mark.parametrize("value,word", [(0.0, "zero"), (1.5, "constant at +1.5 N")])
def test_zero_or_constant_channel(value, word):
    force, vel, _ = _record()
    with pytest.raises(ChannelError) as exc:
        analyze_channels(_with(force, np.full(force.n_samples, value)), vel, source="c.uff")
    msg = _one_line(exc)
    assert "'Fz'" in msg and word in msg


def test_wrong_quantity():
    force, vel, acc = _record()
    # "is a acceleration channel" was printed
    with pytest.raises(ChannelError, match=r"'Az': is an acceleration channel, expected a "
                                           r"velocity"):
        analyze_channels(force, acc, source="q.uff")


def test_acceleration_only_channels():
    force, _, acc = _record(snr_db=50, seed=4)
    res = analyze_channels(force, None, acceleration=acc, source="a.uff")
    w = 2 * np.pi * 100.0
    # 3 % of the brief's tolerance, 50 dB noise on 4000 samples is ~0.5 % scatter
    assert res.loss_factor == pytest.approx(2.0 / (0.5 * w), rel=0.03)


def test_clipping_at_negative_extreme():
    force, vel, _ = _record()
    level = 0.7 * np.min(vel.data)
    clipped = np.clip(vel.data, level, np.inf)
    expected = int(np.sum(clipped == level))
    with pytest.raises(ChannelError) as exc:
        analyze_channels(force, _with(vel, clipped), source="neg.uff")
    assert f"'vib' clipped: {expected} samples at {level:+.6g} m/s" in _one_line(exc)


def test_the_outlier_check_of_a_long_channel_copies_it_once():
    """The outlier check copied a channel without its markers (always, a boolean index
    copies) and percentile copied that again to partition it: 2x the channel on top of it
    for each channel analysed. Without markers the samples are handed to percentile as they
    are (its one copy), and with markers the copy is partitioned in place: 1x, checked with
    0.25x for the marker mask (1/8) and small buffers. The percentiles, and so the verdict,
    are the same numbers (a marker is still found, with the same message)."""
    from pidcore.errors import ChannelError
    from pidcore.signal.validate import check_outliers

    data = np.sin(np.arange(1_000_000) * 0.01)
    tracemalloc.start()
    try:
        check_outliers(data, source="x", channel="Force")
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert peak <= 1.25 * data.nbytes, peak / data.nbytes
    data[1234] = 3.4e38
    with pytest.raises(ChannelError, match=r"1 sample far outside the signal, first at index "
                                           r"1234 \(3\.4e\+38; 99 % of the other samples lie "
                                           r"within -0\.999\d* \.\. 0\.999\d*\)"):
        check_outliers(data, source="x", channel="Force")
