"""The exact-flank contact kernel: per step, the contacts of the window teeth with the worm, one per (tooth, flank,
slice), their slice weights and contact frames, packed in one compiled call (`find_packed`).

For every wheel tooth k of the mesh window and both flanks, and for every slice of the flank grid
(wormsim.tooth.grid) whose conjugate angles come within `margin` of the current wheel angle, `find_contacts` starts at
the profile point whose conjugate angle is nearest (walking from the slice's start point at its last evaluation, by
bisection the first time) and descends along the profile to the worm gap's
minimum (wormsim.tooth.gap), so a step costs about three points per slice. A point of tooth k at wheel angle theta2
sits in the assembly at (rho cos b, rho sin b, zeta), b = psi + theta2 + 2 pi k / z2; with assembly errors it goes
through the body poses (wormsim.tooth.pose). Where the gap's minimum lies past the worm's tip, root or end faces, the
kernel takes the worm's edge on the wheel flank (where the excess crosses zero), so contacts enter and leave at zero
depth. In each slice the deepest point along the profile is refined by the parabola through it and its two
neighbours (the gap across a contact line is quadratic; blended with the next parabola towards its vertex, and at
the active profile's end the one through the end and its two inner neighbours, so the line's depth and point are
continuous in the mesh angle), giving ONE contact per (tooth, flank, slice): depth delta = -G_min, normal
n = grad G / |grad G| in the assembly frame (from the worm into the wheel: the force on the wheel is along +n),
position = the wheel point moved delta / 2 along n (MuJoCo's midpoint). A tooth pair whose contact line spans the face
thus gives S contacts of stiffness K / S each (wormsim.contact3d.law, n_ref = S): the slice method of gear dynamics;
slice_weights scales each by the share of its slice the contact line covers (the line's ends interpolated with the
excess along the contact line to the neighbouring slices, _line_share). Where the line's point lies past the wheel's
active profile, the contact is the profile's end (the wheel's tip edge, or the end at the worm tip's reach) pressed into
the worm flank, its depth the gap there; its depth fades linearly to zero over the outer TAPER_SHARE of the candidate
window, so that it leaves at zero load also where the flanks are still pressed together at the window's edge (seat
motor: 30 um deep, 0.1 pitch past the profile's end). With `merge`, the contacts of one tooth flank are also merged into
one (wormsim.tooth.merge).
"""

from __future__ import annotations

import math

import numba
import numpy as np

from wormsim.tooth.gap import worm_gap_ext, wrap
from wormsim.tooth.grid import FlankGrid
from wormsim.tooth.merge import merge_flanks
from wormsim.tooth.pose import N_WORM_PARAMS, WHEEL, WORM, static_dir_to_world, to_static, tooth_angle

TAPER_SHARE = 0.5  # outer share of the candidate margin over which an edge contact's depth fades to zero
MARGIN_PITCH = 0.10  # candidate points: conjugate angle within this fraction of a pitch (plus the backlash
# angle and the transmission error, find_contacts' margin) of the wheel angle
MEMO_GAP_SHARE = 0.5  # a memorised open slice is skipped while its bound keeps this share of the gap it had
MEMO_JITTER_MODULE = 1e-3  # allowance (x m_x) for the slice minimum's change at constant TE (measured <= 1.5e-5)
MEMO_AGE_CYCLE = 1.0 / 8  # a memorised slice is evaluated again after this share of a mesh cycle of worm rotation
# _line_share's tip tuple where the line has no active segment or no neighbour: inside the tip edge, whole segment
_NO_TIP = (0.0, 0.0, 0.0, True, 1.0, 1e9)
MEMO_COLS = 6  # the memo table's columns: gline, TE, theta1, the pose's drift (_pose_drift) when it was evaluated;
# the slice's start point + 1 at its last evaluation (0: none; _start_near's hint, kept when the rest is forgotten);
# 1 where the slice is memorised by the motion's rate (its minimum at the profile's end or past the worm's edge)
MEMO_RATE_REACH = 2.0  # a rate-memorised slice's parabola has its vertex within this many profile points of ib
MEMO_RATE_GAIN = 20.0  # allowance on a grid point's gap change for the gaps derived from it (the parabola's value
# within MEMO_RATE_REACH points, its blend and the edge's interpolation: Lebesgue constants <= 17)
MEMO_CONSTS = 4  # rho_max, jitter allowance, age, the largest distance of a grid point from the wheel's origin
LINE_COLS = 7  # _line_point's cache per slice: f, i0, x, y, the tip's distance and its segment, the excess
TIP_SUBSTEPS = 32  # points across a slice where the contact line crosses the wheel's tip edge (_tip_depth)
INSIDE_SHARE = 0.75 * (1.0 + 1e-3)  # line points deeper inside than this x the distance to the neighbouring slices'
# line points: weight 1 without their excess (the quadratic through them changes by at most 3/4 of it within the slice;
# 1e-3 is far above the round-off; _line_share)


@numba.njit(cache=True, inline="always")
def _excess(x0, y0, zeta, ca, sa, P, tmp):
    """The excess alone (worm_gap_ext's second value, the same operations) of the wheel point of _g: a square root,
    no angle (the face slope needs no gap)."""
    x, y = ca * x0 - sa * y0, sa * x0 + ca * y0
    if P.shape[0] > N_WORM_PARAMS:
        xs, ys, zs = to_static(x, y, zeta, P, tmp)
    else:
        xs, ys, zs = y + P[10], -zeta, -x
    r = math.sqrt(xs * xs + ys * ys)
    return max(r - P[3], P[2] - r, abs(zs) - P[4])


@numba.njit(cache=True)
def find_contacts(grid, ks, theta1, theta2, margin, P, out, taper_rad=0.0, memo=None):
    """Contacts of the window teeth ks at worm angle theta1, wheel angle theta2 (module docstring); grid = (xy, c,
    c_range, span, zeta), the flank grid's arrays (wormsim.tooth.grid.FlankGrid), out = (pos, nrm, depth, meta,
    line), the arrays written. Writes per contact
    the assembly position pos (n, 3), unit normal nrm (n, 3) (worm -> wheel), depth (n,) > 0 and meta (n, 4) =
    (tooth k, flank sigma, slice j, fractional profile index), and line (n, 2) = (the share of its slice's strip
    that the contact line covers, _line_share; its depth: the extended gap's minimum, m) for slice_weights; returns
    n. A contact is written where the depth at
    the worm's edge or the line's depth is positive (depth may then be 0). The candidate window is margin plus the
    transmission error |theta2 - hand z1 / z2 theta1| (wrapped to a pitch), so a wheel pushed far into the
    worm keeps its contacts. Edge contacts fade to zero over the last taper_rad of the margin (default TAPER_SHARE x
    margin; with assembly errors the caller passes TAPER_SHARE x the error-free margin, so contacts that the errors
    move past the nominal conjugate range keep their full depth). memo (`flank_memo`, optional): the open-slice memo
    that skips slices whose flanks are clearly apart (`_find_contacts`); the contacts are the same with and without."""
    N = grid[1].shape[2]
    if taper_rad <= 0.0:
        taper_rad = TAPER_SHARE * margin
    S = grid[1].shape[1]
    line = (np.empty((S, LINE_COLS)), np.empty((S, 2), dtype=np.int64))  # _line_point's cache
    work = (np.empty(6), np.empty(N), np.empty(N), np.empty((N, 3)), np.empty((N, 3)), np.empty(N, dtype=np.int64))
    work = (work[0], work[1], work[2], work[3], work[4], work[5], line[0], line[1])
    if memo is None:
        memo = (np.zeros((0, 2, 1, MEMO_COLS)), np.zeros(MEMO_CONSTS))
    return _find_contacts(grid, ks, theta1, theta2, margin, taper_rad, P, out, work, memo)


