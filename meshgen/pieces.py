"""Convex collision pieces of the worm and of one wheel tooth, the gear set, its cache (docs/geometry.md).

MuJoCo collides a mesh geom as its convex hull, so every piece here IS a convex hull of exact surface points:
- worm: per start, the thread ridge cut into helical segments of 2 pi / worm_segments_per_turn: the hull of the
  exact axial ridge profile (both flanks at profile_points radii from r_f1 - 0.1 m_x to the tip r_a1) at
  WORM_SUBSECTIONS + 1 worm angles across the segment; segments at the ends are clipped by z = +-b1/2. The core
  is a cylinder of radius worm_core_radius_m = r_f1 (a collision cylinder/capsule stands in for it).
- wheel: tooth 0 cut into wheel_slabs slabs across the face width, each the hull of SLAB_SUBSECTIONS + 1 exact
  sections; each flank's conjugate part (above the root fillet / undercut cut by the hob tip edge) forms an
  upper piece (both flanks + tip arc), and where there is a fillet a lower, conservative core piece lies inside
  both fillets, so that no hull bridges the concave kink of a working flank.
Error (piece_error_um): signed distance of dense exact points of the ACTIVE flanks (worm: r from the wheel throat
a - r_a2 to r_a1; wheel: from the worm tip's reach rho = a - sqrt(r_a1^2 - zeta^2) to the wheel tip, conjugate
points; the fillet / undercut points apart as "wheel_undercut_zone") from the union of pieces, in micrometres;
negative: the piece bulges beyond the flank, positive: a gap.
piece_error_um = {"worm"|"wheel"[|"wheel_undercut_zone"]: {"max": max |d|, "rms", "min_signed", "max_signed",
"n_points"}}.
"""

from __future__ import annotations

import functools
import math
from dataclasses import asdict, dataclass, field
from typing import TYPE_CHECKING, Callable

import numpy as np

from meshgen import wheel, worm
from meshgen.cache import cache_key, cached
from meshgen.geometry import GearGeometry
from meshgen.lazymesh import LazyMesh

if TYPE_CHECKING:  # trimesh (scipy.spatial, ~1 s) only where pieces or meshes are built: meshgen.lazymesh
    import trimesh

CODE_VERSION = "meshgen-14"


@dataclass(frozen=True)
class Resolution:
    worm_segments_per_turn: int
    wheel_slabs: int  # slabs across the face width per wheel tooth
    profile_points: int  # samples along the tooth profile (each flank)


RESOLUTIONS: dict[str, Resolution] = {
    "coarse": Resolution(24, 4, 6),
    "medium": Resolution(48, 8, 8),
    "fine": Resolution(96, 16, 12),
}


@dataclass
class GearSet:
    geometry: GearGeometry
    resolution: Resolution
    worm_pieces: list[LazyMesh]  # each a trimesh.Trimesh on first use of anything but vertices and faces
    wheel_tooth_pieces: list[LazyMesh]
    tooth_angle_rad: Callable[[int], float]
    worm_visual: LazyMesh
    wheel_visual: LazyMesh
    worm_core_radius_m: float
    piece_error_um: dict
    undercut_fraction: float = 0.0
    info: dict = field(default_factory=dict)


# ----------------------------------------------------------------------------- pieces


def _hull(points: np.ndarray) -> trimesh.Trimesh:
    """Convex hull as a watertight, outward-oriented mesh (scipy/qhull; trimesh's hull may drop sliver faces)."""
    import trimesh
    from scipy.spatial import ConvexHull

    pts = np.asarray(points, float)
    h = ConvexHull(pts)
    used = np.unique(h.simplices)
    remap = np.full(len(pts), -1)
    remap[used] = np.arange(len(used))
    faces = remap[h.simplices]
    V = pts[used]
    n = np.cross(V[faces[:, 1]] - V[faces[:, 0]], V[faces[:, 2]] - V[faces[:, 0]])
    flip = np.einsum("ij,ij->i", n, h.equations[:, :3]) < 0
    faces[flip] = faces[flip][:, ::-1]
    return trimesh.Trimesh(V, faces, process=False)


