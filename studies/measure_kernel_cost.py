"""Cost of the exact-flank kernel alone (wormsim.tooth.kernel.find_contacts and FlankContacts.find) per call, on
recorded states (issue 13 speed work; docs/contact3d.md, "Exact flanks: cost").

Per seed (medium resolution, 5 ms ramps): the split step runs to load, then one mesh cycle of consecutive states
(theta1, theta2) is recorded (at most MAX_STATES steps; "loaded"), and the same worm angles with the wheel at its
initial offset from the conjugate angle (mid-backlash, no contact: "unloaded"). Each variant is timed over the
states in turn, the seeds and variants interleaved, REPEATS rounds; the best round per variant is reported (the
machine is shared: compare ratios from one run). Variants: `find` = FlankContacts.find as the step calls it;
`find_contacts` = the kernel call alone; with `--ref FILE` also the same two for another version of tooth/kernel.py
(e.g. `git show main:wormsim/tooth/kernel.py > /tmp/flanks_main.py`), whose contacts must equal this one's.

    .venv/bin/python studies/measure_kernel_cost.py [--ref /tmp/flanks_main.py] [--repeats 5]
"""

from __future__ import annotations

import argparse
import importlib.util
import json
import math
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
SEEDS = ("screw_jack", "seat_motor", "involute_41")
MAX_STATES = 2000
STATE_CACHE = Path("/tmp/wormsim_kernel_states")


def record_states(name: str):
    import mujoco

    from wormsim.contact3d.flank_step import FlankContacts
    from wormsim.contact3d.mjcf import build_model
    from wormsim.contact3d.native import split_forward
    from wormsim.physics import gear_theory as gt
    from wormsim.scenario import load_scenario

    sc = load_scenario(
        ROOT / "scenarios" / f"{name}.yaml",
        ["simulation.resolution=medium", "drive.ramp_s=0.005", "load.ramp_s=0.005"],
    )
    bm = build_model(sc)
    STATE_CACHE.mkdir(exist_ok=True)
    f = STATE_CACHE / f"{name}.npz"
    if f.exists():
        z = np.load(f)
        return bm, z["loaded"], z["unloaded"]
    m = bm.model
    d = mujoco.MjData(m)
    fc = FlankContacts(bm, bm.law.contacts_per_pair)
    split_forward(m, d, fc.add)
    th0 = (float(d.qpos[fc.qa1]), float(d.qpos[fc.qa2]))
    cmds = gt.duty(sc, bm.direction).commands
    dt = m.opt.timestep
    warm = int(round(0.012 / dt))
    pitch = 2 * math.pi / bm.geometry.z2
    states = []
    j = 0
    while True:
        t = (j + 0.5) * dt
        d.ctrl[bm.drive_actuator] = cmds.drive(np.array([t]))[0]
        d.ctrl[bm.load_actuator] = cmds.load(np.array([t]))[0]
        fc.step(m, d)
        j += 1
        if j >= warm:
            states.append((float(d.qpos[fc.qa1]), float(d.qpos[fc.qa2])))
            if abs(states[-1][1] - states[0][1]) >= pitch or len(states) >= MAX_STATES:
                break
    loaded = np.array(states)
    ratio = fc.params[12]
    unloaded = np.stack([loaded[:, 0], th0[1] + ratio * (loaded[:, 0] - th0[0])], axis=1)
    np.savez(f, loaded=loaded, unloaded=unloaded)
    return bm, loaded, unloaded


def _load_ref(path: str):
    spec = importlib.util.spec_from_file_location("flanks_ref", path)
    mod = importlib.util.module_from_spec(spec)
    sys.modules["flanks_ref"] = mod
    spec.loader.exec_module(mod)
    return mod


