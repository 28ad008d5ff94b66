"""Result of a DEM load case: SDC, energy tallies, energy balance, virtual shaker record."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np
import pandas as pd

from .. import defaults
from ..constants import COUNT_UNIT, RATIO_UNIT, STANDARD_GRAVITY
from ..loop import ForceDisplacementLoop

if TYPE_CHECKING:  # pragma: no cover
    from ..signal import PowerAnalysis
    from ..specimen import Specimen
    from .contact import ContactLaw
    from .simulate import DemConfig, LoadCase

#: Unit of every scalar and array of :class:`DemResult`.
UNITS: dict[str, str] = {
    "sdc": RATIO_UNIT, "sdc_stderr": RATIO_UNIT, "sdc_stderr_dof": COUNT_UNIT,
    "loss_factor": RATIO_UNIT,
    "energy_per_cycle_j": "J", "energy_dissipated_normal_j": "J",
    "energy_dissipated_friction_j": "J", "energy_dissipated_rolling_j": "J",
    "max_kinetic_energy_j": "J", "work_per_cycle_j": "J",
    "stored_energy_change_per_cycle_j": "J",
    "particles_per_cell": COUNT_UNIT, "particles_full_cell": COUNT_UNIT,
    "cells_simulated": COUNT_UNIT,
    "vibrated_mass_kg": "kg", "coupon_mass_kg": "kg", "moving_mass_kg": "kg",
    "energy_balance_error": RATIO_UNIT, "steps": COUNT_UNIT,
    "wall_s": "s", "particle_steps_per_s": "1/s", "time_step_s": "s",
    "steady_start_cycle": COUNT_UNIT, "steady_cycles": COUNT_UNIT, "cycles_simulated": COUNT_UNIT,
    "settle_time_s": "s", "frequency_hz": "Hz", "acceleration_g": "g", "fill_percent": "%",
    "sdc_per_cell": RATIO_UNIT, "dissipation_per_cycle_j": "J", "sample_time_s": "s",
    "wall_force_n": "N", "shaker_force_n": "N", "velocity_m_s": "m/s",
    "sample_rate_hz": "Hz", "work_walls_j": "J", "dissipated_total_j": "J",
    "mechanical_energy_change_j": "J", "dissipation_per_cell_cycle_j": "J",
    "coupon_cells": COUNT_UNIT, "samples_per_cycle": COUNT_UNIT, "fixture_mass_kg": "kg",
    "particle_mass_kg": "kg", "alpha_pp": RATIO_UNIT, "alpha_pw": RATIO_UNIT,
}


@dataclass(frozen=True)
class DemResult:
    """Outcome of :func:`~pidcore.dem.simulate.simulate_load_case` (SI units, see UNITS).

    Coupon-level quantities scale the K-cell mean to the coupon's ``coupon_cells`` cells
    (the specimen's ``[cell] count``, 441 for the paper's). ``specimen`` is the
    :class:`~pidcore.specimen.Specimen` simulated (its canonical text and hash are stored with
    the run); ``moving_mass_kg`` is the rigid mass the shaker moves, coupon plus fixture
    (``coupon_mass_kg`` is the coupon alone, as in the specimen's ``[coupon] mass_kg``).
    ``energy_dissipated_normal_j`` / ``_friction_j`` / ``_rolling_j`` split
    ``energy_per_cycle_j`` (steady state, per cycle, coupon); ``work_per_cycle_j`` is the
    walls' work on the particles per steady cycle; it equals the dissipation plus
    ``stored_energy_change_per_cycle_j`` (the change of the particles' mechanical energy over
    the steady window divided by its cycles, e.g. a bed compacting).
    ``energy_balance_error`` is (W_walls - dE_mech - D) / W_walls over the whole driven run
    (all cells): ``work_walls_j``, ``mechanical_energy_change_j`` and ``dissipated_total_j``
    are these totals (the simulated cells, every driven cycle; not per cycle, not the
    coupon), with dE_mech = kinetic (incl. rotation) + gravity + elastic (Hertz and
    contact springs) energy change. ``particle_steps_per_s`` counts settling and driven steps
    over the time spent in the kernel (all threads), leaving out kernel calls that compiled
    Numba code (NaN when every call did, see :attr:`notes`); ``wall_s`` is the whole call,
    compilation included.

    ``dissipation_per_cycle_j`` (cycles,) is the coupon dissipation of every driven cycle;
    ``wall_force_n`` (samples,) the drive-axis force the walls exert on the particles of the
    coupon (interval means, 441 x cell mean), ``shaker_force_n`` = coupon mass x acceleration +
    ``wall_force_n`` (the force a shaker would measure), ``velocity_m_s`` the coupon velocity,
    all sampled at ``sample_rate_hz`` from the drive start.

    ``sdc_stderr`` is the scatter of the cells' SDCs (``std(ddof=1) / sqrt(K)``) with
    ``sdc_stderr_dof`` = K - 1; where the cells all ran one motion
    (:func:`cells_ran_one_motion`) it is the batch-means error of that motion's steady
    window (:func:`batch_means_stderr`, batches of ``config.block_cycles`` cycles, dof =
    batches - 1), NaN with fewer than DEM_MIN_STDERR_BATCHES batches or with batch means that
    agree (a periodic motion: no scatter to take an error from); so is a run of one cell
    (:func:`stderr_from_batches`). Runs stored before the degrees of freedom were kept read NaN
    (unknown).

    ``alpha_pp`` and ``alpha_pw`` are the damping constants of Eq. 2 the run used
    (particle-particle, particle-wall): Eq. 3's of the stated restitution, the config's
    override, or the ones ``damping_coefficient="calibrated"`` found; NaN for runs stored
    before they were kept.
    """

    case: LoadCase
    config: DemConfig
    sdc: float
    sdc_stderr: float
    sdc_per_cell: np.ndarray
    energy_per_cycle_j: float
    energy_dissipated_normal_j: float
    energy_dissipated_friction_j: float
    energy_dissipated_rolling_j: float
    work_per_cycle_j: float
    stored_energy_change_per_cycle_j: float
    max_kinetic_energy_j: float
    particles_per_cell: int
    particles_full_cell: int
    cells_simulated: int
    vibrated_mass_kg: float
    moving_mass_kg: float
    energy_balance_error: float
    work_walls_j: float
    dissipated_total_j: float
    mechanical_energy_change_j: float
    steps: int
    wall_s: float
    particle_steps_per_s: float
    time_step_s: float
    steady_start_cycle: int
    steady_detected: bool
    steady_cycles: int
    settle_time_s: float
    dissipation_per_cycle_j: np.ndarray
    dissipation_per_cell_cycle_j: np.ndarray
    sample_rate_hz: float
    sample_time_s: np.ndarray
    wall_force_n: np.ndarray
    shaker_force_n: np.ndarray
    velocity_m_s: np.ndarray
    samples_per_cycle: int
    specimen: Specimen | None = None
    coupon_cells: int = defaults.COUPON_CELLS
    sdc_stderr_dof: float = math.nan
    alpha_pp: float = math.nan
    alpha_pw: float = math.nan

    @classmethod
    def from_run(cls, *, case: LoadCase, config: DemConfig, law: ContactLaw,
                 tally: np.ndarray, wall_force: np.ndarray, steady_start_cycle: int,
                 steady_detected: bool, particles_per_cell: int, full_count: int,
                 vibrated_mass_kg: float, moving_mass_kg: float, dt_s: float, steps_per_cycle: int,
                 sample_every: int, energy_start: np.ndarray, energy_end: np.ndarray,
                 stored_energy_change_steady: np.ndarray,
                 settle_time_s: float, steps: int, wall_s: float, kernel_s: float,
                 particle_steps: int, specimen: Specimen | None = None) -> DemResult:
        """The result of one run's kernel tallies and wall forces (:func:`simulate_load_case`
        calls it): SDC per cell and its mean, energy split, energy balance and the virtual
        shaker record, scaled to the coupon's cells."""
        n_coupon = specimen.cell.count if specimen is not None else defaults.COUPON_CELLS
        k = tally.shape[0]
        steady = tally[:, steady_start_cycle:, :]
        # normal + friction + rolling (kernel tally columns 1, 2, 3)
        per_cell_cycle = tally[:, :, 1] + tally[:, :, 2] + tally[:, :, 3]
        e_max = vibrated_mass_kg * case.acceleration_m_s2**2 / (2 * case.omega_rad_s**2)
        per_cell = n_coupon * steady[:, :, 1:].sum(axis=2).mean(axis=1)  # coupon J / cycle
        sdc_cells = per_cell / e_max if e_max > 0 else np.full(k, np.nan)
        # cells that ran one motion (a lone particle bouncing along the drive axis touches no
        # side wall, so its random start xy does not matter) are one sample, not K: their
        # scatter of exactly 0 is no standard error (it printed "+- 0" for an unsettled
        # bouncer). That motion's own scatter over its steady window is: batch means of it
        # so is one cell: its scatter has no second value
        if stderr_from_batches(sdc_cells):
            stderr, stderr_dof = batch_means_stderr(
                _one_motion_sdc_per_cycle(per_cell_cycle, steady_start_cycle, n_coupon, e_max),
                config.block_cycles)
        elif k > 1:
            stderr = float(np.std(sdc_cells, ddof=1) / math.sqrt(k))
            stderr_dof = float(k - 1)
        else:
            stderr, stderr_dof = float("nan"), float("nan")
        work = float(tally[:, :, 0].sum())
        # friction and normal summed as before rolling existed (same rounding), rolling added
        dissipated = float(tally[:, :, 1:3].sum()) + float(tally[:, :, 3:].sum())
        d_mech = float(np.sum(energy_end[:, 3] - energy_start[:, 3]))
        scale = max(abs(work), dissipated, 1e-300)
        # virtual shaker record, sample interval j covers force evaluations at t=(step+1) dt
        spc = steps_per_cycle // sample_every
        n_s = wall_force.shape[1]
        h = sample_every * dt_s
        t0 = (np.arange(n_s) * sample_every + 0.5) * dt_s
        t1 = t0 + h
        a, w = case.acceleration_m_s2, case.omega_rad_s
        vel = -a / w**2 * (np.sin(w * t1) - np.sin(w * t0)) / h
        acc = a / w * (np.cos(w * t0) - np.cos(w * t1)) / h
        wall_n = n_coupon * wall_force.mean(axis=0)
        return cls(
            case=case, config=config, sdc=float(np.mean(sdc_cells)), sdc_stderr=stderr,
            sdc_per_cell=sdc_cells,
            energy_per_cycle_j=float(np.mean(per_cell)),
            energy_dissipated_normal_j=float(n_coupon * steady[:, :, 1].mean()),
            energy_dissipated_friction_j=float(n_coupon * steady[:, :, 2].mean()),
            energy_dissipated_rolling_j=float(n_coupon * steady[:, :, 3].mean()),
            work_per_cycle_j=float(n_coupon * steady[:, :, 0].mean()),
            stored_energy_change_per_cycle_j=float(
                n_coupon * np.mean(stored_energy_change_steady) / max(steady.shape[1], 1)),
            max_kinetic_energy_j=float(e_max),
            particles_per_cell=int(particles_per_cell), particles_full_cell=int(full_count),
            cells_simulated=int(k), vibrated_mass_kg=float(vibrated_mass_kg),
            moving_mass_kg=float(moving_mass_kg),
            energy_balance_error=float((work - d_mech - dissipated) / scale),
            work_walls_j=work, dissipated_total_j=dissipated, mechanical_energy_change_j=d_mech,
            steps=int(steps), wall_s=float(wall_s),
            particle_steps_per_s=float(particle_steps / kernel_s) if kernel_s > 0
            else float("nan"),
            time_step_s=float(dt_s), steady_start_cycle=int(steady_start_cycle),
            steady_detected=bool(steady_detected),
            steady_cycles=int(tally.shape[1] - steady_start_cycle),
            settle_time_s=float(settle_time_s),
            dissipation_per_cycle_j=n_coupon * per_cell_cycle.mean(axis=0),
            dissipation_per_cell_cycle_j=per_cell_cycle,
            sample_rate_hz=1.0 / h, sample_time_s=0.5 * (t0 + t1), wall_force_n=wall_n,
            shaker_force_n=moving_mass_kg * acc + wall_n, velocity_m_s=vel,
            samples_per_cycle=int(spc), specimen=specimen, coupon_cells=int(n_coupon),
            sdc_stderr_dof=stderr_dof, alpha_pp=float(law.pair_particle.alpha),
            alpha_pw=float(law.pair_wall.alpha),
        )

    @property
    def coupon_mass_kg(self) -> float:
        """The coupon alone (``[coupon] mass_kg``), kg: the fixture is in ``moving_mass_kg``."""
        if self.specimen is None:  # no specimen, no fixture: the rigid mass is the coupon
            return self.moving_mass_kg
        return self.specimen.coupon.mass_kg

    @property
    def notes(self) -> tuple[str, ...]:
        """What a reader of this run's numbers should know (not stored; derived from the run).

        * the steady window measured is longer than asked (``config.steady_cycles``, else
          DEM_MIN_STEADY_CYCLES): the kernel runs whole blocks of ``config.block_cycles``
          cycles, and the two blocks that detect the steady state both belong to the window;
        * the steady state was judged at the transient cap against the cycles' scatter
          (:func:`pidcore.dem.simulate._steady_by_scatter`), not by the block rule;
        * the run did not converge: the share of the dissipation the bed released from its
          stored energy over the window measured, and what that drift does to the SDC;
        * the energy balance closes worse than DEM_ENERGY_BALANCE_LIMIT: the energy left
          unaccounted for as an SDC, and whether the SDC is 0 to within it or not sound;
        * ``particle_steps_per_s`` was not measured (NaN): every kernel call compiled code;
        * a property of the specimen overrides its table material's
          (:func:`pidcore.specimen.table_overrides`);
        * the specimen's fixture is far heavier than its coupon, a likely g typed as kg
          (:func:`pidcore.specimen.heavy_fixture_note`: only `specimen check` said so, and a
          run of a 120 kg fixture on a 41 g coupon printed an SDC of 0.003 in silence), or its
          spheres fit the cell only one above another, a likely diameter typed as the radius
          (:func:`pidcore.specimen.column_note`);
        * the load case's fill overrides the fill or particle count the specimen states
          (:func:`pidcore.specimen.fill_override_note`);
        * the drive is above :data:`pidcore.defaults.DEM_NOTE_ACCELERATION_G` (m/s^2 typed
          for g?).
        """
        from ..specimen import (
            column_note,
            fill_override_note,
            heavy_fixture_note,
            table_overrides,
        )
        from .simulate import required_steady_cycles

        notes = []
        asked = required_steady_cycles(self.case, self.config)
        if self.steady_cycles > asked:
            b = self.config.block_cycles
            why = f"the DEM runs whole blocks of {b} cycles"
            if self.steady_detected:
                why += ", and the two blocks that detected the steady state are both measured"
            notes.append(f"steady window rounded up: {self.steady_cycles} cycles measured for "
                         f"the {asked} asked ({why})")
        b = self.config.block_cycles
        cap = -(-self.config.transient_cap_cycles(self.case.frequency_hz) // b) * b
        if self.steady_detected and self.steady_start_cycle == cap:
            # the block rule's start is at least two blocks before the cycle it is found at,
            # which is never past the cap: a steady start at the cap is the scatter rule's
            notes.append(
                f"steady state judged at the transient cap (cycle {cap}): no two successive "
                "blocks balanced the walls' work and the dissipation within "
                f"{defaults.DEM_STEADY_BALANCE_TOLERANCE:.0%}, but over the cycles before the "
                "cap the stored energy shows no trend and the dissipation no change against "
                "their scatter (docs/calibration.md, 'DEM runs that never reach a steady "
                "state')")
        released = released_share(self.work_per_cycle_j, self.energy_per_cycle_j)
        if not self.steady_detected and math.isfinite(released):
            notes.append(
                f"not converged: no steady state by the transient cap (measured from cycle "
                f"{self.steady_start_cycle}); over the {self.steady_cycles} cycles measured the "
                f"bed's stored energy {'fell' if released >= 0 else 'rose'} by "
                f"{abs(released):.1%} of the dissipation per cycle (walls' work "
                f"{self.work_per_cycle_j:.4g} J against {self.energy_per_cycle_j:.4g} J "
                f"dissipated per cycle): if that is a drift, the SDC is {released:+.1%} off "
                "the one the walls' work gives; where particles fly it is mostly noise "
                "(docs/calibration.md, 'DEM runs that never reach a steady state')")
        notes += self._balance_note()
        if not math.isfinite(self.particle_steps_per_s):
            notes.append("particle_steps_per_s not measured: every kernel call of this run "
                         "included Numba compilation (run again for the compiled speed)")
        if self.specimen is not None:
            notes += table_overrides(self.specimen)
            notes += heavy_fixture_note(self.specimen, self.particles_per_cell)
            notes += column_note(self.specimen, self.specimen.capacity_per_cell())
            overridden = fill_override_note(self.specimen, [self.case.fill_percent],
                                            self.config.fill_reference)
            if overridden:
                notes.append(f"{overridden}: {self.particles_per_cell} particles per cell "
                             "simulated")
        if stderr_from_batches(self.sdc_per_cell) and not np.any(self.sdc_per_cell):
            # an SDC of exactly 0 in every cell says nothing of their motions being one (5
            # elastic frictionless spheres were said to be "the same SDC to the last bit")
            notes.append(
                "no standard error: "
                + ("its one cell" if self.cells_simulated == 1 else
                   f"each of the {self.cells_simulated} cells")
                + " dissipated nothing (an SDC of exactly 0: no contact dissipates, as with "
                "elastic frictionless contacts), so there is no scatter to take an error from")
        elif stderr_from_batches(self.sdc_per_cell):
            same = ("its one cell is one motion, with no second cell to scatter against"
                    if self.cells_simulated == 1 else
                    f"the {self.cells_simulated} cells ran the same motion (the same SDC to "
                    "the last bit, as a lone particle bouncing along the drive axis does), so "
                    "they are one sample and their scatter says nothing of the SDC's "
                    "uncertainty")
            b = self.config.block_cycles
            batches = self.steady_cycles // b
            if math.isfinite(self.sdc_stderr):
                notes.append(
                    f"standard error from {batches} batches of {b} cycles of one motion, not "
                    f"from independent cells ({self.sdc_stderr_dof:g} degrees of freedom): "
                    f"{same}; successive batches of one motion are correlated, so this error "
                    "may understate the SDC's uncertainty")
            elif batches >= defaults.DEM_MIN_STDERR_BATCHES and self._batches_agree():
                notes.append(
                    f"no standard error: {same}, and its {batches} batches of {b} cycles "
                    "agree to rounding (a periodic motion): no scatter to take an error from. A "
                    "deterministic periodic steady state has no sampling error in its SDC, "
                    "but an error of 0 would read as a measured certainty; what the model "
                    "leaves out is not measured by this run")
            elif batches < defaults.DEM_MIN_STDERR_BATCHES:
                notes.append(
                    f"no standard error: {same}, and its steady window of "
                    f"{self.steady_cycles} cycles holds {batches} batches of {b} cycles, "
                    f"fewer than the {defaults.DEM_MIN_STDERR_BATCHES} a batch-means error "
                    "needs")
            else:  # a run stored before such runs got a batch-means error
                notes.append(f"no standard error: {same} (stored before pidcore took one from "
                             "batches of the motion's steady window)")
        g = self.case.acceleration_g
        if g > defaults.DEM_NOTE_ACCELERATION_G:
            notes.append(f"a {g:g} g drive, above the paper's 1-10 g: if it was typed in "
                         f"m/s^2, it is {g / STANDARD_GRAVITY:.3g} g")
        return tuple(notes)

    @property
    def loss_factor(self) -> float:
        """eta / (2 pi) (paper Sect. 3) [-]."""
        return self.sdc / (2 * math.pi)

    def steady_slice(self) -> slice:
        """Slice of the sample arrays covering the steady-state cycles."""
        return slice(self.steady_start_cycle * self.samples_per_cycle, None)

    def power_analysis(self, *, n_harmonics: int = defaults.N_HARMONICS) -> PowerAnalysis:
        """Virtual shaker test: :func:`pidcore.signal.analyze_power` of the steady record."""
        from ..signal import analyze_power

        sl = self.steady_slice()
        return analyze_power(self.shaker_force_n[sl], self.velocity_m_s[sl],
                             self.sample_rate_hz, frequency_hz=self.case.frequency_hz,
                             n_harmonics=n_harmonics)

    def to_dict(self, *, include_arrays: bool = False) -> dict[str, Any]:
        """JSON-safe dict: scalars (and arrays as lists when ``include_arrays``)."""
        out: dict[str, Any] = {
            "case_key": self.case.key,
            "frequency_hz": self.case.frequency_hz,
            "acceleration_g": self.case.acceleration_g,
            "fill_percent": self.case.fill_percent,
            "material": (self.specimen.particles.material if self.specimen is not None
                         else self.case.material),
            "direction": self.case.direction,
            "normal_damping_mode": self.config.normal_damping_mode,
            # eq3 or calibrated: beside the alphas, which of the two made them
            "damping_coefficient": self.config.damping_coefficient,
            "vibrated_mass_convention": self.config.vibrated_mass,
            "start_protocol": self.config.start_protocol,
            "start_packing": self.config.start_packing,
            "tangential_model": self.config.tangential_model,
            "fill_reference": self.config.fill_reference,
            "seed": self.config.seed,
            "coupon_cells": self.coupon_cells,
        }
        if self.specimen is not None:
            out.update({"specimen_name": self.specimen.name,
                        "specimen_sha256": self.specimen.hash,
                        "specimen_is_paper": self.specimen.is_paper(),
                        "tangential_stiffness_model":
                            self.specimen.pairs.tangential_stiffness_model,
                        "fixture_mass_kg": self.specimen.coupon.fixture_mass_kg,
                        "particle_mass_kg": self.specimen.particles.mass_kg})
        for name in ("sdc", "sdc_stderr", "sdc_stderr_dof", "loss_factor", "energy_per_cycle_j",
                     "work_per_cycle_j",
                     "stored_energy_change_per_cycle_j",
                     "energy_dissipated_normal_j", "energy_dissipated_friction_j",
                     "energy_dissipated_rolling_j", "max_kinetic_energy_j",
                     "particles_per_cell", "particles_full_cell",
                     "cells_simulated", "vibrated_mass_kg", "coupon_mass_kg", "moving_mass_kg",
                     "energy_balance_error",
                     "work_walls_j", "dissipated_total_j", "mechanical_energy_change_j",
                     "steps", "wall_s", "particle_steps_per_s", "time_step_s",
                     "steady_start_cycle", "steady_detected", "steady_cycles",
                     "settle_time_s", "sample_rate_hz", "samples_per_cycle",
                     "alpha_pp", "alpha_pw"):
            value = getattr(self, name)
            if isinstance(value, float) and not math.isfinite(value):
                value = None
            out[name] = value
        if include_arrays:
            for name in self.array_names():
                out[name] = np.asarray(getattr(self, name)).tolist()
        return out

    @staticmethod
    def array_names() -> tuple[str, ...]:
        """Names of the array fields (stored beside the scalars)."""
        return ("sdc_per_cell", "dissipation_per_cycle_j", "dissipation_per_cell_cycle_j",
                "sample_time_s", "wall_force_n", "shaker_force_n", "velocity_m_s")

    def arrays(self) -> dict[str, np.ndarray]:
        """The array fields by name (:meth:`array_names`)."""
        return {name: np.asarray(getattr(self, name)) for name in self.array_names()}

    def loop(self, n_points: int = defaults.LOOP_POINTS, *,
             n_harmonics: int = defaults.N_HARMONICS) -> ForceDisplacementLoop:
        """One period of the steady virtual shaker record's force-displacement loop.

        Built exactly as a measurement's (:func:`virtual_shaker_loop`), so the two loops'
        areas are comparable energies per cycle.
        """
        return virtual_shaker_loop(
            self.shaker_force_n, self.velocity_m_s, sample_rate_hz=self.sample_rate_hz,
            frequency_hz=self.case.frequency_hz, steady_start_cycle=self.steady_start_cycle,
            n_points=n_points, n_harmonics=n_harmonics, label=f"DEM {self.case.key}")

    def to_pandas(self) -> pd.DataFrame:
        """The virtual shaker record, one row per sample (SI units, each column names its unit).

        Columns ``time [s]`` (from the drive start), ``cycle [-]`` (the drive cycle the sample
        belongs to), ``steady [True/False]`` (in the steady window the SDC is measured over),
        ``shaker force [N]``, ``wall force [N]`` and ``velocity [m/s]`` (the coupon's). The
        frame's ``attrs`` hold the load case key, ``sdc``, ``sdc_stderr`` and
        ``sample_rate_hz``; the scalar results are :meth:`to_dict`'s, the per-cycle ones
        :attr:`dissipation_per_cycle_j`.
        """
        t = np.asarray(self.sample_time_s, dtype=float)
        cycle = np.arange(t.size) // max(self.samples_per_cycle, 1)
        frame = pd.DataFrame({
            "time [s]": t,
            "cycle [-]": cycle,
            "steady [True/False]": cycle >= self.steady_start_cycle,
            "shaker force [N]": np.asarray(self.shaker_force_n, dtype=float),
            "wall force [N]": np.asarray(self.wall_force_n, dtype=float),
            "velocity [m/s]": np.asarray(self.velocity_m_s, dtype=float),
        })
        frame.attrs.update(case_key=self.case.key, sdc=self.sdc, sdc_stderr=self.sdc_stderr,
                           sample_rate_hz=self.sample_rate_hz)
        return frame

    def _balance_note(self) -> list[str]:
        """A note where the energy balance closes worse than DEM_ENERGY_BALANCE_LIMIT: the
        energy left unaccounted for, as an SDC (spread over the cycles driven, scaled to the
        coupon as the SDC is), says whether the SDC is unsound or only 0 to within it (a bed
        that barely moves closes 1e-14 J to 77 %, and "closure error 77.30%" stood beside its
        SDC without a word)."""
        error = self.energy_balance_error
        if not (math.isfinite(error) and abs(error) > defaults.DEM_ENERGY_BALANCE_LIMIT):
            return []
        unaccounted = self.work_walls_j - self.mechanical_energy_change_j \
            - self.dissipated_total_j
        cycles = np.shape(self.dissipation_per_cell_cycle_j)[-1]
        scale = self.cells_simulated * cycles * self.max_kinetic_energy_j
        as_sdc = abs(unaccounted) * self.coupon_cells / scale if scale > 0 else math.inf
        said = (f"energy balance closure error {error:.2%}, above the "
                f"{defaults.DEM_ENERGY_BALANCE_LIMIT:.0%} limit: {abs(unaccounted):.3g} J of "
                f"the walls' work ({self.work_walls_j:.3g} J over the run) is neither stored "
                f"in the bed nor dissipated, as much as an SDC of {as_sdc:.3g} over the "
                f"{cycles} cycles driven")
        if as_sdc < defaults.DEM_NEGLIGIBLE_SDC:
            return [f"{said}: the SDC {self.sdc:.3g} is 0 to within that (the bed barely "
                    "moves at this drive), not a measured damping"]
        return [f"{said}: the SDC {self.sdc:.4g} is not sound; a shorter time step "
                "closes the balance"]

    def _batches_agree(self) -> bool:
        """Whether the batch means of cell 0's steady SDC per cycle agree
        (:func:`batch_means_agree`): why a one-motion run with batches enough has no error."""
        per_cycle = _one_motion_sdc_per_cycle(self.dissipation_per_cell_cycle_j,
                                              self.steady_start_cycle, self.coupon_cells,
                                              self.max_kinetic_energy_j)
        n = per_cycle.size // self.config.block_cycles
        if n < 2 or not np.all(np.isfinite(per_cycle[:n * self.config.block_cycles])):
            return False
        return batch_means_agree(_batch_means(per_cycle, self.config.block_cycles, n))

    def plot(self, ax: Any = None) -> Any:
        """Per-cycle dissipation and forces (:func:`pidcore.report.figures_results.plot_dem_run`).

        ``ax``: a pair of matplotlib axes, or None for a new figure. Returns the axes.
        """
        from ..report.figures_results import plot_dem_run  # lazy: drawing is optional

        return plot_dem_run(self, ax=ax)


def cells_ran_one_motion(sdc_per_cell: np.ndarray) -> bool:
    """Whether two or more cells gave the same SDC to the last bit: the same simulation."""
    sdc = np.asarray(sdc_per_cell, dtype=float)
    return sdc.size > 1 and bool(np.all(np.isfinite(sdc))) and float(np.ptp(sdc)) == 0.0


def released_share(work_per_cycle_j: float, dissipated_per_cycle_j: float) -> float:
    """The share of the dissipation per cycle a bed released from its stored energy over the
    cycles measured, 1 - work / dissipation: what a drift of that size puts the SDC off by (the
    steady dissipation is what the walls' work supplies). NaN where either is not finite or
    nothing was dissipated."""
    work, dissipated = float(work_per_cycle_j), float(dissipated_per_cycle_j)
    if not (math.isfinite(work) and math.isfinite(dissipated) and dissipated > 0):
        return math.nan
    return 1.0 - work / dissipated


def stderr_from_batches(sdc_per_cell: np.ndarray) -> bool:
    """Whether a run's SDC standard error is taken from batch means of one motion's steady
    window rather than its cells' scatter: it ran one cell, or its cells all ran one motion
    (:func:`cells_ran_one_motion`)."""
    return np.asarray(sdc_per_cell).size == 1 or cells_ran_one_motion(sdc_per_cell)


def batch_means_stderr(per_cycle: np.ndarray, batch_cycles: int, *,
                       min_batches: int = defaults.DEM_MIN_STDERR_BATCHES,
                       ) -> tuple[float, float]:
    """Standard error of the mean of ``per_cycle`` (one motion's SDC of each steady cycle) by
    batch means, and its degrees of freedom: the window cut into whole batches of
    ``batch_cycles`` cycles (a remainder at its end left out), ``std(batch means, ddof=1) /
    sqrt(batches)`` with batches - 1 degrees of freedom. (NaN, NaN) with fewer than
    ``min_batches`` batches or a non-finite cycle, and where the batch means agree
    (:func:`batch_means_agree`: a periodic motion whose period divides the batch has no scatter
    to take an error from, and an error of 0 would read as a measured certainty). Batches of a
    correlated motion are not independent: the error may be understated.

    >>> batch_means_stderr(np.array([1.0, 1.0, 2.0, 2.0, 3.0, 3.0, 4.0, 4.0]), 2)
    (0.6454972243679028, 3.0)
    """
    from ..errors import ParameterError

    values = np.asarray(per_cycle, dtype=float)
    if batch_cycles < 1:
        raise ParameterError(f"batch_cycles {batch_cycles!r}: expected an integer >= 1")
    n = values.size // batch_cycles
    if n < max(min_batches, 2) or not np.all(np.isfinite(values[:n * batch_cycles])):
        return float("nan"), float("nan")
    means = _batch_means(values, batch_cycles, n)
    if batch_means_agree(means):
        return float("nan"), float("nan")
    return float(np.std(means, ddof=1) / math.sqrt(n)), float(n - 1)


def _one_motion_sdc_per_cycle(dissipation_per_cell_cycle_j: np.ndarray, steady_start_cycle: int,
                              coupon_cells: int, e_max_j: float) -> np.ndarray:
    """The SDC of each steady cycle of the first cell (the one motion of
    :func:`stderr_from_batches`): its dissipation scaled to the coupon's cells over E of
    Eq. 10; NaN where E is not positive."""
    per_cycle = np.asarray(dissipation_per_cell_cycle_j, dtype=float)[0, steady_start_cycle:]
    if not e_max_j > 0:
        return np.full(per_cycle.size, np.nan)
    return coupon_cells * per_cycle / e_max_j


def _batch_means(values: np.ndarray, batch_cycles: int, n: int) -> np.ndarray:
    return values[:n * batch_cycles].reshape(n, batch_cycles).mean(axis=1)


def batch_means_agree(means: np.ndarray,
                      rtol: float = defaults.DEM_BATCHES_AGREE_RTOL) -> bool:
    """Whether batch means agree to rounding (spread <= ``rtol`` x their largest magnitude):
    a periodic motion whose period divides the batch, whose scatter is no error."""
    means = np.asarray(means, dtype=float)
    return float(np.ptp(means)) <= rtol * float(np.max(np.abs(means)))


def virtual_shaker_loop(force_n: np.ndarray, velocity_m_s: np.ndarray, *,
                        sample_rate_hz: float, frequency_hz: float,
                        steady_start_cycle: float = 0,
                        n_points: int = defaults.LOOP_POINTS,
                        n_harmonics: int = defaults.N_HARMONICS,
                        label: str = "DEM") -> ForceDisplacementLoop:
    """Force-displacement loop of a DEM run's virtual shaker record (arrays in SI units).

    The record from ``steady_start_cycle`` on goes through the same harmonic analysis as a
    measurement (:func:`pidcore.signal.analyze_power`); a short record (fewer than
    :data:`pidcore.defaults.MIN_PERIODS` steady cycles, at least 2) is accepted with fewer
    uncertainty blocks, as the loop needs no standard error.

    Raises
    ------
    ParameterError
        Arrays of different shapes, or fewer than 2 steady cycles.
    SignalError
        The record cannot be analysed (no dominant drive frequency).
    """
    from ..errors import ParameterError
    from ..signal import analyze_power

    force = np.asarray(force_n, dtype=np.float64)
    velocity = np.asarray(velocity_m_s, dtype=np.float64)
    if force.ndim != 1 or force.shape != velocity.shape:
        raise ParameterError(f"{label}: force and velocity records differ in shape "
                             f"({force.shape} vs {velocity.shape})")
    per_cycle = float(sample_rate_hz) / float(frequency_hz)
    start = int(round(float(steady_start_cycle or 0) * per_cycle))
    cycles = int((force.size - start) / per_cycle)
    if cycles < 2:
        raise ParameterError(f"{label}: {cycles} steady cycles in the virtual shaker record, "
                             "expected at least 2")
    analysis = analyze_power(force[start:], velocity[start:], float(sample_rate_hz),
                             frequency_hz=float(frequency_hz), n_harmonics=n_harmonics,
                             min_periods=min(defaults.MIN_PERIODS, cycles),
                             n_blocks=max(2, min(defaults.N_UNCERTAINTY_BLOCKS, cycles)),
                             source=label,
                             # the loop is force against displacement: it divides by no
                             # reactive power, so a record that stores no kinetic energy
                             # (a pure damper) still has one
                             require_mass_like=False)
    return analysis.loop(n_points)