def flank_memo(grid: FlankGrid, z2: int) -> tuple[np.ndarray, np.ndarray]:
    """Preallocated state of find_contacts' open-slice memo for one grid: table (z2, 2, S, MEMO_COLS) = per (tooth
    mod z2, flank, slice) the line depth's gap gline (> 0; 0 = nothing memorised; the slice's smallest gap where it is
    memorised by the motion's rate), TE, theta1 and the poses' drift when it was evaluated, the start point's hint
    and whether it is memorised by the motion's rate, and consts = (largest radius of a grid point, jitter
    allowance, largest worm-angle age, largest distance of a grid point from the wheel's origin) (`_find_contacts`,
    `_pose_drift`)."""
    P = grid.params
    z1 = abs(P[12]) * 2 * math.pi / P[11]
    rho = float(np.nanmax(np.where(np.isfinite(grid.c), grid.rho[None], np.nan)))
    reach = math.hypot(rho, float(np.max(np.abs(grid.zeta))))
    consts = np.array([rho, MEMO_JITTER_MODULE * P[1] / math.pi, MEMO_AGE_CYCLE * 2 * math.pi / z1, reach])
    return np.zeros((z2, 2, grid.slices, MEMO_COLS)), consts


@numba.njit(cache=True, _nrt=False)
def _find_contacts(grid, ks, theta1, theta2, margin, taper_rad, P, out, work, memo):
    """find_contacts with its work arrays passed in, compiled without numba's reference counting (_nrt=False): the
    inlined helpers take arrays, and with it every helper call cost an atomic incref/decref pair per array (about
    60 % of the kernel's time; docs/contact3d.md, "Exact flanks: cost"). Per window tooth, flank and slice in the
    candidate window: the memo's check (`_memo_skips`), the start point (`_start_near` from the memo table's last
    start point of the slice, `_start_point` without a memo), the slice's contact (`_slice_contact`).

    The open-slice memo (memo = flank_memo(...); an empty table turns it off): a slice whose flanks were apart at its
    last evaluation, with the gap's minimum gline_e > 0 inside the profile (not at its ends, the parabola through
    three points, the line's point inside the threaded region), is skipped while
        gline_e - 2 rho_max |TE - TE_e| - J - 2 (delta + delta_e) > MEMO_GAP_SHARE gline_e
    and |theta1 - theta1_e| <= age. Along the conjugate motion the minimum of such a slice depends on the TE alone
    (the flanks are conjugate): over recorded mesh cycles of the three seeds it moved by <= 1.5e-5 m_x at constant TE
    (J = 1e-3 m_x), and a point of the wheel moves by rho |dTE| relative to the conjugate pose (factor 2 for the gap's
    gradient). With displaced poses (wormsim.tooth.pose: errors:, shafts:) the flanks sit off the nominal assembly
    by delta (`_pose_drift`, now) and delta_e (at the slice's evaluation), the largest distance a wheel grid point
    lies from where the nominal assembly puts it: the gap then differs from the nominal assembly's by at most 2 delta
    (the same factor 2), so the nominal bound holds with 2 (delta + delta_e) more; delta = 0 for the nominal poses. A
    skipped slice gives no contact, as its evaluation would: tests/tooth/test_kernel_memo.py compares with and without
    over mesh cycles, nominal and with moving poses.

    An open slice whose minimum lies at the active profile's end or past the worm's edge (the contact line off the
    profile or the threaded region: its gap changes with the worm angle too) is memorised by the motion's rate with
    ge = min(gmin, gline, gvert) > 0 where its parabola's vertex lies within MEMO_RATE_REACH points, and skipped while
        ge - L (2 rho_max |TE - TE_e| + 2 (delta + delta_e) + (|p| + 2 rho_max |z1 / z2|) |theta1 - theta1_e|) - J
        > MEMO_GAP_SHARE ge
    and |theta1 - theta1_e| <= age: a wheel grid point's gap changes by at most |p| per unit of worm angle (the
    thread is a helicoid: turning the worm is moving it by p along its axis; |dG/dtheta1| = |p| / |grad| <= |p|) and
    by 2 rho_max per unit of wheel angle (theta2 - theta2_e = z1 / z2 (theta1 - theta1_e) + TE - TE_e), and the gaps
    derived from the grid points (the parabola within its reach, its blend, the edge's interpolation) by at most
    L = MEMO_RATE_GAIN times that."""
    xy, c, c_range, span, zeta = grid
    tmp, gaps, exc, pts, nrs, stamp, lcache, lstamp = work
    mtab, mc = memo
    use_memo = mtab.shape[0] > 0
    S = c.shape[1]
    pitch = P[11]
    te = wrap(theta2 - P[12] * theta1, pitch)
    drift = _pose_drift(P, theta2, mc[3]) if use_memo and P.shape[0] > N_WORM_PARAMS else 0.0
    rate = abs(P[0]) + 2.0 * mc[0] * abs(P[12]) if use_memo else 0.0  # _memo_skips' bound per unit of worm angle
    taper_end = margin  # edge contacts fade to zero at this distance past the profile's conjugate range
    margin = margin + abs(te)
    stamp[:] = -1
    lstamp[:] = -1
    sid = 0
    n = 0
    for kk in range(ks.shape[0]):
        k = ks[kk]
        ang = theta2 + pitch * k
        dk = 0.0
        if P.shape[0] > N_WORM_PARAMS:
            ang, dk = tooth_angle(k, P)  # wheel body frame, pitch deviation dk (wormsim.tooth.pose)
        ca, sa = math.cos(ang), math.sin(ang)
        ev = (xy, ca, sa, theta1, P, tmp, gaps, exc, pts, nrs, stamp)
        for sg in range(2):
            target = wrap(theta2 + pitch * (k + sg) + dk, 2 * math.pi)
            lo, hi = target - margin, target + margin
            for j in range(S):
                if hi < c_range[sg, j, 0] or lo > c_range[sg, j, 1]:
                    continue
                # an edge contact (the line's point past the active profile's end, the wheel's tip edge pressed into
                # the worm flank) fades to zero at the window's edge instead of being cut there with its load:
                # the line depth is scaled by the taper over the last taper_rad of the margin without the TE term
                # (a property of the slice's position, not of the wheel's lag; zero before the window cuts)
                past = max(c_range[sg, j, 0] - target, target - c_range[sg, j, 1], 0.0)
                taper = min(max((taper_end - past) / taper_rad, 0.0), 1.0)
                if use_memo and _memo_skips(mtab, mc, k, sg, j, theta1, te, drift, rate):
                    continue
                if span[sg, j, 0] < 0:
                    continue
                if use_memo:  # from the slice's start point at its last evaluation: a step or none
                    km = k % mtab.shape[0]
                    i_s = _start_near(c, span, sg, j, target, int(mtab[km, sg, j, 4]) - 1)
                    mtab[km, sg, j, 4] = i_s + 1.0
                else:
                    i_s = _start_point(c, span, sg, j, target)
                sid += 1
                memo_row = (use_memo, mtab, te, drift)
                # the conjugate contact line of this tooth flank at the current pose: conjugate angle target - TE
                # (the slice weights', _line_share), the tooth's own TE te + dk (a tooth with pitch deviation dk
                # meshes as the tooth turned by dk: its line is the undisplaced tooth's at the worm angle)
                sc = (span, c, target - te - dk, lcache, lstamp, 2 * kk + sg)
                n, full = _slice_contact(ev, sc, zeta, (sg, j, k), i_s, sid, taper, memo_row, out, n)
                if full:
                    return n
    return n


