"""Where the unscaled seat motor's CPU goes at its defaults (issue 33 item 4: at most 10 s per simulated second):
scenarios/seat_motor.yaml, contact3d, exact flanks, `contact.flank_contacts: 4`, 32 slices, medium, its 6.4 us
step, samples as the 20 s run records them (record_every 156).

1. The whole run (wormsim.contact3d.runner.run_model over --seconds simulated from rest, warm caches): CPU seconds of
   the stepping thread (time.thread_time: the compiled loop runs in it), split into the stepping loop
   (runner._loop: the compiled steps and samples, the Python between the compiled stretches) and the rest (the
   source's set-up, the summary and the contact pattern after the loop).
2. The compiled step from --warm-s on, stage by stage (studies/profile_flank_step.profile: each stage timed with
   the thread's CPU clock inside the compiled step, the clock's own cost per reading taken off): the flank kernel
   (wormsim.tooth.kernel.find_packed), the hand-off (mj_addContact), MuJoCo's stages (mj_makeConstraint, the
   solve mj_fwdConstraint, the rest), --rounds rounds from the same state.
The loop's CPU per step less the compiled step's stages (without the clock readings) is what the loop spends outside
the step: the samples (compiled), the Python between the compiled stretches and numba's dispatch.

    .venv/bin/python studies/profile_seat_motor.py [--seconds 0.1] [--warm-s 0.05] [--steps 3000] [--rounds 3]
        [--record seat_motor_profile]
"""

from __future__ import annotations

import argparse
import os
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
SPEED = ["contact.geometry=flanks", "simulation.mass_scaling=1", "simulation.record_every=156"]
# the profile's parts (profile_flank_step.PARTS) grouped for the record
GROUPS = {
    "kernel (find_packed)": ("kernel (find_packed)",),
    "hand-off (fill_add, mj_addContact)": ("hand-off (fill_add)",),
    "mj_makeConstraint": ("makeConstraint",),
    "constraint solve (mj_fwdConstraint)": ("fwdConstraint (solve)",),
    "MuJoCo's other stages": (
        "checkPos+checkVel",
        "kinematics",
        "makeM+factorM",
        "collision",
        "island+transmission+projectConstraint",
        "sensorPos",
        "fwdVelocity+sensorVel",
        "fwdActuation",
        "fwdAcceleration",
        "sensorAcc",
        "checkAcc",
        "integrator",
    ),
}


def whole_run(seconds: float) -> dict:
    """The seat motor's run_model over `seconds`: thread CPU of the run and of its stepping loop, steps, samples."""
    from wormsim.contact3d import runner
    from wormsim.contact3d.mjcf import build_model
    from wormsim.scenario import load_scenario

    spent = {"loop": 0.0}
    inner = runner._loop

    def timed(lp, progress):
        c0 = time.thread_time()
        try:
            inner(lp, progress)
        finally:
            spent["loop"] += time.thread_time() - c0

    bm = build_model(
        load_scenario(ROOT / "scenarios" / "seat_motor.yaml", [*SPEED, f"simulation.duration_s={seconds}"])
    )
    runner._loop = timed
    try:
        c0 = time.thread_time()
        res = runner.run_model(bm)
        cpu = time.thread_time() - c0
    finally:
        runner._loop = inner
    s = res.summary
    return {
        "cpu_s": cpu,
        "loop_cpu_s": spent["loop"],
        "sim_s": res.sim_time_s,
        "steps": res.steps,
        "record_every": s["record_every"],
        "timestep_s": s["timestep_s"],
        "flank_contacts": s["flank_contacts"],
        "flank_slices": s["flank_slices"],
        "contacts_mean": s["contacts_mean"],
        "cpu_s_per_sim_s": cpu / res.sim_time_s,
        "loop_cpu_s_per_sim_s": spent["loop"] / res.sim_time_s,
        "loop_us_per_step": 1e6 * spent["loop"] / res.steps,
    }


