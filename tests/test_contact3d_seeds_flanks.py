"""The seed validation of tests/test_contact3d_seeds.py with `contact.geometry: flanks` (issue 13): same CI
configurations (slices by flanks.default_slices: seat_motor 32, screw_jack 16, involute_41 24), same criteria: ratio
0.1 %, meshing frequency, torque balance 2 %, efficiency within 3 % of the wedge model at the pitch radius and at the
contact radius, DIN 3975 radial force 3 %. Measured numbers of the expected failures in docs/contact3d.md."""

from __future__ import annotations

import pytest
from conftest import SCENARIOS
from test_contact3d_seeds import CI, assert_mesh_frequency

from wormsim.contact3d.runner import simulate
from wormsim.scenario import load_scenario

SCEN = SCENARIOS
SEEDS = list(CI)
_CACHE: dict[str, dict] = {}


def run(name: str) -> dict:
    if name not in _CACHE:
        sc = load_scenario(SCEN / f"{name}.yaml", CI[name] + ["contact.geometry=flanks"])
        _CACHE[name] = {"summary": simulate(sc).summary, "scenario": sc}
    return _CACHE[name]


# all three pass since contacts leave at zero load (wormsim.tooth.kernel, docs/contact3d.md): F_t peaks at
# 29.97 / 22.14 / 24.14 Hz (before: the 3rd harmonic, 89.9 / 66.4 Hz, from half a slice's load dropped at once; and
# involute_41's mesh mode at 1087 Hz with p2p 55 kN, now 292 N on 13.8 kN)
MESH_XFAIL: dict[str, str] = {}


def _xf(table, n):
    return pytest.param(n, marks=pytest.mark.xfail(reason=table[n], strict=True)) if n in table else n


@pytest.mark.parametrize("name", SEEDS)
def test_flanks_ratio_within_0p1_percent(name):
    s = run(name)["summary"]
    assert s["contact_geometry"] == "flanks"
    assert abs(s["ratio"] / s["ratio_theory"] - 1) < 1e-3, s["ratio"]


@pytest.mark.parametrize("name", [_xf(MESH_XFAIL, n) for n in SEEDS])
def test_flanks_mesh_frequency(name):
    assert_mesh_frequency(run(name)["summary"], "mesh_frequency_hz")


RADIAL_XFAIL = {
    "seat_motor": "the radial force's largest peak is the 2nd meshing harmonic, 59.94 Hz against 29.97 Hz, since "
    "contacts leave at zero load (F_t: 29.97 Hz, p2p 1.04 N on 1289 N at 16 slices, 0.87 N at 32); before, the slices' load steps put 29.97 Hz "
    "on top. Physical for the kernel: quasi-static at constant torque its radial harmonics 1-4 are 0.998, 1.239, "
    '0.688, 0.091 N (docs/contact3d.md, "Contacts leaving at zero load")',
}


@pytest.mark.parametrize("name", [_xf(RADIAL_XFAIL, n) for n in SEEDS])
def test_flanks_mesh_frequency_in_the_radial_force(name):
    assert_mesh_frequency(run(name)["summary"], "mesh_frequency_radial_hz")


@pytest.mark.parametrize("name", SEEDS)
def test_flanks_torque_balance_within_2_percent(name):
    from meshgen.geometry import derive

    r = run(name)
    s, sc = r["summary"], r["scenario"]
    assert abs(s["tangential_force_mean_n"] * derive(sc.gear).r2 / sc.load.torque_nm - 1) < 0.02


@pytest.mark.parametrize("name", SEEDS)
def test_flanks_efficiency_within_3_percent_of_wedge(name):
    """Passes for the seat motor too (pieces: -3.2 %, an xfail): exact flanks give 0.613 against 0.620."""
    s = run(name)["summary"]
    assert abs(s["efficiency"] / s["efficiency_theory"] - 1) < 0.03, (s["efficiency"], s["efficiency_theory"])


@pytest.mark.parametrize("name", SEEDS)
def test_flanks_efficiency_within_3_percent_at_the_contact_radius(name):
    s = run(name)["summary"]
    assert abs(s["efficiency"] / s["efficiency_theory_at_contact_radius"] - 1) < 0.03


@pytest.mark.parametrize("name", SEEDS)
def test_flanks_radial_force_on_the_line_of_centres_is_din_3975(name):
    s = run(name)["summary"]
    assert abs(s["radial_force_line_of_centres_mean_n"] / s["radial_force_theory_n"] - 1) < 0.03
