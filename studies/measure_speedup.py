"""Speed-up of a sweep of 8 torsional points on 1 and on 2 LocalCluster workers (one after the other, in one
run), and the overhead per point. Writes docs/data/sweep_speedup.json; README "Sweeps" quotes it.

    .venv/bin/python studies/measure_speedup.py [--out out/speedup]

Overhead per point, from sweep.json's timing records (worker and client clocks are the same machine's):
- dispatch: the gap on a worker between the end of one task and the start of its next (scheduler round trip);
- transfer: result received by the client minus task end on the worker (result serialisation, transfer, the
  client's as_completed wake-up and the row written);
- model build: the torsional level's mesh stiffness (TCA, summary key mesh_stiffness_wall_s) per point, and the
  worker's first-task imports (first task's wall time minus the median of the others on that worker).
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import time
from pathlib import Path

from wormsim.sweep import load_sweep, run_sweep
from wormsim.sweep.plot import parse_value
from wormsim.sweep.runner import read_csv

ROOT = Path(__file__).resolve().parents[1]
SWEEP = """name: speedup
base: {base}
set: {{model: torsional, simulation.duration_s: 0.3, simulation.timestep_s: 2.0e-5}}
grid:
  drive.speed_rpm: {{linspace: [1000, 2400, 8]}}
"""


def overheads(out: Path) -> dict:
    doc = json.loads((out / "sweep.json").read_text())
    rows = {int(r["point"]): {k: parse_value(v) for k, v in r.items()} for r in read_csv(out / "sweep.csv")}
    tim = {p["point"]: p["timing"] for p in doc["points"]}
    by_worker: dict[str, list] = {}
    for i, t in tim.items():
        by_worker.setdefault(t["worker"], []).append((t["start"], t["end"], i))
    gaps, first_extra = [], []
    for tasks in by_worker.values():
        tasks.sort()
        gaps += [b[0] - a[1] for a, b in zip(tasks, tasks[1:])]
        walls = [e - s for s, e, _ in tasks]
        if len(walls) > 1:
            first_extra.append(walls[0] - statistics.median(walls[1:]))
    transfer = [t["received"] - t["end"] for t in tim.values()]
    task = [t["end"] - t["start"] for t in tim.values()]
    return {
        "sweep_wall_s": doc["wall_s"],
        "cluster_start_s": doc["cluster"]["start_s"],
        "points": len(tim),
        "workers": doc["cluster"]["workers"],
        "task_wall_median_s": statistics.median(task),
        "simulate_wall_median_s": statistics.median(r["wall_time_s"] for r in rows.values()),
        "solve_wall_median_s": statistics.median(r["solve_wall_s"] for r in rows.values()),
        "model_build_tca_median_s": statistics.median(r["mesh_stiffness_wall_s"] for r in rows.values()),
        "first_task_import_extra_s": first_extra,
        "dispatch_gap_median_s": statistics.median(gaps) if gaps else None,
        "transfer_median_s": statistics.median(transfer),
        "result_bytes": max(t["result_bytes"] for t in tim.values()),
        "load_average_at_start": doc["machine"]["load_average"],
    }


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--out", default=str(ROOT / "out" / "speedup"))
    args = ap.parse_args()
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    f = out / "speedup.yaml"
    f.write_text(SWEEP.format(base=ROOT / "scenarios" / "screw_jack.yaml"))
    sw = load_sweep(f)
    res = {}
    for n in (1, 2):
        d = out / f"workers{n}"
        if d.exists():
            for p in d.iterdir():
                p.unlink()
        t0 = time.perf_counter()
        run_sweep(sw, d, workers=n, progress=False)
        res[n] = {"command_wall_s": time.perf_counter() - t0, **overheads(d)}
    rec = {
        "what": "8 torsional screw-jack points (0.3 s at 20 us steps, 1000-2400 rpm), LocalCluster, 1 then 2 workers",
        "cpu_count": os.cpu_count(),
        "load_average_after": list(os.getloadavg()),
        "speedup_command": res[1]["command_wall_s"] / res[2]["command_wall_s"],
        "speedup_excluding_cluster_start": (
            (res[1]["sweep_wall_s"] - res[1]["cluster_start_s"]) / (res[2]["sweep_wall_s"] - res[2]["cluster_start_s"])
        ),
        "runs": res,
    }
    from wormsim.results.provenance import record

    record("sweep_speedup", rec)
    print(json.dumps(rec, indent=2))


if __name__ == "__main__":
    main()
