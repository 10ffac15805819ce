"""Issue 12's study: the screw jack and the seat motor under each assembly error at two sizes, contact3d with exact
flanks (short, coarse runs at the working load): pattern, TE, F_t p2p, efficiency, peak pressure.

    .venv/bin/python studies/errors_study.py [--out rows.csv]   # writes docs/data/errors_study.json

Each error key alone at SIZES of its limit (meshgen.displaced.limits: the closing centre distance and the runouts
against the radial budget (3), the shaft angle (5), the wheel axial offset against the play it closes at the face
edges (docs/errors.md section 2), the worm axial offset (7), every other wheel tooth shifted (8)). The runs cover a
few mesh cycles: a runout shows the phase of the wheel revolution they see (the kinematic TE covers the revolution).
Prints a markdown table and writes the record docs/data/errors_study.json. Discussion: docs/errors.md, "Study".
"""

from __future__ import annotations

import argparse
import csv
import math
import time
from pathlib import Path

from meshgen import displaced
from meshgen.geometry import derive
from wormsim.contact3d.runner import simulate
from wormsim.scenario import ScenarioError, load_scenario

ROOT = Path(__file__).resolve().parents[1]
SIZES = (0.25, 0.5)
RUNS = {
    "screw_jack": [
        "drive.ramp_s=0.02",
        "load.ramp_s=0.02",
        "simulation.duration_s=0.1",
        "simulation.resolution=coarse",
    ],
    "seat_motor": [
        "drive.speed_rpm=3600",
        "drive.ramp_s=0.01",
        "load.ramp_s=0.01",
        "simulation.duration_s=0.06",
        "simulation.resolution=coarse",
    ],
}
KEYS = [
    "contact_pattern_centroid_face_mm",
    "contact_pattern_extent_face_mm",
    "transmission_error_p2p_urad",
    "transmission_error_kinematic_p2p_urad",
    "tangential_force_p2p_n",
    "efficiency",
    "contact_pressure_max_mpa",
    "contact_pressure_mean_mpa",
    "backlash_measured_mm",
]


def error_sets(name: str, f: float) -> dict[str, str]:
    """The errors: override per key at fraction f of its limit (mm, deg, um as the keys' names say)."""
    g = derive(load_scenario(ROOT / "scenarios" / f"{name}.yaml").gear)
    lim = displaced.limits(g)
    close = lim["radial_closing_m"]
    # the axial offset closes the play at the face edges first (docs/errors.md section 2: about 2 dz tan(alpha_x)
    # (b2 / 2) / r1), before (6)
    axial = min(lim["wheel_axial_offset_m"], g.backlash * g.r1 / (g.face_width * math.tan(g.alpha_x)))
    # every other tooth shifted: single pitch deviations of +-f on every tooth, so the short run meshes some
    pitch = ", ".join(f"{f * lim['tooth_shift_m'] * 1e6 * (k % 2):.4g}" for k in range(g.z2))
    return {
        "center_distance_mm": f"{-f * close * 1e3:.4g}",
        "shaft_angle_deg": f"{math.degrees(f * lim['shaft_angle_rad']):.4g}",
        "wheel_axial_offset_mm": f"{f * axial * 1e3:.4g}",
        "worm_axial_offset_mm": f"{f * lim['worm_axial_offset_m'] * 1e3:.4g}",
        "wheel_runout_mm": f"{f * close * 1e3:.4g}",
        "worm_runout_mm": f"{f * close * 1e3:.4g}",
        "wheel_pitch_deviation_um": f"[{pitch}]",
    }


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", type=Path, default=None, help="also write the rows as csv")
    args = ap.parse_args()
    rows = []
    for name, base in RUNS.items():
        cases = [("none", "", "")]
        for f in SIZES:
            cases += [(k, f"{f:g}", v) for k, v in error_sets(name, f).items()]
        for key, f, value in cases:
            sets = ["contact.geometry=flanks", *base] + ([f"errors.{key}={value}"] if value else [])
            t0 = time.perf_counter()
            row = {"gear": name, "error": key, "size": f, "value": value}
            try:
                s = simulate(load_scenario(ROOT / "scenarios" / f"{name}.yaml", sets)).summary
            except ScenarioError as e:  # refused (a limit or the play check): say so in the table
                s = {"efficiency": None}
                row["value"] = f"{value} (refused: {str(e)[:60]})"
            row.update({k: s.get(k) for k in KEYS})
            row["wall_s"] = round(time.perf_counter() - t0, 1)
            rows.append(row)
            print(row, flush=True)
    from wormsim.results.provenance import record

    record("errors_study", {"rows": rows})
    if args.out is not None:
        with args.out.open("w", newline="") as fh:
            w = csv.DictWriter(fh, fieldnames=list(rows[0]))
            w.writeheader()
            w.writerows(rows)
    head = ["gear", "error", "size", "value", *KEYS]
    print("| " + " | ".join(head) + " |")
    print("|" + " --- |" * len(head))
    for r in rows:
        cells = [f"{r[k]:.4g}" if isinstance(r[k], float) else ("" if r[k] is None else str(r[k])) for k in head]
        print("| " + " | ".join(cells) + " |")


if __name__ == "__main__":
    main()