def _ref_find(fc, mod):
    """FlankContacts.find as main has it, with the other module's kernel (no memo)."""

    def find(d):
        th1, th2 = d.qpos[fc.qa1], d.qpos[fc.qa2]
        g = fc.grid
        n = mod.find_contacts(
            g.xy, g.c, g.c_range, g.span, g.zeta, fc.window(th2), th1, th2, fc.margin0, fc.params,
            fc.pos, fc.nrm, fc.depth, fc.meta, fc.line, fc.taper_rad,
        )  # fmt: skip
        fc.n = n = mod.slice_weights(fc.meta, fc.line, n, fc.slices, fc.pos, fc.nrm, fc.depth, fc.weight)
        mod.contact_frames(fc.nrm, n, fc.frame)
        return n

    return find


def main(ref: str | None, repeats: int) -> dict:
    from wormsim.contact3d import flank_step
    from wormsim.contact3d.flank_step import FlankContacts

    refmod = _load_ref(ref) if ref else None
    setups = {}
    for name in SEEDS:
        bm, loaded, unloaded = record_states(name)
        fcs = {"this": FlankContacts(bm, bm.law.contacts_per_pair)}
        off = FlankContacts(bm, bm.law.contacts_per_pair)
        off.kernel.memo_consts[2] = -1.0  # the memo turned off (no memorised slice is young enough)
        fcs["nomemo"] = off
        if refmod is not None:  # the same FlankContacts with the other kernel (its grid, main's find)
            orig_grid = flank_step.flank_grid
            flank_step.flank_grid = refmod.flank_grid
            fc = FlankContacts(bm, bm.law.contacts_per_pair)
            flank_step.flank_grid = orig_grid
            fc.find = _ref_find(fc, refmod)
            fcs["ref"] = fc
        setups[name] = (bm, loaded, unloaded, fcs)

    class _D:  # the two qpos entries find reads
        def __init__(self, n):
            self.qpos = np.zeros(n)

    def run(fc, states, keep):
        d = _D(fc.bm.model.nq)
        fc.memo[0][:] = 0.0  # a cold memo at the first state
        res = []
        t0 = time.perf_counter_ns()
        for th1, th2 in states:
            d.qpos[fc.qa1] = th1
            d.qpos[fc.qa2] = th2
            n = fc.find(d)
            if keep:
                res.append(
                    np.concatenate(
                        [fc.pos[:n].ravel(), fc.nrm[:n].ravel(), fc.depth[:n], fc.weight[:n], fc.meta[:n].ravel()]
                    )
                )
        return (time.perf_counter_ns() - t0) / len(states) / 1e3, res

    result: dict = {"repeats": repeats, "seeds": {}}
    # contacts against the memo-less kernel and the reference first (this also compiles everything)
    for name, (bm, loaded, unloaded, fcs) in setups.items():
        r: dict = {"states": len(loaded)}
        for state_tag, states in (("loaded", loaded), ("unloaded", unloaded)):
            a = run(fcs["this"], states, True)[1]
            r[f"contacts_{state_tag}"] = float(np.mean([len(x) for x in a])) / 12
            for other in [t for t in fcs if t != "this"]:
                b = run(fcs[other], states, True)[1]
                same_n = all(len(x) == len(y) for x, y in zip(a, b))
                pairs = [(x, y) for x, y in zip(a, b) if len(x) == len(y) and len(x)]
                dev = max((float(np.max(np.abs(x - y))) for x, y in pairs), default=0.0)
                r[f"same_count_vs_{other}_{state_tag}"] = same_n
                r[f"max_abs_diff_vs_{other}_{state_tag}"] = dev
        result["seeds"][name] = r
    best: dict = {}
    for _ in range(repeats):
        for name, (bm, loaded, unloaded, fcs) in setups.items():
            for tag, fc in fcs.items():
                for state_tag, states in (("loaded", loaded), ("unloaded", unloaded)):
                    us = run(fc, states, False)[0]
                    key = (name, tag, state_tag)
                    best[key] = min(best.get(key, math.inf), us)
    for (name, tag, state_tag), us in best.items():
        result["seeds"][name][f"find_us_{tag}_{state_tag}"] = round(us, 2)
    return result


if __name__ == "__main__":
    ap = argparse.ArgumentParser()
    ap.add_argument("--ref", default=None)
    ap.add_argument("--repeats", type=int, default=5)
    a = ap.parse_args()
    print(json.dumps(main(a.ref, a.repeats), indent=1))
