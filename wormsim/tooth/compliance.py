"""Tooth compliance of a worm gear pair: influence coefficients of the wheel tooth from a linear FE model, the worm
thread's compliance from a plane-strain FE model of its normal section, and the local contact flattening.

Split of the deflection (Weber & Banaschek, 1953; the split that FE-based loaded tooth contact analyses use, e.g.
Sainsot, Velex & Duverger, J. Mech. Des. 126 (2004) 748): the normal approach of two flank points in contact is

    w = w_wheel(centre line) + w_worm(centre line) + w_flat,wheel + w_flat,worm                              (1)

* w_wheel: the displacement, along the flank normal, of the wheel tooth's CENTRE LINE point under the flank point (the
  point halfway between the two flanks at the same radius rho and face position zeta; distance h_wheel from the
  flank), from the FE model. Under a distributed load it is the sum over the contact line of influence coefficients
  C(x_i, x_j) F_j: tooth bending, shear, the tooth's foundation in the rim and the rim itself, load on one tooth
  bending its neighbours. The FE's own local deformation under the load patch (between the flank and the centre line,
  where a point load's displacement is singular and the patch size and the element size decide its value) is not in
  it: the centre line lies at depth h_wheel ~ 0.3 .. 1 m_x, outside the patch's near field.
* w_flat: the approach of the flank point towards its body's centre line, for each body, from Weber and Banaschek's
  line-contact formula (a Hertz pressure distribution on an elastic half-plane, the displacement difference between
  the surface and the point at depth h below it; Weber & Banaschek, "Formänderung und Profilrücknahme bei gerad- und
  schrägverzahnten Rädern", Schriftenreihe Antriebstechnik 11, Vieweg 1953; also in Sainsot et al. 2004):

      w_flat = 2 q (1 - nu^2) / (pi E) [ ln(2 h / b) - nu / (2 (1 - nu)) ],   b = sqrt(4 q rho' / (pi E*))   (2)

  q the line load (N/m), b the Hertz half-width (Johnson, Contact Mechanics, eq. 4.43), rho' the relative radius of
  curvature across the contact line (wormsim.tooth.hertz), E* = wormsim.physics.gear_theory.effective_modulus_pa. The
  bracket is taken at least 0 (it is > 1 for every load below the tooth's strength). Weber's formula is chosen over
  Lundberg's or the plain Hertz k' = pi E* / 4 because it is the one whose reference point (the centre line at depth
  h) is the point where the FE displacement is read: the two parts meet there and nothing is counted twice.
* w_worm: the worm thread is continuous along its helix, steel, and stands on the full worm core. Its compliance is
  the plane-strain FE solution of the thread's normal section (three threads on the core down to the worm axis, the
  axis clamped): the displacement of the thread's centre line along the flank normal under a line load q on the
  flank at radius r, per q (m^2/N), a local (Winkler) compliance per unit length of contact line. The thread's
  coupling along the helix is left out, which makes it exact for a uniform line load along the thread and an
  approximation where the load varies along the line; its share of the total compliance is measured in
  docs/tooth_compliance.md.

Wheel FE model (wormsim.rating.fe_root's geometry and mesher, each formula there once): the sector of TEETH = 3 wheel
teeth with the rim (RIM_DEPTH_MX below the root, the rim's cut faces clamped), from meshgen's exact wheel,
quadratic tetrahedra (scikit-fem), SuperLU or pyamg, one factorisation and one right-hand side per grid point.
The flank grid: GRID_FACE points across the face width x GRID_PROFILE along the profile on the middle tooth's flank
a, in the (zeta, s) coordinates of wormsim.tooth.mesh_stiffness (s = 0 at the worm tip's reach, 1 at the wheel tip).
At each grid point j a unit normal force is spread over the surface vertices within LOAD_RADIUS_MX axial modules
(wormsim.rating.fe_root._spread); the displacement is read at every grid point's centre line point on the loaded
tooth and on both neighbours. The flank b of a wheel tooth is flank a mirrored in zeta (meshgen.wheel.tooth_flanks),
so one flank's grid serves both flank sides.

Cache: in process and on disk (meshgen.cache), keyed by the geometry, E and nu of both bodies, the mesh density,
the grid and CODE_VERSION.
"""

