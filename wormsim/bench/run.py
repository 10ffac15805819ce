"""`wormsim bench`: speed against accuracy of the fidelity levels (docs/bench.md, bench.json).

For each seed scenario, each fidelity level runs across its resolutions and timesteps. Per run:

    wall_s            median wall time of `repeats` runs in this process, after a short warm-up run
                      that builds the geometry and k(theta) caches: the whole `simulate()` call (model build,
                      stepping loop, summary; no files written)
    realtime_factor   sim_s / wall_s
    loop_wall_s       contact3d only: median of the runner's stepping loop alone (summary `step_wall_us` x steps:
                      from the first step to the last sample, per-sample guards and bookkeeping included; model
                      build, first forward and summary excluded), over the same runs
    error[key]        |value - reference| / |reference| for key in ERROR_KEYS, against the converged
                      reference: the finest contact3d run of that scenario. The reference itself is checked
                      against a finer run (`reference_check` in bench_meta.json).

Outputs, written atomically: bench.json (list of records), bench_meta.json (machine, reference
check, notes, and "stability": the last stable contact3d timestep per seed and how the next one failed,
stability_edge), bench.png (error against wall time per simulated second, log axes, one curve per
level, Pareto front marked).
"""

from __future__ import annotations

import os
import platform
import statistics
import time
from pathlib import Path

import numpy as np

from wormsim.bench.cases import (
    GEOMETRIES,
    BenchCase,
    bench_cases,
    level_available,
    relative_errors,
)
from wormsim.bench.stability import stability_map
from wormsim.exceptions import SimulationError
from wormsim.results.provenance import provenance
from wormsim.run import simulate
from wormsim.runfolder.writer import write_json_atomic
from wormsim.scenario import ScenarioError


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
    return {
        "platform": platform.platform(),
        "python": platform.python_version(),
        "processor": platform.processor() or platform.machine(),
        "cpu_count": os.cpu_count(),
        "load_average_1min": os.getloadavg()[0] if hasattr(os, "getloadavg") else None,
    }


def _run_case(case: BenchCase, repeats: int) -> tuple[dict, float, float, float | None, float | None, int]:
    sc = case.build()
    # warm-up: a run of a few steps builds the geometry / k(theta) caches, so the timed runs measure
    # simulation, not one-off generation (which `wormsim mesh` reports on its own)
    warm = sc.model_copy(deep=True)
    warm.simulation.duration_s = 20 * (sc.simulation.timestep_s or 1e-4)
    try:
        simulate(warm)
    except Exception:  # a too-short run may fail its own checks (or its metrics); the timed runs report real failures
        pass
    walls, loops, res = [], [], None
    for _ in range(repeats):
        t0 = time.perf_counter()
        res = simulate(sc)
        walls.append(time.perf_counter() - t0)
        if res.summary.get("step_wall_us") is not None:
            loops.append(1e-6 * res.summary["step_wall_us"] * res.steps)
    loop = statistics.median(loops) if loops else None
    return res.summary, statistics.median(walls), res.sim_time_s, loop, min(loops) if loops else None, res.steps


def speedups(records: list[dict], key: str = "wall_s_per_sim_s", name: str = "speedup_vs_pieces") -> dict:
    """Wall time per simulated second of pieces over flanks (`key`: the whole simulate() call, or
    loop_wall_s_per_sim_s: the stepping loop alone), per scenario and resolution level, both at their own default
    timestep (timestep_factor 1) in the same bench run; also written into each flanks record (`name`, at every
    timestep factor both ran)."""
    out: dict = {}
    for r in records:
        res = r.get("resolution") or {}
        if r["model"] != "contact3d" or res.get("geometry") != "flanks" or r["status"] != "ok" or r.get("shafts"):
            continue
        p = next(
            (
                q
                for q in records
                if q["model"] == "contact3d"
                and q["scenario"] == r["scenario"]
                and q["status"] == "ok"
                and q.get("timestep_factor") == r.get("timestep_factor")
                and not q.get("shafts")
                and (q.get("resolution") or {}) == {**res, "geometry": "pieces"}
            ),
            None,
        )
        if p is None or not r.get(key) or not p.get(key):
            continue
        r[name] = p[key] / r[key]
        if r.get("timestep_factor") == 1.0:
            out.setdefault(r["scenario"], {})[res["level"]] = r[name]
    return out


