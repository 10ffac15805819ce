"""Wheel tooth flanks generated as the envelope of the worm (hob) thread in the relative motion.

Frames (meshgen.assembly): wheel frame = assembly frame rotated by theta2 about z; the worm axis runs along
the assembly x axis at y = -a, z = 0, worm frame z = assembly -x. A wheel-frame point in cylindrical
coordinates (rho, psi, zeta) (radius, polar angle, axial) sits, at wheel angle theta2, at assembly polar
angle beta = psi + theta2; in the static worm frame it is

    x_s = a + rho sin(beta),   y_s = -zeta,   z_s = -rho cos(beta)
    r_s = sqrt(x_s^2 + y_s^2),  phi_s = atan2(y_s, x_s)

and with theta1 = (beta - psi) / (hand z1/z2) its thread coordinate (worm.py equation (1)) is
u = z_s - p (phi_s - theta1) = -rho cos(beta) - p phi_s + r2 (beta - psi), because p / (hand z1 / z2) = r2.

Hob generation (the way a hob with the worm's flanks, extended to the wheel root torus radius
R_r = a - r_f2, cuts the wheel): the tooth space 0 (centred on psi = -pi/2) is swept by thread 0,
so at a given (rho, zeta) the space spans [psi_-, psi_+] with

    psi_+(rho, zeta) = max_beta F_+(beta) / r2,   F_+ = r2 beta - rho cos(beta) - p phi_s + H(r_s)
    psi_-(rho, zeta) = min_beta F_-(beta) / r2,   F_- = r2 beta - rho cos(beta) - p phi_s - H(r_s)     (3)

over the worm angles at which the point is within the hob's reach, r_s(beta) <= R_r.
dF/dbeta = 0 at an interior extremum IS the equation of meshing n . v12 = 0 (the contact line at
worm angle theta1 is the set of wheel points where it holds; (3) is the envelope). Where the extremum
lies at the reach limit r_s = R_r the flank is cut by the hob tip edge (root fillet, not conjugate).
Sources: Litvin & Fuentes, Gear Geometry and Applied Theory, 2nd ed., ch. 6 (envelope, equation of
meshing) and ch. 19 (worm gear drives); seed 003 (coordinate transformation of the helicoid).

Backlash j: each wheel flank is moved into the tooth by j / (2 r2) in angle (circumferential j/2 at d2).
Blank: wheel tip (throat) rho <= a - sqrt((a - r_a2)^2 - zeta^2) capped at the rim radius r_e2,
root rho >= a - sqrt(R_r^2 - zeta^2), |zeta| <= b2 / 2.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from meshgen import worm
from meshgen.geometry import GearGeometry, GeometryError


def hob_radius(g: GearGeometry) -> float:
    """Hob tip radius = wheel root torus tube radius a - r_f2 = r1 + h_f."""
    return g.root_torus_radius


def tip_rho(g: GearGeometry, zeta):
    """Wheel tip radius at axial position zeta: throat torus, capped at the rim radius r_e2."""
    zeta = np.asarray(zeta, float)
    R = g.throat_radius
    inside = R * R - zeta * zeta
    throat = g.a - np.sqrt(np.maximum(inside, 0.0))
    return np.where(inside > 0, np.minimum(throat, g.r_e2), g.r_e2)


def root_rho(g: GearGeometry, zeta):
    """Wheel root radius at zeta: root torus about the worm axis, tube radius R_r = a - r_f2."""
    zeta = np.asarray(zeta, float)
    R = g.root_torus_radius
    return g.a - np.sqrt(np.maximum(R * R - zeta * zeta, 0.0))


def _F(g: GearGeometry, rho, zeta, beta, side):
    xs = g.a + rho * np.sin(beta)
    rs = np.sqrt(xs * xs + zeta * zeta)
    phis = np.arctan2(-zeta, xs)
    return g.r2 * beta - rho * np.cos(beta) - g.p * phis + side * worm.half_thickness(g, rs)


NEWTON_DROP_M = 1e-12  # a Newton step that lowers sgn F by more than this is taken back (_newton_max)
NEWTON_RETRIES = 24  # further steps for the points where one was taken back


def _newton_max(g: GearGeometry, rho, zeta, beta, side, box, n_newton: int):
    """Newton on dF/dbeta = 0 (central differences) from the grid's best beta, each step at most one grid step
    (box = (lo, hi, that step)), kept in [lo, hi]; returns beta. Safeguarded: a step that lowers sgn F by more than
    NEWTON_DROP_M is taken back and the point's later steps are halved, and such a point gets NEWTON_RETRIES more
    steps. Near the envelope's limit line (high lead angles, near the wheel tip) the maximum is flat and lopsided
    (F'' small, F''' not), where a plain Newton step overshoots by a grid step and the next comes back; the safeguard
    keeps the better point (docs/decisions/0056-envelope-maximum-safeguarded-newton.md). Where no step is taken back
    the iteration is the plain Newton one."""
    lo, hi, dmax = (np.broadcast_to(a, np.shape(beta)) for a in box)
    rho, zeta = np.broadcast_to(rho, np.shape(beta)), np.broadcast_to(zeta, np.shape(beta))
    sgn = float(side)
    h = 1e-5
    out = beta
    sub = np.arange(np.size(beta))
    lam = np.ones(np.shape(beta))
    for it in range(n_newton + NEWTON_RETRIES):
        if it == n_newton:  # the retries: only the points where a step was taken back
            out = beta.copy()
            keep = np.nonzero(lam < 1.0)[0]
            if not len(keep):
                return out
            sub, beta, lam = sub[keep], beta[keep], lam[keep]
            rho, zeta, lo, hi, dmax = rho[keep], zeta[keep], lo[keep], hi[keep], dmax[keep]
        f0 = sgn * _F(g, rho, zeta, beta, side)
        fp = sgn * _F(g, rho, zeta, beta + h, side)
        fm = sgn * _F(g, rho, zeta, beta - h, side)
        d1 = (fp - fm) / (2 * h)
        d2 = (fp - 2 * f0 + fm) / (h * h)
        step = np.where(d2 < 0, -d1 / np.where(d2 < 0, d2, -1.0), 0.0)
        step = lam * np.clip(step, -dmax, dmax)
        cand = np.clip(beta + step, lo, hi)
        drop = sgn * _F(g, rho, zeta, cand, side) < f0 - NEWTON_DROP_M
        beta = np.where(drop, beta, cand)
        lam = np.where(drop, 0.5 * lam, lam)
    out[sub] = beta
    return out


def _beta_range(g: GearGeometry, rho, zeta):
    """Half-width delta of the beta interval -pi/2 +- delta where r_s(beta) <= R_r (hob reach)."""
    R = hob_radius(g)
    s0 = (np.sqrt(np.maximum(R * R - zeta * zeta, 0.0)) - g.a) / rho
    return np.arccos(np.clip(-s0, -1.0, 1.0))


@dataclass
class FlankSolution:
    psi: np.ndarray  # flank polar angle (space 0), rad
    beta: np.ndarray  # assembly polar angle of the contact (worm angle via beta - psi), rad
    interior: np.ndarray  # True where an interior extremum (conjugate contact), False: cut by the hob tip edge


def space_flank(g: GearGeometry, rho, zeta, side: int, n_grid: int = 48, n_newton: int = 8) -> FlankSolution:
    """psi_side(rho, zeta) of tooth space 0 by equation (3); side +1 -> psi_+, -1 -> psi_-.

    Vectorised: a grid search over beta in the reach interval, then Newton on dF/dbeta = 0 with
    central differences (safeguarded: _newton_max), kept inside the interval; the endpoints compete as candidates.
    """
    rho, zeta = np.broadcast_arrays(np.asarray(rho, float), np.asarray(zeta, float))
    shape = rho.shape
    rho, zeta = rho.ravel(), zeta.ravel()
    sgn = float(side)  # maximise sgn * F
    delta = _beta_range(g, rho, zeta)
    lo, hi = -math.pi / 2 - delta, -math.pi / 2 + delta
    s = np.linspace(0.0, 1.0, n_grid)
    B = lo[:, None] + (hi - lo)[:, None] * s[None, :]
    V = sgn * _F(g, rho[:, None], zeta[:, None], B, side)
    k = np.argmax(V, axis=1)
    idx = np.arange(len(rho))
    beta = B[idx, k]
    beta = _newton_max(g, rho, zeta, beta, side, (lo, hi, (hi - lo) / n_grid), n_newton)
    vb = sgn * _F(g, rho, zeta, beta, side)
    vlo = sgn * _F(g, rho, zeta, lo, side)
    vhi = sgn * _F(g, rho, zeta, hi, side)
    best = np.maximum(vb, np.maximum(vlo, vhi))
    interior = (vb >= best) & (beta > lo + 1e-9) & (beta < hi - 1e-9)
    beta = np.where(interior, beta, np.where(vlo >= vhi, lo, hi))
    psi = sgn * best / g.r2
    return FlankSolution(psi.reshape(shape), beta.reshape(shape), interior.reshape(shape))


def tooth_flanks(g: GearGeometry, rho, zeta, which: str = "ab"):
    """Flank angles of wheel tooth 0 (between space 0 and space 1), backlash applied.

    Returns (psi_a, psi_b): psi_a = psi_+ of space 0 + j/(2 r2) (flank facing -psi), psi_b = psi_- of space 0
    + 2 pi / z2 - j/(2 r2). By the tooth symmetry psi_b(rho, zeta) = -pi + 2 pi/z2 - psi_a(rho, -zeta).
    """
    dj = g.backlash / (2 * g.r2)
    a = space_flank(g, rho, zeta, +1).psi + dj if "a" in which else None
    b = space_flank(g, rho, zeta, -1).psi + 2 * math.pi / g.z2 - dj if "b" in which else None
    return a, b


def tooth_angle(g: GearGeometry, k: int) -> float:
    """Polar angle of tooth k's centre line in the wheel frame: -pi/2 + (2k + 1) pi / z2."""
    return -math.pi / 2 + (2 * k + 1) * math.pi / g.z2


def check_wheel(g: GearGeometry, n: int = 25) -> None:
    """Pointed wheel tooth or undercut -> GeometryError.

    Pointed: tooth thickness at the tip (throat, anywhere across the face) below 0.05 m_x.
    Undercut: on the mid-plane, the hob tip edge (not the conjugate flank) cuts the flank above the
    reach of the worm tip, rho > r2 + x2 m_x - h_a + 0.05 m_x, i.e. into the working depth.
    """
    zeta = np.linspace(-g.face_width / 2, g.face_width / 2, n)
    rt = tip_rho(g, zeta)
    a, b = tooth_flanks(g, rt, zeta)
    s_tip = float(np.min((b - a) * rt))
    if s_tip < 0.05 * g.m_x:
        raise GeometryError(
            f"gear: the wheel tooth is pointed (tip thickness {s_tip * 1e3:.4f} mm, minimum 0.05 m_x); "
            f"lower gear.normal_pressure_angle_deg or gear.backlash_mm, or raise gear.wheel_teeth"
        )
    frac = undercut_fraction(g, n)
    if frac > UNDERCUT_LIMIT:
        raise GeometryError(
            f"gear: the wheel teeth are undercut: on the mid-plane the hob tip edge removes {100 * frac:.0f} % of "
            f"the working flank below the reference circle (limit {100 * UNDERCUT_LIMIT:.0f} %); raise "
            f"gear.normal_pressure_angle_deg (now {math.degrees(g.alpha_n):.2f}) or gear.wheel_teeth (now {g.z2})"
            + (f", or gear.profile_radius_mm (now {g.profile_radius * 1e3:.4g})" if g.profile == "ZC" else "")
            + f", or gear.profile_shift_coefficient (now {g.x2:g})"
        )


UNDERCUT_LIMIT = 0.6


def undercut_fraction(g: GearGeometry, n: int = 41) -> float:
    """Undercut on the mid-plane: fraction of the working depth below the worm's reference line, from the worm tip's
    reach a - r_a1 = r2 + x2 m_x - h_a up to a - r1 = r2 + x2 m_x (r2 - h_a .. r2 unshifted), where the flank is cut
    by the hob tip edge instead of being the conjugate envelope (0: none).

    Classical rack theory (z2 < 2 (h_f - x2 m_x) / sin^2(alpha) undercuts: a positive profile shift x2 moves the
    hob's reference line out and lifts the undercut out of the working depth) in the worm's mid-plane; the generated
    tooth never interferes with the worm, but an undercut flank loses its conjugate contact there.
    """
    lo = g.r2 + g.shift - g.h_a  # r2 - h_a bit for bit when x2 = 0
    rho = np.linspace(lo, g.r2 + g.shift, n)
    sol = space_flank(g, rho, np.zeros_like(rho), +1)
    if np.all(sol.interior):
        return 0.0
    top = rho[~sol.interior].max()
    return float((top - lo) / g.h_a)
