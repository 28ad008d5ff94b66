"""Equivalent viscous damper from the specific damping capacity (paper abstract, Sect. 1 and 3).

For a coupon driven at constant acceleration amplitude ``a`` [m/s^2] and angular frequency
``w = 2 pi f``:

* maximum kinetic energy (Eq. 10): ``E = m_c a^2 / (2 w^2)``;
* energy dissipated per cycle (Eq. 8): ``dE = SDC * E``;
* displacement amplitude: ``X = a / w^2``;
* a viscous damper ``c`` moving as ``X sin(w t)`` dissipates ``pi c w X^2`` per cycle, so the
  damper dissipating the same energy is ``c_eq = dE / (pi w X^2) = SDC m_c w / (2 pi)``;
* loss factor ``SDC / (2 pi)`` and damping ratio ``-ln(1 - SDC) / (4 pi)`` (Sect. 3; the latter
  from the logarithmic decrement of a free decay losing the fraction SDC of its energy per cycle,
  small-damping form; undefined for SDC >= 1, reported as NaN).

``c_eq`` per unit area divides by the coupon area: the particles in a cell respond to the motion
of the cell, so the dissipation (not the mass) is what carries over to another structure with
the same fill, acceleration and frequency. The coupon area is one rule for every specimen
(:func:`specimen_area_m2`): the face area its file states (``[coupon] face_area_m2``; the
paper's coupon states its 0.1 m x 0.1 m face), else its cells' cross-section.
"""

from __future__ import annotations

import json
import warnings
from collections.abc import Callable, Sequence
from datetime import UTC, datetime
from importlib import resources
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
import pandas as pd

from .. import __version__
from .. import defaults as D
from ..atomic_files import write_atomically
from ..constants import PACKING_RATIO_COLUMN, STANDARD_GRAVITY, VIBRATED_MASS_CONVENTIONS
from ..errors import ParameterError, as_given
from ..specimen import MAX_FACE_TO_CELLS_AREA
from .sdc_model import SdcModel
from .sdc_model import held_error as held_error_of

if TYPE_CHECKING:  # a name for the hints only: the specimen module is imported where used
    from ..specimen import Specimen

#: The flag of :func:`equivalent_damper_table` marking points whose SDC rests on a filled hole of
#: the model grid (:meth:`SdcModel.filled_dependence`), not only the hole itself.
#: Like the report's category columns (``alignment [grid/interpolated/...]``) its
#: brackets list the values it takes, as pandas writes and reads them back (bool).
SDC_FILLED_COLUMN = "sdc_filled [True/False]"
#: The key of :func:`equivalent_damper_table`'s ``attrs`` holding what the rows flagged in
#: :data:`SDC_FILLED_COLUMN` rest on and how far their SDC moves with it ("" where none).
SDC_FILLED_NOTE = "sdc_filled_note"
#: The flag of :func:`equivalent_damper_table` marking points outside the model's grid whose SDC
#: is the edge value held there (``clip_to_range=True`` only; False everywhere else).
SDC_HELD_COLUMN = "sdc_held_at_edge [True/False]"
#: Which way the SDC of a point flagged in :data:`SDC_HELD_COLUMN` errs, by the model's own
#: slope at the edge held (:meth:`SdcModel.held_edges`); "not held" on the rows modelled.
SDC_HELD_ERROR_COLUMN = "sdc_held_error [overstated/understated/unknown/not held]"
#: Output columns of :func:`equivalent_damper_table` and their units, each named in the
#: column's brackets (the flag's "unit" is its values).
DAMPER_COLUMNS: dict[str, str] = {
    "frequency [Hz]": "Hz",
    "acceleration [g]": "g",
    PACKING_RATIO_COLUMN: "%",
    "sdc [-]": "-",
    SDC_FILLED_COLUMN: "True/False",
    SDC_HELD_COLUMN: "True/False",
    SDC_HELD_ERROR_COLUMN: "overstated/understated/unknown/not held",
    "coupon_loss_factor [-]": "-",
    "coupon_damping_ratio [-]": "-",
    "coupon_vibrated_mass [kg]": "kg",
    "coupon_area [m^2]": "m^2",
    "coupon_cells [-]": "-",
    "coupon_energy_per_cycle [J]": "J",
    "displacement_amplitude [m]": "m",
    "velocity_amplitude [m/s]": "m/s",
    "c_eq_per_coupon [N s/m]": "N s/m",
    "c_eq_per_treated_area [N s/m^3]": "N s/m^3",
    "c_eq_per_cell [N s/m]": "N s/m",
}
#: The names :data:`DAMPER_COLUMNS` had before pidcore said in each name what it is per (a
#: reader of the CSV alone took the coupon's ``c_eq`` or ``loss_factor`` for its panel's):
#: old name -> new name, for scripts reading an older file
#: (``pd.read_csv(path).rename(columns=DAMPER_COLUMNS_RENAMED)``).
DAMPER_COLUMNS_RENAMED: dict[str, str] = {
    "loss_factor [-]": "coupon_loss_factor [-]",
    "damping_ratio [-]": "coupon_damping_ratio [-]",
    "vibrated_mass [kg]": "coupon_vibrated_mass [kg]",
    "energy_per_cycle [J]": "coupon_energy_per_cycle [J]",
    "c_eq [N s/m]": "c_eq_per_coupon [N s/m]",
    "c_eq_per_area [N s/m^3]": "c_eq_per_treated_area [N s/m^3]",
    "fill [%]": PACKING_RATIO_COLUMN,  # the report's name for the fill, since 2026-12
}
#: What each column of :data:`DAMPER_COLUMNS` is, per what and where it applies (the JSON
#: file's ``columns``): the brackets name the unit, not whether a number is the coupon's or
#: transfers to another panel.
DAMPER_COLUMN_MEANINGS: dict[str, str] = {
    "frequency [Hz]": "drive frequency f of the coupon test",
    "acceleration [g]": "acceleration amplitude a of the coupon (g = 9.80665 m/s^2)",
    PACKING_RATIO_COLUMN: "fill of every cell of the coupon",
    "sdc [-]": "specific damping capacity dE/E (Eq. 8, E of Eq. 10), pchip model",
    SDC_FILLED_COLUMN: "the point's SDC rests on a hole of the model grid, filled "
                       "(provenance filled_grid_points): it would move with that value",
    SDC_HELD_COLUMN: "the point lies outside the model's grid: its SDC is the nearest edge "
                     "value held, not modelled there",
    SDC_HELD_ERROR_COLUMN: "which way a held SDC (and every damper of it) errs if the model's "
                           "trend at the edge held (its slope there) continues beyond it: "
                           "overstated below a rising edge or above a falling one, "
                           "understated the other way; unknown where that slope is flat or "
                           "two edges held disagree; not a bound",
    "coupon_loss_factor [-]": "SDC/(2 pi) of the coupon, relative to its own m_c: not a loss "
                              "factor of another panel (its mass differs); use "
                              "c_eq_per_treated_area there",
    "coupon_damping_ratio [-]": "-ln(1 - SDC)/(4 pi) of the coupon, relative to its own m_c "
                                "(empty where SDC >= 1): the free decay's ratio, whose cycle "
                                "loses SDC of its energy; not the ratio c_eq/(2 m_c w) = "
                                "SDC/(4 pi) of the damper c_eq (near it at small SDC, 2 x it "
                                "at SDC 0.8): an FEM model with c_eq damps at that one",
    "coupon_vibrated_mass [kg]": "m_c of Eq. 10 the SDC is taken over (provenance "
                                 "vibrated_mass: which masses)",
    "coupon_area [m^2]": "face area (one face) of the coupon c_eq_per_coupon is of: its "
                         "specimen file's [coupon] face_area_m2 (the paper's 0.1 m x 0.1 m), "
                         "else its cells' cross-section, cell count x hexagon (provenance "
                         "area: which, and from where); c_eq_per_treated_area = "
                         "c_eq_per_coupon / coupon_area",
    "coupon_cells [-]": "honeycomb cells of the coupon c_eq_per_coupon is of: c_eq_per_cell = "
                        "c_eq_per_coupon / coupon_cells",
    "coupon_energy_per_cycle [J]": "energy dissipated per drive cycle in the whole coupon, "
                                   "SDC m_c a^2/(2 w^2)",
    "displacement_amplitude [m]": "a/w^2, the coupon's displacement amplitude",
    "velocity_amplitude [m/s]": "a/w, the coupon's velocity amplitude: the damper's force "
                                "amplitude is c_eq_per_coupon times it",
    "c_eq_per_coupon [N s/m]": "viscous damper of the whole coupon (coupon_area, coupon_cells), "
                               "grounded: on the coupon's absolute velocity along the drive "
                               "direction (provenance direction); pi c_eq_per_coupon w X^2 = "
                               "coupon_energy_per_cycle",
    "c_eq_per_treated_area [N s/m^3]": "c_eq_per_coupon per m^2 of coupon face (one face, "
                                       "coupon_area): "
                                       "spread over the treated (filled) area of a panel at "
                                       "the same fill, acceleration and frequency (e.g. a "
                                       "grounded dashpot of c_eq_per_treated_area x tributary "
                                       "treated area at each node, along the drive direction)",
    "c_eq_per_cell [N s/m]": "c_eq_per_coupon per honeycomb cell (one cell): c_eq_per_coupon / "
                             "coupon_cells, for a panel whose cells are modelled one by one at "
                             "the same fill, acceleration and frequency",
}


