"""wormsim.tooth.ltca: the loaded tooth contact analysis over one mesh cycle (docs/tooth_compliance.md)."""

from __future__ import annotations

import copy

import numpy as np
import pytest

from tests.conftest import SCENARIOS
from wormsim.physics.geometry import derive
from wormsim.scenario import load_scenario
from wormsim.tooth import ltca


@pytest.fixture(scope="module")
def screw_jack():
    sc = load_scenario(SCENARIOS / "screw_jack.yaml")
    return sc, derive(sc.gear)


def _with_moduli(materials, worm_gpa: float, wheel_gpa: float, wheel_nu: float | None = None):
    m = copy.deepcopy(materials)
    m.worm.youngs_modulus_gpa = worm_gpa
    m.wheel.youngs_modulus_gpa = wheel_gpa
    if wheel_nu is not None:
        m.wheel.poisson_ratio = wheel_nu
    return m


def test_torque_balance_and_shares(screw_jack):
    """The rigid-body balance: the segments' normal forces times their arms sum to the wheel torque at every angle;
    the tooth shares sum to 1; every load is compressive; the wheel lags (TE > 0); 2 or 3 teeth carry."""
    sc, g = screw_jack
    t = 12.0
    r = ltca.loaded_contact(g, sc.materials, t)
    assert r.te_loaded_rad.shape == (16,) and (r.te_loaded_rad > 0).all()
    for c in r.contacts:
        assert (c.line_load_n_per_m >= 0).all()
        assert np.sum(c.line_load_n_per_m * c.length_m * c.arm_m) == pytest.approx(t, rel=1e-9)
    np.testing.assert_allclose(r.load_share.sum(axis=1), 1.0, rtol=1e-9)
    assert set(np.unique(r.teeth_in_contact)) <= {2, 3}
    s = r.summary()
    assert 0.5 < s["load_share_max"] < 1.0
    assert s["mesh_stiffness_mean_n_per_m"] == pytest.approx(np.mean(t / r.te_loaded_rad / r.arm0_m**2))


def test_pom_wheel_several_times_softer(screw_jack):
    """The same gear with a POM wheel (seed 001's 3.1 GPa, 0.39) against its bronze wheel: several times softer,
    and more of the load moves to the other teeth (a smaller largest share)."""
    sc, g = screw_jack
    bronze = ltca.loaded_contact(g, sc.materials, 12.0).summary()
    pom = ltca.loaded_contact(g, _with_moduli(sc.materials, 210.0, 3.1, 0.39), 12.0).summary()
    ratio = bronze["mesh_stiffness_mean_n_per_m"] / pom["mesh_stiffness_mean_n_per_m"]
    assert ratio > 5, ratio
    assert pom["load_share_max"] < bronze["load_share_max"]


@pytest.mark.long  # two more FE models (~15 s each cold)
def test_doubling_moduli_doubles_stiffness(screw_jack):
    """E of both bodies doubled at twice the torque doubles k within 2 % (the FE parts are linear in 1 / E, and
    Weber-Banaschek's flattening depends on q / E: twice the load keeps its Hertz width); at the same torque the
    flattening's logarithm makes it a little less than 2 (the Hertz width shrinks by sqrt 2, ln(2 h / b) grows;
    measured 1.94)."""
    sc, g = screw_jack
    e1, e2 = sc.materials.worm.youngs_modulus_gpa, sc.materials.wheel.youngs_modulus_gpa
    base = ltca.loaded_contact(g, sc.materials, 12.0).summary()["mesh_stiffness_mean_n_per_m"]
    stiff = _with_moduli(sc.materials, 2 * e1, 2 * e2)
    same_strain = ltca.loaded_contact(g, stiff, 24.0).summary()["mesh_stiffness_mean_n_per_m"]
    same_load = ltca.loaded_contact(g, stiff, 12.0).summary()["mesh_stiffness_mean_n_per_m"]
    assert same_strain / base == pytest.approx(2.0, rel=0.02)
    assert 1.8 < same_load / base < 2.0


