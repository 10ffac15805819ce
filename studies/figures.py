"""Charts and tables of the shipped studies for README "Sweeps" and docs/sweeps.md, from their sweep.csv.

    .venv/bin/wormsim sweep studies/NAME.yaml --out out/sweeps/NAME      # for each study
    .venv/bin/python studies/figures.py [--runs out/sweeps]

Copies each sweep.csv to docs/sweeps/NAME.csv, draws docs/img/sweep_*.png and prints the markdown tables.
"""

from __future__ import annotations

import argparse
import math
import shutil
from pathlib import Path

import matplotlib.pyplot as plt  # Agg where there is no display

from wormsim.sweep.plot import parse_value
from wormsim.sweep.runner import read_csv

ROOT = Path(__file__).resolve().parents[1]
IMG, CSV_DIR = ROOT / "docs" / "img", ROOT / "docs" / "sweeps"
# seed 002 Tables 3 and 4: mean meshing force, peak-to-peak fluctuation, maximum force [N]
SEED_K = {2.0e8: (221, 10940, 10945), 4.39e8: (414, 21850, 21889), 6.0e8: (550, 32830, 32834)}
SEED_N = {1000: (324, 18070, 18071), 1330: (414, 21850, 21889), 1500: (498, 27090, 27090), 2000: (685, 36110, 36109)}


def rows(runs: Path, name: str) -> list[dict]:
    src = runs / name / "sweep.csv"
    if not src.is_file():
        return []
    CSV_DIR.mkdir(parents=True, exist_ok=True)
    shutil.copy(src, CSV_DIR / f"{name}.csv")
    return [{k: parse_value(v) for k, v in r.items()} for r in read_csv(src)]


def _f(v) -> str:
    return "-" if v is None else f"{v:.0f}"


def screw_jack(runs: Path) -> None:
    fig, axes = plt.subplots(1, 2, figsize=(12, 4.6), constrained_layout=True)
    panels = (
        (axes[0], "screw_jack_stiffness", "contact.stiffness_n_per_m", SEED_K, "K [N/m]"),
        (axes[1], "screw_jack_speed", "drive.speed_rpm", SEED_N, "worm speed [rpm]"),
    )
    for ax, name, key, seed, xlabel in panels:
        sx = sorted(seed)
        ax.plot(sx, [seed[v][0] for v in sx], "s--", color="0.5", label="seed 002: mean")
        ax.plot(sx, [seed[v][2] for v in sx], "^--", color="0.3", label="seed 002: maximum (p2p alike)")
        for level, suffix, style in (("contact3d", "", "o-"), ("torsional", "_torsional", "x:")):
            rs = [r for r in rows(runs, name + suffix) if r["status"] == "ok"]
            if not rs:
                continue
            print(
                f"\n{name}{suffix}\n| {xlabel} | seed mean / p2p / max [N] | F_t mean | F_t p2p | F_t max (steady) "
                "| start-up peak | TE p2p [urad] | efficiency |\n| --- | --- | --- | --- | --- | --- | --- | --- |"
            )
            for r in rs:
                s = seed.get(r[key])
                print(
                    f"| {r[key]:.4g} | {' / '.join(str(v) for v in s) if s else '-'} | "
                    f"{r['tangential_force_mean_n']:.1f} | {r['tangential_force_p2p_n']:.3g} | "
                    f"{_f(r.get('tangential_force_max_n'))} | {_f(r.get('startup_tangential_force_peak_n'))} | "
                    f"{r['transmission_error_p2p_urad']:.1f} | {r['efficiency']:.3f} |"
                )
            x = [r[key] for r in rs]
            for k, lab in (
                ("tangential_force_mean_n", "F_t mean"),
                ("tangential_force_p2p_n", "F_t p2p"),
                ("tangential_force_max_n", "F_t max"),
                ("startup_tangential_force_peak_n", "start-up peak"),
            ):
                y = [r.get(k) for r in rs]
                if all(isinstance(v, float) for v in y):
                    geo = rs[0].get("contact_geometry") if level == "contact3d" else None
                    ax.plot(x, y, style, label=f"{level}{' ' + geo if geo else ''}: {lab}")
        ax.set_yscale("log")
        ax.set_xlabel(xlabel)
        ax.set_ylabel("tangential force on the wheel [N]")
        ax.grid(alpha=0.3, which="both")
        ax.legend(fontsize=7, ncol=2)
    axes[0].set_title("seed 002 Table 3: contact stiffness (1330 rpm)")
    axes[1].set_title("seed 002 Table 4: worm speed (K 4.39e8 N/m)")
    fig.savefig(IMG / "sweep_screw_jack.png", dpi=100)
    plt.close(fig)


