"""A reader of a ``calibrate --out`` folder that a kill left half-moved finishes the moves
first (as a database replays its journal on open), or refuses where it cannot write."""
import json

import pytest

from pidcore.calibrate.prediction import load_calibration
from pidcore.errors import ParameterError


def _calibration(path, median, predicted):
    doc = {"parameters": {"fixture_mass_kg": {"median": median, "low95": median / 2,
                                              "high95": median * 2}},
           "predictions": [{"frequency_hz": 100.0, "acceleration_g": 5.0, "fill_percent": 50.0,
                            "material": "acrylic", "measured": predicted,
                            "predicted": predicted, "low95": predicted / 2,
                            "high95": predicted * 2}]}
    path.write_text(json.dumps(doc), encoding="utf-8")


def _killed_mid_move(tmp_path):
    # the old calibration in cal; the new one committed (renamed .commit) but its
    # calibration.json not yet moved in: a plain read gets the OLD numbers beside new files
    out = tmp_path / "cal"
    out.mkdir()
    _calibration(out / "calibration.json", 0.2, 0.3)
    committed = tmp_path / f".cal.{'7c' * 8}.commit"
    committed.mkdir()
    _calibration(committed / "calibration.json", 0.4, 0.6)
    return out, committed


@pytest.mark.parametrize("given", ["folder", "file"])
def test_reading_a_killed_out_folder_gets_the_new_calibration_whole_and_says_so(tmp_path,
                                                                              given):
    out, committed = _killed_mid_move(tmp_path)
    calibrated = load_calibration(out if given == "folder" else out / "calibration.json")
    # exact: the numbers are the ones written, no arithmetic between
    assert calibrated.parameters["fixture_mass_kg"]["median"] == 0.4
    assert calibrated.predictions[0].sdc == 0.6
    assert calibrated.read_note == (
        f"{out}: a calibration killed while moving its outputs into it had left 1 of them to "
        "move (calibration.json); moved now, so it holds that calibration's whole set, not a "
        "mix with the earlier one")
    assert not committed.exists()
    assert load_calibration(out).read_note == ""  # once finished, nothing more to say


def test_reading_a_killed_out_folder_that_cannot_be_written_refuses_in_one_line(tmp_path,
                                                                             monkeypatch):
    import pidcore.atomic_files as atomic_files

    out, committed = _killed_mid_move(tmp_path)

    # a read-only folder (as root, chmod does not stop a rename: the refusal is simulated)
    def refused(commit, target):
        raise PermissionError(13, "Permission denied", str(target))

    monkeypatch.setattr(atomic_files, "_finish_moves", refused)
    with pytest.raises(ParameterError) as caught:
        load_calibration(out)
    message = str(caught.value)
    assert "\n" not in message
    assert message.startswith(f"{out}: holds the half-moved outputs of a killed calibration")
    # the library names the call that writes the folder; the CLI says it as its command
    assert message.endswith("or write the calibration into it again "
                            "(write_outputs(result, out_dir))")
    from pidcore.cli._vocabulary import cli_words

    assert cli_words(message, "report", names=[str(out)]).endswith(
        "or write the calibration into it again (pidcore calibrate --out)")
    assert (out / "calibration.json").exists() and committed.exists()  # nothing changed


def test_the_app_says_the_refusal_of_a_half_moved_folder_as_the_command_that_writes_it(
        tmp_path, monkeypatch):
    # the Compare page showed "... (write_outputs(result, out_dir))", a Python call the page's
    # user has no way to make; the page writes no calibration folder, the CLI does
    import pidcore.atomic_files as atomic_files
    from pidcore.app.calibration import CALIBRATION_ENV_VAR, available_calibrations

    out, committed = _killed_mid_move(tmp_path)

    def refused(commit, target):
        raise PermissionError(13, "Permission denied", str(target))

    monkeypatch.setattr(atomic_files, "_finish_moves", refused)
    [(calibration, reason)] = available_calibrations(
        None, environ={CALIBRATION_ENV_VAR: str(out)}, cwd=tmp_path)
    assert calibration is None
    assert reason.startswith(f"calibration not shown: {out}: holds the half-moved outputs")
    assert reason.endswith("or write the calibration into it again (`pidcore calibrate --out`)")
    assert "write_outputs" not in reason
    assert committed.exists()  # nothing changed
