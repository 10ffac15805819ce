"""Does the leaving tooth's load history converge in slices? (issue 31, item 2; docs/contact3d.md, "Default slice
count"). One case of studies/slice_convergence_default.py (default involute_41's CI run with flanks; medium) at several
slice counts, one sample per step, and per step every flank contact's tooth, flank, slice, its share of its slice (the
kernel's weight), its depth (the line's), line[:, 0] (the covered share the weight is taken from; before issue 31's fix
the line point's excess in slice widths), its profile index and MuJoCo's normal force on it. Per tooth the normal forces
are summed (the tooth's load); the histories are compared across the counts step by step (the counts share the
timestep), so that a quantity that does not converge as S grows shows where; the first exit in the steady window is
summarised (its load over its last steps).

    .venv/bin/python studies/slice_exit_history.py [--case involute_41] [--slices 24 48 96] [--duration S]
        [--save DIR] [--record NAME]

--save writes each run's per-contact table (npz); --record writes docs/data/NAME.json (provenance) with the summary
and the kernel's git blob (kernel_blob: which wormsim/tooth/kernel.py measured it).
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from studies.slice_convergence_default import scenario  # noqa: E402
from wormsim.contact3d import flank_samples, sources  # noqa: E402
from wormsim.contact3d.runner import simulate  # noqa: E402
from wormsim.results.provenance import record  # noqa: E402
from wormsim.scenario import Scenario  # noqa: E402

COLS = ("step", "tooth", "flank", "slice", "weight", "depth_m", "line0", "profile_index", "normal_n")


def run(case: str, slices: int, duration_s: float | None) -> dict:
    """The case (studies/slice_convergence_default.py's, at medium) at `slices`, one sample per step through the
    runner's Python sample path, every contact logged; duration_s None: the case's own."""
    rows: list[np.ndarray] = []
    orig = sources.FlankSource.sample

    def sample(self, i, th2, mu, rlog, store):
        fc, d = self.fc, self.d
        n = fc.n
        if n:
            adr, efc, _, _, _ = fc.slice_rows(d)
            adr = np.asarray(adr[:n], dtype=np.int64)
            fn = np.where(adr >= 0, efc[np.maximum(adr, 0)], np.nan)
            T = np.empty((n, len(COLS)))
            T[:, 0] = i
            T[:, 1:4] = fc.meta[:n, 0:3]
            T[:, 4] = fc.weight[:n]
            T[:, 5] = fc.depth[:n]
            T[:, 6] = fc.line[:n, 0]
            T[:, 7] = fc.meta[:n, 3]
            T[:, 8] = fn
            rows.append(T)
        return orig(self, i, th2, mu, rlog, store)

    sources.FlankSource.sample = sample
    flank_samples.ENABLED = False  # every sample through the runner's Python path
    try:
        d = scenario(case, slices, medium=True).model_dump()
        d["simulation"]["record_every"] = 1
        if duration_s:
            d["simulation"]["duration_s"] = duration_s
        sc = Scenario.model_validate(d)
        t0 = time.perf_counter()
        res = simulate(sc)
        wall = time.perf_counter() - t0
    finally:
        sources.FlankSource.sample = orig
        flank_samples.ENABLED = True
    bm = res.extra["built"]
    return {
        "table": np.concatenate(rows) if rows else np.zeros((0, len(COLS))),
        "t_s": res.series["t_s"],
        "theta2": res.series["wheel_angle_rad"] if "wheel_angle_rad" in res.series else None,
        "ft_n": res.series["tangential_force_n"],
        "summary": res.summary,
        "k_c": bm.law.contact_stiffness_n_per_m,
        "pair_k": bm.law.pair_stiffness_n_per_m,
        "z2": bm.geometry.z2,
        "wall_s": wall,
    }


def tooth_loads(r: dict) -> dict[int, np.ndarray]:
    """Per tooth (the loaded flank's contacts): MuJoCo's normal forces summed per step (0 without a contact)."""
    T, n = r["table"], len(r["t_s"])
    out = {}
    for k in sorted({int(a) for a in T[:, 1]}):
        m = T[:, 1] == k
        f = np.zeros(n)
        np.add.at(f, T[m, 0].astype(int), np.nan_to_num(T[m, 8]))
        out[k] = f
    return out


def exit_summary(r: dict, loads: dict[int, np.ndarray], window) -> dict:
    """The first tooth to leave inside the steady window: its exit step (its last with load) and its load over its
    last 20 steps."""
    t = r["t_s"]
    ends = {}
    for k, f in loads.items():
        on = np.nonzero(f > 0)[0]
        if len(on) and t[on[-1]] > window[0] and on[-1] < len(t) - 1 and on[0] > 0:
            ends[k] = int(on[-1])
    if not ends:
        return {}
    k = min(ends, key=ends.get)
    f, end = loads[k], ends[k]
    return {
        "tooth": k,
        "exit_step": end,
        "exit_t_s": float(t[end]),
        "load_steps_before_exit": [20, 10, 5, 2, 1, 0],
        "load_before_exit_n": [float(f[end - i]) for i in (20, 10, 5, 2, 1, 0)],
    }


def line_history(r: dict, k: int, steps: list[int]) -> list[dict]:
    """Tooth k's loaded contacts at the given steps: how many, their slices' range, their weights' sum x b2 / S (the
    covered length in slice widths), the smallest weight and its slice, their profile indices' range (against the
    grid's active span of that slice: where the line ends, tip, root or a face end) and the tooth's load."""
    T = r["table"]
    out = []
    for i in steps:
        m = (T[:, 0] == i) & (T[:, 1] == k)
        if not m.any():
            out.append({"step": int(i), "contacts": 0})
            continue
        R = T[m]
        j = int(np.argmin(R[:, 4]))
        out.append(
            {
                "step": int(i),
                "contacts": int(m.sum()),
                "slices": [int(R[:, 3].min()), int(R[:, 3].max())],
                "covered_slices": float(R[:, 4].sum()),
                "min_weight": float(R[j, 4]),
                "min_weight_slice": int(R[j, 3]),
                "profile_index": [float(R[:, 7].min()), float(R[:, 7].max())],
                "depth_um": [float(R[:, 5].min() * 1e6), float(R[:, 5].max() * 1e6)],
                "load_n": float(np.nansum(R[:, 8])),
            }
        )
    return out


def enter_summary(r: dict, loads: dict[int, np.ndarray], window) -> dict:
    """The first tooth to enter inside the steady window: its entry step (its first with load) and its load over
    its first 20 steps."""
    t = r["t_s"]
    starts = {}
    for k, f in loads.items():
        on = np.nonzero(f > 0)[0]
        if len(on) and t[on[0]] > window[0] and on[0] > 0:
            starts[k] = int(on[0])
    if not starts:
        return {}
    k = min(starts, key=starts.get)
    f, s0 = loads[k], starts[k]
    return {
        "tooth": k,
        "entry_step": s0,
        "entry_t_s": float(t[s0]),
        "load_steps_after_entry": [0, 1, 2, 5, 10, 20],
        "load_after_entry_n": [float(f[min(s0 + i, len(f) - 1)]) for i in (0, 1, 2, 5, 10, 20)],
    }


def kernel_blob() -> str:
    """The git blob hash of wormsim/tooth/kernel.py as it is on disk (which kernel measured the record)."""
    import subprocess

    res = subprocess.run(["git", "-C", str(ROOT), "hash-object", "wormsim/tooth/kernel.py"], capture_output=True)
    return res.stdout.decode().strip()


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--case", default="involute_41")
    ap.add_argument("--slices", type=int, nargs="+", default=[24, 48, 96])
    ap.add_argument("--duration", type=float, help="simulated seconds (default: the case's)")
    ap.add_argument("--save", type=Path)
    ap.add_argument("--record")
    ap.add_argument("--note", help="a note kept in the record (e.g. which kernel version ran)")
    a = ap.parse_args()
    out: dict = {"case": a.case, "duration_s": a.duration, "kernel_blob": kernel_blob(), "note": a.note, "runs": {}}
    loads: dict[int, dict] = {}
    for S in a.slices:
        r = run(a.case, S, a.duration)
        s = r["summary"]
        print(S, f"wall {r['wall_s']:.0f} s", "F_t p2p", s["tangential_force_p2p_n"], flush=True)
        if a.save is not None:
            a.save.mkdir(parents=True, exist_ok=True)
            np.savez(
                a.save / f"{a.case}_S{S}.npz",
                table=r["table"],
                t_s=r["t_s"],
                ft_n=r["ft_n"],
                window=np.array(s["steady_window_s"]),
                k_c=r["k_c"],
                th2=r["theta2"] if r["theta2"] is not None else np.zeros(0),
            )
        loads[S] = tooth_loads(r)
        ex = exit_summary(r, loads[S], s["steady_window_s"])
        en = enter_summary(r, loads[S], s["steady_window_s"])
        if ex:
            e = ex["exit_step"]
            ex["line"] = line_history(r, ex["tooth"], [e - i for i in (40, 20, 10, 5, 2, 1, 0)])
        if en:
            e = en["entry_step"]
            en["line"] = line_history(r, en["tooth"], [e + i for i in (0, 1, 2, 5, 10, 20, 40)])
        out["runs"][str(S)] = {
            "exit": ex,
            "entry": en,
            "ft_p2p_n": s["tangential_force_p2p_n"],
            "ft_mean_n": s["tangential_force_mean_n"],
            "steady_window_s": s["steady_window_s"],
            "timestep_s": s["timestep_s"],
            "k_c_n_per_m": r["k_c"],
            "wall_s": r["wall_s"],
        }
        # each tooth's load against the finest count's, step by step (the counts share the step: the stable limit
        # is the pair's, whatever S), over the steady window: the largest difference, share of the tooth's largest load
        ref = loads[max(loads)]
        win = (r["t_s"] >= s["steady_window_s"][0]) & (r["t_s"] <= s["steady_window_s"][1])
        for S2, L in loads.items():
            dev = max(
                float(np.abs(L[k][win] - ref[k][win]).max() / ref[k].max()) for k in L if k in ref and ref[k].max() > 0
            )
            out["runs"][str(S2)]["tooth_load_max_dev_vs_finest"] = dev
        print({S2: round(v["tooth_load_max_dev_vs_finest"], 4) for S2, v in out["runs"].items()}, flush=True)
        if a.record:
            record(a.record, out)


if __name__ == "__main__":
    np.seterr(all="ignore")
    main()
