"""`make docs`: the tables and figures of README.md and docs/*.md rendered from the records under docs/data/*.json
(each with its provenance, wormsim.results.provenance), simulating nothing.

A markdown block to render is marked

    <!-- render: NAME -->
    ...            (replaced by TABLES[NAME]())
    <!-- /render -->

and each figure of FIGURES is drawn to docs/img/NAME.png from its record (matplotlib's Agg backend, fixed
metadata: the same record gives the same bytes). The shipped sweeps' tables and charts read their records
docs/sweeps/*.csv, whose provenance is docs/data/sweeps.json. `python -m tools.docs_render` renders every block
and figure in place; `--check` only reports the blocks that differ from their records (exit 1).
tests/tools/test_docs_render.py runs the check. `python -m tools.docs_render record-bench NAME DIR` turns a
`wormsim bench --out DIR` into the record docs/data/NAME.json (the provenance bench_meta.json carries).
"""

from __future__ import annotations

import json
import re
import sys
from collections.abc import Callable
from pathlib import Path

from wormsim.results.provenance import DATA, KEYS, ROOT, record

MARK = re.compile(r"(<!-- render: (?P<name>[a-z0-9_]+) -->\n)(?P<body>.*?)(<!-- /render -->)", re.S)
IMG = ROOT / "docs" / "img"
# deterministic PNGs: no software/date chunks that change between matplotlib builds or runs
PNG_METADATA = {"Software": None}


def load(name: str) -> dict:
    """docs/data/NAME.json."""
    return json.loads((DATA / f"{name}.json").read_text())


def _fmt(x, digits: int = 3) -> str:
    """A number for a table: '-' for none, fixed for moderate magnitudes, exponent otherwise."""
    if x is None:
        return "-"
    if isinstance(x, str):
        return x
    if x == 0:
        return "0"
    a = abs(x)
    if a < 1e-6:
        return "< 1e-6"
    if a < 1e-2 or a >= 1e6:
        return f"{x:.1e}"
    if a >= 100:
        return f"{x:.0f}"
    return f"{x:.{digits}g}"


def _table(head: list[str], rows: list[list[str]]) -> str:
    lines = ["| " + " | ".join(head) + " |", "|" + " --- |" * len(head)]
    lines += ["| " + " | ".join(r) + " |" for r in rows]
    return "\n".join(lines) + "\n"


def _source(name: str) -> str:
    """The line under a table: its record and the record's provenance."""
    p = load(name)["provenance"]
    return f"Record: `docs/data/{name}.json` (`{p['command']}`; commit {p['commit']}, {p['date'][:10]}).\n"


# ----------------------------------------------------------------------------- tables


def bench_full_table(name: str = "bench_full") -> str:
    """One row per bench record: level, resolution, step, wall s per simulated s, relative errors against the
    reference (the finest contact3d run of the seed, itself checked against h/2)."""
    rows = []
    for r in load(name)["records"]:
        res = r["resolution"]
        level = r["model"]
        if r.get("reference"):
            level += " (reference)"
        elif r.get("finer"):
            level += " (check, h/2)"
        if "mesh_stiffness_samples" in res:
            resolution = f"{res['mesh_stiffness_samples']} samples/cycle"
        else:
            resolution = res.get("level", "") + (f" {res['geometry']}" if "geometry" in res else "")
        e = r.get("error") or {}
        keys = ("ratio", "tangential_force_mean_n", "tangential_force_p2p_n", "mesh_frequency_hz", "efficiency")
        errs = ["-" if r.get("reference") else _fmt(e.get(k), 2) for k in keys]
        rows.append(
            [r["scenario"], level, resolution, f"{r['timestep_s']:g} s", _fmt(r.get("wall_s_per_sim_s"), 3), *errs]
        )
    head = ["seed", "level", "resolution", "timestep", "wall s per sim s", "ratio err", "F_t mean err"]
    head += ["F_t p2p err", "f_mesh err", "efficiency err"]
    return _table(head, rows) + "\n" + _source(name)


def bench_stability_table(name: str = "bench_full") -> str:
    """The stability edge of each seed (bench_meta.json "stability", wormsim.bench.stability)."""
    rows = []
    for seed, s in sorted(load(name)["meta"].get("stability", {}).items()):
        res = next((o.split("=")[1] for o in s.get("overrides", []) if o.startswith("simulation.resolution=")), "")
        h0, lim = s["default_timestep_s"], s["stable_limit_s"]
        last = s.get("last_stable_timestep_s")
        last_s = f"{last:.3g} s (x{s['last_stable_factor']}, {last / lim:.2f} h_lim)" if last else "-"
        nxt = s.get("failed_timestep_s")
        nxt_s = f"{nxt:.3g} s ({nxt / lim:.2f} h_lim)" if nxt else "-"
        rows.append([f"{seed} ({res})", f"{h0:.3g} s", f"{lim:.3g} s", last_s, nxt_s, s.get("failure") or "-"])
    head = ["seed (resolution)", "h0", "h_lim", "last stable", "next step", "failed as"]
    return _table(head, rows) + "\n" + _source(name)


def bench_flanks_vs_pieces_table(name: str = "bench_flanks_vs_pieces") -> str:
    """Speed-up of exact flanks over convex pieces (bench_meta.json): at the same resolution level and step, and at
    equal or better accuracy (wormsim.bench.run.speedups_equal_accuracy; every error is measured against the
    reference run of the seed's default geometry, which is the flanks' own finest run)."""
    m = load(name)["meta"]
    rows = []
    for seed in sorted(m.get("speedup_flanks_vs_pieces", {})):
        for level, whole in sorted(m["speedup_flanks_vs_pieces"][seed].items()):
            loop = m.get("speedup_flanks_vs_pieces_loop", {}).get(seed, {}).get(level)
            eq = m.get("speedup_flanks_vs_pieces_equal_accuracy", {}).get(seed, {}).get(level, {})
            eq_l = m.get("speedup_flanks_vs_pieces_equal_accuracy_loop", {}).get(seed, {}).get(level, {})

            def x(d: dict, k: str) -> str:
                return _fmt(d.get(k, {}).get("speedup"), 3) + "x"

            rows.append(
                [
                    seed,
                    level,
                    f"{_fmt(whole)}x / {_fmt(loop)}x",
                    f"{x(eq, 'vs_default_pieces')} / {x(eq_l, 'vs_default_pieces')}",
                    f"{x(eq, 'vs_cheapest_pieces')} / {x(eq_l, 'vs_cheapest_pieces')}",
                ]
            )
    head = ["seed", "level", "same step: whole / loop", "equal accuracy, pieces at default step: whole / loop"]
    head += ["pieces' cheapest run (Pareto): whole / loop"]
    note = (
        "Accuracy is each run's relative error against the seed's reference, the finest run of the default "
        "geometry (exact flanks) at its default step: the flanks are compared with their own reference, the pieces "
        "with it too.\n"
    )
    return _table(head, rows) + "\n" + note + _source(name)


def bench_shafts_table(names: tuple[str, ...] = ("bench_shafts_before", "bench_shafts")) -> str:
    """A shafts: run's step against the rigid one's (`wormsim bench --shafts`, bench_meta.json
    step_ratio_shafts_vs_rigid), one row per record: before the shafts' step changes and now."""
    rows = []
    for name in names:
        d = load(name)
        for seed, levels in sorted(d["meta"].get("step_ratio_shafts_vs_rigid", {}).items()):
            for level, r in sorted(levels.items()):
                rows.append(
                    [
                        f"{d['provenance']['commit']}",
                        f"{seed} ({level}, {r['timestep_s']:.3g} s)",
                        f"{r['rigid_step_wall_us']:.0f} us",
                        f"{r['shafts_step_wall_us']:.0f} us",
                        f"{r['loop']:.2f}x",
                        f"{r['loop_best']:.2f}x",
                        f"{r['whole']:.2f}x",
                        f"{d['meta']['machine']['load_average_1min']:.1f}",
                    ]
                )
    head = ["commit", "seed (level, step)", "rigid step", "shafts step", "step ratio (median)", "ratio (best)"]
    head += ["whole simulate()", "load (2 CPUs)"]
    return _table(head, rows) + "\n" + "".join(_source(n) for n in names)


def flank_speed_table(name: str = "flank_speed") -> str:
    """Per step, exact flanks against medium convex pieces (studies/measure_flank_speed.py, best of the repeats)."""
    best = load(name)["best"]
    rows = []
    for seed, b in best.items():
        rows.append(
            [
                seed,
                f"{b['pieces_step_wall_us']:.0f} us",
                f"{b['flanks_step_wall_us']:.0f} us",
                f"{b['speedup_flanks_vs_pieces']:.1f}x",
                f"{b['flanks_tooth_step_wall_us']:.0f} us",
                f"{b['speedup_flanks_tooth_vs_pieces']:.1f}x",
            ]
        )
    head = ["seed", "pieces (medium)", "flanks, per slice", "speed-up", "flanks, per tooth flank"]
    head += ["speed-up"]
    return _table(head, rows) + "\n" + _source(name)


def seat_motor_profile_table(name: str = "seat_motor_profile") -> str:
    """The unscaled seat motor's CPU at its defaults, split (studies/profile_seat_motor.py): the compiled step's
    stages, the loop outside them, the whole run."""
    r = load(name)
    run, st = r["run"], r["step"]
    total = st["sum_of_parts_us"]
    rows = [[g, f"{us:.1f}", f"{100 * us / total:.0f} %"] for g, us in st["groups_us"].items()]
    rows.append(["the compiled step (the stages' sum)", f"{total:.1f}", "100 %"])
    rows.append(
        [
            "the stepping loop outside the compiled steps (samples, Python, numba's dispatch)",
            f"{r['samples_and_python_us_per_step']:.1f}",
            "-",
        ]
    )
    text = _table(["part", "us per step", "share of the step"], rows)
    text += (
        f"\nThe step from t = {st['from_s']} s ({st['steps']} steps, median of {st['rounds']} rounds): "
        f"{st['mujoco_contacts']} MuJoCo contacts ({st['slice_contacts']} slice contacts merged), "
        f"{st['constraint_rows']} constraint rows, {st['solver_iterations']:.2f} solver iterations and "
        f"{st['line_search_evaluations']:.2f} line-search evaluations per step. The whole run over "
        f"{r['seconds']} s from rest: {run['cpu_s_per_sim_s']:.1f} CPU s per simulated s (rounds: "
        + " / ".join(f"{x:.1f}" for x in run["rounds_cpu_s_per_sim_s"])
        + f"), its stepping loop {run['loop_us_per_step']:.1f} us per step, the compiled steps alone over the same "
        f"window {r['run_table_whole_window_us_per_step']:.1f} us per step (load average "
        f"{r['load_average_at_start'][0]:.1f} at the start, {r['load_average_after'][0]:.1f} after).\n"
    )
    return text + "\n" + _source(name)


