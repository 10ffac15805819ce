"""Warnings a finished run carries in summary.json (`warnings`, a list of one-line texts) and prints on stderr: results
that are computed correctly but that a user should not read as the gear's steady behaviour.

- F_t fluctuation: the steady window's tangential-force peak-to-peak above FT_P2P_SHARE of its mean. A meshing
  fluctuation of a working gear is a few percent of the mean (seeds 001-003 with exact flanks: under 2 %,
  docs/validation.md); half the mean or more means impacts (rattle, convex-piece facets, teeth leaving contact)
  or a steady window that still holds the start-up.
- Contacts outside the flanks (contact3d): a share above OFF_FLANK_FORCE_SHARE of the steady window's contact force
  from contact points outside the wheel tooth's flank region: past the tip (throat torus, meshgen.wheel.tip_rho),
  below the root (root torus, meshgen.wheel.root_rho) or past the face, by more than OFF_FLANK_TOL_MODULES axial
  modules. Such contacts are tip, edge or root contacts, which the meshing forces' theory does not describe.
- Meshing line: a steady window of fewer than wormsim.results.metrics.MIN_MESH_CYCLES mesh periods (its spectrum's lines
  overlap, and the p2p and the harmonics describe a few periods only), no peak near z1 n1 / 60, or a line more
  than MESH_FREQUENCY_REL from it; not for a pair that does not turn or that is held (`locked`: it creeps, and a
  longer run would not resolve a meshing line).
- Plausibility: the largest contact pressure above the wheel material's pitting strength sigma_HlimT (the rating's
  table, wormsim.rating.materials; the material of rating.wheel_material, else the rating's default for
  materials.wheel), at wedge and torsional (no contact pressure) the rating's mean contact stress sigma_Hm;
  a runaway (the driven shaft above RUNAWAY_FACTOR x its speed command, or, for a torque drive,
  RUNAWAY_FACTOR x its speed at half the run at the end: still accelerating); power
  flowing from the wheel into a worm-driven pair (an overhauling load); a pair that does not turn (no ratio and no
  efficiency); a speed drive at its peak torque outside a held back-drive (the shaft follows the limit, not its
  command); a held back-drive whose worm creeps above HOLD_CREEP_SHARE of its free speed (the mesh slipped under the
  stalled drive's torque); a mean more than THEORY_REL from its hand formula (ratio, F_t2, F_r2, efficiency:
  theory_warnings). The root stress above its limit is the rating's warning (wormsim.rating.fe_root).
"""

from __future__ import annotations

import numpy as np

from wormsim.results.result import Result

FT_P2P_SHARE = 0.5
OFF_FLANK_FORCE_SHARE = 0.01
OFF_FLANK_TOL_MODULES = 0.1
MESH_FREQUENCY_REL = 0.005  # the meshing line's tolerance against z1 n1 / 60 (seed 001's criterion)
RUNAWAY_FACTOR = 1.5  # a driven shaft this many times its command (or free speed) runs away
RUNAWAY_MIN_RPM = 1.0  # below this a speed command counts as standstill: vibration there is no runaway


def _num(summary: dict, key: str) -> float | None:
    v = summary.get(key)
    return float(v) if isinstance(v, int | float) and not isinstance(v, bool) and np.isfinite(v) else None


def ft_p2p_warning(summary: dict) -> str | None:
    """F_t p2p over the steady window above FT_P2P_SHARE of |F_t mean|."""
    mean, p2p = summary.get("tangential_force_mean_n"), summary.get("tangential_force_p2p_n")
    if not isinstance(mean, int | float) or not isinstance(p2p, int | float):
        return None
    if not (np.isfinite(mean) and np.isfinite(p2p)) or mean == 0 or p2p <= FT_P2P_SHARE * abs(mean):
        return None
    return (
        f"tangential force p2p {p2p:.4g} N is {100 * p2p / abs(mean):.0f} % of its mean {abs(mean):.4g} N "
        f"(above {100 * FT_P2P_SHARE:.0f} %): impacts, rattle or the start-up in the steady window; "
        "try a finer resolution, contact.geometry flanks or a longer run"
    )


