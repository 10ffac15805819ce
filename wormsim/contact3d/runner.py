"""contact3d runner: steps the MuJoCo model of wormsim.contact3d.mjcf, reads the tooth forces, guards the run.

`simulate(scenario, progress) -> Result` (the interface of wormsim.run). `run_model` makes the guards
(wormsim.contact3d.guards), the contact source (wormsim.contact3d.sources: the exact flanks or the convex pieces,
behind one interface), the shafts' log (wormsim.contact3d.shafts, with `shafts:`) and the series array
(wormsim.contact3d.series), then `_loop` runs the record intervals: each interval's steps (the drive and load commands
at each step's midpoint; the source sums the actuator torques, the shaft powers T w and the contact sensor's
resultant on the wheel over the steps), then per sample (`_sample`) the state, the guards' checks, mu(Vs) at the
sliding speed Vs = |omega1| r1 / cos(gamma) (wormsim.physics.friction), the source's contact outputs (teeth
touching, largest penetration, contact points in tooth 0's frame, the radial force on the line of centres and the
contact radius), the shafts' log and one series column: forces, moment, contact count, torques and powers are the
MEANS over the interval (a box-car: the 10-80 kHz contact vibration does not alias into the meshing band), angles and
speeds the values at its end. The flank source does all of this compiled (wormsim.contact3d.flank_samples), whole
stretches of samples in one call, and hands back to `_sample` only the samples of its events (a guard that acts, a
service that is due).

After the loop: the summary (wormsim.contact3d.metrics), the source's own keys (the flanks' contact pattern and
pressure), the shafts' series and keys, the mass-scaling check and, above the stable limit, the ringing check
(wormsim.contact3d.ringing_check).
The timestep is the model's, chosen before it was built (wormsim.contact3d.timestep.choose_timestep).
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass

import mujoco
import numpy as np

from wormsim.contact3d import jit_warmup, mass_scaling
from wormsim.contact3d.breakaway import static_utilisation
from wormsim.contact3d.contact_sums import RadiusLog
from wormsim.contact3d.diagnosis import diverged_error
from wormsim.contact3d.guards import Guards, bad_state_warnings
from wormsim.contact3d.metrics import contact3d_summary, contact_radius_check
from wormsim.contact3d.mjcf import BuiltModel, build_model
from wormsim.contact3d.ringing_check import ringing
from wormsim.contact3d.series import SERIES, column
from wormsim.contact3d.shafts import ShaftLog
from wormsim.contact3d.sources import FlankSource, PieceSource
from wormsim.physics.friction import mu_of, stuck_after
from wormsim.physics.locking import Held, held_keys, run_keys
from wormsim.physics.units import RPM
from wormsim.results.metrics import power_source
from wormsim.results.result import Result
from wormsim.results.summary_keys import level_summary
from wormsim.runtime import jit_cache, prewarm
from wormsim.scenario import Scenario, Simulation

MAX_POINTS = 48  # contact points kept per sample (for the pattern and the recording)
TARGET_SAMPLES = 20000  # automatic record_every aims at about this many samples per run (each the mean
# over its interval, so decimation does not alias the contact vibration)


def _record_every(sim: Simulation, dt: float, n_steps: int, scaled: bool = False) -> int:
    if "record_every" in sim.model_fields_set:
        return sim.record_every
    return max(1, n_steps // (mass_scaling.SCALED_SAMPLES if scaled else TARGET_SAMPLES))


def run_model(bm: BuiltModel, progress=None) -> Result:
    """Step the built model over simulation.duration_s at its timestep; sample, guard, summarise (module docstring).
    Everything the run takes from its scenario comes with the model's plan (bm.plan)."""
    m = bm.model
    d = mujoco.MjData(m)
    dt = bm.timestep_s
    plan, sim = bm.plan, bm.plan.gear.simulation
    n_steps = int(round(sim.duration_s / dt))
    rec = _record_every(sim, dt, n_steps, plan.scaling.factor > 1)
    n_rec = n_steps // rec
    guards = Guards(bm, rec)
    S_all = np.zeros((len(SERIES), n_rec))  # one column per sample, written at once
    S = dict(zip(SERIES, S_all))
    store = tuple(np.full((n_rec, MAX_POINTS, 3), np.nan, dtype=np.float32) for _ in range(3))  # p0, F, world p
    rlog = RadiusLog()  # the contacts' radii and weights: the efficiency at the contact radius (contact_sums)
    worm_is_drive = bm.plan.drive_on == "worm"
    s0 = int(m.sensor_adr[mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_SENSOR, "mesh_force")])
    ia_drv, ia_load = bm.drive_actuator, bm.load_actuator
    a1, a2 = (ia_drv, ia_load) if worm_is_drive else (ia_load, ia_drv)  # the worm's and the wheel's actuator
    io = (ia_drv, ia_load, a1, a2, s0)
    flanks = plan.flanks
    slog = ShaftLog(m, bm.meta["shafts"], n_rec) if "shafts" in bm.meta else None  # wormsim.contact3d.shafts
    src = FlankSource(bm, d, io, guards, rec, S_all, store, slog) if flanks else PieceSource(bm, d, io, rec)
    t_wall = time.perf_counter()
    prewarm.loop_started()  # the writers' warm-up thread goes now, beside the GIL-free loop (wormsim.runtime.prewarm)
    held = None
    try:
        _loop(_Loop(src, bm, d, guards, S_all, rlog, store, rec, slog), progress)
    except Held as h:  # a self-locking pair held the back-driving wheel: the run ends there (wormsim.physics.locking)
        held = h
        n_done = int(np.count_nonzero(S_all[0] > 0.0))  # samples written (t_s > 0); the held one is not
        S_all = S_all[:, :n_done]
        S = dict(zip(SERIES, S_all))
        store = tuple(a[:n_done] for a in store)
        rlog.truncate(n_done)
        if flanks:
            src.pattern.truncate(n_done)
        if slog is not None:
            slog.truncate(n_done)
    force_signs(S, bm.geometry.hand)  # into docs/outputs.md's convention
    S["efficiency_theory_at_contact_radius"][:] = rlog.efficiency(S["friction_coefficient"], bm.geometry, worm_is_drive)
    wall = time.perf_counter() - t_wall
    gp = plan.gear
    lock = (
        run_keys(
            gp.duty.drive, gp.rho_static_rad, gp.transition_velocity_m_s, bm.geometry, S["t_s"], S["worm_speed_rpm"]
        )
        if held is None
        else held_keys(S["t_s"], S["worm_speed_rpm"], S["wheel_torque_nm"], held.stuck_since_s or held.t_s)
    )
    lock["drive_peak_torque_nm"] = plan.servo_peak_torque_nm  # the speed drive's limit (gear_theory)
    st_keys, ms, lt = _stiffness_outputs(bm)  # the tooth pair's stiffness and load sharing (torsional's)
    step_wall_us = 1e6 * wall / max(n_rec * rec, 1)
    summary = level_summary(
        "contact3d", _run_summary(S, bm, rec, guards.turn_max, len(src.coll), step_wall_us), lock, st_keys
    )
    _overhauled_contact_radius(S, summary, rlog, bm)
    extra = {"points_tooth0": store[0], "points_world": store[2], "forces_world": store[1], "built": bm}
    extra.update({"mesh_stiffness": ms, "ltca": lt})
    src.finish(S, summary, extra)  # the source's own keys (the flanks' contact pattern and pressure)
    summary = level_summary("contact3d", summary, *_after_run_keys(S, bm, slog, summary))
    rang = ringing(S, summary, dt, bm.law.stable_limit_s) if flanks else None  # flanks (ringing_check)
    if rang is not None:
        raise diverged_error(rang[0], dt, bm, rang[1])
    if bm.kinematic_tca is not None:  # errors: the displaced exact flanks' kinematic TE and play
        kin = bm.kinematic_tca.summary(bm.geometry, bm.plan.duty.working_flank)
        summary = level_summary(
            "contact3d", summary, {k: v for k, v in kin.items() if not k.startswith("contact_pattern")}
        )
    steps = n_rec * rec if held is None else S_all.shape[1] * rec
    return Result(model="contact3d", summary=summary, series=S, steps=steps, sim_time_s=float(d.time), extra=extra)


