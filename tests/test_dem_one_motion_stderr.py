"""A DEM run whose cells all ran one motion takes its SDC's standard error from batch means of
that motion's steady window (its cells' scatter is exactly 0: one sample, not K); a run whose
cells differ keeps the cells' scatter, bit for bit."""

from __future__ import annotations

import dataclasses
import math
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from pidcore.cli.dem import format_summary
from pidcore.compare.align import dem_cases
from pidcore.dem.contact import ContactLaw, damping_constant_from_restitution
from pidcore.dem.persist import load_dem_result, save_dem_result
from pidcore.dem.result import DemResult, batch_means_agree, batch_means_stderr
from pidcore.dem.simulate import DemConfig, simulate_load_case
from pidcore.errors import ParameterError
from pidcore.loadcase import LoadCase
from pidcore.specimen import Specimen, describe
from pidcore.store import Store

STEEL = Path(__file__).resolve().parents[1] / "data_samples" / "specimens" / "steel_6mm.toml"
COUPON_CELLS = 441  # the paper's coupon: from_run without a specimen scales to it

# five batches of two cycles: means 0.2, 0.3, 0.25, 0.35, 0.3 (each cycle +- 0.05 about its
# batch's mean, which batch means average out). By hand: mean 0.28, squared deviations sum to
# 0.013, sample variance 0.00325, stderr sqrt(0.00325 / 5) = sqrt(0.00065), 4 dof
BATCH_MEANS = np.array([0.2, 0.3, 0.25, 0.35, 0.3])
SDC_PER_CYCLE = np.repeat(BATCH_MEANS, 2) + np.tile([-0.05, 0.05], 5)
STDERR = math.sqrt(0.00065)


def test_batch_means_stderr_is_the_analytic_one():
    stderr, dof = batch_means_stderr(SDC_PER_CYCLE, 2)
    assert stderr == pytest.approx(STDERR, rel=1e-12)  # a few roundings of numbers near 0.3
    assert dof == 4.0
    # a remainder shorter than a batch is left out, not a sixth batch of one cycle
    assert batch_means_stderr(np.append(SDC_PER_CYCLE, 9.0), 2) == (stderr, dof)
    # three batches are too few: no error, as before
    assert all(math.isnan(v) for v in batch_means_stderr(SDC_PER_CYCLE[:6], 2))
    with pytest.raises(ParameterError, match="batch_cycles 0"):
        batch_means_stderr(SDC_PER_CYCLE, 0)


def _from_tally(sdc_cell_cycle: np.ndarray, *, transient: int, block_cycles: int) -> DemResult:
    """A DemResult of a tally whose steady cycles dissipate ``sdc_cell_cycle`` (K, cycles) in
    SDC units, after ``transient`` cycles of wild dissipation that must not count."""
    case = LoadCase(100.0, 5.0, 50.0, "acrylic")
    k, cycles = sdc_cell_cycle.shape
    m_c = 0.01
    e_max = m_c * case.acceleration_m_s2**2 / (2 * case.omega_rad_s**2)
    tally = np.zeros((k, transient + cycles, 4))
    tally[:, :transient, 1] = 50.0 * e_max / COUPON_CELLS
    tally[:, transient:, 1] = sdc_cell_cycle * e_max / COUPON_CELLS
    tally[:, :, 0] = tally[:, :, 1]  # the walls' work supplies the dissipation
    spc = 4
    return DemResult.from_run(
        case=case, config=DemConfig(cells=k, block_cycles=block_cycles),
        law=ContactLaw.for_material("acrylic"),  # its damping alphas are recorded
        tally=tally, wall_force=np.zeros((k, (transient + cycles) * spc)),
        steady_start_cycle=transient, steady_detected=True, particles_per_cell=1,
        full_count=23, vibrated_mass_kg=m_c, moving_mass_kg=0.1, dt_s=1e-2 / spc,
        steps_per_cycle=spc, sample_every=1, energy_start=np.zeros((k, 4)),
        energy_end=np.zeros((k, 4)), stored_energy_change_steady=np.zeros(k),
        settle_time_s=0.0, steps=(transient + cycles) * spc, wall_s=1.0, kernel_s=1.0,
        particle_steps=1)


