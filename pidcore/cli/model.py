"""``pidcore model``: the SDC interpolation model, its equivalent damper and figures.

``pidcore model damper --out DIR [--table paper|store] [--store FILE] [--format csv,json]``
writes the equivalent-damper table; ``pidcore model figures --out DIR`` writes the SDC figure
families (paper Figs. 8-14) as PNG and SVG. Each replaces its ``--out`` folder's outputs
whole, as ``report --out`` does (:mod:`pidcore.out_folder`). All logic is in
:mod:`pidcore.model` and :mod:`pidcore.report.figures`.
"""

from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path

from .. import defaults
from ..atomic_files import refused_unless_written
from ..constants import PARTICLE_MATERIALS, VIBRATED_MASS_CONVENTIONS
from ..errors import ParameterError, as_given
from ..out_folder import check_replaceable, write_folder_whole
from ._options import (
    add_store_option,
    check_out_folder,
    comma_list,
    command_line,
    path_argument,
)


def _float_list(text: str) -> list[float]:
    try:
        values = [float(v) for v in comma_list(text)]
    except ValueError as exc:
        raise argparse.ArgumentTypeError(f"expected comma-separated numbers, got {text!r}") \
            from exc
    if not all(math.isfinite(v) for v in values):
        raise argparse.ArgumentTypeError(f"expected finite numbers, got {text!r}")
    return values


def _positive_float(text: str) -> float:
    try:
        value = float(text)
    except ValueError as exc:
        raise argparse.ArgumentTypeError(f"expected a number, got {text!r}") from exc
    if not (math.isfinite(value) and value > 0):
        raise argparse.ArgumentTypeError(f"expected a finite number > 0, got {text!r}")
    return value


def _formats(text: str) -> list[str]:
    formats = [v.lower() for v in comma_list(text)]
    bad = sorted(set(formats) - {"csv", "json"})
    if bad:
        raise argparse.ArgumentTypeError(f"unknown format(s) {bad or text!r}; expected csv,json")
    return formats


def _add_model_source(p: argparse.ArgumentParser) -> None:
    p.add_argument("--out", metavar="DIR", type=path_argument, required=True,
                   help="output folder, its earlier outputs replaced whole (one holding other "
                        "files is refused)")
    p.add_argument("--table", choices=("paper", "store"), default="paper",
                   help="SDC data: the paper's Table 3 DEM column or the store's DEM runs "
                        "(default paper)")
    add_store_option(p, help=f"HDF5 store for --table store (default ./{defaults.STORE_PATH})")
    p.add_argument("--where", metavar="COLUMN=VALUE", action="append", default=[],
                   help="with --table store: keep runs whose COLUMN equals VALUE (repeatable; "
                        "numbers as numbers: fill_percent=50 is 50.0), e.g. --where "
                        "material=acrylic")
    p.add_argument("--log-frequency", action="store_true", default=defaults.MODEL_LOG_FREQUENCY,
                   help="interpolate in log(frequency)")


