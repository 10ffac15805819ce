"""Contact pattern and Hertz contact stress from the exact-flank contacts (`contact.geometry: flanks`; issue 13).

Geometry, once per gear and slice count (`flank_curvature`, cached in process), on the kernel's grid
(wormsim.contact3d.flanks.flank_grid: flank sigma, slice j, profile point i): at each active point, the wheel flank
and the worm thread in the rigid conjugate pose at which that point is on the contact line (wheel angle c, the
point's conjugate angle; worm angle c / (hand z1 / z2); the unshifted space-0 flank, i.e. without backlash). There
the gap function G (meshgen.worm.thread_gap of the wheel flank point: the normal distance to the worm thread) is a
ruled valley along the contact line: G = 0 on the line and, across it, G = s^2 / (2 rho') to second order, s the arc
length across the line and rho' the relative radius of curvature of the two flanks in that normal section
(two cylinders in line contact: Johnson, Contact Mechanics, 1985, sec. 4.2). So the Hessian of G on the flank,

    H v = lambda M v,   H = d2G / d(zeta, rho)^2,   M = J^T J,   J = dX / d(zeta, rho)                        (1)

(central differences of meshgen.wheel.space_flank's envelope at offsets H_STEP_MX x m_x; X the flank point in the
wheel frame, zeta = its z), has lambda_min ~ 0 with the contact line's direction t = J v_min / |J v_min|, and
lambda_max = 1 / rho'. The slice's contact-line length inside the slice (width b2 / S across the face) is

    L = (b2 / S) / |t . e_z|,   capped at the active profile length of the slice                              (2)

Hertz line contact (Johnson eq. 4.45; DIN 3996 and ISO/TS 14521 use the same p_H for line contact):

    p_H = sqrt(w E* / (pi rho')),   w = F_n / L                                                                (3)

F_n = the contact's normal force (its constraint row), E* = wormsim.gear_theory.effective_modulus_pa.

Run outputs (`PatternLog`, one record per runner sample at the sample's end, every contact of the kernel): the
summary over the steady window, each sample weighted equally (samples are equally spaced in time, so this is the
time integral): contact_pattern_centroid_face_mm / _radius_mm = the F_n-weighted mean slice centre zeta / flank radius
rho; contact_pattern_extent_face_mm = the face span holding the central 95 % of the load (2.5 % and 97.5 % quantiles
of F_n along zeta, the load of a slice spread evenly over its width); contact_pressure_max_mpa and where
(contact_pressure_max_face_mm, _radius_mm); contact_pressure_mean_mpa = the F_n-weighted mean of p_H. The per-cell
grid (flank, slice, profile point: load F_n dt and the largest p_H) is what report.png and the recording draw.
"""
from __future__ import annotations

import functools
import math
from dataclasses import dataclass

import mujoco
import numpy as np

from meshgen import wheel, worm
from meshgen.geometry import GearGeometry
from wormsim.contact3d.flanks import N_PROFILE, flank_grid

H_STEP_MX = 0.02            # finite-difference step of (1), in axial modules
EXTENT_LOAD_SHARE = 0.95    # contact_pattern_extent_face_mm: the face span holding this share of the load


@dataclass(frozen=True)
class FlankCurvature:
    """(1) and (2) on the kernel's grid; nan where the grid point is not active."""

    inv_rho: np.ndarray      # (2, S, N) 1 / rho' across the contact line, 1/m
    line_tz: np.ndarray      # (2, S, N) |t . e_z| of the contact line's unit tangent
    line_len: np.ndarray     # (2, S, N) contact-line length inside the slice (2), m
    rho: np.ndarray          # (S, N) flank radius of the grid points, m
    zeta: np.ndarray         # (S,) slice centres, m
    slice_width: float       # b2 / S, m


