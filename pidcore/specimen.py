"""A test specimen: honeycomb cell, coupon masses, particles and contact pairs, read from TOML.

A specimen file (TOML, read with the standard library's :mod:`tomllib`) describes what the DEM
simulates and which mass a shaker moves. Units are in the key names (SI). Example (the paper's
coupon, ``pidcore/data/specimens/paper_coupon.toml``)::

    name = "paper_coupon"
    description = "Ahmad, Ranganath & Ghosal: 100 x 100 mm coupon, acrylic spheres"

    [cell]
    shape = "hexagonal"                # closed vocabulary (constants.CellShape)
    inscribed_diameter_m = 4.76e-3     # wall-to-wall distance across the flats
    height_m = 25.4e-3                 # core height (face sheet to face sheet)
    count = 441                        # cells in the coupon
    wall_material = "aluminium_wall"   # a materials.csv row, or inline:
    # wall_youngs_modulus_pa = 72e9
    # wall_poisson_ratio = 0.33
    # wall_density_kg_m3 = 2800.0      # walls move rigidly with the coupon: not used yet

    [coupon]
    mass_kg = 0.0221534                # face sheets + core, without particles
    fixture_mass_kg = 0.0              # moves with the coupon above the force gauge
    baseline_loss_factor = 0.0         # damping of the empty structure [-]
    face_area_m2 = 0.01                # optional: one face of the coupon (0.1 m x 0.1 m)

    [particles]
    material = "acrylic"               # a materials.csv row, or any name with inline:
    radius_m = 1.25e-3
    # density_kg_m3 = 1180.0
    # youngs_modulus_pa = 2.84e9
    # poisson_ratio = 0.402
    # count_per_cell = 11              # or fill_percent = 50.0 (optional: the specimen's fill)

    [pairs]
    # tangential_stiffness_model = "constant"  # or "mindlin": k_t = 8 G* sqrt(R* delta)
    #                                          # of the current overlap (both pairs)

    [pairs.particle_particle]
    restitution = 0.70
    sliding_friction = 0.096
    static_friction = 0.096            # >= sliding_friction
    rolling_friction = 0.0             # mu_r: largest rolling torque mu_r R* |f_n|
    rolling_damping_ratio = 0.0        # rolling dashpot, fraction of critical

    [pairs.particle_wall]
    restitution = 0.70
    sliding_friction = 0.14
    static_friction = 0.14
    rolling_friction = 0.0

``[coupon] face_area_m2`` (optional) is the area of one face of the coupon, m^2: the area
``pidcore model damper``'s ``c_eq_per_treated_area`` (and a panel's loss factor from it) is
per. A file that states none is taken over its cells' cross-section, ``[cell] count`` x one
hexagon (:meth:`Specimen.cells_area_m2`): one rule for every file, the paper's coupon stating
its 0.1 m x 0.1 m face (1.16 x its 441 cells). It is at least the cells' area (the cells lie
within the face) and at most :data:`MAX_FACE_TO_CELLS_AREA` times it (cm^2 or mm^2 typed for
m^2). It is no physics the DEM simulates: it is left out of the canonical text and hash
(:attr:`Specimen.text`), so stating it keeps a file's hash, its DEM runs and its recorded
tests; :meth:`Specimen.to_toml` writes it. Nor does it enter equality (``==``, as the hash).

A calibrated file (``pidcore calibrate``) also records which file it was made from, so that a
user's own ``paper_coupon.toml`` and the paper's coupon, which both calibrate to
``paper_coupon_calibrated``, are told apart (:func:`measured_specimen_name`)::

    [provenance]
    calibrated_from_name = "paper_coupon"
    calibrated_from_sha256 = "45d792..."   # Specimen.hash of that file (64 hex digits)

The table is part of the canonical text and hash (as ``name`` and ``description`` are): two
calibrated files of one set of numbers made from different files model different tests, and
their runs are not pooled. A file without it (every other file, and calibrated files written
before it existed) keeps its text and hash.

A material named in the table fills the properties not given inline; the parsed
:class:`Specimen` always holds the resolved numbers, so its canonical text
(:attr:`Specimen.text`) and :attr:`Specimen.hash` describe the physics completely, whatever the
tables say later. ``[pairs] tangential_stiffness_model`` (``"constant"``, the default, or
``"mindlin"``) appears in the canonical text only when it is ``"mindlin"``: files that do not
set it keep the hash they had before the key existed. Every numeric field (and that key) is
addressable by a dotted path (``"pairs.particle_wall.static_friction"``, ``"particles.radius_m"``,
``"pairs.tangential_stiffness_model"``) for :meth:`Specimen.with_values`.

Public API
----------
load_specimen, paper_specimen, Specimen
    A specimen from a TOML file (or a bundled one by its name), the bundled paper coupon;
    ``Specimen.from_text``, ``with_values``, ``to_toml``, ``capacity_per_cell``.
bundled_specimen_names
    The specimen files bundled with the package, which :func:`load_specimen` takes by name.
is_paper_coupon, measured_specimen_name, models_paper_coupon, hashed_name, tested_label
    Whether a specimen (by hash, else by name) is the paper's coupon: the one rule; the name
    a measurement of a specimen file is saved under; whether a file models the coupon; a
    file's name with its hash, ``"name [45d792]"``, and a test's saved specimen so labelled.
tabulated_by_paper
    Whether Table 3 is compared with a specimen file's tests (as with a row of them).
HASH_OF_WHAT
    What a specimen's sha256 is of (its canonical text, not the file's bytes), for notes.
measured_specimen_sha256, MEASURED_SHA256_FIELD, deciding_sha256, same_tested_file
    The file's hash saved beside that name (record field ``specimen_sha256``), and how a
    measurement's recorded hash meets a DEM run's or a calibration's: by hash where both
    know it, else by name (a record saved before the hash was).
match_hashless_records, NameMatch
    The one rule for a record saved with a name but no hash beside hashed records of that
    name: joined to their one file, or kept apart where the name means two files.
resolve_specimen_name, NamedSpecimen
    The known file a typed specimen name means (the app's settings grid), saved with its
    name and hash as ``analyze --specimen`` saves it; else by name, saying so.
calibrated_name, uncalibrated_name, calibrated_provenance, ProvenanceSpec, provenance_test_name
    What ``pidcore calibrate`` names the file it writes, the name it was made from, the
    ``[provenance]`` table recording the source file's name and sha256, and the name of the
    source's tests where that table tells it from the paper's coupon.
CellSpec, CouponSpec, ParticleSpec, PairSpec, PairsSpec
    Its sections (SI units in the field names).
describe, heavy_fixture_note, column_note
    What follows from it: capacity, masses, contact numbers, time step; the notes a run of it
    repeats (a fixture far heavier than the coupon, spheres that fit only as a column).
particles_for_fill, same_particles_per_cell
    Particles per cell of a fill percentage (the one rounding rule); whether two fills are
    the same particles per cell, so one DEM simulation.
cell_geometry, contact_law
    The DEM's cell geometry and contact law of a specimen.
numeric_fields
    Dotted paths of its numeric fields (what calibration can fit).
bundled_face_area
    A specimen rebuilt from its canonical text (a stored run's), with the ``[coupon]
    face_area_m2`` of the bundled file of its hash (the paper's coupon) that the text leaves
    out.
CALIBRATED_SPECIMEN_FILE, finish_calibration_moves, hearing_read_notes
    The calibrated specimen file of a ``pidcore calibrate --out`` folder; the moves a killed
    calibration left in that folder, finished before it is read (:func:`load_specimen` does
    so for that file); who hears the note a load makes of it (the CLI, the app).
"""

from __future__ import annotations

import codecs
import contextvars
import dataclasses
import functools
import hashlib
import math
import os
import re
import sys
import tomllib
from collections.abc import Callable, Iterator, Mapping, Sequence
from contextlib import contextmanager
from dataclasses import dataclass
from importlib import resources
from pathlib import Path
from typing import TYPE_CHECKING, Any

from .constants import (
    CELL_SHAPES,
    FILL_REFERENCES,
    TANGENTIAL_STIFFNESS_MODELS,
    CellShape,
    ImpactPair,
    NormalDampingMode,
    TangentialStiffnessModel,
)
from .errors import MAX_SHOWN_CHARS, ParameterError, apart, as_given, clipped, real_number
from .loadcase import normalize_material

if TYPE_CHECKING:  # pragma: no cover
    from .dem.contact import ContactLaw
    from .dem.geometry import CellGeometry

#: Version of the specimen schema written by :meth:`Specimen.to_toml`.
SCHEMA_VERSION = 1
#: k_t model of a specimen that states none; left out of the canonical text (hash unchanged).
DEFAULT_TANGENTIAL_STIFFNESS_MODEL: TangentialStiffnessModel = "constant"
#: The paper's coupon, bundled with the package.
PAPER_SPECIMEN_NAME = "paper_coupon"
#: What a specimen's sha256 (:attr:`Specimen.hash`) is of, and how to see it, for notes: it
#: was said to be "its file's sha256" and runs reused "for the same file content", though
#: ``sha256sum`` of the file gives another value and a comment or ``5e-2`` for ``0.050``
#: changes no run.
HASH_OF_WHAT = ("the sha256 of its canonical text: every value as resolved, its name and "
                "description included; not comments, layout, number formatting (0.050 or "
                "5e-2) or the file's name (the JSON of pidcore specimen check prints it as "
                "sha256)")
#: Largest specimen file read, bytes. A specimen is ~1 kB (the bundled files 1-2 kB with their
#: comments); 256 KiB is a 3000-line file. Beyond it the file is not a specimen: a 4 MB file of
#: one array took 12 s to parse before its key was refused, and /dev/zero was read until
#: memory ran out (a MemoryError traceback).
MAX_SPECIMEN_FILE_BYTES = 256 * 1024


def _fail(where: str, message: str) -> ParameterError:
    return ParameterError(f"{where}: {message}")


class StaticBelowSlidingError(ParameterError):
    """A pair's static friction is below its sliding friction. ``pair`` names the pair
    (``"particle_wall"``), so that :meth:`Specimen.with_values` can tell the user which key to
    set too without reading the message's text."""

    def __init__(self, message: str, *, pair: str) -> None:
        super().__init__(message)
        self.pair = pair


def _printable(where: str, text: str) -> None:
    """Refuse a name holding a control character or a lone surrogate (TOML allows both as
    escapes): the name goes into every stored run's record, where HDF5 can hold neither
    ("VLEN strings do not support embedded NULLs": `dem run --store` lost its finished
    simulation to that traceback at the commit), and into reports."""
    bad = next((c for c in text if ord(c) < 32 or ord(c) == 127 or 0xD800 <= ord(c) <= 0xDFFF),
               None)
    if bad is not None:
        raise _fail(where, f"expected a name of printable characters, got {_shown(text)} "
                           f"(it holds {bad!r})")


def _shown(value: object) -> str:
    """A refused value for a message, as Python writes it (clipped: :func:`clipped`)."""
    if isinstance(value, int) and not isinstance(value, bool):
        return _large_count(value)  # repr refuses more than 4300 digits
    if isinstance(value, list | tuple) and len(repr(value)) > MAX_SHOWN_CHARS:
        return f"an array of {len(value)} items ({clipped(repr(value))})"
    return clipped(repr(value))


def _check_particle_material_name(where: str, name: str) -> None:
    """Refuse a particle material name that a load case cannot carry as written: every run,
    file name and sidecar states the material in its canonical form (``normalize_material``),
    so ``"Acrylic"``, ``"PMMA"`` or ``"tungsten carbide"`` passed ``specimen check`` and were
    then refused by ``dem run`` as a clash with ``--material``, which nobody had given."""
    try:
        canonical = normalize_material(name, where, known=None)
    except ParameterError:
        suggestion = re.sub(r"[^a-z0-9_]+", "_", name.strip().lower()).strip("_")
        raise _fail(where, f"{_shown(name)} is not a material name a load case can carry; "
                           "expected lower-case letters, digits and '_' starting with a letter"
                           + (f" (e.g. {suggestion!r})" if re.match(r"^[a-z]", suggestion)
                              else "")) from None
    if canonical != name:
        raise _fail(where, f"{_shown(name)} is written {canonical!r} in load cases, file names "
                           f"and stored runs; write material = \"{canonical}\"")


def _large_count(count: int) -> str:
    """A whole number of any size for a message (``:g`` overflows past 1e308)."""
    if count < 10**15:
        return str(count)
    if count < 10**300:
        return f"{count:.3g}"
    # str() of an int refuses more than 4300 digits; the bit length gives the exponent
    return f"about 10^{int((count.bit_length() - 1) * math.log10(2))}"


def _positive(where: str, value: float, unit: str) -> None:
    if not (math.isfinite(value) and value > 0):
        raise _fail(where, f"expected > 0 {unit}, got {value!r}")


def _non_negative(where: str, value: float, unit: str) -> None:
    if not (math.isfinite(value) and value >= 0):
        raise _fail(where, f"expected >= 0 {unit}, got {value!r}")


@dataclass(frozen=True)
class PlausibleRange:
    """Bounds (SI) a specimen value must lie within, and the unit slip a value beyond suggests."""

    low: float
    high: float
    unit: str
    what: str
    below: str = ""  # likely slip of a value below ``low``
    above: str = ""  # likely slip of a value above ``high``
    kind: str = ""  # what a value is, in messages (default: from ``unit``)


