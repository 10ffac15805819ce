"""Convergence of the exact-flank fluctuation (issue 13): tangential_force_p2p_n and transmission_error_p2p_urad of
the seeds' CI runs (tests/test_contact3d_seeds.py) with contact.geometry flanks, 16 against 32 slices and h against
h/2 (16 slices), each within 10 %. The slice study compares the summaries as the CI runs write them; the step study
compares per-step samples (record_every 1 in both runs: the p2p of the force itself; interval means over a fixed
time, record_every 1 against 2, differ by more: screw jack -10.9 %). Measured numbers and the causes found in
docs/contact3d.md ("Fluctuation against slices and step")."""

from __future__ import annotations

import pytest
from conftest import SCENARIOS
from test_contact3d_seeds import CI
from test_contact3d_seeds_flanks import run as run_ci

from wormsim.contact3d.runner import simulate
from wormsim.scenario import load_scenario

KEYS = ("tangential_force_p2p_n", "transmission_error_p2p_urad")
_CACHE: dict[tuple, dict] = {}


def run(name: str, *extra: str) -> dict:
    """The seed's CI run with flanks and the extra overrides (the plain one shared with the seed tests)."""
    if not extra:
        return run_ci(name)["summary"]
    if (name, extra) not in _CACHE:
        sc = load_scenario(SCENARIOS / f"{name}.yaml", [*CI[name], "contact.geometry=flanks", *extra])
        _CACHE[(name, extra)] = simulate(sc).summary
    return _CACHE[(name, extra)]


def _per_step(name: str, half: bool = False) -> dict:
    """The CI run (half: at h/2) with one sample per step."""
    s = run(name)
    if not half:
        return s if s["record_every"] == 1 else run(name, "simulation.record_every=1")
    return run(name, f"simulation.timestep_s={s['timestep_s'] / 2}", "simulation.record_every=1")


SLICES_XFAIL = {
    "screw_jack": (
        "16 -> 32 slices: F_t p2p 3.83 -> 4.89 N (+27 %, on a 400 N mean: mesh-mode ringing after the remaining "
        "fast stiffness changes); TE p2p 8.61 -> 8.69 urad (+0.9 %) converged. Before contacts left at zero load: "
        "F_t p2p 14.5 -> 6.3 N"
    ),
    "seat_motor": (
        "16 -> 32 slices: F_t p2p 3.83 -> 11.66 N (x3, on a 1289 N mean: the line point jumps along the flat gap "
        "at 31 um deflection, steps up to 11 N quasi-static at 32 slices); TE p2p 198.4 -> 197.6 urad (-0.4 %) "
        "converged (taper as committed: 4.18 -> 8.56 N, TE 214.4 -> 221.2 urad, +3.2 %). Before: F_t p2p 51.5 -> 22.4 N, "
        "TE 226 -> 252 urad"
    ),
}


def _xf(table, n):
    return pytest.param(n, marks=pytest.mark.xfail(reason=table[n], strict=True)) if n in table else n


@pytest.mark.parametrize("name", [_xf(SLICES_XFAIL, n) for n in ("screw_jack", "seat_motor")])
def test_flank_fluctuation_converged_in_slices(name):
    """16 (the CI run, medium) against 32 slices: within 10 %."""
    a, b = run(name), run(name, "contact.slices=32")
    assert a["flank_slices"] == 16 and b["flank_slices"] == 32
    for key in KEYS:
        assert b[key] == pytest.approx(a[key], rel=0.10), (key, a[key], b[key])


@pytest.mark.parametrize("name", ["screw_jack"])
def test_flank_fluctuation_converged_in_timestep(name):
    """h against h/2 at 16 slices, per-step samples: within 10 % (screw jack: F_t p2p 3.833 -> 3.810 N, TE p2p
    8.607 -> 8.605 urad). (Seat motor measured before contacts left at zero load, not run here for time: its h/2 run
    at 2.5e-6 s takes 150 s; F_t p2p 55.5 -> 50.1 N (-9.7 %), TE p2p 226.5 -> 223.9 urad.)"""
    a, b = _per_step(name), _per_step(name, half=True)
    assert b["timestep_s"] == pytest.approx(a["timestep_s"] / 2)
    for key in KEYS:
        assert b[key] == pytest.approx(a[key], rel=0.10), (key, a[key], b[key])
