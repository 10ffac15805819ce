"""Charts of issue 12's error studies (docs/errors.md sections 7 and 8).

    .venv/bin/python studies/errors_figures.py study                 # section 7: from docs/data/errors_study.json
    .venv/bin/python studies/errors_figures.py tolerance [--runs out] # section 8: from RUNS/<gear>_tolerance/sweep.csv

`study` draws docs/img/errors_study.png: each error alone at 0.25 and 0.5 of its limit, one panel per output, the
no-error run as a line. `tolerance` copies each tolerance sweep's csv to docs/sweeps/, draws
docs/img/tolerance_<gear>.png (histograms of the outputs, scatter of each output on the error that explains most
of it) and prints the spread table and the standardised regression coefficients (least squares of each output,
standardised, on the standardised errors: beta_j = b_j sd(x_j) / sd(y)).
"""

from __future__ import annotations

import argparse
import csv
import json
import shutil
import sys
from pathlib import Path

import matplotlib.pyplot as plt  # Agg where there is no display
import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "studies"))
from tolerance_grade import RUNS as _RUNS  # noqa: E402

IMG, CSV_DIR = ROOT / "docs" / "img", ROOT / "docs" / "sweeps"
GEARS = ("screw_jack", "seat_motor")
STUDY_OUT = [
    ("tangential_force_p2p_n", "F_t p2p [N]"),
    ("transmission_error_p2p_urad", "TE p2p loaded [urad]"),
    ("transmission_error_kinematic_p2p_urad", "TE p2p kinematic [urad]"),
    ("efficiency", "efficiency [-]"),
    ("contact_pressure_max_mpa", "p_H max [MPa]"),
    ("contact_pattern_centroid_face_mm", "pattern centroid, face [mm]"),
]
ERRS = [
    "center_distance_mm",
    "shaft_angle_deg",
    "wheel_axial_offset_mm",
    "worm_axial_offset_mm",
    "wheel_runout_mm",
    "worm_runout_mm",
    "wheel_pitch_deviation_um",
]


def _num(v: str) -> float | None:
    try:
        return float(v)
    except (TypeError, ValueError):
        return None


def study(path: Path = IMG / "errors_study.png") -> None:
    rows = [
        {k: "" if v is None else str(v) for k, v in r.items()}
        for r in json.loads((ROOT / "docs" / "data" / "errors_study.json").read_text())["rows"]
    ]
    fig, axes = plt.subplots(len(STUDY_OUT), len(GEARS), figsize=(12, 2.6 * len(STUDY_OUT)), squeeze=False)
    x = np.arange(len(ERRS))
    for j, gear in enumerate(GEARS):
        rs = [r for r in rows if r["gear"] == gear]
        base = next(r for r in rs if r["error"] == "none")
        for i, (key, label) in enumerate(STUDY_OUT):
            ax = axes[i][j]
            for k, (size, color) in enumerate((("0.25", "tab:blue"), ("0.5", "tab:orange"))):
                ys = [next((_num(r[key]) for r in rs if r["error"] == e and r["size"] == size), None) for e in ERRS]
                ax.bar(
                    x + (k - 0.5) * 0.38,
                    [np.nan if y is None else y for y in ys],
                    0.38,
                    color=color,
                    label=f"{size} of the limit",
                )
            b = _num(base[key])
            if b is not None:
                ax.axhline(b, color="k", lw=1, ls="--", label="no error")
            ax.set_ylabel(label, fontsize=8)
            if key.startswith("transmission_error") or key.startswith("tangential"):
                ax.set_yscale("log")
            if key == "efficiency":  # the bars differ in the third digit: zoom (the axis does not start at 0)
                vals = [_num(r[key]) for r in rs if _num(r[key]) is not None]
                ax.set_ylim(min(vals) - 0.005, max(vals) + 0.005)
            ax.set_xticks(x)
            ax.set_xticklabels(
                [e.replace("_mm", "").replace("_deg", "").replace("_um", "") for e in ERRS]
                if i == len(STUDY_OUT) - 1
                else [],
                rotation=30,
                ha="right",
                fontsize=7,
            )
            ax.grid(axis="y", alpha=0.3)
            if i == 0:
                ax.set_title(f"{gear.replace('_', ' ')} (contact3d, exact flanks, short runs)", fontsize=9)
                ax.legend(fontsize=7)
    fig.suptitle("docs/errors.md section 7: each error alone at 0.25 and 0.5 of its limit", fontsize=10)
    fig.tight_layout()
    IMG.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=90)
    print(f"wrote {IMG / 'errors_study.png'}")