from __future__ import annotations

import functools
import math
import time
from dataclasses import asdict, dataclass

import numpy as np

from meshgen import wheel, worm
from meshgen.cache import cached
from meshgen.geometry import GearGeometry

CODE_VERSION = "tooth-compliance-2"
GRID_FACE = 9  # flank grid points across the face width
GRID_PROFILE = 5  # flank grid points along the profile
TEETH = 3  # wheel teeth in the FE model: the loaded one and a neighbour on each side
WORM_THREADS = 3  # threads in the worm's plane-strain section
WORM_RADII = 7  # load heights of the worm model, root .. tip
LOAD_RADIUS_MX = 0.25  # load patch radius in axial modules (as wormsim.rating.fe_root.LOAD_RADIUS_MX)
MIN_SIZE_MX = 0.75  # smallest FE element (at density 1), axial modules: the fillet needs no stress resolution here
CURVATURE_ELEMENTS = 2  # FE elements per full turn of a curved surface at density 1
CLASSIFY_ANGLES_DEG = (
    60.0,
    50.0,
    40.0,
    30.0,
    None,
)  # feature angles in turn, last the surface as is (fe_root.tet_mesh)
DIRECT_DOFS_MAX = 120000  # SuperLU below this many dofs: one factorisation, GRID_FACE x GRID_PROFILE solves
INSET_MX = 0.05  # centre line points this far inside the end faces and the tip, in axial modules
H_NORMAL_MX = 0.02  # finite-difference step of the flank normal, in axial modules


@dataclass(frozen=True)
class ToothCompliance:
    """Influence coefficients and local compliance of one gear pair and material pair (module docstring); SI.

    Grid point index i = a GRID_PROFILE + b (zeta_m[a], s[b]). wheel_m_per_n[0][i, j] is the normal deflection (1) of
    the wheel's centre line at grid point i of a tooth under a unit normal force at grid point j of the same tooth,
    [1] at the point i of the next tooth (space k + 1 of wormsim.tooth.mesh_stiffness), [2] of the previous one."""

    zeta_m: np.ndarray  # (nf,)
    s: np.ndarray  # (ns,)
    points_m: np.ndarray  # (nf, ns, 3) the grid on tooth 0's flank a, wheel frame
    wheel_m_per_n: np.ndarray  # (3, n, n)
    wheel_half_thickness_m: np.ndarray  # (nf, ns) h of (2) for the wheel at the grid points
    worm_radius_m: np.ndarray  # (WORM_RADII,) load heights of the worm model
    worm_m2_per_n: np.ndarray  # (WORM_RADII,) the worm thread's per-length compliance
    worm_half_thickness_m: np.ndarray  # (WORM_RADII,) h of (2) for the worm (normal half thickness)
    e_wheel_pa: float
    nu_wheel: float
    e_worm_pa: float
    nu_worm: float
    e_star_pa: float
    density: int
    elements: int
    nodes: int
    wall_time_s: float

    def kernel(self, zeta_t, s_t, zeta_s, s_s, dk, side: int = 1) -> np.ndarray:
        """Influence coefficients (m/N) between target points (zeta_t, s_t) and source points (zeta_s, s_s) on the
        flank of `side`, bilinear in both from the grid; dk (kt, ks) = target's tooth - source's tooth (0, +1, -1;
        others 0)."""
        sgn = 1.0 if side > 0 else -1.0
        Wt = _bilinear_weights(self.zeta_m, self.s, sgn * np.asarray(zeta_t), np.asarray(s_t))
        Ws = _bilinear_weights(self.zeta_m, self.s, sgn * np.asarray(zeta_s), np.asarray(s_s))
        dk = np.asarray(dk)
        out = np.zeros(dk.shape)
        # mirrored flank (side -1): the mirror in zeta turns the wheel's sense, next <-> previous tooth
        slot = {0: 0, 1: 1 if side > 0 else 2, -1: 2 if side > 0 else 1}
        for d, m in slot.items():
            sel = dk == d
            if sel.any():
                out[sel] = (Wt @ self.wheel_m_per_n[m] @ Ws.T)[sel]
        return out

    def worm_m2_per_n_at(self, r_m) -> np.ndarray:
        """The worm thread's per-length compliance at worm radius r (linear in r, held beyond the table)."""
        return np.interp(r_m, self.worm_radius_m, self.worm_m2_per_n)

    def local_m(self, q_n_per_m, inv_rho_per_m, h_wheel_m, r_worm_m) -> np.ndarray:
        """The local approach (m) at line load q: the worm thread's compliance and both flattenings (2)."""
        q = np.maximum(np.asarray(q_n_per_m, float), 0.0)
        h_worm = np.interp(r_worm_m, self.worm_radius_m, self.worm_half_thickness_m)
        return (
            self.worm_m2_per_n_at(r_worm_m) * q
            + flattening_m(q, self.e_wheel_pa, self.nu_wheel, h_wheel_m, inv_rho_per_m, self.e_star_pa)
            + flattening_m(q, self.e_worm_pa, self.nu_worm, h_worm, inv_rho_per_m, self.e_star_pa)
        )


