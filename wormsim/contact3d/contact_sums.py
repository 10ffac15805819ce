"""Per-sample sums over the individual contacts of wormsim.contact3d.runner (pieces and exact flanks): the radial force
on the line of centres and the force-weighted contact radius and efficiency, compiled (one call per sample; the numpy
version cost about 65 us per sample in small-array overhead).

Each contact c (force F on the wheel, point p in the assembly frame, worm axis along x at y = -a):

    phi_c = atan2(p_z, p_y + a)                       its angle about the worm axis from the line of centres
    F_r,lc = -sum_c (F_y cos phi_c + F_z sin phi_c)   the force turned onto the line of centres (DIN 3975's F_r2 of a
                                                      single pitch-point contact)
    r_c = |(p_y + a, p_z)|, w_c = |F_c|               its worm radius and weight

and the force-weighted means sum w r / sum w and sum w eta(r) / sum w, eta(r) = gear_theory.efficiency_at_radius.
"""

from __future__ import annotations

import math

import numba
import numpy as np

from wormsim import gear_theory as gt


@numba.njit(cache=True)
def radial_and_radius(F, pw, m, a, r, w):
    """F_r,lc and, per contact, r_c into r and w_c into w (module docstring) for contacts 0..m-1; returns
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
        r[c], w[c] = rc, wc
        W += wc
        wr += wc * rc
    return -fr, W, wr


def radius_efficiency(r, w, W: float, wr: float, geo, mu: float, worm_drives: bool) -> tuple[float, float]:
    """Force-weighted worm radius of the contacts and the wedge efficiency at each contact's own radius
    (gear_theory.efficiency_at_radius), averaged with the contact forces as weights. (nan, nan) without contacts."""
    if W <= 0:
        return float("nan"), float("nan")
    eta = gt.efficiency_at_radius(geo.gamma, geo.r1, r, mu, geo.alpha_n, backdriving=not worm_drives)
    return wr / W, float(np.dot(w, eta)) / W


def contact_sums(F: np.ndarray, pw: np.ndarray, geo, mu: float, worm_drives: bool) -> tuple[float, float, float]:
    """(F_r,lc, contact radius, efficiency at the contact radius) of contacts F, pw (n, 3) (module docstring)."""
    n = len(F)
    r, w = np.empty(n), np.empty(n)
    fr, W, wr = radial_and_radius(F, pw, n, geo.a, r, w)
    return (fr, *radius_efficiency(r, w, W, wr, geo, mu, worm_drives))
