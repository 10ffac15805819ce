"""The flank grid: the wheel's generated flanks of tooth 0 on S slices across the face by N_PROFILE points along
the profile, with their conjugate wheel angles, trimmed where the worm cuts them (wormsim.tooth.trim), and the default
slice count (from the mesh stiffness's fluctuation, wormsim.tooth.mesh_stiffness).

Per gear, once (`flank_grid`, cached in process and on disk): zeta_j = slice centres across the face (0 at the
mid-plane), rho from the worm tip's reach, or the wheel root, to the wheel tip (the active zone of
wormsim.tooth.mesh_stiffness), from meshgen.wheel.space_flank (the envelope; no equation repeated here). Flank A of
tooth 0 is psi_+ of tooth space 0 (it faces -psi), flank B is psi_- of space 1; backlash applied. With each point goes
its conjugate wheel angle c = beta - psi (mesh_stiffness (1)): tooth k's flank point touches the conjugate worm at
wheel angle theta2 = c - 2 pi (k + sigma) / z2 (sigma = 0 flank A, 1 flank B). Points cut by the hob tip edge (root
fillet, not conjugate) are left out: exact flanks carry the working flanks only.
"""

from __future__ import annotations

import functools
import hashlib
import math
import sys
from dataclasses import asdict, dataclass

import numpy as np

from meshgen import wheel, worm
from meshgen.cache import cached
from meshgen.geometry import GearGeometry
from meshgen.worm import worm_params
from wormsim.tooth.mesh_stiffness import mesh_stiffness
from wormsim.tooth.trim import cut_points
from wormsim.tooth.window import window_size

# points along the profile per slice (the gap's parabola refines between them); 128: near the envelope's limit line
# the gap along the profile is no parabola about the contact line, and 64 points left a slice's depth there depending
# on where the line lay between points (docs/decisions/0060-128-profile-points.md)
N_PROFILE = 128
SLICES_COARSE = 8  # simulation.resolution coarse: a quick look (not converged; docs/contact3d.md)
SLICES_FINE_FACTOR = 2  # fine: this many times medium's count (the count medium's convergence is measured against)
SLICE_SHARE = 0.2  # medium: a slice's stiffness K / S at most this share of the mesh stiffness's p2p
SLICES_STEP = 8  # the count rounded up to a multiple of this
SLICES_MIN = 32  # medium: at least this many (a line end's kink inside a slice; docs/decisions/0054)
SLICES_TCA_SAMPLES = 128  # worm angles per mesh cycle of the TCA that gives the fluctuation
# Default slices of a mass-scaled run, at most: mass scaling keeps the means and loses the fluctuation
# (docs/contact3d.md, "Mass scaling"), which default_slices sizes the slices for; the means converge from 16 (seat
# motor 20 s at S = 5000, 16 / 32 slices: efficiency 0.61286 / 0.61279, F_t mean 1289.160 / 1289.169 N; 105 / 196
# us per step)
SLICES_MASS_SCALED = 16


def default_slices(g: GearGeometry, resolution: str) -> int:
    """Slices across the face when contact.slices is not given. Each slice switches a stiffness of up to K / S as the
    contact line's end crosses it, and rings the contact mode; the slicing resolves the mesh stiffness's own change
    over a mesh cycle once K / S is small against it, and the kinks of a line's ends inside a slice (where the line
    runs off the wheel's tip edge, decision 0052) once the slices are at least SLICES_MIN:

        S = max(SLICES_MIN, SLICES_STEP ceil(k_mean / (SLICE_SHARE k_p2p) / SLICES_STEP)),

    k_p2p / k_mean the fluctuation of the zero-load TCA's k(theta) (wormsim.tooth.mesh_stiffness, both flank
    sides, the smaller); the measurements behind the rule and the floor: docs/contact3d.md, "Default slice count",
    and docs/decisions/0054-at-least-32-slices.md. That is medium's count; fine takes SLICES_FINE_FACTOR times it
    (the count medium's convergence is measured against), coarse SLICES_COARSE."""
    if resolution == "coarse":
        return SLICES_COARSE
    ms = mesh_stiffness(g, 1.0, "slices", SLICES_TCA_SAMPLES)
    share = min(float(np.ptp(k) / np.mean(k)) for k in (ms.k_mesh_fwd_n_per_m, ms.k_mesh_rev_n_per_m))
    medium = max(SLICES_MIN, int(SLICES_STEP * math.ceil(1.0 / (SLICE_SHARE * max(share, 1e-3)) / SLICES_STEP)))
    return medium * SLICES_FINE_FACTOR if resolution == "fine" else medium


