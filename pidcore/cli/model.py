"""``pidcore model``: the SDC interpolation model, its equivalent damper and figures.

``pidcore model damper --out DIR [--table paper|store] [--store FILE] [--format csv,json]``
writes the equivalent-damper table; ``pidcore model figures --out DIR`` writes the SDC figure
families (paper Figs. 8-14) as PNG and SVG. All logic is in :mod:`pidcore.model` and
:mod:`pidcore.report.figures`.
"""

from __future__ import annotations

import argparse
from pathlib import Path

from .. import defaults
from ..constants import PARTICLE_MATERIALS, VIBRATED_MASS_CONVENTIONS
from ..errors import ParameterError
from ._options import add_store_option


def _float_list(text: str) -> list[float]:
    try:
        values = [float(v) for v in text.split(",") if v.strip()]
    except ValueError as exc:
        raise argparse.ArgumentTypeError(f"expected comma-separated numbers, got {text!r}") \
            from exc
    if not values:
        raise argparse.ArgumentTypeError("expected at least one number")
    return values


def _formats(text: str) -> list[str]:
    formats = [v.strip().lower() for v in text.split(",") if v.strip()]
    bad = sorted(set(formats) - {"csv", "json"})
    if bad or not formats:
        raise argparse.ArgumentTypeError(f"unknown format(s) {bad or text!r}; expected csv,json")
    return formats


def _add_model_source(p: argparse.ArgumentParser) -> None:
    p.add_argument("--out", metavar="DIR", type=Path, required=True, help="output folder")
    p.add_argument("--table", choices=("paper", "store"), default="paper",
                   help="SDC data: the paper's Table 3 DEM column or the store's DEM runs "
                        "(default paper)")
    add_store_option(p, help=f"HDF5 store for --table store (default ./{defaults.STORE_PATH})")
    p.add_argument("--where", metavar="COLUMN=VALUE", action="append", default=[],
                   help="with --table store: keep runs whose COLUMN equals VALUE (repeatable), "
                        "e.g. --where material=acrylic")
    p.add_argument("--log-frequency", action="store_true", default=defaults.MODEL_LOG_FREQUENCY,
                   help="interpolate in log(frequency)")


def register(subparsers: argparse._SubParsersAction) -> None:
    p = subparsers.add_parser(
        "model", help="SDC interpolation model, equivalent damper, figures",
        description="Multivariate pchip model of SDC over fill, acceleration and frequency "
                    "(paper Sect. 4, 8), its equivalent viscous damper and figures.")
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
    d.add_argument("--mass-convention", choices=VIBRATED_MASS_CONVENTIONS,
                   default=defaults.MODEL_VIBRATED_MASS_CONVENTION,
                   help="mass m_c in E = m_c a^2/(2 w^2) (default "
                        f"{defaults.MODEL_VIBRATED_MASS_CONVENTION}; particles by the paper's "
                        "count of 36 per full cell)")
    d.add_argument("--material", choices=PARTICLE_MATERIALS,
                   default=defaults.MODEL_PARTICLE_MATERIAL, help="particle material")
    d.add_argument("--vibrated-mass", metavar="KG", type=float, default=None,
                   help="explicit m_c, kg (overrides --mass-convention)")
    d.set_defaults(func=run_damper)

    f = sub.add_parser("figures", help="SDC figures (paper Figs. 8-14), PNG and SVG")
    _add_model_source(f)
    f.set_defaults(func=run_figures)


def build_model(args: argparse.Namespace):
    """The SDC model selected by --table/--store/--log-frequency."""
    from ..model import SdcModel, load_paper_table3

    if args.table == "paper":
        return SdcModel.from_table(load_paper_table3(), value="sdc_dem",
                                   log_frequency=args.log_frequency,
                                   source="paper Table 3 (DEM)")
    from ..model import select_runs
    from ..store import Store

    where = {}
    for item in args.where:
        column, sep, value = item.partition("=")
        if not sep or not column:
            raise ParameterError(f"--where {item!r}: expected COLUMN=VALUE")
        where[column.strip()] = value.strip()
    runs = Store(args.store).list_dem_runs()
    if runs.empty:
        raise ParameterError(f"{args.store}: no DEM runs stored; run `pidcore dem` first or use "
                             f"--table paper")
    runs = select_runs(runs, where=where)
    text = f"DEM runs in {args.store}" + (f" where {where}" if where else "")
    return SdcModel.from_table(runs, value="sdc", log_frequency=args.log_frequency, source=text)


def run_damper(args: argparse.Namespace) -> int:
    from ..model.damper import (
        coupon_vibrated_mass_kg,
        equivalent_damper_table,
        paper_particles_mass_kg,
        write_damper_table,
    )

    model = build_model(args)
    if args.vibrated_mass is not None:
        mass = args.vibrated_mass
        mass_text = f"{mass} kg (given)"
    else:
        convention = args.mass_convention

        def mass(fill: float) -> float:
            particles = paper_particles_mass_kg(fill, args.material)
            if convention == "particles":
                return particles
            if convention == "coupon":
                return coupon_vibrated_mass_kg()
            return coupon_vibrated_mass_kg(particles_mass_kg=particles)

        mass_text = f"{convention} ({args.material}, paper count per cell)"
    table = equivalent_damper_table(
        model, fills=args.fills if args.fills else model.axes[0],
        accelerations=args.accelerations if args.accelerations else model.axes[1],
        frequencies=args.frequencies if args.frequencies else model.axes[2],
        vibrated_mass_kg=mass)
    provenance = {
        "sdc_source": model.source, "sdc_value": model.value_name,
        "interpolation": "tensor-product pchip (frequency, fill, acceleration passes)",
        "log_frequency": model.log_frequency, "vibrated_mass": mass_text,
        "filled_grid_points": model.filled_points().to_dict(orient="records"),
    }
    paths = write_damper_table(table, args.out, formats=args.format, provenance=provenance)
    for path in paths:
        print(path)
    return 0


def run_figures(args: argparse.Namespace) -> int:
    from ..report.figures import plot_sdc_vs_acceleration, plot_sdc_vs_frequency, save_figure

    model = build_model(args)

    def curves(extra: tuple[float, ...], axis) -> list[float]:
        # grid values (data) plus interpolated ones inside the model's range
        lo, hi = axis[0], axis[-1]
        return sorted({float(v) for v in axis} | {v for v in extra if lo <= v <= hi})

    frequencies = curves(defaults.MODEL_FIGURE_FREQUENCIES_HZ, model.axes[2])
    fills = curves(defaults.MODEL_FIGURE_FILLS_PERCENT, model.axes[0])
    paths = []
    for fill in model.axes[0]:
        fig = plot_sdc_vs_acceleration(model, fills=[fill], frequencies=frequencies)
        paths += save_figure(fig, args.out, f"sdc_vs_acceleration_fill{fill:g}")
    for acc in model.axes[1]:
        fig = plot_sdc_vs_frequency(model, accelerations=[acc], fills=fills)
        paths += save_figure(fig, args.out, f"sdc_vs_frequency_{acc:g}g")
    for path in paths:
        print(path)
    return 0