def speedups_equal_accuracy(records: list[dict], key: str = "wall_s_per_sim_s") -> dict:
    """Flanks against pieces at equal or better accuracy, per scenario and resolution level, from one bench
    run's records (their `error` against the scenario's converged reference, every key of ERROR_LABELS) and cost
    `key` (whole simulate() or the stepping loop per simulated second). Two readings:
    vs_default_pieces: the pieces record at its default step (timestep_factor 1) against the cheapest flanks record
    whose |error| is <= the pieces' in every error key; vs_cheapest_pieces: the cheapest pieces record (any step)
    against the cheapest flanks record at least as accurate as that one (the Pareto reading). A missing error on
    either side disqualifies a flanks record; None where none qualifies."""

    def ok(r: dict, geo: str) -> bool:
        res = r.get("resolution") or {}
        good = r["model"] == "contact3d" and res.get("geometry") == geo and r["status"] == "ok" and bool(r.get(key))
        return good and not r.get("shafts")

    def as_accurate(f: dict, p: dict) -> bool:
        ef, ep = f.get("error") or {}, p.get("error") or {}
        return all(ef.get(k) is not None and ep.get(k) is not None and abs(ef[k]) <= abs(ep[k]) for k in ERROR_LABELS)

    def pick(p: dict, flanks: list[dict]) -> dict | None:
        good = [f for f in flanks if as_accurate(f, p)]
        if not good:
            return None
        f = min(good, key=lambda r: r[key])
        return {
            "speedup": p[key] / f[key],
            "pieces_timestep_factor": p.get("timestep_factor"),
            "pieces_" + key: p[key],
            "flanks_timestep_factor": f.get("timestep_factor"),
            "flanks_" + key: f[key],
        }

    out: dict = {}
    pieces = [r for r in records if ok(r, "pieces")]
    for p0 in pieces:
        scen, level = p0["scenario"], (p0.get("resolution") or {}).get("level")
        if level in out.get(scen, {}):
            continue
        same = [q for q in pieces if q["scenario"] == scen and (q.get("resolution") or {}).get("level") == level]
        flanks = [
            r
            for r in records
            if ok(r, "flanks") and r["scenario"] == scen and (r.get("resolution") or {}).get("level") == level
        ]
        default = next((q for q in same if q.get("timestep_factor") == 1.0), None)
        cheapest = min(same, key=lambda r: r[key])
        out.setdefault(scen, {})[level] = {
            "vs_default_pieces": pick(default, flanks) if default is not None else None,
            "vs_cheapest_pieces": pick(cheapest, flanks),
        }
    return out


def shaft_ratios(records: list[dict]) -> dict:
    """Each shafted run (`bench --shafts`, cases.SHAFTS_BLOCK) against its rigid twin (same scenario, resolution and
    timestep, in the same bench run), per scenario and resolution level: `loop` the stepping loop's wall time per
    simulated second over the rigid run's (medians of the repeats; `loop_best`: their fastest repeats, the reading
    least disturbed by other processes), `whole` the same for the whole simulate() call, and both runs' step_wall_us
    (median repeats)."""
    out: dict = {}
    for r in records:
        if not r.get("shafts") or r["status"] != "ok":
            continue
        twin = next(
            (
                q
                for q in records
                if not q.get("shafts")
                and q["status"] == "ok"
                and q["scenario"] == r["scenario"]
                and q["model"] == r["model"]
                and q.get("resolution") == r.get("resolution")
                and q.get("timestep_s") == r.get("timestep_s")
            ),
            None,
        )
        if twin is None or not twin.get("loop_wall_s") or not r.get("loop_wall_s"):
            continue
        out.setdefault(r["scenario"], {})[(r.get("resolution") or {}).get("level")] = {
            "loop": r["loop_wall_s"] / twin["loop_wall_s"],
            "loop_best": r["loop_wall_s_best"] / twin["loop_wall_s_best"],
            "whole": r["wall_s"] / twin["wall_s"],
            "rigid_step_wall_us": 1e6 * twin["loop_wall_s"] / twin["steps"],
            "shafts_step_wall_us": 1e6 * r["loop_wall_s"] / r["steps"],
            "timestep_s": r.get("timestep_s"),
        }
    return out


