"""torsional report.png and recording.rrd."""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from wormsim.recording import save_series_recording
from wormsim.result import Result
from wormsim.tooth.mesh_stiffness import MeshStiffness

# ----------------------------------------------------------------------------- report, recording


def write_report(result: Result, path) -> None:
    """report.png: speeds, forces, transmission error, and k(theta) over one mesh cycle."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    S, sm = result.series, result.summary
    ms: MeshStiffness = result.extra["mesh_stiffness"]
    t = S["t_s"]
    fig, ax = plt.subplots(2, 2, figsize=(12, 7), constrained_layout=True)
    a = ax[0, 0]
    a.plot(t, S["worm_speed_rpm"], label="worm")
    a.plot(t, S["wheel_speed_rpm"] * sm["ratio_theory"], "--", label="wheel x ratio")
    a.set_xlabel("t [s]")
    a.set_ylabel("speed [rpm]")
    a.legend()
    a.set_title("shaft speeds")
    a = ax[0, 1]
    for k in ("tangential_force_n", "radial_force_n", "axial_force_n"):
        a.plot(t, S[k], label=k.removesuffix("_force_n"))
    w0, w1 = sm["steady_window_s"]
    a.axvspan(w0, w1, color="0.9", zorder=-1, label="steady window")
    # headroom above the curves for the legend, so that it never covers them
    lo, hi = a.get_ylim()
    a.set_ylim(lo, hi + 0.35 * (hi - lo))
    a.set_xlabel("t [s]")
    a.set_ylabel("force [N]")
    a.set_title("forces on the wheel")
    a.legend(fontsize=8, loc="upper center", ncol=4)
    a = ax[1, 0]
    a.plot(t, S["transmission_error_rad"] * 1e6)
    a.set_xlabel("t [s]")
    a.set_ylabel("transmission error [urad]")
    a.set_title("theta2 - hand theta1 z1/z2")
    a = ax[1, 1]
    deg = np.degrees(ms.theta1_rad)
    a.plot(deg, ms.k_mesh_fwd_n_per_m, "o-", ms=3, label="flank side +1 (forward)")
    a.plot(deg, ms.k_mesh_rev_n_per_m, "s--", ms=3, label="flank side -1")
    a.set_xlabel("worm angle in the mesh cycle [deg]")
    a.set_ylabel("k on the line of action [N/m]")
    a.set_title(f"mesh stiffness (TCA, {ms.samples} samples)")
    a.legend(fontsize=8)
    fig.suptitle(
        f"{sm.get('scenario', '')} (torsional): ratio {sm['ratio']:.4g}, "
        f"F_t {sm['tangential_force_mean_n']:.4g} N, "
        f"efficiency {sm['efficiency']:.3f}"
    )
    path = Path(path)
    tmp = path.with_name(f".{path.name}.tmp.png")
    fig.savefig(tmp, dpi=100)
    plt.close(fig)
    os.replace(tmp, path)


def write_recording(result: Result, path) -> None:
    save_series_recording(path, result.summary.get("scenario", "torsional"), result.series["t_s"], result.series)
