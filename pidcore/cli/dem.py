"""``pidcore dem``: DEM prediction of the SDC of one load case (``run``) or a grid (``sweep``)."""

from __future__ import annotations

import argparse
import math
import sys

from .. import defaults, interrupt
from ..constants import (
    DRIVE_DIRECTIONS,
    NORMAL_DAMPING_MODES,
    PARTICLE_MATERIALS,
    START_PACKINGS,
    START_PROTOCOLS,
    TANGENTIAL_MODELS,
    TANGENTIAL_STIFFNESS_MODELS,
    VIBRATED_MASS_CONVENTIONS,
)
from ..errors import ParameterError, PidcoreError, apart
from ._options import (
    add_json_option,
    add_store_option,
    comma_list,
    non_negative_int,
    path_argument,
    positive_int,
    print_json,
    progress_wanted,
    scheduler_address,
)
from ._vocabulary import cli_words

#: Keys of ``pidcore dem run --json`` (more may follow them).
JSON_KEYS = ("sdc", "sdc_stderr", "energy_per_cycle_j", "energy_dissipated_normal_j",
             "energy_dissipated_friction_j", "particles_per_cell", "cells_simulated",
             "vibrated_mass_kg", "energy_balance_error", "steps", "wall_s", "particle_steps_per_s")


def _time_step(text: str) -> float | str:
    if text == "auto":
        return text
    try:
        return float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected seconds or 'auto', got {text!r}") from None


def register(subparsers: argparse._SubParsersAction) -> None:
    dem = subparsers.add_parser(
        "dem", help="DEM prediction of the SDC (paper Eq. 1-10)",
        description="Discrete element simulation of particles in honeycomb cells.")
    sub = dem.add_subparsers(dest="dem_command", metavar="DEM_COMMAND", required=True)
    _register_run(sub)
    _register_sweep(sub)


def _register_run(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "run", help="simulate one load case",
        description="Simulate K independent cells of the specimen's coupon (default: the "
                    "paper's, 441 cells of a 100 x 100 mm coupon) under "
                    "harmonic drive and report the specific damping capacity (Eq. 8-10).")
    p.add_argument("--frequency", metavar="HZ", type=float, required=True,
                   help="drive frequency, Hz")
    p.add_argument("--acceleration", metavar="G", type=float, required=True,
                   help="acceleration amplitude, g")
    p.add_argument("--fill", metavar="PERCENT", type=float, default=None,
                   help="fill fraction, %% of the 100 %% count (see --fill-reference); "
                        "default: the specimen's count_per_cell or fill_percent")
    _add_config_options(p)
    add_store_option(p, default=None,
                     help="run cache: reuse the run stored there with the same inputs, else "
                          "simulate and save it")
    add_json_option(p, progress=True)
    p.set_defaults(func=run)