def _clip_convex(points: np.ndarray, zmin: float, zmax: float) -> np.ndarray | None:
    """Vertices of hull(points) intersected with the slab zmin <= z <= zmax (convex stays convex):
    the hull's vertices inside plus the intersections of its edges with the two planes."""
    h = _hull(points)
    V = np.asarray(h.vertices)
    E = np.asarray(h.edges_unique)
    keep = [V[(V[:, 2] >= zmin) & (V[:, 2] <= zmax)]]
    for z0 in (zmin, zmax):
        za, zb = V[E[:, 0], 2], V[E[:, 1], 2]
        cross = (za - z0) * (zb - z0) < 0
        t = (z0 - za[cross]) / (zb[cross] - za[cross])
        keep.append(V[E[cross, 0]] + t[:, None] * (V[E[cross, 1]] - V[E[cross, 0]]))
    pts = np.concatenate(keep)
    scale = max(float(np.ptp(pts, axis=0).max()), 1e-12)
    _, first = np.unique(np.round(pts / (1e-7 * scale)).astype(np.int64), axis=0, return_index=True)
    pts = pts[np.sort(first)]
    if len(pts) < 4 or np.ptp(pts[:, 2]) <= 0:
        return None
    return pts


WORM_SUBSECTIONS = 4  # the hull of a helical segment spans SUB + 1 exact ridge sections (helix chords: gap only)


def worm_piece_points(
    g: GearGeometry, res: Resolution, start: int, phi0: float, phi1: float, shrink: tuple[float, float] = (0.0, 0.0)
):
    """Exact ridge sections across one helical segment; shrink = (axial offset of the -H flank, of the +H flank)
    toward the thread centre (conservative pieces)."""
    r_in = g.r_f1 - 0.1 * g.m_x
    prof = worm.ridge_profile(g, res.profile_points, r_in)
    r, u = prof[:, 0], prof[:, 1].copy()
    half_n = len(u) // 2  # first half: the -H flank (root -> tip), second: the +H flank
    u[:half_n] += shrink[0]
    u[half_n:] -= shrink[1]
    pts = []
    for phi in np.linspace(phi0, phi1, WORM_SUBSECTIONS + 1):
        pts.append(np.stack([r * np.cos(phi), r * np.sin(phi), g.p * phi + start * g.p_x + u], -1))
    return np.concatenate(pts)


def worm_segment_angles(g: GearGeometry, res: Resolution, start: int):
    """Segment boundaries (worm angles) covering the thread centre z in [-b1/2 - p_x, b1/2 + p_x]."""
    half = g.worm_length / 2 + g.p_x
    ph = sorted([(-half - start * g.p_x) / g.p, (half - start * g.p_x) / g.p])
    d = 2 * math.pi / res.worm_segments_per_turn
    k0, k1 = math.floor(ph[0] / d), math.ceil(ph[1] / d)
    return np.arange(k0, k1 + 1) * d


def worm_shrink(g: GearGeometry, res: Resolution) -> tuple[float, float]:
    """Axial offsets that make the worm pieces conservative. All helical segments are congruent (screw
    symmetry), so the bulge of one segment's hull beyond dense exact flank points (ZA: saddle flank) is measured
    once per flank and the flank moved into the thread by it (CONSERVATIVE_PASSES passes); 0 for ZI."""
    d = 2 * math.pi / res.worm_segments_per_turn
    R, PHI = np.meshgrid(np.linspace(g.r_f1, g.r_a1, 49), np.linspace(0.0, d, 8 * WORM_SUBSECTIONS + 1), indexing="ij")
    checks = [worm.flank_points(g, R, PHI, side).reshape(-1, 3) for side in (-1, 1)]
    r = R[:, 0]
    n_z = float(np.min(1.0 / np.sqrt(1.0 + (g.p / r) ** 2 + worm.half_thickness_dr(g, r) ** 2)))
    shrink = [0.0, 0.0]
    for _ in range(CONSERVATIVE_PASSES + 1):
        piece = _hull(worm_piece_points(g, res, 0, 0.0, d, tuple(shrink)))
        bulge = [max(0.0, -float(union_signed_distance([piece], pts).min())) for pts in checks]
        if max(bulge) <= 1e-9 * g.m_x:
            break
        shrink = [shrink[i] + bulge[i] / n_z for i in range(2)]
    return shrink[0], shrink[1]


