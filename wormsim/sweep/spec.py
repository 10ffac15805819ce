"""Sweep files (docs/sweeps.md, "The sweep file"): the pydantic schema and the expansion into validated points.

    name: screw_jack_stiffness
    base: ../scenarios/screw_jack.yaml        # relative to the sweep file
    set: {model: torsional}                   # fixed overrides, dotted paths as `wormsim run --set`
    grid: {contact.stiffness_n_per_m: [2.0e8, 4.39e8], drive.speed_rpm: {linspace: [1000, 2000, 3]}}
    zip: {a.b: [1, 2, 3], c.d: [4, 5, 6]}     # same lengths, taken side by side
    random: {n: 20, seed: 1, vary: {gear.backlash_mm: {uniform: [0.05, 0.1]}, load.torque_nm: {normal: [12, 1]}}}
    random: {n: 100, seed: 3, vary: {errors.wheel_pitch_deviation_um: {uniform: [-5, 5], size: 24}}}  # a list each

Points: the cartesian product of the grid axes, the zip group (one axis of rows) and the random group (one axis
of n draws), in that order, the last axis varying fastest. A value list is a YAML list; {linspace: [a, b, n]} is
numpy.linspace; {logspace: [a, b, n]} is n values from a to b evenly spaced in log (numpy.geomspace: a and b are
the end values, not exponents). Random draws use numpy.random.default_rng(seed), one path after another in the
order written, so a sweep file gives the same points on every machine (and a rerun into the same folder resumes:
the points, hence their scenario hashes, are the same). With size: N a draw is a list of N values (one per wheel
tooth, say), drawn point after point.

Every point is validated as a scenario (wormsim.scenario.scenario_from_dict) before anything runs; a bad point
raises ScenarioError naming the point, its swept values and the field (exit 2). Each point carries the hash of
its validated scenario (scenario_hash), which `wormsim sweep` uses to resume.
"""

from __future__ import annotations

import copy
import hashlib
import itertools
import json
import re
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import yaml
from pydantic import BaseModel, ConfigDict, Field, ValidationError, field_validator, model_validator

from wormsim.scenario import Scenario, ScenarioError, format_validation_error, scenario_from_dict, set_path, yaml_load
from wormsim.sweep.cluster import may_run_contact3d

MAX_POINTS = 100_000
_PATH = r"^[A-Za-z_][A-Za-z0-9_]*(\.[A-Za-z_][A-Za-z0-9_]*)*$"


class _Strict(BaseModel):
    model_config = ConfigDict(extra="forbid")


class Linspace(_Strict):
    linspace: tuple[float, float, int] = Field(..., description="[a, b, n]: n evenly spaced values from a to b")

    @model_validator(mode="after")
    def _n(self) -> "Linspace":
        if not 1 <= self.linspace[2] <= MAX_POINTS:
            raise ValueError(f"linspace n = {self.linspace[2]}: allowed 1 to {MAX_POINTS}")
        return self

    def values(self) -> list:
        a, b, n = self.linspace
        return np.linspace(a, b, n).tolist()


class Logspace(_Strict):
    logspace: tuple[float, float, int] = Field(
        ..., description="[a, b, n]: n values from a to b, even in log (a, b > 0)"
    )

    @model_validator(mode="after")
    def _n(self) -> "Logspace":
        a, b, n = self.logspace
        if a <= 0 or b <= 0:
            raise ValueError(
                f"logspace [{a}, {b}, {n}]: the end values a and b must be > 0 (they are values, not exponents)"
            )
        if not 1 <= n <= MAX_POINTS:
            raise ValueError(f"logspace n = {n}: allowed 1 to {MAX_POINTS}")
        return self

    def values(self) -> list:
        a, b, n = self.logspace
        return np.geomspace(a, b, n).tolist()


Axis = list[Any] | Linspace | Logspace
_AXIS_FORMS = "a list of values, {linspace: [a, b, n]} or {logspace: [a, b, n]}"