def wheel_point(g: GearGeometry, zeta, rho, side: int) -> np.ndarray:
    """Point (..., 3) of space-0 flank `side` (meshgen.wheel.space_flank, no backlash) in the wheel frame."""
    psi = wheel.space_flank(g, rho, zeta, side).psi
    return np.stack([rho * np.cos(psi), rho * np.sin(psi), np.broadcast_to(zeta, np.shape(psi))], axis=-1)


def _gap_rows(g: GearGeometry, pts: np.ndarray, th1: np.ndarray) -> np.ndarray:
    """thread_gap with one theta1 per point (its equation (1) with theta1 broadcast)."""
    r = np.hypot(pts[..., 0], pts[..., 1])
    phi = np.arctan2(pts[..., 1], pts[..., 0])
    u = worm.wrap(pts[..., 2] - g.p * (phi - th1), g.p_x)
    G = np.abs(u) - worm.half_thickness(g, r)
    return G / np.sqrt(1.0 + (g.p / r) ** 2 + worm.half_thickness_dr(g, r) ** 2)


def curvature_at(g: GearGeometry, zeta, rho, c, side: int, h: float | None = None):
    """(1) at flank points (zeta, rho) of space-0 flank `side` with conjugate angles c: (1/rho', t_z, |grad G|)."""
    zeta, rho, c = np.broadcast_arrays(np.asarray(zeta, float), np.asarray(rho, float), np.asarray(c, float))
    h = H_STEP_MX * g.m_x if h is None else h
    off = [(a, b) for a in (-1, 0, 1) for b in (-1, 0, 1)]
    Z = np.stack([zeta + a * h for a, b in off])
    R = np.stack([rho + b * h for a, b in off])
    X = wheel_point(g, Z, R, side)
    G = np.stack([_gap_rows(g, _static(g, X[k], c), c / (g.hand * g.z1 / g.z2)) for k in range(9)])
    Gm = {o: G[k] for k, o in enumerate(off)}
    Xm = {o: X[k] for k, o in enumerate(off)}
    hzz = (Gm[1, 0] - 2 * Gm[0, 0] + Gm[-1, 0]) / h**2
    hrr = (Gm[0, 1] - 2 * Gm[0, 0] + Gm[0, -1]) / h**2
    hzr = (Gm[1, 1] - Gm[1, -1] - Gm[-1, 1] + Gm[-1, -1]) / (4 * h * h)
    gz = (Gm[1, 0] - Gm[-1, 0]) / (2 * h)
    gr = (Gm[0, 1] - Gm[0, -1]) / (2 * h)
    Jz = (Xm[1, 0] - Xm[-1, 0]) / (2 * h)
    Jr = (Xm[0, 1] - Xm[0, -1]) / (2 * h)
    Hm = np.stack([np.stack([hzz, hzr], -1), np.stack([hzr, hrr], -1)], -2)
    M = np.stack([np.stack([(Jz * Jz).sum(-1), (Jz * Jr).sum(-1)], -1),
                  np.stack([(Jz * Jr).sum(-1), (Jr * Jr).sum(-1)], -1)], -2)
    # generalized eigenproblem via the Cholesky factor of the metric: L^-1 H L^-T
    Lc = np.linalg.cholesky(M)
    Li = np.linalg.inv(Lc)
    A = Li @ Hm @ np.swapaxes(Li, -1, -2)
    lam, V = np.linalg.eigh(A)
    v_min = np.einsum("...ji,...j->...i", Li, V[..., :, 0])        # L^-T y: the parameter direction
    t = v_min[..., 0, None] * Jz + v_min[..., 1, None] * Jr
    tz = np.abs(t[..., 2]) / np.linalg.norm(t, axis=-1)
    gnorm = np.hypot(gz, gr)
    return lam[..., 1], tz, gnorm


def _static(g: GearGeometry, X: np.ndarray, c: np.ndarray) -> np.ndarray:
    cc, sc = np.cos(c), np.sin(c)
    x = cc * X[..., 0] - sc * X[..., 1]
    y = sc * X[..., 0] + cc * X[..., 1]
    return np.stack([y + g.a, -X[..., 2], -x], axis=-1)


