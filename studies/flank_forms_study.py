"""The five worm flank forms on the screw jack and the seat motor at the same load (docs/flank_forms.md).

Each form at contact3d (exact flanks, the seeds' CI settings of tests/contact3d/test_seeds_pieces.py) and at
torsional (the
mesh stiffness); writes docs/data/flank_forms.json with provenance {command, commit, date, machine} and
docs/img/flank_forms.png (per form: p_H max and mean, efficiency against the theory at the contact radius, F_t p2p,
TE p2p, mesh stiffness) and docs/img/flank_forms_pattern.png (the loaded contact pattern of each form, as report.png
draws it). A form the gear data cannot make (wormsim's exit 2 checks) is recorded with its message.

    PYTHONPATH=. python studies/flank_forms_study.py
"""

from __future__ import annotations

import datetime
import json
import platform
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from meshgen.geometry import derive  # noqa: E402
from tests.contact3d.test_seeds_pieces import CI  # noqa: E402  (the seeds' CI settings)
from wormsim.contact3d.runner import simulate  # noqa: E402
from wormsim.physics.validate import validate_geometry  # noqa: E402
from wormsim.run import run_scenario  # noqa: E402
from wormsim.scenario import ScenarioError, load_scenario  # noqa: E402
from wormsim.tooth.hertz import draw_pattern  # noqa: E402

FORMS = {
    "ZA": [],
    "ZI": [],
    "ZN": ["gear.zn_section=thread"],
    "ZK": [],
    # the default arc radius 5.5 m_x undercuts these unshifted wheels (docs/flank_forms.md): 10 m_x (the screw jack's
    # 25 mm, the INTERFACE example) is the smallest of 5.5, 8, 10 m_x that the undercut check passes
    # unshifted wheels (ZC's default profile shift 0.5 turned off): the study compares the forms on the same wheel
    "ZC": ["gear.profile_radius_mm=25", "gear.profile_shift_coefficient=0"],
}
GEARS = ("screw_jack", "seat_motor")
KEYS = (
    "contact_pressure_max_mpa",
    "contact_pressure_mean_mpa",
    "efficiency",
    "efficiency_theory_at_contact_radius",
    "tangential_force_mean_n",
    "tangential_force_p2p_n",
    "transmission_error_p2p_urad",
    "ratio",
    "mesh_frequency_hz",
    "mesh_frequency_theory_hz",
)


PATTERNS: dict = {}  # (gear, form) -> (pattern grid, geometry, summary) for the pattern figure


def one(gear: str, form: str) -> dict:
    sets = CI[gear] + ["contact.geometry=flanks", f"gear.profile={form}", *FORMS[form]]
    if gear == "seat_motor" and form == "ZC":
        sets = [s for s in sets if not s.startswith("gear.profile_radius_mm")]
    rec: dict = {"set": sets}
    try:
        sc = load_scenario(ROOT / "scenarios" / f"{gear}.yaml", sets)
        validate_geometry(sc)
    except ScenarioError as exc:
        rec["refused"] = str(exc)
        return rec
    res = simulate(sc)
    s = res.summary
    rec["contact3d"] = {k: s.get(k) for k in KEYS}
    PATTERNS[gear, form] = (res.extra.get("flank_pattern"), derive(sc.gear), s)
    sct = load_scenario(ROOT / "scenarios" / f"{gear}.yaml", ["model=torsional", f"gear.profile={form}", *FORMS[form]])
    with tempfile.TemporaryDirectory() as d:
        st = run_scenario(sct, d, progress=False)
    rec["torsional"] = {
        k: st.get(k)
        for k in ("mesh_stiffness_mean_n_per_m", "mesh_stiffness_p2p_n_per_m", "transmission_error_p2p_urad")
        if k in st
    }
    rec["torsional"].update({k: v for k, v in st.items() if "stiffness" in k and isinstance(v, float)})
    return rec


