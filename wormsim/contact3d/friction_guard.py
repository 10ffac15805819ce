"""contact3d's friction guard: sliding contacts whose friction does not oppose their slip (docs/contact3d.md,
"Friction against the slip").

On MuJoCo's elliptic cone a sliding contact's friction force points along -(J_t qacc - a_ref_t), the tangential
part of the constraint's "jar" (engine_core_constraint.c, the cone's middle zone; wormsim.contact3d.law), with the
friction rows' reference acceleration a_ref_t = -b_f v_t. Coulomb's friction opposes the slip v_t only while
|b_f v_t| dominates the contact's tangential acceleration |J_t qacc|. The flank contacts' friction rows have a
small damping c_f, law (4), sized at the working load's normal force; far above that load (a self-locking pair
back-driven by a stiff speed servo: mesh force 1e4 x the nominal) |J_t qacc| exceeds |b_f v_t| and the friction
turns towards the contacts' acceleration. Measured (screw jack, wheel speed-driven at 55 rpm, mu 0.2, coarse
flanks): |a_ref_t| 120 m/s^2 against |J_t qacc| 130-300 m/s^2, cos(f_t, -v_t) 0.27-0.31 (median over the contacts)
on contacts on the cone (|f_t| = mu f_n), so the worm's friction torque fell to the normal forces' driving torque
and the self-locking worm was back-driven at 700-900 rpm; with c_f = c_c (the pieces' value) the cosine is 0.98.

The guard: after the ramps, the friction-weighted mean of cos(f_t, -v_t) over the contacts that slide (on the
cone, slip faster than contact.transition_velocity_m_s, above which law (3) makes friction Coulomb's) must stay at or
above ALIGN_MIN; below it for HOLD_S the run stops (SimulationError; where a speed-driven wheel drives a pair that
is self-locking, the cause of the overload, the run ends held instead: wormsim.physics.locking). Valid runs measured at
1.000 (screw jack, seat demo, involute_41 forward; the back-driven screw jack at mu 0.02).
"""

from __future__ import annotations

import math

import mujoco
import numba

from wormsim.contact3d.diagnosis import locked_error
from wormsim.exceptions import SimulationError
from wormsim.physics.locking import Held
from wormsim.physics.units import rad_s_to_rpm, rpm_to_rad_s

ALIGN_MIN = 0.5  # friction-weighted cos(f_t, -v_t) of the sliding contacts below this ...
HOLD_S = 0.02  # ... for this long (start-up transients measured: under 6 ms of misalignment, seat demo)
ON_CONE = 0.99  # |f_t| >= ON_CONE mu f_n: the contact slides (on the friction cone)
CHECK_EVERY_S = HOLD_S / 40  # the contacts are read at most this often (a sample can be a single step)


def friction_alignment(d: mujoco.MjData, v_min: float) -> tuple[float, float, float]:
    """(friction-weighted mean of cos(f_t, -v_t) over the contacts on the cone that slip faster than v_min, their
    friction force sum (N), the normal force sum of all contacts (N)); cosine 1 where none slides. Elliptic-cone rows:
    normal, tangent 1, tangent 2 (efc_force the forces, efc_vel = J qvel the velocities, in the contact frame)."""
    n = d.ncon
    if n == 0:
        return 1.0, 0.0, 0.0
    con = d.contact
    return _alignment(con.efc_address, con.dim, con.friction, d.efc_force, d.efc_vel, v_min)


@numba.njit(cache=True, error_model="numpy")
def _alignment(adr, dim, friction, f, v, v_min):
    """friction_alignment over the contacts' rows, compiled (a numpy version cost ~150 us per call, 0.3 s per
    seat-motor 20 s run)."""
    return alignment_rows(adr, dim, friction[:, 0], f, v, v_min)


