"""Shared helpers of the meshgen tests: seed gears, exact clearance between worm and wheel surfaces."""

from __future__ import annotations

import math
from functools import lru_cache

import numpy as np

from meshgen import assembly, worm
from meshgen.geometry import GearGeometry, derive
from tests.conftest import ROOT
from wormsim.scenario import load_scenario


@lru_cache(maxsize=None)
def seed_geometry(name: str) -> GearGeometry:
    return derive(load_scenario(ROOT / "scenarios" / f"{name}.yaml").gear)


def gear_with(name: str, **changes) -> GearGeometry:
    sc = load_scenario(ROOT / "scenarios" / f"{name}.yaml")
    return derive(sc.gear.model_copy(update=changes))


def clearance_to_worm(g: GearGeometry, wheel_pts: np.ndarray, theta1: float, teeth=range(-3, 4)):
    """Signed clearance of wheel points (wheel frame, tooth 0) from the exact worm thread at worm angle theta1
    and the conjugate wheel angle, over the wheel teeth k in `teeth` (tooth k = tooth 0 rotated 2 pi k / z2).

    Returns (axial, normal) arrays (min over the teeth), +inf where a point is out of the worm's reach
    (beyond the tip cylinder or the threaded length). axial = |wrap(z - p phi)| - H(r) exactly (worm.py (1));
    normal = the same divided by |grad| (first-order normal distance). Points below the worm root (inside the
    core) get -inf.
    """
    theta2 = assembly.wheel_angle(g, theta1)
    winv = np.linalg.inv(assembly.worm_to_assembly(theta1, g))
    ax_best = np.full(len(wheel_pts), np.inf)
    n_best = np.full(len(wheel_pts), np.inf)
    for k in teeth:
        m = winv @ assembly.wheel_to_assembly(theta2 + 2 * math.pi * k / g.z2)
        P = assembly.transform_points(m, wheel_pts)
        r = np.hypot(P[:, 0], P[:, 1])
        reach = (r <= g.r_a1) & (np.abs(P[:, 2]) <= g.worm_length / 2)
        phi = np.arctan2(P[:, 1], P[:, 0])
        u = worm.wrap(P[:, 2] - g.p * phi, g.p_x)
        ax = np.abs(u) - worm.half_thickness(g, r)
        nr = worm.thread_gap(g, P)
        ax = np.where(reach, np.where(r < g.r_f1, -np.inf, ax), np.inf)
        nr = np.where(reach, np.where(r < g.r_f1, -np.inf, nr), np.inf)
        ax_best = np.minimum(ax_best, ax)
        n_best = np.minimum(n_best, nr)
    return ax_best, n_best


def face_samples(mesh, n: int = 4) -> np.ndarray:
    """Points on every face of a mesh: a barycentric grid of n + 1 rows per triangle."""
    T = np.asarray(mesh.triangles)
    out = []
    for i in range(n + 1):
        for j in range(n + 1 - i):
            a, b = i / n, j / n
            out.append(a * T[:, 0] + b * T[:, 1] + (1 - a - b) * T[:, 2])
    return np.concatenate(out)
