"""The run's guards (docs/contact3d.md, "Failure modes and guards"): after every record interval, non-finite state or
MuJoCo's bad-qacc warning (divergence), the worm turning more than OVERSPEED_GUARD x MAX_WORM_TURN_PER_STEP_RAD per
step (overspeed), the transmission error passing JUMP_PITCH of a pitch (teeth jumped), the sliding contacts'
friction against their slip (wormsim.contact3d.friction_guard), penetration beyond gear_theory.penetration_limit_m,
and a speed-driven drive stuck below half its command (locked). Each raises its SimulationError subclass
(wormsim.exceptions) with what to change; the messages are built in wormsim.contact3d.diagnosis."""

from __future__ import annotations

import math

import mujoco
import numba

from wormsim.contact3d.diagnosis import (
    JUMP_PITCH,
    diverged_error,
    jump_error,
    locked_error,
    overspeed_error,
    penetration_error,
)
from wormsim.contact3d.friction_guard import FrictionGuard
from wormsim.contact3d.mjcf import BuiltModel
from wormsim.contact3d.timestep import MAX_WORM_TURN_PER_STEP_RAD, OVERSPEED_GUARD
from wormsim.physics import gear_theory as gt
from wormsim.physics.locking import Held
from wormsim.physics.units import rad_s_to_rpm

DIVERGED, OVERSPEED, JUMPED = 1, 2, 3  # state_event's codes (0: none)
PENETRATED, STUCK, RUNNING = 4, 5, 6  # contact_event's codes (0: none)


@numba.njit(cache=True, inline="always")
def state_event(th1, th2, w1, w2, bad, dt, turn_lim, direction, ratio, jump_rad):
    """The state checks of a sample, in order: DIVERGED (non-finite state, or MuJoCo's bad-qpos, -qvel or -qacc
    warnings' count bad: MuJoCo then reset the state and the time), OVERSPEED (the worm's turn per step |w1| dt beyond
    turn_lim), JUMPED (the transmission error th2 - direction th1 / ratio beyond jump_rad), 0 when none fires; with
    (the TE, the turn). Guards.state and the compiled samples (wormsim.contact3d.flank_samples) both decide by it."""
    if not math.isfinite(th1 + th2 + w1 + w2) or bad != 0:
        return DIVERGED, 0.0, 0.0
    turn = abs(w1) * dt
    if turn > turn_lim:
        return OVERSPEED, 0.0, turn
    te = th2 - direction * th1 / ratio
    if abs(te) > jump_rad:
        return JUMPED, te, turn
    return 0, te, turn


HELD_FOLLOW_FRACTION = 0.1  # a back-driven worm turning slower than this share of the kinematic speed is held


@numba.njit(cache=True, inline="always")
def contact_event(t, pen, pen_lim, w_drive, cmd, speed_driven, lock_start, lock_fraction):
    """The contact checks of a sample, in order: PENETRATED (the largest penetration pen beyond pen_lim), then for a
    speed-driven drive after lock_start STUCK (|w_drive| below lock_fraction of its command |cmd|:
    gear_theory.drive_stuck) or RUNNING; 0 when the lock is not watched. Guards.contact and the compiled samples
    (wormsim.contact3d.flank_samples) both decide by it."""
    if pen > pen_lim:
        return PENETRATED
    if speed_driven and t > lock_start:
        if abs(w_drive) < lock_fraction * abs(cmd):
            return STUCK
        return RUNNING
    return 0


def bad_state_warnings(d: mujoco.MjData) -> list[str]:
    """Which of MuJoCo's bad-state warnings (qpos, qvel, qacc) fired: on each MuJoCo resets the state and d.time to
    the start and steps on (mj_checkPos / mj_checkVel / mj_checkAcc)."""
    return [
        w for w in ("qpos", "qvel", "qacc") if d.warning[getattr(mujoco.mjtWarning, f"mjWARN_BAD{w.upper()}")].number
    ]