def flattening_m(q_n_per_m, e_pa: float, nu: float, h_m, inv_rho_per_m, e_star_pa: float) -> np.ndarray:
    """(2): Weber and Banaschek's approach of the flank towards the point at depth h under a Hertz line load q."""
    q = np.maximum(np.asarray(q_n_per_m, float), 1e-12)
    b = np.sqrt(4.0 * q / (math.pi * e_star_pa * np.maximum(np.asarray(inv_rho_per_m, float), 1e-12)))
    bracket = np.maximum(np.log(2.0 * np.asarray(h_m) / b) - nu / (2.0 * (1.0 - nu)), 0.0)
    return 2.0 * q * (1.0 - nu**2) / (math.pi * e_pa) * bracket


def _bilinear_weights(xg: np.ndarray, yg: np.ndarray, x: np.ndarray, y: np.ndarray) -> np.ndarray:
    """(k, nx ny) weights of the bilinear interpolation on the grid (xg, yg) at points (x, y), clamped to the grid;
    grid index a ny + b."""
    x, y = np.atleast_1d(x).astype(float), np.atleast_1d(y).astype(float)
    nx, ny = len(xg), len(yg)
    fx = np.clip(np.interp(x, xg, np.arange(nx)), 0, nx - 1)
    fy = np.clip(np.interp(y, yg, np.arange(ny)), 0, ny - 1)
    i0 = np.minimum(np.floor(fx).astype(int), nx - 2)
    j0 = np.minimum(np.floor(fy).astype(int), ny - 2)
    a, b = fx - i0, fy - j0
    W = np.zeros((len(x), nx * ny))
    rows = np.arange(len(x))
    for di, dj, w in ((0, 0, (1 - a) * (1 - b)), (1, 0, a * (1 - b)), (0, 1, (1 - a) * b), (1, 1, a * b)):
        np.add.at(W, (rows, (i0 + di) * ny + j0 + dj), w)
    return W


# ----------------------------------------------------------------------------- the wheel tooth (3D FE)


def flank_grid(g: GearGeometry) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """(zeta (nf,), s (ns,), points (nf, ns, 3), inward normals (nf, ns, 3), centre-line points (nf, ns, 3)) of tooth
    0's flank a on the (zeta, s) grid (module docstring)."""
    from wormsim.tooth.mesh_stiffness import profile_span

    zeta = np.linspace(-g.face_width / 2, g.face_width / 2, GRID_FACE)
    s = np.linspace(0.0, 1.0, GRID_PROFILE)
    lo, hi = profile_span(g, zeta)
    Z, S = np.meshgrid(zeta, s, indexing="ij")
    R = lo[:, None] + (hi - lo)[:, None] * S

    def point(rho, z):
        psi = wheel.tooth_flanks(g, rho, z, "a")[0]
        return np.stack([rho * np.cos(psi), rho * np.sin(psi), z], axis=-1), psi

    X, psi_a = point(R, Z)
    d = H_NORMAL_MX * g.m_x
    tz = point(R, Z + d)[0] - point(R, Z - d)[0]
    tr = point(R + d, Z)[0] - point(R - d, Z)[0]
    n = np.cross(tz, tr)
    n /= np.linalg.norm(n, axis=-1, keepdims=True)
    psi_b = wheel.tooth_flanks(g, R, Z, "b")[1]
    psi_m = 0.5 * (psi_a + psi_b)
    # the centre line point, kept INSET_MX inside the end faces and the tip (the meshed surface is a polyline)
    Rc = np.minimum(R, wheel.tip_rho(g, Z) - INSET_MX * g.m_x)
    Zc = np.clip(Z, -g.face_width / 2 + INSET_MX * g.m_x, g.face_width / 2 - INSET_MX * g.m_x)
    C = np.stack([Rc * np.cos(psi_m), Rc * np.sin(psi_m), Zc], axis=-1)
    n *= np.where(np.einsum("...i,...i->...", n, C - X) < 0, -1.0, 1.0)[..., None]  # into the tooth
    return zeta, s, X, n, C