@pytest.mark.long  # the h/2 FE model (minutes)
def test_mesh_density_h_vs_h2(screw_jack):
    """FE mesh density 1 (h) against 2 (h/2): the mean mesh stiffness moves by at most 5 %."""
    sc, g = screw_jack
    k1 = ltca.loaded_contact(g, sc.materials, 12.0, density=1).summary()["mesh_stiffness_mean_n_per_m"]
    k2 = ltca.loaded_contact(g, sc.materials, 12.0, density=2).summary()["mesh_stiffness_mean_n_per_m"]
    assert abs(k2 / k1 - 1) <= 0.05, (k1, k2)


def test_deviations_gaps(screw_jack):
    """Assembly errors enter as the kinematic gaps g_i: a vanishing centre-distance error gives the perfect pair's
    result; a 10 um pitch deviation of the tooth that carries in the middle of the cycle changes its share and adds
    a kinematic TE; a +20 um centre distance opens the backlash (the wheel lags about da tan(alpha_n) / r2 more) and
    concentrates the load on fewer points (a lower secant stiffness)."""
    from meshgen.displaced import Deviations

    sc, g = screw_jack
    perfect = ltca.loaded_contact(g, sc.materials, 12.0)
    tiny = ltca.loaded_contact(g, sc.materials, 12.0, deviations=Deviations(center_distance=1e-12))
    for key, value in perfect.summary().items():
        assert tiny.summary()[key] == pytest.approx(value, rel=1e-3), key
    col = list(perfect.teeth).index(-1)
    shifted = ltca.loaded_contact(g, sc.materials, 12.0, deviations=Deviations(tooth_shift=(0.0,) * 23 + (10e-6,)))
    assert np.max(np.abs(shifted.load_share[:, col] - perfect.load_share[:, col])) > 0.05
    assert np.ptp(shifted.te_loaded_rad) > np.ptp(perfect.te_loaded_rad)
    wide = ltca.loaded_contact(g, sc.materials, 12.0, deviations=Deviations(center_distance=20e-6))
    lag = 20e-6 * np.tan(g.alpha_n) / g.r2
    assert np.mean(wide.te_loaded_rad - perfect.te_loaded_rad) == pytest.approx(lag, rel=0.3)
    assert wide.summary()["mesh_stiffness_mean_n_per_m"] < perfect.summary()["mesh_stiffness_mean_n_per_m"]


def test_flank_sides_mirror(screw_jack):
    """The reverse flank (side -1) is the working flank mirrored in the face (a symmetric thread and tooth): the same
    stiffness and shares, with the compliance grid read mirrored (ToothCompliance.kernel)."""
    sc, g = screw_jack
    fwd = ltca.loaded_contact(g, sc.materials, 12.0, side=1).summary()
    rev = ltca.loaded_contact(g, sc.materials, 12.0, side=-1).summary()
    for key, value in fwd.items():
        assert rev[key] == pytest.approx(value, rel=1e-6), key


@pytest.mark.long  # another FE model (~15 s cold)
def test_left_hand_mirrors_right_hand(screw_jack):
    """A left-hand worm gear is the right-hand one mirrored: the same LTCA up to the FE meshes of the mirrored
    geometry (measured 0.6 % apart on the screw jack)."""
    sc, g = screw_jack
    left_sc = load_scenario(SCENARIOS / "screw_jack.yaml", ["gear.hand=left"])
    right = ltca.loaded_contact(g, sc.materials, 12.0).summary()
    left = ltca.loaded_contact(derive(left_sc.gear), left_sc.materials, 12.0).summary()
    assert left["mesh_stiffness_mean_n_per_m"] == pytest.approx(right["mesh_stiffness_mean_n_per_m"], rel=0.02)
    assert left["teeth_in_contact_mean"] == right["teeth_in_contact_mean"]
