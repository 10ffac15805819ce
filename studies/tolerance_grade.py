"""Issue 12's tolerance study: the limits of the errors: keys for a gear of a stated quality grade, and the sweep
file that draws them at random (`wormsim sweep`).

    .venv/bin/python studies/tolerance_grade.py [--grade 8] [--n 100] [--seed 12]   # writes studies/*_tolerance.yaml

DIN 3974-1/-2 (worm gear tolerances) is not available here, so the values are DERIVED, not copied from it: DIN 3974
grades the wheel and the worm on the ISO 1328 / DIN 3961 scale (step sqrt(2) per grade from grade 5), and the
formulas below are those standards' (docs/errors.md, section 8, says which value comes from where):

    f_pT  = (0.001 d + 0.4 m_n + 5) sqrt(2)^(Q - 5)                 um   single pitch, ISO 1328-1:2013
    F_r   = 0.8 (0.3 m_n + 1.25 sqrt(d) + 7) sqrt(2)^(Q - 5)        um   runout, ISO 1328-2:1997 annex B (0.8 F_p)
    F_b   = (0.1 sqrt(d) + 0.63 sqrt(b) + 4.2) sqrt(2)^(Q - 5)      um   helix, ISO 1328-1:1995/2013
    f_a   = +- IT / 2 of the centre distance, IT per _JS_IT          um   js field, DIN 3964's pairing (recalled)
    f_S   = F_b(wheel) / b2                                         rad  ISO/TR 10064-3 f_Sd = (L / b) F_b, L = b2
    f_x   = f_a                                                          wheel mid-plane: assumed as the centre distance

d and m_n in mm (the reference diameter and normal module of the part), Q the grade. Mapping to the errors: keys
(each uniform, independent): wheel_runout_mm in [0, F_r2 / 2] (F_r is a range: 2 e for an eccentricity e) with
wheel_runout_phase_deg in [0, 360); worm_runout_mm in [0, F_r1 / 2]; wheel_pitch_deviation_um one shift per wheel
tooth in +- f_pT2 / 2 (so the single pitch deviations, neighbour differences, stay within +- f_pT2 and the
cumulative one within f_pT2); center_distance_mm and wheel_axial_offset_mm in +- f_a; shaft_angle_deg in +- f_S.
worm_axial_offset_mm stays 0 (a phase only, docs/errors.md section 1).
"""

from __future__ import annotations

import argparse
import math
from pathlib import Path

from meshgen import displaced
from meshgen.geometry import derive
from wormsim.scenario import load_scenario

ROOT = Path(__file__).resolve().parents[1]
MM = 1e-3

# ISO 286-1 standard tolerance IT5..IT9 in um for nominal sizes (upper bound of the range, mm)
_IT = {
    18: {5: 8, 6: 11, 7: 18, 8: 27, 9: 43},
    30: {5: 9, 6: 13, 7: 21, 8: 33, 9: 52},
    50: {5: 11, 6: 16, 7: 25, 8: 39, 9: 62},
    80: {5: 13, 6: 19, 7: 30, 8: 46, 9: 74},
    120: {5: 15, 6: 22, 7: 35, 8: 54, 9: 87},
}

# gear grade -> ISO 286 IT grade of the centre distance's js field (DIN 3964 pairs grades 5-6 / 7-8 / 9 with
# js6 / js7 / js8, as recalled: the DIN 3964 table is not available here)
_JS_IT = {5: 6, 6: 6, 7: 7, 8: 7, 9: 8}

# the short contact3d runs of docs/errors.md section 7 (working load, a few mesh cycles)
RUNS = {
    "screw_jack": {
        "drive.ramp_s": 0.02,
        "load.ramp_s": 0.02,
        "simulation.duration_s": 0.1,
        "simulation.resolution": "coarse",
    },
    "seat_motor": {
        "drive.speed_rpm": 3600,
        "drive.ramp_s": 0.01,
        "load.ramp_s": 0.01,
        "simulation.duration_s": 0.06,
        "simulation.resolution": "coarse",
    },
}


def _step(q: int) -> float:
    return math.sqrt(2.0) ** (q - 5)


def f_pt_um(d_mm: float, mn_mm: float, q: int) -> float:
    """Single pitch tolerance, ISO 1328-1:2013: (0.001 d + 0.4 m_n + 5) sqrt(2)^(Q-5), um."""
    return (0.001 * d_mm + 0.4 * mn_mm + 5.0) * _step(q)


def f_r_um(d_mm: float, mn_mm: float, q: int) -> float:
    """Runout tolerance, ISO 1328-2:1997 annex B: 0.8 F_p = 0.8 (0.3 m_n + 1.25 sqrt(d) + 7) sqrt(2)^(Q-5), um."""
    return 0.8 * (0.3 * mn_mm + 1.25 * math.sqrt(d_mm) + 7.0) * _step(q)


def f_beta_um(d_mm: float, b_mm: float, q: int) -> float:
    """Helix tolerance, ISO 1328-1:1995 (kept in 2013): (0.1 sqrt(d) + 0.63 sqrt(b) + 4.2) sqrt(2)^(Q-5), um."""
    return (0.1 * math.sqrt(d_mm) + 0.63 * math.sqrt(b_mm) + 4.2) * _step(q)


