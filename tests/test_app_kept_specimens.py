"""Uploaded specimen files kept over a page reload (pidcore.app.kept_specimens), without
Streamlit."""

from __future__ import annotations

import hashlib
from pathlib import Path

import pytest

from pidcore.app.kept_specimens import (
    keep_specimen,
    kept_specimens_folder,
    restore_specimen,
    specimen_upload,
)
from pidcore.errors import ParameterError
from pidcore.specimen import load_specimen

STEEL = Path(__file__).resolve().parents[1] / "data_samples" / "specimens" / "steel_6mm.toml"


def _files(folder: Path) -> dict[str, bytes]:
    return {p.name: p.read_bytes() for p in sorted(folder.iterdir())} if folder.exists() else {}


def test_a_kept_upload_comes_back_by_its_hash_as_the_same_specimen(tmp_path):
    folder = kept_specimens_folder(tmp_path / "app_store.h5")
    assert folder == tmp_path / "app_store.h5.specimens"  # beside the store, not in it
    # edited by hand (comments, layout): its own bytes are kept, not the canonical text
    data = b"# my panel\n" + STEEL.read_bytes()
    kept, problem = keep_specimen(folder, "my panel.toml", data)
    assert problem == ""
    # the specimen's hash, as its DEM runs and saved tests carry it (not the bytes')
    assert kept.sha256 == load_specimen(STEEL).hash != hashlib.sha256(data).hexdigest()
    back = restore_specimen(folder, kept.sha256)
    assert (back.name, back.data) == ("my panel.toml", data)
    assert back.specimen.hash == load_specimen(STEEL).hash  # the same physics
    # the same bytes kept twice write nothing new
    before = _files(folder)
    keep_specimen(folder, "my panel.toml", data)
    assert _files(folder) == before


@pytest.mark.parametrize("data, key", [
    (b"name = 'x'\n[cell\n", "not valid TOML"),
    (STEEL.read_bytes().replace(b"radius_m", b"radius_mm"), "[particles]"),
])
def test_a_bad_upload_is_refused_by_the_clis_checker_and_not_kept(tmp_path, data, key):
    folder = tmp_path / "kept"
    with pytest.raises(ParameterError) as refused:
        keep_specimen(folder, "bad.toml", data)
    message = str(refused.value)
    assert message.startswith("bad.toml: ") and key in message and "\n" not in message
    # the message `pidcore specimen check` gives for the same bytes (one checker)
    from pidcore.specimen import Specimen

    with pytest.raises(ParameterError) as cli:
        Specimen.from_bytes(data, source="bad.toml")
    assert str(cli.value) == message
    assert _files(folder) == {}  # nothing written for a refused file


def test_an_unknown_or_malformed_hash_is_one_line_naming_the_address(tmp_path):
    folder = tmp_path / "kept"
    keep_specimen(folder, "steel.toml", STEEL.read_bytes())
    unknown = "0" * 64
    with pytest.raises(ParameterError) as refused:
        restore_specimen(folder, unknown)
    assert str(refused.value) == (
        f"specimen file 000000000000 (from the page address): not an uploaded specimen file "
        f"this app keeps (none in {folder}); upload the specimen file again")
    # an edited address never names another file: only 64 hex digits are read at all
    for bad in ("../../etc/passwd", "A" * 64, "0" * 63, ""):
        with pytest.raises(ParameterError, match=r"^specimen file '.*' \(from the page "
                                                 r"address\): expected the sha256"):
            restore_specimen(folder, bad)


def test_a_kept_file_changed_on_disk_is_refused_not_used(tmp_path):
    folder = tmp_path / "kept"
    kept, _ = keep_specimen(folder, "steel.toml", STEEL.read_bytes())
    path = folder / f"{kept.sha256}.toml"
    path.write_bytes(STEEL.read_bytes().replace(b"steel_6mm", b"other"))
    with pytest.raises(ParameterError, match=r"^steel\.toml \(specimen file [0-9a-f]{12}, from "
                                             r"the page address\): the kept file .* was "
                                             r"changed since it was uploaded"):
        restore_specimen(folder, kept.sha256)


def test_an_unwritable_folder_says_the_file_is_not_kept_but_uses_it(tmp_path):
    blocker = tmp_path / "blocked"
    blocker.write_text("a file where the folder would be")
    kept, problem = keep_specimen(blocker, "steel.toml", STEEL.read_bytes())
    assert kept.specimen.name == "steel_6mm"
    assert problem.startswith(f"steel.toml: not kept for a page reload: cannot write {blocker}")
    state = specimen_upload(blocker, upload=("steel.toml", STEEL.read_bytes()), sha256=None,
                            upload_seen=False)
    # the address names no file a reload could not restore
    assert state.kept is not None and state.sha256 is None and state.note == problem


def test_the_forms_state_over_upload_reload_and_removal(tmp_path):
    folder = tmp_path / "kept"
    data = STEEL.read_bytes()
    sha = load_specimen(STEEL).hash
    uploaded = specimen_upload(folder, upload=("steel.toml", data), sha256=None,
                               upload_seen=False)
    assert (uploaded.sha256, uploaded.upload_seen, uploaded.error) == (sha, True, None)
    # a reload: a fresh session, an empty uploader, the address's hash
    reloaded = specimen_upload(folder, upload=None, sha256=sha, upload_seen=False)
    assert reloaded.kept.data == data and reloaded.sha256 == sha and not reloaded.upload_seen
    assert reloaded.note == (f"steel.toml (steel_6mm [{sha[:6]}]): the specimen file uploaded "
                             "before the page was reloaded, kept beside the store; upload "
                             "another file to replace it")
    # the user removes the file from the uploader: forgotten, the address is cleared
    removed = specimen_upload(folder, upload=None, sha256=sha, upload_seen=True)
    assert (removed.kept, removed.sha256, removed.error) == (None, None, None)
    # a refused upload: an error, and no hash for the address
    bad = specimen_upload(folder, upload=("bad.toml", b"[cell\n"), sha256=sha,
                          upload_seen=True)
    assert bad.kept is None and bad.sha256 is None and bad.error.startswith("bad.toml: ")
    # an unknown hash in the address: refused (never the paper's coupon instead), kept in
    # the address until the user uploads or forgets
    unknown = specimen_upload(folder, upload=None, sha256="f" * 64, upload_seen=False)
    assert unknown.kept is None and unknown.sha256 == "f" * 64
    assert unknown.error.startswith("specimen file ffffffffffff (from the page address): not "
                                    "an uploaded specimen file this app keeps")
