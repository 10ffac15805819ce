"""Ringing above the contact's stable limit: a run that oscillates to its end with no other guard firing.

Above ContactLaw.stable_limit_s the explicit contact spring-damper can ring at the step frequency without running
away: the state stays finite, the transmission error stays within half a pitch, the penetration within 0.4 m_x, and
the run looks complete. What rings is the mesh itself: the tooth force drops towards zero on one step and
overshoots on the next, so its largest per-step value leaves the mean far behind. A steady mesh carrying its load
cannot do that; its force moves with the meshing (a few to 20 % of the mean on the gears of the step sweep).

Check, after the run and before anything is written: when the timestep is above the stable limit, the largest
per-step |F_t| in the steady window (summary tangential_force_max_n) over the window's mean |F_t|
(tangential_force_mean_n) must stay within RING_PEAK_OVER_MEAN. Below the limit the explicit scheme is stable and
a peak is physics (an impact, a rattle), so nothing is checked there. Exact flanks only (contact.geometry flanks):
the pieces' facet impacts reach 3.6 x the mean at the default step (screw jack, coarse), so the signature does not
tell their ringing from their facets. Measured margins: docs/contact3d.md, "Ringing above the stable limit".
"""

from __future__ import annotations

import numpy as np

# largest per-step |F_t| over its mean in the steady window, above the stable limit (docs/contact3d.md: stable runs
# up to 1.18, ringing runs from 1.74; the two that rang undetected 2.38 and 2.87)
RING_PEAK_OVER_MEAN = 1.5


def ringing(S: dict, summary: dict, dt: float, stable_limit_s: float) -> tuple[float, str] | None:
    """(time of the peak, what rang) when the run rang above the stable limit, else None."""
    if dt <= stable_limit_s:
        return None
    peak = summary.get("tangential_force_max_n")
    mean = summary.get("tangential_force_mean_n")
    if peak is None or mean is None or not np.isfinite(peak) or peak <= RING_PEAK_OVER_MEAN * abs(mean):
        return None
    t = S["t_s"]
    w0, w1 = summary["steady_window_s"]
    m = (t >= w0) & (t <= w1)
    ft = S["tangential_force_abs_max_n"]
    t_peak = float(t[m][int(np.argmax(ft[m]))]) if m.any() else float(t[-1])
    return t_peak, (
        f"the mesh rang: tangential force peak {peak:.4g} N is {peak / max(abs(mean), 1e-300):.3g} x its steady mean "
        f"{abs(mean):.4g} N, allowed up to {RING_PEAK_OVER_MEAN:g} x"
    )
