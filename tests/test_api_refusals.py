"""Wrong types and out-of-range values given to the library are refused where they are given,
with a one-line :class:`~pidcore.errors.ParameterError` naming the keyword (as the CLI's
options are), not as a TypeError or AttributeError from deep inside, nor run as something
else (``cells=2.5`` ran; a fill of 150 % gave one and a half cells of particles)."""

from __future__ import annotations

import dataclasses
import json
import math
from pathlib import Path

import numpy as np
import pytest

from pidcore.calibrate import load_calibration
from pidcore.dem import DemConfig, LoadCase, particles_per_cell, simulate_load_case
from pidcore.dem.sweep import run_sweep
from pidcore.errors import ChannelError, ParameterError
from pidcore.io import read_measurement, read_measurements
from pidcore.measure import AnalysisOptions, analyze_file, save_analyses
from pidcore.model import (
    SdcModel,
    TreatedMode,
    harmonic_response,
    load_paper_table3,
    time_domain_response,
)
from pidcore.records import Channel, Measurement
from pidcore.signal import analyze_power
from pidcore.specimen import paper_specimen
from pidcore.store import Store


@pytest.mark.parametrize(("keywords", "named"), [
    ({"cells": 2.5}, "cells: expected a whole number, got 2.5"),
    ({"cells": "4"}, "cells: expected a whole number, got '4'"),
    ({"seed": 1.5}, "seed: expected a whole number"),
    ({"steady_cycles": 10.5}, "steady_cycles: expected a whole number"),
    ({"samples_per_cycle": True}, "samples_per_cycle: expected a whole number"),
    ({"time_step": True}, "time_step: expected a number, got True"),
    ({"max_transient_s": "1"}, "max_transient_s: expected a number"),
    ({"alpha_pp": "0.1"}, "alpha_pp: expected a number"),
])
def test_dem_config_refuses_wrong_types_naming_the_field(keywords, named):
    with pytest.raises(ParameterError, match=f"^{named}"):
        DemConfig(**keywords)


def test_a_seed_beyond_the_largest_says_the_bound_it_breaks():
    # 10^19 (an app seed typed 1e19) was refused as "expected a whole number >= 0"
    assert DemConfig(seed=2**63 - 1).seed == 2**63 - 1
    with pytest.raises(ParameterError) as refused:
        DemConfig(seed=10**19)
    assert str(refused.value) == ("seed: expected a whole number below 2^63 "
                                  "(9223372036854775808), got 10000000000000000000")


def test_dem_config_takes_whole_floats_as_counts():
    # a JSON or HDF5 reader may give 4.0 back for a count: the same run, kept an int
    config = DemConfig(cells=4.0, seed=np.int64(7), steady_cycles=20.0)
    assert (config.cells, config.seed, config.steady_cycles) == (4, 7, 20)
    assert all(type(v) is int for v in (config.cells, config.seed, config.steady_cycles))
    assert config == DemConfig(cells=4, seed=7, steady_cycles=20)


@pytest.mark.parametrize(("arguments", "named"), [
    (((100.0, 5.0, 50.0),), r"^case: expected a LoadCase, got tuple"),
    ((LoadCase(100.0, 5.0, 50.0), {"cells": 1}),
     r"^config: expected a DemConfig or None, got dict"),
])
def test_simulate_load_case_refuses_what_is_not_a_record(arguments, named):
    with pytest.raises(ParameterError, match=named):
        simulate_load_case(*arguments)


def test_simulate_load_case_refuses_a_specimen_path_saying_how_to_read_it():
    with pytest.raises(ParameterError, match=r"^specimen: expected a Specimen or None, got str "
                                             r".*load_specimen\(path\)"):
        simulate_load_case(LoadCase(100.0, 5.0, 50.0), DemConfig(cells=1),
                           specimen="steel_6mm.toml")


def test_a_fill_above_a_full_cell_is_refused():
    n_full, full = particles_per_cell(100.0)
    assert n_full == full  # the limit itself: a full cell
    with pytest.raises(ParameterError, match=r"^fill_percent 150 %: more than a full cell"):
        particles_per_cell(150.0)  # was (1.5 x capacity, capacity): more than fit


