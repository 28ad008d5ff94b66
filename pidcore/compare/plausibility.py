"""Plausibility of an Eq. 11 result: the numbers a wrong set-up produces, named with their cause.

A wrong vibrometer delay, an inverted channel or a mass correction larger than the mass give
numbers that look ordinary in a table (a loss factor of -0.24, an SDC of 19.5). These checks
read only the analysis (:class:`pidcore.signal.PowerAnalysis`) and return warnings with the
likely cause; the app shows them on the file's card and asks for confirmation before saving.

The fundamental's complex power ``P = F V* / 2`` of a coupon shaken well below its first
resonance is mostly reactive and inertial: ``Im P > 0`` (force leads velocity by about 90°)
and a small positive ``Re P`` (the damping). So:

* ``Re P < 0`` (negative loss factor) is energy *delivered* by the coupon: impossible for a
  passive damper. A velocity delayed by ``tau`` turns the phase by ``-w tau``; the delay that
  would make the loss factor zero is reported.
* ``Im P < 0`` is a force lagging the velocity: a spring, or a channel of inverted sign.
* An SDC above the bound of :func:`sdc_bound` dissipates more per cycle than the particles
  can. Where the specimen and its fill are known, the bound is that of the particles' impacts,
  ``max(2 pi, 8 m_p / m_s)``; else :data:`SDC_UPPER_BOUND` (2 pi, a loss factor of 1). Table 3's
  largest SDC is 0.88.

The particle-impact bound. With ``P = F V* / 2`` the loss factor is ``eta = Re P / Im P`` and
``SDC = 2 pi eta`` (:mod:`pidcore.signal.power`). ``Re P = D / T = D omega / (2 pi)`` for an
energy ``D`` dissipated per cycle. The structure that moves rigidly with the drive (coupon and
fixture, ``m_s``, without the particles, which may decouple from it) gives
``Im P >= omega m_s |V|^2 / 2`` wherever the particles' own reactive part is not negative: they
add inertia while they ride with the walls and little while they fly. (A bed moving against
the walls makes it slightly negative: -2 g beside the 55 g below in pidcore's DEM at 200 Hz,
20 g; the margin of the dissipation bound covers it.) Particles of total mass ``m_p`` in cells
driven at velocity amplitude ``V`` lose at most about two fully inelastic impacts per cycle at
the largest relative speed ``2 V``: ``D <= 2 x m_p (2 V)^2 / 2 = 4 m_p V^2``. Hence
``eta = D / (pi m_s V^2) <= 4 m_p / (pi m_s)`` and ``SDC <= 8 m_p / m_s``. A linear check: a
mass ``m_p`` on a dashpot ``c`` to the base absorbs ``Re P = omega m_p V^2 / 4`` at most (at
``c = omega m_p``), an SDC below ``pi m_p / m_s``, below the impact bound. It is the bound of a
perfect damper, not a prediction: a user's panel of 263 g of 2 mm steel spheres on a 40 g
coupon and a 15 g fixture, whose bound is 38.3, gave an Eq. 11 SDC of 8.4 in pidcore's DEM
virtual shaker (12.9 at 50 Hz, 10 g on 2 cells), above 2 pi; its dissipation per cycle was at
most 0.4 x 4 m_p V^2 (tests/test_sdc_bound.py).
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:  # pragma: no cover
    from ..specimen import Specimen

#: SDC above which a result is implausible where the specimen or its fill is not known, and the
#: least bound where they are (:func:`sdc_bound`): 2*pi, a loss factor of 1 (the energy
#: dissipated per radian equals the peak stored energy). Table 3's largest SDC is 0.88 (DEM) and
#: 0.71 (measured), so this bound only catches gross set-up errors.
SDC_UPPER_BOUND = 2 * math.pi
#: Column of an SDC bound (:func:`sdc_bound`) in every table: the app's Calibrate page and
#: :meth:`pidcore.calibrate.Calibration.to_pandas` (which said "sdc bound [-]" before 2026-12).
SDC_BOUND_COLUMN = "SDC bound [-]"

#: Fully inelastic impacts per drive cycle at twice the drive velocity that bound what the
#: particles dissipate (module docstring): ``SDC <= PARTICLE_IMPACT_SDC_FACTOR m_p / m_s``.
PARTICLE_IMPACT_SDC_FACTOR = 8.0


def particle_impact_sdc(particle_mass_kg: float, structure_mass_kg: float) -> float:
    """Largest SDC particles of ``particle_mass_kg`` in cells of a structure of
    ``structure_mass_kg`` (coupon and fixture, without the particles) can give:
    ``8 m_p / m_s`` (two fully inelastic impacts per cycle at twice the drive velocity; the
    module docstring derives it)."""
    return PARTICLE_IMPACT_SDC_FACTOR * particle_mass_kg / structure_mass_kg


@dataclass(frozen=True)
class SdcBound:
    """The SDC above which a result is implausible, and what it comes from.

    Attributes
    ----------
    sdc : float
        The bound: ``max(2 pi, 8 m_p / m_s)``, or 2 pi where the masses are not known.
    particle_mass_kg, structure_mass_kg : float
        ``m_p`` (particles per cell x cells x one particle's mass) and ``m_s`` (coupon plus
        fixture), kg; NaN where the specimen or its fill is not known.
    """

    sdc: float = SDC_UPPER_BOUND
    particle_mass_kg: float = math.nan
    structure_mass_kg: float = math.nan
    #: where it was read from: "" (a specimen file at hand, or 2 pi), or a stored record's
    #: words for it (:func:`recorded_sdc_bound`); not part of the bound's value, so that the
    #: bound stored with a record equals its file's
    origin: str = field(default="", compare=False)
    #: the particles of every cell full (kg) where the fill is not known but the specimen is:
    #: the most a unit slip is judged against (a force in N under "kN" of a file stating no
    #: fill showed a 50 kg vibrated mass on a 22 g coupon, and was saved); NaN otherwise
    full_particle_mass_kg: float = field(default=math.nan, compare=False)

    @property
    def known(self) -> bool:
        """Whether the bound comes from the specimen's masses."""
        return math.isfinite(self.particle_mass_kg) and math.isfinite(self.structure_mass_kg)

    def basis(self) -> str:
        """Where the bound comes from, in words (empty for the plain 2 pi)."""
        if not self.known:
            return ""
        impact = particle_impact_sdc(self.particle_mass_kg, self.structure_mass_kg)
        return (f"particles of {self.particle_mass_kg * 1e3:.3g} g on a "
                f"{self.structure_mass_kg * 1e3:.3g} g structure can dissipate at most "
                f"SDC 8 m_p/m_s = {impact:.3g}, two fully inelastic impacts per cycle")

    def words(self, loss_factor: float) -> str:
        """``'the physical bound 38.3 (particles of ...)'`` for a result of ``loss_factor``."""
        origin = f"; {self.origin}" if self.origin else ""
        if self.sdc > SDC_UPPER_BOUND:
            return f"the physical bound {self.sdc:.3g} ({self.basis()}{origin})"
        known = f"; {self.basis()}" if self.known else ""
        return (f"the physical bound {self.sdc:.3g} (loss factor {loss_factor:.3g} > 1"
                f"{known}{origin})")

    def as_record(self) -> dict[str, float]:
        """The record fields that keep this bound with a saved analysis
        (:data:`RECORDED_BOUND_UNITS`), so that the record is judged alike where its specimen
        file is not at hand (the store keeps the specimen's name and hash, not its masses);
        none for the plain 2 pi (nothing to keep: that is the bound without them)."""
        if not self.known:
            return {}
        return {RECORDED_BOUND_FIELD: float(self.sdc),
                RECORDED_PARTICLE_MASS_FIELD: float(self.particle_mass_kg),
                RECORDED_STRUCTURE_MASS_FIELD: float(self.structure_mass_kg)}


