"""Mesh stiffness k(theta1) of a worm gear pair over one mesh cycle: a tooth contact analysis (TCA) on the
exact, generated wheel flanks (meshgen.wheel), computed once per gear and cached.

Flank and contact lines. meshgen.wheel.space_flank solves the envelope (hob generation) of tooth space 0:
for a wheel-frame point (rho, zeta) it returns the flank angle psi_side(rho, zeta) and the assembly polar
angle beta at which that flank point is in conjugate contact with the worm thread (interior extremum =
equation of meshing n . v12 = 0; Litvin & Fuentes, Gear Geometry and Applied Theory, ch. 6 and 19).
A wheel point sits at assembly angle psi + theta2 (meshgen.assembly), so flank point (rho, zeta) of space 0
touches the worm at the wheel angle

    c(rho, zeta) = beta(rho, zeta) - psi(rho, zeta),                                             (1)

and the same point of space k (rotated by 2 pi k / z2) at theta2 = c - 2 pi k / z2. The CONTACT LINES at
wheel angle theta2 = hand theta1 z1 / z2 (conjugate position) are therefore the iso-lines

    c(rho, zeta) = theta2 + 2 pi k / z2,   k integer,                                            (2)

restricted to the active flank: conjugate (interior) points, inside the wheel blank (root torus .. throat
tip, |zeta| <= b2 / 2) and inside the worm thread (distance from the worm axis r_s <= r_a1 at the contact,
worm axial position |z_s| <= b1 / 2). They are traced on a (zeta, s) grid with contourpy (marching squares,
s in [0, 1] spanning rho from the worm tip's reach a - sqrt(r_a1^2 - zeta^2) to the wheel tip).
Conjugate flanks touch along the whole line at once (line contact, no ease-off), so a line's load is
spread uniformly along it: a linear stiffness k' per unit length.

Stiffness per unit line length k' (wormsim.tooth.stiffness.per_length_stiffness: the one place every level takes it
from; its source is reported as mesh_stiffness_source / contact_stiffness_source):
    contact.stiffness_n_per_m = K given:  k' = K / b2   "scenario" (K is one tooth pair whose contact line spans
                                          the face width, as contact3d reads it: wormsim.contact3d.law; an override
                                          of the teeth's stiffness, docs/decisions/0034-contact-stiffness-override.md)
    not given (contact.stiffness_model):  "teeth" (the default): k' = wormsim.tooth.stiffness.line_stiffness_n_per_m2,
                                          the teeth's bending, shear and rim compliance with the contact flattening,
                                          so that this module's mean k_mesh is the loaded TCA's (wormsim.tooth.ltca) at
                                          ISO 6336-1's reference line load 100 N/mm (compliance.reference_torque_nm);
                                          "hertz": k' = pi E* / 4 (Hertz line contact of seed 001, rigid teeth;
                                          K = pi L E* / 4 per length L)

Projection on the line of action. A wheel lag angle e (worm held) closes the normal gap at a contact point by
arm * e, arm = moment arm of the flank normal about the wheel axis. With the flank written as
G = psi - f(rho, zeta) = 0, grad G = -f_rho e_rho + e_psi / rho - f_zeta e_z, and

    arm = rho (n . e_psi) = 1 / sqrt(f_rho^2 + 1 / rho^2 + f_zeta^2).                            (3)

The torsional mesh stiffness (wheel torque per wheel lag angle) of one flank side is

    K_theta(theta1) = sum over the contact lines of  integral k' arm(s)^2 ds,                    (4)

reported along the line of action at the pitch point as k_mesh = K_theta / arm0^2, arm0 = r2 cos(alpha_n)
cos(gamma) (DIN 3975 force components, wormsim.contact3d.mjcf.mesh_arms). Side +1 is the flank the worm pushes when it
leads (hand theta1 z1 / z2 > theta2: forward drive), side -1 the opposite flank (reverse / back-driven by an
overrunning wheel).

Periodicity: the pattern of space k at theta2 is that of space k + 1 at theta2 + 2 pi / z2, i.e. one mesh cycle
is 2 pi / z1 of worm rotation; samples are taken at theta1 = i (2 pi / z1) / N, i = 0 .. N - 1.

Cache: in-process (functools) and on disk next to meshgen's gear sets (meshgen.cache, env
WORMSIM_CACHE), keyed by the gear geometry, the per-length stiffness, the sample count and CODE_VERSION.
"""

from __future__ import annotations

import functools
import math
from dataclasses import asdict, dataclass

import numpy as np

from meshgen import wheel
from meshgen.cache import cached
from meshgen.geometry import GearGeometry

CODE_VERSION = "mesh-stiffness-2"
GRID_ZETA = 121  # TCA grid across the face width (mean k within ~1.5 % of a 241 x 161 grid)
GRID_S = 81  # TCA grid along the profile (worm tip reach .. wheel tip)


