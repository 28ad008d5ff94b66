"""pidcore.dem: discrete element model of particle impact damping in honeycomb cells.

Public API
----------
LoadCase, DemConfig, simulate_load_case, DemResult
    One load case -> :class:`DemResult` (SDC, energy tallies, virtual shaker record;
    ``to_pandas()``, ``plot()``).
ContactLaw, PairLaw, PairParameters, MaterialProperties, CellGeometry
    Contact parameters (from the CSV tables or explicit properties); the hexagonal cell.
cell_capacity, particles_per_cell
    How many particles fit; fill percentage -> particle count.
measure_restitution, calibrate_damping_coefficient, simulate_impact
    Single impacts through the production kernel.

Benchmarks (kernel throughput, a grid sweep into a temporary store) are in
:mod:`pidcore.dem.bench`.
"""

# _numba_cache first: it sets up Numba's cache (where it lives, saves that fail) at its import,
# and Numba chooses a function's cache place when the modules below decorate it
from .. import _numba_cache, interrupt  # noqa: F401
from .contact import ContactLaw, PairLaw
from .geometry import CellGeometry, cell_capacity
from .impact import calibrate_damping_coefficient, measure_restitution, simulate_impact
from .materials import MaterialProperties, PairParameters
from .result import DemResult
from .simulate import DemConfig, LoadCase, particles_per_cell, simulate_load_case

interrupt.defer_while_compiling()

__all__ = ["CellGeometry", "ContactLaw", "DemConfig", "DemResult", "LoadCase",
           "MaterialProperties", "PairLaw", "PairParameters",
           "calibrate_damping_coefficient", "cell_capacity", "measure_restitution",
           "particles_per_cell", "simulate_impact", "simulate_load_case"]
