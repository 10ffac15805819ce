"""The full 20 s seat motor (scenarios/seat_motor.yaml, contact3d, exact flanks) with `simulation.mass_scaling`
(docs/performance.md, "Quasi-static runs: mass scaling"), beside the unscaled 20 s run with pieces
(docs/data/seat_motor_20s.json). Wall times are one run each after a warm-up run, in one process: read them with the
load average the provenance gives. Writes the record docs/data/mass_scaling.json.

    .venv/bin/python studies/mass_scaling.py [--scale auto] [--scale 1000]
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

from wormsim import load_scenario, simulate
from wormsim.results.provenance import record

ROOT = Path(__file__).resolve().parents[1]
KEYS = (
    "mass_scaling",
    "timestep_s",
    "step_wall_us",
    "efficiency",
    "efficiency_theory",
    "ratio",
    "tangential_force_mean_n",
    "tangential_force_theory_n",
    "mesh_frequency_hz",
    "mesh_frequency_theory_hz",
    "kinetic_energy_share",
    "kinetic_energy_share_estimate",
    "flank_slices",
)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--scale", action="append", default=None, help="mass_scaling values (default: auto)")
    args = ap.parse_args()
    scales = args.scale or ["auto"]
    path = ROOT / "scenarios" / "seat_motor.yaml"
    # warm-up: numba's cache and the flank grid (a short run of the same gear)
    simulate(load_scenario(path, ["simulation.mass_scaling=auto", "simulation.duration_s=0.5"]))
    runs = {}
    for scale in scales:
        sc = load_scenario(path, [f"simulation.mass_scaling={scale}"])
        t0 = time.perf_counter()
        res = simulate(sc)
        wall = time.perf_counter() - t0
        s = res.summary
        sim = float(res.series["t_s"][-1])
        runs[scale] = {
            "wall_s": wall,
            "sim_time_s": sim,
            "steps": round(sim / s["timestep_s"]),
            **{k: s.get(k) for k in KEYS},
        }
        print(scale, runs[scale], flush=True)
    print(record("mass_scaling", {"scenario": "scenarios/seat_motor.yaml", "runs": runs}))


if __name__ == "__main__":
    main()
