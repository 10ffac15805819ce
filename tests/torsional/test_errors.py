"""The torsional level's loaded tooth contact analysis of the displaced flanks (issue 12; wormsim.torsional.loaded_tca,
docs/errors.md section 5a): the perfect pair's slope against mesh_stiffness's k(theta), and a shaft angle error's
effect on the mesh stiffness, the loaded contact band and the loaded transmission error."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest

from wormsim.physics import gear_theory as gt
from wormsim.physics.geometry import derive, displaced_pair
from wormsim.scenario import load_scenario
from wormsim.tooth.mesh_stiffness import mesh_stiffness, stiffness_at
from wormsim.tooth.stiffness import per_length_stiffness
from wormsim.torsional import loaded_tca as lt

SCEN = Path(__file__).resolve().parents[2] / "scenarios"
# contact3d (exact flanks) on the same gear with the same shaft angles: the record of studies/errors_shaft_angle.py
# (docs/data/errors_shaft_angle.json, with its provenance): rows for 0, +0.1 and -0.1 deg
CONTACT3D = {
    r["shaft_angle_deg"]: r
    for r in json.loads((SCEN.parent / "docs" / "data" / "errors_shaft_angle.json").read_text())["rows"]
}


def _pair(name: str, sets=()):
    sc = load_scenario(SCEN / f"{name}.yaml", ["model=torsional", *sets])
    g = derive(sc.gear)
    kp, src = per_length_stiffness(sc.contact, g, sc.materials)
    return sc, g, kp, src


SLOPE_XFAIL = {
    "seat_motor": "torque per lag at 1 urad 13492 against the contact-line TCA's 12984 (+3.9 %; 12974 before decision "
    "0052): both are off. The reference is not converged in its grid (121 x 81: 12984; 241 x 161: 13175; 481 x 321: "
    "13279; 961 x 641: 13339; 1921 x 1281: 13367; limit about 13395), against which the kernel's mean is +0.94 / +0.66 "
    "/ +0.59 % at 32 / 64 / 128 slices (before decision 0052 -2.95 / -3.10 / -3.20 %). Per worm angle the kernel is "
    "not: at angle 0 +13.0 % at 128 slices, from decision 0052's depth for a line point past the profile's lower end "
    "(the end parabola gives the leaving tooth's slices 0.6-2.66 x the conjugate line's own 18 nm depth): a depth "
    "error of tens of nm, about 0.55 mN m at every lag (518 / 63 / 5 N m/rad of the slope at 1 / 10 / 100 urad), "
    "negligible at working depths of a micrometre and more",
}


@pytest.mark.parametrize(
    "name",
    [
        pytest.param(n, marks=pytest.mark.xfail(reason=SLOPE_XFAIL[n], strict=True)) if n in SLOPE_XFAIL else n
        for n in ("screw_jack", "seat_motor")
    ],
)
def test_perfect_pair_slope_is_the_mesh_stiffness(name):
    """At a small lag (1 urad) past the first touch the table's torque per lag is k(theta) of the contact-line TCA
    (measured, 32 slices, 16 worm angles: mean ratio 0.997 screw jack, 0.994 seat motor; per worm angle within 3.2 %
    and 5.6 %). The secant grows with the lag (more of the flanks comes into reach): +1.1 / +2.9 % at 10 urad,
    +3.1 / +4.6 % at 100 urad (docs/errors.md section 5a)."""
    sc, g, kp, _ = _pair(name)
    ev = lt.Evaluator(g, None, kp * g.face_width, lt.SLICES)
    th = np.arange(16) * (2 * math.pi / g.z1) / 16
    hz, gap, x = g.hand * g.z1 / g.z2, g.backlash / (2 * g.r2), 1e-6
    k_tab = np.array([ev.torque(t, hz * t - (gap + x)) / x for t in th])
    k_ref = stiffness_at(g, kp, th, 1)
    assert np.mean(k_tab) == pytest.approx(np.mean(k_ref), rel=0.03)
    assert np.all(np.abs(k_tab / k_ref - 1) < 0.1)
    # the other flank: the same by symmetry of the perfect pair
    k_rev = np.array([-ev.torque(t, hz * t + (gap + x)) / x for t in th])
    assert np.mean(k_rev) == pytest.approx(np.mean(k_ref), rel=0.03)


def test_shaft_angle_narrows_the_loaded_band_as_contact3d_shows():
    """Screw jack, 0.1 deg shaft angle, at the working torque: the LTCA's contact band across the face against
    contact3d's loaded pattern (its 95 % extent, CONTACT3D: 19.6 mm perfect, 5.3 mm at +0.1 deg), within 15 % / 10 %
    (the LTCA's band is the slice centres' span, in steps of b2 / 32)."""
    sc, g, kp, src = _pair("screw_jack", ["errors.shaft_angle_deg=0.1"])
    dev, kin = displaced_pair(sc.errors, g)
    ms = mesh_stiffness(g, kp, src, sc.simulation.mesh_stiffness_samples)
    t2 = gt.working_wheel_torque_of(sc.drive, sc.load, g.ratio)
    tab = lt.loaded_tca(g, dev, kin, kp * g.face_width, t2, float(np.mean(ms.k_theta_fwd_nm_per_rad)))
    side = gt.duty(sc, g.hand).working_flank
    T = tab.torque_fwd_nm if side > 0 else tab.torque_rev_nm
    ev = lt.Evaluator(g, dev, kp * g.face_width, tab.slices)
    hz = g.hand * g.z1 / g.z2
    bands = []
    for t1, row in zip(tab.theta1_rad, T):
        x = float(np.interp(t2, row, tab.x_rad))
        ev.torque(t1, hz * t1 - side * (lt._gap(kin, t1, side, g) + x))
        bands.append(ev.band_extent_m())
    band_mm = 1e3 * float(np.mean(bands))
    ev0 = lt.Evaluator(g, None, kp * g.face_width, tab.slices)
    x0 = t2 / float(np.mean(ms.k_theta_fwd_nm_per_rad))
    perfect_mm = 1e3 * np.mean(
        [
            (ev0.torque(t1, hz * t1 - side * (g.backlash / (2 * g.r2) + x0)), ev0.band_extent_m())[1]
            for t1 in tab.theta1_rad[::4]
        ]
    )
    # measured: 5.10 mm, perfect pair 21.2 mm
    assert band_mm == pytest.approx(CONTACT3D[0.1]["contact_pattern_extent_face_mm"], rel=0.15)
    assert perfect_mm == pytest.approx(CONTACT3D[0.0]["contact_pattern_extent_face_mm"], rel=0.1)
    # secant stiffness at the working torque: a wedge-shaped gap across the face, F = k' s L^2 / 2, lowers it far
    # below the perfect pair's (measured 0.082 of it); the band's share, 5.1 of 21.2 mm, alone would give 0.24
    k_err = np.nanmean(tab.secant_stiffness_nm_per_rad(side, t2))
    assert k_err < 0.15 * np.mean(ms.k_theta_fwd_nm_per_rad)


def test_shaft_angle_lowers_the_torsional_mesh_stiffness_and_raises_the_loaded_te():
    """Torsional runs of the screw jack: 0.1 deg shaft angle against the perfect pair (docs/errors.md section 5a).
    Measured: loaded TE p2p 9.7 -> 207 urad (kinematic 210), mesh deflection 0.68 -> 8.2 um, mesh stiffness 634 ->
    52.2 N/um."""
    from wormsim.run import simulate

    r0 = simulate(load_scenario(SCEN / "screw_jack.yaml", ["model=torsional"])).summary
    r1 = simulate(load_scenario(SCEN / "screw_jack.yaml", ["model=torsional", "errors.shaft_angle_deg=0.1"])).summary
    assert "mesh_stiffness_loaded_tca_mean_n_per_m" not in r0
    assert r1["mesh_stiffness_loaded_tca_mean_n_per_m"] < 0.15 * r0["mesh_stiffness_mean_n_per_m"]
    assert r1["mesh_deflection_mean_um"] > 5 * r0["mesh_deflection_mean_um"]
    assert r1["transmission_error_p2p_urad"] > 10 * r0["transmission_error_p2p_urad"]
    # the loaded TE against contact3d's at the same point (CONTACT3D, +0.1 deg: 201 urad), within 25 %
    assert r1["transmission_error_p2p_urad"] == pytest.approx(CONTACT3D[0.1]["transmission_error_p2p_urad"], rel=0.25)