@dataclass(frozen=True)
class MeshStiffness:
    """k(theta1) tables over one mesh cycle (worm angle 0 .. 2 pi / z1, N samples, periodic); SI."""

    theta1_rad: np.ndarray  # (N,) sample angles
    period_rad: float  # 2 pi / z1
    k_theta_fwd_nm_per_rad: np.ndarray  # (N,) K_theta, side +1 (4)
    k_theta_rev_nm_per_rad: np.ndarray  # (N,) side -1
    k_mesh_fwd_n_per_m: np.ndarray  # (N,) along the line of action, K_theta / arm0^2
    k_mesh_rev_n_per_m: np.ndarray
    length_fwd_m: np.ndarray  # (N,) total contact-line length, side +1
    length_rev_m: np.ndarray
    teeth_fwd: np.ndarray  # (N,) wheel teeth in contact, side +1
    teeth_rev: np.ndarray
    arm0_m: float  # r2 cos(alpha_n) cos(gamma)
    stiffness_per_length_n_per_m2: float  # k'
    stiffness_source: str  # STIFFNESS_SOURCES: "teeth" | "scenario" | "hertz"
    samples: int

    def summary(self) -> dict:
        return {
            "mesh_stiffness_samples": self.samples,
            "mesh_stiffness_source": self.stiffness_source,
            "mesh_stiffness_mean_n_per_m": float(np.mean(self.k_mesh_fwd_n_per_m)),
            "mesh_stiffness_min_n_per_m": float(np.min(self.k_mesh_fwd_n_per_m)),
            "mesh_stiffness_max_n_per_m": float(np.max(self.k_mesh_fwd_n_per_m)),
            "contact_line_length_mean_mm": float(np.mean(self.length_fwd_m) * 1e3),
            "teeth_in_contact_mean": float(np.mean(self.teeth_fwd)),
        }


@dataclass(frozen=True)
class _Field:
    """The active flank of one side on the (zeta, s) grid."""

    c: np.ndarray  # (1) contact wheel angle, masked where not an active conjugate point
    xyz: np.ndarray  # (nz, ns, 3) wheel-frame flank points
    arm: np.ndarray  # (nz, ns) (3)


def profile_span(g: GearGeometry, zeta):
    """(lo, hi): the flank radii that s = 0 and s = 1 of the (zeta, s) grid stand for (module docstring): the worm
    tip's reach (at least the wheel root) and the wheel tip."""
    zeta = np.asarray(zeta, float)
    lo = g.a - np.sqrt(np.maximum(g.r_a1**2 - zeta**2, 0.0))  # worm tip reach at beta = -pi/2
    hi = wheel.tip_rho(g, zeta)
    return np.maximum(lo, wheel.root_rho(g, zeta)), hi


def _flank_field(g: GearGeometry, side: int) -> _Field:
    zeta = np.linspace(-g.face_width / 2, g.face_width / 2, GRID_ZETA)
    s = np.linspace(0.0, 1.0, GRID_S)
    lo, hi = profile_span(g, zeta)
    Z, S = np.meshgrid(zeta, s, indexing="ij")
    R = lo[:, None] + (hi - lo)[:, None] * S
    sol = wheel.space_flank(g, R, Z, side)
    psi, beta = sol.psi, sol.beta
    # where the contact happens, in the static worm frame (meshgen.wheel docstring)
    xs = g.a + R * np.sin(beta)
    rs = np.hypot(xs, Z)
    zs = -R * np.cos(beta)
    ok = sol.interior & (rs <= g.r_a1 * (1 + 1e-9)) & (np.abs(zs) <= g.worm_length / 2) & (hi > lo)[:, None]
    c = np.ma.masked_array(beta - psi, mask=~ok)
    # arm (3): derivatives of psi = f(rho, zeta) on the (zeta, s) grid by the chain rule
    dpsi_dz, dpsi_ds = np.gradient(psi, zeta, s)
    dR_dz, dR_ds = np.gradient(R, zeta, s)
    f_rho = dpsi_ds / np.where(np.abs(dR_ds) > 0, dR_ds, 1e-30)
    f_zeta = dpsi_dz - f_rho * dR_dz
    arm = 1.0 / np.sqrt(f_rho**2 + 1.0 / R**2 + f_zeta**2)
    xyz = np.stack([R * np.cos(psi), R * np.sin(psi), Z], axis=-1)
    return _Field(c=c, xyz=xyz, arm=arm)


def _bilinear(F: np.ndarray, i: np.ndarray, j: np.ndarray) -> np.ndarray:
    """Values of grid array F (nz, ns, ...) at fractional indices (i, j)."""
    i0 = np.clip(np.floor(i).astype(int), 0, F.shape[0] - 2)
    j0 = np.clip(np.floor(j).astype(int), 0, F.shape[1] - 2)
    a, b = i - i0, j - j0
    if F.ndim == 3:
        a, b = a[:, None], b[:, None]
    return (
        (1 - a) * (1 - b) * F[i0, j0]
        + a * (1 - b) * F[i0 + 1, j0]
        + (1 - a) * b * F[i0, j0 + 1]
        + a * b * F[i0 + 1, j0 + 1]
    )


