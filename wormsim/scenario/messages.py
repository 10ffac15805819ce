"""The messages of a refused scenario: one line per problem, `source: field = value: what is allowed`, with the
allowed range from the field's bounds, a "did you mean" for a misspelt key and a unit hint for a size in metres.

Pure functions of a pydantic ValidationError and the model class whose fields it names (`top`); the schema and the
loader pass the Scenario.
"""

from __future__ import annotations

import difflib
import json
from typing import Any

from pydantic import BaseModel, ValidationError

MAX_PROBLEMS = 10  # validation problems listed; the rest is counted
MAX_SHOWN = 60  # characters of a value quoted in a message


def _fmt_loc(loc: tuple) -> str:
    return ".".join(str(p) for p in loc if not (isinstance(p, str) and p.startswith("function-")))


def abbreviate(value, limit: int = MAX_SHOWN) -> str:
    """A value as a message shows it: JSON-like, at most `limit` characters (huge ints, lists, strings cut)."""
    if isinstance(value, dict):
        return "{...}"
    if isinstance(value, (list, tuple)):
        text = "[...]" if len(value) > 20 else None
    else:
        text = None
    if text is None:
        try:
            text = json.dumps(value, default=str) if not isinstance(value, str) or len(value) < 10 * limit else None
        except (ValueError, TypeError, RecursionError):  # ints beyond the str conversion limit, cycles
            text = None
        if text is None:
            text = f"<{type(value).__name__}>"
    return text if len(text) <= limit else text[: limit - 3] + "..."


def _field_info(loc: tuple, top: type[BaseModel]):
    """The pydantic FieldInfo of a dotted location in `top` (None when the location is not a model field)."""
    import types
    import typing

    model: type[BaseModel] | None = top
    info = None
    for part in loc:
        if isinstance(part, str) and part.startswith("function-"):
            continue
        if model is None or not isinstance(part, str) or part not in model.model_fields:
            return None
        info = model.model_fields[part]
        model = None
        ann = info.annotation
        for cand in (
            typing.get_args(ann)
            if isinstance(ann, types.UnionType) or typing.get_origin(ann) is typing.Union
            else (ann,)
        ):
            if isinstance(cand, type) and issubclass(cand, BaseModel):
                model = cand
    return info


def _allowed_range(loc: tuple, root: type[BaseModel] | None, top: type[BaseModel]) -> str | None:
    """'allowed: 0 < x <= 50' from the field's numeric bounds, for messages about numbers."""
    info = _field_info(loc, top) if root is None else root.model_fields.get(str(loc[-1])) if len(loc) == 1 else None
    if info is None:
        return None
    lo = hi = None
    for m in info.metadata:
        for attr, sym in (("gt", "<"), ("ge", "<=")):
            if getattr(m, attr, None) is not None:
                lo = f"{getattr(m, attr):g} {sym} "
        for attr, sym in (("lt", "<"), ("le", "<=")):
            if getattr(m, attr, None) is not None:
                hi = f" {sym} {getattr(m, attr):g}"
    if lo is None and hi is None:
        return None
    return f"allowed: {lo or ''}{str(loc[-1])}{hi or ''}"


NUMBER_ERRORS = (
    "finite_number",
    "greater_than",
    "greater_than_equal",
    "less_than",
    "less_than_equal",
    "float_parsing",
    "float_type",
    "int_parsing",
    "int_type",
    "int_from_float",
)


# the millimetre sizes of a gear, none of which is below 0.1 mm in a real worm gear (a backlash or a deviation may be)
SIZE_KEYS_MM = ("normal_module_mm", "axial_module_mm", "face_width_mm", "worm_length_mm", "tool_diameter_mm")


def unit_hint(key: str, value: Any) -> str:
    """'; ... looks like metres' for a gear size in millimetres (SIZE_KEYS_MM) given below 0.1 (0.003 for a 3 mm
    module), else ''."""
    if key not in SIZE_KEYS_MM or isinstance(value, bool) or not isinstance(value, int | float):
        return ""
    if 0 < abs(value) < 0.1:
        return f"; {key} is in millimetres: {value:g} looks like metres ({value * 1000:g} mm?)"
    return ""


def _did_you_mean(loc: tuple, top: type[BaseModel]) -> str:
    """' (did you mean 'wheel_teeth'?)' for a misspelt key: the closest field names of its block (difflib)."""
    parent = loc[:-1]
    if parent:
        info = _field_info(parent, top)
        model = _block_model(info.annotation) if info is not None else None
    else:
        model = top
    if model is None or not isinstance(loc[-1], str):
        return ""
    # a key of another file kind (a scenario's `gear` in a sweep file) is no misspelling of itself
    close = [c for c in difflib.get_close_matches(loc[-1], list(model.model_fields), n=2, cutoff=0.6) if c != loc[-1]]
    return f" (did you mean {' or '.join(repr(c) for c in close)}?)" if close else ""


def _block_model(ann) -> type[BaseModel] | None:
    import types
    import typing

    for cand in (
        typing.get_args(ann) if isinstance(ann, types.UnionType) or typing.get_origin(ann) is typing.Union else (ann,)
    ):
        if isinstance(cand, type) and issubclass(cand, BaseModel):
            return cand
    return None


def describe_errors(err: ValidationError, source: str, root: type[BaseModel] | None, top: type[BaseModel]) -> str:
    """One line per problem: `source: field = value: what is allowed`; at most MAX_PROBLEMS lines, then a count.
    root: the model whose own fields a one-part location names (an assignment), else None; top: the model of the
    whole file, whose fields a dotted location and a misspelt key are looked up in."""
    lines = []
    errors = err.errors(include_url=False)
    for e in errors[:MAX_PROBLEMS]:
        field = abbreviate(_fmt_loc(e["loc"]) or "(top level)", 2 * MAX_SHOWN).strip('"')
        msg = e["msg"].removeprefix("Value error, ")
        if e["type"] == "extra_forbidden":
            lines.append(f"{source}: unknown key '{field}'{_did_you_mean(e['loc'], top)} (see docs/scenario.md)")
        elif e["type"] == "missing":
            lines.append(f"{source}: missing required field '{field}'")
        else:
            rng = _allowed_range(e["loc"], root, top) if e["type"] in NUMBER_ERRORS else None
            hint = unit_hint(str(e["loc"][-1]), e.get("input")) if e["loc"] else ""
            if msg.startswith(f"{field}."):  # a block's cross-field rule that names its own key and value
                lines.append(f"{source}: {msg}")
                continue
            value = abbreviate(e.get("input"))
            lines.append(f"{source}: {field} = {value}: {msg}" + (f"; {rng}" if rng else "") + hint)
    if len(errors) > MAX_PROBLEMS:
        lines.append(f"{source}: ... and {len(errors) - MAX_PROBLEMS} more problems")
    return "\n".join(lines)
