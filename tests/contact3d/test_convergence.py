"""Convergence of the exact-flank fluctuation (issue 13): tangential_force_p2p_n and transmission_error_p2p_urad of the
seeds' CI runs (tests/contact3d/test_seeds_pieces.py) with contact.geometry flanks, the default slice count (medium:
wormsim.tooth.kernel.default_slices) against twice it and h against h/2 (at the default), each within 10 %; and
F_t's meshing band (below 1 kHz) against the slices. The slice study compares the summaries as the CI runs write
them; the step study compares per-step samples (record_every 1 in both runs: the p2p of the force itself; interval
means over a fixed time, record_every 1 against 2, differ by more: screw jack -10.9 % at 16 slices). Measured numbers
and the causes found in docs/contact3d.md ("Fluctuation against slices and step", "Default slice count")."""

from __future__ import annotations

import pytest

from tests.conftest import SCENARIOS
from tests.contact3d.test_seeds_pieces import CI
from wormsim.contact3d.runner import simulate
from wormsim.results.metrics import p2p_below
from wormsim.scenario import load_scenario

KEYS = ("tangential_force_p2p_n", "transmission_error_p2p_urad")
# issue 31: F_t p2p and p_H max (wormsim.tooth.hertz (4)) within 10 % of twice the slices; the TE p2p as well
SLICE_KEYS = (*KEYS, "contact_pressure_max_mpa")
MESH_BAND_HZ = 1000.0  # F_t's meshing band: below the lowest contact mode measured (involute_41, 1.3-1.8 kHz)
_CACHE: dict[tuple, dict] = {}
_BAND: dict[tuple, float] = {}


def _simulate(name: str, extra: tuple) -> None:
    """One run: its summary and F_t's p2p over the steady window below MESH_BAND_HZ (wormsim.results.metrics.p2p_below)."""
    sc = load_scenario(SCENARIOS / f"{name}.yaml", [*CI[name], "contact.geometry=flanks", *extra])
    res = simulate(sc)
    t = res.series["t_s"]
    t0, t1 = res.summary["steady_window_s"]
    m = (t >= t0) & (t <= t1)
    _CACHE[(name, extra)] = res.summary
    _BAND[(name, extra)] = p2p_below(t[m], res.series["tangential_force_n"][m], MESH_BAND_HZ)


def run(name: str, *extra: str) -> dict:
    """The seed's CI run with flanks and the extra overrides."""
    if (name, extra) not in _CACHE:
        _simulate(name, extra)
    return _CACHE[(name, extra)]


def mesh_band_p2p(name: str, *extra: str) -> float:
    """F_t p2p over the steady window below MESH_BAND_HZ."""
    if (name, extra) not in _BAND:
        _simulate(name, extra)
    return _BAND[(name, extra)]


def _per_step(name: str, half: bool = False) -> dict:
    """The CI run (half: at h/2) with one sample per step."""
    s = run(name)
    if not half:
        return s if s["record_every"] == 1 else run(name, "simulation.record_every=1")
    return run(name, f"simulation.timestep_s={s['timestep_s'] / 2}", "simulation.record_every=1")


DEFAULT_SLICES = {
    "screw_jack": 16,
    "seat_motor": 32,
    "involute_41": 24,
}  # wormsim.tooth.grid.default_slices at medium (the CI runs' resolution)


SLICES_XFAIL = {
    ("involute_41", "tangential_force_p2p_n"): "whole-band F_t p2p 458.1 N at 24 slices against 301.5 N at 48 "
    "(+51.9 %; below 1 kHz 389.1 against 296.1 N, +31.4 %; its default step 8.5e-5 s): with the teeth's compliance "
    "(1.01e9 N/m per tooth pair) the contact mode falls to about 770 Hz, where the slices' switching rings it; its "
    "p_H max converges (250.4 -> 252.9 MPa), and so does the TE p2p (11.21 -> 10.67 urad). The mode falls with the "
    "count (772 -> 652 Hz) by the contact rows' added mass (impedance d = 0.01 per row); at d = 0.001 it stays at "
    "941 Hz and F_t p2p is 582.7 N against 270.6 N (+115 %; at 5e-5 s 558 against 268 N, docs/data/"
    "slice_convergence_impedance.json)",
}


