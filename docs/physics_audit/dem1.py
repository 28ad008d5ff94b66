import math, dataclasses, numpy as np
from scipy.integrate import solve_ivp
from pidcore.specimen import load_specimen, contact_law
from pidcore.dem.impact import simulate_impact
from pidcore.dem.geometry import CellGeometry
from pidcore.dem.state import CellsState, KernelSettings, advance
G = 9.80665
def my_alpha(e):  # paper Eq. 3
    l = math.log(e); return -l*math.sqrt(5/(l*l+math.pi**2))
def my_restitution(e_table, k, m, v0, clip):
    a = my_alpha(e_table); c = a*math.sqrt(m*k)
    def f(t, y):
        d, dd = y
        if d <= 0: return [dd, 0.0]
        F = k*d**1.5 + c*d**0.25*dd
        if clip: F = max(F, 0.0)
        return [dd, -F/m]
    ev = lambda t, y: y[0] if t > 0 else 1.0
    ev.terminal, ev.direction = True, -1
    tc = 2.9432*(1.25*m*v0**2/k)**0.4/v0
    s = solve_ivp(f, [0, 10*tc], [0.0, v0], events=ev, rtol=1e-11, atol=1e-16, max_step=tc/2000)
    return -s.y_events[0][0][1]/v0
for name in ["wc", "steel", "pom", "paper"]:
    sp = load_specimen(f"{name}.toml"); law = contact_law(sp)
    m = law.mass_kg
    for pair, pp, mstar in [("wall", sp.pairs.particle_wall, m), ("particle", sp.pairs.particle_particle, m/2)]:
        k = (law.pair_wall if pair == "wall" else law.pair_particle).stiffness
        for v in (0.1, 1.0):
            dt = law.contact_time(v)/50
            for mode in ("literal", "no_attraction"):
                out = simulate_impact(pair=pair, impact_speed_m_s=v, dt_s=dt, law=law, mode=mode)
                mine = my_restitution(pp.restitution, k, mstar, v, mode == "no_attraction")
                print(f"| {name} | {pair} | {v} | {mode} | table {pp.restitution} | pidcore {out.restitution:.5f} | ODE {mine:.5f} | {(out.restitution-mine)/mine:+.2e} | vs table {(out.restitution-pp.restitution)/pp.restitution:+.2e} | KE lost {out.kinetic_energy_before_j-out.kinetic_energy_after_j:.4e} tally {out.dissipated_normal_j+out.dissipated_friction_j:.4e}")