def register(subparsers: argparse._SubParsersAction) -> None:
    p = subparsers.add_parser(
        "model", help="SDC interpolation model, equivalent damper, figures",
        description="Multivariate pchip model of SDC over fill, acceleration and frequency "
                    "(paper Sect. 5.1, 8), its equivalent viscous damper and figures.")
    sub = p.add_subparsers(dest="model_command", metavar="ACTION", required=True)

    d = sub.add_parser("damper", help="equivalent viscous damper table (CSV/JSON)",
                       description="Equivalent viscous damper c_eq = SDC m_c w / (2 pi) per "
                                   "coupon and per unit area over a grid of fill, acceleration "
                                   "and frequency (default: the model's grid).")
    _add_model_source(d)
    d.add_argument("--format", metavar="LIST", type=_formats, default=["csv", "json"],
                   help="comma-separated: csv,json (default both)")
    d.add_argument("--fills", metavar="LIST", type=_float_list, help="fills, %%")
    d.add_argument("--accelerations", metavar="LIST", type=_float_list,
                   help="acceleration amplitudes, g")
    d.add_argument("--frequencies", metavar="LIST", type=_float_list, help="frequencies, Hz")
    d.add_argument("--mass-convention", choices=VIBRATED_MASS_CONVENTIONS, default=None,
                   help="mass m_c in E = m_c a^2/(2 w^2): --table paper: default "
                        f"{defaults.MODEL_VIBRATED_MASS_CONVENTION}, particles by the paper's "
                        "count of 36 per full cell; --table store: the m_c the runs divided "
                        "their SDC by (their specimen's masses and count; another convention "
                        "is refused)")
    d.add_argument("--material", choices=PARTICLE_MATERIALS, default=None,
                   help="particle material of the masses: --table paper: "
                        f"{defaults.MODEL_PARTICLE_MATERIAL}, Table 3's (another is refused "
                        "unless --vibrated-mass gives m_c, whose unit-slip check it sets); "
                        "--table store: the runs' own")
    d.add_argument("--vibrated-mass", metavar="KG", type=_positive_float, default=None,
                   help="explicit m_c, kg, of one fill: give that fill alone with --fills "
                        "(each fill's SDC was divided by its own m_c; several fills are "
                        "refused); overrides --mass-convention; --table paper only: stored "
                        "runs divided their SDC by their own m_c; more than 100 x outside the "
                        "paper coupon's m_c at that fill is refused as a unit slip")
    d.add_argument("--area", metavar="M2", type=_positive_float, default=None,
                   help="coupon area for c_eq per area, m^2 (default: the specimen's [coupon] "
                        "face_area_m2, the paper's 0.1 m x 0.1 m, else its cells' "
                        "cross-section, cell count x hexagon area; a value more than 5 %% off "
                        "the default is noted, more than 100 x off the cells' is refused as a "
                        "unit slip)")
    d.add_argument("--specimen", metavar="FILE", type=path_argument, default=None,
                   help="the specimen file the SDC is of (with --table store: the store's "
                        "runs of this file, by its sha256; with --table paper: the paper's "
                        "coupon), for the [coupon] face_area_m2 it states: a DEM run stores "
                        "its specimen without it; another specimen (another sha256) is "
                        "refused")
    d.add_argument("--panel-areal-mass", metavar="KG_M2", type=_positive_float, default=None,
                   help="mass per m^2 of your panel, with its particles, kg/m^2: adds "
                        "panel_loss_factor, the loss factor the particles add to it moving as "
                        "the coupon did (one amplitude everywhere; not a mode's); more than "
                        "100 x outside the coupons' own m_c / area is refused as a unit slip, "
                        "and so is less than its particles' own mass per m^2 (the coupon's "
                        "at the largest fill x --panel-treated-fraction)")
    d.add_argument("--panel-treated-fraction", metavar="F", type=_positive_float, default=None,
                   help="with --panel-areal-mass: share of the panel's area filled, in (0, 1] "
                        "(default 1)")
    # --out is replaced whole (pidcore.out_folder): an interrupt's line says which set it holds
    d.set_defaults(func=run_damper, out_written_whole_by="model damper")

    f = sub.add_parser("figures", help="SDC figures (paper Figs. 8-14), PNG and SVG")
    _add_model_source(f)
    f.add_argument("--specimen", metavar="FILE", type=path_argument, default=None,
                   help="with --table store: draw the store's runs of this specimen file (by "
                        "its sha256), the other specimens' left out")
    f.set_defaults(func=run_figures, out_written_whole_by="model figures")