def build_worm_pieces(g: GearGeometry, res: Resolution) -> list[trimesh.Trimesh]:
    half = g.worm_length / 2
    shrink = worm_shrink(g, res)
    out = []
    for n in range(g.z1):
        phis = worm_segment_angles(g, res, n)
        for a, b in zip(phis[:-1], phis[1:]):
            pts = worm_piece_points(g, res, n, a, b, shrink)
            z = pts[:, 2]
            if z.max() <= -half or z.min() >= half:
                continue
            if z.min() < -half or z.max() > half:
                pts = _clip_convex(pts, -half, half)
                if pts is None:
                    continue
            out.append(_hull(pts))
    vmax = max(h.volume for h in out)
    return [h for h in out if h.volume > 1e-3 * vmax]  # drop end slivers of the clipping


def conjugate_junction_rho(
    g: GearGeometry, zeta: np.ndarray, side: int, n_grid: int = 48, n_bisect: int = 30
) -> np.ndarray:
    """Per zeta: the lowest radius above which the flank of tooth space 0 on `side` (+1: psi_+, the tooth-0
    flank A; -1: psi_-, flank B of tooth 0 by periodicity) is conjugate (envelope points), i.e. the top of the
    root fillet / undercut cut by the hob tip edge; the root radius where there is none."""
    lo, hi = wheel.root_rho(g, zeta), wheel.tip_rho(g, zeta)
    s = np.linspace(0.0, 1.0, n_grid)
    R = lo[:, None] + s[None, :] * (hi - lo)[:, None]
    Z = np.broadcast_to(zeta[:, None], R.shape)
    conj = wheel.space_flank(g, R, Z, side).interior
    # index of the first grid point from which every point above is conjugate
    bad_above = np.flip(np.cumsum(np.flip(~conj, axis=1), axis=1), axis=1) > 0
    k = np.argmin(bad_above, axis=1)
    k = np.where(bad_above[:, -1], n_grid - 1, k)
    a = R[np.arange(len(zeta)), np.maximum(k - 1, 0)]
    b = R[np.arange(len(zeta)), k]
    none = k == 0
    for _ in range(n_bisect):
        m = 0.5 * (a + b)
        ok = wheel.space_flank(g, m, zeta, side).interior
        b = np.where(ok, m, b)
        a = np.where(ok, a, m)
    return np.where(none, lo, b)


def wheel_slab_sections(
    g: GearGeometry,
    n_profile: int,
    zeta: np.ndarray,
    flank_a: tuple,
    flank_b: tuple,
    n_tip: int = 3,
    tip: bool = True,
    dpsi_a: float = 0.0,
    dpsi_b: float = 0.0,
):
    """Points of tooth-0 sections at the given zeta values: flank A (psi_a) from lo_a to hi_a, flank B from lo_b
    to hi_b (flank_a = (lo_a, hi_a), flank_b = (lo_b, hi_b): radius arrays over zeta), plus n_tip points across the
    tip arc when tip: (len(zeta), m, 3). dpsi_a, dpsi_b >= 0 move flank A / flank B into the tooth by that angle
    (conservative pieces)."""
    (lo_a, hi_a), (lo_b, hi_b) = flank_a, flank_b
    s = np.linspace(0.0, 1.0, n_profile)
    Z = np.broadcast_to(zeta[:, None], (len(zeta), n_profile))
    Ra = lo_a[:, None] + s[None, :] * (hi_a - lo_a)[:, None]
    Rb = lo_b[:, None] + s[None, :] * (hi_b - lo_b)[:, None]
    pa, _ = wheel.tooth_flanks(g, Ra, Z, which="a")
    _, pb = wheel.tooth_flanks(g, Rb, Z, which="b")
    pa, pb = pa + dpsi_a, pb - dpsi_b
    rho, psi = [Ra, Rb], [pa, pb]
    if tip:
        w = np.linspace(0.0, 1.0, n_tip + 2)[1:-1]
        psi.append(pa[:, -1:] + w[None, :] * (pb[:, -1:] - pa[:, -1:]))
        rho.append(np.broadcast_to(hi_a[:, None], psi[-1].shape))
    rho, psi = np.concatenate(rho, axis=1), np.concatenate(psi, axis=1)
    zz = np.broadcast_to(zeta[:, None], rho.shape)
    return np.stack([rho * np.cos(psi), rho * np.sin(psi), zz], -1)


