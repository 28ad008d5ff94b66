"""Measurement workflow: file -> channels -> Eq. 11 analysis -> store.

The glue shared by the CLI (``pidcore analyze``), the report and the app, so that each of them
stays thin; a script analyses files the same way.

Public API
----------
analyze_file, analyze_measurement
    One export file (or a measurement read already) -> :class:`AnalyzedRecord`: channels
    mapped to roles, units checked, the Eq. 11 analysis (``record.analysis``, a
    :class:`~pidcore.signal.PowerAnalysis` with ``to_pandas()`` and ``plot()``) and notes.
AnalysisOptions
    The options of ``pidcore analyze`` (channels, delay, mass below the gauge, baseline, ...).
AnalyzedRecord
    A measurement with its analysis, channels used, notes and corrections.
save_analyses, SavedAnalyses, store_analysis
    Analyses saved to a :class:`~pidcore.store.Store` in one transaction.

Examples
--------
>>> from pidcore.measure import AnalysisOptions, analyze_file          # doctest: +SKIP
>>> record = analyze_file("run_012.uff", AnalysisOptions(velocity_delay_s=50e-6))  # doctest: +SKIP
>>> record.analysis.sdc, record.analysis.sdc_stderr                   # doctest: +SKIP
"""

from __future__ import annotations

import math
import os
from collections.abc import Mapping, Sequence
from contextlib import suppress
from dataclasses import asdict, dataclass, field, fields, replace
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from . import defaults
from .compare.settings_columns import (
    CHANNEL_FIELDS,
    _changed_settings,
    _parameters_of,
    analysis_parameters_to_store,
    other_settings_note,
)
from .constants import COUNT_UNIT, RATIO_UNIT
from .errors import (
    ChannelError,
    ParameterError,
    SignalError,
    StoreError,
    a_or_an,
    as_given,
    instance_of,
    listed,
)
from .io import assign_roles, read_measurement
from .records import Channel, Measurement
from .signal import PowerAnalysis, analyze_channels
from .signal.power import PROBABLY_INVERTED, check_analysis_settings
from .signal.validate import SAME_RATE_RELATIVE_TOLERANCE
from .units import given_time_unit, lookup_unit, milli_g, read_unit

if TYPE_CHECKING:
    import pandas as pd

    from .store import Store

__all__ = ["AnalysisOptions", "AnalyzedRecord", "SavedAnalyses", "analyze_file",
           "analyze_measurement", "save_analyses", "store_analysis"]

#: Largest uncertainty, as a phase at the drive frequency, of the start offset between the force
#: and the motion channel: the loss factor moves by the phase error (d eta = d phi near eta = 0),
#: so 1e-4 rad keeps it within the 1.5e-4 absolute of the accuracy target (README). A start
#: time printed with six digits (UFF) misses that from a few ms on at 1 kHz. The same 1e-4 is
#: the budget of the loss factor for the motion channel's and the mass-cancelling
#: acceleration's start offsets together (:func:`_check_start_offset_known`).
MAX_START_OFFSET_PHASE_UNCERTAINTY_RAD = 1e-4
#: An acceleration channel whose drive-line amplitude differs from omega |V| of the velocity
#: channel by more than this factor (either way) is noted as a likely unit slip: a rigid coupon
#: and the shaker head beside it move alike (a fixture resonance may give a factor of 2 or
#: so), while a unit written wrongly gives 9.81 (g as m/s^2), 25.4 (in) or 1000 (mm as m).
UNIT_SLIP_FACTOR = 5.0


@dataclass(frozen=True, kw_only=True)
class AnalysisOptions:
    """User choices for one analysis run (channel mapping and corrections)."""

    force: str | None = None
    velocity: str | None = None
    acceleration: str | None = None
    velocity_delay_s: float = 0.0
    mass_below_gauge_kg: float = 0.0
    baseline_loss_factor: float = 0.0
    structure_mass_kg: float | None = None
    frequency_hz: float | None = None
    n_harmonics: int = defaults.N_HARMONICS
    sample_rate_hz: float | None = None
    allow_clipped: bool = False
    force_unit: str | None = None
    velocity_unit: str | None = None
    acceleration_unit: str | None = None
    invert: tuple[str, ...] = ()
    time_unit: str | None = None

    def __post_init__(self) -> None:
        if isinstance(self.invert, str):
            raise ParameterError(f"invert: expected a sequence of channel names, got "
                                 f"{self.invert!r}")
        object.__setattr__(self, "invert", tuple(self.invert))  # JSON gives back a list
        # refused when made, naming the keyword, not when the first file is analysed (or, for
        # a string, as a TypeError from inside the analysis)
        for name in ("force", "velocity", "acceleration", "force_unit", "velocity_unit",
                     "acceleration_unit", "time_unit"):
            instance_of(name, getattr(self, name), (str, type(None)))
        for name in self.invert:
            instance_of("invert", name, str)
        given_time_unit(self.time_unit)  # a unit of time, refused naming the keyword
        instance_of("allow_clipped", self.allow_clipped, (bool, np.bool_))
        for name in ("velocity_delay_s", "mass_below_gauge_kg", "baseline_loss_factor"):
            # -0 (a sidecar's '-0', --velocity-delay -0) is no correction: saved as -0.0 it
            # made a second record of the same analysis (parameters_json differed) and was
            # shown as 'vibrometer delay -0 µs'
            value = getattr(self, name)
            if isinstance(value, float) and value == 0.0:
                object.__setattr__(self, name, 0.0)
        delay = self.velocity_delay_s
        if isinstance(delay, (int, float)) and not isinstance(delay, bool) and delay < 0:
            # the one rule for a delay a user states (CLI, sidecar, app, script): analyze_power
            # takes a signed delay, as a start offset between the channels corrects either
            # way, but a vibrometer's output only ever lags the motion; -50 µs gave a loss
            # factor shifted by -w tau and saved it
            raise ParameterError(f"velocity_delay_s: {as_given(delay)} s, expected a delay "
                                 ">= 0 s (the vibrometer output lags the motion)")
        if isinstance(self.structure_mass_kg, (int, float)) and self.structure_mass_kg == 0:
            # 0 states no mass, as 0 states no correction in the other columns (the app's
            # settings grid starts every row at 0): the baseline then goes off the whole
            # vibrated mass, noted by the analysis
            object.__setattr__(self, "structure_mass_kg", None)
        check_analysis_settings(
            n_harmonics=self.n_harmonics, mass_below_gauge_kg=self.mass_below_gauge_kg,
            frequency_hz=self.frequency_hz, velocity_delay_s=self.velocity_delay_s,
            baseline_loss_factor=self.baseline_loss_factor, sample_rate_hz=self.sample_rate_hz,
            structure_mass_kg=self.structure_mass_kg)

    def parameters(self) -> dict:
        """JSON-safe parameters stored as provenance."""
        return {k: (list(v) if isinstance(v, tuple) else v) for k, v in asdict(self).items()
                if v is not None and v != ()}


