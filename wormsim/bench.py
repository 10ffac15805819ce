"""`wormsim bench`: speed against accuracy of the fidelity levels (INTERFACE.md, bench.json).

For each seed scenario, each fidelity level runs across its resolutions and timesteps. Per run:

    wall_s            median wall time of `repeats` runs in this process, after a short warm-up run
                      that builds the geometry and k(theta) caches
    realtime_factor   sim_s / wall_s
    error[key]        |value - reference| / |reference| for key in ERROR_KEYS, against the converged
                      reference: the finest contact3d run of that scenario. The reference itself is checked
                      against a finer run (`reference_check` in bench_meta.json).

Outputs, written atomically: bench.json (list of records), bench_meta.json (machine, reference
check, notes, and "stability": the last stable contact3d timestep per seed and how the next one failed,
stability_edge), bench.png (error against wall time per simulated second, log axes, one curve per
level, Pareto front marked).
"""
from __future__ import annotations

import importlib.util
import os
import platform
import statistics
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from wormsim.output import write_json_atomic
from wormsim.scenario import ScenarioError, load_scenario

ROOT = Path(__file__).resolve().parents[1]
SCENARIOS = ROOT / "scenarios"
ERROR_KEYS = ("ratio", "tangential_force_mean_n", "tangential_force_p2p_n", "mesh_frequency_hz", "efficiency")


@dataclass(frozen=True)
class BenchCase:
    scenario: str                 # stem of scenarios/<stem>.yaml
    model: str                    # fidelity level
    resolution: dict              # free-form description of the level's resolution
    timestep_s: float | None
    overrides: tuple[str, ...] = field(default_factory=tuple)
    reference: bool = False       # the converged reference of its scenario
    finer: bool = False           # the finer run that checks the reference


def _level_available(model: str) -> bool:
    from wormsim.run import MODEL_MODULES

    return importlib.util.find_spec(MODEL_MODULES[model]) is not None


# Bench variants of the seed scenarios: every level runs the same variant, so errors compare one to one.
# The seat motor runs its worm at 1800 rpm (seed 001's 36 rpm needs 20 s for 12 mesh periods: about an
# hour at contact3d fidelity on this machine); ramps are shortened; each run holds >= 5 mesh periods.
VARIANTS = {
    "seat_motor": ("drive.speed_rpm=1800", "drive.ramp_s=0.02", "load.ramp_s=0.02"),
    "screw_jack": ("drive.ramp_s=0.02", "load.ramp_s=0.02"),
    "involute_41": ("drive.ramp_s=0.02", "load.ramp_s=0.02"),
}
DURATION_S = {"seat_motor": 0.25, "screw_jack": 0.3, "involute_41": 0.3}
QUICK_DURATION_S = 0.15


def contact3d_default_timestep(name: str, overrides: tuple[str, ...] = ()) -> float:
    """The timestep contact3d chooses for this scenario (wormsim.model.default_timestep, set on the built model)."""
    from wormsim.model import build_model

    sc = load_scenario(SCENARIOS / f"{name}.yaml", list(overrides))
    return float(build_model(sc).model.opt.timestep)


def bench_cases(quick: bool, models: tuple[str, ...] | None = None,
                scenarios: tuple[str, ...] | None = None) -> list[BenchCase]:
    """The grid. contact3d: resolution levels x timesteps of 2, 1 and 1/2 times its default (the default
    is 0.4 x the explicit stability limit, so 2x probes the edge); the reference is the finest level at
    the default step, checked against half that step. torsional: k(theta) samples per mesh cycle.
    quick: the seat motor only, 0.15 s, coarse/medium (a few minutes; CI runs the torsional part only).
    models: only these levels. scenarios: only these seeds (names of VARIANTS)."""
    names = ("seat_motor",) if quick else tuple(VARIANTS)
    if scenarios is not None:
        unknown = sorted(set(scenarios) - set(VARIANTS))
        if unknown:
            raise ScenarioError(f"bench --scenario: {', '.join(unknown)} is not a seed scenario; "
                                f"allowed: {', '.join(VARIANTS)}")
        names = tuple(n for n in VARIANTS if n in scenarios)
    levels = ("coarse", "medium") if quick else ("coarse", "medium", "fine")
    out: list[BenchCase] = []
    for name in names:
        dur = QUICK_DURATION_S if quick else DURATION_S[name]
        common = VARIANTS[name] + (f"simulation.duration_s={dur}",)
        if _level_available("contact3d") and (models is None or "contact3d" in models):
            h = contact3d_default_timestep(name, common)
            factors = (2.0, 1.0) if quick else (2.0, 1.0, 0.5)
            for lvl in levels:
                for f in factors:
                    dt = float(f"{h * f:.4g}")
                    out.append(BenchCase(name, "contact3d", {"level": lvl}, dt,
                                         common + (f"simulation.resolution={lvl}", f"simulation.timestep_s={dt}"),
                                         reference=(lvl == levels[-1] and f == 1.0)))
            dt = float(f"{h / 2:.4g}")
            same = next((i for i, c in enumerate(out) if c.scenario == name and c.model == "contact3d"
                         and c.resolution == {"level": levels[-1]} and c.timestep_s == dt), None)
            if same is not None:     # the grid already runs the finest level at h/2: that run is the check
                out[same] = BenchCase(**{**out[same].__dict__, "finer": True})
            else:
                out.append(BenchCase(name, "contact3d", {"level": levels[-1]}, dt,
                                     common + (f"simulation.resolution={levels[-1]}", f"simulation.timestep_s={dt}"),
                                     finer=True))
        if _level_available("torsional"):
            # resolution = k(theta) samples per mesh cycle; the default timestep is one sample's worth of worm
            # rotation at full speed (wormsim.torsional.default_timestep), so this sweeps both
            for n in ((16, 64) if quick else (16, 32, 64, 128, 256)):
                out.append(BenchCase(name, "torsional", {"level": "mesh-stiffness table", "mesh_stiffness_samples": n},
                                     None, common + ("model=torsional", f"simulation.mesh_stiffness_samples={n}")))
    if models is not None:
        out = [c for c in out if c.model in models]
    return out


