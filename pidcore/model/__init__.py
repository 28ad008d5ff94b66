"""pidcore.model: SDC interpolation model, equivalent damper and harmonic response.

Paper Sect. 3, 4 and 8: Table 3 (:func:`load_paper_table3`), the multivariate pchip SDC model
(:class:`SdcModel`), the equivalent viscous damper derived from SDC (:mod:`.damper`) and the
response of a structure treated with it (:mod:`.response`).
"""

from .damper import (
    DAMPER_COLUMNS,
    SDC_FILLED_COLUMN,
    coupon_area_m2,
    coupon_vibrated_mass_kg,
    damping_ratio,
    displacement_amplitude,
    energy_per_cycle,
    equivalent_damper_table,
    equivalent_damping_coefficient,
    loss_factor,
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
from .sdc_model import AXIS_NAMES, DEM_CONDITION_COLUMNS, SdcModel, select_runs
from .table3 import TABLE3_COLUMNS, load_paper_table3

__all__ = [
    "AXIS_NAMES", "DAMPER_COLUMNS", "DEM_CONDITION_COLUMNS", "HarmonicResponse",
    "SDC_FILLED_COLUMN", "SdcModel",
    "TABLE3_COLUMNS", "TimeDomainSteadyState", "TreatedMode", "coupon_area_m2",
    "coupon_vibrated_mass_kg", "damping_ratio", "displacement_amplitude", "energy_per_cycle",
    "equivalent_damper_table", "equivalent_damping_coefficient", "harmonic_response",
    "paper_vibrated_mass", "runs_vibrated_mass",
    "load_paper_table3", "loss_factor", "paper_particles_mass_kg", "particle_damping_n_s_m",
    "sdc_from_damping_coefficient", "sdc_from_energy_per_cycle", "select_runs",
    "time_domain_response", "write_damper_table",
]
