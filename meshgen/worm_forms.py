"""Axial profiles of the ZN, ZK and ZC worm flanks from their manufacturing kinematics (DIN 3975 / ISO/TR 10828).

Every cylindrical worm flank is a helicoid (meshgen.worm, equation (1)): a screw motion of helix parameter p about
the worm axis carries it into itself, so the flank is fully described by its axial profile, the half-thickness H(r)
of the thread in u = z - p phi. The flank forms differ only in H(r). A tool (a straight cutting edge, or a disc
turning about its own axis) generates the flank as the worm screws past it; u is invariant under that screw motion,
so the region the tool removes is the image of the tool in the (r, u) plane, and the flank is the boundary of that
image (Litvin & Fuentes, Gear Geometry and Applied Theory, 2nd ed., 2004, ch. 19 "Worm-gear drives with cylindrical
worms": 19.4 ZN, 19.6 ZK, 19.7-19.8 ZC/Flender worms; DIN 3975-1 for the names).

Frame (the worm frame of meshgen.worm): axis +z; the reference cylinder r1; on it the thread (or space) centre line
is the helix through (r1, 0, 0) with unit tangent t = (0, r1, |p|) / L, L = sqrt(r1^2 + |p|^2) (lead angle gamma:
tan gamma = |p| / r1). H does not depend on the hand (a left-hand worm is the mirror image), so |p| is used. The
plane through the x axis normal to t is the normal section; its in-plane unit vector across the thread is
n2 = (0, -s, c), s = sin gamma = |p| / L, c = cos gamma = r1 / L. A point X = x e_x + sigma n2 of that plane has

    r = sqrt(x^2 + sigma^2 s^2),   u = sigma c + |p| atan(sigma s / x)                                         (1)

ZN (straight in the normal section, DIN 3975 "ZN"; Litvin 19.4): the cutting edge is the straight line of the normal
section at the normal pressure angle alpha_n,

    ZN1 (thread):  sigma(x) = sigma_0 - (x - r1) tan(alpha_n),  H(r) = u                                           (2)
    ZN2 (space):   sigma(x) = sigma_0 + (x - r1) tan(alpha_n),  H(r) = p_x / 2 - u   (the line in the space's section)

with x from r by (1) (Newton). The flank is the helicoid swept by the line, so its normal section through the line
is the line itself.

ZK and ZC (Litvin 19.6, 19.8): a disc (milling cutter or grinding wheel) of radius R_t = tool_diameter / 2 at the
pitch point turns about its axis; the disc's mid-plane is the normal section (it contains e_x and t), the axis is
A = n2 = (0, -s, c) through the centre C = (r1 + R_t, 0, 0) (the space centre at u = 0). A point of the tool's surface
at tool radius rho and angle theta about A is

    X(rho, theta) = C + W_t(rho) A + rho (cos theta (-e_x) + sin theta (A x (-e_x))),   A x (-e_x) = (0, -c, -s)  (3)

with the tool's half-thickness W_t (its axial profile):

    ZK: straight-sided, W_t(rho) = w_0 - (rho - R_t) tan(alpha_n)                      (double cone)
    ZC: convex circular arc of radius rho_c through the pitch point (w_0, R_t), tangent there at alpha_n:
        W_t(rho) = w_c + sqrt(rho_c^2 - (rho - rho_m)^2),
        w_c = w_0 - rho_c cos(alpha_n),  rho_m = R_t - rho_c sin(alpha_n)

for rho up to the disc's tip radius (tool_tip_radius). The tool removes, at worm radius r, the u values of its points on
the cylinder r: the space's half-width is

    W(r) = max over theta of u(X(rho(theta), theta)),  with rho(theta) from r(X) = r                                 (4)

(the worm flank is the envelope of the tool surfaces in the screw motion; the stationary condition du/dtheta = 0 on
the cylinder r is the equation of meshing n . v = 0 of tool and worm, Litvin ch. 6), and H(r) = p_x / 2 - W(r).
(4) is solved per radius: rho(theta) by Newton on r(X)^2 = r^2 (analytic derivative), then theta by a grid search
and Newton on du/dtheta = 0 (central differences).

Thickness: in every form the tool's setting (sigma_0 or w_0) is chosen so that the axial thread thickness on the
reference cylinder is p_x / 2 (H(r1) = p_x / 4, secant iteration), as for ZA and ZI: the wheel's backlash is then
set by gear.backlash_mm alone.

Evaluation (`FormTable`): H is interpolated on [r1 - h_f - 0.1 m_x, r1 + h_f + 0.1 m_x] (the worm root up to the hob's
tip, which cuts the wheel root, meshgen.wheel) by a Chebyshev series of N_CHEB terms through the exact values (2)-(4)
at the Chebyshev points, and continued linearly (C1) outside. form_table refuses (GeometryError) a flank that does not
narrow outwards from the root to the hob's tip (the tool undercuts the thread) or that the series misses by more than
TABLE_TOL_M. tests/meshgen/test_worm_forms.py pins the series to the exact
solution (max |error| below 1 nm on the seeds' gears) and the exact solution to the definitions: ZN's normal section
straight, ZK's and ZC's axial sections against an independent simulation of the disc cutting (the tool's positions
swept densely, the lower envelope of the cut), ZC's axial section concave.

Defaults (DEFAULT_TOOL_DIAMETER_MM, DEFAULT_PROFILE_RADIUS_MODULES): docs/flank_forms.md.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.polynomial import chebyshev as C

from meshgen.errors import GeometryError
from meshgen.worm_forms_jit import N_CHEB, table_many

Gear = Any  # a meshgen.geometry.GearGeometry (not imported: meshgen.geometry imports this module)

DEFAULT_TOOL_DIAMETER_MM = 100.0  # ZK, ZC disc (docs/flank_forms.md)
DEFAULT_PROFILE_RADIUS_MODULES = 5.5  # ZC tool arc radius / m_x (docs/flank_forms.md)
DEFAULT_ZC_PROFILE_SHIFT = 0.5  # ZC wheel profile shift x2 (docs/flank_forms.md)

TABLE_TOL_M = 1e-9  # the table's largest allowed deviation from the exact H(r) (form_table's check)
FORMS = ("ZA", "ZN", "ZI", "ZK", "ZC")
TABLE_FORMS = ("ZN", "ZK", "ZC")  # the forms evaluated by the table (ZA, ZI: closed forms in meshgen.worm)
__all__ = [
    "DEFAULT_PROFILE_RADIUS_MODULES",
    "DEFAULT_ZC_PROFILE_SHIFT",
    "DEFAULT_TOOL_DIAMETER_MM",
    "FormTable",
    "exact_half_thickness",
    "form_table",
]


def default_profile_shift(profile: str) -> float:
    """The wheel's profile shift x2 when gear.profile_shift_coefficient is not given: 0, and for ZC the
    DEFAULT_ZC_PROFILE_SHIFT of ZC practice, with which ZC's default arc radius leaves a 20 deg wheel uncut
    (docs/flank_forms.md has the sources and the undercut it removes)."""
    return DEFAULT_ZC_PROFILE_SHIFT if profile == "ZC" else 0.0


def _geom(g: Gear):
    ap = abs(g.p)
    L = math.hypot(g.r1, ap)
    return ap, ap / L, g.r1 / L


def _normal_line_u(g: Gear, r, sigma0: float, slope: float):
    """u(r) on the helicoid swept by the normal-section line sigma = sigma0 + slope (x - r1) (equations (1), (2))."""
    ap, s, c = _geom(g)
    r = np.asarray(r, float)
    x = r.copy()
    for _ in range(50):
        sg = sigma0 + slope * (x - g.r1)
        f = x * x + (sg * s) ** 2 - r * r
        df = 2 * x + 2 * sg * slope * s * s
        dx = f / df
        x = x - dx
        if np.all(np.abs(dx) < 1e-15 * g.r1):
            break
    sg = sigma0 + slope * (x - g.r1)
    return sg * c + ap * np.arctan(sg * s / x)


def _tool_profile(g: Gear, rho, w0: float):
    """W_t(rho) and dW_t/drho of the ZK / ZC tool (equation (3))."""
    Rt = g.tool_diameter / 2
    if g.profile == "ZK":
        t = math.tan(g.alpha_n)
        return w0 - (rho - Rt) * t, np.full_like(rho, -t)
    rc = g.profile_radius
    wc = w0 - rc * math.cos(g.alpha_n)
    rm = Rt - rc * math.sin(g.alpha_n)
    d = rho - rm
    q = np.sqrt(np.maximum(rc * rc - d * d, 1e-30))
    return wc + q, -d / q


def _tool_point(g: Gear, rho, theta, w0: float):
    """X(rho, theta) of equation (3) and dX/drho."""
    _, s, c = _geom(g)
    cx = g.r1 + g.tool_diameter / 2
    Wt, dWt = _tool_profile(g, rho, w0)
    ct, st = np.cos(theta), np.sin(theta)
    X = np.stack([cx - rho * ct, -s * Wt - c * rho * st, c * Wt - s * rho * st])
    dX = np.stack([-ct, -s * dWt - c * st, c * dWt - s * st])
    return X, dX


def _u_on_cylinder(g: Gear, r, theta, w0: float):
    """u of the tool point at angle theta on the worm cylinder r (rho by Newton on r(X)^2 = r^2); nan where none."""
    ap, _, _ = _geom(g)
    Rt = g.tool_diameter / 2
    cx = g.r1 + Rt
    rho = np.broadcast_to(cx - r, np.broadcast(r, theta).shape).astype(float)
    r = np.broadcast_to(r, rho.shape)
    for _ in range(40):
        X, dX = _tool_point(g, rho, theta, w0)
        f = X[0] ** 2 + X[1] ** 2 - r * r
        df = 2 * X[0] * dX[0] + 2 * X[1] * dX[1]
        step = f / np.where(np.abs(df) > 1e-30, df, 1e-30)
        rho = rho - np.clip(step, -0.2 * Rt, 0.2 * Rt)
        if np.all(np.abs(step) < 1e-15 * Rt):
            break
    X, _ = _tool_point(g, rho, theta, w0)
    ok = (np.abs(np.hypot(X[0], X[1]) - r) < 1e-12 * Rt) & (rho <= tool_tip_radius(g))
    u = X[2] - ap * np.arctan2(X[1], X[0])
    return np.where(ok, u, np.nan)


def tool_tip_radius(g: Gear) -> float:
    """The disc's tip radius: R_t + (r1 - r_lo) + 1.5 m_x, 1.5 m_x past the depth of the table's range (module
    docstring; at a large lead angle the contact at r_lo lies off the disc's mid-plane, further out on the disc). The
    disc exists only up to it; an unbounded disc would reach round a slender worm's axis and cut it on the far side."""
    lo, _ = table_range(g)
    return g.tool_diameter / 2 + (g.r1 - lo) + 1.5 * g.m_x


def _space_half_width_tool(g: Gear, r, w0: float, n_grid: int = 41, n_newton: int = 12):
    """W(r) of equation (4) for the ZK / ZC disc: grid search over theta, then Newton on du/dtheta = 0."""
    r = np.atleast_1d(np.asarray(r, float))
    Rt = g.tool_diameter / 2
    # the tool's points reach the cylinder r only while rho |sin theta| c <~ r: the section of the disc
    th_max = np.arcsin(np.minimum(0.9, 0.9 * r / Rt))
    s = np.linspace(-1.0, 1.0, n_grid)
    TH = th_max[:, None] * s[None, :]
    U = _u_on_cylinder(g, r[:, None], TH, w0)
    k = np.nanargmax(np.where(np.isfinite(U), U, -np.inf), axis=1)
    th = TH[np.arange(len(r)), k]
    h = 1e-4 * th_max
    for _ in range(n_newton):
        up = _u_on_cylinder(g, r, th + h, w0)
        u0 = _u_on_cylinder(g, r, th, w0)
        um = _u_on_cylinder(g, r, th - h, w0)
        d1 = (up - um) / (2 * h)
        d2 = (up - 2 * u0 + um) / (h * h)
        step = np.where(d2 < 0, -d1 / np.where(d2 < 0, d2, -1.0), 0.0)
        th = th + np.clip(step, -th_max / n_grid, th_max / n_grid)
    return _u_on_cylinder(g, r, th, w0)


def _space_half_width_normal(g: Gear, r, sigma0: float):
    return _normal_line_u(g, r, sigma0, +math.tan(g.alpha_n))


def exact_half_thickness(g: Gear, r) -> np.ndarray:
    """H(r) of the ZN / ZK / ZC flank by equations (2)-(4), the tool set for H(r1) = p_x / 4 (module docstring)."""
    return _exact(g, np.atleast_1d(np.asarray(r, float)), tool_setting(g))


def _exact(g: Gear, r, k0: float):
    if g.profile == "ZN" and g.zn_section == "thread":
        return _normal_line_u(g, r, k0, -math.tan(g.alpha_n))
    if g.profile == "ZN":
        return g.p_x / 2 - _space_half_width_normal(g, r, k0)
    return g.p_x / 2 - _space_half_width_tool(g, r, k0)


@functools.lru_cache(maxsize=64)
def tool_setting(g: Gear) -> float:
    """sigma_0 (ZN) or w_0 (ZK, ZC) with H(r1) = p_x / 4 (secant iteration from the normal thickness p_x cos / 4)."""
    _check_tool(g)
    _, _, c = _geom(g)
    target = g.p_x / 4
    k0 = target * c
    k1 = k0 * 1.01
    f0 = float(_exact(g, np.array([g.r1]), k0)[0]) - target
    for _ in range(30):
        f1 = float(_exact(g, np.array([g.r1]), k1)[0]) - target
        if not math.isfinite(f1):
            raise GeometryError(
                f"gear.profile = {g.profile}: the tool does not generate a flank on the reference cylinder"
            )
        if f1 == f0 or abs(f1) < 1e-16:
            break
        k0, k1, f0 = k1, k1 - f1 * (k1 - k0) / (f1 - f0), f1
    return k1


def _check_tool(g: Gear) -> None:
    """The disc must reach over the table's range of depth (module docstring): R_t > depth, and for ZC the arc must
    cover it, rho_c (1 - sin alpha_n) >= 1.5 (h_f + 0.1 m_x) (its tangent turns radial at the arc's end)."""
    if g.profile not in ("ZK", "ZC"):
        return
    depth = g.h_f + 0.1 * g.m_x
    if g.tool_diameter / 2 < 3 * depth:
        raise GeometryError(
            f"gear.tool_diameter_mm = {g.tool_diameter * 1e3:.4g}: too small for this worm; allowed from "
            f"{6 * depth * 1e3:.4g} mm (6 x (dedendum + 0.1 module))"
        )
    if g.profile == "ZC":
        need = 1.5 * depth / (1 - math.sin(g.alpha_n))
        if g.profile_radius < need:
            raise GeometryError(
                f"gear.profile_radius_mm = {g.profile_radius * 1e3:.4g}: the tool's arc does not cover the thread's "
                f"depth; allowed from {need * 1e3:.4g} mm (1.5 (h_f + 0.1 m_x) / (1 - sin alpha_n))"
            )


@dataclass(frozen=True)
class FormTable:
    """H(r) of a ZN / ZK / ZC worm as a Chebyshev series on [r_lo, r_hi], continued linearly outside."""

    r_lo: float
    r_hi: float
    coef: np.ndarray  # (N_CHEB,) Chebyshev coefficients of H in x = (2 r - r_lo - r_hi) / (r_hi - r_lo)

    def evaluate(self, r) -> tuple[np.ndarray, np.ndarray]:
        """(H(r), dH/dr): the compiled series (meshgen.worm_forms_jit.half_thickness, the one evaluation)."""
        r = np.asarray(r, float)
        H, dH = np.empty(r.shape), np.empty(r.shape)
        table_many(np.ascontiguousarray(r).reshape(-1), self.params(), H.reshape(-1), dH.reshape(-1))
        return H, dH

    def half_thickness(self, r):
        return self.evaluate(r)[0]

    def half_thickness_dr(self, r):
        return self.evaluate(r)[1]

    def params(self) -> np.ndarray:
        """[r_lo, r_hi, coef...] for the compiled evaluator (meshgen.worm_forms_jit)."""
        return np.concatenate([[self.r_lo, self.r_hi], self.coef])


def table_range(g: Gear) -> tuple[float, float]:
    """[r1 - h_f - 0.1 m_x, r1 + h_f + 0.1 m_x]: the worm root to past the hob's tip (module docstring)."""
    d = g.h_f + 0.1 * g.m_x
    return g.r1 - d, g.r1 + d


@functools.lru_cache(maxsize=64)
def form_table(g: Gear) -> FormTable:
    """The H(r) table of a ZN / ZK / ZC worm (exact values at the Chebyshev points of the range)."""
    lo, hi = table_range(g)
    k = np.arange(N_CHEB)
    x = np.cos(math.pi * (k + 0.5) / N_CHEB)
    r = 0.5 * (lo + hi) + 0.5 * (hi - lo) * x
    H = exact_half_thickness(g, r)
    if not np.all(np.isfinite(H)):
        raise GeometryError(
            f"gear.profile = {g.profile}: the tool generates no flank over the thread's depth; raise "
            f"gear.tool_diameter_mm or gear.profile_radius_mm"
        )
    coef = C.chebfit(x, H, N_CHEB - 1)
    table = FormTable(lo, hi, coef)
    # the thread must narrow outwards from the root to the hob's tip, and the series hold the exact flank there
    # (a disc at a large lead angle on a slender worm undercuts the thread's root: the flank turns back)
    r = np.linspace(g.r_f1, g.r1 + g.h_f, 65)
    Ht = table.half_thickness(r)
    check = r[::8]
    err = np.max(np.abs(table.half_thickness(check) - exact_half_thickness(g, check)))
    if not (np.all(np.diff(Ht) < 0) and err < TABLE_TOL_M):
        raise GeometryError(
            f"gear.profile = {g.profile}: the tool undercuts the worm thread's root at this lead angle "
            f"({math.degrees(g.gamma):.2f} deg, diameter quotient {g.q:.3g}); allowed: a thread narrowing outwards "
            f"from root to tip; raise gear.diameter_quotient or gear.tool_diameter_mm, or use gear.profile ZI"
        )
    return table
