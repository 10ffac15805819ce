"""Scenario files: the pydantic schema of ../shared/INTERFACE.md, loading, `--set` overrides.

Units are in the key names (`_mm`, `_deg`, `_rpm`, `_nm`, `_n`, `_s`, ...). This module is the
one edge where user units meet the code: everything downstream reads the validated model and
converts once (see `wormsim.units`).

Every model forbids unknown keys, so a misspelt field is an error, not a silent default.
`load_scenario` turns any validation failure into `ScenarioError`, whose message is one line
naming the field (dotted path), the value given and what is allowed; the CLI maps it to exit 2.
"""
from __future__ import annotations

import json
import re
from pathlib import Path
from typing import Annotated, Any, Literal

import yaml
from pydantic import BaseModel, ConfigDict, Field, ValidationError, model_validator


class ScenarioError(ValueError):
    """Invalid input: the message names the field, the value and what is allowed (exit code 2)."""


class _Strict(BaseModel):
    model_config = ConfigDict(extra="forbid", validate_default=True)


PositiveFloat = Annotated[float, Field(gt=0)]
NonNegFloat = Annotated[float, Field(ge=0)]
FrictionGroup = Literal["I", "II", "III"]


# ----------------------------------------------------------------------------- gear, materials

class Gear(_Strict):
    """Worm gear data (DIN 3975 / ISO 1122 names). Exactly one module and one of lead angle / q."""

    profile: Literal["ZI", "ZA"] = Field("ZI", description="ZI: involute helicoid (seed 003); ZA: straight-sided axial profile")
    hand: Literal["right", "left"] = Field("right", description="thread hand of the worm")
    worm_starts: int = Field(1, ge=1, le=8, description="z1")
    wheel_teeth: int = Field(..., ge=10, le=200, description="z2")
    normal_module_mm: float | None = Field(None, gt=0, le=50)
    axial_module_mm: float | None = Field(None, gt=0, le=50)
    normal_pressure_angle_deg: float = Field(20.0, ge=5, le=30)
    lead_angle_deg: float | None = Field(None, gt=0, lt=45, description="gamma at the worm reference diameter")
    diameter_quotient: float | None = Field(None, gt=0, le=40, description="q = d1 / m_axial")
    face_width_mm: float | None = Field(None, gt=0, description="wheel face width b2; default 0.75 * worm tip diameter (DIN 3975 guide)")
    worm_length_mm: float | None = Field(None, gt=0, description="threaded length; default covers the wheel's mesh zone")
    backlash_mm: NonNegFloat = Field(0.05, description="circumferential, at the wheel reference circle")
    addendum_coef: float = Field(1.0, gt=0, le=1.5, description="h_a / m_axial")
    dedendum_coef: float = Field(1.2, gt=0, le=2.0, description="h_f / m_axial")

    @model_validator(mode="after")
    def _one_of(self) -> "Gear":
        if (self.normal_module_mm is None) == (self.axial_module_mm is None):
            raise ValueError("give exactly one of normal_module_mm / axial_module_mm")
        if (self.lead_angle_deg is None) == (self.diameter_quotient is None):
            raise ValueError("give exactly one of lead_angle_deg / diameter_quotient")
        if self.dedendum_coef <= self.addendum_coef:
            raise ValueError("dedendum_coef must exceed addendum_coef (root clearance)")
        return self


class Material(_Strict):
    youngs_modulus_gpa: float = Field(..., gt=0, le=1000)
    poisson_ratio: float = Field(..., ge=0, lt=0.5)
    density_kg_m3: float = Field(..., gt=0, le=25000)


class Materials(_Strict):
    worm: Material = Material(youngs_modulus_gpa=210, poisson_ratio=0.3, density_kg_m3=7850)
    wheel: Material = Material(youngs_modulus_gpa=100, poisson_ratio=0.34, density_kg_m3=8800)


# ----------------------------------------------------------------------------- contact, drive, load

