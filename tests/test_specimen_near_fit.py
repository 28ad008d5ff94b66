"""A sphere nearly as wide (or as tall) as its cell: packed, with the capacity a hand count
gives, or refused in one line naming ``[particles] radius_m`` and the limit -- the same in
``specimen check``, ``dem run``, ``calibrate`` and the app; never a traceback.

The packing's candidate grid was anchored at a corner of the region where a centre may sit
(a hexagon of apothem a - r): when that region was narrower than a grid step (a sphere
diameter within ~2 % of the cell's flat-to-flat width) no grid node fell in it, and the
packing failed on an empty argmin.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from pidcore.app import jobs
from pidcore.cli import main
from pidcore.dem.geometry import (
    PACKING_GAP_FRACTION,
    CellGeometry,
    cell_capacity,
    check_sphere_fits,
    drop_packing,
    random_packing,
)
from pidcore.dem.state import assert_no_overlap
from pidcore.errors import ParameterError
from pidcore.specimen import Specimen, describe

REPO = Path(__file__).resolve().parents[1]
TEXT = (REPO / "data_samples" / "specimens" / "steel_6mm.toml").read_text(encoding="utf-8")

#: (flat-to-flat width, core height), m: a 2.5 mm micro-cell, the paper's cell, the 1/4 inch
#: cell of the steel sample.
CELLS = [(2.5e-3, 25.4e-3), (4.76e-3, 25.4e-3), (6.35e-3, 12.7e-3)]
#: Radii as fractions of the apothem (half the width): the near-fit range, where the grid
#: missed the room (from ~98.4 %), up to a hair below the limit, where only the cell axis is
#: left (1e-12: the axis is exactly one apothem from every wall, no rounding to lose it).
FRACTIONS = (0.97, 0.98, 0.985, 0.99, 0.995, 0.999, 0.9999, 1 - 1e-12)


def _edit(old: str, new: str, text: str = TEXT) -> str:
    assert old in text, old
    return text.replace(old, new, 1)


def _column_bounds(width: float, height: float, r: float) -> tuple[int, int]:
    """(spheres of a straight column, most spheres any packing holds), by hand.

    A centre may sit in a hexagon of apothem a - r, whose widest span is its corner-to-corner
    2 (a - r) 2/sqrt(3). Below the contact distance c = 2 r (1 + gap) no two spheres sit side
    by side: each sphere sits at least sqrt(c^2 - span^2) above the one below it. The first
    centre rests r (1 + gap) above the floor, the last as far below the ceiling, so at most
    1 + (h - c) / sqrt(c^2 - span^2) fit; a straight column holds floor(h / c).
    """
    c = 2.0 * r * (1.0 + PACKING_GAP_FRACTION)
    span = 2.0 * (0.5 * width - r) * 2.0 / math.sqrt(3.0)
    assert span < c  # a column: the bound holds
    return math.floor(height / c), 1 + math.floor((height - c) / math.sqrt(c * c - span * span))


@pytest.mark.parametrize("width, height", CELLS)
def test_a_near_fit_is_packed_as_a_column_with_the_hand_counted_capacity(width, height):
    geometry = CellGeometry(width, height)
    for fraction in FRACTIONS:
        r = fraction * 0.5 * width
        column, most = _column_bounds(width, height, r)
        # the lean of a column in so narrow a room saves under 1e-3 of a diameter per sphere:
        # these cells hold no extra sphere by it, so the hand count is exact
        assert column == most, (width, r)
        assert cell_capacity(geometry, r) == column, (width, fraction)
        packed = drop_packing(geometry, r, None)
        assert_no_overlap(packed[None], r, geometry)
        # the DEM's start packing (random drops) places a full cell too, without overlap
        start = random_packing(geometry, r, column, np.random.default_rng(7))
        assert len(start) == column
        assert_no_overlap(start[None], r, geometry)


def test_a_hand_count_of_one_near_fit():
    # 2.5 mm cell, 25.4 mm core, 2.48 mm spheres: 10 stacked are 24.8 mm (11 would be
    # 27.3 mm); the room across is 0.02 mm, far too little for two side by side
    assert cell_capacity(CellGeometry(2.5e-3, 25.4e-3), 1.24e-3) == 10


@pytest.mark.parametrize("width, height", CELLS)
def test_a_sphere_as_wide_as_the_cell_or_wider_is_refused_naming_the_limit(width, height):
    geometry = CellGeometry(width, height)
    limit = f"expected a radius below {0.5 * width * 1e3:.6g} mm"
    for r in (0.5 * width, 0.5 * width * (1 + 1e-9), 0.5 * width * 1.01):
        with pytest.raises(ParameterError, match=limit):
            cell_capacity(geometry, r)
        with pytest.raises(ParameterError, match=limit):
            check_sphere_fits(geometry, r)


def test_a_sphere_as_tall_as_the_core_is_refused_not_a_capacity_of_none():
    # 1 mm spheres in a 2.0001 mm core: the packing keeps 1e-4 r to floor and ceiling, so no
    # sphere fits (it placed none: capacity 0, and a fill of that empty cell divided by zero)
    geometry = CellGeometry(2.5e-3, 2.0001e-3)
    with pytest.raises(ParameterError, match=r"expected a radius up to 0.99995 mm"):
        cell_capacity(geometry, 1e-3)
    # just within the limit, one sphere: one layer (the 2.5 mm cell leaves 0.58 mm of room
    # across for centres 2 mm apart) of one
    assert cell_capacity(geometry, 0.9999e-3) == 1
    text = _edit("height_m = 12.7e-3", "height_m = 2.0001e-3")
    with pytest.raises(ParameterError, match=r"s.toml: \[particles\] radius_m: a sphere of "
                                             r"radius 1 mm does not fit .*up to 0.99995 mm"):
        Specimen.from_text(text, source="s.toml")


def _near_fit_text(radius_m: str) -> str:
    return _edit("fill_percent = 50.0", "count_per_cell = 1",
                 _edit("radius_m = 1.0e-3", f"radius_m = {radius_m}"))


def test_the_trials_near_fit_specimen_is_checked_with_its_capacity(tmp_path, capsys):
    # 6.3 mm spheres in 6.35 mm x 12.7 mm cells: 2 stacked are 12.6 mm, 3 would be 18.9 mm
    near = tmp_path / "near_fit.toml"
    near.write_text(_near_fit_text("3.15e-3"), encoding="utf-8")
    assert main(["specimen", "check", str(near)]) == 0
    assert "capacity 2 particles per cell" in capsys.readouterr().out
    assert main(["specimen", "check", "--json", str(near)]) == 0
    assert '"capacity_per_cell": 2' in capsys.readouterr().out
    spec = jobs.specimen_from_upload("near_fit.toml", near.read_bytes())  # the app's path
    assert describe(spec)["capacity_per_cell"] == 2


def test_an_exact_fit_is_one_line_exit_2_in_check_dem_run_calibrate_and_the_app(tmp_path,
                                                                                capsys):
    exact = tmp_path / "exact_fit.toml"
    exact.write_text(_near_fit_text("3.175e-3"), encoding="utf-8")
    said = (f"{exact}: [particles] radius_m: a sphere of radius 3.175 mm does not fit a "
            "6.35 x 12.7 mm cell; expected a radius below 3.175 mm")
    data = tmp_path / "m.csv"
    data.write_text("frequency_hz,acceleration_g,fill_percent,sdc\n100,5,50,0.3\n",
                    encoding="utf-8")
    for argv in (["specimen", "check", str(exact)],
                 ["specimen", "check", "--json", str(exact)],
                 ["dem", "run", "--specimen", str(exact), "--frequency", "100",
                  "--acceleration", "5", "--no-progress"],
                 ["calibrate", "--data", str(data), "--specimen", str(exact),
                  "--out", str(tmp_path / "out"), "--no-progress"]):
        assert main(argv) == 2, argv
        err = capsys.readouterr().err
        assert err.count("\n") == 1 and said in err and "Traceback" not in err, argv
    with pytest.raises(ParameterError, match=r"^exact_fit.toml: \[particles\] radius_m: .*"
                                             r"expected a radius below 3.175 mm"):
        jobs.specimen_from_upload("exact_fit.toml", exact.read_bytes())