def _add_config_options(p: argparse.ArgumentParser) -> None:
    """Options of DemConfig and of the load case shared by ``run`` and ``sweep``."""
    p.add_argument("--cells", metavar="K", type=int, default=defaults.DEM_CELLS,
                   help=f"independent cells simulated (default {defaults.DEM_CELLS})")
    p.add_argument("--seed", metavar="S", type=non_negative_int, default=defaults.DEM_SEED,
                   help=f"random seed of the packings (default {defaults.DEM_SEED})")
    p.add_argument("--specimen", metavar="FILE", type=path_argument, default=None,
                   help="specimen file (cell, coupon and fixture masses, particles, contact "
                        "pairs; see 'pidcore specimen check'); default: the paper's coupon")
    p.add_argument("--material", metavar="NAME", default=None,
                   help=f"particle material: {', '.join(PARTICLE_MATERIALS)} for the paper's "
                        "coupon (default acrylic); with --specimen its own particles' (e.g. "
                        "steel; the default)")
    p.add_argument("--direction", choices=DRIVE_DIRECTIONS, default="z",
                   help="drive direction in the cell frame (z normal to the face sheets; "
                        "default z)")
    p.add_argument("--cycles", metavar="N", type=int, default=None,
                   help=f"steady-state cycles measured, at least (default "
                        f"{defaults.DEM_MIN_STEADY_CYCLES}, at most "
                        f"{defaults.DEM_MAX_STEADY_CYCLES}); the DEM runs whole blocks of "
                        f"{defaults.DEM_STEADY_BLOCK_CYCLES} cycles and measures the two that "
                        "detect the steady state, so more may be measured (noted)")
    p.add_argument("--time-step", metavar="S", type=_time_step,
                   default=defaults.DEM_TIME_STEP_MODE,
                   help=f"time step, s, or 'auto' (default: min({defaults.DEM_TIME_STEP_S:g} "
                        f"s, contact time / {defaults.DEM_MIN_STEPS_PER_CONTACT}, a stuck "
                        f"tangential spring's period / {defaults.DEM_MIN_STEPS_PER_CONTACT}); "
                        "either is shortened to a whole number of steps per output sample "
                        f"({defaults.DEM_SAMPLES_PER_CYCLE} per drive period; dem run "
                        "prints the step taken as dt))")
    p.add_argument("--damping-mode", choices=NORMAL_DAMPING_MODES,
                   default=defaults.DEM_NORMAL_DAMPING_MODE,
                   help=f"normal damping at contact end (default "
                        f"{defaults.DEM_NORMAL_DAMPING_MODE})")
    p.add_argument("--damping-coefficient", choices=("eq3", "calibrated"),
                   default=defaults.DEM_DAMPING_COEFFICIENT,
                   help="alpha by Eq. 3, or calibrated so that a head-on impact gives the "
                        "stated restitution of each pair (tables' or specimen's; default "
                        f"{defaults.DEM_DAMPING_COEFFICIENT})")
    p.add_argument("--mass-convention", choices=VIBRATED_MASS_CONVENTIONS,
                   default=defaults.DEM_VIBRATED_MASS_CONVENTION,
                   help="mass m_c in E = m_c a^2 / (2 w^2); 'coupon' is the moving mass, "
                        "the specimen's coupon and fixture (default "
                        f"{defaults.DEM_VIBRATED_MASS_CONVENTION})")
    p.add_argument("--start", choices=START_PROTOCOLS, default=defaults.DEM_START_PROTOCOL,
                   help="particles at rest or moving with the cell when the drive starts "
                        f"(default {defaults.DEM_START_PROTOCOL})")
    p.add_argument("--packing", choices=START_PACKINGS, default=defaults.DEM_START_PACKING,
                   help="start packing: settled first without friction (dense) or with "
                        f"friction only (loose) (default {defaults.DEM_START_PACKING})")
    p.add_argument("--tangential-model", choices=TANGENTIAL_MODELS,
                   default=defaults.DEM_TANGENTIAL_MODEL,
                   help="friction: tangential spring capped by mu |f_n| (stick_slip) or Eq. 5 "
                        f"regularised near zero slip (coulomb) (default "
                        f"{defaults.DEM_TANGENTIAL_MODEL})")
    p.add_argument("--tangential-stiffness", choices=TANGENTIAL_STIFFNESS_MODELS, default=None,
                   help="k_t of the stick-slip spring: Mindlin's at a 0.3 m/s impact's overlap "
                        "(constant) or 8 G* sqrt(R* delta) of the current overlap (mindlin); "
                        "overrides the specimen's [pairs] tangential_stiffness_model (default: "
                        "the specimen's, constant for the paper's coupon)")
    p.add_argument("--fill-reference", choices=("capacity", "paper"),
                   default=defaults.DEM_FILL_REFERENCE,
                   help="100 %% = cell capacity (dense packing) or the paper's 36 particles "
                        f"(default {defaults.DEM_FILL_REFERENCE})")


