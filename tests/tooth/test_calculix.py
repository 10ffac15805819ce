"""The CalculiX contact check (wormsim.tooth.calculix, issue 30 item 7) on a small case: the screw jack at one worm
angle on a coarse mesh. Checks that can fail: the contact forces' moments about the wheel axis, summed over the
wheel teeth, balance the torque of the wheel's support (equilibrium of CalculiX's own solution, within 3 %); the
mesh stiffness per face width lies within a factor 0.5 .. 3 of ISO 6336-1's single stiffness c' of the virtual spur
gear (c_gamma of a contact ratio near 2 is 1.75 c'; the FE's coarse contact zone and the worm's shaft make it
softer or stiffer by tens of per cent, not by a factor 3); at least two wheel teeth carry load (the TCA's teeth in
contact at this angle). Long (tests/conftest.py): the solve takes minutes on one core."""

from __future__ import annotations

import math

import pytest

from wormsim.physics import gear_theory
from wormsim.physics.geometry import derive
from wormsim.scenario import load_scenario
from wormsim.tooth import calculix as cx
from wormsim.tooth.compliance import iso6336_stiffness

pytestmark = pytest.mark.skipif(
    cx.ccx_path() is None, reason="CalculiX (ccx) is not installed: apt-get install calculix-ccx"
)


@pytest.fixture(scope="module")
def small_case(tmp_path_factory, monkeypatch_module):
    sc = load_scenario("scenarios/screw_jack.yaml")
    g = derive(sc.gear)
    monkeypatch_module.setattr(cx, "H_FINE_MX", 0.4)
    monkeypatch_module.setattr(cx, "H_MAX_MX", 1.2)
    side = gear_theory.duty(sc, g.hand).working_flank
    m = sc.materials
    lag = 12.0 / (15e9 * g.face_width * cx.arm0_m(g) ** 2)
    r = cx.solve(g, m, side, 0.0, lag, workdir=tmp_path_factory.mktemp("ccx"))
    return g, m, r


@pytest.fixture(scope="module")
def monkeypatch_module():
    mp = pytest.MonkeyPatch()
    yield mp
    mp.undo()


def test_torque_balance(small_case):
    _, _, r = small_case
    assert r["torque_nm"] > 0
    assert abs(r["torque_balance"]) < 0.03, r


def test_stiffness_against_iso6336(small_case):
    g, m, r = small_case
    c = iso6336_stiffness(g, m)
    ratio = r["mesh_stiffness_per_width_n_per_mm_um"] / c["c_prime"]
    assert 0.5 < ratio < 3.0, (ratio, r["mesh_stiffness_per_width_n_per_mm_um"], c)


def test_teeth_share_the_load(small_case):
    _, _, r = small_case
    assert r["teeth_loaded"] >= 2, r["load_share"]
    assert math.isclose(sum(r["load_share"].values()), 1.0, rel_tol=1e-9)