#: The bound where the specimen or its fill is not known: 2 pi.
UNKNOWN_SPECIMEN_BOUND = SdcBound()

#: Record fields of a saved analysis that keep the bound it was judged with at its save
#: (:meth:`SdcBound.as_record`), and their units.
RECORDED_BOUND_FIELD = "plausibility_sdc_bound"
RECORDED_PARTICLE_MASS_FIELD = "plausibility_particle_mass_kg"
RECORDED_STRUCTURE_MASS_FIELD = "plausibility_structure_mass_kg"
RECORDED_BOUND_UNITS = {RECORDED_BOUND_FIELD: "1", RECORDED_PARTICLE_MASS_FIELD: "kg",
                        RECORDED_STRUCTURE_MASS_FIELD: "kg"}

#: What a bound read from a record says of itself.
RECORDED_BOUND_ORIGIN = ("the bound stored with the record when it was saved: its specimen file "
                         "is not at hand")

#: Relative difference within which a stored bound is its stored masses' (a float's round
#: trip through HDF5 is exact; this only absorbs another pidcore's summation order).
_RECORDED_BOUND_RTOL = 1e-9


def sdc_bound(*, fill_percent: float | None, material: str | None = None,
              specimen: Specimen | None = None) -> SdcBound:
    """The SDC bound of a test of ``specimen`` (:class:`pidcore.specimen.Specimen`; None: the
    paper's coupon assumed, with ``material`` particles) at ``fill_percent``: 2 pi, or
    ``8 m_p / m_s`` where larger. 2 pi where the fill is not known, or ``material`` (given) is
    neither the specimen's nor a table material the paper's coupon can be filled with."""
    from ..constants import PARTICLE_MATERIALS
    from ..dem.simulate import particles_per_cell
    from ..errors import PidcoreError
    from ..specimen import paper_specimen

    if specimen is not None and (not material or material == specimen.particles.material):
        tested = specimen
    elif not material or material in PARTICLE_MATERIALS:
        tested = paper_specimen(material or "acrylic")
    else:  # an own material without its specimen file: no cell, no particle mass
        return UNKNOWN_SPECIMEN_BOUND
    if fill_percent is None or not math.isfinite(float(fill_percent)) or fill_percent <= 0:
        # the bound is 2 pi, but the structure is known without the fill: a unit slip is
        # judged by it (a force in kN under "N" of a file stating no fill was saved)
        full = tested.capacity_per_cell() * tested.cell.count * tested.particles.mass_kg
        return SdcBound(SDC_UPPER_BOUND, math.nan, tested.coupon.moving_mass_kg,
                        full_particle_mass_kg=full)
    try:
        per_cell, _ = particles_per_cell(float(fill_percent), specimen=tested)
    except PidcoreError:  # a fill the DEM refuses (its own message says so elsewhere)
        return UNKNOWN_SPECIMEN_BOUND
    particles = per_cell * tested.cell.count * tested.particles.mass_kg
    structure = tested.coupon.moving_mass_kg
    return SdcBound(max(SDC_UPPER_BOUND, particle_impact_sdc(particles, structure)),
                    particles, structure)


