"""Summary metrics shared by the gear-level models (torsional, contact3d; docs/outputs.md keys), from the time series.

- steady window: starts after the last ramp (drive.ramp_s, load.start_s + load.ramp_s) plus settling,
  the first time from which a one-mesh-period moving mean of the driven shaft's speed (from its angle increments,
  interval_speed_rpm) stays within
  2 % of the mean of the run's last half; then trimmed from the start to a whole number of mesh periods
  (when at least one fits), so periodic fluctuation does not bias the means;
- mean speeds = |angle increment| / window duration (a mean of |speed| samples would be biased by the
  wheel's high-frequency vibration, which reverses its speed); ratio = n1 / n2; theory z2 / z1;
- meshing frequency: the meshing line, the largest peak of the amplitude spectrum of the meshing signal (contact3d: the
  tangential force; torsional: the transmission error) over the window (mean and linear trend removed, Hann window)
  searched in the band z1 n1 / 60 x (1 +- MESH_BAND) around the theory with n1 the measured mean worm speed
  (mesh_line): the meshing harmonics (2, 3 ... z1 n1 / 60), the contact mode's ringing and the convex pieces' facets
  lie outside the band and are never taken for it. The spectrum is zero-padded (MESH_PAD) and the peak refined on
  the continuous spectrum (DTFT, its maximum next to the bin by Newton's method on its derivative: refine_peak); the
  harmonics' amplitudes k = 1..4 are the spectrum at k f_mesh. The bin width 1 / T_window is
  `mesh_frequency_resolution_hz`; with fewer than MIN_MESH_CYCLES periods in the window, the lines of the harmonics
  overlap and the run warns
  (wormsim.results.run_warnings). The full band's peak of F_t2 is `force_peak_full_band_hz` (dominant_frequency);
- forces: means and peak-to-peak (max - min) over the window, magnitudes of the means;
- efficiency = output power / input power over the window = mean(-T_load w_load) / mean(T_drive w_drive)
  (contact3d: the series worm_power_w / wheel_power_w, T w averaged over every step of each sample);
  theory tan(g) / tan(g + rho') (or tan(g - rho') / tan(g) back-driving), rho' = atan(mu / cos(alpha_n)),
  mu the mean friction coefficient applied over the window.
"""

from __future__ import annotations

import math

import numpy as np

from wormsim.physics import gear_theory as gt
from wormsim.physics.units import RPM, rad_s_to_rpm


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


MESH_BAND = 0.25  # half-width of the meshing line's search band, a share of z1 n1 / 60 (the 2nd harmonic at +100 %)
MESH_PAD = 8  # zero-padding factor of the spectrum the line is first located on
MESH_PAD_MAX = 1 << 22  # ... up to this many points (32 MiB of float64)
MIN_MESH_CYCLES = 5.0  # mesh periods a window needs: Hann main lobes +-2 bins, so the 1st and 2nd lines part at > 4
MESH_HARMONICS = 4  # harmonics whose amplitudes the summary carries


def _hann_dtft_amplitude(tt: np.ndarray, y: np.ndarray, wsum: float, f: float) -> float:
    """Amplitude of the Hann-windowed, detrended y at frequency f (the continuous spectrum, 2 |Y(f)| / sum(w)): the
    amplitude of a sinusoid at exactly f."""
    return float(2.0 * abs(np.dot(y, np.exp(-2j * np.pi * f * tt))) / max(wsum, 1e-300))


def _power_slope(tt: np.ndarray, y: np.ndarray, f: float) -> tuple[float, float]:
    """First and second derivative in f of P(f) = |Y(f)|^2, Y(f) = sum y exp(-2 pi i f t):
    P' = 2 Re(conj(Y) Y'), P'' = 2 (|Y'|^2 + Re(conj(Y) Y'')), Y' = sum (-2 pi i t) y e, Y'' = sum -(2 pi t)^2 y e."""
    ye = y * np.exp(-2j * np.pi * f * tt)
    w = -2j * np.pi * tt
    Y, Y1, Y2 = ye.sum(), np.dot(ye, w), np.dot(ye, w * w)
    return 2.0 * (Y.conjugate() * Y1).real, 2.0 * (abs(Y1) ** 2 + (Y.conjugate() * Y2).real)


