"""contact3d's guards (wormsim.contact3d.runner): each failure mode stops the run with SimulationError (CLI exit 3,
summary.json "failed") and a diagnosis that says what to change; a valid run trips none; the timestep stability
edge (wormsim.bench.stability_edge) records the last stable timestep and classifies how the next one failed.

Runs are short (milliseconds of simulated time) on coarse collision pieces. Which guard fires for which input was
measured first (seat motor demo gear, default timestep 5e-6 s, explicit stable limit 1.61e-5 s):
  - a wheel load stepped onto the held worm: 300 N m is carried (max penetration 109 um); 700 N m trips the
    penetration guard (349 um > 0.4 m_x = 281 um) in 3 steps; 2000 N m throws the 7 g wheel past a tooth in 2 steps
    (transmission error -0.67 pitch) before any sampled penetration reaches the limit: teeth jumped.
  - timestep 2e-5 s (x4, 1.24 x the limit) and above: the transmission error runs away within a millisecond
    (1.6 to 4700 pitch); the state stays finite, MuJoCo's bad-qacc warning does not fire. This is divergence, and is
    reported so (a stiffer contact, the jump guard's other cure, would make it worse).
"""

from __future__ import annotations

import json
import math
import re

import pytest

from tests.conftest import SCENARIOS as SCEN
from wormsim import cli
from wormsim.bench.stability import FAILURE_CLASSES, classify_failure, stability_edge
from wormsim.contact3d.diagnosis import JUMP_PITCH
from wormsim.contact3d.friction_guard import friction_error
from wormsim.contact3d.mjcf import build_model
from wormsim.contact3d.runner import simulate
from wormsim.contact3d.timestep import default_timestep
from wormsim.exceptions import LockedError, SimulationError
from wormsim.physics.gear_theory import penetration_limit_m
from wormsim.scenario import load_scenario

DEMO = SCEN / "seat_motor_demo.yaml"
JACK = SCEN / "screw_jack.yaml"

# screw jack (gamma 5.71 deg, alpha_n 20 deg) with the WHEEL speed-driven at its nominal 55 rpm and a light load on
# the worm; one constant friction coefficient
WHEEL_DRIVEN = [
    "drive.on=wheel",
    "drive.speed_rpm=55",
    "drive.ramp_s=0.01",
    "load.on=worm",
    "load.torque_nm=0.1",
    "load.ramp_s=0.01",
    "contact.friction_static=null",
    "contact.friction_dynamic=null",
    "simulation.resolution=coarse",
]
# the lock guard arms 0.02 s after the ramps and fires after 0.05 s below half the command: 0.085 s covers it
LOCK_DURATION = "simulation.duration_s=0.085"


def _rho_deg(mu: float, alpha_n_deg: float) -> float:
    """Virtual friction angle rho' = atan(mu / cos alpha_n) (DIN 3975)."""
    return math.degrees(math.atan(mu / math.cos(math.radians(alpha_n_deg))))


def _held_through_the_cli(tmp_path, capsys, geometry: str) -> dict:
    """The wheel-driven screw jack at mu 0.2 through `wormsim run`: exit 0, status ok, `locked` true and no message
    about the contact; its summary."""
    out = tmp_path / "locked"
    args = ["run", str(JACK), "--out", str(out), "--no-progress"]
    for kv in WHEEL_DRIVEN + ["contact.friction=0.2", LOCK_DURATION, f"contact.geometry={geometry}"]:
        args += ["--set", kv]
    assert cli.main(args) == 0, capsys.readouterr().err
    err = capsys.readouterr().err
    summary = json.loads((out / "summary.json").read_text())
    assert summary["status"] == "ok" and summary["model"] == "contact3d" and summary["locked"] is True, err
    assert "stiffness" not in err and "soft" not in err and "penetration" not in err, err
    return summary


