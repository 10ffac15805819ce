"""A valve with no load (issue 10): the wedge model must run to the motor's synchronous speed, not chatter."""

from __future__ import annotations

import math

import numpy as np
import pytest

from tests.conftest import SCENARIOS
from wormsim.scenario import load_scenario
from wormsim.wedge.dynamics import REGIME_CODE, UNLOADED, simulate


@pytest.mark.parametrize(
    "overrides", [["wedge.load.force_n=0"], ["wedge.load.start_s=1000"], ["wedge.load.force_n=0", "wedge.monitor=seed"]]
)
def test_no_load_runs_to_synchronous_speed(overrides):
    sc = load_scenario(SCENARIOS / "mov_1.yaml", overrides)
    res = simulate(sc)
    sm, s = res.summary, res.series
    v0 = sc.wedge.motor.synchronous_speed_m_s
    # the integrator reaches V0 within rounding and may cross phi = 0 there: then the hold takes over (was: chatter)
    assert sm["regimes"] in (["tractive"], ["tractive", UNLOADED])
    # F1(V0) = 0 and no load: the equilibrium is V0 exactly, both face forces zero
    assert sm["speed_steady_m_s"] == pytest.approx(v0, rel=1e-6)
    assert abs(sm["S1_steady_n"]) < 1e-6 and abs(sm["S2_steady_n"]) < 1e-6
    held = s["regime_code"] == REGIME_CODE[UNLOADED]
    assert np.all(s["a1_m_s2"][held] == 0.0) and np.all(s["v1_m_s"][held] == s["v1_m_s"][-1])
    # before the hold the run-up is the tractive solution, whose speed only approaches V0 from below
    assert np.all(s["v1_m_s"] <= v0 * (1 + 1e-9))
    assert res.steps < 1000  # was: > 20000 regime changes, exit 3


def test_load_after_unloaded_hold_is_carried():
    """A load that starts after the motor reached V0 unloaded leaves the hold: tractive again, S2 -> F2."""
    sc = load_scenario(SCENARIOS / "mov_1.yaml", ["wedge.load.start_s=0.15", "simulation.duration_s=0.4"])
    sm = simulate(sc).summary
    assert sm["regimes"] in (["tractive"], ["tractive", UNLOADED, "tractive"])
    # F2 = -5000 N of scenarios/mov_1.yaml (seed 000 test case 1); S1 = |F2| tan(g + rho) (static wedge, seed 000)
    assert sm["S2_steady_n"] == pytest.approx(-5000.0, rel=1e-3)
    g = math.radians(sc.wedge.lead_angle_deg)
    assert sm["S1_steady_n"] == pytest.approx(5000.0 * math.tan(g + math.radians(sm["rho_steady_deg"])), rel=2e-3)


def test_no_load_from_above_synchronous_speed():
    """Started above V0 (generator side) with no load: inverse down to V0, then the hold, across the (empty) ramp."""
    sc = load_scenario(SCENARIOS / "mov_1.yaml", ["wedge.load.force_n=0", "wedge.initial_speed_m_s=9"])
    sm = simulate(sc).summary
    assert sm["regimes"] in (["inverse"], ["inverse", UNLOADED])
    assert sm["speed_steady_m_s"] == pytest.approx(sc.wedge.motor.synchronous_speed_m_s, rel=1e-6)
    assert sm["min_speed_m_s"] >= sc.wedge.motor.synchronous_speed_m_s * (1 - 1e-9)
