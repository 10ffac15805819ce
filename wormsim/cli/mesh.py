"""`wormsim mesh SCENARIO --out DIR`: worm.stl, wheel.stl, assembly.json (meshgen.export), recording.rrd and
section.png (the wheel mid-plane section of both meshes, meshgen.section), each written to a temporary name and
renamed (atomic). The recording shows both meshes placed in the assembly frame,
turning through one worm turn with theta2 = hand theta1 z1 / z2."""

from __future__ import annotations

import math
import os
import tempfile
from pathlib import Path

import numpy as np
import trimesh

from meshgen import assembly
from meshgen.export import assembly_data
from meshgen.geometry import GearGeometry
from meshgen.pieces import GearSet
from wormsim.physics.geometry import gear_set
from wormsim.results.recording import log_mesh, log_transforms, recording
from wormsim.runfolder.writer import write_json_atomic
from wormsim.scenario import Scenario, ScenarioError


def _write_stl_atomic(mesh: trimesh.Trimesh, path: Path) -> None:
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", dir=path.parent)
    with os.fdopen(fd, "wb") as fh:
        mesh.export(fh, file_type="stl")
    os.chmod(tmp, 0o644)
    os.replace(tmp, path)


def _recording(path: Path, name: str, g: GearGeometry, gs: GearSet, n_frames: int = 60) -> None:
    theta1 = np.linspace(0.0, 2 * math.pi, n_frames)  # one worm turn
    t_s = np.linspace(0.0, 1.0, n_frames)
    with recording(path, name) as rec:
        log_mesh(rec, "assembly/worm", gs.worm_visual.vertices, gs.worm_visual.faces, color=(170, 175, 185))
        log_mesh(rec, "assembly/wheel", gs.wheel_visual.vertices, gs.wheel_visual.faces, color=(205, 150, 60))
        log_transforms(rec, "assembly/worm", t_s, np.stack([assembly.worm_to_assembly(th, g) for th in theta1]))
        log_transforms(
            rec,
            "assembly/wheel",
            t_s,
            np.stack([assembly.wheel_to_assembly(assembly.wheel_angle(g, th)) for th in theta1]),
        )


def _section_png(path: Path, name: str, g: GearGeometry, gs: GearSet) -> None:
    from meshgen.section import plot_section

    tmp = path.with_name(f".{path.stem}.tmp.png")
    plot_section(g, gs, tmp, name)
    os.chmod(tmp, 0o644)
    os.replace(tmp, path)


def write_mesh_outputs(scenario: Scenario, out_dir: str | Path) -> dict:
    """Generate and write the geometry files; print the derived quantities. Returns the assembly.json dict."""
    if scenario.gear is None:
        raise ScenarioError("gear: `wormsim mesh` needs a gear: block (model contact3d)")
    g, gs = gear_set(scenario)
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    _write_stl_atomic(gs.worm_visual, out / "worm.stl")
    _write_stl_atomic(gs.wheel_visual, out / "wheel.stl")
    data = assembly_data(g, gs)
    _recording(out / "recording.rrd", scenario.name, g, gs)
    _section_png(out / "section.png", scenario.name, g, gs)
    write_json_atomic(out / "assembly.json", data)
    os.chmod(out / "assembly.json", 0o644)
    derived = data["derived"]
    width = max(len(k) for k in derived)
    for k, v in derived.items():
        if k == "hand":
            v = "right" if v > 0 else "left"
        print(f"  {k:<{width}}  {v:.6g}" if isinstance(v, float) else f"  {k:<{width}}  {v}")
    e = gs.piece_error_um
    r = gs.resolution
    level = scenario.simulation.resolution
    print(
        f"  collision pieces (resolution {level}: {r.worm_segments_per_turn} worm segments per turn, "
        f"{r.wheel_slabs} wheel slabs across the face, {r.profile_points} profile points per flank): "
        f"worm {len(gs.worm_pieces)}, wheel {len(gs.wheel_tooth_pieces)}/tooth; "
        f"error worm max {e['worm']['max']:.2f} um rms {e['worm']['rms']:.2f} um, "
        f"wheel max {e['wheel']['max']:.2f} um rms {e['wheel']['rms']:.2f} um"
    )
    if gs.undercut_fraction > 0:
        print(f"  note: wheel undercut {100 * gs.undercut_fraction:.0f} % of the dedendum working depth (mid-plane)")
    print(f"wrote {out / 'worm.stl'}, {out / 'wheel.stl'}, {out / 'assembly.json'}, {out / 'section.png'}")
    print(f"recording: {out / 'recording.rrd'}  (view with: rerun {out / 'recording.rrd'})")
    return data
