"""wormsim.physics.gear_theory: each shared formula pinned against values computed by hand from its source (DIN 3975-2,
seed 000, ADAMS STEP), so that a level that calls it and a copy that drifts both show here."""

from __future__ import annotations

import math

import numpy as np
import pytest

from wormsim.physics import gear_theory as gt
from wormsim.scenario import Material, Materials, ScenarioError, load_scenario

DEG = math.pi / 180


def test_virtual_friction_angle_float_and_array():
    # rho' = atan(mu / cos alpha_n): mu 0.05, alpha_n 20 deg -> atan(0.05 / 0.93969) = 3.04577 deg
    assert gt.virtual_friction_angle_rad(0.05, 20 * DEG) / DEG == pytest.approx(3.04577, abs=1e-5)
    arr = gt.virtual_friction_angle_rad(np.array([0.0, 0.05]), 20 * DEG)
    assert isinstance(arr, np.ndarray) and arr[0] == 0.0 and arr[1] / DEG == pytest.approx(3.04577, abs=1e-5)
    assert gt.virtual_friction_angle_rad(0.05, 0.0) == pytest.approx(math.atan(0.05))  # alpha_n 0: rho = atan(mu)


def test_efficiencies_forward_backward_self_locking():
    g, rho = 10 * DEG, 3 * DEG
    # tan 10 / tan 13 = 0.176327 / 0.230868 = 0.763756; tan 7 / tan 10 = 0.122785 / 0.176327 = 0.696346
    assert gt.efficiency_forward(g, rho) == pytest.approx(0.763756, abs=1e-6)
    assert gt.efficiency_backward(g, rho) == pytest.approx(0.696346, abs=1e-6)
    assert gt.efficiency_self_locking(g, rho) == 0.0
    # self-locking: rho 12 deg > gamma 10 deg -> backward 0, self-locking tan 2 / tan 10 = 0.198046
    assert gt.efficiency_backward(g, 12 * DEG) == 0.0
    assert gt.efficiency_self_locking(g, 12 * DEG) == pytest.approx(0.198046, abs=1e-6)
    # frictionless: 1 both ways
    assert gt.efficiency_forward(g, 0.0) == pytest.approx(1.0) and gt.efficiency_backward(g, 0.0) == pytest.approx(1.0)
    # arrays take the same formulas
    arr = gt.efficiency_forward(np.array([g, g]), np.array([rho, 0.0]))
    assert arr == pytest.approx([0.763756, 1.0], abs=1e-6)


def test_efficiency_theory_uses_rho_prime():
    g, an, mu = 4.79 * DEG, 10 * DEG, 0.05
    rho = math.atan(mu / math.cos(an))
    assert gt.efficiency_theory(g, an, mu) == pytest.approx(math.tan(g) / math.tan(g + rho), rel=1e-15)
    assert gt.efficiency_theory(g, an, mu, backdriving=True) == pytest.approx(
        math.tan(g - rho) / math.tan(g), rel=1e-15
    )


def test_efficiency_at_radius_is_the_pitch_value_at_r1_and_rises_outward():
    g, an, mu, r1 = 4.79 * DEG, 10 * DEG, 0.05, 4.19e-3
    at_r1 = gt.efficiency_at_radius(g, r1, np.array([r1]), mu, an)
    assert at_r1[0] == pytest.approx(gt.efficiency_theory(g, an, mu), rel=1e-12)
    # local lead angle: tan(gamma_r) = tan(gamma) r1 / r -> at 2 r1, tan halves
    assert math.tan(gt.lead_angle_at_radius_rad(g, r1, np.array([2 * r1]))[0]) == pytest.approx(math.tan(g) / 2)
    eta = gt.efficiency_at_radius(g, r1, np.array([0.9 * r1, 1.1 * r1]), mu, an)
    assert eta[0] > at_r1[0] > eta[1]  # a smaller radius has a steeper thread: higher efficiency


