"""The header panel every report.png starts with: the gear, the shafts' torques and powers, and the answers a
drive engineer looks for first (ratio, tangential force, efficiency, self-locking).

Self-locking: the summary's `self_locking` key where the level writes it; otherwise from the friction the run used
(`friction_coefficient_mean`), rho' = atan(mu / cos alpha_n) against the lead angle gamma
(gear_theory.virtual_friction_angle_rad, DIN 3975-2). Input power: the shaft with the larger |T n| (the input of a
lossy pair carries more power than its output).
"""

from __future__ import annotations

import math

from wormsim.physics import gear_theory as gt
from wormsim.physics.units import RPM


def _num(summary: dict, key: str) -> float | None:
    v = summary.get(key)
    if isinstance(v, bool) or not isinstance(v, int | float) or not math.isfinite(v):
        return None
    return float(v)


def gear_line(geo) -> str:
    """d1, d2, a, gamma and the rest of the gear data (geo: meshgen.geometry.GearGeometry, SI)."""
    hand = "right" if geo.hand > 0 else "left"
    return (
        f"gear {geo.profile} {hand}, z1/z2 {geo.z1}/{geo.z2}, m_x {geo.m_x * 1e3:.3g} mm, "
        f"d1 {geo.d1 * 1e3:.4g} mm, d2 {geo.d2 * 1e3:.4g} mm, a {geo.a * 1e3:.4g} mm, "
        f"gamma {math.degrees(geo.gamma):.3g} deg, alpha_n {math.degrees(geo.alpha_n):.3g} deg, "
        f"b2 {geo.face_width * 1e3:.3g} mm"
        + (
            f", x2 {geo.x2:+.3g} (d_a2 {2 * geo.r_a2 * 1e3:.4g} mm, gamma_m {math.degrees(geo.gamma_m):.3g} deg)"
            if geo.x2
            else ""
        )
    )


def shafts_line(summary: dict) -> str:
    """Worm and wheel speed, torque and power over the steady window; which one is the input."""
    n1, n2 = _num(summary, "worm_speed_mean_rpm"), _num(summary, "wheel_speed_mean_rpm")
    t1, t2 = _num(summary, "worm_torque_mean_nm"), _num(summary, "wheel_torque_mean_nm")
    if None in (n1, n2, t1, t2):
        return ""
    p1, p2 = abs(t1 * n1 * RPM), abs(t2 * n2 * RPM)
    inp = "worm" if p1 >= p2 else "wheel"
    return (
        f"worm {n1:.4g} rpm, torque {t1:.4g} N m, {p1:.4g} W;  wheel {n2:.4g} rpm, torque {t2:.4g} N m, "
        f"{p2:.4g} W;  input power {max(p1, p2):.4g} W ({inp})"
    )


def self_locking_text(summary: dict, geo) -> str:
    """'self-locking: yes/no' with the reason (rho' against gamma)."""
    if isinstance(summary.get("self_locking"), bool):
        return f"self-locking: {'yes' if summary['self_locking'] else 'no'}"
    mu = _num(summary, "friction_coefficient_mean")
    if mu is None or geo is None:
        return ""
    rho = gt.virtual_friction_angle_rad(mu, geo.alpha_n)
    locks = rho >= geo.gamma_m
    rel = ">=" if locks else "<"
    return (
        f"self-locking: {'yes' if locks else 'no'} (rho' {math.degrees(rho):.3g} deg {rel} gamma "
        f"{math.degrees(geo.gamma_m):.3g} deg at mu {mu:.3g})"
    )


