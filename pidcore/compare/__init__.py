"""pidcore.compare: load cases of measurements and their alignment with DEM and the paper.

:mod:`.loadcase` says which load case a measurement belongs to (measured frequency and
acceleration, stated fill/material/direction); :mod:`.align` pairs measured cases with our DEM
grid, the pchip model over it (never extrapolated) and the paper's Table 3;
:mod:`.settings_columns` says what each analysis column of a settings table sets and how every
analysis setting is said in words.

Public API
----------
LoadCase, LoadCaseError
    The load case (:mod:`pidcore.loadcase`, the same class).
StatedLoadCase, resolve_load_case, parse_file_name, read_sidecar
    What a file's name, a sidecar table and options state about its load case.
SIDECAR_NAME, SIDECAR_COLUMNS, FILL_PATTERN, MATERIAL_PATTERN, DIRECTION_PATTERN
    The sidecar table's name and load-case columns; what a file name may state.
Aligner, align_measured, AlignedCase, AlignmentStatus, ALIGNMENT_STATUSES
    Measured cases beside our DEM (grid point, interpolated, out of range, no model, no runs).
Tolerances
    When two load cases are the same grid point.
dem_cases, DemCase, pooled_mean, simulation_identity
    Stored DEM runs pooled into load cases (mean and standard error over seeds).
match_paper
    The paper's Table 3 SDCs at a grid point.
DEM_COLUMNS, MEASURED_COLUMNS
    Columns the aligner reads.
MEASURED_EQ11_COLUMN, MEASURED_EQ11_STDERR_COLUMN, MEASURED_EQ11_DOF_COLUMN
    The measured Eq. 11 SDC's columns as every table names them.
MEASURED_BASELINE_COLUMN
    The part of it the analysis took off as the empty coupon's damping.
MEASURED_COLUMNS_RENAMED
    Their old names -> these, for a table an earlier pidcore wrote.
CALIBRATED_COLUMN, CALIBRATED_LOW_COLUMN, CALIBRATED_HIGH_COLUMN
    The calibrated DEM's Eq. 11 SDC and its 95 % band as every table names them.
"""

from .align import (
    ALIGNMENT_STATUSES,
    CALIBRATED_COLUMN,
    CALIBRATED_HIGH_COLUMN,
    CALIBRATED_LOW_COLUMN,
    DEM_COLUMNS,
    MEASURED_BASELINE_COLUMN,
    MEASURED_COLUMNS,
    MEASURED_COLUMNS_RENAMED,
    MEASURED_EQ11_COLUMN,
    MEASURED_EQ11_DOF_COLUMN,
    MEASURED_EQ11_STDERR_COLUMN,
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
    "ALIGNMENT_STATUSES", "CALIBRATED_COLUMN", "CALIBRATED_HIGH_COLUMN", "CALIBRATED_LOW_COLUMN",
    "DEM_COLUMNS", "DIRECTION_PATTERN", "FILL_PATTERN", "MATERIAL_PATTERN",
    "MEASURED_BASELINE_COLUMN", "MEASURED_COLUMNS", "MEASURED_COLUMNS_RENAMED",
    "MEASURED_EQ11_COLUMN",
    "MEASURED_EQ11_DOF_COLUMN", "MEASURED_EQ11_STDERR_COLUMN", "SIDECAR_COLUMNS", "SIDECAR_NAME",
    "AlignedCase", "Aligner",
    "AlignmentStatus", "DemCase", "LoadCase", "LoadCaseError", "StatedLoadCase", "Tolerances",
    "align_measured", "dem_cases", "match_paper", "parse_file_name", "pooled_mean",
    "read_sidecar", "resolve_load_case", "simulation_identity",
]