def run_bench(
    quick: bool,
    out_dir: str | Path,
    repeats: int | None = None,
    models: tuple[str, ...] | None = None,
    scenarios: tuple[str, ...] | None = None,
    geometries: tuple[str, ...] | None = None,
    resolutions: tuple[str, ...] | None = None,
    shafts: bool = False,
) -> list[dict]:
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    if repeats is not None and repeats < 1:
        raise ScenarioError(f"bench --repeats: {repeats} is not allowed; allowed: an integer >= 1")
    repeats = repeats or (1 if quick else 3)
    records, summaries, notes = [], {}, []
    machine_start = machine_info()
    for case in bench_cases(quick, models, scenarios, geometries, resolutions, shafts):
        try:
            summary, wall, sim_s, loop, loop_best, steps = _run_case(case, repeats)
        except SimulationError as exc:
            notes.append(f"{case.scenario} {case.model} {case.resolution} dt={case.timestep_s}: failed: {exc}")
            records.append(
                {
                    "scenario": case.scenario,
                    "model": case.model,
                    "resolution": case.resolution,
                    "timestep_s": case.timestep_s,
                    "timestep_factor": case.timestep_factor,
                    "wall_s": None,
                    "sim_s": None,
                    "realtime_factor": None,
                    "status": "failed",
                    "message": str(exc),
                    "error": {},
                }
            )
            continue
        rec = {
            "scenario": case.scenario,
            "shafts": case.shafts,
            "model": case.model,
            "resolution": case.resolution,
            "timestep_s": summary.get("timestep_s", case.timestep_s),
            "timestep_factor": case.timestep_factor,
            "wall_s": wall,
            "sim_s": sim_s,
            "realtime_factor": sim_s / wall if wall > 0 else None,
            "wall_s_per_sim_s": wall / sim_s if sim_s else None,
            "loop_wall_s": loop,
            "loop_wall_s_per_sim_s": loop / sim_s if loop is not None and sim_s else None,
            "loop_wall_s_best": loop_best,
            "steps": steps,
            "status": "ok",
            "reference": case.reference,
            "finer": case.finer,
            "error": {},
        }
        summaries[id(rec)] = summary
        records.append(rec)
    meta = {
        "provenance": provenance(),  # command, commit, date, machine (wormsim.results.provenance; docs/data records)
        "machine": machine_start,
        "load_average_1min_end": machine_info()["load_average_1min"],
        "quick": quick,
        "repeats": repeats,
        "scenarios": sorted({r["scenario"] for r in records}),
        "reference_check": {},
        "speedup_flanks_vs_pieces": speedups(records),  # whole simulate() calls (wall_s)
        "speedup_flanks_vs_pieces_loop": speedups(records, "loop_wall_s_per_sim_s", "loop_speedup_vs_pieces"),
        "notes": notes,
    }
    if shafts:
        meta["step_ratio_shafts_vs_rigid"] = shaft_ratios(records)
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
    # flanks against pieces at equal or better accuracy, now that every record has its errors
    meta["speedup_flanks_vs_pieces_equal_accuracy"] = speedups_equal_accuracy(records)
    meta["speedup_flanks_vs_pieces_equal_accuracy_loop"] = speedups_equal_accuracy(records, "loop_wall_s_per_sim_s")
    if level_available("contact3d") and (models is None or "contact3d" in models):
        # the timestep sweep of each seed until a guard fires (stability_edge); quick: the seat motor only
        meta["stability"] = stability_map(
            quick, scenarios, tuple(g for g in GEOMETRIES if geometries is None or g in geometries)
        )
    write_json_atomic(out / "bench.json", records)
    write_json_atomic(out / "bench_meta.json", meta)
    plot_bench(records, out / "bench.png")
    return records


