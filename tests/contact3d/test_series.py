"""The run's time-series layout (wormsim.contact3d.series): one step's sums and one sample's column, checked by hand
against the sensor layout the compiled loop hands them (found, F (3), torque about the point (3), point (3))."""

from __future__ import annotations

import numpy as np
import pytest

from wormsim.contact3d.series import N_SUMS, SERIES, SUMS, ZERO_SUMS, add_step, column


def _sensor(found, f, tau, p):
    return np.array([found, *f, *tau, *p], dtype=float)


def test_sums_over_an_interval_are_the_column_means():
    act = np.array([0.0, 2.0, -30.0])  # worm actuator 1, wheel actuator 2
    steps = [
        (_sensor(3, (100.0, -20.0, 5.0), (0.0, 0.0, 0.5), (0.0, -0.1, 0.0)), 10.0, -0.5),
        (_sensor(2, (-140.0, -10.0, 7.0), (0.0, 0.0, 0.1), (0.01, -0.1, 0.0)), 12.0, -0.6),
    ]
    sums = ZERO_SUMS
    for sd, w1, w2 in steps:
        sums = add_step(sums, act, sd, 1, 2, 0, w1, w2)
    assert len(sums) == N_SUMS == len(SUMS)
    col = column((0.1, 1.0, 2.0, 10.0, -0.5, 0.7), sums, 2, (2, 1e-6, 0.05, 1e-5, 33.0, 0.012), np.pi / 30)
    row = dict(zip(SERIES, col))
    assert len(col) == len(SERIES)
    assert row["worm_torque_nm"] == pytest.approx(2.0) and row["wheel_torque_nm"] == pytest.approx(-30.0)
    assert row["worm_power_w"] == pytest.approx(2.0 * 11.0)  # T1 times the mean of the speeds read before each step
    assert row["tangential_force_n"] == pytest.approx(-20.0)  # (100 - 140) / 2
    assert row["radial_force_n"] == pytest.approx(15.0)  # e_r = -y
    assert row["axial_force_n"] == pytest.approx(6.0)
    assert row["contacts"] == pytest.approx(2.5)
    assert row["tangential_force_abs_max_n"] == pytest.approx(140.0)  # the peak, not a mean
    # M_z = tau_z + p_x F_y - p_y F_x, per step, then the mean
    mz = ((0.5 + 0.0 * -20.0 - (-0.1) * 100.0) + (0.1 + 0.01 * -10.0 - (-0.1) * -140.0)) / 2
    assert row["wheel_contact_torque_nm"] == pytest.approx(mz)
    assert row["worm_speed_rpm"] == pytest.approx(10.0 * 30 / np.pi)
    assert row["efficiency_theory_at_contact_radius"] == 0.0  # filled after the run
