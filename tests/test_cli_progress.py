"""Long commands on a terminal and off it: a progress bar only where one can be drawn, a re-run
that says what it reused, and a dask scheduler address refused in one line."""

from __future__ import annotations

import re
import sys

import pytest

from pidcore.cli import main
from pidcore.store import Store

# one tiny case: the bar's drawing is under test, not the physics
SWEEP = ["dem", "sweep", "--frequencies", "1000", "--accelerations", "5", "--fills", "25",
         "--cells", "1", "--cycles", "2", "--workers", "1"]
# a calibration that needs one DEM run per load case (no DEM parameter fitted)
CALIBRATION_ROWS = "frequency_hz,acceleration_g,fill_percent,sdc\n" \
                   "500,5,50,0.6\n1000,5,50,0.6\n1000,10,50,0.3\n"
CALIBRATE = ["calibrate", "--fit", "fixture_mass_kg", "--cells", "2", "--steady-cycles", "10",
             "--workers", "1"]


def _on_a_terminal(monkeypatch, yes: bool) -> None:
    """stderr (pytest's capture) as a terminal or, as captured, not one."""
    monkeypatch.setattr(sys.stderr, "isatty", lambda: yes, raising=False)


def _bar_drawn(err: str) -> bool:
    # tqdm redraws with carriage returns; its rate and ETA field is "[00:00<..."
    return "\r" in err or "<?" in err or "it/s" in err


@pytest.mark.parametrize("terminal", [False, True])
def test_sweep_draws_its_bar_only_on_a_terminal(tmp_path, capsys, monkeypatch, terminal):
    """`pidcore dem sweep ... 2> log` wrote every redraw of the bar into the log as one line
    of carriage returns (dem run drew none there; sweep and calibrate did)."""
    _on_a_terminal(monkeypatch, terminal)
    assert main([*SWEEP, "--store", str(tmp_path / "s.h5")]) == 0
    err = capsys.readouterr().err
    assert _bar_drawn(err) == terminal, repr(err)
    if terminal:
        assert "DEM sweep" in err
    _on_a_terminal(monkeypatch, True)  # --no-progress: none on a terminal either
    assert main([*SWEEP, "--store", str(tmp_path / "t.h5"), "--no-progress"]) == 0
    assert not _bar_drawn(capsys.readouterr().err)


def test_calibrate_draws_no_bar_off_a_terminal_and_says_a_rerun_reused_its_runs(
        tmp_path, capsys, monkeypatch):
    table = tmp_path / "m.csv"
    table.write_text(CALIBRATION_ROWS)
    store = tmp_path / "dem.h5"
    argv = [*CALIBRATE, "--data", str(table), "--dem-store", str(store)]
    _on_a_terminal(monkeypatch, False)
    assert main(argv) == 0
    first = capsys.readouterr()
    assert not _bar_drawn(first.err), repr(first.err)
    assert f"DEM runs: 3 computed, 0 reused from {store}" in first.out
    runs = set(Store(store).list_dem_runs()["case_key"])
    _on_a_terminal(monkeypatch, True)
    assert main(argv) == 0
    again = capsys.readouterr()
    # the re-run computed nothing (the store holds the same runs) and says so
    assert f"DEM runs: 0 computed, 3 reused from {store}" in again.out
    assert set(Store(store).list_dem_runs()["case_key"]) == runs
    # with --json, said on stderr (stdout holds the one document)
    assert main([*argv, "--json", "--no-progress"]) == 0
    assert f"note: DEM runs: 0 computed, 3 reused from {store}" in capsys.readouterr().err
    # everything else it printed is the first run's, number for number (the calibration
    # itself: saved by the first, found stored already by the second)
    def result_lines(out: str) -> list[str]:
        return [line for line in out.splitlines()
                if not line.startswith(("DEM runs:", "saved calibration", "calibration cal_"))]

    assert result_lines(again.out) == result_lines(first.out)
    assert "saved calibration cal_" in first.out and "already (the same result)" in again.out


