"""The package layout (docs/where.md, "Layout"): wormsim's top level holds only the public API and the command-line
entry, each subpackage imports only the layers below it, and the repository's tooling (tools/, studies/) stays out
of the installed package."""

from __future__ import annotations

import ast

import pytest

from tests.conftest import ROOT
from tests.test_tooth_layers import _imports

# the modules at wormsim's top level: the public API (wormsim/__init__.py and the modules behind its names) and the
# command-line entry (`python -m wormsim`)
TOP = {"__init__", "__main__", "exceptions", "pair", "run"}

# bottom to top: a package imports its own layer's or lower layers' packages (the levels not each other)
LAYERS = (
    ("meshgen", "wormsim.exceptions", "wormsim.runtime"),
    ("wormsim.scenario",),
    ("wormsim.physics", "wormsim.runfolder"),
    ("wormsim.tooth", "wormsim.rating"),
    ("wormsim.results",),
    ("wormsim.wedge", "wormsim.torsional", "wormsim.contact3d"),
    ("wormsim.pair", "wormsim.run"),
    ("wormsim.bench", "wormsim.sweep"),
    ("wormsim.cli",),
    ("wormsim", "wormsim.__main__"),
)
LEVELS = LAYERS[5]


def _package(module: str) -> str:
    parts = module.split(".")
    return "meshgen" if parts[0] == "meshgen" else ".".join(parts[:2])


def test_top_level_holds_only_the_public_api_and_the_entry():
    modules = {p.stem for p in (ROOT / "wormsim").glob("*.py")}
    assert modules == TOP, sorted(modules ^ TOP)


def test_every_package_has_a_layer():
    layer = {p for ps in LAYERS for p in ps}
    packages = {f"wormsim.{p.name}" for p in (ROOT / "wormsim").iterdir() if (p / "__init__.py").is_file()}
    packages |= {f"wormsim.{m}" for m in TOP - {"__init__"}}
    assert packages <= layer, sorted(packages - layer)


def test_packages_import_only_their_layer_and_below():
    rank = {p: i for i, ps in enumerate(LAYERS) for p in ps}
    bad = []
    for m, deps in _imports().items():
        a = _package(m)
        for d in deps:
            b = _package(d)
            if a == b or b == "wormsim":  # the package face (`import wormsim` for its version) is no layer
                continue
            if rank[b] > rank[a] or (a in LEVELS and b in LEVELS):
                bad.append((m, d))
    assert not bad, sorted(bad)


def test_tooling_stays_out_of_the_package():
    tomllib = pytest.importorskip("tomllib")
    packages = tomllib.loads((ROOT / "pyproject.toml").read_text())["tool"]["setuptools"]["packages"]
    assert not [p for p in packages if p.split(".")[0] in ("tools", "studies", "tests")], packages
    bad = []
    for path in [*(ROOT / "wormsim").rglob("*.py"), *(ROOT / "meshgen").rglob("*.py")]:
        for node in ast.walk(ast.parse(path.read_text())):
            names = (
                [a.name for a in node.names]
                if isinstance(node, ast.Import)
                else [node.module or ""]
                if isinstance(node, ast.ImportFrom)
                else []
            )
            bad += [(str(path.relative_to(ROOT)), n) for n in names if n.split(".")[0] in ("tools", "studies")]
    assert not bad, bad