def test_din_3975_force_components():
    # T2 = 24 N m on r2 = 18.55 mm, alpha_n 20 deg, gamma 5 deg, rho' = 3 deg (worm driving, s = +1)
    T2, r2, an, g, rho = 24.0, 18.55e-3, 20 * DEG, 5 * DEG, 3 * DEG
    ft = gt.tangential_force_n(T2, r2)
    assert ft == pytest.approx(1293.80, abs=0.01)  # 24 / 0.01855
    assert gt.axial_force_n(ft, g, rho) == pytest.approx(ft * math.tan(8 * DEG))
    assert gt.radial_force_n(ft, an, g, rho) == pytest.approx(ft * math.tan(an) * math.cos(rho) / math.cos(8 * DEG))
    assert gt.radial_force_n(ft, an, g, -rho) == pytest.approx(ft * math.tan(an) * math.cos(rho) / math.cos(2 * DEG))
    # frictionless normal force: F_n = F_t2 / (cos alpha_n cos gamma) = 1293.80 / (0.939693 * 0.996195) = 1382.09 N
    assert gt.normal_force_n(T2, r2, an, g) == pytest.approx(1382.09, abs=0.01)
    # worm torque T1 = (T2 / r2) r1 tan(gamma + rho'), signed by the hand
    r1 = 4.19e-3
    assert gt.worm_torque_nm(T2, 1, r1, r2, g, rho) == pytest.approx(ft * r1 * math.tan(8 * DEG))
    assert gt.worm_torque_nm(T2, -1, r1, r2, g, rho) == pytest.approx(-ft * r1 * math.tan(8 * DEG))
    # frictionless: power balance T1 omega1 = T2 omega2 with omega1 / omega2 = r2 tan(gamma) / r1 ... = z2 / z1
    t1 = gt.worm_torque_nm(T2, 1, r1, r2, g, 0.0)
    assert t1 / T2 == pytest.approx(r1 * math.tan(g) / r2)
    arm1, arm2 = gt.mesh_arms_m(r1, r2, an, g)
    assert arm1 == pytest.approx(r1 * math.cos(an) * math.sin(g)) and arm2 == pytest.approx(
        r2 * math.cos(an) * math.cos(g)
    )


def test_working_wheel_torque_of_the_seat_motor(scenario_dir):
    sc = load_scenario(scenario_dir / "seat_motor.yaml")
    # load.torque_nm 24 of scenarios/seat_motor.yaml
    assert gt.working_wheel_torque_of(sc.drive, sc.load, 53.0) == 24.0  # the load on the wheel
    on_worm = sc.model_copy(update={"load": sc.load.model_copy(update={"on": "worm", "torque_nm": 0.5})})
    assert gt.working_wheel_torque_of(on_worm.drive, on_worm.load, 53.0) == pytest.approx(26.5)  # 0.5 N m x ratio 53


def test_commands_follow_adams_step_and_the_load_resists(scenario_dir):
    sc = load_scenario(scenario_dir / "seat_motor.yaml")  # 36 rpm over 0.3 s; 24 N m from 0 over 0.3 s
    c = gt.duty(sc, direction=1).commands
    w = 36 * 2 * math.pi / 60
    assert c.drive(0.0) == 0.0 and c.drive(0.3) == pytest.approx(w) and c.drive(1.0) == pytest.approx(w)
    assert c.drive(0.15) == pytest.approx(w / 2)  # STEP is half way at mid-ramp
    # load.torque_nm 24 of scenarios/seat_motor.yaml, reached at the end of its 0.3 s ramp
    assert c.load(0.3) == pytest.approx(-24.0)  # resists the positive motion
    assert gt.duty(sc, direction=-1).commands.load(0.3) == pytest.approx(24.0)
    t = np.array([0.0, 0.075, 0.15, 0.3])
    # STEP: s^2 (3 - 2 s) at s = 0.25 -> 0.15625; float and array paths agree exactly
    assert c.drive(t)[1] == pytest.approx(0.15625 * w)
    assert list(c.drive(t)) == [c.drive(float(x)) for x in t]
    # ramp_s 0.3 of scenarios/seat_motor.yaml; + LOCK_SETTLE_S 0.02 of wormsim/physics/gear_theory.py
    d = gt.duty(sc, direction=1)
    assert d.ramps_end_s == 0.3 and d.lock_check_start_s == pytest.approx(0.32)


