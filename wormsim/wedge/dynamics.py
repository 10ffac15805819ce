"""Two-sided wedge model (TSWM) of a worm drive: seed 000 with a third regime, standstill (locked).

Source: seed 000, the two-sided wedge model's document (README, "Seeds"); docs/wedge.md derives every line.

Bodies and forces (seed 000, fig. 1): body 1 (the worm, reduced to its pitch radius, mass m1 with
the motor rotor) moves along x1 under the motor force F1; body 2 (the wheel, mass m2) moves along
x2 under the load F2 (negative resists). One wedge face of lead angle gamma couples them:

    x2 = x1 tan(gamma),   Vs = x1' / cos(gamma)                                  (seed 000)
    S1 = F1 - m1 x1'',    S2 = F2 - m2 x2''    (internal reduced forces; S2 = S1 / psi while sliding)

Contact on the face: normal force N (N > 0 on face a-a, N < 0 on face b-b: zero backlash) and
Coulomb friction tan(rho) |N| against the sliding. With s = sign(x1') and k = sign(N) s:

    S1 = N (sin g + k tan(rho) cos g),   S2 = -N (cos g - k tan(rho) sin g)
    S1 / S2 = psi_k = -tan(g + k rho):   k = +1 tractive psi1 = -tan(g + rho),
                                         k = -1 inverse   psi2 = -tan(g - rho)      (seed 000)
    x1'' = (F1 - F2 psi_k) / (m1 - m2 psi_k tan g)                                  (seed 000)
    N = (m2 tan g F1 - m1 F2) / (m1 B_k + m2 tan g A_k),  A_k = sin g + k mu cos g, B_k = cos g - k mu sin g

The numerator of N is m1 m2 tan g times the seed's switching function phi = F1/m1 - F2/(m2 tan g),
so phi picks the face, and the face together with the direction of sliding picks psi. The seed's
monitor (psi1 if phi > 0) is right while x1' > 0 and wrong at standstill and in reverse.

Standstill (x1' = 0): the pair sticks (regime "locked", x1'' = 0) while the friction needed,

    N0 = F1 sin g - F2 cos g,   T0 = -F1 cos g - F2 sin g,   |T0| <= tan(rho(0)) |N0|,

is available, i.e. while F1/F2 lies between psi1 and psi2 at rho(0). Otherwise it slides in the
direction s = -sign(T0). rho(Vs) is rho_rad of wormsim.physics.friction (seed 000's fit; its value at
Vs = 0 is the static friction angle).

Motor (seed 000, Kloss): F1 = 2 Fmax / (V + 1/V),  V = (V0 - x1') / (V0 - Vmax).

No load (F2 = 0 and constant): the motor runs up to its synchronous speed V0, where F1 = 0 and N = 0 (neither face
carries a force; regime "unloaded"). Both sliding regimes approach this point (tractive from below, inverse from
above) and meet on phi = 0, where both give the same acceleration F1/m1 = 0: an equilibrium ON the switching
surface. The exact solution only tends to it, but the integrator steps across phi = 0 by rounding and would switch
regimes ever faster (stick-slip-like chatter, found with `--set wedge.load.force_n=0`). A phi event with the load
constant up to the next breakpoint and |F2| below EQUILIBRIUM_FORCE_TOL x peak force is therefore this equilibrium:
the speed is held there (x1'' = 0, S1 = S2 = 0) until the load changes.

Integration: scipy solve_ivp (DOP853) per segment of constant regime; terminal events at x1' = 0
and at phi = 0; a locked segment ends where the stick margin crosses zero (found by bisection, the
load being the only thing that changes while locked); load breakpoints (start_s, start_s + ramp_s)
end segments too.

Dynamic factors (seed 000): Kd1 = |S1 peak| / Ft1, Kd2 = |S2 peak| / Ft2 with Ft1 the motor's
rated force (wedge.motor.nominal_force_n) and Ft2 = Ft1 / tan(g + rho(Vs_n)) the static wedge
relation at the rated speed (wedge.motor.nominal_speed_m_s).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.integrate import solve_ivp, trapezoid

from wormsim.exceptions import SimulationError
from wormsim.physics import gear_theory as gt
from wormsim.physics.friction import friction_coefficient, rho_rad
from wormsim.physics.units import DEG, step
from wormsim.results.result import Result
from wormsim.results.summary_keys import level_summary

TRACTIVE, INVERSE, LOCKED, UNLOADED = "tractive", "inverse", "locked", "unloaded"
REGIME_CODE = {LOCKED: 0, TRACTIVE: 1, INVERSE: 2, UNLOADED: 3}
EQUILIBRIUM_FORCE_TOL = 1e-9  # of wedge.motor.peak_force_n: a load this small counts as none (unloaded equilibrium)
GRID_POINTS = 4001  # uniform output samples over the run (plus solver steps and events)
MAX_SEGMENTS = 20000  # a guard against endless stick-slip chatter
STEADY_FRACTION = 0.1  # steady values: time average over the last 10 % of the run


@dataclass(frozen=True)
class WedgeParams:
    """Seed 000's parameters in SI."""

    gamma_rad: float
    m1_kg: float
    m2_kg: float
    group: str | None
    friction: float | None
    peak_force_n: float
    sync_speed_m_s: float
    peak_speed_m_s: float
    nominal_force_n: float
    nominal_speed_m_s: float
    load_initial_n: float
    load_final_n: float
    load_start_s: float
    load_ramp_s: float
    monitor: str
    v0_m_s: float
    duration_s: float
    rtol: float
    # derived from gear: (wormsim.wedge.derive): the contact's friction law mu(Vs) and rho' = atan(mu / cos alpha_n),
    # the friction angle of the gear levels; None: seed 000's rho(Vs) of `group` / `friction` (rho = atan(mu))
    contact: object | None = None
    cos_alpha_n: float = 1.0
    method: str = "DOP853"  # solve_ivp method; the derived motor curve is stiff (Radau)


