"""A 16-point sweep of 0.3 s screw-jack points at contact3d, run as `wormsim sweep` commands on 1 and on 2 LocalCluster
workers (one after the other, in one run, the kernels' cache warm), the fixed cost per command, and the scaling
model to 16 workers and to a cluster. Writes docs/data/sweep_scaling.json; docs/sweeps.md renders it.

    .venv/bin/python studies/measure_sweep_scaling.py [--out out/sweep_scaling] [--points 16] [--duration 0.3]
        [--repeats 1]

Per command, from its wall time and sweep.json's timing records (worker and client clocks are the same machine's):
- span_s: the first point's start on a worker to the last point's end;
- fixed_s: the command's wall time less span_s (the fork server's preload of the workers' imports and kernels, or
  the client's interpreter, imports and validation where they take longer, the workers' start and connection, the
  tables written, sweep.png beside the cluster's close, the process's exit);
- point_wall_median_s: a point's simulate() on its worker (sweep.csv wall_time_s); step_wall_us: its loop's step;
- point_cpu_median_s: a point's CPU seconds on its worker's thread (sweep.json thread_cpu_s): against the point's
  wall time, what it waited for a core (other processes of the command, or of the machine); against the 1-worker
  run's, whether a point itself runs slower with both cores busy (memory, caches);
- idle_per_point_s: span_s x workers less the points' task time, per point (hand-back, dispatch, imbalance);
- first_point_extra_s: each worker's first point less the median of its others;
- cluster_start_s: sweep.json's cluster start, from the sweep file read (the cluster's thread started) to the
  workers connected (it waits for the fork server, started at the command's start);
- before_first_point_s, after_last_point_s: the command's start to the first point's start (the fork server's
  preload beside the client's interpreter, imports, validation and cluster start; the workers forked and connected)
  and the last point's end to the command's exit (hand-back, csv/json, the cluster's close beside sweep.png, the
  process's end): fixed_s is their sum.
With --repeats R the commands run R times, 1 and 2 workers taking turns, and the record keeps each worker count's
fastest command (the machine is shared: the least disturbed reading) and every command's wall time.
The model (docs/sweeps.md, "Scaling"): T(N) = fixed_s + ceil(P / N) x t_point x g(N), t_point the 1-worker run's
span per point (the point and its idle time), g(N) the step's growth with N busy cores (g(2) measured here).
`--model-only` recomputes the model of an existing record from its runs.
With --standing the commands run on standing clusters instead (`dask scheduler` and `dask worker --nworkers N
--nthreads 1` on this machine, one cluster per worker count, started before the commands and kept between them, the
local cluster's dask settings in their environment): each cluster's first command (its workers load the kernels with
the warm-up plugin) is recorded apart (`first_command_s`) and not timed with the others; the timed commands give
`--scheduler ADDRESS --workers N`. Writes docs/data/sweep_scaling_standing.json.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import statistics
import subprocess
import sys
import time
from pathlib import Path

from wormsim.results.provenance import provenance
from wormsim.sweep.plot import parse_value
from wormsim.sweep.runner import read_csv

ROOT = Path(__file__).resolve().parents[1]
SWEEP = """name: scaling
base: {base}
set: {{model: contact3d, simulation.duration_s: {duration}}}
grid:
  drive.speed_rpm: {{linspace: [1000, 2000, {points}]}}