#: Generous physical bounds of specimen values. A value outside is almost surely in the wrong
#: unit (mm for m, g for kg, MPa for Pa, g/cm^3 for kg/m^3): it would give numbers that look
#: fine but are wrong, or a packing too large to compute, so it is refused. The bounds hold
#: every real honeycomb specimen and particle material with room to spare:
PLAUSIBLE_RANGES: dict[str, PlausibleRange] = {
    # cells: from micro-cell cores (~1 mm) to a single large cavity; 0.5 mm-1 m
    "inscribed_diameter_m": PlausibleRange(0.5e-3, 1.0, "m", "a cell is 0.5 mm-1 m across",
                                           above="was it mm?"),
    "height_m": PlausibleRange(0.5e-3, 1.0, "m", "a core is 0.5 mm-1 m high",
                               above="was it mm?"),
    # particles: fine shot (0.1 mm) to large balls (50 mm); finer powder is not DEM territory
    "radius_m": PlausibleRange(0.05e-3, 25e-3, "m", "a particle radius is 0.05-25 mm",
                               above="was it mm?"),
    # densities: polymer foam beads (~15 kg/m^3) to osmium (22590 kg/m^3)
    "density_kg_m3": PlausibleRange(10.0, 25000.0, "kg/m^3",
                                    "a solid is 10-25000 kg/m^3", below="was it g/cm^3?"),
    # Young's modulus: soft rubber (~1 MPa) to diamond (1.2e12 Pa); a softer sphere overlaps
    # by a sizeable part of its radius at shaker-test impact speeds, where Hertz's law fails
    "youngs_modulus_pa": PlausibleRange(1e6, 1.5e12, "Pa", "a solid is 1e6-1.5e12 Pa",
                                        below="was it MPa or GPa?"),
    # a coupon a shaker carries weighs grams to kilograms; 100 kg is a large panel
    "mass_kg": PlausibleRange(0.0, 100.0, "kg", "a coupon is up to 100 kg", above="was it g?"),
    # a fixture (adapter plate, head expander) may be heavy, but not more than a shaker lifts
    "fixture_mass_kg": PlausibleRange(0.0, 1000.0, "kg", "a fixture is up to 1000 kg",
                                      above="was it g?"),
    # the empty coupon's loss factor (Re/Im of its complex power, 2 x damping ratio): metal
    # honeycomb sandwiches are ~0.001-0.01, and even the most lossy viscoelastic layers reach
    # about 1 only at their glass transition. Above 1 the empty coupon would dissipate more
    # per radian than it stores, a damper rather than the mass-like structure the analysis
    # assumes; such a value is a percentage (5 for 0.05; calibrate's prior is 0-0.05)
    "baseline_loss_factor": PlausibleRange(0.0, 1.0, "", "the empty coupon's loss factor is "
                                           "0-1, metal sandwiches ~0.001-0.01",
                                           above="was it %?"),
    # Coulomb coefficients of dry solids: ~0.05 (PTFE) to ~1.5 (clean metals in vacuum,
    # rubber); 2 leaves room. A larger number is a percentage or an angle in degrees
    "friction": PlausibleRange(0.0, 2.0, "", "a friction coefficient is 0-2, dry solids "
                               "~0.05-1.5", above="was it % or an angle?",
                               kind="a coefficient"),
    # rolling resistance coefficients (torque / (R* F_n)): ~0.001 (steel balls) to ~0.3
    # (rough or angular grains); 1 would resist rolling as a sphere's own lever arm does
    "rolling_friction": PlausibleRange(0.0, 1.0, "", "a rolling friction coefficient is 0-1, "
                                       "real spheres ~0.001-0.3", above="was it %?",
                                       kind="a coefficient"),
    # the rolling dashpot as a fraction of its critical value: 0-1 (LIGGGHTS epsd2 ~0.3). An
    # overdamped one is also beyond the explicit integration: 30 (a percentage) left a 23-particle
    # bed of 2 mm spheres still moving after 1 s of settling, and the run failed
    "rolling_damping_ratio": PlausibleRange(0.0, 1.0, "", "a rolling damping ratio is 0-1, "
                                            "typically ~0.3", above="was it %?",
                                            kind="a fraction of critical"),
}
#: Most coupon mass per coupon area (``[cell] count`` cells' cross-section), kg/m^2: a 127 mm
#: steel plate. Sandwich panels weigh 1-20 kg/m^2 (the paper's 2.6); more is a mass in grams
#: or a cell count that does not describe the coupon.
MAX_COUPON_AREAL_MASS_KG_M2 = 1000.0
#: Most coupon area (``[cell] count`` cells' cross-section), m^2: the largest shaker slip
#: tables and head expanders are about 2 x 2 m, so 100 m^2 leaves room for any coupon. More is
#: a cell count that does not describe a coupon (10^20 cells of 6.35 mm passed, and a run of
#: them simulated to the end before the store refused to save its count).
MAX_COUPON_AREA_M2 = 100.0
#: Most a stated ``[coupon] face_area_m2`` may be of its cells' cross-section (``[cell] count``
#: x one hexagon): cm^2 or mm^2 typed for m^2 is 1e4 or 1e6 times off, while a coupon with a
#: wide unfilled margin, or the paper's 0.01 m^2 over its 441 cells (1.16 x), stays well within.
#: The same bound as a coupon area given to the damper (:data:`pidcore.model.damper.
#: AREA_TO_CELLS_LIMIT`).
MAX_FACE_TO_CELLS_AREA = 100.0
#: Relative slack of "face area >= cells' area": a face area written to 15 digits from the
#: cells' own may round below it in the last bit.
_FACE_AREA_RTOL = 1e-12
PLAUSIBLE_RANGES["wall_density_kg_m3"] = PLAUSIBLE_RANGES["density_kg_m3"]
PLAUSIBLE_RANGES["wall_youngs_modulus_pa"] = PLAUSIBLE_RANGES["youngs_modulus_pa"]


#: Largest normal restitution a pair may state (1: an elastic impact; more gains energy).
MAX_RESTITUTION = 1.0
#: Pair fields checked against one :data:`PLAUSIBLE_RANGES` entry of another name.
_PAIR_RANGE_KEYS = {"sliding_friction": "friction", "static_friction": "friction"}


def field_domain(path: str) -> tuple[float, float]:
    """Closed range a numeric field (dotted path, e.g. ``pairs.particle_wall.restitution``)
    must lie within by a rule of its own: 0 < restitution <= :data:`MAX_RESTITUTION`, or its
    :data:`PLAUSIBLE_RANGES` entry (frictions 0..2, ...); (-inf, inf) where the file checks it
    only against other fields or by an open bound (a particle that fits its cell, Poisson's
    ratio < 0.5)."""
    leaf = path.rpartition(".")[2]
    if leaf == "restitution":
        return math.nextafter(0.0, 1.0), MAX_RESTITUTION
    key = _PAIR_RANGE_KEYS.get(leaf, leaf) if path.startswith("pairs.") else leaf
    r = PLAUSIBLE_RANGES.get(key)
    return (r.low, r.high) if r is not None else (-math.inf, math.inf)


def _plausible(where: str, key: str, value: float) -> None:
    """Refuse a (finite, signed-checked) value outside :data:`PLAUSIBLE_RANGES` of ``key``."""
    r = PLAUSIBLE_RANGES[key]
    if r.low <= value <= r.high:
        return
    hint = r.below if value < r.low else r.above
    unit = r.kind or {"m": "metres", "kg": "kilograms", "Pa": "pascals",
                      "": "a fraction"}.get(r.unit, r.unit)
    shown = f"{as_given(value)} {r.unit}".rstrip()  # a ratio has no unit to show
    raise _fail(where, f"{shown}: expected {unit} ({r.what})" + (f"; {hint}" if hint else ""))


#: Fastest bar wave speed sqrt(E / rho) of any solid, m/s: diamond's is 18.5 km/s (E 1.2e12 Pa,
#: 3515 kg/m^3), beryllium's 12.5 km/s, steel's 5 km/s. Each of E and rho alone may lie within
#: its range with the other in the wrong unit: tungsten carbide's 15.6 g/cm^3 typed as 15.6
#: kg/m^3 beside its 600 GPa is 196 km/s (a 1000 x lighter particle, silently simulated).
#: Checked for the particles only: the walls are rigid and their density is unused, and a
#: honeycomb's bulk core density (32.1 kg/m^3 in the paper's Table 2) beside its foil's
#: modulus is a reasonable thing to write there.
MAX_BAR_WAVE_SPEED_M_S = 2.0e4


def _wave_speed(where: str, *, density_key: str, density_kg_m3: float,
                modulus_key: str, youngs_modulus_pa: float) -> None:
    """Refuse a density and Young's modulus no solid combines (one is in the wrong unit)."""
    speed = math.sqrt(youngs_modulus_pa / density_kg_m3)
    if speed <= MAX_BAR_WAVE_SPEED_M_S:
        return
    raise _fail(f"{where} {density_key}",
                f"{as_given(density_kg_m3)} kg/m^3 with {modulus_key} "
                f"{as_given(youngs_modulus_pa)} Pa gives a bar wave speed sqrt(E/rho) of "
                f"{speed / 1e3:.3g} km/s; expected a solid's, at most "
                f"{MAX_BAR_WAVE_SPEED_M_S / 1e3:g} km/s (diamond 18.5 km/s); was the density "
                "in g/cm^3, or the modulus in the wrong unit?")


def _poisson(where: str, value: float) -> None:
    if not (math.isfinite(value) and -1.0 < value < 0.5):
        raise _fail(where, f"expected -1 < nu < 0.5, got {value!r}")


#: Largest fill, %, that is refused as ambiguous where it holds a particle: a fraction (0.3,
#: 0.7, 1) typed for a percentage (30 %, 70 %, 100 %) lies at or below it.
MAX_AMBIGUOUS_FILL_PERCENT = 1.0


def filled_share(fill_percent: float, count: int, full: int) -> str:
    """", 72.7 % filled" where ``count`` of ``full`` particles (the fill rounded,
    :func:`particles_for_fill`) is not the ``fill_percent`` stated; "" where it is."""
    share = 100.0 * count / full
    return "" if math.isclose(share, fill_percent, rel_tol=1e-9) else f", {share:.3g} % filled"


def particles_for_fill(fill_percent: float, full: int, *, what: str = "fill_percent",
                       typed: bool = False) -> int:
    """Particles per cell of a fill percentage of ``full`` (the count taken as 100 %).

    The one rounding rule of a fill, for ``specimen check`` and ``dem run`` alike: the nearest
    count, a half to the even one (Python's :func:`round`: 25 % of 22 is 5.5 -> 6, 75 % is 16.5
    -> 16; kept, as every stored run and the bundled grid were made with it); the share the
    count makes is printed beside a fill it differs from. A fill that
    rounds to no particle is refused (an empty cell damps nothing, and its SDC is 0/0).
    ``what``: how the refusal names the fill, by default the keyword a Python caller gave it
    by (a front end passes its own: ``--fill``, or ``fill`` where its message says where the
    fill came from). ``typed``: the fill is one a person wrote (a specimen's
    ``fill_percent``, ``--fill``, a file name, a sidecar or data table), where one of at most
    :data:`MAX_AMBIGUOUS_FILL_PERCENT` that holds a particle is refused too, as a fraction
    typed for a percentage; a count's own share (``count_per_cell``) is not typed, and
    :func:`pidcore.dem.simulate.particles_per_cell` takes a specimen stating that count as
    confirming a typed fill of it.
    """
    fill_percent = real_number(what, fill_percent)
    if not math.isfinite(fill_percent):
        raise ParameterError(f"{what} {fill_percent} %: expected a finite percentage")
    if fill_percent > 100.0:  # 150 % gave 1.5 full cells of particles, more than fit
        raise ParameterError(f"{what} {as_given(fill_percent)} %: more than a full cell; "
                             "expected a packing ratio in (0, 100] %")
    n = int(round(fill_percent / 100.0 * full))
    if n < 1:
        # the smallest fill shown on a 0.01 % step strictly above half a particle: rounds to 1
        least = math.floor(5000.0 / full) / 100 + 0.01
        # a fraction typed for a percentage (0.5 for 50 %), offered only where x100 is a fill
        # that holds a particle (1e-9 as 1e-7 % holds none either)
        hint = (f"; was {as_given(fill_percent)} meant as {fill_percent * 100:g} %?"
                if 0 < fill_percent <= 1.0 and round(fill_percent * full) >= 1 else "")
        expected = f">= {least:.2f} %"
        if typed and least <= MAX_AMBIGUOUS_FILL_PERCENT:
            # "expected >= 0.15 %" sent the user to 0.15, then refused as read as a fraction
            expected = (f"> {MAX_AMBIGUOUS_FILL_PERCENT:g} % (a smaller one reads as a "
                        "fraction; for so few particles a specimen file states [particles] "
                        "count_per_cell)")
        raise ParameterError(f"{what} {as_given(fill_percent)} % of {full} particles rounds to "
                             f"none; expected {expected}{hint}")
    if typed and fill_percent <= MAX_AMBIGUOUS_FILL_PERCENT:
        # in a cell of more than 50 particles 0.7 (70 % as a fraction) holds one or more, and
        # ran silently at 3 of 441 particles where 309 were meant
        raise ParameterError(
            f"{what} {as_given(fill_percent)} % is {n} of {full} particles per cell; a fill of "
            f"at most {MAX_AMBIGUOUS_FILL_PERCENT:g} % reads as a fraction: was "
            f"{as_given(fill_percent)} meant as {fill_percent * 100:g} %? (for so few "
            f"particles, a specimen file stating [particles] count_per_cell = {n} confirms "
            "it)")
    return n


@dataclass(frozen=True)
class CellSpec:
    """The honeycomb cell (SI): shape, size, count in the coupon, wall elasticity."""

    shape: CellShape
    inscribed_diameter_m: float
    height_m: float
    count: int
    wall_material: str
    wall_youngs_modulus_pa: float
    wall_poisson_ratio: float
    wall_density_kg_m3: float

    def __post_init__(self):
        if self.shape not in CELL_SHAPES:
            raise _fail("[cell] shape",
                        f"expected one of {CELL_SHAPES}, got {_shown(self.shape)}")
        _positive("[cell] inscribed_diameter_m", self.inscribed_diameter_m, "m")
        _plausible("[cell] inscribed_diameter_m", "inscribed_diameter_m",
                   self.inscribed_diameter_m)
        _positive("[cell] height_m", self.height_m, "m")
        _plausible("[cell] height_m", "height_m", self.height_m)
        if isinstance(self.count, bool) or not isinstance(self.count, int) or self.count < 1:
            raise _fail("[cell] count", f"expected a whole number >= 1, got {self.count!r}")
        _positive("[cell] wall_youngs_modulus_pa", self.wall_youngs_modulus_pa, "Pa")
        _plausible("[cell] wall_youngs_modulus_pa", "wall_youngs_modulus_pa",
                   self.wall_youngs_modulus_pa)
        _poisson("[cell] wall_poisson_ratio", self.wall_poisson_ratio)
        _positive("[cell] wall_density_kg_m3", self.wall_density_kg_m3, "kg/m^3")
        _plausible("[cell] wall_density_kg_m3", "wall_density_kg_m3", self.wall_density_kg_m3)