def params_from_scenario(scenario) -> WedgeParams:
    w = scenario.wedge
    return WedgeParams(
        gamma_rad=w.lead_angle_deg * DEG,
        m1_kg=w.driving_mass_kg,
        m2_kg=w.driven_mass_kg,
        group=w.friction_group if w.friction is None else None,
        friction=w.friction,
        peak_force_n=w.motor.peak_force_n,
        sync_speed_m_s=w.motor.synchronous_speed_m_s,
        peak_speed_m_s=w.motor.peak_force_speed_m_s,
        nominal_force_n=w.motor.nominal_force_n,
        nominal_speed_m_s=w.motor.nominal_speed_m_s,
        load_initial_n=w.load.initial_force_n,
        load_final_n=w.load.force_n,
        load_start_s=w.load.start_s,
        load_ramp_s=w.load.ramp_s,
        monitor=w.monitor,
        v0_m_s=w.initial_speed_m_s,
        duration_s=scenario.simulation.duration_s,
        rtol=w.rtol,
    )


# ----------------------------------------------------------------------------- closed forms


def motor_force_n(v1_m_s, p: WedgeParams):
    """Kloss curve (seed 000): F1 = 2 Fmax / (V + 1/V) = 2 Fmax V / (1 + V^2), V = (V0 - v)/(V0 - Vmax).

    Written as 2 Fmax V / (1 + V^2) it has no pole at the synchronous speed (F1 = 0 there) and
    turns negative above it (generator).
    """
    V = (p.sync_speed_m_s - np.asarray(v1_m_s, dtype=float)) / (p.sync_speed_m_s - p.peak_speed_m_s)
    out = 2.0 * p.peak_force_n * V / (1.0 + V * V)
    return float(out) if np.ndim(out) == 0 else out


def load_force_n(t_s, p: WedgeParams):
    """F2(t): STEP (ADAMS cubic) from initial_force_n at start_s to force_n at start_s + ramp_s."""
    return step(t_s, p.load_start_s, p.load_initial_n, p.load_start_s + p.load_ramp_s, p.load_final_n)


