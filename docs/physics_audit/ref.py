"""Independent first-principles reference for `pidcore specimen check` (my own formulas)."""
import json, math, sys, tomllib
G0 = 9.80665
WALL = dict(E=72e9, nu=0.33)   # aluminium_wall of materials.csv (AA 2024 face sheet, Table 2)
def ref(path):
    s = tomllib.load(open(path, 'rb'))
    c, p, cp = s['cell'], s['particles'], s['coupon']
    d, h, r = c['inscribed_diameter_m'], c['height_m'], p['radius_m']
    rho, E, nu = p['density_kg_m3'], p['youngs_modulus_pa'], p['poisson_ratio']
    Ew, nuw = c.get('wall_youngs_modulus_pa', WALL['E']), c.get('wall_poisson_ratio', WALL['nu'])
    m = 4/3*math.pi*r**3*rho
    out = {}
    out['particle_mass_kg'] = m
    # hexagon: flat-to-flat d -> apothem d/2, side = circumradius = d/sqrt(3), area (sqrt3/2) d^2
    out['hex_area_m2'] = math.sqrt(3)/2*d**2
    out['hex_circumdiameter_m'] = 2*d/math.sqrt(3)
    out['hex_volume_m3'] = out['hex_area_m2']*h
    out['cells_in_100mm_square'] = 0.01/out['hex_area_m2']
    out['wall_to_wall_gap_m'] = d - 2*r
    out['floor_to_ceiling_gap_m'] = h - 2*r
    Epp = 1/(2*(1-nu**2)/E); Epw = 1/((1-nu**2)/E + (1-nuw**2)/Ew)
    Rpp, Rpw = r/2, r
    out['normal_stiffness_pp_n_m1_5'] = 4/3*Epp*math.sqrt(Rpp)
    out['normal_stiffness_pw_n_m1_5'] = 4/3*Epw*math.sqrt(Rpw)
    G = E/(2*(1+nu)); Gw = Ew/(2*(1+nuw))
    Gpp = 1/(2*(2-nu)/G); Gpw = 1/((2-nu)/G + (2-nuw)/Gw)
    def dmax(k, ms, v): return (15*ms*v**2/(16*(3*k/4)))**0.4   # (15 m v^2/(16 E* sqrt R*))^(2/5)
    # constant k_t: Mindlin's at the overlap of a 0.3 m/s impact (not a key of specimen check)
    v03 = 0.3
    dpp, dpw = dmax(out['normal_stiffness_pp_n_m1_5'], m/2, v03), dmax(out['normal_stiffness_pw_n_m1_5'], m, v03)
    out['tangential_stiffness_pp_n_m'] = 8*Gpp*math.sqrt(Rpp*dpp)
    out['tangential_stiffness_pw_n_m'] = 8*Gpw*math.sqrt(Rpw*dpw)
    # largest impact: 50 Hz 10 g: wall velocity amplitude a/w each way + free fall over h
    w = 2*math.pi*50; v = 2*10*G0/w + math.sqrt(2*G0*h)
    out['reference_impact_speed_m_s'] = v
    # specimen check's reference_impact_overlap_*: the Hertz overlap of that largest impact
    out['reference_impact_overlap_pp_m'] = dmax(out['normal_stiffness_pp_n_m1_5'], m/2, v)
    out['reference_impact_overlap_pw_m'] = dmax(out['normal_stiffness_pw_n_m1_5'], m, v)
    # Hertz impact duration, Johnson: t = 2.9432 * dmax / v
    tpp = 2.9432*dmax(out['normal_stiffness_pp_n_m1_5'], m/2, v)/v
    tpw = 2.9432*dmax(out['normal_stiffness_pw_n_m1_5'], m, v)/v
    out['contact_time_s'] = min(tpp, tpw)
    # stuck tangential spring: effective tangential mass of a sphere with rolling = 2/7 m
    ttp = 2*math.pi*math.sqrt(2/7*(m/2)/out['tangential_stiffness_pp_n_m'])
    ttw = 2*math.pi*math.sqrt(2/7*m/out['tangential_stiffness_pw_n_m'])
    out['tangential_period_s'] = min(ttp, ttw)
    out['time_step_s'] = min(2e-6, min(out['contact_time_s'], out['tangential_period_s'])/10)
    return out, s
if __name__ == "__main__":  # importable: tests/test_docs_consistency.py
    for f in sys.argv[1:]:
        mine, s = ref(f + '.toml')
        pc = json.load(open(f + '.json'))
        n = pc['particles_per_cell']
        mine['particles_mass_kg'] = s['cell']['count']*n*mine['particle_mass_kg']
        mine['vibrated_mass_kg'] = s['coupon']['mass_kg'] + s['coupon'].get('fixture_mass_kg', 0) + mine['particles_mass_kg']
        print(f"## {f}: capacity {pc['capacity_per_cell']}, per cell {n}; hex area {mine['hex_area_m2']*1e6:.4f} mm2, "
              f"circumdiameter {mine['hex_circumdiameter_m']*1e3:.4f} mm, volume {mine['hex_volume_m3']*1e9:.3f} mm3, "
              f"cells/100mm square {mine['cells_in_100mm_square']:.1f} (file {s['cell']['count']}); packing fraction "
              f"{pc['capacity_per_cell']*4/3*math.pi*s['particles']['radius_m']**3/mine['hex_volume_m3']:.3f}")
        for k, v in mine.items():
            if k in pc:
                print(f"| {f} | {k} | {pc[k]:.6g} | {v:.6g} | {(pc[k]-v)/v:+.2e} |")
