"""report.png's header panel and axes (wormsim.results.report_header) and the contact pattern's band (flank_outputs):
self-locking from rho' against gamma, the shafts' powers, axes scaled to the steady window, no holes in the band."""

from __future__ import annotations

import math

import numpy as np
import pytest

from meshgen.geometry import derive
from tests.conftest import SCENARIOS
from wormsim.results import report_header as RH
from wormsim.scenario import load_scenario


@pytest.fixture(scope="module")
def seat_geo():
    return derive(load_scenario(SCENARIOS / "seat_motor.yaml").gear)


def test_self_locking_from_the_friction_angle(seat_geo):
    """Seat gear (gamma 4.79 deg, alpha_n 10 deg): rho' = atan(mu / cos alpha_n) (DIN 3975-2) is 5.80 deg at
    mu 0.1 (locks) and 2.91 deg at mu 0.05 (does not); the boundary mu = tan(4.79 deg) cos(10 deg) = 0.0825."""
    locks = RH.self_locking_text({"friction_coefficient_mean": 0.1}, seat_geo)
    runs = RH.self_locking_text({"friction_coefficient_mean": 0.05}, seat_geo)
    assert locks.startswith("self-locking: yes") and "5.8 deg >= gamma 4.79 deg" in locks
    assert runs.startswith("self-locking: no") and "2.91 deg < gamma" in runs
    assert RH.self_locking_text({"friction_coefficient_mean": 0.0826}, seat_geo).startswith("self-locking: yes")
    assert RH.self_locking_text({"friction_coefficient_mean": 0.0824}, seat_geo).startswith("self-locking: no")
    # a level's own self_locking key wins over the estimate
    assert RH.self_locking_text({"self_locking": False, "friction_coefficient_mean": 0.1}, seat_geo) == (
        "self-locking: no"
    )


def test_shafts_line_names_the_input_power():
    """P = T n 2 pi / 60: 1 N m at 1800 rpm is 188.5 W; the input is the shaft with the larger power."""
    line = RH.shafts_line(
        {"worm_speed_mean_rpm": 1800.0, "worm_torque_mean_nm": 1.0, "wheel_speed_mean_rpm": 36.0,
         "wheel_torque_mean_nm": 30.0}
    )  # fmt: skip
    assert "input power 188.5 W (worm)" in line and "113.1 W" in line  # 30 N m at 36 rpm
    assert RH.shafts_line({"worm_speed_mean_rpm": 1800.0}) == ""  # keys missing: no line, no error


def test_gear_and_results_lines(seat_geo):
    g = RH.gear_line(seat_geo)
    for part in (f"d1 {seat_geo.d1 * 1e3:.4g} mm", f"d2 {seat_geo.d2 * 1e3:.4g} mm", f"a {seat_geo.a * 1e3:.4g} mm"):
        assert part in g
    assert "gamma 4.79 deg" in g and "z1/z2 1/53" in g
    r = RH.results_line(
        {"ratio": 53.0001, "ratio_theory": 53.0, "efficiency": 0.6129, "efficiency_theory": 0.62,
         "tangential_force_mean_n": 1289.17, "friction_coefficient_mean": 0.05, "tangential_force_theory_n": math.nan},
        seat_geo,
    )  # fmt: skip
    assert "ratio 53 (theory 53)" in r and "efficiency 0.613 (theory 0.620)" in r and "self-locking: no" in r
    assert "F_t 1289.2 N" in r and "T2 / r2" not in r  # a NaN theory is left out


def test_axes_scaled_to_the_steady_window():
    """The issue's case: 100 rpm steady after a start-up overshoot to 160 rpm reads on a 0-115 rpm axis; a start-up
    force spike 30x the steady force is left off the force axis."""
    t = np.linspace(0.0, 1.0, 1001)
    speed = np.where(t < 0.1, 160.0 * t / 0.1, 100.0)
    lo, hi = RH.speed_ylim(t, [speed], (0.2, 1.0))
    # speed_ylim's margin 0.15 over the steady 100 rpm: 0 to 115 rpm (the function's documented rule)
    assert lo == 0.0 and hi == pytest.approx(115.0)
    force = 400.0 + 5.0 * np.sin(2 * np.pi * 22 * t)
    force[20] = 12_000.0
    lo, hi = RH.steady_ylim(t, [force], (0.2, 1.0))
    assert 390.0 < lo < 395.0 and 405.0 < hi < 410.0  # 400 +- 5 N with a quarter of its span each side
    lo, hi = RH.steady_ylim(t, [force, -force / 3], (0.2, 1.0))
    assert -275 < lo < -265 and 535 < hi < 545  # -135..405 N, padded by a quarter of the span (540 N)


def test_pattern_band_has_no_holes(seat_geo):
    """Cells inside a slice's loaded range that the sampled contact lines missed are drawn (pressure interpolated
    along the slice): a band with a missing row is drawn whole, and no cell outside the loaded range is added."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.collections import PolyCollection

    from wormsim.tooth.hertz import draw_pattern

    ns, nc = 8, 20
    zeta = (np.arange(ns) + 0.5) / ns * seat_geo.face_width - seat_geo.face_width / 2
    rho = np.tile(np.linspace(seat_geo.r_f2, seat_geo.r_a2, nc), (ns, 1))
    load = np.zeros((2, ns, nc))
    load[0, :, 5:15] = 1.0
    load[0, :, 9] = 0.0  # a row of cells the sampled lines missed: a white stripe before
    p = np.where(load > 0, 3e8, 0.0)
    grid = {"load": load, "pressure_max_pa": p, "rho_m": rho, "zeta_m": zeta, "slice_width_m": seat_geo.face_width / ns}
    fig, ax = plt.subplots()
    draw_pattern(ax, fig, grid, seat_geo, {"contact_pressure_max_mpa": 300.0, "contact_pressure_mean_mpa": 300.0})
    (pc,) = [c for c in ax.collections if isinstance(c, PolyCollection)]
    assert len(pc.get_array()) == ns * 10  # cells 5..14 of every slice, the missed row 9 included
    # the 3e8 Pa of the synthetic grid above, in MPa
    assert np.allclose(pc.get_array(), 300.0)
    plt.close(fig)
