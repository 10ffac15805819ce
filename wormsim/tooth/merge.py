"""Fewer MuJoCo contacts than slices (`contact.flank_contacts: tooth` or N): the slice contacts of one tooth flank
(same tooth, same side: meta[:, 0:2], contiguous in the kernel's order), or of each run of `group` adjacent slices on
it (slice index meta[:, 2] // group; N contacts per tooth flank: group = ceil(S / N)), handed to MuJoCo as one
contact.

The contact law is a linear spring per contact whose stiffness is scaled by the contact's share w_i of its slice
(wormsim.contact3d.law (1); kernel.slice_weights; flank_handoff.fill_add scales solref by w). With a_i = w_i d_i:

    depth = sum a_i / W,   W = sum w_i,   pos = sum a_i p_i / sum a_i  (the spring forces' centroid),
    normal = sum a_i n_i / |sum a_i n_i|,   c_w = |sum a_i n_i| / sum a_i,
    weight = c_w W (solref scaled by it),   mu = mu_slice / c_w

so the merged spring force k c_w W depth = |sum k a_i n_i| is the slices' resultant (exact, magnitude and direction).
The normals turn about the worm axis along the contact line (the line wraps the worm), so c_w < 1 and the slices'
normal forces sum to more than their resultant; friction acts on that sum (Coulomb: mu sum f_i), hence mu / c_w on
the merged contact (without it: efficiency +10-14 %). Not exact: the moment arms (position-normal covariance along
the line), the damping (the centroid's velocity against the weighted mean) and friction's direction (one cone, one
sliding direction);
docs/contact3d.md, "One contact per tooth flank", has the measured differences.

Per-slice outputs (contact pattern, Hertz pressure, the radial force and contact radius) come from the merged
contact's force split over its slices in proportion to a_i (the linear springs' shares): `split_forces`.
"""

from __future__ import annotations

import math

import numba
import numpy as np


@numba.njit(cache=True)
def merge_flanks(meta, n, slices, grp, share, merged, axes, group):
    """The merged contacts of the n slice contacts slices = (pos, nrm, depth, weight) (module docstring): merged =
    (mpos, mnrm, mdepth, mweight, mfric (the friction coefficient's factor), mwrap (1 / c_w)) per tooth flank;
    grp[c] the merged contact of slice contact c, share[c] = a_c / sum a (its share of the slices' spring forces);
    axes = (a point on the worm axis, its direction, a point on the wheel axis, its direction, the wheel's speed per
    worm speed): the hinges for the moment-arm and friction corrections (module docstring); group: the slices per
    merged contact (S or more: one per tooth flank). Returns the number of merged contacts."""
    pos, nrm, depth, weight = slices
    mpos, mnrm, mdepth, mweight, mfric, mwrap = merged
    g = 0
    i = np.int64(0)  # not a literal: _match_arms compiles once (int64), not also for Literal[int](0)
    while i < n:
        e = i + 1
        seg = int(meta[i, 2]) // group
        while e < n and meta[e, 0] == meta[i, 0] and meta[e, 1] == meta[i, 1] and int(meta[e, 2]) // group == seg:
            e += 1
        W = 0.0
        A = 0.0
        px = py = pz = nx = ny = nz = 0.0
        for c in range(i, e):
            a = weight[c] * depth[c]
            W += weight[c]
            A += a
            px += a * pos[c, 0]
            py += a * pos[c, 1]
            pz += a * pos[c, 2]
            nx += a * nrm[c, 0]
            ny += a * nrm[c, 1]
            nz += a * nrm[c, 2]
        cw = 1.0  # |sum a_i n_i| / sum a_i: the normals' wrap around the worm
        nn = math.sqrt(nx * nx + ny * ny + nz * nz)
        if A > 0.0:
            cw = nn / A
            mpos[g, 0], mpos[g, 1], mpos[g, 2] = px / A, py / A, pz / A
            mnrm[g, 0], mnrm[g, 1], mnrm[g, 2] = nx / nn, ny / nn, nz / nn
            for c in range(i, e):
                share[c] = weight[c] * depth[c] / A
        else:  # no spring force (slice_weights keeps depth > 0 and w > 0, so not reached): the plain mean
            for a in range(3):
                mpos[g, a] = 0.0
                mnrm[g, a] = 0.0
            for c in range(i, e):
                for a in range(3):
                    mpos[g, a] += pos[c, a] / (e - i)
                    mnrm[g, a] += nrm[c, a]
            nn = math.sqrt(mnrm[g, 0] ** 2 + mnrm[g, 1] ** 2 + mnrm[g, 2] ** 2)
            for a in range(3):
                mnrm[g, a] /= nn
            for c in range(i, e):
                share[c] = 1.0 / (e - i)
        if A > 0.0 and e > i + 1:
            _match_arms(pos, nrm, depth, weight, i, e, nn, mpos[g], mnrm[g], axes)
            # friction: the slices' sliding power mu sum f_j |v_j| at the merged point (v: the conjugate motion's
            # sliding velocity per unit worm speed in the tangent plane; mu_m F_m |v_m| = mu sum f_j |v_j|)
            sv = 0.0
            for c in range(i, e):
                sv += weight[c] * depth[c] * _slip(pos[c, 0], pos[c, 1], pos[c, 2], nrm[c], axes)
            vm = _slip(mpos[g, 0], mpos[g, 1], mpos[g, 2], mnrm[g], axes)
            if vm > 0.0 and sv > 0.0:
                cw = nn * vm / sv
        mdepth[g] = A / W
        mweight[g] = nn / mdepth[g] if A > 0.0 else W  # c_w W: the slices' resultant
        mfric[g] = 1.0 / cw
        mwrap[g] = A / nn if nn > 0.0 else 1.0
        for c in range(i, e):
            grp[c] = g
        g += 1
        i = e
    return g