def _fillet_core_sections(g: GearGeometry, zeta, root, top, n: int = 16, dpsi_a: float = 0.0, dpsi_b: float = 0.0):
    """Conservative core of the tooth below the conjugate flanks, per section: the annular sector
    root <= rho <= top, max psi_a <= psi <= min psi_b over that radius range (inside the exact tooth, so the hull
    never bulges into the concave root fillet / undercut where the worm tip passes). (len(zeta), 4, 3)."""
    s = np.linspace(0.0, 1.0, n)
    R = root[:, None] + s[None, :] * (top - root)[:, None]
    Z = np.broadcast_to(zeta[:, None], R.shape)
    pa, pb = wheel.tooth_flanks(g, R, Z)
    lo, hi = pa.max(axis=1) + dpsi_a, pb.min(axis=1) - dpsi_b
    rho = np.stack([root, root, top, top], axis=1)
    psi = np.stack([lo, hi, lo, hi], axis=1)
    zz = np.broadcast_to(zeta[:, None], rho.shape)
    return np.stack([rho * np.cos(psi), rho * np.sin(psi), zz], -1)


def build_wheel_tooth_pieces(g: GearGeometry, res: Resolution) -> list[trimesh.Trimesh]:
    """Slabs across the face width; where the hob tip edge cut a root fillet / undercut (concave), each slab is
    split at each flank's conjugate junction radius, so that no hull bridges the concave kink of a working flank:
    an upper piece (both conjugate flanks + tip) and a lower, conservative core piece (_fillet_core_sections).

    Conservative on the working flanks: the wheel flank is concave across the face width, so a slab's hull
    bulges beyond it between its sections; each flank of each upper piece is moved into the tooth by the bulge
    measured on dense exact points of that slab (two passes), so the pieces never stand proud of the exact
    flank (the error becomes a gap of about that size at the sections)."""
    sub = SLAB_SUBSECTIONS
    zeta = np.linspace(-g.face_width / 2, g.face_width / 2, sub * res.wheel_slabs + 1)
    root, tip = wheel.root_rho(g, zeta), wheel.tip_rho(g, zeta)
    ja, jb = conjugate_junction_rho(g, zeta, +1), conjugate_junction_rho(g, zeta, -1)
    has_fillet = (ja > root + 1e-6 * g.m_x) | (jb > root + 1e-6 * g.m_x)
    c = math.cos(g.alpha_n) * math.cos(g.gamma)  # |n . e_psi| of the flank at the pitch point
    out = []
    for j in range(res.wheel_slabs):
        sl = slice(sub * j, sub * (j + 1) + 1)
        zf = np.linspace(zeta[sl][0], zeta[sl][-1], 8 * sub + 1)
        checks = [_flank_check_points(g, zf, side) for side in (+1, -1)]
        out.append(
            _conservative_hull(
                lambda da, db: wheel_slab_sections(
                    g, res.profile_points, zeta[sl], (ja[sl], tip[sl]), (jb[sl], tip[sl]), dpsi_a=da, dpsi_b=db
                ),
                checks,
                g.m_x,
                c,
            )
        )
        if has_fillet[sl].any():
            # the core stays inside the whole flank (fillet included): checked on root-to-tip points
            full = [_flank_check_points(g, zf, side, from_root=True) for side in (+1, -1)]
            out.append(
                _conservative_hull(
                    lambda da, db: _fillet_core_sections(
                        g, zeta[sl], root[sl], np.minimum(ja, jb)[sl], dpsi_a=da, dpsi_b=db
                    ),
                    full,
                    g.m_x,
                    c,
                )
            )
    return out