def tested_sdc_bound(*, fill_percent: float | None, material: str | None,
                     specimen_name: str = "", specimen_sha256: str = "",
                     given: Specimen | None = None) -> SdcBound:
    """:func:`sdc_bound` of a measurement that names ``specimen_name`` (a record's
    ``specimen``; "": none, the paper's coupon assumed): ``given`` (the ``--specimen`` file)
    where it names that file, the paper's coupon where it names the coupon, else 2 pi (a
    specimen whose file is not at hand)."""
    from ..specimen import is_paper_coupon

    name, sha256 = _name_and_hash(specimen_name, specimen_sha256)
    if _names_given(name, sha256, given):
        return sdc_bound(fill_percent=fill_percent, material=material, specimen=given)
    if is_paper_coupon(name, sha256):
        return sdc_bound(fill_percent=fill_percent, material=material)
    return UNKNOWN_SPECIMEN_BOUND


def _name_and_hash(specimen_name: object, specimen_sha256: object) -> tuple[str, str]:
    """A record's specimen name (stripped) and file hash, "" for each that is not text."""
    return (specimen_name.strip() if isinstance(specimen_name, str) else "",
            specimen_sha256 if isinstance(specimen_sha256, str) else "")


def _names_given(name: str, sha256: str, given: Specimen | None) -> bool:
    """Whether a measurement naming ``name`` (with its file's ``sha256``, "" where not
    recorded) is a test of ``given``."""
    from ..specimen import measured_specimen_name, measured_specimen_sha256

    return (given is not None and bool(name) and name in (given.name,
                                                          measured_specimen_name(given))
            and (not sha256 or sha256 == measured_specimen_sha256(given)))


