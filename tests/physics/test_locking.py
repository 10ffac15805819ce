"""Self-locking is a result, not a failure (wormsim.physics.locking; issue 31): a speed-driven wheel against a pair that
self-locks at standstill stalls, the mesh holds, and the run says so with status ok and exit 0: `locked` true, the
holding torque and the worm's creep speed, at torsional and contact3d. No message blames the contact stiffness.

The gear: the seat motor demo's (gamma 4.79 deg, alpha_n 10 deg): the pair self-locks at rest for
mu >= cos(alpha_n) tan(gamma) = 0.0825 (DIN 3975-2). mu 0.1 here: rho' = 5.80 deg > gamma."""

from __future__ import annotations

import json
import math

import pytest

from meshgen.geometry import derive
from tests.conftest import SCENARIOS
from tests.contact3d.test_guards import LOCK_DURATION, WHEEL_DRIVEN
from wormsim import cli
from wormsim.contact3d.mjcf import prepare
from wormsim.physics import gear_theory as gt
from wormsim.physics.locking import backdrive_self_locks, stall_torque_nm
from wormsim.physics.plan import gear_plan
from wormsim.run import simulate
from wormsim.scenario import load_scenario

DEMO = SCENARIOS / "seat_motor_demo.yaml"
WHEEL_RPM = 20.0
BACKDRIVE = [
    "drive.on=wheel",
    f"drive.speed_rpm={WHEEL_RPM}",
    "drive.ramp_s=0.01",
    "load.on=worm",
    "load.torque_nm=0",
    "load.ramp_s=0.01",
    "contact.friction_static=null",
    "contact.friction_dynamic=null",
]


def _run(tmp_path, model: str, mu: float, extra: list[str]) -> tuple[int, dict]:
    args = ["run", str(DEMO), "--out", str(tmp_path / model), "--no-progress", "--set", f"model={model}"]
    for kv in [*BACKDRIVE, f"contact.friction={mu}", *extra]:
        args += ["--set", kv]
    rc = cli.main(args)
    return rc, json.loads((tmp_path / model / "summary.json").read_text())


def _peak_torque_nm(sc, inertias_kg_m2: tuple[float, float]) -> float:
    """The wheel servo's peak torque by hand (gear_theory.servo_peak_torque_nm): 3 x (T_expected + J_eff 1.5 omega /
    ramp), J_eff = I2 + I1 i^2 from the level's shaft inertias."""
    g = derive(sc.gear)
    mu1 = float(sc.contact.friction)
    t_exp = gt.expected_drive_torque_of(sc.drive, sc.load, g.ratio, g.gamma, g.alpha_n, mu1)
    i1, i2 = inertias_kg_m2
    j_eff = i2 + i1 * g.ratio**2
    w = WHEEL_RPM * 2 * math.pi / 60
    return 3.0 * (t_exp + j_eff * 1.5 * w / sc.drive.ramp_s)


def test_self_locking_condition_is_din_3975s():
    """backdrive_self_locks: a speed-driven wheel with rho' = atan(mu / cos alpha_n) >= gamma; never the worm."""
    g = derive(load_scenario(DEMO).gear)
    mu_star = math.cos(g.alpha_n) * math.tan(g.gamma)  # 0.0825
    assert 0.082 < mu_star < 0.083
    for mu, locks in ((mu_star * 1.01, True), (mu_star * 0.99, False)):
        sc = load_scenario(DEMO, [*BACKDRIVE, f"contact.friction={mu}"])
        assert gear_plan(sc).backdrive_self_locks is locks
        assert backdrive_self_locks(sc.drive, g.gamma, gear_plan(sc).rho_static_rad) is locks
    assert not gear_plan(
        load_scenario(DEMO, ["contact.friction_static=0.2", "contact.friction_dynamic=0.2"])
    ).backdrive_self_locks


def test_torsional_backdrive_of_a_self_locking_pair_is_held_exit_0(tmp_path, capsys):
    """torsional, mu 0.1, the wheel at 20 rpm, the worm free, 0.1 s: exit 0 (before: exit 3 "drive locked"),
    `locked` true, the mesh held the stalled servo's peak torque (gear_theory.servo_peak_torque_nm: 3 x the rated
    torque, not kv omega_cmd = T_expected / SPEED_DROOP, 1000 x the expected) and the worm crept under 0.1 % of the
    wheel command times the ratio (1060 rpm)."""
    rc, s = _run(tmp_path, "torsional", 0.1, ["simulation.duration_s=0.1"])
    err = capsys.readouterr().err
    assert rc == 0, err
    assert s["status"] == "ok" and s["locked"] is True
    sc = load_scenario(DEMO, [*BACKDRIVE, "contact.friction=0.1"])
    peak = _peak_torque_nm(sc, (s["worm_inertia_kg_m2"], s["wheel_inertia_kg_m2"]))
    assert s["drive_peak_torque_nm"] == pytest.approx(peak, rel=1e-9)
    # below the unlimited servo's stall torque, 1000 x the expected torque (the worm's 0 N m load: the 1e-3 N m
    # floor, so 1 N m; the peak is mostly the ramp's acceleration torque)
    t_exp = s["drive_kv_nm_s"] * gt.SPEED_DROOP * WHEEL_RPM * 2 * math.pi / 60
    assert peak < stall_torque_nm(t_exp, None)
    # 2 %: the stalled servo pushes with its peak (measured: the peak to 1e-9)
    assert s["holding_torque_nm"] == pytest.approx(peak, rel=0.02)
    free = WHEEL_RPM * s["ratio_theory"]
    assert s["creep_speed_rpm"] < 1e-3 * free  # 0.1 %: the creep bound
    assert "stiff" not in err and "soft" not in err


