"""Exact-flank tooth contact of contact3d (`contact.geometry: flanks`): the geometry kernel.

Per gear, once (`flank_grid`, cached in process): the wheel's generated flanks of tooth 0 on a grid of S SLICES
across the face (zeta_j = slice centres, zeta across the face, 0 at the mid-plane) by N_PROFILE points along the
profile (rho from the worm tip's reach, or the wheel root, to the wheel tip: the active zone of
wormsim.torsional.mesh_stiffness), from meshgen.wheel.tooth_flanks / space_flank (the envelope; no equation repeated
here). Flank A of tooth 0 is psi_+ of tooth space 0 (it faces -psi), flank B is psi_- of space 1; backlash applied.
With each point goes its conjugate wheel angle c = beta - psi (mesh_stiffness (1)): tooth k's flank point touches
the conjugate worm at wheel angle theta2 = c - 2 pi (k + sigma) / z2 (sigma = 0 flank A, 1 flank B). Points cut by
the hob tip edge (root fillet, not conjugate) are left out: exact flanks carry the working flanks only.

Each step (`find_contacts`, numba): for every wheel tooth k of the mesh window and both flanks, and for every slice
whose conjugate angles come within `margin` of the current wheel angle, the kernel starts at the profile point whose
conjugate angle is nearest (bisection) and descends along the profile to the gap's minimum, so a step costs about three
points per slice. A point of tooth k at wheel
angle theta2 sits in the assembly at (rho cos b, rho sin b, zeta), b = psi + theta2 + 2 pi k / z2, and in the
static worm frame (meshgen.assembly: x_s = y + a, y_s = -z, z_s = -x) at radius r and angle phi. Its signed
normal distance from the worm thread is the closed form of meshgen.worm.thread_gap (equations (1), (2) there):

    u = wrap(z_s - p (phi - theta1), p_x),   G = (|u| - H(r)) / |grad G|,
    grad G = sign(u) (e_z - (p / r) e_phi) - H'(r) e_r,                                              (1)

negative inside the thread, valid for r_f1 <= r <= r_a1 and |z_s| <= b1 / 2; the kernel evaluates it past these
bounds too (the flank extended, worm_gap_ext) and, where the minimum lies outside, takes the worm's edge on the wheel
flank (where the excess crosses zero), so contacts enter and leave at zero depth (docs/contact3d.md). In each slice
the deepest point along the profile is refined by the parabola through it and its two neighbours (the gap across a
contact line is quadratic; blended with the next parabola towards its vertex, and at the active profile's end the one
through the end and its two inner neighbours, so the line's depth and point are continuous in the mesh angle),
giving ONE contact per (tooth, flank, slice): depth delta = -G_min, normal
n = grad G / |grad G| in the assembly frame (from the worm into the wheel: the force on the wheel is along +n),
position = the wheel point moved delta / 2 along n (MuJoCo's midpoint). A tooth pair whose contact line spans the face
thus gives S contacts of stiffness K / S each (wormsim.contact3d.law, n_ref = S): the slice method of gear dynamics;
slice_weights scales each by the share of its slice the contact line covers (the line's end interpolated with the
excess's own slope across the face at the line's point, _face_slope). Where the
line's point lies past the wheel's active profile, the contact is the profile's end (the wheel's tip edge, or the
end at the worm tip's reach) pressed into the worm flank, its depth the gap there; its depth fades linearly to zero
over the outer TAPER_SHARE of the candidate window, so that it leaves at zero load also where the flanks are still
pressed together at the window's edge (seat motor: 30 um deep, 0.1 pitch past the profile's end).

The kernel repeats the worm's H(r) (meshgen.worm.half_thickness, ZI/ZA; ZN/ZK/ZC meshgen.worm_forms_jit) compiled;
tests/test_flank_contact.py pins the kernel's distance to meshgen.worm.thread_gap.
"""

from __future__ import annotations

import functools
import hashlib
import math
import sys
from dataclasses import asdict, dataclass

import numba
import numpy as np

from meshgen import wheel, worm, worm_forms, worm_forms_jit
from meshgen.cache import cached
from meshgen.geometry import GearGeometry
from wormsim.contact3d.flank_merge import merge_flanks
from wormsim.contact3d.flank_pose import N_WORM_PARAMS, static_dir_to_world, to_static, tooth_angle

N_PROFILE = 64  # points along the profile per slice (the parabola refines between them)
SLICES_COARSE = 8  # simulation.resolution coarse: a quick look (not converged; docs/contact3d.md)
SLICE_SHARE = 0.2  # medium and fine: a slice's stiffness K / S at most this share of the mesh stiffness's p2p
SLICES_STEP = 8  # the count rounded up to a multiple of this
SLICES_TCA_SAMPLES = 128  # worm angles per mesh cycle of the TCA that gives the fluctuation
# Default slices of a mass-scaled run, at most: mass scaling keeps the means and loses the fluctuation
# (docs/contact3d.md, "Mass scaling"), which default_slices sizes the slices for; the means converge from 16 (seat
# motor 20 s at S = 5000, 16 / 32 slices: efficiency 0.61286 / 0.61279, F_t mean 1289.160 / 1289.169 N; 105 / 196
# us per step)
SLICES_MASS_SCALED = 16
TAPER_SHARE = 0.5  # outer share of the candidate margin over which an edge contact's depth fades to zero
MARGIN_PITCH = 0.10  # candidate points: conjugate angle within this fraction of a pitch (plus the backlash
# angle and the transmission error, find_contacts' margin) of the wheel angle
MEMO_GAP_SHARE = 0.5  # a memorised open slice is skipped while its bound keeps this share of the gap it had
MEMO_JITTER_MODULE = 1e-3  # allowance (x m_x) for the slice minimum's change at constant TE (measured <= 1.5e-5)
MEMO_AGE_CYCLE = 1.0 / 8  # a memorised slice is evaluated again after this share of a mesh cycle of worm rotation
INSIDE_SHARE = 0.5 * (1.0 + 1e-3)  # line points deeper inside than this x the slice width: weight 1 without the face
# slope (its |change| across a slice is at most the slice width; 1e-3 is far above the slope's round-off)