def seat_motor_levers_table(name: str = "seat_motor_levers") -> str:
    """The unscaled seat motor's result-moving levers (studies/seat_motor_levers.py): CPU s per simulated s and the
    ratio to the default per round, the CI run's results relative to the default."""
    r = load(name)
    rows = []
    for k, c in r["cpu_s_per_sim_s"].items():
        rel = r["ci_relative_pct"][k]
        rows.append(
            [
                k,
                " / ".join(f"{x:.1f}" for x in c),
                " / ".join(f"{x:.2f}" for x in r["ratio_to_default"][k]),
                ", ".join(f"{rel[x]:+.3f} %" for x in ("tangential_force_mean_n", "tangential_force_p2p_n")),
                ", ".join(f"{rel[x]:+.3f} %" for x in ("efficiency", "transmission_error_p2p_urad")),
            ]
        )
    head = ["lever", "CPU s per simulated s (rounds)", "ratio to default", "CI run: F_t mean, p2p"]
    head += ["CI run: efficiency, TE p2p"]
    return _table(head, rows) + "\n" + _source(name)


def kernel_replay_table(name: str = "kernel_replay") -> str:
    """The flank kernel's parts on a recorded replay of the seat motor (studies/kernel_replay.py): each part's cost
    (what doing it twice adds), the counts per call, and another kernel against the base."""
    r = load(name)
    base = r["us_per_call"]["plain"]
    rows = [["the whole kernel call (find_packed)", f"{base:.1f}", "100 %"]]
    rows += [[k, f"{v:.1f}", f"{100 * v / base:.0f} %"] for k, v in r["part_us"].items()]
    text = _table(["part (base kernel)", "us per call", "share of the call"], rows)
    c = r["counts_per_call"]
    text += (
        f"\nPer call ({r['steps']} steps of {r['timestep_s'] * 1e6:.1f} us from t = {r['warm_s']} s, median of "
        f"{r['rounds']} interleaved rounds, load average {r['load_average_at_start'][0]:.1f} at the start): "
        + (", ".join(f"{v:.1f} {k}" for k, v in c.items()) if c else "the parts above")
        + ".\n"
    )
    if r.get("other"):
        chk = r["contacts_check"]["other"]
        text += (
            f"\n`{r['other']}` against the base ({r['base']}): {r['us_per_call']['other']:.1f} against {base:.1f} us "
            f"per call, ratio {r['other_over_base']:.2f}"
            + (
                f", the rounds' own ratios' median {r['other_over_base_median_of_rounds']:.2f}"
                if "other_over_base_median_of_rounds" in r
                else ""
            )
            + " (rounds "
            + " / ".join(f"{x:.2f}" for x in r["other_over_base_rounds"])
            + f"); contacts per step equal: {'yes' if chk['contacts_equal'] else 'no'}, the last step's merged "
            f"contacts' largest difference {chk['last_step_max_abs_diff']:.1e}.\n"
        )
    return text + "\n" + _source(name)


def flank_contacts_table(name: str = "flank_contacts") -> str:
    """MuJoCo contacts per tooth flank (studies/flank_contacts.py): the seat motor's CPU s per simulated second per
    variant, and the seeds' CI results relative to per slice."""
    r = load(name)
    cpu, seeds = r["cpu_s_per_sim_s"], r["seeds"]
    variants = list(cpu)
    head = ["contact.flank_contacts", "seat motor, 36 rpm: CPU s per simulated s (rounds)", "ratio to slice"]
    keys = (
        ("tangential_force_p2p_n", "F_t p2p"),
        ("efficiency", "efficiency"),
        ("transmission_error_p2p_urad", "TE p2p"),
    )
    for seed in seeds:
        head.append(f"{seed}: contacts; " + ", ".join(k[1] for k in keys))
    rows = []
    for v in variants:
        row = [v, " / ".join(f"{x:.1f}" for x in cpu[v]), " / ".join(f"{x:.2f}" for x in r["ratio_to_slice"][v])]
        for seed, res in seeds.items():
            b, x = res["slice"], res[v]
            if v == "slice":
                cell = f"{x['contacts_mean']:.0f}; " + ", ".join(f"{x[k]:.4g}" for k, _ in keys)
            else:
                cell = f"{x['contacts_mean']:.0f}; " + ", ".join(f"{(x[k] / b[k] - 1) * 100:+.2f} %" for k, _ in keys)
            row.append(cell)
        rows.append(row)
    return _table(head, rows) + "\n" + _source(name)


def flank_contacts_default_table(name: str = "flank_contacts_default") -> str:
    """N MuJoCo contacts per tooth flank against per slice on the slice-convergence cases (studies/
    flank_contacts_default.py): N per flank's change at the default slices S, the stepping's CPU per simulated second,
    and S against 2 S per variant (issue 31's criterion: F_t p2p and p_H max within 10 %)."""
    r = load(name)
    n = str(r["n"])
    keys = (
        ("tangential_force_mean_n", "F_t mean"),
        ("tangential_force_p2p_n", "F_t p2p"),
        ("contact_pressure_max_mpa", "p_H max"),
        ("transmission_error_p2p_urad", "TE p2p"),
        ("efficiency", "efficiency"),
        ("radial_force_mean_n", "F_r"),
        ("axial_force_mean_n", "F_a"),
    )
    head = ["case (S)", *(f"{k[1]}: {n} per flank vs slice" for k in keys), "CPU s per simulated s: slice, " + n]
    head += [f"S vs 2 S: F_t p2p, p_H max: slice; {n} per flank"]

    def pct(x):
        return "-" if x is None else f"{100 * x:+.2f} %"

    rows = []
    within = {"slice": 0, n: 0}
    for case, c in r["cases"].items():
        ch, cv = c["change_vs_slice"], c["change_S_vs_2S"]
        a, b = c["runs"]["slice"][0], c["runs"][n][0]
        conv = "; ".join(
            ", ".join(f"{100 * cv[v][k]:+.1f} %" for k in ("tangential_force_p2p_n", "contact_pressure_max_mpa"))
            for v in ("slice", n)
        )
        for v in within:
            within[v] += all(abs(cv[v][k]) <= 0.10 for k in ("tangential_force_p2p_n", "contact_pressure_max_mpa"))
        row = [f"{case} ({c['default_slices']})", *(pct(ch[k]) for k, _ in keys)]
        rows.append([*row, f"{a['cpu_s_per_sim_s']:.1f}, {b['cpu_s_per_sim_s']:.1f}", conv])
    total = len(r["cases"])
    foot = f"\nS against 2 S within 10 % (F_t p2p and p_H max): per slice {within['slice']} of {total}, {n} per flank "
    foot += f"{within[n]} of {total}.\n"
    return _table(head, rows) + foot + "\n" + _source(name)


def seat_motor_20s_table(name: str = "seat_motor_20s") -> str:
    """The 20 s seat motor run (pieces, unscaled): its summary recomputed with the fixed steady window."""
    r = load(name)
    s = r.get("recomputed_with_the_fixed_steady_window") or r["summary_as_written_by_the_run"]
    keys = [
        ("wall_time_s", "wall s", 0),
        ("steps", "steps", 0),
        ("efficiency", "efficiency", 4),
        ("ratio", "ratio", 6),
        ("tangential_force_mean_n", "F_t mean N", 6),
        ("tangential_force_p2p_n", "F_t p2p N", 3),
        ("mesh_frequency_hz", "f_mesh Hz", 5),
        ("mesh_frequency_theory_hz", "z1 n1 / 60 Hz", 5),
        ("steady_window_s", "steady window s", 0),
    ]
    row = []
    for k, _, d in keys:
        v = s.get(k, r.get(k))
        if isinstance(v, list):
            row.append(f"{v[0]:.2f}-{v[1]:.2f}")
        elif k == "ratio":
            row.append(f"{v:.5f}")
        elif isinstance(v, float) and d:
            row.append(f"{v:.{d}g}")
        else:
            row.append(_fmt(v) if not isinstance(v, int) else f"{v}")
    return _table([h for _, h, _ in keys], [row]) + "\n" + _source(name)


def sweep_speedup_table(name: str = "sweep_speedup") -> str:
    """1 against 2 dask workers on the same sweep (studies/measure_speedup.py)."""
    r = load(name)
    rows = []
    for n, x in sorted(r["runs"].items()):
        rows.append(
            [
                n,
                f"{x['command_wall_s']:.0f}",
                f"{x['sweep_wall_s']:.0f}",
                f"{x['cluster_start_s']:.1f}",
                f"{x['task_wall_median_s']:.1f}",
                f"{x['simulate_wall_median_s']:.1f}",
            ]
        )
    head = ["workers", "command wall s", "sweep wall s", "cluster start s", "task median s", "simulate median s"]
    text = _table(head, rows)
    text += (
        f"\nSpeed-up 1 -> 2 workers: {r['speedup_command']:.2f}x for the whole command, "
        f"{r['speedup_excluding_cluster_start']:.2f}x without the cluster's start ({r['what']}).\n"
    )
    return text + "\n" + _source(name)


def _before_after(x: dict) -> str:
    """A scaling run's fixed cost split: the command's start to the first point, the last point to its exit."""
    if x.get("before_first_point_s") is None:
        return "-"
    return f"{x['before_first_point_s']:.1f} / {x['after_last_point_s']:.1f}"


