"""The independent FE contact check of the tooth compliance (issue 30, item 7; docs/validation.md, "CalculiX contact
check"): CalculiX (wormsim.tooth.calculix) at ANGLES worm angles over one mesh cycle on a seed gear (screw_jack: steel
worm, cast-iron wheel) and on a steel/bronze 2x31 ZI gear (scenarios/calculix_zi_2x31.yaml), each at its scenario's
wheel torque, against
* the loaded tooth contact analysis wormsim.tooth.ltca (when importable) at the same worm angles and torque:
  mesh stiffness along the line of action and the load share per wheel tooth;
* the FE root stress of `wormsim rate --fe` (wormsim.rating.fe_root) at the same torque;
* ISO 6336-1's c' and c_gamma of the wheel's virtual spur gear (wormsim.tooth.compliance.iso6336_stiffness).
Writes the record docs/data/calculix_check.json. CPU bound (gmsh + ccx): about 5 min per case on 1 core.

    .venv/bin/python studies/calculix_check.py [--angles 3] [--density 1.0] [--threads 1]  (about 1 h)
    .venv/bin/python studies/calculix_check.py --reread   (the record again from out/calculix_check's files)
"""

from __future__ import annotations

import argparse
import math
import time
from pathlib import Path

import numpy as np

from wormsim.physics import gear_theory
from wormsim.physics.geometry import derive
from wormsim.results.provenance import record
from wormsim.scenario import load_scenario
from wormsim.tooth import calculix as cx
from wormsim.tooth.compliance import iso6336_stiffness

ROOT = Path(__file__).resolve().parents[1]
GEARS = {
    "screw_jack": ROOT / "scenarios" / "screw_jack.yaml",
    "zi_2x31_bronze": ROOT / "scenarios" / "calculix_zi_2x31.yaml",
}
C_GUESS_N_PER_MM_UM = 15.0  # the lag that gives about the scenario torque: T / (c b2 arm0^2), ISO 6336's order


def ltca_values(g, materials, torque_nm: float, angles: int, side: int) -> dict:
    """The LTCA at the check's worm angles (samples = 4 x angles over the cycle, every 4th), or why not."""
    try:
        from wormsim.tooth import ltca
    except ImportError as e:
        return {"available": False, "reason": f"wormsim.tooth.ltca not importable ({e})"}
    import inspect

    kw = {"side": side} if "side" in inspect.signature(ltca.loaded_contact).parameters else {}
    res = ltca.loaded_contact(g, materials, torque_nm, samples=4 * angles, **kw)
    rows = []
    for i in range(angles):
        j = 4 * i
        share = np.asarray(res.load_share[j], float)
        rows.append(
            {
                "theta1_deg": math.degrees(float(res.theta1_rad[j])),
                "mesh_stiffness_n_per_m": float(res.mesh_stiffness_n_per_m[j]),
                "load_share": [float(v) for v in share if v > 0],
                "load_share_max": float(share.max()),
                "teeth_in_contact": float(res.teeth_in_contact[j]),
            }
        )
    return {"available": True, "torque_nm": torque_nm, "side": side, "angles": rows, "summary": res.summary()}


def fe_root_value(g, sc, side: int, torque_nm: float) -> dict:
    """`wormsim rate --fe`'s root stress (wormsim.rating.fe_root) at torque_nm, the rating's default positions."""
    from wormsim.rating import fe_root
    from wormsim.rating.rate import rating_inputs

    r = rating_inputs(sc)
    w = sc.materials.wheel
    t0 = time.perf_counter()
    out = fe_root.root_stress(g, w.youngs_modulus_gpa * 1e9, w.poisson_ratio, side, torque_nm, r.fe_positions,
                              density=r.fe_mesh_density)  # fmt: skip
    return {
        "torque_nm": torque_nm,
        "root_stress_max_mpa": out["root_stress_max_mpa"],
        "per_position_mpa": out["per_position_mpa"],
        "positions": out["positions"],
        "wall_s": time.perf_counter() - t0,
    }


