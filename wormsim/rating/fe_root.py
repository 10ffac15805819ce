"""FE tooth-root stress of the wheel from the simulated contact (ISO/TS 14521 calls this kind of analysis method C).

Model:
* Solid: one wheel tooth with its rim, from meshgen's exact wheel geometry (meshgen.wheel: the flanks of tooth 0,
  the tip on the throat torus, the root on the root torus), every face-width section's outline from the middle of
  the space before the tooth to the middle of the space after it, down to a rim of RIM_DEPTH_MX axial modules below
  the wheel's throat root circle. meshgen's wheel has a sharp corner between flank and root, where linear elasticity
  has no finite stress: each section's corner is rounded with the root radius of the ISO 53 basic rack profile A,
  rho_fP = 0.38 m (FILLET_COEF; ISO 53:1998 profile A, as any gear program lists it, e.g. the KISSsoft report cited in
  wormsim.rating.materials). The sections are lofted into one watertight triangulated surface.
* Mesh: gmsh (tetrahedra inside the given surface triangulation); the element size is set by the surface sampling
  (`density`: 1 coarse, 2 the h/2 mesh).
* Solver: scikit-fem, quadratic tetrahedra, isotropic linear elasticity (wheel E, nu of materials.wheel); the rim's
  cut faces (the two space-middle planes below the root and the inner face) are clamped.
* Load: the contact lines of the loaded tooth contact analysis of the torsional level
  (wormsim.tooth.mesh_stiffness: the contour lines of the conjugate-contact field on the flank) with that
  analysis's load law: a line element ds carries k' arm ds of the mesh's deflection, so the normal force per length
  is q = T2 arm / sum over all teeth in contact of the integral of arm^2 ds, frictionless, along the flank normal.
  Sampled at `positions` wheel angles evenly over the tooth's whole engagement (entry to exit), the share of the
  teeth in contact at each from the same lines.
* Output: the root stress at a point is the first principal stress of the stress tensor averaged over the ball of
  AVERAGING_RADIUS_MX axial modules around it (a fixed physical radius, below the fillet radius: the quadrature
  points of the quadratic elements weighted by their volume), so it does not depend on the element size and has a
  finite limit under refinement where the pointwise stress has none (the contact samples' loads, the fillet meeting
  the end face). root_stress_max_mpa is its largest value over the centres in the root band (element centroids
  within ROOT_BAND_MX axial modules of the root torus radius), its position, and its range over the positions. Left
  out as centres: those within LOAD_EXCLUSION_MX of a contact sample at that position (the load patch's own stress),
  and within EDGE_EXCLUSION_MX of the wheel's end faces, where the contact lines end on the free edge.
  On the screw jack (3 positions) h vs h/2 (density 1 / 2) give 6.55 / 6.52 MPa (docs/rating.md, 'FE root stress').
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from meshgen import wheel
from meshgen.cache import cached
from meshgen.geometry import GearGeometry
from wormsim.exceptions import SimulationError

CODE_VERSION = "fe-root-4"
FILLET_COEF = 0.38  # rho_fP / m: ISO 53 profile A root radius of the basic rack
FILLET_ROOM = 0.9  # a fillet's tangent points: at most this share of the way to the space middle / flank middle
RIM_DEPTH_MX = 2.5  # rim below the throat root circle, in axial modules (model extent, clamped there)
ROOT_BAND_MX = 0.35  # root band: element centroids within this many m_x above the root torus radius
FLANK_DENSE = 48  # flank points per section before resampling
SURFACE_DENSITY = 2  # sampling of the outline sections that gmsh re-meshes (the geometry; the element size is apart)
CURVATURE_ELEMENTS = 4  # elements per full turn of a curved surface at density 1 (the default; density 2: 8)
LOAD_RADIUS_MX = 0.25  # radius of the patch over which a contact sample's force is spread (surface vertices)
LOAD_EXCLUSION_MX = 0.25  # elements within this many m_x of a contact sample are not root elements at that position
EDGE_EXCLUSION_MX = 0.5  # nor elements within this many m_x of the wheel's end faces (module docstring)
AVERAGING_RADIUS_MX = 0.25  # root stress: the stress tensor's volume average in a ball of this radius
_VERBOSE = False  # gmsh's messages on the terminal (debugging)


# ----------------------------------------------------------------------------- geometry


def _resample(poly: np.ndarray, n: int) -> np.ndarray:
    """n points evenly by arc length along a polyline (first and last kept)."""
    seg = np.linalg.norm(np.diff(poly, axis=0), axis=1)
    s = np.concatenate([[0.0], np.cumsum(seg)])
    t = np.linspace(0.0, s[-1], n)
    return np.stack([np.interp(t, s, poly[:, k]) for k in range(poly.shape[1])], axis=-1)


def arc(r: float, a0: float, a1: float, n: int) -> np.ndarray:
    t = np.linspace(a0, a1, n)
    return np.stack([r * np.cos(t), r * np.sin(t)], axis=-1)


def _fillet(
    corner: np.ndarray, toward_root: np.ndarray, toward_flank: np.ndarray, radius: float, n: int, t_max: float = np.inf
):
    """n points of the circular arc of `radius` tangent to the two rays from `corner` (unit directions), from the
    root-side tangent point to the flank-side one; and the distance of the tangent points from the corner. Where
    that distance would pass t_max (a tooth space narrower at its root than two fillets), the radius is the one whose
    tangent points lie t_max from the corner."""
    u1, u2 = toward_root / np.linalg.norm(toward_root), toward_flank / np.linalg.norm(toward_flank)
    theta = math.acos(float(np.clip(u1 @ u2, -1.0, 1.0)))
    t = radius / math.tan(theta / 2)
    if t > t_max:
        t, radius = t_max, t_max * math.tan(theta / 2)
    bis = (u1 + u2) / np.linalg.norm(u1 + u2)
    centre = corner + bis * radius / math.sin(theta / 2)
    p1, p2 = corner + t * u1, corner + t * u2
    a1 = math.atan2(*(p1 - centre)[::-1])
    a2 = math.atan2(*(p2 - centre)[::-1])
    da = (a2 - a1 + math.pi) % (2 * math.pi) - math.pi
    ang = a1 + np.linspace(0.0, da, n)
    return centre + radius * np.stack([np.cos(ang), np.sin(ang)], axis=-1), t


@dataclass(frozen=True)
class Counts:
    zeta: int
    root: int
    fillet: int
    flank: int
    tip: int
    radial: int
    inner: int

    @staticmethod
    def at(density: int) -> Counts:
        d = density
        return Counts(zeta=6 * d + 1, root=2 * d + 1, fillet=3 * d + 1, flank=6 * d + 1, tip=2 * d + 1, radial=3 * d,
                      inner=4 * d + 1)  # fmt: skip


def space_middles(g: GearGeometry, zeta):
    """Polar angles of the middles of space 0 and space 1 at the root, at axial position(s) zeta (the teeth are
    helical: these turn across the face)."""
    pitch = 2 * math.pi / g.z2
    zeta = np.asarray(zeta, float)
    lo = wheel.root_rho(g, zeta)
    pa, pb = wheel.tooth_flanks(g, lo, zeta)
    return 0.5 * (pa + pb - pitch), 0.5 * (pa + pb + pitch)


def _tooth_top(g: GearGeometry, zeta: float, c: Counts) -> np.ndarray:
    """Tooth 0's part of the section outline at axial position zeta, counter-clockwise: the root from the middle of
    space 0, the fillets, the flanks and the tip, to the middle of space 1 (module docstring)."""
    lo = float(wheel.root_rho(g, zeta))
    hi = float(wheel.tip_rho(g, zeta))
    rho = np.linspace(lo, hi, FLANK_DENSE)
    pa, pb = wheel.tooth_flanks(g, rho, np.full_like(rho, zeta))
    A = np.stack([rho * np.cos(pa), rho * np.sin(pa)], -1)  # flank a, root -> tip
    B = np.stack([rho * np.cos(pb), rho * np.sin(pb)], -1)  # flank b, root -> tip
    r_f = FILLET_COEF * g.m_x
    s0, s1 = space_middles(g, zeta)
    # flanks' arc lengths from the root
    sa = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(A, axis=0), axis=1))])
    sb = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(B, axis=0), axis=1))])
    # a fillet ends before the space middle and below the flank's middle (FILLET_ROOM of each): where a space is
    # narrower at its root than two fillets (near the end faces of a throated wheel), the radius is smaller there and
    # the outline stays simple (overlapping fillets are facets that gmsh refuses)
    tan_a = np.array([math.sin(pa[0]), -math.cos(pa[0])])  # root circle tangent at A's root, towards space 0
    room_a = FILLET_ROOM * min(lo * (pa[0] - float(s0)), 0.5 * sa[-1])
    fa, ta = _fillet(A[0], tan_a, A[1] - A[0], r_f, c.fillet, room_a)
    tan_b = np.array([-math.sin(pb[0]), math.cos(pb[0])])  # towards space 1
    room_b = FILLET_ROOM * min(lo * (float(s1) - pb[0]), 0.5 * sb[-1])
    fb, tb = _fillet(B[0], tan_b, B[1] - B[0], r_f, c.fillet, room_b)
    # flanks from their fillet tangent point to the tip
    flank_a = _resample(np.concatenate([fa[-1:], A[sa > ta]]), c.flank)
    flank_b = _resample(np.concatenate([fb[-1:], B[sb > tb]]), c.flank)
    root_a = arc(lo, s0, math.atan2(fa[0, 1], fa[0, 0]), c.root)
    root_b = arc(lo, math.atan2(fb[0, 1], fb[0, 0]), s1, c.root)
    tip = arc(hi, pa[-1], pb[-1], c.tip)
    return np.concatenate([root_a, fa[1:], flank_a[1:], tip[1:-1], flank_b[::-1], fb[::-1][1:], root_b[1:]])


def section_outline(g: GearGeometry, zeta: float, c: Counts, teeth: int = 1) -> np.ndarray:
    """Closed outline (N, 2) of `teeth` wheel teeth with their rim in the wheel section at axial position zeta,
    counter-clockwise, N the same for every zeta (module docstring): tooth 0 (teeth = 1), or tooth 0 with
    (teeth - 1) / 2 neighbours on each side (teeth odd), each tooth k tooth 0's outline turned by k 2 pi / z2."""
    pitch = 2 * math.pi / g.z2
    half = (teeth - 1) // 2
    top = _tooth_top(g, zeta, c)
    parts = []
    for k in range(-half, half + 1):
        ck, sk = math.cos(k * pitch), math.sin(k * pitch)
        turned = top @ np.array([[ck, sk], [-sk, ck]])
        parts.append(turned if k == -half else turned[1:])
    lo = float(wheel.root_rho(g, zeta))
    s0, s1 = space_middles(g, zeta)
    s0, s1 = float(s0) - half * pitch, float(s1) + half * pitch
    r_in = g.r_f2 - RIM_DEPTH_MX * g.m_x
    down = np.linspace(lo, r_in, c.radial + 1)[1:-1]
    side_b = np.stack([down * math.cos(s1), down * math.sin(s1)], -1)
    inner = arc(r_in, s1, s0, c.inner + (c.inner - 1) * (teeth - 1))
    side_a = np.stack([down[::-1] * math.cos(s0), down[::-1] * math.sin(s0)], -1)
    return np.concatenate(parts + [side_b, inner, side_a])


