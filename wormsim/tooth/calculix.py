"""FE contact check of the tooth compliance with CalculiX (ccx): a worm thread segment and a wheel segment of the
teeth in mesh as linear elastic bodies in frictionless surface-to-surface contact, meshed from meshgen's geometry.
The open counterpart of seed 003's ANSYS contact analysis and the independent check of wormsim.tooth.ltca
(docs/validation.md has the comparison).

Model (assembly frame of meshgen.assembly, millimetres, N, MPa in the .inp):
* Wheel segment: the teeth in contact at worm angle theta1 (meshgen.wheel's exact flanks, the sections of
  wormsim.rating.fe_root: the ISO 53 root fillet, a rim RIM_DEPTH_MX below the throat root circle) and one
  neighbour on each side, lofted from SECTIONS face-width sections. Placed at the kinematic touch of the working
  flank: the conjugate wheel angle hand theta1 z1 / z2 minus side x j / (2 r2) (the backlash closed), so that the
  flanks touch along the contact lines with no load.
* Worm segment: the threads (meshgen.worm's helicoids) and the core down to a bore BORE_MX axial modules below the
  root, cut to a wedge of the worm's polar angle around the line of centres and to the axial span of the wheel
  segment (manifold3d booleans).
* Mesh: gmsh tetrahedra, size H_FINE_MX m_x within the band of the TCA's contact lines (wormsim.tooth.mesh_stiffness)
  growing at GRADE to H_MAX_MX m_x; quadratic (C3D10) with the midside nodes added here. The nodes of the working
  wheel flanks and of the worm's flanks are moved onto the exact surfaces (meshgen.wheel.space_flank,
  meshgen.worm.half_thickness), so that the facets of the lofted input leave no gap of their own.
* Boundary conditions: the worm's bore is clamped; the wheel rim's inner face is a rigid body about the wheel axis
  (*RIGID BODY, its rotation node turned by the prescribed lag angle in INCREMENTS equal steps, the load control
  that needs no initial contact); the reaction moment of the rotation node is the wheel torque T.
* Contact: *CONTACT PAIR TYPE=SURFACE TO SURFACE, one per wheel tooth (slave: its working flank; master: the worm's
  flanks), frictionless, linear penalty PENALTY_FACTOR x E_wheel / h_fine (pressure per overclosure): its own
  compliance per contact area is h_fine / (PENALTY_FACTOR E), a few per cent of the flattening of a line contact.
* Outputs: the mesh stiffness along the line of action k = T / (arm0^2 lag) with arm0 = r2 cos(alpha_n) cos(gamma)
  (the convention of wormsim.tooth.mesh_stiffness), lag the rotation from the kinematic touch; the tangent
  stiffness of the last increment beside it; per wheel tooth the moment of its contact forces about the wheel
  axis (CalculiX's CF totals) -> the load shares; the root stress: the first principal stress of the element-mean
  stress averaged over a ball of fe_root.AVERAGING_RADIUS_MX m_x, over the root band (fe_root.ROOT_BAND_MX) away
  from the end faces (fe_root.EDGE_EXCLUSION_MX) and from the contact lines (fe_root.LOAD_EXCLUSION_MX), the
  definition of wormsim.rating.fe_root.
"""

from __future__ import annotations

import math
import os
import pickle
import re
import shutil
import subprocess
import tempfile
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from meshgen import assembly, wheel, worm
from meshgen.geometry import GearGeometry
from wormsim.scenario import Materials

CODE_VERSION = "calculix-1"
SECTIONS = 41  # face-width sections of the wheel loft (the flank nodes are moved to the exact surface afterwards)
H_FINE_MX = 0.3  # element size at the contact lines, axial modules
H_MAX_MX = 1.0  # largest element size
GRADE = 0.5  # element size growth per distance from the contact lines
BORE_MX = 1.2  # worm bore below the worm root, axial modules
WEDGE_MARGIN_MX = 1.0  # worm wedge beyond the wheel's face width, axial modules (at the pitch radius)
PENALTY_FACTOR = 50.0  # contact penalty K = PENALTY_FACTOR E_wheel / h_fine
INCREMENTS = 2  # equal rotation increments (the tangent stiffness from the last two)
SNAP_MX = 0.05  # nodes within this many m_x of an exact flank are moved onto it


def ccx_path() -> str | None:
    """The CalculiX solver on PATH (Debian package calculix-ccx), None when absent."""
    return shutil.which("ccx")


# ----------------------------------------------------------------------------- geometry


def teeth_in_contact(g: GearGeometry, side: int, theta2_rad: float) -> list[int]:
    """Wheel teeth whose working flank carries a contact line at wheel angle theta2 (the TCA's field:
    wormsim.tooth.mesh_stiffness (2)); space k's side +1 flank is tooth k's flank a, its side -1 flank tooth k-1's b."""
    from wormsim.tooth import mesh_stiffness as ms

    fld = ms._flank_field(g, side)
    pitch = 2 * math.pi / g.z2
    cmin, cmax = float(fld.c.min()), float(fld.c.max())
    spaces = range(math.ceil((cmin - theta2_rad) / pitch), math.floor((cmax - theta2_rad) / pitch) + 1)
    return [k if side > 0 else k - 1 for k in spaces]


