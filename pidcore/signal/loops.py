"""Force-displacement loops as data: one loop type, built from stored phasors or DEM runs.

Both the report's matplotlib figures (:mod:`pidcore.report.comparison_figures`) and the app's
charts (:mod:`pidcore.app.charts`) draw the frames these functions return, so a loop is built
one way only: harmonic synthesis from the phasors of an Eq. 11 analysis,
``X_n = V_n / (j n w)``, whether the record is a measurement or a DEM run's virtual shaker.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np
import pandas as pd

from .. import defaults
from ..errors import ParameterError, PidcoreError

#: Points on one synthesised loop.
LOOP_POINTS = 256
#: Force arrays looked for in a DEM run, in order: the force a shaker's gauge would measure
#: (coupon inertia + particles), comparable with a measured force; then the particles' force
#: on the walls alone.
DEM_FORCE_ARRAYS: tuple[str, ...] = ("shaker_force_n", "wall_force_n")
#: Coupon velocity arrays looked for in a DEM run.
DEM_VELOCITY_ARRAYS: tuple[str, ...] = ("velocity_m_s", "coupon_velocity_m_s")
#: Time arrays (sample instants) looked for in a DEM run.
DEM_TIME_ARRAYS: tuple[str, ...] = ("sample_time_s", "time_s")
#: Columns of :func:`loop_frame`.
LOOP_COLUMNS = ("series", "displacement [m]", "force [N]", "order")


def loop_area(displacement_m: np.ndarray, force_n: np.ndarray) -> float:
    """Area enclosed by a closed force-displacement loop, J (shoelace formula).

    The sign follows the traversal; its magnitude is the energy dissipated per cycle.
    """
    x = np.asarray(displacement_m, dtype=float)
    f = np.asarray(force_n, dtype=float)
    if x.shape != f.shape or x.ndim != 1 or x.size < 3:
        raise ParameterError("loop: displacement and force must be 1-D arrays of equal length >= 3")
    return float(0.5 * np.sum(x * np.roll(f, -1) - np.roll(x, -1) * f))


@dataclass(frozen=True)
class LoopCurve:
    """One period of a force-displacement loop (open: the point after the last is the first).

    Attributes
    ----------
    label : str
        What the loop is, e.g. ``"measured: run1.csv"``.
    displacement_m : numpy.ndarray
        Displacement, m.
    force_n : numpy.ndarray
        Force, N.
    """

    label: str
    displacement_m: np.ndarray
    force_n: np.ndarray

    @property
    def energy_per_cycle_j(self) -> float:
        """Enclosed area, J (energy dissipated per cycle)."""
        return abs(loop_area(self.displacement_m, self.force_n))


def loop_from_phasors(arrays: Mapping[str, np.ndarray], frequency_hz: object, *,
                      n_points: int = LOOP_POINTS) -> tuple[np.ndarray, np.ndarray] | str:
    """One period of an analysis' force-displacement loop, or a note why there is none.

    Rebuilt from the harmonic phasors (``harmonics``, ``force_phasors_n``,
    ``velocity_phasors_m_s``, as :func:`pidcore.measure.analysis_arrays` stores them) exactly as
    :meth:`pidcore.signal.PowerAnalysis.force_displacement_loop` does: X_n = V_n / (j n w).
    """
    needed = ("harmonics", "force_phasors_n", "velocity_phasors_m_s")
    if any(name not in arrays for name in needed):
        return f"stored analysis keeps no harmonic phasors ({', '.join(needed)})"
    if not isinstance(frequency_hz, int | float) or not frequency_hz > 0:
        return "stored analysis has no drive frequency"
    harmonics = np.asarray(arrays["harmonics"], dtype=float)
    force = np.asarray(arrays["force_phasors_n"], dtype=complex)
    velocity = np.asarray(arrays["velocity_phasors_m_s"], dtype=complex)
    omega = 2 * np.pi * float(frequency_hz)
    phase = 2 * np.pi * np.arange(n_points) / n_points
    rot = np.exp(1j * np.outer(harmonics, phase))
    displacement = velocity / (1j * harmonics * omega)
    return np.real(displacement @ rot), np.real(force @ rot)


def _first(arrays: Mapping[str, np.ndarray], names: tuple[str, ...]) -> np.ndarray | None:
    for name in names:
        if name in arrays:
            return np.asarray(arrays[name], dtype=float)
    return None


def dem_loop_from_arrays(arrays: Mapping[str, np.ndarray],
                         record: Mapping[str, object] | None = None, *,
                         n_points: int = LOOP_POINTS) -> tuple[np.ndarray, np.ndarray] | str:
    """One period of a DEM run's force-displacement loop, or a note why there is none.

    The stored virtual shaker record (force :data:`DEM_FORCE_ARRAYS`, coupon velocity
    :data:`DEM_VELOCITY_ARRAYS`) from the steady state on (``steady_start_cycle`` of the record)
    is analysed like a measurement (:func:`pidcore.signal.analyze_power`) and the loop
    synthesised from its harmonics, so measured and DEM loops are drawn the same way and their
    areas are comparable energies per cycle.

    Parameters
    ----------
    arrays : mapping
        The run's arrays (:attr:`pidcore.store.StoredEntry.arrays`).
    record : mapping, optional
        The run's scalars: ``frequency_hz``, ``sample_rate_hz`` (else from the time array),
        ``steady_start_cycle`` (default 0).
    n_points : int
        Points on the loop.

    Returns
    -------
    (displacement m, force N) or str
    """
    from .power import analyze_power

    record = record or {}
    force = _first(arrays, DEM_FORCE_ARRAYS)
    velocity = _first(arrays, DEM_VELOCITY_ARRAYS)
    if force is None or velocity is None:
        return (f"DEM run keeps no force ({', '.join(DEM_FORCE_ARRAYS)}) or velocity "
                f"({', '.join(DEM_VELOCITY_ARRAYS)}) time series")
    if force.shape != velocity.shape or force.ndim != 1:
        return "DEM run's force and velocity arrays differ in shape"
    rate = record.get("sample_rate_hz")
    time = _first(arrays, DEM_TIME_ARRAYS)
    if not isinstance(rate, int | float) and time is not None and time.size > 1:
        rate = 1.0 / float(np.mean(np.diff(time)))
    freq = record.get("frequency_hz")
    if not isinstance(rate, int | float) or not isinstance(freq, int | float) or not rate > 0:
        return "DEM run lacks sample_rate_hz or frequency_hz"
    per_cycle = float(rate) / float(freq)
    start = int(round(float(record.get("steady_start_cycle") or 0) * per_cycle))
    cycles = int((force.size - start) / per_cycle)
    if cycles < 2:
        return "DEM run has fewer than 2 steady cycles"
    try:
        # A short DEM window (a smoke run of a few steady cycles) is analysed over what it has.
        analysis = analyze_power(force[start:], velocity[start:], float(rate),
                                 frequency_hz=float(freq), source="DEM run",
                                 min_periods=min(defaults.MIN_PERIODS, cycles),
                                 n_blocks=max(2, min(defaults.N_UNCERTAINTY_BLOCKS, cycles)))
    except PidcoreError as exc:
        return f"DEM time series cannot be analysed ({exc})"
    return analysis.force_displacement_loop(n_points)


def loop_frame(loops: Sequence[LoopCurve]) -> pd.DataFrame:
    """Closed loops as one long table (SI units), one row per point, in drawing order.

    Columns :data:`LOOP_COLUMNS`; ``series`` is the loop's label; each loop's first point is
    repeated at its end to close it.
    """
    parts = []
    for loop in loops:
        x = np.append(loop.displacement_m, loop.displacement_m[:1])
        f = np.append(loop.force_n, loop.force_n[:1])
        parts.append(pd.DataFrame({"series": loop.label, "displacement [m]": x,
                                   "force [N]": f, "order": np.arange(x.size)}))
    return (pd.concat(parts, ignore_index=True) if parts
            else pd.DataFrame(columns=list(LOOP_COLUMNS)))
