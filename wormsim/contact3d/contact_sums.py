"""Per-sample sums over the individual contacts of wormsim.contact3d.runner (pieces and exact flanks): the radial force
on the line of centres and the force-weighted contact radius and efficiency. The sums are compiled (one call per
sample); the efficiency is evaluated once for the whole run from a log of the contacts' radii and weights (the numpy
version per sample cost about 65 us in small-array overhead; docs/contact3d.md, "Exact flanks: cost").

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