def contact_line_points(g: GearGeometry, side: int, theta2_rad: float) -> np.ndarray:
    """Points (n, 3) of the TCA's contact lines at wheel angle theta2, in the wheel frame of tooth k = space k's
    flank (no backlash shift), densely sampled."""
    import contourpy

    from wormsim.tooth import mesh_stiffness as ms

    fld = ms._flank_field(g, side)
    gen = contourpy.contour_generator(z=fld.c, name="serial", corner_mask=True)
    pitch = 2 * math.pi / g.z2
    cmin, cmax = float(fld.c.min()), float(fld.c.max())
    out = [np.zeros((0, 3))]
    for k in range(math.ceil((cmin - theta2_rad) / pitch), math.floor((cmax - theta2_rad) / pitch) + 1):
        for ln in gen.lines(theta2_rad + k * pitch):
            if len(ln) < 2:
                continue
            P = ms._bilinear(fld.xyz, ln[:, 1], ln[:, 0])
            # space k is space 0 turned by k pitches
            c, s = math.cos(k * pitch), math.sin(k * pitch)
            out.append(P @ np.array([[c, s, 0.0], [-s, c, 0.0], [0.0, 0.0, 1.0]]))
    return np.concatenate(out)


def wheel_segment_surface(g: GearGeometry, teeth: list[int]) -> tuple[np.ndarray, np.ndarray]:
    """Watertight triangulated surface (m, wheel frame) of the wheel teeth `teeth` (consecutive) with their rim
    (module docstring), lofted from SECTIONS sections of fe_root's outline."""

    from wormsim.rating import fe_root

    c = fe_root.Counts(zeta=SECTIONS, root=3, fillet=5, flank=17, tip=5, radial=5, inner=5)
    pitch = 2 * math.pi / g.z2
    ks = sorted(teeth)
    zetas = np.linspace(-g.face_width / 2, g.face_width / 2, c.zeta)
    n_tail = 2 * (c.radial - 1) + c.inner
    r_in = g.r_f2 - fe_root.RIM_DEPTH_MX * g.m_x
    secs = []
    for z in zetas:
        one = fe_root.section_outline(g, float(z), c)[:-n_tail]  # tooth 0: root_a .. root_b
        parts = []
        for i, k in enumerate(ks):
            cr, sr = math.cos(k * pitch), math.sin(k * pitch)
            P = one @ np.array([[cr, sr], [-sr, cr]])
            parts.append(P if i == 0 else P[1:])
        s0, s1 = fe_root.space_middles(g, float(z))
        s0, s1 = float(s0) + ks[0] * pitch, float(s1) + ks[-1] * pitch
        lo = float(wheel.root_rho(g, z))
        down = np.linspace(lo, r_in, c.radial + 1)[1:-1]
        side_b = np.stack([down * math.cos(s1), down * math.sin(s1)], -1)
        inner = fe_root.arc(r_in, s1, s0, c.inner * len(ks))
        side_a = np.stack([down[::-1] * math.cos(s0), down[::-1] * math.sin(s0)], -1)
        secs.append(np.concatenate(parts + [side_b, inner, side_a]))
    return fe_root.loft(np.stack(secs), zetas)


def worm_segment_surface(
    g: GearGeometry, theta1_rad: float, z_lo: float, z_hi: float, wedge_rad: float
) -> tuple[np.ndarray, np.ndarray]:
    """Watertight surface (m) of the worm segment in the STATIC worm frame (the worm frame at worm angle 0 of
    meshgen.assembly, the threads turned by theta1): the axial profile of the threads (meshgen.worm, thread n
    centred on u = z - p (phi - theta1) = n p_x) and of the core down to the bore, from the middle of one space to
    the middle of another so that it covers z_lo .. z_hi at every polar angle, swept along the worm polar angle
    phi over +-wedge_rad (the line of centres is +x), with plane end caps at +-wedge_rad."""

    r_bore = g.r_f1 - BORE_MX * g.m_x
    reach = abs(g.p) * (wedge_rad + abs(theta1_rad))
    n_lo = math.floor((z_lo - reach) / g.p_x)
    n_hi = math.ceil((z_hi + reach) / g.p_x)
    n_fl = 13
    r = np.linspace(g.r_f1, g.r_a1, n_fl)
    if g.profile == "ZI" and g.r_b > g.r_f1:  # radial below the base cylinder (meshgen.worm): no collinear points
        r = np.concatenate([[g.r_f1], np.linspace(g.r_b, g.r_a1, n_fl - 1)])
    H = worm.half_thickness(g, r)
    u_lo, u_hi = (n_lo - 0.5) * g.p_x, (n_hi + 0.5) * g.p_x
    # the closed (r, u) outline: right end up, each thread's + flank up and - flank down, left end down, the bore
    # back; the caps are triangulated here as quad strips (ear clipping leaves zero-area triangles on the many
    # collinear root points, which gmsh's reparametrisation cannot take)
    pts = [[r_bore, u_hi], [g.r_f1, u_hi]]
    ridges, root_line = [], [1]
    for n in range(n_hi, n_lo - 1, -1):
        up = list(range(len(pts), len(pts) + n_fl))
        pts += [[ri, n * g.p_x + hi] for ri, hi in zip(r, H)]
        dn = list(range(len(pts), len(pts) + n_fl))
        pts += [[ri, n * g.p_x - hi] for ri, hi in zip(r[::-1], H[::-1])]
        ridges.append((up, dn[::-1]))
        root_line += [up[0], dn[-1]]
    root_line.append(len(pts))
    pts += [[g.r_f1, u_lo], [r_bore, u_lo]]
    bottom = [len(pts) - 1]
    for j in root_line[-2:0:-1]:  # the bore under the root points, from u_lo back to u_hi
        bottom.append(len(pts))
        pts.append([r_bore, pts[j][1]])
    bottom.append(0)
    prof = np.asarray(pts)
    quads = [(uu[i], uu[i + 1], dd[i + 1], dd[i]) for uu, dd in ridges for i in range(n_fl - 1)]
    under = bottom[::-1]  # from u_hi to u_lo, aligned with root_line
    quads += [(root_line[j], root_line[j + 1], under[j + 1], under[j]) for j in range(len(root_line) - 1)]
    tri = np.array([(q[0], q[1], q[2]) for q in quads] + [(q[0], q[2], q[3]) for q in quads])
    e1, e2 = prof[tri[:, 1]] - prof[tri[:, 0]], prof[tri[:, 2]] - prof[tri[:, 0]]
    tri = np.where((e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0] < 0)[:, None], tri[:, ::-1], tri)  # all one way
    phi = np.linspace(-wedge_rad, wedge_rad, int(math.ceil(2 * wedge_rad / math.radians(0.5))) + 1)
    R, U = prof[:, 0][None], prof[:, 1][None]
    X = np.stack([R * np.cos(phi[:, None]), R * np.sin(phi[:, None]), g.p * (phi[:, None] - theta1_rad) + U], -1)
    nz, N = X.shape[:2]
    V = X.reshape(-1, 3)
    idx = np.arange(nz * N).reshape(nz, N)
    I = np.concatenate([idx, idx[:, :1]], axis=1)
    a, b, cc, d = I[:-1, :-1], I[1:, :-1], I[1:, 1:], I[:-1, 1:]
    sides = np.concatenate([np.stack([a, cc, b], -1).reshape(-1, 3), np.stack([a, d, cc], -1).reshape(-1, 3)])
    import trimesh

    F = np.concatenate([sides, idx[0][tri][:, ::-1], idx[-1][tri]])
    if not trimesh.Trimesh(V, F, process=False).is_winding_consistent:
        F = np.concatenate([sides, idx[0][tri], idx[-1][tri][:, ::-1]])
    vol = np.einsum("ij,ij->i", V[F[:, 0]], np.cross(V[F[:, 1]], V[F[:, 2]])).sum() / 6.0
    if vol < 0:
        F = F[:, ::-1]
    return V, F