@dataclass
class _Loop:
    """What the stepping loop writes to and reads from: the contact source, the model and its data, the guards, the
    series array, the radius log, the contact points' store, the samples' steps and the shafts' log (None without
    `shafts:`)."""

    src: object
    bm: BuiltModel
    d: mujoco.MjData
    guards: Guards
    S_all: np.ndarray
    rlog: RadiusLog
    store: tuple
    rec: int
    slog: ShaftLog | None


def _loop(lp: _Loop, progress) -> None:
    """The samples in blocks of about 4096 steps' commands (each step's at its midpoint): the source advances
    (wormsim.contact3d.sources: a flank source runs whole stretches of samples compiled and hands back only the
    samples of its events) and `_sample` does the samples it hands back."""
    bm, d, S_all, rec, src = lp.bm, lp.d, lp.S_all, lp.rec, lp.src
    dt, n_rec = bm.timestep_s, S_all.shape[1]
    cmds = bm.plan.commands
    block = max(1, 4096 // rec)
    i = 0
    while i < n_rec:
        if i % block == 0:
            t_blk = (i * rec + np.arange(min(block, n_rec - i) * rec) + 0.5) * dt
            cmd_arr, load_arr = cmds.drive(t_blk), cmds.load(t_blk)
        i_end = min(n_rec, i - i % block + block)
        i, sums = src.advance(cmd_arr, load_arr, i, i_end, (i % block) * rec, lp.rlog)
        if sums is None:  # samples done up to i
            if progress is not None:
                progress.update(float(S_all[0, i - 1]))
            continue
        cmd = float(cmd_arr[(i % block) * rec + rec - 1])
        _sample(lp, i, cmd, sums)
        if progress is not None:
            progress.update(float(d.time))
        i += 1


def _sample(lp: _Loop, i: int, cmd: float, sums) -> None:
    """Sample i after its steps (cmd the drive command of its last step, sums its steps' sums): the state, the
    guards, mu(Vs), the source's contact outputs, the shafts' log and the series column."""
    bm, d, guards = lp.bm, lp.d, lp.guards
    m, geo = bm.model, bm.geometry
    qp, qv = d.qpos, d.qvel
    th1 = float(qp[m.jnt_qposadr[m.dof_jntid[bm.worm_dof]]])
    th2 = float(qp[m.jnt_qposadr[m.dof_jntid[bm.wheel_dof]]])
    w1, w2 = float(qv[bm.worm_dof]), float(qv[bm.wheel_dof])
    t = float(d.time) if not bad_state_warnings(d) else (i + 1) * lp.rec * bm.timestep_s  # (MuJoCo reset d.time)
    te = guards.state(d, t, th1, th2, w1, w2)
    vs = abs(w1) * geo.r_m1 / math.cos(geo.gamma_m)  # the sliding speed Vs
    # a stuck pair: the share of its static friction that holding the worm needs (wormsim.contact3d.breakaway)
    u = static_utilisation(m, d, bm.worm_dof) if guards.stuck else 0.0
    guards.stuck = stuck_after(guards.stuck, vs, bm.plan.stick_velocity_m_s, u)
    mu = mu_of(0.0 if guards.stuck else vs, bm.plan.mu_law)  # static while stuck (friction.stuck_after)
    # each contact's force turned about the worm axis onto the line of centres: the radial force DIN 3975's
    # single pitch-point contact means; the force-weighted contact radius and efficiency there (contact_sums)
    nteeth, pen, fr_lc, r_c = lp.src.sample(i, th2, mu, lp.rlog, lp.store)
    guards.contact(t, pen, w1 if bm.plan.drive_on == "worm" else w2, cmd, w1)
    if lp.slog is not None:
        lp.slog.record(i, d)
    lp.S_all[:, i] = column((t, th1, th2, w1, w2, cmd), sums, lp.rec, (nteeth, pen, mu, te, fr_lc, r_c), RPM)


def force_signs(S: dict, hand: int) -> None:
    """The samples' forces (e_t = +x, e_r = -y outward, e_z) into the sign convention of docs/outputs.md
    (wormsim.results.summary_keys.FORCE_SIGNS), in place: radial positive towards the wheel axis (separating), axial
    along
    -hand e_z (F_a2 = F_t2 tan(gamma + rho') with its sign, as at torsional)."""
    S["radial_force_n"] *= -1.0
    S["radial_force_line_of_centres_n"] *= -1.0
    S["axial_force_n"] *= -float(hand)


def _after_run_keys(S: dict, bm: BuiltModel, slog: ShaftLog | None, summary: dict) -> tuple[dict, dict]:
    """(the shafts' keys, with their series added to S; the mass scaling's keys and ringing guard) after the run."""
    shaft_keys: dict = {}
    if slog is not None:  # the shafts' deflections and bearing forces
        S.update(slog.series())
        shaft_keys = slog.summary(S["t_s"], summary["steady_window_s"])
    plan = bm.plan
    ine = plan.inertias  # the scaled shafts with the driven machine's inertia
    ine_kg_m2 = (
        ine.worm_inertia_kg_m2 + ine.worm_load_inertia_kg_m2,
        ine.wheel_inertia_kg_m2 + ine.wheel_load_inertia_kg_m2,
    )
    requested = plan.gear.simulation.mass_scaling
    scaling = mass_scaling.run_summary(S, plan.duty, requested, plan.scaling, ine_kg_m2, {**summary, **shaft_keys})
    return shaft_keys, scaling


def _stiffness_outputs(bm: BuiltModel) -> tuple[dict, object, object | None]:
    """wormsim.tooth.stiffness.stiffness_outputs with the law's k' (K = k' b2): the same keys as torsional's, from
    the TCA table at the default sample count (simulation.mesh_stiffness_samples is torsional's); with the TCA and the
    LTCA (None unless the teeth's stiffness is used) for the report."""
    from wormsim.tooth.mesh_stiffness import mesh_stiffness
    from wormsim.tooth.stiffness import per_length_stiffness, stiffness_outputs

    g, gp = bm.geometry, bm.plan.gear
    kp, source = per_length_stiffness(gp.contact, g, gp.materials)
    ms = mesh_stiffness(g, kp, source, Simulation.model_fields["mesh_stiffness_samples"].default)
    keys, lt = stiffness_outputs(
        ms,
        g,
        gp.materials,
        gp.working_wheel_torque_nm,
        gp.duty.working_flank,
        errors=gp.displaced is not None,
    )
    return keys, ms, lt


def _overhauled_contact_radius(S: dict, summary: dict, rlog: RadiusLog, bm: BuiltModel) -> None:
    """An overhauling load (power from the load's shaft, wormsim.results.metrics.power_source): the friction acts
    the other way, so the efficiency at the contacts' radius is the other direction's (the series and its summary
    key, in place); nothing otherwise."""
    drive_on = bm.plan.drive_on
    if power_source(summary["power_flow"], drive_on) == drive_on:
        return
    S["efficiency_theory_at_contact_radius"][:] = rlog.efficiency(
        S["friction_coefficient"], bm.geometry, drive_on != "worm"
    )
    w0, w1 = summary["steady_window_s"]
    summary.update(contact_radius_check(S, (S["t_s"] >= w0) & (S["t_s"] <= w1)))


def _run_summary(S: dict, bm: BuiltModel, rec: int, turn_max: float, collision_geoms: int, step_wall_us: float) -> dict:
    """contact3d_summary plus what the run used: timestep, contact law, friction, window, contact geometry
    (contact.geometry; flank_slices: the flank contacts per tooth flank, None for pieces), cost."""
    law, gp, flanks = bm.law, bm.plan.gear, bm.plan.flanks
    sim = gp.simulation
    return {
        **contact3d_summary(S, bm),
        "scenario": gp.name,
        "timestep_s": bm.timestep_s,
        "timestep_stable_limit_s": law.stable_limit_s,
        "timestep_source": bm.timestep_source,
        "worm_turn_per_step_max_rad": turn_max,
        "speculative": sim.speculative,
        "resolution": sim.resolution,
        "integrator": sim.integrator,
        "record_every": rec,
        "contact_pair_stiffness_n_per_m": law.pair_stiffness_n_per_m,
        "contact_stiffness_source": law.stiffness_source,
        "contact_exponent_reported": law.exponent,
        "contacts_per_pair_ref": law.contacts_per_pair,
        "contact_damping_requested_n_s_per_m": law.contact_damping_requested_n_s_per_m * law.contacts_per_pair,
        "contact_damping_used_n_s_per_m": law.contact_damping_n_s_per_m * law.contacts_per_pair,
        "contact_damping_ratio": law.damping_ratio,
        "friction": gp.friction_mode,
        "friction_impratio": law.impratio,
        "window_teeth": bm.window_teeth,
        "collision_geoms": collision_geoms,
        "contact_geometry": gp.contact.geometry,
        "flank_slices": law.contacts_per_pair if flanks else None,
        "flank_contacts": str(bm.meta.get("flank_contacts")) if flanks else None,
        "step_wall_us": step_wall_us,
        "piece_error_um": bm.pieces.piece_error_um,
    }


def simulate(scenario: Scenario, progress=None) -> Result:
    """Build the model (its timestep chosen before the build) and run it."""
    t0 = time.perf_counter()
    jit_cache.listen()  # the compile seconds counted (the progress line, a sweep's timing)
    jit_cache.ensure_warm(
        warm_runs, getattr(progress, "compiling", None)
    )  # compiled once per machine (wormsim.runtime.jit_cache)
    if progress is not None and time.perf_counter() - t0 > 0.5:  # the estimate's clock starts after the compile
        progress.restart_clock()
    jit_warmup.start()  # numba's start-up beside MuJoCo's model compilation (wormsim.contact3d.jit_warmup)
    bm = build_model(scenario)
    requested = bm.plan.gear.simulation.mass_scaling
    if progress is not None and requested != 1:
        progress.note(mass_scaling.note(bm.plan.scaling, requested, bm.timestep_s))
    res = run_model(bm, progress)
    if scenario.simulation.backdrive_probe:  # a second run with the wheel driving (wormsim.contact3d.backdrive)
        from wormsim.contact3d.backdrive import probe

        res.summary.update(probe(scenario, res.summary, simulate))
    return res


def warm_runs(runs: tuple[tuple[str, tuple[str, ...]], ...] = jit_cache.WARM_RUNS, steps: int | None = None) -> None:
    """The short contact3d runs of `runs` (default wormsim.runtime.jit_cache.WARM_RUNS, the machine's warm-up: every
    compiled entry point with the signatures the runs use), `steps` steps each (default jit_cache.WARM_STEPS)."""
    from wormsim.runtime.data import data_dir
    from wormsim.scenario import load_scenario

    seeds = data_dir("scenarios")
    if runs == jit_cache.WARM_RUNS:  # the flank grid's own compiled trim (a run whose grid is cached never calls it)
        from wormsim.physics.geometry import derive
        from wormsim.tooth import grid

        grid._flank_grid(derive(load_scenario(seeds / "screw_jack.yaml").gear), 2, 6)
    for name, overrides in runs:
        sc = load_scenario(seeds / f"{name}.yaml", ["model=contact3d", *overrides])
        sc.simulation.duration_s = (steps or jit_cache.WARM_STEPS) * (sc.simulation.timestep_s or 1e-4)
        simulate(sc)
    if runs == jit_cache.WARM_RUNS:  # the friction check, due later in a run than the warm-up's steps
        _warm_friction_check()
        _warm_helpers()
        _warm_split_forces()


def _warm_helpers() -> None:
    """The compiled helpers that the screw jack's warm-up runs do not call: H(r)'s table (meshgen.worm_forms.FormTable:
    ZN / ZK / ZC worms) and mu(Vs) called from Python (friction_coefficient_scalar: the Python samples of a run with a
    friction group), each with the types of its callers."""
    import numpy as np

    from meshgen.worm_forms import FormTable
    from meshgen.worm_forms_jit import N_CHEB
    from wormsim.physics.friction import GROUP, GROUPS, mu_at

    FormTable(0.0, 1.0, np.zeros(N_CHEB)).evaluate(0.5)
    mu_at(0.1, GROUP, *(float(x) for x in GROUPS["I"]))


def _box_on_plane():
    """MuJoCo's data of a box resting on a plane after mj_forward (4 contacts): the warm-ups' contact arrays."""
    import mujoco

    m = mujoco.MjModel.from_xml_string(
        "<mujoco><worldbody><geom type='plane' size='1 1 .1'/><body pos='0 0 .09'><freejoint/>"
        "<geom type='box' size='.1 .1 .1'/></body></worldbody></mujoco>"
    )
    d = mujoco.MjData(m)
    mujoco.mj_forward(m, d)
    return d


def _warm_split_forces() -> None:
    """merge.split_forces and kernel.contact_frames as FlankContacts.slice_rows calls them from Python (the merged
    contacts' forces split over their slices and their frames: the per-sample outputs off the compiled loop, e.g. the
    contact pattern's rows), with their argument types: d.contact.efc_address (MuJoCo's strided view), d.efc_force,
    int k0, bool cone3, float64 arrays, int n (a box resting on a plane: 4 contacts, merged into one)."""
    import numpy as np

    from wormsim.tooth.kernel import contact_frames
    from wormsim.tooth.merge import split_forces

    d = _box_on_plane()
    n = int(d.ncon)
    merged = (np.zeros(n), np.full(n, 1.0 / max(n, 1)), np.ones(n), np.ones(n))
    split_forces(d.contact.efc_address, d.efc_force, 0, True, merged, n, (np.zeros(n, np.int64), np.zeros(3 * n)))
    normals = np.tile(np.array([0.0, 0.0, 1.0]), (n, 1))  # unit normals (a zero one divides by zero)
    contact_frames(normals, n, np.zeros((n, 9)))  # the slices' frames after it (FlankContacts.slice_rows)


def _warm_friction_check() -> None:
    """friction_guard.friction_alignment on MuJoCo's contact arrays (a box resting on a plane: 4 contacts)."""
    from wormsim.contact3d.friction_guard import friction_alignment

    d = _box_on_plane()
    friction_alignment(d, 1e-3)
