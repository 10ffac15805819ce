"""Derived gear dimensions (meshgen/geometry.py) against hand calculations from DIN 3975 relations."""

import math

import pytest

from meshgen.geometry import GeometryError, derive
from wormsim.scenario import Gear


def test_seed_001_seat_motor():
    # seed 001: m_n 0.7 mm, 53/1, alpha_n 10 deg, gamma 4.79 deg
    g = derive(Gear(wheel_teeth=53, normal_module_mm=0.7, normal_pressure_angle_deg=10, lead_angle_deg=4.79))
    m_x = 0.7e-3 / math.cos(math.radians(4.79))  # 0.70245 mm
    assert g.m_x == pytest.approx(m_x, rel=1e-12)
    assert g.d1 == pytest.approx(m_x / math.tan(math.radians(4.79)), rel=1e-12)  # 8.383 mm
    assert g.d2 == pytest.approx(53 * m_x) and g.a == pytest.approx((g.d1 + g.d2) / 2)
    assert g.d1 * 1e3 == pytest.approx(8.383, abs=1e-3) and g.a * 1e3 == pytest.approx(22.806, abs=1e-3)
    # base lead angle: cos(gamma_b) = cos(gamma) cos(alpha_n) -> 11.08 deg (seed 003 relation)
    assert math.degrees(g.gamma_b) == pytest.approx(11.0775, abs=1e-3)
    assert g.r_b == pytest.approx(g.p / math.tan(g.gamma_b))
    assert g.p == pytest.approx(g.r1 * math.tan(g.gamma))  # helix parameter = lead / 2 pi
    assert g.ratio == 53


def test_seed_003_involute_41():
    # seed 003: m 10 mm, q 9, 41/1 -> gamma = atan(1/9) = 6.340 deg, d1 90, d2 410, a 250 mm
    g = derive(Gear(wheel_teeth=41, axial_module_mm=10, normal_pressure_angle_deg=20, diameter_quotient=9))
    assert math.degrees(g.gamma) == pytest.approx(6.3402, abs=1e-4)
    assert (g.d1, g.d2, g.a) == pytest.approx((0.090, 0.410, 0.250))
    assert g.throat_radius == pytest.approx(g.r1 - g.m_x) and g.root_torus_radius == pytest.approx(g.r1 + 1.2 * g.m_x)
    # s2 = p_x / 2 - j_t (DIN 3975 tooth thickness, backlash from the wheel) with the default j_t 0.05 mm
    assert g.wheel_tooth_thickness == pytest.approx(math.pi * 0.010 / 2 - 0.05e-3)


def test_left_hand_flips_helix_parameter_only():
    r = derive(Gear(wheel_teeth=30, axial_module_mm=2, diameter_quotient=10))
    l = derive(Gear(wheel_teeth=30, axial_module_mm=2, diameter_quotient=10, hand="left"))
    assert l.p == -r.p and l.r_b == r.r_b and l.a == r.a


def test_impossible_gear_data_is_an_input_error():
    with pytest.raises(GeometryError, match="backlash_mm"):
        derive(Gear(wheel_teeth=30, axial_module_mm=2, diameter_quotient=10, backlash_mm=2.9))
    with pytest.raises(GeometryError, match="worm root radius"):
        derive(Gear(wheel_teeth=30, axial_module_mm=2, diameter_quotient=2))
    with pytest.raises(GeometryError, match="face_width_mm"):
        derive(Gear(wheel_teeth=30, axial_module_mm=2, diameter_quotient=10, face_width_mm=200))


def test_the_clipped_default_face_width_given_back_is_accepted():
    """A wheel whose DIN-guide face width would reach past the root torus gets b2_max as its default; that width
    given back in mm (REXS export and import, tests/cli/test_commands_random.py gear 123) was refused by one ulp."""
    gear = dict(
        profile="ZK",
        worm_starts=2,
        wheel_teeth=30,
        axial_module_mm=0.838,
        diameter_quotient=15.45,
        normal_pressure_angle_deg=20.9,
        profile_shift_coefficient=0.57,
        backlash_mm=0.0419,
    )
    g = derive(Gear(**gear))
    assert g.face_width < 0.75 * 2 * g.r_a1  # clipped
    again = derive(Gear(**gear, face_width_mm=g.face_width * 1e3))
    assert again.face_width == pytest.approx(g.face_width, rel=1e-12)
    with pytest.raises(GeometryError, match="leaves no tooth at the face edges"):
        derive(Gear(**gear, face_width_mm=g.face_width * 1e3 * 1.001))