def sweep_scaling_table(name: str = "sweep_scaling") -> str:
    """A contact3d sweep as `wormsim sweep` commands on 1 and 2 workers, and the scaling model
    (studies/measure_sweep_scaling.py)."""
    r = load(name)
    rows = []
    for n, x in sorted(r["runs"].items(), key=lambda kv: int(kv[0])):
        rows.append(
            [
                n,
                f"{x['command_wall_s']:.1f}",
                f"{x['span_s']:.1f}",
                f"{x['fixed_s']:.1f}",
                _before_after(x),
                f"{x['cluster_start_s']:.1f}",
                "-" if x.get("warm_s") is None else f"{x['warm_s']:.1f}",
                f"{x['point_wall_median_s']:.2f}",
                "-" if x.get("point_cpu_median_s") is None else f"{x['point_cpu_median_s']:.2f}",
                f"{x['step_wall_us_median']:.0f}",
                f"{x['idle_per_point_s']:.2f}",
                ", ".join(f"{v:.2f}" for v in x["first_point_extra_s"]) or "-",
                ", ".join(f"{v:.1f}" for v in x["compile_s_per_worker"]),
                str(x.get("points_per_task")),
            ]
        )
    head = [
        "workers",
        "command s",
        "points' span s",
        "fixed s",
        "before first point / after last s",
        "cluster start s",
        "warm-up s",
        "point median s",
        "point CPU s",
        "step us",
        "idle per point s",
        "first point extra s",
        "compile s per worker",
        "points per task",
    ]
    m = r["model"]
    text = _table(head, rows)
    text += (
        f"\n{r['what']}. Speed-up 1 -> 2 workers: {r['speedup_command']:.2f}x for the whole command, "
        f"{r['speedup_span']:.2f}x over the points' span; the step grows {r['step_growth_2']:.2f}x with 2 busy "
        "workers"
        + (f", a point's CPU seconds {r['point_cpu_growth_2']:.2f}x" if r.get("point_cpu_growth_2") is not None else "")
        + f". Load average after: {', '.join(f'{v:.1f}' for v in r['load_average_after'])} "
        f"({r['cpu_count']} CPUs)."
        + (
            " Commands (s), in turns: "
            + "; ".join(
                f"{n} worker{'s' if n != '1' else ''}: {', '.join(f'{v:.1f}' for v in w)}"
                for n, w in sorted(r["command_walls_s"].items())
            )
            + "."
            if r.get("command_walls_s")
            else ""
        )
        + (
            " Each standing cluster's first command (its workers load the kernels): "
            + "; ".join(
                f"{n} worker{'s' if n != '1' else ''} {v:.1f} s" for n, v in sorted(r["first_command_s"].items())
            )
            + "."
            if r.get("first_command_s")
            else ""
        )
        + "\n\n"
        f"Model T(N) = fixed + ceil(P / N) t_point g(N), t_point = {m['t_point_s']:.1f} s the 1-worker span per "
        "point: "
        f"T(1) {m['T_1_s']:.1f} s, T(2) {m['T_2_s']:.1f} s (with the measured g(2)), "
        f"T(16) {m['T_16_s_no_growth']:.1f} s with no step growth and {m['T_16_s_growth_1.31']:.1f} s "
        "with g(16) 1.31.\n"
    )
    return text + "\n" + _source(name)


CONTENTION_LABELS = {
    "python": "pure-Python integer loop",
    "numpy_small": "NumPy on 64-element arrays",
    "mujoco": "mj_step of MuJoCo's sample model from Python",
    "mujoco_rollout": "mujoco.rollout of the same model",
    "stream": "64 MB NumPy copy (memory bandwidth)",
    "point": "screw-jack point at contact3d (ours)",
}


QUIET_OTHERS_CORES = 0.2  # the other processes' cores below which an "alone" run was alone


def core_contention_table(name: str = "core_contention") -> str:
    """The same work alone and two at once, one process per core (studies/measure_core_contention.py)."""
    r = load(name)
    rows = []
    for k, x in r["summary"].items():
        rows.append(
            [
                CONTENTION_LABELS.get(k, k),
                f"{x['cpu_alone_median_s']:.3f}",
                f"{x['cpu_pair_median_s']:.3f}",
                f"{x['growth']:.2f}",
                f"{x['growth_best']:.2f}",
                f"{x['growth_beside_python']:.2f}",
                f"{x['growth_beside_stream']:.2f}",
                f"{x['others_cores_alone_median']:.2f} / {x['others_cores_pair_median']:.2f}",
            ]
        )
    head = [
        "work",
        "CPU s alone",
        "CPU s two at once",
        "growth two at once",
        "same, fastest",
        "growth beside a Python loop",
        "growth beside a 64 MB copy",
        "others' cores alone / two",
    ]
    text = _table(head, rows)
    text += (
        "\nThe same work alone, two at once, and beside a neighbour on the other core (each process pinned to its "
        f"core; CPU seconds of the working thread, medians of {r['repeats']} turns). Load average before / after: "
        f"{', '.join(f'{v:.1f}' for v in r['load_average_before'])} / "
        f"{', '.join(f'{v:.1f}' for v in r['load_average_after'])} ({r['cpu_count']} CPUs). "
        "Others' cores: what the machine's other processes used meanwhile (/proc/stat less ours)."
    )
    point = r["summary"].get("point")
    if point is not None and point["others_cores_alone_median"] <= QUIET_OTHERS_CORES:
        bound = min(2.0, r["span_speedup_bound_2"])  # a growth below 1 is noise, not a faster core
        text += f" Bound on a CPU-bound 2-worker span from the point's growth: {bound:.2f}x."
    elif point is not None:
        text += (
            f" The machine was not quiet (others' cores above {QUIET_OTHERS_CORES}): no growth or bound is read "
            "from this record."
        )
    return text + "\n\n" + _source(name)


def sweep_fixed_cost_table(name: str = "sweep_fixed_cost") -> str:
    """A sweep command's fixed cost, this commit against an earlier one, taking turns
    (studies/measure_sweep_fixed.py)."""
    r = load(name)
    keys = [
        ("preload_cpu_s", "fork server's preload, CPU s"),
        ("worker_cpu_s", "a worker before its first point, CPU s"),
        ("before_first_point_s", "before the first point s"),
        ("after_last_point_s", "after the last point s"),
        ("fixed_s", "fixed s"),
        ("command_s", "command s"),
    ]
    names = list(r["medians"])
    rows = [
        [label, *(f"{r['medians'][n][k]:.2f}" for n in names), f"{r['ratio_this_over_compare'][k]:.2f}"]
        for k, label in keys
        if k in r["ratio_this_over_compare"]  # (worker_cpu_s: records from 2026-11-28 on)
    ]
    head = ["median", *(("this commit" if n == "this" else n) for n in names), "ratio"]
    text = _table(head, rows)
    text += (
        f"\n{r['what']}. Load average before / after: {', '.join(f'{v:.1f}' for v in r['load_average_before'])} / "
        f"{', '.join(f'{v:.1f}' for v in r['load_average_after'])} ({r['cpu_count']} CPUs).\n"
    )
    return text + "\n" + _source(name)


def _study_value(v) -> str:
    """The error's value: a number, or the pitch deviations of every other tooth as one phrase."""
    if v in (None, ""):
        return "-"
    if isinstance(v, str) and v.startswith("["):
        v = json.loads(v)
    if isinstance(v, list):
        return f"every other tooth +{max(v):g} um"
    return str(v)


def errors_study_table(name: str = "errors_study") -> str:
    """studies/errors_study.py: each error alone at 0.25 and 0.5 of its limit (docs/errors.md section 7)."""

    def f(x, spec):
        return "-" if x is None or x == "" else spec.format(x)

    rows = []
    for r in load(name)["rows"]:
        te, kin = r.get("transmission_error_p2p_urad"), r.get("transmission_error_kinematic_p2p_urad")
        te_s = f(te, "{:.0f}") + (f" ({kin:.0f})" if kin not in (None, "") else "")
        p = f"{f(r.get('contact_pressure_max_mpa'), '{:.0f}')} / {f(r.get('contact_pressure_mean_mpa'), '{:.0f}')}"
        play = r.get("backlash_measured_mm")
        rows.append(
            [
                r["gear"].replace("_", " "),
                r["error"],
                f(r.get("size"), "{:g}") if r.get("size") not in (None, "") else "-",
                _study_value(r.get("value")),
                f(r.get("contact_pattern_centroid_face_mm"), "{:.2f}"),
                f(r.get("contact_pattern_extent_face_mm"), "{:.1f}"),
                te_s,
                f(r.get("tangential_force_p2p_n"), "{:.1f}"),
                f(r.get("efficiency"), "{:.3f}"),
                p,
                "j" if play in (None, "") else f"{play:.4f}",
            ]
        )
    head = ["gear", "error", "size", "value", "centroid face mm", "extent mm", "TE p2p urad (kin.)", "F_t p2p N"]
    head += ["efficiency", "p_H max / mean MPa", "play mm"]
    return _table(head, rows) + "\n" + _source(name)


def errors_shaft_angle_table(name: str = "errors_shaft_angle") -> str:
    """studies/errors_shaft_angle.py: the screw jack at its working point with a shaft angle (docs/errors.md, 6)."""
    rows = []
    for r in load(name)["rows"]:
        kin = r.get("transmission_error_kinematic_p2p_urad")
        play = r.get("backlash_measured_mm")
        rows.append(
            [
                f"{r['shaft_angle_deg']:+g} deg" if r["shaft_angle_deg"] else "none",
                f"{r['contact_pattern_centroid_face_mm']:+.2f} mm",
                f"{r['contact_pattern_extent_face_mm']:.1f} mm",
                f"{r['contact_pressure_max_mpa']:.0f} / {r['contact_pressure_mean_mpa']:.0f} MPa",
                f"{r['tangential_force_p2p_n']:.1f} N",
                f"{r['transmission_error_p2p_urad']:.0f}" + (f" ({kin:.0f})" if kin is not None else "") + " urad",
                f"{r['efficiency']:.3f}",
                "j" if play is None else f"{play:.3f} mm",
            ]
        )
    head = ["shaft angle", "pattern centroid face", "95 % extent", "p_H max / mean", "F_t p2p", "TE p2p (kin.)"]
    head += ["efficiency", "play"]
    return _table(head, rows) + "\n" + _source(name)


def contact_pattern_table(name: str = "ci_seeds_flanks") -> str:
    """The loaded contact pattern and Hertz pressure of the seeds' CI runs with exact flanks (studies/ci_seeds.py)."""
    rows = []
    for seed, run in load(name)["runs"].items():
        s = run["summary"]
        rows.append(
            [
                seed,
                f"{s['contact_pattern_centroid_face_mm']:.2f} / {s['contact_pattern_centroid_radius_mm']:.2f} mm",
                f"{s['contact_pattern_extent_face_mm']:.2f} mm",
                f"{s['contact_pressure_mean_mpa']:.0f} MPa",
                f"{s['contact_pressure_max_mpa']:.0f} MPa ({s['contact_pressure_max_face_mm']:.2f}, "
                f"{s['contact_pressure_max_radius_mm']:.2f} mm)",
            ]
        )
    head = ["seed (CI run)", "pattern centroid face / radius", "95 % extent", "p_H mean", "p_H max (face, radius)"]
    return _table(head, rows) + "\n" + _source(name)


