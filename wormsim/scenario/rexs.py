"""REXS in and out: a worm stage from a REXS model (FVA Workbench, KISSsoft, MESYS ...) as a scenario, and a scenario
with its results back as REXS.

REXS (Reusable Engineering EXchange Standard, FVA) is a component / attribute / relation model with a unit on every
attribute; it comes as XML (.rexs) or JSON (.rexsj). The attribute ids, names and units used here are those of the
REXS 1.4 database (the FVA's REXS API repository, `models/rexs_schema_1.4_en.xml`); files of REXS 1.x are read.

Import (`wormsim import FILE --out SCENARIO.yaml`, `wormsim run FILE.rexs`): the one `worm_stage` with its
`worm_gear` (gear_1) and `worm_wheel` (gear_2), their materials (`reference` relations), the stage's lubricant, the
shafts that carry the gears (`assembly` relations) with their bearings (`side` relations), the driving shaft's speed
and the output shaft's torque. Each value is converted from its REXS unit to the scenario's unit here (the unit
table `_UNITS`), the only conversion; every scenario key carries its REXS source as a comment, and one line lists
every attribute not used.

Mapping (DIN 3975 names): m_x = worm axial_module (normal_module / cos(gamma) without it); q = d1 / m_x from the
worm's reference diameter; the hand from the sign of the worm's lead angle (negative: left); alpha_n from the
worm's pressure angle alpha_0 (ZA: alpha_0 is the axial angle, tan(alpha_n) = tan(alpha_0) cos(gamma)); addendum and
dedendum factors from the worm's tip and root diameters; the wheel's profile shift x2 =
addendum_modification_coefficient_worm_wheel, or (a - (d1 + d2) / 2) / m_x from the centre distance; bearings at
their u coordinates minus the gear's u coordinate on the same shaft; a bearing stiffness of 1e12 N/m or more is
rigid. Derived values are rounded to 12 significant digits so that an import -> export -> import round trip gives
the same scenario.

Export (`wormsim run ... --rexs OUT.rexs`): the stage as the import reads it, with the results as the REXS 1.4
result attributes where REXS defines them (`RESULT_ATTRIBUTES`).
"""

from __future__ import annotations

import json
import math
import re
import xml.etree.ElementTree as ET
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from wormsim.exceptions import ScenarioError

REXS_MAX_BYTES = 64 * 2**20  # a whole gear unit is a few MB
RIGID_N_PER_M = 1e12  # a REXS bearing stiffness at or above this is rigid (FVA Workbench writes 1e20)
WHEEL_TABLE = ("CuSn12Ni2", "CuSn12", "CuAl10Fe5Ni5", "GJS-400", "GJL-250", "POM")  # rating.wheel_material

# REXS unit -> (the scenario's unit, factor): scenario value = REXS value x factor
_UNITS: dict[str, dict[str, float]] = {
    "mm": {"mm": 1.0, "m": 1e3, "mum": 1e-3},
    "deg": {"deg": 1.0, "rad": 180.0 / math.pi},
    "rpm": {"1 / min": 1.0},
    "nm": {"N m": 1.0, "N mm": 1e-3, "kN m": 1e3},
    "gpa": {"N / mm^2": 1e-3, "MPa": 1e-3, "GPa": 1.0, "Pa": 1e-9},
    "kg_m3": {"kg / dm^3": 1e3, "kg / m^3": 1.0, "g / cm^3": 1e3},
    "n_per_um": {"N / m": 1e-6, "N / mm": 1e-3, "N / mum": 1.0},
    "mm2_s": {"mm^2 / s": 1.0},
    "c": {"C": 1.0},
    "h": {"h": 1.0},
    "none": {"none": 1.0, "": 1.0},
}


@dataclass
class Attr:
    id: str
    unit: str
    value: Any


@dataclass
class Component:
    id: int
    type: str
    name: str
    attrs: dict[str, Attr] = field(default_factory=dict)


@dataclass
class Relation:
    id: int
    type: str
    refs: list[tuple[int, str, str]]  # (component id, role, hint)
    order: int | None = None


@dataclass
class Model:
    version: str
    application: str
    components: dict[int, Component]
    relations: list[Relation]
    source: str = "REXS"


# ----------------------------------------------------------------------------- reading


def read_model(path: str | Path) -> Model:
    """A REXS model from a .rexs (XML) or .rexsj (JSON) file; ScenarioError (exit 2) for what is not REXS."""
    path = Path(path)
    if not path.is_file():
        raise ScenarioError(f"{path}: no such REXS file")
    try:
        if path.stat().st_size > REXS_MAX_BYTES:
            raise ScenarioError(f"{path}: larger than {REXS_MAX_BYTES // 2**20} MB; not read")
        raw = path.read_bytes()
    except OSError as exc:
        raise ScenarioError(f"{path}: cannot read: {exc.strerror or exc}") from None
    return parse(raw, path.name)


def parse(raw: bytes | str, source: str = "REXS") -> Model:
    """Parse REXS text: XML if it starts with '<', JSON if with '{' (whatever the file's suffix)."""
    text = raw.decode("utf-8-sig", errors="replace") if isinstance(raw, bytes) else raw
    head = text.lstrip()[:1]
    if head == "<":
        model = _parse_xml(text, source)
    elif head == "{":
        model = _parse_json(text, source)
    else:
        raise ScenarioError(f"{source}: not a REXS file: neither XML (.rexs) nor JSON (.rexsj)")
    if not re.match(r"^1(\.\d+)*$", model.version):
        raise ScenarioError(f"{source}: REXS version {model.version!r}; allowed: REXS 1.x")
    return model


def _value_xml(el: ET.Element) -> Any:
    arr = el.find("array")
    if arr is not None:
        return [_scalar(c.text or "") for c in arr.findall("c")]
    mat = el.find("matrix")
    if mat is not None:
        return [[_scalar(c.text or "") for c in r.findall("c")] for r in mat.findall("r")]
    return _scalar((el.text or "").strip())


