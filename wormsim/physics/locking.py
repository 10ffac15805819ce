"""Self-locking as a result (docs/outputs.md `locked`, `holding_torque_nm`, `creep_speed_rpm`).

A speed-driven wheel that back-drives a pair that self-locks at standstill, rho' = atan(mu_static / cos alpha_n)
>= gamma (DIN 3975-2: back-driving efficiency tan(gamma - rho') / tan(gamma) <= 0), cannot turn the worm: the
wheel stalls and the mesh holds. That is the answer the run was asked for, not a failure. At torsional and contact3d
the lock guard (gear_theory.drive_stuck held for LOCK_HOLD_S after the ramps) and, at contact3d, the penetration
guard while the worm creeps or follows the wheel at under a tenth of the ratio (the stalled wheel's speed servo
pushing the held mesh into the contact; wormsim.contact3d.guards.HELD_FOLLOW_FRACTION) end such a run
at that moment with status ok; the summary is taken over the run up to there and says

- `locked`: true;
- `holding_torque_nm`: the largest |wheel drive torque| the mesh held before the run ended (the drive kept
  pushing, so this is what was held, not a breaking limit);
- `creep_speed_rpm`: the worm's mean |speed| over the stuck stretch (the drive below half its command).

Every other torsional and contact3d run writes `locked: false` and null for the other two. A jammed mesh (the drive
stuck with rho' < gamma, or the worm stuck) stays a failure (LockedError, exit 3).
"""

from __future__ import annotations

import math

import numpy as np

from wormsim.physics import gear_theory as gt
from wormsim.scenario import Drive


class Held(Exception):
    """Internal: a guard found the self-locking pair holding (module docstring); `t_s` when it was found. Never
    leaves a level's simulate."""

    def __init__(self, t_s: float, stuck_since_s: float | None):
        super().__init__(f"held at t = {t_s:.4g} s")
        self.t_s = t_s
        self.stuck_since_s = stuck_since_s


def backdrive_self_locks(drive: Drive, lead_angle_rad: float, rho_static_rad: float) -> bool:
    """A speed-driven wheel against a pair that self-locks at standstill, rho' at rest >= gamma (module
    docstring)."""
    if drive.on != "wheel" or drive.speed_rpm is None:
        return False
    return gt.self_locking(lead_angle_rad, rho_static_rad)


def run_keys(
    drive: Drive,
    rho_static_rad: float,
    transition_velocity_m_s: float,
    geo,
    t_s: np.ndarray,
    worm_speed_rpm: np.ndarray,
) -> dict:
    """`locked`, `holding_torque_nm`, `creep_speed_rpm` of a run that ended normally: a torque-driven wheel against a
    pair that self-locks at rest holds when the worm's mean |speed| over the run's last fifth slides slower than
    contact.transition_velocity_m_s (static friction's reach); the holding torque is then the wheel's torque
    command. Every other run: NOT_LOCKED."""
    drv = drive
    if drv.on != "wheel" or drv.torque_nm is None or not len(t_s):
        return dict(NOT_LOCKED)
    if not gt.self_locking(geo.gamma_m, rho_static_rad):
        return dict(NOT_LOCKED)
    k = t_s >= t_s[-1] - 0.2 * (t_s[-1] - t_s[0])
    creep = float(np.mean(np.abs(worm_speed_rpm[k])))
    vs = creep * 2 * math.pi / 60 * geo.r_m1 / math.cos(geo.gamma_m)
    if vs >= transition_velocity_m_s:
        return dict(NOT_LOCKED)
    return {"locked": True, "holding_torque_nm": abs(float(drv.torque_nm)), "creep_speed_rpm": creep}


def stall_torque_nm(expected_drive_torque_nm: float, peak_torque_nm: float | None) -> float:
    """The torque a stalled speed servo pushes with: its peak torque (gear_theory.servo_peak_torque_nm), or without
    one (a step command) kv omega_cmd = T_expected / SPEED_DROOP (gear_theory.servo_gain_of). contact3d takes it as
    the held mesh's working torque for the friction rows' hardness (wormsim.contact3d.law (3)) when
    backdrive_self_locks: with the worm load alone (often 0) impratio fell to 1 and the held pair crept back through
    the soft cone's viscous branch (measured: 65 rpm of the worm, 6 % of the wheel command times the ratio, on the
    seat motor demo gear at mu 0.1)."""
    if peak_torque_nm is not None:
        return peak_torque_nm
    return expected_drive_torque_nm / gt.SPEED_DROOP