#: The columns :func:`equivalent_damper_table` adds for a panel of known areal mass
#: (``panel_areal_mass_kg_m2``), and their units.
PANEL_COLUMNS: dict[str, str] = {
    "panel_areal_mass [kg/m^2]": "kg/m^2",
    "panel_treated_fraction [-]": "-",
    "panel_loss_factor [-]": "-",
}
DAMPER_COLUMN_MEANINGS.update({
    "panel_areal_mass [kg/m^2]": "mass per m^2 of the panel the loss factor is of, with its "
                                 "particles (all the mass that moves)",
    "panel_treated_fraction [-]": "share of the panel's face area filled at this fill "
                                  "(treated area / panel area)",
    "panel_loss_factor [-]": "loss factor the particles add to that panel if all of it moves "
                             "as the coupon did (one amplitude everywhere, along the drive "
                             "direction, at this acceleration and frequency): "
                             "c_eq_per_treated_area x panel_treated_fraction / "
                             "(panel_areal_mass x w); not a mode's, whose amplitude varies "
                             "over the panel (harmonic_response with treated_regions)",
})
#: Most a panel's areal mass may lie outside the coupons' own (m_c / coupon area over the
#: table) before it is refused as a unit slip: g/m^2 typed for kg/m^2 is 1000 x off, while a
#: light 1 kg/m^2 skin or a heavy 50 kg/m^2 panel beside the paper coupon's 2.2-16 kg/m^2
#: stays well within it.
AREAL_MASS_LIMIT = 100.0


def panel_loss_factor(c_eq_per_treated_area: float | np.ndarray, *,
                      frequency_hz: float | np.ndarray, panel_areal_mass_kg_m2: float,
                      treated_fraction: float = 1.0) -> np.ndarray:
    """Loss factor [-] the particles add to a panel moving as the coupon did.

    Every point of the panel (areal mass ``mu`` [kg/m^2] with its particles, a share
    ``treated_fraction`` of its area ``A_p`` treated) moves at one amplitude X along the drive
    direction: the treated area dissipates ``c'' A_t pi w X^2`` per cycle (``c''`` =
    ``c_eq_per_treated_area``), the panel's peak kinetic energy is ``mu A_p w^2 X^2 / 2``,
    and the loss factor, dissipation over 2 pi times it, is

        eta = c'' (A_t / A_p) / (mu w).

    Not a mode's: there the amplitude varies over the panel (use
    :func:`~pidcore.model.harmonic_response` with ``treated_regions``).

    Examples
    --------
    >>> float(panel_loss_factor(10.0, frequency_hz=100 / np.pi, panel_areal_mass_kg_m2=5.0,
    ...                         treated_fraction=0.5))  # 10 x 0.5 / (5 x 200)
    0.005
    """
    mu = float(_positive("panel_areal_mass_kg_m2", panel_areal_mass_kg_m2))
    fraction = float(_positive("treated_fraction", treated_fraction))
    if fraction > 1.0:
        raise ParameterError(f"treated_fraction must be in (0, 1] (treated area / panel "
                             f"area), got {treated_fraction!r}")
    w = 2.0 * np.pi * _positive("frequency_hz", frequency_hz)
    return np.asarray(c_eq_per_treated_area, dtype=float) * fraction / (mu * w)


