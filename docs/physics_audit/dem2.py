import math, dataclasses, sys, numpy as np
sys.path.insert(0, "../../tests")
from _incline import Incline as _Incline  # the tests keep it in tests/_incline.py
from pidcore.specimen import load_specimen, contact_law
from pidcore.dem.geometry import CellGeometry, random_packing
from pidcore.dem.state import CellsState, KernelSettings, advance, energies
from pidcore.dem.simulate import settle_bed
from pidcore.dem.impact import simulate_impact
G = 9.80665
sp = load_specimen("wc.toml"); law = contact_law(sp); geo = sp.geometry()
m, r = law.mass_kg, law.radius_m
print("m", m, "r", r, "I", law.inertia_kg_m2, "2/5 m r^2", 0.4*m*r*r)
# --- restitution at the production time step (specimen check's dt) at 0.3 m/s
dt_auto = 5.179022537454826e-07
for pair in ("wall", "particle"):
    for v in (0.05, 0.3, 1.12):
        o = simulate_impact(pair=pair, impact_speed_m_s=v, dt_s=dt_auto, law=law, mode="literal")
        tab = (sp.pairs.particle_wall if pair == "wall" else sp.pairs.particle_particle).restitution
        print(f"| restitution at auto dt | {pair} {v} m/s | {o.restitution:.5f} | table {tab} | {(o.restitution-tab)/tab:+.2e} | steps/contact {law.contact_time(v)/dt_auto:.1f}")
# --- free flight: one sphere in the middle of the cell, launched, 3 ms (no wall reached)
st = CellsState.from_positions(np.array([[[0.0, 0.0, 0.0]]]), mass_kg=m)
v0 = np.array([0.2, -0.1, 0.5]); st.vel[:, 0, 0] = v0; st.omg[:, 0, 0] = [100.0, 0, 0]
dt = 1e-6; n = 3000
advance(st, KernelSettings(law=law, geometry=geo, dt_s=dt), n)
t = n*dt
exp = v0*t + np.array([0, 0, -0.5*G*t*t])
print("| free flight pos | ", st.pos[:, 0, 0], exp, np.abs(st.pos[:, 0, 0]-exp).max(), "| vel", st.vel[:, 0, 0], v0 + [0, 0, -G*t], "| spin", st.omg[:, 0, 0])
# --- incline with WC's wall pair: mu_s=0.35, mu=0.3, non-rotating (frozen) block
froz = dataclasses.replace(law, inertia_kg_m2=law.inertia_kg_m2*1e12)
def on_incline(lw, th, v0=0.0, preload=True):
    pl = _Incline(th); k = lw.pair_wall.stiffness
    d = (lw.mass_kg*G*math.cos(th)/k)**(2/3)
    s = CellsState.from_positions(((lw.radius_m-d)*pl.normal)[None, None, :], mass_kg=lw.mass_kg)
    s.frc[:, 0, 0] += lw.mass_kg*G*math.cos(th)*pl.normal
    s.vel[:, 0, 0] = v0*pl.down
    if preload:
        kt = lw.pair_wall.tangential_stiffness
        s.spring_pw[0, 0, 6, :3] = lw.mass_kg*G*math.sin(th)/kt*pl.down; s.spring_pw[0, 0, 6, 4] = kt
    return s, KernelSettings(law=lw, geometry=pl, dt_s=2e-7), pl
def track(s, se, pl, chunks, every):
    S, V = [], []
    for _ in range(chunks):
        advance(s, se, every); S.append(float(s.pos[:, 0, 0] @ pl.down)); V.append(float(s.vel[:, 0, 0] @ pl.down))
    return np.arange(1, chunks+1)*every*se.dt_s, np.array(S), np.array(V)
mu, mus = sp.pairs.particle_wall.sliding_friction, sp.pairs.particle_wall.static_friction
for tt in (0.33, 0.34, 0.36, 0.40):
    th = math.atan(tt); s, se, pl = on_incline(froz, th)
    t, S, V = track(s, se, pl, 40, 1000)  # 8 ms
    keep = t >= 2e-3
    acc = 2*np.polyfit(t[keep], S[keep], 2)[0]
    exp = G*(math.sin(th)-mu*math.cos(th)) if tt > mus else 0.0
    print(f"| incline tan={tt} (mu_s {mus}, mu {mu}) | moved {S[-1]:.3e} m | acc {acc:.5g} | expected {exp:.5g} | {(acc-exp)/exp if exp else float('nan'):+.2e}")
# --- rolling sphere stop distance, mu_r(pw) = 0.005, on the floor
mur = sp.pairs.particle_wall.rolling_friction
th = 0.0; s, se, pl = on_incline(law, 0.0, v0=0.02, preload=False)
s.omg[:, 0, 0] = 0.02/r*np.cross(pl.normal, pl.down)
se = dataclasses.replace(se, dt_s=2e-7)
t, S, V = track(s, se, pl, 300, 25000)  # 1.5 s
stop = int(np.argmax(V <= 0.0))
exp = 7*0.02**2/(10*mur*G)
print(f"| rolling stop distance mu_r={mur} | {S[stop]:.6g} m at t={t[stop]:.3f} | expected {exp:.6g} | {(S[stop]-exp)/exp:+.2e} | t_exp {0.02/(5/7*mur*G):.3f}")
