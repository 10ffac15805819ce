"""Contact pattern and Hertz contact stress from the exact-flank contacts (`contact.geometry: flanks`).

Geometry, once per gear and slice count (`flank_curvature`, cached in process and on disk), on the kernel's grid
(wormsim.tooth.kernel.flank_grid: flank sigma, slice j, profile point i): at each active point, the wheel flank
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

    L = s (b2 / S) / |t . e_z|,   capped at the active profile length of the slice                            (2)

(s the contact's share of its slice, wormsim.tooth.kernel.slice_weights: 1 inside the line, less at its ends).

Hertz line contact (Johnson eq. 4.45; DIN 3996 and ISO/TS 14521 use the same p_H for line contact):

    p_H = sqrt(w E* / (pi rho')),   w = F_n / L                                                                (3)

F_n = the contact's normal force (its constraint row), E* = wormsim.physics.gear_theory.effective_modulus_pa.

Run outputs (`PatternLog`, one record per runner sample at the sample's end, every contact of the kernel): the
summary over the steady window, each sample weighted equally (samples are equally spaced in time, so this is the
time integral): contact_pattern_centroid_face_mm / _radius_mm = the F_n-weighted mean slice centre zeta / flank radius
rho; contact_pattern_extent_face_mm = the face span holding the central 95 % of the load (2.5 % and 97.5 % quantiles
of F_n along zeta, the load of a slice spread evenly over its width); contact_pressure_max_mpa and where
(contact_pressure_max_face_mm, _radius_mm); contact_pressure_mean_mpa = the F_n-weighted mean of p_H (3). The per-cell
grid (flank, slice, profile point: load F_n dt and the largest averaged p_H (4)) is what report.png and the recording
draw.

The maximum (summary and grid) is a peak of the line load averaged over a length of the contact line, not one
contact's (3) (docs/decisions/0037-contact-pressure-peak.md): per sample and contact line (the contacts of one tooth
flank on consecutive slices), over the window of the n = ceil(l_H / (b2 / S)) slices centred on each contact,

    w_avg = sum F_n / max(sum s L, l_H),   1/rho'_avg = sum F_n / rho' / sum F_n,
    p_H,avg = sqrt(w_avg E* / (pi rho'_avg)),   l_H = PRESSURE_LENGTH_MX m_x                                    (4)

s L the contacts' own line lengths (2). A contact entering or leaving the line has a share s -> 0 of its slice, so (3)
divides a vanishing force by a vanishing length, and MuJoCo's constraint force keeps a part that does not scale with s
(the impedance term D J qacc, D from solimp and A_hat); in (4) a window whose line is shorter than l_H counts its load
over l_H. Measured with (3) per contact (the maximum over contacts above 1 % of the mean F_n), S against 2 S slices:
4-start-z41 187 / 2841 MPa, random gear 0 153 / 1967 MPa (a contact of 0.08 N at the profile's end); with (4)
131 / 131 and 127 / 131 MPa (studies/slice_convergence_default.py, docs/contact3d.md "Default slice count").
"""

from __future__ import annotations

import functools
import hashlib
import math
from dataclasses import asdict, dataclass

import numba
import numpy as np

from meshgen import wheel, worm
from meshgen.cache import cached
from meshgen.geometry import GearGeometry
from wormsim.tooth import grid
from wormsim.tooth.grid import flank_grid

H_STEP_MX = 0.02  # finite-difference step of (1), in axial modules
EXTENT_LOAD_SHARE = 0.95  # contact_pattern_extent_face_mm: the face span holding this share of the load
PRESSURE_LENGTH_MX = 1.0  # l_H of (4), in axial modules: the line length the pressure peak is averaged over


@dataclass(frozen=True)
class FlankCurvature:
    """(1) and (2) on the kernel's grid; nan where the grid point is not active."""

    inv_rho: np.ndarray  # (2, S, N) 1 / rho' across the contact line, 1/m
    line_tz: np.ndarray  # (2, S, N) |t . e_z| of the contact line's unit tangent
    line_len: np.ndarray  # (2, S, N) contact-line length inside the slice (2), m
    rho: np.ndarray  # (S, N) flank radius of the grid points, m
    zeta: np.ndarray  # (S,) slice centres, m
    slice_width: float  # b2 / S, m


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
    M = np.stack(
        [np.stack([(Jz * Jz).sum(-1), (Jz * Jr).sum(-1)], -1), np.stack([(Jz * Jr).sum(-1), (Jr * Jr).sum(-1)], -1)], -2
    )
    # generalized eigenproblem via the Cholesky factor of the metric: L^-1 H L^-T
    Lc = np.linalg.cholesky(M)
    Li = np.linalg.inv(Lc)
    A = Li @ Hm @ np.swapaxes(Li, -1, -2)
    lam, V = np.linalg.eigh(A)
    v_min = np.einsum("...ji,...j->...i", Li, V[..., :, 0])  # L^-T y: the parameter direction
    t = v_min[..., 0, None] * Jz + v_min[..., 1, None] * Jr
    tz = np.abs(t[..., 2]) / np.linalg.norm(t, axis=-1)
    gnorm = np.hypot(gz, gr)
    return lam[..., 1], tz, gnorm


