"""meshgen.lazymesh: the gear set's meshes as arrays until trimesh is needed, then the same mesh as before."""

from __future__ import annotations

import copy
import pickle

import numpy as np
import trimesh

from meshgen.lazymesh import LazyMesh


def _box() -> tuple[np.ndarray, np.ndarray]:
    b = trimesh.creation.box(extents=(1.0, 2.0, 3.0))
    return np.asarray(b.vertices, float), np.asarray(b.faces, np.int64)


def test_arrays_without_trimesh_then_trimesh_attributes_as_before():
    v, f = _box()
    m = LazyMesh(v, f)
    assert m.vertices is v and m.faces is f and m._mesh is None  # nothing built for the arrays
    ref = trimesh.Trimesh(v, f, process=False)
    assert m.volume == ref.volume and np.array_equal(m.centroid, ref.centroid)
    assert np.array_equal(m.mass_properties["inertia"], ref.mass_properties["inertia"])
    assert isinstance(m.mesh, trimesh.Trimesh) and m.is_watertight


def test_changes_go_to_the_trimesh_and_the_arrays_follow():
    v, f = _box()
    m = LazyMesh(v, f)
    m.apply_translation((1.0, 0.0, 0.0))
    assert np.allclose(m.vertices, v + (1.0, 0.0, 0.0))
    m.density = 7.8e3  # a set attribute lands on the trimesh
    assert m.mesh.density == 7.8e3 and m.mass == m.volume * 7.8e3
    c = m.copy()
    assert isinstance(c, trimesh.Trimesh) and np.array_equal(c.vertices, m.vertices)


def test_pickle_and_copy_keep_the_arrays():
    v, f = _box()
    for m in (LazyMesh(v, f), pickle.loads(pickle.dumps(LazyMesh(v, f))), copy.deepcopy(LazyMesh(v, f))):
        assert np.array_equal(m.vertices, v) and np.array_equal(m.faces, f) and m.volume > 0