def _register_sweep(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "sweep", help="simulate a grid of load cases (resumable)",
        description="Simulate every load case of a grid and save each to the store as it "
                    "finishes; a re-run skips finished cases. Local processes by default, a "
                    "dask.distributed cluster with --scheduler.")
    p.add_argument("--grid", default="table3", help="named grid (default table3: 48 cases)")
    for flag, what in (("--frequencies", "drive frequencies, Hz"),
                       ("--accelerations", "acceleration amplitudes, g"),
                       ("--fills", "fills (packing ratios), %%")):
        p.add_argument(flag, metavar="X,X", type=comma_list, default=None,
                       help=f"{what}, comma-separated, in place of the grid's (every "
                            "combination is run, each value once, in Table 3's order: "
                            "ascending, whatever the order given)"
                            + ("; default for a --specimen stating its fill (count_per_cell "
                               "or fill_percent): that fill alone, as dem run's"
                               if flag == "--fills" else ""))
    _add_config_options(p)
    p.add_argument("--workers", metavar="N", type=positive_int, default=None,
                   help="local processes (default: all cores); not with --scheduler")
    p.add_argument("--scheduler", metavar="ADDR", type=scheduler_address, default=None,
                   help="dask.distributed scheduler address (needs the 'distributed' extra)")
    add_store_option(p)
    add_json_option(p, progress=True)
    p.set_defaults(func=sweep)


def _config(args: argparse.Namespace):
    from ..dem import DemConfig

    return DemConfig(cells=args.cells, seed=args.seed, time_step=args.time_step,
                     normal_damping_mode=args.damping_mode,
                     damping_coefficient=args.damping_coefficient,
                     vibrated_mass=args.mass_convention, start_protocol=args.start,
                     start_packing=args.packing, tangential_model=args.tangential_model,
                     fill_reference=args.fill_reference, steady_cycles=args.cycles)


def _specimen(args: argparse.Namespace):
    """(specimen or None, load-case material) from --specimen, --material and
    --tangential-stiffness (a specimen value: the specimen's hash, and so the run's key and
    provenance, say which k_t model ran)."""
    from ..loadcase import normalize_material
    from ..specimen import load_specimen, paper_specimen

    specimen = None if args.specimen is None else load_specimen(args.specimen)
    if args.material is None:
        material = "acrylic" if specimen is None else specimen.particles.material
    else:
        # a specimen's own material (steel) is a name as good as the table's, as for `report
        # --material`; one that is not its particles' is refused with the case (names both)
        material = normalize_material(args.material, "--material", None)
        if specimen is None and material not in PARTICLE_MATERIALS:
            raise ParameterError(
                f"--material {args.material}: the paper's coupon holds "
                f"{' or '.join(PARTICLE_MATERIALS)} particles; give --specimen FILE whose "
                f"particles are {material}")
    if args.tangential_stiffness is not None:
        specimen = (specimen or paper_specimen(material)).with_values(
            {"pairs.tangential_stiffness_model": args.tangential_stiffness})
    return specimen, material


def _interrupted(command: str, saved: int, store, *, left: int = 1) -> int:
    """Ctrl-C (or SIGTERM): say what was saved (finished runs are, each in its own
    transaction), exit 130 (143). ``left``: runs still missing from the store (none: nothing
    to resume)."""
    from .. import interrupt
    from ..interrupt import untouched

    if saved:
        what = f"{saved} finished run(s) saved to {store}; " + (
            "re-run to resume" if left else "every case is stored, nothing left to run")
    else:
        what = "nothing saved" + (f", {untouched(store)}" if store is not None else "")
    print(f"pidcore dem {command}: interrupted; {what}", file=sys.stderr)
    return interrupt.exit_status()