@numba.njit(cache=True, inline="always")
def _memo_skips(mtab, mc, k, sg, j, theta1, te, drift, rate):
    """The open-slice memo's check of (tooth k, flank sg, slice j) (_find_contacts); a memorised slice that is not
    skipped is forgotten. rate: |p| + 2 rho_max |z1 / z2| (the rate-memorised slices' bound per unit of worm angle)."""
    km = k % mtab.shape[0]
    ge = mtab[km, sg, j, 0]
    if ge > 0.0:
        d1 = abs(theta1 - mtab[km, sg, j, 2])
        if mtab[km, sg, j, 5] > 0.0:
            moved = 2.0 * mc[0] * abs(te - mtab[km, sg, j, 1]) + 2.0 * (drift + mtab[km, sg, j, 3]) + rate * d1
            if d1 <= mc[2] and ge - MEMO_RATE_GAIN * moved - mc[1] > MEMO_GAP_SHARE * ge:
                return True
        elif (
            d1 <= mc[2]
            and ge - 2.0 * mc[0] * abs(te - mtab[km, sg, j, 1]) - mc[1] - 2.0 * (drift + mtab[km, sg, j, 3])
            > MEMO_GAP_SHARE * ge
        ):
            return True
        mtab[km, sg, j, 0] = 0.0
    return False


@numba.njit(cache=True, inline="always")
def _pose_drift(P, theta2, reach):
    """delta of `_find_contacts`' memo: how far the displaced poses in P (wormsim.tooth.pose) put a wheel grid point
    from where the nominal assembly does, as a bound: with D = A^-1 X_g Rz(-theta2) the wheel's frame, its hinge
    angle taken out, in the static worm frame, and D0 the nominal (x, y, z) -> (y + a, -z, -x),
    |D q - D0 q| <= |t - t0| + ||R - R0||_F |q|, |q| <= reach (the grid's largest distance from the wheel's origin)."""
    cs, sn = math.cos(theta2), math.sin(theta2)
    d_t = 0.0
    d_r = 0.0
    for i in range(3):
        # column i of A's rotation, A's translation taken from the wheel's
        t = 0.0
        m0 = m1 = m2 = 0.0
        for r in range(3):
            a = P[WORM + 4 * r + i]
            g0, g1 = P[WHEEL + 4 * r], P[WHEEL + 4 * r + 1]
            m0 += a * (g0 * cs - g1 * sn)
            m1 += a * (g0 * sn + g1 * cs)
            m2 += a * P[WHEEL + 4 * r + 2]
            t += a * (P[WHEEL + 4 * r + 3] - P[WORM + 4 * r + 3])
        # the nominal rows: (0, 1, 0) + a e_x, (0, 0, -1), (-1, 0, 0)
        if i == 0:
            d_t += (t - P[10]) ** 2
            d_r += m0 * m0 + (m1 - 1.0) ** 2 + m2 * m2
        elif i == 1:
            d_t += t * t
            d_r += m0 * m0 + m1 * m1 + (m2 + 1.0) ** 2
        else:
            d_t += t * t
            d_r += (m0 + 1.0) ** 2 + m1 * m1 + m2 * m2
    return math.sqrt(d_t) + math.sqrt(d_r) * reach


@numba.njit(cache=True, inline="always")
def _start_point(c, span, sg, j, target):
    """The active point of (flank sg, slice j) whose conjugate angle is nearest the target (the contact line's point;
    bisection, c is monotone along the active profile; a row with a point trimmed inside it is scanned instead);
    -1 where no point of the row is active."""
    a, b = span[sg, j, 0], span[sg, j, 1]
    inc = c[sg, j, b] > c[sg, j, a]
    while b - a > 1:
        mid = (a + b) // 2
        cm = c[sg, j, mid]
        if cm != cm:  # a point trimmed inside the row (wormsim.tooth.trim): scan the row instead
            a = -1
            break
        if (cm < target) == inc:
            a = mid
        else:
            b = mid
    if a >= 0:
        return a if abs(c[sg, j, a] - target) <= abs(c[sg, j, b] - target) else b
    i_s, dc = -1, np.inf
    for i in range(span[sg, j, 0], span[sg, j, 1] + 1):
        ci = c[sg, j, i]
        if ci == ci and abs(ci - target) < dc:
            dc, i_s = abs(ci - target), i
    return i_s


@numba.njit(cache=True, inline="always")
def _start_near(c, span, sg, j, target, hint):
    """_start_point's point, found by walking from the point hint (the slice's start point at its last evaluation:
    the seat motor's wheel turns a small fraction of a profile point's conjugate angle per step) instead of by
    bisection: the segment [i, i + 1] of the row whose conjugate angles bracket the target as the bisection's does,
    then its nearer end, ties to i (the bisection's rule, so the point is the same); the bisection where hint is
    not a point of the active row or the walk meets a trimmed point."""
    a, b = span[sg, j, 0], span[sg, j, 1]
    if hint < a or hint > b or b - a < 1:
        return _start_point(c, span, sg, j, target)
    inc = c[sg, j, b] > c[sg, j, a]
    i = min(hint, b - 1)
    for _ in range(b - a):
        c0, c1 = c[sg, j, i], c[sg, j, i + 1]
        if c0 != c0 or c1 != c1:
            return _start_point(c, span, sg, j, target)
        if i > a and (c0 < target) != inc:
            i -= 1
        elif i < b - 1 and (c1 < target) == inc:
            i += 1
        else:
            break
    return i if abs(c[sg, j, i] - target) <= abs(c[sg, j, i + 1] - target) else i + 1


