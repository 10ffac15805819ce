"""The stick state's break-away at contact3d: the share of the contacts' static friction that holding the worm needs
(docs/decisions/0058-breakaway-on-static-friction.md).

A stuck pair (wormsim.physics.friction.stuck_after) breaks away when the friction it needs reaches the static limit
(Coulomb). The worm is one rigid body on its hinge, so the need and the limit are taken on the worm's hinge, summed
over the contacts: at rest the friction rows must cancel the generalised force of the normal rows and everything else
on the worm's degree of freedom (qfrc_smooth: the worm's load torque, passive and bias forces),

    need = | sum_i J_n,i f_n,i + qfrc_smooth |,

and on MuJoCo's elliptic cone a contact's friction force is any vector in its tangent plane up to mu_i f_n,i, so
the most the friction rows can hold on the hinge is

    limit = sum_i mu_i f_n,i |(J_t1,i, J_t2,i)|,

with J the constraint rows' Jacobian column of the worm's hinge (mj_mulJacVec on that unit vector), f_n,i the normal
row's force (efc_force), mu_i the contact's own friction coefficient (MuJoCo's cone: mu(0), with a merged contact's
factor). `static_utilisation` = need / limit; the pair breaks away at 1 (friction.BREAKAWAY). This is the
self-locking condition of the whole mesh, rho' >= gamma, evaluated on the run's own contacts and loads: where the
wheel alone loads the mesh it is a geometric ratio near the pitch point's tan(gamma) / tan(rho'), whatever the load's
size or rate.

MuJoCo's own friction forces cannot tell holding from sliding here: its friction rows carry no position term, so a
pair whose load rises sits on the cone (|f_t| = mu f_n on every contact) while it holds. The measurements are in
docs/decisions/0058-breakaway-on-static-friction.md.
"""

from __future__ import annotations

import math

import mujoco
import numba
import numpy as np


@numba.njit(cache=True)
def hinge_utilisation(adr, dim, mu, n, efc_force, col, smooth):
    """need / limit (module docstring) over contacts 0..n-1 (their efc addresses adr, dimensions dim, friction
    coefficients mu), the constraint forces efc_force, the hinge's Jacobian column col and its qfrc_smooth; 0 where no
    contact carries friction. The compiled samples (wormsim.contact3d.flank_samples) and static_utilisation call it."""
    need = smooth
    limit = 0.0
    for k in range(n):
        a = adr[k]
        if a < 0 or dim[k] < 3:
            continue
        fn = efc_force[a]
        need += col[a] * fn
        limit += mu[k] * fn * math.hypot(col[a + 1], col[a + 2])
    if limit <= 0.0:
        return 0.0
    return abs(need) / limit


def static_utilisation(m: mujoco.MjModel, d: mujoco.MjData, dof: int) -> float:
    """need / limit on the worm's hinge `dof` (module docstring) from d's contacts and constraint forces after a step
    (hinge_utilisation); 0 where no contact carries friction (nothing to hold with: the stick state waits for the
    contacts)."""
    n = d.ncon
    if n == 0:
        return 0.0
    unit = np.zeros(m.nv)
    unit[dof] = 1.0
    col = np.zeros(d.nefc)
    mujoco.mj_mulJacVec(m, d, col, unit)  # the worm hinge's column of the constraint Jacobian
    con = d.contact
    return hinge_utilisation(con.efc_address, con.dim, con.friction[:, 0], n, d.efc_force, col, d.qfrc_smooth[dof])
