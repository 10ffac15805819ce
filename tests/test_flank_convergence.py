"""Convergence of the exact-flank fluctuation (issue 13): tangential_force_p2p_n and transmission_error_p2p_urad of
the seeds' CI runs (tests/test_contact3d_seeds.py) with contact.geometry flanks, the default slice count (medium: 32)
against 64 slices and h against h/2 (at the default), each within 10 %; and F_t's meshing band (below 1 kHz) against
the slices. The slice study compares the summaries as the CI runs write them; the step study compares per-step
samples (record_every 1 in both runs: the p2p of the force itself; interval means over a fixed time, record_every 1
against 2, differ by more: screw jack -10.9 % at 16 slices). Measured numbers and the causes found in
docs/contact3d.md ("Fluctuation against slices and step", "Default slice count")."""

from __future__ import annotations

import pytest
from conftest import SCENARIOS
from test_contact3d_seeds import CI
from test_contact3d_seeds_flanks import run as run_ci

from wormsim.contact3d.runner import simulate
from wormsim.metrics import p2p_below
from wormsim.scenario import load_scenario

KEYS = ("tangential_force_p2p_n", "transmission_error_p2p_urad")
MESH_BAND_HZ = 1000.0  # F_t's meshing band: below the lowest contact mode measured (involute_41, 1.3-1.8 kHz)
_CACHE: dict[tuple, dict] = {}
_SERIES: dict[tuple, float] = {}


def run(name: str, *extra: str) -> dict:
    """The seed's CI run with flanks and the extra overrides (the plain one shared with the seed tests)."""
    if not extra:
        return run_ci(name)["summary"]
    if (name, extra) not in _CACHE:
        sc = load_scenario(SCENARIOS / f"{name}.yaml", [*CI[name], "contact.geometry=flanks", *extra])
        _CACHE[(name, extra)] = simulate(sc).summary
    return _CACHE[(name, extra)]


def mesh_band_p2p(name: str, *extra: str) -> float:
    """F_t p2p over the steady window below MESH_BAND_HZ (wormsim.metrics.p2p_below)."""
    if (name, extra) not in _SERIES:
        sc = load_scenario(SCENARIOS / f"{name}.yaml", [*CI[name], "contact.geometry=flanks", *extra])
        res = simulate(sc)
        t = res.series["t_s"]
        t0, t1 = res.summary["steady_window_s"]
        m = (t >= t0) & (t <= t1)
        _SERIES[(name, extra)] = p2p_below(t[m], res.series["tangential_force_n"][m], MESH_BAND_HZ)
    return _SERIES[(name, extra)]


def _per_step(name: str, half: bool = False) -> dict:
    """The CI run (half: at h/2) with one sample per step."""
    s = run(name)
    if not half:
        return s if s["record_every"] == 1 else run(name, "simulation.record_every=1")
    return run(name, f"simulation.timestep_s={s['timestep_s'] / 2}", "simulation.record_every=1")


# whole-band F_t p2p at the default (32) against 64 slices; the contact mode's ringing (5.2-6.2 kHz) makes it
SLICES_XFAIL = {
    ("screw_jack", "tangential_force_p2p_n"): (
        "32 -> 64 slices: F_t p2p 1.639 -> 3.282 N (x2.0) on a 400 N mean: the contact mode's ringing (lines at "
        "5.2-6.2 kHz) is the p2p, and its p2p does not converge in slices (12 / 16 / 24 / 32 / 48 / 64: 1.33 / 1.64 / "
        "1.15 / 1.64 / 1.59 / 3.28 N); F_t below 1 kHz 0.341 -> 0.316 N (-7.3 %) and the TE (-2.1 %) converge "
        "(docs/contact3d.md, 'Default slice count')"
    ),
}


def _xf(table, n):
    return pytest.param(*n, marks=pytest.mark.xfail(reason=table[n], strict=True)) if n in table else n


@pytest.mark.parametrize(
    ("name", "key"), [_xf(SLICES_XFAIL, (n, k)) for n in ("screw_jack", "seat_motor") for k in KEYS]
)
def test_flank_fluctuation_converged_in_slices(name, key):
    """The default slice count (the CI run, medium: 32) against twice it: within 10 %. Seat motor (F_t p2p 0.08 %
    of its mean): 0.869 -> 0.851 N (-2.1 %), TE p2p 219.9 -> 203.4 urad (-7.5 %); at 16 slices (the default
    before) F_t p2p was 1.043 N, -16.7 % to 32: the slices' switching rang the contact mode (F_t above 1 kHz p2p
    0.313 / 0.189 N at 16 / 32). Screw jack TE p2p 8.650 -> 8.472 urad."""
    a, b = run(name), run(name, "contact.slices=64")
    assert a["flank_slices"] == 32 and b["flank_slices"] == 64
    assert b[key] == pytest.approx(a[key], rel=0.10), (key, a[key], b[key])


@pytest.mark.parametrize("name", ["screw_jack", "seat_motor"])
def test_flank_mesh_band_converged_in_slices(name):
    """F_t's meshing band (below 1 kHz, under the contact modes) at the default (32) against 64 slices, within 10 %:
    screw jack 0.341 -> 0.316 N, seat motor 0.815 -> 0.866 N (measured with the sweep, sweeps/slice_convergence.py)."""
    a, b = mesh_band_p2p(name), mesh_band_p2p(name, "contact.slices=64")
    assert b == pytest.approx(a, rel=0.10), (a, b)


@pytest.mark.parametrize("name", ["screw_jack", "seat_motor"])
def test_flank_fluctuation_converged_in_timestep(name):
    """h against h/2 at 16 slices, per-step samples: within 10 % (screw jack: F_t p2p 1.636 -> 1.622 N, TE p2p
    8.580 -> 8.579 urad; seat motor, its h/2 run ~110 s: F_t p2p 1.048 -> 1.045 N, TE p2p 216.41 -> 216.40 urad)."""
    a, b = _per_step(name), _per_step(name, half=True)
    assert b["timestep_s"] == pytest.approx(a["timestep_s"] / 2)
    for key in KEYS:
        assert b[key] == pytest.approx(a[key], rel=0.10), (key, a[key], b[key])