class Contact(_Strict):
    """Tooth contact. Every key optional; defaults derived from Hertz (README, 'Contact law')."""

    stiffness_n_per_m: float | None = Field(None, gt=0, description="ADAMS IMPACT K")
    exponent: float = Field(1.5, ge=1, le=3, description="ADAMS IMPACT e")
    damping_n_s_per_m: float | None = Field(None, ge=0, description="ADAMS IMPACT C")
    penetration_depth_m: float = Field(1e-5, gt=0, description="ADAMS IMPACT d (full damping depth)")
    friction: float | None = Field(None, ge=0, le=1, description="one Coulomb coefficient")
    friction_static: float | None = Field(None, ge=0, le=1)
    friction_dynamic: float | None = Field(None, ge=0, le=1)
    friction_group: FrictionGroup | None = Field(None, description="seed 000 rho(Vs) material group")
    transition_velocity_m_s: float = Field(1e-3, gt=0, description="static -> dynamic friction blend speed")

    @model_validator(mode="after")
    def _friction(self) -> "Contact":
        given = [self.friction is not None, self.friction_group is not None,
                 self.friction_static is not None or self.friction_dynamic is not None]
        if sum(given) > 1:
            raise ValueError("give one of friction / friction_group / friction_static+friction_dynamic")
        if (self.friction_static is None) != (self.friction_dynamic is None):
            raise ValueError("friction_static and friction_dynamic go together")
        if (self.friction_static is not None and self.friction_dynamic is not None
                and self.friction_dynamic > self.friction_static):
            raise ValueError("friction_dynamic must not exceed friction_static")
        return self


class Drive(_Strict):
    on: Literal["worm", "wheel"] = Field("worm", description="driven shaft (wheel = back-driving)")
    speed_rpm: float | None = Field(None, gt=-100000, lt=100000, description="speed-controlled drive, STEP ramp from 0 over ramp_s")
    torque_nm: float | None = Field(None, gt=-1e6, lt=1e6, description="torque drive, same STEP ramp")
    ramp_s: NonNegFloat = Field(0.0, description="STEP ramp time of the drive")

    @model_validator(mode="after")
    def _one_of(self) -> "Drive":
        if (self.speed_rpm is None) == (self.torque_nm is None):
            raise ValueError("give exactly one of speed_rpm / torque_nm")
        return self


class Load(_Strict):
    on: Literal["worm", "wheel"] = Field("wheel", description="loaded shaft (the other one)")
    torque_nm: float = Field(0.0, gt=-1e6, lt=1e6, description="resisting torque")
    start_s: NonNegFloat = Field(0.0, description="STEP ramp of the load starts here")
    ramp_s: NonNegFloat = Field(0.0, description="STEP ramp time of the load")
    inertia_kg_m2: float = Field(0.0, ge=0, le=1e6, description=(
        "driven-machine inertia rigidly on the loaded shaft (contact3d: joint armature; 0 = bare gear)"))


class Simulation(_Strict):
    duration_s: float = Field(1.0, gt=0, le=3600)
    timestep_s: float | None = Field(None, gt=0, le=0.01, description="default documented; the summary states the one used")
    resolution: Literal["coarse", "medium", "fine"] = Field("medium", description="collision decomposition level (contact3d)")
    integrator: Literal["implicitfast", "rk4", "euler", "implicit", "discrete"] = "implicitfast"
    record_every: int = Field(1, ge=1, le=100000, description=(
        "store every n-th step in the time series (forces, torques and powers: the mean over those n steps)"))
    speculative: bool = Field(False, description=(
        "contact3d: MuJoCo's speculative contacts (sweep fast geoms over the step against tunnelling)"))
    mesh_stiffness_samples: int = Field(
        64, ge=8, le=4096, description="torsional: k(theta) samples per mesh cycle (tooth contact analysis)")


# ----------------------------------------------------------------------------- wedge (seed 000)

