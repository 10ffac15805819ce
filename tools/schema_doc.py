"""Markdown reference of the scenario schema, generated from the pydantic models (docs/scenario.md).

`python -m tools.schema_doc > docs/scenario.md` regenerates it; tests/tools/test_schema_doc.py fails when
the committed file is out of date, so the documentation cannot drift from the code.
"""

from __future__ import annotations

import typing

from pydantic import BaseModel
from pydantic_core import PydanticUndefined

from wormsim import scenario as S


def _models(ann) -> list[type[BaseModel]]:
    """The pydantic models an annotation holds (a block, an optional block, a list of blocks)."""
    if isinstance(ann, type) and issubclass(ann, BaseModel):
        return [ann]
    return [m for a in typing.get_args(ann) for m in _models(a)]


def blocks(root: type[BaseModel] = S.Scenario) -> list[tuple[str, type[BaseModel]]]:
    """Every block of the scenario, (dotted title, model) depth-first from the top level; a model met under several
    keys (materials.worm, materials.wheel) once, titled with all of them."""
    found: dict[type[BaseModel], list[str]] = {}

    def walk(title: str, model: type[BaseModel]) -> None:
        if model in found:
            found[model].append(title)
            return
        found[model] = [title]
        for name, f in model.model_fields.items():
            for sub in _models(f.annotation):
                walk(name if title == "(top level)" else f"{title}.{name}", sub)

    walk("(top level)", root)
    return [(" / ".join(titles), model) for model, titles in found.items()]


BLOCKS = blocks()


def _type_name(ann) -> str:
    origin = typing.get_origin(ann)
    if origin is typing.Literal:
        return " \\| ".join(f"`{a}`" for a in typing.get_args(ann))
    if origin in (typing.Union, getattr(__import__("types"), "UnionType", None)):
        parts = [a for a in typing.get_args(ann) if a is not type(None)]
        return " \\| ".join(_type_name(a) for a in parts)
    if origin is typing.Annotated:
        return _type_name(typing.get_args(ann)[0])
    if isinstance(ann, type) and issubclass(ann, BaseModel):
        return "block"
    return getattr(ann, "__name__", str(ann))


def _bounds(field) -> str:
    out = []
    for m in field.metadata:
        for attr, sym in (("gt", ">"), ("ge", ">="), ("lt", "<"), ("le", "<=")):
            v = getattr(m, attr, None)
            if v is not None:
                out.append(f"{sym} {v:g}" if isinstance(v, (int, float)) else f"{sym} {v}")
        if getattr(m, "pattern", None):
            out.append(f"matches `{m.pattern}`")
    return ", ".join(out)


def _default(field) -> str:
    if field.is_required():
        return "**required**"
    d = field.default
    if d is PydanticUndefined or isinstance(d, BaseModel):
        return "see block"
    return "-" if d is None else f"`{d}`"


def markdown() -> str:
    lines = [
        "# Scenario file reference",
        "",
        "Generated from `wormsim/scenario/schema.py` by `python -m tools.schema_doc`; do not edit by hand.",
        "Units are in the key names. Unknown keys are errors. `wormsim schema` prints the same as JSON schema.",
        "",
    ]
    for title, model in BLOCKS:
        lines += [f"## `{title}`", ""]
        if model.__doc__:
            lines += [" ".join(model.__doc__.split()), ""]
        lines += ["| key | type | default | allowed | meaning |", "| --- | --- | --- | --- | --- |"]
        for name, f in model.model_fields.items():
            desc = (f.description or "").replace("|", "\\|")
            lines.append(f"| `{name}` | {_type_name(f.annotation)} | {_default(f)} | {_bounds(f)} | {desc} |")
        lines.append("")
    lines += [
        "Cross-field rules: exactly one of `gear.normal_module_mm` / `gear.axial_module_mm`; exactly one of",
        "`gear.lead_angle_deg` / `gear.diameter_quotient`; `gear.dedendum_coef` > `gear.addendum_coef`; one of",
        "`contact.friction` / `contact.friction_group` / `contact.friction_static` + `contact.friction_dynamic`",
        "(dynamic <= static); exactly one of `drive.speed_rpm` / `drive.torque_nm`; `drive.on` != `load.on`;",
        "the gear models need `gear:` and `drive:`; `model: wedge` takes a `wedge:` block (seed 000's reduced",
        "model) or, without one, derives it from `gear:`, `drive:` (the worm at `drive.speed_rpm` > 0) and `load:`",
        '(on the wheel) (docs/wedge.md, "Derived from gear:"). Blocks and keys a level does not use are named on',
        "stderr and in summary.json `ignored_inputs`.",
        "",
    ]
    return "\n".join(lines)


if __name__ == "__main__":
    print(markdown(), end="")
