"""Trim of the exact-flank grid (wormsim.tooth.kernel.flank_grid): flank points that the conjugate worm would
cut into are not on the generated wheel flank.

meshgen.wheel.space_flank takes each flank point as the envelope maximum over the hob positions found by a grid
search in its reach interval and a Newton iteration. A point short of the maximum lies inside the thread at another
worm position: the hob would have removed it. Before that iteration was safeguarded (docs/decisions/0056-envelope-
maximum-safeguarded-newton.md) it stopped up to 36 um short near the wheel tip at high lead angles (z1 4, q 6, gamma
33.7 deg), and the kernel took such points as flank (a 76 um deep contact against the 47 um of the conjugate pose;
docs/contact3d.md, "Variety"); this trim cut them away, and remains the check. Checked here directly: each
backlash-free grid point is turned with the wheel through the whole mesh window at the conjugate worm angle
(theta1 = theta2 z2 / (hand z1)) and its signed distance from the thread (wormsim.tooth.gap.worm_gap) is taken at
every position; a point whose least distance is below -TRIM_TOL_M is cut away (nan), like the hob-tip-cut root
points.
"""

from __future__ import annotations

import math

import numba
import numpy as np

from wormsim.tooth.gap import worm_gap

TRIM_TOL_M = 5e-8  # generated points: least distance >= 0 (measured); cut points: -1 to -29 um
POSITIONS_PER_PITCH = 64  # wheel positions per pitch in the sweep


@numba.njit(cache=True)
def least_gap(xy, zeta, theta2, P, gap):
    """Least signed distance of every point xy (F, S, N, 2) (wheel frame, tooth 0) from the worm thread over the
    wheel angles theta2 (worm at the conjugate angle); nan points stay nan."""
    out = np.empty(6)
    ratio = P[12]  # hand z1 / z2
    a = P[10]
    for f in range(xy.shape[0]):
        for j in range(xy.shape[1]):
            z = zeta[j]
            for i in range(xy.shape[2]):
                x0, y0 = xy[f, j, i, 0], xy[f, j, i, 1]
                if x0 != x0:
                    gap[f, j, i] = np.nan
                    continue
                best = np.inf
                for t in range(theta2.shape[0]):
                    th2 = theta2[t]
                    ca, sa = math.cos(th2), math.sin(th2)
                    x, y = ca * x0 - sa * y0, sa * x0 + ca * y0
                    from_worm = worm_gap(y + a, -z, -x, th2 / ratio, P, out)
                    if from_worm < best:
                        best = from_worm
                gap[f, j, i] = best


def cut_points(xy_free: np.ndarray, zeta: np.ndarray, P: np.ndarray, window_pitches: float) -> np.ndarray:
    """Mask (F, S, N) of the backlash-free grid points xy_free that the conjugate worm cuts deeper than TRIM_TOL_M,
    swept over +- window_pitches / 2 wheel pitches about the line of centres."""
    pitch = P[11]
    n = max(int(POSITIONS_PER_PITCH * window_pitches), 16)
    theta2 = np.linspace(-window_pitches / 2 * pitch, window_pitches / 2 * pitch, n)
    gap = np.empty(xy_free.shape[:3])
    least_gap(np.ascontiguousarray(xy_free), zeta, theta2, P, gap)
    with np.errstate(invalid="ignore"):
        return gap < -TRIM_TOL_M