def contact_lines(fld: _Field, gen, theta2: float, pitch2: float):
    """The contact lines (2) at wheel angle theta2: (k, fractional grid indices i along zeta, j along s) per line
    piece of space k (at least 2 points)."""
    cmin, cmax = float(fld.c.min()), float(fld.c.max())
    for k in range(math.ceil((cmin - theta2) / pitch2), math.floor((cmax - theta2) / pitch2) + 1):
        for ln in gen.lines(theta2 + k * pitch2):
            if len(ln) >= 2:
                # contourpy works in index coordinates (x = column j along s, y = row i along zeta)
                yield k, ln[:, 1], ln[:, 0]


def _lines_at(fld: _Field, gen, theta2: float, pitch2: float) -> tuple[float, float, int]:
    """(integral of arm^2 ds, total length, teeth) of the contact lines (2) at wheel angle theta2."""
    integral = length = 0.0
    touched: set[int] = set()
    for k, i, j in contact_lines(fld, gen, theta2, pitch2):
        P = _bilinear(fld.xyz, i, j)
        A = _bilinear(fld.arm, i, j)
        ds = np.linalg.norm(np.diff(P, axis=0), axis=1)
        a2 = 0.5 * (A[1:] ** 2 + A[:-1] ** 2)
        integral += float(np.sum(a2 * ds))
        length += float(np.sum(ds))
        if float(np.sum(ds)) > 0:
            touched.add(k)
    return integral, length, len(touched)


def compute(g: GearGeometry, stiffness_per_length: float, source: str, samples: int) -> MeshStiffness:
    """The TCA (module docstring): k(theta1) at `samples` worm angles over one mesh cycle, both flank sides."""
    import contourpy

    period = 2 * math.pi / g.z1
    th1 = np.arange(samples) * period / samples
    pitch2 = 2 * math.pi / g.z2
    out = {}
    for side, tag in ((+1, "fwd"), (-1, "rev")):
        fld = _flank_field(g, side)
        gen = contourpy.contour_generator(z=fld.c, name="serial", corner_mask=True)
        I = np.zeros(samples)
        L = np.zeros(samples)
        T = np.zeros(samples, dtype=int)
        for n, t1 in enumerate(th1):
            t2 = g.hand * t1 * g.z1 / g.z2
            I[n], L[n], T[n] = _lines_at(fld, gen, t2, pitch2)
        out[tag] = (stiffness_per_length * I, L, T)
    arm0 = g.r2 * math.cos(g.alpha_n) * math.cos(g.gamma_m)
    return MeshStiffness(
        theta1_rad=th1,
        period_rad=period,
        k_theta_fwd_nm_per_rad=out["fwd"][0],
        k_theta_rev_nm_per_rad=out["rev"][0],
        k_mesh_fwd_n_per_m=out["fwd"][0] / arm0**2,
        k_mesh_rev_n_per_m=out["rev"][0] / arm0**2,
        length_fwd_m=out["fwd"][1],
        length_rev_m=out["rev"][1],
        teeth_fwd=out["fwd"][2],
        teeth_rev=out["rev"][2],
        arm0_m=arm0,
        stiffness_per_length_n_per_m2=stiffness_per_length,
        stiffness_source=source,
        samples=samples,
    )


def stiffness_at(g: GearGeometry, stiffness_per_length: float, theta1_rad, side: int = 1) -> np.ndarray:
    """K_theta (N m/rad) of flank `side` at arbitrary worm angles (4), without the table: for checks."""
    import contourpy

    fld = _flank_field(g, side)
    gen = contourpy.contour_generator(z=fld.c, name="serial", corner_mask=True)
    th = np.atleast_1d(np.asarray(theta1_rad, float))
    return np.array(
        [stiffness_per_length * _lines_at(fld, gen, g.hand * t1 * g.z1 / g.z2, 2 * math.pi / g.z2)[0] for t1 in th]
    )


@functools.lru_cache(maxsize=32)
def mesh_stiffness(
    g: GearGeometry, stiffness_per_length: float, source: str, samples: int, use_cache: bool = True
) -> MeshStiffness:
    """compute(), cached in process and on disk (module docstring)."""
    parts = {
        "g": asdict(g),
        "kp": stiffness_per_length,
        "src": source,
        "n": samples,
        "v": CODE_VERSION,
        "grid": (GRID_ZETA, GRID_S),
    }
    return cached("meshk", parts, lambda: compute(g, stiffness_per_length, source, samples), use_cache)
