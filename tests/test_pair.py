"""wormsim.WormPair: the exact-flank pair inside a user's MuJoCo model (wormsim.pair, docs/multibody.md).

Expected numbers: the ratio z2 / z1 (INTERFACE.md: ratio = mean worm speed / mean wheel speed) and the wheel's
tangential force T / r2 (a wheel torque T balanced at the reference radius r2, DIN 3975 F_t2); the 0.1 % and 2 %
tolerances are issue 25's acceptance criteria."""

from __future__ import annotations

import importlib.util
from pathlib import Path

import mujoco
import numpy as np
import pytest

import wormsim
from wormsim.pair import PairStepError
from wormsim.scenario import load_scenario

ROOT = Path(__file__).resolve().parents[1]
SLICES = 8  # coarse slicing keeps the steps cheap; the means do not depend on it (docs/contact3d.md)


def _example():
    spec = importlib.util.spec_from_file_location("pair_in_machine", ROOT / "docs/examples/pair_in_machine.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def _jack(**contact):
    sc = load_scenario(ROOT / "scenarios/screw_jack.yaml")
    return sc.model_copy(update={"contact": sc.contact.model_copy(update={"slices": SLICES, **contact})})


def _ratio(th1: np.ndarray, th2: np.ndarray) -> float:
    return float((th1[-1] - th1[0]) / (th2[-1] - th2[0]))


def test_example_motor_and_gravity_arm_meshes_at_ratio_and_carries_the_load():
    """docs/examples/pair_in_machine.py: motor (rotor inertia, velocity servo) -> worm, wheel -> load arm under
    gravity; the arm's torque M g L cos(theta2) over r2 is the tangential force."""
    ex = _example()
    model, data, pair = ex.build(_jack())
    s = ex.run(model, data, pair, duration_s=0.06)
    ratio, ratio_th, ft, ft_th = ex.check(s, pair)
    assert ratio_th == 24.0  # screw_jack.yaml: wheel_teeth 24, worm_starts 1
    assert abs(ratio / ratio_th - 1) < 1e-3, (ratio, ratio_th)
    assert abs(ft / ft_th - 1) < 0.02, (ft, ft_th)
    assert pair.contact_count() > 0


MACHINE = """
<mujoco>
  <option timestep="1e-5" integrator="implicitfast" gravity="0 0 -9.81"/>
  <worldbody>
    <body name="frame">
      {housing_joint}
      <inertial pos="0 0 0" mass="20" diaginertia="0.5 0.5 0.5"/>
      <body name="housing"/>
    </body>
  </worldbody>
  <actuator>{actuators}</actuator>
</mujoco>
"""


def _machine(pairs, loads_nm, housing_joint="", housing_act="", worm_rad_s=30.0):
    """The housing (under a frame body that may move) with the pairs attached side by side along the housing's z;
    per pair a velocity servo on the worm and a constant resisting motor torque on the wheel."""
    acts = [housing_act]
    for i, _ in enumerate(pairs):
        acts.append(f'<velocity name="motor{i}" joint="p{i}_worm_hinge" kv="1"/>')
        acts.append(f'<motor name="load{i}" joint="p{i}_wheel_hinge"/>')
    spec = mujoco.MjSpec.from_string(MACHINE.format(housing_joint=housing_joint, actuators="".join(acts)))
    for i, p in enumerate(pairs):
        p.attach(spec, parent="housing", prefix=f"p{i}_", pos=(0.0, 0.0, 0.2 * i))
    model = spec.compile()
    data = mujoco.MjData(model)
    return model, data


def _drive(model, data, pairs, loads_nm, steps, worm_rad_s=30.0, ramp_s=0.02, housing=None):
    """Step all pairs together; returns per pair the arrays (theta1, theta2, ft) of every step."""
    h = model.opt.timestep
    ids = [
        (
            mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_ACTUATOR, f"motor{i}"),
            mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_ACTUATOR, f"load{i}"),
            model.jnt_qposadr[mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, p.joint_names[0])],
            model.jnt_qposadr[mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, p.joint_names[1])],
        )
        for i, p in enumerate(pairs)
    ]
    out = np.zeros((len(pairs), 3, steps))
    for k in range(steps):
        s = min(1.0, (data.time + h) / ramp_s)
        for (am, al, _, _), T in zip(ids, loads_nm, strict=True):
            data.ctrl[am] = worm_rad_s * s
            data.ctrl[al] = -T * s
        if housing is not None:
            housing(data)
        wormsim.step(model, data, pairs)
        for i, (p, (_, _, q1, q2)) in enumerate(zip(pairs, ids, strict=True)):
            out[i, :, k] = data.qpos[q1], data.qpos[q2], p.mesh_forces(data)[0]
    return out