def refine_peak(tt: np.ndarray, y: np.ndarray, a: float, b: float, rtol: float = 1e-12, max_iter: int = 60) -> float:
    """The frequency in [a, b] where |Y(f)| (the continuous spectrum of y at the times tt) is largest, for [a, b]
    within one spectral line's main lobe (one maximum): the zero of P'(f) (_power_slope) by Newton's method kept inside
    the bracket where P' changes sign, a bisection where a Newton step leaves it (Press et al., Numerical Recipes,
    rtsafe); a or b when P' does not change sign in [a, b] (the largest value at the interval's end). Newton converges
    quadratically from the padded spectrum's bin, to within rtol f in 3-5 steps, where a bounded scalar search takes
    about 20 evaluations of |Y| to 1e-6 f; no optimisation package is imported for one line per summary."""
    lo, hi = a, b
    d_lo, _ = _power_slope(tt, y, lo)
    d_hi, _ = _power_slope(tt, y, hi)
    if d_lo <= 0.0:  # |Y| falls from a: the largest value is at an end
        return a if d_hi <= 0.0 or _hann_dtft_amplitude(tt, y, 1.0, a) >= _hann_dtft_amplitude(tt, y, 1.0, b) else b
    if d_hi >= 0.0:
        return b
    f = 0.5 * (lo + hi)
    for _ in range(max_iter):
        d1, d2 = _power_slope(tt, y, f)
        if d1 > 0.0:
            lo = f
        else:
            hi = f
        step = d1 / d2 if d2 < 0.0 else float("inf")
        f_new = f - step
        if not (lo < f_new < hi):
            f_new = 0.5 * (lo + hi)
        if abs(f_new - f) <= rtol * abs(f_new) or hi - lo <= rtol * abs(f_new):
            return f_new
        f = f_new
    return f


def mesh_line(t: np.ndarray, x: np.ndarray, f_theory_hz: float, harmonics: bool = True) -> dict:
    """The meshing line of x(t) (uniform grid) near f_theory_hz = z1 n1 / 60 (see the module docstring).

    Returns {"f_hz", "resolution_hz", "cycles", "amplitudes", "found"}: the line's frequency (NaN when x is too short
    or f_theory_hz not positive), the bin width 1 / T, the mesh periods in the window (T f_theory_hz), the amplitudes
    of x at k f_hz for k = 1..MESH_HARMONICS (x's unit; nan without `harmonics`: a caller that takes the frequency
    alone) and whether the band's largest value is an interior peak (False: the largest value sits at the band's edge,
    no line near the theory)."""
    n = len(x)
    nan = {"f_hz": float("nan"), "resolution_hz": float("nan"), "cycles": 0.0, "found": False}
    if n < 8 or not (f_theory_hz > 0) or not np.all(np.isfinite(x)):
        return {**nan, "amplitudes": [float("nan")] * MESH_HARMONICS}
    tt = t - t[0]
    dt = tt[-1] / (n - 1)
    span = n * dt
    w = np.hanning(n)
    y = (x - np.polyval(np.polyfit(tt, x, 1), tt)) * w
    wsum = float(w.sum())
    base = 1 << int(math.ceil(math.log2(n)))
    nfft = max(base, min(MESH_PAD * base, MESH_PAD_MAX))  # long records: less padding (the refinement is exact)
    spec = np.abs(np.fft.rfft(y, nfft)) * 2.0 / max(wsum, 1e-300)
    freqs = np.fft.rfftfreq(nfft, dt)
    lo, hi = f_theory_hz * (1 - MESH_BAND), min(f_theory_hz * (1 + MESH_BAND), freqs[-1])
    band = np.nonzero((freqs >= lo) & (freqs <= hi))[0]
    if len(band) < 3:
        return {
            **nan,
            "resolution_hz": 1.0 / span,
            "cycles": span * f_theory_hz,
            "amplitudes": [float("nan")] * MESH_HARMONICS,
        }
    k = int(band[np.argmax(spec[band])])
    found = band[0] < k < band[-1]
    step = freqs[1] - freqs[0]
    a, b = max(lo, freqs[k] - step), min(hi, freqs[k] + step)
    f = refine_peak(tt, y, a, b)
    amps = [
        _hann_dtft_amplitude(tt, y, wsum, j * f) if harmonics else float("nan") for j in range(1, MESH_HARMONICS + 1)
    ]
    return {"f_hz": f, "resolution_hz": 1.0 / span, "cycles": span * f_theory_hz, "amplitudes": amps, "found": found}


def mesh_line_keys(t: np.ndarray, S: dict, sl: slice, f_theory_hz: float, source: str) -> dict:
    """The summary's meshing-frequency keys from the meshing line of S[source] over the window sl (mesh_line), with
    the amplitudes of the tangential force's and the transmission error's first MESH_HARMONICS meshing harmonics at
    that line's multiples."""
    line = mesh_line(t[sl], S[source][sl], f_theory_hz)
    out = {
        "mesh_frequency_hz": line["f_hz"],
        "mesh_frequency_resolution_hz": line["resolution_hz"],
        "mesh_frequency_line_found": bool(line["found"]),
        "steady_window_mesh_cycles": line["cycles"],
    }
    for key, unit, scale in (("tangential_force_n", "n", 1.0), ("transmission_error_rad", "urad", 1e6)):
        if key not in S:
            continue
        amps = line["amplitudes"] if key == source else _harmonic_amplitudes(t[sl], S[key][sl], line["f_hz"])
        base = key.rsplit("_", 1)[0]
        for j, a in enumerate(amps, 1):
            out[f"{base}_harmonic{j}_{unit}"] = float(a) * scale
    return out