@pytest.mark.parametrize(("keywords", "said"), [
    # inf found a steady state at once: the transient's SDC stored as steady
    ({"steady_relative_tolerance": math.inf},
     "steady_relative_tolerance: expected a finite fraction >= 0, got inf"),
    ({"steady_relative_tolerance": math.nan},  # never steady: always the cap
     "steady_relative_tolerance: expected a finite fraction >= 0, got nan"),
    ({"steady_relative_tolerance": -0.1},
     "steady_relative_tolerance: expected a finite fraction >= 0, got -0.1"),
    ({"friction_regularisation_m_s": math.nan},  # simulated and stored in the run's record
     "friction_regularisation_m_s: expected a speed > 0 m/s, got nan"),
    ({"friction_regularisation_m_s": -1e-6},
     "friction_regularisation_m_s: expected a speed > 0 m/s, got -1e-06"),
    # refused as "non-finite positions; try a smaller time step", "overlap above 5 %"
    ({"alpha_pp": math.nan}, "alpha_pp: expected an Eq. 3 damping constant >= 0 (0: elastic), "
                             "got nan"),
    ({"alpha_pw": -1.0}, "alpha_pw: expected an Eq. 3 damping constant >= 0 (0: elastic), "
                         "got -1.0"),
    ({"max_transient_s": math.inf},  # an OverflowError of the cap's ceil()
     "max_transient_s: expected a finite time >= 0 s, got inf"),
])
def test_dem_settings_no_run_can_honour_are_refused_when_made(keywords, said):
    with pytest.raises(ParameterError) as refused:
        DemConfig(**keywords)
    assert str(refused.value) == said
    assert DemConfig(steady_relative_tolerance=0.0, alpha_pp=0.0).alpha_pp == 0.0  # the limits


def test_a_fill_of_no_particle_is_refused_naming_the_keyword_before_any_work(tmp_path):
    # `pidcore dem run --fill 1` names its option; the library said "fill 1 % of 22 ...",
    # naming no parameter a script has. 1 % of the 22 acrylic spheres of the paper's cell is
    # 0.22 of a sphere, rounded to none; 2.28 % is the least fill that rounds to one
    said = r"^fill_percent 1 % of 22 particles rounds to none; expected >= 2\.28 %"
    with pytest.raises(ParameterError, match=said):
        particles_per_cell(1.0)
    with pytest.raises(ParameterError, match=said):
        simulate_load_case(LoadCase(500.0, 5.0, 1.0), DemConfig(cells=1))
    store = tmp_path / "dem.h5"
    with pytest.raises(ParameterError, match=said):  # the valid case is not run either
        run_sweep([LoadCase(500.0, 5.0, 50.0), LoadCase(500.0, 5.0, 1.0)], DemConfig(cells=1),
                  store_path=store, workers=1, progress=False)
    assert not store.exists()


@pytest.mark.parametrize(("keywords", "named"), [
    ({"velocity_delay_s": "50e-6"}, r"^velocity_delay_s: expected a number, got '50e-6'"),
    ({"mass_below_gauge_kg": -0.01}, r"^mass_below_gauge_kg: -0.01, expected >= 0 kg"),
    ({"baseline_loss_factor": -0.1}, r"^baseline_loss_factor: -0.1, expected a loss factor"),
    ({"n_harmonics": 0}, r"^n_harmonics: 0, expected an integer >= 1"),
    ({"n_harmonics": 2.5}, r"^n_harmonics: 2.5, expected an integer >= 1"),
    ({"frequency_hz": -100.0}, r"^frequency_hz: -100.0, expected a positive hint"),
    ({"sample_rate_hz": 0.0}, r"^sample_rate_hz: 0.0, expected a positive number"),
    ({"force": 3}, r"^force: expected a str or None, got int"),
    ({"allow_clipped": "yes"}, r"^allow_clipped: expected a bool, got str"),
])
def test_analysis_options_are_refused_when_made(keywords, named):
    # before: made without a word, and refused (or a TypeError) only once a file was read
    with pytest.raises(ParameterError, match=named):
        AnalysisOptions(**keywords)


