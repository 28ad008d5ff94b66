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
class Material:
    """One row of ``materials.csv`` (SI units)."""

    name: str
    role: str
    density_kg_m3: float
    youngs_modulus_pa: float
    poisson_ratio: float
    default_radius_m: float  # nan for walls (flat: infinite radius)

    def sphere_mass(self, radius_m: float) -> float:
        """Mass of a solid sphere of this material, kg."""
        return self.density_kg_m3 * 4.0 / 3.0 * np.pi * radius_m**3


@dataclass(frozen=True)
class PairProperties:
    """One row of ``material_pairs.csv``: sliding friction and normal restitution [-]."""

    material_a: str
    material_b: str
    sliding_friction: float
    normal_restitution: float


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


def pair_properties(name_a: str, name_b: str) -> PairProperties:
    """Friction and restitution of a pair of materials (order does not matter)."""
    table = pair_table()
    hit = table[((table.material_a == name_a) & (table.material_b == name_b))
                | ((table.material_a == name_b) & (table.material_b == name_a))]
    if hit.empty:
        raise ParameterError(
            f"material pair: no row for ({name_a!r}, {name_b!r}) in "
            "pidcore/data/material_pairs.csv")
    row = hit.iloc[0]
    return PairProperties(name_a, name_b, float(row["sliding_friction"]),
                          float(row["normal_restitution"]))