@numba.njit(cache=True, inline="always")
def _g(ev, sg, j, i, zj, sid):
    """Extended gap (worm_gap_ext) of profile point i of (flank sg, slice j) at the face position zj, with the tooth's
    evaluation context ev = (xy, ca, sa, theta1, P, tmp, gaps, exc, pts, nrs, stamp): evaluated once per slice
    (stamp[i] == sid) and kept in gaps, exc (excess), pts (the wheel point turned by the angle (cos ca, sin sa) about
    z, assembly frame), nrs (the unit gradient, static worm frame); +inf off the grid and at points that are not
    active flank points. With a displaced pose in P (wormsim.tooth.pose) the turned point is in the wheel body's frame
    and goes through the poses (pose.to_static). One function level, as numba copies an inlined callee's IR (with its
    own inlined callees) per call site and level."""
    xy, ca, sa, theta1, P, tmp, gaps, exc, pts, nrs, stamp = ev
    if i < 0 or i >= gaps.shape[0]:
        return np.inf
    if stamp[i] == sid:
        return gaps[i]
    stamp[i] = sid
    x0 = xy[sg, j, i, 0]
    if x0 != x0:
        gaps[i], exc[i] = np.inf, np.inf
        return np.inf
    y0 = xy[sg, j, i, 1]
    x, y = ca * x0 - sa * y0, sa * x0 + ca * y0
    if P.shape[0] > N_WORM_PARAMS:
        xs, ys, zs = to_static(x, y, zj, P, tmp)
    else:
        tmp[3], tmp[4], tmp[5] = x, y, zj
        xs, ys, zs = y + P[10], -zj, -x
    gv, ex = worm_gap_ext(xs, ys, zs, theta1, P, tmp)
    gaps[i], exc[i] = gv, ex
    pts[i, 0], pts[i, 1], pts[i, 2] = tmp[3], tmp[4], tmp[5]
    nrs[i, 0], nrs[i, 1], nrs[i, 2] = tmp[0], tmp[1], tmp[2]
    return gv


@numba.njit(cache=True, inline="always")
def _slice_contact(ev, sc, zeta, slc, i_s, sid, taper, memo_row, out, n):
    """The contact of slc = (flank sg, slice j, tooth k) from the start point i_s (module docstring): the gap's
    minimum along the profile (`_descend`), the parabola through it (`_line_parabola`), the worm's edge where the
    minimum lies past it (`_edge_minimum`); written as contact n (`_write_contact`) where it touches, else the slice
    memorised where it is open (memo_row = (use_memo, table, TE)). sc = (span, c, the contact line's conjugate
    angle, _line_point's cache), the grid's and _line_share's. Returns (the contacts written, out full)."""
    span = sc[0]
    sg, j, k = slc
    exc = ev[7]
    zj = zeta[j]
    ib, best = _descend(ev, sg, j, zj, i_s, sid)
    if best == np.inf:
        return n, False
    qa, qb, x, par, gm, gp = _line_parabola(ev, sg, j, zj, ib, best, sid)
    x = min(max(x, -1.0), 1.0)
    nb = ib + 1 if x > 0.0 else ib - 1
    e_x = exc[ib] if x == 0.0 else exc[ib] + abs(x) * (exc[nb] - exc[ib])
    x_l = x
    gmin, x = _edge_minimum(ev, sg, j, zj, (ib, nb, best, e_x), (qa, qb, x, par, gm, gp), sid)
    gline = best + qa * x_l + qb * x_l * x_l
    # the line's own gap, its parabola's vertex unclamped (past the wheel's tip edge the clamped gline is the tip
    # edge's gap): a slice whose line point lies past the tip edge may still carry where the line lies inside it
    gvert = best - qa * qa / (4.0 * qb) if qb > 0.0 else gline
    if gmin >= 0.0 and gline >= 0.0 and gvert >= 0.0:
        use_memo, mtab, te, drift = memo_row
        if use_memo and gline > 0.0:
            # conjugate (the line's point inside the profile and the threaded region): by the TE; else (the
            # minimum at the profile's end or past the worm's edge) by the motion's rate, on the smallest of the
            # slice's gaps, where the parabola's vertex lies within MEMO_RATE_REACH points (_find_contacts)
            conj = par and e_x <= 0.0 and span[sg, j, 0] < ib < span[sg, j, 1]
            ge = gline if conj else min(gmin, gline, gvert)
            if conj or (ge > 0.0 and qb > 0.0 and abs(qa) <= 2.0 * MEMO_RATE_REACH * qb):
                km = k % mtab.shape[0]
                mtab[km, sg, j, 0], mtab[km, sg, j, 1], mtab[km, sg, j, 2] = ge, te, ev[3]
                mtab[km, sg, j, 3] = drift
                mtab[km, sg, j, 5] = 0.0 if conj else 1.0
        return n, False
    if gmin == np.inf:
        x = x_l  # no edge inside reach: the line's point (only its weight can make it carry)
    if n >= out[2].shape[0]:
        return n, True
    _write_contact(ev, sc, zeta, slc, (ib, x), (gmin, gline, taper, (best, qa, qb, ib)), out, n)
    return n + 1, False


@numba.njit(cache=True, inline="always")
def _descend(ev, sg, j, zj, ib, sid):
    """From profile point ib down along the profile to the minimum of the extended gap (one minimum per slice: the
    gap across a contact line is quadratic); returns (its index, its gap), the gap +inf where there is none. The
    points ib, ib - 1, ib + 1, then the next ones in the falling direction, from one evaluation site in a loop (each
    inlined _g is a copy of the gap's evaluation to compile)."""
    best = gl = np.inf
    step = 0
    phase = 0  # 0: ib, 1: ib - 1, 2: ib + 1, 3: walking in direction step
    while True:
        i = ib if phase == 0 else ib - 1 if phase == 1 else ib + 1 if phase == 2 else ib + step
        gn = _g(ev, sg, j, i, zj, sid)
        if phase == 0:
            best = gn
        elif phase == 1:
            gl = gn
        elif phase == 2:
            if gl < best and gl <= gn:
                step, ib, best = -1, ib - 1, gl
            elif gn < best:
                step, ib, best = 1, ib + 1, gn
            else:
                break
        elif gn < best:
            ib, best = ib + step, gn
        else:
            break
        phase = min(phase + 1, 3)
    return ib, best


@numba.njit(cache=True, inline="always")
def _known(gaps, i):
    """The gap of profile point i that _descend evaluated in this slice (+inf off the grid, as _g)."""
    return gaps[i] if 0 <= i < gaps.shape[0] else np.inf


@numba.njit(cache=True, inline="always")
def _line_parabola(ev, sg, j, zj, ib, best, sid):
    """The parabola q(x) = best + qa x + qb x^2 through the deepest point ib and its neighbours (the gap across a
    contact line is quadratic; the extended gap is one smooth surface across the worm's edges), blended towards its
    vertex, or at the active profile's end the one through the end and its two inner neighbours. Returns (qa, qb,
    its vertex x, whether there is one, the neighbours' gaps gm, gp). The neighbours are _descend's (evaluated);
    the point two steps on has one evaluation site for both cases."""
    gaps = ev[6]
    gm = _known(gaps, ib - 1)
    gp = _known(gaps, ib + 1)
    qa, qb, x = 0.0, 0.0, 0.0
    par = gm < np.inf and gp < np.inf and gm - 2.0 * best + gp > 0.0
    end = (gm == np.inf) != (gp == np.inf)
    if par:
        qa, qb = 0.5 * (gp - gm), 0.5 * (gm - 2.0 * best + gp)
        x = -qa / (2.0 * qb)
        s1 = 1 if x > 0.0 else -1
    else:
        s1 = 1 if gm == np.inf else -1
    if par or end:
        g1 = gp if s1 > 0 else gm
        g2 = _g(ev, sg, j, ib + 2 * s1, zj, sid)
        qa2, qb2, x2, ok2 = _end_parabola(best, g1, g2, s1)
        if par:
            # blended with the parabola through the next three points towards the vertex, by lam = |x| (0 at the
            # grid point, 1/2 where the deepest point passes to the neighbour: there both sides blend the same two
            # parabolas), so the line's depth and point do not step when the deepest point moves on
            if ok2 and x != 0.0:
                lam = min(abs(x), 0.5)
                qa, qb = (1.0 - lam) * qa + lam * qa2, (1.0 - lam) * qb + lam * qb2
                x = -qa / (2.0 * qb)
        else:
            # the deepest point is the active profile's end: the parabola through it and its two inner neighbours
            # (the one the central fit uses once the next point is deeper), its vertex clamped to the profile, so
            # the line point moves continuously onto the end instead of jumping to it
            qa, qb, x, par = qa2, qb2, x2, ok2
    return qa, qb, x, par, gm, gp


