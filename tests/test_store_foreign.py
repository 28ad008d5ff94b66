"""A store file with a foreign layout (a section that is a dataset, an entry that is a link
out of the file or to nothing) is refused in one line, read by nothing and never changed."""

from __future__ import annotations

import hashlib
import os

import h5py
import numpy as np
import pytest

from pidcore.cli import main
from pidcore.errors import StoreError
from pidcore.records import Channel, Measurement
from pidcore.store import Store


def _digest(path):
    return hashlib.sha256(path.read_bytes()).hexdigest()


def _section_dataset(section):
    def edit(h5):
        del h5[section]
        h5.create_dataset(section, data=np.arange(3))
    return edit


FOREIGN = {
    "measurements a dataset": (_section_dataset("measurements"),
                               "/measurements is a dataset"),
    "analyses a dataset": (_section_dataset("analyses"), "/analyses is a dataset"),
    "entry an external link": (lambda h5: h5["measurements"].__setitem__(
        "evil", h5py.ExternalLink("/etc/passwd", "/")), "external link to '/etc/passwd'"),
    "entry a soft link to nothing": (lambda h5: h5["analyses"].__setitem__(
        "zz", h5py.SoftLink("/nowhere")), "soft link to '/nowhere'"),
    "entry a dataset": (lambda h5: h5["dem_runs"].create_dataset("run", data=[1.0]),
                        "/dem_runs/run is a dataset"),
}


@pytest.mark.parametrize("case", list(FOREIGN))
def test_foreign_layout_is_refused_and_the_file_never_changes(tmp_path, capsys, case):
    edit, expected = FOREIGN[case]
    path = tmp_path / "pid_store.h5"
    fs = 25600.0
    t = np.arange(2560) / fs
    Store(path).add_measurement(Measurement("a.csv", (
        Channel("Force", "force", np.sin(2 * np.pi * 100 * t), fs, "N"),
        Channel("Velocity", "velocity", 0.01 * np.sin(2 * np.pi * 100 * t - 1.2), fs, "m/s")),
        sha256="ab" * 32, file_format="csv"))
    with h5py.File(path, "r+") as h5:
        edit(h5)
    before = _digest(path)
    with pytest.raises(StoreError, match=expected):
        Store(path)
    export = tmp_path / "run.csv"
    rows = (f"{a:.17g},{np.sin(2 * np.pi * 100 * a):.17g},"
            f"{0.01 * np.sin(2 * np.pi * 100 * a - 1.2):.17g}" for a in t)
    export.write_text("Time [s],Force [N],Velocity [m/s]\n" + "\n".join(rows) + "\n")
    assert main(["analyze", str(export), "--store", str(path)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and expected in err
    assert _digest(path) == before


def test_analysing_the_store_into_itself_is_refused_and_adds_no_copy(tmp_path, capsys):
    """'pidcore analyze S.h5 --store S.h5' read the store's measurement, whose hash is the
    store file's, and saved it again under that new key: a copy of a stored measurement, one
    more on every run (the store's hash changes with each save)."""
    fs = 25600.0
    t = np.arange(2560) / fs
    rows = (f"{a:.17g},{np.sin(2 * np.pi * 100 * a):.17g},"
            f"{0.01 * np.sin(2 * np.pi * 100 * a - 1.2):.17g}" for a in t)
    export = tmp_path / "run.csv"
    export.write_text("Time [s],Force [N],Velocity [m/s]\n" + "\n".join(rows) + "\n")
    store = tmp_path / "pid_store.h5"
    assert main(["analyze", str(export), "--store", str(store)]) == 0
    before = _digest(store)
    capsys.readouterr()
    assert main(["analyze", str(store), "--store", str(store)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "is the store being saved to" in err
    assert _digest(store) == before
    assert len(Store(store).list_measurements()) == 1
    assert main(["analyze", str(store), "--no-store"]) == 0  # reading it is fine


def test_the_store_among_the_files_is_refused_before_it_is_read(tmp_path, capsys):
    """'pidcore analyze *' run twice in a folder holding its pid_store.h5: the store (of two
    measurements) was read as an input and refused with 'holds 2 measurements ...; choose one
    with --key NAME', advice that only led to 'is the store being saved to'. report FILES
    --store did the same. Both now name the store at once and leave it unchanged."""
    fs = 25600.0
    t = np.arange(2560) / fs
    exports = []
    for i, f in enumerate((100.0, 200.0)):
        rows = (f"{a:.17g},{np.sin(2 * np.pi * f * a):.17g},"
                f"{0.01 * np.sin(2 * np.pi * f * a - 1.2):.17g}" for a in t)
        export = tmp_path / f"run{i}_fill50.csv"
        export.write_text("Time [s],Force [N],Velocity [m/s]\n" + "\n".join(rows) + "\n")
        exports.append(str(export))
    store = tmp_path / "pid_store.h5"
    assert main(["analyze", *exports, "--store", str(store)]) == 0
    before = _digest(store)
    capsys.readouterr()
    for args in (["analyze", *exports, str(store), "--store", str(store)],
                 ["report", *exports, str(store), "--store", str(store),
                  "--out", str(tmp_path / "out")]):
        assert main(args) == 2
        err = capsys.readouterr().err
        assert err.count("\n") == 1 and "is the store being saved to" in err, err
        assert "--key" not in err
        assert _digest(store) == before
    assert len(Store(store).list_measurements()) == 2


def test_a_store_path_that_is_a_loop_of_symbolic_links_is_refused_and_the_links_kept(tmp_path):
    loop_a, loop_b = tmp_path / "loopA.h5", tmp_path / "loopB.h5"
    loop_a.symlink_to(loop_b.name)
    loop_b.symlink_to(loop_a.name)
    with pytest.raises(StoreError, match=r"loopA\.h5: is a symbolic link that leads in a loop"):
        Store(loop_a).add_dem_run("a", {"sdc": 0.1})
    assert loop_a.is_symlink() and os.readlink(loop_a) == loop_b.name
