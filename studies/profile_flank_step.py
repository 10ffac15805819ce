"""Stage by stage cost of the compiled exact-flank step (wormsim.contact3d.flank_loop.flank_step) on the unscaled
seat motor at its default step: the same stages, each timed with the thread's CPU clock (clock_gettime through its
address; its own cost per reading, calibrated, is taken off), mj_step2 split into its parts (mj_fwdActuation,
mj_fwdAcceleration, mj_fwdConstraint, mj_sensorAcc, mj_checkAcc, the integrator). Variants of MuJoCo's options
(--variant) run interleaved with the default from the same state (MuJoCo's data and the kernel's buffers copied
back), --rounds times; prints the median us per step per part, the thread's CPU per step, the ratio to the default,
and the solver's iterations and line-search evaluations (sampled every 10th step).

    .venv/bin/python studies/profile_flank_step.py [--rpm 36] [--warm-s 0.05] [--steps 3000] [--rounds 3]
        [--variant tolerance=1e-8] [--set KEY=VALUE ...]
"""

from __future__ import annotations

import argparse
import ctypes
import os
import time

import mujoco
import numba
import numpy as np
from llvmlite import ir
from numba import types
from numba.extending import intrinsic

from wormsim.contact3d import native
from wormsim.contact3d.flank_handoff import fill_add
from wormsim.contact3d.flank_loop import FV, IV, Row, views
from wormsim.contact3d.native import call_stage, f1
from wormsim.tooth.kernel import find_packed
from wormsim.tooth.pose import set_pose
from wormsim.tooth.window import window_centre

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
_LIBC = ctypes.CDLL(None)
CLOCK = int(ctypes.cast(_LIBC.clock_gettime, ctypes.c_void_p).value)
PARTS = (
    "checkPos+checkVel",
    "kinematics",
    "makeM+factorM",
    "collision",
    "kernel (find_packed)",
    "hand-off (fill_add)",
    "makeConstraint",
    "island+transmission+projectConstraint",
    "sensorPos",
    "fwdVelocity+sensorVel",
    "fwdActuation",
    "fwdAcceleration",
    "fwdConstraint (solve)",
    "sensorAcc",
    "checkAcc",
    "integrator",
)
STEP2 = ("mj_fwdActuation", "mj_fwdAcceleration", "mj_fwdConstraint", "mj_sensorAcc", "mj_checkAcc")


@intrinsic
def _call_clock(typingctx, fn, ts_addr):
    sig = types.int32(types.int64, types.int64)

    def codegen(context, builder, signature, args):
        fnty = ir.FunctionType(ir.IntType(32), [ir.IntType(32), ir.IntType(8).as_pointer()])
        f = builder.inttoptr(args[0], fnty.as_pointer())
        return builder.call(f, [ir.Constant(ir.IntType(32), 3), builder.inttoptr(args[1], ir.IntType(8).as_pointer())])

    return sig, codegen


@numba.njit
def _now(fn, ts):
    _call_clock(fn, ts.ctypes.data)
    return ts[0] * 1_000_000_000 + ts[1]


@numba.njit
def calibrate(clk, n):
    """ns per clock reading (n readings back to back)."""
    ts = np.zeros(2, dtype=np.int64)
    t0 = _now(clk, ts)
    for _ in range(n):
        _now(clk, ts)
    return (_now(clk, ts) - t0) / (n + 1)


