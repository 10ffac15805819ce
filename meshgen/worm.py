"""Worm thread surfaces (ZI involute helicoid, ZA straight axial profile; ZN, ZK, ZC by their axial profile from
meshgen.worm_forms), in the WORM frame.

Worm frame: axis +z, origin on the axis at mid-length; at worm angle 0 a thread is centred on
phi = 0 (the +x axis, which points at the wheel centre in the assembly, see `meshgen.assembly`) at z = 0.

Every cylindrical worm flank is a helicoid of helix parameter p (signed by hand, p = lead / 2 pi),
so it is fully described by its AXIAL profile. In cylindrical coordinates (r, phi, z) the thread of
start n occupies

    | wrap(z - p phi - n p_x) | <= H(r)          wrap to (-p_x/2, p_x/2]          (1)

with H(r) the axial half-thickness of the thread at radius r: H(r1) = p_x / 4 (thread thickness p_x/2 on d1).
The two flanks are z - p phi - n p_x = +H(r) and = -H(r).

ZA (DIN 3975, straight-sided axial profile, axial pressure angle alpha_x, tan alpha_x = tan alpha_n / cos gamma):

    H(r) = p_x/4 - (r - r1) tan(alpha_x)

ZI (involute helicoid, seed 003): x = r_b cos(theta+t) + r_b t sin(theta+t), y = r_b sin(theta+t) - r_b t cos(theta+t),
z = p theta. Its point has radius r = r_b sqrt(1 + t^2) and polar angle phi = theta + t - atan(t), so
z - p phi = p (atan t - t): the axial profile of the involute helicoid is (for the flank whose thickness falls with r)

    H(r) = p_x/4 - |p| [(t - atan t) - (t1 - atan t1)],  t = sqrt(r^2/r_b^2 - 1),  t1 = t(r1)        (2)

and the opposite flank is the involute helicoid unwound the other way (t -> -t), i.e. the mirror profile -H(r).
The base radius follows from tan(gamma_b) = |p| / r_b, cos(gamma_b) = cos(gamma) cos(alpha_n) (meshgen.geometry).
Below the base cylinder (r < r_b) the involute helicoid does not exist: there the flank is continued as the
radial-line helicoid H(r) = H(r_b) (dH/dr = 0 at r_b, so the continuation is C1). For every seed gear r_b < r_f1.

Normal of a flank z - p phi - s H(r) = const (s = +-1): grad = (-s H'(r)) e_r + (-p / r) e_phi + e_z, so the
normal pressure angle at radius r is sin(alpha_n) = |n . e_r| = |H'| / sqrt(H'^2 + (p/r)^2 + 1).
"""

from __future__ import annotations

import functools
import math

import numpy as np

from meshgen import worm_forms, worm_forms_jit
from meshgen.geometry import GearGeometry, GeometryError


@functools.lru_cache(maxsize=64)
def worm_params(g: GearGeometry) -> np.ndarray:
    """Scalars of the closed form (1), (2), in the order the compiled H(r) (meshgen.worm_forms_jit) and the contact
    kernel (wormsim.tooth.gap) read them; read-only (cached per gear)."""
    J = worm_forms_jit
    form = J.ZI if g.profile == "ZI" else J.TABLE if g.profile in worm_forms.TABLE_FORMS else J.ZA
    t1 = math.sqrt(max(g.r1**2 / g.r_b**2 - 1.0, 0.0)) if form == J.ZI else 0.0
    table = worm_forms.form_table(g).params() if form == J.TABLE else np.zeros(J.TABLE_LEN)
    head = np.array(
        [
            g.p,
            g.p_x,
            g.r_f1,
            g.r_a1,
            g.worm_length / 2,
            form,
            g.r_b,
            math.tan(g.alpha_x),
            t1 - math.atan(t1),
            g.r1,
            g.a,
            2 * math.pi / g.z2,
            g.hand * g.z1 / g.z2,
        ],
        dtype=float,
    )
    P = np.concatenate([head, table])  # ZN, ZK, ZC: H(r)'s table at P[TABLE_AT:]
    P.flags.writeable = False
    return P


def _t_of_r(g: GearGeometry, r):
    return worm_forms_jit.zi_t(np.asarray(r, dtype=float), g.r_b)


