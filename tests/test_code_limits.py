"""No function in wormsim/ or meshgen/ is longer than MAX_LINES lines (its docstring included) or takes more than
MAX_PARAMS parameters (self / cls not counted, *args and **kwargs one each): the sources read with ast, nothing
imported."""

from __future__ import annotations

import ast
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
MAX_LINES = 100
MAX_PARAMS = 10
PACKAGES = ("wormsim", "meshgen")


def n_params(node: ast.FunctionDef | ast.AsyncFunctionDef) -> int:
    """The function's parameters: positional and keyword ones without self / cls, *args and **kwargs one each."""
    a = node.args
    names = [x.arg for x in (*a.posonlyargs, *a.args, *a.kwonlyargs)]
    return sum(n not in ("self", "cls") for n in names) + (a.vararg is not None) + (a.kwarg is not None)


def over_limits(text: str) -> list[tuple[str, int, int, int]]:
    """(name, line, lines, parameters) of each function (nested ones and methods too) in the source text that is
    longer than MAX_LINES or takes more than MAX_PARAMS parameters."""
    out = []
    for node in ast.walk(ast.parse(text)):
        if isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef):
            n, p = node.end_lineno - node.lineno + 1, n_params(node)
            if n > MAX_LINES or p > MAX_PARAMS:
                out.append((node.name, node.lineno, n, p))
    return out


def _files() -> list[Path]:
    return sorted(f for p in PACKAGES for f in (ROOT / p).rglob("*.py"))


def test_no_function_over_the_limits():
    files = _files()
    assert len(files) > 100
    found = [
        f"{f.relative_to(ROOT)}:{line} {name} ({n} lines, {p} parameters)"
        for f in files
        for name, line, n, p in over_limits(f.read_text(encoding="utf-8"))
    ]
    assert found == []


def test_the_check_sees_a_long_function_and_many_parameters():
    body = "\n".join(f"    x{i} = {i}" for i in range(MAX_LINES))
    assert over_limits(f"def short():\n{body[: body.rindex(chr(10))]}\n") == []
    long = f"class A:\n    def long(self):\n    {body.replace(chr(10), chr(10) + '    ')}\n"
    assert over_limits(long) == [("long", 2, MAX_LINES + 1, 0)]
    ten = ", ".join(f"a{i}" for i in range(MAX_PARAMS - 2))
    assert over_limits(f"class B:\n    def f(self, {ten}, *args, **kw):\n        pass\n") == []
    assert over_limits(f"def g({ten}, b, *args, **kw):\n    pass\n") == [("g", 1, 2, MAX_PARAMS + 1)]
    assert over_limits(f"def h({ten}, *, b, c, d):\n    pass\n") == [("h", 1, 2, MAX_PARAMS + 1)]