@numba.njit(cache=True, inline="always")
def _edge_minimum(ev, sg, j, zj, at, parab, sid):
    """The slice's gap minimum inside the threaded region and its fractional offset x from ib: the parabola's where
    the line's point (excess e_x) lies inside; else the worm's edge on the wheel flank, where the excess crosses
    zero (between ib and nb, or walking inwards from ib); +inf where no edge lies within reach. at = (ib, nb, the
    gap at ib, e_x), parab = (qa, qb, x, par, gm, gp) (_line_parabola's, x clamped to [-1, 1])."""
    ib, nb, best, e_x = at
    qa, qb, x, par, gm, gp = parab
    gaps, exc = ev[6], ev[7]
    if e_x <= 0.0:
        return best + qa * x + qb * x * x, x
    if exc[ib] <= 0.0:
        # the minimum lies just past the worm's tip, root or end face: the contact is the worm's edge on the wheel
        # flank, where the excess crosses zero between ib and nb
        x = (x / abs(x)) * exc[ib] / (exc[ib] - exc[nb])
        return best + qa * x + qb * x * x, x
    # the minimum lies outside: walk towards the inside to the first point there; the edge contact sits where the
    # excess crosses zero, its depth falls to zero continuously as the line moves on
    step = -1 if (gm < np.inf and (gp == np.inf or exc[ib - 1] < exc[ib + 1])) else 1
    ia = ib
    gmin = np.inf
    while True:
        ibn = ia + step
        gn = _g(ev, sg, j, ibn, zj, sid)
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
    return gmin, x


@numba.njit(cache=True, inline="always")
def _write_contact(ev, sc, zeta, slc, at, gap, out, n):
    """Contact n of slc = (flank sg, slice j, tooth k) at at = (ib, x): fractional profile index ib + x; gap = (the
    edge's gap minimum gmin, the line's gline, the taper, the gap's parabola (best, qa, qb, ib) of _line_parabola);
    sc = (span, c, the contact line's conjugate angle, ...) (_line_share): its point and normal linear between the grid
    points around it, moved half the depth along the normal (find_contacts' fields). The depth for slice_weights
    (line[n, 1]) is the line's gline, except where the line leaves the active profile (decision 0052): where the line
    crosses the wheel's tip edge in the slice, the depth averaged across the slice (_tip_depth: the line's inside the
    edge, the tip edge's parabola past it); where the line's point lies past the profile's lower end (the worm tip's
    reach, where the share w is the worm's), the line's own depth, the parabola at the line's point. With the
    profile end's gap instead (the clamped parabola) each slice took its centre's depth across its width, which
    falls from the line's to zero within a small share of a slice past an end: on the screw jack at 16 slices the
    mesh stiffness over a mesh cycle 3.8 % of its mean off 64 slices' (1.7 % with these depths)."""
    sg, j, k = slc
    ib, x = at
    gmin, gline, taper, parab = gap
    xy, ca, sa, P, tmp, pts, nrs = ev[0], ev[1], ev[2], ev[4], ev[5], ev[8], ev[9]
    pos, nrm, depth, meta, line = out
    N = xy.shape[2]
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
    pos[n, 0] = px + 0.5 * dlt * ax
    pos[n, 1] = py + 0.5 * dlt * ay
    pos[n, 2] = pz + 0.5 * dlt * az
    nrm[n, 0], nrm[n, 1], nrm[n, 2] = ax, ay, az
    depth[n] = max(dlt, 0.0)
    w, tip = _line_share(xy, sc, zeta, sg, j, ib, ca, sa, P, tmp)
    line[n, 0] = w
    best, qa, qb, il = parab
    if qb > 0.0 and tip[5] < sc[0][sg, j, 0]:
        # the line's point lies past the profile's lower end (the worm tip's reach): the covered share w is the
        # worm's (its excess along the line), the covered part's depth the line's, the gap's parabola at the line's
        # point (at least the clamped line's), not the profile end's gap
        xl = tip[5] - il
        dl = max(-(best + qa * xl + qb * xl * xl), -gline)
    elif tip[3] or qb <= 0.0:  # the line inside the wheel's tip edge across the slice
        dl = -gline
    else:
        # the line crosses the tip edge in the slice (or lies past it): its depth averaged across the slice, the
        # line's depth the gap's parabola (_line_parabola, profile index offsets from il) at the line's point (at
        # tip[0] past the last point b along the end segment of length tip[4]), at least the clamped line's
        xl = sc[0][sg, j, 1] - il + tip[0] / tip[4]
        delta = max(-(best + qa * xl + qb * xl * xl), -gline)
        dl = _tip_depth(delta, qb / (tip[4] * tip[4]), tip[0], tip[1], tip[2])
    if dl - dl != 0.0:  # not finite (a trimmed point next to the profile's end: no end segment): the line's gline
        dl = -gline
    line[n, 1] = dl * taper
    meta[n, 0], meta[n, 1], meta[n, 2], meta[n, 3] = k, sg, j, f


@numba.njit(cache=True, inline="always")
def _point_at(xy, sg, j, f, i0):
    """(x, y) of (flank sg, slice j) at fractional profile index f, linear through the grid points i0 and i0 + 1
    (extrapolated past them)."""
    t = f - i0
    x = xy[sg, j, i0, 0] + t * (xy[sg, j, i0 + 1, 0] - xy[sg, j, i0, 0])
    y = xy[sg, j, i0, 1] + t * (xy[sg, j, i0 + 1, 1] - xy[sg, j, i0, 1])
    return x, y


@numba.njit(cache=True, inline="always")
def _index_at(c, span, sg, j, target, hint):
    """(f, i0): the fractional profile index f of (flank sg, slice j) whose conjugate angle is target, linear in
    the segment [i0, i0 + 1] around it, extrapolated along the end segment past the active profile (so f is
    continuous in target); i0 = -1 where the slice has no active segment there. c is monotone along the active
    profile: the segment is found by walking from the segment at index hint (the line's point of the slice or its
    neighbour's: a step or two), by bisection (_start_point) where the walk meets a trimmed point."""
    a, b = span[sg, j, 0], span[sg, j, 1]
    if a < 0 or b <= a:
        return -1.0, -1
    up = 1.0 if c[sg, j, b] > c[sg, j, a] else -1.0  # c's direction along the profile
    i0 = min(max(hint, a), b - 1)
    for _ in range(b - a):
        c0, c1 = c[sg, j, i0], c[sg, j, i0 + 1]
        if c0 != c0 or c1 != c1:
            i0 = -1  # a point trimmed inside the row
            break
        if up * (target - c0) < 0.0 and i0 > a:
            i0 -= 1
        elif up * (target - c1) > 0.0 and i0 < b - 1:
            i0 += 1
        else:
            break
    if i0 < 0:
        i = _start_point(c, span, sg, j, target)
        if i < 0:
            return -1.0, -1
        # the segment on the target's side of the nearest point i
        i0 = min(max(i if up * (target - c[sg, j, i]) > 0.0 else i - 1, a), b - 1)
    c0, c1 = c[sg, j, i0], c[sg, j, i0 + 1]
    if c0 != c0 or c1 != c1 or c1 == c0:
        return -1.0, -1
    return i0 + (target - c0) / (c1 - c0), i0