def _scalar(s: str) -> Any:
    s = s.strip()
    if s in ("true", "false"):
        return s == "true"
    try:
        return int(s) if re.fullmatch(r"[-+]?\d+", s) else float(s)
    except ValueError:
        return s


def _parse_xml(text: str, source: str) -> Model:
    try:
        root = ET.fromstring(text.encode("utf-8"))
    except ET.ParseError as exc:
        raise ScenarioError(f"{source}: not a REXS file: XML error: {exc}") from None
    if root.tag != "model":
        raise ScenarioError(f"{source}: not a REXS file: the XML root is <{root.tag}>, REXS has <model>")
    comps: dict[int, Component] = {}
    for c in root.iter("component"):
        try:
            cid = int(c.get("id", ""))
        except ValueError:
            raise ScenarioError(f"{source}: component {c.get('id')!r}: the id is not an integer") from None
        comp = Component(cid, c.get("type", ""), c.get("name", ""))
        for a in c.findall("attribute"):
            comp.attrs[a.get("id", "")] = Attr(a.get("id", ""), a.get("unit", ""), _value_xml(a))
        comps[cid] = comp
    rels = []
    for r in root.iter("relation"):
        refs = [(int(x.get("id", "0")), x.get("role", ""), x.get("hint", "")) for x in r.findall("ref")]
        order = r.get("order")
        rels.append(Relation(int(r.get("id", "0")), r.get("type", ""), refs, int(order) if order else None))
    return Model(root.get("version", ""), root.get("applicationId", ""), comps, rels, source)


_JSON_VALUE_KEYS = (
    "floating_point",
    "integer",
    "boolean",
    "string",
    "enum",
    "reference_component",
    "floating_point_array",
    "integer_array",
    "boolean_array",
    "string_array",
    "enum_array",
    "floating_point_matrix",
    "integer_matrix",
    "file_reference",
)


def _parse_json(text: str, source: str) -> Model:
    try:
        doc = json.loads(text)
    except json.JSONDecodeError as exc:
        raise ScenarioError(f"{source}: not a REXS file: JSON error: {exc}") from None
    m = doc.get("model") if isinstance(doc, dict) else None
    if not isinstance(m, dict):
        raise ScenarioError(f"{source}: not a REXS file: the JSON has no 'model' object")
    comps: dict[int, Component] = {}
    for c in m.get("components", []):
        comp = Component(int(c["id"]), c.get("type", ""), c.get("name", ""))
        for a in c.get("attributes", []):
            key = next((k for k in _JSON_VALUE_KEYS if k in a), None)
            val = a[key] if key else next((v for k, v in a.items() if k not in ("id", "unit")), None)
            if isinstance(val, dict) and "code" in val:  # base64-coded arrays are not used here
                val = None
            comp.attrs[a["id"]] = Attr(a["id"], a.get("unit", ""), val)
        comps[comp.id] = comp
    rels = [
        Relation(
            int(r.get("id", 0)),
            r.get("type", ""),
            [(int(x["id"]), x.get("role", ""), x.get("hint", "")) for x in r.get("refs", [])],
            r.get("order"),
        )
        for r in m.get("relations", [])
    ]
    return Model(str(m.get("version", "")), str(m.get("applicationId", "")), comps, rels, source)


# ----------------------------------------------------------------------------- import


def _r(x: float) -> float:
    """12 significant digits: a derived value's float noise does not survive a round trip."""
    return float(f"{x:.12g}")


@dataclass
class Imported:
    """A scenario dict from a REXS model, with where each key came from and what was not used."""

    data: dict
    sources: dict[str, str]  # dotted scenario key -> "worm_gear[8].axial_module = 4.0 mm"
    unused: list[str]  # "type[id].attribute"
    notes: list[str]  # what the importer assumed or found odd (stderr and the YAML header)
    source: str = ""


class _Reader:
    """Attribute access with unit conversion and a record of what was used."""

    def __init__(self, model: Model):
        self.m = model
        self.used: set[tuple[int, str]] = set()
        self.sources: dict[str, str] = {}

    def has(self, c: Component, attr: str) -> bool:
        a = c.attrs.get(attr)
        return a is not None and a.value is not None and a.value != ""

    def get(self, c: Component, attr: str, unit: str, key: str | None = None, required: bool = True) -> Any:
        a = c.attrs.get(attr)
        if a is None or a.value is None or a.value == "":
            if required:
                raise ScenarioError(
                    f"{self.m.source}: {c.type}[{c.id}].{attr} is missing; wormsim needs it for the worm stage"
                )
            return None
        self.used.add((c.id, attr))
        v = a.value
        if unit != "raw":
            table = _UNITS[unit]
            if a.unit not in table:
                raise ScenarioError(
                    f"{self.m.source}: {c.type}[{c.id}].{attr} has unit {a.unit!r}; allowed: {', '.join(table)}"
                )
            f = table[a.unit]
            if isinstance(v, list):
                v = [float(x) * f for x in v]
            elif isinstance(v, bool) or not isinstance(v, int | float):
                raise ScenarioError(f"{self.m.source}: {c.type}[{c.id}].{attr} = {v!r}: not a number")
            else:
                v = float(v) * f
        if key is not None:
            shown = v if not isinstance(v, float) else f"{a.value:g}"
            self.sources[key] = f"{c.type}[{c.id}].{attr} = {shown}" + (
                f" {a.unit}" if a.unit not in ("", "none") else ""
            )
        return v

    def related(self, cid: int, rel_type: str, own_role: str | None = None) -> list[tuple[Component, str]]:
        """Components in relations of rel_type with cid (role own_role, if given): (component, its role)."""
        out = []
        for r in self.m.relations:
            if r.type != rel_type or not any(i == cid and (own_role is None or ro == own_role) for i, ro, _ in r.refs):
                continue
            out += [(self.m.components[i], ro) for i, ro, _ in r.refs if i != cid and i in self.m.components]
        return out


