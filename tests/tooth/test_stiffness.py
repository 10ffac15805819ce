"""One home for the tooth pair's stiffness (wormsim.tooth.stiffness.per_length_stiffness, issue 30): both levels
take k' from it, report its source, and contact3d's timestep follows the stiffness it gives
(docs/decisions/0034-contact-stiffness-override.md)."""

from __future__ import annotations

import math

import pytest

from meshgen.geometry import derive
from tests.conftest import SCENARIOS
from wormsim.contact3d.mjcf import prepare
from wormsim.contact3d.timestep import choose_timestep
from wormsim.physics.gear_theory import effective_modulus_pa
from wormsim.scenario import load_scenario
from wormsim.tooth import stiffness as ST

SCREW = SCENARIOS / "screw_jack.yaml"
UNSET = "contact.stiffness_n_per_m=null"


def _sc(*sets):
    return load_scenario(SCREW, list(sets))


def test_an_explicit_stiffness_overrides_the_teeth():
    sc = _sc()
    g = derive(sc.gear)
    kp, src = ST.per_length_stiffness(sc.contact, g, sc.materials)
    assert src == "scenario"
    assert kp * g.face_width == pytest.approx(4.39e8, rel=1e-12)  # the seed's ADAMS K, as it ran


def test_hertz_is_pi_e_star_over_4():
    sc = _sc(UNSET, "contact.stiffness_model=hertz")
    kp, src = ST.per_length_stiffness(sc.contact, derive(sc.gear), sc.materials)
    assert src == "hertz"
    assert kp == pytest.approx(math.pi * effective_modulus_pa(sc.materials) / 4, rel=1e-12)


def test_the_default_is_the_teeth_compliance():
    from wormsim.tooth.stiffness import line_stiffness_n_per_m2

    sc = _sc(UNSET)
    assert sc.contact.stiffness_model == "teeth"
    g = derive(sc.gear)
    kp, src = ST.per_length_stiffness(sc.contact, g, sc.materials)
    assert src == "teeth"
    assert kp == pytest.approx(line_stiffness_n_per_m2(g, sc.materials), rel=1e-12)
    # teeth that bend are softer than Hertz's rigid line contact (issue 30: 5-7x on steel/bronze)
    assert kp < ST.hertz_per_length_n_per_m2(sc.materials) / 2


@pytest.mark.parametrize(
    "sets", [(), (UNSET, "contact.stiffness_model=hertz"), (UNSET,)], ids=["scenario", "hertz", "teeth"]
)
def test_contact3d_pair_stiffness_is_the_one_home_s(sets):
    """contact3d's K = k' b2 with torsional's k', source included."""
    sc = _sc("contact.geometry=flanks", *sets)
    g = derive(sc.gear)
    kp, src = ST.per_length_stiffness(sc.contact, g, sc.materials)
    law = prepare(sc).law
    assert law.pair_stiffness_n_per_m == pytest.approx(kp * g.face_width, rel=1e-12)
    assert law.stiffness_source == src


def test_the_timestep_follows_the_softer_contact():
    """The stable limit goes as 1 / sqrt(K) at a fixed damping ratio: the teeth's K gives a larger default step."""
    hz = _sc("contact.geometry=flanks", UNSET, "contact.stiffness_model=hertz")
    th = _sc("contact.geometry=flanks", UNSET)
    ph, pt = prepare(hz), prepare(th)
    ratio = ph.law.pair_stiffness_n_per_m / pt.law.pair_stiffness_n_per_m
    assert ratio > 2
    assert pt.law.stable_limit_s / ph.law.stable_limit_s == pytest.approx(math.sqrt(ratio), rel=1e-9)
    h_hertz, _ = choose_timestep(hz, derive(hz.gear), ph.law)
    h_teeth, _ = choose_timestep(th, derive(th.gear), pt.law)
    assert h_teeth > h_hertz


def test_torsional_k_theta_is_the_loaded_tcas_with_the_teeth():
    """mesh_stiffness_table: with the teeth's compliance k(theta1) of each side is the LTCA's at its samples (same mean
    as the contact-line TCA's with k'_eff, a smaller variation: the bending couples the lines); with an explicit K or
    Hertz it is the contact-line TCA's."""
    import numpy as np

    from wormsim.tooth import compliance, ltca, mesh_stiffness

    sc = _sc(UNSET)
    g = derive(sc.gear)
    ms = ST.mesh_stiffness_table(sc.contact, g, sc.materials, 64)
    tca = mesh_stiffness.mesh_stiffness(g, ms.stiffness_per_length_n_per_m2, "teeth", 64)
    t = compliance.reference_torque_nm(g)
    for side, k in ((1, ms.k_mesh_fwd_n_per_m), (-1, ms.k_mesh_rev_n_per_m)):
        lt = ltca.loaded_contact(g, sc.materials, t, samples=ST.LTCA_SAMPLES, side=side)
        np.testing.assert_allclose(k[:: 64 // ST.LTCA_SAMPLES], lt.mesh_stiffness_n_per_m, rtol=1e-12)
    np.testing.assert_allclose(ms.k_theta_fwd_nm_per_rad, ms.k_mesh_fwd_n_per_m * ms.arm0_m**2, rtol=1e-12)
    assert np.mean(ms.k_mesh_fwd_n_per_m) == pytest.approx(np.mean(tca.k_mesh_fwd_n_per_m), rel=0.01)
    assert np.ptp(ms.k_mesh_fwd_n_per_m) < 0.8 * np.ptp(tca.k_mesh_fwd_n_per_m)  # 0.255 against 0.363 of the mean
    seed = _sc()
    kp, _ = ST.per_length_stiffness(seed.contact, g, seed.materials)
    same = ST.mesh_stiffness_table(seed.contact, g, seed.materials, 64)
    np.testing.assert_array_equal(
        same.k_mesh_fwd_n_per_m, mesh_stiffness.mesh_stiffness(g, kp, "scenario", 64).k_mesh_fwd_n_per_m
    )
