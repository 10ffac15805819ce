"""The REXS worm stages at every level and through the rating (docs/rating.md "The FVA REXS stage", docs/rexs.md):
the FVA Workbench stage (tests/assets/rexs/FVA_worm_stage_1-4.rexsj) and the second test stage
(other_worm_stage.rexsj), each imported as `wormsim import` does, run at wedge and torsional (the file's speed and
torque) and at contact3d on the file's bearings for 0.1 s (ramps 0.02 s), and rated (ISO/TS 14521 method B with
the file's oil, life and application factor). Writes the record docs/data/rexs_stages.json.

    .venv/bin/python studies/rexs_stages.py
"""

from __future__ import annotations

import time
from pathlib import Path

from wormsim.rating.rate import RATING_KEYS
from wormsim.results.provenance import record

ROOT = Path(__file__).resolve().parents[1]
STAGES = {
    "FVA_worm_stage_1-4": ROOT / "tests" / "assets" / "rexs" / "FVA_worm_stage_1-4.rexsj",
    "other_worm_stage": ROOT / "tests" / "assets" / "rexs" / "other_worm_stage.rexsj",
}
LEVELS = {
    "wedge": ["model=wedge"],
    "torsional": ["model=torsional"],
    "contact3d": ["model=contact3d", "simulation.duration_s=0.1", "drive.ramp_s=0.02", "load.ramp_s=0.02"],
}
RUN_KEYS = (
    "ratio",
    "tangential_force_mean_n",
    "efficiency",
    "efficiency_theory",
    "efficiency_theory_at_contact_radius",
    "worm_torque_mean_nm",
    "contact_pressure_mean_mpa",
    "contact_pressure_max_mpa",
    "worm_deflection_mesh_um",
    "worm_bearing_axial_mean_n",
)
# ISO/TS 14521 method B: the rating keys of wormsim.rating.rate before its AGMA keys, warnings and sources
ISO_KEYS = RATING_KEYS[: RATING_KEYS.index("agma_rated_tangential_force_n")]


def main() -> None:
    from wormsim import simulate
    from wormsim.physics.geometry import derive
    from wormsim.rating.rate import rate
    from wormsim.scenario import load_scenario, rexs

    out = {}
    for name, path in STAGES.items():
        imp = rexs.import_file(path)
        sc = load_scenario(path)
        g = derive(sc.gear)
        rec = {
            "file": str(path.relative_to(ROOT)),
            "gear": {
                "profile": sc.gear.profile,
                "z1": g.z1,
                "z2": g.z2,
                "m_x_mm": g.m_x * 1e3,
                "d1_mm": g.d1 * 1e3,
                "d2_mm": g.d2 * 1e3,
                "a_mm": g.a * 1e3,
                "x2": g.x2,
                "b2_mm": g.face_width * 1e3,
            },
            "speed_rpm": sc.drive.speed_rpm,
            "torque_nm": sc.load.torque_nm,
            "ft2_theory_n": sc.load.torque_nm / g.r2,
            "notes": imp.notes,
            "levels": {},
        }
        for level, sets in LEVELS.items():
            sl = load_scenario(path, sets)
            t0 = time.perf_counter()
            s = simulate(sl).summary
            rec["levels"][level] = {k: s.get(k) for k in RUN_KEYS} | {"wall_s": time.perf_counter() - t0}
            print(name, level, f"F_t2 {s['tangential_force_mean_n']:.1f} N", flush=True)
        r = rate(sc)
        rec["rating"] = {k: r.get(k) for k in ISO_KEYS} | {"warnings": r["warnings"]}
        out[name] = rec
    record("rexs_stages", {"stages": out})


if __name__ == "__main__":
    main()