def _compiled_loop():
    """(bm, model, data, FlankContacts, FlankLoop) of the seat motor at SPEED, its contacts at mu 0.05, from rest."""
    import mujoco

    from wormsim.contact3d import native
    from wormsim.contact3d.flank_loop import FlankLoop
    from wormsim.contact3d.flank_step import FlankContacts
    from wormsim.contact3d.mjcf import build_model
    from wormsim.scenario import load_scenario

    bm = build_model(load_scenario(ROOT / "scenarios" / "seat_motor.yaml", SPEED))
    m = bm.model
    d = mujoco.MjData(m)
    fc = FlankContacts(bm, bm.law.contacts_per_pair)
    native.split_forward(m, d, fc.add)
    s0 = int(m.sensor_adr[mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_SENSOR, "mesh_force")])
    loop = FlankLoop(fc, d, bm.drive_actuator, bm.load_actuator, 0, 1, s0)
    fc.set_friction(0.05)
    return bm, m, d, fc, loop


def table_run(seconds: float) -> float:
    """us per step of the compiled steps alone (FlankLoop.run: run_table with its per-step sums, no samples) over the
    whole run's window, 0..seconds from rest, in one call."""
    bm, m, d, _, loop = _compiled_loop()
    n = int(round(seconds / m.opt.timestep))
    t = (np.arange(n) + 0.5) * m.opt.timestep
    cmd, load = bm.plan.commands.drive(t), bm.plan.commands.load(t)
    c0 = time.thread_time()
    loop.run(cmd, load, 0, n)
    return 1e6 * (time.thread_time() - c0) / n