def relative_errors(summary: dict, reference: dict, keys: tuple[str, ...] = ERROR_KEYS) -> dict:
    """|x - x_ref| / |x_ref| for each of `keys` both summaries hold (None where undefined)."""
    err = {}
    for k in keys:
        x, r = summary.get(k), reference.get(k)
        if x is None or r is None or not np.isfinite(x) or not np.isfinite(r) or r == 0:
            err[k] = None
        else:
            err[k] = abs(x - r) / abs(r)
    return err


def pareto_front(cost: np.ndarray, error: np.ndarray) -> np.ndarray:
    """Mask of points not dominated by another (lower-or-equal cost AND error, one strictly lower)."""
    cost, error = np.asarray(cost, float), np.asarray(error, float)
    keep = np.ones(len(cost), bool)
    for i in range(len(cost)):
        dominated = (cost <= cost[i]) & (error <= error[i]) & ((cost < cost[i]) | (error < error[i]))
        keep[i] = not dominated.any()
    return keep


def machine_info() -> dict:
    """Platform, CPU count and the 1-minute load average (wall times are only comparable at the same load)."""
    return {"platform": platform.platform(), "python": platform.python_version(),
            "processor": platform.processor() or platform.machine(), "cpu_count": os.cpu_count(),
            "load_average_1min": os.getloadavg()[0] if hasattr(os, "getloadavg") else None}


def _run_case(case: BenchCase, repeats: int) -> tuple[dict, float, float]:
    from wormsim.run import simulate

    sc = load_scenario(SCENARIOS / f"{case.scenario}.yaml", list(case.overrides))
    # warm-up: a run of a few steps builds the geometry / k(theta) caches, so the timed runs measure
    # simulation, not one-off generation (which `wormsim mesh` reports on its own)
    warm = sc.model_copy(deep=True)
    warm.simulation.duration_s = 20 * (sc.simulation.timestep_s or 1e-4)
    try:
        simulate(warm)
    except Exception:  # noqa: BLE001  a too-short run may fail its own checks; the timed runs report real failures
        pass
    walls, res = [], None
    for _ in range(repeats):
        t0 = time.perf_counter()
        res = simulate(sc)
        walls.append(time.perf_counter() - t0)
    return res.summary, statistics.median(walls), res.sim_time_s


