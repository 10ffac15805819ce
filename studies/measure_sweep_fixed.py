"""The fixed cost of a `wormsim sweep` command, this checkout against another (an earlier commit's source tree), in
one run, the commands taking turns. Writes docs/data/sweep_fixed_cost.json; docs/sweeps.md renders it.

    .venv/bin/python studies/measure_sweep_fixed.py --compare BASE_DIR [--label-compare 5c5cb29] [--repeats 6]

BASE_DIR holds the other source tree (e.g. `git archive 5c5cb29 | tar -x -C BASE_DIR`); its code runs with this
virtual environment through PYTHONPATH (its kernels' cache is its own: warm it first with `make`'s warm-up command
under the same PYTHONPATH). The trees take turns (in order, then reversed), first --preload-repeats times:
- preload: the CPU seconds (user + system) of a process that imports wormsim.sweep.preload_warm, the local cluster's
  fork server's work before it forks the first worker (the workers' imports, numba's start-up, the kernels loaded,
  the short run): the path before a sweep's first point on a machine with a core free beside the client;
then --worker-repeats times:
- workers: a local cluster of --workers workers started as the sweep starts it (the warm fork server, the warm-up
  plugin), one short screw-jack point per worker; each worker process's CPU seconds less its point's thread CPU
  seconds: what a worker costs between its fork and its first point (start, registration, the first task unpickled),
  averaged over the workers;
then --repeats times:
- command: a sweep of --points screw-jack points of --duration s at contact3d on --workers workers, its wall time,
  the time before its first point and after its last (sweep.json's timing), fixed = command less the points' span.
Each tree's medians, and the ratio this / other of the medians (CPU seconds hold on a shared machine; wall times
only where it is quiet: the record keeps the load average).
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import statistics
import subprocess
import sys
import time
from pathlib import Path

from wormsim.results.provenance import provenance

ROOT = Path(__file__).resolve().parents[1]
SWEEP = """name: fixed
base: {base}
set: {{model: contact3d, simulation.duration_s: {duration}}}
grid:
  drive.speed_rpm: {{linspace: [1000, 2000, {points}]}}
"""


def _env(tree: Path) -> dict:
    env = dict(os.environ)
    env["PYTHONPATH"] = str(tree)
    return env


def preload_cpu(tree: Path) -> float:
    """CPU seconds of a fresh process importing the fork server's warm preload from `tree`."""
    r0 = resource.getrusage(resource.RUSAGE_CHILDREN)
    subprocess.run([sys.executable, "-c", "import wormsim.sweep.preload_warm"], env=_env(tree), check=True, cwd=tree)
    r1 = resource.getrusage(resource.RUSAGE_CHILDREN)
    return (r1.ru_utime - r0.ru_utime) + (r1.ru_stime - r0.ru_stime)


# run with PYTHONPATH=tree: argv scenario, workers; prints the workers' mean CPU seconds outside their points
WORKER_PROBE = """
import inspect, json, os, sys
from wormsim.scenario import load_scenario
from wormsim.sweep.cluster import close_cluster, open_client, start_fork_server, warm_workers
from wormsim.sweep.runner import run_point


def cpu():
    t = os.times()
    return t.user + t.system


start_fork_server(True)
kw = {"warm": True} if "warm" in inspect.signature(open_client).parameters else {}
client, cluster, info = open_client(None, int(sys.argv[2]), **kw)
try:
    warm_workers(client, info)
    sc = load_scenario(sys.argv[1], ["model=contact3d", "simulation.duration_s=0.01"]).model_dump(mode="json")
    futs = [client.submit(run_point, sc, False, pure=False, key=f"probe-{i}") for i in range(info["workers"])]
    res = client.gather(futs)
    cpus = client.run(cpu)
finally:
    close_cluster(client, cluster)
print(json.dumps((sum(cpus.values()) - sum(r["timing"]["thread_cpu_s"] for r in res)) / len(cpus)))
"""


def worker_cpu(tree: Path, workers: int) -> float:
    """The mean CPU seconds of a local cluster's workers outside their points (WORKER_PROBE) with `tree`'s code."""
    cp = subprocess.run(
        [sys.executable, "-c", WORKER_PROBE, str(ROOT / "scenarios" / "screw_jack.yaml"), str(workers)],
        env=_env(tree),
        check=True,
        cwd=tree,
        capture_output=True,
        text=True,
    )
    return float(cp.stdout.splitlines()[-1])


