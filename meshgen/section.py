"""docs/img/seat_motor_section.png: the wheel mid-plane section (assembly z = 0) of the generated worm and wheel
meshes at theta1 = theta2 = 0, in mm (`make images` calls plot_section with a scenario's gear set)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from meshgen.geometry import GearGeometry
from meshgen.pieces import GearSet


def plot_section(
    g: GearGeometry, gs: GearSet, out_png: str | Path, name: str, half_width_modules: float = 14.0
) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import trimesh
    from matplotlib.collections import LineCollection

    from meshgen import assembly

    hand = "right" if g.hand > 0 else "left"
    fig, ax = plt.subplots(figsize=(8, 5.2))
    for mesh, T, color, label in (
        (gs.wheel_visual, assembly.wheel_to_assembly(0.0), "#c88a1e", f"wheel ({g.z2} teeth)"),
        (gs.worm_visual, assembly.worm_to_assembly(0.0, g), "#55606e", f"worm ({g.z1} start, {hand} hand)"),
    ):
        m = mesh.copy()
        m.apply_transform(T)
        seg = trimesh.intersections.mesh_plane(m, plane_normal=[0, 0, 1], plane_origin=[0, 0, 0])  # (n, 2, 3)
        ax.add_collection(LineCollection(seg[:, :, :2] * 1e3, colors=color, linewidths=1.0, label=label))
    w = half_width_modules * g.m_x * 1e3
    ax.set_xlim(-w, w)
    ax.set_ylim(-(g.a + g.r_a1 + 0.8 * g.m_x) * 1e3, -(g.r2 - 6 * g.m_x) * 1e3)
    ax.set_aspect("equal")
    ax.axhline(-g.r2 * 1e3, color="0.6", ls="--", lw=0.7)
    ax.text(
        -w * 0.97,
        -g.r2 * 1e3,
        "wheel reference circle d2",
        ha="left",
        va="center",
        fontsize=8,
        color="0.3",
        bbox=dict(facecolor="white", edgecolor="none", alpha=0.85),
    )
    ax.set_xlabel("x along the worm axis [mm]")
    ax.set_ylabel("y towards the wheel centre [mm] (wheel centre at 0)")
    ax.set_title(
        f"{name}: wheel mid-plane section of the generated meshes (m_x {g.m_x * 1e3:.3g} mm, "
        f"alpha_n {np.degrees(g.alpha_n):.3g} deg, backlash {g.backlash * 1e3:.3g} mm)",
        fontsize=9,
    )
    ax.legend(loc="center", fontsize=9)
    ax.grid(True, alpha=0.25)
    fig.tight_layout()
    fig.savefig(out_png, dpi=110)
    plt.close(fig)
