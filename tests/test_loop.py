"""The one loop record and the data results hand over (loop, spectrum frame)."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from pidcore import defaults
from pidcore.dem.result import virtual_shaker_loop
from pidcore.errors import ParameterError
from pidcore.loop import ForceDisplacementLoop
from pidcore.signal import analyze_power, synthesize_shaker_record

G = 9.80665


@pytest.fixture(scope="module")
def analysis():
    rec = synthesize_shaker_record(mass_kg=0.4, acceleration_amplitude_m_s2=4 * G,
                                   frequency_hz=120.0, sample_rate_hz=10240.0, n_periods=50.5,
                                   viscous_damping_n_s_m=3.0, coulomb_friction_n=0.5,
                                   force_harmonics_n=(0.3, 0.2), snr_db=45, seed=2)
    return analyze_power(rec.force_n, rec.velocity_m_s, 10240.0, source="run.uff")


def test_viscous_loop_area_is_pi_c_omega_x_squared():
    # f = c v with x = X sin(wt): oint f dx = pi c w X^2 (exact). The N-gon of the ellipse
    # encloses only N/(2 pi) sin(2 pi/N) of it (1 - 1e-4 at N = 256), which the app showed
    # as the energy per cycle; the area is exact to rounding (1e-12), at any N >= 3
    c, freq, amp = 2.5, 80.0, 1e-4
    w = 2 * np.pi * freq
    exact = np.pi * c * w * amp**2
    for n in (3, 16, defaults.LOOP_POINTS):
        loop = ForceDisplacementLoop.from_phasors([1], [c * w * amp], [w * amp], freq,
                                                  n_points=n)
        assert loop.energy_per_cycle_j == pytest.approx(exact, rel=1e-12)
        assert loop.n_points == n
    # a pure spring (force in phase with displacement) encloses nothing
    spring = ForceDisplacementLoop.from_phasors([1], [1e3 * amp / 1j], [w * amp], freq)
    assert abs(spring.energy_per_cycle_j) < 1e-15


def test_power_analysis_loop_area_is_the_measured_energy_per_cycle(analysis):
    loop = analysis.loop(512)
    # the loop of 5 harmonics encloses Re(P_c) T, the energy `pidcore analyze` prints, to
    # rounding (1e-12; the polygon's area was off by 1e-4 and the app showed that digit)
    assert loop.energy_per_cycle_j == pytest.approx(
        analysis.complex_power_w.real * analysis.period_s, rel=1e-12)
    assert analysis.loop().energy_per_cycle_j == pytest.approx(analysis.energy_per_cycle_j,
                                                               rel=1e-12)
    assert loop.label == "run.uff" and loop.frequency_hz == analysis.frequency_hz
    x, f = analysis.force_displacement_loop(512)  # 0.1 spelling: the same arrays
    np.testing.assert_array_equal(x, loop.displacement_m)
    np.testing.assert_array_equal(f, loop.force_n)


def test_loop_frame_round_trips_the_arrays_with_units(analysis):
    loop = analysis.loop()
    frame = loop.to_pandas()
    assert list(frame.columns) == ["phase [rad]", "displacement [m]", "force [N]"]
    np.testing.assert_array_equal(frame["displacement [m]"].to_numpy(), loop.displacement_m)
    np.testing.assert_array_equal(frame["force [N]"].to_numpy(), loop.force_n)
    assert frame.attrs["energy_per_cycle_j"] == loop.energy_per_cycle_j
    assert loop.UNITS["displacement_m"] == "m" and loop.UNITS["force_n"] == "N"
    x, f = loop.closed()
    assert x[-1] == x[0] and f[-1] == f[0] and x.size == loop.n_points + 1


def test_spectrum_frame_gives_back_the_phasors(analysis):
    frame = analysis.to_pandas()
    assert isinstance(frame, pd.DataFrame)
    n = frame["harmonic [-]"].to_numpy()
    np.testing.assert_array_equal(n, analysis.harmonics)
    np.testing.assert_allclose(frame["frequency [Hz]"], n * analysis.frequency_hz, rtol=1e-15)
    force = frame["force amplitude [N]"] * np.exp(1j * frame["force phase [rad]"])
    velocity = frame["velocity amplitude [m/s]"] * np.exp(1j * frame["velocity phase [rad]"])
    np.testing.assert_allclose(force, analysis.force_phasors_n, rtol=1e-12)
    np.testing.assert_allclose(velocity, analysis.velocity_phasors_m_s, rtol=1e-12)


def test_virtual_shaker_loop_skips_the_transient():
    # 5 cycles of a spring (no area), then 12 of a viscous damper: the loop from cycle 5 on
    # encloses exactly the damper's energy
    rate, freq, c, amp_v = 12800.0, 100.0, 4.0, 0.02
    t = np.arange(17 * 128) / rate
    v = amp_v * np.sin(2 * np.pi * freq * t)
    f = np.where(t < 5 / freq, -3e4 * amp_v / (2 * np.pi * freq) * np.cos(2 * np.pi * freq * t),
                 c * v)
    loop = virtual_shaker_loop(f, v, sample_rate_hz=rate, frequency_hz=freq,
                               steady_start_cycle=5, n_harmonics=1)
    exact = 0.5 * c * amp_v**2 / freq  # Re(P_c) T
    # one harmonic fitted to a noise-free sine over whole periods: exact to rounding
    # (the polygon of 256 points had 1 - 1e-4 of the ellipse's area)
    assert loop.energy_per_cycle_j == pytest.approx(exact, rel=1e-9)
    with pytest.raises(ParameterError, match="steady cycles"):
        virtual_shaker_loop(f, v, sample_rate_hz=rate, frequency_hz=freq,
                            steady_start_cycle=16)


def test_loop_refuses_bad_input():
    with pytest.raises(ParameterError, match="equal length"):
        ForceDisplacementLoop(np.zeros(4), np.zeros(5), 10.0)
    with pytest.raises(ParameterError, match="frequency_hz"):
        ForceDisplacementLoop.from_phasors([1], [1.0], [1.0], -5.0)
    with pytest.raises(ParameterError, match="n_points"):
        ForceDisplacementLoop.from_phasors([1], [1.0], [1.0], 5.0, n_points=2)


def test_plot_forwards_to_the_report_figures(analysis):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from pidcore.report.figures_results import plot_loop

    ax = analysis.plot()
    heights = [p.get_height() for p in ax.patches]
    np.testing.assert_allclose(heights, np.abs(analysis.force_phasors_n))
    ax = plot_loop(analysis.loop())
    np.testing.assert_allclose(ax.lines[0].get_xdata(), analysis.loop().closed()[0] * 1e6)
    plt.close("all")