@dataclass(frozen=True)
class PlausibilityWarning:
    """One implausible number, what it probably means, and what to check.

    Attributes
    ----------
    check : str
        ``"negative_loss_factor"``, ``"sdc_above_bound"`` or ``"force_lags_velocity"``.
    message : str
        The finding, with the number.
    likely_cause : str
        What usually produces it and what to change.
    """

    check: str
    message: str
    likely_cause: str

    def __str__(self) -> str:
        return f"{self.message}. Likely cause: {self.likely_cause}"


def check_analysis(analysis, *, bound: SdcBound | None = None
                   ) -> tuple[PlausibilityWarning, ...]:
    """Plausibility warnings of one Eq. 11 analysis (empty when it looks physical).

    Parameters
    ----------
    analysis : PowerAnalysis
        Needs ``complex_power_w``, ``loss_factor``, ``sdc`` and ``omega_rad_s``.
    bound : SdcBound, optional
        The SDC bound of the specimen tested (:func:`sdc_bound`); default 2 pi (not known).
    """
    bound = bound or UNKNOWN_SPECIMEN_BOUND
    p = complex(analysis.complex_power_w)
    eta = float(analysis.loss_factor)
    sdc = float(analysis.sdc)
    omega = float(analysis.omega_rad_s)
    out = []
    # first: a velocity channel that holds an acceleration or a displacement (m/s^2 or m
    # under "m/s") shows a vibrated mass off by omega, and turns the phase by 90 degrees,
    # which the sign and phase findings below would take for an inverted channel or a
    # vibrometer delay (a "loss factor -20" explained by "a delay of 484 µs more"): the
    # refusal names the first finding, so the quantity or unit slip comes first
    vibrated_kg = _vibrated_mass_kg(analysis)
    if math.isfinite(bound.structure_mass_kg) and math.isfinite(vibrated_kg):
        # the Eq. 11 loss factor is a ratio and survives a force or velocity channel in
        # another unit than its header says; the energy per cycle (Eq. 10, the like-for-like
        # comparison with the DEM) does not: a force in kN under "N" pooled SDCs 1000 x apart.
        # The vibrated mass Im(P_c) shows is then 1000 x off what the specimen can show
        low = bound.structure_mass_kg / VIBRATED_MASS_SLIP_FACTOR
        # without the fill, the particles' mass is at most a full cell's
        stated = math.isfinite(bound.particle_mass_kg)
        particles = bound.particle_mass_kg if stated else bound.full_particle_mass_kg
        high = (bound.structure_mass_kg + particles) * VIBRATED_MASS_SLIP_FACTOR
        if vibrated_kg < low or vibrated_kg > high:
            out.append(PlausibilityWarning(
                "vibrated_mass_off",
                f"the vibrated mass the record shows, Im(P_c)/(omega |V|^2/2) = "
                f"{vibrated_kg * 1e3:.4g} g, is "
                + (f"below 1/{VIBRATED_MASS_SLIP_FACTOR:g} of the specimen's coupon and "
                   f"fixture ({bound.structure_mass_kg * 1e3:.4g} g)" if vibrated_kg < low else
                   f"over {VIBRATED_MASS_SLIP_FACTOR:g} x the specimen's coupon, fixture and "
                   + ("particles" if stated else "particles of full cells (no fill stated)")
                   + f" ({(high / VIBRATED_MASS_SLIP_FACTOR) * 1e3:.4g} g)"),
                "a force, velocity or time in another unit than its header says (kN under "
                "'N', mm/s under 'm/s', ms under 's': check the channel units or give "
                "force_unit=UNIT, velocity_unit=UNIT or time_unit=UNIT), or another "
                "specimen than the one assumed; or a velocity channel that holds an "
                "acceleration or a displacement (its vibrated mass is then omega times off, "
                "and its loss factor about -1/eta: no vibrometer delay or inverted channel "
                "mends it)"))
    if p.imag < 0:
        phase = math.degrees(math.atan2(p.imag, p.real))
        out.append(PlausibilityWarning(
            "force_lags_velocity",
            f"force lags velocity (phase of P {phase:.0f}°, a coupon's inertia makes it about "
            "+90°)",
            "a force or velocity channel of inverted sign (check the channel mapping and the "
            "sensor sign), or the wrong channel chosen as force"))
    # Without a velocity channel the velocity is the acceleration's integral: there is no
    # vibrometer, and a delay correction is refused for such a record, so a cause naming one
    # sent the user to an option that is then refused; the lag that turns the phase here is
    # the acceleration's behind the force (their conditioning or anti-aliasing filters).
    from_acceleration = bool(getattr(analysis, "corrections", {}).get(
        "velocity_from_acceleration", False))
    if math.isfinite(eta) and eta < 0:
        delay_cause = ("a lag of the acceleration channel behind the force (their signal "
                       "conditioning or anti-aliasing filters differ; a delay is corrected only "
                       "for a vibrometer velocity channel, which this record has not)"
                       if from_acceleration else "an uncorrected vibrometer output delay")
        cause = (f"more energy out than in is impossible for a passive damper: {delay_cause}, "
                 "or a mass-below-gauge or baseline correction that is too large")
        if p.imag > 0 and omega > 0:
            # a velocity delayed by tau turns P by +w tau; this tau brings Re P to zero
            tau = -math.atan2(p.real, p.imag) / omega
            if tau > 0:
                cause += (f"; a lag of about {tau * 1e6:.0f} µs of the acceleration behind "
                          "the force turns zero damping into this loss factor"
                          if from_acceleration else
                          f"; a vibrometer delay of about {tau * 1e6:.0f} µs more would bring "
                          "the loss factor to zero")
        out.append(PlausibilityWarning("negative_loss_factor",
                                       f"negative loss factor {eta:.4g} (SDC {sdc:.4g})", cause))
    if math.isfinite(sdc) and sdc > bound.sdc:
        out.append(PlausibilityWarning(
            "sdc_above_bound", f"SDC {sdc:.4g} is above {bound.words(eta)}",
            ("a lead of the acceleration channel over the force (their signal conditioning "
             "or anti-aliasing filters differ: it turns the force-velocity phase and inflates "
             "Re P)" if from_acceleration else
             "a wrong vibrometer delay (a delay too large turns the force-velocity phase and "
             "inflates Re P)")
            + ", or a mass-below-gauge correction close to the whole moving mass"
            # heavy particles (steel) read as implausible with only set-up errors named,
            # where their specimen file, not given, would have allowed it
            + ("" if bound.known else
               "; or particles heavier than their coupon whose specimen file is not given "
               "(without it the bound is 2 pi; with it, 8 m_p/m_s: give its specimen file, "
               "specimen=FILE)")))
    return tuple(out)