CONSERVATIVE_PASSES = 2  # 0: pieces exact at the sections and bulging between them


def _conservative_hull(sections, checks, m_x: float, c: float) -> trimesh.Trimesh:
    """Hull of `sections(dpsi_a, dpsi_b)` made conservative: each flank side is moved into the tooth by the
    bulge measured on its exact check points (`checks[i] = (points, scale)`), repeated CONSERVATIVE_PASSES
    times or until the bulge is below 1e-9 m_x."""
    d = [0.0, 0.0]
    piece = None
    for _ in range(CONSERVATIVE_PASSES + 1):
        piece = _hull(sections(d[0], d[1]).reshape(-1, 3))
        bulge = [max(0.0, -float(union_signed_distance([piece], pts).min())) for pts, _ in checks]
        if max(bulge) <= 1e-9 * m_x:
            break
        d = [d[i] + bulge[i] / (checks[i][1] * c) for i in range(2)]
    return piece


def _flank_check_points(g: GearGeometry, zeta: np.ndarray, side: int, n_rho: int = 49, from_root: bool = False):
    """Exact conjugate points of tooth 0's flank A (side +1) or B (-1) from the junction to the tip at the given
    zeta values (clustered toward the junction, where the bottom edge of the piece cuts across the flank), and
    their mean radius: (points (k, 3), rho_mean)."""
    lo = wheel.root_rho(g, zeta) if from_root else conjugate_junction_rho(g, zeta, side)
    hi = wheel.tip_rho(g, zeta)
    s = np.linspace(0.0, 1.0, n_rho) ** (1 if from_root else 2)
    R = lo[:, None] + s[None, :] * (hi - lo)[:, None]
    Z = np.broadcast_to(zeta[:, None], R.shape)
    a, b = wheel.tooth_flanks(g, R, Z, which="a" if side > 0 else "b")
    psi = a if side > 0 else b
    pts = np.stack([R * np.cos(psi), R * np.sin(psi), Z], -1).reshape(-1, 3)
    return pts, float(R.mean())


SLAB_SUBSECTIONS = 4  # exact sections per slab that its hull spans (2 ends + 3 inside)


# ----------------------------------------------------------------------------- error of the pieces


def _plane_sets(pieces):
    out = []
    for p in pieces:
        n = np.asarray(p.face_normals)
        d = np.einsum("ij,ij->i", n, np.asarray(p.triangles_center))
        out.append((n, d))
    return out


def union_signed_distance(pieces, pts: np.ndarray) -> np.ndarray:
    """Signed distance of points from the union of convex pieces (max over face planes, min over pieces).

    Exact inside a piece and where the nearest feature is a face; a lower bound near edges outside. Each piece
    is evaluated only for the points in its bounding box grown by a fifth of its diagonal (farther points are
    farther than that from it); points near no piece get +inf.
    """
    pts = np.asarray(pts, float)
    best = np.full(len(pts), np.inf)
    for p, (n, d) in zip(pieces, _plane_sets(pieces)):
        lo, hi = np.asarray(p.bounds)
        grow = 0.2 * float(np.linalg.norm(hi - lo))
        near = np.all((pts >= lo - grow) & (pts <= hi + grow), axis=1)
        if not near.any():
            continue
        sd = (pts[near] @ n.T - d[None, :]).max(axis=1)
        best[near] = np.minimum(best[near], sd)
    return best