def ci_seeds_table(name: str = "ci_seeds_flanks") -> str:
    """The seeds' CI runs with exact flanks against the closed forms (studies/ci_seeds.py)."""
    rows = []
    for seed, run in load(name)["runs"].items():
        s = run["summary"]
        rows.append(
            [
                seed,
                f"{s['ratio']:.5f} ({s['ratio_theory']:g})",
                f"{s['mesh_frequency_hz']:.4f} ({s['mesh_frequency_theory_hz']:.4f}) Hz",
                f"{s['tangential_force_mean_n']:.1f} ({s['tangential_force_theory_n']:.1f}) N",
                # older records carry DIN's F_r2 (the line of centres') as radial_force_line_of_centres_mean_n
                f"{s.get('radial_force_line_of_centres_mean_n', s['radial_force_mean_n']):.1f} "
                f"({s['radial_force_theory_n']:.1f}) N",
                f"{s['efficiency']:.4f} ({s['efficiency_theory_at_contact_radius']:.4f})",
                f"{s['tangential_force_p2p_n']:.3g} N",
                f"{s['transmission_error_p2p_urad']:.4g} urad",
                f"{s['resolution']}, {s['flank_slices']} slices, {s['timestep_s']:g} s",
            ]
        )
    head = [
        "seed",
        "ratio (z2 / z1)",
        "f_mesh (z1 n1 / 60)",
        "F_t mean (T2 / r2)",
        "F_r on the line of centres (DIN 3975)",
    ]
    head += ["efficiency (wedge at r_c)", "F_t p2p", "TE p2p", "resolution, slices, step"]
    return _table(head, rows) + "\n" + _source(name)


def torsional_seeds_table(name: str = "torsional_seeds") -> str:
    """The torsional level on each seed file as it is (studies/torsional_seeds.py), closed forms in brackets."""
    rows = []
    for seed, run in load(name)["runs"].items():
        r = run["default"]
        rows.append(
            [
                f"{seed} ({r['sim_time_s']:.3g} s)",
                f"{r['wall_s']:.3g} s",
                f"{r['wall_s'] / r['sim_time_s']:.2g}",
                f"{r['ratio']:.4f}",
                f"{r['tangential_force_mean_n']:.2f} ({r['tangential_force_theory_n']:.2f})",
                f"{r['efficiency']:.5f} ({r['efficiency_theory']:.5f})",
                f"{r['mesh_frequency_hz']:.4g} ({r['mesh_frequency_theory_hz']:.4g})",
            ]
        )
    head = ["scenario (sim time)", "wall", "wall / sim s", "ratio", "F_t mean [N] (T2 / r2)"]
    head += ["efficiency (wedge)", "mesh freq [Hz] (z1 n1 / 60)"]
    return _table(head, rows) + "\n" + _source(name)


def torsional_samples_table(name: str = "torsional_seeds") -> str:
    """The torsional level against its k(theta) samples per mesh cycle N (studies/torsional_seeds.py)."""
    rows = []
    for seed, run in load(name)["runs"].items():
        rs = run["samples"]
        ns = list(rs)

        def col(f) -> str:
            return " / ".join(f(rs[n]) for n in ns)

        rows.append(
            [
                seed,
                " / ".join(ns),
                col(lambda r: f"{r['timestep_s']:g}"),
                col(lambda r: f"{r['wall_s'] / r['sim_time_s']:.2g}"),
                col(lambda r: f"{r['tangential_force_p2p_n']:.3g}"),
                col(lambda r: f"{r['transmission_error_p2p_urad']:.3g}"),
            ]
        )
    head = ["scenario", "N", "timestep [s]", "wall / sim s", "F_t p2p [N]", "TE p2p [urad]"]
    return _table(head, rows) + "\n" + _source(name)


# ----------------------------------------------------------------------------- the shipped sweeps (docs/sweeps/*.csv)


def _sweep_rows(name: str) -> list[dict]:
    """The ok rows of docs/sweeps/NAME.csv, numbers parsed (an empty cell is None)."""
    import csv

    def num(v: str):
        try:
            return float(v)
        except ValueError:
            return v or None

    with (ROOT / "docs" / "sweeps" / f"{name}.csv").open(newline="") as fh:
        return [{k: num(v) for k, v in r.items()} for r in csv.DictReader(fh) if r["status"] == "ok"]


def _sweep_source(*names: str) -> str:
    """The line under a sweep table: its csv files and their provenance (docs/data/sweeps.json)."""
    files = load("sweeps")["files"]
    parts = []
    for n in names:
        p = files[f"docs/sweeps/{n}.csv"]
        parts.append(f"`docs/sweeps/{n}.csv` (`{p['command'].split(';')[0]}`; commit {p['commit']}, {p['date'][:10]})")
    return "Records: " + ", ".join(parts) + "; provenance in `docs/data/sweeps.json`.\n"


def _study_module(name: str):
    """studies/NAME.py as a fresh module (its constants: the seeds' tables, the tolerance study's fits; a chart's
    caller redirects its IMG / CSV_DIR), from the package `studies` at the top of the repository."""
    import importlib.util

    spec = importlib.util.find_spec(f"studies.{name}")
    assert spec is not None and spec.loader is not None
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def _screw_jack_sweep_table(name: str, key: str, head0: str, seed: dict) -> str:
    """Seed 002's Table 3 or 4 beside the contact3d (exact flanks) and torsional sweeps of the same points."""
    tors = {r[key]: r for r in _sweep_rows(f"{name}_torsional")}
    rows = []
    for r in _sweep_rows(name):
        t = tors.get(r[key], {})
        s = seed.get(r[key]) or seed.get(int(r[key]), ("-", "-", "-"))
        rows.append(
            [
                f"{r[key]:.3g}".replace("e+0", "e"),
                " / ".join(f"{v:g}" for v in s),
                f"{r['tangential_force_mean_n']:.1f} / {r['tangential_force_p2p_n']:.1f} / "
                f"{r['tangential_force_max_n']:.1f} / {r['startup_tangential_force_peak_n']:.1f}, "
                f"{r['transmission_error_p2p_urad']:.3g}",
                f"{_fmt(t.get('tangential_force_mean_n'), 4)} / {_fmt(t.get('tangential_force_p2p_n'), 2)}, "
                f"{_fmt(t.get('transmission_error_p2p_urad'), 2)}",
            ]
        )
    head = [head0, "seed 002: mean / p2p / max [N]"]
    head += ["contact3d (flanks): F_t mean / p2p / max (steady) / start-up peak [N], TE p2p [urad]"]
    head += ["torsional: F_t mean / p2p [N], TE p2p [urad]"]
    return _table(head, rows) + "\n" + _sweep_source(name, f"{name}_torsional")


def sweep_screw_jack_stiffness_table() -> str:
    """Seed 002 Table 3: contact stiffness at 1330 rpm (studies/screw_jack_stiffness*.yaml)."""
    seed = _study_module("figures").SEED_K
    return _screw_jack_sweep_table("screw_jack_stiffness", "contact.stiffness_n_per_m", "K [N/m] at 1330 rpm", seed)


def sweep_screw_jack_speed_table() -> str:
    """Seed 002 Table 4: worm speed at 4.39e8 N/m (studies/screw_jack_speed*.yaml)."""
    seed = _study_module("figures").SEED_N
    return _screw_jack_sweep_table("screw_jack_speed", "drive.speed_rpm", "worm speed [rpm] at 4.39e8 N/m", seed)


def sweep_seat_motor_friction_table() -> str:
    """The lubricant study (studies/seat_motor_friction.yaml): contact3d's efficiency against the wedge law at the
    pitch radius and at the contacts' radius, and the torsional level."""
    rows_all = _sweep_rows("seat_motor_friction")
    tors = {r["contact.friction"]: r for r in rows_all if r["model"] == "torsional"}
    rows = []
    for r in (r for r in rows_all if r["model"] == "contact3d"):
        e, e1, ec = r["efficiency"], r["efficiency_theory"], r["efficiency_theory_at_contact_radius"]
        t = tors.get(r["contact.friction"], {})
        rows.append(
            [
                f"{r['contact.friction']:g}",
                f"{e:.4f}",
                f"{e1:.4f} ({(e / e1 - 1) * 100:+.1f} %)",
                f"{ec:.4f} ({(e / ec - 1) * 100:+.2f} %)",
                _fmt(t.get("efficiency"), 4),
                f"{r['tangential_force_mean_n']:.1f} ({r['tangential_force_theory_n']:.1f})",
            ]
        )
    head = ["mu", "contact3d efficiency", "tan g / tan(g + rho') at the pitch radius"]
    head += ["the same at the contacts' radius"]
    head += ["torsional", "contact3d F_t mean [N] (T2 / r2)"]
    return _table(head, rows) + "\n" + _sweep_source("seat_motor_friction")


def _tolerance_table(gear: str) -> str:
    """The tolerance study's spread and dominant error (studies/errors_figures.py's regression)."""
    import numpy as np

    ef = _study_module("errors_figures")
    rows = ef._tol_rows(ROOT / "docs" / "sweeps" / f"{gear}_tolerance.csv", gear)
    out = []
    for key, label in ef.TOL_OUT:
        v = np.array([r[key] for r in rows if r.get(key) is not None], float)
        q = np.percentile(v, [5, 50, 95])
        inputs = ef.TOL_IN_SIGNED if key == "contact_pattern_centroid_face_mm" else ef.TOL_IN
        beta, r2, _ = ef.regression(rows, key, inputs)
        top = max(beta, key=lambda p: abs(beta[p]))
        out.append(
            [
                label,
                f"{q[1]:.4g}",
                f"{q[0]:.4g} to {q[2]:.4g}",
                f"{v.max():.4g}",
                f"{dict(inputs)[top]} ({beta[top]:+.2f}; R^2 {r2:.2f})",
            ]
        )
    head = [f"{gear.replace('_', ' ')}, {len(rows)} points", "median", "5-95 %", "max"]
    head += ["largest standardised beta (R^2 of the fit)"]
    return _table(head, out) + "\n" + _sweep_source(f"{gear}_tolerance")


