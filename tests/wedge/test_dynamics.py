"""Two-sided wedge model (seed 000) against closed forms; regimes, lock, seed monitor, scenarios.

Closed forms used (docs/wedge.md derives them):
  steady sliding (x1'' = 0):  F1(v) = F2 psi_k(rho(v)),  psi1 = -tan(g + rho), psi2 = -tan(g - rho)
  Kloss motor:                F1(v) = 2 Fmax V / (1 + V^2),  V = (V0 - v) / (V0 - Vmax)
  efficiencies:               eta = tan g / tan(g + rho),  mu = tan(g - rho) / tan g
  standstill holds while      tan(g - rho0) <= F1 / |F2| <= tan(g + rho0)   (F2 < 0)
"""

import json
import math

import numpy as np
import pytest
from scipy.optimize import brentq

from tests.conftest import ROOT
from wormsim.exceptions import SimulationError
from wormsim.results.recording import recorded_entities
from wormsim.run import run_scenario
from wormsim.scenario import load_scenario, scenario_from_dict
from wormsim.wedge import dynamics as wedge

MOV = sorted((ROOT / "scenarios").glob("mov_*.yaml"))
G = 4.76 * math.pi / 180  # seed 000's lead angle
F1_REST = 2 * 2178 * (7.85 / 1.35) / (1 + (7.85 / 1.35) ** 2)  # Kloss at v = 0: 727.6 N


def run_wedge(duration_s=0.3, **wedge_block):
    sc = scenario_from_dict(
        {"name": "t", "model": "wedge", "wedge": wedge_block, "simulation": {"duration_s": duration_s}}
    )
    return wedge.simulate(sc)


def params(res):
    return res.extra["params"]


def sliding(res, code):
    """Samples sliding in regime `code` where S1/S2 is defined (not at the N = 0 switch itself)."""
    s = res.series
    return (s["regime_code"] == code) & (np.abs(s["v1_m_s"]) > 1e-3) & (np.abs(s["S2_n"]) > 1.0)


def test_motor_force_at_rest_is_the_kloss_value():
    p = wedge.params_from_scenario(load_scenario(ROOT / "scenarios" / "mov_1.yaml"))
    # Kloss (seed 000): F = 2 F_k / (s / s_k + s_k / s), slip s = 1 at rest, s_k = (7.85 - 6.5) / 7.85 = 0.17197:
    # 2 x 2178 / (1 / 0.17197 + 0.17197) = 727.6 N
    assert wedge.motor_force_n(0.0, p) == pytest.approx(727.6, abs=0.1)
    # F_k = 2178 N at Vmax 6.5 m/s, synchronous 7.85 m/s: the Kloss parameters of scenarios/mov_1.yaml (seed 000)
    assert wedge.motor_force_n(6.5, p) == pytest.approx(2178.0, rel=1e-12)  # peak at Vmax
    assert wedge.motor_force_n(7.85, p) == 0.0  # synchronous speed
    assert wedge.motor_force_n(8.0, p) < 0  # generator above it


# ----------------------------------------------------------------------------- steady states


def test_tractive_steady_state_matches_psi1_and_motor_curve():
    F2 = -10000.0
    res = run_wedge(load={"force_n": F2, "start_s": 0.1, "ramp_s": 0.02})
    p, s = params(res), res.series
    assert res.summary["regimes"] == ["tractive"]

    def f(v):
        return wedge.motor_force_n(v, p) - math.tan(G + wedge.rho_of_speed(v, p)) * abs(F2)

    v_ss = brentq(f, 6.5, 7.85, xtol=1e-13)
    assert s["v1_m_s"][-1] == pytest.approx(v_ss, rel=1e-7)
    assert res.summary["speed_steady_m_s"] == pytest.approx(v_ss, rel=1e-6)
    assert res.summary["S1_steady_n"] == pytest.approx(wedge.motor_force_n(v_ss, p), rel=1e-6)
    assert res.summary["S2_steady_n"] == pytest.approx(F2, rel=1e-6)
    # S1 = psi1 S2 at every sliding sample (seed 000: S2 = S1 / psi)
    m = sliding(res, 1)
    psi1 = -np.tan(G + np.radians(s["rho_deg"][m]))
    np.testing.assert_allclose(s["S1_n"][m] / s["S2_n"][m], psi1, rtol=1e-9)