def test_a_negative_vibrometer_delay_is_refused_by_the_library_as_by_the_cli(tmp_path):
    # `pidcore analyze --velocity-delay=-5e-5` was refused, AnalysisOptions(velocity_delay_s=
    # -5e-5) analysed and saved a loss factor shifted by -w tau; the rule is now the options'
    # own, which the CLI, the sidecar table, the app and a script all make
    said = (r"^velocity_delay_s: -5e-05 s, expected a delay >= 0 s \(the vibrometer output "
            r"lags the motion\)$")
    with pytest.raises(ParameterError, match=said):
        AnalysisOptions(velocity_delay_s=-5e-5)
    with pytest.raises(ParameterError, match=said):  # the app's way to a changed setting
        dataclasses.replace(AnalysisOptions(), velocity_delay_s=-5e-5)
    assert AnalysisOptions(velocity_delay_s=-0.0).velocity_delay_s == 0.0  # no correction
    store = tmp_path / "s.h5"
    with pytest.raises(ParameterError, match=said):  # a script's analyse-and-save
        options = AnalysisOptions(velocity_delay_s=-5e-5)
        save_analyses(store, [analyze_file(_SAMPLE, options)], options)
    assert not store.exists()


def test_analyze_power_names_a_sample_rate_that_is_not_a_number():
    t = np.arange(4000) / 4000.0
    force, velocity = np.sin(2 * np.pi * 50 * t), np.cos(2 * np.pi * 50 * t)
    with pytest.raises(ParameterError, match=r"^sample_rate_hz: expected a number, got '4000'"):
        analyze_power(force, velocity, "4000")  # was TypeError: must be real number, not str


_SAMPLE = (Path(__file__).resolve().parents[1] / "data_samples" / "exports"
           / "synthetic_f500Hz_a1g_fill50_acrylic.csv")


def test_analyze_file_takes_the_default_options_when_given_none():
    # a script's first call, analyze_file(path), was a TypeError (options was required)
    default = analyze_file(_SAMPLE, AnalysisOptions())
    assert analyze_file(_SAMPLE).analysis.sdc == default.analysis.sdc


def test_analyze_file_refuses_options_that_are_not_analysis_options():
    with pytest.raises(ParameterError, match=r"^options: expected an AnalysisOptions, got dict"):
        analyze_file(_SAMPLE, {"velocity_delay_s": 5e-5})  # was AttributeError: 'dict' ...


def test_a_load_case_refuses_booleans():
    # True was taken as 1 Hz (or a fill of 1 %)
    with pytest.raises(ParameterError, match=r"^load case: frequency_hz must be .* got True"):
        LoadCase(True, 5.0, 50.0)
    with pytest.raises(ParameterError, match=r"^load case: fill True is not a number"):
        LoadCase(100.0, 5.0, True)
    assert LoadCase("100", "5", "50") == LoadCase(100.0, 5.0, 50.0)  # text as tables hold it


def test_the_paper_specimen_takes_the_material_aliases_a_load_case_takes():
    # LoadCase and the CLI read "aluminum" as "aluminium"; paper_specimen refused it
    assert LoadCase(100.0, 5.0, 50.0, material="aluminum").material == "aluminium"
    assert paper_specimen("aluminum") == paper_specimen("aluminium")
    assert paper_specimen("PMMA") == paper_specimen("acrylic")


def test_a_file_descriptor_is_not_a_path():
    # read_measurement(0) opened file descriptor 0 (stdin) and read from it
    for read in (read_measurement, read_measurements):
        with pytest.raises(ParameterError, match=r"^path: expected a str or PathLike, got int"):
            read(0)