def sweep(args: argparse.Namespace) -> int:
    from ..dem.persist import run_key, stored_keys
    from ..dem.simulate import check_drive
    from ..dem.sweep import (
        check_workers_or_scheduler,
        cross_cases,
        grid_axes,
        run_sweep,
        sweep_fills,
    )
    from ..loadcase import parse_values
    from ..specimen import fill_override_note

    # before any note or file is read: its one line alone
    check_workers_or_scheduler(args.workers, args.scheduler)
    axes = grid_axes(args.grid)
    values = [axes[axis] if given is None else
              [value for item in given for value in parse_values(item, name=flag)]
              for axis, given, flag in (("frequency_hz", args.frequencies, "--frequencies"),
                                        ("acceleration_g", args.accelerations,
                                         "--accelerations"),
                                        ("fill_percent", args.fills, "--fills"))]
    specimen, material = _specimen(args)
    fills_note = ""  # which fills run and why: run_sweep, given only the cases, cannot say
    if args.fills is None:  # an own specimen's stated fill, else the grid's (and why)
        values[2], note = sweep_fills(specimen, args.grid, args.fill_reference)
        fills_note = cli_words(note, "dem sweep") if note else ""
    else:
        # the summary's notes say the same to a library caller and in --json
        note = fill_override_note(specimen, values[2], args.fill_reference)
    for fill in values[2]:
        _check_fill(fill, "--fills", args, specimen, material)
    # before the run (an interrupted sweep prints no summary)
    if note:  # on stderr: --json prints one document
        print(f"pidcore dem sweep: note: {cli_words(note, 'dem sweep')}", file=sys.stderr)
    cases = cross_cases(*values, material=material, direction=args.direction)
    config = _config(args)
    for case in cases:  # before any case runs, not in a worker after the others
        check_drive(case, config, specimen, what="--frequencies/--accelerations")
    # What a Ctrl-C leaves saved is read from the store itself: a count kept beside the saves
    # could miss one that committed as the interrupt came.
    keys = [run_key(case, config, specimen) for case in cases]
    before = stored_keys(args.store, keys)
    from ..dem.persist import other_files_runs_note

    other_files = other_files_runs_note(
        args.store, [c for c, k in zip(cases, keys, strict=True) if k not in before], config,
        specimen)
    if other_files:  # before the run, as the fill's note: an edited file runs every case
        print(f"pidcore dem sweep: note: {other_files}", file=sys.stderr)
    try:
        summary = run_sweep(cases, config, store_path=args.store, workers=args.workers,
                            scheduler=args.scheduler, progress=progress_wanted(args),
                            specimen=specimen)
        if fills_note:  # first, as on stderr: --json said nothing of which fills ran, or why
            summary.notes.insert(0, fills_note)
        # inside: a Ctrl-C as the summary is printed (every case done) said "no store write
        # was left half-done" instead of what the sweep saved
        _print_sweep(args, summary)
        interrupt.raise_if_interrupted()
    except KeyboardInterrupt:
        stored = stored_keys(args.store, keys)
        return _interrupted("sweep", len(stored - before), args.store,
                            left=len(set(keys) - stored))
    except PidcoreError as exc:  # a case refused or failed, a worker killed: what is kept
        saved = stored_keys(args.store, keys) - before
        if not saved:
            raise
        raise type(exc)(f"{exc}; {len(saved)} finished run(s) saved to {args.store}; re-run "
                        "to resume") from None
    return 0


def _sweep_specimens(cases: list[dict]) -> str:
    """``"; specimen my_steel [9a19aa]"``: whose runs the sweep's cases are, as stored, each
    by the label the app and reports show (:func:`pidcore.specimen.hashed_name`); "" where
    no case is stored."""
    from ..specimen import hashed_name

    named = dict.fromkeys((c.get("specimen_name"), c.get("specimen_sha256")) for c in cases
                          if c.get("specimen_sha256"))
    if not named:
        return ""
    return "; specimen " + ", ".join(hashed_name(name, sha) for name, sha in named)


