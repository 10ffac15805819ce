"""The load-capacity rating with the FE root stress on the seed scenarios (README "Durability", docs/rating.md "The
seeds"): `wormsim rate scenarios/NAME.yaml --fe --set rating.wheel_material=...` for each seed at its own load, with
the wheel material of the seed's table row (seed 002's HT150 grey iron as GJL-250, seed 003's Al-Fe bronze as
CuAl10Fe5Ni5, seed 001's POM). Each mesh is built cold (a fresh cache). Writes the record
docs/data/rating_seeds.json with what each seed reports beside it.

    .venv/bin/python studies/rating_seeds.py
"""

from __future__ import annotations

import os
import tempfile
import time
from pathlib import Path

from wormsim.results.provenance import record
from wormsim.scenario import load_scenario

ROOT = Path(__file__).resolve().parents[1]
SEEDS = {"seat_motor": ("001", "POM"), "screw_jack": ("002", "GJL-250"), "involute_41": ("003", "CuAl10Fe5Ni5")}
# what each seed document states about durability (the seed documents, paraphrased)
SEED_SAYS = {
    "seat_motor": "POM wheel (E 3.1 GPa); no stress or strength values",
    "screw_jack": "the meshing-force fluctuation drives fatigue (pitting, bending fatigue); no values",
    "involute_41": "FEM: max contact stress near the tooth tip at initial engagement; bending stress peaks at the "
    "root fillet; no values",
}
KEYS = (
    "safety_pitting",
    "safety_wear",
    "safety_root",
    "safety_root_sim",
    "root_stress_max_mpa",
    "root_stress_range_mpa",
    "contact_stress_mean_iso_mpa",
    "refused",
)


def main() -> None:
    os.environ["WORMSIM_CACHE"] = tempfile.mkdtemp(prefix="wormsim-fe-")  # cold: the FE mesh is built here
    from wormsim.physics.geometry import derive
    from wormsim.rating.fe_root import add_fe_root_stress
    from wormsim.rating.rate import rate

    seeds = {}
    for name, (seed, material) in SEEDS.items():
        sc = load_scenario(ROOT / "scenarios" / f"{name}.yaml", [f"rating.wheel_material={material}"])
        t0 = time.perf_counter()
        res = add_fe_root_stress(sc, rate(sc))
        wall = time.perf_counter() - t0
        fe = res["fe_root"]
        seeds[name] = {
            "seed": seed,
            "wheel_material": material,
            "wheel_torque_nm": res["inputs"]["wheel_torque_rated_nm"],
            **{k: res.get(k) for k in KEYS},
            "position_mm": fe["position_mm"],
            "position_index": fe["position_index"],
            "positions": fe["positions"],
            "face_half_width_mm": derive(sc.gear).face_width * 1e3 / 2,
            "root_stress_limit_mpa": fe["root_stress_limit_mpa"],
            "elements": fe["elements"],
            "density": fe["density"],
            "fe_wall_s": fe["wall_time_s"],
            "rate_fe_wall_s": wall,
            "seed_says": SEED_SAYS[name],
        }
        print(name, f"{fe['root_stress_max_mpa']:.3g} MPa, {wall:.1f} s", flush=True)
    record("rating_seeds", {"seeds": seeds})


if __name__ == "__main__":
    main()