def test_response_functions_refuse_what_is_not_their_record():
    table = load_paper_table3()
    mode = TreatedMode(natural_frequency_hz=300.0, modal_mass_kg=2.0,
                       structural_damping_ratio=0.01, treated_area_m2=0.2, fill_percent=50.0,
                       coupon_vibrated_mass_kg=0.1)
    with pytest.raises(ParameterError, match=r"^model: expected an? SdcModel, got DataFrame") \
            as refused:  # was AttributeError: 'DataFrame' object has no attribute 'bounds'
        harmonic_response(table, mode, frequencies_hz=[300.0], force_amplitude_n=10.0)
    assert "\n" not in str(refused.value)  # one line, though a frame's repr has many
    model = SdcModel.from_table(table)
    with pytest.raises(ParameterError, match=r"^measure_cycles: expected a whole number"):
        time_domain_response(model, mode, frequency_hz=300.0, force_amplitude_n=10.0,
                             measure_cycles=2.5)  # was a TypeError of numpy
    with pytest.raises(ParameterError, match=r"^TreatedMode: natural_frequency_hz: expected a "
                                             r"number, got '300'"):
        TreatedMode(natural_frequency_hz="300", modal_mass_kg=2.0,  # was a TypeError of numpy
                    structural_damping_ratio=0.01, treated_area_m2=0.2, fill_percent=50.0,
                    coupon_vibrated_mass_kg=0.1)


def test_a_calibration_refuses_what_is_not_a_load_case_or_a_stderr():
    calibration = load_calibration(_SAMPLE.parents[1] / "paper_calibration")
    with pytest.raises(ParameterError, match=r"^case: expected a LoadCase, got tuple"):
        calibration.lookup((50.0, 1.0, 50.0))  # was AttributeError: no attribute 'material'
    with pytest.raises(ParameterError, match=r"^stderr: expected a number, got '0.1'"):
        calibration.predictions[0].band("0.1")


def test_a_measurement_without_a_common_time_axis_is_not_tabulated():
    force = Channel("F", "force", np.zeros(100), 1000.0, "N")
    velocity = Channel("V", "velocity", np.zeros(50), 500.0, "m/s")
    with pytest.raises(ChannelError, match=r"^m.csv: channel 'V' \(500 Hz from 0 s\) and 'F' "
                                           r"\(1000 Hz from 0 s\) share no time axis"):
        Measurement("m.csv", (force, velocity)).to_pandas()
    shorter = Channel("V", "velocity", np.ones(60), 1000.0, "m/s")
    frame = Measurement("m.csv", (force, shorter)).to_pandas()
    assert len(frame) == 100 and frame["V [m/s]"].isna().sum() == 40  # padded, not cut


@pytest.mark.parametrize("make", [lambda: DemConfig(4), lambda: AnalysisOptions("Force"),
                                  lambda: TreatedMode(300.0, 2.0, 0.01, 0.2, 50.0, 0.1)],
                         ids=["DemConfig", "AnalysisOptions", "TreatedMode"])
def test_settings_records_take_keywords_only(make):
    # 15-20 fields of one type each: DemConfig(4) was cells=4, TreatedMode(...) took six
    # numbers in an order nothing at the call showed (mass and frequency swap silently)
    with pytest.raises(TypeError, match="positional argument"):
        make()


def test_saved_analyses_carry_the_options_they_were_analysed_with(tmp_path):
    from pidcore.measure import save_analyses
    from pidcore.store import Store

    options = AnalysisOptions(velocity_delay_s=5e-5)
    record = analyze_file(_SAMPLE, options)
    assert record.options == options
    store = Store(tmp_path / "s.h5")
    # AnalysisOptions() given for a record analysed with a 50 µs delay: the store said delay 0
    with pytest.raises(ParameterError, match=r"^options: .*synthetic_f500Hz_a1g_fill50_acrylic"
                                             r"\.csv would be saved with velocity_delay_s 0\.0 "
                                             r"\(analysed with 5e-05\)"):
        save_analyses(store, [record], AnalysisOptions(), [(_SAMPLE.name, None, "")])
    assert not store.path.exists()  # nothing half-written
    saved = save_analyses(store, [record])  # options and names: the record's own
    stored = json.loads(store.list_analyses().set_index("key").loc[saved.keys[0],
                                                                   "parameters_json"])
    assert stored["velocity_delay_s"] == 5e-5


def test_calibrate_reads_fit_as_the_cli_does_before_any_run(tmp_path):
    from pidcore.calibrate import calibrate, read_measured_table

    points = read_measured_table(_SAMPLE.parents[1] / "paper_measured_sdc.csv")
    # a string was taken letter by letter: "unknown parameter 'r'"
    with pytest.raises(ParameterError, match=r"unknown parameter 'foo'"):
        calibrate(points, fit="rolling_friction,foo", store_path=tmp_path / "c.h5")
    assert not (tmp_path / "c.h5").exists()  # refused before any DEM run