def sweep_tolerance_screw_jack_table() -> str:
    return _tolerance_table("screw_jack")


def sweep_tolerance_seat_motor_table() -> str:
    return _tolerance_table("seat_motor")


def wedge_seed000_table(name: str = "wedge_seed000") -> str:
    """The wedge level on seed 000's valve cases beside the seed's results table (studies/wedge_seed000.py)."""
    rows = []
    for case, r in load(name)["runs"].items():
        sd = r.get("seed") or {}

        def pair(ours: str, seed: str, spec: str) -> str:
            return f"{r[ours]:{spec}} / " + (f"{sd[seed]:g}" if seed in sd else "-")

        rows.append(
            [
                case,
                f"{r['driven_mass_kg']:g} kg",
                f"{r['load_force_n']:g} N",
                pair("S1_peak_n", "S1_n", ".0f"),
                pair("Kd1", "Kd1", ".2f"),
                pair("S2_peak_n", "S2_n", ".0f"),
                pair("Kd2", "Kd2", ".2f"),
                f"{r['speed_steady_m_s']:.2f} m/s",
            ]
        )
    head = ["case", "m2", "F2", "S1 peak ours / seed [N]", "Kd1 ours / seed", "S2 peak ours / seed [N]"]
    head += ["Kd2 ours / seed", "steady speed (ours)"]
    return _table(head, rows) + "\n" + _source(name)


def mass_scaling_table(name: str = "mass_scaling", ref: str = "seat_motor_20s") -> str:
    """The 20 s seat motor with mass scaling (studies/mass_scaling.py) beside the unscaled run with pieces (its fixed
    steady window): relative deviations in brackets."""
    r0 = load(ref)
    run0 = r0["summary_as_written_by_the_run"]
    s0 = r0.get("recomputed_with_the_fixed_steady_window") or run0

    def dev(v: float, k: str) -> str:
        return f"({(v / s0[k] - 1) * 100:+.3g} %)"

    rows = [
        [
            "pieces, unscaled (`seat_motor_20s`)",
            "1",
            f"{run0['timestep_s']:.2g} s",
            f"{r0['steps']}",
            f"{r0['wall_time_s']:.0f}",
            f"{r0['wall_time_s'] / run0['sim_time_s']:.3g}",
            f"{s0['efficiency']:.5f}",
            f"{s0['ratio']:.5f}",
            f"{s0['tangential_force_mean_n']:.2f}",
            f"{s0['mesh_frequency_hz']:.5f}",
            "-",
        ]
    ]
    for scale, r in load(name)["runs"].items():
        rows.append(
            [
                f"flanks, `{scale}`",
                f"{r['mass_scaling']:g}",
                f"{r['timestep_s']:.2g} s",
                f"{r['steps']}",
                f"{r['wall_s']:.3g}",
                f"{r['wall_s'] / r['sim_time_s']:.3g}",
                f"{r['efficiency']:.5f} {dev(r['efficiency'], 'efficiency')}",
                f"{r['ratio']:.5f} {dev(r['ratio'], 'ratio')}",
                f"{r['tangential_force_mean_n']:.2f} {dev(r['tangential_force_mean_n'], 'tangential_force_mean_n')}",
                f"{r['mesh_frequency_hz']:.5f} {dev(r['mesh_frequency_hz'], 'mesh_frequency_hz')}",
                f"{100 * r['kinetic_energy_share']:.2g} % / {100 * r['kinetic_energy_share_estimate']:.2g} %",
            ]
        )
    head = ["run", "S", "step", "steps", "wall [s]", "wall per simulated s", "efficiency", "ratio", "mean F_t [N]"]
    head += ["f_mesh [Hz]", "KE share measured / estimated"]
    return _table(head, rows) + "\n" + _source(ref) + _source(name)


def piece_error_table(name: str = "piece_error") -> str:
    """The seeds' convex collision pieces and their error against the exact flanks (studies/piece_error.py)."""
    rows = []
    for r in load(name)["rows"]:
        e = r["piece_error_um"]
        fillet = e.get("wheel_undercut_zone")
        rows.append(
            [
                r["gear"],
                f"{r['resolution']} ({r['worm_segments_per_turn']}, {r['wheel_slabs']}, {r['profile_points']})",
                f"{r['worm_pieces']}",
                f"{r['wheel_tooth_pieces']}",
                f"{e['worm']['max']:.2g} / {e['worm']['rms']:.2g}",
                f"{e['wheel']['max']:.3g} / {e['wheel']['rms']:.3g}",
                f"{e['wheel']['min_signed']:.2g}",
                "-" if not fillet else f"{fillet['min_signed']:.2g}",
                f"{r['normal_half_backlash_um']:.3g}",
                f"{r['wall_s']:.2g}",
            ]
        )
    head = ["gear", "level (segments/turn, slabs, profile pts)", "worm pieces", "pieces/tooth", "worm max / rms um"]
    head += ["wheel max / rms um", "wheel min signed um", "fillet zone min um", "normal j/2 um", "time s"]
    return _table(head, rows) + "\n" + _source(name)


def backlash_min_table(name: str = "piece_error") -> str:
    """The pieces' bulge b and the smallest backlash j_min of each seed and level (wormsim.contact3d.backlash, from
    the record of the pieces, studies/piece_error.py) beside the scenario's backlash."""
    from meshgen.geometry import derive
    from wormsim.contact3d.backlash import min_backlash_m, piece_bulge_m
    from wormsim.scenario import load_scenario

    rows: dict[str, list[str]] = {}
    levels: list[str] = []
    for r in load(name)["rows"]:
        sc = load_scenario(ROOT / "scenarios" / f"{r['gear']}.yaml")
        geo = derive(sc.gear)
        b = piece_bulge_m(r["piece_error_um"])
        row = rows.setdefault(r["gear"], [r["gear"]])
        row.append(f"{b * 1e6:.2g} um / {min_backlash_m(geo, b) * 1e3:.2g} mm")
        if r["resolution"] not in levels:
            levels.append(r["resolution"])
        if len(row) == 1 + 3:
            row.append(f"{sc.gear.backlash_mm:g} mm")
    head = ["gear", *[f"b / j_min {lv}" for lv in levels], "scenario j"]
    return _table(head, list(rows.values())) + "\n" + _source(name)


def errors_seat_motor_table(name: str = "errors_seat_motor") -> str:
    """studies/errors_seat_motor.py: the seat motor's loaded pattern under each error alone, at 4 and 24 N m, with the
    kinematic TCA's pattern centroid of the same errors (docs/errors.md, 6)."""
    rows = []
    for r in load(name)["rows"]:
        kin = r.get("transmission_error_kinematic_p2p_urad")
        tca = r.get("kinematic_contact_pattern_centroid_face_mm")
        play = r.get("backlash_measured_mm")
        errs = ", ".join(e.removeprefix("errors.").replace("=", " ") for e in r["errors"]) or "none"
        rows.append(
            [
                f"{r['load_torque_nm']:g} N m",
                errs,
                f"{r['contact_pattern_centroid_face_mm']:+.2f} mm" + (f" ({tca:+.2f})" if tca is not None else ""),
                f"{r['contact_pattern_extent_face_mm']:.2f} mm",
                f"{r['contact_pressure_max_mpa']:.0f} / {r['contact_pressure_mean_mpa']:.0f} MPa",
                f"{r['tangential_force_p2p_n']:.2g} N",
                f"{r['transmission_error_p2p_urad']:.0f}" + (f" ({kin:.0f})" if kin is not None else "") + " urad",
                f"{r['efficiency']:.3f}",
                "j" if play is None else f"{play:.3f} mm",
            ]
        )
    head = ["load", "error", "pattern centroid face (kinematic TCA)", "95 % extent", "p_H max / mean", "F_t p2p"]
    head += ["TE p2p (kin.)", "efficiency", "play"]
    return _table(head, rows) + "\n" + _source(name)


def _tolerance_full(gear: str) -> str:
    """The tolerance study's spread and the standardised coefficients of every error (docs/errors.md, 8)."""
    import numpy as np

    ef = _study_module("errors_figures")
    rows = ef._tol_rows(ROOT / "docs" / "sweeps" / f"{gear}_tolerance.csv", gear)
    spread, fits = [], []
    for key, label in ef.TOL_OUT:
        v = np.array([r[key] for r in rows if r.get(key) is not None], float)
        q = np.percentile(v, [5, 50, 95])
        spread.append([label, *(f"{x:.4g}" for x in (v.mean(), v.std(), v.min(), q[0], q[1], q[2], v.max()))])
        signed = key == "contact_pattern_centroid_face_mm"
        beta, r2, _ = ef.regression(rows, key, ef.TOL_IN_SIGNED if signed else ef.TOL_IN)
        top = max(beta, key=lambda p: abs(beta[p]))
        cells = [f"**{b:+.2f}**" if p == top and r2 > 0.2 else f"{b:+.2f}" for p, b in beta.items()]
        fits.append([label + (" (signed)" if signed else ""), f"{r2:.2f}", *cells])
    text = _table(["output", "mean", "sd", "min", "5 %", "median", "95 %", "max"], spread) + "\n"
    text += _table(["output", "R^2", *(lbl for _, lbl in ef.TOL_IN)], fits)
    return text + "\n" + _sweep_source(f"{gear}_tolerance")


def mesh_stiffness_seeds_table(name: str = "mesh_stiffness_seeds") -> str:
    """k(theta) of the torsional level on each seed file (studies/mesh_stiffness_seeds.py)."""
    rows = []
    for seed, r in load(name)["runs"].items():
        k, kp = r["mesh_stiffness_mean_n_per_m"], r["pair_stiffness_n_per_m"]
        f = r.get("force_peak_full_band_hz")
        fm = r.get("mesh_frequency_theory_hz")
        rows.append(
            [
                f"{seed} (N = {r['mesh_stiffness_samples']})",
                f"{k:.3g} N/m ({r['mesh_stiffness_min_n_per_m']:.3g}-{r['mesh_stiffness_max_n_per_m']:.3g})",
                f"{kp:.3g} N/m ({r['mesh_stiffness_source']}): {k / kp:.2f}",
                f"{r['teeth_in_contact_mean']:.2f}",
                f"{r['contact_line_length_mean_mm']:.1f} mm on b2 = {r['face_width_mm']:.3g} mm",
                "-" if f is None or not fm else f"{f:.3g} Hz = {f / fm:.1f} f_mesh",
            ]
        )
    head = ["seed", "k_mesh mean (min-max)", "tooth-pair K (source): k_mesh / K", "teeth in contact"]
    head += ["contact lines", "F_t full-band peak"]
    return _table(head, rows) + "\n" + _source(name)