"""


def measure(out: Path, workers: int, scheduler: str | None = None) -> dict:
    d = out / f"workers{workers}"
    if d.exists():
        for f in d.iterdir():
            f.unlink()
    wormsim = Path(sys.executable).parent / "wormsim"
    t0 = time.perf_counter()
    w0 = time.time()
    subprocess.run(
        [str(wormsim), "sweep", str(out / "scaling.yaml"), "--out", str(d), "--workers", str(workers), "--no-progress"]
        + (["--scheduler", scheduler] if scheduler else []),
        check=True,
    )
    command_wall = time.perf_counter() - t0
    w1 = time.time()
    doc = json.loads((d / "sweep.json").read_text())
    rows = {int(r["point"]): {k: parse_value(v) for k, v in r.items()} for r in read_csv(d / "sweep.csv")}
    tim = {p["point"]: p["timing"] for p in doc["points"]}
    span = max(t["end"] for t in tim.values()) - min(t["start"] for t in tim.values())
    task = [t["end"] - t["start"] for t in tim.values()]
    by_worker: dict[str, list] = {}
    for t in tim.values():
        by_worker.setdefault(t["worker"], []).append((t["start"], t["end"], t.get("compile_s", 0.0)))
    first_extra, compile_s = [], []
    for tasks in by_worker.values():
        tasks.sort()
        walls = [e - s for s, e, _ in tasks]
        if len(walls) > 1:
            first_extra.append(walls[0] - statistics.median(walls[1:]))
        compile_s.append(max(c or 0.0 for _, _, c in tasks))
    n_w = doc["cluster"]["workers"]
    return {
        "workers": n_w,
        "points": len(tim),
        "points_per_task": doc["cluster"].get("points_per_task"),
        "command_wall_s": command_wall,
        "sweep_wall_s": doc["wall_s"],
        "cluster_start_s": doc["cluster"]["start_s"],
        "warm_s": doc["cluster"].get("warm_s"),
        "span_s": span,
        "fixed_s": command_wall - span,
        "before_first_point_s": min(t["start"] for t in tim.values()) - w0,
        "after_last_point_s": w1 - max(t["end"] for t in tim.values()),
        "point_wall_median_s": statistics.median(r["wall_time_s"] for r in rows.values()),
        "step_wall_us_median": statistics.median(r["step_wall_us"] for r in rows.values()),
        "point_cpu_median_s": statistics.median(cpu)
        if (cpu := [t.get("thread_cpu_s") for t in tim.values()]) and None not in cpu
        else None,
        "idle_per_point_s": (span * n_w - sum(task)) / len(tim),
        "first_point_extra_s": first_extra,
        "compile_s_per_worker": compile_s,
        "ok": sum(1 for r in rows.values() if r["status"] == "ok"),
        "load_average_at_start": doc["machine"]["load_average"],
    }


def standing_cluster(out: Path, workers: int) -> tuple[str, list[subprocess.Popen]]:
    """A `dask scheduler` and `dask worker --nworkers workers --nthreads 1` on this machine, with the local cluster's
    dask settings (wormsim.sweep.cluster.LOCAL_DASK_CONFIG) in their environment; returns (address, processes)."""
    from wormsim.sweep.cluster import LOCAL_DASK_CONFIG

    env = dict(os.environ, MUJOCO_GL="disable")
    for key, value in LOCAL_DASK_CONFIG.items():
        env["DASK_" + key.upper().replace(".", "__").replace("-", "_")] = str(value)
    bin_dir = Path(sys.executable).parent
    sf = out / f"scheduler{workers}.json"
    sf.unlink(missing_ok=True)
    log = (out / f"cluster{workers}.log").open("w")
    procs = [
        subprocess.Popen(
            [str(bin_dir / "dask"), "scheduler", "--host", "127.0.0.1", "--port", "0", "--no-dashboard"]
            + ["--scheduler-file", str(sf)],
            env=env,
            stdout=log,
            stderr=log,
        )
    ]
    t0 = time.perf_counter()
    while not sf.exists() and time.perf_counter() - t0 < 60:
        time.sleep(0.1)
    address = json.loads(sf.read_text())["address"]
    procs.append(
        subprocess.Popen(
            [str(bin_dir / "dask"), "worker", address, "--nworkers", str(workers), "--nthreads", "1"]
            + ["--no-dashboard"],
            env=env,
            stdout=log,
            stderr=log,
        )
    )
    return address, procs


def model(runs: dict, workers: int, g: float) -> float:
    """T(N) = fixed_s + ceil(P / N) x t_point x g, from the 1-worker run (module docstring)."""
    r1 = runs["1"]
    return r1["fixed_s"] + math.ceil(r1["points"] / workers) * r1["span_s"] / r1["points"] * g


def models(runs: dict, g2: float) -> dict:
    return {
        "t_point_s": runs["1"]["span_s"] / runs["1"]["points"],
        "T_1_s": model(runs, 1, 1.0),
        "T_2_s": model(runs, 2, g2),
        "T_16_s_no_growth": model(runs, 16, 1.0),
        "T_16_s_growth_1.31": model(runs, 16, 1.31),
    }


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--out", default=str(ROOT / "out" / "sweep_scaling"))
    ap.add_argument("--points", type=int, default=16)
    ap.add_argument("--duration", type=float, default=0.3)
    ap.add_argument("--repeats", type=int, default=1)
    ap.add_argument("--record", default=str(ROOT / "docs" / "data" / "sweep_scaling.json"))
    ap.add_argument("--model-only", action="store_true", help="recompute the model of the existing record")
    ap.add_argument("--standing", action="store_true", help="standing clusters (module docstring)")
    args = ap.parse_args()
    if args.standing and args.record == ap.get_default("record"):
        args.record = str(ROOT / "docs" / "data" / "sweep_scaling_standing.json")
    if args.model_only:
        rec = json.loads(Path(args.record).read_text())
        rec["model"] = models(rec["runs"], rec["step_growth_2"])
        Path(args.record).write_text(json.dumps(rec, indent=1) + "\n")
        return
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    (out / "scaling.yaml").write_text(
        SWEEP.format(base=ROOT / "scenarios" / "screw_jack.yaml", duration=args.duration, points=args.points)
    )
    walls: dict[str, list[float]] = {"1": [], "2": []}
    runs: dict[str, dict] = {}
    schedulers: dict[int, str | None] = {1: None, 2: None}
    first: dict[str, float] = {}
    procs: list[subprocess.Popen] = []
    try:
        if args.standing:
            for n in (1, 2):
                schedulers[n], ps = standing_cluster(out, n)
                procs += ps
            for n in (1, 2):
                first[str(n)] = measure(out, n, schedulers[n])["command_wall_s"]
        for _ in range(args.repeats):
            for n in (1, 2):
                r = measure(out, n, schedulers[n])
                walls[str(n)].append(r["command_wall_s"])
                if str(n) not in runs or r["command_wall_s"] < runs[str(n)]["command_wall_s"]:
                    runs[str(n)] = r
    finally:
        for p in procs[::-1]:
            p.terminate()
        for p in procs:
            p.wait(timeout=30)
    g2 = runs["2"]["step_wall_us_median"] / runs["1"]["step_wall_us_median"]
    rec = {
        "provenance": provenance(
            "python studies/measure_sweep_scaling.py"
            + (" --standing" if args.standing else "")
            + (f" --repeats {args.repeats}" if args.repeats > 1 else "")
        ),
        "load_average_after": list(os.getloadavg()),
        "what": f"{args.points} contact3d screw-jack points ({args.duration} s, 1000-2000 rpm), `wormsim sweep` "
        + (
            "commands with `--scheduler` on standing clusters of 1 and 2 workers (`dask scheduler`, `dask worker "
            "--nthreads 1`; each cluster's first command not timed)"
            if args.standing
            else "commands on a LocalCluster of 1 then 2 workers"
        )
        + ", the kernels' cache warm"
        + (f", {args.repeats} times each taking turns, the fastest kept" if args.repeats > 1 else ""),
        "cpu_count": os.cpu_count(),
        "repeats": args.repeats,
        "command_walls_s": walls,
        **({"first_command_s": first} if first else {}),
        "runs": runs,
        "speedup_command": runs["1"]["command_wall_s"] / runs["2"]["command_wall_s"],
        "speedup_span": runs["1"]["span_s"] / runs["2"]["span_s"],
        "step_growth_2": g2,
        "point_cpu_growth_2": (
            runs["2"]["point_cpu_median_s"] / runs["1"]["point_cpu_median_s"]
            if runs["1"].get("point_cpu_median_s") and runs["2"].get("point_cpu_median_s")
            else None
        ),
        "model": models(runs, g2),
    }
    Path(args.record).write_text(json.dumps(rec, indent=1) + "\n")
    print(json.dumps({k: v for k, v in rec.items() if k != "runs"}, indent=1))


if __name__ == "__main__":
    main()