def test_tolerances_name_a_value_that_is_not_a_number():
    from pidcore.compare import Tolerances

    with pytest.raises(ParameterError, match=r"^Tolerances: frequency_rtol: expected a number"):
        Tolerances(frequency_rtol="0.1")  # was TypeError: must be real number, not str


def test_save_analyses_refuses_what_is_not_a_list_of_analysed_records(tmp_path):
    # a record given alone, the arguments swapped or a list of paths failed with
    # AttributeError/TypeError from inside (`'int' object has no attribute 'options'`)
    from pidcore.measure import save_analyses
    from pidcore.store import Store

    record = analyze_file(_SAMPLE, AnalysisOptions(velocity_delay_s=5e-5))
    store = Store(tmp_path / "s.h5")
    with pytest.raises(ParameterError, match=r"^results: expected a list, got AnalyzedRecord"):
        save_analyses(store, record)
    with pytest.raises(ParameterError, match=r"^results: expected a list, got Store"):
        save_analyses([record], store)
    with pytest.raises(ParameterError, match=r"^results\[1\]: expected an AnalyzedRecord, "
                                             r"got PosixPath"):
        save_analyses(store, [record, _SAMPLE])
    with pytest.raises(ParameterError, match=r"^options\[0\]: expected an AnalysisOptions, "
                                             r"got dict"):
        save_analyses(store, [record], [{}])
    assert not store.path.exists()  # nothing half-written
    assert len(save_analyses(store, (record,)).keys) == 1  # a tuple is a sequence too


def test_listing_functions_refuse_a_store_given_for_its_listing(tmp_path):
    # select_runs(Store(...)) and build_report_table(runs, Store(...), None), the listing call
    # forgotten, failed with AttributeError ('Store' object has no attribute 'columns')
    from pidcore.model import select_runs
    from pidcore.report import build_report_table
    from pidcore.store import Store

    store = Store(_SAMPLE.parents[1] / "dem_table3.h5")
    with pytest.raises(ParameterError, match=r"^runs: expected a DataFrame, got Store .*"
                                             r"\(e\.g\. Store\(path\)\.list_dem_runs\(\)\)$"):
        select_runs(store)
    runs = select_runs(store.list_dem_runs())
    with pytest.raises(ParameterError, match=r"^analyses: expected a DataFrame or None, got "
                                             r"Store .*list_analyses\(\)\)$"):
        build_report_table(runs, store, None)
    with pytest.raises(ParameterError, match=r"^dem_runs: expected a DataFrame or None, got str"):
        build_report_table("runs.h5", None, None)
    assert len(build_report_table(runs, None, None)) == len(runs.groupby(
        ["frequency_hz", "acceleration_g", "fill_percent"]))  # one row per DEM load case


def test_saving_a_fill_of_no_particle_is_refused_as_analyze_refuses_it(tmp_path):
    # `pidcore analyze --fill 0.5` is refused (0.5 % of the paper cell's 22 acrylic spheres
    # rounds to none); save_analyses stored a script's LoadCase(500, 1, 0.5), a load case no
    # DEM run can be made at
    record = analyze_file(_SAMPLE)
    store = tmp_path / "s.h5"
    with pytest.raises(ParameterError) as refused:
        save_analyses(store, [record], stated=[("run.csv", LoadCase(500.0, 1.0, 0.5), "script")])
    assert str(refused.value) == ("run.csv: fill_percent 0.5 % of 22 particles rounds to none; "
                                  "expected >= 2.28 %; was 0.5 meant as 50 %?")
    assert not store.exists()
    # the least fill holding a particle is saved; a record naming its specimen is of its cell
    save_analyses(store, [record], stated=[("run.csv", LoadCase(500.0, 1.0, 2.28), "script")])
    other = tmp_path / "other.h5"
    save_analyses(other, [record], stated=[("run.csv", LoadCase(500.0, 1.0, 0.5), "script")],
                  fields=[{"specimen": "big_cells"}])
    assert Store(other).list_analyses()["fill_percent"].tolist() == [0.5]
