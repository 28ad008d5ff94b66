"""The calibrated specimen file of a ``calibrate --out`` folder that a kill left half-moved is
read after the moves are finished (as the folder's calibration.json is), said to the user, or
refused where the folder cannot be written; the app shows what reading a calibration did."""
import json

import pytest
from _build_leftovers import calibration_outputs_script

from pidcore.calibrate.outputs import SPECIMEN_FILE
from pidcore.cli import main
from pidcore.errors import ParameterError
from pidcore.specimen import hearing_read_notes, load_specimen, paper_specimen

#: The restitution of the earlier and of the new calibration's specimen: two files (and so two
#: hashes) that differ in one value, each a valid specimen.
_RESTITUTIONS = {"earlier": 0.6, "new": 0.8}

#: ``pidcore calibrate --out`` as the kill tests run it (tests/_build_leftovers.py's
#: calibration_outputs_script), with a real calibrated specimen: calibration.json names its
#: hash, so a mix of two calibrations shows as a specimen whose hash calibration.json does not name.
_OUTPUTS_SCRIPT = calibration_outputs_script(
    "import json\n"
    "from pidcore.specimen import paper_specimen\n"
    "specimen = paper_specimen().with_values(\n"
    f'    {{"pairs.particle_particle.restitution": {_RESTITUTIONS!r}[run]}})\n'
    "outputs.document_json = lambda document: json.dumps({'specimen_sha256': specimen.hash})\n"
    "outputs.specimen_text = lambda result: specimen.to_toml()\n")


def _hash(run: str) -> str:
    return paper_specimen().with_values(
        {"pairs.particle_particle.restitution": _RESTITUTIONS[run]}).hash


def _killed_at_move(tmp_path, renames: int):
    """``cal`` holding the earlier calibration, then the new one's write into it killed
    (SIGKILL's effect) at its rename number ``renames``: 0 is the commit, 1 the move of
    calibrated_specimen.toml (the first in name order), 2 that of calibration.json."""
    from _build_leftovers import run_killed_at_rename

    out = tmp_path / "cal"
    assert not run_killed_at_rename(_OUTPUTS_SCRIPT, 99, exchange=False, cwd=tmp_path,
                                    args=(str(out), "earlier"))
    assert run_killed_at_rename(_OUTPUTS_SCRIPT, renames, exchange=False, cwd=tmp_path,
                                args=(str(out), "new"))
    return out


def _journals(tmp_path) -> list[str]:
    return sorted(p.name for p in tmp_path.iterdir() if p.name.endswith(".commit"))


def _moved_note(out, left: int, names: str) -> str:
    return (f"{out}: a calibration killed while moving its outputs into it had left {left} of "
            f"them to move ({names}); moved now, so it holds that calibration's whole set, not "
            "a mix with the earlier one")


_LEFT = {1: (6, "calibrated_specimen.toml, calibration.json, posterior_pairs.png, "
                "predictions.png, summary.html, summary.md"),
         2: (5, "calibration.json, posterior_pairs.png, predictions.png, summary.html, "
                "summary.md")}


@pytest.mark.parametrize("renames", [1, 2])
def test_a_killed_calibrated_specimen_file_is_read_as_the_new_calibration_and_said(tmp_path,
                                                                                 renames):
    # killed before calibrated_specimen.toml was moved (1), the loader read the EARLIER
    # specimen beside a calibration that is the new one once finished; killed after it (2), the
    # new specimen beside the earlier calibration.json. Either way a mix, and nothing said.
    out = _killed_at_move(tmp_path, renames)
    assert _journals(tmp_path)  # the commit was made: the moves are left to do
    heard = []
    with hearing_read_notes(heard.append):
        specimen = load_specimen(out / SPECIMEN_FILE)
    named = json.loads((out / "calibration.json").read_text(encoding="utf-8"))
    # exact: hashes of the files written, no arithmetic between
    assert specimen.hash == named["specimen_sha256"] == _hash("new")
    assert specimen.read_note == _moved_note(out, *_LEFT[renames])
    assert heard == [specimen.read_note]  # said once, to whoever listens
    assert _journals(tmp_path) == []
    # once finished, nothing more to say (and the specimen is the same)
    again = load_specimen(out / SPECIMEN_FILE)
    assert again == specimen and again.read_note == ""