def _stats(d: np.ndarray) -> dict:
    d_um = d * 1e6
    return {
        "max": float(np.max(np.abs(d_um))),
        "rms": float(np.sqrt(np.mean(d_um**2))),
        "min_signed": float(d_um.min()),
        "max_signed": float(d_um.max()),
        "n_points": int(len(d_um)),
    }


def worm_active_flank_points(g: GearGeometry, phi0: float, phi1: float, n_r: int = 25, n_phi: int = 41):
    r = np.linspace(g.throat_radius, g.r_a1, n_r)
    phi = np.linspace(phi0, phi1, n_phi)
    R, PHI = np.meshgrid(r, phi, indexing="ij")
    return np.concatenate([worm.flank_points(g, R, PHI, s).reshape(-1, 3) for s in (-1, 1)])


def wheel_active_flank_points(g: GearGeometry, n_rho: int = 25, n_zeta: int = 61):
    zeta = np.linspace(-g.face_width / 2, g.face_width / 2, n_zeta)
    lo = g.a - np.sqrt(np.maximum(g.r_a1**2 - zeta**2, 0.0))
    hi = wheel.tip_rho(g, zeta)
    lo = np.minimum(lo, hi)
    s = np.linspace(0.0, 1.0, n_rho)
    R = lo[None, :] + s[:, None] * (hi - lo)[None, :]
    Z = np.broadcast_to(zeta[None, :], R.shape)
    pa, pb = wheel.tooth_flanks(g, R, Z)
    ia = wheel.space_flank(g, R, Z, +1).interior
    ib = wheel.space_flank(g, R, Z, -1).interior
    pts = [np.stack([R * np.cos(p), R * np.sin(p), Z], -1).reshape(-1, 3) for p in (pa, pb)]
    return np.concatenate(pts), np.concatenate([ia.ravel(), ib.ravel()])


def wheel_random_flank_points(g: GearGeometry, n: int, seed: int):
    """n random (rho, zeta) of the active flank region, both flanks of tooth 0, and their conjugate flags."""
    rng = np.random.default_rng(seed)
    zeta = rng.uniform(-g.face_width / 2, g.face_width / 2, n)
    lo = g.a - np.sqrt(np.maximum(g.r_a1**2 - zeta**2, 0.0))
    hi = wheel.tip_rho(g, zeta)
    lo = np.minimum(lo, hi)
    rho = lo + rng.uniform(0, 1, n) * (hi - lo)
    pa, pb = wheel.tooth_flanks(g, rho, zeta)
    ia = wheel.space_flank(g, rho, zeta, +1).interior
    ib = wheel.space_flank(g, rho, zeta, -1).interior
    pts = [np.stack([rho * np.cos(p), rho * np.sin(p), zeta], -1) for p in (pa, pb)]
    return np.concatenate(pts), np.concatenate([ia, ib])


def measure_piece_error(g: GearGeometry, res: Resolution, worm_pieces, wheel_pieces) -> dict:
    # worm: one turn of start 0 around the middle, away from the clipped ends
    d = 2 * math.pi / res.worm_segments_per_turn
    # 4 samples per sub-section interval: the sections, their quarter and mid points (the chords' worst)
    pts = worm_active_flank_points(g, -math.pi, math.pi, n_phi=4 * WORM_SUBSECTIONS * res.worm_segments_per_turn + 1)
    near = [p for p in worm_pieces if abs(p.centroid[2]) < abs(g.p) * (math.pi + 2 * d) + g.p_x]
    dw = union_signed_distance(near, pts)
    pts, conj = wheel_active_flank_points(g, n_zeta=8 * res.wheel_slabs + 1)
    rpts, rconj = wheel_random_flank_points(g, 4000, seed=12345)
    pts, conj = np.concatenate([pts, rpts]), np.concatenate([conj, rconj])
    dh = union_signed_distance(wheel_pieces, pts)
    out = {"worm": _stats(dw), "wheel": _stats(dh[conj])}
    if not conj.all():
        out["wheel_undercut_zone"] = _stats(dh[~conj])
    return out


# ----------------------------------------------------------------------------- gear set + cache