def test_inverse_steady_state_matches_psi2_and_motor_curve():
    # an overhauling load (F2 > 0) drives the pair forward; rho = atan(0.05) = 2.86 deg < gamma
    F2 = 5000.0
    res = run_wedge(
        duration_s=0.4, friction=0.05, load={"initial_force_n": -5000.0, "force_n": F2, "start_s": 0.1, "ramp_s": 0.1}
    )
    p, s = params(res), res.series
    assert res.summary["regimes"] == ["tractive", "inverse"]
    rho = math.atan(0.05)

    def f(v):  # motor brakes as a generator: F1 = psi2 F2 = -tan(g - rho) F2 < 0
        return wedge.motor_force_n(v, p) + math.tan(G - rho) * F2

    v_ss = brentq(f, 7.85, 9.0, xtol=1e-13)
    assert s["v1_m_s"][-1] == pytest.approx(v_ss, rel=1e-7)
    assert res.summary["S1_steady_n"] == pytest.approx(-math.tan(G - rho) * F2, rel=1e-6)
    m = sliding(res, 2)
    np.testing.assert_allclose(s["S1_n"][m] / s["S2_n"][m], -math.tan(G - rho), rtol=1e-9)
    assert np.all(s["S1_n"][m & (s["t_s"] > 0.25)] < 0) and np.all(s["S2_n"][m & (s["t_s"] > 0.25)] > 0)


def test_locked_steady_state_from_rest_under_full_load():
    res = wedge.simulate(load_scenario(ROOT / "scenarios" / "mov_1_from_rest.yaml"))
    s, sm = res.series, res.summary
    assert sm["regimes"] == ["locked"] and sm["stalled"] and sm["self_locking"]
    assert np.all(s["v1_m_s"] == 0) and np.all(s["x1_m"] == 0)
    np.testing.assert_allclose(s["S1_n"], F1_REST, rtol=1e-12)
    # F2 = -5000 N of scenarios/mov_1_from_rest.yaml (seed 000 test case 1); S1 = F1(0), the Kloss force at rest
    np.testing.assert_allclose(s["S2_n"], -5000.0, rtol=1e-12)
    # why it locks: the motor's starting force is below the tractive breakaway force
    assert F1_REST < math.tan(G + math.radians(1 / 0.088)) * 5000


# ----------------------------------------------------------------------------- efficiencies


def test_efficiency_forward_is_power_ratio_and_closed_form():
    res = run_wedge(load={"force_n": -10000.0, "start_s": 0.1, "ramp_s": 0.02})
    s, sm = res.series, res.summary
    rho = math.radians(sm["rho_steady_deg"])
    p_in = s["S1_n"][-1] * s["v1_m_s"][-1]
    p_out = -s["S2_n"][-1] * s["v2_m_s"][-1]
    assert p_out / p_in == pytest.approx(math.tan(G) / math.tan(G + rho), rel=1e-6)
    assert sm["efficiency_forward"] == pytest.approx(math.tan(G) / math.tan(G + rho), rel=1e-12)
    # group III self-locks at standstill (rho(0) = 11.4 deg > gamma): no back-driving from rest (INTERFACE.md),
    # while a pair already sliding at the steady speed back-drives with tan(g - rho) / tan g
    assert sm["self_locking"] and sm["efficiency_backward"] == 0.0
    assert sm["efficiency_backward_sliding"] == pytest.approx(math.tan(G - rho) / math.tan(G), rel=1e-12)


def test_efficiency_backward_is_power_ratio_and_closed_form():
    res = run_wedge(
        duration_s=0.4,
        friction=0.05,
        load={"initial_force_n": -5000.0, "force_n": 5000.0, "start_s": 0.1, "ramp_s": 0.1},
    )
    s, sm = res.series, res.summary
    rho = math.atan(0.05)
    p_in = s["S2_n"][-1] * s["v2_m_s"][-1]  # the load drives
    p_out = -s["S1_n"][-1] * s["v1_m_s"][-1]  # the motor absorbs
    assert p_out / p_in == pytest.approx(math.tan(G - rho) / math.tan(G), rel=1e-6)
    assert sm["efficiency_backward"] == pytest.approx(math.tan(G - rho) / math.tan(G), rel=1e-12)


