"""Rerun recordings (.rrd) of a run: time series on a simulated-time timeline, meshes, transforms.

Every fidelity level writes its recording through these helpers, so all recordings share one layout:

    /series/<name>            scalar time series (units in the name), timeline "sim_time" (seconds)
    /assembly/worm, /assembly/wheel   meshes (contact3d, meshgen) placed by Transform3D
    /assembly/contacts        contact points and force arrows (contact3d)

Open a recording with `rerun DIR/recording.rrd`.
"""

from __future__ import annotations

import os
from contextlib import contextmanager
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:  # rerun (~0.6 s) is imported where a recording is written: wormsim.run imports it meanwhile
    import rerun as rr

TIMELINE = "sim_time"
APP_ID = "wormsim"


@contextmanager
def recording(path: str | Path, name: str):
    """A RecordingStream that saves to `path` (written to a temp file, renamed on success)."""
    import rerun as rr

    path = Path(path)
    tmp = path.with_name(f".{path.name}.tmp{os.getpid()}")
    rec = rr.RecordingStream(APP_ID, recording_id=name, send_properties=False)
    rec.save(str(tmp))
    try:
        yield rec
        rec.flush()
        rec.disconnect()
        os.replace(tmp, path)
    finally:
        if tmp.exists():
            tmp.unlink()


def log_series(rec: rr.RecordingStream, t_s: np.ndarray, series: dict[str, np.ndarray], prefix: str = "series") -> None:
    """Log every 1-D numeric array of len(t_s) in `series` as a scalar plot on the sim-time timeline.

    Multi-column arrays (N, k) become k plots named `<name>/<i>`. Non-numeric or mismatched arrays
    are skipped (they belong elsewhere).
    """
    import rerun as rr

    t_s = np.asarray(t_s, dtype=float)
    times = rr.TimeColumn(TIMELINE, duration=t_s)
    for name, values in series.items():
        arr = np.asarray(values)
        if name == "t_s" or arr.shape[:1] != t_s.shape or not np.issubdtype(arr.dtype, np.number):
            continue
        cols = arr.reshape(len(t_s), -1).astype(float)
        for i in range(cols.shape[1]):
            path = f"{prefix}/{name}" if cols.shape[1] == 1 else f"{prefix}/{name}/{i}"
            rr.send_columns(path, indexes=[times], columns=rr.Scalars.columns(scalars=cols[:, i]), recording=rec)


def log_mesh(
    rec: rr.RecordingStream,
    path: str,
    vertices: np.ndarray,
    faces: np.ndarray,
    color=(180, 180, 190),
    static: bool = True,
    vertex_normals: np.ndarray | None = None,
) -> None:
    """A triangle mesh (metres) with vertex normals (trimesh's, unless given), logged once (static) under `path`."""
    import rerun as rr

    if vertex_normals is None:
        import trimesh

        mesh = trimesh.Trimesh(vertices=vertices, faces=faces, process=False)
        vertices, faces, vertex_normals = mesh.vertices, mesh.faces, mesh.vertex_normals
    rr.log(
        path,
        rr.Mesh3D(
            vertex_positions=vertices,
            triangle_indices=faces,
            vertex_normals=vertex_normals,
            albedo_factor=list(color),
        ),
        static=static,
        recording=rec,
    )


def log_transforms(rec: rr.RecordingStream, path: str, t_s: np.ndarray, matrices: np.ndarray) -> None:
    """A moving frame: 4x4 homogeneous transforms (N, 4, 4) of `path` on the sim-time timeline."""
    import rerun as rr

    t_s = np.asarray(t_s, dtype=float)
    mats = np.asarray(matrices, dtype=float)
    rr.send_columns(
        path,
        indexes=[rr.TimeColumn(TIMELINE, duration=t_s)],
        columns=rr.Transform3D.columns(translation=mats[:, :3, 3], mat3x3=mats[:, :3, :3]),
        recording=rec,
    )


def save_series_recording(path: str | Path, name: str, t_s: np.ndarray, series: dict[str, np.ndarray]) -> None:
    """Convenience: a recording holding only time series."""
    with recording(path, name) as rec:
        log_series(rec, t_s, series)


def recorded_entities(path: str | Path) -> set[str]:
    """Entity paths stored in an .rrd file (read back with rerun's RrdReader): for tests and checks."""
    from rerun.chunk import RrdReader

    return set(RrdReader(str(path)).store().schema().entity_paths())


ROW_ID_COLUMN = "rerun.controls.RowId"


def _plain(col) -> list:
    """An arrow column as Python values (durations as int64 nanoseconds: to_pylist would need pandas)."""
    import pyarrow as pa

    if pa.types.is_duration(col.type) or pa.types.is_timestamp(col.type):
        col = col.cast(pa.int64())
    return col.to_pylist()


def recorded_data(path: str | Path) -> dict[str, list]:
    """What a recording holds, without rerun's bookkeeping: for each entity path, its chunks' columns (timelines
    and components) as Python lists. Two recordings of identical runs are equal here; their bytes differ because
    rerun stamps every row and chunk with a RowId/ChunkId (a TUID: wall-clock nanoseconds plus a random increment)
    that rerun-sdk 0.41 does not let a logger choose (docs/recording.md)."""
    from rerun.chunk import RrdReader

    out: dict[str, list] = {}
    for chunk in RrdReader(str(path)).store().stream().to_chunks():
        rb = chunk.to_record_batch()
        cols = {n: _plain(rb.column(n)) for n in rb.schema.names if n != ROW_ID_COLUMN}
        out.setdefault(chunk.entity_path, []).append(cols)
    for chunks in out.values():
        chunks.sort(key=lambda c: repr(sorted(c.items()))[:10000])
    # entities by path: the store streams chunks in the order the batcher flushed them, which depends on timing
    return dict(sorted(out.items()))
