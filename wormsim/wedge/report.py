"""wedge report.png and recording.rrd."""

from __future__ import annotations

from wormsim.recording import save_series_recording
from wormsim.result import Result
from wormsim.wedge.dynamics import INVERSE, LOCKED, TRACTIVE, UNLOADED

# ----------------------------------------------------------------------------- report, recording


def write_report(result: Result, path) -> None:
    """report.png: S1(t) with F1, S2(t) with F2, speed, regime timeline; the summary in the title."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    s, m = result.series, result.summary
    t_ms = s["t_s"] * 1e3
    fig, ax = plt.subplots(4, 1, figsize=(9, 10), sharex=True, gridspec_kw={"height_ratios": [3, 3, 2, 1]})
    ax[0].plot(t_ms, s["S1_n"], label="S1 (internal, worm side)")
    ax[0].plot(t_ms, s["F1_n"], "--", lw=1, label="F1 (motor)")
    ax[0].plot(m["S1_peak_time_s"] * 1e3, m["S1_peak_n"], "ro", ms=4, label=f"peak {m['S1_peak_n']:.0f} N")
    ax[0].set_ylabel("force [N]")
    ax[1].plot(t_ms, s["S2_n"], label="S2 (internal, wheel side)")
    ax[1].plot(t_ms, s["F2_n"], "--", lw=1, label="F2 (load)")
    ax[1].plot(m["S2_peak_time_s"] * 1e3, m["S2_peak_n"], "ro", ms=4, label=f"peak {m['S2_peak_n']:.0f} N")
    ax[1].set_ylabel("force [N]")
    ax[2].plot(t_ms, s["v1_m_s"], label="x1' (worm pitch line)")
    ax[2].plot(t_ms, s["vs_m_s"], ":", lw=1, label="Vs (sliding)")
    ax[2].set_ylabel("speed [m/s]")
    ax[3].step(t_ms, s["regime_code"], where="post")
    ax[3].set_yticks([0, 1, 2, 3], [LOCKED, TRACTIVE, INVERSE, UNLOADED])
    ax[3].set_ylim(-0.5, 3.5)
    ax[3].set_xlabel("time [ms]")
    for a in ax[:3]:
        a.legend(loc="best", fontsize=8)
    for a in ax:
        a.grid(True, alpha=0.3)
    name = result.extra.get("name", "wedge")
    fig.suptitle(
        f"{name}: wedge model (monitor {m['monitor']}), Kd1 {m['Kd1']:.2f}, Kd2 {m['Kd2']:.2f}, "
        f"stalled {m['stalled']}, self-locking {m['self_locking']}\n"
        f"regimes: {' -> '.join(m['regimes'])};  efficiency forward {m['efficiency_forward']:.3f}, "
        f"backward {m['efficiency_backward']:.3f}"
        + (" (self-locking at rest)" if m["self_locking"] else "")
        + f", friction angle rho {m['rho_steady_deg']:.2f} deg at the steady speed",
        fontsize=9,
    )
    fig.tight_layout()
    fig.savefig(path, dpi=100, format="png")
    plt.close(fig)


def write_recording(result: Result, path) -> None:
    """recording.rrd: the same time series on the sim_time timeline (wormsim.recording layout)."""
    s = result.series
    save_series_recording(path, result.extra.get("name", "wedge"), s["t_s"], {k: v for k, v in s.items() if k != "t_s"})
