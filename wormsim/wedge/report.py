"""wedge report.png and recording.rrd."""

from __future__ import annotations

from wormsim.results.recording import save_series_recording
from wormsim.results.report_header import (
    draw_header,
    gear_line,
    header_rows,
    results_line,
    self_locking_text,
    shafts_line,
    speed_ylim,
    warning_text,
)
from wormsim.results.result import Result
from wormsim.wedge.dynamics import INVERSE, LOCKED, TRACTIVE, UNLOADED

# ----------------------------------------------------------------------------- report, recording


def write_report(result: Result, path) -> None:
    """report.png: a header (the wedge data, forces and dynamic factors, efficiencies, self-locking, regimes); S1(t)
    with F1, S2(t) with F2, speed (axis scaled to the steady window), regime timeline."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    s, m = result.series, result.summary
    t_ms = s["t_s"] * 1e3
    name = result.extra.get("name", "wedge")
    p = result.extra.get("params")
    geo = result.extra.get("geometry")  # where the wedge comes from a gear: block

    def f(key: str, spec: str) -> str:  # a summary number, "-" where this run does not write the key
        v = m.get(key)
        return format(v, spec) if isinstance(v, int | float) and not isinstance(v, bool) else "-"

    fr = (f"friction {p.friction:g}" if p.friction is not None else f"friction group {p.group}") if p else ""
    lines = [
        gear_line(geo) if geo is not None else "",
        (
            f"wedge: gamma {f('lead_angle_deg', '.3g')} deg, m1 {p.m1_kg:.4g} kg (worm side), m2 {p.m2_kg:.4g} kg "
            f"(driven), {fr}:\nfriction angle rho {f('rho_steady_deg', '.3g')} deg at the steady speed, "
            f"{f('rho_static_deg', '.3g')} deg at rest"
            if p
            else ""
        ),
        shafts_line(m),
        results_line(m, geo) if "ratio" in m else "",
        f"S1 steady {f('S1_steady_n', '.4g')} N (peak {f('S1_peak_n', '.4g')} N, Kd1 {f('Kd1', '.2f')}),  S2 steady "
        f"{f('S2_steady_n', '.4g')} N (peak {f('S2_peak_n', '.4g')} N, Kd2 {f('Kd2', '.2f')}),  steady speed "
        f"{f('speed_steady_m_s', '.4g')} m/s",
        f"efficiency {f('efficiency_forward', '.3f')} (worm driving), back-driving {f('efficiency_backward', '.3f')},  "
        + self_locking_text(m, geo)
        + (" (rho at rest >= gamma)" if m.get("self_locking") is True else "")
        + f",  stalled {'yes' if m.get('stalled') else 'no'}",
        f"regimes: {' -> '.join(m.get('regimes', []))}",
    ]
    warn = warning_text(m)
    hh = header_rows(lines, warn)
    fig = plt.figure(figsize=(10, 9.5 + hh))
    gs = fig.add_gridspec(5, 1, height_ratios=[hh, 3, 3, 2.2, 1.1])
    ax = [fig.add_subplot(gs[1])]
    ax += [fig.add_subplot(gs[i], sharex=ax[0]) for i in (2, 3, 4)]
    draw_header(fig.add_subplot(gs[0]), lines, f"{name} (wedge, monitor {m.get('monitor', '-')})", warn=warn)
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
    w = m.get("steady_window_s")
    if w:
        ax[2].set_ylim(*speed_ylim(s["t_s"], [s["v1_m_s"], s["vs_m_s"]], w))
    ax[2].set_ylabel("speed [m/s]")
    ax[3].step(t_ms, s["regime_code"], where="post")
    ax[3].set_yticks([0, 1, 2, 3], [LOCKED, TRACTIVE, INVERSE, UNLOADED])
    ax[3].set_ylim(-0.5, 3.5)
    ax[3].set_xlabel("time [ms]")
    for a in ax[:3]:
        a.legend(loc="best", fontsize=8)
        a.tick_params(labelbottom=False)
    for a in ax:
        a.grid(True, alpha=0.3)
    fig.tight_layout()
    fig.savefig(path, dpi=100, format="png")
    plt.close(fig)


def write_recording(result: Result, path) -> None:
    """recording.rrd: the same time series on the sim_time timeline (wormsim.results.recording layout)."""
    s = result.series
    save_series_recording(path, result.extra.get("name", "wedge"), s["t_s"], {k: v for k, v in s.items() if k != "t_s"})
