"""``pidcore model`` sub-command, driven through its own parser (thin layer over the library)."""

from __future__ import annotations

import argparse
import json

import numpy as np
import pandas as pd
import pytest

from pidcore.cli import model as model_cli
from pidcore.errors import ParameterError
from pidcore.model import SdcModel, coupon_vibrated_mass_kg, load_paper_table3


def _run(argv: list[str]) -> int:
    parser = argparse.ArgumentParser(prog="pidcore")
    sub = parser.add_subparsers(dest="command", required=True)
    model_cli.register(sub)
    args = parser.parse_args(argv)
    return args.func(args)


def test_damper_writes_the_paper_grid(tmp_path):
    assert _run(["model", "damper", "--out", str(tmp_path), "--mass-convention", "coupon"]) == 0
    table = pd.read_csv(tmp_path / "equivalent_damper.csv")
    assert len(table) == 48
    np.testing.assert_allclose(table["vibrated_mass [kg]"], coupon_vibrated_mass_kg())
    ref = load_paper_table3().dropna(subset=["sdc_dem"])
    merged = table.merge(ref, left_on=["frequency [Hz]", "acceleration [g]", "fill [%]"],
                         right_on=["frequency_hz", "acceleration_g", "fill_percent"])
    assert len(merged) == 47
    np.testing.assert_allclose(merged["sdc [-]"], merged["sdc_dem"], rtol=1e-12)
    doc = json.loads((tmp_path / "equivalent_damper.json").read_text())
    assert len(doc["records"]) == 48
    assert doc["provenance"]["filled_grid_points"][0]["frequency_hz"] == 1000.0
    # the flag reads back as bool under its bracketed name, in the CSV as in the JSON
    assert table["sdc_filled [True/False]"].dtype == bool
    flagged = table[table["sdc_filled [True/False]"]]
    assert flagged[["frequency [Hz]", "acceleration [g]", "fill [%]"]].values.tolist() == [
        [1000.0, 1.0, 90.0]]
    assert doc["units"]["sdc_filled [True/False]"] == "True/False"
    assert sum(r["sdc_filled [True/False]"] is True for r in doc["records"]) == 1


def test_damper_options(tmp_path):
    _run(["model", "damper", "--out", str(tmp_path), "--format", "csv", "--fills", "30,60",
          "--accelerations", "2", "--frequencies", "75,300", "--vibrated-mass", "0.5"])
    assert not (tmp_path / "equivalent_damper.json").exists()
    table = pd.read_csv(tmp_path / "equivalent_damper.csv")
    assert len(table) == 4 and set(table["vibrated_mass [kg]"]) == {0.5}
    with pytest.raises(ParameterError, match="outside the model range"):
        _run(["model", "damper", "--out", str(tmp_path), "--fills", "95"])
    with pytest.raises(SystemExit):
        _run(["model", "damper", "--out", str(tmp_path), "--format", "xlsx"])


def test_damper_from_store_runs(tmp_path, monkeypatch):
    import pidcore.store

    base = load_paper_table3().dropna(subset=["sdc_dem"]).rename(columns={"sdc_dem": "sdc"})
    runs = pd.concat([base.assign(sdc=base.sdc * 0.9), base.assign(sdc=base.sdc * 1.1)])
    runs = pd.concat([runs.assign(material="acrylic"), base.assign(material="aluminium", sdc=0.7)])

    class FakeStore:
        def __init__(self, path):
            self.path = path

        def list_dem_runs(self):
            return runs.assign(sdc_stderr=0.01, case_key="k")

    monkeypatch.setattr(pidcore.store, "Store", FakeStore, raising=False)
    argv = ["model", "damper", "--out", str(tmp_path), "--table", "store", "--store",
            str(tmp_path / "s.h5"), "--format", "csv"]
    with pytest.raises(ParameterError, match="differ in material"):
        _run(argv)
    _run([*argv, "--where", "material=acrylic"])
    table = pd.read_csv(tmp_path / "equivalent_damper.csv")
    # duplicates averaged: mean of 0.9 x and 1.1 x is the paper value
    expected = SdcModel.from_table(load_paper_table3())
    np.testing.assert_allclose(table["sdc [-]"], expected(table["fill [%]"],
                               table["acceleration [g]"], table["frequency [Hz]"]), rtol=1e-12)


@pytest.mark.slow
def test_figures_writes_every_family(tmp_path, monkeypatch):
    # Which files the command writes, not how they look: the figures are built as usual but
    # not rasterised (14 drawn files took ~4 s); test_model_figures draws and saves them.
    from matplotlib.figure import Figure

    built = []

    def save_undrawn(fig, path, **_):
        built.append(fig)
        path.write_bytes(b"x")

    monkeypatch.setattr(Figure, "savefig", save_undrawn)
    assert _run(["model", "figures", "--out", str(tmp_path)]) == 0
    assert len({id(fig) for fig in built}) == 4 + 3  # one figure per family, saved twice
    names = sorted(p.name for p in tmp_path.iterdir())
    assert len(names) == 2 * (4 + 3)
    assert "sdc_vs_acceleration_fill90.svg" in names and "sdc_vs_frequency_10g.png" in names