@dataclass(frozen=True)
class AnalyzedRecord:
    """A measurement with its analysis and the channels used. ``measurement`` is the one
    read (what the store keeps under the file's SHA-256); channels inverted by ``invert``
    are inverted for the analysis only, and the inversion is in ``corrections``."""

    measurement: Measurement
    analysis: PowerAnalysis
    channels_used: dict[str, str]
    notes: tuple[str, ...] = field(default_factory=tuple)
    channels: tuple[dict, ...] = field(default_factory=tuple)
    corrections: dict = field(default_factory=dict)
    #: The options it was analysed with (what :func:`save_analyses` saves as its parameters).
    options: AnalysisOptions | None = None

    def to_dict(self) -> dict:
        """JSON-safe record: the analysis, the channels used (role, name, SI unit, unit in the
        file), every note and every correction applied (reader, channel preparation, analysis).
        """
        out = self.analysis.to_dict()
        out["channels"] = [dict(c) for c in self.channels]
        out["notes"] = list(self.notes)
        out["corrections"] = {**out.get("corrections", {}), **self.corrections}
        return out


_UNIT_OPTIONS = {"force": "force_unit", "velocity": "velocity_unit",
                 "acceleration": "acceleration_unit"}
_UNIT_EXAMPLES = {"force": "N, kN, lbf", "velocity": "m/s, mm/s, in/s",
                  "acceleration": "m/s^2, g"}


def _with_unit(ch: Channel, role: str, unit: str | None, source: str,
               notes: list[str], corrections: dict) -> Channel:
    """The channel in SI: its file unit, or ``unit`` (an option) which overrides it."""
    if unit is None and role == "acceleration" and ch.quantity == "unknown" and \
            (thousandth := milli_g(ch.source_unit)) is not None:
        # 'mg' is a milligram in SI (pint's reading), a milli-g on an accelerometer: a
        # channel that is an acceleration by its name or its option can only mean the latter
        notes.append(f"channel {ch.name!r} (acceleration): unit {ch.source_unit!r} read as "
                     f"milli-g ({thousandth.factor:.6g} m/s^2), not the milligram")
        return Channel(ch.name, role, np.asarray(ch.data) * thousandth.factor,
                       ch.sample_rate_hz, ch.source_unit, ch.start_time_s)
    if unit is None:
        if ch.quantity == "unknown":
            problem = read_unit(ch.source_unit).problem
            said = (f"has a unit pidcore refuses: {problem}" if problem else
                    f"has no recognised unit (the file gives {ch.source_unit!r})"
                    if ch.source_unit else "has no recognised unit (the file gives none)")
            raise ChannelError(
                f"{source}: channel {ch.name!r} ({role}) {said}; give it with "
                f"{_UNIT_OPTIONS[role]}=UNIT (e.g. {_UNIT_EXAMPLES[role]})")
        corrected = read_unit(ch.source_unit).correction
        if corrected:
            # the case of a prefix is its meaning: a reading of another case is said
            notes.append(f"channel {ch.name!r}: {corrected}")
        return ch
    reading = read_unit(unit)
    info = reading.info
    thousandth = milli_g(unit) if role == "acceleration" else None
    if thousandth is not None:
        # an acceleration's unit: 'mg' can only be the milli-g here, not the milligram
        info = thousandth
        notes.append(f"{_UNIT_OPTIONS[role]}: {unit!r} read as milli-g "
                     f"({info.factor:.6g} m/s^2), not the milligram")
    elif info is None or info.quantity != role:
        why = f": {reading.problem}" if reading.problem else ""
        raise ParameterError(f"{_UNIT_OPTIONS[role]}={unit!r}: not {a_or_an(role)} unit{why}")
    if reading.corrected:
        notes.append(f"{_UNIT_OPTIONS[role]}: {reading.correction}")
    if ch.quantity != "unknown":
        # the reader scaled the file's numbers to SI by the file's unit, of whatever quantity
        # (a force exported as "m/s"): undo that, then apply the unit the user gives
        old = lookup_unit(ch.source_unit)
        old_factor = old.factor if old is not None and old.quantity == ch.quantity else 1.0
        raw = np.asarray(ch.data) / old_factor
        kind = "" if ch.quantity == role else f", {a_or_an(ch.quantity)} unit"
        notes.append(f"channel {ch.name!r}: the file says {ch.source_unit!r}{kind}; taken as "
                     f"{unit!r} ({_UNIT_OPTIONS[role]})")
    else:
        raw = np.asarray(ch.data)
        notes.append(f"channel {ch.name!r}: no unit in the file; taken as {unit!r} "
                     f"({_UNIT_OPTIONS[role]})")
    corrections[f"{role}_unit"] = unit
    # source_unit stays the file's (what the output calls it); the option's is in the notes
    # and the corrections
    return Channel(ch.name, role, raw * info.factor, ch.sample_rate_hz, ch.source_unit,
                   ch.start_time_s)


def _half_unit(value: float, digits: int | None) -> float:
    """Half a unit in the last of ``digits`` significant digits of ``value`` (0 for an exact
    value: no digits stated, or zero)."""
    if not digits or value == 0 or not math.isfinite(value):
        return 0.0
    return 0.5 * 10.0 ** (math.floor(math.log10(abs(value))) - digits + 1)


def _printed_offset_uncertainty(start: float, force_start: float, digits: int | None) -> float:
    """How far off, s, the offset of a start from the force's may be where the file prints
    both with ``digits`` significant digits: half a unit of each (two starts printed alike
    may lie that far apart)."""
    return _half_unit(start, digits) + _half_unit(force_start, digits)


def _motion_role(channels: Mapping[str, Channel]) -> str:
    """The role of the channel the velocity comes from: the velocity, or without one the
    acceleration it is integrated from."""
    return "velocity" if "velocity" in channels else "acceleration"


