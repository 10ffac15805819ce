"""Watertight triangle meshes of the worm and the wheel (visual / export / mass properties), metres.

Construction (no approximation beyond the sampling of the exact surfaces):
- wheel tooth = image of a box under (w, s, t) -> (rho, psi, zeta): zeta across the face width, rho from below
  the root torus to the tip (throat) surface, psi linear between the two generated flanks (meshgen.wheel);
  its boundary is watertight by construction. The whole wheel = manifold3d union of the z2 rotated teeth and
  the rim, a solid of revolution whose outer profile is the root torus section (bore radius 0.35 r_f2).
- worm = manifold3d union of the core cylinder (root radius r_f1) and, per start, the helical sweep of the
  thread ridge's axial profile (meshgen.worm), trimmed to the worm length by the planes z = +-b1/2.
Booleans run in millimetres (manifold3d's tolerance), the result is scaled back to metres.
"""
from __future__ import annotations

import math

import manifold3d as mf
import numpy as np
import trimesh

from meshgen import wheel, worm
from meshgen.geometry import GearGeometry

MM_PER_M = 1000.0


def grid_surface(P: np.ndarray, closed_u: bool = False) -> np.ndarray:
    """Triangles (indices into P.reshape(-1, 3)) of a structured (nu, nv) grid."""
    nu, nv = P.shape[:2]
    idx = np.arange(nu * nv).reshape(nu, nv)
    if closed_u:
        idx = np.concatenate([idx, idx[:1]], axis=0)
    a, b = idx[:-1, :-1], idx[1:, :-1]
    c, d = idx[1:, 1:], idx[:-1, 1:]
    return np.concatenate([np.stack([a, b, c], -1).reshape(-1, 3), np.stack([a, c, d], -1).reshape(-1, 3)])


def box_mesh(P: np.ndarray) -> trimesh.Trimesh:
    """Watertight boundary of a deformed box given as a structured grid P (n0, n1, n2, 3)."""
    n0, n1, n2 = P.shape[:3]
    idx = np.arange(n0 * n1 * n2).reshape(n0, n1, n2)
    faces = []

    def quads(I, flip):
        a, b, c, d = I[:-1, :-1], I[1:, :-1], I[1:, 1:], I[:-1, 1:]
        t = np.concatenate([np.stack([a, b, c], -1).reshape(-1, 3), np.stack([a, c, d], -1).reshape(-1, 3)])
        return t[:, ::-1] if flip else t

    faces += [quads(idx[0], True), quads(idx[-1], False)]
    faces += [quads(idx[:, 0, :], False), quads(idx[:, -1, :], True)]
    faces += [quads(idx[:, :, 0], True), quads(idx[:, :, -1], False)]
    m = trimesh.Trimesh(P.reshape(-1, 3), np.concatenate(faces), process=False)
    m.remove_unreferenced_vertices()
    if m.volume < 0:
        m.invert()
    return m


def tooth_grid(g: GearGeometry, n_zeta: int, n_rho: int, n_w: int, rho_below_root: float = 0.0,
               rho_lo=None, rho_hi=None):
    """Grid (n_w, n_rho, n_zeta, 3) of wheel tooth 0 in the wheel frame; flanks exact at w = 0 and w = 1.

    rho runs from root_rho(zeta) - rho_below_root (flank angle held at its root value below the root) to the tip.
    """
    zeta = np.linspace(-g.face_width / 2, g.face_width / 2, n_zeta)
    lo = wheel.root_rho(g, zeta) if rho_lo is None else rho_lo(zeta)
    hi = wheel.tip_rho(g, zeta) if rho_hi is None else rho_hi(zeta)
    s = np.linspace(0.0, 1.0, n_rho)
    R = lo[None, :] + s[:, None] * (hi - lo)[None, :]               # (n_rho, n_zeta)
    Z = np.broadcast_to(zeta[None, :], R.shape)
    psi_a, psi_b = wheel.tooth_flanks(g, R, Z)
    if rho_below_root > 0:
        R = R.copy()
        R[0] -= rho_below_root
    w = np.linspace(0.0, 1.0, n_w)[:, None, None]
    PSI = psi_a[None] + w * (psi_b - psi_a)[None]
    RR = np.broadcast_to(R[None], PSI.shape)
    ZZ = np.broadcast_to(Z[None], PSI.shape)
    return np.stack([RR * np.cos(PSI), RR * np.sin(PSI), ZZ], axis=-1)


def _to_manifold(m: trimesh.Trimesh) -> mf.Manifold:
    mesh = mf.Mesh64(vert_properties=np.ascontiguousarray(m.vertices * MM_PER_M, dtype=np.float64),
                     tri_verts=np.ascontiguousarray(m.faces, dtype=np.uint32))
    out = mf.Manifold(mesh)
    if out.status() != mf.Error.NoError:
        raise RuntimeError(f"manifold3d rejected a mesh: {out.status()}")
    return out


