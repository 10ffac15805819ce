"""The wedge derived from a gear (wormsim.wedge.derive.params_from_gear): reduced masses at the worm's operating
radius and the wheel's pitch radius, and the working force of the wedge, F1 = F2 tan(gamma + rho'), checked by hand."""

from __future__ import annotations

import math

import pytest

from tests.conftest import SCENARIOS
from wormsim.physics import gear_theory as gt
from wormsim.physics.friction import friction_coefficient
from wormsim.physics.geometry import derive
from wormsim.physics.units import rpm_to_rad_s
from wormsim.scenario import load_scenario
from wormsim.wedge.derive import params_from_gear


def test_reduced_masses_and_working_force_by_hand():
    sc = load_scenario(SCENARIOS / "screw_jack.yaml", ["model=wedge"])
    p, d = params_from_gear(sc)
    g = derive(sc.gear)
    I1, I2 = gt.shaft_inertias_kg_m2(sc.materials, sc.load, g.r1, g.worm_length, g.r2, g.face_width)
    assert p.m1_kg == pytest.approx(I1 / g.r_m1**2) and p.m2_kg == pytest.approx(I2 / g.r2**2)
    v = rpm_to_rad_s(sc.drive.speed_rpm) * g.r_m1
    rho = math.atan(float(friction_coefficient(sc.contact, v / math.cos(g.gamma_m))) / math.cos(g.alpha_n))
    f2 = abs(sc.load.torque_nm) / g.r2
    assert p.nominal_force_n == pytest.approx(f2 * math.tan(g.gamma_m + rho), rel=1e-12)  # a resisting load
    assert p.nominal_speed_m_s == pytest.approx(v) and p.gamma_rad == g.gamma_m
    # the motor curve passes through the working point below its synchronous speed
    assert p.peak_force_n > p.nominal_force_n and p.sync_speed_m_s > v > p.peak_speed_m_s
    assert d["driving_mass_kg"] == p.m1_kg and d["wedge_source"].startswith("derived from gear:")


def test_the_derived_run_reads_its_plan_only():
    """wormsim.wedge.derive.derived_plan: built once from the scenario; run_derived takes nothing else."""
    from wormsim.wedge.derive import derived_plan, run_derived

    sc = load_scenario(SCENARIOS / "screw_jack.yaml", ["model=wedge", "simulation.duration_s=0.05"])
    plan = derived_plan(sc)
    assert plan.load_torque_nm == sc.load.torque_nm and plan.params.duration_s == 0.05 and "geometry" not in plan.keys
    s = run_derived(plan).summary
    assert s["tangential_force_theory_n"] == pytest.approx(abs(sc.load.torque_nm) / plan.geometry.r2)
    assert s["friction"] == plan.friction