def test_self_locking_pair_with_speed_driven_wheel_ends_held_with_flanks(tmp_path, capsys):
    """The default geometry's held back-drive ends as a result (exit 0, locked, no contact message): the wheel's
    servo stalls at its peak torque (gear_theory.servo_peak_torque_nm) and the mesh holds it; the summary says what
    the servo pushed with (its peak, to 1e-9) and that the penetration stayed far inside its guard."""
    s = _held_through_the_cli(tmp_path, capsys, "flanks")
    assert s["holding_torque_nm"] == pytest.approx(s["drive_peak_torque_nm"], rel=1e-9)
    # the unlimited servo crushed the mesh to the penetration guard (1 mm, 0.4 m_x); held at the peak: 22 um
    assert s["max_penetration_um"] < 0.1 * 0.4 * 2.5e3, s["max_penetration_um"]


@pytest.mark.parametrize("geometry", ["flanks", "pieces"])
def test_self_locking_pair_with_speed_driven_wheel_is_held_through_the_cli(tmp_path, capsys, geometry):
    """mu = 0.2: rho' = 12.0 deg > gamma = 5.71 deg, the wheel cannot turn the worm. That is the run's result
    (wormsim.physics.locking), not a failure: exit 0, status ok, `locked` true, the holding torque the stalled servo
    pushed with (its peak torque, wormsim.physics.locking.stall_torque_nm) and a creeping worm; no message about the
    contact. For each contact.geometry. Before the servo's peak torque (decision 0053) the flanks crept at 0.71 %:
    the unlimited servo (1000 x its expected torque, 21 kN m) crushed the held mesh to 1 mm."""
    # gamma = atan(z1 / q) = atan(1 / 10) = 5.71 deg for the screw jack (scenarios/screw_jack.yaml)
    assert _rho_deg(0.2, 20.0) > 5.71
    summary = _held_through_the_cli(tmp_path, capsys, geometry)
    # the worm creeps at most 0.1 % of the wheel command (55 rpm) times the ratio (24)
    assert summary["creep_speed_rpm"] < 1e-3 * 55 * 24, summary["creep_speed_rpm"]
    assert summary["holding_torque_nm"] > 0


def test_friction_guard_names_the_lock_only_where_the_wheel_drives_a_self_locking_pair():
    """friction_error's diagnosis: LockedError naming the self-locking where the speed-driven wheel meets rho' >=
    gamma (mu 0.2); otherwise (mu 0.02, rho' < gamma) a SimulationError saying the load is beyond what the friction
    rows were sized for, with the measured cosine and force ratio."""
    for mu, locked in ((0.2, True), (0.02, False)):
        sc = load_scenario(JACK, WHEEL_DRIVEN + [f"contact.friction={mu}", LOCK_DURATION])
        bm = build_model(sc)
        err = friction_error(0.03, 0.3, 2e5, 90.0, 5.0, 100.0, bm)
        assert isinstance(err, LockedError) == locked, str(err)
        msg = str(err)
        assert "cos(f_t, -v_t) = 0.30" in msg and "2e+03 x the 100 N" in msg, msg
        if locked:
            assert msg.startswith("the drive locked") and "self-locking" in msg, msg
        else:
            assert msg.startswith("friction out of range") and "load.torque_nm" in msg, msg