def _static(g: GearGeometry, X: np.ndarray, c: np.ndarray) -> np.ndarray:
    cc, sc = np.cos(c), np.sin(c)
    x = cc * X[..., 0] - sc * X[..., 1]
    y = sc * X[..., 0] + cc * X[..., 1]
    return np.stack([y + g.a, -X[..., 2], -x], axis=-1)


def flank_curvature(g: GearGeometry, slices: int, n_profile: int | None = None) -> FlankCurvature:
    """(1), (2) on flank_grid(g, slices, n_profile)'s active points (None: the grid's N_PROFILE when called); in
    process and on disk (meshgen.cache, keyed by the geometry, the grid size and the source of this module and of
    the grid's modules), like the grid it is computed on."""
    return _flank_curvature_cached(g, slices, grid.N_PROFILE if n_profile is None else n_profile)


@functools.lru_cache(maxsize=16)
def _flank_curvature_cached(g: GearGeometry, slices: int, n_profile: int) -> FlankCurvature:
    parts = {"g": asdict(g), "slices": slices, "n_profile": n_profile, "code": _curvature_code_hash()}
    return cached("flankcurv", parts, lambda: _flank_curvature(g, slices, n_profile))


@functools.cache
def _curvature_code_hash() -> str:
    """SHA-256 of this module's source and of the grid's code hash (the envelope, the trim, the worm)."""
    import inspect
    import sys

    src = inspect.getsource(sys.modules[__name__]) + grid.grid_code_hash()
    return hashlib.sha256(src.encode()).hexdigest()


def _flank_curvature(g: GearGeometry, slices: int, n_profile: int) -> FlankCurvature:
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
    return FlankCurvature(inv_rho=inv_rho, line_tz=tz, line_len=length, rho=fg.rho, zeta=fg.zeta, slice_width=width)


def hertz_line_pressure_pa(line_load_n_per_m, e_star_pa: float, inv_rho_per_m):
    """(3): p_H = sqrt(w E* / (pi rho')) (Hertz line contact; Johnson, Contact Mechanics, eq. 4.45)."""
    return np.sqrt(np.maximum(line_load_n_per_m, 0.0) * e_star_pa * np.maximum(inv_rho_per_m, 0.0) / math.pi)


@numba.njit(cache=True, inline="always")
def _line_pressure(w, e_star, inv_rho):
    """(3) for one contact, compiled (pattern_rows, _window_rows): hertz_line_pressure_pa's formula, its operations
    in its order."""
    return math.sqrt(max(w, 0.0) * e_star * max(inv_rho, 0.0) / math.pi)


@numba.njit(cache=True, inline="always")
def _lerp(a, sg, j, f):
    """a[sg, j, f] linear in the fractional profile index f; a nan neighbour gives the other one."""
    N = a.shape[2]
    i0 = min(max(int(math.floor(f)), 0), N - 1)
    i1 = min(i0 + 1, N - 1)
    w = min(max(f - i0, 0.0), 1.0)
    a0, a1 = a[sg, j, i0], a[sg, j, i1]
    if a0 != a0:
        return a1
    if a1 != a1:
        return a0
    return (1 - w) * a0 + w * a1


@numba.njit(cache=True)
def _lerp_rows(a, sg, j, f):
    """_lerp for arrays of (sigma, j, f)."""
    out = np.empty(f.shape[0])
    for k in range(f.shape[0]):
        out[k] = _lerp(a, int(sg[k]), int(j[k]), f[k])
    return out