def _align(channels: dict[str, Channel], source: str, notes: list[str],
           corrections: dict, start_digits: int | None = None
           ) -> tuple[dict[str, Channel], dict[str, float], dict[str, float]]:
    """Cut the channels to their common time span; returns them, per role other than the
    force the delay (s) that corrects its fractional-sample start offset against the force
    (absent where none is), and how far off that offset may be (s) where the file states its
    start times with ``start_digits`` significant digits."""
    rate = channels["force"].sample_rate_hz
    # equal within the analysis's tolerance, not bit for bit: two time columns printed with 8
    # digits give rates 1e-12 apart, and the start offset between them was then ignored
    if any(abs(ch.sample_rate_hz - rate) > SAME_RATE_RELATIVE_TOLERANCE * rate
           for ch in channels.values()):
        return channels, {}, {}  # refused by the analysis with both rates named
    starts = {r: ch.start_time_s for r, ch in channels.items()}
    lengths = {r: ch.n_samples for r, ch in channels.items()}
    if len(set(starts.values())) == 1 and len(set(lengths.values())) == 1:
        return channels, {}, {}
    force_start = starts["force"]
    # offsets of each channel from the force in samples: integer part cut, fraction corrected
    offsets = {r: (s - force_start) * rate for r, s in starts.items()}
    shift = {r: math.floor(o + 0.5) for r, o in offsets.items()}
    frac = {r: offsets[r] - shift[r] for r in offsets}
    delays: dict[str, float] = {}
    uncertainties: dict[str, float] = {}
    for role, f in frac.items():
        if role == "force":
            continue
        # one start printed as the other is one clock reading: their offset is exact
        uncertainties[role] = (0.0 if starts[role] == force_start else
                               _printed_offset_uncertainty(starts[role], force_start,
                                                           start_digits))
        if abs(f) > 1e-6:
            # sampled f samples after the force's instants: the channel holds x(t + f/rate),
            # a delay of -f/rate in the convention of velocity_delay_s (x(t - tau)). The
            # motion channel (a velocity integrated from a delayed acceleration is delayed
            # alike) and the acceleration mass cancellation takes m a from are corrected by
            # the one rule: ignoring 0.02 samples of the latter's turned m a by 2.5e-3 rad
            # at 1 kHz, 51.2 kHz, and Re(P_c) with it
            delays[role] = -f / rate
    first = max(shift.values())
    last = min(shift[r] + lengths[r] for r in channels)
    if last - first < 8:
        names = listed(c.name for c in channels.values())
        raise ChannelError(f"{source}: the channels {names} do not overlap in time (start times "
                           f"{', '.join(f'{s:.6g} s' for s in starts.values())})")
    out = {}
    for role, ch in channels.items():
        a = first - shift[role]
        out[role] = replace(ch, data=ch.data[a:a + last - first],
                            start_time_s=ch.start_time_s + a / rate)
    span = f"{force_start + first / rate:.6g} s to {force_start + last / rate:.6g} s"
    notes.append("channels aligned on their common time span " + span + " (starts "
                 + ", ".join(f"{ch.name!r} {starts[r]:.6g} s" for r, ch in channels.items())
                 + "; lengths " + ", ".join(str(n) for n in lengths.values()) + ")")
    corrections["aligned_span_s"] = [force_start + first / rate, force_start + last / rate]
    # the analysis carries the delays in its corrections (start_offset_delay_s,
    # acceleration_start_offset_delay_s); each channel's is said in the same words
    notes.extend(f"channel {channels[role].name!r} starts {frac[role]:+.4g} samples off the "
                 f"force's grid: corrected as a delay of {delay:.6g} s"
                 for role, delay in delays.items())
    return out, delays, uncertainties


def _inertia_weight(chosen: Mapping[str, Channel], analysis: PowerAnalysis,
                    mass_below_gauge_kg: float) -> float:
    """How much of a phase error of the mass-cancelling acceleration goes into the loss factor.

    An error d tau of its delay turns m A_1 by w d tau, which moves F_1 by m |A_1| w d tau
    and P_c = 1/2 F conj(V) by half that times |V_1|; all of it goes into Re(P_c) where A_1
    lies along j w V_1, as mass cancellation expects. The loss factor Re/Im moves by that over
    Im(P_c): d eta = w d tau x m |A_1| |V_1| / Im(F_1 conj V_1) = w d tau x m |A_1| / (|F_1|
    cos phi) (phi = atan eta), the phase error weighed by the inertia force's share of the
    force. As for the motion channel (weight 1) the fundamental stands for the record: the
    harmonics' n w d tau turns shares of P_c too small to count."""
    omega = analysis.omega_rad_s
    held = float(np.imag(analysis.force_phasors_n[0] * np.conj(analysis.velocity_phasors_m_s[0])))
    if not held > 0:
        return math.inf  # no stored energy at the drive line for the error to be a share of
    inertia = mass_below_gauge_kg * _drive_amplitude(chosen["acceleration"], omega)
    return inertia * abs(analysis.velocity_phasors_m_s[0]) / held


def _check_start_offset_known(as_started: Mapping[str, Channel], chosen: Mapping[str, Channel],
                              uncertainties_s: Mapping[str, float], digits: int | None,
                              analysis: PowerAnalysis, mass_below_gauge_kg: float,
                              source: str) -> None:
    """Refuse a record whose start offsets against the force the file states too coarsely to
    correct: the motion channel's, whose phase error is the loss factor's, and the
    acceleration's that mass cancellation takes beside a velocity, whose phase error weighs
    in by :func:`_inertia_weight`. The two may add: their sum is held to the one budget."""
    said, total = _start_offset_said(as_started, chosen, uncertainties_s, digits, analysis,
                                     mass_below_gauge_kg)
    if not said:
        return
    raise ChannelError(
        f"{source}: {'; '.join(said)}, up to {total:.2g} off in the loss factor (expected "
        f"within {MAX_START_OFFSET_PHASE_UNCERTAINTY_RAD:g}); export the channels with one "
        "start time (one trigger), or in a format that states it finely (CSV time columns, "
        "MAT, HDF5)")


