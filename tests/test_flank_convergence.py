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
    "seat_motor": (
        "16 -> 32 slices: F_t p2p 1.043 -> 0.869 N (-16.7 %, on a 1289 N mean: 0.08 % of it, the sum of the meshing "
        "harmonics 1-9, whose 1st-3rd agree within 5 %: 0.252 / 0.244, 0.112 / 0.112, 0.105 / 0.100 N); TE p2p "
        "216.4 -> 219.9 urad (+1.6 %) converged. 32 -> 64 slices: F_t p2p 0.851 N (-2.1 %), TE 203.4 urad (-7.5 %). "
        "Before contacts left at zero load at the profile's and the line's end: 4.18 -> 8.56 N"
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


@pytest.mark.parametrize("name", ["seat_motor"])
def test_flank_fluctuation_converged_in_slices_fine(name):
    """32 (fine) against 64 slices: within 10 % (seat motor, whose 16 -> 32 step is the xfail above: F_t p2p
    0.869 -> 0.851 N, TE p2p 219.9 -> 203.4 urad): the seat motor's fluctuation is converged from 32 slices."""
    a, b = run(name, "contact.slices=32"), run(name, "contact.slices=64")
    assert a["flank_slices"] == 32 and b["flank_slices"] == 64
    for key in KEYS:
        assert b[key] == pytest.approx(a[key], rel=0.10), (key, a[key], b[key])


@pytest.mark.parametrize("name", ["screw_jack", "seat_motor"])
def test_flank_fluctuation_converged_in_timestep(name):
    """h against h/2 at 16 slices, per-step samples: within 10 % (screw jack: F_t p2p 1.636 -> 1.622 N, TE p2p
    8.580 -> 8.579 urad; seat motor, its h/2 run ~110 s: F_t p2p 1.048 -> 1.045 N, TE p2p 216.41 -> 216.40 urad)."""
    a, b = _per_step(name), _per_step(name, half=True)
    assert b["timestep_s"] == pytest.approx(a["timestep_s"] / 2)
    for key in KEYS:
        assert b[key] == pytest.approx(a[key], rel=0.10), (key, a[key], b[key])
