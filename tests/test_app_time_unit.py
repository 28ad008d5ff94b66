"""The Analyse page states a file's time unit as ``pidcore analyze --time-unit`` does: a UFF
export whose abscissa is in ms under a label pidcore does not read is refused naming the page's
field (it named the CLI option, which the page user has not got), and read with the field's unit
it gives the record the CLI gives with ``--time-unit``. The export is derived from the bundled
sample as tests/test_io_time_unit.py derives it (increments x1000, label 'msek')."""

from __future__ import annotations

import pytest
from _cli_runs import analyze_json
from test_io_time_unit import RATE_HZ, SAME, uff_in_ms

from pidcore.app import uploads
from pidcore.compare.case import stated_case
from pidcore.errors import ParameterError
from pidcore.measure import analysis_record

FIELD = "'time base unit' under 'Options for every file'"


def test_a_refused_time_base_names_the_pages_field_not_the_cli_option(tmp_path):
    path = uff_in_ms(tmp_path / "ms", b"msek")
    refused = uploads.parse_upload(path.name, path.read_bytes())
    assert refused.error == (f"{path.name}: record 1 ('Force'): abscissa unit 'msek' is no unit "
                             "of time pidcore reads; expected a unit of time such as s or ms "
                             "(the abscissa increment 0.0390625 is in it, so it sets the sample "
                             f"rate); give it as {FIELD}")


def test_parse_upload_with_the_time_unit_gives_the_clis_record(tmp_path, capsys):
    path = uff_in_ms(tmp_path / "ms", b"msek")
    cli = analyze_json(path, capsys, "--time-unit", "ms")
    found = uploads.parse_upload(path.name, path.read_bytes(), time_unit="ms")
    assert found.error is None
    assert [c.sample_rate_hz for c in found.measurement.channels] == [RATE_HZ] * 3
    options = uploads.options_of(uploads.default_settings_row(path.name, stated_case(path.name)),
                                 time_unit="ms")
    assert options.time_unit == "ms"  # saved with the record, as the CLI saves --time-unit
    outcome = uploads.analyze_parsed(found, options)
    assert outcome.ok, outcome.error
    app = analysis_record(outcome.record)
    shared = sorted(set(app) & set(cli))
    assert {"frequency_hz", "loss_factor", "sdc", "complex_power_real_w",
            "complex_power_imag_w", "sdc_stderr"} <= set(shared)
    # same samples, same rate, same analysis: equal to the last bits (SAME tells a slip apart)
    for key in shared:
        if isinstance(app[key], float):
            assert cli[key] == pytest.approx(app[key], rel=SAME, nan_ok=True), key
        else:
            assert cli[key] == app[key], key
    assert cli["sample_rate_hz"] == RATE_HZ
    assert app["frequency_hz"] == pytest.approx(50.0, rel=2e-7)  # not 0.05 Hz
    # the reader's note names the field that stated the unit
    assert (f"{path.name}: record 1 ('Force') abscissa unit 'msek' overridden: taken as 'ms' "
            f"({FIELD}), sample rate 25600 Hz") in outcome.record.notes
    # analyze_upload passes the options' time unit to the reader as well
    assert uploads.analyze_upload(path.name, path.read_bytes(), options).ok


@pytest.mark.parametrize(("typed", "read"), [("", None), ("  ", None), (" ms ", "ms"),
                                             ("us", "us")])
def test_the_typed_time_unit_is_read(typed, read):
    assert uploads.page_time_unit(typed) == read


@pytest.mark.parametrize(("typed", "said"), [
    ("m", "time base unit: 'm' is not a unit of time; expected s, ms or us"),
    ("MS", "time base unit: 'MS' is not a unit of time: 'MS' is ambiguous: unit prefixes are "
           "case-sensitive, and it reads as ms (0.001 s) or Ms (1e+06 s); expected s, ms or us"),
])
def test_a_typed_time_unit_that_is_none_is_refused_naming_the_field(typed, said):
    with pytest.raises(ParameterError) as info:
        uploads.page_time_unit(typed)
    assert str(info.value) == said


def test_the_time_base_unit_columns_help_says_it_overrides_a_stated_unit():
    # The column's help said the cell applies "where its time column states none or one
    # pidcore does not read", but a cell of 'ms' beside a CSV time column stated in s reads
    # that time in ms (as `pidcore analyze --time-unit` does): the help must say so.
    from pathlib import Path

    sample = Path(__file__).resolve().parents[1] / (
        "data_samples/exports/synthetic_f500Hz_a1g_fill50_acrylic.csv")
    as_stated = uploads.parse_upload(sample.name, sample.read_bytes())
    overridden = uploads.parse_upload(sample.name, sample.read_bytes(), time_unit="ms")
    assert as_stated.error is None and overridden.error is None
    rate = as_stated.measurement.channels[0].sample_rate_hz
    # the stated 's' is overridden, not kept: every time 1000 x shorter, the rate 1000 x higher
    assert overridden.measurement.channels[0].sample_rate_hz == pytest.approx(1000 * rate)
    assert "overrides the unit its time column states" in uploads.TIME_UNIT_COLUMN_HELP
    assert "(a note says so)" in uploads.TIME_UNIT_COLUMN_HELP