def tooth_compliance_seeds_table(name: str = "tooth_compliance_seeds") -> str:
    """The LTCA on each seed file (studies/tooth_compliance_seeds.py)."""
    rows = []
    for seed, r in load(name)["runs"].items():
        iso = r["iso6336"]
        rows.append(
            [
                f"{seed} (E2 {r['wheel_e_gpa']:g} GPa, T2 {r['torque_nm']:g} N m)",
                f"{r['mesh_stiffness_per_width_n_per_mm_um']:.3g}",
                f"{r['hertz_per_width_n_per_mm_um']:.3g}",
                f"{iso['c_prime']:.3g} / {iso['c_gamma']:.3g}",
                f"{r['teeth_in_contact_mean']:.2f}",
                f"{r['load_share_max']:.2f}",
                f"{r['transmission_error_loaded_p2p_urad']:.3g}",
                f"{r['pressure_max_mpa']:.0f}",
                f"{r['line_stiffness_n_per_m2'] / r['hertz_line_stiffness_n_per_m2']:.3f}",
                f"{r['compliance_wall_s_uncached']:.0f} s ({r['fe_nodes']} nodes)",
            ]
        )
    head = ["seed", "k_mesh / b2 LTCA", "Hertz only", "ISO c' / c_gamma", "teeth in contact", "load share max"]
    head += ["loaded TE p2p (urad)", "p_H max (MPa)", "k'_eff / (pi E* / 4)", "FE (uncached)"]
    parts = load(name)["screw_jack_parts"]
    base = parts["mesh_stiffness_three_teeth_n_per_m"]
    note = (
        f"\nStiffness per width in N/(mm um). Screw jack, the FE model's parts: one wheel tooth instead of three "
        f"{parts['mesh_stiffness_one_tooth_n_per_m'] / base:.3f} x the mean k_mesh, the worm thread rigid "
        f"{parts['mesh_stiffness_worm_thread_rigid_n_per_m'] / base:.3f} x"
    )
    if "mesh_stiffness_grid_13x7_n_per_m" in parts:
        note += f", the flank grid 13 x 7 instead of 9 x 5 {parts['mesh_stiffness_grid_13x7_n_per_m'] / base:.3f} x"
    if "mesh_stiffness_at_4x_load_n_per_m" in parts:
        note += (
            f"; at a quarter of its 12 N m {parts['mesh_stiffness_at_0.25x_load_n_per_m'] / base:.3f} x, at 4 times "
            f"{parts['mesh_stiffness_at_4x_load_n_per_m'] / base:.3f} x (the flattening)"
        )
    return _table(head, rows) + note + ".\n\n" + _source(name)


def tooth_compliance_materials_table(name: str = "tooth_compliance_seeds") -> str:
    """The LTCA on the screw jack's gear with each wheel material (studies/tooth_compliance_seeds.py)."""
    mats = load(name)["screw_jack_materials"]
    ref = mats["CuSn12"]["mesh_stiffness_mean_n_per_m"]
    rows = [
        [
            f"{k} ({m['wheel_e_gpa']:g} GPa, {m['wheel_nu']:g})",
            f"{m['mesh_stiffness_per_width_n_per_mm_um']:.3g}",
            f"{m['mesh_stiffness_mean_n_per_m'] / ref:.3f}",
            f"{m['load_share_max']:.3f}",
            f"{m['transmission_error_loaded_p2p_urad']:.3g}",
            m["source"],
        ]
        for k, m in mats.items()
    ]
    head = ["wheel", "k_mesh / b2 (N/(mm um))", "k / k(CuSn12)", "load share max", "loaded TE p2p (urad)", "E, nu from"]
    return _table(head, rows) + "\n" + _source(name)


def cli_wall_table(name: str = "cli_wall") -> str:
    """The whole CLI run's wall time (studies/measure_cli_wall.py), after a warm-up run."""
    r = load(name)
    p = r["provenance"]
    row = [f"`{r['command']}`", " / ".join(f"{w:.3g} s" for w in r["wall_s"]), p["machine"]]
    return _table(["command", "wall time of each run", "machine (load)"], [row]) + "\n" + _source(name)


def shafts_study_table(name: str = "shafts_study") -> str:
    """studies/shafts_study.py: each drive at several loads, rigid hinges against its shafts on bearings
    (docs/multibody.md)."""

    def f(x, spec: str) -> str:
        if x is None:
            return "-"
        if isinstance(x, list):
            return ", ".join(spec.format(v) for v in x)
        return spec.format(x)

    rows = []
    for r in load(name)["rows"]:
        rows.append(
            [
                r["scenario"],
                f"{r['load_nm']:g}",
                r["shafts"],
                f"{r['transmission_error_p2p_urad']:.1f}",
                f"{r['contact_pattern_centroid_face_mm']:.2f}",
                f(r["worm_deflection_mesh_um"], "{:.2f}"),
                f(r["wheel_deflection_mesh_um"], "{:.2f}"),
                f(r["worm_bearing_radial_mean_n"], "{:.0f}"),
                f(r["worm_bearing_axial_mean_n"], "{:.0f}"),
                f(r["wheel_bearing_radial_mean_n"], "{:.0f}"),
                f(r["wheel_bearing_axial_mean_n"], "{:.0f}"),
                f"{r['efficiency']:.4f}",
            ]
        )
    head = ["scenario", "load [N m]", "shafts", "TE p2p [urad]", "pattern centroid [mm]", "worm defl. [um]"]
    head += ["wheel defl. [um]", "worm bearings radial [N]", "worm axial [N]", "wheel bearings radial [N]"]
    head += ["wheel axial [N]", "efficiency"]
    return _table(head, rows) + "\n" + _source(name)


def _flank_forms_runs(name: str):
    """(gear, form, label, contact3d summary, torsional k(theta), refusal) of each run of the flank-form study."""
    r = load(name)
    for gear, forms in r["results"].items():
        for form, run in forms.items():
            rho = next((s.split("=")[1] for s in run.get("set", []) if s.startswith("gear.profile_radius_mm=")), None)
            label = form + (f" (rho_c {rho} mm)" if rho else "")
            yield gear, form, label, run.get("contact3d"), run.get("torsional"), run.get("refused")


def flank_forms_table(name: str = "flank_forms") -> str:
    """studies/flank_forms_study.py: every worm flank form at contact3d (exact flanks) and torsional's TCA."""
    rows = []
    for gear, _, label, c, t, refused in _flank_forms_runs(name):
        g = gear.replace("_", " ")
        if refused:
            rows.append([g, label, f"refused: {refused.split(': ', 1)[-1].split(';')[0]}", "", "", "", ""])
            continue
        eff, th = c["efficiency"], c["efficiency_theory_at_contact_radius"]
        k = [t[f"mesh_stiffness_{s}_n_per_m"] / 1e6 for s in ("mean", "min", "max")]
        rows.append(
            [
                g,
                label,
                f"{c['contact_pressure_max_mpa']:.0f} / {c['contact_pressure_mean_mpa']:.0f}",
                f"{eff:.4f} / {th:.4f} ({(eff / th - 1) * 100:+.2f} %)",
                f"{c['tangential_force_p2p_n']:.2f}",
                f"{c['transmission_error_p2p_urad']:.1f}",
                " / ".join(f"{x:.0f}" for x in k),
            ]
        )
    head = ["gear", "form", "p_H max / mean (MPa)", "efficiency / theory at contact radius", "F_t p2p (N)"]
    head += ["TE p2p (urad)", "mesh stiffness mean / min / max (N/um)"]
    return _table(head, rows) + "\n" + _source(name)


def flank_forms_checks_table(name: str = "flank_forms") -> str:
    """The flank-form study's runs against the closed forms: the range over the forms each gear can make."""
    by_gear: dict[str, list[dict]] = {}
    for gear, _, _, c, _, refused in _flank_forms_runs(name):
        if not refused:
            by_gear.setdefault(gear, []).append(c)

    def span(vals: list[float], spec: str) -> str:
        lo, hi = spec.format(min(vals)), spec.format(max(vals))
        return lo if lo == hi else f"{lo} to {hi}"

    gears = list(by_gear)
    cells: dict[str, list[str]] = {
        "ratio": [],
        "F_t mean": [],
        "efficiency against theory at the contact radius": [],
        "meshing frequency (z1 n1 / 60)": [],
    }
    for gear in gears:
        cs = by_gear[gear]
        cells["ratio"].append(span([c["ratio"] for c in cs], "{:.6f}"))
        cells["F_t mean"].append(span([c["tangential_force_mean_n"] for c in cs], "{:.2f}") + " N")
        dev = [(c["efficiency"] / c["efficiency_theory_at_contact_radius"] - 1) * 100 for c in cs]
        cells["efficiency against theory at the contact radius"].append(span(dev, "{:+.2f}") + " %")
        fm = [c["mesh_frequency_hz"] for c in cs]
        th = [c["mesh_frequency_theory_hz"] for c in cs]
        cells["meshing frequency (z1 n1 / 60)"].append(f"{span(fm, '{:.4f}')} ({span(th, '{:.4f}')}) Hz")
    rows = [[k, *v] for k, v in cells.items()]
    return _table(["check", *(g.replace("_", " ") for g in gears)], rows) + "\n" + _source(name)


def rating_seeds_table(name: str = "rating_seeds") -> str:
    """The rating with the FE root stress on each seed beside what the seed reports (studies/rating_seeds.py)."""
    rows = []
    for seed, r in load(name)["seeds"].items():
        x, y, z = r["position_mm"]
        where = (
            f"root, z {z:.1f} of +-{r['face_half_width_mm']:.1f} mm, position {r['position_index'] + 1} of "
            f"{r['positions']}"
        )
        rows.append(
            [
                f"{r['seed']} {seed} ({r['wheel_material']}, {r['wheel_torque_nm']:.4g} N m)",
                "refused (plastic)" if r["refused"] else _fmt(r["safety_pitting"]),
                _fmt(r["safety_wear"]),
                _fmt(r["safety_root"]),
                _fmt(r["safety_root_sim"]),
                f"{_fmt(r['root_stress_max_mpa'])}; {where}",
                r["seed_says"],
            ]
        )
    head = ["seed (wheel, T2)", "S_H", "S_W", "S_F", "S_F,sim (FE)", "FE root stress max [MPa]; where"]
    head += ["what the seed reports"]
    return _table(head, rows) + "\n" + _source(name)