ERROR_LABELS = {
    "ratio": "ratio",
    "tangential_force_mean_n": "mean tangential force",
    "tangential_force_p2p_n": "tangential force peak-to-peak",
    "mesh_frequency_hz": "meshing frequency",
    "efficiency": "efficiency",
}
PANEL_KEYS = ("tangential_force_mean_n", "tangential_force_p2p_n", "efficiency")
ERROR_FLOOR = 1e-6
NOTE_ERROR_1 = (
    "An error near 1 (100 %) is a value near 0 against a reference that is not: the torsional level's "
    "tangential-force ripple comes from its nearly smooth k(theta) table alone, far below the ripple of "
    "contact3d's contacts."
)


def curve_label(r: dict) -> str:
    """'screw jack, contact3d flanks' etc.: scenario and level in words."""
    geo = (r.get("resolution") or {}).get("geometry")
    level = r["model"] + (f" {geo}" if geo else "")
    return f"{r['scenario'].replace('_', ' ')}, {level}"


def plot_bench(records: list[dict], path: Path, keys: tuple[str, ...] = PANEL_KEYS) -> None:
    """One panel per output in `keys`: relative error against wall time per simulated second, log-log; each curve
    (scenario and level) joined in order of cost; the Pareto front of each seed dashed."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    ok = [
        r
        for r in records
        if r["status"] == "ok"
        and r.get("wall_s_per_sim_s")
        and not r.get("finer")
        and not r.get("reference")
        and not r.get("shafts")
    ]
    fig, axes = plt.subplots(1, len(keys), figsize=(5.2 * len(keys), 5.0), constrained_layout=True, squeeze=False)
    labels = sorted({curve_label(r) for r in ok})
    colors = {lab: plt.cm.tab10(i % 10) for i, lab in enumerate(labels)}
    for ax, key in zip(axes[0], keys):
        pts = [
            (r["wall_s_per_sim_s"], max(r["error"][key], ERROR_FLOOR), curve_label(r))
            for r in ok
            if r["error"].get(key) is not None
        ]
        for label in labels:
            sel = sorted((p for p in pts if p[2] == label), key=lambda p: p[0])  # in order of cost
            if sel:
                ax.plot([p[0] for p in sel], [p[1] for p in sel], "o-", color=colors[label], label=label, alpha=0.85)
        for k, scen in enumerate(sorted({p[2].split(",")[0] for p in pts})):
            sel = [p for p in pts if p[2].split(",")[0] == scen]
            c, e = np.array([p[0] for p in sel]), np.array([p[1] for p in sel])
            m = pareto_front(c, e)
            order = np.argsort(c[m])
            ax.plot(
                c[m][order], e[m][order], "k--", lw=1.0, alpha=0.6, label="Pareto front (per gear)" if k == 0 else None
            )
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_title(ERROR_LABELS.get(key, key))
        ax.set_xlabel("wall time per simulated second [s]")
        ax.set_ylabel(f"relative error against the reference (floored at {ERROR_FLOOR:g})")
        ax.grid(True, which="both", alpha=0.3)
    handles, names = axes[0][0].get_legend_handles_labels()
    for ax in axes[0][1:]:
        for h, n in zip(*ax.get_legend_handles_labels()):
            if n not in names:
                handles.append(h)
                names.append(n)
    if handles:
        fig.legend(handles, names, loc="outside lower center", ncol=min(4, len(names)), fontsize=8)
    fig.suptitle(
        "wormsim bench: accuracy against speed (reference: the finest contact3d run of each gear at its "
        "default step)\n" + NOTE_ERROR_1,
        fontsize=9,
    )
    tmp = path.with_name(f".{path.name}.tmp.png")
    fig.savefig(tmp, dpi=110)
    plt.close(fig)
    os.replace(tmp, path)
