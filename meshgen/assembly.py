"""Frames and kinematics of the worm gear pair (docs/geometry.md).

Assembly frame: wheel axis = z through the origin; worm axis parallel to x at y = -a, z = 0.

Worm frame (worm.stl, worm pieces): axis +z, origin on the axis at mid-length. Its axes map into the
assembly (at theta1 = 0) as

    worm +x -> assembly +y   (points from the worm axis at the wheel centre: the line of centres)
    worm +y -> assembly -z
    worm +z -> assembly -x

    worm_to_assembly(theta1) = Trans(0, -a, 0) @ R0 @ Rz(theta1),   R0 = [[0, 0, -1], [1, 0, 0], [0, -1, 0]]

Why -x: docs/geometry.md requires that positive worm rotation (right-hand rule about the worm's own axis +z)
drives the wheel in the positive sense (about +z) for a right-hand worm. Turning a right-hand helicoid
z = p phi + c (p > 0) by +theta1 about its +z moves its thread pattern by -p theta1 along worm z; the
wheel's teeth in mesh sit at y = -r2 (between the wheel centre and the worm), and a positive wheel rotation
moves them along assembly +x. Hence worm +z must be assembly -x. (With worm +z = +x the wheel would turn
negatively for a right-hand worm, contradicting the contract.)

Wheel frame (wheel.stl, wheel pieces): axis +z, mid-plane z = 0; wheel_to_assembly(theta2) = Rz(theta2).
At theta1 = theta2 = 0 worm thread 0 is centred (z_worm = 0 on the worm's +x axis) in the wheel tooth
space centred at polar angle -pi/2 of the wheel frame, on the line of centres. Tooth k's centre line is at
-pi/2 + (2k + 1) pi / z2.

Kinematics (exact for the conjugate pair): theta2 = hand * theta1 * z1 / z2, hand = +1 right, -1 left.
"""

from __future__ import annotations

import math

import numpy as np

from meshgen.geometry import GearGeometry

R0 = np.array([[0.0, 0.0, -1.0], [1.0, 0.0, 0.0], [0.0, -1.0, 0.0]])


def _rz(theta: float) -> np.ndarray:
    c, s = math.cos(theta), math.sin(theta)
    m = np.eye(4)
    m[:2, :2] = [[c, -s], [s, c]]
    return m


def worm_to_assembly(theta1: float, center_distance_m: float | GearGeometry) -> np.ndarray:
    """4x4 homogeneous transform worm frame -> assembly frame at worm angle theta1 (rad)."""
    a = center_distance_m.a if isinstance(center_distance_m, GearGeometry) else float(center_distance_m)
    m = np.eye(4)
    m[:3, :3] = R0
    m[:3, 3] = (0.0, -a, 0.0)
    return m @ _rz(theta1)


def wheel_to_assembly(theta2: float) -> np.ndarray:
    """4x4 homogeneous transform wheel frame -> assembly frame at wheel angle theta2 (rad)."""
    return _rz(theta2)


def wheel_angle(g: GearGeometry, theta1: float) -> float:
    """theta2 = hand * theta1 * z1 / z2 (rad): the wheel angle conjugate to worm angle theta1."""
    return g.hand * theta1 * g.z1 / g.z2


def transform_points(m: np.ndarray, pts: np.ndarray) -> np.ndarray:
    pts = np.asarray(pts, float)
    return pts @ m[:3, :3].T + m[:3, 3]