def _print_sweep(args: argparse.Namespace, summary) -> None:
    """What a finished sweep did: its JSON document, or each case's results (as ``dem run``
    states them) and how its run was got, the counts, the cases it found to be the same
    simulation as another, and its runs' notes."""
    if args.json:
        print_json(summary.to_dict())
    else:
        from ..dem.sweep import STORED_MEANWHILE

        # a case each: the summary line alone gave no SDC, energy balance or steady state
        for case in summary.cases:
            print(_sweep_case_line(case))
        meanwhile = sum(case["status"] == STORED_MEANWHILE for case in summary.cases)
        # what this sweep saved: a run another process stored first is not counted as ours
        print(f"{len(summary.completed)} case(s) simulated and saved, {len(summary.skipped)} "
              f"already in {args.store}"
              + (f" ({meanwhile} of them saved meanwhile by another process, whose runs "
                 "are kept)" if meanwhile else "")
              + f"; wall time {summary.wall_s:.1f} s" + _sweep_specimens(summary.cases))
        for case in summary.cases:
            if case["status"].startswith("same simulation"):
                print(f"fill {case['fill_percent']:g} % ({case['frequency_hz']:g} Hz, "
                      f"{case['acceleration_g']:g} g): {case['status']} ("
                      f"{case.get('particles_per_cell', '?')} particles per cell, the same "
                      f"seed and settings), not simulated again: {case['store_key']}")
        for line in _sweep_notes(summary.cases):
            print(line)


def _where(case: dict) -> str:
    """``"500 Hz, 5 g, fill 50 %"``: a sweep's case by its load case, as asked."""
    return (f"{case['frequency_hz']:g} Hz, {case['acceleration_g']:g} g, fill "
            f"{case['fill_percent']:g} %")


def _sweep_notes(cases: list[dict]) -> list[str]:
    """The notes ``dem run`` prints of each case's stored run, each once, naming the cases it
    is of (``every case`` where all of them): a note of the specimen or of the settings is
    the same for every case, and a line of it per case would bury the others."""
    of: dict[str, list[str]] = {}
    for case in cases:
        for note in case.get("notes", ()):
            of.setdefault(note, []).append(_where(case))
    return [f"note ({'every case' if len(where) == len(cases) > 1 else '; '.join(where)}): "
            f"{note}" for note, where in of.items()]


def _sweep_case_line(case: dict) -> str:
    """One case of a sweep (a dict of :attr:`~pidcore.dem.sweep.SweepSummary.cases`): its load
    case, its stored run's SDC, energy balance and steady state in ``dem run``'s words, and
    whether its run was simulated now or reused."""
    how = ("simulated now" if case["status"] == "simulated" else
           f"reused: {case['status']}")
    where = f"{_where(case)}: "
    if case.get("sdc") is None:  # not stored (a run stored without an SDC reads so too)
        return f"{where}no stored result ({how})"
    stderr, balance = case.get("sdc_stderr"), case.get("energy_balance_error")
    steady = case.get("steady_detected")
    return (where + f"SDC {_sdc_text(case['sdc'], stderr)} [-]"
            # one cell, or cells of one motion (dem run's note says which)
            + (" (no standard error)" if stderr is None else "") + ", energy balance "
            + ("not stored" if balance is None else _balance_text(balance))
            + ", steady state "
            + ("not stored" if steady is None else _steady_text(steady)) + f" ({how})")


def _sdc_text(sdc: float, stderr: float | None) -> str:
    """An SDC with its standard error, as analyze and the app write them (the SDC alone where
    it has none: one cell, one motion, or null in a document)."""
    from ..units import display_value_with_error

    return display_value_with_error(sdc, math.nan if stderr is None else stderr)


def _balance_text(error: float) -> str:
    """The energy balance's closure error (a ratio) in percent."""
    return f"closure error {error:.2%}"


def _steady_text(detected: bool) -> str:
    """Whether a run's steady state was detected, or its transient hit the cap."""
    return "detected" if detected else "NOT converged, transient cap"


def _check_fill(fill: float, option: str, args: argparse.Namespace, specimen,
                material: str) -> None:
    """A fill that rounds to no particle (or more than fit) is refused naming the option."""
    from ..dem.simulate import particles_per_cell
    from ..loadcase import check_fill_range

    check_fill_range(fill, option)
    # (a fraction typed for a percentage is asked about by particles_for_fill, as for analyze)
    particles_per_cell(fill, material, specimen=specimen, fill_reference=args.fill_reference,
                       what=option, typed=True)


