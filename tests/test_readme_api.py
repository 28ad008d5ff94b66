"""The README's ``Python API`` block runs as written: the whole job through the library, on the
bundled samples (a script user's first copy must not fail), and its numbers are the CLI's."""

from __future__ import annotations

import json
import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]


def _python_api_block() -> str:
    section = (ROOT / "README.md").read_text(encoding="utf-8").split("\n## Python API\n", 1)[1]
    match = re.search(r"```python\n(.*?)```", section.split("\n## ", 1)[0], re.S)
    assert match, "README: no python block under '## Python API'"
    return match.group(1)


@pytest.mark.slow  # one small DEM run (1 cell, 10 steady cycles)
def test_the_readme_python_api_block_runs(tmp_path, monkeypatch, capsys):
    (tmp_path / "data_samples").symlink_to(ROOT / "data_samples")
    monkeypatch.chdir(tmp_path)
    namespace: dict = {}
    exec(compile(_python_api_block(), "README.md (Python API)", "exec"), namespace)  # noqa: S102
    printed = capsys.readouterr().out.split()
    assert float(printed[0]) == namespace["records"][0].analysis.sdc
    # the same files through `pidcore analyze --json`: the same numbers, bit for bit
    from pidcore.cli import main

    files = [str(f) for f in namespace["files"]]
    assert main(["analyze", *files, "--velocity-delay", "5e-5", "--no-store", "--json"]) == 0
    cli = json.loads(capsys.readouterr().out)["records"]
    for record, printed_by_cli in zip(namespace["records"], cli, strict=True):
        for key in ("sdc", "sdc_stderr", "loss_factor", "energy_per_cycle_j", "frequency_hz"):
            assert record.analysis.to_dict()[key] == printed_by_cli[key], key
    low, high = namespace["prediction"].band(stderr=0.01)
    assert low <= namespace["prediction"].sdc <= high
    assert (tmp_path / "my_store.h5").is_file()
    table = namespace["table"]
    # every saved measurement is in the table, at its file name's load case (saved without
    # `stated` they had no fill: 'have no fill stated; not in the table', 0 measured rows)
    measured = table[table["SDC measured (Eq. 11) [-]"].notna()]
    assert sorted(measured["SDC measured (Eq. 11) [-]"]) == sorted(r.analysis.sdc
                                                          for r in namespace["records"])
    assert set(measured["packing ratio [%]"]) == {50.0}
    assert not any("no fill" in note for note in table.attrs.get("notes", []))
    assert namespace["run"].sdc > 0
    assert list(namespace["damper"]["c_eq_per_coupon [N s/m]"] > 0) == [True, True]


def test_the_refusals_the_python_api_section_promises():
    # the section said "wrong keywords ... are refused with a ParameterError": a misspelt
    # keyword is Python's own TypeError; a wrong value or type is a ParameterError naming
    # the keyword a script writes, not the CLI's flag
    from pidcore.dem import DemConfig
    from pidcore.errors import ParameterError
    from pidcore.measure import AnalysisOptions, analyze_file

    section = (ROOT / "README.md").read_text(encoding="utf-8").split("\n## Python API\n", 1)[1]
    assert "misspelt keyword with Python's own `TypeError`" in " ".join(section.split())
    with pytest.raises(TypeError, match="'velocity_delay'"):
        AnalysisOptions(velocity_delay=1e-4)
    with pytest.raises(ParameterError, match=r"^velocity_delay_s: expected a number, got 'abc'$"):
        AnalysisOptions(velocity_delay_s="abc")
    with pytest.raises(ParameterError, match=r"^cells: expected >= 1, got 0$"):
        DemConfig(cells=0)
    export = ROOT / "data_samples" / "exports" / "synthetic_f500Hz_a1g_fill50_acrylic.csv"
    with pytest.raises(ParameterError) as refused:
        analyze_file(export, AnalysisOptions(structure_mass_kg=5.0, baseline_loss_factor=0.01))
    assert "structure_mass_kg 5 kg" in str(refused.value)
    assert "--" not in str(refused.value)
