"""One MuJoCo contact per tooth flank (`contact.flank_contacts: tooth`; issue 13): the slice contacts of one tooth
flank (same tooth, same side: meta[:, 0:2], contiguous in the kernel's order) handed to MuJoCo as one contact.

The contact law is a linear spring per contact whose stiffness is scaled by the contact's share w_i of its slice
(wormsim.contact3d.law (1); flanks.slice_weights; flank_handoff._fill_add scales solref by w). With a_i = w_i d_i:

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


@numba.njit(cache=True)
def merge_flanks(meta, n, pos, nrm, depth, weight, grp, share, mpos, mnrm, mdepth, mweight, mfric):
    """The merged contacts of the n slice contacts (module docstring): mpos, mnrm, mdepth, mweight, mfric per tooth
    flank; grp[c] the merged contact of slice contact c, share[c] = a_c / sum a (its share of the slices' spring
    forces). Returns the number of merged contacts."""
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
        cw = 1.0  # |sum a_i n_i| / sum a_i: the normals' wrap around the worm
        if A > 0.0:
            nn = math.sqrt(nx * nx + ny * ny + nz * nz)
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
        mdepth[g] = A / W
        mweight[g] = W * cw
        mfric[g] = 1.0 / cw
        for c in range(i, e):
            grp[c] = g
        g += 1
        i = e
    return g


@numba.njit(cache=True)
def split_forces(adr, efc_force, k0, cone3, grp, share, mfric, n, adr_out, efc_out):
    """Per-slice constraint forces from the merged contacts' (module docstring): the merged contact grp[c] (d.contact
    entry k0 + grp[c], constraint rows from adr[k0 + grp[c]]; normal and, with cone3, the two tangent rows) in its own
    frame, times share[c] / c_w (c_w = 1 / mfric: the slices' spring forces sum to the merged normal force / c_w), as
    slice c's rows in slice c's own frame: efc_out[3c:3c+3], adr_out[c] = 3c (-1 where the merged contact has no
    rows). The frames (flanks.contact_frames) turn with the normal about the worm axis, so a slice's friction keeps
    its direction relative to its own normal."""
    for c in range(n):
        g = int(grp[c])
        a = adr[k0 + g] if k0 + g < adr.shape[0] else -1  # -1: not taken (arena full)
        if a < 0:
            adr_out[c] = -1
            continue
        s = share[c] * mfric[g]
        efc_out[3 * c] = s * efc_force[a]
        efc_out[3 * c + 1] = s * efc_force[a + 1] if cone3 else 0.0
        efc_out[3 * c + 2] = s * efc_force[a + 2] if cone3 else 0.0
        adr_out[c] = 3 * c
