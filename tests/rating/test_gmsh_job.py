"""wormsim.rating.fe_root.tet_mesh: gmsh in a child process (wormsim.rating.gmsh_job) with a time limit, and the
last resort that meshes a closed surface as it is."""

from __future__ import annotations

import numpy as np
import pytest
import trimesh

from wormsim.rating import fe_root


@pytest.fixture(scope="module")
def box():
    m = trimesh.creation.box(extents=(0.01, 0.02, 0.03))
    return np.asarray(m.vertices), np.asarray(m.faces)


@pytest.mark.parametrize("angle", [40.0, None], ids=["re-meshed", "as-is"])
def test_a_closed_surface_gets_tetrahedra_filling_its_volume(box, angle):
    P, T = fe_root.tet_mesh(*box, 0.004, 0.002, 2, angle)
    a, b, c, d = (P[T[:, i]] for i in range(4))
    vol = np.abs(np.einsum("ij,ij->i", b - a, np.cross(c - a, d - a))).sum() / 6
    assert vol == pytest.approx(0.01 * 0.02 * 0.03, rel=1e-9)
    assert T.min() == 0 and T.max() == len(P) - 1  # every point is used


def test_an_attempt_over_its_time_limit_is_refused_like_a_gmsh_error(box):
    with pytest.raises(RuntimeError, match="gmsh did not finish within 0.001 s"):
        fe_root.tet_mesh(*box, 0.004, 0.002, 2, 40.0, timeout_s=0.001)


def test_a_refused_attempt_is_followed_by_the_next(box, monkeypatch):
    """An attempt that gmsh refuses, or in which it dies (a segfault in libgmsh, in process, took a test worker down;
    in the child it is a non-zero exit, the same path), is one refused attempt: the retry goes on."""
    calls = []
    real = fe_root.tet_mesh

    def flaky(V, F, size, min_size, curvature, angle):
        calls.append(angle)
        if len(calls) == 1:
            return real(V[:3], F[:1], size, min_size, curvature, angle)  # not a closed surface: gmsh refuses it
        return real(V, F, size, min_size, curvature, angle)

    monkeypatch.setattr(fe_root, "tet_mesh", flaky)
    P, T = fe_root.tet_mesh_retried(*box, 0.004, 0.002, 2, (40.0, None))
    assert calls == [40.0, None] and len(T) > 0


def test_the_job_writes_its_mesh_or_exits_3_with_gmsh_s_message(box, tmp_path):
    """wormsim.rating.gmsh_job, the child's script (run as the parent runs it, in a process of its own): IN.npz ->
    OUT.npz and exit 0; a surface gmsh refuses (an open one: a box without its last two faces) -> exit 3 and gmsh's
    message on stderr, no OUT."""
    import subprocess
    import sys

    from wormsim.rating import gmsh_job

    V, F = box

    def job(faces, name):
        inp, out = tmp_path / f"{name}.in.npz", tmp_path / f"{name}.out.npz"
        np.savez(inp, V=V, F=faces, size_m=0.004, min_size_m=0.002, curvature=2, angle_deg=np.nan, verbose=False)
        cp = subprocess.run(
            [sys.executable, gmsh_job.__file__, str(inp), str(out)], capture_output=True, text=True, timeout=120
        )
        return cp, out

    cp, out = job(F, "closed")
    assert cp.returncode == 0 and len(np.load(out)["tets"]) > 0
    cp, out = job(F[:-2], "open")
    assert cp.returncode == 3 and not out.exists() and cp.stderr.strip()
