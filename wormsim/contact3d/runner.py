"""contact3d runner: steps the MuJoCo model of wormsim.contact3d.mjcf, reads the tooth forces, guards the run.

`simulate(scenario, progress) -> Result` (the interface of wormsim.run). The loop steps the model one step at a
time (the drive and load commands follow their STEP ramps at each step's midpoint) and, at every step, adds up
the model's contact sensor (worm against the wheel's subtree, reduce="netforce": the resultant tooth force on the
wheel, its point and moment) and the shaft powers T w. Every `record_every` steps it stores one sample whose
forces, moment, contact count, torques and powers are the MEANS over those steps (a box-car filter: the contact
vibration at 10-80 kHz does not alias into the meshing band, and the box's nulls at multiples of the sampling
rate cancel exactly what would fold onto 0 Hz), and whose angles and speeds are the values at its end. Then it

- re-poses the wheel's collision window by whole pitches (wormsim.contact3d.slots.repose_window),
- sets the friction coefficient mu(Vs) from the sliding speed Vs = |omega1| r1 / cos(gamma),
- resolves the mean resultant on the wheel in the wheel's directions at the pitch point on the line of centres
  (DIN 3975 F_t2, F_r2, F_a2; seed 001's x/y components): tangential, radial (outward), axial; the contact
  torque M_z apart (wheel_contact_torque_nm); and takes, at the sample instant, the number of wheel teeth
  touching, the largest penetration and the contact points in the frame of wheel tooth 0 (for the contact
  pattern), from the contacts' elliptic-cone rows (what mj_contactForce returns, contact_details),
- checks the guards: non-finite state or MuJoCo's bad-qacc warning (divergence), penetration beyond
  `penetration_limit_m`, the transmission error passing half a pitch (teeth jumped; divergence when the
  timestep is above the contact's stable limit), a speed-driven drive stuck below half its command (locked;
  self-locking named when the wheel drives), the worm turning more than 1.25 x MAX_WORM_TURN_PER_STEP_RAD per
  step (overspeed: its pieces would tunnel through the wheel's), the sliding contacts' friction turned away from
  their slip (wormsim.contact3d.friction_guard); after the loop, above the stable limit, an exact-flank mesh that rang
  to the end (wormsim.contact3d.ringing_check). Each raises its subclass of SimulationError
  (wormsim.errors) with what to change (diverged_error, jump_error, locked_error, overspeed_error, penetration_error;
  docs/contact3d.md "Failure modes and guards").

The timestep is the model's, chosen before it was built (wormsim.contact3d.timestep.choose_timestep).
"""

from __future__ import annotations

import functools
import math
import time

import mujoco
import numpy as np

from wormsim import gear_theory as gt
from wormsim import prewarm
from wormsim.contact3d import jit_warmup, mass_scaling
from wormsim.contact3d.contact_sums import RadiusLog
from wormsim.contact3d.diagnosis import diverged_error
from wormsim.contact3d.guards import Guards
from wormsim.contact3d.metrics import contact3d_summary
from wormsim.contact3d.mjcf import BuiltModel, build_model
from wormsim.contact3d.ringing_check import ringing
from wormsim.contact3d.shafts import ShaftLog
from wormsim.contact3d.slots import repose_window
from wormsim.friction import friction_coefficient_scalar, friction_mode
from wormsim.result import Result
from wormsim.scenario import Scenario
from wormsim.units import rad_s_to_rpm

MAX_POINTS = 48  # contact points kept per sample (for the pattern and the recording)
TARGET_SAMPLES = 20000  # automatic record_every aims at about this many samples per run (each the mean
# over its interval, so decimation does not alias the contact vibration)
_ROWS3 = np.arange(3)  # the normal and two tangent rows of an elliptic-cone contact