def _inside(finder, P: np.ndarray, step: float, tries: int = 40) -> np.ndarray:
    """P with each point that lies outside the tetrahedral mesh (the meshed surface is a polyline of the exact one:
    the tip torus's chords) moved radially inwards (towards the wheel axis) by `step` until it is inside."""
    P = P.copy()
    for i in range(len(P)):
        for _ in range(tries):
            try:
                finder(*P[i][:, None])
                break
            except ValueError:
                rho = math.hypot(P[i, 0], P[i, 1])
                P[i, :2] *= (rho - step) / rho
    return P


def _turn(P: np.ndarray, angle: float) -> np.ndarray:
    c, s = math.cos(angle), math.sin(angle)
    return P @ np.array([[c, s, 0.0], [-s, c, 0.0], [0.0, 0.0, 1.0]])


def wheel_influence(g: GearGeometry, e_pa: float, nu: float, density: int = 1, teeth: int = TEETH) -> dict:
    """The wheel's influence coefficients (3, n, n) on flank_grid (module docstring) with the FE sizes."""
    from scipy.spatial import cKDTree

    from wormsim.rating import fe_root

    tm = fe_root.tooth_mesh(
        g,
        density,
        teeth=teeth,
        min_size_m=MIN_SIZE_MX * g.m_x,
        curvature_elements=CURVATURE_ELEMENTS,
        classify_angles_deg=CLASSIFY_ANGLES_DEG,
    )
    ib, free, solve = fe_root.elastic_solver(
        tm.points, tm.tets, e_pa, nu, fe_root.clamped_faces(g, tm.r_in, teeth), DIRECT_DOFS_MAX
    )
    zeta, s, X, n, C = flank_grid(g)
    Xf, nf, Cf = X.reshape(-1, 3), n.reshape(-1, 3), C.reshape(-1, 3)
    pitch = 2 * math.pi / g.z2
    reads = [(Cf, nf)]
    if teeth >= 3:
        reads += [(_turn(Cf, pitch), _turn(nf, pitch)), (_turn(Cf, -pitch), _turn(nf, -pitch))]
    finder = ib.mesh.element_finder()
    probes = [ib.probes(_inside(finder, P, INSET_MX * g.m_x).T.copy()).tocsr() for P, _ in reads]
    surf = np.unique(fe_root._boundary_faces(tm.tets))
    tree = cKDTree(tm.points[surf])
    nn = len(Xf)
    out = np.zeros((3, nn, nn))
    for j in range(nn):
        verts, forces = fe_root._spread(tree, surf, Xf[j : j + 1], nf[j : j + 1], LOAD_RADIUS_MX * g.m_x)
        f = np.zeros(ib.N)
        for c in range(3):
            np.add.at(f, ib.nodal_dofs[c, verts], forces[:, c])
        u = np.zeros(ib.N)
        u[free] = solve(f[free])
        for m, (Pr, nr) in enumerate(reads):
            uv = (probes[m] @ u).reshape(3, -1).T  # probes: component-major rows
            out[m, :, j] = np.einsum("ij,ij->i", uv, nr)
    return {
        "zeta": zeta,
        "s": s,
        "points": X,
        "half_thickness": np.linalg.norm(C - X, axis=-1),
        "influence": out,
        "elements": int(len(tm.tets)),
        "nodes": int(len(tm.points)),
    }


