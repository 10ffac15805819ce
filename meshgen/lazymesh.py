"""A triangle mesh kept as its vertex and face arrays until something needs trimesh.

meshgen's gear set (meshgen.pieces) is loaded from its cache as arrays. Runs that read only `vertices` and
`faces` (contact3d with exact flanks: the visual meshes for MuJoCo and the recording) then never import trimesh,
whose import (scipy.spatial) costs ~1 s. Any other attribute, read or set, goes to a trimesh.Trimesh built on first
use exactly as the gear set built it before (process=False); from then on `vertices` and `faces` are its arrays.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np

if TYPE_CHECKING:
    import trimesh


class LazyMesh:
    __slots__ = ("_v", "_f", "_mesh")

    def __init__(self, vertices: np.ndarray, faces: np.ndarray):
        object.__setattr__(self, "_v", vertices)
        object.__setattr__(self, "_f", faces)
        object.__setattr__(self, "_mesh", None)

    @property
    def mesh(self) -> trimesh.Trimesh:
        """The trimesh.Trimesh of these arrays (built once)."""
        if self._mesh is None:
            import trimesh

            object.__setattr__(self, "_mesh", trimesh.Trimesh(self._v, self._f, process=False))
        return self._mesh

    @property
    def vertices(self) -> np.ndarray:
        return self._v if self._mesh is None else self._mesh.vertices

    @property
    def faces(self) -> np.ndarray:
        return self._f if self._mesh is None else self._mesh.faces

    def __getattr__(self, name: str) -> Any:  # only names not found above: trimesh's
        if name.startswith("__") or name in LazyMesh.__slots__:  # unset slot (copy / unpickling): no recursion
            raise AttributeError(name)
        return getattr(self.mesh, name)

    def __setattr__(self, name: str, value: Any) -> None:
        setattr(self.mesh, name, value)

    def __getstate__(self):
        return (np.asarray(self.vertices), np.asarray(self.faces))

    def __setstate__(self, state) -> None:
        LazyMesh.__init__(self, *state)
