"""The run's time series: their names in row order (SERIES, the layout of the series array), the per-step sums of a
record interval (SUMS, `add_step`) and one sample's column (`column`), each compiled once and called by the Python
paths (wormsim.contact3d.runner, the pieces' steps in wormsim.contact3d.sources) and by the compiled ones
(wormsim.contact3d.flank_loop, wormsim.contact3d.flank_samples) alike.

The interval's mean resultant on the wheel is resolved at the pitch point P = (0, -r2, 0) on the line of centres, in
the wheel's directions there (DIN 3975 F_t2, F_r2, F_a2; seed 001 resolves ADAMS's contact force the same way):
tangential e_t = +x, radial e_r = -y (outward, towards the worm), axial e_z. The contact torque M_z is kept apart:
M_z / r2 equals the mean F_t, but by the wheel's torque balance it varies only through I2 alpha2 and hides the mesh."""

from __future__ import annotations

import numba

SERIES = (
    "t_s",
    "worm_angle_rad",
    "wheel_angle_rad",
    "worm_speed_rpm",
    "wheel_speed_rpm",
    "worm_torque_nm",
    "wheel_torque_nm",
    "drive_command",
    "tangential_force_n",
    "radial_force_n",
    "axial_force_n",
    "contacts",
    "teeth_in_contact",
    "max_penetration_m",
    "friction_coefficient",
    "transmission_error_rad",
    "wheel_contact_torque_nm",
    "worm_power_w",
    "wheel_power_w",
    "tangential_force_abs_max_n",
    "radial_force_line_of_centres_n",
    "worm_contact_radius_m",
    "efficiency_theory_at_contact_radius",
)


# the per-step sums of a record interval, in the order of the sums array (add_step) and of column's `sums`
SUMS = ("worm_torque", "wheel_torque", "worm_power", "wheel_power", "contacts", "f_x", "f_y", "f_z", "m_z", "f_x_peak")
N_SUMS = len(SUMS)


@numba.njit(cache=True, inline="always")
def add_step(sums, act, sd, a1, a2, s0, w1, w2):
    """The interval's sums (SUMS order; all 0.0 at its start) with one step added: the worm's and the wheel's
    actuator torques act[a1], act[a2] and powers T w with the speeds w1, w2 read before the step, the contact
    sensor's count, resultant F on the wheel (global frame) and its moment about the wheel axis M_z = tau_z + p_x F_y
    - p_y F_x (sensordata from s0: found, F (3), torque about the point (3), point (3)), and the peak |F_x| (the
    start-up impact is shorter than an interval). A tuple in and out: the compiled loop keeps it in registers."""
    t1, t2, p1, p2, nc, fx, fy, fz, mz, fpk = sums
    q1, q2 = act[a1], act[a2]
    f0, f1, f2 = sd[s0 + 1], sd[s0 + 2], sd[s0 + 3]
    if abs(f0) > fpk:
        fpk = abs(f0)
    mz += sd[s0 + 6] + sd[s0 + 7] * f1 - sd[s0 + 8] * f0
    return t1 + q1, t2 + q2, p1 + q1 * w1, p2 + q2 * w2, nc + sd[s0], fx + f0, fy + f1, fz + f2, mz, fpk


ZERO_SUMS = (0.0,) * N_SUMS  # the sums at an interval's start


@numba.njit(cache=True)
def column(state, sums, rec, contact, rpm):
    """One sample's column in SERIES order: the state at the interval's end, state = (t, th1, th2, w1, w2, cmd), the
    interval's per-step sums (SUMS order: T1, T2, P1, P2, contacts, F_x, F_y, F_z, M_z, |F_x| peak) over its rec
    steps as means, and the sample's contact outputs, contact = (teeth in contact, max penetration, mu, TE, radial
    force on the line of centres, contact radius); rpm = (rad/s) per rpm. The efficiency at the contact radius is
    filled after the run."""
    t, th1, th2, w1, w2, cmd = state
    nteeth, pen, mu, te, fr_lc, r_c = contact
    t1, t2, p1, p2, nc, fx, fy, fz, mz, fpk = sums
    return (
        t,  # t_s
        th1,  # worm_angle_rad
        th2,  # wheel_angle_rad
        w1 / rpm,  # worm_speed_rpm
        w2 / rpm,  # wheel_speed_rpm
        t1 / rec,  # worm_torque_nm
        t2 / rec,  # wheel_torque_nm
        cmd,  # drive_command
        fx / rec,  # tangential_force_n
        -fy / rec,  # radial_force_n
        fz / rec,  # axial_force_n
        nc / rec,  # contacts
        float(nteeth),  # teeth_in_contact
        pen,  # max_penetration_m
        mu,  # friction_coefficient
        te,  # transmission_error_rad
        mz / rec,  # wheel_contact_torque_nm
        p1 / rec,  # worm_power_w
        p2 / rec,  # wheel_power_w
        fpk,  # tangential_force_abs_max_n
        fr_lc,  # radial_force_line_of_centres_n
        r_c,  # worm_contact_radius_m
        0.0,  # efficiency_theory_at_contact_radius
    )