def rho_of_speed(v1_m_s, p: WedgeParams):
    """rho(Vs), Vs = |x1'| / cos(gamma) (seed 000); derived from gear: rho' = atan(mu(Vs) / cos alpha_n)."""
    if p.contact is not None:
        mu = friction_coefficient(p.contact, np.abs(v1_m_s) / math.cos(p.gamma_rad))
        return gt.virtual_friction_angle_rad(mu, math.acos(p.cos_alpha_n))
    return rho_rad(np.abs(v1_m_s) / math.cos(p.gamma_rad), p.group, p.friction)


def rho_static(p: WedgeParams) -> float:
    return rho_of_speed(0.0, p)


def psi(k: int, gamma: float, rho):
    """Force transfer function (seed 000): psi1 = -tan(g + rho) (k = +1), psi2 = -tan(g - rho) (k = -1)."""
    return -np.tan(gamma + k * rho)


def accel_sliding(F1, F2, k: int, rho, p: WedgeParams):
    """x1'' = (F1 - F2 psi_k) / (m1 - m2 psi_k tan g) (seed 000)."""
    ps = psi(k, p.gamma_rad, rho)
    return (F1 - F2 * ps) / (p.m1_kg - p.m2_kg * ps * math.tan(p.gamma_rad))


def phi_numerator(F1, F2, p: WedgeParams):
    """G = m2 tan g F1 - m1 F2 = m1 m2 tan g phi, phi the seed's switching function; sign(N) = sign(G)."""
    return p.m2_kg * math.tan(p.gamma_rad) * F1 - p.m1_kg * F2


def normal_denominator(k: int, rho, p: WedgeParams):
    """D_k = m1 B_k + m2 tan g A_k; N = G / D_k. D_k <= 0 is Painleve's paradox (no unique solution)."""
    g, mu = p.gamma_rad, np.tan(rho)
    A = math.sin(g) + k * mu * math.cos(g)
    B = math.cos(g) - k * mu * math.sin(g)
    return p.m1_kg * B + p.m2_kg * math.tan(g) * A


def stick_forces(F1, F2, gamma: float):
    """Normal and tangential face force at standstill (x1'' = 0): N0 = F1 sin g - F2 cos g,
    T0 = -F1 cos g - F2 sin g (T0 along the direction body 2 slides relative to body 1 for x1' > 0)."""
    return F1 * math.sin(gamma) - F2 * math.cos(gamma), -F1 * math.cos(gamma) - F2 * math.sin(gamma)


def stick_margin(F1, F2, gamma: float, rho0: float):
    """tan(rho0) |N0| - |T0|: >= 0 the pair holds at standstill (F1/F2 between psi1 and psi2 at rho0)."""
    N0, T0 = stick_forces(F1, F2, gamma)
    return math.tan(rho0) * np.abs(N0) - np.abs(T0)


def efficiencies(gamma: float, rho: float) -> dict:
    """Seed 000: eta = tan g / tan(g + rho) (forward); mu = tan(g - rho) / tan g (backward, 0 when
    rho >= g); mu_SL = tan(rho - g) / tan g when rho > g (motor power still needed per unit of
    assisting load power, inverse regime of a self-locking pair), else 0."""
    return {
        "efficiency_forward": gt.efficiency_forward(gamma, rho),
        "efficiency_backward": gt.efficiency_backward(gamma, rho),
        "efficiency_self_locking": gt.efficiency_self_locking(gamma, rho),
    }


def _summary_efficiencies(gamma: float, rho_sliding: float, rho_static: float) -> dict:
    """summary.json efficiencies (docs/outputs.md). efficiency_backward is 0 when the pair self-locks at
    standstill (rho(0) > gamma: it cannot be back-driven from rest); the back-driving efficiency of a
    pair that is already sliding at the steady speed is efficiency_backward_sliding."""
    e = efficiencies(gamma, rho_sliding)
    e["efficiency_backward_sliding"] = e["efficiency_backward"]
    if rho_static > gamma:
        e["efficiency_backward"] = 0.0
    return e


def rated_forces_n(p: WedgeParams) -> tuple[float, float]:
    """Ft1 = the motor's rated force; Ft2 = Ft1 / tan(g + rho(Vs_n)) (static wedge relation, rated speed)."""
    rho_n = rho_of_speed(p.nominal_speed_m_s, p)
    return p.nominal_force_n, p.nominal_force_n / math.tan(p.gamma_rad + rho_n)


