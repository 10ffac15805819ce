"""One MuJoCo contact per tooth flank (`contact.flank_contacts: tooth`; issue 13): the slice contacts of one tooth
flank (same tooth, same side: meta[:, 0:2], contiguous in the kernel's order) handed to MuJoCo as one contact.

The contact law is a linear spring per contact whose stiffness is scaled by the contact's share w_i of its slice
(wormsim.contact3d.law (1); flanks.slice_weights; flank_handoff._fill_add scales solref by w). With a_i = w_i d_i:

    W = sum w_i  (solref scaled by W),   depth = sum a_i / W   =>   k W depth = sum k w_i d_i             (exact)
    pos = sum a_i p_i / sum a_i  (the spring forces' centroid),   normal = sum a_i n_i / |sum a_i n_i|

so the total normal spring force is the slices'. Not exact: the moment arms (position-normal covariance along the
line), the damping (the centroid's velocity against the weighted mean) and friction (one cone, one sliding direction);
docs/contact3d.md, "One contact per tooth flank", has the measured differences.

Per-slice outputs (contact pattern, Hertz pressure, the radial force and contact radius) come from the merged
contact's force split over its slices in proportion to a_i (the linear springs' shares): `split_forces`.
"""

from __future__ import annotations

import math

import numba


@numba.njit(cache=True)
def merge_flanks(meta, n, pos, nrm, depth, weight, grp, share, mpos, mnrm, mdepth, mweight):
    """The merged contacts of the n slice contacts (module docstring): mpos, mnrm, mdepth, mweight per tooth flank;
    grp[c] the merged contact of slice contact c, share[c] = a_c / sum a (its share of the merged spring force).
    Returns the number of merged contacts."""
    g = 0
    i = 0
    while i < n:
        e = i + 1
        while e < n and meta[e, 0] == meta[i, 0] and meta[e, 1] == meta[i, 1]:
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
        if A > 0.0:
            nn = math.sqrt(nx * nx + ny * ny + nz * nz)
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
        mdepth[g] = A / W
        mweight[g] = W
        for c in range(i, e):
            grp[c] = g
        g += 1
        i = e
    return g


@numba.njit(cache=True)
def split_forces(adr, efc_force, k0, cone3, grp, share, mframe, frame, n, adr_out, efc_out):
    """Per-slice constraint forces from the merged contacts' (module docstring): the merged contact grp[c] (d.contact
    entry k0 + grp[c], constraint rows from adr[k0 + grp[c]]; normal and, with cone3, the two tangent rows) turned
    into the world force, times share[c], expressed in slice c's own frame into efc_out[3c:3c+3]; adr_out[c] = 3c
    (-1 where the merged contact has no rows). The slices' world forces sum to the merged contact's exactly."""
    for c in range(n):
        g = int(grp[c])
        a = adr[k0 + g] if k0 + g < adr.shape[0] else -1  # -1: not taken (arena full)
        if a < 0:
            adr_out[c] = -1
            continue
        f0 = efc_force[a]
        f1 = efc_force[a + 1] if cone3 else 0.0
        f2 = efc_force[a + 2] if cone3 else 0.0
        mf = mframe[g]
        s = share[c]
        fx = s * (f0 * mf[0] + f1 * mf[3] + f2 * mf[6])
        fy = s * (f0 * mf[1] + f1 * mf[4] + f2 * mf[7])
        fz = s * (f0 * mf[2] + f1 * mf[5] + f2 * mf[8])
        fr = frame[c]
        for r in range(3):
            efc_out[3 * c + r] = fx * fr[3 * r] + fy * fr[3 * r + 1] + fz * fr[3 * r + 2]
        adr_out[c] = 3 * c