#: How far the vibrated mass a record shows may lie outside what its specimen can show (its
#: coupon and fixture below, with all its particles above) before it is taken for a unit
#: slip: a bed moving against the coupon near its resonance lowers it, by tens of per cent of
#: the structure's for the paper's coupon, and a heavy bed can lower it more; a slip of units
#: moves it by 1000.
VIBRATED_MASS_SLIP_FACTOR = 20.0


def _vibrated_mass_kg(analysis) -> float:
    """The mass-like reactive power's mass, Im(P_c) / (omega |V_1|^2 / 2), kg (NaN where the
    record has no such amplitude or force leads nothing): the fundamental's, which the drive
    is; harmonics of the velocity add under 1 % at the bundled records."""
    power = complex(analysis.complex_power_w)
    omega = float(getattr(analysis, "omega_rad_s", math.nan))
    speed = float(getattr(analysis, "velocity_amplitude_m_s", math.nan))
    if not (power.imag > 0 and omega > 0 and math.isfinite(speed) and speed > 0):
        return math.nan
    return power.imag / (0.5 * omega * speed ** 2)


#: Standard errors within which a negative loss factor is read as zero damping (an empty
#: coupon's loss factor of 1e-4 measured as -2e-5 +- 1e-5), not as a set-up error.
NEGATIVE_WITHIN_STDERRS = 3.0


def lowest_kept_sdc(stderr: float) -> float:
    """The lowest measured SDC kept as zero damping measured with noise: -
    :data:`NEGATIVE_WITHIN_STDERRS` x its standard error ``stderr`` (0 where none is known:
    0, NaN or not a standard error). Below it a measurement is energy created beyond its
    noise, refused as implausible (:func:`implausible_findings`, a ``calibrate --data``
    row), and a calibrated 95 % band of a measurement is cut there, as its top is cut at the
    SDC bound (:meth:`pidcore.calibrate.prediction.CalibratedPrediction.band`)."""
    stderr = float(stderr)
    if not (math.isfinite(stderr) and stderr > 0):
        return 0.0
    return -NEGATIVE_WITHIN_STDERRS * stderr


