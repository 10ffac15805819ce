"""Layers of the tooth contact (docs/contact3d.md, "Layout"): wormsim.tooth imports without MuJoCo; contact3d and
torsional both build on tooth/ and neither imports the other; no import circle among wormsim's modules."""

from __future__ import annotations

import ast
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
PACKAGES = ("wormsim", "meshgen")


def _module_name(path: Path) -> str:
    parts = path.relative_to(ROOT).with_suffix("").parts
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def _imports() -> dict[str, set[str]]:
    """Every module of wormsim and meshgen -> the first-party modules it imports (at the top or inside functions)."""
    files = [p for pkg in PACKAGES for p in (ROOT / pkg).rglob("*.py")]
    mods = {_module_name(p): p for p in files}
    out: dict[str, set[str]] = {}
    for name, path in mods.items():
        deps: set[str] = set()
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.Import):
                targets = [a.name for a in node.names]
            elif isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
                targets = [node.module] + [f"{node.module}.{a.name}" for a in node.names]
            else:
                continue
            deps |= {t for t in targets if t in mods and t != name}
        out[name] = deps
    return out


def test_tooth_imports_without_mujoco():
    code = (
        "import sys; sys.modules['mujoco'] = None\n"
        "import pkgutil, importlib, wormsim.tooth\n"
        "for m in pkgutil.iter_modules(wormsim.tooth.__path__): importlib.import_module('wormsim.tooth.' + m.name)\n"
        "import wormsim.torsional.dynamics, wormsim.torsional.loaded_tca\n"
        "print('imported')\n"
    )
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=ROOT, timeout=300)
    assert r.returncode == 0 and "imported" in r.stdout, r.stderr[-2000:]


def test_contact3d_and_torsional_do_not_import_each_other():
    imp = _imports()
    for a, b in (("wormsim.contact3d", "wormsim.torsional"), ("wormsim.torsional", "wormsim.contact3d")):
        bad = sorted((m, d) for m, ds in imp.items() if m.startswith(a) for d in ds if d.startswith(b))
        assert not bad, bad
    up = ("wormsim.contact3d", "wormsim.torsional", "wormsim.bench", "wormsim.sweep", "wormsim.cli", "wormsim.run")
    bad = sorted((m, d) for m, ds in imp.items() if m.startswith("wormsim.tooth") for d in ds if d.startswith(up))
    assert not bad, bad


def test_no_import_circle():
    imp = _imports()
    # a package's __init__ naming its own submodules is not a circle of files
    edges = {m: {d for d in ds if not m.startswith(d + ".")} for m, ds in imp.items()}
    state: dict[str, int] = {}
    stack: list[str] = []
    cycles: list[list[str]] = []

    def visit(m: str) -> None:
        state[m] = 1
        stack.append(m)
        for d in sorted(edges.get(m, ())):
            if state.get(d) == 1:
                cycles.append(stack[stack.index(d) :] + [d])
            elif d not in state:
                visit(d)
        stack.pop()
        state[m] = 2

    for m in sorted(edges):
        if m not in state:
            visit(m)
    assert not cycles, cycles