@numba.njit(cache=True)
def split_forces(adr, efc_force, k0, cone3, merged, n, out):
    """Per-slice constraint forces from the merged contacts' (module docstring), merged = (grp, share, mfric, mwrap)
    (merge_flanks' outputs), out = (adr_out, efc_out): the merged contact grp[c] (d.contact
    entry k0 + grp[c], constraint rows from adr[k0 + grp[c]]; normal and, with cone3, the two tangent rows) in its own
    frame as slice c's rows in slice c's own frame: normal x share[c] / c_w (the slices' spring forces sum to the
    merged normal force / c_w), friction x share[c] / (c_w mfric) (a slice's own mu). efc_out[3c:3c+3], adr_out[c]
    = 3c (-1 where the merged contact has no rows). The frames (kernel.contact_frames) turn with the normal about the
    worm axis, so a slice's friction keeps its direction relative to its own normal."""
    grp, share, mfric, mwrap = merged
    adr_out, efc_out = out
    for c in range(n):
        g = int(grp[c])
        a = adr[k0 + g] if k0 + g < adr.shape[0] else -1  # -1: not taken (arena full)
        if a < 0:
            adr_out[c] = -1
            continue
        s = share[c] * mwrap[g]
        st = s / mfric[g]
        efc_out[3 * c] = s * efc_force[a]
        efc_out[3 * c + 1] = st * efc_force[a + 1] if cone3 else 0.0
        efc_out[3 * c + 2] = st * efc_force[a + 2] if cone3 else 0.0
        adr_out[c] = 3 * c


@numba.njit(cache=True, inline="always")
def _arm(px, py, pz, nx, ny, nz, axes, k):
    """((p - c_k) x n) . e_k: the normal row's moment arm about hinge k (axes[6k:6k+3] a point, [6k+3:6k+6] the
    direction)."""
    rx, ry, rz = px - axes[6 * k], py - axes[6 * k + 1], pz - axes[6 * k + 2]
    ex, ey, ez = axes[6 * k + 3], axes[6 * k + 4], axes[6 * k + 5]
    return (ry * nz - rz * ny) * ex + (rz * nx - rx * nz) * ey + (rx * ny - ry * nx) * ez


