"""A specimen of the paper's coupon renamed "panel" and exports of its tests, for the tests of
how a measurement's specimen file (name and sha256) is recorded and matched."""

from __future__ import annotations

from pathlib import Path

from pidcore.specimen import Specimen, paper_specimen


def panel_specimen(fixture_mass_kg: float) -> Specimen:
    """The paper's coupon renamed "panel" (not the paper's), with its own fixture mass: two
    masses are two files of one name."""
    text = paper_specimen().with_values({"coupon.fixture_mass_kg": fixture_mass_kg}).to_toml()
    return Specimen.from_text(text.replace('name = "paper_coupon"', 'name = "panel"', 1))


def panel_export(path: Path, damping_n_s_m: float) -> Path:
    """An export at ``path`` (its format by the suffix) of a 50 g mass with a viscous damper
    shaken at 1000 Hz, 5 g (its loss factor follows from ``damping_n_s_m``)."""
    from pidcore.constants import STANDARD_GRAVITY
    from pidcore.io import write_measurement
    from pidcore.records import Channel, Measurement
    from pidcore.signal import synthesize_shaker_record

    rate = 51200.0
    rec = synthesize_shaker_record(mass_kg=0.05,
                                   acceleration_amplitude_m_s2=5 * STANDARD_GRAVITY,
                                   frequency_hz=1000.0, sample_rate_hz=rate, n_periods=40,
                                   viscous_damping_n_s_m=damping_n_s_m)
    write_measurement(Measurement(path.stem, (
        Channel("Force", "force", rec.force_n, rate, "N"),
        Channel("LDV", "velocity", rec.velocity_m_s, rate, "m/s"))), path)
    return path
