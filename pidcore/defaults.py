"""Every default value in one place (python-control style).

Change a default here and every CLI option, function and app widget follows.
"""

from pathlib import Path

#: Store file used when none is given.
STORE_PATH = Path("pid_store.h5")

# --- Measurement (Eq. 11) -------------------------------------------------------------------
#: Number of drive harmonics fitted (1 = fundamental only). Harmonics above Nyquist are dropped.
N_HARMONICS = 5
#: Fewest whole drive periods accepted in a record.
MIN_PERIODS = 10
#: Number of blocks of whole periods for the standard error of the SDC.
N_UNCERTAINTY_BLOCKS = 8
#: A sample within this fraction of the channel's extreme value counts toward clipping detection.
CLIPPING_RELATIVE_TOLERANCE = 1e-9
#: Run of identical extreme samples that flags a channel as clipped.
CLIPPING_MIN_RUN = 4

# --- DEM ------------------------------------------------------------------------------------
DEM_TIME_STEP_S = 2e-6
DEM_MIN_STEPS_PER_CONTACT = 10
DEM_CELLS = 8
DEM_MIN_STEADY_CYCLES = 80
DEM_MAX_OVERLAP_FRACTION = 0.05
DEM_SEED = 12345

# --- Coupon (paper Sect. 2, Table 2) ---------------------------------------------------------
COUPON_SIDE_M = 0.100
COUPON_CELLS = 441
CELL_INSCRIBED_DIAMETER_M = 4.76e-3
CELL_HEIGHT_M = 25.4e-3
FACE_SHEET_THICKNESS_M = 0.25e-3
FACE_SHEET_DENSITY_KG_M3 = 2800.0
CORE_DENSITY_KG_M3 = 32.1
#: The paper's particle count per cell that it calls 100 % fill (Sect. 5.1).
PAPER_PARTICLES_PER_FULL_CELL = 36

# --- Reports / app --------------------------------------------------------------------------
APP_PORT = 8501
APP_MAX_UPLOAD_MB = 200
