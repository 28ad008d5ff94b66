"""A channel whose name says one role and whose unit another (``Velocity [N]``): the unit decides
and the output says so, or the refusal names the column; against the analytic truth of
F = F0 sin(wt), V = V0 sin(wt - phi) (loss factor tan(90 deg - phi))."""

from __future__ import annotations

import math

import numpy as np
import pytest
from test_io_din_headers import ETA, F0, FREQ, FS, PHI, V0, write_export

from pidcore.cli import main
from pidcore.errors import ChannelError
from pidcore.measure import AnalysisOptions, analyze_file

NOTE = ("channel 'Velocity' is named like a velocity but its unit 'N' is a force unit: used as "
        "the force, as its unit says")


def test_a_velocity_named_column_in_newtons_is_the_force_and_the_notes_say_so(tmp_path):
    # the force was exported under the name 'Velocity' (the units are the acquisition's, the
    # name typed): it was used as the force without a word
    path = write_export(tmp_path / "swapped.csv", ("Time [s]", "Velocity [N]", "Point1:+Z [m/s]"),
                        (1.0, 1.0, 1.0))
    record = analyze_file(path)
    assert record.channels_used["force"] == "Velocity"
    # 12 printed digits, whole periods: exact to ~1e-10; 1e-6 catches any unit or phase slip
    assert record.analysis.loss_factor == pytest.approx(ETA, rel=1e-6)
    (note,) = [n for n in record.notes if "named like" in n]
    assert NOTE in note
    assert note.endswith("name it with velocity='Velocity' and give its unit with "
                         "velocity_unit=UNIT")


def test_the_cli_prints_the_note_in_its_own_option_names(tmp_path, capsys):
    path = write_export(tmp_path / "swapped.csv", ("Time [s]", "Velocity [N]", "LDV [m/s]"),
                        (1.0, 1.0, 1.0))
    assert main(["analyze", str(path), "--no-store", "--no-progress"]) == 0
    out = capsys.readouterr().out
    assert NOTE in out
    assert "--velocity 'Velocity'" in out and "--velocity-unit UNIT" in out


def test_a_names_role_left_unfilled_because_of_its_unit_is_refused_naming_the_column(tmp_path):
    # 'Force [N]' and 'Velocity [N]': two forces, the one named force taken, no velocity; the
    # refusal "no velocity or acceleration channel among 'Force', 'Velocity'" did not say why
    # the column named Velocity was none
    path = write_export(tmp_path / "two_forces.csv", ("Time [s]", "Force [N]", "Velocity [N]"),
                        (1.0, 1.0, 1.0))
    with pytest.raises(ChannelError) as info:
        analyze_file(path)
    message = str(info.value)
    assert "\n" not in message
    assert "no velocity or acceleration channel" in message
    assert "('Velocity' is named like a velocity but its unit 'N' is a force unit: if it is " \
           "the velocity, name it with velocity='Velocity' and give its unit with " \
           "velocity_unit=UNIT)" in message


def test_naming_the_channel_for_its_role_with_a_unit_reads_it_so(tmp_path):
    # the way out the note offers works: the column's numbers are a velocity in m/s
    path = write_export(tmp_path / "label.csv", ("Time [s]", "Force [N]", "Velocity [N]"),
                        (1.0, 1.0, 1.0))
    record = analyze_file(path, AnalysisOptions(velocity="Velocity", velocity_unit="m/s"))
    assert record.analysis.loss_factor == pytest.approx(ETA, rel=1e-6)
    assert not [n for n in record.notes if "named like" in n]


def test_an_unused_velocity_named_column_in_g_beside_the_acceleration_is_said(tmp_path, capsys):
    # 'Velocity [g]' (a velocity in m/s exported under the unit g) beside 'Acceleration
    # [m/s^2]': two accelerations by their units, the one named so taken as the motion, and
    # the velocity-named one left out with only "ignored channels (not needed): 'Velocity'";
    # the note of a name against its unit was said only of a channel used
    t = np.arange(int(FS)) / FS
    w = 2 * math.pi * FREQ
    rows = zip(t, F0 * np.sin(w * t), V0 * np.sin(w * t - PHI),
               w * V0 * np.cos(w * t - PHI), strict=True)
    path = tmp_path / "velocity_in_g.csv"
    path.write_text("Time [s],Force [N],Velocity [g],Acceleration [m/s^2]\n" + "".join(
        ",".join(f"{x:.12g}" for x in row) + "\n" for row in rows), encoding="utf-8")
    record = analyze_file(path)
    assert record.channels_used.get("velocity", "") == ""
    assert record.channels_used["acceleration"] == "Acceleration"
    # the acceleration is the velocity's exact derivative: its loss factor is the truth (12
    # printed digits over whole periods; 1e-6 catches any unit or phase slip)
    assert record.analysis.loss_factor == pytest.approx(ETA, rel=1e-6)
    (note,) = [n for n in record.notes if "named like" in n]
    assert ("channel 'Velocity' is named like a velocity but its unit 'g' is an acceleration "
            "unit: not used (its unit makes it an acceleration, its name a velocity: check "
            "which quantity it holds); if it is the velocity, name it with "
            "velocity='Velocity' and give its unit with velocity_unit=UNIT") in note
    assert main(["analyze", str(path), "--no-store", "--no-progress"]) == 0
    out = capsys.readouterr().out
    assert "'Velocity' is named like a velocity but its unit 'g' is an acceleration unit: " \
        "not used" in out and "--velocity 'Velocity'" in out