def gear_set_key(g: GearGeometry, res: Resolution) -> dict:
    return {"g": asdict(g), "r": asdict(res), "v": CODE_VERSION}


def _pack(m: trimesh.Trimesh):
    return (np.asarray(m.vertices, float), np.asarray(m.faces, np.int64))


def _unpack(t) -> LazyMesh:
    """The stored arrays as a mesh: a LazyMesh, which builds its trimesh.Trimesh(process=False) on first use."""
    return LazyMesh(t[0], t[1])


def _generate(g: GearGeometry, res: Resolution) -> dict:
    from meshgen import meshes

    worm.check_worm(g, wheel.hob_radius(g))
    wheel.check_wheel(g)
    wp = build_worm_pieces(g, res)
    hp = build_wheel_tooth_pieces(g, res)
    err = measure_piece_error(g, res, wp, hp)
    return {
        "worm_pieces": [_pack(m) for m in wp],
        "wheel_tooth_pieces": [_pack(m) for m in hp],
        "worm_visual": _pack(meshes.worm_mesh(g)),
        "wheel_visual": _pack(meshes.wheel_mesh(g)),
        "piece_error_um": err,
        "undercut_fraction": wheel.undercut_fraction(g),
    }


def build_gear_set(geometry: GearGeometry, resolution: Resolution | str = "medium", use_cache: bool = True) -> GearSet:
    """Generate (or load from the cache) the gear set. Raises GeometryError for undercut / pointed teeth."""
    res = RESOLUTIONS[resolution] if isinstance(resolution, str) else resolution
    g = geometry
    data = cached("gearset", gear_set_key(g, res), lambda: _generate(g, res), use_cache)
    return GearSet(
        geometry=g,
        resolution=res,
        worm_pieces=[_unpack(t) for t in data["worm_pieces"]],
        wheel_tooth_pieces=[_unpack(t) for t in data["wheel_tooth_pieces"]],
        tooth_angle_rad=functools.partial(wheel.tooth_angle, g),
        worm_visual=_unpack(data["worm_visual"]),
        wheel_visual=_unpack(data["wheel_visual"]),
        worm_core_radius_m=g.r_f1,
        piece_error_um=data["piece_error_um"],
        undercut_fraction=data["undercut_fraction"],
        info={"cache_key": cache_key(gear_set_key(g, res)), "code_version": CODE_VERSION},
    )


def _generate_solids(g: GearGeometry) -> dict:
    from meshgen import meshes

    worm.check_worm(g, wheel.hob_radius(g))
    wheel.check_wheel(g)
    return {
        "worm_visual": _pack(meshes.worm_mesh(g)),
        "wheel_visual": _pack(meshes.wheel_mesh(g)),
        "undercut_fraction": wheel.undercut_fraction(g),
    }


def build_solids(geometry: GearGeometry, resolution: Resolution | str = "medium", use_cache: bool = True) -> GearSet:
    """The solid worm and wheel meshes alone, as a GearSet without collision pieces: what a run with exact flanks
    needs (the shafts' inertias, the visual geoms, the recording). The same meshes as build_gear_set's; resolution
    only labels the set. Raises GeometryError for undercut / pointed teeth."""
    res = RESOLUTIONS[resolution] if isinstance(resolution, str) else resolution
    g = geometry
    key = {"g": asdict(g), "v": CODE_VERSION, "solids": True}
    data = cached("solids", key, lambda: _generate_solids(g), use_cache)
    return GearSet(
        geometry=g,
        resolution=res,
        worm_pieces=[],
        wheel_tooth_pieces=[],
        tooth_angle_rad=functools.partial(wheel.tooth_angle, g),
        worm_visual=_unpack(data["worm_visual"]),
        wheel_visual=_unpack(data["wheel_visual"]),
        worm_core_radius_m=g.r_f1,
        piece_error_um={},
        undercut_fraction=data["undercut_fraction"],
        info={"cache_key": cache_key(key), "code_version": CODE_VERSION, "solids_only": True},
    )