@dataclass(frozen=True)
class CouponSpec:
    """Masses a shaker moves besides the particles (kg), the empty structure's damping, and
    the area of one face of the coupon (m^2; None: not stated, its cells' area is taken)."""

    mass_kg: float
    fixture_mass_kg: float = 0.0
    baseline_loss_factor: float = 0.0
    # not in the canonical text nor the hash, so not in equality either: a specimen rebuilt
    # from a stored run's text is the specimen that ran
    face_area_m2: float | None = dataclasses.field(default=None, compare=False)

    def __post_init__(self):
        if self.face_area_m2 is not None:
            # against the cells in Specimen: this record does not know them
            _positive("[coupon] face_area_m2", self.face_area_m2, "m^2")
        _positive("[coupon] mass_kg", self.mass_kg, "kg")
        _plausible("[coupon] mass_kg", "mass_kg", self.mass_kg)
        _non_negative("[coupon] fixture_mass_kg", self.fixture_mass_kg, "kg")
        _plausible("[coupon] fixture_mass_kg", "fixture_mass_kg", self.fixture_mass_kg)
        _non_negative("[coupon] baseline_loss_factor", self.baseline_loss_factor, "[-]")
        _plausible("[coupon] baseline_loss_factor", "baseline_loss_factor",
                   self.baseline_loss_factor)

    @property
    def moving_mass_kg(self) -> float:
        """Coupon plus fixture: the rigid mass above the force gauge, kg."""
        return self.mass_kg + self.fixture_mass_kg


@dataclass(frozen=True)
class ParticleSpec:
    """Spherical particles (SI); the fill is optional (a load case usually states it)."""

    material: str
    radius_m: float
    density_kg_m3: float
    youngs_modulus_pa: float
    poisson_ratio: float
    count_per_cell: int | None = None
    fill_percent: float | None = None

    def __post_init__(self):
        if not self.material or not isinstance(self.material, str):
            raise _fail("[particles] material",
                        f"expected a name, got {_shown(self.material)}")
        _printable("[particles] material", self.material)
        _check_particle_material_name("[particles] material", self.material)
        _positive("[particles] radius_m", self.radius_m, "m")
        _plausible("[particles] radius_m", "radius_m", self.radius_m)
        _positive("[particles] density_kg_m3", self.density_kg_m3, "kg/m^3")
        _plausible("[particles] density_kg_m3", "density_kg_m3", self.density_kg_m3)
        _positive("[particles] youngs_modulus_pa", self.youngs_modulus_pa, "Pa")
        _plausible("[particles] youngs_modulus_pa", "youngs_modulus_pa", self.youngs_modulus_pa)
        _wave_speed("[particles]", density_key="density_kg_m3", density_kg_m3=self.density_kg_m3,
                    modulus_key="youngs_modulus_pa", youngs_modulus_pa=self.youngs_modulus_pa)
        _poisson("[particles] poisson_ratio", self.poisson_ratio)
        if self.count_per_cell is not None and self.fill_percent is not None:
            raise _fail("[particles]", "give count_per_cell or fill_percent, not both")
        if self.count_per_cell is not None and (
                isinstance(self.count_per_cell, bool) or not isinstance(self.count_per_cell, int)
                or self.count_per_cell < 1):
            raise _fail("[particles] count_per_cell",
                        f"expected a whole number >= 1, got {_shown(self.count_per_cell)}")
        if self.fill_percent is not None and not (0 < self.fill_percent <= 100):
            raise _fail("[particles] fill_percent",
                        f"expected 0 < fill <= 100 %, got {self.fill_percent!r}")

    @property
    def mass_kg(self) -> float:
        """Mass of one sphere, kg."""
        return self.density_kg_m3 * 4.0 / 3.0 * math.pi * self.radius_m**3


@dataclass(frozen=True)
class PairSpec:
    """Contact parameters of one pair of materials [-]."""

    restitution: float
    sliding_friction: float
    static_friction: float
    rolling_friction: float = 0.0
    rolling_damping_ratio: float = 0.0

    def check(self, where: str) -> None:
        """Raise a ParameterError naming ``where`` if a value is out of range."""
        if not (math.isfinite(self.restitution) and 0 < self.restitution <= MAX_RESTITUTION):
            raise _fail(f"{where} restitution",
                        f"expected 0 < e <= 1, got {self.restitution!r}")
        _non_negative(f"{where} sliding_friction", self.sliding_friction, "[-]")
        _plausible(f"{where} sliding_friction", "friction", self.sliding_friction)
        _non_negative(f"{where} static_friction", self.static_friction, "[-]")
        _plausible(f"{where} static_friction", "friction", self.static_friction)
        _non_negative(f"{where} rolling_friction", self.rolling_friction, "[-]")
        _plausible(f"{where} rolling_friction", "rolling_friction", self.rolling_friction)
        _non_negative(f"{where} rolling_damping_ratio", self.rolling_damping_ratio, "[-]")
        _plausible(f"{where} rolling_damping_ratio", "rolling_damping_ratio",
                   self.rolling_damping_ratio)
        if self.static_friction < self.sliding_friction:
            raise StaticBelowSlidingError(
                f"{where} static_friction: {self.static_friction!r} is below sliding_friction "
                f"{self.sliding_friction!r}; expected static >= sliding",
                pair=where.strip("[]").rpartition(".")[2])


@dataclass(frozen=True)
class PairsSpec:
    """The two contact pairs of a one-material bed: particle-particle and particle-wall.

    ``tangential_stiffness_model``: k_t of both pairs' stick-slip spring, ``"constant"``
    (Mindlin's 8 G* sqrt(R* delta_ref) at a reference overlap) or ``"mindlin"`` (of the
    current overlap), see :class:`pidcore.dem.contact.ContactLaw`.
    """

    particle_particle: PairSpec
    particle_wall: PairSpec
    tangential_stiffness_model: TangentialStiffnessModel = DEFAULT_TANGENTIAL_STIFFNESS_MODEL

    def __post_init__(self):
        self.particle_particle.check("[pairs.particle_particle]")
        self.particle_wall.check("[pairs.particle_wall]")
        if self.tangential_stiffness_model not in TANGENTIAL_STIFFNESS_MODELS:
            raise _fail("[pairs] tangential_stiffness_model",
                        f"expected one of {TANGENTIAL_STIFFNESS_MODELS}, "
                        f"got {_shown(self.tangential_stiffness_model)}")


#: A sha256 as :attr:`Specimen.hash` writes it: 64 lowercase hexadecimal digits.
_SHA256_DIGITS = frozenset("0123456789abcdef")


@dataclass(frozen=True)
class ProvenanceSpec:
    """Which specimen file a calibrated one was made from (``[provenance]``, written by
    ``pidcore calibrate``): the tested specimen's ``name`` and :attr:`Specimen.hash`.

    The name alone cannot say it: a user's own ``paper_coupon.toml`` (another cell, another
    mass) calibrates to ``paper_coupon_calibrated`` as the paper's coupon does, and its tests
    are saved as ``"paper_coupon [45d792]"`` (:func:`measured_specimen_name`); the hash tells
    the two apart.
    """

    calibrated_from_name: str
    calibrated_from_sha256: str

    def __post_init__(self):
        if not isinstance(self.calibrated_from_name, str) or not self.calibrated_from_name:
            raise _fail("[provenance] calibrated_from_name",
                        f"expected a non-empty name, got {_shown(self.calibrated_from_name)}")
        _printable("[provenance] calibrated_from_name", self.calibrated_from_name)
        sha = self.calibrated_from_sha256
        if not isinstance(sha, str) or len(sha) != 64 or not set(sha) <= _SHA256_DIGITS:
            raise _fail("[provenance] calibrated_from_sha256",
                        f"expected the sha256 of the specimen it was calibrated from (64 "
                        f"lowercase hexadecimal digits), got {_shown(sha)}")


