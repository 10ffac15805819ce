"""The seed validation of tests/contact3d/test_seeds_pieces.py with `contact.geometry: flanks` (issue 13): same CI
configurations (slices by flanks.default_slices: 32 each), same criteria: ratio
0.1 %, meshing frequency, torque balance 2 %, efficiency within 3 % of the wedge model at the pitch radius and at the
contact radius, DIN 3975 radial force 3 %. Measured numbers of the expected failures in docs/contact3d.md."""

from __future__ import annotations

import pytest

from tests.conftest import SCENARIOS
from tests.contact3d.test_seeds_pieces import CI, assert_mesh_frequency
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


# mesh_frequency_hz is the meshing line near z1 n1 / 60 (wormsim.results.metrics.mesh_line): 29.97 / 22.14 / 24.14 Hz. The
# largest F_t peak is not always there: involute_41 with the teeth's compliance (1.01e9 N/m per tooth pair against
# Hertz's 5.41e9) has its contact mode among the meshing harmonics (941 Hz, the 39th; law (5) of wormsim.contact3d.law),
# which it amplifies (F_t p2p 584 N on 13.8 kN, docs/data/slice_convergence_medium.json; with Hertz 148 N before (5),
# docs/data/stiffness_seeds.json)
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


# the seat motor's radial force has a larger 2nd than 1st meshing harmonic (quasi-static at constant torque the
# kernel's radial harmonics 1-4 are 0.998, 1.239, 0.688, 0.091 N; docs/contact3d.md, "Contacts leaving at zero load"):
# the meshing line near z1 n1 / 60 is the 1st (wormsim.results.metrics.mesh_line)
RADIAL_XFAIL: dict[str, str] = {}


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
    assert abs(s["radial_force_mean_n"] / s["radial_force_theory_n"] - 1) < 0.03
    # the resultant's radial component is the smaller one: the contacts sit around the worm (docs/outputs.md)
    assert s["radial_force_resultant_mean_n"] < 0.97 * s["radial_force_mean_n"]


# ----------------------------------------------------------------------------- independent references of the forces
# The worm torque is the speed servo's reaction to the contacts' moments about the worm axis, the forces are the
# contact sensor's resultant on the wheel: neither is the load command, so the closed forms below can fail.


def _geometry(name: str):
    from meshgen.geometry import derive

    return derive(run(name)["scenario"].gear)


@pytest.mark.parametrize("name", SEEDS)
def test_flanks_worm_torque_is_t2_over_i_eta_at_the_contact_radius(name):
    """T1 = T2 / (i eta) (power balance, DIN 3975-2) with eta = tan(g_r) / tan(g_r + rho') at the contacts'
    force-weighted worm radius r_c (tan g_r = tan g r1 / r_c, DIN 3975-1; wormsim.physics.gear_theory.efficiency_at_radius),
    rho' = atan(mu / cos alpha_n): within 1 % (measured +0.07 / +0.12 / +0.13 %; at the pitch radius r1 the same
    formula is 1.2-1.8 % off, so the check tells the radii apart)."""
    from wormsim.physics import gear_theory as gt

    s, sc, g = run(name)["summary"], run(name)["scenario"], _geometry(name)
    eta = gt.efficiency_at_radius(
        g.gamma, g.r1, s["worm_contact_radius_mean_m"], s["friction_coefficient_mean"], g.alpha_n
    )
    expected = sc.load.torque_nm / (g.ratio * float(eta))
    assert abs(s["worm_torque_mean_nm"] / expected - 1) < 0.01, (s["worm_torque_mean_nm"], expected)


# involute_41 passes at 4 contacts per tooth flank (the default, decision 0049): 2154.9 N against T1 / r_c 2213.1 N
# (-2.63 %); per slice it was -3.04 % (2145.7 N)
AXIAL_XFAIL = {
    "screw_jack": "F_a2 57.17 N against T1 / r_c = 0.7841 N m / 13.155 mm = 59.61 N (-4.1 %; per slice 56.93 N, "
    "-4.5 %); seat motor -2.7 %, involute_41 -2.6 %: the contacts sit at angles about the worm axis (force-weighted "
    "|phi| about 28 deg), which turn part of their worm-tangential force out of the wheel's axial direction",
}


