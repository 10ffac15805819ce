"""Issue 12: a wheel runout modulates the loaded mesh at the wheel's rotation frequency, which shows as sidebands
f_mesh +- f_wheel in the spectrum of the tangential force (contact3d, exact flanks). One wheel revolution of the
screw jack costs 45-70 s here, so this test is in the long set (tests/conftest.py LONG_TESTS). Measured numbers:
docs/errors.md section 6."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from wormsim.contact3d.runner import simulate
from wormsim.scenario import load_scenario

SCEN = Path(__file__).resolve().parents[2] / "scenarios"


def test_wheel_runout_gives_f_t_sidebands_at_f_mesh_plus_minus_f_wheel():
    sc = load_scenario(
        SCEN / "screw_jack.yaml",
        [
            "contact.geometry=flanks",
            "simulation.resolution=coarse",
            "simulation.duration_s=1.3",
            "errors.wheel_runout_mm=0.02",
        ],
    )
    res = simulate(sc)
    t, ft = res.series["t_s"], res.series["tangential_force_n"]
    z1, z2 = sc.gear.worm_starts, sc.gear.wheel_teeth
    t_wheel = 60.0 / (sc.drive.speed_rpm * z1 / z2)  # one wheel revolution: FFT bins are wheel orders
    assert t[-1] - t_wheel > 0.1  # after the 0.05 s ramps
    n = 64 * z2
    tt = t[-1] - t_wheel + np.arange(n) * t_wheel / n
    f = np.interp(tt, t, ft)
    f = f - np.polyval(np.polyfit(tt, f, 1), tt)  # linear trend removed, rectangular window
    amp = np.abs(np.fft.rfft(f)) * 2 / n
    mesh = z2 * z1  # order of the mesh frequency
    background = np.median(amp[3:60])
    lo, line, hi = amp[mesh - 1], amp[mesh], amp[mesh + 1]
    # measured (N, main of 2026-11-23): orders 22-26: 0.037, 0.244, 0.041, 0.265, 0.028; background (median,
    # orders 3-60) 0.041 (docs/errors.md section 6)
    assert lo > 4 * background and hi > 4 * background, (amp[20:28], background)
    assert lo > 3 * line and hi > 3 * line  # the modulation's lines, above the mesh line itself
    assert lo > 4 * amp[mesh - 2] and hi > 4 * amp[mesh + 2]  # f_mesh +- 2 f_wheel not lifted alike
    assert 0.5 < lo / hi < 2
