"""Exact-flank contact with assembly errors (contact3d's `contact.geometry: flanks`): the poses of the
displaced worm and wheel, as MuJoCo places them, for the kernel (wormsim.tooth.kernel.find_contacts).

Without errors the kernel maps a wheel point of tooth k into the static worm frame by the nominal assembly: turn by
theta2 + 2 pi k / z2 about z, then (x_s, y_s, z_s) = (y + a, -zeta, -x) (meshgen.assembly). With errors the bodies sit
where meshgen.displaced (1), (2) puts them (wormsim.contact3d.mjcf._place_displaced), and each step the kernel gets
their poses from MuJoCo (d.xpos, d.xmat, after mj_fwdKinematics) appended to its scalars P:

    P[WHEEL:WHEEL + 12]   X_g, wheel body -> world (3 x 4, row-major): M_g Rz(theta2) E_g of meshgen.displaced (2)
    P[WORM:WORM + 12]     A, static worm frame -> world: X_w Rz(-theta1), X_w = M_w Rz(theta1) E_w of (1)
    P[SHIFT:SHIFT + z2]   f_k / r2, the wheel teeth's pitch deviations (rad)

Tooth k's point p (tooth 0's grid) is then w = X_g Rz(2 pi k / z2 + f_k / r2) p in the world (the contact position),
and s = A^-1 w in the static worm frame, where the closed form of meshgen.worm.thread_gap is evaluated with the
worm's hinge angle theta1: the worm body frame is A^-1 turned by -theta1, and the closed form depends on the angle
only through phi - theta1, so gap(s, theta1) = gap(body coordinates, 0), the thread on the body's axis (worm runout:
the body axis is off the hinge axis). The gradient goes back to the world by A's rotation. With zero errors
X_g = Rz(theta2) and A = Trans(0, -a, 0) R0: the nominal mapping (tests/contact3d/test_flank_errors.py: contacts within
1e-12 of the nominal path).

The kernel's candidate window (find_contacts' margin) is widened by `error_margin_rad`: the wheel points move
relative to the worm by at most delta = |da| + |dz| + e1 + e2 + (b2 / 2) |sin dS| (the worm's axial offset is a phase,
meshgen.displaced), which changes the conjugate angle of the touching point by about delta |grad c| (c the
conjugate angle over the flank grid, per metre along the flank; its 99th percentile, the largest values sit at the
grid's ragged edges). Measured on the seat motor with a 0.1 mm axial offset: 0.60 pitch; 0.37 pitch missed contacts
27 um deep (docs/errors.md, section 6).
"""

from __future__ import annotations

import math

import numba
import numpy as np

from meshgen.worm_forms_jit import TABLE_LEN

N_WORM_PARAMS = 13 + TABLE_LEN  # len(meshgen.worm.worm_params(g)): the nominal kernel's P
WHEEL = N_WORM_PARAMS  # offsets into the displaced P (module docstring)
WORM = WHEEL + 12
SHIFT = WORM + 12


def displaced_params(worm_p: np.ndarray, tooth_shift_rad: np.ndarray) -> np.ndarray:
    """The kernel's P with room for the poses (module docstring); set_pose fills them each step."""
    if worm_p.shape[0] != N_WORM_PARAMS:
        raise ValueError("wormsim.tooth.pose: worm_params changed length; update N_WORM_PARAMS")
    P = np.zeros(SHIFT + len(tooth_shift_rad))
    P[:N_WORM_PARAMS] = worm_p
    P[SHIFT:] = tooth_shift_rad
    return P


@numba.njit(cache=True)
def set_pose(P, xpos, xmat, worm_body, wheel_body, theta1):
    """Write X_g and A (module docstring) from MuJoCo's body poses into P."""
    for r in range(3):
        for c in range(3):
            P[WHEEL + 4 * r + c] = xmat[wheel_body, 3 * r + c]
        P[WHEEL + 4 * r + 3] = xpos[wheel_body, r]
    cs, sn = math.cos(theta1), math.sin(theta1)
    for r in range(3):
        r0, r1 = xmat[worm_body, 3 * r], xmat[worm_body, 3 * r + 1]
        # X_w Rz(-theta1): columns 0, 1 turned back by theta1
        P[WORM + 4 * r] = cs * r0 - sn * r1
        P[WORM + 4 * r + 1] = sn * r0 + cs * r1
        P[WORM + 4 * r + 2] = xmat[worm_body, 3 * r + 2]
        P[WORM + 4 * r + 3] = xpos[worm_body, r]