def default_slices(g: GearGeometry, resolution: str) -> int:
    """Slices across the face when contact.slices is not given. Each slice switches a stiffness of up to K / S as the
    contact line's end crosses it, and rings the contact mode; the slicing resolves the mesh stiffness's own change
    over a mesh cycle once K / S is small against it:

        S = SLICES_STEP ceil(k_mean / (SLICE_SHARE k_p2p) / SLICES_STEP),

    k_p2p / k_mean the fluctuation of the zero-load TCA's k(theta) (wormsim.torsional.mesh_stiffness, both flank
    sides, the smaller). Measured (docs/contact3d.md, "Default slice count"): seat motor 0.177 -> 32 slices (16 were
    not converged), screw jack 0.376 -> 16, involute_41 0.267 -> 24. Coarse: SLICES_COARSE."""
    if resolution == "coarse":
        return SLICES_COARSE
    from wormsim.torsional.mesh_stiffness import mesh_stiffness

    ms = mesh_stiffness(g, 1.0, "slices", SLICES_TCA_SAMPLES)
    share = min(float(np.ptp(k) / np.mean(k)) for k in (ms.k_mesh_fwd_n_per_m, ms.k_mesh_rev_n_per_m))
    return int(SLICES_STEP * math.ceil(1.0 / (SLICE_SHARE * max(share, 1e-3)) / SLICES_STEP))


@dataclass(frozen=True)
class FlankGrid:
    """Tooth 0's two active flanks on (slice, profile) grids; wheel frame, SI."""

    slices: int
    zeta: np.ndarray  # (S,) slice centres
    rho: np.ndarray  # (S, N) radius of the profile points
    psi: np.ndarray  # (2, S, N) polar angle (flank A, flank B), nan where not an active flank point
    xy: np.ndarray  # (2, S, N, 2) the points' (x, y) in the wheel frame (rho cos psi, rho sin psi)
    c: np.ndarray  # (2, S, N) conjugate wheel angle, nan where not active
    c_range: np.ndarray  # (2, S, 2) min and max of c per flank and slice (whole slices are skipped by it)
    span: np.ndarray  # (2, S, 2) first and last active profile index per flank and slice (c is monotone
    # between them; -1, -1 where a slice has none)
    params: np.ndarray  # worm scalars for the kernel (worm_params)


