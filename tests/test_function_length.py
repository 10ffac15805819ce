"""No function in wormsim/contact3d/ or wormsim/tooth/ is longer than MAX_LINES lines (its docstring included): the
sources read with ast, nothing imported."""

from __future__ import annotations

import ast
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
MAX_LINES = 150
PACKAGES = ("wormsim/contact3d", "wormsim/tooth")


def _long_functions(text: str, label: str) -> list[str]:
    """'label:line name (n lines)' of each function (nested ones too) longer than MAX_LINES in the source text."""
    out = []
    for node in ast.walk(ast.parse(text)):
        if isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef):
            n = node.end_lineno - node.lineno + 1
            if n > MAX_LINES:
                out.append(f"{label}:{node.lineno} {node.name} ({n} lines)")
    return out


def test_no_function_longer_than_the_limit():
    files = sorted(f for p in PACKAGES for f in (ROOT / p).glob("*.py"))
    assert len(files) > 20
    long = [s for f in files for s in _long_functions(f.read_text(encoding="utf-8"), str(f.relative_to(ROOT)))]
    assert long == []


def test_the_check_sees_a_long_function():
    body = "\n".join(f"    x{i} = {i}" for i in range(MAX_LINES))
    assert _long_functions(f"def short():\n{body[: body.rindex(chr(10))]}\n", "f") == []
    assert _long_functions(f"class A:\n    def long(self):\n    {body.replace(chr(10), chr(10) + '    ')}\n", "f") == [
        f"f:2 long ({MAX_LINES + 1} lines)"
    ]