def _positive(name: str, value: np.ndarray) -> np.ndarray:
    arr = np.asarray(value, dtype=float)
    if not np.all(np.isfinite(arr)) or np.any(arr <= 0):
        raise ParameterError(f"{name} must be finite and > 0, got {value!r}")
    return arr


def loss_factor(sdc: float | np.ndarray) -> np.ndarray:
    """Loss factor [-] from SDC [-]: ``SDC / (2 pi)``."""
    return np.asarray(sdc, dtype=float) / (2.0 * np.pi)


def damping_ratio(sdc: float | np.ndarray) -> np.ndarray:
    """Damping ratio [-] from SDC [-]: ``-ln(1 - SDC) / (4 pi)``; NaN where SDC >= 1."""
    s = np.asarray(sdc, dtype=float)
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(s < 1.0, -np.log1p(-np.minimum(s, 1.0)) / (4.0 * np.pi), np.nan)


def energy_per_cycle(sdc: float | np.ndarray, *, vibrated_mass_kg: float | np.ndarray,
                     acceleration_m_s2: float | np.ndarray,
                     frequency_hz: float | np.ndarray) -> np.ndarray:
    """Energy dissipated per cycle [J]: ``SDC * m_c a^2 / (2 w^2)`` (Eq. 8-10)."""
    m = _positive("vibrated_mass_kg", vibrated_mass_kg)
    a = _positive("acceleration_m_s2", acceleration_m_s2)
    w = 2.0 * np.pi * _positive("frequency_hz", frequency_hz)
    return np.asarray(sdc, dtype=float) * m * a**2 / (2.0 * w**2)


def sdc_from_energy_per_cycle(energy_per_cycle_j: float, *, vibrated_mass_kg: float,
                              acceleration_m_s2: float, frequency_hz: float) -> float:
    """SDC [-] of a measured energy per cycle: ``dE / (m_c a^2 / (2 w^2))`` (Eq. 8-10).

    The inverse of :func:`energy_per_cycle`; NaN where ``m_c``, ``a`` or ``f`` is not finite
    and > 0 (no reference energy, e.g. an unknown vibrated mass).

    Examples
    --------
    >>> round(sdc_from_energy_per_cycle(1.0, vibrated_mass_kg=2.0, acceleration_m_s2=9.80665,
    ...                                 frequency_hz=1.0), 6)  # E = 2 g^2 / (2 (2 pi)^2)
    0.410505
    """
    try:
        reference = float(energy_per_cycle(1.0, vibrated_mass_kg=vibrated_mass_kg,
                                           acceleration_m_s2=acceleration_m_s2,
                                           frequency_hz=frequency_hz))
    except ParameterError:
        return float("nan")
    return float(energy_per_cycle_j) / reference


def displacement_amplitude(acceleration_m_s2: float | np.ndarray,
                           frequency_hz: float | np.ndarray) -> np.ndarray:
    """Displacement amplitude [m] of harmonic motion: ``a / w^2``."""
    w = 2.0 * np.pi * _positive("frequency_hz", frequency_hz)
    return _positive("acceleration_m_s2", acceleration_m_s2) / w**2


def equivalent_damping_coefficient(sdc: float | np.ndarray, *,
                                   vibrated_mass_kg: float | np.ndarray,
                                   frequency_hz: float | np.ndarray) -> np.ndarray:
    """Viscous damper [N s/m] dissipating the same energy per cycle: ``SDC m_c w / (2 pi)``.

    Independent of the acceleration amplitude for a given SDC (the amplitude dependence is in
    SDC itself). Equals ``dE / (pi w X^2)`` with :func:`energy_per_cycle` and
    :func:`displacement_amplitude`.

    Examples
    --------
    >>> float(equivalent_damping_coefficient(2 * np.pi * 0.01, vibrated_mass_kg=1.0,
    ...                                      frequency_hz=1 / (2 * np.pi)))
    0.01
    """
    m = _positive("vibrated_mass_kg", vibrated_mass_kg)
    w = 2.0 * np.pi * _positive("frequency_hz", frequency_hz)
    return np.asarray(sdc, dtype=float) * m * w / (2.0 * np.pi)


def sdc_from_damping_coefficient(c_eq: float | np.ndarray, *,
                                 vibrated_mass_kg: float | np.ndarray,
                                 frequency_hz: float | np.ndarray) -> np.ndarray:
    """Inverse of :func:`equivalent_damping_coefficient`: ``2 pi c_eq / (m_c w)``."""
    m = _positive("vibrated_mass_kg", vibrated_mass_kg)
    w = 2.0 * np.pi * _positive("frequency_hz", frequency_hz)
    return 2.0 * np.pi * np.asarray(c_eq, dtype=float) / (m * w)


def coupon_area_m2(side_m: float = D.COUPON_SIDE_M) -> float:
    """Face area of the square coupon [m^2] (paper: 0.1 m x 0.1 m)."""
    return float(_positive("side_m", side_m)) ** 2


#: Most a coupon area may differ from its cells' cross-section (count x hexagon) before it is
#: refused as a unit slip: cm^2 or mm^2 typed for m^2 is 1e4 or 1e6 times off, while a panel
#: whose filled cells are a patch of it, or the paper's 0.01 m^2 over its 441 cells (1.16 x),
#: stay well within it. The bound a specimen file's ``[coupon] face_area_m2`` is held to.
AREA_TO_CELLS_LIMIT = MAX_FACE_TO_CELLS_AREA


def runs_specimen(runs: pd.DataFrame):
    """The specimen of DEM runs (its canonical text, stored with each run), None where the
    runs hold none (an older store) or several.

    The canonical text leaves ``[coupon] face_area_m2`` out (no DEM physics): runs of a file
    pidcore bundles (the paper's coupon, of any table material; same hash) take that file's
    face area, as that file does; runs of any other file state none, and are taken over their
    cells' area (:func:`specimen_area_m2`) unless an area is given."""
    from ..compare.align import stored_parameters
    from ..specimen import Specimen, bundled_face_area

    if "parameters_json" not in runs.columns or runs.empty:
        return None
    texts = {(stored_parameters(p) or {}).get("specimen_text") for p in runs["parameters_json"]}
    if len(texts) != 1 or None in texts:
        return None
    return bundled_face_area(Specimen.from_text(texts.pop(), source="stored DEM runs"))