def _fill(args: argparse.Namespace, specimen, material: str) -> float:
    if args.fill is not None:
        _check_fill(args.fill, "--fill", args, specimen, material)
        return args.fill
    stated = specimen.stated_fill(args.fill_reference) if specimen is not None else None
    if stated is not None:
        return stated[0]
    if specimen is None:
        raise ParameterError("--fill: required (or a --specimen file stating count_per_cell "
                             "or fill_percent)")
    raise ParameterError(f"--fill: required ({specimen.name} states no count_per_cell or "
                         "fill_percent)")


def run(args: argparse.Namespace) -> int:
    from ..dem import LoadCase, simulate_load_case

    specimen, material = _specimen(args)
    case = LoadCase(args.frequency, args.acceleration, _fill(args, specimen, material),
                    material=material, direction=args.direction)
    from ..dem.simulate import check_drive

    config = _config(args)
    check_drive(case, config, specimen, what="--frequency/--acceleration")
    progress = progress_wanted(args)
    key = None
    reused = False
    store = None
    try:
        if args.store is not None:
            from ..dem import persist
            from ..store import Store

            store = Store(args.store)
            cached = persist.cached_run(store, specimen, case, config, progress=progress)
            result, key, reused = cached.result, cached.key, cached.reused
            other_files = "" if reused else \
                persist.other_files_runs_note(args.store, [case], config, specimen)
        else:
            result = simulate_load_case(case, config, progress=progress, specimen=specimen)
            other_files = ""
        # inside: a Ctrl-C as the result is printed said "no store write was left
        # half-done" instead of whether the run was saved
        _print_run(args, result, case, specimen, key=key, reused=reused,
                   other_files=other_files)
        interrupt.raise_if_interrupted()
    except KeyboardInterrupt:
        # the run is saved in one transaction at its end: committed now, or not at all
        # one run: saved, it is finished (nothing to resume)
        return _interrupted("run", int(store is not None and store.commits > 0), args.store,
                            left=0)
    return 0


def _print_run(args: argparse.Namespace, result, case, specimen, *, key: str | None,
               reused: bool, other_files: str = "") -> None:
    """One run's summary and notes, or its JSON document, and where it is stored."""
    notes = list(result.notes)
    said = [note for note in (_same_simulation_note(case, result) if reused else "",
                              _baseline_note(specimen, result), other_files) if note]
    notes += said
    if args.json:
        out = {k: result.to_dict()[k] for k in JSON_KEYS}
        out.update(result.to_dict())
        out["notes"] = notes
        # every number names its unit, as calibrate --json does (work_walls_j and the other
        # run totals are of the simulated cells over the whole run: DemResult)
        from ..dem.result import UNITS as DEM_UNITS

        out["units"] = {k: unit for k, unit in DEM_UNITS.items() if k in out}
        if key is not None:
            out["store_key"] = key
            out["reused_from_store"] = reused
        print_json(out)
        return
    print(format_summary(result, reused=reused))
    total = _measured_sdc_line(specimen, result)
    if total:
        print(total)
    for note in said:
        print(f"note            {note}")
    if key is not None:
        print(f"{'reused from' if reused else 'saved to'} {args.store} as {key}")


