"""The compiled kernels' cold compile, function by function (issue 33, docs/decisions/0047-compiled-specialisations.md):
on an empty cache folder (a fresh WORMSIM_JIT_CACHE, set here), the set-up's warm-up
(wormsim.contact3d.runner.warm_runs) and then short runs of other kinds (one contact per tooth flank, a ZK worm, the
demo), each compile timed from numba's "numba:compile" events in the compiling thread's CPU seconds (a shared
machine's load inflates the wall, not these), with and without the functions it compiled inside it (`self_s`,
`incl_s`), and every compiled function's signatures. A run of another kind that compiles anything after the warm-up
is a specialisation the warm-up misses.

    .venv/bin/python studies/compile_profile.py [--json FILE]
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
AFTER = (
    ("tooth", "seat_motor", ["model=contact3d", "contact.flank_contacts=tooth"]),
    ("ZK", "screw_jack", ["model=contact3d", "gear.profile=ZK"]),
    ("demo", "seat_motor_demo", ["model=contact3d"]),
)


def main() -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("--json", type=Path, help="write the records here")
    a = ap.parse_args()
    os.environ.pop("NUMBA_CACHE_DIR", None)
    os.environ["WORMSIM_JIT_CACHE"] = tempfile.mkdtemp(prefix="wormsim-jit-")  # before wormsim is imported

    from numba.core import event

    import wormsim  # noqa: F401  (points numba at the empty folder)

    recs: list[dict] = []
    stack: list[list] = []

    class Timer(event.Listener):
        def on_start(self, ev):
            f = ev.data["dispatcher"].py_func
            stack.append([f"{f.__module__}.{f.__qualname__}", time.thread_time(), 0.0])

        def on_end(self, ev):
            name, c0, inner = stack.pop()
            dc = time.thread_time() - c0
            if stack:
                stack[-1][2] += dc
            recs.append({"fn": name, "incl_s": dc, "self_s": dc - inner, "depth": len(stack)})

    event.register("numba:compile", Timer())
    from wormsim.contact3d.runner import simulate, warm_runs
    from wormsim.scenario import load_scenario

    phases = {}
    warm_runs()
    phases["warm-up"] = [r for r in recs if r["depth"] == 0]
    for tag, name, sets in AFTER:
        n0 = len(recs)
        sc = load_scenario(ROOT / "scenarios" / f"{name}.yaml", sets)
        sc.simulation.duration_s = 0.003
        simulate(sc)
        phases[tag] = [r for r in recs[n0:] if r["depth"] == 0]
    from numba.core.registry import CPUDispatcher

    sigs = {}
    for mname, mod in list(sys.modules.items()):
        if mod is not None and mname.startswith(("wormsim", "meshgen")):
            for x in list(vars(mod).values()):
                if isinstance(x, CPUDispatcher) and x.__module__ == mname and x.signatures:
                    sigs[f"{mname}.{x.py_func.__qualname__}"] = [str(s) for s in x.signatures]
    print("CPU s compiling (outermost compiles) per phase:")
    for tag, rs in phases.items():
        names = sorted({r["fn"] for r in rs}) if tag != "warm-up" else ""
        print(f"  {tag:8s} {sum(r['incl_s'] for r in rs):6.1f}  {names}")
    print("functions by their own compile CPU s (self, with callees):")
    for r in sorted(recs, key=lambda r: -r["self_s"])[:25]:
        print(f"  {r['self_s']:6.2f} {r['incl_s']:6.2f}  {r['fn']}")
    multi = {k: v for k, v in sigs.items() if len(v) > 1}
    print(f"compiled functions {len(sigs)}, with more than one signature: {multi or 'none'}")
    if a.json:
        a.json.write_text(json.dumps({"phases": phases, "signatures": sigs}, indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
