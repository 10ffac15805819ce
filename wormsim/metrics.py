"""Summary metrics shared by the gear-level models (torsional, contact3d; INTERFACE.md keys), from the time series.

- steady window: starts after the last ramp (drive.ramp_s, load.start_s + load.ramp_s) plus settling,
  the first time from which a one-mesh-period moving mean of the driven shaft's speed (from its angle increments,
  interval_speed_rpm) stays within
  2 % of the mean of the run's last half; then trimmed from the start to a whole number of mesh periods
  (when at least one fits), so periodic fluctuation does not bias the means;
- mean speeds = |angle increment| / window duration (a mean of |speed| samples would be biased by the
  wheel's high-frequency vibration, which reverses its speed); ratio = n1 / n2; theory z2 / z1;
- meshing frequency: dominant peak of the FFT of the tangential force over the window (mean and linear
  trend removed, Hann window, DC bin excluded), searched below half the piece-passing frequency
  (worm segments per turn x worm speed: the facets of the convex pieces excite the force there; the
  full-band peak is reported as `force_peak_full_band_hz`; the same search on the radial force as
  `mesh_frequency_radial_hz`), refined by Gaussian (log-parabolic) interpolation of
  the peak's three bins; bin width 1 / T_window reported as `mesh_frequency_resolution_hz`; theory
  z1 n1 / 60 with n1 the mean worm speed;
- forces: means and peak-to-peak (max - min) over the window, magnitudes of the means;
- efficiency = output power / input power over the window = mean(-T_load w_load) / mean(T_drive w_drive)
  (contact3d: the series worm_power_w / wheel_power_w, T w averaged over every step of each sample);
  theory tan(g) / tan(g + rho') (or tan(g - rho') / tan(g) back-driving), rho' = atan(mu / cos(alpha_n)),
  mu the mean friction coefficient applied over the window.
"""

from __future__ import annotations

import math

import numpy as np

from wormsim import gear_theory as gt
from wormsim.friction import friction_coefficient
from wormsim.units import RPM, rad_s_to_rpm


