import re
base = open("wc.toml").read()
cases = {
 "radius_mm": ("radius_m = 1.0e-3", "radius_m = 1.0"),
 "radius_cm": ("radius_m = 1.0e-3", "radius_m = 0.1"),
 "density_gcc": ("density_kg_m3 = 15630.0", "density_kg_m3 = 15.63"),
 "E_GPa": ("youngs_modulus_pa = 600e9", "youngs_modulus_pa = 600"),
 "E_MPa": ("youngs_modulus_pa = 600e9", "youngs_modulus_pa = 600000"),
 "nu_pct": ("poisson_ratio = 0.22", "poisson_ratio = 22"),
 "diam_mm": ("inscribed_diameter_m = 6.35e-3", "inscribed_diameter_m = 6.35"),
 "diam_cm": ("inscribed_diameter_m = 6.35e-3", "inscribed_diameter_m = 0.635"),
 "height_mm": ("height_m = 12.7e-3", "height_m = 12.7"),
 "height_cm": ("height_m = 12.7e-3", "height_m = 1.27"),
 "mass_g": ("mass_kg = 0.0333", "mass_kg = 33.3"),
 "fixture_g": ("fixture_mass_kg = 0.02", "fixture_mass_kg = 20.0"),
 "baseline_pct": ("baseline_loss_factor = 0.004", "baseline_loss_factor = 0.4"),
 "restitution_pct": ("restitution = 0.9", "restitution = 90"),
 "friction_deg": ("sliding_friction = 0.2\n", "sliding_friction = 11.3\n"),
 "fill_fraction": ("fill_percent = 50.0", "fill_percent = 0.5"),
 "wall_E_GPa": ('wall_material = "aluminium_wall"', 'wall_material = "al"\nwall_youngs_modulus_pa = 70\nwall_poisson_ratio = 0.33\nwall_density_kg_m3 = 2700.0'),
 "wall_rho_gcc": ('wall_material = "aluminium_wall"', 'wall_material = "al"\nwall_youngs_modulus_pa = 70e9\nwall_poisson_ratio = 0.33\nwall_density_kg_m3 = 2.7'),
 "count_str": ("count = 286", "count = 286.5"),
 "rolling_damp": ("rolling_damping_ratio = 0.0\n[pairs.particle_wall]", "rolling_damping_ratio = 30.0\n[pairs.particle_wall]"),
}
for k, (a, b) in cases.items():
    assert a in base, k
    open(f"edges/{k}.toml", "w").write(base.replace(a, b, 1).replace('name = "wc_6mm"', f'name = "{k}"'))
