"""Hexagonal honeycomb cell (paper Eq. 1, Table 2) and particle packing in it.

Cell frame: origin at the cell centre, z normal to the face sheets. The six side walls are the
planes y = +-(sqrt(3)/2) R and x +- y/sqrt(3) = +-R, whose distance from the axis (the apothem,
(sqrt(3)/2) R) is half the inscribed-circle diameter 4.76 mm; the face sheets are z = +-h/2.
Every wall is stored as an inward unit normal ``n`` and offset ``d`` so that a point ``p`` is
inside when ``n . p + d >= 0`` (the signed distance from the wall).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .. import defaults
from ..errors import ParameterError

#: Wall names in kernel order.
WALL_NAMES: tuple[str, ...] = ("side_30deg", "side_90deg", "side_150deg", "side_210deg",
                               "side_270deg", "side_330deg", "floor", "ceiling")


@dataclass(frozen=True)
class CellGeometry:
    """Hexagonal cell with inscribed diameter ``inscribed_diameter_m`` and height ``height_m``."""

    inscribed_diameter_m: float = defaults.CELL_INSCRIBED_DIAMETER_M
    height_m: float = defaults.CELL_HEIGHT_M

    def __post_init__(self):
        if not (self.inscribed_diameter_m > 0 and self.height_m > 0):
            raise ParameterError("cell geometry: inscribed diameter and height must be > 0 m")

    @property
    def apothem_m(self) -> float:
        """Distance from the cell axis to each side wall, (sqrt(3)/2) R, m."""
        return 0.5 * self.inscribed_diameter_m

    @property
    def circumradius_m(self) -> float:
        """R of Eq. 1 (centre to corner), m."""
        return self.apothem_m * 2.0 / np.sqrt(3.0)

    @property
    def wall_normals(self) -> np.ndarray:
        """(8, 3) inward unit normals, side walls first (see :data:`WALL_NAMES`)."""
        angles = np.deg2rad([30.0, 90.0, 150.0, 210.0, 270.0, 330.0])
        sides = -np.column_stack([np.cos(angles), np.sin(angles), np.zeros(6)])
        faces = np.array([[0.0, 0.0, 1.0], [0.0, 0.0, -1.0]])
        return np.ascontiguousarray(np.vstack([sides, faces]))

    @property
    def wall_offsets(self) -> np.ndarray:
        """(8,) offsets d of ``n . p + d = 0``, m."""
        return np.array([self.apothem_m] * 6 + [0.5 * self.height_m] * 2)

    def signed_distances(self, points: np.ndarray) -> np.ndarray:
        """Signed distance of (..., 3) points from each wall, (..., 8), m (> 0 inside)."""
        return np.asarray(points) @ self.wall_normals.T + self.wall_offsets

    def volume_m3(self) -> float:
        """Volume of the hexagonal prism (area 2 sqrt(3) apothem^2 times height), m^3."""
        return 2.0 * np.sqrt(3.0) * self.apothem_m**2 * self.height_m


#: Most candidate points :func:`drop_packing` lays out: it holds (n, 3) points and (n, 6) wall
#: distances in float64, 0.15 GB at this size. Enough for a cell some 50 particle radii across
#: (the paper's is 3.8); a larger ratio is almost surely a unit slip, and would ask for GiBs.
MAX_PACKING_GRID_POINTS = 2_000_000
#: Most spheres a cell may hold (densest-packing estimate). The DEM keeps a contact history
#: for every pair of a cell's particles, N^2 slots of 64 bytes: 2000 particles are 256 MB per
#: cell. More is beyond this DEM (and usually a unit slip in the cell's or particles' size).
MAX_PACKED_PARTICLES = 2_000
#: Most (candidate point x sphere) steps of :func:`drop_packing`, as each sphere scans every
#: point: some seconds (2.6 s for the 2e8 steps of a cell 25 radii across, 2026-11-30). The
#: two limits above hold each factor, not the product: fine shot in a tall cell passed both
#: and packed for an hour.
MAX_PACKING_WORK = 5e8
#: Densest packing of equal spheres (Kepler, pi / sqrt(18)): no cell holds more.
_DENSEST_PACKING_FRACTION = np.pi / np.sqrt(18.0)
#: Default candidate-grid spacing of :func:`drop_packing`, in particle radii.
GRID_FRACTION = 0.04
#: Default gap :func:`drop_packing` keeps between spheres and to floor and ceiling, in radii.
PACKING_GAP_FRACTION = 1e-4


def check_sphere_fits(geometry: CellGeometry, radius_m: float) -> None:
    """Refuse (ParameterError, one line with the limit) a sphere :func:`drop_packing` cannot
    place, so that a capacity is never computed as nothing (or fails).

    Across the flats the sphere must be strictly narrower than the cell: its centre then has
    room on the cell axis, exactly one apothem from every side wall (no rounding). Up the
    core it must clear floor and ceiling by the packing's gap (``PACKING_GAP_FRACTION`` r
    each), or the packing places no sphere at all; tested with the packing's own arithmetic.
    """
    r = float(radius_m)
    width, height = geometry.inscribed_diameter_m, geometry.height_m
    clearance = r * (1 + PACKING_GAP_FRACTION)
    if r < geometry.apothem_m and -0.5 * height + clearance <= 0.5 * height - clearance:
        return
    # 6 digits: a radius just past the limit must not print equal to it
    if r >= geometry.apothem_m:
        expected = (f"expected a radius below {geometry.apothem_m * 1e3:.6g} mm, half the "
                    f"{width * 1e3:.6g} mm flat-to-flat width")
    else:
        expected = (f"expected a radius up to {0.5 * height / (1 + PACKING_GAP_FRACTION) * 1e3:.6g}"
                    f" mm, half the {height * 1e3:.6g} mm core height less the packing's gap "
                    f"of {PACKING_GAP_FRACTION:g} radii to floor and ceiling")
    raise ParameterError(f"a sphere of radius {r * 1e3:.6g} mm does not fit a "
                         f"{width * 1e3:.6g} x {height * 1e3:.6g} mm cell; {expected}")


def check_packing_size(geometry: CellGeometry, radius_m: float,
                       grid_fraction: float = GRID_FRACTION) -> None:
    """Refuse (ParameterError) a packing whose candidate grid or sphere count would be huge.

    Called before :func:`drop_packing` allocates anything, so that a cell or radius in the
    wrong unit is one error line instead of a multi-GiB allocation or an endless loop.
    """
    check_sphere_fits(geometry, radius_m)
    inner = geometry.apothem_m - radius_m
    size = (f"a {radius_m * 1e3:.3g} mm radius sphere in a "
            f"{geometry.inscribed_diameter_m * 1e3:.4g} x {geometry.height_m * 1e3:.4g} mm cell")
    per_side = 2.0 * inner * 2.0 / np.sqrt(3.0) / (grid_fraction * radius_m) + 2.0
    if per_side**2 > MAX_PACKING_GRID_POINTS:
        raise ParameterError(
            f"{size} needs a packing grid of {per_side**2:.3g} points (limit "
            f"{MAX_PACKING_GRID_POINTS:.3g}, a cell up to about 50 radii across); check the "
            "units of the cell's and the particles' size")
    most = _DENSEST_PACKING_FRACTION * geometry.volume_m3() / (4.0 / 3.0 * np.pi * radius_m**3)
    if most > MAX_PACKED_PARTICLES:
        raise ParameterError(
            f"{size} holds up to {most:.3g} spheres; this DEM keeps a contact history for every "
            f"pair of a cell's particles and takes at most {MAX_PACKED_PARTICLES} per cell "
            "(check the units of the sizes, or simulate larger particles)")
    if per_side**2 * most > MAX_PACKING_WORK:
        raise ParameterError(
            f"{size} is too fine to pack: {per_side**2:.3g} candidate points for up to "
            f"{most:.3g} spheres (limit {MAX_PACKING_WORK:.3g} point-sphere steps); "
            "check the units of the sizes, or simulate larger particles")


def _grid_points(geometry: CellGeometry, radius_m: float,
                 axis_values: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The xy grid of ``axis_values`` along x and y as 3-D points at z = 0, and whether each
    leaves a sphere of ``radius_m`` clear of the six side walls."""
    xx, yy = np.meshgrid(axis_values, axis_values)
    pts = np.column_stack([xx.ravel(), yy.ravel(), np.zeros(xx.size)])
    sd = pts @ geometry.wall_normals[:6].T + geometry.wall_offsets[:6]
    return pts, np.all(sd >= radius_m * (1 + 1e-9), axis=1)


