"""Accuracy table of the export variants of ``test_io_variants.py`` (not a test module).

Runs every variant test that reaches an analysis and prints, per variant, the loss factor, its
error over the issue's tolerance max(3 %, 1.5e-4), and the relative errors of the energy per
cycle and the acceleration amplitude. The variants whose test goes through the CLI first
(mass below gauge, inverted channel, bare names) are analysed here with the option the error
message asks for.

    PYTHONPATH=. python tests/_io_variants_table.py
"""

from __future__ import annotations

import inspect
import sys
import tempfile
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

import test_io_variants as tv  # noqa: E402

from pidcore.io import write_measurement  # noqa: E402
from pidcore.measure import AnalysisOptions, analyze_file  # noqa: E402
from pidcore.records import Channel, Measurement  # noqa: E402

ROWS: list[tuple[str, float, float, float, float]] = []
_CURRENT = [""]


def _record(name: str, analysis) -> None:
    lf, tol = analysis.loss_factor, max(0.03 * tv.LF, 1.5e-4)
    ROWS.append((name, lf, abs(lf - tv.LF) / tol, analysis.energy_per_cycle_j / tv.ENERGY - 1,
                 analysis.acceleration_amplitude_m_s2 / tv.A - 1))


def _run_variant_tests() -> None:
    original = tv._assert_truth

    def capture(analysis, **kw):
        _record(_CURRENT[0], analysis)
        original(analysis, **kw)

    tv._assert_truth = capture
    skip = ("memory", "head", "ctrl_c", "mass_below", "inverted", "unknown_units", "json",
            "non_utf8", "hdf5", "declared")
    for name, fn in inspect.getmembers(tv, inspect.isfunction):
        if not name.startswith("test_") or any(s in name for s in skip):
            continue
        cases: list[dict] = [{}]
        for mark in getattr(fn, "pytestmark", []):
            if mark.name == "parametrize":
                names = mark.args[0]
                names = [n.strip() for n in names.split(",")] if isinstance(names, str) else names
                cases = [dict(zip(names, v if isinstance(v, tuple) else (v,), strict=True))
                         for v in mark.args[1]]
        for case in cases:
            label = ",".join(str(v) for v in case.values())
            _CURRENT[0] = name[5:] + (f"[{label}]" if case else "")
            with tempfile.TemporaryDirectory() as d:
                fn(**case, tmp_path=Path(d))


def _run_cli_variants() -> None:
    with tempfile.TemporaryDirectory() as d:
        d = Path(d)
        rec = tv._record(mass=tv.M + 0.1, with_acceleration=True)
        t = np.arange(rec.force_n.size) / tv.FS
        path = d / "mass.csv"
        write_measurement(Measurement("x", (
            Channel("Force", "force", rec.force_n, tv.FS, "N"),
            Channel("LDV", "velocity", rec.velocity_m_s, tv.FS, "m/s"),
            Channel("Acc drive point", "acceleration", rec.acceleration_m_s2, tv.FS, "m/s^2"),
            Channel("Ref acc shaker", "acceleration", 1.3 * tv.A * np.cos(tv.W * t + 0.6),
                    tv.FS, "m/s^2"))), path)
        _record("mass_below_gauge + --acceleration 'Acc drive point'", analyze_file(
            path, AnalysisOptions(mass_below_gauge_kg=0.1, acceleration="Acc drive point")
        ).analysis)
        rec = tv._record()
        path = d / "inv.csv"
        write_measurement(Measurement("x", (
            Channel("Force", "force", rec.force_n, tv.FS, "N"),
            Channel("Velocity", "velocity", -rec.velocity_m_s, tv.FS, "m/s"))), path)
        _record("inverted velocity + --invert Velocity",
                analyze_file(path, AnalysisOptions(invert=("Velocity",))).analysis)
        path = d / "bare.csv"
        t = np.arange(rec.force_n.size) / tv.FS
        path.write_text("Time,Force,Velocity\n" + "".join(
            f"{a:.10g},{b:.10g},{c * 1e3:.10g}\n"
            for a, b, c in zip(t, rec.force_n, rec.velocity_m_s, strict=True)))
        _record("bare names + --force-unit N --velocity-unit mm/s", analyze_file(
            path, AnalysisOptions(force_unit="N", velocity_unit="mm/s")).analysis)


if __name__ == "__main__":
    _run_variant_tests()
    _run_cli_variants()
    print(f"{'variant':<62} {'loss factor':>11} {'|err|/tol':>9} {'dE err':>8} {'accel err':>9}")
    for name, lf, ratio, de, da in ROWS:
        print(f"{name[:62]:<62} {lf:11.6f} {ratio:9.3f} {de * 100:7.2f}% {da * 100:8.2f}%")
    print(f"truth loss factor {tv.LF:.6f}; {len(ROWS)} variants; worst |err|/tol "
          f"{max(r[2] for r in ROWS):.3f}")