def _one_stage(model: Model) -> Component:
    stages = [c for c in model.components.values() if c.type == "worm_stage"]
    if len(stages) == 1:
        return stages[0]
    counts: dict[str, int] = {}
    for c in model.components.values():
        if c.type.endswith("_stage") or c.type in ("worm_gear", "worm_wheel", "cylindrical_gear", "bevel_gear"):
            counts[c.type] = counts.get(c.type, 0) + 1
    there = ", ".join(f"{n} {t}" for t, n in sorted(counts.items())) or "no gear stage at all"
    if not stages:
        raise ScenarioError(f"{model.source}: no worm stage (REXS worm_stage) in the model; it holds: {there}")
    ids = ", ".join(str(c.id) for c in stages)
    raise ScenarioError(
        f"{model.source}: {len(stages)} worm stages (worm_stage ids {ids}); wormsim takes a model with one ({there})"
    )


def _gears(rd: _Reader, stage: Component) -> tuple[Component, Component]:
    worm = wheel = None
    for c, role in rd.related(stage.id, "stage", "stage"):
        if c.type == "worm_gear" or role == "gear_1":
            worm = worm or (c if c.type == "worm_gear" else None)
        if c.type == "worm_wheel" or role == "gear_2":
            wheel = wheel or (c if c.type == "worm_wheel" else None)
    if worm is None or wheel is None:
        missing = " and ".join(n for n, c in (("worm_gear", worm), ("worm_wheel", wheel)) if c is None)
        raise ScenarioError(
            f"{rd.m.source}: worm_stage[{stage.id}] has no {missing} in a 'stage' relation; a worm stage needs both"
        )
    return worm, wheel


def import_model(model: Model, name: str = "rexs_stage") -> Imported:
    """The scenario dict of the model's one worm stage (module docstring)."""
    rd = _Reader(model)
    notes: list[str] = []
    stage = _one_stage(model)
    worm, wheel = _gears(rd, stage)
    gear, geo = _gear_block(rd, stage, worm, wheel, notes)
    data: dict[str, Any] = {
        "name": name,
        "description": f"imported from {model.source} (REXS {model.version}, {model.application or 'unknown tool'})",
        "model": "torsional",
        "gear": gear,
    }
    mats, wheel_designation = _materials(rd, worm, wheel, notes)
    strength = mats.pop("_pitting_strength_mpa", None)
    if mats:
        data["materials"] = mats
    shafts, drive, load, span = _shafts_and_loads(rd, worm, wheel, notes)
    if shafts:
        data["shafts"] = shafts
    data["drive"], data["load"] = drive, load
    data["rating"] = _rating_block(rd, stage, wheel_designation, span, notes)
    if strength is not None:
        data["rating"]["wheel_pitting_strength_mpa"] = strength
    used = rd.used
    unused = [f"{c.type}[{c.id}].{a}" for c in model.components.values() for a in c.attrs if (c.id, a) not in used]
    _ = geo
    return Imported(data, rd.sources, unused, notes, model.source)


def _gear_block(rd: _Reader, stage: Component, worm: Component, wheel: Component, notes: list[str]):
    g: dict[str, Any] = {}
    form = str(rd.get(worm, "flank_form", "raw", "gear.profile")).upper()
    if form not in ("ZA", "ZN", "ZI", "ZK", "ZC"):
        raise ScenarioError(f"{rd.m.source}: worm_gear[{worm.id}].flank_form = {form.lower()}; allowed: za zn zi zk zc")
    g["profile"] = form
    if rd.has(wheel, "flank_form"):
        rd.get(wheel, "flank_form", "raw")
    lead = rd.get(worm, "lead_angle_worm_gear", "deg", "gear.hand", required=False)
    g["hand"] = "left" if lead is not None and lead < 0 else "right"
    z1 = int(rd.get(worm, "number_of_teeth", "none", "gear.worm_starts"))
    z2 = int(rd.get(wheel, "number_of_teeth", "none", "gear.wheel_teeth"))
    g["worm_starts"], g["wheel_teeth"] = z1, z2
    d1 = rd.get(worm, "reference_diameter_worm_gear", "mm", "gear.diameter_quotient")
    if rd.has(worm, "axial_module"):
        m_x = rd.get(worm, "axial_module", "mm", "gear.axial_module_mm")
    elif rd.has(worm, "normal_module") and lead is not None:
        m_x = _r(rd.get(worm, "normal_module", "mm", "gear.axial_module_mm") / math.cos(math.radians(lead)))
    else:
        raise ScenarioError(
            f"{rd.m.source}: worm_gear[{worm.id}].axial_module is missing (and no normal_module with a lead angle); "
            "a worm stage needs the module"
        )
    g["axial_module_mm"] = m_x
    g["diameter_quotient"] = q = _r(d1 / m_x)
    gamma = math.atan(z1 / q)
    if lead is not None and abs(abs(lead) - math.degrees(gamma)) > 0.01:
        notes.append(
            f"worm_gear[{worm.id}].lead_angle_worm_gear = {lead:g} deg, but z1 / q gives {math.degrees(gamma):.4f} "
            "deg; the reference diameter and module are used"
        )
    a0 = rd.get(worm, "pressure_angle_worm_gear", "deg", "gear.normal_pressure_angle_deg")
    g["normal_pressure_angle_deg"] = (
        _r(math.degrees(math.atan(math.tan(math.radians(a0)) * math.cos(gamma)))) if form == "ZA" else a0
    )
    if form == "ZA":
        notes.append(f"ZA: the REXS pressure angle {a0:g} deg is the axial one; normal = atan(tan(alpha_0) cos gamma)")
    d2 = z2 * m_x
    if rd.has(wheel, "reference_diameter_worm_gear"):
        d2_file = rd.get(wheel, "reference_diameter_worm_gear", "mm")
        if abs(d2_file - d2) > 1e-3:
            notes.append(f"worm_wheel[{wheel.id}] reference diameter {d2_file:g} mm differs from z2 m_x = {d2:g} mm")
    if rd.has(worm, "tip_diameter_worm_gear"):
        da1 = rd.get(worm, "tip_diameter_worm_gear", "mm", "gear.addendum_coef")
        g["addendum_coef"] = _r((da1 - d1) / (2 * m_x))
    if rd.has(worm, "root_diameter_worm_gear"):
        df1 = rd.get(worm, "root_diameter_worm_gear", "mm", "gear.dedendum_coef")
        g["dedendum_coef"] = _r((d1 - df1) / (2 * m_x))
    x2 = _profile_shift(rd, stage, wheel, d1, d2, m_x, notes)
    g["profile_shift_coefficient"] = x2
    _check_wheel_form(rd, stage, wheel, g, d1, d2, m_x, x2, notes)
    for attr in ("effective_face_width_worm_wheel", "face_width_worm_wheel"):
        if rd.has(wheel, attr):
            g["face_width_mm"] = rd.get(wheel, attr, "mm", "gear.face_width_mm")
            break
    if rd.has(worm, "length_worm_gear"):
        g["worm_length_mm"] = rd.get(worm, "length_worm_gear", "mm", "gear.worm_length_mm")
    if rd.has(wheel, "outer_diameter_worm_wheel"):
        g["wheel_outside_diameter_mm"] = rd.get(
            wheel, "outer_diameter_worm_wheel", "mm", "gear.wheel_outside_diameter_mm"
        )
    return g, gamma