def stick_velocity_m_s(
    drive: Drive, lead_angle_rad: float, rho_static_rad: float, transition_velocity_m_s: float, mu_varies: bool = True
) -> float:
    """The friction law's stick state at contact3d (wormsim.physics.friction.stuck_after): v_t =
    contact.transition_velocity_m_s where the wheel drives (the worm undriven) a pair that self-locks at rest,
    rho'(mu(0)) >= gamma, and mu depends on the sliding speed (mu_varies: a static/dynamic pair or a friction group),
    else 0 (no stick state: mu follows mu(Vs) from the first sample, as on every other run; a constant mu is its own
    static value). Holding from rest needs it: the soft contact lets a freshly loaded pair slide a little (measured on
    the seat motor demo gear, 2 N m in 2 ms, mu 0.0877 constant: the worm reaches Vs 0.90 mm/s at 1 ms, then creeps at
    0.09 rpm), and with mu(Vs) blending towards the dynamic value over that slip the pair ran back. The stuck pair
    breaks away when the friction it needs on the worm's hinge reaches mu(0) times its normal forces
    (wormsim.contact3d.breakaway), not at a slip speed: under a fast load that slip passes v_t long before static
    friction is used up (docs/decisions/0058-breakaway-on-static-friction.md); v_t is where a sliding pair's mu(Vs)
    reaches the dynamic value, and it sticks again below STICK_RELEASE v_t."""
    if drive.on != "wheel" or not mu_varies or not gt.self_locking(lead_angle_rad, rho_static_rad):
        return 0.0
    return float(transition_velocity_m_s)


def wheel_start_rad(drive: Drive, flanks: bool, backlash_m: float, r2_m: float, perfect_pair: bool) -> float:
    """The wheel's starting angle at contact3d: a torque-driven wheel (a holding or back-driving run) starts on its
    loaded flank, turned by the half backlash j / (2 r2) (the flank grid's backlash, wormsim.tooth.grid) towards its
    torque; every other run starts centred in its backlash (0). Holding from rest needs the pair at rest in contact:
    started centred, the wheel crossed the backlash under its torque and the impact kicked the 4 g worm of the seat
    motor demo past contact.transition_velocity_m_s, so friction was the dynamic value from the first contact on
    (measured: the worm ran back at 3.2 % of its free speed; from flank contact with a 20 ms ramp it holds, 0.09 rpm,
    docs/stability_backlash_locking.md). Only the exact flanks (contact.geometry flanks) of a perfect pair: the
    pieces' bulge and displaced flanks (errors:, shafts:) have their own play; flanks: contact.geometry is flanks."""
    drv = drive
    if drv.on != "wheel" or drv.torque_nm is None or not flanks or not perfect_pair:
        return 0.0
    return math.copysign(backlash_m / (2.0 * r2_m), drv.torque_nm) if drv.torque_nm else 0.0


NOT_LOCKED = {"locked": False, "holding_torque_nm": None, "creep_speed_rpm": None}


def held_keys(t_s: np.ndarray, worm_speed_rpm: np.ndarray, wheel_torque_nm: np.ndarray, stuck_since_s: float) -> dict:
    """The summary keys of a held run (module docstring) from its series up to the end of the run."""
    k = t_s >= stuck_since_s
    if not k.any():
        k = np.ones_like(t_s, dtype=bool)
    return {
        "locked": True,
        "holding_torque_nm": float(np.max(np.abs(wheel_torque_nm))) if len(wheel_torque_nm) else 0.0,
        "creep_speed_rpm": float(np.mean(np.abs(worm_speed_rpm[k]))) if k.any() else 0.0,
    }


__all__ = [
    "Held",
    "NOT_LOCKED",
    "backdrive_self_locks",
    "held_keys",
    "run_keys",
    "stall_torque_nm",
    "stick_velocity_m_s",
    "wheel_start_rad",
]
