"""Measurement workflow: file -> channels -> Eq. 11 analysis -> store.

The glue shared by the CLI (``pidcore analyze``), the report and the app, so that each of them
stays thin.
"""

from __future__ import annotations

import os
from collections.abc import Mapping, Sequence
from dataclasses import asdict, dataclass, field
from pathlib import Path

from . import defaults
from .io import assign_roles, read_measurement
from .records import Measurement
from .signal import PowerAnalysis, analyze_channels


@dataclass(frozen=True)
class AnalysisOptions:
    """User choices for one analysis run (channel mapping and corrections)."""

    force: str | None = None
    velocity: str | None = None
    acceleration: str | None = None
    velocity_delay_s: float = 0.0
    mass_below_gauge_kg: float = 0.0
    baseline_loss_factor: float = 0.0
    frequency_hz: float | None = None
    n_harmonics: int = defaults.N_HARMONICS
    sample_rate_hz: float | None = None
    allow_clipped: bool = False

    def parameters(self) -> dict:
        """JSON-safe parameters stored as provenance."""
        return {k: v for k, v in asdict(self).items() if v is not None}


@dataclass(frozen=True)
class AnalyzedRecord:
    """A measurement with its analysis and the channels used."""

    measurement: Measurement
    analysis: PowerAnalysis
    channels_used: dict[str, str]
    notes: tuple[str, ...] = field(default_factory=tuple)


def analyze_measurement(measurement: Measurement, options: AnalysisOptions) -> AnalyzedRecord:
    """Map channels to roles and run the Eq. 11 analysis on one measurement."""
    roles = assign_roles(measurement, force=options.force, velocity=options.velocity,
                         acceleration=options.acceleration)
    analysis = analyze_channels(
        roles.force, roles.velocity, acceleration=roles.acceleration,
        source=measurement.source,
        velocity_delay_s=options.velocity_delay_s,
        mass_below_gauge_kg=options.mass_below_gauge_kg,
        baseline_loss_factor=options.baseline_loss_factor,
        frequency_hz=options.frequency_hz,
        n_harmonics=options.n_harmonics,
        allow_clipped=options.allow_clipped,
    )
    used = {"force": roles.force.name}
    if roles.velocity is not None:
        used["velocity"] = roles.velocity.name
    if roles.acceleration is not None:
        used["acceleration"] = roles.acceleration.name
    return AnalyzedRecord(measurement, analysis, used, analysis.notes)


def analyze_file(path: str | os.PathLike, options: AnalysisOptions) -> AnalyzedRecord:
    """Read one export file and analyse it."""
    measurement = read_measurement(Path(path), sample_rate_hz=options.sample_rate_hz)
    return analyze_measurement(measurement, options)


def store_analysis(store, result: AnalyzedRecord, parameters: Mapping, *,
                   fields: Mapping | None = None) -> str:
    """Add one analysed record and its measurement to an open :class:`~pidcore.store.Store`.

    The analysis is keyed by its measurement and ``parameters`` (plus the channels used), so
    the same file analysed with the same options replaces its entry. ``fields`` adds record
    fields (the load case, :meth:`pidcore.compare.LoadCase.as_record`). Returns the key.
    """
    measurement_key, _ = store.add_measurement(result.measurement)
    record = {**analysis_record(result), **(fields or {})}
    return store.add_analysis(
        measurement_key, record, arrays=analysis_arrays(result.analysis),
        parameters={**parameters, "channels": result.channels_used},
        units={k: v for k, v in ANALYSIS_UNITS.items() if k in record})


def save_analyses(store_path: str | os.PathLike, results: Sequence[AnalyzedRecord],
                  options: AnalysisOptions) -> list[str]:
    """Save measurements and their analyses to the store in one transaction."""
    from .store import Store

    store = Store(store_path)
    with store.transaction():
        return [store_analysis(store, r, options.parameters()) for r in results]


#: Units of the scalar fields stored per analysis.
ANALYSIS_UNITS = {
    "frequency_hz": "Hz", "acceleration_g": "g", "acceleration_m_s2": "m/s^2",
    "complex_power_real_w": "W", "complex_power_imag_w": "var", "loss_factor": "1",
    "loss_factor_stderr": "1", "sdc": "1", "sdc_stderr": "1", "damping_ratio": "1",
    "energy_per_cycle_j": "J", "max_kinetic_energy_j": "J", "force_amplitude_n": "N",
    "velocity_amplitude_m_s": "m/s", "displacement_amplitude_m": "m", "n_periods": "1",
    "fill_percent": "%",
}


def analysis_record(r: AnalyzedRecord) -> dict:
    """Flat scalar record of one analysis, as stored."""
    a = r.analysis
    return {
        "frequency_hz": a.frequency_hz,
        "acceleration_g": a.acceleration_g,
        "acceleration_m_s2": a.acceleration_amplitude_m_s2,
        "complex_power_real_w": a.complex_power_w.real,
        "complex_power_imag_w": a.complex_power_w.imag,
        "loss_factor": a.loss_factor,
        "loss_factor_stderr": a.loss_factor_stderr,
        "sdc": a.sdc,
        "sdc_stderr": a.sdc_stderr,
        "damping_ratio": float("nan") if a.damping_ratio is None else a.damping_ratio,
        "energy_per_cycle_j": a.energy_per_cycle_j,
        "max_kinetic_energy_j": a.max_kinetic_energy_j,
        "force_amplitude_n": a.force_amplitude_n,
        "velocity_amplitude_m_s": a.velocity_amplitude_m_s,
        "displacement_amplitude_m": a.displacement_amplitude_m,
        "n_periods": a.n_periods,
        "force_channel": r.channels_used.get("force", ""),
        "velocity_channel": r.channels_used.get("velocity", ""),
        "acceleration_channel": r.channels_used.get("acceleration", ""),
    }


def analysis_arrays(a: PowerAnalysis) -> dict:
    return {
        "harmonics": a.harmonics,
        "force_phasors_n": a.force_phasors_n,
        "velocity_phasors_m_s": a.velocity_phasors_m_s,
    }
