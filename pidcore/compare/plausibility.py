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
* An SDC above :data:`SDC_UPPER_BOUND` dissipates more per radian of motion than the coupon
  stores; no particle damper in the paper comes near (Table 3's largest SDC is 0.88).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

#: SDC above which a result is implausible for a particle damper on a coupon: 2*pi, a loss
#: factor of 1 (the energy dissipated per radian equals the peak stored energy). Table 3's
#: largest SDC is 0.88 (DEM) and 0.71 (measured), so this bound only catches gross set-up errors.
SDC_UPPER_BOUND = 2 * math.pi


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


def check_analysis(analysis) -> tuple[PlausibilityWarning, ...]:
    """Plausibility warnings of one Eq. 11 analysis (empty when it looks physical).

    Parameters
    ----------
    analysis : PowerAnalysis
        Needs ``complex_power_w``, ``loss_factor``, ``sdc`` and ``omega_rad_s``.
    """
    p = complex(analysis.complex_power_w)
    eta = float(analysis.loss_factor)
    sdc = float(analysis.sdc)
    omega = float(analysis.omega_rad_s)
    out = []
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
    if math.isfinite(sdc) and sdc > SDC_UPPER_BOUND:
        out.append(PlausibilityWarning(
            "sdc_above_bound",
            f"SDC {sdc:.4g} is above the physical bound {SDC_UPPER_BOUND:.3g} (loss factor "
            f"{eta:.3g} > 1)",
            ("a lead of the acceleration channel over the force (their signal conditioning "
             "or anti-aliasing filters differ: it turns the force-velocity phase and inflates "
             "Re P)" if from_acceleration else
             "a wrong vibrometer delay (a delay too large turns the force-velocity phase and "
             "inflates Re P)")
            + ", or a mass-below-gauge correction close to the whole moving mass"))
    return tuple(out)


#: Standard errors within which a negative loss factor is read as zero damping (an empty
#: coupon's loss factor of 1e-4 measured as -2e-5 +- 1e-5), not as a set-up error.
NEGATIVE_WITHIN_STDERRS = 3.0


def implausible_findings(analysis) -> tuple[tuple[PlausibilityWarning, ...], tuple[str, ...]]:
    """(warnings beyond noise, notes) of one analysis: :func:`check_analysis`'s warnings,
    except a negative loss factor within :data:`NEGATIVE_WITHIN_STDERRS` standard errors of
    zero, which becomes a note (zero damping, measured with noise)."""
    from ..defaults import REACTIVE_POWER_MIN_FRACTION

    stderr = float(getattr(analysis, "sdc_stderr", math.nan))
    power = complex(analysis.complex_power_w)
    warnings, notes = [], []
    for w in check_analysis(analysis):
        if (w.check == "negative_loss_factor" and math.isfinite(stderr)
                and analysis.sdc + NEGATIVE_WITHIN_STDERRS * stderr >= 0):
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


def plausibility_notes(analysis) -> tuple[str, ...]:
    """The notes a kept result carries: a negative SDC read as zero within its noise, and
    each warning beyond noise kept as asked (:func:`refuse_implausible` with ``accept``)."""
    return _findings_notes(implausible_findings(analysis), "kept as asked")


def refuse_implausible(records, names, *, accept: bool) -> list:
    """``records`` (:class:`pidcore.measure.AnalyzedRecord`) checked for plausibility before
    anything is saved or reported, as the app asks for confirmation before it saves.

    A warning beyond noise (:func:`implausible_findings`: a negative loss factor, an SDC
    above :data:`SDC_UPPER_BOUND`) refuses the file (``names``: how messages name each), with
    the likely cause, unless ``accept``: then the record is kept and its notes say what was
    accepted (:func:`plausibility_notes`). Returns the records with those notes added.
    """
    from dataclasses import replace

    from ..errors import SignalError

    records = list(records)
    findings = [implausible_findings(record.analysis) for record in records]
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


def stored_findings(record) -> tuple[tuple[PlausibilityWarning, ...], tuple[str, ...]]:
    """:func:`implausible_findings` of a stored analysis (a row of
    :meth:`pidcore.store.Store.list_analyses`: its complex power, loss factor, SDC, standard
    error and frequency); nothing where the row lacks those numbers."""
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
    return implausible_findings(analysis)


def stored_plausibility_notes(record) -> tuple[str, ...]:
    """The notes a stored analysis carries (:func:`stored_findings`), as
    :func:`plausibility_notes` gives them for an analysis in memory. A store keeps the numbers,
    not the notes: a record saved with ``--accept-implausible`` was reported from the store
    as any other (its SDC -1.26 pooled into a row without a word)."""
    return _findings_notes(stored_findings(record),
                           "saved as accepted (accept_implausible=True)")
