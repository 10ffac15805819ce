"""Stability edge of contact3d: the timestep doubled until a guard fires; failures classified."""

from __future__ import annotations

import time

import numpy as np

from wormsim.bench.cases import SCENARIOS, VARIANTS, relative_errors
from wormsim.contact3d.mjcf import prepare
from wormsim.contact3d.runner import simulate
from wormsim.contact3d.timestep import default_timestep
from wormsim.exceptions import (
    DivergedError,
    LockedError,
    OverspeedError,
    PenetrationError,
    RingingError,
    SimulationError,
    TeethJumpedError,
)
from wormsim.scenario import load_scenario

STABILITY_FACTORS = (1, 2, 4, 8, 16, 32)
# drift tolerances against the run at the default timestep (docs/contact3d.md's validation criteria: ratio within
# 0.1 %, torque balance F_t r2 within 2 %). The ratio is taken from the shaft angles over the steady window
# (ratio_angles): the summary's mean-speed ratio of a run shorter than a mesh period follows the light wheel's rattle
# (seat motor, 0.03 s: 53.03 at x1, 57.78 at x2, while the angles agree)
STABILITY_TOLERANCES = {"ratio_angles": 1e-3, "tangential_force_mean_n": 0.02}
# resolution per seed for the sweep: coarse where its pieces leave no interference (involute_41 needs fine,
# docs/contact3d.md "Validation")
STABILITY_RESOLUTION = {"seat_motor": "coarse", "screw_jack": "coarse", "involute_41": "fine"}
STABILITY_DURATION_S = 0.05
# each guard's exception (wormsim.exceptions) -> the class name bench_meta.json holds
FAILURE_CLASSES: tuple[tuple[type[SimulationError], str], ...] = (
    (DivergedError, "diverged"),
    (TeethJumpedError, "teeth_jumped"),
    (PenetrationError, "penetration"),
    (LockedError, "locked"),
    (OverspeedError, "overspeed"),
    (RingingError, "ringing"),
)


def classify_failure(exc: BaseException) -> str:
    """Class of a guard's exception: diverged | teeth_jumped | penetration | locked | overspeed | ringing, else
    "other"."""
    for klass, name in FAILURE_CLASSES:
        if isinstance(exc, klass):
            return name
    return "other"


def angle_ratio(series: dict, window_s) -> float | None:
    """|theta1(t1) - theta1(t0)| / |theta2(t1) - theta2(t0)| over the steady window [t0, t1] (None without one)."""
    if not window_s:
        return None
    t = np.asarray(series["t_s"])
    i0, i1 = int(np.searchsorted(t, window_s[0])), min(int(np.searchsorted(t, window_s[1])), len(t) - 1)
    d2 = float(series["wheel_angle_rad"][i1] - series["wheel_angle_rad"][i0])
    if i1 <= i0 or d2 == 0:
        return None
    return abs(float(series["worm_angle_rad"][i1] - series["worm_angle_rad"][i0]) / d2)


