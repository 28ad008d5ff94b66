"""Virtual shaker 'measurements' of alumina_6mm_trial.toml at hidden true parameter values
(docs/calibration.md, "Identifiability on an own specimen"). Writes six exports in five
formats and a sidecar loadcases.csv into the folder given (default trial_exports/):

    python docs/trial_own_specimen/make_measurements.py trial_exports

The truth is one DEM realisation (4 cells, seed 777, 40 steady cycles; the calibration's runs
use seed 12345, 2 cells), with the empty structure's loss factor added to the shaker force
as a viscous force eta0 * omega * m_s * v (Re(P_c) = eta0 * 1/2 omega m_s |V|^2), 40 dB sensor
noise and a 50 us vibrometer delay (pidcore.samples.virtual_shaker_measurement).
"""

import sys
from pathlib import Path

from pidcore.dem import DemConfig, LoadCase, simulate_load_case
from pidcore.io import write_measurement
from pidcore.samples import virtual_shaker_measurement
from pidcore.specimen import load_specimen

HERE = Path(__file__).resolve().parent
TRUTH = {"pairs.particle_particle.rolling_friction": 0.04,
         "pairs.particle_wall.rolling_friction": 0.04,
         "coupon.fixture_mass_kg": 0.12, "coupon.baseline_loss_factor": 0.006}
# (frequency Hz, acceleration g, fill % of the 46-sphere capacity: 10 and 14 spheres, format)
CASES = [(200, 5, 21.7391, "uff"), (400, 3, 21.7391, "csv"), (400, 8, 30.4348, "mat"),
         (800, 5, 21.7391, "hdf5"), (800, 10, 30.4348, "uff58b"), (300, 2, 30.4348, "csv")]
EXTENSION = {"uff": "uff", "uff58b": "uff", "csv": "csv", "mat": "mat", "hdf5": "h5"}

out = Path(sys.argv[1] if len(sys.argv) > 1 else "trial_exports")
out.mkdir(parents=True, exist_ok=True)
truth = load_specimen(HERE / "alumina_6mm_trial.toml").with_values(TRUTH)
eta0 = TRUTH["coupon.baseline_loss_factor"]
rows = []
for i, (f, a, fill, fmt) in enumerate(CASES):
    case = LoadCase(float(f), float(a), fill, material="alumina")
    run = simulate_load_case(case, DemConfig(cells=4, seed=777, steady_cycles=40),
                             specimen=truth)
    steady = run.steady_slice()
    force = (run.shaker_force_n[steady]
             + eta0 * case.omega_rad_s * run.moving_mass_kg * run.velocity_m_s[steady])
    name = f"trial_f{f}Hz_a{a}g{'_58b' if fmt == 'uff58b' else ''}.{EXTENSION[fmt]}"
    measurement = virtual_shaker_measurement(
        time_s=run.sample_time_s[steady], shaker_force_n=force, frequency_hz=f,
        acceleration_m_s2=case.acceleration_m_s2, source=name, snr_db=40.0, seed=50 + i)
    write_measurement(measurement, out / name, "uff" if fmt.startswith("uff") else fmt,
                      binary=fmt == "uff58b")
    rows.append(f"{name},{fill},alumina,z,50,alumina_6mm_trial\n")
    print(f"wrote {out / name}", flush=True)
(out / "loadcases.csv").write_text(
    "file,fill_percent,material,direction,velocity_delay_us,specimen\n" + "".join(rows))
