"""The loaded tooth contact analysis (wormsim.tooth.ltca) on each seed file at its load torque
(docs/tooth_compliance.md): mean mesh stiffness per face width beside the Hertz-only value (pi E* / 4 per unit line
length, wormsim.tooth.mesh_stiffness) and ISO 6336-1's c' and c_gamma of the wheel's virtual spur gear, teeth in
contact, the largest load share, loaded TE p2p, the largest Hertz pressure, k'_eff; and on the screw jack the
effect of the FE model's parts (one tooth instead of three, the worm thread rigid). Writes the record
docs/data/tooth_compliance_seeds.json.

    .venv/bin/python studies/tooth_compliance_seeds.py
"""

from __future__ import annotations

import dataclasses
import math
import time
from pathlib import Path

import numpy as np

from meshgen.geometry import derive
from wormsim.physics.gear_theory import effective_modulus_pa
from wormsim.results.provenance import record
from wormsim.scenario import load_scenario
from wormsim.tooth import compliance, ltca, mesh_stiffness
from wormsim.tooth import stiffness as ST

ROOT = Path(__file__).resolve().parents[1]
SEEDS = ("seat_motor", "screw_jack", "involute_41")
# wheel materials on the screw jack's gear (steel worm 210 GPa, 0.269): (E GPa, nu, source)
MATERIALS = {
    "steel": (210.0, 0.3, "steel"),
    "GJS-400": (175.0, 0.3, "wormsim.rating.materials (DIN 3996 via MITCalc)"),
    "CuAl10Fe5Ni5": (122.6, 0.35, "wormsim.rating.materials"),
    "GJL-250": (98.1, 0.3, "wormsim.rating.materials"),
    "CuSn12": (88.3, 0.35, "wormsim.rating.materials (KISSsoft report)"),
    "POM": (3.1, 0.39, "seed 001 (scenarios/seat_motor.yaml)"),
    "PA66": (2.8, 0.4, "typical dry PA66 datasheet value, an assumption (no source in the repository)"),
}
GRID_FINE = (13, 7)  # the flank grid's refinement check
LOAD_FACTORS = (0.25, 4.0)  # the load dependence (the flattening) on the screw jack, x its 12 N m


def main() -> None:
    runs = {}
    for seed in SEEDS:
        sc = load_scenario(ROOT / "scenarios" / f"{seed}.yaml")
        g = derive(sc.gear)
        t0 = time.perf_counter()
        comp = compliance.tooth_compliance(g, sc.materials)
        t_comp = time.perf_counter() - t0
        t = abs(sc.load.torque_nm)
        res = ltca.loaded_contact(g, sc.materials, t)
        hertz_kp = math.pi * effective_modulus_pa(sc.materials) / 4
        hz = mesh_stiffness.mesh_stiffness(g, hertz_kp, "hertz", 16)
        kp = ST.line_stiffness_n_per_m2(g, sc.materials, t)
        runs[seed] = {
            "torque_nm": t,
            "face_width_mm": g.face_width * 1e3,
            "wheel_e_gpa": sc.materials.wheel.youngs_modulus_gpa,
            **res.summary(),
            "hertz_mesh_stiffness_mean_n_per_m": float(np.mean(hz.k_mesh_fwd_n_per_m)),
            "hertz_per_width_n_per_mm_um": float(np.mean(hz.k_mesh_fwd_n_per_m)) / g.face_width * 1e-9,
            "line_stiffness_n_per_m2": kp,
            "hertz_line_stiffness_n_per_m2": hertz_kp,
            "iso6336": compliance.iso6336_stiffness(g, sc.materials),
            "pressure_max_mpa": max(float(c.pressure_pa.max()) for c in res.contacts) / 1e6,
            "compliance_wall_s": t_comp,
            "compliance_wall_s_uncached": comp.wall_time_s,
            "fe_nodes": comp.nodes,
            "fe_elements": comp.elements,
        }
        print(seed, runs[seed], flush=True)
    # the FE model's parts on the screw jack
    sc = load_scenario(ROOT / "scenarios" / "screw_jack.yaml")
    g = derive(sc.gear)
    comp = compliance.tooth_compliance(g, sc.materials)
    base = ltca.loaded_contact(g, sc.materials, 12.0).summary()["mesh_stiffness_mean_n_per_m"]
    one = ltca.compute(g, sc.materials, 12.0, 16, 1, 1, comp=compliance.compute(g, sc.materials, 1, teeth=1))
    rigid_worm = dataclasses.replace(comp, worm_m2_per_n=np.zeros_like(comp.worm_m2_per_n))
    no_worm = ltca.compute(g, sc.materials, 12.0, 16, 1, 1, comp=rigid_worm)
    parts = {
        "mesh_stiffness_three_teeth_n_per_m": base,
        "mesh_stiffness_one_tooth_n_per_m": float(np.mean(one.mesh_stiffness_n_per_m)),
        "mesh_stiffness_worm_thread_rigid_n_per_m": float(np.mean(no_worm.mesh_stiffness_n_per_m)),
    }
    # the flank grid refined (13 x 7 instead of 9 x 5)
    saved = (compliance.GRID_FACE, compliance.GRID_PROFILE)
    compliance.GRID_FACE, compliance.GRID_PROFILE = GRID_FINE
    try:
        fine = ltca.compute(g, sc.materials, 12.0, 16, 1, 1, comp=compliance.compute(g, sc.materials, 1))
    finally:
        compliance.GRID_FACE, compliance.GRID_PROFILE = saved
    parts["mesh_stiffness_grid_13x7_n_per_m"] = float(np.mean(fine.mesh_stiffness_n_per_m))
    for factor in LOAD_FACTORS:
        r = ltca.loaded_contact(g, sc.materials, 12.0 * factor)
        parts[f"mesh_stiffness_at_{factor:g}x_load_n_per_m"] = r.summary()["mesh_stiffness_mean_n_per_m"]
    print(parts, flush=True)
    mats = {}
    for name, (e_gpa, nu, source) in MATERIALS.items():
        m = sc.materials.model_copy(deep=True)
        m.wheel.youngs_modulus_gpa, m.wheel.poisson_ratio = e_gpa, nu
        r = ltca.loaded_contact(g, m, 12.0)
        mats[name] = {"wheel_e_gpa": e_gpa, "wheel_nu": nu, "source": source, **r.summary()}
        print(name, mats[name], flush=True)
    print(record("tooth_compliance_seeds", {"runs": runs, "screw_jack_parts": parts, "screw_jack_materials": mats}))


if __name__ == "__main__":
    main()
