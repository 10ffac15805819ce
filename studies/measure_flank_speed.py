"""Per-step cost of exact-flank contacts against medium convex pieces (issue 13), measured in one process: the CI
configurations of tests/contact3d/test_seeds_pieces.py shortened to 0.08 s at medium resolution, pieces and flanks
alternating twice (flanks with one contact per slice, `contact.flank_contacts: slice`, and with one per tooth
flank, `tooth`; the default, 4 per flank, is in docs/data/flank_contacts.json); wall time per step (summary
step_wall_us: the step and the runner's per-sample work) and the run's CPU time. Writes docs/data/flank_speed.json;
README "Speed of exact flanks against the issue's targets" quotes the best of two per geometry. Compare ratios from
one run only: the machine is shared.

    .venv/bin/python studies/measure_flank_speed.py [seat_motor screw_jack involute_41]
"""

from __future__ import annotations

import os
import platform
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def main(seeds: list[str]) -> dict:
    from wormsim.contact3d.runner import simulate
    from wormsim.scenario import load_scenario

    CI = _ci()
    runs: dict[str, list[dict]] = {}
    for name in seeds:
        base = [o for o in CI[name] if not o.startswith(("simulation.duration_s", "simulation.resolution"))]
        base += ["simulation.duration_s=0.08", "simulation.resolution=medium"]
        for rep in range(2):
            for geo in ("pieces", "flanks", "flanks-tooth"):
                over = [f"contact.geometry={geo.split('-')[0]}"]
                over += (
                    [f"contact.flank_contacts={'tooth' if geo.endswith('-tooth') else 'slice'}"]
                    if geo != "pieces"
                    else []
                )
                sc = load_scenario(ROOT / "scenarios" / f"{name}.yaml", base + over)
                c0 = time.process_time()
                s = simulate(sc).summary
                rec = {
                    "step_wall_us": s["step_wall_us"],
                    "timestep_s": s["timestep_s"],
                    "run_cpu_s": time.process_time() - c0,
                }
                runs.setdefault(f"{name}/{geo}", []).append(rec)
                print(name, geo, rep, round(rec["step_wall_us"], 1), flush=True)
    best = {}
    for name in seeds:
        p = min(r["step_wall_us"] for r in runs[f"{name}/pieces"])
        f = min(r["step_wall_us"] for r in runs[f"{name}/flanks"])
        t = min(r["step_wall_us"] for r in runs[f"{name}/flanks-tooth"])
        best[name] = {
            "pieces_step_wall_us": p,
            "flanks_step_wall_us": f,
            "speedup_flanks_vs_pieces": p / f,
            "flanks_tooth_step_wall_us": t,
            "speedup_flanks_tooth_vs_pieces": p / t,
        }
        print(name, best[name], flush=True)
    return {"machine": platform.node(), "cpus": os.cpu_count(), "runs": runs, "best": best}


def _ci() -> dict:
    """The CI configurations (tests/contact3d/test_seeds_pieces.py)."""
    sys.path.insert(0, str(ROOT))
    from tests.contact3d.test_seeds_pieces import CI

    return CI


if __name__ == "__main__":
    out = main(sys.argv[1:] or list(_ci()))
    from wormsim.results.provenance import record

    record("flank_speed", out)