# ----------------------------------------------------------------------------- tolerance study (section 8)

# predictors of the magnitude outputs: the signed centre distance (negative closes the mesh), the sizes of the
# errors whose sign only mirrors the pattern, the runouts, and the single pitch deviations of the teeth that mesh
# in the run's steady window (a run covers about one mesh cycle: the other teeth do not mesh)
TOL_IN = [
    ("errors.center_distance_mm", "centre distance"),
    ("abs_wheel_axial_offset_mm", "abs wheel axial offset"),
    ("abs_shaft_angle_deg", "abs shaft angle"),
    ("errors.wheel_runout_mm", "wheel runout"),
    ("errors.worm_runout_mm", "worm runout"),
    ("local_fpt_um", "f_pt of the meshing teeth"),
]
# the pattern's centroid moves with the sign of the shaft angle and the axial offset
TOL_IN_SIGNED = [
    ("errors.center_distance_mm", "centre distance"),
    ("errors.wheel_axial_offset_mm", "wheel axial offset"),
    ("errors.shaft_angle_deg", "shaft angle"),
    ("errors.wheel_runout_mm", "wheel runout"),
    ("errors.worm_runout_mm", "worm runout"),
    ("local_fpt_um", "f_pt of the meshing teeth"),
]
TOL_OUT = STUDY_OUT[:5] + [("contact_pattern_centroid_face_mm", "pattern centroid [mm]")]


def _meshing_fpt_um(gear: str, shifts: np.ndarray, t0: float, t1: float) -> float:
    """Largest |single pitch deviation| (neighbour difference of the tooth shifts) among the teeth that cross the
    line of centres in the steady window [t0, t1], widened by one pitch each side (the contact zone)."""
    from meshgen import wheel
    from meshgen.geometry import derive
    from wormsim.scenario import load_scenario

    sc = load_scenario(ROOT / "scenarios" / f"{gear}.yaml", [f"{k}={v}" for k, v in _RUNS[gear].items()])
    g = derive(sc.gear)
    w2 = sc.drive.speed_rpm * 2 * np.pi / 60 * g.z1 / g.z2
    ramp = sc.drive.ramp_s
    a, b = w2 * (t0 - ramp / 2), w2 * (t1 - ramp / 2)  # wheel angle (the ramp's smooth step: half its time)
    pitch = 2 * np.pi / g.z2
    z = len(shifts)
    worst = 0.0
    for k in range(z):
        cross = (-np.pi / 2 - wheel.tooth_angle(g, k)) % (2 * np.pi)
        if a - pitch <= cross <= b + pitch or a - pitch <= cross - 2 * np.pi <= b + pitch:
            worst = max(worst, abs(shifts[k] - shifts[k - 1]), abs(shifts[(k + 1) % z] - shifts[k]))
    return float(worst)


def _tol_rows(src: Path, gear: str) -> list[dict]:
    with src.open(newline="") as fh:
        rows = [r for r in csv.DictReader(fh) if r["status"] == "ok"]
    out = []
    for r in rows:
        d = {k: _num(v) for k, v in r.items()}
        shifts = np.array(json.loads(r["errors.wheel_pitch_deviation_um"]))
        d["local_fpt_um"] = _meshing_fpt_um(gear, shifts, d["startup_time_s"], d["sim_time_s"])
        d["abs_wheel_axial_offset_mm"] = abs(d["errors.wheel_axial_offset_mm"])
        d["abs_shaft_angle_deg"] = abs(d["errors.shaft_angle_deg"])
        out.append(d)
    return out