def _one_start_note(as_started: Mapping[str, Channel], chosen: Mapping[str, Channel],
                    digits: int | None, analysis: PowerAnalysis,
                    mass_below_gauge_kg: float) -> str:
    """Say where channels printed with the force's start are taken as one clock reading
    although that print could hide an offset beyond the budget of
    :func:`_check_start_offset_known` ("" where it could not: a start of 0, or fine digits).

    Channels exported from one acquisition share its trigger and print one start, which is
    exact, and refusing them would refuse every Testlab export of a record that does not
    start at 0; but records of two acquisitions 0.4 ms apart at 100 s print alike in E13.5
    (1.00000e+02) and read a loss factor of 0.31 for 0.05. The assumption is said, with what
    it would cost if it were wrong."""
    force = as_started["force"]
    # two starts printed alike may lie a unit of the last digit apart: the guard's rule
    possible = {role: _printed_offset_uncertainty(ch.start_time_s, force.start_time_s, digits)
                for role, ch in as_started.items()
                if role != "force" and ch.start_time_s == force.start_time_s}
    said, total = _start_offset_said(as_started, chosen, possible, digits, analysis,
                                     mass_below_gauge_kg, printed_alike=True)
    if not said:
        return ""
    return (f"{'; '.join(said)}; taken as one clock reading (one trigger, as one acquisition "
            "exports its channels): had they started apart within that print, the loss factor "
            f"would be up to {total:.2g} off (a start offset must be known to "
            f"{MAX_START_OFFSET_PHASE_UNCERTAINTY_RAD:g}); if they come from different "
            "acquisitions, export them in a format that states the start finely (CSV time "
            "columns, MAT, HDF5)")


def _start_offset_said(as_started: Mapping[str, Channel], chosen: Mapping[str, Channel],
                       uncertainties_s: Mapping[str, float], digits: int | None,
                       analysis: PowerAnalysis, mass_below_gauge_kg: float, *,
                       printed_alike: bool = False) -> tuple[list[str], float]:
    """Per channel, how far off its start offset against the force may be and what phase
    that is, and the loss factor's uncertainty from them all; ``([], total)`` where that is
    within :data:`MAX_START_OFFSET_PHASE_UNCERTAINTY_RAD`. ``printed_alike``: the starts
    print as the force's (:func:`_one_start_note`)."""
    motion = _motion_role(chosen)
    weights = {motion: 1.0}
    if (motion == "velocity" and "acceleration" in chosen and mass_below_gauge_kg > 0
            and uncertainties_s.get("acceleration")):
        weights["acceleration"] = _inertia_weight(chosen, analysis, mass_below_gauge_kg)
    omega = analysis.omega_rad_s
    total = sum(weight * omega * uncertainties_s.get(role, 0.0)
                for role, weight in weights.items())
    if not total > MAX_START_OFFSET_PHASE_UNCERTAINTY_RAD:
        return [], total
    force = as_started["force"]
    rate = force.sample_rate_hz
    said = []
    for role, weight in weights.items():
        uncertainty_s = uncertainties_s.get(role, 0.0)
        if not uncertainty_s:
            continue
        ch = as_started[role]
        phase = omega * uncertainty_s
        start = (f"channel {ch.name!r} states the start of channel {force.name!r}, "
                 f"{ch.start_time_s:.6g} s, to {digits} significant digits, a print that "
                 f"holds starts ±{uncertainty_s * rate:.2g} samples apart" if printed_alike else
                 f"channel {ch.name!r} starts "
                 f"{(ch.start_time_s - force.start_time_s) * rate:+.4f} samples from channel "
                 f"{force.name!r} by the start times the file states with {digits} "
                 f"significant digits, known to ±{uncertainty_s * rate:.2g} samples only")
        said.append(f"{start}: {phase:.2g} rad at {analysis.frequency_hz:.6g} Hz"
                    + ("" if role == motion else
                       f" on the inertia force m a it cancels, weighed by m|A|/(|F| cos phi) "
                       f"= {weight:.2g}"))
    return said, total


def _invert(measurement: Measurement, names: Sequence[str], notes: list[str]) -> Measurement:
    if not names:
        return measurement
    known = {c.name for c in measurement.channels}
    for name in names:
        if name not in known:
            raise ChannelError(f"{measurement.source}: invert={name!r}: no such channel; "
                               f"channels are {listed(known)}")
    channels = tuple(replace(c, data=-np.asarray(c.data)) if c.name in names else c
                     for c in measurement.channels)
    notes.extend(f"channel {n!r} inverted (invert={n!r})" for n in names)
    return replace(measurement, channels=channels)


def _drive_amplitude(channel: Channel, omega_rad_s: float) -> float:
    """Amplitude of ``channel`` at the drive line: least-squares cosine, sine and offset."""
    data = np.asarray(channel.data, dtype=np.float64)
    # normal equations accumulated in blocks: no N x 3 basis for a 5 M-sample record
    normal, rhs = np.zeros((3, 3)), np.zeros(3)
    for start in range(0, data.size, 1 << 16):
        t = np.arange(start, min(start + (1 << 16), data.size)) / channel.sample_rate_hz
        basis = np.stack([np.cos(omega_rad_s * t), np.sin(omega_rad_s * t), np.ones_like(t)])
        normal += basis @ basis.T
        rhs += basis @ data[start:start + t.size]
    coef = np.linalg.lstsq(normal, rhs, rcond=None)[0]
    return float(np.hypot(coef[0], coef[1]))


def _unit_slip_notes(measurement: Measurement, chosen: Mapping[str, Channel],
                     analysis: PowerAnalysis, *, mass_below_gauge_kg: float = 0.0) -> list[str]:
    """A note per acceleration channel (used or ignored) whose drive-line amplitude is more
    than :data:`UNIT_SLIP_FACTOR` times off omega |V| of the velocity channel used: one of the
    two units is likely wrong. A velocity exported in mm/s but labelled m/s changes neither the
    loss factor nor the SDC (force and velocity scale Re and Im of P_c alike), so nothing else
    shows it; the acceleration amplitude and the energy per cycle come out 1000 times off.
    omega |V| is the analysis' own (its fundamental velocity phasor), not fitted again.

    The acceleration that cancels ``mass_below_gauge_kg`` is refused instead: its unit does
    change the loss factor (g written as m/s^2 cancelled a tenth of the mass, 0.0174 for 0.02
    with 50 g below the gauge of a 0.3 kg coupon), and which of the two units is wrong
    cannot be told."""
    velocity = chosen.get("velocity")
    if velocity is None or velocity.data.size < 8:
        return []
    accelerations = [c for c in measurement.channels if c.quantity == "acceleration"
                     and c.name not in (velocity.name, chosen["force"].name)
                     and c.data.size >= 8]
    if "acceleration" in chosen:
        accelerations = [chosen["acceleration"]] + [c for c in accelerations
                                                     if c.name != chosen["acceleration"].name]
    expected = analysis.acceleration_amplitude_m_s2
    notes = []
    for acc in accelerations:
        amplitude = _drive_amplitude(acc, analysis.omega_rad_s)
        if not (expected > 0 and amplitude > 0):
            continue
        ratio = amplitude / expected
        if 1.0 / UNIT_SLIP_FACTOR <= ratio <= UNIT_SLIP_FACTOR:
            continue
        if mass_below_gauge_kg > 0 and acc is chosen.get("acceleration"):
            raise ChannelError(
                f"{measurement.source}: channel {acc.name!r} ({acc.source_unit or 'no unit'}) "
                f"has {ratio:.4g} x the acceleration of channel {velocity.name!r} "
                f"({velocity.source_unit or 'no unit'}) at the drive line ({amplitude:.4g} "
                f"against omega |V| = {expected:.4g} m/s^2), expected within a factor "
                f"{UNIT_SLIP_FACTOR:g}: a unit slip in one of them, and the mass below the "
                "gauge would be cancelled with the wrong acceleration; check both units "
                "(velocity_unit, acceleration_unit)")
        notes.append(
            f"channel {acc.name!r} ({acc.source_unit or 'no unit'}) has {ratio:.4g} x the "
            f"acceleration of channel {velocity.name!r} ({velocity.source_unit or 'no unit'}) "
            f"at the drive line ({amplitude:.4g} against omega |V| = {expected:.4g} m/s^2): "
            "a unit slip in one of them (mm/s written as m/s, g as m/s^2)? The velocity is "
            "used as its unit says; check both units (velocity_unit, "
            "acceleration_unit)")
    return notes


