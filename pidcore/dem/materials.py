"""Material and contact-pair parameters read from ``pidcore/data/*.csv`` (paper Tables 1-2).

The tables are read once (pandas) and cached; every DEM parameter derives from them, so a
changed table changes every simulation, and no physical constant is a literal in the kernel.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass
from importlib import resources

import numpy as np
import pandas as pd

from ..errors import ParameterError

#: Name of the wall material row in ``materials.csv`` (AA 5056 core / AA 2024 face sheets).
WALL_MATERIAL = "aluminium_wall"


@dataclass(frozen=True)
class MaterialProperties:
    """Elastic properties and density of one material (SI units), from the table or a specimen.

    Examples
    --------
    >>> MaterialProperties(density_kg_m3=7800, youngs_modulus_pa=200e9, poisson_ratio=0.3)
    ... # doctest: +ELLIPSIS
    MaterialProperties(density_kg_m3=7800, ...)
    """

    density_kg_m3: float
    youngs_modulus_pa: float
    poisson_ratio: float

    def __post_init__(self):
        if not self.density_kg_m3 > 0:
            raise ParameterError(f"density: expected > 0 kg/m^3, got {self.density_kg_m3}")
        if not self.youngs_modulus_pa > 0:
            raise ParameterError(f"youngs_modulus: expected > 0 Pa, got {self.youngs_modulus_pa}")
        if not -1.0 < self.poisson_ratio < 0.5:
            raise ParameterError(f"poisson_ratio: expected -1 < nu < 0.5, got {self.poisson_ratio}")

    def sphere_mass(self, radius_m: float) -> float:
        """Mass of a solid sphere of this material, kg."""
        return self.density_kg_m3 * 4.0 / 3.0 * np.pi * radius_m**3


@dataclass(frozen=True)
class Material:
    """One row of ``materials.csv`` (SI units)."""

    name: str
    role: str
    density_kg_m3: float
    youngs_modulus_pa: float
    poisson_ratio: float
    default_radius_m: float  # nan for walls (flat: infinite radius)

    @property
    def properties(self) -> MaterialProperties:
        """Density and elastic constants as a :class:`MaterialProperties`."""
        return MaterialProperties(density_kg_m3=self.density_kg_m3,
                                  youngs_modulus_pa=self.youngs_modulus_pa,
                                  poisson_ratio=self.poisson_ratio)

    def sphere_mass(self, radius_m: float) -> float:
        """Mass of a solid sphere of this material, kg."""
        return self.properties.sphere_mass(radius_m)


@dataclass(frozen=True)
class PairParameters:
    """Contact parameters of one pair of materials, all dimensionless.

    ``restitution``: normal coefficient of restitution e_n (0 < e <= 1).
    ``sliding_friction``: mu, the Coulomb coefficient while the contact slides.
    ``static_friction``: mu_s >= mu, the limit a sticking contact must exceed to break loose
    (None: equal to ``sliding_friction``, which is the model before static friction existed).
    ``rolling_friction``: mu_r, the largest rolling resistance torque is mu_r R* |f_n|
    (0: no rolling resistance). ``rolling_damping_ratio``: eta_r of the rolling dashpot, as a
    fraction of its critical value (0: the dashpot is off, LIGGGHTS ``epsd2``).
    """

    restitution: float
    sliding_friction: float
    static_friction: float | None = None
    rolling_friction: float = 0.0
    rolling_damping_ratio: float = 0.0

    def __post_init__(self):
        if self.static_friction is None:
            object.__setattr__(self, "static_friction", self.sliding_friction)
        if not 0.0 < self.restitution <= 1.0:
            raise ParameterError(f"restitution: expected 0 < e <= 1, got {self.restitution}")
        if not self.sliding_friction >= 0.0:
            raise ParameterError(
                f"sliding_friction: expected >= 0, got {self.sliding_friction}")
        if not self.static_friction >= self.sliding_friction:
            raise ParameterError(
                f"static_friction: expected >= sliding_friction {self.sliding_friction}, "
                f"got {self.static_friction}")
        if not self.rolling_friction >= 0.0:
            raise ParameterError(
                f"rolling_friction: expected >= 0, got {self.rolling_friction}")
        if not self.rolling_damping_ratio >= 0.0:
            raise ParameterError(
                f"rolling_damping_ratio: expected >= 0, got {self.rolling_damping_ratio}")


def _read_csv(name: str) -> pd.DataFrame:
    path = resources.files("pidcore") / "data" / name
    with resources.as_file(path) as p:
        return pd.read_csv(p, comment="#")


@functools.cache
def material_table() -> pd.DataFrame:
    """The materials table, indexed by name."""
    return _read_csv("materials.csv").set_index("name")


@functools.cache
def pair_table() -> pd.DataFrame:
    """The material-pair table (rows are unordered pairs)."""
    return _read_csv("material_pairs.csv")


def material(name: str) -> Material:
    """Look up a material by name.

    Examples
    --------
    >>> material("acrylic").default_radius_m
    0.00125
    """
    table = material_table()
    if name not in table.index:
        raise ParameterError(
            f"material: unknown material {name!r}; expected one of {sorted(table.index)} "
            "(pidcore/data/materials.csv)")
    row = table.loc[name]
    return Material(name=name, role=str(row["role"]),
                    density_kg_m3=float(row["density_kg_m3"]),
                    youngs_modulus_pa=float(row["youngs_modulus_pa"]),
                    poisson_ratio=float(row["poisson_ratio"]),
                    default_radius_m=float(row["default_radius_m"]))


def pair_properties(name_a: str, name_b: str) -> PairParameters:
    """Restitution and friction coefficients of a pair of materials (order does not matter).

    Examples
    --------
    >>> pair_properties("acrylic", "aluminium_wall").sliding_friction
    0.14
    """
    table = pair_table()
    hit = table[((table.material_a == name_a) & (table.material_b == name_b))
                | ((table.material_a == name_b) & (table.material_b == name_a))]
    if hit.empty:
        raise ParameterError(
            f"material pair: no row for ({name_a!r}, {name_b!r}) in "
            "pidcore/data/material_pairs.csv")
    row = hit.iloc[0]
    return PairParameters(restitution=float(row["normal_restitution"]),
                          sliding_friction=float(row["sliding_friction"]),
                          static_friction=float(row["static_friction"]),
                          rolling_friction=float(row["rolling_friction"]))
