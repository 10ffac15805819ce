"""gmsh's tetrahedral mesh of a closed surface, run as a script in a child process by wormsim.rating.fe_root.tet_mesh
(gmsh's meshers cannot be interrupted from Python, and some surfaces make them run for minutes: the parent kills the
child after its time limit). Imports only numpy and gmsh, so that the child starts in about half a second.

    python gmsh_job.py IN.npz OUT.npz      (IN: V (n, 3) m, F (m, 3), size_m, min_size_m, curvature, angle_deg (nan:
                                            no re-meshing), verbose; OUT: points (p, 3) m, tets (t, 4))
"""

from __future__ import annotations

import math
import sys

import numpy as np


def mesh(V, F, size_m: float, min_size_m: float, curvature: int, angle_deg: float | None, verbose: bool = False):
    """The surface (V, F) classified into patches at sharp edges (angle_deg), re-parametrised and re-meshed at size_m
    (refined on curvature, `curvature` elements per 2 pi of a curve's turn, down to min_size_m), then the volume
    meshed; angle_deg None: the triangles (V, F) are the boundary as they are and only the volume is meshed (interior
    elements up to size_m). Returns gmsh's (node tags, xyz in m, tet node tags (t, 4))."""
    import gmsh

    gmsh.initialize(["-noenv"], readConfigFiles=False)
    try:
        gmsh.option.setNumber("General.Terminal", 1 if verbose else 0)
        gmsh.option.setNumber("General.NumThreads", 1)
        gmsh.model.add("tooth")
        s = gmsh.model.addDiscreteEntity(2)
        gmsh.model.mesh.addNodes(2, s, list(range(1, len(V) + 1)), (V * 1e3).ravel().tolist())  # mm
        gmsh.model.mesh.addElementsByType(s, 2, [], (F.ravel() + 1).tolist())
        if angle_deg is not None:
            gmsh.model.mesh.classifySurfaces(math.radians(angle_deg), True, True, math.pi)
            gmsh.model.mesh.createGeometry()
        surfs = [e[1] for e in gmsh.model.getEntities(2)]
        loop = gmsh.model.geo.addSurfaceLoop(surfs)
        gmsh.model.geo.addVolume([loop])
        gmsh.model.geo.synchronize()
        gmsh.option.setNumber("Mesh.MeshSizeMax", size_m * 1e3)
        gmsh.option.setNumber("Mesh.MeshSizeMin", min_size_m * 1e3)
        gmsh.option.setNumber("Mesh.MeshSizeFromCurvature", curvature)
        gmsh.model.mesh.generate(3)
        tags, xyz, _ = gmsh.model.mesh.getNodes()
        _, _, conn = gmsh.model.mesh.getElements(3)
        tets = np.asarray(conn[0], dtype=np.int64).reshape(-1, 4)
        return np.asarray(tags, dtype=np.int64), np.asarray(xyz).reshape(-1, 3) / 1e3, tets
    finally:
        gmsh.finalize()


def main(argv: list[str]) -> int:
    inp, out = argv
    d = np.load(inp)
    angle = float(d["angle_deg"])
    try:
        tags, xyz, tets = mesh(
            d["V"], d["F"], float(d["size_m"]), float(d["min_size_m"]), int(d["curvature"]),
            None if math.isnan(angle) else angle, bool(d["verbose"]),
        )  # fmt: skip
    except Exception as exc:  # gmsh raises plain Exception with its message: the parent re-raises it
        print(exc, file=sys.stderr)
        return 3
    np.savez(out, tags=tags, xyz=xyz, tets=tets)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
