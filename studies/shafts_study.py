"""The shafts study: the screw jack and the seat motor on realistic bearings, rigid beside compliant, against load:
the worm's deflection at the mesh, the bearing loads, the contact pattern and the loaded transmission error
(contact3d, exact flanks, short coarse runs at each load; docs/multibody.md, "Study").

    .venv/bin/python studies/shafts_study.py [--out docs/data/shafts_study.json] [--figure docs/img/shafts_study.png]

The seat motor runs at 3600 rpm (seed 001's 36 rpm needs 1.7 s per mesh cycle), as studies/errors_study.py does. The
bearing data are typical values, not measurements of either drive: the screw jack's worm (d1 25 mm) on two ball
bearings 120 mm apart, radial 200 N/um, axial 100 N/um; its wheel on two bearings 50 mm apart, 300 / 150 N/um. The
seat motor's worm (d1 ~ 8 mm) on the motor shaft between two sintered bushings 15 mm and 25 mm from the mesh,
radial 20 N/um, axial 10 N/um; its POM wheel on a steel pin, bushings 16 mm apart, 30 / 10 N/um.
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

from wormsim.contact3d.runner import simulate
from wormsim.results.provenance import provenance
from wormsim.scenario import Scenario, load_scenario

ROOT = Path(__file__).resolve().parents[1]
RUNS = {
    "screw_jack": {
        "set": {
            "drive": {"ramp_s": 0.02},
            "load": {"ramp_s": 0.02},
            "simulation": {"duration_s": 0.1, "resolution": "coarse", "record_every": 10},
        },
        "loads_nm": [3.0, 6.0, 9.0, 12.0, 15.0],
        "shafts": {
            "worm": {
                "bearings_mm": [-60, 60],
                "radial_stiffness_n_per_um": 200,
                "axial_stiffness_n_per_um": 100,
                "bending": True,
            },
            "wheel": {"bearings_mm": [-25, 25], "radial_stiffness_n_per_um": 300, "axial_stiffness_n_per_um": 150},
        },
    },
    "seat_motor": {
        "set": {
            "drive": {"speed_rpm": 3600, "ramp_s": 0.01},
            "load": {"ramp_s": 0.01},
            "simulation": {"duration_s": 0.06, "resolution": "coarse", "record_every": 10},
        },
        "loads_nm": [6.0, 12.0, 18.0, 24.0],
        "shafts": {
            "worm": {
                "bearings_mm": [-15, 25],
                "radial_stiffness_n_per_um": 20,
                "axial_stiffness_n_per_um": 10,
                "bending": True,
            },
            "wheel": {"bearings_mm": [-8, 8], "radial_stiffness_n_per_um": 30, "axial_stiffness_n_per_um": 10},
        },
    },
}
KEYS = [
    "ratio",
    "tangential_force_mean_n",
    "efficiency",
    "transmission_error_p2p_urad",
    "contact_pattern_centroid_face_mm",
    "contact_pattern_extent_face_mm",
    "contact_pressure_max_mpa",
    "worm_deflection_mesh_um",
    "wheel_deflection_mesh_um",
    "worm_bearing_radial_mean_n",
    "wheel_bearing_radial_mean_n",
    "worm_bearing_axial_mean_n",
    "wheel_bearing_axial_mean_n",
]


def scenario(name: str, torque_nm: float, compliant: bool) -> Scenario:
    cfg = RUNS[name]
    d = load_scenario(ROOT / "scenarios" / f"{name}.yaml").model_dump()
    for block, vals in cfg["set"].items():
        d[block].update(vals)
    d["load"]["torque_nm"] = torque_nm
    if compliant:
        d["shafts"] = cfg["shafts"]
    return Scenario.model_validate(d)


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", default=str(ROOT / "docs/data/shafts_study.json"))
    ap.add_argument("--figure", default=str(ROOT / "docs/img/shafts_study.png"))
    a = ap.parse_args(argv)
    rows = []
    for name, cfg in RUNS.items():
        for T in cfg["loads_nm"]:
            for compliant in (False, True):
                s = simulate(scenario(name, T, compliant)).summary
                row = {"scenario": name, "load_nm": T, "shafts": "compliant" if compliant else "rigid"}
                row.update({k: s.get(k) for k in KEYS})
                rows.append(row)
                print(json.dumps(row), flush=True)
    doc = {
        "provenance": provenance(
            " ".join(["python", "studies/shafts_study.py", *(argv if argv is not None else sys.argv[1:])])
        ),
        "runs": {k: {"set": v["set"], "shafts": v["shafts"], "loads_nm": v["loads_nm"]} for k, v in RUNS.items()},
        "rows": rows,
    }
    Path(a.out).parent.mkdir(parents=True, exist_ok=True)
    Path(a.out).write_text(json.dumps(doc, indent=1) + "\n")
    figure(rows, a.figure)


def figure(rows: list[dict], path: str) -> None:
    """Per scenario: TE p2p, the pattern's centroid across the face and the worm's mesh deflection against load,
    rigid beside compliant."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    names = list(RUNS)
    panels = [
        ("transmission_error_p2p_urad", "TE p2p [urad]"),
        ("contact_pattern_centroid_face_mm", "pattern centroid across the face [mm]"),
        ("worm_deflection_mesh_um", "worm deflection at the mesh [um]"),
    ]
    fig, axes = plt.subplots(len(names), len(panels), figsize=(13, 7), squeeze=False)
    for i, name in enumerate(names):
        for j, (key, label) in enumerate(panels):
            ax = axes[i][j]
            for mode, style in (("rigid", "o-"), ("compliant", "s--")):
                pts = [(r["load_nm"], r[key]) for r in rows if r["scenario"] == name and r["shafts"] == mode]
                pts = [(x, y if y is not None else 0.0) for x, y in pts]
                ax.plot([p[0] for p in pts], [p[1] for p in pts], style, label=mode)
            ax.set_xlabel("wheel load [N m]")
            ax.set_ylabel(label)
            ax.set_title(name)
            ax.grid(alpha=0.3)
            ax.legend()
    fig.tight_layout()
    Path(path).parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=110)


if __name__ == "__main__":
    main()