def step_split(warm_s: float, steps: int, rounds: int) -> dict:
    """The compiled step's stages (profile_flank_step.profile) over `steps` steps from t = warm_s, `rounds` rounds
    from the same state: the median us per step per part, the thread's CPU per step with and without the clock
    readings, the solver's iterations and line-search evaluations, the MuJoCo contacts and rows."""
    import mujoco

    sys.path.insert(0, str(ROOT / "studies"))
    from profile_flank_step import CLOCK, PARTS, STEP2, calibrate, profile

    from wormsim.contact3d import native

    bm, m, d, fc, loop = _compiled_loop()
    dt = m.opt.timestep
    nw = int(round(warm_s / dt))
    t = (np.arange(nw + steps + 400) + 0.5) * dt
    cmd, load = bm.plan.commands.drive(t), bm.plan.commands.load(t)
    loop.run(cmd, load, 0, nw)
    implicit = (mujoco.mjtIntegrator.mjINT_IMPLICIT, mujoco.mjtIntegrator.mjINT_IMPLICITFAST)
    integ = "mj_implicit" if m.opt.integrator in implicit else "mj_Euler"
    fns2 = np.array([native.address(s) for s in (*STEP2, integ)], dtype=np.int64)
    T = loop.prepare()
    acc = np.zeros(len(PARTS), dtype=np.int64)
    profile(T, m._address, d._address, cmd[nw:], load[nw:], 20, fns2, CLOCK, acc)  # compile
    per = calibrate(CLOCK, 20000)
    d0 = mujoco.MjData(m)
    mujoco.mj_copyData(d0, m, d)
    k = fc.kernel
    fb0, ib0, st0 = k.fb.copy(), k.ib.copy(), loop.state.copy()
    chunk = 10
    nst = (steps // chunk) * chunk
    parts, cpu, niter, neval, table = [], [], [], [], []
    for _ in range(rounds):
        # the compiled loop's steps alone (FlankLoop.run: run_table, the per-step sums, no samples)
        mujoco.mj_copyData(d, m, d0)
        k.fb[:], k.ib[:], loop.state[:] = fb0, ib0, st0
        c0 = time.thread_time()
        loop.run(cmd, load, nw, nw + nst)
        table.append(1e6 * (time.thread_time() - c0) / nst)
        mujoco.mj_copyData(d, m, d0)
        k.fb[:], k.ib[:], loop.state[:] = fb0, ib0, st0
        acc[:] = 0
        it = ev = 0
        c0 = time.thread_time()
        for j in range(0, nst, chunk):
            profile(T, m._address, d._address, cmd[nw + j :], load[nw + j :], chunk, fns2, CLOCK, acc)
            it += int(d.solver_niter[0])
            ev += int(sum(d.solver.neval[: d.solver_niter[0]]))
        cpu.append(1e6 * (time.thread_time() - c0) / nst)
        parts.append((acc / nst - per) / 1e3)
        niter.append(it * chunk / nst)
        neval.append(ev * chunk / nst)
    med = np.median(np.array(parts), axis=0)
    by_part = dict(zip(PARTS, med.tolist()))
    readings = 11 + len(fns2)  # clock readings per step in profile(): 11, then one after each of mj_step2's parts
    return {
        "from_s": warm_s,
        "steps": nst,
        "rounds": rounds,
        "clock_reading_ns": per,
        "parts_us": by_part,
        "groups_us": {g: sum(by_part[p] for p in ps) for g, ps in GROUPS.items()},
        "sum_of_parts_us": float(med.sum()),
        "thread_cpu_us_per_step": float(np.median(cpu)),
        "run_table_us_per_step": float(np.median(table)),
        "clock_readings_per_step": readings,
        "thread_cpu_us_per_step_without_clock": float(np.median(cpu)) - readings * per / 1e3,
        "solver_iterations": float(np.mean(niter)),
        "line_search_evaluations": float(np.mean(neval)),
        "mujoco_contacts": int(d.ncon),
        "constraint_rows": int(d.nefc),
        "slice_contacts": int(loop.state[1]),
    }


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seconds", type=float, default=0.1)
    ap.add_argument("--warm-s", type=float, default=0.05)
    ap.add_argument("--steps", type=int, default=3000)
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--record", default="")
    a = ap.parse_args()
    sys.path.insert(0, str(ROOT))
    from wormsim.results.provenance import provenance, record

    load0 = os.getloadavg()
    whole_run(0.002)  # warm: numba's cache, the flank grid
    runs, tables = [], []
    for r in range(a.rounds):  # interleaved (the shared machine's speed drifts): the whole run, its steps alone
        for which in ("run", "table") if r % 2 == 0 else ("table", "run"):
            if which == "run":
                runs.append(whole_run(a.seconds))
            else:
                tables.append(table_run(a.seconds))
    run = {k: float(np.median([x[k] for x in runs])) if isinstance(runs[0][k], float) else runs[0][k] for k in runs[0]}
    run["rounds_cpu_s_per_sim_s"] = [x["cpu_s_per_sim_s"] for x in runs]
    table_us = float(np.median(tables))
    outside = [x["loop_us_per_step"] - y for x, y in zip(runs, tables)]
    print(
        f"whole run: {run['cpu_s_per_sim_s']:.2f} CPU s per simulated s, loop {run['loop_cpu_s_per_sim_s']:.2f}"
        f" ({run['loop_us_per_step']:.1f} us per step), run_table over the same window {table_us:.1f} us per step",
        flush=True,
    )
    split = step_split(a.warm_s, a.steps, a.rounds)
    for g, us in split["groups_us"].items():
        print(f"  {g:40s} {us:7.2f} us per step")
    print(f"  {'sum of the stages':40s} {split['sum_of_parts_us']:7.2f}")
    print(f"  run_table (the compiled steps, no samples) {split['run_table_us_per_step']:.2f} us per step")
    print(f"  thread CPU per step {split['thread_cpu_us_per_step']:.2f} us, without the clock readings "
          f"{split['thread_cpu_us_per_step_without_clock']:.2f} us")  # fmt: skip
    out = {
        "what": "the unscaled seat motor at its defaults (exact flanks, 4 contacts per flank, 32 slices, medium, "
        "6.4 us step, record_every 156): the whole run's CPU s per simulated s and its stepping loop's; the "
        "compiled step's stages (us per step, median of rounds, the clock readings' cost taken off)",
        "seconds": a.seconds,
        "load_average_at_start": load0,
        "load_average_after": os.getloadavg(),
        "run": run,
        "run_table_whole_window_us_per_step": table_us,
        "run_table_rounds_us_per_step": tables,
        "step": split,
        "samples_and_python_us_per_step": float(np.median(outside)),
        "samples_and_python_rounds_us_per_step": outside,
    }
    print(f"  loop outside the compiled steps: {out['samples_and_python_us_per_step']:.2f} us per step")
    if a.record:
        cmd = "python studies/profile_seat_motor.py" + "".join(f" {x}" for x in sys.argv[1:])
        record(a.record, out, prov=provenance(cmd))


if __name__ == "__main__":
    main()
