"""Backlash against the collision pieces: the check contact3d makes before it simulates (near-zero backlash).

The wheel tooth is thinned by the circumferential backlash j at d2, j / 2 per flank (meshgen.wheel). Along the
flank normal at the pitch point that is the clearance per flank (DIN 3975 force directions, as
wormsim.physics.gear_theory.mesh_arms_m)

    c = (j / 2) cos(alpha_n) cos(gamma).                                                          (1)

meshgen's convex pieces are made conservative (moved inside the exact flanks by their measured bulge), but a
residual bulge b remains (piece_error_um: the most negative signed distance of dense exact flank points from the
union of pieces, docs/geometry.md): worm flanks, wheel conjugate flanks, wheel fillet / undercut zone. Worm piece
against wheel piece the clearance is about c - b_worm - b_wheel (tests/meshgen/test_pieces.py), so contact3d requires

    c > b = max(0, -min_signed(worm)) + max(0, -min_signed(wheel), -min_signed(wheel_undercut_zone)),   (2)

i.e. j > j_min = 2 b / (cos(alpha_n) cos(gamma)). Below it the pieces can overlap at the rigid-conjugate pose: a
preload that rigid pieces with a soft contact turn into a friction drag on the back flanks (measured, involute_41
with j = 0: 3.5 um overlap over a mesh cycle at coarse, efficiency 0.571 against 0.655 with j = 0.2 mm; 0.55 um at
fine, 0.625 against 0.653; docs/stability_backlash_locking.md). (2) is a practical limit, not a guarantee: b comes
from sampled points, and the overlap measured at j = 0 (piece_play) was 0.01-0.25 b for involute_41 and 1.1-1.8 b
(at most 0.53 um) for the seat motor and the screw jack; above j_min no overlap was found in any case run.
Zero backlash (both flanks touching) is physically a
preloaded pair: contact3d does not model a preload, so j = 0 always fails (2) (every level leaves some bulge) and
is rejected with j_min; a backlash just above j_min gives a pair that touches both flanks within the piece error.

`piece_play` measures what the model really has (the wheel's free rotation between its flanks with the worm
held, at the rigid-conjugate pose, over one mesh cycle); it checks (2) in the tests and gives the docs' numbers.
"""

from __future__ import annotations

import math

import mujoco
import numpy as np

from meshgen.geometry import GearGeometry
from wormsim.contact3d.slots import repose_window
from wormsim.physics.units import MM
from wormsim.scenario import ScenarioError

UM = 1e-3 * MM  # m per micrometre (piece_error_um)


def flank_clearance_m(geo: GearGeometry) -> float:
    """(1): flank-normal clearance per flank at the pitch point, (j / 2) cos(alpha_n) cos(gamma)."""
    return 0.5 * geo.backlash * math.cos(geo.alpha_n) * math.cos(geo.gamma)


def piece_bulge_m(piece_error_um: dict) -> float:
    """b of (2): residual bulge of the worm pieces plus that of the wheel pieces (conjugate flanks or fillet zone,
    whichever bulges more), from meshgen's piece_error_um (negative min_signed = bulge)."""

    def bulge(part: str) -> float:
        e = piece_error_um.get(part)
        return max(0.0, -float(e["min_signed"])) if e else 0.0

    return (bulge("worm") + max(bulge("wheel"), bulge("wheel_undercut_zone"))) * UM


def min_backlash_m(geo: GearGeometry, bulge_m: float) -> float:
    """j_min = 2 b / (cos(alpha_n) cos(gamma)): the smallest circumferential backlash (2) allows."""
    return 2.0 * bulge_m / (math.cos(geo.alpha_n) * math.cos(geo.gamma))


def _round_up(x: float, digits: int = 2) -> float:
    """x rounded UP to `digits` significant digits (so that a value quoted in a message passes the check)."""
    if x <= 0:
        return 0.0
    e = math.floor(math.log10(x)) - digits + 1
    return math.ceil(x / 10**e * (1 - 1e-12)) * 10**e


def check_backlash(geo: GearGeometry, piece_error_um: dict, resolution: str) -> dict:
    """Raise ScenarioError (exit 2) naming gear.backlash_mm, its allowed range at this resolution and the finer
    resolution when (2) fails; otherwise return the numbers for the model's meta (m)."""
    c, b = flank_clearance_m(geo), piece_bulge_m(piece_error_um)
    j_min = min_backlash_m(geo, b)
    if c <= b:
        j_mm = geo.backlash / MM
        quoted = _round_up(j_min / MM * (1 + 1e-6) + 1e-9)
        what = (
            "zero backlash (both flanks touching) is a preloaded pair, which contact3d's rigid collision pieces "
            "cannot hold"
            if geo.backlash == 0
            else f"gear.backlash_mm = {j_mm:.4g} leaves a flank-normal clearance (j/2) cos(alpha_n) cos(gamma) of "
            f"{c / UM:.3g} um per flank"
        )
        raise ScenarioError(
            f"{what}: at simulation.resolution {resolution} the collision pieces bulge up to {b / UM:.3g} um beyond "
            f"the exact flanks, so worm and wheel pieces can interfere at the conjugate pose: a preload that drags on "
            f"both flanks (jams the mesh); give gear.backlash_mm > {quoted:.2g} mm (j_min = 2 b / (cos(alpha_n) "
            f"cos(gamma)) = {j_min / MM:.3g} mm at resolution {resolution})"
            + (", or simulation.resolution fine (its pieces bulge least)" if resolution != "fine" else "")
        )
    return {"flank_clearance_m": c, "piece_bulge_m": b, "backlash_min_m": j_min}


