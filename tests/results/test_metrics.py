"""wormsim.results.metrics on synthetic signals whose answers are known in closed form."""

import math

import numpy as np
import pytest

from wormsim.physics.gear_theory import efficiency_theory
from wormsim.results.metrics import dominant_frequency, steady_window


@pytest.mark.parametrize("f_true", [7.3, 12.0, 31.77])
def test_fft_peak_interpolation_beats_the_bin(f_true):
    t = np.arange(0, 2.0, 1e-3)  # bin 0.5 Hz
    x = 5 + 0.2 * t + np.sin(2 * math.pi * f_true * t) + 0.3 * np.sin(2 * math.pi * 3 * f_true * t)
    f, df, _, _ = dominant_frequency(t, x)
    assert df == pytest.approx(0.5, rel=1e-3)
    assert abs(f - f_true) < 0.1 * df  # Gaussian interpolation on a Hann window


def test_fft_search_band_excludes_facet_noise():
    t = np.arange(0, 2.0, 1e-3)
    x = np.sin(2 * math.pi * 7.3 * t) + 3 * np.sin(2 * math.pi * 120 * t)
    # the synthetic signal's own frequencies: 120 Hz strongest, 7.3 Hz below the 50 Hz band limit
    assert dominant_frequency(t, x)[0] == pytest.approx(120, abs=0.1)
    assert dominant_frequency(t, x, f_max_hz=50)[0] == pytest.approx(7.3, abs=0.05)


def test_steady_window_starts_after_ramp_and_settling_and_spans_whole_periods():
    t = np.arange(0, 3.0, 1e-3)
    period = 0.25
    speed = np.where(t < 0.5, t / 0.5, 1.0) + 0.3 * np.exp(-(t - 0.5).clip(0) / 0.1) * (t > 0.5)
    speed = speed + 0.01 * np.sin(2 * math.pi * t / period)
    i0, i1 = steady_window(t, speed, 0.5, period)
    assert t[i0] > 0.5 + 0.2  # 0.3 exp(-t/0.1) < 2 % after ~0.27 s
    span = t[i1 - 1] - t[i0]
    assert span / period == pytest.approx(round(span / period), abs=0.01)


def test_efficiency_theory_wedge_values():
    g, a = math.radians(4.79), math.radians(10)
    rho = math.atan(0.05 / math.cos(a))
    assert efficiency_theory(g, a, 0.05) == pytest.approx(math.tan(g) / math.tan(g + rho))
    assert efficiency_theory(g, a, 0.0) == pytest.approx(1.0)
    assert efficiency_theory(g, a, 0.1, backdriving=True) == 0.0  # rho' 5.8 deg > gamma 4.79 deg


def test_power_source_is_the_flows_source_else_the_drive():
    """The shaft that puts power in: an overhauling load's wheel in a worm-driven pair (the friction, and with it the
    wedge formulas' sign, follows it: DIN 3975-2), the drive's shaft when no power flows."""
    from wormsim.results.metrics import power_source

    assert power_source("worm to wheel", "worm") == "worm"
    assert power_source("wheel to worm", "worm") == "wheel"
    assert power_source("worm to wheel", "wheel") == "worm"
    assert power_source("none", "wheel") == "wheel" and power_source("none", "worm") == "worm"


def test_refine_peak_is_the_continuous_spectrums_maximum():
    """Newton's bracketed refinement finds the maximum of |Y(f)| that a bounded scalar search (scipy's, tight
    tolerance) finds, on noisy lines with a harmonic and an offset; a maximum at the bracket's end returns the end."""
    from scipy.optimize import minimize_scalar

    from wormsim.results.metrics import _hann_dtft_amplitude, refine_peak

    rng = np.random.default_rng(7)
    for _ in range(40):
        n, dt = int(rng.integers(64, 8000)), 1e-4
        t = np.arange(n) * dt
        f0 = rng.uniform(20.0, 1500.0)
        x = rng.uniform(0.1, 10) * np.sin(2 * np.pi * f0 * t + rng.uniform(0, 6)) + 0.3 * np.sin(4 * np.pi * f0 * t)
        x += rng.normal(0, rng.uniform(0, 1), n)
        w = np.hanning(n)
        y = (x - np.polyval(np.polyfit(t, x, 1), t)) * w
        f_bin = f0 + rng.uniform(-0.1, 0.1) / (n * dt)  # the padded spectrum's bin next to the line
        a, b = f_bin - 0.25 / (n * dt), f_bin + 0.25 / (n * dt)
        ref = minimize_scalar(
            lambda f: -_hann_dtft_amplitude(t, y, w.sum(), f),
            bounds=(a, b),
            method="bounded",
            options={"xatol": 1e-12 * a},
        ).x
        got = refine_peak(t, y, a, b)
        assert a <= got <= b
        assert got == pytest.approx(ref, rel=1e-7)
        assert _hann_dtft_amplitude(t, y, w.sum(), got) >= _hann_dtft_amplitude(t, y, w.sum(), ref) * (1 - 1e-12)
    # a line above the bracket: |Y| rises to b
    t = np.arange(2000) * 1e-4
    y = np.sin(2 * np.pi * 100.0 * t) * np.hanning(2000)
    assert refine_peak(t, y, 90.0, 95.0) == 95.0
    assert refine_peak(t, y, 105.0, 110.0) == 105.0
