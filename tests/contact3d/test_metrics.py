"""contact3d's summary pieces (wormsim.contact3d.metrics) on hand-made series: DIN 3975's headline forces beside the
resultant's components, the start-up peak against the steady window, the contact radius's efficiency."""

from __future__ import annotations

import math
from types import SimpleNamespace

import numpy as np
import pytest

from wormsim.contact3d.metrics import contact_radius_check, din_forces, startup_peak

GEO = SimpleNamespace(alpha_n=math.radians(20), gamma_m=math.radians(5.71), r_m1=0.02, r2=0.08)


def _series(n=100):
    t = np.linspace(0.0, 0.1, n)
    return {
        "t_s": t,
        "tangential_force_n": np.full(n, -1000.0),
        "radial_force_n": np.full(n, 320.0),
        "axial_force_n": np.full(n, -140.0),
        "friction_coefficient": np.full(n, 0.05),
        "radial_force_line_of_centres_n": np.full(n, 370.0),
        "tangential_force_abs_max_n": np.r_[np.full(10, 5000.0), np.full(n - 10, 1100.0)],
        "max_penetration_m": np.r_[np.full(10, 3e-5), np.full(n - 10, 1e-5)],
    }


def test_din_forces_are_the_headline_and_the_resultant_its_own_keys():
    S, sl = _series(), slice(20, 100)
    out = din_forces(S, "worm", GEO, sl, worm_torque_mean_nm=2.4)
    rho = math.atan(0.05 / math.cos(GEO.alpha_n))
    # DIN 3975-2: F_r2 = F_t2 tan(alpha_n) cos(rho') / cos(gamma + rho'), worm driving
    fr = 1000.0 * math.tan(GEO.alpha_n) * math.cos(rho) / math.cos(GEO.gamma_m + rho)
    assert out["radial_force_theory_n"] == pytest.approx(fr, rel=1e-12)
    assert out["axial_force_mean_n"] == pytest.approx(2.4 / 0.02)  # F_a2 = F_t1 = T1 / r1
    assert out["radial_force_mean_n"] == 370.0  # on the line of centres
    assert out["radial_force_resultant_mean_n"] == 320.0 and out["axial_force_resultant_mean_n"] == 140.0
    back = din_forces(S, "wheel", GEO, sl, worm_torque_mean_nm=2.4)
    assert back["radial_force_theory_n"] == pytest.approx(
        1000.0 * math.tan(GEO.alpha_n) * math.cos(rho) / math.cos(GEO.gamma_m - rho), rel=1e-12
    )
    assert din_forces(S, "worm", GEO, slice(0, 0), 2.4) == {}


def test_startup_peak_is_before_the_window_and_the_steady_max_inside_it():
    S = _series()
    out = startup_peak(S, 20, 100)
    assert out["startup_time_s"] == S["t_s"][20]
    assert out["startup_tangential_force_peak_n"] == 5000.0 and out["tangential_force_max_n"] == 1100.0
    assert out["startup_penetration_max_um"] == pytest.approx(30.0)
    assert startup_peak(S, 0, 100)["startup_tangential_force_peak_n"] == 0.0


def test_contact_radius_check_takes_the_window_and_skips_empty_samples():
    S = {
        "worm_contact_radius_m": np.array([np.nan, 0.021, 0.023, np.nan]),
        "efficiency_theory_at_contact_radius": np.array([np.nan, 0.60, 0.62, np.nan]),
    }
    out = contact_radius_check(S, slice(0, 4))
    assert out["worm_contact_radius_mean_m"] == pytest.approx(0.022)
    assert out["efficiency_theory_at_contact_radius"] == pytest.approx(0.61)
    assert math.isnan(contact_radius_check(S, slice(0, 1))["worm_contact_radius_mean_m"])
    assert contact_radius_check({}, slice(0, 4)) == {}
