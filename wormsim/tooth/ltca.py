"""Loaded tooth contact analysis (LTCA) of a worm gear pair over one mesh cycle: load distribution over all contact
lines of all wheel teeth, loaded transmission error, mesh stiffness and load sharing from the teeth's compliance.

At worm angle theta1 (wheel angle theta2 = hand theta1 z1 / z2, conjugate pose) the contact lines are those of
wormsim.tooth.mesh_stiffness (the iso-lines of the conjugate-contact field on the flank, traced with contourpy, on
every wheel tooth k; pieces shorter than MIN_PIECE_WIDTHS b2, contourpy's fragments where a line grazes the edge of
the active flank, are left out: seat motor, a 0.007 mm piece carried 443 N/mm, p_H 1569 MPa against <= 380 MPa on
the lines). Each line is cut into segments of length at most b2 / SEGMENTS_PER_WIDTH (midpoint x_i,
length ds_i, moment arm arm_i about the wheel axis, eq. (3) there). With the worm held and the wheel turned back by
its lag angle e (the loaded transmission error as a wheel angle), compatibility at a loaded segment and
non-penetration elsewhere read (a linear complementarity problem, the formulation of FE-based LTCA since Conry &
Seireg, J. Eng. Ind. 93 (1971) 1115):

    arm_i e - g_i = sum_j C_ij F_j + w_loc,i(F_i / ds_i)     where F_i > 0,                              (1)
    arm_i e - g_i <= sum_j C_ij F_j + w_loc,i(F_i / ds_i)    where F_i = 0,
    sum_i arm_i F_i = T2                                     (the wheel torque; rigid-body balance)

F_i the segment's normal force, g_i the kinematic gap (0 for the perfect pair: conjugate flanks touch along the whole
line; with assembly errors and pitch deviations, meshgen.displaced.Deviations, the clearance of each segment to the
displaced worm thread when the first one touches, kinematic_gaps_rad less the perfect pair's at the same points,
along the nominal contact lines, over the mesh cycle from theta1 = 0), C_ij the wheel tooth's influence coefficients
between segments (wormsim.tooth.compliance, bilinear from its flank grid, the same tooth or a neighbour), w_loc the
local approach (the worm thread's per-length compliance and both bodies' Weber-Banaschek flattening at line load
q_i = F_i / ds_i, wormsim.tooth.compliance (1), (2)). The flattening is nonlinear in q: (1) is solved with its
secant compliance w_loc(q_i) / F_i, FLATTENING_ITERATIONS times from the uniform load. Each linear problem is solved
by an active set (the loaded segments; the one that would pull most is dropped, the one that would penetrate most is
added, until neither is left): a dense linear system of the loaded segments with the torque row, unknowns F and e.
C is not symmetric (the load acts on the flank, the displacement is read on the centre line), so this is an LCP
rather than a QP.

Outputs: te_loaded = e(theta1) plus the kinematic lag to the first touch (rad; 0 for the perfect pair); the mesh
stiffness along the line of action k = T2 / (e arm0^2) (e from the first touch), arm0 = r2 cos(alpha_n) cos(gamma)
(wormsim.tooth.mesh_stiffness's convention), at that torque (the flattening makes k grow slowly with load); the load
share of each tooth (its sum of F_i arm_i over T2); the line load q_i and the Hertz pressure
p_H = sqrt(q E* / (pi rho')) (wormsim.tooth.hertz) per segment.
"""

from __future__ import annotations

import functools
import math
from dataclasses import asdict, dataclass

import numpy as np

from meshgen import wheel
from meshgen.cache import cached
from meshgen.displaced import Deviations
from meshgen.geometry import GearGeometry

CODE_VERSION = "ltca-4"
SEGMENTS_PER_WIDTH = 24  # contact-line segments per face width
FLATTENING_ITERATIONS = 6  # secant iterations of the nonlinear flattening
GAP_PROBE_MX = 0.01  # wheel-angle step (as an arc at r2, in axial modules) of the clearance's closing rate
MIN_PIECE_WIDTHS = 0.01  # contact-line pieces shorter than this share of b2 are left out