def friction(runs: Path) -> None:
    rs = rows(runs, "seat_motor_friction")
    if not rs:
        return
    gamma, alpha_n = math.radians(4.79), math.radians(10.0)
    mu_lock = math.tan(gamma) * math.cos(alpha_n)
    fig, ax = plt.subplots(figsize=(7, 4.4), constrained_layout=True)
    tor = [r for r in rs if r["model"] == "torsional" and r["status"] == "ok"]
    c3d = [r for r in rs if r["model"] == "contact3d" and r["status"] == "ok"]
    failed = [r for r in rs if r["status"] != "ok"]
    mus = [i / 1000 for i in range(10, 161)]
    theory = [math.tan(gamma) / math.tan(gamma + math.atan(m / math.cos(alpha_n))) for m in mus]
    ax.plot(mus, theory, "k--", lw=1, label="tan(gamma) / tan(gamma + rho')")
    ax.plot([r["contact.friction"] for r in tor], [r["efficiency"] for r in tor], "o-", ms=3, label="torsional")
    geo = c3d[0].get("contact_geometry") if c3d else None
    c3d_label = f"contact3d ({geo})" if geo else "contact3d"
    ax.plot([r["contact.friction"] for r in c3d], [r["efficiency"] for r in c3d], "s", ms=7, label=c3d_label)
    if failed:
        ax.plot([r["contact.friction"] for r in failed], [0.05] * len(failed), "rx", label="failed")
    ax.axvline(mu_lock, color="red", lw=1)
    ax.axvspan(mu_lock, 0.16, color="red", alpha=0.06)
    ax.text(mu_lock + 0.002, 0.75, f"self-locking\n(rho' > gamma,\nmu > {mu_lock:.4f})", color="red", fontsize=8)
    ax.set_xlabel("friction coefficient mu (contact.friction)")
    ax.set_ylabel("efficiency (output / input power)")
    ax.set_title("seat motor (seed 001 gear, 1800 rpm, 24 N m): efficiency against mu")
    ax.set_xlim(0.01, 0.16)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    fig.savefig(IMG / "sweep_seat_motor_friction.png", dpi=100)
    plt.close(fig)
    print("\nseat_motor_friction\n| mu | torsional | contact3d | tan g / tan(g + rho') |\n| --- | --- | --- | --- |")
    by = {}
    for r in rs:
        by.setdefault(r["contact.friction"], {})[r["model"]] = r
    for mu in sorted(by):
        if mu in {r["contact.friction"] for r in c3d} or abs(mu * 100 - round(mu * 100)) < 1e-9:
            t, c = by[mu].get("torsional"), by[mu].get("contact3d")
            th = math.tan(gamma) / math.tan(gamma + math.atan(mu / math.cos(alpha_n)))
            print(f"| {mu:.3f} | {_cell(t)} | {_cell(c)} | {th:.3f} |")


def _cell(r) -> str:
    return "-" if r is None else (f"{r['efficiency']:.3f}" if r["status"] == "ok" else "failed")


def resonance(runs: Path) -> None:
    rs = [r for r in rows(runs, "screw_jack_resonance") if r["status"] == "ok"]
    if not rs:
        return
    n = [r["drive.speed_rpm"] for r in rs]
    fn = rs[0]["mesh_natural_frequency_hz"]
    z1 = 1
    fig, axes = plt.subplots(2, 1, figsize=(9, 7), sharex=True, constrained_layout=True)
    axes[0].plot(n, [r["tangential_force_p2p_n"] for r in rs], "o-", ms=2.5)
    axes[0].set_ylabel("F_t p2p [N]")
    axes[0].set_yscale("log")
    axes[1].plot(n, [r["transmission_error_p2p_urad"] for r in rs], "o-", ms=2.5)
    axes[1].set_ylabel("transmission error p2p [urad]")
    for ax in axes:
        for h in range(1, 200):
            nh = 60 * fn / (z1 * h)
            if min(n) <= nh <= max(n) and (h <= 20 or h in (30, 40, 50, 100)):
                ax.axvline(nh, color="red", lw=0.6, alpha=0.5)
                if ax is axes[0]:
                    ax.text(nh, 1.02, f"{h}", transform=ax.get_xaxis_transform(), ha="center", fontsize=6, color="red")
        ax.axvspan(1000, 2000, color="green", alpha=0.08)
        ax.grid(alpha=0.3, which="both")
        ax.set_xscale("log")
    axes[1].set_xlabel("worm speed [rpm]")
    axes[0].set_title(
        f"screw jack, torsional: h x meshing frequency = mesh mode {fn:.0f} Hz at the red lines (h above); "
        "green: seed 002's speeds",
        fontsize=9,
    )
    fig.savefig(IMG / "sweep_screw_jack_resonance.png", dpi=100)
    plt.close(fig)


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--runs", default=str(ROOT / "out" / "sweeps"))
    runs = Path(ap.parse_args().runs)
    IMG.mkdir(parents=True, exist_ok=True)
    screw_jack(runs)
    friction(runs)
    resonance(runs)


if __name__ == "__main__":
    main()
