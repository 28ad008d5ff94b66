"""Closed vocabularies and physical constants shared by all subpackages.

Closed vocabularies are ``Literal`` aliases so that type checkers and ``get_args`` can validate
user input in one place.

Public API
----------
Quantity, ChannelRole, FileFormat, DriveDirection, ParticleMaterial, NormalDampingMode
    Closed vocabularies (``Literal`` aliases) of channels, files, load cases and contact laws.
VibratedMassConvention, StartProtocol, TangentialModel, TangentialStiffnessModel
    The DEM's model options, as ``pidcore dem run`` takes them.
StartPacking, CellShape, ReportFormat, FillReference, AlignmentStatus, ImpactPair
    More closed vocabularies: packings, cells, report formats, fill references, alignments.
DampingCoefficient, BackgroundState, BandVerdict
    The normal damping constant's choice; the states of an app page's background work; a
    measured SDC's verdict against the calibrated DEM's 95 % band.
QUANTITIES, CHANNEL_ROLES, DRIVE_DIRECTIONS, PARTICLE_MATERIALS, NORMAL_DAMPING_MODES
    Each vocabulary's values as a tuple (``get_args`` of its alias).
VIBRATED_MASS_CONVENTIONS, START_PROTOCOLS, TANGENTIAL_MODELS, START_PACKINGS
    The same, for the DEM's model options.
TANGENTIAL_STIFFNESS_MODELS, REPORT_FORMATS, FILL_REFERENCES, DAMPING_COEFFICIENTS
    The same, for the rest.
CELL_SHAPES, BACKGROUND_STATES, ALIGNMENT_STATUSES, IMPACT_PAIRS, BAND_VERDICTS
    The same, for the rest.
UNTABULATED_PARTICLE_MATERIALS
    Particle materials a file name may state that the material table lacks (refused unless a
    specimen file gives them).
PACKING_RATIO_COLUMN
    The fill of the cells with particles as every table and figure names it.
STANDARD_GRAVITY, RATIO_UNIT, COUNT_UNIT, SI_UNITS
    Standard gravity (m/s^2) and the one spelling of each unit in every output.
"""

from typing import Literal, get_args

__all__ = [
    "Quantity", "ChannelRole", "FileFormat", "DriveDirection", "ParticleMaterial",
    "NormalDampingMode", "VibratedMassConvention", "StartProtocol", "TangentialModel",
    "TangentialStiffnessModel", "StartPacking", "CellShape", "ReportFormat", "FillReference",
    "AlignmentStatus", "ImpactPair", "DampingCoefficient", "BackgroundState", "BandVerdict",
    "QUANTITIES",
    "CHANNEL_ROLES", "DRIVE_DIRECTIONS", "PARTICLE_MATERIALS", "NORMAL_DAMPING_MODES",
    "VIBRATED_MASS_CONVENTIONS", "START_PROTOCOLS", "TANGENTIAL_MODELS", "START_PACKINGS",
    "TANGENTIAL_STIFFNESS_MODELS", "REPORT_FORMATS", "FILL_REFERENCES", "DAMPING_COEFFICIENTS",
    "CELL_SHAPES", "BACKGROUND_STATES", "ALIGNMENT_STATUSES", "IMPACT_PAIRS", "BAND_VERDICTS",
    "UNTABULATED_PARTICLE_MATERIALS", "PACKING_RATIO_COLUMN", "STANDARD_GRAVITY", "RATIO_UNIT",
    "COUNT_UNIT", "SI_UNITS",
]

#: Physical quantity a channel carries (after unit normalisation).
Quantity = Literal["force", "velocity", "acceleration", "displacement", "pressure", "voltage",
                   "time", "unknown"]