def _shares(d) -> str:
    """Load shares, largest first, as 'a / b / c'."""
    vals = sorted(d.values() if isinstance(d, dict) else d, reverse=True)
    return " / ".join(f"{v:.2f}" for v in vals if v > 0.005) or "-"


def calculix_check_table(name: str = "calculix_check") -> str:
    """The CalculiX contact check (studies/calculix_check.py): per gear and worm angle the CalculiX mesh stiffness and
    load shares beside the LTCA's, the mean per gear with ISO 6336-1's c' and c_gamma, the root stress beside
    `wormsim rate --fe`'s."""
    rec = load(name)
    rows = []
    for gear, d in rec["gears"].items():
        lt = d["ltca"]
        la = lt["angles"] if lt.get("available") else [None] * len(d["calculix"])
        for c, a in zip(d["calculix"], la):
            rows.append(
                [
                    gear,
                    f"{c['theta1_deg']:.1f}",
                    f"{c['torque_nm']:.3g}",
                    f"{c['mesh_stiffness_n_per_m']:.3g}",
                    f"{a['mesh_stiffness_n_per_m']:.3g}" if a else "-",
                    _shares(c["load_share"]),
                    _shares(a["load_share"]) if a else "-",
                    f"{c['torque_balance']:+.0e}",
                    _fmt(c.get("root_stress_max_mpa")),
                ]
            )
        m, iso = d["calculix_mean"], d["iso6336"]
        cmp = d.get("comparison", {})
        ratio = cmp.get("mesh_stiffness_ratio_calculix_to_ltca")
        rows.append(
            [
                f"**{gear} mean**",
                "-",
                f"{m['torque_nm']:.3g}",
                f"**{m['mesh_stiffness_mean_n_per_m']:.3g}** ({m['mesh_stiffness_per_width_n_per_mm_um']:.3g} "
                f"N/(mm um); ISO c' {iso['c_prime']:.3g}, c_gamma {iso['c_gamma']:.3g})",
                (
                    f"**{cmp['ltca_mesh_stiffness_mean_at_angles_n_per_m']:.3g}** (CalculiX / LTCA {ratio:.3f}; "
                    f"12 samples: {lt['summary']['mesh_stiffness_mean_n_per_m']:.3g})"
                    if lt.get("available") and ratio is not None
                    else "LTCA not available"
                ),  # fmt: skip
                f"max {m['load_share_max']:.2f}",
                (f"max diff {cmp['load_share_max_difference']:.3f}" if "load_share_max_difference" in cmp else "-"),
                f"max {m['torque_balance_max']:.0e}",
                f"{_fmt(m['root_stress_max_mpa_at_scenario_torque'])} at {d['torque_scenario_nm']:.3g} N m "
                f"(rate --fe: {_fmt(d['fe_root']['root_stress_max_mpa'])})",
            ]
        )
    head = ["gear", "theta1 [deg]", "T2 [N m]", "k CalculiX [N/m]", "k LTCA [N/m]", "shares CalculiX",
            "shares LTCA", "torque balance (rel.)", "root stress [MPa]"]  # fmt: skip
    conv = rec.get("convergence")
    note = ""
    if conv:
        c, f = conv["coarse"], conv["fine"]
        note = (
            f"\nh-refinement ({conv['gear']}, theta1 {conv['theta1_deg']:.0f} deg): element size at the contact lines "
            f"{c['h_fine_mm']:.3g} -> {f['h_fine_mm']:.3g} mm ({c['nodes']} -> {f['nodes']} nodes): k "
            f"{c['mesh_stiffness_n_per_m']:.3g} -> {f['mesh_stiffness_n_per_m']:.3g} N/m "
            f"({conv['mesh_stiffness_change'] * 100:+.1f} %), shares {_shares(c['load_share'])} -> "
            f"{_shares(f['load_share'])}, root stress {_fmt(c['root_stress_max_mpa'])} -> "
            f"{_fmt(f['root_stress_max_mpa'])} MPa.\n"
        )
    return _table(head, rows) + note + "\n" + _source(name)


def rexs_stages_table(name: str = "rexs_stages") -> str:
    """The REXS stages at every level beside F_t2 = T2 / (d2 / 2) (studies/rexs_stages.py)."""
    rows = []
    for stage, r in load(name)["stages"].items():
        g = r["gear"]
        gear = (
            f"{stage}: {g['profile']} {g['z1']}/{g['z2']}, m_x {_fmt(g['m_x_mm'])}, a {_fmt(g['a_mm'])} mm, x2 "
            f"{_fmt(g['x2'])}, {_fmt(r['speed_rpm'])} rpm, {_fmt(r['torque_nm'])} N m"
        )
        for level, s in r["levels"].items():
            eff_t = s["efficiency_theory_at_contact_radius"] if level == "contact3d" else s["efficiency_theory"]
            rows.append(
                [
                    gear,
                    level,
                    _fmt(s["ratio"], 6),
                    f"{s['tangential_force_mean_n']:.1f} ({r['ft2_theory_n']:.1f})",
                    f"{_fmt(s['efficiency'], 4)} ({_fmt(eff_t, 4)})",
                    _fmt(s.get("contact_pressure_max_mpa")),
                    _fmt(s.get("worm_deflection_mesh_um")),
                    _fmt(s["wall_s"], 2),
                ]
            )
            gear = ""
    head = ["stage", "level", "ratio", "F_t2 [N] (T2 / r2)", "efficiency (theory)", "p_H max [MPa]"]
    head += ["worm deflection [um]", "wall [s]"]
    return _table(head, rows) + "\n" + _source(name)


def rexs_rating_table(name: str = "rexs_stages") -> str:
    """ISO/TS 14521 method B on the REXS stages (studies/rexs_stages.py)."""
    keys = (
        ("contact_stress_mean_iso_mpa", "sigma_Hm [MPa]"),
        ("friction_iso", "mu_zm"),
        ("efficiency_iso", "eta_z"),
        ("safety_pitting", "S_H"),
        ("safety_wear", "S_W"),
        ("safety_root", "S_F"),
        ("safety_deflection", "S_delta"),
        ("oil_temperature_c", "theta_S [C]"),
        ("safety_temperature", "S_T"),
    )
    rows = [[stage] + [_fmt(r["rating"][k]) for k, _ in keys] for stage, r in load(name)["stages"].items()]
    return _table(["stage"] + [h for _, h in keys], rows) + "\n" + _source(name)


def stiffness_seeds_table(name: str = "stiffness_seeds") -> str:
    """The seeds' CI runs with each source of the tooth-pair stiffness (studies/stiffness_seeds.py): the seed's own K,
    Hertz's rigid line contact, the teeth's compliance; contact3d's step and speed, the fluctuations, pattern and
    pressure, and torsional's TE beside contact3d's."""
    rec = load(name)
    rows = []
    for seed, modes in rec["runs"].items():
        for mode, r in modes.items():
            c, t = r["contact3d"], r["torsional"]
            te_c, te_t = c["transmission_error_p2p_urad"], t["transmission_error_p2p_urad"]
            rows.append(
                [
                    f"{seed}, {mode}",
                    f"{c['contact_pair_stiffness_n_per_m']:.3g} N/m ({c['contact_stiffness_source']})",
                    f"{_fmt(c.get('mesh_stiffness_mean_n_per_m'))} N/m; "
                    f"{_fmt(c.get('mesh_stiffness_per_width_n_per_mm_um'))}",
                    f"{c['timestep_s']:g} s; {c['wall_s_per_simulated_s']:.3g}",
                    f"{c['tangential_force_mean_n']:.1f} N; {c['efficiency']:.4f}",
                    f"{c['tangential_force_p2p_n']:.3g} N",
                    f"{te_c:.4g} / {te_t:.4g} urad ({100 * (te_t / te_c - 1):+.1f} %)",
                    f"{c['contact_pattern_centroid_face_mm']:.2f} / {c['contact_pattern_centroid_radius_mm']:.2f} mm",
                    f"{c['contact_pressure_max_mpa']:.0f} MPa",
                    f"{_fmt(c.get('transmission_error_loaded_p2p_urad'))} urad; {_fmt(c.get('load_share_max'))}",
                ]
            )
    head = [
        "seed, stiffness",
        "tooth pair K (source)",
        "k_mesh mean; per width N/(mm um)",
        "contact3d step; wall s per simulated s",
        "F_t mean; efficiency",
        "F_t p2p",
        "TE p2p contact3d / torsional",
        "pattern centroid face / radius",
        "p_H max",
        "LTCA TE p2p; largest load share",
    ]
    return _table(head, rows) + "\n" + _source(name)


# studies/slice_convergence_default.py's records at medium: the cases and the seat motor (run apart)
SLICE_CONVERGENCE_RECORDS = ("slice_convergence_medium", "slice_convergence_seat_motor")
# the same before law (5) (the flank rows' impedance d per row, decision 0045)
SLICE_CONVERGENCE_PER_ROW = tuple(f"slice_convergence_per_row_{n}" for n in ("medium", "variety", "seat_motor"))