def _harmonic_amplitudes(t: np.ndarray, x: np.ndarray, f_hz: float) -> list[float]:
    """Amplitudes of x(t) (detrended, Hann window) at k f_hz, k = 1..MESH_HARMONICS."""
    n = len(x)
    if n < 8 or not np.isfinite(f_hz):
        return [float("nan")] * MESH_HARMONICS
    tt = t - t[0]
    w = np.hanning(n)
    y = (x - np.polyval(np.polyfit(tt, x, 1), tt)) * w
    return [_hann_dtft_amplitude(tt, y, float(w.sum()), j * f_hz) for j in range(1, MESH_HARMONICS + 1)]


def window_of(S: dict, duty: gt.Duty, geo) -> tuple[int, int, float]:
    """window_after the ramps of the run's drive and load (gear_theory.Duty)."""
    return window_after(S, duty.drive.on, duty.ramps_end_s, geo)


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
    plan,
    i0: int,
    i1: int,
    n1: float,
    n2: float,
    shaft_powers_w: tuple[np.ndarray, np.ndarray] | None = None,
) -> dict:
    """The summary keys every gear-level model shares (docs/outputs.md, less the meshing
    frequency, which each model takes from its own signal): ratio, forces, torques, speeds, efficiency
    (output / input power over the window) and its theory tan(g) / tan(g + rho') (or back-driving).
    shaft_powers_w: (worm, wheel) power series where the level has better ones than the samples' T w (contact3d:
    interval means over every step). plan: the run's wormsim.physics.plan.GearPlan."""
    t = S["t_s"]
    geo, load = plan.geometry, plan.duty.load
    sl = slice(i0, i1)
    ft = S["tangential_force_n"][sl]
    T1, T2 = S["worm_torque_nm"][sl], S["wheel_torque_nm"][sl]
    if shaft_powers_w is not None:
        p1, p2 = float(np.mean(shaft_powers_w[0][sl])), float(np.mean(shaft_powers_w[1][sl]))
    else:
        p1 = float(np.mean(T1 * S["worm_speed_rpm"][sl] * RPM))
        p2 = float(np.mean(T2 * S["wheel_speed_rpm"][sl] * RPM))
    flow = power_flow(n1, n2, geo.ratio, p1, p2)
    eff = flow_efficiency(flow, p1, p2)
    mu = float(np.mean(S["friction_coefficient"][sl]))
    w2 = S["wheel_speed_rpm"]
    return {
        "ratio": n1 / n2 if flow != "none" else float("nan"),
        "power_flow": flow,
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
        "efficiency_theory": gt.efficiency_theory(geo.gamma_m, geo.alpha_n, mu, backdriving=flow == "wheel to worm")
        if flow != "none"
        else float("nan"),
        "friction_coefficient_mean": mu,
        # static: mu at rest (the contact's friction law at Vs = 0); dynamic: the mean mu applied over the window
        **gt.backdrive_keys(
            geo.gamma_m,
            plan.rho_static_rad,
            gt.virtual_friction_angle_rad(mu, geo.alpha_n),
        ),
        "steady_window_s": [float(t[i0]), float(t[i1 - 1])],
        "transmission_error_p2p_urad": float(np.ptp(S["transmission_error_rad"][sl]) * 1e6),
        "wheel_speed_fluctuation": float(np.ptp(w2[sl]) / n2) if n2 > 0 else float("nan"),
        "wheel_speed_std_rpm": float(np.std(w2[sl])),
    }


STANDSTILL_RPM = (
    0.01  # a worm slower than this over the window (3.6 deg a minute) does not turn: no ratio, no efficiency
)


def power_flow(n1_rpm: float, n2_rpm: float, ratio: float, p1_w: float, p2_w: float) -> str:
    """The direction power flows through the mesh over the window: "worm to wheel" (the worm's shaft puts power in,
    p1 > 0), "wheel to worm" (the wheel's shaft puts power in: back-driving, or an overhauling load that drives a
    worm-driven pair) or "none" (either shaft below STANDSTILL_RPM (the wheel: over the ratio), or no shaft puts
    power in): then the ratio and the efficiency are not defined."""
    if not (n1_rpm >= STANDSTILL_RPM and n2_rpm >= STANDSTILL_RPM / max(ratio, 1e-12)):
        return "none"
    if p1_w > 0 and p1_w >= p2_w:
        return "worm to wheel"
    if p2_w > 0:
        return "wheel to worm"
    return "none"


def power_source(flow: str, drive_on: str) -> str:
    """The shaft that puts power into the mesh, "worm" or "wheel": the power flow's source (an overhauling load on
    the wheel of a worm-driven pair: the wheel), else the drive's shaft (no power flows). The friction acts against
    that shaft's motion: the wedge formulas' sign (DIN 3975-2, s = +1 worm driving, -1 wheel driving) follows it."""
    if flow == "worm to wheel":
        return "worm"
    if flow == "wheel to worm":
        return "wheel"
    return drive_on


def flow_efficiency(flow: str, p1_w: float, p2_w: float) -> float:
    """Output power / input power in the direction of the power flow (power_flow): -p2 / p1 worm to wheel, -p1 / p2
    wheel to worm; NaN when no power flows."""
    if flow == "worm to wheel":
        return -p2_w / p1_w
    if flow == "wheel to worm":
        return -p1_w / p2_w
    return float("nan")


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