def _parse_axes(section: str, axes: Any) -> dict:
    """One clear message per bad axis instead of pydantic's error for every member of the union."""
    if not isinstance(axes, dict):
        raise ValueError(f"{section}: expected a mapping of dotted paths to {_AXIS_FORMS}")
    out = {}
    for p, ax in axes.items():
        if isinstance(ax, list):
            out[p] = ax
            continue
        kind = next(iter(ax), None) if isinstance(ax, dict) and len(ax) == 1 else None
        if kind not in ("linspace", "logspace"):
            raise ValueError(f"{section}.{p} = {ax!r}: expected {_AXIS_FORMS}")
        ab_n = ax[kind]
        if not (isinstance(ab_n, list) and len(ab_n) == 3):
            raise ValueError(f"{section}.{p}.{kind} = {ab_n!r}: expected [a, b, n]")
        try:
            out[p] = (Linspace if kind == "linspace" else Logspace).model_validate(ax)
        except ValidationError as err:
            raise ValueError(
                f"{section}.{p}.{kind} = {ab_n!r}: "
                + "; ".join(e["msg"].removeprefix("Value error, ") for e in err.errors())
            ) from None
    return out


_SIZE = Field(None, ge=1, le=1000, description="draw a list of this many values per point (e.g. one per wheel tooth)")


class Uniform(_Strict):
    uniform: tuple[float, float] = Field(..., description="[low, high]")
    size: int | None = _SIZE

    @model_validator(mode="after")
    def _order(self) -> "Uniform":
        if self.uniform[0] > self.uniform[1]:
            raise ValueError(f"uniform [{self.uniform[0]}, {self.uniform[1]}]: low must be <= high")
        return self

    def draw(self, rng: np.random.Generator, n: int) -> list:
        if self.size is None:
            return rng.uniform(self.uniform[0], self.uniform[1], n).tolist()
        return rng.uniform(self.uniform[0], self.uniform[1], (n, self.size)).tolist()


class Normal(_Strict):
    normal: tuple[float, float] = Field(..., description="[mean, standard deviation]")
    size: int | None = _SIZE

    @model_validator(mode="after")
    def _sd(self) -> "Normal":
        if self.normal[1] < 0:
            raise ValueError(f"normal sd = {self.normal[1]}: must be >= 0")
        return self

    def draw(self, rng: np.random.Generator, n: int) -> list:
        if self.size is None:
            return rng.normal(self.normal[0], self.normal[1], n).tolist()
        return rng.normal(self.normal[0], self.normal[1], (n, self.size)).tolist()


class Random(_Strict):
    n: int = Field(..., ge=1, le=MAX_POINTS, description="number of draws")
    seed: int = Field(0, ge=0, description="numpy.random.default_rng seed")
    vary: dict[str, Uniform | Normal] = Field(
        ...,
        min_length=1,
        description="PATH: {uniform: [a, b]} | {normal: [mean, sd]}, either with size: N for a list of N draws",
    )

    @field_validator("vary", mode="before")
    @classmethod
    def _vary(cls, v: Any) -> Any:
        if not isinstance(v, dict):
            return v
        out = {}
        for p, d in v.items():
            keys = [k for k in d if k != "size"] if isinstance(d, dict) else []
            kind = keys[0] if len(keys) == 1 else None
            if kind not in ("uniform", "normal"):
                raise ValueError(
                    f"random.vary.{p} = {d!r}: expected {{uniform: [low, high]}} or {{normal: [mean, sd]}}"
                    " (optionally with size: N)"
                )
            try:
                out[p] = (Uniform if kind == "uniform" else Normal).model_validate(d)
            except ValidationError as err:
                raise ValueError(
                    f"random.vary.{p}.{kind} = {d[kind]!r}: "
                    + "; ".join(e["msg"].removeprefix("Value error, ") for e in err.errors())
                ) from None
        return out


class Plot(_Strict):
    """Optional: what sweep.png shows (default: the main outputs against the first swept path)."""

    x: str | None = Field(None, description="swept path on the x axis")
    series: str | None = Field(None, description="swept path with one line per value")
    outputs: list[str] | None = Field(None, description="summary keys, one panel each")
    log_x: bool | None = None


