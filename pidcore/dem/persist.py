"""DEM runs in the HDF5 store (:mod:`pidcore.store`): one key, one entry layout, one save path,
and the run cache.

A run's key holds every input that changes its numbers: the load case, the configuration
(seed, cells, numerical options), the specimen (its hash: cell, masses, particles, contact
pairs) and :data:`DEM_CODE_VERSION`. ``pidcore dem run --store``, sweeps, the app and the
calibration all save through :func:`save_dem_entry` and find runs by :func:`run_key`, so a run
stored by any of them is reused by the others (:func:`run_or_load`), never recomputed.

The key hashes the fill as stated; the simulation reads it only through the particle count it
rounds to. A run of another fill with the same count (and seed, settings, specimen) is the
same simulation: the run cache and sweeps find it by the stored runs' inputs
(:func:`stored_run_key`, :func:`run_identity`) without changing any key, and the report counts
such runs once (:func:`pidcore.compare.align.simulation_identity`).
"""

from __future__ import annotations

import dataclasses
import math
import os
from collections.abc import Iterable, Mapping
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from ..compare.align import CALIBRATION_VARIANT_FIELD, parameters_digest
from ..errors import StoreError
from ..loadcase import key_0_1
from ..specimen import HASH_OF_WHAT, Specimen, hashed_name, is_paper_coupon, paper_specimen
from .result import UNITS, DemResult
from .simulate import (
    DemConfig,
    LoadCase,
    config_parameters,
    resolve_specimen,
    simulate_load_case,
)

if TYPE_CHECKING:  # pragma: no cover
    from ..store import Store, StoredEntry

#: Version of the DEM's numbers: bump it with any change to the kernel, contact laws or
#: run protocol that alters a result, so that stored runs of older code are not reused.
#: (A code version, not the package version: that reads "0.0.0+unknown" from a source tree.)
DEM_CODE_VERSION = 1


def _key_case(case: LoadCase, specimen: Specimen) -> str:
    """Readable part of the key: the load case, named by the particles actually simulated."""
    # an inline material (e.g. steel) the load case may not name: the key says what ran
    return dataclasses.replace(case, material=specimen.particles.material).key


def run_parameters(case: LoadCase, config: DemConfig,
                   specimen: Specimen | None = None) -> dict[str, Any]:
    """Every input of a run (JSON-safe): load case, configuration, specimen text and hash,
    code version. Stored with the run as its provenance."""
    specimen = resolve_specimen(case, specimen)
    params = config_parameters(case, config)
    params.update({"specimen_name": specimen.name, "specimen_sha256": specimen.hash,
                   "specimen_text": specimen.text, "dem_code_version": DEM_CODE_VERSION})
    return params


def run_key(case: LoadCase, config: DemConfig, specimen: Specimen | None = None) -> str:
    """Store key of one DEM run: readable load case plus a hash of every other input.

    E.g. ``f50Hz_a5g_fill50pct_acrylic_z_seed12345_cells8_<hash>``: the same for
    ``pidcore dem run --store``, sweeps, the run cache and the app, so a sweep skips a run
    saved by any of them. ``specimen=None`` is the paper's coupon with ``case.material``
    particles.
    """
    specimen = resolve_specimen(case, specimen)
    params = run_parameters(case, config, specimen)
    params.pop("specimen_text")  # the hash stands for it
    digest = parameters_digest(params)
    return f"{_key_case(case, specimen)}_seed{config.seed}_cells{config.cells}_{digest[:10]}"


def run_key_case(key: str) -> str:
    """The readable load case a :func:`run_key` begins with (``f50Hz_a5g_fill50pct_acrylic_z``
    of ``f50Hz_a5g_fill50pct_acrylic_z_seed12345_cells8_<hash>``): what two runs of one load
    case share, whatever their seed, cells and settings."""
    return key.split("_seed")[0]


def run_key_0_1(case: LoadCase, config: DemConfig) -> str:
    """The key pidcore 0.1 stored the same run under (``acrylic_z_f50_a5_fill50_seed...``), so
    a sweep over a 0.1 store skips the runs it holds."""
    params = config_parameters(case, config)
    digest = parameters_digest(params)
    return f"{key_0_1(case)}_seed{config.seed}_cells{config.cells}_{digest[:10]}"