@functools.lru_cache(maxsize=16)
def flank_curvature(g: GearGeometry, slices: int, n_profile: int = N_PROFILE) -> FlankCurvature:
    """(1), (2) on flank_grid(g, slices)'s active points."""
    fg = flank_grid(g, slices, n_profile)
    S, N = fg.rho.shape
    Z = np.broadcast_to(fg.zeta[:, None], (S, N))
    inv_rho = np.full((2, S, N), np.nan)
    tz = np.full((2, S, N), np.nan)
    for sg, side in enumerate((+1, -1)):
        ok = np.isfinite(fg.c[sg])
        if ok.any():
            k, t, _ = curvature_at(g, Z[ok], fg.rho[ok], fg.c[sg][ok], side)
            inv_rho[sg][ok], tz[sg][ok] = k, t
    width = g.face_width / slices
    # active profile length per slice and flank (the points' 3D polyline, wheel frame)
    P = np.stack([fg.xy[..., 0], fg.xy[..., 1], np.broadcast_to(Z, (2, S, N))], axis=-1)
    seg = np.linalg.norm(np.diff(P, axis=2), axis=-1)
    prof = np.nansum(seg, axis=2)
    with np.errstate(divide="ignore", invalid="ignore"):
        length = np.minimum(width / tz, prof[:, :, None])
    return FlankCurvature(inv_rho=inv_rho, line_tz=tz, line_len=length, rho=fg.rho, zeta=fg.zeta,
                          slice_width=width)


def hertz_line_pressure_pa(line_load_n_per_m, e_star_pa: float, inv_rho_per_m):
    """(3): p_H = sqrt(w E* / (pi rho')) (Hertz line contact; Johnson, Contact Mechanics, eq. 4.45)."""
    return np.sqrt(np.maximum(line_load_n_per_m, 0.0) * e_star_pa * np.maximum(inv_rho_per_m, 0.0) / math.pi)


def _interp(a: np.ndarray, sg: np.ndarray, j: np.ndarray, f: np.ndarray) -> np.ndarray:
    """a[sg, j, f] linear in the fractional profile index f; a nan neighbour falls back to the other one."""
    N = a.shape[-1]
    i0 = np.clip(np.floor(f).astype(int), 0, N - 1)
    i1 = np.minimum(i0 + 1, N - 1)
    w = np.clip(f - i0, 0.0, 1.0)
    a0, a1 = a[sg, j, i0], a[sg, j, i1]
    a0 = np.where(np.isfinite(a0), a0, a1)
    a1 = np.where(np.isfinite(a1), a1, a0)
    return (1 - w) * a0 + w * a1


