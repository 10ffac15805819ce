"""The torsional level on the seed scenarios (docs/torsional.md, "Measured"): each seed file as it is (model=torsional)
and at N = 16 / 64 / 256 k(theta) samples per mesh cycle (the default timestep follows N). Wall times are the best of
`--repeats` calls in one process after a warm-up. Writes the record docs/data/torsional_seeds.json (seconds).

    .venv/bin/python studies/torsional_seeds.py [--repeats 3]
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

from wormsim.results.provenance import record
from wormsim.scenario import load_scenario
from wormsim.torsional.dynamics import simulate

ROOT = Path(__file__).resolve().parents[1]
SEEDS = ("seat_motor", "screw_jack", "involute_41")
SAMPLES = (16, 64, 256)
KEYS = (
    "ratio",
    "ratio_theory",
    "tangential_force_mean_n",
    "tangential_force_theory_n",
    "tangential_force_p2p_n",
    "efficiency",
    "efficiency_theory",
    "mesh_frequency_hz",
    "mesh_frequency_theory_hz",
    "transmission_error_p2p_urad",
    "timestep_s",
)


def _best(sets: list[str], name: str, repeats: int) -> dict:
    sc = load_scenario(ROOT / "scenarios" / f"{name}.yaml", ["model=torsional", *sets])
    simulate(sc)  # warm-up: imports and the cached k(theta) table
    walls, s, t_end = [], {}, 0.0
    for _ in range(repeats):
        t0 = time.perf_counter()
        res = simulate(sc)
        walls.append(time.perf_counter() - t0)
        s, t_end = res.summary, float(res.series["t_s"][-1])
    return {"overrides": sets, "wall_s": min(walls), **{k: s.get(k) for k in KEYS}, "sim_time_s": t_end}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeats", type=int, default=3)
    args = ap.parse_args()
    runs = {}
    for name in SEEDS:
        runs[name] = {
            "default": _best([], name, args.repeats),
            "samples": {str(n): _best([f"simulation.mesh_stiffness_samples={n}"], name, args.repeats) for n in SAMPLES},
        }
        print(name, flush=True)
    record("torsional_seeds", {"repeats": args.repeats, "runs": runs})


if __name__ == "__main__":
    main()