def _profile_shift(rd: _Reader, stage, wheel, d1, d2, m_x, notes) -> float:
    x_a = None
    if rd.has(stage, "center_distance"):
        a = rd.get(stage, "center_distance", "mm", "gear.profile_shift_coefficient")
        x_a = _r((a - (d1 + d2) / 2) / m_x)
    if rd.has(wheel, "addendum_modification_coefficient_worm_wheel"):
        x2 = _r(rd.get(wheel, "addendum_modification_coefficient_worm_wheel", "none", "gear.profile_shift_coefficient"))
        if x_a is not None and abs(x_a - x2) > 1e-6:
            notes.append(f"the centre distance gives x2 = {x_a:g}, the wheel's addendum modification {x2:g}: used")
        return x2
    if x_a is None:
        raise ScenarioError(
            f"{rd.m.source}: worm_stage[{stage.id}].center_distance is missing (and no "
            "addendum_modification_coefficient_worm_wheel); the stage needs one of them"
        )
    return x_a


def _check_wheel_form(rd: _Reader, stage, wheel, g, d1, d2, m_x, x2, notes) -> None:
    """The wheel's tip, root and throat as the file gives them against DIN 3975 with the worm's factors."""
    ha, hf = g.get("addendum_coef", 1.0), g.get("dedendum_coef", 1.2)
    a = (d1 + d2) / 2 + x2 * m_x
    expect = {
        "tip_diameter_worm_gear": d2 + 2 * m_x * (ha + x2),
        "root_diameter_worm_gear": d2 - 2 * m_x * (hf - x2),
    }
    for attr, want in expect.items():
        if rd.has(wheel, attr):
            got = rd.get(wheel, attr, "mm")
            if abs(got - want) > 1e-3:
                notes.append(
                    f"worm_wheel[{wheel.id}].{attr} = {got:g} mm; DIN 3975 with the worm's factors gives {want:.4f} mm "
                    "(used)"
                )
    if rd.has(wheel, "throat_radius_worm_wheel"):
        r_k = rd.get(wheel, "throat_radius_worm_wheel", "mm")
        want = a - (d2 + 2 * m_x * (ha + x2)) / 2
        if r_k > 0 and abs(r_k - want) > 1e-3:
            notes.append(
                f"worm_wheel[{wheel.id}].throat_radius_worm_wheel = {r_k:g} mm; the throat a - d_a2 / 2 = {want:.4f} "
                "mm is used"
            )
    if rd.has(stage, "center_distance_offset"):
        off = rd.get(stage, "center_distance_offset", "mm")
        if off != 0.0:
            notes.append(f"worm_stage[{stage.id}].center_distance_offset = {off:g} mm: set errors.center_distance_mm")


def _material(rd: _Reader, gear: Component, part: str) -> tuple[dict | None, str | None]:
    mats = [c for c, _ in rd.related(gear.id, "reference", "origin") if c.type == "material"]
    if not mats:
        return None, None
    m = mats[0]
    key = f"materials.{part}"
    out = {
        "youngs_modulus_gpa": _r(rd.get(m, "elastic_modulus", "gpa", f"{key}.youngs_modulus_gpa")),
        "poisson_ratio": rd.get(m, "poisson_ratio", "none", f"{key}.poisson_ratio"),
        "density_kg_m3": _r(rd.get(m, "density", "kg_m3", f"{key}.density_kg_m3")),
    }
    designation = (
        rd.get(m, "material_designation", "raw", required=False) if rd.has(m, "material_designation") else None
    )
    if part == "wheel":
        category = m.attrs.get("material_category_vdi_2736_2014")
        steel = category is not None and str(category.value) in ("steel", "cast_iron")
        if not steel and rd.has(m, "endurance_limit_flank"):  # a bronze's pitting strength (a steel: a placeholder)
            strength = rd.get(m, "endurance_limit_flank", "gpa", "rating.wheel_pitting_strength_mpa")
            out["_pitting_strength_mpa"] = strength * 1e3
        elif steel:
            rd.get(m, "material_category_vdi_2736_2014", "raw")
    return out, designation


def _materials(rd: _Reader, worm, wheel, notes) -> tuple[dict, str | None]:
    out = {}
    mw, _ = _material(rd, worm, "worm")
    if mw:
        out["worm"] = mw
    mh, desig = _material(rd, wheel, "wheel")
    if mh:
        strength = mh.pop("_pitting_strength_mpa", None)
        out["wheel"] = mh
        if strength is not None:
            out["_pitting_strength_mpa"] = _r(strength)
    return out, desig


def _bearings(rd: _Reader, shaft: Component) -> list[Component]:
    return [c for c, _ in rd.related(shaft.id, "side", "inner_part") if c.type in ("concept_bearing", "bearing")]


def _shaft_of(rd: _Reader, gear: Component) -> Component | None:
    owners = [c for c, role in rd.related(gear.id, "assembly", "part") if c.type == "shaft" and role == "assembly"]
    return owners[0] if owners else None


