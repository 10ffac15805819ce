"""Kinematic (unloaded) tooth contact analysis of a displaced worm gear pair (docs/errors.md).

For each worm angle theta1 it finds, on each flank side, the wheel angle at which the displaced flanks first touch,
from the exact surfaces: the wheel teeth are meshgen.wheel's enveloped (hob-generated) flanks, sampled on a
(zeta, rho) grid of tooth 0 from the root torus to the tip (backlash applied, tooth k rotated by 2 pi k / z2 plus its
pitch deviation), placed by meshgen.displaced (2); the worm is meshgen.worm's closed-form thread, placed by (1). A
wheel flank point's distance from the thread, d = meshgen.worm.thread_gap of the point in the worm's body frame
(points outside r_f1 <= r <= r_a1 or beyond the threaded length are off the worm), is positive in the clearance.

Side +1 is the flank the worm pushes when it leads (the wheel lags: theta2 < hand theta1 z1 / z2), side -1 the
other (as wormsim.tooth.mesh_stiffness). At the conjugate wheel angle theta2c = hand theta1 z1 / z2 every point
i has a clearance d_i; turning the wheel by -side Delta closes it at the rate r_i = -dd_i / dDelta (a finite
difference). The first touch is

    g_side(theta1) = min_i d_i / r_i                                                                       (1)

refined to below the grid spacing by the minimum of the quadratic through the 3 x 3 neighbourhood of the grid minimum
(a conjugate line contact is a valley of d / r along the contact line, which the quadratic represents exactly) and
corrected by one Newton step at theta2c - side g. For the perfect pair g = j / (2 r2) on both sides.

Outputs over the analysed worm angles (one worm revolution, or one wheel revolution when an error repeats once per
wheel revolution; the common period when both):
    transmission error on side s, TE_s(theta1) = theta2 - theta2c on the flank = -s g_s (wheel angle, rad);
    play (circumferential at the reference circle, the wheel turned from flank to flank with the worm held):
        j(theta1) = r2 (g_+1 + g_-1)                                                                        (2)
    contact pattern (a marking-compound film of MARKING_FILM_M on the wheel flank): at each worm angle, the flank
    points of the working side whose normal clearance at the touching pose is below the film, d_i - r_i g < film;
    centroid (face coordinate zeta, 0 at the wheel's own mid-plane, and radius rho in the wheel's body frame) and
    extent across the face over all analysed angles, weighted by the grid cells' areas.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass

import numpy as np

from meshgen import assembly, displaced, wheel, worm
from meshgen.geometry import GearGeometry, GeometryError

GRID_ZETA = 33  # flank grid across the face
GRID_RHO = 33  # flank grid root .. tip
SAMPLES_PER_MESH = 16  # worm angles per mesh cycle (2 pi / z1)
MARKING_FILM_M = 6e-6  # our choice: a marking compound's film is a few micrometres thick


@dataclass(frozen=True)
class KinematicTCA:
    theta1_rad: np.ndarray  # (N,) analysed worm angles over `period_rad` (periodic)
    period_rad: float
    gap_fwd_rad: np.ndarray  # (N,) g_+1 (1): wheel rotation from the conjugate angle to touch side +1
    gap_rev_rad: np.ndarray  # (N,) g_-1
    contact_fwd: np.ndarray  # (N, 2) (zeta, rho) of the first touch, side +1, wheel body frame, m
    contact_rev: np.ndarray
    pattern_fwd: dict  # film pattern (module docstring), side +1, m
    pattern_rev: dict

    def te_rad(self, side: int) -> np.ndarray:
        """Kinematic transmission error theta2 - theta2c riding on flank `side`."""
        return -self.gap_fwd_rad if side > 0 else self.gap_rev_rad

    def play_m(self, g: GearGeometry) -> np.ndarray:
        """(2)."""
        return g.r2 * (self.gap_fwd_rad + self.gap_rev_rad)

    def summary(self, g: GearGeometry, side: int) -> dict:
        te = self.te_rad(side)
        play = self.play_m(g)
        pat = self.pattern_fwd if side > 0 else self.pattern_rev
        return {
            "transmission_error_kinematic_p2p_urad": float(np.ptp(te) * 1e6),
            "transmission_error_kinematic_flank": "forward" if side > 0 else "reverse",
            "transmission_error_kinematic_samples": int(len(te)),
            "transmission_error_kinematic_period_deg": math.degrees(self.period_rad),
            "backlash_measured_mm": float(np.min(play) * 1e3),
            "backlash_measured_mean_mm": float(np.mean(play) * 1e3),
            "backlash_measured_max_mm": float(np.max(play) * 1e3),
            "contact_pattern_centroid_face_mm": pat["centroid_face_m"] * 1e3,
            "contact_pattern_centroid_radius_mm": pat["centroid_radius_m"] * 1e3,
            "contact_pattern_extent_face_mm": pat["extent_face_m"] * 1e3,
            "contact_pattern_source": f"kinematic (unloaded), marking film {MARKING_FILM_M * 1e6:.0f} um",
        }


def analysis_period(g: GearGeometry, dev: displaced.Deviations) -> float:
    """Worm angle over which the errors repeat: one worm revolution, or the common period with one wheel revolution
    (2 pi z2 / z1 of worm angle) when an error repeats once per wheel revolution: 2 pi z2 / gcd(z1, z2)."""
    if dev.per_wheel_revolution():
        return 2 * math.pi * (g.z2 // math.gcd(g.z1, g.z2) if dev.worm_runout else g.z2 / g.z1)
    return 2 * math.pi


class _Flanks:
    """Tooth 0's flank grids (body frame) of both sides, backlash applied, and their cell areas."""

    def __init__(self, g: GearGeometry, nz: int = GRID_ZETA, nr: int = GRID_RHO):
        zeta = np.linspace(-g.face_width / 2, g.face_width / 2, nz)
        lo, hi = wheel.root_rho(g, zeta), wheel.tip_rho(g, zeta)
        s = np.linspace(0.0, 1.0, nr)
        Z = np.repeat(zeta[:, None], nr, axis=1)
        R = lo[:, None] + (hi - lo)[:, None] * s[None, :]
        psi_a, psi_b = wheel.tooth_flanks(g, R, Z)
        self.pts = {}
        for side, psi in ((1, psi_a), (-1, psi_b)):
            self.pts[side] = np.stack([R * np.cos(psi), R * np.sin(psi), Z], axis=-1)
        self.zeta, self.rho = Z, R
        dz = np.gradient(zeta)
        self.area = dz[:, None] * ((hi - lo) / (nr - 1))[:, None] * np.ones((1, nr))


