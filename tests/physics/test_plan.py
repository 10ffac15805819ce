"""wormsim.physics.plan: the gear-level plan holds what the drive and load functions of wormsim.physics.gear_theory and the friction
law give for the scenario, derived once; a scenario without gear: or drive: is refused (exit 2's ScenarioError)."""

from __future__ import annotations

import math

import pytest

from wormsim.physics import gear_theory as gt
from wormsim.physics.friction import friction_coefficient, friction_mode
from wormsim.physics.geometry import derive
from wormsim.physics.plan import NOMINAL_SLIDING_SPEED_M_S, gear_plan
from wormsim.scenario import ScenarioError, load_scenario


@pytest.mark.parametrize("name", ["seat_motor", "screw_jack"])
def test_plan_holds_the_drive_and_load_functions_values(scenario_dir, name):
    sc = load_scenario(scenario_dir / f"{name}.yaml")
    p = gear_plan(sc)
    g = derive(sc.gear)
    assert p.geometry == g and p.name == sc.name and p.model == sc.model
    assert p.duty == gt.duty(sc, g.hand)
    mu0 = float(friction_coefficient(sc.contact, 0.0))
    mu1 = float(friction_coefficient(sc.contact, NOMINAL_SLIDING_SPEED_M_S))
    assert (p.mu_static, p.mu_nominal) == (mu0, mu1)
    assert p.rho_static_rad == math.atan(mu0 / math.cos(g.alpha_n))
    assert p.friction_mode == friction_mode(sc.contact)
    assert p.working_wheel_torque_nm == gt.working_wheel_torque_of(sc.drive, sc.load, g.ratio)
    t_drive = gt.expected_drive_torque_of(sc.drive, sc.load, g.ratio, g.gamma_m, g.alpha_n, mu1)
    assert p.drive_torque_nm == t_drive and p.servo_gain_nm_s == gt.servo_gain_of(sc.drive, t_drive)
    assert p.worm_speed_rad_s == gt.worm_speed_command_rad_s(sc.drive, g.ratio)
    assert p.backdrive_self_locks is False  # the worm drives
    assert p.displaced is None and p.transition_velocity_m_s == sc.contact.transition_velocity_m_s


def test_plan_of_a_torque_drive_has_no_servo_and_no_commanded_speed(scenario_dir):
    sc = load_scenario(scenario_dir / "seat_motor.yaml", ["drive.speed_rpm=null", "drive.torque_nm=1.0"])
    p = gear_plan(sc)
    assert p.servo_gain_nm_s is None and p.worm_speed_rad_s is None and not p.duty.speed_driven


def test_plan_needs_a_gear_and_a_drive(scenario_dir):
    sc = load_scenario(scenario_dir / "seat_motor.yaml")
    with pytest.raises(ScenarioError, match="drive: model"):
        gear_plan(sc.model_copy(update={"drive": None}))
    with pytest.raises(ScenarioError, match="gear: model"):
        gear_plan(sc.model_copy(update={"gear": None}))
