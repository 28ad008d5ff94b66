"""pidcore.model: SDC interpolation model, equivalent damper and harmonic response.

Paper Sect. 3, 4 and 8: Table 3 (:func:`load_paper_table3`), the multivariate pchip SDC model
(:class:`SdcModel`), the equivalent viscous damper derived from SDC (:mod:`.damper`) and the
response of a structure treated with it (:mod:`.response`).

Public API
----------
load_paper_table3, TABLE3_COLUMNS
    The paper's Table 3 (DEM and measured SDC over fill, acceleration, frequency).
SdcModel, AXIS_NAMES
    The pchip SDC model: ``SdcModel.from_table(table)(fill_percent, acceleration_g,
    frequency_hz)``; refuses points outside its grid.
HeldEdge, HELD_ERRORS
    ``SdcModel.held_edges(point)``: the axes a point lies beyond, the model's slope at each
    edge and which way holding the edge SDC errs there.
FilledDependence
    ``SdcModel.filled_dependence(points)``: which filled holes of the grid (the paper's
    1000 Hz, 1 g, 90 %) the SDC at each point rests on, and how far it moves with each.
select_runs, DEM_CONDITION_COLUMNS
    The stored DEM runs of one set of conditions, to build a model from.
equivalent_damper_table, write_damper_table, DAMPER_COLUMNS, DAMPER_COLUMN_MEANINGS
    The equivalent viscous damper over a grid (a pandas frame whose columns name what each
    is per, coupon, cell or treated area, and their units; what each is), and its CSV/JSON
    files.
DAMPER_COLUMNS_RENAMED
    The older names of its columns -> the present ones (``.rename(columns=...)``).
SDC_FILLED_COLUMN, SDC_FILLED_NOTE, SDC_HELD_COLUMN, SDC_HELD_ERROR_COLUMN
    Its flags: SDC resting on a filled hole of the grid (and, in ``attrs``, on which and how
    far it moves with it), SDC held at the grid's edge, and which way
    that errs (SdcModel.held_edges: the model's slope at the edge).
loss_factor, damping_ratio, energy_per_cycle, sdc_from_energy_per_cycle, displacement_amplitude
    SDC to loss factor, damping ratio, energy per cycle (Eq. 8-10) and back.
panel_loss_factor, PANEL_COLUMNS
    The loss factor the particles add to a panel of known areal mass moving as the coupon
    did (equivalent_damper_table's panel_areal_mass_kg_m2; CLI --panel-areal-mass).
equivalent_damping_coefficient, sdc_from_damping_coefficient
    SDC to c_eq [N s/m] and back.
coupon_area_m2, coupon_vibrated_mass_kg, paper_particles_mass_kg
    The paper coupon's area and masses.
paper_vibrated_mass, runs_vibrated_mass
    m_c of Eq. 10 against fill: the paper's coupon, or as stored DEM runs normalised it.
TreatedMode, harmonic_response, HarmonicResponse, particle_damping_n_s_m
    A mode treated with particles, its steady response by harmonic balance (``to_pandas()``,
    ``plot()``) and the particle damper c_pd.
time_domain_response, TimeDomainSteadyState
    The same oscillator integrated in time (a check of the harmonic balance).
"""

from .damper import (
    DAMPER_COLUMN_MEANINGS,
    DAMPER_COLUMNS,
    DAMPER_COLUMNS_RENAMED,
    PANEL_COLUMNS,
    SDC_FILLED_COLUMN,
    SDC_FILLED_NOTE,
    SDC_HELD_COLUMN,
    SDC_HELD_ERROR_COLUMN,
    coupon_area_m2,
    coupon_vibrated_mass_kg,
    damping_ratio,
    displacement_amplitude,
    energy_per_cycle,
    equivalent_damper_table,
    equivalent_damping_coefficient,
    loss_factor,
    panel_loss_factor,
    paper_particles_mass_kg,
    paper_vibrated_mass,
    runs_vibrated_mass,
    sdc_from_damping_coefficient,
    sdc_from_energy_per_cycle,
    write_damper_table,
)
from .response import (
    HarmonicResponse,
    TimeDomainSteadyState,
    TreatedMode,
    harmonic_response,
    particle_damping_n_s_m,
    time_domain_response,
)
from .sdc_model import (
    AXIS_NAMES,
    DEM_CONDITION_COLUMNS,
    HELD_ERRORS,
    FilledDependence,
    HeldEdge,
    SdcModel,
    select_runs,
)
from .table3 import TABLE3_COLUMNS, load_paper_table3

__all__ = [
    "AXIS_NAMES", "DAMPER_COLUMN_MEANINGS", "DAMPER_COLUMNS",
    "DAMPER_COLUMNS_RENAMED", "PANEL_COLUMNS", "panel_loss_factor", "DEM_CONDITION_COLUMNS",
    "FilledDependence", "HELD_ERRORS", "HarmonicResponse", "HeldEdge",
    "SDC_FILLED_COLUMN", "SDC_FILLED_NOTE", "SDC_HELD_COLUMN", "SDC_HELD_ERROR_COLUMN", "SdcModel",
    "TABLE3_COLUMNS", "TimeDomainSteadyState", "TreatedMode", "coupon_area_m2",
    "coupon_vibrated_mass_kg", "damping_ratio", "displacement_amplitude", "energy_per_cycle",
    "equivalent_damper_table", "equivalent_damping_coefficient", "harmonic_response",
    "paper_vibrated_mass", "runs_vibrated_mass",
    "load_paper_table3", "loss_factor", "paper_particles_mass_kg", "particle_damping_n_s_m",
    "sdc_from_damping_coefficient", "sdc_from_energy_per_cycle", "select_runs",
    "time_domain_response", "write_damper_table",
]