@numba.njit(cache=True)
def _window_rows(buf, m, inwin, inv_rho, rho3, zeta, e_star, length, n):
    """PatternLog.window_rows compiled: rows 0..m-1 of the log buf (i, sigma, j, f, F_n, p_H; float32), the samples
    in the window inwin (bool per sample), (4) with l_H = length over n slices; the table's columns (i, sigma, j, f,
    F_n, p_H, zeta, rho) of the kept rows, as PatternLog.table makes them, and their averaged pressure (4) (the
    cumulative sums sequential from row 0)."""
    cF, cL, cK = np.zeros(m + 1), np.zeros(m + 1), np.zeros(m + 1)
    ok = np.zeros(m, dtype=np.bool_)
    first = np.zeros(m, dtype=np.int64)  # each row's line's first row
    n_keep = 0
    for r in range(m):
        row = buf[r]
        # float64 as table()'s astype (numba's float() keeps a float32 a float32)
        i, sg, j = np.float64(row[0]), int(row[1]), int(row[2])
        f, fn, ph = np.float64(row[3]), np.float64(row[4]), np.float64(row[5])
        k = _lerp(inv_rho, sg, j, f)
        good = math.isfinite(k) and k > 0 and math.isfinite(ph) and ph > 0 and fn > 0
        ok[r] = good
        F = fn if good else 0.0
        L = F * e_star * k / (math.pi * (ph * ph)) if good else 0.0
        K = F * k if good else 0.0
        cF[r + 1], cL[r + 1], cK[r + 1] = cF[r] + F, cL[r] + L, cK[r] + K
        new = r == 0
        if not new:
            prev = buf[r - 1]
            new = row[0] != prev[0] or sg != int(prev[1]) or j != int(prev[2]) + 1
        first[r] = r if new else first[r - 1]
        if inwin[int(i)] and fn > 0:
            n_keep += 1
    sel = np.empty((n_keep, 8))
    pavg = np.empty(n_keep)
    q = n_keep
    end = m  # one past the current line's last row, walking back
    for r in range(m - 1, -1, -1):
        if r + 1 < m and first[r + 1] == r + 1:
            end = r + 1
        row = buf[r]
        fn = np.float64(row[4])
        if not (inwin[int(row[0])] and fn > 0):
            continue
        q -= 1
        sg, j, f = int(row[1]), int(row[2]), np.float64(row[3])
        for c in range(6):
            sel[q, c] = row[c]
        sel[q, 6] = zeta[j]
        sel[q, 7] = _lerp(rho3, sg, j, f)
        lo, hi = max(first[r], r - (n - 1) // 2), min(end, r + n // 2 + 1)
        sF, sL, sK = cF[hi] - cF[lo], cL[hi] - cL[lo], cK[hi] - cK[lo]
        if ok[r] and sF > 0:
            w = sF / max(sL, length)
            pavg[q] = _line_pressure(w, e_star, sK / sF)
        else:
            pavg[q] = math.nan
    return sel, pavg


@numba.njit(cache=True)
def _grid_cells(sel, pavg, load, pmax):
    """PatternLog.grid's cells: per window row (sel, its averaged pressure pavg) its F_n added to load[sigma, j, i] and
    a finite pavg into pmax's maximum there, i the nearest profile point (rounded half to even, clipped); row by row
    in order, as numpy's add.at and maximum.at do."""
    N = load.shape[2]
    for r in range(sel.shape[0]):
        sg, j = int(sel[r, 1]), int(sel[r, 2])
        i = min(max(int(np.rint(sel[r, 3])), 0), N - 1)
        load[sg, j, i] += sel[r, 4]
        p = pavg[r]
        if math.isfinite(p) and p > pmax[sg, j, i]:
            pmax[sg, j, i] = p


@numba.njit(cache=True)
def pattern_rows(i, adr, efc_force, meta, weight, inv_rho, line_len, e_star, out, m):
    """Appends (i, sigma, j, f, F_n, p_H (3)) per contact with a constraint row to out (float32) from row m. The
    contact carries the share weight[c] of its slice (kernel.slice_weights), so its line is weight[c] x L long."""
    for c in range(adr.shape[0]):
        if adr[c] < 0 or weight[c] <= 0.0:
            continue
        sg, j, f = int(meta[c, 1]), int(meta[c, 2]), meta[c, 3]
        fn = efc_force[adr[c]]  # the normal row: the force on the wheel along +n
        k = _lerp(inv_rho, sg, j, f)
        L = weight[c] * _lerp(line_len, sg, j, f)
        o = out[m]
        o[0], o[1], o[2], o[3], o[4] = i, sg, j, f, fn
        # a contact whose slice has no contact-line length left (L = 0: a steep flank's slice at the active profile's
        # end) has no line load: its p_H is nan, left out of the pressure keys
        o[5] = _line_pressure(fn / L, e_star, k) if L > 0.0 else math.nan
        m += 1
    return m


class PatternLog:
    """Per-sample flank contact loads and pressures (module docstring); `summary` over the steady window."""

    def __init__(self, fc, e_star_pa: float):
        g = fc.bm.geometry
        self.fc = fc
        self.geo = g
        self.cv = flank_curvature(g, fc.grid.slices, fc.grid.rho.shape[1])
        self.rho3 = np.ascontiguousarray(np.broadcast_to(self.cv.rho, self.cv.inv_rho.shape))
        self.e_star = e_star_pa
        self.buf = np.zeros((4096, 6), dtype=np.float32)  # 24 bytes per contact and sample
        self.m = 0
        self._rows: tuple | None = None  # (row count, samples in the window, window_rows' result): `window_rows`

    def record(self, i: int, d) -> None:
        """The kernel's contacts (d.contact's last fc.n entries) at sample i: (i, sigma, j, f, F_n, p_H);
        p_H by (3) (in `pattern_rows`, compiled: `_line_pressure`)."""
        fc = self.fc
        n = fc.n if fc.merge else min(fc.n, d.ncon)
        if n == 0:
            return
        self.reserve(n)
        adr, efc = fc.slice_rows(d)[:2]  # per slice contact (with one contact per tooth flank: its force split)
        cv = self.cv
        self.m = pattern_rows(i, adr, efc, fc.meta, fc.weight, cv.inv_rho, cv.line_len, self.e_star, self.buf, self.m)

    def reserve(self, n: int) -> None:
        """Room for n more rows."""
        while self.m + n > len(self.buf):
            self.buf = np.concatenate([self.buf, np.zeros_like(self.buf)])

    def truncate(self, n: int) -> None:
        """Drop the rows of samples n and later (a run that ended early: wormsim.physics.locking)."""
        keep = self.buf[: self.m][self.buf[: self.m, 0] < n]
        self.buf[: len(keep)] = keep
        self.m = len(keep)
        self._rows = None

    def table(self) -> np.ndarray:
        """The log as float64 rows (i, sigma, j, f, F_n, p_H, zeta, rho): zeta the slice centre, rho the flank radius
        at the contact's profile position."""
        T = self.buf[: self.m].astype(float)
        if not len(T):
            return np.zeros((0, 8))
        j = T[:, 2].astype(np.int64)
        rho = _lerp_rows(self.rho3, T[:, 1].astype(np.int64), j, T[:, 3])
        return np.column_stack([T, self.cv.zeta[j], rho])

    def window_rows(self, t_s: np.ndarray, window_s) -> tuple[np.ndarray, np.ndarray]:
        """The rows of table() with a positive F_n in samples with t in window_s, and their averaged pressure (4) (the
        line load and curvature averaged over the window of slices centred on the row, within its contact line; nan
        for a row without a p_H of its own), computed over all rows of the log (the cumulative sums from its first
        row) and kept for the window's rows, compiled in one pass over the log (`_window_rows`) without the
        whole table (1.5 million rows in a run that records every step of 0.3 s at 2e-5 s: about 0.25 s of numpy);
        computed once for summary and grid (rows are only appended or truncated, so the row count names the log)."""
        inwin = (t_s >= window_s[0]) & (t_s <= window_s[1])
        if self._rows is None or self._rows[0] != self.m or not np.array_equal(self._rows[1], inwin):
            cv = self.cv
            length = PRESSURE_LENGTH_MX * self.geo.m_x
            n = max(1, math.ceil(length / cv.slice_width - 1e-9))
            args = (cv.inv_rho, self.rho3, cv.zeta, float(self.e_star), length, n)
            self._rows = (self.m, inwin, _window_rows(self.buf, self.m, inwin, *args))
        return self._rows[2]

    def summary(self, t_s: np.ndarray, window_s) -> dict:
        """The summary keys of the module docstring over the samples with t in window_s."""
        sel, pavg = self.window_rows(t_s, window_s)
        nan = float("nan")
        keys = {
            "contact_pattern_centroid_face_mm": nan,
            "contact_pattern_centroid_radius_mm": nan,
            "contact_pattern_extent_face_mm": nan,
            "contact_pressure_max_mpa": nan,
            "contact_pressure_mean_mpa": nan,
            "contact_pressure_max_face_mm": nan,
            "contact_pressure_max_radius_mm": nan,
            "contact_pattern_source": "loaded (contact3d exact flanks), contact normal force-weighted over the "
            "steady window",
        }
        if not len(sel):
            return keys
        fn, p, z, r = sel[:, 4], sel[:, 5], sel[:, 6], sel[:, 7]
        W = fn.sum()
        finite = np.isfinite(pavg)
        imax = int(np.argmax(np.where(finite, pavg, -np.inf)))
        ok = np.isfinite(p)  # (_rows: no line length, no p_H)
        keys.update(
            {
                "contact_pattern_centroid_face_mm": float((fn * z).sum() / W * 1e3),
                "contact_pattern_centroid_radius_mm": float((fn * r).sum() / W * 1e3),
                "contact_pattern_extent_face_mm": float(self.extent_face_m(sel) * 1e3),
                "contact_pressure_max_mpa": float(pavg[imax] * 1e-6) if finite.any() else nan,
                "contact_pressure_mean_mpa": float((fn[ok] * p[ok]).sum() / fn[ok].sum() * 1e-6),
                "contact_pressure_max_face_mm": float(z[imax] * 1e3) if finite.any() else nan,
                "contact_pressure_max_radius_mm": float(r[imax] * 1e3) if finite.any() else nan,
            }
        )
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
        T, pavg = self.window_rows(t_s, window_s)
        S, N = self.cv.rho.shape
        load = np.zeros((2, S, N))
        pmax = np.zeros((2, S, N))
        _grid_cells(T, pavg, load, pmax)  # also without rows: a run's first call loads the compiled code
        return {
            "load": load,
            "pressure_max_pa": pmax,
            "rho_m": self.cv.rho,
            "zeta_m": self.cv.zeta,
            "slice_width_m": self.cv.slice_width,
            "xy_m": self.fc.grid.xy,
        }


def draw_tooth_outline(ax, geo: GearGeometry) -> None:
    """The wheel tooth's tip (throat torus, capped at the rim), r2 and root (root torus) across the face, dashed over
    the pattern, each named where it is unambiguous: the tip and r2 in the right margin at the face edge, the root
    (lowest at the mid-plane) under its lowest point, with the radius there."""
    zf = np.linspace(-geo.face_width / 2, geo.face_width / 2, 101)
    edge = 0.5 * geo.face_width * 1e3
    tip, root = wheel.tip_rho(geo, zf), wheel.root_rho(geo, zf)
    for r_, lab, (x, y, va) in (
        (tip, f"tip {tip[-1] * 1e3:.2f} mm (face edge)", (1.04 * edge, tip[-1] * 1e3, "center")),
        (np.full_like(zf, geo.r2), f"r2 {geo.r2 * 1e3:.2f} mm", (1.04 * edge, geo.r2 * 1e3, "center")),
        (root, f"wheel root {geo.r_f2 * 1e3:.2f} mm (mid-plane)", (0.0, float(root.min()) * 1e3, "top")),
    ):
        ax.plot(zf * 1e3, r_ * 1e3, color="0.55", lw=0.8, ls="--", zorder=3)
        ax.annotate(
            lab,
            (x, y),
            xytext=(0, -4 if va == "top" else 0),
            textcoords="offset points",
            fontsize=8,
            va=va,
            ha="center" if va == "top" else "left",
            zorder=4,
            bbox=dict(facecolor="white", edgecolor="0.6", alpha=0.9, pad=1.5),
        )


def draw_pattern(ax, fig, grid: dict, geo: GearGeometry, summary: dict) -> None:
    """report.png's pattern panel with flanks: the loaded cells of the working flank (the one carrying more load) as
    a band, face position against flank radius, coloured by the largest Hertz pressure (3) over the steady window;
    the load centroid, the 95 % load span across the face and where the largest pressure sits."""
    from matplotlib.collections import PolyCollection

    load, pmax = grid["load"], grid["pressure_max_pa"]
    sg = int(np.argmax(load.sum(axis=(1, 2))))
    L, P, R, Z, w = load[sg], pmax[sg] * 1e-6, grid["rho_m"] * 1e3, grid["zeta_m"] * 1e3, grid["slice_width_m"] * 1e3
    keep = L > 1e-3 * max(float(L.max()), 1e-300)
    dr = np.gradient(R, axis=1)
    polys, vals = [], []
    # per face slice, the band from its lowest to its highest loaded cell: cells inside it that the sampled contact
    # lines missed are filled with the pressure interpolated along the slice, so sampling leaves no white stripes
    for j in range(keep.shape[0]):
        idx = np.nonzero(keep[j])[0]
        if not len(idx):
            continue
        cells = np.arange(idx[0], idx[-1] + 1)
        pj = np.interp(cells, idx, P[j, idx])
        x0, x1 = Z[j] - w / 2, Z[j] + w / 2
        for i, pv in zip(cells, pj, strict=True):
            y0, y1 = R[j, i] - dr[j, i] / 2, R[j, i] + dr[j, i] / 2
            polys.append([(x0, y0), (x1, y0), (x1, y1), (x0, y1)])
            vals.append(pv)
    if polys:
        # the cells' own colour as edge colour: no hairline gaps between neighbouring cells when rasterised
        pc = PolyCollection(polys, array=np.asarray(vals), cmap="inferno", edgecolors="face", linewidths=0.3)
        ax.add_collection(pc)
        fig.colorbar(pc, ax=ax, label="largest Hertz pressure p_H [MPa]")
    cz, cr = summary.get("contact_pattern_centroid_face_mm"), summary.get("contact_pattern_centroid_radius_mm")
    ext = summary.get("contact_pattern_extent_face_mm", float("nan"))
    if cz is not None and np.isfinite(cz):
        ax.plot([cz], [cr], "c+", ms=14, mew=2, label=f"load centroid ({cz:.2f} mm, {cr:.2f} mm)")
        ax.axvline(cz, color="c", lw=0.6, ls=":")
    if np.isfinite(ext):
        ax.plot([], [], " ", label=f"95 % of the load within {ext:.2f} mm of face")
    pz, prr = summary.get("contact_pressure_max_face_mm"), summary.get("contact_pressure_max_radius_mm")
    if pz is not None and np.isfinite(pz):
        ax.plot(
            [pz],
            [prr],
            "*",
            color="lime",
            mec="k",
            ms=12,
            label=f"p_H max {summary['contact_pressure_max_mpa']:.0f} MPa "
            f"(mean {summary['contact_pressure_mean_mpa']:.0f} MPa)",
        )
    draw_tooth_outline(ax, geo)
    ax.set_xlim(-0.6 * geo.face_width * 1e3, 1.15 * geo.face_width * 1e3)
    lo = min(geo.r_f2, float(np.nanmin(R)) * 1e-3) * 1e3
    hi = max(geo.r_a2, float(np.nanmax(R)) * 1e-3) * 1e3
    ax.set_ylim(lo - 0.15 * (hi - lo), hi + 0.25 * (hi - lo))
    ax.legend(fontsize=7, loc="upper left")
    ax.set(
        xlabel="across the face: wheel axis position, 0 at the mid-plane [mm]",
        ylabel="wheel radius [mm]",
        title=f"contact pattern on the wheel flank ({'AB'[sg]}, exact flanks, steady window)",
    )


def log_pattern(rec, path: str, grid: dict, geo: GearGeometry) -> None:
    """The recording's pattern: every loaded grid cell of both flanks, on every wheel tooth (the steady-window
    pattern repeats tooth to tooth), as points in the wheel frame (`path` under the moving wheel), coloured by the
    largest Hertz pressure (inferno, 0 .. the run's largest) and sized by the slice width. Logged once (static)."""
    import matplotlib
    import rerun as rr

    load, pmax, xy = grid["load"], grid["pressure_max_pa"], grid["xy_m"]
    keep = load > 1e-3 * max(float(load.max()), 1e-300)
    if not keep.any():
        return
    sg, j, i = np.nonzero(keep)
    p = pmax[sg, j, i]
    base = np.column_stack([xy[sg, j, i, 0], xy[sg, j, i, 1], grid["zeta_m"][j]])
    ang = 2 * np.pi * np.arange(geo.z2) / geo.z2
    c, s = np.cos(ang)[:, None], np.sin(ang)[:, None]
    pts = np.stack(
        [
            c * base[None, :, 0] - s * base[None, :, 1],
            s * base[None, :, 0] + c * base[None, :, 1],
            np.broadcast_to(base[None, :, 2], c.shape[:1] + base.shape[:1]),
        ],
        axis=-1,
    ).reshape(-1, 3)
    rgb = (matplotlib.colormaps["inferno"](p / max(float(p.max()), 1e-300))[:, :3] * 255).astype(np.uint8)
    rr.log(
        path,
        rr.Points3D(pts, colors=np.tile(rgb, (geo.z2, 1)), radii=0.3 * grid["slice_width_m"]),
        static=True,
        recording=rec,
    )