def stability_edge(
    scenario_name: str,
    factors: tuple[float, ...] = STABILITY_FACTORS,
    duration_s: float = STABILITY_DURATION_S,
    overrides: tuple[str, ...] = (),
    resolution: str | None = None,
    tolerances: dict | None = None,
) -> dict:
    """Sweep the contact3d timestep upward from its default h0 (wormsim.contact3d.timestep.default_timestep: 0.4 x
    the explicit limit of the contact spring-damper, rounded down to 1-2-5) by `factors` on a short run of
    scenarios/<scenario_name>.yaml, until a run fails.

    Each run is classified: "ok"; "inaccurate" when the ratio (from the shaft angles over the steady window,
    angle_ratio) or the mean tangential force drifts from the run at the first factor by more than `tolerances`
    (relative; also when a checked value is missing); or the guard
    that stopped it (classify_failure: diverged, teeth_jumped, penetration, locked). The sweep stops at the first
    run that is not "ok". Returns a JSON-ready record: the default and limit timesteps, every run (factor,
    timestep_s, dt / limit, status, failure, message, ratio, tangential_force_mean_n, drift), the last stable
    timestep (the largest "ok" one, None if the first fails) and how the next one failed.
    Wall times are measured, never judged."""
    tol = dict(STABILITY_TOLERANCES if tolerances is None else tolerances)
    base = tuple(overrides) + (f"simulation.duration_s={duration_s}",)
    if resolution is not None:
        base += (f"simulation.resolution={resolution}",)
    sc0 = load_scenario(SCENARIOS / f"{scenario_name}.yaml", list(base))
    law = prepare(sc0).law
    h0 = default_timestep(law)
    limit = law.stable_limit_s
    runs: list[dict] = []
    ref: dict | None = None
    for f in factors:
        dt = float(f"{h0 * f:.4g}")
        sc = load_scenario(SCENARIOS / f"{scenario_name}.yaml", list(base) + [f"simulation.timestep_s={dt}"])
        run = {
            "factor": f,
            "timestep_s": dt,
            "timestep_over_limit": dt / limit,
            "status": "ok",
            "failure": None,
            "message": "",
            "ratio": None,
            "ratio_angles": None,
            "tangential_force_mean_n": None,
            "drift": {},
            "wall_s": None,
        }
        t0 = time.perf_counter()
        try:
            res = simulate(sc)
        except SimulationError as exc:
            run.update(status="failed", failure=classify_failure(exc), message=str(exc))
        else:
            s = dict(res.summary, ratio_angles=angle_ratio(res.series, res.summary.get("steady_window_s")))
            run["ratio"], run["tangential_force_mean_n"] = s.get("ratio"), s.get("tangential_force_mean_n")
            run["ratio_angles"] = s["ratio_angles"]
            if ref is None:
                ref = s
            run["drift"] = relative_errors(s, ref, tuple(tol))
            bad = [k for k, lim in tol.items() if run["drift"][k] is None or run["drift"][k] > lim]
            if bad:
                run.update(
                    status="inaccurate",
                    failure="inaccurate",
                    message="drift beyond tolerance (or no steady value) in " + ", ".join(bad),
                )
        run["wall_s"] = time.perf_counter() - t0
        runs.append(run)
        if run["status"] != "ok":
            break
    ok = [r for r in runs if r["status"] == "ok"]
    last = ok[-1] if ok else None
    first_bad = next((r for r in runs if r["status"] != "ok"), None)
    return {
        "scenario": scenario_name,
        "overrides": list(base),
        "duration_s": duration_s,
        "default_timestep_s": h0,
        "stable_limit_s": limit,
        "tolerances": tol,
        "last_stable_timestep_s": last["timestep_s"] if last else None,
        "last_stable_factor": last["factor"] if last else None,
        "failure": first_bad["failure"] if first_bad else None,
        "failed_timestep_s": first_bad["timestep_s"] if first_bad else None,
        "failure_message": first_bad["message"] if first_bad else "",
        "runs": runs,
    }


def stability_map(
    quick: bool, scenarios: tuple[str, ...] | None = None, geometries: tuple[str, ...] = ("pieces",)
) -> dict:
    """stability_edge for each seed's bench variant (VARIANTS) at STABILITY_RESOLUTION and each contact.geometry;
    quick: the seat motor only (about half a minute). Keyed by scenario (and "/flanks" for the flank contacts),
    written to bench_meta.json under "stability"."""
    names = ("seat_motor",) if quick else tuple(VARIANTS)
    if scenarios is not None:
        names = tuple(n for n in names if n in scenarios)
    dur = STABILITY_DURATION_S  # 1.5 mesh periods of the seat motor at 1800 rpm; shorter runs: no steady window
    return {
        n + ("" if geo == "pieces" else f"/{geo}"): stability_edge(
            n, duration_s=dur, overrides=VARIANTS[n] + (f"contact.geometry={geo}",), resolution=STABILITY_RESOLUTION[n]
        )
        for n in names
        for geo in geometries
    }