def _candidate_grid(geometry: CellGeometry, radius_m: float, spacing_m: float) -> np.ndarray:
    """xy points where a sphere centre may sit (inside the hexagon shrunk by the radius)."""
    check_packing_size(geometry, radius_m, spacing_m / radius_m)
    rc = (geometry.apothem_m - radius_m) * 2.0 / np.sqrt(3.0)
    pts, ok = _grid_points(geometry, radius_m, np.arange(-rc, rc + spacing_m / 2, spacing_m))
    if ok.any():
        return pts[ok, :2]
    # A near fit (sphere diameter within about a grid step, ~2 %, of the cell's width): the region
    # where a centre may sit, a hexagon of apothem (a - r), is narrower than a grid step, and
    # the grid above, anchored at its corner -rc rather than at the axis, can miss it. Lay the
    # same spacing out from the axis instead, so a node is where the room is. The axis node
    # is kept whatever the 1e-9 margin says: its distance from every side wall is the apothem
    # itself, with no rounding, and check_sphere_fits has made sure that exceeds r. (Cells
    # whose grid finds room keep the grid above, so their packings do not change.)
    k = np.arange(-np.floor(rc / spacing_m), np.floor(rc / spacing_m) + 1.0)
    pts, ok = _grid_points(geometry, radius_m, k * spacing_m)
    ok |= (pts[:, 0] == 0) & (pts[:, 1] == 0)
    return pts[ok, :2]