def tooth_surface(g: GearGeometry, density: int = 1, teeth: int = 1) -> tuple[np.ndarray, np.ndarray]:
    """Watertight triangulated surface (vertices (n, 3) in m, faces (m, 3), outward) of the sector of `teeth` teeth
    (section_outline)."""

    c = Counts.at(density)
    zetas = np.linspace(-g.face_width / 2, g.face_width / 2, c.zeta)
    secs = np.stack([section_outline(g, z, c, teeth) for z in zetas])  # (nz, N, 2)
    return loft(secs, zetas)


def loft(secs: np.ndarray, zetas: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The closed surface through the plane sections secs (nz, N, 2) at the heights zetas (nz,): quads between
    neighbouring sections, each end capped by manifold3d's triangulation; (V (nz N, 3), F (m, 3)), oriented outward
    (positive signed volume)."""
    import manifold3d as mf

    nz, N = secs.shape[:2]
    V = np.concatenate([secs.reshape(-1, 2), np.repeat(zetas, N)[:, None]], axis=1)
    idx = np.arange(nz * N).reshape(nz, N)
    I = np.concatenate([idx, idx[:, :1]], axis=1)
    a, b, cc, d = I[:-1, :-1], I[1:, :-1], I[1:, 1:], I[:-1, 1:]
    faces = [np.stack([a, cc, b], -1).reshape(-1, 3), np.stack([a, d, cc], -1).reshape(-1, 3)]
    for row, up in ((0, False), (nz - 1, True)):
        tri = np.asarray(mf.triangulate([secs[row]]), dtype=np.int64)
        t = idx[row][tri]
        faces.append(t if up else t[:, ::-1])
    F = np.concatenate(faces)
    vol = np.einsum("ij,ij->i", V[F[:, 0]], np.cross(V[F[:, 1]], V[F[:, 2]])).sum() / 6.0
    if vol < 0:
        F = F[:, ::-1]
    return V, F


MESH_TIMEOUT_S = 60.0  # one gmsh attempt's time limit (measured 3-15 s per attempt at load 10; some surfaces hang)


def tet_mesh(
    V: np.ndarray,
    F: np.ndarray,
    size_m: float,
    min_size_m: float,
    curvature: int,
    angle_deg: float | None = 40.0,
    timeout_s: float = MESH_TIMEOUT_S,
) -> tuple[np.ndarray, np.ndarray]:
    """Tetrahedra (gmsh) inside the closed surface (V, F): (points (n, 3), tets (m, 4)). The surface is classified
    into patches at sharp edges (angle_deg), re-parametrised and re-meshed at `size_m` (refined on curvature,
    `curvature` elements per 2 pi of a curve's turn, down to min_size_m: the root fillet), then the volume is meshed;
    angle_deg None: no re-meshing, the triangles (V, F) are the boundary and only the volume is meshed (nothing to
    refuse for a closed surface, at the surface's own resolution). gmsh runs in a child process
    (wormsim.rating.gmsh_job): an attempt not done within timeout_s is refused (RuntimeError) like a gmsh error."""
    import subprocess
    import sys
    import tempfile
    from pathlib import Path

    job = Path(__file__).with_name("gmsh_job.py")
    with tempfile.TemporaryDirectory(prefix="wormsim-gmsh-") as d:
        inp, out = Path(d) / "in.npz", Path(d) / "out.npz"
        np.savez(
            inp, V=V, F=F, size_m=size_m, min_size_m=min_size_m, curvature=curvature,
            angle_deg=math.nan if angle_deg is None else angle_deg, verbose=_VERBOSE,
        )  # fmt: skip
        try:
            r = subprocess.run(
                [sys.executable, str(job), str(inp), str(out)], capture_output=True, text=True, timeout=timeout_s
            )
        except subprocess.TimeoutExpired:
            raise RuntimeError(f"gmsh did not finish within {timeout_s:g} s") from None
        if r.returncode != 0:
            raise RuntimeError((r.stderr.strip().splitlines() or [f"gmsh exited {r.returncode}"])[-1])
        res = np.load(out)
        tags, P, conn = res["tags"], res["xyz"], res["tets"]
    order = np.empty(int(tags.max()) + 1, dtype=np.int64)
    order[tags] = np.arange(len(tags))
    T = order[conn]
    used = np.unique(T)
    remap = -np.ones(len(P), dtype=np.int64)
    remap[used] = np.arange(len(used))
    return P[used], remap[T]


# element-size factors tried in turn when gmsh refuses a surface re-mesh ("Invalid boundary mesh (overlapping
# facets)": two re-meshed patches meet in the same triangle at some sizes; measured on a 1-start ZI gear, z2 40, m_x 4,
# q 10: refused at 1.0, meshed at 0.9). The largest and the smallest size scale together.
SIZE_RETRIES = (1.0, 0.9, 1.1, 0.8, 1.25, 0.7)
# gmsh's feature angles tried after every size at the caller's angles failed ("Wrong topology of boundary mesh for
# parametrization" at 40 deg and every size on a 1-start ZI gear, z2 24, m_x 0.93, q 12.8, x2 -0.13: meshed at 60 deg);
# a tooth that meshes at the caller's angles keeps its mesh
FALLBACK_ANGLES_DEG = (60.0, 50.0, 30.0)


def tet_mesh_retried(
    V: np.ndarray,
    F: np.ndarray,
    size_m: float,
    min_size_m: float,
    curvature: int,
    angles_deg: tuple[float | None, ...] = (40.0,),
    fallback_angles_deg: tuple[float, ...] = (),
) -> tuple[np.ndarray, np.ndarray]:
    """tet_mesh at the element sizes times each of SIZE_RETRIES, each at the feature angles angles_deg in turn (None:
    the surface's own triangles, tet_mesh), until gmsh meshes the tooth; then the same at fallback_angles_deg;
    SimulationError (exit 3) naming what to change when every size and angle is refused."""
    errors = []
    for angles in (angles_deg, tuple(a for a in fallback_angles_deg if a not in angles_deg)):
        for f in SIZE_RETRIES if angles else ():
            for angle in angles:
                try:
                    return tet_mesh(V, F, size_m * f, min_size_m * f, curvature, angle)
                except Exception as exc:  # gmsh raises plain Exception with its message
                    errors.append(f"x{f:g} at {'no re-meshing' if angle is None else f'{angle:g} deg'}: {exc}")
    raise SimulationError(
        f"the FE root stress: gmsh refused the wheel tooth's mesh at every element size tried ({'; '.join(errors)}); "
        "change rating.fe_mesh_density (1 to 4) or gear.backlash_mm slightly, or rate without --fe "
        "(rating.root_stress: none)"
    )


# ----------------------------------------------------------------------------- solver


@dataclass(frozen=True)
class Solution:
    stress: np.ndarray  # (n_load, m, 3, 3) element-centroid stress, Pa
    centroids: np.ndarray  # (m, 3)
    displacement: np.ndarray  # (n_load, n_nodes, 3) at the mesh vertices
    qp_stress: np.ndarray  # (n_load, m * q, 3, 3) stress at the quadrature points, Pa
    qp_points: np.ndarray  # (m * q, 3) their positions
    qp_weights: np.ndarray  # (m * q,) their volume weights


def solve_elastic(
    points: np.ndarray,
    tets: np.ndarray,
    e_pa: float,
    nu: float,
    fixed_facet,
    loads: list[tuple[np.ndarray, np.ndarray]],
) -> Solution:
    """Linear elasticity on quadratic tetrahedra (scikit-fem). fixed_facet(x) -> bool mask of boundary-facet
    midpoints (3, k) that are clamped; loads: per load case (vertex indices (k,), forces (k, 3) N) at mesh vertices."""
    from skfem.models.elasticity import lame_parameters

    ib, free, solve = elastic_solver(points, tets, e_pa, nu, fixed_facet)
    mesh = ib.mesh
    lam, mu = lame_parameters(e_pa, nu)
    us, stresses, qp_stress = [], [], []
    for verts, forces in loads:
        f = np.zeros(ib.N)
        for d in range(3):
            np.add.at(f, ib.nodal_dofs[d, verts], forces[:, d])
        u = np.zeros(ib.N)
        u[free] = solve(f[free])
        ui = ib.interpolate(u)
        grad = np.asarray(ui.grad)  # (3, 3, m, q)
        eps = 0.5 * (grad + grad.transpose(1, 0, 2, 3))
        tr = np.trace(eps)
        sig = 2 * mu * eps + lam * tr[None, None] * np.eye(3)[:, :, None, None]
        qp_stress.append(np.moveaxis(sig.reshape(3, 3, -1), -1, 0))
        stresses.append(np.moveaxis(sig.mean(axis=-1), -1, 0))  # the element mean: the centroid value of a P2 strain
        us.append(u[ib.nodal_dofs].T)
    cent = mesh.p[:, mesh.t].mean(axis=1).T
    qp_x = np.asarray(ib.mapping.F(ib.X)).reshape(3, -1).T
    return Solution(
        stress=np.array(stresses), centroids=cent, displacement=np.array(us), qp_stress=np.array(qp_stress),
        qp_points=qp_x, qp_weights=np.asarray(ib.dx).ravel(),
    )  # fmt: skip


def elastic_solver(
    points: np.ndarray, tets: np.ndarray, e_pa: float, nu: float, fixed_facet, direct_dofs_max: int | None = None
):
    """(basis, free dofs, solve) of linear elasticity on quadratic tetrahedra (scikit-fem): the stiffness matrix with
    the dofs on the facets where fixed_facet(midpoints (3, k)) is true clamped, factorised once (_solver);
    solve(f_free) -> u_free."""
    from skfem import Basis, ElementTetP2, ElementVector, MeshTet, asm
    from skfem.models.elasticity import lame_parameters, linear_elasticity

    mesh = MeshTet(points.T.copy(), tets.T.copy()).oriented()
    ib = Basis(mesh, ElementVector(ElementTetP2()), intorder=2)
    lam, mu = lame_parameters(e_pa, nu)
    K = asm(linear_elasticity(lam, mu), ib).tocsc()
    fixed = ib.get_dofs(lambda x: fixed_facet(x)).all()
    free = np.setdiff1d(np.arange(ib.N), fixed)
    Kff = K[free][:, free].tocsr()
    return ib, free, _solver(Kff, ib.doflocs, free, DIRECT_DOFS_MAX if direct_dofs_max is None else direct_dofs_max)


DIRECT_DOFS_MAX = 30000  # above this, algebraic multigrid (pyamg) with conjugate gradients instead of SuperLU
CG_RTOL = 1e-8  # relative residual; the stresses change by < 1e-5 relative below it (measured on involute_41)


def _solver(Kff, doflocs: np.ndarray, free: np.ndarray, direct_dofs_max: int = DIRECT_DOFS_MAX):
    """x = solve(b) for the clamped stiffness matrix: SuperLU for small systems, else pyamg's smoothed aggregation
    with the rigid-body modes as near-null space, as the preconditioner of conjugate gradients."""
    import scipy.sparse.linalg as spla

    if Kff.shape[0] <= direct_dofs_max:
        lu = spla.splu(Kff.tocsc(), permc_spec="MMD_AT_PLUS_A")  # symmetric ordering: 0.6 x COLAMD's fill here
        return lu.solve
    import pyamg

    # rigid-body modes at the free dofs (dof k of the vector basis is component k % 3 in skfem's interleaving)
    n = doflocs.shape[1]
    x = doflocs[:, free]
    comp = free % 3
    B = np.zeros((len(free), 6))
    for d in range(3):
        B[comp == d, d] = 1.0
    # rotations: e_d x r
    B[comp == 0, 3], B[comp == 1, 3] = -x[1, comp == 0], x[0, comp == 1]
    B[comp == 1, 4], B[comp == 2, 4] = -x[2, comp == 1], x[1, comp == 2]
    B[comp == 2, 5], B[comp == 0, 5] = -x[0, comp == 2], x[2, comp == 0]
    del n
    # the coarsest level by SuperLU: pinv's dense SVD of it costs more than all the cycles (a ~2400-dof coarse level)
    ml = pyamg.smoothed_aggregation_solver(Kff, B=B, max_coarse=500, coarse_solver="splu")

    def solve(b):
        return ml.solve(b, tol=CG_RTOL, accel="cg", maxiter=500)

    return solve


def max_principal(stress: np.ndarray) -> np.ndarray:
    """First principal stress of (..., 3, 3) symmetric tensors."""
    return np.linalg.eigvalsh(stress)[..., -1]


# ----------------------------------------------------------------------------- contact load (torsional LTCA lines)


def contact_loads(g: GearGeometry, side: int, t2_nm: float, positions: int) -> list[tuple[np.ndarray, np.ndarray]]:
    """Per position over tooth 0's engagement: (points (k, 3) m on tooth 0's working flank, forces (k, 3) N on the
    wheel), from the contact lines and load law of the torsional TCA (module docstring)."""
    import contourpy

    from wormsim.tooth import mesh_stiffness as ms

    fld = ms._flank_field(g, side)
    gen = contourpy.contour_generator(z=fld.c, name="serial", corner_mask=True)
    pitch = 2 * math.pi / g.z2
    dj = g.backlash / (2 * g.r2)
    rot = dj if side > 0 else pitch - dj  # the field's flank -> tooth 0's working flank (meshgen.wheel.tooth_flanks)
    cr, sr = math.cos(rot), math.sin(rot)
    Rz = np.array([[cr, -sr, 0.0], [sr, cr, 0.0], [0.0, 0.0, 1.0]])
    zeta = np.linspace(-g.face_width / 2, g.face_width / 2, fld.xyz.shape[0])
    s = np.linspace(0.0, 1.0, fld.xyz.shape[1])
    dz = np.gradient(fld.xyz, zeta, axis=0)
    dsv = np.gradient(fld.xyz, s, axis=1)
    normal = np.cross(dz, dsv)
    normal /= np.linalg.norm(normal, axis=-1, keepdims=True)
    cmin, cmax = float(fld.c.min()), float(fld.c.max())
    psi_c = wheel.tooth_angle(g, 0)
    levels = cmin + (cmax - cmin) * (np.arange(positions) + 0.5) / positions
    out = []
    for theta2 in levels:
        total = 0.0
        mine: list[tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]] = []
        for k in range(math.ceil((cmin - theta2) / pitch), math.floor((cmax - theta2) / pitch) + 1):
            for ln in gen.lines(theta2 + k * pitch):
                if len(ln) < 2:
                    continue
                ln = np.asarray(ln)
                j, i = ln[:, 0], ln[:, 1]
                P = ms._bilinear(fld.xyz, i, j)
                A = ms._bilinear(fld.arm, i, j)
                n = ms._bilinear(normal, i, j)
                ds = np.linalg.norm(np.diff(P, axis=0), axis=1)
                total += float(np.sum(0.5 * (A[1:] ** 2 + A[:-1] ** 2) * ds))
                if k == 0:
                    Pm, Am, nm = 0.5 * (P[1:] + P[:-1]), 0.5 * (A[1:] + A[:-1]), 0.5 * (n[1:] + n[:-1])
                    mine.append((Pm, Am, nm, ds))
        pts, frc = [np.zeros((0, 3))], [np.zeros((0, 3))]
        for Pm, Am, nm, ds in mine:
            q = t2_nm * Am / total  # N per m of line
            Pw = Pm @ Rz.T
            nw = nm @ Rz.T
            nw /= np.linalg.norm(nw, axis=1, keepdims=True)
            psi = np.arctan2(Pw[:, 1], Pw[:, 0])
            e_psi = np.stack([-np.sin(psi), np.cos(psi), np.zeros_like(psi)], -1)
            into = np.sign(psi_c - psi)  # into tooth 0's material
            nw *= np.where(np.einsum("ij,ij->i", nw, e_psi) * into < 0, -1.0, 1.0)[:, None]
            pts.append(Pw)
            frc.append(nw * (q * ds)[:, None])
        out.append((np.concatenate(pts), np.concatenate(frc)))
    return out


# ----------------------------------------------------------------------------- the root stress


@dataclass(frozen=True)
class ToothMesh:
    points: np.ndarray
    tets: np.ndarray
    r_in: float


def tooth_mesh(
    g: GearGeometry,
    density: int = 1,
    size_m: float | None = None,
    use_cache: bool = True,
    teeth: int = 1,
    min_size_m: float | None = None,
    curvature_elements: int = CURVATURE_ELEMENTS,
    classify_angles_deg: tuple[float | None, ...] = (40.0,),
) -> ToothMesh:
    """The tetrahedral mesh of the sector of `teeth` teeth (section_outline; 1: the one-tooth sector), cached by
    geometry (meshgen.cache). `density` d sets the element sizes together (d = 1 is the default, d = 1 and 2 are an
    h / (h/2) pair): largest 1.5 m_x / d (or size_m), smallest FILLET_COEF m_x / d (the fillet radius over d; or
    min_size_m / d), curvature_elements d per full turn of a curved surface (default CURVATURE_ELEMENTS). gmsh's
    surface classification at each of classify_angles_deg in turn, then at FALLBACK_ANGLES_DEG (tet_mesh_retried; its
    re-meshing of the classified patches fails on some sectors at some angles)."""
    from dataclasses import asdict

    size = size_m if size_m is not None else 1.5 * g.m_x / density
    min_size = min((FILLET_COEF * g.m_x if min_size_m is None else min_size_m) / density, size)
    curvature = curvature_elements * density

    def build() -> ToothMesh:
        V, F = tooth_surface(g, SURFACE_DENSITY, teeth)
        P, T = tet_mesh_retried(V, F, size, min_size, curvature, classify_angles_deg, FALLBACK_ANGLES_DEG)
        return ToothMesh(P, T, g.r_f2 - RIM_DEPTH_MX * g.m_x)

    parts = {"geometry": asdict(g), "density": density, "size_m": size, "code": CODE_VERSION}
    if (teeth, min_size_m, curvature_elements, classify_angles_deg) != (1, None, CURVATURE_ELEMENTS, (40.0,)):
        parts.update(teeth=teeth, min_size_m=min_size_m, curvature_elements=curvature_elements)
        parts.update(angles=classify_angles_deg)
    return cached("fe-tooth", parts, build, use_cache=use_cache)


def clamped_faces(g: GearGeometry, r_in: float, teeth: int = 1):
    """fixed_facet(x) of the sector of `teeth` teeth: the rim's cut faces, i.e. the inner face (radius r_in) and the
    two radial faces below the root at the middles of the outermost spaces."""
    tol = 1e-3 * g.m_x
    half = (teeth - 1) // 2
    pitch = 2 * math.pi / g.z2

    def fixed(x):
        rho = np.hypot(x[0], x[1])
        psi = np.arctan2(x[1], x[0])
        s0, s1 = space_middles(g, x[2])
        s0, s1 = s0 - half * pitch, s1 + half * pitch
        below = rho < wheel.root_rho(g, x[2]) - tol
        on_side = below & ((np.abs(psi - s0) * rho < tol) | (np.abs(psi - s1) * rho < tol))
        return (rho < r_in + tol) | on_side

    return fixed


def root_stress(
    g: GearGeometry,
    e_pa: float,
    nu: float,
    side: int,
    t2_nm: float,
    positions: int,
    density: int = 1,
    size_m: float | None = None,
    use_cache: bool = True,
) -> dict:
    """FE root stress of the wheel tooth over its engagement at wheel torque t2_nm (module docstring): a dict with
    root_stress_max_mpa, root_stress_range_mpa, the position (mm, wheel frame) and the per-position maxima."""
    return root_stress_cases(g, e_pa, nu, side, [t2_nm], positions, density, size_m, use_cache)[0]


def root_stress_cases(
    g: GearGeometry,
    e_pa: float,
    nu: float,
    side: int,
    torques_nm: list[float],
    positions: int,
    density: int = 1,
    size_m: float | None = None,
    use_cache: bool = True,
) -> list[dict]:
    """root_stress at several torques with one mesh and one stiffness matrix."""
    from scipy.spatial import cKDTree

    tm = tooth_mesh(g, density, size_m, use_cache)
    P, T = tm.points, tm.tets
    fixed = clamped_faces(g, tm.r_in)

    # each contact sample's force spread over the surface vertices within LOAD_RADIUS_MX (a load patch of fixed size)
    surf = np.unique(_boundary_faces(T))
    tree = cKDTree(P[surf])
    loads, samples = [], []
    for t2 in torques_nm:
        for pts, frc in contact_loads(g, side, t2, positions):
            samples.append(pts)
            if len(pts) == 0:
                loads.append((np.zeros(0, dtype=np.int64), np.zeros((0, 3))))
                continue
            loads.append(_spread(tree, surf, pts, frc, LOAD_RADIUS_MX * g.m_x))
    sol = solve_elastic(P, T, e_pa, nu, fixed, loads)
    c = sol.centroids
    rho_c = np.hypot(c[:, 0], c[:, 1])
    root_c = wheel.root_rho(g, c[:, 2])
    band = (rho_c <= root_c + ROOT_BAND_MX * g.m_x) & (rho_c >= root_c - ROOT_BAND_MX * g.m_x)
    band &= np.abs(c[:, 2]) <= g.face_width / 2 - EDGE_EXCLUSION_MX * g.m_x
    # the point loads' own local stress is not root stress: elements near a contact sample are left out there
    near = np.zeros((len(samples), int(band.sum())), dtype=bool)
    for i, pts in enumerate(samples):
        if len(pts):
            dist, _ = cKDTree(pts).query(c[band])
            near[i] = dist < LOAD_EXCLUSION_MX * g.m_x
    out = []
    for k in range(len(torques_nm)):
        cases = slice(k * positions, (k + 1) * positions)
        radius = AVERAGING_RADIUS_MX * g.m_x
        stress = _ball_average(sol.qp_stress[cases], sol.qp_points, sol.qp_weights, c[band], radius)
        s1v = np.where(near[cases], -np.inf, max_principal(stress))
        per_pos = s1v.max(axis=1)
        ipos, iel = np.unravel_index(int(np.argmax(s1v)), s1v.shape)
        # the history at the critical element along the peak's principal direction; out of mesh it is 0
        w, v = np.linalg.eigh(stress[ipos, iel])
        n = v[:, -1]
        hist = np.einsum("i,pij,j->p", n, stress[:, iel], n)
        out.append(
            {
                "root_stress_max_mpa": float(s1v.max() / 1e6),
                "root_stress_range_mpa": float((hist.max() - min(hist.min(), 0.0)) / 1e6),
                "position_mm": [float(x * 1e3) for x in c[band][iel]],
                "position_index": int(ipos),
                "per_position_mpa": [float(x / 1e6) for x in per_pos],
                "critical_history_mpa": [float(x / 1e6) for x in hist],
                "elements": int(len(T)),
                "nodes": int(len(P)),
                "positions": int(positions),
                "density": int(density),
                "fillet_radius_mm": FILLET_COEF * g.m_x * 1e3,
            }
        )
    return out


def _ball_average(stress: np.ndarray, cent: np.ndarray, vol: np.ndarray, centres: np.ndarray, radius: float):
    """(cases, k, 3, 3): the volume average of the stress (cases, n, 3, 3) at n quadrature points (positions `cent`,
    volume weights `vol`) over those within `radius` of each of the k centres."""
    import scipy.sparse as sp
    from scipy.spatial import cKDTree

    groups = cKDTree(cent).query_ball_point(centres, radius)
    rows = np.repeat(np.arange(len(centres)), [len(x) for x in groups])
    cols = np.concatenate([np.asarray(x, dtype=np.int64) for x in groups])
    W = sp.csr_matrix((vol[cols], (rows, cols)), shape=(len(centres), len(cent)))
    W = sp.diags(1.0 / np.asarray(W.sum(axis=1)).ravel()) @ W
    flat = stress.reshape(stress.shape[0], stress.shape[1], 9)
    out = np.stack([W @ flat[i] for i in range(len(flat))])
    return out.reshape(stress.shape[0], len(centres), 3, 3)


def _spread(tree, surf: np.ndarray, pts: np.ndarray, frc: np.ndarray, radius: float):
    """(vertices, forces): each force shared by the surface vertices within `radius` of its point, weights 1 - d/R
    (the nearest 3 where none is that close), so the load patch keeps its size when the mesh is refined."""
    verts, forces = [], []
    for p, f, near in zip(pts, frc, tree.query_ball_point(pts, radius)):
        if len(near) < 3:
            _, near = tree.query(p, k=3)
            w = np.ones(3)
        else:
            d = np.linalg.norm(tree.data[near] - p, axis=1)
            w = 1.0 - d / radius
        near = np.asarray(near)
        verts.append(surf[near])
        forces.append(np.outer(w / w.sum(), f))
    return np.concatenate(verts), np.concatenate(forces)


def _boundary_faces(T: np.ndarray) -> np.ndarray:
    """Triangles that belong to one tetrahedron only."""
    f = np.concatenate([T[:, [0, 1, 2]], T[:, [0, 1, 3]], T[:, [0, 2, 3]], T[:, [1, 2, 3]]])
    fs = np.sort(f, axis=1)
    _, inv, cnt = np.unique(fs, axis=0, return_inverse=True, return_counts=True)
    return f[cnt[inv.ravel()] == 1]


# ----------------------------------------------------------------------------- the rating's use

TRESCA_FACTOR = 2.0  # max principal / max shear stress of a uniaxial stress state (Mohr's circle; Tresca criterion)


def root_stress_limit_mpa(given_mpa: float | None, material: str | None) -> tuple[float | None, str]:
    """The permissible max principal root stress of safety_root_sim and its origin: rating.root_stress_limit_mpa
    when given; else TRESCA_FACTOR x tau_FlimT of the wheel material's row (wormsim.rating.materials, the DIN 3996
    values as MITCalc lists them): the root fillet's surface is in a nearly uniaxial stress state, whose largest
    shear stress is half its max principal stress (Tresca), so the shear strength tau_FlimT is met at a max
    principal stress of 2 tau_FlimT. tau_FlimT is calibrated on method B's nominal tau_F, not on a local FE stress:
    the derived limit is an equivalence assumption, stated as such. None where the row has no tau_FlimT (POM)."""
    from wormsim.rating.materials import WHEEL_MATERIALS

    if given_mpa is not None:
        return given_mpa, "rating.root_stress_limit_mpa"
    row = WHEEL_MATERIALS.get(material) if material is not None else None
    if row is None or row.tau_flim_t_mpa is None:
        return None, f"the material table has no sourced root strength (tau_FlimT) for {material}"
    return TRESCA_FACTOR * row.tau_flim_t_mpa, (
        f"limit {TRESCA_FACTOR:g} x tau_FlimT = {TRESCA_FACTOR * row.tau_flim_t_mpa:g} MPa of {row.name} (tau_FlimT of "
        "the material table; Tresca: max principal = 2 x max shear in a uniaxial stress; an equivalence assumption, "
        "docs/rating.md)"
    )


def add_fe_root_stress(scenario, result: dict) -> dict:
    """root_stress_max_mpa, root_stress_range_mpa, safety_root_sim (and `fe_root`, the details) into a rating result
    of wormsim.rating.rate: the wheel of materials.wheel (E, nu) at the rated torque K_A T2 on the working flank."""
    import time

    from wormsim.physics import gear_theory
    from wormsim.physics.geometry import derive
    from wormsim.rating.rate import rating_inputs

    r = rating_inputs(scenario)
    g = derive(scenario.gear)
    side = gear_theory.duty(scenario, g.hand).working_flank
    t2 = result["inputs"]["wheel_torque_rated_nm"]
    t0 = time.perf_counter()
    fe = root_stress(
        g, scenario.materials.wheel.youngs_modulus_gpa * 1e9, scenario.materials.wheel.poisson_ratio, side, t2,
        r.fe_positions, density=r.fe_mesh_density,
    )  # fmt: skip
    fe["wall_time_s"] = time.perf_counter() - t0
    result["fe_root"] = fe
    result["root_stress_max_mpa"] = fe["root_stress_max_mpa"]
    result["root_stress_range_mpa"] = fe["root_stress_range_mpa"]
    limit, why = root_stress_limit_mpa(r.root_stress_limit_mpa, result["inputs"].get("wheel_material"))
    fe["root_stress_limit_mpa"] = limit
    fe["root_stress_limit_source"] = why
    if limit is not None:
        result["safety_root_sim"] = limit / fe["root_stress_max_mpa"]
        if r.root_stress_limit_mpa is None:
            result["warnings"].append(f"safety_root_sim: {why}; give rating.root_stress_limit_mpa to use another limit")
        if fe["root_stress_max_mpa"] > limit:
            result["warnings"].append(
                f"root stress {fe['root_stress_max_mpa']:.4g} MPa above its limit {limit:.4g} MPa (safety_root_sim "
                f"{limit / fe['root_stress_max_mpa']:.3g} < 1): the wheel teeth break at this load; lower the load or "
                "choose a larger module, a wider face or a stronger wheel material"
            )
    else:
        result["safety_root_sim"] = None
        result["warnings"].append(f"safety_root_sim not given: {why}; give rating.root_stress_limit_mpa")
    src = "FE root stress: gmsh + scikit-fem on meshgen's wheel tooth, loaded by the torsional TCA's contact lines"
    if src not in result["sources"]:
        result["sources"].append(src)
    return result