def test_servo_gain_gives_the_speed_droop_at_the_expected_torque(scenario_dir):
    sc = load_scenario(scenario_dir / "seat_motor.yaml")
    g, an, mu, i = 4.79 * DEG, 10 * DEG, 0.05, 53.0
    eta = gt.efficiency_theory(g, an, mu)
    t_exp = gt.expected_drive_torque_of(sc.drive, sc.load, i, g, an, mu)
    # T1 = T2 / (i eta): power balance with the theory efficiency; 24 N m of scenarios/seat_motor.yaml
    assert t_exp == pytest.approx(24.0 / i / eta)
    kv = gt.servo_gain_of(sc.drive, t_exp)
    w = 36 * 2 * math.pi / 60
    assert kv * gt.SPEED_DROOP * w == pytest.approx(t_exp)  # the torque at a 0.1 % droop
    # back-driving a self-locking pair (eta 0): the efficiency floor keeps the gain finite
    back = sc.model_copy(update={"drive": sc.drive.model_copy(update={"on": "wheel"})})
    assert gt.expected_drive_torque_of(back.drive, back.load, i, g, an, 0.2) == pytest.approx(
        24.0 * i / gt.MIN_EFFICIENCY
    )


def test_duty_holds_what_the_drive_and_load_functions_give(scenario_dir):
    """gear_theory.duty derives the drive and load once: its commands, ramps, lock start and working flank are those
    of the drive and load functions, for both drive sides and both hands; a scenario without drive: is refused."""
    sc = load_scenario(scenario_dir / "seat_motor.yaml")
    back = sc.model_copy(update={"drive": sc.drive.model_copy(update={"on": "wheel"})})
    for s in (sc, back):
        for hand in (1, -1):
            d = gt.duty(s, hand)
            assert d.commands == gt.commands_of(s.drive, s.load, hand)
            assert d.working_flank == gt.working_flank_of(s.drive, hand)
            ramps = gt.ramps_end_of(s.drive, s.load)
            assert (d.ramps_end_s, d.lock_check_start_s) == (ramps, gt.lock_check_after(ramps))
            assert d.speed_driven and d.drive is s.drive and d.load is s.load
    assert gt.duty(sc, 1).working_flank == 1 and gt.duty(back, 1).working_flank == -1
    with pytest.raises(ScenarioError, match="drive: model wedge needs a drive: block"):
        gt.duty(sc.model_copy(update={"model": "wedge", "drive": None}), 1)
    # the worm's commanded speed: 36 rpm of scenarios/seat_motor.yaml on the worm, x the ratio from the wheel
    w = 36 * 2 * math.pi / 60
    assert gt.worm_speed_command_rad_s(sc.drive, 53.0) == pytest.approx(w)
    assert gt.worm_speed_command_rad_s(back.drive, 53.0) == pytest.approx(53.0 * w)


def test_guards_penetration_limit_and_stuck_drive():
    assert gt.penetration_limit_m(0.7e-3) == pytest.approx(0.28e-3)  # 0.4 m_x
    assert gt.drive_stuck(0.4, 1.0) and not gt.drive_stuck(0.6, 1.0) and gt.drive_stuck(-0.4, -1.0)
    assert list(gt.drive_stuck(np.array([0.1, 0.9]), np.array([1.0, 1.0]))) == [True, False]


# 1-2-5 series: the largest of {1, 2, 5} x 10^k not above h (definition of round_down_125)
@pytest.mark.parametrize(
    "h, expected",
    [
        (7.3e-6, 5e-6),
        (5e-6, 5e-6),
        (4.99e-6, 2e-6),
        (1.9e-4, 1e-4),
        (2.5e-3, 2e-3),
        (1.0, 1.0),
        (9.99, 5.0),
        (5e-6 * (1 - 1e-13), 5e-6),  # a hair below 5e-6 (a float computed as 5e-6) still rounds to it
    ],
)
def test_round_down_125(h, expected):
    assert gt.round_down_125(h) == expected


def test_round_down_125_avoids_the_float_trap():
    # 5 * 10.0 ** -6 is 4.9999999999999996e-06, not the decimal 5e-06 a user would type or a summary would print
    assert 5 * 10.0**-6 != 5e-6
    assert repr(gt.round_down_125(6e-6)) == "5e-06"


