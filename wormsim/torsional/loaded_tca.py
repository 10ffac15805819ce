"""Loaded tooth contact analysis (LTCA) of a displaced worm gear pair for the torsional level: the mesh
torque on the wheel as a table T_side(theta1, x) over the worm angle and the wheel's lag past the first touch.

Geometry and contact law are contact3d's exact-flank ones, evaluated statically, without MuJoCo:
the wheel flanks of wormsim.tooth.grid (tooth 0's grid of S slices across the face, every wheel tooth rotated by
2 pi k / z2 plus its pitch deviation), placed with the worm by meshgen.displaced (1), (2) exactly as
wormsim.tooth.pose passes MuJoCo's body poses to the kernel (X_g = wheel body -> assembly, A = worm body at
theta1 turned back by theta1); `find_contacts` and `slice_weights` give, per (tooth, flank, slice), the depth delta_i
of the displaced flanks' interpenetration, its unit normal n_i (worm -> wheel) and the share w_i of the slice that the
contact line covers. Each contact carries contact3d's linear spring k_c w_i delta_i, k_c = K / S
(wormsim.contact3d.law, n_ref = S; K = k' b2 with wormsim.tooth.mesh_stiffness's k'), so the torque about the
wheel's axis of rotation (direction a and point o of M_g in meshgen.displaced (2)) is

    T(theta1, theta2) = sum_i k_c w_i delta_i ((p_i - o) x n_i) . a.                                         (1)

Rigid bodies, no tooth bending, no contact spreading beyond what the linear springs give (the slice method of gear
dynamics with contact3d's law). Tabulated per side s = +1 (the worm leads), -1 at wheel angles
theta2 = hand theta1 z1 / z2 - s (g_s(theta1) + x), g_s the kinematic TCA's first touch (meshgen.kinematic_tca,
the same gap table the force element uses, linear between its samples), for x on a uniform grid from X_BELOW intervals
below 0 up to X_MAX_FACTOR times the working deflection (doubled until the working torque is reached on every worm
angle and the first column is free of contact; at least the perfect pair's torque at MIN_APPROACH_M), and
SAMPLES_PER_MESH worm angles per mesh cycle over the kinematic TCA's period. T is reported as s T >= 0.

Check on the perfect pair (tests/torsional/test_errors.py): the slope dT/dx against mesh_stiffness's K_theta (4),
which integrates k' arm^2 along the contact LINE, while (1) sums per slice of the face width (contact3d's slice
method); docs/errors.md, section 5a, has the measured ratio.
"""

from __future__ import annotations

import hashlib
import inspect
import math
from dataclasses import asdict, dataclass

import numpy as np

from meshgen import assembly, displaced
from meshgen.cache import cached
from meshgen.geometry import GearGeometry
from wormsim.exceptions import SimulationError
from wormsim.tooth import gap as tooth_gap
from wormsim.tooth import grid as tooth_grid
from wormsim.tooth import kernel as tooth_kernel
from wormsim.tooth import pose as flank_pose
from wormsim.tooth.grid import flank_grid
from wormsim.tooth.kernel import MARGIN_PITCH, TAPER_SHARE, find_contacts, slice_weights

CODE_VERSION = "ltca-3"
KERNEL_MODULES = (tooth_gap, tooth_grid, tooth_kernel, flank_pose)  # their source keys the cache
SLICES = 32  # slices across the face (contact3d's default for the seat motor; wormsim.tooth.grid.default_slices)
SAMPLES_PER_MESH = 32  # worm angles per mesh cycle
X_POINTS = 17  # wheel lag grid points from 0 to the range's end
X_BELOW = 4  # and below 0 (the flank kernel touches up to ~35 urad before the kinematic TCA's g: screw jack)
MAX_DOUBLINGS = 8
MIN_APPROACH_M = 1e-6  # the range covers at least the perfect pair's torque at this approach (an unloaded run)
X_MAX_FACTOR = 1.5  # the grid reaches this multiple of the working torque's deflection on every worm angle