def build_model(args: argparse.Namespace):
    """(SDC model, the DEM runs it is built on or None for the paper's table) selected by
    --table/--store/--where/--log-frequency."""
    from ..model import SdcModel, load_paper_table3

    if args.table == "paper":
        if args.where:
            raise ParameterError("--where selects DEM runs: use it with --table store")
        return SdcModel.from_table(load_paper_table3(), value="sdc_dem",
                                   log_frequency=args.log_frequency,
                                   source="paper Table 3 (DEM)"), None
    from ..model import select_runs
    from ..store import Store

    where = {}
    for item in args.where:
        column, sep, value = item.partition("=")
        if not sep or not column:
            raise ParameterError(f"--where {item!r}: expected COLUMN=VALUE")
        where[column.strip()] = value.strip()
    runs = Store(args.store).list_dem_runs()
    if runs.empty and not Path(args.store).is_file():  # a mistyped path: "no DEM runs stored"
        from ..errors import StoreError

        raise StoreError(f"{args.store}: store not found; expected the store holding the DEM "
                         "runs (--store FILE)")
    if runs.empty:
        raise ParameterError(f"{args.store}: no DEM runs stored; run `pidcore dem` first or use "
                             f"--table paper")
    if getattr(args, "specimen", None) is not None:
        runs = _runs_of_specimen_file(runs, args.specimen, args.store)
    try:
        runs = select_runs(runs, where=where)
    except ParameterError as exc:
        raise ParameterError(_cli_where(str(exc), where)) from None
    from ..compare.specimens import run_specimen_labels

    # the specimen named: steel and paper-coupon figures looked alike
    specimen = run_specimen_labels(runs).iloc[0]
    text = f"DEM runs of {specimen} in {args.store}" + (
        " where " + ", ".join(f"{k}={v}" for k, v in where.items()) if where else "")
    from ..model.sdc_model import complete_grid_model

    # one run off the grid (300 Hz at 2 g only) refused the whole store, naming neither it
    # nor the run, and --where cannot leave a value out: the report's rule, said
    runs = runs.reset_index(drop=True)  # the runs left out are named by their rows
    model, kept, left_out = complete_grid_model(runs, value="sdc",
                                                log_frequency=args.log_frequency, source=text)
    if left_out:
        print(f"pidcore model {args.model_command}: note: {text}: left out of the SDC model, "
              f"off its complete frequency x acceleration grid: {left_out}; "
              f"{_runs_named(runs.drop(kept.index))}", file=sys.stderr)
    return model, kept


def _runs_named(runs) -> str:
    """``"2 run(s): f300Hz_..., f300Hz_..."`` (the first few keys), for a note."""
    keys = [str(k) for k in runs["case_key"]] if "case_key" in runs.columns else []
    shown = ", ".join(keys[:5]) + (f", ... ({len(keys) - 5} more)" if len(keys) > 5 else "")
    return f"{len(runs)} run(s)" + (f": {shown}" if shown else "")


def _runs_of_specimen_file(runs, path, store):
    """The runs of the ``--specimen`` file (its sha256): a store holding runs of two files (an
    edited one, the paper's coupon) was refused as "of 2 specimens", asking for a --where of
    the hash that --specimen already gave."""
    from ..compare.specimens import runs_per_specimen_text
    from ..dem.persist import runs_of_specimen
    from ..specimen import hashed_name, load_specimen

    given = load_specimen(path)
    mine = runs_of_specimen(runs, given)
    if mine.empty:
        raise ParameterError(
            f"--specimen {path}: {store} holds no DEM runs of "
            f"{hashed_name(given.name, given.hash)} (it holds {runs_per_specimen_text(runs)}); "
            "run them with "
            + command_line("pidcore", "dem", "sweep", "--specimen", path, "--store", store))
    return mine


def _cli_where(message: str, where: dict) -> str:
    """A :func:`pidcore.model.select_runs` message in the CLI's words: its library selection
    (``where={'material': 'steel'} (CLI: --where material=steel)``) as the ``--where`` option
    alone, and the selection that matched nothing as the options typed."""
    import re

    message = re.sub(r"where=\{[^{}]*\} \(CLI: (--where [^)]*)\)", r"\1", message)
    if message.startswith("DEM runs: none match "):
        message = "DEM runs: none match " + " ".join(f"--where {k}={v}"
                                                    for k, v in where.items())
    return message


