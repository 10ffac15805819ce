"""Friction angle of seed 000: rho(Vs) = 1 / (a Vs^b + c) deg (table "Approximated formulae ...")."""

import math

import numpy as np
import pytest

from wormsim.physics.friction import GROUPS, rho_rad, rho_static_rad

DEG = math.pi / 180


# c of each friction group: seed 000 friction-angle table (rho = 1 / (a Vs^b + c) deg), lines I* to III*
@pytest.mark.parametrize("group, c", [("I", 0.151), ("II", 0.140), ("III", 0.088)])
def test_static_angle_is_one_over_c_degrees(group, c):
    assert rho_static_rad(group=group) == pytest.approx(DEG / c, rel=1e-12)


def test_group_iii_at_standstill_exceeds_the_mov_lead_angle():
    # seed 000's MOV: group III, lead angle 4.76 deg; rho(0) = 1/0.088 = 11.36 deg (self-locking at rest)
    assert rho_static_rad(group="III") / DEG == pytest.approx(11.3636, abs=1e-4)
    assert rho_static_rad(group="III") > 4.76 * DEG


@pytest.mark.parametrize("group", ["I", "II", "III"])
def test_value_by_hand_and_monotone(group):
    a, b, c = GROUPS[group]
    # Vs = 1 m/s: 1^b = 1, so rho = 1 / (a + c) deg
    assert rho_rad(1.0, group=group) == pytest.approx(DEG / (a + c), rel=1e-12)
    vs = np.linspace(0.0, 15.0, 200)
    r = rho_rad(vs, group=group)
    assert r.shape == vs.shape and np.all(np.diff(r) < 0)


def test_even_in_sliding_speed_and_float_in_float_out():
    assert isinstance(rho_rad(2.0, group="III"), float)
    assert rho_rad(-2.0, group="III") == rho_rad(2.0, group="III")
    assert np.isfinite(rho_rad(np.array([-3.0, 0.0, 3.0]), group="II")).all()


def test_constant_coefficient():
    assert rho_rad(np.array([0.0, 1.0, 10.0]), friction=0.05) == pytest.approx(np.full(3, math.atan(0.05)))
    assert rho_static_rad(friction=0.1) == pytest.approx(math.atan(0.1))


def test_bad_arguments():
    with pytest.raises(ValueError, match="exactly one"):
        rho_rad(1.0)
    with pytest.raises(ValueError, match="exactly one"):
        rho_rad(1.0, group="I", friction=0.1)
    with pytest.raises(ValueError, match="allowed I, II, III"):
        rho_rad(1.0, group="IV")