@numba.njit(cache=True)
def _match_arms(pos, nrm, depth, weight, i, e, nn, p, n, axes):
    """Moves the merged contact's point p in the plane normal to n so that its normal row's moment arms about both
    hinges are the slices' spring-weighted ones, sum a_j arm_j / |sum a_j n_j| (then F_m arm_m = sum f_j arm_j on
    both shafts, and the contact keeps the slices' conjugate action: zero normal speed in the conjugate motion):
    delta = alpha u_1 + beta u_2, u_k = n x e_k, from the 2 x 2 system delta . u_k = target_k - arm_k(p). Unchanged
    where u_1, u_2 are (nearly) parallel."""
    t0 = 0.0
    t1 = 0.0
    for c in range(i, e):
        a = weight[c] * depth[c]
        t0 += a * _arm(pos[c, 0], pos[c, 1], pos[c, 2], nrm[c, 0], nrm[c, 1], nrm[c, 2], axes, 0)
        t1 += a * _arm(pos[c, 0], pos[c, 1], pos[c, 2], nrm[c, 0], nrm[c, 1], nrm[c, 2], axes, 1)
    r0 = t0 / nn - _arm(p[0], p[1], p[2], n[0], n[1], n[2], axes, 0)
    r1 = t1 / nn - _arm(p[0], p[1], p[2], n[0], n[1], n[2], axes, 1)
    # u_k = n x e_k; ((p + delta - c) x n) . e = (p - c) . (n x e) + delta . (n x e)
    e0x, e0y, e0z, e1x, e1y, e1z = axes[3], axes[4], axes[5], axes[9], axes[10], axes[11]
    u0 = (n[1] * e0z - n[2] * e0y, n[2] * e0x - n[0] * e0z, n[0] * e0y - n[1] * e0x)
    u1 = (n[1] * e1z - n[2] * e1y, n[2] * e1x - n[0] * e1z, n[0] * e1y - n[1] * e1x)
    g00 = u0[0] * u0[0] + u0[1] * u0[1] + u0[2] * u0[2]
    g11 = u1[0] * u1[0] + u1[1] * u1[1] + u1[2] * u1[2]
    g01 = u0[0] * u1[0] + u0[1] * u1[1] + u0[2] * u1[2]
    det = g00 * g11 - g01 * g01
    if det <= 1e-12 * g00 * g11:
        return
    al = (r0 * g11 - r1 * g01) / det
    be = (r1 * g00 - r0 * g01) / det
    for a in range(3):
        p[a] += al * u0[a] + be * u1[a]


@numba.njit(cache=True, inline="always")
def _slip(px, py, pz, n, axes):
    """|v_t| per unit worm speed at p: v = e_1 x (p - c_1) - i e_2 x (p - c_2) (i = axes[12], the wheel's speed per
    worm speed), without its component along the normal n."""
    vx = axes[4] * (pz - axes[2]) - axes[5] * (py - axes[1])
    vy = axes[5] * (px - axes[0]) - axes[3] * (pz - axes[2])
    vz = axes[3] * (py - axes[1]) - axes[4] * (px - axes[0])
    r = axes[12]
    vx -= r * (axes[10] * (pz - axes[8]) - axes[11] * (py - axes[7]))
    vy -= r * (axes[11] * (px - axes[6]) - axes[9] * (pz - axes[8]))
    vz -= r * (axes[9] * (py - axes[7]) - axes[10] * (px - axes[6]))
    vn = vx * n[0] + vy * n[1] + vz * n[2]
    vx, vy, vz = vx - vn * n[0], vy - vn * n[1], vz - vn * n[2]
    return math.sqrt(vx * vx + vy * vy + vz * vz)