def test_valid_back_driven_run_trips_no_guard():
    """The counter-case and the valid run: mu = 0.02 (rho' = 1.22 deg < gamma) lets the speed-driven wheel turn the
    worm, for as long as the lock guard watches; ratio 24 holds, penetration and transmission error stay inside
    their guards."""
    sc = load_scenario(JACK, WHEEL_DRIVEN + ["contact.friction=0.02", LOCK_DURATION])
    res = simulate(sc)
    bm = res.extra["built"]
    # LOCK_DURATION above: the run reaches its simulation.duration_s (input echoed back)
    assert res.sim_time_s == pytest.approx(0.085, abs=1e-4)
    # ratio from the shaft angles over the last 0.05 s (the summary's mean-speed ratio has about one 22 Hz mesh
    # period in so short a window)
    t = res.series["t_s"]
    i = int((t < t[-1] - 0.05).sum())
    d1 = res.series["worm_angle_rad"][-1] - res.series["worm_angle_rad"][i]
    d2 = res.series["wheel_angle_rad"][-1] - res.series["wheel_angle_rad"][i]
    # 24 = z2 / z1 of scenarios/screw_jack.yaml (kinematics)
    assert abs(d1 / d2) == pytest.approx(24.0, rel=1e-3)
    assert max(res.series["max_penetration_m"]) < penetration_limit_m(bm.geometry.m_x)
    te_pitch = abs(res.series["transmission_error_rad"]).max() / (2 * math.pi / bm.geometry.z2)
    assert te_pitch < JUMP_PITCH
    # the worm really turned at the kinematic speed after the ramp: 55 rpm (WHEEL_DRIVEN) x z2 / z1 = 24, half as bound
    assert abs(res.series["worm_speed_rpm"][-1]) > 0.5 * 55 * 24


@pytest.mark.parametrize(
    "torque_nm, klass, cure",
    [
        (700, "penetration", "lower load.torque_nm"),
        (2000, "teeth_jumped", "lower load.torque_nm"),
    ],
)
def test_overload_on_held_worm_penetrates_or_jumps_with_a_diagnosis(torque_nm, klass, cure):
    """A wheel load stepped onto the worm held at 0 rpm, at the default (stable) timestep: 700 N m is stopped by the
    penetration guard (0.4 m_x); 2000 N m throws the wheel past a tooth within two steps: the jump guard's
    message, not the divergence guard's."""
    sc = load_scenario(
        DEMO,
        [
            "drive.speed_rpm=0",
            "drive.ramp_s=0",
            "load.ramp_s=0",
            f"load.torque_nm={torque_nm}",
            "simulation.duration_s=0.001",
        ],
    )
    bm = build_model(sc)
    assert bm.model.opt.timestep == bm.timestep_s <= bm.law.stable_limit_s
    with pytest.raises(SimulationError) as exc:
        simulate(sc)
    msg = str(exc.value)
    assert classify_failure(exc.value) == klass, msg
    assert cure in msg, msg
    if klass == "teeth_jumped":
        assert "diverged" not in msg
        # the default contact.geometry (flanks) does not model the jump itself, and says which geometry does
        assert "contact.geometry pieces models it" in msg, msg
        assert abs(float(re.search(r"transmission error (-?[0-9.]+) pitch", msg).group(1))) > JUMP_PITCH


def test_timestep_above_the_stable_limit_diverges_and_names_the_stable_timestep():
    """dt = 1e-4 s, 20 x the default and 6 x the explicit limit of the contact spring-damper: the message is the
    divergence guard's and states the limit (ContactLaw.stable_timestep_s with three pairs) and the default
    timestep (wormsim.contact3d.timestep.default_timestep) to set."""
    sc = load_scenario(DEMO, ["simulation.timestep_s=1e-4", "simulation.duration_s=0.005"])
    law = build_model(sc).law
    with pytest.raises(SimulationError) as exc:
        simulate(sc)
    msg = str(exc.value)
    assert classify_failure(exc.value) == "diverged", msg
    limit = float(re.search(r"stable limit ([0-9.e+-]+) s", msg).group(1))
    advice = float(re.search(r"simulation\.timestep_s <= ([0-9.e+-]+) s", msg).group(1))
    assert limit == pytest.approx(law.stable_timestep_s(3 * law.contacts_per_pair), rel=5e-3)
    assert advice == pytest.approx(default_timestep(law), rel=1e-9)
    assert advice < limit < 1e-4


