"""Re-posing the MuJoCo model's window slots on the W teeth nearest the line of centres (wormsim.tooth.window)."""

from __future__ import annotations

from typing import Protocol

import mujoco
import numpy as np

from meshgen.geometry import GearGeometry
from wormsim.tooth.window import slot_quat, window_teeth_at


class Windowed(Protocol):
    """What re-posing needs of a built model (wormsim.contact3d.mjcf.BuiltModel has it)."""

    model: mujoco.MjModel
    geometry: GearGeometry
    window_teeth: int
    tooth0_angle_rad: float
    slot_bodies: np.ndarray
    tooth_shift_rad: np.ndarray | None  # (z2,) pitch deviations f_k / r2 (errors:), None for the perfect pair


def repose_window(bm: Windowed, theta2: float, current: np.ndarray | None = None) -> np.ndarray:
    """Place the window slots on the W teeth nearest the line of centres; returns the tooth indices."""
    ks = window_teeth_at(theta2, bm.geometry.z2, bm.window_teeth, bm.tooth0_angle_rad)
    if current is not None and np.array_equal(ks, current):
        return current
    m = bm.model
    for k in ks:
        if current is not None and k in current:
            continue
        m.body_quat[bm.slot_bodies[int(k % bm.window_teeth)]] = slot_quat(int(k), bm.geometry.z2, bm.tooth_shift_rad)
    return ks
