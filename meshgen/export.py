"""The geometry files' content (docs/geometry.md, `wormsim mesh`): assembly.json's data for a gear set.

worm.stl in the worm frame, wheel.stl in the wheel frame (metres); assembly.json holds center_distance_m,
the 4x4 transforms of both parts into the assembly frame at theta1 = theta2 = 0 (meshgen.assembly), the
kinematic relation, the derived quantities (mm, deg) and the measured error of the convex collision pieces.
Writing the files (atomically) and the recording are the simulator's (wormsim.cli.mesh).
"""

from __future__ import annotations

from meshgen import assembly
from meshgen.geometry import GearGeometry
from meshgen.pieces import GearSet


def assembly_data(g: GearGeometry, gs: GearSet) -> dict:
    """assembly.json's content: frames, transforms, derived quantities, piece counts and errors."""
    return {
        "center_distance_m": g.a,
        "frames": {
            "assembly": "wheel axis = z through the origin; worm axis parallel to x at y = -a, z = 0",
            "worm": "axis +z (= assembly -x), origin on the axis at mid-length",
            "wheel": "axis +z, origin at the wheel centre, mid-plane z = 0",
        },
        "kinematics": "theta2 = hand * theta1 * z1 / z2",
        "worm": {
            "stl": "worm.stl",
            "transform": assembly.worm_to_assembly(0.0, g).tolist(),
            "volume_m3": float(gs.worm_visual.volume),
            "pieces": len(gs.worm_pieces),
            "core_radius_m": gs.worm_core_radius_m,
        },
        "wheel": {
            "stl": "wheel.stl",
            "transform": assembly.wheel_to_assembly(0.0).tolist(),
            "volume_m3": float(gs.wheel_visual.volume),
            "pieces_per_tooth": len(gs.wheel_tooth_pieces),
            "tooth0_angle_rad": gs.tooth_angle_rad(0),
        },
        "derived": g.as_dict_mm_deg(),
        "resolution": gs.resolution.__dict__,
        "piece_error_um": gs.piece_error_um,
        "undercut_fraction": gs.undercut_fraction,
    }