def test_bad_qacc_at_a_stable_timestep_names_the_command_step_and_its_cure():
    """MuJoCo's bad-qacc warning at the default (stable) timestep: a 100 N m load and the full speed command applied
    as steps at t = 0 (ramp_s = 0) on the 7 g seat wheel. The divergence guard names that cause and its cure; the
    cure it names (2 ms ramps, which the runner follows step by step) runs the same load through."""
    base = ["simulation.duration_s=0.004", "load.torque_nm=100"]
    with pytest.raises(SimulationError) as exc:
        simulate(load_scenario(DEMO, base + ["load.ramp_s=0", "drive.ramp_s=0"]))
    msg = str(exc.value)
    assert classify_failure(exc.value) == "diverged" and "bad-qacc" in msg, msg
    assert "within the contact's stable limit" in msg and "drive.ramp_s" in msg and "load.ramp_s" in msg
    res = simulate(load_scenario(DEMO, base + ["load.ramp_s=0.002", "drive.ramp_s=0.002"]))
    # simulation.duration_s 0.004 of base (the run reaches its end)
    assert res.sim_time_s == pytest.approx(0.004, abs=1e-5)


@pytest.mark.parametrize("field", ["qvel", "qacc"])
def test_a_state_mujoco_resets_mid_run_fails_at_the_time_it_happened(monkeypatch, field):
    """MuJoCo resets the state and d.time to the start on a non-finite or huge qpos, qvel or qacc and steps on: a run
    must not go on from rest as if nothing happened, and the divergence must be dated by the run's clock, not the
    reset one. A NaN velocity (MuJoCo's bad-qvel) or a huge applied force (bad-qacc) is planted after the first
    sample past 5 ms of a screw-jack run on the compiled flank path."""
    import numpy as np

    from wormsim.contact3d import runner

    real, planted = runner._sample, []

    def plant(lp, i, cmd, sums):
        real(lp, i, cmd, sums)
        if not planted and lp.d.time > 0.005:
            planted.append(float(lp.d.time))
            if field == "qvel":
                lp.d.qvel[:] = np.nan
            else:
                lp.d.qfrc_applied[:] = 1e30

    monkeypatch.setattr(runner, "_sample", plant)
    with pytest.raises(SimulationError) as exc:
        simulate(load_scenario(JACK, ["simulation.duration_s=0.02", "simulation.resolution=coarse"]))
    msg = str(exc.value)
    assert classify_failure(exc.value) == "diverged" and f"bad-{field}" in msg, msg
    t = float(re.search(r"diverged at t = ([0-9.e+-]+) s", msg).group(1))
    assert planted[0] < t < planted[0] + 0.002, (planted, msg)


def test_classify_failure_names_each_guard_by_its_exception_type():
    for exc_type, klass in FAILURE_CLASSES:
        assert issubclass(exc_type, SimulationError)
        assert classify_failure(exc_type("any wording at all")) == klass
    assert classify_failure(SimulationError("diverged at t = 0.1 s")) == "other"  # the wording does not count
    assert classify_failure(ZeroDivisionError()) == "other"


def test_stability_edge_records_the_last_stable_timestep_and_the_failure():
    """A tiny sweep on the seat motor demo (x1, x4 its default timestep, 15 ms): x1 is the reference and passes,
    x4 (1.24 x the explicit limit) runs away and is classified as divergence; the record says so. contact.geometry
    pieces: with the flank contacts x4 did not run away within the 15 ms (measured: classified "inaccurate"), so the
    divergence record is made with pieces."""
    rec = stability_edge(
        "seat_motor_demo",
        factors=(1, 4),
        duration_s=0.015,
        overrides=("drive.ramp_s=0.002", "load.ramp_s=0.002", "contact.geometry=pieces"),
    )
    for k in (
        "scenario",
        "default_timestep_s",
        "stable_limit_s",
        "last_stable_timestep_s",
        "last_stable_factor",
        "failure",
        "failed_timestep_s",
        "failure_message",
        "runs",
        "tolerances",
    ):
        assert k in rec, k
    h0 = rec["default_timestep_s"]
    # DEFAULT_FRACTION x stable limit rounded down to two digits for the seat motor demo (0.4 x 1.61e-5 s): this code's
    # value, no independent source
    assert h0 == pytest.approx(6.4e-6) and h0 < rec["stable_limit_s"] < 4 * h0
    first, second = rec["runs"]
    assert first["status"] == "ok" and first["drift"] == {"ratio_angles": 0.0, "tangential_force_mean_n": 0.0}
    # shaft angles over the ~5 ms steady window of so short a run: the wheel's rattle in its 25 um half backlash
    # (up to 1.3e-3 rad at r2) sits on 0.02 rad of travel (measured 53.09)
    assert first["ratio_angles"] == pytest.approx(53.0, rel=1e-2)
    assert second["status"] == "failed" and second["failure"] == "diverged"
    assert second["timestep_s"] == pytest.approx(4 * h0) and second["timestep_over_limit"] > 1
    assert rec["last_stable_timestep_s"] == pytest.approx(h0) and rec["last_stable_factor"] == 1
    assert rec["failure"] == "diverged" and rec["failed_timestep_s"] == pytest.approx(4 * h0)
    json.dumps(rec)  # bench_meta.json-ready