def analyze_measurement(measurement: Measurement, options: AnalysisOptions | None = None
                        ) -> AnalyzedRecord:
    """Map channels to roles, prepare them and run the Eq. 11 analysis on one measurement.

    ``options``: channels, corrections and analysis settings; ``AnalysisOptions()`` (the
    CLI's defaults) when not given.

    Preparation, each step announced in the notes: channels inverted on request
    (``invert``), units given by option for channels without one (a channel of unknown unit is
    never taken as SI), channels cut to their common time span when their start times or
    lengths differ (a fractional-sample start offset of the velocity, of the acceleration a
    velocity is integrated from, or of the acceleration mass cancellation takes beside a
    velocity, is corrected as a delay of that channel),
    channels no role needs named as ignored.
    """
    options = AnalysisOptions() if options is None else options
    instance_of("options", options, AnalysisOptions,
                hint="e.g. AnalysisOptions(velocity_delay_s=5e-5)")
    notes: list[str] = list(measurement.metadata.get("reader_notes", ()) or ())
    corrections: dict = {}
    as_read = measurement  # what is stored: the file's channels, the inversion a parameter
    measurement = _invert(measurement, options.invert, notes)
    if options.invert:
        corrections["inverted_channels"] = list(options.invert)
    units = {"force": options.force_unit, "velocity": options.velocity_unit,
             "acceleration": options.acceleration_unit}
    roles = assign_roles(measurement, force=options.force, velocity=options.velocity,
                         acceleration=options.acceleration,
                         mass_cancellation=options.mass_below_gauge_kg > 0,
                         retyped={role for role, unit in units.items() if unit is not None})
    notes.extend(roles.notes)
    chosen = {role: _with_unit(ch, role, units[role], measurement.source, notes, corrections)
              for role, ch in (("force", roles.force), ("velocity", roles.velocity),
                               ("acceleration", roles.acceleration)) if ch is not None}
    for role, unit in units.items():
        if unit is not None and role not in chosen:
            raise ParameterError(f"{_UNIT_OPTIONS[role]}={unit!r}: {measurement.source} has no "
                                 f"{role} channel in use")
    as_started = chosen  # the channels' own start times, for a refusal to name
    start_digits = measurement.metadata.get("start_time_significant_digits")
    chosen, start_delays, start_uncertainties_s = _align(chosen, measurement.source, notes,
                                                         corrections, start_digits)
    motion = _motion_role(chosen)
    if roles.ignored:
        notes.append("ignored channels (not needed): "
                     + listed(roles.ignored))
        corrections["ignored_channels"] = list(roles.ignored)
    try:
        analysis = analyze_channels(
            chosen["force"], chosen.get("velocity"), acceleration=chosen.get("acceleration"),
            source=measurement.source,
            velocity_delay_s=options.velocity_delay_s,
            start_offset_delay_s=start_delays.get(motion, 0.0),
            acceleration_start_offset_delay_s=(start_delays.get("acceleration", 0.0)
                                               if motion == "velocity" else 0.0),
            mass_below_gauge_kg=options.mass_below_gauge_kg,
            baseline_loss_factor=options.baseline_loss_factor,
            structure_mass_kg=options.structure_mass_kg,
            frequency_hz=options.frequency_hz,
            n_harmonics=options.n_harmonics,
            allow_clipped=options.allow_clipped,
        )
    except SignalError as exc:
        # "one of the channels is probably inverted: ... pass invert=NAME" read as if none
        # was, where the inversion asked for is the likely slip (a channel inverted twice)
        if options.invert and PROBABLY_INVERTED in str(exc):
            raise SignalError(f"{exc} (inverted on request already: "
                              + ", ".join(f"invert={n!r}" for n in options.invert)
                              + "; is that one right?)") from None
        raise
    _check_start_offset_known(as_started, chosen, start_uncertainties_s, start_digits,
                              analysis, options.mass_below_gauge_kg, measurement.source)
    one_start = _one_start_note(as_started, chosen, start_digits, analysis,
                                options.mass_below_gauge_kg)
    if one_start:
        notes.append(one_start)
    notes.extend(_unit_slip_notes(measurement, chosen, analysis,
                                  mass_below_gauge_kg=options.mass_below_gauge_kg))
    if options.structure_mass_kg is not None and not options.baseline_loss_factor > 0:
        # the mass only says how much of the reactive power the baseline applies to: given
        # alone it changes nothing, which a user who set it believing the structure's damping
        # taken off must be told
        notes.append(f"structure mass {options.structure_mass_kg:.4g} kg given without a "
                     "baseline loss factor: nothing subtracted (give the empty structure's "
                     "loss factor too: baseline_loss_factor, or a baseline_loss_factor column of "
                     "the settings table)")
    used = {role: ch.name for role, ch in chosen.items()}
    detail = tuple({"role": role, "name": ch.name, "unit": ch.unit,
                    "source_unit": ch.source_unit} for role, ch in chosen.items())
    return AnalyzedRecord(as_read, analysis, used, tuple(notes) + analysis.notes,
                          detail, corrections, options)


