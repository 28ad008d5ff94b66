import numpy as np, pandas as pd, math
d = pd.read_csv("damper/equivalent_damper.csv")
t3 = pd.read_csv("../../pidcore/data/paper_table3.csv", comment="#"); print(t3.columns.tolist()); print(t3.head(3))
mp = 4/3*math.pi*1.25e-3**3*1180; coupon = 2*0.01*0.25e-3*2800 + 0.01*0.0254*32.1
n = np.rint(d["packing ratio [%]"]/100*36)
mc = coupon + 441*n*mp
w = 2*np.pi*d["frequency [Hz]"]; a = d["acceleration [g]"]*9.80665; s = d["sdc [-]"]
mine = {"coupon_vibrated_mass [kg]": mc, "coupon_loss_factor [-]": s/(2*np.pi), "coupon_damping_ratio [-]": -np.log(1-s)/(4*np.pi),
        "coupon_energy_per_cycle [J]": s*mc*a**2/(2*w**2), "displacement_amplitude [m]": a/w**2,
        "c_eq_per_coupon [N s/m]": s*mc*a**2/(2*w**2)/(np.pi*w*(a/w**2)**2), "c_eq_per_treated_area [N s/m^3]": s*mc*w/(2*np.pi)/0.01}
for k, v in mine.items():
    rel = np.abs(d[k]/v - 1).max(); print(f"| damper {k} | max rel diff over {len(d)} rows | {rel:.2e} |")
# SDC at grid points vs paper table
key = ["frequency [Hz]", "acceleration [g]", "packing ratio [%]"]
