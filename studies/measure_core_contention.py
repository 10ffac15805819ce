"""Whether a sweep point's CPU seconds grow with both cores busy because of the machine or because of the point: the
same fixed work, run by one process alone and by two processes at once (one per core), for plain CPU-bound loops
that are not ours and for a screw-jack point. Writes docs/data/core_contention.json; docs/sweeps.md renders it.

    .venv/bin/python studies/measure_core_contention.py [--repeats 5] [--record docs/data/core_contention.json]

Workloads (each child process sets up once, then runs the work on "go"; its thread's CPU seconds are timed):
- python: a pure-Python integer loop (no memory traffic: the interpreter's own state, in the core's L1/L2);
- numpy_small: NumPy on 64-element arrays, a fresh result array per call (per-step allocations, as a point's Python
  per step);
- mujoco: mj_step of MuJoCo's sample model (mujoco/testdata/model.xml, shipped with the package), the step
  called from Python;
- mujoco_rollout: mujoco.rollout of the same model (the steps in C, no Python between them);
- stream: a 64 MB NumPy copy (memory bandwidth: beyond the core's caches);
- point: wormsim's simulate() of the screw jack at contact3d (0.15 s simulated, twice, the kernels loaded by one
  warm-up run in the child).
Modes: alone (child 0 pinned to core 0, nothing of ours on core 1), pair (children 0 and 1 pinned to cores 0 and
1, started at once), beside_python and beside_stream (child 0, and on core 1 a neighbour that runs until it is
stopped: a pure-Python loop, or a 64 MB copy). The modes take turns (in order, then reversed) for every workload in
every repeat. The growth of a workload is median CPU(mode) / median CPU(alone) per unit of work: a growth beside any
busy neighbour (the pure-Python loop touches no memory) is the machine's (the two virtual CPUs share a physical
core, or its clock); a growth only beside a twin or the copy is the work's own traffic in the shared caches and
memory. The machine's other work is read from
/proc/stat (busy jiffies of both cores less ours during the measurement, and the hypervisor's steal).
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
KINDS = ("python", "numpy_small", "mujoco", "mujoco_rollout", "stream", "point")


# ----------------------------------------------------------------------------- child


def _setup(kind: str):
    """(work: a callable doing one unit of the workload)."""
    if kind == "python":

        def work():
            s = 0
            for i in range(14_000_000):
                s += i * i % 7
            return s

        return work
    import numpy as np

    if kind == "numpy_small":
        a, b = np.random.default_rng(0).random((2, 64))

        def work():
            x = a
            for _ in range(700_000):
                x = np.sin(x) * b + a
            return float(x.sum())

        return work
    if kind == "stream":
        src = np.ones(8_000_000)
        dst = np.empty_like(src)

        def work():
            for _ in range(180):
                np.copyto(dst, src)
            return float(dst[0])

        return work
    if kind in ("mujoco", "mujoco_rollout"):
        import mujoco

        xml = Path(mujoco.__file__).parent / "testdata" / "model.xml"
        model = mujoco.MjModel.from_xml_path(str(xml))
        data = mujoco.MjData(model)
        steps = 25_000
        if kind == "mujoco":

            def work():
                mujoco.mj_resetData(model, data)
                for _ in range(steps):
                    mujoco.mj_step(model, data)
                return float(data.time)

            return work
        from mujoco import rollout

        mujoco.mj_resetData(model, data)
        state0 = np.zeros(mujoco.mj_stateSize(model, mujoco.mjtState.mjSTATE_FULLPHYSICS))
        mujoco.mj_getState(model, data, state0, mujoco.mjtState.mjSTATE_FULLPHYSICS)

        def work():
            state, _ = rollout.rollout(model, data, state0[None, :], nstep=steps)
            return float(state[0, -1, 0])

        return work
    if kind == "point":
        from wormsim.run import simulate
        from wormsim.scenario import load_scenario

        sc = load_scenario(
            ROOT / "scenarios" / "screw_jack.yaml", overrides=["model=contact3d", "simulation.duration_s=0.15"]
        )
        simulate(sc)  # (the kernels loaded)

        def work():
            return sum(simulate(sc).steps for _ in range(2))

        return work
    raise ValueError(kind)


def child(kind: str, core: int) -> None:
    os.sched_setaffinity(0, {core})
    work = _setup(kind)
    work()  # (first call: caches, allocations)
    print("ready", flush=True)
    for line in sys.stdin:
        if line.strip() != "go":
            break
        c0, t0 = time.thread_time(), time.perf_counter()
        work()
        c1, t1 = time.thread_time(), time.perf_counter()
        print(json.dumps({"cpu_s": c1 - c0, "wall_s": t1 - t0}), flush=True)


# ----------------------------------------------------------------------------- parent


def _cpu_jiffies() -> dict:
    """Busy and steal jiffies of the whole machine (/proc/stat's cpu line)."""
    f = [int(x) for x in Path("/proc/stat").read_text().splitlines()[0].split()[1:]]
    user, nice, system, idle, iowait, irq, softirq, steal = f[:8]
    return {"busy": user + nice + system + irq + softirq, "steal": steal}


class Child:
    def __init__(self, kind: str, core: int):
        self.p = subprocess.Popen(
            [sys.executable, __file__, "--child", kind, "--core", str(core)],
            stdin=subprocess.PIPE,
            stdout=subprocess.PIPE,
            text=True,
            cwd=ROOT,
        )

    def ready(self) -> None:
        line = self.p.stdout.readline()
        if line.strip() != "ready":
            raise RuntimeError(f"child did not start: {line!r}")

    def go(self) -> None:
        self.p.stdin.write("go\n")
        self.p.stdin.flush()

    def result(self) -> dict:
        return json.loads(self.p.stdout.readline())

    def stop(self) -> None:
        self.p.stdin.close()
        self.p.wait(30)


# a neighbour on core 1 that runs until it is stopped: a pure-Python loop (no memory traffic) or a 64 MB copy
SPINNERS = {
    "python": "import os\nos.sched_setaffinity(0, {1})\ns = 0\nwhile True:\n    for i in range(100000):\n"
    "        s += i * i % 7\n",
    "stream": "import os\nos.sched_setaffinity(0, {1})\nimport numpy as np\na = np.ones(8_000_000)\n"
    "b = np.empty_like(a)\nwhile True:\n    np.copyto(b, a)\n",
}


def run_mode(children: list[Child], mode: str) -> dict:
    """mode: alone (child 0), pair (children 0 and 1), beside_python / beside_stream (child 0, a SPINNERS
    neighbour on core 1)."""
    used = children if mode == "pair" else children[:1]
    spinner = None
    if mode.startswith("beside_"):
        spinner = subprocess.Popen([sys.executable, "-c", SPINNERS[mode.removeprefix("beside_")]])
        time.sleep(0.3)  # (its start-up)
    hz = os.sysconf("SC_CLK_TCK")
    j0, t0 = _cpu_jiffies(), time.perf_counter()
    for c in used:
        c.go()
    res = [c.result() for c in used]
    j1, t1 = _cpu_jiffies(), time.perf_counter()
    if spinner is not None:
        spinner.kill()
        spinner.wait()
    wall = t1 - t0
    ours = sum(r["cpu_s"] for r in res) + (wall if spinner is not None else 0.0)  # (the spinner: about a core)
    return {
        "cpu_s": [r["cpu_s"] for r in res],
        "wall_s": [r["wall_s"] for r in res],
        # cores the machine's other processes used meanwhile (of 2), and the hypervisor's steal
        "others_cores": max(0.0, ((j1["busy"] - j0["busy"]) / hz - ours) / wall),
        "steal_cores": (j1["steal"] - j0["steal"]) / hz / wall,
    }


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--child")
    ap.add_argument("--core", type=int, default=0)
    ap.add_argument("--repeats", type=int, default=5)
    ap.add_argument("--kinds", default=",".join(KINDS))
    ap.add_argument("--record", default=str(ROOT / "docs" / "data" / "core_contention.json"))
    args = ap.parse_args()
    if args.child:
        child(args.child, args.core)
        return
    from wormsim.results.provenance import provenance

    kinds = args.kinds.split(",")
    load_before = list(os.getloadavg())
    children = {k: [Child(k, 0), Child(k, 1)] for k in kinds}
    for cs in children.values():
        for c in cs:
            c.ready()
    modes = ("alone", "pair", "beside_python", "beside_stream")
    runs: dict[str, dict[str, list]] = {k: {m: [] for m in modes} for k in kinds}
    for rep in range(args.repeats):
        for k in kinds:
            for mode in modes if rep % 2 == 0 else modes[::-1]:
                runs[k][mode].append(run_mode(children[k], mode))
    for cs in children.values():
        for c in cs:
            c.stop()
    summary = {}
    for k in kinds:
        alone = [r["cpu_s"][0] for r in runs[k]["alone"]]
        pair = [x for r in runs[k]["pair"] for x in r["cpu_s"]]
        summary[k] = {
            "cpu_alone_median_s": statistics.median(alone),
            "cpu_pair_median_s": statistics.median(pair),
            "growth": statistics.median(pair) / statistics.median(alone),
            "growth_best": min(pair) / min(alone),
            **{
                f"growth_{m}": statistics.median(r["cpu_s"][0] for r in runs[k][m]) / statistics.median(alone)
                for m in ("beside_python", "beside_stream")
            },
            "others_cores_alone_median": statistics.median(r["others_cores"] for r in runs[k]["alone"]),
            "others_cores_pair_median": statistics.median(r["others_cores"] for r in runs[k]["pair"]),
            "steal_cores_median": statistics.median(r["steal_cores"] for mode in runs[k].values() for r in mode),
        }
    g = summary.get("point", {}).get("growth")
    rec = {
        "provenance": provenance(
            "python studies/measure_core_contention.py"
            + (f" --repeats {args.repeats}" if args.repeats != 5 else "")
            + (f" --kinds {args.kinds}" if args.kinds != ",".join(KINDS) else "")
        ),
        "what": "the same work by one process alone, by two at once and beside a neighbour on the other core (a "
        "pure-Python loop, a 64 MB copy), each pinned to its core, modes taking turns; CPU seconds of the working "
        "thread",
        "cpu_count": os.cpu_count(),
        "load_average_before": load_before,
        "load_average_after": list(os.getloadavg()),
        "repeats": args.repeats,
        "summary": summary,
        # a CPU-bound point on 2 busy cores runs at 1 / growth of its speed alone: the span's speed-up is at most
        # 2 / growth (no fixed cost, no idle time)
        "span_speedup_bound_2": 2.0 / g if g else None,
        "runs": runs,
    }
    Path(args.record).write_text(json.dumps(rec, indent=1) + "\n")
    print(json.dumps({k: v for k, v in rec.items() if k != "runs"}, indent=1))


if __name__ == "__main__":
    main()