def half_thickness(g: GearGeometry, r):
    """H(r): axial half-thickness of the thread at radius r, m: equations (1), (2) above, written once in
    meshgen.worm_forms_jit (ZA, ZI: evaluated here on numpy arrays, compiled in the contact kernel; ZN, ZK, ZC: the
    table's compiled evaluation)."""
    r = np.asarray(r, dtype=float)
    if g.profile in worm_forms.TABLE_FORMS:
        H = worm_forms.form_table(g).half_thickness(r)
        return H[()] if r.ndim == 0 else H
    if g.profile == "ZA":
        return worm_forms_jit.za_half_thickness(r, g.p_x, g.r1, math.tan(g.alpha_x))
    t1 = float(_t_of_r(g, g.r1))
    return worm_forms_jit.zi_half_thickness(_t_of_r(g, r), abs(g.p), g.p_x, t1 - math.atan(t1))


def half_thickness_dr(g: GearGeometry, r):
    """dH/dr: ZA -tan(alpha_x); ZI -|p| t / r (0 below r_b); ZN, ZK, ZC: the table (as half_thickness)."""
    r = np.asarray(r, dtype=float)
    if g.profile in worm_forms.TABLE_FORMS:
        dH = worm_forms.form_table(g).half_thickness_dr(r)
        return dH[()] if r.ndim == 0 else dH
    if g.profile == "ZA":
        return np.full_like(r, -math.tan(g.alpha_x))
    return -abs(g.p) * _t_of_r(g, r) / r


def wrap(u, period):
    """Wrap to [-period/2, period/2)."""
    return (np.asarray(u) + period / 2) % period - period / 2


def thread_gap(g: GearGeometry, pts, theta1: float = 0.0):
    """Signed normal distance (first order) of worm-frame points from the thread surface, m.

    Positive outside the thread material (between threads), negative inside a thread, for points with
    r_f1 <= r <= r_a1 (callers restrict). G = |wrap(z - p (phi - theta1))| - H(r), normalised by
    |grad G| = sqrt(1 + (p/r)^2 + H'(r)^2) (equation (1); theta1 = worm rotation angle).
    """
    pts = np.asarray(pts, dtype=float)
    r = np.hypot(pts[..., 0], pts[..., 1])
    phi = np.arctan2(pts[..., 1], pts[..., 0])
    u = wrap(pts[..., 2] - g.p * (phi - theta1), g.p_x)
    G = np.abs(u) - half_thickness(g, r)
    return G / np.sqrt(1.0 + (g.p / r) ** 2 + half_thickness_dr(g, r) ** 2)


def flank_points(g: GearGeometry, r, phi, side: int, start: int = 0):
    """Exact flank points: z = p phi + n p_x + side H(r); r, phi broadcast; returns (..., 3)."""
    r, phi = np.broadcast_arrays(np.asarray(r, float), np.asarray(phi, float))
    z = g.p * phi + start * g.p_x + side * half_thickness(g, r)
    return np.stack([r * np.cos(phi), r * np.sin(phi), z], axis=-1)


def check_worm(g: GearGeometry, hob_tip_radius: float) -> None:
    """Pointed worm (or hob) thread -> GeometryError. The hob reaches the wheel root torus radius."""
    for name, r in (("worm tip", g.r_a1), ("hob tip (wheel root)", hob_tip_radius)):
        s = 2 * float(half_thickness(g, r))
        if s < 0.05 * g.m_x:
            raise GeometryError(
                f"gear: the worm thread is pointed at the {name} (thickness {s * 1e3:.4f} mm); lower "
                f"gear.normal_pressure_angle_deg (now {math.degrees(g.alpha_n):.2f}) or gear.dedendum_coef / "
                f"gear.addendum_coef"
            )
    if g.profile == "ZI" and g.r_b > g.r_f1:
        # allowed: flank continued radially below r_b (module docstring); nothing to do
        pass


def ridge_profile(g: GearGeometry, n_flank: int, r_in: float, r_out: float | None = None):
    """Closed axial profile (r, u) of one thread ridge, counter-clockwise in the (r, u) plane.

    From (r_in, -H(r_in)) up the -flank to the tip, across the tip, down the +flank to (r_in, +H(r_in)).
    r_in below the root (the ridge overlaps the core cylinder). Returns (m, 2).
    """
    r_out = g.r_a1 if r_out is None else r_out
    r = np.linspace(r_in, r_out, n_flank)
    H = half_thickness(g, r)
    left = np.stack([r, -H], axis=1)
    right = np.stack([r[::-1], H[::-1]], axis=1)
    return np.concatenate([left, right])