def test_cells_of_one_motion_get_the_batch_means_error_of_their_window():
    result = _from_tally(np.tile(SDC_PER_CYCLE, (3, 1)), transient=4, block_cycles=2)
    assert result.sdc == pytest.approx(0.28, rel=1e-12)  # the transient is not measured
    # the same numbers scaled by e_max / 441 and back: a few roundings
    assert result.sdc_stderr == pytest.approx(STDERR, rel=1e-9)
    assert result.sdc_stderr_dof == 4.0  # batches - 1, not cells - 1 = 2
    note = next(n for n in result.notes if n.startswith("standard error from"))
    assert "5 batches of 2 cycles of one motion, not from independent cells" in note
    assert "4 degrees of freedom" in note
    assert "may understate" in note
    # three batches are too few: no error, as before, and the note says why
    short = _from_tally(np.tile(SDC_PER_CYCLE[:6], (3, 1)), transient=4, block_cycles=2)
    assert math.isnan(short.sdc_stderr) and math.isnan(short.sdc_stderr_dof)
    assert any("holds 3 batches of 2 cycles, fewer than the 4" in n for n in short.notes)
    # such a run stored before batch means existed (no error kept) is not said to be short
    older = dataclasses.replace(result, sdc_stderr=math.nan, sdc_stderr_dof=math.nan)
    assert any("stored before pidcore took one from batches" in n for n in older.notes)


@pytest.mark.parametrize("cells", [1, 2])
def test_cells_that_dissipate_nothing_are_not_said_to_run_one_motion(cells):
    """Five elastic frictionless spheres per cell were said to be "the same motion (the same
    SDC to the last bit ...)": their cells only shared an SDC of 0."""
    result = _from_tally(np.zeros((cells, 10)), transient=4, block_cycles=2)
    assert result.sdc == 0.0 and math.isnan(result.sdc_stderr)
    notes = " ".join(result.notes)
    assert "same motion" not in notes and "one motion" not in notes
    assert "dissipated nothing (an SDC of exactly 0" in notes
    # and the damping constant of e = 1 is 0, not "-0"
    elastic = dataclasses.replace(result, alpha_pp=damping_constant_from_restitution(1.0),
                                  alpha_pw=damping_constant_from_restitution(1.0))
    assert "alpha of Eq. 2 0 particle-particle, 0 particle-wall" in format_summary(elastic)


def test_cells_that_differ_keep_their_scatter_bit_for_bit():
    cells = np.tile(SDC_PER_CYCLE, (3, 1)) * np.array([[1.0], [1.1], [0.95]])
    result = _from_tally(cells, transient=4, block_cycles=2)
    # the expression used before batch means existed, on the same per-cell SDCs
    assert result.sdc_stderr == float(np.std(result.sdc_per_cell, ddof=1) / math.sqrt(3))
    assert result.sdc_stderr_dof == 2.0
    assert not any("batches" in n for n in result.notes)


def test_one_sphere_per_cell_run_gets_a_finite_stderr_that_survives_the_store(tmp_path):
    # one steel sphere per cell driven along z touches no side wall: both cells run one motion
    text = STEEL.read_text().replace("fill_percent = 50.0", "count_per_cell = 1")
    lone = Specimen.from_text(text)
    config = DemConfig(cells=2, steady_cycles=8, block_cycles=2, max_transient_cycles=2)
    result = simulate_load_case(
        LoadCase(200.0, 5.0, 100.0 / describe(lone)["capacity_per_cell"], "steel"), config,
        specimen=lone)
    assert result.particles_per_cell == 1
    assert result.sdc_per_cell[0] == result.sdc_per_cell[1] > 0  # the same motion
    batches = result.steady_cycles // 2
    assert batches >= 4
    assert math.isfinite(result.sdc_stderr) and result.sdc_stderr_dof == batches - 1
    # the error from the stored per-cycle dissipation, batched here by hand
    per_cycle = result.dissipation_per_cell_cycle_j[0, result.steady_start_cycle:]
    sdc_cycles = result.coupon_cells * per_cycle / result.max_kinetic_energy_j
    means = sdc_cycles[:batches * 2].reshape(batches, 2).mean(axis=1)
    # the kernel's tally columns summed in another order: rounding only
    assert result.sdc_stderr == pytest.approx(np.std(means, ddof=1) / math.sqrt(batches),
                                              rel=1e-9)

    store = Store(tmp_path / "runs.h5")
    key = save_dem_result(store, result)
    again = load_dem_result(store.get_dem_run(key))
    assert (again.sdc_stderr, again.sdc_stderr_dof) == (result.sdc_stderr, result.sdc_stderr_dof)
    runs = store.list_dem_runs()
    assert dem_cases(runs)[0].sdc_stderr_dof == batches - 1  # the stored one, not cells - 1
    # a run stored before the degrees of freedom were kept reads as before: cells - 1
    assert dem_cases(runs.drop(columns="sdc_stderr_dof"))[0].sdc_stderr_dof == 1.0


