"""Round 14 audit: the app's Compare numbers against the CLI's, for the stored measurements.

The equivalent damper the Compare page prints for "our DEM" (c_eq = SDC m_c w / (2 pi) of the
grid case) against `pidcore model damper --table store` at that grid point, and the page's
measured SDC with E of Eq. 10 against the report's column.

  python app_cli_ref.py STORE.h5 DAMPER_DIR REPORT.csv
"""
import sys
from pathlib import Path

import pandas as pd

sys.path.insert(0, str(Path(__file__).resolve().parents[2]))
from pidcore.compare.case import MeasuredEntry, compare_case, equivalent_dampers  # noqa: E402
from pidcore.model import load_paper_table3  # noqa: E402
from pidcore.store import Store  # noqa: E402
from pidcore.store.listing import saved_analyses  # noqa: E402

store_h5, damper_dir, report_csv = sys.argv[1:4]
store = Store(store_h5)
runs = store.list_dem_runs()
damper = pd.read_csv(Path(damper_dir) / "equivalent_damper.csv")
report = pd.read_csv(report_csv, comment="#")
worst = [0.0, 0.0]
for _, row in saved_analyses(store_h5).iterrows():
    entry = MeasuredEntry.from_store(row, store.get_analysis(str(row["key"])).arrays)
    comp = compare_case([entry], runs, load_paper_table3())
    g = comp.aligned.grid_case.load_case
    cli = damper[(damper["frequency [Hz]"] == g.frequency_hz)
                 & (damper["acceleration [g]"] == g.acceleration_g)
                 & (damper["packing ratio [%]"] == g.fill_percent)]["c_eq_per_coupon [N s/m]"].iloc[0]
    rep = report[report["source file(s)"].fillna("").str.endswith(entry.file)].iloc[0]
    worst[0] = max(worst[0], abs(equivalent_dampers(comp)["our DEM"] / cli - 1))
    worst[1] = max(worst[1], abs(comp.measured_sdc_eq10 / rep["SDC measured, E of Eq. 10 [-]"]
                                 - 1))
print(f"app c_eq vs model damper: {worst[0]:.1e}; app Eq. 10 SDC vs report: {worst[1]:.1e}")