def dem_run_entry(result: DemResult, *,
                  calibration_variant: Mapping[str, Any] | None = None) -> dict:
    """``record``, ``arrays``, ``parameters`` and ``units`` of a run, as the store takes them.

    ``calibration_variant``: where the run's specimen is a calibration's variant of a file at
    a design point, which file and values (:data:`pidcore.compare.align.
    CALIBRATION_VARIANT_FIELD`); None: the specimen file as given. Stored beside the inputs,
    outside the key: its run of the same specimen elsewhere is the same run."""
    record = result.to_dict()
    record.pop("case_key", None)  # reserved listing column; the key is the entry name
    arrays = result.arrays()
    units = {k: v for k, v in UNITS.items() if k in record or k in arrays}
    parameters = run_parameters(result.case, result.config, result.specimen)
    # stated for every run saved now: a run that lacks it was stored before pidcore told a
    # calibration's variants from the files they vary, and is either
    parameters[CALIBRATION_VARIANT_FIELD] = (None if calibration_variant is None
                                             else dict(calibration_variant))
    return {"record": record, "arrays": arrays, "parameters": parameters, "units": units}


def _open(store: Store | str | os.PathLike[str]) -> Store:
    from ..store import Store

    return store if isinstance(store, Store) else Store(store)


def stored_keys(store_path: str | os.PathLike[str], keys: Iterable[str]) -> set[str]:
    """The run keys of ``keys`` that the store at ``store_path`` holds now, read from the store
    itself: after Ctrl-C, a count kept beside the saves could miss the one that committed as
    the interrupt came."""
    from ..store import Store

    if not Path(store_path).exists():
        return set()
    store = Store(store_path)
    return {key for key in keys if store.has_dem_run(key)}


def save_dem_entry(store: Store | str | os.PathLike[str], key: str, entry: dict) -> bool:
    """Add one run to the store unless its key is there already; True if it was added.

    The one save path of every DEM run. A stored run is never replaced: the key holds every
    input, so a run found under it is this run (a concurrent writer stored it first).
    """
    store = _open(store)
    with store.transaction():
        if store.has_dem_run(key):
            return False
        store.add_dem_run(key, **entry)
    return True


def save_dem_result(store: Store | str | os.PathLike[str], result: DemResult) -> str:
    """Add ``result`` (scalars, arrays, every input, units) to the store; returns its key."""
    key = run_key(result.case, result.config, result.specimen)
    save_dem_entry(store, key, dem_run_entry(result))
    return key


def _config_from(parameters: dict[str, Any]) -> DemConfig:
    values = {}
    for f in dataclasses.fields(DemConfig):
        name = f"config_{f.name}"
        if name in parameters:
            value = parameters[name]
            values[f.name] = None if value == "" else value  # config_parameters wrote None as ""
    return DemConfig(**values)


def record_coupon_mass_kg(record: Mapping[str, Any]) -> float:
    """The coupon's mass without its fixture, kg, from a stored DEM run's record.

    Runs stored before ``moving_mass_kg`` existed held coupon + fixture under
    ``coupon_mass_kg``; their ``fixture_mass_kg`` (0 where not stored: the paper's coupon) is
    taken off.
    """
    coupon = float(record["coupon_mass_kg"])
    if "moving_mass_kg" not in record:
        coupon -= float(record.get("fixture_mass_kg") or 0.0)
    return coupon