# ----------------------------------------------------------------------------- integration


def _sign(x: float) -> int:
    return 1 if x > 0 else -1


def _breakpoints(p: WedgeParams) -> list[float]:
    pts = {p.load_start_s, p.load_start_s + p.load_ramp_s}
    return sorted(t for t in pts if 0.0 < t < p.duration_s)


def _choose_k(s: int, sigma: int, v1: float, p: WedgeParams) -> int:
    k = sigma * s
    if normal_denominator(k, rho_of_speed(v1, p), p) <= 0:
        raise SimulationError(
            "the sliding equations have no unique solution (Painleve's paradox: m2 tan(gamma) tan(rho - gamma) "
            ">= m1); raise wedge.driving_mass_kg or lower the friction"
        )
    return k


def _locked_until(t0: float, t1: float, F1_0: float, p: WedgeParams, rho0: float) -> float | None:
    """First time in (t0, t1] where the stick margin turns negative, or None. F2 is monotone between
    breakpoints and the stick set is an interval in F2, so checking t1 and bisecting suffices."""

    def margin(t):
        return stick_margin(F1_0, load_force_n(t, p), p.gamma_rad, rho0)

    if margin(t1) >= 0:
        return None
    lo, hi = t0, t1
    for _ in range(200):
        if hi - lo <= 1e-13 * max(1.0, p.duration_s):
            break
        mid = 0.5 * (lo + hi)
        if margin(mid) >= 0:
            lo = mid
        else:
            hi = mid
    return hi


def _load_constant(t0: float, t1: float, p: WedgeParams) -> bool:
    """F2 is constant on [t0, t1] (t1 a breakpoint or the end: outside the open ramp interval)."""
    return p.load_initial_n == p.load_final_n or t1 <= p.load_start_s or t0 >= p.load_start_s + p.load_ramp_s


def _unloaded_equilibrium(t: float, t_end: float, p: WedgeParams) -> bool:
    """At a phi event: the point is the no-load equilibrium (module docstring) rather than a crossing."""
    return _load_constant(t, t_end, p) and abs(load_force_n(t, p)) <= EQUILIBRIUM_FORCE_TOL * p.peak_force_n


def _segment_times(grid: np.ndarray, t0: float, t1: float, extra=()) -> np.ndarray:
    inner = grid[(grid > t0) & (grid < t1)]
    return np.unique(np.concatenate([[t0], inner, np.asarray(extra, float), [t1]]))


def simulate(scenario, progress=None) -> Result:
    """Integrate the wedge model of `scenario`'s wedge: block (seed 000's valve case) and return series and
    summary; a scenario without one goes to wormsim.wedge.derive (wormsim.wedge.level picks)."""
    p = params_from_scenario(scenario)
    res = simulate_params(p, progress=progress, name=scenario.name)
    source = "wedge: block (seed 000: rho = atan(mu), forces reduced to the pitch radii)"
    res.summary = level_summary("wedge", res.summary, {"wedge_source": source})
    return res