@pytest.mark.parametrize("name", [_xf(AXIAL_XFAIL, n) for n in SEEDS])
def test_flanks_axial_force_is_worm_torque_over_contact_radius(name):
    """The resultant's axial component against F_t1 = T1 / r (DIN 3975-2, with the contacts' force-weighted worm
    radius r_c for r1), within 3 % (the issue's tolerance for the DIN 3975 forces); the headline F_a2 is DIN's
    T1 / r1 (docs/outputs.md, "Force keys"). involute_41: 2147.5 N against 2213.8 N (-2.99 %; -3.04 % before the
    slice weights along the contact line, decision 0051)."""
    s = run(name)["summary"]
    expected = s["worm_torque_mean_nm"] / s["worm_contact_radius_mean_m"]
    assert abs(s["axial_force_resultant_mean_n"] / expected - 1) < 0.03, (s["axial_force_resultant_mean_n"], expected)


# ----------------------------------------------------------------------------- torsional against contact3d
# Two mechanisms on the same gear and the same CI scenario: torsional (a mesh spring k(theta) from the loaded TCA, the
# DIN 3975 forces at the pitch point) and contact3d (MuJoCo contacts on the exact flanks).
_TORSIONAL: dict[str, dict] = {}


def torsional_run(name: str) -> dict:
    if name not in _TORSIONAL:
        from wormsim.torsional.dynamics import simulate as simulate_torsional

        sc = load_scenario(SCEN / f"{name}.yaml", [*CI[name], "model=torsional"])
        _TORSIONAL[name] = simulate_torsional(sc).summary
    return _TORSIONAL[name]


# key of contact3d -> key of torsional, relative tolerance (3 %: the tolerance for the DIN 3975 forces and the
# wedge efficiency; 1 % for the mean F_t, which both must hold to the load by statics; 10 % for the TE p2p, the
# fluctuation criterion of tests/contact3d/test_convergence.py)
CROSS = {
    "tangential_force_mean_n": ("tangential_force_mean_n", 0.01),
    "efficiency": ("efficiency", 0.03),
    "worm_torque_mean_nm": ("worm_torque_mean_nm", 0.03),
    "radial_force_mean_n": ("radial_force_mean_n", 0.03),
    "axial_force_mean_n": ("axial_force_mean_n", 0.03),
    "transmission_error_p2p_urad": ("transmission_error_p2p_urad", 0.10),
}
# the axial force: torsional's F_t2 tan(gamma + rho') against contact3d's DIN F_a2 = T1 / r1 (the resultant's axial
# component is 5-8 % lower: test_flanks_axial_force_is_worm_torque_over_contact_radius)
CROSS_XFAIL = {
    ("seat_motor", "transmission_error_p2p_urad"): "torsional 325.3 urad against contact3d 219.9 urad (+48 %): the "
    "torsional k(theta) from 64 TCA samples against the kernel's contacts on the flanks at 32 slices; the seed's K "
    "overrides the teeth (decision 0034); with the teeth's compliance (torsional's k(theta1) the LTCA's) 1435 against "
    "952 urad (+50.7 %), with Hertz +47.9 %: not the stiffness level (docs/data/stiffness_seeds.json)",
    ("involute_41", "transmission_error_p2p_urad"): "torsional 8.66 urad against contact3d 11.21 urad (-22.8 %) with "
    "the teeth's compliance (its default): torsional's k(theta1) is the loaded TCA's, where the tooth's bending couples "
    "the contact lines (k ptp / mean 0.193), contact3d's slices are independent springs of k'_eff per length (the "
    "contact-line TCA's 0.263, docs/tooth_compliance.md); with the contact-line TCA at torsional +8.0 %. Torsional "
    "agrees with the quasi-static LTCA (test_torsional_te_is_the_loaded_tcas)",
    ("screw_jack", "transmission_error_p2p_urad"): "torsional 9.67 urad against contact3d 8.58 urad (+12.7 %) with "
    "the seed's K; with the teeth's compliance (torsional's k(theta1) the LTCA's) 9.96 against 12.52 urad (-20.4 %), "
    "with Hertz +1.9 % "
    "(docs/data/stiffness_seeds.json)",
}