def _support(rd: _Reader, shaft: Component, gear: Component, part: str, notes) -> tuple[dict | None, float]:
    bearings = _bearings(rd, shaft)
    if len(bearings) != 2:
        notes.append(f"shaft[{shaft.id}] ({part}) has {len(bearings)} bearings; shafts.{part} needs two: left rigid")
        return None, 0.0
    u_gear = rd.get(gear, "u_coordinate_on_shaft", "mm", f"shafts.{part}.bearings_mm")
    us = []
    for b in bearings:
        attr = (
            "u_coordinate_on_shaft_inner_side"
            if rd.has(b, "u_coordinate_on_shaft_inner_side")
            else "u_coordinate_on_shaft"
        )
        us.append(rd.get(b, attr, "mm") - u_gear)
    order = sorted(range(2), key=lambda i: us[i])
    bearings = [bearings[i] for i in order]
    pos = [_r(us[i]) for i in order]
    sup: dict[str, Any] = {"bearings_mm": pos}
    axial = [
        rd.get(b, "axial_force_absorption", "raw") if rd.has(b, "axial_force_absorption") else None for b in bearings
    ]
    both = [i for i, x in enumerate(axial) if x == "both_directions"]
    sup["locating_bearing"] = both[0] if both else 0
    if not both and any(x in ("negative", "positive") for x in axial):
        notes.append(
            f"shaft[{shaft.id}] ({part}): the bearings take the axial force one direction each ({axial[0]} / "
            f"{axial[1]}); wormsim's locating bearing is bearing 0 for both directions"
        )
    kr = [rd.get(b, "radial_stiffness", "n_per_um") for b in bearings if rd.has(b, "radial_stiffness")]
    ka = [rd.get(b, "axial_stiffness", "n_per_um") for b in bearings if rd.has(b, "axial_stiffness")]
    rigid = RIGID_N_PER_M * 1e-6
    if kr and min(kr) < rigid:
        sup["radial_stiffness_n_per_um"] = _r(min(kr))
        rd.sources[f"shafts.{part}.radial_stiffness_n_per_um"] = "the bearings' radial_stiffness (N / m)"
        if max(kr) != min(kr):
            notes.append(f"shaft[{shaft.id}]: bearing radial stiffnesses {kr} N/um differ; the smaller is used")
    if ka and min(ka) < rigid:
        sup["axial_stiffness_n_per_um"] = _r(ka[sup["locating_bearing"]] if len(ka) == 2 else min(ka))
        rd.sources[f"shafts.{part}.axial_stiffness_n_per_um"] = "the locating bearing's axial_stiffness (N / m)"
    rd.sources[f"shafts.{part}"] = ", ".join(f"{b.type}[{b.id}]" for b in bearings) + f" on shaft[{shaft.id}]"
    rd.sources[f"shafts.{part}.bearings_mm"] = (
        "the bearings' u_coordinate_on_shaft_inner_side - the gear's u_coordinate_on_shaft"
    )
    if part == "worm":
        sections = [c for c, role in rd.related(shaft.id, "assembly", "assembly") if c.type == "shaft_section"]
        sup["bending"] = bool(sections)
        if sections:
            rd.sources["shafts.worm.bending"] = (
                f"{len(sections)} shaft_section of shaft[{shaft.id}] (the worm bends on its root-diameter section; the "
                "sections' diameters are not used)"
            )
    return sup, pos[1] - pos[0]


def _shafts_and_loads(rd: _Reader, worm, wheel, notes):
    shafts: dict[str, Any] = {}
    span = 0.0
    s1, s2 = _shaft_of(rd, worm), _shaft_of(rd, wheel)
    for part, shaft, gear in (("worm", s1, worm), ("wheel", s2, wheel)):
        if shaft is None:
            continue
        sup, sp = _support(rd, shaft, gear, part, notes)
        if sup:
            shafts[part] = sup
            if part == "worm":
                span = sp
    drive = load = None
    for part, shaft, gear in (("worm", s1, worm), ("wheel", s2, wheel)):
        for c in (shaft, gear):
            if c is not None and rd.has(c, "rotational_speed") and drive is None:
                n = rd.get(c, "rotational_speed", "rpm", "drive.speed_rpm")
                drive = {"on": part, "speed_rpm": abs(n)}
                rd.sources["drive.on"] = f"{c.type}[{c.id}] carries the speed"
                if rd.has(c, "defines_speed"):
                    rd.get(c, "defines_speed", "raw")
        loads = (
            [x for x, role in rd.related(shaft.id, "assembly", "assembly") if x.type == "external_load"]
            if shaft
            else []
        )
        for x in loads:
            if rd.has(x, "torque_around_u_axis") and load is None:
                t = rd.get(x, "torque_around_u_axis", "nm", "load.torque_nm")
                if t != 0.0:
                    load = {"on": part, "torque_nm": abs(t)}
                    rd.sources["load.on"] = f"external_load[{x.id}] on shaft[{shaft.id}]"
                    for a in ("defines_torque", "transmits_torque"):
                        if rd.has(x, a):
                            rd.get(x, a, "raw")
            for a in ("force_u_direction", "u_coordinate_on_shaft", "transmits_torque"):
                if rd.has(x, a) and (not isinstance(x.attrs[a].value, float) or x.attrs[a].value == 0.0):
                    rd.get(x, a, "raw")  # zero forces / the load's position: consistent with a pure torque
    if drive is None:
        raise ScenarioError(
            f"{rd.m.source}: no rotational_speed on the worm's or the wheel's shaft; the drive needs one"
        )
    if load is None:
        raise ScenarioError(
            f"{rd.m.source}: no external_load with torque_around_u_axis on the worm's or the wheel's shaft; the load "
            "needs one"
        )
    if drive["on"] == load["on"]:
        raise ScenarioError(f"{rd.m.source}: the speed and the torque are on the same shaft ({drive['on']})")
    return shafts, drive, load, span


_LUBRICANTS = {
    "non_water_soluble_polyglycol": "peg",
    "water_soluble_polyglycol": "peg",
    "polyglycol": "peg",
    "mineral_oil": "mineral",
    "polyalphaolefin": "pao",
    "pao": "pao",
}