def test_a_specimen_file_of_another_name_beside_a_journal_is_read_as_it_is(tmp_path):
    # only the calibrated specimen's file is of the calibration: a user's own file in that
    # folder is no output the moves replace (read as before, nothing finished nor said)
    out = _killed_at_move(tmp_path, 1)
    own = out / "my_specimen.toml"
    own.write_text(paper_specimen().to_toml(), encoding="utf-8")
    assert load_specimen(own).read_note == ""
    assert _journals(tmp_path)


def test_a_command_given_the_killed_calibrated_specimen_says_the_moves_were_finished(
        tmp_path, capsys):
    # `--specimen cal/calibrated_specimen.toml`, of any command: the note on stderr, first
    out = _killed_at_move(tmp_path, 1)
    argv = ["report", "--specimen", str(out / SPECIMEN_FILE), "--store",
            str(tmp_path / "missing.h5"), "--out", str(tmp_path / "report")]
    assert main(argv) == 2  # the store is missing: refused after the specimen was read
    err = capsys.readouterr().err.splitlines()
    assert err[0] == f"pidcore report: note: {_moved_note(out, *_LEFT[1])}"
    assert err[1] == f"pidcore report: error: {tmp_path / 'missing.h5'}: store not found"
    assert _journals(tmp_path) == []
    assert load_specimen(out / SPECIMEN_FILE).hash == _hash("new")


def test_a_killed_calibrated_specimen_in_a_folder_that_cannot_be_written_is_refused(
        tmp_path, capsys, monkeypatch):
    from _build_leftovers import folder_contents

    import pidcore.atomic_files as atomic_files

    out = _killed_at_move(tmp_path, 1)
    before = folder_contents(tmp_path)

    # a read-only folder (as root, chmod does not stop a rename: the refusal is simulated as
    # tests/test_calibration_read_finishes_moves.py does)
    def refused(commit, target):
        raise PermissionError(13, "Permission denied", str(target))

    monkeypatch.setattr(atomic_files, "_finish_moves", refused)
    with pytest.raises(ParameterError) as caught:
        load_specimen(out / SPECIMEN_FILE)
    assert "\n" not in str(caught.value)
    assert str(caught.value).startswith(
        f"{out}: holds the half-moved outputs of a killed calibration")
    # --fill 200 (refused after the specimen is read): no DEM runs where it is not refused
    argv = ["dem", "run", "--specimen", str(out / SPECIMEN_FILE), "--frequency", "100",
            "--acceleration", "5", "--fill", "200"]
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1  # one line
    assert err.startswith(f"pidcore dem run: error: {out}: holds the half-moved outputs of a "
                          "killed calibration")
    assert err.rstrip().endswith("or write the calibration into it again "
                                 "(pidcore calibrate --out)")
    assert folder_contents(tmp_path) == before  # nothing changed


def _calibration_json(path, median):
    doc = {"parameters": {"fixture_mass_kg": {"median": median, "low95": median / 2,
                                              "high95": median * 2}},
           "predictions": [{"frequency_hz": 100.0, "acceleration_g": 5.0, "fill_percent": 50.0,
                            "material": "acrylic", "measured": 0.3, "predicted": 0.3,
                            "low95": 0.15, "high95": 0.6}]}
    path.write_text(json.dumps(doc), encoding="utf-8")


def test_the_app_shows_that_reading_a_calibration_finished_a_killed_ones_moves(tmp_path):
    # the app read $PIDCORE_CALIBRATION's folder (the moves finished) and said nothing of it
    from pidcore.app.calibration import (
        CALIBRATION_ENV_VAR,
        available_calibrations,
        calibration_read_notes,
        remember_read_notes,
    )

    out = tmp_path / "cal"
    out.mkdir()
    _calibration_json(out / "calibration.json", 0.2)
    committed = tmp_path / f".cal.{'7c' * 8}.commit"
    committed.mkdir()
    _calibration_json(committed / "calibration.json", 0.4)
    environ = {CALIBRATION_ENV_VAR: str(out)}
    offered = available_calibrations(None, environ, cwd=tmp_path)
    (calibration, _), = offered
    assert calibration.parameters["fixture_mass_kg"]["median"] == 0.4  # the new one, exact
    note = _moved_note(out, 1, "calibration.json")
    kept: list[str] = []
    assert remember_read_notes(kept, calibration_read_notes(offered)) == [note]
    # the next rerun's read has nothing to say: the session's note is still shown, once
    later = available_calibrations(None, environ, cwd=tmp_path)
    assert calibration_read_notes(later) == []
    assert remember_read_notes(kept, calibration_read_notes(later)) == [note]
    assert remember_read_notes(kept, [note]) == [note]
