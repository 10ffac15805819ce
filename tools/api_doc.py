"""docs/api.md, generated from the public API's docstrings (`python -m tools.api_doc > docs/api.md`); a test keeps
the file current, so the reference cannot drift from the code."""

from __future__ import annotations

import inspect
import sys

import wormsim

# what docs/api.md documents, in reading order: every name of wormsim.__all__ but LEVELS (a line of the header)
ORDER = (
    "load_scenario",
    "Scenario",
    "simulate",
    "Result",
    "run_scenario",
    "ScenarioError",
    "SimulationError",
    "WormPair",
    "step",
)


METHODS = ("WormPair",)  # classes whose public methods and properties docs/api.md lists


def _members(cls) -> list[str]:
    """One list item per public method and property defined on cls: its signature and its docstring's first line."""
    out = []
    for name, obj in vars(cls).items():
        if name.startswith("_"):
            continue
        fn = obj.__func__ if isinstance(obj, classmethod | staticmethod) else obj
        doc = inspect.cleandoc(getattr(fn, "__doc__", None) or "").split("\n\n")[0].replace("\n", " ")
        if isinstance(obj, property):
            out.append(f"- `{name}` (property): {doc}")
        elif callable(fn):
            out.append(f"- `{name}{_signature(fn)}`: {doc}")
    return out


def _signature(obj) -> str:
    try:
        return str(inspect.signature(obj)).replace("NoneType", "None")
    except (TypeError, ValueError):
        return "(...)"


def _example(doc: str) -> list[str]:
    """The indented example lines of the package docstring, dedented."""
    lines = inspect.cleandoc(doc).splitlines()
    start = next(i for i, ln in enumerate(lines) if ln.startswith("    "))
    end = next(i for i in range(start, len(lines)) if lines[i] and not lines[i].startswith("    "))
    return [ln[4:] for ln in lines[start:end]][: end - start - 1]


def _sections(doc: str) -> list[str]:
    """Google-style sections (Args:, Returns:, ...) as bold headings with one list item per entry."""
    out: list[str] = []
    section = ""
    for ln in doc.splitlines():
        if ln.rstrip(":") in ("Args", "Returns", "Raises", "Attributes") and ln.endswith(":"):
            section = ln[:-1]
            out += ["", f"**{section}**", ""]
        elif (ln.startswith("        ") or section == "Returns") and ln.strip() and out and out[-1].startswith("- "):
            out[-1] += " " + ln.strip()
        elif ln.startswith("    "):
            out.append("- " + ln.strip())
        else:
            out.append(ln)
    return out


def markdown() -> str:
    lines = [
        "# Python API",
        "",
        "Generated from the docstrings by `python -m tools.api_doc > docs/api.md`; do not edit by hand.",
        "",
        "```python",
        *_example(wormsim.__doc__ or ""),
        "```",
        "",
        f"`wormsim.LEVELS`: the fidelity levels (scenario `model`): {', '.join(f'`{k}`' for k in wormsim.LEVELS)}.",
        "Scenario keys: docs/scenario.md. Summary keys with units and signs: docs/outputs.md "
        "(`wormsim.results.summary_keys.KEYS`).",
        "",
    ]
    for name in ORDER:
        obj = getattr(wormsim, name)
        kind = "class" if inspect.isclass(obj) else "def"
        sig = "" if inspect.isclass(obj) and issubclass(obj, Exception) else _signature(obj)
        if kind == "class" and name == "Scenario":
            sig = ""
        lines += [f"## `wormsim.{name}`", "", "```python", f"{kind} {name}{sig}", "```", ""]
        lines += [*_sections(inspect.cleandoc(obj.__doc__ or "")), ""]
        if name in METHODS:
            lines += ["**Methods and properties**", "", *_members(obj), ""]
    return "\n".join(lines).rstrip() + "\n"


if __name__ == "__main__":
    sys.stdout.write(markdown())