class WedgeMotor(_Strict):
    """Kloss induction-motor force curve of seed 000 (forces reduced to the worm pitch radius)."""

    peak_force_n: float = Field(2178.0, gt=0)
    synchronous_speed_m_s: float = Field(7.85, gt=0)
    peak_force_speed_m_s: float = Field(6.5, gt=0)
    nominal_force_n: float = Field(
        990.0, gt=0, description="rated force Ft1 = M_n / R1 for the dynamic factor Kd1; seed 000: 2178 N / (Mmax/Mn = 2.2)")
    nominal_speed_m_s: float = Field(
        7.59, gt=0, description="rated speed n_n R1 (Ft2 uses rho there); seed 000: 2900 rpm at R1 = 25 mm")

    @model_validator(mode="after")
    def _order(self) -> "WedgeMotor":
        if self.peak_force_speed_m_s >= self.synchronous_speed_m_s:
            raise ValueError("peak_force_speed_m_s must be below synchronous_speed_m_s")
        if self.nominal_speed_m_s >= self.synchronous_speed_m_s:
            raise ValueError("nominal_speed_m_s must be below synchronous_speed_m_s")
        return self


class WedgeLoad(_Strict):
    force_n: float = Field(-5000.0, gt=-1e7, lt=1e7, description="F2 on the driven body (negative resists)")
    initial_force_n: float = Field(0.0, gt=-1e7, lt=1e7, description="F2 before start_s; STEP to force_n over ramp_s")
    start_s: NonNegFloat = 0.0
    ramp_s: NonNegFloat = 0.0


class Wedge(_Strict):
    lead_angle_deg: float = Field(4.76, gt=0, lt=45)
    driving_mass_kg: float = Field(11.8, gt=0)
    driven_mass_kg: float = Field(100.0, gt=0)
    friction_group: FrictionGroup | None = "III"
    friction: float | None = Field(None, ge=0, le=1, description="constant coefficient; rho = atan(friction)")
    motor: WedgeMotor = WedgeMotor()
    load: WedgeLoad = WedgeLoad()
    monitor: Literal["three_regime", "seed"] = Field(
        "three_regime", description="three_regime: tractive/inverse/locked with events; seed: seed 000's literal two-regime switch")
    initial_speed_m_s: float = Field(0.0, ge=0)
    rtol: float = Field(1e-8, gt=0, le=1e-2)

    @model_validator(mode="after")
    def _friction(self) -> "Wedge":
        if self.friction is not None and self.friction_group is not None and "friction_group" in self.model_fields_set:
            raise ValueError("give one of friction_group / friction")
        if self.friction is not None:
            self.friction_group = None
        return self


# ----------------------------------------------------------------------------- scenario

class Scenario(_Strict):
    name: str = Field(..., pattern=r"^[a-z0-9_-]+$", description="case name, used in outputs")
    description: str = Field("", description="free text")
    model: Literal["contact3d", "torsional", "wedge"] = Field(
        "contact3d", description="fidelity level: 3D tooth contact (MuJoCo), 2-DOF torsional, or 1-DOF wedge (seed 000)")
    gear: Gear | None = None
    materials: Materials = Materials()
    contact: Contact = Contact()
    drive: Drive | None = None
    load: Load = Load()
    simulation: Simulation = Simulation()
    wedge: Wedge | None = None

    @model_validator(mode="after")
    def _blocks(self) -> "Scenario":
        if self.model == "wedge":
            if self.wedge is None:
                raise ValueError("model: wedge needs a wedge: block")
        else:
            if self.gear is None:
                raise ValueError(f"model: {self.model} needs a gear: block")
            if self.drive is None:
                raise ValueError(f"model: {self.model} needs a drive: block")
            if self.drive.on == self.load.on:
                raise ValueError("drive.on and load.on must name different shafts")
        return self


# ----------------------------------------------------------------------------- loading