def _rating_block(rd: _Reader, stage, wheel_designation, span, notes) -> dict:
    r: dict[str, Any] = {}
    if rd.has(stage, "application_factor_din_3996_2019"):
        r["application_factor"] = rd.get(stage, "application_factor_din_3996_2019", "none", "rating.application_factor")
    units = [c for c in rd.m.components.values() if c.type == "gear_unit"]
    if units and rd.has(units[0], "operating_time"):
        r["life_h"] = rd.get(units[0], "operating_time", "h", "rating.life_h")
    lubs = [c for c, _ in rd.related(stage.id, "reference", "origin") if c.type == "lubricant"]
    if lubs:
        lub = lubs[0]
        if rd.has(lub, "lubricant_type_iso_6336_2006"):
            t = str(rd.get(lub, "lubricant_type_iso_6336_2006", "raw", "rating.lubricant"))
            base = _LUBRICANTS.get(t)
            if base is None:
                base = "mineral"
                notes.append(f"lubricant type {t!r}: rated as mineral oil")
            r["lubricant"] = base
        if rd.has(lub, "viscosity_at_40_degree_celsius"):
            r["oil_viscosity_40_mm2_s"] = rd.get(
                lub, "viscosity_at_40_degree_celsius", "mm2_s", "rating.oil_viscosity_40_mm2_s"
            )
        if rd.has(lub, "viscosity_at_100_degree_celsius"):
            r["oil_viscosity_100_mm2_s"] = rd.get(
                lub, "viscosity_at_100_degree_celsius", "mm2_s", "rating.oil_viscosity_100_mm2_s"
            )
    if rd.has(stage, "temperature_lubricant"):
        r["oil_sump_temperature_c"] = rd.get(stage, "temperature_lubricant", "c", "rating.oil_sump_temperature_c")
    if wheel_designation in WHEEL_TABLE:
        r["wheel_material"] = wheel_designation
        rd.sources["rating.wheel_material"] = f"material_designation = {wheel_designation}"
    else:
        r["wheel_material"] = "CuSn12Ni2"
        notes.append(
            f"the wheel's material is given as {wheel_designation or 'nothing'}: worm wheels of such stages are "
            "bronze, so it looks like a placeholder; materials.wheel keeps the file's values, the rating rates "
            "CuSn12Ni2 (rating.wheel_material)"
        )
        rd.sources["rating.wheel_material"] = f"the file's wheel material {wheel_designation}: not in the rating table"
    if span > 0:
        r["worm_bearing_span_mm"] = _r(span)
        rd.sources["rating.worm_bearing_span_mm"] = "the worm shaft's bearing distance"
    return r


# ----------------------------------------------------------------------------- the scenario YAML


def _yaml_scalar(v: Any) -> str:
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, float):
        return repr(v)
    if isinstance(v, list):
        return "[" + ", ".join(_yaml_scalar(x) for x in v) + "]"
    if isinstance(v, str):
        return json.dumps(v) if (not re.fullmatch(r"[A-Za-z0-9_.-]+", v) or v in ("true", "false", "null")) else v
    return str(v)


def to_yaml(imp: Imported) -> str:
    """The scenario as commented YAML: each key with its REXS source, the notes, one line of unused attributes."""
    lines = [
        f"# imported by `wormsim import` from {imp.source}: REXS attribute ids in the comments, values converted to "
        "the units in the key names",
    ]
    lines += [f"# note: {n}" for n in imp.notes]

    def emit(d: dict, prefix: str, indent: int) -> None:
        for k, v in d.items():
            key = f"{prefix}{k}"
            src = imp.sources.get(key)
            com = f"  # {src}" if src else ""
            if isinstance(v, dict):
                lines.append(f"{'  ' * indent}{k}:{com}")
                emit(v, key + ".", indent + 1)
            else:
                lines.append(f"{'  ' * indent}{k}: {_yaml_scalar(v)}{com}")

    emit(imp.data, "", 0)
    lines.append("# not used: " + (", ".join(imp.unused) if imp.unused else "none"))
    return "\n".join(lines) + "\n"


def import_file(path: str | Path) -> Imported:
    path = Path(path)
    name = re.sub(r"[^a-z0-9_-]+", "_", path.stem.lower()).strip("_") or "rexs_stage"
    return import_model(read_model(path), name)


def is_rexs(path: str | Path) -> bool:
    return Path(path).suffix.lower() in (".rexs", ".rexsj")


# ----------------------------------------------------------------------------- export

# scenario-side result key -> (REXS component role, attribute id, REXS unit, factor from the result's unit)
RESULT_ATTRIBUTES: dict[str, tuple[str, str, str, float]] = {
    # the run (summary.json)
    "ratio": ("stage", "gear_ratio", "none", 1.0),
    "tangential_force_mean_n": ("stage", "nominal_tangential_force_at_reference_circle", "N", 1.0),
    "contact_pressure_mean_mpa": ("stage", "mean_hertzian_stress_ltca_worm_stage", "N / mm^2", 1.0),
    "contact_pressure_max_mpa": ("stage", "maximum_hertzian_stress_ltca_worm_stage", "N / mm^2", 1.0),
    "worm_torque_mean_nm": ("worm_data", "torque", "N m", 1.0),
    "wheel_torque_mean_nm": ("wheel_data", "torque", "N m", 1.0),
    # the rating (rating.json: DIN 3996 = ISO/TS 14521 method B)
    "efficiency_iso": ("stage", "gear_efficiency_in_reducer_din_3996_2019", "none", 1.0),
    "friction_iso": ("stage", "mean_tooth_coefficient_of_friction_din_3996_2019", "none", 1.0),
    "contact_stress_mean_iso_mpa": ("stage", "mean_hertzian_stress_din_3996_2019", "N / mm^2", 1.0),
    "sliding_speed_m_s": ("stage", "sliding_velocity_at_reference_diameter_din_3996_2019", "m / s", 1.0),
    "safety_pitting": ("stage", "safety_factor_pitting_din_3996_2019", "none", 1.0),
    "safety_root": ("stage", "safety_factor_root_without_wear_din_3996_2019", "none", 1.0),
    "safety_deflection": ("stage", "safety_factor_deflection_din_3996_2019", "none", 1.0),
    "safety_temperature": ("stage", "temperature_safety_factor_din_3996_2019", "none", 1.0),
    "oil_temperature_c": ("stage", "oil_sump_temperature_din_3996_2019", "C", 1.0),
}