# ----------------------------------------------------------------------------- the worm thread (plane strain FE)


def worm_section(g: GearGeometry, n_flank: int = 16) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The worm's normal section (x across the thread, y the radius): (outline (N, 2) counter-clockwise, the middle
    thread's radii (n_flank,), its normal half thickness there): WORM_THREADS threads of normal pitch p_x cos(gamma)
    on the core down to the axis (y = 0). The axial half thickness (meshgen.worm.half_thickness) times the cosine of
    the lead angle at that radius, tan(gamma_r) = |p| / r."""
    r = np.linspace(g.r_f1, g.r_a1, n_flank)
    hn = worm.half_thickness(g, r) * np.cos(np.arctan(abs(g.p) / r))
    pn = g.p_x * math.cos(g.gamma)
    half = WORM_THREADS // 2
    w = (half + 0.5) * pn
    pts = [np.array([[-w, 0.0], [w, 0.0]])]
    for k in range(half, -half - 1, -1):
        right = np.stack([k * pn + hn, r], -1)
        left = np.stack([k * pn - hn[::-1], r[::-1]], -1)
        pts.append(np.concatenate([right, left]))
    P = np.concatenate(pts)
    P = np.insert(P, 2, [w, g.r_f1], axis=0)
    P = np.concatenate([P, [[-w, g.r_f1]]])
    return P, r, hn


def worm_compliance(g: GearGeometry, e_pa: float, nu: float, density: int = 1) -> dict:
    """Per-length compliance (m^2/N) of the middle thread's flank at WORM_RADII radii (module docstring)."""
    import gmsh
    from scipy.spatial import cKDTree
    from skfem import Basis, ElementTriP2, ElementVector, MeshTri, asm
    from skfem.models.elasticity import lame_parameters, linear_elasticity

    from wormsim.rating import fe_root

    P, r, hn = worm_section(g)
    fine = g.m_n / (6 * density)
    gmsh.initialize(["-noenv"], readConfigFiles=False)
    try:
        gmsh.option.setNumber("General.Terminal", 0)
        gmsh.model.add("thread")
        tags = [
            gmsh.model.geo.addPoint(x, y, 0.0, fine if y >= g.r_f1 - 1e-12 else max(fine, g.r_f1 / (4 * density)))
            for x, y in P
        ]
        lines = [gmsh.model.geo.addLine(tags[i], tags[(i + 1) % len(tags)]) for i in range(len(tags))]
        gmsh.model.geo.addPlaneSurface([gmsh.model.geo.addCurveLoop(lines)])
        gmsh.model.geo.synchronize()
        gmsh.model.mesh.generate(2)
        ntags, xyz, _ = gmsh.model.mesh.getNodes()
        _, _, conn = gmsh.model.mesh.getElements(2)
        pts = np.asarray(xyz).reshape(-1, 3)[:, :2]
        order = np.empty(int(ntags.max()) + 1, dtype=np.int64)
        order[np.asarray(ntags, dtype=np.int64)] = np.arange(len(ntags))
        tri = order[np.asarray(conn[0], dtype=np.int64).reshape(-1, 3)]
    finally:
        gmsh.finalize()
    used = np.unique(tri)
    remap = -np.ones(len(pts), dtype=np.int64)
    remap[used] = np.arange(len(used))
    pts, tri = pts[used], remap[tri]
    mesh = MeshTri(pts.T.copy(), tri.T.copy()).oriented()
    ib = Basis(mesh, ElementVector(ElementTriP2()), intorder=4)
    lam, mu = lame_parameters(e_pa, nu)  # plane strain
    K = asm(linear_elasticity(lam, mu), ib).tocsc()
    fixed = ib.get_dofs(lambda x: x[1] < 1e-9 * g.m_x).all()
    free = np.setdiff1d(np.arange(ib.N), fixed)
    import scipy.sparse.linalg as spla

    lu = spla.splu(K[free][:, free].tocsc())
    radii = np.linspace(g.r_f1 + 0.1 * (g.r_a1 - g.r_f1), g.r_a1 - 0.1 * (g.r_a1 - g.r_f1), WORM_RADII)
    h = np.interp(radii, r, hn)
    dh = np.gradient(hn, r)
    slope = np.interp(radii, r, dh)
    n_out = np.stack([np.ones_like(slope), -slope], -1)
    n_out /= np.linalg.norm(n_out, axis=-1, keepdims=True)
    flank = np.stack([h, radii], -1)
    centre = np.stack([np.zeros_like(radii), radii], -1)
    bnd = np.unique(mesh.facets[:, mesh.boundary_facets()])
    tree = cKDTree(mesh.p[:, bnd].T)
    probe = ib.probes(centre.T.copy()).tocsr()
    comp = np.zeros(WORM_RADII)
    for k in range(WORM_RADII):
        verts, forces = fe_root._spread(tree, bnd, flank[k : k + 1], -n_out[k : k + 1], LOAD_RADIUS_MX * g.m_x)
        f = np.zeros(ib.N)
        for c in range(2):
            np.add.at(f, ib.nodal_dofs[c, verts], forces[:, c])
        u = np.zeros(ib.N)
        u[free] = lu.solve(f[free])
        uv = (probe @ u).reshape(2, -1).T
        comp[k] = float(uv[k] @ -n_out[k])
    return {"radius": radii, "compliance": comp, "half_thickness": h, "elements": int(mesh.t.shape[1])}