def load_dem_result(entry: StoredEntry) -> DemResult:
    """Rebuild a :class:`DemResult` from a stored run (the numbers exactly as computed).

    Runs stored before specimens existed are the paper's coupon; arrays they lack
    (``dissipation_per_cell_cycle_j``) come back as NaN.
    """
    params = entry.parameters
    case = LoadCase(**{k[5:]: v for k, v in params.items() if k.startswith("case_")})
    config = _config_from(params)
    text = params.get("specimen_text")
    specimen = Specimen.from_text(text, source=f"stored run {entry.key}") if text \
        else paper_specimen(case.material)
    record = dict(entry.record)
    if "m_c_kg" in record:  # the column's name in stores written by pidcore 0.1
        record.setdefault("vibrated_mass_kg", record.pop("m_c_kg"))
    values: dict[str, Any] = {"case": case, "config": config, "specimen": specimen}
    for f in dataclasses.fields(DemResult):
        if f.name in values:
            continue
        if f.name in entry.arrays:
            values[f.name] = np.asarray(entry.arrays[f.name])
        elif f.name in record:
            value = record[f.name]
            values[f.name] = float("nan") if value is None else value
    if "moving_mass_kg" not in record:
        # stored before the key existed: coupon_mass_kg held coupon + fixture then
        values["moving_mass_kg"] = record["coupon_mass_kg"]
    values.setdefault("coupon_cells", specimen.cell.count)
    # stored before the degrees of freedom were kept: unknown (readers assume cells - 1)
    values.setdefault("sdc_stderr_dof", float("nan"))
    # stored before the damping constants used were kept: unknown
    values.setdefault("alpha_pp", float("nan"))
    values.setdefault("alpha_pw", float("nan"))
    if "energy_dissipated_rolling_j" not in record and not any(
            pair.rolling_friction for pair in (specimen.pairs.particle_particle,
                                               specimen.pairs.particle_wall)):
        # stored before rolling resistance was tallied: none acted (rolling friction 0)
        values["energy_dissipated_rolling_j"] = 0.0
    values.setdefault("samples_per_cycle",
                      int(round(record["sample_rate_hz"] / case.frequency_hz)))
    values.setdefault("dissipation_per_cell_cycle_j", np.full(
        (int(record["cells_simulated"]), len(entry.arrays["dissipation_per_cycle_j"])),
        np.nan))
    missing = [f.name for f in dataclasses.fields(DemResult) if f.name not in values]
    if missing:
        raise StoreError(f"DEM run {entry.key!r}: stored run lacks {missing}")
    for name in ("particles_per_cell", "particles_full_cell", "cells_simulated", "steps",
                 "steady_start_cycle", "steady_cycles", "samples_per_cycle", "coupon_cells"):
        values[name] = int(values[name])
    values["steady_detected"] = bool(values["steady_detected"])
    for name in ("sdc", "sdc_stderr", "sdc_stderr_dof"):
        if values[name] is None or not math.isfinite(float(values[name])):
            values[name] = float("nan")
    return DemResult(**values)


def run_identity(case: LoadCase, config: DemConfig, specimen: Specimen | None = None) -> str:
    """The simulation a run of these inputs is (:func:`pidcore.compare.align.
    simulation_identity`): its inputs with the fill replaced by the particles per cell."""
    from ..compare.align import simulation_identity
    from .simulate import particles_per_cell

    specimen = resolve_specimen(case, specimen)
    count, _ = particles_per_cell(case.fill_percent, specimen=specimen,
                                  fill_reference=config.fill_reference)
    identity = simulation_identity(run_parameters(case, config, specimen), count)
    assert identity is not None  # run_parameters states the seed; the count is a whole number
    return identity


def stored_identities(store: Store | str | os.PathLike[str]) -> dict[str, str]:
    """Simulation identity -> key of the first stored run of it, for the runs of ``store``
    that record their inputs (:func:`run_identity`)."""
    from ..compare.align import simulation_identity

    store = _open(store)
    if not store.path.exists():
        return {}
    runs = store.list_dem_runs()
    if runs.empty or "parameters_json" not in runs.columns:
        return {}
    out: dict[str, str] = {}
    for key, params, count in zip(runs["case_key"], runs["parameters_json"],
                                  runs.get("particles_per_cell", [None] * len(runs)),
                                  strict=True):
        identity = simulation_identity(params, count)
        if identity is not None:
            out.setdefault(identity, str(key))
    return out


def own_run_keys(case: LoadCase, config: DemConfig,
                 specimen: Specimen | None = None) -> tuple[str, ...]:
    """The keys a run of these inputs is stored under: its :func:`run_key`, and for the
    paper's coupon the key pidcore 0.1 stored it under (:func:`run_key_0_1`). A 0.1 key names
    only the paper's coupon with its constant k_t: another specimen's run, a Mindlin one of
    that coupon included, is never found under it."""
    key = run_key(case, config, specimen)
    if resolve_specimen(case, specimen).is_paper():
        return key, run_key_0_1(case, config)
    return (key,)


def stored_run_key(store: Store | str | os.PathLike[str], case: LoadCase, config: DemConfig,
                   specimen: Specimen | None = None, *,
                   identities: Mapping[str, str] | None = None) -> str | None:
    """Key under which ``store`` holds this run: one of its :func:`own_run_keys`, else a run
    of the same simulation under another key; None if neither.

    A key hashes the fill as stated, the simulation only the particle count it rounds to
    (:func:`pidcore.compare.align.simulation_identity`): ``dem run --specimen`` stores the
    specimen's fill 21.73913... %, ``dem sweep --fills 21.7391`` asks for another key with
    the same 5 particles per cell and seed. Such a run is found by the stored runs' inputs
    (:func:`run_identity`), so no key changes; runs that do not record their inputs are never
    matched.

    ``identities``: :func:`stored_identities` of ``store``, read once by a caller that looks
    up many runs (default: read here).
    """
    store = _open(store)
    if not store.path.exists():
        return None
    for key in own_run_keys(case, config, specimen):
        if store.has_dem_run(key):
            return key
    if identities is None:
        identities = stored_identities(store)
    return identities.get(run_identity(case, config, specimen))