@pytest.mark.parametrize("address", ["", "  "])
def test_an_empty_scheduler_address_is_refused_not_run_locally(tmp_path, capsys, address):
    """`--scheduler "$SCHEDULER"` with the variable unset ran every case on local processes
    without a word."""
    store = tmp_path / "s.h5"
    with pytest.raises(SystemExit) as refused:  # a usage error: argparse exits
        main([*SWEEP, "--no-progress", "--scheduler", address, "--store", str(store)])
    assert refused.value.code == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "--scheduler" in err[0] and "tcp://host:8786" in err[0], err
    assert not store.exists()


def test_a_scheduler_address_dask_cannot_use_is_one_line_exit_2(tmp_path, capsys):
    """tls:// without a TLS configuration raised a TypeError inside distributed: a 40-line
    traceback and exit 1."""
    pytest.importorskip("distributed")
    store = tmp_path / "s.h5"
    # without --workers, which is refused beside --scheduler
    code = main([*SWEEP[:-2], "--no-progress", "--scheduler", "tls://127.0.0.1:1",
                 "--store", str(store)])
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 2
    assert len(err) == 1 and "--scheduler tls://127.0.0.1:1" in err[0], err
    assert not store.exists()


@pytest.mark.parametrize("terminal", [False, True])
def test_bench_dem_grid_draws_its_sweep_bar_only_on_a_terminal(monkeypatch, capsys, terminal):
    """`pidcore bench dem --grid > log 2>&1` filled the log with the grid sweep's redraws."""
    import pidcore.dem.bench
    import pidcore.dem.sweep
    from pidcore.dem.sweep import SweepSummary

    asked: list[bool] = []

    def sweep(cases, config, *, progress, **kwargs):
        asked.append(progress)
        return SweepSummary(wall_s=1.0)

    bed = {"particle_steps_per_s": 1.0, "particle_steps_per_s_cpu": 1.0,
           "reference_particle_steps_per_s": 1.0}
    monkeypatch.setattr(pidcore.dem.bench, "run_dem_bench", lambda **kwargs: bed)
    monkeypatch.setattr(pidcore.dem.sweep, "run_sweep", sweep)
    _on_a_terminal(monkeypatch, terminal)
    assert main(["bench", "dem", "--repeat", "1", "--grid", "--json"]) == 0
    assert main(["bench", "dem", "--repeat", "1", "--grid", "--json", "--no-progress"]) == 0
    assert asked == [terminal, False]


@pytest.mark.parametrize("terminal", [False, True])
def test_analyze_shows_a_bar_over_many_files_only_on_a_terminal(capsys, monkeypatch,
                                                                 terminal):
    """Forty exports took 7-12 s (a 5 M-sample export alone 2.6 s to read) with nothing on
    the screen until the table."""
    from pathlib import Path

    exports = sorted(str(p) for p in (Path(__file__).resolve().parents[1] / "data_samples"
                                      / "exports").iterdir() if p.suffix in (".csv", ".uff"))
    assert len(exports) >= 2
    _on_a_terminal(monkeypatch, terminal)
    # each file made to take longer than tqdm's 0.1 s between redraws: on a fast machine the
    # three samples finished inside one interval and no "n/3" was ever drawn (a flaky test)
    import time

    import pidcore.file_settings

    analyze_one = pidcore.file_settings.analyze_with_settings

    def slow(*args, **kwargs):
        time.sleep(0.15)
        return analyze_one(*args, **kwargs)

    monkeypatch.setattr(pidcore.file_settings, "analyze_with_settings", slow)
    assert main(["analyze", *exports, "--no-store"]) == 0
    err = capsys.readouterr().err
    assert _bar_drawn(err) == terminal, repr(err)
    if terminal:
        # the files to do, then files done (tqdm skips redraws closer than 0.1 s: which)
        assert f"0/{len(exports)}" in err and "analysing" in err, repr(err)
        assert re.search(rf"\b[1-9]\d*/{len(exports)}\b", err), repr(err)
    assert main(["analyze", *exports, "--no-store", "--no-progress"]) == 0
    assert not _bar_drawn(capsys.readouterr().err)