@dataclass(frozen=True)
class Specimen:
    """A honeycomb specimen: cell, coupon, particles, contact pairs (see the module docstring).

    Build with :func:`load_specimen`, :meth:`from_text` or :func:`paper_specimen`; derive
    variants with :meth:`with_values`. ``source`` (where it was read from) is not part of the
    specimen's identity: :attr:`hash` is that of the canonical text.
    """

    name: str
    cell: CellSpec
    coupon: CouponSpec
    particles: ParticleSpec
    pairs: PairsSpec
    description: str = ""
    provenance: ProvenanceSpec | None = None
    source: str = dataclasses.field(default="<specimen>", compare=False)
    #: What reading the file did first, to be said to the user ("" where nothing): the note
    #: of a killed calibration's moves finished in the folder of a calibrated specimen file
    #: (:func:`load_specimen`). Not part of the specimen's identity.
    read_note: str = dataclasses.field(default="", compare=False, repr=False)

    def __post_init__(self):
        if not isinstance(self.name, str) or not self.name:
            raise _fail("name", f"expected a non-empty name, got {_shown(self.name)}")
        _printable("name", self.name)
        from .dem.geometry import check_packing_size, check_sphere_fits

        r = self.particles.radius_m
        geometry = self.geometry()
        try:
            # the packing's own limit (a sphere strictly narrower than the cell, clearing
            # floor and ceiling by its gap): a looser one let a near fit through to fail there
            check_sphere_fits(geometry, r)
        except ParameterError as exc:
            raise _fail("[particles] radius_m", str(exc)) from None
        cell_area = float(geometry.volume_m3() / self.cell.height_m)
        # an int compares with a float exactly: a count of thousands of digits is refused here
        # rather than overflowing the float product below (a traceback)
        if self.cell.count > MAX_COUPON_AREA_M2 / cell_area:
            raise _fail("[cell] count",
                        f"{_large_count(self.cell.count)} cells of {cell_area * 1e6:.4g} mm^2 "
                        f"are more than {MAX_COUPON_AREA_M2:g} m^2 of coupon; expected the "
                        "number of cells in the coupon (a shaker-test coupon is at most a few "
                        "m^2)")
        area = self.cells_area_m2(geometry)
        self._check_face_area(area)
        if self.coupon.mass_kg / area > MAX_COUPON_AREAL_MASS_KG_M2:
            raise _fail("[coupon] mass_kg",
                        f"{as_given(self.coupon.mass_kg)} kg on {self.cell.count} cells "
                        f"({area * 1e4:.4g} cm^2) is {self.coupon.mass_kg / area:.4g} kg/m^2; "
                        f"expected kilograms (a coupon is up to "
                        f"{MAX_COUPON_AREAL_MASS_KG_M2:g} kg/m^2); was it g, or is [cell] "
                        "count wrong?")
        try:
            # before any packing is laid out: a size in the wrong unit would ask for GiBs
            check_packing_size(geometry, r)
        except ParameterError as exc:
            raise _fail("[particles] radius_m", str(exc)) from None
        if self.particles.fill_percent is not None:
            try:
                particles_for_fill(self.particles.fill_percent, self.capacity_per_cell(),
                                   what="fill", typed=True)  # the key is named before it
            except ParameterError as exc:
                raise _fail("[particles] fill_percent", f"{exc} (the cell's capacity)") \
                    from None
        if self.particles.count_per_cell is not None:
            capacity = self.capacity_per_cell()
            if self.particles.count_per_cell > capacity:
                raise _fail("[particles] count_per_cell",
                            f"{_large_count(self.particles.count_per_cell)} particles do not "
                            f"fit the cell (capacity {capacity})")

    def _check_face_area(self, cells_area_m2: float) -> None:
        """Refuse a stated face area below the cells' cross-section (the cells lie within the
        face) or more than :data:`MAX_FACE_TO_CELLS_AREA` times it (a unit slip)."""
        face = self.coupon.face_area_m2
        if face is None:
            return
        ratio = face / cells_area_m2
        cells = (f"the cross-section of its {self.cell.count} cells "
                 f"({cells_area_m2:.6g} m^2, [cell] count x one hexagon)")
        if ratio < 1.0 - _FACE_AREA_RTOL:
            raise _fail("[coupon] face_area_m2",
                        f"{face:.6g} m^2 is {ratio:.3g} x {cells}; expected the area of "
                        "one face of the coupon in m^2, at least its cells' (leave the key out "
                        "to take the cells' area); was it one cell's area, or is [cell] count "
                        "wrong?")
        if ratio > MAX_FACE_TO_CELLS_AREA:
            raise _fail("[coupon] face_area_m2",
                        f"{face:.6g} m^2 is {ratio:.3g} x {cells}; expected the area of "
                        "one face of the coupon in m^2; was it cm^2 or mm^2?")

    # --- construction --------------------------------------------------------------------

    @classmethod
    def from_text(cls, text: str, *, source: str = "<specimen>") -> Specimen:
        """Parse specimen TOML; errors are one line naming ``source`` and the key."""
        try:
            data = tomllib.loads(text)
        except tomllib.TOMLDecodeError as exc:
            raise ParameterError(f"{source}: not valid TOML ({exc})") from None
        except ValueError:
            # tomllib turns a decimal integer into a Python int, which refuses more than
            # sys.get_int_max_str_digits() (4300) digits with a bare ValueError
            raise ParameterError(f"{source}: not a specimen file (an integer of more than "
                                 f"{sys.get_int_max_str_digits()} digits, which no specimen "
                                 "value has)") from None
        except RecursionError:  # tomllib parses nested arrays/tables recursively
            raise ParameterError(f"{source}: not a specimen file (arrays or tables nested "
                                 "too deeply for TOML to be read)") from None
        try:
            return _from_mapping(data, source=source)
        except ParameterError as exc:
            raise ParameterError(f"{source}: {exc}") from None

    @classmethod
    def from_bytes(cls, data: bytes, *, source: str = "<specimen>") -> Specimen:
        """Decode (UTF-8, a byte-order mark allowed) and parse a specimen file's bytes; a file
        that is not UTF-8 is one line naming ``source`` and the line of the bad byte."""
        if len(data) > MAX_SPECIMEN_FILE_BYTES:
            raise ParameterError(f"{source}: not a specimen file (more than "
                                 f"{MAX_SPECIMEN_FILE_BYTES // 1024} KiB; a specimen file is "
                                 "a few kB of TOML)")
        try:
            if data.startswith((codecs.BOM_UTF16_LE, codecs.BOM_UTF16_BE)):
                # Notepad's "Unicode": UTF-16 behind its byte-order mark, unambiguous; it was
                # refused as "not UTF-8 (byte 0xff on line 1)"
                text = data.decode("utf-16")
            else:
                # utf-8-sig: Windows editors write a byte-order mark, which TOML does not allow
                text = data.decode("utf-8-sig")
        except UnicodeDecodeError as exc:
            line = data[:exc.start].count(b"\n") + 1
            raise ParameterError(f"{source}: not UTF-8 text (byte 0x{data[exc.start]:02x} on "
                                 f"line {line}); save the specimen file as UTF-8") from None
        return cls.from_text(text, source=source)

    def with_values(self, values: Mapping[str, Any]) -> Specimen:
        """A new specimen with fields replaced by dotted path, checked like a file; a value
        None leaves the key out, as a file without it (``{"coupon.face_area_m2": None}``: the
        cells' area, for a variant whose cells no longer fit the face stated).

        Examples
        --------
        >>> s = paper_specimen().with_values({"pairs.particle_wall.static_friction": 0.3})
        >>> s.pairs.particle_wall.static_friction
        0.3
        """
        data = self.to_mapping()
        for path, value in values.items():
            parts = path.split(".")
            node: Any = data
            for i, part in enumerate(parts):
                last = i == len(parts) - 1
                if not isinstance(node, dict) or part not in _allowed_keys(parts[:i]):
                    raise ParameterError(f"{self.source}: unknown specimen field {path!r}; "
                                         f"expected one of {numeric_fields(self)}")
                if last and value is None:
                    node.pop(part, None)  # a required key is then refused as missing
                elif last:
                    node[part] = value
                else:
                    node = node.setdefault(part, {})
        try:
            return _from_mapping(data, source=self.source)
        except StaticBelowSlidingError as exc:
            raise ParameterError(f"{self.source}: {exc}{_static_too(values, exc.pair)}") from None
        except ParameterError as exc:
            raise ParameterError(f"{self.source}: {exc}") from None

    # --- identity ------------------------------------------------------------------------

    def to_mapping(self, *, face_area: bool = True) -> dict[str, Any]:
        """Nested dict of the resolved specimen, as the TOML file would hold it
        (``face_area=False``: without ``[coupon] face_area_m2``, as :attr:`text` is)."""
        out: dict[str, Any] = {"schema_version": SCHEMA_VERSION, "name": self.name,
                               "description": self.description}
        for section in ("cell", "coupon", "particles"):
            out[section] = {k: v for k, v in dataclasses.asdict(getattr(self, section)).items()
                            if v is not None}
        if not face_area:
            out["coupon"].pop("face_area_m2", None)
        pairs: dict[str, Any] = {}
        model = self.pairs.tangential_stiffness_model
        if model != DEFAULT_TANGENTIAL_STIFFNESS_MODEL:
            # only a non-default model is written: earlier files keep their text and hash
            pairs["tangential_stiffness_model"] = model
        pairs.update((k, dataclasses.asdict(v)) for k, v in
                     (("particle_particle", self.pairs.particle_particle),
                      ("particle_wall", self.pairs.particle_wall)))
        out["pairs"] = pairs
        if self.provenance is not None:
            # only a calibrated file written since the table existed has it: every other file
            # keeps its text and hash
            out["provenance"] = dataclasses.asdict(self.provenance)
        return out

    def to_toml(self) -> str:
        """TOML text of the whole specimen (resolved values, fixed key order, floats as
        ``repr``): :attr:`text` plus a stated ``[coupon] face_area_m2``.

        Written by a small writer for this schema (scalars in at most two levels of tables):
        no TOML writer is in the standard library, and none is a dependency of pidcore.
        ``Specimen.from_text(s.to_toml()) == s`` for every specimen.
        """
        return _dump_toml(self.to_mapping())

    @property
    def text(self) -> str:
        """Canonical text, stored with every DEM run as provenance: :meth:`to_toml` without
        ``[coupon] face_area_m2``, which the DEM does not simulate (a file that states it
        keeps the text and hash it had without it)."""
        return _dump_toml(self.to_mapping(face_area=False))

    @property
    def hash(self) -> str:
        """sha256 of the canonical text (hex): equal for equal physics, whatever the layout."""
        return hashlib.sha256(self.text.encode("utf-8")).hexdigest()

    def is_paper(self) -> bool:
        """True for the paper's coupon (acrylic, or another table particle material): the
        specimen of the paper's Table 3, so only its runs are compared with that table
        (:func:`is_paper_coupon` by its hash)."""
        return is_paper_coupon(self.name, self.hash)

    # --- what follows from it ------------------------------------------------------------

    def cells_area_m2(self, geometry: CellGeometry | None = None) -> float:
        """Cross-section of the coupon's ``[cell] count`` cells, m^2 (count x one cell's
        hexagon across the flats): the coupon's face area as far as its cells go.
        ``geometry``: :meth:`geometry`, where the caller has it."""
        geometry = geometry or self.geometry()
        return self.cell.count * geometry.volume_m3() / self.cell.height_m

    def capacity_per_cell(self) -> int:
        """Spheres one cell holds (dense drop packing, :func:`pidcore.dem.cell_capacity`)."""
        return _capacity(self.cell.shape, self.cell.inscribed_diameter_m, self.cell.height_m,
                         self.particles.radius_m)

    def stated_fill(self, fill_reference: str = "capacity") -> tuple[float, str] | None:
        """The specimen's own fill (% of :meth:`capacity_per_cell`) and where it comes from
        in words, or None when it states neither ``count_per_cell`` nor ``fill_percent``.

        What a DEM run of this specimen simulates when no fill is given (``pidcore dem run
        --specimen`` without ``--fill``, the app's DEM page with its fills field empty). A
        count is its share of the capacity, which rounds back to that count.

        ``fill_reference="paper"`` (a run's :attr:`pidcore.dem.DemConfig.fill_reference`):
        the same particles per cell as a share of the paper's 36, which a run of that
        reference takes as 100 %. The capacity's percentage there simulated another count
        (a file stating 20 of 46 particles ran 16 of 36 without a word).
        """
        from . import defaults

        p = self.particles
        if p.fill_percent is not None:
            stated: tuple[float, str] = (p.fill_percent, "[particles] fill_percent")
        elif p.count_per_cell is not None:
            capacity = self.capacity_per_cell()
            stated = (100.0 * p.count_per_cell / capacity,
                      f"[particles] count_per_cell {p.count_per_cell} of capacity {capacity}")
        else:
            return None
        if fill_reference == "capacity":
            return stated
        if fill_reference != "paper":
            raise ParameterError(f"fill_reference: expected one of {FILL_REFERENCES}, got "
                                 f"{fill_reference!r}")
        count = p.count_per_cell if p.count_per_cell is not None else \
            particles_for_fill(p.fill_percent, self.capacity_per_cell())
        full = defaults.PAPER_PARTICLES_PER_FULL_CELL
        return (100.0 * count / full,
                f"{stated[1]}: {count} particles, of the paper's {full} per full cell")

    def geometry(self) -> CellGeometry:
        """The cell as a DEM geometry record (dispatch on ``cell.shape``)."""
        return cell_geometry(self.cell)

    def vibrated_mass_kg(self, particles_per_cell: int, convention: str =
                         "coupon_plus_particles") -> float:
        """m_c of Eq. 10, kg: coupon + fixture (+ all particles of ``cell.count`` cells)."""
        particles = self.cell.count * particles_per_cell * self.particles.mass_kg
        return vibrated_mass_by_convention(convention, rigid_kg=self.coupon.moving_mass_kg,
                                           particles_kg=particles)


def vibrated_mass_by_convention(convention: str, *, rigid_kg: float,
                                particles_kg: float) -> float:
    """m_c of Eq. 10, kg, by a named convention (:data:`pidcore.constants.
    VIBRATED_MASS_CONVENTIONS`): the rigid mass (coupon and fixture) plus the particles, the
    rigid mass alone, or the particles alone."""
    if convention == "coupon_plus_particles":
        return rigid_kg + particles_kg
    if convention == "coupon":
        return rigid_kg
    if convention == "particles":
        return particles_kg
    raise ParameterError(f"vibrated_mass: unknown convention {convention!r}")


#: What ``pidcore calibrate`` appends to the name of the specimen it calibrates.
CALIBRATED_SUFFIX = "_calibrated"


def uncalibrated_name(name: str) -> str:
    """The name of the specimen a calibrated one was made from ("x_calibrated" -> "x", and
    "x_calibrated_calibrated", a calibrated file calibrated again, -> "x"); other names
    unchanged."""
    # one suffix removed made a recalibrated file "x_calibrated"'s, and the tests of x were
    # refused as another specimen's
    while name.endswith(CALIBRATED_SUFFIX):
        name = name.removesuffix(CALIBRATED_SUFFIX)
    return name


def calibrated_name(name: str) -> str:
    """The name ``pidcore calibrate`` gives the specimen it calibrates from ``name``
    ("x" -> "x_calibrated"; "x_calibrated", calibrated again, stays "x_calibrated")."""
    return uncalibrated_name(name) + CALIBRATED_SUFFIX


def calibrated_provenance(start: Specimen) -> ProvenanceSpec | None:
    """The ``[provenance]`` of the file ``pidcore calibrate`` writes from ``start``: the
    specimen that was tested, as the calibrated name says (:func:`calibrated_name` keeps one
    ``_calibrated``). ``start`` itself (its name and hash) where it is not a calibrated file;
    a calibrated file's own provenance where it was calibrated again; None for a calibrated
    file without one (written before the table existed): which file it came from is unknown,
    and its calibration reads by name, as that file does."""
    if start.provenance is not None:
        return start.provenance
    if uncalibrated_name(start.name) != start.name:
        return None
    return ProvenanceSpec(calibrated_from_name=start.name, calibrated_from_sha256=start.hash)


# --- schema ---------------------------------------------------------------------------------

#: Keys of each section: name -> (required, kind). kind: "float", "int", "str".
SCHEMA: dict[str, dict[str, tuple[bool, str]]] = {
    "": {"schema_version": (False, "int"), "name": (True, "str"),
         "description": (False, "str")},
    "cell": {"shape": (True, "str"), "inscribed_diameter_m": (True, "float"),
             "height_m": (True, "float"), "count": (True, "int"),
             "wall_material": (True, "str"), "wall_youngs_modulus_pa": (False, "float"),
             "wall_poisson_ratio": (False, "float"), "wall_density_kg_m3": (False, "float")},
    "coupon": {"mass_kg": (True, "float"), "fixture_mass_kg": (False, "float"),
               "baseline_loss_factor": (False, "float"), "face_area_m2": (False, "float")},
    "particles": {"material": (True, "str"), "radius_m": (False, "float"),
                  "density_kg_m3": (False, "float"), "youngs_modulus_pa": (False, "float"),
                  "poisson_ratio": (False, "float"), "count_per_cell": (False, "int"),
                  "fill_percent": (False, "float")},
    "pair": {"restitution": (True, "float"), "sliding_friction": (True, "float"),
             "static_friction": (False, "float"), "rolling_friction": (False, "float"),
             "rolling_damping_ratio": (False, "float")},
    "pairs": {"tangential_stiffness_model": (False, "str")},
    "provenance": {"calibrated_from_name": (True, "str"),
                   "calibrated_from_sha256": (True, "str")},
}
PAIR_NAMES = ("particle_particle", "particle_wall")


def _allowed_keys(prefix: list[str]) -> tuple[str, ...]:
    if not prefix:
        return (*SCHEMA[""], "cell", "coupon", "particles", "pairs")
    if prefix == ["pairs"]:
        return (*SCHEMA["pairs"], *PAIR_NAMES)
    if len(prefix) == 2 and prefix[0] == "pairs":
        return tuple(SCHEMA["pair"])
    if len(prefix) == 1 and prefix[0] in SCHEMA:
        return tuple(SCHEMA[prefix[0]])
    return ()


def numeric_fields(specimen: Specimen) -> list[str]:
    """Dotted paths of every numeric field of ``specimen`` (for :meth:`Specimen.with_values`)."""
    out = []

    def walk(node: Mapping[str, Any], prefix: str) -> None:
        for key, value in node.items():
            if isinstance(value, Mapping):
                walk(value, f"{prefix}{key}.")
            elif isinstance(value, int | float) and not isinstance(value, bool) \
                    and key != "schema_version":
                out.append(prefix + key)

    # the face area enters no DEM run: a fit of it would vary nothing the SDC depends on
    walk(specimen.to_mapping(face_area=False), "")
    return out


_TABLE_OF_SECTION = {"": "the top level", "cell": "[cell]", "coupon": "[coupon]",
                     "particles": "[particles]", "pair": "[pairs.particle_particle] and "
                     "[pairs.particle_wall]", "pairs": "[pairs]", "provenance": "[provenance]"}


def _static_too(values: Mapping[str, Any], pair: str) -> str:
    """The end of a ``with_values`` refusal where ``pair``'s sliding friction was raised past
    the static friction the specimen holds, which was not set: a file without static_friction
    holds its sliding friction there, so {"...sliding_friction": 0.4} was refused naming a
    static 0.3 the user never wrote."""
    if (f"pairs.{pair}.sliding_friction" in values
            and f"pairs.{pair}.static_friction" not in values):
        return (f"; set pairs.{pair}.static_friction too (a file without it holds its "
                "sliding friction there)")
    return ""


def _key_of_another_table(key: str, section: str) -> str:
    """The end of an unknown key's message where the key is another table's: a table header
    left out puts its keys in the table above it (``[cell]`` missing: "top level shape:
    unknown key; expected one of ['schema_version', 'name', 'description']", which sent the
    user to the key they wrote right)."""
    owners = [_TABLE_OF_SECTION[name] for name, keys in SCHEMA.items()
              if name != section and key in keys]
    if not owners:
        return ""
    return (f"; {key} belongs in {' and '.join(owners)}: is that table's header missing or "
            "below it?")


#: Length units a diameter key may end with, and their factor to metres.
_DIAMETER_UNITS = {"_m": 1.0, "_mm": 1e-3, "_cm": 1e-2, "_um": 1e-6, "": None}


def _diameter_for_radius(key: Any, value: Any, section: str) -> str:
    """The end of an unknown key's message for a sphere diameter (``diameter_m``,
    ``diameter_mm``): beads are sold by their diameter, the file states the radius, and the
    message only listed the keys, so a user could write the diameter as ``radius_m``, twice
    the spheres' size (a note catches that only where they then fit one above another)."""
    if section != "particles" or not isinstance(key, str) or "diameter" not in key:
        return ""
    unit = next((u for u in _DIAMETER_UNITS if u and key.endswith(u)), "")
    factor = _DIAMETER_UNITS[unit]
    if factor is None or isinstance(value, bool) or not isinstance(value, int | float):
        return "; the spheres are given by their radius: write radius_m, half the diameter, in m"
    return (f"; the spheres are given by their radius: write radius_m = {value * factor / 2:g} "
            "(half the diameter, in m)")