def _window(g: GearGeometry, dev: displaced.Deviations) -> int:
    """Half-width (teeth) of the wheel teeth examined around the line of centres: those the threaded length reaches
    (from assembly x = -b1/2 - |dw| to +b1/2 + |dw|), plus one."""
    reach = g.worm_length / 2 + abs(dev.worm_axial_offset) + g.p_x
    return int(math.ceil(math.asin(min(reach / g.r_e2, 1.0)) * g.z2 / (2 * math.pi))) + 1


def _refine_min(F: np.ndarray) -> tuple[float, tuple]:
    """Minimum of a (teeth, nz, nr) field to below the grid: the grid minimum, then the minimum of the quadratic
    through its 3 x 3 neighbourhood (minimum-norm step for a valley; kept when it lies within the neighbourhood)."""
    idx = np.unravel_index(int(np.argmin(F)), F.shape)
    k, i, j = idx
    f0 = float(F[idx])
    if not (1 <= i < F.shape[1] - 1 and 1 <= j < F.shape[2] - 1):
        return f0, idx
    N = F[k, i - 1 : i + 2, j - 1 : j + 2]
    if not np.all(np.isfinite(N)):
        return f0, idx
    gx, gy = (N[2, 1] - N[0, 1]) / 2, (N[1, 2] - N[1, 0]) / 2
    hxx, hyy = N[2, 1] - 2 * N[1, 1] + N[0, 1], N[1, 2] - 2 * N[1, 1] + N[1, 0]
    hxy = (N[2, 2] - N[2, 0] - N[0, 2] + N[0, 0]) / 4
    H = np.array([[hxx, hxy], [hxy, hyy]])
    if np.min(np.linalg.eigvalsh(H)) < -1e-12 * max(abs(hxx), abs(hyy), 1e-300):
        return f0, idx
    gvec = np.array([gx, gy])
    x = -np.linalg.pinv(H, rcond=1e-6) @ gvec
    if np.max(np.abs(x)) > 1.0:
        return f0, idx
    val = f0 + gvec @ x + 0.5 * x @ H @ x
    return float(min(val, f0)), idx