@pytest.mark.parametrize("terminal", [False, True])
def test_report_asks_for_bars_only_on_a_terminal(tmp_path, monkeypatch, terminal):
    import pidcore.report.pipeline

    asked: list[bool] = []

    def report(files, *, progress, **kwargs):
        asked.append(progress)
        raise KeyboardInterrupt  # enough: what it was asked is recorded

    monkeypatch.setattr(pidcore.report.pipeline, "make_report", report)
    _on_a_terminal(monkeypatch, terminal)
    argv = ["report", "--dem-store", str(tmp_path / "none.h5"), "--out", str(tmp_path / "r")]
    assert main(argv) == 130
    assert main([*argv, "--no-progress"]) == 130
    assert asked == [terminal, False]


def test_ctrl_c_during_analyze_clears_the_bar_before_its_one_line(capsys, monkeypatch):
    """The interrupted line was printed after the half-drawn bar on the same line, and the
    bar was cleared only afterwards (when collected), wiping it from the terminal."""
    from pathlib import Path

    import pidcore.file_settings

    exports = sorted(str(p) for p in (Path(__file__).resolve().parents[1] / "data_samples"
                                      / "exports").iterdir() if p.suffix in (".csv", ".uff"))
    real = pidcore.file_settings.analyze_with_settings
    seen: list[str] = []

    def second_interrupted(path, settings, **kwargs):
        seen.append(path)
        if len(seen) == 2:
            raise KeyboardInterrupt
        return real(path, settings, **kwargs)

    monkeypatch.setattr(pidcore.file_settings, "analyze_with_settings", second_interrupted)
    _on_a_terminal(monkeypatch, True)
    assert main(["analyze", *exports, "--no-store"]) == 130
    err = capsys.readouterr().err
    # what the terminal shows last: the bar's line cleared, then the one line
    last = err.split("\r")[-1]
    assert last.strip() == "pidcore analyze: interrupted; nothing saved (--no-store)", repr(err)
    assert "analysing" in err


@pytest.mark.parametrize("terminal", [False, True])
def test_bench_dem_shows_its_beds_only_on_a_terminal(monkeypatch, capsys, terminal):
    """`pidcore bench dem --repeat 1` measured its five beds for ~40 s with nothing shown."""
    import pidcore.dem.bench

    bed = {"particle_steps_per_s": 1.0, "particle_steps_per_s_cpu": 1.0,
           "reference_particle_steps_per_s": 1.0}
    monkeypatch.setattr(pidcore.dem.bench, "run_dem_bench", lambda **kwargs: bed)
    _on_a_terminal(monkeypatch, terminal)
    assert main(["bench", "dem", "--repeat", "1", "--json"]) == 0
    err = capsys.readouterr().err
    assert ("DEM beds" in err and "0/5" in err) == terminal, repr(err)
    assert _bar_drawn(err) == terminal


def test_ctrl_c_as_calibrate_prints_says_what_it_saved_and_wrote(tmp_path, capsys,
                                                                 monkeypatch):
    """A Ctrl-C after the DEM runs and --out were written, as the result printed, got the
    generic line: --out "may hold part of this run's files" (it was written whole) and no
    word of the runs saved."""
    import pidcore.cli.calibrate as calibrate_cli

    table = tmp_path / "m.csv"
    table.write_text(CALIBRATION_ROWS)
    store, out = tmp_path / "dem.h5", tmp_path / "cal"

    def interrupted(*args, **kwargs):
        raise KeyboardInterrupt

    monkeypatch.setattr(calibrate_cli, "_print_result", interrupted)
    assert main([*CALIBRATE, "--data", str(table), "--dem-store", str(store), "--out", str(out),
                 "--no-progress"]) == 130
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1, err
    assert f"3 DEM run(s) finished before the interrupt are saved in {store}" in err[0]
    assert err[0].endswith(f"; {out} was written in full"), err