@numba.njit(cache=True, inline="always")
def _covered(e0, b, a):
    """The measure of {u in [-1/2, 1/2] : e0 + b u + a u^2 < 0} (the share of a slice where the excess along the
    contact line, quadratic in u, slice widths from the slice centre, is negative: covered). Continuous in (e0, b, a)
    except where q has a double root at an end of the interval, or vanishes (e0 = b = a = 0); a = 0 is the linear
    limit (the far root runs off to infinity)."""
    disc = b * b - 4.0 * a * e0
    if disc <= 0.0:  # q keeps one sign (a's; e0's where a = b = 0)
        return 1.0 if (a < 0.0 or (a == 0.0 and e0 < 0.0)) else 0.0
    q = -0.5 * (b + math.copysign(math.sqrt(disc), b))  # the roots q / a and e0 / q, without cancellation
    if a == 0.0:  # linear: the root e0 / q = -e0 / b
        r = e0 / q
        return min(max(r + 0.5, 0.0), 1.0) if b > 0.0 else min(max(0.5 - r, 0.0), 1.0)
    r1, r2 = q / a, e0 / q
    lo, hi = min(r1, r2), max(r1, r2)
    inside = max(0.0, min(hi, 0.5) - max(lo, -0.5))  # where q lies between its roots
    return inside if a > 0.0 else 1.0 - inside


@numba.njit(cache=True, inline="always")
def _line_share(xy, sc, zeta, sg, j, hint, ca, sa, P, tmp):
    """The share of the strip of (flank sg, slice j) that the contact line covers inside the worm's threaded region.
    The contact line is the conjugate one at the current pose: the flank points of conjugate angle c_line (sc =
    (span, c, c_line): the tooth flank's target less the tooth's transmission error, _find_contacts; it lies within a
    fraction of a per cent of a pitch of the loaded line's gap minima), in this slice and its two neighbours (c
    interpolated along the profile, extrapolated along its end segment past the active profile, so the point is
    continuous where the line runs off the grid); the excess along the line (_excess: < 0 inside the threaded region)
    e_-, e_0, e_+ there, taken quadratic in between, and the share of the slice where it is negative (_covered);
    where one neighbour has no active segment (the face's ends) linear through the other, where neither the
    change across the face at the point (_face_slope).

    The line is oblique on the flank: its point moves along the profile from slice to slice, and its excess changes
    with it, not as at a fixed profile point (_face_slope: on involute_41's leaving tooth 0.45 x the change along
    the line, so each slice's weight fell in 0.45 of the time between two slices' exits, a staircase at their exit
    rate). Where the line shrinks to a point inside the face (it touches the worm's tip cylinder there), its excess
    has a quadratic minimum and the covered length falls to zero as the square root of the time left, which the
    quadratic follows within the slice. Where the line leaves the grid (its point past the active profile's end),
    the extrapolated point keeps the line's excess (the gap's minimum stays at the profile's end). Exact for a
    straight line end and for a parabolic excess; a property of the pose and the grid, so each slice's weight is
    continuous in the mesh angle (slice_weights). Where the point lies deeper inside than INSIDE_SHARE x the larger
    distance to a neighbour's point, the share is 1 without the neighbours' excess (a max of distances, it changes
    by at most the distance moved, the quadratic by at most 3/4 of it within the slice). hint: the profile index of
    the slice's line point (_index_at's walk starts there). The line's points, their tip distances and excesses are
    computed once per tooth flank and slice (_line_point, _line_excess: sc = (span, c, c_line, lcache, lstamp,
    fid)) and shared with the neighbouring slices' calls.

    Returns (w, tip): w that share; tip = (t0, tb, ta, inside, seg, f0) for the slice's depth (_write_contact): how
    far the line lies past the wheel's tip edge (the active profile's last point, _tip_past, m), quadratic across the
    slice from the line's points as the excess (t0 + tb u + ta u^2), whether it stays inside the tip edge across the
    slice (by INSIDE_SHARE x its change to the neighbours, as the excess), the end segment's length, and the line
    point's fractional profile index f0 (past the profile's lower end where f0 < its first active point)."""
    span, c, c_line, lcache, lstamp, fid = sc
    S = zeta.shape[0]
    dz = zeta[1] - zeta[0] if S > 1 else 1.0
    # the line's points of this slice and its neighbours (_line_point: once per tooth flank and slice)
    for q in range(3):
        jq = j if q == 0 else j - 1 if q == 1 else j + 1
        if 0 <= jq < S:
            _line_point(xy, sc, sg, jq, hint if q == 0 else int(lcache[j, 1]))
    f0, i0 = lcache[j, 0], int(lcache[j, 1])
    if i0 < 0:  # no active segment on the line (a trimmed point): the change across the face at the profile's middle
        a, b = span[sg, j, 0], span[sg, j, 1]
        i0 = (a + b) // 2
        x0, y0 = xy[sg, j, i0, 0], xy[sg, j, i0, 1]
        e0 = _excess(x0, y0, zeta[j], ca, sa, P, tmp)
        return _covered(e0, _face_slope(x0, y0, zeta[j], dz, ca, sa, P, tmp), 0.0), _NO_TIP
    x0, y0 = lcache[j, 2], lcache[j, 3]
    e0 = _line_excess(sc, j, zeta, ca, sa, P, tmp)
    im = int(lcache[j - 1, 1]) if j > 0 else -1
    ip = int(lcache[j + 1, 1]) if j < S - 1 else -1
    if im < 0 and ip < 0:
        return _covered(e0, _face_slope(x0, y0, zeta[j], dz, ca, sa, P, tmp), 0.0), _NO_TIP
    t0, seg = lcache[j, 4], lcache[j, 5]
    tm = lcache[j - 1, 4] if im >= 0 else 0.0
    tp = lcache[j + 1, 4] if ip >= 0 else 0.0
    # the tip's quadratic across the slice (as the excess's below), and whether it stays negative across the slice
    # (|t_+- - t_0| bounds its change within the slice as for the excess): then w_in = w
    if im < 0:
        tb, ta = tp - t0, 0.0
    elif ip < 0:
        tb, ta = t0 - tm, 0.0
    else:
        tb, ta = 0.5 * (tp - tm), 0.5 * (tp + tm) - t0
    inside = t0 < -INSIDE_SHARE * max(abs(tp - t0) if ip >= 0 else 0.0, abs(tm - t0) if im >= 0 else 0.0)
    reach = 0.0
    if im >= 0:
        xm, ym = lcache[j - 1, 2], lcache[j - 1, 3]
        reach = math.sqrt((xm - x0) ** 2 + (ym - y0) ** 2 + dz * dz)
    if ip >= 0:
        xp, yp = lcache[j + 1, 2], lcache[j + 1, 3]
        reach = max(reach, math.sqrt((xp - x0) ** 2 + (yp - y0) ** 2 + dz * dz))
    if e0 < -INSIDE_SHARE * reach:
        # |e_+- - e_0| <= reach: covered either way
        return 1.0, (t0, tb, ta, inside, seg, f0)
    if im < 0:
        eb, ea = _line_excess(sc, j + 1, zeta, ca, sa, P, tmp) - e0, 0.0
    elif ip < 0:
        eb, ea = e0 - _line_excess(sc, j - 1, zeta, ca, sa, P, tmp), 0.0
    else:
        em = _line_excess(sc, j - 1, zeta, ca, sa, P, tmp)
        ep = _line_excess(sc, j + 1, zeta, ca, sa, P, tmp)
        eb, ea = 0.5 * (ep - em), 0.5 * (ep + em) - e0
    return _covered(e0, eb, ea), (t0, tb, ta, inside, seg, f0)