def test_two_pairs_in_one_model_each_carry_their_own_load():
    pairs = [wormsim.WormPair.from_scenario(_jack()) for _ in range(2)]
    loads = (6.0, 12.0)  # N m, resisting torques of the two wheels' motors
    model, data = _machine(pairs, loads)
    out = _drive(model, data, pairs, loads, 6000)
    sl = slice(3000, None)
    for i, (p, T) in enumerate(zip(pairs, loads, strict=True)):
        ratio = _ratio(out[i, 0, sl], out[i, 1, sl])
        ft = float(np.mean(out[i, 2, sl]))
        assert abs(ratio / p.ratio - 1) < 1e-3, (i, ratio)
        assert abs(ft / (T / p.wheel_pitch_radius_m) - 1) < 0.02, (i, ft, T / p.wheel_pitch_radius_m)


def test_pair_on_a_turning_housing_meshes():
    """The housing turns about the world's x (across the wheel axis) at 2 rad/s by its own servo: the pair's hinge
    angles are relative to it, the kernel takes the moving bodies' poses."""
    pair = wormsim.WormPair.from_scenario(_jack())
    joint = '<joint name="tilt" type="hinge" axis="1 0 0"/>'
    act = '<velocity name="tilt_servo" joint="tilt" kv="200"/>'
    model, data = _machine([pair], (12.0,), housing_joint=joint, housing_act=act)
    tilt = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_ACTUATOR, "tilt_servo")

    def housing(d):
        d.ctrl[tilt] = 2.0  # rad/s

    out = _drive(model, data, [pair], (12.0,), 6000, housing=housing)
    q_tilt = model.jnt_qposadr[mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, "tilt")]
    assert data.qpos[q_tilt] > 0.08  # the housing turned (2 rad/s over 0.06 s, after the servo's spin-up)
    sl = slice(3000, None)
    ratio = _ratio(out[0, 0, sl], out[0, 1, sl])
    ft = float(np.mean(out[0, 2, sl]))
    assert abs(ratio / pair.ratio - 1) < 1e-3, ratio
    # the turning housing adds the wheel's gyroscopic and Euler moments about its own axis only through I2 alpha2
    assert abs(ft / (12.0 / pair.wheel_pitch_radius_m) - 1) < 0.02, ft


def test_timestep_above_the_stable_limit_is_refused_with_the_limit():
    pair = wormsim.WormPair.from_scenario(_jack())
    spec = mujoco.MjSpec.from_string('<mujoco><option timestep="1e-4"/><worldbody/></mujoco>')
    pair.attach(spec, prefix="a_")
    model = spec.compile()
    data = mujoco.MjData(model)
    with pytest.raises(PairStepError, match=r"stable limit 2\.53e-05 s") as e:
        pair.step(model, data)
    assert f"{pair.stable_timestep_s:.3g}" in str(e.value)
    model.opt.timestep = pair.default_timestep_s
    model.opt.integrator = mujoco.mjtIntegrator.mjINT_RK4
    with pytest.raises(PairStepError, match="RK4"):
        pair.step(model, data)