#: The SI units specimen keys end with (longest first: ``_kg_m3`` before ``_m3``).
_SI_KEY_UNITS = ("_kg_m3", "_percent", "_kg", "_pa", "_m2", "_m")


def _key_in_another_unit(key: str, schema: Mapping[str, Any]) -> str:
    """The end of an unknown key's message where it is a known key in another unit, or
    without one (``face_area_cm2``, ``face_area`` for ``face_area_m2``): the value is read in
    the unit the known key names, so the value must be converted, not only the key renamed."""
    if not isinstance(key, str):
        return ""
    stem = key.rsplit("_", 1)[0]
    known = [k for k in schema for unit in _SI_KEY_UNITS
             if k.endswith(unit) and k.removesuffix(unit) in (stem, key)]
    if not known:
        return ""
    return (f"; units are in the key names (SI): write {' or '.join(known)}, with the value "
            "in that unit")


# What a key of each kind of the schema holds, in a refusal's words.
_EXPECTED_OF_KIND = {"float": "a number", "int": "a whole number", "str": "text"}


def _take(table: Mapping[str, Any], section: str, where: str) -> dict[str, Any]:
    """Check keys (unknown, missing, type) of one table; returns a plain dict."""
    schema = SCHEMA[section]
    if not isinstance(table, Mapping):
        raise ParameterError(f"{where}: expected a table")
    for key in table:
        if key not in schema:
            raise ParameterError(f"{where} {clipped(key)}: unknown key; expected one of "
                                 f"{list(schema)}{_key_of_another_table(key, section)}"
                                 f"{_key_in_another_unit(key, schema)}"
                                 f"{_diameter_for_radius(key, table[key], section)}")
    out: dict[str, Any] = {}
    for key, (required, kind) in schema.items():
        if key not in table:
            if required:
                raise ParameterError(f"{where} {key}: missing key; expected "
                                     f"{_EXPECTED_OF_KIND[kind]}")
            continue
        value = table[key]
        if kind == "float":
            if isinstance(value, bool) or not isinstance(value, int | float):
                raise ParameterError(f"{where} {key}: expected a number, got {_shown(value)}")
            try:
                value = float(value)
            except OverflowError:  # an integer literal past 1.8e308 (a float's would be inf)
                raise ParameterError(f"{where} {key}: expected a number, got "
                                     f"{_large_count(value)}, beyond any float") from None
        elif kind == "int":
            if isinstance(value, float) and value.is_integer():
                value = int(value)
            if isinstance(value, bool) or not isinstance(value, int):
                raise ParameterError(f"{where} {key}: expected a whole number, got "
                                     f"{_shown(value)}")
        elif not isinstance(value, str):
            raise ParameterError(f"{where} {key}: expected text, got {_shown(value)}")
        out[key] = value
    return out


def _table_material(name: str, where: str, role: str | None):
    from .dem.materials import material, material_table

    if name not in material_table().index:
        return None
    row = material(name)
    if role is not None and row.role != role:
        table = material_table()
        names = ", ".join(table.index[table["role"] == role])
        raise ParameterError(f"{where}: material {_shown(name)} is a {row.role} material in "
                             f"materials.csv, expected a {role} material ({names}), or "
                             "another name with inline properties")
    return row


#: (section, key, materials.csv column, attribute holding the material name) of each inline
#: property that may differ from its table material's (:func:`table_overrides`; a particle's
#: radius is only a default, free to differ).
#: Keys a material's row completes (key, materials.csv column), in the order a missing one
#: is named: the cell's walls and the particles; the particles' radius is the row's default.
_WALL_FROM_MATERIAL = (("wall_youngs_modulus_pa", "youngs_modulus_pa"),
                       ("wall_poisson_ratio", "poisson_ratio"),
                       ("wall_density_kg_m3", "density_kg_m3"))
_PARTICLE_FROM_MATERIAL = (("density_kg_m3", "density_kg_m3"),
                           ("youngs_modulus_pa", "youngs_modulus_pa"),
                           ("poisson_ratio", "poisson_ratio"))
#: (section, key, column, material key) of the properties a table material's name claims.
_OVERRIDABLE = (tuple(("particles", key, column, "material")
                      for key, column in _PARTICLE_FROM_MATERIAL)
                + tuple(("cell", key, column, "wall_material")
                        for key, column in _WALL_FROM_MATERIAL))


def fill_override_note(specimen: Specimen | None, fills_percent,
                       fill_reference: str | None = None) -> str:
    """What fills given for a run or sweep of ``specimen`` override: the fill (or particle
    count) the specimen file states, which a run without a fill simulates; ``""`` where it
    states none or every fill is the one it states or rounds to its particle count (the
    same simulation), 100 % being the count ``fill_reference`` names (the run's
    :attr:`pidcore.dem.DemConfig.fill_reference`; None: the default,
    :data:`pidcore.defaults.DEM_FILL_REFERENCE`).

    ``dem run --fill 50 --specimen FILE`` of a file stating ``count_per_cell = 5`` simulated
    50 % without a word that the count written in the file was not used; ``--fills 8.7`` of
    one stating 8.69565 % (4 particles of 46, as 8.7 % is) was said to override it.
    """
    from . import defaults

    # in the run's own reference: the same particles per cell as the fills compared with it
    stated = specimen.stated_fill(fill_reference or defaults.DEM_FILL_REFERENCE) \
        if specimen is not None else None
    if stated is None:
        return ""
    overriding = [f for f in sorted(set(map(float, fills_percent)))
                  if not same_particles_per_cell(f, stated[0], specimen, fill_reference)]
    if not overriding:
        return ""
    shown = [apart(f, stated[0]) for f in overriding]
    stated_text = max((text for _, text in shown), key=len)  # the digits every pair needs
    several = len(overriding) > 1
    return (f"fill{'s' if several else ''} {', '.join(text for text, _ in shown)} % "
            f"override{'' if several else 's'} the {stated_text} % specimen {specimen.name} "
            f"states ({stated[1]})")


def same_particles_per_cell(fill_percent: float, stated_percent: float, specimen: Specimen,
                            fill_reference: str | None = None) -> bool:
    """Whether two fills of ``specimen`` are the same particles per cell
    (:func:`particles_for_fill` of the count ``fill_reference`` takes as 100 %; None: the
    default, :data:`pidcore.defaults.DEM_FILL_REFERENCE`), so one DEM simulation; a fill
    that rounds to none, or an unknown reference, is refused by the run itself, not here."""
    from . import defaults

    # relative 1e-9: a count's share of the capacity typed back as a percentage is the same fill
    if math.isclose(fill_percent, stated_percent, rel_tol=1e-9):
        return True
    full = {"capacity": specimen.capacity_per_cell,
            "paper": lambda: defaults.PAPER_PARTICLES_PER_FULL_CELL}.get(
                fill_reference or defaults.DEM_FILL_REFERENCE)
    if full is None:
        return False
    try:
        return particles_for_fill(fill_percent, full()) == particles_for_fill(stated_percent,
                                                                              full())
    except ParameterError:
        return False


def table_overrides(specimen: Specimen) -> tuple[str, ...]:
    """A note for each property that differs from its table material's row.

    Kept, not refused: a calibration fits such fields (``--fit particles.youngs_modulus_pa``)
    and a user may state a grade of a table material; but the name then claims one material
    and the numbers another, so every output that shows the specimen says so.
    """
    notes = []
    for section, key, column, name_key in _OVERRIDABLE:
        part = getattr(specimen, section)
        name = getattr(part, name_key)
        row = _table_material(name, f"[{section}] {name_key}", None)
        if row is None:
            continue
        value, listed = float(getattr(part, key)), float(getattr(row, column))
        # relative 1e-9: the CSV and TOML float parsers may differ in the last digit
        if not math.isclose(value, listed, rel_tol=1e-9):
            notes.append(f"[{section}] {key} {value:g} overrides {listed:g} of table material "
                         f"{name!r} (materials.csv): the numbers, not the name, are simulated")
    return tuple(notes)


def _complete_from_material(table: dict[str, Any], where: str, name: str, role: str | None,
                            columns: tuple[tuple[str, str], ...]) -> None:
    """Fill each key of ``columns`` (key, materials.csv column) that ``table`` does not state
    inline from material ``name``'s row; a key neither stated nor in the table is an error
    naming ``where`` (the material key)."""
    row = _table_material(name, where, role)
    missing = [key for key, _ in columns if key not in table]
    if row is None and missing:
        raise ParameterError(f"{where}: unknown material {_shown(name)} (not in materials.csv) "
                             f"and no inline {', '.join(missing)}; " + _material_hint(name, role))
    for key, column in columns:
        if key not in table:
            table[key] = getattr(row, column)


def _material_hint(name: Any, role: str | None) -> str:
    """What an unknown material should have been: the table's names of its role and the
    closest one (a typo such as 'aluminum_wall' or 'acrylc' was only called unknown, and the
    message named one missing inline key, so a user adding it met the next)."""
    import difflib

    from .dem.materials import material_table

    table = material_table()
    names = [str(n) for n in (table.index if role is None
                              else table.index[table["role"] == role])]
    hint = (f"expected a {role + ' ' if role else ''}material of materials.csv "
            f"({', '.join(names)}), or those keys inline")
    close = difflib.get_close_matches(str(name), names, n=1, cutoff=0.75) if isinstance(
        name, str) and len(name) <= MAX_SHOWN_CHARS else []
    return hint + (f"; did you mean {close[0]!r}?" if close else "")


def _tables_are_tables(node: Mapping[str, Any], names: tuple[str, ...], prefix: str) -> None:
    """Refuse a table of the schema written as an array of tables or as a value: either was
    reported as an unknown key of the level above (``[pairs] particle_wall: unknown key;
    expected one of ['tangential_stiffness_model']`` for ``[[pairs.particle_wall]]``)."""
    for name in names:
        if name in node and not isinstance(node[name], Mapping):
            value = node[name]
            got = (f"an array of tables [[{prefix}{name}]]"
                   if isinstance(value, list) and value and all(isinstance(v, Mapping)
                                                                 for v in value)
                   else f"{prefix}{name} = {_shown(value)}")
            raise ParameterError(f"[{prefix}{name}]: expected one table [{prefix}{name}], "
                                 f"got {got}")


def _from_mapping(data: Mapping[str, Any], *, source: str) -> Specimen:
    _tables_are_tables(data, ("cell", "coupon", "particles", "pairs", "provenance"), "")
    if isinstance(data.get("pairs"), Mapping):
        _tables_are_tables(data["pairs"], PAIR_NAMES, "pairs.")
    top = _take({k: v for k, v in data.items() if not isinstance(v, Mapping)}, "", "top level")
    for key, value in data.items():
        if isinstance(value, Mapping) and key not in ("cell", "coupon", "particles", "pairs",
                                                      "provenance"):
            raise ParameterError(f"[{clipped(key)}]: unknown table; expected [cell], [coupon], "
                                 "[particles], [pairs], [pairs.particle_particle], "
                                 "[pairs.particle_wall], [provenance]")
    version = top.get("schema_version", SCHEMA_VERSION)
    if version != SCHEMA_VERSION:
        raise ParameterError(f"schema_version: this pidcore reads version {SCHEMA_VERSION}, "
                             f"got {_shown(version)}")
    for section in ("cell", "coupon", "particles", "pairs"):
        if section not in data:
            raise ParameterError(f"[{section}]: missing table")

    cell = _take(data["cell"], "cell", "[cell]")
    # a particle row is refused as a wall: its numbers are another material's (materials.csv
    # "aluminium" is the particles' alloy, E 70 GPa, the walls' "aluminium_wall" 72 GPa)
    _complete_from_material(cell, "[cell] wall_material", cell["wall_material"], "wall",
                            _WALL_FROM_MATERIAL)

    particles = _take(data["particles"], "particles", "[particles]")
    # before the table look-up: "Acrylic" is no row of it, but the row meant
    _check_particle_material_name("[particles] material", particles["material"])
    _complete_from_material(particles, "[particles] material", particles["material"],
                            "particle",
                            _PARTICLE_FROM_MATERIAL + (("radius_m", "default_radius_m"),))

    pairs_table = data["pairs"]
    if not isinstance(pairs_table, Mapping):
        raise ParameterError("[pairs]: expected tables [pairs.particle_particle] and "
                             "[pairs.particle_wall]")
    # scalars of [pairs] hold what both pairs share; its tables are the pairs
    shared = _take({k: v for k, v in pairs_table.items() if not isinstance(v, Mapping)},
                   "pairs", "[pairs]")
    for key, value in pairs_table.items():
        if isinstance(value, Mapping) and key not in PAIR_NAMES:
            raise ParameterError(f"[pairs.{clipped(key)}]: unknown pair; expected one of "
                                 f"{PAIR_NAMES}")
    pairs = {}
    for name in PAIR_NAMES:
        if name not in pairs_table:
            raise ParameterError(f"[pairs.{name}]: missing table")
        pair = _take(pairs_table[name], "pair", f"[pairs.{name}]")
        # static friction defaults to the sliding one (no stick beyond the slide limit)
        pair.setdefault("static_friction", pair["sliding_friction"])
        pairs[name] = PairSpec(**pair)

    provenance = (ProvenanceSpec(**_take(data["provenance"], "provenance", "[provenance]"))
                  if "provenance" in data else None)
    return Specimen(name=top["name"], description=top.get("description", ""),
                    provenance=provenance,
                    cell=CellSpec(**cell), coupon=CouponSpec(**_take(data["coupon"], "coupon",
                                                                     "[coupon]")),
                    particles=ParticleSpec(**particles), pairs=PairsSpec(**pairs, **shared),
                    source=source)


def _toml_value(value: Any) -> str:
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, int):
        return str(value)
    if isinstance(value, float):
        if not math.isfinite(value):
            raise ParameterError(f"specimen: cannot write non-finite value {value!r}")
        return repr(value)  # shortest text that reads back to the same float
    if isinstance(value, str):
        escaped = value.replace("\\", "\\\\").replace('"', '\\"').replace("\n", "\\n")
        return f'"{escaped}"'
    raise ParameterError(f"specimen: cannot write {value!r} to TOML")