def regression(rows: list[dict], key: str, inputs: list) -> tuple[dict, float, int]:
    """Standardised coefficients of a least-squares fit of output `key` on the errors, R^2 and the rows used."""
    use = [r for r in rows if r.get(key) is not None and np.isfinite(r[key])]
    X = np.array([[r[p] for p, _ in inputs] for r in use], float)
    y = np.array([r[key] for r in use], float)
    Xs = (X - X.mean(0)) / X.std(0)
    ys = (y - y.mean()) / y.std() if y.std() > 0 else y * 0
    A = np.column_stack([np.ones(len(y)), Xs])
    coef, *_ = np.linalg.lstsq(A, ys, rcond=None)
    resid = ys - A @ coef
    r2 = 1 - float(resid @ resid) / float(ys @ ys) if ys.any() else 0.0
    return {p: float(c) for (p, _), c in zip(inputs, coef[1:], strict=True)}, r2, len(use)


def tolerance(runs: Path) -> None:
    for gear in GEARS:
        src = runs / f"{gear}_tolerance" / "sweep.csv"
        if not src.is_file():
            print(f"{gear}: no {src}")
            continue
        CSV_DIR.mkdir(parents=True, exist_ok=True)
        shutil.copy(src, CSV_DIR / f"{gear}_tolerance.csv")
        rows = _tol_rows(src, gear)
        print(f"\n{gear}: {len(rows)} ok points")
        if len(rows) < len(TOL_IN) + 2:
            continue
        print("| output | mean | sd | min | 5 % | median | 95 % | max |")
        print("| --- | --- | --- | --- | --- | --- | --- | --- |")
        for key, label in TOL_OUT:
            v = np.array([r[key] for r in rows if r.get(key) is not None], float)
            q = np.percentile(v, [5, 50, 95])
            print(
                f"| {label} | {v.mean():.4g} | {v.std():.3g} | {v.min():.4g} | {q[0]:.4g} | {q[1]:.4g} | "
                f"{q[2]:.4g} | {v.max():.4g} |"
            )
        print("\n| output | R^2 | " + " | ".join(lbl for _, lbl in TOL_IN) + " |")
        print("| --- | --- |" + " --- |" * len(TOL_IN))
        fits = {}
        for key, label in TOL_OUT:
            inputs = TOL_IN_SIGNED if key == "contact_pattern_centroid_face_mm" else TOL_IN
            beta, r2, _ = regression(rows, key, inputs)
            fits[key] = (beta, dict(inputs))
            print(f"| {label} | {r2:.2f} | " + " | ".join(f"{b:+.2f}" for b in beta.values()) + " |")
        fig, axes = plt.subplots(2, len(TOL_OUT), figsize=(3.0 * len(TOL_OUT), 5.6))
        for i, (key, label) in enumerate(TOL_OUT):
            v = np.array([r[key] for r in rows if r.get(key) is not None], float)
            axes[0][i].hist(v, bins=15, color="tab:blue", alpha=0.8)
            axes[0][i].set_xlabel(label, fontsize=8)
            axes[0][i].set_ylabel("points" if i == 0 else "", fontsize=8)
            beta, names = fits[key]
            top = max(beta, key=lambda p: abs(beta[p]))
            xs = [r[top] for r in rows if r.get(key) is not None]
            axes[1][i].scatter(xs, v, s=8)
            axes[1][i].set_xlabel(f"{names[top]} (beta {beta[top]:+.2f})", fontsize=8)
            axes[1][i].set_ylabel(label, fontsize=8)
            for ax in axes[:, i]:
                ax.tick_params(labelsize=7)
                ax.grid(alpha=0.3)
        fig.suptitle(
            f"{gear.replace('_', ' ')}: tolerance study, grade 8, {len(rows)} random points "
            "(contact3d, exact flanks); bottom: each output on its dominant error",
            fontsize=9,
        )
        fig.tight_layout()
        fig.savefig(IMG / f"tolerance_{gear}.png", dpi=90)
        print(f"wrote {IMG / f'tolerance_{gear}.png'}")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("what", choices=["study", "tolerance"])
    ap.add_argument("--runs", type=Path, default=ROOT / "out")
    args = ap.parse_args()
    study() if args.what == "study" else tolerance(args.runs)


if __name__ == "__main__":
    main()