def test_attach_names_and_placement():
    """Bodies under the parent as the geometry contract places them: wheel at the origin, worm axis along x at
    y = -a (INTERFACE.md, 'Geometry files'); a second attach with the same prefix is refused."""
    pair = wormsim.WormPair.from_scenario(_jack())
    spec = mujoco.MjSpec.from_string('<mujoco><worldbody><body name="housing" pos="1 2 3"/></worldbody></mujoco>')
    assert pair.attach(spec, parent="housing", prefix="x_") == ("x_worm_hinge", "x_wheel_hinge")
    model = spec.compile()
    data = mujoco.MjData(model)
    mujoco.mj_kinematics(model, data)
    worm, wheel = (mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, n) for n in pair.body_names)
    # the housing body's pos 1 2 3 in the MJCF above; worm at y = -a (INTERFACE.md, 'Geometry files')
    np.testing.assert_allclose(data.xpos[wheel], [1, 2, 3], atol=1e-12)
    np.testing.assert_allclose(data.xpos[worm], [1, 2 - pair.center_distance_m, 3], atol=1e-12)
    worm_axis = data.xmat[worm].reshape(3, 3)[:, 2]
    assert abs(abs(worm_axis[0]) - 1) < 1e-12
    other = wormsim.WormPair.from_scenario(_jack())
    with pytest.raises(ValueError, match="prefix"):
        other.attach(spec, parent="housing", prefix="x_")
    with pytest.raises(ValueError, match="no body 'nowhere'"):
        other.attach(spec, parent="nowhere", prefix="y_")


def test_pair_with_shafts_on_a_compliant_housing_meshes():
    """The pair's shafts: block (worm on compliant bearings and bending) attached under a housing that sits on a
    spring mount (a slide across the line of centres): bearings, bending and mount all yield under the mesh force."""
    sc = _jack()
    block = {"worm": {"bearings_mm": [-60, 60], "radial_stiffness_n_per_um": 500, "bending": True}}
    sc = type(sc).model_validate({**sc.model_dump(), "shafts": block})
    pair = wormsim.WormPair.from_scenario(sc)
    joint = '<joint name="mount" type="slide" axis="0 1 0" stiffness="1e7" damping="2e3"/>'
    model, data = _machine([pair], (12.0,), housing_joint=joint)
    assert mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, "p0_worm_bend") >= 0
    out = _drive(model, data, [pair], (12.0,), 6000)
    q_mount = model.jnt_qposadr[mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, "mount")]
    q_bend = model.jnt_qposadr[mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, "p0_worm_bend_y")]
    assert abs(data.qpos[q_mount]) > 0 and abs(data.qpos[q_bend]) > 1e-7  # they yielded (m)
    sl = slice(3000, None)
    ratio = _ratio(out[0, 0, sl], out[0, 1, sl])
    ft = float(np.mean(out[0, 2, sl]))
    assert abs(ratio / pair.ratio - 1) < 1e-3, ratio
    # 12.0 N m: the load torque given to _machine above (screw_jack.yaml); F_t = T2 / r2 (statics)
    assert abs(ft / (12.0 / pair.wheel_pitch_radius_m) - 1) < 0.02, ft
    # the worm's (rigid) locating bearing takes the worm's axial force, the wheel's tangential force (DIN 3975)
    loads = pair.shaft_loads(data)
    assert abs(abs(loads["worm_bearing_axial_n"]) / abs(pair.mesh_forces(data)[0]) - 1) < 0.03, loads
    assert loads["worm_deflection_mesh_x_m"] != 0.0


_SAME_GEAR: dict = {}