#: The files ``model damper`` writes into ``--out`` (:func:`write_damper_table`'s stem):
#: the folder holds these alone, replaced whole by each run.
DAMPER_STEM = "equivalent_damper"


def run_damper(args: argparse.Namespace) -> int:
    from ..model.damper import (
        SDC_FILLED_COLUMN,
        SDC_FILLED_NOTE,
        area_override_note,
        check_area,
        equivalent_damper_table,
        paper_vibrated_mass,
        runs_particles_mass,
        runs_specimen,
        runs_vibrated_mass,
        specimen_area_m2,
        specimen_particles_mass,
        write_damper_table,
    )

    check_out_folder(args.out, built_beside=True)
    # a CSV of an earlier run at 50 % was left beside this run's JSON at 75 %: the folder is
    # replaced whole, and one holding other files refused before any work
    check_replaceable(args.out, "model damper", option="--out")
    # the table takes a value typed twice once (equivalent_damper_table): said here
    for option in ("fills", "accelerations", "frequencies"):
        given = getattr(args, option)
        once = list(dict.fromkeys(given)) if given else given
        if given and len(once) < len(given):
            print(f"pidcore model damper: note: --{option} {','.join(f'{v:g}' for v in given)}:"
                  f" each value once ({','.join(f'{v:g}' for v in once)})", file=sys.stderr)
    model, runs = build_model(args)
    if runs is not None and args.vibrated_mass is not None:
        raise ParameterError(
            f"--vibrated-mass {as_given(args.vibrated_mass)}: the DEM runs in {args.store} divided "
            "their SDC by their own m_c, which c_eq = SDC m_c w / (2 pi) must use; leave "
            "--vibrated-mass out")
    # the unit each list is in, and the other units whose values would fall inside: 49
    # (m/s^2 for 5 g) or 0.5 (a fraction for 50 %) was refused without naming the unit
    from ..constants import STANDARD_GRAVITY

    for option, axis, values, unit, slips in (
            ("--fills", 0, args.fills, "%", (("a fraction", 100.0),)),
            ("--accelerations", 1, args.accelerations, "g",
             (("m/s^2", 1.0 / STANDARD_GRAVITY),)),
            ("--frequencies", 2, args.frequencies, "Hz",
             (("kHz", 1000.0), ("rad/s", 1.0 / (2.0 * math.pi))))):
        lo, hi = model.axes[axis][0], model.axes[axis][-1]
        outside = [v for v in values or () if not lo <= v <= hi]
        if outside:
            hints = [name for name, factor in slips
                     if all(lo <= v * factor <= hi for v in outside)]
            raise ParameterError(
                f"{option} {','.join(as_given(v) for v in outside)}: outside the model's range "
                f"{lo:g} .. {hi:g} {unit} (never extrapolated)"
                + (f"; expected {unit}: was it {' or '.join(hints)}?" if hints else ""))
    table3 = defaults.MODEL_PARTICLE_MATERIAL  # Table 3's particles (paper Sect. 4)
    if runs is None and args.vibrated_mass is None and args.material not in (None, table3):
        # Table 3's SDC is the acrylic coupon's dissipation over its own m_c: times the m_c
        # of other particles it gave a damper no DEM run found (c_eq 1.18 x at 50 %
        # aluminium), written as the paper's
        raise ParameterError(
            f"--material {args.material}: the paper's Table 3 holds the SDC of {table3} "
            f"particles only, taken over an m_c holding {table3} spheres, which c_eq = SDC "
            f"m_c w / (2 pi) must use; leave --material out, give that m_c with --vibrated-mass, "
            f"or run the DEM with --material {args.material} (pidcore dem sweep) and use "
            "--table store")
    if runs is not None:
        for option, column, given in (("--mass-convention", "vibrated_mass_convention",
                                       args.mass_convention),
                                      ("--material", "material", args.material)):
            stated = sorted(runs[column].dropna().astype(str).unique()) \
                if column in runs.columns else []
            if given is not None and stated and stated != [given]:
                why = " (their SDC is divided by that m_c)" \
                    if option == "--mass-convention" else ""
                raise ParameterError(
                    f"{option} {given}: the DEM runs in {args.store} are {', '.join(stated)}"
                    f"{why}; leave {option} out or select runs with --where")
    fills = args.fills if args.fills else model.axes[0]
    material_note = ""
    if args.vibrated_mass is not None:
        from ..model.damper import check_one_fill_per_mass, check_vibrated_mass

        check_vibrated_mass(args.vibrated_mass, fills,
                            args.material or defaults.MODEL_PARTICLE_MATERIAL, "--vibrated-mass")
        # the one m_c typed went to every fill of the model's grid without a word
        check_one_fill_per_mass(args.vibrated_mass, fills, "--vibrated-mass",
                                "give one fill per m_c (--fills F), or leave --vibrated-mass "
                                "out for the paper coupon's m_c at each fill")
        mass = args.vibrated_mass
        mass_text = f"{mass} kg (given)"
        if runs is None and args.material not in (None, table3):
            # the provenance said acrylic only, the aluminium typed not mentioned
            material_note = (f"--material {args.material}: the SDC is the paper's Table 3, of "
                             f"{table3} particles; {args.material} sets only the range the "
                             "m_c given (--vibrated-mass) is checked against for a unit slip")
    elif runs is not None:
        mass = runs_vibrated_mass(runs)
        mass_text = (f"{runs['vibrated_mass_convention'].iloc[0]}: the m_c the DEM runs "
                     "divided their SDC by (their specimen's coupon, fixture and particle "
                     "masses and count per cell)")
    else:
        convention = args.mass_convention or defaults.MODEL_VIBRATED_MASS_CONVENTION
        material = args.material or defaults.MODEL_PARTICLE_MATERIAL
        mass = paper_vibrated_mass(convention, material)
        mass_text = f"{convention} ({material}, paper count per cell)"
    from ..specimen import paper_specimen

    # runs of an older store name no specimen text: the paper's coupon, as the library takes it
    stated = paper_specimen() if runs is None else runs_specimen(runs)
    if args.specimen is not None:
        stated = _specimen_file_of(args.specimen, stated, runs is None)
    specimen = stated or paper_specimen()
    if args.area is not None:
        check_area(args.area, specimen, "--area")  # first, to name the option typed
        area, area_text = args.area, f"{args.area} m^2 (given)"
        differs = area_override_note(args.area, specimen, "--area") if stated is not None else ""
        area_text += f"; {differs}" if differs else ""
    elif stated is None and runs is not None and "specimen_is_paper" in runs.columns \
            and not runs["specimen_is_paper"].fillna(True).astype(bool).all():
        name = runs["specimen_name"].iloc[0] if "specimen_name" in runs.columns else "?"
        raise ParameterError(f"--area: the DEM runs are of specimen {name}, whose text is "
                             "not stored with them (an older store): its cells' area is not "
                             "known; give the area c_eq per area is taken over, e.g. "
                             "--area 0.01")
    else:
        # the runs' text is their file's without the key: whether the file states one is
        # not known from them
        area, area_text = specimen_area_m2(specimen, read_from="its file" if runs is None or
                                           args.specimen is not None else
                                           "the text its DEM runs stored (a run stores its "
                                           "specimen without it: give --specimen FILE for "
                                           "the one its file states)")
    if args.panel_treated_fraction is not None and args.panel_areal_mass is None:
        raise ParameterError(f"--panel-treated-fraction {as_given(args.panel_treated_fraction)}:"
                             " the share of a panel given by --panel-areal-mass; give that too")
    if args.panel_treated_fraction is not None and args.panel_treated_fraction > 1:
        raise ParameterError(f"--panel-treated-fraction {as_given(args.panel_treated_fraction)}:"
                             " expected the treated share of the panel's area, in (0, 1]; was "
                             "it a percentage?")
    try:
        table = equivalent_damper_table(
            model, fills_percent=fills,
            accelerations_g=args.accelerations if args.accelerations else model.axes[1],
            frequencies_hz=args.frequencies if args.frequencies else model.axes[2],
            vibrated_mass_kg=mass, area_m2=area, specimen=specimen,
            panel_areal_mass_kg_m2=args.panel_areal_mass,
            panel_treated_fraction=args.panel_treated_fraction or 1.0,
            # the particles the m_c holds: Table 3's count (of --material's spheres where
            # --vibrated-mass gives m_c), or the runs' own
            particles_mass_kg=specimen_particles_mass(
                None, args.material or defaults.MODEL_PARTICLE_MATERIAL) if runs is None
            else runs_particles_mass(runs))
    except ParameterError as exc:  # the option as typed, not the library's keyword
        raise ParameterError(str(exc).replace("panel_areal_mass_kg_m2", "--panel-areal-mass")
                             ) from None
    provenance = {
        "sdc_source": model.source, "sdc_value": model.value_name,
        "interpolation": "tensor-product pchip (frequency, fill, acceleration passes)",
        "log_frequency": model.log_frequency, "vibrated_mass": mass_text,
        "area": area_text,
        "cells": f"{specimen.cell.count} (specimen {specimen.name}): c_eq_per_cell is "
                 "c_eq_per_coupon / this count",
        # which DOF the dashpot goes on and which particles it is of: the table's numbers
        # do not say, and a damper along the face (x, y) differs from one normal to it (z)
        "direction": _direction_text(runs),
        # the SDC's particles: Table 3's whatever --material set the m_c check for
        "particle_material": defaults.MODEL_PARTICLE_MATERIAL if runs is None
        else ", ".join(sorted(runs["material"].dropna().astype(str).unique())),
        "filled_grid_points": model.filled_points().to_dict(orient="records"),
    }
    if material_note:
        provenance["particle_material_note"] = material_note
    if args.panel_areal_mass is not None:
        provenance["panel"] = (
            f"{args.panel_areal_mass:g} kg/m^2 with its particles, "
            f"{args.panel_treated_fraction or 1.0:g} of its area treated (given): "
            "panel_loss_factor = c_eq_per_treated_area x treated fraction / (areal mass x w), "
            "the panel moving as the coupon did (one amplitude everywhere), not a mode's")
    if stated is None:
        # the paper's 441 cells are a guess for these runs: a per-cell damper of it is not given
        table = table.drop(columns=["c_eq_per_cell [N s/m]", "coupon_cells [-]"])
        provenance["cells"] = ("not stored with the DEM runs (an older store): no "
                               "c_eq_per_cell and coupon_cells columns")
    # only the hole's own row was flagged; the rows interpolated from it said nothing
    filled_note = table.attrs.get(SDC_FILLED_NOTE, "")
    if filled_note:
        provenance["filled_rows"] = f"{filled_note} ({SDC_FILLED_COLUMN} True)"
    undefined = int((table["sdc [-]"] >= 1.0).sum())
    why = ("damping ratio -ln(1 - SDC) / (4 pi) is undefined where SDC >= 1 (a free decay "
           "would lose all its energy within a cycle): left empty")
    if undefined:
        provenance["damping_ratio"] = why
    with refused_unless_written(args.out, "the damper table"):
        paths = write_folder_whole(
            args.out, "model damper",
            lambda folder: write_damper_table(table, folder, formats=args.format,
                                              stem=DAMPER_STEM, provenance=provenance),
            option="--out")
    for path in paths:
        print(path)
    print(f"pidcore model damper: note: coupon area {area_text}", file=sys.stderr)
    if material_note:
        print(f"pidcore model damper: note: {material_note}", file=sys.stderr)
    if undefined:
        print(f"pidcore model damper: note: {why} in {undefined} of {len(table)} row(s)",
              file=sys.stderr)
    if filled_note:
        print(f"pidcore model damper: note: {filled_note} (flagged {SDC_FILLED_COLUMN})",
              file=sys.stderr)
    return 0