def test_efficiency_backward_is_zero_when_self_locking():
    e = wedge.efficiencies(G, G + 0.01)
    assert e["efficiency_backward"] == 0.0
    assert e["efficiency_self_locking"] == pytest.approx(math.tan(0.01) / math.tan(G))


# ----------------------------------------------------------------------------- lock boundary


@pytest.mark.parametrize("delta_deg, locks", [(+1e-6, True), (-1e-6, False)])
def test_stick_without_motor_exactly_when_rho0_exceeds_gamma(delta_deg, locks):
    # F1 = 0: N0 = -F2 cos g, T0 = -F2 sin g: holds iff tan(rho0) >= tan(g)
    rho0 = G + math.radians(delta_deg)
    assert bool(wedge.stick_margin(0.0, -5000.0, G, rho0) >= 0) is locks


@pytest.mark.parametrize("delta_deg, locks", [(+0.05, True), (-0.05, False)])
def test_self_locking_exactly_when_rho0_exceeds_gamma(delta_deg, locks):
    # a load so large that the motor's 728 N starting force is negligible (F1/|F2| = 1.5e-4 = tan 0.008 deg)
    mu = math.tan(G + math.radians(delta_deg))
    res = run_wedge(duration_s=0.05, friction=mu, driven_mass_kg=1000.0, load={"force_n": -5e6})
    sm = res.summary
    assert sm["self_locking"] is locks
    if locks:
        assert sm["regimes"] == ["locked"] and sm["stalled"]
    else:  # the load back-drives the worm
        assert sm["regimes"] == ["inverse"] and not sm["stalled"] and sm["min_speed_m_s"] < 0


@pytest.mark.parametrize("factor, backdrives", [(1.01, True), (0.99, False)])
def test_back_driving_just_above_and_below_the_lock_boundary(factor, backdrives):
    # rho = atan(0.05) < gamma: at rest the motor's F1(0) holds the load while F1/|F2| >= tan(g - rho)
    F_limit = F1_REST / math.tan(G - math.atan(0.05))  # 21 968 N
    res = run_wedge(duration_s=0.05, friction=0.05, load={"force_n": -factor * F_limit})
    sm = res.summary
    assert not sm["self_locking"]
    if backdrives:
        assert sm["regimes"] == ["inverse"] and sm["x1_end_m"] < 0
    else:
        assert sm["regimes"] == ["locked"] and sm["stalled"]


# ----------------------------------------------------------------------------- regime timelines


def test_load_reversal_timeline_tractive_locked_inverse():
    # the valve thrust grows past what the motor can carry (stall), the pair stops and holds, then the
    # load grows past the static limit and back-drives the worm: power flow reversed
    res = run_wedge(duration_s=1.2, friction=0.05, load={"force_n": -25000.0, "start_s": 0.1, "ramp_s": 1.0})
    p, s, sm = params(res), res.series, res.summary
    assert sm["regimes"] == ["tractive", "locked", "inverse"]
    t_lock, t_break = sm["regime_timeline"][1]["start_s"], sm["regime_timeline"][1]["end_s"]
    # breakaway where the static limit is reached: F1(0) / |F2| = tan(g - rho)
    assert -wedge.load_force_n(t_break, p) == pytest.approx(F1_REST / math.tan(G - math.atan(0.05)), rel=1e-9)
    # the stop happened before that, with the drive stalled beyond its peak force: |F2| tan(g + rho) > Fmax
    # 2178 N: the Kloss peak force F_k of the motor (seed 000, scenarios/mov_1.yaml)
    assert -wedge.load_force_n(t_lock, p) * math.tan(G + math.atan(0.05)) > 2178
    assert s["v1_m_s"][-1] < 0 and np.all(s["v1_m_s"][s["regime_code"] == 0] == 0)


