"""Links inside a store's records: a soft link at any depth of an entry, a link at the root
and an object hard-linked into two records are refused by every read, named by verify and
make removal refuse. A root link /zz = ExternalLink(secret.h5) with a DEM run's array a soft
link to it made get_dem_run return secret.h5's data, and verify called the store sound; a
soft link from one analysis to another's phasors was carried silently, and removing the other
left the first broken."""

from __future__ import annotations

import h5py
import numpy as np
import pytest

from pidcore.errors import StoreError
from pidcore.store import Store, remove_records


def _runs(tmp_path) -> Store:
    store = Store(tmp_path / "s.h5")
    for key in ("a", "b"):
        store.add_dem_run(key, {"sdc": 0.3}, arrays={"velocity_m_s": np.full(8, 1.0)})
    return store


def test_a_soft_link_to_a_root_link_to_another_file_is_never_followed(tmp_path):
    secret = tmp_path / "secret.h5"
    with h5py.File(secret, "w") as h5:
        h5["v"] = np.full(8, 42.0)
    store = _runs(tmp_path)
    with h5py.File(store.path, "r+") as h5:
        h5["zz_ext"] = h5py.ExternalLink(str(secret), "/v")
        del h5["dem_runs/a/arrays/velocity_m_s"]
        h5["dem_runs/a/arrays/velocity_m_s"] = h5py.SoftLink("/zz_ext")
    with pytest.raises(StoreError, match=r"s\.h5: not a readable pidcore store \(/zz_ext is an "
                                         r"external link to '.*secret\.h5'"):
        store.get_dem_run("a")
    # both named, each once: the root link, and the record's soft link to it
    (root, record) = store.verify()
    assert "s.h5: /zz_ext is an external link" in root
    assert "dem_runs/a" in record and "soft link to '/zz_ext'" in record


@pytest.mark.parametrize("name", ["zz", "measurements"])
def test_store_verify_names_a_root_external_link_as_damage_and_exits_1(tmp_path, capsys, name):
    # it said 'not a readable pidcore store' and exited 2, as for a file that is no store;
    # every read still refuses it, and the link is never followed
    from pidcore.cli import main

    store = _runs(tmp_path)
    with h5py.File(store.path, "r+") as h5:
        if name in h5:
            del h5[name]
        h5[name] = h5py.ExternalLink("/etc/passwd", "/")
    capsys.readouterr()
    assert main(["store", "verify", "--store", str(store.path)]) == 1
    out = capsys.readouterr().out.strip()
    assert out == (f"{store.path}: /{name} is an external link to '/etc/passwd'; expected the "
                   "store's own groups at its root (measurements, analyses, dem_runs, "
                   "calibrations)")
    with pytest.raises(StoreError, match=f"not a readable pidcore store \\(/{name} is an "
                                         "external link"):
        store.get_dem_run("a")
    assert main(["store", "list", "--store", str(store.path)]) == 2


@pytest.mark.parametrize("link", ["arrays/velocity_m_s", "record"])
def test_a_soft_link_from_one_record_into_another_is_damage_verify_names_and_reads_refuse(
        tmp_path, link):
    store = _runs(tmp_path)
    with h5py.File(store.path, "r+") as h5:
        del h5[f"dem_runs/a/{link}"]
        h5[f"dem_runs/a/{link}"] = h5py.SoftLink(f"/dem_runs/b/{link}")
    (problem,) = store.verify()
    assert f"s.h5:/dem_runs/a: '/dem_runs/a/{link}' is a soft link to '/dem_runs/b/{link}'" \
        in problem, problem
    with pytest.raises(StoreError, match="is a soft link"):
        store.get_dem_run("a")


def test_removal_refuses_a_store_whose_records_link_into_each_other_and_leaves_it_as_it_was(
        tmp_path):
    store = _runs(tmp_path)
    with h5py.File(store.path, "r+") as h5:
        del h5["dem_runs/a/arrays/velocity_m_s"]
        h5["dem_runs/a/arrays/velocity_m_s"] = h5py.SoftLink("/dem_runs/b/arrays/velocity_m_s")
    before = store.path.read_bytes()
    with pytest.raises(StoreError, match=r"is a soft link to .*; nothing was removed"):
        remove_records(store.path, ["b"])
    assert store.path.read_bytes() == before


def test_a_dataset_hard_linked_into_two_records_is_damage_verify_names_and_removal_refuses(
        tmp_path):
    store = _runs(tmp_path)
    with h5py.File(store.path, "r+") as h5:
        del h5["dem_runs/a/arrays/velocity_m_s"]
        h5["dem_runs/a/arrays/velocity_m_s"] = h5["dem_runs/b/arrays/velocity_m_s"]
    problems = store.verify()
    # both records hold the shared dataset: each is named
    assert len(problems) == 2 and all("is linked under 2 names" in p for p in problems)
    assert {"/dem_runs/a" in p for p in problems} == {True, False}
    with pytest.raises(StoreError, match="linked under 2 names.*nothing was removed"):
        remove_records(store.path, ["b"])
