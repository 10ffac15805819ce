"""Per step (native.split_step, the stages called from Python) and per kernel call (FlankContacts.find), this
kernel.py against another version of it (--ref FILE), both contact modes (per slice, one per tooth flank); seat motor
unscaled (5 us steps, 32 slices) and screw jack (16 slices), medium resolution, 5 ms ramps. Each version runs the
same steps from the same start (the kernels agree, so do the trajectories); versions interleaved, best of --repeats
rounds (the machine is shared: compare the ratios).

    .venv/bin/python studies/measure_kernel_step.py --ref /tmp/flanks_main.py [--steps 3000] [--repeats 3]
"""

from __future__ import annotations

import argparse
import json
import math
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from measure_kernel_cost import ROOT, _load_ref  # noqa: E402

SEEDS = {"seat_motor": ["simulation.mass_scaling=1"], "screw_jack": []}


def _setup(name, extra, merge, mod, warm):
    import mujoco

    from wormsim.contact3d import flank_step, native
    from wormsim.contact3d.mjcf import build_model
    from wormsim.physics import gear_theory as gt
    from wormsim.scenario import load_scenario

    sc = load_scenario(
        ROOT / "scenarios" / f"{name}.yaml",
        ["simulation.resolution=medium", "drive.ramp_s=0.005", "load.ramp_s=0.005", "contact.geometry=flanks"] + extra,
    )
    bm = build_model(sc)
    saved = flank_step.PackedKernel, flank_step.find_packed
    flank_step.PackedKernel, flank_step.find_packed = mod.PackedKernel, mod.find_packed
    try:
        fc = flank_step.FlankContacts(bm, bm.law.contacts_per_pair, merge=merge)
    finally:
        flank_step.PackedKernel, flank_step.find_packed = saved
    m = bm.model
    d = mujoco.MjData(m)
    flank_step.PackedKernel, flank_step.find_packed = mod.PackedKernel, mod.find_packed
    try:
        native.split_forward(m, d, fc.add)
    finally:
        flank_step.PackedKernel, flank_step.find_packed = saved
    cmds = gt.duty(sc, bm.direction).commands
    dt = m.opt.timestep
    t = (np.arange(warm + 100000) + 0.5) * dt
    drive, load = cmds.drive(t), cmds.load(t)
    s = {"mod": mod, "bm": bm, "fc": fc, "m": m, "d": d, "drive": drive, "load": load, "j": 0, "dt": dt}
    _time(s, warm)
    return s


def _time(s, steps):
    """(us per step, us per kernel call (FlankContacts.find inside the steps), contacts per step, final qpos)."""
    from wormsim.contact3d import flank_step, native
    from wormsim.contact3d.flank_handoff import fill_add

    m, d, fc, bm = s["m"], s["d"], s["fc"], s["bm"]
    acc = [0]
    clock = time.perf_counter_ns

    def add(m, d):
        a = clock()
        fc.find(d)
        acc[0] += clock() - a
        n = fc.n_handed()
        if n:
            fr = fc.solreffriction[1] != 0.0
            fill_add(native.MJ_ADD_CONTACT, m._address, d._address, fc.hand, n, fc.handed, fc.mu, fr, fc.merge)

    j0 = s["j"]
    nc = 0
    saved = flank_step.find_packed
    flank_step.find_packed = s["mod"].find_packed
    try:
        t0 = clock()
        for j in range(j0, j0 + steps):
            d.ctrl[bm.drive_actuator], d.ctrl[bm.load_actuator] = s["drive"][j], s["load"][j]
            native.split_step(m, d, add)
            nc += fc.n
        step_us = (clock() - t0) / steps / 1e3
    finally:
        flank_step.find_packed = saved
    s["j"] = j0 + steps
    return step_us, acc[0] / steps / 1e3, nc / steps, d.qpos.copy()


def main(ref: str, steps: int, repeats: int, warm_s: float) -> dict:
    from wormsim.tooth import kernel

    refmod = _load_ref(ref)
    res: dict = {"steps": steps, "repeats": repeats, "runs": {}}
    for name, extra in SEEDS.items():
        for merge in (False, True):
            key = f"{name}_{'tooth' if merge else 'slice'}"
            ss = {}
            for ver, mod in (("ref", refmod), ("this", kernel)):
                s0 = _setup(name, extra, merge, mod, 10)
                warm = int(round(warm_s / s0["dt"]))
                ss[ver] = _setup(name, extra, merge, mod, warm)
            r: dict = {"h_s": ss["this"]["dt"], "slices": ss["this"]["fc"].slices}
            best: dict = {}
            for _ in range(repeats):
                for ver, s in ss.items():
                    st, fu, nc, q = _time(s, steps)
                    best[f"step_us_{ver}"] = min(best.get(f"step_us_{ver}", math.inf), st)
                    best[f"find_us_{ver}"] = min(best.get(f"find_us_{ver}", math.inf), fu)
                    r[f"contacts_{ver}"] = nc
                    r[f"qpos_{ver}"] = q
            r["qpos_max_rel_diff"] = float(np.max(np.abs(r.pop("qpos_this") - (qr := r.pop("qpos_ref"))) / np.abs(qr)))
            r.update({k: round(v, 2) for k, v in best.items()})
            r["step_speedup"] = round(best["step_us_ref"] / best["step_us_this"], 3)
            r["find_speedup"] = round(best["find_us_ref"] / best["find_us_this"], 3)
            res["runs"][key] = r
            print(key, r, flush=True)
    return res


if __name__ == "__main__":
    ap = argparse.ArgumentParser()
    ap.add_argument("--ref", required=True)
    ap.add_argument("--steps", type=int, default=3000)
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--warm-s", type=float, default=0.012)
    a = ap.parse_args()
    print(json.dumps(main(a.ref, a.steps, a.repeats, a.warm_s), indent=1))