@numba.njit(cache=True, inline="always")
def _line_point(xy, sc, sg, j, hint):
    """The contact line's point of (flank sg, slice j) for _line_share, once per tooth flank and slice (sc = (span, c,
    c_line, lcache, lstamp, fid): the slices of a tooth flank share their neighbours' points): its fractional profile
    index f and segment i0 (_index_at from the profile index hint; i0 = -1 where the slice has no active segment
    there), its (x, y) (_point_at) and how far it lies past the tip edge with the end segment's length (_tip_past),
    in lcache[j] (f, i0, x, y, t, seg; the excess in column 6, _line_excess); lstamp[j, 0] = fid once done. The
    segment found does not depend on the walk's start (c is monotone along the active profile), so the values are the
    ones _line_share computed per call."""
    span, c, c_line, lcache, lstamp, fid = sc
    if lstamp[j, 0] == fid:
        return
    lstamp[j, 0] = fid
    f, i0 = _index_at(c, span, sg, j, c_line, hint)
    lcache[j, 0], lcache[j, 1] = f, i0
    if i0 >= 0:
        lcache[j, 2], lcache[j, 3] = _point_at(xy, sg, j, f, i0)
        lcache[j, 4], lcache[j, 5] = _tip_past(xy, span, sg, j, f)


@numba.njit(cache=True, inline="always")
def _line_excess(sc, j, zeta, ca, sa, P, tmp):
    """The excess (_excess) at the line's point of slice j (_line_point's, computed before), once per tooth flank and
    slice (lstamp[j, 1] = fid once done)."""
    lcache, lstamp, fid = sc[3], sc[4], sc[5]
    if lstamp[j, 1] != fid:
        lstamp[j, 1] = fid
        lcache[j, 6] = _excess(lcache[j, 2], lcache[j, 3], zeta[j], ca, sa, P, tmp)
    return lcache[j, 6]


@numba.njit(cache=True, inline="always")
def _tip_past(xy, span, sg, j, f):
    """How far the point at fractional profile index f of (flank sg, slice j) lies past the wheel's tip edge (the
    active profile's last point b), along the profile's end segment: (f - b) times its length (m; < 0 inside), and
    that length."""
    b = span[sg, j, 1]
    seg = math.sqrt((xy[sg, j, b, 0] - xy[sg, j, b - 1, 0]) ** 2 + (xy[sg, j, b, 1] - xy[sg, j, b - 1, 1]) ** 2)
    return (f - b) * seg, seg


@numba.njit(cache=True, inline="always")
def _tip_depth(delta, kappa, t0, tb, ta):
    """The depth averaged across a slice where the contact line crosses the wheel's tip edge: delta (the line's
    depth) where the line lies inside the tip edge, the tip edge's max(delta - kappa t^2, 0) past it (the gap along
    the profile is the parabola of curvature kappa about the line), t(u) = t0 + tb u + ta u^2 how far the line lies
    past the tip edge at u slice widths from the centre (_line_share); the midpoint rule on TIP_SUBSTEPS points."""
    acc = 0.0
    for m in range(TIP_SUBSTEPS):
        u = (m + 0.5) / TIP_SUBSTEPS - 0.5
        t = t0 + tb * u + ta * u * u
        acc += delta if t <= 0.0 else max(delta - kappa * t * t, 0.0)
    return acc / TIP_SUBSTEPS


@numba.njit(cache=True, inline="always")
def _face_slope(x0, y0, zj, dz, ca, sa, P, tmp):
    """Change of the excess (worm_gap_ext) across one slice width at the line's point: the wheel point (x0, y0) of
    the slice at zj (_line_share's, extrapolated along the end segment past the active profile: the grid points
    past its ends may be trimmed, NaN) moved by -dz/2 and +dz/2 along the wheel axis. A property of the point alone,
    so each slice's weight is continuous in the mesh angle (slice_weights)."""
    return _excess(x0, y0, zj + 0.5 * dz, ca, sa, P, tmp) - _excess(x0, y0, zj - 0.5 * dz, ca, sa, P, tmp)


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
    K / S when the end crosses a slice centre. line[:, 0] is that share (find_contacts, _line_share: the excess
    linear along the contact line on each side of the line's point, its change to the neighbouring slices' line
    points; the trapezoidal rule for the line load with its ends interpolated). The share is the contact's own,
    not from the neighbours' contacts: with the neighbours' excess from the list, a neighbour leaving it (its slice
    leaving the candidate window, or a slice without one) switched the slope and stepped the weight at full depth
    (docs/contact3d.md). Keeps the contacts with w > 0 (in place: pos, nrm, depth, meta, line), sets depth to the
    line's depth and weight to w; returns their number. meta and slices are kept in the signature for the
    callers."""
    m = 0
    for i in range(n):
        w = min(max(line[i, 0], 0.0), 1.0)
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
_F_FIELDS += (
    "mpos",
    "mnrm",
    "mdepth",
    "mweight",
    "mframe",
    "grp",
    "share",
    "mfric",
    "mwrap",
    "axes",
)  # wormsim.tooth.merge
_F_FIELDS += ("lcache",)  # _line_point's cache
_I_FIELDS = ("span", "ks", "stamp", "lstamp")
_I_HEADER = 8  # S, N, cap, len(P), W, z2, merge (slices per merged contact, 0: none), merged contacts


@numba.njit(cache=True)
def _layout(S, N, cap, nP, W, z2):
    """The packed buffers' layout, declared once: the shapes of the float buffer's fields (_F_FIELDS order) and of
    the int buffer's after its header (_I_FIELDS order). PackedKernel sizes the buffers by it; `_views` cuts them."""
    f = ((2, S, N, 2), (2, S, N), (2, S, 2), (S,), (nP,), (cap, 3), (cap, 3), (cap,), (cap, 4), (cap, 2), (cap,))
    f2 = ((cap, 9), (z2, 2, S, MEMO_COLS), (MEMO_CONSTS,), (6,), (N,), (N,), (N, 3), (N, 3))
    f3 = ((cap, 3), (cap, 3), (cap,), (cap,), (cap, 9), (cap,), (cap,), (cap,), (cap,), (13,), (S, LINE_COLS))
    return f + f2 + f3, ((2, S, 2), (W,), (N,), (S, 2))


