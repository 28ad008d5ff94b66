"""Round 14 audit: `pidcore model damper --table store` against the stored DEM energies.

The damper a FEM model takes must dissipate, per cycle, what the DEM's coupon dissipated:
c_eq = dE / (pi w X^2), X = a / w^2, with dE the run's stored energy per cycle (not its SDC).
Here dE, a and f come from each stored run; m_c is rebuilt from Tables 1-2 and the run's own
particle count (441 cells); the loss factor is SDC / (2 pi) and the damping ratio
-ln(1 - SDC) / (4 pi) (paper Sect. 3), NaN for SDC >= 1. Also the JSON's unit map.

  pidcore model damper --table store --store STORE.h5 --out DIR
  python damper_store_ref.py DIR STORE.h5
"""
import json
import math
import sys
from pathlib import Path

import numpy as np
import pandas as pd

G = 9.80665


def main(out_dir: str, store_h5: str) -> None:
    sys.path.insert(0, str(Path(__file__).resolve().parents[2]))
    from pidcore.store import Store  # the listing only: the numbers are those stored

    table = pd.read_csv(Path(out_dir) / "equivalent_damper.csv")
    units = json.loads((Path(out_dir) / "equivalent_damper.json").read_text())["units"]
    for column, unit in units.items():
        assert column.endswith(f"[{unit}]"), (column, unit)
    runs = Store(store_h5).list_dem_runs()
    worst: dict[str, float] = {}
    for _, run in runs.iterrows():
        row = table[(table["frequency [Hz]"] == run.frequency_hz)
                    & (table["acceleration [g]"] == run.acceleration_g)
                    & (table["packing ratio [%]"] == run.fill_percent)].iloc[0]
        w = 2 * math.pi * run.frequency_hz
        a = run.acceleration_g * G
        x = a / w**2
        m_c = 441 * run.particles_per_cell * 4 / 3 * math.pi * 1.25e-3**3 * 1180 \
            + 2 * 0.01 * 0.25e-3 * 2800 + 0.01 * 0.0254 * 32.1
        sdc = run.energy_per_cycle_j / (m_c * a**2 / (2 * w**2))
        mine = {"sdc [-]": sdc, "coupon_vibrated_mass [kg]": m_c,
                "coupon_energy_per_cycle [J]": run.energy_per_cycle_j,
                "displacement_amplitude [m]": x,
                "c_eq_per_coupon [N s/m]": run.energy_per_cycle_j / (math.pi * w * x**2),
                "c_eq_per_treated_area [N s/m^3]": run.energy_per_cycle_j / (math.pi * w * x**2) / 0.01,
                "coupon_loss_factor [-]": sdc / (2 * math.pi),
                "coupon_damping_ratio [-]": -math.log(1 - sdc) / (4 * math.pi) if sdc < 1 else math.nan}
        for column, value in mine.items():
            if math.isnan(value):
                assert math.isnan(row[column]), (column, row[column])
                continue
            worst[column] = max(worst.get(column, 0.0), abs(row[column] / value - 1))
    for column, rel in worst.items():
        print(f"| damper --table store {column} | {len(runs)} runs | {rel:.1e} |")
    print("NaN damping ratio where SDC >= 1:", int(table["coupon_damping_ratio [-]"].isna().sum()),
          "rows; SDC >= 1 in", int((table["sdc [-]"] >= 1).sum()))


if __name__ == "__main__":
    main(*sys.argv[1:3])