@dataclass(frozen=True)
class LoadedTCA:
    """T_side(theta1, x) tables (module docstring), SI."""

    theta1_rad: np.ndarray  # (N,) worm angles over period_rad
    period_rad: float
    x_rad: np.ndarray  # (M,) wheel lag past the kinematic first touch, increasing
    torque_fwd_nm: np.ndarray  # (N, M) side +1, s T >= 0
    torque_rev_nm: np.ndarray  # (N, M) side -1
    slices: int

    def secant_stiffness_nm_per_rad(self, side: int, torque_nm: float) -> np.ndarray:
        """(N,) torque / x at the lag where the table reaches torque_nm (linear in x between grid points)."""
        T = self.torque_fwd_nm if side > 0 else self.torque_rev_nm
        out = np.empty(len(self.theta1_rad))
        for i, row in enumerate(T):
            x = float(np.interp(torque_nm, row, self.x_rad)) if row[-1] >= torque_nm else np.nan
            out[i] = torque_nm / x if x > 0 else np.nan
        return out


def _poses(g: GearGeometry, dev: displaced.Deviations, th1: float, th2: float, P: np.ndarray):
    """Write X_g and A (wormsim.tooth.pose) into P; returns (o, a) of the wheel's axis of rotation."""
    Xg = displaced.wheel_to_assembly(g, dev, th2)
    A = displaced.worm_to_assembly(g, dev, th1) @ assembly._rz(-th1)
    P[flank_pose.WHEEL : flank_pose.WHEEL + 12] = Xg[:3, :].ravel()
    P[flank_pose.WORM : flank_pose.WORM + 12] = A[:3, :].ravel()
    M, _ = displaced.wheel_mount(g, dev)
    return M[:3, 3], M[:3, 2]


class Evaluator:
    """(1) at (theta1, theta2): the kernel's buffers and parameters for one pair (dev None or zero: the perfect
    pair through the nominal kernel path)."""

    def __init__(self, g: GearGeometry, dev: displaced.Deviations | None, k_pair_n_per_m: float, slices: int):
        self.g, self.dev = g, dev
        self.grid = grid = flank_grid(g, slices)
        self.kc = k_pair_n_per_m / slices
        self.ks = np.arange(g.z2, dtype=np.int64)
        cap = 2 * g.z2 * slices
        self.pos, self.nrm = np.zeros((cap, 3)), np.zeros((cap, 3))
        self.depth, self.meta, self.line = np.zeros(cap), np.zeros((cap, 4)), np.zeros((cap, 2))
        self.weight = np.zeros(cap)
        self.margin = MARGIN_PITCH * 2 * math.pi / g.z2 + g.backlash / (2 * g.r2)
        self.taper_rad = TAPER_SHARE * self.margin  # of the error-free window (wormsim.tooth.kernel.find_contacts)
        self.slices = slices
        self.n = 0
        if dev is None or dev.is_zero():
            self.P = grid.params  # the nominal kernel path
            self.o, self.a = np.zeros(3), np.array([0.0, 0.0, 1.0])
            self.displaced = False
        else:
            self.P = flank_pose.displaced_params(grid.params, dev.tooth_angle_shift(g, np.arange(g.z2)))
            self.margin += flank_pose.error_margin_rad(g, grid, dev)
            self.displaced = True

    def torque(self, th1: float, th2: float) -> float:
        if self.displaced:
            self.o, self.a = _poses(self.g, self.dev, th1, th2, self.P)
        gr = self.grid
        n = find_contacts(
            (gr.xy, gr.c, gr.c_range, gr.span, gr.zeta), self.ks, th1, th2, self.margin, self.P,
            (self.pos, self.nrm, self.depth, self.meta, self.line), self.taper_rad,
        )  # fmt: skip
        self.n = n = slice_weights(self.meta, self.line, n, self.slices, self.pos, self.nrm, self.depth, self.weight)
        if n == 0:
            return 0.0
        arm = np.cross(self.pos[:n] - self.o, self.nrm[:n]) @ self.a
        return float(self.kc * np.sum(self.weight[:n] * self.depth[:n] * arm))

    def band_extent_m(self) -> float:
        """Extent across the face of the last torque()'s contacts, all teeth together: the slices with a loaded
        contact times b2 / S."""
        n = self.n
        loaded = self.depth[:n] * self.weight[:n] > 0
        return len(np.unique(self.meta[:n, 2][loaded])) * self.g.face_width / self.slices


