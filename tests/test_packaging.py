"""The source distribution holds what its tests and README read, and its metadata is in the
form current build backends take (an SPDX license with its text shipped)."""

from __future__ import annotations

import tomllib
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
#: The folders outside the package that the tests read (samples, the app's entry and config,
#: docs named in the README, CI's script the README names), beside the tests themselves.
READ_BY_THE_TESTS = ("tests", "data_samples", "docs", "app", ".streamlit", ".ci")


def _sdist_files(root: Path, monkeypatch) -> set[str]:
    """The files beside pyproject.toml in ``root`` that MANIFEST.in puts in the sdist, by
    setuptools' own reading of it (the package's files come on top, from the package list)."""
    from setuptools.command.egg_info import FileList

    monkeypatch.chdir(root)
    files = FileList()
    files.findall()
    for line in (root / "MANIFEST.in").read_text(encoding="utf-8").splitlines():
        if line.strip() and not line.lstrip().startswith("#"):
            files.process_template_line(line)
    return set(files.files)


def _tree_files(root: Path, folder: str) -> set[str]:
    return {p.relative_to(root).as_posix() for p in (root / folder).rglob("*")
            if p.is_file() and "__pycache__" not in p.parts}


def test_the_sdist_holds_every_file_of_the_folders_its_tests_read(monkeypatch):
    # it shipped tests/ without data_samples/, app/ and .streamlit/: 53 test files failed
    # from an unpacked sdist. From the repository this compares with the working tree
    # (Python leaves only __pycache__ there, left out below); from an sdist, with itself.
    shipped = _sdist_files(ROOT, monkeypatch)
    missing = {folder: sorted(_tree_files(ROOT, folder) - shipped)[:3]
               for folder in READ_BY_THE_TESTS}
    assert {k: v for k, v in missing.items() if v} == {}


def test_what_running_the_tests_leaves_in_the_tree_stays_out_of_the_sdist(tmp_path,
                                                                          monkeypatch):
    # bytecode, Numba's cache index and data files, a store's lock beside the samples: each
    # would ship from a developer's tree that had run the tests, one of each made here
    (tmp_path / "MANIFEST.in").write_bytes((ROOT / "MANIFEST.in").read_bytes())
    made = {"tests/test_a.py": True, "tests/__pycache__/test_a.cpython-311.pyc": False,
            "data_samples/dem_table3.h5": True, "data_samples/dem_table3.h5.lock": False,
            "tests/__pycache__/kernel.step-12.py311.nbi": False,
            "tests/__pycache__/kernel.step-12.py311.1.nbc": False, ".ci/run": True}
    for name in made:
        (tmp_path / name).parent.mkdir(parents=True, exist_ok=True)
        (tmp_path / name).write_bytes(b"x")
    shipped = _sdist_files(tmp_path, monkeypatch)
    assert {name: name in shipped for name in made} == made


def test_the_license_is_an_spdx_expression_whose_text_ships():
    # a TOML table (license = { text = "MIT" }) is deprecated by setuptools, refused from
    # 2027-02-18; the expression needs setuptools >= 77 (PEP 639) and the file it names
    project = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))
    assert project["project"]["license"] == "MIT"
    texts = project["project"]["license-files"]
    assert texts and all((ROOT / name).read_text(encoding="utf-8").startswith("MIT License")
                         for name in texts)
    assert "setuptools>=77" in project["build-system"]["requires"]