@numba.njit(cache=True, inline="always")
def _take(buf, o, shape):
    """buf's next field of this shape from offset o, as a view; with the offset after it."""
    k = 1
    for x in shape:
        k *= x
    return buf[o : o + k].reshape(shape), o + k


@numba.njit(cache=True, inline="always")
def _views(fb, ib):
    """The packed buffers' fields as views (_layout at the sizes in ib's header): the float fields in _F_FIELDS
    order, the int fields in _I_FIELDS order: find_packed's unpacking (PackedKernel cuts its numpy fields by the
    same _layout in Python, `_cut`)."""
    f, i = _layout(ib[0], ib[1], ib[2], ib[3], ib[4], ib[5])
    o = 0
    xy, o = _take(fb, o, f[0])
    c, o = _take(fb, o, f[1])
    c_range, o = _take(fb, o, f[2])
    zeta, o = _take(fb, o, f[3])
    P, o = _take(fb, o, f[4])
    pos, o = _take(fb, o, f[5])
    nrm, o = _take(fb, o, f[6])
    depth, o = _take(fb, o, f[7])
    meta, o = _take(fb, o, f[8])
    line, o = _take(fb, o, f[9])
    weight, o = _take(fb, o, f[10])
    frame, o = _take(fb, o, f[11])
    mtab, o = _take(fb, o, f[12])
    mc, o = _take(fb, o, f[13])
    tmp, o = _take(fb, o, f[14])
    gaps, o = _take(fb, o, f[15])
    exc, o = _take(fb, o, f[16])
    pts, o = _take(fb, o, f[17])
    nrs, o = _take(fb, o, f[18])
    mpos, o = _take(fb, o, f[19])
    mnrm, o = _take(fb, o, f[20])
    mdepth, o = _take(fb, o, f[21])
    mweight, o = _take(fb, o, f[22])
    mframe, o = _take(fb, o, f[23])
    grp, o = _take(fb, o, f[24])
    share, o = _take(fb, o, f[25])
    mfric, o = _take(fb, o, f[26])
    mwrap, o = _take(fb, o, f[27])
    axes, o = _take(fb, o, f[28])
    lcache, o = _take(fb, o, f[29])
    o = _I_HEADER
    span, o = _take(ib, o, i[0])
    ks, o = _take(ib, o, i[1])
    stamp, o = _take(ib, o, i[2])
    lstamp, o = _take(ib, o, i[3])
    floats = (xy, c, c_range, zeta, P, pos, nrm, depth, meta, line, weight, frame, mtab, mc, tmp, gaps, exc, pts, nrs)
    floats2 = (mpos, mnrm, mdepth, mweight, mframe, grp, share, mfric, mwrap, axes, lcache)
    return floats + floats2, (span, ks, stamp, lstamp)


def _size(shapes) -> int:
    return sum(int(np.prod(sh)) for sh in shapes)


def _cut(buf: np.ndarray, o: int, shapes) -> list[np.ndarray]:
    """buf's fields of these shapes from offset o on, as numpy views (_take's cut, in Python: PackedKernel's fields
    without compiling `_views` as an entry point of its own)."""
    views = []
    for sh in shapes:
        k = int(np.prod(sh))
        views.append(buf[o : o + k].reshape(sh))
        o += k
    return views


class PackedKernel:
    """The kernel's inputs, outputs, memo and work arrays in one float and one int buffer, so that one compiled call,
    find_packed(fb, ib, theta1, theta2, margin, taper_rad), runs find_contacts, slice_weights and contact_frames:
    numba's dispatch costs ~0.25 us per array argument (the three calls with their 28 arrays and find_contacts' work
    allocation cost ~9 us of Python per step). The fields are numpy views of the buffers (pos, nrm, depth, meta, line,
    weight, frame, P, memo, span, ks: write ks and P in place), cut by `_views` from the one layout `_layout`.
    merge: the slices per merged contact (wormsim.tooth.merge; 0: none, S: one per tooth flank): mpos, mnrm,
    mdepth, mweight, mframe, mfric, mwrap, their number in ib[7]; grp, share; axes: the hinges, set by the caller)."""

    def __init__(self, grid: FlankGrid, P: np.ndarray, cap: int, W: int, z2: int, merge: int = 0):
        S, N = grid.slices, grid.c.shape[2]
        fs, is_ = _layout(S, N, cap, len(P), W, z2)
        self.fb = np.zeros(_size(fs))
        self.ib = np.zeros(_I_HEADER + _size(is_), dtype=np.int64)
        self.ib[:7] = (S, N, cap, len(P), W, z2, merge)
        views = _cut(self.fb, 0, fs) + _cut(self.ib, _I_HEADER, is_)
        for name, v in zip(_F_FIELDS + _I_FIELDS, views, strict=True):
            setattr(self, name, v)
        self.xy[:], self.c[:], self.c_range[:], self.zeta[:] = grid.xy, grid.c, grid.c_range, grid.zeta
        self.span[:] = grid.span
        self.P[:] = P
        self.memo_consts[:] = flank_memo(grid, z2)[1]


@numba.njit(cache=True)
def find_packed(fb, ib, theta1, theta2, margin, taper_rad):
    """find_contacts (with its memo), slice_weights and contact_frames on a PackedKernel's buffers at worm angle
    theta1, wheel angle theta2 for the window teeth in its ks; returns the number of contacts (their fields in
    pos, nrm, depth, weight, frame, meta, line; with ib[6], the merged contacts as well, PackedKernel). With ib[6]
    the slice contacts' frames are not computed here (MuJoCo gets the merged contacts' frames, mframe): the samples,
    which alone read them, call contact_frames on nrm (FlankContacts.slice_rows, flank_samples.contact_rows); the
    same values, once per sample instead of once per step."""
    S = ib[0]
    floats, ints = _views(fb, ib)
    xy, c, c_range, zeta, P, pos, nrm, depth, meta, line, weight, frame = floats[:12]
    mtab, mc, tmp, gaps, exc, pts, nrs = floats[12:19]
    mpos, mnrm, mdepth, mweight, mframe, grp, share, mfric, mwrap, axes, lcache = floats[19:]
    span, ks, stamp, lstamp = ints
    if taper_rad <= 0.0:
        taper_rad = TAPER_SHARE * margin
    n = _find_contacts(
        (xy, c, c_range, span, zeta),
        ks,
        theta1,
        theta2,
        margin,
        taper_rad,
        P,
        (pos, nrm, depth, meta, line),
        (tmp, gaps, exc, pts, nrs, stamp, lcache, lstamp),
        (mtab, mc),
    )
    n = slice_weights(meta, line, n, S, pos, nrm, depth, weight)
    if not ib[6]:
        contact_frames(nrm, n, frame)
    else:  # ib[6] slices per merged contact (wormsim.tooth.merge); the slices' frames where a sample reads them
        merged = (mpos, mnrm, mdepth, mweight, mfric, mwrap)
        nm = merge_flanks(meta, n, (pos, nrm, depth, weight), grp, share, merged, axes, ib[6])
        ib[7] = nm
        contact_frames(mnrm, nm, mframe)
    return n