def test_torsional_backdrive_below_the_boundary_runs_and_is_not_locked():
    """mu 0.07 < 0.0825: the wheel back-drives the worm (the pair is not self-locking): `locked` false, the worm
    turns at the wheel speed times the ratio (within 2 %)."""
    sc = load_scenario(DEMO, ["model=torsional", *BACKDRIVE, "contact.friction=0.07", "simulation.duration_s=0.1"])
    s = simulate(sc).summary
    assert s["locked"] is False and s["holding_torque_nm"] is None and s["creep_speed_rpm"] is None
    assert s["worm_speed_mean_rpm"] == pytest.approx(WHEEL_RPM * s["ratio_theory"], rel=0.02)


def test_contact3d_backdrive_of_a_self_locking_pair_is_held_exit_0(tmp_path, capsys):
    """contact3d (coarse), the same back-drive, 0.09 s: exit 0 with `locked` true; no "contact too soft". The held
    mesh's working torque for the friction rows' hardness is the stalled servo's peak
    (wormsim.physics.locking.stall_torque_nm): with the worm load's 0 N m (impratio 1) it crept at 65 rpm."""
    rc, s = _run(tmp_path, "contact3d", 0.1, ["simulation.duration_s=0.09", "simulation.resolution=coarse"])
    err = capsys.readouterr().err
    assert rc == 0, err
    assert s["status"] == "ok" and s["locked"] is True
    assert s["friction_impratio"] > 100
    sc = load_scenario(DEMO, [*BACKDRIVE, "contact.friction=0.1"])
    # contact3d's shaft inertias (the meshes', times simulation.mass_scaling's factor)
    ine = prepare(sc).inertias
    inertias = (
        ine.worm_inertia_kg_m2 + ine.worm_load_inertia_kg_m2,
        ine.wheel_inertia_kg_m2 + ine.wheel_load_inertia_kg_m2,
    )
    assert s["drive_peak_torque_nm"] == pytest.approx(_peak_torque_nm(sc, inertias), rel=1e-6)
    assert s["holding_torque_nm"] == pytest.approx(s["drive_peak_torque_nm"], rel=0.05)
    assert s["creep_speed_rpm"] < 1e-3 * WHEEL_RPM * s["ratio_theory"]
    assert "soft" not in err and "penetration" not in err


def test_torsional_torque_driven_wheel_held_from_rest_is_locked():
    """A torque on the wheel (2 N m over 10 ms), the worm free, mu 0.1: the pair holds from rest (the worm slides
    below contact.transition_velocity_m_s), `locked` true with the 2 N m as the holding torque; at mu 0.07 the worm
    runs back and `locked` is false."""
    base = [
        "model=torsional",
        "drive.on=wheel",
        "drive.speed_rpm=null",
        "drive.torque_nm=2.0",
        "drive.ramp_s=0.01",
        "load.on=worm",
        "load.torque_nm=0",
        "load.ramp_s=0",
        "contact.friction_static=null",
        "contact.friction_dynamic=null",
        "simulation.duration_s=0.1",
    ]
    held = simulate(load_scenario(DEMO, [*base, "contact.friction=0.1"])).summary
    assert held["locked"] is True and held["holding_torque_nm"] == 2.0
    assert held["creep_speed_rpm"] < 1.0
    runs = simulate(load_scenario(DEMO, [*base, "contact.friction=0.07"])).summary
    assert runs["locked"] is False and runs["creep_speed_rpm"] is None


JACK = SCENARIOS / "screw_jack.yaml"
JACK_RPM = 55.0  # the wheel's command in tests/contact3d/test_guards.py's WHEEL_DRIVEN
# the held back-drive of tests/contact3d/test_guards.py (its contact3d runs) at torsional
JACK_BACKDRIVE = ["model=torsional", *WHEEL_DRIVEN, "contact.friction=0.2", LOCK_DURATION]


def test_torsional_backdrive_of_the_screw_jack_is_held_exit_0(tmp_path, capsys):
    """The screw jack (gamma 5.71 deg, mu 0.2: rho' 12.0 deg) back-driven by its wheel at 55 rpm, torsional at the
    default timestep (5e-4 s): exit 0 (before: exit 3, the implicit step's Newton iteration cycled between the two
    saturated sides of the friction direction's tanh at t = 2.76 ms, down to 4.9e-7 s), `locked` true, the mesh
    holds the stalled servo's peak torque and the worm creeps under 0.1 % of 55 rpm x 24 (measured: 0.0386 rpm,
    0.0029 %); a fixed 1e-5 s step, where the plain iteration converges, gives the same creep and holding torque."""
    args = ["run", str(JACK), "--out", str(tmp_path / "jack"), "--no-progress"]
    for kv in JACK_BACKDRIVE:
        args += ["--set", kv]
    rc = cli.main(args)
    err = capsys.readouterr().err
    assert rc == 0, err
    s = json.loads((tmp_path / "jack" / "summary.json").read_text())
    assert s["status"] == "ok" and s["locked"] is True
    assert s["holding_torque_nm"] == pytest.approx(s["drive_peak_torque_nm"], rel=0.02)
    assert s["creep_speed_rpm"] < 1e-3 * JACK_RPM * s["ratio_theory"]
    fine = simulate(load_scenario(JACK, [*JACK_BACKDRIVE, "simulation.timestep_s=1e-5"])).summary
    assert fine["locked"] is True
    assert s["holding_torque_nm"] == pytest.approx(fine["holding_torque_nm"], rel=1e-3)
    assert s["creep_speed_rpm"] == pytest.approx(fine["creep_speed_rpm"], rel=0.01)