def it_um(size_mm: float, it: int) -> float:
    """ISO 286-1 standard tolerance grade IT`it` for a nominal size (sizes 10-120 mm here)."""
    if size_mm <= 10:
        raise ValueError(f"nominal size {size_mm} mm: table covers 10 to 120 mm")
    for upper, row in _IT.items():
        if size_mm <= upper:
            return float(row[it])
    raise ValueError(f"nominal size {size_mm} mm: table covers up to 120 mm")


def tolerances(name: str, grade: int) -> dict:
    """The inputs and the resulting limits of every errors: key for seed scenario `name` at `grade`."""
    g = derive(load_scenario(ROOT / "scenarios" / f"{name}.yaml").gear)
    mn = g.m_n / MM
    d1, d2, b2, a = 2 * g.r1 / MM, 2 * g.r2 / MM, g.face_width / MM, g.a / MM
    fpt2 = f_pt_um(d2, mn, grade)
    fr2, fr1 = f_r_um(d2, mn, grade), f_r_um(d1, mn, grade)
    fb2 = f_beta_um(d2, b2, grade)
    fa = it_um(a, _JS_IT[grade]) / 2
    out = {
        "inputs": {"m_n_mm": mn, "d1_mm": d1, "d2_mm": d2, "b2_mm": b2, "a_mm": a, "z2": g.z2, "grade": grade},
        "tolerances_um": {"f_pT2": fpt2, "F_r2": fr2, "F_r1": fr1, "F_beta2": fb2, "f_a": fa},
        "center_distance_mm": fa / 1000,
        "wheel_axial_offset_mm": fa / 1000,
        "shaft_angle_deg": math.degrees(fb2 / 1000 / b2),
        "wheel_runout_mm": fr2 / 2 / 1000,
        "worm_runout_mm": fr1 / 2 / 1000,
        "tooth_shift_um": fpt2 / 2,
    }
    lim = displaced.limits(g)
    out["radial_worst_mm"] = out["center_distance_mm"] + out["wheel_runout_mm"] + out["worm_runout_mm"]
    out["radial_limit_mm"] = lim["radial_closing_m"] / MM
    if out["radial_worst_mm"] >= out["radial_limit_mm"] or out["tooth_shift_um"] * 1e-6 >= lim["tooth_shift_m"]:
        raise SystemExit(f"{name} grade {grade}: the tolerances exceed the pair's limits (docs/errors.md section 2)")
    return out


def sweep_yaml(name: str, grade: int, n: int, seed: int) -> str:
    t = tolerances(name, grade)
    tol = t["tolerances_um"]

    def r(x: float) -> str:
        return f"{x:.6g}"

    fixed = {"model": "contact3d", "contact.geometry": "flanks", **RUNS[name]}
    sets = "\n".join(f"  {k}: {v}" for k, v in fixed.items())
    shift = f"[{r(-t['tooth_shift_um'])}, {r(t['tooth_shift_um'])}]"
    return f"""# written by studies/tolerance_grade.py --grade {grade} (do not edit by hand; rerun it)
name: {name}_tolerance
description: >
  Issue 12 tolerance study: every errors: key drawn at random (uniform, independent) within the limits of
  quality grade {grade} (DIN 3974 grades on the ISO 1328 scale; the values are derived from ISO 1328 / ISO 286
  formulas, docs/errors.md section 8): f_pT2 {r(tol["f_pT2"])} um, F_r2 {r(tol["F_r2"])} um, F_r1 {r(tol["F_r1"])} um,
  F_beta2 {r(tol["F_beta2"])} um, f_a +-{r(tol["f_a"])} um. contact3d with exact flanks, short runs (section 7).
base: ../scenarios/{name}.yaml
set:
{sets}
random:
  n: {n}
  seed: {seed}
  vary:
    errors.center_distance_mm: {{uniform: [{r(-t["center_distance_mm"])}, {r(t["center_distance_mm"])}]}}
    errors.wheel_axial_offset_mm: {{uniform: [{r(-t["wheel_axial_offset_mm"])}, {r(t["wheel_axial_offset_mm"])}]}}
    errors.shaft_angle_deg: {{uniform: [{r(-t["shaft_angle_deg"])}, {r(t["shaft_angle_deg"])}]}}
    errors.wheel_runout_mm: {{uniform: [0, {r(t["wheel_runout_mm"])}]}}
    errors.wheel_runout_phase_deg: {{uniform: [0, 360]}}
    errors.worm_runout_mm: {{uniform: [0, {r(t["worm_runout_mm"])}]}}
    errors.wheel_pitch_deviation_um: {{uniform: {shift}, size: {t["inputs"]["z2"]}}}
plot:
  x: errors.shaft_angle_deg
  outputs: [tangential_force_p2p_n, transmission_error_p2p_urad, transmission_error_kinematic_p2p_urad, efficiency,
            contact_pressure_max_mpa, contact_pattern_centroid_face_mm]
"""


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--grade", type=int, default=8, choices=range(5, 10))
    ap.add_argument("--n", type=int, default=100)
    ap.add_argument("--seed", type=int, default=12)
    args = ap.parse_args()
    for name in RUNS:
        t = tolerances(name, args.grade)
        print(name, {k: (round(v, 5) if isinstance(v, float) else v) for k, v in t.items() if not isinstance(v, dict)})
        print("  inputs", {k: round(v, 4) for k, v in t["inputs"].items()})
        print("  tolerances_um", {k: round(v, 2) for k, v in t["tolerances_um"].items()})
        (ROOT / "studies" / f"{name}_tolerance.yaml").write_text(sweep_yaml(name, args.grade, args.n, args.seed))


if __name__ == "__main__":
    main()