def off_flank_share(points_tooth0: np.ndarray, forces: np.ndarray, geo) -> float:
    """Share of the contact force (|F| summed) from points outside the wheel tooth's flank region.

    points_tooth0: (..., 3) contact points in the frame of wheel tooth 0 (x, y in the wheel plane, z along the
    wheel axis), NaN where no contact; forces: (..., 3) the matching contact forces; geo: GearGeometry (SI)."""
    from meshgen import wheel

    p = np.asarray(points_tooth0, float).reshape(-1, 3)
    f = np.linalg.norm(np.asarray(forces, float).reshape(-1, 3), axis=1)
    ok = np.isfinite(p[:, 0]) & np.isfinite(f)
    p, f = p[ok], f[ok]
    total = float(f.sum())
    if total <= 0:
        return 0.0
    tol = OFF_FLANK_TOL_MODULES * geo.m_x
    z, r = p[:, 2], np.hypot(p[:, 0], p[:, 1])
    out = (
        (np.abs(z) > geo.face_width / 2 + tol) | (r > wheel.tip_rho(geo, z) + tol) | (r < wheel.root_rho(geo, z) - tol)
    )
    return float(f[out].sum()) / total


def off_flank_warning(result: Result) -> str | None:
    """contact3d: the off-flank share of the steady window's contact force above OFF_FLANK_FORCE_SHARE."""
    P, F, built = (result.extra.get(k) for k in ("points_tooth0", "forces_world", "built"))
    if P is None or F is None or built is None or "steady_window_s" not in result.summary:
        return None
    t = result.series["t_s"]
    w0, w1 = result.summary["steady_window_s"]
    sl = (t >= w0) & (t <= w1)
    if not sl.any():
        return None
    share = off_flank_share(P[sl], F[sl], built.geometry)
    if share <= OFF_FLANK_FORCE_SHARE:
        return None
    return (
        f"{100 * share:.1f} % of the contact force acts outside the wheel flanks (past the tip, below the root or "
        "past the face): tip or edge contact; check gear.backlash_mm, gear.face_width_mm and errors:"
    )


def mesh_window_warnings(summary: dict) -> list[str]:
    """The meshing line's window too short, no line near z1 n1 / 60, or a line more than MESH_FREQUENCY_REL off it."""
    from wormsim.results.metrics import MIN_MESH_CYCLES

    cycles, f, f0 = (
        _num(summary, k) for k in ("steady_window_mesh_cycles", "mesh_frequency_hz", "mesh_frequency_theory_hz")
    )
    if cycles is None or f0 is None or f0 <= 0 or summary.get("power_flow") == "none":  # standstill: its own warning
        return []
    if summary.get("locked") is True:  # a held self-locking pair creeps: no meshing to resolve, whatever the window
        return []
    df = _num(summary, "mesh_frequency_resolution_hz")
    if cycles < MIN_MESH_CYCLES:
        w0, w1 = summary.get("steady_window_s") or (float("nan"), float("nan"))
        more = (MIN_MESH_CYCLES - cycles) / f0
        return [
            f"the steady window ({w0:.4g}-{w1:.4g} s) holds {cycles:.2g} mesh periods, fewer than "
            f"{MIN_MESH_CYCLES:g}: mesh_frequency_hz is uncertain by its resolution {df or float('nan'):.3g} Hz, "
            "and the fluctuations (p2p, harmonics) cover only those periods; run at least "
            f"{more:.2g} s longer (simulation.duration_s)"
        ]
    if f is None or summary.get("mesh_frequency_line_found") is False:
        return [
            f"no meshing line near z1 n1 / 60 = {f0:.4g} Hz in the steady window's spectrum: mesh_frequency_hz "
            "is the largest value at its search band's edge; the meshing signal holds no meshing fluctuation"
        ]
    if abs(f / f0 - 1) > MESH_FREQUENCY_REL:
        return [
            f"the meshing line {f:.4g} Hz is {100 * (f / f0 - 1):+.2g} % from z1 n1 / 60 = {f0:.4g} Hz (more than "
            f"{100 * MESH_FREQUENCY_REL:g} %): another vibration lies next to it; run longer for a finer resolution "
            f"({df or float('nan'):.3g} Hz now)"
        ]
    return []


