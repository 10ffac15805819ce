"""The bench grid: seed variants, resolutions and timesteps per level, and relative errors against the reference."""

from __future__ import annotations

import importlib.util
from dataclasses import dataclass, field, replace

import numpy as np

from wormsim.contact3d.mjcf import prepare
from wormsim.contact3d.timestep import default_timestep
from wormsim.run import LEVELS
from wormsim.runtime.data import data_dir
from wormsim.scenario import Scenario, ScenarioError, load_scenario

SCENARIOS = data_dir("scenarios")  # the seed scenarios, shipped as package data
ERROR_KEYS = ("ratio", "tangential_force_mean_n", "tangential_force_p2p_n", "mesh_frequency_hz", "efficiency")


@dataclass(frozen=True)
class BenchCase:
    scenario: str  # stem of scenarios/<stem>.yaml
    model: str  # fidelity level
    resolution: dict  # free-form description of the level's resolution
    timestep_s: float | None
    overrides: tuple[str, ...] = field(default_factory=tuple)
    reference: bool = False  # the converged reference of its scenario
    finer: bool = False  # the finer run that checks the reference
    timestep_factor: float | None = None  # contact3d: timestep_s / the default timestep of its geometry
    shafts: bool = False  # contact3d: the run with SHAFTS_BLOCK, twin of the rigid case with the same fields

    def build(self) -> Scenario:
        """The case's scenario: the seed with its overrides, and SHAFTS_BLOCK where `shafts`."""
        sc = load_scenario(SCENARIOS / f"{self.scenario}.yaml", list(self.overrides))
        if not self.shafts:
            return sc
        return Scenario.model_validate({**sc.model_dump(), "shafts": SHAFTS_BLOCK})


def level_available(model: str) -> bool:
    return importlib.util.find_spec(LEVELS[model]) is not None


# Bench variants of the seed scenarios: every level runs the same variant, so errors compare one to one.
# The seat motor runs its worm at 1800 rpm (seed 001's 36 rpm needs 20 s for 12 mesh periods: about an
# hour at contact3d fidelity on this machine); ramps are shortened; each run holds >= 5 mesh periods.
VARIANTS = {
    "seat_motor": ("drive.speed_rpm=1800", "drive.ramp_s=0.02", "load.ramp_s=0.02"),
    "screw_jack": ("drive.ramp_s=0.02", "load.ramp_s=0.02"),
    "involute_41": ("drive.ramp_s=0.02", "load.ramp_s=0.02"),
}
DURATION_S = {"seat_motor": 0.25, "screw_jack": 0.3, "involute_41": 0.3}
QUICK_DURATION_S = 0.15
GEOMETRIES = ("flanks", "pieces")  # contact3d's contact.geometry, both benched so one run gives the speed-up
# `bench --shafts`: the shafts: block of the shafted twins (both shafts on compliant bearings, the worm bending: every
# joint and spring of wormsim.contact3d.shafts; tests/contact3d/test_shafts.py's balance case), each run against its
# rigid twin
SHAFTS_BLOCK = {
    "worm": {
        "bearings_mm": [-60, 60],
        "radial_stiffness_n_per_um": 500,
        "axial_stiffness_n_per_um": 200,
        "bending": True,
    },
    "wheel": {"bearings_mm": [-30, 30], "radial_stiffness_n_per_um": 500, "axial_stiffness_n_per_um": 200},
}


def contact3d_default_timestep(name: str, overrides: tuple[str, ...] = ()) -> float:
    """The contact's default timestep for this scenario (wormsim.contact3d.timestep.default_timestep, from the contact
    law; no model is compiled)."""
    sc = load_scenario(SCENARIOS / f"{name}.yaml", list(overrides))
    return default_timestep(prepare(sc).law)