def tet_mesh_sized(V: np.ndarray, F: np.ndarray, size_at) -> tuple[np.ndarray, np.ndarray]:
    """Linear tetrahedra (gmsh) inside the closed surface (V, F) (m), element size size_at(points (n, 3)) -> (n,) m
    (gmsh's size callback); the surface classified at 40 deg as in wormsim.rating.fe_root.tet_mesh."""
    import gmsh

    gmsh.initialize(["-noenv"], readConfigFiles=False)
    try:
        gmsh.option.setNumber("General.Terminal", 0)
        gmsh.option.setNumber("General.NumThreads", 1)
        gmsh.model.add("segment")
        s = gmsh.model.addDiscreteEntity(2)
        gmsh.model.mesh.addNodes(2, s, list(range(1, len(V) + 1)), (V * 1e3).ravel().tolist())
        gmsh.model.mesh.addElementsByType(s, 2, [], (F.ravel() + 1).tolist())
        gmsh.model.mesh.classifySurfaces(math.radians(40), True, True, math.pi)
        gmsh.model.mesh.createGeometry()
        surfs = [e[1] for e in gmsh.model.getEntities(2)]
        loop = gmsh.model.geo.addSurfaceLoop(surfs)
        gmsh.model.geo.addVolume([loop])
        gmsh.model.geo.synchronize()
        gmsh.option.setNumber("Mesh.MeshSizeExtendFromBoundary", 0)
        gmsh.option.setNumber("Mesh.MeshSizeFromPoints", 0)
        gmsh.option.setNumber("Mesh.MeshSizeFromCurvature", 0)
        gmsh.model.mesh.setSizeCallback(
            lambda dim, tag, x, y, z, lc: float(size_at(np.array([[x, y, z]]) / 1e3)[0] * 1e3)
        )
        gmsh.model.mesh.generate(3)
        tags, xyz, _ = gmsh.model.mesh.getNodes()
        _, _, conn = gmsh.model.mesh.getElements(3)
        P = np.asarray(xyz).reshape(-1, 3) / 1e3
        order = np.empty(int(tags.max()) + 1, dtype=np.int64)
        order[np.asarray(tags, dtype=np.int64)] = np.arange(len(tags))
        T = order[np.asarray(conn[0], dtype=np.int64).reshape(-1, 4)]
    finally:
        gmsh.finalize()
    used = np.unique(T)
    remap = -np.ones(len(P), dtype=np.int64)
    remap[used] = np.arange(len(used))
    return P[used], remap[T]


# CalculiX C3D10: corners 1-4, midside 5 (1-2), 6 (2-3), 7 (3-1), 8 (1-4), 9 (2-4), 10 (3-4); faces by corners
EDGES = ((0, 1), (1, 2), (2, 0), (0, 3), (1, 3), (2, 3))
FACES = ((0, 1, 2), (0, 3, 1), (1, 3, 2), (2, 3, 0))  # S1 .. S4