def wheel_pressure_limit(scenario) -> tuple[float, str] | None:
    """(sigma_HlimT [MPa], material name) of the wheel material's row in the rating's table: rating.wheel_material,
    else the rating's default for materials.wheel (wormsim.rating.rate.wheel_material); None without a row."""
    from wormsim.rating.rate import rating_inputs, wheel_material

    mat = wheel_material(scenario, rating_inputs(scenario), [])
    if mat.sigma_hlim_t_mpa is None:
        return None
    return mat.sigma_hlim_t_mpa, mat.name


def pressure_warning(summary: dict, scenario) -> str | None:
    """contact_pressure_max_mpa above the wheel material's pitting strength sigma_HlimT."""
    p = _num(summary, "contact_pressure_max_mpa")
    if p is None or scenario is None:
        return None
    lim = wheel_pressure_limit(scenario)
    if lim is None or p <= lim[0]:
        return None
    given = (
        "rating.wheel_material"
        if scenario.rating is not None and scenario.rating.wheel_material
        else (
            f"the rating's default for materials.wheel E = {scenario.materials.wheel.youngs_modulus_gpa:g} GPa; "
            "set rating.wheel_material for another"
        )
    )
    return (
        f"largest contact pressure {p:.4g} MPa is above the wheel material's pitting strength sigma_HlimT "
        f"{lim[0]:.4g} MPa ({lim[1]}, {given}): the flanks pit or yield at this load, which the elastic contact does "
        "not model; lower the load or enlarge the gear"
    )


def iso_pressure_warning(summary: dict, scenario) -> str | None:
    """Wedge and torsional (no contact pressure of their own): the rating's mean contact stress sigma_Hm (ISO/TS 14521
    method B at the scenario's load and speed, wormsim.rating.rate) above the wheel material's pitting strength
    sigma_HlimT, the limit pressure_warning takes for contact3d's p_H max. A gear the rating cannot rate gives none."""
    if scenario is None or scenario.model == "contact3d" or scenario.gear is None:
        return None
    from wormsim.exceptions import ScenarioError, SimulationError
    from wormsim.rating.rate import rate

    lim = wheel_pressure_limit(scenario)
    try:
        sigma = _num(rate(scenario), "contact_stress_mean_iso_mpa")
    except (ScenarioError, SimulationError, ValueError, ArithmeticError):  # outside the rating's range: no check
        return None
    if lim is None or sigma is None or sigma <= lim[0]:
        return None
    return (
        f"the mean contact stress sigma_Hm {sigma:.4g} MPa at this load (ISO/TS 14521 method B, wormsim rate) is "
        f"above the wheel material's pitting strength sigma_HlimT {lim[0]:.4g} MPa ({lim[1]}): the flanks pit or "
        f"yield at this load, which model {scenario.model} does not see (contact3d reports the contact pressure); "
        "lower the load or enlarge the gear"
    )


def runaway_warning(result: Result, scenario) -> str | None:
    """The driven shaft above RUNAWAY_FACTOR x its speed command over the steady window, or, for a torque drive (no
    command, and a constant torque has no free speed), at the end RUNAWAY_FACTOR x its speed at half the run."""
    if scenario is None or scenario.drive is None or "t_s" not in result.series:
        return None
    drv = scenario.drive
    on = drv.on
    S = result.series
    key = f"{on}_speed_rpm"
    if key not in S or "steady_window_s" not in result.summary:
        return None
    t, w = S["t_s"], np.abs(S[key])
    w0, w1 = result.summary["steady_window_s"]
    sl = (t >= w0) & (t <= w1)
    if sl.sum() < 4:
        return None
    if drv.speed_rpm is not None:
        top = float(np.max(w[sl]))
        if top > RUNAWAY_FACTOR * max(abs(drv.speed_rpm), RUNAWAY_MIN_RPM):
            return (
                f"runaway: the {on} turns at up to {top:.4g} rpm, above {RUNAWAY_FACTOR:g} x its command "
                f"{abs(drv.speed_rpm):.4g} rpm: the load drives the pair past the speed control"
            )
        return None
    # a torque drive: no command, and no free speed either (a constant torque has none): a runaway still
    # accelerates at the end, its speed there RUNAWAY_FACTOR x its speed at half the run or more
    w_mid = float(np.interp(0.5 * float(t[-1]), t, w))
    w_end = float(w[-1])
    if w_end > RUNAWAY_MIN_RPM and w_end > RUNAWAY_FACTOR * w_mid:
        return (
            f"runaway: the torque-driven {on} still accelerates, {w_mid:.4g} rpm at t = {0.5 * float(t[-1]):.3g} s "
            f"and {w_end:.4g} rpm at the end: the drive torque {drv.torque_nm:g} N m exceeds what the load takes, so "
            "the means (efficiency, forces) include the acceleration; use a speed drive (drive.speed_rpm) or balance "
            "the torques"
        )
    return None