def bench_cases(
    quick: bool,
    models: tuple[str, ...] | None = None,
    scenarios: tuple[str, ...] | None = None,
    geometries: tuple[str, ...] | None = None,
    resolutions: tuple[str, ...] | None = None,
    shafts: bool = False,
) -> list[BenchCase]:
    """The grid. contact3d, for each contact.geometry (flanks, pieces): resolution levels x timesteps of 2, 1 and 1/2
    times its default (the default is 0.4 x the explicit stability limit, so 2x probes the edge); the reference is
    the finest level of the scenario's default geometry at the default step, checked against half that step.
    torsional: k(theta) samples per mesh cycle.
    quick: the seat motor only, 0.15 s, coarse/medium. models: only these levels. scenarios: only these seeds (names
    of VARIANTS). geometries: only these contact.geometry values for contact3d. resolutions: only these contact3d
    resolution levels (the reference is then the finest of them). shafts: each contact3d flanks case at the default
    step followed by its shafted twin (SHAFTS_BLOCK), for the shafts' cost per step (run.shaft_ratios)."""
    names = ("seat_motor",) if quick else tuple(VARIANTS)
    if scenarios is not None:
        unknown = sorted(set(scenarios) - set(VARIANTS))
        if unknown:
            raise ScenarioError(
                f"bench --scenario: {', '.join(unknown)} is not a seed scenario; allowed: {', '.join(VARIANTS)}"
            )
        names = tuple(n for n in VARIANTS if n in scenarios)
    geos = tuple(g for g in GEOMETRIES if geometries is None or g in geometries)
    levels = ("coarse", "medium") if quick else ("coarse", "medium", "fine")
    if resolutions is not None:
        unknown = sorted(set(resolutions) - {"coarse", "medium", "fine"})
        if unknown:
            raise ScenarioError(
                f"bench --resolution: {', '.join(unknown)} is not a level; allowed: coarse, medium, fine"
            )
        levels = tuple(lv for lv in ("coarse", "medium", "fine") if lv in resolutions)
    out: list[BenchCase] = []
    for name in names:
        dur = QUICK_DURATION_S if quick else DURATION_S[name]
        common = VARIANTS[name] + (f"simulation.duration_s={dur}",)
        if level_available("contact3d") and (models is None or "contact3d" in models) and geos:
            default_geo = load_scenario(SCENARIOS / f"{name}.yaml", list(common)).contact.geometry
            ref_geo = default_geo if default_geo in geos else geos[0]
            for geo in geos:
                out += _contact3d_cases(
                    name,
                    common + (f"contact.geometry={geo}",),
                    geo,
                    levels,
                    (2.0, 1.0) if quick else (2.0, 1.0, 0.5),
                    reference=geo == ref_geo,
                )
        if level_available("torsional") and (models is None or "torsional" in models):
            # resolution = k(theta) samples per mesh cycle; the default timestep is one sample's worth of worm
            # rotation at full speed (wormsim.torsional.dynamics.default_timestep), so this sweeps both
            for n in (16, 64) if quick else (16, 32, 64, 128, 256):
                out.append(
                    BenchCase(
                        name,
                        "torsional",
                        {"level": "mesh-stiffness table", "mesh_stiffness_samples": n},
                        None,
                        common + ("model=torsional", f"simulation.mesh_stiffness_samples={n}"),
                    )
                )
    if shafts:
        twins = []
        for c in out:
            twins.append(c)
            if c.model == "contact3d" and c.resolution.get("geometry") == "flanks" and c.timestep_factor == 1.0:
                twins.append(replace(c, shafts=True, reference=False, finer=False))
        out = twins
    return out


def _contact3d_cases(
    name: str, common: tuple[str, ...], geo: str, levels: tuple[str, ...], factors: tuple[float, ...], reference: bool
) -> list[BenchCase]:
    """One geometry's resolution x timestep grid; with `reference`, the finest level at the default step is the
    reference and the same at half the step its check (`finer`)."""
    h = contact3d_default_timestep(name, common)
    out = []
    for lvl in levels:
        for f in factors:
            dt = float(f"{h * f:.4g}")
            out.append(
                BenchCase(
                    name,
                    "contact3d",
                    {"level": lvl, "geometry": geo},
                    dt,
                    common + (f"simulation.resolution={lvl}", f"simulation.timestep_s={dt}"),
                    reference=reference and lvl == levels[-1] and f == 1.0,
                    timestep_factor=f,
                )
            )
    if not reference:
        return out
    dt = float(f"{h / 2:.4g}")
    same = next((i for i, c in enumerate(out) if c.resolution["level"] == levels[-1] and c.timestep_s == dt), None)
    if same is not None:  # the grid already runs the finest level at h/2: that run is the check
        out[same] = BenchCase(**{**out[same].__dict__, "finer": True})
    else:
        out.append(
            BenchCase(
                name,
                "contact3d",
                {"level": levels[-1], "geometry": geo},
                dt,
                common + (f"simulation.resolution={levels[-1]}", f"simulation.timestep_s={dt}"),
                finer=True,
                timestep_factor=0.5,
            )
        )
    return out


def relative_errors(summary: dict, reference: dict, keys: tuple[str, ...] = ERROR_KEYS) -> dict:
    """|x - x_ref| / |x_ref| for each of `keys` both summaries hold (None where undefined)."""
    err = {}
    for k in keys:
        x, r = summary.get(k), reference.get(k)
        if x is None or r is None or not np.isfinite(x) or not np.isfinite(r) or r == 0:
            err[k] = None
        else:
            err[k] = abs(x - r) / abs(r)
    return err
