"""torsional report.png and recording.rrd."""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from wormsim.results.recording import save_series_recording
from wormsim.results.report_header import (
    draw_header,
    gear_line,
    header_rows,
    results_line,
    shafts_line,
    speed_ylim,
    steady_ylim,
    warning_text,
)
from wormsim.results.result import Result
from wormsim.tooth.mesh_stiffness import MeshStiffness
from wormsim.tooth.stiffness_plot import draw_load_shares, draw_mesh_stiffness

# ----------------------------------------------------------------------------- report, recording


def write_report(result: Result, path) -> None:
    """report.png: a header (gear, torques, powers, efficiency, self-locking); speeds, forces, transmission error
    (axes scaled to the steady window, the start-up peak as a number), k(theta) over one mesh cycle and the load share
    of each wheel tooth (wormsim.tooth.stiffness_plot)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    S, sm = result.series, result.summary
    ms: MeshStiffness = result.extra["mesh_stiffness"]
    geo = result.extra.get("geometry")
    t = S["t_s"]
    w0, w1 = sm["steady_window_s"]
    lines = [gear_line(geo) if geo is not None else "", shafts_line(sm), results_line(sm, geo)]
    warn = warning_text(sm)
    hh = header_rows(lines, warn)
    lt = result.extra.get("ltca")  # the loaded TCA of the teeth's compliance (None unless the run uses it)
    rows = [hh, 3.8, 3.8] + ([3.8] if lt is not None else [])
    fig = plt.figure(figsize=(12, sum(rows)), constrained_layout=True)
    gs = fig.add_gridspec(len(rows), 2, height_ratios=rows)
    ax = np.array([[fig.add_subplot(gs[i, j]) for j in range(2)] for i in (1, 2)])
    draw_header(
        fig.add_subplot(gs[0, :]),
        lines,
        f"{sm.get('scenario', '')} (torsional): timestep {sm['timestep_s']:.3g} s, steady window {w0:.3g}-{w1:.3g} s",
        warn=warn,
    )
    a = ax[0, 0]
    speeds = [S["worm_speed_rpm"], S["wheel_speed_rpm"] * sm["ratio_theory"]]
    a.plot(t, speeds[0], label="worm")
    a.plot(t, speeds[1], "--", label="wheel x ratio")
    a.axvspan(w0, w1, color="0.9", zorder=-1, label="steady window")
    a.set_ylim(*speed_ylim(t, speeds, (w0, w1)))
    a.set_xlabel("t [s]")
    a.set_ylabel("speed [rpm]")
    a.legend(fontsize=8, loc="lower right")
    a.set_title(f"shaft speeds (worm {sm['worm_speed_mean_rpm']:.4g} rpm, ratio {sm['ratio']:.5g})")
    a = ax[0, 1]
    forces = [S[k] for k in ("tangential_force_n", "radial_force_n", "axial_force_n")]
    for y, lab in zip(forces, ("tangential", "radial", "axial"), strict=True):
        a.plot(t, y, label=lab)
    a.axvspan(w0, w1, color="0.9", zorder=-1, label="steady window")
    lo, hi = steady_ylim(t, forces, (w0, w1))
    pre = t < w0  # the start-up, before the steady window
    peak = float(np.max(np.abs(S["tangential_force_n"][pre]))) if pre.any() else float("nan")
    # headroom above the curves for the legend, so that it never covers them
    a.set_ylim(lo, hi + 0.35 * (hi - lo))
    if np.isfinite(peak):
        off = " (off scale)" if peak > hi + 0.35 * (hi - lo) else ""
        a.plot([], [], " ", label=f"start-up peak |F_t| {peak:.4g} N{off}")
    a.set_xlabel("t [s]")
    a.set_ylabel("force [N]")
    a.set_title("forces on the wheel (axes: steady window)")
    a.legend(fontsize=8, loc="upper center", ncol=3)
    a = ax[1, 0]
    te = S["transmission_error_rad"] * 1e6
    a.plot(t, te)
    a.axvspan(w0, w1, color="0.9", zorder=-1)
    a.set_ylim(*steady_ylim(t, [te], (w0, w1)))
    a.set_xlabel("t [s]")
    a.set_ylabel("transmission error [urad]")
    a.set_title("theta2 - hand theta1 z1/z2 (axes: steady window)")
    draw_mesh_stiffness(ax[1, 1], ms, lt)
    if lt is not None:
        draw_load_shares(fig.add_subplot(gs[3, :]), lt, ms.stiffness_source)
    path = Path(path)
    tmp = path.with_name(f".{path.name}.tmp.png")
    fig.savefig(tmp, dpi=100)
    plt.close(fig)
    os.replace(tmp, path)


def write_recording(result: Result, path) -> None:
    save_series_recording(path, result.summary.get("scenario", "torsional"), result.series["t_s"], result.series)