#: How far a given coupon area may differ from its specimen's own (:func:`specimen_area_m2`)
#: before the output notes it: a coupon cut a cell row larger or smaller differs by some 10 %,
#: rounding the area to two digits by under 5 %.
AREA_NOTE_TOLERANCE = 0.05


def specimen_area_m2(specimen: Specimen, *, read_from: str = "its file"
                     ) -> tuple[float, str]:
    """The coupon area of ``specimen`` for c_eq per area, m^2, and where it comes from
    (``read_from``: what ``specimen`` was read from, as the words name it).

    One rule for every specimen: the face area its file states (``[coupon] face_area_m2``;
    the paper's coupon states its 0.1 m x 0.1 m face, 1.16 x its 441 cells), else the
    cross-section of its cells, ``[cell] count`` x one hexagon's
    (:meth:`pidcore.specimen.Specimen.cells_area_m2`). The paper coupon's cells took its
    0.01 m^2 whatever the file (a calibrated file, another particle fill), any other file its
    cells' area, and no file could state its face."""
    cells = specimen.cells_area_m2()
    count = specimen.cell.count
    face = specimen.coupon.face_area_m2
    if face is not None:
        return face, (f"{face:.6g} m^2 ([coupon] face_area_m2 of specimen {specimen.name}: "
                      f"{face / cells:.3g} x its {count} cells' {cells:.6g} m^2)")
    return cells, (f"{cells:.6g} m^2 (specimen {specimen.name}'s {count} cells x "
                   f"{cells / count * 1e6:.6g} mm^2 each: {read_from} states no [coupon] "
                   "face_area_m2, so the area its cells treat)")


def area_override_note(area_m2: float, specimen: Specimen, what: str = "area_m2") -> str:
    """A note where a given coupon area differs from :func:`specimen_area_m2` by more than
    :data:`AREA_NOTE_TOLERANCE`, else ``""``: the area divides every c_eq per area, and a
    value typed for another coupon is not otherwise visible in the table."""
    own, origin = specimen_area_m2(specimen)
    ratio = float(area_m2) / own
    if abs(ratio - 1.0) <= AREA_NOTE_TOLERANCE:
        return ""
    return (f"{what} {float(area_m2):g} m^2 is {ratio:.3g} x specimen {specimen.name}'s own "
            f"{origin}: c_eq per area is taken over the area given")


def check_area(area_m2: float, specimen, what: str = "area_m2") -> None:
    """Refuse a coupon area more than :data:`AREA_TO_CELLS_LIMIT` times off the cross-section
    of ``specimen``'s cells as a unit slip (``what``: the option as messages name it)."""
    cells = specimen.cells_area_m2()
    ratio = float(area_m2) / cells
    if 1.0 / AREA_TO_CELLS_LIMIT <= ratio <= AREA_TO_CELLS_LIMIT:
        return
    hint = "was it cm^2 or mm^2?" if ratio > 1 else \
        "was it one cell's area, or is the specimen's [cell] count wrong?"
    raise ParameterError(
        f"{what} {float(area_m2):g} m^2 is {ratio:.3g} x the cross-section of specimen "
        f"{specimen.name}'s {specimen.cell.count} cells ({cells:.4g} m^2); expected the "
        f"coupon's face area in m^2; {hint}")


#: Most an explicit m_c may lie outside the range of its coupon's own m_c (the paper coupon's:
#: every convention, every fill of the model; another specimen's: its empty coupon to its
#: cells full) before it is refused as a unit slip: grams typed for kilograms are 1000 x off,
#: while a heavy fixture (the paper calibration's 0.26 kg beside the 0.02-0.2 kg of coupon and
#: particles) stays well within it.
VIBRATED_MASS_LIMIT = 100.0


def check_vibrated_mass(mass_kg: float, fills: Sequence[float],
                        material: str = D.MODEL_PARTICLE_MATERIAL,
                        what: str = "vibrated_mass_kg",
                        specimen: Specimen | None = None) -> None:
    """Refuse an explicit m_c more than :data:`VIBRATED_MASS_LIMIT` times outside the range of
    its coupon's own m_c as a unit slip (``what``: the option as messages name it). The one
    check of a given m_c: :func:`equivalent_damper_table`, ``pidcore model damper
    --vibrated-mass`` and :class:`~pidcore.model.TreatedMode` all refuse by it.

    The range is :func:`vibrated_mass_range`: the paper coupon's m_c over ``fills`` [%] (every
    convention, ``material`` particles) where ``specimen`` is None or the paper's coupon, else
    ``specimen``'s own, from its empty coupon to its cells full."""
    low, high, whose = vibrated_mass_range(fills, material, specimen)
    mass = float(mass_kg)
    if low / VIBRATED_MASS_LIMIT <= mass <= high * VIBRATED_MASS_LIMIT:
        return
    hint = "was it grams?" if mass > high else "was it in another unit?"
    ratio = _three_digits(mass / (high if mass > high else low))
    raise ParameterError(
        f"{what} {as_given(mass)} kg is {ratio} x {whose[0]} ({low:.3g} .. {high:.3g} kg "
        f"{whose[1]}); expected m_c in kg; {hint}")


def vibrated_mass_range(fills: Sequence[float], material: str = D.MODEL_PARTICLE_MATERIAL,
                        specimen: Specimen | None = None
                        ) -> tuple[float, float, tuple[str, str]]:
    """(least, most m_c [kg], (whose masses, how they span) in words) an m_c of Eq. 10 of the
    coupon tests may be, before :data:`VIBRATED_MASS_LIMIT`'s margin.

    The paper's coupon (``specimen`` None or :meth:`~pidcore.specimen.Specimen.is_paper`):
    its m_c over ``fills`` [%] by every convention with the paper's count of ``material``
    particles (:func:`paper_vibrated_mass`). Any other specimen: its own masses, from one
    particle in each cell alone (the ``particles`` convention's least) or its empty coupon
    and fixture, whichever is lighter, to coupon, fixture and every cell full (its
    :meth:`~pidcore.specimen.Specimen.capacity_per_cell`): the paper coupon's 0.02-0.2 kg
    took the 11.6 kg of a 7150-cell tungsten carbide panel for grams."""
    if specimen is not None and not specimen.is_paper():
        from ..specimen import vibrated_mass_by_convention

        rigid = specimen.coupon.moving_mass_kg
        full = specimen.capacity_per_cell()
        one_each = specimen.cell.count * specimen.particles.mass_kg
        low = min(rigid, one_each)
        high = vibrated_mass_by_convention("coupon_plus_particles", rigid_kg=rigid,
                                           particles_kg=full * one_each)
        return low, high, (
            f"specimen {specimen.name}'s vibrated masses",
            f"from {'its empty coupon' if rigid <= one_each else 'one particle per cell'} "
            f"to its {specimen.cell.count} cells full, {full} {specimen.particles.material} "
            "particles each, over every convention")
    masses = [paper_vibrated_mass(convention, material)(float(fill))
              for convention in VIBRATED_MASS_CONVENTIONS for fill in fills]
    return min(m for m in masses if m > 0), max(masses), (
        "the paper coupon's vibrated masses",
        f"over every convention at {_fills_text(fills)} % fill, {material} particles")


