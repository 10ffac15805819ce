"""Every module with behaviour of its own is imported by a test (its behaviour is checked where it is written, not only
through the commands), and the tests mirror the packages: tests/<package>/test_<module>.py."""

from __future__ import annotations

import ast
import importlib
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
PACKAGES = ("wormsim", "meshgen")
# modules that run only as a whole through an entry of their own, each with the test that runs it
THROUGH = {
    "wormsim.__main__": "`python -m wormsim`: tests/test_packaging.py",
    "wormsim.cli.mesh": "`wormsim mesh`: tests/cli/test_mesh.py",
    "wormsim.rating.cmd": "`wormsim rate`: tests/rating/test_rate.py",
    "wormsim.sweep.preload": "the sweep's fork server: tests/sweep/test_runner.py (torsional sweeps)",
    "wormsim.sweep.preload_warm": "the sweep's fork server: tests/sweep/test_runner.py::test_local_workers_start_warm",
}


def _modules() -> set[str]:
    out = set()
    for pkg in PACKAGES:
        for f in (ROOT / pkg).rglob("*.py"):
            parts = f.relative_to(ROOT).with_suffix("").parts
            if parts[-1] != "__init__":
                out.add(".".join(parts))
    return out


def _defined_in(module: str, name: str) -> str | None:
    """The module that defines `name` as `module` exports it (a package's re-export), if it is one of ours."""
    try:
        obj = getattr(importlib.import_module(module), name)
    except (ImportError, AttributeError):
        return None
    if hasattr(obj, "__file__") and hasattr(obj, "__name__"):  # a submodule
        return obj.__name__
    return getattr(obj, "__module__", None)


def _imported_by_tests() -> set[str]:
    seen = set()
    for f in (ROOT / "tests").rglob("*.py"):
        for node in ast.walk(ast.parse(f.read_text())):
            if isinstance(node, ast.Import):
                seen.update(a.name for a in node.names)
            elif isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
                seen.add(node.module)
                seen.update(f"{node.module}.{a.name}" for a in node.names)  # a submodule
                if node.module.split(".")[0] in PACKAGES:
                    seen.update(filter(None, (_defined_in(node.module, a.name) for a in node.names)))
    return seen


def test_every_module_is_imported_by_a_test():
    modules = _modules()
    assert set(THROUGH) <= modules, sorted(set(THROUGH) - modules)
    missing = sorted(modules - _imported_by_tests() - set(THROUGH))
    assert not missing, f"modules no test imports: {missing}"


def test_tests_mirror_the_packages():
    """A test folder is named after a package or subpackage, and holds only tests and their helpers."""
    sub = {p.name for pkg in PACKAGES for p in (ROOT / pkg).iterdir() if (p / "__init__.py").exists()}
    for d in (ROOT / "tests").iterdir():
        if (d / "__init__.py").exists():
            assert d.name in sub | set(PACKAGES) | {"tools"}, f"tests/{d.name}/ mirrors no package"
            for f in d.glob("*.py"):
                assert f.name == "__init__.py" or f.name.startswith(("test_", "_")), f


def test_the_long_test_table_names_existing_files():
    """tests/conftest.py LONG_TESTS is keyed by the path under tests/: a stale key would run its tests in `make test`."""
    from tests.conftest import LONG_TESTS

    assert [k for k in LONG_TESTS if not (ROOT / "tests" / k).is_file()] == []