@dataclass(frozen=True)
class Contacts:
    """The loaded segments at one worm angle, in the wheel-fixed frame (meshgen.wheel's: tooth k is tooth 0 turned by
    2 pi k / z2; the wheel itself stands at theta2 then)."""

    points_m: np.ndarray  # (k, 3) on the flank of space k (wormsim.tooth.mesh_stiffness)
    tooth: np.ndarray  # (k,) space index k
    length_m: np.ndarray  # (k,) ds
    arm_m: np.ndarray  # (k,)
    line_load_n_per_m: np.ndarray  # (k,) q
    pressure_pa: np.ndarray  # (k,) Hertz p_H


@dataclass(frozen=True)
class LTCAResult:
    """(1) over one mesh cycle; SI (module docstring)."""

    theta1_rad: np.ndarray  # (N,)
    torque_nm: float
    te_loaded_rad: np.ndarray  # (N,)
    mesh_stiffness_n_per_m: np.ndarray  # (N,)
    load_share: np.ndarray  # (N, T) per wheel tooth (columns: teeth[] below)
    teeth: np.ndarray  # (T,) the wheel-fixed space index k of each column (space k's flank carries)
    teeth_in_contact: np.ndarray  # (N,)
    contacts: tuple  # (N,) Contacts
    arm0_m: float
    side: int
    face_width_m: float

    def summary(self) -> dict:
        k = float(np.mean(self.mesh_stiffness_n_per_m))
        return {
            "mesh_stiffness_mean_n_per_m": k,
            "mesh_stiffness_per_width_n_per_mm_um": k / self.face_width_m * 1e-9,
            "transmission_error_loaded_p2p_urad": float(np.ptp(self.te_loaded_rad) * 1e6),
            "load_share_max": float(np.max(self.load_share)),
            "teeth_in_contact_mean": float(np.mean(self.teeth_in_contact)),
        }


def _segments(g: GearGeometry, fld, gen, theta2: float, side: int):
    """Contact-line segments at wheel angle theta2: (points, zeta, s, arm, ds, tooth k, conjugate angle c)."""
    from wormsim.tooth import mesh_stiffness as ms

    pitch2 = 2 * math.pi / g.z2
    nz, ns = fld.c.shape
    seg_max = g.face_width / SEGMENTS_PER_WIDTH
    rows = []
    for k, i, j in ms.contact_lines(fld, gen, theta2, pitch2):
        P = ms._bilinear(fld.xyz, i, j)
        d = np.linalg.norm(np.diff(P, axis=0), axis=1)
        s_arc = np.concatenate([[0.0], np.cumsum(d)])
        L = s_arc[-1]
        if L < MIN_PIECE_WIDTHS * g.face_width:
            continue  # a contour fragment at the edge of the active flank (module docstring)
        n = max(1, math.ceil(L / seg_max))
        mid = (np.arange(n) + 0.5) * L / n
        im, jm = np.interp(mid, s_arc, i), np.interp(mid, s_arc, j)
        Pm = ms._bilinear(fld.xyz, im, jm)
        A = ms._bilinear(fld.arm, im, jm)
        zeta = -g.face_width / 2 + im * g.face_width / (nz - 1)
        s = jm / (ns - 1)
        rows.append((Pm, zeta, s, A, np.full(n, L / n), np.full(n, k), np.full(n, theta2 + k * pitch2)))
    if not rows:
        return None
    return [np.concatenate(x) for x in zip(*rows)]


def kinematic_gaps_rad(g: GearGeometry, dev, side: int, theta1: float, P: np.ndarray, k: np.ndarray) -> np.ndarray:
    """Per segment, the wheel rotation (rad, towards flank `side`) that closes its clearance to the displaced worm
    thread at the conjugate wheel angle (meshgen.kinematic_tca (1) at these points): the field's space-0 point P
    turned onto space k's flank with the backlash and tooth k's pitch deviation (meshgen.displaced), placed by both
    mounts, its normal distance d to the thread (meshgen.worm.thread_gap) over its closing rate r = -dd/dtheta2."""
    from meshgen import assembly, displaced, worm

    pitch = 2 * math.pi / g.z2
    dj = g.backlash / (2 * g.r2)
    tooth = k if side > 0 else k - 1  # space k's flank +1 is tooth k's flank a, flank -1 tooth k - 1's flank b
    rot = k * pitch + (dj if side > 0 else -dj) + dev.tooth_angle_shift(g, tooth)
    B = np.column_stack(
        [P[:, 0] * np.cos(rot) - P[:, 1] * np.sin(rot), P[:, 0] * np.sin(rot) + P[:, 1] * np.cos(rot), P[:, 2]]
    )
    Mw, Ew = displaced.worm_mount(g, dev)
    Mg, Eg = displaced.wheel_mount(g, dev)
    Tw_inv = np.linalg.inv(Mw @ assembly._rz(theta1) @ Ew)
    th2c = g.hand * theta1 * g.z1 / g.z2
    h = GAP_PROBE_MX * g.m_x / g.r2

    def gap(th2: float) -> np.ndarray:
        T = Tw_inv @ Mg @ assembly._rz(th2) @ Eg
        return worm.thread_gap(g, B @ T[:3, :3].T + T[:3, 3])

    d0 = gap(th2c)
    rate = (d0 - gap(th2c - side * h)) / h
    return d0 / rate