def run_bench(quick: bool, out_dir: str | Path, repeats: int | None = None,
              models: tuple[str, ...] | None = None, scenarios: tuple[str, ...] | None = None) -> list[dict]:
    from wormsim.errors import SimulationError

    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    if repeats is not None and repeats < 1:
        raise ScenarioError(f"bench --repeats: {repeats} is not allowed; allowed: an integer >= 1")
    repeats = repeats or (1 if quick else 3)
    records, summaries, notes = [], {}, []
    machine_start = machine_info()
    for case in bench_cases(quick, models, scenarios):
        try:
            summary, wall, sim_s = _run_case(case, repeats)
        except SimulationError as exc:
            notes.append(f"{case.scenario} {case.model} {case.resolution} dt={case.timestep_s}: failed: {exc}")
            records.append({"scenario": case.scenario, "model": case.model, "resolution": case.resolution,
                            "timestep_s": case.timestep_s, "wall_s": None, "sim_s": None, "realtime_factor": None,
                            "status": "failed", "message": str(exc), "error": {}})
            continue
        rec = {"scenario": case.scenario, "model": case.model, "resolution": case.resolution,
               "timestep_s": summary.get("timestep_s", case.timestep_s), "wall_s": wall, "sim_s": sim_s,
               "realtime_factor": sim_s / wall if wall > 0 else None,
               "wall_s_per_sim_s": wall / sim_s if sim_s else None, "status": "ok",
               "reference": case.reference, "finer": case.finer, "error": {}}
        summaries[id(rec)] = summary
        records.append(rec)
    meta = {"machine": machine_start, "load_average_1min_end": machine_info()["load_average_1min"],
            "quick": quick, "repeats": repeats, "scenarios": sorted({r["scenario"] for r in records}),
            "reference_check": {}, "notes": notes}
    for scen in {r["scenario"] for r in records}:
        ref = next((r for r in records if r["scenario"] == scen and r.get("reference") and r["status"] == "ok"), None)
        if ref is None:
            notes.append(f"{scen}: no converged reference run; errors left empty")
            continue
        ref_sum = summaries[id(ref)]
        for r in records:
            if r["scenario"] == scen and r["status"] == "ok":
                r["error"] = relative_errors(summaries[id(r)], ref_sum)
        finer = next((r for r in records if r["scenario"] == scen and r.get("finer") and r["status"] == "ok"), None)
        if finer is not None:
            meta["reference_check"][scen] = finer["error"]
    if _level_available("contact3d") and (models is None or "contact3d" in models):
        # the timestep sweep of each seed until a guard fires (stability_edge); quick: the seat motor only
        meta["stability"] = stability_map(quick, scenarios)
    write_json_atomic(out / "bench.json", records)
    write_json_atomic(out / "bench_meta.json", meta)
    plot_bench(records, out / "bench.png")
    return records