class _Loader(yaml.SafeLoader):
    """YAML 1.2 booleans: only true/false. YAML 1.1 would read the key `on:` (drive.on) as True."""


_Loader.yaml_implicit_resolvers = {
    ch: [(tag, rx) for tag, rx in resolvers if tag != "tag:yaml.org,2002:bool"]
    for ch, resolvers in yaml.SafeLoader.yaml_implicit_resolvers.items()
}
_Loader.add_implicit_resolver(
    "tag:yaml.org,2002:bool", re.compile(r"^(?:true|True|TRUE|false|False|FALSE)$"), list("tTfF"))


def yaml_load(text: str):
    return yaml.load(text, Loader=_Loader)  # a SafeLoader subclass


def _fmt_loc(loc: tuple) -> str:
    return ".".join(str(p) for p in loc if not (isinstance(p, str) and p.startswith("function-")))


def format_validation_error(err: ValidationError, source: str = "scenario") -> str:
    """One line per problem: `source: field = value: what is allowed`."""
    lines = []
    for e in err.errors(include_url=False):
        field = _fmt_loc(e["loc"]) or "(top level)"
        msg = e["msg"].removeprefix("Value error, ")
        if e["type"] == "extra_forbidden":
            lines.append(f"{source}: unknown key '{field}' (not in the schema; see `wormsim schema`)")
        elif e["type"] == "missing":
            lines.append(f"{source}: missing required field '{field}'")
        else:
            val = e.get("input")
            shown = json.dumps(val, default=str) if not isinstance(val, dict) else "{...}"
            lines.append(f"{source}: {field} = {shown}: {msg}")
    return "\n".join(lines)


def parse_override(text: str) -> tuple[list[str], Any]:
    """`--set a.b.c=VALUE`; VALUE is parsed as YAML (numbers, booleans, lists, null)."""
    if "=" not in text:
        raise ScenarioError(f"--set {text}: expected KEY=VALUE with a dotted KEY, e.g. gear.wheel_teeth=41")
    key, raw = text.split("=", 1)
    path = [p for p in key.strip().split(".") if p]
    if not path:
        raise ScenarioError(f"--set {text}: empty KEY")
    try:
        value = yaml_load(raw) if raw.strip() else ""
    except yaml.YAMLError as exc:
        raise ScenarioError(f"--set {text}: VALUE is not valid YAML ({exc.__class__.__name__})") from None
    return path, value


def apply_overrides(data: dict, overrides: list[str]) -> dict:
    for text in overrides:
        path, value = parse_override(text)
        node = data
        for i, key in enumerate(path[:-1]):
            nxt = node.get(key)
            if nxt is None:
                nxt = node[key] = {}
            if not isinstance(nxt, dict):
                raise ScenarioError(f"--set {text}: '{'.'.join(path[:i + 1])}' is not a block")
            node = nxt
        node[path[-1]] = value
    return data


def scenario_from_dict(data: Any, source: str = "scenario", overrides: list[str] | None = None) -> Scenario:
    if not isinstance(data, dict):
        raise ScenarioError(f"{source}: the top level must be a mapping of keys (name, model, gear, ...)")
    data = apply_overrides(dict(data), overrides or [])
    try:
        return Scenario.model_validate(data)
    except ValidationError as err:
        raise ScenarioError(format_validation_error(err, source)) from None


def load_scenario(path: str | Path, overrides: list[str] | None = None) -> Scenario:
    path = Path(path)
    if not path.is_file():
        raise ScenarioError(f"{path}: no such scenario file")
    try:
        data = yaml_load(path.read_text())
    except yaml.YAMLError as exc:
        mark = getattr(exc, "problem_mark", None)
        where = f" at line {mark.line + 1}" if mark else ""
        raise ScenarioError(f"{path}: not valid YAML{where}") from None
    return scenario_from_dict(data, str(path.name), overrides)


def json_schema() -> dict:
    return Scenario.model_json_schema()
