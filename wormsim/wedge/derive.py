"""The wedge model derived from a gear scenario (model: wedge without a wedge: block): the same scenario file runs at
every level.

From gear:, materials:, contact:, drive:, load: (docs/wedge.md, "Derived from gear:"):

- lead angle gamma, pitch radii r1, r2 and normal pressure angle alpha_n from the gear geometry (meshgen);
- reduced masses m1 = I1 / r1^2 (worm at its pitch radius), m2 = I2 / r2^2 (wheel at its pitch radius), with the
  shaft inertias of the torsional level (gear_theory.shaft_inertias_kg_m2: solid cylinders, plus load.inertia_kg_m2);
- friction: the contact's law mu(Vs) (wormsim.physics.friction) with the gear levels' friction angle rho' = atan(mu /
  cos alpha_n), so one friction input gives one friction angle at every level (seed 000's wedge: block takes rho =
  atan(mu));
- load: F2 = -load.torque_nm / r2 on the wheel, with load.start_s / load.ramp_s (STEP);
- drive: a Kloss motor curve on the worm (seed 000's motor) through the working point: the worm's pitch-line speed
  v = n1 r1 (drive.speed_rpm) at the force the load needs there, F1 = |F2| tan(gamma + rho') (an assisting load:
  F1 = -F2 tan(gamma - rho'), the motor braking), with a peak force
  KLOSS_PEAK_FACTOR x that force (plus what runs the masses up in RUNUP_S) and a peak-force speed SLIP_SPAN below
  the synchronous speed. The speed servo of the gear levels becomes this stiff speed-force curve: the steady speed
  lands on drive.speed_rpm at the steady friction. drive.ramp_s is not used (the run says so).

The summary adds the gear levels' common keys (ratio, forces on the wheel, torques, speeds, the power flow,
efficiency and its theory in the direction of the power flow) from the wedge's forces and speeds, in the force signs
of docs/outputs.md: F_t2 = -S2, F_a2 = F_t1 = S1,
F_r2 = |F_t2| tan(alpha_n) cos(rho') / cos(gamma + s rho') (DIN 3975-2; the wedge has no radial direction).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from wormsim.physics import gear_theory as gt
from wormsim.physics.friction import friction_coefficient, friction_mode
from wormsim.physics.geometry import derive
from wormsim.physics.units import DEG, rad_s_to_rpm, rpm_to_rad_s
from wormsim.results.metrics import flow_efficiency, power_flow
from wormsim.results.result import Result
from wormsim.results.summary_keys import level_summary
from wormsim.wedge.dynamics import STEADY_FRACTION, WedgeParams, simulate_params

KLOSS_PEAK_FACTOR = 3.0  # peak force / working force: a stiff curve, far from the motor's pull-out
SLIP_SPAN = 0.5  # (synchronous - peak-force speed) / working speed
RUNUP_S = 0.01  # the peak force also runs the reduced masses up to speed in about this time


@dataclass(frozen=True)
class DerivedPlan:
    """The derived wedge's plan, built once from the scenario (derived_plan); run_derived reads nothing else."""

    name: str  # the scenario's name
    params: WedgeParams
    geometry: object  # meshgen's GearGeometry
    keys: dict  # what was derived, as summary keys (wedge_source, the reduced masses, the motor curve)
    load_torque_nm: float  # load.torque_nm (the tangential force's theory)
    friction: str  # wormsim.physics.friction.friction_mode of contact:


def derived_plan(scenario) -> DerivedPlan:
    """The DerivedPlan of a gear scenario at model wedge (module docstring)."""
    p, d = params_from_gear(scenario)
    g = d.pop("geometry")
    return DerivedPlan(scenario.name, p, g, d, scenario.load.torque_nm, friction_mode(scenario.contact))