def _baseline_note(specimen, result) -> str:
    """What the SDC leaves out of a specimen stating the empty coupon's loss factor: the run
    printed the particles' SDC beside a file stating ``baseline_loss_factor`` without a word
    of whether it was in it; "" where the specimen states none.

    The empty structure (coupon and fixture, the rigid mass the shaker moves) dissipates
    2 pi eta_0 of *its own* peak kinetic energy per cycle, so it adds
    2 pi eta_0 m_structure / m_c to an SDC taken over E = m_c a^2 / (2 w^2) -- the observation
    model of ``pidcore calibrate`` (:func:`pidcore.calibrate.surrogate.predicted_sdc`). The note
    said 2 pi eta_0, 9 x too much for a bed of tungsten carbide nine times the structure's mass.
    """
    eta = float(specimen.coupon.baseline_loss_factor) if specimen is not None else 0.0
    if eta <= 0:
        return ""
    share = result.moving_mass_kg / result.vibrated_mass_kg
    # m_c holds the coupon and fixture except under --mass-convention particles, where the
    # note said "0.17 kg of m_c = 0.2528 kg" of an m_c of the particles alone
    within = (f"{result.moving_mass_kg:.4g} kg beside m_c = {result.vibrated_mass_kg:.4g} kg "
              "of the particles alone (--mass-convention particles)"
              if result.config.vibrated_mass == "particles" else
              f"{result.moving_mass_kg:.4g} kg of m_c = {result.vibrated_mass_kg:.4g} kg")
    return (f"SDC of the particles alone: the specimen's [coupon] baseline_loss_factor {eta:g} "
            f"(the empty coupon's damping: 2 pi x {eta:g} of the coupon and fixture's own "
            f"kinetic energy, {within}, i.e. {2 * math.pi * eta * share:.3g} in this "
            "SDC) is not in it; pidcore calibrate's prediction adds it")


def _measured_sdc_line(specimen, result) -> str:
    """The run's SDC as a shaker test of ``specimen`` measures it (Eq. 11 of the virtual
    shaker, with the coupon and fixture's inertia and its ``baseline_loss_factor``: the
    observation model :func:`pidcore.calibrate.calibrate` predicts), where the specimen states a
    baseline; "" elsewhere. A calibrated file ran with its Eq. 10 SDC and a note that the
    baseline adds 0.173 to it, and the number a user compares with a measurement was theirs
    to add up (and not the sum: Eq. 10 divides by another mass)."""
    if specimen is None or not specimen.coupon.baseline_loss_factor > 0:
        return ""
    from ..calibrate.observation import observation_from_run
    from ..dem.persist import dem_run_entry

    entry = dem_run_entry(result)
    seen = observation_from_run(entry["record"], entry["arrays"],
                                coupon_mass_kg=specimen.coupon.mass_kg)
    value = float(seen.sdc(specimen.coupon.fixture_mass_kg,
                           specimen.coupon.baseline_loss_factor))
    return (f"SDC measured    {value:.4g} [-] (Eq. 11 of the virtual shaker with the coupon + "
            f"fixture's {(specimen.coupon.mass_kg + specimen.coupon.fixture_mass_kg) * 1e3:.4g}"
            f" g and baseline_loss_factor {specimen.coupon.baseline_loss_factor:g}: what a "
            "shaker test of this specimen measures, and pidcore calibrate predicts; compare "
            "a measurement with this one)")


def _same_simulation_note(asked, result) -> str:
    """The note for a run reused from a stored run of another stated fill (the same particle
    count: :func:`pidcore.dem.persist.stored_run_key`); "" where the fill is the one asked."""
    stored = result.case.fill_percent
    if stored == asked.fill_percent:
        return ""
    asked_text, stored_text = apart(asked.fill_percent, stored)
    return (f"fill {asked_text} % asked; reused the stored run of fill {stored_text} %: "
            f"the same simulation ({result.particles_per_cell} particles per cell, seed "
            f"{result.config.seed}, the same settings and specimen), so the numbers are those "
            "of that run and it is stated at its fill")


def _tangential_stiffness_model(result) -> str:
    s = result.specimen
    return s.pairs.tangential_stiffness_model if s is not None else "constant"


