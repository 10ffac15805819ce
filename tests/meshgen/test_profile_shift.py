"""The wheel's profile shift x2 (gear.profile_shift_coefficient, DIN 3975): centre distance and wheel diameters, the
wheel still the exact envelope of the worm hobbed at the shifted centre distance, the undercut it removes, x2 = 0
giving the unshifted numbers bit for bit, and the levels on a 1x40 gear with x2 = +0.5."""

from __future__ import annotations

import math
from dataclasses import asdict

import numpy as np
import pytest

from meshgen import pieces, wheel, worm
from meshgen.geometry import GearSpec, derive
from tests._meshgen_common import clearance_to_worm
from tests.conftest import SCENARIOS
from wormsim.scenario import load_scenario

# a plain 1x40 gear (alpha_n 20 deg, m_x 2.5, q 10): a = 62.5 mm unshifted, 63.75 mm at x2 = +0.5
SPEC = {"wheel_teeth": 40, "worm_starts": 1, "axial_module_mm": 2.5, "diameter_quotient": 10.0, "profile": "ZI"}


def _g(x2: float | None, **kw):
    return derive(GearSpec(**{**SPEC, **kw}, profile_shift_coefficient=x2))


def test_din3975_dimensions_at_x2_plus_half():
    g = _g(0.5)
    m = 2.5
    d1, d2 = 25.0, 100.0
    assert g.a * 1e3 == pytest.approx((d1 + d2) / 2 + 0.5 * m, abs=1e-12)  # 63.75
    assert 2e3 * g.r_a2 == pytest.approx(d2 + 2 * m * (1.0 + 0.5), abs=1e-12)  # d_a2 = d2 + 2 m (h_a* + x2)
    assert 2e3 * g.r_f2 == pytest.approx(d2 - 2 * m * (1.2 - 0.5), abs=1e-12)  # d_f2 = d2 - 2 m (h_f* - x2)
    assert (g.d1 * 1e3, g.d2 * 1e3, g.ratio) == pytest.approx((d1, d2, 40.0))  # worm, d2 and ratio unchanged
    assert 2e3 * g.r_m1 == pytest.approx(d1 + 2 * 0.5 * m)  # d_m1 = d1 + 2 x2 m
    assert math.tan(g.gamma_m) == pytest.approx(1 * m / (d1 + 2 * 0.5 * m))
    # the throat and the hob's tip torus keep the worm's radii: a - r_a2 = r1 - h_a, a - r_f2 = r1 + h_f
    assert g.throat_radius * 1e3 == pytest.approx(12.5 - 2.5) and g.root_torus_radius * 1e3 == pytest.approx(15.5)


def test_x2_zero_is_the_unshifted_gear_bit_for_bit():
    """Given 0 or left out: every derived number identical (no tolerance) to the gear without the key."""
    sc = load_scenario(SCENARIOS / "screw_jack.yaml")
    a = asdict(derive(sc.gear))
    b = asdict(derive(sc.gear.model_copy(update={"profile_shift_coefficient": 0.0})))
    assert a == b and a["x2"] == 0.0
    g = derive(sc.gear)
    assert g.r_m1 == g.r1 and g.gamma_m == g.gamma


def _flank_points(g, n_rho=13, n_zeta=17):
    zeta = np.linspace(-g.face_width / 2, g.face_width / 2, n_zeta)
    s = np.linspace(0.0, 1.0, n_rho)
    R = wheel.root_rho(g, zeta)[None] + s[:, None] * (wheel.tip_rho(g, zeta) - wheel.root_rho(g, zeta))[None]
    return R, np.broadcast_to(zeta[None], R.shape)


def test_shifted_wheel_is_still_the_envelope():
    """The tests/meshgen/test_wheel.py checks on the shifted 1x40: the mid-plane tooth thickness on d2 of a ZA wheel is
    DIN 3975's s2 = m_x (pi / 2 + 2 x2 tan(alpha_x)) - j (the worm's straight axial flank rolls on d2 at its radius
    r1 + x2 m_x; 1 um); the conjugate flanks never enter the worm thread and touch it at backlash / 2 (axial) at every
    worm angle of a mesh cycle (tolerances as there: 0.02 um in, 2 um out)."""
    za = _g(0.5, profile="ZA")
    a, b = wheel.tooth_flanks(za, np.array([za.r2]), np.array([0.0]))
    s2 = za.m_x * (math.pi / 2 + 2 * 0.5 * math.tan(za.alpha_x)) - za.backlash
    assert float((b - a)[0] * za.r2) == pytest.approx(s2, abs=1e-6)
    g = _g(0.5)
    pts, conj = pieces.wheel_active_flank_points(g, n_rho=21, n_zeta=31)
    assert conj.mean() > 0.5
    pts = pts[conj]
    mins = np.array([clearance_to_worm(g, pts, th)[0].min() for th in np.linspace(0.0, 2 * math.pi, 25)])
    j2 = g.backlash / 2
    assert mins.min() >= j2 - 2e-8
    assert mins.max() <= j2 + 2e-6