def _from_manifold(man: mf.Manifold) -> trimesh.Trimesh:
    """Mesh of a manifold: vertices kept apart per input mesh are joined through manifold3d's own merge vectors
    (merge_from_vert -> merge_to_vert), never by a distance tolerance (booleans can leave sub-10-nm triangles)."""
    mesh = man.to_mesh64()
    V = np.asarray(mesh.vert_properties)[:, :3] / MM_PER_M
    F = np.asarray(mesh.tri_verts).astype(np.int64)
    remap = np.arange(len(V))
    remap[np.asarray(mesh.merge_from_vert, dtype=np.int64)] = np.asarray(mesh.merge_to_vert, dtype=np.int64)
    out = trimesh.Trimesh(V, remap[F], process=False)
    out.remove_unreferenced_vertices()
    return out


def wheel_mesh(g: GearGeometry, n_zeta: int = 17, n_rho: int = 12, n_w: int = 4, segments: int = 720) -> trimesh.Trimesh:
    """Whole wheel: z2 teeth + rim (see module docstring)."""
    P = tooth_grid(g, n_zeta, n_rho, n_w, rho_below_root=0.3 * g.m_x)
    tooth = _to_manifold(box_mesh(P))
    teeth = [tooth.rotate((0.0, 0.0, 360.0 * k / g.z2)) for k in range(g.z2)]
    zeta = np.linspace(-g.face_width / 2, g.face_width / 2, 4 * n_zeta)
    rr = wheel.root_rho(g, zeta)
    r_bore = 0.35 * g.r_f2
    poly = [(r_bore * MM_PER_M, -g.face_width / 2 * MM_PER_M)]
    poly += [(r * MM_PER_M, z * MM_PER_M) for r, z in zip(rr, zeta)]
    poly += [(r_bore * MM_PER_M, g.face_width / 2 * MM_PER_M)]
    rim = mf.Manifold.revolve(mf.CrossSection([poly]), circular_segments=segments)
    whole = mf.Manifold.batch_boolean([rim] + teeth, mf.OpType.Add)
    return _from_manifold(whole)



def worm_mesh(g: GearGeometry, segments_per_turn: int = 96, n_flank: int = 12) -> trimesh.Trimesh:
    """Worm threads + core, trimmed to the worm length b1 (see module docstring)."""
    half = g.worm_length / 2
    r_in = g.r_f1 - 0.3 * g.m_x
    prof = worm.ridge_profile(g, n_flank, r_in)              # (m, 2) closed, CCW in (r, u)
    parts = [mf.Manifold.cylinder(g.worm_length * MM_PER_M + 2, g.r_f1 * MM_PER_M,
                                  circular_segments=4 * segments_per_turn, center=True)]
    for n in range(g.z1):
        # thread centre z = p phi + n p_x must cover [-half - p_x, half + p_x]
        z0, z1 = -half - g.p_x, half + g.p_x
        ph = np.sort([(z0 - n * g.p_x) / g.p, (z1 - n * g.p_x) / g.p])
        nseg = max(2, int(math.ceil((ph[1] - ph[0]) / (2 * math.pi) * segments_per_turn)))
        phi = np.linspace(ph[0], ph[1], nseg + 1)
        r, u = prof[:, 0], prof[:, 1]
        X = np.stack([r[None] * np.cos(phi[:, None]), r[None] * np.sin(phi[:, None]),
                      g.p * phi[:, None] + n * g.p_x + u[None]], axis=-1)   # (nphi, m, 3)
        m = X.shape[1]
        verts = X.reshape(-1, 3)
        idx = np.arange(len(phi) * m).reshape(len(phi), m)
        idx_c = np.concatenate([idx, idx[:, :1]], axis=1)           # close the profile loop
        a, b, c, d = idx_c[:-1, :-1], idx_c[1:, :-1], idx_c[1:, 1:], idx_c[:-1, 1:]
        faces = np.concatenate([np.stack([a, b, c], -1).reshape(-1, 3), np.stack([a, c, d], -1).reshape(-1, 3)])
        c0 = len(verts)
        cen = np.stack([X[0].mean(0), X[-1].mean(0)])
        verts = np.concatenate([verts, cen])
        k = np.arange(m)
        cap0 = np.stack([np.full(m, c0), idx[0, (k + 1) % m], idx[0, k]], -1)
        cap1 = np.stack([np.full(m, c0 + 1), idx[-1, k], idx[-1, (k + 1) % m]], -1)
        tm = trimesh.Trimesh(verts, np.concatenate([faces, cap0, cap1]), process=False)
        if not tm.is_winding_consistent:
            tm = trimesh.Trimesh(verts, np.concatenate([faces, cap0[:, ::-1], cap1[:, ::-1]]), process=False)
        if tm.volume < 0:
            tm.invert()
        parts.append(_to_manifold(tm))
    whole = mf.Manifold.batch_boolean(parts, mf.OpType.Add)
    whole = whole.trim_by_plane((0.0, 0.0, -1.0), -half * MM_PER_M).trim_by_plane((0.0, 0.0, 1.0), -half * MM_PER_M)
    return _from_manifold(whole)