def _solve(A: np.ndarray, arm: np.ndarray, gap: np.ndarray, torque: float) -> tuple[np.ndarray, float]:
    """The active-set solution of the linear problem (1): (F, e)."""
    n = len(arm)
    act = np.ones(n, dtype=bool)
    F = np.zeros(n)
    e = 0.0
    for _ in range(4 * n + 10):
        idx = np.flatnonzero(act)
        m = len(idx)
        M = np.zeros((m + 1, m + 1))
        M[:m, :m] = A[np.ix_(idx, idx)]
        M[:m, m] = -arm[idx]
        M[m, :m] = arm[idx]
        rhs = np.concatenate([-gap[idx], [torque]])
        x = np.linalg.solve(M, rhs)
        if (x[:m] < 0).any():
            act[idx[np.argmin(x[:m])]] = False
            continue
        F = np.zeros(n)
        F[idx] = x[:m]
        e = float(x[m])
        pen = arm * e - gap - A @ F
        add = (~act) & (pen > 1e-12 * max(abs(e) * arm.max(), 1e-300))
        if not add.any():
            break
        act[np.argmax(np.where(add, pen, -np.inf))] = True
    return F, e


def _at_angle(g, comp, fld, gen, theta1: float, torque: float, side: int, e_star: float, dev=None):
    """(F, e, segments, q, p_H, the kinematic lag to the first touch) at one worm angle."""
    from wormsim.tooth.hertz import curvature_at, hertz_line_pressure_pa

    theta2 = g.hand * theta1 * g.z1 / g.z2
    seg = _segments(g, fld, gen, theta2, side)
    if seg is None:
        raise ValueError("no contact line at this angle")
    P, zeta, s, arm, ds, k, c = seg
    rho = np.hypot(P[:, 0], P[:, 1])
    dk = k[:, None] - k[None, :]
    C = comp.kernel(zeta, s, zeta, s, dk, side)
    inv_rho = curvature_at(g, zeta, rho, c, side)[0]
    psi = np.arctan2(P[:, 1], P[:, 0])
    psi_a, psi_b = wheel.tooth_flanks(g, rho, zeta)
    h_wheel = 0.5 * rho * np.abs(psi_b - psi_a)
    beta = c + psi  # the assembly angle of the contact (wormsim.tooth.mesh_stiffness (1))
    r_worm = np.hypot(g.a + rho * np.sin(beta), zeta)
    gap = np.zeros(len(arm))
    first = 0.0
    if dev is not None:
        # less the perfect pair's: the points are interpolated onto the contact lines, and the quadratic valley of
        # the clearance across a line turns their offset into a clearance of its own (screw jack: +-2 urad of
        # 1333 urad backlash, 7 % of k): the difference keeps only the deviations' part
        ang = kinematic_gaps_rad(g, dev, side, theta1, P, k) - kinematic_gaps_rad(g, Deviations(), side, theta1, P, k)
        first = float(ang.min())
        gap = arm * (ang - first)  # the clearance left when the first point touches, along each normal
    q = np.full(len(arm), torque / float(np.sum(arm * ds)))
    for _ in range(FLATTENING_ITERATIONS):
        w = comp.local_m(q, inv_rho, h_wheel, r_worm)
        A = C + np.diag(w / (q * ds))
        F, e = _solve(A, arm, gap, torque)
        q = np.maximum(F / ds, 1e-6 * torque / float(np.sum(arm * ds)))
    q = F / ds
    return F, e, (P, arm, ds, k), q, hertz_line_pressure_pa(q, e_star, inv_rho), first