def _gap(kin, th1: float, side: int, g: GearGeometry) -> float:
    if kin is None:
        return g.backlash / (2 * g.r2)
    tab = kin.gap_fwd_rad if side > 0 else kin.gap_rev_rad
    n = len(tab)
    x = (th1 % kin.period_rad) / kin.period_rad * n
    i = int(x)
    f = x - i
    return float(tab[i % n] * (1.0 - f) + tab[(i + 1) % n] * f)


def compute(
    g: GearGeometry,
    dev: displaced.Deviations | None,
    kin,
    k_pair_n_per_m: float,
    working_torque_nm: float,
    k_theta_guess_nm_per_rad: float,
    slices: int = SLICES,
    samples_per_mesh: int = SAMPLES_PER_MESH,
) -> LoadedTCA:
    """The tables (module docstring). kin: the kinematic TCA of dev (None: the perfect pair, gap j / (2 r2), one mesh
    cycle); the x range starts at X_MAX_FACTOR working_torque / k_theta_guess and doubles (module docstring)."""
    ev = Evaluator(g, dev, k_pair_n_per_m, slices)
    mesh = 2 * math.pi / g.z1
    period = kin.period_rad if kin is not None else mesh
    n = max(4, int(round(period / mesh * samples_per_mesh)))
    th1s = np.arange(n) * period / n
    hz = g.hand * g.z1 / g.z2
    t_need = X_MAX_FACTOR * max(working_torque_nm, k_theta_guess_nm_per_rad * MIN_APPROACH_M / g.r2)

    def tables(rows, xs):
        out = {}
        for side in (1, -1):
            T = np.zeros((len(rows), len(xs)))
            for i, t1 in enumerate(th1s[rows]):
                g0 = _gap(kin, t1, side, g)
                for j, x in enumerate(xs):
                    T[i, j] = side * ev.torque(t1, hz * t1 - side * (g0 + x))
            out[side] = T
        return out

    def covers(tabs):  # reaches the torque at the end, no contact at the start, on both sides and every row
        return all(T[:, -1].min() >= t_need and T[:, 0].max() <= 0.0 for T in tabs.values())

    x_max = t_need / k_theta_guess_nm_per_rad
    probe = np.arange(0, n, 4)
    for rows in (probe, np.arange(n)):  # the range from every 4th worm angle first, then the whole table
        for _ in range(MAX_DOUBLINGS):
            xs = np.arange(-X_BELOW, X_POINTS) * (x_max / (X_POINTS - 1))
            tabs = tables(rows, xs)
            if covers(tabs):
                break
            x_max *= 2.0
        else:
            raise SimulationError(f"loaded TCA: no lag range up to {x_max * 1e6:.0f} urad reaches {t_need:.3g} N m")
    return LoadedTCA(
        theta1_rad=th1s, period_rad=period, x_rad=xs, torque_fwd_nm=tabs[1], torque_rev_nm=tabs[-1], slices=slices
    )


def loaded_tca(g, dev, kin, k_pair_n_per_m, working_torque_nm, k_theta_guess_nm_per_rad) -> LoadedTCA:
    """compute(), cached on disk (meshgen.cache) by the geometry, the errors, the kinematic TCA's gaps, the law and the
    code's version (with the source of the flank kernel and its poses, which change on their own)."""
    parts = {
        "g": asdict(g),
        "dev": asdict(dev),
        "kin": [kin.period_rad, kin.gap_fwd_rad.tolist(), kin.gap_rev_rad.tolist()],
        "k": k_pair_n_per_m,
        "t2": working_torque_nm,
        "kg": k_theta_guess_nm_per_rad,
        "grid": (SLICES, SAMPLES_PER_MESH, X_POINTS, X_BELOW, X_MAX_FACTOR),
        "v": CODE_VERSION,
        "kernel": hashlib.sha256("".join(inspect.getsource(m) for m in KERNEL_MODULES).encode()).hexdigest(),
    }
    return cached(
        "ltca",
        parts,
        lambda: compute(g, dev, kin, k_pair_n_per_m, working_torque_nm, k_theta_guess_nm_per_rad),
    )