def analyze_file(path: str | os.PathLike, options: AnalysisOptions | None = None, *,
                 key: str | None = None) -> AnalyzedRecord:
    """Read one export file and analyse it (:func:`analyze_measurement`; ``options`` default
    ``AnalysisOptions()``); ``key`` picks a measurement of a pidcore store
    (:func:`pidcore.io.read_measurement`)."""
    options = AnalysisOptions() if options is None else options
    instance_of("options", options, AnalysisOptions,
                hint="e.g. AnalysisOptions(velocity_delay_s=5e-5)")
    measurement = read_measurement(Path(path), sample_rate_hz=options.sample_rate_hz, key=key,
                                   time_unit=options.time_unit)
    return analyze_measurement(measurement, options)


def store_analysis(store: Store, result: AnalyzedRecord, parameters: Mapping, *,
                   fields: Mapping | None = None) -> str:
    """Add one analysed record and its measurement to an open :class:`~pidcore.store.Store`.

    The analysis is keyed by its measurement and ``parameters`` (plus the channels used), so
    the same file analysed with the same options replaces its entry. ``fields`` adds record
    fields (the load case, :meth:`pidcore.compare.LoadCase.as_record`). Returns the key.
    """
    from .compare.plausibility import RECORDED_BOUND_UNITS

    measurement_key, _ = store.add_measurement(result.measurement)
    record = {**analysis_record(result), **(fields or {})}
    arrays = analysis_arrays(result.analysis)
    # the SDC bound a record was judged with (fields, SdcBound.as_record) keeps its units
    units = {**ANALYSIS_UNITS, **RECORDED_BOUND_UNITS}
    return store.add_analysis(
        measurement_key, record, arrays=arrays,
        parameters=analysis_parameters_to_store(result, parameters),
        units={k: v for k, v in units.items() if k in record or k in arrays})


#: How a saved analysis without a load case is named in notes.
NO_LOAD_CASE = "no load case"


@dataclass(frozen=True)
class SavedAnalyses:
    """What :func:`save_analyses` wrote: the analysis ``keys`` (one per result; byte-identical
    files share one), ``notes`` naming each saved record it replaced, and of the distinct keys
    those the store ``already_identical`` held before with the same content (every field but
    its creation time: the same file saved again with the same settings and load case) and
    those it held with other content (``replaced``: another name, load case or specimen, or
    a record an older pidcore saved without a field saved now)."""

    keys: list[str]
    notes: list[str]
    already_identical: list[str] = field(default_factory=list)
    replaced: list[str] = field(default_factory=list)
    #: Of the distinct keys held before with the same content, those another analysis of the
    #: same measurement (other settings) had replaced as the one reports and calibrations use:
    #: saved again, they are that one again (not in :attr:`already_identical`).
    made_used_again: list[str] = field(default_factory=list)

    @property
    def new(self) -> list[str]:
        """The distinct keys the store did not hold before."""
        held = {*self.already_identical, *self.replaced, *self.made_used_again}
        return [key for key in dict.fromkeys(self.keys) if key not in held]

    def breakdown(self) -> str:
        """How many records were new and how many the store already held (``"0 new, 5
        already held with identical content"``); ``""`` where all were new. "saved 5" of a
        save done twice did not say the second one changed nothing. A held record another
        analysis of its file had replaced is counted apart (``"1 already held, made the one
        reports use again"``): "already held with identical content" beside the note that the
        save changed which analysis reports use read as "nothing changed"."""
        if not self.already_identical and not self.replaced and not self.made_used_again:
            return ""
        parts = [f"{len(self.new)} new"]
        if self.already_identical:
            parts.append(f"{len(self.already_identical)} already held with identical content")
        if self.made_used_again:
            parts.append(f"{len(self.made_used_again)} already held, made the one reports "
                         "and calibrations use again")
        if self.replaced:
            # "of other content" beside the note "has the same contents" read as a
            # contradiction: the file is the same, its name, load case, specimen or a field
            # an older pidcore did not save (the SDC bound judged with) is not
            parts.append(f"{len(self.replaced)} replacing the held record of the same file "
                         "under another name, load case or specimen, or one saved without "
                         "a field saved now")
        return ", ".join(parts)


def save_analyses(store: Store | str | os.PathLike, results: Sequence[AnalyzedRecord],
                  options: AnalysisOptions | Sequence[AnalysisOptions] | None = None,
                  stated: Sequence[tuple[str, object, str]] | None = None, *,
                  fields: Sequence[Mapping | None] | None = None) -> SavedAnalyses:
    """Save measurements and their analyses in one transaction of ``store`` (a
    :class:`~pidcore.store.Store` or its path).

    ``options``: per result, the options it was analysed with (their parameters are its
    record's, so that each record says how it was made: files of one call may have different
    settings, :mod:`pidcore.file_settings`); one :class:`AnalysisOptions` stands for all;
    None (default): each result's own (:attr:`AnalyzedRecord.options`). Options whose
    analysis settings differ from those a result was analysed with are refused: the record
    would say it was made otherwise than it was (the channel names may differ: the record
    keeps the channels used).
    ``stated``: per result, (file name, its :class:`~pidcore.loadcase.LoadCase` or None, who
    stated it); the load case goes into the record (:meth:`~pidcore.loadcase.LoadCase.as_record`);
    default: each file's name and no load case.
    ``fields``: per result, further record fields or None (the ``specimen`` a sidecar names,
    the SDC bound it was judged with: :meth:`pidcore.compare.plausibility.SdcBound.as_record`).
    A saved record of the same bytes under another name or load case is replaced, and the
    notes say so (:func:`replacement_notes`).
    """
    from .records import measurement_key
    from .store import Store

    results = _analyzed_records(results)
    if options is None:
        missing = [r.measurement.source for r in results if r.options is None]
        if missing:
            raise ParameterError(f"options: {', '.join(missing)} carry no analysis options; "
                                 "give the options they were analysed with")
        per_result = [r.options for r in results]
    else:
        per_result = ([options] * len(results) if isinstance(options, AnalysisOptions)
                      else list(options))
        for i, given in enumerate(per_result):
            instance_of(f"options[{i}]", given, AnalysisOptions)
    if stated is None:
        stated = [(Path(r.measurement.source).name, None, "") for r in results]
    extra = list(fields) if fields is not None else [None] * len(results)
    for name, given in (("options", per_result), ("stated", stated), ("fields", extra)):
        if len(given) != len(results):
            raise ParameterError(f"{name}: expected one per result ({len(results)}), got "
                                 f"{len(given)}")
    for r, given in zip(results, per_result, strict=True):
        _refuse_other_settings(r, given)
    from .dem.simulate import particles_of_stated_fill
    from .loadcase import LoadCase

    for (name, case, _), more in zip(stated, extra, strict=True):
        # as `pidcore analyze` refuses it: a script saved a 0.5 % load case (50 % typed as a
        # fraction) that no DEM run can match. A record naming its specimen is of another
        # cell, which only the caller knows
        if isinstance(case, LoadCase) and not (more or {}).get("specimen"):
            particles_of_stated_fill(case.fill_percent, case.material,
                                     what=f"{name}: fill_percent")
    store = store if isinstance(store, Store) else Store(store)
    _refuse_the_store_itself(store, results)
    with store.transaction():
        before = store.list_analyses()
        notes = replacement_notes(before, [
            (name, measurement_key(r.measurement),
             case.full_label() if case is not None else NO_LOAD_CASE,
             analysis_parameters_to_store(r, o.parameters()), r.analysis.sdc)
            for r, o, (name, case, _) in zip(results, per_result, stated, strict=True)])
        keys = [store_analysis(store, r, o.parameters(), fields={
                    **(case.as_record(origin) if case is not None else {}), **(more or {})})
                for r, o, (_, case, origin), more in zip(results, per_result, stated, extra,
                                                         strict=True)]
        held = set(before["key"]) & set(keys) if "key" in before.columns else set()
        identical = _identical_entries(before, store.list_analyses(), held) if held else set()
    distinct = list(dict.fromkeys(keys))
    superseded = _superseded(before)
    return SavedAnalyses(keys, notes,
                         [k for k in distinct if k in identical and k not in superseded],
                         [k for k in distinct if k in held - identical],
                         [k for k in distinct if k in identical and k in superseded])