def test_sign_reversal_while_moving_switches_tractive_to_inverse_at_phi_zero():
    res = run_wedge(
        duration_s=0.4,
        friction=0.05,
        load={"initial_force_n": -5000.0, "force_n": 5000.0, "start_s": 0.1, "ramp_s": 0.1},
    )
    p, sm = params(res), res.summary
    assert sm["regimes"] == ["tractive", "inverse"] and sm["min_speed_m_s"] >= 0
    t_sw = sm["regime_timeline"][1]["start_s"]
    v_sw = float(np.interp(t_sw, res.series["t_s"], res.series["v1_m_s"]))
    # seed 000's switching function phi = F1/m1 - F2/(m2 tan g) vanishes at the switch (N = 0)
    phi = wedge.motor_force_n(v_sw, p) / p.m1_kg - wedge.load_force_n(t_sw, p) / (p.m2_kg * math.tan(G))
    assert abs(phi) < 1e-3 * wedge.motor_force_n(v_sw, p) / p.m1_kg


# ----------------------------------------------------------------------------- seed monitor


def test_seed_monitor_runs_the_worm_backwards_from_rest_where_three_regime_locks():
    seed = wedge.simulate(load_scenario(ROOT / "scenarios" / "mov_1_from_rest_seed_monitor.yaml"))
    ours = wedge.simulate(load_scenario(ROOT / "scenarios" / "mov_1_from_rest.yaml"))
    assert ours.summary["stalled"] and ours.summary["regimes"] == ["locked"]
    # the seed's monitor picks psi1 (phi > 0) and so x1'' = (F1 - F2 psi1)/(...) < 0 at rest: the motor,
    # pushing forward, is driven backwards, and it keeps calling that "tractive"
    a0 = seed.series["a1_m_s2"][0]
    assert a0 == pytest.approx(
        (F1_REST - 5000 * math.tan(G + math.radians(1 / 0.088)))
        / (11.8 + 100 * math.tan(G + math.radians(1 / 0.088)) * math.tan(G)),
        rel=1e-9,
    )
    assert a0 < 0 and seed.summary["min_speed_m_s"] < -1.0 and seed.summary["regimes"] == ["tractive"]


def test_seed_monitor_agrees_while_moving_forward():
    kw = dict(load={"force_n": -10000.0, "start_s": 0.1, "ramp_s": 0.02})
    a, b = run_wedge(**kw), run_wedge(monitor="seed", **kw)
    for key in ("S1_peak_n", "S2_peak_n", "speed_steady_m_s", "S1_steady_n"):
        assert b.summary[key] == pytest.approx(a.summary[key], rel=1e-6)


# ----------------------------------------------------------------------------- numerics


@pytest.mark.parametrize(
    "case",
    [
        dict(duration_s=0.3, load={"force_n": -15000.0, "start_s": 0.05, "ramp_s": 0.0}),  # stall + lock
        dict(duration_s=0.3, driven_mass_kg=200, load={"force_n": -10000.0, "start_s": 0.1, "ramp_s": 0.02}),
        dict(duration_s=1.2, friction=0.05, load={"force_n": -25000.0, "start_s": 0.1, "ramp_s": 1.0}),
    ],
)
def test_results_independent_of_solver_tolerance(case):
    coarse, fine = run_wedge(rtol=1e-6, **case), run_wedge(rtol=1e-10, **case)
    assert coarse.summary["regimes"] == fine.summary["regimes"]
    for key in ("S1_peak_n", "S2_peak_n", "S1_steady_n", "S2_steady_n", "Kd1", "Kd2"):
        assert coarse.summary[key] == pytest.approx(fine.summary[key], rel=1e-3), key
    assert coarse.summary["speed_steady_m_s"] == pytest.approx(fine.summary["speed_steady_m_s"], rel=1e-3, abs=1e-4)
    for c, f in zip(coarse.summary["regime_timeline"], fine.summary["regime_timeline"]):
        assert c["start_s"] == pytest.approx(f["start_s"], rel=1e-3, abs=1e-6)


def test_painleve_configuration_is_a_diagnosed_failure():
    # rho > gamma and m2 tan g tan(rho - g) > m1: the inverse regime's N has no consistent sign
    with pytest.raises(SimulationError, match="Painleve"):
        run_wedge(
            duration_s=0.05,
            friction=0.5,
            driving_mass_kg=1.0,
            driven_mass_kg=100.0,
            initial_speed_m_s=5.0,
            load={"force_n": 1e5},
        )