def _dump_toml(data: Mapping[str, Any]) -> str:
    lines: list[str] = []

    def table(node: Mapping[str, Any], name: str) -> None:
        scalars = [(k, v) for k, v in node.items() if not isinstance(v, Mapping)]
        subtables = [(k, v) for k, v in node.items() if isinstance(v, Mapping)]
        if name and scalars:
            lines.append(f"\n[{name}]")
        for key, value in scalars:
            lines.append(f"{key} = {_toml_value(value)}")
        for key, value in subtables:
            table(value, f"{name}.{key}" if name else key)

    table(data, "")
    return "\n".join(lines).lstrip("\n") + "\n"


# --- loading --------------------------------------------------------------------------------

#: The calibrated specimen's file in a folder ``pidcore calibrate --out`` wrote
#: (:data:`pidcore.calibrate.outputs.SPECIMEN_FILE`); :func:`load_specimen` finishes a killed
#: calibration's moves into its folder before reading it.
CALIBRATED_SPECIMEN_FILE = "calibrated_specimen.toml"

#: Who hears the notes of :func:`load_specimen` as it reads (:func:`hearing_read_notes`): a
#: context variable, so that one app session's or thread's hearer hears only its own reads.
_READ_NOTE_HEARERS: contextvars.ContextVar[tuple[Callable[[str], None], ...]] = \
    contextvars.ContextVar("pidcore_specimen_read_note_hearers", default=())


@contextmanager
def hearing_read_notes(hear: Callable[[str], None]) -> Iterator[None]:
    """Within the block, ``hear(note)`` is called with each :attr:`Specimen.read_note`
    :func:`load_specimen` makes (a killed calibration's moves finished): the one place a
    front-end says it (the CLI on stderr, for every command that takes ``--specimen``), rather
    than each command that loads a file."""
    token = _READ_NOTE_HEARERS.set((*_READ_NOTE_HEARERS.get(), hear))
    try:
        yield
    finally:
        _READ_NOTE_HEARERS.reset(token)


def finish_calibration_moves(folder: str | os.PathLike[str]) -> str:
    """Finish the moves a calibration killed while writing its outputs into ``folder``
    (``pidcore calibrate --out``) left, before anything there is read; returns the note that
    says so ("" where nothing was left).

    Raises
    ------
    ParameterError
        Where the moves cannot be finished (a read-only folder): one line naming the folder;
        nothing is changed.
    """
    from .atomic_files import finish_moves_before_reading

    return finish_moves_before_reading(folder, kind="calibration",
                                       writer="write_outputs(result, out_dir)")


def _finish_calibration_moves(path: Path) -> str:
    """Before a calibrated specimen file (by its name, :data:`CALIBRATED_SPECIMEN_FILE`) is
    read: :func:`finish_calibration_moves` of its folder, so that the file read is of the same
    calibration as the calibration.json beside it, not the earlier one. Any other file: ""
    at once; this one costs a listing of the folder above (no journal: nothing to do)."""
    if path.name != CALIBRATED_SPECIMEN_FILE:
        return ""
    folder = path.parent
    if folder.name in ("", ".", ".."):  # "calibrated_specimen.toml", "../x": a named folder
        folder = Path(os.path.abspath(folder))
    return finish_calibration_moves(folder)


def load_specimen(path: str | os.PathLike[str]) -> Specimen:
    """Read and check a specimen file; a bad file is one ParameterError line naming it.

    A bare name of a bundled specimen (``paper_coupon``: :func:`bundled_specimen_names`) where
    no file of that name exists is that bundled file, the note saying so (below); a file of
    that name is read as any other.

    A calibrated specimen file (``calibrated_specimen.toml`` of ``pidcore calibrate --out``)
    whose calibration was killed while its outputs were moved into the folder is read after
    those moves are finished, as the calibration's readers do: the file is then the same
    calibration's as calibration.json beside it, never the earlier one. The note saying so is
    the specimen's :attr:`Specimen.read_note`, and is told to :func:`hearing_read_notes`; a
    folder where they cannot be finished (read-only) is refused (ParameterError).
    """
    path = Path(path)
    bundled = _bundled_in_place_of(path)
    if bundled is not None:
        note = (f"specimen {str(path)!r}: no file of that name in the current folder; the "
                f"bundled specimen {path.name} is taken ({bundled})")
        specimen = _read_specimen_file(bundled)
    else:
        note = _finish_calibration_moves(path)
        specimen = _read_specimen_file(path)
    if not note:
        return specimen
    for hear in _READ_NOTE_HEARERS.get():
        hear(note)
    return dataclasses.replace(specimen, read_note=note)


def _bundled_folder() -> Path:
    """Where the specimen files bundled with the package lie (site-packages once installed)."""
    return Path(str(resources.files("pidcore") / "data" / "specimens"))


def bundled_specimen_names() -> tuple[str, ...]:
    """The names of the specimen files bundled with the package (``paper_coupon``), each of
    which :func:`load_specimen` takes by its name alone where no file of that name exists."""
    return tuple(sorted(p.stem for p in _bundled_folder().glob("*.toml")))


def _bundled_in_place_of(path: Path) -> Path | None:
    """The bundled file a bare ``path`` names (``paper_coupon``: its folder is site-packages
    once installed, which no user types); None where a file or folder of that name exists (a
    path given always wins) or the path has a folder or suffix of its own."""
    if path.parent != Path(".") or path.suffix or path.exists() \
            or path.name not in bundled_specimen_names():
        return None
    return _bundled_folder() / f"{path.name}.toml"


def _read_specimen_file(path: Path) -> Specimen:
    try:
        with path.open("rb") as file:
            # one byte past the limit tells a file at the limit from a larger one, and a
            # device or pipe that never ends is not read to the end
            data = file.read(MAX_SPECIMEN_FILE_BYTES + 1)
    except OSError as exc:
        # the bundled files lie in site-packages once installed: a name that is not one of
        # them learns which are and where
        bundled = (f"; a bundled specimen is taken by its name alone "
                   f"({', '.join(bundled_specimen_names())}, in {_bundled_folder()})"
                   if isinstance(exc, FileNotFoundError) else "")
        raise ParameterError(f"{path}: cannot read specimen file ({exc.strerror})"
                             f"{bundled}") from None
    from .io import display_path  # lazily: the readers are not needed to read a specimen

    return Specimen.from_bytes(data, source=display_path(path))


@functools.cache
def _paper_text() -> str:
    return (_bundled_folder() / f"{PAPER_SPECIMEN_NAME}.toml").read_text(encoding="utf-8")


@functools.cache
def paper_specimen(material: str = "acrylic") -> Specimen:
    """The paper's coupon (bundled file); ``material`` swaps in another table particle.

    With another particle material, radius and contact pairs come from the tables
    (``materials.csv``, ``material_pairs.csv``), which reproduces ``--material aluminium``
    runs of earlier versions.
    """
    # "aluminum" and "pmma", which LoadCase and the CLI take, were unknown here
    material = normalize_material(material, "material", known=None)
    base = Specimen.from_text(_paper_text(), source=f"pidcore:{PAPER_SPECIMEN_NAME}.toml")
    if material == base.particles.material:
        return base
    from .dem.materials import pair_properties

    row = _table_material(material, "material", "particle")
    if row is None:
        raise ParameterError(f"material: unknown particle material {material!r}")
    pp = pair_properties(material, material)
    pw = pair_properties(material, base.cell.wall_material)
    particles = ParticleSpec(material=material, radius_m=row.default_radius_m,
                             density_kg_m3=row.density_kg_m3,
                             youngs_modulus_pa=row.youngs_modulus_pa,
                             poisson_ratio=row.poisson_ratio)
    pairs = PairsSpec(**{name: PairSpec(restitution=t.restitution,
                                        sliding_friction=t.sliding_friction,
                                        static_friction=t.static_friction,
                                        rolling_friction=t.rolling_friction,
                                        rolling_damping_ratio=t.rolling_damping_ratio)
                         for name, t in (("particle_particle", pp), ("particle_wall", pw))})
    return dataclasses.replace(
        base, name=f"{PAPER_SPECIMEN_NAME}_{material}", particles=particles, pairs=pairs,
        description=f"the paper's coupon with {material} spheres from the tables")


# --- contact law ----------------------------------------------------------------------------

def contact_law(specimen: Specimen, *, alpha_pp: float | None = None,
                alpha_pw: float | None = None) -> ContactLaw:
    """The DEM contact law of a specimen's particles in its cell (paper Eq. 2-5).

    :meth:`pidcore.dem.contact.ContactLaw.from_properties` fed from the specimen's resolved
    numbers (so the paper's specimen gives ``ContactLaw.for_material`` bit for bit).
    ``alpha_*`` override Eq. 3's damping constants. The k_t model is the specimen's
    ``[pairs] tangential_stiffness_model``.
    """
    from .dem.contact import ContactLaw
    from .dem.materials import MaterialProperties, PairParameters

    p, c = specimen.particles, specimen.cell

    def pair(spec: PairSpec) -> PairParameters:
        return PairParameters(restitution=spec.restitution,
                              sliding_friction=spec.sliding_friction,
                              static_friction=spec.static_friction,
                              rolling_friction=spec.rolling_friction,
                              rolling_damping_ratio=spec.rolling_damping_ratio)

    return ContactLaw.from_properties(
        particle=MaterialProperties(density_kg_m3=p.density_kg_m3,
                                    youngs_modulus_pa=p.youngs_modulus_pa,
                                    poisson_ratio=p.poisson_ratio),
        radius_m=p.radius_m,
        wall=MaterialProperties(density_kg_m3=c.wall_density_kg_m3,  # rigid: mass unused
                                youngs_modulus_pa=c.wall_youngs_modulus_pa,
                                poisson_ratio=c.wall_poisson_ratio),
        pair_particle=pair(specimen.pairs.particle_particle),
        pair_wall=pair(specimen.pairs.particle_wall),
        particle_material=p.material, alpha_pp=alpha_pp, alpha_pw=alpha_pw,
        tangential_stiffness_model=specimen.pairs.tangential_stiffness_model)


@functools.cache
def paper_hashes() -> frozenset[str]:
    """Hashes of the paper's coupon with each table particle material: one specimen (its
    runs with either material are the paper's)."""
    from .constants import PARTICLE_MATERIALS

    return frozenset(paper_specimen(m).hash for m in PARTICLE_MATERIALS)


def bundled_face_area(specimen: Specimen) -> Specimen:
    """``specimen`` with the ``[coupon] face_area_m2`` of the file pidcore bundles of the same
    hash (the paper's coupon, any table particle material) where it states none itself: a
    specimen rebuilt from its canonical text (a stored DEM run's), which leaves the face area
    out, is then taken over the face that file states, as the file itself is. Any other
    specimen unchanged."""
    from .constants import PARTICLE_MATERIALS

    if specimen.coupon.face_area_m2 is not None or specimen.hash not in paper_hashes():
        return specimen
    for material in PARTICLE_MATERIALS:
        bundled = paper_specimen(material)
        if bundled.hash == specimen.hash:  # one text: every other coupon value is the same
            return dataclasses.replace(specimen, coupon=bundled.coupon)
    return specimen


@functools.cache
def _paper_names() -> frozenset[str]:
    from .constants import PARTICLE_MATERIALS

    return frozenset(paper_specimen(m).name for m in PARTICLE_MATERIALS)


def is_paper_coupon(name: object = "", sha256: object = "") -> bool:
    """Whether a specimen is the paper's coupon: the one the paper's Table 3 describes, and the
    one ``pidcore calibrate`` calibrates when no specimen file is given. The one rule for DEM
    runs (``specimen_name``, ``specimen_sha256``), measurements (the ``specimen`` they name)
    and specimen files (:meth:`Specimen.is_paper`).

    - Where the content is known (``sha256``, the hash of the specimen's canonical text: a DEM
      run, a specimen file), it alone decides: the paper's coupon is the bundled
      ``paper_coupon.toml`` (:func:`paper_hashes`). Another file is another specimen whatever
      its name: a copy named ``paper_coupon`` with another cell size, or a calibration's
      design point, is not compared with Table 3 nor pooled with the coupon's runs.
    - Where only a name is known (a measurement, a run stored before specimens had a hash),
      the name decides: none (``""``: the paper's coupon by default) or the paper's coupon's
      with a table particle material. A measurement analysed with a file of that name but
      other content is saved under :func:`measured_specimen_name`'s ``"paper_coupon
      [45d792]"``, which is not the paper's.
    - ``paper_coupon_aluminium`` (:func:`paper_specimen` ``("aluminium")``) is the paper's
      coupon: one coupon, filled with the table's aluminium spheres (both hashes are in
      :func:`paper_hashes`). (a) Table 3: it counts; the table holds acrylic rows only, so an
      aluminium row gets no Table 3 value by its material (``compare.align.match_paper``),
      not by its specimen. (b) Calibration: it counts; ``pidcore calibrate`` without a
      specimen file calibrates ``paper_specimen(material)`` of the points' particles, and a
      test naming ``paper_coupon`` or ``paper_coupon_aluminium`` is a test of it (the material
      is checked apart: points of two materials are refused).
    - A calibrated name (``x_calibrated``, the file ``pidcore calibrate`` wrote from ``x``'s
      tests) names the specimen ``x`` that was tested (:func:`uncalibrated_name`): a
      measurement naming ``paper_coupon_calibrated`` is a test of the paper's coupon, for
      Table 3 and for calibration alike. A calibrated file's content (its hash) is not the
      paper's: its DEM runs model the coupon with fitted values, not the paper's DEM. Where
      the file records its source (``[provenance]``) and that is another file of the coupon's
      name, its tests are that file's (:func:`provenance_test_name`), not the coupon's.
    """
    if isinstance(sha256, str) and sha256:
        return sha256 in paper_hashes()
    named = name.strip() if isinstance(name, str) else ""
    return not named or uncalibrated_name(named) in _paper_names()