class PatternLog:
    """Per-sample flank contact loads and pressures (module docstring); `summary` over the steady window."""

    def __init__(self, fc, e_star_pa: float):
        g = fc.bm.geometry
        self.fc = fc
        self.geo = g
        self.cv = flank_curvature(g, fc.grid.slices, fc.grid.rho.shape[1])
        self.e_star = e_star_pa
        self.rows: list[np.ndarray] = []

    def record(self, i: int, d: mujoco.MjData) -> None:
        """The kernel's contacts (d.contact's last fc.n entries) at sample i: (i, sigma, j, f, F_n, p_H, zeta, rho)."""
        fc = self.fc
        n = min(fc.n, d.ncon)
        if n == 0:
            return
        k0 = d.ncon - n
        adr = np.asarray(d.contact.efc_address[k0:d.ncon])
        ok = adr >= 0
        if not ok.any():
            return
        meta = fc.meta[:n][ok]
        fn = d.efc_force[adr[ok]]                      # normal row of each contact (on the wheel, along +n)
        sg, j, f = meta[:, 1].astype(int), meta[:, 2].astype(int), meta[:, 3]
        cv = self.cv
        k = _interp(cv.inv_rho, sg, j, f)
        L = _interp(cv.line_len, sg, j, f)
        p = hertz_line_pressure_pa(fn / L, self.e_star, k)
        rho = _interp(np.broadcast_to(cv.rho, cv.inv_rho.shape), sg, j, f)
        self.rows.append(np.column_stack([np.full(len(fn), i), sg, j, f, fn, p, cv.zeta[j], rho]))

    def table(self) -> np.ndarray:
        return np.concatenate(self.rows) if self.rows else np.zeros((0, 8))

    def summary(self, t_s: np.ndarray, window_s) -> dict:
        """The summary keys of the module docstring over the samples with t in window_s."""
        T = self.table()
        w0, w1 = window_s
        inwin = (t_s >= w0) & (t_s <= w1)
        sel = T[inwin[T[:, 0].astype(int)]] if len(T) else T
        sel = sel[sel[:, 4] > 0] if len(sel) else sel
        nan = float("nan")
        keys = {"contact_pattern_centroid_face_mm": nan, "contact_pattern_centroid_radius_mm": nan,
                "contact_pattern_extent_face_mm": nan, "contact_pressure_max_mpa": nan,
                "contact_pressure_mean_mpa": nan, "contact_pressure_max_face_mm": nan,
                "contact_pressure_max_radius_mm": nan,
                "contact_pattern_source": "loaded (contact3d exact flanks), contact normal force-weighted over the "
                                          "steady window"}
        if not len(sel):
            return keys
        fn, p, z, r = sel[:, 4], sel[:, 5], sel[:, 6], sel[:, 7]
        W = fn.sum()
        imax = int(np.nanargmax(p))
        keys.update({
            "contact_pattern_centroid_face_mm": float((fn * z).sum() / W * 1e3),
            "contact_pattern_centroid_radius_mm": float((fn * r).sum() / W * 1e3),
            "contact_pattern_extent_face_mm": float(self.extent_face_m(sel) * 1e3),
            "contact_pressure_max_mpa": float(p[imax] * 1e-6),
            "contact_pressure_mean_mpa": float((fn * p).sum() / W * 1e-6),
            "contact_pressure_max_face_mm": float(z[imax] * 1e3),
            "contact_pressure_max_radius_mm": float(r[imax] * 1e3),
        })
        return keys

    def extent_face_m(self, sel: np.ndarray) -> float:
        """Face span holding EXTENT_LOAD_SHARE of the load (each slice's load spread evenly over its width)."""
        cv = self.cv
        S = len(cv.zeta)
        load = np.bincount(sel[:, 2].astype(int), weights=sel[:, 4], minlength=S)
        edges = cv.zeta[0] - cv.slice_width / 2 + cv.slice_width * np.arange(S + 1)
        cum = np.concatenate([[0.0], np.cumsum(load)]) / load.sum()
        q = (1 - EXTENT_LOAD_SHARE) / 2
        lo, hi = np.interp([q, 1 - q], cum, edges)
        return float(hi - lo)

    def grid(self, t_s: np.ndarray, window_s) -> dict:
        """Per cell (flank, slice, nearest profile point) over the window: summed F_n and the largest p_H."""
        T = self.table()
        S, N = self.cv.rho.shape
        load = np.zeros((2, S, N))
        pmax = np.zeros((2, S, N))
        if len(T):
            inwin = (t_s >= window_s[0]) & (t_s <= window_s[1])
            T = T[inwin[T[:, 0].astype(int)]]
            T = T[T[:, 4] > 0]
            sg, j = T[:, 1].astype(int), T[:, 2].astype(int)
            i = np.clip(np.rint(T[:, 3]).astype(int), 0, N - 1)
            np.add.at(load, (sg, j, i), T[:, 4])
            np.maximum.at(pmax, (sg, j, i), T[:, 5])
        return {"load": load, "pressure_max_pa": pmax, "rho_m": self.cv.rho, "zeta_m": self.cv.zeta,
                "slice_width_m": self.cv.slice_width}