class Guards:
    """The checks after every record interval (module docstring); each raises its SimulationError subclass. What they
    check against comes from the run's plan (bm.plan: the timestep, the drive's kind, the guards' times, the working
    load, the values the error messages quote: wormsim.contact3d.diagnosis)."""

    def __init__(self, bm: BuiltModel, rec: int):
        plan = bm.plan
        self.bm, self.dt = bm, plan.timestep_s
        geo = bm.geometry
        self.pen_lim = gt.penetration_limit_m(geo.m_x)
        self.pitch_angle = 2 * math.pi / geo.z2
        self.turn_lim = OVERSPEED_GUARD * MAX_WORM_TURN_PER_STEP_RAD
        self.jump_rad = JUMP_PITCH * self.pitch_angle
        self.lock_start = plan.lock_start_s
        self.lock_hold = max(gt.LOCK_HOLD_S, 20 * rec * self.dt)
        self.speed_driven = plan.speed_driven
        self.locked_since: float | None = None
        self.self_locking_backdrive = plan.gear.backdrive_self_locks
        self.turn_max = 0.0
        self.stuck = plan.stick_velocity_m_s > 0.0  # the friction law's stick state: a run starts at rest
        # sliding contacts' friction against their slip (wormsim.contact3d.friction_guard)
        self.friction = FrictionGuard(bm, rec * self.dt)

    def state(self, d: mujoco.MjData, t: float, th1: float, th2: float, w1: float, w2: float) -> float:
        """Divergence, overspeed, teeth jumped, friction against the slip; returns the transmission error (rad)."""
        bm, dt = self.bm, self.dt
        bad = bad_state_warnings(d)
        code, te, turn = state_event(
            th1, th2, w1, w2, len(bad), dt, self.turn_lim, float(bm.direction), bm.geometry.ratio, self.jump_rad
        )
        if code == DIVERGED:
            what = "huge acceleration" if "qacc" in bad else "huge velocity or position"
            why = f" (MuJoCo's bad-{' / bad-'.join(bad)} warning)" if bad else ""
            raise diverged_error(t, dt, bm, f"non-finite state or {what}{why}")
        self.turn_max = max(self.turn_max, turn)
        if code == OVERSPEED:
            if dt > bm.law.stable_limit_s:
                raise diverged_error(t, dt, bm, f"the worm ran away to {rad_s_to_rpm(abs(w1)):.0f} rpm")
            raise overspeed_error(t, w1, dt, bm)
        if code == JUMPED:
            raise jump_error(t, te / self.pitch_angle, dt, bm)
        self.friction.check(d, t, w1, w2)
        return te

    def _creeping(self, w_worm: float, w_wheel: float) -> bool:
        """The worm holds: its sliding speed below 10 transition velocities (the static friction's reach), or it follows
        the wheel at under HELD_FOLLOW_FRACTION of the ratio (the wheel's servo crushes the held mesh instead of turning
        the worm: the screw jack at mu 0.2, worm at 0.66 % of z2 / z1 times the wheel's speed when the penetration
        guard trips)."""
        geo = self.bm.geometry
        if abs(w_worm) * geo.r_m1 / math.cos(geo.gamma_m) < 10 * self.bm.plan.transition_velocity_m_s:
            return True
        return abs(w_worm) < HELD_FOLLOW_FRACTION * geo.ratio * abs(w_wheel)

    def contact(self, t: float, pen: float, w_drive: float, cmd: float, w_worm: float = 0.0) -> None:
        """Penetration beyond the limit; a speed-driven drive stuck below half its command (locked) for lock_hold.
        A wheel back-driving a self-locking pair ends the run as held (wormsim.physics.locking.Held) when it stalls, or
        when
        its servo pushes the held mesh past the penetration limit while the worm (speed w_worm) creeps."""
        code = contact_event(
            t, pen, self.pen_lim, w_drive, cmd, self.speed_driven, self.lock_start, gt.LOCK_SPEED_FRACTION
        )
        if code == PENETRATED:
            if self.self_locking_backdrive and self._creeping(w_worm, w_drive):  # the stalled wheel's servo pushed on
                raise Held(t, self.locked_since)
            raise penetration_error(t, pen, self.pen_lim, self.dt, self.bm)
        if code == STUCK:
            self.locked_since = t if self.locked_since is None else self.locked_since
            if t - self.locked_since > self.lock_hold:
                if self.self_locking_backdrive:  # the answer, not a failure (wormsim.physics.locking)
                    raise Held(t, self.locked_since)
                raise locked_error(t, w_drive, cmd, self.bm)
        elif code == RUNNING:
            self.locked_since = None