def analyse(
    g: GearGeometry,
    dev: displaced.Deviations,
    samples_per_mesh: int = SAMPLES_PER_MESH,
    period_rad: float | None = None,
    grid: tuple[int, int] = (GRID_ZETA, GRID_RHO),
) -> KinematicTCA:
    """The kinematic TCA (module docstring) over `period_rad` of worm angle (default analysis_period)."""
    period = analysis_period(g, dev) if period_rad is None else period_rad
    n = max(4, int(round(period / (2 * math.pi / g.z1) * samples_per_mesh)))
    th1s = np.arange(n) * period / n
    fl = _Flanks(g, *grid)
    hz = g.hand * g.z1 / g.z2
    pitch = 2 * math.pi / g.z2
    half = _window(g, dev)
    Mw, Ew = displaced.worm_mount(g, dev)
    Mg, Eg = displaced.wheel_mount(g, dev)
    tooth0 = wheel.tooth_angle(g, 0)
    h_probe = max(g.backlash, 0.2 * g.m_x * 0.05) / (2 * g.r2)
    teeth = _teeth_points(g, dev, fl, pitch)
    gaps = {1: np.zeros(n), -1: np.zeros(n)}
    where = {1: np.zeros((n, 2)), -1: np.zeros((n, 2))}
    pats = {1: [], -1: []}

    for m, th1 in enumerate(th1s):
        th2c = hz * th1
        # worm body <- assembly (inverse of (1))
        Tw_inv = np.linalg.inv(Mw @ assembly._rz(th1) @ Ew)
        # teeth within the window around the line of centres (tooth k's centre at tooth0 + k pitch + theta2)
        c = (-math.pi / 2 - tooth0 - th2c) / pitch
        ks = np.arange(int(math.floor(c)) - half, int(math.ceil(c)) + half + 1)
        for side in (1, -1):
            B = teeth[side][np.mod(ks, g.z2)]  # (K, nz, nr, 3) body points of the teeth in the window
            flat = B.reshape(-1, 3)

            def to_worm(th2: float, pts: np.ndarray) -> np.ndarray:
                T = Tw_inv @ Mg @ assembly._rz(th2) @ Eg
                return pts @ T[:3, :3].T + T[:3, 3]

            def on_worm(q: np.ndarray) -> np.ndarray:
                r = np.hypot(q[:, 0], q[:, 1])
                return (r >= g.r_f1) & (r <= g.r_a1) & (np.abs(q[:, 2]) <= g.worm_length / 2)

            # points on the worm's reach at the conjugate pose or at the probe pose (the only ones that can touch)
            q0, q1 = to_worm(th2c, flat), to_worm(th2c - side * h_probe, flat)
            sel = np.nonzero(on_worm(q0) & on_worm(q1))[0]
            d0, d1 = worm.thread_gap(g, q0[sel]), worm.thread_gap(g, q1[sel])
            rate = (d0 - d1) / h_probe
            keep = rate > 1e-6 * g.r2
            sel, d0, rate = sel[keep], d0[keep], rate[keep]

            def field(values: np.ndarray) -> np.ndarray:
                F = np.full(flat.shape[0], np.inf)
                F[sel] = values
                return F.reshape(B.shape[:-1])

            gap, _ = _refine_min(field(d0 / rate))
            q2 = to_worm(th2c - side * gap, flat[sel])
            d2 = np.where(on_worm(q2), worm.thread_gap(g, q2), np.inf)
            corr, idx = _refine_min(field(d2 / rate))
            gap += corr
            gaps[side][m] = gap
            _, i, j = idx
            where[side][m] = (fl.zeta[i, j], fl.rho[i, j])
            # film pattern: normal clearance at the touching pose below the film
            film = np.zeros(flat.shape[0], bool)
            film[sel] = d2 - rate * corr < MARKING_FILM_M
            _, ii, jj = np.nonzero(film.reshape(B.shape[:-1]))
            pats[side].append((fl.zeta[ii, jj], fl.rho[ii, jj], fl.area[ii, jj]))

    return KinematicTCA(
        theta1_rad=th1s,
        period_rad=period,
        gap_fwd_rad=gaps[1],
        gap_rev_rad=gaps[-1],
        contact_fwd=where[1],
        contact_rev=where[-1],
        pattern_fwd=_pattern(pats[1]),
        pattern_rev=_pattern(pats[-1]),
    )


