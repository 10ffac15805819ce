"""contact3d summary metrics: the common drive summary (wormsim.results.metrics) plus the meshing line of the tangential
force near z1 n1 / 60, contact statistics, the radial and axial forces as DIN 3975 defines them and as resultants,
the efficiency theory at the contacts' radius and the start-up peak."""

from __future__ import annotations

import numpy as np

from wormsim.physics import gear_theory as gt
from wormsim.results.metrics import (
    dominant_frequency,
    drive_summary,
    mean_speeds_rpm,
    mesh_line,
    mesh_line_keys,
    power_source,
    window_after,
)


def contact3d_summary(S: dict, bm) -> dict:
    """drive_summary plus the meshing frequency from the tangential force and contact statistics; the steady window
    after the ramps of the run's plan (bm.plan.duty)."""
    geo, duty = bm.geometry, bm.plan.duty
    t = S["t_s"]
    i0, i1, _ = window_after(S, duty.drive.on, duty.ramps_end_s, geo)
    sl = slice(i0, i1)
    n1, n2 = mean_speeds_rpm(S, i0, i1)
    f_theory = geo.z1 * n1 / 60.0
    f_full, _, _, _ = dominant_frequency(t[sl], S["tangential_force_n"][sl])
    # shaft powers: the interval means of T w over every step (the runner's worm_power_w, wheel_power_w)
    drive = drive_summary(S, bm.plan.gear, i0, i1, n1, n2, shaft_powers_w=(S["worm_power_w"], S["wheel_power_w"]))
    return {
        **drive,
        # the meshing line near z1 n1 / 60 (wormsim.results.metrics.mesh_line): the pieces' facets, the contact mode's
        # ringing
        # and the meshing harmonics lie outside its band
        **mesh_line_keys(t, S, sl, f_theory, "tangential_force_n"),
        "force_peak_full_band_hz": f_full,
        "mesh_frequency_radial_hz": mesh_line(t[sl], S["radial_force_n"][sl], f_theory, harmonics=False)["f_hz"],
        "contacts_mean": float(np.mean(S["contacts"][sl])),
        "teeth_in_contact_mean": float(np.mean(S["teeth_in_contact"][sl])),
        "max_penetration_um": float(np.max(S["max_penetration_m"][sl]) * 1e6),
        **din_forces(S, power_source(drive["power_flow"], duty.drive.on), geo, sl, drive["worm_torque_mean_nm"]),
        **contact_radius_check(S, sl),
        **startup_peak(S, i0, i1),
    }


def contact_radius_check(S: dict, sl: slice) -> dict:
    """worm_contact_radius_mean_m: force-weighted worm radius of the contacts over the window, and
    efficiency_theory_at_contact_radius: the wedge efficiency evaluated at each contact's own radius (local lead
    angle tan(gamma_r) = tan(gamma) r1 / r; gear_theory.efficiency_at_radius), where efficiency_theory
    takes the pitch radius r1 (DIN 3975). Measured (seat motor, coarse, 1800 rpm): contacts at 4.40 mm against
    r1 4.19 mm, 0.609 against 0.620 at r1, measured 0.605."""
    if "worm_contact_radius_m" not in S:
        return {}
    r, e = S["worm_contact_radius_m"][sl], S["efficiency_theory_at_contact_radius"][sl]
    if not np.isfinite(r).any():
        return {"worm_contact_radius_mean_m": float("nan"), "efficiency_theory_at_contact_radius": float("nan")}
    return {
        "worm_contact_radius_mean_m": float(np.nanmean(r)),
        "efficiency_theory_at_contact_radius": float(np.nanmean(e)),
    }


def din_forces(S: dict, source: str, geo, sl: slice, worm_torque_mean_nm: float) -> dict:
    """The headline radial and axial forces as DIN 3975-2 defines them, with the resultant's components as their own
    keys (docs/outputs.md, "Force keys").

    DIN 3975's F_r2 = F_t2 tan(alpha_n) cos(rho') / cos(gamma + s rho') (s = +1 power from the worm, -1 from the wheel:
    back-driving or an overhauling load, `source`; rho' = atan(mu / cos alpha_n)) and F_a2 = F_t1 = 2 T1 / d1 assume
    one contact at the pitch point on the line of centres.
    The 3D contacts sit around the worm at angles phi (about its axis, from the line of centres), which turn their
    radial components partly into the wheel's axial direction, and at worm radii r_c above r1, where the lead angle is
    smaller: the resultant's radial component is below DIN's F_r2 by about <cos phi> (measured: screw jack, medium:
    128.9 against 147.2 N, force-weighted |phi| 28 deg) and its axial component below T1 / r1 (seeds: -5 to -8 %).
    radial_force_mean_n turns each contact's force back onto the line of centres (wormsim.contact3d.runner; screw
    jack 147.8 against 147.2 N) and axial_force_mean_n is the worm torque over r1, F_t1 = T1 / r1: the forces a
    bearing calculation after DIN 3975 takes. The resultant's components are radial_force_resultant_mean_n and
    axial_force_resultant_mean_n: the forces on the wheel's bearings."""
    if not len(S["tangential_force_n"][sl]):
        return {}
    mu = float(np.mean(S["friction_coefficient"][sl]))
    rho = gt.virtual_friction_angle_rad(mu, geo.alpha_n)
    s = -1.0 if source == "wheel" else 1.0  # the shaft that puts power in (wormsim.results.metrics.power_source)
    ft = abs(float(np.mean(S["tangential_force_n"][sl])))
    out = {
        "radial_force_resultant_mean_n": abs(float(np.mean(S["radial_force_n"][sl]))),
        "axial_force_resultant_mean_n": abs(float(np.mean(S["axial_force_n"][sl]))),
        "axial_force_mean_n": worm_torque_mean_nm / geo.r_m1,
        "radial_force_theory_n": gt.radial_force_n(ft, geo.alpha_n, geo.gamma_m, s * rho),
    }
    if "radial_force_line_of_centres_n" in S:
        out["radial_force_mean_n"] = abs(float(np.mean(S["radial_force_line_of_centres_n"][sl])))
    return out


def startup_peak(S: dict, i0: int, i1: int) -> dict:
    """Start-up impact against the steady mesh: startup_tangential_force_peak_n = max |F_t| before the steady window
    starts (t < startup_time_s = its start), tangential_force_max_n = max |F_t| inside it, and the largest
    penetration before the window, startup_penetration_max_um. |F_t| is the largest of every step's
    (tangential_force_abs_max_n, wormsim.contact3d.runner), not the interval mean, so record_every does not average the
    impact away; the penetration is sampled at the end of each interval."""
    ft = S["tangential_force_abs_max_n"] if "tangential_force_abs_max_n" in S else np.abs(S["tangential_force_n"])
    pen = S["max_penetration_m"]
    return {
        "startup_time_s": float(S["t_s"][i0]),
        "startup_tangential_force_peak_n": float(ft[:i0].max()) if i0 > 0 else 0.0,
        "startup_penetration_max_um": float(pen[:i0].max() * 1e6) if i0 > 0 else 0.0,
        "tangential_force_max_n": float(ft[i0:i1].max()),
    }