def check_one_fill_per_mass(mass_kg: float, fills: Sequence[float],
                            what: str = "vibrated_mass_kg",
                            instead: str = "give one fill per m_c (fills_percent=[F]), or "
                                           "vibrated_mass_kg as a function of fill (e.g. "
                                           "paper_vibrated_mass())") -> None:
    """Refuse one explicit m_c for several fills (``what``: the option as messages name it,
    ``instead``: the ways on in their words).

    Each SDC of the model was divided by the m_c of its own fill (Eq. 10), which grows with
    the particles: c_eq = SDC m_c w / (2 pi) over one m_c at every fill was 1.63 x too high at
    25 % and 0.62 x too low at 90 % for the paper coupon's 50 % m_c."""
    distinct = list(dict.fromkeys(float(f) for f in fills))
    if len(distinct) > 1:
        raise ParameterError(
            f"{what} {as_given(float(mass_kg))} kg: one m_c for the fills "
            f"{', '.join(as_given(f) for f in distinct)} %, but each fill's SDC was divided by "
            f"that fill's own m_c (Eq. 10, the particles' mass grows with fill); {instead}")


def _three_digits(ratio: float) -> str:
    # 1000 read "1e+03 x" (:.3g) in the very message of a mass typed in grams
    return f"{float(f'{ratio:.3g}'):g}"


def _fills_text(fills: Sequence[float]) -> str:
    values = sorted({float(f) for f in fills})
    return as_given(values[0]) if len(values) == 1 else \
        f"{as_given(values[0])} .. {as_given(values[-1])}"


def coupon_vibrated_mass_kg(*, particles_mass_kg: float = 0.0,
                            side_m: float = D.COUPON_SIDE_M,
                            face_sheet_thickness_m: float = D.FACE_SHEET_THICKNESS_M,
                            face_sheet_density_kg_m3: float = D.FACE_SHEET_DENSITY_KG_M3,
                            core_height_m: float = D.CELL_HEIGHT_M,
                            core_density_kg_m3: float = D.CORE_DENSITY_KG_M3) -> float:
    """Mass m_c [kg] entering Eq. 10: two face sheets + core (paper Table 2) + particles.

    The particle mass is an explicit argument because the number of particles that fit in a cell
    is the DEM module's business; :func:`paper_particles_mass_kg` gives the paper's count.

    Examples
    --------
    >>> round(coupon_vibrated_mass_kg(), 5)  # 2 x 0.1^2 x 0.25e-3 x 2800 + 0.1^2 x 0.0254 x 32.1
    0.02215
    """
    if particles_mass_kg < 0 or not np.isfinite(particles_mass_kg):
        raise ParameterError(f"particles_mass_kg must be >= 0, got {particles_mass_kg!r}")
    area = coupon_area_m2(side_m)
    faces = 2.0 * area * _positive("face_sheet_thickness_m", face_sheet_thickness_m) \
        * _positive("face_sheet_density_kg_m3", face_sheet_density_kg_m3)
    core = area * _positive("core_height_m", core_height_m) \
        * _positive("core_density_kg_m3", core_density_kg_m3)
    return float(faces + core + particles_mass_kg)


def _particle_mass_kg(material: str) -> float:
    path = resources.files("pidcore.data").joinpath("materials.csv")
    with resources.as_file(path) as p:
        table = pd.read_csv(p, comment="#")
    row = table[(table["name"] == material) & (table["role"] == "particle")]
    if row.empty:
        names = table.loc[table["role"] == "particle", "name"].tolist()
        raise ParameterError(f"material {material!r} is not a particle material; expected one "
                             f"of {names}")
    r = float(row["default_radius_m"].iloc[0])
    return float(row["density_kg_m3"].iloc[0]) * 4.0 / 3.0 * np.pi * r**3


def paper_particles_mass_kg(fill_percent: float, material: str = "acrylic", *,
                            cells: int = D.COUPON_CELLS,
                            particles_per_full_cell: int = D.PAPER_PARTICLES_PER_FULL_CELL
                            ) -> float:
    """Particle mass [kg] in the coupon by the paper's count (Sect. 5.1).

    ``round(particles_per_full_cell * fill / 100)`` particles of the material's default radius
    and density (``pidcore/data/materials.csv``) in each of ``cells`` cells.
    """
    if not 0.0 <= fill_percent <= 100.0:
        raise ParameterError(f"fill_percent must be in [0, 100], got {fill_percent!r}")
    per_cell = round(particles_per_full_cell * fill_percent / 100.0)
    return cells * per_cell * _particle_mass_kg(material)


def paper_vibrated_mass(convention: str = D.MODEL_VIBRATED_MASS_CONVENTION,
                        material: str = D.MODEL_PARTICLE_MATERIAL) -> Callable[[float], float]:
    """m_c [kg] of Eq. 10 against fill [%] for the paper's coupon (Table 2 masses) with the
    paper's count of particles (:func:`paper_particles_mass_kg`), by ``convention``."""
    from ..specimen import vibrated_mass_by_convention

    if convention not in VIBRATED_MASS_CONVENTIONS:
        raise ParameterError(f"vibrated mass convention: expected one of "
                             f"{', '.join(VIBRATED_MASS_CONVENTIONS)}, got {convention!r}")
    rigid = coupon_vibrated_mass_kg()

    def mass(fill_percent: float) -> float:
        return vibrated_mass_by_convention(
            convention, rigid_kg=rigid,
            particles_kg=paper_particles_mass_kg(fill_percent, material))

    return mass