def _specimen_file_of(path, stated, paper_table: bool):
    """The ``--specimen`` file, where it is the specimen the SDC is of (``stated``: the
    paper's coupon, or the one the DEM runs stored): its face area, which the runs' canonical
    text leaves out, is then the damper's. Any other file is refused: its area would divide an
    SDC that is not its own."""
    from ..specimen import hashed_name, load_specimen

    given = load_specimen(path)
    of = "the paper's Table 3 (--table paper)" if paper_table else "the DEM runs"
    if stated is None:
        raise ParameterError(f"--specimen {path}: the DEM runs store no specimen text (an "
                             "older store), so that they are of this file cannot be checked; "
                             "give the area c_eq per area is taken over with --area")
    if given.hash != stated.hash:
        raise ParameterError(
            f"--specimen {path}: {hashed_name(given.name, given.hash)} is not the specimen of "
            f"{of}, {hashed_name(stated.name, stated.hash)}; expected that specimen's file")
    return given


def _direction_text(runs) -> str:
    """The drive direction the damper acts along: the DEM runs' own, or Table 3's."""
    meaning = {"z": "normal to the face sheets", "x": "in the face plane", "y": "in the face "
               "plane"}
    if runs is None:
        # the paper's coupon hangs on a stinger at its centre (Sect. 5); pidcore's Table 3
        # runs shake it along z
        return "z (normal to the face sheets: the paper's Table 3 tests)"
    stated = sorted(runs["direction"].dropna().astype(str).unique()) \
        if "direction" in runs.columns else []
    return ", ".join(f"{d} ({meaning.get(d, '?')}: the DEM runs')" for d in stated) \
        or "not stored with the DEM runs"