def quadratic(P: np.ndarray, T: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """C3D10 from linear tetrahedra: the edge midpoints added (shared between elements), CalculiX's node order."""
    T = np.asarray(T)
    vol = np.einsum("ij,ij->i", P[T[:, 1]] - P[T[:, 0]], np.cross(P[T[:, 2]] - P[T[:, 0]], P[T[:, 3]] - P[T[:, 0]]))
    T = np.where((vol < 0)[:, None], T[:, [0, 2, 1, 3]], T)  # positive orientation
    e = np.concatenate([np.sort(T[:, list(ed)], axis=1) for ed in EDGES])
    uniq, inv = np.unique(e, axis=0, return_inverse=True)
    mid = 0.5 * (P[uniq[:, 0]] + P[uniq[:, 1]])
    inv = inv.ravel().reshape(len(EDGES), len(T)).T + len(P)
    return np.concatenate([P, mid]), np.concatenate([T, inv], axis=1)


def boundary_faces(T10: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(element index, face number 0..3) of the faces that belong to one element only."""
    corners = T10[:, :4]
    f = np.concatenate([np.sort(corners[:, list(fc)], axis=1) for fc in FACES])
    _, inv, cnt = np.unique(f, axis=0, return_inverse=True, return_counts=True)
    one = cnt[inv.ravel()] == 1
    n = len(T10)
    idx = np.nonzero(one)[0]
    return idx % n, idx // n


FACE_NODES = ((0, 1, 2, 4, 5, 6), (0, 3, 1, 7, 8, 4), (1, 3, 2, 8, 9, 5), (2, 3, 0, 9, 7, 6))


def face_nodes(T10: np.ndarray, el: np.ndarray, fc: np.ndarray) -> np.ndarray:
    """The 6 nodes of each (element, face)."""
    table = np.asarray(FACE_NODES)
    return T10[el[:, None], table[fc]]


# ----------------------------------------------------------------------------- the case


@dataclass
class Case:
    """One CalculiX contact case: the meshes (m, assembly frame), sets and loads."""

    g: GearGeometry
    side: int
    theta1_rad: float
    theta2_touch_rad: float
    teeth: list[int]
    points: np.ndarray  # (n, 3) all nodes, wheel first
    wheel_tets: np.ndarray  # (m1, 10)
    worm_tets: np.ndarray  # (m2, 10), indices into points
    slave: dict[int, tuple[np.ndarray, np.ndarray]]  # tooth -> (element indices into wheel_tets, face 0..3)
    master: tuple[np.ndarray, np.ndarray]  # (element indices into worm_tets, face)
    rim_nodes: np.ndarray
    bore_nodes: np.ndarray
    root_elements: np.ndarray  # wheel element indices near the root band
    contact_points: np.ndarray  # (k, 3) TCA contact lines, assembly frame
    h_fine_m: float
    snapped: dict = field(default_factory=dict)


def _wheel_flank_psi(g: GearGeometry, rho, zeta, side: int):
    """Exact polar angle of space 0's `side` flank with the backlash shift of meshgen.wheel.tooth_flanks (the
    working flank of tooth 0 for side +1, of tooth -1 for side -1), and whether it is a conjugate point."""
    sol = wheel.space_flank(g, rho, zeta, side)
    dj = g.backlash / (2 * g.r2)
    return sol.psi + side * dj, sol.interior


def build_case(g: GearGeometry, side: int, theta1_rad: float, density: float = 1.0) -> Case:
    """Meshes, sets and placement of the contact case at worm angle theta1 (module docstring). density scales the
    element sizes by 1 / density."""
    from scipy.spatial import cKDTree

    pitch = 2 * math.pi / g.z2
    theta2 = assembly.wheel_angle(g, theta1_rad)
    dj = g.backlash / (2 * g.r2)
    theta2_touch = theta2 - side * dj
    contact = teeth_in_contact(g, side, theta2)
    teeth = list(range(min(contact) - 1, max(contact) + 2))
    h_fine = H_FINE_MX * g.m_x / density
    h_max = H_MAX_MX * g.m_x / density
    # contact lines in the wheel frame (backlash shift of the working flank) and in the assembly frame
    lines_w = contact_line_points(g, side, theta2)
    cz, sz = math.cos(side * dj), math.sin(side * dj)
    lines_w = lines_w @ np.array([[cz, sz, 0.0], [-sz, cz, 0.0], [0.0, 0.0, 1.0]])
    Rw = assembly.wheel_to_assembly(theta2_touch)
    lines_a = assembly.transform_points(Rw, lines_w)
    tree = cKDTree(lines_a)

    def size_at(x):
        d, _ = tree.query(x)
        return np.minimum(h_fine + GRADE * np.maximum(d - 0.3 * g.m_x, 0.0), h_max)

    # wheel: built in the wheel frame, meshed in the assembly frame
    Vw, Fw = wheel_segment_surface(g, teeth)
    Vw = assembly.transform_points(Rw, Vw)
    Pw, Tw = tet_mesh_sized(Vw, Fw, size_at)
    Pw, Tw = quadratic(Pw, Tw)
    # worm: the static worm frame maps to the assembly by worm_to_assembly(0)
    Mw = assembly.worm_to_assembly(0.0, g)
    zs = -(Pw[:, 0])  # worm axial coordinate of the wheel segment's points (static worm frame z = -x)
    margin = 0.25 * g.p_x
    wedge = math.atan2(g.face_width / 2 + WEDGE_MARGIN_MX * g.m_x, g.r1)
    Vs, Fs = worm_segment_surface(g, theta1_rad, float(zs.min()) - margin, float(zs.max()) + margin, wedge)
    Vs = assembly.transform_points(Mw, Vs)
    Ps, Ts = tet_mesh_sized(Vs, Fs, size_at)
    Ps, Ts = quadratic(Ps, Ts)
    snapped = {}
    # move the flank nodes onto the exact surfaces (not where that would turn an element inside out)
    Pw0, Ps0 = Pw, Ps
    Pw, snapped["wheel"] = _snap_wheel(g, side, Pw, Tw, theta2_touch, pitch)
    Ps, snapped["worm"] = _snap_worm(g, Ps, Ts, theta1_rad, Mw)
    Pw, back_w = keep_positive(Pw0, Pw, Tw)
    Ps, back_s = keep_positive(Ps0, Ps, Ts)
    snapped["wheel"]["reverted"], snapped["worm"]["reverted"] = len(back_w), len(back_s)
    snapped["wheel"]["on_flank_nodes"] = np.setdiff1d(snapped["wheel"]["on_flank_nodes"], back_w)
    # sets
    el, fc = boundary_faces(Tw)
    fn = face_nodes(Tw, el, fc)
    cent = Pw[fn[:, :3]].mean(axis=1)
    Rinv = np.linalg.inv(Rw)
    cw = assembly.transform_points(Rinv, cent)
    rho, psi, zeta = np.hypot(cw[:, 0], cw[:, 1]), np.arctan2(cw[:, 1], cw[:, 0]), cw[:, 2]
    psi_ex, _ = _wheel_flank_psi(g, rho, zeta, side)
    k_of = np.round((psi - psi_ex) / pitch)
    # a face of the working flank has all six nodes on it (moved there by _snap_wheel); a face's corner centroid is
    # no test: on a coarse face it lies off the curved flank by more than a node does
    on_node = np.zeros(len(Pw), dtype=bool)
    on_node[snapped["wheel"].pop("on_flank_nodes")] = True
    on_flank = np.all(on_node[fn], axis=1)
    tooth_of = (k_of + (0 if side > 0 else -1)).astype(int)
    slave = {}
    for k in teeth:
        sel = on_flank & (tooth_of == k)
        if sel.any():
            slave[k] = (el[sel], fc[sel])
    # master: worm boundary faces within 0.5 m_x of a working wheel flank face
    el2, fc2 = boundary_faces(Ts)
    fn2 = face_nodes(Ts, el2, fc2)
    c2 = Ps[fn2[:, :3]].mean(axis=1)
    flank_pts = cent[on_flank]
    d2, _ = cKDTree(flank_pts).query(c2)
    msel = d2 < 0.5 * g.m_x
    master = (el2[msel], fc2[msel])
    r_in = g.r_f2 - _rim_depth() * g.m_x
    rim = np.nonzero(np.hypot(Pw[:, 0], Pw[:, 1]) < r_in + 1e-3 * g.m_x)[0]
    xs = assembly.transform_points(np.linalg.inv(Mw), Ps)
    bore = np.nonzero(np.hypot(xs[:, 0], xs[:, 1]) < g.r_f1 - BORE_MX * g.m_x + 1e-3 * g.m_x)[0]
    # root band elements (with the averaging radius around them)
    from wormsim.rating import fe_root

    ecent = Pw[Tw[:, :4]].mean(axis=1)
    ew = assembly.transform_points(Rinv, ecent)
    erho = np.hypot(ew[:, 0], ew[:, 1])
    root = wheel.root_rho(g, ew[:, 2])
    reach = (fe_root.ROOT_BAND_MX + fe_root.AVERAGING_RADIUS_MX + 0.1) * g.m_x
    root_el = np.nonzero(np.abs(erho - root) <= reach)[0]
    n_w = len(Pw)
    return Case(
        g=g, side=side, theta1_rad=theta1_rad, theta2_touch_rad=theta2_touch, teeth=teeth,
        points=np.concatenate([Pw, Ps]), wheel_tets=Tw, worm_tets=Ts + n_w, slave=slave, master=master,
        rim_nodes=rim, bore_nodes=bore + n_w, root_elements=root_el, contact_points=lines_a, h_fine_m=h_fine,
        snapped=snapped,
    )  # fmt: skip


_GAUSS_A, _GAUSS_B = 0.5854101966249685, 0.1381966011250105  # the 4-point rule of C3D10


def min_jacobian(P: np.ndarray, T10: np.ndarray) -> np.ndarray:
    """Per C3D10 element the smallest Jacobian determinant at its four integration points (where CalculiX checks it)."""
    a, b = _GAUSS_A, _GAUSS_B
    dL = np.array([[-1.0, -1.0, -1.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]])  # dL_i / d(xi, eta, zeta)
    X = P[T10]  # (m, 10, 3)
    out = np.full(len(T10), np.inf)
    for l2, l3, l4 in ((b, b, b), (a, b, b), (b, a, b), (b, b, a)):
        L = np.array([1 - l2 - l3 - l4, l2, l3, l4])
        dN = [(4 * L[i] - 1) * dL[i] for i in range(4)]
        dN += [4 * (L[i] * dL[j] + L[j] * dL[i]) for i, j in EDGES]
        J = np.einsum("mnk,nl->mkl", X, np.array(dN))
        out = np.minimum(out, np.linalg.det(J))
    return out


def keep_positive(P0: np.ndarray, P: np.ndarray, T10: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """P with the moves P0 -> P undone at the nodes of elements whose Jacobian turned nonpositive (repeated until
    none); and the nodes put back."""
    P = P.copy()
    back = [np.zeros(0, dtype=np.int64)]
    for _ in range(10):
        bad = min_jacobian(P, T10) <= 0
        if not bad.any():
            break
        nodes = np.unique(T10[bad])
        moved = nodes[(P[nodes] != P0[nodes]).any(axis=1)]
        if len(moved) == 0:
            break
        P[moved] = P0[moved]
        back.append(moved)
    return P, np.concatenate(back)


def _rim_depth() -> float:
    from wormsim.rating import fe_root

    return fe_root.RIM_DEPTH_MX


def _boundary_nodes(T10: np.ndarray) -> np.ndarray:
    el, fc = boundary_faces(T10)
    return np.unique(face_nodes(T10, el, fc))


def _snap_wheel(g: GearGeometry, side: int, P: np.ndarray, T10: np.ndarray, theta2_touch: float, pitch: float):
    """Boundary nodes within SNAP_MX m_x of a working flank (conjugate part) moved onto it circumferentially."""
    P = P.copy()
    nodes = _boundary_nodes(T10)
    R = assembly.wheel_to_assembly(theta2_touch)
    x = assembly.transform_points(np.linalg.inv(R), P[nodes])
    rho, psi, zeta = np.hypot(x[:, 0], x[:, 1]), np.arctan2(x[:, 1], x[:, 0]), x[:, 2]
    psi_ex, interior = _wheel_flank_psi(g, rho, zeta, side)
    k = np.round((psi - psi_ex) / pitch)
    target = psi_ex + k * pitch
    move = interior & (np.abs(rho * (psi - target)) < SNAP_MX * g.m_x)
    new = np.stack([rho * np.cos(target), rho * np.sin(target), zeta], -1)
    moved = new[move]
    P[nodes[move]] = assembly.transform_points(R, moved)
    shift = np.abs(rho * (psi - target))[move]
    info = {"nodes": int(move.sum()), "max_shift_um": float(shift.max() * 1e6) if move.any() else 0.0}
    return P, {**info, "on_flank_nodes": nodes[move]}


def _snap_worm(g: GearGeometry, P: np.ndarray, T10: np.ndarray, theta1_rad: float, M: np.ndarray):
    """Boundary nodes within SNAP_MX m_x of a thread flank (r_f1 < r < r_a1) moved onto it axially."""
    P = P.copy()
    nodes = _boundary_nodes(T10)
    x = assembly.transform_points(np.linalg.inv(M), P[nodes])
    r = np.hypot(x[:, 0], x[:, 1])
    phi = np.arctan2(x[:, 1], x[:, 0])
    u = worm.wrap(x[:, 2] - g.p * (phi - theta1_rad), g.p_x)
    s = np.sign(u)
    H = worm.half_thickness(g, r)
    du = u - s * H
    tol = 1e-3 * g.m_x
    move = (np.abs(du) < SNAP_MX * g.m_x) & (r > g.r_f1 + tol) & (r < g.r_a1 - tol)
    x[move, 2] -= du[move]
    P[nodes] = assembly.transform_points(M, x)
    return P, {"nodes": int(move.sum()), "max_shift_um": float(np.abs(du[move]).max() * 1e6) if move.any() else 0.0}


# ----------------------------------------------------------------------------- CalculiX input, run, output


def write_inp(case: Case, path: Path, e_wheel_pa: float, nu_wheel: float, e_worm_pa: float, nu_worm: float,
              lag_rad: float) -> None:  # fmt: skip
    """The .inp (module docstring), millimetres / N / MPa: the wheel's rotation node turned by -side x lag_rad."""
    mm = 1e3
    P = case.points * mm
    n_nodes = len(P)
    ref, rot = n_nodes + 1, n_nodes + 2
    nw = len(case.wheel_tets)
    lines = ["*HEADING", f"wormsim {CODE_VERSION} contact case", "*NODE"]
    lines += [f"{i + 1},{x:.9g},{y:.9g},{z:.9g}" for i, (x, y, z) in enumerate(P)]
    lines += [f"{ref},0,0,0", f"{rot},0,0,0"]

    def elements(name: str, T: np.ndarray, first: int) -> list[str]:
        out = [f"*ELEMENT, TYPE=C3D10, ELSET={name}"]
        for i, t in enumerate(T):
            out.append(f"{first + i}," + ",".join(str(int(v) + 1) for v in t))
        return out

    lines += elements("EWHEEL", case.wheel_tets, 1)
    lines += elements("EWORM", case.worm_tets, nw + 1)
    lines += _set("NSET", "RIM", case.rim_nodes + 1)
    lines += _set("NSET", "BORE", case.bore_nodes + 1)
    lines += _set("NSET", "NROT", np.array([rot]))
    lines += _set("ELSET", "EROOT", case.root_elements + 1)
    for k, (el, fc) in case.slave.items():
        lines.append(f"*SURFACE, NAME=ST{_tag(k)}, TYPE=ELEMENT")
        lines += [f"{int(e) + 1},S{int(f) + 1}" for e, f in zip(el, fc)]
    el, fc = case.master
    lines.append("*SURFACE, NAME=SWORM, TYPE=ELEMENT")
    lines += [f"{int(e) + 1 + nw},S{int(f) + 1}" for e, f in zip(el, fc)]
    lines += ["*MATERIAL, NAME=WHEEL", "*ELASTIC", f"{e_wheel_pa / 1e6:.6g},{nu_wheel:.6g}"]
    lines += ["*MATERIAL, NAME=WORM", "*ELASTIC", f"{e_worm_pa / 1e6:.6g},{nu_worm:.6g}"]
    lines += ["*SOLID SECTION, ELSET=EWHEEL, MATERIAL=WHEEL", "*SOLID SECTION, ELSET=EWORM, MATERIAL=WORM"]
    lines += [f"*RIGID BODY, NSET=RIM, REF NODE={ref}, ROT NODE={rot}"]
    k_pen = PENALTY_FACTOR * (e_wheel_pa / 1e6) / (case.h_fine_m * mm)  # MPa / mm
    lines += ["*SURFACE INTERACTION, NAME=SI", "*SURFACE BEHAVIOR, PRESSURE-OVERCLOSURE=LINEAR", f"{k_pen:.6g},0.01"]
    for k in case.slave:
        lines += ["*CONTACT PAIR, INTERACTION=SI, TYPE=SURFACE TO SURFACE", f"ST{_tag(k)},SWORM"]
    lines += ["*BOUNDARY", "BORE,1,3", f"{ref},1,3", f"{rot},1,2"]
    inc = 1.0 / INCREMENTS
    lines += ["*STEP, INC=100", "*STATIC, DIRECT", f"{inc},1.0", "*BOUNDARY", f"{rot},3,3,{-case.side * lag_rad:.9g}"]
    lines += ["*NODE PRINT, NSET=NROT", "RF", "U"]
    lines += ["*EL PRINT, ELSET=EROOT", "S"]
    for k in case.slave:  # CF (the totals of a contact pair) needs the pair named
        lines += [f"*CONTACT PRINT, SLAVE=ST{_tag(k)}, MASTER=SWORM", "CF"]
    lines += ["*END STEP"]
    path.write_text("\n".join(lines) + "\n")


def _tag(k: int) -> str:
    return f"M{-k}" if k < 0 else f"P{k}"


def _untag(s: str) -> int:
    return -int(s[1:]) if s[0] == "M" else int(s[1:])


def _set(kind: str, name: str, ids: np.ndarray) -> list[str]:
    out = [f"*{kind}, {kind}={name}"]
    ids = np.asarray(ids, dtype=np.int64)
    for i in range(0, len(ids), 16):
        out.append(",".join(str(int(v)) for v in ids[i : i + 16]))
    return out


def run_ccx(inp: Path, threads: int = 1, timeout_s: float = 3600.0) -> Path:
    """Runs ccx on inp (path without extension is the job name); returns the .dat. Raises RuntimeError with the
    tail of the log when ccx fails or writes no result."""
    exe = ccx_path()
    if exe is None:
        raise RuntimeError("CalculiX (ccx) is not installed: apt-get install calculix-ccx")
    job = inp.with_suffix("")
    env = dict(os.environ, OMP_NUM_THREADS=str(threads), CCX_NPROC_STIFFNESS=str(threads))
    proc = subprocess.run([exe, "-i", job.name], cwd=inp.parent, capture_output=True, text=True, env=env,
                          timeout=timeout_s)  # fmt: skip
    (inp.parent / f"{job.name}.log").write_text(proc.stdout + proc.stderr)
    dat = job.with_suffix(".dat")
    if proc.returncode != 0 or "*ERROR" in proc.stdout or not dat.exists():
        raise RuntimeError(f"ccx failed on {inp.name}: " + (proc.stdout + proc.stderr)[-2000:])
    return dat


_NUM = r"[-+]?\d*\.?\d+(?:[eE][-+]?\d+)?"


def parse_dat(dat: Path) -> dict:
    """Per time: the rotation node's reaction (RF) and displacement (U), per contact surface the CF totals (force,
    moment about the origin), and the root elements' integration-point stresses (last time only)."""
    text = dat.read_text()
    blocks = re.split(r"\n\s*(?=(?:forces|displacements|stresses|statistics)\b)", text)
    out: dict = {"rf": {}, "u": {}, "cf": {}, "stress": {}}
    for b in blocks:
        head = b.strip().split("\n", 1)[0]
        tm = re.search(r"time\s+(" + _NUM + ")", head)
        if tm is None:
            continue
        t = float(tm.group(1))
        rows = [ln.split() for ln in b.strip().split("\n")[1:] if ln.strip()]
        if head.startswith("forces (fx,fy,fz) for set NROT"):
            out["rf"][t] = [float(v) for v in rows[0][1:4]]
        elif head.startswith("displacements (vx,vy,vz) for set NROT"):
            out["u"][t] = [float(v) for v in rows[0][1:4]]
        elif head.startswith("stresses"):
            out["stress"][t] = np.array([[float(v) for v in r[:8]] for r in rows if len(r) >= 8])
        elif head.startswith("statistics for slave set"):
            # "statistics for slave set NAME, master set ... and time t", then under "total surface force (fx,fy,fz)
            # and moment about the origin (mx,my,mz)" one line of six numbers (N, N mm)
            name = head.split("slave set", 1)[1].split()[0].rstrip(",")
            body = [ln for ln in b.strip().split("\n")[1:] if ln.strip()]
            vals = None
            for i, ln in enumerate(body[:-1]):
                if ln.strip().startswith("total surface force"):
                    vals = [float(v) for v in body[i + 1].split()[:6]]
                    break
            out["cf"].setdefault(t, {})[name] = {
                "force": vals[:3] if vals else None,
                "moment": vals[3:] if vals else None,
            }
    return out


# ----------------------------------------------------------------------------- results


def arm0_m(g: GearGeometry) -> float:
    """r2 cos(alpha_n) cos(gamma): the line-of-action arm of wormsim.tooth.mesh_stiffness."""
    return g.r2 * math.cos(g.alpha_n) * math.cos(g.gamma)


def root_stress_mpa(case: Case, stress: np.ndarray) -> dict:
    """The root stress of fe_root's definition (module docstring) from the root elements' integration-point
    stresses (rows: element, point, sxx, syy, szz, sxy, sxz, syz; MPa)."""
    from scipy.spatial import cKDTree

    from wormsim.rating import fe_root

    g = case.g
    el = stress[:, 0].astype(np.int64) - 1
    ids, inv = np.unique(el, return_inverse=True)
    comp = np.zeros((len(ids), 6))
    np.add.at(comp, inv, stress[:, 2:8])
    comp /= np.bincount(inv)[:, None]
    sig = np.zeros((len(ids), 3, 3))
    for (i, j), c in zip(((0, 0), (1, 1), (2, 2), (0, 1), (0, 2), (1, 2)), range(6)):
        sig[:, i, j] = sig[:, j, i] = comp[:, c]
    T = case.wheel_tets[ids]
    P = case.points
    cent = P[T[:, :4]].mean(axis=1)
    vol = np.abs(np.einsum("ij,ij->i", P[T[:, 1]] - P[T[:, 0]],
                           np.cross(P[T[:, 2]] - P[T[:, 0]], P[T[:, 3]] - P[T[:, 0]]))) / 6  # fmt: skip
    cw = assembly.transform_points(np.linalg.inv(assembly.wheel_to_assembly(case.theta2_touch_rad)), cent)
    rho = np.hypot(cw[:, 0], cw[:, 1])
    root = wheel.root_rho(g, cw[:, 2])
    band = np.abs(rho - root) <= fe_root.ROOT_BAND_MX * g.m_x
    band &= np.abs(cw[:, 2]) <= g.face_width / 2 - fe_root.EDGE_EXCLUSION_MX * g.m_x
    d, _ = cKDTree(case.contact_points).query(cent)
    band &= d >= fe_root.LOAD_EXCLUSION_MX * g.m_x
    if not band.any():
        return {"root_stress_max_mpa": None}
    avg = fe_root._ball_average(sig[None], cent, vol, cent[band], fe_root.AVERAGING_RADIUS_MX * g.m_x)[0]
    s1 = fe_root.max_principal(avg)
    i = int(np.argmax(s1))
    pitch = 2 * math.pi / g.z2
    psi = math.atan2(cw[band][i, 1], cw[band][i, 0])
    tooth = int(round((psi - wheel.tooth_angle(g, 0)) / pitch))
    return {"root_stress_max_mpa": float(s1[i]), "root_stress_tooth": tooth,
            "root_stress_position_mm": [float(v * 1e3) for v in cw[band][i]]}  # fmt: skip


def solve(
    g: GearGeometry,
    materials: Materials,
    side: int,
    theta1_rad: float,
    lag_rad: float,
    density: float = 1.0,
    workdir: Path | None = None,
    threads: int = 1,
) -> dict:
    """One CalculiX contact case (module docstring): the wheel turned by lag_rad from the kinematic touch at worm
    angle theta1 against the worm. Returns the torque, the mesh stiffness (secant from the touch and tangent of the
    last increment), the torque per wheel tooth and the load shares, the torque balance, the root stress and the
    model's size. materials: the scenario's (E, nu of the wheel and the worm)."""
    import time

    e_wheel_pa, nu_wheel = materials.wheel.youngs_modulus_gpa * 1e9, materials.wheel.poisson_ratio
    e_worm_pa, nu_worm = materials.worm.youngs_modulus_gpa * 1e9, materials.worm.poisson_ratio
    t0 = time.perf_counter()
    case = build_case(g, side, theta1_rad, density)
    t_mesh = time.perf_counter() - t0
    tmp = None
    if workdir is None:
        tmp = tempfile.TemporaryDirectory(prefix="wormsim-ccx-")
        workdir = Path(tmp.name)
    workdir.mkdir(parents=True, exist_ok=True)
    try:
        inp = workdir / f"{case_name(theta1_rad)}.inp"
        write_inp(case, inp, e_wheel_pa, nu_wheel, e_worm_pa, nu_worm, lag_rad)
        with open(inp.with_suffix(".pkl"), "wb") as fh:  # for re-reading the results without solving again
            pickle.dump({"case": case, "lag_rad": lag_rad, "mesh_wall_s": t_mesh}, fh)
        t1 = time.perf_counter()
        res = parse_dat(run_ccx(inp, threads))
        t_ccx = time.perf_counter() - t1
    finally:
        if tmp is not None:
            tmp.cleanup()
    return summarise(case, res, lag_rad, t_mesh, t_ccx)


def case_name(theta1_rad: float) -> str:
    return f"case_{int(round(math.degrees(theta1_rad) * 1000))}"


def reread(workdir: Path, theta1_rad: float) -> dict:
    """solve()'s result from the files an earlier solve left in workdir (the .pkl of the case and ccx's .dat)."""
    base = workdir / case_name(theta1_rad)
    with open(base.with_suffix(".pkl"), "rb") as fh:
        saved = pickle.load(fh)
    log = base.with_suffix(".log")
    hit = re.search(r"Total CalculiX Time:\s*(" + _NUM + ")", log.read_text()) if log.exists() else None
    t_ccx = float(hit.group(1)) if hit else 0.0  # ccx's own wall time of that solve
    return summarise(saved["case"], parse_dat(base.with_suffix(".dat")), saved["lag_rad"], saved["mesh_wall_s"], t_ccx)


def summarise(case: Case, res: dict, lag_rad: float, t_mesh: float, t_ccx: float) -> dict:
    """The case's results from the parsed .dat (solve's docstring)."""
    g = case.g
    times = sorted(res["rf"])
    if not times or abs(times[-1] - 1.0) > 1e-6:
        raise RuntimeError(f"ccx did not reach the full load (times {times})")
    arm0 = arm0_m(g)
    torque = [abs(res["rf"][t][2]) / 1e3 for t in times]  # N mm -> N m
    t_full = torque[-1]
    k_secant = t_full / (arm0**2 * lag_rad)
    if len(times) >= 2:
        dt = (times[-1] - times[-2]) * lag_rad
        k_tangent = (torque[-1] - torque[-2]) / (arm0**2 * dt)
    else:
        k_tangent = None
    cf = res["cf"].get(times[-1], {})
    per_tooth = {}
    for name, v in cf.items():
        if name.startswith("ST") and v["moment"] is not None:
            per_tooth[_untag(name[2:])] = abs(v["moment"][2]) / 1e3
    total_cf = sum(per_tooth.values())
    share = {k: v / total_cf for k, v in sorted(per_tooth.items())} if total_cf > 0 else {}
    stress = res["stress"].get(times[-1])
    root = root_stress_mpa(case, stress) if stress is not None and len(stress) else {"root_stress_max_mpa": None}
    return {
        "theta1_deg": math.degrees(case.theta1_rad),
        "lag_urad": lag_rad * 1e6,
        "torque_nm": t_full,
        "torque_increments_nm": torque,
        "mesh_stiffness_n_per_m": k_secant,
        "mesh_stiffness_tangent_n_per_m": k_tangent,
        "mesh_stiffness_per_width_n_per_mm_um": k_secant / g.face_width / 1e9,
        "tooth_torque_nm": {str(k): v for k, v in sorted(per_tooth.items())},
        "load_share": {str(k): v for k, v in share.items()},
        "load_share_max": max(share.values()) if share else None,
        "teeth_loaded": int(sum(1 for v in share.values() if v > 0.02)),
        "torque_balance": total_cf / t_full - 1.0 if t_full > 0 else None,
        **root,
        "teeth_modelled": case.teeth,
        "nodes": int(len(case.points)),
        "elements": int(len(case.wheel_tets) + len(case.worm_tets)),
        "h_fine_mm": case.h_fine_m * 1e3,
        "snapped": case.snapped,
        "mesh_wall_s": t_mesh,
        "ccx_wall_s": t_ccx,
    }