def _pair_and_contact3d_same_gear() -> dict:
    """WormPair and contact3d on the same gear and working point (screw jack, 8 slices, worm at 30 rad/s, 12 N m on
    the wheel, both ramped over 0.02 s, timestep 1e-5 s, means over 0.03-0.06 s; contact3d with one contact per face
    slice, as a pair steps them), run once per process for the tests
    that read them: the pair's means (F_t, F_r, F_a), its efficiency, contact3d's F_r, F_a and efficiency, and the
    mesh's mean friction coefficient."""
    if _SAME_GEAR:
        return _SAME_GEAR
    from wormsim.run import simulate

    sc = _jack()
    pair = wormsim.WormPair.from_scenario(sc)
    model, data = _machine([pair], (12.0,))
    h = model.opt.timestep
    am = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_ACTUATOR, "motor0")
    al = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_ACTUATOR, "load0")
    steps = 6000
    rows = np.zeros((steps, 5))  # F_t, F_r, F_a, worm power, wheel power
    for k in range(steps):
        s = min(1.0, (data.time + h) / 0.02)
        data.ctrl[am], data.ctrl[al] = 30.0 * s, -12.0 * s
        wormsim.step(model, data, [pair])
        w1, w2 = pair.worm_speed_rad_s(data), pair.wheel_speed_rad_s(data)
        rows[k] = (*pair.mesh_forces(data), data.actuator_force[am] * w1, data.actuator_force[al] * w2)
    m = rows[steps // 2 :].mean(axis=0)

    c3 = load_scenario(
        ROOT / "scenarios/screw_jack.yaml",
        [
            "contact.slices=8",
            "contact.flank_contacts=slice",  # (a pair steps one contact per face slice: WormPair.from_scenario)
            f"drive.speed_rpm={30.0 * 60 / (2 * np.pi)}",
            "drive.ramp_s=0.02",
            "load.ramp_s=0.02",
            "simulation.timestep_s=1e-5",
            "simulation.duration_s=0.06",
        ],
    )
    S = simulate(c3).series
    k = S["t_s"] >= 0.03
    _SAME_GEAR.update(
        gear=sc.gear,
        pair=m[:3],
        eta_pair=-m[4] / m[3],
        fr3=float(np.mean(S["radial_force_n"][k])),
        fa3=float(np.mean(S["axial_force_n"][k])),
        eta3=float(-np.mean(S["wheel_power_w"][k]) / np.mean(S["worm_power_w"][k])),
        mu=float(np.mean(S["friction_coefficient"][k])),
    )
    return _SAME_GEAR


def test_pair_forces_and_efficiency_match_contact3d_on_the_same_gear():
    """Issue 31: WormPair's F_r, F_a and efficiency against contact3d's on the same gear and working point
    (_pair_and_contact3d_same_gear). Both step the same exact-flank contacts, one per face slice (measured: F_r
    134.59 / 134.61 N, F_a 57.85 / 57.91 N, efficiency 0.6386 / 0.6385, pair / contact3d; against contact3d's default
    four merged contacts per flank F_a differs 0.48 %); 0.5 % allows for the machine's velocity servo (kv = 1 against
    contact3d's stiffer one)."""
    r = _pair_and_contact3d_same_gear()
    assert r["pair"][1] == pytest.approx(r["fr3"], rel=0.005)
    assert r["pair"][2] == pytest.approx(r["fa3"], rel=0.005)
    assert r["eta_pair"] == pytest.approx(r["eta3"], rel=0.005)


@pytest.mark.xfail(
    strict=True,
    reason="F_a2 57.85 N against DIN 3975's F_t2 tan(gamma + rho') = 61.60 N at the mesh's mean friction (-6.1 %; "
    "-4.7 % at 64 profile points, before decision 0060): the contacts sit at angles about the worm axis, which turn "
    "part of their worm-tangential force out of the wheel's axial direction (the seeds' contact3d runs: "
    "tests/contact3d/test_seeds.py::test_flanks_axial_force_is_worm_torque_over_contact_radius, -2.6 to -4.1 %)",
)
def test_pair_axial_force_against_din_3975():
    """WormPair's F_a2 against DIN 3975's F_t2 tan(gamma + rho') at the mesh's mean friction, within 5 %."""
    from meshgen.geometry import derive
    from wormsim.physics import gear_theory as gt

    r = _pair_and_contact3d_same_gear()
    g = derive(r["gear"])
    rho = gt.virtual_friction_angle_rad(r["mu"], g.alpha_n)
    assert r["pair"][2] == pytest.approx(float(gt.axial_force_n(r["pair"][0], g.gamma, rho)), rel=0.05)