def one_gear(name: str, path: Path, angles: int, density: float, threads: int, workdir: Path, reread: bool) -> dict:
    sc = load_scenario(path)
    g = derive(sc.gear)
    side = gear_theory.duty(sc, g.hand).working_flank
    m = sc.materials
    torque = abs(sc.load.torque_nm)
    arm0 = cx.arm0_m(g)
    lag = torque / (C_GUESS_N_PER_MM_UM * 1e9 * g.face_width * arm0**2)
    period = 2 * math.pi / g.z1
    cases = []
    for i in range(angles):
        th1 = i * period / angles
        if reread:
            r = cx.reread(workdir / name, th1)
        else:
            r = cx.solve(g, m, side, th1, lag, density=density, workdir=workdir / name, threads=threads)
        shown = ("theta1_deg", "torque_nm", "mesh_stiffness_n_per_m", "load_share", "torque_balance", "nodes")
        print(name, {k: r.get(k) for k in shown + ("root_stress_max_mpa", "ccx_wall_s")}, flush=True)
        cases.append(r)
    k = np.array([c["mesh_stiffness_n_per_m"] for c in cases])
    t_mean = float(np.mean([c["torque_nm"] for c in cases]))
    roots = [c["root_stress_max_mpa"] for c in cases if c.get("root_stress_max_mpa") is not None]
    # the root stress scaled to the scenario torque (linear elasticity; the contact's nonlinearity is second order)
    root_at_t = max(c["root_stress_max_mpa"] * torque / c["torque_nm"] for c in cases if c.get("root_stress_max_mpa"))
    out = {
        "scenario": str(path.relative_to(ROOT)),
        "profile": g.profile,
        "z1": g.z1,
        "z2": g.z2,
        "m_x_mm": g.m_x * 1e3,
        "face_width_mm": g.face_width * 1e3,
        "center_distance_mm": g.a * 1e3,
        "e_worm_gpa": m.worm.youngs_modulus_gpa,
        "e_wheel_gpa": m.wheel.youngs_modulus_gpa,
        "side": side,
        "torque_scenario_nm": torque,
        "lag_prescribed_urad": lag * 1e6,
        "arm0_mm": arm0 * 1e3,
        "calculix": cases,
        "calculix_mean": {
            "torque_nm": t_mean,
            "mesh_stiffness_mean_n_per_m": float(k.mean()),
            "mesh_stiffness_per_width_n_per_mm_um": float(k.mean() / g.face_width / 1e9),
            "load_share_max": float(max(c["load_share_max"] or 0.0 for c in cases)),
            "root_stress_max_mpa_at_scenario_torque": root_at_t if roots else None,
            "torque_balance_max": float(max(abs(c["torque_balance"]) for c in cases)),
        },
        "iso6336": iso6336_stiffness(g, m),
    }
    out["ltca"] = ltca_values(g, m, t_mean, angles, side)
    out["fe_root"] = fe_root_value(g, sc, side, torque)
    if out["ltca"]["available"]:
        kl = np.array([a["mesh_stiffness_n_per_m"] for a in out["ltca"]["angles"]])
        out["comparison"] = {
            "ltca_mesh_stiffness_mean_at_angles_n_per_m": float(kl.mean()),
            "mesh_stiffness_ratio_calculix_to_ltca": float(k.mean() / kl.mean()),
            "load_share_max_difference": float(
                max(abs(c["load_share_max"] - a["load_share_max"]) for c, a in zip(cases, out["ltca"]["angles"]))
            ),
        }
    return out


def convergence(a, gears: dict) -> dict:
    """The h-refinement check: the screw jack's first angle at density --fine (element sizes / fine) beside the
    sweep's density."""
    sc = load_scenario(GEARS["screw_jack"])
    g = derive(sc.gear)
    m = sc.materials
    side = gear_theory.duty(sc, g.hand).working_flank
    lag = abs(sc.load.torque_nm) / (C_GUESS_N_PER_MM_UM * 1e9 * g.face_width * cx.arm0_m(g) ** 2)
    where = Path(a.workdir) / "screw_jack_fine"
    if a.reread:
        fine = cx.reread(where, 0.0)
    else:
        fine = cx.solve(g, m, side, 0.0, lag, density=a.fine, workdir=where, threads=a.threads)
    coarse = gears["screw_jack"]["calculix"][0]
    keys = ("mesh_stiffness_n_per_m", "load_share", "root_stress_max_mpa", "torque_nm", "nodes", "h_fine_mm")
    return {
        "gear": "screw_jack",
        "theta1_deg": 0.0,
        "density": a.fine,
        "coarse": {k: coarse.get(k) for k in keys},
        "fine": {k: fine.get(k) for k in keys},
        "mesh_stiffness_change": fine["mesh_stiffness_n_per_m"] / coarse["mesh_stiffness_n_per_m"] - 1.0,
    }


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--angles", type=int, default=3)
    ap.add_argument("--density", type=float, default=1.0)
    ap.add_argument("--threads", type=int, default=1)
    ap.add_argument("--gears", default=",".join(GEARS))
    ap.add_argument("--workdir", default=str(ROOT / "out" / "calculix_check"))
    ap.add_argument("--fine", type=float, default=1.4, help="density of the h-refinement check (screw jack, angle 0)")
    ap.add_argument("--reread", action="store_true", help="the results of an earlier run's files (no solve)")
    a = ap.parse_args()
    if cx.ccx_path() is None and not a.reread:
        raise SystemExit("CalculiX (ccx) is not installed: apt-get install calculix-ccx (make install does it as root)")
    gears = {}
    for name in a.gears.split(","):
        gears[name] = one_gear(name, GEARS[name], a.angles, a.density, a.threads, Path(a.workdir), a.reread)
    data = {"convergence": convergence(a, gears)} if "screw_jack" in gears else {}
    data |= {
        "model": {
            "h_fine_mx": cx.H_FINE_MX / a.density,
            "h_max_mx": cx.H_MAX_MX / a.density,
            "penalty_factor": cx.PENALTY_FACTOR,
            "increments": cx.INCREMENTS,
            "sections": cx.SECTIONS,
            "code": cx.CODE_VERSION,
        },
        "angles": a.angles,
        "gears": gears,
    }
    print(record("calculix_check", data))


if __name__ == "__main__":
    main()