@numba.njit(cache=True, error_model="numpy")
def alignment_rows(adr, dim, mu, f, v, v_min):
    """friction_alignment of contacts with efc addresses adr, dimensions dim and friction coefficients mu (the
    compiled samples read them from d: wormsim.contact3d.flank_samples). |f_t| cos = -(f_t . v_t) / |v_t|, summed and
    divided by the summed |f_t|."""
    proj = fs = fn_sum = 0.0
    rows = sliding = 0
    for k in range(adr.size):
        a = adr[k]
        if a < 0 or dim[k] < 3:
            continue
        rows += 1
        fn, f1, f2, v1, v2 = f[a], f[a + 1], f[a + 2], v[a + 1], v[a + 2]
        fn_sum += fn
        ft, vt = math.hypot(f1, f2), math.hypot(v1, v2)
        if vt > v_min and fn > 0 and ft >= ON_CONE * mu[k] * fn:
            sliding += 1
            proj -= (f1 * v1 + f2 * v2) / vt
            fs += ft
    if rows == 0:
        return 1.0, 0.0, 0.0
    if sliding == 0:
        return 1.0, 0.0, fn_sum
    return proj / fs, fs, fn_sum


class FrictionGuard:
    """The check of the module docstring, one call per sample."""

    def __init__(self, bm, rec_interval_s: float):
        """bm.plan: the ramps' end, the transition velocity, the working load's normal force, the self-locking
        back-drive and what the error's message quotes (friction_error)."""
        plan = bm.plan
        self.bm = bm
        self.start = plan.ramps_end_s
        self.hold = max(HOLD_S, 5 * rec_interval_s)
        self.v_min = plan.transition_velocity_m_s
        self.f_nominal = plan.normal_force_n
        self.since: float | None = None
        self.next_check = self.start

    def check(self, d: mujoco.MjData, t: float, w1: float, w2: float) -> None:
        if t <= self.next_check:
            return
        self.next_check = t + CHECK_EVERY_S
        cos, _, fn = friction_alignment(d, self.v_min)
        if cos >= ALIGN_MIN:
            self.since = None
            return
        self.since = t if self.since is None else self.since
        if t - self.since > self.hold:
            if self.bm.plan.gear.backdrive_self_locks:  # the held mesh's overload (wormsim.physics.locking)
                raise Held(t, self.since)
            raise friction_error(t, cos, fn, w1, w2, self.f_nominal, self.bm, self.hold)


def friction_error(
    t: float, cos: float, fn: float, w1: float, w2: float, f_nominal: float, bm, hold_s: float = HOLD_S
) -> SimulationError:
    """Friction against the slip: where the wheel drives a pair that is self-locking at standstill, the drive is
    locked (wormsim.contact3d.diagnosis.locked_error's diagnosis, with what was measured); otherwise the load is
    beyond what the friction rows were sized for."""
    geo = bm.geometry
    law = bm.law
    ratio = fn / f_nominal if f_nominal > 0 else math.inf
    what = (
        f"the sliding contacts' friction no longer opposes the slip (friction-weighted cos(f_t, -v_t) = "
        f"{cos:.2f} < {ALIGN_MIN} for {hold_s * 1e3:.3g} ms) at a mesh normal force of {fn / 1e3:.4g} kN, "
        f"{ratio:.3g} x the {f_nominal:.4g} N of the working load that the friction rows' damping "
        f"c_f = {law.friction_damping:.3g} N s/m was sized for (wormsim.contact3d.law (4)); the worm turns at "
        f"{rad_s_to_rpm(w1):.4g} rpm, the wheel at {rad_s_to_rpm(w2):.4g} rpm"
    )
    drv = bm.plan.duty.drive
    if drv.on == "wheel" and drv.speed_rpm is not None:
        if bm.plan.gear.rho_static_rad >= geo.gamma_m:
            err = locked_error(t, w2, rpm_to_rad_s(drv.speed_rpm), bm)
            return type(err)(f"{err} (caught by the friction guard: {what}; the back-driving is not physical)")
    pieces = " or run contact.geometry=pieces (friction rows with c_f = c_c)" if law.friction_damping_n_s_per_m else ""
    return SimulationError(
        f"friction out of range at t = {t:.4g} s: {what}; set load.torque_nm to the working load{pieces}"
    )