def measured_specimen_name(specimen: Specimen) -> str:
    """The specimen name a measurement analysed with ``specimen`` is saved and compared under
    (``pidcore analyze --specimen FILE``, ``pidcore report FILES --specimen FILE``): its
    ``name``, except for a file that takes the paper's coupon's name (:func:`is_paper_coupon`
    by name) with other content, which is ``"paper_coupon [45d792]"`` (name and hash, as its
    DEM runs are labelled on every page: :func:`pidcore.compare.specimens.specimen_label`).

    A measurement records this name and its file's hash (:func:`measured_specimen_sha256`;
    a record of an earlier pidcore, the name only): under the bare name ``paper_coupon``, a
    test of a coupon with another cell size was compared with the paper's Table 3 and
    calibrated with the paper coupon's tests. A calibrated file of the paper's coupon
    (``paper_coupon_calibrated``: fitted contact, mass or damping values, the paper's cell and
    spheres) keeps its name: its tests are the paper's coupon's.

    A calibrated file that records its source (``[provenance]``, :func:`calibrated_provenance`)
    made from another file of the paper's coupon's name is named as that file's tests are,
    ``"paper_coupon [45d792]"`` (the source's hash): ``pidcore calibrate --specimen
    mine/paper_coupon.toml`` writes ``paper_coupon_calibrated`` as the paper's coupon's
    calibration does, and its calibration and DEM runs met the paper's coupon's tests instead
    of its own. A calibrated file without the table (written before it) is named as before.
    """
    routed = provenance_test_name(specimen)
    if routed:
        return routed
    if specimen.is_paper() or not is_paper_coupon(specimen.name):
        return specimen.name
    if specimen.name != uncalibrated_name(specimen.name) and models_paper_coupon(specimen):
        return specimen.name
    return hashed_name(specimen.name, specimen.hash)


#: Record field of a saved analysis: the sha256 of the specimen file its test was made on
#: (:func:`measured_specimen_sha256`); absent in a record saved without a specimen file, or
#: before the field existed (matched by its ``specimen`` name, as then).
MEASURED_SHA256_FIELD = "specimen_sha256"


def measured_specimen_sha256(specimen: Specimen) -> str:
    """The sha256 a measurement analysed with ``specimen`` is saved with (record field
    :data:`MEASURED_SHA256_FIELD`): that of the file tested, the file given or, for a file
    ``pidcore calibrate`` wrote that records its source (``[provenance]``), the source's (its
    tests are that file's, as :func:`measured_specimen_name` names them). A name alone
    pooled the tests of two files of one name (an edited ``x.toml``) and met the other's
    DEM runs and calibration."""
    source = specimen.provenance
    return source.calibrated_from_sha256 if source is not None else specimen.hash


def deciding_sha256(sha256: object) -> str:
    """A measurement's recorded specimen hash where it decides what the test meets; ``""``
    where its name does: none recorded (a record saved without a specimen file, or before
    the hash was saved; a listing's NaN) or the paper's coupon's (either table material: one
    coupon, whose runs without a hash and calibrations are matched by name as before)."""
    if not isinstance(sha256, str) or len(sha256) != 64 or not set(sha256) <= _SHA256_DIGITS:
        return ""
    return "" if sha256 in paper_hashes() else sha256


def same_tested_file(measured_sha256: object, tested: object) -> bool | None:
    """Whether a measurement recording ``measured_sha256`` is a test of the file whose hash
    is ``tested`` (a DEM run's specimen, or the file a calibration calibrated); None where
    either is unknown or the paper's coupon's (:func:`deciding_sha256`): the names decide."""
    mine, theirs = deciding_sha256(measured_sha256), deciding_sha256(tested)
    if not mine or not theirs:
        return None
    return mine == theirs


@dataclass(frozen=True)
class NameMatch:
    """How each of a set of measurement records meets its specimen file
    (:func:`match_hashless_records`): ``sha256``, per record, the hash it is grouped and matched
    by ("" where its name decides); ``ambiguous``, per record, whether it is a record without
    its file's hash that several files of its name could have been tested with (kept apart);
    ``notes``, per record, what was decided for it ("" where nothing was)."""

    sha256: tuple[str, ...]
    ambiguous: tuple[bool, ...]
    notes: tuple[str, ...]


def match_hashless_records(names: Sequence[object], sha256s: Sequence[object], *,
                           given: Mapping[str, str] | None = None,
                           others: Sequence[tuple[object, object]] = ()) -> NameMatch:
    """The one rule for a measurement saved with a specimen name but no file hash (by a
    pidcore before :data:`MEASURED_SHA256_FIELD` existed, or without a known file), for
    ``calibrate --store``, reports and the app's Compare alike.

    ``names`` and ``sha256s``: each record's saved specimen name and hash (NaN or "" for
    none); ``given``: name -> hash of the specimen files the caller was given
    (:func:`measured_specimen_sha256`), e.g. ``calibrate --specimen FILE``; ``others``: (name,
    hash) of the store's records not among them (a page's filter, a report of some files),
    which count as they do but are not resolved: a filter does not change what a record is.

    A hashless record of name N is a test of the one file every hashed record of N names
    where they all name the same file (and a given file of that name is that file): it then
    carries that hash, with a note that it was matched by name only. Where the hashed
    records of N (or they and the given file) name two files, a name alone cannot say which
    was tested: the record keeps no hash, is flagged ambiguous, and its note says so; it is
    never pooled with either file's tests. Records of N with no hashed record beside them
    are matched by name, as before (no note). The paper's coupon is one coupon by name
    (:func:`deciding_sha256`): never concerned.
    """
    given = {str(k): deciding_sha256(v) for k, v in (given or {}).items()}
    named = [n.strip() if isinstance(n, str) else "" for n in names]
    hashes = [deciding_sha256(h) if n else "" for n, h in zip(named, sha256s, strict=True)]
    files: dict[str, list[str]] = {}
    context = [(n.strip() if isinstance(n, str) else "", h) for n, h in others]
    for n, h in [*zip(named, hashes, strict=True),
                 *((n, deciding_sha256(h) if n else "") for n, h in context)]:
        if n and h and h not in files.setdefault(n, []):
            files[n].append(h)
    out_hashes, ambiguous, notes = list(hashes), [False] * len(named), [""] * len(named)
    counts: dict[str, int] = {}
    for n, h in zip(named, hashes, strict=True):
        if n and not h:
            counts[n] = counts.get(n, 0) + 1
    for i, (n, h) in enumerate(zip(named, hashes, strict=True)):
        if not n or h or n not in files or is_paper_coupon(n):
            continue
        stored = files[n]
        mine = given.get(n, "")
        how_many = f"{counts[n]} record(s) of specimen {n} saved without its specimen's sha256"
        if len(stored) == 1 and mine in ("", stored[0]):
            out_hashes[i] = stored[0]
            notes[i] = (f"{how_many} (an older pidcore, or no file given) matched by name only "
                        f"to {hashed_name(n, stored[0])}, the one file of that name its other "
                        "tests recorded")
            continue
        ambiguous[i] = True
        labels = [hashed_name(n, h) for h in stored]
        if mine and mine not in stored:
            where = (f"the tests recorded {', '.join(labels)} and the specimen given is "
                     f"{hashed_name(n, mine)}")
        else:
            where = f"the tests recorded {len(stored)} files of that name ({', '.join(labels)})"
        notes[i] = (f"{how_many} kept apart: {where}, and a name alone does not say which "
                    "was tested (analyse them again with their specimen file to record it)")
    return NameMatch(tuple(out_hashes), tuple(ambiguous), tuple(notes))


@dataclass(frozen=True)
class NamedSpecimen:
    """What a specimen typed by name is saved as (:func:`resolve_specimen_name`): the record's
    ``name`` and ``sha256`` ("" where no one known file has that name), and ``note``, one line
    saying why only the name is saved ("" where the file was found or no name was typed)."""

    name: str
    sha256: str = ""
    note: str = ""


def resolve_specimen_name(typed: str, known: Sequence[Specimen]) -> NamedSpecimen:
    """The specimen file a typed name means among the ``known`` files (those a page offers),
    saved as ``pidcore analyze --specimen FILE`` saves it (:func:`measured_specimen_name`,
    :func:`measured_specimen_sha256`). ``typed`` is a file's name or its
    :func:`hashed_name` (``"panel [3e945a]"``, which tells two files of one name apart).

    A name no known file has, or that several files of different content have, is saved by
    name only, as a record of an earlier pidcore (matched by name), with a note saying so: a
    file picked at random among two of one name would meet the other's DEM runs."""
    typed = typed.strip()
    if not typed:
        return NamedSpecimen("")
    found = {s.hash: s for s in known
             if typed in (s.name, hashed_name(s.name, s.hash), measured_specimen_name(s))}
    if len(found) == 1:
        (specimen,) = found.values()
        return NamedSpecimen(measured_specimen_name(specimen), measured_specimen_sha256(specimen))
    if found:
        labels = ", ".join(sorted(hashed_name(s.name, s.hash) for s in found.values()))
        return NamedSpecimen(typed, "", f"specimen {typed}: {len(found)} known files of that "
                             f"name ({labels}); saved by name only: name one as shown to "
                             "save its specimen's sha256")
    return NamedSpecimen(typed, "", f"specimen {typed}: no known specimen file of that name; "
                         "saved by name only (its DEM runs are met by name)")


def hashed_name(name: str, sha256: str) -> str:
    """A specimen file by its name and the start of its hash, ``"name [45d792]"``: how the
    pages label its DEM runs (:func:`pidcore.compare.specimens.specimen_label`) and the name
    its tests are saved under (:func:`measured_specimen_name`), one spelling so that the two
    meet."""
    return f"{name or 'unnamed'} [{sha256[:6]}]"


def tested_label(name: str, sha256: str) -> str:
    """The specimen a measurement records (its name and hash, :data:`MEASURED_SHA256_FIELD`)
    as labels show it: :func:`hashed_name` where a hash is recorded, which tells two files of
    one name apart; the name as saved where none is, or where it holds one already
    (``"paper_coupon [45d792]"``: :func:`measured_specimen_name`); "" for none named."""
    if not name or not sha256 or name.endswith("]"):
        return name
    return hashed_name(name, sha256)


def provenance_test_name(specimen: Specimen) -> str:
    """The name the tests of the file ``specimen`` was calibrated from are saved under, where
    its ``[provenance]`` says it was made from another file of the paper's coupon's name
    (``"paper_coupon [45d792]"``: that file's name and hash, as :func:`measured_specimen_name`
    names its tests); "" otherwise (no provenance, the paper's own coupon, or another name,
    whose ``x_calibrated`` names its tests by :func:`uncalibrated_name`)."""
    source = specimen.provenance
    if source is None or not is_paper_coupon(source.calibrated_from_name) \
            or is_paper_coupon(source.calibrated_from_name, source.calibrated_from_sha256):
        return ""
    return hashed_name(source.calibrated_from_name, source.calibrated_from_sha256)


def models_paper_coupon(specimen: Specimen) -> bool:
    """Whether ``specimen`` holds the paper coupon's physics: its cells, its spheres (of its
    particle material: radius and density) and its coupon mass, whatever its contact values
    and the test rig's fixture mass and baseline damping: a calibration's design point or
    calibrated file of the coupon, a model of the coupon its tests were made on. A file with
    another cell, other spheres or another coupon mass models another coupon, whatever its
    name."""
    try:
        paper = paper_specimen(specimen.particles.material)
    except ParameterError:  # a material the tables lack: not the paper's spheres
        return False
    # the masses too: a calibration that fitted the spheres' density or the coupon's mass
    # modelled another coupon, yet its tests met Table 3 as the paper's
    return (specimen.cell == paper.cell
            and specimen.particles.radius_m == paper.particles.radius_m
            and specimen.particles.density_kg_m3 == paper.particles.density_kg_m3
            and specimen.coupon.mass_kg == paper.coupon.mass_kg)


def tabulated_by_paper(specimen: Specimen) -> bool:
    """Whether the paper's Table 3 is compared with the tests ``specimen`` models: by the one
    rule a measured row is judged by, :func:`is_paper_coupon` of the name its tests are saved
    under (:func:`measured_specimen_name`). The paper's coupon itself; a file ``pidcore
    calibrate`` wrote from it (``[provenance]`` naming the coupon's hash, or without the table
    a calibrated name of the coupon) that keeps its physics (:func:`models_paper_coupon`:
    fitted contact, fixture and baseline values only). Not a file that only takes the
    coupon's name, nor one calibrated from such a file.

    ``report --specimen paper_calibrated_specimen.toml`` decided by the file's own hash (not
    the paper's: Table 3 dropped) while the rows of its tests, saved as
    ``paper_coupon_calibrated``, were the paper's coupon's by name (Table 3 shown)."""
    return is_paper_coupon(measured_specimen_name(specimen))


# --- what follows from a specimen ------------------------------------------------------------

#: Load case whose impacts are the hardest of the paper's Table 3 grid (largest 2 a/w): the
#: time step :func:`describe` reports is the one ``time_step="auto"`` picks for it, and so
#: the smallest of the grid's (a softer load case's contact lasts longer: 6.98e-7 s at
#: 500 Hz, 5 g beside 6.01e-7 s here for steel_6mm), not the step of every run (each run also
#: shortens its own to whole steps per output sample: :func:`pidcore.dem.simulate.drive_sampling`).
DESCRIBE_FREQUENCY_HZ = 50.0
DESCRIBE_ACCELERATION_G = 10.0


