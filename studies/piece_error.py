"""The convex collision pieces of each seed gear at coarse / medium / fine (docs/geometry.md, docs/models.md): piece
counts, their measured error against the exact flanks (meshgen.pieces.measure_piece_error, um) and the time to
generate them without the cache. Writes the record docs/data/piece_error.json.

    .venv/bin/python studies/piece_error.py
"""

from __future__ import annotations

import math
import time
from pathlib import Path

from meshgen.geometry import derive
from meshgen.pieces import RESOLUTIONS, build_gear_set
from wormsim.results.provenance import record
from wormsim.scenario import load_scenario

ROOT = Path(__file__).resolve().parents[1]
SEEDS = ("seat_motor", "screw_jack", "involute_41")


def main() -> None:
    rows = []
    for seed in SEEDS:
        g = derive(load_scenario(ROOT / "scenarios" / f"{seed}.yaml").gear)
        for level, res in RESOLUTIONS.items():
            t0 = time.perf_counter()
            gs = build_gear_set(g, res, use_cache=False)
            wall = time.perf_counter() - t0
            rows.append(
                {
                    "gear": seed,
                    "resolution": level,
                    "worm_segments_per_turn": res.worm_segments_per_turn,
                    "wheel_slabs": res.wheel_slabs,
                    "profile_points": res.profile_points,
                    "worm_pieces": len(gs.worm_pieces),
                    "wheel_tooth_pieces": len(gs.wheel_tooth_pieces),
                    "piece_error_um": gs.piece_error_um,
                    # flank-normal clearance of the exact pair at the pitch point, (j/2) cos(alpha_n) cos(gamma)
                    "normal_half_backlash_um": g.backlash / 2 * math.cos(g.alpha_n) * math.cos(g.gamma) * 1e6,
                    "wall_s": wall,
                }
            )
            print(rows[-1], flush=True)
    print(record("piece_error", {"rows": rows}))


if __name__ == "__main__":
    main()
