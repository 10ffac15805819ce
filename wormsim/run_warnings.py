"""Warnings a finished run carries in summary.json (`warnings`, a list of one-line texts) and prints on stderr: results
that are computed correctly but that a user should not read as the gear's steady behaviour.

- F_t fluctuation: the steady window's tangential-force peak-to-peak above FT_P2P_SHARE of its mean. A meshing
  fluctuation of a working gear is a few percent of the mean (seeds 001-003 with exact flanks: under 2 %,
  docs/validation.md); half the mean or more means impacts (rattle, convex-piece facets, teeth leaving contact)
  or a steady window that still holds the start-up.
- Contacts outside the flanks (contact3d): a share above OFF_FLANK_FORCE_SHARE of the steady window's contact force
  from contact points outside the wheel tooth's flank region: past the tip (throat torus, meshgen.wheel.tip_rho),
  below the root (root torus, meshgen.wheel.root_rho) or past the face, by more than OFF_FLANK_TOL_MODULES axial
  modules. Such contacts are tip, edge or root contacts, which the meshing forces' theory does not describe.
"""

from __future__ import annotations

import numpy as np

from wormsim.result import Result

FT_P2P_SHARE = 0.5
OFF_FLANK_FORCE_SHARE = 0.01
OFF_FLANK_TOL_MODULES = 0.1


def ft_p2p_warning(summary: dict) -> str | None:
    """F_t p2p over the steady window above FT_P2P_SHARE of |F_t mean|."""
    mean, p2p = summary.get("tangential_force_mean_n"), summary.get("tangential_force_p2p_n")
    if not isinstance(mean, int | float) or not isinstance(p2p, int | float):
        return None
    if not (np.isfinite(mean) and np.isfinite(p2p)) or mean == 0 or p2p <= FT_P2P_SHARE * abs(mean):
        return None
    return (
        f"tangential force p2p {p2p:.4g} N is {100 * p2p / abs(mean):.0f} % of its mean {abs(mean):.4g} N "
        f"(above {100 * FT_P2P_SHARE:.0f} %): impacts, rattle or the start-up in the steady window; "
        "try a finer resolution, contact.geometry flanks or a longer run"
    )


def off_flank_share(points_tooth0: np.ndarray, forces: np.ndarray, geo) -> float:
    """Share of the contact force (|F| summed) from points outside the wheel tooth's flank region.

    points_tooth0: (..., 3) contact points in the frame of wheel tooth 0 (x, y in the wheel plane, z along the
    wheel axis), NaN where no contact; forces: (..., 3) the matching contact forces; geo: GearGeometry (SI)."""
    from meshgen import wheel

    p = np.asarray(points_tooth0, float).reshape(-1, 3)
    f = np.linalg.norm(np.asarray(forces, float).reshape(-1, 3), axis=1)
    ok = np.isfinite(p[:, 0]) & np.isfinite(f)
    p, f = p[ok], f[ok]
    total = float(f.sum())
    if total <= 0:
        return 0.0
    tol = OFF_FLANK_TOL_MODULES * geo.m_x
    z, r = p[:, 2], np.hypot(p[:, 0], p[:, 1])
    out = (
        (np.abs(z) > geo.face_width / 2 + tol) | (r > wheel.tip_rho(geo, z) + tol) | (r < wheel.root_rho(geo, z) - tol)
    )
    return float(f[out].sum()) / total


def off_flank_warning(result: Result) -> str | None:
    """contact3d: the off-flank share of the steady window's contact force above OFF_FLANK_FORCE_SHARE."""
    P, F, built = (result.extra.get(k) for k in ("points_tooth0", "forces_world", "built"))
    if P is None or F is None or built is None or "steady_window_s" not in result.summary:
        return None
    t = result.series["t_s"]
    w0, w1 = result.summary["steady_window_s"]
    sl = (t >= w0) & (t <= w1)
    if not sl.any():
        return None
    share = off_flank_share(P[sl], F[sl], built.geometry)
    if share <= OFF_FLANK_FORCE_SHARE:
        return None
    return (
        f"{100 * share:.1f} % of the contact force acts outside the wheel flanks (past the tip, below the root or "
        "past the face): tip or edge contact; check gear.backlash_mm, gear.face_width_mm and errors:"
    )


def run_warnings(result: Result) -> list[str]:
    """Every warning of a finished run, in a fixed order."""
    return [w for w in (ft_p2p_warning(result.summary), off_flank_warning(result)) if w]