def test_meshing_equation_on_the_shifted_wheel():
    """Every conjugate flank point found by the envelope lies on the worm thread at its worm angle (the hob runs at
    the shifted centre distance: meshgen.wheel with g.a)."""
    from meshgen import assembly

    g = _g(0.5)
    R, Z = _flank_points(g)
    sol = wheel.space_flank(g, R, Z, +1)
    ok = sol.interior
    assert ok.mean() > 0.5
    rho, zeta, psi, beta = R[ok], Z[ok], sol.psi[ok], sol.beta[ok]
    X = np.stack([rho * np.cos(psi), rho * np.sin(psi), zeta], -1)
    k = g.hand * g.z1 / g.z2
    th2 = beta - psi
    th1 = th2 / k
    Y = np.array(
        [
            assembly.transform_points(
                np.linalg.inv(assembly.worm_to_assembly(a1, g)) @ assembly.wheel_to_assembly(a2), x[None]
            )[0]
            for x, a1, a2 in zip(X, th1, th2)
        ]
    )
    r = np.hypot(Y[:, 0], Y[:, 1])
    u = worm.wrap(Y[:, 2] - g.p * np.arctan2(Y[:, 1], Y[:, 0]), g.p_x)
    on = np.minimum(np.abs(u - worm.half_thickness(g, r)), np.abs(u + worm.half_thickness(g, r)))
    assert on.max() < 1e-9


def test_positive_shift_lifts_the_undercut():
    """ZC at its default arc radius on the 1x40: 63 % of the working flank undercut unshifted (refused, limit 60 %),
    22.5 % at the default x2 = 0.5 (accepted)."""
    from meshgen.geometry import GeometryError

    g0 = _g(0.0, profile="ZC")
    assert wheel.undercut_fraction(g0) == pytest.approx(0.625, abs=0.03)
    with pytest.raises(GeometryError, match="profile_shift_coefficient"):
        wheel.check_wheel(g0)
    g = _g(None, profile="ZC")  # the default shift of ZC
    assert g.x2 == 0.5
    assert wheel.undercut_fraction(g) < 0.3
    wheel.check_wheel(g)


def test_torsional_on_the_shifted_gear(tmp_path):
    """involute_41 shifted by x2 = +0.5 at torsional: ratio, F_t2 = T2 / (d2 / 2) (0.5 %) and the efficiency of the
    wedge law at the operating lead angle gamma_m (it differs from the unshifted gamma's)."""
    from wormsim import simulate
    from wormsim.physics import gear_theory as gt

    sc = load_scenario(
        SCENARIOS / "involute_41.yaml",
        ["model=torsional", "gear.profile_shift_coefficient=0.5", "simulation.duration_s=0.3"],
    )
    g = derive(sc.gear)
    s = simulate(sc).summary
    assert s["ratio"] == pytest.approx(g.ratio, rel=1e-3)
    assert s["tangential_force_mean_n"] == pytest.approx(sc.load.torque_nm / g.r2, rel=5e-3)
    mu = s["friction_coefficient_mean"]
    assert s["efficiency"] == pytest.approx(gt.efficiency_theory(g.gamma_m, g.alpha_n, mu), rel=0.01)
    assert abs(gt.efficiency_theory(g.gamma, g.alpha_n, mu) / s["efficiency"] - 1) > 0.01


@pytest.mark.parametrize("name", ["contact3d_shifted_1x40"])
def test_contact3d_on_the_shifted_1x40(name):
    """The screw jack's worm (m_x 2.5, q 10, ZI, alpha_n 20 deg) on a 40-tooth wheel shifted by x2 = +0.5 (a = 63.75
    mm) at contact3d, with tests/contact3d/test_flank_forms.py's short run: ratio 0.1 %, torque balance 2 %,
    efficiency within 3 % of the wedge law at the contacts' radius, the contacts near the operating radius r_m1
    (measured: ratio 40.0000, F_t2 400.003 N of 400, efficiency 0.6365 against 0.6373, contacts at 13.2 mm with
    r1 12.5 and r_m1 13.75 mm)."""
    from tests.contact3d.test_flank_forms import CONTACT3D
    from wormsim.contact3d.runner import simulate

    sets = [*CONTACT3D, "gear.wheel_teeth=40", "gear.profile_shift_coefficient=0.5", "load.torque_nm=20"]
    sc = load_scenario(SCENARIOS / "screw_jack.yaml", sets)
    g = derive(sc.gear)
    assert g.a * 1e3 == pytest.approx(63.75)
    s = simulate(sc).summary
    assert abs(s["ratio"] / s["ratio_theory"] - 1) < 1e-3
    assert abs(s["tangential_force_mean_n"] * g.r2 / sc.load.torque_nm - 1) < 0.02
    assert abs(s["efficiency"] / s["efficiency_theory_at_contact_radius"] - 1) < 0.03
    assert g.r1 < s["worm_contact_radius_mean_m"] < g.r_m1 + 0.5 * g.m_x


def test_report_header_gives_the_shift():
    from wormsim.results.report_header import gear_line

    assert "x2" not in gear_line(_g(0.0))
    line = gear_line(_g(0.5))
    assert "a 63.75 mm" in line and "x2 +0.5 (d_a2 107.5 mm" in line