def simulate_params(p: WedgeParams, progress=None, name: str = "wedge") -> Result:
    T, g = p.duration_s, p.gamma_rad
    rho0 = rho_static(p)
    grid = np.linspace(0.0, T, GRID_POINTS)
    stops = _breakpoints(p) + [T]
    atol = np.array([1e-3, 1e-2]) * p.rtol
    seed_monitor = p.monitor == "seed"

    segs: list[dict] = []  # {"regime", "t", "x", "v", "a", "k"}
    t, x, v = 0.0, 0.0, float(p.v0_m_s)
    sigma_hint: int | None = None
    steps = 0
    while t < T * (1 - 1e-12):
        if len(segs) > MAX_SEGMENTS:
            raise SimulationError(
                f"more than {MAX_SEGMENTS} regime changes by t = {t:.6g} s (stick-slip chatter); "
                "lower wedge.rtol or check the friction law"
            )
        t_end = next(b for b in stops if b > t * (1 + 1e-12) + 1e-15)
        F1, F2 = motor_force_n(v, p), load_force_n(t, p)
        if segs and segs[-1]["regime"] == UNLOADED and _unloaded_equilibrium(t, t_end, p):
            segs.append(_unloaded_segment(grid, t, t_end, x, v))  # still no load past a breakpoint: stay on it
            t, x = t_end, float(x + v * (t_end - t))
            continue
        if v == 0.0 and not seed_monitor:
            if stick_margin(F1, F2, g, rho0) >= 0:
                t_break = _locked_until(t, t_end, F1, p, rho0)
                t_stop = t_end if t_break is None else t_break
                ts = _segment_times(grid, t, t_stop)
                zero = np.zeros_like(ts)
                segs.append({"regime": LOCKED, "t": ts, "x": np.full_like(ts, x), "v": zero, "a": zero.copy(), "k": 0})
                t = t_stop
                sigma_hint = None
                if progress is not None:
                    progress.update(t)
                continue
            s = -_sign(stick_forces(F1, F2, g)[1])
        else:
            s = _sign(v) if v != 0.0 else 1
        G = phi_numerator(F1, F2, p)
        sigma = sigma_hint if sigma_hint is not None else (_sign(G) if G != 0 else 1)
        sigma_hint = None
        k = sigma if seed_monitor else _choose_k(s, sigma, v, p)
        if v == 0.0 and not seed_monitor and accel_sliding(F1, F2, k, rho0, p) * s <= 0:
            raise SimulationError(
                f"breakaway at t = {t:.6g} s found no consistent sliding direction "
                "(marginal stick); this is a bug in the wedge model, please report it"
            )

        def rhs(tt, y, k=k):
            vv = y[1]
            return [vv, accel_sliding(motor_force_n(vv, p), load_force_n(tt, p), k, rho_of_speed(vv, p), p)]

        def ev_phi(tt, y):
            return phi_numerator(motor_force_n(y[1], p), load_force_n(tt, p), p)

        ev_phi.terminal, ev_phi.direction = True, -sigma
        events = [ev_phi]
        if not seed_monitor:

            def ev_stop(tt, y):
                return y[1]

            ev_stop.terminal, ev_stop.direction = True, -s
            events.append(ev_stop)

        sol = solve_ivp(
            rhs, (t, t_end), [x, v], method=p.method, rtol=p.rtol, atol=atol, events=events, dense_output=True
        )
        if sol.status < 0:
            raise SimulationError(f"the integrator failed at t = {t:.6g} s: {sol.message}")
        steps += max(len(sol.t) - 1, 0)
        t_stop = float(sol.t[-1])
        ts = _segment_times(grid, t, t_stop, sol.t)
        ys = sol.sol(ts)
        xs, vs = ys[0], ys[1]
        hit_phi = len(sol.t_events[0]) > 0
        hit_stop = (not seed_monitor) and len(sol.t_events[1]) > 0
        if hit_stop:
            vs[-1] = 0.0
        acc = accel_sliding(motor_force_n(vs, p), load_force_n(ts, p), k, rho_of_speed(vs, p), p)
        segs.append({"regime": TRACTIVE if k == 1 else INVERSE, "t": ts, "x": xs, "v": vs, "a": acc, "k": k})
        if not np.all(np.isfinite(xs)) or np.max(np.abs(vs)) > 1e3:
            raise SimulationError(f"the wedge model diverged by t = {t_stop:.6g} s (|x1'| > 1000 m/s)")
        t, x, v = t_stop, float(xs[-1]), float(vs[-1])
        if hit_stop:
            v = 0.0
        elif hit_phi and _unloaded_equilibrium(t, t_end, p):
            segs.append(_unloaded_segment(grid, t, t_end, x, v))
            t, x = t_end, float(x + v * (t_end - t))
        elif hit_phi:
            sigma_hint = -sigma
        if progress is not None:
            progress.update(t)

    return _assemble(segs, p, steps, name)


def _unloaded_segment(grid: np.ndarray, t: float, t_end: float, x: float, v: float) -> dict:
    """The segment from t to t_end on the unloaded equilibrium: constant speed v from x."""
    ts = _segment_times(grid, t, t_end)
    return {
        "regime": UNLOADED,
        "t": ts,
        "x": x + v * (ts - t),
        "v": np.full_like(ts, v),
        "a": np.zeros_like(ts),
        "k": 0,
    }


