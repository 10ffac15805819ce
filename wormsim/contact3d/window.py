"""The wheel's active collision window: only the W tooth slots nearest the line of centres carry collision pieces,
re-posed by whole pitches as the wheel turns (tooth k lives in slot k mod W), so the cost does not grow with z2."""

from __future__ import annotations

import math
from typing import Protocol

import mujoco
import numpy as np

from meshgen.geometry import GearGeometry


class Windowed(Protocol):
    """What re-posing needs of a built model (wormsim.contact3d.mjcf.BuiltModel has it)."""

    model: mujoco.MjModel
    geometry: GearGeometry
    window_teeth: int
    tooth0_angle_rad: float
    slot_bodies: np.ndarray
    tooth_shift_rad: np.ndarray | None  # (z2,) pitch deviations f_k / r2 (errors:), None for the perfect pair


def window_size(geo: GearGeometry) -> int:
    """Wheel teeth with collision: those the threaded length can reach, plus one each side."""
    reach = min(geo.worm_length / 2, geo.r_e2)
    half = math.asin(min(reach / geo.r_e2, 1.0)) * geo.z2 / (2 * math.pi)
    return int(min(geo.z2, 2 * math.ceil(half) + 2))


def window_teeth_at(theta2: float, z2: int, window: int, tooth0_angle: float) -> np.ndarray:
    """Unwrapped tooth indices k of the window at wheel angle theta2: the W teeth nearest the line of
    centres (angle -pi/2 in the assembly frame), tooth k at angle tooth0 + 2 pi k / z2 + theta2."""
    pitch = 2 * math.pi / z2
    c = math.floor((-math.pi / 2 - tooth0_angle - theta2) / pitch)
    h = window // 2
    return np.arange(c - h + 1, c - h + 1 + window)


def slot_quat(k: int, z2: int, tooth_shift_rad: np.ndarray | None = None) -> list[float]:
    """Orientation of the slot that holds tooth k: a rotation by 2 pi k / z2 about the wheel axis, plus the tooth's
    pitch deviation f_k / r2 (meshgen.displaced) when given."""
    ang = 2 * math.pi * k / z2
    if tooth_shift_rad is not None:
        ang += tooth_shift_rad[k % z2]
    return [math.cos(ang / 2), 0, 0, math.sin(ang / 2)]


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
