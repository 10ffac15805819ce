"""The wheel's mesh window: the W teeth nearest the line of centres, the only ones the contact looks at (and, in the
MuJoCo model, the W tooth slots re-posed by whole pitches as the wheel turns: tooth k lives in slot k mod W), so the
cost does not grow with z2."""

from __future__ import annotations

import math

import numba
import numpy as np

from meshgen.geometry import GearGeometry


def window_size(geo: GearGeometry) -> int:
    """Wheel teeth with collision: those the threaded length can reach, plus one each side."""
    reach = min(geo.worm_length / 2, geo.r_e2)
    half = math.asin(min(reach / geo.r_e2, 1.0)) * geo.z2 / (2 * math.pi)
    return int(min(geo.z2, 2 * math.ceil(half) + 2))


@numba.njit(cache=True)
def window_centre(theta2, tooth0_angle, pitch):
    """The tooth c whose window (window_teeth_at: c - W // 2 + 1 .. c - W // 2 + W) is nearest the line of centres
    (angle -pi/2 in the assembly frame), tooth k at angle tooth0 + k pitch + theta2."""
    return math.floor((-math.pi / 2 - tooth0_angle - theta2) / pitch)


def window_teeth_at(theta2: float, z2: int, window: int, tooth0_angle: float) -> np.ndarray:
    """Unwrapped tooth indices k of the window at wheel angle theta2: the W teeth nearest the line of
    centres (window_centre), tooth k at angle tooth0 + 2 pi k / z2 + theta2."""
    c = window_centre(theta2, tooth0_angle, 2 * math.pi / z2)
    h = window // 2
    return np.arange(c - h + 1, c - h + 1 + window)


def slot_quat(k: int, z2: int, tooth_shift_rad: np.ndarray | None = None) -> list[float]:
    """Orientation of the slot that holds tooth k: a rotation by 2 pi k / z2 about the wheel axis, plus the tooth's
    pitch deviation f_k / r2 (meshgen.displaced) when given."""
    ang = 2 * math.pi * k / z2
    if tooth_shift_rad is not None:
        ang += tooth_shift_rad[k % z2]
    return [math.cos(ang / 2), 0, 0, math.sin(ang / 2)]