def command(tree: Path, sweep: Path, out: Path, workers: int) -> dict:
    if out.exists():
        for f in out.iterdir():
            f.unlink()
    w0, t0 = time.time(), time.perf_counter()
    subprocess.run(
        [sys.executable, "-m", "wormsim", "sweep", str(sweep), "--out", str(out), "--workers", str(workers)]
        + ["--no-progress"],
        env=_env(tree),
        check=True,
        cwd=tree,
        stdout=subprocess.DEVNULL,
    )
    wall, w1 = time.perf_counter() - t0, time.time()
    tim = [p["timing"] for p in json.loads((out / "sweep.json").read_text())["points"]]
    first, last = min(t["start"] for t in tim), max(t["end"] for t in tim)
    return {
        "command_s": wall,
        "before_first_point_s": first - w0,
        "after_last_point_s": w1 - last,
        "fixed_s": wall - (last - first),
    }


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--compare", required=True, help="the other source tree")
    ap.add_argument("--label-compare", default="compare")
    ap.add_argument("--repeats", type=int, default=6, help="commands per tree")
    ap.add_argument("--preload-repeats", type=int, default=10, help="preload processes per tree")
    ap.add_argument("--worker-repeats", type=int, default=4, help="worker probes per tree")
    ap.add_argument("--points", type=int, default=4)
    ap.add_argument("--duration", type=float, default=0.05)
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--out", default=str(ROOT / "out" / "sweep_fixed"))
    ap.add_argument("--record", default=str(ROOT / "docs" / "data" / "sweep_fixed_cost.json"))
    args = ap.parse_args()
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    sweep = out / "fixed.yaml"
    sweep.write_text(
        SWEEP.format(base=ROOT / "scenarios" / "screw_jack.yaml", duration=args.duration, points=args.points)
    )
    trees = {"this": ROOT, args.label_compare: Path(args.compare).resolve()}
    load_before = list(os.getloadavg())
    runs: dict[str, list[dict]] = {k: [] for k in trees}
    preload: dict[str, list[float]] = {k: [] for k in trees}
    for rep in range(args.preload_repeats):
        for name in trees if rep % 2 == 0 else list(trees)[::-1]:
            preload[name].append(preload_cpu(trees[name]))
    wcpu: dict[str, list[float]] = {k: [] for k in trees}
    for rep in range(args.worker_repeats):
        for name in trees if rep % 2 == 0 else list(trees)[::-1]:
            wcpu[name].append(worker_cpu(trees[name], args.workers))
    for rep in range(args.repeats):
        for name in trees if rep % 2 == 0 else list(trees)[::-1]:
            runs[name].append(command(trees[name], sweep, out / name, args.workers))
    keys = ("command_s", "before_first_point_s", "after_last_point_s", "fixed_s")
    med = {
        n: {
            "preload_cpu_s": statistics.median(preload[n]),
            **({"worker_cpu_s": statistics.median(wcpu[n])} if wcpu[n] else {}),
            **{k: statistics.median(r[k] for r in rs) for k in keys},
        }
        for n, rs in runs.items()
    }
    keys = ("preload_cpu_s", *(("worker_cpu_s",) if args.worker_repeats else ()), *keys)
    rec = {
        "provenance": provenance(
            f"python studies/measure_sweep_fixed.py --compare TREE_OF_{args.label_compare} "
            f"--label-compare {args.label_compare} --repeats {args.repeats} --preload-repeats {args.preload_repeats} "
            f"--worker-repeats {args.worker_repeats}"
        ),
        "what": f"`wormsim sweep` of {args.points} contact3d screw-jack points ({args.duration} s) on {args.workers} "
        f"workers ({args.repeats} each), the fork server's preload ({args.preload_repeats} each) and the workers' CPU "
        f"outside their first points ({args.worker_repeats} clusters each), this checkout "
        f"against {args.label_compare}, taking turns",
        "cpu_count": os.cpu_count(),
        "load_average_before": load_before,
        "load_average_after": list(os.getloadavg()),
        "medians": med,
        "ratio_this_over_compare": {k: med["this"][k] / med[args.label_compare][k] for k in keys},
        "preload_cpu_s": preload,
        "worker_cpu_s": wcpu,
        "runs": runs,
    }
    Path(args.record).write_text(json.dumps(rec, indent=1) + "\n")
    print(json.dumps({k: v for k, v in rec.items() if k != "runs"}, indent=1))


if __name__ == "__main__":
    main()
