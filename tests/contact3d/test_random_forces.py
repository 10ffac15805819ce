"""Random gears at contact3d checked beyond ratio and F_t (issue 31): the efficiency against the wedge formula at the
contacts' own radius (DIN 3975-2 with the lead angle at r_c, wormsim.physics.gear_theory.efficiency_at_radius) and the radial
force on the line of centres against F_t2 tan(alpha_n) cos(rho') / cos(gamma + rho') (radial_force_theory_n), within
3 % as the variant gears (tests/contact3d/test_variety.py). The gears: numpy's default_rng(31) drawn over the ranges
of tests/cli/test_robustness.py's property test (z1 1-4, z2 20-80, m_x 0.5-12 mm, q 6-16, alpha_n 10-25 deg, hand,
ZI / ZA), the first four; the scenario is that test's contact3d one (3000 rpm, 5 ms ramps, 0.05 s, coarse flanks,
mu 0.05, load 0.04 m_x^3 z2 N m). Measured (efficiency / at r_c, F_r,lc / theory): 0.80383 / 0.80373, 1.0010;
0.85068 / 0.85144, 1.0196; 0.73648 / 0.73655, 1.0119. Long tests (four contact3d runs, ~10 s each)."""

from __future__ import annotations

import numpy as np
import pytest

from meshgen.geometry import derive
from wormsim.physics import gear_theory as gt
from wormsim.run import simulate
from wormsim.scenario import Scenario


def _draw(n: int) -> list[dict]:
    rng = np.random.default_rng(31)
    out = []
    for _ in range(n):
        out.append(
            {
                "worm_starts": int(rng.integers(1, 5)),
                "wheel_teeth": int(rng.integers(20, 81)),
                "axial_module_mm": round(float(rng.uniform(0.5, 12)), 2),
                "diameter_quotient": round(float(rng.uniform(6, 16)), 2),
                "normal_pressure_angle_deg": round(float(rng.uniform(10, 25)), 1),
                "hand": str(rng.choice(["right", "left"])),
                "profile": str(rng.choice(["ZI", "ZA"])),
            }
        )
    return out


GEARS = _draw(3)  # the 4th draw (3/26, m_x 3.78, q 9.02, alpha_n 10.3 deg, ZA) is refused as undercut (exit 2)
# hypothesis's shrunk case of the property test with these checks added: a steep (gamma 33.7 deg), low pressure angle
STEEP = {
    "worm_starts": 4,
    "wheel_teeth": 38,
    "axial_module_mm": 1.0,
    "diameter_quotient": 6.0,
    "normal_pressure_angle_deg": 10.0,
    "hand": "right",
    "profile": "ZI",
}


def _scenario(gear: dict) -> Scenario:
    m = gear["axial_module_mm"]
    return Scenario.model_validate(
        {
            "name": "random3d",
            "model": "contact3d",
            "gear": {**gear, "backlash_mm": 0.05 * m},
            "materials": {
                "worm": {"youngs_modulus_gpa": 210, "poisson_ratio": 0.3, "density_kg_m3": 7850},
                "wheel": {"youngs_modulus_gpa": 100, "poisson_ratio": 0.34, "density_kg_m3": 8800},
            },
            "contact": {"geometry": "flanks", "friction": 0.05},
            "drive": {"speed_rpm": 3000, "ramp_s": 0.005},
            "load": {"torque_nm": 0.04 * m**3 * gear["wheel_teeth"], "ramp_s": 0.005},
            "simulation": {"duration_s": 0.05, "resolution": "coarse"},
        }
    )


_RUNS: dict = {}


def _summary(gear: dict) -> dict:
    """The gear's contact3d summary, run once per test session."""
    key = tuple(sorted(gear.items()))
    if key not in _RUNS:
        _RUNS[key] = simulate(_scenario(gear)).summary
    return _RUNS[key]


@pytest.mark.parametrize(
    "gear",
    [
        *GEARS,
        pytest.param(
            STEEP,
            id="steep",
            marks=pytest.mark.xfail(
                strict=True,
                reason=(
                    "4/38, m_x 1, q 6 (gamma 33.7 deg), alpha_n 10 deg, ZI: the radial force on the line of centres is "
                    "1.427 x F_t2 tan(alpha_n) cos(rho') / cos(gamma + rho') (efficiency 0.8921 against 0.8944 at the "
                    "contact radius: within 0.3 %); the pitch-point formula does not hold for this steep, low-pressure-"
                    "angle pair's contacts (not investigated further)"
                ),
            ),
        ),
    ],
)
def test_random_gear_efficiency_at_the_contact_radius_and_radial_force_on_the_line_of_centres(gear):
    sc = _scenario(gear)
    s = _summary(gear)
    g = derive(sc.gear)
    eta_c = float(
        gt.efficiency_at_radius(
            g.gamma, g.r1, s["worm_contact_radius_mean_m"], s["friction_coefficient_mean"], g.alpha_n
        )
    )
    fr = s["radial_force_mean_n"] / s["radial_force_theory_n"]
    assert abs(s["ratio"] / s["ratio_theory"] - 1) < 1e-3
    assert abs(s["efficiency"] / eta_c - 1) < 0.03, (s["efficiency"], eta_c)
    assert abs(fr - 1) < 0.03, fr


def test_the_steep_gear_warns_that_its_radial_force_is_not_the_pitch_point_formulas():
    """Where contact3d's F_r2 contradicts DIN 3975-2's pitch-point formula (the steep gear, 1.427 x), the run says so
    (wormsim.results.run_warnings.theory_warnings), and none of its other means does."""
    s = _summary(STEEP)
    fr = s["radial_force_mean_n"] / s["radial_force_theory_n"]
    ws = [w for w in s["warnings"] if "x the hand formula's" in w]
    assert abs(fr - 1) > 0.10 and len(ws) == 1 and ws[0].startswith("radial force F_r2"), (fr, s["warnings"])