def run_figures(args: argparse.Namespace) -> int:
    from ..report.figures import plot_sdc_vs_acceleration, plot_sdc_vs_frequency, save_figure
    from ..report.fonts import figure_fonts, missing_glyphs_note

    check_out_folder(args.out, built_beside=True)
    # the figures of fills an earlier model had stayed beside this one's
    check_replaceable(args.out, "model figures", option="--out")
    if args.specimen is not None and args.table == "paper":
        raise ParameterError(f"--specimen {args.specimen}: selects DEM runs: use it with "
                             "--table store (--table paper draws the paper's coupon)")
    model, _ = build_model(args)

    def curves(extra: tuple[float, ...], axis) -> list[float]:
        # grid values (data) plus interpolated ones inside the model's range
        lo, hi = axis[0], axis[-1]
        return sorted({float(v) for v in axis} | {v for v in extra if lo <= v <= hi})

    frequencies = curves(defaults.MODEL_FIGURE_FREQUENCIES_HZ, model.axes[2])
    fills = curves(defaults.MODEL_FIGURE_FILLS_PERCENT, model.axes[0])
    def draw(folder: Path) -> list[Path]:
        paths = []
        for fill in model.axes[0]:
            fig = plot_sdc_vs_acceleration(model, fills=[fill], frequencies=frequencies)
            paths += save_figure(fig, folder, f"sdc_vs_acceleration_fill{fill:g}")
        for acc in model.axes[1]:
            fig = plot_sdc_vs_frequency(model, accelerations=[acc], fills=fills)
            paths += save_figure(fig, folder, f"sdc_vs_frequency_{acc:g}g")
        return paths

    # a specimen's or store's name in CJK in the titles
    with figure_fonts() as missing, refused_unless_written(args.out, "the figures"):
        paths = write_folder_whole(args.out, "model figures", draw, option="--out")
    for path in paths:
        print(path)
    if missing:
        print(f"pidcore model figures: note: {missing_glyphs_note(missing)}", file=sys.stderr)
    return 0
