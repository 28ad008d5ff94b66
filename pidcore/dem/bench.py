"""Throughput benchmark of the DEM kernel (particle-steps per second on one core)."""

from __future__ import annotations

import dataclasses
import math
import time

import numpy as np

from .. import defaults
from .contact import LAW_DAMPING, LAW_SLIDING, LAW_STIFFNESS, ContactLaw
from .geometry import CellGeometry, random_packing
from .simulate import LoadCase, choose_time_step, settle_bed
from .state import CellsState, KernelSettings, advance


def run_dem_bench(*, particles_per_cell: int = 20, cells: int = 8, steps: int = 20000,
                  threads: int = 1, frequency_hz: float = 100.0, acceleration_g: float = 5.0,
                  material: str = "acrylic", seed: int = defaults.DEM_SEED,
                  static_friction: float | None = None, rolling_friction: float = 0.0,
                  repeat: int = 1, grid: bool = False, workers: int | None = None,
                  reference: bool = False) -> dict:
    """Measure kernel throughput on a driven bed in steady motion (compile time excluded).

    The bed is settled as a load case starts (dense packing by default) and driven for one
    steady-state block (DEM_STEADY_BLOCK_CYCLES cycles, after which the grid's beds are steady;
    this also compiles or loads the kernel); then ``steps`` driven steps from that same state
    are timed ``repeat`` times with ``threads`` Numba threads, and the fastest run is kept (on
    a shared machine the others were slowed by other processes). ``static_friction`` and
    ``rolling_friction`` (both pairs; None: the table's) switch those laws on.
    ``reference=True`` also times :func:`~.bench_reference.all_pairs_reference` (a plain
    all-pairs kernel without contact history: the yardstick of issue 11's targets) from the
    same state, the same number of steps and repetitions.

    Returns
    -------
    dict with ``particle_steps_per_s`` [1/s] (fastest wall time), ``particle_steps_per_s_cpu``
    [1/s] (fastest process CPU time: the kernel's own speed when other processes share the
    core), ``particle_steps_per_s_per_thread`` [1/s], ``wall_s`` [s], ``particles_per_cell``,
    ``cells``, ``steps``, ``threads``, ``repeat``, ``time_step_s``; with ``reference=True``
    also ``reference_particle_steps_per_s`` [1/s] (fastest process CPU time, like ``_cpu``);
    with ``grid=True`` also ``grid_cases`` and ``grid_wall_s`` [s]: the paper's Table 3 grid
    run with default settings by :func:`pidcore.dem.sweep.run_sweep` (``workers`` processes)
    into a temporary store.
    """
    import numba

    geometry = CellGeometry()
    law = ContactLaw.for_material(material)
    if static_friction is not None or rolling_friction > 0.0:
        def pair(p):
            return dataclasses.replace(
                p, static_friction=max(p.sliding_friction, static_friction or 0.0),
                rolling_friction=rolling_friction)
        law = law.with_parameters(pair_particle=pair(law.pair_particle.parameters),
                                  pair_wall=pair(law.pair_wall.parameters))
    case = LoadCase(frequency_hz, acceleration_g, 50.0, material=material)
    dt = choose_time_step(case, law, geometry, "auto")
    rng = np.random.default_rng(seed)
    pos = np.stack([random_packing(geometry, law.radius_m, particles_per_cell, rng)
                    for _ in range(cells)])
    state = CellsState.from_positions(pos, mass_kg=law.mass_kg)
    settings = KernelSettings(law=law, geometry=geometry, dt_s=dt,
                              omega_rad_s=case.omega_rad_s, accel_m_s2=case.acceleration_m_s2)
    previous = numba.get_num_threads()
    numba.set_num_threads(min(threads, numba.config.NUMBA_NUM_THREADS))
    try:
        settle_bed(state, dataclasses.replace(settings, omega_rad_s=0.0, accel_m_s2=0.0))
        # bed in steady motion: a dense start needs a few cycles to break up and fly
        advance(state, settings, int(defaults.DEM_STEADY_BLOCK_CYCLES / (frequency_hz * dt)))
        wall = cpu = math.inf
        for _ in range(max(repeat, 1)):
            run = state.copy()
            start, start_cpu = time.perf_counter(), time.process_time()
            advance(run, settings, steps)
            wall = min(wall, time.perf_counter() - start)
            cpu = min(cpu, time.process_time() - start_cpu)
    finally:
        numba.set_num_threads(previous)
    rate = steps * cells * particles_per_cell / wall
    extra = run_grid_bench(material=material, seed=seed, workers=workers) if grid else {}
    if reference:
        extra["reference_particle_steps_per_s"] = steps * cells * particles_per_cell / \
            _time_reference(state, settings, steps, repeat)
    return extra | {"particle_steps_per_s": rate,
            "particle_steps_per_s_cpu": steps * cells * particles_per_cell / cpu,
            "particle_steps_per_s_per_thread": rate / max(threads, 1),
            "wall_s": wall, "particles_per_cell": particles_per_cell, "cells": cells,
            "steps": steps, "threads": threads, "repeat": repeat, "time_step_s": dt,
            "material": material, "static_friction": static_friction,
            "rolling_friction": rolling_friction}


def _time_reference(state: CellsState, settings: KernelSettings, steps: int,
                    repeat: int) -> float:
    """Fastest process CPU time of the all-pairs yardstick over ``steps`` from ``state``, s."""
    from .bench_reference import all_pairs_reference
    from .state import law_vectors

    law = settings.law
    pair_law, wall_law = (vector[[LAW_STIFFNESS, LAW_DAMPING, LAW_SLIDING]].copy()
                          for vector in law_vectors(law))

    def run(n: int) -> float:
        copy = state.copy()
        start = time.process_time()
        all_pairs_reference(copy.pos, copy.vel, copy.omg, settings.geometry.wall_normals,
                            settings.geometry.wall_offsets, law.radius_m, law.mass_kg,
                            law.inertia_kg_m2, pair_law, wall_law, settings.gravity_m_s2,
                            settings.dt_s, n, settings.omega_rad_s, settings.accel_m_s2,
                            settings.friction_regularisation_m_s)
        return time.process_time() - start

    run(1)  # compile or load from the cache
    return min(run(steps) for _ in range(max(repeat, 1)))


def run_grid_bench(*, material: str = "acrylic", seed: int = defaults.DEM_SEED,
                   workers: int | None = None, progress: bool = True) -> dict:
    """Wall time of the paper's Table 3 grid with default settings, into a temporary store.

    Returns ``grid_cases`` and ``grid_wall_s`` [s] of :func:`pidcore.dem.sweep.run_sweep` with
    ``workers`` processes; ``progress``: the sweep's bar on stderr.
    """
    import tempfile
    from pathlib import Path

    from .simulate import DemConfig
    from .sweep import grid_cases, run_sweep

    cases = grid_cases("table3", material=material)
    with tempfile.TemporaryDirectory() as tmp:
        summary = run_sweep(cases, DemConfig(seed=seed), store_path=Path(tmp) / "b.h5",
                            workers=workers, progress=progress)
    return {"grid_cases": len(cases), "grid_wall_s": summary.wall_s}