def steady_window(t: np.ndarray, speed: np.ndarray, t_start: float, period_s: float) -> tuple[int, int]:
    """Indices [i0, i1) of the steady window (see the module docstring)."""
    n = len(t)
    i_ramp = int(np.searchsorted(t, t_start))
    if n - i_ramp < 8:
        return max(0, n - 8), n
    dt = (t[-1] - t[0]) / max(n - 1, 1)
    half = speed[max(i_ramp, n // 2) :]
    ref = abs(float(np.mean(half))) if len(half) else 0.0
    w = max(1, int(round(period_s / dt))) if period_s > 0 else 1
    w = min(w, max(1, (n - i_ramp) // 4))
    mm = np.abs(np.convolve(speed, np.ones(w) / w, mode="same"))
    bad = np.abs(mm[i_ramp:] - ref) > 0.02 * max(ref, 1e-12)
    # first index after which no moving mean is outside the band (ignore the last half-window edge)
    edge = max(1, w // 2)
    bad[-edge:] = False
    idx = np.nonzero(bad)[0]
    i0 = i_ramp + (int(idx[-1]) + 1 if len(idx) else 0)
    i0 = min(i0, n - max(8, (n - i_ramp) // 4))
    i1 = n
    if period_s > 0:
        span = t[i1 - 1] - t[i0]
        periods = math.floor(span / period_s)
        if periods >= 1:
            i0 = int(np.searchsorted(t, t[i1 - 1] - periods * period_s))
    return i0, i1


def dominant_frequency(
    t: np.ndarray, x: np.ndarray, f_max_hz: float = float("inf")
) -> tuple[float, float, np.ndarray, np.ndarray]:
    """(f_peak_hz, resolution_hz, freqs, amplitude spectrum) of x(t) on a uniform grid: linear trend
    removed, Hann window, DC bin excluded, peak searched below f_max_hz, Gaussian interpolation of the
    peak bin."""
    n = len(x)
    if n < 8:
        return float("nan"), float("nan"), np.zeros(0), np.zeros(0)
    dt = (t[-1] - t[0]) / (n - 1)
    tt = t - t[0]
    coef = np.polyfit(tt, x, 1)
    y = (x - np.polyval(coef, tt)) * np.hanning(n)
    spec = np.abs(np.fft.rfft(y)) * 2 / max(np.hanning(n).sum(), 1e-12)
    freqs = np.fft.rfftfreq(n, dt)
    df = 1.0 / (n * dt)
    top = max(2, int(np.searchsorted(freqs, f_max_hz, side="right")))
    k = 1 + int(np.argmax(spec[1:top]))
    f = freqs[k]
    if 1 <= k < len(spec) - 1 and spec[k - 1] > 0 and spec[k] > 0 and spec[k + 1] > 0:
        a, b, c = np.log(spec[k - 1]), np.log(spec[k]), np.log(spec[k + 1])
        den = a - 2 * b + c
        if den < 0:
            f = freqs[k] + 0.5 * (a - c) / den * df
    return float(f), float(df), freqs, spec


def window_of(S: dict, scenario, geo) -> tuple[int, int, float]:
    """window_after the scenario's ramps (gear_theory.ramps_end_s) with its drive."""
    return window_after(S, scenario.drive.on, gt.ramps_end_s(scenario), geo)


def window_after(S: dict, drive_on: str, ramp_end: float, geo) -> tuple[int, int, float]:
    """Steady window [i0, i1) of a run after its ramps' end (s) and the mesh period used to find and trim it; the
    driven shaft's angle (the wheel's when drive_on is "worm") gives the speeds."""
    t = S["t_s"]
    w1 = S["worm_speed_rpm"]
    n1_guess = abs(float(np.mean(w1[len(w1) // 2 :]))) if len(w1) else 0.0
    f_mesh_guess = geo.z1 * n1_guess / 60.0
    period = 1.0 / f_mesh_guess if f_mesh_guess > 0 else 0.0
    ang = S["wheel_angle_rad"] if drive_on == "worm" else S["worm_angle_rad"]
    i0, i1 = steady_window(t, interval_speed_rpm(t, ang), ramp_end, period)
    return i0, i1, period


def interval_speed_rpm(t: np.ndarray, angle: np.ndarray) -> np.ndarray:
    """Mean speed over each sample interval from the angle increments, rpm. The speed samples themselves are point
    values: a light wheel that rattles at kHz (seat motor: speed p2p 28x its mean at 36 rpm, 1 ms samples) makes
    their one-period moving mean wander by ~20 %, and the 2 % steady band was then found only in the run's last
    two mesh periods (20 s run: window 16.7-20 s); the angle increments integrate the rattle exactly."""
    if len(t) < 2:
        return rad_s_to_rpm(np.zeros_like(angle))
    v = np.empty_like(angle, dtype=float)
    v[1:] = np.diff(angle) / np.maximum(np.diff(t), 1e-300)
    v[0] = v[1]
    return rad_s_to_rpm(v)


def mean_speeds_rpm(S: dict, i0: int, i1: int) -> tuple[float, float]:
    """Mean worm and wheel speeds = |angle increment| / window duration (exact for the sampled angles; a
    mean of |speed| samples would be biased by the wheel's high-frequency vibration, which reverses it)."""
    t = S["t_s"]
    span = t[i1 - 1] - t[i0]
    if span <= 0:
        return float("nan"), float("nan")
    n1 = rad_s_to_rpm(abs(S["worm_angle_rad"][i1 - 1] - S["worm_angle_rad"][i0]) / span)
    n2 = rad_s_to_rpm(abs(S["wheel_angle_rad"][i1 - 1] - S["wheel_angle_rad"][i0]) / span)
    return float(n1), float(n2)


def drive_summary(
    S: dict,
    scenario,
    geo,
    i0: int,
    i1: int,
    n1: float,
    n2: float,
    shaft_powers_w: tuple[np.ndarray, np.ndarray] | None = None,
) -> dict:
    """The summary keys every gear-level model shares (INTERFACE.md contact3d list, less the meshing
    frequency, which each model takes from its own signal): ratio, forces, torques, speeds, efficiency
    (output / input power over the window) and its theory tan(g) / tan(g + rho') (or back-driving).
    shaft_powers_w: (worm, wheel) power series where the level has better ones than the samples' T w (contact3d:
    interval means over every step)."""
    t = S["t_s"]
    drv, load = scenario.drive, scenario.load
    sl = slice(i0, i1)
    ft = S["tangential_force_n"][sl]
    T1, T2 = S["worm_torque_nm"][sl], S["wheel_torque_nm"][sl]
    if shaft_powers_w is not None:
        p1, p2 = float(np.mean(shaft_powers_w[0][sl])), float(np.mean(shaft_powers_w[1][sl]))
    else:
        p1 = float(np.mean(T1 * S["worm_speed_rpm"][sl] * RPM))
        p2 = float(np.mean(T2 * S["wheel_speed_rpm"][sl] * RPM))
    if drv.on == "worm":
        eff = -p2 / p1 if p1 > 0 else float("nan")
    else:
        eff = -p1 / p2 if p2 > 0 else float("nan")
    mu = float(np.mean(S["friction_coefficient"][sl]))
    w2 = S["wheel_speed_rpm"]
    return {
        "ratio": n1 / n2 if n2 > 0 else float("inf"),
        "ratio_theory": geo.ratio,
        "mesh_frequency_theory_hz": geo.z1 * n1 / 60.0,
        "tangential_force_mean_n": abs(float(np.mean(ft))),
        "tangential_force_p2p_n": float(np.ptp(ft)) if len(ft) else float("nan"),
        "tangential_force_theory_n": gt.tangential_force_n(abs(load.torque_nm), geo.r2)
        if load.on == "wheel"
        else float("nan"),
        "radial_force_mean_n": abs(float(np.mean(S["radial_force_n"][sl]))),
        "axial_force_mean_n": abs(float(np.mean(S["axial_force_n"][sl]))),
        "worm_torque_mean_nm": abs(float(np.mean(T1))),
        "wheel_torque_mean_nm": abs(float(np.mean(T2))),
        "worm_speed_mean_rpm": n1,
        "wheel_speed_mean_rpm": n2,
        "efficiency": eff,
        "efficiency_theory": gt.efficiency_theory(geo.gamma_m, geo.alpha_n, mu, backdriving=drv.on == "wheel"),
        "friction_coefficient_mean": mu,
        # static: mu at rest (the contact's friction law at Vs = 0); dynamic: the mean mu applied over the window
        **gt.backdrive_keys(
            geo.gamma_m,
            gt.virtual_friction_angle_rad(float(friction_coefficient(scenario.contact, 0.0)), geo.alpha_n),
            gt.virtual_friction_angle_rad(mu, geo.alpha_n),
        ),
        "steady_window_s": [float(t[i0]), float(t[i1 - 1])],
        "transmission_error_p2p_urad": float(np.ptp(S["transmission_error_rad"][sl]) * 1e6),
        "wheel_speed_fluctuation": float(np.ptp(w2[sl]) / n2) if n2 > 0 else float("nan"),
        "wheel_speed_std_rpm": float(np.std(w2[sl])),
    }


def p2p_below(t: np.ndarray, x: np.ndarray, f_max_hz: float) -> float:
    """Peak-to-peak of x(t) (uniform grid) below f_max_hz: linear trend removed, the FFT's lines at and above
    f_max_hz zeroed (a brick-wall low-pass). Separates F_t's meshing band from the contact mode's ringing
    (docs/contact3d.md, "Default slice count")."""
    n = len(x)
    if n < 8:
        return float("nan")
    tt = t - t[0]
    y = x - np.polyval(np.polyfit(tt, x, 1), tt)
    X = np.fft.rfft(y)
    X[np.fft.rfftfreq(n, tt[-1] / (n - 1)) >= f_max_hz] = 0
    return float(np.ptp(np.fft.irfft(X, n)))
