"""Virtual shaker 'measurements' of alumina_6mm_trial.toml at hidden true parameter values
(docs/calibration.md, "Identifiability on an own specimen"). Writes six exports in five
formats and a sidecar loadcases.csv into the folder given (default trial_exports/):

    python docs/trial_own_specimen/make_measurements.py trial_exports

The truth is one DEM realisation (4 cells, seed 777, 40 steady cycles; the calibration's runs
use seed 12345, 2 cells), with the empty structure's loss factor added to the shaker force
as a viscous force eta0 * omega * m_s * v (Re(P_c) = eta0 * 1/2 omega m_s |V|^2), 40 dB sensor
noise and a 50 us vibrometer delay (pidcore.samples.own_specimen_exports).

For your own specimen change SPECIMEN_FILE, TRUTH and CASES: the load cases' particle
material and the sidecar's specimen name are taken from the specimen file.
"""

import sys
from pathlib import Path

from pidcore.dem import DemConfig
from pidcore.samples import own_specimen_exports
from pidcore.specimen import load_specimen

SPECIMEN_FILE = Path(__file__).resolve().parent / "alumina_6mm_trial.toml"
TRUTH = {"pairs.particle_particle.rolling_friction": 0.04,
         "pairs.particle_wall.rolling_friction": 0.04,
         "coupon.fixture_mass_kg": 0.12, "coupon.baseline_loss_factor": 0.006}
# (frequency Hz, acceleration g, fill % of the 46-sphere capacity: 10 and 14 spheres, format:
# uff, uff58b, csv, mat or hdf5); each file name states its fill
CASES = [(200, 5, 21.7391, "uff"), (400, 3, 21.7391, "csv"), (400, 8, 30.4348, "mat"),
         (800, 5, 21.7391, "hdf5"), (800, 10, 30.4348, "uff58b"), (300, 2, 30.4348, "csv")]

if __name__ == "__main__":
    own_specimen_exports(load_specimen(SPECIMEN_FILE).with_values(TRUTH), CASES,
                         sys.argv[1] if len(sys.argv) > 1 else "trial_exports",
                         config=DemConfig(cells=4, seed=777, steady_cycles=40),
                         report=lambda line: print(line, flush=True))
