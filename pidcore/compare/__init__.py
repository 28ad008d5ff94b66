"""pidcore.compare: load cases of measurements and their alignment with DEM and the paper.

:mod:`.loadcase` says which load case a measurement belongs to (measured frequency and
acceleration, stated fill/material/direction); :mod:`.align` pairs measured cases with our DEM
grid, the pchip model over it (never extrapolated) and the paper's Table 3.
"""

from .align import (
    ALIGNMENT_STATUSES,
    DEM_COLUMNS,
    MEASURED_COLUMNS,
    AlignedCase,
    Aligner,
    AlignmentStatus,
    DemCase,
    Tolerances,
    align_measured,
    dem_cases,
    match_paper,
    pooled_mean,
    simulation_identity,
)
from .loadcase import (
    DIRECTION_PATTERN,
    FILL_PATTERN,
    MATERIAL_PATTERN,
    SIDECAR_COLUMNS,
    SIDECAR_NAME,
    LoadCase,
    LoadCaseError,
    StatedLoadCase,
    parse_file_name,
    read_sidecar,
    resolve_load_case,
)

__all__ = [
    "ALIGNMENT_STATUSES", "DEM_COLUMNS", "DIRECTION_PATTERN", "FILL_PATTERN", "MATERIAL_PATTERN",
    "MEASURED_COLUMNS", "SIDECAR_COLUMNS", "SIDECAR_NAME", "AlignedCase", "Aligner",
    "AlignmentStatus", "DemCase", "LoadCase", "LoadCaseError", "StatedLoadCase", "Tolerances",
    "align_measured", "dem_cases", "match_paper", "parse_file_name", "pooled_mean",
    "read_sidecar", "resolve_load_case", "simulation_identity",
]