def compute(
    g: GearGeometry, materials, torque_nm: float, samples: int, side: int, density: int, comp=None, dev=None
) -> LTCAResult:
    """(1) at `samples` worm angles over one mesh cycle (module docstring); comp: a ToothCompliance to use instead of
    tooth_compliance(g, materials, density) (for studies of its parts)."""
    import contourpy

    from wormsim.physics.gear_theory import effective_modulus_pa
    from wormsim.tooth import mesh_stiffness as ms
    from wormsim.tooth.compliance import tooth_compliance

    comp = tooth_compliance(g, materials, density) if comp is None else comp
    e_star = effective_modulus_pa(materials)
    fld = ms._flank_field(g, side)
    gen = contourpy.contour_generator(z=fld.c, name="serial", corner_mask=True)
    period = 2 * math.pi / g.z1
    th1 = np.arange(samples) * period / samples
    arm0 = g.r2 * math.cos(g.alpha_n) * math.cos(g.gamma)
    te, te_kin, shares, contacts, n_teeth = [], [], [], [], []
    for t1 in th1:
        F, e, (P, arm, ds, k), q, p, first = _at_angle(g, comp, fld, gen, t1, torque_nm, side, e_star, dev)
        te.append(e)
        te_kin.append(first)
        share = {int(kk): float(np.sum((F * arm)[k == kk]) / torque_nm) for kk in np.unique(k)}
        shares.append(share)
        n_teeth.append(sum(1 for v in share.values() if v > 0))
        turn = k * 2 * math.pi / g.z2  # the field's space-0 point -> the same point of space k
        Pk = np.stack(
            [P[:, 0] * np.cos(turn) - P[:, 1] * np.sin(turn), P[:, 0] * np.sin(turn) + P[:, 1] * np.cos(turn)]
        )
        contacts.append(Contacts(np.column_stack([Pk.T, P[:, 2]]), k, ds, arm, q, p))
    teeth = np.array(sorted({kk for sh in shares for kk in sh}))
    load_share = np.array([[sh.get(int(kk), 0.0) for kk in teeth] for sh in shares])
    te_arr = np.array(te)
    return LTCAResult(
        theta1_rad=th1, torque_nm=float(torque_nm), te_loaded_rad=te_arr + np.array(te_kin),
        mesh_stiffness_n_per_m=torque_nm / te_arr / arm0**2, load_share=load_share, teeth=teeth,
        teeth_in_contact=np.array(n_teeth), contacts=tuple(contacts), arm0_m=arm0, side=side,
        face_width_m=g.face_width,
    )  # fmt: skip


@functools.lru_cache(maxsize=32)
def _loaded_contact(g, moduli, materials, torque_nm, samples, side, density, dev) -> LTCAResult:
    from wormsim.tooth import compliance

    parts = {
        "g": asdict(g),
        "moduli": moduli,
        "t": torque_nm,
        "n": samples,
        "side": side,
        "density": density,
        "dev": None if dev is None else asdict(dev),
        "v": (CODE_VERSION, compliance.cache_version(), SEGMENTS_PER_WIDTH, FLATTENING_ITERATIONS),
    }
    return cached("ltca", parts, lambda: compute(g, materials, torque_nm, samples, side, density, dev=dev))


def loaded_contact(
    g: GearGeometry, materials, torque_nm: float, samples: int = 16, deviations=None, side: int = 1, density: int = 1
) -> LTCAResult:
    """compute(), cached in process and on disk (meshgen.cache). torque_nm: the wheel torque (its magnitude);
    side: the loaded flank (+1 forward drive, wormsim.tooth.mesh_stiffness). deviations: a
    meshgen.displaced.Deviations (assembly errors, pitch deviations), or None for the perfect pair (gaps 0)."""
    from wormsim.tooth.compliance import FrozenMaterials, moduli

    dev = None if deviations is None or deviations.is_zero() else deviations
    if not torque_nm:
        raise ValueError("loaded_contact: torque_nm must be non-zero")
    return _loaded_contact(
        g, moduli(materials), FrozenMaterials(materials), abs(float(torque_nm)), samples, side, density, dev
    )