@numba.njit
def profile(T, m_addr, d_addr, cmd, load, n, fns2, clk, acc):
    """n steps of flank_step's stages (flank_loop.add_flanks inlined, mj_step2 by its parts fns2), acc (PARTS) the
    nanoseconds per part summed."""
    v = views(T)
    ts = np.zeros(2, dtype=np.int64)
    ctrl = f1(T, Row.ctrl)
    iv, fv, state, ks, qpos = v.iv, v.fv, v.state, v.ks, v.qpos
    fns = v.fns
    W, pitch = iv[IV.window_teeth], fv[FV.pitch]
    for j in range(n):
        ctrl[iv[IV.drive_actuator]] = cmd[j]
        ctrl[iv[IV.load_actuator]] = load[j]
        t0 = _now(clk, ts)
        call_stage(fns[0], m_addr, d_addr)
        call_stage(fns[1], m_addr, d_addr)
        t1 = _now(clk, ts)
        acc[0] += t1 - t0
        call_stage(fns[2], m_addr, d_addr)
        t2 = _now(clk, ts)
        acc[1] += t2 - t1
        call_stage(fns[3], m_addr, d_addr)
        call_stage(fns[4], m_addr, d_addr)
        t3 = _now(clk, ts)
        acc[2] += t3 - t2
        call_stage(fns[5], m_addr, d_addr)
        t4 = _now(clk, ts)
        acc[3] += t4 - t3
        th1, th2 = qpos[iv[IV.worm_qpos]], qpos[iv[IV.wheel_qpos]]
        if iv[IV.displaced]:
            set_pose(v.params, v.xpos, v.xmat, iv[IV.worm_body], iv[IV.wheel_body], th1)
        cw = window_centre(th2, fv[FV.tooth0], pitch)
        if cw != state[0]:
            h = W // 2
            for i in range(W):
                ks[i] = cw - h + 1 + i
            state[0] = cw
        ib = v.ib
        nn = find_packed(v.fb, ib, th1, th2, fv[FV.margin], fv[FV.taper])
        state[1] = nn
        t5 = _now(clk, ts)
        acc[4] += t5 - t4
        nh = ib[7] if ib[6] != 0 else nn
        if nh > 0:
            k = min(nh, v.hand.records.shape[0])
            fill_add(
                fns[fns.shape[0] - 1], m_addr, d_addr, v.hand, k, v.out, fv[FV.mu], iv[IV.friction_rows] != 0,
                ib[6] != 0,
            )  # fmt: skip
        t6 = _now(clk, ts)
        acc[5] += t6 - t5
        call_stage(fns[6], m_addr, d_addr)  # makeConstraint
        t7 = _now(clk, ts)
        acc[6] += t7 - t6
        call_stage(fns[7], m_addr, d_addr)
        call_stage(fns[8], m_addr, d_addr)
        call_stage(fns[9], m_addr, d_addr)
        t8 = _now(clk, ts)
        acc[7] += t8 - t7
        call_stage(fns[10], m_addr, d_addr)
        t9 = _now(clk, ts)
        acc[8] += t9 - t8
        call_stage(fns[11], m_addr, d_addr)
        call_stage(fns[12], m_addr, d_addr)
        tp = _now(clk, ts)
        acc[9] += tp - t9
        for s in range(fns2.shape[0]):
            call_stage(fns2[s], m_addr, d_addr)
            tn = _now(clk, ts)
            acc[10 + s] += tn - tp
            tp = tn


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--rpm", type=float, default=36.0)
    ap.add_argument("--warm-s", type=float, default=0.05)
    ap.add_argument("--steps", type=int, default=4000)
    ap.add_argument("--set", action="append", default=[])
    ap.add_argument(
        "--variant",
        action="append",
        default=[],
        help="model.opt FIELD=VALUE[,FIELD=VALUE] (e.g. tolerance=1e-8), interleaved with the default",
    )
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--only", default="", help="run this variant alone (default or one of --variant)")
    a = ap.parse_args()
    from wormsim.contact3d.flank_loop import FlankLoop
    from wormsim.contact3d.flank_step import FlankContacts
    from wormsim.contact3d.mjcf import build_model
    from wormsim.scenario import load_scenario

    sc = load_scenario(
        os.path.join(ROOT, "scenarios", "seat_motor.yaml"),
        [f"drive.speed_rpm={a.rpm}", "contact.geometry=flanks", "simulation.mass_scaling=1", *a.set],
    )
    bm = build_model(sc)
    m = bm.model
    d = mujoco.MjData(m)
    fc = FlankContacts(bm, bm.law.contacts_per_pair)
    native.split_forward(m, d, fc.add)
    s0 = int(m.sensor_adr[mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_SENSOR, "mesh_force")])
    loop = FlankLoop(fc, d, bm.drive_actuator, bm.load_actuator, 0, 1, s0)
    fc.set_friction(0.05)
    dt = m.opt.timestep
    nw = int(round(a.warm_s / dt))
    t = (np.arange(nw + a.steps + 400) + 0.5) * dt
    cmds = bm.plan.commands
    cmd, load = cmds.drive(t), cmds.load(t)
    loop.run(cmd, load, 0, nw)  # into load (compiled loop)
    integ = (
        "mj_implicit"
        if m.opt.integrator in (mujoco.mjtIntegrator.mjINT_IMPLICIT, mujoco.mjtIntegrator.mjINT_IMPLICITFAST)
        else "mj_Euler"
    )
    fns2 = np.array([native.address(s) for s in (*STEP2, integ)], dtype=np.int64)
    T = loop.prepare()
    acc = np.zeros(len(PARTS), dtype=np.int64)
    profile(T, m._address, d._address, cmd[nw:], load[nw:], 20, fns2, CLOCK, acc)  # compile
    per = calibrate(CLOCK, 20000)
    # the start state of every variant's round: MuJoCo's data and the kernel's buffers (memo, window)
    d0 = mujoco.MjData(m)
    mujoco.mj_copyData(d0, m, d)
    k = fc.kernel
    fb0, ib0, st0 = k.fb.copy(), k.ib.copy(), loop.state.copy()
    base = {
        f: getattr(m.opt, f) for f in ("tolerance", "ls_tolerance", "iterations", "ls_iterations", "solver", "jacobian")
    }
    variants = [("default", {})] + [
        (v, dict((kv.split("=")[0], float(kv.split("=")[1])) for kv in v.split(","))) for v in a.variant
    ]
    if a.only:  # one variant alone (e.g. under `perf stat`, whose counts do not depend on the machine's load)
        variants = [x for x in variants if x[0] == a.only]
    chunk = 10
    nst = (a.steps // chunk) * chunk
    res = {name: [] for name, _ in variants}
    for r in range(a.rounds):
        for name, opts in variants if r % 2 == 0 else variants[::-1]:  # ABBA: no variant always first
            for f, val in base.items():
                setattr(m.opt, f, val)
            for f, val in opts.items():
                setattr(m.opt, f, type(getattr(m.opt, f))(val))
            mujoco.mj_copyData(d, m, d0)
            k.fb[:], k.ib[:], loop.state[:] = fb0, ib0, st0
            acc[:] = 0
            niter = neval = 0
            c0 = time.thread_time()
            for j in range(0, nst, chunk):
                profile(T, m._address, d._address, cmd[nw + j :], load[nw + j :], chunk, fns2, CLOCK, acc)
                niter += int(d.solver_niter[0])
                neval += int(sum(d.solver.neval[: d.solver_niter[0]]))
            cpu = time.thread_time() - c0
            us = (acc / nst - per) / 1e3
            res[name].append((1e6 * cpu / nst, us, niter * chunk / nst, neval * chunk / nst, d.nefc))
    print(f"seat motor {a.rpm} rpm, step {dt:.3g} s, {nst} steps from t = {a.warm_s} s, {a.rounds} rounds interleaved")
    print(f"clock reading {per:.0f} ns (taken off each part); load average {os.getloadavg()}")
    names = [n for n, _ in variants]
    print(f"  {'part (median us per step)':40s} " + " ".join(f"{n[:16]:>16s}" for n in names))
    for i, p in enumerate(PARTS):
        print(f"  {p:40s} " + " ".join(f"{np.median([x[1][i] for x in res[n]]):16.2f}" for n in names))
    print(f"  {'sum of parts':40s} " + " ".join(f"{np.median([x[1].sum() for x in res[n]]):16.2f}" for n in names))
    print(
        f"  {'thread CPU per step (median)':40s} "
        + " ".join(f"{np.median([x[0] for x in res[n]]):16.2f}" for n in names)
    )
    print(
        f"  {'ratio to default (median of rounds)':40s} "
        + " ".join(f"{np.median([x[0] / y[0] for x, y in zip(res[n], res[names[0]])]):16.3f}" for n in names)
    )
    print(
        f"  {'solver iterations (sampled)':40s} " + " ".join(f"{np.mean([x[2] for x in res[n]]):16.2f}" for n in names)
    )
    print(
        f"  {'line-search evaluations (sampled)':40s} "
        + " ".join(f"{np.mean([x[3] for x in res[n]]):16.2f}" for n in names)
    )
    print(f"  {'nefc at the end':40s} " + " ".join(f"{res[n][-1][4]:16d}" for n in names))


if __name__ == "__main__":
    main()