# ----------------------------------------------------------------------------- the public entry points


def moduli(materials) -> tuple[float, float, float, float]:
    w, h = materials.worm, materials.wheel
    return h.youngs_modulus_gpa * 1e9, h.poisson_ratio, w.youngs_modulus_gpa * 1e9, w.poisson_ratio


def compute(g: GearGeometry, materials, density: int = 1, teeth: int = TEETH) -> ToothCompliance:
    """The FE models and the grid (module docstring); teeth: the wheel sector's teeth (1 for the study of the
    neighbours' effect)."""
    from wormsim.physics.gear_theory import effective_modulus_pa

    t0 = time.perf_counter()
    e2, nu2, e1, nu1 = moduli(materials)
    wh = wheel_influence(g, e2, nu2, density, teeth)
    wo = worm_compliance(g, e1, nu1, density)
    return ToothCompliance(
        zeta_m=wh["zeta"], s=wh["s"], points_m=wh["points"], wheel_m_per_n=wh["influence"],
        wheel_half_thickness_m=wh["half_thickness"], worm_radius_m=wo["radius"], worm_m2_per_n=wo["compliance"],
        worm_half_thickness_m=wo["half_thickness"], e_wheel_pa=e2, nu_wheel=nu2, e_worm_pa=e1, nu_worm=nu1,
        e_star_pa=effective_modulus_pa(materials), density=density, elements=wh["elements"], nodes=wh["nodes"],
        wall_time_s=time.perf_counter() - t0,
    )  # fmt: skip


def cache_version() -> tuple:
    """What a cached compliance (and a cached LTCA built on it) depends on besides its inputs: this module's
    CODE_VERSION, the FE sector's geometry and mesher (wormsim.rating.fe_root.CODE_VERSION) and the mesher's feature
    angles."""
    from wormsim.rating import fe_root

    return CODE_VERSION, fe_root.CODE_VERSION, CLASSIFY_ANGLES_DEG


@functools.lru_cache(maxsize=16)
def _tooth_compliance(g: GearGeometry, moduli: tuple, materials, density: int) -> ToothCompliance:
    parts = {
        "g": asdict(g),
        "moduli": moduli,
        "density": density,
        "grid": (GRID_FACE, GRID_PROFILE, TEETH, WORM_THREADS, WORM_RADII, LOAD_RADIUS_MX),
        "mesh": (MIN_SIZE_MX, CURVATURE_ELEMENTS, INSET_MX, H_NORMAL_MX),
        "v": cache_version(),
    }
    return cached("tooth-compliance", parts, lambda: compute(g, materials, density))