def test_effective_modulus_steel_on_nylon():
    m = Materials(
        worm=Material(youngs_modulus_gpa=210, poisson_ratio=0.3, density_kg_m3=7850),
        wheel=Material(youngs_modulus_gpa=3.1, poisson_ratio=0.39, density_kg_m3=1410),
    )
    # 1 / E* = (1 - 0.09) / 210e9 + (1 - 0.1521) / 3.1e9 -> E* = 3.5991 GPa
    assert gt.effective_modulus_pa(m) / 1e9 == pytest.approx(3.5991, abs=1e-4)


def test_servo_peak_torque_is_three_times_the_rated_torque_with_the_ramp():
    """servo_peak_torque_nm: 3 x (T_expected + J_eff 1.5 omega / ramp); 1.5 = the ADAMS STEP's steepest slope
    (6 x (1 - x) at x = 1/2); no limit for a step command. J_eff: I1 + I2 / i^2 on the worm, I2 + I1 i^2 on the
    wheel."""
    assert gt.servo_peak_torque_nm(2.0, 1e-3, 100.0, 0.05) == pytest.approx(3 * (2.0 + 1e-3 * 1.5 * 100.0 / 0.05))
    assert gt.servo_peak_torque_nm(2.0, 1e-3, -100.0, 0.05) == gt.servo_peak_torque_nm(2.0, 1e-3, 100.0, 0.05)
    assert gt.servo_peak_torque_nm(2.0, 1e-3, 100.0, 0.0) is None
    assert gt.drive_inertia_kg_m2("worm", 40.0, 1e-5, 0.16) == pytest.approx(1e-5 + 0.16 / 1600)
    assert gt.drive_inertia_kg_m2("wheel", 40.0, 1e-5, 0.16) == pytest.approx(0.16 + 1e-5 * 1600)
    # the STEP's steepest slope, by finite differences of the drive's own STEP
    x = np.linspace(0.0, 1.0, 100001)
    slope = np.max(np.diff(x**2 * (3 - 2 * x)) / np.diff(x))
    assert slope == pytest.approx(gt.STEP_PEAK_SLOPE, rel=1e-6)


def test_servo_command_leaves_the_linear_law_bit_for_bit_and_holds_the_peak():
    """servo_command: inside band = peak / kv of the speed the command is the command itself (the same float: a run
    whose drive never reaches its peak does not move); beyond it the servo's torque kv (command - w) is +-peak."""
    kv, peak = 8333.0, 150.0
    band = peak / kv
    for cmd, w in ((5.76, 5.76), (5.76, 5.76 - 0.9 * band), (-3.0, -3.0 + 0.99 * band), (0.1234567, 0.1234)):
        assert gt.servo_command(cmd, w, band) == cmd
    assert kv * (gt.servo_command(5.76, 0.0, band) - 0.0) == pytest.approx(peak, rel=1e-12)  # a stall
    assert kv * (gt.servo_command(5.76, 9.0, band) - 9.0) == pytest.approx(-peak, rel=1e-12)  # an overrun
    assert gt.servo_command(5.76, 0.0, 0.0) == 5.76  # band 0: no limit


def test_torsional_servo_law_bends_to_its_peak_and_is_linear_below_the_knee():
    """servo_limited_torque_nm: the linear law up to 0.9 x peak, then continuous in value and slope, rising, below
    the peak, and at the peak for a stalled servo's 1000 x."""
    peak = 10.0
    for t in (0.0, 3.0, -8.9999, 9.0):
        assert gt.servo_limited_torque_nm(t, peak) == t
    ts = np.linspace(0.0, 40.0, 4001)
    ys = np.array([gt.servo_limited_torque_nm(float(t), peak) for t in ts])
    assert np.all(np.diff(ys) >= 0) and ys.max() < peak
    dy = np.diff(ys) / np.diff(ts)
    assert abs(dy[899] - 1.0) < 1e-2 and abs(dy[900] - 1.0) < 1e-2  # the slope at the knee (t = 9)
    assert gt.servo_limited_torque_nm(1000.0 * peak, peak) == pytest.approx(peak)
    assert gt.servo_limited_torque_nm(-1000.0 * peak, peak) == pytest.approx(-peak)
    assert gt.servo_limited_torque_nm(123.0, None) == 123.0