# ----------------------------------------------------------------------------- results


def _time_mean(t: np.ndarray, y: np.ndarray, t0: float) -> float:
    m = t >= t0
    if m.sum() < 2:
        return float(y[-1])
    return float(trapezoid(y[m], t[m]) / (t[m][-1] - t[m][0]))


def _assemble(segs: list[dict], p: WedgeParams, steps: int, name: str) -> Result:
    g, tan_g = p.gamma_rad, math.tan(p.gamma_rad)
    t = np.concatenate([s["t"] for s in segs])
    x1 = np.concatenate([s["x"] for s in segs])
    v1 = np.concatenate([s["v"] for s in segs])
    a1 = np.concatenate([s["a"] for s in segs])
    code = np.concatenate([np.full(len(s["t"]), REGIME_CODE[s["regime"]], dtype=np.int8) for s in segs])
    F1 = motor_force_n(v1, p)
    F2 = load_force_n(t, p)
    rho = np.where(code == 0, rho_static(p), rho_of_speed(v1, p))
    S1 = F1 - p.m1_kg * a1
    S2 = F2 - p.m2_kg * tan_g * a1
    series = {
        "t_s": t,
        "x1_m": x1,
        "v1_m_s": v1,
        "a1_m_s2": a1,
        "x2_m": x1 * tan_g,
        "v2_m_s": v1 * tan_g,
        "vs_m_s": v1 / math.cos(g),
        "F1_n": F1,
        "F2_n": F2,
        "S1_n": S1,
        "S2_n": S2,
        "rho_deg": rho / DEG,
        "regime_code": code,
    }

    timeline: list[list] = []
    for s in segs:
        if timeline and timeline[-1][0] == s["regime"]:
            timeline[-1][2] = float(s["t"][-1])
        else:
            timeline.append([s["regime"], float(s["t"][0]), float(s["t"][-1])])
    regimes = [r for r, t0, t1 in timeline]

    t_ss = p.duration_s * (1 - STEADY_FRACTION)
    v_ss = _time_mean(t, v1, t_ss)
    rho_ss = float(rho_of_speed(v_ss, p))
    i1, i2 = int(np.argmax(np.abs(S1))), int(np.argmax(np.abs(S2)))
    Ft1, Ft2 = rated_forces_n(p)
    rho0 = rho_static(p)
    summary = level_summary(
        "wedge",
        {
            "speed_steady_m_s": v_ss,
            "S1_peak_n": float(S1[i1]),
            "S2_peak_n": float(S2[i2]),
            "S1_peak_time_s": float(t[i1]),
            "S2_peak_time_s": float(t[i2]),
            "S1_steady_n": _time_mean(t, S1, t_ss),
            "S2_steady_n": _time_mean(t, S2, t_ss),
            "Kd1": abs(float(S1[i1])) / Ft1,
            "Kd2": abs(float(S2[i2])) / Ft2,
            "Ft1_n": Ft1,
            "Ft2_n": Ft2,
            **_summary_efficiencies(g, rho_ss, rho0),
            "rho_steady_deg": rho_ss / DEG,
            "rho_static_deg": rho0 / DEG,
            **gt.backdrive_keys(g, rho0, rho_ss),
            "stalled": bool(np.max(np.abs(x1)) == 0.0),
            "locked_at_end": bool(code[-1] == 0),
            "x1_end_m": float(x1[-1]),
            "min_speed_m_s": float(np.min(v1)),
            "max_speed_m_s": float(np.max(v1)),
            "regimes": regimes,
            "regime_timeline": [{"regime": r, "start_s": t0, "end_s": t1} for r, t0, t1 in timeline],
            "monitor": p.monitor,
            "steady_window_s": [t_ss, p.duration_s],
        },
    )
    return Result(
        model="wedge",
        summary=summary,
        series=series,
        steps=steps,
        sim_time_s=float(t[-1]),
        extra={"params": p, "name": name},
    )