def specimen_particles_mass(specimen: Specimen | None = None,
                            material: str = D.MODEL_PARTICLE_MATERIAL
                            ) -> Callable[[float], float]:
    """The particles' mass [kg] in the whole coupon against fill [%]: the paper's coupon
    (``specimen`` None or :meth:`~pidcore.specimen.Specimen.is_paper`) by Table 3's count of
    ``material`` spheres (:func:`paper_particles_mass_kg`, the count its m_c holds), another
    specimen's cells at its capacity as 100 % (the DEM's default fill reference,
    :meth:`~pidcore.specimen.Specimen.capacity_per_cell`). Stored DEM runs:
    :func:`runs_particles_mass`."""
    if specimen is None or specimen.is_paper():
        material = specimen.particles.material if specimen is not None else material
        return lambda fill_percent: paper_particles_mass_kg(float(fill_percent), material)
    from ..specimen import particles_for_fill

    per_particle = specimen.cell.count * specimen.particles.mass_kg
    full = specimen.capacity_per_cell()
    return lambda fill_percent: per_particle * particles_for_fill(float(fill_percent), full)


#: Columns of a DEM-run listing that fix m_c(fill) as the runs normalised their SDC.
RUN_MASS_COLUMNS: tuple[str, ...] = (
    "vibrated_mass_convention", "coupon_mass_kg", "fixture_mass_kg", "coupon_cells",
    "particle_mass_kg", "particles_full_cell")


def _runs_masses(runs: pd.DataFrame) -> tuple[str, float, float, int]:
    """(m_c convention, coupon + fixture [kg], one particle in each cell [kg], particles
    taken as 100 % fill) of the DEM runs of one specimen, from their stored columns."""
    missing = [c for c in (*RUN_MASS_COLUMNS, "fill_percent", "vibrated_mass_kg")
               if c not in runs.columns]
    if missing:
        raise ParameterError(f"DEM runs: no {', '.join(missing)} column(s) to take the vibrated "
                             "mass m_c from (runs of an older pidcore); run them again")
    values = {}
    for column in RUN_MASS_COLUMNS:
        distinct = runs[column].dropna().unique()
        if len(distinct) != 1:
            raise ParameterError(
                f"DEM runs: {column} is {sorted(map(str, distinct)) or 'not stored'}; the "
                "vibrated mass m_c needs the runs of one specimen (select with --where)")
        values[column] = distinct[0]
    convention = str(values["vibrated_mass_convention"])
    if convention not in VIBRATED_MASS_CONVENTIONS:
        raise ParameterError(f"DEM runs: unknown vibrated_mass_convention {convention!r}")
    return (convention, float(values["coupon_mass_kg"]) + float(values["fixture_mass_kg"]),
            int(values["coupon_cells"]) * float(values["particle_mass_kg"]),
            int(values["particles_full_cell"]))


def runs_particles_mass(runs: pd.DataFrame) -> Callable[[float], float]:
    """The particles' mass [kg] in the whole coupon against fill [%], as the DEM runs of one
    specimen simulated it (their cell count, particle mass and count taken as 100 %)."""
    from ..specimen import particles_for_fill

    _, _, per_particle, full = _runs_masses(runs)
    return lambda fill_percent: per_particle * particles_for_fill(float(fill_percent), full)


def runs_vibrated_mass(runs: pd.DataFrame) -> Callable[[float], float]:
    """m_c [kg] of Eq. 10 against fill [%], as the DEM runs of one specimen normalised their SDC.

    c_eq = SDC m_c w / (2 pi) recovers the dissipated energy only with the m_c the SDC was
    divided by. The runs' own specimen fixes it (their coupon and fixture masses, cell count,
    particle mass and the count taken as 100 % fill); the result is checked against each
    run's stored ``vibrated_mass_kg`` (a run of another specimen, or of a store written
    before these columns meant what they mean now, is refused, not mixed in).
    """
    from ..specimen import vibrated_mass_by_convention

    convention, rigid, _, _ = _runs_masses(runs)
    particles = runs_particles_mass(runs)

    def mass(fill_percent: float) -> float:
        return vibrated_mass_by_convention(convention, rigid_kg=rigid,
                                           particles_kg=particles(fill_percent))

    stored = runs["vibrated_mass_kg"].to_numpy(float)
    rebuilt = np.array([mass(f) for f in runs["fill_percent"].to_numpy(float)])
    # the same sums of the same stored numbers: equal to rounding
    bad = ~np.isclose(rebuilt, stored, rtol=1e-9, atol=0.0)
    if bad.any():
        k = int(np.flatnonzero(bad)[0])
        raise ParameterError(
            f"DEM run {runs['case_key'].iloc[k] if 'case_key' in runs else k}: stored m_c "
            f"{stored[k]:.6g} kg, but its specimen columns give {rebuilt[k]:.6g} kg; run it "
            "again")
    return mass