@dataclass(frozen=True)
class FlankGrid:
    """Tooth 0's two active flanks on (slice, profile) grids; wheel frame, SI."""

    slices: int
    zeta: np.ndarray  # (S,) slice centres
    rho: np.ndarray  # (S, N) radius of the profile points
    psi: np.ndarray  # (2, S, N) polar angle (flank A, flank B), nan where not an active flank point
    xy: np.ndarray  # (2, S, N, 2) the points' (x, y) in the wheel frame (rho cos psi, rho sin psi)
    c: np.ndarray  # (2, S, N) conjugate wheel angle, nan where not active
    c_range: np.ndarray  # (2, S, 2) min and max of c per flank and slice (whole slices are skipped by it)
    span: np.ndarray  # (2, S, 2) first and last active profile index per flank and slice (c is monotone
    # between them; -1, -1 where a slice has none)
    params: np.ndarray  # worm scalars for the kernel (worm_params)


def flank_grid(g: GearGeometry, slices: int, n_profile: int | None = None) -> FlankGrid:
    """The grids of the module docstring (meshgen.wheel's envelope, both flanks of tooth 0) at n_profile points along
    the profile (None: the module's N_PROFILE when called, which a study may set); in process and on disk
    (meshgen.cache, keyed by the geometry, the grid size and the source of the modules that compute the grid)."""
    return _flank_grid_cached(g, slices, N_PROFILE if n_profile is None else n_profile)


@functools.lru_cache(maxsize=16)
def _flank_grid_cached(g: GearGeometry, slices: int, n_profile: int) -> FlankGrid:
    parts = {"g": asdict(g), "slices": slices, "n_profile": n_profile, "code": grid_code_hash()}
    return cached("flankgrid", parts, lambda: _flank_grid(g, slices, n_profile))


@functools.cache
def grid_code_hash() -> str:
    """SHA-256 of the source that determines flank_grid's result (this module, the trim, the pose, the window and
    meshgen's geometry, worm and wheel)."""
    import inspect

    from meshgen import geometry as mg
    from meshgen import worm_forms
    from wormsim.tooth import gap, pose, trim, window

    mods = (sys.modules[__name__], gap, trim, pose, window, mg, worm, wheel, worm_forms)
    return hashlib.sha256("".join(inspect.getsource(m) for m in mods).encode()).hexdigest()


def _flank_grid(g: GearGeometry, slices: int, n_profile: int) -> FlankGrid:
    bw = g.face_width
    zeta = -bw / 2 + (np.arange(slices) + 0.5) * bw / slices
    lo = np.maximum(g.a - np.sqrt(np.maximum(g.r_a1**2 - zeta**2, 0.0)), wheel.root_rho(g, zeta))
    hi = wheel.tip_rho(g, zeta)
    s = np.linspace(0.0, 1.0, n_profile)
    R = lo[:, None] + (hi - lo)[:, None] * s[None, :]
    Z = np.broadcast_to(zeta[:, None], R.shape)
    dj = g.backlash / (2 * g.r2)
    pitch = 2 * math.pi / g.z2
    psi = np.full((2,) + R.shape, np.nan)
    c = np.full((2,) + R.shape, np.nan)
    for i, side in enumerate((+1, -1)):
        sol = wheel.space_flank(g, R, Z, side)
        ok = sol.interior & (hi > lo)[:, None]
        ok &= ~_cut_by_worm(g, R, sol.psi, zeta)
        # flank A: psi_+ of space 0 + dj; flank B: psi_- of space 0 + pitch - dj (meshgen.wheel.tooth_flanks);
        # c is the conjugate angle of the unshifted space-0 flank (flank B's tooth space is 1: sigma in find_contacts)
        shift = dj if side > 0 else pitch - dj
        psi[i] = np.where(ok, sol.psi + shift, np.nan)
        c[i] = np.where(ok, sol.beta - sol.psi, np.nan)
    # the conjugate angles' range per slice; a slice with no flank point has the empty range (inf, -inf)
    fin = np.isfinite(c)
    rng = np.stack([np.where(fin, c, np.inf).min(axis=2), np.where(fin, c, -np.inf).max(axis=2)], axis=-1)
    xy = np.stack([R * np.cos(psi), R * np.sin(psi)], axis=-1)
    act = np.isfinite(c)
    first = np.where(act.any(axis=2), np.argmax(act, axis=2), -1)
    last = np.where(act.any(axis=2), n_profile - 1 - np.argmax(act[:, :, ::-1], axis=2), -1)
    span = np.stack([first, last], axis=-1).astype(np.int64)
    return FlankGrid(
        slices=slices, zeta=zeta, rho=R, psi=psi, xy=xy, c=c, c_range=rng, span=span, params=worm_params(g)
    )


def _cut_by_worm(g: GearGeometry, R: np.ndarray, psi0: np.ndarray, zeta: np.ndarray) -> np.ndarray:
    """Envelope points of tooth space 0 that the conjugate worm cuts into (wormsim.tooth.trim)."""
    xy = np.stack([R * np.cos(psi0), R * np.sin(psi0)], axis=-1)[None]
    return cut_points(xy, zeta, worm_params(g), float(window_size(g)))[0]