@pytest.mark.parametrize(
    "name,key",
    [
        pytest.param(n, k, marks=pytest.mark.xfail(reason=CROSS_XFAIL[(n, k)], strict=True))
        if (n, k) in CROSS_XFAIL
        else (n, k)
        for n in SEEDS
        for k in CROSS
    ],
)
def test_torsional_agrees_with_contact3d_on_the_same_gear(name, key):
    """Measured: mean F_t within 0.02 %, efficiency and worm torque 1.2-1.8 % (torsional at the pitch radius; the axial
    force F_a2 = T1 / r1 at both levels follows the worm torque), radial force on the line of centres 0.3-0.6 %, TE p2p
    involute_41 -22.8 % (its default, the teeth's compliance: CROSS_XFAIL; +1.1 % with Hertz's stiffer contact)."""
    c, t = run(name)["summary"], torsional_run(name)
    tkey, rel = CROSS[key]
    assert abs(t[tkey] / c[key] - 1) < rel, (key, t[tkey], c[key])


def test_torsional_te_is_the_loaded_tcas():
    """involute_41 (the teeth's compliance): torsional's loaded TE p2p against the quasi-static LTCA's at the working
    torque, both in its summary, within the 10 % of the TE cross-check above."""
    t = torsional_run("involute_41")
    assert t["mesh_stiffness_source"] == "teeth"
    assert abs(t["transmission_error_p2p_urad"] / t["transmission_error_loaded_p2p_urad"] - 1) < 0.10, (
        t["transmission_error_p2p_urad"],
        t["transmission_error_loaded_p2p_urad"],
    )


# ----------------------------------------------------------------------------- Hertz pressure against a closed form
HERTZ_XFAIL = {
    "involute_41": "contact_pressure_mean_mpa 201.0 MPa against 207.5 MPa from the pitch point's closed form (-3.1 %; "
    "-1.9 % with Hertz's stiffer contact): with the teeth's compliance (its default) the F_t fluctuation grows to 703 N "
    "p2p (the contact mode at 941 Hz, the 39th meshing harmonic) and the load spreads over the contact lines "
    "differently from the pitch point's",
    "seat_motor": "contact_pressure_mean_mpa 200.8 MPa against 189.8 MPa from the pitch point's closed form (+5.8 %; 198.7 "
    "MPa with 64 points along the profile, decision 0060): "
    "the 58 % undercut wheel carries its load above the pitch radius (contacts at 4.32 against r1 4.19 mm), where the "
    "flanks' relative curvature is not the pitch point's; screw jack -0.4 %, involute_41 -1.9 %",
}


@pytest.mark.parametrize("name", [_xf(HERTZ_XFAIL, n) for n in SEEDS])
def test_flanks_mean_contact_pressure_is_the_line_contact_formula(name):
    """The F_n-weighted mean Hertz pressure of the run (wormsim.tooth.hertz: per cell, from the kernel's
    loads and the flanks' numerical curvature) against the line-contact formula p = sqrt(w E* / (pi rho')) (Johnson,
    Contact Mechanics, section 4.3: the peak p_0 of two cylinders) with the load per length w = F_n / L, F_n = T2 / (r2 cos alpha_n cos gamma)
    (DIN 3975-2), L the torsional TCA's mean total contact line length, and rho' the relative radius of curvature at
    the pitch point in the normal section of the virtual spur gears (Tredgold: r / cos^2 beta; the wheel's helix angle
    is gamma, the worm's 90 deg - gamma): 1 / rho' = cos^2 g / (r2 sin a_n) + sin^2 g / (r1 sin a_n). Within 3 %."""
    import math

    from wormsim.physics import gear_theory as gt

    s, sc, g = run(name)["summary"], run(name)["scenario"], _geometry(name)
    length_m = torsional_run(name)["contact_line_length_mean_mm"] * 1e-3
    fn = gt.normal_force_n(sc.load.torque_nm, g.r2, g.alpha_n, g.gamma)
    sa = math.sin(g.alpha_n)
    inv_rho = math.cos(g.gamma) ** 2 / (g.r2 * sa) + math.sin(g.gamma) ** 2 / (g.r1 * sa)
    p_mpa = math.sqrt(fn / length_m * gt.effective_modulus_pa(sc.materials) * inv_rho / math.pi) * 1e-6
    assert abs(s["contact_pressure_mean_mpa"] / p_mpa - 1) < 0.03, (s["contact_pressure_mean_mpa"], p_mpa)