FINER = {"coarse": "medium", "medium": "fine"}


def conjugate_interference_m(bm, n_angles: int = 16) -> float:
    """Deepest penetration of any worm piece into any wheel piece at the rigid-conjugate pose
    theta2 = hand theta1 z1 / z2, over n_angles worm angles of one mesh cycle (MuJoCo's collision only: a few
    milliseconds). (2) rests on meshgen's sampled bulge; this is the model itself. Found needed: a wide-faced
    gear (m_x 4 mm, q 16, z2 80, b2 50 mm) passed (2) at coarse (sampled bulge 13 um against c = 56 um) while its
    coarse wheel slabs stood 130 um into the worm's pieces, and the run jammed (efficiency 0.0006)."""
    depth, restore = _depth_probe(bm)
    try:
        return max(depth(th1, th2) for th1, th2 in _conjugate_poses(bm.geometry, n_angles))
    finally:
        restore()


INTERFERENCE_TOLERANCE = 0.05  # of the working deflection F_n / K_pair (a preload of 5 % of the working load)


def check_conjugate_interference(bm, resolution: str, working_normal_force_n: float) -> float:
    """Raise ScenarioError (exit 2) when the pieces interfere at the conjugate pose (conjugate_interference_m) by
    more than INTERFERENCE_TOLERANCE of the mesh's working deflection F_n / K_pair (the overlap is then a preload of
    more than 5 % of the working load; measured: involute_41 coarse, j = 0, 3.5 um against a 2.7 um deflection,
    efficiency -13 %; seat motor coarse at j_min of (2), 0.09 um against 88 um: no effect). The message names the
    finer resolution and gear.backlash_mm. Returns the interference (m)."""
    pen = conjugate_interference_m(bm)
    tol = INTERFERENCE_TOLERANCE * working_normal_force_n / bm.law.pair_stiffness_n_per_m
    if pen > tol:
        g = bm.geometry
        finer = FINER.get(resolution)
        cure = (
            f"use simulation.resolution {finer} (allowed: coarse, medium, fine; finer pieces bulge less) or "
            if finer
            else ""
        )
        raise ScenarioError(
            f"at simulation.resolution {resolution} the collision pieces of worm and wheel interfere by "
            f"{pen / UM:.3g} um at the rigid-conjugate pose (gear.backlash_mm = {g.backlash / MM:.4g} leaves "
            f"{flank_clearance_m(g) / UM:.3g} um per flank; allowed: {tol / UM:.3g} um, 5 % of the working "
            f"deflection): the mesh would start jammed; {cure}raise gear.backlash_mm"
        )
    return pen


def _conjugate_poses(g: GearGeometry, n_angles: int):
    """(theta1, theta2) of the rigid-conjugate pose theta2 = hand theta1 z1 / z2 at n_angles worm angles over one
    mesh cycle (2 pi / z1)."""
    for th1 in np.linspace(0.0, 2 * math.pi / g.z1, n_angles, endpoint=False):
        yield float(th1), g.hand * float(th1) * g.z1 / g.z2


def _depth_probe(bm):
    """(depth(theta1, theta2), restore()): the deepest piece penetration at a pose (MuJoCo's collision, margin 0;
    the wheel window re-posed for theta2) on a scratch MjData; restore() puts the window back."""
    m = bm.model
    d = mujoco.MjData(m)
    q1 = int(m.jnt_qposadr[m.dof_jntid[bm.worm_dof]])
    q2 = int(m.jnt_qposadr[m.dof_jntid[bm.wheel_dof]])
    quat0 = m.body_quat[bm.slot_bodies].copy()

    def depth(th1: float, th2: float) -> float:
        d.qpos[q1], d.qpos[q2] = th1, th2
        repose_window(bm, th2)
        mujoco.mj_kinematics(m, d)
        mujoco.mj_collision(m, d)
        return max(0.0, -float(np.min(d.contact.dist[: d.ncon]))) if d.ncon else 0.0

    def restore() -> None:
        m.body_quat[bm.slot_bodies] = quat0

    return depth, restore


def piece_play(bm, n_angles: int = 8, iterations: int = 32) -> dict:
    """The circumferential play the collision pieces really leave, at the rigid-conjugate pose theta2 =
    hand theta1 z1 / z2 for n_angles worm angles over one mesh cycle (2 pi / z1): with the worm held, the wheel is
    turned each way by bisection until some piece pair penetrates (MuJoCo's collision, margin 0). Returns, in m:
    play_min / play_max (arc at r2, both sides added), interference_max (deepest penetration at the conjugate pose;
    0 when the pieces are clear there)."""
    g = bm.geometry
    depth, restore = _depth_probe(bm)
    pitch = 2 * math.pi / g.z2
    plays, pens = [], []
    try:
        for th1, th2 in _conjugate_poses(g, n_angles):
            pen = depth(th1, th2)
            pens.append(pen)
            if pen > 0:
                plays.append(0.0)
                continue
            play = 0.0
            for s in (1.0, -1.0):
                lo, hi = 0.0, 0.25 * pitch
                for _ in range(iterations):
                    mid = 0.5 * (lo + hi)
                    lo, hi = (lo, mid) if depth(th1, th2 + s * mid) > 0 else (mid, hi)
                play += lo
            plays.append(play * g.r2)
    finally:
        restore()
    return {"play_min_m": float(min(plays)), "play_max_m": float(max(plays)), "interference_max_m": float(max(pens))}