#: Role a channel plays in a power analysis.
ChannelRole = Literal["force", "velocity", "acceleration"]
#: File formats the readers understand.
FileFormat = Literal["uff", "csv", "mat", "hdf5"]
#: Drive direction of the coupon in the cell frame (z normal to the face sheets).
DriveDirection = Literal["z", "x", "y"]
#: Particle materials in the materials table.
ParticleMaterial = Literal["acrylic", "aluminium"]
#: Normal damping behaviour at the end of a contact (Eq. 2 taken literally or cut at zero).
NormalDampingMode = Literal["literal", "no_attraction"]
#: Which mass enters E = m_c a^2 / (2 w^2) (Eq. 10).
VibratedMassConvention = Literal["coupon_plus_particles", "coupon", "particles"]
#: How particles move when the drive starts.
StartProtocol = Literal["rest", "with_cell"]
#: Tangential contact force (Eq. 5): "stick_slip" = elastic tangential spring capped by
#: mu |f_n| (Cundall-Strack); "coulomb" = Eq. 5 as written, regularised near v_t = 0.
TangentialModel = Literal["stick_slip", "coulomb"]
#: Tangential spring stiffness of the stick-slip model: "constant" = Mindlin's k_t at a
#: reference overlap; "mindlin" = 8 G* sqrt(R* delta) of the current overlap.
TangentialStiffnessModel = Literal["constant", "mindlin"]
#: Packing the drive starts from: "dense" = settled without friction, then settled again
#: with friction; "loose" = settled with friction from the random drop.
StartPacking = Literal["dense", "loose"]
#: Cell shape of a specimen (``[cell] shape``); cylindrical and rectangular cells may follow.
CellShape = Literal["hexagonal"]
#: Report output formats.
ReportFormat = Literal["csv", "md", "html", "tex", "pdf"]
#: What 100 % fill is: the cell's capacity (dense drop packing) or the paper's 36 particles.
FillReference = Literal["capacity", "paper"]
#: How a measured case was matched with our DEM (:mod:`pidcore.compare.align`): at a grid
#: point of the runs, interpolated by the pchip model, outside its range, runs over which no
#: pchip model can be built (one fill only, say), or no runs at all.
AlignmentStatus = Literal["grid", "interpolated", "out_of_range", "no_model", "no_dem_runs"]
#: What a single-impact run hits (:mod:`pidcore.dem.impact`): a wall or another particle.
ImpactPair = Literal["wall", "particle"]
#: Normal damping constant: "eq3" = alpha from the table's e_n by Eq. 3; "calibrated" = alpha
#: root-found so that a simulated head-on impact gives the table's e_n exactly.
DampingCoefficient = Literal["eq3", "calibrated"]
#: State of work an app page runs outside Streamlit's script run (a report build, a
#: calibration), in the order it passes through them: running, then done or failed.
BackgroundState = Literal["running", "done", "failed", "cancelled"]
#: Whether a measured Eq. 11 SDC lies in the calibrated DEM's 95 % band (the report's column,
#: the app's Compare page): "yes", "no", "not compared" (no band or no measurement to judge;
#: not "n/a", which pandas.read_csv reads back as NaN), or "uninformative" (the band spans
#: every plausible SDC, 0 .. 2 pi, so it cannot test the model; not counted as inside).
BandVerdict = Literal["yes", "no", "not compared", "uninformative"]

#: Particle materials in use for particle dampers that the material table does not hold: a
#: file name stating one (``..._fill50_steel.csv``) is refused unless a specimen file gives
#: the material, instead of being read as the default acrylic.
UNTABULATED_PARTICLE_MATERIALS: tuple[str, ...] = (
    "steel", "stainless", "tungsten", "carbide", "glass", "brass", "bronze", "copper", "lead",
    "titanium", "nylon", "ptfe", "teflon", "delrin", "polyurethane", "rubber", "ceramic",
    "zirconia", "alumina")

ALIGNMENT_STATUSES: tuple[str, ...] = get_args(AlignmentStatus)
IMPACT_PAIRS: tuple[str, ...] = get_args(ImpactPair)
QUANTITIES: tuple[str, ...] = get_args(Quantity)
CHANNEL_ROLES: tuple[str, ...] = get_args(ChannelRole)
DRIVE_DIRECTIONS: tuple[str, ...] = get_args(DriveDirection)
PARTICLE_MATERIALS: tuple[str, ...] = get_args(ParticleMaterial)
NORMAL_DAMPING_MODES: tuple[str, ...] = get_args(NormalDampingMode)
VIBRATED_MASS_CONVENTIONS: tuple[str, ...] = get_args(VibratedMassConvention)
START_PROTOCOLS: tuple[str, ...] = get_args(StartProtocol)
TANGENTIAL_MODELS: tuple[str, ...] = get_args(TangentialModel)
START_PACKINGS: tuple[str, ...] = get_args(StartPacking)
TANGENTIAL_STIFFNESS_MODELS: tuple[str, ...] = get_args(TangentialStiffnessModel)
REPORT_FORMATS: tuple[str, ...] = get_args(ReportFormat)
FILL_REFERENCES: tuple[str, ...] = get_args(FillReference)
DAMPING_COEFFICIENTS: tuple[str, ...] = get_args(DampingCoefficient)
CELL_SHAPES: tuple[str, ...] = get_args(CellShape)
BACKGROUND_STATES: tuple[str, ...] = get_args(BackgroundState)
BAND_VERDICTS: tuple[str, ...] = get_args(BandVerdict)
#: The fill of the cells with particles, by the paper's term, as every table and figure of
#: pidcore names it (the report's files, :meth:`pidcore.calibrate.Calibration.to_pandas`,
#: calibration's summary.md/html, the equivalent damper's table, the app's tables and charts).
#: Calibration and the damper table called it "fill [%]" before 2026-12
#: (:data:`pidcore.calibrate.CALIBRATION_COLUMNS_RENAMED`,
#: :data:`pidcore.model.DAMPER_COLUMNS_RENAMED`) beside the report's name for the same number.
#: Here, not in :mod:`pidcore.compare.align`, so that :mod:`pidcore.model` can use it too.
PACKING_RATIO_COLUMN = "packing ratio [%]"

#: Standard gravity, m/s^2 (ISO 80000-3); used for g <-> m/s^2 and for gravity on particles.
STANDARD_GRAVITY = 9.80665

#: Unit of a dimensionless ratio (loss factor, SDC, a relative error) and of a count (steps,
#: periods, harmonic numbers, particles) in the store and every output: one spelling each.
RATIO_UNIT = "-"
COUNT_UNIT = "1"

#: SI unit of each quantity, as written in every output.
SI_UNITS: dict[str, str] = {
    "force": "N",
    "velocity": "m/s",
    "acceleration": "m/s^2",
    "displacement": "m",
    "pressure": "Pa",
    "voltage": "V",
    "time": "s",
    "unknown": "1",
}