def format_summary(result, *, reused: bool = False) -> str:
    """Readable multi-line summary with units."""
    from ..dem.result import stderr_from_batches
    from ..specimen import filled_share, hashed_name

    c = result.case
    s = result.specimen
    material = s.particles.material if s is not None else c.material
    lines = [
        f"DEM load case   {c.frequency_hz:g} Hz, {c.acceleration_g:g} g, fill "
        f"{c.fill_percent:g} % ({result.particles_per_cell} of {result.particles_full_cell} "
        f"{material} particles per cell"
        f"{filled_share(c.fill_percent, result.particles_per_cell, result.particles_full_cell)}, "
        f"reference {result.config.fill_reference}), "
        f"drive along {c.direction}",
    ]
    if s is not None:
        kind = "the paper's coupon" if s.is_paper() else "own specimen"
        particles = result.coupon_cells * result.particles_per_cell * s.particles.mass_kg
        lines += [
            f"specimen        {hashed_name(s.name, s.hash)} ({kind}): {result.coupon_cells} "
            f"{s.cell.shape} cells {s.cell.inscribed_diameter_m * 1e3:.4g} x "
            f"{s.cell.height_m * 1e3:.4g} mm, particles r = {s.particles.radius_m * 1e3:.4g} mm",
            f"masses          coupon {s.coupon.mass_kg * 1e3:.4g} g + fixture "
            f"{s.coupon.fixture_mass_kg * 1e3:.4g} g + particles {particles * 1e3:.4g} g",
        ]
    lines += [
        # as analyze and the app write an SDC with its error (it printed 0.2635 +- 0.0038)
        (f"SDC             {_sdc_text(result.sdc, result.sdc_stderr)} [-] "
         f"(loss factor "
         f"{result.loss_factor:.4g} [-]) over {result.cells_simulated} "
         f"{'cell' if result.cells_simulated == 1 else 'cells'}"
         # the error of cells that ran one motion is from batches of it, not the cells
         + (" (stderr from batches of one motion: see the note)"
            if stderr_from_batches(result.sdc_per_cell) else "")
         if math.isfinite(result.sdc_stderr) else
         f"SDC             {result.sdc:.4g} [-] (loss factor {result.loss_factor:.4g} [-]) over "
         f"{result.cells_simulated} cell(s): no standard error"
         # a run of one cell or of one motion says in a note why it has none
         + " (see the note)"),
        f"dissipated      {result.energy_per_cycle_j:.4g} J/cycle (coupon, "
        f"{result.coupon_cells} cells): normal "
        f"damping {result.energy_dissipated_normal_j:.4g} J, friction "
        f"{result.energy_dissipated_friction_j:.4g} J, rolling "
        f"{result.energy_dissipated_rolling_j:.4g} J",
        f"E (Eq. 10)      {result.max_kinetic_energy_j:.4g} J with m_c = "
        f"{result.vibrated_mass_kg:.4g} kg ({result.config.vibrated_mass})",
        f"energy balance  {_balance_text(result.energy_balance_error)}",
        f"steady state    from cycle {result.steady_start_cycle} "
        f"({_steady_text(result.steady_detected)}), "
        f"{result.steady_cycles} cycles measured",
        f"model           friction {result.config.tangential_model}, normal damping "
        f"{result.config.normal_damping_mode}, start {result.config.start_packing} packing "
        f"{result.config.start_protocol.replace('_', ' ')}, k_t "
        f"{_tangential_stiffness_model(result)}",
        *([f"damping         alpha of Eq. 2 {result.alpha_pp:.4g} particle-particle, "
           f"{result.alpha_pw:.4g} particle-wall ({result.config.damping_coefficient})"]
          if math.isfinite(result.alpha_pp) else []),  # NaN: stored before it was kept
        # "30.4 s wall, 1.74e+07 particle-steps/s" for 1.9e7 particle-steps: the wall time
        # holds the settle and a first Numba compile, the rate only the kernel's own calls
        f"numerics        dt {result.time_step_s:.4g} s, {result.steps} driven steps, "
        f"{result.wall_s:.1f} s wall (settle and any Numba compile included), "
        f"{result.particle_steps_per_s:.3g} particle-steps/s in the kernel"
        # a reused run's wall time is the stored run's: this command simulated nothing
        + (" (the stored run's; nothing simulated now)" if reused else ""),
    ]
    lines += [f"note            {note}" for note in result.notes]
    return "\n".join(lines)