@dataclasses.dataclass(frozen=True)
class CachedRun:
    """What :func:`cached_run` gave: the run, the key it is stored under, and whether it was
    found in the store (``reused``) rather than simulated and saved."""

    result: DemResult
    key: str
    reused: bool


def cached_run(store: Store | str | os.PathLike[str], specimen: Specimen | None,
               case: LoadCase, config: DemConfig | None = None, *,
               progress: bool = False) -> CachedRun:
    """:func:`run_or_load`, saying under which key the run is stored and whether it was
    found there (``pidcore dem run --store`` says both)."""
    config = config or DemConfig()
    store = _open(store)
    specimen = resolve_specimen(case, specimen)
    stored = stored_run_key(store, case, config, specimen)
    if stored is not None:
        return CachedRun(load_dem_result(store.get_dem_run(stored)), stored, True)
    store.check_writable()  # before the simulation, not at its commit
    result = simulate_load_case(case, config, specimen=specimen, progress=progress)
    key = run_key(case, config, specimen)
    save_dem_entry(store, key, dem_run_entry(result))
    return CachedRun(result, key, False)


def run_or_load(store: Store | str | os.PathLike[str], specimen: Specimen | None,
                case: LoadCase, config: DemConfig | None = None, *,
                progress: bool = False) -> DemResult:
    """The run cache: the stored run of these inputs, or simulate, store and return it.

    A stored run of the same simulation under another key (another fill stated that rounds to
    the same particle count: :func:`stored_run_key`) is returned as stored: its ``case``
    states the fill it was stored with, which callers should say
    (``pidcore dem run`` does).

    Parameters
    ----------
    store : Store or path
        HDF5 store (created on the first save).
    specimen : Specimen or None
        None: the paper's coupon with ``case.material`` particles.
    case, config
        Load case and numerical settings (``DemConfig()`` by default).

    Examples
    --------
    >>> r = run_or_load("runs.h5", None, LoadCase(500, 5, 50))  # doctest: +SKIP
    """
    return cached_run(store, specimen, case, config, progress=progress).result


def runs_of_specimen(runs, specimen: Specimen | None = None):
    """Rows of a DEM-run listing (:meth:`pidcore.store.Store.list_dem_runs`) of one specimen.

    ``specimen=None`` is the paper's coupon: its runs with any table particle material, and
    runs stored before specimens existed (no ``specimen_sha256``), which are all the paper's.
    """
    if runs is None or runs.empty:
        return runs
    specimen = specimen or paper_specimen()
    # a plain list: pandas' string dtype turns a mapped None back into NaN, which would make
    # a run stored before specimens (no hash) look like another specimen's beside hashed ones
    stated = [h if isinstance(h, str) and h else None
              for h in runs.get("specimen_sha256", [None] * len(runs))]
    if specimen.is_paper():
        # no hash: a run stored before specimens, the paper's (is_paper_coupon of no name)
        keep = [is_paper_coupon("", h or "") for h in stated]
    else:
        keep = [h == specimen.hash for h in stated]
    return runs[np.array(keep, dtype=bool)].reset_index(drop=True)