def power_flow_warning(summary: dict, scenario) -> str | None:
    """Power flowing against the drive (an overhauling load: from the wheel into a worm-driven pair, or from the
    worm into a wheel-driven one), or a pair that does not turn."""
    flow = summary.get("power_flow")
    if flow == "none":
        from wormsim.results.metrics import STANDSTILL_RPM

        n1, n2 = (_num(summary, k) or 0.0 for k in ("worm_speed_mean_rpm", "wheel_speed_mean_rpm"))
        ratio = _num(summary, "ratio_theory") or 1.0
        if n1 >= STANDSTILL_RPM and n2 >= STANDSTILL_RPM / ratio:  # both turn (vibrate), neither puts power in
            return (
                f"no power flows through the mesh over the steady window (worm {n1:.3g} rpm, wheel {n2:.3g} rpm, "
                "neither shaft puts power in on average): ratio and efficiency are not defined and reported as null"
            )
        return (
            f"the pair does not turn over the steady window (worm {n1:.3g} rpm, wheel {n2:.3g} rpm): ratio and "
            "efficiency are not defined and reported as null"
        )
    drive_on = scenario.drive.on if scenario is not None and scenario.drive is not None else None
    eff, eff_theory = (
        v if (v := _num(summary, k)) is not None else float("nan") for k in ("efficiency", "efficiency_theory")
    )
    if flow == "wheel to worm" and drive_on == "worm":
        return (
            f"power flows from the wheel to the worm: the load on the wheel overhauls the drive, efficiency "
            f"{eff:.3g} is worm power out / wheel power in (theory "
            f"tan(gamma - rho') / tan(gamma) = {eff_theory:.3g})"
        )
    if flow == "worm to wheel" and drive_on == "wheel":
        return (
            f"power flows from the worm to the wheel: the load on the worm overhauls the wheel's drive, efficiency "
            f"{eff:.3g} is wheel power out / worm power in (theory "
            f"tan(gamma) / tan(gamma + rho') = {eff_theory:.3g})"
        )
    return None


def drive_peak_warning(result: Result, scenario) -> str | None:
    """A speed drive at its peak torque (summary `drive_peak_torque_nm`, wormsim.physics.gear_theory
    .servo_peak_torque_nm) in a run that did not end held: its |torque| at or above SERVO_KNEE of the peak, where the
    limit bends the servo's law (torsional) or binds (contact3d), so the shaft follows the limit, not its command.
    A held back-drive (`locked`) stalls at the peak by design and is not warned about."""
    from wormsim.physics import gear_theory as gt

    peak = _num(result.summary, "drive_peak_torque_nm")
    if peak is None or scenario is None or scenario.drive is None or result.summary.get("locked") is True:
        return None
    on = scenario.drive.on
    S = result.series
    if f"{on}_torque_nm" not in S or "t_s" not in S or not len(S["t_s"]):
        return None
    t, T = np.asarray(S["t_s"]), np.abs(np.asarray(S[f"{on}_torque_nm"]))
    hit = T >= gt.SERVO_KNEE * peak
    if not hit.any():
        return None
    t_hit = t[hit]
    return (
        f"the speed drive reached its peak torque: {float(T.max()):.4g} N m on the {on} against its peak "
        f"{peak:.4g} N m ({gt.SERVO_PEAK_FACTOR:g} x the rated torque: the expected torque at the full load plus the "
        f"ramp's acceleration torque) between t = {float(t_hit[0]):.3g} s and {float(t_hit[-1]):.3g} s; there the "
        f"{on} follows the limit, slower than commanded: lengthen drive.ramp_s, or the load or the pair asks more "
        "than the drive's rating"
    )


HOLD_CREEP_SHARE = 1e-3  # a held pair creeps at most this share of its free speed (docs/outputs.md)