def worm_params(g: GearGeometry) -> np.ndarray:
    """Scalars of meshgen.worm's closed form, in the order the kernel reads them."""
    zi = 1.0 if g.profile == "ZI" else 2.0 if g.profile in worm_forms.TABLE_FORMS else 0.0
    t1 = math.sqrt(max(g.r1**2 / g.r_b**2 - 1.0, 0.0)) if zi == 1.0 else 0.0
    table = worm_forms.form_table(g).params() if zi == 2.0 else np.zeros(worm_forms_jit.TABLE_LEN)
    head = np.array(
        [
            g.p,
            g.p_x,
            g.r_f1,
            g.r_a1,
            g.worm_length / 2,
            zi,
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
    return np.concatenate([head, table])  # ZN, ZK, ZC: H(r)'s table at P[13:] (meshgen.worm_forms_jit)


@functools.lru_cache(maxsize=16)
def flank_grid(g: GearGeometry, slices: int, n_profile: int = N_PROFILE) -> FlankGrid:
    """The grids of the module docstring (meshgen.wheel's envelope, both flanks of tooth 0); in process and on disk
    (meshgen.cache, keyed by the geometry, the grid size and the source of the modules that compute the grid)."""
    parts = {"g": asdict(g), "slices": slices, "n_profile": n_profile, "code": _grid_code_hash()}
    return cached("flankgrid", parts, lambda: _flank_grid(g, slices, n_profile))


@functools.cache
def _grid_code_hash() -> str:
    """SHA-256 of the source that determines flank_grid's result (this module, the trim, the pose, the window and
    meshgen's geometry, worm and wheel)."""
    import inspect

    from meshgen import geometry as mg
    from wormsim.contact3d import flank_pose, flank_trim, window

    mods = (sys.modules[__name__], flank_trim, flank_pose, window, mg, worm, wheel, worm_forms)
    return hashlib.sha256("".join(inspect.getsource(m) for m in mods).encode()).hexdigest()


def _flank_grid(g: GearGeometry, slices: int, n_profile: int) -> FlankGrid:
    bw = g.face_width
    zeta = -bw / 2 + (np.arange(slices) + 0.5) * bw / slices
    lo = np.maximum(g.a - np.sqrt(np.maximum(g.r_a1**2 - zeta**2, 0.0)), wheel.root_rho(g, zeta))
    hi = wheel.tip_rho(g, zeta)
    s = np.linspace(0.0, 1.0, n_profile)
    R = lo[:, None] + (hi - lo)[:, None] * s[None, :]
    Z = np.broadcast_to(zeta[:, None], R.shape)
    dj = g.backlash / (2 * g.r2)
    pitch = 2 * math.pi / g.z2
    psi = np.full((2,) + R.shape, np.nan)
    c = np.full((2,) + R.shape, np.nan)
    for i, side in enumerate((+1, -1)):
        sol = wheel.space_flank(g, R, Z, side)
        ok = sol.interior & (hi > lo)[:, None]
        ok &= ~_cut_by_worm(g, R, sol.psi, zeta)
        # flank A: psi_+ of space 0 + dj; flank B: psi_- of space 0 + pitch - dj (meshgen.wheel.tooth_flanks);
        # c is the conjugate angle of the unshifted space-0 flank (flank B's tooth space is 1: sigma in find_contacts)
        shift = dj if side > 0 else pitch - dj
        psi[i] = np.where(ok, sol.psi + shift, np.nan)
        c[i] = np.where(ok, sol.beta - sol.psi, np.nan)
    with np.errstate(all="ignore"):
        rng = np.stack([np.nanmin(c, axis=2), np.nanmax(c, axis=2)], axis=-1)
    rng = np.where(np.isfinite(rng), rng, np.array([np.inf, -np.inf]))
    xy = np.stack([R * np.cos(psi), R * np.sin(psi)], axis=-1)
    act = np.isfinite(c)
    first = np.where(act.any(axis=2), np.argmax(act, axis=2), -1)
    last = np.where(act.any(axis=2), n_profile - 1 - np.argmax(act[:, :, ::-1], axis=2), -1)
    span = np.stack([first, last], axis=-1).astype(np.int64)
    return FlankGrid(
        slices=slices, zeta=zeta, rho=R, psi=psi, xy=xy, c=c, c_range=rng, span=span, params=worm_params(g)
    )


def _cut_by_worm(g: GearGeometry, R: np.ndarray, psi0: np.ndarray, zeta: np.ndarray) -> np.ndarray:
    """Envelope points of tooth space 0 that the conjugate worm cuts into (wormsim.contact3d.flank_trim)."""
    from wormsim.contact3d.flank_trim import cut_points
    from wormsim.contact3d.window import window_size

    xy = np.stack([R * np.cos(psi0), R * np.sin(psi0)], axis=-1)[None]
    return cut_points(xy, zeta, worm_params(g), float(window_size(g)))[0]


@numba.njit(cache=True, inline="always")
def _half_thickness(r, P):
    """meshgen.worm.half_thickness and its derivative dH/dr (ZI equation (2), ZA straight; ZN, ZK, ZC the table)."""
    p, p_x, r1 = P[0], P[1], P[9]
    if P[5] > 1.5:
        return worm_forms_jit.half_thickness(r, P, 13)
    if P[5] > 0.5:
        r_b = P[6]
        x = r * r / (r_b * r_b) - 1.0
        t = math.sqrt(x) if x > 0.0 else 0.0
        ap = abs(p)
        return p_x / 4 - ap * ((t - math.atan(t)) - P[8]), -ap * t / r
    return p_x / 4 - (r - r1) * P[7], -P[7]


@numba.njit(cache=True, inline="always")
def _wrap(x, period):
    """x wrapped to [-period / 2, period / 2): Python's (x + period / 2) % period - period / 2 with floor, inlined
    (numba's float % calls a helper around fmod: 15 % of the kernel's time); equal to it within an ulp of x."""
    w = x + 0.5 * period
    return w - period * math.floor(w / period) - 0.5 * period


@numba.njit(cache=True, inline="always")
def worm_gap_ext(xs, ys, zs, theta1, P, out):
    """Signed normal distance (1) of a static-worm-frame point from the thread flank extended past the worm's tip,
    root and end faces, the unit gradient (static worm frame) in out[0:3], and the excess (m) by which the point is
    outside the threaded region: max(r - r_a1, r_f1 - r, |z_s| - b1/2) (<= 0 inside). Returns (gap, excess)."""
    r = math.sqrt(xs * xs + ys * ys)
    ex = max(r - P[3], P[2] - r, abs(zs) - P[4])
    p, p_x = P[0], P[1]
    phi = math.atan2(ys, xs)
    u = _wrap(zs - p * (phi - theta1), p_x)
    H, dH = _half_thickness(r, P)
    sg = 1.0 if u >= 0.0 else -1.0
    ir = 1.0 / r
    cp, sp = xs * ir, ys * ir
    # grad G = sg (e_z - p/r e_phi) - H' e_r, e_r = (c, s, 0), e_phi = (-s, c, 0)
    gx = sg * (p * ir) * sp - dH * cp
    gy = -sg * (p * ir) * cp - dH * sp
    gz = sg
    inrm = 1.0 / math.sqrt(gx * gx + gy * gy + gz * gz)
    out[0], out[1], out[2] = gx * inrm, gy * inrm, gz * inrm
    return (abs(u) - H) * inrm, ex


@numba.njit(cache=True)
def worm_gap(xs, ys, zs, theta1, P, out):
    """Signed normal distance (1) of a static-worm-frame point and the unit gradient (static worm frame) in out[0:3].
    Returns +inf where there is no thread (r outside [r_f1, r_a1] or |z_s| > b1/2)."""
    gv, ex = worm_gap_ext(xs, ys, zs, theta1, P, out)
    return np.inf if ex > 0.0 else gv


@numba.njit(cache=True, inline="always")
def _eval(x0, y0, zeta, ca, sa, theta1, P, out):
    """Extended gap and excess (worm_gap_ext) of the wheel point (x0, y0, zeta) turned by the angle (cos ca, sin sa)
    about z (assembly frame), and the turned point in out[3:6]. With a displaced pose in P
    (wormsim.contact3d.flank_pose) the turned point is in the wheel body's frame and goes through the poses instead
    (flank_pose.to_static)."""
    x, y = ca * x0 - sa * y0, sa * x0 + ca * y0
    if P.shape[0] > N_WORM_PARAMS:
        xs, ys, zs = to_static(x, y, zeta, P, out)
        return worm_gap_ext(xs, ys, zs, theta1, P, out)
    out[3], out[4], out[5] = x, y, zeta
    return worm_gap_ext(y + P[10], -zeta, -x, theta1, P, out)


@numba.njit(cache=True, inline="always")
def _excess(x0, y0, zeta, ca, sa, P, tmp):
    """The excess alone (worm_gap_ext's second value, the same operations) of the wheel point of _eval: a square root,
    no angle (the face slope needs no gap)."""
    x, y = ca * x0 - sa * y0, sa * x0 + ca * y0
    if P.shape[0] > N_WORM_PARAMS:
        xs, ys, zs = to_static(x, y, zeta, P, tmp)
    else:
        xs, ys, zs = y + P[10], -zeta, -x
    r = math.sqrt(xs * xs + ys * ys)
    return max(r - P[3], P[2] - r, abs(zs) - P[4])


@numba.njit(cache=True, inline="always")
def _gap_at(xy, sg, j, i, zeta, ca, sa, theta1, P, tmp, gaps, exc, pts, nrs, stamp, sid):
    """Extended gap of profile point i of (flank sg, slice j), evaluated once per slice (stamp[i] == sid) and kept in
    gaps, exc (excess), pts, nrs; +inf off the grid and at points that are not active flank points."""
    if i < 0 or i >= gaps.shape[0]:
        return np.inf
    if stamp[i] == sid:
        return gaps[i]
    stamp[i] = sid
    x0 = xy[sg, j, i, 0]
    if x0 != x0:
        gaps[i], exc[i] = np.inf, np.inf
        return np.inf
    gv, ex = _eval(x0, xy[sg, j, i, 1], zeta, ca, sa, theta1, P, tmp)
    gaps[i], exc[i] = gv, ex
    pts[i, 0], pts[i, 1], pts[i, 2] = tmp[3], tmp[4], tmp[5]
    nrs[i, 0], nrs[i, 1], nrs[i, 2] = tmp[0], tmp[1], tmp[2]
    return gv


@numba.njit(cache=True)
def find_contacts(
    xy, c, c_range, span, zeta, ks, theta1, theta2, margin, P, pos, nrm, depth, meta, line, taper_rad=0.0, memo=None
):
    """Contacts of the window teeth ks at worm angle theta1, wheel angle theta2 (module docstring). Writes per contact
    the assembly position pos (n, 3), unit normal nrm (n, 3) (worm -> wheel), depth (n,) > 0 and meta (n, 4) =
    (tooth k, flank sigma, slice j, fractional profile index), and line (n, 2) = (excess of the contact line's point
    in slice widths, e / |de| with de its change across one slice width (_face_slope; e / dz, dz the slice width, where
    the slice's strip lies wholly inside: slice_weights gives weight 1 either way); its depth: the extended gap's
    minimum, m) for slice_weights; returns n. A contact is written where the depth at
    the worm's edge or the line's depth is positive (depth may then be 0). The candidate window is margin plus the
    transmission error |theta2 - hand z1 / z2 theta1| (wrapped to a pitch), so a wheel pushed far into the
    worm keeps its contacts. Edge contacts fade to zero over the last taper_rad of the margin (default TAPER_SHARE x
    margin; with assembly errors the caller passes TAPER_SHARE x the error-free margin, so contacts that the errors
    move past the nominal conjugate range keep their full depth). memo (`flank_memo`, optional): the open-slice memo
    that skips slices whose flanks are clearly apart (`_find_contacts`); the contacts are the same with and without."""
    N = c.shape[2]
    if taper_rad <= 0.0:
        taper_rad = TAPER_SHARE * margin
    work = (np.empty(6), np.empty(N), np.empty(N), np.empty((N, 3)), np.empty((N, 3)), np.empty(N, dtype=np.int64))
    if memo is None:
        memo = (np.zeros((0, 2, 1, 3)), np.zeros(3))
    return _find_contacts(
        xy, c, c_range, span, zeta, ks, theta1, theta2, margin, taper_rad, P, (pos, nrm, depth, meta, line), work, memo
    )


def flank_memo(grid: FlankGrid, z2: int) -> tuple[np.ndarray, np.ndarray]:
    """Preallocated state of find_contacts' open-slice memo for one grid: table (z2, 2, S, 3) = per (tooth mod z2,
    flank, slice) the line depth's gap gline (> 0; 0 = nothing memorised), TE and theta1 when it was evaluated, and
    consts = (largest radius of a grid point, jitter allowance, largest worm-angle age) (`_find_contacts`)."""
    P = grid.params
    z1 = abs(P[12]) * 2 * math.pi / P[11]
    rho = float(np.nanmax(np.where(np.isfinite(grid.c), grid.rho[None], np.nan)))
    consts = np.array([rho, MEMO_JITTER_MODULE * P[1] / math.pi, MEMO_AGE_CYCLE * 2 * math.pi / z1])
    return np.zeros((z2, 2, grid.slices, 3)), consts


@numba.njit(cache=True, _nrt=False)
def _find_contacts(xy, c, c_range, span, zeta, ks, theta1, theta2, margin, taper_rad, P, out, work, memo):
    """find_contacts with its work arrays passed in, compiled without numba's reference counting (_nrt=False): the
    inlined helpers take arrays, and with it every helper call cost an atomic incref/decref pair per array (about
    60 % of the kernel's time; docs/contact3d.md, "Exact flanks: cost").

    The open-slice memo (memo = flank_memo(...); an empty table turns it off, as do displaced poses): a slice whose
    flanks were apart at its last evaluation, with the gap's minimum gline_e > 0 inside the profile (not at its ends,
    the parabola through three points, the line's point inside the threaded region), is skipped while
        gline_e - 2 rho_max |TE - TE_e| - J > MEMO_GAP_SHARE gline_e   and   |theta1 - theta1_e| <= age.
    Along the conjugate motion the minimum of such a slice depends on the TE alone (the flanks are conjugate): over
    recorded mesh cycles of the three seeds it moved by <= 1.5e-5 m_x at constant TE (J = 1e-3 m_x), and a point of the
    wheel moves by rho |dTE| relative to the conjugate pose (factor 2 for the gap's gradient). A skipped slice gives no
    contact, as its evaluation would: tests/test_flank_kernel_memo.py compares with and without over mesh cycles."""
    pos, nrm, depth, meta, line = out
    tmp, gaps, exc, pts, nrs, stamp = work
    mtab, mc = memo
    use_memo = mtab.shape[0] > 0 and P.shape[0] <= N_WORM_PARAMS
    S, N = c.shape[1], c.shape[2]
    pitch = P[11]
    te = _wrap(theta2 - P[12] * theta1, pitch)
    taper_end = margin  # edge contacts fade to zero at this distance past the profile's conjugate range
    margin = margin + abs(te)
    stamp[:] = -1
    sid = 0
    n = 0
    for kk in range(ks.shape[0]):
        k = ks[kk]
        ang = theta2 + pitch * k
        dk = 0.0
        if P.shape[0] > N_WORM_PARAMS:
            ang, dk = tooth_angle(k, P)  # wheel body frame, pitch deviation dk (flank_pose)
        ca, sa = math.cos(ang), math.sin(ang)
        for sg in range(2):
            target = _wrap(theta2 + pitch * (k + sg) + dk, 2 * math.pi)
            lo, hi = target - margin, target + margin
            for j in range(S):
                if hi < c_range[sg, j, 0] or lo > c_range[sg, j, 1]:
                    continue
                # an edge contact (the line's point past the active profile's end, the wheel's tip edge pressed into
                # the worm flank) fades to zero at the window's edge instead of being cut there with its load:
                # the line depth is scaled by the taper over the last taper_rad of the margin without the TE term
                # (a property of the slice's position, not of the wheel's lag; zero before the window cuts)
                out = max(c_range[sg, j, 0] - target, target - c_range[sg, j, 1], 0.0)
                taper = min(max((taper_end - out) / taper_rad, 0.0), 1.0)
                if use_memo:
                    km = k % mtab.shape[0]
                    ge = mtab[km, sg, j, 0]
                    if ge > 0.0:
                        if (
                            abs(theta1 - mtab[km, sg, j, 2]) <= mc[2]
                            and ge - 2.0 * mc[0] * abs(te - mtab[km, sg, j, 1]) - mc[1] > MEMO_GAP_SHARE * ge
                        ):
                            continue
                        mtab[km, sg, j, 0] = 0.0
                # start at the active point whose conjugate angle is nearest the target (the contact line's point;
                # bisection, c is monotone along the active profile)
                a, b = span[sg, j, 0], span[sg, j, 1]
                if a < 0:
                    continue
                inc = c[sg, j, b] > c[sg, j, a]
                while b - a > 1:
                    mid = (a + b) // 2
                    cm = c[sg, j, mid]
                    if cm != cm:  # a point trimmed inside the row (flank_trim): scan the row instead
                        a = -1
                        break
                    if (cm < target) == inc:
                        a = mid
                    else:
                        b = mid
                if a >= 0:
                    i_s = a if abs(c[sg, j, a] - target) <= abs(c[sg, j, b] - target) else b
                else:
                    i_s, dc = -1, np.inf
                    for i in range(span[sg, j, 0], span[sg, j, 1] + 1):
                        ci = c[sg, j, i]
                        if ci == ci and abs(ci - target) < dc:
                            dc, i_s = abs(ci - target), i
                sid += 1
                zj = zeta[j]
                ib = i_s
                best = _gap_at(xy, sg, j, ib, zj, ca, sa, theta1, P, tmp, gaps, exc, pts, nrs, stamp, sid)
                # descend along the profile to the minimum of the extended gap (one minimum per slice: the gap across
                # a contact line is quadratic)
                step = 0
                gl = _gap_at(xy, sg, j, ib - 1, zj, ca, sa, theta1, P, tmp, gaps, exc, pts, nrs, stamp, sid)
                gr = _gap_at(xy, sg, j, ib + 1, zj, ca, sa, theta1, P, tmp, gaps, exc, pts, nrs, stamp, sid)
                if gl < best and gl <= gr:
                    step, ib, best = -1, ib - 1, gl
                elif gr < best:
                    step, ib, best = 1, ib + 1, gr
                while step != 0:
                    gn = _gap_at(xy, sg, j, ib + step, zj, ca, sa, theta1, P, tmp, gaps, exc, pts, nrs, stamp, sid)
                    if gn < best:
                        ib, best = ib + step, gn
                    else:
                        break
                if best == np.inf:
                    continue
                gm = _gap_at(xy, sg, j, ib - 1, zj, ca, sa, theta1, P, tmp, gaps, exc, pts, nrs, stamp, sid)
                gp = _gap_at(xy, sg, j, ib + 1, zj, ca, sa, theta1, P, tmp, gaps, exc, pts, nrs, stamp, sid)
                # parabola q(x) = best + qa x + qb x^2 through the deepest point and its neighbours (the gap across a
                # contact line is quadratic; the extended gap is one smooth surface across the worm's edges)
                qa, qb, x = 0.0, 0.0, 0.0
                par = gm < np.inf and gp < np.inf and gm - 2.0 * best + gp > 0.0
                if par:
                    qa, qb = 0.5 * (gp - gm), 0.5 * (gm - 2.0 * best + gp)
                    x = -qa / (2.0 * qb)
                    # blended with the parabola through the next three points towards the vertex, by lam = |x| (0 at
                    # the grid point, 1/2 where the deepest point passes to the neighbour: there both sides blend the
                    # same two parabolas), so the line's depth and point do not step when the deepest point moves on
                    s1 = 1 if x > 0.0 else -1
                    g2 = _gap_at(xy, sg, j, ib + 2 * s1, zj, ca, sa, theta1, P, tmp, gaps, exc, pts, nrs, stamp, sid)
                    qa2, qb2, _, ok2 = _end_parabola(best, gp if s1 > 0 else gm, g2, s1)
                    if ok2 and x != 0.0:
                        lam = min(abs(x), 0.5)
                        qa, qb = (1.0 - lam) * qa + lam * qa2, (1.0 - lam) * qb + lam * qb2
                        x = -qa / (2.0 * qb)
                elif (gm == np.inf) != (gp == np.inf):
                    # the deepest point is the active profile's end: the parabola through it and its two inner
                    # neighbours (the one the central fit uses once the next point is deeper), its vertex clamped
                    # to the profile, so the line point moves continuously onto the end instead of jumping to it
                    s1 = 1 if gm == np.inf else -1
                    g1 = gp if s1 > 0 else gm
                    g2 = _gap_at(xy, sg, j, ib + 2 * s1, zj, ca, sa, theta1, P, tmp, gaps, exc, pts, nrs, stamp, sid)
                    qa, qb, x, par = _end_parabola(best, g1, g2, s1)
                x = min(max(x, -1.0), 1.0)
                nb = ib + 1 if x > 0.0 else ib - 1
                e_x = exc[ib] if x == 0.0 else exc[ib] + abs(x) * (exc[nb] - exc[ib])
                x_l = x
                if e_x <= 0.0:
                    gmin = best + qa * x + qb * x * x
                elif exc[ib] <= 0.0:
                    # the minimum lies just past the worm's tip, root or end face: the contact is the worm's edge on
                    # the wheel flank, where the excess crosses zero between ib and nb
                    x = (x / abs(x)) * exc[ib] / (exc[ib] - exc[nb])
                    gmin = best + qa * x + qb * x * x
                else:
                    # the minimum lies outside: walk towards the inside to the first point there; the edge contact
                    # sits where the excess crosses zero, its depth falls to zero continuously as the line moves on
                    step = -1 if (gm < np.inf and (gp == np.inf or exc[ib - 1] < exc[ib + 1])) else 1
                    ia = ib
                    gmin = np.inf
                    while True:
                        ibn = ia + step
                        gn = _gap_at(xy, sg, j, ibn, zj, ca, sa, theta1, P, tmp, gaps, exc, pts, nrs, stamp, sid)
                        if gn == np.inf:
                            break
                        if exc[ibn] <= 0.0:
                            w = exc[ia] / (exc[ia] - exc[ibn])
                            x = (ia - ib) + w * step
                            if par and abs(x) <= 1.0:
                                gmin = best + qa * x + qb * x * x
                            else:
                                gmin = gaps[ia] + w * (gn - gaps[ia])
                            break
                        ia = ibn
                        if gaps[ia] >= 0.0:
                            break  # past the parabola's reach: the linear crossings from here on are >= 0
                gline = best + qa * x_l + qb * x_l * x_l
                if gmin >= 0.0 and gline >= 0.0:
                    if use_memo and par and e_x <= 0.0 and gline > 0.0 and span[sg, j, 0] < ib < span[sg, j, 1]:
                        km = k % mtab.shape[0]
                        mtab[km, sg, j, 0], mtab[km, sg, j, 1], mtab[km, sg, j, 2] = gline, te, theta1
                    continue
                if gmin == np.inf:
                    x = x_l  # no edge inside reach: the line's point (only its weight can make it carry)
                # the contact point and normal at fractional index f, linear between the grid points around it
                f = ib + x
                i0 = min(int(math.floor(f)), N - 2)
                t = f - i0
                if t <= 0.0:
                    px, py, pz = pts[i0, 0], pts[i0, 1], pts[i0, 2]
                    nx, ny, nz = nrs[i0, 0], nrs[i0, 1], nrs[i0, 2]
                else:
                    px = (1 - t) * pts[i0, 0] + t * pts[i0 + 1, 0]
                    py = (1 - t) * pts[i0, 1] + t * pts[i0 + 1, 1]
                    pz = (1 - t) * pts[i0, 2] + t * pts[i0 + 1, 2]
                    nx = (1 - t) * nrs[i0, 0] + t * nrs[i0 + 1, 0]
                    ny = (1 - t) * nrs[i0, 1] + t * nrs[i0 + 1, 1]
                    nz = (1 - t) * nrs[i0, 2] + t * nrs[i0 + 1, 2]
                    nn = math.sqrt(nx * nx + ny * ny + nz * nz)
                    nx, ny, nz = nx / nn, ny / nn, nz / nn
                # static worm frame -> assembly: (x, y, z)_asm = (-z_s, x_s - a, -y_s), i.e. R0 applied
                ax, ay, az = -nz, nx, -ny
                if P.shape[0] > N_WORM_PARAMS:
                    ax, ay, az = static_dir_to_world(nx, ny, nz, P)
                dlt = -gmin if gmin < np.inf else -gline
                if n >= depth.shape[0]:
                    return n
                pos[n, 0] = px + 0.5 * dlt * ax
                pos[n, 1] = py + 0.5 * dlt * ay
                pos[n, 2] = pz + 0.5 * dlt * az
                nrm[n, 0], nrm[n, 1], nrm[n, 2] = ax, ay, az
                depth[n] = max(dlt, 0.0)
                dz = zeta[1] - zeta[0]
                if e_x < -INSIDE_SHARE * dz:
                    # the slice's strip lies wholly inside the threaded region: the excess changes by at most the
                    # distance moved (a max of distances), so |sl| <= dz, e / |sl| < -1/2 and the weight is 1
                    # either way (slice_weights); e / dz is kept instead of the slope's two evaluations
                    line[n, 0] = e_x / dz
                else:
                    line[n, 0] = _excess_in_slices(
                        e_x, _face_slope(xy, sg, j, ib + x_l, zj, dz, ca, sa, theta1, P, tmp)
                    )
                line[n, 1] = -gline * taper
                meta[n, 0], meta[n, 1], meta[n, 2], meta[n, 3] = k, sg, j, f
                n += 1
    return n


@numba.njit(cache=True, inline="always")
def _face_slope(xy, sg, j, f, zj, dz, ca, sa, theta1, P, tmp):
    """Change of the excess (worm_gap_ext) across one slice width at the line's point: the wheel point at fractional
    profile index f of (flank sg, slice j), its (x, y) linear between the grid points, moved by -dz/2 and +dz/2
    along the wheel axis. A property of the point alone, so each slice's weight is continuous in the mesh angle
    (slice_weights)."""
    i0 = int(math.floor(f))
    t = f - i0
    x0, y0 = xy[sg, j, i0, 0], xy[sg, j, i0, 1]
    if t > 0.0:
        x0 += t * (xy[sg, j, i0 + 1, 0] - x0)
        y0 += t * (xy[sg, j, i0 + 1, 1] - y0)
    return _excess(x0, y0, zj + 0.5 * dz, ca, sa, P, tmp) - _excess(x0, y0, zj - 0.5 * dz, ca, sa, P, tmp)


@numba.njit(cache=True, inline="always")
def _excess_in_slices(e, sl):
    """The line point's excess e in slice widths along the face, e / |sl| (sl: its change across one slice width,
    _face_slope): how far past the contact line's end the slice centre lies. +-inf where sl is 0 or undefined."""
    a = abs(sl)
    if a > 0.0:
        return e / a
    return -np.inf if e <= 0.0 else np.inf


@numba.njit(cache=True, inline="always")
def _end_parabola(g0, g1, g2, s1):
    """Parabola q(x) = g0 + qa x + qb x^2 through the gaps g0, g1, g2 at x = 0, s1, 2 s1 (s1 = +-1 towards the
    profile's inside, or towards the vertex), and its vertex clamped to that side (s1 x >= 0). Returns
    (qa, qb, x, ok); ok is False (x = 0) where the three points are not convex or g2 is missing."""
    if g2 == np.inf or g2 - 2.0 * g1 + g0 <= 0.0:
        return 0.0, 0.0, 0.0, False
    qb = 0.5 * (g2 - 2.0 * g1 + g0)
    qa = s1 * (g1 - g0 - qb)
    x = -qa / (2.0 * qb)
    if s1 * x < 0.0:
        x = 0.0
    return qa, qb, x, True


@numba.njit(cache=True)
def slice_weights(meta, line, n, slices, pos, nrm, depth, weight):
    """Line-end interpolation of the slice method: each contact's share w in [0, 1] of its slice's strip (width b2 / S)
    that the contact line covers, so that the mesh stiffness changes continuously as the line's end (where it runs
    past the worm's tip, root or end face: the line point's excess crosses 0) sweeps across the face, instead of by
    K / S when the end crosses a slice centre. line[:, 0] is the line point's excess in slice widths, e / |de|
    (find_contacts: de is the excess's change across one slice width at that point, _face_slope); with the excess
    linear across the strip, the covered share is w = clip(1/2 - e / |de|, 0, 1) (the trapezoidal rule for the line
    load with its end interpolated). The slope is the contact's own, not the neighbours' difference: with the
    neighbours' excess, a neighbour leaving the list (its slice leaving the candidate window, or a slice without
    one) switched the slope and stepped the weight at full depth (docs/contact3d.md). Keeps the contacts with w > 0
    (in place: pos, nrm, depth, meta, line), sets depth to the line's depth and weight to w; returns their number.
    meta and slices are kept in the signature for the callers."""
    m = 0
    for i in range(n):
        w = min(max(0.5 - line[i, 0], 0.0), 1.0)
        if w <= 0.0 or line[i, 1] <= 0.0:
            continue
        if m != i:
            for a in range(3):
                pos[m, a], nrm[m, a] = pos[i, a], nrm[i, a]
            for a in range(4):
                meta[m, a] = meta[i, a]
            line[m, 0], line[m, 1] = line[i, 0], line[i, 1]
        depth[m] = line[i, 1]
        weight[m] = w
        m += 1
    return m


@numba.njit(cache=True)
def contact_frames(nrm, n, frame):
    """MuJoCo contact frames (n, 9): the normal, then two unit tangents (mju_makeFrame's construction)."""
    for i in range(n):
        a0, a1, a2 = nrm[i, 0], nrm[i, 1], nrm[i, 2]
        # tangent 1: normal x (the axis least aligned with it)
        if abs(a0) < 0.5:
            t0, t1, t2 = 0.0, a2, -a1  # n x e_x
        else:
            t0, t1, t2 = -a2, 0.0, a0  # e_y x n
        tn = math.sqrt(t0 * t0 + t1 * t1 + t2 * t2)
        t0, t1, t2 = t0 / tn, t1 / tn, t2 / tn
        b0 = a1 * t2 - a2 * t1
        b1 = a2 * t0 - a0 * t2
        b2 = a0 * t1 - a1 * t0
        f = frame[i]
        f[0], f[1], f[2] = a0, a1, a2
        f[3], f[4], f[5] = t0, t1, t2
        f[6], f[7], f[8] = b0, b1, b2


_F_FIELDS = ("xy", "c", "c_range", "zeta", "P", "pos", "nrm", "depth", "meta", "line", "weight", "frame", "memo")
_F_FIELDS += ("memo_consts", "tmp", "gaps", "exc", "pts", "nrs")
_F_FIELDS += ("mpos", "mnrm", "mdepth", "mweight", "mframe", "grp", "share", "mfric", "mwrap", "axes")  # flank_merge
_I_HEADER = 8  # S, N, cap, len(P), W, z2, merge (one contact per tooth flank), merged contacts


def _shapes(S: int, N: int, cap: int, nP: int, W: int, z2: int) -> tuple[list, list]:
    """Shapes of the packed buffers' fields, in order (PackedKernel; find_packed unpacks the same order)."""
    f = [(2, S, N, 2), (2, S, N), (2, S, 2), (S,), (nP,), (cap, 3), (cap, 3), (cap,), (cap, 4), (cap, 2), (cap,)]
    f += [(cap, 9), (z2, 2, S, 3), (3,), (6,), (N,), (N,), (N, 3), (N, 3)]
    f += [(cap, 3), (cap, 3), (cap,), (cap,), (cap, 9), (cap,), (cap,), (cap,), (cap,), (13,)]
    return f, [(2, S, 2), (W,), (N,)]


class PackedKernel:
    """The kernel's inputs, outputs, memo and work arrays in one float and one int buffer, so that one compiled call,
    find_packed(fb, ib, theta1, theta2, margin, taper_rad), runs find_contacts, slice_weights and contact_frames:
    numba's dispatch costs ~0.25 us per array argument (the three calls with their 28 arrays and find_contacts' work
    allocation cost ~9 us of Python per step). The fields are numpy views of the buffers (pos, nrm, depth, meta, line,
    weight, frame, P, memo, span, ks: write ks and P in place). merge: also one contact per tooth flank
    (wormsim.contact3d.flank_merge: mpos, mnrm, mdepth, mweight, mframe, mfric, mwrap, their number in ib[7];
    grp, share; axes: the hinges, set by the caller)."""

    def __init__(self, grid: FlankGrid, P: np.ndarray, cap: int, W: int, z2: int, merge: bool = False):
        S, N = grid.slices, grid.c.shape[2]
        fs, is_ = _shapes(S, N, cap, len(P), W, z2)
        self.fb = np.zeros(sum(int(np.prod(sh)) for sh in fs))
        self.ib = np.zeros(_I_HEADER + sum(int(np.prod(sh)) for sh in is_), dtype=np.int64)
        self.ib[:7] = (S, N, cap, len(P), W, z2, int(merge))
        o = 0
        for name, sh in zip(_F_FIELDS, fs):
            k = int(np.prod(sh))
            setattr(self, name, self.fb[o : o + k].reshape(sh))
            o += k
        o = _I_HEADER
        for name, sh in zip(("span", "ks", "stamp"), is_):
            k = int(np.prod(sh))
            setattr(self, name, self.ib[o : o + k].reshape(sh))
            o += k
        self.xy[:], self.c[:], self.c_range[:], self.zeta[:] = grid.xy, grid.c, grid.c_range, grid.zeta
        self.span[:] = grid.span
        self.P[:] = P
        self.memo_consts[:] = flank_memo(grid, z2)[1]


@numba.njit(cache=True)
def find_packed(fb, ib, theta1, theta2, margin, taper_rad):
    """find_contacts (with its memo), slice_weights and contact_frames on a PackedKernel's buffers at worm angle
    theta1, wheel angle theta2 for the window teeth in its ks; returns the number of contacts (their fields in
    pos, nrm, depth, weight, frame, meta, line; with ib[6], the merged contacts as well, PackedKernel)."""
    S, N, cap, nP, W, z2 = ib[0], ib[1], ib[2], ib[3], ib[4], ib[5]
    o = 0
    xy = fb[o : o + 4 * S * N].reshape((2, S, N, 2))
    o += 4 * S * N
    c = fb[o : o + 2 * S * N].reshape((2, S, N))
    o += 2 * S * N
    c_range = fb[o : o + 4 * S].reshape((2, S, 2))
    o += 4 * S
    zeta = fb[o : o + S]
    o += S
    P = fb[o : o + nP]
    o += nP
    pos = fb[o : o + 3 * cap].reshape((cap, 3))
    o += 3 * cap
    nrm = fb[o : o + 3 * cap].reshape((cap, 3))
    o += 3 * cap
    depth = fb[o : o + cap]
    o += cap
    meta = fb[o : o + 4 * cap].reshape((cap, 4))
    o += 4 * cap
    line = fb[o : o + 2 * cap].reshape((cap, 2))
    o += 2 * cap
    weight = fb[o : o + cap]
    o += cap
    frame = fb[o : o + 9 * cap].reshape((cap, 9))
    o += 9 * cap
    mtab = fb[o : o + 6 * z2 * S].reshape((z2, 2, S, 3))
    o += 6 * z2 * S
    mc = fb[o : o + 3]
    o += 3
    tmp = fb[o : o + 6]
    o += 6
    gaps = fb[o : o + N]
    o += N
    exc = fb[o : o + N]
    o += N
    pts = fb[o : o + 3 * N].reshape((N, 3))
    o += 3 * N
    nrs = fb[o : o + 3 * N].reshape((N, 3))
    o += 3 * N
    mpos = fb[o : o + 3 * cap].reshape((cap, 3))
    o += 3 * cap
    mnrm = fb[o : o + 3 * cap].reshape((cap, 3))
    o += 3 * cap
    mdepth = fb[o : o + cap]
    o += cap
    mweight = fb[o : o + cap]
    o += cap
    mframe = fb[o : o + 9 * cap].reshape((cap, 9))
    o += 9 * cap
    grp = fb[o : o + cap]
    o += cap
    share = fb[o : o + cap]
    o += cap
    mfric = fb[o : o + cap]
    o += cap
    mwrap = fb[o : o + cap]
    o += cap
    axes = fb[o : o + 13]
    o = 8
    span = ib[o : o + 4 * S].reshape((2, S, 2))
    o += 4 * S
    ks = ib[o : o + W]
    o += W
    stamp = ib[o : o + N]
    if taper_rad <= 0.0:
        taper_rad = TAPER_SHARE * margin
    n = _find_contacts(
        xy,
        c,
        c_range,
        span,
        zeta,
        ks,
        theta1,
        theta2,
        margin,
        taper_rad,
        P,
        (pos, nrm, depth, meta, line),
        (tmp, gaps, exc, pts, nrs, stamp),
        (mtab, mc),
    )
    n = slice_weights(meta, line, n, S, pos, nrm, depth, weight)
    contact_frames(nrm, n, frame)
    if ib[6]:  # one contact per tooth flank (flank_merge)
        nm = merge_flanks(meta, n, pos, nrm, depth, weight, grp, share, mpos, mnrm, mdepth, mweight, mfric, mwrap, axes)
        ib[7] = nm
        contact_frames(mnrm, nm, mframe)
    return n


def gap_reference(g: GearGeometry, pts_static: np.ndarray, theta1: float) -> np.ndarray:
    """meshgen.worm.thread_gap on static-worm-frame points (the reference the kernel is tested against)."""
    return worm.thread_gap(g, pts_static, theta1)