def equivalent_damper_table(model: SdcModel, *, fills_percent: Sequence[float] | None = None,
                            accelerations_g: Sequence[float] | None = None,
                            frequencies_hz: Sequence[float] | None = None,
                            vibrated_mass_kg: float | Callable[[float], float],
                            area_m2: float | None = None,
                            specimen: Specimen | None = None,
                            clip_to_range: bool = False,
                            panel_areal_mass_kg_m2: float | None = None,
                            panel_treated_fraction: float = 1.0,
                            particles_mass_kg: Callable[[float], float] | None = None,
                            fills: Sequence[float] | None = None,
                            accelerations: Sequence[float] | None = None,
                            frequencies: Sequence[float] | None = None) -> pd.DataFrame:
    """Equivalent damper over a grid of fill [%], acceleration [g] and frequency [Hz].

    Parameters
    ----------
    model : SdcModel
        SDC model.
    fills_percent, accelerations_g, frequencies_hz : sequence of float
        Values in %, g and Hz; the table is their Cartesian product, each value once (in the
        order given).
    vibrated_mass_kg : float or callable
        m_c [kg] of Eq. 10, or a function of fill [%] returning it (the particle mass grows
        with fill, and each fill's SDC was divided by its own m_c): a number is the m_c of
        one fill, and is refused with several ``fills_percent``. A number more than
        :data:`VIBRATED_MASS_LIMIT` times outside ``specimen``'s own m_c
        (:func:`vibrated_mass_range`: the paper coupon's at that fill, another specimen's
        from its empty coupon to its cells full) is refused as a unit slip (grams typed for
        kg), as ``pidcore model damper --vibrated-mass`` and
        :class:`~pidcore.model.TreatedMode` refuse it.
    area_m2 : float, optional
        Coupon area for the per-area damper; default :func:`specimen_area_m2` (the
        specimen's ``[coupon] face_area_m2``, the paper's 0.01 m^2, else its cells'
        cross-section). An area more
        than :data:`AREA_TO_CELLS_LIMIT` times off ``specimen``'s cells is refused as a unit
        slip (cm^2 or mm^2 typed for m^2), as ``pidcore model damper --area`` refuses it.
    specimen : pidcore.specimen.Specimen, optional
        The coupon the SDC and m_c are of (default: the paper's,
        :func:`pidcore.specimen.paper_specimen`; for stored DEM runs :func:`runs_specimen`):
        ``area_m2`` is checked against its cells, a number ``vibrated_mass_kg`` against its
        masses, ``c_eq_per_cell`` divides by their count.
    clip_to_range : bool
        Passed to :meth:`SdcModel.evaluate` (default: refuse points outside the model); the
        points it held at the edge are flagged in :data:`SDC_HELD_COLUMN`.
    panel_areal_mass_kg_m2 : float, optional
        A panel's mass per m^2 of face, with its particles: adds :data:`PANEL_COLUMNS`, its
        :func:`panel_loss_factor` (the panel moving as the coupon did). More than
        :data:`AREAL_MASS_LIMIT` times outside the coupons' own m_c / area is refused as a
        unit slip (g/m^2 typed for kg/m^2).
    panel_treated_fraction : float
        The share of that panel's area filled (default 1: all of it), in (0, 1].
    particles_mass_kg : callable, optional
        The particles' mass [kg] in the coupon against fill [%] (default
        :func:`specimen_particles_mass` of ``specimen``; for stored DEM runs
        :func:`runs_particles_mass`): a ``panel_areal_mass_kg_m2`` below that mass over the
        coupon area times ``panel_treated_fraction`` (a panel lighter than its own particles)
        is refused, naming both.
    fills, accelerations, frequencies : sequence of float, optional
        The names of pidcore 0.2, without their units (a ``DeprecationWarning``); giving
        both names of one axis is refused.

    Returns
    -------
    pandas.DataFrame
        Columns :data:`DAMPER_COLUMNS` (each names its unit); :data:`SDC_FILLED_COLUMN` (a
        bool flag) is True where the point's SDC rests on a filled hole of the model grid
        (:meth:`SdcModel.filled_dependence`; ``attrs[SDC_FILLED_NOTE]`` says on which and how
        far the SDC moves with it),
        :data:`SDC_HELD_COLUMN` where its SDC is an edge value held beyond the grid, and
        :data:`SDC_HELD_ERROR_COLUMN` which way that errs by the model's slope at the edge.
    """
    # one call each, not a loop: the warning points at the caller's line (stacklevel)
    fills = _one_name("fills_percent", fills_percent, "fills", fills)
    accelerations = _one_name("accelerations_g", accelerations_g, "accelerations",
                              accelerations)
    frequencies = _one_name("frequencies_hz", frequencies_hz, "frequencies", frequencies)
    # each value once, in the order given: a value typed twice gave two identical rows, which
    # an FEM table lookup of strictly increasing keys refuses (dem sweep runs each once too)
    fills, accelerations, frequencies = (list(dict.fromkeys(map(float, axis)))
                                         for axis in (fills, accelerations, frequencies))
    grid = pd.MultiIndex.from_product(
        [np.asarray(frequencies, float), np.asarray(accelerations, float),
         np.asarray(fills, float)], names=["f", "a", "p"]).to_frame(index=False)
    if grid.empty:
        raise ParameterError("equivalent_damper_table: fills, accelerations and frequencies "
                             "must each hold at least one value")
    f, a_g, p = (grid[c].to_numpy() for c in ("f", "a", "p"))
    if specimen is None:
        from ..specimen import paper_specimen

        specimen = paper_specimen()
    if area_m2 is None:
        area = specimen_area_m2(specimen)[0]
    else:
        # 100 (cm^2) for 0.01 m^2 gave a c_eq per area 1e4 x too small; only --area was checked
        area = float(_positive("area_m2", area_m2))
        check_area(area, specimen)
    # the points first: m_c is checked at their fills, which a fill of 150 % is none of
    sdc = model.evaluate(p, a_g, f, clip_to_range=clip_to_range)
    if callable(vibrated_mass_kg):
        mass = np.array([float(vibrated_mass_kg(x)) for x in p])
    else:
        # 69 (g) for 0.069 kg gave a c_eq 1000 x too large without a word; the CLI refused it
        check_vibrated_mass(float(_positive("vibrated_mass_kg", vibrated_mass_kg)), fills,
                            specimen=specimen)
        # the 50 % m_c at 25 and 90 % gave a c_eq 1.63 x too high and 0.62 x too low
        check_one_fill_per_mass(vibrated_mass_kg, fills)
        mass = np.full(p.shape, float(vibrated_mass_kg))
    mass = _positive("vibrated_mass_kg", mass)
    # a 20 g row carried the 10 g SDC and a c_eq from it, like a modelled one
    edges = [model.held_edges(*point) for point in zip(p, a_g, f, strict=True)]
    held = np.array([bool(e) for e in edges], dtype=bool)
    # the flag said a 20 g row was held at 10 g, not whether its damper is too high or too low
    held_error = [held_error_of(e) or "not held" for e in edges]
    a = _positive("acceleration [g]", a_g) * STANDARD_GRAVITY
    c_eq = equivalent_damping_coefficient(sdc, vibrated_mass_kg=mass, frequency_hz=f)
    # only the hole itself was flagged, though (90 %, 1.5 g, 1000 Hz) moves +0.67 per unit of
    # the value held there: every row whose SDC rests on a filled value is
    filled_dependence = model.filled_dependence(p, a_g, f, clip_to_range=clip_to_range)
    filled = filled_dependence.any
    out = pd.DataFrame({
        "frequency [Hz]": f,
        "acceleration [g]": a_g,
        PACKING_RATIO_COLUMN: p,
        "sdc [-]": sdc,
        SDC_FILLED_COLUMN: filled,
        SDC_HELD_COLUMN: held,
        SDC_HELD_ERROR_COLUMN: held_error,
        "coupon_loss_factor [-]": loss_factor(sdc),
        "coupon_damping_ratio [-]": damping_ratio(sdc),
        "coupon_vibrated_mass [kg]": mass,
        "coupon_area [m^2]": np.full(p.shape, area),
        "coupon_cells [-]": np.full(p.shape, specimen.cell.count, dtype=int),
        "coupon_energy_per_cycle [J]": energy_per_cycle(sdc, vibrated_mass_kg=mass,
                                                 acceleration_m_s2=a, frequency_hz=f),
        "displacement_amplitude [m]": displacement_amplitude(a, f),
        "velocity_amplitude [m/s]": a / (2.0 * np.pi * f),
        "c_eq_per_coupon [N s/m]": c_eq,
        "c_eq_per_treated_area [N s/m^3]": c_eq / area,
        "c_eq_per_cell [N s/m]": c_eq / specimen.cell.count,
    })
    if panel_areal_mass_kg_m2 is not None:
        mu = float(_positive("panel_areal_mass_kg_m2", panel_areal_mass_kg_m2))
        coupon = mass / area
        low, high = float(coupon.min()), float(coupon.max())
        if not low / AREAL_MASS_LIMIT <= mu <= high * AREAL_MASS_LIMIT:
            hint = "was it g/m^2?" if mu > high else "was it in another unit?"
            raise ParameterError(
                f"panel_areal_mass_kg_m2 {mu:g} kg/m^2 is {mu / (high if mu > high else low):.3g}"
                f" x the coupons' own areal mass ({low:.3g} .. {high:.3g} kg/m^2, m_c / "
                f"coupon area); expected the panel's mass per m^2 in kg/m^2; {hint}")
        # 0.5 kg/m^2 at 50 % fill was taken, though the particles alone are 7.66 kg per m^2
        # of the paper coupon: its loss factor was of a panel lighter than what it carries
        particles = particles_mass_kg or specimen_particles_mass(specimen)
        fraction = float(panel_treated_fraction)
        top = max(fills)  # the most particles: the areal mass grows with fill
        carried = particles(top) / area * fraction
        if mu < carried:
            several = f", the most of the fills {_fills_text(fills)} %" if len(fills) > 1 else ""
            raise ParameterError(
                f"panel_areal_mass_kg_m2 {as_given(mu)} kg/m^2 is less than its particles' "
                f"own {carried:.3g} kg/m^2 at {as_given(top)} % fill{several} "
                f"({particles(top):.3g} kg in the coupon's {area:.4g} m^2 x treated fraction "
                f"{fraction:g}); expected the panel's mass per m^2 with its particles"
                + (", at the fills it holds" if several else ""))
        out["panel_areal_mass [kg/m^2]"] = mu
        out["panel_treated_fraction [-]"] = float(panel_treated_fraction)
        out["panel_loss_factor [-]"] = panel_loss_factor(
            out["c_eq_per_treated_area [N s/m^3]"].to_numpy(), frequency_hz=f,
            panel_areal_mass_kg_m2=mu, treated_fraction=panel_treated_fraction)
    out.attrs[SDC_FILLED_NOTE] = filled_dependence.summary().replace("point(s)", "row(s)")
    return out