def figure(data: dict, path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    panels = (
        ("p_H max / mean (MPa)", "contact3d", ("contact_pressure_max_mpa", "contact_pressure_mean_mpa")),
        ("efficiency / theory at contact radius - 1 (%)", "contact3d", None),
        ("F_t p2p (N)", "contact3d", ("tangential_force_p2p_n",)),
        ("TE p2p (urad)", "contact3d", ("transmission_error_p2p_urad",)),
        ("mesh stiffness mean, min, max (N/um)", "torsional", None),
    )
    fig, axes = plt.subplots(len(GEARS), len(panels), figsize=(18, 3.3 * len(GEARS)))
    for i, gear in enumerate(GEARS):
        forms = [f for f in FORMS if "contact3d" in data[gear][f]]
        x = list(range(len(forms)))
        for j, (title, level, keys) in enumerate(panels):
            ax = axes[i, j]
            if j == 1:
                c = [data[gear][f]["contact3d"] for f in forms]
                ax.bar(x, [100 * (r["efficiency"] / r["efficiency_theory_at_contact_radius"] - 1) for r in c])
                ax.axhline(0, color="k", lw=0.6)
            elif j == 4:
                t = [data[gear][f]["torsional"] for f in forms]
                for n, k in enumerate(("mean", "min", "max")):
                    vals = [r[f"mesh_stiffness_{k}_n_per_m"] * 1e-6 for r in t]
                    ax.bar([v + 0.27 * n for v in x], vals, width=0.27, label=k)
                ax.legend(fontsize=6)
            else:
                w = 0.8 / len(keys)
                for n, k in enumerate(keys):
                    vals = [data[gear][f][level][k] or 0.0 for f in forms]
                    ax.bar([v + n * w for v in x], vals, width=w, label=k.replace("contact_pressure_", "p_H "))
                if len(keys) > 1:
                    ax.legend(fontsize=6)
            ax.set_xticks(x, forms)
            ax.set_title(f"{gear}: {title}", fontsize=9)
    fig.tight_layout()
    fig.savefig(path, dpi=80)
    plt.close(fig)


def pattern_figure(path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    keys = [k for k in PATTERNS if PATTERNS[k][0] is not None]
    fig, axes = plt.subplots(len(GEARS), len(FORMS), figsize=(4.2 * len(FORMS), 3.6 * len(GEARS)), squeeze=False)
    for i, gear in enumerate(GEARS):
        for j, form in enumerate(FORMS):
            ax = axes[i, j]
            if (gear, form) not in keys:
                ax.text(0.5, 0.5, f"{gear} {form}: refused\n(undercut wheel)", ha="center", va="center", fontsize=9)
                ax.set_axis_off()
                continue
            grid, geo, s = PATTERNS[gear, form]
            draw_pattern(ax, fig, grid, geo, s)
            ax.set_title(f"{gear} {form}", fontsize=9)
            ax.set_xlabel("face position (mm)", fontsize=7)
            ax.set_ylabel("wheel radius (mm)", fontsize=7)
            ax.legend(fontsize=5, loc="lower right")
            ax.autoscale_view()
    fig.tight_layout()
    fig.savefig(path, dpi=75)
    plt.close(fig)


def main() -> None:
    data: dict = {g: {f: one(g, f) for f in FORMS} for g in GEARS}
    commit = subprocess.run(["git", "rev-parse", "HEAD"], cwd=ROOT, capture_output=True, text=True).stdout.strip()
    record = {
        "provenance": {
            "command": "PYTHONPATH=. python studies/flank_forms_study.py",
            "commit": commit,
            "date": datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds"),
            "machine": f"{platform.node()} {platform.machine()} {platform.processor() or ''}".strip(),
        },
        "forms": FORMS,
        "results": data,
    }
    (ROOT / "docs" / "data" / "flank_forms.json").write_text(json.dumps(record, indent=1) + "\n")
    figure(data, ROOT / "docs" / "img" / "flank_forms.png")
    pattern_figure(ROOT / "docs" / "img" / "flank_forms_pattern.png")
    print(json.dumps(record, indent=1))


if __name__ == "__main__":
    main()