@numba.njit(cache=True, inline="always")
def tooth_angle(k, P):
    """(angle of tooth k in the wheel body frame, its pitch deviation f_k / r2)."""
    z2 = P.shape[0] - SHIFT
    dk = P[SHIFT + k % z2]
    return P[11] * k + dk, dk


@numba.njit(cache=True, inline="always")
def to_static(x, y, z, P, out):
    """Wheel body point -> world (written to out[3:6]) -> static worm frame (returned)."""
    wx = P[WHEEL] * x + P[WHEEL + 1] * y + P[WHEEL + 2] * z + P[WHEEL + 3]
    wy = P[WHEEL + 4] * x + P[WHEEL + 5] * y + P[WHEEL + 6] * z + P[WHEEL + 7]
    wz = P[WHEEL + 8] * x + P[WHEEL + 9] * y + P[WHEEL + 10] * z + P[WHEEL + 11]
    out[3], out[4], out[5] = wx, wy, wz
    dx, dy, dz = wx - P[WORM + 3], wy - P[WORM + 7], wz - P[WORM + 11]
    return (
        P[WORM] * dx + P[WORM + 4] * dy + P[WORM + 8] * dz,
        P[WORM + 1] * dx + P[WORM + 5] * dy + P[WORM + 9] * dz,
        P[WORM + 2] * dx + P[WORM + 6] * dy + P[WORM + 10] * dz,
    )


@numba.njit(cache=True, inline="always")
def static_dir_to_world(nx, ny, nz, P):
    """A direction of the static worm frame in the world (A's rotation)."""
    return (
        P[WORM] * nx + P[WORM + 1] * ny + P[WORM + 2] * nz,
        P[WORM + 4] * nx + P[WORM + 5] * ny + P[WORM + 6] * nz,
        P[WORM + 8] * nx + P[WORM + 9] * ny + P[WORM + 10] * nz,
    )


@numba.njit(cache=True, inline="always")
def to_wheel_body(wx, wy, wz, P):
    """A world point in the wheel body's frame (X_g^-1: the offset turned back by X_g's rotation, its transpose)."""
    dx, dy, dz = wx - P[WHEEL + 3], wy - P[WHEEL + 7], wz - P[WHEEL + 11]
    return (
        dx * P[WHEEL] + dy * P[WHEEL + 4] + dz * P[WHEEL + 8],
        dx * P[WHEEL + 1] + dy * P[WHEEL + 5] + dz * P[WHEEL + 9],
        dx * P[WHEEL + 2] + dy * P[WHEEL + 6] + dz * P[WHEEL + 10],
    )


def error_margin_rad(g, grid, dev, quantile: float = 0.99) -> float:
    """The candidate window's widening for the errors dev (module docstring), rad of wheel angle. |grad c| on the
    flank in (zeta, rho) by differences on the grid (d/drho along the profile; d/dzeta across the slices at fixed
    rho, with the profile's own slope taken out), its `quantile` over the active points (the largest values sit at
    the grid's ragged edges, where the differences straddle a fold)."""
    delta = (
        abs(dev.center_distance)
        + abs(dev.wheel_axial_offset)
        + abs(dev.worm_runout)
        + abs(dev.wheel_runout)
        + 0.5 * g.face_width * abs(math.sin(dev.shaft_angle))
    )
    if delta == 0.0 or grid.slices < 2:
        return 0.0 if delta == 0.0 else delta * 2 * math.pi / g.z2 / g.face_width
    vals = []
    with np.errstate(all="ignore"):
        d_rho_i = np.gradient(grid.rho, axis=1)
        d_rho_j = np.gradient(grid.rho, axis=0)
        d_zeta = np.gradient(grid.zeta)[:, None]
        for s in range(2):
            c = grid.c[s]
            c_rho = np.gradient(c, axis=1) / d_rho_i
            c_zeta = (np.gradient(c, axis=0) - c_rho * d_rho_j) / d_zeta
            gm = np.hypot(c_rho, c_zeta)
            vals.append(gm[np.isfinite(gm)])
    v = np.concatenate(vals)
    return delta * float(np.quantile(v, quantile)) if v.size else 0.0
