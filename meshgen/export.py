"""`wormsim mesh SCENARIO --out DIR`: worm.stl, wheel.stl, assembly.json, recording.rrd (INTERFACE.md).

worm.stl in the worm frame, wheel.stl in the wheel frame (metres); assembly.json holds center_distance_m,
the 4x4 transforms of both parts into the assembly frame at theta1 = theta2 = 0 (meshgen.assembly), the
kinematic relation, the derived quantities (mm, deg) and the measured error of the convex collision pieces.
The recording shows both meshes placed in the assembly frame, turning through one wheel pitch with
theta2 = hand theta1 z1 / z2. Every file is written to a temporary name and renamed (atomic).
"""
from __future__ import annotations

import math
import os
import tempfile
from pathlib import Path

import numpy as np

from meshgen import assembly
from meshgen.geometry import derive
from meshgen.pieces import build_gear_set
from wormsim.output import write_json_atomic


def _write_stl_atomic(mesh, path: Path) -> None:
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", dir=path.parent)
    with os.fdopen(fd, "wb") as fh:
        mesh.export(fh, file_type="stl")
    os.chmod(tmp, 0o644)
    os.replace(tmp, path)


def _recording(path: Path, name: str, g, gs, n_frames: int = 60) -> None:
    from wormsim.recording import log_mesh, log_transforms, recording

    theta1 = np.linspace(0.0, 2 * math.pi, n_frames)   # one worm turn
    t_s = np.linspace(0.0, 1.0, n_frames)
    with recording(path, name) as rec:
        log_mesh(rec, "assembly/worm", gs.worm_visual.vertices, gs.worm_visual.faces, color=(170, 175, 185))
        log_mesh(rec, "assembly/wheel", gs.wheel_visual.vertices, gs.wheel_visual.faces, color=(205, 150, 60))
        log_transforms(rec, "assembly/worm", t_s,
                       np.stack([assembly.worm_to_assembly(th, g) for th in theta1]))
        log_transforms(rec, "assembly/wheel", t_s,
                       np.stack([assembly.wheel_to_assembly(assembly.wheel_angle(g, th)) for th in theta1]))


def write_mesh_outputs(scenario, out_dir) -> dict:
    """Generate and write the geometry files; print the derived quantities. Returns the assembly.json dict."""
    if scenario.gear is None:
        from wormsim.scenario import ScenarioError

        raise ScenarioError("gear: `wormsim mesh` needs a gear: block (model contact3d)")
    g = derive(scenario.gear)
    gs = build_gear_set(g, getattr(getattr(scenario, "simulation", None), "resolution", None) or "medium")
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    _write_stl_atomic(gs.worm_visual, out / "worm.stl")
    _write_stl_atomic(gs.wheel_visual, out / "wheel.stl")
    derived = g.as_dict_mm_deg()
    data = {
        "center_distance_m": g.a,
        "frames": {"assembly": "wheel axis = z through the origin; worm axis parallel to x at y = -a, z = 0",
                   "worm": "axis +z (= assembly -x), origin on the axis at mid-length",
                   "wheel": "axis +z, origin at the wheel centre, mid-plane z = 0"},
        "kinematics": "theta2 = hand * theta1 * z1 / z2",
        "worm": {"stl": "worm.stl", "transform": assembly.worm_to_assembly(0.0, g).tolist(),
                 "volume_m3": float(gs.worm_visual.volume), "pieces": len(gs.worm_pieces),
                 "core_radius_m": gs.worm_core_radius_m},
        "wheel": {"stl": "wheel.stl", "transform": assembly.wheel_to_assembly(0.0).tolist(),
                  "volume_m3": float(gs.wheel_visual.volume), "pieces_per_tooth": len(gs.wheel_tooth_pieces),
                  "tooth0_angle_rad": gs.tooth_angle_rad(0)},
        "derived": derived,
        "resolution": gs.resolution.__dict__,
        "piece_error_um": gs.piece_error_um,
        "undercut_fraction": gs.undercut_fraction,
    }
    _recording(out / "recording.rrd", scenario.name, g, gs)
    write_json_atomic(out / "assembly.json", data)
    os.chmod(out / "assembly.json", 0o644)
    width = max(len(k) for k in derived)
    for k, v in derived.items():
        print(f"  {k:<{width}}  {v:.6g}" if isinstance(v, float) else f"  {k:<{width}}  {v}")
    e = gs.piece_error_um
    print(f"  collision pieces ({gs.resolution}): worm {len(gs.worm_pieces)}, wheel {len(gs.wheel_tooth_pieces)}/tooth; "
          f"error worm max {e['worm']['max']:.2f} um rms {e['worm']['rms']:.2f} um, "
          f"wheel max {e['wheel']['max']:.2f} um rms {e['wheel']['rms']:.2f} um")
    if gs.undercut_fraction > 0:
        print(f"  note: wheel undercut {100 * gs.undercut_fraction:.0f} % of the dedendum working depth (mid-plane)")
    print(f"wrote {out / 'worm.stl'}, {out / 'wheel.stl'}, {out / 'assembly.json'}")
    print(f"recording: {out / 'recording.rrd'}  (view with: rerun {out / 'recording.rrd'})")
    return data
