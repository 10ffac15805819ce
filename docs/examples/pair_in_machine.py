"""A worm pair inside a machine of one's own: a motor with rotor inertia turns the worm through a velocity
actuator, and the wheel lifts a load arm against gravity (docs/multibody.md).

    PYTHONPATH=. python docs/examples/pair_in_machine.py            # prints ratio and forces against theory

The machine is plain MJCF: a housing whose wheel axis lies horizontal, the motor's velocity actuator on the worm
hinge the pair adds (`jack_worm_hinge`: the prefix `jack_` given to attach). The pair comes from the screw jack
scenario; the load is an arm of mass M at radius L on the wheel, so the wheel torque is M g L cos(theta2).
"""

from __future__ import annotations

from pathlib import Path

import mujoco
import numpy as np

import wormsim

ROOT = Path(__file__).resolve().parents[2]
SCENARIO = ROOT / "scenarios" / "screw_jack.yaml"
G = 9.81  # m/s^2, the model's gravity

MACHINE = """
<mujoco model="jack_machine">
  <option integrator="implicitfast" gravity="0 0 -9.81"/>
  <worldbody>
    <!-- housing turned about y by 90 deg: the pair's wheel axis (housing z) is the world's x, horizontal -->
    <body name="housing" quat="0.70710678 0 0.70710678 0"/>
  </worldbody>
  <actuator>
    <!-- the motor: a speed servo on the worm hinge the pair adds (its name carries attach's prefix) -->
    <velocity name="motor" joint="jack_worm_hinge" kv="{kv}"/>
  </actuator>
</mujoco>
"""


def build(
    scenario=SCENARIO,
    arm_mass_kg: float = 12.0,
    arm_length_m: float = 0.1,
    rotor_inertia_kg_m2: float = 1e-4,
    kv_nm_s: float = 1.0,
    timestep_s: float | None = None,
):
    """(model, data, pair): the machine with the pair attached under "housing", the motor's rotor as the worm
    hinge's armature, the load arm a point mass on the wheel at radius arm_length_m along the wheel's y axis (level
    at theta2 = 0). timestep_s: default the pair's default_timestep_s."""
    pair = wormsim.WormPair.from_scenario(scenario)
    spec = mujoco.MjSpec.from_string(MACHINE.format(kv=kv_nm_s))
    worm_joint, _ = pair.attach(spec, parent="housing", prefix="jack_")
    spec.joint(worm_joint).armature = rotor_inertia_kg_m2  # the motor's rotor, rigid on the worm shaft
    arm = spec.body(pair.body_names[1]).add_body()
    arm.name = "load_arm"
    arm.pos = [0.0, arm_length_m, 0.0]
    g = arm.add_geom()
    g.type = mujoco.mjtGeom.mjGEOM_SPHERE
    g.size = [0.01, 0, 0]
    g.mass = arm_mass_kg
    g.contype = g.conaffinity = 0
    spec.option.timestep = pair.default_timestep_s if timestep_s is None else timestep_s
    model = spec.compile()
    return model, mujoco.MjData(model), pair


def run(model, data, pair, worm_speed_rad_s: float = 30.0, ramp_s: float = 0.02, duration_s: float = 0.07):
    """Ramp the motor's speed command linearly over ramp_s, then hold it; step with the pair. Returns the series
    (t, worm angle, wheel angle, worm speed, wheel speed, ft, fr, fa) as a dict of arrays."""
    h = model.opt.timestep
    n = int(round(duration_s / h))
    out = np.zeros((8, n))
    w1, w2 = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, pair.joint_names[0]), None
    q1 = model.jnt_qposadr[w1]
    j2 = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, pair.joint_names[1])
    q2, w2 = model.jnt_qposadr[j2], model.jnt_dofadr[j2]
    d1 = model.jnt_dofadr[w1]
    motor = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_ACTUATOR, "motor")
    for i in range(n):
        data.ctrl[motor] = worm_speed_rad_s * min(1.0, (data.time + h) / ramp_s)
        pair.step(model, data)
        out[:, i] = (data.time, data.qpos[q1], data.qpos[q2], data.qvel[d1], data.qvel[w2], *pair.mesh_forces(data))
    keys = ("t_s", "worm_angle_rad", "wheel_angle_rad", "worm_speed_rad_s", "wheel_speed_rad_s", "ft_n", "fr_n", "fa_n")
    return dict(zip(keys, out, strict=True))


def check(series, pair, arm_mass_kg: float = 12.0, arm_length_m: float = 0.1, window_s: float = 0.03):
    """(ratio, ratio_theory, ft mean, T / r2 over the last window_s): the speed ratio from the angles travelled, the
    mean tangential force against the arm's mean torque M g L cos(theta2) over r2."""
    t = series["t_s"]
    sl = t >= t[-1] - window_s
    th1, th2 = series["worm_angle_rad"][sl], series["wheel_angle_rad"][sl]
    ratio = (th1[-1] - th1[0]) / (th2[-1] - th2[0])
    torque = arm_mass_kg * G * arm_length_m * np.cos(th2)
    return ratio, pair.ratio, float(np.mean(series["ft_n"][sl])), float(np.mean(torque) / pair.wheel_pitch_radius_m)


if __name__ == "__main__":
    model, data, pair = build()
    s = run(model, data, pair)
    ratio, ratio_th, ft, ft_th = check(s, pair)
    print(f"timestep {model.opt.timestep:.3g} s (stable limit {pair.stable_timestep_s:.3g} s)")
    print(f"ratio {ratio:.5f} (z2 / z1 = {ratio_th:g}, {100 * (ratio / ratio_th - 1):+.3f} %)")
    print(f"F_t {ft:.1f} N against M g L cos(theta2) / r2 = {ft_th:.1f} N ({100 * (ft / ft_th - 1):+.2f} %)")
    print(f"last step: F_r {s['fr_n'][-1]:.1f} N, F_a {s['fa_n'][-1]:.1f} N, {pair.contact_count()} contacts")