def tooth_compliance(g: GearGeometry, materials, density: int = 1) -> ToothCompliance:
    """compute(), cached in process and on disk (meshgen.cache) by geometry, E and nu of both bodies, the mesh
    density and CODE_VERSION."""
    return _tooth_compliance(g, moduli(materials), FrozenMaterials(materials), density)


class FrozenMaterials:
    """A materials block as an lru_cache argument: hashed and compared by E and nu only (the key)."""

    def __init__(self, materials):
        self.worm, self.wheel = materials.worm, materials.wheel
        self._key = moduli(materials)

    def __hash__(self) -> int:
        return hash(self._key)

    def __eq__(self, other) -> bool:
        return isinstance(other, FrozenMaterials) and other._key == self._key


REFERENCE_LINE_LOAD_N_PER_M = 1e5  # 100 N/mm: ISO 6336-1's c' holds from F_t K_A / b = 100 N/mm on


def reference_torque_nm(g: GearGeometry) -> float:
    """The wheel torque whose tangential force per face width is REFERENCE_LINE_LOAD_N_PER_M: the working load of
    line_stiffness_n_per_m2 when none is given."""
    return REFERENCE_LINE_LOAD_N_PER_M * g.face_width * g.r2


# ----------------------------------------------------------------------------- ISO 6336-1's estimate (for checks)

E_STEEL_PA = 206e9  # ISO 6336-1's reference modulus
ISO_C = (0.04723, 0.15551, 0.25791, -0.00635, -0.11654, -0.00193, -0.24188, 0.00529, 0.00182)  # C1 .. C9
C_M = 0.8  # ISO 6336-1 theoretical -> measured single stiffness


def iso6336_stiffness(g: GearGeometry, materials) -> dict:
    """ISO 6336-1 method B's single stiffness c' and mesh stiffness c_gamma_alpha (N/(mm um) of face width) of the
    wheel's virtual spur gear: z_n2 = z2 / cos^3(gamma), the worm as its rack (z_n1 -> infinity), no profile shift:

        q' = C1 + C3 / z_n2,  c'_th = 1 / q',  c' = c'_th C_M C_R C_B cos(beta) E / E_st
        C_B = [1 + 0.5 (1.2 - h_fP / m_n)] [1 - 0.02 (20 deg - alpha_n)],  C_R = 1 (solid wheel body),
        beta = gamma (the wheel's helix angle), E = 2 E1 E2 / (E1 + E2), E_st = 206 GPa,
        c_gamma_alpha = c' (0.75 eps_alpha + 0.25),
        eps_alpha = [sqrt(r_a^2 - r_b^2) - r sin(alpha_n) + h_a / sin(alpha_n)] / (pi m_n cos(alpha_n))

    (ISO 6336-1:2019, 9.3 and 9.4; the transverse contact ratio of a gear of z_n2 teeth with its basic rack, module
    m_n, addendum h_a of both the wheel's addendum coefficient)."""
    e1, e2 = materials.worm.youngs_modulus_gpa * 1e9, materials.wheel.youngs_modulus_gpa * 1e9
    zn2 = g.z2 / math.cos(g.gamma) ** 3
    q = ISO_C[0] + ISO_C[2] / zn2
    h_fp = g.h_f / g.m_x  # the dedendum coefficient (of m_x; m_n differs by cos(gamma) < 0.5 % here)
    c_b = (1 + 0.5 * (1.2 - h_fp)) * (1 - 0.02 * (20 - math.degrees(g.alpha_n)))
    e_pair = 2 * e1 * e2 / (e1 + e2)
    c1 = (1 / q) * C_M * c_b * math.cos(g.gamma) * e_pair / E_STEEL_PA
    r = zn2 * g.m_n / 2
    ha = g.h_a / g.m_x * g.m_n
    ra, rb = r + ha, r * math.cos(g.alpha_n)
    eps = (math.sqrt(ra**2 - rb**2) - r * math.sin(g.alpha_n) + ha / math.sin(g.alpha_n)) / (
        math.pi * g.m_n * math.cos(g.alpha_n)
    )
    return {"c_prime": c1, "c_gamma": c1 * (0.75 * eps + 0.25), "eps_alpha": eps, "z_n2": zn2}