class SweepFile(_Strict):
    name: str = Field(..., pattern=r"^[a-z0-9_-]+$")
    description: str = ""
    base: str = Field(..., description="base scenario YAML, relative to the sweep file")
    set: dict[str, Any] = Field(default_factory=dict, description="fixed overrides, dotted paths")
    grid: dict[str, Axis] = Field(default_factory=dict)
    zip: dict[str, Axis] = Field(default_factory=dict)
    random: Random | None = None
    plot: Plot = Plot()

    @field_validator("grid", "zip", mode="before")
    @classmethod
    def _axes_forms(cls, v: Any, info) -> Any:
        return _parse_axes(info.field_name, v)

    @model_validator(mode="after")
    def _axes(self) -> "SweepFile":
        swept = self.swept_paths()
        if not swept:
            raise ValueError("a sweep needs at least one of grid / zip / random")
        for p in [*self.set, *swept]:
            if not re.match(_PATH, p):
                raise ValueError(f"'{p}' is not a dotted path (e.g. contact.stiffness_n_per_m)")
        dup = sorted({p for p in swept if swept.count(p) > 1} | (set(self.set) & set(swept)))
        if dup:
            raise ValueError(f"{', '.join(dup)}: a path may be swept once and not also fixed in set")
        for section in ("grid", "zip"):
            for p, ax in getattr(self, section).items():
                if not _values(ax):
                    raise ValueError(f"{section}.{p}: an empty list of values")
        lens = {p: len(_values(ax)) for p, ax in self.zip.items()}
        if len(set(lens.values())) > 1:
            raise ValueError(
                "zip: every path needs the same number of values; got "
                + ", ".join(f"{p}: {n}" for p, n in lens.items())
            )
        for key in ("x", "series"):
            v = getattr(self.plot, key)
            if v is not None and v not in swept:
                raise ValueError(f"plot.{key} = {v}: not a swept path ({', '.join(swept)})")
        return self

    def swept_paths(self) -> list[str]:
        return [*self.grid, *self.zip, *(self.random.vary if self.random else {})]


def _values(ax: Axis) -> list:
    return list(ax) if isinstance(ax, list) else ax.values()


@dataclass
class Point:
    index: int
    values: dict[str, Any]  # swept path -> value
    scenario: Scenario
    scenario_hash: str

    def label(self) -> str:
        return f"point {self.index} (" + ", ".join(f"{p}={_fmt(v)}" for p, v in self.values.items()) + ")"


def _fmt(v) -> str:
    return f"{v:.6g}" if isinstance(v, float) else str(v)


def scenario_hash(sc: Scenario) -> str:
    """sha256 of the validated scenario (every field, defaults filled in): identical scenarios, identical hash."""
    text = json.dumps(sc.model_dump(mode="json"), sort_keys=True, separators=(",", ":"))
    return hashlib.sha256(text.encode()).hexdigest()[:16]


@dataclass
class Sweep:
    spec: SweepFile
    path: Path  # the sweep file
    base_path: Path
    raw: dict  # the sweep file as written
    points: list[Point]

    @property
    def swept_paths(self) -> list[str]:
        return self.spec.swept_paths()


def expand(spec: SweepFile) -> list[dict[str, Any]]:
    """The swept values of every point, in order (grid axes, then zip rows, then random draws)."""
    axes: list[list[dict]] = [[{p: v} for v in _values(ax)] for p, ax in spec.grid.items()]
    if spec.zip:
        cols = {p: _values(ax) for p, ax in spec.zip.items()}
        n = len(next(iter(cols.values())))
        axes.append([{p: cols[p][i] for p in cols} for i in range(n)])
    if spec.random:
        rng = np.random.default_rng(spec.random.seed)
        draws = {p: d.draw(rng, spec.random.n) for p, d in spec.random.vary.items()}
        axes.append([{p: draws[p][i] for p in draws} for i in range(spec.random.n)])
    total = int(np.prod([len(a) for a in axes]))
    if total > MAX_POINTS:
        raise ScenarioError(f"sweep: {total} points; allowed at most {MAX_POINTS} (fewer values per axis)")
    return [{k: v for part in combo for k, v in part.items()} for combo in itertools.product(*axes)]


