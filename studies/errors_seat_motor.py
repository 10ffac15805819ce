"""contact3d (exact flanks) on the seat motor with a wheel axial offset or a shaft angle, at 4 N m (a light load: its
mesh approach is about the kinematic TCA's marking film) and at the working 24 N m: the loaded pattern, pressure,
fluctuation, TE and play (docs/errors.md section 6), with the kinematic TCA's pattern centroid of the same errors
(the torsional level's unloaded pattern) beside the loaded one. Writes the record docs/data/errors_seat_motor.json.

    .venv/bin/python studies/errors_seat_motor.py
"""

from __future__ import annotations

import sys
from pathlib import Path

from wormsim.contact3d.runner import simulate
from wormsim.results.provenance import record
from wormsim.scenario import load_scenario
from wormsim.torsional.dynamics import simulate as simulate_torsional

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "studies"))
from errors_study import KEYS, RUNS  # noqa: E402  (the study's short coarse runs and outputs)

# (load torque N m, errors overrides): each error alone
CASES = [
    (4.0, []),
    (4.0, ["errors.wheel_axial_offset_mm=0.1"]),
    (4.0, ["errors.wheel_axial_offset_mm=-0.1"]),
    (4.0, ["errors.shaft_angle_deg=0.1"]),
    (4.0, ["errors.shaft_angle_deg=0.3"]),
    (4.0, ["errors.shaft_angle_deg=-0.3"]),
    (24.0, []),
    (24.0, ["errors.wheel_axial_offset_mm=0.1"]),
    (24.0, ["errors.wheel_axial_offset_mm=-0.1"]),
]


def main() -> None:
    path = ROOT / "scenarios" / "seat_motor.yaml"
    base = ["contact.geometry=flanks", *RUNS["seat_motor"]]
    rows = []
    for torque, errs in CASES:
        sets = [*base, f"load.torque_nm={torque}", *errs]
        s = simulate(load_scenario(path, sets)).summary
        kin = {}
        if errs:  # the kinematic pattern of the same errors (torsional: the unloaded TCA's keys)
            t = simulate_torsional(load_scenario(path, [*sets, "model=torsional", "simulation.duration_s=0.2"]))
            kin = {"kinematic_contact_pattern_centroid_face_mm": t.summary.get("contact_pattern_centroid_face_mm")}
        rows.append({"load_torque_nm": torque, "errors": errs, **{k: s.get(k) for k in KEYS}, **kin})
        print(rows[-1], flush=True)
    record("errors_seat_motor", {"scenario": "scenarios/seat_motor.yaml", "overrides": base, "rows": rows})


if __name__ == "__main__":
    main()
