"""The worm gap: the signed normal distance of a point from the worm thread, in compiled form (numba), for the
contact kernel (wormsim.tooth.kernel) and the trim (wormsim.tooth.trim).

A point in the static worm frame (meshgen.assembly: x_s = y + a, y_s = -z, z_s = -x) at radius r and angle phi has the
closed form of meshgen.worm.thread_gap (equations (1), (2) there):

    u = wrap(z_s - p (phi - theta1), p_x),   G = (|u| - H(r)) / |grad G|,
    grad G = sign(u) (e_z - (p / r) e_phi) - H'(r) e_r,                                              (1)

negative inside the thread, valid for r_f1 <= r <= r_a1 and |z_s| <= b1 / 2; worm_gap_ext evaluates it past these
bounds too (the flank extended) and returns the excess by which the point lies outside. H(r) is meshgen's compiled
one (meshgen.worm_forms_jit.thread_half_thickness, on meshgen.worm.worm_params); tests/tooth/test_kernel.py pins the
gap to meshgen.worm.thread_gap. The angle phi is atan(y_s / x_s) where x_s > 0 (the C library's atan costs about
half its atan2; the two agree within an ulp, the contacts within 1e-12 relative: docs/performance.md), atan2 elsewhere.
"""

from __future__ import annotations

import math

import numba
import numpy as np

from meshgen import worm
from meshgen.geometry import GearGeometry
from meshgen.worm_forms_jit import thread_half_thickness


@numba.njit(cache=True, inline="always")
def wrap(x, period):
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
    phi = math.atan(ys / xs) if xs > 0.0 else math.atan2(ys, xs)  # atan: about half atan2's cost (module docstring)
    u = wrap(zs - p * (phi - theta1), p_x)
    H, dH = thread_half_thickness(r, P)
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


def gap_reference(g: GearGeometry, pts_static: np.ndarray, theta1: float) -> np.ndarray:
    """meshgen.worm.thread_gap on static-worm-frame points (the reference the kernel is tested against)."""
    return worm.thread_gap(g, pts_static, theta1)