def _newest_first(analyses: pd.DataFrame) -> pd.DataFrame:
    """A listing of :meth:`~pidcore.store.Store.list_analyses` newest first: of one
    measurement's analyses the first is the one reports and calibrations use (empty where it
    lacks the columns that tell)."""
    if analyses.empty or not {"key", "measurement_key", "created_utc"} <= set(
            analyses.columns):
        return analyses.iloc[0:0]
    # stable: of equal stamps the one listed last was saved last
    return analyses.iloc[::-1].sort_values("created_utc", kind="stable", ascending=False)


def _superseded(analyses: pd.DataFrame) -> set[str]:
    """Keys of a listing's analyses that another analysis of the same measurement replaced
    as the one reports and calibrations use (not the newest of their measurement)."""
    newest = _newest_first(analyses)
    used = set(newest.drop_duplicates("measurement_key")["key"].astype(str))
    return set(newest["key"].astype(str)) - used


def _identical_entries(before: pd.DataFrame, after: pd.DataFrame, keys: set[str]) -> set[str]:
    """Of ``keys``, those whose listed entry (every field but ``created_utc``, which a save
    always renews) is the same in both listings of :meth:`~pidcore.store.Store.list_analyses`."""
    def rows(listing: pd.DataFrame) -> dict[str, dict]:
        return {str(row["key"]): {k: v for k, v in row.items() if k != "created_utc"}
                for row in listing[listing["key"].isin(keys)].to_dict("records")}

    old, new = rows(before), rows(after)
    return {key for key in keys if key in new and _same_fields(old.get(key, {}), new[key])}


def _same_fields(first: Mapping, second: Mapping) -> bool:
    """Equal field by field, a missing field and NaN both read as the listing's empty value
    (NaN == NaN here: an unknown standard error saved again is the same unknown)."""
    def empty(value: object) -> bool:
        return value is None or (isinstance(value, float) and math.isnan(value))

    for name in {*first, *second}:
        a, b = first.get(name), second.get(name)
        if empty(a) and empty(b):
            continue
        if empty(a) or empty(b) or a != b:
            return False
    return True


def _analyzed_records(results: object) -> list[AnalyzedRecord]:
    """``results`` as a list of :class:`AnalyzedRecord`, else a ParameterError naming it: one
    record given alone, the arguments swapped or a measurement failed inside with
    AttributeError/TypeError."""
    hint = "e.g. [analyze_file(path)]"
    if isinstance(results, (AnalyzedRecord, str, bytes, os.PathLike)) or not isinstance(
            results, Sequence):
        instance_of("results", results, list, hint=hint)
    for i, r in enumerate(results):
        instance_of(f"results[{i}]", r, AnalyzedRecord, hint=hint)
    return list(results)


def _refuse_other_settings(result: AnalyzedRecord, given: AnalysisOptions) -> None:
    """Refuse to save ``result`` with options whose analysis settings differ from those it
    was analysed with: its record would say a delay, mass or baseline it was not made with
    (a script passing ``AnalysisOptions()`` for files analysed with a 50 µs delay)."""
    instance_of("options", given, AnalysisOptions)
    used = result.options
    if used is None:
        return  # a record made by hand: its options are the caller's word
    differ = [f"{name} {getattr(given, name)!r} (analysed with {getattr(used, name)!r})"
              for name in (f.name for f in fields(AnalysisOptions))
              if name not in CHANNEL_FIELDS and getattr(given, name) != getattr(used, name)]
    if differ:
        raise ParameterError(f"options: {result.measurement.source} would be saved with "
                             f"{'; '.join(differ)}; give the options it was analysed with, or "
                             "none (its own)")


def refuse_store_among_inputs(store, paths: Sequence[str | os.PathLike]) -> None:
    """Refuse ``paths`` that are the file of ``store`` (a :class:`~pidcore.store.Store` or
    path), which the analyses are to be saved to, before anything is read.

    A measurement read from the store file itself holds that file's hash, not its original
    file's: saved, it would be a copy of a stored measurement under a new key, and one more
    each time (the store's hash changes with every save). Checked before reading, so that
    ``pidcore analyze *`` in a folder holding its ``pid_store.h5`` is told so, not asked to
    choose one of the store's measurements with ``--key`` (which this refusal then met)."""
    from .store import Store

    store_path = store.path if isinstance(store, Store) else Path(store)
    for path in paths:
        source = Path(path)
        with suppress(OSError):
            if store_path.exists() and source.is_file() and os.path.samefile(source,
                                                                              store_path):
                raise StoreError(f"{path}: is the store being saved to; its "
                                 "measurements are stored in it already: analyse it without "
                                 "saving, or save to another store")