def test_kd_uses_the_rated_forces():
    res = run_wedge(load={"force_n": -10000.0, "start_s": 0.1, "ramp_s": 0.02})
    p, sm = params(res), res.summary
    rho_n = wedge.rho_of_speed(7.59, p)
    # Ft1 = nominal_force_n 990 N, Vs_n 7.59 m/s: wedge defaults (wormsim/scenario/schema.py), seed 000 MOV (M_n / R1)
    assert sm["Ft1_n"] == 990.0
    assert sm["Ft2_n"] == pytest.approx(990.0 / math.tan(G + rho_n), rel=1e-12)
    assert sm["Kd1"] == pytest.approx(abs(sm["S1_peak_n"]) / 990.0, rel=1e-12)
    assert sm["Kd2"] == pytest.approx(abs(sm["S2_peak_n"]) / sm["Ft2_n"], rel=1e-12)


# ----------------------------------------------------------------------------- scenario files

WEDGE_KEYS = {
    "speed_steady_m_s",
    "S1_peak_n",
    "S2_peak_n",
    "S1_steady_n",
    "S2_steady_n",
    "Kd1",
    "Kd2",
    "efficiency_forward",
    "efficiency_backward",
    "self_locking",
    "stalled",
    "regimes",
}


def test_the_mov_scenarios_exist():
    names = {f.stem for f in MOV}
    assert {"mov_1", "mov_2", "mov_3", "mov_4", "mov_5", "mov_1_from_rest"} <= names


def test_early_seat_stalls_and_locks_with_s1_at_the_static_wedge_limit():
    res = wedge.simulate(load_scenario(ROOT / "scenarios" / "mov_3_early_seat.yaml"))
    s, sm = res.series, res.summary
    assert sm["regimes"] == ["tractive", "locked"] and sm["locked_at_end"] and not sm["stalled"]
    t_stop = sm["regime_timeline"][1]["start_s"]
    assert sm["S1_peak_time_s"] == pytest.approx(t_stop, abs=1e-9)
    # just before the stop x1' -> 0, rho -> rho(0): S1 = psi1(rho0) S2 with S2 = F2 - m2 tan g x1''
    # m1 11.8 kg, m2 100 kg, F2 -15000 N, rho(0) = 1 / 0.088 deg (group III): scenarios/mov_3_early_seat.yaml, seed 000
    rho0 = math.radians(1 / 0.088)
    a = (F1_REST - (-15000.0) * -math.tan(G + rho0)) / (11.8 + 100 * math.tan(G + rho0) * math.tan(G))
    assert sm["S1_peak_n"] == pytest.approx(F1_REST - 11.8 * a, rel=1e-6)
    np.testing.assert_allclose(s["S1_n"][s["t_s"] > t_stop + 1e-6], F1_REST, rtol=1e-12)


@pytest.mark.parametrize("path", MOV, ids=[f.stem for f in MOV])
def test_every_mov_scenario_runs_and_writes_all_files(path, tmp_path):
    summary = run_scenario(load_scenario(path), tmp_path, progress=False)
    assert summary["status"] == "ok" and summary["model"] == "wedge"
    for name in ("summary.json", "timeseries.npz", "recording.rrd", "report.png"):
        assert (tmp_path / name).stat().st_size > 0, name
    on_disk = json.loads((tmp_path / "summary.json").read_text())
    assert WEDGE_KEYS <= set(on_disk) and on_disk["status"] == "ok"
    assert set(on_disk["regimes"]) <= {"tractive", "inverse", "locked"}
    with np.load(tmp_path / "timeseries.npz") as ts:
        assert {"t_s", "x1_m", "v1_m_s", "S1_n", "S2_n", "F1_n", "F2_n", "regime_code"} <= set(ts.files)
        # simulation.duration_s 0.3 of every scenarios/mov_*.yaml (input echoed back)
        assert ts["t_s"][-1] == pytest.approx(0.3)
    assert {"/series/S1_n", "/series/S2_n", "/series/v1_m_s"} <= recorded_entities(tmp_path / "recording.rrd")
    assert (tmp_path / "report.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