def plot_bench(records: list[dict], path: Path, key: str = "tangential_force_mean_n") -> None:
    """Error of `key` (and the worst of ERROR_KEYS) against wall time per simulated second, log-log."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    ok = [r for r in records if r["status"] == "ok" and r.get("wall_s_per_sim_s") and not r.get("finer")]
    fig, axes = plt.subplots(1, 2, figsize=(12, 4.8), constrained_layout=True)
    for ax, mode in zip(axes, (key, "worst")):
        pts = []
        for r in ok:
            errs = [v for v in r["error"].values() if v is not None]
            e = r["error"].get(key) if mode == key else (max(errs) if errs else None)
            if e is None or r.get("reference"):
                continue
            pts.append((r["wall_s_per_sim_s"], max(e, 1e-6), f"{r['scenario']}/{r['model']}"))
        for label in sorted({p[2] for p in pts}):
            sel = sorted((p for p in pts if p[2] == label), key=lambda p: p[0])
            ax.plot([p[0] for p in sel], [p[1] for p in sel], "o-", label=label, alpha=0.8)
        # the Pareto front of each seed (errors of different gears are not comparable with each other)
        for k, scen in enumerate(sorted({p[2].split("/")[0] for p in pts})):
            sel = [p for p in pts if p[2].split("/")[0] == scen]
            c, e = np.array([p[0] for p in sel]), np.array([p[1] for p in sel])
            m = pareto_front(c, e)
            order = np.argsort(c[m])
            ax.plot(c[m][order], e[m][order], "k--", lw=1.2, alpha=0.8,
                    label="Pareto front (per seed)" if k == 0 else None)
        ax.set_xscale("log"); ax.set_yscale("log")
        ax.set_xlabel("wall time per simulated second [s/s]")
        ax.set_ylabel((f"relative error of {mode}" if mode == key else "worst relative error of the ERROR_KEYS")
                      + " (floored at 1e-6)")
        ax.grid(True, which="both", alpha=0.3)
        if pts:
            ax.legend(fontsize=7)
    fig.suptitle("wormsim bench: accuracy against speed (errors vs the finest contact3d run)")
    tmp = path.with_name(f".{path.name}.tmp.png")
    fig.savefig(tmp, dpi=110)
    plt.close(fig)
    os.replace(tmp, path)


# ----------------------------------------------------------------------------- stability edge (issue 5, first slice)

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
# the guards' messages (wormsim.simulate) start with these words; the class names are what bench_meta.json holds
FAILURE_CLASSES = (("diverged", "diverged"), ("teeth jumped", "teeth_jumped"), ("penetration", "penetration"),
                   ("the drive locked", "locked"), ("worm overspeed", "overspeed"))


def classify_failure(message: str) -> str:
    """Class of a contact3d guard message (wormsim.simulate): diverged | teeth_jumped | penetration | locked,
    else "other"."""
    for head, cls in FAILURE_CLASSES:
        if message.startswith(head):
            return cls
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


def stability_edge(scenario_name: str, factors: tuple[float, ...] = STABILITY_FACTORS,
                   duration_s: float = STABILITY_DURATION_S, overrides: tuple[str, ...] = (),
                   resolution: str | None = None, tolerances: dict | None = None) -> dict:
    """Sweep the contact3d timestep upward from its default h0 (wormsim.model.default_timestep: 0.4 x the explicit
    limit of the contact spring-damper, rounded down to 1-2-5) by `factors` on a short run of
    scenarios/<scenario_name>.yaml, until a run fails.

    Each run is classified: "ok"; "inaccurate" when the ratio (from the shaft angles over the steady window,
    angle_ratio) or the mean tangential force drifts from the run at the first factor by more than `tolerances` (relative; also when a checked value is missing); or the guard
    that stopped it (classify_failure: diverged, teeth_jumped, penetration, locked). The sweep stops at the first
    run that is not "ok". Returns a JSON-ready record: the default and limit timesteps, every run (factor,
    timestep_s, dt / limit, status, failure, message, ratio, tangential_force_mean_n, drift), the last stable
    timestep (the largest "ok" one, None if the first fails) and how the next one failed.
    Wall times are measured, never judged."""
    import time as _time

    from wormsim.errors import SimulationError
    from wormsim.model import build_model, default_timestep
    from wormsim.simulate import simulate

    tol = dict(STABILITY_TOLERANCES if tolerances is None else tolerances)
    base = tuple(overrides) + (f"simulation.duration_s={duration_s}",)
    if resolution is not None:
        base += (f"simulation.resolution={resolution}",)
    sc0 = load_scenario(SCENARIOS / f"{scenario_name}.yaml", list(base))
    law = build_model(sc0).law
    h0 = default_timestep(law)
    limit = law.stable_timestep_s(3 * law.contacts_per_pair)
    runs: list[dict] = []
    ref: dict | None = None
    for f in factors:
        dt = float(f"{h0 * f:.4g}")
        sc = load_scenario(SCENARIOS / f"{scenario_name}.yaml", list(base) + [f"simulation.timestep_s={dt}"])
        run = {"factor": f, "timestep_s": dt, "timestep_over_limit": dt / limit, "status": "ok", "failure": None,
               "message": "", "ratio": None, "ratio_angles": None, "tangential_force_mean_n": None, "drift": {},
               "wall_s": None}
        t0 = _time.perf_counter()
        try:
            res = simulate(sc)
        except SimulationError as exc:
            run.update(status="failed", failure=classify_failure(str(exc)), message=str(exc))
        else:
            s = dict(res.summary, ratio_angles=angle_ratio(res.series, res.summary.get("steady_window_s")))
            run["ratio"], run["tangential_force_mean_n"] = s.get("ratio"), s.get("tangential_force_mean_n")
            run["ratio_angles"] = s["ratio_angles"]
            if ref is None:
                ref = s
            run["drift"] = relative_errors(s, ref, tuple(tol))
            bad = [k for k, lim in tol.items() if run["drift"][k] is None or run["drift"][k] > lim]
            if bad:
                run.update(status="inaccurate", failure="inaccurate",
                           message="drift beyond tolerance (or no steady value) in " + ", ".join(bad))
        run["wall_s"] = _time.perf_counter() - t0
        runs.append(run)
        if run["status"] != "ok":
            break
    ok = [r for r in runs if r["status"] == "ok"]
    last = ok[-1] if ok else None
    first_bad = next((r for r in runs if r["status"] != "ok"), None)
    return {"scenario": scenario_name, "overrides": list(base), "duration_s": duration_s,
            "default_timestep_s": h0, "stable_limit_s": limit, "tolerances": tol,
            "last_stable_timestep_s": last["timestep_s"] if last else None,
            "last_stable_factor": last["factor"] if last else None,
            "failure": first_bad["failure"] if first_bad else None,
            "failed_timestep_s": first_bad["timestep_s"] if first_bad else None,
            "failure_message": first_bad["message"] if first_bad else "",
            "runs": runs}


def stability_map(quick: bool, scenarios: tuple[str, ...] | None = None) -> dict:
    """stability_edge for each seed's bench variant (VARIANTS) at STABILITY_RESOLUTION; quick: the seat motor only
    (about half a minute). Keyed by scenario, written to bench_meta.json under "stability"."""
    names = ("seat_motor",) if quick else tuple(VARIANTS)
    if scenarios is not None:
        names = tuple(n for n in names if n in scenarios)
    dur = STABILITY_DURATION_S          # 1.5 mesh periods of the seat motor at 1800 rpm; shorter runs have no steady window
    return {n: stability_edge(n, duration_s=dur, overrides=VARIANTS[n], resolution=STABILITY_RESOLUTION[n])
            for n in names}