@pytest.mark.parametrize(
    "name,key",
    [
        pytest.param(n, k, marks=pytest.mark.xfail(reason=SLICES_XFAIL[(n, k)], strict=True))
        if (n, k) in SLICES_XFAIL
        else (n, k)
        for n in DEFAULT_SLICES
        for k in SLICE_KEYS
    ],
)
def test_flank_fluctuation_converged_in_slices(name, key):
    """The default slice count (the CI run, medium: flanks.default_slices) against twice it: within 10 % (issue 31:
    F_t p2p and p_H max, wormsim.tooth.hertz (4); and the TE p2p). p_H max: screw jack 318.3 -> 322.2 MPa, involute_41
    250.4 -> 252.9 MPa, seat motor 661.9 -> 628.9 MPa (+5.2 %; one contact's p_H, the maximum before: 341.9 -> 338.8,
    279.1 -> 292.8 and 844.7 -> 856.8 MPa; docs/data/slice_convergence_medium.json, _seat_motor.json; involute_41's at
    its default step 8.5e-5 s, 300.7 -> 294.4 MPa at 5e-5 s in the record). Seat motor
    (32; F_t p2p 0.07 % of its mean): F_t p2p 0.874 -> 0.856 N (-2.1 %), TE p2p 219.9 -> 203.4 urad (-7.5 %); at 16
    slices (the default before) F_t p2p is 1.062 N, -17.7 % to 32: the slices' switching rings the contact mode
    (F_t above 1 kHz p2p 0.324 / 0.203 N at 16 / 32; all at the default step, 6.4e-6 s). Screw jack (16): F_t p2p
    1.636 -> 1.639 N, TE p2p 8.580 -> 8.650 urad; its whole-band F_t p2p is the contact mode's ringing and jumps between other counts (24 -> 48: +38 %,
    32 -> 64: x2.0; docs/contact3d.md, 'Default slice count'), its meshing band below converges."""
    n = DEFAULT_SLICES[name]
    a, b = run(name), run(name, f"contact.slices={2 * n}")
    assert a["flank_slices"] == n and b["flank_slices"] == 2 * n
    assert b[key] == pytest.approx(a[key], rel=0.10), (key, a[key], b[key])


MESH_BAND_XFAIL = {
    "involute_41": "meshing band below 1 kHz: F_t p2p 389.1 N at 24 slices against 296.1 N at 48 (-23.9 %; its "
    "default step 8.5e-5 s): with the "
    "teeth's compliance (its default; 1.01e9 N/m per tooth pair against Hertz's 5.41e9) the contact mode falls from "
    "1.3-1.8 kHz to about 770 Hz, inside the band, where the slices' switching rings it (the F_t peak at the 32nd "
    "meshing harmonic, 772.6 Hz: tests/contact3d/test_seeds.py's MESH_XFAIL)",
}


@pytest.mark.parametrize(
    "name",
    [
        pytest.param(n, marks=pytest.mark.xfail(reason=MESH_BAND_XFAIL[n], strict=True)) if n in MESH_BAND_XFAIL else n
        for n in DEFAULT_SLICES
    ],
)
def test_flank_mesh_band_converged_in_slices(name):
    """F_t's meshing band (below 1 kHz, under the contact modes) at the default against twice the slices, within 10 %:
    screw jack 0.359 -> 0.341 N (16 -> 32), seat motor 0.815 -> 0.866 N (32 -> 64; studies/slice_convergence.py)."""
    n = DEFAULT_SLICES[name]
    a, b = mesh_band_p2p(name), mesh_band_p2p(name, f"contact.slices={2 * n}")
    assert b == pytest.approx(a, rel=0.10), (a, b)


@pytest.mark.parametrize("name", list(DEFAULT_SLICES))
def test_flank_fluctuation_converged_in_timestep(name):
    """h against h/2 at the default slices, per-step samples: within 10 % (screw jack, 16: F_t p2p 1.636 -> 1.622 N,
    TE p2p 8.580 -> 8.579 urad; seat motor, 32, 6.4e-6 s: F_t p2p 0.874 -> 0.869 N, TE p2p 219.935 -> 219.922 urad;
    h and h/2 together ~75 s at a load of ~2.5, the h/2 test 228 s at ~7)."""
    a, b = _per_step(name), _per_step(name, half=True)
    assert b["timestep_s"] == pytest.approx(a["timestep_s"] / 2)
    for key in KEYS:
        assert b[key] == pytest.approx(a[key], rel=0.10), (key, a[key], b[key])
