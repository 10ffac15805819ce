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
wheel alone loads the mesh it is a geometric ratio, tan(gamma) / tan(rho') near the pitch point, whatever the load's
size or rate (the user's gear, rho' = gamma + 0.3 deg: 0.939 through a 2 ms and a 20 ms ramp of 150 N m).

MuJoCo's own friction forces cannot tell holding from sliding here: its friction rows carry no position term, so a
pair whose load rises sits on the cone (|f_t| = mu f_n on every contact) while it holds (the same gear, 20 ms ramp:
|f_t| / (mu f_n) 1.000 on each contact, 0.998 summed, the worm creeping at 0.15 rpm and held at 0.007 rpm after the
ramp).
"""

from __future__ import annotations

import mujoco
import numpy as np


def static_utilisation(m: mujoco.MjModel, d: mujoco.MjData, dof: int) -> float:
    """need / limit on the worm's hinge `dof` (module docstring) from d's contacts and constraint forces after a step;
    0 where no contact carries friction (nothing to hold with: the stick state waits for the contacts)."""
    n = d.ncon
    if n == 0:
        return 0.0
    con = d.contact
    adr = np.asarray(con.efc_address[:n])
    keep = (adr >= 0) & (np.asarray(con.dim[:n]) >= 3)
    if not keep.any():
        return 0.0
    adr, mu = adr[keep], np.asarray(con.friction[:n, 0])[keep]
    unit = np.zeros(m.nv)
    unit[dof] = 1.0
    col = np.zeros(d.nefc)
    mujoco.mj_mulJacVec(m, d, col, unit)  # the worm hinge's column of the constraint Jacobian
    f = d.efc_force
    fn = f[adr]
    limit = float(np.sum(mu * fn * np.hypot(col[adr + 1], col[adr + 2])))
    if limit <= 0.0:
        return 0.0
    need = abs(float(np.dot(col[adr], fn)) + float(d.qfrc_smooth[dof]))
    return need / limit