def _record_every(scenario: Scenario, dt: float, n_steps: int, scaled: bool = False) -> int:
    sim = scenario.simulation
    if "record_every" in sim.model_fields_set:
        return sim.record_every
    return max(1, n_steps // (mass_scaling.SCALED_SAMPLES if scaled else TARGET_SAMPLES))


def contact_details(bm: BuiltModel, d: mujoco.MjData, window_ks: np.ndarray):
    """The contacts one by one (the resultant comes from the contact sensor): (n_teeth touching, max penetration,
    points in the frame of wheel tooth 0 (n, 3), forces on the wheel (n, 3) world, points (n, 3) world). Forces are
    the elliptic-cone rows (normal, two tangents: what mj_contactForce returns) turned into the world frame."""
    n = d.ncon
    if n == 0:
        z = np.zeros((0, 3))
        return 0, 0.0, z, z, z
    con = d.contact
    adr = np.asarray(con.efc_address[:n])
    ok = adr >= 0
    geom = np.asarray(con.geom[:n])[ok]
    adr = adr[ok]
    frame = np.asarray(con.frame[:n])[ok].reshape(-1, 3, 3)
    pos = np.asarray(con.pos[:n])[ok]
    dist = np.asarray(con.dist[:n])[ok]
    f = d.efc_force[adr[:, None] + _ROWS3]
    F = np.einsum("ni,nij->nj", f, frame)  # force on geom2, world frame
    wheel_is_2 = bm.model.geom_bodyid[geom[:, 1]] != bm.worm_body
    F = np.where(wheel_is_2[:, None], F, -F)  # force on the wheel
    wheel_geom = np.where(wheel_is_2, geom[:, 1], geom[:, 0])
    # tooth index of each contact: slot -> tooth in the current window
    W = bm.window_teeth
    slots = _slot_lookup(bm)[wheel_geom]
    tooth_of_slot = np.zeros(W, dtype=int)
    tooth_of_slot[np.asarray(window_ks) % W] = window_ks
    ks = tooth_of_slot[slots]
    # contact points in tooth-0 frame: undo wheel rotation and tooth angle
    th2 = float(d.qpos[bm.model.jnt_qposadr[bm.model.dof_jntid[bm.wheel_dof]]])
    ang = -(th2 + 2 * math.pi * ks / bm.geometry.z2)
    c, s = np.cos(ang), np.sin(ang)
    p0 = np.stack([c * pos[:, 0] - s * pos[:, 1], s * pos[:, 0] + c * pos[:, 1], pos[:, 2]], axis=1)
    pen = float(max(0.0, -dist.min())) if len(dist) else 0.0
    return int(np.unique(ks).size), pen, p0, F, pos


def _slot_lookup(bm: BuiltModel) -> np.ndarray:
    """Geom id -> window slot of the wheel's collision geoms (-1 elsewhere), computed once per model layout."""
    rows = np.ascontiguousarray(bm.wheel_slot_geoms, dtype=np.int64)
    return _slot_table(int(bm.model.ngeom), rows.shape, rows.tobytes())


@functools.lru_cache(maxsize=8)
def _slot_table(ngeom: int, shape: tuple[int, ...], slot_geoms: bytes) -> np.ndarray:
    """The lookup of _slot_lookup, keyed by its content: the model's geom count and the slots' geom ids (a sweep
    that runs several scenarios in one process gets each model's own table)."""
    rows = np.frombuffer(slot_geoms, dtype=np.int64).reshape(shape)
    lut = np.full(ngeom, -1, dtype=int)
    for s, row in enumerate(rows):
        lut[row] = s
    lut.flags.writeable = False
    return lut


SERIES = (
    "t_s",
    "worm_angle_rad",
    "wheel_angle_rad",
    "worm_speed_rpm",
    "wheel_speed_rpm",
    "worm_torque_nm",
    "wheel_torque_nm",
    "drive_command",
    "tangential_force_n",
    "radial_force_n",
    "axial_force_n",
    "contacts",
    "teeth_in_contact",
    "max_penetration_m",
    "friction_coefficient",
    "transmission_error_rad",
    "wheel_contact_torque_nm",
    "worm_power_w",
    "wheel_power_w",
    "tangential_force_abs_max_n",
    "radial_force_line_of_centres_n",
    "worm_contact_radius_m",
    "efficiency_theory_at_contact_radius",
)


def run_model(bm: BuiltModel, scenario: Scenario, progress=None) -> Result:
    """Step the built model over simulation.duration_s at its timestep; sample, guard, summarise (module docstring)."""
    m = bm.model
    d = mujoco.MjData(m)
    geo = bm.geometry
    dt = bm.timestep_s
    n_steps = int(round(scenario.simulation.duration_s / dt))
    rec = _record_every(scenario, dt, n_steps, bm.meta.get("mass_scaling", 1) > 1)
    n_rec = n_steps // rec
    qa_worm = int(m.jnt_qposadr[m.dof_jntid[bm.worm_dof]])
    qa_wheel = int(m.jnt_qposadr[m.dof_jntid[bm.wheel_dof]])
    coll = np.concatenate([bm.worm_geoms, bm.wheel_slot_geoms.ravel()])
    guards = Guards(bm, scenario, dt, rec)

    S_all = np.zeros((len(SERIES), n_rec))  # one column per sample, written at once
    S = dict(zip(SERIES, S_all))
    pts = np.full((n_rec, MAX_POINTS, 3), np.nan, dtype=np.float32)
    pts_world = np.full((n_rec, MAX_POINTS, 3), np.nan, dtype=np.float32)
    forces = np.full((n_rec, MAX_POINTS, 3), np.nan, dtype=np.float32)
    store = (pts, forces, pts_world)
    rlog = RadiusLog()  # the contacts' radii and weights: the efficiency at the contact radius (contact_sums)

    fc = pattern = loop = None
    if bm.meta.get("contact_geometry") == "flanks":
        # contacts found on the exact flanks and added between collision and constraints (wormsim.contact3d.flank_step)
        from wormsim.contact3d.flank_step import FlankContacts, flank_contact_details, split_forward
        from wormsim.tooth.hertz import PatternLog

        fc = FlankContacts(bm, bm.law.contacts_per_pair)
        pattern = PatternLog(fc, gt.effective_modulus_pa(scenario.materials))  # contact pattern and stress
        split_forward(m, d, fc.add)
        window = None
        step_fn = fc.step
    else:
        window = repose_window(bm, 0.0)
        mujoco.mj_forward(m, d)
        step_fn = mujoco.mj_step
    t_wall = time.perf_counter()
    worm_is_drive = scenario.drive.on == "worm"
    sd, act, qv, qp, ctrl = d.sensordata, d.actuator_force, d.qvel, d.qpos, d.ctrl
    s0 = int(m.sensor_adr[mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_SENSOR, "mesh_force")])
    ia_drv, ia_load, dof1, dof2 = bm.drive_actuator, bm.load_actuator, bm.worm_dof, bm.wheel_dof
    # worm / wheel actuator on each shaft: (drive, load) or (load, drive)
    a1, a2 = (ia_drv, ia_load) if worm_is_drive else (ia_load, ia_drv)
    mu_of = friction_coefficient_scalar(scenario.contact)
    mu_set = None
    if fc is not None:  # the record interval's steps compiled (wormsim.contact3d.flank_loop)
        from wormsim.contact3d.flank_loop import FlankLoop

        loop = FlankLoop(fc, d, ia_drv, ia_load, a1, a2, s0)
    # the commands at each step's midpoint, evaluated for blocks of about 4096 steps at once
    cmds = bm.plan.commands
    block = max(1, 4096 // rec)
    fast = None
    if loop is not None:  # whole stretches of samples in one compiled call (wormsim.contact3d.flank_samples)
        from wormsim.contact3d.flank_samples import FlankSamples

        fast = FlankSamples(loop, guards, scenario, bm, worm_is_drive, rec, S_all)
        fast.bind(store)
    slog = ShaftLog(m, bm.meta["shafts"], n_rec) if "shafts" in bm.meta else None  # wormsim.contact3d.shafts
    prewarm.loop_started()  # the writers' warm-up thread goes now, beside the GIL-free loop (wormsim.prewarm)
    i = 0
    while i < n_rec:
        if i % block == 0:
            t_blk = (i * rec + np.arange(min(block, n_rec - i) * rec) + 0.5) * dt
            cmd_arr, load_arr = cmds.drive(t_blk), cmds.load(t_blk)
            cmd_blk, load_blk = cmd_arr.tolist(), load_arr.tolist()
        o = (i % block) * rec
        fx = fy = fz = mz = nc = t1 = t2 = p1 = p2 = fpk = 0.0
        if fast is not None and fast.usable():
            i_next, pending = fast.run(cmd_arr, load_arr, i, min(n_rec, i - i % block + block), o, pattern, rlog)
            if progress is not None and i_next > i:
                progress.update(float(S_all[0, i_next - 1]))
            i = i_next
            if not pending:  # samples done up to i_next (the block's end)
                continue
            o = (i % block) * rec  # sample i's steps are done; its per-sample work follows in Python
            t1, t2, p1, p2, nc, fx, fy, fz, mz, fpk = loop.acc.tolist()
        elif loop is not None:
            t1, t2, p1, p2, nc, fx, fy, fz, mz, fpk = loop.run(cmd_arr, load_arr, o, o + rec).tolist()
        for j in range(o, o + rec) if loop is None else ():
            ctrl[ia_drv] = cmd_blk[j]
            ctrl[ia_load] = load_blk[j]
            w1j, w2j = qv[dof1], qv[dof2]
            step_fn(m, d)
            # actuator forces of this step (computed at its start, with the speeds above) and the sensor's
            # resultant (found, F (3), torque about the point (3), point (3); global frame, on the wheel)
            q1, q2 = act[a1], act[a2]
            t1 += q1
            t2 += q2
            p1 += q1 * w1j
            p2 += q2 * w2j
            nc += sd[s0]
            f0, f1, f2 = sd[s0 + 1], sd[s0 + 2], sd[s0 + 3]
            fx += f0
            if abs(f0) > fpk:  # the per-step peak (the start-up impact is shorter than an interval)
                fpk = abs(f0)
            fy += f1
            fz += f2
            mz += sd[s0 + 6] + sd[s0 + 7] * f1 - sd[s0 + 8] * f0
        cmd = cmd_blk[o + rec - 1]
        th1, th2 = float(qp[qa_worm]), float(qp[qa_wheel])
        w1, w2 = float(qv[dof1]), float(qv[dof2])
        t = float(d.time)
        te = guards.state(d, t, th1, th2, w1, w2)
        vs = abs(w1) * geo.r1 / math.cos(geo.gamma)
        mu = mu_of(vs)
        # each contact's force turned about the worm axis onto the line of centres: the radial force DIN 3975's
        # single pitch-point contact means; the force-weighted contact radius and efficiency there (contact_sums)
        if fc is None or fc.displaced:
            if fc is None:
                window = repose_window(bm, th2, window)
                if mu != mu_set:
                    m.geom_friction[coll, 0] = mu_set = mu
                nteeth, pen, p0, F, pw = contact_details(bm, d, window)
            else:
                fc.set_friction(mu)
                nteeth, pen, p0, F, pw = flank_contact_details(fc, d)
                pattern.record(i, d)
            k = min(len(p0), MAX_POINTS)
            pts[i, :k], forces[i, :k], pts_world[i, :k] = p0[:k], F[:k], pw[:k]
            fr_lc, r_c = rlog.add(i, F, pw, geo.a)
        else:  # compiled (wormsim.contact3d.flank_loop)
            fc.set_friction(mu)
            nteeth, pen, fr_lc, r_c = loop.sample(i, pattern, rlog, store)
        guards.contact(t, pen, w1 if worm_is_drive else w2, cmd)
        if slog is not None:
            slog.record(i, d)
        # the mean resultant on the wheel resolved at the pitch point P = (0, -r2, 0) on the line of centres, in the
        # wheel's directions there (DIN 3975 F_t2, F_r2, F_a2; seed 001 resolves ADAMS's contact force the same
        # way): tangential e_t = +x, radial e_r = -y (outward, towards the worm), axial e_z. The contact torque M_z
        # is kept apart: M_z / r2 equals the mean F_t, but by the wheel's torque balance it varies only through
        # I2 alpha2 and hides the mesh
        S_all[:, i] = (  # in SERIES order
            t,  # t_s
            th1,  # worm_angle_rad
            th2,  # wheel_angle_rad
            rad_s_to_rpm(w1),  # worm_speed_rpm
            rad_s_to_rpm(w2),  # wheel_speed_rpm
            t1 / rec,  # worm_torque_nm
            t2 / rec,  # wheel_torque_nm
            cmd,  # drive_command
            fx / rec,  # tangential_force_n
            -fy / rec,  # radial_force_n
            fz / rec,  # axial_force_n
            nc / rec,  # contacts
            nteeth,  # teeth_in_contact
            pen,  # max_penetration_m
            mu,  # friction_coefficient
            te,  # transmission_error_rad
            mz / rec,  # wheel_contact_torque_nm
            p1 / rec,  # worm_power_w
            p2 / rec,  # wheel_power_w
            fpk,  # tangential_force_abs_max_n
            fr_lc,  # radial_force_line_of_centres_n
            r_c,  # worm_contact_radius_m
            0.0,  # efficiency_theory_at_contact_radius: after the loop, from rlog
        )
        if progress is not None:
            progress.update(t)
        i += 1
    S["efficiency_theory_at_contact_radius"][:] = rlog.efficiency(S["friction_coefficient"], geo, worm_is_drive)
    wall = time.perf_counter() - t_wall
    summary = _run_summary(
        S, scenario, bm, rec, guards.turn_max, len(coll), 1e6 * wall / max(n_rec * rec, 1), flanks=fc is not None
    )
    extra = {"points_tooth0": pts, "points_world": pts_world, "forces_world": forces, "built": bm}
    if slog is not None:  # the shafts' deflections and bearing forces
        S.update(slog.series())
        summary.update(slog.summary(S["t_s"], summary["steady_window_s"]))
    if pattern is not None:  # the loaded contact pattern and Hertz stress (flank_outputs)
        summary.update(pattern.summary(S["t_s"], summary["steady_window_s"]))
        extra["flank_pattern"] = pattern.grid(S["t_s"], summary["steady_window_s"])
    summary.update(mass_scaling.run_summary(S, scenario, bm.meta, summary))  # and the ringing guard (exit 3)
    rang = ringing(S, summary, dt, bm.law.stable_limit_s) if fc is not None else None  # flanks (ringing_check)
    if rang is not None:
        raise diverged_error(rang[0], dt, bm, rang[1])
    if bm.kinematic_tca is not None:  # errors: the displaced exact flanks' kinematic TE and play
        kin = bm.kinematic_tca.summary(bm.geometry, gt.working_flank(scenario, bm.geometry.hand))
        summary.update({k: v for k, v in kin.items() if not k.startswith("contact_pattern")})
    return Result(
        model="contact3d", summary=summary, series=S, steps=n_rec * rec, sim_time_s=float(d.time), extra=extra
    )


def _run_summary(
    S: dict,
    scenario: Scenario,
    bm: BuiltModel,
    rec: int,
    turn_max: float,
    collision_geoms: int,
    step_wall_us: float,
    flanks: bool = False,
) -> dict:
    """contact3d_summary plus what the run used: timestep, contact law, friction, window, contact geometry
    (contact.geometry; flank_slices: the flank contacts per tooth flank, None for pieces), cost."""
    law = bm.law
    return {
        **contact3d_summary(S, scenario, bm),
        "scenario": scenario.name,
        "timestep_s": bm.timestep_s,
        "timestep_stable_limit_s": law.stable_limit_s,
        "timestep_source": bm.timestep_source,
        "worm_turn_per_step_max_rad": turn_max,
        "speculative": scenario.simulation.speculative,
        "resolution": scenario.simulation.resolution,
        "integrator": scenario.simulation.integrator,
        "record_every": rec,
        "contact_pair_stiffness_n_per_m": law.pair_stiffness_n_per_m,
        "contact_stiffness_source": law.stiffness_source,
        "contact_exponent_reported": law.exponent,
        "contacts_per_pair_ref": law.contacts_per_pair,
        "contact_damping_requested_n_s_per_m": law.contact_damping_requested_n_s_per_m * law.contacts_per_pair,
        "contact_damping_used_n_s_per_m": law.contact_damping_n_s_per_m * law.contacts_per_pair,
        "contact_damping_ratio": law.damping_ratio,
        "friction": friction_mode(scenario.contact),
        "friction_impratio": law.impratio,
        "window_teeth": bm.window_teeth,
        "collision_geoms": collision_geoms,
        "contact_geometry": bm.meta.get("contact_geometry", "pieces"),
        "flank_slices": law.contacts_per_pair if flanks else None,
        "flank_contacts": bm.meta.get("flank_contacts") if flanks else None,
        "step_wall_us": step_wall_us,
        "piece_error_um": bm.pieces.piece_error_um,
    }


def simulate(scenario: Scenario, progress=None) -> Result:
    """Build the model (its timestep chosen before the build) and run it."""
    jit_warmup.start()  # numba's start-up beside MuJoCo's model compilation (wormsim.contact3d.jit_warmup)
    bm = build_model(scenario)
    if progress is not None and scenario.simulation.mass_scaling != 1:
        progress.note(mass_scaling.note(bm.meta["mass_scaling_check"], scenario.simulation.mass_scaling, bm.timestep_s))
    return run_model(bm, scenario, progress)
