"""Per-sample sums over the individual contacts of wormsim.contact3d.runner (pieces and exact flanks): the radial force
on the line of centres and the force-weighted contact radius and efficiency. The sums are compiled (one call per
sample); the efficiency is evaluated once for the whole run from a log of the contacts' radii and weights (the numpy
version per sample cost about 65 us in small-array overhead; docs/contact3d.md, "Exact flanks: cost").
`contact_forces` turns the exact-flank contacts' constraint rows into forces and points (wormsim.contact3d.flank_step,
flank_loop).

Each contact c (force F on the wheel, point p in the assembly frame, worm axis along x at y = -a):

    phi_c = atan2(p_z, p_y + a)                       its angle about the worm axis from the line of centres
    F_r,lc = -sum_c (F_y cos phi_c + F_z sin phi_c)   the force turned onto the line of centres (DIN 3975's F_r2 of a
                                                      single pitch-point contact)
    r_c = |(p_y + a, p_z)|, w_c = |F_c|               its worm radius and weight

and per sample the force-weighted means sum w r / sum w and sum w eta(r) / sum w, eta(r) the wedge efficiency at the
contact's own radius (gear_theory.efficiency_at_radius) with the sample's friction coefficient; nan without contacts.
"""

from __future__ import annotations

import math

import numba
import numpy as np

from wormsim.physics import gear_theory as gt
from wormsim.tooth.pose import N_WORM_PARAMS, to_wheel_body, tooth_angle


@numba.njit(cache=True)
def radial_and_radius(F, pw, m, a, i, log, lm):
    """F_r,lc of contacts 0..m-1 (module docstring), and their rows (i, r_c, w_c) written to log from row lm; returns
    (F_r,lc, sum w, sum w r)."""
    fr = 0.0
    W = 0.0
    wr = 0.0
    for c in range(m):
        y, z = pw[c, 1] + a, pw[c, 2]
        phi = math.atan2(z, y)
        fr += F[c, 1] * math.cos(phi) + F[c, 2] * math.sin(phi)
        wc = math.sqrt(F[c, 0] * F[c, 0] + F[c, 1] * F[c, 1] + F[c, 2] * F[c, 2])
        rc = math.hypot(y, z)
        row = log[lm + c]
        row[0], row[1], row[2] = i, rc, wc
        W += wc
        wr += wc * rc
    return -fr, W, wr


class RadiusLog:
    """The contacts' (sample, radius, weight) rows of a run; `efficiency` at the end (module docstring)."""

    def __init__(self):
        self.buf = np.zeros((4096, 3))
        self.m = 0

    def reserve(self, n: int) -> None:
        """Room for n more rows."""
        while self.m + n > len(self.buf):
            self.buf = np.concatenate([self.buf, np.zeros_like(self.buf)])

    def add(self, i: int, F: np.ndarray, pw: np.ndarray, a: float) -> tuple[float, float]:
        """Sample i's contacts F, pw (n, 3): logs them; returns (F_r,lc, contact radius)."""
        n = len(F)
        self.reserve(n)
        fr, W, wr = radial_and_radius(F, pw, n, a, i, self.buf, self.m)
        self.m += n
        return fr, radius_mean(W, wr)

    def truncate(self, n: int) -> None:
        """Drop the rows of samples n and later (a run that ended early: wormsim.physics.locking)."""
        keep = self.buf[: self.m][self.buf[: self.m, 0] < n]
        self.buf[: len(keep)] = keep
        self.m = len(keep)

    def efficiency(self, mu: np.ndarray, geo, worm_drives: bool) -> np.ndarray:
        """Per sample the force-weighted efficiency at the contacts' radii, mu the samples' friction coefficients."""
        n = len(mu)
        rows = self.buf[: self.m]
        i = rows[:, 0].astype(np.int64)
        eta = gt.efficiency_at_radius(geo.gamma, geo.r1, rows[:, 1], mu[i], geo.alpha_n, backdriving=not worm_drives)
        W = np.bincount(i, weights=rows[:, 2], minlength=n)
        num = np.bincount(i, weights=rows[:, 2] * eta, minlength=n)
        with np.errstate(invalid="ignore", divide="ignore"):
            return np.where(W > 0, num / np.where(W > 0, W, 1.0), np.nan)


def radius_mean(W: float, wr: float) -> float:
    """sum w r / sum w; nan without contacts."""
    return wr / W if W > 0 else float("nan")


@numba.njit(cache=True)
def contact_forces(adr, frame, pos, efc_force, cone3, meta, th2, z2, out, P):
    """flank_step.flank_contact_details' loop over the exact-flank contacts with a constraint row (adr >= 0), in
    order: out[0] the point in the frame of wheel tooth 0, out[1] the force on the wheel (the normal row and, with an
    elliptic cone (cone3), the two tangent rows, through the contact frame), out[2] the point; returns (their number,
    the number of distinct teeth with a nonzero force). P is the kernel's P: with the rigid poses the point is turned
    by -(th2 + 2 pi k / z2) about z; with displaced poses (P holds them, wormsim.tooth.pose) it goes into the
    displaced wheel body's frame (pose.to_wheel_body) and is turned by -(2 pi k / z2 + f_k / r2)."""
    m = 0
    teeth = np.empty(adr.shape[0])
    nt = 0
    displaced = P.shape[0] > N_WORM_PARAMS
    for c in range(adr.shape[0]):
        a = adr[c]
        if a < 0:
            continue
        f0 = efc_force[a]
        f1 = efc_force[a + 1] if cone3 else 0.0
        f2 = efc_force[a + 2] if cone3 else 0.0
        fr = frame[c]
        for i in range(3):
            out[1, m, i] = f0 * fr[i] + f1 * fr[3 + i] + f2 * fr[6 + i]
        x, y, z = pos[c, 0], pos[c, 1], pos[c, 2]
        k = meta[c, 0]
        if displaced:
            bx, by, bz = to_wheel_body(x, y, z, P)
            ang = -(2 * math.pi * k / z2 + tooth_angle(int(k), P)[1])
        else:
            bx, by, bz = x, y, z
            ang = -(th2 + 2 * math.pi * k / z2)
        ca, sa = math.cos(ang), math.sin(ang)
        out[0, m, 0], out[0, m, 1], out[0, m, 2] = ca * bx - sa * by, sa * bx + ca * by, bz
        out[2, m, 0], out[2, m, 1], out[2, m, 2] = x, y, z
        if out[1, m, 0] != 0.0 or out[1, m, 1] != 0.0 or out[1, m, 2] != 0.0:
            new = True
            for t in range(nt):
                if teeth[t] == k:
                    new = False
                    break
            if new:
                teeth[nt] = k
                nt += 1
        m += 1
    return m, nt