class _Builder:
    def __init__(self):
        self.comps: dict[int, Component] = {}
        self.rels: list[Relation] = []

    def comp(self, cid: int, typ: str, name: str) -> Component:
        c = Component(cid, typ, name)
        self.comps[cid] = c
        return c

    def rel(self, typ: str, *refs: tuple[int, str]) -> None:
        self.rels.append(Relation(len(self.rels) + 1, typ, [(i, role, self.comps[i].type) for i, role in refs]))


def _set(c: Component, attr: str, unit: str, value: Any) -> None:
    c.attrs[attr] = Attr(attr, unit, value)


def export_model(scenario, summary: dict | None = None, rating: dict | None = None) -> Model:
    """The scenario's worm stage (what import_model reads) with the results as REXS attributes."""
    from meshgen.geometry import derive as _derive

    gear = scenario.gear
    if gear is None or scenario.drive is None or scenario.load is None:
        raise ScenarioError("--rexs: REXS export needs a gear:, drive: and load: block (model torsional or contact3d)")
    g = _derive(gear)
    b = _Builder()
    unit = b.comp(1, "gear_unit", "gear unit")
    if scenario.rating is not None:
        _set(unit, "operating_time", "h", scenario.rating.life_h)
    b.comp(2, "gear_casing", "casing")
    st = b.comp(3, "worm_stage", "worm stage")
    _set(st, "center_distance", "mm", g.a * 1e3)
    _set(st, "center_distance_offset", "mm", 0.0)
    b.comp(4, "shaft", "worm shaft")
    b.comp(5, "shaft", "wheel shaft")
    w1, w2 = b.comp(6, "worm_gear", "worm"), b.comp(7, "worm_wheel", "wheel")
    gamma = g.gamma
    _set(w1, "flank_form", "none", gear.profile.lower())
    _set(w2, "flank_form", "none", gear.profile.lower())
    _set(w1, "lead_angle_worm_gear", "deg", math.degrees(gamma) * (1 if gear.hand == "right" else -1))
    _set(w1, "number_of_teeth", "none", gear.worm_starts)
    _set(w2, "number_of_teeth", "none", gear.wheel_teeth)
    _set(w1, "axial_module", "mm", g.m_x * 1e3)
    _set(w1, "normal_module", "mm", g.m_n * 1e3)
    _set(w1, "reference_diameter_worm_gear", "mm", g.d1 * 1e3)
    _set(w2, "reference_diameter_worm_gear", "mm", g.d2 * 1e3)
    a0 = math.degrees(g.alpha_x if gear.profile == "ZA" else g.alpha_n)
    _set(w1, "pressure_angle_worm_gear", "deg", gear.normal_pressure_angle_deg if gear.profile != "ZA" else a0)
    _set(w1, "tip_diameter_worm_gear", "mm", 2 * g.r_a1 * 1e3)
    _set(w1, "root_diameter_worm_gear", "mm", 2 * g.r_f1 * 1e3)
    _set(w2, "tip_diameter_worm_gear", "mm", 2 * g.r_a2 * 1e3)
    _set(w2, "root_diameter_worm_gear", "mm", 2 * g.r_f2 * 1e3)
    _set(w2, "throat_radius_worm_wheel", "mm", g.throat_radius * 1e3)
    if gear.wheel_outside_diameter_mm is not None:
        _set(w2, "outer_diameter_worm_wheel", "mm", gear.wheel_outside_diameter_mm)
    _set(w2, "addendum_modification_coefficient_worm_wheel", "none", g.x2)
    _set(w2, "effective_face_width_worm_wheel", "mm", g.face_width * 1e3)
    _set(w1, "length_worm_gear", "mm", g.worm_length * 1e3)
    b.rel("stage", (3, "stage"), (6, "gear_1"), (7, "gear_2"))
    for sid in (3, 4, 5):
        b.rel("assembly", (1, "assembly"), (sid, "part"))
    b.rel("assembly", (4, "assembly"), (6, "part"))
    b.rel("assembly", (5, "assembly"), (7, "part"))
    for cid, part, mat in ((8, "worm", scenario.materials.worm), (9, "wheel", scenario.materials.wheel)):
        m = b.comp(cid, "material", f"{part} material")
        _set(m, "elastic_modulus", "N / mm^2", mat.youngs_modulus_gpa * 1e3)
        _set(m, "poisson_ratio", "none", mat.poisson_ratio)
        _set(m, "density", "kg / dm^3", mat.density_kg_m3 * 1e-3)
        if part == "wheel" and scenario.rating is not None and scenario.rating.wheel_material is not None:
            _set(m, "material_designation", "none", scenario.rating.wheel_material)
        if part == "wheel" and scenario.rating is not None and scenario.rating.wheel_pitting_strength_mpa is not None:
            _set(m, "endurance_limit_flank", "N / mm^2", scenario.rating.wheel_pitting_strength_mpa)
        b.rel("reference", (6 if part == "worm" else 7, "origin"), (cid, "referenced"))
    r = scenario.rating
    if r is not None:
        _set(st, "application_factor_din_3996_2019", "none", r.application_factor)
        if r.oil_sump_temperature_c is not None:
            _set(st, "temperature_lubricant", "C", r.oil_sump_temperature_c)
        lub = b.comp(10, "lubricant", "lubricant")
        lt = {"peg": "non_water_soluble_polyglycol", "mineral": "mineral_oil", "pao": "polyalphaolefin"}[r.lubricant]
        _set(lub, "lubricant_type_iso_6336_2006", "none", lt)
        _set(lub, "viscosity_at_40_degree_celsius", "mm^2 / s", r.oil_viscosity_40_mm2_s)
        if r.oil_viscosity_100_mm2_s is not None:
            _set(lub, "viscosity_at_100_degree_celsius", "mm^2 / s", r.oil_viscosity_100_mm2_s)
        b.rel("reference", (3, "origin"), (10, "referenced"))
    _export_shafts(b, scenario, g)
    _export_results(b, summary or {}, rating or {})
    return Model("1.4", "wormsim", b.comps, b.rels, "wormsim")


