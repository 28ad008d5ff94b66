"""``pidcore specimen check FILE``: validate a specimen file and print what follows from it."""

from __future__ import annotations

import argparse
import json

from .. import defaults
from ._options import add_json_option, path_argument


def register(subparsers: argparse._SubParsersAction) -> None:
    p = subparsers.add_parser(
        "specimen", help="specimen files (cell, coupon, particles, contact pairs)",
        description="Specimen files describe what the DEM simulates (TOML, SI units in the key "
                    "names; see README 'Specimen files').")
    sub = p.add_subparsers(dest="specimen_command", metavar="SPECIMEN_COMMAND", required=True)
    check = sub.add_parser(
        "check", help="validate a specimen file and print capacity, masses, contact numbers",
        description="Validate FILE (one-line error, exit 2, on a missing or unknown key, a "
                    "negative mass, a value outside its plausible range (a unit slip), "
                    "particles that do not fit, a fill of no particle, static below sliding "
                    "friction or an unknown material) and print what follows from it; a "
                    "table material with inline properties that differ from the table's keeps "
                    "them, and a note names each value that overrides the table's.")
    check.add_argument("file", metavar="FILE", type=path_argument, help="specimen TOML file")
    add_json_option(check)
    check.set_defaults(func=run_check)


def run_check(args: argparse.Namespace) -> int:
    from ..specimen import describe, load_specimen

    facts = describe(load_specimen(args.file))
    if args.json:
        print(json.dumps(facts))
        return 0
    print(format_facts(facts, str(args.file)))
    return 0


def format_facts(f: dict, source: str) -> str:
    """Readable lines with units."""
    from ..specimen import hashed_name

    kind = "the paper's coupon" if f["is_paper"] else "not the paper's coupon"
    # the label the app, reports and dem run/sweep show (16 hex digits here matched none)
    return "\n".join([
        f"specimen        {hashed_name(f['name'], f['sha256'])} ({source}): OK, {kind}; "
        "[...] starts its sha256 (of every value, name and description included)",
        *([f"calibrated from {hashed_name(f['calibrated_from_name'], f['calibrated_from_sha256'])}"
           ": the tests it models are that file's"]
          if f.get("calibrated_from_sha256") else []),
        f"cells           {f['cells_per_coupon']} {f['cell_shape']}, capacity "
        f"{f['capacity_per_cell']} particles per cell (dense drop packing)",
        f"gaps            wall to wall {f['wall_to_wall_gap_m'] * 1e3:.4g} mm, floor to "
        f"ceiling {f['floor_to_ceiling_gap_m'] * 1e3:.4g} mm beside one particle",
        f"particles       {f['particles_per_cell']} per cell ({f['particles_per_cell_basis']}), "
        f"radius {f['particle_radius_m'] * 1e3:.4g} mm (diameter "
        f"{2 * f['particle_radius_m'] * 1e3:.4g} mm), {f['particle_mass_kg'] * 1e3:.4g} g "
        f"each, {f['particles_mass_kg'] * 1e3:.4g} g in the coupon",
        f"masses          coupon {f['coupon_mass_kg'] * 1e3:.4g} g + fixture "
        f"{f['fixture_mass_kg'] * 1e3:.4g} g + particles = vibrated "
        f"{f['vibrated_mass_kg'] * 1e3:.4g} g",
        f"stiffness       normal (Hertz k_n) particle-particle "
        f"{f['normal_stiffness_pp_n_m1_5']:.4g}, particle-wall "
        f"{f['normal_stiffness_pw_n_m1_5']:.4g} N/m^1.5; tangential "
        f"{f['tangential_stiffness_pp_n_m']:.4g}, {f['tangential_stiffness_pw_n_m']:.4g} N/m",
        _tangential_line(f),
        f"contact time    {f['contact_time_s']:.4g} s at {f['reference_impact_speed_m_s']:.3g} "
        f"m/s ({_reference_case(f)}); stuck tangential period {f['tangential_period_s']:.4g} s"
        + (f" (at the largest overlap the DEM takes, "
           f"{defaults.DEM_MAX_OVERLAP_FRACTION * 100:g} % of the radius)"
           if f["tangential_stiffness_model"] == "mindlin" else ""),
        # a run at 500 Hz takes a longer step than this one: the line read as the run's step
        f"time step       {f['time_step_s']:.4g} s at {_reference_case(f)} (auto: "
        f"{_step_limit(f)}), the smallest of the Table 3 grid; a run takes its own load "
        "case's, shortened to a whole number of steps per output sample (dem run prints "
        "that as dt)",
        *(f"note: {note}" for note in f["notes"]),
    ])


def _reference_case(f: dict) -> str:
    """The load case the contact time and time step are for: ``"50 Hz, 10 g"``."""
    return f"{f['reference_frequency_hz']:g} Hz, {f['reference_acceleration_g']:g} g"


def _step_limit(f: dict) -> str:
    """What sets the automatic time step (:func:`pidcore.dem.simulate.choose_time_step`): it
    said "for that impact", read as the contact time, where a Mindlin spring's period (2.5 x
    shorter than the contact for 2 mm tungsten carbide spheres) set it."""
    shortest = min(f["contact_time_s"], f["tangential_period_s"])
    if shortest / defaults.DEM_MIN_STEPS_PER_CONTACT > defaults.DEM_TIME_STEP_S:
        return f"the {defaults.DEM_TIME_STEP_S:g} s cap"
    what = ("that contact time" if f["contact_time_s"] <= f["tangential_period_s"]
            else "the stuck tangential period")
    return f"1/{defaults.DEM_MIN_STEPS_PER_CONTACT} of {what}"


def _tangential_line(f: dict) -> str:
    """The k_t model; for Mindlin's, k_t at the hardest impact's overlap beside the constant."""
    if f["tangential_stiffness_model"] != "mindlin":
        return ("k_t model       constant: Mindlin's k_t at the overlap of a "
                f"{defaults.DEM_TANGENTIAL_REFERENCE_SPEED_M_S:g} m/s impact (values above)")
    return (f"k_t model       mindlin: 8 G* sqrt(R* delta) of the current overlap; at the "
            f"{f['reference_impact_speed_m_s']:.3g} m/s impact's overlap "
            f"({f['reference_impact_overlap_pp_m'] * 1e6:.3g}, "
            f"{f['reference_impact_overlap_pw_m'] * 1e6:.3g} um) "
            f"{f['mindlin_tangential_stiffness_pp_n_m']:.4g}, "
            f"{f['mindlin_tangential_stiffness_pw_n_m']:.4g} N/m (constant: "
            f"{f['tangential_stiffness_pp_n_m']:.4g}, {f['tangential_stiffness_pw_n_m']:.4g} N/m)")