def implausible_findings(analysis, *, bound: SdcBound | None = None
                         ) -> tuple[tuple[PlausibilityWarning, ...], tuple[str, ...]]:
    """(warnings beyond noise, notes) of one analysis: :func:`check_analysis`'s warnings
    (``bound``: the specimen's SDC bound, default 2 pi), except a negative loss factor within
    :data:`NEGATIVE_WITHIN_STDERRS` standard errors of zero, which becomes a note (zero
    damping, measured with noise)."""
    from ..defaults import REACTIVE_POWER_MIN_FRACTION

    stderr = float(getattr(analysis, "sdc_stderr", math.nan))
    power = complex(analysis.complex_power_w)
    warnings, notes = [], []
    for w in check_analysis(analysis, bound=bound):
        if w.check == "negative_loss_factor" and analysis.sdc >= lowest_kept_sdc(stderr):
            notes.append(f"SDC {analysis.sdc:.3g} is zero within its uncertainty "
                         f"({NEGATIVE_WITHIN_STDERRS:g} x its standard error {stderr:.2g}): "
                         "no damping resolved")
            continue
        if (w.check == "negative_loss_factor"
                and -power.real <= REACTIVE_POWER_MIN_FRACTION * abs(power)):
            # a noise-free undamped record gives Re P of round-off (-1e-16 |P|), whose block
            # standard error is round-off too: it was refused as energy created, with "a
            # vibrometer delay of about 0 µs" as its cause
            notes.append(f"SDC {analysis.sdc:.3g} is zero within round-off (Re P_c below "
                         f"{REACTIVE_POWER_MIN_FRACTION:g} x |P_c|): no damping resolved")
            continue
        warnings.append(w)
    return tuple(warnings), tuple(notes)


def _findings_notes(findings, kept: str) -> tuple[str, ...]:
    """The notes of :func:`implausible_findings`' (warnings, notes): the notes, then each
    warning as an implausible result ``kept`` (how it came to be kept)."""
    warnings, notes = findings
    return notes + tuple(f"implausible, {kept}: {w}" for w in warnings)


def plausibility_notes(analysis, *, bound: SdcBound | None = None) -> tuple[str, ...]:
    """The notes a kept result carries: a negative SDC read as zero within its noise, and
    each warning beyond noise kept as asked (:func:`refuse_implausible` with ``accept``)."""
    return _findings_notes(implausible_findings(analysis, bound=bound), "kept as asked")


def refuse_implausible(records, names, *, accept: bool,
                       bounds: Sequence[SdcBound | None] | None = None) -> list:
    """``records`` (:class:`pidcore.measure.AnalyzedRecord`) checked for plausibility before
    anything is saved or reported, as the app asks for confirmation before it saves.

    A warning beyond noise (:func:`implausible_findings`: a negative loss factor, an SDC
    above its specimen's bound, ``bounds``: one :class:`SdcBound` or None per record, default
    2 pi) refuses the file (``names``: how messages name each), with the likely cause, unless
    ``accept``: then the record is kept and its notes say what was accepted
    (:func:`plausibility_notes`). Returns the records with those notes added.
    """
    from dataclasses import replace

    from ..errors import SignalError

    records = list(records)
    bounds = [None] * len(records) if bounds is None else list(bounds)
    findings = [implausible_findings(record.analysis, bound=bound)
                for record, bound in zip(records, bounds, strict=True)]
    flagged = [(name, warnings[0])
               for (warnings, _), name in zip(findings, names, strict=True) if warnings]
    if flagged and not accept:
        # the first in full; the others named, so that one run shows every file to fix
        (name, warning), others = flagged[0], [n for n, _ in flagged[1:]]
        also = (f"; also implausible: {', '.join(others)}" if others else "")
        raise SignalError(f"{name}: implausible: {warning}{also}; refused, nothing saved "
                          "(pass accept_implausible=True to keep it as it is)")
    out = []
    for record, found in zip(records, findings, strict=True):
        notes = _findings_notes(found, "kept as asked")
        out.append(replace(record, notes=record.notes + notes) if notes else record)
    return out