def _export_shafts(b: _Builder, scenario, g) -> None:
    sh = scenario.shafts
    drive, load = scenario.drive, scenario.load
    nid = 11
    for part, shaft_id, gear_id in (("worm", 4, 6), ("wheel", 5, 7)):
        sup = getattr(sh, part) if sh is not None else None
        gear_c = b.comps[gear_id]
        u0 = 0.0 if sup is None else max(0.0, -sup.bearings_mm[0]) + 10.0
        _set(gear_c, "u_coordinate_on_shaft", "mm", u0)
        if sup is not None:
            for i, pos in enumerate(sup.bearings_mm):
                bc = b.comp(nid, "concept_bearing", f"{part} bearing {i}")
                _set(bc, "u_coordinate_on_shaft_inner_side", "mm", u0 + pos)
                _set(
                    bc,
                    "axial_force_absorption",
                    "none",
                    "both_directions" if i == sup.locating_bearing else "no_direction",
                )
                kr = sup.radial_stiffness_n_per_um
                _set(bc, "radial_stiffness", "N / m", 1e20 if kr is None else kr * 1e6)
                ka = sup.axial_stiffness_n_per_um
                _set(bc, "axial_stiffness", "N / m", 1e20 if ka is None else ka * 1e6)
                b.rel("side", (2, "outer_part"), (shaft_id, "inner_part"), (nid, "assembly"))
                nid += 1
            if part == "worm" and sup.bending:
                sec = b.comp(nid, "shaft_section", "worm section")
                nid += 1
                d = 2 * g.r_f1 * 1e3
                _set(sec, "u_coordinate_on_shaft", "mm", u0 + sup.bearings_mm[0])
                _set(sec, "length", "mm", sup.bearings_mm[1] - sup.bearings_mm[0])
                for k in ("outer_diameter_begin", "outer_diameter_end"):
                    _set(sec, k, "mm", d)
                b.rel("assembly", (shaft_id, "assembly"), (sec.id, "part"))
        if drive.on == part:
            sc = b.comps[shaft_id]
            _set(sc, "rotational_speed", "1 / min", drive.speed_rpm if drive.speed_rpm is not None else 0.0)
            _set(sc, "defines_speed", "none", True)
        if load.on == part:
            ld = b.comp(nid, "external_load", f"{part} load")
            nid += 1
            _set(ld, "torque_around_u_axis", "N m", load.torque_nm)
            _set(ld, "defines_torque", "none", True)
            b.rel("assembly", (shaft_id, "assembly"), (ld.id, "part"))


def _export_results(b: _Builder, summary: dict, rating: dict) -> None:
    data = {}
    for part, gear_id, cid in (("worm", 6, 40), ("wheel", 7, 41)):
        c = b.comp(cid, "worm_stage_gear_data", f"{part} stage data")
        b.rel("stage_gear_data", (3, "stage"), (gear_id, "gear"), (cid, "stage_gear_data"))
        data[f"{part}_data"] = c
    roles = {"stage": b.comps[3], **data}
    for key, (role, attr, unit, f) in RESULT_ATTRIBUTES.items():
        v = summary.get(key, rating.get(key))
        if isinstance(v, bool) or not isinstance(v, int | float) or not math.isfinite(v):
            continue
        _set(roles[role], attr, unit, float(v) * f)


def _xml_value(el: ET.Element, v: Any) -> None:
    if isinstance(v, list):
        arr = ET.SubElement(el, "array")
        for x in v:
            ET.SubElement(arr, "c").text = repr(float(x))
    elif isinstance(v, bool):
        el.text = "true" if v else "false"
    elif isinstance(v, float):
        el.text = repr(v)
    else:
        el.text = str(v)


def to_xml(model: Model) -> str:
    root = ET.Element("model", applicationId=model.application, applicationVersion="", version=model.version)
    rels = ET.SubElement(root, "relations")
    for r in model.relations:
        re_ = ET.SubElement(rels, "relation", id=str(r.id), type=r.type)
        for i, role, hint in r.refs:
            ET.SubElement(re_, "ref", hint=hint, id=str(i), role=role)
    comps = ET.SubElement(root, "components")
    for c in model.components.values():
        ce = ET.SubElement(comps, "component", id=str(c.id), name=c.name, type=c.type)
        for a in c.attrs.values():
            _xml_value(ET.SubElement(ce, "attribute", id=a.id, unit=a.unit), a.value)
    ET.indent(root)
    return '<?xml version="1.0" encoding="UTF-8"?>\n' + ET.tostring(root, encoding="unicode") + "\n"


def _json_attr(a: Attr) -> dict:
    v = a.value
    if isinstance(v, bool):
        k = "boolean"
    elif isinstance(v, int):
        k = "integer"
    elif isinstance(v, float):
        k = "floating_point"
    elif isinstance(v, list):
        k = "floating_point_array"
    else:
        k = "string" if a.id in ("material_designation", "name") else "enum"
    return {"id": a.id, "unit": a.unit, k: v}


def to_json(model: Model) -> str:
    doc = {
        "model": {
            "applicationId": model.application,
            "applicationVersion": "",
            "version": model.version,
            "relations": [
                {"id": r.id, "type": r.type, "refs": [{"id": i, "role": ro, "hint": h} for i, ro, h in r.refs]}
                for r in model.relations
            ],
            "components": [
                {"id": c.id, "type": c.type, "name": c.name, "attributes": [_json_attr(a) for a in c.attrs.values()]}
                for c in model.components.values()
            ],
        }
    }
    return json.dumps(doc, indent=2) + "\n"