def test_one_cell_gets_the_batch_means_error_of_its_window():
    # one cell is one motion: the same batch-means error as K cells of one motion (it had none)
    result = _from_tally(SDC_PER_CYCLE[None, :], transient=4, block_cycles=2)
    assert result.cells_simulated == 1
    assert result.sdc_stderr == pytest.approx(STDERR, rel=1e-9)  # as for 3 cells, above
    assert result.sdc_stderr_dof == 4.0  # batches - 1 (cells - 1 would be 0)
    note = next(n for n in result.notes if n.startswith("standard error from"))
    assert "5 batches of 2 cycles of one motion, not from independent cells" in note
    assert "its one cell is one motion" in note
    summary = format_summary(result)
    assert "(stderr from batches of one motion: see the note)" in summary
    assert "[-]) over 1 cell (stderr" in summary  # one cell, not "1 cells"
    # three batches are too few: none, and the note says why
    short = _from_tally(SDC_PER_CYCLE[None, :6], transient=4, block_cycles=2)
    assert math.isnan(short.sdc_stderr) and math.isnan(short.sdc_stderr_dof)
    assert any("its one cell is one motion" in n and "holds 3 batches of 2 cycles" in n
               for n in short.notes)


def _runs(sdcs, stderrs, dofs) -> pd.DataFrame:
    n = len(sdcs)
    return pd.DataFrame({"frequency_hz": [100.0] * n, "acceleration_g": [5.0] * n,
                         "fill_percent": [50.0] * n, "material": ["acrylic"] * n,
                         "direction": ["z"] * n, "sdc": sdcs, "sdc_stderr": stderrs,
                         "sdc_stderr_dof": dofs, "cells_simulated": [1] * n})


def test_one_cell_runs_are_pooled_with_their_stored_dof():
    # one 1-cell run: its own error and batches - 1 (cells - 1 = 0 is no dof at all)
    (case,) = dem_cases(_runs([0.28], [STDERR], [4.0]))
    assert (case.sdc, case.sdc_stderr, case.sdc_stderr_dof) == (0.28, STDERR, 4.0)
    # two of equal error whose means lie within it: Welch-Satterthwaite of the stored dofs,
    # (2 se^2)^2 / (2 se^4 / 4) = 8 exactly in theory; rounding of se^2, se^4 only
    (pooled,) = dem_cases(_runs([0.28, 0.2801], [STDERR, STDERR], [4.0, 4.0]))
    assert pooled.sdc_stderr_dof == pytest.approx(8.0, rel=1e-12)


PERIODIC = np.tile([0.2, 0.4], 5)  # period 2 cycles = one batch: every batch mean is 0.3


@pytest.mark.parametrize("cells", [1, 3])
def test_a_periodic_motion_has_no_error_not_an_error_of_zero(cells):
    assert all(math.isnan(v) for v in batch_means_stderr(PERIODIC, 2))  # it was (0.0, 4.0)
    result = _from_tally(np.tile(PERIODIC, (cells, 1)), transient=4, block_cycles=2)
    assert result.sdc == pytest.approx(0.3, rel=1e-12)
    assert math.isnan(result.sdc_stderr) and math.isnan(result.sdc_stderr_dof)
    note = next(n for n in result.notes if n.startswith("no standard error"))
    assert ("5 batches of 2 cycles agree to rounding (a periodic motion): no scatter to take "
            "an error from") in note
    summary = format_summary(result)
    assert "+- 0" not in summary and "no standard error (see the note)" in summary
    # a period that does not divide the batch (3 cycles in batches of 2) scatters: an error
    odd = _from_tally(np.tile([0.2, 0.3, 0.4], (cells, 4)), transient=4, block_cycles=2)
    assert odd.sdc_stderr > 0 and odd.sdc_stderr_dof == 5.0


def test_batch_means_agree_to_rounding_only():
    assert not batch_means_agree(np.array([0.3, 0.3 * (1 + 1e-8)]))  # above rounding: scatter
    assert batch_means_agree(np.array([0.3, 0.3 * (1 + 1e-12)]))  # rounding of the tally
    assert batch_means_agree(np.zeros(4))  # nothing dissipated: no scatter either


@pytest.mark.parametrize(("sdc", "stderr", "shown"), [
    (0.01234, 0.00056, "0.01234 ± 0.00056"), (4.09, 0.2, "4.09 ± 0.20")])
def test_summary_writes_the_sdc_with_its_error_as_the_app_does(sdc, stderr, shown):
    """``dem run`` printed 4.09 +- 0.2 where the app's Compare heading showed the same run's
    SDC by its own rule: one rule (:func:`pidcore.units.display_value_with_error`)."""
    from dataclasses import replace

    from pidcore.app.uploads import format_sdc

    result = replace(_from_tally(SDC_PER_CYCLE[None, :], transient=4, block_cycles=2),
                     sdc=sdc, sdc_stderr=stderr)
    assert f"SDC             {shown} [-] (loss factor" in format_summary(result)
    assert format_sdc(sdc, stderr) == shown