def test_bench_writes_the_stability_record_into_bench_meta(tmp_path, monkeypatch):
    """run_bench puts stability_map's record under "stability" in bench_meta.json. The grid is emptied and the map
    cut to one sweep step of 2 ms at x4 (a timestep that runs away within 1 ms), so the record holds a failure at
    the first step and no stable timestep (contact.geometry pieces, as above)."""
    from wormsim.bench import run as bench

    monkeypatch.setattr(bench, "bench_cases", lambda *args: [])
    monkeypatch.setattr(
        bench,
        "stability_map",
        lambda *args: {
            "seat_motor_demo": stability_edge(
                "seat_motor_demo",
                factors=(4,),
                duration_s=0.002,
                overrides=("drive.ramp_s=0.002", "load.ramp_s=0.002", "contact.geometry=pieces"),
            )
        },
    )
    bench.run_bench(quick=True, out_dir=tmp_path, models=("contact3d",))
    rec = json.loads((tmp_path / "bench_meta.json").read_text())["stability"]["seat_motor_demo"]
    assert rec["last_stable_timestep_s"] is None and rec["failure"] == "diverged"
    assert len(rec["runs"]) == 1 and rec["runs"][0]["status"] == "failed"
    assert "stable limit" in rec["failure_message"]


def test_friction_alignment_reads_one_for_a_box_sliding_on_a_plane():
    """friction_guard.friction_alignment's signs (efc_force against efc_vel in the contact frame): a 1 kg box sliding
    at 1 m/s on a plane (elliptic cone, mu 0.5) has its friction on the cone and against the slip (cos 1), |f_t| =
    mu f_n = mu m g; at rest nothing slides (cos 1 by definition, friction sum 0)."""
    import mujoco

    from wormsim.contact3d.friction_guard import friction_alignment

    xml = """<mujoco><option cone="elliptic" timestep="1e-4"/><worldbody>
    <geom type="plane" size="1 1 0.1" friction="0.5 0 0"/>
    <body pos="0 0 0.05"><freejoint/><geom type="box" size="0.05 0.05 0.05" mass="1" friction="0.5 0 0"/></body>
    </worldbody></mujoco>"""
    m = mujoco.MjModel.from_xml_string(xml)
    d = mujoco.MjData(m)
    for _ in range(200):  # settle onto the plane
        mujoco.mj_step(m, d)
    cos, ft, fn = friction_alignment(d, 1e-3)
    # f_n = m g = 1 kg x 9.81 m/s^2 (statics of the box at rest)
    assert cos == 1.0 and ft == 0.0 and fn == pytest.approx(9.81, rel=0.02)
    d.qvel[0] = 1.0
    for _ in range(5):
        mujoco.mj_step(m, d)
    cos, ft, fn = friction_alignment(d, 1e-3)
    # Coulomb: |f_t| = mu f_n with mu 0.5 of the MJCF above
    assert cos == pytest.approx(1.0, abs=1e-3) and ft == pytest.approx(0.5 * fn, rel=0.01), (cos, ft, fn)