def params_from_gear(scenario) -> tuple[WedgeParams, dict]:
    """(WedgeParams, what was derived: summary keys) of a gear scenario (module docstring)."""
    g = derive(scenario.gear)
    I1, I2 = gt.shaft_inertias_kg_m2(scenario.materials, scenario.load, g.r1, g.worm_length, g.r2, g.face_width)
    # the worm meshes at its operating radius r_m1 and lead angle gamma_m (r1, gamma unshifted; DIN 3975-1)
    m1, m2 = I1 / g.r_m1**2, I2 / g.r2**2
    gamma, tg = g.gamma_m, math.tan(g.gamma_m)
    v = rpm_to_rad_s(scenario.drive.speed_rpm) * g.r_m1
    mu = float(friction_coefficient(scenario.contact, v / math.cos(gamma)))
    rho = gt.virtual_friction_angle_rad(mu, g.alpha_n)
    F2 = -scenario.load.torque_nm / g.r2
    # the worm force that holds the load at the working speed (seed 000's psi): a resisting load (F2 < 0) slides
    # tractive, F1 = -F2 tan(gamma + rho'); an assisting one (F2 > 0) inverse, F1 = -F2 tan(gamma - rho') (< 0: the
    # motor brakes, in its generator range above the synchronous speed)
    f_work = -F2 * math.tan(gamma + rho) if F2 < 0 else -F2 * math.tan(gamma - rho)
    f_peak = KLOSS_PEAK_FACTOR * abs(f_work) + (m1 + m2 * tg * tg) * v / RUNUP_S
    # 2 Fmax V / (1 + V^2) = f_work: the root of smaller |V|, then V0 - V_w (V0 - Vmax) = v
    V_w = (f_peak - math.sqrt(f_peak**2 - f_work**2)) / f_work if f_work != 0 else 0.0
    span = SLIP_SPAN * v
    v_sync = v + V_w * span
    p = WedgeParams(
        gamma_rad=gamma,
        m1_kg=m1,
        m2_kg=m2,
        group=None,
        friction=None,
        peak_force_n=f_peak,
        sync_speed_m_s=v_sync,
        peak_speed_m_s=v_sync - span,
        nominal_force_n=abs(f_work) if f_work != 0 else f_peak,
        nominal_speed_m_s=v,
        load_initial_n=0.0,
        load_final_n=F2,
        load_start_s=scenario.load.start_s,
        load_ramp_s=scenario.load.ramp_s,
        monitor="three_regime",
        v0_m_s=0.0,
        duration_s=scenario.simulation.duration_s,
        rtol=1e-8,
        contact=scenario.contact,
        cos_alpha_n=math.cos(g.alpha_n),
        method="Radau",
    )
    derived = {
        "wedge_source": "derived from gear:, drive:, load: (rho' = atan(mu / cos alpha_n), as torsional and contact3d)",
        "driving_mass_kg": m1,
        "driven_mass_kg": m2,
        "motor_peak_force_n": f_peak,
        "motor_synchronous_speed_m_s": v_sync,
    }
    return p, {"geometry": g, **derived}


def simulate_derived(scenario, progress=None) -> Result:
    """Run the derived wedge of a gear scenario (its plan, derived_plan, built once)."""
    return run_derived(derived_plan(scenario), progress)


def run_derived(plan: DerivedPlan, progress=None) -> Result:
    """Run the derived wedge and add the gear levels' common keys and force series (module docstring)."""
    p, g, d = plan.params, plan.geometry, plan.keys
    res = simulate_params(p, progress=progress, name=plan.name)
    S = res.series
    t = S["t_s"]
    rho = S["rho_deg"] * DEG
    s = np.where(S["regime_code"] == 1, 1.0, np.where(S["regime_code"] == 2, -1.0, 0.0))  # tractive / inverse
    ft = -S["S2_n"]
    S["tangential_force_n"] = ft
    S["axial_force_n"] = S["S1_n"]
    S["radial_force_n"] = gt.radial_force_n(np.abs(ft), g.alpha_n, g.gamma_m, s * rho)
    S["worm_speed_rpm"] = rad_s_to_rpm(S["v1_m_s"] / g.r_m1)
    S["wheel_speed_rpm"] = rad_s_to_rpm(S["v2_m_s"] / g.r2)
    S["friction_coefficient"] = np.tan(rho) * p.cos_alpha_n

    t0 = p.duration_s * (1 - STEADY_FRACTION)
    sl = t >= t0

    def mean(x):
        return float(np.trapezoid(x[sl], t[sl]) / (t[sl][-1] - t[sl][0])) if np.ptp(t[sl]) > 0 else float(x[-1])

    n1, n2 = mean(S["worm_speed_rpm"]), mean(S["wheel_speed_rpm"])
    # the power each shaft puts into the pair; an assisting load drives the wheel (the motor brakes): power flows
    # from the wheel to the worm, and the efficiency is the worm's power out over the wheel's in (as at the gear
    # levels, wormsim.results.metrics.power_flow)
    p1, p2 = mean(S["F1_n"] * S["v1_m_s"]), mean(S["F2_n"] * S["v2_m_s"])
    flow = power_flow(n1, n2, g.ratio, p1, p2)
    mu = mean(S["friction_coefficient"])
    T_load = plan.load_torque_nm
    res.summary = level_summary(
        "wedge",
        res.summary,
        {
            "ratio": n1 / n2 if flow != "none" else float("nan"),
            "power_flow": flow,
            "ratio_theory": g.ratio,
            "mesh_frequency_theory_hz": g.z1 * n1 / 60.0,
            "tangential_force_mean_n": abs(mean(ft)),
            "tangential_force_p2p_n": float(np.ptp(ft[sl])),
            "tangential_force_theory_n": gt.tangential_force_n(abs(T_load), g.r2),
            "radial_force_mean_n": abs(mean(S["radial_force_n"])),
            "axial_force_mean_n": abs(mean(S["axial_force_n"])),
            "worm_torque_mean_nm": abs(mean(S["F1_n"])) * g.r_m1,
            "wheel_torque_mean_nm": abs(mean(S["F2_n"])) * g.r2,
            "worm_speed_mean_rpm": n1,
            "wheel_speed_mean_rpm": n2,
            "efficiency": flow_efficiency(flow, p1, p2),
            "efficiency_theory": gt.efficiency_theory(g.gamma_m, g.alpha_n, mu, backdriving=flow == "wheel to worm")
            if flow != "none"
            else float("nan"),
            "friction_coefficient_mean": mu,
            "friction": plan.friction,
            **d,
        },
    )
    return res