def creep_warning(summary: dict, scenario) -> str | None:
    """A held back-drive (`locked`) whose worm creeps faster than HOLD_CREEP_SHARE of its free speed, the wheel's
    speed command times the ratio: the mesh did not hold the torque it was given (a stalled drive's peak torque), it
    slipped through; `locked` then says that the drive stalled, not that the pair held."""
    creep = _num(summary, "creep_speed_rpm")
    ratio = _num(summary, "ratio_theory")
    if summary.get("locked") is not True or creep is None or ratio is None or scenario is None:
        return None
    drv = scenario.drive
    if drv is None or drv.on != "wheel" or drv.speed_rpm is None:
        return None
    free = abs(drv.speed_rpm) * ratio
    if creep <= HOLD_CREEP_SHARE * free:
        return None
    held = _num(summary, "holding_torque_nm")
    return (
        f"the back-driven pair stalled the wheel's drive but did not hold: the worm crept at {creep:.3g} rpm, "
        f"{100 * creep / free:.2g} % of the wheel command times the ratio ({free:.4g} rpm), above "
        f"{100 * HOLD_CREEP_SHARE:g} %, under the holding torque {held or float('nan'):.4g} N m (the drive's peak, "
        "drive_peak_torque_nm); the contact slips at that torque: a lower load on the worm or a torque drive "
        "(drive.torque_nm) gives a holding run at a chosen torque"
    )


THEORY_REL = 0.10  # a mean this far from its hand formula contradicts it (the seeds: within 1 %, docs/validation.md)
# (mean key, formula key, what it is, the formula's name); efficiency: the formula at the contacts' radius where the
# run has it (contact3d) and the power flows from the worm
THEORY_PAIRS = (
    ("ratio", "ratio_theory", "ratio", "z2 / z1"),
    ("tangential_force_mean_n", "tangential_force_theory_n", "tangential force F_t2", "T_load / r2"),
    ("radial_force_mean_n", "radial_force_theory_n", "radial force F_r2", "DIN 3975-2's pitch-point formula"),
    ("efficiency", "efficiency_theory", "efficiency", "tan(gamma) / tan(gamma + rho')"),
)


def theory_warnings(summary: dict) -> list[str]:
    """Each steady-window mean of THEORY_PAIRS more than THEORY_REL from its hand formula. The formulas hold at the
    pitch point (DIN 3975-2); a pair whose contacts carry the load elsewhere (a steep lead angle, an undercut wheel,
    flank errors), or a run that is not steady, departs from them: the run is not wrong for that, but its number
    and the formula's must not be read as one."""
    out = []
    for key, ref, what, formula in THEORY_PAIRS:
        if key == "efficiency" and summary.get("power_flow") == "worm to wheel":
            ref = "efficiency_theory_at_contact_radius" if _num(summary, ref + "_at_contact_radius") else ref
        m, t = _num(summary, key), _num(summary, ref)
        if m is None or t is None or t == 0 or abs(m / t - 1) <= THEORY_REL:
            continue
        out.append(
            f"{what} {m:.4g} is {m / t:.3g} x the hand formula's {t:.4g} ({formula}, `{ref}`; more than "
            f"{100 * THEORY_REL:g} % apart): the contacts carry the load away from where the formula assumes, or the "
            "window is not steady; read the contact pattern and the resultant keys, and lengthen the run"
        )
    return out


def plausibility_warnings(result: Result, scenario) -> list[str]:
    """The results that contradict a physical limit or the run's premise (see the module docstring)."""
    s = result.summary
    return [
        w
        for w in (
            pressure_warning(s, scenario),
            iso_pressure_warning(s, scenario),
            runaway_warning(result, scenario),
            power_flow_warning(s, scenario),
            drive_peak_warning(result, scenario),
            creep_warning(s, scenario),
            *theory_warnings(s),
        )
        if w
    ]


def run_warnings(result: Result, scenario=None) -> list[str]:
    """Every warning of a finished run, in a fixed order; scenario (a Scenario) enables the checks against its
    inputs (the speed command, the wheel material)."""
    return [
        w
        for w in (ft_p2p_warning(result.summary), off_flank_warning(result), *mesh_window_warnings(result.summary))
        if w
    ] + plausibility_warnings(result, scenario)