def _refuse_the_store_itself(store, results: Sequence[AnalyzedRecord]) -> None:
    """:func:`refuse_store_among_inputs` of the results' sources (a library caller that
    analysed the store file itself)."""
    refuse_store_among_inputs(store, [r.measurement.source for r in results])


def _stored_case_label(row) -> str:
    from .compare.align import _row_case

    try:
        case = _row_case(row)
    except (KeyError, TypeError, ValueError):
        return NO_LOAD_CASE
    return case.full_label()


def replacement_notes(analyses: pd.DataFrame,
                      incoming: Sequence[tuple[str, str, str, Mapping, float]]) -> list[str]:
    """Which saved records (file name, load case, settings) saving ``incoming`` replaces.

    ``incoming``: per file to be saved, (file name, measurement key
    (:func:`pidcore.records.measurement_key`), load case in words, the parameters it is
    stored with (:func:`~pidcore.compare.settings_columns.analysis_parameters_to_store`), the
    new SDC). The store
    keeps a measurement by its contents, so a byte-identical file under another name, or a
    second copy in the same save, is the same record and only the last one saved is kept:
    each such replacement of another name or load case is said, never silent. A file saved
    again with other settings (another vibrometer delay, mass below the gauge, baseline) is
    a new analysis of the same measurement, and the newest is the one reports and
    calibrations use: that too is said, with the settings that differ and both SDCs (a
    forgotten settings table silently replaced a delay-corrected result). ``analyses`` is
    :meth:`pidcore.store.Store.list_analyses` before the save.
    """
    notes = []
    saved = {}  # measurement key -> (file, load case, parameters, SDC) it holds now
    # measurement key -> (parameters, SDC) of each analysis of it, newest first
    kept: dict[str, list[tuple[dict | None, float]]] = {}
    if not analyses.empty and {"measurement_key", "created_utc"} <= set(analyses.columns):
        for _, row in analyses.sort_values("created_utc", kind="stable").iterrows():
            saved[str(row["measurement_key"])] = (
                Path(str(row.get("source", ""))).name, _stored_case_label(row),
                _parameters_of(row.get("parameters_json")), _number(row.get("sdc")))
            kept.setdefault(str(row["measurement_key"]), []).insert(
                0, (_parameters_of(row.get("parameters_json")), _number(row.get("sdc"))))
    for name, key, case, given, sdc in incoming:
        parameters = _parameters_of(given)
        if key in saved:
            old_name, old_case, old_parameters, old_sdc = saved[key]
            changed = _changed_settings(old_parameters, parameters)
            if (old_name, old_case) != (name, case):
                notes.append(f"{name} has the same contents as the saved record {old_name} "
                             f"({old_case}); saved as one record: {name} ({case}) replaces it"
                             + (f" (other settings: {changed})" if changed else ""))
            elif changed:
                notes.append(other_settings_note(name, old_parameters, parameters, old_sdc,
                                                 sdc))
            else:
                # saved again as it is used: a second Save said only "already held", and the
                # note of the first (which SDC reports use) was gone from the page
                earlier = next(((p, s) for p, s in kept.get(key, ())
                                if _changed_settings(p, parameters)), None)
                if earlier is not None:
                    notes.append(other_settings_note(
                        name, earlier[0], parameters, earlier[1], sdc,
                        now="still the one reports and calibrations use, the earlier is kept "
                            "in the store"))
        saved[key] = (name, case, parameters, sdc)
    return notes


def _number(value: object) -> float:
    try:
        return float(value)
    except (TypeError, ValueError):
        return math.nan


#: Units of the scalar fields stored per analysis.
ANALYSIS_UNITS = {
    "frequency_hz": "Hz", "acceleration_g": "g", "acceleration_m_s2": "m/s^2",
    "complex_power_real_w": "W", "complex_power_imag_w": "W", "loss_factor": RATIO_UNIT,
    "loss_factor_stderr": RATIO_UNIT, "sdc": RATIO_UNIT, "sdc_stderr": RATIO_UNIT,
    "damping_ratio": RATIO_UNIT, "energy_per_cycle_j": "J", "max_kinetic_energy_j": "J",
    "force_amplitude_n": "N", "velocity_amplitude_m_s": "m/s", "displacement_amplitude_m": "m",
    "n_periods": COUNT_UNIT, "sdc_stderr_dof": COUNT_UNIT, "fill_percent": "%",
    # arrays (analysis_arrays): harmonic numbers and the phasors x(t) = Re(X e^{j n w t})
    "harmonics": COUNT_UNIT, "force_phasors_n": "N", "velocity_phasors_m_s": "m/s",
}


def analysis_record(r: AnalyzedRecord) -> dict:
    """Flat scalar record of one analysis, as stored."""
    a = r.analysis
    # an undefined damping ratio (SDC >= 1, or no positive loss factor) is stored as the
    # store's null (None), with the note saying why, not as NaN. A standard error that cannot
    # be had stays NaN, the "unknown" every reader of sdc_stderr pools by, with its note.
    notes = {}
    if a.damping_ratio is None:
        notes["damping_ratio_note"] = a.damping_ratio_note
    if not (math.isfinite(a.sdc_stderr) and math.isfinite(a.loss_factor_stderr)):
        notes["uncertainty_note"] = a.uncertainty_note
    if math.isfinite(a.sdc_stderr_dof):
        # n_blocks - 1: a 95 % band of sdc_stderr takes Student's t quantile with them; left
        # out (not NaN) where there is no standard error, as in a record of an older pidcore
        notes["sdc_stderr_dof"] = a.sdc_stderr_dof
    record = {
        "frequency_hz": a.frequency_hz,
        "acceleration_g": a.acceleration_g,
        "acceleration_m_s2": a.acceleration_amplitude_m_s2,
        "complex_power_real_w": a.complex_power_w.real,
        "complex_power_imag_w": a.complex_power_w.imag,
        "loss_factor": a.loss_factor,
        "loss_factor_stderr": a.loss_factor_stderr,
        "sdc": a.sdc,
        "sdc_stderr": a.sdc_stderr,
        "damping_ratio": a.damping_ratio,
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
    return record | notes


def analysis_arrays(a: PowerAnalysis) -> dict:
    return {
        "harmonics": a.harmonics,
        "force_phasors_n": a.force_phasors_n,
        "velocity_phasors_m_s": a.velocity_phasors_m_s,
    }