def results_line(summary: dict, geo) -> str:
    """Ratio, F_t, efficiency against their theory, and self-locking."""
    parts = []
    r, rt = _num(summary, "ratio"), _num(summary, "ratio_theory")
    if r is not None:
        parts.append(f"ratio {r:.5g}" + (f" (theory {rt:.5g})" if rt is not None else ""))
    ft, ftt = _num(summary, "tangential_force_mean_n"), _num(summary, "tangential_force_theory_n")
    if ft is not None:
        parts.append(f"F_t {ft:.5g} N" + (f" (T2 / r2 {ftt:.5g} N)" if ftt is not None else ""))
    e, et = _num(summary, "efficiency"), _num(summary, "efficiency_theory")
    if e is not None:
        parts.append(f"efficiency {e:.3f}" + (f" (theory {et:.3f})" if et is not None else ""))
    lock = self_locking_text(summary, geo)
    if lock:
        parts.append(lock)
    return ",  ".join(parts)


def warning_text(summary: dict, first: str = "") -> str:
    """The red line(s) of the header: `first` (a level's own caveat) and the run's `warnings`, each cut to one line."""
    ws = [first] if first else []
    ws += [f"warning: {w}" for w in summary.get("warnings") or []]
    return "\n".join(w if len(w) <= 170 else w[:167] + "..." for w in ws)


def header_rows(lines: list[str], warn: str = "") -> float:
    """Height of the header row in inches: the title, the non-empty lines and the warning lines."""
    n = 1.4 + sum(x.count("\n") + 1 for x in lines if x) + (warn.count("\n") + 1 if warn else 0)
    return 0.2 * n


def draw_header(ax, lines: list[str], title: str, warn: str = "") -> None:
    """Write the header text into `ax` (an axes without frame): the title bold at the top, the lines below it, `warn`
    in red below them. The texts stay out of the layout engine's bounding boxes (a long line must not shrink the
    plots); the figure gives the header row header_rows() inches."""
    ax.set_axis_off()
    head = ax.text(0.0, 1.0, title, fontsize=11, fontweight="bold", va="top", ha="left", transform=ax.transAxes)
    body = ax.annotate(
        "\n".join(x for x in lines if x),
        (0, 0),
        xycoords=head,
        xytext=(0, -3),
        textcoords="offset points",
        fontsize=9,
        va="top",
        ha="left",
        linespacing=1.5,
    )
    texts = [head, body]
    if warn:
        texts.append(
            ax.annotate(
                warn, (0, 0), xycoords=body, xytext=(0, -3), textcoords="offset points", fontsize=9, color="C3",
                va="top", ha="left", linespacing=1.5,
            )
        )  # fmt: skip
    for x in texts:
        x.set_in_layout(False)


def steady_ylim(t, ys, window, pad: float = 0.25) -> tuple[float, float]:
    """y limits that hold every y over the steady window (t in window), padded by `pad` of the span, with 0 in
    view when the data lie near it: start-up peaks outside the window are clipped (the report names them)."""
    import numpy as np

    sl = (t >= window[0]) & (t <= window[1])
    if not sl.any():
        sl = np.ones_like(t, dtype=bool)
    lo = min(float(np.nanmin(y[sl])) for y in ys)
    hi = max(float(np.nanmax(y[sl])) for y in ys)
    span = max(hi - lo, 1e-6 * max(abs(lo), abs(hi), 1.0))
    lo, hi = lo - pad * span, hi + pad * span
    if lo > 0 and lo < 0.5 * hi:
        lo = 0.0
    if hi < 0 and hi > 0.5 * lo:
        hi = 0.0
    return lo, hi


def speed_ylim(t, ys, window, margin: float = 0.15) -> tuple[float, float]:
    """y limits for speeds: from 0 to the steady window's extreme plus `margin` of it (a start-up overshoot or the
    raw rattle outside that is clipped), so a steady 100 rpm reads as 100 rpm on a 0-115 rpm axis."""
    import numpy as np

    sl = (t >= window[0]) & (t <= window[1])
    if not sl.any():
        sl = np.ones_like(t, dtype=bool)
    lo = min(0.0, min(float(np.nanmin(y[sl])) for y in ys))
    hi = max(0.0, max(float(np.nanmax(y[sl])) for y in ys))
    span = max(hi - lo, 1e-9)
    return lo - margin * span * (lo < 0), hi + margin * span * (hi > 0)
