"""Layers kept by a test: every import under pidcore/ points down the README's Layout table.

The map of modules to layers is data: it is read from the README's ``## Layout`` table (first
column: module names in backticks, dotted for a submodule placed apart from its package;
second column: the layer number). Moving a package (say ``_app`` to ``app``) means editing
that table, not this file.
"""

from __future__ import annotations

import ast
import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
PACKAGE = ROOT / "pidcore"
README = ROOT / "README.md"

#: The only imports allowed to point up: ``.plot()`` methods of results forwarding to the
#: report's matplotlib figures (python-control style), each imported lazily inside the method.
#: (importing module, imported module) -> why.
UPWARD_ALLOWED: dict[tuple[str, str], str] = {
    ("pidcore.signal.power", "pidcore.report.figures_results"): "PowerAnalysis.plot forwards",
    ("pidcore.dem.result", "pidcore.report.figures_results"): "DemResult.plot forwards",
    ("pidcore.records", "pidcore.report.figures_results"): "Measurement.plot forwards",
    ("pidcore.loop", "pidcore.report.figures_results"): "ForceDisplacementLoop.plot forwards",
    ("pidcore.model.response", "pidcore.report.figures_results"):
        "HarmonicResponse.plot forwards",
    ("pidcore.calibrate.prediction", "pidcore.report.figures_results"):
        "Calibration.plot forwards",
}


def read_layers(text: str) -> dict[str, int]:
    """``{dotted name under pidcore: layer}`` from the ``## Layout`` table of the README."""
    section = text.split("\n## Layout", 1)[1].split("\n## ", 1)[0]
    layers: dict[str, int] = {}
    for line in section.splitlines():
        cells = [c.strip() for c in line.strip().strip("|").split("|")]
        if len(cells) < 2 or not line.lstrip().startswith("|"):
            continue
        level = re.match(r"(\d+)\b", cells[1])
        if level is None:  # header or separator row
            continue
        for name in re.findall(r"`([^`]+)`", cells[0]):
            layers[name] = int(level.group(1))
    return layers


def module_name(path: Path) -> str:
    parts = list(path.relative_to(PACKAGE.parent).with_suffix("").parts)
    if parts[-1] == "__init__":
        parts.pop()
    return ".".join(parts)


def _exists(dotted: str) -> bool:
    rel = Path(*dotted.split("."))
    return (PACKAGE.parent / rel).with_suffix(".py").is_file() or \
        (PACKAGE.parent / rel / "__init__.py").is_file()


def imported_modules(source: str, module: str, *, is_package: bool) -> list[tuple[int, str]]:
    """``(line, module)`` of every pidcore module ``source`` imports, anywhere in the file
    (lazy and TYPE_CHECKING imports included: they are dependencies too)."""
    package = module if is_package else module.rpartition(".")[0]
    found: list[tuple[int, str]] = []
    for node in ast.walk(ast.parse(source)):
        if isinstance(node, ast.Import):
            found += [(node.lineno, a.name) for a in node.names
                      if a.name.split(".")[0] == "pidcore"]
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = package.split(".")
                base = base[:len(base) - (node.level - 1)]
                target = ".".join(base + ([node.module] if node.module else []))
            else:
                target = node.module or ""
            if target.split(".")[0] != "pidcore":
                continue
            for alias in node.names:  # `from . import x`: x may be a module
                sub = f"{target}.{alias.name}"
                found.append((node.lineno, sub if _exists(sub) else target))
    return sorted(set(found))


def layer_of(dotted: str, layers: dict[str, int]) -> tuple[str, int] | None:
    """The most specific entry of ``layers`` that ``dotted`` (``pidcore.x.y``) falls under."""
    parts = dotted.split(".")[1:]
    if not parts:
        parts = ["__init__"]
    for n in range(len(parts), 0, -1):
        name = ".".join(parts[:n])
        if name in layers:
            return name, layers[name]
    return None


def violations(layers: dict[str, int], sources: dict[str, tuple[str, bool]]) -> list[str]:
    """One line per import that points to a higher layer (or to an unplaced module)."""
    out = []
    for module, (source, is_package) in sorted(sources.items()):
        own = layer_of(module, layers)
        if own is None:
            out.append(f"{module}: not placed in the README's Layout table")
            continue
        for line, target in imported_modules(source, module, is_package=is_package):
            theirs = layer_of(target, layers)
            if theirs is None:
                out.append(f"{module}:{line} imports {target}, not placed in the Layout table")
            elif theirs[1] > own[1] and (module, target) not in UPWARD_ALLOWED:
                out.append(f"{module}:{line} (layer {own[1]} {own[0]}) imports {target} "
                           f"(layer {theirs[1]} {theirs[0]}): against the data flow")
    return out


def _package_sources() -> dict[str, tuple[str, bool]]:
    return {module_name(p): (p.read_text(encoding="utf-8"), p.name == "__init__.py")
            for p in PACKAGE.rglob("*.py")}


@pytest.fixture(scope="module")
def layers() -> dict[str, int]:
    return read_layers(README.read_text(encoding="utf-8"))


def test_every_import_points_down_the_layers(layers):
    found = violations(layers, _package_sources())
    assert not found, "\n".join(found)


def test_layout_table_lists_every_top_level_module_and_nothing_else(layers):
    top = {p.stem for p in PACKAGE.glob("*.py")} | {
        p.name for p in PACKAGE.iterdir() if (p / "__init__.py").is_file()}
    listed_top = {name.split(".")[0] for name in layers}
    assert top - listed_top == set(), "missing from the README's Layout table"
    assert listed_top - top == set(), "in the README's Layout table but not in pidcore/"
    for name in layers:
        assert _exists("pidcore." + name) or name == "__init__", name


def test_allowed_upward_imports_are_still_needed(layers):
    # an exception nobody uses any more should be deleted, not left to excuse a new one
    sources = _package_sources()
    for module, target in UPWARD_ALLOWED:
        source, is_package = sources[module]
        assert target in {t for _, t in imported_modules(source, module, is_package=is_package)}


def test_checker_catches_an_upward_import(layers):
    # records (layer 1) importing the store (layer 4), relative and absolute, top level or lazy
    bad = {
        "pidcore.records": ("from .store import Store\n", False),
        "pidcore.io.csv_reader": ("def f():\n    import pidcore.report.table\n", False),
        "pidcore.signal": ("from ..measure import analyze_file\n", True),
    }
    found = violations(layers, bad)
    assert len(found) == 3
    assert any("pidcore.records:1" in v and "imports pidcore.store " in v for v in found)
    # and lets a downward one through
    assert violations(layers, {"pidcore.report.x": ("from ..signal import power\n", False)}) \
        == []