def describe(specimen: Specimen, *,
             damping_mode: NormalDampingMode | None = None) -> dict[str, Any]:
    """What follows from a specimen (units in the keys): capacity, masses, contact numbers.

    Particle counts and masses are for the specimen's stated fill (``count_per_cell`` or
    ``fill_percent`` of the capacity) where it states one, else for a full cell. Contact time
    and time step are for the hardest impact of the Table 3 grid (``reference_frequency_hz``,
    ``reference_acceleration_g``: 50 Hz, 10 g), so the step is the grid's smallest; a run at
    another load case takes its own (:func:`pidcore.dem.simulate.choose_time_step`).

    ``coupon_area_m2`` is the area ``pidcore model damper``'s c_eq per treated area is per
    (:func:`pidcore.model.damper.specimen_area_m2`), ``coupon_area_from`` where it comes from.

    ``tangential_stiffness_*_n_m`` is the constant k_t (Mindlin's at the overlap of a
    DEM_TANGENTIAL_REFERENCE_SPEED_M_S impact); with ``tangential_stiffness_model = "mindlin"``
    ``mindlin_tangential_stiffness_*_n_m`` is k_t = 8 G* sqrt(R* delta) at the Hertz overlap
    ``reference_impact_overlap_*_m`` of that hardest impact (None for ``"constant"``).

    ``restitution_*_stated`` is each pair's e_n, ``restitution_*_simulated`` what a head-on
    impact through the kernel gives with Eq. 3's alpha in ``damping_mode`` (the DEM's default
    by default) at DEM_CALIBRATION_SPEED_M_S (``restitution_impact_speed_m_s``) and step
    ``time_step_s``: clipped damping (``no_attraction``) gives more than stated, the more the
    lower e_n; a note names the pairs off by more than RESTITUTION_NOTE_GAP
    (:func:`restitution_note`).
    """
    from . import defaults
    from .constants import PARTICLE_MATERIALS
    from .dem.contact import check_damping_mode, maximum_overlap
    from .dem.simulate import LoadCase, choose_time_step, max_impact_speed
    from .model.damper import specimen_area_m2

    law = contact_law(specimen)
    geometry = specimen.geometry()
    capacity = specimen.capacity_per_cell()
    area, area_from = specimen_area_m2(specimen)
    p = specimen.particles
    if p.count_per_cell is not None:
        count, basis = p.count_per_cell, "count_per_cell"
    elif p.fill_percent is not None:
        count, basis = particles_for_fill(p.fill_percent, capacity), "fill_percent"
    else:
        count, basis = capacity, "capacity"
    material = p.material if p.material in PARTICLE_MATERIALS else "acrylic"
    case = LoadCase(DESCRIBE_FREQUENCY_HZ, DESCRIBE_ACCELERATION_G, 100.0, material=material)
    speed = max_impact_speed(case, geometry)
    mindlin = specimen.pairs.tangential_stiffness_model == "mindlin"
    overlap = {name: float(maximum_overlap(stiffness=pair.stiffness,
                                           mass_kg=pair.effective_mass_kg,
                                           impact_speed_m_s=speed))
               for name, pair in (("pp", law.pair_particle), ("pw", law.pair_wall))}
    k_t_mindlin = {name: float(pair.mindlin_factor * math.sqrt(overlap[name])) if mindlin
                   else None
                   for name, pair in (("pp", law.pair_particle), ("pw", law.pair_wall))}
    mode = defaults.DEM_NORMAL_DAMPING_MODE if damping_mode is None else damping_mode
    check_damping_mode(mode)
    dt = choose_time_step(case, law, geometry, "auto", defaults.DEM_TANGENTIAL_MODEL)
    v_cal = defaults.DEM_CALIBRATION_SPEED_M_S
    stated = {"pp": law.pair_particle.restitution, "pw": law.pair_wall.restitution}
    simulated = {name: _simulated_restitution(specimen, pair, v_cal, dt, mode, law, geometry)
                 for name, pair in (("pp", "particle"), ("pw", "wall"))}
    return {
        "name": specimen.name, "sha256": specimen.hash, "is_paper": specimen.is_paper(),
        # the file a calibrated one was made from ([provenance]; None: not recorded)
        "calibrated_from_name": None if specimen.provenance is None
        else specimen.provenance.calibrated_from_name,
        "calibrated_from_sha256": None if specimen.provenance is None
        else specimen.provenance.calibrated_from_sha256,
        "notes": [*table_overrides(specimen), *heavy_fixture_note(specimen, count),
                  *_no_fixture_note(specimen), *column_note(specimen, capacity),
                  *restitution_note(stated, simulated, mode)],
        "cell_shape": specimen.cell.shape, "cells_per_coupon": specimen.cell.count,
        "cells_area_m2": specimen.cells_area_m2(geometry),
        # the area pidcore model damper's c_eq per treated area is per, and why that one
        "coupon_area_m2": area, "coupon_area_from": area_from,
        "capacity_per_cell": capacity, "particles_per_cell": count,
        "particles_per_cell_basis": basis,
        # the fill stated (None: a count or a full cell) and the share the rounded count
        # makes of the capacity (75 % of 22 is 16, 72.7 %)
        "fill_percent": p.fill_percent if basis == "fill_percent" else None,
        "filled_percent": 100.0 * count / capacity,
        "particle_radius_m": p.radius_m,
        "particle_mass_kg": p.mass_kg,
        "particles_mass_kg": specimen.cell.count * count * p.mass_kg,
        "coupon_mass_kg": specimen.coupon.mass_kg,
        "fixture_mass_kg": specimen.coupon.fixture_mass_kg,
        "moving_mass_kg": specimen.coupon.moving_mass_kg,
        "vibrated_mass_kg": specimen.vibrated_mass_kg(count),
        "wall_to_wall_gap_m": specimen.cell.inscribed_diameter_m - 2 * p.radius_m,
        "floor_to_ceiling_gap_m": specimen.cell.height_m - 2 * p.radius_m,
        "normal_stiffness_pp_n_m1_5": law.pair_particle.stiffness,
        "normal_stiffness_pw_n_m1_5": law.pair_wall.stiffness,
        "tangential_stiffness_pp_n_m": law.pair_particle.tangential_stiffness,
        "tangential_stiffness_pw_n_m": law.pair_wall.tangential_stiffness,
        "tangential_stiffness_model": specimen.pairs.tangential_stiffness_model,
        "reference_impact_overlap_pp_m": overlap["pp"],
        "reference_impact_overlap_pw_m": overlap["pw"],
        "mindlin_tangential_stiffness_pp_n_m": k_t_mindlin["pp"],
        "mindlin_tangential_stiffness_pw_n_m": k_t_mindlin["pw"],
        # the load case the contact time and time step are for (a run takes its own's)
        "reference_frequency_hz": DESCRIBE_FREQUENCY_HZ,
        "reference_acceleration_g": DESCRIBE_ACCELERATION_G,
        "reference_impact_speed_m_s": speed,
        "contact_time_s": law.contact_time(speed),
        "tangential_period_s": law.tangential_period(),
        "time_step_s": dt,
        "restitution_pp_stated": stated["pp"], "restitution_pw_stated": stated["pw"],
        "restitution_pp_simulated": simulated["pp"],
        "restitution_pw_simulated": simulated["pw"],
        "restitution_damping_mode": mode, "restitution_impact_speed_m_s": v_cal,
    }


def _simulated_restitution(specimen: Specimen, pair: ImpactPair, speed_m_s: float, dt_s: float,
                           mode: NormalDampingMode, law: ContactLaw,
                           geometry: CellGeometry) -> float:
    """The restitution of :func:`describe`'s head-on impact, an impact that does not end
    refused naming the file and the key: "particle still in contact", naming neither, was
    all `specimen check` said."""
    from .dem.impact import StillInContact, measure_restitution, pair_name

    try:
        return measure_restitution(pair=pair, impact_speed_m_s=speed_m_s, dt_s=dt_s,
                                   mode=mode, law=law, geometry=geometry)
    except StillInContact as exc:
        key = f"pairs.{'particle_wall' if pair == 'wall' else 'particle_particle'}.restitution"
        pair_law = law.pair_wall if pair == "wall" else law.pair_particle
        raise ParameterError(
            f"{specimen.source}: {key} {pair_law.restitution:g}: the {pair_name(pair)} impact "
            f"with Eq. 3's alpha {pair_law.alpha:.4g} in {mode} damping has not rebounded "
            f"({exc}), so the kernel gives it no restitution; expected a larger restitution"
            + (", or normal_damping_mode='no_attraction'" if mode == "literal" else "")
        ) from None


def restitution_note(stated: dict[str, float], simulated: dict[str, float],
                     mode: NormalDampingMode) -> tuple[str, ...]:
    """A note naming the pairs (``"pp"``, ``"pw"``) whose head-on impact through the kernel
    gives a restitution more than RESTITUTION_NOTE_GAP from the stated one, and the options
    that give the stated value: a run with Eq. 3's alpha simulates a livelier bed than the
    file says, and nothing else said so. And one naming the pairs whose impact gains energy
    (a restitution more than RESTITUTION_GAIN_NOTE above 1): 1.001 for e = 1 was printed
    without a word."""
    from . import defaults

    names = {"pp": "particle-particle", "pw": "particle-wall"}
    notes = []
    off = [f"{names[k]} {simulated[k]:.3f} for the stated {stated[k]:g}" for k in names
           if abs(simulated[k] - stated[k]) > defaults.RESTITUTION_NOTE_GAP]
    if off:
        cures = ("damping_coefficient='calibrated' (DemConfig) tunes alpha to give the stated "
                 "value")
        if mode != "literal":
            cures += (", or normal_damping_mode='literal' (Eq. 3's alpha is exact for damping "
                      "that may pull at the contact's end)")
        notes.append(f"restitution in {mode} damping mode with Eq. 3's alpha: the kernel gives "
                     f"{', '.join(off)} (head-on at "
                     f"{defaults.DEM_CALIBRATION_SPEED_M_S:g} m/s); {cures}")
    gains = [f"{names[k]} {simulated[k]:.4f} ({simulated[k] ** 2 - 1:.2%} of its kinetic "
             "energy)" for k in names if simulated[k] > 1 + defaults.RESTITUTION_GAIN_NOTE]
    if gains:
        notes.append(f"restitution above 1: each head-on impact gains energy, "
                     f"{', '.join(gains)}: the explicit time step's error, which a shorter "
                     "time step lowers; no damping setting removes it")
    return tuple(notes)


#: A fixture this many times the coupon (its particles left out) is named in `specimen
#: check`'s notes: m_c, and so E of Eq. 10, is then almost all fixture (a 35 g fixture typed as
#: 35 kg on a 16 g coupon is 2200 x; the paper's calibrated 0.254 kg fixture is 11 x its 22 g
#: coupon). The particles are left out because heavy ones hid the slip: a 15 g fixture typed
#: as 15 kg on a 40 g coupon with 263 g of 2 mm steel spheres is 375 x the coupon but only
#: 50 x the coupon and its particles, and passed in silence.
HEAVY_FIXTURE_RATIO = 100.0


def heavy_fixture_note(specimen: Specimen, count: int) -> tuple[str, ...]:
    """A note for a fixture far heavier than the coupon it carries (a likely g typed as kg); a
    note, not a refusal: a heavy head expander is possible, but the SDC then measures little."""
    coupon = specimen.coupon.mass_kg
    carried = coupon + specimen.cell.count * count * specimen.particles.mass_kg
    fixture = specimen.coupon.fixture_mass_kg
    if coupon <= 0 or fixture <= HEAVY_FIXTURE_RATIO * coupon:
        return ()
    return (f"[coupon] fixture_mass_kg {fixture:g} kg is {fixture / coupon:.0f} x the coupon "
            f"({coupon * 1e3:.4g} g) and {fixture / carried:.0f} x the coupon and its particles "
            f"({carried * 1e3:.4g} g): E of Eq. 10 (m_c a^2 / (2 w^2)) is then "
            f"{fixture / (fixture + carried):.1%} the fixture's and the SDC small; was it g?",)


def _no_fixture_note(specimen: Specimen) -> tuple[str, ...]:
    """A note for a file of one's own without a fixture: a key left out reads as 0 kg, the
    same specimen (hash) as 0 stated, and nothing said so; a 120 g adapter plate forgotten on
    a 41 g coupon with 234 g of spheres raised the DEM's SDC from 1.0 to 1.43 (E of Eq. 10 has
    0.28 kg, not 0.40 kg) in silence. Not for the paper's coupon, whose runs are of none."""
    if specimen.coupon.fixture_mass_kg > 0 or specimen.is_paper():
        return ()
    return ("[coupon] fixture_mass_kg is 0 kg (stated, or left out: 0 is its default): the "
            "shaker moves the coupon alone above the force gauge; state the mass of an adapter "
            "plate, bolts or head expander between gauge and coupon there (it is in m_c of "
            "Eq. 10 and the virtual shaker's force)",)


def column_note(specimen: Specimen, capacity: int) -> tuple[str, ...]:
    """A note for spheres that fit the cell only one above another (a diameter typed as the
    radius: 1.5 mm beads as radius_m = 1.5e-3 in a 3.2 mm cell were 3 per cell, the check said
    OK); a note, not a refusal: a single column of beads is a possible damper."""
    radius = specimen.particles.radius_m
    layers = int(specimen.cell.height_m // (2 * radius))
    if capacity > layers:
        return ()
    return (f"[particles] radius_m {radius * 1e3:.4g} mm: the spheres (diameter "
            f"{2 * radius * 1e3:.4g} mm) fit the {specimen.cell.inscribed_diameter_m * 1e3:.4g} "
            f"mm cell only one above another, a column of {capacity}; was the diameter given "
            "as the radius?",)


# --- geometry -------------------------------------------------------------------------------

def cell_geometry(cell: CellSpec) -> CellGeometry:
    """DEM geometry of a cell, by shape (only ``"hexagonal"`` so far)."""
    from .dem.geometry import CellGeometry

    builders = {"hexagonal": lambda c: CellGeometry(inscribed_diameter_m=c.inscribed_diameter_m,
                                                    height_m=c.height_m)}
    if cell.shape not in builders:  # pragma: no cover - the vocabulary and builders agree
        raise ParameterError(f"[cell] shape: no DEM geometry for {cell.shape!r} yet")
    return builders[cell.shape](cell)


@functools.cache
def _capacity(shape: str, inscribed_diameter_m: float, height_m: float, radius_m: float) -> int:
    from .dem.geometry import cell_capacity

    cell = CellSpec(shape=shape, inscribed_diameter_m=inscribed_diameter_m, height_m=height_m,
                    count=1, wall_material="-", wall_youngs_modulus_pa=72e9,
                    wall_poisson_ratio=0.0, wall_density_kg_m3=2800.0)  # walls: no effect
    return cell_capacity(cell_geometry(cell), radius_m)


__all__ = ["HASH_OF_WHAT", "CellSpec", "CouponSpec", "PairSpec", "PairsSpec", "ParticleSpec",
           "Specimen", "ProvenanceSpec", "calibrated_name", "calibrated_provenance",
           "uncalibrated_name",
           "cell_geometry", "column_note", "contact_law", "describe", "hashed_name",
           "heavy_fixture_note",
           "is_paper_coupon",
           "tested_label",
           "load_specimen", "bundled_specimen_names", "hearing_read_notes",
           "CALIBRATED_SPECIMEN_FILE",
           "finish_calibration_moves",
           "MEASURED_SHA256_FIELD", "deciding_sha256", "measured_specimen_name",
           "measured_specimen_sha256", "models_paper_coupon", "NamedSpecimen",
           "resolve_specimen_name", "numeric_fields", "same_tested_file", "bundled_face_area",
           "provenance_test_name", "tabulated_by_paper",
           "match_hashless_records", "NameMatch",
           "paper_specimen", "particles_for_fill", "same_particles_per_cell"]

