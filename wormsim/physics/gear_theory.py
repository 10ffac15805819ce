"""Worm gear theory that every fidelity level shares: one home per formula, each with its source. SI units, rad.

Sources:
- DIN 3975-2:2017 (worm gear geometry and forces) and Niemann / Winter, Maschinenelemente III, 2nd ed. (1986),
  ch. 24 (worm gears): the virtual friction angle rho' = atan(mu / cos alpha_n), the efficiencies
  eta = tan(gamma) / tan(gamma + rho') and eta' = tan(gamma - rho') / tan(gamma), and the force components
  F_t2, F_a2, F_r2, F_n at the pitch point;
- seed 000 (the wedge model): the same efficiencies with the friction angle rho of its rho(Vs) fit;
- ADAMS STEP (INTERFACE.md) for the drive and load ramps (wormsim.physics.units.step);
- Hertz line contact (Johnson, Contact Mechanics, 1985, ch. 4) for the effective modulus E*.

Floats go through `math`, arrays through numpy: a level's scalar and vectorised paths give the same numbers
they did before these formulas moved here (bit for bit on the seed runs).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from wormsim.physics.units import GPA, rpm_to_rad_s, step
from wormsim.scenario import Drive, Load, Materials, Scenario, ScenarioError

# ----------------------------------------------------------------------------- friction angle and efficiency


def virtual_friction_angle_rad(mu, alpha_n_rad: float):
    """rho' = atan(mu / cos(alpha_n)): the friction angle in the flank normal seen in the worm's axial section
    (DIN 3975-2; Niemann / Winter III, eq. 24.31). Float or array mu."""
    if isinstance(mu, float | int):
        return math.atan(mu / math.cos(alpha_n_rad))
    return np.arctan(mu / math.cos(alpha_n_rad))


def efficiency_forward(lead_angle_rad, rho_rad):
    """Worm driving: eta = tan(gamma) / tan(gamma + rho) (DIN 3975-2; seed 000). Floats or arrays."""
    if isinstance(lead_angle_rad, float | int) and isinstance(rho_rad, float | int):
        return math.tan(lead_angle_rad) / math.tan(lead_angle_rad + rho_rad)
    return np.tan(lead_angle_rad) / np.tan(lead_angle_rad + rho_rad)


def efficiency_backward(lead_angle_rad, rho_rad):
    """Wheel driving: eta' = tan(gamma - rho) / tan(gamma), 0 when self-locking (rho >= gamma) (DIN 3975-2;
    seed 000). Floats or arrays."""
    if isinstance(lead_angle_rad, float | int) and isinstance(rho_rad, float | int):
        return max(math.tan(lead_angle_rad - rho_rad) / math.tan(lead_angle_rad), 0.0)
    return np.maximum(np.tan(lead_angle_rad - rho_rad), 0.0) / np.tan(lead_angle_rad)


def efficiency_self_locking(lead_angle_rad: float, rho_rad: float) -> float:
    """tan(rho - gamma) / tan(gamma) when rho > gamma, else 0: the motor power a self-locking pair still needs per
    unit of assisting load power (seed 000, inverse regime)."""
    return max(0.0, math.tan(rho_rad - lead_angle_rad) / math.tan(lead_angle_rad))


def self_locking(lead_angle_rad: float, rho_rad: float) -> bool:
    """A pair self-locks (the wheel cannot drive the worm) when the friction angle reaches the lead angle:
    rho' >= gamma, where tan(gamma - rho') / tan(gamma) (efficiency_backward) falls to 0 (DIN 3975-2; Niemann /
    Winter III, ch. 24: static self-locking with the friction at rest, dynamic with the friction while sliding)."""
    return bool(rho_rad >= lead_angle_rad)


def backdrive_keys(lead_angle_rad: float, rho_static_rad: float, rho_dynamic_rad: float) -> dict:
    """The summary keys every level writes on back-driving (docs/outputs.md): `self_locking` (static: rho' at rest
    >= gamma, the pair holds the load from standstill), `self_locking_dynamic` (rho' while sliding >= gamma: a
    back-driven pair comes to rest), `efficiency_backdrive` = tan(gamma - rho') / tan(gamma) with the sliding
    friction, 0 when it self-locks dynamically (DIN 3975-2), and the angles used."""
    return {
        "self_locking": self_locking(lead_angle_rad, rho_static_rad),
        "self_locking_dynamic": self_locking(lead_angle_rad, rho_dynamic_rad),
        "efficiency_backdrive": efficiency_backward(lead_angle_rad, rho_dynamic_rad),
        "friction_angle_static_deg": math.degrees(rho_static_rad),
        "friction_angle_dynamic_deg": math.degrees(rho_dynamic_rad),
        "lead_angle_deg": math.degrees(lead_angle_rad),
    }


def efficiency_theory(
    lead_angle_rad: float, normal_pressure_angle_rad: float, mu: float, backdriving: bool = False
) -> float:
    """Efficiency at the pitch radius r1 with rho' = atan(mu / cos(alpha_n)): efficiency_forward, or
    efficiency_backward when the wheel drives (DIN 3975-2)."""
    rho = virtual_friction_angle_rad(mu, normal_pressure_angle_rad)
    if backdriving:
        return efficiency_backward(lead_angle_rad, rho)
    return efficiency_forward(lead_angle_rad, rho)


def lead_angle_at_radius_rad(lead_angle_rad: float, r1_m: float, r_m):
    """Local lead angle of a helicoid at radius r: tan(gamma_r) = tan(gamma) r1 / r (one lead on every cylinder,
    DIN 3975-1). Array r."""
    return np.arctan(math.tan(lead_angle_rad) * r1_m / np.maximum(r_m, 1e-12))


def efficiency_at_radius(
    lead_angle_rad: float, r1_m: float, r_m, mu: float, alpha_n_rad: float, backdriving: bool = False
):
    """The wedge efficiency at contact radius r instead of r1: efficiency_forward / efficiency_backward at
    gamma_r (lead_angle_at_radius_rad) with rho' = atan(mu / cos alpha_n) (contact3d reports it at its contacts'
    radii). Array r."""
    g = lead_angle_at_radius_rad(lead_angle_rad, r1_m, r_m)
    rho = virtual_friction_angle_rad(mu, alpha_n_rad)
    return efficiency_backward(g, rho) if backdriving else efficiency_forward(g, rho)


# ----------------------------------------------------------------------------- forces at the pitch point


def tangential_force_n(wheel_torque_nm, r2_m: float):
    """F_t2 = T2 / r2 (DIN 3975-2)."""
    return wheel_torque_nm / r2_m


def normal_force_n(wheel_torque_nm: float, r2_m: float, alpha_n_rad: float, lead_angle_rad: float) -> float:
    """F_n = T2 / (r2 cos(alpha_n) cos(gamma)): the flank-normal force at the pitch point without friction
    (DIN 3975-2; Niemann / Winter III)."""
    return wheel_torque_nm / (r2_m * math.cos(alpha_n_rad) * math.cos(lead_angle_rad))


def axial_force_n(ft2_n, lead_angle_rad: float, rho_signed_rad):
    """F_a2 = F_t1 = F_t2 tan(gamma + s rho') (DIN 3975-2; s = +1 worm driving, -1 back-driving; rho_signed_rad =
    s rho', which may be smoothed between -rho' and rho'). Arrays."""
    return ft2_n * np.tan(lead_angle_rad + rho_signed_rad)


def radial_force_n(ft2_abs_n, alpha_n_rad: float, lead_angle_rad: float, rho_signed_rad):
    """F_r2 = |F_t2| tan(alpha_n) cos(rho') / cos(gamma + s rho') (DIN 3975-2; rho_signed_rad = s rho').
    Floats or arrays."""
    if isinstance(ft2_abs_n, float | int) and isinstance(rho_signed_rad, float | int):
        return ft2_abs_n * math.tan(alpha_n_rad) * math.cos(rho_signed_rad) / math.cos(lead_angle_rad + rho_signed_rad)
    return ft2_abs_n * math.tan(alpha_n_rad) * np.cos(rho_signed_rad) / np.cos(lead_angle_rad + rho_signed_rad)


def worm_torque_nm(
    wheel_torque_nm: float, hand: int, r1_m: float, r2_m: float, lead_angle_rad: float, rho_signed_rad: float
) -> float:
    """Torque the mesh takes from the worm for a mesh torque T2 on the wheel: T1 = hand (T2 / r2) r1 tan(gamma +
    s rho') = F_a2 r1 (DIN 3975-2; rho_signed_rad = s rho'). Floats (the torsional ODE's right-hand side)."""
    return hand * (wheel_torque_nm / r2_m) * r1_m * math.tan(lead_angle_rad + rho_signed_rad)


def mesh_arms_m(r1_m: float, r2_m: float, alpha_n_rad: float, lead_angle_rad: float) -> tuple[float, float]:
    """Moment arms of a unit flank-normal force at the pitch point about the worm and wheel axes:
    r1 cos(alpha_n) sin(gamma) and r2 cos(alpha_n) cos(gamma) (DIN 3975-2 force components)."""
    ca = math.cos(alpha_n_rad)
    return r1_m * ca * math.sin(lead_angle_rad), r2_m * ca * math.cos(lead_angle_rad)


def working_wheel_torque_of(drv: Drive, load: Load, ratio: float) -> float:
    """T2 (N m) through the mesh at the working load: the load, or the worm load times the ratio when the load is on
    the worm; a torque driving the WHEEL counts too, the larger of the two (it passes through the mesh whatever the
    worm does, and against a free worm it is the only load). A torque driving the worm is not counted: what it does
    not pass to the wheel load accelerates the worm."""
    t2 = abs(load.torque_nm) * (1.0 if load.on == "wheel" else ratio)
    if drv.torque_nm is not None and drv.on == "wheel":
        t2 = max(t2, abs(drv.torque_nm))
    return t2


# ----------------------------------------------------------------------------- contact (shared by the levels)

DEFAULT_DAMPING_RATIO = 0.1  # mesh damping when none is given, of one tooth pair's critical damping
MAX_DAMPING_RATIO = 0.1  # cap of the mesh damping (measured gear-mesh damping ratios: 0.03-0.17)


def shaft_inertias_kg_m2(
    materials: Materials, load: Load, r1_m: float, worm_length_m: float, r2_m: float, face_width_m: float
):
    """(I1, I2) in kg m^2: the worm a solid cylinder r1 x threaded length, the wheel a solid cylinder r2 x face width
    (I = m r^2 / 2, densities from materials:), plus the driven-machine inertia load.inertia_kg_m2 on the loaded
    shaft (rigid on it, as contact3d's joint armature). The torsional and the derived wedge level use it."""
    mats = materials
    m1 = mats.worm.density_kg_m3 * math.pi * r1_m**2 * worm_length_m
    m2 = mats.wheel.density_kg_m3 * math.pi * r2_m**2 * face_width_m
    j = load.inertia_kg_m2
    j1, j2 = (j, 0.0) if load.on == "worm" else (0.0, j)
    return 0.5 * m1 * r1_m**2 + j1, 0.5 * m2 * r2_m**2 + j2


def effective_modulus_pa(materials: Materials) -> float:
    """E* with 1/E* = (1 - nu1^2)/E1 + (1 - nu2^2)/E2 (Hertz; seeds 001, 002)."""
    w, g = materials.worm, materials.wheel
    return 1.0 / (
        (1 - w.poisson_ratio**2) / (w.youngs_modulus_gpa * GPA)
        + (1 - g.poisson_ratio**2) / (g.youngs_modulus_gpa * GPA)
    )


# ----------------------------------------------------------------------------- drive and load commands


def drive_target(drive: Drive) -> float:
    """The drive's full command: speed in rad/s (speed_rpm) or torque in N m (torque_nm)."""
    if drive.speed_rpm is not None:
        return rpm_to_rad_s(drive.speed_rpm)
    assert drive.torque_nm is not None  # the scenario gives exactly one
    return drive.torque_nm


def load_target_nm(drive: Drive, load: Load, direction: int) -> float:
    """The load's full torque on its shaft: it resists, its sign opposite to the load shaft's expected motion,
    direction x sign(drive command) (direction: +1/-1 per unit command, the hand for a worm pair)."""
    target = drive_target(drive)
    s = (math.copysign(1.0, target) if target != 0 else 1.0) * direction
    return -s * load.torque_nm


def ramps_end_of(drive: Drive, load: Load) -> float:
    """When both commands have reached their full value (s)."""
    return max(drive.ramp_s, load.start_s + load.ramp_s)


@dataclass(frozen=True)
class Commands:
    """Drive command (rad/s or N m) and load torque (N m, on the load shaft) against time: ADAMS STEP from 0 over
    drive.ramp_s, and from load.start_s over load.ramp_s (INTERFACE.md). Floats or arrays of t."""

    drive_target: float
    drive_ramp_s: float
    load_target_nm: float
    load_start_s: float
    load_end_s: float

    def drive(self, t):
        return step(t, 0.0, 0.0, self.drive_ramp_s, self.drive_target)

    def load(self, t):
        return step(t, self.load_start_s, 0.0, self.load_end_s, self.load_target_nm)


def commands_of(drv: Drive, load: Load, direction: int) -> Commands:
    """The drive's and the load's STEPs (Commands) for the expected direction (load_target_nm)."""
    return Commands(
        drive_target(drv), drv.ramp_s, load_target_nm(drv, load, direction), load.start_s, load.start_s + load.ramp_s
    )


def working_flank_of(drv: Drive, hand: int) -> int:
    """+1 when the mesh torque on the wheel is positive in the intended running (the worm drives against a resisting
    load: hand x sign(command)), -1 otherwise (the wheel drives: the mesh resists its motion). The flank side of
    meshgen.kinematic_tca and wormsim.tooth.mesh_stiffness."""
    s = 1 if drive_target(drv) >= 0 else -1
    return s * hand if drv.on == "worm" else -s


def worm_speed_command_rad_s(drv: Drive, ratio: float) -> float | None:
    """Worm speed (rad/s) the drive commands: |speed_rpm| when the worm is speed-driven, ratio x |speed_rpm| when the
    wheel is (kinematics z2 / z1); None for a torque drive (its speed is known only while running)."""
    if drv.speed_rpm is None:
        return None
    w = abs(rpm_to_rad_s(drv.speed_rpm))
    return w if drv.on == "worm" else w * ratio


@dataclass(frozen=True)
class Duty:
    """A gear-level run's drive and load (the scenario's drive: and load: blocks) and what follows from them and the
    expected direction alone, derived once (duty) and handed down instead of the scenario."""

    drive: Drive
    load: Load
    direction: int  # +1/-1: the load shaft's expected sign per sign of the drive command (the hand for a worm pair)
    commands: Commands  # commands_of
    ramps_end_s: float  # ramps_end_of
    lock_check_start_s: float  # lock_check_after the ramps
    working_flank: int  # working_flank_of (direction is the hand)

    @property
    def speed_driven(self) -> bool:
        """drive.speed_rpm given (else drive.torque_nm)."""
        return self.drive.speed_rpm is not None


def duty(scenario: Scenario, direction: int) -> Duty:
    """The scenario's Duty for the expected direction (the pair's hand): built once from the scenario's drive: and
    load: blocks (a gear-level scenario, torsional or contact3d, has a drive: block); the levels and their helpers
    take the Duty, not the scenario."""
    if scenario.drive is None:
        raise ScenarioError(f"drive: model {scenario.model} needs a drive: block")
    drv, load = scenario.drive, scenario.load
    ramps = ramps_end_of(drv, load)
    return Duty(
        drv,
        load,
        direction,
        commands_of(drv, load, direction),
        ramps,
        lock_check_after(ramps),
        working_flank_of(drv, direction),
    )


# ----------------------------------------------------------------------------- speed servo

SPEED_DROOP = 1e-3  # speed servo: kv = T_expected / (SPEED_DROOP omega_cmd), a 0.1 % droop at the expected torque
MIN_EFFICIENCY = 0.05  # floor of the efficiency in the expected torque (a self-locking back-drive has 0)


def expected_drive_torque_of(
    drv: Drive, load: Load, ratio: float, lead_angle_rad: float, alpha_n_rad: float, mu: float
) -> float:
    """Drive torque (N m) at the full load: T_load / i / eta (worm driving) or T_load i / eta (wheel driving), with
    eta = efficiency_theory at mu, at least MIN_EFFICIENCY; at least 1e-3 N m."""
    eta = efficiency_theory(lead_angle_rad, alpha_n_rad, mu, backdriving=drv.on == "wheel")
    if drv.on == "worm":
        t_exp = abs(load.torque_nm) / ratio / max(eta, MIN_EFFICIENCY)
    else:
        t_exp = abs(load.torque_nm) * ratio / max(eta, MIN_EFFICIENCY)
    return max(t_exp, 1e-3)


def servo_gain_of(drv: Drive, expected_torque_nm: float) -> float:
    """kv = T_expected / (SPEED_DROOP omega_cmd) (N m s/rad) of a speed-driven drive (contact3d's velocity actuator,
    the torsional level's servo): the speed droops SPEED_DROOP of the command at the expected torque
    (expected_drive_torque_of)."""
    if drv.speed_rpm is None:
        raise ValueError("servo_gain_nm_s: the drive is torque-controlled")
    w_cmd = abs(rpm_to_rad_s(drv.speed_rpm))
    return expected_torque_nm / (SPEED_DROOP * max(w_cmd, 1e-3))


SERVO_PEAK_FACTOR = 3.0  # a speed drive's peak torque: this many times its rated torque (servo_peak_torque_nm)
SERVO_KNEE = 0.9  # the torsional servo's limit bends off the linear law above this share of the peak
STEP_PEAK_SLOPE = 1.5  # ADAMS STEP's steepest slope, x (h1 - h0) / ramp: d/dx x^2 (3 - 2 x) = 6 x (1 - x) at x = 1/2


def servo_peak_torque_nm(
    expected_torque_nm: float, drive_inertia_kg_m2: float, command_rad_s: float, ramp_s: float
) -> float | None:
    """The peak torque (N m) of a speed drive: SERVO_PEAK_FACTOR x its rated torque, the rated torque being what the
    run asks of it, the expected torque at the full load (expected_drive_torque_of) plus the start-up ramp's
    acceleration torque J_eff STEP_PEAK_SLOPE omega_cmd / ramp_s (J_eff: the inertia the drive accelerates, reduced
    to its shaft, drive_inertia_kg_m2). None (no limit) for a step command (ramp_s 0), whose acceleration no finite
    torque follows.

    A speed servo (a motor with its amplifier's speed loop) is sized for its duty's rated torque (the load plus the
    acceleration, servo-sizing practice) and delivers a peak torque of a few times that for short spells: the
    intermittent zone of a servo motor's torque-speed curve reaches about three times its continuous rating, and the
    amplifier's current limit holds the torque there. SERVO_PEAK_FACTOR = 3 is that modelling choice, not a
    measured value. The run's servo (servo_gain_of) droops SPEED_DROOP at the expected torque, so unlimited it would
    push a stalled shaft with T_expected / SPEED_DROOP (1000 x): a wheel back-driving a self-locking pair crushed the
    held mesh (the screw jack at mu 0.2: 21 kN m against the 12 N m load, 1 mm penetration, the worm creeping at
    0.7 %); held at this limit it stands (0.002 %, docs/decisions/0053-servo-peak-torque.md). Where it applies:
    servo_peak_applies."""
    if ramp_s <= 0.0:
        return None
    rated = expected_torque_nm + drive_inertia_kg_m2 * STEP_PEAK_SLOPE * abs(command_rad_s) / ramp_s
    return SERVO_PEAK_FACTOR * rated


def servo_peak_applies(speed_driven: bool, backdrive_self_locks: bool) -> bool:
    """Where a speed drive's peak torque (servo_peak_torque_nm) is enforced: a drive that stalls by design, the wheel
    back-driving a pair that self-locks at rest (wormsim.physics.locking.backdrive_self_locks). Every other speed
    drive stays unlimited, a motion drive as in the seeds' ADAMS models: its servo also stands in for the motor's
    rotor inertia, which the model lacks and which carries a real drive through impacts. Limited at 3 x, the other
    gear's start-up impact (5.3 x its rating, 1.5 ms) and the convex pieces' facet impacts (up to 4.9 x, throughout
    a 0.04 s run) bound, and the pieces variant's ratio moved by 0.13 % (docs/decisions/0053-servo-peak-torque.md)."""
    return speed_driven and backdrive_self_locks


def drive_inertia_kg_m2(drive_on: str, ratio: float, worm_kg_m2: float, wheel_kg_m2: float) -> float:
    """The inertia a drive accelerates, reduced to its shaft: I1 + I2 / i^2 on the worm, I2 + I1 i^2 on the
    wheel (each with its driven-machine inertia)."""
    if drive_on == "worm":
        return worm_kg_m2 + wheel_kg_m2 / ratio**2
    return wheel_kg_m2 + worm_kg_m2 * ratio**2


def servo_limited_torque_nm(torque_nm: float, peak_nm: float | None) -> float:
    """The torsional servo's torque under its peak (servo_peak_torque_nm), solved within the implicit step: the
    linear law up to SERVO_KNEE x peak, above it peak - d exp(-(|T| - knee) / d) with d = peak - knee (continuous in
    value and slope: with a hard clip the step's Newton iteration cycled and did not converge where the bend did, the
    screw jack's held back-drive at 3 x at t = 3 ms). None: the linear law."""
    if peak_nm is None:
        return torque_nm
    knee = SERVO_KNEE * peak_nm
    x = abs(torque_nm)
    if x <= knee:
        return torque_nm
    d = peak_nm - knee
    return math.copysign(peak_nm - d * math.exp(-(x - knee) / d), torque_nm)


def servo_command(cmd: float, w: float, band: float) -> float:
    """The speed servo's command under its peak torque (servo_peak_torque_nm), for a step that starts at speed w:
    cmd, or, where w is more than band = peak / kv from it, w + band towards it. The servo's torque kv (command -
    w') at the step's end speed w' is then peak - kv (w' - w): the peak at a stall, the linear law wherever the
    limit does not bind (the command unchanged, bit for bit), and implicit in w' as the unlimited servo (a hard
    clip of kv (cmd - w) is explicit where it binds: with kv h / I of 400 it chattered between +peak and -peak
    step by step with MuJoCo's forcerange; docs/decisions/0053-servo-peak-torque.md). contact3d's drive
    (wormsim.contact3d.flank_loop.run_table); the torsional level's implicit step solves the limited law itself
    (servo_limited_torque_nm). Where it binds while the shaft is free to accelerate, the damping
    kv (w' - w) slows the acceleration to I / (I + kv h) of the peak's: such a run is warned about
    (wormsim.results.run_warnings.drive_peak_warning). band 0: no limit."""
    if band > 0.0:
        if cmd - w > band:
            return w + band
        if w - cmd > band:
            return w - band
    return cmd


# ----------------------------------------------------------------------------- guards

PENETRATION_LIMIT_AXIAL_MODULES = 0.4  # beyond 0.4 m_x of penetration (mesh deflection) teeth are about to skip
LOCK_SETTLE_S = 0.02  # the locked-drive check starts this long after the ramps end
LOCK_SPEED_FRACTION = 0.5  # a speed-driven drive below this fraction of its command is stuck ...
LOCK_HOLD_S = 0.05  # ... and locked once stuck this long


def penetration_limit_m(m_x: float) -> float:
    """Largest penetration (contact3d) or mesh deflection (torsional) a run allows: 0.4 m_x."""
    return PENETRATION_LIMIT_AXIAL_MODULES * m_x


def lock_check_after(ramps_end_s: float) -> float:
    """The locked-drive check's start (s): LOCK_SETTLE_S after the ramps' end."""
    return ramps_end_s + LOCK_SETTLE_S


def drive_stuck(w_drive, command):
    """|omega_drive| < LOCK_SPEED_FRACTION |command|: the speed-driven drive does not follow (floats or arrays)."""
    return abs(w_drive) < LOCK_SPEED_FRACTION * abs(command)


# ----------------------------------------------------------------------------- rounding


def round_down_125(h: float) -> float:
    """Largest 1, 2 or 5 x 10^e not above h, as the decimal value: 5e-06, not 5 * 10.0 ** -6 =
    4.9999999999999996e-06 (the float trap: a timestep printed as 5e-06 must be 5e-06)."""
    e = math.floor(math.log10(h))
    for mant in (5, 2, 1):
        if float(f"{mant}e{e}") <= h * (1 + 1e-12):
            return float(f"{mant}e{e}")
    return float(f"1e{e}")
