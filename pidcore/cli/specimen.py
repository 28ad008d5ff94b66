"""``pidcore specimen check FILE``: validate a specimen file and print what follows from it;
``pidcore specimen kept``: the specimen files the app keeps beside a store, and removing those
nothing needs."""

from __future__ import annotations

import argparse
from typing import TYPE_CHECKING

from .. import defaults
from ..constants import NORMAL_DAMPING_MODES
from ._options import add_json_option, add_store_option, path_argument, print_json
from ._vocabulary import cli_words

if TYPE_CHECKING:
    from ..app.kept_specimens import KeptFolder


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
                    "them, and a note names each value that overrides the table's. Each pair's "
                    "restitution is simulated by a head-on impact through the DEM kernel: the "
                    "first check after an install compiles the kernel (minutes, once: Numba "
                    "caches it beside pidcore, else in ~/.cache/numba, else in a folder of the "
                    "user's under the system's temporary folder; NUMBA_CACHE_DIR first).")
    check.add_argument("file", metavar="FILE", type=path_argument, help="specimen TOML file")
    check.add_argument("--damping-mode", choices=NORMAL_DAMPING_MODES,
                       default=defaults.DEM_NORMAL_DAMPING_MODE,
                       help="normal damping mode of the head-on impacts that give the "
                            "restitution the kernel simulates (default %(default)s, as dem run)")
    add_json_option(check)
    check.set_defaults(func=run_check)
    kept = sub.add_parser(
        "kept", help="list the specimen files the app keeps beside a store; --remove the "
                     "unused ones",
        description="List the specimen files uploaded to the app and kept beside the store "
                    "(<store>.specimens/, one per sha256, for a page reload), each with what "
                    "still needs it: a record of the store that names its sha256, or a queued "
                    "or running job of the app. Nothing is removed without --remove, which "
                    "removes the files nothing needs; a file a record names is never "
                    "removed, and the store is only read. A file the app used (kept from an "
                    "upload, restored for a page) within --keep-recent-hours, or holds now "
                    "(a calibration of it runs), is left: an open page may name it. --remove "
                    "also removes temporary files (.<name>.<16 hex>.tmp) that killed writes "
                    "left in the folder and of the job table, once older than that. Checked "
                    "and removed under the locks of the store, the job table and the folder. "
                    "Exit 2, nothing removed, where the store or the app's job table cannot be "
                    "read, a lock cannot be taken or a FILE is not a kept file of the store.")
    add_store_option(kept, help=f"the app's store (default ./{defaults.STORE_PATH})")
    kept.add_argument("files", metavar="FILE", nargs="*",
                      help="only these kept files (a sha256, or the path of its .toml or "
                           ".json in the kept folder; default: all)")
    kept.add_argument("--remove", action="store_true",
                      help="remove the listed files no record and no waiting job needs")
    kept.add_argument("--keep-recent-hours", type=float, metavar="HOURS",
                      default=defaults.KEPT_SPECIMEN_RECENT_HOURS,
                      help="leave the files the app used within this many hours, h "
                           "(default: %(default)g)")
    add_json_option(kept)
    kept.set_defaults(func=run_kept)


def run_check(args: argparse.Namespace) -> int:
    from ..specimen import describe, load_specimen

    specimen = load_specimen(args.file)
    facts = describe(specimen, damping_mode=args.damping_mode)
    facts["notes"] = [cli_words(note, "specimen check") for note in facts["notes"]]
    if args.json:
        print_json(facts)
        return 0
    # the file read: a bundled specimen named by its name alone is read from site-packages
    print(format_facts(facts, specimen.source))
    return 0


def run_kept(args: argparse.Namespace) -> int:
    from ..app.kept_specimens import prune_kept_specimens

    found = prune_kept_specimens(args.store, remove=args.remove, only=args.files,
                                 recent_hours=args.keep_recent_hours)
    if args.json:
        print_json(found.to_dict())
        return 0
    print(format_kept(found))
    return 0


def format_kept(found: KeptFolder) -> str:
    """One line per kept file (what needs it, or that it was or would be removed) and a
    closing line with the count and the bytes freed."""
    if not found.files and not found.others and not found.temporaries_removed:
        return f"no specimen files kept in {found.folder}"
    verb = "removed" if found.removed else "unused: would be removed with --remove"
    lines = [f"{f.sha256}  {f.name or '(name lost)'}  {f.size_bytes} B  "
             + (f"kept: {f.referred_by}" if f.referred_by
                else f"left: {f.left_because}" if f.left_because else verb)
             for f in found.files]
    lines += [f"{p.name}: not a file the app keeps; left as it is" for p in found.others]
    lines += [f"{p.name}: temporary file of a killed write; "
              + ("removed" if found.removed else "would be removed with --remove")
              for p in found.temporaries_removed]
    unused = found.unused
    freed = sum(f.size_bytes for f in unused)
    lines.append(f"{found.folder}: {len(found.files)} kept specimen file(s), {len(unused)} "
                 f"unused ({freed} B) " + ("removed" if found.removed else
                                           "(nothing removed: --remove removes them)")
                 + f"; files the app used in the last {found.recent_hours:g} h are left "
                   "(--keep-recent-hours)")
    return "\n".join(lines)


def format_facts(f: dict, source: str) -> str:
    """Readable lines with units."""
    from ..specimen import hashed_name

    kind = "the paper's coupon" if f["is_paper"] else "not the paper's coupon"
    # the label the app, reports and dem run/sweep show (16 hex digits here matched none)
    return "\n".join([
        f"specimen        {hashed_name(f['name'], f['sha256'])} ({source}): OK, {kind}; "
        "[...] starts the sha256 of its canonical text (of every value, name and description "
        "included, but [coupon] face_area_m2, which no DEM run simulates; not of the file's "
        "bytes: comments, layout and number formatting leave it; --json prints it whole)",
        *([f"calibrated from {hashed_name(f['calibrated_from_name'], f['calibrated_from_sha256'])}"
           ": the tests it models are that file's"]
          if f.get("calibrated_from_sha256") else []),
        f"cells           {f['cells_per_coupon']} {f['cell_shape']}, capacity "
        f"{f['capacity_per_cell']} particles per cell (dense drop packing)",
        f"coupon area     {f['coupon_area_from']}: what c_eq_per_treated_area (pidcore "
        "model damper) is per",
        f"gaps            wall to wall {f['wall_to_wall_gap_m'] * 1e3:.4g} mm, floor to "
        f"ceiling {f['floor_to_ceiling_gap_m'] * 1e3:.4g} mm beside one particle",
        f"particles       {f['particles_per_cell']} per cell ({f['particles_per_cell_basis']}"
        f"{_share(f)}), "
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
        f"restitution     particle-particle {f['restitution_pp_stated']:g} stated, "
        f"{f['restitution_pp_simulated']:.4g} simulated; particle-wall "
        f"{f['restitution_pw_stated']:g} stated, {f['restitution_pw_simulated']:.4g} simulated "
        f"(a head-on impact through the kernel at {f['restitution_impact_speed_m_s']:g} m/s, "
        f"that time step, {f['restitution_damping_mode']} damping, Eq. 3's alpha)",
        *(f"note: {note}" for note in f["notes"]),
    ])


def _share(f: dict) -> str:
    # a stated fill that the rounded count does not make (75 % of 22 is 16: 72.7 %)
    if f["particles_per_cell_basis"] != "fill_percent":
        return ""
    from ..specimen import filled_share

    return filled_share(f["fill_percent"], f["particles_per_cell"], f["capacity_per_cell"])


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