def drop_packing(geometry: CellGeometry, radius_m: float, n_particles: int | None, *,
                 rng: np.random.Generator | None = None,
                 gap_fraction: float = PACKING_GAP_FRACTION,
                 grid_fraction: float = GRID_FRACTION,
                 random_band_fraction: float = 0.5) -> np.ndarray:
    """Place spheres one by one, each dropped vertically onto floor and spheres below.

    Deterministic greedy ("lowest drop", ``rng=None``): each sphere goes to the candidate xy
    (grid of spacing ``grid_fraction * r`` inside the cell) where it comes to rest lowest --
    a dense sequential packing. Random (``rng`` given): each sphere is dropped at a random
    candidate xy among those where it would rest within ``random_band_fraction * r`` of the
    lowest rest height (random, slightly looser packings; different per seed). Spheres keep a gap of
    ``gap_fraction * r`` so that the start state never overlaps. Stops when the next sphere
    would stick out of the cell top; ``n_particles=None`` fills to that point.

    Returns
    -------
    (n, 3) ndarray of centres, m.
    """
    r = float(radius_m)
    cand = _candidate_grid(geometry, r, grid_fraction * r)
    floor_z = -0.5 * geometry.height_m + r * (1 + gap_fraction)
    top_z = 0.5 * geometry.height_m - r * (1 + gap_fraction)
    contact = 2.0 * r * (1 + gap_fraction)
    rest = np.full(len(cand), floor_z)
    centres: list[np.ndarray] = []
    limit = n_particles if n_particles is not None else 10**6
    while len(centres) < limit:
        if rng is None:
            idx = int(np.argmin(rest))
        else:
            low = np.flatnonzero(rest <= rest.min() + random_band_fraction * r)
            idx = int(low[rng.integers(len(low))])
        z = rest[idx]
        if z > top_z:
            if n_particles is None:
                break
            raise ParameterError(f"{n_particles} particles of radius {r * 1e3:.3g} mm do "
                                 f"not fit the cell (capacity {len(centres)})")
        c = np.array([cand[idx, 0], cand[idx, 1], z])
        centres.append(c)
        d2 = np.sum((cand - c[:2]) ** 2, axis=1)
        near = d2 < contact**2
        rest[near] = np.maximum(rest[near], z + np.sqrt(contact**2 - d2[near]))
    return np.array(centres).reshape(-1, 3)


def cell_capacity(geometry: CellGeometry, radius_m: float) -> int:
    """Number of spheres the cell holds (dense greedy drop packing, :func:`drop_packing`).

    A sequential estimate, not a proven optimum; it is the reference of ``fill_reference=
    "capacity"`` (100 % fill). A sphere just narrower than the cell stacks up its axis (a
    column); one the cell cannot hold is a ParameterError naming the limit
    (:func:`check_sphere_fits`), never a capacity of 0.
    """
    return len(drop_packing(geometry, radius_m, None))


def random_packing(geometry: CellGeometry, radius_m: float, n_particles: int,
                   rng: np.random.Generator) -> np.ndarray:
    """Random non-overlapping start packing of ``n_particles`` (see :func:`drop_packing`).

    Narrows the random band (0.5 r, 0.2 r, 0.05 r, 0.01 r) until the particles fit, then falls
    back to the dense deterministic packing; always returns centres with no overlap.
    """
    for band in (0.5, 0.2, 0.05, 0.01):
        try:
            return drop_packing(geometry, radius_m, n_particles, rng=rng,
                                random_band_fraction=band)
        except ParameterError:
            continue
    return drop_packing(geometry, radius_m, n_particles, rng=None)