def _one_name(new: str, new_value: Sequence[float] | None, old: str,
              old_value: Sequence[float] | None) -> Sequence[float]:
    """The grid axis given under its name with the unit (``new``) or, warned, under the name
    pidcore 0.2 gave it (``old``); one of them, not both."""
    if new_value is not None and old_value is not None:
        raise ParameterError(f"{new} and {old} name the same axis; give {new} only")
    if old_value is not None:
        warnings.warn(f"equivalent_damper_table: {old}= is now {new}= (the unit in the name)",
                      DeprecationWarning, stacklevel=3)
        return old_value
    if new_value is None:
        raise TypeError(f"equivalent_damper_table() missing keyword argument: {new!r}")
    return new_value


def _json_value(value):
    if isinstance(value, (bool, np.bool_)):
        return bool(value)
    if isinstance(value, (int, np.integer)):
        return int(value)
    if isinstance(value, (float, np.floating)):
        return float(value) if np.isfinite(value) else None
    return value


def write_damper_table(table: pd.DataFrame, out_dir: str | Path, *,
                       formats: Sequence[str] = ("csv", "json"), stem: str = "equivalent_damper",
                       provenance: dict | None = None) -> list[Path]:
    """Write an :func:`equivalent_damper_table` as CSV and/or JSON; return the paths.

    JSON holds ``{"records": [...], "units": {column: unit}, "columns": {column: what it is},
    "provenance": {...}}`` (``columns``: :data:`DAMPER_COLUMN_MEANINGS`); NaN is written as
    ``null``.
    """
    unknown = sorted(set(formats) - {"csv", "json"})
    if unknown or not formats:
        raise ParameterError(f"formats: unknown {unknown or list(formats)}; expected csv, json")
    # every text made before any file is written, each file then replaced whole
    # (:func:`pidcore.atomic_files.write_atomically`): a Ctrl-C or a full disk leaves the
    # previous table, never half a CSV that reads as a shorter table
    texts: dict[Path, str] = {}
    out = Path(out_dir)
    if "csv" in formats:
        texts[out / f"{stem}.csv"] = table.to_csv(index=False)
    if "json" in formats:
        prov = {"pidcore_version": __version__,
                "created_utc": datetime.now(UTC).isoformat(timespec="seconds")}
        prov.update(provenance or {})
        # to_dict keeps full float precision (to_json rounds to 10 significant digits)
        records = [{k: _json_value(v) for k, v in row.items()}
                   for row in table.to_dict(orient="records")]
        units = {c: {**DAMPER_COLUMNS, **PANEL_COLUMNS}.get(c, "") for c in table.columns}
        meanings = {c: DAMPER_COLUMN_MEANINGS.get(c, "") for c in table.columns}
        texts[out / f"{stem}.json"] = json.dumps({"records": records, "units": units,
                                                  "columns": meanings, "provenance": prov},
                                                 indent=1)
    out.mkdir(parents=True, exist_ok=True)
    paths: list[Path] = []
    for path, text in texts.items():
        write_atomically(path, text)
        paths.append(path)
    return paths
