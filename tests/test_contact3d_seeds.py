"""Validation of contact3d on the three seed gears (issue 4), CI-sized: same gear, materials, contact law
and load as scenarios/*.yaml; shorter ramps and durations (a few meshing periods); resolution fine
enough that meshgen's piece bulge stays inside half the backlash (involute_41 needs `fine`).
seat_motor runs its worm at 1800 rpm instead of 36 rpm (a 0.6 Hz mesh would need 20 s of 2 us steps).

Checks per seed: ratio within 0.1 % of z2/z1; meshing frequency within max(1 %, one FFT bin) of
z1 n1 / 60; torque balance: mean tangential force x r2 within 2 % of the load torque; efficiency within
3 % of the wedge model's tan(g) / tan(g + rho'). Failing physics stays strict and is marked xfail with
the measured numbers (see docs/contact3d.md).
"""
from __future__ import annotations

import math
from pathlib import Path

import pytest

from wormsim.scenario import load_scenario
from wormsim.simulate import simulate

SCEN = Path(__file__).resolve().parent.parent / "scenarios"
CI = {
    "seat_motor": ["drive.speed_rpm=1800", "drive.ramp_s=0.02", "load.ramp_s=0.02", "simulation.duration_s=0.1",
                   "simulation.resolution=medium"],
    "screw_jack": ["drive.ramp_s=0.02", "load.ramp_s=0.02", "simulation.duration_s=0.11", "simulation.resolution=medium"],
    "involute_41": ["drive.ramp_s=0.02", "load.ramp_s=0.02", "simulation.duration_s=0.15",
                    "simulation.resolution=fine"],
}
_CACHE: dict[str, dict] = {}


def run(name: str) -> dict:
    if name not in _CACHE:
        sc = load_scenario(SCEN / f"{name}.yaml", CI[name])
        res = simulate(sc)
        _CACHE[name] = {"summary": res.summary, "scenario": sc}
    return _CACHE[name]


SEEDS = list(CI)


@pytest.mark.parametrize("name", SEEDS)
def test_ratio_within_0p1_percent(name):
    s = run(name)["summary"]
    assert abs(s["ratio"] / s["ratio_theory"] - 1) < 1e-3, s["ratio"]


MESH_XFAIL = {}
EFF_XFAIL = {}


@pytest.mark.parametrize("name", [pytest.param(n, marks=pytest.mark.xfail(reason=MESH_XFAIL[n], strict=True))
                                  if n in MESH_XFAIL else n for n in SEEDS])
def test_mesh_frequency(name):
    s = run(name)["summary"]
    tol = max(0.01 * s["mesh_frequency_theory_hz"], s["mesh_frequency_resolution_hz"])
    assert abs(s["mesh_frequency_hz"] - s["mesh_frequency_theory_hz"]) <= tol, (
        s["mesh_frequency_hz"], s["mesh_frequency_theory_hz"], s["mesh_frequency_resolution_hz"])


@pytest.mark.parametrize("name", SEEDS)
def test_torque_balance_within_2_percent(name):
    r = run(name)
    s, sc = r["summary"], r["scenario"]
    from meshgen.geometry import derive

    r2 = derive(sc.gear).r2
    assert abs(s["tangential_force_mean_n"] * r2 / sc.load.torque_nm - 1) < 0.02, s["tangential_force_mean_n"]


@pytest.mark.parametrize("name", [pytest.param(n, marks=pytest.mark.xfail(reason=EFF_XFAIL[n], strict=True))
                                  if n in EFF_XFAIL else n for n in SEEDS])
def test_efficiency_within_3_percent_of_wedge(name):
    s = run(name)["summary"]
    assert abs(s["efficiency"] / s["efficiency_theory"] - 1) < 0.03, (s["efficiency"], s["efficiency_theory"])