def slice_convergence_table(*names: str) -> str:
    """The default slice count S against 2 S (studies/slice_convergence_default.py): F_t p2p (whole and below the
    meshing band's limit), p_H max (hertz (4)) and one contact's largest p_H (hertz (3)), each S -> 2 S and its
    change; 'yes' where F_t p2p and p_H max are both within 10 %. The rows of each record in `names` (default:
    SLICE_CONVERGENCE_RECORDS) that exists."""
    names = tuple(n for n in (names or SLICE_CONVERGENCE_RECORDS) if (DATA / f"{n}.json").exists())
    recs = [load(n) for n in names]
    rows = []

    def pair(runs: list, ch: dict, key: str, fmt: str) -> str:
        a, b = runs[0].get(key), runs[1].get(key)
        if a is None or b is None:
            return "-"
        c = ch.get(key)
        return f"{fmt.format(a)} / {fmt.format(b)} ({'-' if c is None else f'{100 * c:+.1f} %'})"

    cases = {k: v for rec in recs for k, v in rec["cases"].items()}  # a case in a later record replaces its row
    for case, c in cases.items():
        runs, ch = c["runs"], c["change_default_vs_double"]
        src = runs[0].get("contact_stiffness_source") or "-"
        if c.get("hertz_fallback"):
            src += " (teeth's failed)"
        ok = all(ch.get(k) is not None and abs(ch[k]) <= 0.10 for k in ("ft_p2p_n", "ph_max_mpa"))
        rows.append(
            [
                case,
                src,
                f"{runs[0]['slices']} / {runs[1]['slices']}",
                pair(runs, ch, "ft_p2p_n", "{:.3g}"),
                pair(runs, ch, "ft_p2p_band_n", "{:.3g}"),
                pair(runs, ch, "ph_max_mpa", "{:.0f}"),
                pair(runs, ch, "ph_max_cell_mpa", "{:.0f}"),
                "yes" if ok else "no",
            ]
        )
    head = [
        "case",
        "contact stiffness",
        "slices n / 2 n",
        "F_t p2p [N]",
        f"F_t p2p below {recs[0]['band_hz']:.0f} Hz [N]",
        "p_H max [MPa] (averaged, (4))",
        "one contact's p_H [MPa] ((3))",
        "both within 10 %",
    ]
    # the run's --save folder (pattern tables kept aside, not a record) shown as DIR
    return _table(head, rows) + "\n" + "".join(re.sub(r"--save \S+", "--save DIR", _source(n)) for n in names)


TABLES: dict[str, Callable[[], str]] = {
    "calculix_check": calculix_check_table,
    "stiffness_seeds": stiffness_seeds_table,
    "slice_convergence": slice_convergence_table,
    "slice_convergence_per_row": lambda: slice_convergence_table(*SLICE_CONVERGENCE_PER_ROW),
    "slice_convergence_double": lambda: slice_convergence_table("slice_convergence_double"),
    "slice_convergence_impedance": lambda: slice_convergence_table(
        "slice_convergence_impedance", "slice_convergence_impedance_rest"
    ),
    "slice_convergence_impedance_double": lambda: slice_convergence_table("slice_convergence_impedance_double"),
    "torsional_seeds": torsional_seeds_table,
    "rexs_stages": rexs_stages_table,
    "rexs_rating": rexs_rating_table,
    "rating_seeds": rating_seeds_table,
    "torsional_samples": torsional_samples_table,
    "mesh_stiffness_seeds": mesh_stiffness_seeds_table,
    "tooth_compliance_seeds": tooth_compliance_seeds_table,
    "tooth_compliance_materials": tooth_compliance_materials_table,
    "contact_pattern": contact_pattern_table,
    "ci_seeds": ci_seeds_table,
    "errors_shaft_angle": errors_shaft_angle_table,
    "errors_seat_motor": errors_seat_motor_table,
    "bench_full": bench_full_table,
    "bench_stability": bench_stability_table,
    "bench_flanks_vs_pieces": bench_flanks_vs_pieces_table,
    "flank_speed": flank_speed_table,
    "seat_motor_profile": seat_motor_profile_table,
    "seat_motor_levers": seat_motor_levers_table,
    "kernel_replay": kernel_replay_table,
    "kernel_search": lambda: kernel_replay_table("kernel_search"),
    "flank_contacts": flank_contacts_table,
    "flank_contacts_default": flank_contacts_default_table,
    "bench_shafts": bench_shafts_table,
    "seat_motor_20s": seat_motor_20s_table,
    "sweep_speedup": sweep_speedup_table,
    "sweep_scaling": sweep_scaling_table,
    "sweep_fixed_cost": sweep_fixed_cost_table,
    "sweep_scaling_standing": lambda: sweep_scaling_table("sweep_scaling_standing"),
    "core_contention": core_contention_table,
    "errors_study": errors_study_table,
    "wedge_seed000": wedge_seed000_table,
    "mass_scaling": mass_scaling_table,
    "cli_wall": cli_wall_table,
    "shafts_study": shafts_study_table,
    "flank_forms": flank_forms_table,
    "flank_forms_checks": flank_forms_checks_table,
    "piece_error": piece_error_table,
    "backlash_min": backlash_min_table,
    "sweep_screw_jack_stiffness": sweep_screw_jack_stiffness_table,
    "sweep_screw_jack_speed": sweep_screw_jack_speed_table,
    "sweep_seat_motor_friction": sweep_seat_motor_friction_table,
    "sweep_tolerance_screw_jack": sweep_tolerance_screw_jack_table,
    "sweep_tolerance_seat_motor": sweep_tolerance_seat_motor_table,
    "tolerance_screw_jack": lambda: _tolerance_full("screw_jack"),
    "tolerance_seat_motor": lambda: _tolerance_full("seat_motor"),
}


# ----------------------------------------------------------------------------- figures


def _bench_png(name: str) -> Callable[[Path], None]:
    def draw(path: Path) -> None:
        from wormsim.bench.run import plot_bench

        plot_bench(load(name)["records"], path)

    return draw


def _errors_study_png(path: Path) -> None:
    _study_module("errors_figures").study(path)


def _sweep_png(module: str, func: str, name: str, runs: tuple[str, ...]) -> Callable[[Path], None]:
    """A chart of studies/MODULE.py's FUNC drawn from the csv files under docs/sweeps/ (the shipped studies'
    records): the module reads RUNS/NAME/sweep.csv and writes IMG/NAME.png, both redirected to a temporary folder."""

    def draw(path: Path) -> None:
        import contextlib
        import io
        import shutil
        import tempfile

        mod = _study_module(module)
        with tempfile.TemporaryDirectory() as tmp:
            t = Path(tmp)
            for run in runs:
                (t / "runs" / run).mkdir(parents=True)
                shutil.copy(ROOT / "docs" / "sweeps" / f"{run}.csv", t / "runs" / run / "sweep.csv")
            mod.IMG, mod.CSV_DIR = t / "img", t / "csv"
            mod.IMG.mkdir()
            with contextlib.redirect_stdout(io.StringIO()):
                getattr(mod, func)(t / "runs")
            shutil.copy(t / "img" / f"{name}.png", path)

    return draw


FIGURES: dict[str, Callable[[Path], None]] = {
    "bench_full": _bench_png("bench_full"),
    "bench_quick": _bench_png("bench_quick"),
    "errors_study": _errors_study_png,
    "sweep_screw_jack": _sweep_png(
        "figures",
        "screw_jack",
        "sweep_screw_jack",
        ("screw_jack_stiffness", "screw_jack_stiffness_torsional", "screw_jack_speed", "screw_jack_speed_torsional"),
    ),
    "sweep_seat_motor_friction": _sweep_png(
        "figures", "friction", "sweep_seat_motor_friction", ("seat_motor_friction",)
    ),
    "sweep_screw_jack_resonance": _sweep_png(
        "figures", "resonance", "sweep_screw_jack_resonance", ("screw_jack_resonance",)
    ),
    "tolerance_screw_jack": _sweep_png(
        "errors_figures", "tolerance", "tolerance_screw_jack", ("screw_jack_tolerance", "seat_motor_tolerance")
    ),
    "tolerance_seat_motor": _sweep_png(
        "errors_figures", "tolerance", "tolerance_seat_motor", ("screw_jack_tolerance", "seat_motor_tolerance")
    ),
}


# ----------------------------------------------------------------------------- rendering


def render_text(text: str) -> str:
    """text with every marked block replaced by its table (an unknown NAME raises KeyError naming it)."""

    def sub(m: re.Match) -> str:
        name = m.group("name")
        if name not in TABLES:
            raise KeyError(f"<!-- render: {name} -->: no such table (tools.docs_render.TABLES: {sorted(TABLES)})")
        return m.group(1) + TABLES[name]() + m.group(4)

    return MARK.sub(sub, text)


def markdown_files() -> list[Path]:
    """README.md and docs/*.md; not docs/decisions/, whose records are history with their deciding numbers as
    measured at the time."""
    return [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]


def blocks(text: str) -> list[str]:
    """The NAMEs of the marked blocks in text."""
    return [m.group("name") for m in MARK.finditer(text)]


def render_figures(img: Path = IMG, names: list[str] | None = None) -> list[Path]:
    """Draw every FIGURES entry (or those named) to IMG/NAME.png with fixed PNG metadata."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    saved = plt.savefig
    out = []

    def savefig(*a, **k):  # the figure functions call plt.savefig / fig.savefig: fix their metadata
        k.setdefault("metadata", PNG_METADATA)
        return saved(*a, **k)

    from matplotlib.figure import Figure

    fig_saved = Figure.savefig

    def fig_savefig(self, *a, **k):
        k.setdefault("metadata", PNG_METADATA)
        return fig_saved(self, *a, **k)

    plt.savefig, Figure.savefig = savefig, fig_savefig  # type: ignore[method-assign]
    try:
        for name, draw in FIGURES.items():
            if names is not None and name not in names:
                continue
            path = img / f"{name}.png"
            draw(path)
            plt.close("all")
            out.append(path)
    finally:
        plt.savefig, Figure.savefig = saved, fig_saved  # type: ignore[method-assign]
    return out


def record_bench(name: str, bench_dir: Path) -> Path:
    """docs/data/NAME.json from a `wormsim bench --out DIR`: its records, its meta, the meta's provenance."""
    records = json.loads((bench_dir / "bench.json").read_text())
    meta = json.loads((bench_dir / "bench_meta.json").read_text())
    prov = meta.pop("provenance", None)
    if prov is None or any(k not in prov for k in KEYS):
        raise SystemExit(f"{bench_dir / 'bench_meta.json'}: no provenance (written by an older wormsim bench)")
    return record(name, {"records": records, "meta": meta}, prov=prov)


def main(argv: list[str] | None = None) -> int:
    argv = sys.argv[1:] if argv is None else argv
    if argv[:1] == ["record-bench"] and len(argv) == 3:
        print(record_bench(argv[1], Path(argv[2])))
        return 0
    check = argv == ["--check"]
    if argv and not check:
        print("usage: python -m tools.docs_render [--check | record-bench NAME DIR]", file=sys.stderr)
        return 2
    stale = []
    for path in markdown_files():
        text = path.read_text()
        new = render_text(text)
        if new != text:
            stale.append(path.relative_to(ROOT))
            if not check:
                path.write_text(new)
    if check:
        for p in stale:
            print(f"{p}: a rendered block differs from its record (run `make docs`)")
        return 1 if stale else 0
    for p in render_figures():
        print(p.relative_to(ROOT))
    for p in stale:
        print(f"rendered {p}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