def stated_sdc_bounds(stated: Sequence[Any], settings: Sequence[Any],
                      given: Specimen | None = None) -> list[SdcBound]:
    """Each file's SDC bound (:func:`tested_sdc_bound`) from what is stated about it
    (:func:`pidcore.file_settings.resolve_files`' load cases, None where no fill is stated,
    and :class:`~pidcore.file_settings.FileSettings`, which name its specimen); ``given``: the
    ``--specimen`` file."""
    return [tested_sdc_bound(fill_percent=st.fill_percent if st is not None else None,
                             material=st.material if st is not None else None,
                             specimen_name=fs.specimen if fs is not None else "",
                             specimen_sha256=fs.specimen_sha256 if fs is not None else "",
                             given=given)
            for st, fs in zip(stated, settings, strict=True)]


def specimen_at_hand(specimen_name: str = "", specimen_sha256: str = "",
                     given: Specimen | None = None) -> bool:
    """Whether the specimen a measurement names is at hand for :func:`tested_sdc_bound`:
    ``given`` (the ``--specimen`` file) where it names that file (its hash, where recorded,
    the file's), or the paper's coupon (no specimen named, or the coupon)."""
    from ..specimen import is_paper_coupon

    name, sha256 = _name_and_hash(specimen_name, specimen_sha256)
    return _names_given(name, sha256, given) or is_paper_coupon(name, sha256)


def _recorded_number(record: Mapping[str, Any], name: str) -> float:
    try:
        value = record.get(name)
        return math.nan if value is None or isinstance(value, bool) else float(value)
    except (TypeError, ValueError):
        return math.nan


def recorded_sdc_bound(record: Mapping[str, Any]) -> tuple[SdcBound | None, str]:
    """``(bound, note)``: the SDC bound stored with a saved analysis (a row of
    :meth:`pidcore.store.Store.list_analyses`, :meth:`SdcBound.as_record`), marked as read
    from the record; None where it stored none (saved by an older pidcore, or with no
    specimen's masses known). A stored bound that is not one (below 2 pi, which no specimen
    gives, not finite, or not ``max(2 pi, 8 m_p/m_s)`` of its stored masses) is not trusted:
    None, and the note says it was ignored."""
    if not any(name in record for name in RECORDED_BOUND_UNITS):
        return None, ""
    sdc = _recorded_number(record, RECORDED_BOUND_FIELD)
    particles = _recorded_number(record, RECORDED_PARTICLE_MASS_FIELD)
    structure = _recorded_number(record, RECORDED_STRUCTURE_MASS_FIELD)
    if all(math.isnan(v) for v in (sdc, particles, structure)):
        return None, ""  # a listing of other records' fields: this one stored none
    problem = ""
    if not math.isfinite(sdc):
        problem = "is not a number"
    elif sdc < SDC_UPPER_BOUND:
        problem = f"is below 2 pi ({SDC_UPPER_BOUND:.4g}), the least bound of any specimen"
    elif not (math.isfinite(particles) and math.isfinite(structure) and particles > 0
              and structure > 0):
        problem = "has no positive particle and structure masses beside it"
    elif not math.isclose(sdc, max(SDC_UPPER_BOUND, particle_impact_sdc(particles, structure)),
                          rel_tol=_RECORDED_BOUND_RTOL):
        problem = (f"is not max(2 pi, 8 m_p/m_s) of its stored masses ({particles:.4g} kg, "
                   f"{structure:.4g} kg)")
    if problem:
        return None, (f"the SDC bound stored with the record ({RECORDED_BOUND_FIELD} "
                      f"{sdc:.4g}) {problem}: ignored, judged as without it")
    return SdcBound(sdc, particles, structure, origin=RECORDED_BOUND_ORIGIN), ""


def stored_record_name(record: Mapping[str, Any]) -> str:
    """How a note names a stored analysis (a row of :meth:`pidcore.store.Store.
    list_analyses`): its file's name, printable (:func:`pidcore.io.display_path`), else its
    key. ``report --store``, ``calibrate --store`` and the app's Compare page head the note of
    a stored bound ignored (:func:`stored_sdc_bound_and_note`) with it."""
    from pathlib import Path

    from ..io import display_path

    return display_path(Path(str(record.get("source", "") or record.get("key", ""))).name)