_EXP_FLOAT = re.compile(r"^[-+]?(\.[0-9]+|[0-9]+(\.[0-9]*)?)[eE][-+]?[0-9]+$")


def _yaml12_numbers(obj):
    """2.0e8 and 1e-5 as numbers: PyYAML (YAML 1.1) reads a float only with a dot and a signed exponent, so
    these stay text, which pydantic would coerce in a scenario field but which a swept value list must not be."""
    if isinstance(obj, dict):
        return {k: _yaml12_numbers(v) for k, v in obj.items()}
    if isinstance(obj, list):
        return [_yaml12_numbers(v) for v in obj]
    if isinstance(obj, str) and _EXP_FLOAT.match(obj):
        return float(obj)
    return obj


def load_sweep(path: str | Path, max_errors: int = 5, on_parsed: Callable[[bool], None] | None = None) -> Sweep:
    """Read, expand and validate a sweep file; ScenarioError (exit 2) on the first problems found.
    on_parsed(contact3d) is called once the file and its base scenario have been read, before the points are
    validated (`wormsim sweep` starts its cluster there, so the start overlaps the validation); contact3d: whether
    points may run at contact3d (the base's model, or a swept model)."""
    path = Path(path)
    if not path.is_file():
        raise ScenarioError(f"{path}: no such sweep file")
    try:
        raw = yaml_load(path.read_text())
    except yaml.YAMLError as exc:
        mark = getattr(exc, "problem_mark", None)
        raise ScenarioError(f"{path.name}: not valid YAML{f' at line {mark.line + 1}' if mark else ''}") from None
    if not isinstance(raw, dict):
        raise ScenarioError(f"{path.name}: the top level must be a mapping (name, base, set, grid, zip, random)")
    if {"gear", "model"} & raw.keys() and not {"base", "grid", "zip", "random"} & raw.keys():
        raise ScenarioError(
            f"{path.name}: a scenario, not a sweep file (it has {', '.join(sorted({'gear', 'model'} & raw.keys()))} "
            f"and no base / grid / zip / random): run it with `wormsim run {path.name}`, or name it as a sweep file's "
            "base (docs/sweeps.md)"
        )
    raw = {k: (_yaml12_numbers(v) if k in ("set", "grid", "zip", "random") else v) for k, v in raw.items()}
    try:
        spec = SweepFile.model_validate(raw)
    except ValidationError as err:
        # the messages of this module's validators name their field; drop the "block = {...}: " before them
        raise ScenarioError(
            re.sub(r"(?m)^(\S+: )(\(top level\)|[\w.]+) = \{\.\.\.\}: ", r"\1", format_validation_error(err, path.name))
        ) from None
    base_path = (path.parent / spec.base).resolve()
    if not base_path.is_file():
        raise ScenarioError(f"{path.name}: base = {spec.base}: no such scenario file ({base_path})")
    try:
        base = yaml_load(base_path.read_text())
    except yaml.YAMLError:
        raise ScenarioError(f"{path.name}: base = {spec.base}: not valid YAML") from None
    if not isinstance(base, dict):
        raise ScenarioError(f"{path.name}: base = {spec.base}: the top level must be a mapping")
    for p, v in spec.set.items():
        set_path(base, p.split("."), v, f"{path.name}: set.{p}")
    if on_parsed is not None:
        on_parsed(may_run_contact3d(base.get("model", "contact3d"), [*spec.grid, *spec.zip]))

    points, errors = [], []
    for i, values in enumerate(expand(spec)):
        data = copy.deepcopy(base)
        label = Point(i, values, None, "").label()  # type: ignore[arg-type]
        try:
            for p, v in values.items():
                set_path(data, p.split("."), v, f"{path.name}: {label}")
            sc = scenario_from_dict(data, f"{path.name}: {label}")
        except ScenarioError as exc:
            errors.append(str(exc))
            if len(errors) >= max_errors:
                break
            continue
        points.append(Point(i, values, sc, scenario_hash(sc)))
    if errors:
        raise ScenarioError("\n".join(errors))
    return Sweep(spec=spec, path=path, base_path=base_path, raw=raw, points=points)
