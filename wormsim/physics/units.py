"""The one place where user units (mm, deg, rpm, GPa) become SI (m, rad, rad/s, Pa) and back."""

import math

import numpy as np

MM = 1e-3  # m per mm
GPA = 1e9  # Pa per GPa
DEG = math.pi / 180.0  # rad per deg
RPM = 2.0 * math.pi / 60.0  # (rad/s) per rpm


def rpm_to_rad_s(n_rpm: float) -> float:
    return n_rpm * RPM


def rad_s_to_rpm(w_rad_s: float) -> float:
    return w_rad_s / RPM


def step(t, t0: float, h0: float, t1: float, h1: float):
    """ADAMS STEP: h0 + (h1 - h0) s^2 (3 - 2 s), s = clip((t - t0)/(t1 - t0), 0, 1) (INTERFACE.md).

    Works on floats (without numpy: ODE right-hand sides call it) and numpy arrays; t1 <= t0 gives a jump at t0.
    """
    if isinstance(t, float | int):
        if t1 <= t0:
            return h1 if t >= t0 else h0
        s = (t - t0) / (t1 - t0)
        s = 0.0 if s < 0.0 else (1.0 if s > 1.0 else s)
        return h0 + (h1 - h0) * s * s * (3.0 - 2.0 * s)
    if t1 <= t0:
        return np.where(np.asarray(t) >= t0, h1, h0) if np.ndim(t) else (h1 if t >= t0 else h0)
    s = np.clip((np.asarray(t, dtype=float) - t0) / (t1 - t0), 0.0, 1.0)
    out = h0 + (h1 - h0) * s * s * (3.0 - 2.0 * s)
    return float(out) if np.ndim(out) == 0 else out