def _teeth_points(g: GearGeometry, dev: displaced.Deviations, fl: _Flanks, pitch: float) -> dict:
    """Every tooth's flank points in the wheel's body frame, per side: tooth k = tooth 0 turned by k pitch + f_k / r2
    ((z2, nz, nr, 3))."""
    rot = np.arange(g.z2) * pitch + dev.tooth_angle_shift(g, np.arange(g.z2))
    cr, sr = np.cos(rot)[:, None, None], np.sin(rot)[:, None, None]
    return {
        side: np.stack(
            [
                cr * P[None, ..., 0] - sr * P[None, ..., 1],
                sr * P[None, ..., 0] + cr * P[None, ..., 1],
                np.broadcast_to(P[..., 2], (g.z2,) + P.shape[:2]),
            ],
            axis=-1,
        )
        for side, P in fl.pts.items()
    }


def _pattern(items) -> dict:
    """The marking pattern's centroid (face, radius) and face extent from the (zeta, rho, area) of the film points of
    every sample."""
    z = np.concatenate([a for a, _, _ in items])
    r = np.concatenate([b for _, b, _ in items])
    w = np.concatenate([c for _, _, c in items])
    if not len(z):
        return {"centroid_face_m": float("nan"), "centroid_radius_m": float("nan"), "extent_face_m": 0.0}
    return {
        "centroid_face_m": float(np.sum(w * z) / np.sum(w)),
        "centroid_radius_m": float(np.sum(w * r) / np.sum(w)),
        "extent_face_m": float(np.ptp(z)),
    }


@functools.lru_cache(maxsize=16)
def kinematic_tca(g: GearGeometry, dev: displaced.Deviations, samples_per_mesh: int = SAMPLES_PER_MESH) -> KinematicTCA:
    """analyse(), cached in process (a sweep of runs on one displaced pair computes it once)."""
    return analyse(g, dev, samples_per_mesh)


def check_play(g: GearGeometry, kin: KinematicTCA) -> KinematicTCA:
    """GeometryError (wormsim: ScenarioError, exit 2) when the displaced flanks leave no play at some worm angle
    (they interfere: the sum of the errors exceeds the backlash budget even where each is within its own limit,
    meshgen.displaced)."""
    play = kin.play_m(g)
    if np.min(play) <= 0:
        i = int(np.argmin(play))
        raise GeometryError(
            f"errors: together the errors close the play between the flanks to {play[i] * 1e6:.3g} um at worm angle "
            f"{math.degrees(kin.theta1_rad[i]):.1f} deg (gear.backlash_mm = {g.backlash * 1e3:.4g}): the flanks "
            f"interfere; reduce the errors (the play must stay above 0; docs/errors.md) or raise gear.backlash_mm"
        )
    return kin