def rekey_dem_store(source: str | os.PathLike[str], target: str | os.PathLike[str]) -> int:
    """Copy every DEM run of ``source`` into a new store ``target`` under today's key.

    For stores written before specimens (runs without ``specimen_sha256``: the paper's coupon
    with their particle material) or before a change of the key's inputs. Each run gets the
    specimen's text and hash as provenance; its numbers are copied, not recomputed, so this
    is only right while :data:`DEM_CODE_VERSION` is the one the runs were made with (checked
    where a run states it; a run that does not is taken as version 1, the first versioned
    code, which reproduces them bit for bit). ``source`` must hold DEM runs only (a store with
    measurements or analyses is refused); ``target`` must not exist. Returns the run count.
    """
    from ..store import Store

    source, target = Path(source), Path(target)
    if target.exists():
        raise StoreError(f"{target}: exists already; rekey_dem_store writes a new store")
    old = Store(source)
    if len(old.list_measurements()) or len(old.list_analyses()):
        raise StoreError(f"{source}: holds measurements or analyses; only a store of DEM runs "
                         "can be re-keyed")
    items = []
    for key in old.list_dem_runs()["case_key"]:
        entry = old.get_dem_run(key)
        version = entry.parameters.get("dem_code_version", 1)
        if version != DEM_CODE_VERSION:
            raise StoreError(f"{source}: DEM run {key!r} is from DEM code version {version}, "
                             f"this is {DEM_CODE_VERSION}: simulate it again instead")
        result = load_dem_result(entry)
        new = dem_run_entry(result)  # the stored numbers, with today's provenance fields
        # whether it was a calibration's variant is the stored run's to say: unstated stays
        # unstated, not "the file as given"
        if CALIBRATION_VARIANT_FIELD in entry.parameters:
            new["parameters"][CALIBRATION_VARIANT_FIELD] = \
                entry.parameters[CALIBRATION_VARIANT_FIELD]
        else:
            new["parameters"].pop(CALIBRATION_VARIANT_FIELD)
        new["arrays"] = dict(entry.arrays)  # not the NaN stand-ins for arrays it lacks
        new["units"] = {k: v for k, v in new["units"].items()
                        if k in new["record"] or k in new["arrays"]}
        items.append({"case_key": run_key(result.case, result.config, result.specimen), **new})
    Store(target).add_dem_runs(items)
    return len(items)


def other_files_runs_note(store_path: str | os.PathLike[str], cases: Iterable[LoadCase],
                          config: DemConfig, specimen: Specimen | None = None) -> str:
    """The note for runs a store holds of ``cases`` at ``config``'s seed and cell count by
    other specimen files of ``specimen``'s name (an edited ``x.toml``, or a calibration's
    design points): "" where it holds none.

    A run is reused only for the same specimen (:attr:`Specimen.hash`, of its canonical text:
    :data:`~pidcore.specimen.HASH_OF_WHAT`), so a file whose values, name or description
    changed after its runs were stored simulates every case again; ``dem run`` and ``dem
    sweep`` did so saying "0 already in STORE", as if the store held none."""
    from ..store import Store

    cases = list(cases)
    if not cases or not Path(store_path).exists():
        return ""
    runs = Store(store_path).list_dem_runs()
    if runs.empty or "specimen_sha256" not in runs.columns:
        return ""
    own = resolve_specimen(cases[0], specimen)
    wanted = {_key_case(case, resolve_specimen(case, specimen)) for case in cases}
    # a run stored before specimens had none: the paper's coupon, matched by the name alone
    sha = runs["specimen_sha256"].map(lambda value: value if isinstance(value, str)
                                      and len(value) == 64 else "")
    others = runs[(runs["specimen_name"] == own.name) & (sha != "") & (sha != own.hash)
                  & runs["case_key"].map(run_key_case).isin(wanted)
                  & (runs["seed"] == config.seed) & (runs["cells_simulated"] == config.cells)]
    if others.empty:
        return ""
    from ..compare.specimens import (
        AS_GIVEN,
        are_calibration_variants,
        run_origins,
        run_specimen_descriptions,
    )

    # a calibration's variants by what they stored: "an earlier version of this file" was
    # said of runs pidcore knew a calibration had made
    files = ", ".join(dict.fromkeys(run_specimen_descriptions(others)))
    whose, origin = (
        ("of a calibration's variants", "its design points")
        if are_calibration_variants(others).all()
        else ("by other files", "an earlier version of this file")
        if (run_origins(others) == AS_GIVEN).all()
        else ("by other files", "an earlier version of this file, or a calibration's design "
                                "points"))
    return (f"{store_path} holds {len(others)} run(s) of these load cases (seed {config.seed}, "
            f"{config.cells} cells) {whose} named {own.name} ({files}: {origin}); "
            f"not reused: a run is reused only for the same specimen, by {HASH_OF_WHAT}; this "
            f"file is {hashed_name(own.name, own.hash)} (any changed value, its description "
            "too, makes another specimen)")


__all__ = ["DEM_CODE_VERSION", "cached_run", "CachedRun", "dem_run_entry", "load_dem_result",
           "other_files_runs_note", "own_run_keys", "rekey_dem_store", "run_identity", "run_key",
           "run_key_case", "run_or_load",
           "run_parameters", "runs_of_specimen", "save_dem_entry", "save_dem_result",
           "stored_identities", "stored_run_key"]