def stored_sdc_bound_and_note(record: Any, *, given: Specimen | None = None
                              ) -> tuple[SdcBound, str]:
    """:func:`stored_sdc_bound` and the note of a stored bound ignored
    (:func:`recorded_sdc_bound`; "" where none was)."""
    from ..specimen import MEASURED_SHA256_FIELD

    def text(name: str) -> str:
        value = record.get(name, "")
        return value.strip() if isinstance(value, str) else ""

    try:
        fill = float(record.get("fill_percent", math.nan))
    except (TypeError, ValueError):
        fill = math.nan
    return measured_sdc_bound(fill_percent=fill if math.isfinite(fill) else None,
                              material=text("material") or None,
                              specimen_name=text("specimen"),
                              specimen_sha256=text(MEASURED_SHA256_FIELD), given=given,
                              record=record)


def measured_sdc_bound(*, fill_percent: float | None, material: str | None,
                       specimen_name: str, specimen_sha256: str, given: Specimen | None,
                       record: Mapping[str, Any] | None) -> tuple[SdcBound, str]:
    """``(bound, note)`` of a measurement naming ``specimen_name`` (file hash
    ``specimen_sha256``): :func:`tested_sdc_bound` where its specimen is at hand
    (:func:`specimen_at_hand`; the file's own bound wins, equal to a stored one by
    construction), else the bound saved with its stored ``record``
    (:func:`recorded_sdc_bound`, with its note where one was ignored), else 2 pi."""
    if record is None or specimen_at_hand(specimen_name, specimen_sha256, given):
        return tested_sdc_bound(fill_percent=fill_percent, material=material,
                                specimen_name=specimen_name, specimen_sha256=specimen_sha256,
                                given=given), ""
    recorded, note = recorded_sdc_bound(record)
    return (recorded or UNKNOWN_SPECIMEN_BOUND), note


def stored_sdc_bound(record: Any, *, given: Specimen | None = None) -> SdcBound:
    """:func:`tested_sdc_bound` of a stored analysis (a row of
    :meth:`pidcore.store.Store.list_analyses`): its fill, material and specimen; ``given``:
    the ``--specimen`` file of the command reading it. Where its specimen file is not at hand
    (:func:`specimen_at_hand`), the bound saved with the record (:func:`recorded_sdc_bound`:
    ``pidcore analyze`` and the app keep it), else 2 pi."""
    return stored_sdc_bound_and_note(record, given=given)[0]


def stored_findings(record: Any, *, given: Specimen | None = None,
                    bound: SdcBound | None = None
                    ) -> tuple[tuple[PlausibilityWarning, ...], tuple[str, ...]]:
    """:func:`implausible_findings` of a stored analysis (a row of
    :meth:`pidcore.store.Store.list_analyses`: its complex power, loss factor, SDC, standard
    error and frequency), judged against ``bound`` or else its specimen's
    (:func:`stored_sdc_bound`, ``given``: the ``--specimen`` file at hand); nothing where the
    row lacks those numbers."""
    from types import SimpleNamespace

    try:
        analysis = SimpleNamespace(
            complex_power_w=complex(float(record["complex_power_real_w"]),
                                    float(record["complex_power_imag_w"])),
            loss_factor=float(record["loss_factor"]), sdc=float(record["sdc"]),
            sdc_stderr=float(record.get("sdc_stderr", math.nan)),
            omega_rad_s=2 * math.pi * float(record["frequency_hz"]),
            # a stored record names the channels it used: no velocity channel, an
            # acceleration one, is a velocity integrated from the acceleration
            corrections={"velocity_from_acceleration": not record.get("velocity_channel", "x")
                         and bool(record.get("acceleration_channel", ""))})
    except (KeyError, TypeError, ValueError):  # a listing without the numbers: nothing to say
        return (), ()
    ignored = ""
    if bound is None:
        bound, ignored = stored_sdc_bound_and_note(record, given=given)
    warnings, notes = implausible_findings(analysis, bound=bound)
    return warnings, ((ignored,) if ignored else ()) + notes


def stored_plausibility_notes(record: Any, *, given: Specimen | None = None
                              ) -> tuple[str, ...]:
    """The notes a stored analysis carries (:func:`stored_findings`), as
    :func:`plausibility_notes` gives them for an analysis in memory. A store keeps the numbers,
    not the notes: a record saved with ``--accept-implausible`` was reported from the store
    as any other (its SDC -1.26 pooled into a row without a word)."""
    return _findings_notes(stored_findings(record, given=given),
                           "saved as accepted (accept_implausible=True)")
