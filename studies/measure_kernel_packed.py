"""find_packed (kernel.PackedKernel: kernel with its memo, slice_weights, contact frames, and with merge the one
contact per tooth flank) per call on recorded states, this kernel.py against another version of it (--ref FILE, e.g.
`git show main:wormsim/contact3d/kernel.py > /tmp/flanks_main.py`), both modes (per slice, merged). States:
studies/measure_kernel_cost.record_states (medium resolution: screw jack 16, seat motor 32 slices; loaded and unloaded).
Checks that both versions give the same contacts (max abs difference over every output field) and times them
interleaved, best of --repeats rounds (the machine is shared: compare the ratios).

    .venv/bin/python studies/measure_kernel_packed.py --ref /tmp/flanks_main.py [--repeats 5] [--seeds screw_jack]
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
from measure_kernel_cost import _load_ref, record_states  # noqa: E402

FIELDS = ("pos", "nrm", "depth", "weight", "frame", "meta", "line")  # line[:, 0] only through the weight
MFIELDS = ("mpos", "mnrm", "mdepth", "mweight", "mframe", "mfric", "mwrap", "grp", "share")


def _kernels(bm, mod, merge):
    from wormsim.contact3d.flank_step import FlankContacts

    fc = FlankContacts(bm, bm.law.contacts_per_pair, merge=merge)
    k = mod.PackedKernel(fc.grid, fc.params, len(fc.depth), len(fc.ks), bm.geometry.z2, fc.group)
    k.axes[:] = fc.kernel.axes
    return fc, k


def _run(mod, fc, k, states, keep):
    k.memo[:] = 0.0
    out = []
    fp = mod.find_packed
    t0 = time.perf_counter_ns()
    for th1, th2 in states:
        k.ks[:] = fc.window(th2)
        n = fp(k.fb, k.ib, th1, th2, fc.margin0, fc.taper_rad)
        if keep:
            nm = int(k.ib[7])
            a = [getattr(k, f)[:n].copy() for f in FIELDS] + [getattr(k, f)[:nm].copy() for f in MFIELDS]
            a[FIELDS.index("line")] = a[FIELDS.index("line")][:, 1]  # its [:, 0] matters through the weight alone
            out.append(a)
    return (time.perf_counter_ns() - t0) / len(states) / 1e3, out


def main(ref: str, repeats: int, seeds: list[str]) -> dict:
    from wormsim.tooth import kernel

    refmod = _load_ref(ref)
    setups = {}
    for name in seeds:
        bm, loaded, unloaded = record_states(name)
        for merge in (False, True):
            fc, kt = _kernels(bm, kernel, merge)
            _, kr = _kernels(bm, refmod, merge)
            setups[(name, merge)] = (fc, kt, kr, loaded, unloaded)
    res: dict = {"repeats": repeats, "runs": {}}
    for (name, merge), (fc, kt, kr, loaded, unloaded) in setups.items():
        r = {"slices": fc.slices, "states": len(loaded)}
        for tag, states in (("loaded", loaded), ("unloaded", unloaded)):
            a = _run(kernel, fc, kt, states, True)[1]
            b = _run(refmod, fc, kr, states, True)[1]
            r[f"same_counts_{tag}"] = all(len(x[0]) == len(y[0]) and len(x[7]) == len(y[7]) for x, y in zip(a, b))
            dev = 0.0
            for x, y in zip(a, b):
                for u, v in zip(x, y):
                    if len(u) == len(v) and len(u):
                        dev = max(dev, float(np.max(np.abs(u - v))))
            r[f"max_abs_diff_{tag}"] = dev
            r[f"contacts_{tag}"] = float(np.mean([len(x[2]) for x in a]))
        res["runs"][f"{name}_{'tooth' if merge else 'slice'}"] = r
    best: dict = {}
    for _ in range(repeats):
        for (name, merge), (fc, kt, kr, loaded, unloaded) in setups.items():
            for tag, states in (("loaded", loaded), ("unloaded", unloaded)):
                for ver, mod, k in (("this", kernel, kt), ("ref", refmod, kr)):
                    us = _run(mod, fc, k, states, False)[0]
                    key = (f"{name}_{'tooth' if merge else 'slice'}", f"us_{ver}_{tag}")
                    best[key] = min(best.get(key, math.inf), us)
    for (run, key), us in best.items():
        res["runs"][run][key] = round(us, 2)
    for r in res["runs"].values():
        for tag in ("loaded", "unloaded"):
            r[f"speedup_{tag}"] = round(r[f"us_ref_{tag}"] / r[f"us_this_{tag}"], 2)
    return res


if __name__ == "__main__":
    ap = argparse.ArgumentParser()
    ap.add_argument("--ref", required=True)
    ap.add_argument("--repeats", type=int, default=5)
    ap.add_argument("--seeds", nargs="+", default=["screw_jack", "seat_motor"])
    a = ap.parse_args()
    print(json.dumps(main(a.ref, a.repeats, a.seeds), indent=1))
